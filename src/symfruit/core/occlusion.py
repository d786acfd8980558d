"""Where the camera could not have seen one fruit: the occlusion information of a frame.

From a fruit's points alone, the edge of whatever lies in front of it (a leaf, a calyx, a stem, another
fruit) or the image border looks like the fruit's own outline, and a shape fitted to that outline is cut
short. The frame knows better: beside an occluding contour (the fruit seen edge-on) the camera sees
something clearly *behind* the fruit (the background), beside an occluder something at the fruit's
depth or in front of it. :func:`occlusion` marks, in an image window around the fruit, the pixels where
the camera could not have seen the fruit (:class:`Occlusion`); a completion method then treats outline
parts beside them as cuts and band rays landing on them as no evidence.

Numpy and scipy only; the same function serves a frame (:func:`symfruit.detect.detect`) and the
evaluation's rendered views, so both measure what a robot gets.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from ..errors import InputError
from .camera import Camera
from .kernels import compiled
from .limits import MAX_IMAGE_SIDE, check_image_size, depth_metres
from .points import as_points
from .raster import Silhouette, mask_box, nearest_index, square_filter

__all__ = [
    "Occlusion",
    "bridged",
    "occlusion",
    "overshoot",
    "own_edge",
    "support_radius",
    "support_reach",
    "with_own",
]


@dataclass(frozen=True)
class Occlusion:
    """Pixels of an image window where the camera could not have seen a fruit.

    Attributes
    ----------
    u0, v0 : int
        Image column and row of the window's top-left pixel.
    hidden : (h, w) bool
        Pixels where something at the fruit's depth or in front of it was seen (it may hide the fruit),
        or another fruit's mask lies (unless clearly behind the fruit).
    width, height : int
        The image's size: every pixel outside it is hidden (the camera saw nothing there). Pixels inside the
        image but outside the window are not.
    own : (h, w) bool, optional
        The fruit's own pixels in the window (its instance mask), which may reach beyond its points' pixels
        (a border dropped against flying pixels, pixels without depth).
    depth : (h, w) float, metres, optional
        What the camera saw at each pixel of the window (NaN: nothing): a hidden pixel hides the fruit only
        behind that depth, so a completion there must lie behind it (:meth:`depth_at`).
    overshoot : (h, w) bool, optional
        The pixels of :attr:`own` the mask overshoots the fruit by (:func:`overshoot`): the fruit's width is read
        without them (:func:`with_own`, ``trimmed``).
    seen_past : bool
        :attr:`overshoot` is where a time-of-flight camera saw past the fruit (:func:`overshoot`): no occluder's,
        so it is read on a cut outline too (stop 43).
    """

    u0: int
    v0: int
    hidden: np.ndarray
    width: int
    height: int
    own: np.ndarray | None = None
    depth: np.ndarray | None = None
    overshoot: np.ndarray | None = None
    seen_past: bool = False
    #: :attr:`hidden` grown by each radius asked for (:meth:`grown`), made once (the maps are read-only).
    _grown: dict[int, np.ndarray] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        hidden = np.asarray(self.hidden)
        if hidden.ndim != 2 or hidden.dtype != bool:
            raise InputError(f"occlusion hidden must be a 2-D bool image, got {hidden.dtype} {hidden.shape}")
        object.__setattr__(self, "hidden", hidden)
        for name in ("u0", "v0", "width", "height"):  # NaN, inf or fractions would index nonsense later
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer, float, np.floating)):
                raise InputError(f"occlusion {name} must be a whole number of pixels, got {value!r}")
            if not np.isfinite(value) or float(value) != int(value):
                raise InputError(f"occlusion {name} must be a whole number of pixels, got {value!r}")
            object.__setattr__(self, name, int(value))
        check_image_size(self.width, self.height, "occlusion")
        h, w = hidden.shape
        if not (0 <= self.u0 and 0 <= self.v0 and self.u0 + w <= self.width and self.v0 + h <= self.height):
            raise InputError(f"occlusion window {w}x{h} at ({self.u0}, {self.v0}) does not lie in its "
                             f"{self.width}x{self.height} image")  # fmt: skip
        if self.own is not None:
            own = np.asarray(self.own)
            if own.shape != hidden.shape or own.dtype != bool:
                raise InputError(f"occlusion own must be a bool image of the window's {w}x{h}, got {own.dtype} "
                                 f"{own.shape}")  # fmt: skip
        if self.overshoot is not None:
            over = np.asarray(self.overshoot)
            if over.shape != hidden.shape or over.dtype != bool:
                raise InputError(f"occlusion overshoot must be a bool image of the window's {w}x{h}, got "
                                 f"{over.dtype} {over.shape}")  # fmt: skip
        if self.depth is not None:
            seen = np.asarray(self.depth)
            if seen.shape != hidden.shape or seen.dtype.kind != "f":
                raise InputError(f"occlusion depth must be a float image of the window's {w}x{h}, got {seen.dtype} "
                                 f"{seen.shape}")  # fmt: skip

    @classmethod
    def _made(cls, u0: int, v0: int, hidden: np.ndarray, width: int, height: int, own: np.ndarray,
              depth: np.ndarray, overshoot: np.ndarray | None = None,
              seen_past: bool = False) -> Occlusion:  # fmt: skip
        """``Occlusion(u0, v0, hidden, width, height, own=own, depth=depth, overshoot=overshoot)`` without the checks
        that maps :func:`occlusion` made itself always pass (whole numbers, a window within a valid camera's image,
        bool and float maps of one shape): the same fields, the same object (stop 42: the checks cost about 25 us a
        fruit)."""
        made = object.__new__(cls)
        made.__dict__.update(u0=int(u0), v0=int(v0), hidden=hidden, width=int(width), height=int(height), own=own,
                             depth=depth, overshoot=overshoot, seen_past=seen_past, _grown={})  # fmt: skip
        return made

    def at(self, u: np.ndarray, v: np.ndarray, *, radius: int = 0) -> np.ndarray:
        """Whether pixels ``(u, v)`` are hidden, or have a hidden pixel within ``radius`` (a square).

        Parameters
        ----------
        u, v : (m,) float, pixels
            Image coordinates (rounded to the nearest pixel).
        radius : int, pixels

        Returns
        -------
        (m,) bool
        """
        u, v = np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64)
        if u.ndim == 1 and u.shape == v.shape and (jit := compiled()) is not None:  # the compiled twin of what follows
            return jit.occluded_at(np.ascontiguousarray(u), np.ascontiguousarray(v), self.hidden, self.u0, self.v0,
                                   self.width, self.height, int(radius))  # fmt: skip
        col = np.rint(u).astype(np.intp)
        row = np.rint(v).astype(np.intp)
        out = (col < radius) | (col >= self.width - radius) | (row < radius) | (row >= self.height - radius)
        h, w = self.hidden.shape
        c, r = col - self.u0, row - self.v0
        inside = (c >= 0) & (c < w) & (r >= 0) & (r < h)
        if radius <= 0 or not inside.any():
            out[inside] |= self.hidden[r[inside], c[inside]]
            return out
        r, c = r[inside], c[inside]  # the grown map over these pixels' box alone (:meth:`grown_part`)
        r0, c0 = int(r.min()), int(c.min())
        out[inside] |= self.grown_part(radius, r0, int(r.max()) + 1, c0, int(c.max()) + 1)[r - r0, c - c0]
        return out

    def grown(self, radius: int) -> np.ndarray:
        """(h, w) bool: the window's pixels with a hidden pixel of the window within ``radius`` (a square), made
        once per radius (the image border is :meth:`at`'s)."""
        if radius <= 0 or not self.hidden.any():
            return self.hidden
        found = self._grown.get(radius)
        if found is None:
            found = square_filter(self.hidden, radius)
            found.flags.writeable = False
            self._grown[radius] = found
        return found

    def grown_part(self, radius: int, r0: int, r1: int, c0: int, c1: int) -> np.ndarray:
        """(r1 - r0, c1 - c0) bool: rows ``r0:r1`` and columns ``c0:c1`` of :meth:`grown` (window pixels, inside
        the window), the same values, filtered over that box grown by ``radius`` alone (the filter's square
        reaches no farther; beyond the window it reads nothing hidden either way). A fruit's outline or seen
        region is a small part of its occlusion window (which reaches to where the fruit could project), and
        filtering the whole window cost more than the rest of :func:`~symfruit.core.agreement.observe`'s
        occlusion look-ups; a map :meth:`grown` has already made is cut instead."""
        if radius <= 0:
            return self.hidden[r0:r1, c0:c1]
        found = self._grown.get(radius)
        if found is not None:
            return found[r0:r1, c0:c1]
        h, w = self.hidden.shape
        g0, g1, f0, f1 = max(r0 - radius, 0), min(r1 + radius, h), max(c0 - radius, 0), min(c1 + radius, w)
        part = self.hidden[g0:g1, f0:f1]
        if not part.any():
            return part[r0 - g0 : r1 - g0, c0 - f0 : c1 - f0]
        grown = square_filter(part, radius)
        return grown[r0 - g0 : r1 - g0, c0 - f0 : c1 - f0]

    def depth_at(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """(m,) float, metres: what the camera saw at pixels ``(u, v)`` (rounded), NaN where nothing or outside
        the window (or without :attr:`depth`)."""
        col = np.rint(np.asarray(u, dtype=np.float64)).astype(np.intp) - self.u0
        row = np.rint(np.asarray(v, dtype=np.float64)).astype(np.intp) - self.v0
        out = np.full(col.shape, np.nan)
        if self.depth is None:
            return out
        h, w = self.hidden.shape
        inside = (col >= 0) & (col < w) & (row >= 0) & (row < h)
        out[inside] = self.depth[row[inside], col[inside]]
        return out

    def seen_at(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(hidden (m,) bool, seen (m,) float)``: :meth:`at` of pixels ``(u, v)`` (radius 0) and, where hidden,
        :meth:`depth_at` there (NaN elsewhere). By one compiled call where numba is installed
        (:func:`symfruit.core._jit.hidden_seen`: the same booleans and depths; issue 19, stop 50)."""
        u, v = np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64)
        if u.ndim == 1 and u.shape == v.shape and (jit := compiled()) is not None:
            depth = _NO_DEPTH if self.depth is None else self.depth
            if depth.ndim == 2 and depth.dtype in _NATIVE_FLOATS:
                return jit.hidden_seen(np.ascontiguousarray(u), np.ascontiguousarray(v), self.hidden, depth,
                                       self.u0, self.v0, self.width, self.height)  # fmt: skip
        hidden = self.at(u, v)
        seen = np.where(hidden, self.depth_at(u, v), np.nan) if hidden.any() else np.full(hidden.shape, np.nan)
        return hidden, seen

    def window(self, region: Silhouette, *, radius: int = 0) -> np.ndarray:
        """(h, w) bool in ``region``'s window: :meth:`at` of every pixel (cut from the grown map, no per-pixel
        look-up)."""
        h, w = region.mask.shape
        u = np.arange(region.u0, region.u0 + w)
        v = np.arange(region.v0, region.v0 + h)
        out = ((v < radius) | (v >= self.height - radius))[:, None] | ((u < radius) | (u >= self.width - radius))[
            None, :
        ]
        gh, gw = self.hidden.shape
        r0, c0 = max(region.v0, self.v0), max(region.u0, self.u0)
        r1, c1 = min(region.v0 + h, self.v0 + gh), min(region.u0 + w, self.u0 + gw)
        if r1 > r0 and c1 > c0:
            out[r0 - region.v0 : r1 - region.v0, c0 - region.u0 : c1 - region.u0] |= self.grown_part(
                radius, r0 - self.v0, r1 - self.v0, c0 - self.u0, c1 - self.u0
            )
        return out

    def allowed(self, region: Silhouette, *, gap: int = 2, thin: int = 0) -> np.ndarray:
        """(h, w) bool, this window: where the fruit seen as ``region`` may project.

        Its silhouette covers the region and cannot reach pixels where the camera saw something clearly behind
        it, so it lies within the connected part of the region and the hidden pixels (joined across gaps of
        up to ``gap`` pixels) that holds the region. With ``thin``, hidden structures narrower than ``2 thin
        + 1`` pixels (a stem) are left out first: a fruit cannot hide behind them.
        """
        h, w = self.hidden.shape
        rh, rw = region.mask.shape
        r0, c0 = max(region.v0, self.v0), max(region.u0, self.u0)
        r1, c1 = min(region.v0 + rh, self.v0 + h), min(region.u0 + rw, self.u0 + w)
        seen = np.zeros((h, w), dtype=bool)
        if r1 > r0 and c1 > c0:
            seen[r0 - self.v0 : r1 - self.v0, c0 - self.u0 : c1 - self.u0] = region.mask[
                r0 - region.v0 : r1 - region.v0, c0 - region.u0 : c1 - region.u0
            ]
        if not seen.any():
            return seen
        if (jit := compiled()) is not None:  # the compiled twin of what follows (the same pixels)
            return jit.allowed(self.hidden, seen, gap, thin)
        hidden = self.hidden
        if thin > 0 and (box := mask_box(hidden)) is not None:
            # An opening keeps a subset of its input, so it is made over the hidden pixels' box alone (outside
            # it, as outside the window, there is nothing): the same pixels, a window often several times larger.
            b0, b1, a0, a1 = box
            hidden = np.zeros_like(self.hidden)
            hidden[b0:b1, a0:a1] = open_square(self.hidden[b0:b1, a0:a1], 2 * thin + 1)
        allowed = hidden.copy()
        if gap > 0:
            # both filters only matter within ``gap`` of the seen pixels: run them on the seen box grown by
            # ``2 gap`` (their inputs there), clipped to the window as the filters' own border is
            size = 2 * gap + 1
            s0, s1, t0, t1 = mask_box(seen) or (0, h, 0, w)  # seen has pixels (above)
            b0, b1 = max(s0 - 2 * gap, 0), min(s1 + 2 * gap, h)
            a0, a1 = max(t0 - 2 * gap, 0), min(t1 + 2 * gap, w)
            grown = ndimage.maximum_filter(seen[b0:b1, a0:a1], size=size, mode="constant", cval=False)
            near = ndimage.maximum_filter(hidden[b0:b1, a0:a1], size=size, mode="constant", cval=False)
            allowed[b0:b1, a0:a1] |= grown & near
        allowed |= seen
        # Components are labelled over the box of the allowed pixels (none lies outside it, so no component
        # changes), the window's rest stays outside.
        b0, b1, a0, a1 = mask_box(allowed) or (0, h, 0, w)  # allowed holds the seen pixels
        labels, count = ndimage.label(allowed[b0:b1, a0:a1], structure=np.ones((3, 3), bool))
        keep = np.zeros(count + 1, dtype=bool)
        keep[labels[seen[b0:b1, a0:a1]]] = True
        keep[0] = False
        out = np.zeros_like(allowed)
        out[b0:b1, a0:a1] = np.take(keep, labels)  # a table look-up: np.take is twice as fast as keep[labels]
        return out

    def extent(self, region: Silhouette, *, gap: int = 2, thin: int = 0) -> np.ndarray:
        """Where the fruit seen as ``region`` can project at most: ``(u_min, v_min, u_max, v_max)``, pixels
        (pixel edges): the box of :meth:`allowed`; a side where it reaches the image's border is unbounded
        (``-inf`` / ``+inf``), one where it reaches the window's edge ends there.

        Where numba is, the box comes from a compiled twin of :meth:`allowed` that keeps the box of its flood fill,
        not an image of it, and reads the region's mask in place (:func:`symfruit.core._jit.allowed_box`: the same
        box; issue 19, eighteenth round: 1.1 against 1.6 ms for the benchmark frame's 9 fruit)."""
        if (jit := compiled()) is not None and region.mask.dtype == bool and region.mask.ndim == 2:
            ok, r0, r1, c0, c1 = jit.allowed_box(self.hidden, region.mask, region.v0 - self.v0, region.u0 - self.u0,
                                                 int(gap), int(thin))  # fmt: skip
            found = (r0, r1, c0, c1) if ok else None
        else:
            found = mask_box(self.allowed(region, gap=gap, thin=thin))
        if found is None:
            return np.array([-np.inf, -np.inf, np.inf, np.inf])
        r0, r1, c0, c1 = found  # pixel edges: the first row's top, the last row's bottom (r1 - 1 + 0.5)
        box = np.array([c0 + self.u0 - 0.5, r0 + self.v0 - 0.5, c1 + self.u0 - 0.5, r1 + self.v0 - 0.5])
        box[0] = -np.inf if c0 + self.u0 == 0 else box[0]
        box[1] = -np.inf if r0 + self.v0 == 0 else box[1]
        box[2] = np.inf if c1 + self.u0 == self.width else box[2]
        box[3] = np.inf if r1 + self.v0 == self.height else box[3]
        return box

    def share(self) -> float:
        """Share of the window's pixels that are hidden (for reports)."""
        return float(self.hidden.mean()) if self.hidden.size else 0.0


#: The depth dtypes the kernels read (native byte order).
_NATIVE_FLOATS = (np.dtype(np.float32), np.dtype(np.float64))
#: :meth:`Occlusion.seen_at`'s depth without one (no pixel inside it: NaN throughout).
_NO_DEPTH = np.zeros((0, 0))


def occlusion(
    depth: np.ndarray,
    mask: np.ndarray,
    points: np.ndarray,
    camera: Camera,
    *,
    others: np.ndarray | None = None,
    tolerance: float = 0.005,
    reach: int = 3,
    pad: int = 16,
    checked: bool = False,
    band: int = 8,
    trim_own: bool = True,
    eroded: int = 1,
    supports: bool = True,
) -> Occlusion:
    """The pixels around one fruit where the camera could not have seen it.

    A pixel beside the fruit's mask is hidden when what the camera saw there is not clearly behind the
    fruit: its depth is less than the fruit's own depth at the nearest of its points' pixels plus
    ``tolerance``, or it belongs to another fruit's mask that is not clearly behind. If the fruit
    continued there, its surface would lie at about that nearest depth, so the camera would have seen the
    fruit in front of anything clearly behind it (background: the fruit's edge there is its occluding
    contour); anything nearer, or at the fruit's own depth (a calyx lying on it, a touching fruit), may
    hide it. A pixel without depth (sensor dropout, common beside edges) takes the depth of the nearest
    pixel with depth within ``reach`` pixels that is not the fruit's; with none, it is not hidden. Last, a thin
    band at the fruit's own depth beside its mask that ends in something not hiding it is the fruit's own edge
    spread by the sensor (an active-stereo camera's fattening), not hidden (:func:`own_edge`, ``band``; stop 40), and
    with ``supports`` so is the band beside it of a surface at its own depth that runs on (a support; stop 56).

    Where numba is installed the maps are made in one compiled pass over the window
    (:func:`symfruit.core._jit.occlusion_maps`, after :func:`~symfruit.core.raster.nearest_index`: the same
    maps, bit for bit; the benchmark frame's 9 windows 4.9 against 9.1 ms; issue 19, fourteenth round), the
    nearest point pixels looked for only where they decide, on the rows holding such pixels
    (:func:`symfruit.core._jit.occlusion_window`: the same maps; 2.0 against 3.0 ms; eighteenth round), and with the
    window and the fruit's own depths in the same kernel, the images read in place and the own depths kept over the
    points' pixels' box alone (:func:`symfruit.core._jit.occlusion_at`: the same maps; 1.98 against 3.48 ms for the
    benchmark frame's 9 fruit, least of 40 passes of the recorded calls, on a loaded machine; twentieth round), and
    with :func:`own_edge` on the maps in the same kernel (``occlusion_edge_boxed`` until stop 60, since then
    :func:`symfruit.core._jit.occlusion_projected`, which projects the points too: the same maps; the benchmark
    frame's occlusion stage 6.6 against 4.0 ms least thread CPU; issue 19, stop 41).

    Parameters
    ----------
    depth : (H, W) float, metres
        The frame's depth image, aligned to the camera (0 or NaN: no depth).
    mask : (H, W) bool
        The fruit's own pixels (its instance mask): never hidden.
    points : (n, 3) float, metres
        The fruit's points (camera frame), which give its depth beside each pixel.
    camera : Camera
        Its image is ``W x H``; every pixel outside it is hidden (:meth:`Occlusion.at`).
    others : (H, W) bool, optional
        Other fruit's masks (this fruit's own pixels may be marked too: they are never hidden).
    tolerance : float, metres
        How far behind the fruit's nearest depth something must lie to count as seen behind it.
    reach : int, pixels
    pad : int, pixels
        The window is the points' pixel box grown on every side by this much plus the box's own size (a
        fruit hidden by half is no larger than that), clipped to the image.
    band : int, pixels
        The widest fattened edge an active-stereo camera spreads the fruit's own depth over (:func:`own_edge`, run
        on the map last: 0 leaves it out).
    trim_own : bool
        Find the pixels the mask overshoots the fruit by (:attr:`Occlusion.overshoot`, :func:`overshoot`; the
        maps are made with the whole mask); off: none.
    eroded : int, pixels
        The mask's border its points were never taken from (extraction's ``erode_px``), handed to
        :func:`overshoot`.
    supports : bool
        A surface that runs on from the fruit's outline at the fruit's own depth (a support: the board or branch it
        rests on) is not hidden within ``band`` of the fruit beyond the reach a round fruit may still continue behind
        it, whether or not the band ends (:func:`own_edge`'s ``supports``, :func:`support_reach`; stop 56); off: only
        a band that ends is cleared (stop 40's rule).
    checked : bool
        ``depth`` has been through :func:`~symfruit.core.limits.depth_metres` already (a
        :class:`~symfruit.core.frame.Frame`'s has): its units are not sampled again. The sample reads one
        cache line per pixel across the whole image, and for each fruit of a frame they had been evicted
        (a third of a millisecond a fruit, most of this function's own time after the transforms).

    Returns
    -------
    Occlusion

    Raises
    ------
    InputError
        On images of the wrong shape or no point in the image.
    """
    if not isinstance(camera, Camera):
        raise InputError(f"occlusion: camera must be a symfruit Camera, got {type(camera).__name__}")
    # plain float and ints from here: a numpy integer or float32 would be a kernel compiled anew (uint64 mixed with
    # int64 is float64 in numba, no slice index)
    tolerance, reach, pad, band, eroded = _check_parameters(tolerance, reach, pad, band, eroded)
    depth = np.asarray(depth) if checked else depth_metres(depth, "occlusion depth")
    if depth.dtype not in _NATIVE_FLOATS:  # float16, big-endian: every kernel below reads native float32 or float64
        depth = depth.astype(np.float64 if depth.dtype.itemsize > 4 else np.float32)  # (stop 47: numba TypingErrors)
    mask = np.asarray(mask, dtype=bool)
    shape = (camera.height, camera.width)
    if depth.shape != shape or mask.shape != shape:
        raise InputError(f"occlusion needs depth and mask images of {shape[1]}x{shape[0]} (the camera's), got "
                         f"{depth.shape[::-1]} and {mask.shape[::-1]}")  # fmt: skip
    if others is not None and np.shape(others) != shape:
        raise InputError(f"occlusion others must be a {shape[1]}x{shape[0]} image, got {np.shape(others)[::-1]}")
    points = as_points(points, min_count=1)
    focal = float(np.sqrt(camera.fx * camera.fy))  # overshoot reads the mask's width in metres
    if (jit := compiled()) is not None:  # as_points gives contiguous float64
        # the window, the fruit's own depths and the maps below in one compiled pass, the images read in place (the
        # same bits: issue 19, seventeenth round, the window and own depths; eighteenth, the nearest point pixel
        # looked for only where it decides, on the rows that need it alone; twentieth, the own depths kept over the
        # points' pixels' box, the window's maps in one kernel)
        image = depth if depth.dtype in (np.float32, np.float64) else np.asarray(depth, dtype=np.float64)
        near_to = np.zeros((0, 0), bool) if others is None else np.asarray(others, dtype=bool)
        # stop 41: own_edge on the maps in the same call; stop 45: without the window's own depths and own pixels as
        # maps, its square filters read from summed-area tables (jit._own_edge_in_box: the same maps; the
        # benchmark frame's 9 calls 2.5 against 2.0 ms)
        # stop 60: the points projected in the kernel (Camera.project's arithmetic, the same pixels; here only where
        # overshoot reads them), the own edge on the mask's box found by one OR a row (jit.occlusion_projected: the
        # same maps; the benchmark frame's occlusion stage 0.2 ms less, docs/speedo60.md)
        found, u0, v0, hidden, seen = jit.occlusion_projected(points, float(camera.fx), float(camera.fy),
                                                              float(camera.cx), float(camera.cy), pad, image, mask,
                                                              near_to, tolerance, _steps(reach), max(int(band), 0),
                                                              bool(supports), focal)  # fmt: skip
        if not found:
            raise InputError("occlusion: no point of the fruit projects into the image")
        h, w = hidden.shape
        own_w = mask[v0 : v0 + h, u0 : u0 + w].copy()
        over = (
            overshoot(
                own_w,
                depth[v0 : v0 + h, u0 : u0 + w],
                camera.project(points),
                points,
                u0,
                v0,
                tolerance,
                max(int(band), 1),
                int(eroded),
                focal,
            )
            if trim_own
            else (None, False)
        )
        return Occlusion._made(u0, v0, hidden, camera.width, camera.height, own_w, seen, *over)
    uv = camera.project(points)
    with np.errstate(invalid="ignore"):  # a non-finite point's pixel is no pixel of the image (not numpy's warning)
        col = np.rint(uv[:, 0]).astype(np.intp)
        row = np.rint(uv[:, 1]).astype(np.intp)
    ok = (col >= 0) & (col < camera.width) & (row >= 0) & (row < camera.height)
    if not ok.any():
        raise InputError("occlusion: no point of the fruit projects into the image")
    col, row, z = col[ok], row[ok], points[ok, 2]
    span_u, span_v = int(col.max() - col.min()) + pad, int(row.max() - row.min()) + pad
    u0, v0 = max(int(col.min()) - span_u, 0), max(int(row.min()) - span_v, 0)
    u1, v1 = min(int(col.max()) + span_u + 1, camera.width), min(int(row.max()) + span_v + 1, camera.height)
    h, w = v1 - v0, u1 - u0
    flat = np.full(h * w, np.inf)
    np.minimum.at(flat, (row - v0) * w + (col - u0), z)
    own_z = flat.reshape(h, w)
    seen_own = np.isfinite(own_z)
    # The fruit's depth beside every pixel: that of the nearest of its points' pixels.
    z_ref = np.take(own_z.ravel(), nearest_index(~seen_own))  # the nearest point pixel's
    own = mask[v0:v1, u0:u1] | seen_own
    d = np.asarray(depth[v0:v1, u0:u1], dtype=np.float64)
    valid = np.isfinite(d) & (d > 0) & ~own
    d = np.where(valid, d, np.nan)
    if reach > 0 and valid.any() and not (valid | own).all():  # pixels without depth take a neighbour's
        d = _fill(d, valid, own, reach)
    with np.errstate(invalid="ignore"):
        behind = d >= z_ref + tolerance  # NaN compares False: no depth is not "seen behind"
        near = d < z_ref + tolerance
    hidden = near & ~own
    if others is not None:
        hidden |= np.asarray(others[v0:v1, u0:u1], dtype=bool) & ~behind & ~own
    hidden = own_edge(hidden, own, own_z, d, others[v0:v1, u0:u1] if others is not None else None, tolerance, band,
                      bool(supports), focal)  # fmt: skip
    own_w = mask[v0:v1, u0:u1].copy()
    over = (
        overshoot(own_w, depth[v0:v1, u0:u1], uv, points, u0, v0, tolerance, max(int(band), 1), int(eroded), focal)
        if trim_own
        else (None, False)
    )
    return Occlusion(
        u0, v0, hidden, camera.width, camera.height, own=own_w, depth=d, overshoot=over[0], seen_past=over[1]
    )


def overshoot(own: np.ndarray, depth: np.ndarray, uv: np.ndarray, points: np.ndarray, u0: int, v0: int,
              tolerance: float, reach: int, eroded: int = 0,
              focal: float = 0.0) -> tuple[np.ndarray | None, bool]:  # fmt: skip
    """The pixels ((h, w) bool) of the fruit's mask ``own`` (a window at ``(u0, v0)``) that overshoot the fruit
    (None: none found), and whether they are where a time-of-flight camera saw past the fruit.

    Masks drawn by people or models overshoot a fruit by a few pixels (issue 18, point 4), and the completion reads
    the fruit's width from its outline (:func:`with_own`), then its depth from that width. Beyond the fruit's
    points (``uv``: their pixels, image coordinates) the mask's band holds, by camera family:

    - time of flight: mostly no depth (``depth`` 0 or NaN), the rim the camera invalidates (grazing and mixed
      pixels; the shared Azure Kinect frames lose the outer 13 % of every sphere's radius), and the background
      where the depth camera sees past the edge (its baseline to the colour camera) or the mask overshoots. Where
      the camera saw past the fruit (a pixel farther than the fruit's front plus half the mask's width: behind
      the outline of a round fruit that wide; and not joined to its points by a continuous surface, stop 44)
      nearly all round the outline, the mask beyond the fruit's edge there is the overshoot (:func:`_seen_past`,
      ``focal``: the camera's focal length in pixels; stop 43, docs/treeover43.md); seen past over part of it and a
      support or neighbour at the fruit's depth over the rest, the overshoot read on opposite sides seen past is
      taken off all round (:func:`_seen_past_in_part`, stop 56, docs/overshoot56.md); elsewhere the mask is the
      only measure of the fruit's width, and nothing is taken off;
    - active stereo: mostly the fruit's own depth spread beyond its silhouette by the correlation window (the
      least depth the window holds, ``synthetic.sensors``' ``fatten_px``): nearer than the nearest of its points'
      pixels (its rim beside the band, where the surface recedes) but not by ``tolerance`` nearer than the nearest
      of its points' depths within ``reach`` pixels. Extraction dropped it: the band is the camera's and the
      mask's, not the fruit's, and its pixels are the overshoot, peeled from the mask's border inwards (a pixel
      inside the points' region stays), all but those seen clearly in front of the fruit (an occluder an amodal
      mask was drawn over).

    Which of the two: whether the band holds such a spread depth on more pixels than it holds none (a per-view
    majority, no constant of a sensor; a time-of-flight camera's mixed pixels and the rim pixels extraction
    dropped lie behind the rim beside them, not in front). ``eroded``: the mask's border extraction never takes
    points from (its ``erode_px``): that much of the band next to what is kept stays the fruit's (a mask drawn
    right loses nothing).
    """
    h, w = own.shape
    col = np.rint(uv[:, 0]).astype(np.intp) - u0
    row = np.rint(uv[:, 1]).astype(np.intp) - v0
    ok = (col >= 0) & (col < w) & (row >= 0) & (row < h)
    if not ok.any():
        return None, False
    own = np.ascontiguousarray(own, dtype=bool)
    own_z, band, ahead = np.empty((h, w)), np.empty((h, w), bool), np.empty((h, w), bool)
    # the maps in one compiled pass where numba is (issue 19, stop 44: scipy's 17 x 17 minimum filter over the
    # window and a dozen numpy passes were most of this function's time; the same values, bit for bit)
    maps = _overshoot_band if (jit := compiled()) is None else jit.overshoot_band
    n_band, spread, n_beyond = maps(own, depth, row[ok], col[ok], np.ascontiguousarray(points[ok, 2]), float(tolerance),
                                    int(reach), own_z, band, ahead)  # fmt: skip
    if not n_band:
        return None, False
    seen = np.isfinite(own_z)
    if spread <= n_beyond - n_band:  # no more than hold no depth: not a spread edge
        d = np.asarray(depth, dtype=np.float64)
        past = _seen_past(own, seen, d, band, points, focal, eroded, tolerance, ahead=ahead) if focal > 0 else None
        return past, past is not None
    drop = own & ~seen & ~ahead  # all but what lies clearly in front
    # peeled from the mask's border inwards: what a mask overshoots lies at its border
    if jit is None:
        drop = _peel(own, drop)
    else:
        peeled = np.empty((h, w), bool)
        jit.peel(own, drop, peeled)
        drop = peeled
    if eroded > 0:  # the ring extraction never took points from is the fruit's as far as the points say
        drop &= ~square_filter(own & ~drop, eroded)
    return drop, False


def _overshoot_band(own: np.ndarray, depth: np.ndarray, row: np.ndarray, col: np.ndarray, z: np.ndarray,
                    tolerance: float, reach: int, own_z: np.ndarray, band: np.ndarray,
                    ahead: np.ndarray) -> tuple[int, int, int]:  # fmt: skip
    """The numpy twin of :func:`symfruit.core._jit.overshoot_band` (:func:`overshoot`'s maps, into ``own_z``,
    ``band`` and ``ahead``; the band's pixel count, the spread's and the mask's pixels beyond the points')."""
    h, w = own.shape
    flat = np.full(h * w, np.inf)
    np.minimum.at(flat, row * w + col, z)
    own_z[...] = flat.reshape(h, w)
    seen = np.isfinite(own_z)
    d = np.asarray(depth, dtype=np.float64)
    beyond = own & ~seen
    with np.errstate(invalid="ignore"):
        band[...] = beyond & np.isfinite(d) & (d > 0)
    ahead[...] = False
    if not band.any():
        return 0, 0, int(np.count_nonzero(beyond))
    # the nearest point pixel's depth, over the box of the mask and the points' pixels alone
    b0, b1, a0, a1 = mask_box(own | seen)  # type: ignore[misc]
    near = np.take(own_z[b0:b1, a0:a1].ravel(), nearest_index(~seen[b0:b1, a0:a1]))
    z_ref = near.reshape(b1 - b0, a1 - a0)[band[b0:b1, a0:a1]]
    # the nearest of the fruit's own depths within ``reach`` pixels: a spread depth is the least the correlation
    # window holds, nearer than the rim's own (as :func:`own_edge` reads it)
    z_near = ndimage.minimum_filter(own_z, size=2 * reach + 1, mode="constant", cval=np.inf)[band]
    zb = d[band]
    is_ahead = zb < np.minimum(z_ref, z_near) - tolerance  # clearly in front of the fruit: an occluder
    ahead[band] = is_ahead
    spread = np.count_nonzero(~is_ahead & (zb < z_ref))  # the fruit's own depth, nearer than its rim beside it
    return len(zb), int(spread), int(np.count_nonzero(beyond))


def _peel(own: np.ndarray, drop: np.ndarray) -> np.ndarray:
    """The numpy twin of :func:`symfruit.core._jit.peel`: the pixels of ``drop`` joined to its pixels on the mask's
    border (a pixel of their 3 x 3 square outside ``own`` or the window) through ``drop``."""
    edge = drop & ~square_filter(own, 1, every=True)
    return np.asarray(ndimage.binary_propagation(edge, structure=np.ones((3, 3), bool), mask=drop))


#: Angular sectors a time-of-flight view's edge is found in (:func:`overshoot`): a sector spans 2-4 px of the
#: outline of a fruit 40-70 px across (issue 18's apples at 1.2-2 m), the depth pixels' footprint.
SECTORS = 48

#: The least share of its star polygon about the points' centroid (each sector's farthest mask pixel) a mask must
#: fill for :func:`_seen_past` to read it by sectors: a silhouette every ray from the centroid leaves once, as a
#: round fruit's. Every ellipse up to 3:1, 16-200 px across, fills 0.91 or more (0.97 up to 3:2); a curved fruit
#: (a banana seen from the side) less, and there "the edge in each direction" is not one radius.
STAR_SHARE = 0.9


def _seen_past(own: np.ndarray, seen: np.ndarray, d: np.ndarray, band: np.ndarray, points: np.ndarray,
               focal: float, eroded: int, tolerance: float, sectors: int = SECTORS, *,
               ahead: np.ndarray | None = None) -> np.ndarray | None:  # fmt: skip
    """:func:`overshoot` on a time-of-flight camera's view: the mask's pixels beyond the fruit's edge where the
    camera saw past the fruit nearly all round it (None: not so, or nothing beyond).

    Seen past: a pixel of the mask's band (``band``) farther than the fruit's front plus half the mask's width (the
    depth of a round fruit's outline were it as wide as the mask) plus ``tolerance``, and not joined to the fruit's
    points by a continuous surface (:func:`_joined`, stop 44, docs/guard44.md): a fruit's own surface receding
    beyond extraction's slab (a banana's far end, a pear's body seen end-on past its neck) steps in depth by what a
    surface can per pixel, the background seen past a silhouette lies a step behind it. About the points' centroid,
    in each of ``sectors`` angular sectors: the farthest point pixel (the fruit's last depth) and the nearest pixel
    seen past. Between the two the camera returned nothing: the mixed pixels a time-of-flight camera invalidates on
    both sides of an edge (AK-DEPTH, ``symfruit.synthetic.sensors.SOURCES``), so the edge is taken halfway (where
    the camera also loses the grazing rim inside the edge, halfway lies inside it by half the difference:
    docs/treeover43.md); but where the mask's band holds an occluder between the two (``ahead``: its pixels clearly
    in front of the fruit, from :func:`overshoot`'s maps), the gap is the occluder's, not the fruit's edge: the
    fruit may reach under it as far as the background less the mixed pixels outside an edge (half the gap of the
    sectors with no occluder between; stop 45, docs/hidden45.md: halfway across a leaf cut a mostly hidden apple's
    mask drawn over it towards the visible crescent's width). A sector where nothing was seen past takes its
    neighbours' edge (periodic interpolation). Nearly all round: no third of the outline without a sector seen
    past. A mask an annotator or a model drew too wide overshoots all round; a depth camera seeing past one side of
    a fruit (its baseline to the colour camera, a registration a few pixels off) is one side, and the mask there
    is kept (the shared lab spheres leave 180-315 degrees without: docs/treeover43.md). Short of nearly all round,
    :func:`_seen_past_in_part` reads what opposite sides seen past say (stop 56). A pixel joined to the
    points is never cut. :data:`STAR_SHARE`: the mask must fill that share of its star polygon about the centroid
    (stop 43's gate for curved fruit, before the surface test).
    """
    front = float(points[:, 2].min())
    half = 0.5 * np.sqrt(4.0 * np.count_nonzero(own) / np.pi) * front / focal  # the mask's half-width, metres
    past = band & (np.where(band, d, 0.0) > front + half + tolerance)
    if not past.any():
        return None
    joined = _joined(own, seen, d, focal, tolerance)
    past &= ~joined
    if not past.any():
        return None
    rs, cs = np.nonzero(seen)
    r0, c0 = rs.mean(), cs.mean()
    vv, uu = np.nonzero(own)  # past lies in the mask's band
    ang = np.arctan2(vv - r0, uu - c0)
    sec = np.minimum(((ang + np.pi) / (2 * np.pi) * sectors).astype(np.intp), sectors - 1)
    rad = np.hypot(vv - r0, uu - c0)
    is_joined, is_past, is_seen = joined[vv, uu], past[vv, uu], seen[vv, uu]
    if STAR_SHARE > 0:
        reach = np.zeros(sectors)  # the star polygon of the mask: its farthest pixel (its outer side) in each sector
        np.maximum.at(reach, sec, rad + 0.5)
        if np.count_nonzero(own) < STAR_SHARE * 0.5 * float(reach @ reach) * (2 * np.pi / sectors):
            return None  # not star-shaped about the centroid: sectors do not give one edge per direction
    last = np.full(sectors, -np.inf)
    np.maximum.at(last, sec[is_seen], rad[is_seen])
    first = np.full(sectors, np.inf)
    np.minimum.at(first, sec[is_past], rad[is_past])
    held = np.isfinite(last)
    both = held & np.isfinite(first) & (first > last)
    # nearly all round: no third of the outline without a sector seen past
    at = np.flatnonzero(both)
    if len(at) < 2 or np.diff(np.r_[at, at[0] + sectors]).max() > sectors // 3:
        # stop 56: seen past over part of the outline, a support or neighbour at the fruit's own depth over the rest
        return _seen_past_in_part(own, band, past, ahead, is_joined, sec, rad, vv, uu, last, first, both,
                                  eroded)  # fmt: skip
    centre = (np.arange(sectors) + 0.5) * (2 * np.pi / sectors) - np.pi
    with np.errstate(invalid="ignore"):  # inf - inf: NaN where not ``both``, never read
        halfway = 0.5 * (last + first)
    if ahead is not None and (behind := both & _occluder_between(ahead[vv, uu], sec, rad, last, first)).any():
        # an occluder between the fruit's last depth and the background (stop 45): the fruit may reach under it up
        # to the background, less the mixed pixels the camera invalidates outside an edge, read in the sectors
        # where nothing lies between (half their gap); with none such, the gap's outer end
        free = both & ~behind
        ring = 0.5 * float(np.median(first[free] - last[free])) if free.any() else 0.0
        halfway[behind] = np.maximum(first[behind] - ring, halfway[behind])
    edge = np.interp(centre, centre[both], halfway[both], period=2 * np.pi)
    drop = np.zeros(own.shape, bool)
    out = ~is_joined & (rad > edge[sec])
    drop[vv[out], uu[out]] = True
    if eroded > 0:  # the ring extraction never took points from is the fruit's as far as the points say
        drop &= ~square_filter(own & ~drop, eroded)
    return drop if drop.any() else None


#: The least number of opposite pairs of sectors both seen past :func:`_seen_past_in_part` reads an overshoot from
#: (as :func:`_seen_past` needs two sectors seen past).
PAIRS = 2

#: The least overshoot (pixels, of the mask's outline beyond the fruit's edge read on opposite sides) that
#: :func:`_seen_past_in_part` takes off: a pixel's rounding of the mask's farthest pixel and of the edge.
LEAST_OVERSHOOT_PX = 1.0


def _seen_past_in_part(own: np.ndarray, band: np.ndarray, past: np.ndarray, ahead: np.ndarray | None,
                       is_joined: np.ndarray, sec: np.ndarray, rad: np.ndarray, vv: np.ndarray, uu: np.ndarray,
                       last: np.ndarray, first: np.ndarray, both: np.ndarray,
                       eroded: int) -> np.ndarray | None:  # fmt: skip
    """:func:`_seen_past` where the camera saw past the fruit over part of its outline only, and a support or a
    neighbour at the fruit's own depth runs on over the rest (stop 56, docs/overshoot56.md): the mask's pixels
    beyond the fruit's edge, that edge read as the mask's outline less one overshoot all round, and never less
    than a sector's own pixels seen past where it has them (None: not so).

    Where the camera saw past, the overshoot of a sector is read as the mask's pixels seen past along the ray (from
    the first pixel seen past to the mask's farthest, its outline there): the mask's overshoot less the mixed pixels
    the camera invalidates outside the fruit's edge, so never more than the overshoot. Not halfway between the last
    depth and the first pixel seen past, as :func:`_seen_past` reads the edge all round: a real time-of-flight
    camera loses far more of the rim inside the edge than outside (the Azure Kinect frames a quarter of every
    sphere's radius), and halfway read 2-3 px more than the mask's pixels seen past on the same sectors there (a
    200 mm sphere's mask drawn 2 px wide cut to 15 mm under its diameter). Read on one side alone it is the
    depth's displacement against colour as much as the mask's (a registration a few pixels off, a time-of-flight
    camera's parallax: the background it sees beside the fruit lands inside the fruit's colour outline on one side,
    its shadow without depth on the other; the real Azure Kinect frames see past 2-12 px inside masks drawn right).
    On two opposite sectors a displacement adds to one as much as it takes from the other, so their mean is the
    mask's own. Where a support or a neighbour at the fruit's depth runs on past the outline nothing can be read:
    the overshoot there is taken as the opposite pairs' median, the one assumption a pen or a model's dilation,
    about as wide all round, allows. Taken only where (a) every third of the outline holds a sector seen past or one
    whose band holds depth not seen past and not clearly in front (``ahead``): at the fruit's own depth, or joined
    to its points by a continuous surface. The arcs without either are where the mask is the only measure of the
    fruit, as :func:`_seen_past` leaves them; (b) at least :data:`PAIRS` opposite pairs of sectors are both seen
    past; (c) the overshoot is at least :data:`LEAST_OVERSHOOT_PX`. A pixel joined to the points (``is_joined``: the
    fruit's own surface, or a support meeting it at its depth) is never cut, as in :func:`_seen_past`.
    """
    sectors = len(last)
    if sectors % 2:  # no opposite sectors
        return None
    level = band & ~past  # the band's depth not seen past: at the fruit's own, or joined to its points
    if ahead is not None:
        level &= ~ahead
    support = np.zeros(sectors, bool)
    support[sec[level[vv, uu]]] = True
    at = np.flatnonzero(both | support)
    if len(at) < 2 or np.diff(np.r_[at, at[0] + sectors]).max() > sectors // 3:
        return None
    reach = np.zeros(sectors)  # the mask's outline: its farthest pixel in each sector
    np.maximum.at(reach, sec, rad + 0.5)
    half = sectors // 2
    pairs = both[:half] & both[half:]
    if np.count_nonzero(pairs) < PAIRS:
        return None
    over = reach - first + 0.5  # the mask's pixels seen past along the ray (read only where ``both``)
    shift_free = 0.5 * (over[:half] + over[half:])[pairs]
    by = float(np.median(shift_free))
    if not by >= LEAST_OVERSHOOT_PX:
        return None
    # where seen past, never more than the sector's own pixels seen past: a mask displaced against the depth holds
    # less than ``by`` on one side, and its outline there lies nearer the edge by as much
    cut = np.where(both, np.minimum(by, over), by)
    drop = np.zeros(own.shape, bool)
    out = ~is_joined & (rad > (reach - cut)[sec])
    drop[vv[out], uu[out]] = True
    if eroded > 0:  # the ring extraction never took points from is the fruit's as far as the points say
        drop &= ~square_filter(own & ~drop, eroded)
    return drop if drop.any() else None


def _occluder_between(is_ahead: np.ndarray, sec: np.ndarray, rad: np.ndarray, last: np.ndarray,
                      first: np.ndarray) -> np.ndarray:  # fmt: skip
    """(sectors,) bool: the sectors holding a mask pixel clearly in front of the fruit (``is_ahead``, per pixel of
    the mask, with its sector ``sec`` and radius ``rad`` about the points' centroid) beyond the fruit's farthest
    point pixel (``last``) and short of the nearest pixel seen past (``first``): an occluder covering the span
    where the fruit's edge lies, so the gap there is not the mixed pixels of the fruit's own edge."""
    hit = is_ahead & (rad > last[sec]) & (rad < first[sec])
    out = np.zeros(len(last), bool)
    out[sec[hit]] = True
    return out


#: The steepest a fruit's own surface is read at by a time-of-flight camera, as depth per pixel over the pixel's
#: footprint (the tangent of the angle between the surface and the image plane): 4.9 at ``|cos| = 0.2`` between ray
#: and normal, where ``symfruit.synthetic.sensors`` has half the pixels return nothing (its ``grazing`` judgement).
SLOPE = 5.0


def _joined(own: np.ndarray, seen: np.ndarray, d: np.ndarray, focal: float, tolerance: float) -> np.ndarray:
    """The pixels of the mask ``own`` with depth joined to the fruit's points' pixels (``seen``) by a continuous
    surface: reached from them through pixels with depth, none farther than a neighbour with depth by more than a
    surface can step over a pixel (:data:`SLOPE` times the pixel's footprint at the nearer depth, plus
    ``tolerance`` for the noise). A fruit's own surface beyond extraction's slab (a banana's far end) is so joined;
    the background the camera saw past a silhouette is not: the first pixel of it beside the fruit, or beside a
    flying pixel between the two, lies a step farther (a neighbour with no depth joins nothing)."""
    box = mask_box(own | seen)
    out = np.zeros(own.shape, bool)
    if box is None:
        return out
    b0, b1, a0, a1 = box
    z = d[b0:b1, a0:a1]
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(z) & (z > 0)
    z = np.where(ok, z, np.inf)
    rows = z.copy()  # the least depth of the 3x3 neighbourhood: of three rows, then of three columns
    np.minimum(rows[1:], z[:-1], out=rows[1:])
    np.minimum(rows[:-1], z[1:], out=rows[:-1])
    nearer = rows.copy()
    np.minimum(nearer[:, 1:], rows[:, :-1], out=nearer[:, 1:])
    np.minimum(nearer[:, :-1], rows[:, 1:], out=nearer[:, :-1])
    with np.errstate(invalid="ignore"):
        step = z - nearer > tolerance + SLOPE * nearer / focal  # inf - inf: NaN, False
    mine = seen[b0:b1, a0:a1]
    way = (ok & ~step & own[b0:b1, a0:a1]) | mine
    labels, n = ndimage.label(way, structure=np.ones((3, 3), bool))
    keep = np.zeros(n + 1, bool)
    keep[labels[mine]] = True  # the pieces holding a point pixel (none is 0: ``mine`` lies in ``way``)
    out[b0:b1, a0:a1] = keep[labels]
    return out


def own_edge(
    hidden: np.ndarray,
    own: np.ndarray,
    own_z: np.ndarray,
    depth: np.ndarray,
    others: np.ndarray | None,
    tolerance: float,
    band: int,
    supports: bool = False,
    focal: float = 0.0,
) -> np.ndarray:
    """``hidden`` without the fruit's own edge spread beyond its mask by the sensor (active stereo's fattening) and,
    with ``supports``, without the band beside the fruit of a surface that meets it at its own depth (a support).

    An active-stereo camera gives the pixels a few beyond a foreground's silhouette the foreground's depth (the
    least depth its correlation window holds: ``synthetic.sensors``' ``fatten_px``), so beside a fruit with nothing
    in front of it :func:`occlusion` found a thin ring "at the fruit's depth", and every outline pixel within a
    completion's ``occluded_px`` of it read as cut (stop 40, docs/occl40.md: the contour share below 0.1 on 90 % of
    the D435 model's views with nothing in front). Told by physics, not by the sensor: a hidden pixel is the fruit's
    own edge, not something that may hide it, when

    - it lies within ``band`` pixels of the fruit's own pixels (``own``: its mask and its points' pixels);
    - it is not another fruit's (``others``);
    - something not hiding the fruit (background clearly behind it, or no depth) lies within ``band + 1`` pixels of
      it, and no hidden pixel farther than ``band`` from the fruit lies within ``band`` of it: the band ends there
      (a leaf or a support at the fruit's depth wider than the band does not). With ``supports`` (and ``focal``,
      the camera's focal length in pixels) this is not asked of the pixels reached in more steps from the fruit than
      :func:`support_reach` of their depth: a surface that runs on from the fruit's outline at the fruit's own depth
      (a board or a branch it rests on, the face of the box it stands on) hides only the part of the fruit deeper
      than itself, and a round fruit ends within that reach of where the surface meets it (stop 56,
      docs/support56.md). An occluder lies in front of the fruit's edge by a step (the next condition), and a leaf
      lying on the fruit's face meets it near its front, where the reach is its whole radius: both stay hidden;
    - it joins the fruit's own pixels through such pixels (not past a gap);
    - its depth is not clearly nearer (by ``tolerance``) than the nearest of the fruit's own depths (``own_z``,
      +inf where none) within ``2 band`` pixels: a spread depth is the least of the foreground's nearby, never in
      front of it (a leaf 3 cm in front is).

    Numpy and the compiled square filter, over the box of the own pixels grown by ``2 band + 1``; a window with no
    hidden pixel within ``band`` of the fruit returns ``hidden`` itself. Where numba is, in one compiled pass
    (:func:`symfruit.core._jit.own_edge`: the same pixels, bit for bit; its eight dilation passes and scipy's minimum
    filter were most of the occlusion maps' time; issue 19, stop 41), and :func:`occlusion` runs it in the same
    kernel as the maps (:func:`symfruit.core._jit.occlusion_projected`).
    """
    if band <= 0 or not hidden.any():
        return hidden
    supports = bool(supports)
    shape = np.shape(hidden)
    same = np.shape(own) == np.shape(own_z) == np.shape(depth) == shape
    same = same and (others is None or np.shape(others) == shape)
    if (jit := compiled()) is not None and same and len(shape) == 2:
        out = np.array(hidden, dtype=bool, order="C")  # the compiled twin clears in place (the same pixels)
        near_to = np.zeros((0, 0), bool) if others is None else np.asarray(others, dtype=bool)
        z = np.asarray(own_z, dtype=np.float64)
        found = jit.own_edge(out, np.asarray(own, dtype=bool), z, np.asarray(depth, dtype=np.float64), near_to,
                             float(tolerance), int(band), supports, float(focal))  # fmt: skip
        return out if found else hidden
    box = mask_box(own)
    if box is None:
        return hidden
    h, w = hidden.shape
    g = 2 * band + 1
    b0, b1, a0, a1 = max(box[0] - g, 0), min(box[1] + g, h), max(box[2] - g, 0), min(box[3] + g, w)
    hid, mine = hidden[b0:b1, a0:a1], own[b0:b1, a0:a1]
    near = square_filter(mine, band)
    cand = hid & near & ~mine
    if others is not None:
        cand &= ~np.asarray(others[b0:b1, a0:a1], dtype=bool)
    if not cand.any():
        return hidden
    # the band ends: something not hiding the fruit lies just beyond, and nothing hidden runs on past it; with
    # ``supports`` a band that runs on is cleared too, past the reach the fruit may continue behind it
    ends = square_filter(~hid & ~mine, band + 1) & ~square_filter(hid & ~near, band)
    if not supports:
        cand &= ends
        if not cand.any():
            return hidden
    zmin = ndimage.minimum_filter(own_z[b0:b1, a0:a1], size=2 * band + 1, mode="constant", cval=np.inf)
    d = np.asarray(depth[b0:b1, a0:a1], dtype=np.float64)
    with np.errstate(invalid="ignore"):
        cand &= d >= zmin - tolerance  # NaN: not the fruit's
    if not cand.any():
        return hidden
    # the band runs on from the fruit's own pixels: what lies at the fruit's depth past a gap is something else (the
    # step each pixel is reached at: a support's pixel is cleared past its reach alone)
    step = np.zeros(cand.shape, np.intp)
    reached = np.zeros(cand.shape, bool)
    edge = mine
    for i in range(1, band + 1):
        edge = ndimage.binary_dilation(edge, structure=np.ones((3, 3), bool)) & cand & ~reached
        if not edge.any():
            break
        step[edge] = i
        reached |= edge
    reach = np.zeros(cand.shape)
    front = float(np.min(own_z))
    r_px = support_radius(box)
    r_m = r_px * front / focal if focal > 0.0 else 0.0
    lone = reached & ~ends
    if supports and 0.0 < r_m < np.inf and lone.any():
        reach[lone] = support_reach(d[lone], front, r_px, r_m)
    clear = reached & (reach < step)
    if not clear.any():
        return hidden
    out = hidden.copy()
    out[b0:b1, a0:a1] &= ~clear
    return out


def support_radius(box: tuple[int, int, int, int]) -> float:
    """Pixels: the radius :func:`support_reach` reads for a fruit whose own pixels' box is ``box`` (rows ``r0:r1``,
    columns ``c0:c1``): half its larger side. A fruit cut by a leaf along one axis keeps its radius along the other
    (half the mean side was short of it, and so was the reach: stop 57, docs/shift57.md); an elongated fruit gets
    its larger half-length, which only keeps more of a support's band hidden (the rule before stop 56 kept all of
    it)."""
    return 0.5 * max(box[1] - box[0], box[3] - box[2])


def support_reach(depth: np.ndarray, front: float, r_px: float, r_m: float) -> np.ndarray:
    """Pixels: how far past its outline a round fruit may still continue behind a surface that meets it at seen depth
    ``depth`` (metres), the fruit's front at ``front`` and its radius ``r_px`` pixels, ``r_m`` metres.

    What lies behind a surface at depth ``d`` is the fruit's part deeper than ``d``: of a sphere, the ring outside the
    circle where its depth is ``d``, ``k = (d - front) / r`` of the radius behind its front, radius
    ``r sqrt(1 - (1 - k)^2)``. So the fruit's outline may lie at most ``r (1 - sqrt(k (2 - k)))`` past where the
    surface meets it: a surface at the fruit's front (``k = 0``, a leaf lying on its face) may hide it to its full
    radius, one at the depth of its outline (``k = 1``) hides nothing. (The real 66 mm sphere standing on a box, the
    box's face meeting it 0.44-0.5 of a radius behind its front: 13-17 % of the radius, 4-5 mm; docs/support56.md.)
    ``k`` is clipped to [0, 1]."""
    k = np.minimum(np.maximum((depth - front) / r_m, 0.0), 1.0)
    return r_px * (1.0 - np.sqrt(k * (2.0 - k)))


def _fill(d: np.ndarray, valid: np.ndarray, own: np.ndarray, reach: int) -> np.ndarray:
    """``d`` with each pixel that is neither ``valid`` nor ``own`` given the value of the nearest ``valid`` pixel
    within ``reach`` pixels, the one ``ndimage.distance_transform_edt(~valid, return_indices=True)`` picks.

    Only the pixels to fill look for it, through the offsets within ``reach`` nearest first: most dropouts have
    depth a pixel away, and a feature transform of the window (most of which has depth) costs many times more.
    Among equally near pixels scipy's transform picks the one of least column, then least row offset; so
    do the offsets' order here (checked against the transform on random dropouts, ties included).

    The pixels to fill read their offsets by flat index into the valid map padded by ``reach`` (nothing valid in
    the pad), all of them the four offsets a pixel away at once, then those still without depth (a third on the
    benchmark frame) the rest at once, each taking its first valid one: a loop over the offsets cost some ten
    numpy calls each.
    """
    h, w = d.shape
    rows, cols = np.nonzero(~(valid | own))
    out = d.copy()
    if not len(rows):
        return out
    pw = w + 2 * reach
    padded = np.zeros((h + 2 * reach, pw), dtype=bool)
    padded[reach : reach + h, reach : reach + w] = valid
    offsets = _offsets(reach)
    steps = np.array([dr * pw + dc for dr, dc in offsets], dtype=np.intp)
    todo = (rows + reach) * pw + (cols + reach)  # padded flat index of each pixel to fill
    dst, src = [], []
    for group in (steps[:4], steps[4:]):  # the offsets a pixel away (every reach has four), then the rest
        if not len(todo) or not len(group):
            break
        at = todo[:, None] + group[None, :]  # (m, offsets), nearest first
        ok = np.take(padded.ravel(), at)
        first = ok.argmax(axis=1)
        pick = np.arange(len(todo))
        found = ok[pick, first]
        dst.append(todo[found])
        src.append(at[pick, first][found])
        todo = todo[~found]
    dst_i, src_i = np.concatenate(dst), np.concatenate(src)
    # padded flat indices back to the window's
    src_w = (src_i // pw - reach) * w + src_i % pw - reach
    out.ravel()[(dst_i // pw - reach) * w + dst_i % pw - reach] = np.take(d.ravel(), src_w)
    return out


#: The widest ``reach``, ``band`` and ``eroded`` :func:`occlusion` takes, pixels: the settings' bound on
#: ``occlusion.reach_px`` and ``extract.erode_px`` (:data:`symfruit.extract.MAX_RADIUS_PX`). ``reach`` makes a
#: table of every offset within it, ``(2 reach + 1)^2`` of them: 10**9 asked for exbibytes.
MAX_OCCLUSION_PX = 50


def _check_parameters(
    tolerance: object, reach: object, pad: object, band: object, eroded: object
) -> tuple[float, int, int, int, int]:
    """Refuse :func:`occlusion`'s parameters it cannot use, naming them (before: NaN and a negative ``reach`` were
    taken in silence, a ``reach`` of 10**9 was numpy's MemoryError and a ``band`` of 2.5 a TypeError from slicing);
    ``(tolerance, reach, pad, band, eroded)`` as a float and ints."""
    if (
        isinstance(tolerance, bool)
        or not isinstance(tolerance, int | float | np.integer | np.floating)
        or not (-1.0 <= float(tolerance) <= 1.0)
    ):  # NaN fails the range too
        raise InputError(f"occlusion: tolerance must be a number of metres in [-1, 1], got {tolerance!r:.40}")
    for name, value, most in (("reach", reach, MAX_OCCLUSION_PX), ("pad", pad, MAX_IMAGE_SIDE),
                              ("band", band, MAX_OCCLUSION_PX), ("eroded", eroded, MAX_OCCLUSION_PX)):  # fmt: skip
        if isinstance(value, bool) or not isinstance(value, int | np.integer) or not 0 <= value <= most:
            raise InputError(f"occlusion: {name} must be a whole number of pixels from 0 to {most}, got "
                             f"{value!r:.40}")  # fmt: skip
    return float(tolerance), int(reach), int(pad), int(band), int(eroded)  # type: ignore[call-overload]


def _offsets(reach: int) -> list[tuple[int, int]]:
    """``(dr, dc)`` within ``reach`` (Euclidean, not 0), by distance, then column offset, then row offset."""
    found = _OFFSETS.get(reach)
    if found is None:
        span = range(-reach, reach + 1)
        near = [(dr, dc) for dr in span for dc in span if 0 < dr * dr + dc * dc <= reach * reach]
        found = sorted(near, key=lambda o: (o[0] ** 2 + o[1] ** 2, o[1], o[0]))
        _OFFSETS[reach] = found
    return found


_OFFSETS: dict[int, list[tuple[int, int]]] = {}


def _steps(reach: int) -> np.ndarray:
    """(k, 2) int64 :func:`_offsets` of ``reach`` as an array (none for 0), made once per reach (the kernel reads it,
    never writes it)."""
    found = _STEPS.get(reach)
    if found is None:
        found = np.array(_offsets(reach) if reach > 0 else [], dtype=np.int64).reshape(-1, 2)
        _STEPS[reach] = found
    return found


_STEPS: dict[int, np.ndarray] = {}


def open_square(mask: np.ndarray, size: int) -> np.ndarray:
    """``scipy.ndimage.binary_opening`` of a bool image by a ``size x size`` square (odd ``size``; outside
    the image is background), as separable minimum and maximum filters: the same pixels in a sixth of the
    time."""
    eroded = ndimage.minimum_filter(mask, size=size, mode="constant", cval=False)
    return ndimage.maximum_filter(eroded, size=size, mode="constant", cval=False)


def with_own(region: Silhouette, occ: Occlusion, *, trimmed: bool = False) -> Silhouette:
    """``region`` joined with the fruit's own pixels (:attr:`Occlusion.own`), in a window holding both;
    ``trimmed``: but those the mask overshoots the fruit by (:attr:`Occlusion.overshoot`)."""
    own = occ.own
    if trimmed and own is not None and occ.overshoot is not None:
        own = own & ~occ.overshoot
    if own is None or (own_box := mask_box(own)) is None:
        return region
    b0, b1, a0, a1 = own_box
    h, w = region.mask.shape
    u0, v0 = min(region.u0, occ.u0 + a0), min(region.v0, occ.v0 + b0)
    u1, v1 = max(region.u0 + w, occ.u0 + a1), max(region.v0 + h, occ.v0 + b1)
    mask = np.zeros((v1 - v0, u1 - u0), dtype=bool)
    mask[region.v0 - v0 : region.v0 - v0 + h, region.u0 - u0 : region.u0 - u0 + w] = region.mask
    oh, ow = own.shape
    r0, c0 = max(occ.v0, v0), max(occ.u0, u0)
    r1, c1 = min(occ.v0 + oh, v1), min(occ.u0 + ow, u1)
    mask[r0 - v0 : r1 - v0, c0 - u0 : c1 - u0] |= own[r0 - occ.v0 : r1 - occ.v0, c0 - occ.u0 : c1 - occ.u0]
    return Silhouette(u0, v0, mask, region.fill_radius)


def bridged(region: Silhouette, occ: Occlusion, *, radius: int = 2) -> Silhouette:
    """``region`` with the pixels hidden from the camera that lie between its parts: where the region is in two or
    more pieces (8-neighbours), a hidden pixel (:meth:`Occlusion.window`, within ``radius`` of one: an occluder's
    edge loses its mixed pixels) with region pixels on both sides of it in its row or in its column.

    A surface in front crossing a fruit (a twig, a leaf's midrib or strip) parts its seen silhouette in pieces; the
    fruit's silhouette runs on behind it, and a convex fruit's silhouette holds every pixel between two of its own
    in a row or a column. Left out, the pixels behind the strip read as outside the fruit: the silhouette's moment
    ellipse of two pieces is too narrow and too tall (issue 18, docs/strip57.md: a 123 mm real sphere under a 5 cm
    strip, the mask cut by it, read 106 x 125 mm) and the strip's edges as the fruit's outline. A region in one
    piece is returned as it is (a leaf cutting its side leaves no pixel between two of its own)."""
    mask = region.mask
    # the pieces counted by a compiled flood fill where numba is (the same answer as the labels'; stop 59, speedc59)
    if (jit := compiled()) is not None and mask.dtype == bool and mask.ndim == 2:
        if not jit.in_pieces(mask):
            return region
    elif ndimage.label(mask, np.ones((3, 3), bool))[1] < 2:
        return region
    down, up = np.logical_or.accumulate(mask, axis=0), np.logical_or.accumulate(mask[::-1], axis=0)[::-1]
    right, left = np.logical_or.accumulate(mask, axis=1), np.logical_or.accumulate(mask[:, ::-1], axis=1)[:, ::-1]
    fill = ((down & up) | (right & left)) & ~mask
    if not fill.any():
        return region
    fill &= occ.window(region, radius=radius)
    return Silhouette(region.u0, region.v0, mask | fill, region.fill_radius) if fill.any() else region
