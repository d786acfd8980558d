"""ROS 2 bags of located fruit: ``vision_msgs/msg/Detection3DArray`` written with ``rosbags`` (extra ``bag``).

The types are registered into a rosbags typestore from the upstream ROS 2 definitions shipped in
``msg/ros2/vision_msgs`` (vision_msgs 4.x, Humble onwards: ``ObjectHypothesisWithPose`` holds an
``ObjectHypothesis`` (``class_id``, ``score``), ``Detection3D`` has a string ``id``, ``BoundingBox3D.center``
is a ``Pose``). Each frame becomes one message on :data:`TOPIC`, stamped (header and bag time) with the
frame's colour header when it has one (:func:`frame_header`), as the ROS 1 node's outputs are, so the bag
can be replayed beside the camera topics it came from::

    with Ros2DetectionBag("out/detections_bag", storage="mcap") as bag:
        bag.write(stamp_ns, fruits)           # core.Fruit records, e.g. core.fruits_of(detect(frame))

Per detection: ``id`` = the fruit's id in ``detections.json``, ``bbox`` = centre and size of the completed
fruit's box, one result with ``class_id`` (the fruit kind), ``score`` = confidence and ``pose`` = centre:
the content of ``detections.json`` (:func:`symfruit.ros.core.fruits_of`). ``symfruit detect --ros2-bag``
appends each frame from the batch loop (:meth:`Ros2DetectionBag.write_frame` as ``run_batch``'s ``on_frame``).
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Sequence
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from ..core.frame import Frame
from ..detect import FrameDetections
from ..errors import FileFormatError, OutputError, SymfruitError
from ..writers import OPTICAL_FRAME
from .core import Fruit, fruits_of

__all__ = ["MSGTYPE", "ROS2_TYPES", "TOPIC", "Ros2DetectionBag", "frame_header", "ros2_typestore"]

TOPIC = "/symfruit/detections"
MSGTYPE = "vision_msgs/msg/Detection3DArray"
#: Registered in dependency order.
ROS2_TYPES = ("ObjectHypothesis", "ObjectHypothesisWithPose", "BoundingBox3D", "Detection3D", "Detection3DArray")
STORAGES = ("mcap", "sqlite3")


def definition(name: str) -> str:
    """The shipped upstream ROS 2 definition (``.msg`` text) of ``vision_msgs/msg/NAME``."""
    return (resources.files(__package__) / "msg" / "ros2" / "vision_msgs" / f"{name}.msg").read_text(encoding="utf-8")


def _rosbags():
    try:
        import rosbags.rosbag2
        import rosbags.typesys
    except ImportError:
        raise SymfruitError("writing ROS 2 bags needs rosbags: pip install 'symfruit[bag]'") from None
    return rosbags


def ros2_typestore():
    """A rosbags ROS 2 (Humble) typestore with the vision_msgs detection types registered."""
    _rosbags()
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    types: dict = {}
    for name in ROS2_TYPES:
        types.update(get_types_from_msg(definition(name), f"vision_msgs/msg/{name}"))
    store.register(types)
    return store


def frame_header(frame: Frame, index: int = 0) -> tuple[int, str]:
    """``(stamp in ns, frame_id)`` of a frame's detections: the colour image's header (``frame.stamp`` and
    ``frame.frame_id``: bags and the node carry it), as the ROS 1 node's outputs and ``detections.json`` copy
    it; a frame without a stamp (a frame folder) is stamped ``index`` seconds; ``frame_id`` defaults to the
    colour camera's optical frame."""
    stamp = frame.stamp if frame.stamp is not None else index * 1_000_000_000
    return int(stamp), frame.frame_id or OPTICAL_FRAME


