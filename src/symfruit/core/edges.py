"""How far a depth image sits from its colour image, from the whole frame's edges (not the fruit's).

The standard targetless idea for calibrating a range sensor against a camera (depth discontinuities should lie
on image edges; Levinson and Thrun, "Automatic online calibration of cameras and lasers", RSS 2013): the near
side of every depth discontinuity is an object's outline, which the colour image sees as an edge. The shift that
lays the depth's outlines on the colour's edges is the registration offset.

- :func:`depth_outline`: the near side of every depth discontinuity, whether the far side holds depth (a jump)
  or not (a time-of-flight camera invalidates the mixed pixels between, and the depth camera's parallax shadow
  lies behind it). The far side of an invalid band (the shadow's edge), the edge of the depth camera's field
  of view and a band of invalid pixels between two surfaces at about one depth (where two surfaces meet, or a
  dark patch) are no outline: no surface within ``reach`` pixels lies farther by ``jump`` of the depth.
- :func:`colour_edges`: the colour image's edges (gradient maxima along the gradient, the strongest channel's
  gradient, a threshold a multiple of the frame's median gradient), with their orientation.
- :func:`mask_shift`: the same score with the fruit's masks' outlines in place of the depth's: the shift that lays
  masks drawn a few pixels off their fruit (an annotator's outline, a model's mask, masks drawn on an image
  registered off) back on the colour's edges, where the two opposite sides of the outlines agree (stop 61,
  docs/shift61.md).
- :func:`edge_shift`: an oriented, truncated chamfer score (each outline pixel's distance to the nearest colour
  edge of about its orientation, capped, the worst share dropped) at every integer shift within ``max_px``. The
  colour's texture (a printed board, handles, shading) only adds edges, which a distance from the depth's
  outline to the colour's edges tolerates. The outline pixels are also split by the side their background lies
  on: a time-of-flight camera loses the outermost pixels of every foreground object (mixed pixels), which moves
  each outline a band ``b`` towards its object; left and right outlines then give ``du + b`` and ``du - b``, top
  and bottom ones ``dv + b`` and ``dv - b``, so the band cancels where both sides are seen and can be told apart.

Convention as :func:`symfruit.core.surface.registration_shift`: the depth pixel ``(u + du, v + dv)`` sees what
the colour pixel ``(u, v)`` sees. Numpy and scipy only; images in, numbers out.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from .kernels import compiled
from .raster import distance_transform

__all__ = ["EdgeShift", "colour_edges", "depth_outline", "edge_shift", "mask_shift"]

#: Orientation bins of the oriented chamfer score (edge normals modulo 180 degrees); a depth outline pixel is
#: matched to colour edges in its own bin and the two beside it (within 45 degrees).
N_BINS = 6

#: The outline pixels a side of :func:`mask_shift`'s masks needs to say anything (:func:`edge_shift`'s own floor for
#: a side of the depth's outline). One mask alone has 20-60 a side at 40-120 px across: alone, 4 of the rendered
#: trees' 300 exact masks and 7 of the real spheres' 24 generous ones read moves of 2-10 px at a floor of 20, and
#: none at 100; frames of several masks read the same shifts at either (stop 62, docs/edge62.md).
MIN_SIDE_PX = 100


@dataclass(frozen=True)
class EdgeShift:
    """What :func:`edge_shift` found.

    Attributes
    ----------
    shift : (int, int)
        ``(du, dv)``, pixels: the shift of least cost over all outline pixels.
    cost : (2 m + 1, 2 m + 1) float
        The trimmed mean capped distance (pixels) at every shift, ``cost[dv + m, du + m]``.
    n_outline : int
        Outline pixels scored (after thinning to at most ``max_points``).
    sides : dict
        For ``"left"``, ``"right"``, ``"top"``, ``"bottom"`` (where the outline's background lies), the best shift
        along the axis that side constrains (``du`` for left and right, ``dv`` for top and bottom; the other
        coordinate free), how many outline pixels it rests on and how sharp its optimum is (the cost 2 px either
        side less the optimum's, pixels): ``(shift, n, rise)``, shift and rise None under ``min_side`` pixels.
    band : float or None
        Half the difference of the left and right sides' ``du`` (pixels): how far a time-of-flight camera's lost
        rim moves an outline towards its object (None without both sides).
    rise : (float, float)
        How sharp the optimum is: the cost 2 px away along ``u`` and along ``v`` (the mean of both directions),
        less the cost at the optimum, pixels.
    """

    shift: tuple[int, int]
    cost: np.ndarray
    n_outline: int
    sides: dict[str, tuple[int | None, int, float | None]]
    band: float | None
    rise: tuple[float, float]

    @property
    def balanced(self) -> tuple[float | None, float | None]:
        """``(du, dv)`` from the sides, the band cancelled: the mean of left and right (of top and bottom), each side
        weighted alike however many pixels it has. None for an axis one of whose sides does not say (the band
        need not be the same across and along: a side alone says the shift plus or minus its band)."""
        out: list[float | None] = []
        for lo, hi in (("left", "right"), ("top", "bottom")):
            a, b = self.sides[lo][0], self.sides[hi][0]
            out.append(None if a is None or b is None else (a + b) / 2.0)
        return out[0], out[1]


def _orientation_bin(gx: np.ndarray, gy: np.ndarray) -> np.ndarray:
    angle = np.mod(np.arctan2(gy, gx), np.pi)
    return (np.floor(angle / (np.pi / N_BINS) + 0.5).astype(np.int64)) % N_BINS


def depth_outline(
    depth: np.ndarray, *, jump: float = 0.1, reach: int = 30
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The near side of the depth image's discontinuities.

    Parameters
    ----------
    depth : (h, w) float, metres; 0 or NaN where invalid
    jump : float
        A surface at least this share of the pixel's depth (and 2 cm) farther, within ``reach`` pixels, makes a
        valid pixel at the image of an outline (beside an invalid or a farther pixel) the near side of a
        discontinuity.
    reach : int, pixels
        How far across an invalid band the farther surface is looked for. Pixels within ``reach`` of the depth
        camera's field of view (the valid region closed over gaps of ``2 reach`` and its holes filled) are no
        outline: the field's edge is no object's.

    Returns
    -------
    outline : (h, w) bool
    gx, gy : (h, w) float
        The outline's normal, pointing from the object to its background (the gradient of the depth with invalid
        pixels filled by the farthest depth within ``reach``: across an invalid band, its far side).
    """
    z = np.asarray(depth, dtype=np.float64)
    valid = np.isfinite(z) & (z > 0)
    z = np.where(valid, z, 0.0)
    far = ndimage.maximum_filter(z, size=2 * reach + 1)
    step = np.maximum(jump * z, 0.02)
    neighbours = np.full(z.shape, 0.0)
    for dv, du in ((0, 1), (0, -1), (1, 0), (-1, 0)):
        other = np.roll(np.where(valid, z, np.inf), (dv, du), axis=(0, 1))
        neighbours = np.maximum(neighbours, np.where(np.isfinite(other), other - z, np.inf))
    outline = valid & (neighbours > step) & (far - z > step)
    # The invalid band's side: keep only pixels that are the near side locally (nothing nearer by a step beside them).
    near = ndimage.minimum_filter(np.where(valid, z, np.inf), size=5)
    outline &= z - near < step
    closed = ndimage.binary_closing(valid, iterations=reach, border_value=0)
    field = ndimage.binary_fill_holes(closed | valid)
    outline &= ndimage.binary_erosion(field, iterations=reach, border_value=0)
    filled = ndimage.gaussian_filter(np.where(valid, z, far), 1.0)
    gx = ndimage.sobel(filled, axis=1)
    gy = ndimage.sobel(filled, axis=0)
    return outline, gx, gy


def colour_edges(color: np.ndarray, *, sigma: float = 1.0, ratio: float = 4.0) -> tuple[np.ndarray, np.ndarray]:
    """The colour image's edges: pixels whose gradient (the strongest of the three channels after a Gaussian of
    ``sigma``) is a maximum along its own direction and at least ``ratio`` times the frame's median gradient.

    Returns
    -------
    edges : (h, w) bool
    bins : (h, w) int
        Each pixel's gradient orientation bin (``N_BINS`` bins over 180 degrees).
    """
    gx, gy, mag = _colour_gradient(color, sigma)
    return _colour_peaks(gx, gy, mag, ratio * max(float(np.median(mag)), 1e-9))


def _colour_gradient(color: np.ndarray, sigma: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`colour_edges`' gradient, ``(gx, gy, mag)``: the strongest channel's after a Gaussian of ``sigma``."""
    img = np.asarray(color, dtype=np.float64)
    if img.ndim == 2:
        img = img[..., None]
    gx = np.zeros(img.shape[:2])
    gy = np.zeros(img.shape[:2])
    mag = np.zeros(img.shape[:2])
    for c in range(img.shape[2]):
        ch = ndimage.gaussian_filter(img[..., c], sigma)
        cx, cy = ndimage.sobel(ch, axis=1), ndimage.sobel(ch, axis=0)
        m = np.hypot(cx, cy)
        take = m > mag
        gx, gy, mag = np.where(take, cx, gx), np.where(take, cy, gy), np.where(take, m, mag)
    return gx, gy, mag


def _colour_peaks(gx: np.ndarray, gy: np.ndarray, mag: np.ndarray, threshold: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`colour_edges` from the gradient: its maxima along their own direction above ``threshold``."""
    # Non-maximum suppression along the gradient, quantised to 4 directions.
    angle = np.mod(np.arctan2(gy, gx), np.pi)
    q = (np.floor(angle / (np.pi / 4) + 0.5).astype(np.int64)) % 4
    offsets = ((0, 1), (1, 1), (1, 0), (1, -1))  # (dv, du) along 0, 45, 90, 135 degrees
    peak = np.zeros(mag.shape, bool)
    for k, (dv, du) in enumerate(offsets):
        a = np.roll(mag, (dv, du), axis=(0, 1))
        b = np.roll(mag, (-dv, -du), axis=(0, 1))
        peak |= (q == k) & (mag >= a) & (mag >= b)
    edges = peak & (mag > threshold)
    edges[[0, -1], :] = False
    edges[:, [0, -1]] = False
    return edges, _orientation_bin(gx, gy)


def _edge_distances(edges: np.ndarray, ebins: np.ndarray, cap: float, used: np.ndarray | None = None) -> np.ndarray:
    """(N_BINS, h, w) float32: one distance map an orientation bin, each pixel's distance to the nearest colour edge
    within one bin of it, capped at ``cap`` (:func:`edge_shift`'s and :func:`mask_shift`'s score). ``used``: the
    bins whose maps are read (the others are left at ``cap``); all of them when None."""
    dist = np.full((N_BINS, *edges.shape), cap, np.float32)
    for b in range(N_BINS) if used is None else np.unique(used):
        apart = (ebins - b) % N_BINS  # within one bin of b: 0, 1 or N_BINS - 1
        near_bin = edges & ((apart <= 1) | (apart == N_BINS - 1))
        if near_bin.any():
            dist[b] = np.minimum(distance_transform(~near_bin), cap)
    return dist


def _shift_costs(dist: np.ndarray, rows: np.ndarray, cols: np.ndarray, bins: np.ndarray, m: int, cap: float,
                 sign: int) -> np.ndarray:  # fmt: skip
    """(2m+1, 2m+1, n) float32 over (dv, du, point): each point's capped distance (``dist``, its bin's map) where the
    shift puts it, ``(r + sign dv, c + sign du)``; ``cap`` off the image."""
    h, w = dist.shape[1:]
    out = np.full((2 * m + 1, 2 * m + 1, len(rows)), cap, np.float32)
    for i, dv in enumerate(range(-m, m + 1)):
        rr = rows + sign * dv
        ok_r = (rr >= 0) & (rr < h)
        for j, du in enumerate(range(-m, m + 1)):
            cc = cols + sign * du
            ok = ok_r & (cc >= 0) & (cc < w)
            out[i, j, ok] = dist[bins[ok], rr[ok], cc[ok]]
    return out


def _moved_costs(dist: np.ndarray, rows: np.ndarray, cols: np.ndarray, bins: np.ndarray, m: int,
                 cap: float) -> np.ndarray:  # fmt: skip
    """:func:`_shift_costs` with ``sign`` 1 read in one gather: each point's ``(2m+1, 2m+1)`` window of its bin's map
    (padded by ``cap``), the same values."""
    padded = np.pad(dist, ((0, 0), (m, m), (m, m)), constant_values=np.float32(cap))
    windows = np.lib.stride_tricks.sliding_window_view(padded, (2 * m + 1, 2 * m + 1), axis=(1, 2))
    return np.ascontiguousarray(np.moveaxis(windows[bins, rows, cols], 0, -1))


def _trimmed(values: np.ndarray, keep: float) -> np.ndarray:
    """The mean of the ``keep`` share of the smallest values along the last axis (at least one)."""
    k = max(1, round(keep * values.shape[-1]))
    return np.sort(values, axis=-1)[..., :k].mean(axis=-1)


def edge_shift(
    depth: np.ndarray, color: np.ndarray, *, max_px: int = 20, cap: float = 6.0, keep: float = 0.7,
    max_points: int = 8000, min_side: int = 100, jump: float = 0.1, reach: int = 30,
    exclude: np.ndarray | None = None,
) -> EdgeShift:  # fmt: skip
    """The integer shift ``(du, dv)`` within ``max_px`` that lays the depth's outlines (:func:`depth_outline`) on
    the colour's edges (:func:`colour_edges`).

    Each outline pixel costs its distance to the nearest colour edge within 45 degrees of its orientation, capped
    at ``cap`` pixels (a pixel off the image costs ``cap``); a shift costs the mean of its ``keep`` share of
    cheapest pixels (an outline without a colour edge, a colour edge the depth does not see). At most
    ``max_points`` outline pixels are scored, evenly thinned. ``exclude``: (h, w) bool, pixels whose outline is
    not scored (the fruit's masks grown by ``max_px``, for a cue independent of the fruit).

    Raises
    ------
    ValueError
        When depth and colour differ in size.
    """
    z = np.asarray(depth, dtype=np.float64)
    if np.asarray(color).shape[:2] != z.shape:
        raise ValueError(f"depth {z.shape} and colour {np.asarray(color).shape[:2]} differ in size")
    outline, ogx, ogy = depth_outline(z, jump=jump, reach=reach)
    if exclude is not None:
        outline &= ~np.asarray(exclude, dtype=bool)
    edges, ebins = colour_edges(color)
    rows, cols = np.nonzero(outline)
    m = int(max_px)
    # Every point's cost at every shift is kept (for the sides): at most about 2e7 of them.
    max_points = max(1, min(max_points, 20_000_000 // (2 * m + 1) ** 2))
    step = max(1, -(-len(rows) // max_points))
    rows, cols = rows[::step], cols[::step]
    nx, ny = ogx[rows, cols], ogy[rows, cols]
    bins = _orientation_bin(nx, ny)
    dist = _edge_distances(edges, ebins, cap)
    shifts = np.arange(-m, m + 1)
    n = len(rows)

    def trimmed(values: np.ndarray) -> np.ndarray:
        return _trimmed(values, keep)

    # the depth's outline moved onto the colour: a point at (r, c) is read at (r - dv, c - du)
    every = _shift_costs(dist, rows, cols, bins, m, cap, -1)
    cost = trimmed(every) if n else np.full((2 * m + 1, 2 * m + 1), cap)
    iv, iu = (int(i) for i in np.unravel_index(int(np.argmin(cost)), cost.shape))
    shift = (int(shifts[iu]), int(shifts[iv]))

    def rise_along(axis: int) -> float:
        i0 = (iv, iu)
        vals = []
        for d in (-2, 2):
            idx = list(i0)
            idx[axis] = min(max(idx[axis] + d, 0), 2 * m)
            vals.append(cost[tuple(idx)])
        return float(np.mean(vals) - cost[iv, iu])

    # Sides: background to the left has a normal pointing -u (the depth rises towards the background).
    horizontal = np.abs(nx) > 2.0 * np.abs(ny)
    vertical = np.abs(ny) > 2.0 * np.abs(nx)
    side_sel = {"left": horizontal & (nx < 0), "right": horizontal & (nx > 0),
                "top": vertical & (ny < 0), "bottom": vertical & (ny > 0)}  # fmt: skip
    sides: dict[str, tuple[int | None, int, float | None]] = {}
    for name, sel in side_sel.items():
        count = int(sel.sum())
        if count < min_side:
            sides[name] = (None, count, None)
            continue
        # The axis the side constrains: the other is free (its best for every value of this one).
        per = trimmed(every[:, :, sel])
        profile = per.min(axis=0) if name in ("left", "right") else per.min(axis=1)
        best = int(np.argmin(profile))
        around = float(np.mean(profile[[max(best - 2, 0), min(best + 2, 2 * m)]]) - profile[best])
        sides[name] = (int(shifts[best]), count, around)
    left, right = sides["left"][0], sides["right"][0]
    band = None if left is None or right is None else (left - right) / 2.0
    return EdgeShift(shift, cost, n, sides, band, (rise_along(1), rise_along(0)))


def mask_shift(color: np.ndarray, labels: np.ndarray, *, max_px: int = 10, cap: float = 6.0, keep: float = 0.7,
               max_points: int = 8000, min_side: int = MIN_SIDE_PX,
               boxes: list[tuple[slice, slice] | None] | None = None) -> tuple[int, int]:  # fmt: skip
    """The integer shift ``(du, dv)`` within ``max_px`` that moves the masks ``labels`` (0: none) onto the colour's
    edges (:func:`colour_edges`), ``(0, 0)`` where the outlines do not tell one.

    The score is :func:`edge_shift`'s (each outline pixel's distance to the nearest colour edge within 45 degrees of
    its orientation, capped at ``cap``; a shift costs the mean of its ``keep`` share of cheapest pixels), with the
    masks' outline pixels (a mask's pixels beside one outside it, oriented by the smoothed mask's gradient) moved by
    the shift. Each side of the outlines (top, bottom, left, right) gives its best shift along the axis it constrains,
    the other axis free, from at least ``min_side`` pixels (:data:`MIN_SIDE_PX`: a few masks' worth, so a frame of
    one or two small masks is not moved). An axis moves only where its two sides agree within two
    pixels: a mask drawn off its fruit moves both one way, a generous mask pulls them apart (its top outline up, its
    bottom one down), and one side alone cannot tell a shift from an overshoot (a side whose outline lies on no edge
    at any shift, most of it farther than half the cap, says nothing). Each side reads its outline to a pixel (the
    colour edge's maximum lies between a mask's last pixel and the first outside it; on the real Azure Kinect
    spheres, masks drawn right read their top -1 and bottom +1), so two sides of masks drawn right may differ by two
    and a mask grown a pixel or two reads as much: an axis whose sides straddle none stays. An axis moves by its two
    sides' mean (their pixels of rounding outwards cancel; a half pixel goes to the shift of less cost over every
    outline pixel), and only where that mean is :data:`MIN_MOVE_PX` or more (it is told to about a pixel), and the
    shift is taken only where it costs less than none over every outline pixel.

    Each mask's colour edges are read in a window about it (:func:`_mask_costs`: a tenth to an eighth of a
    1920 x 1080 tree frame's pixels, 0.05-0.07 s of CPU for the whole window's 0.56-0.85 s; stop 62), at the
    threshold the windows' union gives. The shift is the frame's, one for all its masks: each mask alone reads too
    little (stop 62: alone, 4 of the rendered trees' 300 exact masks read moves of 2-10 px, and 7 of the real
    spheres' masks grown 2-10 px read 3-9 px).

    Parameters
    ----------
    color : (h, w, 3) or (h, w) array, the colour image
    labels : (h, w) int, the masks on the colour image's pixels
    boxes : list, optional
        ``ndimage.find_objects(labels)`` where the caller has it (a pass over the whole image less).

    Raises
    ------
    ValueError
        When colour and masks differ in size.
    """
    parts = _mask_costs(color, labels, max_px=max_px, cap=cap, max_points=max_points, boxes=boxes)
    if not parts:
        return (0, 0)
    every = np.concatenate([p[1] for p in parts], axis=2)
    gx, gy = (np.concatenate([p[i] for p in parts]) for i in (2, 3))
    return _decide(every, gx, gy, int(max_px), cap, keep, min_side)


#: The least move :func:`mask_shift` makes along an axis (pixels): the two sides' mean is told to about a pixel.
MIN_MOVE_PX = 2.0

#: Pixels beyond a colour edge's own that :func:`colour_edges` reads to find it: the Gaussian's reach (4 sigma at
#: sigma 1), the Sobel's pixel and the non-maximum suppression's neighbour; a window grown by it finds the edges
#: of its inner part as the whole image would, but for the threshold (the median gradient of the window).
EDGE_REACH = 6


def _outline_samples(
    lab: np.ndarray, max_points: int, boxes: list[tuple[slice, slice] | None] | None = None
) -> tuple[list[tuple[int, tuple[slice, slice]]], np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
           np.ndarray] | None:  # fmt: skip
    """:func:`_mask_costs`' outline pixels of the masks ``lab`` (2-D labels; ``boxes`` their
    ``ndimage.find_objects``, found here when None): ``(parts, ks, rows, cols, gx, gy, bins)``, ``parts`` each mask's
    ``(label, box)`` in label order, then of all masks' outline pixels together, thinned to at most ``max_points``
    (every ``step``-th), their labels, rows, columns, the gradient of the mask smoothed by 1.5 px at them and their
    orientation bins (:func:`_orientation_bin`); None when no mask has a pixel."""
    h, w = lab.shape
    parts = []
    jit = compiled()
    for k, sl in enumerate(ndimage.find_objects(lab) if boxes is None else boxes, start=1):
        if sl is None:
            continue
        a0, a1 = max(sl[0].start - 3, 0), min(sl[0].stop + 3, h)
        b0, b1 = max(sl[1].start - 3, 0), min(sl[1].stop + 3, w)
        if jit is not None:  # the same pixels and gradient, worked out at the outline alone (stop 63)
            rows, cols, gx, gy = jit.outline_gradient(lab, k, a0, a1, b0, b1, *gaussian_weights(1.5))
            parts.append((np.full(len(rows), k), rows + a0, cols + b0, gx, gy, (k, sl)))
            continue
        mask = lab[a0:a1, b0:b1] == k
        rows, cols = np.nonzero(mask & ~ndimage.binary_erosion(mask, border_value=1))
        smooth = ndimage.gaussian_filter(mask.astype(np.float64), 1.5)
        gx, gy = ndimage.sobel(smooth, axis=1)[rows, cols], ndimage.sobel(smooth, axis=0)[rows, cols]
        parts.append((np.full(len(rows), k), rows + a0, cols + b0, gx, gy, (k, sl)))
    if not parts:
        return None
    ks, rows, cols, gx, gy = (np.concatenate([p[i] for p in parts]) for i in range(5))
    step = max(1, -(-len(rows) // max(1, int(max_points))))
    ks, rows, cols, gx, gy = ks[::step], rows[::step], cols[::step], gx[::step], gy[::step]
    return [p[5] for p in parts], ks, rows, cols, gx, gy, _orientation_bin(gx, gy)


def _mask_costs(
    color: np.ndarray, labels: np.ndarray, *, max_px: int, cap: float, max_points: int,
    boxes: list[tuple[slice, slice] | None] | None = None,
) -> list[tuple[int, np.ndarray, np.ndarray, np.ndarray]]:  # fmt: skip
    """The masks' outline pixels and each one's capped distance to the colour's edges at every shift
    (:func:`mask_shift`'s score), one ``(label, every, gx, gy)`` a mask with outline pixels left after thinning
    all masks' together to at most ``max_points``: ``every`` (2m+1, 2m+1, n) as :func:`_shift_costs`, ``gx, gy``
    the smoothed mask's gradient at them.

    Each mask's colour edges are read in its own window: its box grown by the search, the cap and the edges' reach
    (:data:`EDGE_REACH`), so every edge within the cap of a shifted outline pixel is the whole image's, and the
    threshold is the median gradient of the mask's window (the fruit and what lies just around it), not a whole
    frame's. A frame of small masks reads a band about each outline instead of the whole image (a 1920 x 1080 tree
    frame: a tenth to an eighth of its pixels).

    Only the threshold needs the whole window's gradient (:func:`_window_gradient`, every channel at once). The
    edges (:func:`_window_peaks`: their orientation and the non-maximum suppression only at pixels above the
    threshold) and their distance maps (:func:`_capped_distances`: each bin's over its own outline pixels' box,
    bounded at the cap) are worked out only within the search and the cap of the mask's box, where the shifted
    outline reads them: the same costs, to the bit, at 0.7 times the CPU (stop 62, docs/edgespeed62.md).

    With the compiled kernels (stop 63, docs/shift63.md) the outlines (:func:`symfruit.core._jit.outline_gradient`),
    the windows' gradients (:func:`symfruit.core._jit.colour_gradient`, which leaves the strongest channel's sum of
    squares for its magnitude: :func:`_squared_median` and :func:`_squared_peaks` take ``hypot`` only where a
    comparison is close) and the distance maps (:func:`symfruit.core._jit.capped_distances`) are each one call: the
    same costs, to the bit, at about half stop 62's CPU.
    """
    img = np.asarray(color)
    lab = np.asarray(labels)
    if img.shape[:2] != lab.shape or lab.ndim != 2:
        raise ValueError(f"colour {img.shape[:2]} and masks {lab.shape} differ in size")
    m = int(max_px)
    if m <= 0:
        return []
    h, w = lab.shape
    found = _outline_samples(lab, max_points, boxes)
    if found is None:
        return []
    parts, ks, rows, cols, gx, gy, bins = found
    reach = m + int(np.ceil(cap))  # an outline pixel's edges within the cap of it, wherever the search moves it
    pad = reach + EDGE_REACH + 1
    squared = _squares_kernel(img)
    windows, seen, pooled, fresh = [], np.zeros((h, w), bool), [], []
    for k, sl in parts:
        mine = ks == k
        if not mine.any():
            continue
        r0, r1 = max(sl[0].start - pad, 0), min(sl[0].stop + pad, h)
        c0, c1 = max(sl[1].start - pad, 0), min(sl[1].stop + pad, w)
        gradient = _window_gradient(img[r0:r1, c0:c1], squared)
        windows.append((k, sl, mine, r0, c0, gradient))
        fresh.append(~seen[r0:r1, c0:c1])
        pooled.append(gradient[0][fresh[-1]])  # each pixel of the windows' union once
        seen[r0:r1, c0:c1] = True
    if not windows:  # thinned away, or no mask has a pixel beside one outside it (a mask over the whole image)
        return []
    # the threshold: a multiple of the median gradient over the windows' union (the masks and what lies around them)
    values = np.concatenate(pooled)
    if squared:  # the kernel's sums of squares: their median's magnitude, hypot worked out only about the median

        def band(lo: float, hi: float) -> np.ndarray:
            """The magnitudes of the union's pixels whose sum of squares lies within ``[lo, hi]``."""
            out = []
            for (*_, (sq, sx, sy, _e)), f in zip(windows, fresh, strict=True):
                sel = f & (sq >= lo) & (sq <= hi)
                out.append(np.hypot(sx[0][sel], sy[0][sel]))
            return np.concatenate(out)

        median = _squared_median(values, band)
    else:
        median = float(np.median(values))
    threshold = 4.0 * max(median, 1e-9)
    costs = []
    for k, sl, mine, r0, c0, gradient in windows:
        # the window's edges and their distances are read only within ``reach`` of the mask's box (its outline
        # pixels moved by the search and the cap about them): no farther edge lies within the cap of a read pixel
        a0, a1 = max(sl[0].start - reach, 0) - r0, min(sl[0].stop + reach, h) - r0
        b0, b1 = max(sl[1].start - reach, 0) - c0, min(sl[1].stop + reach, w) - c0
        if squared:
            er, ec, ebins = _squared_peaks(gradient[0], gradient[1][0], gradient[2][0], threshold, (a0, a1, b0, b1))
        else:
            mag, cx, cy, each = gradient
            assert each is not None
            er, ec, ebins = _window_peaks(mag, cx, cy, each, threshold, (a0, a1, b0, b1))
        rr, cc = rows[mine] - r0 - a0, cols[mine] - c0 - b0
        dist = _capped_distances((a1 - a0, b1 - b0), er - a0, ec - b0, ebins, cap, (rr, cc, bins[mine]), m)
        # the masks moved by (du, dv): a point at (r, c) is read at (r + dv, c + du); off the window is off the image
        costs.append((k, mine, _padded_costs(dist, rr + m, cc + m, bins[mine], m)))
    return [(k, every, gx[mine], gy[mine]) for k, mine, every in costs]


#: A part in 1e9: how far apart two sums of squares ``gx * gx + gy * gy`` must lie to order their ``hypot``s, and a
#: sum of squares from the square of a magnitude (each is within a few parts in 1e16 of its exact value, ``hypot``
#: within one; stop 63, docs/shift63.md).
_APART = 1e-9


def _squares_kernel(img: np.ndarray) -> bool:
    """Whether :func:`_window_gradient` runs the compiled kernel on windows of ``img``: there are kernels, and its
    values are whole numbers or finite floats under 1e100 (their gradients' squares then neither overflow nor lose
    their ordering to rounding)."""
    if compiled() is None or img.size == 0:
        return False
    if img.dtype.kind in "biu":
        return True
    return img.dtype.kind == "f" and bool(np.isfinite(img).all()) and float(np.abs(img).max()) < 1e100


def _squared_median(values: np.ndarray, band: Callable[[float, float], np.ndarray]) -> float:
    """``np.median`` of the magnitudes ``hypot(gx, gy)`` whose sums of squares ``gx * gx + gy * gy`` are ``values``,
    to the bit, from ``band(lo, hi)``: the magnitudes of the values within ``[lo, hi]`` alone.

    The two middle sums of squares (one for an odd count) bound the band, widened by :data:`_APART`: a value below
    it is the magnitude of less than the lower middle one, a value above it of more than the upper middle one
    (their rounding is far less than a part in 1e9). So the middle magnitudes are the band's own, at their ranks
    less the count below it, and their mean is ``np.median``'s (a mean of the one or two middle values)."""
    n = len(values)
    lo_k, hi_k = (n - 1) // 2, n // 2
    part = np.partition(values, [lo_k, hi_k] if hi_k != lo_k else lo_k)
    a, b = float(part[lo_k]), float(part[hi_k])
    lo = a * (1.0 - _APART) if a > 1e-280 else -1.0  # near underflow: every value from 0 up
    hi = max(b * (1.0 + _APART), 1e-280)
    below = int(np.count_nonzero(values < lo))
    exact = np.sort(band(lo, hi))
    return float(np.mean(exact[lo_k - below : hi_k - below + 1]))


@functools.lru_cache(maxsize=8)
def gaussian_weights(sigma: float = 1.0) -> tuple[np.ndarray, bool]:
    """The weights of ``ndimage.gaussian_filter1d(x, sigma)`` (truncated at 4 sigma): its response to an impulse
    (each weight times 1, plus zeros: exact; the kernel is symmetric), and whether ``ndimage.correlate1d`` takes them
    as symmetric (each pair within the float64 epsilon: it then adds each pair before multiplying). The compiled
    filters that must give scipy's values to the bit take these (here and in :mod:`symfruit.segment.colour`)."""
    radius = int(4.0 * sigma + 0.5)
    impulse = np.zeros(2 * radius + 1)
    impulse[radius] = 1.0
    weights = ndimage.gaussian_filter1d(impulse, sigma, mode="constant")
    weights.flags.writeable = False
    eps = float(np.finfo(np.float64).eps)
    return weights, bool(np.all(np.abs(weights[radius + 1 :] - weights[:radius][::-1]) <= eps))


def _window_gradient(
    window: np.ndarray, squared: bool | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """:func:`_colour_gradient` at sigma 1 with the channels side by side, ``(mag, cx, cy, each)``: ``mag`` (h, w)
    the strongest channel's magnitude, ``cx, cy, each`` (c, h, w) every channel's gradient and magnitude. The same
    filters along the same axes (a Gaussian and a Sobel per channel): the same values, to the bit.

    ``squared`` (:func:`_squares_kernel` of the image when None): the compiled kernel,
    :func:`symfruit.core._jit.colour_gradient`, in one pass a channel, and ``(squares, gx, gy, None)``: the strongest
    channel's (the same channel) ``gx * gx + gy * gy`` (h, w) in place of its magnitude, and its gradient ``gx, gy``
    (1, h, w) alone, the twin's to the bit. ``hypot``, some 12 ns a pixel, was half the kernel's time; its value is
    needed only where a comparison is close (:func:`_squared_median`, :func:`_squared_peaks`; stop 63,
    docs/shift63.md)."""
    img = np.asarray(window)
    if img.ndim == 2:
        img = img[..., None]
    if _squares_kernel(img) if squared is None else squared:
        h, w = img.shape[:2]
        squares, gx, gy = np.empty((h, w)), np.empty((1, h, w)), np.empty((1, h, w))
        weights, symmetric = gaussian_weights()
        jit = compiled()
        assert jit is not None
        jit.colour_gradient(img if img.dtype != np.bool_ else img.view(np.uint8), weights, symmetric, squares, gx[0],
                            gy[0])  # fmt: skip
        return squares, gx, gy, None
    img = np.asarray(img, dtype=np.float64)
    img = np.ascontiguousarray(np.moveaxis(img, -1, 0))
    ch = ndimage.gaussian_filter(img, (0.0, 1.0, 1.0))  # no smoothing across channels
    cx = ndimage.correlate1d(ch, [-1, 0, 1], 2, None, "reflect", 0.0, 0)  # ndimage.sobel(axis=1) of each channel
    ndimage.correlate1d(cx, [1, 2, 1], 1, cx, "reflect", 0.0, 0)
    cy = ndimage.correlate1d(ch, [-1, 0, 1], 1, None, "reflect", 0.0, 0)  # ndimage.sobel(axis=0)
    ndimage.correlate1d(cy, [1, 2, 1], 2, cy, "reflect", 0.0, 0)
    each = np.hypot(cx, cy)
    mag = each[0].copy()
    for c in range(1, len(each)):
        np.maximum(mag, each[c], out=mag)
    return mag, cx, cy, each


def _window_peaks(mag: np.ndarray, cx: np.ndarray, cy: np.ndarray, each: np.ndarray, threshold: float,
                  part: tuple[int, int, int, int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`_colour_peaks` of :func:`_window_gradient`'s gradient within ``part`` = ``(r0, r1, c0, c1)`` of the
    window, worked out only at the pixels above ``threshold`` (every other one is no edge): the edges' rows,
    columns (the window's) and orientation bins. The channel is the first strongest, as :func:`_colour_gradient`'s
    strict comparisons take it, and the window's own border holds no edge."""
    h, w = mag.shape
    r0, r1, c0, c1 = max(part[0], 1), min(part[1], h - 1), max(part[2], 1), min(part[3], w - 1)
    if r1 <= r0 or c1 <= c0:
        empty = np.zeros(0, np.int64)
        return empty, empty, empty
    rows, cols = np.nonzero(mag[r0:r1, c0:c1] > threshold)
    rows += r0
    cols += c0
    k = each[:, rows, cols].argmax(axis=0)
    gx, gy = cx[k, rows, cols], cy[k, rows, cols]
    angle = np.mod(np.arctan2(gy, gx), np.pi)
    q = (np.floor(angle / (np.pi / 4) + 0.5).astype(np.int64)) % 4
    dv, du = np.array((0, 1, 1, 1))[q], np.array((1, 1, 0, -1))[q]  # along 0, 45, 90, 135 degrees
    here = mag[rows, cols]
    peak = (here >= mag[rows - dv, cols - du]) & (here >= mag[rows + dv, cols + du])
    bins = (np.floor(angle[peak] / (np.pi / N_BINS) + 0.5).astype(np.int64)) % N_BINS  # _orientation_bin's
    return rows[peak], cols[peak], bins


def _squared_peaks(squares: np.ndarray, gx: np.ndarray, gy: np.ndarray, threshold: float,
                   part: tuple[int, int, int, int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`_window_peaks` from the compiled kernel's gradient (:func:`_window_gradient`): the strongest channel's
    ``gx, gy`` (h, w) and ``squares`` = ``gx * gx + gy * gy`` for its magnitude. A pixel is above ``threshold``, and
    at least as strong as a neighbour along its gradient, as the magnitudes say: by the sums of squares where they
    lie more than :data:`_APART` apart (squared threshold, or the two pixels'; nothing the rounding can turn), by
    ``hypot`` itself where they lie closer. The same edges and bins as :func:`_window_peaks`."""
    h, w = squares.shape
    r0, r1, c0, c1 = max(part[0], 1), min(part[1], h - 1), max(part[2], 1), min(part[3], w - 1)
    if r1 <= r0 or c1 <= c0:
        empty = np.zeros(0, np.int64)
        return empty, empty, empty
    t2 = threshold * threshold  # at least 1.6e-17: no sum of squares compared with it is near underflow
    rows, cols = np.nonzero(squares[r0:r1, c0:c1] > t2 * (1.0 - _APART))
    rows += r0
    cols += c0
    here = squares[rows, cols]
    close = here <= t2 * (1.0 + _APART)
    if close.any():
        keep = ~close
        keep[close] = np.hypot(gx[rows[close], cols[close]], gy[rows[close], cols[close]]) > threshold
        rows, cols, here = rows[keep], cols[keep], here[keep]
    sx, sy = gx[rows, cols], gy[rows, cols]
    angle = np.mod(np.arctan2(sy, sx), np.pi)
    q = (np.floor(angle / (np.pi / 4) + 0.5).astype(np.int64)) % 4
    dv, du = np.array((0, 1, 1, 1))[q], np.array((1, 1, 0, -1))[q]  # along 0, 45, 90, 135 degrees

    def at_least(nr: np.ndarray, nc: np.ndarray) -> np.ndarray:
        """Whether each pixel's magnitude is at least its neighbour's at ``(nr, nc)``."""
        other = squares[nr, nc]
        out = here >= other
        close = (here <= other * (1.0 + _APART)) & (other <= here * (1.0 + _APART))
        if close.any():
            mine = np.hypot(sx[close], sy[close])
            out[close] = mine >= np.hypot(gx[nr[close], nc[close]], gy[nr[close], nc[close]])
        return out

    peak = at_least(rows - dv, cols - du) & at_least(rows + dv, cols + du)
    bins = (np.floor(angle[peak] / (np.pi / N_BINS) + 0.5).astype(np.int64)) % N_BINS  # _orientation_bin's
    return rows[peak], cols[peak], bins


def _capped_distances(shape: tuple[int, int], rows: np.ndarray, cols: np.ndarray, ebins: np.ndarray, cap: float,
                      points: tuple[np.ndarray, np.ndarray, np.ndarray], m: int) -> np.ndarray:  # fmt: skip
    """:func:`_edge_distances` of the edges at ``(rows, cols)`` (orientation bins ``ebins``) on an image of
    ``shape``, where the ``points`` ``(rows, cols, bins)`` read them at every shift within ``m``, padded by ``m``
    pixels of ``cap`` all round: (N_BINS, h + 2 m, w + 2 m) float32, the same values wherever a point reads.

    Each bin's map is worked out over its own points' box grown by ``m + ceil(cap)`` (an edge farther from every
    point of the bin than that is farther than the cap from every pixel they read), the rest left at ``cap``."""
    h, w = shape
    prow, pcol, pbins = points
    reach = m + int(np.ceil(cap))
    dist = np.full((N_BINS, h + 2 * m, w + 2 * m), cap, np.float32)
    jit = compiled()
    if jit is not None:  # the same steps in one call (stop 63, docs/shift63.md)
        jit.capped_distances(rows, cols, ebins, float(cap), prow, pcol, pbins, m, dist)
        return dist
    for b in np.unique(pbins):
        apart = (ebins - b) % N_BINS  # within one bin of b: 0, 1 or N_BINS - 1
        near = (apart <= 1) | (apart == N_BINS - 1)
        mine = pbins == b
        r0, r1 = max(int(prow[mine].min()) - reach, 0), min(int(prow[mine].max()) + reach + 1, h)
        c0, c1 = max(int(pcol[mine].min()) - reach, 0), min(int(pcol[mine].max()) + reach + 1, w)
        near &= (rows >= r0) & (rows < r1) & (cols >= c0) & (cols < c1)
        if near.any():
            edges = np.zeros((r1 - r0, c1 - c0), bool)
            edges[rows[near] - r0, cols[near] - c0] = True
            away = ndimage.distance_transform_edt(~edges)
            dist[b, m + r0 : m + r1, m + c0 : m + c1] = np.minimum(away, cap, out=away)
    return dist


def _padded_costs(dist: np.ndarray, rows: np.ndarray, cols: np.ndarray, bins: np.ndarray, m: int) -> np.ndarray:
    """:func:`_moved_costs` on maps already padded by ``m`` (:func:`_capped_distances`; ``rows, cols`` the padded
    maps' own): each point's ``(2m+1, 2m+1)`` window of its bin's map, (2m+1, 2m+1, n)."""
    if (jit := compiled()) is not None:  # the same values copied in one call (stop 63)
        out = np.empty((2 * m + 1, 2 * m + 1, len(rows)), dist.dtype)
        jit.padded_costs(dist, rows, cols, bins, m, out)
        return out
    windows = np.lib.stride_tricks.sliding_window_view(dist, (2 * m + 1, 2 * m + 1), axis=(1, 2))
    return np.ascontiguousarray(np.moveaxis(windows[bins, rows - m, cols - m], 0, -1))


def _decide(every: np.ndarray, gx: np.ndarray, gy: np.ndarray, m: int, cap: float, keep: float,
            min_side: int) -> tuple[int, int]:  # fmt: skip
    """:func:`mask_shift`'s rule on the outline pixels' costs ``every`` (:func:`_mask_costs`)."""

    def trimmed(values: np.ndarray) -> np.ndarray:
        return _trimmed(values, keep)

    # the smoothed mask rises into the mask: a top side's gradient points down (+v), a left side's right (+u)
    vertical, horizontal = np.abs(gy) > 2.0 * np.abs(gx), np.abs(gx) > 2.0 * np.abs(gy)
    sides = {"top": vertical & (gy > 0), "bottom": vertical & (gy < 0), "left": horizontal & (gx > 0),
             "right": horizontal & (gx < 0)}  # fmt: skip
    best: dict[str, int | None] = {}
    for name, sel in sides.items():
        if np.count_nonzero(sel) < min_side:
            best[name] = None
            continue
        per = trimmed(every[:, :, sel])
        profile = per.min(axis=1) if name in ("top", "bottom") else per.min(axis=0)
        # a side whose outline lies on no edge at any shift (most of it farther than half the cap) says nothing
        best[name] = int(np.argmin(profile)) - m if profile.min() < 0.5 * cap else None
    told = []
    for one, other in (("left", "right"), ("top", "bottom")):
        x, y = best[one], best[other]
        lo, hi = (min(x, y), max(x, y)) if x is not None and y is not None else (0, 0)
        mid = 0.5 * (lo + hi)  # each side's pixel of rounding outwards cancels in the two sides' mean
        # the mean is told to about a pixel (two sides of masks drawn right may read two apart): a move under two
        # pixels is not told from none (on the real spheres at a third of their resolution the sides read -2
        # and -1, and a move of a pixel, three of the camera's, put every box 3-5 mm off; stop 62, docs/edge62.md)
        agree = hi - lo <= 2 and (lo > 0 or hi < 0) and abs(mid) >= MIN_MOVE_PX
        told.append(sorted({math.floor(mid), math.ceil(mid)}) if agree else [0])
    if told == [[0], [0]]:
        return (0, 0)
    cost = trimmed(every)
    du, dv = min(
        ((u, v) for u in told[0] for v in told[1]), key=lambda t: (cost[t[1] + m, t[0] + m], abs(t[0]) + abs(t[1]))
    )
    return (du, dv) if cost[dv + m, du + m] < cost[m, m] else (0, 0)
