"""``symfruit ros``: the ROS 1 node (rospy), a thin wrapper around :mod:`symfruit.ros.core`.

Subscribes, approximately time-synchronised, to

- ``color``       ``sensor_msgs/Image`` rgb8/bgr8/rgba8/bgra8/mono8  (default ``/camera/color/image_raw``)
- ``depth``       ``sensor_msgs/Image`` 16UC1 mm or 32FC1 m, aligned  (``/camera/aligned_depth_to_color/image_raw``)
- ``camera_info`` ``sensor_msgs/CameraInfo``                           (``/camera/color/camera_info``)

(the RealSense wrapper's names; remap either the short name, ``color:=/my/image``, or the default
itself) and publishes, per frame and with the colour image's header:

- ``~detections``   ``vision_msgs/Detection3DArray`` (upstream noetic type and md5sum): per fruit a
  ``Detection3D`` whose ``bbox`` is the completed fruit's box (centre, size) and one result with
  ``id`` = the fruit's id in ``detections.json``, ``score`` = its confidence, ``pose`` = the centre;
- ``~markers``      ``visualization_msgs/MarkerArray``: DELETEALL, then per fruit a translucent box,
  a centre sphere and a label (namespaces ``symfruit/box``, ``symfruit/centre``, ``symfruit/label``);
- ``~fruit_points`` ``sensor_msgs/PointCloud2`` (x, y, z, fruit, completed) of the completed clouds,
  built only while someone subscribes.

Private parameters: ``~method`` (the default method, ``evidence``), ``~fruit`` (strawberry), ``~config``
(settings file, ""), ``~masks`` (auto), resolved by :func:`symfruit.settings.resolve_settings` as on the command line;
``~depth_scale`` (0.001 m per 16UC1 unit), ``~slop`` (0.05 s), ``~queue_size`` (5), ``~fruit_processes`` (1: a
worker process kept to share each frame's fruit with, :class:`symfruit.fruitpool.FruitPool`; 0 for none), checked at
start (:func:`private_parameters`). A frame that cannot be
used is logged and skipped; frames arriving while one is processed are dropped (only the newest waits).
Each frame logs its latency. Everything but rospy lives in :mod:`symfruit.ros.core`.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import SymfruitError
from ..methods import DEFAULT_METHOD
from .core import (
    PARAMETERS,
    FrameProcessor,
    Fruit,
    LatestOnly,
    Overlapped,
    Processed,
    checked_parameters,
    unknown_parameters,
)

__all__ = ["DEFAULT_TOPICS", "SymfruitNode", "main"]

DEFAULT_TOPICS = {
    "color": "/camera/color/image_raw",
    "depth": "/camera/aligned_depth_to_color/image_raw",
    "camera_info": "/camera/color/camera_info",
}
BOX_RGBA = (0.0, 0.86, 1.0, 0.35)  # the overlay's cyan, translucent
CENTRE_RGBA = (1.0, 0.2, 0.2, 1.0)
LABEL_RGBA = (1.0, 1.0, 1.0, 1.0)
CENTRE_DIAMETER = 0.008  # metres


def require_rospy():
    """``(rospy, message_filters)``, or a :class:`SymfruitError` naming the Debian packages to install."""
    try:
        import message_filters
        import rospy
    except ImportError as exc:
        raise SymfruitError(
            f"`symfruit ros` needs ROS 1's rospy ({exc}); on Debian/Ubuntu: sudo apt-get install python3-rospy "
            "python3-message-filters python3-sensor-msgs python3-visualization-msgs python3-geometry-msgs "
            "python3-genpy python3-rosmaster, then `make ros-env` so that the project's venv sees them"
        ) from None
    return rospy, message_filters


def input_topic(rospy, name: str) -> str:
    """``name`` as remapped on the command line or by a launch file, else its RealSense default."""
    plain = rospy.names.ns_join(rospy.get_namespace(), name)
    resolved = rospy.resolve_name(name)
    return resolved if resolved != plain else DEFAULT_TOPICS[name]


# --------------------------------------------------------------------------------------------------
# messages (ROS 1 classes; the content is what core.Fruit holds)
# --------------------------------------------------------------------------------------------------


def copy_header(header):
    from std_msgs.msg import Header

    return Header(stamp=header.stamp, frame_id=header.frame_id)


def detection_array(vision_msgs, header, fruits: Sequence[Fruit]):
    """A ``vision_msgs/Detection3DArray`` of the fruit, every header a copy of ``header``."""
    from geometry_msgs.msg import Point, Quaternion, Vector3

    out = vision_msgs.Detection3DArray(header=copy_header(header))
    for f in fruits:
        cx, cy, cz = (float(v) for v in f.centre)
        hyp = vision_msgs.ObjectHypothesisWithPose(id=f.id, score=f.score)
        hyp.pose.pose.position = Point(cx, cy, cz)
        hyp.pose.pose.orientation = Quaternion(0.0, 0.0, 0.0, 1.0)
        det = vision_msgs.Detection3D(header=copy_header(header), results=[hyp])
        det.bbox.center.position = Point(cx, cy, cz)
        det.bbox.center.orientation = Quaternion(0.0, 0.0, 0.0, 1.0)
        det.bbox.size = Vector3(*(float(v) for v in f.size))
        out.detections.append(det)
    return out


def marker_array(header, fruits: Sequence[Fruit]):
    """DELETEALL (clears the previous frame's markers), then a box, a centre sphere and a label per fruit."""
    from geometry_msgs.msg import Point, Quaternion, Vector3
    from std_msgs.msg import ColorRGBA
    from visualization_msgs.msg import Marker, MarkerArray

    out = MarkerArray()
    out.markers.append(Marker(header=copy_header(header), action=Marker.DELETEALL))
    for f in fruits:
        centre = Point(*(float(v) for v in f.centre))
        common = {"header": copy_header(header), "id": f.id, "action": Marker.ADD}
        box = Marker(ns="symfruit/box", type=Marker.CUBE, color=ColorRGBA(*BOX_RGBA), **common)
        box.pose.position, box.pose.orientation = centre, Quaternion(0.0, 0.0, 0.0, 1.0)
        box.scale = Vector3(*(max(float(v), 1e-4) for v in f.size))
        dot = Marker(ns="symfruit/centre", type=Marker.SPHERE, color=ColorRGBA(*CENTRE_RGBA), **common)
        dot.pose.position, dot.pose.orientation = centre, Quaternion(0.0, 0.0, 0.0, 1.0)
        dot.scale = Vector3(CENTRE_DIAMETER, CENTRE_DIAMETER, CENTRE_DIAMETER)
        text = f"{f.id}: {f.centre[2] * 1000:.0f} mm" + ("" if np.isnan(f.score) else f" ({f.score:.2f})")
        label = Marker(
            ns="symfruit/label", type=Marker.TEXT_VIEW_FACING, color=ColorRGBA(*LABEL_RGBA), text=text, **common
        )
        label.pose.position = Point(centre.x, centre.y - float(f.size[1]) / 2 - 0.01, centre.z)  # above (y down)
        label.pose.orientation = Quaternion(0.0, 0.0, 0.0, 1.0)
        label.scale.z = 0.015
        out.markers.extend([box, dot, label])
    return out


#: PointCloud2 layout of ~fruit_points: x, y, z, fruit id, completed (0 seen, 1 mirrored), all float32.
CLOUD_FIELDS = ("x", "y", "z", "fruit", "completed")


def cloud_array(fruits: Sequence[Fruit]) -> np.ndarray:
    """(n, 5) float32 rows of :data:`CLOUD_FIELDS` for every fruit's completed cloud."""
    out = np.zeros((sum(len(f.points) for f in fruits), len(CLOUD_FIELDS)), np.float32)
    start = 0
    for f in fruits:  # one block per fruit
        block = out[start : start + len(f.points)]
        block[:, :3] = f.points
        block[:, 3] = f.id
        block[f.n_visible :, 4] = 1.0
        start += len(f.points)
    return out


def point_cloud(header, fruits: Sequence[Fruit]):
    from sensor_msgs.msg import PointCloud2, PointField

    data = cloud_array(fruits)
    fields = [
        PointField(name=n, offset=4 * i, datatype=PointField.FLOAT32, count=1) for i, n in enumerate(CLOUD_FIELDS)
    ]
    return PointCloud2(
        header=copy_header(header),
        height=1,
        width=len(data),
        fields=fields,
        is_bigendian=False,
        point_step=4 * len(CLOUD_FIELDS),
        row_step=4 * len(CLOUD_FIELDS) * len(data),
        data=data.tobytes(),
        is_dense=True,
    )


# --------------------------------------------------------------------------------------------------
# the node
# --------------------------------------------------------------------------------------------------


class SymfruitNode:
    """Subscriptions, the latest-frame worker and the publishers; call after ``rospy.init_node``."""

    def __init__(self) -> None:
        rospy, message_filters = require_rospy()
        from sensor_msgs.msg import CameraInfo, Image, PointCloud2
        from visualization_msgs.msg import MarkerArray

        from .ros1_msgs import load_vision_msgs

        self.rospy = rospy
        self.vision_msgs = load_vision_msgs()
        p = private_parameters(rospy.get_param, given_private_names(rospy.get_param_names(), rospy.get_name()))
        self.core = FrameProcessor(
            method=p["method"] or DEFAULT_METHOD, fruit=p["fruit"] or None, config=p["config"] or None,
            masks=p["masks"], depth_scale=p["depth_scale"], fruit_processes=p["fruit_processes"],
        )  # fmt: skip
        self.pub_detections = rospy.Publisher("~detections", self.vision_msgs.Detection3DArray, queue_size=2)
        self.pub_markers = rospy.Publisher("~markers", MarkerArray, queue_size=2)
        self.pub_points = rospy.Publisher("~fruit_points", PointCloud2, queue_size=2)
        self.topics = {name: input_topic(rospy, name) for name in DEFAULT_TOPICS}
        big = 1 << 26  # rospy's 64 kB default receive buffer makes large images lag far behind
        # Everything the synchroniser needs is read (two round trips to the master) and the worker started before
        # the first subscription: a frame completed between subscribing and registering the callback was dropped.
        queue_size, slop = p["queue_size"], p["slop"]
        # frames in a stream: the next one decoded and segmented while the fruit workers end the last one's fruit
        self.overlapped = Overlapped(self.core, done=self._publish, skipped=self._skipped, failed=self._on_error)
        self.worker = LatestOnly(self._handle, on_error=self._on_error, drain=self.overlapped.drain).start()
        subs = [
            message_filters.Subscriber(self.topics["color"], Image, queue_size=1, buff_size=big, tcp_nodelay=True),
            message_filters.Subscriber(self.topics["depth"], Image, queue_size=1, buff_size=big, tcp_nodelay=True),
            message_filters.Subscriber(self.topics["camera_info"], CameraInfo, queue_size=1, tcp_nodelay=True),
        ]
        self.sync = message_filters.ApproximateTimeSynchronizer(subs, queue_size=queue_size, slop=slop)
        self.sync.registerCallback(self._on_frame)
        rospy.on_shutdown(self._stop)
        rospy.loginfo("symfruit: method %s, listening to %s, %s, %s", self.core.method, *self.topics.values())
        rospy.loginfo("symfruit: %s", self.core.workers_said())

    def _on_frame(self, color, depth, info) -> None:  # subscriber thread: hand over, never block
        if self.worker.put((time.perf_counter(), color, depth, info)):
            self.rospy.logdebug("symfruit: fell behind, dropped a frame (%d so far)", self.worker.dropped)

    def _stop(self) -> None:
        """At shutdown: the current frame finished, then the fruit workers ended."""
        self.worker.stop()
        self.core.close()

    def _on_error(self, item: Any, exc: BaseException) -> None:  # a bug, not a bad frame: log it, carry on
        stamp = "(in flight)" if item is None else _stamp(item[1])
        self.rospy.logerr("symfruit: frame %s failed: %r", stamp, exc, exc_info=exc)

    def _skipped(self, item: Any, exc: BaseException) -> None:
        self.rospy.logwarn("symfruit: frame %s skipped: %s", _stamp(item[1]), exc)

    def _handle(self, item: tuple) -> None:
        stamp = _stamp(item[1])
        self.overlapped.handle(item, name=stamp, source=f"ros:{self.topics['color']}@{stamp}")

    def _publish(self, item: tuple, processed: Processed) -> None:
        t_in, color, _, _, t_start = item
        stamp = _stamp(color)
        header = color.header
        t_publish = time.perf_counter()
        self.pub_detections.publish(detection_array(self.vision_msgs, header, processed.fruits))
        self.pub_markers.publish(marker_array(header, processed.fruits))
        if self.pub_points.get_num_connections() > 0:
            self.pub_points.publish(point_cloud(header, processed.fruits))
        t_end = time.perf_counter()
        total = t_end - t_in
        detect_s = processed.found.timings.get("total", processed.seconds["detect"])
        failed = len(processed.found.detections) - len(processed.fruits)
        self.rospy.loginfo(
            "symfruit: frame %s: %d fruit%s in %.1f ms (detect %.1f ms, node %.1f ms: wait %.1f, decode %.1f, "
            "collect %.1f, publish %.1f), %d dropped so far",
            stamp,
            len(processed.fruits),
            f" ({failed} failed)" if failed else "",
            total * 1e3,
            detect_s * 1e3,
            (total - detect_s) * 1e3,
            (t_start - t_in) * 1e3,
            processed.seconds["decode"] * 1e3,
            processed.seconds["collect"] * 1e3,
            (t_end - t_publish) * 1e3,
            self.worker.dropped,
        )


def _stamp(msg) -> str:
    s = msg.header.stamp
    return f"{s.secs}.{s.nsecs:09d}"


USAGE = """usage: symfruit ros [ROS arguments]

Run the symfruit ROS 1 node (ROS_MASTER_URI from the environment). ROS arguments, e.g.:
  color:=/my/color/image_raw depth:=/my/depth camera_info:=/my/camera_info   remap the inputs
  _method:=evidence _fruit:=strawberry _config:=settings.yaml _masks:=auto   private parameters
  _fruit_processes:=0                                                         no fruit worker process (default 1)
  __name:=symfruit __ns:=/robot                                               node name, namespace
"""


def private_parameters(get_param: Any, given: Sequence[str] = ()) -> dict[str, Any]:
    """The node's private parameters (``~method`` ... ``~queue_size``; ROS 1 has no ``qos``) through ``get_param``
    (``rospy.get_param``), checked as the ROS 2 node's are (:func:`~symfruit.ros.core.checked_parameters`): a
    ``~queue_size`` that is no whole number, or a ``~slop`` out of [0, 10] s, is one line naming it, and so is a
    private parameter the node does not have among ``given`` (their names, :func:`given_private_names`)."""
    known = {name: v for name, v in PARAMETERS.items() if name != "qos"}
    unknown_parameters(given, known=known)
    return checked_parameters({name: get_param(f"~{name}", default) for name, (default, _) in known.items()})


def given_private_names(names: Sequence[str], node_name: str) -> list[str]:
    """The private parameters among the parameter server's ``names`` (``rospy.get_param_names()``) of the node
    ``node_name`` (``rospy.get_name()``): their first component below the node's namespace."""
    prefix = node_name.rstrip("/") + "/"
    return sorted({n[len(prefix) :].split("/")[0] for n in names if n.startswith(prefix) and len(n) > len(prefix)})


def main(argv: Sequence[str] | None = None) -> int:
    """Run the node until shutdown; ``argv`` are ROS arguments (remappings, ``_param:=value``)."""
    args = list(sys.argv[1:] if argv is None else argv)
    if any(a in ("-h", "--help") for a in args):
        print(USAGE, end="")
        return 0
    rospy, _ = require_rospy()
    unknown = rospy.myargv(args)
    if unknown:
        raise SymfruitError(
            f"symfruit ros: unknown arguments {' '.join(unknown)}; ROS arguments look like "
            "name:=value (see symfruit ros --help)"
        )
    rospy.init_node("symfruit", argv=["symfruit", *args])
    SymfruitNode()
    rospy.spin()
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
