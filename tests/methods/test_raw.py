"""``raw``: the box of the visible points."""

import numpy as np

from symfruit import complete
from symfruit.methods.raw import raw

from ..conftest import front_half, sphere_cloud


def test_raw_is_the_box_of_the_visible_points():
    visible = front_half(sphere_cloud())
    result = complete(visible, method="raw")
    assert np.allclose(result.box.min, visible.min(axis=0)) and np.allclose(result.box.max, visible.max(axis=0))
    assert result.plane is None and np.isnan(result.score)


def test_raw_copies_the_points_and_scores_nothing(camera):
    visible = front_half(sphere_cloud())
    done = raw(visible, camera, None)
    assert np.array_equal(done.points, visible) and not np.shares_memory(done.points, visible)
    assert np.array_equal(done.box.min, visible.min(axis=0)) and np.array_equal(done.box.max, visible.max(axis=0))
    assert done.plane is None and done.planes is None and np.isnan(done.score) and done.scores.shape == (0,)
    assert done.extras == {}
