"""Camera intrinsics files in the common layouts.

=====================  ==================================================================
layout                 keys
=====================  ==================================================================
plain (symfruit)       ``fx, fy, cx, cy, width, height``
RealSense              ``fx, fy, ppx, ppy, width, height`` (``rs2_intrinsics``; may sit under
                       ``intrinsics``, ``color`` or ``colour``)
Open3D                 ``width, height, intrinsic_matrix`` (9 numbers, column-major), as written by
                       ``o3d.io.write_pinhole_camera_intrinsic``
ROS CameraInfo         ``K`` (ROS 1) or ``k`` (ROS 2), 9 numbers row-major, with ``width, height``;
                       also ``camera_matrix: {data: [...]}`` with ``image_width, image_height``
                       (``camera_calibration_parsers`` YAML)
=====================  ==================================================================

Distortion coefficients (RealSense ``coeffs``, ROS ``D``/``d``, ``distortion_coefficients``) are checked to be
finite numbers but never applied: symfruit's pipeline is pinhole. Non-zero ones raise a
:class:`~symfruit.errors.SymfruitWarning` naming the file and the largest coefficient (undistort the images, or
give the rectified camera's intrinsics, ROS ``P``); they are not ignored in silence. A principal point
(``cx, cy``) outside the image is warned about alike (:func:`warn_principal_point`): intrinsics of another
resolution, or swapped width and height, more often than a cropped image's.

JSON or YAML by extension (YAML through ``yaml.safe_load`` only). A file's keys are checked: a key that none of
these layouts has (nor ``depth_scale``/``depth_units``, read beside them by :func:`symfruit.io.read_frame`) is
refused naming the file, the key and the closest known key, so a misspelt ``depth_scal`` is not a default
depth scale in disguise. :func:`camera_from_dict` (a mapping handed to the API, ``symfruit.complete(camera=...)``)
checks them alike (``depth_scale``/``depth_units`` allowed at the top level), so a misspelt ``ppy`` is refused
by name, not read as a missing field or ignored.
"""

from __future__ import annotations

import difflib
import math
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..core.camera import Camera
from ..core.limits import MAX_DISTORTION_COEFFS, MAX_SETTINGS_BYTES, shown
from ..errors import FileFormatError, InputError, SymfruitWarning
from .text import as_path, read_structured

__all__ = [
    "camera_from_dict",
    "check_binning_roi",
    "check_pinhole_matrix",
    "load_camera",
    "warn_distortion",
    "warn_principal_point",
]

#: Largest intrinsics file read (bytes): that of a settings file (:mod:`symfruit.core.limits`).
MAX_INTRINSICS_BYTES = MAX_SETTINGS_BYTES

_NESTS = ("intrinsics", "intrinsic", "color", "colour", "camera", "camera_info")

#: Every key of the layouts above: symfruit's own, ``rs2_intrinsics``, Open3D, ROS 1 and 2 ``CameraInfo`` and
#: ``camera_calibration_parsers`` YAML.
LAYOUT_KEYS = frozenset(
    {"fx", "fy", "cx", "cy", "width", "height"}
    | {"ppx", "ppy", "model", "coeffs"}
    | {"intrinsic_matrix"}
    | {"header", "distortion_model", "D", "K", "R", "P", "d", "k", "r", "p", "binning_x", "binning_y", "roi"}
    | {"image_width", "image_height", "camera_name", "camera_matrix", "distortion_coefficients",
       "rectification_matrix", "projection_matrix"}
)  # fmt: skip
#: Keys a frame folder's camera file holds beside the intrinsics (:func:`symfruit.io.read_frame`).
DEPTH_KEYS = frozenset({"depth_scale", "depth_units"})
#: Keys beside a nested layout (``{"color": {...}, "depth": {...}}`` as RealSense tools write it).
_BESIDE_NESTS = frozenset({*_NESTS, "depth", "extrinsics"})
#: Keys that make a mapping a layout of its own (its nests, if any, are not followed).
_LAYOUT_MARKS = frozenset({"fx", "intrinsic_matrix", "K", "k", "camera_matrix"})


