"""The default method: known answers, regime detection, confidence, profiles."""

import numpy as np
import pytest

from symfruit import Box, ConfigError, box_iou, centre_deviation, complete
from symfruit.core.fits import fit_aligned_ellipsoid, fit_revolution, surface_noise
from symfruit.profiles import available_profiles, load_profile
from symfruit.shapes import rotation

from .conftest import CENTRE, ellipsoid_cloud, fibonacci_sphere, front_half, revolution_cloud, sphere_cloud


def random_sphere(n=2000, radius=0.03, seed=0):
    d = np.random.default_rng(seed).normal(size=(n, 3))
    return radius * d / np.linalg.norm(d, axis=1, keepdims=True) + CENTRE


def test_clean_sphere_and_ellipsoid_are_boxed_exactly():
    for cloud, axes in (
        (random_sphere(), np.full(3, 0.03)),
        (ellipsoid_cloud(n=4000), np.array([0.018, 0.025, 0.015])),
    ):
        visible = front_half(cloud)
        result = complete(visible)
        assert result.method == "fused" and result.extras["regime"] == "clean"
        exact = Box(CENTRE - axes, CENTRE + axes)
        assert box_iou(result.box, exact) > 0.95 and centre_deviation(result.box, exact) < 5e-4


def test_noisy_sphere_is_fused_and_close():
    visible = front_half(random_sphere(4000)) + np.random.default_rng(1).normal(scale=0.001, size=(1, 3)) * 0
    visible = visible + np.random.default_rng(1).normal(scale=0.001, size=visible.shape)
    result = complete(visible)
    assert result.extras["regime"] == "noisy"
    assert np.linalg.norm(result.centre - CENTRE) < 0.003
    assert result.plane is not None  # the mirror completion's plane is reported


def test_roughness_ratio_tells_clean_from_noisy():
    clean = front_half(random_sphere(3000))
    noisy = clean + np.random.default_rng(2).normal(scale=0.001, size=clean.shape)
    ratio_clean, _, normals = surface_noise(clean)
    ratio_noisy, noise, _ = surface_noise(noisy)
    assert ratio_clean > 3.3 > ratio_noisy
    assert 0.0003 < noise < 0.002
    assert np.all(np.einsum("ni,ni->n", normals, clean[:: max(1, len(clean) // 120)][: len(normals)]) < 0)


def test_aligned_ellipsoid_fit_known_answer():
    axes = np.array([0.02, 0.03, 0.025])
    cap = front_half(fibonacci_sphere(3000) * axes + CENTRE)
    centre, semi = fit_aligned_ellipsoid(cap, prior=0.0)
    assert np.allclose(centre, CENTRE, atol=2e-4) and np.allclose(semi, axes, atol=3e-4)


def test_revolution_axis_from_normals():
    tilt = rotation(20, 0, 15)
    cloud = (revolution_cloud() - CENTRE) @ tilt.T + CENTRE
    visible = front_half(cloud)
    _, _, normals = surface_noise(visible, queries=len(visible))
    box, _, direction = fit_revolution(visible, normals)
    true_axis = tilt @ [0.0, 1.0, 0.0]
    assert abs(direction @ true_axis) > np.cos(np.radians(6))
    assert box_iou(box, Box.from_points(cloud)) > 0.85


def test_confidence_drops_when_half_the_fruit_is_hidden():
    visible = front_half(random_sphere(6000)) + np.random.default_rng(3).normal(scale=0.0008, size=(1, 3))
    visible = visible + np.random.default_rng(3).normal(scale=0.0008, size=visible.shape)
    full = complete(visible)
    half = complete(visible[visible[:, 0] < CENTRE[0]])
    assert 0 <= half.confidence < full.confidence <= 1
    assert isinstance(full.reliable, bool)


def test_box_contains_the_visible_points_for_every_profile():
    visible = front_half(revolution_cloud())
    for name in available_profiles():
        result = complete(visible, settings=load_profile(name))
        assert result.box.contains(visible, tol=1e-9)


def test_profiles_ship_and_load(tmp_path):
    assert {"strawberry", "apple", "citrus", "tomato"} <= set(available_profiles())
    assert load_profile("strawberry").fused.revolution is True
    assert load_profile("apple").fused.mirror_weight == 0.25
    mine = tmp_path / "pear.yaml"
    mine.write_text("fused:\n  depth_ratio: 1.3\n")
    assert load_profile(mine).fused.depth_ratio == 1.3
    with pytest.raises(ConfigError, match="no fruit profile 'banana'"):
        load_profile("banana")
    bad = tmp_path / "bad.yaml"
    bad.write_text("fused:\n  mirror_weight: 2\n")
    with pytest.raises(ConfigError, match=r"fused\.mirror_weight: must be <= 1"):
        load_profile(bad)


def test_cli_fruit_profile(tmp_path, capsys):
    import json

    from symfruit.cli import main

    np.save(tmp_path / "a.npy", front_half(sphere_cloud()))
    assert (
        main(["complete", str(tmp_path / "a.npy"), "--fruit", "citrus", "--json", "--output", str(tmp_path / "o.ply")])
        == 0
    )
    capsys.readouterr()
    saved = json.loads((tmp_path / "o.json").read_text())
    assert saved["settings"]["fused"]["depth_ratio"] == 1.1
    assert main(["complete", str(tmp_path / "a.npy"), "--fruit", "banana"]) == 2
