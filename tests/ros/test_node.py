"""symfruit.ros.node (`symfruit ros`): its message builders, then end to end against a real ROS master, the node
as a subprocess and the example frame played in with rospy.

Every wait is for an event (a message with a given stamp, a connection, a line in the node's log) with a generous
deadline (SYMFRUIT_ROS_TIMEOUT, default 120 s); nothing relies on a fixed sleep. Every process started here is
stopped by its fixture.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from symfruit.errors import SymfruitError
from symfruit.ros.core import Fruit
from symfruit.ros.master import stop_group

REPO = Path(__file__).resolve().parents[2]
TIMEOUT = float(os.environ.get("SYMFRUIT_ROS_TIMEOUT", "120"))
NODE = "/symfruit_under_test"
FRAME_ID = "camera_color_optical_frame"
#: The node's log line once its synchroniser has its callback. Its inputs are subscribed a moment before, so a
#: publisher sees them connected while a frame sent then would still be dropped (and a test wait its whole deadline
#: for it): frames are sent after this line.
LISTENING = ", listening to "


# --------------------------------------------------------------------------------------------------
# message builders (ROS 1 message classes, no master)
# --------------------------------------------------------------------------------------------------


def some_fruits() -> list[Fruit]:
    pts = np.array([[0.0, 0.0, 0.3], [0.01, 0.0, 0.3], [0.0, 0.01, 0.32]])
    return [
        Fruit(3, np.array([0.01, -0.02, 0.3]), np.array([0.03, 0.04, 0.035]), 0.8, pts, 2),
        Fruit(5, np.array([-0.05, 0.02, 0.4]), np.array([0.02, 0.02, 0.02]), float("nan"), pts[:1], 1),
    ]


def test_detection_array_round_trips(ros1):
    import io

    from std_msgs.msg import Header

    from symfruit.ros.node import detection_array
    from symfruit.ros.ros1_msgs import load_vision_msgs

    vm = load_vision_msgs()
    msg = detection_array(vm, Header(stamp=ros1.Time(12, 345), frame_id=FRAME_ID), some_fruits())
    buf = io.BytesIO()
    msg.serialize(buf)
    back = vm.Detection3DArray().deserialize(buf.getvalue())
    assert back.header.stamp == ros1.Time(12, 345) and back.header.frame_id == FRAME_ID
    assert [d.results[0].id for d in back.detections] == [3, 5]
    d = back.detections[0]
    assert (d.bbox.center.position.x, d.bbox.center.position.y, d.bbox.center.position.z) == (0.01, -0.02, 0.3)
    assert (d.bbox.size.x, d.bbox.size.y, d.bbox.size.z) == (0.03, 0.04, 0.035)
    assert d.results[0].score == 0.8 and np.isnan(back.detections[1].results[0].score)
    assert d.results[0].pose.pose.position.z == 0.3 and d.bbox.center.orientation.w == 1.0
    assert d.header.stamp == back.header.stamp


def test_markers_clear_then_box_sphere_label(ros1):
    from std_msgs.msg import Header
    from visualization_msgs.msg import Marker

    from symfruit.ros.node import marker_array

    msg = marker_array(Header(frame_id="cam"), some_fruits())
    assert msg.markers[0].action == Marker.DELETEALL
    body = msg.markers[1:]
    assert [m.type for m in body] == [Marker.CUBE, Marker.SPHERE, Marker.TEXT_VIEW_FACING] * 2
    assert [m.id for m in body] == [3, 3, 3, 5, 5, 5]
    box = body[0]
    assert (box.pose.position.x, box.scale.x, box.scale.y, box.scale.z) == (0.01, 0.03, 0.04, 0.035)
    assert all(m.header.frame_id == "cam" for m in msg.markers)


def test_point_cloud_layout(ros1):
    from std_msgs.msg import Header

    from symfruit.ros.node import CLOUD_FIELDS, point_cloud

    msg = point_cloud(Header(frame_id="cam"), some_fruits())
    rows = np.frombuffer(msg.data, np.float32).reshape(-1, len(CLOUD_FIELDS))
    assert [f.name for f in msg.fields] == list(CLOUD_FIELDS) and msg.width == 4 and msg.point_step == 20
    np.testing.assert_array_equal(rows[:, 3], [3, 3, 3, 5])
    np.testing.assert_array_equal(rows[:, 4], [0, 0, 1, 0])  # fruit 3: two seen, one completed
    np.testing.assert_allclose(rows[0, :3], [0.0, 0.0, 0.3], atol=1e-7)


def test_cli_ros_help_needs_no_ros(capsys):
    from symfruit.cli import main

    assert main(["ros", "--help"]) == 0
    assert "ROS arguments" in capsys.readouterr().out


def test_cli_ros_refuses_non_ros_arguments(ros1, capsys):
    from symfruit.cli import main

    assert main(["ros", "--method", "fused"]) == 2
    assert "name:=value" in capsys.readouterr().err


# --------------------------------------------------------------------------------------------------
# a real master, the node as a subprocess
# --------------------------------------------------------------------------------------------------


class Inbox:
    """Messages of one topic by header stamp (secs, nsecs), with a wait for a given stamp."""

    def __init__(self, key: Callable[[Any], Any] = lambda m: m) -> None:
        self.by_stamp: dict[tuple[int, int], Any] = {}
        self.cond = threading.Condition()
        self.key = key

    def __call__(self, msg: Any) -> None:
        head = self.key(msg).header
        with self.cond:
            self.by_stamp[(head.stamp.secs, head.stamp.nsecs)] = msg
            self.cond.notify_all()

    def get(self, stamp: Any) -> Any:
        with self.cond:
            return self.by_stamp.get((stamp.secs, stamp.nsecs))

    def wait(self, stamp: Any, what: str, world: dict) -> Any:
        """The message stamped ``stamp``; fails after the deadline, or at once when the node has exited."""
        deadline = time.monotonic() + TIMEOUT
        key = (stamp.secs, stamp.nsecs)
        with self.cond:
            while key not in self.by_stamp:
                if world["process"].poll() is not None:
                    pytest.fail(f"the node exited waiting for {what}; its log:\n{tail(world['log'])}")
                left = deadline - time.monotonic()
                if left <= 0:
                    pytest.fail(f"timed out after {TIMEOUT:.0f} s waiting for {what}; log:\n{tail(world['log'])}")
                self.cond.wait(min(left, 1.0))  # woken by the message; the 1 s bound only re-checks the node
            return self.by_stamp[key]


def tail(log: Path) -> str:
    return log.read_text(errors="replace")[-4000:] if log.is_file() else "(no log)"


def wait_until(predicate: Callable[[], bool], what: str, process: subprocess.Popen, log: Path) -> None:
    """Wait for a state rospy offers no event for (connection counts, a log line): checked every 10 ms until the
    deadline; fails at once when ``process`` has exited."""
    deadline = time.monotonic() + TIMEOUT
    while not predicate():
        if process.poll() is not None:
            pytest.fail(f"the process exited ({process.returncode}) waiting for {what}; its log:\n{tail(log)}")
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {TIMEOUT:.0f} s waiting for {what}; log:\n{tail(log)}")
        time.sleep(0.01)


def start(cmd: list[str], env: dict[str, str], log: Path) -> subprocess.Popen:
    with open(log, "wb") as out:
        return subprocess.Popen(cmd, env=env, stdout=out, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                start_new_session=True)  # fmt: skip


def stop(process: subprocess.Popen) -> None:
    """SIGINT to the process group (rospy's and roslaunch's clean shutdown), SIGKILL if it lingers."""
    stop_group(process, 60)


#: one worker computes the module's expensive fixture once (pytest-xdist, --dist loadgroup)
pytestmark = pytest.mark.xdist_group("ros1-node")


@pytest.fixture(scope="module")
def ros_world(ros1, tmp_path_factory):
    """A master, this process as a rospy node, and `symfruit ros` as a subprocess, all connected."""
    rospy = ros1
    from sensor_msgs.msg import CameraInfo, Image, PointCloud2
    from visualization_msgs.msg import MarkerArray

    from symfruit.ros.master import RosMaster
    from symfruit.ros.ros1_msgs import load_vision_msgs

    home = tmp_path_factory.mktemp("ros")
    master = RosMaster(home=home).start()
    node = None
    log = home / "node.log"
    mp = pytest.MonkeyPatch()  # rospy reads the master's address from the environment: keep it for the module
    try:
        for key in ("ROS_MASTER_URI", "ROS_HOSTNAME", "ROS_HOME", "ROS_LOG_DIR"):
            mp.setenv(key, master.env[key])
        mp.delenv("ROS_IP", raising=False)
        rospy.init_node("symfruit_test_player", anonymous=True, disable_signals=True)
        vm = load_vision_msgs()
        inbox = {"detections": Inbox(), "markers": Inbox(lambda m: m.markers[0]), "points": Inbox()}
        subs = [
            rospy.Subscriber(f"{NODE}/detections", vm.Detection3DArray, inbox["detections"]),
            rospy.Subscriber(f"{NODE}/markers", MarkerArray, inbox["markers"]),
            rospy.Subscriber(f"{NODE}/fruit_points", PointCloud2, inbox["points"]),
        ]
        pubs = [
            rospy.Publisher("/camera/color/image_raw", Image, queue_size=10),
            rospy.Publisher("/camera/aligned_depth_to_color/image_raw", Image, queue_size=10),
            rospy.Publisher("/camera/color/camera_info", CameraInfo, queue_size=10),
        ]
        env = {**master.env, "PYTHONUNBUFFERED": "1"}
        cmd = [sys.executable, "-m", "symfruit", "ros", f"__name:={NODE[1:]}", "_fruit:=strawberry"]
        node = start(cmd, env, log)
        wait_until(lambda: all(p.get_num_connections() > 0 for p in pubs), "the node to subscribe", node, log)
        wait_until(lambda: all(s.get_num_connections() > 0 for s in subs), "the node's topics", node, log)
        wait_until(lambda: LISTENING in log.read_text(errors="replace"), "the node to listen", node, log)
        yield {"rospy": rospy, "vm": vm, "pubs": pubs, "inbox": inbox, "process": node, "log": log, "master": master}
    finally:
        if node is not None:
            stop(node)
        shutdown_rospy(rospy, "tests done")
        master.close()
        mp.undo()


def shutdown_rospy(rospy: Any, reason: str) -> None:
    """``rospy.signal_shutdown``, and the end of its XML-RPC server's thread: rospy closes the server's socket but
    leaves ``serve_forever`` running, which then polls the closed socket without pause, half a core or more for as
    long as this process lives (the pytest-xdist worker: the rest of the run)."""
    from rosgraph.xmlrpc import XmlRpcNode

    nodes = [getattr(h, "__self__", None) for h in rospy.core._shutdown_hooks]
    servers = [n.server for n in nodes if isinstance(n, XmlRpcNode) and n.server is not None]
    rospy.signal_shutdown(reason)
    for server in servers:
        server.shutdown()  # serve_forever returns at its next poll; rospy's loop around it sees its own shutdown


def example_messages(images, stamp, *, color_encoding="rgb8", depth_encoding="16UC1", corrupt=False):
    from sensor_msgs.msg import CameraInfo, Image
    from std_msgs.msg import Header

    rgb, raw, cam = images
    h, w = raw.shape
    color = rgb if color_encoding == "rgb8" else np.ascontiguousarray(rgb[:, :, ::-1])
    depth = raw if depth_encoding == "16UC1" else (raw.astype(np.float32) * np.float32(0.001)).astype("<f4")
    data = color.tobytes()
    if corrupt:
        data = data[: len(data) // 2]  # truncated: half the rows are missing

    def head():
        return Header(stamp=stamp, frame_id=FRAME_ID)

    cmsg = Image(header=head(), height=h, width=w, encoding=color_encoding, is_bigendian=0, step=w * 3, data=data)
    dmsg = Image(header=head(), height=h, width=w, encoding=depth_encoding, is_bigendian=0, step=w * depth.itemsize,
                 data=depth.tobytes())  # fmt: skip
    info = CameraInfo(header=head(), height=h, width=w, distortion_model="plumb_bob", D=[0.0] * 5,
                      K=[cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1], R=[1.0, 0, 0, 0, 1, 0, 0, 0, 1],
                      P=[cam.fx, 0, cam.cx, 0, 0, cam.fy, cam.cy, 0, 0, 0, 1, 0])  # fmt: skip
    return cmsg, dmsg, info


def play(world, images, stamp, *, pubs=None, **kw) -> None:
    for pub, msg in zip(pubs or world["pubs"], example_messages(images, stamp, **kw), strict=True):
        pub.publish(msg)


@pytest.mark.parametrize(("color_encoding", "depth_encoding", "secs"), [("rgb8", "16UC1", 100), ("bgr8", "32FC1", 200)])
def test_detections_equal_symfruit_detect(ros_world, example_images, detect_json, color_encoding, depth_encoding,
                                          secs):  # fmt: skip
    from symfruit.ros.ros1_msgs import UPSTREAM_MD5

    stamp = ros_world["rospy"].Time(secs, 123456789)
    play(ros_world, example_images, stamp, color_encoding=color_encoding, depth_encoding=depth_encoding)
    msg = ros_world["inbox"]["detections"].wait(stamp, f"detections at {stamp}", ros_world)
    assert msg._connection_header["type"] == "vision_msgs/Detection3DArray"
    assert msg._connection_header["md5sum"] == UPSTREAM_MD5["vision_msgs/Detection3DArray"]
    assert msg.header.stamp == stamp and msg.header.frame_id == FRAME_ID
    expected = [e for e in detect_json["fruits"] if "error" not in e]  # what `symfruit detect` wrote
    assert len(msg.detections) == len(expected) > 0
    for det, fruit in zip(msg.detections, expected, strict=True):
        assert det.header.stamp == stamp and det.header.frame_id == FRAME_ID
        c, s, bbox = det.bbox.center.position, det.bbox.size, fruit["bbox"]
        np.testing.assert_allclose([c.x, c.y, c.z], fruit["centre"], rtol=0, atol=1e-6)
        np.testing.assert_allclose([s.x, s.y, s.z], [bbox["size"][k] for k in "xyz"], rtol=0, atol=1e-6)
        (hyp,) = det.results
        assert hyp.id == fruit["id"] and hyp.score == pytest.approx(fruit["confidence"], abs=1e-9)
        p = hyp.pose.pose.position
        np.testing.assert_allclose([p.x, p.y, p.z], fruit["centre"], rtol=0, atol=1e-6)
    line, log = f"frame {secs}.123456789: {len(expected)} fruit in", ros_world["log"]  # its latency, logged after
    wait_until(lambda: line in log.read_text(errors="replace"), "the frame's latency line", ros_world["process"], log)


def test_markers_and_points_arrive(ros_world, example_images, example_fruits):
    from visualization_msgs.msg import Marker

    stamp = ros_world["rospy"].Time(300, 5)
    play(ros_world, example_images, stamp)
    markers = ros_world["inbox"]["markers"].wait(stamp, f"markers at {stamp}", ros_world)
    cloud = ros_world["inbox"]["points"].wait(stamp, f"points at {stamp}", ros_world)
    assert markers.markers[0].action == Marker.DELETEALL  # the first marker of the array clears the last frame
    assert len(markers.markers) == 1 + 3 * len(example_fruits)
    assert all(m.header.frame_id == FRAME_ID and m.header.stamp == stamp for m in markers.markers)
    assert cloud.header.frame_id == FRAME_ID and cloud.point_step == 20
    assert cloud.width == sum(len(f.points) for f in example_fruits)


def test_a_corrupt_image_is_survived(ros_world, example_images, example_fruits):
    rospy, node, log = ros_world["rospy"], ros_world["process"], ros_world["log"]
    bad, good = rospy.Time(400, 0), rospy.Time(401, 0)
    play(ros_world, example_images, bad, corrupt=True)
    line = f"frame {bad.secs}.{bad.nsecs:09d} skipped"
    wait_until(lambda: line in log.read_text(errors="replace"), "the node to log the corrupt frame", node, log)
    assert "image data holds" in log.read_text(errors="replace")  # the reason, from the decoder
    play(ros_world, example_images, good)
    got = ros_world["inbox"]["detections"].wait(good, "detections after the corrupt frame", ros_world)
    assert len(got.detections) == len(example_fruits)
    for kind in ("detections", "markers", "points"):  # nothing at all for the bad frame
        assert ros_world["inbox"][kind].get(bad) is None
    assert node.poll() is None


def test_launch_file_runs_the_node_with_remapped_inputs(ros_world, example_images, example_fruits, require_ros):
    """roslaunch ros/symfruit/launch/symfruit.launch, the package on ROS_PACKAGE_PATH, inputs remapped."""
    from sensor_msgs.msg import CameraInfo, Image

    roslaunch = shutil.which("roslaunch")
    if roslaunch is None:
        require_ros("no roslaunch: apt-get install python3-roslaunch")
    rospy, master = ros_world["rospy"], ros_world["master"]
    pubs = [
        rospy.Publisher("/launch/color", Image, queue_size=10),
        rospy.Publisher("/launch/depth", Image, queue_size=10),
        rospy.Publisher("/launch/camera_info", CameraInfo, queue_size=10),
    ]
    inbox = Inbox()
    sub = rospy.Subscriber("/symfruit_launched/detections", ros_world["vm"].Detection3DArray, inbox)
    env = {**master.env, "ROS_PACKAGE_PATH": str(REPO / "ros"), "PYTHONUNBUFFERED": "1",
           "SYMFRUIT": str(Path(sys.executable).with_name("symfruit"))}  # fmt: skip
    log = master.home / "roslaunch.log"
    cmd = [roslaunch, str(REPO / "ros" / "symfruit" / "launch" / "symfruit.launch"), "node_name:=symfruit_launched",
           "color:=/launch/color", "depth:=/launch/depth", "camera_info:=/launch/camera_info"]  # fmt: skip
    launcher = start(cmd, env, log)
    try:
        ready = lambda: all(p.get_num_connections() > 0 for p in pubs) and sub.get_num_connections() > 0  # noqa: E731
        wait_until(ready, "the launched node to connect", launcher, log)
        wait_until(lambda: LISTENING in log.read_text(errors="replace"), "the launched node to listen", launcher, log)
        stamp = rospy.Time(500, 0)
        play(ros_world, example_images, stamp, pubs=pubs)
        got = inbox.wait(stamp, "detections from the launched node", {"process": launcher, "log": log})
        assert len(got.detections) == len(example_fruits)
        for det, fruit in zip(got.detections, example_fruits, strict=True):
            c = det.bbox.center.position
            np.testing.assert_allclose([c.x, c.y, c.z], fruit.centre, rtol=0, atol=1e-6)
    finally:
        stop(launcher)  # roslaunch stops its nodes
        sub.unregister()
        for p in pubs:
            p.unregister()


def test_private_parameters_are_checked_as_the_ros2_nodes_are():
    from symfruit.ros.node import private_parameters

    def get_param(values):
        return lambda name, default: values.get(name, default)

    p = private_parameters(get_param({"~slop": 1, "~queue_size": 3.0, "~fruit": "apple"}))
    assert (p["slop"], p["queue_size"], p["fruit"], p["masks"]) == (1.0, 3, "apple", "auto")
    for values, message in [  # before: int("abc") a ValueError's traceback; 0, -1 or 1e9 handed to message_filters
        ({"~queue_size": "abc"}, "parameter queue_size: expected a whole number, got 'abc'"),
        ({"~queue_size": 0}, "parameter queue_size: expected 1 to 100, got 0"),
        ({"~queue_size": 10**400}, r"parameter queue_size: expected 1 to 100, got 10{11}\.\.\. \(401 digits\)"),
        ({"~slop": -1.0}, r"parameter slop: expected seconds in \[0, 10\], got -1\.0"),
        ({"~depth_scale": "mm"}, "parameter depth_scale: expected a number, got 'mm'"),
    ]:
        with pytest.raises(SymfruitError, match="^" + message):
            private_parameters(get_param(values))


def test_a_private_parameter_the_node_does_not_have_is_refused_by_name():
    """`_metod:=paper` set /symfruit/metod, which nothing read: the default method ran, unsaid."""
    from symfruit.ros.node import given_private_names, private_parameters

    names = ["/rosdistro", "/symfruit/metod", "/symfruit/fruit", "/symfruit/config/x", "/symfruit_other/a"]
    given = given_private_names(names, "/symfruit")
    assert given == ["config", "fruit", "metod"]
    with pytest.raises(SymfruitError, match=r"^parameter 'metod': no such parameter \(did you mean 'method'\?\)"):
        private_parameters(lambda name, default: default, given)
    with pytest.raises(SymfruitError, match=r"^parameter 'qos': no such parameter"):  # ROS 1 has none
        private_parameters(lambda name, default: default, ["qos"])
    assert private_parameters(lambda name, default: default, ["fruit", "slop"])["fruit"] == "strawberry"
    for value, hint in ((["a.yaml"], ""), ({"a": 1}, ""), (True, " (quote it")):
        with pytest.raises(SymfruitError, match=rf"^parameter config: expected text, got .*{re.escape(hint)}"):
            private_parameters(lambda name, default, v=value: v if name == "~config" else default)
