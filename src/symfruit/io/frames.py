"""RGB-D frames on disk: a folder per frame, folders of frames, and ROS bags.

A frame folder holds::

    color.png | color.jpg     colour image, 8-bit RGB, read as displayed (an EXIF orientation applied; one of them)
    depth.png                 depth aligned to colour, 16-bit, times depth_scale metres per unit
    depth.npy                 ... or depth as float metres (0, NaN, inf or beyond 1e6 m: no depth)
    camera.json | .yaml       intrinsics in any layout symfruit reads; an optional "depth_scale"
                              (metres per unit, default 0.001 as on Intel D400 cameras)
    masks.png                 optional: instance labels, 0 background, k fruit k (8- or 16-bit)
    masks.json                ... or COCO-style annotations (polygons or RLE)
    truth.json                optional: {"fruits": [{"id", "min", "max", "visible", "ripe", ...}]}, true boxes in
                              metres (other keys left alone, one a letter or two from these refused; ids
                              unique, ripe true or false)

Of the depth, intrinsics and mask files a frame holds one each: two (``depth.png`` and ``depth.npy``,
``camera.json`` and ``camera.yaml``, ``masks.png`` and ``masks.json``) are refused by name, never one taken in
silence. A folder whose sub-folders are frame folders is a recording (:mod:`.sources`); so is a ROS 1 ``.bag`` or
ROS 2 bag folder (:mod:`.bags`).
"""

from __future__ import annotations

import errno
import os
from pathlib import Path
from typing import Any

import numpy as np

from ..core.box import Box
from ..core.camera import Camera
from ..core.frame import Frame
from ..core.limits import (
    MAX_DEPTH_METRES,
    MAX_IMAGE_PIXELS,
    MAX_LABEL_ID,
    MAX_TRUTH_BYTES,
    check_image_size,
    depth_metres,
    instance_labels,
    shown,
    typical_depth,
)
from ..errors import FileFormatError, InputError
from .atomic import atomic_write, write_json
from .images import (
    MIN_16BIT_DEPTH_REACH,
    float_depth,
    orientation_mismatch,
    read_color_oriented,
    read_depth_units_oriented,
    turned_mismatch,
)
from .text import as_path, holds_file, read_structured, unchanged_while

__all__ = [
    "COLOR_FILE",
    "COLOR_NAMES",
    "DEFAULT_DEPTH_SCALE",
    "file_depth_scale",
    "is_frame_folder",
    "named_frame",
    "read_depth",
    "read_depth_npy",
    "read_frame",
    "read_truth",
    "write_frame",
]

DEFAULT_DEPTH_SCALE = 0.001
#: ``Frame.extras`` key of a frame read from a folder: its colour file and the EXIF orientation applied to it on
#: reading, which mask files given for the frame (``--masks``) must carry too. Frames without it (bags, arrays)
#: hold pixels as stored: orientation 1.
COLOR_FILE = "color_file"
#: Colour image names a frame folder may use, in order of preference.
COLOR_NAMES = ("color.png", "color.jpg", "color.jpeg")
#: The other files a frame folder's frame is read from (:func:`read_frame`).
FRAME_FILES = ("camera.json", "camera.yaml", "camera.yml", "depth.png", "depth.npy", "masks.png", "masks.json",
               "truth.json")  # fmt: skip
#: Largest truth.json read (bytes), and largest depth.npy (elements): :mod:`symfruit.core.limits`.
MAX_DEPTH_ELEMENTS = MAX_IMAGE_PIXELS


def _only(folder: Path, *names: str) -> Path | None:
    """The one file of ``names`` the frame folder holds, or None; two of them are refused: two depth images or
    intrinsics or mask files that may disagree, one of them taken in silence, would not be the one meant."""
    given = [folder / n for n in names if holds_file(folder / n)]
    if len(given) > 1:
        raise FileFormatError(f"{folder}: holds both {given[0].name} and {given[1].name}; which one is meant? Keep "
                              "one")  # fmt: skip
    return given[0] if given else None


def _not_read(folder: Path, stem: str, most: int = 3) -> str:
    """For the error of a frame folder missing its ``stem`` file: the files it holds under that name that are
    not read (``depth.tiff``, ``Depth.PNG``, ``depth.png.bak``), at most ``most`` named, or nothing."""
    try:
        with os.scandir(folder) as entries:
            near = sorted(e.name for e in entries if e.name.lower().startswith(stem + "."))
    except OSError:
        return ""
    if not near:
        return ""
    named = ", ".join(shown(n) if len(n) > 40 else n for n in near[:most])
    more = f" and {len(near) - most} more" if len(near) > most else ""
    return f"; found {named}{more}, not read: only the names above are"


