"""The colour segmenter (symfruit.segment.colour) on photo-like synthetic images and on rendered depth."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from symfruit import Camera, ConfigError, InputError
from symfruit.evaluate.masks import score_masks
from symfruit.io.frames import read_frame
from symfruit.segment.colour import SegmentSettings, convex_hull_mask, redness, ripe_seeds, segment
from symfruit.synthetic.scenes import make_photo, make_scene

from ..conftest import EXAMPLE_FRAME, SMALL_CAM, disc_frame

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


def test_the_kept_whole_image_maps_are_zero_between_calls(monkeypatch):
    """The segmenter's whole-image maps kept for the next call (stop 47) are all zero between calls, a call that
    raises half way keeps none that is not, and the labels are those of a first call."""
    from symfruit.segment import colour

    scene = make_scene(0)
    colour._SPARE.clear()
    first = segment(scene.color, scene.depth, scene.camera)
    kept = [a for maps in colour._SPARE.values() for a in maps]
    assert len(kept) == 2 and not any(a.any() for a in kept)  # the weak pixels' and the pieces' maps

    def broken(*args, **kwargs):
        raise RuntimeError("half way")

    with monkeypatch.context() as mp:
        mp.setattr(colour, "_merge", broken)  # after the weak pixels are written
        with pytest.raises(RuntimeError, match="half way"):
            segment(scene.color, scene.depth, scene.camera)
    assert not any(a.any() for maps in colour._SPARE.values() for a in maps)
    np.testing.assert_array_equal(segment(scene.color, scene.depth, scene.camera), first)
    np.testing.assert_array_equal(segment(scene.color, scene.depth, scene.camera), first)


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


def test_a_picture_of_colour_noise_is_refused_in_a_moment_not_joined_for_minutes():
    # uniform colour noise over real depth: ~1,600 red pieces, whose pairwise joining took about 10 minutes
    frame = read_frame(EXAMPLE_FRAME)
    noise = (np.random.default_rng(0).random(frame.color.shape) * 255).astype(np.uint8)
    with pytest.raises(InputError, match=r"the colour segmenter found more than 1,000 red pieces; at most 1,000 are"):
        segment(noise, frame.depth, frame.camera)
    assert segment(frame.color, frame.depth, frame.camera).max() == 6  # a real frame's few pieces: as before


def test_noise_over_noisy_depth_is_refused_once_past_the_bound_not_after_cutting_every_region(monkeypatch):
    # colour noise over depth noise (0-65 m): ~14,000 red regions, each cut into fruit (_split) before the piece
    # count was checked (5.8 s for `symfruit detect` on a 640x480 frame); now cutting stops past 1,000 pieces
    import symfruit.segment.colour as colour

    frame = read_frame(EXAMPLE_FRAME)
    rng = np.random.default_rng(0)
    noise = rng.integers(0, 256, frame.color.shape, dtype=np.uint8)
    depth = rng.integers(0, 65536, frame.depth.shape).astype(np.float32) * np.float32(0.001)
    calls = []
    plain = colour._split
    monkeypatch.setattr(colour, "_split", lambda *args: calls.append(1) or plain(*args))
    with pytest.raises(InputError, match=r"found more than 1,000 red pieces"):
        segment(noise, depth, frame.camera)
    assert 1000 // 2 < len(calls) <= 1001  # each call gives a piece or a few: the bound, not ~14,000


def test_joining_pieces_keeps_each_piece_s_surface_once_with_the_same_answers(monkeypatch):
    # _merge works each piece's sphere fit and points out once, not once per pair: the labels are the ones the
    # per-pair work gives (the surfaces cache left out)
    import symfruit.segment.colour as colour

    frame = read_frame(EXAMPLE_FRAME)
    cached = segment(frame.color, frame.depth, frame.camera)
    plain = colour._same_surface
    monkeypatch.setattr(colour, "_same_surface", lambda a, b, depth, weak, geo, s, surfaces=None: plain(
        a, b, depth, weak, geo, s))  # fmt: skip
    assert np.array_equal(segment(frame.color, frame.depth, frame.camera), cached)


def test_redness_and_seeds_known_answers():
    px = np.array([[[200, 50, 40], [100, 25, 20], [90, 90, 90], [30, 5, 5], [210, 120, 40], [30, 20, 18],
                    [30, 18, 10]]], np.uint8)  # fmt: skip
    assert np.allclose(redness(px)[0, :3], [0.75, 0.75, 0.0])
    strong, weak = ripe_seeds(px)
    # a dim pixel (R <= dark, 40) is red when R exceeds G and B by dark_chroma (12) levels: a crimson apple in shade
    # is, a brownish shadow (redness 0.33 and 0.4, but R only 10 and 12 above) is not; orange never seeds
    assert strong[0].tolist() == [True, True, False, True, False, False, True]
    assert weak[0].tolist() == [True, True, False, True, True, False, True]
    strong, weak = ripe_seeds(px, SegmentSettings(dark_chroma=0))  # stops 1-44: dim pixels never red
    assert strong[0].tolist() == [True, True, False, False, False, False, False]
    assert weak[0].tolist() == [True, True, False, False, True, False, False]


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


# --- carried over from the previous segmenter's tests -------------------------------------------------

_YY, _XX = np.mgrid[:120, :160]


def _disc(cx, cy, r):
    return (_XX - cx) ** 2 + (_YY - cy) ** 2 <= r**2


def test_segmenter_on_the_shipped_frame():
    from symfruit.demo import FRAME_SEED

    frame = read_frame(EXAMPLE_FRAME)
    scene = make_scene(FRAME_SEED)  # the same scene, with its true instance labels
    assert np.array_equal(frame.color, scene.color)
    labels = segment(frame.color, frame.depth, frame.camera)
    found = []
    for k in range(1, labels.max() + 1):
        under = scene.labels[labels == k]
        under = under[under > 0]
        assert len(under) > 0.8 * (labels == k).sum()  # a found region is mostly one true fruit
        found.append(int(np.bincount(under).argmax()))
    ripe = {f.id for f in scene.fruits if f.ripe}
    unripe = {f.id for f in scene.fruits if not f.ripe}
    assert sorted(found) == sorted(ripe)  # every ripe fruit once, none twice
    assert not set(found) & unripe
    assert len(frame.truth) == len(ripe)


def test_touching_fruit_are_split_and_specks_ignored():
    color, depth = disc_frame([(55, 60), (95, 60)])  # two discs touching at the same depth
    color[5:7, 5:7] = (200, 20, 30)  # a red speck: too small for a fruit
    labels = segment(color, depth, SMALL_CAM)
    assert labels.max() == 2
    assert labels[60, 55] != labels[60, 95]


def test_white_and_green_fruit_are_ignored():
    for colour in ((230, 230, 220), (120, 180, 60)):
        color, depth = disc_frame([(80, 60)], colour=colour)
        assert segment(color, depth, SMALL_CAM).max() == 0


def test_red_discs_are_found_and_numbered_left_to_right():
    color, depth = disc_frame([(130, 40), (30, 80), (80, 60)], radius=15)
    labels = segment(color, depth, SMALL_CAM)
    assert labels.dtype == np.int32 and labels.shape == (120, 160) and labels.max() == 3
    for k, (cx, cy) in enumerate([(30, 80), (80, 60), (130, 40)], 1):
        found = labels == k
        assert np.all(found[_disc(cx, cy, 14)]) and not np.any(found & ~_disc(cx, cy, 16))
    assert not labels[~(_disc(30, 80, 16) | _disc(80, 60, 16) | _disc(130, 40, 16))].any()


def test_touching_fruit_at_different_depths_are_split_at_the_depth_step():
    # The front fruit (30 cm) hides part of the one behind (36 cm); their silhouettes overlap without a waist.
    color, depth = disc_frame([(70, 60), (92, 60)], radius=20, z=[0.30, 0.36])
    front, back = _disc(70, 60, 20), _disc(92, 60, 20) & ~_disc(70, 60, 20)
    for split in ("both", "depth"):
        labels = segment(color, depth, SMALL_CAM, SegmentSettings(split=split))
        assert labels.max() == 2
        # The cut follows the front fruit's rim to within 3 pixels.
        assert np.all(labels[_disc(70, 60, 18)] == 1) and np.all(
            labels[back & ~_disc(70, 60, 23) & _disc(92, 60, 18)] == 2
        )
        assert not np.any((labels == 2) & _disc(70, 60, 18)) and not np.any((labels == 1) & ~_disc(70, 60, 23))
        assert abs(int((labels == 1).sum()) - int(front.sum())) < 0.1 * front.sum()
    for split in ("watershed", "none"):  # no waist to cut at: one region
        assert segment(color, depth, SMALL_CAM, SegmentSettings(split=split)).max() == 1


def test_touching_fruit_at_the_same_depth_are_split_at_the_waist_only_when_asked():
    color, depth = disc_frame([(62, 60), (98, 60)], radius=20)
    assert segment(color, depth, SMALL_CAM, SegmentSettings(split="watershed")).max() == 2
    assert segment(color, depth, SMALL_CAM, SegmentSettings(split="none")).max() == 1


def test_a_fruit_too_small_for_its_depth_is_ignored():
    color, depth = disc_frame([(80, 60)], radius=4, z=0.3)  # 4 px at 30 cm: 4 mm across
    assert segment(color, depth, SMALL_CAM).max() == 0
    assert segment(color, depth, SMALL_CAM, SegmentSettings(min_diameter=0.002)).max() == 1
    color, _ = disc_frame([(80, 60)], radius=15)
    # an all-zero depth image is no depth: the colour-only size rule (a share of the image) applies
    assert segment(color, np.zeros((120, 160), np.float32), SMALL_CAM).max() == 1


def test_nothing_red_gives_an_empty_label_image():
    color = np.full((120, 160, 3), 90, np.uint8)
    labels = segment(color, np.ones((120, 160), np.float32), SMALL_CAM)
    assert labels.shape == (120, 160) and not labels.any()


# Full camera resolutions: a pyramid for large fruit, the size rule in metres for small fruit with depth.

HD_CAM = Camera(fx=960.0, fy=960.0, cx=959.5, cy=539.5, width=1920, height=1080)


@pytest.mark.parametrize(
    ("shape", "radius"), [((480, 640), 60), ((480, 640), 150), ((1080, 1920), 70), ((1080, 1920), 300)]
)
def test_a_disc_of_known_size_is_found_with_its_area(shape, radius):
    h, w = shape
    color, truth = make_photo([(w * 0.45, h * 0.55, radius, RED)], shape=shape, seed=3)
    labels = segment(color)
    assert labels.max() == 1
    area = np.pi * radius**2
    assert abs(int((labels == 1).sum()) - area) < 0.02 * area + 2 * np.pi * radius  # within a pixel of outline
    assert score_masks(truth, labels).best_iou[0] > 0.97


def test_large_touching_fruit_are_split_on_the_coarser_grid_too():
    # 1080p, fruit 440 px across: worked on every third pixel, still two fruit with full-resolution outlines
    color, truth = make_photo([(700, 540, 220, RED), (1130, 560, 220, RED)], shape=(1080, 1920), seed=2)
    labels = segment(color)
    s = score_masks(truth, labels)
    assert s.n_pred == 2 and s.matched == 2 and s.best_iou.min() > 0.95
    assert labels[540, 700] != labels[560, 1130]


def test_fruit_at_the_image_border_of_a_large_image_are_kept_whole():
    # cut by each border, worked on a coarser grid: the windows clipped to the image, the area right
    fruit = [(-60, 540, 250, RED), (1960, 300, 250, RED), (960, -50, 250, RED), (960, 1140, 250, RED)]
    color, truth = make_photo(fruit, shape=(1080, 1920), seed=4)
    s = score_masks(truth, segment(color))
    assert s.n_pred == 4 and s.matched == 4 and s.best_iou.min() > 0.97


def hd_disc_frame(centres, radius, z=1.5, shape=(1080, 1920)):
    """Red spheres (``radius`` pixels) at ``z`` on grey leaves' depth 10 cm behind: colour and depth."""
    h, w = shape
    yy, xx = np.mgrid[:h, :w]
    color = np.full((h, w, 3), (70, 110, 60), np.uint8)
    depth = np.full((h, w), z + 0.1)
    r_m = radius * z / HD_CAM.fx
    for cx, cy in centres:
        d2 = ((xx - cx) ** 2 + (yy - cy) ** 2) * (z / HD_CAM.fx) ** 2
        inside = d2 < r_m * r_m
        color[inside] = RED
        depth[inside] = z - np.sqrt(r_m * r_m - d2[inside])
    return color, depth


