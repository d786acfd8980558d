"""Rating of mirrored points (paper section 3.5, Algorithm 1, Table 1).

Every mirrored point ``p'`` is located against what the camera saw (:class:`~symfruit.raster.View`):

==========  ==================================================================  ===========
location    condition (tested in this order)                                    case
==========  ==================================================================  ===========
1           projects outside the mask ``Mp``                                    negative
2           in front of the seen surface by more than ``Dist_tol``              negative
3           within ``Dist_tol`` of the seen surface                             positive
4-1         hidden behind it, closer than ``Dist2c_0`` to the centre            negative
4-3         hidden behind it, farther than ``Dist2c_1`` from the centre         negative
4-2         hidden behind it, in between: the "reasonable region"               positive
==========  ==================================================================  ===========

with ``Dist_ref`` the largest extent of the visible points' box, ``Dist_tol = j1 Dist_ref``,
``Dist2c_0 = j2 Dist_ref``, ``Dist2c_1 = j3 Dist_ref``, ``Dist2c`` the distance of ``p'`` to the
centre of the visible points and the depth gap ``g = z(p') - z_seen`` (positive behind the surface).
The paper's ``Vec2n`` points from ``p'`` to the seen surface, and Algorithm 1 calls location 2 the case
where it is "opposite to z": read literally that is a point *behind* the surface, which contradicts
Fig. 4 and the text (location 2 is in front). We follow the figure: location 2 is ``g < -Dist_tol``.

How the equations are read (``scoring`` setting):

``literal``
    Eqs. 6-10 as printed: 1: ``-k1 |Vec2n| / Dist_ref`` with ``Vec2n`` the 3D vector to the seen
    surface point at the nearest mask pixel; 2: ``-k2 |g| / Dist_ref``; 3: ``k3``; 4-1:
    ``-k4 Dist_ref / Dist2c`` (Eq. 9); 4-2: ``k3`` (Algorithm 1; the text's "same as Eq. (9)" is a
    slip, a positive case cannot share the negative Eq. 9); 4-3: ``-k5 Dist2c / Dist_ref`` (Eq. 10).
    These jump at every border (e.g. Eq. 9 is ``-1/j2**2 = -2.8`` at the 4-1 border and unbounded at
    the centre, though the text promises a score in (-1, 0)).
``continuous`` (default)
    Keeps the paper's regions, constants and intent (positive cases score ``k3``; a negative case
    scores lower the farther it is from the reasonable region; "close" means (-1, 0), "far" below -1)
    but makes the score continuous at each border: a negative case starts at ``k3`` on its border and
    falls linearly, reaching -1 one paper unit past it, where the unit is the one Table 1 implies,
    ``Dist_ref / k`` (so ``k2 = 1/j1`` gives -1 one ``Dist_tol`` in front of the tolerance band,
    ``k4 = 1/j2`` gives -1 at the centre, ``k5 = 1/j3`` gives -1 at ``2 Dist2c_1``). A point outside
    the mask scores what it would score on the mask's edge (same depth, its nearest mask pixel) minus
    ``(k3 + 1) k1 e / Dist_ref``, ``e`` its distance to the mask in metres at its depth, so crossing the
    silhouette is continuous too, up to the pixel grid (the first pixel outside costs one pixel's
    distance). The one border left discontinuous is 3 -> 4-1/4-3 along ``g = Dist_tol``, which the
    paper's test order (3 before 4) makes inherent.

Both are monotone as the text describes. A hypothesis scores the mean over its points
(:func:`rate_planes`); :func:`rate_points` gives every point's score and location.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .camera import Camera
from .raster import View

__all__ = ["LOCATIONS", "Rating", "Table1", "rate_planes", "rate_points"]

#: Location codes of :class:`Rating` (4-1 is 41, and so on).
LOCATIONS = (1, 2, 3, 41, 42, 43)

#: Mirrored points rated per block: keeps every work buffer at a few MB and in a reused workspace.
BLOCK_POINTS = 1 << 18

Scoring = Literal["continuous", "literal"]


@dataclass(frozen=True)
class Table1:
    """The rating constants of the paper's Table 1.

    Attributes
    ----------
    j1, j2, j3 : float
        ``Dist_tol = j1 * Dist_ref``, ``Dist2c_0 = j2 * Dist_ref``, ``Dist2c_1 = j3 * Dist_ref``
        (paper: 0.05, 0.6, 1.2).
    k1, k3 : float
        Paper: 10 and 1.
    k2, k4, k5 : float or None
        Table 1 gives ``1/j1``, ``1/j2``, ``1/j3``; None means exactly that. (The text says ``k5 = 1``;
        Table 1 wins because only ``1/j3`` makes Eq. 10 equal -1 at the border of location 4-3, the
        value the text asks of "close to the reasonable region".)
    """

    j1: float = 0.05
    j2: float = 0.6
    j3: float = 1.2
    k1: float = 10.0
    k2: float | None = None
    k3: float = 1.0
    k4: float | None = None
    k5: float | None = None

    @property
    def k2_value(self) -> float:
        return 1.0 / self.j1 if self.k2 is None else self.k2

    @property
    def k4_value(self) -> float:
        return 1.0 / self.j2 if self.k4 is None else self.k4

    @property
    def k5_value(self) -> float:
        return 1.0 / self.j3 if self.k5 is None else self.k5


class _Workspace(threading.local):
    """Per-thread reusable work buffers.

    Allocating fresh arrays of a few hundred kB on every call costs more than the arithmetic on them
    (the page faults of new memory dominate), so the mean-score path writes into buffers kept between
    calls, grown on demand and never larger than one block.
    """

    def __init__(self) -> None:
        self.buffers: dict[tuple[str, type], np.ndarray] = {}

    def get(self, name: str, shape: tuple[int, int], dtype: type) -> np.ndarray:
        size = shape[0] * shape[1]
        key = (name, dtype)
        buf = self.buffers.get(key)
        if buf is None or buf.size < size:
            buf = np.empty(size, dtype=dtype)
            self.buffers[key] = buf
        return buf[:size].reshape(shape)


_WORK = _Workspace()

Buffers = Callable[[str, tuple[int, int], type], np.ndarray]


def _fresh(name: str, shape: tuple[int, int], dtype: type) -> np.ndarray:
    return np.empty(shape, dtype)


@dataclass(frozen=True)
class Rating:
    """Per-point detail of a rating (:func:`rate_points`).

    Attributes
    ----------
    scores : (h, n) float
    locations : (h, n) int8, codes of :data:`LOCATIONS`
    gap : (h, n) float, metres
        Depth of the mirrored point minus the seen depth at its (nearest) mask pixel.
    dist2c : (h, n) float, metres
    outside : (h, n) float, pixels
        Distance to the mask (0 inside).
    """

    scores: np.ndarray
    locations: np.ndarray
    gap: np.ndarray
    dist2c: np.ndarray
    outside: np.ndarray


@dataclass
class _Mirrored:
    """Where every mirrored point of a block of planes falls (arrays ``(h, n)``, some of them scratch)."""

    z: np.ndarray  # mirrored depth, metres (clamped 1 mm in front of the camera)
    e: np.ndarray  # distance to the mask, pixels (0 inside)
    index: np.ndarray  # flat window pixel
    gap: np.ndarray  # mirrored depth minus seen depth, metres (> 0: behind the seen surface)
    d2c: np.ndarray  # distance to the centre, metres
    scratch1: np.ndarray
    scratch2: np.ndarray
    mx: np.ndarray | None  # mirrored x, y relative to the centre (only when asked for)
    my: np.ndarray | None


def _prepare(source, plane_points, normals, centre):
    centre = np.asarray(centre, dtype=np.float64)
    rel = np.asarray(source, dtype=np.float64) - centre
    normals = np.asarray(normals, dtype=np.float64)
    normals = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    t = np.einsum("hi,hi->h", np.asarray(plane_points, dtype=np.float64) - centre, normals)
    per_block = max(1, BLOCK_POINTS // max(len(rel), 1))
    return centre, rel, normals, t, per_block


def rate_planes(
    source: np.ndarray,
    plane_points: np.ndarray,
    normals: np.ndarray,
    view: View,
    camera: Camera,
    *,
    centre: np.ndarray,
    dist_ref: float,
    table: Table1 | None = None,
    scoring: Scoring = "continuous",
    dtype: type = np.float32,
) -> np.ndarray:
    """Mirror ``source`` through every plane and rate the mirrored points against ``view``: mean scores.

    The hot path of the ``paper`` method: all hypotheses and points at once, as array arithmetic in
    reused buffers (blocks of :data:`BLOCK_POINTS` bound the memory). The distance of a mirrored
    point to the centre comes without forming the point: with ``s`` its signed distance to the plane
    and ``t = (q - c) . n``, ``|p' - c|^2 = |p - c|^2 - 4 s t``.

    Parameters
    ----------
    source : (n, 3) float, metres
        Points to mirror (normally the visible points the view was made from).
    plane_points, normals : (h, 3) float
        One point and the normal of each plane.
    view : View
        The rasterised visible fruit.
    camera : Camera
    centre : (3,) float, metres
        The centre ``Dist2c`` is measured from.
    dist_ref : float, metres
        ``Dist_ref``, the largest extent of the visible points.
    table : Table1, optional
        Rating constants (default: the paper's).
    scoring : {"continuous", "literal"}
        How Eqs. 6-10 are read (module docstring).
    dtype : numpy float type
        Precision of the arithmetic (coordinates are taken relative to ``centre``, so single
        precision keeps sub-micrometre accuracy at fruit scale).

    Returns
    -------
    (h,) float64
        Mean score per plane.

    Notes
    -----
    A point projecting outside the rasterised window takes the window's nearest pixel; its distance
    to the mask is that pixel's plus the L1 distance to the window, an upper bound of the true one.
    Mirrored points at or behind the camera are treated as lying 1 mm in front of it, which sends them
    far outside the mask (or, on the optical axis, far in front of the seen surface).
    """
    table = table or Table1()
    centre, rel, normals, t, per_block = _prepare(source, plane_points, normals, centre)
    means = []
    for a in range(0, len(normals), per_block):
        nb, tb = normals[a : a + per_block], t[a : a + per_block]
        if scoring == "continuous":
            g = _mirrored(rel, nb, tb, view, camera, centre, dtype, _WORK.get, with_xy=False)
            means.append(_continuous_mean(g, dist_ref, table, camera, dtype, len(rel)))
        else:
            g = _mirrored(rel, nb, tb, view, camera, centre, dtype, _fresh, with_xy=True)
            scores = _literal_scores(g, view, camera, centre, dist_ref, table, dtype)
            means.append(scores.mean(axis=1, dtype=np.float64))
    return np.concatenate(means)


def rate_points(
    source: np.ndarray,
    plane_points: np.ndarray,
    normals: np.ndarray,
    view: View,
    camera: Camera,
    *,
    centre: np.ndarray,
    dist_ref: float,
    table: Table1 | None = None,
    scoring: Scoring = "continuous",
    dtype: type = np.float32,
) -> Rating:
    """Every mirrored point's score and location (same arguments as :func:`rate_planes`).

    ``rate_points(...).scores.mean(axis=1)`` equals :func:`rate_planes` up to rounding.
    """
    table = table or Table1()
    centre, rel, normals, t, per_block = _prepare(source, plane_points, normals, centre)
    blocks = []
    for a in range(0, len(normals), per_block):
        g = _mirrored(rel, normals[a : a + per_block], t[a : a + per_block], view, camera, centre, dtype, _fresh,
                      with_xy=True)  # fmt: skip
        blocks.append(_per_point(g, view, camera, centre, dist_ref, table, scoring, dtype))
    return Rating(*(np.concatenate([getattr(b, f) for b in blocks]) for f in Rating.__dataclass_fields__))


def _mirrored(rel, normals, t, view, camera, centre, dtype, buffer: Buffers, *, with_xy: bool) -> _Mirrored:
    """Mirror and locate one block of planes; arrays come from ``buffer``."""
    h, n = len(normals), len(rel)
    shape = (h, n)
    wh, ww = view.mask.shape
    f = dtype
    px, py, pz = (rel[:, i].astype(dtype) for i in range(3))

    # Signed distance of every point to every plane, relative to the centre.
    sd = buffer("s", shape, dtype)
    np.matmul(normals.astype(dtype), rel.T.astype(dtype), out=sd)
    sd -= t.astype(dtype)[:, None]

    # Mirrored depth (absolute), clamped 1 mm in front of the camera.
    z = buffer("z", shape, dtype)
    np.multiply(sd, (-2.0 * normals[:, 2]).astype(dtype)[:, None], out=z)
    z += (pz + f(centre[2]))[None, :]
    np.maximum(z, f(1e-3), out=z)
    inv = buffer("inv", shape, dtype)
    np.divide(f(1.0), z, out=inv)

    # Pixel coordinates in the window, shifted by +0.5 so that truncation rounds.
    u = buffer("u", shape, dtype)
    np.multiply(sd, (-2.0 * camera.fx * normals[:, 0]).astype(dtype)[:, None], out=u)
    u += (camera.fx * (px + f(centre[0])))[None, :]
    u *= inv
    u += f(camera.cx - view.u0 + 0.5)
    v = buffer("v", shape, dtype)
    np.multiply(sd, (-2.0 * camera.fy * normals[:, 1]).astype(dtype)[:, None], out=v)
    v += (camera.fy * (py + f(centre[1])))[None, :]
    v *= inv
    v += f(camera.cy - view.v0 + 0.5)
    mx = my = None
    if with_xy:
        mx = (u - f(camera.cx - view.u0 + 0.5)) / inv / f(camera.fx) - f(centre[0])
        my = (v - f(camera.cy - view.v0 + 0.5)) / inv / f(camera.fy) - f(centre[1])

    # Window pixel, and how far outside the window the point fell (L1, pixels).
    uc = buffer("uc", shape, dtype)
    np.clip(u, 0, f(ww - 1e-3), out=uc)
    vc = buffer("vc", shape, dtype)
    np.clip(v, 0, f(wh - 1e-3), out=vc)
    u -= uc
    np.abs(u, out=u)
    v -= vc
    np.abs(v, out=v)
    e = u
    e += v
    np.floor(vc, out=vc)
    vc *= ww
    np.floor(uc, out=uc)
    vc += uc  # flat window index, exact in float32 for any image up to 16 megapixels
    index = buffer("index", shape, np.intp)
    np.copyto(index, vc, casting="unsafe")
    # One gather of (distance to the mask, seen depth) pairs, packed as complex numbers.
    ctype = np.complex64 if dtype == np.float32 else np.complex128
    packed = np.empty(view.dist.shape, ctype)
    packed.real, packed.imag = view.dist, view.near_depth
    pair = buffer("pair", shape, ctype)
    np.take(packed, index, out=pair)
    e += pair.real  # distance to the mask, pixels
    gap = buffer("gap", shape, dtype)
    np.subtract(z, pair.imag, out=gap)  # > 0: behind the seen surface

    # Distance to the centre: |p' - c|^2 = |p - c|^2 - 4 s t.
    d2c = buffer("d2c", shape, dtype)
    np.multiply(sd, (-4.0 * t).astype(dtype)[:, None], out=d2c)
    d2c += (px * px + py * py + pz * pz)[None, :]
    np.maximum(d2c, 0, out=d2c)
    np.sqrt(d2c, out=d2c)
    return _Mirrored(z=z, e=e, index=index, gap=gap, d2c=d2c, scratch1=uc, scratch2=vc, mx=mx, my=my)


def _continuous_penalty(g: _Mirrored, dist_ref: float, table: Table1, camera: Camera, dtype: type,
                        behind: np.ndarray) -> np.ndarray:  # fmt: skip
    """``k3`` minus the continuous score of every point, computed in place (consumes ``g.d2c``, ``g.e``)."""
    f, r = dtype, float(dist_ref)
    tol, d0, d1 = f(table.j1 * r), f(table.j2 * r), f(table.j3 * r)
    drop = table.k3 + 1.0
    tmp = g.scratch1
    np.negative(g.gap, out=tmp)
    tmp -= tol
    np.maximum(tmp, 0, out=tmp)
    tmp *= f(drop * table.k2_value / r)
    side = g.scratch2
    np.subtract(d0, g.d2c, out=side)
    np.maximum(side, 0, out=side)
    side *= f(drop * table.k4_value / r)
    g.d2c -= d1
    np.maximum(g.d2c, 0, out=g.d2c)
    g.d2c *= f(drop * table.k5_value / r)
    side += g.d2c
    side *= behind
    tmp += side
    # Outside the mask: metres at the point's depth (0 inside).
    g.e *= g.z
    g.e *= f(drop * table.k1 / (r * np.sqrt(camera.fx * camera.fy)))
    tmp += g.e
    return tmp


def _continuous_mean(g: _Mirrored, dist_ref: float, table: Table1, camera: Camera, dtype: type, n: int) -> np.ndarray:
    tol = dtype(table.j1 * float(dist_ref))
    behind = _WORK.get("behind", g.gap.shape, np.bool_)
    np.greater(g.gap, tol, out=behind)
    penalty = _continuous_penalty(g, dist_ref, table, camera, dtype, behind)
    return table.k3 - penalty.sum(axis=1, dtype=np.float64) / n


def _literal_scores(g: _Mirrored, view: View, camera: Camera, centre, dist_ref: float, table: Table1,
                    dtype: type) -> np.ndarray:  # fmt: skip
    """Eqs. 6-10 as printed, per point."""
    f, r = dtype, float(dist_ref)
    tol, d0, d1 = f(table.j1 * r), f(table.j2 * r), f(table.j3 * r)
    outside = g.e > 0
    front = g.gap < -tol
    behind = g.gap > tol
    near = behind & (g.d2c < d0)
    far = behind & (g.d2c > d1)
    inside = ~outside
    scores = (inside & ~front & ~behind) * f(table.k3)
    scores += (inside & front) * (np.abs(g.gap) * f(-table.k2_value / r))
    scores += (inside & near) * (f(-table.k4_value * r) / np.maximum(g.d2c, f(1e-12)))
    scores += (inside & far) * (g.d2c * f(-table.k5_value / r))
    scores += (inside & behind & ~near & ~far) * f(table.k3)
    # Location 1: |Vec2n|, the 3D distance to the seen surface at the nearest mask pixel.
    depth: np.ndarray = view.near_depth.astype(dtype, copy=False).take(g.index)
    sx = (view.near_u.astype(dtype, copy=False).take(g.index) - f(camera.cx)) * depth / f(camera.fx)
    sy = (view.near_v.astype(dtype, copy=False).take(g.index) - f(camera.cy)) * depth / f(camera.fy)
    assert g.mx is not None and g.my is not None  # computed (with_xy) on every path that scores literally
    vec2n = np.sqrt((sx - g.mx - f(centre[0])) ** 2 + (sy - g.my - f(centre[1])) ** 2 + (depth - g.z) ** 2)
    scores += outside * (vec2n * f(-table.k1 / r))
    return scores


def _per_point(g: _Mirrored, view: View, camera: Camera, centre, dist_ref: float, table: Table1, scoring: Scoring,
               dtype: type) -> Rating:  # fmt: skip
    f, r = dtype, float(dist_ref)
    tol, d0, d1 = f(table.j1 * r), f(table.j2 * r), f(table.j3 * r)
    outside = g.e > 0
    front = g.gap < -tol
    behind = g.gap > tol
    near = behind & (g.d2c < d0)
    far = behind & (g.d2c > d1)
    e_px, dist2c = g.e.copy(), g.d2c.copy()
    if scoring == "continuous":
        scores = np.subtract(f(table.k3), _continuous_penalty(g, dist_ref, table, camera, dtype, behind))
    else:
        scores = _literal_scores(g, view, camera, centre, dist_ref, table, dtype)
    locations = np.select([outside, front, ~behind, near, far], [1, 2, 3, 41, 43], default=42)
    return Rating(scores=scores, locations=locations.astype(np.int8), gap=g.gap, dist2c=dist2c, outside=e_px)
