"""Marangoz et al.'s superellipsoid fit: down-sampling, normals, the normal-line centre, the analytic Jacobian,
known superellipsoids recovered, their bounds, the surface samplers and the missing surface."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from symfruit.core.superellipsoid import (
    Superellipsoid,
    _evaluate,
    _rotation,
    fit_superellipsoid,
    line_intersection_centre,
    missing_surface,
    radius_normals,
    superellipsoid_box,
    superellipsoid_fibonacci,
    voxel_downsample,
)
from symfruit.errors import InputError

from ..conftest import FUZZ_EXAMPLES


def _sphere_points(n: int, r: float, centre, rng) -> np.ndarray:
    d = rng.normal(size=(n, 3))
    return r * d / np.linalg.norm(d, axis=1, keepdims=True) + centre


def _superellipsoid(axes, e1, e2, angles, centre) -> Superellipsoid:
    m, _ = _rotation(np.asarray(angles, float))
    return Superellipsoid(np.asarray(centre, float), np.asarray(axes, float), e1, e2, m.T, np.asarray(angles, float),
                          np.asarray(centre, float), 0.0, True, 0)  # fmt: skip


def test_voxel_downsample_one_point_per_cell():
    g = np.stack(np.meshgrid(np.arange(4), np.arange(3), np.arange(2), indexing="ij"), -1).reshape(-1, 3) * 0.01
    pts = np.vstack([g + 0.0025, g + 0.0045])  # two points per cell of the grid anchored at the minimum
    out = voxel_downsample(pts, voxel=0.0099)
    assert len(out) == len(g)
    np.testing.assert_allclose(np.sort(out, axis=0), np.sort(g + 0.0035, axis=0), atol=1e-12)
    with pytest.raises(InputError):
        voxel_downsample(pts, voxel=0.0)


def test_radius_normals_of_a_plane_are_its_normal():
    rng = np.random.default_rng(0)
    pts = np.c_[rng.uniform(-0.05, 0.05, (500, 2)), np.full(500, 0.3)]
    normals, counts = radius_normals(pts, radius=0.015)
    assert np.all(counts >= 3)
    np.testing.assert_allclose(np.abs(normals[:, 2]), 1.0, atol=1e-9)


def test_line_intersection_of_sphere_normals_is_the_centre():
    rng = np.random.default_rng(1)
    c = np.array([0.01, -0.02, 0.4])
    pts = _sphere_points(300, 0.03, c, rng)
    normals = (pts - c) * rng.choice([-1.0, 1.0], size=(300, 1))  # the sign must not matter
    np.testing.assert_allclose(line_intersection_centre(pts, normals, regularization=0.0), c, atol=1e-9)
    biased = line_intersection_centre(pts, normals, regularization=1e6)
    np.testing.assert_allclose(biased, pts.mean(axis=0), atol=1e-5)
    with pytest.raises(InputError):
        line_intersection_centre(pts, normals[:10])


def test_superellipsoid_jacobian_matches_finite_differences():
    rng = np.random.default_rng(2)
    pts = rng.normal(size=(40, 3)) * 0.03 + [0.01, 0.02, 0.3]
    th = np.array([0.04, 0.05, 0.03, 0.6, 0.7, 0.01, 0.02, 0.31, 10.0, -20.0, 30.0])
    args = (pts, np.array([0.0, 0.01, 0.3]), 0.7, 0.5)
    _, jac = _evaluate(th, *args, jacobian=True)
    num = np.empty_like(jac)
    for i in range(11):
        h = 1e-7 * max(1.0, abs(th[i]))
        tp, tm = th.copy(), th.copy()
        tp[i] += h
        tm[i] -= h
        num[:, i] = (_evaluate(tp, *args, jacobian=False)[0] - _evaluate(tm, *args, jacobian=False)[0]) / (2 * h)
    np.testing.assert_allclose(jac, num, atol=1e-6)


def test_superellipsoid_fit_recovers_a_known_superellipsoid():
    se = _superellipsoid([0.05, 0.04, 0.03], 0.6, 0.7, [15.0, -10.0, 25.0], [0.02, -0.01, 0.4])
    pts = superellipsoid_fibonacci(se, n=2000)
    fit = fit_superellipsoid(pts, voxel=None, prior_scaling=0.0, prior_center=0.0)
    np.testing.assert_allclose(fit.centre, se.centre, atol=2e-4)
    np.testing.assert_allclose(np.sort(fit.axes), np.sort(se.axes), atol=1e-3)
    assert sorted([fit.e1, fit.e2]) == pytest.approx(sorted([se.e1, se.e2]), abs=0.05)


def test_superellipsoid_defaults_on_a_front_half_keep_their_bounds():
    rng = np.random.default_rng(3)
    pts = _sphere_points(4000, 0.04, [0.0, 0.0, 0.4], rng)
    front = pts[pts[:, 2] < 0.4]
    fit = fit_superellipsoid(front)
    assert np.all(fit.axes >= 0.02 - 1e-12) and np.all(fit.axes <= 0.15 + 1e-12)
    assert 0.3 - 1e-12 <= fit.e1 <= 0.9 + 1e-12 and 0.3 - 1e-12 <= fit.e2 <= 0.9 + 1e-12
    assert np.linalg.norm(fit.centre - [0.0, 0.0, 0.4]) < 0.01
    assert fit.n_fit < len(front)  # the 4 mm voxel grid thinned the cloud
    missing = missing_surface(fit, front)
    assert len(missing) > 0 and np.mean(missing[:, 2]) > 0.4  # the unseen surface is at the back


@settings(max_examples=max(5, FUZZ_EXAMPLES // 2))
@given(
    e1=st.floats(0.3, 1.0), e2=st.floats(0.3, 1.0),
    axes=st.lists(st.floats(0.01, 0.1), min_size=3, max_size=3),
    angles=st.lists(st.floats(-90, 90), min_size=3, max_size=3),
)  # fmt: skip
def test_fibonacci_samples_lie_on_the_surface(e1, e2, axes, angles):
    se = _superellipsoid(axes, e1, e2, angles, [0.0, 0.0, 0.3])
    p = superellipsoid_fibonacci(se, n=200)
    loc = (p - se.centre) @ se.rotation / se.axes
    ax = np.abs(loc)
    f = (ax[:, 0] ** (2 / e2) + ax[:, 1] ** (2 / e2)) ** (e2 / e1) + ax[:, 2] ** (2 / e1)
    np.testing.assert_allclose(f ** (e1 / 2), 1.0, atol=2e-3)


def test_superellipsoid_box_of_a_ball():
    se = _superellipsoid([0.03, 0.03, 0.03], 1.0, 1.0, [30.0, 20.0, 10.0], [0.0, 0.01, 0.3])
    lo, hi = superellipsoid_box(se)
    np.testing.assert_allclose(lo, se.centre - 0.03, atol=1e-4)
    np.testing.assert_allclose(hi, se.centre + 0.03, atol=1e-4)


def test_superellipsoid_rejects_bad_input():
    with pytest.raises(InputError):
        fit_superellipsoid(np.zeros((5, 3)))
    with pytest.raises(InputError):
        fit_superellipsoid(np.zeros((20, 2)))
    with pytest.raises(InputError):
        fit_superellipsoid([[np.nan, 0.0, 0.3]] * 30)