def test_small_fruit_in_a_full_hd_frame_are_found_with_depth():
    # 50 px across at 1.5 m (a 78 mm apple): a thousandth of the image, below the colour-only share rule,
    # fruit-sized by the size rule in metres at their own depth; one cut by the left border
    centres = [(300, 200), (900, 540), (1500, 800), (10, 700)]
    color, depth = hd_disc_frame(centres, radius=25)
    labels = segment(color, depth, HD_CAM)
    assert labels.max() == 4
    for cx, cy in centres[:3]:
        k = labels[cy, cx]
        assert k > 0 and abs(int((labels == k).sum()) - np.pi * 25**2) < 0.1 * np.pi * 25**2
    assert labels[700, 5] > 0
    assert segment(color).max() == 0  # colour alone: the share of the image rules them out


def test_a_small_fruit_cut_in_two_by_a_leaf_in_front_is_found_with_depth():
    # each half is far smaller than the colour-only rule's least fruit; with depth, the pieces are sized in
    # metres and joined again (one sphere), the leaf left out of the visible surface
    color, depth = hd_disc_frame([(900, 540)], radius=25)
    color[:, 896:905] = (60, 120, 50)
    depth[:, 896:905] = 1.4
    labels = segment(color, depth, HD_CAM)
    assert labels.max() == 1
    visible = (color == RED).all(axis=2)
    assert (labels[visible] == 1).mean() > 0.95 and not labels[:, 897:904].any()


def test_a_fruit_outside_the_depth_cameras_view_is_sized_at_the_frames_depth():
    color, depth = hd_disc_frame([(900, 540), (100, 540)], radius=25)
    depth[:, :200] = 0.0  # the depth camera sees less than the colour camera
    labels = segment(color, depth, HD_CAM)
    assert labels.max() == 2 and labels[540, 100] > 0
    speck, depth = hd_disc_frame([(900, 540), (100, 540)], radius=3)  # 4.5 mm at 1.5 m: no fruit
    depth[:, :200] = 0.0
    assert segment(speck, depth, HD_CAM).max() == 0


def test_a_bicoloured_round_fruit_is_found_whole_with_round_fruit():
    # an apple 60 px across at 1.5 m, its left half red and its right half yellow, a leaf 10 cm behind it
    color, depth = hd_disc_frame([(900, 540)], radius=30)
    disc = (color == RED).all(axis=2)
    yellow = disc & (np.mgrid[:1080, :1920][1] > 900)
    color[yellow] = (200, 180, 60)
    color[500:580, 935:990] = np.where(disc[500:580, 935:990, None], color[500:580, 935:990], (150, 140, 60))
    plain = segment(color, depth, HD_CAM)
    assert plain.max() == 1 and (plain > 0).sum() < 0.6 * disc.sum()  # the red half only
    labels = segment(color, depth, HD_CAM, SegmentSettings(round_fruit=True))
    assert labels.max() == 1
    found = labels == 1
    assert (found & disc).sum() > 0.9 * disc.sum()  # the yellow half joined
    assert not found[500:580, 935:990][~disc[500:580, 935:990]].any()  # the yellowish leaf behind did not


def test_a_bicoloured_apple_with_a_yellow_green_side_is_found_whole_but_not_the_leaf_beside_it():
    # an apple 60 px across at 1.5 m: red left half, yellow-green right half (hue 68 degrees: green by the
    # calyx test, not a leaf); a leaf-green strip (hue 108) at the apple's own depth touching its right side
    color, depth = hd_disc_frame([(900, 540)], radius=30)
    disc = (color == RED).all(axis=2)
    xx = np.mgrid[:1080, :1920][1]
    color[disc & (xx > 900)] = (160, 175, 60)
    leaf = (~disc) & (xx >= 925) & (xx < 960) & (np.abs(np.mgrid[:1080, :1920][0] - 540) < 12)
    color[leaf] = (70, 150, 50)
    depth[leaf] = 1.5 - 0.005  # the leaf touches the fruit's rim at its depth: no depth step parts them
    labels = segment(color, depth, HD_CAM, SegmentSettings(round_fruit=True))
    assert labels.max() == 1
    found = labels == 1
    assert (found & disc).sum() > 0.9 * disc.sum()  # the yellow-green half joined
    assert found[leaf].sum() < 0.05 * leaf.sum()  # the leaf did not


def test_a_leaf_green_round_depth_bump_is_no_fruit():
    # a sphere's depth bump 60 px across, leaf green all over, before leaves 10 cm behind: nothing red, nothing found
    color, depth = hd_disc_frame([(900, 540)], radius=30)
    color[(color == RED).all(axis=2)] = (70, 150, 50)
    assert segment(color, depth, HD_CAM, SegmentSettings(round_fruit=True)).max() == 0


@pytest.mark.parametrize(
    ("rgb", "leaf"),
    [((70, 150, 50), True), ((40, 120, 110), True), ((160, 175, 60), False), ((200, 180, 60), False),
     ((120, 160, 60), True), ((150, 160, 60), False)],
)  # fmt: skip
def test_leaf_green_is_a_hue_of_80_degrees_or_more(rgb, leaf):
    import colorsys

    from symfruit.segment.colour import LEAF_HUE, _leaf

    hue = 360 * colorsys.rgb_to_hsv(*(v / 255 for v in rgb))[0]
    assert (hue >= LEAF_HUE) == leaf  # each case lies on its side of the boundary
    assert bool(_leaf(np.array([[rgb]], np.uint8))[0, 0]) == leaf


def test_an_apple_joined_to_brown_bark_is_found_without_the_bark():
    # an apple 60 px across at 1.5 m touching a branch of brown bark (redness 0.27-0.31: weakly red, some pixels
    # strongly) 3 cm behind its rim: the branch joins the apple's red region. (Level with the rim, the skin
    # grows over the bark: brown is not leaf green and no depth step parts them; not handled.)
    behind = 0.03
    from symfruit.settings import resolve_settings

    color, depth = hd_disc_frame([(900, 540)], radius=30)
    disc = (color == RED).all(axis=2)
    yy, xx = np.mgrid[:1080, :1920]
    bark = ~disc & (np.abs(yy - 540) < 12) & (xx > 925) & (xx < 1300)
    rng = np.random.default_rng(4)
    color[bark] = np.c_[np.full(bark.sum(), 120), rng.integers(83, 88, bark.sum()), np.full(bark.sum(), 60)]
    depth[bark] = 1.5 + behind
    s = resolve_settings(fruit="apple").segment
    labels = segment(color, depth, HD_CAM, s)
    assert labels.max() == 1
    found = labels == 1
    assert (found & disc).sum() / (found | disc).sum() > 0.9
    assert found[bark].sum() < 0.02 * bark.sum()


def test_brown_bark_alone_is_no_fruit():
    from symfruit.settings import resolve_settings

    color, depth = hd_disc_frame([], radius=30)
    yy, xx = np.mgrid[:1080, :1920]
    bark = (np.abs(yy - 540) < 15) & (xx > 700) & (xx < 760)  # a stub of branch the size of an apple
    rng = np.random.default_rng(5)
    color[bark] = np.c_[np.full(bark.sum(), 120), rng.integers(80, 90, bark.sum()), np.full(bark.sum(), 60)]
    depth[bark] = 1.5
    assert segment(color, depth, HD_CAM, resolve_settings(fruit="apple").segment).max() == 0


def test_a_region_larger_than_the_largest_fruit_keeps_its_ripe_red_cores():
    from symfruit.segment.colour import _ripe_cores

    # at 1.5 m and f = 960 the largest fruit (0.10 m) is 64 px across: a red disc of 50 px joined by a
    # brown strip (redness 0.29) to a second red disc too small to be a fruit fragment (6 px)
    yy, xx = np.mgrid[:100, :300]
    color = np.full((100, 300, 3), (120, 85, 60), np.uint8)
    apple = (yy - 50) ** 2 + (xx - 50) ** 2 < 25**2
    speck = (yy - 50) ** 2 + (xx - 250) ** 2 < 3**2
    color[apple | speck] = RED
    region = apple | speck | ((np.abs(yy - 50) < 8) & (xx > 60) & (xx < 260))
    depth = np.full((100, 300), 1.5)
    s = SegmentSettings(round_fruit=True, ripe_median=0.35, min_diameter=0.03, round_max_diameter=0.10)
    cores = _ripe_cores(region, color, depth, s, 960.0, 1.5)
    assert len(cores) == 1 and (cores[0] ^ apple).sum() < 0.05 * apple.sum()
    # no larger than the largest fruit: kept whole when ripe-red over most of it, else dropped
    assert _ripe_cores(apple, color, depth, s, 960.0, 1.5)[0] is apple
    strip = region & ~apple & ~speck
    assert _ripe_cores(strip[:, 100:160], color[:, 100:160], depth[:, 100:160], s, 960.0, 1.5) == []


def test_the_dilations_are_scipys():
    from scipy import ndimage

    from symfruit.segment.colour import _dilate

    rng = np.random.default_rng(7)
    for _ in range(20):
        mask = rng.random(tuple(rng.integers(1, 30, 2))) < 0.1
        assert np.array_equal(_dilate(mask), ndimage.binary_dilation(mask))
        assert np.array_equal(_dilate(_dilate(mask)), ndimage.binary_dilation(mask, iterations=2))
        assert np.array_equal(_dilate(mask, square=True), ndimage.binary_dilation(mask, structure=np.ones((3, 3))))


