"""symfruit.ros.node2 (`symfruit ros2`): its parameters and CLI without ROS, then end to end against real ROS 2
processes: the node as a subprocess of the ROS 2 venv, the example frame published as a RealSense camera by
`python -m symfruit.ros.camera2 serve` (another process), both on a domain leased for this module alone and
discovering on this machine only.

Every wait is for an event (a reply of the stand-in, which waits on its own subscriptions; a line in the node's
log) with a generous deadline (SYMFRUIT_ROS_TIMEOUT, default 120 s); nothing relies on a fixed sleep. Every
process started here is stopped by its fixture or test. The tests of this module share one node and run in one
xdist worker (group ros2-node).
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from symfruit.errors import SymfruitError
from symfruit.ros.master import stop_group

pytestmark = pytest.mark.xdist_group("ros2-node")

TIMEOUT = float(os.environ.get("SYMFRUIT_ROS_TIMEOUT", "120"))
FRAME_ID = "camera_color_optical_frame"
CUBE, SPHERE, ADD, DELETEALL = 1, 2, 0, 3  # visualization_msgs/msg/Marker


# --------------------------------------------------------------------------------------------------
# without ROS
# --------------------------------------------------------------------------------------------------


def test_parameters_are_checked_by_name():
    from symfruit.ros.node2 import PARAMETERS, checked_parameters

    defaults = checked_parameters({})
    assert defaults == {name: default for name, (default, _) in PARAMETERS.items()}
    got = checked_parameters({"slop": 1, "queue_size": 3.0, "fruit": "apple", "config": None})
    assert got["slop"] == 1.0 and isinstance(got["slop"], float) and got["queue_size"] == 3 and got["config"] == ""
    assert defaults["fruit_processes"] == 1 and checked_parameters({"fruit_processes": 0})["fruit_processes"] == 0
    for bad, message in [
        ({"slop": "abc"}, "parameter slop: expected a number, got 'abc'"),
        ({"slop": -0.1}, "parameter slop: expected seconds in [0, 10]"),
        ({"queue_size": 2.5}, "parameter queue_size: expected a whole number, got 2.5"),
        ({"queue_size": 0}, "parameter queue_size: expected 1 to 100"),
        ({"depth_scale": True}, "parameter depth_scale: expected a number, got True"),
        ({"qos": "best_effort"}, "parameter qos: expected one of reliable, sensor_data"),
        ({"fruit_processes": 17}, "parameter fruit_processes: expected 0 to 16, got 17"),
        ({"fruit_processes": -1}, "parameter fruit_processes: expected 0 to 16, got -1"),
        ({"fruit_processes": 1.5}, "parameter fruit_processes: expected a whole number, got 1.5"),
    ]:
        with pytest.raises(SymfruitError, match="^" + message.replace("[", r"\[").replace("]", r"\]")):
            checked_parameters(bad)


def test_class_id_is_the_profile_name():
    from symfruit.ros.node2 import class_id_of

    assert class_id_of("strawberry") == "strawberry"
    assert class_id_of("/abs/profiles/cherry.yaml") == "cherry"
    assert class_id_of("") == "fruit"


def test_cli_ros2_help_needs_no_ros(capsys):
    from symfruit.cli import main

    assert main(["ros2", "--help"]) == 0
    out = capsys.readouterr().out
    assert "--ros-args" in out and "/camera/camera/color/image_raw" in out


def test_cli_ros2_without_rclpy_names_make_ros2_env(capsys):
    try:
        import rclpy  # noqa: F401

        pytest.skip("rclpy is importable here: this checks the message where it is not")
    except ImportError:
        pass
    from symfruit.cli import main

    assert main(["ros2"]) == 2
    err = capsys.readouterr().err
    assert "symfruit: error:" in err and "make ros2-env" in err and len(err.strip().splitlines()) == 1


# --------------------------------------------------------------------------------------------------
# real ROS 2 processes
# --------------------------------------------------------------------------------------------------


def tail(log: Path) -> str:
    return log.read_text(errors="replace")[-4000:] if log.is_file() else "(no log)"


def wait_for_line(text: str, process: subprocess.Popen, log: Path) -> None:
    """Wait for ``text`` in a process's log (files offer no event; checked every 10 ms until the deadline);
    fails at once when the process has exited."""
    deadline = time.monotonic() + TIMEOUT
    while text not in log.read_text(errors="replace"):
        if process.poll() is not None:
            pytest.fail(f"the process exited ({process.returncode}) waiting for {text!r}; its log:\n{tail(log)}")
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {TIMEOUT:.0f} s waiting for {text!r}; its log:\n{tail(log)}")
        time.sleep(0.01)


def start_node(python: str, env: dict, log: Path, *ros_args: str) -> subprocess.Popen:
    cmd = [python, "-m", "symfruit", "ros2", *(("--ros-args", *ros_args) if ros_args else ())]
    with open(log, "wb") as out:
        return subprocess.Popen(cmd, env=env, stdout=out, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                start_new_session=True)  # fmt: skip


def shm_mapped(pid: int) -> set[str]:
    """The /dev/shm files a process has mapped (Fast DDS's segments, ports and their mutexes)."""
    with open(f"/proc/{pid}/maps", encoding="utf-8") as maps:
        return {ln.split()[-1] for ln in maps if "/dev/shm/" in ln and not ln.rstrip().endswith("(deleted)")}


def shm_now() -> set[str]:
    return {str(p) for p in Path("/dev/shm").iterdir()}


def shm_left_behind(mapped: set[str], before: set[str]) -> set[str]:
    """Of ``mapped``, what was made after ``before`` and still exists with no live process mapping it. (What was
    there before may be a segment another process left; lttng-ust, in the ROS 2 wheels' tracing library, makes
    one wait segment per user, shared by every traced process and by design never removed.)"""
    alive: set[str] = set()
    for maps in Path("/proc").glob("[0-9]*/maps"):
        try:
            alive |= {ln.split()[-1] for ln in maps.read_text(errors="replace").splitlines() if "/dev/shm/" in ln}
        except OSError:  # a process that ended meanwhile, or not ours to read
            continue
    return {p for p in mapped - before if Path(p).exists() and p not in alive and "/lttng-ust-wait-" not in p}


class World:
    """The node with its defaults, the stand-in camera and what they need, on one domain."""

    def __init__(self, python: str, home: Path, domain: int) -> None:
        from symfruit.ros.camera2 import CameraClient, isolated_env

        self.env = isolated_env(domain, home)
        self.log = home / "node.log"
        self.shm_before = shm_now()
        self.node = start_node(python, self.env, self.log)
        self.camera = CameraClient(python, self.env, home / "camera.log")
        self.ready()

    def call(self, op: str, **args) -> dict:
        if self.node.poll() is not None:
            pytest.fail(f"the node exited ({self.node.returncode}); its log:\n{tail(self.log)}")
        try:
            return self.camera.call(op, deadline=TIMEOUT + 30, **args)
        except RuntimeError as exc:
            pytest.fail(f"{exc}\nthe node's log:\n{tail(self.log)}")

    def ready(self) -> None:
        if not self.call("ready", timeout=TIMEOUT)["ok"]:
            pytest.fail(f"the node and the camera did not connect; the node's log:\n{tail(self.log)}")

    def frame(self, sec: int, nanosec: int = 0, **kw) -> None:
        assert self.call("frame", sec=sec, nanosec=nanosec, **kw)["ok"]

    def wait(self, kind: str, sec: int, nanosec: int = 0) -> dict:
        reply = self.call("wait", kind=kind, sec=sec, nanosec=nanosec, timeout=TIMEOUT)
        if not reply["ok"]:
            pytest.fail(f"no {kind} stamped {sec}.{nanosec:09d}; the node's log:\n{tail(self.log)}")
        return reply["msg"]

    def seen(self, kind: str, sec: int, nanosec: int = 0) -> bool:
        return self.call("seen", kind=kind, sec=sec, nanosec=nanosec)["seen"]

    def line(self, text: str) -> None:
        wait_for_line(text, self.node, self.log)

    def close(self) -> None:
        self.camera.close()
        stop_group(self.node, 60)


@pytest.fixture(scope="module")
def world(ros2_python, tmp_path_factory) -> Iterator[World]:
    """`symfruit ros2` with its defaults and the stand-in camera, connected, on a domain of their own."""
    from symfruit.ros.camera2 import domain_lease

    with domain_lease() as domain:
        w = World(ros2_python, tmp_path_factory.mktemp("ros2"), domain)
        try:
            yield w
        finally:
            w.close()


def assert_detections_equal(msg: dict, expected: list[dict], sec: int, nanosec: int, class_id: str) -> None:
    """``msg`` (camera2.as_data) holds exactly ``expected`` (detections.json's fruit), stamped sec.nanosec."""
    assert msg["header"] == {"sec": sec, "nanosec": nanosec, "frame_id": FRAME_ID}
    assert [d["id"] for d in msg["detections"]] == [str(e["id"]) for e in expected] and expected
    for det, fruit in zip(msg["detections"], expected, strict=True):
        assert det["header"] == msg["header"]
        np.testing.assert_allclose(det["centre"], fruit["centre"], rtol=0, atol=1e-6)
        np.testing.assert_allclose(det["size"], [fruit["bbox"]["size"][k] for k in "xyz"], rtol=0, atol=1e-6)
        assert det["orientation"] == [0.0, 0.0, 0.0, 1.0]
        (hyp,) = det["results"]
        assert hyp["class_id"] == class_id
        if fruit["confidence"] is None:  # a method without one (paper): NaN in the message, null in the file
            assert np.isnan(hyp["score"])
        else:
            assert hyp["score"] == pytest.approx(fruit["confidence"], abs=1e-9)
        np.testing.assert_allclose(hyp["position"], fruit["centre"], rtol=0, atol=1e-6)


@pytest.mark.parametrize(("color", "depth", "sec"), [("rgb8", "16UC1", 100), ("bgr8", "32FC1", 200)])
def test_detections_equal_symfruit_detect(world, detect_json, color, depth, sec):
    world.frame(sec, 123456789, color=color, depth=depth)
    msg = world.wait("detections", sec, 123456789)
    expected = [e for e in detect_json["fruits"] if "error" not in e]  # what `symfruit detect` wrote
    assert_detections_equal(msg, expected, sec, 123456789, "strawberry")
    world.line(f"frame {sec}.123456789: {len(expected)} fruit in")  # its latency, logged after publishing


def test_type_hash_and_qos_on_the_graph(world):
    from symfruit.ros.ros2env import UPSTREAM_TYPE_HASH

    # discovery may show an endpoint before the node that owns it ('_NODE_NAME_UNKNOWN_'): wait for the node's
    # own endpoints first, then read the graph
    for topic in ("/symfruit/detections", "/symfruit/markers", "/symfruit/fruit_points"):
        assert world.call("endpoint", topic=topic, node="/symfruit", side="publisher", timeout=TIMEOUT)["ok"]
    from symfruit.ros.node2 import DEFAULT_TOPICS

    for topic in DEFAULT_TOPICS.values():
        assert world.call("endpoint", topic=topic, node="/symfruit", side="subscription", timeout=TIMEOUT)["ok"]
    graph = world.call("graph")
    (pub,) = graph["publishers"]["/symfruit/detections"]
    assert pub == {"node": "/symfruit", "type": "vision_msgs/msg/Detection3DArray", "reliability": "reliable",
                   "hash": UPSTREAM_TYPE_HASH["vision_msgs/msg/Detection3DArray"]}  # fmt: skip
    assert [p["type"] for p in graph["publishers"]["/symfruit/markers"]] == ["visualization_msgs/msg/MarkerArray"]
    assert [p["type"] for p in graph["publishers"]["/symfruit/fruit_points"]] == ["sensor_msgs/msg/PointCloud2"]
    for topic in DEFAULT_TOPICS.values():  # the node listens to the RealSense topics, reliably (as they publish)
        (sub,) = [s for s in graph["subscriptions"][topic] if s["node"] == "/symfruit"]
        assert sub["reliability"] == "reliable"


def test_markers_and_points_arrive(world, example_fruits):
    world.frame(300, 5)
    markers = world.wait("markers", 300, 5)["markers"]
    cloud = world.wait("fruit_points", 300, 5)  # the stand-in subscribes to it, so the node builds it
    assert markers[0]["action"] == DELETEALL  # the first marker of the array clears the last frame's
    body = markers[1:]
    assert [m["type"] for m in body] == [CUBE, SPHERE] * len(example_fruits)
    assert len({(m["ns"], m["id"]) for m in markers}) == len(markers)  # unique (ns, id)
    for box, dot, fruit in zip(body[::2], body[1::2], example_fruits, strict=True):
        assert (box["ns"], box["id"], dot["ns"], dot["id"]) == ("symfruit/box", fruit.id, "symfruit/centre", fruit.id)
        assert box["action"] == dot["action"] == ADD
        np.testing.assert_allclose(box["position"], fruit.centre, rtol=0, atol=1e-6)
        np.testing.assert_allclose(dot["position"], fruit.centre, rtol=0, atol=1e-6)
        np.testing.assert_allclose(box["scale"], fruit.size, rtol=0, atol=1e-6)
    assert all(m["header"] == {"sec": 300, "nanosec": 5, "frame_id": FRAME_ID} for m in markers)
    assert cloud["fields"] == ["x", "y", "z", "fruit", "completed"] and cloud["point_step"] == 20
    assert cloud["width"] == sum(len(f.points) for f in example_fruits) and cloud["bytes"] == 20 * cloud["width"]


SPOILT = [  # (spoil, what the node's log line says)
    ("truncated_color", "colour image: image data holds 460800 bytes, 480 rows of 1920 need 921600"),
    ("truncated_depth", "depth image: image data holds 307200 bytes, 480 rows of 1280 need 614400"),
    ("color_encoding", "colour image: unsupported image encoding 'yuv420'"),
    ("depth_encoding", "depth image has 3 channels, expected 1"),
    ("short_step", "colour image: image step 640 is shorter than a row of 640 rgb8 pixels"),
    ("huge_claim", "colour image: image of 16384x16384 pixels is empty or larger than 40,000,000 pixels"),
    ("size_mismatch", "colour is 640x480 but depth is 320x480; depth must be aligned to the colour image"),
    ("zero_k", "CameraInfo: camera focal lengths must be positive, got fx=0.0, fy=0.0"),
    ("nan_depth", "the depth image holds no valid depth"),
]


def test_spoilt_frames_are_logged_and_survived(world, example_fruits):
    """Each spoilt frame is logged with its reason and skipped; the node goes on with the next good frame."""
    from symfruit.ros.camera2 import SPOILS

    assert sorted(s for s, _ in SPOILT) == sorted(SPOILS)
    for k, (spoil, reason) in enumerate(SPOILT):
        sec = 400 + k
        world.frame(sec, spoil=spoil, depth="32FC1" if spoil == "nan_depth" else "16UC1")
        world.line(f"frame {sec}.000000000 skipped: ")
        assert (
            reason in world.log.read_text(errors="replace").split(f"frame {sec}.000000000 skipped: ")[1].split("\n")[0]
        )
    world.frame(450)
    assert len(world.wait("detections", 450)["detections"]) == len(example_fruits)
    for k in range(len(SPOILT)):  # nothing at all for the spoilt frames
        assert not any(world.seen(kind, 400 + k) for kind in ("detections", "markers", "fruit_points"))
    assert world.node.poll() is None


def test_stamps_out_of_order_and_apart(world, example_fruits):
    world.frame(600)
    world.wait("detections", 600)
    world.frame(599, 500_000_000)  # older than the last frame used: refused, said so
    world.line("stamped 599.500000000 is not newer than the last frame used: ignored")
    world.frame(601, depth_stamp=(601, 200_000_000))  # depth 0.2 s from its colour (slop 0.05 s): never a pair
    world.frame(602, skip=("camera_info",))  # no camera info: no pair either
    world.frame(603)
    assert len(world.wait("detections", 603)["detections"]) == len(example_fruits)
    assert not world.seen("detections", 599, 500_000_000) and not world.seen("detections", 601)
    assert not world.seen("detections", 602)
    world.frame(10)  # 593 s back: a replay restarted; the synchroniser starts afresh
    world.line("stamped 10.000000000 jumped back in time: synchroniser reset")
    assert len(world.wait("detections", 10)["detections"]) == len(example_fruits)


def test_parameters_remapping_qos_and_sigterm(world, ros2_python, tmp_path):
    """A second node beside the shared one: name, method and qos as parameters, inputs remapped by short name and by
    their default name (it hears none of the shared node's frames); best-effort subscriptions on the remapped
    topics; SIGTERM ends it cleanly, nothing left in /dev/shm. (Frames are not sent to it: best effort loses most
    of a 1.5 MB frame between processes here.)"""
    log = tmp_path / "finder.log"
    before = shm_now()
    node = start_node(ros2_python, world.env, log, "-r", "__node:=fruit_finder", "-p", "method:=paper",
                      "-p", "qos:=sensor_data", "-r", "color:=/cam/rgb", "-r", "depth:=/cam/depth",
                      "-r", "/camera/camera/color/camera_info:=/cam/rgb/info")  # fmt: skip
    try:
        for topic in ("/cam/rgb", "/cam/depth", "/cam/rgb/info"):
            got = world.call("endpoint", topic=topic, node="/fruit_finder", side="subscription", timeout=TIMEOUT)
            assert got["ok"] and [e["reliability"] for e in got["endpoints"]] == ["best_effort"], tail(log)
        got = world.call("endpoint", topic="/fruit_finder/detections", node="/fruit_finder", side="publisher")
        assert got["ok"] and got["endpoints"][0]["type"] == "vision_msgs/msg/Detection3DArray"
        started = "method paper, fruit strawberry, qos sensor_data, listening to /cam/rgb, /cam/depth, /cam/rgb/info"
        wait_for_line(started, node, log)
        mapped = shm_mapped(node.pid)
        assert any("fastdds" in p for p in mapped)  # it does use shared memory
        node.send_signal(signal.SIGTERM)
        assert node.wait(TIMEOUT) == 0, tail(log)
        assert "SIGTERM, shutting down" in log.read_text() and "stopped after 0 frames" in log.read_text()
        assert shm_left_behind(mapped, before) == set()
    finally:
        stop_group(node, 60)


def test_bad_parameter_is_one_line_and_exit_2(ros2_python, tmp_path):
    from symfruit.ros.camera2 import domain_lease, isolated_env

    with domain_lease() as domain:
        cmd = [ros2_python, "-m", "symfruit", "ros2", "--ros-args", "-p", "method:=nope"]
        res = subprocess.run(cmd, env=isolated_env(domain, tmp_path), capture_output=True, text=True, timeout=TIMEOUT)
    assert res.returncode == 2, res.stderr
    assert res.stderr.startswith("symfruit: error: ") and "nope" in res.stderr
    assert "Traceback" not in res.stderr


def test_a_parameter_the_node_does_not_have_is_one_line_and_exit_2(ros2_python, tmp_path):
    """rclpy drops an override of an undeclared parameter: `-p metod:=paper` ran the default method, unsaid."""
    from symfruit.ros.camera2 import domain_lease, isolated_env

    with domain_lease() as domain:
        cmd = [ros2_python, "-m", "symfruit", "ros2", "--ros-args", "-p", "metod:=paper", "-p", "use_sim_time:=false"]
        res = subprocess.run(cmd, env=isolated_env(domain, tmp_path), capture_output=True, text=True, timeout=TIMEOUT)
    assert res.returncode == 2, res.stderr
    assert res.stderr.startswith("symfruit: error: parameter 'metod': no such parameter (did you mean 'method'?)")
    assert "Traceback" not in res.stderr


def test_sigint_ends_the_shared_node_cleanly(world):
    """Last in this module: SIGINT ends the shared node (its context and node destroyed, exit status 0) and it
    leaves nothing in /dev/shm."""
    world.frame(900)
    world.wait("detections", 900)
    mapped = shm_mapped(world.node.pid)
    assert any("fastdds" in p for p in mapped)  # it did use shared memory
    world.node.send_signal(signal.SIGINT)
    assert world.node.wait(TIMEOUT) == 0, tail(world.log)
    assert "stopped after" in world.log.read_text()
    assert world.camera.close() == 0
    assert shm_left_behind(mapped, world.shm_before) == set()
