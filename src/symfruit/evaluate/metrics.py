"""Metrics of a completion against the truth: box IoU and centre deviation (paper Eq. 12, Fig. 8),
and the Chamfer distance and F1 score of the sweet-pepper shape-completion benchmark (Magistri et al.)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ..core.box import Box, box_iou, centre_deviation
from ..core.limits import shown
from ..core.points import as_points
from ..errors import InputError

__all__ = ["Scores", "chamfer_f1", "score_completion"]


@dataclass(frozen=True)
class Scores:
    """Metrics of one completed fruit (millimetres for distances).

    ``depth_mm`` and ``lateral_mm`` are signed size errors of the box (positive: too large): its depth side
    (along the camera's z) against the truth's, and its larger lateral side (x or y) against the truth's
    larger lateral side, the two measures of issue 18 (a caliper's diameter against a robot's box).
    """

    iou: float
    centre_mm: float
    chamfer_mm: float
    f1: float
    precision: float
    recall: float
    depth_mm: float = float("nan")
    lateral_mm: float = float("nan")


def chamfer_f1(
    completed: np.ndarray, truth: np.ndarray, *, threshold: float = 0.005
) -> tuple[float, float, float, float]:
    """Chamfer distance and F1 between two clouds.

    Chamfer is the mean of the two directed mean nearest-neighbour distances,
    ``(mean_a min_b |a - b| + mean_b min_a |a - b|) / 2``; precision is the share of completed points
    within ``threshold`` of the truth, recall the share of truth points within it of the completion,
    and F1 their harmonic mean.

    Parameters
    ----------
    completed, truth : (n, 3), (m, 3) float, metres
        At least one finite point each (else :class:`~symfruit.errors.InputError`).
    threshold : float, metres, > 0

    Returns
    -------
    chamfer : float, metres
    f1, precision, recall : float in [0, 1]

    Examples
    --------
    >>> pts = np.random.default_rng(0).random((100, 3))
    >>> chamfer_f1(pts, pts)
    (0.0, 1.0, 1.0, 1.0)
    """
    completed, truth = as_points(completed, name="completed"), as_points(truth, name="truth")  # >= 1 point each
    for name, cloud in (("completed", completed), ("truth", truth)):  # scipy's 'x must be finite' before
        if not np.isfinite(cloud).all():
            raise InputError(f"chamfer_f1: {name} points hold NaN or infinite coordinates; drop those rows first")
    if isinstance(threshold, bool) or not isinstance(threshold, int | float | np.integer | np.floating):
        raise InputError(f"chamfer_f1: threshold must be metres, got {shown(threshold)}")
    if not 0.0 < threshold < np.inf:  # NaN: F1 0 in silence
        raise InputError(f"chamfer_f1: threshold must be metres > 0, got {threshold!r}")
    d_ct, _ = cKDTree(truth).query(completed)
    d_tc, _ = cKDTree(completed).query(truth)
    chamfer = float((d_ct.mean() + d_tc.mean()) / 2.0)
    precision = float((d_ct <= threshold).mean())
    recall = float((d_tc <= threshold).mean())
    f1 = 0.0 if precision + recall == 0 else 2.0 * precision * recall / (precision + recall)
    return chamfer, f1, precision, recall


def score_completion(box: Box, completed: np.ndarray, truth_box: Box, truth_surface: np.ndarray) -> Scores:
    """All metrics of one completion against the true box and surface."""
    chamfer, f1, precision, recall = chamfer_f1(completed, truth_surface)
    return Scores(
        iou=box_iou(box, truth_box),
        centre_mm=centre_deviation(box, truth_box) * 1000.0,
        chamfer_mm=chamfer * 1000.0,
        f1=f1,
        precision=precision,
        recall=recall,
        depth_mm=float(box.size[2] - truth_box.size[2]) * 1000.0,
        lateral_mm=float(box.size[:2].max() - truth_box.size[:2].max()) * 1000.0,
    )