def test_the_sphere_fit_is_the_former_one_bit_for_bit():
    """The numpy code (``_sphere_lstsq``) is the former fit bit for bit; ``_sphere``, by the compiled kernel where numba
    is (Householder reflections instead of LAPACK's SVD), the same sphere to rounding."""
    from symfruit.core.points import median
    from symfruit.segment.colour import _Geometry, _points, _sphere, _sphere_lstsq

    def former(mask, depth, geo, origin):  # norms and squared norms by numpy's reductions
        p = _points(mask, depth, geo, origin, 1500)
        z = p[:, 2]
        spread = float(np.sqrt(np.var(p[:, 0]) + np.var(p[:, 1]))) * np.sqrt(2.0)
        p = p[np.abs(z - median(z)) <= 2.0 * spread]
        for _ in range(2):
            a = np.concatenate((2.0 * p, np.ones((len(p), 1))), axis=1)
            sol, *_ = np.linalg.lstsq(a, (p * p).sum(axis=1), rcond=None)
            centre = sol[:3]
            radius = float(np.sqrt(max(float(sol[3] + centre @ centre), 0.0)))
            res = np.abs(np.linalg.norm(p - centre, axis=1) - radius)
            p = p[res <= max(3.0 * float(median(res)) * 1.4826, 1e-4)]
        return centre, radius

    rng = np.random.default_rng(3)
    geo = _Geometry(600.0, 40.0, 50.0)
    yy, xx = np.mgrid[:80, :100]
    for _ in range(10):
        r = float(rng.uniform(10, 30))
        disc = (xx - 50) ** 2 + (yy - 40) ** 2 <= r * r
        depth = np.where(
            disc, 0.5 - np.sqrt(np.clip(r * r - (xx - 50) ** 2 - (yy - 40) ** 2, 0, None)) / 600 * 0.5, 0.0
        )
        depth = np.where(disc, depth + rng.normal(0, 0.001, depth.shape), 0.0)
        fit = _sphere_lstsq(disc, depth, geo, (0, 0))
        assert fit is not None
        centre, radius = former(disc, depth, geo, (0, 0))
        assert np.array_equal(fit[0], centre) and fit[1] == radius
        fast = _sphere(disc, depth, geo, (0, 0))
        assert fast is not None
        np.testing.assert_allclose(fast[0], centre, rtol=0, atol=1e-12)
        assert abs(fast[1] - radius) <= 1e-12


def test_ripe_seeds_are_the_former_look_ups():
    from symfruit.segment.colour import _red_pixels

    def former(c, s):  # both look-up tables read for every pixel, the hue for the strong ones
        r, g, b = c[:, :, 0], c[:, :, 1], c[:, :, 2]
        mgb = np.maximum(g, b)
        levels = np.arange(256, dtype=np.float64)
        low = np.floor((1.0 - s.red_low) * levels + 1e-9).astype(np.int16)
        high = np.floor((1.0 - s.red_high) * levels + 1e-9).astype(np.int16)
        dim = (r <= s.dark) & (s.dark_chroma > 0) & (mgb.astype(int) <= r.astype(int) - s.dark_chroma)
        weak, strong = mgb <= low[r], mgb <= high[r]  # the redness tests; then dim pixels by their margin alone
        weak = np.where(r <= s.dark, dim & weak, weak)
        strong = np.where(r <= s.dark, dim & strong, strong)
        idx = np.flatnonzero(strong)
        rs, gs, bs = (ch.ravel()[idx].astype(np.int16) for ch in (r, g, b))
        ok = np.sqrt(3.0) * (gs - bs) < np.tan(np.radians(s.hue_max)) * (2 * rs - gs - bs)
        strong = np.zeros(r.shape, bool)
        strong.ravel()[idx[ok]] = True
        return strong, weak

    rng = np.random.default_rng(11)
    every = np.stack(np.meshgrid(np.arange(256), np.arange(256), indexing="ij"), -1).reshape(-1, 2)
    for settings in (SegmentSettings(), SegmentSettings(red_low=0.3, red_high=0.3, dark=0, hue_max=10.0),
                     SegmentSettings(red_low=0.01, red_high=0.9, dark=254),
                     SegmentSettings(dark_chroma=0), SegmentSettings(dark=80, dark_chroma=30)):  # fmt: skip
        # every (R, max(G, B)) pair, with the other channel random, and a strided window of a random image
        c = np.zeros((256, 256, 3), np.uint8)
        c[..., 0] = every[:, 0].reshape(256, 256)
        c[..., 1] = every[:, 1].reshape(256, 256)
        c[..., 2] = rng.integers(0, 256, (256, 256))
        swap = rng.random((256, 256)) < 0.5
        c[swap, 1], c[swap, 2] = c[swap, 2], c[swap, 1].copy()
        image = rng.integers(0, 256, (60, 90, 4), dtype=np.uint8)
        image[..., 0] = np.maximum(image[..., 0], image[..., 1])
        for case in (c, image[5:50, 7:80, :3], image[::3, ::2]):
            strong, weak = ripe_seeds(case, settings)
            want = former(case[:, :, :3], settings)
            assert np.array_equal(strong, want[0]) and np.array_equal(weak, want[1])
            weak_at, strong_at = _red_pixels(case[:, :, :3], settings)
            assert np.array_equal(weak_at, np.flatnonzero(want[1]))
            assert np.array_equal(strong_at, np.flatnonzero(want[0]))


def test_the_depth_windows_are_nan_to_num_then_maximum_bit_for_bit():
    from symfruit.segment.colour import _Depth, _usable

    rng = np.random.default_rng(5)
    z = rng.normal(0.5, 1.0, (40, 50))
    for value, count in ((np.nan, 300), (np.inf, 50), (-np.inf, 50), (-0.0, 50), (0.0, 50)):
        z.ravel()[rng.integers(0, z.size, count)] = value
    for image in (z, z.astype(np.float32), z[::2, 3:]):
        whole = np.maximum(np.nan_to_num(image.astype(np.float64), nan=0.0, posinf=0.0, neginf=0.0), 0.0)
        depth = _Depth(image)
        assert np.array_equal(_usable(image), whole != 0) and depth.shape == image.shape
        for window in ((slice(None), slice(None)), (slice(3, 17), slice(5, 21)), (slice(1, None, 3), slice(0, 9, 2))):
            got = depth[window]
            assert got.dtype == np.float64 and not got.flags.writeable  # read once: one array for every reader
            assert np.array_equal(got.view(np.int64), whole[window].view(np.int64))  # the bits, -0.0's sign included
            assert depth[window] is got
            with pytest.raises(ValueError):
                got[0] = 1.0
        flat = rng.integers(0, image.size, 200)
        assert np.array_equal(depth.take(flat).view(np.int64), whole.ravel()[flat].view(np.int64))
        clean = _Depth.of(whole)
        assert np.array_equal(clean[(slice(2, 9), slice(None))].view(np.int64), whole[2:9].view(np.int64))


def test_the_red_windows_and_region_boxes_are_the_former_ones():
    from scipy import ndimage

    from symfruit.segment.colour import COARSE_STEP, _boxes, _least_areas, _red_windows

    def former(coarse, shape):  # the boxes painted on the grid and labelled until none join
        h, w = shape
        lab, sizes, *_ = coarse
        lab = np.where((sizes >= 2)[lab], lab, 0)
        gh, gw = lab.shape
        boxes = [(max(sl[0].start - 2, 0), min(sl[0].stop + 2, gh), max(sl[1].start - 2, 0), min(sl[1].stop + 2, gw))
                 for sl in ndimage.find_objects(lab) if sl is not None]  # fmt: skip
        while boxes:
            painted = np.zeros((gh, gw), bool)
            for r0, r1, c0, c1 in boxes:
                painted[r0:r1, c0:c1] = True
            joined = [(a.start, a.stop, b.start, b.stop) for a, b in ndimage.find_objects(ndimage.label(painted)[0])]
            if len(joined) == len(boxes):
                break
            boxes = joined
        step = COARSE_STEP
        return [(slice(r0 * step, min(r1 * step, h)), slice(c0 * step, min(c1 * step, w))) for r0, r1, c0, c1 in boxes]

    rng = np.random.default_rng(2)
    for trial in range(60):
        gh, gw = (int(v) for v in rng.integers(3, 60, 2))
        weak = ndimage.binary_opening(rng.random((gh, gw)) < rng.uniform(0.05, 0.5)) | (rng.random((gh, gw)) < 0.03)
        lab, n = ndimage.label(weak, structure=np.ones((3, 3), bool))
        sizes = np.bincount(lab.ravel(), minlength=n + 1)
        sizes[0] = 0
        at = np.flatnonzero(lab)  # the labelled points as _coarse_regions gives them
        coarse = (lab, sizes, np.ones(n + 1, bool), lab.ravel()[at], *np.divmod(at, gw))
        shape = (gh * COARSE_STEP - int(rng.integers(0, 4)), gw * COARSE_STEP - int(rng.integers(0, 4)))
        assert _red_windows(coarse, shape) == former(coarse, shape), trial
        # the kept regions' boxes, and the least areas from the region pixels alone
        keep = rng.random(n + 1) < 0.5
        keep[0] = False
        at = np.flatnonzero(lab)
        rows, cols = np.divmod(at, gw)
        boxes = _boxes(lab.ravel()[at], rows, cols, keep)
        objects = ndimage.find_objects(lab)
        assert boxes == {k: objects[k - 1] for k in np.flatnonzero(keep).tolist()}
        depth = np.where(rng.random((gh, gw)) < 0.8, rng.uniform(0.3, 2.0, (gh, gw)), 0.0)
        valid = (lab > 0) & (depth > 0)
        count = np.bincount(lab[valid], minlength=n + 1).astype(np.float64)
        total = np.bincount(lab[valid], weights=depth[valid], minlength=n + 1)
        want = np.pi / 4 * (600.0 * 0.02 / np.where(count > 0, total / np.maximum(count, 1.0), 1.1)) ** 2
        got = _least_areas(lab.ravel()[at], depth.ravel()[at], n, 600.0 * 0.02, 1.1)
        assert np.array_equal(got, want)


def test_the_hull_area_is_the_former_one_bit_for_bit():
    from symfruit.segment.colour import _hull_area, _hull_vertices

    def former(mask):  # successors by np.roll and np.diff
        v = _hull_vertices(mask)
        if v is None:
            return float(mask.sum())
        x, y = v[:, 0], v[:, 1]
        area = 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
        perimeter = float(np.hypot(np.diff(x, append=x[0]), np.diff(y, append=y[0])).sum())
        return area + 0.5 * perimeter + 1.0

    rng = np.random.default_rng(4)
    for _ in range(200):
        shape = tuple(rng.integers(1, 80, 2))
        mask = rng.random(shape) < rng.uniform(0.001, 0.3)
        assert _hull_area(mask) == former(mask)


def test_the_leaf_test_is_the_former_one():
    from symfruit.segment.colour import LEAF_HUE, _green, _leaf

    rng = np.random.default_rng(8)
    color = rng.integers(0, 256, (300, 400, 3), dtype=np.uint8)
    r, g, b = (color[:, :, k].astype(np.int16) for k in range(3))
    want = _green(color) & (60 * (g - r) >= (LEAF_HUE - 60) * (g - np.minimum(r, b)))  # _green's casts made twice
    assert np.array_equal(_leaf(color), want) and np.array_equal(_leaf(color[5:90:2, 7:]), want[5:90:2, 7:])


def test_the_depth_steps_are_the_former_ones():
    from symfruit.segment.colour import _steps

    rng = np.random.default_rng(9)
    for _ in range(20):
        z = rng.uniform(0.3, 0.6, tuple(rng.integers(1, 40, 2)))
        z[rng.random(z.shape) < 0.2] = np.nan
        want = np.zeros(z.shape, bool)
        for axis in (0, 1):  # the former: np.diff along each axis
            step = np.abs(np.diff(z, axis=axis)) > 0.05
            if axis == 0:
                want[:-1] |= step
                want[1:] |= step
            else:
                want[:, :-1] |= step
                want[:, 1:] |= step
        assert np.array_equal(_steps(z, 0.05), want)


def test_the_padding_is_numpys():
    from symfruit.segment.colour import _pad1

    rng = np.random.default_rng(10)
    for shape in ((1, 1), (3, 7), (20, 11)):
        mask = rng.random(shape) < 0.5
        assert np.array_equal(_pad1(mask), np.pad(mask, 1)) and _pad1(mask).dtype == bool


APPLE = SegmentSettings(
    round_fruit=True, ground_colour=True, ripe_median=0.35, min_diameter=0.03, round_max_diameter=0.10
)
YELLOW_GREEN = (160, 175, 60)  # hue 68 degrees: a bicoloured apple's ground colour, not leaf green