def _nest(data: dict) -> str | None:
    """The nest (:data:`_NESTS`) whose mapping holds the intrinsics of ``data``, the first there is, or None where
    ``data`` is a layout itself or has no nest."""
    if _LAYOUT_MARKS & set(data):
        return None
    nests = [key for key in _NESTS if isinstance(data.get(key), dict)]
    holding = [key for key in nests if _LAYOUT_MARKS & set(data[key]) or _nest(data[key]) is not None]
    if any(data[key] != data[holding[0]] for key in holding[1:]):  # taking the first would be a guess
        raise InputError(f"intrinsics are given twice, under {' and '.join(repr(k) for k in holding)}, and they "
                         "differ: which one is meant? Keep one")  # fmt: skip
    return nests[0] if nests else None


def load_camera(path: str | Path) -> Camera:
    """Read intrinsics from a ``.json``, ``.yaml`` or ``.yml`` file in any layout above."""
    path = as_path(path, "load_camera: the intrinsics file")
    return camera_from_file_data(path, read_mapping(path))


def camera_from_file_data(path: Path, data: Any) -> Camera:
    """:func:`camera_from_dict` with errors naming the file the data came from."""
    try:
        return _checked(data, str(path))
    except InputError as exc:
        raise FileFormatError(f"{path}: {exc}") from None


#: Most distortion coefficients read: :data:`symfruit.core.limits.MAX_DISTORTION_COEFFS`.
#: Distortion keys of the layouts: RealSense, ROS 1, ROS 2, camera_calibration_parsers.
_DISTORTION_KEYS = ("coeffs", "D", "d", "distortion_coefficients")


def _distortion(data: Any) -> tuple[str, list[float]] | None:
    """``(key, coefficients)`` of the intrinsics mapping's distortion (following the nests :func:`_camera_of`
    follows), or None; coefficients that are not finite numbers are refused naming the key."""
    if not isinstance(data, dict):
        return None
    if (nest := _nest(data)) is not None:
        return _distortion(data[nest])
    key = next((k for k in _DISTORTION_KEYS if k in data), None)
    if key is None:
        return None
    values = data[key]
    if isinstance(values, dict) and "data" in values:
        values = values["data"]
    if values is None:
        return None
    if (
        not isinstance(values, list)
        or len(values) > MAX_DISTORTION_COEFFS
        or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and _fits_float(v) for v in values)
        or not all(math.isfinite(float(v)) for v in values)
    ):
        raise InputError(f"intrinsics field {key!r} must hold at most {MAX_DISTORTION_COEFFS} finite numbers, got "
                         f"{shown(values)}")  # fmt: skip
    return key, [float(v) for v in values]


def _checked(data: Any, source: str) -> Camera:
    """:func:`camera_from_dict`, warning (:class:`SymfruitWarning`) about non-zero distortion it does not apply;
    ``source`` names where the intrinsics came from."""
    camera = _camera_with_keys_checked(data)
    distortion = _distortion(data)
    model = data.get("distortion_model") if isinstance(data, dict) else None
    if distortion is not None or model is not None:
        warn_distortion(source, *(distortion or ("D", [])), stacklevel=4, model=model)
    warn_principal_point(source, camera, stacklevel=4)
    return camera


def warn_principal_point(source: str, camera: Camera, *, stacklevel: int = 2) -> bool:
    """Warn (:class:`SymfruitWarning`) that the principal point of the camera ``source`` names lies outside its
    image (pixel centres at whole numbers: the image spans -0.5 to width - 0.5); whether it warned. Not refused:
    a cropped image's camera may have it there, but intrinsics of another resolution or with width and height
    swapped are likelier, and misplace every point. The one rule for intrinsics files, bags' and live
    ``CameraInfo`` messages and RealSense recordings' colour camera, as :func:`warn_distortion` is."""
    if -0.5 <= camera.cx <= camera.width - 0.5 and -0.5 <= camera.cy <= camera.height - 0.5:
        return False
    warnings.warn(
        SymfruitWarning(
            f"{source}: the principal point (cx {camera.cx:g}, cy {camera.cy:g}) lies outside the "
            f"{camera.width}x{camera.height} image: are these the intrinsics of this resolution (width and height "
            "not swapped)? They are used as given"
        ),
        stacklevel=stacklevel,
    )
    return True


