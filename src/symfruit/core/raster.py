"""Rasterise what the camera saw of one fruit: the visible mask ``Mp`` and the seen depth (section 3.5.2), or
the seen region alone (:func:`silhouette`).

Only a window of the image around the fruit is rasterised (:mod:`symfruit.rating` answers points
falling outside it with an upper bound of their distance to the mask).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import ndimage

from ..errors import InputError
from . import lapack
from .box import Box
from .camera import Camera
from .fits import _plain, eigenvalues2, solve2
from .kernels import compiled
from .limits import MAX_WINDOW_PIXELS
from .points import as_points, column_means, cross_rows, squared_norms

__all__ = [
    "MAX_WINDOW_PIXELS",
    "Across",
    "Silhouette",
    "Tilt",
    "View",
    "across_sight",
    "axis_tilt",
    "close_ragged",
    "cone_widths",
    "distance_maps",
    "distance_transform",
    "fill_holes",
    "inner_distance",
    "interior",
    "mask_box",
    "nearest_index",
    "outline_circle",
    "outline_cone",
    "outline_cracks",
    "point_pixels",
    "principal_widths",
    "rasterise",
    "silhouette",
    "silhouette_cone",
    "silhouette_coverage",
    "width_across",
]

# MAX_WINDOW_PIXELS (.limits): the largest image window one fruit may cover, 2000 x 2000, far more than any
# fruit in a harvesting camera's view; beyond it the intrinsics or the units are wrong (and the buffers would be).


@dataclass(frozen=True)
class View:
    """The seen fruit in an image window whose top-left pixel is ``(u0, v0)``.

    Attributes
    ----------
    mask : (h, w) bool
        ``Mp``: pixels covered by the fruit (points splatted, gaps closed, holes filled).
    dist : (h * w,) float, pixels
        Distance of each pixel to the nearest mask pixel (0 inside the mask).
    near_u, near_v : (h * w,) float, pixels
        Image coordinates of that nearest mask pixel (the pixel itself inside the mask).
    near_depth : (h * w,) float, metres
        Seen depth at that nearest mask pixel. Mask pixels that no point hit take the depth of the
        nearest pixel that one did.
    fill_radius : float, pixels
        Half-width of the square used to close the gaps between points.
    """

    u0: int
    v0: int
    mask: np.ndarray
    dist: np.ndarray
    near_u: np.ndarray
    near_v: np.ndarray
    near_depth: np.ndarray
    fill_radius: float


def _pixels(points: np.ndarray, camera: Camera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pixel column, row and depth of the points that project into the image; by the compiled twin
    :func:`symfruit.core._jit.image_pixels` where numba is installed (the same pixels, in one pass)."""
    if points.ndim == 2 and points.shape[1] == 3 and (jit := compiled()) is not None:
        col, row, z = jit.image_pixels(np.ascontiguousarray(points, dtype=np.float64), float(camera.fx),
                                       float(camera.fy), float(camera.cx), float(camera.cy), int(camera.width),
                                       int(camera.height))  # fmt: skip
        if not len(col):
            raise InputError(
                f"no point projects into the {camera.width}x{camera.height} image; "
                "are the points in the camera's optical frame (z forward) and is this the right camera?"
            )
        return col, row, z
    uv = camera.project(points)
    col = np.rint(uv[:, 0]).astype(np.intp)
    row = np.rint(uv[:, 1]).astype(np.intp)
    inside = (col >= 0) & (col < camera.width) & (row >= 0) & (row < camera.height)
    if not inside.any():
        raise InputError(
            f"no point projects into the {camera.width}x{camera.height} image; "
            "are the points in the camera's optical frame (z forward) and is this the right camera?"
        )
    return col[inside], row[inside], points[inside, 2]


def _window(
    col: np.ndarray, row: np.ndarray, camera: Camera, margin: int, box: tuple[int, int, int, int] | None = None
) -> tuple[int, int, int, int]:
    """``(u0, v0, h, w)``: the pixels' box (``box``: their ``(c0, c1, r0, r1)`` when known) grown by ``margin``,
    clipped to the image, bounded in size."""
    c0, c1, r0, r1 = (int(col.min()), int(col.max()), int(row.min()), int(row.max())) if box is None else box
    u0, v0 = max(c0 - margin, 0), max(r0 - margin, 0)
    u1, v1 = min(c1 + margin + 1, camera.width), min(r1 + margin + 1, camera.height)
    h, w = v1 - v0, u1 - u0
    if h * w > MAX_WINDOW_PIXELS:
        raise InputError(
            f"the visible points span {w}x{h} pixels of the {camera.width}x{camera.height} image, more than one "
            "fruit can; check the intrinsics and that the points are in metres"
        )
    return u0, v0, h, w


def _default_fill(col: np.ndarray, row: np.ndarray) -> float:
    """0.7 sqrt(area / n), ``area`` the ellipse inscribed in the pixels' box: 1.5 times the expected
    median nearest-neighbour spacing of ``n`` points spread over the silhouette."""
    area = np.pi / 4.0 * (np.ptp(col) + 1) * (np.ptp(row) + 1)
    return 0.7 * float(np.sqrt(area / len(col)))


def _closed_mask(hit: np.ndarray, half: int) -> np.ndarray:
    """The marked pixels closed by a square of half-width ``half`` (0: as they are), holes filled; the closing by
    the compiled twin :func:`symfruit.core._jit.close_square` where numba is installed (the same pixels)."""
    closed = hit
    if half > 0 and hit.ndim == 2 and hit.dtype == bool and (jit := compiled()) is not None:
        closed = np.empty(hit.shape, dtype=bool)
        jit.close_square(hit, half, closed)
    elif half > 0:
        # Closing by a square, as box means: dilation = any hit in the square, erosion = all dilated.
        # "nearest" keeps a silhouette that the image edge cuts from being eroded there.
        size = 2 * half + 1
        weight = ndimage.uniform_filter(hit.astype(np.float32), size=size, mode="constant")
        dilated = (weight > 1e-6).astype(np.float32)
        closed = ndimage.uniform_filter(dilated, size=size, mode="nearest") > 1.0 - 1e-3
        closed |= hit
    # Fill holes: background components (4-connected) not touching the window's edge.
    return fill_holes(closed)


@dataclass(frozen=True)
class Silhouette:
    """The region the seen points cover in an image window whose top-left pixel is ``(u0, v0)``.

    Attributes
    ----------
    u0, v0 : int
    mask : (h, w) bool
    fill_radius : float, pixels
        Half-width of the square that closed the gaps between points (0: none).
    """

    u0: int
    v0: int
    mask: np.ndarray
    fill_radius: float
    #: What :func:`silhouette_cone`, :func:`across_sight` and :func:`outline_cracks` work out of the mask alone,
    #: made once per region and read-only (no code changes a region's mask in place once the region holds it).
    _made: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)


def point_pixels(points: np.ndarray, camera: Camera) -> tuple[np.ndarray, np.ndarray] | None:
    """``(col (n,), row (n,))`` int64: the pixel of each of ``points`` (n, 3) float64, C-ordered (as
    :func:`~symfruit.core.points.as_points` gives them), :meth:`~symfruit.core.camera.Camera.project`'s coordinates
    rounded half to even, by the compiled kernel :func:`symfruit.core._jit.point_pixels`: one projection of a view's
    points that :func:`silhouette`, :func:`symfruit.core.agreement.observe` and
    :func:`symfruit.methods.evidence.rim_coverage` share (each projected the points itself before; issue 19, stop
    40). None where numba is not installed (or the points are not such an array): each of them projects its own."""
    if (points.ndim == 2 and points.shape[1] == 3 and points.dtype == np.float64 and points.flags.c_contiguous
            and len(points) and (jit := compiled()) is not None):  # fmt: skip
        col, row = jit.point_pixels(points, float(camera.fx), float(camera.fy), float(camera.cx), float(camera.cy))
        return col, row
    return None


def silhouette(
    points: np.ndarray, camera: Camera, *, pad: int = 8, fill_radius: float | None = None,
    pixels: tuple[np.ndarray, np.ndarray] | None = None,
) -> Silhouette:  # fmt: skip
    """The seen region of one fruit: every point's pixel, gaps between neighbouring points closed, holes
    filled, in a window ``pad`` pixels wider than the region on every side (clipped to the image).

    Parameters
    ----------
    points : (n, 3) float, metres, z > 0
    camera : Camera
    pad : int, pixels
        Margin around the region (at least as wide as any band of pixels outside it that is examined).
    fill_radius : float, pixels, optional
        Default: as :func:`rasterise` (``0.7 sqrt(area / n)``) for a sparse cloud, and 0 (every pixel as
        it is) once there is a point for at least every second pixel of the region (a depth camera).
    pixels : ((n,), (n,)) int, optional
        The points' pixels (:func:`point_pixels`), when known: used where every one lies in the image (the same
        pixels as projecting the points again).

    Raises
    ------
    InputError
        When no point projects into the image.
    """
    box: tuple[int, int, int, int] | None = None
    jit = compiled()
    if pixels is not None and jit is not None and len(pixels[0]) == len(points) and len(pixels[0]):
        c0, c1, r0, r1 = jit.pixel_box(pixels[0], pixels[1])
        if c0 >= 0 and r0 >= 0 and c1 < camera.width and r1 < camera.height:  # all in the image: _pixels' own
            (col, row), box = pixels, (int(c0), int(c1), int(r0), int(r1))
    if box is None:
        col, row, _ = _pixels(as_points(points, min_count=1), camera)
        if jit is not None:  # the four reductions in one compiled pass (the same whole numbers)
            b = jit.pixel_box(col, row)
            box = (int(b[0]), int(b[1]), int(b[2]), int(b[3]))
        else:
            box = int(col.min()), int(col.max()), int(row.min()), int(row.max())  # once (np.ptp and _window's own)
    if fill_radius is None:
        area = np.pi / 4.0 * (box[1] - box[0] + 1) * (box[3] - box[2] + 1)  # _default_fill's ellipse
        fill_radius = 0.7 * float(np.sqrt(area / len(col))) if len(col) < 0.5 * area else 0.0
    half = int(np.ceil(fill_radius))
    u0, v0, h, w = _window(col, row, camera, pad + half + 2, box)
    if jit is not None:  # the marks by the compiled kernel (the same pixels)
        hit = jit.mark_pixels(col, row, u0, v0, h, w)
    else:
        hit = np.zeros((h, w), dtype=bool)
        hit.ravel()[(row - v0) * w + (col - u0)] = True  # by flat index: twice as fast as two index arrays
    return Silhouette(u0, v0, _closed_mask(hit, half), float(fill_radius))


