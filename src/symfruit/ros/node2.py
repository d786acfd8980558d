"""``symfruit ros2``: the ROS 2 node (rclpy), a thin wrapper around :mod:`symfruit.ros.core`.

Subscribes to the realsense2_camera ROS 2 wrapper's default topics (``ros2 launch realsense2_camera
rs_launch.py align_depth.enable:=true``), paired by approximate time (:class:`~symfruit.ros.sync.ApproximateSync`):

- ``color``       ``sensor_msgs/msg/Image`` rgb8/bgr8/rgba8/bgra8/mono8 (``/camera/camera/color/image_raw``)
- ``depth``       ``sensor_msgs/msg/Image`` 16UC1 mm or 32FC1 m, aligned to colour
  (``/camera/camera/aligned_depth_to_color/image_raw``)
- ``camera_info`` ``sensor_msgs/msg/CameraInfo`` (``/camera/camera/color/camera_info``)

(remap either the short name, ``-r color:=/my/image``, or the default itself) and publishes, per frame and
with the colour image's header:

- ``~/detections``   ``vision_msgs/msg/Detection3DArray`` (upstream's type and type hash, built by ``make
  ros2-env``): per fruit a ``Detection3D`` with ``id`` = the fruit's id in ``detections.json``, ``bbox`` =
  the completed fruit's box (centre, size), one result with ``hypothesis.class_id`` = the fruit profile,
  ``hypothesis.score`` = its confidence and ``pose`` = the centre;
- ``~/markers``      ``visualization_msgs/msg/MarkerArray``: DELETEALL, then per fruit a translucent box
  (``symfruit/box``, CUBE) and a centre sphere (``symfruit/centre``, SPHERE), both with the fruit's id;
- ``~/fruit_points`` ``sensor_msgs/msg/PointCloud2`` (x, y, z, fruit, completed) of the completed clouds,
  built only while someone subscribes.

Parameters (``--ros-args -p name:=value``, read at start): ``method`` (the default method), ``fruit``
(strawberry), ``config`` (settings file, ""), ``masks`` (auto), resolved as on the command line;
``depth_scale`` (0.001 m per 16UC1 unit), ``slop`` (0.05 s), ``queue_size`` (5), ``qos`` (``reliable``, as
the RealSense wrapper publishes; ``sensor_data`` for best effort), ``fruit_processes`` (1: a worker process kept to
share each frame's fruit with, :class:`symfruit.fruitpool.FruitPool`; 0 for none). A frame that cannot be used is logged
and skipped; frames arriving while one is processed are dropped (only the newest waits). SIGINT and
SIGTERM end it cleanly (node and context destroyed). Everything but rclpy lives in :mod:`symfruit.ros.core`.
"""

from __future__ import annotations

import array
import copy
import os
import signal
import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..errors import SymfruitError
from ..methods import DEFAULT_METHOD
from .core import (
    PARAMETERS,
    QOS_CHOICES,
    FrameProcessor,
    Fruit,
    LatestOnly,
    Overlapped,
    Processed,
    checked_parameters,
    stop_signals,
    unknown_parameters,
)
from .node import BOX_RGBA, CENTRE_DIAMETER, CENTRE_RGBA, CLOUD_FIELDS, cloud_array
from .sync import ApproximateSync

__all__ = ["DEFAULT_TOPICS", "NODE_NAME", "PARAMETERS", "QOS_CHOICES", "Ros2Node", "main", "stamp_text"]

NODE_NAME = "symfruit"
DEFAULT_TOPICS = {
    "color": "/camera/camera/color/image_raw",
    "depth": "/camera/camera/aligned_depth_to_color/image_raw",
    "camera_info": "/camera/camera/color/camera_info",
}


def require_rclpy() -> Any:
    """``rclpy``, or a :class:`SymfruitError` naming how to get ROS 2 (``make ros2-env``)."""
    try:
        import rclpy
        import sensor_msgs.msg  # noqa: F401
        import visualization_msgs.msg  # noqa: F401
    except ImportError as exc:
        raise SymfruitError(
            f"`symfruit ros2` needs ROS 2's rclpy ({exc}); `make ros2-env` builds .venv-ros2 with it and vision_msgs: "
            "run .venv-ros2/bin/symfruit ros2"
        ) from None
    return rclpy


