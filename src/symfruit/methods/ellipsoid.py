"""``ellipsoid``: least-squares ellipsoid fit (Li & Griffiths 2004); the box of the ellipsoid."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.box import Box
from ..core.camera import Camera
from ..core.fits import ellipsoid_half_extents, fit_ellipsoid, fit_sphere
from ..errors import InputError
from .registry import Completion, register


@register("ellipsoid")
def ellipsoid(points: np.ndarray, camera: Camera, settings: None) -> Completion:
    """Least-squares ellipsoid (Li-Griffiths); completes by point reflection; the ellipsoid's box.

    Falls back to the sphere fit (and says so in ``extras["fallback"]``) when no ellipsoid fits.
    The box is joined with the visible points' box, so it always contains them.
    """
    extras: dict[str, Any]
    try:
        centre, shape = fit_ellipsoid(points)
        half = ellipsoid_half_extents(shape)
        extras = {
            "centre": centre.tolist(),
            "semi_axes": np.sort(1.0 / np.sqrt(np.linalg.eigvalsh(shape))).tolist(),
        }
    except InputError as exc:
        centre, radius = fit_sphere(points)
        half = np.full(3, radius)
        extras = {"centre": centre.tolist(), "fallback": f"sphere ({exc})"}
    box = Box(min=centre - half, max=centre + half).union(Box.from_points(points))
    return Completion(points=np.vstack([points, 2.0 * centre - points]), box=box, extras=extras)
