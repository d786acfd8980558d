"""A stand-in RealSense camera on ROS 2, and a listener of the node's outputs: ``python -m symfruit.ros.camera2``.

For the tests, the benchmark and trying ``symfruit ros2`` without a camera; the rclpy side runs in the ROS 2
venv (``make ros2-env``), the client side (:class:`CameraClient`, :func:`domain_lease`, :func:`isolated_env`)
anywhere, without ROS:

- :class:`Camera` publishes a frame (the example frame by default) as the realsense2_camera wrapper does: on
  its default topics (:data:`symfruit.ros.node2.DEFAULT_TOPICS`), images with its ``SYSTEM_DEFAULT`` QoS
  (reliable), camera info with ``DEFAULT``; colour rgb8 or bgr8, aligned depth 16UC1 millimetres or 32FC1
  metres, every header the same stamp and ``camera_color_optical_frame``. :func:`frame_messages` can also
  spoil a frame (:data:`SPOILS`: truncated, mis-encoded, sizes that disagree, stamps apart) to check a node
  survives it;
- :class:`Listener` keeps the node's ``detections``, ``markers`` and ``fruit_points`` by header stamp, as
  plain data (:func:`as_data`);
- ``serve``: both, driven by JSON lines on stdin, one JSON reply per line on stdout (:class:`CameraClient`
  is the other end); ``play FRAME``: publish a frame folder at ``--rate`` Hz until interrupted.

Its writers repair a lost fragment of a frame within 50 ms (:func:`writer_profile`): on Fast DDS's defaults a
1.5 MB frame between two processes here often loses a fragment, repaired only at the next 3 s heartbeat.

Every DDS process of a test gets ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` and a ``ROS_DOMAIN_ID`` leased
for it alone (:func:`domain_lease`), so nothing leaves the machine and parallel tests never hear each other.
"""

from __future__ import annotations

import argparse
import array
import contextlib
import fcntl
import json
import math
import os
import queue
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import IO, Any

import numpy as np

from .master import stop_group
from .node2 import DEFAULT_TOPICS, NODE_NAME

__all__ = [
    "OUTPUTS",
    "SPOILS",
    "Camera",
    "CameraClient",
    "Listener",
    "as_data",
    "domain_lease",
    "frame_messages",
    "isolated_env",
    "main",
    "use_writer_profile",
    "writer_profile",
]

FRAME_ID = "camera_color_optical_frame"
#: The node's outputs by short name (relative to the node, ``/symfruit/...`` by default).
OUTPUTS = ("detections", "markers", "fruit_points")
#: What :func:`frame_messages` can spoil, each a way a frame reaches a node broken.
SPOILS = (
    "truncated_color",  # half of the colour image's data
    "truncated_depth",  # half of the depth image's data
    "color_encoding",  # colour claims yuv420 (a layout no reader decodes)
    "depth_encoding",  # depth claims rgb8 (a colour image on the depth topic)
    "short_step",  # colour step shorter than a row
    "huge_claim",  # colour claims 16384 x 16384 pixels, with the data of 640 x 480
    "size_mismatch",  # depth of half the colour's width
    "zero_k",  # camera info with K all zero
    "nan_depth",  # 32FC1 depth all NaN
)
DOMAINS = range(1, 102)  # 0 left to the user's robot; ROS 2 advises <= 101 on Linux (ephemeral ports)


# --------------------------------------------------------------------------------------------------
# without ROS: domains, environments, the client
# --------------------------------------------------------------------------------------------------


@contextlib.contextmanager
def domain_lease(lock_dir: Path | None = None) -> Iterator[int]:
    """A ``ROS_DOMAIN_ID`` no other lease holder on this machine has while the ``with`` lasts (an ``flock``
    per id in ``lock_dir``, default the temporary folder); the search starts at an id drawn from the pid."""
    folder = Path(lock_dir or tempfile.gettempdir())
    start = os.getpid() % len(DOMAINS)
    for k in range(len(DOMAINS)):
        domain = DOMAINS[(start + k) % len(DOMAINS)]
        handle = open(folder / f"symfruit-ros2-domain-{domain}.lock", "a+")  # held while leased
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            handle.close()
            continue
        try:
            yield domain
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)
            handle.close()
        return
    raise RuntimeError(f"every ROS domain id {DOMAINS.start}-{DOMAINS.stop - 1} is leased on this machine")