def unreadable_folder(path: Path) -> bool:
    """Whether ``path`` is a folder this process's user may not list or open anything in (its mode; root may
    always): asking whether it holds a file then raised pathlib's ``PermissionError`` (stop 52, robust52)."""
    return path.is_dir() and not os.access(
        path, os.R_OK | os.X_OK, effective_ids=os.access in os.supports_effective_ids
    )


def is_frame_folder(folder: Path) -> bool:
    """Whether ``folder`` holds an entry under one of :data:`COLOR_NAMES` (a colour image; anything else of
    that name is then refused by name when the frame is read)."""
    return folder.is_dir() and any(os.path.lexists(folder / name) for name in COLOR_NAMES)


def read_frame(folder: str | Path) -> Frame:
    """Read a frame folder (layout above).

    Raises
    ------
    FileFormatError or InputError
        Naming the file and the problem: missing file, unreadable image, sizes that disagree, unknown
        depth units, a file changed while the frame was read.
    """
    folder = as_path(folder, "read_frame: the frame folder")
    if not folder.is_dir():
        raise FileFormatError(f"{folder}: no such frame folder")
    if unreadable_folder(folder):
        raise FileFormatError(f"{folder}: cannot read frame folder ({os.strerror(errno.EACCES)}: this user may not "
                              "list it or open what it holds)")  # fmt: skip
    # every file a frame may be read from, looked at before and after: one changed in between fails the frame
    with unchanged_while([folder / name for name in (*COLOR_NAMES, *FRAME_FILES)], "while the frame was read"):
        return _read_frame(folder)


def _read_frame(folder: Path) -> Frame:
    """:func:`read_frame` of a folder that is one and may be read."""
    from .intrinsics import camera_from_file_data, read_mapping
    from .masks import read_masks

    color_path = _only(folder, *COLOR_NAMES)  # color.png beside color.jpg: which one is meant?
    if color_path is None:
        raise FileFormatError(f"{folder}: no color.png or color.jpg")
    cam_path = _only(folder, "camera.json", "camera.yaml", "camera.yml")
    if cam_path is None:
        raise FileFormatError(f"{folder}: no camera.json (intrinsics){_not_read(folder, 'camera')}")
    cam_data = read_mapping(cam_path)
    camera = camera_from_file_data(cam_path, cam_data)
    scale = _depth_scale(cam_path, cam_data)
    color, color_orientation = read_color_oriented(color_path)
    depth_file = _only(folder, "depth.png", "depth.npy")
    if depth_file is None:
        raise FileFormatError(f"{folder}: no depth.png or depth.npy{_not_read(folder, 'depth')}")
    if depth_file.suffix.lower() != ".npy" and 65535 * scale < MIN_16BIT_DEPTH_REACH:  # the scale's file, named
        raise InputError(f"{cam_path}: depth_scale {scale:g} m per unit: {depth_file.name}'s 16-bit units would reach "
                         f"only {65535 * scale:.3g} m, and no camera measures depth that finely (0.001 for "
                         "millimetres)")  # fmt: skip
    depth = read_depth(depth_file, scale, color=(color_path, color_orientation))
    if (
        depth_file.suffix.lower() != ".npy"
        and (typical := typical_depth(depth)) is not None
        and (typical > MAX_DEPTH_METRES)
    ):  # the units are the scale's (stop 48, robust48: "FOLDER: depth is 7009 m typically", the frame folder alone)
        raise InputError(f"{cam_path}: at its depth scale, {scale:g} m per unit, {depth_file.name}'s depth is "
                         f"{typical:.4g} m typically: its units look like millimetres or finer; state their scale "
                         "(0.001 for millimetres)")  # fmt: skip
    turned_mismatch(color_path, color.shape, {f"the intrinsics ({cam_path.name})": (camera.height, camera.width)})
    if (camera.height, camera.width) != color.shape[:2] == depth.shape[:2]:  # the intrinsics' file named (the frame
        # alone before; images of two sizes: the Frame's error says which)
        raise InputError(f"{cam_path}: intrinsics are for {camera.width}x{camera.height} but the images are "
                         f"{color.shape[1]}x{color.shape[0]}; give the colour camera's intrinsics at the images' "
                         "size")  # fmt: skip
    # a label image too must turn as the colour does: a mirrored or half-turned mask keeps the size
    oriented = (str(color_path), color_orientation)
    masks = read_masks(folder, color.shape[:2], color=oriented) if _only(folder, "masks.png", "masks.json") else None
    truth, visible = _truth(folder / "truth.json") if holds_file(folder / "truth.json") else (None, {})
    return named_frame(str(folder), folder.name, color, depth, camera, masks, truth, str(folder), visible=visible,
                       extras={COLOR_FILE: oriented})  # fmt: skip


