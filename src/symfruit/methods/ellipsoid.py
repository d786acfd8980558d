"""``ellipsoid``: least-squares ellipsoid fit (Li & Griffiths 2004); the box of the ellipsoid."""

from __future__ import annotations

import numpy as np

from ..box import Box
from ..camera import Camera
from ..config import Settings
from ..errors import InputError
from . import Completion, register
from .sphere import fit_sphere

__all__ = ["fit_ellipsoid"]


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


@register("ellipsoid")
def ellipsoid(points: np.ndarray, camera: Camera, settings: Settings) -> Completion:
    """Fit an ellipsoid; complete by point reflection through its centre; box the ellipsoid.

    Falls back to the sphere fit (and says so in ``extras["fallback"]``) when no ellipsoid fits.
    The box is joined with the visible points' box, so it always contains them.
    """
    try:
        centre, shape = fit_ellipsoid(points)
        half = np.sqrt(np.diag(np.linalg.inv(shape)))
        extras: dict = {
            "centre": centre.tolist(),
            "semi_axes": np.sort(1.0 / np.sqrt(np.linalg.eigvalsh(shape))).tolist(),
        }
    except InputError as exc:
        centre, radius = fit_sphere(points)
        half = np.full(3, radius)
        extras = {"centre": centre.tolist(), "fallback": f"sphere ({exc})"}
    box = Box(min=centre - half, max=centre + half).union(Box.from_points(points))
    return Completion(points=np.vstack([points, 2.0 * centre - points]), box=box, extras=extras)
