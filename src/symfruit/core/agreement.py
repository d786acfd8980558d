"""How well a closed candidate shape explains what the camera saw.

One view shows a fruit's silhouette (the region its points cover) and the depth of its front surface.
A candidate completion that is a closed shape (sphere, ellipsoid, solid of revolution, anything with an
inside test) predicts both: cast the camera's rays through it. :func:`observe` takes the view apart once
(the pixel rays of a spread sample of the seen points with their depths, and rays of pixels just inside
and just outside the silhouette's edge); :func:`explain` then measures any candidate on the same rays,
vectorised over rays and march steps:

* ``depth``: robust RMS of seen minus predicted front depth (metres) on the sampled rays; a ray that
  misses the candidate counts as off by the candidate's depth range;
* ``outside``: share of the rays just outside the silhouette that hit the candidate (the camera saw
  background there);
* ``inside``: share of the rays just inside the silhouette that miss it (the camera saw fruit there).

A quadric candidate (sphere, ellipsoid: :class:`Quadric`) is met in closed form, the smaller root of
one quadratic per ray (:func:`intersect_quadric`); any other shape with an inside test is marched front to
back in fixed steps through its depth range, the first crossing refined by linear interpolation of the
inside function (:func:`march`), vectorised over rays and steps (no loop over rays).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

from .camera import Camera
from .kernels import compiled
from .occlusion import _NATIVE_FLOATS, _NO_DEPTH, Occlusion
from .points import as_points, row_norms
from .raster import (
    Silhouette,
    distance_maps,
    inner_distance,
    interior,
    mask_box,
    outer_distance,
    outline_cone,
    outline_cracks,
    pixel_count,
    silhouette_cone,
)

__all__ = ["Agreement", "Inside", "Observation", "Quadric", "explain", "intersect_quadric", "march", "observe"]

#: ``inside(x)`` for points ``x`` (..., 3), metres: positive inside the shape (a signed distance, or any
#: function with the same sign), shape ``x.shape[:-1]``.
Inside = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True, eq=False)
class Quadric:
    """The solid ellipsoid ``(x - centre)^T shape (x - centre) <= 1`` as an :data:`Inside` test
    (``1 - (x - centre)^T shape (x - centre)``) whose rays are met in closed form (:meth:`intersect`).

    Attributes
    ----------
    centre : (3,) float, metres
    shape : (3, 3) float, symmetric positive definite, metres^-2 (a sphere of radius ``r``: ``I / r^2``)
    """

    centre: np.ndarray
    shape: np.ndarray

    def __call__(self, x: np.ndarray) -> np.ndarray:
        d = np.asarray(x, dtype=np.float64) - self.centre
        return 1.0 - np.einsum("...i,ij,...j->...", d, self.shape, d)

    def intersect(self, rays: np.ndarray, z0: float, z1: float) -> tuple[np.ndarray, np.ndarray]:
        """:func:`intersect_quadric` of this quadric."""
        return intersect_quadric(self.centre, self.shape, rays, z0, z1)


def intersect_quadric(
    centre: np.ndarray, shape: np.ndarray, rays: np.ndarray, z0: float, z1: float
) -> tuple[np.ndarray, np.ndarray]:
    """First entry into the solid ellipsoid ``(x - centre)^T shape (x - centre) <= 1`` along rays ``x = z *
    ray`` for ``z`` in ``[z0, z1]``, in closed form: what :func:`march` approximates.

    Along a ray the quadric is ``a z^2 - 2 b z + c`` with ``a = ray^T S ray``, ``b = ray^T S centre`` and
    ``c = centre^T S centre - 1``; the ray is inside between the roots ``(b -+ sqrt(b^2 - a c)) / a``. A ray
    that only touches the surface (``b^2 = a c``) does not enter it.

    Parameters
    ----------
    centre : (3,) float, metres
    shape : (3, 3) float, symmetric positive definite
    rays : (m, 3) float, ``z = 1``
    z0, z1 : float, metres

    Returns
    -------
    hit : (m,) bool
        The ray is inside the solid somewhere in ``(z0, z1)``.
    depth : (m,) float, metres
        The entry depth (``z0`` where the ray is inside at ``z0``; NaN where there is no hit).

    Examples
    --------
    >>> hit, depth = intersect_quadric(np.array([0.0, 0.0, 0.5]), np.eye(3) / 0.04**2,
    ...                                np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 1.0]]), 0.3, 0.7)
    >>> hit.tolist(), np.round(depth, 6).tolist()
    ([True, False], [0.46, nan])
    """
    rays = np.asarray(rays, dtype=np.float64)
    sc = shape @ centre
    a = np.einsum("ni,ij,nj->n", rays, shape, rays)
    b = rays @ sc
    c = float(centre @ sc) - 1.0
    disc = b * b - a * c
    root = np.sqrt(np.maximum(disc, 0.0))
    near, far = (b - root) / a, (b + root) / a
    hit = (disc > 0) & (near < z1) & (far > z0)
    return hit, np.where(hit, np.maximum(near, z0), np.nan)


@dataclass(frozen=True)
class Observation:
    """A view reduced to what candidates are measured on.

    Attributes
    ----------
    rays : (m, 3) float
        Pixel rays (``z = 1``) of a spread sample of the seen points.
    depth : (m,) float, metres
        Their seen depths.
    rays_in, rays_out : tuple of (k, 3) float
        Per band distance, rays of pixels that far inside / outside the silhouette's edge.
    contour : float in [0, 1]
        How much of the seen region's edge is an occluding contour: the share of the points along it
        whose surface is seen at a grazing angle (normal within 60 degrees of perpendicular to the ray).
        A camera's view of a whole fruit gives about 1; a cloud cut by a plane (the paper's visibility
        rule) or by an occluder less, and there "outside the edge" is no evidence of background.
    cone, axis : (3, 3) float, (3,) float
        The silhouette's viewing cone and the ray through its centroid
        (:func:`~symfruit.core.raster.silhouette_cone`).
    interior : (k, 3) float, metres
        The sampled points at least ``edge`` pixels inside the silhouette (where depths are reliable).
    out_weights : tuple of (k,) float
        Per outside band, 1 for a ray beside a contour part of the edge, 0 beside a cut (no evidence of
        background there); None: every ray counts.
    out_depth : tuple of (k,) float, metres, optional
        Per outside band, the depth the camera saw at each ray's pixel where that pixel is hidden (an occluder
        there hides the fruit only behind it: a candidate nearer than it is contradicted); NaN elsewhere.
    cone_source : {"moments", "contour"}
        Whether :attr:`cone` is the seen region's moment ellipse's or the ellipse fitted to the contour part
        of the outline (see :func:`observe`).
    extent : (4,) float, pixels, optional
        With occlusion information: the pixel box the fruit can project into at most (``u_min, v_min, u_max,
        v_max``; :meth:`~symfruit.core.occlusion.Occlusion.extent`).
    hidden : (h, w) bool, optional
        The pixels of the region's window with a hidden pixel within 2 px (an outline crossing onto one is an
        occluder's edge), when given; :func:`observe` leaves it to :meth:`hidden_map`, which makes it from the
        occlusion information on first call (most views never read it).
    inner : (h, w) float, pixels, optional
        The region's distance map (``ndimage.distance_transform_edt(region.mask)``), for reuse: exact up to
        ``inner_reach`` pixels, +inf beyond.
    inner_reach : float, pixels
    """

    rays: np.ndarray
    depth: np.ndarray
    rays_in: tuple[np.ndarray, ...]
    rays_out: tuple[np.ndarray, ...]
    contour: float = 1.0
    cone: np.ndarray | None = None
    axis: np.ndarray | None = None
    interior: np.ndarray | None = None
    out_weights: tuple[np.ndarray, ...] | None = None
    out_depth: tuple[np.ndarray, ...] | None = None
    cone_source: str = "moments"
    extent: np.ndarray | None = None
    hidden: np.ndarray | None = None
    inner: np.ndarray | None = None
    inner_reach: float = float("inf")
    #: What :func:`explain` reads of every candidate's rays alike (:func:`_bands`), made once per observation.
    _made: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)
    #: ``(occlusion, region)`` that :meth:`hidden_map` makes :attr:`hidden` of, when not given.
    _hidden_of: tuple[Occlusion, Silhouette] | None = field(default=None, repr=False, compare=False)
    #: The bands as :func:`observe` made them, whole (:class:`_BandParts`): :func:`_bands` reads them instead of
    #: joining the per-band tuples again, while those are the ones they were sliced into.
    _parts: _BandParts | None = field(default=None, repr=False, compare=False)

    def hidden_map(self) -> np.ndarray | None:
        """:attr:`hidden`, or where :func:`observe` had occlusion information, the region's window pixels with a
        hidden pixel within 2 px (:meth:`~symfruit.core.occlusion.Occlusion.window`), made on first call (issue 19,
        seventeenth round: one view in nine read it, every view made it); None without either."""
        if self.hidden is not None or self._hidden_of is None:
            return self.hidden
        found = self._made.get("hidden")
        if found is None:
            occlusion, region = self._hidden_of
            found = self._made["hidden"] = occlusion.window(region, radius=2)
        return found


@dataclass(frozen=True)
class Agreement:
    """How a candidate explains the view (smaller is better for all three).

    Attributes
    ----------
    depth : float, metres
        Robust RMS depth misfit on the sampled rays.
    inside, outside : float in [0, 1]
        Shares of silhouette-band rays the candidate gets wrong (mean over the bands).
    """

    depth: float
    inside: float
    outside: float


def observe(
    points: np.ndarray,
    region: Silhouette,
    camera: Camera,
    *,
    n_rays: int = 160,
    n_band: int = 64,
    bands: tuple[float, ...] = (2.0, 5.0),
    contour_points: int = 150,
    edge: float = 3.0,
    dense: np.ndarray | None = None,
    occlusion: Occlusion | None = None,
    occluded_px: int = 4,
    contour_cone: float = 0.3,
    thin_px: int = 3,
    inner_reach: float | None = None,
    dense_pixels: tuple[np.ndarray, np.ndarray] | None = None,
) -> Observation:
    """Reduce a view to sample rays and silhouette-band rays.

    Parameters
    ----------
    points : (n, 3) float, metres
        The seen points (all of them, or a spread subset).
    region : Silhouette
        The seen region (:func:`symfruit.core.raster.silhouette` of all the seen points).
    camera : Camera
    n_rays, n_band : int
        At most this many depth rays, and rays per band and side (evenly spread along the outline).
    bands : tuple of float, pixels
        Distances of the band pixels from the silhouette's edge: 2 px is far enough that a pixel's
        partial coverage does not matter, 5 px grades larger outline errors. Bands are cut by the image
        window (pixels the camera did not see are no evidence).
    contour_points : int
        Edge points whose normals decide :attr:`Observation.contour`: at most this many of the points (of ``dense``
        where given) within 1.5 px of the region's edge. A region grown a pixel or more beyond the points all round
        (``evidence``'s: the fruit's mask around the border extraction leaves out) has none: its outline is then
        labelled by ``occlusion`` alone, and without that, all of it is a contour (issue 18, docs/edges52.md).
    edge : float, pixels
        Points at least this far inside the silhouette's edge are :attr:`Observation.interior`.
    dense : (N, 3) float, metres, optional
        Every seen point, when ``points`` is a subset: the surface normals along the edge that decide
        :attr:`Observation.contour` are taken over neighbourhoods of these (at full density a
        neighbourhood spans a millimetre or two, small enough to follow even a thin fruit's rim).
    occlusion : Occlusion, optional
        Where the camera could not have seen the fruit (:func:`symfruit.core.occlusion.occlusion`). The contour
        share is then measured on the region's own outline pixels: a pixel with a hidden pixel within
        ``occluded_px`` pixels is a cut whatever the normals say (an occluder's edge, the image border);
        rays of the outside bands landing on hidden pixels are no evidence; when part of the outline is a
        cut but at least ``contour_cone`` of it is a contour, the viewing cone is that of the ellipse fitted
        to the contour part (:func:`~symfruit.core.raster.outline_cone`: a cut region's moments are not the
        fruit's); and :attr:`Observation.extent` bounds where the fruit can project, hidden structures
        narrower than ``2 thin_px + 1`` pixels (stems) left out.
    occluded_px, thin_px : int, pixels
    contour_cone : float in [0, 1]
    inner_reach : float, pixels, optional
        How far inside the edge :attr:`Observation.inner` must be exact for its caller (e.g. a rim band); it is
        then exact up to the larger of that and what this function reads of it (the bands, ``edge``, the 8 px
        of the edge points' neighbourhoods) and +inf beyond, instead of the whole map (None).
    dense_pixels : ((N,), (N,)) int, optional
        The pixels of ``dense`` (:func:`~symfruit.core.raster.point_pixels`), when known: not projected again.
    """
    points = as_points(points, min_count=3)
    sample = points[:: max(1, len(points) // n_rays)]
    rays = sample / sample[:, 2:3]
    mask = region.mask
    # every read of the map below compares it with at most this (the bands, ``edge``, _contour_points' 8 px)
    reach = None if inner_reach is None else max(inner_reach, max(bands, default=0.0) + 0.5, edge, 8.0)
    # the outside bands read the map out to the widest band alone
    out_reach = max(bands, default=0.0) + 0.5
    edge_points = points if dense is None else as_points(dense, min_count=3, name="dense")
    # the maps, the points' and edge points' depths inside the edge and the edge normals in one call (issue 19, stop 51)
    edged_px = None if reach is None else _observed_edges(points, edge_points, dense, dense_pixels, region, camera,
                                                          reach, out_reach, contour_points)  # fmt: skip
    if edged_px is not None:
        inner, outer, depth_px, edge_px, edges = edged_px
        edge_uv, is_contour = edges if edges is not None else _contour_points(edge_points, edge_px, camera,
                                                                              contour_points)  # fmt: skip
    else:
        if reach is None:
            box = mask_box(mask)  # once for both maps
            inner, outer = inner_distance(mask, box=box), outer_distance(mask, out_reach, box=box)
        else:  # both maps in one call (issue 19, stop 50)
            inner, outer = distance_maps(mask, reach, out_reach)
        depth_px = _inside_px(points, region, camera, inner)
        edge_px = depth_px if dense is None else _inside_px(edge_points, region, camera, inner, dense_pixels)
        if len(edge_points) >= 0.5 * pixel_count(region):  # about a point per pixel: neighbours from the image grid
            edge_uv, is_contour = _contour_pixels(edge_points, edge_px, region, camera, contour_points)
        else:
            edge_uv, is_contour = _contour_points(edge_points, edge_px, camera, contour_points)
    kept: dict[str, Any] = {}  # _labels_at's tree of the edge points, where one is made (without numba)
    jit = compiled() if bands else None
    made: _Banded | None = None
    crack_labels = None
    outlined = None
    if occlusion is not None and jit is not None:  # the edges, bands and crack labels in one call (issue 19, stop 51)
        outlined = _outline_bands(jit, rays, inner, outer, bands, n_band, region, camera, edge_uv, is_contour,
                                  occlusion, contour_points, occluded_px, contour_cone)  # fmt: skip
    if outlined is not None:
        edge_uv, is_contour, made, crack_labels = outlined
    elif occlusion is not None:
        edge_uv, is_contour = _occluded_edges(region, occlusion, edge_uv, is_contour, contour_points, occluded_px)
    # the share from the count (a whole number over the length: the mean of the booleans, to the bit)
    contour = np.count_nonzero(is_contour) / len(is_contour) if len(is_contour) else 1.0
    edged = len(is_contour) > 0  # the edge points' labels are looked up beside band pixels and cracks (_labels_at)

    whole: list[tuple[np.ndarray, list[int], np.ndarray | None, np.ndarray | None]] = []  # for _BandParts

    def bands_of(dist: np.ndarray, outside: bool) -> tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]]:
        """Each band's rays, weights and seen depths (the last two for the outside bands alone, the depths with
        occlusion information alone); the bands' pixels looked up together (every look-up is pixel by pixel: the
        same values as band by band, in a quarter of the calls). The whole arrays go to ``whole``."""
        if not bands:  # no bands asked for
            return [], [], []
        uv, rays, sizes = _band_rays(dist, bands, n_band, region, camera)
        starts, ends = [0], []
        size_list = sizes.tolist()
        for size in size_list:  # each band's rows, sliced (np.split's views, its calls)
            ends.append(starts[-1] + size)
            starts.append(ends[-1])
        cut = list(zip(starts, ends, strict=False))
        if not outside:
            whole.append((rays, size_list, None, None))
            return [rays[a:b] for a, b in cut], [], []
        m = len(uv)
        weight: np.ndarray | None = None
        seen: np.ndarray | None = None
        hidden: np.ndarray | None = None
        seen_at = np.zeros(0)
        if occlusion is not None and m:  # the pixels hidden and, where they are, the depth seen (one call)
            hidden, seen_at = occlusion.seen_at(uv[:, 0], uv[:, 1])
            hidden = hidden if hidden.any() else None  # (none: the weights times 1, and no depth seen)
        if edged and m:  # beyond a cut edge (a hidden pixel's label is not read: its weight is 0 whatever it is)
            weight = _labels_at(edge_uv, is_contour, uv, kept, moot=hidden).astype(np.float64)
        if hidden is not None and occlusion is not None:
            weight = (np.ones(m) if weight is None else weight) * ~hidden  # a hidden pixel: no evidence of background
            seen = seen_at  # ... but of free space (NaN where not hidden)
        weight = np.ones(m) if weight is None else weight
        if occlusion is not None and seen is None:
            seen = np.full(m, np.nan)
        whole.append((rays, size_list, weight, seen))
        return ([rays[a:b] for a, b in cut], [weight[a:b] for a, b in cut],
                [] if seen is None else [seen[a:b] for a, b in cut])  # fmt: skip

    if made is None and jit is not None:  # both sides' bands in one call (issue 19, stop 51)
        made = _observed_bands(jit, rays, inner, outer, bands, n_band, region, camera, edge_uv, is_contour,
                               occlusion)  # fmt: skip
    if made is None:
        rays_in, _, _ = bands_of(inner, False)
        rays_out, out_weights, out_depth = bands_of(outer, True)
    else:
        rays_in, rays_out, out_weights, out_depth, packed = made
    fitted = None
    labelled = False
    if occlusion is not None and edged and contour < 1.0:  # which of the outline is the fruit's own: kept for the
        labelled = True  # prior's width (evidence's cut_circle reads a circle through it however little is free)
        cracks = outline_cracks(region)
        if crack_labels is None:
            crack_labels = _labels_at(edge_uv, is_contour, cracks, kept)
        if contour_cone <= contour:
            fitted = outline_cone(region, camera, cracks[crack_labels])
    # the moment ellipse's cone only where the contour's is not taken (it was made and dropped there before)
    (cone, axis), source = (fitted, "contour") if fitted is not None else (silhouette_cone(region, camera), "moments")
    tuples = (tuple(rays_in), tuple(rays_out), tuple(out_weights), None if occlusion is None else tuple(out_depth))
    parts = None
    if made is not None:
        n, n_in = len(rays), packed.n_in  # the parts the packed bands hold, as bands_of's parts (views)
        parts = _BandParts(packed.rays[n : n + n_in], [len(r) for r in rays_in], packed.rays[n + n_in :],
                           [len(r) for r in rays_out], packed.out_w, packed.seen, tuples, packed)  # fmt: skip
    elif len(whole) == 2 and whole[1][2] is not None:  # both sides' bands made (none asked for: no parts)
        (in_rays, in_sizes, _, _), (out_rays, out_sizes, out_w, out_seen) = whole
        parts = _BandParts(in_rays, in_sizes, out_rays, out_sizes, out_w, out_seen, tuples)  # type: ignore[arg-type]
    obs = Observation(rays=rays, depth=sample[:, 2], rays_in=tuples[0], rays_out=tuples[1],
                       contour=contour, cone=cone, axis=axis, interior=points[depth_px >= edge],
                       out_weights=tuples[2], out_depth=tuples[3], _parts=parts,
                       cone_source=source,
                       extent=None if occlusion is None else occlusion.extent(region, thin=thin_px),
                       inner=inner, inner_reach=float("inf") if reach is None else reach,
                       _hidden_of=None if occlusion is None else (occlusion, region))  # fmt: skip
    if labelled:  # the outline and which of it is the fruit's own contour, the ellipse's points where one was tried
        obs._made["outline"] = (cracks, crack_labels)
    return obs


@dataclass(frozen=True, eq=False)
class _BandParts:
    """:func:`observe`'s bands before they are sliced band by band: the inside and outside bands' rays (each one
    array, the bands one after the other) and sizes, the outside bands' weights and seen depths (None without
    occlusion information), and the tuples of :class:`Observation` they were sliced into (:func:`_bands` reads the
    parts only while the observation holds those very tuples)."""

    rays_in: np.ndarray
    in_sizes: list[int]
    rays_out: np.ndarray
    out_sizes: list[int]
    out_w: np.ndarray
    seen: np.ndarray | None
    of: tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...], tuple[np.ndarray, ...], tuple[np.ndarray, ...] | None]
    #: The :class:`_Bands` of these parts where :func:`_observed_bands` made them (read instead of made again).
    packed: _Bands | None = None


@dataclass(frozen=True)
class _Bands:
    """An observation's rays packed for :func:`explain`: every ray (depth, inside bands, outside bands) in one
    array, and per band where its rays start in the band part and how many; the outside bands' weights and
    seen depths in one array each (``finite``: where a depth was seen, the weight is 1 there). ``*_ok``: the
    bands that count (an inside band with rays, an outside band of positive weight), ``out_rays`` the outside
    bands with rays."""

    rays: np.ndarray
    n_in: int
    in_starts: np.ndarray
    in_sizes: np.ndarray
    in_ok: np.ndarray
    out_starts: np.ndarray
    out_w: np.ndarray
    out_wsum: np.ndarray
    out_rays: np.ndarray
    out_ok: np.ndarray
    seen: np.ndarray | None
    finite: np.ndarray | None


def _bands(obs: Observation) -> _Bands:
    """The observation's :class:`_Bands`, made once (every candidate is measured on the same rays)."""
    found = obs._made.get("bands")
    if found is not None:
        return found
    parts = obs._parts
    if parts is not None and all(a is b for a, b in zip(parts.of, (obs.rays_in, obs.rays_out, obs.out_weights,
                                                                   obs.out_depth), strict=True)):  # fmt: skip
        found = obs._made["bands"] = parts.packed if parts.packed is not None else _bands_of_parts(obs.rays, parts)
        return found
    in_sizes = np.array([len(r) for r in obs.rays_in], dtype=np.intp)
    out_sizes = np.array([len(r) for r in obs.rays_out], dtype=np.intp)
    in_starts = np.concatenate(([0], np.cumsum(in_sizes)[:-1])).astype(np.intp)
    out_starts = np.concatenate(([0], np.cumsum(out_sizes)[:-1])).astype(np.intp)
    weights = [np.ones(len(r)) if obs.out_weights is None else obs.out_weights[i] for i, r in enumerate(obs.rays_out)]
    out_w = np.concatenate(weights) if weights else np.zeros(0)
    seen = finite = None
    counted = out_w
    if obs.out_depth is not None:
        seen = np.concatenate(obs.out_depth) if len(obs.out_depth) else np.zeros(0)
        finite = np.isfinite(seen)
        counted = np.where(finite, 1.0, out_w)
    # each band's weight: its own sum (whole numbers; the per-band sum of before)
    out_wsum = np.array([counted[s : s + k].sum() for s, k in zip(out_starts, out_sizes, strict=True)])
    found = _Bands(
        rays=np.concatenate([obs.rays, *obs.rays_in, *obs.rays_out]), n_in=int(in_sizes.sum()),
        in_starts=in_starts, in_sizes=in_sizes, in_ok=in_sizes > 0, out_starts=out_starts, out_w=out_w,
        out_wsum=out_wsum, out_rays=out_sizes > 0, out_ok=(out_sizes > 0) & (out_wsum > 0), seen=seen,
        finite=finite,
    )  # fmt: skip
    obs._made["bands"] = found
    return found


def _bands_of_parts(rays: np.ndarray, parts: _BandParts) -> _Bands:
    """:func:`_bands` from :func:`observe`'s whole bands (issue 19, stop 45): the same arrays as joining the bands'
    slices back (the rays, weights and seen depths those slices were cut from; each band's start the running sum of
    the sizes before it, whole numbers), the per-band weight sums the same slices' sums."""
    in_sizes, out_sizes = parts.in_sizes, parts.out_sizes
    in_starts, out_starts, at = [], [], 0
    for size in in_sizes:
        in_starts.append(at)
        at += size
    n_in, at = at, 0
    for size in out_sizes:
        out_starts.append(at)
        at += size
    out_w, seen = parts.out_w, parts.seen
    finite = None
    counted = out_w
    if seen is not None:
        finite = np.isfinite(seen)
        counted = np.where(finite, 1.0, out_w)
    # ``np.add.reduce`` is what ``ndarray.sum`` calls (the same sums, without its Python wrappers; issue 19, stop 47)
    out_wsum = np.array([_add(counted[s : s + k]) for s, k in zip(out_starts, out_sizes, strict=True)])
    in_sizes_a = np.array(in_sizes, dtype=np.intp)
    out_sizes_a = np.array(out_sizes, dtype=np.intp)
    out_rays = out_sizes_a > 0
    return _Bands(
        rays=np.concatenate((rays, parts.rays_in, parts.rays_out)), n_in=n_in,
        in_starts=np.array(in_starts, dtype=np.intp), in_sizes=in_sizes_a, in_ok=in_sizes_a > 0,
        out_starts=np.array(out_starts, dtype=np.intp), out_w=out_w, out_wsum=out_wsum, out_rays=out_rays,
        out_ok=out_rays & (out_wsum > 0), seen=seen, finite=finite,
    )  # fmt: skip


_add = np.add.reduce


def _band_pixels(dist: np.ndarray, bands: tuple[float, ...], n_band: int) -> tuple[np.ndarray, np.ndarray]:
    """``(rc (m, 2) int, sizes (k,) int)``: each band's pixels of the distance map ``dist`` (those within half a
    pixel of its distance ``bands[i]``), row-major, at most ``n_band`` of them evenly spread (``np.linspace``'s
    picks), the bands one after the other. By the compiled twin :func:`symfruit.core._jit.band_pixels` where numba
    is installed (the same pixels)."""
    if (jit := compiled()) is not None:
        return jit.band_pixels(dist, np.asarray(bands, dtype=np.float64), n_band)
    # every band's pixels in one pass over the map
    rc = np.argwhere((dist > min(bands) - 0.5) & (dist <= max(bands) + 0.5))
    at = dist[rc[:, 0], rc[:, 1]]
    rings = [rc[(at > b - 0.5) & (at <= b + 0.5)] for b in bands]
    rcs = [r[np.linspace(0, len(r) - 1, n_band).astype(int)] if len(r) > n_band else r for r in rings]
    return np.concatenate(rcs), np.array([len(r) for r in rcs], dtype=np.intp)


def _band_rays(dist: np.ndarray, bands: tuple[float, ...], n_band: int, region: Silhouette,
               camera: Camera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """``(uv (m, 2) float, rays (m, 3) float, sizes (k,) int)``: :func:`_band_pixels`' pixels as image coordinates
    (the region's window at ``region.u0, region.v0``) and their viewing rays (:meth:`~symfruit.core.camera.Camera.
    rays`). By the compiled twin :func:`symfruit.core._jit.band_rays` where numba is installed (the same values:
    the same operations on each pixel)."""
    if (jit := compiled()) is not None:
        return jit.band_rays(dist, np.asarray(bands, dtype=np.float64), n_band, int(region.u0), int(region.v0),
                             float(camera.fx), float(camera.fy), float(camera.cx), float(camera.cy))  # fmt: skip
    rc, sizes = _band_pixels(dist, bands, n_band)
    uv = np.empty((len(rc), 2))
    uv[:, 0] = rc[:, 1] + region.u0
    uv[:, 1] = rc[:, 0] + region.v0
    return uv, camera.rays(uv[:, 0], uv[:, 1]), sizes


def _occluded_edges(
    region: Silhouette, occlusion: Occlusion, edge_uv: np.ndarray, is_contour: np.ndarray, count: int, radius: int
) -> tuple[np.ndarray, np.ndarray]:
    """``(uv (m, 2), contour (m,) bool)`` of up to ``2 count`` of the region's own outline pixels: a contour
    where the normal of the nearest edge point (``edge_uv``, ``is_contour``; none: every one) says so and
    no hidden pixel lies within ``radius`` pixels."""
    uv = _outline_uv(region, count)
    labels = _labels_at(edge_uv, is_contour, uv) if len(is_contour) else np.ones(len(uv), dtype=bool)
    return uv, labels & ~occlusion.at(uv[:, 0], uv[:, 1], radius=radius)


def _labels_at(
    edge_uv: np.ndarray,
    labels: np.ndarray,
    uv: np.ndarray,
    kept: dict[str, Any] | None = None,
    moot: np.ndarray | None = None,
) -> np.ndarray:
    """(m,) bool: the label (``labels`` (k,) bool, ``k >= 1``) of the edge point (``edge_uv`` (k, 2), pixels) nearest
    each of ``uv`` (m, 2); where the nearest points (equally near to the bit) carry both labels, the label of the first
    of them in ``edge_uv``'s order (:func:`_first_nearest`). Where every label is the same, that label (any nearest
    point has it); else by the compiled twin :func:`symfruit.core._jit.nearest_labels` where numba is installed (the
    same squared distances as a k-d tree's; issue 19, nineteenth round: a fruit's look-ups on the benchmark frame take
    9 us against 275 for a tree and its query), its ties by :func:`_first_nearest`; else by a k-d tree (``kept``:
    where it is kept for further look-ups on the same edge points), the queries whose two nearest points lie equally
    far by :func:`_first_nearest`. ``moot`` (m,) bool: the pixels whose label the caller does not read (any nearest
    point's label is returned there). Until stop 55 a tie was the tree's pick, the first point its search met, which
    hangs on how scipy's build ordered each leaf: the tree cost about 1 ms a benchmark frame for 1-3 tied pixels a
    fruit (docs/fast55.md)."""
    n_true = np.count_nonzero(labels)
    if n_true == len(labels) or n_true == 0:
        return np.full(len(uv), n_true > 0)
    jit = compiled() if len(uv) else None
    if jit is not None:
        found, unsure = jit.nearest_labels(np.ascontiguousarray(edge_uv, dtype=np.float64),
                                           np.ascontiguousarray(labels, dtype=bool),
                                           np.ascontiguousarray(uv, dtype=np.float64))  # fmt: skip
        if moot is not None:
            unsure &= ~moot
        if unsure.any():
            found[unsure] = _first_nearest(edge_uv, labels, uv[unsure])
        return found
    distance, index = _tree(edge_uv, kept).query(uv, k=2)  # the two nearest: a tie where they lie equally far
    found = labels[index[:, 0]]
    tied = distance[:, 0] == distance[:, 1]
    if moot is not None:
        tied &= ~moot
    if tied.any():
        found[tied] = _first_nearest(edge_uv, labels, np.asarray(uv)[tied])
    return found


#: :func:`_first_nearest`: at most about this many squared distances at a time (8 MB of float64).
_NEAREST_BLOCK = 2**20


def _first_nearest(points: np.ndarray, labels: np.ndarray, queries: np.ndarray) -> np.ndarray:
    """(m,) the label (``labels`` (k,)) of the point of ``points`` (k, 2) nearest each row of ``queries`` (m, 2), the
    first in ``points``' order among those equally near (squared distances ``dx * dx + dy * dy``, as
    :func:`symfruit.core._jit.nearest_labels` and scipy's k-d tree take them): :func:`_labels_at`'s rule for ties,
    the same in both kernel modes. Every distance is computed, a block of queries at a time: it is asked for the
    few queries whose nearest points tie."""
    p = np.asarray(points, dtype=np.float64)
    q = np.asarray(queries, dtype=np.float64)
    out = np.empty(len(q), dtype=np.asarray(labels).dtype)
    rows = max(1, _NEAREST_BLOCK // max(1, len(p)))
    for i in range(0, len(q), rows):
        dx = q[i : i + rows, None, 0] - p[None, :, 0]
        dy = q[i : i + rows, None, 1] - p[None, :, 1]
        out[i : i + rows] = labels[np.argmin(dx * dx + dy * dy, axis=1)]  # argmin: the first least
    return out


def _tree(edge_uv: np.ndarray, kept: dict[str, Any] | None) -> cKDTree:
    """:func:`_labels_at`'s ``cKDTree(edge_uv)``, the one in ``kept`` where there is one (made and kept there else)."""
    tree = None if kept is None else kept.get("tree")
    if tree is None:
        tree = cKDTree(edge_uv)
        if kept is not None:
            kept["tree"] = tree
    return tree


def _observed_edges(
    points: np.ndarray, edge_points: np.ndarray, dense: np.ndarray | None,
    dense_pixels: tuple[np.ndarray, np.ndarray] | None, region: Silhouette, camera: Camera, reach: float,
    out_reach: float, count: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, tuple[np.ndarray, np.ndarray] | None] | None:  # fmt: skip
    """:func:`observe`'s :func:`~symfruit.core.raster.distance_maps`, both :func:`_inside_px` and, for a cloud with
    about a point per pixel, :func:`_contour_pixels` by one compiled call (:func:`symfruit.core._jit.observe_edges`;
    issue 19, stop 51): ``(inner, outer, depth_px, edge_px, (edge_uv, is_contour) or None for a sparser cloud)``,
    the same values (each step the kernel it called). None without numba, for a mask that is not a 2-D bool image,
    or where ``observe_maps`` declines (the twins' other paths): the caller takes the steps one by one."""
    mask = region.mask
    if mask.ndim != 2 or mask.dtype != bool or (jit := compiled()) is None:
        return None
    given, col, row = (0, _NO_PIXELS, _NO_PIXELS) if dense is None else (1, _NO_PIXELS, _NO_PIXELS)
    if dense_pixels is not None and dense is not None and len(dense_pixels[0]) == len(edge_points):
        given, (col, row) = 2, dense_pixels
    done, inner, outer, depth_px, edge_px, grid, uv, contour = jit.observe_edges(
        mask, float(reach), float(out_reach), points, edge_points, col, row, given, camera.fx, camera.fy, camera.cx,
        camera.cy, region.u0, region.v0, count, 3)  # fmt: skip
    if not done:
        return None
    return inner, outer, depth_px, edge_px, (uv, contour) if grid else None


#: :func:`_observed_edges`' pixels of a dense cloud not given (not read).
_NO_PIXELS = np.zeros(0, dtype=np.int64)


def _occlusion_maps(occlusion: Occlusion | None) -> tuple[np.ndarray, np.ndarray, int, int, int, int] | None:
    """``(hidden, depth, u0, v0, width, height)`` of ``occlusion`` as the kernels read them (without one: empty maps),
    or None where :meth:`~symfruit.core.occlusion.Occlusion.seen_at` would not take its kernel (a depth map of another
    dtype or byte order)."""
    if occlusion is None:
        return _NO_HIDDEN, _NO_DEPTH, 0, 0, 0, 0
    depth = _NO_DEPTH if occlusion.depth is None else occlusion.depth
    if depth.ndim != 2 or depth.dtype not in _NATIVE_FLOATS:
        return None
    return occlusion.hidden, depth, occlusion.u0, occlusion.v0, occlusion.width, occlusion.height


def _observed_bands(
    jit: Any, rays: np.ndarray, inner: np.ndarray, outer: np.ndarray, bands: tuple[float, ...], n_band: int,
    region: Silhouette, camera: Camera, edge_uv: np.ndarray, is_contour: np.ndarray, occlusion: Occlusion | None,
) -> _Banded | None:  # fmt: skip
    """:func:`observe`'s bands by one compiled call (:func:`symfruit.core._jit.observe_bands`; issue 19, stop 51):
    the same values as ``observe``'s ``bands_of`` on both sides (the same pieces, :func:`_band_rays`,
    :meth:`~symfruit.core.occlusion.Occlusion.seen_at` and :func:`_labels_at`, in one call; a label tied between
    nearest edge points of both labels is :func:`_first_nearest`'s, as there). None where ``seen_at`` would not take its
    kernel: the caller takes ``bands_of``."""
    maps = _occlusion_maps(occlusion)
    if maps is None:
        return None
    edge = np.ascontiguousarray(edge_uv, dtype=np.float64)
    labels = np.ascontiguousarray(is_contour, dtype=bool)
    made = jit.observe_bands(rays, inner, outer, np.asarray(bands, dtype=np.float64), n_band, int(region.u0),
                             int(region.v0), float(camera.fx), float(camera.fy), float(camera.cx), float(camera.cy),
                             edge, labels, occlusion is not None, *maps)  # fmt: skip
    return _unpacked(made, len(rays), edge, labels, occlusion is not None)


def _outline_bands(
    jit: Any, rays: np.ndarray, inner: np.ndarray, outer: np.ndarray, bands: tuple[float, ...], n_band: int,
    region: Silhouette, camera: Camera, edge_uv: np.ndarray, is_contour: np.ndarray, occlusion: Occlusion,
    count: int, radius: int, share: float,
) -> tuple[np.ndarray, np.ndarray, _Banded, np.ndarray | None] | None:  # fmt: skip
    """:func:`_occluded_edges`, :func:`_observed_bands` and the outline cracks' labels (:func:`observe`'s ``cracks``,
    where ``share <= contour < 1``) by one compiled call (:func:`symfruit.core._jit.outline_bands`; issue 19, stop 51):
    ``(uv, contour labels, bands, the cracks' labels or None)``, the same values (ties of labels by
    :func:`_first_nearest`, as :func:`_labels_at` takes them). Where the edge normals' labels (``is_contour``) are all
    alike or none: their outline labels need no look-up (``_labels_at`` gives that label everywhere); else, or where
    ``_observed_bands`` or ``_outline_uv`` would not take their kernels, None: the caller takes the pieces one
    by one."""
    n_true = np.count_nonzero(is_contour)
    maps = _occlusion_maps(occlusion)
    mask = region.mask
    if maps is None or count < 1 or 0 < n_true < len(is_contour) or mask.ndim != 2 or mask.dtype != bool:
        return None
    cracks = outline_cracks(region)
    uv, labels, made, took, found, _ = jit.outline_bands(
        np.ascontiguousarray(mask), count, int(radius), bool(n_true > 0 or not len(is_contour)), cracks, float(share),
        rays, inner, outer, np.asarray(bands, dtype=np.float64), n_band, int(region.u0), int(region.v0),
        float(camera.fx), float(camera.fy), float(camera.cx), float(camera.cy), *maps)  # fmt: skip
    banded = _unpacked(made, len(rays), uv, labels, True)  # the cracks' ties resolved as the bands' (stop 65)
    return uv, labels, banded, found if took else None


#: :func:`_observed_bands`' result: each band's rays (inside, outside), the outside bands' weights and seen depths
#: (none without occlusion information), and the :class:`_Bands` that :func:`_bands_of_parts` would make of them.
_Banded = tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray], list[np.ndarray], "_Bands"]


def _unpacked(made: tuple[np.ndarray, ...], n: int, edge: np.ndarray, labels: np.ndarray, occluded: bool) -> _Banded:
    """:func:`symfruit.core._jit.observe_bands`' result ``made`` (``n`` depth rays, the edge points ``edge`` with
    ``labels``) as :func:`_observed_bands` returns it. A label tied between nearest edge points of both labels is
    :func:`_labels_at`'s (:func:`_first_nearest`'s rule): until stop 65 it was picked here and each band's weight sum
    moved by the change, since then the kernel picks it (``first_nearest_label``) before it sums the weights."""
    # the ties of labels come resolved (stop 65, look65: the kernel's first_nearest_label, _first_nearest's rule)
    every, _, in_sizes, in_starts, out_sizes, out_starts, _, weight, seen, finite, wsum = made
    n_in = int(in_sizes.sum())
    cut_in = [(n + s, n + s + k) for s, k in zip(in_starts.tolist(), in_sizes.tolist(), strict=True)]
    cut_out = [(s, s + k) for s, k in zip(out_starts.tolist(), out_sizes.tolist(), strict=True)]
    rays_in = [every[a:b] for a, b in cut_in]
    rays_out = [every[n + n_in + a : n + n_in + b] for a, b in cut_out]
    out_depth = [seen[a:b] for a, b in cut_out] if occluded else []
    out_rays = out_sizes > 0
    packed = _Bands(rays=every, n_in=n_in, in_starts=in_starts, in_sizes=in_sizes, in_ok=in_sizes > 0,
                    out_starts=out_starts, out_w=weight, out_wsum=wsum, out_rays=out_rays, out_ok=out_rays & (wsum > 0),
                    seen=seen if occluded else None, finite=finite if occluded else None)  # fmt: skip
    return rays_in, rays_out, [weight[a:b] for a, b in cut_out], out_depth, packed


#: :func:`_observed_bands`' hidden map without occlusion information (not read).
_NO_HIDDEN = np.zeros((0, 0), dtype=bool)


def _outline_uv(region: Silhouette, count: int) -> np.ndarray:
    """(m, 2) float, pixels: every ``max(1, k // (2 count))``-th of the region's ``k`` outline pixels (``mask &
    ~interior(mask)``), row-major, in image coordinates. By the compiled twin :func:`symfruit.core._jit.outline_uv`
    where numba is installed (the same pixels)."""
    mask = region.mask
    if count >= 1 and (jit := compiled()) is not None:
        return jit.outline_uv(np.ascontiguousarray(mask, dtype=bool), count, int(region.u0), int(region.v0))
    rows, cols = np.nonzero(mask & ~interior(mask))
    step = max(1, len(rows) // (2 * count))
    return np.stack((cols[::step] + region.u0, rows[::step] + region.v0), axis=1).astype(np.float64)


def _inside_px(points: np.ndarray, region: Silhouette, camera: Camera, inner: np.ndarray,
               pixels: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:  # fmt: skip
    """(n,) float: how far inside the region's edge each point's pixel lies (``inner``: its distance map); by the
    compiled twin :func:`symfruit.core._jit.inside_px` where numba is installed (the same values), from the points'
    pixels (:func:`~symfruit.core.raster.point_pixels`) where they are given (:func:`symfruit.core._jit.inside_px_of`,
    the same values without projecting the points again)."""
    if (jit := compiled()) is not None and pixels is not None and len(pixels[0]) == len(points):
        return jit.inside_px_of(pixels[0], pixels[1], region.u0, region.v0, inner)
    if jit is not None:
        return jit.inside_px(points, camera.fx, camera.fy, camera.cx, camera.cy, region.u0, region.v0, inner)
    uv = camera.project(points)
    col = np.clip(np.rint(uv[:, 0]).astype(np.intp) - region.u0, 0, inner.shape[1] - 1)
    row = np.clip(np.rint(uv[:, 1]).astype(np.intp) - region.v0, 0, inner.shape[0] - 1)
    return np.take(np.ascontiguousarray(inner).ravel(), row * inner.shape[1] + col)  # flat: faster than [row, col]


def _grazing(normal: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(m,) bool: whether each unit ``normal`` is within 60 degrees of perpendicular to the ray to its point."""
    ray = points / row_norms(points)[:, None]
    return np.abs(np.einsum("ni,ni->n", normal, ray)) < 0.5


def _contour_pixels(
    points: np.ndarray, depth_px: np.ndarray, region: Silhouette, camera: Camera, count: int, half: int = 3
) -> tuple[np.ndarray, np.ndarray]:
    """As :func:`_contour_points` for a cloud with about one point per pixel: each edge point's neighbours
    are the points of the ``(2 half + 1)^2`` pixels around its own (no search tree). By the compiled twin
    :func:`symfruit.core._jit.contour_pixels` where numba is installed (the same points; the normals to rounding)."""
    if (jit := compiled()) is not None:
        return jit.contour_pixels(points, depth_px, camera.fx, camera.fy, camera.cx, camera.cy, region.u0, region.v0,
                                  *region.mask.shape, count, half)  # fmt: skip
    near = np.flatnonzero(depth_px <= half + 1.5)  # every neighbour of an edge point lies this close
    points, depth_px = points[near], depth_px[near]
    h, w = region.mask.shape
    uv = camera.project(points)
    col = np.rint(uv[:, 0]).astype(np.intp) - region.u0 + half
    row = np.rint(uv[:, 1]).astype(np.intp) - region.v0 + half
    ok = (col >= half) & (col < w + half) & (row >= half) & (row < h + half)
    # A point on the image's last row or column can round to the pixel beyond it (outside the window).
    edge = np.flatnonzero((depth_px <= 1.5) & ok)
    if len(edge) < 3:
        return np.empty((0, 2)), np.empty(0, dtype=bool)
    edge = edge[:: max(1, len(edge) // count)]
    grid = np.full((h + 2 * half, w + 2 * half, 3), np.nan)
    # by flat pixel index (twice as fast as two index arrays; a pixel met twice keeps the later point either way)
    grid.reshape(-1, 3)[row[ok] * (w + 2 * half) + col[ok]] = points[ok]
    d = np.arange(-half, half + 1)
    rr = row[edge][:, None, None] + d[None, :, None]
    cc = col[edge][:, None, None] + d[None, None, :]
    at = (rr * (w + 2 * half) + cc).ravel()  # flat pixel indices: np.take is faster than grid[rr, cc]
    patch = np.take(grid.reshape(-1, 3), at, axis=0).reshape(len(edge), -1, 3)  # (m, (2 half + 1)^2, 3), NaN: none
    valid = np.isfinite(patch[..., 0])
    n = valid.sum(axis=1)
    patch = np.where(valid[..., None], patch, 0.0)
    mean = patch.sum(axis=1) / np.maximum(n, 1)[:, None]
    centred = np.where(valid[..., None], patch - mean[:, None, :], 0.0)
    _, vec = np.linalg.eigh(np.einsum("nki,nkj->nij", centred, centred))
    keep = n >= 6
    return uv[edge][keep], _grazing(vec[keep, :, 0], points[edge][keep])


def _contour_points(
    points: np.ndarray, depth_px: np.ndarray, camera: Camera, count: int, k: int = 30
) -> tuple[np.ndarray, np.ndarray]:
    """``(uv (m, 2), contour (m,) bool)`` of up to ``count`` points within 1.5 px of the region's edge
    (``depth_px``: each point's distance inside it): whether their local plane (PCA of their ``k`` nearest
    points among those within 8 px of the edge) is within 60 degrees of containing their ray."""
    near = np.flatnonzero(depth_px <= 8.0)
    edge = np.flatnonzero(depth_px[near] <= 1.5)
    k = min(k, len(near))
    if len(edge) < 3 or k < 6:
        return np.empty((0, 2)), np.empty(0, dtype=bool)
    edge = edge[:: max(1, len(edge) // count)]
    points = points[near]
    _, idx = cKDTree(points).query(points[edge], k=k)
    nb = points[idx] - points[idx].mean(axis=1, keepdims=True)
    _, vec = np.linalg.eigh(np.einsum("nki,nkj->nij", nb, nb))
    return camera.project(points[edge]), _grazing(vec[:, :, 0], points[edge])


def march(inside: Inside, rays: np.ndarray, z0: float, z1: float, *, steps: int = 24) -> tuple[np.ndarray, np.ndarray]:
    """First crossing into a shape along rays ``x = z * ray`` for ``z`` in ``[z0, z1]``.

    Parameters
    ----------
    inside : callable
        See :data:`Inside`.
    rays : (m, 3) float, ``z = 1``
    z0, z1 : float, metres
    steps : int
        Evaluations per ray (evenly spaced); the crossing is interpolated linearly between them.

    Returns
    -------
    hit : (m,) bool
    depth : (m,) float, metres (NaN where there is no hit; ``z0`` where the ray starts inside)
    """
    zs = np.linspace(z0, z1, steps)
    # (m, steps, 3): every ray times every depth, made as rows of ``steps`` copies of the ray times each depth
    # repeated per component (the same products; broadcasting over a last axis of 3 ran numpy's inner loop once
    # per point, several times the arithmetic)
    points = (np.tile(rays, steps) * np.repeat(zs, 3)).reshape(len(rays), steps, 3)
    f = inside(points)  # (m, steps)
    pos = f > 0
    hit = np.asarray(pos.any(axis=1))
    first = np.argmax(pos, axis=1)
    prev = np.maximum(first - 1, 0)
    rows = np.arange(len(rays))
    fa, fb = f[rows, prev], f[rows, first]
    frac = np.where((first > 0) & (fb != fa), -fa / np.where(fb != fa, fb - fa, 1.0), 0.0)
    depth = zs[prev] + np.clip(frac, 0.0, 1.0) * (zs[first] - zs[prev])
    depth = np.where(first == 0, zs[0], depth)
    return hit, np.where(hit, depth, np.nan)


#: No seen depths, for the kernels (empty: nothing in it to change, so writable, the kernels' usual array type).
_NO_SEEN = np.empty(0)


def explain(
    inside: Inside,
    box: tuple[np.ndarray, np.ndarray],
    obs: Observation,
    *,
    steps: int = 24,
    trim: float = 0.8,
    free: float = 0.01,
) -> Agreement:
    """Measure one closed candidate against the observation.

    Parameters
    ----------
    inside : callable
        The candidate's inside function (:data:`Inside`); one with an ``intersect(rays, z0, z1)`` method
        (a :class:`Quadric`) is met in closed form instead of marched, one with a ``march(rays, z0, z1, steps)``
        method (:class:`symfruit.core.fits.RevolutionInside`) marches its own rays where it can (None: not). A
        :class:`Quadric` is measured by the compiled twin :func:`symfruit.core._jit.explain_quadric` where numba
        is installed (one pass over the rays: 9 against 120 us; the depth RMS within rounding, the same shares),
        any other shape's rays, once met, by its last step, :func:`symfruit.core._jit.agreement`.
    box : ((3,), (3,)) float, metres
        The candidate's box: the rays are met over its depth range (1 mm beyond on both sides).
    obs : Observation
    steps : int
        March steps per ray (:func:`march`).
    trim : float in (0, 1]
        Share of the depth residuals kept (the smallest) for the robust RMS.
    free : float, metres
        An outside ray on a hidden pixel (:attr:`Observation.out_depth`) is wrong when the candidate meets it
        more than this in front of what the camera saw there (it would have been seen instead).
    """
    lo, hi = box
    z0, z1 = float(lo[2]) - 1e-3, float(hi[2]) + 1e-3
    n = len(obs.rays)
    if isinstance(inside, Quadric) and n and (jit := compiled()) is not None:  # one pass over the rays, compiled
        b = _bands(obs)
        seen = _NO_SEEN if b.seen is None else b.seen
        rms, ins, outs = jit.explain_quadric(inside.centre, inside.shape, b.rays, z0, z1, obs.depth,
                                             max(1, int(trim * n)), b.in_starts, b.in_sizes, b.out_starts, b.out_w,
                                             b.out_wsum, seen, free)  # fmt: skip
        return Agreement(depth=rms, inside=ins, outside=outs)
    every = _bands(obs).rays  # one march for all rays
    closed_form = getattr(inside, "intersect", None)
    marcher = getattr(inside, "march", None)  # a compiled march (core.fits.RevolutionInside), None without numba
    if callable(closed_form):
        hit_all, depth_all = closed_form(every, z0, z1)
    elif not callable(marcher) or (marched := marcher(every, z0, z1, steps)) is None:
        hit_all, depth_all = march(inside, every, z0, z1, steps=steps)
    else:
        hit_all, depth_all = marched
    if n and (jit := compiled()) is not None:  # the measures below, compiled (explain_quadric's own)
        b = _bands(obs)
        rms, ins, outs = jit.agreement(np.ascontiguousarray(hit_all, dtype=bool),
                                       np.ascontiguousarray(depth_all, dtype=np.float64), z0, z1, obs.depth,
                                       max(1, int(trim * n)), b.in_starts, b.in_sizes, b.out_starts, b.out_w,
                                       b.out_wsum, _NO_SEEN if b.seen is None else b.seen, free)  # fmt: skip
        return Agreement(depth=rms, inside=ins, outside=outs)
    hit, depth = hit_all[:n], depth_all[:n]
    res = np.where(hit, obs.depth - np.where(hit, depth, 0.0), z1 - z0)
    keep = max(1, int(trim * len(res)))
    r2 = np.partition(res * res, keep - 1)[:keep]
    hits = hit_all[n:]
    bands = _bands(obs)
    # every band's share of rays wrong from whole-number counts (sums of 0 and 1: exact in any order, so the
    # same shares as a mean and a sum per band), the bands' order and empty bands (0) kept
    # (np.add.reduceat sums from each given start to the next: the starts of the bands with rays alone)
    ins = np.zeros(len(obs.rays_in))
    if bands.in_ok.any():
        counts = np.add.reduceat(hits[: bands.n_in], bands.in_starts[bands.in_ok], dtype=np.int64)
        ins[bands.in_ok] = 1.0 - counts / bands.in_sizes[bands.in_ok]
    outs = np.zeros(len(obs.rays_out))
    if bands.out_ok.any():
        hits_out = hits[bands.n_in :]
        wrong = hits_out * bands.out_w
        if bands.seen is not None and bands.finite is not None:
            # free space in front of an occluder: a candidate there is contradicted
            with np.errstate(invalid="ignore"):
                carved = hits_out & (depth_all[n + bands.n_in :] < bands.seen - free)
            wrong = np.where(bands.finite, carved, wrong)
        sums = np.add.reduceat(wrong, bands.out_starts[bands.out_rays])  # every band with rays
        outs[bands.out_ok] = sums[bands.out_ok[bands.out_rays]] / bands.out_wsum[bands.out_ok]
    return Agreement(depth=float(np.sqrt(r2.mean())), inside=float(np.mean(ins)), outside=float(np.mean(outs)))
