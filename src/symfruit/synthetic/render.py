"""A small z-buffer renderer and an RGB-D sensor model, for synthetic views and scenes.

``render`` rasterises triangle meshes exactly (the depth of each pixel is where its ray meets the
triangle's plane); ``SensorNoise`` turns the ideal depth into what a D435-like camera returns.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.camera import Camera

__all__ = ["Rendering", "SensorNoise", "render"]


@dataclass(frozen=True)
class Rendering:
    """An ideal depth image of some meshes.

    Attributes
    ----------
    depth : (h, w) float, metres; ``inf`` where nothing was hit
    ids : (h, w) int; index of the mesh seen at each pixel, -1 for background
    facing : (h, w) float; ``|cos|`` of the angle between the pixel's ray and the surface normal
        (small at grazing angles, as near a fruit's silhouette)
    """

    depth: np.ndarray
    ids: np.ndarray
    facing: np.ndarray


def render(meshes: list[tuple[np.ndarray, np.ndarray]], camera: Camera, *, max_candidates: int = 1 << 21) -> Rendering:
    """Render triangle meshes with a z-buffer.

    Parameters
    ----------
    meshes : list of (vertices (v, 3) float, faces (f, 3) int)
        In the camera optical frame, metres; triangles with a vertex at ``z <= 1 mm`` are skipped.
    camera : Camera
    max_candidates : int
        Pixel candidates tested per batch of triangles (bounds memory).

    Returns
    -------
    Rendering
    """
    h, w = camera.height, camera.width
    tris: list[np.ndarray] = []
    owners: list[np.ndarray] = []
    for k, (vertices, faces) in enumerate(meshes):
        if len(faces):
            tris.append(np.asarray(vertices, dtype=np.float64)[np.asarray(faces)])
            owners.append(np.full(len(faces), k))
    zbuf = np.full(h * w, np.inf)
    ids = np.full(h * w, -1)
    facing = np.zeros(h * w)
    if not tris:
        return Rendering(zbuf.reshape(h, w), ids.reshape(h, w), facing.reshape(h, w))
    tri = np.concatenate(tris)
    owner = np.concatenate(owners)
    keep = (tri[:, :, 2] > 1e-3).all(axis=1)
    tri, owner = tri[keep], owner[keep]
    uv = camera.project(tri)  # (t, 3, 2)
    lo = np.ceil(uv.min(axis=1) - 1e-9).astype(np.int64)
    hi = np.floor(uv.max(axis=1) + 1e-9).astype(np.int64)
    lo = np.maximum(lo, 0)
    hi = np.minimum(hi, [w - 1, h - 1])
    size = hi - lo + 1
    ok = (size > 0).all(axis=1)
    tri, owner, uv, lo, size = tri[ok], owner[ok], uv[ok], lo[ok], size[ok]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(normal, axis=1)
    good = norm > 0
    tri, owner, uv, lo, size, normal = tri[good], owner[good], uv[good], lo[good], size[good], normal[good]
    normal = normal / np.linalg.norm(normal, axis=1, keepdims=True)
    offset = np.einsum("ti,ti->t", normal, tri[:, 0])

    # Batch triangles by the side of their pixel box so the candidate grids stay small.
    sides = size.max(axis=1)
    cand_pix: list[np.ndarray] = []
    cand_z: list[np.ndarray] = []
    cand_t: list[np.ndarray] = []
    for side in np.unique(sides):
        group = np.flatnonzero(sides == side)
        per_batch = max(1, max_candidates // int(side * side))
        for first in range(0, len(group), per_batch):
            idx = group[first : first + per_batch]
            _candidates(idx, int(side), lo, size, uv, normal, offset, camera, w, cand_pix, cand_z, cand_t)
    if not cand_pix:
        return Rendering(zbuf.reshape(h, w), ids.reshape(h, w), facing.reshape(h, w))
    pix, z, t = np.concatenate(cand_pix), np.concatenate(cand_z), np.concatenate(cand_t)
    np.minimum.at(zbuf, pix, z)
    win = z <= zbuf[pix]
    pix, t = pix[win], t[win]
    ids[pix] = owner[t]
    u, v = pix % w, pix // w
    ray = camera.rays(u, v)
    ray /= np.linalg.norm(ray, axis=1, keepdims=True)
    facing[pix] = np.abs(np.einsum("ti,ti->t", normal[t], ray))
    return Rendering(zbuf.reshape(h, w), ids.reshape(h, w), facing.reshape(h, w))


def _candidates(idx, side, lo, size, uv, normal, offset, camera, w, cand_pix, cand_z, cand_t) -> None:
    """Pixels covered by triangles ``idx`` (boxes up to ``side`` pixels) and their exact depths.

    Each triangle's candidates are the ``side x side`` pixels from its box's corner, ``(t, dv, du)``. An edge
    function ``(q - p) x (pixel - p)`` is a product depending on the row alone minus one depending on the column
    alone: each is computed once per row or column and the two broadcast, the same floating-point operations on
    the same numbers as per pixel."""
    n, step = len(idx), np.arange(side)
    pu = lo[idx, 0, None] + step  # (n, side): the columns of each box
    pv = lo[idx, 1, None] + step  # (n, side): the rows
    a, b, c = uv[idx, 0], uv[idx, 1], uv[idx, 2]

    def edge(p: np.ndarray, q: np.ndarray) -> np.ndarray:
        rows = (q[:, 0, None] - p[:, 0, None]) * (pv - p[:, 1, None])
        cols = (q[:, 1, None] - p[:, 1, None]) * (pu - p[:, 0, None])
        return (rows[:, :, None] - cols[:, None, :]).reshape(n, side * side)

    e0, e1, e2 = edge(a, b), edge(b, c), edge(c, a)
    inside = ((step < size[idx, 1, None])[:, :, None] & (step < size[idx, 0, None])[:, None, :]).reshape(n, -1)
    # Inside: all three edge functions >= 0 or all <= 0, with a small tolerance so that pixels exactly on an edge
    # shared by two triangles are not lost (the least >= -eps or the largest <= eps; NaN is neither, as before).
    eps = 1e-6
    inside &= (np.minimum(np.minimum(e0, e1), e2) >= -eps) | (np.maximum(np.maximum(e0, e1), e2) <= eps)
    t_i, k = np.nonzero(inside)
    if len(t_i) == 0:
        return
    u, v = pu[t_i, k % side], pv[t_i, k // side]
    tt = idx[t_i]
    ray = camera.rays(u, v)
    denom = np.einsum("ti,ti->t", normal[tt], ray)
    with np.errstate(divide="ignore", invalid="ignore"):
        z = offset[tt] / denom
    valid = np.isfinite(z) & (z > 0)
    cand_pix.append((v * w + u)[valid])
    cand_z.append(z[valid])
    cand_t.append(tt[valid])


@dataclass(frozen=True)
class SensorNoise:
    """A D435-like depth sensor.

    Attributes
    ----------
    axial_at_03 : float, metres
        Standard deviation of the depth noise at 0.3 m; it grows with the square of the distance
        (1 mm at 0.3 m gives 4 mm at 0.6 m, in line with the D435's published RMS error).
    lateral_px : float, pixels
        Standard deviation of the lateral jitter of each de-projected pixel.
    edge_dropout : float
        Probability that a pixel on an object's silhouette returns no depth.
    grazing_dropout : float
        Probability that a pixel seen at a grazing angle (``facing < grazing``) returns no depth.
    grazing : float
    dropout : float
        Probability that any pixel returns no depth.
    """

    axial_at_03: float = 0.001
    lateral_px: float = 0.3
    edge_dropout: float = 0.5
    grazing_dropout: float = 0.6
    grazing: float = 0.25
    dropout: float = 0.01

    def sigma(self, z: np.ndarray) -> np.ndarray:
        """Axial noise standard deviation at depth ``z`` (metres)."""
        return self.axial_at_03 * (np.asarray(z) / 0.3) ** 2

    def apply(self, rendering: Rendering, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """Noisy depth (0 where no depth returned) and the sub-pixel jitter ``(h, w, 2)`` of each pixel."""
        depth = rendering.depth.copy()
        seen = np.isfinite(depth)
        ids = rendering.ids
        edge = np.zeros_like(seen)
        for axis in (0, 1):
            for step in (1, -1):
                edge |= seen & (np.roll(ids, step, axis=axis) != ids)
        drop = rng.random(depth.shape) < self.dropout
        drop |= edge & (rng.random(depth.shape) < self.edge_dropout)
        drop |= seen & (rendering.facing < self.grazing) & (rng.random(depth.shape) < self.grazing_dropout)
        noisy = np.where(seen, depth + rng.normal(size=depth.shape) * self.sigma(np.where(seen, depth, 0.0)), 0.0)
        noisy[drop | ~seen] = 0.0
        jitter = rng.normal(scale=self.lateral_px, size=depth.shape + (2,))
        return noisy, jitter