def close_ragged(region: Silhouette, *, radius: int = 3, ragged: float = 0.3) -> Silhouette:
    """The region with the gaps of a ragged outline closed, or as it is.

    A depth sensor drops pixels at the rim (mixed and grazing pixels), so a dense view's outline recedes
    in a ragged way; closing by a square of half-width ``radius`` fills those gaps, but would also round a
    clean outline's concave corners. So the closing is kept only when it adds more than ``ragged`` pixels
    per outline pixel (a clean render's outline gains about 0.15, the repository's D435 model's 0.4 and
    more).

    Parameters
    ----------
    region : Silhouette
    radius : int, pixels
    ragged : float
    """
    mask = region.mask
    if radius <= 0 or not mask.any():
        return region
    if mask.ndim == 2 and mask.dtype == bool and (jit := compiled()) is not None:  # the compiled twin of what follows
        closed, added, outline = jit.close_ragged(np.ascontiguousarray(mask), int(radius))
        if added <= ragged * max(outline, 1):
            return region
        return Silhouette(region.u0, region.v0, closed, max(region.fill_radius, float(radius)))
    padded = np.zeros((mask.shape[0] + 2 * radius, mask.shape[1] + 2 * radius), dtype=bool)  # np.pad is slow
    padded[radius:-radius, radius:-radius] = mask
    closed = _closed_mask(padded, radius)[radius:-radius, radius:-radius]
    outline = int((mask & ~interior(mask)).sum())
    if (closed & ~mask).sum() <= ragged * max(outline, 1):
        return region
    return Silhouette(region.u0, region.v0, closed, max(region.fill_radius, float(radius)))


