"""``ellipsoid``: the box of the least-squares ellipsoid, with a sphere fallback."""

import numpy as np
import pytest

from symfruit import Box, InputError, box_iou, centre_deviation, complete

from ..conftest import CENTRE, ellipsoid_cloud, front_half

AXES = np.array([0.018, 0.025, 0.015])


def test_an_exact_ellipsoid_is_boxed_exactly():
    visible = front_half(ellipsoid_cloud(axes=AXES, n=3000))
    result = complete(visible, method="ellipsoid")
    exact = Box(CENTRE - AXES, CENTRE + AXES)
    assert centre_deviation(result.box, exact) < 1e-9 and box_iou(result.box, exact) > 1 - 1e-6
    assert np.allclose(result.extras["centre"], CENTRE, atol=1e-9)
    assert np.allclose(result.extras["semi_axes"], np.sort(AXES), rtol=1e-6)
    assert "fallback" not in result.extras


def test_completion_is_the_point_reflection_through_the_centre():
    visible = front_half(ellipsoid_cloud(axes=AXES, n=3000))
    result = complete(visible, method="ellipsoid")
    n = len(visible)
    assert np.array_equal(result.points[:n], visible)
    assert np.allclose(result.points[n:], 2 * CENTRE - visible, atol=1e-9)
    assert result.box.contains(visible)


def test_falls_back_to_the_sphere_when_no_ellipsoid_fits(monkeypatch):
    from symfruit.methods import ellipsoid

    def refuse(points):
        raise InputError("no ellipsoid here")

    monkeypatch.setattr(ellipsoid, "fit_ellipsoid", refuse)
    d = np.random.default_rng(0).normal(size=(600, 3))
    visible = front_half(0.02 * d / np.linalg.norm(d, axis=1, keepdims=True) + CENTRE)
    result = complete(visible, method="ellipsoid")
    assert result.extras["fallback"] == "sphere (no ellipsoid here)"
    assert np.allclose(result.extras["centre"], CENTRE, atol=1e-9)
    assert np.allclose(result.box.min, CENTRE - 0.02, atol=1e-9) and np.allclose(
        result.box.max, CENTRE + 0.02, atol=1e-9
    )
    assert "semi_axes" not in result.extras and result.box.size == pytest.approx(np.full(3, 0.04))
