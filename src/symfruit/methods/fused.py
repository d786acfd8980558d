"""``fused``: the default method. A shape fit and symmetric completion fused by the data's noise level.

Why: a least-squares sphere is excellent for round fruit and poor for elongated ones; the paper's
mirror completion handles any symmetric shape but samples planes coarsely; a general ellipsoid fits
clean scans superbly and falls apart on noisy depth. ``fused`` measures the noise of the visible
surface (the residual of local plane fits, relative to the fruit's size) and

* on clean data (reconstructed scans): fits a general ellipsoid (Li-Griffiths) and, for fruit whose
  profile says so (strawberries), a solid of revolution whose axis is found from the surface normals
  (every normal of a surface of revolution meets its axis); the boxes are averaged;
* on noisy data (a depth camera): fits an ellipsoid aligned with the camera axes, regularised toward
  a depth extent of ``depth_ratio`` times its lateral ones and robust to outliers (Huber), and runs the
  mirror completion of ``paper`` on a deeper grid; the box takes the fit's size and the centre the
  weighted mean of both centres.

Clean and noisy are told apart by how the surface's roughness grows with scale
(:func:`surface_noise`), which does not depend on the point density.

Every choice here was kept because it won on the evaluation (see ``docs/ablation.md``).

Confidence (``extras["confidence"]``, in [0, 1]) is the share of the fitted fruit's silhouette the
camera saw (occluded or cut views score low), times the agreement of the independent estimates (their
centre spread relative to the fruit's size), times the support (number of points);
``extras["reliable"]`` is ``confidence >= reliable_at``.
"""

from __future__ import annotations

import functools

import numpy as np
from scipy.spatial import cKDTree

from ..box import Box
from ..camera import Camera
from ..config import Settings
from ..errors import InputError
from ..raster import View, rasterise
from . import Completion, register
from .ellipsoid import fit_ellipsoid
from .paper import mirror_complete
from .sphere import fit_sphere

__all__ = ["fit_aligned_ellipsoid", "fit_revolution", "surface_noise"]


def surface_noise(
    points: np.ndarray, small: int = 8, large: int = 30, queries: int = 120
) -> tuple[float, float, np.ndarray]:
    """How much of the surface's roughness is noise: ``(ratio, noise, normals)``.

    The RMS distance of a point's neighbours to their best plane grows with the square of the
    neighbourhood's size where it comes from the surface's curvature (a clean scan) and not at all
    where it comes from sensor noise. ``ratio`` is that residual for the ``large`` nearest neighbours
    over the one for the ``small`` nearest (medians over the points): about 5 on clean scans, about
    2 on depth-camera views, whatever the density. ``noise`` is the small-scale residual (metres);
    ``normals`` (from the small neighbourhoods of the first ``queries`` points, a fixed spread
    subset) face the camera.
    """
    k_large = min(large, len(points))
    step = max(1, len(points) // queries)
    _, idx = cKDTree(points).query(points[::step], k=k_large)
    hood = points[idx]
    k = min(small, k_large)
    near = hood[:, :k] - hood[:, :k].mean(axis=1, keepdims=True)
    values, vectors = np.linalg.eigh(np.einsum("nki,nkj->nij", near, near) / k)
    small_res, normals = np.sqrt(max(float(np.median(values[:, 0])), 0.0)), vectors[:, :, 0]
    wide = hood - hood.mean(axis=1, keepdims=True)
    large_res = np.sqrt(
        max(float(np.median(np.linalg.eigvalsh(np.einsum("nki,nkj->nij", wide, wide) / k_large)[:, 0])), 0.0)
    )
    flip = np.einsum("ni,ni->n", normals, points[::step]) > 0
    normals[flip] *= -1.0
    return large_res / max(small_res, 1e-15), small_res, normals


def _residuals(theta, points, prior, ratio, delta, jac=True):
    centre, axes = theta[:3], np.exp(theta[3:])
    u = (points - centre) / axes
    r = np.maximum(np.linalg.norm(u, axis=1), 1e-12)
    mean_axis = axes.mean()
    res = (r - 1.0) * mean_axis  # about the distance to the surface, metres
    w = np.sqrt(np.where(np.abs(res) <= delta, 1.0, delta / np.maximum(np.abs(res), 1e-15)))
    weight = prior * np.sqrt(len(points)) * mean_axis
    prior_res = weight * (theta[5] - 0.5 * (theta[3] + theta[4]) - np.log(ratio))
    b = np.empty(len(points) + 1)
    b[:-1] = res * w
    b[-1] = prior_res
    if not jac:
        return b, None
    j = np.empty((len(points) + 1, 6))
    scale = (mean_axis * w / r)[:, None]
    j[:-1, :3] = -(u / axes) * scale
    j[:-1, 3:] = -(u * u) * scale
    j[-1] = weight * np.array([0.0, 0.0, 0.0, -0.5, -0.5, 1.0])
    return b, j


def fit_aligned_ellipsoid(
    points: np.ndarray, *, prior: float = 1.0, depth_ratio: float = 1.0, huber: float = 0.002, iterations: int = 15
) -> tuple[np.ndarray, np.ndarray]:
    """Fit an ellipsoid with axes along the camera's x, y, z (its box is the fruit's box).

    Minimises robust (Huber, ``huber`` metres) distances of the points to the surface plus ``prior``
    times the squared log-ratio of the depth semi-axis to ``depth_ratio`` times the geometric mean of
    the lateral ones (the depth of a fruit is barely seen from the front). Levenberg-Marquardt from
    the sphere fit.

    Returns
    -------
    centre : (3,) float, metres
    semi_axes : (3,) float, metres
    """
    centre, radius = fit_sphere(points, refine=False)
    theta = np.concatenate([centre, np.log([radius, radius, radius * depth_ratio])])
    b, jac = _residuals(theta, points, prior, depth_ratio, huber)
    cost, mu = float(b @ b), 1e-3
    for _ in range(iterations):
        h, g = jac.T @ jac, jac.T @ b
        while True:
            step = -np.linalg.solve(h + mu * np.diag(np.diag(h) + 1e-12), g)
            trial = theta + step
            b_new, _ = _residuals(trial, points, prior, depth_ratio, huber, jac=False)
            new = float(b_new @ b_new)
            if new < cost:
                mu = max(mu / 3.0, 1e-9)
                break
            mu *= 4.0
            if mu > 1e8:
                return theta[:3], np.exp(theta[3:])
        theta = trial
        done = cost - new < 1e-6 * cost
        cost = new
        b, jac = _residuals(theta, points, prior, depth_ratio, huber)
        if done:
            break
    return theta[:3], np.exp(theta[3:])


def _hemisphere(n: int) -> np.ndarray:
    i = np.arange(2 * n) + 0.5
    phi = np.arccos(1.0 - 2.0 * i / (2 * n))
    theta = np.pi * (1.0 + 5**0.5) * i
    d = np.c_[np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)]
    return d[d[:, 2] >= 0]


