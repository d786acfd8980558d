"""Every documented bound, in one place, and the checks every entry point (each command, each reader, the
Python API) applies with them.

The numbers here are the ones README's limits table states (a test parses that table and compares).
A size read from a file or handed to the API is checked against them *before* anything of that size is
allocated; a value beyond a bound is refused by name, never truncated or wrapped.

Numpy only: the checks take sizes and arrays, and raise :class:`~symfruit.errors.InputError` (or the error
class the caller names, e.g. :class:`~symfruit.errors.FileFormatError` for a file).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError, SymfruitError

__all__ = [
    "MAX_BAG_CHUNK_BYTES",
    "MAX_BAG_METADATA_BYTES",
    "MAX_CLOUD_POINTS",
    "MAX_COCO_BYTES",
    "MAX_DEPTH_METRES",
    "MAX_DISTORTION_COEFFS",
    "MAX_FACES",
    "MAX_FOCAL_PX",
    "MAX_IMAGE_PIXELS",
    "MAX_IMAGE_SIDE",
    "MAX_INSTANCES",
    "MAX_LABEL_ID",
    "MAX_OBJ_BYTES",
    "MAX_PIECES",
    "MAX_SETTINGS_BYTES",
    "MAX_TABLE_BYTES",
    "MAX_TABLE_ROWS",
    "MAX_TEXT_CLOUD_BYTES",
    "MAX_TRUTH_BYTES",
    "MAX_WINDOW_PIXELS",
    "MIN_DEPTH_METRES",
    "check_image_size",
    "depth_metres",
    "instance_labels",
    "shown",
    "typical_depth",
    "unmasked",
]

#: Largest image side (pixels) and largest image (pixels), for every image (colour, depth, labels, a bag or
#: ROS message, a COCO entry) and the camera: an 8K x 5K sensor fits; a depth camera gives about 1 MP.
MAX_IMAGE_SIDE = 16384
MAX_IMAGE_PIXELS = 40_000_000
#: Largest focal length and principal-point offset (pixels): a 16K sensor behind a 60x telephoto fits.
MAX_FOCAL_PX = 1e6
#: Most lens distortion coefficients read with a camera's intrinsics (OpenCV's largest model has 14; ROS
#: ``rational_polynomial`` 8).
MAX_DISTORTION_COEFFS = 16
#: One fruit's window in the image (the rating's raster), pixels.
MAX_WINDOW_PIXELS = 4_000_000
#: Largest cloud read from a file (points), and largest text cloud (bytes).
MAX_CLOUD_POINTS = 5_000_000
MAX_TEXT_CLOUD_BYTES = 256 << 20
#: Largest mesh (faces) and OBJ file (bytes) of the evaluation's scans.
MAX_FACES = 10_000_000
MAX_OBJ_BYTES = 64 << 20
#: Largest settings / profile / intrinsics file, truth file and COCO file (bytes).
MAX_SETTINGS_BYTES = 1 << 20
MAX_TRUTH_BYTES = 16 << 20
MAX_COCO_BYTES = 256 << 20
#: Largest ``metadata.yaml`` of a ROS 2 bag folder (bytes), checked before rosbags reads it whole: a few kB per
#: topic and split file; as large as a truth file may be.
MAX_BAG_METADATA_BYTES = MAX_TRUTH_BYTES
#: Largest chunk of a ROS 2 bag's MCAP file, uncompressed (bytes), checked (with every record's length against
#: the bytes left in the file) before rosbags reads the file: rosbag2 writes chunks of 768 kB (the MCAP writer's
#: default ``chunk_size``, 786432) and a message larger than that alone in its chunk; the largest image message
#: read (40 megapixels of 32-bit depth) is 160 MB.
MAX_BAG_CHUNK_BYTES = 1024 << 20
#: Most fruit (instances) one image's masks may hold, and the largest label id (32-bit signed).
MAX_INSTANCES = 1000
MAX_LABEL_ID = 2**31 - 1
#: Most candidate pieces (red regions and their parts) the colour segmenter joins into fruit in one image: as
#: many as fruit. Joining tests nearby pairs, so the cost grows with their square: a frame of colour noise gives
#: ~1,600 pieces (minutes); real frames give at most a few hundred (an apple tree at 1920x1080: 225).
MAX_PIECES = MAX_INSTANCES
#: A run's fruit table read by ``symfruit report``: most rows (a season of ~3 million frames of 6 fruit) and
#: most bytes of the columns read (uncompressed, as the file's metadata states; checked before reading).
MAX_TABLE_ROWS = 20_000_000
MAX_TABLE_BYTES = 4096 << 20
#: Depth handed over as metres whose typical value is beyond this is refused as "raw units, not metres"
#: (millimetres from a 16-bit depth image are hundreds to thousands).
MAX_DEPTH_METRES = 100.0
#: Points nearer the camera than this (metres) are refused: no depth camera measures them, and one at 1e-300 m
#: projects beyond any float (a method's numpy error, or a fruit sized by one stray point).
MIN_DEPTH_METRES = 0.001


def shown(value: Any, limit: int = 40) -> str:
    """A bad value as an error message shows it: its ``repr``, or, beyond ``limit`` characters, its start and
    how long it is (a 400-digit width read from a file is not printed whole: ``99999999999... (400 digits)``).

    Examples
    --------
    >>> shown(640), shown(10**400 - 1), shown("x" * 50)
    ('640', '999999999999... (400 digits)', "'xxxxxxxxxxxxxxxxxxx... (52 characters)")
    """
    if isinstance(value, np.generic):
        value = value.item()
    try:
        text = repr(value)
    except ValueError:  # a whole number beyond Python's 4300-digit conversion limit
        return f"a whole number of about {int(abs(value).bit_length() * 0.30103) + 1} digits"
    if len(text) <= limit:
        return text
    if isinstance(value, int) and not isinstance(value, bool):
        return f"{text[:12]}... ({len(text.lstrip('-'))} digits)"
    return f"{text[:20]}... ({len(text)} characters)"


def check_image_size(
    width: Any,
    height: Any,
    what: str,
    *,
    error: type[SymfruitError] = InputError,
    max_pixels: int | None = None,
    max_side: int | None = None,
) -> tuple[int, int]:
    """``(width, height)`` as ints, or ``error`` naming ``what`` when a side is not 1-:data:`MAX_IMAGE_SIDE`
    pixels or the image holds more than :data:`MAX_IMAGE_PIXELS` (``max_pixels``, ``max_side``: tighter
    bounds a caller keeps)."""
    max_pixels = MAX_IMAGE_PIXELS if max_pixels is None else max_pixels
    max_side = MAX_IMAGE_SIDE if max_side is None else max_side
    try:
        w, h = int(width), int(height)
    except (TypeError, ValueError, OverflowError):
        raise error(f"{what}: image size {shown(width)}x{shown(height)} is not whole numbers of pixels") from None
    size = f"{shown(w)}x{shown(h)}"
    if w <= 0 or h <= 0:
        raise error(f"{what}: image is {size} pixels; it must not be empty")
    if w > max_side or h > max_side:
        raise error(f"{what}: image is {size} pixels; at most {max_side} pixels a side are read")
    if w * h > max_pixels:
        raise error(f"{what}: image is {size} pixels; at most {max_pixels:,} pixels are read")
    return w, h


def unmasked(values: Any, fill: Any) -> np.ndarray:
    """``values`` as an array, the masked entries of a :class:`numpy.ma.MaskedArray` set to ``fill`` (no
    measurement: no depth, background, a point to drop); ``np.asarray`` alone would hand over the values the mask
    hides, as if measured. Anything else is ``np.asarray(values)``.

    Examples
    --------
    >>> unmasked(np.ma.masked_array([1.0, 2.0], mask=[False, True]), 0.0).tolist()
    [1.0, 0.0]
    """
    if isinstance(values, np.ma.MaskedArray):
        if np.ma.getmask(values) is np.ma.nomask:
            return np.asarray(values.data)
        if values.dtype.kind in "iub" and isinstance(fill, float) and not fill.is_integer():
            values = values.astype(np.float64)  # NaN for an integer array's masked entries
        return np.asarray(values.filled(fill))
    return np.asarray(values)


def instance_labels(labels: Any, what: str, *, error: type[SymfruitError] = InputError) -> np.ndarray:
    """Instance labels as ``(h, w) int32`` (0 background), checked: a 2-D image of whole numbers in
    0-:data:`MAX_LABEL_ID` holding at most :data:`MAX_INSTANCES` fruit, within the image bounds.

    Ids beyond 32 bits are refused, never truncated (truncation would merge two fruit or drop one); bool
    masks are one fruit; a masked pixel of a :class:`numpy.ma.MaskedArray` is background.

    Raises
    ------
    error
        Naming ``what`` and the problem.
    """
    arr = unmasked(labels, 0)  # a masked pixel (numpy.ma) is background, not its hidden label
    if arr.ndim != 2:
        raise error(f"{what}: instance labels must be an (h, w) image, got shape {arr.shape}")
    check_image_size(arr.shape[1], arr.shape[0], what, error=error)
    if arr.dtype == bool:
        return arr.astype(np.int32)
    if not np.issubdtype(arr.dtype, np.integer):
        raise error(f"{what}: instance labels must be whole numbers, got {arr.dtype}")
    if arr.size == 0:
        return arr.astype(np.int32)
    lo, hi = int(arr.min()), int(arr.max())
    if lo < 0:
        raise error(f"{what}: masks hold negative labels (got {shown(lo)}); 0 is background, 1..k the fruit")
    if hi > MAX_LABEL_ID:
        raise error(f"{what}: label id {shown(hi)} is beyond 32 bits (at most {MAX_LABEL_ID}); number the fruit 1..k")
    if hi > MAX_INSTANCES:  # more ids than fruit allowed may still be few fruit: count them
        if hi <= 1 << 22:
            count = int(np.count_nonzero(np.bincount(arr.ravel(), minlength=hi + 1)[1:]))
        else:
            values = np.unique(arr)
            count = len(values) - int(values[0] == 0)
        if count > MAX_INSTANCES:
            raise error(f"{what}: masks hold {count} instances; at most {MAX_INSTANCES} fruit per image are read")
    return arr.astype(np.int32, copy=False)


def depth_metres(depth: Any, what: str, *, error: type[SymfruitError] = InputError) -> np.ndarray:
    """A depth image handed over as metres, checked: ``(h, w)`` floating point within the image bounds, and
    not raw sensor units (integer images, or typical values beyond :data:`MAX_DEPTH_METRES`, are millimetres
    or another unit: multiply by the depth scale first). 0 or NaN is "no depth", as is a masked pixel of a
    :class:`numpy.ma.MaskedArray`.

    Raises
    ------
    error
        Naming ``what`` and the problem.
    """
    arr = unmasked(depth, 0)  # a masked pixel (numpy.ma) is no depth, not the value hidden under the mask
    if arr.ndim != 2:
        raise error(f"{what}: depth must be a 2-D image, got shape {arr.shape}")
    check_image_size(arr.shape[1], arr.shape[0], what, error=error)
    if not np.issubdtype(arr.dtype, np.floating):
        raise error(f"{what}: depth is {arr.dtype}; depth must be float metres (raw units such as 16-bit "
                    "millimetres: multiply by the depth scale, e.g. 0.001, first)")  # fmt: skip
    typical = typical_depth(arr)
    if typical is not None and typical > MAX_DEPTH_METRES:
        raise error(f"{what}: depth is {typical:g} m typically; depth must be metres (these look like millimetres "
                    "or raw units: multiply by the depth scale first)")  # fmt: skip
    return arr


def typical_depth(depth: np.ndarray) -> float | None:
    """The median of a spread sample of a 2-D depth image's valid (finite, positive) pixels, or None where the
    sample holds none: it tells units apart (metres against millimetres is a factor of 1000). Rows and columns
    are strided alike, so a 640x480 frame costs 4,800 pixels and a 1920x1080 one 8,100. The median is
    :func:`symfruit.core.points.median`'s (``np.median``'s value bit for bit, without its general-axis machinery:
    about 10 of the 20-35 us of a depth image's check; stop 53, seg53)."""
    from .points import median  # points imports this module

    stride = max(1, int(np.sqrt(depth.size / 8_000)))
    sample = depth[::stride, ::stride].ravel()
    with np.errstate(invalid="ignore"):
        valid = sample[np.isfinite(sample) & (sample > 0)]
    return float(median(valid)) if len(valid) else None