def shaded(color, disc, rgb, depth, z):
    """Paint ``rgb`` over ``disc`` shaded by the sphere's depth (brighter where it faces the camera)."""
    light = np.clip(1.0 - 8.0 * (depth - depth[disc].min()), 0.55, 1.0)
    color[disc] = (np.array(rgb)[None] * light[disc][:, None]).astype(np.uint8)


def test_an_apple_showing_only_its_yellow_green_side_is_found_by_its_round_depth():
    # a 78 mm apple at 1.5 m (52 px across) turned with its ground colour to the camera: no red to seed it
    color, depth = hd_disc_frame([(900, 540)], radius=26)
    disc = (color == RED).all(axis=2)
    shaded(color, disc, YELLOW_GREEN, depth, 1.5)
    labels = segment(color, depth, HD_CAM, APPLE)
    assert labels.max() == 1
    found = labels == 1
    assert (found & disc).sum() > 0.9 * disc.sum() and (found & ~disc).sum() < 0.05 * disc.sum()
    off = SegmentSettings(round_fruit=True, ripe_median=0.35, min_diameter=0.03, round_max_diameter=0.10)
    assert segment(color, depth, HD_CAM, off).max() == 0  # without ground_colour: nothing red, nothing found
    depth[:, :1000] = 0.0  # outside the depth camera's view: no depth to confirm it, not found
    assert segment(color, depth, HD_CAM, APPLE).max() == 0


def test_an_apple_with_a_small_blush_is_found_whole():
    # the red blush a thin crescent on the left (too little to grow the yellow-green side from it), the rest of
    # the apple ground colour: the red fruit and the round body are one apple
    color, depth = hd_disc_frame([(900, 540)], radius=26)
    disc = (color == RED).all(axis=2)
    xx = np.mgrid[:1080, :1920][1]
    shaded(color, disc & (xx > 882), YELLOW_GREEN, depth, 1.5)
    labels = segment(color, depth, HD_CAM, APPLE)
    assert labels.max() == 1
    assert ((labels == 1) & disc).sum() > 0.9 * disc.sum()


def patch_depth(shape):
    """An apple-sized patch at 1.5 m before leaves 10 cm behind, its mask and depth: an apple (a 39 mm sphere's
    cap), a flat disc facing the camera, a tilted flat leaf (an ellipse 90 x 45 mm), a leaf curled as tightly as
    an apple but in one direction only, a dome far flatter than an
    apple (a 0.1 m sphere's cap), a concave bowl."""
    color, depth = hd_disc_frame([], radius=26)
    yy, xx = np.mgrid[:1080, :1920]
    f = HD_CAM.fx / 1.5  # pixels per metre at 1.5 m
    if shape == "curled leaf":  # a 30 mm cylinder's front, 54 x 60 mm, its axis upright
        patch = (np.abs(xx - 900) <= 0.027 * f) & (np.abs(yy - 540) <= 0.03 * f)
        depth[patch] = 1.5 + 0.03 - np.sqrt(0.03**2 - ((xx[patch] - 900) / f) ** 2)
    elif shape == "tilted leaf":
        patch = ((xx - 900) / (0.045 * f)) ** 2 + ((yy - 540) / (0.0225 * f)) ** 2 <= 1
        depth[patch] = 1.5 + 0.5 * (xx[patch] - 900) / f  # tilted 27 degrees
    else:
        rho2 = ((xx - 900) ** 2 + (yy - 540) ** 2) / f**2
        patch = rho2 <= 0.039**2
        rho2 = rho2[patch]
        radius = {"apple": 0.039, "flat disc": np.inf, "large dome": 0.1, "bowl": -0.04}[shape]  # negative: concave
        sag = 0.0 * rho2 if np.isinf(radius) else np.sign(radius) * (abs(radius) - np.sqrt(radius**2 - rho2))
        depth[patch] = 1.5 + sag
    shaded(color, patch, YELLOW_GREEN, depth, 1.5)
    return color, patch, depth


@pytest.mark.parametrize("shape", ["flat disc", "tilted leaf", "curled leaf", "large dome", "bowl"])
def test_a_yellow_green_patch_that_is_not_a_round_body_is_no_fruit(shape):
    # sunlit leaves can approach an apple's ground colour; their depth is not an apple's
    color, _, depth = patch_depth(shape)
    assert segment(color, depth, HD_CAM, APPLE).max() == 0


@pytest.mark.parametrize("shape", ["apple", "flat disc", "tilted leaf", "curled leaf", "large dome", "bowl"])
def test_a_round_body_is_a_fruit_sized_sphere_convex_towards_the_camera(shape):
    from symfruit.segment.colour import _Geometry, _round_body

    _, patch, depth = patch_depth(shape)
    rng = np.random.default_rng(5)
    depth = depth + rng.normal(0, 0.0015, depth.shape)  # the Azure Kinect's noise at 1.5 m
    fit = _round_body(patch, depth, _Geometry(HD_CAM.fx, HD_CAM.cy, HD_CAM.cx), APPLE, (0, 0))
    assert (fit is not None) == (shape == "apple")
    if fit is not None:
        assert abs(fit[1] - 0.039) < 0.006 and abs(fit[0][2] - (1.5 + 0.039)) < 0.006


@pytest.mark.parametrize(
    ("rgb", "ground"),
    [((160, 175, 60), True), ((200, 180, 60), True), ((200, 160, 60), True), ((200, 150, 60), False),
     ((120, 160, 60), False), ((70, 150, 50), False), ((140, 140, 120), False), ((30, 33, 10), False),
     ((150, 160, 60), True)],
)  # fmt: skip
def test_ground_colour_is_a_saturated_hue_from_40_to_80_degrees(rgb, ground):
    import colorsys

    from symfruit.segment.colour import GROUND_HUE, LEAF_HUE, _ground

    hue, sat, value = colorsys.rgb_to_hsv(*(v / 255 for v in rgb))
    expected = GROUND_HUE <= 360 * hue < LEAF_HUE and sat >= 1 / 3 and 255 * value > 40
    assert expected == ground  # each case lies on its side of the boundaries
    assert bool(_ground(np.array([[rgb]], np.uint8))[0, 0]) == ground


def test_the_bulging_test_fits_each_pieces_paraboloid():
    from symfruit.segment.colour import _bulging, _Geometry

    geo = _Geometry(1000.0, 0.0, 0.0)
    rng = np.random.default_rng(3)
    rows, cols, labels, depth = [], [], [], []
    # piece 0: a 35 mm sphere's cap at 1.5 m; piece 1: a tilted plane; piece 2: a 35 mm bowl; piece 3: too few points
    for k, (r0, c0) in enumerate([(100, 100), (300, 100), (500, 100), (700, 100)]):
        rr, cc = np.mgrid[-12:13, -12:13]
        keep = rr**2 + cc**2 <= 144 if k < 3 else (rr == 0) & (np.abs(cc) < 3)
        rr, cc = rr[keep], cc[keep]
        rho2 = (rr**2 + cc**2) * (1.5 / geo.focal) ** 2
        cap = 0.035 - np.sqrt(0.035**2 - rho2)
        z = 1.5 + [cap, 0.3 * cc * 1.5 / geo.focal, -cap, cap][k] + rng.normal(0, 2e-4, len(rr))
        rows.append(rr + r0), cols.append(cc + c0), labels.append(np.full(len(rr), k)), depth.append(z)
    s = SegmentSettings(min_diameter=0.03, round_max_diameter=0.10)
    ok = _bulging(*(np.concatenate(v) for v in (labels, rows, cols, depth)), 3, geo, s)
    assert ok.tolist() == [True, False, False, False]


def test_the_gap_fill_is_scipys_maximum_filter_where_depth_is_missing():
    from scipy import ndimage

    from symfruit.segment.colour import _gap_filled

    rng = np.random.default_rng(11)
    for size in (3, 7):
        for _ in range(20):
            depth = rng.uniform(0.5, 3.0, tuple(rng.integers(1, 40, 2)))
            depth[rng.random(depth.shape) < 0.6] = 0.0
            near = np.where(depth > 0, depth, ndimage.maximum_filter(depth, size))
            assert np.array_equal(_gap_filled(depth, size), np.where(near > 0, near, np.nan), equal_nan=True)


def test_two_flat_pieces_joined_where_depth_is_missing_are_no_round_body():
    # an apple-sized yellow-green patch: two flat leaves 6 cm apart in depth, a band without depth between them
    # (a time-of-flight camera's invalid rim): no step is seen between them, yet a sphere fits their points
    from symfruit.segment.colour import _Geometry, _round_body

    _, patch, depth = patch_depth("flat disc")
    yy = np.mgrid[:1080, :1920][0]
    depth[patch & (yy > 545)] = 1.56 + 0.0002 * (yy[patch & (yy > 545)] - 545)
    depth[patch & (np.abs(yy - 541) <= 3)] = 0.0
    rng = np.random.default_rng(2)
    depth[depth > 0] += rng.normal(0, 0.0015, int((depth > 0).sum()))
    assert _round_body(patch, depth, _Geometry(HD_CAM.fx, HD_CAM.cy, HD_CAM.cx), APPLE, (0, 0)) is None


def tof_rim(depth, disc, inner=4, outer=2, shift=0):
    """A time-of-flight camera's view of ``depth``: no depth in a band about the silhouette of ``disc`` (``inner``
    pixels inside it, ``outer`` outside), and depth registered ``shift`` pixels to the right of the colour."""
    from scipy import ndimage

    band = ndimage.binary_dilation(disc, iterations=outer) & ~ndimage.binary_erosion(disc, iterations=inner)
    out = np.where(band, 0.0, depth)
    return np.roll(out, shift, axis=1) if shift else out


def blushed_apple(blush_px=9, z=1.5):
    """A 78 mm apple at ``z`` (52 px across) turned with its yellow-green side to the camera, a red blush the
    crescent of its left ``blush_px`` pixels; its colour, depth and silhouette."""
    color, depth = hd_disc_frame([(900, 540)], radius=26, z=z)
    disc = (color == RED).all(axis=2)
    xx = np.mgrid[:1080, :1920][1]
    shaded(color, disc & (xx >= 874 + blush_px), YELLOW_GREEN, depth, z)
    return color, depth, disc


def test_a_blush_along_the_rim_without_the_apples_depth_grows_over_its_ground_colour():
    # the blush a crescent on the rim: a time-of-flight camera has no depth on the rim's mixed pixels and depth
    # registered 6 px off puts the leaves behind on the rest of the crescent. The ground colour beside it lies
    # in front of that depth: the blush is the rim of the apple whose surface that is, and grows over it
    color, depth, disc = blushed_apple()
    depth = tof_rim(depth, disc, shift=6)
    labels = segment(color, depth, HD_CAM, APPLE)
    assert labels.max() == 1
    assert ((labels == 1) & disc).sum() > 0.85 * disc.sum() and ((labels == 1) & ~disc).sum() < 0.1 * disc.sum()
    off = SegmentSettings(round_fruit=True, ripe_median=0.35, min_diameter=0.03, round_max_diameter=0.10)
    assert ((segment(color, depth, HD_CAM, off) > 0) & disc).sum() < 0.5 * disc.sum()  # not without ground_colour
    # outside the depth camera's view nothing tells the apple's surface: the blush alone, as before
    assert ((segment(color, np.zeros_like(depth), HD_CAM, APPLE) > 0) & disc).sum() < 0.5 * disc.sum()