#: Variables that would take a DDS process elsewhere than this machine's loopback, or change the middleware.
_FOREIGN = ("ROS_LOCALHOST_ONLY", "ROS_STATIC_PEERS", "ROS_DISCOVERY_SERVER", "ROS_SUPER_CLIENT",
            "FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE", "FASTDDS_ENVIRONMENT_FILE",
            "CYCLONEDDS_URI", "ROS_SECURITY_ENABLE", "ROS_MASTER_URI", "ROS_NAMESPACE")  # fmt: skip


def isolated_env(domain: int, log_dir: Path, base: Mapping[str, str] | None = None) -> dict[str, str]:
    """The environment of a DDS process of a test: ``base`` (default ``os.environ``) with discovery on this
    machine only, the leased domain, Fast DDS, logs into ``log_dir``, unbuffered output."""
    env = {k: v for k, v in (os.environ if base is None else base).items() if k not in _FOREIGN}
    env.update(
        ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
        ROS_DOMAIN_ID=str(int(domain)),
        RMW_IMPLEMENTATION="rmw_fastrtps_cpp",
        ROS_LOG_DIR=str(log_dir),
        ROS_HOME=str(log_dir),
        PYTHONUNBUFFERED="1",
        RCUTILS_COLORIZED_OUTPUT="0",
        RCUTILS_LOGGING_BUFFERED_STREAM="0",  # each log line reaches the log file at once
    )
    return env


class CameraClient:
    """The other end of ``python -m symfruit.ros.camera2 serve``: one request, one reply, in order.

    Parameters
    ----------
    python : path
        The ROS 2 venv's interpreter.
    env : mapping
        Its environment (:func:`isolated_env`).
    log : path
        Where its stderr goes.
    node : str
        Name of the node whose outputs to listen to.
    """

    def __init__(self, python: str | Path, env: Mapping[str, str], log: Path, *, node: str = NODE_NAME) -> None:
        self.log = Path(log)
        with open(self.log, "wb") as err:
            self.process = subprocess.Popen(
                [str(python), "-m", "symfruit.ros.camera2", "serve", "--node", node],
                env=dict(env), stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=err, text=True,
                start_new_session=True,
            )  # fmt: skip
        self._replies: queue.Queue[str | None] = queue.Queue()
        self._ended = False  # the process closed its output
        self._reader = threading.Thread(target=self._read, args=(self.process.stdout,), daemon=True)
        self._reader.start()

    def _read(self, stream: IO[str]) -> None:
        for line in stream:
            self._replies.put(line)
        self._replies.put(None)  # the process closed its output

    def call(self, op: str, *, deadline: float = 120.0, **args: Any) -> dict:
        """Send ``op`` with ``args``; the reply (``{"ok": ..., ...}``). Raises ``RuntimeError`` when the process
        ends or does not answer within ``deadline`` seconds (its log in the message)."""
        assert self.process.stdin is not None
        if self._ended:
            raise RuntimeError(f"the camera process has ended; its log:\n{self.tail()}")
        try:
            self.process.stdin.write(json.dumps({"op": op, **args}) + "\n")
            self.process.stdin.flush()
        except (BrokenPipeError, OSError):
            raise RuntimeError(f"the camera process has ended; its log:\n{self.tail()}") from None
        try:
            line = self._replies.get(timeout=deadline)
        except queue.Empty:
            raise RuntimeError(f"no answer to {op} in {deadline:.0f} s; its log:\n{self.tail()}") from None
        if line is None:
            self._ended = True
            raise RuntimeError(f"the camera process ended during {op}; its log:\n{self.tail()}")
        return json.loads(line)

    def tail(self) -> str:
        return self.log.read_text(errors="replace")[-4000:] if self.log.is_file() else "(no log)"

    def close(self, timeout: float = 60.0) -> int | None:
        """Ask the process to quit (it destroys its node and context), else stop it; its exit status."""
        if self.process.poll() is None:
            with contextlib.suppress(RuntimeError):
                self.call("quit", deadline=timeout)
            try:
                self.process.wait(timeout)
            except subprocess.TimeoutExpired:
                stop_group(self.process, timeout)
        return self.process.returncode