_DIRECTIONS = _hemisphere(300)


def fit_revolution(points: np.ndarray, normals: np.ndarray, *, bins: int = 24) -> tuple[Box, np.ndarray, np.ndarray]:
    """The box of the solid of revolution that best explains the points.

    The axis (point ``a``, direction ``d``) makes every normal line meet it: for each of ~300
    directions at once, ``a`` solves a 3x3 least-squares problem and the direction with the smallest
    trimmed residual wins. The profile is the 90th percentile of the distance to the axis in ``bins``
    slices along it; each slice's ring contributes its exact axis-aligned extent.

    Returns
    -------
    box : Box
    axis_point, axis_direction : (3,) float
    """
    c = points.mean(axis=0)
    q = points - c
    m = np.cross(_DIRECTIONS[:, None, :], normals[None, :, :])  # (k, n, 3)
    b = np.einsum("ni,kni->kn", q, m)
    mm = np.einsum("kni,knj->kij", m, m)
    mm = mm + (1e-9 * np.trace(mm, axis1=1, axis2=2)[:, None, None] + 1e-18) * np.eye(3)
    a = np.linalg.solve(mm, np.einsum("kni,kn->ki", m, b)[..., None])[..., 0]
    res = b - np.einsum("ki,kni->kn", a, m)
    keep = max(1, int(0.8 * res.shape[1]))
    cost = np.partition(res**2, keep - 1, axis=1)[:, :keep].mean(axis=1)
    k = int(np.argmin(cost))
    a0, d = a[k] + c, _DIRECTIONS[k]
    t = (points - a0) @ d
    rho = np.linalg.norm((points - a0) - t[:, None] * d, axis=1)
    edges = np.quantile(t, np.linspace(0.0, 1.0, bins + 1))
    which = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, bins - 1)
    spread = np.sqrt(np.clip(1.0 - d**2, 0.0, None))
    lo, hi = points.min(axis=0), points.max(axis=0)
    for j in range(bins):  # a loop over profile slices (24), not over points or hypotheses
        sel = which == j
        if sel.sum() < 3:
            continue
        r = np.quantile(rho[sel], 0.9)
        for tt in (t[sel].min(), t[sel].max()):
            ring = a0 + tt * d
            lo, hi = np.minimum(lo, ring - r * spread), np.maximum(hi, ring + r * spread)
    return Box(lo, hi), a0, d


