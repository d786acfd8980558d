import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from symfruit.core.planes import Plane, PlaneGrid, hypothesis_planes, mirror
from symfruit.errors import InputError

coords = arrays(np.float64, (12, 3), elements=st.floats(-1.0, 1.0))
unit = arrays(np.float64, 3, elements=st.floats(-1.0, 1.0)).filter(lambda v: np.linalg.norm(v) > 0.1)


@given(coords, arrays(np.float64, 3, elements=st.floats(-1.0, 1.0)), unit)
def test_mirror_is_an_involution_and_an_isometry(points, q, n):
    once = mirror(points, q, n)
    assert np.allclose(mirror(once, q, n), points, atol=1e-9)
    d_before = np.linalg.norm(points[:, None] - points[None], axis=-1)
    d_after = np.linalg.norm(once[:, None] - once[None], axis=-1)
    assert np.allclose(d_before, d_after, atol=1e-9)


@given(arrays(np.float64, 3, elements=st.floats(-1.0, 1.0)), unit, st.floats(-1.0, 1.0), st.floats(-1.0, 1.0))
def test_points_on_the_plane_stay_put(q, n, a, b):
    n = n / np.linalg.norm(n)
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(n, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    p = (q + a * e1 + b * e2)[None]
    assert np.allclose(mirror(p, q, n), p, atol=1e-9)


def test_mirror_through_z_plane_known_answer():
    p = np.array([[0.1, 0.2, 0.30]])
    assert np.allclose(mirror(p, [0, 0, 0.35], [0, 0, 1]), [[0.1, 0.2, 0.40]])


def test_batched_mirror_matches_single_planes():
    rng = np.random.default_rng(3)
    pts = rng.normal(size=(50, 3))
    qs, ns = rng.normal(size=(7, 3)), rng.normal(size=(7, 3))
    batch = mirror(pts, qs, ns)
    assert batch.shape == (7, 50, 3)
    for i in range(7):
        assert np.allclose(batch[i], mirror(pts, qs[i], ns[i]))


def test_default_grid_is_the_papers(sphere_view):
    planes = hypothesis_planes(sphere_view)
    assert len(planes) == 132  # m=4, j=11, k=3
    assert np.allclose(np.linalg.norm(planes.normals, axis=1), 1.0)
    assert sorted(set(np.round(planes.angles_x, 6))) == [5.0 * i for i in range(-5, 6)]
    assert sorted(set(np.round(planes.angles_y, 6))) == [-5.0, 0.0, 5.0]
    len_depth = np.ptp(sphere_view[:, 2])
    assert np.allclose(sorted(set(np.round(planes.offsets / len_depth, 9))), [0.0, 0.2, 0.4, 0.6])
    # Translation-major order; the first plane is the initial hypothesis (section 3.2) rotated to the
    # first angles; the unrotated initial plane is through the centroid with normal +z.
    centre = np.flatnonzero((planes.offsets == 0) & (planes.angles_x == 0) & (planes.angles_y == 0))
    assert len(centre) == 1
    assert np.allclose(planes.normals[centre[0]], [0, 0, 1])
    assert np.allclose(planes.points[centre[0]], sphere_view.mean(axis=0))
    assert np.all(np.diff(planes.offsets) >= 0)


def test_rotations_are_about_x_and_y_not_z(sphere_view):
    # Eq. 3 of the paper prints a rotation about z, which would leave every normal at +z.
    planes = hypothesis_planes(sphere_view, PlaneGrid(translations=1, rotations_x=3, rotations_y=1, rotation_x_step=10))
    assert np.allclose(planes.normals[0], [0.0, np.sin(np.radians(10)), np.cos(np.radians(10))])
    planes = hypothesis_planes(sphere_view, PlaneGrid(translations=1, rotations_x=1, rotations_y=3, rotation_y_step=10))
    assert np.allclose(planes.normals[2], [np.sin(np.radians(10)), 0.0, np.cos(np.radians(10))])


@pytest.mark.parametrize("m, j, k", [(1, 1, 1), (2, 5, 7), (10, 22, 6)])
def test_grid_sizes(sphere_view, m, j, k):
    assert len(hypothesis_planes(sphere_view, PlaneGrid(translations=m, rotations_x=j, rotations_y=k))) == m * j * k


def test_mirror_accepts_lists_and_integers():
    assert np.allclose(mirror([[1, 2, 3]], [0, 0, 0], [0, 0, 2]), [[1.0, 2.0, -3.0]])  # the normal is normalised
    batch = mirror([[1, 2, 3]], [[0, 0, 0], [1, 0, 0]], [[0, 0, 1], [1, 0, 0]])
    assert batch.shape == (2, 1, 3) and np.allclose(batch, [[[1.0, 2.0, -3.0]], [[1.0, 2.0, 3.0]]])


def test_planes_index_to_copies_and_serialise(sphere_view):
    planes = hypothesis_planes(sphere_view, PlaneGrid(translations=2, rotations_x=1, rotations_y=1))
    first = planes[1]
    assert np.array_equal(first.point, planes.points[1]) and np.array_equal(first.normal, planes.normals[1])
    first.point[0] = 99.0
    assert planes.points[1, 0] != 99.0  # a copy: the batch is untouched
    assert planes[0].to_dict() == {"point": planes.points[0].tolist(), "normal": [0.0, 0.0, 1.0]}


def test_first_translation_and_negative_steps(sphere_view):
    len_depth = np.ptp(sphere_view[:, 2])
    planes = hypothesis_planes(
        sphere_view, PlaneGrid(translations=2, translation_first=-1.0, rotations_x=1, rotations_y=1)
    )
    assert np.allclose(planes.offsets, [-0.2 * len_depth, 0.0])
    planes = hypothesis_planes(
        sphere_view, PlaneGrid(translations=1, rotations_x=3, rotation_x_step=-10.0, rotations_y=1)
    )
    assert np.allclose(planes.angles_x, [10.0, 0.0, -10.0])


def test_hypothesis_planes_accept_a_list(sphere_view):
    assert len(hypothesis_planes(sphere_view.tolist())) == 132


def test_hypothesis_planes_refuse_wrong_shapes():
    from symfruit import InputError

    with pytest.raises(InputError, match="shape"):
        hypothesis_planes(np.zeros((5, 2)))


def test_mirror_refuses_wrong_shapes():
    from symfruit import InputError

    with pytest.raises(InputError, match="shape"):
        mirror(np.zeros((5, 2)), [0.0, 0.0, 0.0], [0.0, 0.0, 1.0])


@pytest.mark.parametrize(
    ("point", "normal", "what"),
    [
        ([0.0, 0.0, 0.3], [0.0, 0.0, 0.0], "normal must not be zero"),
        ([0.0, 0.0, 0.3], [0.0, float("nan"), 1.0], "normal must be 3 finite"),
        ([0.0, 0.0, 0.3], [0.0, 1.0], "normal must be 3 finite"),
        ([0.0, float("inf"), 0.3], [0.0, 0.0, 1.0], "point must be 3 finite"),
        ("abc", [0.0, 0.0, 1.0], "point must be 3 numbers"),
    ],
)
def test_a_plane_without_a_direction_or_place_is_refused_at_construction(point, normal, what):
    with pytest.raises(InputError, match=what):
        Plane(point=np.array(point), normal=np.array(normal))


def test_a_plane_with_a_unit_normal_is_kept_as_given():
    normal = np.array([0.0, 0.6, 0.8])
    plane = Plane(point=np.zeros(3), normal=normal)
    assert plane.normal is normal and plane.to_dict()["normal"] == [0.0, 0.6, 0.8]


@pytest.mark.parametrize(
    ("normal", "unit"),
    [
        ([0.0, 0.0, 2.0], [0.0, 0.0, 1.0]),  # before: kept as [0, 0, 2], read as a unit normal by to_dict's readers
        ([0.0, -3.0, 4.0], [0.0, -0.6, 0.8]),
        ([0.0, 1e-300, 0.0], [0.0, 1.0, 0.0]),  # its squared length underflows to 0
        ([1e300, 0.0, 1e300], [2**-0.5, 0.0, 2**-0.5]),  # its squared length overflows to inf
    ],
)
def test_a_plane_normal_of_another_length_is_made_unit_the_same_plane(normal, unit):
    plane = Plane(point=[0.0, 0.0, 0.3], normal=normal)
    assert np.allclose(plane.normal, unit, rtol=0, atol=1e-15) and np.linalg.norm(plane.normal) == pytest.approx(1.0)


def test_a_plane_given_lists_holds_arrays():
    plane = Plane(point=[0, 0, 1], normal=(0.0, 0.0, 1.0))  # before: AttributeError 'list' object has no 'tolist'
    assert plane.to_dict() == {"point": [0.0, 0.0, 1.0], "normal": [0.0, 0.0, 1.0]}
    assert plane.point.dtype == np.float64 and plane.normal.dtype == np.float64
