"""Shape fits to a fruit's visible points: sphere, ellipsoid (any orientation and camera-aligned), solid
of revolution, and the surface-noise measure that tells clean scans from depth-camera views.

Every function takes ``points : (n, 3) float, metres`` first and normalises it (:func:`as_points`), takes
its options as keywords, and returns arrays; none knows settings objects or files.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..errors import InputError
from .box import Box
from .points import as_points

__all__ = [
    "ellipsoid_half_extents",
    "fit_aligned_ellipsoid",
    "fit_ellipsoid",
    "fit_revolution",
    "fit_sphere",
    "surface_noise",
]


def fit_sphere(points: np.ndarray, *, refine: bool = True, iterations: int = 10) -> tuple[np.ndarray, float]:
    """Fit a sphere to points.

    The algebraic fit solves ``|p|^2 = 2 c . p + (r^2 - |c|^2)`` in the least-squares sense (points
    are centred first for conditioning); ``refine`` then runs Gauss-Newton on the geometric
    residuals ``|p - c| - r``.

    Parameters
    ----------
    points : (n, 3) float, metres, n >= 4

    Returns
    -------
    centre : (3,) float, metres
    radius : float, metres

    Raises
    ------
    InputError
        When the points are (nearly) coplanar or collinear, so no unique sphere exists.
    """
    points = as_points(points, min_count=4)
    mean = points.mean(axis=0)
    q = points - mean
    scale = float(np.sqrt((q**2).sum(axis=1).mean())) or 1.0
    q = q / scale
    a = np.column_stack([2.0 * q, np.ones(len(q))])
    b = (q**2).sum(axis=1)
    sol, _, rank, sv = np.linalg.lstsq(a, b, rcond=None)
    if rank < 4 or sv[-1] < 1e-6 * sv[0]:
        raise InputError("cannot fit a sphere: the points are (nearly) coplanar or collinear")
    c = sol[:3]
    r = float(np.sqrt(max(sol[3] + c @ c, 1e-12)))
    if refine:
        for _ in range(iterations):
            diff = q - c
            dist = np.linalg.norm(diff, axis=1)
            dist = np.maximum(dist, 1e-12)
            jac = np.column_stack([-diff / dist[:, None], -np.ones(len(q))])
            res = dist - r
            step, *_ = np.linalg.lstsq(jac, -res, rcond=None)
            c = c + step[:3]
            r = float(abs(r + step[3]))
            if np.abs(step).max() < 1e-10:
                break
    return c * scale + mean, r * scale


def fit_ellipsoid(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Fit an ellipsoid ``(x - c)^T A (x - c) = 1`` to points, in any orientation.

    The quadric's ten coefficients are found by the ellipsoid-specific least-squares fit of Li and
    Griffiths (2004), which constrains ``4J - I^2 > 0`` and so returns an ellipsoid even from a
    partial view (points are centred and scaled first for conditioning).

    Parameters
    ----------
    points : (n, 3) float, metres, n >= 10

    Returns
    -------
    centre : (3,) float, metres
    shape : (3, 3) float, symmetric positive definite ``A``

    Raises
    ------
    InputError
        When no ellipsoid fits (degenerate or planar points).
    """
    points = as_points(points, min_count=10)
    mean = points.mean(axis=0)
    scale = float(np.sqrt(((points - mean) ** 2).sum(axis=1).mean())) or 1.0
    x, y, z = ((points - mean) / scale).T
    d = np.column_stack([x * x, y * y, z * z, 2 * y * z, 2 * x * z, 2 * x * y, 2 * x, 2 * y, 2 * z, np.ones_like(x)])
    s = d.T @ d
    s11, s12, s22 = s[:6, :6], s[:6, 6:], s[6:, 6:]
    k = 4.0
    c1 = np.zeros((6, 6))
    c1[:3, :3] = k / 2.0 - 1.0
    np.fill_diagonal(c1[:3, :3], -1.0)
    c1[3:, 3:] = -k * np.eye(3)
    try:
        s22_inv_s21 = np.linalg.solve(s22, s12.T)
        m = np.linalg.solve(c1, s11 - s12 @ s22_inv_s21)
        values, vectors = np.linalg.eig(m)
    except np.linalg.LinAlgError:
        raise InputError("cannot fit an ellipsoid: the points are degenerate") from None
    values, vectors = values.real, vectors.real
    # The solution is the eigenvector of the one positive eigenvalue; on exact data it tends to 0 and
    # may come out a rounding error below it.
    if values.max() < -1e-9 * np.abs(values).max():
        raise InputError("cannot fit an ellipsoid to these points")
    v1 = vectors[:, int(np.argmax(values))]
    v2 = -s22_inv_s21 @ v1
    a, b, c, f, g, h = v1
    p, q, r, dd = v2
    quad = np.array([[a, h, g], [h, b, f], [g, f, c]])
    lin = np.array([p, q, r])
    try:
        centre = -np.linalg.solve(quad, lin)
    except np.linalg.LinAlgError:
        raise InputError("cannot fit an ellipsoid: the quadric has no centre") from None
    level = centre @ quad @ centre - dd
    shape = quad / level
    if not np.all(np.linalg.eigvalsh(shape) > 0):
        raise InputError("cannot fit an ellipsoid: the best quadric is not an ellipsoid")
    return centre * scale + mean, shape / scale**2


def ellipsoid_half_extents(shape: np.ndarray) -> np.ndarray:
    """(3,) float: half the axis-aligned extent of the ellipsoid ``x^T A x = 1`` along x, y, z.

    The box of an ellipsoid with shape matrix ``A`` has half-widths ``sqrt(diag(A^-1))``.
    """
    return np.sqrt(np.diag(np.linalg.inv(np.asarray(shape, dtype=np.float64))))


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
    points = as_points(points, min_count=3)
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
    points = as_points(points, min_count=6)
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
    points = as_points(points, min_count=3)
    normals = as_points(normals, min_count=len(points), name="normals")
    if len(normals) != len(points):
        raise InputError(f"fit_revolution needs one normal per point, got {len(normals)} for {len(points)} points")
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