def require_vision_msgs() -> Any:
    """``vision_msgs.msg``, or a :class:`SymfruitError` naming ``make ros2-env``, which builds it."""
    try:
        import vision_msgs.msg
    except ImportError as exc:
        raise SymfruitError(
            f"`symfruit ros2` needs vision_msgs built from the shipped upstream definitions ({exc}); "
            "`make ros2-env` (or `python -m symfruit.ros.ros2env --here` in a venv with symfruit[ros2]) builds it"
        ) from None
    return vision_msgs.msg


def stamp_text(header: Any) -> str:
    """``sec.nanosec`` of a header's stamp, as the node's log lines name frames."""
    return f"{header.stamp.sec}.{header.stamp.nanosec:09d}"


# --------------------------------------------------------------------------------------------------
# messages (ROS 2 classes; the content is what core.Fruit holds)
# --------------------------------------------------------------------------------------------------


def _pose(centre: Any) -> Any:
    """A pose at ``centre``, unrotated. The builders below hand one such object to every field that holds it: rclpy
    serialises fields by value, and none is changed after building (fewer objects: a frame is built in ~1 ms)."""
    from geometry_msgs.msg import Point, Pose, Quaternion

    x, y, z = (float(v) for v in centre)
    return Pose(position=Point(x=x, y=y, z=z), orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0))


def detection_array(vision_msgs: Any, header: Any, fruits: Sequence[Fruit], class_id: str) -> Any:
    """A ``vision_msgs/msg/Detection3DArray`` of the fruit, every header ``header``."""
    from geometry_msgs.msg import PoseWithCovariance, Vector3

    out = vision_msgs.Detection3DArray(header=header)
    for f in fruits:
        sx, sy, sz = (float(v) for v in f.size)
        pose = _pose(f.centre)
        hyp = vision_msgs.ObjectHypothesisWithPose(
            hypothesis=vision_msgs.ObjectHypothesis(class_id=class_id, score=float(f.score)),
            pose=PoseWithCovariance(pose=pose),
        )
        bbox = vision_msgs.BoundingBox3D(center=pose, size=Vector3(x=sx, y=sy, z=sz))
        out.detections.append(vision_msgs.Detection3D(header=header, results=[hyp], bbox=bbox, id=str(f.id)))
    return out


def marker_array(header: Any, fruits: Sequence[Fruit]) -> Any:
    """DELETEALL (clears the previous frame's markers), then a box and a centre sphere per fruit."""
    from geometry_msgs.msg import Vector3
    from std_msgs.msg import ColorRGBA
    from visualization_msgs.msg import Marker, MarkerArray

    box_rgba, centre_rgba = (ColorRGBA(r=c[0], g=c[1], b=c[2], a=c[3]) for c in (BOX_RGBA, CENTRE_RGBA))
    d = CENTRE_DIAMETER
    centre_scale = Vector3(x=d, y=d, z=d)
    # one Marker built per kind, then copied (shallow, its never-changed defaults shared): a Marker is ~20 fields
    box_kind = Marker(header=header, ns="symfruit/box", type=Marker.CUBE, action=Marker.ADD, color=box_rgba)
    dot_kind = Marker(header=header, ns="symfruit/centre", type=Marker.SPHERE, action=Marker.ADD, color=centre_rgba,
                      scale=centre_scale)  # fmt: skip
    out = MarkerArray()
    out.markers.append(Marker(header=header, action=Marker.DELETEALL))
    for f in fruits:
        sx, sy, sz = (max(float(v), 1e-4) for v in f.size)
        pose = _pose(f.centre)
        box, dot = copy.copy(box_kind), copy.copy(dot_kind)
        box.id = dot.id = int(f.id)
        box.pose = dot.pose = pose
        box.scale = Vector3(x=sx, y=sy, z=sz)
        out.markers.extend([box, dot])
    return out