def named_frame(where: str, name: str, *args: Any, **kwargs: Any) -> Frame:
    """``Frame(name, *args, **kwargs)`` for a reader: a frame it refuses (colour, depth and intrinsics of
    different sizes, depth in millimetres...) is refused naming ``where`` (the folder, the bag and stamp)
    instead of the frame's name alone."""
    try:
        return Frame(name, *args, **kwargs)
    except InputError as exc:
        raise InputError(f"{where}: {str(exc).removeprefix(f'frame {name}: ')}") from None


def read_depth(path: Path, scale: float, *, color: tuple[str | Path, int], dtype: Any = np.float32) -> np.ndarray:
    """Depth in metres (``dtype``) from ``.npy`` (float metres: :func:`read_depth_npy`) or a depth image (16-bit
    units, ``scale`` metres each: :func:`~symfruit.io.images.read_depth_units`), for the colour image ``color``:
    its file and the EXIF orientation applied to it on reading, which the depth image must carry too (depth
    registered to a phone photo's stored pixels is refused naming both files, never paired turned). The one
    reader of a depth file beside a colour image: frame folders and ``symfruit segment --depth``."""
    depth_orientation = 1  # a .npy array has none
    if path.suffix.lower() == ".npy":
        depth = read_depth_npy(path).astype(dtype, copy=False)  # sizes checked from the header; never unpickled
    else:
        units, depth_orientation = read_depth_units_oriented(path, scale=scale)
        depth = units.astype(dtype) * np.dtype(dtype).type(scale)
    orientation_mismatch(color[0], color[1], path, depth_orientation)
    return depth


def read_depth_npy(path: Path) -> np.ndarray:
    """A float depth image in metres from ``.npy`` (never unpickled; size checked from the header)."""
    from .clouds import npy_header

    shape, dtype = npy_header(path)
    if len(shape) != 2 or dtype.kind != "f":
        raise FileFormatError(f"{path}: depth must be a 2-D float array in metres, got {dtype} {shape}")
    if int(np.prod(shape)) > MAX_DEPTH_ELEMENTS:
        raise FileFormatError(f"{path}: depth is {shape[1]}x{shape[0]}; at most {MAX_DEPTH_ELEMENTS:,} pixels are read")
    check_image_size(shape[1], shape[0], str(path), error=FileFormatError)
    try:
        depth = np.load(path, allow_pickle=False)
    except (ValueError, OSError, EOFError) as exc:
        raise FileFormatError(f"{path}: cannot read ({exc})") from None
    return float_depth(depth)  # NaN, inf, beyond float32 or NO_DEPTH_BEYOND (FLT_MAX, a sentinel): no depth


def file_depth_scale(path: str | Path) -> float | None:
    """The depth scale (metres per unit) an intrinsics file states (``depth_scale`` or ``depth_units``, as a
    frame's ``camera.json`` does), or None where it states none: what ``segment --depth`` with ``--camera``
    reads 16-bit depth by."""
    from .intrinsics import read_mapping

    path = as_path(path, "file_depth_scale: the intrinsics file")
    data = read_mapping(path)
    if not isinstance(data, dict) or ("depth_scale" not in data and "depth_units" not in data):
        return None
    return _depth_scale(path, data)


def _depth_scale(cam_path: Path, data: Any) -> float:
    """Metres per depth unit from the parsed camera file (``depth_scale`` or ``depth_units``)."""
    scale = data.get("depth_scale", DEFAULT_DEPTH_SCALE) if isinstance(data, dict) else DEFAULT_DEPTH_SCALE
    units = data.get("depth_units") if isinstance(data, dict) else None
    if units is not None:
        known = {"m": 1.0, "mm": 0.001, "0.1mm": 0.0001, "cm": 0.01}
        if not isinstance(units, str) or units not in known:  # a list or mapping is no unit (nor hashable)
            raise InputError(f"{cam_path}: unknown depth_units {shown(units)}; use one of {', '.join(known)} or "
                             "depth_scale")  # fmt: skip
        if isinstance(data, dict) and "depth_scale" in data and data["depth_scale"] != known[units]:
            raise InputError(f"{cam_path}: depth_scale {shown(data['depth_scale'])} and depth_units {units!r} "
                             f"({known[units]:g} m) disagree; which one is meant? Keep one")  # fmt: skip
        scale = known[units]
    if isinstance(scale, bool) or not isinstance(scale, (int, float)) or not 0 < scale <= 1:
        raise InputError(f"{cam_path}: depth_scale must be metres per unit in (0, 1], got {shown(scale)}")
    return float(scale)


