"""Reading images: one place that opens every file Pillow can open, bounds its size before decoding it,
and normalises its mode to what the pipeline needs (or refuses it by name).

=============  ==============================================================================
use            accepted modes -> result
=============  ==============================================================================
colour         ``RGB`` as is; ``RGBA``/``RGBX``/``RGBa``, ``P``/``PA`` (palette), ``L``/``LA``/``La``,
               ``1``, ``CMYK``, ``YCbCr``, ``LAB``, ``HSV`` converted to RGB; 16-bit grey
               (``I;16*``) and 32-bit ``I`` scaled to 8 bits -> ``(h, w, 3) uint8``
depth          single channel ``I;16*``, ``I`` (0-65535) or ``L`` -> ``(h, w) uint16`` units
labels         ``1``, ``L``, ``P`` (palette indices are the labels), ``I;16*``, ``I`` -> ``(h, w)
               int32``; ``RGB``/``RGBA`` -> one label per distinct colour, black = background
=============  ==============================================================================

Every error names the file and the problem (:class:`~symfruit.errors.FileFormatError`); Pillow's own
errors, including its decompression-bomb error, never escape.
"""

from __future__ import annotations

import io
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from ..core.camera import MAX_IMAGE_PIXELS  # checked from the header, before any pixel is decoded
from ..errors import FileFormatError

__all__ = ["MAX_IMAGE_PIXELS", "decode_color", "read_color", "read_depth_units", "read_labels"]


_COLOUR_MODES = {"RGB", "RGBA", "RGBX", "RGBa", "P", "PA", "L", "LA", "La", "1", "CMYK", "YCbCr", "LAB", "HSV"}
_WIDE_GREY = {"I;16", "I;16B", "I;16L", "I;16N", "I"}


def _open(source: Path | bytes, label: str) -> Any:
    """The opened (not yet decoded) Pillow image, size-checked; ``label`` names it in errors."""
    from PIL import Image, UnidentifiedImageError

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            img = Image.open(io.BytesIO(source) if isinstance(source, bytes) else source)
    except FileNotFoundError:
        raise FileFormatError(f"{label}: no such image") from None
    except (Image.DecompressionBombError, Image.DecompressionBombWarning) as exc:
        raise FileFormatError(f"{label}: image too large ({exc})") from None
    except (UnidentifiedImageError, OSError, SyntaxError, ValueError) as exc:
        raise FileFormatError(f"{label}: cannot read image ({exc})") from None
    w, h = img.size
    if w <= 0 or h <= 0 or w * h > MAX_IMAGE_PIXELS:
        img.close()
        raise FileFormatError(f"{label}: image is {w}x{h} pixels; at most {MAX_IMAGE_PIXELS:,} pixels are read")
    return img


def _decode(img: Any, label: str) -> Any:
    from PIL import Image

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            img.load()
    except (OSError, SyntaxError, ValueError, Image.DecompressionBombWarning, Image.DecompressionBombError) as exc:
        raise FileFormatError(f"{label}: cannot decode image ({exc})") from None
    return img


def _to_rgb(img: Any, label: str) -> np.ndarray:
    mode = img.mode
    if mode == "RGB":
        return np.asarray(img, dtype=np.uint8)
    if mode in _COLOUR_MODES:
        return np.asarray(img.convert("RGB"), dtype=np.uint8)
    if mode in _WIDE_GREY:
        grey = np.asarray(img).astype(np.int64)
        if grey.size and (grey.min() < 0 or grey.max() > 65535):
            raise FileFormatError(f"{label}: 32-bit grey values outside 0-65535 cannot be a colour image")
        grey8 = (grey >> 8 if mode != "I" or (grey.size and grey.max() > 255) else grey).astype(np.uint8)
        return np.repeat(grey8[:, :, None], 3, axis=2)
    raise FileFormatError(f"{label}: image mode {mode!r} cannot be read as colour (use 8-bit RGB)")


def read_color(path: str | Path) -> np.ndarray:
    """A colour image as ``(h, w, 3) uint8`` RGB, from any mode listed in the module docstring."""
    path = Path(path)
    with _open(path, str(path)) as img:
        return np.ascontiguousarray(_to_rgb(_decode(img, str(path)), str(path)))


def decode_color(data: bytes, label: str) -> np.ndarray:
    """:func:`read_color` for encoded bytes (a ``CompressedImage``'s JPEG or PNG)."""
    with _open(bytes(data), label) as img:
        return np.ascontiguousarray(_to_rgb(_decode(img, label), label))


def read_depth_units(path: str | Path) -> np.ndarray:
    """A single-channel depth image as ``(h, w) uint16`` raw units (``depth_scale`` metres each)."""
    path = Path(path)
    with _open(path, str(path)) as img:
        img = _decode(img, str(path))
        if img.mode not in _WIDE_GREY and img.mode != "L":
            raise FileFormatError(f"{path}: depth PNG must be single-channel 16-bit, got mode {img.mode!r}")
        raw = np.asarray(img)
    if raw.ndim != 2:
        raise FileFormatError(f"{path}: depth PNG must be single-channel, got shape {raw.shape}")
    if raw.dtype.kind not in "ui":
        raise FileFormatError(f"{path}: depth PNG must hold integer units, got {raw.dtype}")
    if raw.size and (raw.min() < 0 or raw.max() > 65535):
        raise FileFormatError(f"{path}: depth units outside 0-65535")
    return raw.astype(np.uint16)


def read_labels(path: str | Path) -> np.ndarray:
    """An instance label image as ``(h, w) int32`` (0 background); RGB label images get one label per colour."""
    path = Path(path)
    with _open(path, str(path)) as img:
        img = _decode(img, str(path))
        mode = img.mode
        if mode in ("RGB", "RGBA", "RGBX"):
            rgb = np.asarray(img)[:, :, :3].astype(np.int64)
            keys = rgb[:, :, 0] << 16 | rgb[:, :, 1] << 8 | rgb[:, :, 2]
            _, inverse = np.unique(keys.ravel(), return_inverse=True)
            labels = inverse.reshape(keys.shape).astype(np.int32)  # black (key 0) sorts first: label 0
            return labels if keys.min() == 0 else labels + 1
        if mode in ("1", "L", "P") or mode in _WIDE_GREY:
            labels = np.asarray(img).astype(np.int64)
        else:
            raise FileFormatError(f"{path}: label image mode {mode!r} is not an instance label image (use a "
                                  "single-channel 8- or 16-bit PNG, or RGB with one colour per fruit)")  # fmt: skip
    if labels.size and labels.min() < 0:
        raise FileFormatError(f"{path}: negative labels")
    return labels.astype(np.int32)
