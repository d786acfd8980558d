"""The built-in segmenter: ripe red fruit by colour, each fruit whole, touching fruit apart. No weights.

A strawberry is a convex red body; what is not red on it (seeds, specular highlights, the green calyx
lying over it) sits inside that body's outline. So the segmenter

1. classes pixels by *chromaticity*, which shading does not change: redness ``(R - max(G, B)) / R``
   (0 for white, grey and green, 1 for pure red) and hue. A region grows from strongly red seed pixels
   (``redness >= red_high`` and a red, not orange, hue) through weakly red ones (``redness >= red_low``):
   hysteresis. White and green (unripe) fruit, the calyx, stems, skin tones too weak to seed and the
   light background never start a region; very dark pixels (deep shadow, black borders) are never red.
   Red is looked for on a coarse grid first and at full resolution only around what it finds; when
   every candidate fruit there is large (a close-up, a 1920x1080 photo), the image is worked on every
   2nd-4th pixel (each fruit still ``WORK_DIAMETER`` pixels across) and the fruit are brought back to full
   resolution as polygons. With depth, a region is kept by the least fruit's size at its own depth
   (``min_diameter``), not by a share of the image, so 40-60 px apples in a 1920x1080 frame count.
2. splits each region where it is not one convex body. A convex body's *distance transform* (the
   distance of each pixel to the region's outline) is concave: one peak, and the points deeper than any
   radius stay connected. Two touching or overlapping fruit give two peaks joined by a *waist*. A peak
   cut off from every larger one by a waist (below ``waist`` times its radius) is another fruit's
   centre; the region is cut between the centres (each centre's deep core, every other pixel to the
   nearest core). With depth, depth steps and concave depth creases count as outline, and every
   saddle is a candidate. A cut is kept only where evidence backs two bodies:

   * with depth: steps or creases along most of the cut, or two *surfaces*: the spheres fitted to the
     two parts' depth points have centres more than ``sphere_apart`` of the sum of their radii apart
     (touching fruit: about one sum of radii; one fruit cut in two: one centre);
   * by shape: a waist, and *convexity defects* where the parts meet: the hull of the two parts exceeds
     their own hulls by more than ``merge_slack`` (they are not one convex body).
3. merges the fragments of one fruit (pieces the calyx, a stem or a highlight band cut apart): two
   pieces whose union's hull, less the green pixels in it, exceeds their own hulls by at most
   ``merge_slack`` are one convex body; with depth, the smaller one must also lie on the larger one's
   sphere.
4. reports each fruit as its convex hull: seeds, highlights and the calyx inside the outline are filled
   (``fill``: without depth the whole outline, as annotators draw it; with depth the visible surface,
   green calyx, leaf and stem pixels over it left out, and pixels off the fruit's depth dropped).
   With ``round_fruit`` (apples), the visible skin also takes the pixels around the red part reached from
   it without crossing a depth step and not leaf green (a bicoloured apple's yellow or yellow-green side, not
   the leaf behind it).
5. drops parts that are not ripe fruit: too small (with depth: smaller than ``min_diameter`` at their
   depth; without: than ``min_area_share`` of the image), without depth far more elongated than a
   berry, or not red over most of their body (``ripe_median``; blushed white or green fruit). With
   ``round_fruit`` and depth this is settled for each region before it is split: one no larger than the
   largest fruit (``round_max_diameter``) and not ripe-red over most of it is dropped at once (bark, twigs),
   and one larger (a fruit joined to bark by weakly red pixels) keeps only its ripe-red cores.

Fruit cut by the image border are kept (their hull is cut by the border too).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np
from scipy import ndimage

from ..core.edges import gaussian_weights as _gaussian_weights
from ..core.kernels import compiled
from ..core.lapack import lstsq
from ..core.limits import MAX_PIECES, check_image_size, depth_metres
from ..core.points import median, row_norms
from ..core.raster import distance_transform, fill_holes, mask_box, nearest_index, square_filter
from ..errors import InputError
from ..settings import Section, SettingError, setting

__all__ = ["SegmentSettings", "convex_hull_mask", "learned_masks", "redness", "ripe_seeds", "segment"]

#: Largest morphology or smoothing radius a setting may ask for (pixels).
MAX_RADIUS_PX = 50

Window = tuple[slice, slice]


class _Focal(Protocol):
    @property
    def fx(self) -> float: ...

    @property
    def fy(self) -> float: ...


@dataclass(frozen=True)
class SegmentSettings(Section):
    """The built-in colour segmenter (:mod:`symfruit.segment.colour`): ripe red fruit, no weights needed.

    Attributes
    ----------
    red_high, red_low : float in (0, 1)
        Redness ``(R - max(G, B)) / R`` a seed pixel needs, and that a pixel needs to join a region
        grown from seeds. White, grey and green pixels have redness <= 0.
    hue_max : float, degrees
        Seed pixels must have a hue below this (red-magenta to red-orange: ``atan2(sqrt(3) (G - B),
        2R - G - B)``); skin and orange tones above it do not seed.
    dark : int, 0-255
        Pixels with red channel at or below this are dim: their chromaticity is noise unless the red
        channel clearly exceeds the others (``dark_chroma``); black borders, deep shadow.
    dark_chroma : int, 0-255
        A dim pixel (red at or below ``dark``) is red only when its red channel also exceeds green and blue by
        this many levels, besides the redness tests: an apple in a leaf's shadow (R 20-40 with G and B near
        10 in an auto-exposed outdoor frame) keeps its colour, a grey or brownish shadow pixel whose channels
        differ by noise does not. 0: dim pixels are never red (stops 1-44). Default 12: a 8-bit camera frame's
        noise in shadow is about 2 levels a channel (after demosaicing and JPEG), so the difference of two
        channels about 3 and the largest of two about 2 more; 12 is over three of those spreads.
    close_px : int, pixels
        Radius of a closing of each region before it is split (bridges seeds on its outline); 0: none.
    min_area_share : float
        Without depth, the least area of a fruit as a share of the image.
    merge_slack : float
        Two pieces are one fruit when the convex hull of their union exceeds the sum of their own hulls
        by at most this share; a region is split only where its parts exceed it.
    fill : {"auto", "hull", "surface"}
        What of a fruit's convex hull is reported: the whole hull (its outline, as annotators draw it:
        the calyx lying over the fruit included), or its visible surface (green calyx, leaf and stem
        pixels over it left out; what the extraction of points needs). "auto": the surface with depth,
        the hull without.
    split : {"both", "depth", "watershed", "none"}
        The evidence a cut between touching fruit may rest on: the shape of the region (a waist with
        convexity defects, "watershed"), its depth (steps, creases, two surfaces; with depth only),
        both, or none (touching fruit stay one region).
    waist : float in (0, 1]
        By shape, two distance-transform peaks are separate fruit when the region between them narrows
        below this share of the smaller peak's inscribed radius.
    max_elongation : float
        Without depth, parts whose hull is more elongated than this (ratio of principal axes) are not fruit
        (a finger, a rim of skin); with depth the size rule in metres decides, and a sliver of a fruit
        seen past a leaf is kept.
    ripe_median : float
        A ripe fruit is red over most of its body: the median redness of a part's red pixels must reach
        this. Skin, and fruit that are only blushed (white or green with a pink tinge), fall short.
    min_diameter : float, metres
        With depth: parts smaller than a fruit of this diameter at their depth are ignored.
    depth_jump : float, metres
        With depth: a step between neighbouring pixels larger than this separates fruit; hull pixels
        farther than this from the fruit's median depth are dropped.
    crease_curvature : float, 1/metres
        With depth: a concave crease of the smoothed depth (Laplacian below ``-crease_curvature``
        metres per metre squared) separates fruit at the same depth. Convex fruit surfaces never reach it.
    crease_sigma : float, pixels
        Smoothing of the depth before the crease test (the sensor noise must not look like creases).
    sphere_apart : float
        With depth: two touching parts are two fruit when the spheres fitted to their depth points have
        centres farther apart than this share of the sum of their radii (touching fruit: about 1; one
        fruit cut in two: about 0); two fragments are one fruit when the smaller lies on the larger's
        sphere within this share of its radius.
    round_fruit : bool
        With depth: the fruit are round and may be only partly red (bicoloured apples), so each one's
        visible skin also takes the pixels around its red part (within twice its radius) reached without
        crossing a depth step and not leaf green (hue :data:`LEAF_HUE` or more): the yellow or yellow-green
        side, not the leaf behind. Off for strawberries.
    round_max_diameter : float, metres
        With depth and ``round_fruit``: the largest fruit. A weakly red region larger than a disc of this
        diameter at its depth is a fruit joined to bark or a twig by weakly red pixels, and only its ripe-red
        cores are kept; a smaller one not ripe-red over most of it (``ripe_median``) is dropped before it is
        split (:func:`_ripe_cores`); a grown skin larger than that disc is not taken. Default 0.12: round
        fruit up to large apples and oranges (about 100 mm) with a margin; the apple profile sets 0.10.
    ground_colour : bool
        With depth and ``round_fruit``: a fruit turned with its ground colour (yellow to yellow-green, hue
        :data:`GROUND_HUE` to :data:`LEAF_HUE` degrees) to the camera, no red to seed it, is found when its
        depth shows a round body of fruit size (:func:`_round_body`: a sphere of radius ``min_diameter / 2``
        to ``0.6 round_max_diameter`` fits its surface far better than a plane, convex towards the camera; its
        outline convex). Unripe fruit of the same colour are found too: colour cannot tell them apart. Off by
        default; the apple profile sets it.
    """

    red_high: float = setting(0.30, gt=0.0, lt=1.0)
    red_low: float = setting(0.12, gt=0.0, lt=1.0)
    hue_max: float = setting(25.0, gt=0.0, lt=90.0)
    dark: int = setting(40, ge=0, le=254)
    dark_chroma: int = setting(12, ge=0, le=255)
    close_px: int = setting(0, ge=0, le=MAX_RADIUS_PX)
    min_area_share: float = setting(0.002, ge=0.0, lt=1.0)
    merge_slack: float = setting(0.08, ge=0.0, le=1.0)
    fill: Literal["auto", "hull", "surface"] = setting("auto")
    split: Literal["both", "depth", "watershed", "none"] = setting("both")
    waist: float = setting(0.6, gt=0.0, le=1.0)
    max_elongation: float = setting(3.0, ge=1.0, le=100.0)
    ripe_median: float = setting(0.20, ge=0.0, lt=1.0)
    min_diameter: float = setting(0.012, gt=0.0, le=1.0)
    depth_jump: float = setting(0.015, gt=0.0, le=10.0)
    crease_curvature: float = setting(1500.0, gt=0.0, le=1e7)
    crease_sigma: float = setting(2.0, ge=0.0, le=MAX_RADIUS_PX)
    sphere_apart: float = setting(0.5, gt=0.0, le=10.0)
    round_fruit: bool = setting(False)
    round_max_diameter: float = setting(0.12, gt=0.0, le=1.0)
    ground_colour: bool = setting(False)

    def check(self) -> None:
        if self.red_low > self.red_high:
            raise SettingError("red_low", f"must not exceed red_high ({self.red_high:g}), got {self.red_low:g}")


def _color(color: np.ndarray) -> np.ndarray:
    c = np.asarray(color)
    if c.ndim != 3 or c.shape[2] not in (3, 4) or c.shape[0] < 1 or c.shape[1] < 1:
        raise InputError(f"color must be an (h, w, 3) image, got shape {c.shape}")
    if c.dtype != np.uint8:
        if c.dtype.kind not in "iuf" or not np.isfinite(c).all():
            raise InputError("color must be a finite uint8 image (0-255)")
        # 8-bit values in another type (a list, int64) are read as they are; anything else is no 8-bit colour and
        # was cut into 0-255 unsaid: 16-bit colour read as white, a float image in [0, 1] as black (no fruit)
        lo, hi = float(c.min()), float(c.max())
        if lo < 0 or hi > 255:
            raise InputError(f"color must be 8-bit (0-255), got values {lo:g} to {hi:g} ({c.dtype}; 16-bit colour: "
                             "divide by 257 first)")  # fmt: skip
        if c.dtype.kind == "f" and (0 < hi <= 1 or not np.array_equal(c, np.round(c))):  # [0, 1]: not 8-bit
            raise InputError(f"color must be 8-bit whole numbers (0-255), got {c.dtype} {lo:g} to {hi:g} (a float "
                             "image in [0, 1]: multiply by 255 first)")  # fmt: skip
        c = c.astype(np.uint8)
    return c[:, :, :3]


def _ripe(color: np.ndarray, red: np.ndarray, ripe_median: float) -> bool:
    """Whether the median redness of the pixels ``red`` (h, w) bool of ``color`` (h, w, 3) uint8 reaches
    ``ripe_median``: the float32 median compared in float32, with the compiled twin (issue 19, eighteenth round)
    as without it (a setting such as 0.35 rounds down in float32, and a median equal to it is ripe either way); where
    numba is, the answer mostly by counting the values below it (:func:`symfruit.core._jit.red_ripe`, stop 48)."""
    jit = compiled()
    if jit is not None and red.ndim == 2 and red.dtype == bool and color.dtype == np.uint8 and color.ndim == 3:
        return bool(jit.red_ripe(color, red, np.float32(ripe_median)))  # mostly without the median (stop 48)
    value = jit.red_median(color, red) if jit is not None else median(redness(color[red]))
    return bool(np.float32(value) >= np.float32(ripe_median))


def redness(color: np.ndarray) -> np.ndarray:
    """Chromatic redness ``(R - max(G, B)) / R`` of each pixel (negative when not red).

    Parameters
    ----------
    color : (h, w, 3) uint8, or (n, 3)

    Returns
    -------
    (h, w) float32 (or (n,)), at most 1; independent of the brightness (shading) of a pixel.

    Examples
    --------
    >>> redness(np.array([[[200, 50, 40], [100, 25, 20], [90, 90, 90]]], np.uint8)).round(2)
    array([[0.75, 0.75, 0.  ]], dtype=float32)
    """
    c = np.asarray(color)
    if c.ndim == 2 and c.shape[-1] in (3, 4):
        c = c[None]
    c = _color(c)
    r = c[..., 0].astype(np.float32)
    gb = np.maximum(c[..., 1], c[..., 2]).astype(np.float32)
    out = (r - gb) / np.maximum(r, 1.0)
    return out[0] if np.asarray(color).ndim == 2 else out


def ripe_seeds(color: np.ndarray, settings: SegmentSettings | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The seed (strongly red) and grow (weakly red) pixel masks of :func:`segment`.

    Parameters
    ----------
    color : (h, w, 3) uint8
    settings : SegmentSettings

    Returns
    -------
    strong, weak : (h, w) bool
    """
    c = _color(color)
    weak_at, strong_at = _red_pixels(c, settings or SegmentSettings())
    strong = np.zeros(c.shape[:2], bool)
    strong.ravel()[strong_at] = True
    weak = np.zeros(c.shape[:2], bool)
    weak.ravel()[weak_at] = True
    return strong, weak


def _red_pixels(c: np.ndarray, s: SegmentSettings) -> tuple[np.ndarray, np.ndarray]:
    """The flat indices (ascending) of :func:`ripe_seeds`' weak and strong pixels of a checked colour image."""
    low, high = _red_tables(s.red_low, s.red_high, s.dark, s.dark_chroma)
    if (jit := compiled()) is not None and c.dtype == np.uint8 and c.ndim == 3 and c.shape[2] == 3:
        # the compiled twin of what follows (:func:`symfruit.core._jit.red_pixels`: the same pixels; issue 19, sixteenth
        # round), on the window as it is
        weak, strong = jit.red_pixels(c, low, high, float(np.sqrt(3.0)), float(np.tan(np.radians(s.hue_max))))
        return weak, strong
    # a weakly red pixel has R above max(G, B) (low[R] < R as red_low > 0): the tables are read for those
    # pixels alone (a look-up over the whole image converts every pixel's index to 64 bits first), and the
    # strong table for the weak ones alone (high <= low, as red_high >= red_low); on a contiguous copy (numpy's
    # loops over a window's strided channels are several times slower)
    c = np.ascontiguousarray(c)
    at = np.flatnonzero(c[:, :, 0] > np.maximum(c[:, :, 1], c[:, :, 2]))
    rgb = c.reshape(-1, 3).take(at, axis=0).astype(np.int16)
    rw, mw = rgb[:, 0], np.maximum(rgb[:, 1], rgb[:, 2])
    keep = np.flatnonzero(mw <= low.take(rw))
    at, rgb, rw, mw = at.take(keep), rgb.take(keep, axis=0), rw.take(keep), mw.take(keep)
    keep = np.flatnonzero(mw <= high.take(rw))
    # hue < hue_max  <=>  sqrt(3) (G - B) < tan(hue_max) (2R - G - B)  (2R - G - B > 0 on red pixels);
    # tested on the strongly red pixels only
    rs, gs, bs = rw.take(keep), rgb[:, 1].take(keep), rgb[:, 2].take(keep)
    hue = np.sqrt(3.0) * (gs - bs) < np.tan(np.radians(s.hue_max)) * (2 * rs - gs - bs)
    return at, at.take(keep)[hue]


