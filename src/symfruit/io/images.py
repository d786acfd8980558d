"""Reading images: one place that opens every file Pillow can open, bounds its size before decoding it,
and normalises its mode to what the pipeline needs (or refuses it by name).

=============  ==============================================================================
use            accepted modes -> result
=============  ==============================================================================
colour         ``RGB`` as is; ``RGBA``/``RGBX``/``RGBa``, ``P``/``PA`` (palette), ``L``/``LA``/``La``,
               ``1``, ``CMYK``, ``YCbCr``, ``LAB``, ``HSV`` converted to RGB; 16-bit grey
               (``I;16*``) and 32-bit ``I`` scaled to 8 bits -> ``(h, w, 3) uint8``
depth          single channel ``I;16*``, ``I`` (0-65535) or ``L`` -> ``(h, w) uint16`` units (``L`` only
               where 255 units reach 1 m: :data:`MIN_8BIT_DEPTH_REACH`)
labels         ``1``, ``L``, ``P`` (palette indices are the labels), ``I;16*``, ``I`` -> ``(h, w)
               int32``; ``RGB``/``RGBA`` -> one label per distinct colour, black (and an RGBA pixel of alpha 0) =
               background
=============  ==============================================================================

Images are read as displayed: an EXIF orientation (phone photos: 6 and 8 turn them a quarter) is applied
to every image read, colour, depth and labels alike (:func:`exif_orientation`). Where colour and depth (or
a label image) carry different orientations (:func:`orientation_mismatch`), or a colour image is turned a quarter beside
intrinsics for its stored size (:func:`turned_mismatch`), readers refuse them naming the file and its
orientation, never pair turned colour with unturned depth (:func:`decode_color`, a message's image beside
raw depth, refuses a tag).

A depth or label image file that holds several images (an animated PNG or GIF, a multi-page TIFF) is refused: its
first is not necessarily the one meant.

Every error names the file and the problem (:class:`~symfruit.errors.FileFormatError`); Pillow's own
errors, including its decompression-bomb error, never escape.
"""

from __future__ import annotations

import contextlib
import io
import re
import warnings
import zlib
from pathlib import Path
from typing import Any

import numpy as np

from ..core.limits import MAX_IMAGE_PIXELS, check_image_size, instance_labels  # checked before decoding
from ..errors import FileFormatError
from .text import as_path, refuse_pipe, unchanged_while

__all__ = [
    "MAX_IMAGE_PIXELS",
    "NO_DEPTH_BEYOND",
    "decode_color",
    "exif_orientation",
    "float_depth",
    "image_suffixes",
    "orientation_mismatch",
    "read_color",
    "read_color_oriented",
    "read_depth_units",
    "read_depth_units_oriented",
    "read_labels",
    "read_labels_oriented",
    "turned_mismatch",
]

#: Suffixes Pillow opens that symfruit reads as something else (``.pcd``: a point cloud, not a Kodak PhotoCD).
_NOT_IMAGES = {".pcd"}


def image_suffixes() -> frozenset[str]:
    """The file suffixes (lower case, with the dot) of every format :func:`read_color` opens: a folder
    listing takes exactly these, so a folder yields every image that would be read if named on its own."""
    from PIL import Image

    Image.init()
    return frozenset(e.lower() for e, fmt in Image.registered_extensions().items() if fmt in Image.OPEN) - _NOT_IMAGES


_COLOUR_MODES = {"RGB", "RGBA", "RGBX", "RGBa", "P", "PA", "L", "LA", "La", "1", "CMYK", "YCbCr", "LAB", "HSV"}
_WIDE_GREY = {"I;16", "I;16B", "I;16L", "I;16N", "I"}


