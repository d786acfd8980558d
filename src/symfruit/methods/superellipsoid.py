"""``superellipsoid``: the peer method of Marangoz et al. (CASE 2022), see :mod:`symfruit.core.superellipsoid`.

S. Marangoz, T. Zaenker, R. Menon, M. Bennewitz, "Fruit Mapping with Shape Completion for Autonomous Crop
Monitoring", IEEE CASE 2022; their code: ``github.com/salihmarangoz/capsicum_superellipsoid_detector``. The
completed fruit is the visible points plus the fitted surface's missing part (their
``estimateMissingSurfaces``); its box is the box of both. Every default is theirs (no fruit profile),
including the semi-axis bounds of 20-150 mm, which were made for sweet peppers; where each comes from is
on :class:`SuperellipsoidSettings` and in the core module.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.box import Box
from ..core.camera import Camera
from ..core.superellipsoid import fit_superellipsoid, missing_surface, superellipsoid_box
from ..settings import Section, SettingError, setting
from .registry import Completion, register

__all__ = ["SuperellipsoidSettings"]


@dataclass(frozen=True)
class SuperellipsoidSettings(Section):
    """Settings of the ``superellipsoid`` method; the defaults are Marangoz et al.'s.

    Attributes
    ----------
    voxel : float or None, metres
        Fit one point (the centroid) per cube of this side: their pipeline fits the surface cloud of a
        voxblox map with ``tsdf_voxel_size = 0.004`` (``launch/start_sim.launch``). None fits every point.
    normal_radius : float, metres
        PCA neighbourhood radius of the normals (``estimate_normals_search_radius = 0.015``).
    regularization : float
        Bias of the normal-line intersection (the centre prior) towards the points' mean
        (``estimate_cluster_center_regularization = 2.5``).
    prior_center, prior_scaling : float
        Weights of the centre prior and of the axes-similarity prior (``prior_center = prior_scaling = 0.1``).
    axis_min, axis_max : float, metres
        Semi-axis bounds (their ``SetParameterLowerBound/UpperBound``: 0.02 and 0.15).
    exponent_min, exponent_max : float
        Bounds of both exponents (0.3 and 0.9).
    max_iterations : int
        Levenberg-Marquardt iterations (``max_num_iterations = 100``).
    missing_threshold : float, metres
        Surface samples farther than this from every seen point are the missing surface
        (``missing_surfaces_threshold = 0.015``).
    missing_samples : int
        Fibonacci surface samples tested (``missing_surfaces_num_samples = 500``).
    """

    voxel: float | None = setting(0.004, gt=0.0, le=1.0)
    normal_radius: float = setting(0.015, gt=0.0, le=1.0)
    regularization: float = setting(2.5, ge=0.0, le=1e4)
    prior_center: float = setting(0.1, ge=0.0, le=1e3)
    prior_scaling: float = setting(0.1, ge=0.0, le=1e3)
    axis_min: float = setting(0.02, gt=0.0, le=10.0)
    axis_max: float = setting(0.15, gt=0.0, le=10.0)
    exponent_min: float = setting(0.3, gt=0.0, le=10.0)
    exponent_max: float = setting(0.9, gt=0.0, le=10.0)
    max_iterations: int = setting(100, ge=1, le=10_000)
    missing_threshold: float = setting(0.015, gt=0.0, le=1.0)
    missing_samples: int = setting(500, ge=10, le=1_000_000)

    def check(self) -> None:
        if self.axis_min > self.axis_max:
            raise SettingError("axis_min", "must be <= axis_max")
        if self.exponent_min > self.exponent_max:
            raise SettingError("exponent_min", "must be <= exponent_max")


@register("superellipsoid", settings=SuperellipsoidSettings)
def superellipsoid(points: np.ndarray, camera: Camera, settings: SuperellipsoidSettings) -> Completion:
    """Marangoz et al.: superellipsoid fit with normal-based centre prior; box of seen + missing surface."""
    s = settings
    se = fit_superellipsoid(
        points, voxel=s.voxel, normal_radius=s.normal_radius, regularization=s.regularization,
        prior_center=s.prior_center, prior_scaling=s.prior_scaling, axis_bounds=(s.axis_min, s.axis_max),
        exponent_bounds=(s.exponent_min, s.exponent_max), max_iterations=s.max_iterations,
    )  # fmt: skip
    missing = missing_surface(se, points, threshold=s.missing_threshold, n=s.missing_samples)
    completed = np.vstack([points, missing]) if len(missing) else points.copy()
    lo, hi = superellipsoid_box(se)
    return Completion(
        points=completed,
        box=Box.from_points(completed),
        extras={
            "centre": se.centre.tolist(), "axes": se.axes.tolist(), "e1": se.e1, "e2": se.e2,
            "angles": se.angles.tolist(), "prior_centre": se.prior_centre.tolist(), "converged": se.success,
            "surface_box": {"min": lo.tolist(), "max": hi.tolist()}, "n_fit": se.n_fit,
        },
    )  # fmt: skip