def point_cloud(header: Any, fruits: Sequence[Fruit]) -> Any:
    """``sensor_msgs/msg/PointCloud2`` of :func:`~symfruit.ros.node.cloud_array` (x, y, z, fruit, completed)."""
    from sensor_msgs.msg import PointCloud2, PointField

    data = cloud_array(fruits)
    fields = [
        PointField(name=n, offset=4 * i, datatype=PointField.FLOAT32, count=1) for i, n in enumerate(CLOUD_FIELDS)
    ]
    step = 4 * len(CLOUD_FIELDS)
    return PointCloud2(header=header, height=1, width=len(data), fields=fields, is_bigendian=False, point_step=step,
                       row_step=step * len(data), data=array.array("B", data.tobytes()), is_dense=True)  # fmt: skip


# --------------------------------------------------------------------------------------------------
# parameters
# --------------------------------------------------------------------------------------------------


def class_id_of(fruit: str) -> str:
    """``class_id`` of every detection: the fruit profile's name (a profile file's stem), else ``fruit``."""
    return Path(fruit).stem if fruit else "fruit"


# --------------------------------------------------------------------------------------------------
# the node
# --------------------------------------------------------------------------------------------------


class Ros2Node:
    """The ``symfruit`` rclpy node: parameters, subscriptions, the synchroniser, the worker, the publishers.

    Parameters
    ----------
    context : rclpy.context.Context
        An initialised context (``rclpy.init(args=..., context=context)``: ``--ros-args`` come from there).

    Raises
    ------
    SymfruitError
        For a bad parameter (the node is destroyed again first).
    """

    def __init__(self, context: Any) -> None:
        rclpy = require_rclpy()
        self.vision_msgs = require_vision_msgs()
        from rcl_interfaces.msg import ParameterDescriptor
        from rclpy.node import Node
        from rclpy.qos import QoSProfile, qos_profile_sensor_data
        from sensor_msgs.msg import CameraInfo, Image, PointCloud2
        from visualization_msgs.msg import MarkerArray

        self.rclpy, self.context = rclpy, context
        self.node = Node(NODE_NAME, context=context)
        try:
            for name, (default, text) in PARAMETERS.items():  # dynamic typing: `-p slop:=1` is 1 s, not an error
                self.node.declare_parameter(name, default, ParameterDescriptor(description=text, read_only=True,
                                                                                dynamic_typing=True))  # fmt: skip
            unknown_parameters(getattr(self.node, "_parameter_overrides", {}))  # `-p metod:=...`: rclpy drops it
            self.params = checked_parameters({n: self.node.get_parameter(n).value for n in PARAMETERS})
            p = self.params
            self.core = FrameProcessor(method=p["method"] or DEFAULT_METHOD, fruit=p["fruit"] or None,
                                       config=p["config"] or None, masks=p["masks"] or "auto",
                                       depth_scale=p["depth_scale"],
                                       fruit_processes=p["fruit_processes"])  # fmt: skip
        except Exception:
            self.node.destroy_node()
            raise
        self.class_id = class_id_of(p["fruit"])
        self.log = self.node.get_logger()
        out_qos = QoSProfile(depth=10)  # reliable, volatile: what `ros2 topic echo` and RViz ask for
        self.pub_detections = self.node.create_publisher(self.vision_msgs.Detection3DArray, "~/detections", out_qos)
        self.pub_markers = self.node.create_publisher(MarkerArray, "~/markers", out_qos)
        self.pub_points = self.node.create_publisher(PointCloud2, "~/fruit_points", out_qos)
        self.topics = {name: self.input_topic(name) for name in DEFAULT_TOPICS}
        in_qos = QoSProfile(depth=p["queue_size"]) if p["qos"] == "reliable" else qos_profile_sensor_data
        self.sync = ApproximateSync(3, self._on_frame, slop=p["slop"], queue_size=p["queue_size"])
        # frames in a stream: the next one decoded and segmented while the fruit workers end the last one's fruit
        self.overlapped = Overlapped(self.core, done=self._publish, skipped=self._skipped, failed=self._on_error)
        self.worker = LatestOnly(self._handle, on_error=self._on_error, drain=self.overlapped.drain).start()
        self.subs = [
            self.node.create_subscription(kind, self.topics[name], self._adder(i, name), in_qos)
            for i, (name, kind) in enumerate((("color", Image), ("depth", Image), ("camera_info", CameraInfo)))
        ]
        self.topics = {name: sub.topic_name for name, sub in zip(DEFAULT_TOPICS, self.subs, strict=True)}  # remapped
        self.log.info(
            f"symfruit: method {self.core.method}, fruit {p['fruit'] or '-'}, qos {p['qos']}, listening to "
            + ", ".join(self.topics.values())
        )
        self.log.info(f"symfruit: {self.core.workers_said()}")

    def input_topic(self, name: str) -> str:
        """``name`` as remapped with ``-r name:=...``, else its RealSense default (which may itself be remapped)."""
        resolved = self.node.resolve_topic_name(name)
        return resolved if resolved != self.node.resolve_topic_name(name, only_expand=True) else DEFAULT_TOPICS[name]

    def _adder(self, index: int, name: str) -> Any:
        def add(msg: Any) -> None:  # executor thread: pair, hand over, never block
            late, resets = self.sync.late, self.sync.resets
            self.sync.add(index, msg)
            if self.sync.late > late:
                self.log.warning(f"symfruit: {name} stamped {stamp_text(msg.header)} is not newer than the last "
                                 f"frame used: ignored ({self.sync.late} so far)")  # fmt: skip
            elif self.sync.resets > resets:
                self.log.warning(f"symfruit: {name} stamped {stamp_text(msg.header)} jumped back in time: "
                                 "synchroniser reset")  # fmt: skip

        return add

    def _on_frame(self, color: Any, depth: Any, info: Any) -> None:
        if self.worker.put((time.perf_counter(), color, depth, info)):
            self.log.debug(f"symfruit: fell behind, dropped a frame ({self.worker.dropped} so far)")

    def _on_error(self, item: Any, exc: BaseException) -> None:  # a bug, not a bad frame: log it, carry on
        if self.context.ok():
            stamp = "(in flight)" if item is None else stamp_text(item[1].header)
            self.log.error(f"symfruit: frame {stamp} failed: {exc!r}")

    def _skipped(self, item: Any, exc: BaseException) -> None:
        self.log.warning(f"symfruit: frame {stamp_text(item[1].header)} skipped: {exc}")

    def _handle(self, item: tuple) -> None:
        stamp = stamp_text(item[1].header)
        self.overlapped.handle(item, name=stamp, source=f"ros2:{self.topics['color']}@{stamp}")

    def _publish(self, item: tuple, processed: Processed) -> None:
        t_in, color, _, _, t_start = item
        stamp = stamp_text(color.header)
        if not self.context.ok():  # shutting down: nothing to publish to
            return
        header = color.header
        t_publish = time.perf_counter()
        self.pub_detections.publish(detection_array(self.vision_msgs, header, processed.fruits, self.class_id))
        if self.pub_markers.get_subscription_count() > 0:  # built only for a viewer (rclpy would serialise for none)
            self.pub_markers.publish(marker_array(header, processed.fruits))
        if self.pub_points.get_subscription_count() > 0:
            self.pub_points.publish(point_cloud(header, processed.fruits))
        t_end = time.perf_counter()
        total = t_end - t_in
        detect_s = processed.found.timings.get("total", processed.seconds["detect"])
        failed = len(processed.found.detections) - len(processed.fruits)
        self.log.info(
            f"symfruit: frame {stamp}: {len(processed.fruits)} fruit{f' ({failed} failed)' if failed else ''} in "
            f"{total * 1e3:.1f} ms (detect {detect_s * 1e3:.1f} ms, node {(total - detect_s) * 1e3:.1f} ms: wait "
            f"{(t_start - t_in) * 1e3:.1f}, decode {processed.seconds['decode'] * 1e3:.1f}, collect "
            f"{processed.seconds['collect'] * 1e3:.1f}, publish {(t_end - t_publish) * 1e3:.1f}), "
            f"{self.worker.dropped} dropped so far"
        )

    def close(self) -> None:
        """Let the current frame finish, then destroy the subscriptions, publishers and the node."""
        from rclpy.logging import get_logger

        self.worker.stop()
        self.core.close()  # the fruit workers, after the last frame
        self.node.destroy_node()
        # after a signal the context is gone, and with it /rosout: this line goes to the console only
        get_logger(NODE_NAME).info(
            f"symfruit: stopped after {self.worker.handled} frames ({self.worker.dropped} dropped)"
        )


