"""Known-answer geometry: the methods on solids with exact centres, seen from the front."""

import numpy as np
import pytest

import symfruit
from symfruit import Box, InputError, box_iou, centre_deviation, complete
from symfruit.core.fits import fit_sphere
from symfruit.methods import Completion, available, register

from .conftest import CENTRE, ellipsoid_cloud, front_half, revolution_cloud, sphere_cloud

SOLIDS = {"sphere": sphere_cloud, "ellipsoid": ellipsoid_cloud, "revolution": revolution_cloud}


def scores(cloud, method, **settings):
    truth = Box.from_points(cloud)
    result = complete(front_half(cloud), method=method, settings=settings or None)
    return box_iou(result.box, truth), centre_deviation(result.box, truth) * 1000, result


@pytest.mark.parametrize("solid", SOLIDS)
@pytest.mark.parametrize("scoring", ["continuous", "literal"])
def test_paper_beats_raw_on_solids(solid, scoring):
    cloud = SOLIDS[solid]()
    raw_iou, raw_dev, _ = scores(cloud, "raw")
    iou, dev, result = scores(cloud, "paper", paper={"scoring": scoring})
    # Measured (continuous / literal): sphere 0.90 / 0.91 and 2.0 / 2.0 mm, ellipsoid 0.87 / 0.74 and
    # 2.2 / 3.6 mm, revolution 0.92 / 0.93 and 1.5 / 1.1 mm; raw 0.48-0.50 and 7.5-10.7 mm.
    assert raw_iou < 0.51 and raw_dev > 7.0
    assert iou > 0.70 and iou > raw_iou + 0.2
    assert dev < 4.0 and dev < raw_dev / 2
    assert result.box.contains(result.visible)
    assert len(result.scores) == 132 and result.score == result.scores.max()
    assert result.score == result.scores[result.extras["best_index"]]


def test_paper_completes_with_the_mirror_of_the_visible_points():
    visible = front_half(sphere_cloud())
    result = complete(visible, method="paper")
    mirrored = result.points[len(visible) :]
    assert np.array_equal(result.points[: len(visible)], visible)
    assert np.allclose(symfruit.core.planes.mirror(mirrored, result.plane.point, result.plane.normal), visible)
    assert np.allclose(result.box.min, result.points.min(axis=0))


def test_sphere_fit_is_exact_on_a_sphere():
    rng = np.random.default_rng(1)
    d = rng.normal(size=(300, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    pts = front_half(0.03 * d + CENTRE)
    centre, radius = fit_sphere(pts)
    assert np.allclose(centre, CENTRE, atol=1e-9) and radius == pytest.approx(0.03, abs=1e-9)
    result = complete(pts, method="sphere")
    exact = Box(CENTRE - 0.03, CENTRE + 0.03)
    assert centre_deviation(result.box, exact) < 1e-9 and box_iou(result.box, exact) > 1 - 1e-9


def test_sphere_fit_with_noise_is_close():
    rng = np.random.default_rng(2)
    d = rng.normal(size=(600, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    pts = front_half(0.02 * d + CENTRE)
    pts = pts + rng.normal(scale=0.0003, size=pts.shape)
    centre, radius = fit_sphere(pts)
    assert np.linalg.norm(centre - CENTRE) < 0.001 and abs(radius - 0.02) < 0.0005


def test_sphere_fit_refuses_a_plane():
    xy = np.random.default_rng(0).random((50, 2))
    with pytest.raises(InputError, match="coplanar"):
        fit_sphere(np.c_[xy, np.full(50, 0.3)])


def test_raw_is_the_box_of_the_visible_points():
    visible = front_half(sphere_cloud())
    result = complete(visible, method="raw")
    assert np.allclose(result.box.min, visible.min(axis=0)) and np.allclose(result.box.max, visible.max(axis=0))
    assert result.plane is None and np.isnan(result.score)


def test_registry():
    assert {"paper", "raw", "sphere"} <= set(available())
    with pytest.raises(InputError, match="unknown method 'nope'; available: "):
        complete(front_half(sphere_cloud()), method="nope")

    @register("test-centroid")
    def centroid(points, camera, settings):
        """Box of a single point at the centroid (a test method)."""
        c = points.mean(axis=0, keepdims=True)
        return Completion(points=c, box=Box.from_points(c))

    result = complete(front_half(sphere_cloud()), method="test-centroid")
    assert result.method == "test-centroid" and result.box.size.max() == 0
    with pytest.raises(ValueError, match="already registered"):
        register("test-centroid")(lambda p, c, s: None)


def test_result_is_deterministic_and_translation_equivariant_in_depth():
    visible = front_half(sphere_cloud())
    a = complete(visible, method="paper")
    b = complete(visible.copy(), method="paper")
    assert np.array_equal(a.points, b.points) and a.score == b.score
    shifted = complete(visible + [0, 0, 0.002], method="paper")
    assert np.allclose(shifted.centre, a.centre + [0, 0, 0.002], atol=2e-3)


def test_to_dict_has_the_documented_keys():
    result = complete(front_half(sphere_cloud()), method="paper")
    d = result.to_dict()
    assert set(d) >= {"method", "centre", "box", "plane", "score", "n_visible", "n_completed", "seconds"}
    assert d["confidence"] is None and d["reliable"] is None
    assert set(d["box"]) == {"min", "max", "size"} and set(d["plane"]) == {"point", "normal"}
    assert d["n_completed"] == 2 * d["n_visible"]


@pytest.mark.parametrize(
    "points, message",
    [
        (np.zeros((0, 3)), "at least 10 points"),
        (np.zeros((5, 3)) + 0.3, "at least 10 points"),
        (np.full((20, 3), 0.3), "identical"),
        (np.c_[np.linspace(0, 0.01, 20), np.zeros(20), np.full(20, 0.3)], "on a line"),
        (np.random.default_rng(0).random((50, 3)) * 4e-5 + [0, 0, 0.3], "too small for a fruit"),
        (np.c_[np.random.default_rng(0).random((20, 2)), np.full(20, -0.3)], "behind the camera"),
        (np.random.default_rng(0).random((50, 3)) * 40 + [0, 0, 300], "millimetres"),
        (np.zeros((10, 2)), "shape"),
        ([["a", "b", "c"]], "numeric"),
    ],
)
def test_bad_clouds_get_clear_errors(points, message):
    with pytest.raises(InputError, match=message):
        complete(points)


def test_non_finite_points_are_dropped_and_counted():
    visible = front_half(sphere_cloud())
    dirty = np.vstack([visible, [[np.nan, 0, 0.3], [0, np.inf, 0.3]]])
    result = complete(dirty, method="raw")
    assert result.n_dropped == 2 and len(result.visible) == len(visible)
