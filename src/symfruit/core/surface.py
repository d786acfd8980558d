"""A fruit's own surface in a registered depth image, and the registration itself.

A mask drawn on the colour image (by an annotator, a segmenter or a model) does not pick out a fruit's depth
pixels on a real RGB-D camera: depth is registered to colour a few pixels off, a time-of-flight camera
returns no depth where the surface turns away from it (low return at grazing angles, mixed pixels at the
rim), flying pixels bridge the fruit and what lies behind it, the mask overshoots onto the background,
leaves and the surface the fruit touches. Every depth pixel that is not the fruit's own enters its cloud
and every completion then grows too large (issue 18: boxes 25-45 mm too deep on real frames).

:func:`fruit_surface` keeps the pixels of one smooth convex cap, found without any model of the fruit: the
depth mode of the mask's pixels (:func:`fruit_depth`), a slab from there to a fruit radius behind it (the
radius from the mask's size), and, from the cap's nearest point, only what a convex surface seen from
outside can be: along every ray in the image from its nearest point a convex fruit's depth never falls
(:func:`monotone_region`), so a support, a stem or a leaf meeting the fruit is cut where depth turns back
towards the camera. :func:`registration_shift` finds how far the depth image sits from the masks: the
shift that lays the outline of every fruit's depth cap parallel to its mask's outline, a band of the
mask's rim (the grazing pixels a time-of-flight camera invalidates) allowed between them, along the axes whose
both sides show a silhouette rather than a support running on.

Numpy and scipy only (or their compiled twins, :mod:`symfruit.core.kernels`, where numba is); images in, images and
numbers out.
"""

from __future__ import annotations

import functools
import importlib
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from scipy import ndimage

from . import lapack
from .fits import eigenvalues2
from .kernels import compiled
from .points import median
from .raster import distance_transform, eroded, fill_holes, inner_distance, interior, mask_box, principal_widths

__all__ = [
    "Reading",
    "Surface",
    "colour_trim",
    "depth_noise",
    "depth_step",
    "fruit_depth",
    "fruit_surface",
    "monotone_region",
    "registration_shift",
    "thin_front",
    "within",
]


@dataclass(frozen=True)
class Surface:
    """One fruit's surface pixels in an image window.

    Attributes
    ----------
    pixels : (h, w) bool
        The fruit's own surface.
    front : float, metres
        The nearest depth of the fruit's depth mode.
    radius : float, metres
        The mask's equivalent radius (``sqrt(area / pi)``) at ``front``.
    noise : float, metres
        The depth noise measured in the mask (:func:`depth_noise`).
    apex : (int, int)
        Row and column of the cap's nearest pixel (median-filtered depth).
    """

    pixels: np.ndarray
    front: float
    radius: float
    noise: float
    apex: tuple[int, int]


@dataclass(frozen=True)
class Reading:
    """What :func:`fruit_surface` reads of a mask before its slab and convex cap, and what it read it from (surf65):
    a caller that asks for the same mask's surface twice, on two windows holding the same box (``extract.front_ring``
    and ``extract.own_cap`` on a drawn mask and the depth moved by the registration's shift), reads it once.

    Attributes
    ----------
    depth, mask : (bh, bw) float64 and bool
        Copies of the (cleaned) depth and the mask on the mask's box.
    given : tuple
        The arguments it was read with: focal, tolerance, step, thin, and whether the kernels read it.
    front, radius, noise, tol, radius_px : float
        The fruit's front and radius (metres, after ``thin``'s sheet), the depth's noise, the convexity test's
        tolerance (metres) and the mask's equivalent radius (pixels).
    sheet : (bh, bw) bool or None
        The sheet in front ``thin`` found on the box (its pixels left out of the region), None without one.
    """

    depth: np.ndarray
    mask: np.ndarray
    given: tuple[float, float, float | None, bool, bool]
    front: float
    radius: float
    noise: float
    tol: float
    radius_px: float
    sheet: np.ndarray | None

    def box_in(self, depth: np.ndarray, mask: np.ndarray,
               given: tuple[float, float, float | None, bool, bool]) -> tuple[int, int, int, int] | None:  # fmt: skip
        """``mask``'s box ``(r0, r1, c0, c1)`` where, with the same arguments ``given``, ``mask`` (h, w) bool and
        ``depth`` (h, w) float64 hold on it what this was read from (the same pixels, the same bits); else None."""
        if given != self.given or not (
            isinstance(mask, np.ndarray) and isinstance(depth, np.ndarray) and mask.dtype == bool
            and self.mask.dtype == bool and mask.ndim == 2 and depth.dtype == self.depth.dtype == np.float64
            and depth.shape == mask.shape
        ):  # fmt: skip
            return None
        if (found := mask_box(mask)) is None:
            return None
        r0, r1, c0, c1 = found
        if (r1 - r0, c1 - c0) != self.mask.shape:
            return None
        box = (slice(r0, r1), slice(c0, c1))
        # the bits compared, not the values (0.0 and -0.0, NaN)
        if not np.array_equal(mask[box], self.mask) or not np.array_equal(depth[box].view(np.int64),
                                                                          self.depth.view(np.int64)):  # fmt: skip
            return None
        return found


#: :func:`depth_noise`'s least noise (metres), and an empty leaf image (:func:`fruit_surface`'s compiled measures).
_NOISE_FLOOR = 0.0005
_NO_LEAF = np.zeros((0, 0), bool)


def depth_noise(depth: np.ndarray, mask: np.ndarray, *, floor: float = _NOISE_FLOOR) -> float:
    """Depth noise (metres) of a surface: the robust spread of the differences between horizontally
    neighbouring depth pixels of ``mask``, divided by ``sqrt(2)``, at least ``floor``.

    A registered depth image repeats a coarser depth camera's pixels, so equal neighbours are left out
    (their difference says nothing of the noise); the fruit's own slope between neighbours is small beside
    the noise at working distances.

    Parameters
    ----------
    depth : (h, w) float, metres (0: none)
    mask : (h, w) bool

    Where numba is, its compiled twin finds the differences and their medians (:func:`symfruit.core._jit.depth_noise`:
    the same differences and order statistics, the same value; issue 19, fifteenth round).
    """
    if (jit := compiled()) is not None and depth.ndim == 2 and depth.dtype == np.float64 and mask.shape == depth.shape:
        n, mad = jit.depth_noise(depth, np.asarray(mask, dtype=bool))
        return max(floor, 0.002) if n < 10 else max(floor, 1.4826 * float(mad) / np.sqrt(2.0))
    diff = _neighbour_differences(depth, mask)
    moved = diff[diff != 0]
    if len(moved) >= 20:
        diff = moved
    if len(diff) < 10:
        return max(floor, 0.002)
    mad = float(median(np.abs(diff - median(diff))))
    return max(floor, 1.4826 * mad / np.sqrt(2.0))


def depth_step(depth: np.ndarray, mask: np.ndarray) -> float:
    """The depth's quantisation step (metres): the smallest non-zero difference between horizontally
    neighbouring depth pixels of ``mask``, 0 with none.

    Depth cameras store whole depth units (a millimetre on the RealSense and Azure Kinect images and in their
    16-bit PNGs); a continuous depth (a render) has no step worth the name, and its smallest difference is
    negligible beside any tolerance.

    Parameters
    ----------
    depth : (h, w) float, metres (0: none)
    mask : (h, w) bool
    """
    depth = np.asarray(depth)
    if (
        (jit := compiled()) is not None
        and depth.ndim == 2
        and depth.dtype.kind == "f"
        and np.shape(mask) == depth.shape
    ):
        return jit.depth_step(depth, np.asarray(mask, dtype=bool))
    diff = np.abs(_neighbour_differences(depth, mask))
    diff = diff[diff > 0]
    return float(diff.min()) if len(diff) else 0.0