@functools.lru_cache(maxsize=16)
def _red_tables(red_low: float, red_high: float, dark: int, dark_chroma: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_red_pixels`' look-up tables, (256,) int16 each, read-only: redness >= t  <=>  max(G, B) <= (1 - t) R,
    compared against per-R tables (integers only); worked out once per setting, not for each of a frame's windows.
    Dim pixels (R <= dark) also need max(G, B) <= R - dark_chroma (never red with ``dark_chroma`` 0)."""
    levels = np.arange(256, dtype=np.float64)
    low = np.floor((1.0 - red_low) * levels + 1e-9).astype(np.int16)
    high = np.floor((1.0 - red_high) * levels + 1e-9).astype(np.int16)
    dim = np.arange(dark + 1, dtype=np.int16)
    margin = dim - dark_chroma if dark_chroma > 0 else np.full(dark + 1, -1, np.int16)
    low[: dark + 1] = np.maximum(np.minimum(low[: dark + 1], margin), -1)  # -1: never red
    high[: dark + 1] = np.maximum(np.minimum(high[: dark + 1], margin), -1)
    low.flags.writeable = False
    high.flags.writeable = False
    return low, high


def convex_hull_mask(mask: np.ndarray) -> np.ndarray:
    """The filled convex hull of a mask's pixels (pixel centres, edges included).

    Parameters
    ----------
    mask : (h, w) bool

    Returns
    -------
    (h, w) bool, a superset of ``mask``.

    Examples
    --------
    >>> m = np.zeros((5, 5), bool); m[0, 0] = m[0, 4] = m[4, 0] = True
    >>> int(convex_hull_mask(m).sum())
    15
    """
    mask = np.asarray(mask, dtype=bool)
    if mask.ndim != 2:
        raise InputError(f"mask must be (h, w), got shape {mask.shape}")
    return _hull_mask(_hull_vertices(mask), mask)


def _hull_mask(vertices: np.ndarray | None, mask: np.ndarray) -> np.ndarray:
    """:func:`convex_hull_mask` from the mask's :func:`_hull_vertices`. Where numba is, the hull is filled in the
    mask's copy by the compiled twin of Pillow's fill (:func:`symfruit.core._jit.polygon_fill`: the same pixels; its
    image, drawing and copy were 2.5 ms a 1920x1080 tree frame; stop 44)."""
    if vertices is None:
        return mask.copy()
    jit = compiled()
    if jit is not None and mask.ndim == 2 and mask.dtype == bool and vertices.dtype == np.float64 and _pillow_fill():
        out: np.ndarray = jit.polygon_fill(vertices, mask)
        if out.shape == mask.shape:  # whole-number vertices (a hull's always are)
            return out
    return _fill_polygon(vertices, mask.shape) | mask


def _hull_vertices(mask: np.ndarray) -> np.ndarray | None:
    """(m, 2) float (x, y) vertices of the convex hull of the mask's pixels, counter-clockwise from the least
    ``(y, x)``; None when degenerate. Where numba is, its compiled twin gives the same vertices
    (:func:`symfruit.core._jit.hull_vertices`, a monotone chain on the row ends: no Qhull call, some 0.2 ms each;
    issue 19, seventeenth round). Qhull's vertices are rolled to that start (it starts anywhere): the reported
    hull is the same polygon from any start, and a hull's area (:func:`_hull_area_of`) sums its perimeter in
    this order."""
    if (jit := compiled()) is not None and mask.ndim == 2 and mask.dtype == bool:
        v = jit.hull_vertices(mask)
        return v if len(v) else None
    from scipy.spatial import ConvexHull, QhullError

    rows = np.flatnonzero(mask.any(axis=1))
    if len(rows) == 0:
        return None
    sub = mask[rows]
    first = np.argmax(sub, axis=1)
    last = mask.shape[1] - 1 - np.argmax(sub[:, ::-1], axis=1)
    # row ends span every pixel's hull
    pts = np.concatenate((np.stack((first, rows), axis=1), np.stack((last, rows), axis=1))).astype(np.float64)
    if len(rows) < 2 and np.all(first == last):
        return None
    try:
        v = pts[ConvexHull(pts).vertices]  # counter-clockwise in (x, y), from any vertex
    except QhullError:  # all on a line
        return None
    start = int(np.lexsort((v[:, 0], v[:, 1]))[0])
    return np.concatenate((v[start:], v[:start]))


@functools.cache
def _pillow_fill() -> bool:
    """Whether the installed Pillow fills polygons as :func:`symfruit.core._jit.polygon_fill` does: its scan-line fill
    since 12.1 (checked against 12.1.1's ``Draw.c`` and Pillow 13.0's pixels; an older one joins corners otherwise)."""
    from PIL import __version__

    return tuple(int(v) for v in __version__.split(".")[:2] if v.isdigit()) >= (12, 1)


def _fill_polygon(vertices: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    from PIL import Image, ImageDraw

    img = Image.new("L", (shape[1], shape[0]), 0)
    ImageDraw.Draw(img).polygon([tuple(v) for v in vertices.tolist()], fill=1, outline=1)
    # its bytes (0 or 1) read as bool: ``np.asarray(img, dtype=bool)``'s values without its conversion (Pillow's array
    # interface, then a cast: two thirds of the call on a 1920x1080 frame's hulls; issue 19, twentieth round)
    return np.frombuffer(img.tobytes(), np.uint8).view(bool).reshape(shape[0], shape[1])


def _hull_area(mask: np.ndarray) -> float:
    """Area of the hull polygon of the mask's pixel centres, plus its half-perimeter (the pixels' own area
    beyond the centres): the filled hull's pixel count, without drawing it."""
    return _hull_area_of(_hull_vertices(mask), mask)


def _hull_area_of(v: np.ndarray | None, mask: np.ndarray) -> float:
    """:func:`_hull_area` from the mask's :func:`_hull_vertices` (each vertex's successor by one concatenation:
    the values of ``np.roll(x, -1)`` and ``np.diff(x, append=x[0])``, without their calls' overhead). Where numba is,
    in one call for whole-number vertices (:func:`symfruit.core._jit.hull_area_of`: the same value; stop 52)."""
    if v is None:
        return float(mask.sum())
    if (jit := compiled()) is not None and v.ndim == 2 and len(v) and v.shape[1] == 2 and v.dtype == np.float64:
        area = float(jit.hull_area_of(v))  # the same value in one call (stop 52, round52)
        if area >= 0.0:
            return area
    x, y = v[:, 0], v[:, 1]
    xn, yn = np.concatenate((x[1:], x[:1])), np.concatenate((y[1:], y[:1]))
    area = 0.5 * abs(float(np.dot(x, yn) - np.dot(y, xn)))
    perimeter = float(np.hypot(xn - x, yn - y).sum())
    return area + 0.5 * perimeter + 1.0


def learned_masks(spec: str) -> Callable[[np.ndarray], np.ndarray] | None:
    """The labeller ``color -> (h, w) int32 labels`` of a learned mask source, or None if ``spec`` names none.

    ``"maskrcnn:CHECKPOINT"`` is a torchvision Mask R-CNN (optional extra ``seg``), ``"onnx:MODEL"`` an ONNX
    instance-segmentation export (optional extra ``onnx``). The model is loaded (and checked) here, once;
    a missing extra or a bad file raises here, naming it.
    """
    prefix, _, path = spec.partition(":")
    if prefix == "maskrcnn" and path:
        from .maskrcnn import load_maskrcnn, maskrcnn_labels

        load_maskrcnn(path)
        return lambda color: maskrcnn_labels(color, path)
    if prefix == "onnx" and path:
        from .onnx import load_onnx, onnx_labels

        load_onnx(path)
        return lambda color: onnx_labels(color, path)
    return None


def segment(
    color: np.ndarray,
    depth: np.ndarray | None = None,
    camera: _Focal | None = None,
    settings: SegmentSettings | None = None,
) -> np.ndarray:
    """Instance labels of the ripe fruit in an image, each fruit whole.

    Parameters
    ----------
    color : (h, w, 3) uint8
    depth : (h, w) float, metres, optional
        0 = no depth. Without depth (or with none valid) the rules that need it are skipped: no
        depth split, and the size rule is ``min_area_share`` of the image.
    camera : object with ``fx``, ``fy`` (pixels), optional
        Needed with depth (the size rule and the depth tests convert metres to pixels); its ``cx``,
        ``cy`` are used when it has them (else the image centre).
    settings : SegmentSettings

    Returns
    -------
    (h, w) int32: 0 background, 1..k the fruit, numbered left to right.
    """
    if settings is not None and not isinstance(settings, SegmentSettings):
        raise InputError(f"segment: settings must be a SegmentSettings (Settings().segment), got "
                         f"{type(settings).__name__}")  # fmt: skip
    s = settings or SegmentSettings()
    c = _color(color)
    check_image_size(c.shape[1], c.shape[0], "segment: colour image")  # the bounds of every entry point
    h, w = c.shape[:2]
    z, geo = _depth(depth, camera, (h, w))
    min_area = max(s.min_area_share * h * w, 4.0)

    # Red pixels are looked for on a coarse grid first (the pyramid's top). When every candidate fruit there
    # is large, the image is worked on every ``step``-th pixel (each fruit still WORK_DIAMETER pixels or
    # more across) and the fruit brought back to full resolution.
    coarse = _coarse_regions(c, s)
    ground = s.ground_colour and s.round_fruit and z is not None
    if coarse is None and not ground:
        return np.zeros((h, w), np.int32)
    step = 1 if coarse is None else _working_step(coarse, min_area if z is None else 0.0)
    # with depth, a part without any depth (outside the depth camera's view) is sized at the frame's typical depth,
    # the median of every 8th pixel's; where the ground-colour bodies are looked for at full resolution, those pixels
    # are every other one of their coarse grid's depths (:func:`_ground_bodies`), read once (the same values; stop 54)
    if z is None:
        grid = None
    elif ground and step == 1 and 8 % COARSE_STEP == 0:
        grid = z[::COARSE_STEP, ::COARSE_STEP][:: 8 // COARSE_STEP, :: 8 // COARSE_STEP]
    else:
        grid = z[::8, ::8]
    z_typical = 0.0 if grid is None else float(median(grid[grid > 0])) if (grid > 0).any() else 1.0
    if step == 1:
        return _segment_at(c, z, geo, s, min_area, z_typical, _red_windows(coarse, (h, w)))
    o = step // 2
    small_c = c[o::step, o::step]
    small_z = None if z is None else _Depth.of(z[o::step, o::step])
    small_geo = _Geometry(geo.focal / step, (geo.cy - o) / step, (geo.cx - o) / step)
    small = _segment_at(small_c, small_z, small_geo, s, min_area / step**2, z_typical,
                        _red_windows(_coarse_regions(small_c, s), small_c.shape[:2]))  # fmt: skip
    hull = s.fill == "hull" or (s.fill == "auto" and z is None)
    return _upsample(small, step, (h, w), hull=hull)


#: A fruit this many pixels across (or more) is segmented as well on a coarser grid: when every candidate
#: fruit of an image is at least twice this, the image is worked on every other (third, fourth) pixel.
WORK_DIAMETER = 128

#: The coarsest working grid (every fourth pixel).
MAX_STEP = 4


def _working_step(coarse: Coarse, min_area: float) -> int:
    """The pixel step to work on: the smallest seeded candidate region's equivalent diameter (on the coarse
    grid) over :data:`WORK_DIAMETER`, 1 to :data:`MAX_STEP`. Regions too small to hold a quarter of the
    least fruit (``min_area``, pixels; 0 with depth, where the size rule is in metres) do not count."""
    _, sizes, seeded, *_ = coarse
    area = sizes * COARSE_STEP**2
    candidates = seeded & (area >= 0.25 * min_area)
    candidates[0] = False
    if not candidates.any():
        return 1
    diameter = float(np.sqrt(4.0 / np.pi * area[candidates].min()))
    return int(np.clip(diameter // WORK_DIAMETER, 1, MAX_STEP))


def _upsample(small: np.ndarray, step: int, shape: tuple[int, int], *, hull: bool) -> np.ndarray:
    """Labels found on every ``step``-th pixel (sampled at ``step // 2``) brought to full resolution: each
    fruit's blocks of pixels, or with ``hull`` the convex hull of those blocks (a polygon, not a staircase)."""
    h, w = shape
    out = np.zeros((h, w), np.int32)
    corners = np.array([[0, 0], [step - 1, 0], [0, step - 1], [step - 1, step - 1]], np.float64)
    for k, sl in enumerate(ndimage.find_objects(small), 1):
        if sl is None:
            continue
        mask = small[sl] == k
        r0, c0 = sl[0].start * step, sl[1].start * step
        r1, c1 = min(sl[0].stop * step, h), min(sl[1].stop * step, w)
        full = np.repeat(np.repeat(mask, step, axis=0), step, axis=1)[: r1 - r0, : c1 - c0]
        if hull:
            v = _hull_vertices(mask)
            if v is not None:
                pts = (v[:, None, :] * step + corners[None]).reshape(-1, 2)
                full = _hull_mask(_polygon(pts), full)  # the polygon filled in, as over a mask
        window = out[r0:r1, c0:c1]
        window[full & (window == 0)] = k
    return out


def _polygon(points: np.ndarray) -> np.ndarray:
    """The convex hull vertices of (n, 2) points."""
    from scipy.spatial import ConvexHull, QhullError

    try:
        return points[ConvexHull(points).vertices]
    except QhullError:
        return points


def _segment_at(
    c: np.ndarray,
    z: _Depth | None,
    geo: _Geometry,
    s: SegmentSettings,
    min_area: float,
    z_typical: float,
    windows: list[Window],
) -> np.ndarray:
    """:func:`segment` on one level of the pyramid, in the ``windows`` where red was found."""
    h, w = c.shape[:2]
    # Red pixels are looked for at full resolution around what the coarse grid found: a region that no grid
    # point falls in is far smaller than a fruit.
    weak = _zeroed((h, w), np.bool_)
    pieces: list[_Piece] = []
    sources = 0
    for win in windows:
        # the window's weak and strong pixels by flat index: the regions' sizes, depths and boxes are read off
        # the weak pixels alone, not off every pixel of a window that may span most of the image
        regions = _window_regions(c, win, z, s, geo.focal, min_area, z_typical)
        if regions is None:
            continue
        weak_w, labels, sizes, image_at, zw, ids, grouped, first, objects = regions
        weak[win] = weak_w
        if len(ids) == 0:  # no region is kept (none seeded: half the windows of the benchmark frame; stop 46)
            continue
        one = ripe = np.zeros(len(ids), bool)
        if s.round_fruit and image_at is not None and zw is not None:
            # a region no larger than one fruit and not ripe-red is dropped before its masks are made: its pixels'
            # depths and colours read off at once
            at = image_at.take(grouped)
            if (jit := compiled()) is not None:  # the same values in one call (issue 19, eighteenth round)
                red_at = jit.redness_at(c, at)
            else:
                red_at = redness(c.reshape(-1, 3).take(at, axis=0) if c.flags.c_contiguous else c[at // w, at % w])
            one, ripe = _one_fruit(first, sizes.take(ids), zw.take(grouped), red_at, s, geo.focal, z_typical)
        for k, whole in zip(ids[ripe | ~one].tolist(), one[ripe | ~one].tolist(), strict=True):
            sl = _pad(objects[k], 1, labels.shape)
            region = labels[sl] == k
            sl = (slice(sl[0].start + win[0].start, sl[0].stop + win[0].start),
                  slice(sl[1].start + win[1].start, sl[1].stop + win[1].start))  # fmt: skip
            sub_z = None if z is None else np.where(weak[sl], z[sl], 0.0)  # depth on red pixels only
            origin = (sl[0].start, sl[1].start)
            cores = [region]
            if s.round_fruit and sub_z is not None and not whole:
                cores = _ripe_cores(region, c[sl], sub_z, s, geo.focal, z_typical)
            for core in cores:
                parts = _split(core, sub_z, s, geo, origin, min_area)
                pieces += [_Piece(sl, part, 1 << sources) for part in parts]
                sources += 1
                if len(pieces) > MAX_PIECES:  # refused once past the bound: a frame of noise over noisy depth
                    raise _too_many_pieces()  # holds ~14,000 red regions, each cut into fruit at ~0.3 ms
    ground = s.ground_colour and s.round_fruit and z is not None
    if not pieces and not ground:
        return np.zeros((h, w), np.int32)
    pieces = _merge(pieces, s, c, weak, z, geo)

    pieces = sorted(pieces, key=lambda p: -p.area)
    # which piece each red pixel is part of (no hull takes another's), and below which ground-colour body each pixel
    # is: whole-image maps, in the narrowest integer type that numbers them (an 8 MB int32 image is 0.5-1 ms of
    # zeroing alone)
    owner = _zeroed((h, w), _id_type(len(pieces)))
    for k, piece in enumerate(pieces, 1):
        owner[piece.window][piece.mask] = k
    # fruit showing their ground colour: joined to the red fruit whose skin reaches them, else fruit of their own
    bodies = _ground_bodies(c, z, geo, s, owner) if ground and z is not None else []
    body_map = _zeroed((h, w), _id_type(len(bodies))) if bodies else None
    for i, body in enumerate(bodies, 1):
        body_map[body.window][body.mask] = i  # type: ignore[index]
    taken = np.zeros(len(bodies) + 1, bool)
    bridged = _BridgedDepth(z) if z is not None and s.ground_colour and s.round_fruit else None
    out = np.zeros((h, w), np.int32)
    found: list[tuple[Window, np.ndarray, tuple[int, int, int, int]]] = []
    for k, piece in enumerate(pieces, 1):
        sl, part = piece.window, piece.mask
        if z is not None and not s.round_fruit and (plain := _plain_piece(piece, k, c, weak, owner, z, s, geo.focal,
                                                                           z_typical)) is not None:  # fmt: skip
            if isinstance(plain, np.ndarray) and (claimed := _claim(out[sl], plain)) is not None:  # (stop 49)
                found.append((sl, *claimed))
            continue
        sub_z = None if z is None else z[sl]
        tested = _round_piece(piece, k, c, weak, owner, z, s) if z is not None and s.round_fruit else None
        if tested is False:  # not ripe (stop 52)
            continue
        if isinstance(tested, np.ndarray):  # the hull of a ripe round fruit's piece, in one call (stop 52)
            hull = tested
        else:
            red = part & weak[sl]
            if not red.any() or not _ripe(c[sl], red, s.ripe_median):
                continue
            surface = s.fill == "surface" or (s.fill == "auto" and sub_z is not None)
            hull = _surface_hull(piece.hull_vertices(), part, owner[sl], k, c[sl], surface)
            if sub_z is not None:
                hull = _depth_consistent(hull, red, sub_z, s.depth_jump)
        if s.round_fruit and z is not None:  # the rest of a round fruit's skin
            if bridged is not None:  # across the depth camera's invalid bands (stop 47)
                sl, hull = _bridged_skin(sl, hull, z, bridged, c, geo, s, owner, k)
            else:
                sl, hull = _round_skin(sl, hull, z, c, geo, s, owner, k)
            if body_map is not None:
                sl, hull = _join_bodies(sl, hull, bodies, body_map, taken, z, geo, s)
            sub_z = z[sl]
        if not _fruit_sized(hull, sub_z, s, geo.focal, min_area, z_typical):
            continue
        if sub_z is None and _elongation(hull) > s.max_elongation:  # with depth, a sliver seen past a leaf is kept
            continue
        claimed = _claim(out[sl], hull)
        if claimed is None:  # mostly inside a larger fruit: a piece of it, not a fruit
            continue
        found.append((sl, *claimed))
    for i, body in enumerate(bodies, 1):  # the rest: fruit with no red to seed them
        if taken[i] or z is None:
            continue
        if bridged is not None:  # across the depth camera's invalid bands (stop 47)
            sl, hull = _bridged_skin(body.window, body.mask, z, bridged, c, geo, s, owner, -1)
        else:
            sl, hull = _round_skin(body.window, body.mask, z, c, geo, s, owner, -1)
        if not _fruit_sized(hull, z[sl], s, geo.focal, min_area, z_typical):
            continue
        claimed = _claim(out[sl], hull)
        if claimed is None:
            continue
        found.append((sl, *claimed))
    if s.round_fruit and z is not None and len(found) > 1:  # a round fruit's pieces, each grown to its skin (seg63)
        found = _join_found(found, c, z, geo, s, z_typical)
    # number the fruit left to right (then top to bottom) by their box centres, for stable ids
    order = sorted(range(len(found)), key=lambda i: _box_centre(found[i][0], found[i][2]))
    for new, i in enumerate(order, 1):
        sl, free, _ = found[i]
        out[sl][free] = new
    _give_back(weak, windows)
    _give_back(owner, [piece.window for piece in pieces])
    if body_map is not None:
        _give_back(body_map, [body.window for body in bodies])
    return out


#: Zeroed whole-image maps of :func:`_segment_at` kept for its next call, by shape and type: zeroing a fresh
#: 1920x1080 map of int16 is about 0.5 ms (glibc's ``calloc`` from reused heap memory), setting the windows written
#: back to 0 a few microseconds (stop 47). A map is taken out while in use: a second thread, or a call that raised,
#: never shares or hands back one that is not all 0.
_SPARE: dict[tuple[tuple[int, ...], type[np.generic]], list[np.ndarray]] = {}


def _zeroed(shape: tuple[int, int], dtype: type[np.generic]) -> np.ndarray:
    """A zeroed map, one of :data:`_SPARE` if one is kept."""
    try:
        return _SPARE[(shape, dtype)].pop()
    except (KeyError, IndexError):
        return np.zeros(shape, dtype)


def _give_back(a: np.ndarray, windows: list[Window]) -> None:
    """Keep map ``a`` for the next call (:data:`_SPARE`) once the ``windows`` it was written in are 0 again: two maps
    of a shape and type (the pieces' and the bodies' may both be int16), of at most four shapes and types (a process
    segmenting images of many sizes keeps no more)."""
    for key in {(w[0].start, w[0].stop, w[1].start, w[1].stop) for w in windows}:
        a[key[0] : key[1], key[2] : key[3]] = 0
    if len(_SPARE) >= 4 and (a.shape, a.dtype.type) not in _SPARE:
        _SPARE.clear()
    spares = _SPARE.setdefault((a.shape, a.dtype.type), [])
    if len(spares) < 2:
        spares.append(a)


def _claim(out: np.ndarray, hull: np.ndarray) -> tuple[np.ndarray, tuple[int, int, int, int]] | None:
    """A found fruit's ``hull`` takes the pixels of ``out`` (its window of the image's labels) that are still 0,
    unless those are fewer than half its pixels (mostly inside a larger fruit: a piece of it, not a fruit; None):
    they are set to -1 and returned, with their box (:func:`symfruit.core.raster.mask_box`, for the numbering).
    Where numba is, its compiled twin does the same in one call (:func:`symfruit.core._jit.claim`; stop 41)."""
    if (jit := compiled()) is not None and hull.dtype == bool and hull.ndim == 2:
        free, r0, r1, c0, c1 = jit.claim(out, hull)
        return None if free.shape != hull.shape else (free, (int(r0), int(r1), int(c0), int(c1)))
    free = hull & (out == 0)
    if free.sum() < 0.5 * hull.sum():
        return None
    out[free] = -1
    return free, mask_box(free) or (0, 0, 0, 0)


def _surface_hull(
    vertices: np.ndarray | None, part: np.ndarray, owner: np.ndarray, k: int, color: np.ndarray, surface: bool
) -> np.ndarray:
    """A piece's filled hull (its ``vertices``, over its ``part``) less the pixels another piece owns (``owner``, the
    window of the image's map: 0 and ``k`` free) and, with ``surface``, less the green pixels that are not the part's
    (the calyx, a leaf or a stem over the fruit is not its surface). Where numba is, in one call
    (:func:`symfruit.core._jit.surface_hull`: the same pixels; stop 46)."""
    jit = compiled()
    if (jit is not None and vertices is not None and vertices.dtype == np.float64 and part.ndim == 2
            and part.dtype == bool and color.dtype == np.uint8 and color.ndim == 3 and color.shape[2] == 3
            and _pillow_fill()):  # fmt: skip
        out: np.ndarray = jit.surface_hull(vertices, part, owner, int(k), color, bool(surface))
        if out.shape == part.shape:
            return out
    hull = _hull_mask(vertices, part) & ((owner == 0) | (owner == k))
    if surface:
        hull &= part | ~_green(color)
    return hull


def _green_in_hull(vertices: np.ndarray | None, union: np.ndarray, color: np.ndarray) -> int:
    """How many pixels of the filled hull (``vertices``, over ``union``) outside ``union`` are green. Where numba is,
    in one call (:func:`symfruit.core._jit.green_in_hull`: the same count; stop 46)."""
    jit = compiled()
    if (jit is not None and vertices is not None and vertices.dtype == np.float64 and union.ndim == 2
            and union.dtype == bool and color.dtype == np.uint8 and color.ndim == 3 and color.shape[2] == 3
            and _pillow_fill()):  # fmt: skip
        n = int(jit.green_in_hull(vertices, union, color))
        if n >= 0:
            return n
    return int((_hull_mask(vertices, union) & ~union & _green(color)).sum())


def _label(mask: np.ndarray, *, eight: bool = False) -> tuple[np.ndarray, int]:
    """``ndimage.label(mask)`` of a 2-d bool mask (``eight``: with ``structure=np.ones((3, 3))``): int32 labels
    numbered by their first pixels in raster order, and their number. Where numba is, its compiled twin gives the
    same labels (:func:`symfruit.core._jit.label`, union-find; issue 19, seventeenth round): scipy's call costs more
    than the labelling on the segmenter's small windows."""
    if (jit := compiled()) is not None and mask.ndim == 2 and mask.dtype == bool:
        labels, n = jit.label(mask, eight)
        return labels, int(n)
    labels, n = ndimage.label(mask, structure=np.ones((3, 3), bool) if eight else None)
    return labels, int(n)


def _labelled(mask: np.ndarray) -> tuple[np.ndarray, int, np.ndarray, np.ndarray]:
    """:func:`_label` of a 2-d bool ``mask`` with eight neighbours, and the labelled pixels' flat indices (ascending)
    and labels. Where numba is, in one call (:func:`symfruit.core._jit.label_flat`: the same arrays; stop 51)."""
    if (jit := compiled()) is not None and mask.ndim == 2 and mask.dtype == bool:
        lab, n, at, la = jit.label_flat(mask, True)
        return lab, int(n), at, la
    lab, n = _label(mask, eight=True)
    flat = lab.ravel()
    at = np.flatnonzero(flat)
    return lab, n, at, flat.take(at)


def _red_regions(
    cw: np.ndarray, s: SegmentSettings
) -> tuple[np.ndarray, np.ndarray, int, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """A window's weakly red regions (8-connected): its weak pixels' mask (:func:`_red_pixels`), their labels and count
    n, the weak pixels' labels (in raster order), which regions hold a strong pixel, each one's size ((n + 1,), the
    background's 0 and unseeded), the weak pixels' rows and columns; None without a weak pixel. Where numba is, its
    compiled twin gives the same (:func:`symfruit.core._jit.red_regions_once`: one call, not a dozen numpy ones on
    each of a frame's windows, issue 19's seventeenth round; since stop 41 the tests and the labelling in one pass,
    the labels numbered over the weak pixels alone)."""
    if (jit := compiled()) is not None and cw.dtype == np.uint8 and cw.ndim == 3 and cw.shape[2] == 3:
        low, high = _red_tables(s.red_low, s.red_high, s.dark, s.dark_chroma)
        weak_w, labels, n, weak_at, _, lab, seeded, sizes, rows, cols = jit.red_regions_once(
            cw, low, high, float(np.sqrt(3.0)), float(np.tan(np.radians(s.hue_max)))
        )
        return None if len(weak_at) == 0 else (weak_w, labels, int(n), lab, seeded, sizes, rows, cols)
    weak_at, strong_at = _red_pixels(cw, s)
    if len(weak_at) == 0:
        return None
    shape = cw.shape[:2]
    weak_w = np.zeros(shape, bool)
    weak_w.ravel()[weak_at] = True
    labels, n = _label(weak_w, eight=True)
    flat = labels.ravel()
    seeded = np.zeros(n + 1, bool)
    seeded[flat.take(strong_at)] = True
    seeded[0] = False
    lab = flat.take(weak_at)
    sizes = np.bincount(lab, minlength=n + 1)
    rows, cols = np.divmod(weak_at, shape[1])
    return weak_w, labels, n, lab, seeded, sizes, rows, cols


def _window_regions(
    c: np.ndarray, win: Window, z: _Depth | None, s: SegmentSettings, focal: float, min_area: float, z_typical: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None, np.ndarray, np.ndarray,
           np.ndarray, dict[int, Window]] | None:  # fmt: skip
    """A red window's regions as :func:`_segment_at` works on them, None without a weak pixel: :func:`_red_regions`'
    weak mask, labels and the regions' sizes; with depth the weak pixels' flat indices in the image and their depths
    (else None); then the regions kept (seeded and, as fragments down to a quarter of a fruit may join one, at least a
    quarter of the least fruit: ``min_area``, or with depth at the region's depth, :func:`_least_areas`) grouped
    (:func:`_grouped`: their labels, pixels and runs; none where no region is seeded) and their boxes
    (:func:`_group_boxes`). Where numba is, with depth, in one compiled call (:func:`symfruit.core._jit.window_regions`:
    the same arrays; stop 55, seg55), not five calls and the numpy between them."""
    cw = c[win]
    jit = compiled()
    if (jit is not None and z is not None and cw.dtype == np.uint8 and cw.ndim == 3 and cw.shape[2] == 3
            and z.given.dtype in _FLOATS and z.given.ndim == 2 and z.given.flags.c_contiguous):  # fmt: skip
        low, high = _red_tables(s.red_low, s.red_high, s.dark, s.dark_chroma)
        weak_w, labels, n_weak, sizes, image_at, zw, ids, grouped, first, boxes = jit.window_regions(
            cw, low, high, float(np.sqrt(3.0)), float(np.tan(np.radians(s.hue_max))), z.given, int(win[0].start),
            int(win[1].start), float(s.min_diameter * focal), float(z_typical))  # fmt: skip
        if n_weak == 0:
            return None
        if len(first) == 0:  # no region seeded: no depths read
            return weak_w, labels, sizes, None, None, ids, grouped, first, {}
        objects = {k: (slice(a, b), slice(d, e)) for k, (a, b, d, e) in zip(ids.tolist(), boxes.tolist(), strict=True)}
        return weak_w, labels, sizes, image_at, zw, ids, grouped, first, objects
    regions = _red_regions(cw, s)
    if regions is None:
        return None
    weak_w, labels, n, lab, seeded, sizes, rows, cols = regions
    if not seeded.any():  # no region is kept: none is seeded
        none = np.zeros(0, np.int64)
        return weak_w, labels, sizes, None, None, none, none, none, {}
    image_at = zw = None
    least: float | np.ndarray = min_area
    if z is not None:
        image_at = (rows + win[0].start) * c.shape[1] + (cols + win[1].start)  # the pixels' flat indices in the image
        zw = z.take(image_at)
        least = _least_areas(lab, zw, n, s.min_diameter * focal, z_typical)
    keep = seeded & (sizes >= 0.25 * least)
    ids, grouped, first = _grouped(lab, keep)  # the kept regions alone: a window may hold thousands of specks
    objects = _group_boxes(ids, grouped, first, rows, cols)
    return weak_w, labels, sizes, image_at, zw, ids, grouped, first, objects


def _too_many_pieces() -> InputError:
    return InputError(f"the colour segmenter found more than {MAX_PIECES:,} red pieces; at most {MAX_PIECES:,} are "
                      "joined into fruit (a picture of noise, or a red backdrop?)")  # fmt: skip


def _id_type(n: int) -> type[np.signedinteger]:
    """The signed integer type of a map numbering ``n`` things (-1 and 0 free for none)."""
    return np.int16 if n < np.iinfo(np.int16).max else np.int32


#: Grid step of the first, coarse look for red pixels (pixels).
COARSE_STEP = 4


#: :func:`_coarse_regions`' answer: the grid's labels, each label's size and whether it holds a seed, and the weak grid
#: points' labels, rows and columns (raster order).
Coarse = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _coarse_regions(c: np.ndarray, s: SegmentSettings) -> Coarse | None:
    """The weakly red regions on a coarse grid of step :data:`COARSE_STEP`: their labels, sizes (grid
    points) and whether each holds a seed (strongly red) point, and the labelled points' labels, rows and columns
    (:data:`Coarse`); None without any. The grid's :func:`_red_regions`
    (one compiled call where numba is: the red tests, the labels and their sizes and seeds together), the values of
    :func:`ripe_seeds`' masks labelled with eight neighbours, their ``bincount`` and seeds (stop 43: their bincount
    over the grid's labels alone was 0.7 ms of a 1920x1080 frame)."""
    regions = _red_regions(c[::COARSE_STEP, ::COARSE_STEP], s)
    if regions is None:
        return None
    _, lab, _, points, seeded, sizes, rows, cols = regions
    return lab, sizes, seeded, points, rows, cols


def _red_windows(coarse: Coarse | None, shape: tuple[int, int]) -> list[Window]:
    """Disjoint image windows holding every weakly red region with a grid point in it (the coarse grid of
    :func:`_coarse_regions`), each with a margin of two grid steps. The regions' points as :func:`_red_regions` gave
    them (the grid's labelled points, in raster order), not looked for again over the whole grid (stop 58, speed58)."""
    if coarse is None:
        return []
    h, w = shape
    step = COARSE_STEP
    lab, sizes, _, points, rows, cols = coarse
    # a region that holds a single grid point is a speck, not a fruit (a fruit fragment holds several)
    big = sizes >= 2
    big[0] = False
    pad = 2  # grid steps: one around the region, and one more for its pixels between the grid points
    boxes = _join_boxes(_padded_boxes(points, rows, cols, big, pad, lab.shape))
    return [(slice(r0 * step, min(r1 * step, h)), slice(c0 * step, min(c1 * step, w))) for r0, r1, c0, c1 in boxes]


def _join_boxes(boxes: list[tuple[int, int, int, int]]) -> list[tuple[int, int, int, int]]:
    """Boxes ``(r0, r1, c0, c1)`` joined until none overlaps or abuts another: each time, the boxes whose
    painted pixels are 4-connected become their bounding box, ordered by its first pixel in raster order, as
    the labels of the painted image number them (``ndimage.label`` and ``find_objects``, worked out on the
    boxes instead of the grid); unchanged (in their own order) once no two join. The groups are the connected
    components of the graph of touching boxes (scipy's, not a union-find in Python over the pairs). Where numba is,
    its compiled twin does the same rounds (:func:`symfruit.core._jit.join_boxes`: the same boxes in the same order;
    issue 19, sixteenth round)."""
    if boxes and (jit := compiled()) is not None:
        joined = jit.join_boxes(np.array(boxes, np.int64)).tolist()
        return [(r0, r1, c0, c1) for r0, r1, c0, c1 in joined]
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    while boxes:
        b = np.array(boxes, np.int64)
        r0, r1, c0, c1 = b[:, 0], b[:, 1], b[:, 2], b[:, 3]
        rows_over = (r0[:, None] < r1[None]) & (r0[None] < r1[:, None])
        rows_touch = (r0[:, None] <= r1[None]) & (r0[None] <= r1[:, None])
        cols_over = (c0[:, None] < c1[None]) & (c0[None] < c1[:, None])
        cols_touch = (c0[:, None] <= c1[None]) & (c0[None] <= c1[:, None])
        i, j = np.nonzero(np.triu((rows_over & cols_touch) | (rows_touch & cols_over), 1))
        n = len(boxes)
        if len(i) == 0:
            break
        m, group = connected_components(coo_matrix((np.ones(len(i)), (i, j)), shape=(n, n)), directed=False)
        top = np.full(m, np.iinfo(np.int64).max)
        np.minimum.at(top, group, r0)
        first = np.full(m, np.iinfo(np.int64).max)  # the component's first pixel in raster order: its top row's
        at_top = r0 == top[group]
        np.minimum.at(first, group[at_top], c0[at_top])
        left = np.full(m, np.iinfo(np.int64).max)
        np.minimum.at(left, group, c0)
        bottom, right = np.zeros(m, np.int64), np.zeros(m, np.int64)
        np.maximum.at(bottom, group, r1)
        np.maximum.at(right, group, c1)
        order = np.lexsort((first, top))  # no two components share their first pixel
        boxes = list(zip(*(v.take(order).tolist() for v in (top, bottom, left, right)), strict=True))
    return boxes


def _box_centre(sl: Window, box: tuple[int, int, int, int]) -> tuple[int, float]:
    """A found fruit's sort key (left to right in columns of 20 pixels, then top to bottom) from its box in ``sl``
    (:func:`_claim`'s; a found piece is never empty)."""
    r0, r1, c0, c1 = box
    x = sl[1].start + (c0 + c1) / 2
    y = sl[0].start + (r0 + r1) / 2
    return round(x / 20), y


def _green(color: np.ndarray) -> np.ndarray:
    """(h, w) bool: green pixels (calyx, leaves, stems): green the largest channel, and saturated (a third
    above the smallest; a grey-green backdrop is not). Where numba is, its compiled twin gives the same pixels
    (:func:`symfruit.core._jit.green_pixels`; issue 19, seventeenth round)."""
    if (jit := compiled()) is not None and color.dtype == np.uint8 and color.ndim == 3 and color.shape[2] == 3:
        return jit.green_pixels(color, -1)
    r, g, b = (color[:, :, k].astype(np.int16) for k in range(3))
    return (g > r) & (g >= b) & (3 * (g - np.minimum(r, b)) >= g)


def _leaf(color: np.ndarray) -> np.ndarray:
    """(h, w) bool: leaf-green pixels, :func:`_green` and of a hue of at least :data:`LEAF_HUE` degrees. A
    yellow-green fruit skin (a bicoloured apple's ground colour) is green by :func:`_green` but yellower.
    With G the largest channel, the hue is ``60 + 60 (G - R) / (G - min(R, B))`` degrees (above 120 when
    B > R), so hue >= LEAF_HUE is ``60 (G - R) >= (LEAF_HUE - 60) (G - min(R, B))``: integers, independent of
    brightness and saturation. Where numba is, its compiled twin gives the same pixels
    (:func:`symfruit.core._jit.green_pixels`; issue 19, seventeenth round)."""
    if (jit := compiled()) is not None and color.dtype == np.uint8 and color.ndim == 3 and color.shape[2] == 3:
        return jit.green_pixels(color, LEAF_HUE)
    r, g, b = (color[:, :, k].astype(np.int16) for k in range(3))
    over = g - np.minimum(r, b)  # the channels cast once for both tests (as _green casts them)
    green = (g > r) & (g >= b) & (3 * over >= g)
    return green & (60 * (g - r) >= (LEAF_HUE - 60) * over)


#: The least hue (degrees) of a leaf. Leaves of apple and most fruit trees are green of hue about 85-130;
#: the ground colour of yellow-green and bicoloured apples (Golden Delicious, Gala, Fuji, Pink Lady) yellow to
#: yellow-green, about 45-75. Used by :func:`_leaf`'s integer test; a physical boundary between the
#: two, not fitted (on the rendered apple trees, seeds 0-5, the recall is flat within 1 % for 75-85).
LEAF_HUE = 80


def _depth(depth: np.ndarray | None, camera: _Focal | None, shape: tuple[int, int]) -> tuple[_Depth | None, _Geometry]:
    """The depth (:class:`_Depth`: float64 metres, 0 where invalid, window by window) and the camera geometry (the
    principal point defaults to the image centre), or ``(None, ...)`` without usable depth."""
    none = _Geometry(0.0, shape[0] / 2, shape[1] / 2)
    if depth is None:
        return None, none
    z = np.asarray(depth)
    if z.shape != shape:
        raise InputError(f"depth is {z.shape[1::-1] if z.ndim >= 2 else z.shape}, the colour image {shape[::-1]}")
    given = depth_metres(z, "segment: depth")  # float metres, not raw units
    size = (getattr(camera, "width", None), getattr(camera, "height", None))
    if None not in size and (int(size[0]), int(size[1])) != (shape[1], shape[0]):  # type: ignore[arg-type]
        raise InputError(f"segment: the camera is for {size[0]}x{size[1]} images, the image is {shape[1]}x{shape[0]}")
    given = np.ascontiguousarray(given)  # read by flat index window by window (a copy only if strided)
    # usable depth anywhere: looked for on every 8th pixel first, over the whole image only when none is there
    if not (_usable(given[::8, ::8]).any() or _usable(given).any()):
        return None, none
    if camera is None:
        raise InputError("segment: a camera (fx, fy) is needed with depth")
    try:
        if any(isinstance(getattr(camera, k, 0.0), str | bytes | bool) for k in ("fx", "fy", "cx", "cy")):
            raise TypeError  # float() reads "615" as 615 and True as 1 in silence, as symfruit.Camera refuses (stop 43)
        fx, fy = float(camera.fx), float(camera.fy)
        cx, cy = float(getattr(camera, "cx", shape[1] / 2)), float(getattr(camera, "cy", shape[0] / 2))
    except (TypeError, ValueError, AttributeError):  # AttributeError: no camera at all (a path, a mapping)
        raise InputError(f"segment: camera must be a Camera with numbers fx, fy (cx, cy), got "
                         f"{type(camera).__name__}") from None  # fmt: skip
    if not (np.isfinite(fx) and np.isfinite(fy) and fx > 0 and fy > 0):
        raise InputError("segment: camera fx, fy must be positive")
    cx, cy = (cx if np.isfinite(cx) else shape[1] / 2), (cy if np.isfinite(cy) else shape[0] / 2)
    return _Depth(given), _Geometry(float(np.sqrt(fx * fy)), cy, cx)


def _usable(z: np.ndarray) -> np.ndarray:
    """(h, w) bool: depths positive and finite (False for NaN)."""
    valid = np.greater(z, 0.0)
    valid &= np.less(z, np.inf)
    return valid


class _Depth:
    """A depth image as float64 metres with NaN, infinite and non-positive depths 0, converted window by window
    when read (``depth[window]``, read-only and converted once per window; ``take(flat)``, a copy): the values of
    ``np.nan_to_num(z, nan=0, posinf=0, neginf=0)`` then ``np.maximum(z, 0)`` over a float64 copy of the whole
    image, to the bit (-0.0 becomes 0.0 there too). The segmenter reads some 170 small windows of a frame: a float64
    copy of a 1920x1080 image, 16 MB of fresh pages, cost more than all of them, and so did the validity of every
    pixel (two passes over the image, 2 ms at 1920x1080): each window's is worked out when it is read (the depth's
    own type keeps its order against 0 and infinity)."""

    def __init__(self, given: np.ndarray) -> None:
        self.given = given  # float, as handed over
        self.shape: tuple[int, int] = (int(given.shape[0]), int(given.shape[1]))
        self.read: dict[tuple[int | None, ...], np.ndarray] = {}  # the windows read so far, by their slices

    @classmethod
    def of(cls, z: np.ndarray) -> _Depth:
        """A float64 depth already cleaned (0 where invalid)."""
        return cls(z)

    def __getitem__(self, window: tuple[slice, slice]) -> np.ndarray:
        """The window's depths, read-only: a window read again (a region's window is read by its split, its merge
        tests, its hull and its skin; some 170 reads of 70 windows a 1920x1080 tree frame) is converted once."""
        a, b = window
        key = (a.start, a.stop, a.step, b.start, b.stop, b.step)
        z = self.read.get(key)
        if z is None:
            given = self.given[window]
            jit = compiled()
            rows, cols = a.indices(self.shape[0]), b.indices(self.shape[1])
            if jit is not None and given.ndim == 2 and given.dtype in _FLOATS and rows[2] > 0 and cols[2] > 0 and (
                    self.given.flags.c_contiguous):  # fmt: skip
                # read along the whole image's rows (:func:`symfruit.core._jit.depth_window_at`: the same values;
                # vectorised rows, about 1.5 times as fast as through the window's view; stop 44)
                z = jit.depth_window_at(self.given, rows, cols)
            elif jit is not None and given.ndim == 2 and given.dtype in _FLOATS:
                z = jit.depth_window(given)  # the same values in one pass (issue 19, nineteenth round)
            else:
                z = np.where(_usable(given), given.astype(np.float64), 0.0)  # a select: faster than a masked copy
            z.flags.writeable = False
            self.read[key] = z
        return z

    def take(self, flat: np.ndarray) -> np.ndarray:
        """The depths at flat (row-major) pixel indices."""
        given = np.asarray(self.given)
        if (jit := compiled()) is not None and given.dtype in _FLOATS and flat.ndim == 1:
            return jit.depth_at(given.ravel(), flat)  # the same values (issue 19, nineteenth round)
        z = given.ravel().take(flat)
        return np.where(_usable(z), z.astype(np.float64), 0.0)


#: The depth types :class:`_Depth`'s compiled reads take (others, if any, are read by numpy).
_FLOATS = (np.dtype(np.float32), np.dtype(np.float64))


def _pad(sl: Window, pad: int, shape: tuple[int, int]) -> Window:
    return (slice(max(sl[0].start - pad, 0), min(sl[0].stop + pad, shape[0])),
            slice(max(sl[1].start - pad, 0), min(sl[1].stop + pad, shape[1])))  # fmt: skip


@dataclass(frozen=True)
class _Geometry:
    """What the depth rules need of the camera: the focal length and principal point (pixels)."""

    focal: float
    cy: float
    cx: float


@dataclass
class _Piece:
    """A candidate fruit: its mask inside an image window, the region it came from, its hull area."""

    window: Window
    mask: np.ndarray
    source: int  # a bit set of the colour regions it came from
    hull: float = -1.0
    serial: int = -1  # a number of its own while pieces are merged
    vertices: tuple[np.ndarray | None] | None = None  # its hull's vertices, once worked out

    def __post_init__(self) -> None:
        self.area = int(self.mask.sum())

    def hull_vertices(self) -> np.ndarray | None:
        """:func:`_hull_vertices` of the mask, worked out once (a merge test, then the reported hull)."""
        if self.vertices is None:
            self.vertices = (_hull_vertices(self.mask),)
        return self.vertices[0]

    def hull_area(self) -> float:
        """:func:`_hull_area` of the mask, worked out when first asked for: only pieces near another need it."""
        if self.hull < 0:
            self.hull = _hull_area_of(self.hull_vertices(), self.mask)
        return self.hull


def _merge(
    pieces: list[_Piece],
    s: SegmentSettings,
    color: np.ndarray,
    weak: np.ndarray,
    depth: _Depth | None,
    geo: _Geometry,
    grown: _Grown | None = None,
) -> list[_Piece]:
    """Join pieces of one convex body (greedy, largest first): the hull of their union, less the green
    pixels in it that are neither piece (a stem, a leaf or the calyx lying across the fruit), exceeds
    their own hulls by at most ``merge_slack``; with depth, the smaller piece's points must also lie on
    the sphere of the larger (:func:`_same_surface`). Parts cut from one region (the same ``source``)
    were kept apart on purpose and are not joined again, except with ``round_fruit`` (stop 46): there a
    camera's softness and 4:2:0 chroma join the red on both sides of a thin leaf or twig across one apple into
    one region that the split cuts at the leaf (its cut sees neither the leaf's green nor the one sphere), and the
    merge's own tests (the green discounted, :func:`_two_extents`, the one sphere) decide, as they do for the
    pieces of two regions. With ``grown`` (:class:`_Grown`: the found fruit joined once grown to their skins) its
    tests of nearness, extent and depth take the place of :func:`_near_pieces`, :func:`_two_extents` and
    :func:`_same_surface`."""
    slack = s.merge_slack
    pieces = sorted(pieces, key=lambda p: -p.area)
    for k, piece in enumerate(pieces):
        piece.serial = k
    serial = len(pieces)
    apart: set[tuple[int, int]] = set()  # pairs already tested and not joined (a test's answer never changes)
    surfaces: dict[int, _Surface] = {}  # each piece's sphere fit and points, worked out once per piece, not per pair

    def two_fruit(a: _Piece, b: _Piece, vertices: np.ndarray | None, union: tuple[Window, np.ndarray]) -> bool:
        return _two_extents(a, b, vertices) if grown is None else grown.two(a, b, vertices, union)

    def one_surface(a: _Piece, b: _Piece) -> bool | None:
        assert depth is not None
        if grown is None:
            return _same_surface(a, b, depth, weak, geo, s, surfaces)
        return grown.same(a, b, weak, surfaces)

    merged = True
    while merged and len(pieces) > 1:
        merged = False
        near = _near_pieces(pieces, s.round_fruit) if grown is None else grown.near(pieces)  # those near each one
        for i in range(len(pieces)):
            for j in near(i):
                a, b = pieces[i], pieces[j]
                if (a.source & b.source and not s.round_fruit) or (a.serial, b.serial) in apart:
                    continue
                window, union = _union(a, b)
                vertices = _hull_vertices(union)
                if s.round_fruit and two_fruit(a, b, vertices, (window, union)):
                    apart.add((a.serial, b.serial))
                    continue
                hull = _hull_area_of(vertices, union)
                if hull > (1.0 + slack) * (a.hull_area() + b.hull_area()):
                    hull -= float(_green_in_hull(vertices, union, color[window]))
                if hull <= (1.0 + slack) * (a.hull_area() + b.hull_area()) and (
                    depth is None or one_surface(a, b) is not False
                ):
                    pieces[i] = _Piece(window, union, a.source | b.source, hull, serial, (vertices,))
                    serial += 1
                    del pieces[j]
                    merged = True
                    break
                apart.add((a.serial, b.serial))
            if merged:
                break
    return pieces


def _near_pieces(pieces: list[_Piece], round_fruit: bool = False) -> Callable[[int], list[int]]:
    """For each piece ``i``, the pieces ``j > i`` near it, in order (``near(i)``): their boxes closer than an occluder
    narrower than the smaller fruit (a gap of half the square root of the smaller area, at least 2 pixels). With
    ``round_fruit``, also closer than the gap two pieces of one round fruit may leave between them: the union of a
    fruit's pieces reaches at most :data:`ROUND_EXTENT` times the larger piece's extent (:func:`_two_extents`), so a
    leaf across the fruit may leave up to ``ROUND_EXTENT - 1`` of the larger box's longer side between them (a leaf
    across a small apple is wider than half the square root of either half's area; the merge's tests decide). Up to
    :data:`NEAR_TABLE` pieces all pairs are tested in one pass over an (n, n) table (issue 19, nineteenth round: the
    same values as the row-by-row test, which costs a dozen numpy calls a piece); more are tested row by row when
    asked for (a merge round stops at its first merge)."""
    box = np.array([[p.window[0].start, p.window[0].stop, p.window[1].start, p.window[1].stop] for p in pieces])
    area = np.array([p.area for p in pieces], dtype=np.float64)
    side = np.maximum(box[:, 1] - box[:, 0], box[:, 3] - box[:, 2]) if round_fruit else np.zeros(len(pieces), int)
    reach = ((ROUND_EXTENT - 1.0) * side).astype(np.int64)  # 0 but for round fruit
    if len(pieces) <= NEAR_TABLE:
        gap = np.maximum(2, (0.5 * np.sqrt(np.minimum(area[:, None], area[None, :]))).astype(np.int64))
        gap = np.maximum(gap, np.maximum(reach[:, None], reach[None, :]))
        a, b = box[:, None, :], box[None, :, :]
        table = ((a[..., 0] - gap < b[..., 1]) & (b[..., 0] - gap < a[..., 1])
                 & (a[..., 2] - gap < b[..., 3]) & (b[..., 2] - gap < a[..., 3]))  # fmt: skip
        # the pairs by one nonzero of the table (row-major: each row's columns ascending, as a row's flatnonzero gives
        # them), not one call a row (stop 41)
        rows: list[list[int]] = [[] for _ in range(len(pieces))]
        first, second = np.nonzero(np.triu(table, 1))
        for i, j in zip(first.tolist(), second.tolist(), strict=True):
            rows[i].append(j)
        return rows.__getitem__

    def near(i: int) -> list[int]:
        gap = np.maximum(2, (0.5 * np.sqrt(np.minimum(area[i], area[i + 1 :]))).astype(np.int64))
        gap = np.maximum(gap, np.maximum(reach[i], reach[i + 1 :]))
        rest = box[i + 1 :]
        found = ((box[i, 0] - gap < rest[:, 1]) & (rest[:, 0] - gap < box[i, 1])
                 & (box[i, 2] - gap < rest[:, 3]) & (rest[:, 2] - gap < box[i, 3]))  # fmt: skip
        return (np.flatnonzero(found) + i + 1).tolist()

    return near


#: The most pieces :func:`_near_pieces` tests in one table (a frame of noise has up to :data:`MAX_PIECES`).
NEAR_TABLE = 256


#: Round fruit: two pieces whose union reaches further than this times the larger piece alone are two fruit.
ROUND_EXTENT = 1.35


def _extent(vertices: np.ndarray | None, mask: np.ndarray) -> float:
    """The largest distance across a mask (between its hull's vertices, plus a pixel), in pixels."""
    if vertices is None:
        return float(np.sqrt(mask.sum()))
    if (jit := compiled()) is not None and vertices.ndim == 2 and vertices.dtype == np.float64:
        return float(np.sqrt(jit.widest_pair(vertices))) + 1.0  # the same largest square (stop 51)
    d = vertices[:, None, :] - vertices[None, :, :]
    return float(np.sqrt((d * d).sum(axis=2).max())) + 1.0


def _two_extents(a: _Piece, b: _Piece, union: np.ndarray | None) -> bool:
    """Whether two pieces of round fruit are two fruit by their extents: every piece of one round fruit lies
    within its outline, so the union reaches no further than the fruit is across, and the larger piece of a
    fruit seen past a leaf spans most of that; two whole fruit side by side reach as far as both together.
    The union reaching more than :data:`ROUND_EXTENT` times the larger piece's extent is two fruit (with
    depth or without: two apples beside each other outside the depth camera's view, where the convexity
    test alone joins them when one partly hides the other)."""
    if union is None:
        return False
    ea, eb = _extent(a.hull_vertices(), a.mask), _extent(b.hull_vertices(), b.mask)
    return _extent(union, a.mask) > ROUND_EXTENT * max(ea, eb)


@dataclass
class _Surface:
    """What :func:`_same_surface` needs of one piece, worked out when first asked for: its sphere fit (as the
    larger piece), its points (as the smaller one) and its depths."""

    piece: _Piece
    depth: _Depth
    weak: np.ndarray
    geo: _Geometry
    fit: tuple[tuple[np.ndarray, float] | None] | None = None
    points: np.ndarray | None = None
    depths: np.ndarray | None = None

    def origin(self) -> tuple[int, int]:
        return (self.piece.window[0].start, self.piece.window[1].start)

    def sphere(self) -> tuple[np.ndarray, float] | None:
        if self.fit is None:
            w = self.piece.window
            self.fit = (_sphere(self.piece.mask & self.weak[w], self.depth[w], self.geo, self.origin()),)
        return self.fit[0]

    def cloud(self) -> np.ndarray:
        if self.points is None:
            w = self.piece.window
            self.points = _points(self.piece.mask & self.weak[w], self.depth[w], self.geo, self.origin())
        return self.points

    def z(self) -> np.ndarray:
        if self.depths is None:
            w = self.piece.window
            z = self.depth[w][self.piece.mask & self.weak[w]]
            self.depths = z[z > 0]
        return self.depths


def _same_surface(
    a: _Piece,
    b: _Piece,
    depth: _Depth,
    weak: np.ndarray,
    geo: _Geometry,
    s: SegmentSettings,
    surfaces: dict[int, _Surface] | None = None,
) -> bool | None:
    """Whether the smaller piece's depth points lie on the sphere fitted to the larger one (the median
    distance off it at most ``sphere_apart`` times its radius, and at most a depth step ``depth_jump``; with
    ``round_fruit``, of its points that may be a fruit's surface there, :func:`_near_surface`). Without
    a fit: not when the two pieces' median depths lie further apart than the largest fruit is across
    (``round_max_diameter``: two fruit, one behind the other), else None (nothing to tell)."""
    big, small = (a, b) if a.area >= b.area else (b, a)
    if surfaces is None:
        big_s, small_s = _Surface(big, depth, weak, geo), _Surface(small, depth, weak, geo)
    else:  # by serial: one merge's pieces, one depth, one weak mask
        big_s, small_s = (surfaces.setdefault(x.serial, _Surface(x, depth, weak, geo)) for x in (big, small))
    fit = big_s.sphere()
    p = small_s.cloud()
    if fit is not None and s.round_fruit:
        p = _near_surface(p, fit, s)
    if fit is None or len(p) < 20:
        zs = [big_s.z(), small_s.z()]
        if all(len(z) >= SAME_SURFACE_POINTS for z in zs) and abs(median(zs[0]) - median(zs[1])) > s.round_max_diameter:
            return False
        return None
    off = np.abs(row_norms(p - fit[0]) - fit[1])
    return bool(median(off) <= min(s.sphere_apart * fit[1], s.depth_jump))  # off it by a depth step: not one


def _near_surface(p: np.ndarray, fit: tuple[np.ndarray, float], s: SegmentSettings) -> np.ndarray:
    """The points (n, 3) of a round fruit's piece that may be a fruit's surface near the sphere ``fit`` (centre,
    radius): those whose depth lies within the sphere's depth span (its centre's depth, plus or minus its radius)
    widened by the largest fruit's diameter (``round_max_diameter``). A piece along a fruit's silhouette, or one cut
    off by a leaf across the fruit, carries besides its own surface the depth of what lies far in front (the leaf:
    the depth camera sees it from a few centimetres beside the colour camera) and far behind (mixed and
    misregistered pixels on the rim); those are no fruit's surface there and tell nothing of whether the piece lies
    on the sphere, yet can be most of a thin piece's points and carry their median off it. A second fruit beside or
    behind the first keeps its points (within a fruit's diameter), off the sphere by about its radius."""
    reach = fit[1] + s.round_max_diameter
    return p[np.abs(p[:, 2] - fit[0][2]) <= reach]


#: Depth points each piece needs for :func:`_same_surface` to compare their median depths without a sphere.
SAME_SURFACE_POINTS = 10


def _union(a: _Piece, b: _Piece) -> tuple[Window, np.ndarray]:
    sa, sb = a.window, b.window
    r0, r1 = min(sa[0].start, sb[0].start), max(sa[0].stop, sb[0].stop)
    c0, c1 = min(sa[1].start, sb[1].start), max(sa[1].stop, sb[1].stop)
    out = np.zeros((r1 - r0, c1 - c0), bool)
    out[sa[0].start - r0 : sa[0].stop - r0, sa[1].start - c0 : sa[1].stop - c0] |= a.mask
    out[sb[0].start - r0 : sb[0].stop - r0, sb[1].start - c0 : sb[1].stop - c0] |= b.mask
    return (slice(r0, r1), slice(c0, c1)), out


def _split(
    region: np.ndarray,
    depth: np.ndarray | None,
    s: SegmentSettings,
    geo: _Geometry,
    origin: tuple[int, int],
    min_area: float,
) -> list[np.ndarray]:
    """Cut a region into fruit (see the module docstring): at waists of its distance transform (the depth
    steps and creases taken as part of its outline), keeping the cuts that evidence backs. Where numba is, with depth
    and no closing, the steps up to the centres in two compiled calls (:func:`symfruit.core._jit.split_seen` and
    :func:`symfruit.core._jit.split_centres`: the holes filled, the median depth, the depth edges, the carved region's
    distance map and its centres; the same values as the calls below; issue 19, twentieth round)."""
    jit = compiled()
    if (jit is not None and depth is not None and not s.close_px and s.split in ("depth", "both")
            and region.ndim == 2 and region.dtype == bool and depth.dtype == np.float64):  # fmt: skip
        region, n_seen, zm = jit.split_seen(region, depth)
        if n_seen >= 20:
            zm = float(zm)
            least = max(0.25 * geo.focal * s.min_diameter / zm, 2.0)
            weights, symmetric = _gaussian_weights(float(s.crease_sigma)) if s.crease_sigma > 0 else _IDENTITY
            limit = -s.crease_curvature * (zm / geo.focal) ** 2
            edges, found = jit.split_centres(region, depth, weights, symmetric, limit, float(s.depth_jump),
                                             int(least), float(least), CANDIDATE_WAIST, float(s.waist),
                                             MAX_WAIST_TESTS)  # fmt: skip
            centres = [(int(a), int(b), float(r), bool(f)) for a, b, r, f in found.tolist()]
            return _cut(region, depth, s, geo, origin, centres, edges, True)
    region = fill_holes(region)
    if s.close_px:
        r = s.close_px
        padded = np.pad(region, r + 1)
        region = ndimage.binary_closing(padded, structure=_disc(r))[r + 1 : -r - 1, r + 1 : -r - 1] | region
    seen = None if depth is None else region & (depth > 0)  # the region's pixels with depth
    use_depth = seen is not None and s.split in ("depth", "both") and int(seen.sum()) >= 20
    if s.split == "none" or (s.split == "depth" and not use_depth):
        return [region]
    carved, edges = region, None
    # the smallest fruit worth cutting off: fruit-sized (with depth: at its depth, and half of it may be
    # hidden behind the fruit in front or a leaf)
    least = np.sqrt(min_area / np.pi)
    if use_depth and depth is not None and seen is not None:
        zm = float(median(depth[seen]))
        edges = _depth_edges(region, depth, seen, zm, s, geo.focal)
        carved = fill_holes(region & ~edges)
        least = 0.25 * geo.focal * s.min_diameter / zm
    # with depth, every saddle of the distance transform is tried: the depth surface decides
    centres = _centres(
        carved, max(least, 2.0), s.waist, CANDIDATE_WAIST if use_depth else s.waist, coarse=not use_depth
    )
    return _cut(region, depth, s, geo, origin, centres, edges, use_depth)


def _cut(
    region: np.ndarray,
    depth: np.ndarray | None,
    s: SegmentSettings,
    geo: _Geometry,
    origin: tuple[int, int],
    centres: list[tuple[int, int, float, bool]],
    edges: np.ndarray | None,
    use_depth: bool,
) -> list[np.ndarray]:
    """:func:`_split`'s cut of the (filled) ``region`` among its ``centres``: the cells, the cuts evidence backs, the
    cut moved onto the depth ``edges`` (None: without depth)."""
    if len(centres) < 2:
        return [region]
    cells = _cells(region, [(a, b, r) for a, b, r, _ in centres], CANDIDATE_WAIST if use_depth else s.waist)
    if len(cells) < 2:
        return [region]
    firm = [f for *_, f in centres]
    fits: dict[int, tuple[np.ndarray, float] | None] = {}

    def sphere(i: int) -> tuple[np.ndarray, float] | None:
        """Cell ``i``'s sphere, fitted when a test first asks (most cuts are settled by the depth edges or have no
        neighbour: 1 pair test for 6 cells on the benchmark frame, 15 for 69 on tree frames 0-2; stop 46)."""
        if i not in fits:
            fits[i] = _sphere(cells[i], depth, geo, origin) if use_depth and depth is not None else None
        return fits[i]

    parts = _supported(cells, firm, sphere, edges, s, by_shape=s.split in ("watershed", "both"))
    return parts if edges is None or len(parts) < 2 else _follow_edges(parts, region, edges)


def _follow_edges(parts: list[np.ndarray], region: np.ndarray, edges: np.ndarray) -> list[np.ndarray]:
    """Move the cut between fruit onto the depth steps and creases where they run: every piece of the region
    that the edges enclose goes whole to the fruit holding most of it (when one holds at least
    :data:`EDGE_PURITY` of it), and the edge pixels to the nearest piece. A front fruit's rim, not a straight
    line through the one behind, then separates them. Where numba is, in one call
    (:func:`symfruit.core._jit.follow_edges`: the same labels, counts, seeds and nearest seeds, so the same parts;
    stop 46)."""
    if (jit := compiled()) is not None and region.dtype == edges.dtype == bool and region.ndim == edges.ndim == 2:
        owner = np.zeros(region.shape, np.int64)
        for k, part in enumerate(parts, 1):
            owner[part] = k
        grown, moved = jit.follow_edges(region, edges, owner, len(parts), EDGE_PURITY)
        return [m for k in range(1, len(parts) + 1) if (m := grown == k).any()] if moved else parts
    pieces, n = _label(region & ~edges)
    if n < 2:
        return parts
    owner = np.zeros(region.shape, np.int64)
    for k, part in enumerate(parts, 1):
        owner[part] = k
    # each (piece, owner) pair's pixels, counted by one bincount of the pairs' numbers (np.add.at's counts, several
    # times faster; issue 19, eighteenth round)
    counts = np.bincount(pieces.ravel() * (len(parts) + 1) + owner.ravel(), minlength=(n + 1) * (len(parts) + 1))
    counts = counts.reshape(n + 1, len(parts) + 1)
    major = counts[:, 1:].argmax(axis=1) + 1
    total = counts[:, 1:].sum(axis=1)
    pure = counts[np.arange(n + 1), major] >= EDGE_PURITY * np.maximum(total, 1)
    seeds = np.where(pure[pieces], major[pieces], owner)
    seeds[(pieces == 0) | ~region] = 0  # edge pixels and the outside: to the nearest piece
    if not seeds.any():
        return parts
    grown = np.where(region, np.take(seeds.ravel(), nearest_index(seeds == 0)), 0)
    return [m for k in range(1, len(parts) + 1) if (m := grown == k).any()]


#: Share of an edge-enclosed piece that one fruit must already hold for the whole piece to go to it.
EDGE_PURITY = 0.9


#: With depth, a peak of the distance transform is a candidate fruit centre when any path to a larger peak
#: dips below this share of its radius; whether it is a fruit is then decided by the depth surface.
CANDIDATE_WAIST = 0.9


def _centres(
    region: np.ndarray, least: float, waist: float, loose: float, *, coarse: bool = True
) -> list[tuple[int, int, float, bool]]:
    """Fruit centres ``(row, col, inscribed radius, firm)``: peaks of the distance transform, largest first,
    each outside the inscribed discs of the larger ones and separated from each by a waist.

    A convex body's distance transform is concave: it has a single peak, and every set of its points
    deeper than some radius is connected. A peak of radius ``r`` is another fruit when it lies in a
    different connected component of the points deeper than ``loose * r`` than every larger centre;
    ``firm`` when it is so even at ``waist * r`` (the region narrows to a ``waist`` between them).
    With ``coarse``, fruit-sized regions are searched on every other pixel (four times fewer).
    """
    if coarse and least >= 8:  # a fruit at least 16 pixels across is found as well on every other pixel
        step = 2
        found = _centres(region[::step, ::step], least / step, waist, loose, coarse=False)
        return [(a * step, b * step, r * step, f) for a, b, r, f in found if region[a * step, b * step]]
    edt = distance_transform(_pad1(region))[1:-1, 1:-1]  # scipy's map, compiled where numba is
    if float(edt.max()) < least:
        return []
    if (jit := compiled()) is not None:  # the peaks and the walk below in one call, the same centres
        found = jit.centre_search(edt, int(least), float(least), float(loose), float(waist), MAX_WAIST_TESTS)
        return [(int(a), int(b), float(r), bool(f)) for a, b, r, f in found.tolist()]  # (issue 19, eighteenth round)
    # peaks: the deepest points within the smallest fruit's radius (two fruit's centres lie farther apart)
    peaks = (edt >= ndimage.maximum_filter(edt, size=2 * int(least) + 1)) & (edt >= least)
    pr, pc = np.nonzero(peaks)
    order = np.argsort(-edt[pr, pc], kind="stable")
    centres: list[tuple[int, int, float, bool]] = []
    budget = [MAX_WAIST_TESTS]
    for i in order[:400]:
        p, q, r = int(pr[i]), int(pc[i]), float(edt[pr[i], pc[i]])
        if any((p - a) ** 2 + (q - b) ** 2 <= ra * ra for a, b, ra, _ in centres):
            continue  # inside a larger fruit's inscribed disc
        firm = True
        if centres:
            if not _separate(edt, (p, q), centres, loose * r, budget):
                continue  # joined to a larger peak without a waist: the same fruit
            if waist < loose:
                firm = _separate(edt, (p, q), centres, waist * r, budget)
        centres.append((p, q, r, firm))
        if len(centres) >= 8 or budget[0] <= 0:
            break
    return centres


#: Most connected-component labellings one region's waist tests may take (a hand or a vine with many
#: bumps is not a cluster of fruit; this bounds the time such a region costs).
MAX_WAIST_TESTS = 16


def _on_path(edt: np.ndarray, p: tuple[int, int], others: list[tuple[int, int]], t: float) -> bool:
    """Whether a straight path from ``p`` to one of ``others`` stays deeper than ``t``."""
    for a, b in others:
        n = int(max(abs(a - p[0]), abs(b - p[1]))) + 1
        rows = np.rint(np.linspace(p[0], a, n + 1)).astype(np.int64)
        cols = np.rint(np.linspace(p[1], b, n + 1)).astype(np.int64)
        if float(edt[rows, cols].min()) > t:
            return True
    return False


def _supported(
    cells: list[np.ndarray],
    firm: list[bool],
    spheres: Callable[[int], tuple[np.ndarray, float] | None],
    edges: np.ndarray | None,
    s: SegmentSettings,
    *,
    by_shape: bool = True,
) -> list[np.ndarray]:
    """Join again the neighbouring cells whose cut no evidence of two bodies backs. The evidence is

    * with depth: depth steps or creases along most of the cut, or two surfaces: the spheres that fit
      the two cells' depth points lie apart, their centres farther than ``sphere_apart`` times the sum of
      their radii (one fruit cut in two gives two fits about one centre; two touching fruit, two spheres
      touching: centres a sum of radii apart);
    * shape (``by_shape``), when a cell lacks a sphere: a waist between their centres (``firm``) and
      convexity defects: the convex hull of the two cells exceeds their own hulls by more than
      ``merge_slack`` (they are not one convex body).
    """
    n = len(cells)
    # with the edges, where numba is, each pair's cut and its edge test in one call at the cut's pixels alone
    # (:func:`symfruit.core._jit.near_edge_cut`: the same answers as the masks below; stop 46)
    jit = compiled() if edges is not None and edges.dtype == bool and all(c.dtype == bool for c in cells) else None
    grown = [] if jit is not None else [_dilate(c, square=True) for c in cells]
    near_edges = None if edges is None or jit is not None else _dilate(_dilate(edges))
    owner = list(range(n))
    hulls: dict[int, float] = {}  # a cell's hull area, worked out when a shape test first asks (stop 46)

    def hull(i: int) -> float:
        if i not in hulls:
            hulls[i] = _hull_area(cells[i])
        return hulls[i]

    def root(i: int) -> int:
        while owner[i] != i:
            i = owner[i]
        return i

    for i in range(n):
        for j in range(i + 1, n):
            if jit is not None:
                along = jit.near_edge_cut(cells[i], cells[j], edges)
                if along != 0:
                    continue  # no cut (-1), or a depth step or crease runs along it (1)
            else:
                cut = (cells[i] & grown[j]) | (cells[j] & grown[i])
                if not cut.any():
                    continue
                if near_edges is not None and near_edges[cut].mean() >= 0.5:
                    continue  # a depth step or crease runs along the cut
            two = _two_spheres(spheres(i), spheres(j), s)
            if two:
                continue  # two surfaces
            if (
                two is None
                and by_shape
                and firm[j]
                and _hull_area(cells[i] | cells[j]) > (1 + s.merge_slack) * (hull(i) + hull(j))
            ):
                continue  # a waist, and concave where they meet: two convex bodies touching
            owner[root(j)] = root(i)
    groups: dict[int, np.ndarray] = {}
    for i in range(n):
        r = root(i)
        groups[r] = groups[r] | cells[i] if r in groups else cells[i]
    return list(groups.values())


def _dilate(mask: np.ndarray, *, square: bool = False) -> np.ndarray:
    """(h, w) bool: ``ndimage.binary_dilation(mask)`` by the 4-neighbourhood (``square``: the 8-neighbourhood,
    ``structure=np.ones((3, 3))``), from shifted views of the padded mask (scipy's general structuring element
    costs several times more on these small windows)."""
    p = _pad1(mask)
    if square:
        rows = p[:-2] | p[1:-1] | p[2:]
        return rows[:, :-2] | rows[:, 1:-1] | rows[:, 2:]
    return p[1:-1, 1:-1] | p[:-2, 1:-1] | p[2:, 1:-1] | p[1:-1, :-2] | p[1:-1, 2:]


def _pad1(mask: np.ndarray) -> np.ndarray:
    """``np.pad(mask, 1)`` of a bool image, written out (np.pad's own work costs more than the copy on these small
    windows)."""
    p = np.zeros((mask.shape[0] + 2, mask.shape[1] + 2), bool)
    p[1:-1, 1:-1] = mask
    return p


def _points(
    mask: np.ndarray, depth: np.ndarray, geo: _Geometry, origin: tuple[int, int], most: int = 1500
) -> np.ndarray:
    """(n, 3) camera-frame points (metres) of the mask's pixels with depth, in a window at ``origin``; at
    most ``most`` of them, evenly picked."""
    if (jit := compiled()) is not None and mask.ndim == depth.ndim == 2 and mask.dtype == bool:  # the same points
        return jit.window_points(mask, depth, int(origin[0]), int(origin[1]), float(geo.cx), float(geo.cy),
                                 float(geo.focal), int(most))  # fmt: skip
    rows, cols = np.nonzero(mask & (depth > 0))
    if len(rows) > most:
        pick = np.linspace(0, len(rows) - 1, most).astype(np.int64)
        rows, cols = rows[pick], cols[pick]
    z = depth[rows, cols]
    return np.stack(
        ((cols + origin[1] - geo.cx) * z / geo.focal, (rows + origin[0] - geo.cy) * z / geo.focal, z), axis=1
    )


def _two_spheres(
    a: tuple[np.ndarray, float] | None, b: tuple[np.ndarray, float] | None, s: SegmentSettings
) -> bool | None:
    """Whether two fitted spheres are two fruit (centres more than ``sphere_apart`` of the sum of their
    radii apart) or one; None when either fit is missing."""
    if a is None or b is None:
        return None
    return bool(np.linalg.norm(a[0] - b[0]) > s.sphere_apart * (a[1] + b[1]))


def _sphere(
    mask: np.ndarray, depth: np.ndarray, geo: _Geometry, origin: tuple[int, int], most: int = 1500
) -> tuple[np.ndarray, float] | None:
    """The sphere (centre in the camera frame, metres; radius) that best fits the depth points of a mask in
    the window at ``origin`` (algebraic least squares, once more without the points far off it); None
    with fewer than 20 points or when the fit is not a fruit-like cap (its radius off the points' own
    spread by more than 4x either way). Where numba is, one compiled call gives it
    (:func:`symfruit.core._jit.sphere_fit`: the same points, its least squares by Householder reflections instead of
    LAPACK's SVD, so the same sphere to rounding; issue 19, eighteenth round: 30 against 300 us a fit), and the
    numpy code below (:func:`_sphere_lstsq`) where the kernel leaves a nearly singular system to ``lstsq``."""
    if (jit := compiled()) is not None and mask.ndim == depth.ndim == 2 and mask.dtype == bool:
        fit = np.empty(4)
        found = jit.sphere_fit(mask, depth, int(origin[0]), int(origin[1]), float(geo.cx), float(geo.cy),
                               float(geo.focal), int(most), fit)  # fmt: skip
        if found >= 0:
            return (fit[:3], float(fit[3])) if found else None
    return _sphere_lstsq(mask, depth, geo, origin, most)


def _sphere_lstsq(
    mask: np.ndarray, depth: np.ndarray, geo: _Geometry, origin: tuple[int, int], most: int = 1500
) -> tuple[np.ndarray, float] | None:
    """:func:`_sphere` by numpy's ``lstsq`` (the compiled kernel's twin)."""
    if (jit := compiled()) is not None and mask.ndim == depth.ndim == 2 and mask.dtype == bool:
        # the same points and spread (:func:`symfruit.core._jit.sphere_points`; issue 19, seventeenth round)
        p, spread = jit.sphere_points(mask, depth, int(origin[0]), int(origin[1]), float(geo.cx), float(geo.cy),
                                      float(geo.focal), int(most))  # fmt: skip
    else:
        p = _points(mask, depth, geo, origin, most)
        if len(p) < 20:
            return None
        z = p[:, 2]
        spread = float(np.sqrt(np.var(p[:, 0]) + np.var(p[:, 1]))) * np.sqrt(2.0)  # a disc's radius from its spread
        p = p[np.abs(z - median(z)) <= 2.0 * spread]  # a fruit's surface spans about its radius in depth
    centre, radius = np.zeros(3), 0.0
    for _ in range(2):  # fit, drop the points far off the sphere (mixed pixels at the outline), fit again
        if len(p) < 20:
            return None
        a = np.concatenate((2.0 * p, np.ones((len(p), 1))), axis=1)  # np.c_ costs 5-10 us a call
        # |p|^2 term by term: numpy sums a 3-long axis left to right, the same values without its slow reduction
        sol, *_ = np.linalg.lstsq(a, p[:, 0] * p[:, 0] + p[:, 1] * p[:, 1] + p[:, 2] * p[:, 2], rcond=None)
        centre = sol[:3]
        radius = float(np.sqrt(max(float(sol[3] + centre @ centre), 0.0)))
        if (jit := compiled()) is not None and np.isfinite(centre).all() and np.isfinite(radius):  # the same points
            p = jit.sphere_inliers(p, np.ascontiguousarray(centre), radius)
            continue
        res = np.abs(row_norms(p - centre) - radius)
        p = p[res <= max(3.0 * float(median(res)) * 1.4826, 1e-4)]
    if not (np.isfinite(radius) and 0.25 * spread <= radius <= 4.0 * spread):
        return None
    return centre, radius


def _disc(r: int) -> np.ndarray:
    yy, xx = np.mgrid[-r : r + 1, -r : r + 1]
    return xx * xx + yy * yy <= r * r


def _separate(
    edt: np.ndarray, p: tuple[int, int], centres: list[tuple[int, int, float, bool]], t: float, budget: list[int]
) -> bool:
    """Whether ``p`` lies in another connected component of ``edt > t`` than every centre (a straight path
    that stays above ``t`` joins them without labelling the window; ``budget`` counts the labellings
    left: with none left, ``p`` is taken as joined)."""
    if _on_path(edt, p, [(a, b) for a, b, _, _ in centres], t):
        return False
    if budget[0] <= 0:
        return False
    budget[0] -= 1
    above = edt > t
    if (jit := compiled()) is not None:  # p's component alone, walked (:func:`symfruit.core._jit.flood`)
        if not above[p]:  # labelled 0 below: another component than every centre above t
            return all(bool(above[a, b]) for a, b, _, _ in centres)
        seed = np.zeros(above.shape, bool)
        seed[p] = True
        reached = jit.flood(above, seed)
        return not any(reached[a, b] for a, b, _, _ in centres)
    deep = ndimage.label(above)[0]
    return all(deep[a, b] != deep[p] for a, b, _, _ in centres)


def _cells(region: np.ndarray, centres: list[tuple[int, int, float]], loose: float) -> list[np.ndarray]:
    """The region cut among fruit centres: each centre's core (the points around it deeper than ``loose``
    times the smallest centre's radius, shared out by power distance ``|x - c|^2 - r^2`` where cores
    touch) and every other pixel to the nearest core, so two fruit meet at the waist between them. Where numba is, the
    cells' map in one compiled call (:func:`symfruit.core._jit.cells`: the same cells; issue 19, eighteenth round)."""
    if (jit := compiled()) is not None and region.ndim == 2 and region.dtype == bool:
        cells = jit.cells(region, np.array(centres, dtype=np.float64).reshape(-1, 3), float(loose))
        return [m for k in range(1, len(centres) + 1) if (m := cells == k).any()]
    edt = distance_transform(_pad1(region))[1:-1, 1:-1]  # scipy's map, compiled where numba is
    cen = np.array(centres, dtype=np.float64)
    deep, _ = _label(edt > loose * float(cen[:, 2].min()))
    rows, cols = np.nonzero(deep)
    power = (rows[:, None] - cen[None, :, 0]) ** 2 + (cols[:, None] - cen[None, :, 1]) ** 2 - cen[None, :, 2] ** 2
    near = np.argmin(power, axis=1)
    at = deep[cen[:, 0].astype(int), cen[:, 1].astype(int)]
    keep = deep[rows, cols] == at[near]  # in the deep component of the centre it is nearest to
    cores = np.zeros(region.shape, np.int32)
    cores[rows[keep], cols[keep]] = near[keep] + 1
    cores[cen[:, 0].astype(int), cen[:, 1].astype(int)] = np.arange(1, len(cen) + 1)
    cells = np.where(region, np.take(cores.ravel(), nearest_index(cores == 0)), 0)
    return [m for k in range(1, len(centres) + 1) if (m := cells == k).any()]


def _depth_edges(
    region: np.ndarray, depth: np.ndarray, seen: np.ndarray, zm: float, s: SegmentSettings, focal: float
) -> np.ndarray:
    """Pixels of the region on a depth step (larger than ``depth_jump`` between neighbours) or on a concave
    crease of the depth surface: where one fruit ends and another begins. ``seen``: the region's pixels with depth
    (``region & (depth > 0)``), ``zm`` their median depth. Where numba is and 20 or more pixels have depth, the creases
    and steps in one compiled call (:func:`symfruit.core._jit.depth_edges`: the same pixels; issue 19, eighteenth
    round)."""
    if (jit := compiled()) is not None and seen.sum() >= 20:
        filled = np.take(np.ascontiguousarray(depth).ravel(), nearest_index(~seen))
        weights, symmetric = _gaussian_weights(float(s.crease_sigma)) if s.crease_sigma > 0 else _IDENTITY
        limit = -s.crease_curvature * (zm / focal) ** 2
        return jit.depth_edges(filled, weights, symmetric, limit, region, depth, seen, float(s.depth_jump))
    z = np.where(seen, depth, np.nan)
    return (_creases(region, depth, seen, zm, s, focal) | _steps(z, s.depth_jump)) & region


def _steps(z: np.ndarray, jump: float) -> np.ndarray:
    """(h, w) bool: pixels whose depth differs from a 4-neighbour's by more than ``jump`` (NaN: no step). The
    neighbours' differences by slices (``np.diff``'s values, without its call's overhead)."""
    edge = np.zeros(z.shape, bool)
    step = np.abs(z[1:] - z[:-1]) > jump  # NaN compares False: no step
    edge[:-1] |= step
    edge[1:] |= step
    step = np.abs(z[:, 1:] - z[:, :-1]) > jump
    edge[:, :-1] |= step
    edge[:, 1:] |= step
    return edge


def _creases(
    region: np.ndarray, depth: np.ndarray, valid: np.ndarray, zm: float, s: SegmentSettings, focal: float
) -> np.ndarray:
    """Concave creases of the depth surface: where two convex fruit meet, depth peaks across the seam. ``valid``:
    the region's pixels with depth, ``zm`` their median depth."""
    if valid.sum() < 20:
        return np.zeros(region.shape, bool)
    filled = np.take(np.ascontiguousarray(depth).ravel(), nearest_index(~valid))
    if (jit := compiled()) is not None:  # the same pixels (:func:`symfruit.core._jit.creases`; seventeenth round)
        weights, symmetric = _gaussian_weights(float(s.crease_sigma)) if s.crease_sigma > 0 else _IDENTITY
        return jit.creases(filled, weights, symmetric, region, -s.crease_curvature * (zm / focal) ** 2)
    smooth = _gaussian(filled, s.crease_sigma) if s.crease_sigma > 0 else filled
    lap = ndimage.correlate1d(smooth, _SECOND, 0)  # ndimage.laplace's sum, without its call's overhead
    lap += ndimage.correlate1d(smooth, _SECOND, 1)
    return region & (lap < -s.crease_curvature * (zm / focal) ** 2)


#: The second difference that :func:`scipy.ndimage.laplace` takes along each axis.
_SECOND = np.array([1.0, -2.0, 1.0])


def _gaussian(image: np.ndarray, sigma: float) -> np.ndarray:
    """``ndimage.gaussian_filter(image, sigma)`` of a float64 image, the same values: its weights worked out once per
    ``sigma`` (:func:`_gaussian_weights`), not on every call (a polynomial's set-up and evaluation, some 40 us a call
    on these small windows), then the two passes it makes, rows then columns, the second in place."""
    weights = _gaussian_weights(float(sigma))[0]
    out = ndimage.correlate1d(image, weights, 0)
    return ndimage.correlate1d(out, weights, 1, output=out)


#: Weights that leave a line as it is (``crease_sigma`` 0: no smoothing), symmetric.
_IDENTITY = (np.ones(1), True)


def _largest_area(mask: np.ndarray, depth: np.ndarray, s: SegmentSettings, focal: float, z_typical: float) -> float:
    """Area (pixels) of the largest round fruit's disc (``round_max_diameter``) at the mask's median depth
    (``z_typical`` where none of its pixels has depth)."""
    if (jit := compiled()) is not None and mask.dtype == bool and depth.dtype == np.float64 and mask.ndim == 2:
        _, valid, zm = jit.masked_median(mask, depth)  # the same median in one call (issue 19, nineteenth round)
        zr = float(zm) if valid else z_typical
        return float(np.pi / 4 * (focal * s.round_max_diameter / zr) ** 2)
    return _largest_disc(depth[mask & (depth > 0)], s, focal, z_typical)


def _largest_disc(z: np.ndarray, s: SegmentSettings, focal: float, z_typical: float) -> float:
    """:func:`_largest_area` at the median of the depths ``z`` (all positive; ``z_typical`` when there are none)."""
    zr = float(median(z)) if len(z) else z_typical
    return float(np.pi / 4 * (focal * s.round_max_diameter / zr) ** 2)


def _ripe_cores(
    region: np.ndarray, color: np.ndarray, depth: np.ndarray, s: SegmentSettings, focal: float, z_typical: float
) -> list[np.ndarray]:
    """What of a weakly red region (``region`` in a window of ``color`` and ``depth``) may hold round fruit.

    One no larger than the largest fruit (a disc of ``round_max_diameter`` at its median depth, at
    ``z_typical`` without any) is kept whole when its median redness reaches ``ripe_median``, else dropped.
    One larger is not one fruit: brown bark, a twig or a shaded leaf joins a red fruit through weakly red
    pixels. It is taken as its cores, the pieces of its pixels whose redness averaged over
    :data:`CORE_SMOOTH_PX` pixels reaches ``ripe_median``, each at least the least fruit's disc
    (``min_diameter``); the fruit's skin around them is found again later (the hull, :func:`_round_skin`)."""
    largest = _largest_area(region, depth, s, focal, z_typical)
    if region.sum() <= largest:
        # one fruit at most: ripe when red over most of it (the test every fruit passes at the end, made
        # before the region is split and merged: a twig or bark never costs the work on a fruit); the redness
        # of its own pixels alone (per pixel, in the same order: the values of the window's at them)
        return [region] if median(redness(color[region])) >= s.ripe_median else []
    # redness averaged over a few pixels: bark of redness about ripe_median has single pixels above it; where numba
    # is, in one call (:func:`symfruit.core._jit.ripe_core`: the same pixels; stop 58, speed58)
    if (jit := compiled()) is not None and color.dtype == np.uint8 and color.ndim == 3 and region.dtype == bool:
        core = jit.ripe_core(color, region, CORE_SMOOTH_PX, np.float32(s.ripe_median))
    else:
        core = region & (ndimage.uniform_filter(redness(color), CORE_SMOOTH_PX) >= s.ripe_median)
    lab, n = _label(core, eight=True)
    sizes = np.bincount(lab.ravel(), minlength=n + 1)
    keep = sizes >= largest * (s.min_diameter / s.round_max_diameter) ** 2  # the least fruit's disc
    keep[0] = False
    return [lab == k for k in np.flatnonzero(keep)]


def _one_fruit(
    first: np.ndarray,
    sizes: np.ndarray,
    depth: np.ndarray,
    red: np.ndarray,
    s: SegmentSettings,
    focal: float,
    z_typical: float,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_ripe_cores`' first test on regions, from their pixels alone (no window, no mask): which are no larger
    than the largest fruit's disc at their median depth (one fruit at most), and of those which are ripe (their median
    redness reaches ``ripe_median``; :func:`_ripe_cores` keeps them whole and drops the rest). ``depth`` and ``red``:
    the regions' pixels' depths (0: none) and rednesses, region by region, region ``i``'s from ``first[i]`` to
    ``first[i + 1]``; ``sizes``: their pixel counts. Returns two (n,) bool."""
    one, ripe = np.zeros(len(sizes), bool), np.zeros(len(sizes), bool)
    if (jit := compiled()) is not None and depth.dtype == np.float64 and red.dtype == np.float32:
        # every region's medians in one compiled call (:func:`symfruit.core._jit.region_medians`: the same values),
        # the tests as below (issue 19, nineteenth round)
        zmed, nz, rmed = jit.region_medians(np.ascontiguousarray(first, np.int64), depth, red)
        for i, (size, zr, valid) in enumerate(zip(sizes.tolist(), zmed.tolist(), nz.tolist(), strict=True)):
            if size <= float(np.pi / 4 * (focal * s.round_max_diameter / (zr if valid else z_typical)) ** 2):
                one[i] = True
                ripe[i] = rmed[i] >= s.ripe_median  # a float32 against the setting, as numpy compares them
        return one, ripe
    for i, size in enumerate(sizes.tolist()):
        z = depth[first[i] : first[i + 1]]
        if size <= _largest_disc(z[z > 0], s, focal, z_typical):
            one[i] = True
            ripe[i] = median(red[first[i] : first[i + 1]]) >= s.ripe_median
    return one, ripe


#: Width (pixels) of the box over which a ripe-red core's redness is averaged (the colour noise of one
#: pixel: brown bark whose mean redness lies just below ``ripe_median`` has single pixels above it).
CORE_SMOOTH_PX = 5


def _round_skin(
    sl: Window,
    hull: np.ndarray,
    depth: _Depth,
    color: np.ndarray,
    geo: _Geometry,
    s: SegmentSettings,
    owner: np.ndarray,
    k: int,
) -> tuple[Window, np.ndarray]:
    """The rest of a round fruit's visible skin around its red part (``hull`` in window ``sl``): the pixels
    within :data:`ROUND_REACH` times the part's own radius of its centre, or the largest fruit's diameter
    (``round_max_diameter`` at the part's median depth) where that is farther (stop 46), reached from it without
    crossing a depth step (half ``depth_jump`` between neighbours), lie within the part's radius plus
    ``depth_jump`` of its median depth, and are neither leaf green (:func:`_leaf`) nor another fruit's
    (``owner``, whole image: red pixels of piece ``k`` or of none). The growth starts from the part's pixels
    within ``depth_jump`` of its median depth (its hull's rim may lie on what is behind it). A bicoloured
    apple's yellow or yellow-green side joins its red blush; a leaf in front or behind, beyond a depth step,
    does not. When what is reached exceeds the largest fruit's disc (``round_max_diameter``) it is not one
    fruit's skin (bark or a branch at the fruit's depth joined it) and the part is kept as it was. With
    ``ground_colour``, a red part that is a blush along a fruit's rim carrying the depth of what lies behind grows
    from the depth of the ground colour beside it (:func:`_blush_rim`). Returns the grown window and mask."""
    jit = compiled()
    seed = _skin_seed(sl, hull, depth, color, s, owner, k) if s.ground_colour and k > 0 else None
    if seed is not None:  # the part's start in one call (stop 52, round52)
        sl, hull, n, zm, count, mr, mc = seed
        if n < 20:
            return sl, hull
        rc, cc = mr + sl[0].start, mc + sl[1].start
        own = float(np.sqrt(count / np.pi))
    else:
        if s.ground_colour and k > 0 and isinstance(depth, _BridgedDepth):
            depth[_pad(sl, GAP_PX, depth.shape)]  # :func:`_blush_rim`'s window first: the part's is cut from it
        z_sl = depth[sl]
        z_part = jit.masked_depths(hull, z_sl)[1] if jit is not None and hull.dtype == bool else z_sl[hull & (z_sl > 0)]
        if s.ground_colour and k > 0:  # a red part's blush along the rim: the depth of the apple beside it
            sl, hull, z_part = _blush_rim(sl, hull, z_part, depth, color, s, owner, k)
        if len(z_part) < 20:
            return sl, hull
        if jit is not None and hull.dtype == bool:  # the count and mean row and column, the same values
            count, mr, mc = jit.mask_centre(hull)
            rc, cc = mr + sl[0].start, mc + sl[1].start
            own = float(np.sqrt(count / np.pi))
        else:
            rows, cols = np.nonzero(hull)
            rc, cc = rows.mean() + sl[0].start, cols.mean() + sl[1].start
            own = float(np.sqrt(hull.sum() / np.pi))
        zm = float(median(z_part))
    reach = ROUND_REACH * own
    deep_limit = ROUND_REACH * own * zm / geo.focal + s.depth_jump
    far = s.round_max_diameter * geo.focal / zm
    big, z, skin, at = _skin_flood(sl, hull, depth, color, s, owner, k, (rc, cc, reach, deep_limit, zm), far > reach)
    if far > reach and (_at_reach(skin, big, rc, cc, reach) if at is None else at):
        # again out to the largest fruit's diameter at the part's depth (stop 46): the skin lies within the fruit's
        # diameter of any of its pixels, and a blush cut to a thin crescent by a leaf's shadow and the camera's
        # 4:2:0 chroma is small against its apple
        big, z, skin, _ = _skin_flood(sl, hull, depth, color, s, owner, k, (rc, cc, far, deep_limit, zm), False)
    if skin.sum() > _largest_area(skin, z, s, geo.focal, zm):
        return sl, hull  # more than one fruit's skin: bark or a branch at the fruit's depth joined it
    return big, skin


def _skin_seed(
    sl: Window, hull: np.ndarray, depth: _Depth, color: np.ndarray, s: SegmentSettings, owner: np.ndarray, k: int
) -> tuple[Window, np.ndarray, int, float, int, float, float] | None:
    """:func:`_round_skin`'s start for a red part (``hull`` in window ``sl``, the ``k``-th piece, with
    ``ground_colour``) in one compiled call where numba is (:func:`symfruit.core._jit.skin_seed`: the part's depths,
    :func:`_blush_rim`'s test in the window padded by :data:`GAP_PX`, the median depth and the centre it grows from),
    not five calls and their arrays: the window and mask it grows from, how many depths it has, their median, the
    mask's pixel count and mean row and column in its window. None where the calls are to be made (no numba, other
    types). The same values (stop 52, round52)."""
    jit = compiled()
    if jit is None or hull.dtype != bool or hull.ndim != 2 or color.dtype != np.uint8 or color.ndim != 3:
        return None
    big = _pad(sl, GAP_PX, depth.shape)  # read first: the part's own window is cut from it (treeseg49)
    z = depth[big]
    if z.dtype != np.float64:
        return None
    moved, mask, n, zm, count, mr, mc = jit.skin_seed(
        np.ascontiguousarray(hull), z, sl[0].start - big[0].start, sl[1].start - big[1].start, color[big], owner[big],
        int(k), GAP_PX, float(s.depth_jump), GROUND_HUE, LEAF_HUE, GROUND_DARK)  # fmt: skip
    return (big, mask, int(n), float(zm), int(count), float(mr), float(mc)) if moved else (
        sl, hull, int(n), float(zm), int(count), float(mr), float(mc))  # fmt: skip


def _at_reach(skin: np.ndarray, big: Window, rc: float, cc: float, reach: float) -> bool:
    """Whether :func:`_round_skin`'s skin (in window ``big``) may have been stopped by its reach: a pixel of it on the
    window's edge, or with a neighbour outside the disc of radius ``reach`` about ``(rc, cc)``. When not, a wider
    reach grows the same skin (every pixel next to it lies inside both discs and windows, and is refused there by
    the same tests or by a depth step the wider window only adds to). Where numba is, in one call
    (:func:`symfruit.core._jit.at_reach`: the same answer; stop 47)."""
    if (jit := compiled()) is not None and skin.dtype == bool and skin.ndim == 2:
        return bool(jit.at_reach(skin, big[0].start, big[1].start, float(rc), float(cc), (reach - 1.0) ** 2))
    box = mask_box(skin)
    if box is None:
        return False
    r0, r1, c0, c1 = box
    if r0 == 0 or c0 == 0 or r1 == skin.shape[0] or c1 == skin.shape[1]:
        return True
    # the box's farthest corner inside the disc: every pixel is (two reductions, not every pixel's coordinates)
    dy = max(abs(r0 + big[0].start - rc), abs(r1 - 1 + big[0].start - rc))
    dx = max(abs(c0 + big[1].start - cc), abs(c1 - 1 + big[1].start - cc))
    if dy * dy + dx * dx <= (reach - 1.0) ** 2:
        return False
    rows, cols = np.nonzero(skin[r0:r1, c0:c1])
    dr, dc = rows + (r0 + big[0].start - rc), cols + (c0 + big[1].start - cc)
    return bool((dr * dr + dc * dc > (reach - 1.0) ** 2).any())


def _skin_flood(
    sl: Window,
    hull: np.ndarray,
    depth: _Depth,
    color: np.ndarray,
    s: SegmentSettings,
    owner: np.ndarray,
    k: int,
    grow: tuple[float, float, float, float, float],
    reached: bool,
) -> tuple[Window, np.ndarray, np.ndarray, bool | None]:
    """:func:`_round_skin`'s growth from the red part ``hull`` (in window ``sl``) within a reach (``grow``: the
    part's centre row and column, the reach in pixels, the depth limit and the median depth), in the window that
    holds both: the window, its depth, the skin, and with ``reached`` whether the reach may have stopped it
    (:func:`_at_reach`; None when not asked, or where it is not worked out here: the twins)."""
    rc, cc, reach, deep_limit, zm = grow
    h, w = depth.shape
    big = (slice(max(min(int(rc - reach), sl[0].start), 0), min(max(int(rc + reach) + 1, sl[0].stop), h)),
           slice(max(min(int(cc - reach), sl[1].start), 0), min(max(int(cc + reach) + 1, sl[1].stop), w)))  # fmt: skip
    z = depth[big]
    r, c = sl[0].start - big[0].start, sl[1].start - big[1].start
    jit = compiled()
    if jit is not None and hull.dtype == bool and hull.ndim == 2:
        # the part's copy, the flood (a flood of the seeds' components alone; issue 19, seventeenth round) and the
        # reach test in one call (:func:`symfruit.core._jit.skin_flood`: the same pixels and answer; stop 53, seg53)
        skin, at = jit.skin_flood(z, color[big], owner[big], int(k), hull, r, c, big[0].start, big[1].start, float(rc),
                                  float(cc), float(reach**2), float(deep_limit), zm, 0.5 * s.depth_jump, s.depth_jump,
                                  LEAF_HUE, (reach - 1.0) ** 2 if reached else -1.0)  # fmt: skip
        return big, z, skin, bool(at) if reached else None
    part = np.zeros(z.shape, bool)
    part[r : r + hull.shape[0], c : c + hull.shape[1]] = hull
    if jit is not None:  # the same pixels (:func:`symfruit.core._jit.round_skin`; issue 19, seventeenth round)
        skin = jit.round_skin(z, color[big], owner[big], int(k), part, big[0].start, big[1].start, float(rc),
                              float(cc), float(reach**2), float(deep_limit), zm, 0.5 * s.depth_jump, s.depth_jump,
                              LEAF_HUE)  # fmt: skip
        return big, z, skin, None
    # broadcast: the same values per pixel, without two full grids (np.ogrid's, without its call's overhead)
    yy, xx = np.arange(big[0].start, big[0].stop)[:, None], np.arange(big[1].start, big[1].stop)[None]
    free = (owner[big] == 0) | (owner[big] == k)
    near = (yy - rc) ** 2 + (xx - cc) ** 2 <= reach**2
    candidate = near & (z > 0) & (np.abs(z - zm) <= deep_limit) & ~_leaf(color[big]) & free
    # grown from the part's pixels near its median depth: its hull's rim may lie on what is behind it
    allowed = (candidate | part) & ~_steps(z, 0.5 * s.depth_jump)
    lab, n = ndimage.label(allowed)
    grown = np.zeros(n + 1, bool)
    grown[lab[part & (np.abs(z - zm) <= s.depth_jump)]] = True
    grown[0] = False
    return big, z, grown[lab] | part, None


def _blush_rim(
    sl: Window,
    hull: np.ndarray,
    z_part: np.ndarray,
    depth: _Depth,
    color: np.ndarray,
    s: SegmentSettings,
    owner: np.ndarray,
    k: int,
) -> tuple[Window, np.ndarray, np.ndarray]:
    """The window, mask and depths a red part's skin grows from (:func:`_round_skin`): the part's own, or, for a
    blush along a fruit's silhouette, the fruit's. A time-of-flight camera invalidates the mixed pixels along a
    silhouette and depth registered a few pixels off the colour puts what lies behind on the rest of a thin rim,
    so a blush crescent on an apple turned with its ground colour to the camera carries the depth of what
    surrounds the apple, not the apple's. Such a part is told by two facts of depth: its median depth is that of
    its other surroundings (its neighbours within :data:`GAP_PX` that are not ground colour, within ``depth_jump``:
    a fruit's own surface stands in front of what surrounds it), and the ground-colour pixels beside it (free, with
    depth) lie in front of it by more than ``depth_jump`` (the apple's body hides what is behind the rim). Then
    the part is taken with the ground-colour pixels beside it at their depth, and grows from that depth. A red
    fruit with a depth of its own is not changed (a yellow-green leaf in front of it is not its skin); nor is a
    part with too little depth of its own to tell (fewer than 20 pixels; outside the depth camera's view nothing
    changes)."""
    if len(z_part) < 20:
        return sl, hull, z_part
    pad = GAP_PX
    big = _pad(sl, pad, depth.shape)
    z = depth[big]
    part = np.zeros(z.shape, bool)
    r, c = sl[0].start - big[0].start, sl[1].start - big[1].start
    part[r : r + hull.shape[0], c : c + hull.shape[1]] = hull
    if (jit := compiled()) is not None and color.dtype == np.uint8 and z.dtype == np.float64:
        # the rim's test in one compiled call (:func:`symfruit.core._jit.blush_rim`: the same pixels, medians and
        # answer; issue 19, nineteenth round)
        near = jit.blush_rim(part, z, color[big], owner[big], int(k), pad, np.ascontiguousarray(z_part, np.float64),
                             float(s.depth_jump), GROUND_HUE, LEAF_HUE, GROUND_DARK)  # fmt: skip
        if near.shape != part.shape:
            return sl, hull, z_part
        return big, part | near, z[near]
    beside = square_filter(part, pad) & ~part & (z > 0)
    ground = _ground(color[big])
    ring = beside & ground & ((owner[big] == 0) | (owner[big] == k))
    other = beside & ~ground
    if ring.sum() < 20 or other.sum() < 20:
        return sl, hull, z_part
    zm, front = float(median(z_part)), float(median(z[ring]))
    if zm - front <= s.depth_jump or abs(zm - float(median(z[other]))) > s.depth_jump:
        return sl, hull, z_part
    near = ring & (np.abs(z - front) <= s.depth_jump)
    return big, part | near, z[near]


#: A round fruit's skin is looked for within this many times its red part's own radius (a red cap over a
#: third of the visible disc has about 0.6 of its radius).
ROUND_REACH = 2.0


def _ground(color: np.ndarray) -> np.ndarray:
    """(h, w) bool: ground-colour pixels, yellow to yellow-green: saturated as :func:`_green` (the largest channel
    a third above the smallest), blue the smallest, of a hue from :data:`GROUND_HUE` up to (not including)
    :data:`LEAF_HUE` degrees, and not dark (the largest channel above :data:`GROUND_DARK`). Integer tests: with
    R the largest the hue is ``60 (G - B) / (R - B)``, with G the largest ``60 + 60 (G - R) / (G - B)``. Where numba
    is, its compiled twin gives the same pixels (:func:`symfruit.core._jit.ground_pixels`; issue 19, nineteenth
    round)."""
    if (jit := compiled()) is not None and color.dtype == np.uint8 and color.ndim == 3 and color.shape[2] >= 3:
        return jit.ground_pixels(color, GROUND_HUE, LEAF_HUE, GROUND_DARK)
    r, g, b = (color[:, :, k].astype(np.int16) for k in range(3))
    top = np.maximum(r, g)
    gb, rb = g - b, r - b
    out = (b <= np.minimum(r, g)) & (3 * (top - b) >= top) & (top > GROUND_DARK)
    out &= 60 * gb >= GROUND_HUE * rb  # hue >= GROUND_HUE (where G > R it is above 60 anyway)
    out &= (r >= g) | (60 * (g - r) < (LEAF_HUE - 60) * gb)  # hue < LEAF_HUE
    return out


#: The least hue (degrees) of a fruit's ground colour: yellow-orange. Below it lie the red blush and its orange
#: stripes (found from red) and brown bark and twigs (hue about 20-35).
GROUND_HUE = 40

#: Ground-colour pixels need a largest channel above this (0-255): in deep shadow the hue is noise.
GROUND_DARK = 40


@dataclass
class _Body:
    """A round body of ground colour (:func:`_ground_bodies`): its mask in an image window and the sphere its
    depth fits (centre in the camera frame and radius, metres)."""

    window: Window
    mask: np.ndarray
    centre: np.ndarray
    radius: float


def _ground_bodies(c: np.ndarray, z: _Depth, geo: _Geometry, s: SegmentSettings, owner: np.ndarray) -> list[_Body]:
    """Round fruit showing their ground colour: the pieces of ground-colour pixels (:func:`_ground`) with depth
    and no depth step inside, not red pixels of a candidate fruit (``owner``), fruit-sized (a disc of
    ``min_diameter`` to one of ``round_max_diameter`` at their depth), convex in outline
    (:data:`GROUND_SOLIDITY`), whose depth is a round body (:func:`_round_body`). Each one's mask is its hull
    less leaf green and the pixels off its depth. Looked for on the coarse grid first (:data:`COARSE_STEP`), at
    full resolution only around what it finds."""
    h, w = c.shape[:2]
    g = COARSE_STEP
    focal = geo.focal
    z_grid = z[(slice(None, None, g), slice(None, None, g))]
    if not (z_grid > 0).any():
        return []
    cand = _ground_steps(c[::g, ::g], z_grid, 3, 2.0 * s.depth_jump)  # a grid step spans 4 pixels of a surface
    lab, n, at, la = _labelled(cand)
    if n == 0:
        return []
    count, disc = _piece_discs(la, z_grid, at, n, focal)
    area = count * g * g
    keep = (area >= 0.5 * disc * s.min_diameter**2) & (area <= 2.0 * disc * s.round_max_diameter**2)
    keep[0] = False
    if not keep.any():
        return []
    sized = np.flatnonzero(keep.take(la))  # the fruit-sized pieces' points alone, numbered 0..m-1 for the test
    at, la = at.take(sized), la.take(sized)
    rows, cols = np.divmod(at, lab.shape[1])
    ids = np.flatnonzero(keep)
    index = np.zeros(n + 1, np.int64)
    index[ids] = np.arange(len(ids))
    keep[ids] = _bulging(index.take(la), rows * g, cols * g, z_grid.ravel().take(at), len(ids) - 1, geo, s)
    if not keep.any():
        return []
    bodies: list[_Body] = []
    for r0, r1, c0, c1 in _join_boxes(_padded_boxes(la, rows, cols, keep, 2, lab.shape)):
        win = (slice(r0 * g, min(r1 * g, h)), slice(c0 * g, min(c1 * g, w)))
        zw = z[win]
        if not (zw > 0).any():
            continue
        cand = _ground_steps(c[win], zw, GAP_PX, s.depth_jump) & (owner[win] == 0)
        lab, n, at, la = _labelled(cand)
        if n == 0:
            continue
        count, disc = _piece_discs(la, zw, at, n, focal)
        keep = (count >= disc * s.min_diameter**2) & (count <= disc * s.round_max_diameter**2)
        keep[0] = False
        rows, cols = np.divmod(at, lab.shape[1])
        for k, box in _boxes(la, rows, cols, keep).items():
            box = _pad(box, 1, lab.shape)
            part = fill_holes(lab[box] == k)
            sl = (slice(box[0].start + win[0].start, box[0].stop + win[0].start),
                  slice(box[1].start + win[1].start, box[1].stop + win[1].start))  # fmt: skip
            vertices = _hull_vertices(part)
            sub_z = z[sl]
            if not _convex_outline(part, vertices, sub_z, s.depth_jump):
                continue  # not one convex outline: leaves, or fruit and leaves
            fit = _round_body(part, sub_z, geo, s, (sl[0].start, sl[1].start))
            if fit is None:
                continue
            hull = _hull_mask(vertices, part) & (part | ~_leaf(c[sl])) & ((owner[sl] == 0) | part)
            bodies.append(_Body(sl, _depth_consistent(hull, part, sub_z, s.depth_jump), *fit))
    return bodies


def _convex_outline(part: np.ndarray, vertices: np.ndarray | None, depth: np.ndarray, jump: float) -> bool:
    """Whether a ground-colour piece (``part``, its hull's ``vertices``, the window's ``depth``, 0: none) is one
    convex outline: it fills at least :data:`GROUND_SOLIDITY` of its hull, not counting the hull's pixels that
    something in front hides (a leaf, a twig or a stem across a fruit: their depth nearer than the piece's median
    by more than ``jump``; a pixel without depth takes the nearest depth within :data:`GAP_PX`, the invalid rim of
    an occluder's silhouette being the occluder's edge). A leaf behind a fruit, or beside it at its depth, does not
    make its outline convex; without depth nothing is hidden."""
    area = float(part.sum())
    hull_area = _hull_area_of(vertices, part)
    if area >= GROUND_SOLIDITY * hull_area:
        return True
    seen = part & (depth > 0)
    if not seen.any():
        return False
    front = float(median(depth[seen])) - jump
    rest = _hull_mask(vertices, part) & ~part
    if (jit := compiled()) is not None and depth.dtype == np.float64:  # the same count, the box read where needed
        return area >= GROUND_SOLIDITY * (hull_area - float(jit.hidden_count(rest, depth, front, GAP_PX)))
    near = np.where(depth > 0, depth, np.inf)
    near = ndimage.minimum_filter(near, size=GAP_PX, mode="nearest")
    z = np.where(depth > 0, depth, near)
    hidden = rest & (z < front)
    return area >= GROUND_SOLIDITY * (hull_area - float(hidden.sum()))


def _ground_steps(color: np.ndarray, depth: np.ndarray, size: int, jump: float) -> np.ndarray:
    """(h, w) bool: ground-colour pixels (:func:`_ground`) not on a depth step (:func:`_steps`, larger than ``jump``)
    of the ``depth`` (0: none) with its gaps filled over a ``size`` box (:func:`_gap_filled`). Where numba is, its
    compiled twin finds the same steps in one call (:func:`symfruit.core._jit.ground_steps`; issue 19, eighteenth
    round: numpy's dozen calls on each window cost twice as much)."""
    ground = _ground(color)
    if (jit := compiled()) is not None and depth.ndim == 2 and depth.dtype == np.float64:
        return jit.ground_steps(ground, depth, size, jump)
    return ground & ~_steps(_gap_filled(depth, size), jump)


def _piece_discs(
    labels: np.ndarray, depth: np.ndarray, at: np.ndarray, n: int, focal: float
) -> tuple[np.ndarray, np.ndarray]:
    """For pieces ``0..n`` (``labels`` of the pixels at flat indices ``at`` of the window's ``depth``, 0 where none):
    each one's pixel count, and the area (pixels) a disc 1 m across would cover at its mean depth (over its pixels with
    depth). Where numba is, the three sums in one pass (:func:`symfruit.core._jit.piece_sums`: the same values; stop
    58, speed58)."""
    if (jit := compiled()) is not None and depth.dtype == np.float64 and depth.flags.c_contiguous:
        count, total, seen = jit.piece_sums(labels, depth.reshape(-1), at, int(n))
    else:
        z = depth.ravel().take(at)
        count = np.bincount(labels, minlength=n + 1).astype(np.float64)
        total, seen = (
            np.bincount(labels, weights=z, minlength=n + 1),
            np.bincount(labels, weights=z > 0, minlength=n + 1),
        )
    zmean = total / np.maximum(seen, 1.0)
    return count, np.pi / 4 * (focal / np.maximum(zmean, 1e-6)) ** 2


#: Width (pixels) of the box over which a pixel without depth takes the farthest depth near it
#: (:func:`_gap_filled`): a time-of-flight camera's invalid rim is 1-2 depth pixels, 3-6 colour pixels at 1920x1080.
GAP_PX = 7


def _bulging(
    labels: np.ndarray,
    rows: np.ndarray,
    cols: np.ndarray,
    depth: np.ndarray,
    n: int,
    geo: _Geometry,
    s: SegmentSettings,
) -> np.ndarray:
    """(n + 1,) bool: which labelled pieces (``labels`` 0..n of pixels at ``rows``, ``cols`` with ``depth``, 0 where
    none) may be a round fruit's visible surface, all at once: the paraboloid ``z = a + b x + c y + d (x^2 + y^2)``
    (camera-frame metres, about each piece's mean) fitted to its points with depth (10 or more) by least squares
    bulges towards the camera (``d > 0``) with a curvature radius ``1 / (2 d)`` from a quarter of the least fruit's
    radius to twice the largest's (``min_diameter``, ``round_max_diameter``), and fits them more closely than a
    plane (a residual sum of squares at most :data:`BULGE_RSS` of the plane's). A quick test on the coarse grid
    before :func:`_round_body`, looser than it: a paraboloid follows a cap's steep rim less well than a sphere."""
    if (jit := compiled()) is not None and depth.dtype == np.float64:  # the same sums in one call (stop 44)
        count, m, rhs, zz = jit.bulge_sums(np.ascontiguousarray(labels, np.int64), rows, cols, depth, int(n),
                                           float(geo.cx), float(geo.cy), float(geo.focal))  # fmt: skip
    else:
        ok = depth > 0
        lab = labels[ok]
        z = depth[ok]
        x = (cols[ok] - geo.cx) * z / geo.focal
        y = (rows[ok] - geo.cy) * z / geo.focal
        count = np.bincount(lab, minlength=n + 1).astype(np.float64)
        safe = np.maximum(count, 1.0)
        x = x - (np.bincount(lab, weights=x, minlength=n + 1) / safe)[lab]
        y = y - (np.bincount(lab, weights=y, minlength=n + 1) / safe)[lab]
        cols_ = (np.ones_like(x), x, y, x * x + y * y)
        m = np.empty((n + 1, 4, 4))
        for i in range(4):
            for j in range(i, 4):
                m[:, i, j] = m[:, j, i] = np.bincount(lab, weights=cols_[i] * cols_[j], minlength=n + 1)
        rhs = np.stack([np.bincount(lab, weights=v * z, minlength=n + 1) for v in cols_], axis=1)
        zz = np.bincount(lab, weights=z * z, minlength=n + 1)
    enough = count >= 10
    m[~enough] = np.eye(4)  # a placeholder: those pieces are not tested
    m += 1e-12 * np.eye(4)
    sol4 = np.linalg.solve(m, rhs[:, :, None])[:, :, 0]
    sol3 = np.linalg.solve(m[:, :3, :3], rhs[:, :3, None])[:, :, 0]
    rss4 = zz - np.einsum("ij,ij->i", sol4, rhs)
    rss3 = zz - np.einsum("ij,ij->i", sol3, rhs[:, :3])
    d = sol4[:, 3]
    radius = 0.5 / np.maximum(d, 1e-9)
    bounded = (radius >= 0.125 * s.min_diameter) & (radius <= s.round_max_diameter)
    return enough & (d > 0) & bounded & (rss4 <= BULGE_RSS * rss3)


#: A coarse piece bulges when its paraboloid's residual sum of squares is at most this share of the plane's: a
#: loose bound (chosen on seeds 0-5 of the rendered trees: 0.25 lost six apples there; whole visible apples give
#: 0.3-0.45, their rims and the depth's offset from the colour included).
BULGE_RSS = 0.6


def _gap_filled(depth: np.ndarray, size: int) -> np.ndarray:
    """A depth image (0: none) with each pixel without depth given the farthest depth within a ``size`` box, NaN
    where there is none (no step is seen there): a step between two surfaces then lies at the nearer one's edge,
    not across the band of missing depth between them (a time-of-flight camera's invalid rim). The box's maximum
    from shifted views, rows then columns: ``ndimage.maximum_filter(depth, size)``'s values, at a third of its
    cost."""
    near = depth.copy()
    for axis in (0, 1):
        src = near.copy()
        for k in range(1, size // 2 + 1):
            lead = (slice(k, None), slice(None)) if axis == 0 else (slice(None), slice(k, None))
            lag = (slice(None, -k), slice(None)) if axis == 0 else (slice(None), slice(None, -k))
            np.maximum(near[lead], src[lag], out=near[lead])
            np.maximum(near[lag], src[lead], out=near[lag])
    near = np.where(depth > 0, depth, near)  # a select: several times a masked copy's speed
    return np.where(near > 0, near, np.nan)  # no NaN in a cleaned depth: not positive is 0


def _join_bodies(
    sl: Window,
    hull: np.ndarray,
    bodies: list[_Body],
    body_map: np.ndarray,
    taken: np.ndarray,
    depth: _Depth,
    geo: _Geometry,
    s: SegmentSettings,
) -> tuple[Window, np.ndarray]:
    """A red fruit's skin (``hull`` in window ``sl``) joined with the ground-colour bodies it reaches (overlaps,
    or touches) whose sphere its depth lies on (the median distance of its points off the body's sphere at most
    ``sphere_apart`` of its radius and ``depth_jump``), while the whole stays within the largest fruit's disc
    (``round_max_diameter``). The bodies joined are marked ``taken``."""
    near = [b.window for b in bodies if b.window[0].start <= sl[0].stop and sl[0].start <= b.window[0].stop
            and b.window[1].start <= sl[1].stop and sl[1].start <= b.window[1].stop]  # fmt: skip
    if not near:
        return sl, hull
    grown = _dilate(hull, square=True)
    ids = np.unique(body_map[sl][grown])
    for i in ids[ids > 0].tolist():
        if taken[i]:
            continue
        body = bodies[i - 1]
        p = _points(hull, depth[sl], geo, (sl[0].start, sl[1].start))
        if len(p) < 20:
            continue
        off = float(median(np.abs(row_norms(p - body.centre) - body.radius)))
        if off > min(s.sphere_apart * body.radius, s.depth_jump):
            continue
        window, union = _union(_Piece(sl, hull, 0), _Piece(body.window, body.mask, 0))
        if union.sum() > _largest_area(union, depth[window], s, geo.focal, 1.0):
            continue
        taken[i] = True
        sl, hull = window, union
    return sl, hull


def _round_body(
    part: np.ndarray, depth: np.ndarray, geo: _Geometry, s: SegmentSettings, origin: tuple[int, int]
) -> tuple[np.ndarray, float] | None:
    """Whether the depth of a piece (``part`` in the window at ``origin`` of ``depth``; its largest surface without a
    step of ``depth_jump``) is a round fruit's visible surface: a sphere (:func:`_sphere`) of radius
    ``min_diameter / 2`` to :data:`GROUND_RADIUS` times ``round_max_diameter`` fits it, convex towards the camera
    (its centre at least :data:`GROUND_BEHIND` of its radius behind the surface's median depth), and at least
    twice as closely as a plane (:data:`GROUND_PLANE`, median distances, each fit once more without the points far
    off it: a leaf or the background seen through a gap is flat; a leaf curled in one direction fits neither
    well). Returns the sphere (centre, radius), or None."""
    surface = _largest_surface(part, depth, s.depth_jump)
    if surface is None:
        return None
    part = surface
    fit = _sphere(part, depth, geo, origin)
    if fit is None:
        return None
    centre, radius = fit
    if not 0.5 * s.min_diameter <= radius <= GROUND_RADIUS * s.round_max_diameter:
        return None
    p = _points(part, depth, geo, origin)
    zm = float(median(p[:, 2]))
    if centre[2] - zm < GROUND_BEHIND * radius:
        return None
    a = np.concatenate((p[:, :2], np.ones((len(p), 1))), axis=1)
    keep = np.ones(len(p), bool)
    for _ in range(2):  # fit, drop the points far off the plane (a leaf's mixed rim pixels), fit again: as the sphere
        coef = lstsq(a[keep], p[keep, 2])[0]  # numpy's LAPACK call without its wrapper: the same values (stop 47)
        off = np.abs(a @ coef - p[:, 2])
        keep = off <= max(3.0 * float(median(off)) * 1.4826, 1e-4)
    plane = float(median(off))
    sphere = float(median(np.abs(row_norms(p - centre) - radius)))
    return (centre, radius) if sphere <= GROUND_PLANE * plane else None


def _largest_surface(part: np.ndarray, depth: np.ndarray, jump: float) -> np.ndarray | None:
    """:func:`_round_body`'s surface: the largest piece of the pixels of ``part`` with depth and on no depth step
    (larger than ``jump`` between 4-neighbours with depth): not two leaves' pieces joined where depth is missing
    (4-connected: the steps are looked for between 4-neighbours); None with fewer than 20 pixels with depth. Where
    numba is, in one call (:func:`symfruit.core._jit.largest_surface`: the same pixels; stop 51)."""
    if (jit := compiled()) is not None and part.ndim == depth.ndim == 2 and part.dtype == bool and (
            depth.dtype == np.float64):  # fmt: skip
        out: np.ndarray = jit.largest_surface(part, depth, float(jump))
        return out if out.shape == part.shape and out.size else None  # (0, 0): none
    seen = part & (depth > 0)
    if seen.sum() < 20:
        return None
    lab, n = _label(seen & ~_steps(np.where(seen, depth, np.nan), jump))
    if n == 0:
        return None
    return lab == np.argmax(np.bincount(lab.ravel())[1:]) + 1


#: A ground-colour piece is one fruit's outline when it fills at least this share of its convex hull.
GROUND_SOLIDITY = 0.75

#: The largest sphere a ground-colour piece may fit, as a share of ``round_max_diameter`` (its radius, 0.5,
#: with a margin for the fit's noise on a partial cap).
GROUND_RADIUS = 0.6

#: A sphere's centre lies about a radius behind its visible cap (the cap's median depth at least half a radius
#: in front of the centre: a fruit's surface is convex towards the camera).
GROUND_BEHIND = 0.5

#: A round surface: the sphere's median distance from the points at most this share of the plane's.
GROUND_PLANE = 0.5


def _depth_consistent(hull: np.ndarray, part: np.ndarray, depth: np.ndarray, jump: float) -> np.ndarray:
    """Drop hull pixels (outside the colour part) whose depth is far from the part's median depth. Where numba is, in
    one compiled call (:func:`symfruit.core._jit.depth_consistent`: the same pixels; issue 19, nineteenth round)."""
    if (jit := compiled()) is not None and hull.dtype == part.dtype == bool and depth.dtype == np.float64:
        out: np.ndarray = jit.depth_consistent(hull, part, depth, float(jump))
        return out
    z = depth[part & (depth > 0)]
    if len(z) == 0:
        return hull
    zm = float(median(z))
    off = (depth > 0) & (np.abs(depth - zm) > jump)
    return part | (hull & ~off)


def _fruit_sized(
    mask: np.ndarray, depth: np.ndarray | None, s: SegmentSettings, focal: float, min_area: float, z_typical: float
) -> bool:
    """Whether a part is fruit-sized: without depth ``min_area`` pixels; with depth at least a disc of
    ``min_diameter`` at its median depth (``z_typical`` when none of its pixels has depth)."""
    if depth is None:
        return int(mask.sum()) >= min_area
    if (jit := compiled()) is not None and mask.dtype == bool and depth.dtype == np.float64 and mask.ndim == 2:
        area, valid, zm = jit.masked_median(mask, depth)  # the same values in one call (issue 19, nineteenth round)
        return _sized(int(area), float(zm) if valid else z_typical, s, focal)
    area = int(mask.sum())
    z = depth[mask & (depth > 0)]
    diameter_px = focal * s.min_diameter / (float(median(z)) if len(z) else z_typical)
    return area >= np.pi / 4 * diameter_px**2


def _sized(area: int, zm: float, s: SegmentSettings, focal: float) -> bool:
    """:func:`_fruit_sized`'s test with depth, from the part's ``area`` (pixels) and median depth ``zm``."""
    diameter_px = focal * s.min_diameter / zm
    return area >= np.pi / 4 * diameter_px**2


def _plain_piece(
    piece: _Piece, k: int, c: np.ndarray, weak: np.ndarray, owner: np.ndarray, z: _Depth, s: SegmentSettings,
    focal: float, z_typical: float,
) -> np.ndarray | bool | None:  # fmt: skip
    """:func:`_segment_at`'s tests of a found ``piece`` (the ``k``-th) with depth and without the round fruit's skin,
    in two compiled calls where numba is (:func:`symfruit.core._jit.piece_ripe`, then its hull, the hull's depth test
    and the median depth the size test reads by :func:`symfruit.core._jit.piece_hull`), not five calls and their masks
    (stop 49): the hull to claim, False when the piece is not a ripe fruit-sized one, None where the calls below it
    are to be made (no numba, other types, a hull that Pillow fills). The same hull and answers."""
    jit = compiled()
    if jit is None or c.dtype != np.uint8 or not _pillow_fill():
        return None
    sl, part = piece.window, piece.mask
    if part.dtype != bool or part.ndim != 2:
        return None
    color = c[sl]
    if not jit.piece_ripe(color, part, weak[sl], np.float32(s.ripe_median)):
        return False
    vertices = piece.hull_vertices()
    sub_z = z[sl]
    if vertices is None or vertices.dtype != np.float64 or sub_z.dtype != np.float64:
        return None
    surface = s.fill in ("surface", "auto")
    hull, area, valid, zm = jit.piece_hull(vertices, part, weak[sl], owner[sl], int(k), color, surface, sub_z,
                                           float(s.depth_jump))  # fmt: skip
    if hull.shape != part.shape:
        return None
    return hull if _sized(int(area), float(zm) if valid else z_typical, s, focal) else False


def _round_piece(
    piece: _Piece, k: int, c: np.ndarray, weak: np.ndarray, owner: np.ndarray, z: _Depth, s: SegmentSettings
) -> np.ndarray | bool | None:
    """:func:`_segment_at`'s first tests of a round fruit's found ``piece`` (the ``k``-th) with depth in one compiled
    call where numba is (:func:`symfruit.core._jit.round_piece`: its red pixels ripe, its surface hull, the hull's
    depth test), not three calls and their masks: the hull, False when the piece is not ripe, None where the calls
    are to be made (no numba, other types, a hull that Pillow fills). The same hull and answer (stop 52, round52)."""
    jit = compiled()
    sl, part = piece.window, piece.mask
    if jit is None or c.dtype != np.uint8 or part.dtype != bool or part.ndim != 2 or not _pillow_fill():
        return None
    vertices = piece.hull_vertices()
    sub_z = z[sl]
    if vertices is None or vertices.dtype != np.float64 or sub_z.dtype != np.float64:
        return None
    state, hull = jit.round_piece(c[sl], part, weak[sl], np.float32(s.ripe_median), vertices, owner[sl], int(k),
                                  s.fill in ("surface", "auto"), sub_z, float(s.depth_jump))  # fmt: skip
    return hull if state == 1 else False if state == 0 else None


def _least_areas(labels: np.ndarray, depth: np.ndarray, n: int, diameter_px_m: float, z_typical: float) -> np.ndarray:
    """(n + 1,) the least fruit's area (pixels) at each labelled region's mean depth (``z_typical`` for
    regions without depth), from the labels ``1..n`` of a window's region pixels and their depths (in the
    window's raster order: each mean sums its depths in that order); ``diameter_px_m`` is the least diameter
    times the focal length. Where numba is, in one compiled pass (:func:`symfruit.core._jit.least_areas`: the same
    values; issue 19, eighteenth round)."""
    if (jit := compiled()) is not None and labels.ndim == depth.ndim == 1 and depth.dtype == np.float64:
        areas: np.ndarray = jit.least_areas(labels, depth, int(n), float(diameter_px_m), float(z_typical))
        return areas
    valid = depth > 0
    lab = labels[valid]
    count = np.bincount(lab, minlength=n + 1).astype(np.float64)
    total = np.bincount(lab, weights=depth[valid], minlength=n + 1)
    z = np.where(count > 0, total / np.maximum(count, 1.0), z_typical)  # the mean: a threshold needs no more
    return np.pi / 4 * (diameter_px_m / z) ** 2


def _boxes(labels: np.ndarray, rows: np.ndarray, cols: np.ndarray, keep: np.ndarray) -> dict[int, Window]:
    """The boxes of the labels that ``keep`` marks, as ``ndimage.find_objects`` gives them, from the labels,
    rows and columns of a window's labelled pixels (scipy's makes a box for every label of the window)."""
    return _group_boxes(*_grouped(labels, keep), rows, cols)


def _padded_boxes(
    labels: np.ndarray, rows: np.ndarray, cols: np.ndarray, keep: np.ndarray, pad: int, shape: tuple[int, int]
) -> list[tuple[int, int, int, int]]:
    """:func:`_boxes` as ``(r0, r1, c0, c1)``, each widened by ``pad`` on every side within ``shape``, in the labels'
    order. Where numba is, from :func:`symfruit.core._jit.group_boxes`' array by four numpy calls, not slices made and
    read back box by box (the same numbers; stop 53, seg53)."""
    ids, at, first = _grouped(labels, keep)
    if len(at) == 0:
        return []
    if (jit := compiled()) is None or not (at.ndim == first.ndim == rows.ndim == cols.ndim == 1):
        return [(max(sl[0].start - pad, 0), min(sl[0].stop + pad, shape[0]),
                 max(sl[1].start - pad, 0), min(sl[1].stop + pad, shape[1]))
                for sl in _group_boxes(ids, at, first, rows, cols).values()]  # fmt: skip
    b = jit.group_boxes(at, first, rows, cols)
    lo, hi = np.maximum(b[:, 0::2] - pad, 0), np.minimum(b[:, 1::2] + pad, shape)
    return list(zip(lo[:, 0].tolist(), hi[:, 0].tolist(), lo[:, 1].tolist(), hi[:, 1].tolist(), strict=True))


def _grouped(labels: np.ndarray, keep: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pixels of the labels that ``keep`` marks, grouped by label: their labels in ascending order, the
    pixels' indices (into ``labels``) label by label (each label's in their own order), and where each label's
    run starts in them (one more at the end: their number). Where numba is, by a compiled counting sort
    (:func:`symfruit.core._jit.grouped`: the same arrays; issue 19, eighteenth round)."""
    if (jit := compiled()) is not None and labels.ndim == 1 and keep.ndim == 1 and keep.dtype == bool:
        found: tuple[np.ndarray, np.ndarray, np.ndarray] = jit.grouped(labels, keep)
        return found
    at = np.flatnonzero(keep.take(labels))
    lab = labels.take(at)
    order = np.argsort(lab, kind="stable")
    lab, at = lab.take(order), at.take(order)
    first = np.flatnonzero(np.concatenate(([len(lab) > 0], lab[1:] != lab[:-1])))
    return lab.take(first), at, np.append(first, len(lab))


def _group_boxes(
    ids: np.ndarray, at: np.ndarray, first: np.ndarray, rows: np.ndarray, cols: np.ndarray
) -> dict[int, Window]:
    """:func:`_boxes` of the groups of :func:`_grouped`. Where numba is, in one call
    (:func:`symfruit.core._jit.group_boxes`: the same boxes; stop 48)."""
    if len(at) == 0:
        return {}
    if (jit := compiled()) is not None and at.ndim == first.ndim == rows.ndim == cols.ndim == 1:
        boxes = jit.group_boxes(at, first, rows, cols).tolist()
        return {k: (slice(a, b), slice(d, e)) for k, (a, b, d, e) in zip(ids.tolist(), boxes, strict=True)}
    r, c, first = rows.take(at), cols.take(at), first[:-1]
    r0, r1 = np.minimum.reduceat(r, first), np.maximum.reduceat(r, first) + 1
    c0, c1 = np.minimum.reduceat(c, first), np.maximum.reduceat(c, first) + 1
    cells = zip(*(v.tolist() for v in (ids, r0, r1, c0, c1)), strict=True)
    return {k: (slice(a, b), slice(d, e)) for k, a, b, d, e in cells}


def _elongation(mask: np.ndarray) -> float:
    rows, cols = np.nonzero(mask)
    if len(rows) < 3:
        return float("inf")
    cov = np.cov(np.stack([rows, cols]).astype(np.float64))
    ev = np.linalg.eigvalsh(cov)
    return float(np.sqrt(ev[1] / max(ev[0], 1e-9)))


# --- stop 47, yellow47: a round fruit's skin across the depth camera's invalid bands


class _BridgedDepth:
    """A depth image (:class:`_Depth`) read window by window with its short gaps bridged: a pixel without depth takes
    the depth of the nearest pixel with depth when that lies within :data:`BRIDGE_PX` of it (``nearest_index``'s
    choice), else stays 0. A time-of-flight camera invalidates the mixed pixels along every silhouette and misses
    depth where the colour camera sees past an occluder's edge that the depth camera does not (registration's
    shadow): bands of 1-2 depth pixels, up to :data:`GAP_PX` colour pixels at 1920x1080, across a fruit beside a
    leaf or a twig lying over it, and along its rim. Bridged from both sides, such a band takes the depth of the
    surface on each side up to its middle (between a fruit and what lies behind, a step there: about the
    silhouette); a wider gap (a hole through the canopy, the frame's edge beyond the depth camera's view) is left
    as it was. Windows are read once and kept, as :class:`_Depth` keeps them."""

    def __init__(self, depth: _Depth) -> None:
        self.depth = depth
        self.shape = depth.shape
        self.read: dict[tuple[int | None, ...], np.ndarray] = {}
        self.recent: list[tuple[int, int, int, int, np.ndarray]] = []  # the last windows filled, their bounds

    def __getitem__(self, window: tuple[slice, slice]) -> np.ndarray:
        a, b = window
        key = (a.start, a.stop, b.start, b.stop)
        z = self.read.get(key)
        if z is None:
            (r0, r1, _), (c0, c1, _) = a.indices(self.shape[0]), b.indices(self.shape[1])
            for q0, q1, p0, p1, held in self.recent:
                # inside a window filled just before (the blush rim's holds its part's; stop 49, treeseg49): cut out
                # of it, a pixel's bridged depth being the same in any window
                if q0 <= r0 and r1 <= q1 and p0 <= c0 and c1 <= p1:
                    z = np.ascontiguousarray(held[r0 - q0 : r1 - q0, c0 - p0 : c1 - p0])
                    break
            else:
                z = self._fill(window, r0, r1, c0, c1)
                self.recent = [(r0, r1, c0, c1, z), *self.recent[: RECENT_FILLS - 1]]
            z.flags.writeable = False
            self.read[key] = z
        return z

    def _fill(self, window: tuple[slice, slice], r0: int, r1: int, c0: int, c1: int) -> np.ndarray:
        """The window's bridged depth, worked out."""
        jit = compiled()
        given = self.depth.given
        if jit is not None and given.ndim == 2 and given.dtype in _FLOATS:  # only the pixels without depth
            # search, over the disc about them, in the depth as handed over (stop 47, yellowfast47)
            z = np.empty((max(r1 - r0, 0), max(c1 - c0, 0)), np.float64)
            jit.bridge_gaps(given, r0, r1, c0, c1, BRIDGE_PX, z)
            return z
        a, b = window
        big = _pad(window, int(BRIDGE_PX) + 1, self.shape)  # the gaps' nearest depths may lie outside
        r0, c0 = a.start - big[0].start, b.start - big[1].start
        inner = (slice(r0, r0 + a.stop - a.start), slice(c0, c0 + b.stop - b.start))
        return _bridged(self.depth[big], inner)


#: How many of the last windows :class:`_BridgedDepth` filled a window read is looked for in.
RECENT_FILLS = 4


def _bridged(zb: np.ndarray, inner: Window) -> np.ndarray:
    """:class:`_BridgedDepth`'s window ``inner`` of ``zb``, a cleaned depth padded about it by more than
    :data:`BRIDGE_PX`: each pixel without depth takes the depth of the nearest pixel with depth (``nearest_index``'s
    choice) when that lies within :data:`BRIDGE_PX`, else keeps its own. The numpy twin of
    :func:`symfruit.core._jit.bridge_gaps`."""
    seen = zb > 0
    if seen[inner].all() or not seen.any():
        return zb[inner]
    at = nearest_index(~seen)  # each pixel's nearest pixel with depth (flat index)
    rows, cols = np.divmod(at, zb.shape[1])
    yy, xx = np.indices(zb.shape)
    near = (rows - yy) ** 2 + (cols - xx) ** 2 <= BRIDGE_PX**2
    filled = np.where(~seen & near, zb.ravel().take(at), zb)
    return np.ascontiguousarray(filled[inner])


#: The farthest (pixels) a pixel without depth takes the nearest depth from: half of :data:`GAP_PX`, so that an
#: invalid band as wide as a time-of-flight camera's at a silhouette (1-2 depth pixels, 3-6 colour pixels at
#: 1920x1080) is bridged from both sides.
BRIDGE_PX = GAP_PX / 2


def _bridged_skin(
    sl: Window,
    part: np.ndarray,
    depth: _Depth,
    bridged: _BridgedDepth,
    color: np.ndarray,
    geo: _Geometry,
    s: SegmentSettings,
    owner: np.ndarray,
    k: int,
) -> tuple[Window, np.ndarray]:
    """:func:`_round_skin` of a round fruit's part (``part`` in window ``sl``: a red fruit's hull, or a ground-colour
    body) grown over the depth with its short gaps bridged (:class:`_BridgedDepth`). The skin grows only along
    depth, so on a fruit 30-50 px across the invalid bands of a time-of-flight camera (its rim, the shadow of a leaf
    or twig across it) stop it at a half or a third of the fruit (seeds 0-11: 9 of the 26 apples missed with their
    yellow-green side to the camera, their mask IoU 0.2-0.49, half the pixels missed without depth). Of the pixels
    grown that have no depth of their own, only those inside the convex hull of the part and the grown pixels with
    depth are kept (a gap inside the fruit, not the band outside its rim, where the background is). Where the
    skin is then not one convex outline (filling under :data:`GROUND_SOLIDITY` of its hull: it ran on through a
    gap into a branch or a neighbour at its depth) the skin grown without bridging is taken, as before."""
    grown_sl, skin = _round_skin(sl, part, bridged, color, geo, s, owner, k)  # type: ignore[arg-type]
    z = depth[grown_sl]
    r0, c0 = sl[0].start - grown_sl[0].start, sl[1].start - grown_sl[1].start
    jit = compiled()
    state = 0
    if jit is not None and skin.dtype == part.dtype == bool and z.dtype == np.float64 and _pillow_fill():
        # the same pixels in one call, no hull where the skin has depth throughout (:func:`symfruit.core._jit.
        # bridged_trim`; stop 49, treeseg49), and the test below (:func:`symfruit.core._jit.bridged_solid`; stop 52)
        skin, state = jit.bridged_solid(skin, z, part, r0, c0, GROUND_SOLIDITY)
    if state == 0:
        core = skin & (z > 0)
        core[r0 : r0 + part.shape[0], c0 : c0 + part.shape[1]] |= part
        skin = skin & ((z > 0) | convex_hull_mask(core))
    if state == 2 or (state in (0, 3) and skin.sum() < GROUND_SOLIDITY * _hull_area(skin)):
        return _round_skin(sl, part, depth, color, geo, s, owner, k)
    return grown_sl, skin


# --- seg63: a round fruit's pieces joined once grown to their skins (issue 18)


def _join_found(
    found: list[tuple[Window, np.ndarray, tuple[int, int, int, int]]],
    c: np.ndarray,
    z: _Depth,
    geo: _Geometry,
    s: SegmentSettings,
    z_typical: float,
) -> list[tuple[Window, np.ndarray, tuple[int, int, int, int]]]:
    """The found round fruit (:func:`_segment_at`'s ``found``: window, claimed mask, its box) with the pieces of one
    fruit joined, by :func:`_merge` with :class:`_Grown`'s tests. The merge of the red pieces runs before their skins
    are grown; two red parts of one apple split by a leaf across it (or by its highlight, or by the boundary of
    its blush) that the merge kept apart are often found as two partial masks, each grown over its side of the
    apple, neither half of it (mask IoU under 0.5). Once grown they are joined when, as one fruit's pieces must,
    their union is one convex outline (the merge's hull test, the green of a leaf across them discounted), reaches
    no further than the largest fruit is across at its depth, and lies on one surface in depth (:class:`_Grown`)."""
    pieces = []
    for i, (sl, free, box) in enumerate(found):
        r0, r1, c0, c1 = box
        win = (slice(sl[0].start + r0, sl[0].start + r1), slice(sl[1].start + c0, sl[1].start + c1))
        pieces.append(_Piece(win, np.ascontiguousarray(free[r0:r1, c0:c1]), 1 << i))
    weak = _zeroed(z.shape, np.bool_)  # every found pixel: the sphere fits take a grown skin's points, not only red
    for p in pieces:
        weak[p.window] |= p.mask
    joined = _merge(pieces, s, c, weak, z, geo, _Grown(z, geo, s, z_typical))
    _give_back(weak, [p.window for p in pieces])
    if len(joined) == len(pieces):
        return found
    return [(p.window, p.mask, mask_box(p.mask) or (0, 0, 0, 0)) for p in joined]


class _Grown:
    """:func:`_merge`'s tests for round fruit found and grown to their skins (:func:`_join_found`). A grown skin
    carries depth along its silhouette that is not its own (a time-of-flight camera's mixed pixels, depth
    registered a few pixels off the colour: what lies behind the fruit), so a sphere fitted to it is often far off
    (radii of 0.2-2 m on apples 70 mm across) and the merge's sphere test refuses both halves of one apple. Here:

    - **near** (:meth:`near`): two pieces whose boxes together span no more than the largest fruit
      (``round_max_diameter``) at the depth of either; a leaf across an apple may hide its middle, leaving its two
      sides further apart than :func:`_near_pieces` looks;
    - **two fruit** (:meth:`two`): the union reaches further than the largest fruit is across at the union's median
      depth (an absolute bound where :func:`_two_extents` is relative to the larger piece: two sides of an apple seen
      past a leaf are each much narrower than the apple); without depth on the union, :func:`_two_extents`;
    - **one surface** (:meth:`same`): the pieces' median depths lie within the largest fruit's radius of each other
      (one fruit's visible surface spans at most its radius in depth; the median of a piece is its own surface's
      where most of its pixels are), or the merge's sphere test holds; without depth on either piece, nothing to
      tell (None). A piece larger than the largest fruit's disc at its own median depth has no depth of its own
      to tell by (a rim piece whose pixels carry the depth of what lies far behind the fruit: at 4.7 m the largest
      apple spans 20 px, at 1.8 m the apple it lies on 50)."""

    def __init__(self, z: _Depth, geo: _Geometry, s: SegmentSettings, z_typical: float) -> None:
        self.z, self.geo, self.s, self.z_typical = z, geo, s, z_typical
        self.medians: dict[int, float | None] = {}

    def median(self, p: _Piece) -> float | None:
        """The piece's median depth; None with fewer than :data:`SAME_SURFACE_POINTS` pixels of depth, or when the
        piece is larger than the largest fruit's disc at that depth."""
        if p.serial not in self.medians:
            n, zm = _masked_median(p.mask, self.z[p.window])
            # larger than any fruit at that depth: the depth of what lies behind it
            own = n >= SAME_SURFACE_POINTS and p.area <= np.pi / 4 * self.largest(zm) ** 2
            self.medians[p.serial] = zm if own else None
        return self.medians[p.serial]

    def largest(self, zm: float) -> float:
        """The largest fruit's diameter (pixels) at depth ``zm``."""
        return self.s.round_max_diameter * self.geo.focal / zm

    def near(self, pieces: list[_Piece]) -> Callable[[int], list[int]]:
        box = np.array([[p.window[0].start, p.window[0].stop, p.window[1].start, p.window[1].stop] for p in pieces])
        far = np.array([self.largest(self.median(p) or self.z_typical) for p in pieces])
        limit = np.maximum(far[:, None], far[None, :])
        high = np.maximum(box[:, None, 1], box[None, :, 1]) - np.minimum(box[:, None, 0], box[None, :, 0])
        wide = np.maximum(box[:, None, 3], box[None, :, 3]) - np.minimum(box[:, None, 2], box[None, :, 2])
        order = np.arange(len(pieces))
        table = (high <= limit) & (wide <= limit) & (order[:, None] < order[None, :])
        rows: list[list[int]] = [[] for _ in range(len(pieces))]
        for i, j in zip(*np.nonzero(table), strict=True):
            rows[int(i)].append(int(j))
        return rows.__getitem__

    def two(self, a: _Piece, b: _Piece, vertices: np.ndarray | None, union: tuple[Window, np.ndarray]) -> bool:
        n, zm = _masked_median(union[1], self.z[union[0]])
        if n < 20:
            return _two_extents(a, b, vertices)
        return _extent(vertices, union[1]) > self.largest(zm)

    def same(self, a: _Piece, b: _Piece, weak: np.ndarray, surfaces: dict[int, _Surface]) -> bool | None:
        za, zb = self.median(a), self.median(b)
        if za is not None and zb is not None and abs(za - zb) <= 0.5 * self.s.round_max_diameter:
            return True
        if _same_surface(a, b, self.z, weak, self.geo, self.s, surfaces) is True:
            return True
        return None if za is None or zb is None else False


def _masked_median(mask: np.ndarray, depth: np.ndarray) -> tuple[int, float]:
    """How many of ``mask``'s pixels have depth, and the median of their depths (NaN without any); where numba is
    in one call (:func:`symfruit.core._jit.masked_median`: the same values)."""
    if (jit := compiled()) is not None and mask.dtype == bool and depth.dtype == np.float64 and mask.ndim == 2:
        _, n, zm = jit.masked_median(mask, depth)
        return int(n), float(zm)
    z = depth[mask]
    z = z[z > 0]
    return len(z), float(median(z)) if len(z) else float("nan")