def _open(source: Path | bytes, label: str) -> Any:
    """The opened (not yet decoded) Pillow image, size-checked; ``label`` names it in errors."""
    from PIL import Image, UnidentifiedImageError

    if not isinstance(source, bytes):
        refuse_pipe(source, "image", devices=True)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            img = Image.open(io.BytesIO(source) if isinstance(source, bytes) else source)
    except FileNotFoundError:
        raise FileFormatError(f"{label}: no such image") from None
    except (Image.DecompressionBombError, Image.DecompressionBombWarning) as exc:
        # Pillow's own, looser bound tripped first (its message names its bound, not ours): say ours
        claimed = re.search(r"\((\d+) pixels\)", str(exc))
        size = f"image of {int(claimed.group(1)):,} pixels" if claimed else "image too large"
        raise FileFormatError(f"{label}: {size}; at most {MAX_IMAGE_PIXELS:,} pixels are read") from None
    except UnidentifiedImageError:
        raise FileFormatError(f"{label}: cannot read image ({_unidentified(source)})") from None
    except (OSError, SyntaxError, ValueError) as exc:  # an OSError's reason alone, not "[Errno 13] ...: 'PATH'"
        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else _in_our_words(exc)
        raise FileFormatError(f"{label}: cannot read image ({why})") from None
    try:
        check_image_size(
            *img.size, label, error=FileFormatError, max_pixels=MAX_IMAGE_PIXELS
        )  # sides and pixels, from the header
    except FileFormatError:
        img.close()
        raise
    return img


def _in_our_words(exc: BaseException) -> str:
    """Pillow's reason, where it names its own internals, said as what is wrong with the file (stop 55, robust55:
    ``Decompressed data too large for PngImagePlugin.MAX_TEXT_CHUNK``, ``Too much memory used in text chunks:
    67500000>MAX_TEXT_MEMORY``, ``Truncated File Read``); any other reason as Pillow gives it."""
    from PIL import PngImagePlugin

    text = str(exc)
    if "MAX_TEXT_CHUNK" in text:
        return (f"a PNG text or colour-profile chunk decompresses to over {PngImagePlugin.MAX_TEXT_CHUNK >> 20} MB, "
                "more than is read: save the image without that metadata")  # fmt: skip
    if "MAX_TEXT_MEMORY" in text:
        return (f"its PNG text chunks hold over {PngImagePlugin.MAX_TEXT_MEMORY >> 20} MB, more than is read: save "
                "the image without that metadata")  # fmt: skip
    if text == "Truncated File Read":
        return "the file ends before the data it announces: it is cut short or damaged"
    return text


def _unidentified(source: Path | bytes) -> str:
    """Why Pillow did not know an image, in our words (its own, ``cannot identify image file 'PATH'``, says the
    path again and not why): a PNG whose header states a side of 0 (Pillow takes no such PNG), else a file of
    no image format Pillow reads, or a damaged header. Stop 49 (robust49)."""
    head = source[:24] if isinstance(source, bytes) else b""
    if not isinstance(source, bytes):
        with contextlib.suppress(OSError), open(source, "rb") as f:
            head = f.read(24)
    if head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR":
        width, height = int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")
        if width and height:  # a size Pillow takes: what it did not was further on (a chunk's checksum or type)
            return (
                f"its PNG header states {width}x{height} pixels, but a chunk after it is damaged: {_png_damage(source)}"
            )
        return f"its PNG header states a size of {width}x{height} pixels: no image, or a damaged header"
    return "not of an image format Pillow reads, PNG, JPEG, TIFF, ...; or its header is damaged"


def _png_damage(source: Path | bytes) -> str:
    """Why Pillow's PNG reader refused a PNG whose header states a size (Image.open says only that no reader knew
    it): a chunk's checksum or type, in our words."""
    from PIL import PngImagePlugin

    try:
        with io.BytesIO(source) if isinstance(source, bytes) else open(source, "rb") as file:
            PngImagePlugin.PngImageFile(file).close()
    except SyntaxError as exc:  # "broken PNG file (bad header checksum in b'tEXt')", "broken PNG file (chunk b'..')"
        found = re.search(r"checksum in b'([^']{1,8})'", str(exc))
        if found:
            return f"the checksum of its {found.group(1)} chunk is wrong"
        return "a chunk's type or length is no PNG's"
    except Exception:  # anything else: said in general below
        pass
    return "its chunks cannot be read"


