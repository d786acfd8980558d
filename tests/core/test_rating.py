"""Rating (paper section 3.5): every location hit by a hand-built mirrored point, scored as documented."""

import numpy as np
import pytest

import symfruit
from symfruit.core.raster import rasterise
from symfruit.core.rating import Table1, rate_planes, rate_points

from ..conftest import CENTRE


@pytest.fixture
def scene(sphere_view, camera):
    view = rasterise(sphere_view, camera)
    centroid = sphere_view.mean(axis=0)
    dist_ref = float(np.ptp(sphere_view, axis=0).max())
    return sphere_view, view, centroid, dist_ref


def rate_targets(scene, camera, targets, table, scoring="continuous", dtype=np.float64):
    """Rate one mirrored point per target: the plane maps a visible point onto the target."""
    visible, view, centroid, dist_ref = scene
    source = visible[np.argmin(visible[:, 2])][None]  # the front pole
    targets = np.atleast_2d(targets)
    normals = targets - source
    points = (targets + source) / 2.0
    rating = rate_points(source, points, normals, view, camera, centre=centroid, dist_ref=dist_ref,
                         table=table, scoring=scoring, dtype=dtype)  # fmt: skip
    return rating.scores[:, 0], rating.locations[:, 0], rating


def ray(camera, u, v, z):
    u, v, z = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float), np.asarray(z, float))
    return camera.deproject(np.stack([u, v], axis=-1), z)


def centre_pixel(camera):
    return camera.project(CENTRE[None])[0]


@pytest.mark.parametrize("scoring", ["continuous", "literal"])
def test_each_location_is_hit_and_scored(scene, camera, scoring):
    s = Table1()
    _, view, centroid, r = scene
    u, v = centre_pixel(camera)
    seen = view.near_depth[(round(v) - view.v0) * view.mask.shape[1] + round(u) - view.u0]
    tol, d0, d1 = s.j1 * r, s.j2 * r, s.j3 * r
    targets = {
        2: ray(camera, u, v, seen - 0.01),  # 10 mm in front of the seen surface
        3: ray(camera, u, v, seen + 0.5 * tol),  # on it
        41: CENTRE,  # hidden, 10 mm from the centroid (< Dist2c_0)
        42: CENTRE + [0.0, 0.0, 0.02],  # the back pole, in the reasonable region
        43: CENTRE + [0.0, 0.0, 0.07],  # far behind
        1: CENTRE + [0.06, 0.0, 0.0],  # beside the fruit, outside the mask
    }
    scores, locations, rating = rate_targets(scene, camera, np.array(list(targets.values())), s, scoring)
    assert locations.tolist() == list(targets)
    gap, d2c = rating.gap[:, 0], rating.dist2c[:, 0]
    assert np.allclose(d2c, np.linalg.norm(np.array(list(targets.values())) - centroid, axis=1))
    assert d2c[2] < d0 < d2c[3] < d1 < d2c[4]
    if scoring == "literal":
        expected = [
            -s.k2_value * abs(gap[0]) / r,  # Eq. 7
            s.k3,  # Eq. 8
            -s.k4_value * r / d2c[2],  # Eq. 9
            s.k3,  # Algorithm 1: 4-2 scores as location 3
            -s.k5_value * d2c[4] / r,  # Eq. 10
        ]
        assert scores[5] < -s.k1 * 0.5  # Eq. 6: far outside the mask, |Vec2n| > Dist_ref / 2
    else:
        drop = s.k3 + 1
        expected = [
            s.k3 - drop * s.k2_value * (-gap[0] - tol) / r,
            s.k3,
            s.k3 - drop * s.k4_value * (d0 - d2c[2]) / r,
            s.k3,
            s.k3 - drop * s.k5_value * (d2c[4] - d1) / r,
        ]
        assert scores[5] < -5
    assert np.allclose(scores[:5], expected, rtol=1e-9, atol=1e-12)
    # Signs as the paper says: 3 and 4-2 positive, the rest negative.
    assert scores[1] > 0 and scores[3] > 0
    assert scores[0] < 0 and scores[2] < 0 and scores[4] < 0 and scores[5] < 0


