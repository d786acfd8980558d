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

Rays are marched front to back in fixed steps through the candidate's depth range and the first
crossing is refined by linear interpolation of the inside function, so any shape with an inside test is
measured the same way (no per-shape ray casting, no loop over rays).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from .camera import Camera
from .points import as_points
from .raster import Silhouette

__all__ = ["Evidence", "Inside", "Observation", "explain", "march", "observe"]

#: ``inside(x)`` for points ``x`` (..., 3), metres: positive inside the shape (a signed distance, or any
#: function with the same sign), shape ``x.shape[:-1]``.
Inside = Callable[[np.ndarray], np.ndarray]


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
    """

    rays: np.ndarray
    depth: np.ndarray
    rays_in: tuple[np.ndarray, ...]
    rays_out: tuple[np.ndarray, ...]
    contour: float = 1.0


@dataclass(frozen=True)
class Evidence:
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


def _rays(u: np.ndarray, v: np.ndarray, camera: Camera) -> np.ndarray:
    return np.stack([(u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, np.ones_like(u, dtype=float)], -1)


def observe(
    points: np.ndarray,
    region: Silhouette,
    camera: Camera,
    *,
    n_rays: int = 160,
    n_band: int = 64,
    bands: tuple[float, ...] = (2.0, 5.0),
    contour_points: int = 150,
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
        Edge points whose normals decide :attr:`Observation.contour`.
    """
    points = as_points(points, min_count=3)
    sample = points[:: max(1, len(points) // n_rays)]
    rays = sample / sample[:, 2:3]
    mask = region.mask
    inner = ndimage.distance_transform_edt(mask)
    outer = ndimage.distance_transform_edt(~mask)

    def spread(rc: np.ndarray) -> np.ndarray:
        if len(rc) > n_band:
            rc = rc[np.linspace(0, len(rc) - 1, n_band).astype(int)]
        return _rays(rc[:, 1] + region.u0, rc[:, 0] + region.v0, camera)

    rays_in = tuple(spread(np.argwhere((inner > b - 0.5) & (inner <= b + 0.5))) for b in bands)
    rays_out = tuple(spread(np.argwhere((outer > b - 0.5) & (outer <= b + 0.5))) for b in bands)
    contour = _contour_share(points, region, camera, inner, contour_points)
    return Observation(rays=rays, depth=sample[:, 2], rays_in=rays_in, rays_out=rays_out, contour=contour)


def _contour_share(points: np.ndarray, region: Silhouette, camera: Camera, inner: np.ndarray, count: int,
                   k: int = 12) -> float:  # fmt: skip
    """Share of the points within 3 px of the region's edge whose local plane (PCA of their ``k``
    nearest points) is within 60 degrees of containing their ray."""
    uv = camera.project(points)
    col = np.clip(np.rint(uv[:, 0]).astype(np.intp) - region.u0, 0, inner.shape[1] - 1)
    row = np.clip(np.rint(uv[:, 1]).astype(np.intp) - region.v0, 0, inner.shape[0] - 1)
    edge = np.flatnonzero(inner[row, col] <= 3.0)
    if len(edge) < 3 or len(points) < k:
        return 1.0
    edge = edge[:: max(1, len(edge) // count)]
    _, idx = cKDTree(points).query(points[edge], k=k)
    nb = points[idx] - points[idx].mean(axis=1, keepdims=True)
    _, vec = np.linalg.eigh(np.einsum("nki,nkj->nij", nb, nb))
    normal = vec[:, :, 0]
    ray = points[edge] / np.linalg.norm(points[edge], axis=1, keepdims=True)
    return float(np.mean(np.abs(np.einsum("ni,ni->n", normal, ray)) < 0.5))


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
    f = inside(rays[:, None, :] * zs[None, :, None])  # (m, steps)
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


def explain(
    inside: Inside, box: tuple[np.ndarray, np.ndarray], obs: Observation, *, steps: int = 24, trim: float = 0.8
) -> Evidence:
    """Measure one closed candidate against the observation.

    Parameters
    ----------
    inside : callable
        The candidate's inside function (:data:`Inside`).
    box : ((3,), (3,)) float, metres
        The candidate's box: the rays are marched over its depth range (1 mm beyond on both sides).
    obs : Observation
    steps : int
        March steps per ray (:func:`march`).
    trim : float in (0, 1]
        Share of the depth residuals kept (the smallest) for the robust RMS.
    """
    lo, hi = box
    z0, z1 = float(lo[2]) - 1e-3, float(hi[2]) + 1e-3
    n = len(obs.rays)
    every = np.concatenate([obs.rays, *obs.rays_in, *obs.rays_out])  # one march for all rays
    hit_all, depth_all = march(inside, every, z0, z1, steps=steps)
    hit, depth = hit_all[:n], depth_all[:n]
    res = np.where(hit, obs.depth - np.where(hit, depth, 0.0), z1 - z0)
    keep = max(1, int(trim * len(res)))
    r2 = np.partition(res * res, keep - 1)[:keep]
    hits = hit_all[n:]
    ins, outs, k = [], [], 0
    for r in obs.rays_in:
        ins.append(1.0 - hits[k : k + len(r)].mean() if len(r) else 0.0)
        k += len(r)
    for r in obs.rays_out:
        outs.append(hits[k : k + len(r)].mean() if len(r) else 0.0)
        k += len(r)
    return Evidence(depth=float(np.sqrt(r2.mean())), inside=float(np.mean(ins)), outside=float(np.mean(outs)))