def _mean_box(boxes: list[Box]) -> Box:
    """The box with the mean centre and the mean size of ``boxes``."""
    centre = np.mean([b.centre for b in boxes], axis=0)
    size = np.mean([b.size for b in boxes], axis=0)
    return Box(centre - size / 2.0, centre + size / 2.0)


@register("fused")
def fused(points: np.ndarray, camera: Camera, settings: Settings) -> Completion:
    """A shape fit and symmetric completion, fused by the noise level; with a confidence."""
    s = settings.fused
    sample = points
    if len(points) > s.fit_points:
        sample = points[np.sort(np.random.default_rng(0).choice(len(points), s.fit_points, replace=False))]
    extent = float(np.ptp(points, axis=0).max())
    ratio, noise, normals = surface_noise(sample)
    step = max(1, len(sample) // 120)
    centres: list[np.ndarray] = []
    view, plane = None, None
    extras: dict = {"noise": noise, "roughness_ratio": ratio}
    if ratio >= s.clean_ratio:
        extras["regime"] = "clean"
        try:
            c, shape = fit_ellipsoid(sample)
            with np.errstate(invalid="ignore"):
                half = np.sqrt(np.diag(np.linalg.inv(shape)))
            if not (np.all(np.isfinite(half)) and np.all(np.isfinite(c)) and half.max() < 10 * extent):
                raise InputError("the ellipsoid fit is degenerate")
            boxes = [Box(c - half, c + half)]
        except (InputError, np.linalg.LinAlgError):
            c, r = fit_sphere(sample)
            boxes = [Box(c - r, c + r)]
        if s.revolution:
            rev, a0, d = fit_revolution(sample[::step], normals)
            boxes.append(rev)
            extras["axis"] = {"point": a0.tolist(), "direction": d.tolist()}
        box = _mean_box(boxes)
        sphere_centre, _ = fit_sphere(sample)
        centres = [box.centre, *(b.centre for b in boxes), sphere_centre]  # the spread feeds the confidence
    else:
        extras["regime"] = "noisy"
        thin = sample[:: max(1, -(-len(sample) // s.shape_points))]  # a spread subset for the fit
        c, axes = fit_aligned_ellipsoid(thin, prior=s.depth_prior, depth_ratio=s.depth_ratio, huber=s.huber)
        if not (np.all(np.isfinite(c)) and np.all(np.isfinite(axes)) and axes.max() < 10 * extent):
            c, radius = fit_sphere(sample)  # a degenerate fit: fall back to the sphere
            axes = np.full(3, radius)
        fit_box = Box(c - axes, c + axes)
        view = rasterise(sample, camera)
        mirrored = mirror_complete(sample, camera, _mirror_settings(settings).paper, view)
        w = s.mirror_weight
        centre = (1.0 - w) * fit_box.centre + w * mirrored.box.centre
        size = (1.0 - s.mirror_size) * fit_box.size + s.mirror_size * mirrored.box.size
        box = Box(centre - size / 2.0, centre + size / 2.0)
        centres = [box.centre, fit_box.centre, mirrored.box.centre]
        plane = mirrored.plane
        extras.update(semi_axes=axes.tolist(), mirror_score=mirrored.score)
    box = box.union(Box.from_points(points))
    spread = max(float(np.linalg.norm(other - centres[0])) for other in centres)
    coverage = silhouette_coverage(view if view is not None else rasterise(sample, camera), box, camera)
    confidence = _confidence(spread, coverage, float(box.size.max()), len(points), s)
    extras.update(confidence=confidence, reliable=confidence >= s.reliable_at, spread=spread, coverage=coverage)
    completed = np.vstack([points, 2.0 * box.centre - points])
    return Completion(points=completed, box=box, plane=plane, extras=extras)


@functools.lru_cache(maxsize=32)
def _mirror_settings(settings: Settings) -> Settings:
    """The ``paper`` settings of the fused mirror completion (cached: settings are immutable)."""
    s = settings.fused
    grid = {"translations": s.mirror_translations, "translation_step": s.mirror_translation_step,
            "j2": s.mirror_j2, "j3": s.mirror_j3, "rating_points": s.mirror_points}  # fmt: skip
    return settings.replace(paper=grid)


def silhouette_coverage(view: View, box: Box, camera: Camera) -> float:
    """Share of the fitted fruit's silhouette that the camera saw: how much of the ellipse inscribed in
    the box's projection (at the box centre's depth) the rasterised visible points (``view``) cover.
    Occluded, cut or sparse views cover less."""
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


def _confidence(spread: float, coverage: float, size: float, n: int, s) -> float:
    """Silhouette coverage x agreement of the estimates x support, in [0, 1]."""
    agree = np.exp(-spread / (s.spread_scale * size))
    support = min(1.0, n / s.min_support)
    return float(np.clip(coverage * agree * support, 0.0, 1.0))