def test_a_red_apple_is_not_grown_over_a_yellow_green_leaf_in_front_of_it():
    # a red apple (with its own depth) and a sunlit yellow-green leaf 6 cm in front of it overlapping its right
    # side: the ground colour beside the red lies in front of it, but the red part's depth is an apple's own
    color, depth = hd_disc_frame([(900, 540)], radius=26)
    disc = (color == RED).all(axis=2)
    yy, xx = np.mgrid[:1080, :1920]
    leaf = ((xx - 935) / 24) ** 2 + ((yy - 540) / 12) ** 2 <= 1
    depth[leaf] = 1.44 + 0.0003 * (xx[leaf] - 935)  # flat and a little tilted
    shaded(color, leaf, YELLOW_GREEN, depth, 1.44)
    depth = tof_rim(tof_rim(depth, disc), leaf)
    labels = segment(color, depth, HD_CAM, APPLE)
    apple = disc & ~leaf
    assert labels.max() == 1
    assert ((labels == 1) & apple).sum() > 0.85 * apple.sum() and ((labels == 1) & leaf & ~disc).sum() == 0


def test_a_piece_of_ground_colour_hidden_in_part_by_a_leaf_in_front_is_one_convex_outline():
    from symfruit.segment.colour import _convex_outline, _hull_vertices

    # an apple-sized cap of ground colour with a leaf band across it 5 cm nearer (its edges without depth),
    # the same band 10 cm behind (a gap through to leaves behind: two pieces, not one outline), and no depth at all
    _, patch, depth = patch_depth("apple")
    yy = np.mgrid[:1080, :1920][0]
    band = np.abs(yy - 540) <= 9
    for z_band, convex in ((1.45, True), (1.6, False), (None, False)):
        d = depth.copy()
        if z_band is None:
            d[:] = 0.0
        else:
            d[band] = z_band
            d[band & (np.abs(yy - 540) >= 7)] = 0.0  # the band's invalid rim
        part = patch & ~band
        assert _convex_outline(part, _hull_vertices(part), d, APPLE.depth_jump) == convex
    assert _convex_outline(patch, _hull_vertices(patch), depth, APPLE.depth_jump)  # whole: convex as it is


def test_two_pieces_a_fruit_apart_in_depth_are_not_one_fruit_without_a_sphere():
    """Two red pieces, one in front of the other: where no sphere fits the larger (flat here, as a ragged or
    mixed-pixel cap can be), their median depths tell them apart when they lie further apart than the largest
    fruit is across; nearer, nothing is told (None), as before."""
    from symfruit.segment.colour import _Depth, _Geometry, _Piece, _same_surface

    s = SegmentSettings(round_max_diameter=0.10)
    geo = _Geometry(900.0, 100.0, 100.0)
    depth = np.zeros((200, 200))
    weak = np.zeros((200, 200), bool)
    a, b = np.zeros((200, 200), bool), np.zeros((200, 200), bool)
    a[20:90, 20:90], b[100:150, 100:150] = True, True
    weak[a | b] = True
    for far, told in ((1.40, False), (1.29, None), (1.22, None)):
        depth[a], depth[b] = 1.20, far  # flat: no sphere fits either
        whole = (slice(0, 200), slice(0, 200))
        pa, pb = _Piece(whole, a.copy(), 1), _Piece(whole, b.copy(), 2)
        assert _same_surface(pa, pb, _Depth.of(depth), weak, geo, s) is told, far


def test_depth_off_the_sampling_grid_is_still_used():
    """The depth's validity is looked for on every 8th pixel first, and over the whole image only when none is there:
    depth on pixels off that grid alone is depth all the same (the same labels as with it made explicit)."""
    from symfruit.segment.colour import _depth

    depth = np.zeros((H, W))
    depth[3::8, 5::8] = 0.6  # no pixel of the 8-grid
    z, geo = _depth(depth, CAM, (H, W))
    assert z is not None and geo.focal == 600.0
    assert np.array_equal(z[(slice(None), slice(None))], depth)
    assert _depth(np.where(depth > 0, np.nan, 0.0), CAM, (H, W))[0] is None  # NaN is no depth


@given(n=st.integers(0, 12), size=st.integers(1, 300), seed=st.integers(0, 2**32 - 1), share=st.floats(0.0, 1.0))
def test_the_grouped_pixels_are_each_kept_label_s_in_order(n, size, seed, share):
    """_grouped: every kept label's pixels, in their own order, label after label ascending; its boxes are _boxes'."""
    from symfruit.segment.colour import _boxes, _group_boxes, _grouped

    rng = np.random.default_rng(seed)
    labels = rng.integers(0, n + 1, size)
    keep = rng.random(n + 1) < share
    rows, cols = rng.integers(0, 50, size), rng.integers(0, 70, size)
    ids, at, first = _grouped(labels, keep)
    want = [k for k in range(n + 1) if keep[k] and (labels == k).any()]
    assert ids.tolist() == want and len(first) == len(ids) + 1 and first[-1] == len(at)
    for i, k in enumerate(want):
        assert np.array_equal(at[first[i] : first[i + 1]], np.flatnonzero(labels == k))
    assert _group_boxes(ids, at, first, rows, cols) == _boxes(labels, rows, cols, keep)


@given(st.lists(st.tuples(st.integers(0, 40), st.integers(1, 12), st.integers(0, 40), st.integers(1, 12)), max_size=25))
def test_the_joined_boxes_neither_touch_nor_lose_a_box(raw):
    """_join_boxes: no two boxes it returns overlap or abut (4-connected), each box given lies in one of them, and each
    returned box is the bounding box of the boxes in it; boxes that touch none come back unchanged."""
    from symfruit.segment.colour import _join_boxes

    boxes = [(r0, r0 + dr, c0, c0 + dc) for r0, dr, c0, dc in raw]
    out = _join_boxes(list(boxes))
    painted = np.zeros((60, 60), bool)
    for r0, r1, c0, c1 in out:
        assert not painted[r0:r1, c0:c1].any()  # no overlap
        painted[r0:r1, c0:c1] = True
    for a, (r0, r1, c0, c1) in enumerate(out):
        for b, (s0, s1, d0, d1) in enumerate(out):
            if a != b:  # no abutting either: a shared edge would join their pixels
                assert not (
                    (r0 < s1 and s0 < r1 and (c1 == d0 or d1 == c0)) or (c0 < d1 and d0 < c1 and (r1 == s0 or s1 == r0))
                )
        inside = [box for box in boxes if r0 <= box[0] and box[1] <= r1 and c0 <= box[2] and box[3] <= c1]
        assert inside and (min(x[0] for x in inside), max(x[1] for x in inside), min(x[2] for x in inside),
                           max(x[3] for x in inside)) == (r0, r1, c0, c1)  # fmt: skip
    assert all(any(r0 <= b[0] and b[1] <= r1 and c0 <= b[2] and b[3] <= c1 for r0, r1, c0, c1 in out) for b in boxes)
    if len(out) == len(boxes):
        assert out == boxes


def test_the_crease_smoothing_is_scipy_s_bit_for_bit():
    from scipy import ndimage

    from symfruit.segment.colour import _SECOND, _gaussian

    rng = np.random.default_rng(11)
    for shape in ((1, 1), (3, 40), (57, 83), (120, 9)):
        image = rng.normal(1.0, 0.3, shape)
        for sigma in (0.5, 2.0, 3.3):
            smooth = _gaussian(image, sigma)
            assert np.array_equal(smooth.view(np.int64), ndimage.gaussian_filter(image, sigma).view(np.int64))
            lap = ndimage.correlate1d(smooth, _SECOND, 0)
            lap += ndimage.correlate1d(smooth, _SECOND, 1)
            assert np.array_equal(lap.view(np.int64), ndimage.laplace(smooth).view(np.int64))


def test_the_early_ripe_test_is_ripe_cores_first_one():
    """_one_fruit tells from a region's pixels alone what _ripe_cores does with it at once: a region no larger than
    the largest fruit's disc is kept whole when ripe, dropped when not; a larger one is left to _ripe_cores."""
    from symfruit.segment.colour import _grouped, _one_fruit, _ripe_cores

    s = SegmentSettings(round_fruit=True, round_max_diameter=0.10)
    rng = np.random.default_rng(6)
    for trial in range(40):
        color = rng.integers(30, 256, (60, 80, 3), dtype=np.uint8)
        color[..., 0] = np.maximum(color[..., 0], rng.integers(0, 256, (60, 80)).astype(np.uint8))
        labels = np.zeros((60, 80), np.int64)
        for k in range(1, 6):
            r, c, rad = rng.integers(0, 60), rng.integers(0, 80), rng.integers(2, 25)
            labels[(YY[:60, :80] - r) ** 2 + (XX[:60, :80] - c) ** 2 <= rad * rad] = k
        red = np.stack(
            [rng.integers(150, 256, (60, 80)), rng.integers(0, 120, (60, 80)), rng.integers(0, 120, (60, 80))], -1
        )
        color = np.where((labels % 2 == 1)[..., None], red, color).astype(np.uint8)  # odd regions mostly ripe-red
        depth = np.where(rng.random((60, 80)) < 0.8, rng.uniform(0.5, 3.0, (60, 80)), 0.0)
        if trial % 5 == 0:
            depth[:] = 0.0  # no depth at all: sized at the typical depth
        at = np.flatnonzero(labels)
        lab = labels.ravel()[at]
        keep = np.ones(6, bool)
        ids, grouped, first = _grouped(lab, keep)
        sizes = np.bincount(lab, minlength=6).take(ids)
        pixels = at.take(grouped)
        one, ripe = _one_fruit(first, sizes, depth.ravel().take(pixels), redness(color.reshape(-1, 3)[pixels]), s,
                               300.0, 1.4)  # fmt: skip
        for i, k in enumerate(ids.tolist()):
            region = labels == k
            cores = _ripe_cores(region, color, np.where(region, depth, 0.0), s, 300.0, 1.4)
            if one[i]:
                assert cores == [] if not ripe[i] else len(cores) == 1 and np.array_equal(cores[0], region), trial


def test_the_id_maps_hold_every_id():
    from symfruit.segment.colour import _id_type

    for n in (0, 1, 255, 32766, 32767, 100_000):
        info = np.iinfo(_id_type(n))
        assert info.min <= -1 and n <= info.max
    assert _id_type(30) == np.int16


@pytest.mark.parametrize(
    ("scale", "dtype", "message"),
    [
        (257, np.uint16, r"color must be 8-bit \(0-255\), got values 0 to 65535 \(uint16; 16-bit colour"),
        (1 / 255, np.float64, r"got float64 0 to 1 \(a float image in \[0, 1\]: multiply by 255"),
        (0.5 / 255, np.float32, r"got float32 0 to 0.5 \(a float image in \[0, 1\]"),
        (-1, np.int16, r"color must be 8-bit \(0-255\), got values -255 to 0"),
    ],
)
def test_colour_of_other_values_than_8_bit_is_refused_not_cut_into_0_255(scale, dtype, message):
    img = np.zeros((40, 50, 3), np.float64)
    img[..., 0] = 255
    img[10:20, 10:20] = (0, 255, 0)
    with pytest.raises(InputError, match=message):  # before: clipped, 16-bit read as white, [0, 1] as black
        segment((img * scale).astype(dtype))
    # 8-bit values in another type are read as they are (a list, int64, whole floats): the same labels
    as_uint8 = segment(img.astype(np.uint8))
    assert np.array_equal(segment(img.astype(np.int64)), as_uint8) and np.array_equal(segment(img), as_uint8)