def _single(img: Any, label: str, what: str) -> None:
    """Refuse an image file holding several images (an animated PNG or GIF, a multi-page TIFF) where one is
    read by value (depth, labels): Pillow would give its first in silence, which may not be the one meant."""
    try:
        frames = int(getattr(img, "n_frames", 1))
    except Exception:  # a damaged frame index: decoding the image says what is wrong
        return
    if frames > 1:
        raise FileFormatError(f"{label}: holds {frames} images (an animation or a multi-page file); {what} is one "
                              "image: save the one meant on its own")  # fmt: skip


def _decode(img: Any, label: str) -> tuple[Any, int]:
    """The decoded image, turned as its EXIF orientation says (a new image where it is not 1), and that
    orientation (1-8)."""
    from PIL import Image

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            marked = _png_mark(img)
            img.load()
    except (OSError, SyntaxError, ValueError, Image.DecompressionBombWarning, Image.DecompressionBombError) as exc:
        raise FileFormatError(f"{label}: cannot decode image ({_in_our_words(exc)})") from None
    if getattr(img, "format", None) == "PNG":
        _png_whole(img, label, marked)
    orientation = _orientation(img)
    turn = _TRANSPOSE.get(orientation)
    return (img if turn is None else img.transpose(Image.Transpose[turn])), orientation


def _png_file(img: Any) -> Any:
    """A decoded PNG's file opened anew (Pillow has closed a file it opened by name), or its buffer at its start;
    None when gone."""
    name = getattr(img, "filename", "")
    try:
        if name:
            return open(name, "rb")  # closed by the caller
        fp = getattr(img, "fp", None)
        return io.BytesIO(fp.getbuffer()) if isinstance(fp, io.BytesIO) else None
    except (OSError, ValueError):  # gone or changed since: Pillow's decoding stands
        return None


#: Samples per pixel of each PNG colour type (grey, RGB, palette, grey and alpha, RGBA).
_PNG_SAMPLES = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}


#: The value :func:`_png_mark` fills a PNG's last row with before Pillow decodes it (each band; 16-bit: 0x5A5A):
#: any value would do; one that a whole row of an image rarely holds (a row of 0, no depth, is common).
_MARK = 0x5A


def _png_mark(img: Any) -> tuple[Any, bytes] | None:
    """Before a single, non-interlaced PNG is decoded: the image memory Pillow will decode it into, made here
    with its last row filled with :data:`_MARK` (Pillow keeps image memory of the right mode and size, and
    leaves a row its data does not reach as it was), and that row's bytes as stored, so that
    :func:`_png_whole` sees whether the decoder wrote the row without inflating the data again (robust53);
    None where not so marked."""
    from PIL import Image

    if getattr(img, "format", None) != "PNG" or img.info.get("interlace") or getattr(img, "is_animated", False):
        return None
    try:
        width, height = img.size
        row = (0, height - 1, width, height)
        memory = Image.core.new(img.mode, img.size)
        value = _MARK * 0x101 if img.mode in _WIDE_GREY else _MARK
        memory.paste(value if len(img.getbands()) == 1 else (value,) * len(img.getbands()), row)
        stored = img._new(memory.crop(row)).tobytes()
    except Exception:  # a Pillow that makes image memory otherwise: the rows are counted (_png_whole)
        return None
    img.im = memory
    return memory, stored