def read_truth(path: Path) -> list[tuple[int, Box]]:
    """The ripe fruit of a ``truth.json``: ``[(id, Box)]`` (unripe fruit, ``"ripe": false``, are no targets)."""
    return _truth(path)[0]


def _truth(path: Path) -> tuple[list[tuple[int, Box]], dict[int, float]]:
    """:func:`read_truth`, and the share of each fruit's silhouette the camera sees where a fruit records one
    (``"visible"``, in [0, 1])."""
    data = read_structured(path, what="truth file", max_bytes=MAX_TRUTH_BYTES)
    try:
        fruits = data["fruits"] if isinstance(data, dict) else data
        if not isinstance(fruits, list):
            raise TypeError("'fruits' is not a list")
        out, visible = [], {}
        seen_ids: dict[int, int] = {}  # every fruit's id (unripe ones' too: a label is one fruit's) -> its number
        for k, item in enumerate(fruits, 1):
            if not isinstance(item, dict):
                raise TypeError(f"fruit {k} is not an object")
            _misspelt_truth_key(item, k)
            ripe = item.get("ripe", True)
            if not isinstance(ripe, bool):  # "false" or 0 is not False: it would count an unripe fruit as a target
                raise ValueError(f"fruit {k}: ripe must be true or false, got {shown(ripe)}")
            fid = item.get("id", k)
            if isinstance(fid, int) and not isinstance(fid, bool):  # other ids are refused below, if ripe
                if fid == 0:  # matched with no fruit, ever: label 0 is the masks' background
                    raise ValueError(f"fruit {k}: id 0 is no mask label (0 is the background; labels start at 1)")
                if fid in seen_ids:
                    raise ValueError(f"fruit {k}: id {fid} is fruit {seen_ids[fid]}'s too; each fruit has its own "
                                     "id (its mask label)")  # fmt: skip
                seen_ids[fid] = k
            if not ripe:
                continue
            for key in ("min", "max"):  # numpy reads "0.3" as 0.3 and true as 1: a corner is numbers
                corner = item[key]
                if isinstance(corner, list) and any(isinstance(v, bool | str | bytes) for v in corner):
                    raise ValueError(f"fruit {k}: {key} must be three numbers, got {shown(corner)}")
            lo, hi = np.array(item["min"], dtype=np.float64), np.array(item["max"], dtype=np.float64)
            if lo.shape != (3,) or hi.shape != (3,) or not (np.isfinite(lo).all() and np.isfinite(hi).all()):
                raise ValueError(f"fruit {k}: min and max need three finite numbers each")
            if (lo > hi).any():
                raise ValueError(f"fruit {k}: min {lo.tolist()} lies beyond max {hi.tolist()}")
            if max(np.abs(lo).max(), np.abs(hi).max()) > MAX_DEPTH_METRES:
                raise ValueError(f"fruit {k}: a box more than {MAX_DEPTH_METRES:g} m from the camera; boxes are in "
                                 "metres (these look like millimetres)")  # fmt: skip
            if isinstance(fid, bool) or not isinstance(fid, int) or not 1 <= fid <= MAX_LABEL_ID:
                raise ValueError(f"fruit {k}: id must be a whole number in 1-{MAX_LABEL_ID} (a label id)")
            out.append((fid, Box(lo, hi)))
            if "visible" in item:
                seen = item["visible"]
                if isinstance(seen, bool) or not isinstance(seen, int | float) or not 0.0 <= seen <= 1.0:
                    raise ValueError(f"fruit {k}: visible must be a share in [0, 1]")
                visible[fid] = float(seen)
        return out, visible
    except (ValueError, KeyError, TypeError, OverflowError) as exc:  # OverflowError: a 400-digit whole number
        raise FileFormatError(
            f"{path}: expected {{'fruits': [{{'min': [x, y, z], 'max': [x, y, z]}}]}} ({exc})"
        ) from None


#: The keys of a truth fruit that are read; other keys (a scene's ``kind``, ``centre``, ``size``, a detection's
#: fields) are kept out of the way, but one a letter or two from these is a misspelling that would be dropped.
TRUTH_KEYS = ("id", "min", "max", "ripe", "visible")


