import numpy as np
import pytest

from symfruit import Box, box_iou, centre_deviation
from symfruit.metrics import chamfer_f1, score_completion

UNIT = Box(np.zeros(3), np.ones(3))


@pytest.mark.parametrize(
    "other, iou",
    [
        (UNIT, 1.0),  # identical
        (Box(np.full(3, 2.0), np.full(3, 3.0)), 0.0),  # disjoint
        (Box(np.full(3, 1.0), np.full(3, 2.0)), 0.0),  # touching at a corner
        (Box(np.full(3, 0.25), np.full(3, 0.75)), 0.125),  # nested: 0.5^3 / 1
        (Box(np.array([0.5, 0, 0]), np.array([1.5, 1, 1])), 1 / 3),  # shifted by half along x
        (Box(np.array([0.5, 0.5, 0]), np.array([1.5, 1.5, 1])), 0.25 / 1.75),  # shifted along x and y
    ],
)
def test_box_iou_known_answers(other, iou):
    assert box_iou(UNIT, other) == pytest.approx(iou)
    assert box_iou(other, UNIT) == pytest.approx(iou)


def test_centre_deviation():
    assert centre_deviation(UNIT, Box(np.array([3.0, 4.0, 0.0]), np.array([4.0, 5.0, 1.0]))) == pytest.approx(5.0)


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