def test_segment_refuses_a_camera_or_settings_of_another_type_by_name():
    img = np.zeros((40, 50, 3), np.uint8)
    depth = np.full((40, 50), 0.5, np.float32)
    with pytest.raises(InputError, match="segment: camera must be a Camera with numbers fx, fy"):
        segment(img, depth, "camera.json")  # before: AttributeError: 'str' object has no attribute 'fx'
    with pytest.raises(InputError, match="segment: settings must be a SegmentSettings"):
        segment(img, settings={"dark": 10})  # before: AttributeError


def _apples_outside_the_depth_view(apart, leaf=0):
    """An apple (28 px) with a dark grey rim at (300, 540) and, ``apart`` px to its right, one (26 px) partly behind it;
    with ``leaf``, a leaf band ``2 leaf + 1`` px high across the front one instead. The depth camera sees x >= 600
    only (outside its view, no depth: nothing to tell two surfaces apart)."""
    yy, xx = np.mgrid[:1080, :1920]
    color = np.full((1080, 1920, 3), (70, 110, 60), np.uint8)
    depth = np.full((1080, 1920), 1.6)
    depth[:, :600] = 0.0
    front = (xx - 300) ** 2 + (yy - 540) ** 2 <= 28**2
    if apart:
        behind = (xx - 300 - apart) ** 2 + (yy - 540) ** 2 <= 26**2
        color[behind] = (180, 25, 35)
        # a dark rim, grey in shadow (R only 6 above G and B: not red even as a dim pixel, ``dark_chroma``; a rim of
        # (40, 20, 20), 20 above, is dim red since stop 45 and joins the two into one region)
        color[(xx - 300) ** 2 + (yy - 540) ** 2 <= 30**2] = (30, 24, 24)
    color[front] = RED
    if leaf:
        band = np.abs(yy - 540) <= leaf
        color[band & front] = (60, 120, 50)
    return color, depth, front & (color == RED).all(axis=2), (color == (180, 25, 35)).all(axis=2)


@pytest.mark.parametrize("apart", [40, 50, 60])
def test_two_round_fruit_side_by_side_without_depth_are_two(apart):
    """Two apples side by side outside the depth camera's view, one partly hiding the other: their union is
    convex enough for the merge's hull test, but reaches half as far again as either apple alone, which no two
    pieces of one round fruit do (``_two_extents``): two fruit with ``round_fruit``."""
    color, depth, front, behind = _apples_outside_the_depth_view(apart)
    labels = segment(color, depth, HD_CAM, APPLE)
    assert labels.max() == 2
    a, b = np.bincount(labels[front]).argmax(), np.bincount(labels[behind]).argmax()
    assert a > 0 and b > 0 and a != b
    assert (labels[front] == a).mean() > 0.95 and (labels[behind] == b).mean() > 0.95


def test_a_round_fruit_cut_by_a_leaf_without_depth_is_one():
    """The pieces of one apple either side of a leaf reach no further than the apple: joined as before."""
    color, depth, front, _ = _apples_outside_the_depth_view(0, leaf=5)
    labels = segment(color, depth, HD_CAM, APPLE)
    assert labels.max() == 1 and (labels[front] == 1).all()


def test_the_extent_of_a_disc_is_its_diameter():
    from symfruit.segment.colour import _extent, _hull_vertices

    yy, xx = np.mgrid[:101, :101]
    disc = (xx - 50) ** 2 + (yy - 50) ** 2 <= 40**2
    assert abs(_extent(_hull_vertices(disc), disc) - 81) <= 1.0
    assert _extent(None, np.ones((3, 3), bool)) == 3.0


def test_the_edge_following_counts_are_the_former_ones():
    """Random regions, edges and parts: ``_follow_edges`` (each piece's counts by one bincount) gives the former
    pieces (counted by ``np.add.at``; issue 19, eighteenth round)."""
    from symfruit.core.raster import nearest_index
    from symfruit.segment.colour import EDGE_PURITY, _follow_edges, _label

    def former(parts, region, edges):
        pieces, n = _label(region & ~edges)
        if n < 2:
            return parts
        owner = np.zeros(region.shape, np.int64)
        for k, part in enumerate(parts, 1):
            owner[part] = k
        counts = np.zeros((n + 1, len(parts) + 1), np.int64)
        np.add.at(counts, (pieces.ravel(), owner.ravel()), 1)
        major = counts[:, 1:].argmax(axis=1) + 1
        total = counts[:, 1:].sum(axis=1)
        pure = counts[np.arange(n + 1), major] >= EDGE_PURITY * np.maximum(total, 1)
        seeds = np.where(pure[pieces], major[pieces], owner)
        seeds[(pieces == 0) | ~region] = 0
        if not seeds.any():
            return parts
        grown = np.where(region, np.take(seeds.ravel(), nearest_index(seeds == 0)), 0)
        return [grown == k for k in range(1, len(parts) + 1) if (grown == k).any()]

    rng = np.random.default_rng(5)
    for _ in range(30):
        h, w = (int(x) for x in rng.integers(2, 50, 2))
        region = rng.random((h, w)) < 0.9
        edges = region & (rng.random((h, w)) < 0.2)
        cut = rng.integers(1, 4)
        parts = [region & (np.arange(w) % cut == k) for k in range(int(cut))]
        parts = [p for p in parts if p.any()]
        got, want = _follow_edges(parts, region, edges), former(parts, region, edges)
        assert len(got) == len(want) and all(np.array_equal(a, b) for a, b in zip(got, want, strict=True))


@pytest.mark.parametrize("kernels", ["numba", "numpy"])
def test_the_ripe_test_compares_in_float32_with_and_without_the_kernels(monkeypatch, kernels):
    """A region whose median redness is exactly the float32 of ``ripe_median`` (R 20, G 13: 7 / 20 is float32(0.35),
    which lies below 0.35) is ripe with the compiled twin as with numpy (the kernel's value, compared in float64,
    read it as below the setting); a shade less red is not."""
    from symfruit.segment.colour import _ripe

    if kernels == "numpy":
        monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    else:
        monkeypatch.delenv("SYMFRUIT_KERNELS", raising=False)
    color = np.zeros((6, 7, 3), np.uint8)
    color[..., 0], color[..., 1] = 20, 13
    red = np.ones((6, 7), bool)
    assert float(np.float32(7) / np.float32(20)) < 0.35  # the premise: the setting rounds down in float32
    assert _ripe(color, red, 0.35)
    color[..., 1] = 14
    assert not _ripe(color, red, 0.35)


def test_a_filled_polygon_is_pillows_image_as_bool():
    """Random polygons (2-7 vertices, some off the image) on images of random shape: ``_fill_polygon``'s mask is
    ``np.asarray(image, dtype=bool)`` of the Pillow drawing it reads its bytes from, shape, type and pixels."""
    from PIL import Image, ImageDraw

    from symfruit.segment.colour import _fill_polygon

    rng = np.random.default_rng(40)
    for _ in range(300):
        h, w = (int(x) for x in rng.integers(1, 60, 2))
        v = rng.uniform(-5.0, 65.0, (int(rng.integers(2, 8)), 2))
        img = Image.new("L", (w, h), 0)
        ImageDraw.Draw(img).polygon([tuple(p) for p in v.tolist()], fill=1, outline=1)
        want = np.asarray(img, dtype=bool)
        got = _fill_polygon(v, (h, w))
        assert got.shape == want.shape and got.dtype == want.dtype and np.array_equal(got, want)


def _random_pieces(seed: int) -> list:
    """40 pieces of random boxes and fill (touching, overlapping and apart; each with its corner pixel set)."""
    from symfruit.segment import colour

    rng = np.random.default_rng(seed)
    pieces = []
    for _ in range(40):
        r0, c0 = int(rng.integers(0, 300)), int(rng.integers(0, 300))
        h, w = int(rng.integers(1, 40)), int(rng.integers(1, 40))
        mask = rng.random((h, w)) < rng.uniform(0.2, 1.0)
        mask[0, 0] = True
        pieces.append(colour._Piece((slice(r0, r0 + h), slice(c0, c0 + w)), mask, 1))
    return pieces


@pytest.mark.parametrize("seed", range(4))
def test_near_pieces_table_is_the_row_by_row_test(seed, monkeypatch):
    """The pairs of near pieces read off the table by one ``np.nonzero`` (stop 41) are the row-by-row test's, in
    its order (each piece's later neighbours ascending), for clusters of boxes of many sizes, touching, overlapping
    and apart; some pieces have no neighbour."""
    from symfruit.segment import colour

    pieces = _random_pieces(seed)
    table = colour._near_pieces(pieces)
    monkeypatch.setattr(colour, "NEAR_TABLE", 0)
    rows = colour._near_pieces(pieces)
    found = [table(i) for i in range(len(pieces))]
    assert found == [rows(i) for i in range(len(pieces))]
    assert sum(map(len, found)) >= 10 and any(not f for f in found)


@pytest.mark.parametrize("seed", range(4))
def test_the_coarse_regions_are_the_ripe_seeds_labelled(seed, monkeypatch):
    """Red blobs and specks over random colours: ``_coarse_regions`` (the grid's ``_red_regions``, stop 43) gives
    what it gave from :func:`ripe_seeds`: the weak grid points labelled with eight neighbours (scipy's numbers), each
    label's size (0 for the background) and whether it holds a strong point, and the labelled points' labels, rows and
    columns in raster order (what ``_red_windows`` reads), with the kernels and without."""
    from scipy import ndimage

    from symfruit.segment.colour import COARSE_STEP, _coarse_regions

    rng = np.random.default_rng(seed)
    h, w = 160, 200
    image = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
    yy, xx = np.mgrid[:h, :w]
    for _ in range(6):
        cy, cx, r = rng.uniform(0, h), rng.uniform(0, w), rng.uniform(6, 30)
        image[(yy - cy) ** 2 + (xx - cx) ** 2 <= r * r] = (int(rng.integers(120, 256)), int(rng.integers(0, 90)), 20)
    s = SegmentSettings()
    strong, weak = ripe_seeds(image[::COARSE_STEP, ::COARSE_STEP], s)
    lab, n = ndimage.label(weak, structure=np.ones((3, 3), bool))
    sizes = np.bincount(lab.ravel(), minlength=n + 1)
    sizes[0] = 0
    seeded = np.zeros(n + 1, bool)
    seeded[lab[strong]] = True
    at = np.flatnonzero(lab)  # the labelled points, their labels, rows and columns
    for kernels in ("numpy", ""):
        monkeypatch.setenv("SYMFRUIT_KERNELS", kernels)
        found = _coarse_regions(image, s)
        assert found is not None
        for a, b in zip(found, (lab, sizes, seeded, lab.ravel()[at], *np.divmod(at, lab.shape[1])), strict=True):
            assert a.dtype == b.dtype
            np.testing.assert_array_equal(a, b)
    assert n > 3 and seeded.sum() >= 3
    assert _coarse_regions(np.zeros((40, 40, 3), np.uint8), s) is None


# --- stop 43, robust43


@pytest.mark.parametrize("bad", [{"fx": "615", "fy": "615"}, {"fx": True, "fy": 615.0}, {"fx": 615.0, "fy": b"6"},
                                 {"fx": 615.0, "fy": 615.0, "cx": "80"}])  # fmt: skip
def test_segment_refuses_a_camera_of_text_or_booleans_for_numbers(bad):
    """Before: float() read "615" as 615 and True as 1 (a 1-pixel focal length) in silence; symfruit.Camera refuses
    both."""
    from types import SimpleNamespace

    color, depth = disc_frame([(80, 60)])
    with pytest.raises(InputError, match="segment: camera must be a Camera with numbers fx, fy"):
        segment(color, depth, SimpleNamespace(**bad))
    assert segment(color, depth, SimpleNamespace(fx=600.0, fy=600.0)).max() == 1