def test_continuous_scores_have_no_jumps_but_the_documented_one(scene, camera):
    s = Table1()
    u, v = centre_pixel(camera)
    z = np.arange(0.30, 0.45, 2e-5)
    scores, locations, rating = rate_targets(scene, camera, ray(camera, u, v, z), s)
    assert set(locations.tolist()) == {2, 3, 41, 42, 43}
    jumps = np.abs(np.diff(scores))
    allowed = np.flatnonzero(np.diff(rating.gap[:, 0] > s.j1 * scene[3]))  # 3 -> 4-x along g = Dist_tol
    assert len(allowed) == 1
    others = np.delete(jumps, allowed)
    assert others.max() < 0.05
    # Monotone as the text says: lower the farther in front, the closer to the centre, the farther away.
    front = locations == 2
    assert np.all(np.diff(scores[front]) >= -1e-12)
    far = locations == 43
    assert np.all(np.diff(scores[far]) <= 1e-12)


def test_literal_scores_jump_at_borders(scene, camera):
    s = Table1()
    u, v = centre_pixel(camera)
    z = np.arange(0.30, 0.45, 2e-5)
    scores, locations, _ = rate_targets(scene, camera, ray(camera, u, v, z), s, "literal")
    border = np.flatnonzero((locations[:-1] == 41) & (locations[1:] == 42))[0]
    assert scores[border] == pytest.approx(-1 / s.j2**2, rel=1e-3)  # Eq. 9 at Dist2c_0
    assert scores[border + 1] == s.k3


def test_outside_penalty_grows_with_distance_and_is_continuous_at_the_silhouette(scene, camera):
    s = Table1()
    u, v = centre_pixel(camera)
    us = np.arange(u, u + 120, 0.25)  # walk right along the image row at the centre's depth + 20 mm
    targets = ray(camera, us, np.full_like(us, v), np.full_like(us, CENTRE[2] + 0.02))
    scores, locations, _ = rate_targets(scene, camera, targets, s)
    out = locations == 1
    assert out[-1] and not out[0]
    first = np.argmax(out)
    # Continuous up to the pixel grid: the first outside pixel costs one pixel's distance.
    one_pixel = (s.k3 + 1) * s.k1 * targets[first, 2] / camera.fx / scene[3]
    assert abs(scores[first] - scores[first - 1]) <= one_pixel * 1.01
    assert np.all(np.diff(scores[first:]) <= 1e-9)


@pytest.mark.parametrize("scoring", ["continuous", "literal"])
@pytest.mark.parametrize("dtype, tol", [(np.float64, 1e-9), (np.float32, 1e-4)])
def test_fast_means_equal_per_point_means(scene, camera, scoring, dtype, tol):
    visible, view, centroid, r = scene
    rng = np.random.default_rng(7)
    normals = rng.normal(size=(40, 3)) * [0.3, 0.3, 1.0]
    points = centroid + rng.normal(scale=0.005, size=(40, 3))
    kw = {"centre": centroid, "dist_ref": r, "table": Table1(), "scoring": scoring}
    fast = rate_planes(visible, points, normals, view, camera, dtype=dtype, **kw)
    slow = rate_points(visible, points, normals, view, camera, dtype=np.float64, **kw)
    assert np.allclose(fast, slow.scores.mean(axis=1), atol=tol)


def test_blocks_do_not_change_the_result(scene, camera, monkeypatch):
    from symfruit.core import rating

    visible, view, centroid, r = scene
    planes = symfruit.core.planes.hypothesis_planes(visible)
    whole = rate_planes(visible, planes.points, planes.normals, view, camera, centre=centroid, dist_ref=r)
    monkeypatch.setattr(rating, "BLOCK_POINTS", len(visible) * 5)
    blocked = rate_planes(visible, planes.points, planes.normals, view, camera, centre=centroid, dist_ref=r)
    assert np.array_equal(whole, blocked)


def test_points_behind_the_camera_score_badly(scene, camera):
    scores, _, _ = rate_targets(scene, camera, [[0.05, 0.0, -0.1], [0.0, 0.0, -0.05]], Table1())
    assert np.all(scores < -5)
