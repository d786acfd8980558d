"""Superellipsoid fit of Marangoz, Zaenker, Menon and Bennewitz (CASE 2022), in numpy/scipy.

S. Marangoz, T. Zaenker, R. Menon, M. Bennewitz, "Fruit Mapping with Shape Completion for Autonomous
Crop Monitoring", IEEE CASE 2022, pp. 471-476 (doi 10.1109/CASE49997.2022.9926466, arXiv 2203.15489);
their code: github.com/salihmarangoz/capsicum_superellipsoid_detector, ``include/capsicum_superellipsoid_
detector/superellipsoid.h`` (class ``Superellipsoid``: ``estimateNormals``, ``estimateClusterCenter``,
``fit``, struct ``SuperellipsoidError``) and ``cfg/SuperellipsoidDetector.cfg`` (default parameters).
"Their code" below means those files; each choice says where it comes from.

The pipeline (their ``SuperellipsoidDetector::processInput``, per fruit cluster):

1. surface normals by PCA over all neighbours within ``normal_radius`` (PCL ``NormalEstimation``
   with ``setRadiusSearch(estimate_normals_search_radius = 0.015)``);
2. the centre prior ``p``: the least-squares intersection of the normal lines, regularised towards the
   cluster mean (``estimateClusterCenter(estimate_cluster_center_regularization = 2.5)``);
3. a non-linear least-squares fit of the 11 parameters (semi-axes ``a, b, c``, exponents ``e1, e2``,
   centre ``t``, three Euler angles) to the radial Euclidean distance (``cost_type = 2``,
   ``RADIAL_EUCLIDIAN_DISTANCE``), with a centre prior and an axes-similarity prior
   (``prior_center = prior_scaling = 0.1``), bounds on the axes and exponents, Levenberg-Marquardt with
   at most 100 iterations (``max_num_iterations``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.spatial import cKDTree

from ..errors import InputError
from .points import as_points, row_norms

__all__ = [
    "Superellipsoid",
    "fit_superellipsoid",
    "line_intersection_centre",
    "missing_surface",
    "radius_normals",
    "superellipsoid_box",
    "superellipsoid_fibonacci",
    "superellipsoid_surface",
    "voxel_downsample",
]

_DEG = np.pi / 180.0


@dataclass(frozen=True)
class Superellipsoid:
    """A fitted superellipsoid ``f(R^T (x - centre)) = 1``.

    Attributes
    ----------
    centre : (3,) float, metres
        The optimised centre ``t``.
    axes : (3,) float, metres
        Semi-axes ``a, b, c`` along the local x, y, z.
    e1, e2 : float
        Exponents (``e1`` north-south, ``e2`` east-west; 1 is an ellipsoid, below 1 boxier).
    rotation : (3, 3) float
        Columns are the local axes in the input frame (local-to-input rotation).
    angles : (3,) float, degrees
        The Euler angles as their code parameterises them (``pitch, roll, yaw``).
    prior_centre : (3,) float, metres
        The centre estimated from the normals (the prior ``p``).
    cost : float
        Final cost (half the sum of squared residuals, scipy's convention).
    success : bool
        Whether the solver reported convergence (their ``summary.IsSolutionUsable()``).
    n_fit : int
        Points the fit used (after the voxel down-sampling).
    """

    centre: np.ndarray
    axes: np.ndarray
    e1: float
    e2: float
    rotation: np.ndarray
    angles: np.ndarray
    prior_centre: np.ndarray
    cost: float
    success: bool
    n_fit: int


def _finite(points: object, minimum: int) -> np.ndarray:
    """``points`` as (n, 3) float64 (:func:`as_points`), non-finite rows dropped, at least ``minimum`` left."""
    arr = as_points(points, min_count=0)
    arr = arr[np.isfinite(arr).all(axis=1)]
    if len(arr) < minimum:
        raise InputError(f"need at least {minimum} finite points, got {len(arr)}")
    return arr


def voxel_downsample(points: np.ndarray, *, voxel: float) -> np.ndarray:
    """The centroid of the points in each occupied cube of side ``voxel``.

    Parameters
    ----------
    points : (n, 3) float, metres
    voxel : float, metres, > 0

    Returns
    -------
    (m, 3) float, metres, m <= n, in the order of the first point of each voxel.
    """
    points = _finite(points, 1)
    if voxel <= 0:
        raise InputError("voxel must be positive")
    cells = np.floor((points - points.min(axis=0)) / voxel).astype(np.int64)
    span = cells.max(axis=0) + 1
    keys = (cells[:, 0] * span[1] + cells[:, 1]) * span[2] + cells[:, 2]
    _, first, inverse, counts = np.unique(keys, return_index=True, return_inverse=True, return_counts=True)
    sums = np.stack([np.bincount(inverse, weights=points[:, i], minlength=len(counts)) for i in range(3)], axis=1)
    order = np.argsort(first)
    return (sums / counts[:, None])[order]


def radius_normals(points: np.ndarray, *, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals by PCA over every neighbour within ``radius`` (the point itself included).

    The covariance of each neighbourhood comes from sparse sums (one sparse matrix product for all
    points, no loop); the normal is its eigenvector of least variance, as PCL's ``NormalEstimation``
    with a radius search. Sign: arbitrary (flipped by the caller).

    Parameters
    ----------
    points : (n, 3) float, metres
    radius : float, metres

    Returns
    -------
    normals : (n, 3) float, unit length (NaN where a neighbourhood has fewer than 3 points)
    counts : (n,) int, neighbourhood sizes
    """
    points = _finite(points, 1)
    n = len(points)
    pairs = cKDTree(points).query_pairs(radius, output_type="ndarray")
    rows = np.concatenate([pairs[:, 0], pairs[:, 1], np.arange(n)])
    cols = np.concatenate([pairs[:, 1], pairs[:, 0], np.arange(n)])
    adj = sparse.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    counts = np.asarray(adj.sum(axis=1)).ravel()
    centred = points - points.mean(axis=0)  # conditioning
    outer = (centred[:, :, None] * centred[:, None, :]).reshape(n, 9)
    s1 = adj @ centred
    s2 = (adj @ outer).reshape(n, 3, 3)
    mean = s1 / counts[:, None]
    cov = s2 / counts[:, None, None] - mean[:, :, None] * mean[:, None, :]
    _, vectors = np.linalg.eigh(cov)
    normals = vectors[:, :, 0]
    normals[counts < 3] = np.nan
    return normals, counts.astype(np.int64)


def line_intersection_centre(points: np.ndarray, normals: np.ndarray, *, regularization: float = 2.5) -> np.ndarray:
    """Least-squares intersection of the lines ``points[i] + s * normals[i]``, biased to the mean.

    Minimises ``sum_i |(I - v_i v_i^T)(c - a_i)|^2 + regularization * |c - mean|^2``: solves
    ``(sum_i (I - v v^T) + reg I) c = sum_i (I - v v^T) a_i + reg * mean`` with a pseudo-inverse, and
    falls back to the mean if that is not finite (their ``estimateClusterCenter``; the method is the
    one of "least-squares intersection of lines", which their code cites). Lines with a NaN normal
    are skipped; ``mean`` is the mean of all the points, as in their code.

    Parameters
    ----------
    points, normals : (n, 3) float
    regularization : float, >= 0 (their default 2.5)

    Returns
    -------
    (3,) float, metres
    """
    points = _finite(points, 1)
    normals = np.asarray(normals, dtype=np.float64)
    if normals.shape != points.shape:
        raise InputError("normals must have the shape of points")
    mean = points.mean(axis=0)
    ok = np.isfinite(normals).all(axis=1)
    v = normals[ok] / np.linalg.norm(normals[ok], axis=1, keepdims=True)
    a = points[ok] - mean  # conditioning: the solution is shift-invariant
    proj = np.eye(3)[None] - v[:, :, None] * v[:, None, :]
    r = proj.sum(axis=0) + regularization * np.eye(3)
    q = np.einsum("nij,nj->i", proj, a)
    centre = np.linalg.pinv(r) @ q + mean
    return centre if np.all(np.isfinite(centre)) else mean


def _rotation(angles_deg: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
    """``M = Rx(a) Ry(b) Rz(c)`` (input-to-local) and its derivatives per angle (per degree).

    Their cost function builds ``ceres::EulerAnglesToRotationMatrix({-pitch, -roll, -yaw})``, which is
    ``Rz(-yaw) Ry(-roll) Rx(-pitch)`` in row-major order, and reads it column-major (Eigen's default),
    i.e. takes its transpose: ``Rx(pitch) Ry(roll) Rz(yaw)``, angles in degrees.
    """
    a, b, c = np.asarray(angles_deg, dtype=np.float64) * _DEG
    ca, sa, cb, sb, cc, sc = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
    rx = np.array([[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
    ry = np.array([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    rz = np.array([[cc, -sc, 0], [sc, cc, 0], [0, 0, 1]])
    drx = np.array([[0, 0, 0], [0, -sa, -ca], [0, ca, -sa]]) * _DEG
    dry = np.array([[-sb, 0, cb], [0, 0, 0], [-cb, 0, -sb]]) * _DEG
    drz = np.array([[-sc, -cc, 0], [cc, -sc, 0], [0, 0, 0]]) * _DEG
    return rx @ ry @ rz, [drx @ ry @ rz, rx @ dry @ rz, rx @ ry @ drz]


_TINY = 1e-12


def _residuals(theta: np.ndarray, pts: np.ndarray, prior: np.ndarray, w_c: float, w_s: float) -> np.ndarray:
    return _evaluate(theta, pts, prior, w_c, w_s, jacobian=False)[0]


def _jacobian(theta: np.ndarray, pts: np.ndarray, prior: np.ndarray, w_c: float, w_s: float) -> np.ndarray:
    return _evaluate(theta, pts, prior, w_c, w_s, jacobian=True)[1]


def _evaluate(theta, pts, prior, w_c, w_s, *, jacobian):
    """Residuals ``[radial (n), centre prior, scaling prior]`` and their analytic Jacobian (n + 2, 11).

    Radial Euclidean distance (their ``RADIAL_EUCLIDIAN_DISTANCE``): ``|x| |1 - f(x)^(-e1/2)|`` with
    ``f = (|x/a|^(2/e2) + |y/b|^(2/e2))^(e2/e1) + |z/c|^(2/e1)`` in local coordinates. The absolute value
    is dropped (``(|x| (1 - f^(-e1/2)))^2`` is the same cost and is differentiable at the surface).
    """
    a, b, c, e1, e2 = theta[:5]
    t, ang = theta[5:8], theta[8:11]
    m, dms = _rotation(ang)
    q = pts - t
    loc = q @ m.T
    x, y, z = loc[:, 0], loc[:, 1], loc[:, 2]
    ax, ay, az = np.abs(x / a) + _TINY, np.abs(y / b) + _TINY, np.abs(z / c) + _TINY
    la, lb, lz = np.log(ax), np.log(ay), np.log(az)
    big_a, big_b = np.exp((2.0 / e2) * la), np.exp((2.0 / e2) * lb)
    g = big_a + big_b
    lg = np.log(g)
    big_g = np.exp((e2 / e1) * lg)
    big_z = np.exp((2.0 / e1) * lz)
    f = big_g + big_z
    lf = np.log(f)
    fe = np.exp(-0.5 * e1 * lf)  # f^(-e1/2)
    rho = row_norms(q)
    n = len(pts)
    res = np.empty(n + 2)
    res[:n] = rho * (1.0 - fe)
    dc = t - prior
    sc = np.sqrt(0.001 + dc @ dc)
    ds = np.array([a - b, b - c, c - a])
    ss = np.sqrt(0.001 + ds @ ds)
    res[n] = w_c * sc
    res[n + 1] = w_s * ss
    if not jacobian:
        return res, None
    jac = np.zeros((n + 2, 11))
    k = rho * 0.5 * e1 * fe / f  # d r / d f
    gg = big_g / g
    df_da = -(2.0 / e1) * gg * big_a / a
    df_db = -(2.0 / e1) * gg * big_b / b
    df_dc = -(2.0 / e1) * big_z / c
    dg_de2 = -(2.0 / e2**2) * (big_a * la + big_b * lb)
    df_de2 = big_g * (lg / e1 + (e2 / e1) * dg_de2 / g)
    df_de1 = big_g * (-(e2 / e1**2) * lg) + big_z * (-(2.0 / e1**2) * lz)
    jac[:n, 0] = k * df_da
    jac[:n, 1] = k * df_db
    jac[:n, 2] = k * df_dc
    jac[:n, 3] = rho * fe * (0.5 * lf + 0.5 * e1 * df_de1 / f)
    jac[:n, 4] = k * df_de2
    # df / d(local): (2/e1) G/g A/x, (2/e1) G/g B/y, (2/e1) Z/z; A/x written so that x = 0 gives 0.
    with np.errstate(divide="ignore", invalid="ignore"):
        fx = np.where(x != 0, (2.0 / e1) * gg * big_a / x, 0.0)
        fy = np.where(y != 0, (2.0 / e1) * gg * big_b / y, 0.0)
        fz = np.where(z != 0, (2.0 / e1) * big_z / z, 0.0)
    grad_loc = np.stack([fx, fy, fz], axis=1)  # (n, 3)
    one_minus = 1.0 - fe
    safe_rho = np.maximum(rho, _TINY)
    # d loc / d t = -M; d rho / d t = -q / rho.
    jac[:n, 5:8] = -(q / safe_rho[:, None]) * one_minus[:, None] - k[:, None] * (grad_loc @ m)
    for i, dm in enumerate(dms):
        jac[:n, 8 + i] = k * np.einsum("ni,ni->n", grad_loc, q @ dm.T)
    jac[n, 5:8] = w_c * dc / sc
    jac[n + 1, 0] = w_s * (ds[0] - ds[2]) / ss
    jac[n + 1, 1] = w_s * (ds[1] - ds[0]) / ss
    jac[n + 1, 2] = w_s * (ds[2] - ds[1]) / ss
    return res, jac


def _levenberg_marquardt(
    x0: np.ndarray, lower: np.ndarray, upper: np.ndarray, args: tuple, max_iterations: int
) -> tuple[np.ndarray, float, bool]:
    """Ceres' Levenberg-Marquardt on the residuals of :func:`_evaluate`; ``(x, cost, converged)``.

    Ceres' defaults: the step solves ``(J^T J + D / radius) d = -J^T r`` with ``D = diag(J^T J)``
    clamped to [1e-6, 1e32], initial trust radius 1e4; a step is taken if the cost drops by at least
    1e-3 of the predicted drop, then ``radius /= max(1/3, 1 - (2 rho - 1)^3)``, else the radius is
    divided by a factor that doubles on each failure. It stops when the relative cost change is below
    1e-6 (``function_tolerance``), the gradient's max-norm below 1e-10 (``gradient_tolerance``) or the
    step below 1e-8 of the parameters (``parameter_tolerance``). Bounds: trial points are projected
    onto the box, as Ceres does for bounded parameter blocks. Cost is ``0.5 |r|^2``.
    """
    x = x0.copy()
    res, jac = _evaluate(x, *args, jacobian=True)
    cost = 0.5 * float(res @ res)
    radius, factor = 1e4, 2.0
    converged = False
    for _ in range(max_iterations):
        jtj = jac.T @ jac
        g = jac.T @ res
        if np.abs(g).max() <= 1e-10:
            converged = True
            break
        d = np.clip(np.diag(jtj), 1e-6, 1e32)
        try:
            step = -np.linalg.solve(jtj + np.diag(d / radius), g)
        except np.linalg.LinAlgError:
            break
        trial = np.clip(x + step, lower, upper)
        step = trial - x
        if np.linalg.norm(step) <= 1e-8 * (np.linalg.norm(x) + 1e-8):
            converged = True
            break
        new_res = _evaluate(trial, *args, jacobian=False)[0]
        new_cost = 0.5 * float(new_res @ new_res) if np.all(np.isfinite(new_res)) else np.inf
        predicted = -(g @ step + 0.5 * step @ jtj @ step)
        rho = (cost - new_cost) / predicted if predicted > 0 else -1.0
        if rho > 1e-3:
            done = abs(cost - new_cost) <= 1e-6 * cost
            x, cost = trial, new_cost
            radius = min(radius / max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3), 1e16)
            factor = 2.0
            if done:
                converged = True
                break
            res, jac = _evaluate(x, *args, jacobian=True)
        else:
            radius /= factor
            factor *= 2.0
            if radius < 1e-32:
                break
    return x, cost, converged


def fit_superellipsoid(
    points: object,
    *,
    voxel: float | None = 0.004,
    min_fit_points: int = 100,
    normal_radius: float = 0.015,
    regularization: float = 2.5,
    prior_center: float = 0.1,
    prior_scaling: float = 0.1,
    initial_axes: float = 0.05,
    initial_exponents: float = 0.5,
    axis_bounds: tuple[float, float] = (0.02, 0.15),
    exponent_bounds: tuple[float, float] = (0.3, 0.9),
    max_iterations: int = 100,
) -> Superellipsoid:
    """Fit a superellipsoid to one fruit's points as Marangoz et al. (CASE 2022) do.

    Parameters
    ----------
    points : (n, 3) float, metres
        The fruit's (visible) points, any frame. Non-finite rows are dropped.
    voxel : float or None, metres
        Down-sample to one point (the centroid) per cube of this side before everything else. Their
        pipeline fits the ``surface_pointcloud`` of a voxblox map whose ``tsdf_voxel_size`` is 0.004 m
        (``launch/start_sim.launch``), i.e. about one point per 4 mm voxel; None fits every point.
    min_fit_points : int
        If the voxel grid leaves fewer points, the voxel is halved until it does not (ours: their node
        drops clusters under ``min_cluster_size = 100`` points, a single-fruit call must answer).
    normal_radius : float, metres
        Radius of the PCA neighbourhoods for the normals (``estimate_normals_search_radius = 0.015``).
    regularization : float
        Bias of the normal-line intersection towards the points' mean
        (``estimate_cluster_center_regularization = 2.5``; absolute, added to the sum of ``I - v v^T``).
    prior_center, prior_scaling : float
        Weights ``alpha`` and ``beta`` of the priors (their defaults 0.1 and 0.1). Their cost adds, for
        every point, the residuals ``alpha sqrt(0.001 + |t - p|^2)`` and ``beta sqrt(0.001 + (a - b)^2
        + (b - c)^2 + (c - a)^2)`` (the README's ``n (alpha sqrt(...))^2``); here they are two residuals
        scaled by ``sqrt(n)``, the same cost.
    initial_axes, initial_exponents : float
        Start values: ``a = b = c = 0.05`` m and ``e1 = e2 = 0.5`` (their ``fit``); the centre starts at
        the normal-based estimate ``p`` and the angles at zero.
    axis_bounds, exponent_bounds : (float, float)
        Box constraints: semi-axes in [0.02, 0.15] m and exponents in [0.3, 0.9] (their
        ``SetParameterLowerBound/UpperBound``; made for sweet peppers: a semi-axis below 20 mm cannot be
        fitted, which matters for small fruit such as strawberries). Angles and centre are free.
    max_iterations : int
        Their ``max_num_iterations = 100``. Their solver is Ceres' Levenberg-Marquardt with bounds;
        :func:`_levenberg_marquardt` is that algorithm (Ceres' trust-region update and stopping
        tolerances, steps projected onto the bounds) with an analytic Jacobian. (scipy's bounded
        ``least_squares(method="trf")`` reaches the same minima but spends ~5 ms per iteration in an
        SVD of the full Jacobian.)

    Returns
    -------
    Superellipsoid

    Raises
    ------
    InputError
        On fewer than 11 finite points or a wrong shape.

    Notes
    -----
    Their normals come from PCL without a viewpoint and are flipped towards the estimated centre
    afterwards; the line intersection does not depend on the sign, and nothing later uses it.
    Their surface sampler (``sampleSurface``) rotates by the transpose of ``EulerAnglesToRotationMatrix``
    of the angles, which is the exact inverse of the cost's rotation only when at most one angle is
    non-zero; :attr:`Superellipsoid.rotation` is the exact inverse of the rotation the cost used.
    """
    pts = _finite(points, 11)
    fit = pts
    if voxel is not None:
        size = float(voxel)
        fit = voxel_downsample(pts, voxel=size)
        while len(fit) < min(min_fit_points, len(pts)) and size > 2.5e-4:
            size /= 2.0
            fit = voxel_downsample(pts, voxel=size)
    if len(fit) < 11:
        fit = pts
    normals, _ = radius_normals(fit, radius=normal_radius)
    prior = line_intersection_centre(fit, normals, regularization=regularization)
    lo_a, hi_a = axis_bounds
    lo_e, hi_e = exponent_bounds
    x0 = np.r_[np.clip(initial_axes, lo_a, hi_a) * np.ones(3), np.clip(initial_exponents, lo_e, hi_e) * np.ones(2),
               prior, np.zeros(3)]  # fmt: skip
    lower = np.r_[np.full(3, lo_a), np.full(2, lo_e), np.full(6, -np.inf)]
    upper = np.r_[np.full(3, hi_a), np.full(2, hi_e), np.full(6, np.inf)]
    sq = np.sqrt(len(fit))
    th, cost, ok = _levenberg_marquardt(x0, lower, upper, (fit, prior, prior_center * sq, prior_scaling * sq),
                                        max_iterations)  # fmt: skip
    m, _ = _rotation(th[8:11])
    return Superellipsoid(
        centre=th[5:8].copy(), axes=th[:3].copy(), e1=float(th[3]), e2=float(th[4]), rotation=m.T.copy(),
        angles=th[8:11].copy(), prior_centre=prior, cost=cost, success=ok,
        n_fit=len(fit),
    )  # fmt: skip


def superellipsoid_surface(se: Superellipsoid, *, n_u: int = 64, n_v: int = 33) -> np.ndarray:
    """Points of the surface on the parametric grid (their ``_sampleSurfaceParametricDefinition``).

    ``x = a C(v)^e1 C(u)^e2``, ``y = b C(v)^e1 S(u)^e2``, ``z = c S(v)^e1`` with ``C(w)^m = sign(cos w)
    |cos w|^m`` (``S`` likewise), ``u`` in [-pi, pi), ``v`` in [-pi/2, pi/2], then rotated and moved.

    Returns
    -------
    (n_u * n_v, 3) float, metres
    """
    u = np.linspace(-np.pi, np.pi, n_u, endpoint=False)
    v = np.linspace(-np.pi / 2, np.pi / 2, n_v)
    uu, vv = np.meshgrid(u, v)

    def pw(w: np.ndarray, p: float) -> np.ndarray:
        return np.sign(w) * np.abs(w) ** p

    a, b, c = se.axes
    local = np.stack([a * pw(np.cos(vv), se.e1) * pw(np.cos(uu), se.e2), b * pw(np.cos(vv), se.e1) *
                      pw(np.sin(uu), se.e2), c * pw(np.sin(vv), se.e1)], axis=-1).reshape(-1, 3)  # fmt: skip
    return local @ se.rotation.T + se.centre


def superellipsoid_box(se: Superellipsoid) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned box ``(min, max)`` (metres) of the surface, from a dense parametric sampling."""
    s = superellipsoid_surface(se, n_u=128, n_v=65)
    return s.min(axis=0), s.max(axis=0)


def superellipsoid_fibonacci(se: Superellipsoid, *, n: int = 500) -> np.ndarray:
    """``n`` nearly uniform surface points: a Fibonacci sphere projected onto the unit superellipsoid by
    10 radial steps, then scaled, rotated and moved (their ``_sampleSurfaceFibonacciProjection``).

    Returns
    -------
    (n, 3) float, metres
    """
    i = np.arange(n, dtype=np.float64)
    y = 1.0 - i / max(n - 1.0, 1.0) * 2.0
    r = np.sqrt(np.clip(1.0 - y * y, 0.0, None))
    theta = np.pi * (3.0 - np.sqrt(5.0)) * i
    p = np.stack([np.cos(theta) * r, y, np.sin(theta) * r], axis=1)
    e1, e2 = se.e1, se.e2
    for _ in range(10):  # their fixed 10 projection steps (vectorised over all points)
        ax = np.abs(p)
        f = (ax[:, 0] ** (2.0 / e2) + ax[:, 1] ** (2.0 / e2)) ** (e2 / e1) + ax[:, 2] ** (2.0 / e1)
        to_centre = row_norms(p)
        to_surface = np.copysign(np.abs(1.0 - f ** (e1 / 2.0)), f - 1.0)
        p = p * ((to_centre - to_surface) / np.maximum(to_centre, _TINY))[:, None]
    return (p * se.axes) @ se.rotation.T + se.centre


def missing_surface(se: Superellipsoid, points: object, *, threshold: float = 0.015, n: int = 500) -> np.ndarray:
    """The fitted surface's points farther than ``threshold`` from every input point: the predicted
    unseen surface (their ``estimateMissingSurfaces``; ``missing_surfaces_threshold = 0.015``,
    ``missing_surfaces_num_samples = 500``).

    Returns
    -------
    (m, 3) float, metres
    """
    pts = _finite(points, 1)
    samples = superellipsoid_fibonacci(se, n=n)
    dist, _ = cKDTree(pts).query(samples)
    return samples[dist > threshold]
