"""RealSense recordings: the ROS 1 ``.bag`` files the RealSense Viewer and ``rs.recorder`` write (optional
extra ``bag``, read through ``rosbags``), depth registered to colour here.

librealsense's layout (``src/media/ros/ros_file_format.h``, file version 3 and 4)::

    /file_version                                               std_msgs/UInt32
    /device_0/sensor_<s>/<Stream>_<i>/image/data                sensor_msgs/Image (Depth: mono16 units)
    /device_0/sensor_<s>/<Stream>_<i>/info/camera_info          sensor_msgs/CameraInfo (K, D, distortion_model;
                                                                D: rs2_intrinsics' five coeffs, no more)
    /device_0/sensor_<s>/<Stream>_<i>/tf/<group>                geometry_msgs/Transform: group reference -> stream
    /device_0/sensor_<s>/option/Depth Units/value               std_msgs/Float32, metres per unit
                                                                (``Depth_Units`` in SDK 2.5x)

Each depth image is one frame. Its colour image is the one whose header stamp (the frame's timestamp as
the camera gave it) is nearest, within ``max_skew``; depth is deprojected with the depth stream's lens,
moved by the recorded extrinsics (depth -> colour = colour's tf composed with the inverse of depth's) and
projected with the colour lens (:func:`symfruit.core.align.align_depth`), in metres from the recorded depth
units. librealsense appends a ``float32`` of depth units to every image message it writes (not part of
``sensor_msgs/Image``), which ``rosbags`` refuses as a size mismatch: messages are deserialised with rosbags'
own ``sensor_msgs/Image`` decoder and exactly those four trailing bytes are allowed (and used as the depth
units when no option topic recorded them).

The bag is indexed once (stamps only) and each frame decoded on demand: memory stays flat however long
the recording. SDK 2.58 and later record ROS 2 ``.db3`` files instead (another layout); they are not read
here (``rs-convert`` or the SDK 2.57 Viewer give ``.bag``).
"""

from __future__ import annotations

import bisect
import re
import struct
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..core.align import LENS_MODELS, Lens, align_depth
from ..core.camera import Camera
from ..core.frame import Frame
from ..core.limits import shown
from ..errors import FileFormatError, InputError, SymfruitError
from .bags import _require_rosbags, bag_files, color_image, image_array, index_reason, message_reason, reader_reason
from .frames import named_frame
from .intrinsics import check_pinhole_matrix, warn_distortion, warn_principal_point
from .text import unchanged_while

__all__ = ["RealSenseBagSource", "Stream", "is_realsense", "quaternion_matrix", "sdk_aligned"]

_IMAGE = re.compile(r"^/device_(\d+)/sensor_(\d+)/(Depth|Color)_(\d+)/image/data$")
_SENSOR = re.compile(r"^/device_\d+/sensor_\d+/")
_TF = re.compile(r"^/(device_\d+/sensor_\d+/(?:Depth|Color)_\d+)/tf/(\d+)$")
#: File versions of librealsense's ROS 1 layout read here (2 and below are the pre-2.10 "legacy" layout).
FILE_VERSIONS = (3, 4)
_DEPTH_ENCODINGS = ("mono16", "16uc1")
#: Largest lens coefficient (any of ``k1, k2, p1, p2, k3``) of a recorded stream: the depth lens's are applied in
#: the alignment (and the colour lens's), and the SDK's cameras record well under 1 (D400 colour ``|k| < 0.6``,
#: tangential ``< 0.01``, depth lenses 0); at 10 a point at the image corner (``r^2 ~ 0.5``) would move by five
#: times its distance from the centre: no lens, a recording gone wrong (1e30 overflows the projection).
MAX_LENS_COEFF = 10.0