def _misspelt_truth_key(item: dict[str, Any], k: int) -> None:
    import difflib

    for key in item:
        if not isinstance(key, str) or key in TRUTH_KEYS:
            continue
        close = difflib.get_close_matches(key.lower(), TRUTH_KEYS, n=1, cutoff=0.75)
        # a letter or two off ("rip": false would count an unripe fruit as a target), not a longer name that
        # holds one ("visible_box" of a detection)
        if close and abs(len(key) - len(close[0])) <= 2 and close[0] not in item:
            raise ValueError(f"fruit {k}: unknown key {key!r}; did you mean {close[0]!r}?")


def write_frame(
    folder: str | Path, color: np.ndarray, depth: np.ndarray, camera: Camera, *, truth: dict | None = None,
    masks: np.ndarray | None = None, depth_scale: float = DEFAULT_DEPTH_SCALE,
) -> Path:  # fmt: skip
    """Write a frame folder: colour PNG, 16-bit depth PNG, camera.json (with depth_scale), truth, masks.

    Raises
    ------
    InputError
        Before anything is written, for what the folder could not hold as given (it would be read back as something
        else): a ``depth_scale`` that is not metres per unit in (0, 1] (as :func:`read_frame` requires), depth that
        is not float metres or reaches beyond 65535 units of it, colour that is not ``(h, w, 3)`` uint8, masks that
        are no instance labels or hold an id beyond 65535 (a 16-bit PNG's).
    """
    from PIL import Image

    folder = as_path(folder, "write_frame: the frame folder")  # '' was the working folder
    what = f"write_frame {folder}"
    if (
        isinstance(depth_scale, bool)
        or not isinstance(depth_scale, int | float | np.integer | np.floating)
        or not (0 < depth_scale <= 1)
    ):  # before: 0 wrote a depth image of 65535s and a camera.json read_frame refuses, NaN garbage units
        raise InputError(f"{what}: depth_scale must be metres per unit in (0, 1], got {shown(depth_scale)}")
    color = np.asarray(color)
    if color.ndim != 3 or color.shape[2] != 3 or color.dtype != np.uint8:
        raise InputError(f"{what}: colour must be (h, w, 3) uint8 RGB, got {color.dtype} {color.shape}")
    if not isinstance(camera, Camera):  # a mapping was an AttributeError (no to_dict) after the images were written
        raise InputError(f"{what}: camera must be a symfruit.Camera (symfruit.io.camera_from_dict makes one from a "
                         f"mapping), got {type(camera).__name__}")  # fmt: skip
    h, w = color.shape[:2]
    if (camera.width, camera.height) != (w, h):  # written before: a folder read_frame refuses
        raise InputError(f"{what}: the camera is for {camera.width}x{camera.height} images, the colour image is "
                         f"{w}x{h}")  # fmt: skip
    depth = depth_metres(depth, what)
    if depth.shape != (h, w):  # written before: depth of another size beside the colour, refused when read
        raise InputError(f"{what}: depth is {depth.shape[1] if depth.ndim > 1 else '?'}x{depth.shape[0]}, the "
                         f"colour image {w}x{h}; a frame's images are of one size")  # fmt: skip
    with np.errstate(invalid="ignore"):
        far = float(np.nanmax(np.where(np.isfinite(depth), depth, np.nan), initial=0.0))
    if far / depth_scale > 65535.5:  # clipped before: the far depth written as 65535 units in silence
        raise InputError(f"{what}: depth reaches {far:g} m, beyond 65535 units of {depth_scale:g} m; use a larger "
                         "depth_scale")  # fmt: skip
    if masks is not None:
        masks = instance_labels(masks, f"{what}: masks")
        if masks.shape != (h, w):
            raise InputError(f"{what}: masks are {masks.shape[1]}x{masks.shape[0]}, the colour image {w}x{h}")
        if masks.size and int(masks.max()) > 65535:  # before: wrapped into another fruit's id by astype(uint16)
            raise InputError(f"{what}: masks hold label {int(masks.max())}; a 16-bit masks.png holds 0-65535")
    folder.mkdir(parents=True, exist_ok=True)
    units = np.clip(np.rint(np.nan_to_num(depth) / depth_scale), 0, 65535).astype(np.uint16)
    for name, img in (("color.png", Image.fromarray(color)), ("depth.png", Image.fromarray(units))):
        with atomic_write(folder / name, "wb") as handle:
            img.save(handle, format="PNG", compress_level=1)  # zlib level 1: 3x faster to write, ~10 % larger
    write_json(folder / "camera.json", {**camera.to_dict(), "depth_scale": depth_scale})
    if truth is not None:
        write_json(folder / "truth.json", truth)
    if masks is not None:
        with atomic_write(folder / "masks.png", "wb") as handle:
            Image.fromarray(masks.astype(np.uint16 if masks.max() > 255 else np.uint8)).save(handle, format="PNG")
    return folder