def _png_whole(img: Any, label: str, marked: tuple[Any, bytes] | None = None) -> None:
    """Refuse a PNG whose image data holds fewer rows than its header states: Pillow decodes such a file without
    a word, the rows missing left 0 (no depth, black) when the compressed stream ends cleanly before them (stop
    52, robust52). A last row of data was decoded, so every row before it was: where the decoder wrote over the
    mark :func:`_png_mark` left in the last row (``marked``: Pillow decoded into that memory), or, unmarked,
    where the last row is not all 0, the PNG is whole. Otherwise (interlaced; a last row that holds the mark
    itself; unmarked and all 0) the rows are counted: the data inflated again, nothing kept."""
    width, height = img.size
    interlaced = bool(img.info.get("interlace"))
    last = img.crop((0, height - 1, width, height))
    if marked is not None and getattr(img, "im", None) is marked[0]:
        if last.tobytes() != marked[1]:
            return
    elif not interlaced and last.getbbox() is not None:
        return
    file = _png_file(img)
    if file is None:
        return
    with file:
        head = file.read(33)
        if head[12:16] != b"IHDR" or len(head) < 33:
            return
        depth, kind = head[24], head[25]
        row = 1 + (width * _PNG_SAMPLES.get(kind, 1) * depth + 7) // 8
        passes = ((0, 8, 0, 8), (4, 8, 0, 8), (0, 4, 4, 8), (2, 4, 0, 4), (0, 2, 2, 4), (1, 2, 0, 2), (0, 1, 1, 2))
        expected = height * row if not interlaced else sum(
            ((height - y0 + dy - 1) // dy) * (1 + (((width - x0 + dx - 1) // dx) * _PNG_SAMPLES.get(kind, 1) * depth
                                                   + 7) // 8) * (width > x0) for x0, dx, y0, dy in passes
            if height > y0)  # fmt: skip
        found = _png_inflated(file, expected)
        if found is None:
            return
    if found < expected:
        held = f"{found // row:,} of the {height:,} rows" if not interlaced else f"{found:,} of {expected:,} bytes"
        raise FileFormatError(f"{label}: its PNG data holds {held} its header states: the file is cut short or "
                              "damaged")  # fmt: skip


def _png_inflated(file: Any, expected: int) -> int | None:
    """How many bytes a PNG's image data (``file`` past its signature and header) inflates to, counted up to
    ``expected`` (read 1 MB at a time, nothing kept); None for data that cannot be inflated (Pillow's to say)."""
    inflate, found = zlib.decompressobj(), 0
    file.seek(8)
    while found < expected:
        head = file.read(8)
        if len(head) < 8 or head[4:] == b"IEND":
            break
        size = int.from_bytes(head[:4], "big")
        if head[4:] != b"IDAT":
            file.seek(size + 4, io.SEEK_CUR)
            continue
        left = size
        while left and found < expected:
            piece = file.read(min(left, 1 << 20))
            if not piece:
                return found
            left -= len(piece)
            try:
                found += len(inflate.decompress(piece, expected - found + 1))
                while inflate.unconsumed_tail and found < expected:
                    found += len(inflate.decompress(inflate.unconsumed_tail, expected - found + 1))
            except zlib.error:
                return None
        file.seek(left + 4, io.SEEK_CUR)
    return found


#: EXIF orientation -> the ``Image.Transpose`` that shows the image as displayed (2-8; 1 is as stored): as
#: ``PIL.ImageOps.exif_transpose``, which also rewrites the metadata (not needed: pixels are all that is read).
_TRANSPOSE = {2: "FLIP_LEFT_RIGHT", 3: "ROTATE_180", 4: "FLIP_TOP_BOTTOM", 5: "TRANSPOSE", 6: "ROTATE_270",
              7: "TRANSVERSE", 8: "ROTATE_90"}  # fmt: skip
#: Orientations that turn an image a quarter: its width and height swap on reading.
QUARTER_TURNS = frozenset({5, 6, 7, 8})


def _orientation(img: Any) -> int:
    """The EXIF orientation of an opened image, 1 where it has none or an unreadable one (viewers show such
    an image as stored too)."""
    try:
        value = img.getexif().get(0x0112, 1)
    except Exception:  # Pillow's EXIF parser raises many types on a damaged block
        return 1
    return value if isinstance(value, int) and value in _TRANSPOSE else 1  # 1 and nonsense: as stored


def exif_orientation(path: str | Path) -> int:
    """The EXIF orientation (1-8) of an image file, read from its header; 1 where it has none."""
    path = as_path(path, "exif_orientation: the image")
    with _open(path, str(path)) as img:
        return _orientation(img)