def is_realsense(path: Path) -> bool:
    """Whether a ROS 1 bag holds librealsense's topics (``/device_N/sensor_N/...``).

    Reads only the bag's index; a bag rosbags cannot open is not one (the generic reader then names why).
    """
    try:
        from rosbags.rosbag1 import Reader

        with Reader(path) as reader:
            topics = list(reader.topics)
    except Exception:
        return False
    return any(_SENSOR.match(t) for t in topics)


def quaternion_matrix(x: float, y: float, z: float, w: float) -> np.ndarray:
    """(3, 3) rotation of a unit quaternion (librealsense's ``quat2rot``; ``q`` and ``-q`` are one rotation)."""
    q = np.array([x, y, z, w], dtype=np.float64)
    n = float(np.linalg.norm(q))
    if not np.isfinite(n) or abs(n - 1.0) > 1e-3:
        raise InputError(f"extrinsic rotation is not a unit quaternion (x, y, z, w = {x}, {y}, {z}, {w})")
    x, y, z, w = q / n
    return np.array([
        [1 - 2 * y * y - 2 * z * z, 2 * x * y - 2 * z * w, 2 * x * z + 2 * y * w],
        [2 * x * y + 2 * z * w, 1 - 2 * x * x - 2 * z * z, 2 * y * z - 2 * x * w],
        [2 * x * z - 2 * y * w, 2 * y * z + 2 * x * w, 1 - 2 * x * x - 2 * y * y],
    ])  # fmt: skip


@dataclass(frozen=True)
class Stream:
    """One recorded video stream: its topics' common prefix (``device_0/sensor_0/Depth_0``), lens and
    extrinsics from its group's reference (``p_stream = rotation @ p_ref + translation``)."""

    prefix: str
    lens: Lens
    group: int
    rotation: np.ndarray
    translation: np.ndarray