def silhouette_cone(region: Silhouette, camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    """The viewing cone of the ellipse with the silhouette's area moments: ``(cone (3, 3), axis (3,))``.

    The ellipse with the region's centroid and second moments (each pixel a unit square: its covariance
    plus 1/12) is exact for an elliptic silhouette and a robust summary of any other. In normalised
    image coordinates ``x = ((u - cx) / fx, (v - cy) / fy, 1)`` the cone is ``x^T C x = 0``, negative
    inside, scaled to a largest eigenvalue of magnitude 1; ``axis`` is the ray through the centroid.
    """
    _, mu, cov = _moments(region)
    scaled = 4.0 * (cov + _TWELFTH)
    inv = inverse2(scaled)  # numpy's inv to the bit, without LAPACK's call
    if inv is None:
        inv = np.linalg.inv(scaled)
    conic = np.zeros((3, 3))
    conic[:2, :2] = inv
    conic[:2, 2] = conic[2, :2] = -inv @ mu
    conic[2, 2] = mu @ inv @ mu - 1.0
    return _image_cone(conic, mu, camera)


def inverse2(a: np.ndarray) -> np.ndarray | None:
    """(2, 2) float: ``np.linalg.inv(a)`` of a 2x2 float64 matrix as OpenBLAS's ``dgesv`` works it out with the identity
    on the right (partial pivoting; the column below the pivot and both triangular solves multiplied by the pivots'
    reciprocals, as its ``trsm`` does for more than one right-hand side): the same values bit for bit (tested against
    numpy), in Python floats, about 2 us against the call's 10-20 (issue 19, stop 41). None where a value is not
    finite or beyond :func:`~symfruit.core.fits._plain`'s range, or a pivot is exactly zero: ask numpy there (it
    raises on the last)."""
    a00, a01, a10, a11 = a.ravel().tolist()
    if not _plain(a00, a01, a10, a11):
        return None
    swap = abs(a10) > abs(a00)
    if swap:
        a00, a01, a10, a11 = a10, a11, a00, a01
    if a00 == 0.0:
        return None
    r00 = 1.0 / a00
    low = a10 * r00
    u11 = a11 - low * a01
    if u11 == 0.0:
        return None
    r11 = 1.0 / u11
    # the identity's columns, rows swapped as the pivot swapped them
    b0, b1 = (0.0, 1.0) if swap else (1.0, 0.0)
    x1 = (b1 - low * b0) * r11
    y1 = (b0 - low * b1) * r11  # the second column's (b0 and b1 exchanged)
    return np.array([[(b0 - a01 * x1) * r00, (b1 - a01 * y1) * r00], [x1, y1]])


#: ``np.eye(2) / 12.0`` (a pixel's own covariance), made once.
_TWELFTH = np.eye(2) / 12.0
_TWELFTH.flags.writeable = False


def _covariance(m: np.ndarray) -> np.ndarray:
    """``np.cov(m)`` of a real ``(k, n)`` array ``m`` (its rows the variables, ``k >= 2``, ``n >= 2``): (k, k)
    float. numpy's own steps (a float64 copy of ``m`` as ``np.array`` makes it, the rows' means, the product of the
    centred rows with their transpose, scaled by ``1 / (n - 1)``) without its checks of weights and arguments:
    the same values to the bit, 10 against 15 us on 300 points (issue 19, stop 61).

    >>> m = np.array([[0.0, 1.0, 2.0, 4.0], [1.0, 3.0, 2.0, 0.5]])
    >>> bool(np.array_equal(_covariance(m), np.cov(m)))
    True
    """
    x = np.array(m, dtype=np.float64)
    x -= x.mean(axis=1)[:, None]
    c = np.dot(x, x.T)
    c *= np.true_divide(1, x.shape[1] - 1)
    return c


def _moments(region: Silhouette) -> tuple[float, np.ndarray, np.ndarray]:
    """``(n, centroid (2,), covariance (2, 2))`` of a region's pixels (image coordinates ``u, v``; the covariance
    of the pixel centres), made once per region: :func:`silhouette_cone` and :func:`across_sight` both read them
    (kept read-only; an empty region's are NaN, not kept)."""
    found = region._made.get("moments")
    if found is not None:
        return found
    m = region.mask.astype(np.float64)
    h, w = m.shape
    u = np.arange(w, dtype=np.float64) + region.u0
    v = np.arange(h, dtype=np.float64) + region.v0
    col_sums, row_sums = m.sum(axis=0), m.sum(axis=1)
    n = col_sums.sum()
    mu = np.array([col_sums @ u, row_sums @ v]) / n
    du, dv = u - mu[0], v - mu[1]
    cross = dv @ m @ du  # once: the same product twice was a second pass over the window
    cov = np.array([[col_sums @ (du * du), cross], [cross, row_sums @ (dv * dv)]]) / n
    if n > 0:
        mu.flags.writeable = cov.flags.writeable = False
        region._made["moments"] = (float(n), mu, cov)
    return float(n), mu, cov


def mask_box(mask: np.ndarray) -> tuple[int, int, int, int] | None:
    """``(row_start, row_stop, col_start, col_stop)`` of a bool image's true pixels (stops exclusive, as slices
    take them); None when there are none. Two reductions along the axes, not the coordinates of every pixel.

    >>> m = np.zeros((6, 8), bool); m[1:3, 2:7] = True
    >>> mask_box(m)
    (1, 3, 2, 7)
    """
    if type(mask) is np.ndarray and mask.ndim == 2 and mask.dtype == bool and mask.flags.c_contiguous:
        if (jit := compiled()) is not None:  # the compiled twin (the same whole numbers; issue 19, stop 53)
            found, r0, r1, c0, c1 = jit.mask_box(mask)
            return (r0, r1, c0, c1) if found else None
    return _mask_box(mask)


def _mask_box(mask: np.ndarray) -> tuple[int, int, int, int] | None:
    """:func:`mask_box` by numpy: the numpy twin of :func:`symfruit.core._jit.mask_box`."""
    # the ufunc's reduction and nonzero() directly: the method and np.flatnonzero add their wrappers' calls
    rows, cols = np.logical_or.reduce(mask, axis=1).nonzero()[0], np.logical_or.reduce(mask, axis=0).nonzero()[0]
    if not len(rows):
        return None
    return int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1


def inner_distance(
    mask: np.ndarray, reach: float | None = None, *, box: tuple[int, int, int, int] | None = None
) -> np.ndarray:
    """(h, w) float, pixels: ``ndimage.distance_transform_edt(mask)`` (each mask pixel's distance to the nearest
    pixel outside it), transformed over the mask's box grown by a pixel (clipped to the image) alone: a pixel on
    that grown border in the row or column of any farther background pixel is nearer, so the distances are the
    same, and a mask in a wide window costs its own box.

    ``reach`` (pixels, >= 0): only the distances up to it are wanted; they are the same, to the bit, and farther
    ones are +inf (:func:`_near_distance`'s shifts instead of scipy's transform: 0.24 against 0.40 ms for a disc
    134 px across at 10.5 px; issue 19, seventh round). ``box``: the mask's :func:`mask_box` when known (not
    worked out again)."""
    out = np.zeros(mask.shape)
    if (box := mask_box(mask) if box is None else box) is None:
        return out
    r0, r1 = max(box[0] - 1, 0), min(box[1] + 1, mask.shape[0])
    c0, c1 = max(box[2] - 1, 0), min(box[3] + 1, mask.shape[1])
    part = mask[r0:r1, c0:c1]
    if reach is None or part.all():  # no pixel outside the mask in reach of the shifts: the whole map
        out[r0:r1, c0:c1] = distance_transform(part)
    elif (jit := compiled()) is not None:  # the compiled twin of _near_distance, into the map itself
        jit.near_distance(part, float(reach), False, out[r0:r1, c0:c1])
    else:
        out[r0:r1, c0:c1] = _near_distance(~part, reach)
    return out


def distance_maps(mask: np.ndarray, inner_reach: float, outer_reach: float) -> tuple[np.ndarray, np.ndarray]:
    """``(inner_distance(mask, inner_reach), outer_distance(mask, outer_reach))`` (both (h, w) float, pixels), the
    mask's box worked out once for both. Where numba is installed and ``mask`` is a 2-D bool image, by one compiled
    call (:func:`symfruit.core._jit.observe_maps`: the box and both maps' :func:`_near_distance` in place; the same
    pixels and values; issue 19, stop 50), unless the mask is empty or its box grown by a pixel holds no pixel outside
    it (the twins' other paths)."""
    if mask.ndim == 2 and mask.dtype == bool and (jit := compiled()) is not None:
        done, inner, outer = jit.observe_maps(mask, float(inner_reach), float(outer_reach))
        if done:
            return inner, outer
    box = mask_box(mask)
    return inner_distance(mask, inner_reach, box=box), outer_distance(mask, outer_reach, box=box)


def distance_transform(image: np.ndarray) -> np.ndarray:
    """(h, w) float, pixels: ``ndimage.distance_transform_edt(image)`` of a 2-D image (each true pixel's distance to
    the nearest false one, 0 on those), by its compiled twin where there is one and the image holds a false pixel
    (:func:`symfruit.core._jit.distance`, Meijster's exact transform in whole numbers: the same squared distances
    and square roots, so scipy's values to the bit, 5-7x faster on a fruit's window; issue 19, twelfth round)."""
    image = np.asarray(image, dtype=bool)
    if image.ndim == 2 and image.size and (jit := compiled()) is not None and not image.all():
        out = np.empty(image.shape)
        jit.distance(image, False, out)
        return out
    return np.asarray(ndimage.distance_transform_edt(image))


def nearest_index(image: np.ndarray) -> np.ndarray:
    """(h, w) int: each pixel's flat index (``row * w + col``) of the false pixel of a 2-D ``image`` nearest to it,
    the one ``ndimage.distance_transform_edt(image, return_distances=False, return_indices=True)`` picks (``image``
    must hold a false pixel). By its compiled twin where there is one (:func:`symfruit.core._jit.nearest`: scipy's
    feature transform written out, its choices among equally near pixels included, so the same pixels; 0.44
    against 1.0 ms on a 230 px occlusion window; issue 19, fourteenth round), else by scipy's."""
    image = np.asarray(image, dtype=bool)
    if image.ndim == 2 and image.size and (jit := compiled()) is not None:
        out = np.empty(image.shape, np.int64)
        jit.nearest(image, out)
        return out
    ri, ci = ndimage.distance_transform_edt(image, return_distances=False, return_indices=True)
    return ri * image.shape[1] + ci


def outer_distance(mask: np.ndarray, reach: float, *, box: tuple[int, int, int, int] | None = None) -> np.ndarray:
    """(h, w) float, pixels: ``ndimage.distance_transform_edt(~mask)`` (each pixel's distance to the nearest mask
    pixel) wherever that is at most ``reach``, +inf wherever it is farther. An empty mask: scipy's map.

    Worked out over the mask's box grown by ``ceil(reach) + 1`` pixels (clipped to the image) by
    :func:`_near_distance`, not by scipy's whole transform (issue 19, seventh round: 0.25 against 0.73 ms for a
    150 px window at the bands' reach of 5.5 px; the same values within reach, to the bit). ``box``: the mask's
    :func:`mask_box` when known (an empty mask's is worked out again)."""
    if (box := mask_box(mask) if box is None else box) is None:
        return ndimage.distance_transform_edt(~mask)
    m = int(np.ceil(reach)) + 1
    out = np.full(mask.shape, np.inf)
    r0, r1 = max(box[0] - m, 0), min(box[1] + m, mask.shape[0])
    c0, c1 = max(box[2] - m, 0), min(box[3] + m, mask.shape[1])
    if (jit := compiled()) is not None:  # the compiled twin of _near_distance, into the map itself
        jit.near_distance(mask[r0:r1, c0:c1], float(reach), True, out[r0:r1, c0:c1])
    else:
        out[r0:r1, c0:c1] = _near_distance(mask[r0:r1, c0:c1], reach)
    return out


def _near_distance(mask: np.ndarray, reach: float) -> np.ndarray:
    """(h, w) float: each pixel's Euclidean distance to the nearest true pixel of ``mask`` where that is at most
    ``reach`` (``reach >= 0``), +inf elsewhere.

    A true pixel within ``reach`` lies at most ``k = floor(reach)`` rows and columns away, so: each pixel's
    distance along its column to the nearest true pixel, ``g``, by ``k`` shifts up and down (capped at ``k +
    1``: farther is beyond reach), then ``min over |t| <= k of g(c + t)^2 + t^2`` by ``k`` shifts left and right.
    Every term is the squared distance to a true pixel or at least ``(k + 1)^2 > reach^2``, and the nearest
    true pixel's term is among them when it is within reach: the squared distance, a whole number, is exact
    there, and its square root is scipy's (which takes the root of the same whole number). 4k + 2 passes over
    small integers instead of scipy's feature transform (a few hundred instructions a pixel). Where numba is
    installed, :func:`inner_distance` and :func:`outer_distance` run its compiled twin
    (:func:`symfruit.core._jit.near_distance`: the same whole numbers and roots, so the same values to the bit).
    """
    h, w = mask.shape
    k = int(np.floor(reach))
    cap = k + 1
    kind = np.int16 if cap * cap + k * k < np.iinfo(np.int16).max else np.int64
    base = np.where(mask, 0, cap).astype(kind)  # 0 on the mask, beyond reach elsewhere
    g = base.copy()
    for s in range(1, min(cap, h)):  # row offsets up to the reach, not a loop over pixels
        np.minimum(g[s:], base[:-s] + kind(s), out=g[s:])
        np.minimum(g[:-s], base[s:] + kind(s), out=g[:-s])
    g2 = g * g
    d2 = g2.copy()
    for t in range(1, min(k, w - 1) + 1):  # column offsets up to the reach
        np.minimum(d2[:, t:], g2[:, :-t] + kind(t * t), out=d2[:, t:])
        np.minimum(d2[:, :-t], g2[:, t:] + kind(t * t), out=d2[:, :-t])
    out = np.sqrt(d2, dtype=np.float64)
    out[d2 > reach * reach] = np.inf
    return out


def interior(mask: np.ndarray) -> np.ndarray:
    """(h, w) bool: ``ndimage.binary_erosion(mask)`` (the pixels whose 4 neighbours are in the mask; pixels beyond
    the array are not), by five shifted views of the padded mask instead of scipy's general structuring element
    (3x faster); ``mask & ~interior(mask)`` is its outline."""
    p = np.zeros((mask.shape[0] + 2, mask.shape[1] + 2), dtype=bool)  # padded by hand: np.pad is slow
    p[1:-1, 1:-1] = mask
    return p[1:-1, 1:-1] & p[:-2, 1:-1] & p[2:, 1:-1] & p[1:-1, :-2] & p[1:-1, 2:]


def eroded(mask: np.ndarray, iterations: int) -> np.ndarray:
    """(h, w) bool: ``ndimage.binary_erosion(mask, iterations=iterations)`` (``iterations >= 1``; the cross, pixels
    beyond the array not in the mask): :func:`interior` that many times while that is faster (a few erosions of a
    fruit's box, each some 5 us against scipy's 30 us a call), scipy's iterated erosion beyond."""
    if iterations > 4:
        return np.asarray(ndimage.binary_erosion(mask, iterations=iterations))
    out = np.asarray(mask, dtype=bool)
    for _ in range(iterations):
        out = interior(out)
    return out


def square_filter(mask: np.ndarray, radius: int, *, every: bool = False) -> np.ndarray:
    """(h, w) bool: the pixels of ``mask`` (h, w) bool with a true pixel within the ``2 radius + 1`` square about
    them (``every``: with the whole square true), outside the image false: ``ndimage.maximum_filter`` (or
    ``minimum_filter``) with ``mode="constant"``, or its compiled twin (:func:`symfruit.core._jit.square_filter`, the
    same pixels) where numba is installed."""
    if (jit := compiled()) is not None:
        out = np.empty(mask.shape, dtype=bool)
        jit.square_filter(mask, radius, every, out)
        return out
    filt = ndimage.minimum_filter if every else ndimage.maximum_filter
    return np.asarray(filt(mask, size=2 * radius + 1, mode="constant", cval=False))


def fill_holes(mask: np.ndarray) -> np.ndarray:
    """(h, w) bool: ``mask`` with its holes filled, the same as :func:`scipy.ndimage.binary_fill_holes`.

    A hole is a 4-connected piece of the background that does not reach the image border; scipy finds them by
    dilating the background from the border until nothing changes (one pass over the image per pixel of the
    longest path), one labelling finds them at once.

    The labelling covers the mask's box grown by a pixel (clipped to the image) alone: every background pixel
    outside the box reaches the border along its row or column, so a piece of the background inside the grown
    box is a hole exactly when it does not reach the grown box's edge (whose pixels beyond the mask's box are
    background that reaches the border), and a silhouette's window is often twice its box. Where numba is, a flood
    fill of the background from the grown box's edge (:func:`symfruit.core._jit.filled`) replaces the labelling.
    """
    mask = np.asarray(mask, dtype=bool)
    out = mask.copy()
    if (box := mask_box(mask)) is None:
        return out
    r0, r1 = max(box[0] - 1, 0), min(box[1] + 1, mask.shape[0])
    c0, c1 = max(box[2] - 1, 0), min(box[3] + 1, mask.shape[1])
    if (jit := compiled()) is not None:  # the compiled twin of the labelling that follows: the same pixels
        jit.filled(mask[r0:r1, c0:c1], out[r0:r1, c0:c1])
        return out
    lab, n = ndimage.label(~mask[r0:r1, c0:c1])
    if n == 0:
        return out
    outside = np.zeros(n + 1, bool)
    for edge in (lab[0], lab[-1], lab[:, 0], lab[:, -1]):
        outside[edge] = True
    outside[0] = True  # the mask's own pixels: kept as they are
    out[r0:r1, c0:c1] |= ~np.take(outside, lab)  # a table look-up: np.take is twice as fast as outside[lab]
    return out


def principal_widths(mask: np.ndarray, *, origin: tuple[int, int] = (0, 0)) -> tuple[float, float]:
    """``(minor, major)``, pixels: a region's widths across and along its principal axis.

    The extents of the region's pixels projected on the two eigenvectors of their covariance, each pixel
    counted whole (``np.ptp + 1``): for a solid of revolution whose axis lies in the image plane the minor
    width is the diameter of its widest cross-section, which is also its depth extent.

    Examples
    --------
    >>> m = np.zeros((9, 20), bool); m[2:7, 3:17] = True
    >>> principal_widths(m)
    (5.0, 14.0)

    ``origin`` (row, column) is where ``mask`` lies in a larger image: the pixels are taken at that image's
    coordinates (a window cut around a mask gives the same widths, bit for bit, as the whole image).
    """
    mask = np.asarray(mask)
    jit = compiled()
    if mask.dtype == bool and mask.ndim == 2 and jit is not None:
        # the centred coordinates by their compiled twin (issue 19, seventeenth round: the same array, bit for bit);
        # fewer than two pixels give none, as the twin's count (stop 62, surf62: no count of the mask before it)
        xy = jit.centred_pixels(mask, int(origin[0]), int(origin[1]))
        if len(xy) < 2:
            n = float(np.count_nonzero(mask))
            return n, n
    else:
        rows, cols = np.nonzero(mask)
        if origin != (0, 0):
            rows, cols = rows + origin[0], cols + origin[1]
        if len(rows) < 2:
            return float(len(rows)), float(len(rows))
        xy = np.empty((len(rows), 2))
        xy[:, 0], xy[:, 1] = cols, rows
        # the column means from whole-number sums (exact in any order, as numpy's are): xy.mean(axis=0) bit for bit
        xy -= np.array([int(cols.sum()), int(rows.sum())], dtype=np.float64) / len(rows)
    _, vec = lapack.eigh(xy.T @ xy)  # np.linalg.eigh without its wrapper: the same LAPACK call (stop 45)
    p = xy @ vec
    if jit is not None and p.dtype == np.float64:  # both extents in one pass (stop 46: the same)
        minor, major = jit.column_extents(p)
        return float(minor + 1.0), float(major + 1.0)
    return float(np.ptp(p[:, 0]) + 1.0), float(np.ptp(p[:, 1]) + 1.0)


@dataclass(frozen=True)
class Across:
    """A region's extent across the line of sight through its centroid (:func:`across_sight`).

    Attributes
    ----------
    axis : (3,) float
        Unit ray through the region's centroid.
    basis : (2, 3) float
        Unit vectors ``e1`` (in the plane of ``axis`` and the camera's x axis) and ``e2``, both perpendicular
        to ``axis``.
    lo, hi : (2,) float
        The outline's least and greatest tangent coordinates along ``e1`` and ``e2``: a point at distance
        ``D`` along ``axis`` and these coordinates ``(s, t)`` is ``D (axis + s e1 + t e2)``.
    minor, major : float
        Widths across and along the outline's principal axis in tangent coordinates (times ``D``: metres).
    """

    axis: np.ndarray
    basis: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    minor: float
    major: float


def across_sight(region: Silhouette, camera: Camera) -> Across:
    """How wide a region is across the line of sight rather than in the image plane.

    A fruit off the optical axis projects stretched along the direction away from the image centre (by
    ``1 / cos`` of its angle off the axis: 1.25 at 37 deg, the edge of a 90 deg camera), so its pixel
    widths times its depth over the focal length overstate its width. Here the outline's pixel-edge points
    (:func:`outline_cracks`, the exact boundary of the pixel squares) are taken to the plane perpendicular
    to the ray through the region's centroid (tangent coordinates, the ray's distance 1); their widths
    along the principal axes of the region's pixels there, times the fruit's distance along that ray, are
    its widths across the line of sight (a sphere's: its diameter, anywhere in the image).

    Examples
    --------
    >>> cam = Camera(fx=500.0, fy=500.0, cx=50.0, cy=50.0, width=100, height=100)
    >>> m = np.zeros((100, 100), bool); m[40:60, 45:55] = True
    >>> a = across_sight(Silhouette(0, 0, m, 0.0), cam)
    >>> round(a.minor * 500, 3), round(a.major * 500, 3)
    (10.0, 20.0)
    """
    if not region.mask.any():
        raise InputError("the region is empty")
    _, mu, cov = _moments(region)
    if (jit := compiled()) is not None:  # the compiled twin of what follows but the eigh: the same values
        intrinsics = (float(camera.cx), float(camera.cy), float(camera.fx), float(camera.fy))
        axis, basis, carried = jit.across_frame(float(mu[0]), float(mu[1]), cov, *intrinsics)
        _, vec = lapack.eigh(carried)
        lo, hi, minor, major = jit.across_extent(outline_cracks(region), axis, basis, np.ascontiguousarray(vec),
                                                 *intrinsics)  # fmt: skip
        return Across(axis, basis, lo, hi, float(minor), float(major))
    axis = camera.rays(mu[0], mu[1]).reshape(3)
    axis = axis / np.linalg.norm(axis)
    e1 = np.array([axis[2], 0.0, -axis[0]])
    e1 /= np.linalg.norm(e1)
    basis = np.array([e1, cross_rows(axis, e1)])

    def tangent(uu: np.ndarray, vv: np.ndarray) -> np.ndarray:
        r = camera.rays(uu, vv).reshape(-1, 3)
        return (r @ basis.T) / (r @ axis)[:, None]

    # The principal axes from the pixels' covariance carried to tangent coordinates by the map's Jacobian at
    # the centroid (the map is projective: over one fruit's pixels, linear to well under a pixel).
    t0, tu, tv = tangent(mu[0] + np.array([0.0, 1.0, 0.0]), mu[1] + np.array([0.0, 0.0, 1.0]))
    jac = np.stack((tu - t0, tv - t0), axis=1)
    _, vec = np.linalg.eigh(jac @ cov @ jac.T)
    edge = tangent(*outline_cracks(region).T)
    p = edge @ vec
    return Across(axis, basis, edge.min(axis=0), edge.max(axis=0), float(np.ptp(p[:, 0])), float(np.ptp(p[:, 1])))


def tangent_extent(points: np.ndarray, across: Across, camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    """The least and greatest tangent coordinates of outline ``points`` ((m, 2) float, pixels) in ``across``' frame
    (its ray and basis), as :func:`across_sight` reads its region's outline: ``(lo, hi)``, each (2,).

    >>> cam = Camera(fx=500.0, fy=500.0, cx=50.0, cy=50.0, width=100, height=100)
    >>> m = np.zeros((100, 100), bool); m[40:60, 45:55] = True
    >>> a = across_sight(Silhouette(0, 0, m, 0.0), cam)
    >>> lo, hi = tangent_extent(outline_cracks(Silhouette(0, 0, m, 0.0)), a, cam)
    >>> bool(np.allclose(lo, a.lo) and np.allclose(hi, a.hi))
    True
    """
    pts = np.asarray(points, dtype=np.float64)
    r = camera.rays(pts[:, 0], pts[:, 1]).reshape(-1, 3)
    t = (r @ across.basis.T) / (r @ across.axis)[:, None]
    return t.min(axis=0), t.max(axis=0)


def width_across(region: Silhouette, across: Across, camera: Camera, gravity: np.ndarray) -> float | None:
    """The region's width across ``gravity`` (a camera-frame vector, REP-103: a level camera's is ``(0, 1, 0)``)
    in ``across``' tangent units (times the distance: metres): its outline's extent along the direction across the
    line of sight and across gravity (``axis x gravity``, horizontal), as :func:`across_sight` reads its widths;
    None where gravity lies along the line of sight (within a degree: a fruit seen from straight above or below).

    A fruit hanging from its stalk is (near) a solid of revolution about the vertical, so it is as deep along a
    level line of sight as it is wide across gravity, oblate or prolate alike (issue 18, docs/hang65.md).

    >>> cam = Camera(fx=500.0, fy=500.0, cx=50.0, cy=50.0, width=100, height=100)
    >>> m = np.zeros((100, 100), bool); m[40:60, 45:55] = True
    >>> a = across_sight(Silhouette(0, 0, m, 0.0), cam)
    >>> down = np.array([0.0, 1.0, 0.0])
    >>> round(width_across(Silhouette(0, 0, m, 0.0), a, cam, down) * 500, 3)
    10.0
    >>> round(width_across(Silhouette(0, 0, m, 0.0), a, cam, np.array([1.0, 0.0, 0.0])) * 500, 3)
    20.0
    >>> width_across(Silhouette(0, 0, m, 0.0), a, cam, np.array([0.0, 0.0, 1.0])) is None
    True
    """
    g = np.asarray(gravity, dtype=np.float64).reshape(3)
    d = cross_rows(across.axis, g)
    norm = float(np.linalg.norm(d))
    if norm <= math.sin(math.radians(1.0)) * float(np.linalg.norm(g)):
        return None
    c = across.basis @ (d / norm)  # the direction in tangent coordinates (e1, e2): a unit vector in their plane
    pts = outline_cracks(region)
    r = camera.rays(pts[:, 0], pts[:, 1]).reshape(-1, 3)
    t = (r @ across.basis.T) / (r @ across.axis)[:, None]
    return float(np.ptp(t @ c))


def _image_cone(conic: np.ndarray, centre: np.ndarray, camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    """An image conic (negative inside) as a viewing cone scaled to a largest eigenvalue of magnitude 1, and
    the ray through ``centre`` (pixels)."""
    k = camera.matrix
    cone = k.T @ conic @ k
    axis = camera.rays(centre[0], centre[1])
    return cone / np.abs(lapack.eigvalsh(cone)).max(), axis


def cone_widths(cone: np.ndarray, axis: np.ndarray) -> tuple[float, float] | None:
    """``(minor, major)``, tangent units (times the distance: metres): the widths of a viewing cone
    (:func:`silhouette_cone`, :func:`outline_cone`: ``x^T C x = 0``, negative inside) across the line of sight along
    ``axis``, along its two principal axes there, as :func:`across_sight` measures a region's; None where the cone
    does not cut the plane perpendicular to ``axis`` in an ellipse.

    >>> cam = Camera(fx=500.0, fy=500.0, cx=50.0, cy=50.0, width=100, height=100)
    >>> m = np.zeros((100, 100), bool); m[40:60, 45:55] = True
    >>> minor, major = cone_widths(*silhouette_cone(Silhouette(0, 0, m, 0.0), cam))
    >>> round(minor * 500, 1), round(major * 500, 1)  # the moment ellipse of a 10 x 20 rectangle
    (11.5, 23.1)
    """
    a = np.asarray(axis, dtype=np.float64).reshape(3)
    a = a / np.linalg.norm(a)
    e1 = np.array([a[2], 0.0, -a[0]])
    e1 /= np.linalg.norm(e1)
    b = np.column_stack((a, e1, np.cross(a, e1)))
    c = b.T @ np.asarray(cone, dtype=np.float64) @ b  # the cone in the plane's coordinates (1, s, t)
    m, lin = c[1:, 1:], c[1:, 0]
    eig = np.linalg.eigvalsh(m)
    if not np.isfinite(eig).all() or eig[0] <= 0.0:
        return None
    centre = -np.linalg.solve(m, lin)
    k = float(centre @ m @ centre - c[0, 0])
    if not k > 0.0:
        return None
    return float(2.0 * np.sqrt(k / eig[1])), float(2.0 * np.sqrt(k / eig[0]))


def free_side_stretch(cracks: np.ndarray, free: np.ndarray, cone: np.ndarray, camera: Camera,
                      region: Silhouette | None = None, *, tie_px: float = 1.0) -> float:  # fmt: skip
    """How much wider a cut outline's fruit is than the region seen of it: the geometric mean, over the region's two
    principal axes (pixels), of the fruit's extent along the axis over the region's; at least 1.

    ``cracks`` (m, 2) float: the region's outline (pixels, :func:`outline_cracks`); ``free`` (m,) bool: which of it
    is the fruit's own contour (the rest an occluder's or the image border's edge); ``cone``: the viewing cone of the
    ellipse fitted to the free part (:func:`outline_cone`). On each side of each axis, the outline points within
    ``tie_px`` of the region's outermost there decide: mostly free, the fruit ends where the region does (its own
    contour is seen there, and the ellipse's extent is not read); else the fruit goes on behind the cut, to the farther
    of the region's side and the ellipse's, but no farther than makes the axis as long as the region's widest extent
    (an ellipse fitted to part of an outline is least sure across the part it lacks: a peach's free arcs, its cheek
    and suture, gave it 114 px across a cut region 90 px wide, against 98 px along the uncut axis, 99 seen). A leaf
    over a third of a disc (its left side) leaves the vertical extent and the right side seen: only the left side is
    the ellipse's, and an ellipse fitted long or wide on noisy arcs changes nothing where the outline is free. 1.0
    where nothing is cut, the ellipse is not one, or (``region`` given: the outline's region) the ellipse's centre
    lies outside the region: a round fruit's nearest point is then hidden, and a front read from the seen points lies
    behind the fruit's.

    >>> cam = Camera(fx=500.0, fy=500.0, cx=50.0, cy=50.0, width=100, height=100)
    >>> t = np.linspace(0.0, 2.0 * np.pi, 720, endpoint=False)
    >>> disc = np.column_stack((50.0 + 20.0 * np.cos(t), 50.0 + 20.0 * np.sin(t)))
    >>> cut = disc[:, 0] < 44.0  # the left 35 % hidden, the cut along u = 44
    >>> disc[cut, 0] = 44.0
    >>> conic = np.array([[1.0, 0.0, -50.0], [0.0, 1.0, -50.0], [-50.0, -50.0, 5000.0 - 400.0]])
    >>> round(free_side_stretch(disc, ~cut, cam.matrix.T @ conic @ cam.matrix, cam) ** 2, 3)  # 40 / 26 px, 40 / 40
    1.538
    """
    return free_side_reach(cracks, free, cone, camera, region, tie_px=tie_px)[0]


def free_side_reach(
    cracks: np.ndarray, free: np.ndarray, cone: np.ndarray, camera: Camera, region: Silhouette | None = None,
    *, tie_px: float = 1.0,
) -> tuple[float, np.ndarray | None]:  # fmt: skip
    """:func:`free_side_stretch` and the fruit's whole outline it reads: ``(stretch, outline)``, ``outline`` (m, 2)
    float pixels or None where nothing moves (the stretch 1). The outline is ``cracks`` and, on each cut side that
    goes on behind the cut, the ellipse's outermost point along the axis there: where the fruit ends on that side
    (capped as the stretch is, the point then drawn towards the ellipse's centre along the diameter conjugate to the
    axis; where both sides of an axis are cut the cap shares the extra length between them in proportion). Its extent
    is the fruit's on every side: the seen contour's on a free side, the ellipse's on a cut one (a leaf over a disc's
    left third: the disc's leftmost point added, the rest as seen). One point a side, not the cut edge moved: a
    chord carried out along an oblique axis would stick out past the ellipse across it."""
    pts = np.asarray(cracks, dtype=np.float64)
    ok = np.asarray(free, dtype=bool)
    if len(pts) < 3 or ok.all() or not ok.any():
        return 1.0, None
    # np.linalg's LAPACK calls without their wrappers (core.lapack: the same ufuncs, the same values and errors)
    inv_k = lapack.inv(camera.matrix)
    conic = inv_k.T @ np.asarray(cone, dtype=np.float64) @ inv_k  # the ellipse in pixels, negative inside
    a, b = conic[:2, :2], conic[:2, 2]
    # numpy's eigvalsh and solve of the 2x2 block by the closed forms that repeat LAPACK's values bit for bit where
    # they can (core.fits.eigenvalues2, solve2; None: ask LAPACK), as outline_cone does (stop 65, docs/glue65.md)
    (a00, a01, b0), (a10, a11, b1), _ = conic.tolist()
    eig = eigenvalues2(a00, a10, a11)  # eigvalsh reads the lower triangle
    if eig is None:
        eig = tuple(lapack.eigvalsh(a).tolist())
    if not np.isfinite(conic).all() or eig[0] <= 0.0:
        return 1.0, None
    found = solve2(a00, a01, a10, a11, b0, b1)  # raises LinAlgError where LAPACK does
    centre = np.array([-found[0], -found[1]]) if found is not None else -lapack.solve(a, b)
    k = float(centre @ a @ centre - conic[2, 2])
    if not k > 0.0:
        return 1.0, None
    if region is not None:
        cu, cv = round(float(centre[0])) - region.u0, round(float(centre[1])) - region.v0
        h, w = region.mask.shape
        if not (0 <= cu < w and 0 <= cv < h and region.mask[cv, cu]):
            return 1.0, None
    a_inv = lapack.inv(a)
    _, axes = lapack.eigh(_covariance(pts.T))
    stretch = 1.0
    projs = [pts @ e for e in axes.T]
    spans = [(float(proj.min()), float(proj.max())) for proj in projs]
    widest = max(hi - lo for lo, hi in spans)  # np.ptp's max less min
    ends = []
    for e, proj, (lo, hi) in zip(axes.T, projs, spans, strict=True):
        q = float(e @ a_inv @ e)  # once for the reach and the conjugate diameter (the same product; stop 65)
        reach = math.sqrt(k * q)  # the ellipse's half extent along e
        mid = float(centre @ e)
        # most of the extreme outline free: ok[at].mean() > 0.5, as counts (2 s > n: s / n rounds above 0.5)
        free_lo, free_hi = ok[proj <= lo + tie_px], ok[proj >= hi - tie_px]
        new_lo = lo if 2 * np.count_nonzero(free_lo) > len(free_lo) else min(lo, mid - reach)
        new_hi = hi if 2 * np.count_nonzero(free_hi) > len(free_hi) else max(hi, mid + reach)
        if hi > lo:
            length = max(min(new_hi - new_lo, widest), hi - lo)
            stretch *= length / (hi - lo)
            grown = (new_hi - new_lo) - (hi - lo)
            keep = (length - (hi - lo)) / grown if grown > 0.0 else 0.0  # the capped extra length, shared
            # the ellipse's extreme points along e are centre +- reach * conjugate (projections mid +- reach)
            conjugate = (a_inv @ e) / q
            for side, target in ((lo, lo - keep * (lo - new_lo)), (hi, hi + keep * (new_hi - hi))):
                if target != side:
                    ends.append(centre + (target - mid) * conjugate)
    stretch = math.sqrt(stretch)
    return stretch, (np.vstack((pts, *ends)) if ends and stretch > 1.0 else None)


def pixel_count(region: Silhouette) -> int:
    """``np.count_nonzero(region.mask)``, counted once per region (:func:`~symfruit.core.agreement.observe`,
    :func:`~symfruit.methods.evidence.rim_width` and ``evidence`` each read it: the same region's pixels were counted
    up to four times a fruit; stop 65, docs/glue65.md)."""
    found = region._made.get("pixels")
    if found is None:
        found = region._made["pixels"] = int(np.count_nonzero(region.mask))
    return found


def outline_cracks(region: Silhouette) -> np.ndarray:
    """(m, 2) float, pixels: the region's outline as the midpoints of the pixel edges between a region pixel
    and a 4-neighbour outside it (image coordinates: the exact boundary of the pixel squares). Made once per region
    (:func:`~symfruit.core.agreement.observe` and :func:`across_sight` both read it), read-only. By the compiled twin
    :func:`symfruit.core._jit.outline_cracks` where numba is installed (the same points: 73 against 290 us on a dense
    view's 150 px window; issue 19, fourteenth round)."""
    found = region._made.get("cracks")
    if found is not None:
        return found
    mask = region.mask
    if (jit := compiled()) is not None:  # the compiled twin: the same points in the same order
        cracks = jit.outline_cracks(np.ascontiguousarray(mask, dtype=bool), int(region.u0), int(region.v0))
    else:
        h, w = mask.shape
        m = np.zeros((h + 2, w + 2), dtype=bool)  # padded by hand: np.pad's overhead was a fifth of the call
        m[1:-1, 1:-1] = mask
        out = []
        for dr, dc in ((-1, 0), (1, 0), (0, -1), (0, 1)):
            rows, cols = np.nonzero(mask & ~m[1 + dr : h + 1 + dr, 1 + dc : w + 1 + dc])
            uv = np.empty((len(rows), 2))  # half-integers: exact in either order of the sums
            np.add(cols, 0.5 * dc + region.u0, out=uv[:, 0])
            np.add(rows, 0.5 * dr + region.v0, out=uv[:, 1])
            out.append(uv)
        cracks = np.concatenate(out)
    cracks.flags.writeable = False
    region._made["cracks"] = cracks
    return cracks


def outline_cone(
    region: Silhouette, camera: Camera, points: np.ndarray, *, min_points: int = 20, inside: float = 0.97,
    max_area: float = 3.0,
) -> tuple[np.ndarray, np.ndarray] | None:  # fmt: skip
    """The viewing cone of the ellipse fitted to part of the silhouette's outline: ``(cone (3, 3), axis (3,))``
    as :func:`silhouette_cone`, or None when no credible ellipse fits.

    Where part of the outline is an occluder's edge rather than the fruit's, the moment ellipse of the seen
    region is the wrong one; the ellipse through the rest (the occluding contour, ``points``) is not. The
    conic is the direct least-squares ellipse fit (Fitzgibbon, Pilu and Fisher 1999, in the numerically
    stable form of Halir and Flusser 1998) of the points, accepted when it holds at least ``inside`` of the
    region's pixels and its area is at most ``max_area`` times the region's.

    Parameters
    ----------
    region : Silhouette
    camera : Camera
    points : (m, 2) float, pixels
        Outline points on the fruit's own silhouette (e.g. :func:`outline_cracks` beside contour edges).
    min_points : int
    inside, max_area : float
    """
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise InputError(f"outline points must have shape (m, 2), got {pts.shape}")
    if len(pts) < max(min_points, 6):
        return None
    jit = compiled()
    pts = np.ascontiguousarray(pts)
    mu, scale, d1, d2 = _conic_design(pts) if jit is None else jit.conic_design(pts)
    s1, s2, s3 = d1.T @ d1, d1.T @ d2, d2.T @ d2
    try:
        t = -lapack.solve(s3, s2.T)
    except np.linalg.LinAlgError:
        return None
    m = s1 + s2 @ t
    m = np.array([m[2] / 2.0, -m[1], m[0] / 2.0])
    try:
        _, vecs = lapack.eig_real(m)  # np.real of np.linalg.eig's vectors
    except np.linalg.LinAlgError:
        return None
    # the first eigenvector with 4 v0 v2 - v1^2 > 0, in Python floats (numpy's products and difference, left to right)
    good = [j for j, (v0, v1, v2) in enumerate(zip(*vecs.tolist(), strict=True)) if 4.0 * v0 * v2 - v1 * v1 > 0]
    if not good:
        return None
    a1 = vecs[:, good[0]]
    (a, b, c), (d, e, f) = a1.tolist(), (t @ a1).tolist()
    # Back to pixels: x = (u - mu_u) / s, y = (v - mu_v) / s.
    q = np.array([[a, b / 2, d / 2], [b / 2, c, e / 2], [d / 2, e / 2, f]])
    tr = np.array([[1 / scale, 0, -mu[0] / scale], [0, 1 / scale, -mu[1] / scale], [0, 0, 1]])
    conic = tr.T @ q @ tr
    a2 = conic[:2, :2]
    # numpy's 2x2 solve and eigvalsh by the closed forms that repeat them bit for bit where they can
    # (core.fits.solve2, eigenvalues2), not two LAPACK calls of 10-30 us (issue 19, stop 41)
    (c00, c01, c02), (c10, c11, c12), _ = conic.tolist()
    try:
        found = solve2(c00, c01, c10, c11, -c02, -c12)
        centre = np.array(found) if found is not None else np.linalg.solve(a2, -conic[:2, 2])
    except np.linalg.LinAlgError:
        return None
    value = float(centre @ conic[:2, 2] + conic[2, 2])
    if value == 0 or not np.isfinite(value):
        return None
    conic = conic / -value  # -1 at the centre, 0 on the ellipse
    (c00, _, _), (c10, c11, _), _ = conic.tolist()
    eig = eigenvalues2(c00, c10, c11)  # eigvalsh reads the lower triangle
    if eig is None:
        eig = tuple(np.linalg.eigvalsh(conic[:2, :2]).tolist())
    if eig[0] <= 0:  # the least first
        return None
    area = np.pi / np.sqrt(eig[0] * eig[1])
    if not _credible(region, centre, conic[:2, :2], area, inside, max_area):
        return None
    return _image_cone(conic, centre, camera)


def _credible(region: Silhouette, centre: np.ndarray, a2: np.ndarray, area: float, inside: float,
              max_area: float) -> bool:  # fmt: skip
    """:func:`outline_cone`'s acceptance of an ellipse ``a2`` (2, 2) about ``centre`` (pixels; ``(x - centre)^T a2 (x
    - centre) <= 1`` inside) of ``area`` pixels: it holds at least ``inside`` of the region's pixels and is at most
    ``max_area`` times the region's area."""
    if region.mask.ndim == 2 and (jit := compiled()) is not None:  # the compiled twin of what follows: the same count
        n, count = jit.ellipse_holds(np.ascontiguousarray(region.mask, dtype=bool), int(region.u0), int(region.v0),
                                     float(centre[0]), float(centre[1]), float(a2[0, 0]), float(a2[0, 1]),
                                     float(a2[1, 1]))  # fmt: skip
        if not n or area > max_area * n:
            return False
        share = count / n
    else:
        rows, cols = np.nonzero(region.mask)
        n = len(rows)
        if not n or area > max_area * n:
            return False
        u, v = cols + region.u0 - centre[0], rows + region.v0 - centre[1]
        held = (a2[0, 0] * u * u + 2 * a2[0, 1] * u * v + a2[1, 1] * v * v) <= 1.0 + 1e-9
        share = held.mean()
    return bool(share >= inside)


def outline_circle(
    region: Silhouette, camera: Camera, points: np.ndarray, *, min_points: int = 20, inside: float = 0.97,
    max_area: float = 3.0, fit_px: float = 0.5,
) -> tuple[np.ndarray, np.ndarray] | None:  # fmt: skip
    """The viewing cone of the circle fitted to part of the silhouette's outline (``points``, pixels, the fruit's own
    contour): ``(cone, axis)`` as :func:`outline_cone`, or None when no credible circle fits: by
    :func:`outline_cone`'s acceptance (it holds at least ``inside`` of the region's pixels and its area is at most
    ``max_area`` times the region's), and the points lie about it as a digitised circle's outline does, at a root
    mean square distance of at most ``fit_px`` (an outline crack, :func:`outline_cracks`, is the midpoint of the
    pixel edge between a pixel centre inside the outline and one outside, so within half a pixel of it: arcs that
    stray further from their circle are not a round fruit's, and the circle is not its width).

    A round fruit's free arcs give its radius: the algebraic least-squares circle (Kasa 1976: ``u^2 + v^2 + d u + e
    v + f = 0``, linear in its three unknowns, about the points' mean, where its normal equations part) has three
    parameters where the ellipse has five, so it holds on arcs too short for the ellipse on a real mask's edge (a
    60 mm sphere 43 px across with a leaf over its left third: 51-63 free outline points over 103-130 degrees of arc,
    on which the ellipse came out 26 x 36 px, docs/cut58.md 1.3, and the circle 43 px; docs/cut60.md). It is what the
    ellipse is on a round fruit; on an elongated one its callers cap what it may add (:func:`free_side_reach`).

    >>> cam = Camera(fx=500.0, fy=500.0, cx=50.0, cy=50.0, width=100, height=100)
    >>> t = np.linspace(-0.4 * np.pi, 0.4 * np.pi, 60)
    >>> arc = np.column_stack((50.0 + 20.0 * np.cos(t), 50.0 + 20.0 * np.sin(t)))
    >>> yy, xx = np.mgrid[:100, :100]
    >>> m = ((xx - 50) ** 2 + (yy - 50) ** 2 <= 19.5**2) & (xx >= 44)
    >>> minor, major = cone_widths(*outline_circle(Silhouette(0, 0, m, 0.0), cam, arc))
    >>> round(minor * 500, 6), round(major * 500, 6)  # the circle's diameter, 40 px
    (40.0, 40.0)
    """
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise InputError(f"outline points must have shape (m, 2), got {pts.shape}")
    if len(pts) < max(min_points, 3):
        return None
    if (jit := compiled()) is not None:  # the compiled twin of the three lines below and z.mean(): the same values
        mu, x, y, z, z_mean = jit.circle_design(np.ascontiguousarray(pts))
    else:
        mu = column_means(pts)
        x, y = pts[:, 0] - mu[0], pts[:, 1] - mu[1]
        z = x * x + y * y
        z_mean = float(z.mean())
    # the normal equations about the points' mean: f = -mean(z), and a 2 x 2 system for d, e (no least-squares
    # solver: a tenth of the call's cost where the circle is tried on every cut outline without an ellipse)
    try:
        xy = float(x @ y)  # once for both off-diagonal entries (the same product; stop 65)
        found = solve2(float(x @ x), xy, xy, float(y @ y), -float(x @ z), -float(y @ z))
    except np.linalg.LinAlgError:  # the points on a line
        return None
    if found is None:
        return None
    cu, cv = -0.5 * found[0], -0.5 * found[1]
    r2 = cu * cu + cv * cv + z_mean
    if not (math.isfinite(r2) and r2 > 0.0):
        return None
    if jit is not None:  # the compiled twin of the two lines below (stop 65, docs/glue65.md)
        mean_square = float(jit.circle_mean_square(x, y, cu, cv, math.sqrt(r2)))
    else:
        off = np.sqrt((x - cu) ** 2 + (y - cv) ** 2) - math.sqrt(r2)
        mean_square = float((off * off).mean())
    # its root by math.sqrt, np.sqrt's (correctly rounded); NaN: refused
    if not (mean_square >= 0.0 and math.sqrt(mean_square) <= fit_px):
        return None
    centre = np.array([mu[0] + cu, mu[1] + cv])
    if not _credible(region, centre, np.eye(2) / r2, math.pi * r2, inside, max_area):
        return None
    conic = np.array([[1.0, 0.0, -centre[0]], [0.0, 1.0, -centre[1]],
                      [-centre[0], -centre[1], float(centre @ centre) - r2]]) / r2  # fmt: skip
    return _image_cone(conic, centre, camera)


def _conic_design(pts: np.ndarray) -> tuple[np.ndarray, float, np.ndarray, np.ndarray]:
    """``(mean (2,), scale, [x^2, x y, y^2] (m, 3), [x, y, 1] (m, 3))`` of :func:`outline_cone`'s points ``pts`` (m,
    2), ``x, y`` their coordinates less the mean over the scale (the root of their mean squared distance from the
    mean, 1 where that is 0). ``column_means``, ``squared_norms`` and the columns filled one by one: the values of
    ``pts.mean(axis=0)``, ``((pts - mu) ** 2).sum(axis=1)`` and two ``np.stack`` of columns (issue 19, nineteenth
    round). By the compiled twin :func:`symfruit.core._jit.conic_design` where numba is installed (the same values,
    in one call; stop 44)."""
    mu = column_means(pts)
    scale = float(np.sqrt(squared_norms(pts - mu).mean())) or 1.0
    x, y = (pts[:, 0] - mu[0]) / scale, (pts[:, 1] - mu[1]) / scale
    d1 = np.empty((len(x), 3))
    np.multiply(x, x, out=d1[:, 0])
    np.multiply(x, y, out=d1[:, 1])
    np.multiply(y, y, out=d1[:, 2])
    d2 = np.ones((len(x), 3))
    d2[:, 0], d2[:, 1] = x, y
    return mu, scale, d1, d2


def rasterise(points: np.ndarray, camera: Camera, *, fill_radius: float | None = None) -> View:
    """Rasterise visible points into a mask and a seen-depth map at the camera's resolution.

    Each point marks its pixel (the nearest depth wins). The mask ``Mp`` is the closing of the marked
    pixels by a square of half-width ``fill_radius`` with the holes filled, so a sparse cloud of a few
    hundred points still gives a solid silhouette. Mask pixels no point hit take the mean depth of
    the marked pixels within the same square (or, past that, of the nearest marked pixel).

    Parameters
    ----------
    points : (n, 3) float, metres
        Visible points with ``z > 0``.
    camera : Camera
    fill_radius : float, pixels, optional
        Default: ``0.7 * sqrt(area / n)``, with ``area`` the ellipse inscribed in the points' pixel
        box: 1.5 times the expected median nearest-neighbour spacing of ``n`` points spread over the
        silhouette, and at least 1.

    Raises
    ------
    InputError
        When no point projects into the image.
    """
    points = as_points(points, min_count=1)
    col, row, z = _pixels(points, camera)
    if fill_radius is None:
        fill_radius = max(1.0, _default_fill(col, row))
    half = int(np.ceil(fill_radius))
    u0, v0, h, w = _window(col, row, camera, half + 2)
    flat = (row - v0) * w + (col - u0)

    flat_z = np.full(h * w, np.inf)
    np.minimum.at(flat_z, flat, z)
    zbuf = flat_z.reshape(h, w)
    hit = np.isfinite(zbuf)
    mask = _closed_mask(hit, half)

    # Seen depth on the mask: marked pixels keep theirs, the others the mean of the marked pixels in
    # the same square (tripled in size until every mask pixel has one, or at worst the median).
    size = 2 * half + 1
    hit32 = hit.astype(np.float32)
    weight = ndimage.uniform_filter(hit32, size=size, mode="constant")
    seed = np.where(hit, zbuf, 0.0).astype(np.float32)
    depth = seed.copy()
    todo = mask & ~hit
    box = size
    while todo.any():
        if box > 3 * max(h, w):
            depth[todo] = np.median(zbuf[hit])
            break
        if box != size:
            weight = ndimage.uniform_filter(hit32, size=box, mode="constant")
        local = ndimage.uniform_filter(seed, size=box, mode="constant")
        done = todo & (weight > 1e-6)
        depth[done] = local[done] / weight[done]
        todo &= ~done
        box *= 3
    depth = depth.astype(np.float64)
    depth[hit] = zbuf[hit]

    dist, (mr, mc) = ndimage.distance_transform_edt(~mask, return_indices=True)
    return View(
        u0=u0,
        v0=v0,
        mask=mask,
        dist=dist.ravel(),
        near_u=(mc + u0).ravel().astype(np.float64),
        near_v=(mr + v0).ravel().astype(np.float64),
        near_depth=depth[mr, mc].ravel(),
        fill_radius=float(fill_radius),
    )


def silhouette_coverage(view: View, box: Box, camera: Camera) -> float:
    """Share of a fitted fruit's silhouette that the camera saw, in [0, 1].

    How much of the ellipse inscribed in the box's projection (at the box centre's depth) the
    rasterised visible points (``view``) cover. Occluded, cut or sparse views cover less.
    """
    c, half = box.centre, box.size / 2.0
    if not (np.all(np.isfinite(c)) and np.all(np.isfinite(half)) and c[2] > 0):
        return 0.0
    uc, vc = camera.project(c[None])[0]
    au, av = max(camera.fx * half[0] / c[2], 1.0), max(camera.fy * half[1] / c[2], 1.0)
    # Only the window where the camera saw anything can be covered; the area counts the whole ellipse.
    h, w = view.mask.shape
    u0, u1 = max(int(np.floor(uc - au)), view.u0), min(int(np.ceil(uc + au)) + 1, view.u0 + w)
    v0, v1 = max(int(np.floor(vc - av)), view.v0), min(int(np.ceil(vc + av)) + 1, view.v0 + h)
    if u1 <= u0 or v1 <= v0:
        return 0.0
    vv, uu = np.mgrid[v0:v1, u0:u1]
    inside = ((uu - uc) / au) ** 2 + ((vv - vc) / av) ** 2 <= 1.0
    seen = inside & view.mask[vv - view.v0, uu - view.u0]
    return float(min(1.0, seen.sum() / (np.pi * au * av)))


@dataclass(frozen=True)
class Tilt:
    """How a fruit's axis is tilted out of the image plane, read off one view (:func:`axis_tilt`).

    Attributes
    ----------
    major, minor : float, metres
        The outline's half-widths along and across its principal axis, at the seen front's distance.
    slope_major, slope_minor : float
        Depth per lateral metre of the seen front's midline (the front plus the depth the outline's local
        half-width would give a round section) along the outline's major and minor axis.
    cap : float
        The seen front's sag over the outline's local half-width: 1 for round sections across the major axis
        (a solid of revolution lying in the image plane), ``major / minor`` for an oblate spheroid seen side on.
    slope_sd : float
        The standard deviation of ``slope_major`` (and of ``slope_minor``) from the fit's residuals.
    count : int
        Points the fit used (0: no estimate; every other field is then 0 but the half-widths).
    cap_sd : float
        The standard deviation of ``cap`` (0: not estimated; :func:`axis_tilt`'s ``blocks``).
    bend, bend_sd : float, 1 / metres
        The midline's depth per square metre along the major axis about its vertex, and its standard deviation (0:
        not fitted; :func:`axis_tilt`'s ``bend``): a bent axis's sagitta over the outline's half-length is
        ``bend * major^2``.
    """

    major: float
    minor: float
    slope_major: float
    slope_minor: float
    cap: float
    slope_sd: float
    count: int
    cap_sd: float = 0.0
    bend: float = 0.0
    bend_sd: float = 0.0

    def half_depths(self, floor: float = 0.05) -> tuple[float, float]:
        """The depth half-extents ``(prolate, oblate)`` of the spheroid that has this outline and these midline
        slopes (metres).

        A spheroid's dual quadric is ``a^2 I + (c^2 - a^2) u u^T`` (``a`` its equatorial radius, ``c`` its half-length,
        ``u`` its axis); seen along ``z`` its outline's semi-axes are two of that matrix's image-plane entries and its
        midline's slopes the depth column over them, and the matrix minus ``a^2 I`` has rank one. A prolate spheroid
        (``c > a``) projects its axis on the outline's major axis and its equator on the minor one (``a = minor``,
        whatever the tilt), and its depth half-extent is ``H^2 = minor^2 + s^2 major^4 / (major^2 - minor^2)``, with
        ``s`` the midline's slope along the major axis (``s = tan(tilt) (1 - minor^2 / major^2)``: the tilt's tangent
        ``t`` gives ``H^2 = minor^2 + t^2 (major^2 - minor^2)``). An oblate one (``c < a``) projects its axis on the
        minor axis: ``a = major``, ``H^2 = major^2 - s^2 minor^4 / (major^2 - minor^2)`` (``s`` along the minor axis),
        at least ``minor / 2``. ``floor``: the least ``(major^2 - minor^2) / major^2`` divided by (a near-round outline
        says nothing of the tilt); the slopes' noise variance is taken off their squares first. A bent axis
        (:attr:`bend` beyond :attr:`bend_sd`) deepens the prolate one by half its sagitta, ``|bend| (major^2 -
        minor^2) / 2`` (weighted by the outline's elongation: stop 46, docs/tilt46.md).
        """
        big, small = self.major, self.minor
        gap = max(big * big - small * small, floor * big * big)
        var = self.slope_sd**2
        prolate = small * small + max(self.slope_major**2 - var, 0.0) * big**4 / gap
        oblate = big * big - max(self.slope_minor**2 - var, 0.0) * small**4 / gap
        # a bent axis: the sagitta beyond its noise, half of it on each side of the middle; the prolate's long axis
        # only, as far as the outline is elongated (a near-round outline's major axis is no axis that bends)
        sag = 0.5 * max(abs(self.bend) - self.bend_sd, 0.0) * (big * big - small * small)
        return float(np.sqrt(prolate) + sag), float(np.sqrt(max(oblate, 0.25 * small * small)))

    def half_depth(self, floor: float = 0.05) -> float:
        """The depth half-extent (metres) between :meth:`half_depths`' two, in log by where :attr:`cap` lies between
        the two spheroids' own (the prolate's ``sqrt(1 + s^2 major^2 / gap)``, the oblate's
        ``(major / minor) sqrt(1 - s^2 minor^2 / gap)``), clipped to them; their geometric mean when they agree or
        there is no estimate. With :attr:`cap_sd` the share is shrunk towards a half (the geometric mean of the two,
        which is the outline's for a level midline) by ``d^2 / (d^2 + (cap_sd / cap)^2)``, ``d`` the two
        hypotheses' caps apart in log: a cap that cannot tell them apart says nothing of which it is."""
        prolate, oblate = self.half_depths(floor)
        share = self.oblate_share(floor)
        if share is None:
            return float(np.sqrt(prolate * oblate))
        return float(prolate ** (1.0 - share) * oblate**share)

    def oblate_share(self, floor: float = 0.05) -> float | None:
        """Where :attr:`cap` lies between the prolate spheroid's cap and the oblate one's, in log, in [0, 1] (0: the
        prolate's, 1: the oblate's), shrunk towards a half by :attr:`cap_sd` as :meth:`half_depth` reads it; None where
        there is no estimate or the two caps agree (the cap cannot tell them apart)."""
        if self.count == 0:
            return None
        big, small = self.major, self.minor
        gap = max(big * big - small * small, floor * big * big)
        var = self.slope_sd**2
        cap_p = np.sqrt(1.0 + max(self.slope_major**2 - var, 0.0) * big * big / gap)
        cap_o = big / small * np.sqrt(max(1.0 - max(self.slope_minor**2 - var, 0.0) * small * small / gap, 0.25))
        lo, hi = np.log(max(cap_p, 1e-6)), np.log(max(cap_o, 1e-6))
        if abs(hi - lo) < 1e-3:
            return None
        share = float(np.clip((np.log(max(self.cap, 1e-6)) - lo) / (hi - lo), 0.0, 1.0))
        if self.cap_sd > 0:
            noise = (self.cap_sd / max(self.cap, 1e-6)) ** 2
            share = 0.5 + (share - 0.5) * (hi - lo) ** 2 / ((hi - lo) ** 2 + noise)
        return share


def _outline_to(
    e: np.ndarray, outer: Silhouette, camera: Camera, across: Across, centre: np.ndarray, frame: np.ndarray,
    reach: float,
) -> np.ndarray:  # fmt: skip
    """The outline ``e`` (tangent coordinates about ``centre`` in the axes ``frame``) scaled about its middle to the
    widths ``outer``'s outline has along those axes, by no more than ``reach`` either way (:func:`axis_tilt`)."""
    cracks = outline_cracks(outer)
    if len(cracks) < 8:
        return e
    rays = camera.rays(cracks[:, 0], cracks[:, 1]).reshape(-1, 3)
    o = ((rays @ across.basis.T) / (rays @ across.axis)[:, None] - centre) @ frame
    own = np.ptp(e, axis=0)
    if not np.all(own > 0):
        return e
    grow = np.clip(np.ptp(o, axis=0) / own, 1.0 / reach, reach)
    mid = 0.5 * (e.min(axis=0) + e.max(axis=0))
    return mid + (e - mid) * grow


def axis_tilt(
    points: np.ndarray, region: Silhouette, camera: Camera, across: Across, *, bins: int = 24, inner: float = 0.4,
    ends: float = 0.1, rounds: int = 2, outer: Silhouette | None = None, reach: float = 1.5, blocks: int = 0,
    bend: bool = False,
) -> Tilt:  # fmt: skip
    """The tilt of a fruit's axis out of the image plane and the shape of its sections, from its seen front and
    its outline (:class:`Tilt`).

    The outline (:func:`outline_cracks` in :func:`across_sight`'s tangent coordinates, times the front's distance)
    is cut into ``bins`` slices across its principal major axis (the outline's own covariance); each slice's
    half-width ``h`` and middle ``q_c``, interpolated along the axis, give every seen point at ``(p, q)`` the depth a
    round section through it would show, ``g = sqrt(h^2 - (q - q_c)^2)``. The points' depths along the centroid's ray
    are then fitted by least squares as ``z0 + s_major p + s_minor q - cap g``: a solid of revolution lying in the
    image plane has ``cap = 1`` and no slopes, whatever its profile (a pear's neck and body alike); a spheroid
    tilted out of it keeps its outline's minor half-width and turns its midline by ``s_major``
    (:meth:`Tilt.half_depths`). Only points where ``g`` is at least ``inner`` of ``h`` (the rim's depths are the
    noisiest, and ``g`` there the most sensitive to the outline) and at least ``ends`` of the major width from
    either end are fitted; ``rounds`` refits drop points whose residual is over 2.5 robust standard deviations.

    ``outer``: the fruit's whole outline where the points' ``region`` falls short of it (the instance mask: a
    time-of-flight camera returns no depth on a band of the rim, whose light grazes the surface, so the points'
    region is eroded by a few pixels all round; stop 46, docs/tilt46.md). The points' outline is scaled about its
    centre to the outer one's widths along its own two axes (widths, not positions: a registration shift between
    the mask and the depth moves the mask's outline, and moves no width), by no more than ``reach`` either way.
    An eroded outline makes a round section's sag ``g`` too small at its middle and too steep towards its rim, and
    the fit then reads the front as flatter than a round section (``cap`` under 1: the Azure Kinect model's apples
    read 0.8-1.0 where the render's own depth gives 1.1-1.4).

    ``blocks`` (0: off): the fit's uncertainty from a delete-a-block jackknife over that many sectors of the points
    about the outline's middle (:attr:`Tilt.cap_sd`, and :attr:`Tilt.slope_sd` at least the jackknife's): a depth
    camera's noise is correlated over a few pixels (the Azure Kinect model's over 3.5), so the residuals read as
    independent understate it by several times on a fruit a few tens of pixels wide.

    ``bend``: the midline's depth also gets a term in the square of the position along the major axis
    (:attr:`Tilt.bend`). A spheroid's sections have their centres on a line (a conjugate diameter) whatever its
    tilt, so the term is naught for every spheroid and every solid of revolution with a straight axis; a fruit
    whose axis bends towards or away from the camera (a banana hanging) shows it, and no outline does.
    """
    pts = as_points(points, min_count=1)
    big, small = 0.5 * float(across.major), 0.5 * float(across.minor)
    depth = pts @ across.axis
    dist = float(np.median(depth))
    empty = Tilt(big * dist, small * dist, 0.0, 0.0, 1.0, 0.0, 0)
    cracks = outline_cracks(region)
    if len(pts) < 20 or len(cracks) < 8 or big <= 0 or small <= 0:
        return empty
    rays = camera.rays(cracks[:, 0], cracks[:, 1]).reshape(-1, 3)
    edge = (rays @ across.basis.T) / (rays @ across.axis)[:, None]  # tangent coordinates
    centre = edge.mean(axis=0)
    _, vec = lapack.eigh(_covariance((edge - centre).T))
    frame = vec[:, ::-1]  # columns: major, minor
    e = (edge - centre) @ frame
    x = ((pts @ across.basis.T) / depth[:, None] - centre) @ frame  # tangent coordinates, then metres at each depth
    if outer is not None:
        e = _outline_to(e, outer, camera, across, centre, frame, reach)
    lo, hi = float(e[:, 0].min()), float(e[:, 0].max())
    span = hi - lo
    if span <= 0:
        return empty
    big, small = 0.5 * span, 0.5 * float(np.ptp(e[:, 1]))  # this outline's own (the region's, the points')
    which = np.clip(((e[:, 0] - lo) / span * bins).astype(np.intp), 0, bins - 1)
    top = np.full(bins, -np.inf)
    bottom = np.full(bins, np.inf)
    np.maximum.at(top, which, e[:, 1])
    np.minimum.at(bottom, which, e[:, 1])
    ok = np.isfinite(top) & np.isfinite(bottom)
    if ok.sum() < 3:
        return empty
    mids = lo + (np.arange(bins) + 0.5) / bins * span
    half_t = np.interp(x[:, 0], mids[ok], 0.5 * (top - bottom)[ok])
    off_t = x[:, 1] - np.interp(x[:, 0], mids[ok], 0.5 * (top + bottom)[ok])
    inside = (half_t * half_t - off_t * off_t >= (inner * half_t) ** 2) & (x[:, 0] >= lo + ends * span)
    keep = inside & (x[:, 0] <= hi - ends * span)
    if keep.sum() < 20:
        return empty
    xm = x * depth[:, None]
    width = 5 if bend else 4
    coef = np.zeros(width)
    design = np.empty((len(pts), width))
    for scale in (dist, None):
        # the outline lies at the rim's distance, the midline's depth at the centre (``z0``), nearer than the
        # seen points' median: a round section's sag is its half-width there
        at = dist if scale is not None else max(float(coef[0]), dist)
        half, off = half_t * at, off_t * depth
        columns = [np.ones(len(pts)), xm[:, 0], xm[:, 1], -np.sqrt(np.maximum(half * half - off * off, 0.0))]
        design = np.column_stack(columns + [xm[:, 0] ** 2] if bend else columns)
        fit = keep.copy()
        for _ in range(rounds + 1):
            coef = np.linalg.lstsq(design[fit], depth[fit], rcond=None)[0]
            res = depth - design @ coef
            sd = 1.4826 * float(np.median(np.abs(res[fit] - np.median(res[fit]))))
            if sd <= 0:
                break
            nxt = fit & (np.abs(res) <= 2.5 * sd)
            if nxt.sum() < 20 or np.array_equal(nxt, fit):
                break
            fit = nxt
        keep_fit = fit
    dist = max(float(coef[0]), dist)
    a = design[keep_fit]
    try:
        cov = np.linalg.inv(a.T @ a) * float(np.mean((depth[keep_fit] - a @ coef) ** 2))
    except np.linalg.LinAlgError:
        return empty
    slope_sd = float(np.sqrt(max(0.5 * (cov[1, 1] + cov[2, 2]), 0.0)))
    cap_sd = 0.0
    bow, bow_sd = (float(coef[4]), float(np.sqrt(max(cov[4, 4], 0.0)))) if bend else (0.0, 0.0)
    if blocks >= 2:
        # the points' angle about the outline's middle, on the outline's own scale: ``blocks`` even sectors
        mid = 0.5 * (e.min(axis=0) + e.max(axis=0))
        rel = (x[keep_fit] - mid) / np.array([big, small])
        turn = (np.arctan2(rel[:, 1], rel[:, 0]) + np.pi) / (2.0 * np.pi)
        jk = _block_jackknife(a, depth[keep_fit], np.minimum((turn * blocks).astype(np.intp), blocks - 1), blocks)
        slope_sd = max(slope_sd, float(np.sqrt(0.5 * (jk[1] + jk[2]))))
        cap_sd = float(np.sqrt(jk[3]))
        bow_sd = max(bow_sd, float(np.sqrt(jk[4]))) if bend else 0.0
    keep = keep_fit
    return Tilt(big * dist, small * dist, float(coef[1]), float(coef[2]), float(coef[3]), slope_sd, int(keep.sum()),
                cap_sd, bow, bow_sd)  # fmt: skip


def bracket_tilt(inner: Tilt, outer: Tilt) -> Tilt:
    """One :class:`Tilt` from two fits of the same front with two outlines that bracket the fruit's (the points'
    own, which a time-of-flight camera's lost rim band erodes, and the instance mask's, which its annotators grow by
    a few pixels: :func:`axis_tilt`'s ``outer``): their geometric means (half-widths, cap) and means (slopes),
    and standard deviations at least half their difference (``cap_sd`` combined with the fits' own): the outline's
    uncertainty is what makes the cap unsure on a fruit a few tens of pixels wide, and :meth:`Tilt.half_depth`
    then leans on it the less. ``count`` 0 from either: the other."""
    if inner.count == 0 or outer.count == 0:
        return outer if inner.count == 0 else inner
    half = 0.5 * abs(float(np.log(max(outer.cap, 1e-6) / max(inner.cap, 1e-6))))
    cap = float(np.sqrt(max(inner.cap, 1e-6) * max(outer.cap, 1e-6)))
    return Tilt(
        float(np.sqrt(inner.major * outer.major)), float(np.sqrt(inner.minor * outer.minor)),
        0.5 * (inner.slope_major + outer.slope_major), 0.5 * (inner.slope_minor + outer.slope_minor), cap,
        max(inner.slope_sd, outer.slope_sd, 0.5 * abs(inner.slope_major - outer.slope_major),
            0.5 * abs(inner.slope_minor - outer.slope_minor)),
        min(inner.count, outer.count), float(np.hypot(max(inner.cap_sd, outer.cap_sd), half * cap)),
        0.5 * (inner.bend + outer.bend), max(inner.bend_sd, outer.bend_sd, 0.5 * abs(inner.bend - outer.bend)),
    )  # fmt: skip


def _block_jackknife(a: np.ndarray, b: np.ndarray, group: np.ndarray, blocks: int) -> np.ndarray:
    """(k,) float: the delete-a-block jackknife variance of each of the least-squares coefficients of ``a x = b``
    (``a`` (n, k)), the blocks ``group`` (n,) int in ``[0, blocks)``. Each block's own normal equations are taken
    off the whole's and the rest solved at once; a block without points, or one whose rest is singular, is left
    out. Contiguous blocks keep a camera's depth noise, correlated over a few pixels, within one block, and a
    shape the model misses in one part of the front: the spread of the fits without each says what the
    residuals of one fit, read as independent, do not."""
    k = a.shape[1]
    onehot = np.zeros((len(a), blocks))
    onehot[np.arange(len(a)), group] = 1.0
    ata_g = np.einsum("ng,ni,nj->gij", onehot, a, a)
    atb_g = np.einsum("ng,ni,n->gi", onehot, a, b)
    rest, rhs = ata_g.sum(axis=0) - ata_g, atb_g.sum(axis=0) - atb_g
    ok = (onehot.sum(axis=0) > 0) & (np.abs(np.linalg.det(rest)) > 1e-300)
    if ok.sum() < 2:
        return np.zeros(k)
    theta = np.linalg.solve(rest[ok], rhs[ok][..., None])[..., 0]
    m = int(ok.sum())
    return (m - 1) / m * ((theta - theta.mean(axis=0)) ** 2).sum(axis=0)
