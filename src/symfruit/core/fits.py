"""Shape fits to a fruit's visible points: sphere, ellipsoid (any orientation and camera-aligned), solid
of revolution (axis from the normal lines, or from slice circles without normals), and the surface-noise
measure that tells clean scans from depth-camera views.

Every function takes ``points : (n, 3) float, metres`` first and normalises it (:func:`as_points`), takes
its options as keywords, and returns arrays; none knows settings objects or files.

The loops of the sphere's, the solid of revolution's and the cone ellipsoid's fits (and the marching of the solid
of revolution) and the neighbourhoods of :func:`surface_noise` run as compiled kernels where numba (the extra
``fast``) is installed (:mod:`symfruit.core.kernels`); the numpy code here is their twin, run without numba or with
``SYMFRUIT_KERNELS=numpy``, and gives the same results within rounding.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ..errors import InputError
from . import lapack
from .box import Box
from .camera import Camera
from .kernels import compiled
from .points import as_points, column_means, cross_rows, median, perpendicular_basis, row_norms, squared_norms

__all__ = [
    "ConeFit",
    "Revolution",
    "RevolutionInside",
    "ScaledCloud",
    "box_and_profile",
    "closed_profile",
    "cone_ellipsoid",
    "cone_thickness_bound",
    "ellipsoid_half_extents",
    "fit_aligned_ellipsoid",
    "fit_cone_ellipsoid",
    "fit_ellipsoid",
    "fit_revolution",
    "fit_revolution_slices",
    "fit_sphere",
    "noise_level",
    "noise_measures",
    "outline_radii",
    "revolution_box",
    "revolution_inside",
    "scaled_cloud",
    "surface_noise",
]


@dataclass(frozen=True)
class ScaledCloud:
    """A cloud centred on its mean and scaled to a unit RMS distance from it, with the designs of :func:`fit_sphere`'s
    and :func:`fit_ellipsoid`'s algebraic fits (:func:`scaled_cloud`): both fits of one sample take it, made once.

    Attributes
    ----------
    mean : (3,) float, metres
    scale : float, metres
        The RMS distance from the mean (1 where it is 0).
    q : (n, 3) float
        ``(points - mean) / scale``.
    sphere_design, sphere_rhs : (n, 4), (n,) float
        ``[2 q, 1]`` and ``|q|^2``.
    ellipsoid_design : (n, 10) float
        ``[x^2, y^2, z^2, 2yz, 2xz, 2xy, 2x, 2y, 2z, 1]`` of ``q``'s columns.
    """

    mean: np.ndarray
    scale: float
    q: np.ndarray
    sphere_design: np.ndarray
    sphere_rhs: np.ndarray
    ellipsoid_design: np.ndarray


def scaled_cloud(points: np.ndarray) -> ScaledCloud:
    """:class:`ScaledCloud` of ``points`` (n, 3), n >= 1: by the compiled twin :func:`symfruit.core._jit.scaled_cloud`
    where numba is installed (one call, each value these expressions' bit for bit; issue 19, twentieth round)."""
    points = as_points(points, min_count=1)
    if (jit := compiled()) is not None:
        return ScaledCloud(*jit.scaled_cloud(points))
    mean = column_means(points)  # points.mean(axis=0), ((q**2).sum(axis=1)): the same values in fewer calls
    q = points - mean
    scale = float(np.sqrt(squared_norms(q).mean())) or 1.0
    q = q / scale
    x, y, z = q.T
    d = np.column_stack([x * x, y * y, z * z, 2 * y * z, 2 * x * z, 2 * x * y, 2 * x, 2 * y, 2 * z, np.ones_like(x)])
    return ScaledCloud(mean, scale, q, np.column_stack([2.0 * q, np.ones(len(q))]), squared_norms(q), d)


def fit_sphere(
    points: np.ndarray,
    *,
    refine: bool = True,
    iterations: int = 10,
    tolerance: float = 1e-7,
    scaled: ScaledCloud | None = None,
) -> tuple[np.ndarray, float]:
    """Fit a sphere to points.

    The algebraic fit solves ``|p|^2 = 2 c . p + (r^2 - |c|^2)`` in the least-squares sense (points
    are centred first for conditioning); ``refine`` then runs Gauss-Newton on the geometric
    residuals ``|p - c| - r``.

    Parameters
    ----------
    points : (n, 3) float, metres, n >= 4
    refine : bool
    iterations : int
        Gauss-Newton steps at most.
    tolerance : float, metres
        Gauss-Newton stops once a step moves the centre and radius by less than this (issue 19, seventh
        round: a tenth of a micrometre instead of 1e-10 of the points' spread, a few picometres, which most
        fits never reached: on the benchmark frames' fruit 5-10 steps, mean 7.6, instead of 8-10, mean 9.8;
        the same boxes to 0.001 mm on every evaluation instance of docs/ablation.md's checks).
    scaled : ScaledCloud, optional
        :func:`scaled_cloud` of ``points``, where the caller has made it (it is made here otherwise).

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
    if scaled is None and compiled() is not None:
        scaled = scaled_cloud(points)
    if scaled is not None:
        mean, scale, q, a, b = scaled.mean, scaled.scale, scaled.q, scaled.sphere_design, scaled.sphere_rhs
    else:  # scaled_cloud's numpy twin, the sphere's part alone
        mean = column_means(points)
        q = points - mean
        scale = float(np.sqrt(squared_norms(q).mean())) or 1.0
        q = q / scale
        a = np.column_stack([2.0 * q, np.ones(len(q))])
        b = squared_norms(q)
    sol, rank, sv = lapack.lstsq(a, b)  # np.linalg.lstsq(a, b, rcond=None) but its residuals
    if rank < 4 or sv[-1] < 1e-6 * sv[0]:
        raise InputError("cannot fit a sphere: the points are (nearly) coplanar or collinear")
    c = sol[:3]
    r = float(np.sqrt(max(sol[3] + c @ c, 1e-12)))
    if refine and (jit := compiled()) is not None:  # the compiled twin of the loop below
        c_jit = np.array(c)
        r_jit, ok = jit.sphere_steps(q, c_jit, r, iterations, tolerance, scale)
        if ok:
            return c_jit * scale + mean, r_jit * scale
    if refine:
        jac = np.empty((len(q), 4))
        jac[:, 3] = -1.0
        for _ in range(iterations):
            diff = q - c
            dist = np.maximum(np.sqrt(np.einsum("ij,ij->i", diff, diff)), 1e-12)
            np.divide(diff, -dist[:, None], out=jac[:, :3])
            res = dist - r
            try:  # the 4x4 normal equations (the algebraic fit above has checked the points' rank)
                step = np.linalg.solve(jac.T @ jac, -(jac.T @ res))
            except np.linalg.LinAlgError:
                step, *_ = np.linalg.lstsq(jac, -res, rcond=None)
            c = c + step[:3]
            r = float(abs(r + step[3]))
            if np.abs(step).max() * scale < tolerance:
                break
    return c * scale + mean, r * scale


def fit_ellipsoid(points: np.ndarray, *, scaled: ScaledCloud | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Fit an ellipsoid ``(x - c)^T A (x - c) = 1`` to points, in any orientation.

    The quadric's ten coefficients are found by the ellipsoid-specific least-squares fit of Li and
    Griffiths (2004), which constrains ``4J - I^2 > 0`` and so returns an ellipsoid even from a
    partial view (points are centred and scaled first for conditioning).

    Parameters
    ----------
    points : (n, 3) float, metres, n >= 10
    scaled : ScaledCloud, optional
        :func:`scaled_cloud` of ``points``, where the caller has made it (it is made here otherwise).

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
    cloud = scaled_cloud(points) if scaled is None else scaled
    mean, scale, d = cloud.mean, cloud.scale, cloud.ellipsoid_design
    s = d.T @ d
    s11, s12, s22 = s[:6, :6], s[:6, 6:], s[6:, 6:]
    try:
        s22_inv_s21 = lapack.solve(s22, s12.T)
        m = lapack.solve(_LI_GRIFFITHS, s11 - s12 @ s22_inv_s21)
        values, vectors = lapack.eig_real(m)  # the real parts of np.linalg.eig's
    except np.linalg.LinAlgError:
        raise InputError("cannot fit an ellipsoid: the points are degenerate") from None
    # The solution is the eigenvector of the one positive eigenvalue; on exact data it tends to 0 and
    # may come out a rounding error below it.
    if values.max() < -1e-9 * np.abs(values).max():
        raise InputError("cannot fit an ellipsoid to these points")
    v1 = vectors[:, int(np.argmax(values))]
    v2 = -s22_inv_s21 @ v1
    a, b, c, f, g, h = v1.tolist()  # Python floats: the same float64 values in the arrays below (issue 19, stop 45)
    p, q, r, dd = v2.tolist()
    quad = np.array([[a, h, g], [h, b, f], [g, f, c]])
    lin = np.array([p, q, r])
    try:
        centre = -lapack.solve(quad, lin)
    except np.linalg.LinAlgError:
        raise InputError("cannot fit an ellipsoid: the quadric has no centre") from None
    level = centre @ quad @ centre - dd
    shape = quad / level
    # every eigenvalue above 0: decided without LAPACK where a bound makes it sure (issue 19, stop 62)
    if not lapack.surely_positive3(shape) and not (lapack.eigvalsh(shape) > 0).all():
        raise InputError("cannot fit an ellipsoid: the best quadric is not an ellipsoid")
    return centre * scale + mean, shape / scale**2


def _li_griffiths_constraint(k: float = 4.0) -> np.ndarray:
    """(6, 6), read-only: the constraint matrix ``C1`` of Li and Griffiths' fit (:func:`fit_ellipsoid`), made once."""
    c1 = np.zeros((6, 6))
    c1[:3, :3] = k / 2.0 - 1.0
    np.fill_diagonal(c1[:3, :3], -1.0)
    c1[3:, 3:] = -k * np.eye(3)
    c1.flags.writeable = False
    return c1


_LI_GRIFFITHS = _li_griffiths_constraint()


def ellipsoid_half_extents(shape: np.ndarray) -> np.ndarray:
    """(3,) float: half the axis-aligned extent of the ellipsoid ``x^T A x = 1`` along x, y, z.

    The box of an ellipsoid with shape matrix ``A`` has half-widths ``sqrt(diag(A^-1))``.
    """
    return np.sqrt(lapack.inv(np.asarray(shape, dtype=np.float64)).diagonal())  # np.diag's values, one call less


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
    k = min(small, k_large)
    jit = compiled()
    if jit is not None and len(points) * len(range(0, len(points), step)) <= _BRUTE_NEIGHBOURS:
        cov_small, cov_large = jit.neighbour_covariances(points, step, k, k_large)  # the compiled twin
    else:
        cov_small, cov_large = _neighbour_covariances(points, step, k, k_large)
    values, vectors = np.linalg.eigh(cov_small)
    # medians by core.points.median: np.median's values, without its general-axis machinery
    small_res, normals = np.sqrt(max(float(median(values[:, 0])), 0.0)), vectors[:, :, 0]
    large_res = np.sqrt(max(float(median(np.linalg.eigvalsh(cov_large)[:, 0])), 0.0))
    flip = np.einsum("ni,ni->n", normals, points[::step]) > 0
    normals[flip] *= -1.0
    return large_res / max(small_res, 1e-15), small_res, normals


def noise_measures(points: np.ndarray, small: int = 8, large: int = 30, queries: int = 120) -> tuple[float, float]:
    """:func:`surface_noise`'s ``(ratio, noise)`` without its normals (the default method reads nothing else): by
    the compiled twin :func:`symfruit.core._jit.noise_measures` where numba is installed and the brute force's bound
    allows (one call for the neighbourhoods, their least eigenvalues and medians: the same values to rounding, the
    eigenvalues LAPACK's there; issue 19, seventeenth round), else ``surface_noise(...)[:2]``."""
    points = as_points(points, min_count=3)
    k_large = min(large, len(points))
    step = max(1, len(points) // queries)
    jit = compiled()
    if jit is not None and len(points) * len(range(0, len(points), step)) <= _BRUTE_NEIGHBOURS:
        ratio, noise = jit.noise_measures(points, step, min(small, k_large), k_large)
        return float(ratio), float(noise)
    ratio, noise, _ = surface_noise(points, small, large, queries)
    return ratio, noise


def noise_level(points: np.ndarray, small: int = 8, large: int = 30, queries: int = 120) -> float:
    """``noise_measures(points, small, large, queries)[1]``, the same value: by the compiled
    :func:`symfruit.core._jit.noise_level` where :func:`noise_measures` calls its kernel (the ``small``
    neighbourhoods alone, no ``large`` ones: the same neighbours, covariances and median; issue 19, stop 48), else
    :func:`noise_measures`' value."""
    points = as_points(points, min_count=3)
    k_large = min(large, len(points))
    step = max(1, len(points) // queries)
    jit = compiled()
    if jit is not None and len(points) * len(range(0, len(points), step)) <= _BRUTE_NEIGHBOURS:
        return float(jit.noise_level(points, step, min(small, k_large), k_large))
    return noise_measures(points, small, large, queries)[1]


#: :func:`surface_noise` finds neighbours by the kernel's brute force up to this many distances (points times
#: queries: 40,000 in the default method's call on 1,000 points), by a search tree beyond.
_BRUTE_NEIGHBOURS = 5_000_000


def _neighbour_covariances(points: np.ndarray, step: int, small: int, large: int) -> tuple[np.ndarray, np.ndarray]:
    """``(m, 3, 3), (m, 3, 3)``: for each query point ``points[::step]``, the covariance of its ``small`` and its
    ``large`` nearest points (itself among them), each about its own mean (:func:`surface_noise`; its compiled
    twin is :func:`symfruit.core._jit.neighbour_covariances`). Up to ``_BRUTE_NEIGHBOURS`` distances the nearest
    are the kernel's: a search tree's ``large + 8`` nearest, their squared distances summed as the kernel sums
    them and put in a stable order (ties by index), every distance worked out where a tie may reach past those
    (:func:`_nearest_in_order`), so that a tie straddling the ``small``-th or ``large``-th place (a depth camera's
    points lie on a pixel grid) is broken alike with and without numba; beyond, the search tree's order."""
    queries = points[::step]
    if len(points) * len(queries) <= _BRUTE_NEIGHBOURS:
        idx = _nearest_in_order(points, queries, large)
    else:
        _, idx = cKDTree(points).query(queries, k=large)
    hood = points[idx]
    near = hood[:, :small] - hood[:, :small].mean(axis=1, keepdims=True)
    wide = hood - hood.mean(axis=1, keepdims=True)
    return np.einsum("nki,nkj->nij", near, near) / small, np.einsum("nki,nkj->nij", wide, wide) / large


def _squared_distances(points: np.ndarray, queries: np.ndarray, idx: np.ndarray | None = None) -> np.ndarray:
    """Squared distances of ``points`` (n, 3) (or of ``points[idx]``, idx (m, k)) from each of ``queries`` (m, 3),
    summed ``dx * dx + dy * dy + dz * dz`` left to right, as :func:`symfruit.core._jit.neighbour_covariances` does."""
    d: np.ndarray | None = None
    for axis in range(3):
        e = (points[:, axis][None, :] if idx is None else points[idx, axis]) - queries[:, axis][:, None]
        e *= e
        d = e if d is None else d + e
    assert d is not None
    return d


def _nearest_in_order(points: np.ndarray, queries: np.ndarray, large: int) -> np.ndarray:
    """``(m, large)``: the indices of each query's ``large`` nearest ``points`` in the order of a stable sort of
    :func:`_squared_distances` (ties by index), the kernel's. A search tree offers ``large + 8`` candidates; a row
    whose last candidate is not farther than its ``large``-th (a tie that may reach past the candidates, beyond
    rounding) is sorted over every point."""
    n = len(points)
    offered = min(large + 8, n)
    _, cand = cKDTree(points).query(queries, k=offered)
    cand = cand.reshape(len(queries), offered)
    d = _squared_distances(points, queries, cand)
    order = np.lexsort((cand, d), axis=-1)
    cand, d = np.take_along_axis(cand, order, axis=1), np.take_along_axis(d, order, axis=1)
    idx = np.ascontiguousarray(cand[:, :large])
    if offered < n:
        loose = ~(d[:, -1] > d[:, large - 1] * (1.0 + 1e-9) + 1e-300)
        for row in np.flatnonzero(loose):  # rare: a tie (or a cluster of duplicates) as wide as the offer
            full = _squared_distances(points, queries[row : row + 1])[0]
            idx[row] = np.argsort(full, kind="stable")[:large]
    return idx


def _residuals(theta, points, prior, ratio, delta, jac=True):
    centre, axes = theta[:3], np.exp(theta[3:])
    u = (points - centre) / axes
    r = np.maximum(row_norms(u), 1e-12)
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
    rho = row_norms((points - a0) - t[:, None] * d)
    edges = np.quantile(t, np.linspace(0.0, 1.0, bins + 1))
    which = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, bins - 1)
    lo, hi = points.min(axis=0), points.max(axis=0)
    ring_t, ring_r = [], []
    for j in range(bins):  # a loop over profile slices (24), not over points or hypotheses
        sel = which == j
        if sel.sum() < 3:
            continue
        r = np.quantile(rho[sel], 0.9)
        ring_t += [t[sel].min(), t[sel].max()]
        ring_r += [r, r]
    if ring_t:
        rlo, rhi = _rings_box(a0, d, np.array(ring_t), np.array(ring_r))
        lo, hi = np.minimum(lo, rlo), np.maximum(hi, rhi)
    return Box(lo, hi), a0, d


def _rings_box(point: np.ndarray, direction: np.ndarray, t: np.ndarray, r: np.ndarray, ratio: float = 1.0,
               deep: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Axis-aligned box ``(min, max)`` of rings of radius ``r`` (k,) centred on ``point + t direction`` (k,)
    in the planes perpendicular to ``direction`` (unit): a ring spans ``r sqrt(1 - d_i^2)`` along axis ``i``. With
    ``ratio`` other than 1 and ``deep`` (unit), the rings and their axis squashed about ``point`` by ``ratio`` along
    ``deep`` (the map ``S = I + (ratio - 1) deep deep^T``; see :class:`Revolution`): ring centres ``point + t S
    direction``, each an ellipse spanning ``r sqrt((S^2)_ii - (S direction)_i^2)`` along axis ``i``."""
    if ratio != 1.0 and deep is not None:
        direction = _squash(direction, deep, ratio)
        spread = np.sqrt(np.clip(1.0 + (ratio * ratio - 1.0) * deep**2 - direction**2, 0.0, None))
    else:
        spread = np.sqrt(np.clip(1.0 - direction**2, 0.0, None))
    centres = point[None, :] + t[:, None] * direction[None, :]
    return (centres - r[:, None] * spread).min(axis=0), (centres + r[:, None] * spread).max(axis=0)


# --- solid of revolution without normals: slice circles ---------------------------------------------------


@dataclass(frozen=True)
class Revolution:
    """A solid of revolution: axis ``point + t * direction``, radius ``radii[j]`` over slice ``j``.

    Attributes
    ----------
    point : (3,) float, metres
    direction : (3,) float, unit
    edges : (b + 1,) float, metres
        Slice borders along the axis (``t``), covering the fitted points.
    radii : (b,) float, metres
        Radius of each slice (NaN where a slice had fewer than 3 points).
    cost : float, metres^2
        Robust mean squared distance of the points to their slice circles.
    ratio : float
        The solid is this solid of revolution (circular sections) squashed about ``point`` by ``ratio`` along
        ``deep``: the map ``x -> point + S (x - point)``, ``S = I + (ratio - 1) deep deep^T`` (1: none). With the
        axis across ``deep`` every section is an ellipse, ``radii[j]`` across and ``ratio radii[j]`` along ``deep``
        (issue 18, stop 44, docs/revol44.md). ``direction``, ``edges`` and ``radii`` are the circular solid's.
    deep : (3,) float, unit, optional
        The direction squashed (the line of sight to the fitted points' centre; None when ``ratio`` is 1).
    """

    point: np.ndarray
    direction: np.ndarray
    edges: np.ndarray
    radii: np.ndarray
    cost: float
    ratio: float = 1.0
    deep: np.ndarray | None = None


def _slice_costs(q: np.ndarray, dirs: np.ndarray, bins: int) -> np.ndarray:
    """Robust cost (k,) of every axis direction ``dirs`` (k, 3) for centred points ``q`` (n, 3).

    For one direction the points, projected on the plane perpendicular to it (coordinates ``w``) and
    grouped in ``bins`` slices along it, must lie on circles with one common centre ``c``: ``|w|^2 = 2 c . w
    + (r_j^2 - |c|^2)``. Centring ``|w|^2`` and ``w`` within each slice removes the per-slice offsets and
    leaves a 2-unknown least-squares problem per direction, solved for all directions at once; the
    algebraic residual over ``2 rho`` is about the distance to the circle. The lower 80 % of the squared
    distances count (stems, calyx, flying pixels).

    The (k, n) arithmetic runs in place on a few buffers, each operation the plain expression's in the same
    order (the same bits; the tests keep the plain expressions): at 70 directions and 250 points every
    temporary is larger than the allocator's mmap threshold (128 kB), and the plain expressions' fresh ones
    took 2.4 times as long (850 against 350 us a call).
    """
    k, n = len(dirs), len(q)
    e1, e2 = perpendicular_basis(dirs)
    t = dirs @ q.T  # (k, n): one row per direction, reductions along contiguous rows
    u = e1 @ q.T
    v = e2 @ q.T
    lo, hi = t.min(axis=1, keepdims=True), t.max(axis=1, keepdims=True)
    t -= lo  # t is not needed again: the slice index in its place
    t /= np.maximum(hi - lo, 1e-12)
    t *= bins
    idx = t.astype(np.int64)
    np.minimum(idx, bins - 1, out=idx)
    idx += bins * np.arange(k)[:, None]
    idx = idx.ravel()
    safe = np.maximum(np.bincount(idx, minlength=k * bins), 1).astype(np.float64)
    y = np.multiply(u, u)
    buf = np.multiply(v, v, out=t)
    y += buf

    def centred(x: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        mean = np.bincount(idx, weights=x.ravel(), minlength=k * bins) / safe
        return np.subtract(x, np.take(mean, idx).reshape(k, n), out=out)

    du, dv, dy = centred(u), centred(v), centred(y, out=y)
    a11 = np.multiply(du, du, out=buf).sum(1)
    a12 = np.multiply(du, dv, out=buf).sum(1)
    a22 = np.multiply(dv, dv, out=buf).sum(1)
    b1 = np.multiply(du, dy, out=buf).sum(1)
    b2 = np.multiply(dv, dy, out=buf).sum(1)
    det = a11 * a22 - a12 * a12
    det = np.where(np.abs(det) > 1e-30, det, 1e-30)
    au = (0.5 * (a22 * b1 - a12 * b2) / det)[:, None]
    av = (0.5 * (a11 * b2 - a12 * b1) / det)[:, None]
    # res = dy - 2 (au du + av dv); rho2 = (u - au)^2 + (v - av)^2; dist2 = res^2 / (4 max(rho2, 1e-12))
    res = np.multiply(au, du, out=du)
    res += np.multiply(av, dv, out=dv)
    res *= 2.0
    res = np.subtract(dy, res, out=dy)
    u -= au
    u *= u
    v -= av
    v *= v
    rho2 = np.add(u, v, out=u)
    np.maximum(rho2, 1e-12, out=rho2)
    rho2 *= 4.0
    res *= res
    dist2 = np.divide(res, rho2, out=res)
    keep = max(1, int(0.8 * n))
    dist2.partition(keep - 1, axis=1)
    return dist2[:, :keep].mean(axis=1)


def _cap(direction: np.ndarray, spread_deg: float, n: int) -> np.ndarray:
    """``direction`` and ``n`` directions within ``spread_deg`` of it (a Fibonacci cap), unit rows, z >= 0."""
    e1, e2 = perpendicular_basis(direction[None, :])
    rot = np.stack([e1[0], e2[0], direction], axis=1)
    out = np.vstack([direction[None, :], _cap_local(float(spread_deg), int(n)) @ rot.T])
    return out * np.where(out[:, 2:3] < 0, -1.0, 1.0)


@functools.lru_cache(maxsize=16)
def _cap_local(spread_deg: float, n: int) -> np.ndarray:
    """(n, 3) float, read-only: the Fibonacci cap of :func:`_cap` about ``+z`` (it depends on the spread and the
    count alone, so it is made once per pair)."""
    i = np.arange(n) + 0.5
    z = 1.0 - (1.0 - np.cos(np.radians(spread_deg))) * i / n
    r = np.sqrt(np.clip(1.0 - z * z, 0.0, None))
    theta = np.pi * (1.0 + 5**0.5) * i
    local = np.stack((r * np.cos(theta), r * np.sin(theta), z), axis=1)
    local.flags.writeable = False
    return local


@functools.lru_cache(maxsize=16)
def _cap_locals(spreads: tuple[float, ...], n: int) -> np.ndarray:
    """(len(spreads), n, 3) float, read-only: :func:`_cap_local` of each spread, for the compiled search
    (:func:`symfruit.core._jit.revolution_search`)."""
    out = np.stack([_cap_local(spread, n) for spread in spreads]) if spreads else np.empty((0, n, 3))
    out.flags.writeable = False
    return out


_COARSE = _hemisphere(64)


def _revolution_steps(w: np.ndarray, which: np.ndarray, cnt: np.ndarray, a2: np.ndarray, steps: int) -> None:
    """:func:`fit_revolution_slices`' Gauss-Newton on the axis position ``a2`` (2,), refined in place: the points'
    distances from the axis in the plane (coordinates ``w`` (n, 2)) less their slice's mean distance (slice
    ``which`` (n,) of ``b``, ``cnt`` (b,) its points, at least 1), at most ``steps`` steps (the numpy twin of
    :func:`symfruit.core._jit.revolution_steps`)."""
    b = len(cnt)
    # Each step's three slice means (of rho and of the two Jacobian columns) come from one bincount over the
    # three stacked (each bin adds its values in the same order as a bincount of its own: the same sums).
    which3 = np.concatenate((which, which + b, which + 2 * b))
    for _ in range(steps):
        diff = w - a2
        rho = np.sqrt(diff[:, 0] * diff[:, 0] + diff[:, 1] * diff[:, 1])  # numpy sums 2 terms left to right
        np.maximum(rho, 1e-12, out=rho)
        jac = np.negative(diff, out=diff)
        jac /= rho[:, None]
        sums = np.bincount(which3, weights=np.concatenate((rho, jac[:, 0], jac[:, 1])), minlength=3 * b)
        means = sums.reshape(3, b) / cnt
        res = rho - means[0][which]
        jac -= np.take(means[1:].T, which, axis=0)  # rows by np.take: 5x faster than [which] here
        jtj = jac.T @ jac
        if abs(np.linalg.det(jtj)) < 1e-30:
            break
        step = np.linalg.solve(jtj, -(jac.T @ res))  # the normal equations of the 2-unknown step
        a2 += step
        if np.abs(step).max() < 1e-7:
            break


def _revolution_profile(
    q: np.ndarray, best: np.ndarray, e1: np.ndarray, e2: np.ndarray, bins: int, steps: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, bool]:
    """:func:`fit_revolution_slices` about the chosen direction ``best`` (3,) for centred points ``q`` (n, 3)
    (``e1``, ``e2`` (3,) the plane's basis): the axis position in the plane (2,), the profile's ``bins`` slice
    borders along the axis (b + 1,), their radii (b,), the robust cost, and True (the numpy twin of
    :func:`symfruit.core._jit.revolution_profile`)."""
    t = q @ best
    w = np.stack((q @ e1, q @ e2), axis=1)
    edges = np.linspace(t.min(), t.max(), bins + 1)
    which = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, bins - 1)
    counts = np.bincount(which, minlength=bins)
    cnt = np.maximum(counts, 1)
    # Start: the algebraic axis offset on the profile slices, then Gauss-Newton on rho_i - mean_slice(rho).
    ww = w - w.mean(axis=0)
    y = (ww * ww).sum(axis=1)
    dy = y - (np.bincount(which, weights=y, minlength=bins) / cnt)[which]
    dw = ww - np.take(np.stack([np.bincount(which, weights=ww[:, i], minlength=bins) / cnt
                                for i in range(2)], axis=1), which, axis=0)  # fmt: skip
    sol, *_ = np.linalg.lstsq(2.0 * dw, dy, rcond=None)
    a2 = sol + w.mean(axis=0)  # refined in place
    _revolution_steps(np.ascontiguousarray(w), which, cnt.astype(np.float64), a2, steps)
    rho = row_norms(w - a2)
    mean_r = np.bincount(which, weights=rho, minlength=bins) / cnt
    radii = np.where(counts >= 3, mean_r, np.nan)
    res2 = np.sort((rho - mean_r[which]) ** 2)
    return a2, edges, radii, float(res2[: max(1, int(0.8 * len(res2)))].mean()), True


def fit_revolution_slices(
    points: np.ndarray,
    *,
    bins: int = 12,
    profile_bins: int = 16,
    extra_directions: np.ndarray | None = None,
    refine_deg: tuple[float, ...] = (12.0, 4.0),
    refine_n: int = 16,
    gauss_newton_steps: int = 5,
    search_points: int = 240,
    coarse: int = 64,
    ratio: float = 1.0,
) -> Revolution:
    """Fit a solid of revolution to points seen from one side, without normals.

    A surface of revolution meets every plane perpendicular to its axis in a circle centred on the axis,
    so the axis direction is the one for which the points, sliced along it, lie on concentric circles
    (:func:`_slice_costs`, every direction at once). Unlike :func:`fit_revolution` (normal lines), it
    uses only positions, so it holds up under depth noise that ruins local normals, and a slice needs
    only an arc of its circle. The search is coarse to fine: ~64 directions over the hemisphere (plus
    ``extra_directions``), then ``refine_n`` directions within each ``refine_deg``. The axis position is
    refined by Gauss-Newton on the distances to the slice circles (the algebraic fit of an arc seen
    from one side is biased towards the arc); the profile is the mean distance to the axis per slice.

    Parameters
    ----------
    points : (n, 3) float, metres, n >= 20
    bins : int
        Slices along each candidate direction during the search.
    profile_bins : int
        Slices of the final profile.
    extra_directions : (m, 3) float, optional
        More candidate directions for the coarse stage (e.g. an ellipsoid fit's axes).
    refine_deg : tuple of float, degrees
    refine_n : int
    gauss_newton_steps : int
    search_points : int
        The direction search uses an evenly spread subset of at most this many points.
    coarse : int
        Directions of the coarse stage over the hemisphere (about; 0: ``extra_directions`` only).
    ratio : float
        The sections' depth over their width: the solid is fitted to the points stretched by ``1 / ratio`` along
        the line of sight to their centre (the camera at the origin) and squashed back (:class:`Revolution`'s
        ``ratio`` and ``deep``); 1: circular sections, the fit as before (issue 18, stop 44: the view's own fit
        cannot tell the ratio, docs/revol44.md, so nothing in the library sets it).

    Returns
    -------
    Revolution

    Raises
    ------
    InputError
        On fewer than 20 finite points.
    """
    pts = as_points(points, min_count=1)
    jit = compiled()
    every = max(1, len(pts) // search_points)
    # the finite test, the centre, the centred points and the search's every-th of them in one call where the kernels
    # are (issue 19, stop 65, cand65: the same values; as_points' arrays are C-ordered float64)
    ready = jit.revolution_points(pts, every) if jit is not None and len(pts) >= 20 else None
    if ready is not None and ready[0]:
        _, centre, q, qs = ready
    else:
        if not np.isfinite(pts).all():  # a short last-axis reduction is slow: only when something is not finite
            pts = pts[np.isfinite(pts).all(axis=1)]
        if len(pts) < 20:
            raise InputError(f"a solid of revolution needs at least 20 points, got {len(pts)}")
        centre = column_means(pts)
        q = pts - centre
        qs = q[:: max(1, len(q) // search_points)]
    deep = centre / max(float(np.linalg.norm(centre)), 1e-12) if ratio != 1.0 else None  # the line of sight
    if deep is not None:  # the circular solid is fitted to the points stretched along it
        q = _squash(q, deep, 1.0 / ratio)
        qs = q[:: max(1, len(q) // search_points)]
    dirs = _COARSE if coarse == 64 else _hemisphere(coarse) if coarse > 0 else np.empty((0, 3))
    if extra_directions is not None:
        dirs = _revolution_directions(dirs, np.asarray(extra_directions, dtype=np.float64).reshape(-1, 3))
    if not len(dirs):
        raise InputError("fit_revolution_slices needs coarse directions or extra_directions")
    if jit is not None:  # the compiled twin of the search below, coarse and fine in one call
        caps = _cap_locals(tuple(float(d) for d in refine_deg), int(refine_n))
        best = jit.revolution_search(np.ascontiguousarray(qs), np.ascontiguousarray(dirs), bins, caps)
    else:
        best = dirs[int(np.argmin(_slice_costs(qs, dirs, bins)))]
        for spread in refine_deg:
            cand = _cap(best, spread, refine_n)
            best = cand[int(np.argmin(_slice_costs(qs, cand, bins)))]
    e1, e2 = perpendicular_basis(best[None, :])
    found = None if jit is None else jit.revolution_profile(q, best, e1[0], e2[0], profile_bins, gauss_newton_steps)
    if found is None or not found[4]:  # no kernel, or a singular start (the twin's least squares copes)
        found = _revolution_profile(q, best, e1[0], e2[0], profile_bins, gauss_newton_steps)
    a2, edges, radii, cost = found[0], found[1], found[2], float(found[3])
    (a, b), (c0, c1, c2), e1_, e2_ = a2.tolist(), centre.tolist(), e1[0].tolist(), e2[0].tolist()
    # centre + a2[0] e1 + a2[1] e2 in Python floats: numpy's operations, component by component, in the same order
    axis_point = np.array([c0 + a * e1_[0] + b * e2_[0], c1 + a * e1_[1] + b * e2_[1], c2 + a * e1_[2] + b * e2_[2]])
    edges = edges + float(centre @ best - axis_point @ best)
    if deep is None:
        return Revolution(axis_point, best, edges, radii, cost)
    # Fitted to the points stretched along the line of sight: the solid is that fit squashed back about the centre
    return Revolution(centre + _squash(axis_point - centre, deep, ratio), best, edges, radii, cost, ratio, deep)


def _revolution_directions(dirs: np.ndarray, extra: np.ndarray) -> np.ndarray:
    """(k + m, 3): the coarse directions ``dirs`` (k, 3) followed by the ``extra`` ones (m, 3) made unit and turned to
    ``z >= 0``; by the compiled twin :func:`symfruit.core._jit.revolution_directions` where numba is (the same values,
    one call for five; issue 19, stop 45)."""
    if (jit := compiled()) is not None and dirs.dtype == np.float64 and dirs.ndim == 2 and dirs.shape[1] == 3:
        return jit.revolution_directions(np.ascontiguousarray(dirs), np.ascontiguousarray(extra))
    extra = extra / np.linalg.norm(extra, axis=1, keepdims=True)
    return np.vstack([dirs, extra * np.where(extra[:, 2:3] < 0, -1.0, 1.0)])


def outline_radii(rev: Revolution, mask: np.ndarray, origin: tuple[int, int], camera: Camera,
                  *, step: float = 0.25, hidden: np.ndarray | None = None) -> np.ndarray:  # fmt: skip
    """Each slice's radius as the seen outline shows it: ``(b,)`` float, metres (NaN where it cannot).

    The ring of slice ``j`` (centre ``c = point + t_j direction``) reaches farthest across the line of
    sight along ``e = direction x c / |...|``, perpendicular to the axis and to the ray: there the surface
    is seen edge-on, so ``c +- r e`` project onto the silhouette's outline whatever the axis's tilt. The
    outline is found by walking from ``c``'s pixel along ``e``'s image direction, both ways, in ``step``
    pixels, to the first pixel outside ``mask``; each crossing is carried back to the line ``c + s e``
    (the point of that line nearest the crossing's ray), and the radius is the mean of the two reaches.
    The outline is measured to a pixel, not blurred by depth noise, so this profile is sharper than the
    points' (a tapered fruit's shoulders, a pear's body).

    Parameters
    ----------
    rev : Revolution
    mask : (h, w) bool
        The seen region, whose top-left pixel is ``origin = (u0, v0)``.
    camera : Camera
    hidden : (h, w) bool, optional
        Pixels (same window) where the camera could not have seen the fruit: a crossing onto one is an
        occluder's edge, not the outline: that slice gets no radius.
    """
    axis = rev.direction if rev.ratio == 1.0 or rev.deep is None else _squash(rev.direction, rev.deep, rev.ratio)
    h, w = mask.shape
    reach = 2.0 * max(h, w)
    s = np.arange(step, reach, step)  # (m,)
    if (jit := compiled()) is not None and _plain_outline(rev, axis, mask, hidden):  # one call (stop 65, cand65)
        return jit.outline_radii(rev.point, axis, rev.edges, float(camera.fx), float(camera.fy), float(camera.cx),
                                 float(camera.cy), s.astype(np.float64, copy=False), float(origin[0]),
                                 float(origin[1]), mask, mask if hidden is None else hidden, hidden is not None,
                                 float(step))  # fmt: skip
    mid = 0.5 * (rev.edges[:-1] + rev.edges[1:])
    c = rev.point[None, :] + mid[:, None] * axis[None, :]  # (b, 3)
    e = cross_rows(axis, c)
    e /= np.maximum(row_norms(e), 1e-12)[:, None]
    uc = camera.project(c)
    du = camera.project(c + 1e-3 * e) - uc
    du /= np.maximum(row_norms(du), 1e-12)[:, None]
    radii = np.full(len(mid), np.nan)
    found = []
    b = len(mid)
    # both sides' walks at once (the second's rows the first's, the other way): vectorised over slices and steps
    walks = _first_out(np.concatenate((uc, uc)), np.concatenate((du, -du)), s, origin, mask)
    for side, sign in enumerate((1.0, -1.0)):
        start, first, row, col, inside = (x[side * b : (side + 1) * b] for x in walks)
        ok = start & (first >= 0) & inside  # the outline, not the window's edge
        first = np.maximum(first, 0)  # np.argmax's 0 where no step leaves the mask
        if hidden is not None:
            r_, c_ = np.clip(row, 0, h - 1), np.clip(col, 0, w - 1)
            ok &= ~hidden[r_, c_]
        edge_px = (first - 0.5) * step  # halfway between the last pixel in and the first out
        bu = uc[:, 0] + sign * edge_px * du[:, 0]
        bv = uc[:, 1] + sign * edge_px * du[:, 1]
        ray = camera.rays(bu, bv)
        # The point c + s e nearest the ray lambda * ray: least squares in (s, lambda).
        a11, a12, a22 = (e * e).sum(1), -(e * ray).sum(1), (ray * ray).sum(1)
        b1, b2 = -(e * c).sum(1), (ray * c).sum(1)
        det = a11 * a22 - a12 * a12
        sv = (a22 * b1 - a12 * b2) / np.where(np.abs(det) > 1e-18, det, np.nan)
        found.append(np.where(ok, sign * sv, np.nan))
    both = np.isfinite(found[0]) & np.isfinite(found[1])
    radii[both] = 0.5 * (found[0][both] + found[1][both])
    return np.where(radii > 0, radii, np.nan)


def _plain_outline(rev: Revolution, axis: np.ndarray, mask: np.ndarray, hidden: np.ndarray | None) -> bool:
    """Whether :func:`outline_radii`'s arguments are those :func:`symfruit.core._jit.outline_radii` takes: the solid's
    point, axis and (1-d) slice borders float64 arrays of 3, 3 and at least one value, ``mask`` a 2-d bool array and
    ``hidden`` none or a bool array of its shape."""
    return (
        all(type(x) is np.ndarray and x.dtype == np.float64 and x.ndim == 1 for x in (rev.point, axis, rev.edges))
        and len(rev.point) == len(axis) == 3
        and len(rev.edges) >= 1
        and type(mask) is np.ndarray
        and mask.dtype == np.bool_
        and mask.ndim == 2
        and (hidden is None or (type(hidden) is np.ndarray and hidden.dtype == np.bool_ and hidden.shape == mask.shape))
    )


def _first_out(uc: np.ndarray, way: np.ndarray, s: np.ndarray, origin: tuple[int, int],
               mask: np.ndarray) -> tuple[np.ndarray, ...]:  # fmt: skip
    """:func:`outline_radii`'s walks: from each pixel ``uc`` (b, 2) along ``way`` (b, 2) (a slice's image direction,
    its side's sign applied) by ``s`` (m,) pixels, to the first step whose pixel (rounded, less ``origin``) is not
    one of ``mask``'s (off the window counts as out). ``(start, first, row, col, inside)``, each (b,): whether the
    first step is in the mask, the first step out (-1: none), and that step's pixel and whether it lies in the window
    (at step 0 where there is none). Walked a block of steps at a time, the slices still in the mask alone, until
    each has left it (half the window's larger side a block: the fruit's radius, about): each step's pixel is
    computed on its own, as over every slice and step at once, so the same steps (4-5 times fewer pixels read)."""
    h, w = mask.shape
    n = len(uc)
    first = np.full(n, -1, np.intp)
    row, col, inside = np.zeros(n, np.intp), np.zeros(n, np.intp), np.zeros(n, bool)
    start = np.zeros(n, bool)
    todo = np.arange(n)
    block = max(1, math.ceil(0.5 * max(h, w) / float(s[0]))) if len(s) else 1
    for j0 in range(0, len(s), block):
        sj = s[j0 : j0 + block]
        pu = uc[todo, None, 0] + sj[None, :] * way[todo, None, 0] - origin[0]
        pv = uc[todo, None, 1] + sj[None, :] * way[todo, None, 1] - origin[1]
        c, r = np.rint(pu).astype(np.intp), np.rint(pv).astype(np.intp)
        within = (c >= 0) & (c < w) & (r >= 0) & (r < h)
        hit = np.zeros_like(within)
        hit[within] = mask[r[within], c[within]]
        out = ~hit
        at = np.argmax(out, axis=1)
        k = np.arange(len(todo))
        if j0 == 0:  # step 0: the start, and np.argmax's pick where no step leaves the mask
            start = hit[:, 0].copy()
            row, col, inside = r[:, 0].copy(), c[:, 0].copy(), within[:, 0].copy()
        left = out.any(axis=1)
        done, at, k = todo[left], at[left], k[left]
        first[done] = j0 + at
        row[done], col[done], inside[done] = r[k, at], c[k, at], within[k, at]
        todo = todo[~left]
        if not len(todo):
            break
    return start, first, row, col, inside


def closed_profile(rev: Revolution, *, close: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Slice positions and radii of a fitted solid, an unseen end closed: ``(t (m,), r (m,))``, metres.

    A fruit's profile closes at both ends. Where the seen profile is still widening when the data stop
    (its widest slice is the first or the last: the far half of a fruit seen end-on hides behind its widest
    ring), the missing half is the mirror image of the seen one about the end slice. Seen end-on (the axis
    within 45 deg of the line of sight, ``direction[2] ** 2 >= 0.5``), the far end is closed so too when no
    slice from the widest to it is narrower than the widest by more than the fit's own RMS, ``sqrt(cost)``: the
    slice at the widest ring, seen edge-on, reads a hair narrower than the one before it. A profile that
    narrows towards an end by more than that, however bluntly, or whose near end, or whose end seen across
    the line of sight (where a mirrored half would show beside the outline), falls short of the widest at
    all, ends there. ``close=False``: the seen profile as it is.

    Issue 18, stop 42 (docs/scan42.md): with the widest slice required to be the end one, the end-on views of
    the paper protocol's pears and lemons (and the real pear stood up) were closed at their deepest seen point
    on most views, as short as the raw box, the rim's slice reading 0.2-1 mm under the one before it.
    """
    mid = 0.5 * (rev.edges[:-1] + rev.edges[1:])
    ok = np.isfinite(rev.radii)
    t, r = mid[ok], rev.radii[ok]
    if len(t) < 2:
        return np.array([rev.edges[0], rev.edges[-1]]), np.zeros(2)
    widest = int(np.argmax(r))
    floor = r[widest] - _flat(rev)
    along = float(rev.direction[2])
    endon = along * along >= 0.5  # the axis nearer the line of sight than the image plane
    if close and (widest == len(t) - 1 or (endon and along > 0 and bool((r[widest:] >= floor).all()))):
        t, r = np.concatenate((t, 2 * t[-1] - t[:-1][::-1])), np.concatenate((r, r[:-1][::-1]))
    elif close and (widest == 0 or (endon and along < 0 and bool((r[: widest + 1] >= floor).all()))):
        t, r = np.concatenate((2 * t[0] - t[1:][::-1], t)), np.concatenate((r[1:][::-1], r))
    return t, r


def _flat(rev: Revolution) -> float:
    """How far a slice's radius may fall short of the widest one's and still be no narrowing, metres: the fit's own
    RMS distance of the points to their slice circles (``sqrt(cost)``). A slice's radius is read to about that (its
    points' mean distance to the axis), so a profile's end within it of the widest radius is the widest ring seen
    edge-on, not an end closing (issue 18, stop 42)."""
    return float(np.sqrt(max(float(rev.cost), 0.0)))


def revolution_box(rev: Revolution, *, close: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned box ``(min (3,), max (3,))``, metres, of a fitted solid (see :func:`closed_profile`)."""
    lo, hi, _, _ = box_and_profile(rev, close=close)
    return lo, hi


def box_and_profile(rev: Revolution, *, close: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`revolution_box` and the :func:`closed_profile` it is the box of: ``(lo (3,), hi (3,), t (m,), r (m,))``;
    by the compiled twin :func:`symfruit.core._jit.revolution_box` where numba is installed (one call for some 15
    numpy calls, each value theirs; issue 19, stop 41). The profile is handed to :class:`RevolutionInside`, whose
    march needs it again."""
    jit = compiled()
    if jit is not None and rev.edges.shape == (len(rev.radii) + 1,) and rev.radii.ndim == 1 and len(rev.radii):
        lo, hi, t, r = jit.revolution_box(
            np.ascontiguousarray(rev.point, dtype=np.float64), np.ascontiguousarray(rev.direction, dtype=np.float64),
            np.ascontiguousarray(rev.edges, dtype=np.float64), np.ascontiguousarray(rev.radii, dtype=np.float64),
            bool(close), _flat(rev),
        )  # fmt: skip
        if rev.ratio != 1.0 and rev.deep is not None:  # elliptic sections: the same profile, their box
            lo, hi = _rings_box(rev.point, rev.direction, t, r, rev.ratio, rev.deep)
        return lo, hi, t, r
    t, r = closed_profile(rev, close=close)
    return (*_rings_box(rev.point, rev.direction, t, r, rev.ratio, rev.deep), t, r)


def _squash(x: np.ndarray, deep: np.ndarray, ratio: float) -> np.ndarray:
    """Vectors ``x`` (n, 3) (or (3,)) with their component along ``deep`` (unit) times ``ratio``."""
    along = x @ deep
    return x + np.multiply.outer((ratio - 1.0) * along, deep)


def _unsquash(rev: Revolution, x: np.ndarray) -> np.ndarray:
    """Vectors ``x`` (n, 3) from ``rev.point`` mapped into the solid of circular sections ``rev`` was fitted as: their
    component along ``rev.deep`` divided by ``rev.ratio``."""
    return _squash(x, np.asarray(rev.deep, dtype=np.float64), 1.0 / rev.ratio)


def revolution_inside(rev: Revolution, x: np.ndarray, *, close: bool = True) -> np.ndarray:
    """Signed inside measure of points ``x`` (..., 3): the profile's radius minus the distance to the axis,
    metres (positive inside; beyond the profile's ends, minus the distance past the end as well)."""
    t_prof, r_prof = closed_profile(rev, close=close)
    x = np.asarray(x, dtype=np.float64)
    shape = x.shape[:-1]
    flat = x.reshape(-1, 3)
    # Component by component: ``x - point`` and ``rel - t direction`` broadcast over a last axis of 3 ran numpy's
    # inner loop once per point (a march's 6,000 points: several times the arithmetic); these are the same
    # subtractions and products, one strided pass per component, and ``rel @ direction`` the same product.
    rel = np.empty_like(flat)
    for c in range(3):  # three components, not a loop over points
        np.subtract(flat[:, c], rev.point[c], out=rel[:, c])
    if rev.ratio != 1.0 and rev.deep is not None:  # elliptic sections: measured in the circular solid they map to
        rel = _unsquash(rev, rel)
    t = rel @ rev.direction
    off = [rel[:, c] - t * rev.direction[c] for c in range(3)]
    total = off[0] * off[0] + off[1] * off[1]  # as row_norms: numpy sums the three squares left to right
    total += off[2] * off[2]
    rho = np.sqrt(total)
    r = np.interp(t, t_prof, r_prof, left=0.0, right=0.0)
    past = np.maximum(t_prof[0] - t, 0.0) + np.maximum(t - t_prof[-1], 0.0)
    return (r - rho - past).reshape(shape)


@dataclass(frozen=True, eq=False)
class RevolutionInside:
    """:func:`revolution_inside` of a fitted solid as an inside test (:data:`symfruit.core.agreement.Inside`) whose
    rays are marched by a compiled kernel where numba is installed (:meth:`march`; its twin is
    :func:`symfruit.core.agreement.march` of this test)."""

    rev: Revolution
    close: bool = True
    #: :func:`closed_profile` ``(t, r)`` of ``rev`` with ``close``, where the caller has it (:func:`box_and_profile`)
    profile: tuple[np.ndarray, np.ndarray] | None = None

    def __call__(self, x: np.ndarray) -> np.ndarray:
        return revolution_inside(self.rev, x, close=self.close)

    def march(self, rays: np.ndarray, z0: float, z1: float, steps: int) -> tuple[np.ndarray, np.ndarray] | None:
        """``(hit (m,), depth (m,))`` of :func:`symfruit.core.agreement.march` along rays (m, 3) by the compiled
        kernel (each ray stopped at its first step inside), or None without it."""
        jit = compiled()
        if jit is None:
            return None
        t, r = closed_profile(self.rev, close=self.close) if self.profile is None else self.profile
        point = np.asarray(self.rev.point, dtype=np.float64)
        if self.rev.ratio != 1.0 and self.rev.deep is not None:
            # Elliptic sections: the rays and the axis point mapped (a linear map: the ray z * ray goes to
            # z * unsquashed ray) into the circular solid, where the kernel marches the same depths z.
            point, rays = _unsquash(self.rev, point[None, :])[0], _unsquash(self.rev, np.asarray(rays, np.float64))
        return jit.revolution_march(
            np.ascontiguousarray(point), np.ascontiguousarray(self.rev.direction, dtype=np.float64),
            np.ascontiguousarray(t, dtype=np.float64), np.ascontiguousarray(r, dtype=np.float64),
            np.ascontiguousarray(rays, dtype=np.float64), float(z0), float(z1), int(steps),
        )  # fmt: skip


# --- ellipsoid tangent to the silhouette's viewing cone ----------------------------------------------------


def cone_ellipsoid(
    params: np.ndarray, cone: np.ndarray, axis: np.ndarray, *, cone_inv: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The ellipsoids tangent to a viewing cone, from their parameters ``(a, b, log d, tau)`` (k, 4).

    An ellipsoid ``(x - m)^T S^-1 (x - m) = 1`` seen from the origin has the tangent cone whose dual is
    ``m m^T - S``; so every ellipsoid with the silhouette's cone ``x^T C x = 0`` (``C`` with signature
    ``(+, +, -)``, negative inside) is ``S = lambda C^-1 + m m^T`` for a centre ``m`` inside the cone and
    ``0 < lambda < -m^T C m`` (then ``S`` is positive definite). Here ``m = d (axis + (a, b, 0))`` and
    ``lambda = -m^T C m / (1 + exp(-tau))``, so every parameter vector is a valid ellipsoid with exactly
    that outline; ``tau`` trades depth for width (large: flat across the line of sight).

    ``cone_inv``, ``C^-1``, may be passed when known.

    Returns
    -------
    centre : (k, 3) float, metres
    shape : (k, 3, 3) float, ``S`` (NaN where the centre falls outside the cone)
    valid : (k,) bool
    """
    p = np.atleast_2d(np.asarray(params, dtype=np.float64))
    offset = np.zeros((len(p), 3))
    offset[:, :2] = p[:, :2]
    m = np.exp(p[:, 2:3]) * (axis[None, :] + offset)
    q = -((m @ cone) * m).sum(axis=1)
    valid = q > 0
    lam = np.where(valid, q, np.nan) / (1.0 + np.exp(-np.clip(p[:, 3], -50.0, 50.0)))
    inv = np.linalg.inv(cone) if cone_inv is None else cone_inv
    shape = lam[:, None, None] * inv[None] + m[:, :, None] * m[:, None, :]
    return m, shape, valid


def _cone_fronts(params: np.ndarray, cone: np.ndarray, axis: np.ndarray, rays: np.ndarray,
                 ray_cone: np.ndarray, *, split: int = 0) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Front depth (k, n) along rays (n, ``z = 1``) of the ellipsoids of :func:`cone_ellipsoid` with parameters
    (k, 4), straight from the cone (NaN where a ray misses), and which parameters are valid (k,).

    ``split``: the parameter rows before it and from it on go through separate matrix products, so that each
    group's values are, to the bit, those of a call with that group alone (OpenBLAS rounds a one-row product,
    a matrix-vector kernel, differently from the same row of a many-row product; every other operation here
    is row by row). :func:`fit_cone_ellipsoid` evaluates a trial step and the Jacobian about it in one call.

    With ``S = lambda C^-1 + m m^T`` and ``q = -m^T C m``, Sherman-Morrison gives ``S^-1 = C / lambda - C m m^T C
    / (lambda (lambda - q))``, so along a ray ``r`` the quadratic ``a z^2 - 2 b z + c`` of
    ``(z r - m)^T S^-1 (z r - m) - 1`` has ``a = r^T C r / lambda - (r^T C m)^2 / (lambda (lambda - q))``, ``b =
    r^T C m / (lambda - q)`` and ``c = -lambda / (lambda - q)``: no 3x3 inverse per ellipsoid, no (k, n, 3)
    product. ``ray_cone`` is ``r^T C r`` of every ray (n,).
    """
    p = np.atleast_2d(params)
    m = np.empty((len(p), 3))
    m[:, :2] = axis[:2] + p[:, :2]
    m[:, 2] = axis[2]
    m *= np.exp(p[:, 2:3])
    if 0 < split < len(p):
        cm = np.empty_like(m)
        rcm = np.empty((len(p), len(rays)))
        for group in (slice(0, split), slice(split, None)):  # two groups, not a loop over hypotheses
            np.matmul(m[group], cone, out=cm[group])
            np.matmul(cm[group], rays.T, out=rcm[group])
    else:
        cm = m @ cone  # (k, 3); C is symmetric
        rcm = cm @ rays.T  # (k, n)
    q = -(cm * m).sum(axis=1)
    valid = q > 0
    lam = np.where(valid, q, np.nan) / (1.0 + np.exp(-np.clip(p[:, 3], -50.0, 50.0)))
    gap = (lam - q)[:, None]  # < 0; 0 once the logistic saturates (p[3] above about 37): no front, NaN rows
    with np.errstate(invalid="ignore", divide="ignore"):
        a = ray_cone[None, :] / lam[:, None] - rcm * rcm / (lam[:, None] * gap)
        b = rcm / gap
        c = -lam[:, None] / gap
        disc = b * b - a * c
        root = np.sqrt(np.maximum(disc, 0.0))
        return np.where(disc >= 0, (b - root) / a, np.nan), valid


def _cone_front(m: np.ndarray, shape: np.ndarray, rays: np.ndarray) -> np.ndarray:
    """Front depth (k, n) of ellipsoids (k) along rays (n, ``z = 1``); NaN where a ray misses."""
    inv = np.linalg.inv(shape)
    a = ((rays[None] @ inv) * rays[None]).sum(axis=2)  # (k, n)
    im = (inv @ m[:, :, None])[:, :, 0]
    b = im @ rays.T  # (k, n)
    c = (m * im).sum(axis=1) - 1.0
    disc = b * b - a * c[:, None]
    root = np.sqrt(np.maximum(disc, 0.0))
    return np.where(disc >= 0, (b - root) / a, np.nan)


def _cone_grid(front: float, extent: float) -> np.ndarray:
    """(49, 4): :func:`fit_cone_ellipsoid`'s starting grid, every centre depth ``front + (0.15 .. 1) extent`` (7)
    with every ``tau`` in ``-4 .. 4`` (7), the depth the slower index, no lateral offset (built by whole
    columns: a nested list of 49 rows cost more than the fit's first evaluation)."""
    grid = np.zeros((49, 4))
    grid[:, 2] = np.repeat(np.log(front + 0.5 * extent * _GRID_DEPTHS), 7)
    grid[:, 3] = _GRID_TAUS
    return grid


#: :func:`_cone_grid`'s depth multiples and its ``tau`` column, made once (the same values; their three numpy calls
#: were a tenth of the cone fit's call outside its kernel).
_GRID_DEPTHS = np.linspace(0.3, 2.0, 7)
_GRID_TAUS = np.tile(np.linspace(-4.0, 4.0, 7), 7)
_GRID_DEPTHS.flags.writeable = _GRID_TAUS.flags.writeable = False


#: LAPACK's relative machine precision (``dlamch('E')``, half numpy's ``eps``) and its square, as ``dsterf`` uses them.
_LAPACK_EPS = 2.0**-53
_LAPACK_EPS2 = _LAPACK_EPS * _LAPACK_EPS


def _plain(*values: float) -> bool:
    """Whether every value is zero or of a magnitude within 1e-100 .. 1e100: where LAPACK scales nothing and OpenBLAS
    divides nothing by a tiny pivot's reciprocal, so :func:`eigenvalues2` and :func:`solve2` repeat it."""
    for v in values:  # a loop, not all() of a generator: the same test, a call fewer per value (issue 19, stop 46)
        if not (v == 0.0 or 1e-100 < abs(v) < 1e100):
            return False
    return True


def eigenvalues2(a: float, b: float, c: float) -> tuple[float, float] | None:
    """The eigenvalues of the symmetric matrix ``[[a, b], [b, c]]``, least first, as ``np.linalg.eigvalsh`` gives
    them (LAPACK's ``dsyevd``, whose ``dsterf`` splits off a negligible ``b`` and otherwise takes a 2x2 block's
    eigenvalues from ``dlae2``): the same values bit for bit (tested against numpy), in Python floats, about 1 us
    against the call's 20-30 (issue 19, nineteenth round). None where LAPACK would scale the matrix (a value beyond
    :func:`_plain`'s range) or one is not finite: ask numpy there."""
    if not _plain(a, b, c):
        return None
    if b == 0.0 or abs(b) <= (math.sqrt(abs(a)) * math.sqrt(abs(c))) * _LAPACK_EPS or \
            b * b <= _LAPACK_EPS2 * abs(a * c):  # fmt: skip
        return (a, c) if a <= c else (c, a)
    b = math.sqrt(b * b)  # dsterf squares the off-diagonal and hands dlae2 its root
    sm, adf, ab = a + c, abs(a - c), abs(b + b)
    big, small = (a, c) if abs(a) > abs(c) else (c, a)
    # ``x**2`` as gfortran compiles it, ``x * x`` (Python's ``**`` rounds through ``pow``, otherwise than the product
    # in about 3 of 100,000 matrices: then a value an ulp from numpy's; stop 64, docs/comp64.md)
    if adf > ab:
        q = ab / adf
        rt = adf * math.sqrt(1.0 + q * q)
    elif adf < ab:
        q = adf / ab
        rt = ab * math.sqrt(1.0 + q * q)
    else:
        rt = ab * math.sqrt(2.0)
    if sm < 0.0:
        rt1 = 0.5 * (sm - rt)
        rt2 = (big / rt1) * small - (b / rt1) * b
    elif sm > 0.0:
        rt1 = 0.5 * (sm + rt)
        rt2 = (big / rt1) * small - (b / rt1) * b
    else:
        rt1, rt2 = 0.5 * rt, -0.5 * rt
    return (rt1, rt2) if rt1 <= rt2 else (rt2, rt1)


def solve2(a00: float, a01: float, a10: float, a11: float, b0: float, b1: float) -> tuple[float, float] | None:
    """``np.linalg.solve([[a00, a01], [a10, a11]], [b0, b1])`` as OpenBLAS's ``dgesv`` works it out (partial
    pivoting, the column below the pivot multiplied by the pivot's reciprocal, the triangular solves by division):
    the same values bit for bit (tested against numpy), in Python floats (issue 19, nineteenth round). Raises
    ``np.linalg.LinAlgError`` where numpy does (an exactly zero pivot); None where a value is not finite or beyond
    :func:`_plain`'s range: ask numpy there."""
    if not _plain(a00, a01, a10, a11, b0, b1):
        return None
    if abs(a10) > abs(a00):
        a00, a01, a10, a11, b0, b1 = a10, a11, a00, a01, b1, b0
    if a00 == 0.0:
        raise np.linalg.LinAlgError("Singular matrix")
    low = a10 * (1.0 / a00)
    u11 = a11 - low * a01
    if u11 == 0.0:
        raise np.linalg.LinAlgError("Singular matrix")
    x1 = (b1 - low * b0) / u11
    return (b0 - a01 * x1) / a00, x1


def cone_thickness_bound(cone: np.ndarray, min_thickness: float) -> float:
    """The largest shape parameter ``tau`` of :func:`cone_ellipsoid` whose ellipsoid is at least ``min_thickness``
    of the outline's narrowest width deep along the line of sight.

    For a cone about the optical axis with half-angle tangents ``t_1 <= t_2`` and a centre on its axis, ``lambda =
    q s`` with ``s`` the logistic of ``tau`` gives ``S_zz = d^2 (1 - s)`` and ``S_xx = d^2 t_1^2 s``: the depth
    over the narrowest width is ``exp(-tau / 2) / t_1``, so the bound is ``-2 log(min_thickness t_1)``. ``t_1`` is
    the narrowest semi-axis of the cone's section by the plane ``z = 1`` (off the axis, the same to first order).
    ``inf`` for ``min_thickness <= 0`` or a cone without such a section.
    """
    if min_thickness <= 0:
        return float("inf")
    (a00, a01, b0), (a10, a11, b1), (_, _, c) = np.asarray(cone, dtype=np.float64).tolist()
    # numpy's solve and eigvalsh of the 2x2 block by their closed forms where those repeat LAPACK's values (Python
    # floats: b @ x, a dot of two, sums left to right as numpy's does)
    x = solve2(a00, a01, a10, a11, b0, b1)
    values = eigenvalues2(a00, a10, a11)  # eigvalsh reads the lower triangle
    if x is None or values is None:
        a, b = np.asarray(cone, dtype=np.float64)[:2, :2], np.asarray(cone, dtype=np.float64)[:2, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            x, values = tuple(np.linalg.solve(a, b).tolist()), tuple(np.linalg.eigvalsh(a).tolist())
    k = b0 * x[0] + b1 * x[1] - c
    top = values[1]
    narrow = math.sqrt(k / top) if k > 0 and top > 0 else float("nan")
    if not np.isfinite(narrow) or narrow <= 0:
        return float("inf")
    return float(-2.0 * np.log(min_thickness * narrow))


@dataclass(frozen=True)
class ConeFit:
    """The ellipsoid of :func:`fit_cone_ellipsoid`.

    Attributes
    ----------
    centre : (3,) float, metres
    shape : (3, 3) float
        ``S``: the ellipsoid is ``(x - centre)^T S^-1 (x - centre) <= 1``; its box has half-widths
        ``sqrt(diag(S))``.
    back_std : float, metres
        Standard deviation of its back face's depth from the fit (the depths' noise carried through the
        four parameters; NaN when it cannot be had).
    rms : float, metres
        Robust RMS of the depth residuals.
    """

    centre: np.ndarray
    shape: np.ndarray
    back_std: float
    rms: float


def fit_cone_ellipsoid(
    points: np.ndarray,
    *,
    cone: np.ndarray,
    axis: np.ndarray,
    front: float,
    extent: float,
    huber: float = 0.003,
    iterations: int = 10,
    tolerance: float = 1e-4,
    max_points: int = 300,
    min_thickness: float = 0.25,
) -> ConeFit:
    """The ellipsoid whose outline is the silhouette and whose front best fits the seen depths.

    The silhouette fixes five of an ellipsoid's nine degrees of freedom (its tangent cone from the camera,
    :func:`cone_ellipsoid`); the remaining four (the centre's depth and lateral offset, the depth/width
    trade) are fitted to the seen depths along the seen points' rays, which is where a depth camera's
    noise lies (axial), by Levenberg-Marquardt with Huber weights (``huber`` metres), from the best of a
    grid of depths and elongations. The lateral extent never depends on the noisy depths, and the back
    of the fruit follows from the front by the ellipsoid's symmetry.

    Parameters
    ----------
    points : (n, 3) float, metres, n >= 8
        Seen points away from the silhouette's edge (near the edge the depth is steep and unreliable).
    cone : (3, 3) float
        The silhouette's viewing cone in normalised image coordinates (:func:`symfruit.core.raster.
        silhouette_cone`).
    axis : (3,) float
        A ray inside the cone (``z = 1``), e.g. through the silhouette's centroid.
    front : float, metres
        Depth of the nearest surface point (where the grid search starts).
    extent : float, metres
        About the fruit's size (the grid's depth range).
    huber : float, metres
    iterations, tolerance : int, float
        Levenberg-Marquardt stops after this many iterations, or when a step lowers the cost by less than
        ``tolerance`` of it.
    max_points : int
        The fit uses an evenly spread subset of at most this many points (four parameters are set by a
        few hundred depths as well as by thousands).
    min_thickness : float
        The ellipsoid's depth along the line of sight is kept at least this share of the outline's narrowest
        width (:func:`cone_thickness_bound`, a bound on ``tau``). As ``tau`` grows the ellipsoid flattens into
        a disc in the plane of the outline, whose tilt fits an elongated fruit's front (a banana seen from the
        side) as well as any ellipsoid; the logistic then saturates, the fit no longer depends on ``tau`` and
        where it stops is decided by rounding (the last bits of a BLAS kernel moved such boxes by up to 13 mm).
        No fruit is a flat disc; 0.25 leaves every fit that does not run into one as it was.

    Returns
    -------
    ConeFit

    Raises
    ------
    InputError
        On too few points, or when no ellipsoid of the cone meets the rays.
    """
    points = as_points(points, min_count=8)
    points = points[:: max(1, -(-len(points) // max_points))]
    cone = np.asarray(cone, dtype=np.float64)
    axis = np.asarray(axis, dtype=np.float64)
    jit = compiled()
    if jit is not None:  # the compiled twin of the rays, their r^T C r and the depths below: the same values
        rays, ray_cone, z = jit.cone_rays(points, np.ascontiguousarray(cone))
    else:
        rays = points / points[:, 2:3]
        z = points[:, 2]
        ray_cone = ((rays @ cone) * rays).sum(axis=1)
    grid = _cone_grid(front, extent)
    tau_max = cone_thickness_bound(cone, min_thickness)
    np.minimum(grid[:, 3], tau_max, out=grid[:, 3])

    cone_inv = lapack.inv(cone)
    step = np.array([1e-4, 1e-4, 1e-4, 1e-3])
    steps = at = np.empty(0)  # the twin's (below; the kernels need neither)

    def residuals(p: np.ndarray, split: int = 0) -> np.ndarray:
        fronts, valid = _cone_fronts(p, cone, axis, rays, ray_cone, split=split)
        res = np.where(valid[:, None], z[None, :] - fronts, 0.05)
        return np.where(np.isfinite(res), res, 0.02)

    def with_steps(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The residuals at ``p`` (n,) and at ``p`` plus each finite-difference step (4, n), in one evaluation
        (a trial step that is taken needs both; one that is not wastes the four rows, cheaper than a second
        call), each group's values those of its own call (``split``)."""
        at[0] = p
        np.add(p[None], steps, out=at[1:])
        both = residuals(at, split=1)
        return both[0], both[1:]

    def cost(res: np.ndarray) -> np.ndarray:
        a = np.abs(res)
        return np.where(a <= huber, 0.5 * res * res, huber * (a - 0.5 * huber)).sum(axis=-1)

    if jit is not None:  # the compiled twin of the grid search, the loop and the back face below
        cone_c, axis_c = np.ascontiguousarray(cone), np.ascontiguousarray(axis)
        p, both, status = jit.cone_fit(
            grid, cone_c, axis_c, rays, ray_cone, np.ascontiguousarray(z), step, huber, iterations, tolerance, tau_max
        )
        if status == 0:  # else no finite cost (1) or a singular damped system (2): the twin decides
            centre, shape, valid, back_std, rms = jit.cone_result(p, both, step, huber, cone_c, axis_c, cone_inv)
            if not valid:
                raise InputError("no ellipsoid with the silhouette's outline meets the seen rays")
            return ConeFit(centre, shape, back_std, rms)
    steps, at = np.diag(step), np.empty((5, 4))
    costs = cost(residuals(grid))
    if not np.isfinite(costs).any():
        raise InputError("no ellipsoid with the silhouette's outline meets the seen rays")
    p = grid[int(np.argmin(costs))]
    r, r_steps = with_steps(p)
    current, mu = float(cost(r)), 1e-2
    for _ in range(iterations):
        done = False
        jac = (r_steps - r[None]) / step[:, None]  # (4, n), forward differences
        a = np.abs(r)
        w = np.where(a <= huber, 1.0, huber / np.maximum(a, 1e-12))
        jtj = (jac * w) @ jac.T
        g = (jac * w) @ r
        improved = False
        # At the thickness bound with the cost falling beyond it, ``tau`` stays there and the other three
        # parameters are solved for alone (an active set of one bound).
        free = slice(0, 3) if p[3] >= tau_max and g[3] < 0 else slice(0, 4)
        while mu < 1e6:
            delta = np.zeros(4)
            sub = jtj[free, free]
            delta[free] = -np.linalg.solve(sub + mu * np.diag(np.diag(sub) + 1e-12), g[free])
            trial = p + delta
            trial[3] = min(trial[3], tau_max)
            r_new, r_new_steps = with_steps(trial)  # the next Jacobian's evaluations too, should it be taken
            new = float(cost(r_new))
            if new < current:
                p, r, r_steps, mu, improved = trial, r_new, r_new_steps, max(mu / 3.0, 1e-7), True
                done = current - new < tolerance * current
                current = new
                break
            mu *= 4.0
        if not improved or done:
            break
    m, shape, valid = cone_ellipsoid(p[None], cone, axis)
    if not valid[0]:
        raise InputError("no ellipsoid with the silhouette's outline meets the seen rays")
    # The back face's standard deviation: the parameters' covariance sigma^2 (J^T W J)^-1 (sigma from the
    # residuals, the Jacobian of the last step), carried to z_c + sqrt(S_zz) by finite differences.
    a = np.abs(r)
    w = np.where(a <= huber, 1.0, huber / np.maximum(a, 1e-12))
    sigma2 = float((w * r * r).sum() / max(w.sum() - 4.0, 1.0))
    jac = (r_steps - r[None]) / step[:, None]
    try:
        cov = sigma2 * np.linalg.inv((jac * w) @ jac.T + 1e-18 * np.eye(4))
    except np.linalg.LinAlgError:
        cov = np.full((4, 4), np.nan)
    mb, sb, vb = cone_ellipsoid(p[None] + np.diag(step), cone, axis, cone_inv=cone_inv)
    back = m[0, 2] + np.sqrt(shape[0, 2, 2])
    grad = (mb[:, 2] + np.sqrt(sb[:, 2, 2]) - back) / step
    back_std = float(np.sqrt(max(grad @ cov @ grad, 0.0))) if vb.all() else float("nan")
    return ConeFit(m[0], shape[0], back_std, float(np.sqrt(sigma2)))
