"""Axis-aligned boxes and their overlap (paper Eq. 12): known answers, input normalisation, invariants."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from symfruit import Box, InputError, box_iou, centre_deviation

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


def test_degenerate_boxes_have_no_overlap():
    flat = Box(np.zeros(3), np.array([1.0, 1.0, 0.0]))
    assert flat.volume == 0.0 and box_iou(flat, flat) == 0.0 and box_iou(flat, UNIT) == 0.0


def test_from_points_accepts_lists_and_integers():
    box = Box.from_points([[1, 2, 3], [4, 0, 5], [2, 6, 4]])
    assert box.min.dtype == np.float64 and box.min.tolist() == [1.0, 0.0, 3.0] and box.max.tolist() == [4.0, 6.0, 5.0]
    assert Box.from_points(np.array([[1, 2, 3]], dtype=np.int16)).size.tolist() == [0.0, 0.0, 0.0]
    assert Box([0, 0, 0], (1, 2, 3)).volume == 6.0


@pytest.mark.parametrize(
    "points, message",
    [
        (np.zeros((0, 3)), "at least 1 points"),
        ([], "shape"),
        (np.zeros((4, 2)), r"shape \(n, 3\), got \(4, 2\)"),
        (np.zeros(3), "shape"),
        (np.zeros((2, 3, 1)), "shape"),
        ([["a", "b", "c"]], "numeric"),
        (np.zeros((2, 3), complex), "real"),
    ],
)
def test_from_points_refuses_what_is_not_points(points, message):
    with pytest.raises(InputError, match=message):
        Box.from_points(points)


def test_a_box_needs_two_corners_of_three_coordinates():
    with pytest.raises(InputError, match=r"min and max of shape \(3,\)"):
        Box(np.zeros(2), np.ones(2))
    with pytest.raises(InputError, match=r"got \(3,\) and \(4,\)"):
        Box(np.zeros(3), np.ones(4))


def test_properties_and_dict():
    box = Box(np.array([0.0, -1.0, 2.0]), np.array([2.0, 1.0, 5.0]))
    assert box.centre.tolist() == [1.0, 0.0, 3.5] and box.size.tolist() == [2.0, 2.0, 3.0] and box.volume == 12.0
    assert box.to_dict() == {"min": [0.0, -1.0, 2.0], "max": [2.0, 1.0, 5.0], "size": [2.0, 2.0, 3.0]}
    union = box.union(Box(np.array([-1.0, 0.0, 0.0]), np.array([0.5, 3.0, 1.0])))
    assert union.min.tolist() == [-1.0, -1.0, 0.0] and union.max.tolist() == [2.0, 3.0, 5.0]


def test_corners_follow_the_bit_order():
    box = Box(np.zeros(3), np.array([1.0, 2.0, 3.0]))
    corners = box.corners()
    assert corners.shape == (8, 3)
    for i, corner in enumerate(corners):
        assert corner.tolist() == [(i >> axis & 1) * [1.0, 2.0, 3.0][axis] for axis in range(3)]


def test_contains_with_and_without_tolerance():
    assert UNIT.contains([[0, 0, 0], [1, 1, 1], [0.5, 0.2, 0.9]])
    assert not UNIT.contains([[1.001, 0.5, 0.5]])
    assert UNIT.contains([[1.001, 0.5, 0.5]], tol=0.002)
    assert UNIT.contains(np.zeros((0, 3)))  # nothing to contain
    with pytest.raises(InputError, match="shape"):
        UNIT.contains(np.zeros((2, 2)))


corner = arrays(np.float64, 3, elements=st.floats(-1.0, 1.0))
extent = arrays(np.float64, 3, elements=st.floats(0.01, 1.0))


@given(corner, extent, corner, extent)
def test_iou_is_symmetric_bounded_and_one_only_for_the_same_box(lo_a, size_a, lo_b, size_b):
    a, b = Box(lo_a, lo_a + size_a), Box(lo_b, lo_b + size_b)
    iou = box_iou(a, b)
    assert iou == pytest.approx(box_iou(b, a), abs=1e-12)
    assert 0.0 <= iou <= 1.0 + 1e-12
    assert box_iou(a, a) == pytest.approx(1.0)
    assert box_iou(a, a.union(b)) == pytest.approx(a.volume / a.union(b).volume)
    assert centre_deviation(a, b) == pytest.approx(np.linalg.norm(a.centre - b.centre))


@given(arrays(np.float64, st.tuples(st.integers(1, 30), st.just(3)), elements=st.floats(-10.0, 10.0)))
def test_the_box_of_points_is_the_tightest_that_contains_them(points):
    box = Box.from_points(points)
    assert box.contains(points)
    # Every face of the box touches a point.
    assert np.array_equal(box.min, points.min(axis=0)) and np.array_equal(box.max, points.max(axis=0))


def test_box_from_points_refuses_non_finite_points_and_box_functions_refuse_what_is_no_box():
    with pytest.raises(InputError, match="hold NaN or infinite coordinates"):
        Box.from_points([[0.0, 0.0, 0.3], [0.01, 0.01, np.nan]])  # before: a box of NaN corners
    with pytest.raises(InputError, match="a box needs min and max of 3 numbers"):
        Box("a", "b")  # before: ValueError from numpy
    unit = Box(np.zeros(3), np.ones(3))
    with pytest.raises(InputError, match="box_iou needs two Box"):
        box_iou(unit, np.ones((2, 3)))  # before: TypeError comparing ndarray.max with ndarray.min
    with pytest.raises(InputError, match="centre_deviation needs two Box"):
        centre_deviation(np.zeros(3), unit)  # before: AttributeError


@pytest.mark.parametrize(
    "lo, hi, message",
    [
        ([0.0, 0.0, 1.0], [1.0, 1.0, 0.5], "min lies beyond its max along z"),  # before: size -0.5, volume negative
        ([2.0, 0.0, 0.0], [1.0, 1.0, 1.0], "along x"),
        ([0.0, np.nan, 0.0], [1.0, 1.0, 1.0], "finite corners"),  # before: a box of NaN centre and IoU 0
        ([0.0, 0.0, 0.0], [1.0, np.inf, 1.0], "finite corners"),
        ([-np.inf, 0.0, 0.0], [1.0, 1.0, 1.0], "finite corners"),
    ],
)
def test_a_box_with_its_min_beyond_its_max_or_a_corner_not_finite_is_refused(lo, hi, message):
    with pytest.raises(InputError, match=message):
        Box(np.array(lo), np.array(hi))


def test_a_flat_or_point_box_is_still_a_box():
    assert Box(np.ones(3), np.ones(3)).volume == 0.0
    assert Box([0.0, 0.0, 0.3], [0.0, 0.1, 0.3]).size.tolist() == [0.0, 0.1, 0.0]


def test_union_needs_a_box_and_contains_a_finite_tolerance():
    with pytest.raises(InputError, match=r"Box\.union needs two Box"):
        UNIT.union(np.ones((2, 3)))  # before: TypeError comparing a float with ndarray.min, a method
    for tol in ("a", np.nan, True, None):  # before: a UFuncTypeError, False for NaN (every point 'outside'), True
        with pytest.raises(InputError, match=r"Box\.contains: tol must be a finite number of metres"):
            UNIT.contains([[0.5, 0.5, 0.5]], tol=tol)
    assert UNIT.contains([[1.05, 0.5, 0.5]], tol=np.float32(0.1)) and not UNIT.contains([[0.95, 0.5, 0.5]], tol=-0.1)
