"""``sphere``: least-squares sphere fit; the box of the sphere (a strong baseline for round fruit)."""

from __future__ import annotations

import numpy as np

from ..box import Box
from ..camera import Camera
from ..config import Settings
from ..errors import InputError
from . import Completion, register

__all__ = ["fit_sphere"]


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


@register("sphere")
def sphere(points: np.ndarray, camera: Camera, settings: Settings) -> Completion:
    """Fit a sphere; complete by point reflection through its centre; box the sphere.

    The box is the sphere's box joined with the visible points' box, so it always contains every
    visible point even when noise puts some outside the sphere.
    """
    centre, radius = fit_sphere(points, refine=settings.sphere.refine)
    mirrored = 2.0 * centre - points
    box = Box(min=centre - radius, max=centre + radius).union(Box.from_points(points))
    return Completion(
        points=np.vstack([points, mirrored]),
        box=box,
        extras={"centre": centre.tolist(), "radius": radius},
    )