# --------------------------------------------------------------------------------------------------
# with ROS: the camera, the listener, the server
# --------------------------------------------------------------------------------------------------


def writer_profile() -> Path:
    """The shipped Fast DDS profile of a camera process (``fastdds_writer.xml``: a 50 ms heartbeat, so that a lost
    fragment of a frame is sent again within ~50 ms instead of Fast DDS's default 3 s)."""
    from importlib import resources

    return Path(str(resources.files(__package__) / "fastdds_writer.xml"))


def use_writer_profile() -> None:
    """Give this process's DDS writers :func:`writer_profile`, unless a profile file is set already; call before
    ``rclpy.init``. (Only the camera side: the node runs on Fast DDS's defaults, as it would beside a camera.)"""
    os.environ.setdefault("FASTDDS_DEFAULT_PROFILES_FILE", str(writer_profile()))


def _bytes(data: bytes) -> array.array:
    return array.array("B", data)  # rclpy takes a uint8 array without checking every element


def frame_messages(
    images: tuple[np.ndarray, np.ndarray, Any],
    sec: int,
    nanosec: int = 0,
    *,
    color: str = "rgb8",
    depth: str = "16UC1",
    spoil: str | None = None,
    depth_stamp: tuple[int, int] | None = None,
) -> tuple[Any, Any, Any]:
    """``(Image, Image, CameraInfo)`` of ``images`` (RGB uint8, depth uint16 millimetres, Camera) as the RealSense
    wrapper publishes them, stamped ``sec.nanosec`` (the depth image ``depth_stamp`` when given), optionally
    spoilt (:data:`SPOILS`)."""
    from builtin_interfaces.msg import Time
    from sensor_msgs.msg import CameraInfo, Image
    from std_msgs.msg import Header

    if spoil is not None and spoil not in SPOILS:
        raise ValueError(f"unknown spoil {spoil!r}; one of {', '.join(SPOILS)}")
    rgb, raw, cam = images
    h, w = raw.shape
    pixels = rgb if color == "rgb8" else np.ascontiguousarray(rgb[:, :, ::-1])
    if depth == "16UC1":
        depth_px: np.ndarray = raw
    else:
        depth_px = (raw.astype(np.float32) * np.float32(0.001)).astype("<f4")
        if spoil == "nan_depth":
            depth_px = np.full_like(depth_px, np.nan)
    cdata, ddata = pixels.tobytes(), depth_px.tobytes()
    cstep, dstep, cw, ch, dw = w * 3, w * depth_px.itemsize, w, h, w
    if spoil == "truncated_color":
        cdata = cdata[: len(cdata) // 2]
    elif spoil == "truncated_depth":
        ddata = ddata[: len(ddata) // 2]
    elif spoil == "color_encoding":
        color = "yuv420"
    elif spoil == "depth_encoding":
        depth, ddata, dstep = "rgb8", cdata, cstep
    elif spoil == "short_step":
        cstep = w
    elif spoil == "huge_claim":
        cw, ch, cstep = 16384, 16384, 16384 * 3
    elif spoil == "size_mismatch":
        dw = w // 2
        ddata = np.ascontiguousarray(depth_px[:, :dw]).tobytes()
        dstep = dw * depth_px.itemsize

    def header(stamp: tuple[int, int]) -> Any:
        return Header(stamp=Time(sec=stamp[0], nanosec=stamp[1]), frame_id=FRAME_ID)

    k = [cam.fx, 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0]
    if spoil == "zero_k":
        k = [0.0] * 9
    cmsg = Image(header=header((sec, nanosec)), height=ch, width=cw, encoding=color, is_bigendian=0, step=cstep,
                 data=_bytes(cdata))  # fmt: skip
    dmsg = Image(header=header(depth_stamp or (sec, nanosec)), height=h, width=dw, encoding=depth, is_bigendian=0,
                 step=dstep, data=_bytes(ddata))  # fmt: skip
    p = [cam.fx, 0.0, cam.cx, 0.0, 0.0, cam.fy, cam.cy, 0.0, 0.0, 0.0, 1.0, 0.0]
    info = CameraInfo(header=header((sec, nanosec)), height=h, width=w, distortion_model="plumb_bob", d=[0.0] * 5,
                      k=k, r=[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], p=p)  # fmt: skip
    return cmsg, dmsg, info


class Camera:
    """Publishers of the RealSense wrapper's three topics on ``node`` (its QoS: images reliable)."""

    def __init__(self, node: Any, images: tuple[np.ndarray, np.ndarray, Any] | None = None) -> None:
        from rclpy.qos import QoSProfile, qos_profile_system_default
        from sensor_msgs.msg import CameraInfo, Image

        from .bench import example_images

        self.images = images if images is not None else example_images()
        self.publishers = [
            node.create_publisher(Image, DEFAULT_TOPICS["color"], qos_profile_system_default),
            node.create_publisher(Image, DEFAULT_TOPICS["depth"], qos_profile_system_default),
            node.create_publisher(CameraInfo, DEFAULT_TOPICS["camera_info"], QoSProfile(depth=10)),
        ]

    def matched(self) -> bool:
        """Whether something subscribes to all three topics."""
        return all(p.get_subscription_count() > 0 for p in self.publishers)

    def publish(self, sec: int, nanosec: int = 0, *, skip: tuple[str, ...] = (), **kw: Any) -> float:
        """Publish a frame (:func:`frame_messages` arguments) except the ``skip`` topics; ``time.perf_counter()``
        just before the first message went out."""
        msgs = frame_messages(self.images, sec, nanosec, **kw)
        t = time.perf_counter()
        for name, pub, msg in zip(DEFAULT_TOPICS, self.publishers, msgs, strict=True):
            if name not in skip:
                pub.publish(msg)
        return t


def _xyz(v: Any) -> list[float]:
    return [v.x, v.y, v.z]


def _head(h: Any) -> dict:
    return {"sec": h.stamp.sec, "nanosec": h.stamp.nanosec, "frame_id": h.frame_id}


def as_data(kind: str, msg: Any) -> dict:
    """A message of the node's ``kind`` output (:data:`OUTPUTS`) as plain, JSON-ready data."""
    if kind == "detections":
        dets = []
        for d in msg.detections:
            dets.append({
                "header": _head(d.header), "id": d.id, "centre": _xyz(d.bbox.center.position),
                "orientation": [*_xyz(d.bbox.center.orientation), d.bbox.center.orientation.w],
                "size": _xyz(d.bbox.size),
                "results": [{"class_id": r.hypothesis.class_id, "score": r.hypothesis.score,
                             "position": _xyz(r.pose.pose.position)} for r in d.results],
            })  # fmt: skip
        return {"header": _head(msg.header), "detections": dets}
    if kind == "markers":
        return {"markers": [{"header": _head(m.header), "ns": m.ns, "id": m.id, "type": m.type, "action": m.action,
                             "position": _xyz(m.pose.position), "scale": _xyz(m.scale)}
                            for m in msg.markers]}  # fmt: skip
    if kind == "fruit_points":
        return {"header": _head(msg.header), "width": msg.width, "height": msg.height, "point_step": msg.point_step,
                "fields": [f.name for f in msg.fields], "bytes": len(msg.data)}  # fmt: skip
    raise ValueError(f"unknown output {kind!r}; one of {', '.join(OUTPUTS)}")


class Listener:
    """Subscriptions to the node's outputs; each message kept by its header stamp (markers: the first
    marker's), with the time it arrived, until :meth:`wait` hands it over."""

    def __init__(self, node: Any, prefix: str = f"/{NODE_NAME}", *, points: bool = True, markers: bool = True) -> None:
        from rclpy.qos import QoSProfile
        from sensor_msgs.msg import PointCloud2
        from vision_msgs.msg import Detection3DArray
        from visualization_msgs.msg import MarkerArray

        self.prefix = prefix
        self.cond = threading.Condition()
        self.got: dict[tuple[str, int, int], tuple[float, Any]] = {}
        kinds = {"detections": Detection3DArray, "markers": MarkerArray, "fruit_points": PointCloud2}
        self.subs = [
            node.create_subscription(kinds[k], f"{prefix}/{k}", self._keeper(k), QoSProfile(depth=10))
            for k in OUTPUTS
            if (points or k != "fruit_points") and (markers or k != "markers")
        ]

    def _keeper(self, kind: str) -> Any:
        def keep(msg: Any) -> None:
            head = msg.markers[0].header if kind == "markers" and msg.markers else getattr(msg, "header", None)
            if head is None:
                return
            with self.cond:
                self.got[(kind, head.stamp.sec, head.stamp.nanosec)] = (time.perf_counter(), msg)
                self.cond.notify_all()

        return keep

    def matched(self, node: Any) -> bool:
        """Whether the node publishes every output this listener subscribes to."""
        return all(node.count_publishers(s.topic_name) > 0 for s in self.subs)

    def wait(self, kind: str, sec: int, nanosec: int = 0, timeout: float = 120.0) -> tuple[float, Any] | None:
        """``(arrival time, message)`` of ``kind`` stamped ``sec.nanosec``, or None after ``timeout`` seconds."""
        key = (kind, int(sec), int(nanosec))
        with self.cond:
            if not self.cond.wait_for(lambda: key in self.got, timeout):
                return None
            return self.got[key]

    def seen(self, kind: str, sec: int, nanosec: int = 0) -> bool:
        with self.cond:
            return (kind, int(sec), int(nanosec)) in self.got


def _endpoints(infos: list) -> list[dict]:
    return [{"node": f"{i.node_namespace.rstrip('/')}/{i.node_name}", "type": i.topic_type,
             "hash": str(i.topic_type_hash), "reliability": i.qos_profile.reliability.name.lower()}
            for i in infos]  # fmt: skip


def serve(
    node_name: str = NODE_NAME, ros_args: list[str] | None = None, *, stdin: IO[str] = sys.stdin,
    stdout: IO[str] = sys.stdout,
) -> int:  # fmt: skip
    """Answer JSON lines until ``quit`` or end of input (see :class:`CameraClient`). Requests:

    ``ready`` (``timeout``): wait until the node subscribes to the camera and publishes its outputs;
    ``frame`` (``sec``, ``nanosec``, ``color``, ``depth``, ``spoil``, ``skip``, ``depth_stamp``): publish;
    ``wait`` (``kind``, ``sec``, ``nanosec``, ``timeout``): the output stamped so, as :func:`as_data`;
    ``seen`` (``kind``, ``sec``, ``nanosec``); ``graph``: publishers and subscriptions of the node's topics;
    ``endpoint`` (``topic``, ``node``, ``side``: ``subscription`` or ``publisher``, ``timeout``): that node's
    endpoints on the topic once discovery shows them; ``quit``.
    """
    import rclpy
    from rclpy.executors import SingleThreadedExecutor

    use_writer_profile()
    context = rclpy.Context()
    rclpy.init(args=["camera2", *(ros_args or [])], context=context)
    node = rclpy.create_node("symfruit_camera_standin", context=context)
    # graph queries by a node without the --ros-args remappings, which would otherwise apply to the names asked for
    observer = rclpy.create_node("symfruit_camera_observer", context=context, use_global_arguments=False)
    camera, listener = Camera(node), Listener(node, f"/{node_name}")
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()

    def answer(**reply: Any) -> None:
        stdout.write(json.dumps(reply) + "\n")
        stdout.flush()

    try:
        for line in stdin:
            req = json.loads(line)
            op = req.pop("op")
            if op == "quit":
                answer(ok=True)
                break
            if op == "ready":
                deadline = time.monotonic() + float(req.get("timeout", 120))
                while not (camera.matched() and listener.matched(node)) and time.monotonic() < deadline:
                    time.sleep(0.01)  # the graph has no event to wait on; checked every 10 ms
                answer(ok=camera.matched() and listener.matched(node))
            elif op == "frame":
                skip = tuple(req.pop("skip", ()))
                stamp = req.pop("depth_stamp", None)
                camera.publish(int(req.pop("sec")), int(req.pop("nanosec", 0)), skip=skip,
                               depth_stamp=tuple(stamp) if stamp else None, **req)  # fmt: skip
                answer(ok=True)
            elif op == "wait":
                got = listener.wait(req["kind"], req["sec"], req.get("nanosec", 0), float(req.get("timeout", 120)))
                answer(ok=got is not None, msg=None if got is None else as_data(req["kind"], got[1]))
            elif op == "seen":
                answer(ok=True, seen=listener.seen(req["kind"], req["sec"], req.get("nanosec", 0)))
            elif op == "endpoint":  # a node's subscription to (or publisher of) a topic, once discovery shows it
                get = observer.get_subscriptions_info_by_topic if req.get("side") == "subscription" else \
                    observer.get_publishers_info_by_topic  # fmt: skip
                deadline = time.monotonic() + float(req.get("timeout", 120))
                found: list[dict] = []
                while not found and time.monotonic() < deadline:
                    found = [e for e in _endpoints(get(req["topic"])) if e["node"] == req["node"]]
                    if not found:
                        time.sleep(0.01)  # the graph has no event to wait on; checked every 10 ms
                answer(ok=bool(found), endpoints=found)
            elif op == "graph":
                topics = [*DEFAULT_TOPICS.values(), *(f"/{node_name}/{k}" for k in OUTPUTS)]
                pubs = {t: _endpoints(observer.get_publishers_info_by_topic(t)) for t in topics}
                subs = {t: _endpoints(observer.get_subscriptions_info_by_topic(t)) for t in topics}
                answer(ok=True, publishers=pubs, subscriptions=subs)
            else:
                answer(ok=False, error=f"unknown op {op!r}")
    finally:
        executor.shutdown()
        observer.destroy_node()
        node.destroy_node()
        spinner.join(10)
        rclpy.try_shutdown(context=context)
        context.destroy()
    return 0


def play(frame: Path | None, rate: float, count: int, ros_args: list[str] | None = None) -> int:
    """Publish ``frame`` (a frame folder; the example frame by default) at ``rate`` Hz, ``count`` times (0: until
    SIGINT), stamped with the wall clock."""
    import rclpy
    from rclpy.executors import ExternalShutdownException

    images = None
    if frame is not None:
        from ..io.frames import read_frame

        f = read_frame(frame)
        images = (f.color, np.round(f.depth * 1000.0).astype("<u2"), f.camera)
    use_writer_profile()
    rclpy.init(args=["camera2", *(ros_args or [])])
    node = rclpy.create_node("symfruit_camera_standin")
    camera = Camera(node, images)
    sent = 0
    try:
        while rclpy.ok() and (count == 0 or sent < count):
            ns = time.time_ns()
            camera.publish(ns // 1_000_000_000, ns % 1_000_000_000)
            sent += 1
            rclpy.spin_once(node, timeout_sec=max(0.0, 1.0 / rate - (time.time_ns() - ns) / 1e9))
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    print(f"published {sent} frames on {', '.join(DEFAULT_TOPICS.values())}", file=sys.stderr)
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    cut = argv.index("--ros-args") if "--ros-args" in argv else len(argv)
    argv, ros_args = argv[:cut], argv[cut:]
    parser = argparse.ArgumentParser(prog="python -m symfruit.ros.camera2", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("serve", help="answer JSON lines on stdin (tests, benchmark)")
    p.add_argument("--node", default=NODE_NAME, help="name of the node whose outputs to listen to")
    p = sub.add_parser("play", help="publish a frame folder (default: the example frame) as a RealSense camera")
    p.add_argument("frame", type=Path, nargs="?")
    from ..cli import _real, _whole  # ASCII digits alone, as every symfruit number option (stop 56)

    p.add_argument("--rate", type=_real, default=5.0, help="frames per second (default 5)")
    p.add_argument("--count", type=_whole, default=0, help="frames to publish (default 0: until Ctrl-C)")
    args = parser.parse_args(argv)
    if args.command == "serve":
        return serve(args.node, ros_args)
    if not (args.rate > 0 and math.isfinite(args.rate)):
        parser.error("--rate must be a positive number of frames per second")
    if args.count < 0:
        parser.error(f"--count must be 0 (until Ctrl-C) or more frames, got {args.count}")
    return play(args.frame, args.rate, args.count, ros_args)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
