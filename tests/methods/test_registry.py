"""The registry of completion methods: registering, looking up, and a method's own settings section."""

from dataclasses import dataclass

import numpy as np
import pytest

from symfruit import Box, ConfigError, InputError, Settings, complete
from symfruit.methods import Completion, available, get, register
from symfruit.methods.registry import MethodInfo
from symfruit.settings import Section, setting

from ..conftest import front_half, sphere_cloud


def test_registry(isolated_registry):
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


def test_the_built_in_methods_and_their_sections():
    assert available() == sorted(available())
    assert {"ellipsoid", "fused", "paper", "raw", "sphere"} <= set(available())
    for name in ("paper", "fused", "sphere"):
        info = get(name)
        assert isinstance(info, MethodInfo) and info.name == name and info.settings is type(Settings().section(name))
    assert get("raw").settings is None and get("ellipsoid").settings is None
    assert get("raw").summary == "The box of the visible points (no completion)."


@pytest.mark.parametrize("name", ["nope", None, ["paper"]])
def test_unknown_names_list_the_known_ones(name):
    with pytest.raises(InputError, match=r"unknown method .*; available: .*paper"):
        get(name)


def test_registering_again_the_same_function_is_harmless(isolated_registry):
    def twice(points, camera, settings):
        return Completion(points=points, box=Box.from_points(points))

    register("test-twice")(twice)
    register("test-twice")(twice)
    assert available().count("test-twice") == 1 and get("test-twice").summary == ""


@dataclass(frozen=True)
class ShrinkSettings(Section):
    """A test method's section."""

    factor: float = setting(0.5, gt=0.0, le=1.0)


def test_a_method_brings_its_own_settings_section(isolated_registry):
    @register("test-shrink", settings=ShrinkSettings)
    def shrink(points, camera, settings):
        """The visible box shrunk about its centre by the section's factor."""
        box = Box.from_points(points)
        half = box.size / 2 * settings.factor
        return Completion(points=points, box=Box(box.centre - half, box.centre + half))

    visible = front_half(sphere_cloud())
    full = Box.from_points(visible)
    default = complete(visible, method="test-shrink")
    assert np.allclose(default.box.size, full.size * 0.5)
    chosen = complete(visible, method="test-shrink", settings={"test-shrink": {"factor": 0.25}})
    assert np.allclose(chosen.box.size, full.size * 0.25)
    assert chosen.settings.section("test-shrink") == ShrinkSettings(factor=0.25)
    with pytest.raises(ConfigError, match=r"test-shrink\.factor: must be <= 1, got 2"):
        complete(visible, method="test-shrink", settings={"test-shrink": {"factor": 2}})
    assert get("test-shrink").summary.startswith("The visible box shrunk")


def test_only_methods_that_take_it_get_the_occlusion_information(isolated_registry):
    from symfruit.core.occlusion import Occlusion

    seen = {}

    @register("test-occ", occlusion=True)
    def takes(points, camera, settings, *, occlusion=None):
        seen["occlusion"] = occlusion
        return Completion(points=points, box=Box.from_points(points))

    @register("test-plain")
    def plain(points, camera, settings):
        return Completion(points=points, box=Box.from_points(points))

    cloud = front_half(sphere_cloud())
    occ = Occlusion(0, 0, np.zeros((4, 4), bool), 640, 480)
    complete(cloud, method="test-occ", occlusion=occ)
    assert seen["occlusion"] is occ and get("test-occ").occlusion and not get("test-plain").occlusion
    complete(cloud, method="test-occ")
    assert seen["occlusion"] is None
    assert complete(cloud, method="test-plain", occlusion=occ).method == "test-plain"
    assert get("evidence").occlusion and not get("paper").occlusion
    with pytest.raises(InputError, match="occlusion must be"):
        complete(cloud, occlusion=np.zeros((4, 4), bool))
    with pytest.raises(InputError, match="320x240 image"):
        complete(cloud, occlusion=Occlusion(0, 0, np.zeros((4, 4), bool), 320, 240))
