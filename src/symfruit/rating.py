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

Both are monotone as the text describes. A hypothesis scores the mean over its points.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np

from .camera import Camera
from .config import PaperSettings
from .raster import View

__all__ = ["LOCATIONS", "Rating", "rate_planes"]

#: Location codes returned by :func:`rate_planes` with ``per_point=True`` (4-1 is 41, and so on).
LOCATIONS = (1, 2, 3, 41, 42, 43)

#: Mirrored points rated per block: keeps every work buffer at a few MB and in a reused workspace.
BLOCK_POINTS = 1 << 18


class _Workspace(threading.local):
    """Per-thread reusable work buffers.

    Allocating fresh arrays of a few hundred kB on every call costs more than the arithmetic on them
    (the page faults of new memory dominate), so the hot path writes into buffers kept between
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


@dataclass(frozen=True)
class Rating:
    """Per-point detail of a rating (from :func:`rate_planes` with ``per_point=True``).

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


def rate_planes(
    source: np.ndarray,
    plane_points: np.ndarray,
    normals: np.ndarray,
    view: View,
    camera: Camera,
    centre: np.ndarray,
    dist_ref: float,
    settings: PaperSettings,
    *,
    dtype: type = np.float32,
    per_point: bool = False,
) -> np.ndarray | Rating:
    """Mirror ``source`` through every plane and rate the mirrored points against ``view``.

    The hot path of the ``paper`` method: all hypotheses and points at once, as array arithmetic
    in reused buffers (blocks of :data:`BLOCK_POINTS` bound the memory). The distance of a mirrored
    point to the centre comes without forming the point: with ``s`` its signed distance to the plane
    and ``t = (q - c) . n``, ``|p' - c|^2 = |p - c|^2 - 4 s t``.

    Parameters
    ----------
    source : (n, 3) float, metres
        Points to mirror (normally the visible points the view was made from).
    plane_points, normals : (h, 3) float
        One point and the unit normal of each plane.
    view : View
        The rasterised visible fruit.
    camera : Camera
    centre : (3,) float, metres
        The centre ``Dist2c`` is measured from.
    dist_ref : float, metres
        ``Dist_ref``, the largest extent of the visible points.
    settings : PaperSettings
    dtype : numpy float type
        Precision of the arithmetic (coordinates are taken relative to ``centre``, so single
        precision keeps sub-micrometre accuracy at fruit scale).
    per_point : bool
        Return a :class:`Rating` with every point's score and location instead of the means.

    Returns
    -------
    (h,) float64 mean score per plane, or a :class:`Rating`.

    Notes
    -----
    A point projecting outside the rasterised window takes the window's nearest pixel; its distance
    to the mask is that pixel's plus the L1 distance to the window, an upper bound of the true one.
    Mirrored points at or behind the camera are treated as lying 1 mm in front of it, which sends them
    far outside the mask (or, on the optical axis, far in front of the seen surface).
    """
    centre = np.asarray(centre, dtype=np.float64)
    rel = np.asarray(source, dtype=np.float64) - centre
    normals = np.asarray(normals, dtype=np.float64)
    normals = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    t = np.einsum("hi,hi->h", np.asarray(plane_points, dtype=np.float64) - centre, normals)
    n_pts, n_planes = len(rel), len(normals)
    per_block = max(1, BLOCK_POINTS // max(n_pts, 1))
    blocks = [
        _rate_block(
            rel,
            normals[a : a + per_block],
            t[a : a + per_block],
            view,
            camera,
            centre,
            dist_ref,
            settings,
            dtype,
            per_point=per_point,
        )
        for a in range(0, n_planes, per_block)
    ]
    if per_point:
        return Rating(*(np.concatenate([getattr(b, f) for b in blocks]) for f in Rating.__dataclass_fields__))
    return np.concatenate(blocks)


def _rate_block(rel, normals, t, view, camera, centre, dist_ref, s, dtype, *, per_point):
    """Rate one block of planes; see :func:`rate_planes`. Buffers come from the workspace."""
    ws = (
        (lambda name, shape: np.empty(shape, dtype))
        if per_point
        else (lambda name, shape: _WORK.get(name, shape, dtype))
    )
    h, n = len(normals), len(rel)
    shape = (h, n)
    r = float(dist_ref)
    wh, ww = view.mask.shape
    f = dtype
    px, py, pz = (rel[:, i].astype(dtype) for i in range(3))

    # Signed distance of every point to every plane, relative to the centre.
    sd = ws("s", shape)
    np.matmul(normals.astype(dtype), rel.T.astype(dtype), out=sd)
    sd -= t.astype(dtype)[:, None]

    # Mirrored depth (absolute), clamped 1 mm in front of the camera.
    z = ws("z", shape)
    np.multiply(sd, (-2.0 * normals[:, 2]).astype(dtype)[:, None], out=z)
    z += (pz + f(centre[2]))[None, :]
    np.maximum(z, f(1e-3), out=z)
    inv = ws("inv", shape)
    np.divide(f(1.0), z, out=inv)

    # Pixel coordinates in the window, shifted by +0.5 so that truncation rounds.
    u = ws("u", shape)
    np.multiply(sd, (-2.0 * camera.fx * normals[:, 0]).astype(dtype)[:, None], out=u)
    u += (camera.fx * (px + f(centre[0])))[None, :]
    u *= inv
    u += f(camera.cx - view.u0 + 0.5)
    v = ws("v", shape)
    np.multiply(sd, (-2.0 * camera.fy * normals[:, 1]).astype(dtype)[:, None], out=v)
    v += (camera.fy * (py + f(centre[1])))[None, :]
    v *= inv
    v += f(camera.cy - view.v0 + 0.5)
    if per_point or s.scoring == "literal":
        mx = (u - f(camera.cx - view.u0 + 0.5)) / inv / f(camera.fx) - f(centre[0])
        my = (v - f(camera.cy - view.v0 + 0.5)) / inv / f(camera.fy) - f(centre[1])

    # Window pixel, and how far outside the window the point fell (L1, pixels).
    uc = ws("uc", shape)
    np.clip(u, 0, f(ww - 1e-3), out=uc)
    vc = ws("vc", shape)
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
    index = np.empty(shape, np.intp) if per_point else _WORK.get("index", shape, np.intp)
    np.copyto(index, vc, casting="unsafe")
    # One gather of (distance to the mask, seen depth) pairs, packed as complex numbers.
    ctype = np.complex64 if dtype == np.float32 else np.complex128
    packed = np.empty(view.dist.shape, ctype)
    packed.real, packed.imag = view.dist, view.near_depth
    pair = np.empty(shape, ctype) if per_point else _WORK.get("pair", shape, ctype)
    np.take(packed, index, out=pair)
    e += pair.real  # distance to the mask, pixels
    gap = ws("gap", shape)
    np.subtract(z, pair.imag, out=gap)  # > 0: behind the seen surface

    # Distance to the centre: |p' - c|^2 = |p - c|^2 - 4 s t.
    d2c = ws("d2c", shape)
    np.multiply(sd, (-4.0 * t).astype(dtype)[:, None], out=d2c)
    d2c += (px * px + py * py + pz * pz)[None, :]
    np.maximum(d2c, 0, out=d2c)
    np.sqrt(d2c, out=d2c)

    tol, d0, d1 = f(s.j1 * r), f(s.j2 * r), f(s.j3 * r)
    behind = _WORK.get("behind", shape, np.bool_) if not per_point else np.empty(shape, np.bool_)
    np.greater(gap, tol, out=behind)

    if per_point or s.scoring == "literal":
        outside = e > 0
        front = gap < -tol
        near = behind & (d2c < d0)
        far = behind & (d2c > d1)
        e_px, dist2c = e.copy(), d2c.copy()
    if s.scoring == "continuous":
        drop = s.k3 + 1.0
        tmp = uc  # free now
        np.negative(gap, out=tmp)
        tmp -= tol
        np.maximum(tmp, 0, out=tmp)
        tmp *= f(drop * s.k2_value / r)
        side = vc  # free now
        np.subtract(d0, d2c, out=side)
        np.maximum(side, 0, out=side)
        side *= f(drop * s.k4_value / r)
        d2c -= d1
        np.maximum(d2c, 0, out=d2c)
        d2c *= f(drop * s.k5_value / r)
        side += d2c
        side *= behind
        tmp += side
        # Outside the mask: metres at the point's depth (0 inside).
        e *= z
        e *= f(drop * s.k1 / (r * np.sqrt(camera.fx * camera.fy)))
        tmp += e
        if not per_point:
            return s.k3 - tmp.sum(axis=1, dtype=np.float64) / n
        scores = np.subtract(f(s.k3), tmp)
    else:
        inside = ~outside
        scores = (inside & ~front & ~behind) * f(s.k3)
        scores += (inside & front) * (np.abs(gap) * f(-s.k2_value / r))
        scores += (inside & near) * (f(-s.k4_value * r) / np.maximum(d2c, f(1e-12)))
        scores += (inside & far) * (d2c * f(-s.k5_value / r))
        scores += (inside & behind & ~near & ~far) * f(s.k3)
        # Location 1: |Vec2n|, the 3D distance to the seen surface at the nearest mask pixel.
        depth = view.near_depth.astype(dtype, copy=False).take(index)
        sx = (view.near_u.astype(dtype, copy=False).take(index) - f(camera.cx)) * depth / f(camera.fx)
        sy = (view.near_v.astype(dtype, copy=False).take(index) - f(camera.cy)) * depth / f(camera.fy)
        vec2n = np.sqrt((sx - mx - f(centre[0])) ** 2 + (sy - my - f(centre[1])) ** 2 + (depth - z) ** 2)
        scores += outside * (vec2n * f(-s.k1 / r))
        if not per_point:
            return scores.mean(axis=1, dtype=np.float64)
    locations = np.select([outside, front, ~behind, near, far], [1, 2, 3, 41, 43], default=42)
    return Rating(scores=scores, locations=locations.astype(np.int8), gap=gap, dist2c=dist2c, outside=e_px)