#: What each EXIF orientation does to the stored pixels on reading.
ORIENTATION_NAMES = {1: "as stored", 2: "mirrored left-right", 3: "turned half around", 4: "mirrored top-bottom",
                     5: "mirrored and turned a quarter", 6: "turned a quarter clockwise", 7: "mirrored and turned "
                     "a quarter", 8: "turned a quarter anticlockwise"}  # fmt: skip


def orientation_mismatch(color_path: Path | str, orientation: int, depth_path: Path, depth_orientation: int, *,
                         what: str = "depth") -> None:  # fmt: skip
    """Refuse colour and depth (or instance labels, ``what``) that their EXIF orientations turn differently on
    reading (a phone photo's tag beside a depth image registered to its stored pixels): even where the sizes
    agree (half a turn, a mirror), depth or labels would meet the wrong pixels.

    Raises
    ------
    FileFormatError
        Naming both files and their orientations.
    """
    if orientation == depth_orientation:
        return
    raise FileFormatError(f"{color_path}: its EXIF orientation {orientation} ({ORIENTATION_NAMES[orientation]}) is "
                          f"applied on reading (images are read as displayed), but {Path(depth_path).name} has "
                          f"{depth_orientation} ({ORIENTATION_NAMES[depth_orientation]}): {what} registered to the "
                          "stored pixels would meet other pixels; save the colour image as displayed without its "
                          "orientation tag, or give both the same")  # fmt: skip


def turned_mismatch(color_path: Path, shape: tuple[int, ...], others: dict[str, tuple[int, ...]]) -> None:
    """Refuse a colour image that its EXIF orientation turned a quarter on reading (``shape``, as read)
    while ``others`` (what -> its ``(h, w)``: the depth image, the intrinsics) are for its stored size.

    Raises
    ------
    FileFormatError
        Naming the colour file, its orientation and what has the stored size.
    """
    h, w = shape[:2]
    stored = [what for what, size in others.items() if tuple(size[:2]) == (w, h) and w != h]
    if not stored:
        return
    orientation = exif_orientation(color_path)
    if orientation not in QUARTER_TURNS:
        return
    raise FileFormatError(f"{color_path}: its EXIF orientation {orientation} turns it a quarter on reading (images "
                          f"are read as displayed: {h}x{w} stored, {w}x{h} shown), but {' and '.join(stored)} "
                          f"{'are' if len(stored) > 1 else 'is'} for the stored {h}x{w} pixels; save the colour "
                          "image turned as displayed (or without its orientation tag) so that all agree")  # fmt: skip


#: Pixels converted at a time: a decoded image is copied out of Pillow in bands of rows, so reading one costs
#: its decoded size plus the result, not several full-size temporaries (a 39-MP photo: ~0.3 GB, not ~1 GB).
BAND_PIXELS = 1 << 20


