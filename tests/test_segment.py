"""The built-in colour segmenter: ripe red fruit found and numbered left to right, unripe fruit and specks
ignored, touching fruit split at depth steps and at waists."""

import numpy as np
import pytest

from symfruit.io.frames import read_frame
from symfruit.scenes import make_scene
from symfruit.segment import SegmentSettings, red_mask, segment

from .conftest import EXAMPLE_FRAME, SMALL_CAM, disc_frame

CAM = SMALL_CAM
YY, XX = np.mgrid[:120, :160]


def disc(cx, cy, r):
    return (XX - cx) ** 2 + (YY - cy) ** 2 <= r**2


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
    labels = segment(color, depth, CAM)
    assert labels.max() == 2
    assert labels[60, 55] != labels[60, 95]


def test_white_and_green_fruit_are_ignored():
    for colour in ((230, 230, 220), (120, 180, 60)):
        color, depth = disc_frame([(80, 60)], colour=colour)
        assert segment(color, depth, CAM).max() == 0


def test_red_discs_are_found_and_numbered_left_to_right():
    color, depth = disc_frame([(130, 40), (30, 80), (80, 60)], radius=15)
    labels = segment(color, depth, CAM)
    assert labels.dtype == np.int32 and labels.shape == (120, 160) and labels.max() == 3
    for k, (cx, cy) in enumerate([(30, 80), (80, 60), (130, 40)], 1):
        found = labels == k
        assert np.all(found[disc(cx, cy, 14)]) and not np.any(found & ~disc(cx, cy, 16))
    assert not labels[~(disc(30, 80, 16) | disc(80, 60, 16) | disc(130, 40, 16))].any()


def test_touching_fruit_at_different_depths_are_split_at_the_depth_step():
    # The front fruit (30 cm) hides part of the one behind (36 cm); their silhouettes overlap without a waist.
    color, depth = disc_frame([(70, 60), (92, 60)], radius=20, z=[0.30, 0.36])
    front, back = disc(70, 60, 20), disc(92, 60, 20) & ~disc(70, 60, 20)
    for split in ("both", "depth"):
        labels = segment(color, depth, CAM, SegmentSettings(split=split))
        assert labels.max() == 2
        # The cut follows the front fruit's rim to within 3 pixels.
        assert np.all(labels[disc(70, 60, 18)] == 1) and np.all(
            labels[back & ~disc(70, 60, 23) & disc(92, 60, 18)] == 2
        )
        assert not np.any((labels == 2) & disc(70, 60, 18)) and not np.any((labels == 1) & ~disc(70, 60, 23))
        assert abs(int((labels == 1).sum()) - int(front.sum())) < 0.1 * front.sum()
    for split in ("watershed", "none"):  # no waist to cut at: one region
        assert segment(color, depth, CAM, SegmentSettings(split=split)).max() == 1


def test_touching_fruit_at_the_same_depth_are_split_at_the_waist_only_when_asked():
    color, depth = disc_frame([(62, 60), (98, 60)], radius=20)
    assert segment(color, depth, CAM, SegmentSettings(split="watershed")).max() == 2
    assert segment(color, depth, CAM, SegmentSettings(split="none")).max() == 1


def test_a_fruit_too_small_for_its_depth_is_ignored():
    color, depth = disc_frame([(80, 60)], radius=4, z=0.3)  # 4 px at 30 cm: 4 mm across
    assert segment(color, depth, CAM).max() == 0
    assert segment(color, depth, CAM, SegmentSettings(min_diameter=0.002)).max() == 1
    color, _ = disc_frame([(80, 60)], radius=15)
    assert segment(color, np.zeros((120, 160), np.float32), CAM).max() == 0  # no depth: no size, no fruit


def test_nothing_red_gives_an_empty_label_image():
    color = np.full((120, 160, 3), 90, np.uint8)
    labels = segment(color, np.ones((120, 160), np.float32), CAM)
    assert labels.shape == (120, 160) and not labels.any()


@pytest.mark.parametrize(
    "rgb, red",
    [((200, 20, 30), True), ((255, 0, 0), True), ((200, 30, 80), True), ((120, 180, 60), False),
     ((230, 230, 220), False), ((30, 5, 5), False), ((200, 120, 30), False), ((90, 90, 90), False)],
)  # fmt: skip
def test_the_red_test_on_known_colours(rgb, red):
    color = np.zeros((2, 2, 3), np.uint8) + np.array(rgb, np.uint8)
    assert red_mask(color).all() == red and red_mask(color).any() == red
    assert red_mask(color, SegmentSettings(hue_low=0.0, hue_high=360.0, sat_min=0.0, val_min=0.0)).all()