USAGE = """usage: symfruit ros2 [--ros-args ...]

Run the symfruit ROS 2 node (rclpy; `make ros2-env` builds .venv-ros2 with it). ROS arguments, e.g.:
  --ros-args -p method:=paper -p fruit:=apple -p config:=/abs/my.yaml -p masks:=auto      parameters
  --ros-args -p qos:=sensor_data                      best-effort inputs (default reliable, as RealSense)
  --ros-args -p fruit_processes:=0                    no worker process for the fruit (default 1)
  --ros-args -r color:=/cam/rgb -r depth:=/cam/depth_aligned -r camera_info:=/cam/rgb/info   remap inputs
  --ros-args -r __node:=fruit_finder -r __ns:=/robot                                 node name, namespace
Topics: in /camera/camera/color/image_raw, /camera/camera/aligned_depth_to_color/image_raw,
/camera/camera/color/camera_info; out ~/detections, ~/markers, ~/fruit_points.
"""


def main(argv: Sequence[str] | None = None) -> int:
    """Run the node until SIGINT or SIGTERM; ``argv`` are ROS arguments (``--ros-args ...``)."""
    args = list(sys.argv[1:] if argv is None else argv)
    own = args[: args.index("--ros-args")] if "--ros-args" in args else args
    if any(a in ("-h", "--help") for a in own):
        print(USAGE, end="")
        return 0
    rclpy = require_rclpy()
    require_vision_msgs()
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions
    from rclpy.utilities import remove_ros_args

    unknown = remove_ros_args(["symfruit", *args])[1:]
    if unknown:
        raise SymfruitError(
            f"symfruit ros2: unknown arguments {' '.join(unknown)}; ROS arguments follow --ros-args "
            "(see symfruit ros2 --help)"
        )
    # SIGINT and SIGTERM are held for the main thread (stop_signals), which waits for them while a thread spins:
    # the shutdown below then always runs, in this order.
    with stop_signals() as wait_for_stop:
        context = rclpy.Context()
        rclpy.init(args=["symfruit", *args], context=context, signal_handler_options=SignalHandlerOptions.NO)
        executor = SingleThreadedExecutor(context=context)
        stopping = threading.Event()
        failed: list[BaseException] = []
        node = None
        try:
            node = Ros2Node(context)
            executor.add_node(node.node)
            spinner = threading.Thread(target=_spin, args=(executor, stopping, failed), name="symfruit-spin")
            spinner.start()
            received = wait_for_stop()
            stopping.set()
            node.log.info(f"symfruit: {signal.Signals(received).name}, shutting down")
            executor.shutdown()
            spinner.join()
        finally:
            stopping.set()
            if node is not None:
                node.close()  # the worker finishes its frame first, then the node goes
            executor.shutdown()
            rclpy.try_shutdown(context=context)
            context.destroy()  # the DDS participant with it: its shared-memory segments go
    if failed:
        raise SymfruitError(f"symfruit ros2: the executor failed: {failed[0]!r}")
    return 0


def _spin(executor: Any, stopping: threading.Event, failed: list[BaseException]) -> None:
    """Spin until the main thread shuts the executor down; should it end by itself (an error), wake the main thread
    as a signal would."""
    try:
        executor.spin()
    except BaseException as exc:  # handed to the main thread, which ends the node and reports it
        failed.append(exc)
    if not stopping.is_set():
        os.kill(os.getpid(), signal.SIGTERM)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
