"""``paper``: the symmetry completion of Ge et al. (sections 3.2-3.6), faithfully and vectorised.

All hypotheses and all points are mirrored and rated at once (:func:`symfruit.rating.rate_planes`).
"""

from __future__ import annotations

import numpy as np

from ..box import Box
from ..camera import Camera
from ..config import PaperSettings, Settings
from ..planes import hypothesis_planes, mirror
from ..raster import View, rasterise
from ..rating import rate_planes
from . import Completion, register


@register("paper")
def paper(points: np.ndarray, camera: Camera, settings: Settings) -> Completion:
    """Hypothesise planes, mirror, rate, keep the best mean score (ties to the first), merge, box."""
    return mirror_complete(points, camera, settings.paper)


def mirror_complete(points: np.ndarray, camera: Camera, s: PaperSettings, view: View | None = None) -> Completion:
    """The ``paper`` method with its settings section; ``view`` reuses a rasterised view of ``points``."""
    planes = hypothesis_planes(
        points,
        translations=s.translations,
        translation_step=s.translation_step,
        translation_first=s.translation_first,
        rotations_x=s.rotations_x,
        rotation_x_step=s.rotation_x_step,
        rotations_y=s.rotations_y,
        rotation_y_step=s.rotation_y_step,
    )
    if view is None:
        view = rasterise(points, camera, fill_radius=s.fill_radius)
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = points.mean(axis=0) if s.centre == "centroid" else (lo + hi) / 2.0
    dist_ref = float((hi - lo).max())

    dtype = np.float32 if s.precision == "single" else np.float64
    rated = points
    if s.rating_points is not None and len(points) > s.rating_points:
        pick = np.random.default_rng(0).choice(len(points), size=s.rating_points, replace=False)
        rated = points[np.sort(pick)]
    hypothesis_scores = rate_planes(
        rated, planes.points, planes.normals, view, camera, centre, dist_ref, s, dtype=dtype
    )

    best = int(np.argmax(hypothesis_scores))  # argmax returns the first of equal maxima
    plane = planes[best]
    completed = np.vstack([points, mirror(points, plane.point, plane.normal)])
    return Completion(
        points=completed,
        box=Box.from_points(completed),
        plane=plane,
        score=float(hypothesis_scores[best]),
        scores=hypothesis_scores,
        planes=planes,
        extras={
            "best_index": best,
            "dist_ref": dist_ref,
            "fill_radius": view.fill_radius,
            "offset": float(planes.offsets[best]),
            "angle_x": float(planes.angles_x[best]),
            "angle_y": float(planes.angles_y[best]),
        },
    )
