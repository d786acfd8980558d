"""Frames from ROS 1 / ROS 2 bags, through the pure-Python ``rosbags`` package (optional extra ``bag``).

Colour (``sensor_msgs/Image`` rgb8/bgr8/rgba8/bgra8, or ``CompressedImage``), depth (``Image`` 16UC1 in
millimetres or 32FC1 in metres) and ``CameraInfo`` topics are found by type and name (a topic whose
name contains "depth" is depth); each depth image is paired with the colour image nearest in time
(within ``max_skew``) and the latest camera info.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np

from ..errors import FileFormatError, SymfruitError

__all__ = ["iter_bag"]


def _require_rosbags():
    try:
        from rosbags.highlevel import AnyReader
    except ImportError:
        raise SymfruitError(
            "reading bags needs the rosbags package: pip install 'symfruit[bag]' (or pip install rosbags)"
        ) from None
    return AnyReader


def _to_array(msg, typename: str) -> np.ndarray:
    if typename.endswith("CompressedImage"):
        import io

        from PIL import Image

        return np.asarray(Image.open(io.BytesIO(bytes(msg.data))).convert("RGB"))
    enc = msg.encoding.lower()
    dtype, channels = {
        "rgb8": (np.uint8, 3), "bgr8": (np.uint8, 3), "rgba8": (np.uint8, 4), "bgra8": (np.uint8, 4),
        "mono8": (np.uint8, 1), "16uc1": (np.uint16, 1), "mono16": (np.uint16, 1), "32fc1": (np.float32, 1),
    }.get(enc, (None, 0))  # fmt: skip
    if dtype is None:
        raise FileFormatError(f"unsupported image encoding {msg.encoding!r}")
    dt = np.dtype(dtype).newbyteorder(">" if msg.is_bigendian else "<")
    row = np.frombuffer(bytes(msg.data), dtype=np.uint8).reshape(msg.height, msg.step)
    img = row[:, : msg.width * channels * dt.itemsize].copy().view(dt).reshape(msg.height, msg.width, channels)
    img = img.astype(dtype)
    if enc.startswith("bgr"):
        img = img[:, :, [2, 1, 0]]
    return img[:, :, 0] if channels == 1 else img[:, :, :3]


def iter_bag(path: Path, *, max_skew: float = 0.05) -> Iterator[tuple[str, object]]:
    """Yield ``(name, Frame or error)`` for every depth image of the bag that has a colour partner."""
    from ..camera import Camera
    from .frames import Frame

    reader_cls = _require_rosbags()
    try:
        reader = reader_cls([path])
        reader.open()
    except Exception as exc:  # rosbags raises its own ReaderError / AnyReaderError types
        raise FileFormatError(f"{path}: cannot open bag ({exc})") from None
    try:
        conns = reader.connections
        info = [c for c in conns if c.msgtype.endswith("CameraInfo")]
        images = [c for c in conns if c.msgtype.endswith(("/Image", "/CompressedImage"))]
        depth_c = [c for c in images if "depth" in c.topic.lower()]
        color_c = [c for c in images if "depth" not in c.topic.lower()]
        if not depth_c or not color_c:
            raise FileFormatError(f"{path}: bag needs a colour and a depth image topic (topics: "
                                  f"{', '.join(c.topic for c in conns)})")  # fmt: skip
        colours: list[tuple[int, object, str]] = []
        depths: list[tuple[int, object, str]] = []
        camera = None
        for conn, stamp, raw in reader.messages(connections=info + depth_c[:1] + color_c[:1]):
            try:
                msg = reader.deserialize(raw, conn.msgtype)
            except Exception as exc:
                raise FileFormatError(f"{path}: corrupt message on {conn.topic} ({exc})") from None
            if conn in info:
                k = list(getattr(msg, "k", getattr(msg, "K", [])))
                camera = Camera(fx=k[0], fy=k[4], cx=k[2], cy=k[5], width=msg.width, height=msg.height)
            elif conn in depth_c:
                depths.append((stamp, msg, conn.msgtype))
            else:
                colours.append((stamp, msg, conn.msgtype))
    finally:
        reader.close()
    if camera is None:
        raise FileFormatError(f"{path}: bag has no CameraInfo topic")
    stamps = np.array([c[0] for c in colours])
    for i, (stamp, dmsg, dtype) in enumerate(depths):
        name = f"{Path(path).stem}_{i:05d}_{stamp}"
        try:
            j = int(np.argmin(np.abs(stamps - stamp)))
            if abs(int(stamps[j]) - stamp) > max_skew * 1e9:
                raise FileFormatError(f"no colour image within {max_skew} s of depth at {stamp}")
            color = _to_array(colours[j][1], colours[j][2])
            raw = _to_array(dmsg, dtype)
            depth = raw.astype(np.float32) * (0.001 if raw.dtype == np.uint16 else 1.0)
            depth = np.nan_to_num(depth, nan=0.0, posinf=0.0, neginf=0.0)
            yield (
                name,
                Frame(name, np.ascontiguousarray(color, dtype=np.uint8), depth, camera, source=f"{path}@{stamp}"),
            )
        except SymfruitError as exc:
            yield name, exc
