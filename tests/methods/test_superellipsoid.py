"""The peer method ``superellipsoid`` (Marangoz et al., CASE 2022) through :func:`symfruit.complete`."""

import numpy as np
import pytest

from symfruit import ConfigError, complete
from symfruit.settings import Settings

from ..conftest import CENTRE, front_half, random_sphere


def test_completes_a_front_half_sphere_with_its_missing_surface():
    visible = front_half(random_sphere(3000, radius=0.035))
    r = complete(visible, method="superellipsoid")
    assert r.box.contains(visible)
    assert np.linalg.norm(r.centre - CENTRE) < 0.01
    assert len(r.points) > len(visible) and r.points[len(visible) :, 2].mean() > CENTRE[2]
    assert {"axes", "e1", "e2", "prior_centre", "converged"} <= set(r.extras)
    assert all(0.02 - 1e-12 <= a <= 0.15 + 1e-12 for a in r.extras["axes"])


def test_their_bounds_are_settings():
    visible = front_half(random_sphere(3000, radius=0.015))
    default = complete(visible, method="superellipsoid")
    assert min(default.extras["axes"]) >= 0.02 - 1e-12  # a 15 mm fruit cannot be fitted with their bounds
    small = complete(visible, method="superellipsoid", settings={"superellipsoid": {"axis_min": 0.005}})
    assert min(small.extras["axes"]) < 0.02
    with pytest.raises(ConfigError, match="axis_min: must be <= axis_max"):
        Settings().replace(superellipsoid={"axis_min": 0.2})