class RealSenseBagSource:
    """A RealSense ``.bag`` as a recording: one frame per depth image, aligned to colour (module docstring).

    Parameters
    ----------
    path : Path
    max_skew : float
        Largest gap (seconds) between a depth image's stamp and its colour image's.
    """

    def __init__(self, path: Path, *, max_skew: float = 0.05) -> None:
        self.path = Path(path)
        self.max_skew = max_skew
        self._files = bag_files(self.path)  # each frame read checks that none changed since (robust53)
        reader_cls = _require_rosbags()
        try:
            self._reader = reader_cls([self.path])
            self._reader.open()
        except Exception as exc:  # rosbags' own ReaderError / AnyReaderError types
            raise FileFormatError(f"{self.path}: cannot open bag ({reader_reason(exc)})") from None
        try:
            self._index()
        except SymfruitError as exc:
            self.close()
            raise FileFormatError(f"{self.path}: {exc}") from None
        except Exception as exc:  # a corrupt bag fails inside rosbags while indexing
            self.close()
            raise FileFormatError(f"{self.path}: cannot index bag ({index_reason(exc)})") from None

    # --- indexing ---------------------------------------------------------------------------------------

    def _deserialize(self, raw: Any, conn: Any) -> tuple[Any, bytes]:
        """A message and the bytes after it (librealsense's trailing depth units on images, else empty)."""
        store = self._reader.typestore
        msgdef = store.get_msgdef(conn.msgtype)
        try:
            msg, pos = msgdef.deserialize_ros1(raw, 0, msgdef.cls, store)
        except Exception as exc:
            raise FileFormatError(
                f"corrupt {conn.msgtype} message on {conn.topic} ({message_reason(exc, raw)})"
            ) from None
        tail = bytes(raw[pos:])
        allowed = 4 if conn.msgtype.endswith("/Image") else 0
        if len(tail) > allowed:
            raise FileFormatError(f"{conn.msgtype} message on {conn.topic} has {len(tail)} bytes past its end")
        return msg, tail

    def _only(self, topic: str) -> Any:
        """The first message of ``topic`` (None when the bag has no such topic or it is empty)."""
        conns = [c for c in self._reader.connections if c.topic == topic]
        if not conns:  # rosbags reads every connection when given none
            return None
        for conn, _, raw in self._reader.messages(connections=conns):
            return self._deserialize(raw, conn)[0]
        return None

    def _stream(self, prefix: str, tfs: dict[str, tuple[int, Any]]) -> Stream:
        info = self._only(f"/{prefix}/info/camera_info")
        if info is None:
            raise FileFormatError(f"no intrinsics for {prefix} (topic /{prefix}/info/camera_info missing or empty)")
        model = str(info.distortion_model)
        if model not in LENS_MODELS:
            raise FileFormatError(f"{prefix}: lens model {shown(model)} is not supported (known: "
                                  f"{', '.join(LENS_MODELS)})")  # fmt: skip
        # librealsense writes D from rs2_intrinsics::coeffs, a float[5] (ros_writer.cpp), and reads five back: every
        # model's coefficients are those five, so a D of any other length is not its recording; refused, never cut
        # (counted before any value is converted: a D of millions is refused as it stands)
        if len(info.K) != 9 or len(info.D) not in (0, 5):
            raise FileFormatError(f"{prefix}: camera info K has {len(info.K)} values and D {len(info.D)}; expected "
                                  "9 and 5 (librealsense records five lens coefficients, rs2_intrinsics "
                                  "coeffs)")  # fmt: skip
        k, coeffs = [float(v) for v in info.K], [float(v) for v in info.D]
        if not all(abs(c) <= MAX_LENS_COEFF for c in coeffs):  # NaN too
            raise FileFormatError(f"{prefix}: lens coefficients {shown(coeffs)} are not plausible (each at most "
                                  f"{MAX_LENS_COEFF:g} in size; real lenses record well under 1)")  # fmt: skip
        try:
            camera = Camera(fx=k[0], fy=k[4], cx=k[2], cy=k[5], width=int(info.width), height=int(info.height))
            lens = Lens(camera, LENS_MODELS[model], tuple(coeffs or [0.0] * 5))
            check_pinhole_matrix(k, "camera info K")
        except InputError as exc:
            raise FileFormatError(f"{prefix}: invalid intrinsics ({exc})") from None
        if prefix not in tfs:
            raise FileFormatError(f"no extrinsics for {prefix} (no /{prefix}/tf/<group> topic): depth cannot be "
                                  "registered to colour")  # fmt: skip
        group, tf = tfs[prefix]
        t, q = tf.translation, tf.rotation
        translation = np.array([t.x, t.y, t.z], dtype=np.float64)
        if not np.isfinite(translation).all() or np.abs(translation).max() > 10.0:
            raise FileFormatError(f"{prefix}: extrinsic translation {translation.tolist()} m is not plausible")
        try:
            rotation = quaternion_matrix(q.x, q.y, q.z, q.w)
        except InputError as exc:
            raise FileFormatError(f"{prefix}: {exc}") from None
        return Stream(prefix, lens, group, rotation, translation)

    def _index(self) -> None:
        conns = self._reader.connections
        topics = sorted({c.topic for c in conns})
        version = self._only("/file_version")
        if version is not None and int(version.data) not in FILE_VERSIONS:
            raise FileFormatError(f"RealSense file version {int(version.data)} is not supported (versions "
                                  f"{', '.join(map(str, FILE_VERSIONS))}: SDK 2.10 to 2.57)")  # fmt: skip
        images = {m.group(3): c for c in conns if (m := _IMAGE.match(c.topic)) and m.group(4) == "0"}
        for kind in ("Depth", "Color"):
            if kind not in images:
                raise FileFormatError(f"no {kind.lower()} stream recorded (no /device_0/sensor_N/{kind}_0/image/data "
                                      f"topic; {_streams(topics)})")  # fmt: skip
        self._depth, self._color = images["Depth"], images["Color"]
        tfs: dict[str, tuple[int, Any]] = {}
        for conn in conns:
            m = _TF.match(conn.topic)
            if m and m.group(1) not in tfs:
                msg = self._only(conn.topic)
                if msg is not None:
                    tfs[m.group(1)] = (int(m.group(2)), msg)
        depth_prefix = self._depth.topic[1 : -len("/image/data")]
        color_prefix = self._color.topic[1 : -len("/image/data")]
        self.depth_stream = self._stream(depth_prefix, tfs)
        self.color_stream = self._stream(color_prefix, tfs)
        # the colour lens's distortion registers depth to the colour pixels (align_depth) but the frames' camera is
        # its pinhole part: said so, as for any camera; the depth lens's is applied in full
        warn_distortion(f"{self.path}: colour camera info /{color_prefix}/info/camera_info", "D",
                        self.color_stream.lens.coeffs, stacklevel=4)  # fmt: skip
        warn_principal_point(f"{self.path}: colour camera info /{color_prefix}/info/camera_info",
                             self.color_stream.lens.camera, stacklevel=4)  # fmt: skip
        d, c = self.depth_stream, self.color_stream
        if d.group != c.group:
            raise FileFormatError(f"depth and colour extrinsics are relative to different references "
                                  f"(tf/{d.group} and tf/{c.group})")  # fmt: skip
        # depth -> colour: p_c = Rc (Rd^T (p_d - td)) + tc
        self.rotation = c.rotation @ d.rotation.T
        self.translation = c.translation - self.rotation @ d.translation
        sensor = depth_prefix.split("/")[1]
        self.depth_units: float | None = None
        for name in ("Depth Units", "Depth_Units"):
            units = self._only(f"/device_0/{sensor}/option/{name}/value")
            if units is not None:
                self.depth_units = _check_units(float(units.data), f"option {name}")
                break
        self._depth_stamps: list[tuple[int, int]] = []  # (header stamp or bag time, bag time)
        self._color_stamps: list[tuple[int, int]] = []
        for conn, bag_time, raw in self._reader.messages(connections=[self._depth, self._color]):
            try:
                stamp = _header_ns(self._deserialize(raw, conn)[0]) or bag_time
            except FileFormatError:  # one torn image: its frame fails when read, naming it, not the recording
                stamp = _raw_header_ns(raw) or bag_time
            (self._depth_stamps if conn == self._depth else self._color_stamps).append((stamp, bag_time))
        if not self._depth_stamps:
            raise FileFormatError(f"depth topic {self._depth.topic} holds no images")
        if not self._color_stamps:
            raise FileFormatError(f"colour topic {self._color.topic} holds no images")
        self._color_stamps.sort()
        self._color_keys = [s for s, _ in self._color_stamps]

    # --- the FrameSource protocol -----------------------------------------------------------------------

    def __len__(self) -> int:
        return len(self._depth_stamps)

    def names(self) -> list[str]:
        return [f"{self.path.stem}_{i:05d}_{s}" for i, (s, _) in enumerate(self._depth_stamps)]

    def _message(self, conn: Any, bag_time: int) -> tuple[Any, bytes]:
        for c, _, raw in self._reader.messages(connections=[conn], start=bag_time, stop=bag_time + 1):
            return self._deserialize(raw, c)
        raise FileFormatError(f"no message on {conn.topic} at {bag_time}")  # pragma: no cover

    def read_raw(self, index: int) -> tuple[np.ndarray, np.ndarray, float, int]:
        """Frame ``index`` unaligned: colour (h, w, 3) uint8 RGB, depth (h_d, w_d) uint16 units, metres per
        unit, and the colour image's stamp (ns)."""
        if not 0 <= index < len(self._depth_stamps):
            raise IndexError(f"frame index {index} out of range for {len(self._depth_stamps)} frames")
        stamp, bag_time = self._depth_stamps[index]
        j = bisect.bisect_left(self._color_keys, stamp)
        near = min((k for k in (j - 1, j) if 0 <= k < len(self._color_keys)),
                   key=lambda k: abs(self._color_keys[k] - stamp))  # fmt: skip
        if abs(self._color_keys[near] - stamp) > self.max_skew * 1e9:
            raise FileFormatError(f"{self.path}: no colour image within {self.max_skew} s of depth at {stamp}")
        try:
            dmsg, tail = self._message(self._depth, bag_time)
            cmsg, _ = self._message(self._color, self._color_stamps[near][1])
            color = color_image(cmsg, self._color.msgtype)
            if str(dmsg.encoding).lower() not in _DEPTH_ENCODINGS:
                raise FileFormatError(f"depth image encoding {shown(dmsg.encoding)}: expected mono16 (Z16) units")
            units = image_array(dmsg, self._depth.msgtype)
            scale = self.depth_units
            if scale is None:
                if len(tail) != 4:
                    raise FileFormatError("no depth units recorded (no option/Depth Units/value topic, none on the "
                                          "image)")  # fmt: skip
                scale = _check_units(struct.unpack("<f" if not dmsg.is_bigendian else ">f", tail)[0], "image")
            for what, img, lens in (
                ("depth", units, self.depth_stream.lens),
                ("colour", color, self.color_stream.lens),
            ):
                if img.shape[:2] != (lens.camera.height, lens.camera.width):
                    raise FileFormatError(f"{what} image is {img.shape[1]}x{img.shape[0]} but its camera info says "
                                          f"{lens.camera.width}x{lens.camera.height}")  # fmt: skip
        except SymfruitError as exc:
            message = str(exc)
            raise FileFormatError(
                message if message.startswith(str(self.path)) else f"{self.path}: {message}"
            ) from None
        return color, units, scale, self._color_keys[near]

    def read(self, index: int) -> Frame:
        with unchanged_while(self._files, "since the bag was opened"):
            return self._read(index)

    def _read(self, index: int) -> Frame:
        color, units, scale, stamp = self.read_raw(index)
        depth = np.multiply(units, np.float32(scale), dtype=np.float32)
        aligned = align_depth(depth, self.depth_stream.lens, self.color_stream.lens, self.rotation, self.translation)
        depth_stamp = self._depth_stamps[index][0]
        return named_frame(f"{self.path}@{depth_stamp}", f"{self.path.stem}_{index:05d}_{depth_stamp}", color, aligned,
                           self.color_stream.lens.camera, source=f"{self.path}@{depth_stamp}", stamp=stamp,
                           extras={"depth_units": scale, "aligned_by": "symfruit"})  # fmt: skip

    def close(self) -> None:
        """Close the bag."""
        reader = getattr(self, "_reader", None)
        if reader is not None:
            try:
                reader.close()
            except Exception:
                pass
            self._reader = None

    def __enter__(self) -> RealSenseBagSource:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _streams(topics: Sequence[str], most: int = 6) -> str:
    """What a recording without a needed stream holds, for its error: the image streams (``.../NAME/image/data``
    topics) by name, at most ``most`` of them and each cut to 60 characters, and how many topics in all (a bag's
    topics alone ran to 800 characters, the file's own text unbounded)."""
    streams = [t[1 : -len("/image/data")] for t in topics if t.endswith("/image/data")]
    named = [t if len(t) <= 60 else t[:57] + "..." for t in streams[:most]]
    if len(streams) > most:
        named.append(f"{len(streams) - most} more")
    held = f"its image streams: {', '.join(named)}" if named else "no image stream"
    return f"{held}; {len(topics)} topic{'s' if len(topics) != 1 else ''} in all"


