"""The previous default method, ``fused``: known answers, regime detection, confidence, under every profile."""

from dataclasses import replace

import numpy as np
import pytest

from symfruit import Box, ConfigError, box_iou, centre_deviation, complete
from symfruit.methods.fused import FusedSettings
from symfruit.methods.paper import PaperSettings
from symfruit.profiles import available_profiles, load_profile

from ..conftest import CENTRE, ellipsoid_cloud, front_half, random_sphere, revolution_cloud


def test_clean_sphere_and_ellipsoid_are_boxed_exactly():
    for cloud, axes in (
        (random_sphere(), np.full(3, 0.03)),
        (ellipsoid_cloud(n=4000), np.array([0.018, 0.025, 0.015])),
    ):
        visible = front_half(cloud)
        result = complete(visible, method="fused")
        assert result.method == "fused" and result.extras["regime"] == "clean"
        exact = Box(CENTRE - axes, CENTRE + axes)
        assert box_iou(result.box, exact) > 0.95 and centre_deviation(result.box, exact) < 5e-4


def test_noisy_sphere_is_fused_and_close():
    visible = front_half(random_sphere(4000)) + np.random.default_rng(1).normal(scale=0.001, size=(1, 3)) * 0
    visible = visible + np.random.default_rng(1).normal(scale=0.001, size=visible.shape)
    result = complete(visible, method="fused")
    assert result.extras["regime"] == "noisy"
    assert np.linalg.norm(result.centre - CENTRE) < 0.003
    assert result.plane is not None  # the mirror completion's plane is reported


def test_confidence_drops_when_half_the_fruit_is_hidden():
    visible = front_half(random_sphere(6000)) + np.random.default_rng(3).normal(scale=0.0008, size=(1, 3))
    visible = visible + np.random.default_rng(3).normal(scale=0.0008, size=visible.shape)
    full = complete(visible, method="fused")
    half = complete(visible[visible[:, 0] < CENTRE[0]], method="fused")
    assert 0 <= half.confidence < full.confidence <= 1
    assert isinstance(full.reliable, bool)


def test_box_contains_the_visible_points_for_every_profile():
    visible = front_half(revolution_cloud())
    for name in available_profiles():
        result = complete(visible, settings=load_profile(name), method="fused")
        assert result.box.contains(visible, tol=1e-9)


def test_reliable_follows_the_threshold_and_extras_are_reported():
    visible = front_half(random_sphere(3000))
    result = complete(visible, method="fused")
    extras = result.extras
    assert {"noise", "roughness_ratio", "regime", "confidence", "reliable", "spread", "coverage"} <= set(extras)
    assert extras["reliable"] is (extras["confidence"] >= FusedSettings().reliable_at)
    never = complete(visible, settings={"fused": {"reliable_at": 1.0}}, method="fused")
    always = complete(visible, settings={"fused": {"reliable_at": 0.0}}, method="fused")
    assert never.confidence == result.confidence and (never.reliable, always.reliable) == (result.confidence >= 1, True)
    assert np.allclose(result.points[len(visible) :], 2 * result.centre - visible)  # point reflection


def test_the_regime_threshold_is_a_setting():
    visible = front_half(random_sphere(3000))
    assert complete(visible, method="fused").extras["regime"] == "clean"
    forced = complete(visible, settings={"fused": {"clean_ratio": 100.0}}, method="fused")
    assert forced.extras["regime"] == "noisy" and forced.plane is not None and "mirror_score" in forced.extras


def test_the_mirror_section_is_a_paper_section():
    s = FusedSettings()
    assert isinstance(s.mirror, PaperSettings) and (s.mirror.translations, s.mirror.translation_step) == (8, 0.1)
    assert replace(s, mirror=PaperSettings(translations=2)).mirror.translations == 2
    with pytest.raises(ConfigError, match="mirror: must be a paper settings section, got dict"):
        FusedSettings(mirror={"translations": 2})  # type: ignore[arg-type]