class Ros2DetectionBag:
    """A new ROS 2 bag folder with one ``Detection3DArray`` topic; a context manager.

    Parameters
    ----------
    path : path
        Bag folder to create (must not exist).
    storage : {"mcap", "sqlite3"}
    topic : str
    class_id : str
        ``ObjectHypothesis.class_id`` of every detection (the fruit kind, e.g. the profile name).
    """

    def __init__(self, path: str | Path, *, storage: str = "mcap", topic: str = TOPIC, class_id: str = "fruit") -> None:
        if storage not in STORAGES:
            raise SymfruitError(f"ROS 2 bag storage must be one of {', '.join(STORAGES)}, got {storage!r}")
        self.path, self.storage, self.topic, self.class_id = Path(path), storage, topic, class_id
        self.store = ros2_typestore()
        self.count = 0
        self._writer: Any = None
        self._conn: Any = None
        self._partial: Path | None = None  # the hidden folder the bag is written in until closed

    def open(self) -> Ros2DetectionBag:
        """Start the bag in a hidden folder beside ``path`` (``.NAME.partial-XXXX/NAME``): :meth:`close` renames it
        into place once rosbags has closed it (its ``metadata.yaml`` written), so ``path`` is never a bag cut
        short (a killed run leaves only the hidden folder)."""
        _rosbags()
        from rosbags.rosbag2 import StoragePlugin, Writer

        if os.path.lexists(self.path):
            raise FileFormatError(f"{self.path}: exists already; a ROS 2 bag is written to a new folder")
        plugin = StoragePlugin.MCAP if self.storage == "mcap" else StoragePlugin.SQLITE3
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)  # as rosbags' writer makes a bag's parents
            self._partial = Path(tempfile.mkdtemp(prefix=f".{self.path.name}.partial-", dir=self.path.parent))
            self._writer = Writer(self._partial / self.path.name, version=8, storage_plugin=plugin)
            self._writer.open()
        except OSError as exc:  # a folder on the way is a file (stop 48, robust48: "[Errno 17] File exists: ...")
            self._discard_partial()
            file = next((p for p in self.path.parents if p.exists() and not p.is_dir()), None)
            why = f"{file} is a file, not a folder" if file is not None else exc.strerror or exc
            raise OutputError(f"{self.path}: cannot create ROS 2 bag ({why})", exc.errno) from None
        except Exception as exc:  # rosbags' WriterError
            self._discard_partial()
            raise FileFormatError(f"{self.path}: cannot create ROS 2 bag ({exc})") from None
        self._conn = self._writer.add_connection(self.topic, MSGTYPE, typestore=self.store)
        return self

    def _discard_partial(self) -> None:
        if self._partial is not None:
            shutil.rmtree(self._partial, ignore_errors=True)
            self._partial = None

    def message(self, stamp_ns: int, fruits: Sequence[Fruit], frame_id: str = OPTICAL_FRAME):
        """The ``Detection3DArray`` (rosbags class) of one frame."""
        t = self.store.types
        sec, nanosec = divmod(int(stamp_ns), 1_000_000_000)
        header = t["std_msgs/msg/Header"](
            stamp=t["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec), frame_id=frame_id
        )
        point, quat = t["geometry_msgs/msg/Point"], t["geometry_msgs/msg/Quaternion"]

        def pose(c):
            return t["geometry_msgs/msg/Pose"](
                position=point(x=c[0], y=c[1], z=c[2]), orientation=quat(x=0.0, y=0.0, z=0.0, w=1.0)
            )

        detections = []
        for f in fruits:
            c, s = [float(v) for v in f.centre], [float(v) for v in f.size]
            hyp = t["vision_msgs/msg/ObjectHypothesisWithPose"](
                hypothesis=t["vision_msgs/msg/ObjectHypothesis"](class_id=self.class_id, score=float(f.score)),
                pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=pose(c), covariance=np.zeros(36)),
            )
            bbox = t["vision_msgs/msg/BoundingBox3D"](
                center=pose(c), size=t["geometry_msgs/msg/Vector3"](x=s[0], y=s[1], z=s[2])
            )
            detections.append(t["vision_msgs/msg/Detection3D"](header=header, results=[hyp], bbox=bbox, id=str(f.id)))
        return t[MSGTYPE](header=header, detections=detections)

    def write_frame(self, index: int, found: FrameDetections) -> None:
        """Append a frame's detections (:func:`~symfruit.ros.core.fruits_of`) at its :func:`frame_header`;
        ``index`` is the frame's place in its recording. Fits ``run_batch(on_frame=...)``."""
        stamp, frame_id = frame_header(found.frame, index)
        self.write(stamp, fruits_of(found), frame_id)

    def write(self, stamp_ns: int, fruits: Sequence[Fruit], frame_id: str = OPTICAL_FRAME) -> None:
        """Append one frame's detections at ``stamp_ns`` (header stamp and bag time)."""
        if self._writer is None:
            self.open()
        data = self.store.serialize_cdr(self.message(stamp_ns, fruits, frame_id), MSGTYPE)
        self._writer.write(self._conn, int(stamp_ns), data)
        self.count += 1

    def close(self, *, keep: bool = True) -> None:
        """Close the bag and rename it into place (``keep``), or drop it (``keep=False``: nothing at ``path``)."""
        if self._writer is not None:
            writer, self._writer = self._writer, None
            try:
                writer.close()
            except BaseException:
                self._discard_partial()
                raise
        if self._partial is None:
            return
        if not keep:
            self._discard_partial()
            return
        try:
            if os.path.lexists(self.path):  # made while the batch ran; never renamed over (an empty folder would be)
                raise FileExistsError(f"{self.path} appeared while the bag was written")
            os.rename(self._partial / self.path.name, self.path)
        except OSError as exc:
            self._discard_partial()
            raise FileFormatError(f"{self.path}: cannot put the ROS 2 bag in place ({exc})") from None
        self._discard_partial()

    def __enter__(self) -> Ros2DetectionBag:
        return self.open()

    def __exit__(self, *exc) -> None:
        self.close()