def _check_units(value: float, what: str) -> float:
    if not (np.isfinite(value) and 0 < value <= 1):
        raise FileFormatError(f"depth units from {what} must be metres per unit in (0, 1], got {value!r}")
    return float(value)


def _header_ns(msg: Any) -> int:
    stamp = msg.header.stamp
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def _raw_header_ns(raw: Any) -> int:
    """The header stamp of a ROS 1 message whose body cannot be deserialised (``seq``, then ``secs`` and ``nsecs``
    as little-endian uint32); 0 when not even those 12 bytes are there."""
    if len(raw) < 12:
        return 0
    secs, nsecs = struct.unpack_from("<II", bytes(raw[:12]), 4)
    return secs * 1_000_000_000 + nsecs


def _require_pyrealsense2() -> Any:
    try:
        import pyrealsense2 as rs
    except ImportError as exc:  # no wheel for this platform, or libusb-1.0 missing
        raise SymfruitError(
            f"the SDK comparison needs pyrealsense2: pip install 'symfruit[realsense]' ({exc})"
        ) from None
    return rs


def sdk_aligned(path: str | Path, *, timeout_ms: int = 5000, attempts: int = 10) -> Iterator[tuple[int, np.ndarray]]:
    """Play a recording with the RealSense SDK (pyrealsense2, extra ``realsense``) and align its depth to
    colour with ``rs.align``: ``(depth stamp in ns, (h, w) float32 metres)`` per depth frame the SDK's pipeline
    delivers, in order, each once. No camera is needed.

    The stamps are the depth images' header stamps, as :class:`RealSenseBagSource` names its frames. The SDK's
    pipeline pairs depth with colour and may leave frames out (one of the two of ``examples/realsense/fruit.bag``).
    A playback starts in real time until it is switched off, a moment after the pipeline starts: on a loaded
    machine it can run to its end before a frame is taken (about 1 start in 150 with both cores busy), and it
    then says "stopped", as a playback that has not started yet does. One that stays stopped for a second
    without a frame is started again, up to ``attempts`` times, within ``timeout_ms`` in all.
    """
    rs = _require_pyrealsense2()
    seen: set[int] = set()
    deadline = time.monotonic() + timeout_ms / 1000.0
    for _ in range(max(1, attempts)):
        yield from _sdk_playback(rs, path, deadline, seen)
        if seen or time.monotonic() >= deadline:
            return


