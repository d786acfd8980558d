"""The front surface's depth: unbiased under depth noise, exact on clean data."""

import numpy as np
import pytest

from symfruit import InputError
from symfruit.core.front import apex_depth

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
