"""``sphere``: the least-squares sphere's box, completing by point reflection through its centre."""

import numpy as np
import pytest

from symfruit import Box, box_iou, centre_deviation, complete
from symfruit.core.fits import fit_sphere

from ..conftest import CENTRE, front_half, random_sphere


def test_sphere_method_is_exact_on_a_sphere():
    rng = np.random.default_rng(1)
    d = rng.normal(size=(300, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    pts = front_half(0.03 * d + CENTRE)
    result = complete(pts, method="sphere")
    exact = Box(CENTRE - 0.03, CENTRE + 0.03)
    assert centre_deviation(result.box, exact) < 1e-9 and box_iou(result.box, exact) > 1 - 1e-9


def test_completion_reflects_through_the_centre_and_reports_the_fit():
    visible = front_half(random_sphere(800, radius=0.02, seed=3))
    result = complete(visible, method="sphere")
    n = len(visible)
    assert np.array_equal(result.points[:n], visible)
    assert np.allclose(result.points[n:], 2 * CENTRE - visible, atol=1e-9)
    assert np.allclose(result.extras["centre"], CENTRE, atol=1e-9) and result.extras["radius"] == pytest.approx(0.02)
    assert result.plane is None and np.isnan(result.score)


def test_the_refine_setting_reaches_the_fit():
    visible = front_half(random_sphere(800, radius=0.02, seed=3))
    visible = visible + np.random.default_rng(4).normal(scale=0.001, size=visible.shape)
    for refine in (True, False):
        result = complete(visible, method="sphere", settings={"sphere": {"refine": refine}})
        centre, radius = fit_sphere(visible, refine=refine)
        assert np.array_equal(result.extras["centre"], centre.tolist()) and result.extras["radius"] == radius
    a = complete(visible, method="sphere", settings={"sphere": {"refine": True}})
    b = complete(visible, method="sphere", settings={"sphere": {"refine": False}})
    assert a.extras["radius"] != b.extras["radius"]


def test_the_box_holds_points_that_noise_put_outside_the_sphere():
    visible = front_half(random_sphere(800, radius=0.02, seed=3))
    visible[0] = CENTRE + [0.0, 0.0, -0.03]  # an outlier 10 mm in front of the surface
    result = complete(visible, method="sphere")
    assert result.box.contains(visible) and result.box.min[2] == pytest.approx(CENTRE[2] - 0.03)
