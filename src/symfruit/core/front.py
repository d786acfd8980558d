"""The depth of a fruit's front surface, robust to depth noise.

The minimum of a depth camera's noisy depths lies a few standard deviations in front of the surface
(3.7-4.5 mm for a D435-like camera at 0.3-0.5 m), and every box that contains the seen points inherits
that bias in its front face. A smooth surface fitted around its nearest part does not.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from . import lapack
from .fits import eigenvalues2, solve2
from .kernels import compiled
from .points import as_points, column_means, squared_norms

__all__ = ["apex_depth", "sphere_front", "sphere_front_behind"]


def apex_depth(points: np.ndarray, *, share: float = 0.08, min_points: int = 12) -> tuple[float, np.ndarray]:
    """Depth of the nearest point of the surface: ``(z_min, apex (3,))``, metres.

    The points around the front-most part of the surface (the ``share`` of the points nearest, in the
    image plane, to the centroid of the 2 % front-most points, at least ``min_points``) are fitted with
    a quadric ``z = a + b x + c y + d x^2 + e x y + f y^2``; ``z_min`` is its lowest value over those
    points' ``x, y``, or its vertex when the quadric is convex and the vertex lies among them.

    Parameters
    ----------
    points : (n, 3) float, metres, camera frame, n >= 6
    share : float in (0, 1]
    min_points : int

    Returns
    -------
    z_min : float, metres
    apex : (3,) float, metres

    Raises
    ------
    InputError
        On fewer than 6 points or a wrong shape.
    """
    p = as_points(points, min_count=6)
    n = len(p)
    z = p[:, 2]
    front = max(1, int(0.02 * n))
    k = min(n, max(min_points, int(share * n)))
    # by the compiled twins where numba is and the points are C-ordered float64 (the same values; issue 19, stop 45:
    # two calls for fourteen), the partitions numpy's either way (their order of the picked rows is the fit's)
    jit = compiled() if p.dtype == np.float64 and p.flags.c_contiguous else None
    # (the arrays' own argpartition and argmin: what np.argpartition and np.argmin call, without their dispatch;
    # issue 19, stop 65, docs/evid65.md)
    if jit is not None:
        seed, d2 = jit.apex_near(p, z.argpartition(front - 1)[:front])
    else:
        seed = column_means(p[z.argpartition(front - 1)[:front], :2])  # .mean(axis=0), the same values
        d2 = squared_norms(p[:, :2] - seed)  # ((...) ** 2).sum(axis=1), the same values
    pick = d2.argpartition(k - 1)[:k]
    if jit is not None:
        a, near_z = jit.apex_design(p, pick, seed)
    else:
        near = p[pick]
        a = np.empty((k, 6))  # the array of np.stack((1, x, y, x x, x y, y y), axis=1), column by column
        a[:, 0] = 1.0
        np.subtract(near[:, 0], seed[0], out=a[:, 1])
        np.subtract(near[:, 1], seed[1], out=a[:, 2])
        np.multiply(a[:, 1], a[:, 1], out=a[:, 3])
        np.multiply(a[:, 1], a[:, 2], out=a[:, 4])
        np.multiply(a[:, 2], a[:, 2], out=a[:, 5])
        near_z = near[:, 2]
    x, y = a[:, 1], a[:, 2]
    coef, _, _ = lapack.lstsq(a, near_z)  # np.linalg.lstsq(..., rcond=None)'s
    fitted = a @ coef
    i = int(fitted.argmin())
    best_z, best_xy = float(fitted[i]), (float(x[i]), float(y[i]))  # Python floats: the same sums below
    c1, c2, c3, c4, c5 = coef[1:].tolist()
    # The Hessian's eigenvalues and the vertex by the closed forms that repeat numpy's eigvalsh and solve bit for bit
    # (core.fits.eigenvalues2 and solve2; numpy where they cannot), not two LAPACK calls of 20-30 us.
    values = eigenvalues2(2 * c3, c4, 2 * c5)
    if values is None:
        values = tuple(np.linalg.eigvalsh(np.array([[2 * c3, c4], [c4, 2 * c5]])).tolist())
    if values[0] > 0 and values[1] > 0:
        found = solve2(2 * c3, c4, c4, 2 * c5, -c1, -c2)
        if found is None:
            found = tuple(np.linalg.solve(np.array([[2 * c3, c4], [c4, 2 * c5]]), -coef[1:3]).tolist())
        v = np.array(found)
        if found[0] * found[0] + found[1] * found[1] <= float(d2[pick].max()):  # v @ v: numpy's dot, left to right
            zv = float(np.array([1.0, v[0], v[1], v[0] ** 2, v[0] * v[1], v[1] ** 2]) @ coef)
            if zv < best_z:
                best_z, best_xy = zv, found  # v's values
    s0, s1 = seed.tolist()  # the apex, ``np.concatenate((best_xy + seed, [best_z]))``'s values in one array
    return best_z, np.array([best_xy[0] + s0, best_xy[1] + s1, best_z])


def sphere_front(points: np.ndarray, radius: float, *, iterations: int = 20,
                 tolerance: float = 1e-7) -> tuple[float, np.ndarray]:  # fmt: skip
    """The front of the sphere of ``radius`` that best fits the points: ``(z_min, apex (3,))``, metres.

    Where a leaf hides the nearest part of a fruit, the nearest seen point lies on the seen part's edge, behind
    the fruit's front; the seen part's curvature and the silhouette's width still place the fruit (stop 46,
    docs/apex46.md). The centre ``c`` minimises ``sum (|p - c| - radius)^2`` (Gauss-Newton from ``radius`` behind
    the points' centroid, at most ``iterations`` steps, until a step moves less than ``tolerance`` metres);
    ``z_min = c_z - radius``, the apex ``c - (0, 0, radius)``.

    Parameters
    ----------
    points : (n, 3) float, metres, camera frame, n >= 4
    radius : float, metres, > 0
    iterations : int
    tolerance : float, metres

    Returns
    -------
    z_min : float, metres
    apex : (3,) float, metres

    Raises
    ------
    InputError
        On fewer than 4 points, a wrong shape or a radius not above 0.

    >>> t = np.linspace(0.0, 2.0 * np.pi, 40, endpoint=False)
    >>> ring = np.stack((0.03 * np.cos(t), 0.03 * np.sin(t), np.full(40, 0.54)), axis=1)  # 30 mm off the axis
    >>> z, apex = sphere_front(ring, 0.05)  # the ring lies 40 mm in front of the centre, the front 50
    >>> round(z, 6), round(float(np.hypot(apex[0], apex[1])), 6)
    (0.53, 0.0)
    """
    p = as_points(points, min_count=4)
    r = float(radius)
    if not r > 0.0:
        raise InputError(f"sphere_front needs a radius above 0, got {radius!r}")
    c = column_means(p)
    c[2] += r
    jac = np.empty((len(p), 3))
    resid = np.empty(len(p))
    jit = compiled()
    for _ in range(iterations):
        # the Jacobian and residuals by the compiled twin where numba is (stop 47: the same values, one call for
        # numpy's six passes, its divide broadcast over rows of 3); the products stay numpy's (OpenBLAS's bits)
        if jit is not None:
            jit.sphere_residuals(p, c, r, jac, resid)
        else:
            resid = _sphere_residuals(p, c, r, jac)
        jt = jac.T
        try:  # core.lapack: numpy's solve and lstsq without their wrappers, the same values and errors
            step = lapack.solve(jt @ jac, -(jt @ resid))
        except np.linalg.LinAlgError:
            step = lapack.lstsq(jac, -resid)[0]
        c = c + step
        s0, s1, s2 = step.tolist()  # np.abs(step).max() < tolerance: every one below (a NaN none, as its max)
        if abs(s0) < tolerance and abs(s1) < tolerance and abs(s2) < tolerance:
            break
    return float(c[2] - r), np.array([c[0], c[1], c[2] - r])


def sphere_front_behind(points: np.ndarray, radius: float, front: float, *, iterations: int = 20,
                        tolerance: float = 1e-7) -> bool:  # fmt: skip
    """Whether ``sphere_front(points, radius, iterations=iterations, tolerance=tolerance)[0]`` surely is at least
    ``front``, by the compiled :func:`symfruit.core._jit.sphere_front_behind` (the same Gauss-Newton, its sums in
    the points' order, taken on until its steps show it settled; issue 19, stop 63). False where it is not sure, and
    always without numba or for points that are not C-ordered (n, 3) float64 (the caller then fits): a True never
    stands for a front :func:`sphere_front` would place in front of ``front``, nor for an input it would refuse."""
    if (jit := compiled()) is None:
        return False
    p = points
    if not (type(p) is np.ndarray and p.dtype == np.float64 and p.ndim == 2 and p.shape[1] == 3
            and p.flags.c_contiguous and len(p) >= 4):  # fmt: skip
        return False
    return bool(jit.sphere_front_behind(p, float(radius), int(iterations), float(tolerance), float(front)))


def _sphere_residuals(p: np.ndarray, c: np.ndarray, r: float, jac: np.ndarray) -> np.ndarray:
    """:func:`sphere_front`'s Jacobian (into ``jac`` (n, 3)) and residuals (n,) at the centre ``c`` (3,) of the points
    ``p`` (n, 3): the numpy twin of :func:`symfruit.core._jit.sphere_residuals`."""
    diff = p - c
    dist = np.maximum(np.sqrt(squared_norms(diff)), 1e-12)
    np.divide(diff, -dist[:, None], out=jac)
    return dist - r