#: Lens models (a ``CameraInfo``'s or an intrinsics file's ``distortion_model``) that are no pinhole one even with
#: every coefficient 0: a fisheye image's radius grows with the angle (equidistant: r = f * theta), a pinhole's with
#: its tangent (ROS image_pipeline's ``equidistant``; OpenCV's ``fisheye`` is the same Kannala-Brandt model).
FISHEYE_MODELS = frozenset({"equidistant", "fisheye", "kannala_brandt", "kb4"})


def warn_distortion(source: str, key: str, values: Sequence[float], *, stacklevel: int = 2, model: Any = None) -> bool:
    """Warn (:class:`SymfruitWarning`) that the distortion coefficients ``values`` (field ``key``) of the camera
    ``source`` names are not applied, when one is non-zero, or that its lens ``model`` is a fisheye one
    (:data:`FISHEYE_MODELS`, coefficients all 0 too: stop 48, robust48); whether it warned. The one rule for
    intrinsics files, bags' and live ``CameraInfo`` messages and RealSense recordings' colour lens."""
    if isinstance(model, str) and model.lower() in FISHEYE_MODELS:
        warnings.warn(
            SymfruitWarning(
                f"{source}: distortion model {model!r} is a fisheye lens, not applied: symfruit treats the image as "
                "pinhole; rectify it first (image_proc), else points away from the centre are misplaced"
            ),
            stacklevel=stacklevel,
        )
        return True
    if not any(values):
        return False
    largest = max(values, key=abs)
    warnings.warn(
        SymfruitWarning(
            f"{source}: non-zero distortion coefficients {key!r} (largest {largest:.4g}) are not applied: "
            "symfruit treats the image as pinhole; undistort it first (or use the rectified camera's "
            "intrinsics, ROS P), else points far from the centre are misplaced"
        ),
        stacklevel=stacklevel,
    )
    return True


def _unknown_key(data: Any, where: str) -> tuple[str, str, str | None] | None:
    """The first key of the intrinsics mapping ``data`` (following the nests :func:`camera_from_dict`
    follows) that no layout has: ``(key, where, closest known key or None)``, or None."""
    if not isinstance(data, dict):
        return None
    nest = _nest(data)
    known = (_BESIDE_NESTS if nest is not None else LAYOUT_KEYS) | (DEPTH_KEYS if not where else frozenset())
    for key in data:
        if not isinstance(key, str) or key not in known:
            name = str(key)
            close = difflib.get_close_matches(name, sorted(known | DEPTH_KEYS), n=1, cutoff=0.6)
            return name, where, close[0] if close else None
    if nest is not None:
        return _unknown_key(data[nest], f"{where}{nest}.")
    return None


def _unknown_message(key: str, where: str, close: str | None) -> str:
    if where and key in DEPTH_KEYS:
        return f"{key!r} under {where[:-1]!r} is not read: write it at the top level of the file"
    from ..settings import known_names  # the near ones and a count: every key was a line of 400+ characters (robust48)

    where_listed = "README's table of inputs, row 'intrinsics', lists the layouts"
    listed = known_names(key, sorted(LAYOUT_KEYS | DEPTH_KEYS), where=where_listed)
    hint = f"; did you mean {close!r}?" if close else f"; {listed.replace('known:', 'known keys:', 1)}"
    return f"unknown key {where + key!r} (not a key of any intrinsics layout symfruit reads){hint}"


def read_mapping(path: Path) -> Any:
    """Parse an intrinsics file (JSON, or YAML through the safe loader); errors name the file."""
    suffix = path.suffix.lower()
    if suffix not in (".json", ".yaml", ".yml"):
        raise FileFormatError(f"{path}: intrinsics must be .json, .yaml or .yml, not {suffix!r}")
    return read_structured(path, what="intrinsics file", max_bytes=MAX_INTRINSICS_BYTES)


