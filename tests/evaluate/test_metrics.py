"""Metrics of a completion against the truth: Chamfer distance, F1, and the box scores in millimetres.

(Box IoU and centre deviation live with the box, in ``tests/core/test_box.py``.)"""

import numpy as np
import pytest

from symfruit import Box
from symfruit.evaluate.metrics import Scores, chamfer_f1, score_completion


def test_chamfer_and_f1_known_answers():
    rng = np.random.default_rng(0)
    a = rng.random((500, 3)) * 0.05
    assert chamfer_f1(a, a) == (0.0, 1.0, 1.0, 1.0)
    # Every point 1 mm away from a copy: chamfer <= 1 mm, all within 5 mm.
    chamfer, f1, _, _ = chamfer_f1(a + [0.001, 0, 0], a)
    assert 0 < chamfer <= 0.001 + 1e-12 and f1 == 1.0
    # A cloud 10 cm away: nothing within 5 mm.
    chamfer, f1, precision, recall = chamfer_f1(a + [0.1, 0, 0], a)
    assert f1 == precision == recall == 0.0 and chamfer > 0.05
    # Half the truth covered: recall 0.5, precision 1.
    truth = np.vstack([a, a + [1.0, 0, 0]])
    _, f1, precision, recall = chamfer_f1(a, truth)
    assert precision == 1.0 and recall == 0.5 and f1 == pytest.approx(2 / 3)


def test_score_completion_in_millimetres():
    pts = np.random.default_rng(1).random((100, 3)) * 0.04
    box = Box.from_points(pts)
    moved = Box(box.min + [0.003, 0.004, 0], box.max + [0.003, 0.004, 0])
    s = score_completion(moved, pts, box, pts)
    assert s.centre_mm == pytest.approx(5.0) and s.chamfer_mm == 0.0 and s.f1 == 1.0 and 0 < s.iou < 1


def test_chamfer_is_the_mean_of_both_directions_and_the_threshold_is_a_keyword():
    a = np.array([[0.0, 0.0, 0.0]])
    b = np.array([[0.0, 0.0, 0.0], [0.004, 0.0, 0.0]])
    chamfer, f1, precision, recall = chamfer_f1(a, b)
    assert chamfer == pytest.approx((0.0 + 0.002) / 2) and precision == 1.0 and recall == 1.0 and f1 == 1.0
    chamfer, f1, precision, recall = chamfer_f1(a, b, threshold=0.003)
    assert (precision, recall) == (1.0, 0.5) and f1 == pytest.approx(2 / 3)
    cube = Box(np.zeros(3), np.full(3, 0.004))
    s = score_completion(cube, a, cube, b)
    assert isinstance(s, Scores) and s.iou == 1.0 and s.centre_mm == 0.0 and s.chamfer_mm == pytest.approx(1.0)


def test_chamfer_refuses_empty_non_finite_or_misshapen_clouds_and_a_threshold_that_is_no_length():
    from symfruit import InputError

    p = np.random.default_rng(0).random((50, 3))
    cases = [
        ((np.zeros((0, 3)), p), {}, "completed must hold at least 1 points"),  # before: NaN chamfer, a warning
        ((p, np.zeros((0, 3))), {}, "truth must hold at least 1 points"),
        ((p, p[:, :2]), {}, r"truth must have shape \(n, 3\)"),  # before: scipy's ValueError
        ((np.r_[p, [[np.nan, 0, 0]]], p), {}, "completed points hold NaN"),  # before: scipy's 'x must be finite'
        ((p, np.r_[p, [[np.inf, 0, 0]]]), {}, "truth points hold NaN or infinite"),
        ((p, p), {"threshold": float("nan")}, "threshold must be metres > 0, got nan"),  # before: F1 0
        ((p, p), {"threshold": -1.0}, "threshold must be metres > 0"),  # before: F1 0
        ((p, p), {"threshold": "a"}, "threshold must be metres, got 'a'"),  # before: UFuncTypeError
    ]
    for args, kwargs, message in cases:
        with pytest.raises(InputError, match=message):
            chamfer_f1(*args, **kwargs)
