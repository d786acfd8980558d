"""The front surface's depth: unbiased under depth noise, exact on clean data."""

import numpy as np
import pytest

from symfruit import InputError
from symfruit.core.front import apex_depth, sphere_front

from ..conftest import ball_mesh, rendered_view


def test_apex_depth_is_unbiased_under_noise():
    visible, _ = rendered_view(ball_mesh(), [0.02, -0.01, 0.45], noise=0.01, seed=1)
    z, apex = apex_depth(visible)
    truth = 0.45 - 0.035  # the ball's nearest point (straight in front of the centre, up to 0.1 mm)
    assert visible[:, 2].min() < truth - 0.002  # the raw minimum is biased towards the camera
    assert z == pytest.approx(truth, abs=5e-4)
    assert apex[2] == z and np.hypot(apex[0] - 0.02, apex[1] + 0.01) < 0.004


def test_apex_depth_of_a_clean_view_is_its_minimum():
    visible, _ = rendered_view(ball_mesh(), [0.0, 0.0, 0.3])
    z, _ = apex_depth(visible)
    assert z == pytest.approx(visible[:, 2].min(), abs=1e-4)


def test_apex_depth_refuses_too_few_points():
    with pytest.raises(InputError):
        apex_depth(np.zeros((5, 3)))


def _former_apex_depth(points, share=0.08, min_points=12):
    """apex_depth as it was before issue 19's nineteenth round (LAPACK's eigvalsh and solve of the 2x2 Hessian)."""
    from symfruit.core.points import column_means, squared_norms

    p = np.asarray(points, dtype=np.float64)
    n = len(p)
    front = max(1, int(0.02 * n))
    seed = column_means(p[np.argpartition(p[:, 2], front - 1)[:front], :2])
    k = min(n, max(min_points, int(share * n)))
    d2 = squared_norms(p[:, :2] - seed)
    pick = np.argpartition(d2, k - 1)[:k]
    near = p[pick]
    x, y = near[:, 0] - seed[0], near[:, 1] - seed[1]
    a = np.stack((np.ones(k), x, y, x * x, x * y, y * y), axis=1)
    coef, *_ = np.linalg.lstsq(a, near[:, 2], rcond=None)
    fitted = a @ coef
    i = int(np.argmin(fitted))
    best_z, best_xy = float(fitted[i]), np.array([x[i], y[i]])
    hess = np.array([[2 * coef[3], coef[4]], [coef[4], 2 * coef[5]]])
    vertex = False
    if np.all(np.linalg.eigvalsh(hess) > 0):
        v = np.linalg.solve(hess, -coef[1:3])
        if v @ v <= float(d2[pick].max()):
            zv = float(np.array([1.0, v[0], v[1], v[0] ** 2, v[0] * v[1], v[1] ** 2]) @ coef)
            if zv < best_z:
                best_z, best_xy, vertex = zv, v, True
    return best_z, np.concatenate((best_xy + seed, [best_z])), vertex


def test_apex_depth_is_the_former_lapack_one_bit_for_bit():
    """The Hessian's eigenvalues and vertex by closed forms (issue 19, nineteenth round): the same depth and apex,
    bit for bit on this project's machines, as with LAPACK's eigvalsh and solve (checked to 1e-12, as another
    architecture's LAPACK may round in the last place), on 600 caps, noisy and clean, convex and saddle-shaped, of 6
    to 1,500 points; the vertex decides on many of them."""
    rng = np.random.default_rng(0)
    vertices = 0
    for i in range(600):
        n = int(rng.integers(6, 1500))
        xy = rng.normal(size=(n, 2)) * 0.02
        curv = rng.normal(size=3) * 20.0
        z = 0.4 + curv[0] * xy[:, 0] ** 2 + curv[1] * xy[:, 0] * xy[:, 1] + curv[2] * xy[:, 1] ** 2
        pts = np.column_stack((xy, z + rng.normal(size=n) * rng.choice([0.0, 1e-4, 1e-3])))
        if i % 5 == 0:
            pts = np.round(pts, 3)
        want_z, want_apex, vertex = _former_apex_depth(pts)
        got_z, got_apex = apex_depth(pts)
        np.testing.assert_allclose(got_z, want_z, rtol=1e-12, atol=0.0)
        np.testing.assert_allclose(got_apex, want_apex, rtol=1e-12, atol=1e-15)
        vertices += vertex
    assert vertices > 50


def test_apex_depth_builds_the_former_apex_to_the_bit():
    """The apex made of Python floats (issue 19, stop 65: the arrays' own argpartition and argmin, one ``np.array``
    for ``np.concatenate((best_xy + seed, [best_z]))``): where the quadric's lowest fitted point decides (no vertex,
    whose 2x2 solve may round otherwise on another architecture), the same depth and apex bytes as the former
    function's, on 300 caps of 6 to 1,500 points; and the apex a float64 (3,) array either way."""
    rng = np.random.default_rng(1)
    exact = 0
    for _ in range(300):
        n = int(rng.integers(6, 1500))
        xy = rng.normal(size=(n, 2)) * 0.02
        curv = rng.normal(size=3) * 20.0
        z = 0.4 + curv[0] * xy[:, 0] ** 2 + curv[1] * xy[:, 0] * xy[:, 1] + curv[2] * xy[:, 1] ** 2
        pts = np.column_stack((xy + rng.normal(size=2), z + rng.normal(size=n) * rng.choice([0.0, 1e-4, 1e-3])))
        want_z, want_apex, vertex = _former_apex_depth(pts)
        got_z, got_apex = apex_depth(pts)
        assert got_apex.dtype == np.float64 and got_apex.shape == (3,)
        if not vertex:
            assert got_z == want_z and got_apex.tobytes() == want_apex.tobytes()
            exact += 1
    assert exact > 50


def test_sphere_front_places_a_hidden_front_from_the_seen_cap():
    """A 35 mm ball at 0.45 m whose lower two thirds a leaf hides: the nearest seen point lies 4.7 mm behind the
    ball's front; the sphere of the ball's radius through the seen cap has it within 0.3 mm (noisy depths)."""
    from ..conftest import occluded_view

    visible, _, _, _ = occluded_view(ball_mesh(), [0.0, 0.03, 0.45], below=255, occluder_z=0.38, noise=0.005, seed=1)
    truth = 0.45 - 0.035
    assert visible[:, 2].min() > truth + 0.004
    z, apex = sphere_front(visible, 0.035)
    assert z == pytest.approx(truth, abs=3e-4)
    assert apex[2] == z and np.hypot(apex[0], apex[1] - 0.03) < 0.002


def test_sphere_front_is_unbiased_under_noise_where_the_apex_is_seen():
    """The whole visible cap of the ball under axial noise of 1.6 mm: the fixed-radius sphere's front stays within
    0.2 mm of the truth over five noise draws (the noisy minimum lies several deviations in front)."""
    truth = 0.45 - 0.035
    fronts = [sphere_front(rendered_view(ball_mesh(), [0.0, 0.0, 0.45], noise=0.008, seed=s)[0], 0.035)[0]
              for s in range(5)]  # fmt: skip
    assert np.mean(fronts) == pytest.approx(truth, abs=2e-4)


def test_sphere_front_refuses_a_radius_not_above_zero():
    with pytest.raises(InputError):
        sphere_front(np.random.default_rng(0).normal(size=(10, 3)), 0.0)
