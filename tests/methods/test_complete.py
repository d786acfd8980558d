"""The public entry point: :func:`symfruit.complete` checks and normalises its input, runs the method, and
reports the result; properties that hold for any cloud and any method."""

import sys
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from symfruit import ConfigError, InputError, Settings, SymfruitError, complete
from symfruit.methods import get
from symfruit.methods.complete import InputSettings, Result

from ..conftest import CENTRE, FUZZ_EXAMPLES, VISIBLE, front_half, sphere_cloud


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


@pytest.mark.parametrize(
    "points, message",
    [
        (np.c_[np.random.default_rng(0).random((40, 2)) * 0.03, np.full(40, 0.3)], "on a plane"),
        (np.full((30, 3), np.nan), "after dropping 30 non-finite"),
    ],
)
def test_more_bad_clouds(points, message):
    with pytest.raises(InputError, match=message):
        complete(points)


def test_a_million_points_are_down_sampled(monkeypatch):
    rng = np.random.default_rng(0)
    d = rng.normal(size=(1_000_000, 3))
    cloud = front_half(0.03 * d / np.linalg.norm(d, axis=1, keepdims=True) + CENTRE)
    # The method is handed the down-sampled cloud only (what keeps a million points at about a second;
    # asserted on the count, not on a wall clock, so a loaded machine cannot fail it).
    info = get("evidence")
    handed = []

    def spy(points, camera, section, *, occlusion=None):
        handed.append(len(points))
        return info.fn(points, camera, section, occlusion=occlusion)

    monkeypatch.setattr(sys.modules["symfruit.methods.complete"], "get", lambda name: replace(info, fn=spy))
    result = complete(cloud)
    assert len(result.visible) == 20000 and result.n_input == len(cloud)
    assert handed == [20000]


finite = st.floats(-0.05, 0.05, allow_nan=False)


@settings()
@given(
    arrays(np.float64, st.tuples(st.integers(0, 60), st.just(3)), elements=finite),
    st.sampled_from(["fused", "paper", "sphere", "ellipsoid", "raw"]),
)
def test_complete_raises_only_documented_errors_and_boxes_every_visible_point(offsets, method):
    cloud = offsets + CENTRE
    try:
        result = complete(cloud, method=method)
    except SymfruitError:
        return
    assert result.box.contains(result.visible, tol=1e-9)
    again = complete(cloud.copy(), method=method)
    assert np.array_equal(again.box.min, result.box.min) and np.array_equal(again.box.max, result.box.max)


@settings(max_examples=max(10, FUZZ_EXAMPLES // 4))
@given(st.floats(-0.05, 0.15), st.sampled_from(["fused", "paper", "sphere", "raw"]))
def test_translation_along_the_optical_axis_moves_the_box_with_it(shift, method):
    a = complete(VISIBLE, method=method)
    b = complete(VISIBLE + [0.0, 0.0, shift], method=method)
    # Perspective changes the rasterised view a little, so the tolerance is a few millimetres.
    assert np.allclose(b.centre, a.centre + [0.0, 0.0, shift], atol=0.004)


def test_the_camera_may_be_a_mapping_in_any_layout():
    realsense = {"color": {"fx": 600.0, "fy": 600.0, "ppx": 300.0, "ppy": 250.0, "width": 640, "height": 480}}
    result = complete(VISIBLE, method="paper", camera=realsense)
    other = complete(VISIBLE, method="paper")
    assert not np.array_equal(result.scores, other.scores)  # the rasterised view depends on the camera
    with pytest.raises(InputError, match="intrinsics lack"):
        complete(VISIBLE, camera={"fx": 600.0})
    with pytest.raises(InputError, match="camera must be a Camera or a mapping of intrinsics, got str"):
        complete(VISIBLE, camera="d435.json")


def test_settings_may_be_an_object_or_a_mapping_but_not_a_path():
    mine = Settings().replace(paper={"translations": 1})
    assert len(complete(VISIBLE, method="paper", settings=mine).scores) == 33
    result = complete(VISIBLE, method="paper", settings={"paper": {"translations": 2}})
    assert len(result.scores) == 66 and result.settings.paper.translations == 2
    with pytest.raises(InputError, match=r"settings must be a Settings or a mapping.*resolve_settings\(config=path\)"):
        complete(VISIBLE, settings="settings.yaml")
    with pytest.raises(ConfigError, match="unknown setting papr"):
        complete(VISIBLE, settings={"papr": {}})


def test_input_limits_are_settings_named_in_the_messages():
    with pytest.raises(InputError, match=r"input\.min_points sets the limit"):
        complete(VISIBLE[:50], settings={"input": {"min_points": 60}})
    assert complete(VISIBLE[:50], method="raw", settings={"input": {"min_points": 40}}).n_input == 50
    small = complete(VISIBLE, method="raw", settings={"input": {"max_points": 100}})
    assert len(small.visible) == 100 and small.n_input == len(VISIBLE)
    with pytest.raises(ConfigError, match=r"input\.max_points: must be >= min_points"):
        Settings().replace(input={"max_points": 5})  # under the default min_points (10)
    with pytest.raises(ConfigError, match="min_extent: must be smaller than max_extent"):
        InputSettings(min_extent=2.0, max_extent=1.0)


def test_result_bookkeeping():
    result = complete(VISIBLE, method="raw")
    assert isinstance(result, Result) and result.method == "raw" and result.n_input == len(VISIBLE)
    assert result.n_dropped == 0 and result.seconds >= 0 and result.settings == Settings()
    assert np.array_equal(result.centre, result.box.centre)
    assert result.confidence is None and result.reliable is None  # raw estimates no confidence
    fused = complete(VISIBLE)
    assert isinstance(fused.confidence, float) and isinstance(fused.reliable, bool)
    assert fused.to_dict()["confidence"] == fused.confidence and fused.to_dict()["n_dropped"] == 0


def test_scalars_and_other_objects_are_refused_as_input():
    for bad in (3.0, None, "points", {"x": 1}):
        with pytest.raises(InputError, match=r"numeric \(n, 3\) array|must have shape \(n, 3\), got \(\)"):
            complete(bad)


def test_a_streak_along_the_line_of_sight_is_refused_by_every_method():
    rng = np.random.default_rng(0)
    z = np.linspace(0.30, 0.33, 200)
    streak = np.c_[rng.normal(0, 1e-4, 200) * z, rng.normal(0, 1e-4, 200) * z, z]  # all within one pixel
    for method in ("fused", "paper", "sphere", "ellipsoid", "raw"):
        with pytest.raises(InputError, match="a streak along the line of sight"):
            complete(streak, method=method)


def test_a_completion_larger_than_a_fruit_is_refused_naming_the_method(isolated_registry):
    from symfruit.core.box import Box
    from symfruit.methods import Completion, register

    @register("huge")
    def huge(points, camera, settings):
        """Completes anything to a 3-metre box."""
        return Completion(points=points, box=Box(points.min(axis=0) - 1.5, points.max(axis=0) + 1.5))

    with pytest.raises(InputError, match=r"method 'huge' completed these points to a box 3\.\d+ m across"):
        complete(VISIBLE, method="huge")
