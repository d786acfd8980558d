"""The occlusion section: its values reach :func:`symfruit.core.occlusion.occlusion`, disabling it gives None, and
the settings validation bounds it by key."""

import numpy as np
import pytest

from symfruit.core.camera import Camera
from symfruit.errors import SymfruitError
from symfruit.occlusion import OcclusionSettings, fruit_occlusion
from symfruit.settings import resolve_settings

from .conftest import hidden_image

CAM = Camera(fx=100.0, fy=100.0, cx=20.0, cy=15.0, width=40, height=30)


def _frame():
    """A disc of radius 6 px at 0.3 m; left of it something 3 mm behind the fruit's depth."""
    vv, uu = np.mgrid[:30, :40]
    disc = (uu - 20) ** 2 + (vv - 15) ** 2 <= 36
    depth = np.full((30, 40), 1.0)
    depth[disc] = 0.3
    depth[:, :10] = 0.303
    rows, cols = np.nonzero(disc)
    points = CAM.deproject(np.c_[cols, rows].astype(float), np.full(len(rows), 0.3))
    return depth, disc, points


def _hidden_left(occ) -> bool:
    return bool(hidden_image(occ)[:, :10].any())


def test_tolerance_decides_whether_a_surface_just_behind_hides_the_fruit():
    depth, disc, points = _frame()
    near = fruit_occlusion(depth, disc, points, CAM, OcclusionSettings(tolerance=0.005))
    far = fruit_occlusion(depth, disc, points, CAM, OcclusionSettings(tolerance=0.002))
    assert near is not None and far is not None
    assert _hidden_left(near)  # 3 mm behind is within 5 mm: it may hide the fruit
    assert not _hidden_left(far)  # ... but not within 2 mm: it is background


def test_disabled_gives_no_occlusion_information():
    depth, disc, points = _frame()
    assert fruit_occlusion(depth, disc, points, CAM, OcclusionSettings(enabled=False)) is None


def test_other_fruit_masks_are_hidden():
    depth, disc, points = _frame()
    others = np.zeros((30, 40), bool)
    others[:, 30:] = True
    depth[:, 30:] = 0.3
    occ = fruit_occlusion(depth, disc, points, CAM, OcclusionSettings(), others=others)
    assert occ is not None
    full = hidden_image(occ)
    w = occ.hidden.shape[1]
    assert occ.u0 + w > 31  # the window reaches into the other fruit
    assert full[:, 30 : occ.u0 + w].all()
    assert not full[:, 27:30].any()  # the gap between them, background, is not hidden


@pytest.mark.parametrize("key, value", [("tolerance", 2.0), ("reach_px", 51), ("reach_px", -1)])
def test_out_of_range_settings_are_refused_with_their_key(key, value):
    with pytest.raises(SymfruitError, match=f"occlusion.{key}"):
        resolve_settings(overrides={"occlusion": {key: value}})
