"""The paper's symmetry completion (Ge et al. sections 3.2-3.6) as one array-in, result-out function.

Hypothesise planes (:mod:`.planes`), rasterise what the camera saw (:mod:`.raster`), mirror and rate
every point through every plane at once (:mod:`.rating`), keep the best mean score (ties to the first,
as in the paper), merge the mirrored points with the visible ones and box them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from .box import Box
from .camera import Camera
from .planes import PAPER_GRID, Plane, PlaneGrid, Planes, hypothesis_planes, mirror
from .points import as_points, subsample
from .raster import View, rasterise
from .rating import Scoring, Table1, rate_planes

__all__ = ["SymmetryCompletion", "complete_by_symmetry"]


@dataclass(frozen=True)
class SymmetryCompletion:
    """The best mirror plane and what it completes.

    Attributes
    ----------
    points : (2n, 3) float, metres
        The visible points followed by their mirror images.
    box : Box
        The box of ``points``.
    plane : Plane
        The winning hypothesis.
    score : float
        Its mean score.
    scores : (h,) float
        Every hypothesis's mean score, in the order of ``planes``.
    planes : Planes
    view : View
        The rasterised visible fruit the hypotheses were rated against.
    best : int
        Index of the winner.
    dist_ref : float, metres
        ``Dist_ref``, the largest extent of the visible points.
    """

    points: np.ndarray
    box: Box
    plane: Plane
    score: float
    scores: np.ndarray
    planes: Planes
    view: View
    best: int
    dist_ref: float

    def extras(self) -> dict[str, Any]:
        """JSON-ready details of the winner."""
        return {
            "best_index": self.best,
            "dist_ref": self.dist_ref,
            "fill_radius": self.view.fill_radius,
            "offset": float(self.planes.offsets[self.best]),
            "angle_x": float(self.planes.angles_x[self.best]),
            "angle_y": float(self.planes.angles_y[self.best]),
        }


def complete_by_symmetry(
    points: np.ndarray,
    camera: Camera,
    *,
    grid: PlaneGrid = PAPER_GRID,
    table: Table1 | None = None,
    scoring: Scoring = "continuous",
    centre: Literal["centroid", "box"] = "centroid",
    fill_radius: float | None = None,
    precision: Literal["single", "double"] = "single",
    rating_points: int | None = 1500,
    view: View | None = None,
) -> SymmetryCompletion:
    """Complete one fruit by its best mirror plane.

    Parameters
    ----------
    points : (n, 3) float, metres
        The visible points, camera optical frame.
    camera : Camera
    grid : PlaneGrid
        The hypothesis grid (:func:`~symfruit.core.planes.hypothesis_planes`; the paper's by default).
    table : Table1, optional
        Rating constants (default: the paper's Table 1).
    scoring : {"continuous", "literal"}
        How Eqs. 6-10 are read (:mod:`symfruit.core.rating`).
    centre : {"centroid", "box"}
        The "centre of original points" ``Dist2c`` is measured from.
    fill_radius : float, pixels, optional
        Gap closing of the visible mask (:func:`~symfruit.core.raster.rasterise`); None estimates it.
    precision : {"single", "double"}
        Precision of the rating; the plane and the completion are always double.
    rating_points : int, optional
        Rate on a fixed random subset of at most this many points (None: all).
    view : View, optional
        A rasterised view of ``points`` to reuse.

    Returns
    -------
    SymmetryCompletion
    """
    points = as_points(points, min_count=3)
    planes = hypothesis_planes(points, grid)
    if view is None:
        view = rasterise(points, camera, fill_radius=fill_radius)
    lo, hi = points.min(axis=0), points.max(axis=0)
    ref = points.mean(axis=0) if centre == "centroid" else (lo + hi) / 2.0
    dist_ref = float((hi - lo).max())
    dtype = np.float32 if precision == "single" else np.float64
    rated = subsample(points, rating_points)
    scores = rate_planes(rated, planes.points, planes.normals, view, camera, centre=ref, dist_ref=dist_ref,
                         table=table, scoring=scoring, dtype=dtype)  # fmt: skip
    best = int(np.argmax(scores))  # argmax returns the first of equal maxima
    plane = planes[best]
    completed = np.vstack([points, mirror(points, plane.point, plane.normal)])
    return SymmetryCompletion(points=completed, box=Box.from_points(completed), plane=plane,
                              score=float(scores[best]), scores=scores, planes=planes, view=view, best=best,
                              dist_ref=dist_ref)  # fmt: skip
