"""The paper's symmetry completion as one function: known answers on a sphere, what the result holds,
input normalisation."""

import numpy as np
import pytest

from symfruit import Box, InputError, box_iou
from symfruit.core.planes import PlaneGrid, hypothesis_planes, mirror
from symfruit.core.raster import rasterise
from symfruit.core.rating import Table1
from symfruit.core.symmetry import complete_by_symmetry

from ..conftest import VISIBLE, front_half, sphere_cloud

ON_AXIS = np.array([0.0, 0.0, 0.35])
#: The front half of a 20 mm sphere on the optical axis: its centroid is 10 mm in front of the centre
#: and its depth extent is 20 mm, so a translation of half the depth extent puts the plane through the centre.
HEMISPHERE = front_half(sphere_cloud(centre=ON_AXIS, n=2400), ON_AXIS)
GRID = {"grid": PlaneGrid(translations=2, translation_step=0.5, rotations_x=3, rotations_y=3)}


def test_the_plane_through_the_centre_wins_and_completes_the_sphere(camera):
    done = complete_by_symmetry(HEMISPHERE, camera, **GRID)
    assert len(done.planes) == 18 and len(done.scores) == 18
    # Translation-major: indices 9-17 are the planes through the centre; 13 is the unrotated one.
    assert done.best == 13 and done.extras()["angle_x"] == 0.0 and done.extras()["angle_y"] == 0.0
    assert np.allclose(done.plane.normal, [0.0, 0.0, 1.0])
    assert done.plane.point[2] == pytest.approx(ON_AXIS[2], abs=1e-4)
    assert done.scores[9:].min() > 0.9 > -3.0 > done.scores[:9].max()  # planes through the visible centroid fail
    assert box_iou(done.box, Box(ON_AXIS - 0.02, ON_AXIS + 0.02)) > 0.99


def test_the_result_is_the_visible_points_and_their_mirror_image(camera):
    done = complete_by_symmetry(VISIBLE, camera)
    n = len(VISIBLE)
    assert done.points.shape == (2 * n, 3)
    assert np.array_equal(done.points[:n], VISIBLE)
    assert np.allclose(done.points[n:], mirror(VISIBLE, done.plane.point, done.plane.normal), atol=1e-12)
    assert np.array_equal(done.box.min, done.points.min(axis=0)) and np.array_equal(
        done.box.max, done.points.max(axis=0)
    )
    assert done.best == int(np.flatnonzero(done.scores == done.scores.max())[0])  # the first of equal best
    assert done.score == done.scores[done.best]
    assert np.array_equal(done.plane.point, done.planes.points[done.best])
    assert done.dist_ref == pytest.approx(float(np.ptp(VISIBLE, axis=0).max()))
    extras = done.extras()
    assert extras["best_index"] == done.best and extras["dist_ref"] == done.dist_ref
    assert extras["offset"] == done.planes.offsets[done.best] and extras["fill_radius"] == done.view.fill_radius


def test_the_grid_is_the_papers_by_default(camera):
    done = complete_by_symmetry(VISIBLE, camera)
    planes = hypothesis_planes(VISIBLE)
    assert len(done.planes) == 132
    assert np.array_equal(done.planes.normals, planes.normals) and np.array_equal(done.planes.points, planes.points)


def test_lists_and_integers_are_accepted(camera):
    as_array = complete_by_symmetry(VISIBLE, camera)
    as_list = complete_by_symmetry(VISIBLE.tolist(), camera)
    assert np.array_equal(as_list.scores, as_array.scores) and as_list.best == as_array.best
    # Integer coordinates (tenths of a millimetre): projection and rating are scale-free, so the scores
    # equal those of the same numbers as floats.
    tenths = np.rint(VISIBLE * 1e4).astype(np.int64)
    from_ints = complete_by_symmetry(tenths, camera)
    from_floats = complete_by_symmetry(tenths.astype(np.float64), camera)
    assert np.array_equal(from_ints.scores, from_floats.scores) and np.array_equal(from_ints.points, from_floats.points)


@pytest.mark.parametrize(
    "points, message",
    [(np.zeros((10, 2)), r"shape \(n, 3\)"), (VISIBLE[:2], "at least 3 points"), ("abc", "numeric|shape")],
)
def test_wrong_shapes_are_refused(camera, points, message):
    with pytest.raises(InputError, match=message):
        complete_by_symmetry(points, camera)


def test_options_reach_the_rating(camera):
    single = complete_by_symmetry(VISIBLE, camera)
    double = complete_by_symmetry(VISIBLE, camera, precision="double")
    assert double.best == single.best and np.allclose(double.scores, single.scores, atol=1e-4)
    every = complete_by_symmetry(VISIBLE, camera, rating_points=None)
    enough = complete_by_symmetry(VISIBLE, camera, rating_points=len(VISIBLE))  # no subset needed
    assert np.array_equal(every.scores, enough.scores)
    subset = complete_by_symmetry(VISIBLE, camera, rating_points=100)
    again = complete_by_symmetry(VISIBLE.copy(), camera, rating_points=100)
    assert np.array_equal(subset.scores, again.scores)  # a fixed (seeded) subset
    assert not np.array_equal(subset.scores, every.scores)
    literal = complete_by_symmetry(VISIBLE, camera, scoring="literal")
    assert not np.array_equal(literal.scores, single.scores)
    strict = complete_by_symmetry(VISIBLE, camera, table=Table1(k3=2.0))
    assert strict.scores.max() > single.scores.max()  # positive cases score k3


def test_a_view_is_reused_when_given(camera):
    view = rasterise(VISIBLE, camera, fill_radius=3.0)
    reused = complete_by_symmetry(VISIBLE, camera, view=view)
    fresh = complete_by_symmetry(VISIBLE, camera, fill_radius=3.0)
    assert reused.view is view and np.array_equal(reused.scores, fresh.scores)