def _number(data: dict[str, Any], key: str) -> float:
    value = data[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not _fits_float(value):
        raise InputError(f"intrinsics field {key!r} must be a number, got {shown(value)}")
    return float(value)


def _fits_float(value: int | float) -> bool:
    """Whether a number read from a file converts to float (JSON and YAML read a 400-digit whole number as an
    int, which float() refuses with OverflowError)."""
    try:
        float(value)
    except OverflowError:
        return False
    return True


def _matrix(values: Any, name: str) -> list[float]:
    if isinstance(values, dict) and "data" in values:
        values = values["data"]
    if (
        not isinstance(values, list)
        or len(values) != 9
        or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and _fits_float(v) for v in values)
    ):
        raise InputError(f"intrinsics field {name!r} must hold 9 numbers")
    return [float(v) for v in values]


def check_pinhole_matrix(m: Sequence[float], name: str, *, column_major: bool = False) -> None:
    """Refuse 9 numbers that are not a pinhole intrinsic matrix ``[[fx, s, cx], [0, fy, cy], [0, 0, 1]]`` in
    their order (ROS ``K``: row-major; Open3D ``intrinsic_matrix``: column-major): a matrix given in the other
    order puts the principal point in the bottom row and reads ``cx = cy = 0`` in silence, and one scaled by a
    last entry other than 1 halves or doubles the focal lengths.

    Raises
    ------
    InputError
        Naming the field and what is wrong.
    """
    below = (m[1], m[2], m[5]) if column_major else (m[3], m[6], m[7])  # the three entries below the diagonal
    if any(below) or m[-1] != 1.0:
        order = "column-major, as Open3D writes it" if column_major else "row-major, as ROS writes it"
        given = ", ".join(f"{float(v):g}" for v in m)
        raise InputError(f"{name} [{given}] is not a pinhole intrinsic matrix [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] "
                         f"{order}: its entries below the diagonal must be 0 and the last 1 (given in the other "
                         "order?)")  # fmt: skip


def _one(data: dict[str, Any], keys: Sequence[str], what: str) -> None:
    """Refuse a mapping that gives ``what`` twice, under two of ``keys``: which one is meant?"""
    given = [k for k in keys if k in data]
    if len(given) > 1:
        raise InputError(f"intrinsics give {what} twice, as {' and '.join(repr(k) for k in given)}: which one is "
                         "meant? Keep one")  # fmt: skip


def _size(data: dict[str, Any]) -> tuple[Any, Any]:
    _one(data, ("width", "image_width"), "the width")
    _one(data, ("height", "image_height"), "the height")
    width = data.get("width", data.get("image_width"))
    height = data.get("height", data.get("image_height"))
    if width is None or height is None:
        raise InputError("intrinsics lack the image size (width and height)")
    return width, height


def camera_from_dict(data: Any) -> Camera:
    """Build a :class:`Camera` from a parsed intrinsics mapping in any supported layout.

    Raises
    ------
    InputError
        Naming the missing or invalid field, or a key no layout has (with the closest known key).

    Warns
    -----
    SymfruitWarning
        When the mapping holds non-zero distortion coefficients, which are not applied.
    """
    return _checked(data, "intrinsics")


def _camera_with_keys_checked(data: Any) -> Camera:
    """:func:`camera_from_dict` without the distortion warning."""
    try:
        camera = _camera_of(data)
    except InputError:
        unknown = _unknown_key(data, "")
        if unknown is not None and unknown[2] is not None:  # a misspelt key explains the failure better
            raise InputError(_unknown_message(*unknown)) from None
        raise
    unknown = _unknown_key(data, "")
    if unknown is not None:
        raise InputError(_unknown_message(*unknown))
    return camera


