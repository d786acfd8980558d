"""``sphere``: least-squares sphere fit; the box of the sphere (a strong baseline for round fruit)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.box import Box
from ..core.camera import Camera
from ..core.fits import fit_sphere
from ..settings import Section, setting
from .registry import Completion, register

__all__ = ["SphereSettings"]


@dataclass(frozen=True)
class SphereSettings(Section):
    """Settings of the ``sphere`` method.

    Attributes
    ----------
    refine : bool
        Refine the algebraic (linear least-squares) fit by geometric Gauss-Newton steps, which
        minimise the distances of the points to the sphere rather than the algebraic residual.
    """

    refine: bool = setting(True)


@register("sphere", settings=SphereSettings)
def sphere(points: np.ndarray, camera: Camera, settings: SphereSettings) -> Completion:
    """Least-squares sphere; completes by point reflection through its centre; the sphere's box.

    The box is the sphere's box joined with the visible points' box, so it always contains every
    visible point even when noise puts some outside the sphere.
    """
    centre, radius = fit_sphere(points, refine=settings.refine)
    mirrored = 2.0 * centre - points
    box = Box(min=centre - radius, max=centre + radius).union(Box.from_points(points))
    return Completion(
        points=np.vstack([points, mirrored]),
        box=box,
        extras={"centre": centre.tolist(), "radius": radius},
    )