def _sdk_playback(
    rs: Any, path: str | Path, deadline: float, seen: set[int], *, stopped_ms: int = 1000
) -> Iterator[tuple[int, np.ndarray]]:
    """One playback of :func:`sdk_aligned` until it ends, stays stopped ``stopped_ms`` without a frame or the
    ``deadline`` (``time.monotonic()``) passes; the stamps yielded are added to ``seen`` (and not yielded again)."""
    config = rs.config()
    config.enable_device_from_file(str(path), repeat_playback=False)
    pipeline = rs.pipeline()
    try:
        profile = pipeline.start(config)
    except RuntimeError as exc:
        raise FileFormatError(f"{path}: the SDK cannot play it ({exc})") from None
    try:
        device = profile.get_device()
        playback = device.as_playback()
        playback.set_real_time(False)
        scale = device.first_depth_sensor().get_depth_scale()
        align = rs.align(rs.stream.color)
        taken = 0
        stopped_for = 0
        while True:
            ok, frames = pipeline.try_wait_for_frames(100)
            if not ok:  # the end of the file, a playback not started yet or one that ran out unseen
                stopped = playback.current_status() == rs.playback_status.stopped
                stopped_for = stopped_for + 100 if stopped else 0
                if (stopped and taken) or stopped_for >= stopped_ms or time.monotonic() >= deadline:
                    return
                continue
            taken += 1
            aligned = align.process(frames)
            depth = aligned.get_depth_frame()
            if not depth:
                continue
            stamp = round(depth.get_timestamp() * 1e6)  # ms -> ns, as the image header holds it
            if stamp in seen:
                continue
            seen.add(stamp)
            units = np.asanyarray(depth.get_data())
            yield stamp, np.multiply(units, np.float32(scale), dtype=np.float32)
    finally:
        pipeline.stop()
