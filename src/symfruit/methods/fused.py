"""``fused``: the previous default method (kept for the comparison tables; the default is now ``evidence``).
A shape fit and symmetric completion fused by the data's noise level.

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

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.box import Box
from ..core.camera import Camera
from ..core.fits import (
    ellipsoid_half_extents,
    fit_aligned_ellipsoid,
    fit_ellipsoid,
    fit_revolution,
    fit_sphere,
    surface_noise,
)
from ..core.points import subsample
from ..core.raster import View, rasterise, silhouette_coverage
from ..core.symmetry import complete_by_symmetry
from ..errors import InputError
from ..settings import Section, SettingError, setting
from .paper import PaperSettings
from .registry import Completion, register

__all__ = ["FusedSettings"]


@dataclass(frozen=True)
class FusedSettings(Section):
    """Settings of the ``fused`` method (the previous default); fruit profiles set these.

    Attributes
    ----------
    clean_ratio : float
        Data count as a clean scan when the local plane-fit residual grows by at least this factor from
        8 to 30 neighbours (curvature, not noise): measured 4.5-6.7 on clean scans of every fruit kind,
        1.5-2.2 on D435-like views, so 3.3 separates them with room on both sides.
    revolution : bool
        On clean data, also fit a solid of revolution and average its box with the ellipsoid's
        (on for strawberries, whose tapered shape an ellipsoid misses).
    depth_prior, depth_ratio : float
        Noisy data: weight of the prior that the depth semi-axis is ``depth_ratio`` times the geometric
        mean of the lateral ones.
    huber : float, metres
        Noisy data: residuals beyond this count linearly (outliers, flying pixels).
    mirror_weight : float in [0, 1]
        Noisy data: share of the mirror completion in the centre (the rest is the aligned fit's).
    mirror_size : float in [0, 1]
        Noisy data: share of the mirror completion in the box size.
    mirror : PaperSettings
        The mirror completion (a ``paper`` section of its own): by default a deeper grid of depth offsets
        (8 x 0.1 ``len_depth``) and a reasonable region of 0.4-1.0 ``Dist_ref``, rated on 600 points;
        the paper's 4 x 0.2 stops short of the true plane for shallow views and its 0.6-1.2 region
        penalises the true back of elongated fruit (see docs/ablation.md).
    fit_points : int
        Fits and the mirror completion use a fixed random subset of at most this many points (the
        box always covers every visible point).
    shape_points : int
        Points the camera-aligned ellipsoid is fitted to (a spread subset: the fit averages the
        noise of a few hundred points as well as of thousands, at a fraction of the cost).
    spread_scale, min_support, reliable_at : float
        Confidence = coverage * exp(-spread / (spread_scale * size)) * min(1, n / min_support), with
        ``coverage`` the share of the fitted silhouette the camera saw and ``spread`` the largest
        distance between the estimates' centres; ``reliable`` when it is at least ``reliable_at``.
    """

    clean_ratio: float = setting(3.3, gt=0.0, le=100.0)
    revolution: bool = setting(False)
    depth_prior: float = setting(1.0, ge=0.0, le=1e6)
    depth_ratio: float = setting(1.0, gt=0.0, le=100.0)
    huber: float = setting(0.002, gt=0.0, le=1.0)
    mirror_weight: float = setting(0.5, ge=0.0, le=1.0)
    mirror_size: float = setting(0.0, ge=0.0, le=1.0)
    mirror: PaperSettings = setting(
        PaperSettings(translations=8, translation_step=0.1, j2=0.4, j3=1.0, rating_points=600)
    )
    fit_points: int = setting(2000, ge=20, le=1_000_000)
    shape_points: int = setting(800, ge=10, le=1_000_000)
    spread_scale: float = setting(0.1, gt=0.0, le=100.0)
    min_support: float = setting(150.0, gt=0.0, le=1e9)
    reliable_at: float = setting(0.4, ge=0.0, le=1.0)

    def check(self) -> None:
        if not isinstance(self.mirror, PaperSettings):
            raise SettingError("mirror", f"must be a paper settings section, got {type(self.mirror).__name__}")


def _mean_box(boxes: list[Box]) -> Box:
    """The box with the mean centre and the mean size of ``boxes``."""
    centre = np.mean([b.centre for b in boxes], axis=0)
    size = np.mean([b.size for b in boxes], axis=0)
    return Box(centre - size / 2.0, centre + size / 2.0)


@register("fused", settings=FusedSettings)
def fused(points: np.ndarray, camera: Camera, settings: FusedSettings) -> Completion:
    """Shape fit and mirror completion, fused by the data's noise level; with a confidence."""
    s = settings
    sample = subsample(points, s.fit_points)
    extent = float(np.ptp(points, axis=0).max())
    ratio, noise, normals = surface_noise(sample)
    step = max(1, len(sample) // 120)
    centres: list[np.ndarray] = []
    view: View | None = None
    plane = None
    extras: dict[str, Any] = {"noise": noise, "roughness_ratio": ratio}
    if ratio >= s.clean_ratio:
        extras["regime"] = "clean"
        try:
            c, shape = fit_ellipsoid(sample)
            with np.errstate(invalid="ignore"):
                half = ellipsoid_half_extents(shape)
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
        mirrored = complete_by_symmetry(sample, camera, **s.mirror.options(), view=view)
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


def _confidence(spread: float, coverage: float, size: float, n: int, s: FusedSettings) -> float:
    """Silhouette coverage x agreement of the estimates x support, in [0, 1]."""
    agree = np.exp(-spread / (s.spread_scale * size))
    support = min(1.0, n / s.min_support)
    return float(np.clip(coverage * agree * support, 0.0, 1.0))