def _neighbour_differences(depth: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """(n,) the differences, right less left, between horizontally neighbouring pixels of ``mask`` that both hold
    depth (:func:`depth_noise`'s spread and :func:`depth_step`'s unit are read off them)."""
    a, b = depth[:, 1:], depth[:, :-1]
    return (a - b)[mask[:, 1:] & mask[:, :-1] & (a > 0) & (b > 0)]


def _sorted_quantile(z: np.ndarray, q: float) -> float:
    """``np.quantile(z, q)`` (its default, linear method) of sorted ``z``: the same two neighbours and the same
    interpolation, read off the sorted values instead of partitioning them again."""
    n = len(z)
    at = (n - 1) * q
    if n < 2 or not 0.0 <= at < n - 1:
        return float(np.quantile(z, q))
    below = int(np.floor(at))
    t = at - below
    a, b = float(z[below]), float(z[below + 1])
    # numpy's _lerp: a + (b - a) t, from the upper end when t >= 0.5
    return b - (b - a) * (1.0 - t) if t >= 0.5 else a + (b - a) * t


def fruit_depth(values: np.ndarray, radius_px: float, focal: float, *, noise: float = 0.001,
                leafy: np.ndarray | None = None) -> tuple[float, float]:  # fmt: skip
    """``(front, radius)``, metres: where a mask's fruit lies in depth, and how large it is there.

    The depths of a mask's pixels hold the fruit and whatever the mask reaches beyond it (background,
    leaves behind, the surface it lies on). Their histogram (bins of a third of the fruit's radius, at least
    4 mm and two noise deviations) has one peak per surface; the fruit's is the nearest of the peaks holding
    at least half as many pixels as the largest (a fruit behind the fruit shows through less than the
    fruit itself; a leaf in front drawn into the mask rarely covers half of it), extended nearer over every
    bin holding depths (a fruit's depths run without a gap from its nearest point to its rim). ``front`` is
    the 5 % quantile of the depths of the nearest of those bins (of the peak, when that is the nearest),
    ``radius`` the mask's equivalent radius at ``front``.

    Parameters
    ----------
    values : (n,) float, metres
        Depths of the mask's pixels (0 and non-finite values are ignored).
    radius_px : float, pixels
        The mask's equivalent radius.
    focal : float, pixels
    noise : float, metres
    leafy : (n,) bool, optional
        Which pixels are leaf green, aligned with ``values``: a peak most of whose pixels are (a leaf in front drawn
        into the mask) is passed over for the nearest peak behind it that holds a tenth of the largest's pixels
        and is mostly not (:data:`LEAFY`).

    Returns
    -------
    front, radius : float, metres (NaN when fewer than 10 depths are valid)

    Where numba is, its compiled twin does the same steps (:func:`symfruit.core._jit.fruit_depth`: the same numbers,
    bit for bit; issue 19, sixteenth round).
    """
    if (jit := compiled()) is not None and isinstance(values, np.ndarray) and values.dtype == np.float64 and (
        values.ndim == 1
    ):  # fmt: skip
        ok = np.empty(values.shape, bool)  # the compiled twin of the two lines below (stop 49: the same depths)
        kept = jit.finite_positive(values, ok)
    else:
        ok = np.isfinite(values) & (values > 0)
        kept = values[ok]
    z = np.sort(kept)
    if (jit := compiled()) is not None and z.dtype == np.float64 and kept.ndim == 1 and (
        leafy is None or np.shape(leafy) == np.shape(values)
    ):  # fmt: skip
        leaf = np.zeros(0, bool) if leafy is None else np.asarray(leafy, dtype=bool)[ok]
        front, radius, done = jit.fruit_depth(z, kept, float(radius_px), float(focal), float(noise), leaf,
                                              leafy is not None, (float(LEAFY[0]), float(LEAFY[1])))  # fmt: skip
        if done:
            return float(front), float(radius)
    if len(z) < 10:
        return float("nan"), float("nan")
    half = len(z) // 2
    median = float(z[half]) if len(z) % 2 else float((z[half - 1] + z[half]) / 2.0)  # np.median of sorted z
    radius = radius_px * median / focal
    step = max(radius / 3.0, 0.004, 2.0 * noise)
    n_bins = int(min(max(np.ceil((z[-1] - z[0]) / step), 1), 4096))
    counts, edges = _sorted_histogram(z, n_bins, (z[0], z[0] + n_bins * step))
    mass = np.convolve(counts, np.ones(3), mode="same")
    after, before = np.concatenate((mass[1:], [-1.0])), np.concatenate(([-1.0], mass[:-1]))
    peak = (mass >= after) & (mass >= before) & (mass >= 0.5 * mass.max())
    i = int(np.flatnonzero(peak)[0])
    if leafy is not None:
        leaf = np.asarray(leafy, dtype=bool)[ok]

        def leaf_share(k: int) -> float:
            """The leaf-green share of the depths from edge ``k - 1`` to edge ``k + 2`` (both included): counted on
            the depths as they are, not carried through the sort (a whole number of pixels either way)."""
            lo, hi = edges[max(k - 1, 0)], edges[min(k + 2, n_bins)]
            a, b = np.searchsorted(z, lo), np.searchsorted(z, hi, "right")
            return int(np.count_nonzero(leaf & (kept >= lo) & (kept <= hi))) / (b - a) if b - a >= 10 else 0.0

        if leaf_share(i) >= LEAFY[0]:
            local = (mass >= after) & (mass >= before) & (mass >= 0.1 * mass.max())
            behind = [int(k) for k in np.flatnonzero(local) if i < k < len(counts)]
            i = next((k for k in behind if leaf_share(k) < LEAFY[1] and mass[k] >= 10), i)
    # the fruit's depths run without a gap from its nearest point to its rim: walk nearer while bins are filled
    # (an occluder in front is apart in depth; a fruit receding along its length is not)
    first = i
    least = max(2, 0.01 * len(z))
    while first > 0 and counts[first - 1] >= least:
        first -= 1
    lo = edges[first]
    if first < i and counts[i] >= least:
        # a gap is a bin's width of depths holding fewer than the filled bin's count, wherever it starts: read on the
        # bins' grid alone, whose phase is the nearest depth's, a gap a bin wide is walked over or not by where the
        # grid falls on it (a leaf 12 mm in front of a half-hidden apple, the mask moved by one pixel: stop 59,
        # docs/reg59.md). A peak bin not filled itself (its three bins' mass its neighbours') walks as before: its
        # nearer neighbour is the peak's surface, and the depths a bin beyond are the next one's
        end = edges[min(i + 1, n_bins)]
        run = z[np.searchsorted(z, lo, side="left") : np.searchsorted(z, end, side="left")]
        gap = _gap_before(run, int(np.searchsorted(run, edges[i], side="left")), least, float(edges[1] - edges[0]))
        if gap > lo:  # a walk stopped at it: on the bin holding it, from its first depth after the gap
            first = i
            while first > 0 and counts[first - 1] >= least and edges[first] > gap:
                first -= 1
            lo = max(edges[first], min(gap, float(end))) if first < i else edges[first]
    hi = edges[first + 1] if first < i else edges[min(i + 2, n_bins)]
    front = _sorted_quantile(z[np.searchsorted(z, lo, side="left") : np.searchsorted(z, hi, side="right")], 0.05)
    return front, radius_px * front / focal


def _gap_before(run: np.ndarray, below: int, least: float, width: float) -> float:
    """The depth after the last gap among ``run`` (sorted depths) before its ``below``-th: the first depth after the
    last window ``width`` wide that starts after one of the first ``below`` depths and holds fewer than ``least`` of
    them (the depth past ``run``'s end when none follows: +inf), or -inf where there is no such window.
    :func:`fruit_depth`'s walk nearer reads its filled bins at every phase so (its compiled twin:
    :func:`symfruit.core._jit.gap_before`, the same comparisons)."""
    t = int(np.ceil(least))
    n = len(run)
    j = np.arange(below)
    ahead = np.minimum(j + t, n - 1)
    gaps = np.flatnonzero((j + t >= n) | (run[ahead] - run[j] > width))
    if len(gaps) == 0:
        return float("-inf")
    last = int(gaps[-1])
    return float(run[last + 1]) if last + 1 < n else float("inf")


#: (a leaf, not a leaf): a depth peak at least this share of whose pixels are leaf green is a leaf, one below the
#: second share is not (:func:`fruit_depth`).
LEAFY = (0.5, 0.3)

#: :func:`thin_front`: (sheet, fruit, known): a surface whose mean curvature times the fruit's radius is below the
#: first number, and below it plus 0.2 two standard errors up, is a sheet (a leaf: a fruit's cap reads about 1, a leaf
#: about 0); a part behind it reading at least the second is the fruit; either known to within the third (one standard
#: error, times the radius).
THIN = (0.3, 0.5, 0.25)


@dataclass(frozen=True)
class Around:
    """The depth around a mask's box (:func:`thin_front`): ``depth`` (0: none) and ``mask`` on a window holding the
    box at rows ``r0``, columns ``c0``."""

    depth: np.ndarray
    mask: np.ndarray
    r0: int
    c0: int
    #: a True for each :meth:`beyond` asked (:func:`fruit_surface`'s :class:`Reading` then depends on the window)
    asked: list[bool] = field(default_factory=list, repr=False, compare=False)

    def beyond(self, part: np.ndarray, join: float) -> int:
        """How many pixels outside the mask continue the surface of ``part`` (a (h, w) bool image on the box): the
        window's pixels with depth, joined to it through neighbours within ``join`` (:func:`_smooth_parts`)."""
        self.asked.append(True)
        labels, _ = _smooth_parts(self.depth, self.depth > 0, join)
        h, w = part.shape
        inside = labels[self.r0 : self.r0 + h, self.c0 : self.c0 + w][part]
        ids = np.unique(inside[inside > 0])
        if not len(ids):
            return 0
        return int(np.count_nonzero(np.isin(labels, ids) & ~self.mask))


def thin_front(depth: np.ndarray, mask: np.ndarray, focal: float, front: float, radius: float, join: float,
               noise: float = 0.0, *, around: Around | None = None) -> tuple[float, np.ndarray] | None:  # fmt: skip
    """``(front, sheet)`` when the mask's nearest surface is a thin sheet in front of the fruit (a leaf drawn into
    the mask, its depth fattened over the fruit's edge by a stereo camera), told by its shape alone: None when not.

    The mask's pixels with depth fall into smooth parts (neighbours whose depths differ by at most ``join``: a
    surface's depth runs on, a leaf's edge over the fruit is a step). The part holding the depth mode's front
    (``front``, :func:`fruit_depth`) is a sheet when its mean curvature is clearly below a fruit's (:data:`THIN`;
    a convex cap's depth grows towards its outline as ``r^2 / 2R``, a leaf is flat or gently curved). The fruit is
    then the largest part behind it, touching it (what the leaf hides is bounded by its edge), clearly convex
    and holding at least a tenth of the sheet's pixels; its front is :func:`fruit_depth`'s of its own depths (bins
    of the measured ``noise``). A front part not flat is passed over too, for a convex part behind it, touching it,
    that holds more pixels than it (a leaf's depth a stereo camera fattens a few pixels into a mask of the visible
    fruit; an occluder's part too small or curled to be told flat: a fruit's own front is its mask's largest part),
    and only where it lies in front of that part's surface extended under it by more than ``join`` (an occluder lies
    in front of the fruit; the fruit's own front seen apart from the rest of it, a hole in the leaves or a step of
    noise between, lies on it: stop 41, docs/strip41.md).
    Where noise bridges the step (``join`` a few noise deviations wide, a stereo camera's far depth), the parts
    are found again on the depth's 5 x 5 median (steps kept, the noise a third), joined at three of its own noise
    deviations (read at a lag of the filter's width), when three of ``noise`` exceed 3 mm. A fruit alone (its cap
    is convex), a leaf with nothing convex behind, a mask without a sheet: None.

    Parameters
    ----------
    depth : (h, w) float, metres (0: none)
    mask : (h, w) bool
    focal : float, pixels
    front, radius : float, metres
        The depth mode's front and the fruit's radius there (:func:`fruit_depth`).
    join : float, metres
        The largest depth difference between neighbours of one surface (the convexity test's tolerance).
    noise : float, metres
        The depth's noise (:func:`depth_noise`).

    Returns
    -------
    (front, sheet) : float metres and (h, w) bool (the sheet's pixels), or None
    """
    # a registered depth image repeats a coarser camera's pixels: the fits' standard errors count its own pixels
    plain = depth.dtype == np.float64 and depth.ndim == 2 and mask.dtype == bool and mask.shape == depth.shape
    if (jit := compiled() if plain else None) is not None:
        # every pass between the fits in one call (stop 51, surface51: the same pixels, parts and numbers)
        return _thin_front_compiled(jit, depth, mask, focal, front, radius, join, noise, around)
    # the numpy twin of what follows (thin_passes' twin: _thin_counts, _reaches_outline, _smooth_parts, _part_sizes,
    # _window_medians, _lag_differences, the deviation's medians)
    ok, counts, rows, cols = _thin_counts(depth, mask, front, join)
    inflate = _inflation(counts)
    # the nearest surface clearly convex is the fruit's own front, not a sheet: nothing to look behind (one fit
    # instead of the parts, their fits and the median's re-partition on every fruit seen whole: the benchmark
    # frame's extraction 24.8 -> 16.8 ms thread CPU, 7.6 without the test); rows, cols: the pixels with depth within
    # join of the front
    # ... unless it reaches the mask's outline: a fruit's nearest point lies inside its outline, while the nearest
    # edge of a tilted leaf, or a leaf's depth fattened over the fruit, runs along it (a narrow band whose fit reads
    # any curvature). The outline is asked first: where it is reached the fit decides nothing (stop 44, speedreg44:
    # the registration's cue, its depth a few pixels off the mask, reaches it on most fruit)
    if len(rows) >= 30 and not _reaches_outline(mask, rows, cols):
        kappa, error = _mean_curvature(rows, cols, depth[rows, cols], focal)
        if (kappa - 2.0 * inflate * error) * radius >= THIN[0]:
            return None
    parts, count = _smooth_parts(depth, mask, join)
    found = _behind_sheet(depth, mask, focal, front, radius, join, inflate, parts, count, noise=noise, around=around)
    if found is not None:
        return found
    if 3.0 * noise <= 0.003 or counts[0] < 60:
        return None  # the step was not bridged by noise
    # the 5 x 5 median (edges repeated) at the mask's pixels with depth alone, the only ones read: the same values as
    # ndimage.median_filter(..., mode="nearest") there, without sweeping the box's other pixels; a pixel without depth
    # takes its nearest pixel's (compiled: window_medians, lag_differences and median_deviation in thin_passes)
    smooth, diff = _lag_differences(_window_medians(depth, ok), ok, mask, 5)
    if len(diff) < 20:
        return None
    mad = median(np.abs(diff - median(diff)))
    sigma = 1.4826 * float(mad) / np.sqrt(2.0)
    narrow = min(join, max(3.0 * sigma, 0.003))
    if narrow >= join:
        return None  # the same parts
    parts, count = _smooth_parts(smooth, mask, narrow)
    return _behind_sheet(depth, mask, focal, front, radius, join, inflate, parts, count, noise=noise, around=around)


def _inflation(counts: np.ndarray) -> float:
    """:func:`thin_front`'s factor on the sheet's standard error from :func:`_thin_counts`' counts: the square root of
    how many pixels repeat one depth pixel (a registered depth image repeats a coarser camera's pixels)."""
    repeats = 1.0
    for both, equal in ((counts[1], counts[2]), (counts[3], counts[4])):
        if both:
            repeats /= max(1.0 - float(equal) / float(both), 0.1)
    return float(np.sqrt(repeats))


def _thin_front_compiled(
    jit: Any,
    depth: np.ndarray,
    mask: np.ndarray,
    focal: float,
    front: float,
    radius: float,
    join: float,
    noise: float,
    around: Around | None,
) -> tuple[float, np.ndarray] | None:
    """:func:`thin_front` by :func:`symfruit.core._jit.thin_passes` (``depth`` (h, w) float64, ``mask`` bool of its
    shape): every pass of the twin's between its fits (the counts, the outline test, both partitions into smooth parts
    and their sizes, the 5 x 5 median and its noise) in one call, the fits and the rest of :func:`_behind_sheet` here,
    in the twin's order: the same answer, bit for bit (stop 51, surface51)."""
    ok, counts, labels = np.empty(depth.shape, bool), np.empty(5, np.int64), np.empty(depth.shape, np.int32)
    args = (depth, mask, float(front), float(join), float(noise))
    answer, rows, cols, count, sizes, near = jit.thin_passes(*args, 0, ok, counts, labels)
    inflate = _inflation(counts)
    if answer == jit.THIN_FIT:  # the nearest surface clearly convex is the fruit's own front (as the twin asks)
        if _clearly_convex(jit, rows, cols, depth, focal, inflate, radius):
            return None
        answer, _, _, count, sizes, near = jit.thin_passes(*args, 1, ok, counts, labels)
    if answer == jit.THIN_SHEET:
        found = _behind_sheet(depth, mask, focal, front, radius, join, inflate, labels, int(count), noise=noise,
                              around=around, counted=(sizes, near))  # fmt: skip
        if found is not None:
            return found
        answer, _, _, count, sizes, near = jit.thin_passes(*args, 2, ok, counts, labels)
    if answer == jit.THIN_SMOOTHED:
        return _behind_sheet(depth, mask, focal, front, radius, join, inflate, labels, int(count), noise=noise,
                             around=around, counted=(sizes, near))  # fmt: skip
    return None


#: :func:`_clearly_convex`: the compiled fit answers where the test's value lies farther from its bound than this many
#: times the rounding's scale (the normal matrix's condition number times the double's epsilon, times the test's
#: terms); the kernel and its twin differ by about ten times that scale (the benchmark frame's fits: 0.4-1.7e-12 of
#: the curvature at condition numbers of 0.4-6e9; stop 62, cap62), so both lie on one side of the bound
CERTAIN = 1e4


def _clearly_convex(
    jit: Any, rows: np.ndarray, cols: np.ndarray, depth: np.ndarray, focal: float, inflate: float, radius: float
) -> bool:  # fmt: skip
    """:func:`thin_front`'s test whether the nearest surface, seen at the pixels ``rows, cols`` of ``depth``, is
    clearly convex: ``(kappa - 2 inflate error) radius >= THIN[0]`` of :func:`_mean_curvature` (``inflate``: the
    standard error's factor, :func:`_inflation`; ``radius``: the fruit's, metres). By its compiled fit
    (:func:`symfruit.core._jit.thin_curvature`, the same pixels drawn where there are more than 2,048) where the
    value lies farther than :data:`CERTAIN` times the rounding's scale from the bound, so the twin's fit, the same to
    rounding, answers alike; the twin's fit itself elsewhere (a singular fit, a value at the bound: the same answer
    as before). 5-25 against 25-45 us a fit (stop 62, cap62)."""
    some_rows, some_cols = rows, cols
    if len(rows) > 2048:  # the twin's draw (_InverseQuadratic)
        some = np.sort(_seeded().choice(len(rows), 2048, replace=False))
        some_rows, some_cols = rows[some], cols[some]
    done, kappa, error, condition = jit.thin_curvature(some_rows, some_cols, depth, float(focal))
    if done:
        value = (kappa - 2.0 * inflate * error) * radius - THIN[0]
        scale = ((abs(kappa) + 2.0 * abs(inflate * error)) * abs(radius) + THIN[0]) * condition * _EPS
        if np.isfinite(value) and np.isfinite(scale) and abs(value) > CERTAIN * scale:
            return bool(value > 0.0)
    kappa, error = _mean_curvature(rows, cols, depth[rows, cols], focal)
    return bool((kappa - 2.0 * inflate * error) * radius >= THIN[0])


#: the double's epsilon (:func:`_clearly_convex`)
_EPS = float(np.finfo(np.float64).eps)


def _reaches_outline(mask: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> bool:
    """Whether one of the pixels ``(rows, cols)`` lies on ``mask``'s outline (a pixel of it with a 4-neighbour outside
    it or beyond the array). The compiled twin: :func:`symfruit.core._jit.reaches_outline` (stop 45)."""
    return bool((mask & ~interior(mask))[rows, cols].any())


def _thin_counts(
    depth: np.ndarray, mask: np.ndarray, front: float, join: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`thin_front`'s first pass: ``ok`` (h, w) bool, the mask's pixels with depth above 0; the counts (5,)
    int: ``ok``'s pixels, then of the vertical and of the horizontal neighbours both ``ok``, how many pairs and how
    many of them hold equal depths (a registered depth image repeats a coarser camera's pixels); and the rows and
    columns (``np.nonzero``'s) of the ``ok`` pixels within ``join`` of ``front``. The compiled twin:
    :func:`symfruit.core._jit.thin_counts` (stop 43)."""
    ok = mask & (depth > 0)
    counts = [int(np.count_nonzero(ok))]
    pairs = ((depth[1:], depth[:-1], ok[1:] & ok[:-1]), (depth[:, 1:], depth[:, :-1], ok[:, 1:] & ok[:, :-1]))
    for a, b, both in pairs:
        counts += [int(np.count_nonzero(both)), int(np.count_nonzero((a == b) & both))]
    rows, cols = np.nonzero(ok & (np.abs(depth - front) <= join))
    return ok, np.array(counts, np.int64), rows, cols


def _window_medians(depth: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """(n,) the 5 x 5 median (edges repeated) of ``depth`` (h, w) at the pixels of ``ok`` (h, w) bool (raster order;
    it must hold one), each pixel not ``ok`` taking its nearest ``ok`` pixel's depth (scipy's feature transform):
    :func:`thin_front`'s smoothed depth. The compiled twin: :func:`symfruit.core._jit.window_medians` (stop 45)."""
    rows, cols = np.nonzero(ok)
    _, (ri, ci) = ndimage.distance_transform_edt(~ok, return_indices=True)
    return median_at(depth[ri, ci], rows, cols, size=5)


def _lag_differences(
    medians: np.ndarray, ok: np.ndarray, mask: np.ndarray, lag: int
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`thin_front`'s smoothed depth (h, w): 0 but at the pixels of ``ok`` (h, w) bool, which take ``medians``
    (n,) in raster order; and the differences (m,) ``smooth[r, c + lag] - smooth[r, c]`` where both pixels are
    ``mask``'s and both values above 0, in raster order. The compiled twin: :func:`symfruit.core._jit.lag_differences`
    (stop 43)."""
    smooth = np.zeros(ok.shape)
    smooth[ok] = medians
    a, b = smooth[:, lag:], smooth[:, :-lag]
    return smooth, (a - b)[mask[:, lag:] & mask[:, :-lag] & (a > 0) & (b > 0)]


def _behind_sheet(depth: np.ndarray, mask: np.ndarray, focal: float, front: float, radius: float, join: float,
                  inflate: float, parts: np.ndarray, count: int, *, noise: float = 0.001,
                  around: Around | None = None,
                  counted: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[float, np.ndarray] | None:  # fmt: skip
    """:func:`thin_front` on one partition of the mask into smooth parts (``parts``: 0 none, 1..``count``), the
    sheet's curvature's standard error times ``inflate`` (the square root of how many pixels repeat one depth pixel:
    a flat reading must hold on the camera's own pixels; the cap behind is not asked as much). A front part that is
    not a sheet is passed over only for a convex part behind it holding more pixels than it does: an occluder whose
    shape is not told (a strip of a leaf's depth a stereo camera fattens into a mask of the visible fruit, a few
    pixels wide; a leaf's small or curled part) hides less of the mask than the fruit shows, while a fruit's own front
    is the mask's largest surface (stop 40, docs/leaf40.md). Such a front part must also lie in front of the part
    behind's surface extended under it (:meth:`_InverseQuadratic.offset`) by more than ``join``: one lying on it is
    that fruit's own front, parted from the rest of its surface (stop 41, docs/strip41.md). Behind a sheet told flat, a
    part whose fit reads convex at two standard errors and more curved than the sheet by two of both errors is the
    fruit too, though below a fruit's curvature (a cap a time-of-flight camera flattens: stop 62, docs/true62.md).
    ``noise``: the depth's noise, for :func:`fruit_depth`'s bins on the part behind. ``counted``: :func:`_part_sizes`'
    counts when the caller has them (:func:`symfruit.core._jit.thin_passes`)."""
    if count < 2:
        return None
    plain = parts.ndim == 2 and parts.shape == depth.shape and depth.dtype == np.float64
    if counted is not None:
        sizes, near = counted
    elif (jit := compiled() if plain else None) is not None:  # the compiled twin of _part_sizes (stop 45: the same)
        sizes, near = jit.part_sizes(parts, int(count), depth, float(front), float(join))
    else:
        sizes, near = _part_sizes(parts, count, depth, front, join)
    if not near.any():
        return None
    sheet_id = int(np.argmax(near[1:])) + 1
    n_sheet = int(sizes[sheet_id])
    if n_sheet < 30:
        return None
    others = sizes[1:].copy()
    others[sheet_id - 1] = 0  # the largest other part (every part holds a pixel: the same maximum)
    largest = int(others.max())
    if largest < max(30, 0.1 * n_sheet):
        # no part large enough behind (a fruit's own front, not flat: the usual case, ended here), whatever the
        # sheet's fit reads: asked before it and before the sheet's pixels are listed (stop 44, speedreg44)
        return None
    sheet = parts == sheet_id
    rows, cols = np.nonzero(sheet)
    kappa, error = _mean_curvature(rows, cols, depth[rows, cols], focal)
    error *= inflate
    sheet_kappa, sheet_error = kappa, error
    flat = kappa * radius < THIN[0] and (kappa + 2.0 * error) * radius < THIN[0] + 0.2 and error * radius <= THIN[2]
    # not a sheet: still an occluder where a convex part behind it is larger (a fruit's own front is its largest part)
    least = max(30, 0.1 * len(rows)) if flat else len(rows) + 1
    # a surface whose most pixels lie outside the mask is not the fruit the mask is drawn on (a leaf running on
    # beyond the fruit's outline): a smaller part behind it is looked at, and it need not prove itself convex (the
    # window's parts are followed only where this decides: once a mask)
    known: list[bool] = []

    def outside() -> bool:
        if not known:
            known.append(around is not None and around.beyond(sheet, join) > len(rows))
        return known[0]

    if not flat and outside():
        least = max(30, 0.1 * len(rows))
    if largest < least:
        return None
    far = float(median(depth[rows, cols]))
    # what the sheet hides is bounded by its edge: a part touching it (a few pixels apart: a stereo camera's
    # shadow, a time-of-flight camera's invalid rim lie between)
    reach = 3 + int(np.ceil(0.3 * np.sqrt(mask.sum() / np.pi)))
    touching = ndimage.binary_dilation(sheet, iterations=reach)
    order = np.argsort(-sizes[1:], kind="stable") + 1
    for k in order:
        if sizes[k] < least:
            break
        if k == sheet_id:
            continue
        pr, pc = np.nonzero(parts == k)
        z = depth[pr, pc]
        if float(median(z)) <= far + join or not touching[pr, pc].any():
            continue
        seen = _InverseQuadratic(pr, pc, z, focal)
        kappa, error = seen.curvature()
        told = kappa * radius >= THIN[1] and error * radius <= THIN[2]
        # behind a sheet told flat, a part whose fit reads convex at two standard errors and more curved than the
        # sheet by two of both errors: a fruit's cap a time-of-flight camera flattens (its rim lost, 1 mm steps: the
        # real 60 mm sphere's cap behind a leaf reads kappa R 0.18 +- 0.014, below THIN[0]) is still convex where the
        # leaf is flat (stop 62, docs/true62.md)
        bulged = flat and kappa > 2.0 * error and kappa - 2.0 * error > sheet_kappa + 2.0 * sheet_error
        # behind a surface shown not the fruit's, a part curved more than a sheet and convex at two standard errors;
        # behind a sheet told flat, a part whose curvature is not known (its fit's error beyond THIN[2]) but may be a
        # fruit's (THIN[1] within two standard errors): what a leaf hides is the fruit's, and a stereo camera's far,
        # fattened depth leaves of it a few noisy pixels whose fit tells nothing (stop 45, docs/leaf45.md)
        unknown = flat and error * radius > THIN[2] and (kappa + 2.0 * error) * radius >= THIN[1]
        if told or unknown or bulged or (kappa * radius >= THIN[0] and kappa > 2.0 * error and outside()):
            behind, _ = fruit_depth(z, np.sqrt(mask.sum() / np.pi), focal, noise=noise)
            if not flat and seen.offset(rows, cols, depth[rows, cols]) >= -join:
                continue  # on the part behind's own surface, extended under it: that fruit's own front, not an occluder
            if np.isfinite(behind) and behind > front:
                return behind, sheet
    return None


def _crossings(parts: np.ndarray, mask: np.ndarray, count: int) -> tuple[np.ndarray, int]:
    """(count + 1,) int: for each part of ``parts`` (0 none, 1..``count``), how many pairs of 4-neighbours it holds
    with one pixel in ``mask`` and the other outside it (its surface running on across the mask's outline); and the
    mask's outline pixels (those with a 4-neighbour outside it, within the array)."""
    cross = np.zeros(count + 1, np.int64)
    edge = np.zeros(mask.shape, bool)
    for a, b in ((np.s_[1:], np.s_[:-1]), (np.s_[:-1], np.s_[1:])):
        for pa, pb in (((a, slice(None)), (b, slice(None))), ((slice(None), a), (slice(None), b))):
            out = mask[pa] & ~mask[pb]
            edge[pa] |= out
            same = out & (parts[pa] == parts[pb]) & (parts[pa] > 0)
            cross += np.bincount(parts[pa][same], minlength=count + 1)
    return cross, int(np.count_nonzero(edge))


def _behind_crossing(depth: np.ndarray, mask: np.ndarray, focal: float, front: float, radius: float, join: float,
                     noise: float) -> float | None:  # fmt: skip
    """The front of the fruit behind an occluder its mask is drawn over, told by where surfaces end: None when the
    mask's nearest surface is not such an occluder.

    An annotator draws a fruit's mask round the fruit (a few pixels over its edge), so the fruit's own surface ends
    inside the mask's outline: its rim, a step to what lies behind or a rim without depth. A leaf or branch in front
    that the mask is drawn over is larger than what it hides of the fruit and runs on across the outline. The mask's
    nearest surface (the smooth part, :func:`_smooth_parts` on the depth in and around the mask, holding the depth
    mode's front) is passed over when it runs on across the outline along at least :data:`CROSSING` of it; the fruit
    is then the nearest part behind it, in the mask with at least 10 pixels, that does not run on across the outline
    (at most a tenth of the crossing pixel pairs the front's holds), that touches a part passed over (what an
    occluder hides is bounded by its edge) and that is not told flat (:data:`THIN`, as :func:`thin_front` tells a
    sheet: a leaf ending inside the mask is passed over too); its front, :func:`fruit_depth`'s of its own depths,
    must lie further behind ``front`` than the fruit can be deep: two radii, or the mask's longer principal width
    for an elongated fruit (the occluder a separate layer in front of the whole fruit). A
    nearest surface curved in every direction as a fruit's cap (its least principal curvature at least ``THIN[0] /
    radius``) is the fruit's own front, joined to a surface at its depth that crosses: not passed over."""
    found = mask_box(mask)
    if found is None:
        return None
    r0, r1 = max(found[0] - 1, 0), min(found[1] + 1, mask.shape[0])
    c0, c1 = max(found[2] - 1, 0), min(found[3] + 1, mask.shape[1])
    d, m = depth[r0:r1, c0:c1], np.asarray(mask[r0:r1, c0:c1], dtype=bool)
    rim = m & ~interior(m)
    if np.count_nonzero(rim & (d > 0) & (d <= front + radius)) < CROSSING * np.count_nonzero(rim):
        return None  # too little of the outline in front of the fruit's middle for a surface there to run on across
    parts, count = _smooth_parts(d, d > 0, join)
    if count < 2:
        return None
    cross, outline = _crossings(parts, m, count)
    inside = np.bincount(parts[m], minlength=count + 1)
    near = m & (parts > 0) & (np.abs(d - front) <= join)
    if not near.any():
        return None
    sheet = int(np.argmax(np.bincount(parts[near], minlength=count + 1)))
    if cross[sheet] < CROSSING * outline:
        return None  # the nearest surface ends inside the outline: the fruit's own (the usual case, ended here)
    # ... or it is the fruit's own front, joined to a surface at its depth that crosses (a leaf touching its rim): its
    # part in the mask is then curved in every direction as a fruit's cap is, where a leaf is flat and a branch is
    # curved across its length only
    rows, cols = np.nonzero(m & (parts == sheet))
    if _least_curvature(rows, cols, d[rows, cols], focal) * radius >= THIN[0]:
        return None
    ids = np.flatnonzero((inside >= 10) & (np.arange(count + 1) > 0))
    if len(ids) < 2:
        return None
    inner = parts * m
    medians = np.asarray(ndimage.median(d, inner, ids), dtype=np.float64)
    order = np.argsort(medians, kind="stable")
    sheet_depth = float(medians[int(np.flatnonzero(ids == sheet)[0])]) if sheet in ids else front
    passed = parts == sheet
    reach = 3 + int(np.ceil(0.3 * np.sqrt(m.sum() / np.pi)))
    for j in order:
        k, z_k = int(ids[j]), float(medians[j])
        if k == sheet:
            continue
        own = parts == k
        if z_k <= sheet_depth + join:
            # not behind the nearest surface: a part of its layer, parted from it by a step, where it runs on across
            # the outline too (its median within join of the sheet's, on either side as the mask moves by a pixel:
            # stop 60, docs/thin60.md)
            if cross[k] >= CROSSING * outline:
                passed |= own
            continue
        if cross[k] <= 0.1 * cross[sheet] and ndimage.binary_dilation(passed, iterations=reach)[own].any():
            rows, cols = np.nonzero(own & m)
            kappa, error = _mean_curvature(rows, cols, d[rows, cols], focal)
            r_k = radius * z_k / front
            if kappa * r_k < THIN[0] and (kappa + 2.0 * error) * r_k < THIN[0] + 0.2 and error * r_k <= THIN[2]:
                passed |= own  # told flat as thin_front tells a sheet: a leaf ending inside the mask, not the fruit
                continue
            behind, _ = fruit_depth(d[own & m], float(np.sqrt(m.sum() / np.pi)), focal, noise=noise)
            # a separate layer: the occluder lies in front of the whole fruit, more than a fruit's depth before what
            # it hides (about its width, two radii, for a round fruit; up to its length for an elongated one, read off
            # the mask's longer principal width: a banana seen obliquely has its far end that far behind its near
            # one, stop 46); nearer, the part behind may be the fruit's own far side
            length = principal_widths(m)[1] * front / focal
            return behind if np.isfinite(behind) and behind > front + max(2.0 * radius, length) else None
        if cross[k] >= CROSSING * outline:
            passed |= own  # an occluder behind the first, running on across the outline too
    return None


def _least_curvature(rows: np.ndarray, cols: np.ndarray, z: np.ndarray, focal: float) -> float:
    """1/metres: the lesser principal curvature of the surface seen at the pixels (:class:`_InverseQuadratic`'s fit;
    its mean is :func:`_mean_curvature`'s): about ``1 / R`` on a fruit's cap, 0 on a leaf or along a branch; NaN
    where the fit is singular or too few pixels (under 30)."""
    if len(z) < 30:
        return float("nan")
    fit = _InverseQuadratic(rows, cols, z, focal)
    if fit.inverse is None:
        return float("nan")
    a, b, c = (float(fit.coef[k]) for k in (3, 4, 5))
    # the principal curvatures are -zm^2 times the eigenvalues of the inverse depth's Hessian [[2a, b], [b, 2c]] (on a
    # sphere a = c = -1 / (2 R zm^2): both 1 / R); the lesser is the greater eigenvalue's (eigenvalues2: eigvalsh's
    # values bit for bit, numpy's call only where LAPACK would scale the matrix)
    eig = eigenvalues2(2.0 * a, b, 2.0 * c)
    if eig is None:
        eig = tuple(lapack.eigvalsh(np.array([[2.0 * a, b], [b, 2.0 * c]])))
    return -fit.zm * fit.zm * float(eig[1])


#: :func:`_behind_crossing`: the least share of a mask's outline along which its nearest surface runs on across it
#: for that surface to be an occluder drawn over, not the fruit (whose own surface ends inside its mask's outline).
CROSSING = 0.125


def _part_sizes(
    parts: np.ndarray, count: int, depth: np.ndarray, front: float, join: float
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """(count + 1,) int each: the pixels of each part of ``parts`` (0 none, 1..``count``), and of each part those whose
    depth lies within ``join`` of ``front`` (0 at 0). The compiled twin: :func:`symfruit.core._jit.part_sizes`
    (stop 45)."""
    near = (parts > 0) & (np.abs(depth - front) <= join)
    return np.bincount(parts.ravel(), minlength=count + 1), np.bincount(parts[near], minlength=count + 1)


def _smooth_parts(depth: np.ndarray, mask: np.ndarray, join: float) -> tuple[np.ndarray, int]:
    """(h, w) int labels (0: none, 1..n) and n: the pixels of ``mask`` with depth whose 4 neighbours (those in the
    mask with depth) all lie within ``join`` of them, joined 4-connected (a surface's depth runs on; a pixel on a
    depth step belongs to neither side). By its compiled twin where numba is (:func:`symfruit.core._jit.smooth_parts`:
    the same labels; stop 42)."""
    jit = compiled()
    if jit is not None and depth.dtype == np.float64 and depth.ndim == 2 and mask.dtype == bool:
        labels = np.empty(depth.shape, np.int32)
        return labels, int(jit.smooth_parts(depth, mask, float(join), labels))
    ok = mask & (depth > 0)
    smooth = ok.copy()
    pairs = ((depth[1:], depth[:-1], ok[1:], ok[:-1]), (depth[:, 1:], depth[:, :-1], ok[:, 1:], ok[:, :-1]))
    for za, zb, a, b in pairs:
        step = a & b & (np.abs(za - zb) > join)
        if za.shape[0] < depth.shape[0]:
            smooth[1:] &= ~step
            smooth[:-1] &= ~step
        else:
            smooth[:, 1:] &= ~step
            smooth[:, :-1] &= ~step
    labels, count = ndimage.label(smooth)
    return labels, int(count)


def _mean_curvature(rows: np.ndarray, cols: np.ndarray, z: np.ndarray, focal: float) -> tuple[float, float]:
    """``(kappa, error)``, 1/metres: the mean curvature of the surface seen at the pixels (positive where depth grows
    away from its middle, as on a fruit's front: ``1 / R`` on a sphere of radius R) and its standard error
    (:class:`_InverseQuadratic`)."""
    return _InverseQuadratic(rows, cols, z, focal).curvature()


class _InverseQuadratic:
    """A least-squares quadratic in the lateral coordinates fitted to the inverse depth ``z`` seen at the pixels
    ``rows, cols`` (exactly affine on a plane, whatever its tilt); on at most 2,048 of the pixels drawn by a seeded
    generator (the fit needs no more; a stride through their row order could alias with the rows' widths). Its mean
    curvature (:meth:`curvature`) and the depth of the surface it extends under other pixels (:meth:`offset`) from
    the one fit."""

    def __init__(self, rows: np.ndarray, cols: np.ndarray, z: np.ndarray, focal: float) -> None:
        if len(z) > 2048:
            # np.random.default_rng(0)'s draws, from the thread's generator set back to that state (stop 46: 25 us)
            some = np.sort(_seeded().choice(len(z), 2048, replace=False))
            rows, cols, z = rows[some], cols[some], z[some]
        # stop 42: points.median (np.median's value, bit for bit): 45 us a fit less
        self.zm, self.focal = float(median(z)), focal
        self.r0, self.c0 = float(rows.mean()), float(cols.mean())
        a = self._design(rows, cols)
        w = 1.0 / z
        try:
            self.inverse: np.ndarray | None = lapack.inv(a.T @ a)  # np.linalg.inv's LAPACK call and values
        except np.linalg.LinAlgError:
            self.inverse = None
            return
        self.coef = self.inverse @ (a.T @ w)
        res = w - a @ self.coef
        self.var = float(res @ res) / max(len(w) - 6, 1)

    def _design(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        x = (cols - self.c0) * (self.zm / self.focal)
        y = (rows - self.r0) * (self.zm / self.focal)
        # np.stack((ones, x, y, x x, x y, y y), axis=1)'s array, its columns written in place (stop 42)
        a = np.empty((len(x), 6))
        a[:, 0] = 1.0
        a[:, 1], a[:, 2] = x, y
        np.multiply(x, x, out=a[:, 3])
        np.multiply(x, y, out=a[:, 4])
        np.multiply(y, y, out=a[:, 5])
        return a

    def curvature(self) -> tuple[float, float]:
        """``(kappa, error)``, 1/metres: :func:`_mean_curvature`'s; ``(nan, inf)`` where the fit is singular."""
        if self.inverse is None:
            return float("nan"), float("inf")
        i, zm = self.inverse, self.zm
        kappa = -zm * zm * float(self.coef[3] + self.coef[5])
        error = zm * zm * float(np.sqrt(max(self.var * (i[3, 3] + i[5, 5] + 2.0 * i[3, 5]), 0.0)))
        return kappa, error

    def offset(self, at_rows: np.ndarray, at_cols: np.ndarray, at_z: np.ndarray) -> float:
        """Metres: the median depth ``at_z`` of the pixels ``at_rows, at_cols`` less the depth there of the surface,
        extended under them: negative where they lie in front of it (an occluder), about 0 where they lie on it (the
        same surface, parted by a step). A surface whose extension turns away (no positive inverse depth there), or
        a singular fit, lies infinitely far."""
        if self.inverse is None:
            return float("-inf")
        inverse = self._design(at_rows, at_cols) @ self.coef
        there = np.where(inverse > 0, 1.0 / np.where(inverse > 0, inverse, 1.0), np.inf)
        return float(median(at_z - there))


#: :func:`across_occluder`: the least points a part needs for a surface to be fitted to it (as
#: :func:`_least_curvature`), and the least pixels of a nearer surface between two parts for it to be an occluder
#: crossing the fruit (as :func:`fruit_depth` needs for a surface), not a flying pixel.
PART_POINTS = 30
NEARER_PIXELS = 10
#: :func:`across_occluder` looks at this many of the largest other parts at most (a mask over foliage may hold many).
MAX_PARTS = 8


def across_occluder(depth: np.ndarray, rows: np.ndarray, cols: np.ndarray, labels: np.ndarray, keep: int,
                    tol: float, focal: float, radius: float, grow: int = 3) -> np.ndarray:  # fmt: skip
    """(n_labels,) bool: the parts (``labels`` of the points seen at pixels ``rows, cols`` of ``depth``, metres, 0
    or NaN none) that are part ``keep``'s fruit too, ``keep`` among them: parted from it only by a nearer surface
    crossing the fruit (a twig, a leaf stalk, a leaf's midrib, a strip of leaf) and lying on one convex surface
    with it.

    A surface in front of a fruit parts its seen pixels into pieces that clustering cannot join (the occluder's
    width lies between them); the nearest piece alone is then half a fruit (issue 18, docs/strip56.md: the real
    Azure Kinect spheres under a 5 cm strip 5 cm in front kept one half, the boxes 14.5 mm too shallow). A part
    is joined, to ``keep`` and to the parts joined before it, when

    1. it does not touch them in the image (pieces that touch were parted by a depth step of their own: a leaf
       behind the fruit, the fruit's far side), but is joined to them through pixels with no depth or with depth in
       front of both by more than ``tol``, at least :data:`NEARER_PIXELS` of those in front (something nearer
       crosses between them, not only the camera's lost rim). Each part reaches ``grow`` pixels further over pixels
       not behind it (extraction's eroded border, the mixed pixels at an occluder's edge: the fruit's pixels next
       to the occluder that the parts do not hold);
    2. one convex surface holds both: the quadratic in inverse depth fitted to their points together
       (:class:`_InverseQuadratic`) is curved as no sheet is (its mean curvature times the fruit's ``radius``,
       metres, at least :data:`THIN`'s sheet bound; a part's own fit is not asked: half a real sphere's cap reads
       0.02-0.3 of it), the median of each part's depth less the fit's, and the median of its absolute value, are
       within ``tol`` (the real spheres' halves: 0.0-1.2 and 0.3-2.0 mm), and no step lies between them across the
       gap once the occluder is taken out: the medians of the two parts' depths less the fit's on their edges
       facing each other (:func:`_facing`) are within ``tol`` of each other (the fit takes a step in with a tilt,
       which leaves the two edges on either side of it: a 10 mm step 4-7 mm apart, the real halves 0.0-2.9 mm).

    At most :data:`MAX_PARTS` other parts of :data:`PART_POINTS` points or more are looked at (the largest)."""
    counts = np.bincount(labels)
    joined = np.zeros(len(counts), bool)
    joined[keep] = True
    others = [int(k) for k in np.argsort(-counts, kind="stable") if k != keep and counts[k] >= PART_POINTS]
    if counts[keep] < PART_POINTS or not others:
        return joined
    z = np.asarray(depth[rows, cols], dtype=np.float64)
    others = others[:MAX_PARTS]
    grown = True
    while grown:
        grown = False
        for k in others:
            if joined[k]:
                continue
            part = labels == k
            have = joined[labels]
            if _one_surface(rows, cols, z, have, part, tol, focal, radius) and _parted(
                depth, rows, cols, z, have, part, tol, grow
            ):  # fmt: skip
                joined[k] = grown = True
    return joined


def _one_surface(rows: np.ndarray, cols: np.ndarray, z: np.ndarray, a: np.ndarray, b: np.ndarray, tol: float,
                 focal: float, radius: float) -> bool:  # fmt: skip
    """:func:`across_occluder`'s test 2: the points ``a`` and ``b`` (bool over ``rows, cols, z``) on one convex
    surface."""
    both = a | b
    fit = _InverseQuadratic(rows[both], cols[both], z[both], focal)
    if fit.inverse is None or not fit.curvature()[0] * radius >= THIN[0]:
        return False
    inverse = fit._design(rows[both], cols[both]) @ fit.coef
    if not (inverse > 0).all():
        return False  # the surface turns away from the camera under some of them
    res = np.zeros(len(z))
    res[both] = z[both] - 1.0 / inverse
    for part in (a, b):
        r = np.ascontiguousarray(res[part])
        if abs(float(median(r))) > tol or float(median(np.abs(r))) > tol:
            return False
    # no step across the gap: the fit takes a step between the parts in with a tilt, which leaves the two edges
    # facing each other on either side of it
    facing = [float(median(np.ascontiguousarray(res[_facing(rows, cols, p, q)]))) for p, q in ((a, b), (b, a))]
    return abs(facing[0] - facing[1]) <= tol


#: :func:`_facing`: the share of a part's points nearest the other part that make its edge facing it.
FACING_SHARE = 0.1


def _facing(rows: np.ndarray, cols: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Bool over ``rows, cols``: the points of ``a`` facing ``b`` across the gap between them, the
    :data:`FACING_SHARE` of them (at least 10) nearest to ``b`` in the image."""
    from scipy.spatial import cKDTree

    ia = np.flatnonzero(a)
    dist, _ = cKDTree(np.column_stack((rows[b], cols[b]))).query(np.column_stack((rows[ia], cols[ia])))
    n = min(len(ia), max(10, int(FACING_SHARE * len(ia))))
    out = np.zeros(len(rows), bool)
    out[ia[np.argsort(dist, kind="stable")[:n]]] = True
    return out


def _parted(depth: np.ndarray, rows: np.ndarray, cols: np.ndarray, z: np.ndarray, a: np.ndarray, b: np.ndarray,
            tol: float, grow: int) -> bool:  # fmt: skip
    """:func:`across_occluder`'s test 1: the pixels of ``a`` and ``b`` do not touch (8-neighbours) and, each grown
    ``grow`` pixels over pixels not behind them, are joined through pixels of ``depth`` without depth or in front of
    both by more than ``tol``, some of them in front."""
    both = a | b
    g = grow + 1
    r0, c0 = max(int(rows[both].min()) - g, 0), max(int(cols[both].min()) - g, 0)
    r1, c1 = min(int(rows[both].max()) + g + 1, depth.shape[0]), min(int(cols[both].max()) + g + 1, depth.shape[1])
    image = np.zeros((r1 - r0, c1 - c0), np.int8)
    image[rows[a] - r0, cols[a] - c0] = 1
    image[rows[b] - r0, cols[b] - c0] = 2
    if (ndimage.binary_dilation(image == 1, np.ones((3, 3), bool)) & (image == 2)).any():
        return False  # they touch: a step of their own parted them
    d = np.asarray(depth[r0:r1, c0:c1], dtype=np.float64)
    seen = np.isfinite(d) & (d > 0)
    nearer = seen & (d < float(min(z[a].min(), z[b].min())) - tol) & (image == 0)
    bridge = (~seen & (image == 0)) | nearer
    if grow > 0:
        free = (image == 0) & ~(seen & (d > float(z[both].max()) + tol))
        bridge |= ndimage.binary_dilation(image > 0, np.ones((3, 3), bool), iterations=grow) & free
    parts, _ = ndimage.label(bridge | (image > 0), np.ones((3, 3), bool))
    where = parts[image == 1]
    for label in np.unique(where):
        through = parts == label
        if (through & (image == 2)).any() and np.count_nonzero(through & nearer) >= NEARER_PIXELS:
            return True
    return False


def _sorted_histogram(z: np.ndarray, bins: int, span: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """``np.histogram(z, bins=bins, range=span)`` of sorted ``z``: the counts between the same edges (each bin
    ``[e_i, e_i+1)``, the last closed) found by bisection instead of a pass over ``z`` per bin index."""
    lo, hi = float(span[0]), float(span[1])
    if not lo < hi:  # numpy widens an empty range; let it
        return np.histogram(z, bins=bins, range=(lo, hi))
    edges = np.linspace(lo, hi, bins + 1)
    at = np.searchsorted(z, edges, side="left")
    at[-1] = np.searchsorted(z, hi, side="right")
    return np.diff(at), edges


#: :func:`monotone_region`'s rays: this many sectors of directions.
_RAYS = 72


def monotone_region(depth: np.ndarray, keep: np.ndarray, apex: tuple[int, int], tolerance: float,
                    *, bins: int = _RAYS) -> np.ndarray:  # fmt: skip
    """(h, w) bool: the pixels of ``keep`` reached from ``apex`` along straight image rays on which depth
    never falls more than ``tolerance`` below its running maximum.

    The front of a convex body is a convex function of the image position, so it never falls along a ray
    from its nearest point; where a ray's depth turns back towards the camera it has left the fruit (onto a
    support, a stem, an occluder) and the rest of that ray is cut. Rays are ``bins`` sectors of directions;
    pixels of ``keep`` without depth are not in it.

    Parameters
    ----------
    depth : (h, w) float, metres
    keep : (h, w) bool
        The candidate pixels (with depth).
    apex : (int, int)
        Row and column of the ray's origin.
    tolerance : float, metres
    bins : int
    """
    jit = compiled() if isinstance(keep, np.ndarray) and keep.dtype == bool and keep.ndim == 2 else None
    if jit is not None and np.isfinite(tolerance) and np.shape(depth) == keep.shape:
        h, w = keep.shape
        reach = max(abs(int(apex[0])), abs(h - 1 - int(apex[0])), abs(int(apex[1])), abs(w - 1 - int(apex[1])))
        if (table := _sector_table(bins, reach)) is not None:  # the pixels, their sectors and the rays in one call
            out = np.zeros(keep.shape, dtype=bool)  # (issue 19, stop 41: monotone_at, the same pixels)
            jit.monotone_at(depth, keep, int(apex[0]), int(apex[1]), table, (table.shape[0] - 1) // 2, bins,
                            float(tolerance), out)  # fmt: skip
            return out
    if jit is not None:  # the pixels and their offsets in one pass (issue 19, nineteenth round: the same numbers)
        rows, cols, dy, dx = jit.ray_pixels(keep, int(apex[0]), int(apex[1]))
    else:
        rows, cols = np.nonzero(keep)
    out = np.zeros(keep.shape, dtype=bool)
    if not len(rows) or not np.isfinite(tolerance):
        return keep.copy() if len(rows) else out
    if jit is not None:  # the compiled twin of what follows from the directions on (the same pixels)
        h, w = keep.shape
        reach = max(abs(int(apex[0])), abs(h - 1 - int(apex[0])), abs(int(apex[1])), abs(w - 1 - int(apex[1])))
        if (table := _sector_table(bins, reach)) is not None:  # the sectors of the offsets, read off a table
            jit.monotone_table(depth, rows, cols, dy, dx, table, (table.shape[0] - 1) // 2, bins, float(tolerance),
                               out)  # fmt: skip
        else:
            jit.monotone_rays(depth, rows, cols, np.arctan2(dy, dx), dy, dx, bins, bins / (2.0 * np.pi),
                              float(tolerance), out)  # fmt: skip
        return out
    dy, dx = rows - apex[0], cols - apex[1]
    sector = np.floor((np.arctan2(dy, dx) + np.pi) * (bins / (2.0 * np.pi))).astype(np.int64) % bins
    # by sector, then by distance from the apex (ties in their pixel order): one stable sort of an integer key
    # (squared distances order as the distances do) is the lexsort of (distance, sector), a few times faster
    d2 = dy * dy + dx * dx
    order = _stable_order(sector * (int(d2.max()) + 1) + d2)
    at = (rows * keep.shape[1] + cols)[order]  # flat indices: np.take is faster than two index arrays
    z, sec = np.take(np.ascontiguousarray(depth).ravel(), at).astype(np.float64), sector[order]
    # a running maximum per sector: offset each sector above every earlier one, accumulate, take it back off
    offset = sec * (2.0 * (np.abs(z).max() + tolerance + 1.0))
    running = np.maximum.accumulate(z + offset) - offset
    fell = np.cumsum(z < running - tolerance)
    start = np.searchsorted(sec, sec, side="left")
    before = np.where(start > 0, fell[np.maximum(start - 1, 0)], 0)
    ok = fell == before
    out.ravel()[at[ok]] = True
    return out


#: :func:`_sector_table`'s tables by ``bins``, and the largest offset made one (beyond it, ``arctan2`` per pixel)
_SECTORS: dict[int, np.ndarray] = {}
_SECTOR_REACH = 512


def _sector_table(bins: int, reach: int) -> np.ndarray | None:
    """(2 r + 1, 2 r + 1) int16, ``r >= reach``: the sector of :func:`monotone_region` of every whole-number offset
    ``(dy, dx)`` within ``r`` of the apex (at ``[dy + r, dx + r]``), worked out as its compiled twin works out a
    pixel's, from numpy's ``arctan2`` of the same whole numbers (``floor((arctan2(dy, dx) + pi) * bins / (2 pi)) %
    bins``: the same values, elementwise); made once per ``bins`` for offsets up to a power of two of at least 64, and
    again larger when a larger one is asked for, up to :data:`_SECTOR_REACH` (None beyond, or for more than
    32767 bins). A fruit's sectors cost a look-up a pixel instead of an ``arctan2``, the most of
    :func:`monotone_region`'s own time (issue 19, twentieth round)."""
    if reach > _SECTOR_REACH or not 0 < bins <= 32767:
        return None
    table = _SECTORS.get(bins)
    if table is None or (table.shape[0] - 1) // 2 < reach:
        r = 64
        while r < reach:
            r *= 2
        r = min(r, _SECTOR_REACH)
        off = np.arange(-r, r + 1, dtype=np.int64)
        dy, dx = np.repeat(off, 2 * r + 1), np.tile(off, 2 * r + 1)
        per_radian = bins / (2.0 * np.pi)
        sector = np.empty(len(dy), np.int64)
        for i in range(0, len(dy), 2 * r + 1):  # a row at a time, as a fruit's pixels reach arctan2
            sector[i : i + 2 * r + 1] = np.floor((np.arctan2(dy[i : i + 2 * r + 1], dx[i : i + 2 * r + 1]) + np.pi)
                                                 * per_radian).astype(np.int64) % bins  # fmt: skip
        table = sector.astype(np.int16).reshape(2 * r + 1, 2 * r + 1)
        table.flags.writeable = False
        _SECTORS[bins] = table
    return table


def _stable_order(key: np.ndarray) -> np.ndarray:
    """``np.argsort(key, kind="stable")`` of non-negative whole numbers (int64): the keys made distinct as ``key * n +
    position`` (ties in their positions' order), sorted as values and the positions read back, when that fits in
    64 bits and there are enough of them: numpy sorts int64 values faster than it sorts them stably by index
    (a fruit's 2,000-7,000 pixels: 20-25 % less; 20,000 random keys: a tenth), not below a thousand."""
    n = len(key)
    if n < 1024 or int(key.max()) >= (2**62 - n) // n:
        return np.argsort(key, kind="stable")
    return np.sort(key * n + np.arange(n)) % n


def median_at(image: np.ndarray, rows: np.ndarray, cols: np.ndarray, *, size: int) -> np.ndarray:
    """(n,) the ``size`` x ``size`` median filter of ``image`` (odd ``size``; edges repeated, as
    ``scipy.ndimage.median_filter(..., mode="nearest")``) at the pixels ``(rows, cols)`` only.

    The apex search needs it on a fruit's core alone, a fraction of the window the filter would sweep.
    """
    h, w = image.shape
    half = size // 2
    off = np.arange(size) - half
    if len(rows) and rows.min() >= half and rows.max() < h - half and cols.min() >= half and cols.max() < w - half:
        # every window inside the image (a fruit's core): the same flat indices without clipping
        at = (rows * w + cols)[:, None] + (off[:, None] * w + off[None, :]).ravel()[None, :]
    else:
        r = np.clip(rows[:, None, None] + off[None, :, None], 0, h - 1)
        c = np.clip(cols[:, None, None] + off[None, None, :], 0, w - 1)
        at = r * w + c
    # one flat index per value: np.take is several times faster than indexing by two broadcast arrays
    values = np.take(np.ascontiguousarray(image).ravel(), at).reshape(len(rows), size * size)
    middle = size * size // 2
    return np.partition(values, middle, axis=1)[:, middle]


def fruit_surface(depth: np.ndarray, mask: np.ndarray, focal: float, *, slab: float = 1.3,
                  tolerance: float = 3.0, interior: float = 0.35,
                  region: np.ndarray | None = None, inner: np.ndarray | None = None,
                  leafy: np.ndarray | None = None, step: float | None = None,
                  thin: bool = False, crossing: bool = False, clean: bool = False,
                  wanted: Callable[[float, float], bool] | None = None, read: list[Reading] | None = None,
                  known: Reading | None = None) -> Surface | None:  # fmt: skip
    """The pixels of one fruit's own surface under (or around) its mask.

    Parameters
    ----------
    depth : (h, w) float, metres (0: none)
    mask : (h, w) bool
        The fruit's mask (its depth mode and size come from it).
    focal : float, pixels
    slab : float
        Pixels farther than ``slab`` fruit radii behind the front are not the fruit (a fruit seen from any
        side is about as deep as it is wide; its visible front lies within one radius of its nearest point);
        the radius is the larger of the mask's equivalent radius and half its major width (an elongated fruit
        may recede along its length).
    tolerance : float
        The convexity test's tolerance (:func:`monotone_region`) in noise deviations (at least 3 mm), plus the
        depth's quantisation step (:func:`depth_step`).
    interior : float
        Pixels more than this many half minor widths (or equivalent radii, the smaller) inside the mask are
        kept whatever the convexity test says (supports and stems meet a fruit at its outline; a fall deep
        inside is the fruit's own concave side).
    region : (h, w) bool, optional
        Where the surface may lie (default ``mask``): :func:`registration_shift` looks beyond the mask.
    inner : (h, w) float, optional
        ``mask``'s distance map (:func:`~symfruit.core.raster.inner_distance`) when the caller has it.
    leafy : (h, w) bool, optional
        The leaf-green pixels (:func:`fruit_depth`).
    step : float, metres, optional
        The depth's quantisation step added to the tolerance (default: measured in the mask, :func:`depth_step`).
    thin : bool
        Tell a thin occluder in front drawn into the mask (a leaf) by its shape, without colour
        (:func:`thin_front`): where the depth mode's surface is flat and a convex cap lies behind it, bounded by its
        edge, the cap is the fruit and the sheet's pixels are not.
    crossing : bool
        Where ``thin`` finds no sheet, pass over a nearest surface that runs on across the mask's outline for the
        fruit behind it that does not (:func:`_behind_crossing`: an occluder the mask is drawn over; extraction's, not
        the registration's cue, which reads the depth a few pixels off the mask).
    clean : bool
        ``depth`` is already what its cleaning makes of it: every value finite and either above 0 or +0.0 (the
        registration's window, :func:`symfruit.core._jit.valid_depth`'s with a least depth above 0), so it is read
        as it is, not copied (stop 49: the same values).
    wanted : callable, optional
        Asked with the fruit's front and the depth's noise (metres: the :class:`Surface`'s ``front`` and ``noise``)
        once they are known, before the slab and the convex cap: where it answers False, None is returned without
        them (a caller that reads the front and noise alone, and has no use for a surface where they give it nothing:
        :func:`~symfruit.extract.front_ring`). Otherwise the same surface.
    read : list, optional
        Given the :class:`Reading` of the mask (its front, radius, noise, tolerance and sheet, before the slab and the
        convex cap) where it depends on the mask's box alone (no ``crossing``, no ``leafy``, no depth around the box
        read by ``thin``; surf65).
    known : Reading, optional
        A :class:`Reading` made before (``read``): where ``depth`` and ``mask`` hold on the mask's box what it was read
        from, bit for bit, with the same arguments, its numbers are taken instead of worked out again (the same
        numbers: the same steps on the same values); else it is not read.

    Returns
    -------
    Surface, or None when the mask holds fewer than 10 pixels with depth.
    """
    region = mask if region is None else region
    valid: np.ndarray | None = None  # with depth cleaned, its pixels above 0 (made only where wanted)
    # the kernels' module looked up once a call (stop 62, surf62: it was asked for five times; the same module)
    kernels = compiled()
    plain = isinstance(depth, np.ndarray) and depth.dtype == np.float64 and depth.ndim == 2
    jit = kernels if plain else None
    if clean:
        pass  # finite, above 0 or 0: the cleaning below would give the same values
    elif jit is not None:  # the compiled twin of the two lines below (issue 19, seventeenth round: the same depth)
        cleaned = np.empty(depth.shape)
        jit.positive_depth(depth, cleaned)
        depth = cleaned
    else:
        valid = np.isfinite(depth) & (depth > 0)
        depth = np.where(valid, depth, 0.0)
    # What depends on the mask alone is worked out on the mask's box (the same values: pixels outside it are not
    # the mask's); a window around a mask may be several times larger (the registration looks 28 px beyond it)
    unit: float | None = None  # the depth's step, when measured with the noise and the front
    jit = kernels
    given = (float(focal), float(tolerance), None if step is None else float(step), bool(thin), kernels is not None)
    shared = not crossing and leafy is None  # a reading of the mask's box alone (but for thin's depth around it)
    if shared and known is not None and (found_box := known.box_in(depth, mask, given)) is not None:
        # the same box, depth and mask as a reading made before, with the same arguments: its numbers (surf65)
        r0, r1, c0, c1 = found_box
        box = (slice(r0, r1), slice(c0, c1))
        own = mask[box]
        front, radius, noise, tol, radius_px = known.front, known.radius, known.noise, known.tol, known.radius_px
        if known.sheet is not None:
            region = region.copy()
            region[box] &= ~known.sheet
    else:
        if (
            jit is not None
            and isinstance(mask, np.ndarray)
            and mask.dtype == bool
            and mask.ndim == 2
            and np.shape(depth) == mask.shape
            and depth.dtype == np.float64
            and (leafy is None or (np.shape(leafy) == mask.shape and np.asarray(leafy).dtype == bool))
        ):
            # the mask's box and count, the noise, the mask's valid depths, the depth's step and the depth mode on them
            # without sorting them in one call (stop 52, register52: mask_box, mask_values and depth_mode of stop 51,
            # fruit_depth's steps: the same numbers)
            found, r0, r1, c0, c1, count, noise, _, _, unit, front, radius, done = jit.mask_mode(
                depth, mask, _NO_LEAF if leafy is None else np.asarray(leafy), leafy is not None, _NOISE_FLOOR,
                float(focal), (float(LEAFY[0]), float(LEAFY[1])))  # fmt: skip
            if not found:
                return None  # no depth in an empty mask
            box = (slice(r0, r1), slice(c0, c1))
            own, own_depth = mask[box], depth[box]
            radius_px = float(np.sqrt(count / np.pi))
            front, radius = float(front), float(radius)
            if not done:  # left to the twin (fruit_depth's kernel declines)
                front, radius = fruit_depth(own_depth[own], radius_px, focal, noise=noise,
                                            leafy=None if leafy is None else leafy[box][own])  # fmt: skip
        else:
            if (found_box := mask_box(mask)) is None:
                return None  # no depth in an empty mask
            r0, r1, c0, c1 = found_box
            box = (slice(r0, r1), slice(c0, c1))
            own, own_depth = mask[box], depth[box]
            # a bool mask's count by np.count_nonzero (the same whole number, stop 47)
            radius_px = float(np.sqrt((np.count_nonzero(own) if own.dtype == bool else own.sum()) / np.pi))
            noise = depth_noise(own_depth, own)
            front, radius = fruit_depth(own_depth[own], radius_px, focal, noise=noise,
                                        leafy=None if leafy is None else leafy[box][own])  # fmt: skip
        if not np.isfinite(front):
            return None
        # Two depths a depth camera rounds to whole units are each up to half a unit off, so a fall between them is
        # known to a unit: without it a 3 mm tolerance on millimetre depth cuts every 3 mm fall that float32 rounding
        # makes a hair larger (noise of 0.5-0.8 mm puts a running maximum 2 mm above a pixel 1 mm below: a stereo
        # camera's near fruit lost a third of its cap, issue 18)
        if step is None:
            step = depth_step(own_depth, own) if unit is None else unit
        tol = max(tolerance * noise, 0.003) + step
        around, sheet = None, None
        if thin:
            g = int(np.ceil(radius_px))  # the depth within the fruit's size around its mask's box
            w0, w1 = max(r0 - g, 0), min(r1 + g, depth.shape[0])
            v0, v1 = max(c0 - g, 0), min(c1 + g, depth.shape[1])
            around = Around(depth[w0:w1, v0:v1], np.asarray(mask[w0:w1, v0:v1], dtype=bool), r0 - w0, c0 - v0)
        found_leaf = thin_front(own_depth, own, focal, front, radius, tol, noise, around=around) if thin else None
        if found_leaf is not None:
            front, sheet = found_leaf
            radius = radius_px * front / focal
            region = region.copy()
            region[box] &= ~sheet
        if read is not None and shared and np.isfinite(front) and not (around is not None and around.asked):
            # what was read depends on the mask's box alone (surf65): kept, with copies of what it was read from
            read.append(Reading(np.array(own_depth), np.array(own), given, front, radius, noise, tol, radius_px,
                                None if sheet is None else np.array(sheet)))  # fmt: skip
    if thin and crossing and (behind := _behind_crossing(depth, mask, focal, front, radius, tol, noise)) is not None:
        # the nearest surface (behind a sheet thin_front passed over, if any) runs on across the mask's outline: an
        # occluder the mask is drawn over (stop 46, docs/overleaf46.md); what lies in front of the fruit's front is
        # left out by the slab below
        front = behind
        radius = radius_px * front / focal
    if wanted is not None and not wanted(front, noise):
        return None  # the caller reads nothing off the surface with this front and noise (front64)
    # an elongated fruit may lie along the line of sight as far as it is long: half its major width
    minor_px, major_px = principal_widths(own, origin=(r0, c0))
    reach = max(radius, 0.5 * major_px * front / focal)
    # A support, stem or leaf meets a fruit at its outline; deep inside the mask a fall is the fruit's own
    # (a banana's inner side, a pear's neck) and is kept.
    deep_px = interior * min(radius_px, 0.5 * minor_px)
    if (jit := kernels) is not None and depth.dtype == np.float64 and depth.ndim == 2 and (
        np.shape(region) == np.shape(mask) == depth.shape
    ):  # fmt: skip
        # the slab's pixels, the apex, the convex cap and the deep pixels in one call (stop 51, surface51: the same)
        return _surface_compiled(jit, depth, mask, np.asarray(region, dtype=bool), (r0, c0, r1, c1),
                                 max(1, int(0.15 * radius_px)), (front - tol, front + slab * reach), tol, front,
                                 radius, noise, inner, deep_px)  # fmt: skip
    if (jit := compiled()) is not None and depth.dtype == np.float64 and np.shape(region) == depth.shape:
        near = np.empty(depth.shape, bool)  # the compiled twin of the comparisons below: the same pixels
        if not jit.near_pixels(depth, np.asarray(region, dtype=bool), front - tol, front + slab * reach, near):
            return None
    else:
        valid = depth > 0 if valid is None else valid
        near = region & valid & (depth >= front - tol) & (depth <= front + slab * reach)
        if not near.any():
            return None
    # the erosion treats pixels beyond the array as background, as the window's pixels beyond the box are
    if (jit := compiled()) is not None:  # the compiled twin of what follows to the apex: the same pixel
        whole = np.asarray(mask, dtype=bool)
        apex = jit.surface_apex(whole[box], max(1, int(0.15 * radius_px)), near, depth, whole, r0, c0, 5)
        return _surface(depth, mask, near, (int(apex[0]), int(apex[1])), tol, front, radius, noise, inner,
                        interior * min(radius_px, 0.5 * minor_px))  # fmt: skip
    core = eroded(own, max(1, int(0.15 * radius_px))) & near[box]
    if core.any():
        rows, cols = np.nonzero(core)
        rows, cols = rows + r0, cols + c0
    else:
        rows, cols = np.nonzero(near & mask if (near & mask).any() else near)
    if (jit := compiled()) is not None:  # the compiled twin of np.argmin(median_at(...)): the same pixel
        first = int(jit.least_median(np.where(near, depth, np.inf), rows, cols, 5))
    else:
        first = int(np.argmin(median_at(np.where(near, depth, np.inf), rows, cols, size=5)))
    apex = (int(rows[first]), int(cols[first]))
    return _surface(depth, mask, near, apex, tol, front, radius, noise, inner, deep_px)


def _surface_compiled(jit: Any, depth: np.ndarray, mask: np.ndarray, region: np.ndarray, box: tuple[int, int, int, int],
                      iterations: int, slab: tuple[float, float], tol: float, front: float, radius: float, noise: float,
                      inner: np.ndarray | None, deep_px: float) -> Surface | None:  # fmt: skip
    """:func:`fruit_surface` from its slab (depths ``slab``) on by :func:`symfruit.core._jit.surface_cap`: the pixels
    of ``region`` in the slab, the apex (the mask's ``box`` eroded ``iterations`` times), the convex cap and the
    pixels deeper than ``deep_px`` in the mask, each step the kernel it was, in one call; None where no pixel lies in
    the slab. Where the cap is left to it (``monotone_region``'s other paths), :func:`monotone_region` (stop 51)."""
    # the mask's distance map up to deep_px (farther +inf), as _surface takes it: the caller's, else made in the call
    # (a bool mask; another made here, as before)
    if (inner is None or inner.shape != mask.shape) and mask.dtype != bool:
        inner = inner_distance(mask, max(deep_px, 0.0))
    have = inner is not None and inner.shape == mask.shape
    inner = np.asarray(inner, dtype=np.float64) if have else np.zeros(mask.shape)
    near, pixels = np.empty(depth.shape, bool), np.zeros(depth.shape, bool)
    table = _sector_table(_RAYS, 0)  # the sectors' table as it is (made the first time): grown by the twin's path
    assert table is not None
    answer, r, c = jit.surface_cap(depth, region, np.asarray(mask, dtype=bool), *box, iterations, *slab, inner, have,
                                   float(deep_px), table, _RAYS, float(tol), near, pixels)  # fmt: skip
    if answer == 0:
        return None
    apex = (int(r), int(c))
    if answer == 3:  # the mask fills its box grown by a pixel: the whole transform
        inner = inner_distance(mask, max(deep_px, 0.0))
    if answer >= 2:
        pixels = monotone_region(depth, near, apex, tol) | (near & (inner > deep_px))
    return Surface(pixels, front, radius, noise, apex)


def _surface(depth: np.ndarray, mask: np.ndarray, near: np.ndarray, apex: tuple[int, int], tol: float, front: float,
             radius: float, noise: float, inner: np.ndarray | None, deep_px: float) -> Surface:  # fmt: skip
    """:func:`fruit_surface` from its apex on: the convex cap from the apex, and every pixel of ``near`` deeper than
    ``deep_px`` inside the mask (``inner``: the mask's distance map, when the caller has it)."""
    if inner is None or inner.shape != mask.shape:
        # the distances up to deep_px alone, farther ones +inf: the same comparison (stop 45, speedreg45)
        inner = inner_distance(mask, max(deep_px, 0.0))
    deep = inner > deep_px
    return Surface(monotone_region(depth, near, apex, tol) | (near & deep), front, radius, noise, apex)


#: :meth:`_Outline.cost`'s block: about this many outline values at a time (256 KB of float64)
_BLOCK = 2**15


@dataclass(frozen=True)
class _Outline:
    """A fruit's depth-cap outline points and its mask's signed distance map (pixels, + inside), in a window."""

    rows: np.ndarray
    cols: np.ndarray
    inside: np.ndarray
    band: float
    #: (4, 2) int: of the outline's points on its top, bottom, left and right side, how many are free and how many
    #: there are (:func:`_free_points`; counted before ``rows`` and ``cols`` kept the free ones); None: all free
    sides: np.ndarray | None = None
    #: ``inside`` padded by ``pad`` pixels of ``-reach`` (flattened), made once per ``(pad, reach)``; under
    #: ``("keys", pad, reach)`` the same for its whole-number keys (:meth:`keys`), None when it has none; under
    #: ``("table", pad, reach)`` the value of each key (:meth:`_table`)
    _padded: dict[tuple, np.ndarray | None] = field(default_factory=dict, init=False, repr=False, compare=False)
    #: :meth:`ranks` per ``(pad, reach)``
    _ranks: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )
    #: :meth:`_points` per pad
    _points_at: dict[int, tuple[int, np.ndarray]] = field(default_factory=dict, init=False, repr=False, compare=False)

    @functools.cached_property
    def axes(self) -> tuple[bool, bool]:
        """``(v, u)``: whether the outline tells a shift down the image (``dv``: its top and its bottom side free)
        and across it (``du``: its left and its right side free). Worked out once (the search asks for every
        cost)."""
        return (True, True) if self.sides is None else _told_axes(self.sides)

    def _points(self, pad: int) -> tuple[int, np.ndarray]:
        """The width of the maps padded by ``pad`` and each outline point's flat index in them (n,), made once per
        ``pad`` (the compiled costs move them back by each shift themselves)."""
        found = self._points_at.get(pad)
        if found is None:
            width = self.inside.shape[1] + 2 * pad
            found = (width, (self.rows + pad) * width + (self.cols + pad))
            self._points_at[pad] = found
        return found

    def _at(self, shifts: np.ndarray, reach: int, pad: int = 0) -> tuple[np.ndarray, int]:
        """(k, n) flat indices into the padded maps of each outline point moved back by each shift, and the pad (at
        least ``pad``)."""
        # outside the window the distance is -reach: a border that wide around the map replaces bounds tests
        pad = max(int(reach), int(np.abs(shifts).max(initial=0)), pad)
        width = self.inside.shape[1] + 2 * pad
        at = (self.rows + pad) * width + (self.cols + pad)  # one flat index per point, one offset per shift
        return at[None, :] - (shifts[:, :1] * width + shifts[:, 1:]), pad

    def _flat(self, pad: int, reach: int) -> np.ndarray:
        flat = self._padded.get((pad, int(reach)))
        if flat is None:
            flat = np.pad(self.inside, pad, constant_values=-float(reach)).ravel()
            self._padded[(pad, int(reach))] = flat
        return flat

    def keys(self, pad: int, reach: int) -> np.ndarray | None:
        """The padded map as whole numbers in the same order, ``sign * distance^2`` (int16 or int32, flattened), or
        None when the map is not made of signed square roots of whole numbers (it is when it comes from distance
        transforms). Sorting them instead of the distances gives the same order, several times faster."""
        key = ("keys", pad, int(reach))
        if key not in self._padded and (jit := compiled()) is not None and self.inside.dtype == np.float64:
            # the compiled twin of what follows, in one pass (issue 19, seventeenth round: the same keys)
            flat, ok, top = jit.signed_keys(self.inside, int(pad), int(reach))
            self._padded[key] = None if not ok else flat.astype(np.int16) if top < 2**15 - 1 else flat
        if key not in self._padded:
            d = self.inside
            whole = np.rint(d * d)
            found = None
            top = max(float(whole.max(initial=0.0)), float(reach) ** 2)
            # each value must come back exactly from its key (sqrt is correctly rounded, as the transforms' is)
            if top < 2**31 - 1 and np.array_equal(np.sqrt(whole), np.abs(d)):
                dtype = np.int16 if top < 2**15 - 1 else np.int32
                signed = np.where(d < 0, -whole, whole).astype(dtype)
                found = np.pad(signed, pad, constant_values=-(int(reach) ** 2)).ravel()
            self._padded[key] = found
        return self._padded[key]

    def values(self, shifts: np.ndarray, reach: int) -> np.ndarray:
        """(k, n) the signed distance at each outline point moved back by each ``(dv, du)`` of ``shifts`` (k, 2);
        ``-reach`` outside the window."""
        at, pad = self._at(shifts, reach)
        return np.take(self._flat(pad, reach), at)

    def cost(self, shifts: np.ndarray, reach: int, trim: float, *, exact: bool = True) -> np.ndarray:
        """(k,) trimmed mean deviation of the outline points from a band inside the mask shifted by each
        ``(dv, du)`` of ``shifts`` (k, 2).

        Each row's cost depends on that row alone. ``exact=False`` sums the same smallest deviations in ascending
        order (one sort, 3-4x faster than the partition) instead of in the partition's order: the same number
        to within a few units in the last place (``(keep - 1) * 2**-53`` of it, relatively, each way).

        Many shifts are costed a block of rows at a time (:data:`_BLOCK` values): the same rows, each block's arrays
        staying in a core's cache (the whole coarse grid's do not; 1.6x faster on the benchmark frame). Where numba
        is, the fast costs of a map with 16-bit keys come from the compiled twin of :meth:`_cost`
        (:func:`symfruit.core._jit.outline_costs`: each row's ranks of its keys (:meth:`ranks`) counted, the median
        and the same deviations read off the counts, summed in another order; issue 19's twelfth round, made about
        half as costly again by the fifteenth)."""
        if not exact and (jit := compiled()) is not None:  # the compiled twin of the fast costs, all rows at once
            pad = max(int(reach), int(np.abs(shifts).max(initial=0)))
            if (keys := self.keys(pad, reach)) is not None and keys.dtype == np.int16:  # a row's keys: < 2**16 apart
                width, at = self._points(pad)
                keep = max(1, int(trim * len(self.rows)))
                return jit.outline_costs(*self.ranks(pad, reach), at, shifts, width, keep, self.band)
        rows = max(1, _BLOCK // max(1, len(self.rows)))
        if len(shifts) > rows:
            pad = max(int(reach), int(np.abs(shifts).max(initial=0)))  # one pad for all blocks: one padded map
            return np.concatenate(
                [self._cost(shifts[i : i + rows], reach, trim, exact, pad) for i in range(0, len(shifts), rows)]
            )
        return self._cost(shifts, reach, trim, exact)

    def _cost(self, shifts: np.ndarray, reach: int, trim: float, exact: bool, pad: int = 0) -> np.ndarray:
        """:meth:`cost` of one block of shifts, the padded maps at least ``pad`` wide. Where numba is, the exact costs
        of a map with 16-bit keys take their deviations from a compiled twin (:func:`symfruit.core._jit.
        outline_deviations`: the same deviations, bit for bit, read off the map's ranks instead of a padded copy of
        its distances; issue 19, seventeenth round), their partition and mean from numpy as here."""
        if exact and len(self.rows) and (jit := compiled()) is not None:
            pad = max(int(reach), int(np.abs(shifts).max(initial=0)), pad)
            if (keys := self.keys(pad, reach)) is not None and keys.dtype == np.int16:
                width, at = self._points(pad)
                dev = jit.outline_deviations(*self.ranks(pad, reach), at, shifts, width, self.band)
                keep = max(1, int(trim * dev.shape[1]))
                return np.partition(dev, keep - 1, axis=1)[:, :keep].mean(axis=1)
        at, pad = self._at(shifts, reach, pad)
        keys = self.keys(pad, reach)
        if not exact and keys is not None:
            return self._nearest_mean(_sort_rows(np.take(keys, at)), pad, reach, trim)
        val = np.take(self._flat(pad, reach), at)
        # the cap's outline lies a band inside the mask's outline (grazing pixels without depth): the band is
        # the median distance, within 0 to 0.3 radii, and the cost the trimmed mean deviation from it
        n = val.shape[1]
        middle = [(n - 1) // 2, n // 2]  # np.median's two middle places (one place when n is odd)
        if keys is not None:  # the middle keys of each row, and their distances back (the same values)
            k = _sort_rows(np.take(keys, at))[:, middle]
            mid = np.sign(k) * np.sqrt(np.abs(k).astype(np.float64))
        else:  # a sort of these short rows is 4x faster than a two-kth partition
            mid = np.sort(val, axis=1)[:, middle]
        median = 0.5 * (mid[:, 0] + mid[:, 1]) if n % 2 == 0 else mid[:, 1]
        band = np.clip(median[:, None], 0.0, self.band)
        dev = np.abs(val - band)
        keep = max(1, int(trim * dev.shape[1]))
        if not exact:
            return np.sort(dev, axis=1)[:, :keep].mean(axis=1)
        return np.partition(dev, keep - 1, axis=1)[:, :keep].mean(axis=1)

    def _nearest_mean(self, ordered: np.ndarray, pad: int, reach: int, trim: float) -> np.ndarray:
        """:meth:`cost`'s ``exact=False`` from each row's keys in ascending order (:meth:`keys`), without the
        distances' sort: the same deviations, summed in another order.

        The keys in order are the values in order (each value comes back exactly from its key, by a table). The
        ``keep`` values nearest the band (the smallest deviations) are a run of them: it starts at the number of
        places ``i`` where the run ``[i, i + keep)`` comes nearer by dropping value ``i`` for value ``i + keep``
        (``b - v[i] > v[i + keep] - b``; those places are a prefix, the differences being monotone in ``v``
        as rounded too), the run the usual search for the ``keep`` values nearest ``b`` ends in. Ties swap
        equal deviations: the run's deviations are the ``keep`` smallest, as a multiset."""
        # a negative key counts from the table's end; indexing, not np.take (whose int16 indices cost 6x more)
        v = self._table(pad, reach)[ordered]
        k, n = v.shape
        mid = v[:, [(n - 1) // 2, n // 2]]  # np.median's two middle places, as in cost()
        median = 0.5 * (mid[:, 0] + mid[:, 1]) if n % 2 == 0 else mid[:, 1]
        band = np.clip(median[:, None], 0.0, self.band)
        keep = max(1, int(trim * n))
        if keep < n:
            start = np.count_nonzero(np.subtract(band, v[:, : n - keep]) > np.subtract(v[:, keep:], band), axis=1)
        else:
            start = np.zeros(k, dtype=np.intp)
        run = np.take(v.ravel(), (np.arange(k) * n + start)[:, None] + np.arange(keep)[None, :])
        return np.abs(np.subtract(run, band, out=run), out=run).mean(axis=1)

    def ranks(self, pad: int, reach: int) -> tuple[np.ndarray, np.ndarray]:
        """The padded map's whole-number keys (:meth:`keys`, which it must have) as their places among its distinct
        keys (int32, flattened), and the value of each place ((m,) ascending, :meth:`_table`'s bit for bit): the same
        order, a few times fewer places for a row of keys to span than the keys' own values (the squared distances
        that a map holds are sums of two squares; issue 19, fifteenth round). Where numba is, counted by its
        compiled twin (:func:`symfruit.core._jit.key_ranks`: the same places and values)."""
        found = self._ranks.get((pad, int(reach)))
        if found is None:
            keys = self.keys(pad, reach)
            assert keys is not None  # only called when the map has keys
            if (jit := compiled()) is not None:
                found = jit.key_ranks(keys)
            else:
                low = int(keys.min(initial=0))
                shifted = keys.astype(np.int64) - low
                present = np.zeros(int(shifted.max(initial=0)) + 1, bool)
                present[shifted] = True
                ranks = (np.cumsum(present) - 1).astype(np.int32)[shifted]
                whole = (np.flatnonzero(present) + low).astype(np.float64)
                found = (ranks, np.sign(whole) * np.sqrt(np.abs(whole)))
            self._ranks[(pad, int(reach))] = found
        return found

    def _table(self, pad: int, reach: int) -> np.ndarray:
        """The value of every key of :meth:`keys` (``sign * sqrt(|key|)``), indexed by the key itself, negative keys
        from the end (as Python indexes)."""
        key = ("table", pad, int(reach))
        found = self._padded.get(key)
        if found is None:
            keys = self.keys(pad, reach)
            assert keys is not None  # only called when the map has keys
            top, low = max(int(keys.max()), 0), min(int(keys.min()), 0)
            found = np.empty(top + 1 - low)
            found[: top + 1] = np.sqrt(np.arange(top + 1, dtype=np.float64))
            if low < 0:
                found[top + 1 :] = -np.sqrt(-np.arange(low, 0, dtype=np.float64))
            self._padded[key] = found
        return found


def _simd_sort16() -> bool:
    """Whether numpy's default sort of 16-bit integers is its AVX-512 (ICL) one, which beats its radix sort. Read
    from numpy's private ``__cpu_features__``: where numpy moves or renames it, False (the radix sort: the same
    sorted rows, at worst slower than AVX-512's), never an error."""
    for name in ("numpy._core._multiarray_umath", "numpy.core._multiarray_umath"):  # numpy 2, numpy 1
        try:
            features = getattr(importlib.import_module(name), "__cpu_features__", None)
        except Exception:  # gone, or numpy 1's deprecated path warned as an error
            continue
        if isinstance(features, dict):
            return features.get("AVX512_ICL") is True
    return False


#: the sort of :func:`_sort_rows` for 16-bit keys: numpy's radix sort ("stable") but where the default is AVX-512's
_KIND16: Literal["stable"] | None = None if _simd_sort16() else "stable"


def _sort_rows(keys: np.ndarray) -> np.ndarray:
    """``np.sort(keys, axis=1)``: whole numbers in order are the same whatever the sort, and numpy's stable sort of
    16-bit ones is a radix sort (2.4x faster on the registration's rows than the default introsort on a CPU without
    AVX-512; where numpy's default is AVX-512's sort, that is kept)."""
    return np.sort(keys, axis=1, kind=_KIND16 if keys.dtype.itemsize <= 2 else None)


def _outline(depth: np.ndarray, mask: np.ndarray, focal: float, reach: int, max_points: int = 160, *,
             clean: bool = False, occluders: bool = False, count: int | None = None) -> _Outline | None:  # fmt: skip
    """The free points of the outline of a fruit's depth cap found around its mask (``reach`` pixels beyond it),
    and how many of each side's points are free (:func:`_free_points`), or None (fewer than 12 free points).
    ``clean``: :func:`fruit_surface`'s (the depth finite, above 0 or 0 already). ``occluders``: a lost band beside
    something in front is a junction (:func:`_free_points`' ``tol``, ``extract.occluder_edges``; stop 62).
    ``count``: ``np.count_nonzero(mask)`` of a bool mask when the caller has it (:func:`registration_outline`)."""
    if count is None or mask.dtype != bool:
        count = int(np.count_nonzero(mask))
    # a bool mask holding pixels of both kinds: 0 < count < size (stop 65, reg65: without mask.any() and mask.all())
    jit = compiled() if mask.dtype == bool and mask.ndim == 2 and 0 < count < mask.size else None
    found: tuple[bool, np.ndarray, np.ndarray, np.ndarray] | None = None
    inside: np.ndarray | None = None
    if jit is not None:  # the grown window, both distance maps, the keys and their ranks in one call (stop 50)
        grown, inner, inside = np.empty(mask.shape, bool), np.empty(mask.shape), np.empty(mask.shape)
        found = jit.outline_windows(mask, int(reach), grown, inner, inside)
    else:
        grown = _taxicab_within(mask, reach)  # = binary_dilation, reach times
        inner = inner_distance(mask)
    # the outline cue keeps the cap it was measured with (the tolerance without the depth's unit): with the unit, two
    # banana views of the D405 model (true shift 0), whose outlines slide along their length, went from (0, 0) and
    # (0, 17) px to (18, 0) and (-15, 15) (docs/ablation.md, "A fall of whole depth units")
    surface = fruit_surface(depth, mask, focal, region=grown, inner=inner, step=0.0, thin=True, clean=clean)
    if surface is None:
        return None
    jit = compiled()
    pixels, apex = surface.pixels, surface.apex
    tol = _free_tol(surface) if occluders else np.inf
    free: np.ndarray | None = None
    if jit is not None and depth.dtype == np.float64 and depth.ndim == 2 and pixels.dtype == bool and pixels[apex]:
        # the cap, its outline and the outline's free points in one call (stop 50: the same pixels and points)
        cap = pixels  # not read below: _free_points is given the free points
        rows, cols, free = jit.cap_outline(pixels, apex[0], apex[1], depth, _free_far(surface), _FREE_PX,
                                           int(_FREE_PX) + 1, 12, tol)  # fmt: skip
    else:
        cap = _connected(pixels, apex)
        if jit is not None:  # the outline's pixels in one pass (issue 19, nineteenth round: the same)
            rows, cols = jit.outline_pixels(cap)
        else:
            rows, cols = np.nonzero(cap & ~interior(cap))
    if len(rows) < 12:
        return None
    free, sides = _free_points(depth, cap, rows, cols, surface, free=free, tol=tol)
    rows, cols = rows[free], cols[free]  # where the depth runs on, no band lies to be measured
    if len(rows) < 12:
        return None
    step = max(1, len(rows) // max_points)
    if inside is None:
        inside = inner - distance_transform(~mask)
    outline = _Outline(rows[::step], cols[::step], inside, 0.3 * float(np.sqrt(count / np.pi)), sides)
    if found is not None and found[0]:  # the keys and ranks of the costs' pad (the search's shifts are within reach)
        outline._padded[("keys", int(reach), int(reach))] = found[1]
        outline._ranks[(int(reach), int(reach))] = (found[2], found[3])
    return outline


def _rim(rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Indices (ascending) of the outline points (``rows``, ``cols``) farthest from their centroid in each direction
    from it: the cap's outer rim, without the sides of the cracks the convexity test cuts into a noisy cap (rays
    whose depth fell by noise: neither silhouette nor junction). As many directions as a circle of the outline's
    mean radius has pixels around it."""
    dv, du = rows - rows.mean(), cols - cols.mean()
    radius = np.hypot(dv, du)
    bins = max(8, int(2.0 * np.pi * radius.mean()))
    at = np.minimum(((np.arctan2(dv, du) + np.pi) * (bins / (2.0 * np.pi))).astype(np.intp), bins - 1)
    order = np.lexsort((-radius, at))  # by direction, the farthest first
    first = order[np.r_[True, at[order][1:] != at[order][:-1]]]
    return np.sort(first)


#: :func:`_free_points`: an outline point is free when a pixel outside the cap within this many pixels holds no
#: depth or depth behind the fruit's rim. A time-of-flight camera's lost band lies right beside a silhouette, and
#: an active-stereo camera's fattened edge (about 3 depth pixels: 4-5 colour pixels, ``synthetic.sensors``'
#: ``fatten_px`` times its footprint) ends about this far out; a support or a neighbour at the fruit's own depth
#: runs on farther.
_FREE_PX = 4.0

#: :func:`_told_axes`: a side of an outline (or of all a frame's outlines) is free when more than this share of
#: its points is: the band its points lie at is then what its free points say (their median), not its junctions.
_FREE_SHARE = 0.5


def _free_far(surface: Surface) -> float:
    """:func:`_free_points`' depth beyond which a pixel is behind the fruit's rim: its front plus its radius, plus the
    convexity test's tolerance."""
    return surface.front + surface.radius + _free_tol(surface)


def _free_tol(surface: Surface) -> float:
    """:func:`_free_points`' depth tolerance (m), the convexity test's: three times the depth's noise, at least 3 mm.
    Depth nearer than an outline point's own by more than it is something in front of the fruit there."""
    return _free_tol_of(surface.noise)


def _free_tol_of(noise: float) -> float:
    """:func:`_free_tol` of a surface whose depth's noise is ``noise`` (metres)."""
    return max(3.0 * noise, 0.003)


def _occluders_edge(depth: np.ndarray, cap: np.ndarray, box: tuple[slice, slice], reach: float) -> np.ndarray:
    """The least depth above 0 of the pixels not ``cap``'s within ``reach`` of each pixel of ``box`` (+inf where none),
    :func:`_free_points`' look beside a pixel without depth for something in front (the numpy twin of
    :func:`symfruit.core._jit.free_outline`'s; the pixels in reach are :func:`within`'s disc, read over the whole
    array)."""
    k = int(np.floor(reach)) if reach >= 0 else -1
    r0, r1, c0, c1 = box[0].start, box[0].stop, box[1].start, box[1].stop
    h, w = depth.shape
    r1, c1 = min(r1, h), min(c1, w)
    with np.errstate(invalid="ignore"):
        other = np.where(~cap & (depth > 0), depth, np.inf)
    out = np.full((r1 - r0, c1 - c0), np.inf)
    if k < 0:
        return out
    padded = np.pad(other, k, constant_values=np.inf)
    for dr in range(-k, k + 1):
        for dc in range(-k, k + 1):
            d = dr * dr + dc * dc
            if d <= reach * reach and np.sqrt(float(d)) <= reach:
                part = padded[r0 + k + dr : r1 + k + dr, c0 + k + dc : c1 + k + dc]
                np.minimum(out, part, out=out)
    return out


def _free_points(depth: np.ndarray, cap: np.ndarray, rows: np.ndarray, cols: np.ndarray, surface: Surface, *,
                 free: np.ndarray | None = None, tol: float = np.inf) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Which points of a depth cap's outline (``rows``, ``cols``) are *free*: a true silhouette, whose band inside
    the mask (:func:`registration_shift`) is there to be measured; and of the points on its top, bottom, left
    and right side, how many are free and how many there are: ``((n,) bool, (4, 2) int)``.

    An outline point is free when a pixel outside the cap within :data:`_FREE_PX` of it holds no depth (the band
    a time-of-flight camera loses where the surface turns away, or mixed pixels against what is behind) or depth
    behind the fruit's rim (its front plus its radius, plus the convexity test's tolerance: what a fruit hides
    lies behind its rim). Where the depth runs on at the fruit's own depth or nearer, into a support, a
    neighbour or a leaf in front, the outline is the junction, not the silhouette, and no band lies there.
    With ``tol`` finite (``extract.occluder_edges``; the registration gives :func:`_free_tol`), a pixel without
    depth that has, within :data:`_FREE_PX` of it, a pixel other than the cap's nearer than the outline point by
    more than ``tol`` is the lost edge of something in front, not the fruit's: a time-of-flight camera invalidates
    the mixed pixels along every step in depth, an occluder's too, so the band of lost depth between a leaf in
    front and the fruit is a junction (stop 62, docs/leaf62.md: a leaf or a strip cutting the masks of the real
    frames moved them by 3-11 px).
    The sides are counted on the outline's rim (:func:`_rim`); a point belongs to the side its direction from the
    outline's centroid points to most. ``free``: the free points when the caller has them (:func:`_outline`'s
    :func:`symfruit.core._jit.cap_outline`; ``cap`` is then not read)."""
    # on the outline's box grown by the reach alone (the same answers: no farther pixel is within reach)
    r = int(_FREE_PX) + 1
    jit = compiled()
    if free is not None:
        pass
    elif jit is not None and depth.dtype == np.float64 and depth.ndim == 2 and cap.dtype == bool and len(rows):
        # the gap, its distances and the points' test in one pass (issue 19, nineteenth round: the same points)
        free = jit.free_outline(depth, cap, rows, cols, _free_far(surface), _FREE_PX, r, tol)
    else:
        r0, c0 = max(int(rows.min()) - r, 0), max(int(cols.min()) - r, 0)
        box = (slice(r0, int(rows.max()) + r + 1), slice(c0, int(cols.max()) + r + 1))
        zb, outside = depth[box], ~cap[box]
        past = outside & (zb >= _free_far(surface))
        lost = outside & (zb <= 0)
        if not lost.any() or not np.isfinite(tol):
            free = within(past | lost, _FREE_PX)[rows - r0, cols - c0]
        else:  # a lost pixel counts where nothing within reach of it lies nearer than the point by the tolerance
            nearest = _occluders_edge(depth, cap, box, _FREE_PX)
            bound = depth[rows, cols] - tol
            free = np.zeros(len(rows), bool)
            k, (bh, bw) = int(_FREE_PX), zb.shape
            for dr in range(-k, k + 1):
                for dc in range(-k, k + 1):
                    if dr * dr + dc * dc > _FREE_PX * _FREE_PX or np.sqrt(float(dr * dr + dc * dc)) > _FREE_PX:
                        continue
                    rr, cc = rows - r0 + dr, cols - c0 + dc
                    ok = (rr >= 0) & (rr < bh) & (cc >= 0) & (cc < bw)
                    rr, cc = np.where(ok, rr, 0), np.where(ok, cc, 0)
                    free |= ok & (past[rr, cc] | (lost[rr, cc] & ~(nearest[rr, cc] < bound)))
    if jit is not None:  # the compiled twin of the rim and its sides, from numpy's directions on
        # the means from whole-number sums (exact in any order, as numpy's float64 sums of them are; its mean divides
        # the same sum): rows.mean() and cols.mean() bit for bit, without their casts (stop 49)
        dv, du = rows - int(rows.sum()) / len(rows), cols - int(cols.sum()) / len(cols)
        radius = np.hypot(dv, du)
        bins = max(8, int(2.0 * np.pi * radius.mean()))
        return free, jit.rim_sides(dv, du, radius, np.arctan2(dv, du), bins, bins / (2.0 * np.pi), free)
    outer = _rim(rows, cols)
    dv, du = rows[outer] - rows.mean(), cols[outer] - cols.mean()
    along_v = np.abs(dv) >= np.abs(du)
    sides = (along_v & (dv < 0), along_v & (dv > 0), ~along_v & (du < 0), ~along_v & (du > 0))
    return free, np.array([(np.count_nonzero(free[outer] & side), np.count_nonzero(side)) for side in sides])


def _told_axes(sides: np.ndarray) -> tuple[bool, bool]:
    """``(v, u)`` from the free and all points of the top, bottom, left and right sides ((4, 2), :func:`_free_points`):
    an axis is told when both its sides are free (more than :data:`_FREE_SHARE` of their points). A shift along an
    axis is told apart from the band only by both sides of that axis: with the bottom side missing, moving the
    masks down and widening the band at the top are one and the same (a fruit on a board: no band at the bottom,
    where the board runs on; a wide band at the top, mixed pixels against the far background)."""
    # as Python's whole numbers (stop 65, reg65: numpy's tests on the (4, 2) array, a few us less an outline)
    (f0, n0), (f1, n1), (f2, n2), (f3, n3) = sides.tolist()
    return f0 > _FREE_SHARE * n0 and f1 > _FREE_SHARE * n1, f2 > _FREE_SHARE * n2 and f3 > _FREE_SHARE * n3


def _taxicab_within(mask: np.ndarray, reach: int) -> np.ndarray:
    """(h, w) bool: the pixels at most ``reach`` steps along rows and columns from a pixel of ``mask`` (not empty),
    ``ndimage.distance_transform_cdt(~mask, metric="taxicab") <= reach``, or its compiled twin's
    (:func:`symfruit.core._jit.taxicab_within`: the chamfer's two sweeps, the same pixels)."""
    if (jit := compiled()) is not None and mask.any():
        out = np.empty(mask.shape, bool)
        jit.taxicab_within(mask, int(reach), out)
        return out
    return ndimage.distance_transform_cdt(~mask, metric="taxicab") <= reach


def registration_shift(depth: np.ndarray, labels: np.ndarray, focal: float, *, max_px: int,
                       trim: float = 0.7, gain: float = 0.25,
                       depth_range: tuple[float, float] = (0.0, np.inf),
                       boxes: list[tuple[slice, slice] | None] | None = None,
                       occluders: bool = False) -> tuple[int, int]:  # fmt: skip
    """``(du, dv)``, pixels: how far the depth image sits from the masks (depth pixel ``(u + du, v + dv)`` sees
    what colour pixel ``(u, v)`` sees); ``(0, 0)`` when the masks do not say.

    For every fruit of ``labels``, the outline of its depth cap (:func:`fruit_surface`, looked for up to
    ``max_px`` beyond its mask) should run parallel to its mask's outline, a band inside it (a
    time-of-flight camera returns no depth where the surface turns away). The cost of a shift is the trimmed
    mean (``trim`` of the outline points: a support or a leaf bends part of any outline) of each outline
    point's deviation from that band, averaged over the fruit; the shift of least cost is searched on a grid
    of 2 pixels, then refined to a pixel. It is returned when it lowers the cost by more than ``gain`` pixels
    from the unshifted masks' (moving a disc's outline by one pixel changes it by about 0.6; a frame
    registered well enough keeps its masks), and when it lies inside the search: a least cost at ``max_px``
    along an axis is a cost still falling beyond the search, no minimum found (an elongated fruit's outline
    slides along its own length; a cap that runs on into the background), and the masks are kept.

    Only an outline's *free* points, where what lies beyond it has no depth or lies behind the fruit, are a
    silhouette with a band to measure; where the depth runs on into a support, a neighbour or a leaf in front,
    the outline is a junction and is left out (:func:`_free_points`). Along an axis, a shift is told apart from
    the band only when both sides of it are free (top and bottom for ``dv``, left and right for ``du``): a fruit
    on a board has no band at its bottom, and there a shift down and a wider band at its top are the same
    (:func:`_told_axes`). A fruit costs each shift as far as it tells it (along an axis it does not tell, as if
    the shift had no part along it), and an axis that the frame's outlines, pooled, do not tell keeps 0.

    Parameters
    ----------
    depth : (h, w) float, metres (0: none)
    labels : (h, w) int
        Instance masks (0 none, k fruit k).
    focal : float, pixels
    max_px : int
        The search radius (0: no search).
    depth_range : (float, float), metres
        Depth outside it is none.
    boxes : list of (slice, slice) or None, optional
        ``ndimage.find_objects(labels)`` when the caller has it.
    occluders : bool
        ``extract.occluder_edges`` (stop 62, docs/leaf62.md): a band of lost depth beside something in front of
        the fruit is that occluder's edge, a junction, not a free point (:func:`_free_points`), and an outline
        that tells no axis still counts its sides in the frame's pool (:func:`registration_outline`).
    """
    if max_px <= 0:
        return 0, 0
    outlines = []
    for k, sl in enumerate(ndimage.find_objects(labels) if boxes is None else boxes, 1):
        if sl is None:
            continue
        r0, r1, c0, c1 = registration_window(labels.shape, sl, max_px)
        found = registration_outline(depth[r0:r1, c0:c1], labels[r0:r1, c0:c1] == k, focal, max_px=max_px,
                                     depth_range=depth_range, occluders=occluders)  # fmt: skip
        if found is not None:
            outlines.append(found)
    return registration_search(outlines, max_px=max_px, trim=trim, gain=gain)


def registration_window(shape: tuple[int, ...], sl: tuple[slice, slice], max_px: int) -> tuple[int, int, int, int]:
    """``(r0, r1, c0, c1)``: the window of an image of ``shape`` :func:`registration_shift` looks at a mask whose box
    is ``sl`` in (``max_px + 8`` pixels around the box)."""
    r0, c0 = max(sl[0].start - max_px - 8, 0), max(sl[1].start - max_px - 8, 0)
    r1, c1 = min(sl[0].stop + max_px + 8, shape[0]), min(sl[1].stop + max_px + 8, shape[1])
    return r0, r1, c0, c1


def registration_outline(depth: np.ndarray, mask: np.ndarray, focal: float, *, max_px: int,
                         depth_range: tuple[float, float] = (0.0, np.inf),
                         occluders: bool = False) -> _Outline | None:  # fmt: skip
    """One mask's part of :func:`registration_shift` (``max_px`` above 0): the outline of its depth cap, from the
    depth and the (bool) mask of its window (:func:`registration_window`), or None when the mask is too small (30
    pixels) or its outline tells no axis (with ``occluders``, :func:`registration_shift`'s, such an outline is
    returned unless it has too few free points: its sides count in :func:`registration_search`'s pool of the
    frame's sides, though it costs no shift). It reads this fruit's window alone: the outlines of a frame's masks are
    found in any order, or on several processes (:class:`~symfruit.fruitpool.FruitPool`), with the same values;
    :func:`registration_search` takes them in the frame's order."""
    lo, hi = depth_range
    if (count := int(np.count_nonzero(mask))) < 30:  # the sum's count (stop 47)
        return None
    # depth made valid in the fruit's window alone (a whole 1920x1080 frame costs milliseconds), in float64 (a
    # float32 frame converted window by window: the same values, without a float64 copy of the whole frame)
    z = np.asarray(depth, dtype=np.float64)
    if (jit := compiled()) is not None and z.dtype == np.float64:  # the same map by the extraction's kernel:
        valid = np.empty(z.shape)  # z > 0 and z >= lo is z >= the larger of lo and the least positive double
        jit.valid_depth(z, mask, max(float(lo), 5e-324), float(hi), valid, np.empty(z.shape, bool))
        z = valid
    else:
        z = np.where(np.isfinite(z) & (z > 0) & (z >= lo) & (z <= hi), z, 0.0)
    # z is finite, above 0 or 0 (valid_depth's least depth is above 0): fruit_surface reads it as it is (stop 49)
    found = _outline(z, mask, focal, max_px, clean=True, occluders=occluders, count=count)
    # with occluders, an outline that tells no axis is kept too: its sides count in the frame's pool
    # (registration_search), though it costs no shift (stop 62, docs/leaf62.md)
    return found if found is not None and (occluders or any(found.axes)) else None


def registration_search(outlines: list[_Outline], *, max_px: int, trim: float = 0.7,
                        gain: float = 0.25) -> tuple[int, int]:  # fmt: skip
    """:func:`registration_shift`'s answer ``(du, dv)`` from the frame's outlines (:func:`registration_outline`'s,
    in the frame's order; ``trim`` and ``gain`` as there)."""
    if max_px <= 0 or not outlines:
        return 0, 0
    # an axis is searched when the frame's outlines, pooled, tell it (a fruit whose side is free by a few points
    # does not outvote the others; those that tell no axis count here too: a frame whose fruit end mostly at a leaf
    # in front does not leave one outline, perhaps the leaf's own, to decide it; stop 62) and a fruit tells it;
    # otherwise it keeps 0
    counted = [o.sides for o in outlines if o.sides is not None]
    # the sides summed one outline after another (whole numbers: np.sum's, without its array of the list)
    pooled = _told_axes(functools.reduce(np.add, counted)) if counted else (True, True)
    outlines = [o for o in outlines if any(o.axes)]  # the outlines that cost shifts
    if not outlines:
        return 0, 0

    def cost(shifts: np.ndarray, exact: bool = True) -> np.ndarray:
        return np.mean([_told(o, shifts, max_px, trim, exact) for o in outlines], axis=0)

    # the fast costs of every outline in one call a stage where numba is (issue 19, stop 41: the same numbers)
    frame = _FrameCosts.of(outlines, max_px, trim)
    least = functools.partial(frame.least, cost=cost)

    tell_v, tell_u = (pooled[i] and any(o.axes[i] for o in outlines) for i in (0, 1))
    if not (tell_v or tell_u):
        return 0, 0
    coarse, zero = np.arange(-max_px, max_px + 1, 2, dtype=np.int64), np.zeros(1, np.int64)
    grid = _pairs(coarse if tell_v else zero, coarse if tell_u else zero)
    dv, du = grid[least(grid)]
    near = np.arange(-2, 3, dtype=np.int64)
    fine = _pairs(dv + near if tell_v else zero + dv, du + near if tell_u else zero + du)
    fine = fine[(np.abs(fine) <= max_px).all(axis=1)]
    best = least(fine)
    if not fine[best].any() or (np.abs(fine[best]) >= max_px).any():
        # the least shift is none (its cost is the unshifted masks': no gain, whatever the number); or a least cost
        # at the search's border, still falling beyond it: no minimum found
        return 0, 0
    # no gain: the exact costs compared only where the fast ones, each within the slack of its exact cost, do not
    # decide (stop 48, regspeed48: the same answer without 2 x 9 exact costs a frame)
    zero_at = np.flatnonzero(~fine.any(axis=1))
    zero_fast = frame.means[zero_at[0]] if len(zero_at) else frame.fast(np.zeros((1, 2), np.int64))[0]
    no_gain = _no_gain(frame.means[best], zero_fast, gain)
    if no_gain is None:
        zero = cost(np.zeros((1, 2), np.int64))[0]
        no_gain = bool(cost(fine[best : best + 1])[0] > zero - gain)
    if no_gain:
        return 0, 0
    return int(fine[best, 1]), int(fine[best, 0])


def _pairs(v: np.ndarray, u: np.ndarray) -> np.ndarray:
    """(len(v) * len(u), 2) int64: every ``(v[i], u[j])``, ``i`` the slower, of two 1-D whole-number arrays:
    ``np.stack(np.meshgrid(v, u, indexing="ij"), axis=-1).reshape(-1, 2)`` (:func:`registration_search`'s grids of
    shifts), written in two assignments (stop 65, reg65: the same pairs in the same order, without meshgrid's and
    stack's Python, some 20 us a grid)."""
    out = np.empty((len(v), len(u), 2), np.int64)
    out[:, :, 0] = v[:, None]
    out[:, :, 1] = u[None, :]
    return out.reshape(-1, 2)


def _no_gain(at_best: float, zero: float, gain: float) -> bool | None:
    """:func:`registration_shift`'s ``at_best > zero - gain`` (the least shift's exact cost against the unshifted
    masks') told from the two shifts' fast costs ``at_best`` and ``zero`` (:meth:`_FrameCosts.least`'s means), or
    None where they do not tell it. Each fast cost is within a slack of its exact cost (``1e-10`` of one plus the
    cost: the same keep deviations summed in another order, some 10^4 times their rounding; the margin the search's
    ``least`` takes too); a difference more than twice that slack (doubled again for the subtraction's rounding) from
    ``-gain`` is the exact costs' answer. NaN or an infinity: None (the exact costs decide)."""
    if not (np.isfinite(at_best) and np.isfinite(zero)):
        return None
    slack = 1e-10 * (1.0 + max(abs(float(at_best)), abs(float(zero))))
    margin = float(at_best) - (float(zero) - gain)
    if margin > 4.0 * slack:
        return True
    if margin < -4.0 * slack:
        return False
    return None


#: :func:`registration_shift`'s search costs a set of more shifts than this fruit by fruit, pruned
#: (:meth:`_FrameCosts.least`)
_PRUNE_FROM = 30


class _FrameCosts:
    """A frame's outlines' fast costs a stage at a time, for :func:`registration_shift`'s ``least``
    (:meth:`least`): each outline's shifts as far as it tells them (:func:`_told`). Where numba is and every
    outline's map has 16-bit keys (where :meth:`_Outline.cost` takes the compiled fast costs), for shifts within the
    reach (the pad of its maps), one compiled call a stage (:func:`symfruit.core._jit.frame_costs`, issue 19, stop
    41: the same numbers as :meth:`_Outline.cost`'s compiled fast costs, :func:`symfruit.core._jit.outline_costs`,
    whose cost of a shift it shares; without some 40 Python-level calls a frame and the one-axis outlines'
    ``np.unique``); else :func:`_told` outline by outline (:meth:`_twin_stage`, the kernel's twin). One search
    serves both (stop 42: it was written twice, ``_least_pruned`` the numpy one)."""

    def __init__(self, outlines: list[_Outline], reach: int, trim: float, jit: Any = None) -> None:
        self.jit, self.outlines, self.reach, self.trim = jit, outlines, int(reach), float(trim)
        # the outlines costed fewest points first (stop 42): the first one is costed at every shift; each keeps its own
        # row of the costs, so their means are the same numbers whatever the order. After the first, the outlines
        # that tell one axis alone (stop 48): each costs at most one shift per value of that axis however many
        # shifts are left, so it prunes the later ones at next to no cost of its own
        # (Python's sort is stable, as the argsort it stands for: stop 65, reg65)
        order = sorted(range(len(outlines)), key=lambda i: len(outlines[i].rows))
        rest = order[1:]
        one_axis = [i for i in rest if not all(outlines[i].axes)]
        self.order = np.array(order[:1] + one_axis + [i for i in rest if all(outlines[i].axes)], np.int64)
        #: :meth:`least`'s fast costs (the outlines' mean) of its last shifts, NaN at those it left out
        self.means = np.empty(0)
        if jit is None:
            return
        ranks, values, at, widths = [], [], [], []
        for o in outlines:
            rank, value = o.ranks(self.reach, reach)
            width, points = o._points(self.reach)
            ranks.append(rank)
            values.append(value)
            at.append(points)
            widths.append(width)
        self.starts = np.zeros((len(outlines) + 1, 3), np.int64)
        lengths = [(len(r), len(v), len(a)) for r, v, a in zip(ranks, values, at, strict=True)]
        np.cumsum(lengths, axis=0, out=self.starts[1:])
        self.ranks, self.values, self.at = np.concatenate(ranks), np.concatenate(values), np.concatenate(at)
        self.widths = np.array(widths, np.int64)
        self.keeps = np.array([max(1, int(trim * len(o.rows))) for o in outlines], np.int64)
        self.bands = np.array([o.band for o in outlines], np.float64)
        self.axes = np.array([o.axes for o in outlines], np.bool_).reshape(-1, 2)

    @classmethod
    def of(cls, outlines: list[_Outline], reach: int, trim: float) -> _FrameCosts:
        """The frame's costs, compiled where they can be (the class docstring), else by :func:`_told`."""
        jit = compiled()
        for o in outlines if jit is not None else ():
            keys = o.keys(int(reach), reach)
            if keys is None or keys.dtype != np.int16 or not len(o.rows):
                jit = None
                break
        return cls(outlines, reach, trim, jit)

    def _stage(self, shifts: np.ndarray, stage: int, best: int, upper: float, slack: float,
               out: np.ndarray) -> np.ndarray:  # fmt: skip
        """One stage of :meth:`least` into ``out`` (m, k), as :func:`symfruit.core._jit.frame_costs` documents it."""
        if self.jit is None or int(np.abs(shifts).max(initial=0)) > self.reach:
            return self._twin_stage(shifts, stage, best, upper, slack, out)
        return self.jit.frame_costs(self.ranks, self.values, self.at, self.starts, self.widths, self.keeps,
                                    self.bands, self.axes, self.order, shifts, stage, best, upper, slack,
                                    out)  # fmt: skip

    def _twin_stage(self, shifts: np.ndarray, stage: int, best: int, upper: float, slack: float,
                    out: np.ndarray) -> np.ndarray:  # fmt: skip
        """:func:`symfruit.core._jit.frame_costs`' stage by :func:`_told`, outline by outline: the same shifts left,
        the same costs (each row's cost depends on that row alone), the same running sums and bounds."""
        reach, trim, count = self.reach, self.trim, len(self.outlines)
        order = self.order
        first, rest = int(order[0]), [int(i) for i in order[1:]]
        if stage == 0:
            out[first] = _told(self.outlines[first], shifts, reach, trim, False)
            return np.array([int(np.argmin(out[first]))], np.int64)
        if stage == 1:
            for i in rest:
                out[i, best] = _told(self.outlines[i], shifts[best : best + 1], reach, trim, False)[0]
            return np.array([best], np.int64)
        prune = stage == 2
        limit = _limit(upper, slack, count) if prune else np.inf
        full = np.zeros(len(shifts), bool)  # the shifts every outline is costed at already
        if prune:
            full[best] = True
        alive = np.flatnonzero(out[first] <= limit) if prune else np.arange(len(shifts))
        summed = out[first, alive]
        for n, i in enumerate(rest, 2):
            if len(todo := alive[~full[alive]]):
                out[i, todo] = _told(self.outlines[i], shifts[todo], reach, trim, False)
            summed = summed + out[i, alive]
            if not prune:
                continue
            keep = summed <= limit
            alive, summed = alive[keep], summed[keep]
            if n < count and len(alive) > 1:  # the least sum so far: its frame cost may bound lower (stop 42)
                at = int(alive[int(np.argmin(summed))])  # no NaN is left in: each sum is within the limit
                if not full[at]:
                    for j in rest[n - 1 :]:
                        out[j, at] = _told(self.outlines[j], shifts[at : at + 1], reach, trim, False)[0]
                    full[at] = True
                    mean = sum(out[:, at].tolist()) / count  # in the outlines' order, as the kernel sums them
                    if mean < upper:
                        upper, limit = mean, _limit(mean, slack, count)
        return alive

    def fast(self, shifts: np.ndarray) -> np.ndarray:
        """(k,) the fast cost of each shift of ``shifts`` (k, 2): every outline's (as far as it tells it), their mean as
        :meth:`least` takes it."""
        shifts = np.ascontiguousarray(shifts, dtype=np.int64)
        out = np.empty((len(self.outlines), len(shifts)))
        self._stage(shifts, 0, -1, 0.0, 0.0, out)  # the first outline's row, then the others' (as least's plain search)
        self._stage(shifts, 3, -1, 0.0, 0.0, out)
        return np.mean(out, axis=0)

    def least(self, shifts: np.ndarray, cost: Callable[..., np.ndarray]) -> int:
        """``least(shifts)`` of :func:`registration_shift` (``cost``: its exact costs): the first shift of least exact
        cost. The fast costs are within ``slack`` of the exact ones, so only the shifts within twice that of their
        least can be it; those (one, but for ties) are costed exactly.

        With more than one outline and more than :data:`_PRUNE_FROM` shifts (issue 19, eighteenth round: the coarse
        grid's 441 shifts of 9 fruit were most of the registration), not every outline at every shift. A shift's
        cost is the mean of the outlines' costs, each at least 0, so the outlines' costs summed so far, divided by
        their number, are a lower bound of it. The outline of fewest points is costed first, at every shift, and
        the frame's cost at that outline's least shift bounds the least one from above; each further outline is
        costed only at the shifts whose lower bound is not above that by more than the margin (:func:`_limit`),
        which is more than twice the slack (made with a bound of the largest cost an outline can have: its
        window's diagonal plus the reach and its band) and more than the sums' rounding. After each outline, the
        frame's cost at the shift left of least sum so far bounds the least one too, and lowers the bound when less
        (stop 42: the first outline's least shift can cost the frame several times the least one, bench seed 2's
        7.47 px against 1.19, and the pruning then kept most shifts). Any frame cost at any shift is such a bound,
        and the rows of ``out`` are the outlines' whatever the order they are costed in: a shift left out cannot be
        among those within twice the slack of the least fast cost; those left in have every outline's fast cost,
        their mean taken as for every shift. The shifts within twice the larger slack of the least are costed
        exactly, the first least returned: any taken beyond the plain search's own lie more than its slack above
        its least fast cost, so above the least exact one, and are never it."""
        count = len(self.outlines)
        shifts = np.ascontiguousarray(shifts, dtype=np.int64)
        out = np.empty((count, len(shifts)))
        self.means = np.full(len(shifts), np.nan)
        best = int(self._stage(shifts, 0, -1, 0.0, 0.0, out)[0])
        if count > 1 and len(shifts) > _PRUNE_FROM:
            self._stage(shifts, 1, best, 0.0, 0.0, out)
            upper = float(np.mean(np.ascontiguousarray(out[:, best : best + 1]), axis=0)[0])
            # no distance in a window exceeds its diagonal (beyond it the map reads -reach): no fast cost exceeds it
            top = max(float(np.hypot(*o.inside.shape)) + float(self.reach) + o.band for o in self.outlines)
            slack = 1e-10 * (1.0 + top)
            alive = self._stage(shifts, 2, best, upper, slack, out)
            fast = np.mean(out[:, alive], axis=0)
            self.means[alive] = fast
            near = alive[fast <= fast.min() + 2.0 * slack]
        else:
            self._stage(shifts, 3, -1, 0.0, 0.0, out)
            fast = np.mean(out, axis=0)
            self.means[:] = fast
            slack = 1e-10 * (1.0 + float(np.abs(fast).max()))  # some 10^4 times the sums' rounding
            near = np.flatnonzero(fast <= fast.min() + 2.0 * slack)
        return int(near[np.argmin(cost(shifts[near]))]) if len(near) > 1 else int(near[0])


def _limit(upper: float, slack: float, count: int) -> float:
    """:meth:`_FrameCosts.least`'s bound of the sum of ``count`` outlines' fast costs at a shift that can be the least
    one, from a frame cost ``upper`` at some shift: more than twice ``slack`` above it, and more than the sums'
    rounding (the compiled twin: :func:`symfruit.core._jit.prune_limit`, the same number)."""
    return (upper + 2.0 * slack + 1e-9 * (1.0 + upper)) * count


def _told(outline: _Outline, shifts: np.ndarray, reach: int, trim: float, exact: bool) -> np.ndarray:
    """(k,) :meth:`_Outline.cost` of each ``(dv, du)`` of ``shifts`` (k, 2) as far as the outline tells it: along
    an axis it does not tell (:attr:`_Outline.axes`) every shift costs what none does, so that fruit neither pulls
    the shift along it nor weighs against it; each distinct shift costed once.

    The distinct shifts are those of the told axis' column alone (``np.unique(..., axis=0)`` of the shifts with the
    other column zeroed, in the same order, without its rows' structured view and sort: a few times faster)."""
    axes = outline.axes
    if all(axes):
        return outline.cost(shifts, reach, trim, exact=exact)
    seen = np.zeros((min(len(shifts), 1), 2), dtype=shifts.dtype)
    back = np.zeros(len(shifts), dtype=np.intp)
    if any(axes):
        told = 0 if axes[0] else 1
        values, back = np.unique(shifts[:, told], return_inverse=True)
        seen = np.zeros((len(values), 2), dtype=shifts.dtype)
        seen[:, told] = values
    return outline.cost(seen, reach, trim, exact=exact)[back.reshape(-1)]


#: :func:`colour_trim`: the least share of a mask's outline pixels that a cut lying all round it (an overshoot, not a
#: shaded limb or a mask drawn off to one side) removes.
ALL_ROUND = 2.0 / 3.0


def colour_trim(color: np.ndarray, mask: np.ndarray, *, band_px: float, centres: int = 3, iterations: int = 5,
                min_accuracy: float = 0.85, margin: float = 0.5, wider: tuple[float, ...] = (),
                outline_share: float = ALL_ROUND, exclude: np.ndarray | None = None) -> np.ndarray:  # fmt: skip
    """``mask`` less the pixels of its outer band whose colour is the background's, not the fruit's.

    Masks drawn by people or models overshoot the fruit by a few pixels onto what lies around it, and the
    depth cannot tell (a time-of-flight camera returns nothing for a few pixels on both sides of an outline).
    The colour can: the pixels from ``band_px`` to ``3 band_px`` inside the mask are the fruit's (near the
    outline, its limb's shading included), a ring of ``band_px`` outside it the background's; both are
    summarised by ``centres`` colours each (a few rounds of k-means on chromaticity and brightness), and a
    band pixel whose squared colour distance to the background is below ``margin`` times its distance to the
    fruit is removed (a mixed pixel on the outline, between the two, stays). Nothing is removed when the two
    do not separate (the summaries misclass more than ``1 - min_accuracy`` of their own samples: a white ball
    before a white wall), and nothing beyond the band.

    A mask that overshoots by more than the band puts background into the fruit's sample, and the two then do
    not separate either: ``wider`` bands (pixels) are tried in turn, each with its own fruit sample further in,
    until one separates (docs/stress39.md: masks overshooting by 8-12 px at 1920x1080 were not trimmed at all).
    A wider band's trim is taken only when it removes at least ``outline_share`` of the mask's outline pixels: an
    overshooting mask's outline lies on the surroundings nearly all round, where a shaded limb darkening towards
    a background of the fruit's own colour is one side of it (the real lab spheres' lower halves: 36-54 %).

    Parameters
    ----------
    color : (h, w, 3) uint8, RGB
    mask : (h, w) bool
    band_px : float, pixels
    wider : floats, pixels
        Bands tried, in order, when the colours do not separate at ``band_px`` (default none).
    exclude : (h, w) bool, optional
        Pixels never sampled as the surroundings (:func:`symfruit.extract.front_ring`: something in front of the
        fruit, a leaf or twig crossing it, along which the mask was cut: the fruit runs on behind it, so the mask's
        edge there is no overshoot onto the surroundings, and where the occluder shows the fruit's own colour the two
        summaries would not separate; issue 18, strip64).
    """
    mask = np.asarray(mask, dtype=bool)
    if exclude is not None and not (exclude := np.asarray(exclude, dtype=bool) & ~mask).any():
        exclude = None
    if band_px <= 0 or not mask.any():
        return mask
    # the band's trim reads the distances up to its fruit sample's depth alone (3 band_px + 1): those, +inf beyond, the
    # same regions (stop 46, regspeed46); a wider band's reads the whole map
    inner = inner_distance(mask, 3.0 * float(band_px) + 1)
    kept = _colour_trim(color, mask, inner, float(band_px), centres, iterations, min_accuracy, margin, exclude)
    if kept is not None:
        return kept
    if wider:
        inner = inner_distance(mask)
    for band in wider:
        kept = _colour_trim(color, mask, inner, float(band), centres, iterations, min_accuracy, margin, exclude)
        if kept is not None:
            edge = mask & (inner <= 1.0)
            return kept if (edge & ~kept).sum() >= outline_share * edge.sum() else mask
    return mask


def _colour_trim(color: np.ndarray, mask: np.ndarray, inner: np.ndarray, band_px: float, centres: int,
                 iterations: int, min_accuracy: float, margin: float,
                 exclude: np.ndarray | None = None) -> np.ndarray | None:  # fmt: skip
    """:func:`colour_trim` with one band: the mask trimmed, or None where fruit and surroundings do not separate;
    the ring less ``exclude`` (None: nothing excluded)."""
    # a band pixel is compared with the fruit just inside the band and the surroundings just outside it, not
    # with the fruit's lit centre: a limb darkens towards a grey background and is still the fruit (learnt
    # over the whole interior, the real 200 mm sphere's shaded lower limb was trimmed)
    color = np.asarray(color)
    jit = compiled()
    if jit is not None and color.dtype == np.uint8 and color.ndim == 3 and color.shape[2] == 3 and exclude is None:
        return _colour_trim_compiled(jit, color, mask, inner, band_px, centres, iterations, min_accuracy, margin)
    if jit is not None:  # the three regions and their sizes in one pass (the same pixels)
        fruit, ring, band = (np.empty(mask.shape, bool) for _ in range(3))
        n_fruit, n_ring, n_band = jit.trim_regions(inner, mask, float(band_px), 3.0 * band_px + 1,
                                                   float(band_px + 1), fruit, ring, band)  # fmt: skip
    else:
        fruit = (inner > band_px) & (inner <= 3.0 * band_px + 1)
        ring = ~mask & within(mask, band_px + 1)  # 1 to band_px + 1 from the mask
        band = mask & (inner <= band_px)
        n_fruit, n_ring, n_band = int(fruit.sum()), int(ring.sum()), int(band.sum())
    if exclude is not None:
        ring &= ~exclude
        n_ring = int(ring.sum())
    if n_fruit < 20 or n_ring < 20 or not n_band:
        return None
    # the compiled twins of the features, the k-means and the test where numba is (the same values to the bit)
    jit = jit if color.dtype == np.uint8 and color.ndim == 3 and color.shape[2] == 3 else None
    feature = _colour_features if jit is None else jit.colour_features
    kmeans = _kmeans if jit is None else jit.kmeans

    def summary(x: np.ndarray, pick: np.ndarray) -> np.ndarray:
        x = x[pick]
        return kmeans(x, x[np.linspace(0, len(x) - 1, centres).astype(int)], iterations)

    f_fruit, f_ring = feature(color, fruit), feature(color, ring)
    # each summary from a sample of at most _SAMPLE pixels, drawn by np.random.default_rng(0) (both from one
    # generator; numpy promises its streams only within one build, so no compiled copy of its sampler: stop 38)
    rng = _seeded()
    picks = [rng.choice(len(x), min(len(x), _SAMPLE), replace=False) for x in (f_fruit, f_ring)]
    fc, bc = summary(f_fruit, picks[0]), summary(f_ring, picks[1])

    def is_fruit(x: np.ndarray, margin: float = 1.0) -> np.ndarray:
        return (_nearer_fruit if jit is None else jit.nearer_fruit)(x, fc, bc, float(margin))

    if is_fruit(f_fruit).mean() < min_accuracy or (~is_fruit(f_ring)).mean() < min_accuracy:
        return None
    keep = mask.copy()
    keep[band] = is_fruit(feature(color, band), margin)  # a mixed pixel on the outline, between the two, stays
    return fill_holes(_connected(keep, fruit))  # the pieces holding fruit pixels


def _colour_trim_compiled(jit: Any, color: np.ndarray, mask: np.ndarray, inner: np.ndarray, band_px: float,
                          centres: int, iterations: int, min_accuracy: float,
                          margin: float) -> np.ndarray | None:  # fmt: skip
    """:func:`_colour_trim` of a uint8 colour image by its compiled twins (issue 19, twentieth round): the regions and
    their features in one call (:func:`symfruit.core._jit.trim_features`), each summary's rows gathered and its
    k-means in one (``trim_summary``), the two accuracies' counts (``trim_separation``) and the band's test
    (``trim_band``, with the pieces holding fruit pixels and their holes filled since stop 42: ``trim_kept``) in one
    each; the samples drawn by numpy as in the twin. The same regions, features, centres, tests and pixels, bit for
    bit."""
    fruit, band = np.empty(mask.shape, bool), np.empty(mask.shape, bool)
    f_fruit, f_ring, n_band = jit.trim_features(color, inner, mask, float(band_px), 3.0 * band_px + 1,
                                                float(band_px + 1), fruit, band)  # fmt: skip
    if len(f_fruit) < 20 or len(f_ring) < 20 or not n_band:
        return None
    rng = _seeded()  # the twin's samples: the same generator, the same draws
    picks = [rng.choice(len(x), min(len(x), _SAMPLE), replace=False) for x in (f_fruit, f_ring)]
    fc = jit.trim_summary(f_fruit, picks[0], _spread(len(picks[0]), centres), iterations)
    bc = jit.trim_summary(f_ring, picks[1], _spread(len(picks[1]), centres), iterations)
    n_fruit_ok, n_ring_ok = jit.trim_separation(f_fruit, f_ring, fc, bc)
    # the twin's accuracies are the booleans' means: their counts over their rows
    if n_fruit_ok / len(f_fruit) < min_accuracy or n_ring_ok / len(f_ring) < min_accuracy:
        return None
    kept = np.empty(mask.shape, bool)  # the band's test, the pieces holding fruit pixels, their holes filled
    jit.trim_kept(color, mask, band, fruit, fc, bc, float(margin), kept)
    return kept


def _spread(n: int, k: int) -> np.ndarray:
    """(k,) int64: ``np.linspace(0, n - 1, k).astype(int)`` (``n >= 1``), :func:`_colour_trim`'s starting centres, in
    Python floats as numpy computes them (``i * ((n - 1) / (k - 1))``, the last ``n - 1``), without its call (some
    10 us)."""
    if k < 2:
        return np.zeros(k, np.int64)
    step = float(n - 1) / (k - 1)
    at = [int(i * step) if step != 0 else 0 for i in range(k)]
    at[-1] = n - 1
    return np.array(at, np.int64)


def _seeded() -> np.random.Generator:
    """``np.random.default_rng(0)`` as made afresh: this thread's own generator, made once, with the state a fresh one
    starts from set back into it (the same draws; 5 instead of 30 us, and :func:`colour_trim` wants it for every
    fruit of a frame; issue 19, eighteenth round). Not to be held across another call of this function."""
    found = getattr(_SEEDED, "rng", None)
    if found is None:
        found = np.random.default_rng(0)
        _SEEDED.rng, _SEEDED.state = found, found.bit_generator.state
    else:
        found.bit_generator.state = _SEEDED.state
    return found


#: :func:`_seeded`'s generator and its starting state, per thread (a frame's fruit may be trimmed on several)
_SEEDED = threading.local()

#: :func:`colour_trim`'s samples: at most this many pixels of each region
_SAMPLE = 400


def _connected(image: np.ndarray, seeds: np.ndarray | tuple[int, int]) -> np.ndarray:
    """(h, w) bool: the pieces of ``image`` (4-connected, ``ndimage.label``'s default) holding a pixel of ``seeds``
    ((h, w) bool, or one pixel's row and column; a pixel outside ``image`` gives the background, label 0's pixels),
    by labelling them, or by the compiled twin's flood fill (:func:`symfruit.core._jit.connected`: the same
    pixels)."""
    image = np.asarray(image, dtype=bool)
    if (jit := compiled()) is not None and (not isinstance(seeds, tuple) or image[seeds]):
        out = np.empty(image.shape, bool)
        if isinstance(seeds, tuple):  # one pixel: its flood alone (issue 19, twentieth round: the same pixels)
            jit.connected_at(image, int(seeds[0]) % image.shape[0], int(seeds[1]) % image.shape[1], out)
        else:
            jit.connected(image, seeds, out)
        return out
    labels, n = ndimage.label(image)
    if isinstance(seeds, tuple):
        return labels == labels[seeds]
    reached = np.zeros(n + 1, bool)  # looked up by label (np.isin sorts)
    reached[labels[seeds]] = True
    reached[0] = False
    return reached[labels]


def _colour_features(color: np.ndarray, where: np.ndarray) -> np.ndarray:
    """(n, 3) :func:`colour_trim`'s features of the pixels ``where`` (h, w) bool of ``color`` (h, w, 3), in their
    order: chromaticity and brightness. The compiled twin: :func:`symfruit.core._jit.colour_features`."""
    rgb = color[where].astype(np.float64)
    total = rgb[:, 0] + rgb[:, 1] + rgb[:, 2] + 1.0
    return np.stack([rgb[:, 0] / total, rgb[:, 1] / total, 0.25 * total / (3 * 255.0)], axis=-1)


def _kmeans(x: np.ndarray, c: np.ndarray, iterations: int) -> np.ndarray:
    """(k, 3) the centres after up to ``iterations`` rounds of k-means of the rows ``x`` (n, 3) from the centres ``c``
    (k, 3), stopped when the labels repeat (the same labels give the same centres, bit for bit, in every round
    left). The compiled twin: :func:`symfruit.core._jit.kmeans`."""
    k, last = len(c), None
    for _ in range(iterations):
        label = np.argmin(_square_distances(x, c), axis=1)
        if last is not None and np.array_equal(label, last):
            break
        last = label
        # each centre's mean by one bincount: the rows added in order, as x[label == k].mean(axis=0) does
        count = np.bincount(label, minlength=k)
        total = np.bincount((label[:, None] * 3 + np.arange(3)).ravel(), weights=x.ravel(), minlength=3 * k)
        c = np.where(count[:, None] > 0, total.reshape(k, 3) / np.maximum(count, 1)[:, None], c)
    return c


def _nearer_fruit(x: np.ndarray, fruit: np.ndarray, ground: np.ndarray, margin: float) -> np.ndarray:
    """(n,) bool: ``margin`` times each row of ``x``'s (n, 3) least squared distance to the centres ``fruit`` is at
    most its least to the centres ``ground``. The compiled twin: :func:`symfruit.core._jit.nearer_fruit`."""
    return margin * _row_min(_square_distances(x, fruit)) <= _row_min(_square_distances(x, ground))


def within(mask: np.ndarray, radius: float) -> np.ndarray:
    """(h, w) bool: the pixels at most ``radius`` (pixels) from a pixel of ``mask``, the same as
    ``ndimage.distance_transform_edt(~mask) <= radius`` (distances ``sqrt(dy^2 + dx^2)`` compared as the transform
    computes them; nothing when ``mask`` is empty).

    A dilation by the disc of that radius, one row of it at a time: each row of the disc is a run of pixels, so
    the mask is widened along its rows once per run length and the rows ORed in at their offsets. For the few
    pixels of radius trimming needs, several times faster than the transform, which works out every distance.
    """
    mask = np.asarray(mask, dtype=bool)
    r = int(np.floor(radius)) if radius >= 0 else -1
    if r < 0 or not mask.any():
        return np.zeros(mask.shape, bool)
    if (jit := compiled()) is not None:  # the distances within reach, compiled (the same roots, compared alike)
        near = np.empty(mask.shape)
        jit.near_distance(mask, float(radius), True, near)
        return near <= radius
    off = np.arange(-r, r + 1)
    disc = np.sqrt((off[:, None] ** 2 + off[None, :] ** 2).astype(np.float64)) <= radius
    half = (disc.sum(axis=1) - 1) // 2  # each row of the disc: the run -half..half about its centre
    h, w = mask.shape
    rows = np.pad(mask, ((r, r), (0, 0))).view(np.uint8)
    wide = {int(k): ndimage.maximum_filter1d(rows, 2 * int(k) + 1, axis=1, mode="constant") for k in set(half.tolist())}
    out = np.zeros((h, w), np.uint8)
    for dy, k in zip(off.tolist(), half.tolist(), strict=True):
        out |= wide[int(k)][r - dy : r - dy + h]
    return out.view(bool)


def _row_min(d: np.ndarray) -> np.ndarray:
    """(n,) ``d.min(axis=1)`` of a few columns ``d`` (n, k), as ``np.minimum`` of the columns (the same values: a
    minimum is exact): numpy's reduction along so short an axis is some 20x slower."""
    out = d[:, 0]
    for j in range(1, d.shape[1]):
        out = np.minimum(out, d[:, j])
    return out


def _square_distances(x: np.ndarray, c: np.ndarray) -> np.ndarray:
    """(n, k) squared distances of rows ``x`` (n, 3) to rows ``c`` (k, 3): ``((x[:, None] - c[None]) ** 2).sum(-1)``
    term by term (numpy sums three terms left to right: the same values), without the (n, k, 3) array's short
    last-axis reduction."""
    d0 = x[:, 0, None] - c[None, :, 0]
    d1 = x[:, 1, None] - c[None, :, 1]
    d2 = x[:, 2, None] - c[None, :, 2]
    return d0 * d0 + d1 * d1 + d2 * d2