def _camera_of(data: Any) -> Camera:
    """:func:`camera_from_dict` without the check of the keys."""
    if not isinstance(data, dict):
        raise InputError(f"intrinsics must be a mapping, got {type(data).__name__}")
    if (nest := _nest(data)) is not None:
        return _camera_of(data[nest])
    _one(data, ("intrinsic_matrix", "K", "k", "camera_matrix", "fx"), "the focal lengths")
    matrix: tuple[list[float], str, bool] | None = None
    if "intrinsic_matrix" in data:  # Open3D, column-major
        m = _matrix(data["intrinsic_matrix"], "intrinsic_matrix")
        fx, fy, cx, cy = m[0], m[4], m[6], m[7]
        matrix = (m, "intrinsics field 'intrinsic_matrix'", True)
    elif any(k in data for k in ("K", "k", "camera_matrix")):  # ROS, row-major
        key = next(k for k in ("K", "k", "camera_matrix") if k in data)
        m = _matrix(data[key], key)
        fx, fy, cx, cy = m[0], m[4], m[2], m[5]
        matrix = (m, f"intrinsics field {key!r}", False)
    elif "fx" in data:
        _one(data, ("cx", "ppx"), "the principal point's x")
        _one(data, ("cy", "ppy"), "the principal point's y")
        if "fy" not in data:
            raise InputError("intrinsics lack field 'fy'")
        for key, alias in (("cx", "ppx"), ("cy", "ppy")):
            if key not in data and alias not in data:
                raise InputError(f"intrinsics lack field {key!r} (or {alias!r})")
        cx_key = "cx" if "cx" in data else "ppx"
        cy_key = "cy" if "cy" in data else "ppy"
        fx, fy, cx, cy = (_number(data, k) for k in ("fx", "fy", cx_key, cy_key))
    else:
        raise InputError(
            "intrinsics layout not recognised: expected fx/fy/cx/cy, RealSense ppx/ppy, "
            "Open3D intrinsic_matrix or ROS K/k, each with width and height"
        )
    width, height = _size(data)
    camera = Camera(fx=fx, fy=fy, cx=cx, cy=cy, width=width, height=height)
    if matrix is not None:  # after the camera's own checks: an all-zero matrix is 'focal lengths must be positive'
        check_pinhole_matrix(matrix[0], matrix[1], column_major=matrix[2])
    check_binning_roi(data.get("binning_x"), data.get("binning_y"), data.get("roi"), camera, "intrinsics")
    return camera


def _uint32(value: Any) -> bool:
    """Whether ``value`` is a whole number a ``uint32`` field holds (never ``range``'s linear search of a float)."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        return False
    return bool(math.isfinite(value) and float(value).is_integer() and 0 <= value < 2**32)


def check_binning_roi(binning_x: Any, binning_y: Any, roi: Any, camera: Camera, what: str) -> None:
    """Refuse a ``CameraInfo``'s binning (above 1) or region of interest (an offset, or a size not the image's):
    ``K`` is then the full sensor's, not the stored images', and taking it as theirs would misplace every point
    (these were ignored in silence). ``roi`` is a mapping (a file) or a message's ``RegionOfInterest``; 0 or absent
    binning and an all-zero ``roi`` are "none", as ROS defines them.

    Raises
    ------
    InputError
        Naming ``what``, the field and what to give instead (the intrinsics of the images as stored).
    """
    for name, value in (("binning_x", binning_x), ("binning_y", binning_y)):
        if value is None:
            continue
        if not _uint32(value):
            raise InputError(f"{what} field {name!r} must be a whole number, got {shown(value)}")
        if value > 1:
            raise InputError(f"{what} field {name!r} is {int(value)}: binned images are not read (K is the full "
                             "sensor's); give the intrinsics of the images as stored (fx, cx divided by the "
                             "binning) and no binning")  # fmt: skip
    if roi is None:
        return
    fields = ("x_offset", "y_offset", "width", "height")
    get = roi.get if isinstance(roi, dict) else (lambda key, default=0: getattr(roi, key, default))
    if not isinstance(roi, dict) and not all(hasattr(roi, f) for f in fields):
        raise InputError(f"{what} field 'roi' must be a mapping of {', '.join(fields)}, got {shown(roi)}")
    values = [get(f, 0) for f in fields]
    if not all(_uint32(v) for v in values):
        raise InputError(f"{what} field 'roi' must hold whole numbers {', '.join(fields)}, got "
                         f"{', '.join(shown(v) for v in values)}")  # fmt: skip
    x0, y0, w, h = (int(v) for v in values)
    if x0 or y0 or ((w or h) and (w, h) != (camera.width, camera.height)):
        raise InputError(f"{what} field 'roi' is x_offset {x0}, y_offset {y0}, {w}x{h}: a region of interest is not "
                         f"applied (K is the full sensor's); give the intrinsics of the images as stored (cx - "
                         "x_offset, cy - y_offset, their size) and no roi")  # fmt: skip