# --- stop 46, segrecall46


def test_an_apple_cut_by_a_leaf_whose_soft_edge_joins_its_red_is_one_fruit():
    """A leaf 5 px wide 5 cm in front of an apple, its edge softened to a weakly red bridge of 1-7 px
    (a camera's blur and 4:2:0 chroma): the red of both sides is one region, which the split cuts at the leaf;
    with ``round_fruit`` the merge joins the two pieces of one sphere again (before stop 46: two fruit)."""
    yy, xx = np.mgrid[:1080, :1920]
    for bridge in (0, 1, 3):
        color, depth = hd_disc_frame([(900, 540)], radius=30)
        apple = (color == RED).all(axis=2)
        band = (np.abs(yy - 540) <= 2) & (np.abs(xx - 900) <= 45)
        color[band], depth[band] = (60, 120, 50), 1.40
        color[band & (np.abs(xx - 900) <= bridge)] = (150, 110, 90)  # redness 0.27: weakly red, no seed
        labels = segment(color, depth, HD_CAM, APPLE)
        assert labels.max() == 1, bridge
        assert (labels[apple & ~band] == 1).all(), bridge


def test_a_thin_blush_grows_over_the_whole_apple_with_depth():
    """A blush a crescent 8 px wide along the rim of an apple 60 px across, the rest yellow-green: the skin grows
    from the red part up to the largest fruit's diameter at its depth, not twice the crescent's own radius (about
    15 px: a third of the apple, before stop 46); the leaves behind (10 cm back) are not taken."""
    color, depth = hd_disc_frame([(900, 540)], radius=30)
    disc = (color == RED).all(axis=2)
    xx = np.mgrid[:1080, :1920][1]
    shaded(color, disc & (xx > 878), YELLOW_GREEN, depth, 1.5)
    s = SegmentSettings(round_fruit=True, ripe_median=0.35, min_diameter=0.03, round_max_diameter=0.10)
    labels = segment(color, depth, HD_CAM, s)  # no ground_colour: the skin is grown from the red part alone
    assert labels.max() == 1
    found = labels == 1
    assert (found & disc).sum() > 0.9 * disc.sum() and (found & ~disc).sum() < 0.02 * disc.sum()


def test_a_skin_is_at_its_reach_where_it_meets_the_disc_or_the_window_edge():
    """_at_reach: a skin well inside its reach and window is not (a wider reach grows the same skin); one with a
    pixel next to the disc's outline or on the window's edge is."""
    from symfruit.segment.colour import _at_reach

    yy, xx = np.mgrid[:60, :60]
    big = (slice(100, 160), slice(200, 260))
    inside = (yy - 30) ** 2 + (xx - 30) ** 2 <= 10**2
    assert not _at_reach(inside, big, 130.0, 230.0, 20.0)
    assert _at_reach(inside, big, 130.0, 230.0, 10.5)  # its rim 10 px out: a neighbour past the disc of 10.5
    edge = inside.copy()
    edge[30, 0] = True
    assert _at_reach(edge, big, 130.0, 230.0, 100.0)
    assert not _at_reach(np.zeros((60, 60), bool), big, 130.0, 230.0, 20.0)


# --- stop 47, yellow47


def test_a_yellow_green_apple_crossed_by_a_band_without_depth_is_one_fruit_beside_flat_leaves():
    # a bicoloured apple turned with its yellow-green side to the camera (its blush a 12 px crescent on the left),
    # flat leaf-green leaves beside it at its depth, a time-of-flight camera's invalid rim, depth registered 6 px
    # off, and a band 5 px wide without depth across the apple (a twig's edge that the colour camera sees past and
    # the depth camera does not). The skin grew from the blush along depth and stopped at the band: two fruit, a
    # fifth of the apple and the rest. Bridged from both sides, the band is crossed: one fruit, not the leaves
    from symfruit.segment.colour import BRIDGE_PX

    color, depth, disc = blushed_apple(blush_px=12)
    yy, xx = np.mgrid[:1080, :1920]
    leaves = (np.abs(yy - 540) <= 12) & (xx >= 932) & (xx < 990)
    color[leaves] = (60, 120, 40)  # leaf green, hue 110 degrees
    depth[leaves] = 1.5
    depth = tof_rim(depth, disc, shift=6)
    band = disc & (np.abs(xx - 892) <= 2)
    depth[band] = 0.0
    assert 5 <= 2 * BRIDGE_PX  # bridged from both sides
    labels = segment(color, depth, HD_CAM, APPLE)
    assert labels.max() == 1
    found = labels == 1
    assert (found & disc).sum() > 0.85 * disc.sum()
    assert (found & leaves & ~disc).sum() == 0 and (found & ~disc).sum() < 0.05 * disc.sum()
    off = SegmentSettings(round_fruit=True, ripe_median=0.35, min_diameter=0.03, round_max_diameter=0.10)
    assert ((segment(color, depth, HD_CAM, off) > 0) & disc).sum() < 0.5 * disc.sum()  # not without ground_colour


def test_bridged_depth_takes_the_nearest_depth_within_its_reach_only():
    from symfruit.segment.colour import BRIDGE_PX, _BridgedDepth, _Depth

    depth = np.zeros((20, 40))
    depth[:, :10] = 1.0
    depth[:, 30:] = 2.0
    depth[:, 14:17] = 1.5  # a short gap between 1.0 and 1.5 (10-13) and a long one between 1.5 and 2.0 (17-29)
    z = _BridgedDepth(_Depth.of(depth))[(slice(5, 15), slice(0, 40))]
    assert BRIDGE_PX == 3.5
    row = z[0]
    assert row[:10].tolist() == [1.0] * 10 and row[30:].tolist() == [2.0] * 10  # depth kept
    assert row[10:12].tolist() == [1.0, 1.0] and row[12:14].tolist() == [1.5, 1.5]  # the gap split at its middle
    assert row[17:21].tolist() == [1.5] * 3 + [0.0]  # 3 px from the depth: bridged, 4 px: not
    assert row[27:30].tolist() == [2.0] * 3 and row[21:27].tolist() == [0.0] * 6
    assert (z == _BridgedDepth(_Depth.of(depth))[(slice(5, 15), slice(0, 40))]).all()  # read again: the same


# --- stop 49, treeseg49


def test_bridged_depth_cut_from_a_window_filled_before_is_the_same():
    """A window read inside one :class:`_BridgedDepth` filled just before is cut out of that one (no fill of its own)
    and holds the values it has when filled alone, read-only and contiguous; a window reaching past it is filled."""
    from symfruit.segment.colour import _BridgedDepth, _Depth

    rng = np.random.default_rng(3)
    depth = rng.choice(np.array([0.0, 1.0, 1.5, 2.0]), (40, 50), p=[0.6, 0.2, 0.1, 0.1])
    bridged = _BridgedDepth(_Depth.of(depth))
    filled = []
    fill = bridged._fill
    bridged._fill = lambda *a: filled.append(a[1:]) or fill(*a)  # type: ignore[method-assign]
    bridged[(slice(5, 35), slice(3, 40))]
    inner = bridged[(slice(9, 20), slice(10, 31))]
    assert len(filled) == 1 and inner.flags.c_contiguous and not inner.flags.writeable
    np.testing.assert_array_equal(inner, _BridgedDepth(_Depth.of(depth))[(slice(9, 20), slice(10, 31))])
    bridged[(slice(0, 20), slice(10, 31))]
    assert len(filled) == 2


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_pieces_in_two_calls_are_the_five_calls_labels(seed, monkeypatch):
    """``_plain_piece`` (a found piece's ripe test, hull, depth test and median depth in two compiled calls; stop 49)
    gives the labels that the five calls it stands for give (``_plain_piece`` left out), on rendered strawberry frames
    with depth, the default settings and with the hull's colour test off; and it took the pieces."""
    import symfruit.segment.colour as colour

    scene = make_scene(seed)
    taken = [0]
    plain = colour._plain_piece

    def counted(*args, **kwargs):
        found = plain(*args, **kwargs)
        taken[0] += found is not None
        return found

    for settings in (SegmentSettings(), SegmentSettings(fill="hull")):
        monkeypatch.setattr(colour, "_plain_piece", counted)
        fast = segment(scene.color, scene.depth, scene.camera, settings)
        monkeypatch.setattr(colour, "_plain_piece", lambda *args, **kwargs: None)
        np.testing.assert_array_equal(fast, segment(scene.color, scene.depth, scene.camera, settings))
        assert fast.max() >= 3
    kernels = pytest.importorskip("symfruit.core.kernels")
    assert taken[0] >= 6 or kernels.compiled() is None


def _sphere_depth(shape: tuple[int, int], focal: float, centre: np.ndarray, radius: float) -> np.ndarray:
    """The depth (metres, 0 off it) of a sphere's front seen by a pinhole camera of ``focal`` (pixels) whose
    principal point is the image's centre: each pixel's ray met with the sphere."""
    rows, cols = np.mgrid[0 : shape[0], 0 : shape[1]].astype(np.float64)
    cy, cx = shape[0] / 2, shape[1] / 2
    d = np.stack(((cols - cx) / focal, (rows - cy) / focal, np.ones(shape)), axis=-1)
    dc, dd = d @ centre, (d * d).sum(axis=-1)
    disc = dc * dc - dd * (centre @ centre - radius * radius)
    t = (dc - np.sqrt(np.maximum(disc, 0.0))) / dd
    return np.where(disc > 0, t, 0.0)


def test_a_rim_piece_with_depth_from_behind_lies_on_its_fruits_sphere():
    """A round fruit's piece along its silhouette, most of whose pixels carry the depth of what lies far behind
    (mixed and misregistered pixels on the rim) or far in front (the leaf that cut it off), lies on its fruit's
    sphere by its points that may be a fruit's surface there (:func:`_near_surface`; joined by the merge: it was
    told apart by a median over all its points); a piece of a second fruit beside the first, with the same share of
    such pixels, still does not."""
    from symfruit.segment.colour import _Depth, _Geometry, _Piece, _same_surface

    s = SegmentSettings(round_fruit=True, round_max_diameter=0.10)
    geo = _Geometry(900.0, 100.0, 100.0)
    r = 0.035
    one = _sphere_depth((200, 200), geo.focal, np.array([0.0, 0.0, 1.5 + r]), r)
    two = _sphere_depth((200, 200), geo.focal, np.array([2.6 * r, 0.0, 1.5 + r]), r)
    cols = np.arange(200)[None, :]
    rows = np.arange(200)[:, None]
    big = (one > 0) & (cols < 98)
    outlier = (rows + cols) % 5 < 3  # three pixels in five off any fruit's surface
    whole = (slice(0, 200), slice(0, 200))
    for told, small, sphere in ((True, (one > 0) & (cols > 110), one), (False, (two > 0) & (cols > 156), two)):
        depth = np.where(big, one, 0.0) + np.where(small, sphere, 0.0)
        depth[small & outlier & (rows % 2 == 0)] = 4.5  # the background behind the rim
        depth[small & outlier & (rows % 2 == 1)] = 1.2  # a leaf in front
        weak = big | small
        got = _same_surface(_Piece(whole, big.copy(), 1), _Piece(whole, small.copy(), 2), _Depth.of(depth), weak,
                            geo, s)  # fmt: skip
        assert got is told


