"""The colour segmenter (symfruit.segment) on photo-like synthetic images and on rendered depth."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from symfruit import Camera, ConfigError, InputError
from symfruit.evaluate.masks import score_masks
from symfruit.scenes import make_photo, make_scene
from symfruit.segment import SegmentSettings, convex_hull_mask, redness, ripe_seeds, segment

H, W = 240, 320
YY, XX = np.mgrid[:H, :W]
RED = (200, 30, 40)
CAM = Camera(fx=600, fy=600, cx=W / 2, cy=H / 2, width=W, height=H)


def sphere_depth(fruit, z, background=1.5):
    """Depth of spheres ``(cx, cy, r)`` (pixels) whose centres lie at depth ``z`` (one per fruit), nearest
    surface wins; ``background`` elsewhere."""
    depth = np.full((H, W), background)
    for (cx, cy, r), zc in zip(fruit, z, strict=True):
        r_m = r * zc / CAM.fx
        d2 = ((XX - cx) ** 2 + (YY - cy) ** 2) * (zc / CAM.fx) ** 2
        inside = d2 < r_m * r_m
        depth = np.where(inside, np.minimum(depth, zc - np.sqrt(np.clip(r_m * r_m - d2, 0, None))), depth)
    return depth


def test_one_fruit_with_seeds_and_highlight_is_found_whole():
    color, truth = make_photo([(160, 120, 50, RED)])
    labels = segment(color)
    assert labels.dtype == np.int32 and labels.shape == (H, W) and labels.max() == 1
    s = score_masks(truth, labels)
    assert s.matched == 1 and s.best_iou[0] > 0.95  # the seeds and the highlight are filled


def test_a_calyx_over_the_fruit_is_inside_its_outline():
    color, truth = make_photo([(160, 120, 50, RED)], calyx=True)
    s = score_masks(truth, segment(color))
    assert s.n_pred == 1 and s.best_iou[0] > 0.95


def test_white_green_and_blushed_fruit_are_not_ripe():
    for colour in ((235, 230, 215), (120, 180, 60), (220, 190, 180)):
        color, _ = make_photo([(160, 120, 50, colour)])
        assert segment(color).max() == 0, colour


def test_two_touching_fruit_are_split_and_three_too():
    color, truth = make_photo([(110, 120, 45, RED), (198, 120, 45, RED)])
    s = score_masks(truth, segment(color))
    assert s.n_pred == 2 and s.matched == 2 and s.best_iou.min() > 0.9
    color, truth = make_photo([(80, 120, 38, RED), (155, 120, 38, RED), (230, 120, 38, RED)], seed=1)
    s = score_masks(truth, segment(color))
    assert s.n_pred == 3 and s.matched == 3 and s.best_iou.min() > 0.9


def test_overlapping_fruit_of_two_sizes_are_split():
    color, truth = make_photo([(120, 120, 45, RED), (200, 125, 40, RED)], calyx=True)
    s = score_masks(truth, segment(color))
    assert s.n_pred == 2 and s.matched == 2 and s.best_iou.min() > 0.9


def test_without_a_split_touching_fruit_stay_one_region():
    color, _ = make_photo([(110, 120, 45, RED), (198, 120, 45, RED)])
    assert segment(color, settings=SegmentSettings(split="none")).max() == 1


def test_one_fruit_cut_by_a_stem_is_one_fruit():
    color, truth = make_photo([(160, 120, 50, RED)])
    color[:, 158:163] = (70, 120, 40)  # a green stem across the fruit: two red fragments
    s = score_masks(truth, segment(color))
    assert s.n_pred == 1 and s.best_iou[0] > 0.95


def test_fruit_cut_by_the_border_is_kept_and_a_speck_is_not():
    color, truth = make_photo([(10, 120, 50, RED)])
    color[5:8, 300:303] = RED
    s = score_masks(truth, segment(color))
    assert s.n_pred == 1 and s.best_iou[0] > 0.9


def test_fruit_are_numbered_left_to_right():
    color, _ = make_photo([(250, 60, 30, RED), (60, 180, 30, RED), (150, 120, 30, RED)])
    labels = segment(color)
    assert [labels[180, 60], labels[120, 150], labels[60, 250]] == [1, 2, 3]


def test_depth_is_optional_and_used_when_given():
    color, _ = make_photo([(160, 120, 50, RED)])
    flat = np.full((H, W), 0.4)
    assert np.array_equal(segment(color, flat, CAM) > 0, segment(color) > 0)
    tiny, _ = make_photo([(160, 120, 4, RED)])
    assert segment(tiny, np.full((H, W), 0.3), CAM).max() == 0  # 8 px across at 0.3 m: a 4 mm blob
    assert np.array_equal(segment(color, np.zeros((H, W)), None), segment(color))  # no valid depth: colour alone
    with pytest.raises(InputError, match="camera"):
        segment(color, flat)
    with pytest.raises(InputError, match="depth is"):
        segment(color, np.ones((10, 10)), CAM)


def test_overlapping_fruit_are_split_by_their_depth_surfaces():
    fruit = [(125, 120, 45), (190, 120, 45)]  # centres 1.44 radii apart: no waist a colour split trusts
    color, truth = make_photo([(*f, RED) for f in fruit])
    assert segment(color).max() == 1
    depth = sphere_depth(fruit, [0.40, 0.41])
    s = score_masks(truth, segment(color, depth, CAM))
    assert s.n_pred == 2 and s.matched == 2


def test_the_split_setting_picks_the_evidence():
    fruit = [(125, 120, 45), (190, 120, 45)]
    color, _ = make_photo([(*f, RED) for f in fruit])
    depth = sphere_depth(fruit, [0.40, 0.41])
    assert segment(color, depth, CAM, SegmentSettings(split="depth")).max() == 2
    assert segment(color, depth, CAM, SegmentSettings(split="watershed")).max() == 1  # shape alone cannot
    touching, _ = make_photo([(110, 120, 45, RED), (198, 120, 45, RED)])
    assert segment(touching, settings=SegmentSettings(split="depth")).max() == 1  # no depth, no depth split
    assert segment(touching, settings=SegmentSettings(split="watershed")).max() == 2


def test_one_sphere_with_a_stem_in_front_stays_one_fruit_with_depth():
    color, truth = make_photo([(160, 120, 55, RED)])
    color[:, 157:163] = (70, 120, 40)
    depth = sphere_depth([(160, 120, 55)], [0.4])
    depth[:, 157:163] = 0.33  # the stem is in front
    s = score_masks(truth, segment(color, depth, CAM))
    assert s.n_pred == 1 and s.best_iou[0] > 0.9  # the stem is not fruit surface: left out
    assert segment(color, depth, CAM)[120, 160] == 0


def test_the_old_positional_call_of_detect_still_works():
    scene = make_scene(1, n_ripe=3, n_unripe=1, n_leaves=0)
    labels = segment(scene.color, scene.depth, scene.camera, SegmentSettings())
    assert labels.max() >= 2


def test_rendered_touching_fruit_are_split_with_depth():
    scene = make_scene(0)  # fruit 3 and 4, and 5 and 6, touch
    labels = segment(scene.color, scene.depth, scene.camera)
    ripe = [f.id for f in scene.fruits if f.ripe]
    truth = scene.labels[None] == np.array(ripe)[:, None, None]
    s = score_masks(truth, labels)
    assert s.matched == s.n_true == 6 and s.best_iou.mean() > 0.9
    best = {k: np.bincount(labels[scene.labels == k]).argmax() for k in ripe}
    assert best[3] != best[4] and best[5] != best[6] and min(best.values()) > 0


def test_settings_are_bounded_and_checked():
    with pytest.raises(ConfigError, match="red_low"):
        SegmentSettings(red_low=0.5, red_high=0.3)
    with pytest.raises(ConfigError, match="waist"):
        SegmentSettings(waist=0.0)
    with pytest.raises(ConfigError, match="close_px"):
        SegmentSettings(close_px=500)
    from symfruit.settings import Settings

    assert Settings().replace(segment={"fill": "surface"}).segment.fill == "surface"
    with pytest.raises(ConfigError, match=r"segment\.split"):
        Settings().replace(segment={"split": "sometimes"})


def test_bad_colour_input_is_refused():
    with pytest.raises(InputError):
        segment(np.zeros((10, 10)))
    with pytest.raises(InputError):
        segment(np.full((10, 10, 3), np.nan))
    assert segment(np.zeros((1, 1, 3), np.uint8)).shape == (1, 1)


def test_redness_and_seeds_known_answers():
    px = np.array([[[200, 50, 40], [100, 25, 20], [90, 90, 90], [30, 5, 5], [210, 120, 40]]], np.uint8)
    assert np.allclose(redness(px)[0, :3], [0.75, 0.75, 0.0])
    strong, weak = ripe_seeds(px)
    assert strong[0].tolist() == [True, True, False, False, False]  # dark pixels never red; orange never seeds
    assert weak[0].tolist() == [True, True, False, False, True]


def test_convex_hull_mask_fills_a_c_shape():
    m = (XX - 100) ** 2 + (YY - 100) ** 2 <= 40**2
    c = m & ~((XX > 100) & (abs(YY - 100) < 10))
    hull = convex_hull_mask(c)
    assert hull[100, 120] and (hull | m).sum() <= 1.01 * m.sum() and (hull >= c).all()
    assert not convex_hull_mask(np.zeros((4, 4), bool)).any()


@given(
    cx=st.floats(0, W),
    cy=st.floats(0, H),
    r=st.floats(18, 60),
    seed=st.integers(0, 1000),
)
def test_a_single_fruit_anywhere_is_one_region(cx, cy, r, seed):
    color, truth = make_photo([(cx, cy, r, RED)], seed=seed)
    labels = segment(color)
    assert labels.dtype == np.int32 and labels.shape == (H, W) and labels.min() == 0
    visible = int(truth[0].sum())
    if visible >= 0.002 * H * W * 2:  # clearly larger than the least fruit
        s = score_masks(truth, labels)
        assert s.n_pred == 1 and s.best_iou[0] > 0.8
    assert labels.max() <= 1