def _banded(img: Any, out: np.ndarray, convert: Any) -> np.ndarray:
    """Fill ``out`` (``(h, w, ...)``) with ``convert(band)`` of each band of rows of the decoded ``img``."""
    w, h = img.size
    rows = max(1, BAND_PIXELS // max(w, 1))
    for r0 in range(0, h, rows):
        r1 = min(r0 + rows, h)
        out[r0:r1] = convert(img.crop((0, r0, w, r1)))
    return out


def _to_rgb(img: Any, label: str) -> np.ndarray:
    mode = img.mode
    w, h = img.size
    out = np.empty((h, w, 3), np.uint8)
    if mode == "RGB":
        return _banded(img, out, lambda band: np.asarray(band, dtype=np.uint8))
    if mode in _COLOUR_MODES:
        return _banded(img, out, lambda band: np.asarray(band.convert("RGB"), dtype=np.uint8))
    if mode in _WIDE_GREY:
        lo, hi = img.getextrema()
        if lo < 0 or hi > 65535:
            raise FileFormatError(f"{label}: 32-bit grey values outside 0-65535 cannot be a colour image")
        shift = 8 if mode != "I" or hi > 255 else 0

        def grey(band: Any) -> np.ndarray:
            g = (np.asarray(band).astype(np.int64) >> shift).astype(np.uint8)
            return g[:, :, None]

        return _banded(img, out, grey)
    raise FileFormatError(f"{label}: image mode {mode!r} cannot be read as colour (use 8-bit RGB)")


def read_color(path: str | Path) -> np.ndarray:
    """A colour image as ``(h, w, 3) uint8`` RGB, from any mode listed in the module docstring, as displayed."""
    return read_color_oriented(path)[0]


def read_color_oriented(path: str | Path) -> tuple[np.ndarray, int]:
    """:func:`read_color`, and the EXIF orientation it applied (1: none)."""
    path = as_path(path, "read_color: the image")
    with unchanged_while([path], "while it was read"), _open(path, str(path)) as img:
        shown, orientation = _decode(img, str(path))
        return _to_rgb(shown, str(path)), orientation


def decode_color(data: bytes, label: str) -> np.ndarray:
    """:func:`read_color` for encoded bytes (a ``CompressedImage``'s JPEG or PNG). One that carries an EXIF
    orientation is refused: a message's depth beside it is raw pixels, registered to the stored ones."""
    with _open(bytes(data), label) as img:
        shown, orientation = _decode(img, label)
        if orientation != 1:
            raise FileFormatError(f"{label}: carries EXIF orientation {orientation} ({ORIENTATION_NAMES[orientation]} "
                                  "on reading), but depth beside it is raw, registered to the stored pixels; "
                                  "encode the image without an orientation tag")  # fmt: skip
        return _to_rgb(shown, label)


#: Depth an 8-bit depth image must reach (255 units times the depth scale, metres) to be read as depth: one
#: that reaches less (0.255 m at millimetre units) is a picture of depth (normalised to 0-255 for viewing),
#: not a measurement, and would give every pixel a wrong depth.
MIN_8BIT_DEPTH_REACH = 1.0
#: Depth a 16-bit depth image must reach (65535 units times the depth scale, metres): a scale below
#: 1/65535 m (15 micrometres) is no camera's; 1e-300 became 0 in float32 and every pixel had no depth, unsaid.
MIN_16BIT_DEPTH_REACH = 1.0


#: Float depth beyond this (metres, either sign) is no measurement, in metres or in millimetres (16-bit units reach
#: 65,535): a sentinel such as FLT_MAX (3.4e38), read as no depth as inf and NaN are (kept, it overflowed numpy's
#: median of the depth in float32: a RuntimeWarning instead of a clean refusal or a frame).
NO_DEPTH_BEYOND = 1e6


def float_depth(depth: np.ndarray) -> np.ndarray:
    """Float depth in metres as ``float32``: NaN, infinities and values beyond :data:`NO_DEPTH_BEYOND` become 0 (no
    depth); a float64 value beyond float32 is one of them. In place where ``depth`` is already ``float32``."""
    with np.errstate(over="ignore", invalid="ignore"):  # float64 beyond float32 (1e300 m): inf, then no depth
        out = np.asarray(depth).astype(np.float32, copy=False)
        out[~(np.abs(out) <= NO_DEPTH_BEYOND)] = 0.0
    return out


def read_depth_units(path: str | Path, *, scale: float | None = None) -> np.ndarray:
    """A single-channel depth image as ``(h, w) uint16`` raw units (``depth_scale`` metres each), as displayed.

    With ``scale`` (metres per unit), an 8-bit image is refused when 255 units reach less than
    :data:`MIN_8BIT_DEPTH_REACH`, a 16-bit one when 65535 units reach less than :data:`MIN_16BIT_DEPTH_REACH`.
    """
    return read_depth_units_oriented(path, scale=scale)[0]


def read_depth_units_oriented(path: str | Path, *, scale: float | None = None) -> tuple[np.ndarray, int]:
    """:func:`read_depth_units`, and the EXIF orientation it applied (1: none)."""
    path = as_path(path, "read_depth_units: the depth image")
    with unchanged_while([path], "while it was read"), _open(path, str(path)) as img:
        _single(img, str(path), "a depth image")
        img, orientation = _decode(img, str(path))
        kind = f"depth {img.format or 'image'}"  # PNG, TIFF, ... (a folder of depth images may hold any)
        if img.mode == "F":  # a float TIFF of metres, as many tools write depth: say where float depth is read
            raise FileFormatError(f"{path}: {kind} holds 32-bit floats; a depth image must hold 16-bit units "
                                  "(depth in float metres is read from a .npy file: numpy.save('depth.npy', "
                                  "metres))")  # fmt: skip
        if img.mode not in _WIDE_GREY and img.mode != "L":
            raise FileFormatError(f"{path}: {kind} must be single-channel 16-bit, got mode {img.mode!r}")
        if img.mode == "L" and scale is not None and 255 * scale < MIN_8BIT_DEPTH_REACH:
            raise FileFormatError(f"{path}: {kind} is 8-bit: at {scale:g} m per unit it reaches only "
                                  f"{255 * scale:.3g} m, so it is a picture of depth, not depth; write 16-bit units "
                                  "(or give the depth scale that its 8-bit units stand for)")  # fmt: skip
        if img.mode != "L" and scale is not None and 65535 * scale < MIN_16BIT_DEPTH_REACH:
            raise FileFormatError(f"{path}: at {scale:g} m per unit its 16-bit depth reaches only {65535 * scale:.3g} "
                                  "m; no camera measures depth that finely: give the depth scale its units stand "
                                  "for (metres per unit, 0.001 for millimetres)")  # fmt: skip
        raw = np.asarray(img)
    if raw.ndim != 2:
        raise FileFormatError(f"{path}: {kind} must be single-channel, got shape {raw.shape}")
    if raw.dtype.kind not in "ui":
        raise FileFormatError(f"{path}: {kind} must hold integer units, got {raw.dtype}")
    if raw.size and (raw.min() < 0 or raw.max() > 65535):
        raise FileFormatError(f"{path}: depth units outside 0-65535")
    return raw.astype(np.uint16), orientation


def read_labels(path: str | Path) -> np.ndarray:
    """An instance label image as ``(h, w) int32`` (0 background); RGB label images get one label per colour
    (black, and in RGBA a fully transparent pixel, is background)."""
    return read_labels_oriented(path)[0]


def read_labels_oriented(path: str | Path) -> tuple[np.ndarray, int]:
    """:func:`read_labels`, and the EXIF orientation it applied (1: none)."""
    path = as_path(path, "read_labels: the label image")
    with unchanged_while([path], "while it was read"), _open(path, str(path)) as img:
        _single(img, str(path), "a label image")
        img, orientation = _decode(img, str(path))
        mode = img.mode
        if mode in ("RGB", "RGBA", "RGBX"):
            pixels = np.asarray(img)
            rgb = pixels[:, :, :3].astype(np.int64)
            keys = rgb[:, :, 0] << 16 | rgb[:, :, 1] << 8 | rgb[:, :, 2]
            if mode == "RGBA":  # a transparent pixel is background, whatever colour it hides (RGBX: X is padding)
                keys[pixels[:, :, 3] == 0] = 0  # before: a transparent white background was one big fruit
            _, inverse = np.unique(keys.ravel(), return_inverse=True)
            labels = inverse.reshape(keys.shape).astype(np.int32)  # black (key 0) sorts first: label 0
            labels = labels if keys.min() == 0 else labels + 1
            return instance_labels(labels, str(path), error=FileFormatError), orientation
        if mode in ("1", "L", "P") or mode in _WIDE_GREY:
            w, h = img.size
            # every single-channel mode Pillow reads holds 32-bit signed values at most
            labels = _banded(img, np.empty((h, w), np.int32), lambda band: np.asarray(band).astype(np.int32))
        else:
            raise FileFormatError(f"{path}: label image mode {mode!r} is not an instance label image (use a "
                                  "single-channel 8- or 16-bit PNG, or RGB with one colour per fruit)")  # fmt: skip
    if labels.size and labels.min() < 0:
        raise FileFormatError(f"{path}: negative labels")
    return instance_labels(labels, str(path), error=FileFormatError), orientation