def test_a_small_apple_cut_by_a_wide_leaf_in_front_is_one_fruit():
    """A small apple (42 px across, about 1.9 m) behind a leaf band 13-15 px wide, 30 cm in front: the two halves
    either side are farther apart than half the square root of either's area, yet no further than the gap two pieces
    of one round fruit may leave (:func:`_near_pieces` with ``round_fruit``), so the merge tests them and joins them
    (one sphere, the leaf's green discounted: before, two fruit). Without ``round_fruit`` they are not tested."""
    from dataclasses import replace

    yy, xx = np.mgrid[:1080, :1920]
    for half in (6, 7):
        color, depth = hd_disc_frame([(900, 540)], radius=21, z=1.9)
        apple = (color == RED).all(axis=2)
        band = (np.abs(yy - 540) <= half) & (np.abs(xx - 900) <= 40)
        color[band], depth[band] = (60, 120, 50), 1.6
        labels = segment(color, depth, HD_CAM, APPLE)
        assert labels.max() == 1, half
        assert (labels[apple & ~band] == 1).all(), half
        plain = segment(color, depth, HD_CAM, replace(APPLE, round_fruit=False, ground_colour=False))
        assert plain.max() == 2, half


@pytest.mark.parametrize("seed", range(3))
def test_near_pieces_of_round_fruit_table_is_the_row_by_row_test(seed, monkeypatch):
    """With ``round_fruit`` (the gap a leaf across one fruit may leave), the table's pairs are the row-by-row test's,
    and include every pair of the plain test."""
    from symfruit.segment import colour

    pieces = _random_pieces(seed)
    table, plain = colour._near_pieces(pieces, True), colour._near_pieces(pieces)
    monkeypatch.setattr(colour, "NEAR_TABLE", 0)
    rows = colour._near_pieces(pieces, True)
    found = [table(i) for i in range(len(pieces))]
    assert found == [rows(i) for i in range(len(pieces))]
    assert all(set(plain(i)) <= set(found[i]) for i in range(len(pieces)))
    assert sum(map(len, found)) > sum(len(plain(i)) for i in range(len(pieces)))


@pytest.mark.parametrize("seed", [3, 5])
def test_the_round_pieces_in_one_call_are_the_calls_labels(seed, monkeypatch):
    """``_round_piece`` (a round fruit's found piece's ripe test, hull and depth test in one compiled call) and
    ``_skin_seed`` (its skin's start: the part's depths, the blush rim's test, the median depth and centre in one; stop
    52) give the labels that the calls they stand for give (both left out), on small rendered apple-tree frames with
    the apple profile; and they took the pieces."""
    import symfruit.segment.colour as colour
    from symfruit.settings import resolve_settings
    from symfruit.synthetic.scenes import make_tree_scene
    from symfruit.synthetic.sensors import sensor_model

    scene = make_tree_scene(seed, sensor=sensor_model("azure-kinect").at(480, 270), n_apples=12, n_green=2)
    settings = resolve_settings(fruit="apple").segment
    taken = {"_round_piece": 0, "_skin_seed": 0}

    def counted(name):
        fn = getattr(colour, name)

        def call(*args, **kwargs):
            found = fn(*args, **kwargs)
            taken[name] += found is not None
            return found

        return call

    for name in taken:
        monkeypatch.setattr(colour, name, counted(name))
    fast = segment(scene.color, scene.depth, scene.camera, settings)
    for name in taken:
        monkeypatch.setattr(colour, name, lambda *args, **kwargs: None)
    np.testing.assert_array_equal(fast, segment(scene.color, scene.depth, scene.camera, settings))
    assert fast.max() >= 3
    kernels = pytest.importorskip("symfruit.core.kernels")
    assert min(taken.values()) >= 3 or kernels.compiled() is None


@pytest.mark.parametrize("kernels", ["numba", "numpy"])
def test_the_padded_boxes_are_find_objects(monkeypatch, kernels):
    """``_padded_boxes`` (the red windows' and the ground bodies' boxes before they are joined) with the kernels and
    with the twins: for random label images and kept labels, ``ndimage.find_objects``' box of each kept label, in the
    labels' order, widened by the pad and clipped to the image (pads 0-3, labels at the edges, none kept)."""
    from scipy import ndimage

    from symfruit.segment.colour import _padded_boxes

    if kernels == "numba":
        pytest.importorskip("numba")
        monkeypatch.delenv("SYMFRUIT_KERNELS", raising=False)
    else:
        monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    rng = np.random.default_rng(53)
    for _ in range(200):
        shape = (int(rng.integers(1, 30)), int(rng.integers(1, 30)))
        labels, n = ndimage.label(rng.random(shape) < rng.choice([0.1, 0.4, 0.7]), structure=np.ones((3, 3)))
        at = np.flatnonzero(labels)
        rows, cols = np.divmod(at, shape[1])
        keep = rng.random(n + 1) < 0.6
        keep[0] = False
        pad = int(rng.integers(0, 4))
        want = [(max(sl[0].start - pad, 0), min(sl[0].stop + pad, shape[0]),
                 max(sl[1].start - pad, 0), min(sl[1].stop + pad, shape[1]))
                for k, sl in enumerate(ndimage.find_objects(labels), 1) if keep[k]]  # fmt: skip
        got = _padded_boxes(labels.ravel().take(at), rows, cols, keep, pad, shape)
        assert got == want and all(type(v) is int for box in got for v in box)


@pytest.mark.parametrize("fruit", ["apple", "strawberry"])
def test_the_typical_depth_is_read_off_the_ground_bodies_grid(fruit, monkeypatch):
    """The frame's typical depth (the median of every 8th pixel's depth with depth) is the same number either way it
    is read: with the ground-colour bodies looked for (the apple profile, on a small rendered apple-tree frame) off
    every other point of their coarse grid's depths, whose grid is then the only strided window read (stop 54);
    without them (a strawberry frame) off the depth's every 8th pixel as before."""
    import symfruit.segment.colour as colour
    from symfruit.settings import resolve_settings
    from symfruit.synthetic.scenes import make_scene, make_tree_scene
    from symfruit.synthetic.sensors import sensor_model

    if fruit == "apple":
        scene = make_tree_scene(3, sensor=sensor_model("azure-kinect").at(480, 270), n_apples=12, n_green=2)
    else:
        scene = make_scene(0, n_ripe=8, n_unripe=2)
    settings = resolve_settings(fruit=fruit).segment
    steps, typical = [], []
    read, at = colour._Depth.__getitem__, colour._segment_at

    def reading(self, window):
        steps.append((window[0].step, window[1].step))
        return read(self, window)

    def segmenting(*args):
        typical.append(args[5])
        return at(*args)

    monkeypatch.setattr(colour._Depth, "__getitem__", reading)
    monkeypatch.setattr(colour, "_segment_at", segmenting)
    segment(scene.color, scene.depth, scene.camera, settings)
    grid = np.asarray(scene.depth, np.float64)[::8, ::8]
    grid = grid[np.isfinite(grid) & (grid > 0)]
    assert typical == [float(np.median(grid))]
    strided = {step for step in steps if step != (None, None)}
    assert strided == ({(4, 4)} if fruit == "apple" else {(8, 8)})


# --- seg63: a round fruit's pieces joined once grown to their skins


def _apple_behind_a_wide_leaf(half: int, behind: float = 0.0):
    """An 87 mm apple at 1.4 m (60 px across) behind a leaf 25 cm in front of it, ``2 half + 1`` px wide, across its
    middle from top to bottom; with ``behind`` the right side lies that much deeper (a second fruit seen past the
    leaf). Colour, depth and the apple's pixels beside the leaf."""
    yy, xx = np.mgrid[:1080, :1920]
    color, depth = hd_disc_frame([(900, 540)], radius=30, z=1.4)
    apple = (color == RED).all(axis=2)
    depth[apple & (xx > 900)] += behind
    band = (np.abs(xx - 900) <= half) & (np.abs(yy - 540) <= 40)
    color[band], depth[band] = (60, 120, 50), 1.15
    return color, depth, apple & ~band


@pytest.mark.parametrize("half", [12, 14])
def test_the_two_sides_of_an_apple_behind_a_wide_leaf_are_one_fruit(half):
    """A leaf 25-29 px wide across the middle of an apple 60 px across leaves its sides farther apart than the merge
    of the red pieces looks (:func:`_near_pieces`: 0.35 of the larger side's 60 px); each side was found and grown
    alone (two fruit, each under half the apple). Once grown, their union is one convex outline with the leaf's green
    discounted, no wider than the largest fruit (100 mm) at their depth, and their depths lie within its radius:
    one fruit, both sides (:func:`_join_found`)."""
    color, depth, sides = _apple_behind_a_wide_leaf(half)
    labels = segment(color, depth, HD_CAM, APPLE)
    assert labels.max() == 1
    assert (labels[sides] == 1).mean() > 0.95


def test_the_sides_seen_past_a_leaf_at_depths_a_fruit_apart_stay_two():
    """The same outline with its right side 12 cm deeper (more than the largest fruit's radius behind: a second
    fruit seen past the leaf, not the first one's surface): two fruit, as before."""
    color, depth, _ = _apple_behind_a_wide_leaf(12, behind=0.12)
    assert segment(color, depth, HD_CAM, APPLE).max() == 2


def test_two_whole_apples_side_by_side_stay_two():
    """Two apples touching side by side at one depth: their union reaches 120 px, further than the largest fruit
    (100 mm, 69 px at 1.4 m) is across: two fruit."""
    color, depth = hd_disc_frame([(900, 540), (961, 540)], radius=30, z=1.4)
    labels = segment(color, depth, HD_CAM, APPLE)
    assert labels.max() == 2


def test_grown_pieces_are_two_fruit_when_their_union_spans_more_than_the_largest_fruit():
    """:class:`_Grown`'s extent test: two pieces at 1.4 m whose union spans 64 px are one fruit's pieces as far as
    extents tell (the largest fruit, 100 mm, spans 68.6 px there); spanning 78 px, two fruit."""
    from symfruit.segment.colour import _Depth, _Geometry, _Grown, _hull_vertices, _Piece, _union

    grown = _Grown(_Depth.of(np.full((200, 400), 1.4)), _Geometry(960.0, 100.0, 200.0), APPLE, 1.4)
    for end, two in ((60, False), (75, True)):
        a = _Piece((slice(90, 110), slice(0, 20)), np.ones((20, 20), bool), 1)
        b = _Piece((slice(90, 110), slice(end - 20, end)), np.ones((20, 20), bool), 2)
        window, union = _union(a, b)
        assert grown.two(a, b, _hull_vertices(union), (window, union)) is two, end


@pytest.mark.parametrize("seed", range(3))
def test_the_masked_median_in_one_call_is_the_twins(seed, monkeypatch):
    """:func:`_masked_median` (the count of a mask's pixels with depth and their median, one compiled call where
    numba is) gives the numpy twin's values, with and without depth under the mask."""
    from symfruit.segment import colour

    rng = np.random.default_rng(seed)
    mask = rng.random((40, 50)) < 0.6
    depth = np.where(rng.random((40, 50)) < 0.7, rng.uniform(0.5, 3.0, (40, 50)), 0.0)
    for z in (depth, np.zeros_like(depth)):
        fast = colour._masked_median(mask, z)
        monkeypatch.setattr(colour, "compiled", lambda: None)
        twin = colour._masked_median(mask, z)
        monkeypatch.undo()
        assert fast[0] == twin[0] == int((mask & (z > 0)).sum())
        assert fast[1] == twin[1] or (np.isnan(fast[1]) and np.isnan(twin[1]))
