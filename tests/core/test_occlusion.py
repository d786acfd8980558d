"""Where the camera could not have seen a fruit: the occlusion information (known answers on rendered and
hand-made depth images), and where the fruit may project."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy import ndimage

from symfruit.core.camera import Camera
from symfruit.core.occlusion import Occlusion, occlusion, open_square, with_own
from symfruit.core.raster import Silhouette, silhouette
from symfruit.errors import InputError

from ..conftest import ball_mesh, hidden_image, occluded_view

CAM = Camera(fx=100.0, fy=100.0, cx=20.0, cy=15.0, width=40, height=30)


def _disc_frame(background: float = 1.0):
    """A 40x30 depth image: a disc of radius 6 px at 0.3 m centred on (20, 15), background at ``background``."""
    vv, uu = np.mgrid[:30, :40]
    disc = (uu - 20) ** 2 + (vv - 15) ** 2 <= 36
    depth = np.full((30, 40), background)
    depth[disc] = 0.3
    rows, cols = np.nonzero(disc)
    points = CAM.deproject(np.c_[cols, rows].astype(float), np.full(len(rows), 0.3))
    return depth, disc, points


def test_background_behind_is_not_hidden_and_the_image_border_is():
    depth, disc, points = _disc_frame()
    occ = occlusion(depth, disc, points, CAM)
    assert not occ.hidden.any()
    assert occ.at(np.array([-1.0, 40.0, 20.0, 20.0]), np.array([15.0, 15.0, -1.0, 15.0])).tolist() == [
        True, True, True, False,
    ]  # fmt: skip
    assert occ.at(np.array([1.0, 20.0]), np.array([15.0, 15.0]), radius=2).tolist() == [True, False]
    assert occ.own is not None and occ.own.sum() == disc.sum()


def test_an_occluder_in_front_and_a_touching_neighbour_are_hidden():
    depth, disc, points = _disc_frame()
    depth[:, 27:] = 0.25  # a leaf in front, right of the disc
    depth[:, :10] = 0.302  # something at the fruit's own depth, left of it (a calyx, a touching fruit)
    depth[0:3, 18:22] = 0.0  # no depth here, far from anything: not hidden
    depth[22, 14] = 0.0  # no depth beside the disc, next to background: takes the background's
    occ = occlusion(depth, disc, points, CAM, tolerance=0.005)
    full = hidden_image(occ)
    assert full[:, 27:].all() and full[:, :10].all()
    assert not full[:, 10:27][~disc[:, 10:27]].any()
    assert not (full & disc).any()


def test_another_fruit_is_hidden_unless_clearly_behind():
    depth, disc, points = _disc_frame()
    others = np.zeros((30, 40), bool)
    others[:, 30:] = True
    depth[:, 35:] = 0.6  # the right part of the other fruit lies clearly behind
    depth[:, 30:35] = 0.0  # ... its left part has no depth (out of reach of any pixel with depth)
    occ = occlusion(depth, disc, points, CAM, others=others, reach=0)
    full = hidden_image(occ)
    assert full[:, 30:35].all() and not full[:, 35:].any()


def test_where_the_fruit_may_project():
    depth, disc, points = _disc_frame()
    depth[22:, :] = 0.25  # an occluder across the bottom rows
    depth[:9, 19:21] = 0.25  # a thin stem up from the top
    occ = occlusion(depth, disc, points, CAM)
    region = silhouette(points, CAM)
    box = occ.extent(region, thin=0)
    assert box[0] == pytest.approx(-np.inf) and box[3] == np.inf  # the occluder reaches both image borders
    assert box[1] == -np.inf  # ... and so does the stem
    thin = occ.extent(region, thin=2)
    assert thin[1] == pytest.approx(15 - 6 - 0.5) and thin[3] == np.inf  # the stem cannot hide a fruit
    allowed = occ.allowed(region, thin=2)
    assert allowed.sum() > disc.sum()


def test_a_rendered_leaf_is_found(camera):
    visible, depth, mask, _ = occluded_view(ball_mesh(), [0.0, 0.0, 0.4], below=250, occluder_z=0.33)
    occ = occlusion(depth, mask, visible, camera)
    rows = np.nonzero(occ.hidden.any(axis=1))[0] + occ.v0
    assert rows.min() >= 249  # only the leaf's rows ...
    assert occ.hidden[250 - occ.v0].mean() > 0.9  # ... all of them


def test_own_pixels_join_the_seen_region():
    region = Silhouette(5, 5, np.zeros((6, 6), bool), 0.0)
    own = np.zeros((10, 10), bool)
    own[7:9, 7:9] = True
    occ = Occlusion(3, 3, np.zeros((10, 10), bool), 40, 30, own=own)
    joined = with_own(region, occ)
    assert (joined.u0, joined.v0, joined.mask.shape) == (5, 5, (7, 7))  # the window grows to hold both
    assert joined.mask.sum() == 4 and joined.mask[5:7, 5:7].all()


def test_bad_input_is_refused():
    depth, disc, points = _disc_frame()
    with pytest.raises(InputError, match="40x30"):
        occlusion(depth[:-1], disc, points, CAM)
    with pytest.raises(InputError, match="others"):
        occlusion(depth, disc, points, CAM, others=np.zeros((3, 3), bool))
    with pytest.raises(InputError, match="no point"):
        occlusion(depth, disc, points + [5.0, 0.0, 0.0], CAM)
    with pytest.raises(InputError, match="bool"):
        Occlusion(0, 0, np.zeros((3, 3)), 40, 30)


@given(arrays(bool, st.tuples(st.integers(1, 40), st.integers(1, 40))), st.sampled_from([1, 3, 5, 7]))
def test_open_square_is_binary_opening_by_a_square(mask, size):
    expected = ndimage.binary_opening(mask, structure=np.ones((size, size), bool))
    assert np.array_equal(open_square(mask, size), expected)


@pytest.mark.parametrize(
    "args, message",
    [
        ((float("nan"), 0, np.zeros((3, 3), bool), 40, 30), "u0 must be a whole number of pixels, got nan"),
        ((0, 0, np.zeros((3, 3), bool), float("inf"), 30), "width must be a whole number"),
        ((0, 0.5, np.zeros((3, 3), bool), 40, 30), "v0 must be a whole number"),
        ((39, 0, np.zeros((3, 3), bool), 40, 30), "does not lie in its 40x30 image"),
        ((0, 0, np.zeros((3, 3), bool), 40, 30, np.zeros((2, 2), bool)), "own must be a bool image"),
        ((0, 0, np.zeros((3, 3), bool), 30000, 1), "at most 16384 pixels a side"),
    ],
)
def test_an_occlusion_holding_nonsense_is_a_clear_error(args, message):
    with pytest.raises(InputError, match=message):
        Occlusion(*args)
    assert Occlusion(np.int64(2), 1.0, np.zeros((3, 3), bool), 40, 30).v0 == 1


def test_occlusion_refuses_a_camera_of_the_wrong_type_and_raw_depth():
    depth, disc, points = _disc_frame()
    with pytest.raises(InputError, match="camera must be a symfruit Camera, got dict"):
        occlusion(depth, disc, points, CAM.to_dict())
    with pytest.raises(InputError, match="uint16; depth must be float metres"):
        occlusion(np.rint(depth * 1000).astype(np.uint16), disc, points, CAM)
