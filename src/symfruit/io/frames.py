"""RGB-D frames on disk: a folder per frame, folders of frames, and ROS bags.

A frame folder holds::

    color.png | color.jpg     colour image, 8-bit RGB
    depth.png                 depth aligned to colour, 16-bit, times depth_scale metres per unit
    depth.npy                 ... or depth as float metres (0 or NaN: no depth)
    camera.json | .yaml       intrinsics in any layout symfruit reads; an optional "depth_scale"
                              (metres per unit, default 0.001 as on Intel D400 cameras)
    masks.png                 optional: instance labels, 0 background, k fruit k (8- or 16-bit)
    masks.json                optional: COCO-style annotations (polygons or RLE)
    truth.json                optional: {"fruits": [{"id", "min", "max", ...}]}, true boxes in metres

A folder whose sub-folders are frame folders is a recording; so is a ROS 1 ``.bag`` or ROS 2 bag
folder, read with the ``rosbags`` package (``pip install 'symfruit[bag]'``).
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..box import Box
from ..camera import Camera
from ..errors import FileFormatError, InputError
from .atomic import atomic_write, write_json

__all__ = ["Frame", "is_frame_folder", "iter_frames", "read_frame", "write_frame"]

DEFAULT_DEPTH_SCALE = 0.001


@dataclass(frozen=True)
class Frame:
    """One RGB-D frame.

    Attributes
    ----------
    name : str
    color : (h, w, 3) uint8
    depth : (h, w) float32, metres; 0 where the sensor returned nothing
    camera : Camera
    masks : (h, w) int, optional; instance labels from the frame's own ``masks.*``
    truth : list of (id, Box), optional
    source : str
        Where it came from (folder, or bag and timestamp).
    """

    name: str
    color: np.ndarray
    depth: np.ndarray
    camera: Camera
    masks: np.ndarray | None = None
    truth: list[tuple[int, Box]] | None = None
    source: str = ""
    extras: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        h, w = self.depth.shape[:2]
        if self.color.shape[:2] != (h, w):
            raise InputError(
                f"frame {self.name}: colour is {self.color.shape[1]}x{self.color.shape[0]} but depth is {w}x{h}; "
                "depth must be aligned to the colour image"
            )
        if (self.camera.width, self.camera.height) != (w, h):
            raise InputError(
                f"frame {self.name}: intrinsics are for {self.camera.width}x{self.camera.height} "
                f"but the images are {w}x{h}"
            )


def _image(path: Path) -> np.ndarray:
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as img:
            img.load()
            return np.asarray(img)
    except (UnidentifiedImageError, OSError, SyntaxError, ValueError) as exc:
        raise FileFormatError(f"{path}: cannot read image ({exc})") from None


def _first(folder: Path, *names: str) -> Path | None:
    for name in names:
        if (folder / name).is_file():
            return folder / name
    return None


def is_frame_folder(folder: Path) -> bool:
    return folder.is_dir() and _first(folder, "color.png", "color.jpg", "color.jpeg") is not None


def read_frame(folder: str | Path) -> Frame:
    """Read a frame folder (layout above).

    Raises
    ------
    FileFormatError or InputError
        Naming the file and the problem: missing file, unreadable image, sizes that disagree, unknown
        depth units.
    """
    from .masks import read_masks

    folder = Path(folder)
    if not folder.is_dir():
        raise FileFormatError(f"{folder}: no such frame folder")
    color_path = _first(folder, "color.png", "color.jpg", "color.jpeg")
    if color_path is None:
        raise FileFormatError(f"{folder}: no color.png or color.jpg")
    cam_path = _first(folder, "camera.json", "camera.yaml", "camera.yml")
    if cam_path is None:
        raise FileFormatError(f"{folder}: no camera.json (intrinsics)")
    from .intrinsics import camera_from_file_data, read_mapping

    cam_data = read_mapping(cam_path)
    camera = camera_from_file_data(cam_path, cam_data)
    scale = _depth_scale(cam_path, cam_data)
    color = _image(color_path)
    if color.ndim == 2:
        color = np.repeat(color[:, :, None], 3, axis=2)
    color = np.ascontiguousarray(color[:, :, :3]).astype(np.uint8)
    depth_png, depth_npy = folder / "depth.png", folder / "depth.npy"
    if depth_png.is_file():
        raw = _image(depth_png)
        if raw.ndim != 2 or raw.dtype not in (np.uint16, np.int32, np.uint8):
            raise FileFormatError(f"{depth_png}: depth PNG must be single-channel 16-bit, got {raw.dtype} {raw.shape}")
        depth = raw.astype(np.float32) * np.float32(scale)
    elif depth_npy.is_file():
        try:
            depth = np.load(depth_npy, allow_pickle=False)
        except (ValueError, OSError, EOFError) as exc:
            raise FileFormatError(f"{depth_npy}: cannot read ({exc})") from None
        if depth.ndim != 2 or not np.issubdtype(depth.dtype, np.floating):
            raise FileFormatError(f"{depth_npy}: depth must be a 2-D float array in metres")
        depth = np.nan_to_num(depth.astype(np.float32), nan=0.0, posinf=0.0, neginf=0.0)
    else:
        raise FileFormatError(f"{folder}: no depth.png or depth.npy")
    masks = read_masks(folder, color.shape[:2]) if _first(folder, "masks.png", "masks.json") else None
    truth = _read_truth(folder / "truth.json") if (folder / "truth.json").is_file() else None
    return Frame(folder.name, color, depth, camera, masks, truth, str(folder))


def _depth_scale(cam_path: Path, data: Any) -> float:
    """Metres per depth unit from the parsed camera file (``depth_scale`` or ``depth_units``)."""
    scale = data.get("depth_scale", DEFAULT_DEPTH_SCALE) if isinstance(data, dict) else DEFAULT_DEPTH_SCALE
    units = data.get("depth_units") if isinstance(data, dict) else None
    if units is not None:
        known = {"m": 1.0, "mm": 0.001, "0.1mm": 0.0001, "cm": 0.01}
        if units not in known:
            raise InputError(f"{cam_path}: unknown depth_units {units!r}; use one of {', '.join(known)} or depth_scale")
        scale = known[units]
    if isinstance(scale, bool) or not isinstance(scale, (int, float)) or not 0 < scale < 1:
        raise InputError(f"{cam_path}: depth_scale must be metres per unit in (0, 1), got {scale!r}")
    return float(scale)


def _read_truth(path: Path) -> list[tuple[int, Box]]:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        fruits = data["fruits"] if isinstance(data, dict) else data
        out = []
        for k, item in enumerate(fruits, 1):
            if item.get("ripe", True) is False:
                continue  # unripe fruit are not targets
            out.append((int(item.get("id", k)), Box(np.array(item["min"], float), np.array(item["max"], float))))
        return out
    except (ValueError, KeyError, TypeError, AttributeError) as exc:
        raise FileFormatError(
            f"{path}: expected {{'fruits': [{{'min': [x, y, z], 'max': [x, y, z]}}]}} ({exc})"
        ) from None


def write_frame(
    folder: str | Path, color: np.ndarray, depth: np.ndarray, camera: Camera, *, truth: dict | None = None,
    masks: np.ndarray | None = None, depth_scale: float = DEFAULT_DEPTH_SCALE,
) -> Path:  # fmt: skip
    """Write a frame folder: colour PNG, 16-bit depth PNG, camera.json (with depth_scale), truth, masks."""
    from PIL import Image

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    units = np.clip(np.rint(np.nan_to_num(depth) / depth_scale), 0, 65535).astype(np.uint16)
    for name, img in (("color.png", Image.fromarray(color)), ("depth.png", Image.fromarray(units))):
        with atomic_write(folder / name, "wb") as handle:
            img.save(handle, format="PNG", optimize=True)
    write_json(folder / "camera.json", {**camera.to_dict(), "depth_scale": depth_scale})
    if truth is not None:
        write_json(folder / "truth.json", truth)
    if masks is not None:
        with atomic_write(folder / "masks.png", "wb") as handle:
            Image.fromarray(masks.astype(np.uint16 if masks.max() > 255 else np.uint8)).save(handle, format="PNG")
    return folder


def iter_frames(source: str | Path) -> Iterator[tuple[str, Frame | Exception]]:
    """Frames of a frame folder, a folder of frame folders, or a bag: ``(name, frame or the error)``.

    A frame that cannot be read comes back as its error, so a batch can record it and go on.
    """
    source = Path(source)
    if source.suffix == ".bag" or (source.is_dir() and (source / "metadata.yaml").is_file()):
        from .bags import iter_bag

        yield from iter_bag(source)
        return
    if is_frame_folder(source):
        folders = [source]
    elif source.is_dir():
        folders = sorted(p for p in source.iterdir() if p.is_dir() and not p.name.startswith("."))
        if not folders:
            raise FileFormatError(
                f"{source}: neither a frame folder (color.png, depth.png, camera.json) nor a folder of them"
            )
    else:
        raise FileFormatError(f"{source}: no such frame folder, folder of frames or bag")
    for folder in folders:
        try:
            yield folder.name, read_frame(folder)
        except (FileFormatError, InputError) as exc:
            yield folder.name, exc
