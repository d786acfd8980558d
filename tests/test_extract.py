"""From a fruit's mask to its points: exact de-projection, invalid depth dropped and counted, the border
eroded, the fruit's own cluster kept."""

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage

from symfruit import ConfigError, InputError
from symfruit.core.camera import Camera
from symfruit.extract import (
    ExtractSettings,
    _clusters,
    backdrop,
    beyond_even_cut,
    cluster,
    cluster_gap,
    extract,
    front_ring,
    keep_caps,
    one_sided,
    own_cap,
    own_surface,
    register,
    shift_labels,
    star_shaped,
    trim_labels,
    trim_mask,
    trim_window,
)
from symfruit.io import read_frame

from .conftest import EXAMPLE_FRAME, SMALL_CAM, disc_frame, leaf_across_frame

CAM = SMALL_CAM
NO_EROSION = ExtractSettings(erode_px=0)


def test_extract_drops_invalid_depth_flying_pixels_and_other_clusters():
    _, depth = disc_frame([(80, 60)])
    mask = np.zeros((120, 160), bool)
    yy, xx = np.mgrid[:120, :160]
    mask[(xx - 80) ** 2 + (yy - 60) ** 2 <= 22**2] = True  # a little larger than the fruit: background leaks in
    depth[60, 70:75] = 0.0  # no depth
    ex = extract(mask, depth, CAM, ExtractSettings())
    assert ex.n_invalid >= 5 and ex.n_other_clusters > 0
    assert ex.points[:, 2].max() < 0.31 and not ex.truncated
    ex2 = extract(np.roll(mask, -70, axis=1), np.roll(depth, -70, axis=1), CAM)
    assert ex2.truncated


def test_cluster_labels_largest_first():
    rng = np.random.default_rng(0)
    a = rng.random((600, 3)) * 0.01
    b = rng.random((300, 3)) * 0.01 + [0, 0, 0.2]  # behind: another depth slab
    c = rng.random((150, 3)) * 0.01 + [0.1, 0, 0]  # beside: same depths, another cluster
    labels = cluster(np.vstack([b, a, c]), 0.006)
    assert set(labels[300:900]) == {0} and set(labels[:300]) == {1} and set(labels[900:]) == {2}


def test_known_pixels_and_depths_are_deprojected_exactly():
    mask = np.zeros((120, 160), bool)
    depth = np.zeros((120, 160), np.float32)
    pixels = [(10, 20, 0.5), (10, 21, 0.5), (11, 20, 0.5), (60, 80, 0.5), (100, 150, 0.5)]  # (row, col, z)
    for r, c, z in pixels:
        mask[r, c] = True
        depth[r, c] = z
    # One cluster needs neighbours: spread is 1 px at 0.5 m, under a cluster distance of 1 m.
    ex = extract(mask, depth, CAM, ExtractSettings(erode_px=0, cluster_distance=1.0, min_points=4))
    expected = np.array([[(c - 80) / 600 * z, (r - 60) / 600 * z, z] for r, c, z in pixels])
    assert ex.points.shape == (5, 3) and np.allclose(ex.points, expected, rtol=0, atol=1e-12)
    assert (ex.mask_area, ex.n_invalid, ex.n_border, ex.n_other_clusters, ex.truncated) == (5, 0, 0, 0, False)


def test_invalid_depth_is_dropped_and_counted():
    mask = np.zeros((120, 160), bool)
    mask[50:60, 70:80] = True  # 100 pixels
    depth = np.where(mask, 0.4, 1.0).astype(np.float32)  # before a wall (a flat depth all round is no fruit's)
    depth[50, 70:74] = [0.0, np.nan, np.inf, -0.4]  # no depth, NaN, infinite, negative
    depth[51, 70:72] = [0.05, 3.5]  # nearer than min_depth, farther than max_depth
    depth[59, 79] = 0.1  # exactly min_depth: valid
    ex = extract(mask, depth, CAM, NO_EROSION)
    assert ex.n_invalid == 6 and len(ex.points) == 94 - 1 and ex.n_other_clusters == 1
    assert np.isfinite(ex.points).all() and ex.points[:, 2].max() == pytest.approx(0.4)
    kept = extract(mask, depth, CAM, ExtractSettings(erode_px=0, min_depth=0.01, max_depth=4.0))
    assert kept.n_invalid == 4  # the range is a setting


def test_a_far_cluster_is_dropped_and_the_nearest_big_one_kept():
    mask = np.zeros((120, 160), bool)
    mask[40:80, 40:80] = True  # 1600 pixels
    depth = np.full((120, 160), 0.8, np.float32)  # background behind the fruit, leaking in through the mask
    depth[40:80, 40:60] = 0.3  # the fruit: the left half, 800 pixels
    ex = extract(mask, depth, CAM, NO_EROSION)
    assert len(ex.points) == 800 and ex.n_other_clusters == 800 and np.all(ex.points[:, 2] == np.float32(0.3))
    # A small near cluster (a leaf edge) is not the fruit: it holds under cluster_share of the largest.
    depth[40:42, 60:62] = 0.2
    ex = extract(mask, depth, CAM, NO_EROSION)
    assert len(ex.points) == 800 and ex.n_other_clusters == 800 and ex.points[:, 2].min() == np.float32(0.3)
    # ... nor is a large one 10 cm in front: the fruit's depth mode is where most of the mask's depth lies
    depth[40:50, 60:80] = 0.2
    ex = extract(mask, depth, CAM, NO_EROSION)
    assert len(ex.points) == 800 and ex.points[:, 2].min() == np.float32(0.3)


def test_erosion_drops_the_border_unless_the_mask_is_small():
    mask = np.zeros((120, 160), bool)
    mask[40:60, 60:80] = True  # 20 x 20
    depth = np.where(mask, 0.4, 1.0).astype(np.float32)  # before a wall (a flat depth all round is no fruit's)
    ex = extract(mask, depth, CAM, ExtractSettings(erode_px=1))
    assert ex.mask_area == 400 and ex.n_border == 400 - 18 * 18 and len(ex.points) == 18 * 18
    ex2 = extract(mask, depth, CAM, ExtractSettings(erode_px=2))
    assert ex2.n_border == 400 - 16 * 16
    assert extract(mask, depth, CAM, NO_EROSION).n_border == 0
    small = np.zeros((120, 160), bool)
    small[40:46, 60:66] = True  # 6 x 6: eroded it would keep 16 pixels, under min_points (30)
    ex3 = extract(small, np.where(small, 0.4, 1.0).astype(np.float32), CAM, ExtractSettings(erode_px=1))
    assert ex3.n_border == 0 and len(ex3.points) == 36


def test_a_mask_touching_the_image_border_is_truncated():
    depth = np.full((120, 160), 0.4, np.float32)
    for sl in [np.s_[0:10, 50:60], np.s_[110:120, 50:60], np.s_[50:60, 0:10], np.s_[50:60, 150:160]]:
        mask = np.zeros((120, 160), bool)
        mask[sl] = True
        assert extract(mask, depth, CAM).truncated
    mask = np.zeros((120, 160), bool)
    mask[1:11, 1:11] = True
    assert not extract(mask, depth, CAM).truncated


def test_an_empty_mask_gives_no_points():
    ex = extract(np.zeros((120, 160), bool), np.ones((120, 160), np.float32), CAM)
    assert ex.points.shape == (0, 3) and ex.mask_area == 0 and ex.n_invalid == 0


def test_settings_are_checked():
    with pytest.raises(ConfigError, match="min_depth: must be smaller than max_depth"):
        ExtractSettings(min_depth=2.0, max_depth=1.0)
    with pytest.raises(ConfigError, match="erode_px: must be <= 50"):
        ExtractSettings(erode_px=51)


def test_clustering_edge_cases():
    assert cluster(np.zeros((0, 3)), 0.01).shape == (0,)
    assert cluster(np.array([[0.0, 0.0, 0.3]]), 0.01).tolist() == [0]
    far = np.array([[0.0, 0.0, 0.3], [0.0, 0.0, 0.9], [0.0, 0.0, 0.3005]])
    assert cluster(far, 0.01).tolist() == [0, 1, 0]
    sparse = np.array([[0.0, 0.0, 0.3], [50.0, 50.0, 0.3], [0.001, 0.0, 0.3]])  # a huge, sparse grid
    assert cluster(sparse, 0.002).tolist() == [0, 1, 0]


@given(st.integers(0, 10_000), st.floats(0.002, 0.02))
def test_points_closer_than_half_the_distance_share_a_cluster(seed, distance):
    rng = np.random.default_rng(seed)
    walk = np.cumsum(rng.uniform(-1, 1, size=(50, 3)) * distance * 0.49 / np.sqrt(3), axis=0) + [0, 0, 0.4]
    labels = cluster(walk, distance)  # every step is shorter than distance / 2: one chain
    assert set(labels.tolist()) == {0}
    apart = np.vstack([walk, walk + [10 * distance + np.ptp(walk[:, 0]), 0, 0]])
    labels = cluster(apart, distance)
    assert set(labels[:50].tolist()) == {labels[0]} and set(labels[50:].tolist()) == {labels[50]}
    assert labels[0] != labels[50]


def test_shift_labels_moves_and_clips():
    labels = np.zeros((5, 6), np.int32)
    labels[1, 1], labels[4, 5] = 1, 2
    moved = shift_labels(labels, 2, -1)
    assert moved[0, 3] == 1 and moved.sum() == 1  # label 2 moved out of the image
    assert np.array_equal(shift_labels(labels, 0, 0), labels)
    assert not shift_labels(labels, 6, 0).any() and not shift_labels(labels, 0, -5).any()


def test_register_moves_the_masks_onto_the_depth():
    _, depth = disc_frame([(50, 60), (110, 60)], radius=18)
    labels = np.zeros((120, 160), np.int32)
    yy, xx = np.mgrid[:120, :160]
    labels[(xx - 46) ** 2 + (yy - 63) ** 2 <= 18**2] = 1  # both drawn 4 px left and 3 px down of the depth
    labels[(xx - 106) ** 2 + (yy - 63) ** 2 <= 18**2] = 2
    moved, shift = register(labels, depth, CAM)
    assert shift == (4, -3) and np.array_equal(moved, shift_labels(labels, 4, -3))
    same, none = register(moved, depth, CAM)
    assert none == (0, 0) and same is moved
    assert register(labels, depth, CAM, ExtractSettings(registration_px=0))[1] == (0, 0)


def test_a_support_under_the_fruit_is_not_its_surface():
    """A ball on a table: the table meets the ball at its lowest point and comes nearer below it; a mask drawn
    a few pixels too large takes in table pixels at the ball's depth, which the convexity cut leaves out."""
    cam = Camera(fx=600, fy=600, cx=80, cy=60, width=160, height=120)
    yy, xx = np.mgrid[:120, :160].astype(float)
    d2 = ((xx - 80) ** 2 + (yy - 60) ** 2) / 20.0**2
    r_m = 20 * 0.5 / 600
    depth = np.where(yy > 60, 0.5 + r_m - (yy - 80) * 0.002, 0.8)
    depth = np.where(d2 <= 1, 0.5 + r_m * (1 - np.sqrt(np.clip(1 - d2, 0, None))), depth)
    mask = d2 <= (24.0 / 20.0) ** 2
    ex = extract(mask, depth, cam, NO_EROSION)
    uv = cam.project(ex.points)
    off_ball = ((uv[:, 0] - 80) ** 2 + (uv[:, 1] - 60) ** 2) > 20.5**2
    assert off_ball.sum() <= 0.2 * (mask & (d2 > 1)).sum()
    assert not (uv[:, 1] > 81).any()  # below the ball, where the table comes nearer


def test_masks_are_colour_trimmed_in_the_colour_cameras_pixels():
    """Two fruit whose masks overshoot by 3 px: each is trimmed back to its own disc of colour, the other's
    label and the background untouched; with ``colour_trim_px`` 0 nothing changes."""
    color, _ = disc_frame([(50, 60), (115, 60)], radius=18)
    yy, xx = np.mgrid[:120, :160]
    labels = np.zeros((120, 160), np.int32)
    for k, cx in ((1, 50), (2, 115)):
        labels[(xx - cx) ** 2 + (yy - 60) ** 2 <= 21**2] = k
    trimmed = trim_labels(color, labels)
    for k, cx in ((1, 50), (2, 115)):
        assert np.array_equal(trimmed == k, (xx - cx) ** 2 + (yy - 60) ** 2 <= 18**2)
    assert trimmed is not labels and labels.max() == 2 and (labels == 1).sum() > (trimmed == 1).sum()
    assert trim_labels(color, labels, ExtractSettings(colour_trim_px=0)) is labels


def test_masks_overshooting_by_more_than_the_band_are_trimmed_all_round():
    """Masks 7 px too large (the band is 4 px): the fruit's sample just inside the band holds leaves, the colours do
    not separate there; twice the band they do, and each mask is trimmed back to its own disc (before: untouched)."""
    color, _ = disc_frame([(50, 60), (115, 60)], radius=18)
    yy, xx = np.mgrid[:120, :160]
    labels = np.zeros((120, 160), np.int32)
    for k, cx in ((1, 50), (2, 115)):
        labels[(xx - cx) ** 2 + (yy - 60) ** 2 <= 25**2] = k
    trimmed = trim_labels(color, labels)
    for k, cx in ((1, 50), (2, 115)):
        assert np.array_equal(trimmed == k, (xx - cx) ** 2 + (yy - 60) ** 2 <= 18**2)


@pytest.mark.parametrize("name", ["lab-spheres-0", "lab-spheres-1"])
def test_good_masks_of_real_shaded_spheres_are_not_trimmed(name):
    """The shared real Azure Kinect frames: each sphere's mask follows its colour edge to a pixel, and the
    lower limbs are shaded towards the grey board; learning the fruit's colours near its outline keeps them
    (learnt over the whole lit interior, the 200 mm sphere lost about 4 px of its lower arc)."""
    from symfruit.io.frames import read_frame

    from .conftest import EXAMPLES

    frame = read_frame(EXAMPLES / "real-frames" / name)
    labels = frame.masks.astype(np.int32)
    assert np.array_equal(trim_labels(frame.color, labels), labels)


def test_extract_register_and_trim_labels_refuse_inputs_that_do_not_fit_by_name():
    frame = read_frame(EXAMPLE_FRAME)
    h, w = frame.depth.shape
    mask = np.zeros((h, w), bool)
    mask[200:260, 300:360] = True
    ok = extract(mask, frame.depth, frame.camera)
    # an integer mask is read as its non-zero pixels (before: an int64 mask viewed as 8 bytes a pixel, other points)
    assert np.array_equal(extract(mask.astype(np.int64) * 5, frame.depth, frame.camera).points, ok.points)
    cases = [
        (lambda: extract(mask.T, frame.depth, frame.camera), "mask must be an (h, w) image of the depth's shape"),
        (lambda: extract(mask * 0.5, frame.depth, frame.camera), "mask must be bool, got float64"),
        (lambda: extract(mask, (frame.depth * 1000).astype(np.uint16), frame.camera), "depth must be float metres"),
        (lambda: extract(mask, frame.depth, "camera.json"), "camera must be a symfruit Camera, got str"),
        (lambda: extract(mask, frame.depth, Camera(fx=600, fy=600, cx=50, cy=50, width=100, height=100)),
         "the camera is for 100x100 images, the depth is 640x480"),
        (lambda: extract(mask, frame.depth, frame.camera, leafy=np.zeros((3, 3), bool)), "leafy must be an (h, w)"),
        (lambda: register(mask.T.astype(np.int32), frame.depth, frame.camera), "labels must be an (h, w) image"),
        (lambda: register(mask + 0.5, frame.depth, frame.camera), "labels must be whole numbers, got float64"),
        (lambda: trim_labels(frame.color[..., 0], mask.astype(np.int32)), "colour must be (h, w, 3) uint8 RGB"),
        (lambda: trim_labels(frame.color, mask.T.astype(np.int32)), "labels must be an (h, w) image of the colour"),
    ]  # fmt: skip
    for call, message in cases:  # before: numpy broadcast/index errors, AttributeError, or silently no points
        with pytest.raises(InputError, match=re.escape(message)):
            call()


def test_a_leaf_in_front_that_the_mask_covers_is_not_the_fruit_without_colour():
    """A ball 0.5 m away behind a flat leaf 2 cm nearer hiding its left part, the mask the ball's whole outline (an
    annotator's amodal mask, no colour given): the points are the ball's, none the leaf's."""
    cam = Camera(fx=600, fy=600, cx=80, cy=60, width=160, height=120)
    yy, xx = np.mgrid[:120, :160].astype(float)
    d2 = ((xx - 80) ** 2 + (yy - 60) ** 2) / 20.0**2
    r_m = 20 * 0.5 / 600
    depth = np.where(d2 <= 1, 0.5 + r_m * (1 - np.sqrt(np.clip(1 - d2, 0, None))), 0.8)
    leaf = (xx - 50) ** 2 + (yy - 60) ** 2 <= 22**2
    depth = np.where(leaf, 0.48 + 0.0002 * (xx - 50), depth)
    depth += np.random.default_rng(0).normal(scale=0.0005, size=depth.shape)
    ex = extract(d2 <= 1, depth, cam, NO_EROSION)
    assert len(ex.points) >= 0.8 * ((d2 <= 1) & ~leaf).sum()
    assert ex.points[:, 2].min() > 0.497 and ex.points[:, 2].max() < 0.5 + r_m + 0.003


# --- stop 43, robust43


def test_extract_refuses_a_depth_in_millimetres_rather_than_giving_no_points():
    """Float millimetres handed over as metres: before, every pixel lay beyond extract.max_depth and the fruit had 0
    points, unsaid; a Frame's depth (checked=True) is not sampled again."""
    color, depth = disc_frame([(80, 60)])
    mask = np.all(color == (200, 20, 30), axis=2)
    assert len(extract(mask, depth, CAM).points) > 0
    with pytest.raises(InputError, match=r"extract: depth is .* m typically; depth must be metres"):
        extract(mask, depth * 1000.0, CAM)
    assert len(extract(mask, depth * 1000.0, CAM, checked=True).points) == 0
    assert len(extract(mask, np.full_like(depth, np.nan), CAM).points) == 0  # no depth at all: 0 points, as before


def test_trim_labels_names_the_masks_it_trimmed():
    """``trimmed`` gets the labels of the masks that lost pixels: a mask 3 px too large (trimmed) and one drawn to its
    disc (not), labels 1 and 3 with 2 missing; none when the trim is off."""
    color, _ = disc_frame([(50, 60), (115, 60)], radius=18)
    yy, xx = np.mgrid[:120, :160]
    labels = np.zeros((120, 160), np.int32)
    labels[(xx - 50) ** 2 + (yy - 60) ** 2 <= 21**2] = 1
    labels[(xx - 115) ** 2 + (yy - 60) ** 2 <= 18**2] = 3
    trimmed: set[int] = set()
    out = trim_labels(color, labels, trimmed=trimmed)
    assert trimmed == {1} and (out == 1).sum() < (labels == 1).sum()
    assert np.array_equal(out == 3, labels == 3)
    off: set[int] = set()
    assert trim_labels(color, labels, ExtractSettings(colour_trim_px=0), trimmed=off) is labels and off == set()


def test_one_cluster_keeps_every_point_on_the_fruit():
    """A mask well inside a fruit's disc (one cluster, stop 46's path without picking a cluster): every mask pixel's
    point kept, nothing counted as another cluster, the points those of the pixels in raster order."""
    _, depth = disc_frame([(80, 60)])
    yy, xx = np.mgrid[:120, :160]
    mask = (xx - 80) ** 2 + (yy - 60) ** 2 <= 12**2
    ex = extract(mask, depth, CAM, NO_EROSION)
    assert len(ex.points) == int(mask.sum()) and ex.n_other_clusters == 0 and ex.n_invalid == 0
    rows, cols = np.nonzero(mask)
    np.testing.assert_array_equal(ex.points[:, 2], depth[rows, cols].astype(np.float64))
    assert cluster(ex.points, NO_EROSION.cluster_distance).max() == 0


@pytest.mark.parametrize("seed", [0, 1])
def test_an_outlined_mask_over_a_leaf_running_on_across_it_gives_the_fruit_behind(seed):
    """An annotator's mask drawn over a leaf 10 cm in front that hides all but a crescent of the fruit and runs on
    across the outline (``outlined``, the default: :func:`~symfruit.core.surface._behind_crossing` passes it over):
    the crescent's points, none nearer than the fruit's front (0.5 m). ``outlined=False``, as for the colour
    segmenter's masks (stop 47, docs/mask47.md), skips that test: the points are the leaf's (0.40 m), every one."""
    _, depth, mask = leaf_across_frame(seed)
    fruit = extract(mask, depth, CAM)
    assert 120 <= len(fruit.points) <= 200 and fruit.points[:, 2].min() > 0.5
    assert np.array_equal(extract(mask, depth, CAM, outlined=True).points, fruit.points)
    leaf = extract(mask, depth, CAM, outlined=False)
    assert len(leaf.points) > 2000 and leaf.points[:, 2].max() < 0.41


def _ball_before_a_wall(off: int = 0, mask_px: int = 14, rim: float = 0.0):
    """(depth, mask) seen by a 160x120 camera of f = 600 px: a ball of 12 px (its front 0.6 m) before a wall 1.2 m
    away, a mask of ``mask_px`` pixels about a point ``off`` pixels left of the ball's centre (an annotator's mask off
    the fruit, or a registration off it); ``rim``: the ball's outer share of its radius left without depth."""
    yy, xx = np.mgrid[:120, :160].astype(float)
    d2 = ((xx - 80) ** 2 + (yy - 60) ** 2) / 12.0**2
    depth = np.where(d2 <= 1, 0.6 + 0.012 * (1 - np.sqrt(np.clip(1 - d2, 0, None))), 1.2)
    depth[(d2 <= 1) & (d2 >= (1 - rim) ** 2)] = 0.0
    mask = ((xx - 80 + off) ** 2 + (yy - 60) ** 2) <= mask_px**2
    return depth, mask


BALL_CAM = Camera(fx=600, fy=600, cx=80, cy=60, width=160, height=120)


def test_the_wall_around_a_mask_is_behind_a_fruit_and_level_with_the_wall():
    depth, mask = _ball_before_a_wall()
    ball = extract(mask, depth, BALL_CAM)
    behind, level, count = backdrop(ball.points, mask, depth, 600.0)
    assert behind == 1.0 and level == 0.0 and count > 100  # everything around the ball is the wall, 0.6 m behind it
    wall = np.array([[0.0, 0.0, 1.2]] * 40)
    assert backdrop(wall, mask, depth, 600.0)[:2] == (0.0, 1.0)  # the wall's own depth all around
    assert backdrop(wall[:0], mask, depth, 600.0)[2] == 0 and backdrop(wall, mask & False, depth, 600.0)[2] == 0


@pytest.mark.parametrize("off", [14, 16, 20])
def test_a_mask_off_the_fruit_gives_the_fruits_points_not_the_wall_behind(off):
    """The mask holds more wall than ball: extraction's depth mode is the wall's, 0.6 m behind; around the mask the
    wall runs on at that depth and nothing lies behind it, so the ball's pixels in front are taken (before: the wall,
    a box 0.6 m off)."""
    depth, mask = _ball_before_a_wall(off)
    wall = extract(mask, depth, BALL_CAM, own=False)
    assert np.median(wall.points[:, 2]) == pytest.approx(1.2)  # what extraction kept before
    ex = extract(mask, depth, BALL_CAM)
    assert len(ex.points) >= 30 and ex.error == ""
    assert ex.points[:, 2].max() < 0.613 and ex.points[:, 2].min() >= 0.6  # the ball's front, nothing else
    assert ex.n_other_clusters == ex.mask_area - ex.n_border - ex.n_invalid - len(ex.points)


def test_a_mask_holding_only_the_wall_gives_no_points_and_says_why():
    """A ball whose own pixels the camera left without depth (a small fruit far off through a time-of-flight camera)
    under a mask overshooting it: what the mask holds is the wall; no points, the reason."""
    depth, mask = _ball_before_a_wall(0, mask_px=17, rim=1.0)
    ex = extract(mask, depth, BALL_CAM)
    assert len(ex.points) == 0
    why = (r"no depth of the fruit's own: the \d+ points its mask holds \(at 1\.200 m\) run on past its outline at "
           r"their depth \(100% of the pixels around it\) with nothing around behind them \(the background seen "
           r"through the mask, not the fruit\); 0 mask pixels nearer")  # fmt: skip
    assert re.fullmatch(why, ex.error)
    assert extract(mask, depth, BALL_CAM, own=False).error == ""


def test_a_fruit_before_a_wall_or_against_a_leaf_keeps_its_points():
    depth, mask = _ball_before_a_wall(8)  # the mask off the ball, but holding more ball than wall
    ex = extract(mask, depth, BALL_CAM, own=False)
    assert own_surface(ex, mask, depth, BALL_CAM) is ex
    _, depth, mask = leaf_across_frame()  # a leaf in front running on across the outline: no wall behind
    ex = extract(mask, depth, CAM, own=False)
    assert own_surface(ex, mask, depth, CAM) is ex


# --- stop 52, register52


@pytest.mark.parametrize("kernels", ["numba", "numpy"])
@pytest.mark.parametrize("min_depth", [0.0, 0.1])
def test_extraction_hands_its_cleaned_depth_to_the_surface_as_it_is(monkeypatch, kernels, min_depth):
    """With a least depth above 0 the depth extraction keeps is finite and above 0 or 0, and ``fruit_surface`` is
    told so (``clean``: not cleaned again); at 0 it is cleaned as before. The points are the same either way, on a
    ball with NaN, infinite, negative and zero depths among its pixels (with the kernels and with the twins)."""
    import symfruit.extract as extract_module

    if kernels == "numpy":
        monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    _, depth = disc_frame([(80, 60)])
    depth = depth.astype(np.float64)
    rng = np.random.default_rng(3)
    spoilt = rng.random(depth.shape) < 0.05
    depth[spoilt] = rng.choice([np.nan, np.inf, -0.3, 0.0, -0.0], size=int(spoilt.sum()))
    yy, xx = np.mgrid[:120, :160]
    mask = (xx - 80) ** 2 + (yy - 60) ** 2 <= 20**2
    s = ExtractSettings(min_depth=min_depth)
    told, own = [], extract_module.fruit_surface

    def surface(*args, clean=False, **kwargs):
        told.append(clean)
        return own(*args, clean=clean, **kwargs)

    monkeypatch.setattr(extract_module, "fruit_surface", surface)
    ex = extract(mask, depth, CAM, s)
    assert told == [min_depth > 0]

    def cleaned(*args, clean=False, **kwargs):
        return own(*args, clean=False, **kwargs)

    monkeypatch.setattr(extract_module, "fruit_surface", cleaned)
    assert np.array_equal(ex.points, extract(mask, depth, CAM, s).points) and len(ex.points) > 500


def far_sphere(focal, centre_z=1.6, radius=0.1, size=100):
    """A sphere's depth and silhouette through a pinhole of focal length ``focal`` (pixels; principal point at the
    image's centre): the ray through each pixel's centre meets it at its nearest intersection."""
    cam = Camera(fx=focal, fy=focal, cx=(size - 1) / 2, cy=(size - 1) / 2, width=size, height=size)
    v, u = np.mgrid[:size, :size].astype(np.float64)
    rays = np.stack(((u - cam.cx) / focal, (v - cam.cy) / focal, np.ones_like(u)), axis=-1)
    rays /= np.linalg.norm(rays, axis=-1, keepdims=True)
    b = rays[..., 2] * centre_z
    disc = b * b - (centre_z**2 - radius**2)
    hit = disc > 0
    t = np.where(hit, b - np.sqrt(np.where(hit, disc, 0.0)), 0.0)
    return cam, (t * rays[..., 2]).astype(np.float32), hit


def test_a_far_fruit_seen_by_coarse_pixels_is_one_cluster():
    """Stop 55 (docs/realpert55.md): a 200 mm sphere 1.5 m away through a camera of focal length 306 px (the real Azure
    Kinect frames binned 3 x 3) samples its surface 5 mm a pixel, 10 mm where it turns away; a fixed 6 mm
    clustering distance broke it into single pixels (the real sphere kept 6 of 1,033 points and failed). The
    distance grows to four pixel footprints at the points' depth: the whole sphere is kept, as through a finer
    camera."""
    cam, depth, mask = far_sphere(306.0)
    ex = extract(mask, depth, cam, NO_EROSION)
    assert len(ex.points) >= 0.9 * mask.sum() and ex.n_other_clusters <= 0.1 * mask.sum()
    fine_cam, fine_depth, fine_mask = far_sphere(917.0, size=300)
    assert len(extract(fine_mask, fine_depth, fine_cam, NO_EROSION).points) >= 0.9 * fine_mask.sum()


def test_the_wider_gap_is_taken_only_where_the_distance_broke_the_points_into_pixels():
    """Stop 55, on merging realpert55: at 3 m through a 600 px camera four pixel footprints are 20 mm. A fruit and a
    smaller leaf 8 mm off it, each sampled every 2 mm, are two clusters at the setting's 6 mm, the fruit the larger,
    and stay two (the wider gap would join them: a visible apple on the rendered trees grew 0.9 -> 21.5 mm deep); a
    fruit sampled every 8 mm (single points at 6 mm) is one cluster at the wider gap."""
    g = np.arange(0.0, 0.04, 0.002)
    patch = np.stack(np.meshgrid(g, g), axis=-1).reshape(-1, 2)
    fruit = np.column_stack((patch, np.full(len(patch), 3.0)))
    leaf = fruit[fruit[:, 0] < 0.02] + [0.046, 0.0, 0.0]  # half the fruit's columns, 8 mm beyond its last
    labels = _clusters(np.vstack((fruit, leaf)), CAM, 0.006)
    assert (
        labels.max() == 1
        and len(set(labels[: len(fruit)])) == 1
        and set(labels[: len(fruit)]) != set(labels[len(fruit) :])
    )
    assert cluster(np.vstack((fruit, leaf)), cluster_gap(fruit, CAM, 0.006)).max() == 0  # what the gap alone did
    coarse = np.column_stack((patch * 4, np.full(len(patch), 3.0)))  # every 8 mm
    assert cluster(coarse, 0.006).max() + 1 == len(coarse)  # single points at the setting's distance
    assert _clusters(coarse, CAM, 0.006).max() == 0


def test_the_clustering_gap_is_the_setting_until_pixels_are_coarser():
    near = np.array([[0.0, 0.0, 0.5], [0.1, 0.0, 0.6], [0.0, 0.1, 3.0]])  # the median depth 0.6 m
    assert cluster_gap(near, CAM, 0.006) == 0.006  # at 600 px a pixel 1 mm, four 4 mm: the setting
    assert cluster_gap(near * [1, 1, 5], CAM, 0.006) == pytest.approx(4 * 3.0 / 600)  # at 3 m four pixels 20 mm
    odd = Camera(fx=100.0, fy=400.0, cx=50, cy=50, width=100, height=100)  # the geometric mean focal length, 200
    assert cluster_gap(near, odd, 0.001) == pytest.approx(4 * 0.6 / 200)


def sphere_under_a_strip(cut: bool):
    """:func:`far_sphere` (200 mm, 1.4 m, f 917 px; its outer 15 % of radius without depth, a time-of-flight camera's
    rim) with a strip 5 cm in front of its front across its middle fifth, reaching beyond it on both sides, the
    2 px either side of the strip without depth (the camera's mixed pixels); ``cut``: the mask loses the strip
    (the visible part outlined), else it is drawn over it (the whole fruit)."""
    from scipy import ndimage

    cam, depth, mask = far_sphere(917.0, centre_z=1.4, size=180)
    depth = depth.astype(np.float64)
    rows = np.flatnonzero(mask.any(axis=1))
    r0, r1 = rows[0], rows[-1] + 1
    core = ndimage.binary_erosion(mask, iterations=int(0.15 * (r1 - r0) / 2))
    depth[mask & ~core] = 0.0
    yy = np.mgrid[: depth.shape[0], : depth.shape[1]][0]
    strip = np.abs(yy - (r0 + r1 - 1) / 2) <= 0.1 * (r1 - r0)
    depth[strip] = 1.25  # 5 cm in front of the sphere's front pole (1.3 m)
    depth[ndimage.binary_dilation(strip, iterations=2) & ~strip] = 0.0
    drawn = mask & ~strip if cut else mask
    return cam, depth, drawn, strip


@pytest.mark.parametrize("cut", [False, True])
def test_a_fruit_parted_by_a_strip_in_front_keeps_both_parts(cut):
    """Stop 56 (issue 18, docs/strip56.md): a strip 5 cm in front across a sphere parts its seen pixels in two,
    40 mm apart; clustering kept the nearer half alone (the real Azure Kinect spheres' boxes then 14.5 mm too
    shallow). Both halves lie on one convex surface with only the strip between them: both are kept, whether the
    mask is drawn over the strip or cut by it."""
    cam, depth, mask, strip = sphere_under_a_strip(cut)
    ex = extract(mask, depth, cam)
    seen = mask & ~strip & (depth > 1.29)  # the sphere's pixels with depth
    rows = np.round(ex.points[:, 1] / ex.points[:, 2] * cam.fy + cam.cy)
    centre = np.flatnonzero(strip.any(axis=1)).mean()
    assert (rows < centre).sum() > 0.4 * seen.sum() and (rows > centre).sum() > 0.4 * seen.sum()
    assert len(ex.points) >= 0.9 * seen.sum()
    assert ex.points[:, 2].min() > 1.29  # none of the strip


# --- stop 57, shift57: the colour trim takes no pixel of the fruit's own surface (extract.trim_keeps_surface, on
# since stop 61)

KEEPS = ExtractSettings(trim_keeps_surface=True)


def shaded_ball(board: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(color, depth, d2)``: :func:`disc_frame`'s red ball of 20 px at (80, 60), its front 0.29 m, its lowest 5 rows
    shaded to the background's grey (a limb darkening towards a grey board, as the real 200 mm sphere's); ``board``:
    below the ball's bottom row a grey board at its depth there that turns back towards the camera, 4 mm a row (a
    support meeting it at a crease). ``d2`` the squared pixel distance from the disc's centre."""
    color, depth = disc_frame([(80, 60)], radius=20, z=0.3)
    yy, xx = np.mgrid[:120, :160]
    d2 = (xx - 80) ** 2 + (yy - 60) ** 2
    color[(d2 <= 400) & (yy >= 76)] = 90
    if board:
        depth[81:] = (0.3 - 0.004 * (yy[81:] - 80)).astype(np.float32)
    return color, depth, d2


def test_the_colour_trim_takes_no_pixel_of_the_fruits_own_surface():
    """Stop 57 (docs/shift57.md): the colour alone takes the ball's shaded limb off (its lowest rows look like the
    grey ring beside the mask); with the depth and ``trim_keeps_surface``, the limb lies on the ball's own convex cap
    and is kept, the mask exactly the disc (the default since stop 61, docs/small61.md). Off, or no depth given: the
    colour's trim."""
    color, depth, d2 = shaded_ball()
    labels = (d2 <= 400).astype(np.int32)
    limb = (labels == 1) & (np.mgrid[:120, :160][0] >= 76)
    colour_only = trim_labels(color, labels)
    assert (colour_only[limb] == 0).sum() >= 0.5 * limb.sum()
    assert trim_labels(color, labels, KEEPS, depth=depth, focal=600.0) is labels
    assert trim_labels(color, labels, depth=depth, focal=600.0) is labels  # the default
    assert np.array_equal(trim_labels(color, labels, KEEPS), colour_only)
    off = ExtractSettings(trim_keeps_surface=False)
    assert np.array_equal(trim_labels(color, labels, off, depth=depth, focal=600.0), colour_only)


def test_the_colour_trim_still_takes_an_overshoot_onto_the_background_or_a_support_at_the_fruits_depth():
    """The same ball under a mask 3 px too wide all round: above and beside it the background 1 m away (far behind
    its rim), below it a board at its depth turning back towards the camera (the convex cap stops at the crease).
    The colour takes them off with the depth given as without: a cut all round is an overshoot's, and the cap keeps
    none of it (stop 58, :func:`one_sided`)."""
    color, depth, d2 = shaded_ball(board=True)
    labels = (d2 <= 23**2).astype(np.int32)
    kept = trim_labels(color, labels, KEEPS, depth=depth, focal=600.0)
    assert np.array_equal(kept, trim_labels(color, labels))
    assert not (kept == 1)[(d2 > 400) & (depth > 0.9)].any()  # the background
    assert not (kept == 1)[81:].any()  # the board


# --- stop 58, trim58: the fruit's cap keeps pixels of a one-sided cut alone


def test_one_sided_tells_a_cut_on_one_side_from_one_all_round():
    """Known answers on a disc of 20 px: its lowest 5 rows, or its lower half, take less than two thirds of its
    outline pixels; a ring 3 px wide all round, or all but its top 5 rows, take more."""
    yy, xx = np.mgrid[:60, :60]
    d2 = (xx - 30) ** 2 + (yy - 30) ** 2
    mask = d2 <= 400
    assert one_sided(mask, mask & (yy >= 46))
    assert one_sided(mask, mask & (yy > 30))
    assert not one_sided(mask, mask & (d2 > 17**2))
    assert not one_sided(mask, mask & (yy >= 15))
    with pytest.raises(InputError, match="one_sided: mask and cut must be 2-D images of one shape"):
        one_sided(mask, mask[:, :-1])


@given(st.integers(3, 25), st.integers(0, 50))
def test_one_sided_no_cut_is_one_sided_and_the_whole_mask_is_not(radius, row):
    """Any disc: no cut is one-sided, the whole mask is all round, and cutting more rows from the bottom up never
    turns a cut that lies all round back to one side."""
    yy, xx = np.mgrid[:56, :56]
    mask = (xx - 28) ** 2 + (yy - 28) ** 2 <= radius**2
    assert one_sided(mask, np.zeros_like(mask)) and not one_sided(mask, mask)
    if not one_sided(mask, mask & (yy >= row)):
        assert not one_sided(mask, mask & (yy >= row - 1))


def test_the_fruits_cap_keeps_none_of_an_overshoot_all_round_where_the_depth_sits_below_the_colour():
    """Stop 58 (docs/trim58.md): the depth 3 px low against the colour (the ball's cap runs 3 px past its colour edge
    at the bottom, as the real frames' larger spheres' 5-11 px), the mask 3 px too wide all round. The colour cuts
    the overshoot all round; the cap under its lowest rows is the ball's depth, but keeps none of them: the trim is
    the colour's, the disc. (Stop 57's rule kept those rows.) Drawn right, the ball's shaded limb is kept as before."""
    color, depth, d2 = shaded_ball()
    low = np.roll(depth, 3, axis=0)  # the background is 1 m everywhere: rolled rows are the same
    labels = (d2 <= 23**2).astype(np.int32)
    kept = trim_labels(color, labels, KEEPS, depth=low, focal=600.0)
    assert own_cap(low, labels == 1, 600.0)[81:84].any()  # the overshoot's bottom rows lie on the cap
    assert np.array_equal(kept, trim_labels(color, labels))
    assert not (kept == 1)[d2 > 400].any()
    drawn = (d2 <= 400).astype(np.int32)
    assert trim_labels(color, drawn, KEEPS, depth=low, focal=600.0) is drawn


# --- stop 61, small61: the cap keeps its pixels after the registration (keep_caps)


@pytest.mark.parametrize("shift", [(0, 0), (2, 3), (-3, -1)])
def test_keep_caps_gives_back_the_limb_where_the_registration_puts_it(shift):
    """Known answer: the shaded ball's limb, which the colour takes (a one-sided cut), lies on its own convex cap in
    the depth ``shift`` pixels off the colour; the colour-trimmed mask moved by ``shift`` gets it back, the moved
    mask exactly the disc as drawn, moved. Off (``trim_keeps_surface`` false) or no mask cut: the moved masks
    themselves. The depth read unmoved (the cap a few pixels off the limb) gives back fewer pixels than the limb."""
    color, depth, d2 = shaded_ball()
    du, dv = shift
    moved_depth = np.roll(depth, (dv, du), axis=(0, 1))  # the background is 1 m everywhere: rolled rows the same
    drawn = (d2 <= 400).astype(np.int32)
    trimmed = trim_labels(color, drawn)
    assert (trimmed == 0).sum() > (drawn == 0).sum()  # the colour took the limb
    moved = shift_labels(trimmed, du, dv)
    boxes = [(slice(40, 81), slice(60, 101))]
    kept = keep_caps(drawn, trimmed, moved, {1}, boxes, shift, moved_depth, 600.0, KEEPS)
    assert np.array_equal(kept, shift_labels(drawn, du, dv))
    off = ExtractSettings(trim_keeps_surface=False)
    assert keep_caps(drawn, trimmed, moved, {1}, boxes, shift, moved_depth, 600.0, off) is moved
    whole = shift_labels(drawn, du, dv)
    assert keep_caps(drawn, drawn, whole, {1}, boxes, shift, moved_depth, 600.0, KEEPS) is whole
    if shift != (0, 0):
        unmoved = keep_caps(drawn, trimmed, moved, {1}, boxes, shift, depth, 600.0, KEEPS)
        assert (unmoved > 0).sum() < (kept > 0).sum()


@pytest.mark.parametrize("board", [True, False])
def test_keep_caps_gives_back_nothing_of_an_overshoot_all_round(board):
    """The ball under a mask 3 px too wide all round (over the board at its depth, or the background): the colour
    cuts all round, the overshoot and the shaded limb. Nothing of the overshoot comes back, though the board's first
    row lies on the cap; of the limb, which the colour cuts deeper than the overshoot's 3 px (stop 62,
    docs/grown62.md), what lies deeper does. Without the limb's depth, the moved masks themselves."""
    color, depth, d2 = shaded_ball(board=board)
    drawn = (d2 <= 23**2).astype(np.int32)
    trimmed = trim_labels(color, drawn)
    boxes = [(slice(37, 84), slice(57, 104))]
    disc, limb = d2 <= 400, (d2 <= 400) & (np.mgrid[:120, :160][0] >= 76)
    kept = keep_caps(drawn, trimmed, trimmed, {1}, boxes, (0, 0), depth, 600.0, KEEPS)
    back = (kept == 1) & (trimmed != 1)
    assert not (kept == 1)[~disc].any()  # none of the overshoot
    assert back.any() and not back[~limb].any() and back.sum() >= 0.6 * (limb & (trimmed != 1)).sum()
    lost = np.where(limb, 0.0, depth)
    assert keep_caps(drawn, trimmed, trimmed, {1}, boxes, (0, 0), lost, 600.0, KEEPS) is trimmed


def test_star_shaped_is_a_whole_round_outline_and_not_one_cut_along_a_leaf():
    """Known answers: a disc and its lower half are star-shaped about their centroids; the disc with a strip 6 px wide
    cut across it (a mask cut along a leaf in front) is not; an empty mask is not."""
    yy, xx = np.mgrid[:60, :60]
    disc = (xx - 30) ** 2 + (yy - 30) ** 2 <= 23**2
    assert star_shaped(disc) and star_shaped(disc & (yy > 30))
    assert not star_shaped(disc & ~((yy >= 28) & (yy < 34)))
    assert not star_shaped(np.zeros_like(disc))


def test_beyond_even_cut_is_what_the_cut_takes_deeper_than_along_most_of_the_outline():
    """Known answers on a disc of 23 px: a ring 3 px wide all round leaves nothing beyond it; the same ring and the
    disc's lowest 8 rows leave those rows' pixels more than the ring's 3 px (and its outline pixel) inside the mask;
    no cut, or the whole mask, none. Bad arguments are refused by name."""
    yy, xx = np.mgrid[:60, :60]
    d2 = (xx - 30) ** 2 + (yy - 30) ** 2
    mask = d2 <= 23**2
    ring = mask & (d2 > 20**2)
    assert not beyond_even_cut(mask, ring).any()
    cut = ring | (mask & (yy >= 46))
    deeper = beyond_even_cut(mask, cut)
    dist = ndimage.distance_transform_edt(np.pad(mask, 1))[1:-1, 1:-1]
    assert deeper.any() and not deeper[yy < 46].any() and np.array_equal(deeper, cut & (yy >= 46) & (dist > 4))
    assert not beyond_even_cut(mask, np.zeros_like(mask)).any() and not beyond_even_cut(mask, mask).any()
    with pytest.raises(InputError, match="beyond_even_cut: mask and cut must be 2-D images of one shape"):
        beyond_even_cut(mask, mask[:, :-1])
    strip = (yy >= 28) & (yy < 34)  # the mask cut along a leaf in front: its outline there lies inside the fruit
    assert not beyond_even_cut(mask & ~strip, cut & ~strip).any()


def test_keep_caps_does_not_read_the_cap_where_the_cut_holds_no_depth(monkeypatch):
    """The limb the colour takes lies where the camera returned no depth (a time-of-flight camera's lost rim): the
    cap is not read (it holds depth alone, so it could give nothing back) and the moved masks come back themselves;
    with the limb's depth there, it is read and gives the limb back."""
    import symfruit.extract as extract_module

    color, depth, d2 = shaded_ball()
    drawn = (d2 <= 400).astype(np.int32)
    trimmed = trim_labels(color, drawn)
    boxes = [(slice(40, 81), slice(60, 101))]
    calls = []
    read = extract_module.own_cap
    monkeypatch.setattr(extract_module, "own_cap", lambda *a, **k: calls.append(1) or read(*a, **k))
    lost = np.where((drawn == 1) & (trimmed == 0), 0.0, depth)  # no depth where the colour cut
    assert keep_caps(drawn, trimmed, trimmed, {1}, boxes, (0, 0), lost, 600.0, KEEPS) is trimmed and not calls
    assert np.array_equal(keep_caps(drawn, trimmed, trimmed, {1}, boxes, (0, 0), depth, 600.0, KEEPS), drawn)
    assert calls == [1]


def test_keep_caps_does_not_read_the_cap_where_another_mask_holds_the_cut(monkeypatch):
    """Stop 62 (cap62): the limb the colour takes lies where a neighbour's mask (moved onto the depth) holds every
    pixel of it, or where its depth lies beyond the extraction's range: the cap could give none of it back, and it is
    not read; the moved masks come back themselves."""
    import symfruit.extract as extract_module

    color, depth, d2 = shaded_ball()
    drawn = (d2 <= 400).astype(np.int32)
    trimmed = trim_labels(color, drawn)
    cut = (drawn == 1) & (trimmed == 0)
    boxes = [(slice(40, 81), slice(60, 101))]
    calls = []
    read = extract_module.own_cap
    monkeypatch.setattr(extract_module, "own_cap", lambda *a, **k: calls.append(1) or read(*a, **k))
    held = np.where(cut, 2, trimmed).astype(np.int32)  # a neighbour's mask over the limb
    assert keep_caps(drawn, trimmed, held, {1}, boxes, (0, 0), depth, 600.0, KEEPS) is held and not calls
    far = np.where(cut, 20.0, depth)  # beyond max_depth (10 m)
    assert keep_caps(drawn, trimmed, trimmed, {1}, boxes, (0, 0), far, 600.0, KEEPS) is trimmed and not calls
    partly = np.where(cut & (np.mgrid[:120, :160][1] < 80), 2, trimmed).astype(np.int32)  # half of it held
    kept = keep_caps(drawn, trimmed, partly, {1}, boxes, (0, 0), depth, 600.0, KEEPS)
    assert calls == [1] and np.array_equal(kept, np.where(partly == 2, 2, drawn))


@given(st.integers(1, 12), st.integers(1, 12), st.floats(0.0, 1.0), st.integers(0, 2**32 - 1))
def test_the_outline_is_the_distance_maps_first_pixel(h, w, share, seed):
    """``_outline`` (four shifted views) is ``mask & (inner_distance(mask, 2.0) <= 1.0)``, the pixels within one of
    another in the array, on any mask (empty, full, ragged): the same pixels, so :func:`one_sided` answers as
    before."""
    from symfruit.core.raster import inner_distance
    from symfruit.extract import _outline

    mask = np.random.default_rng(seed).random((h, w)) < share
    assert np.array_equal(_outline(mask), mask & (inner_distance(mask, 2.0) <= 1.0))
    assert np.array_equal(_outline(np.ones((h, w), bool)), inner_distance(np.ones((h, w), bool), 2.0) <= 1.0)


@given(st.integers(0, 2**32 - 1))
def test_own_cap_with_the_kernels_is_the_twins(seed):
    """``own_cap``'s depth made valid by the extraction's kernel (stop 62) or by numpy (the twin), on depth with
    holes, NaN, infinities, negative values and depths beyond the range: the same pixels."""
    rng = np.random.default_rng(seed)
    _, depth, d2 = shaded_ball(board=bool(rng.random() < 0.5))
    depth = depth.astype(np.float64 if rng.random() < 0.5 else np.float32)
    bad = rng.random(depth.shape) < rng.uniform(0.0, 0.3)
    depth[bad] = rng.choice([0.0, -0.0, -0.3, np.nan, np.inf, -np.inf, 11.0, 5e-324], bad.sum())
    mask = d2 <= float(rng.uniform(15.0, 24.0)) ** 2
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv("SYMFRUIT_KERNELS", raising=False)
        fast = own_cap(depth, mask, 600.0)
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        twin = own_cap(depth, mask, 600.0)
    assert np.array_equal(fast, twin)


def test_own_cap_is_the_fruits_convex_cap_no_deeper_than_its_rim():
    """Known answer: the ball's pixels (every one has depth up to its rim) and none of the background's, under a mask
    grown 3 px onto them; of the board that turns back towards the camera 4 mm a row below the crease, its first row
    alone (the ball's lowest pixels lie within 2 mm of its rim's depth, and the cap may fall 3 mm); no depth: none."""
    _, depth, d2 = shaded_ball(board=True)
    mask = d2 <= 23**2
    cap = own_cap(depth, mask, 600.0)
    assert np.array_equal(cap[:81], (d2 <= 400)[:81]) and not cap[82:].any()
    assert 0 < cap[81].sum() <= 15
    assert not own_cap(np.zeros_like(depth), mask, 600.0).any()


def test_the_trims_depth_is_checked_by_name():
    color, depth, d2 = shaded_ball()
    labels = (d2 <= 400).astype(np.int32)
    with pytest.raises(InputError, match="trim_labels: depth must be float metres of the masks' shape"):
        trim_labels(color, labels, KEEPS, depth=depth[:, :-1], focal=600.0)
    with pytest.raises(InputError, match="trim_labels: focal must be a positive number"):
        trim_labels(color, labels, KEEPS, depth=depth, focal=0.0)
    with pytest.raises(InputError, match="own_cap: depth must be float metres"):
        own_cap((depth * 1000).astype(np.uint16), labels == 1, 600.0)


# --- strip64: the colour trim's ring leaves out an occluder crossing the fruit (extract.trim_front_ring)


FRONT = ExtractSettings(trim_front_ring=True)


def strip_ball(strip_z: float | None = 0.25, board: bool = False):
    """``(color, depth, labels, strip, edge)`` seen by :data:`SMALL_CAM`: a white ball of 30 px at (80, 60), its front
    0.3 m, lit from the front (its limb 30 % darker), before a dark background 1 m away; across its middle a strip
    9 px tall at ``strip_z`` (None: no strip) that reaches 7 px past it on both sides, its edge (2 px either side)
    without depth, and shows in the colour image what lies behind it (the ball: docs/realpert55.py's unpainted
    strip, the ring beside the cut edges of the ball's own colour); the mask the ball less the strip (two halves).
    ``board``: below the ball a board 6 mm nearer a row (a support seen obliquely, nearer than the ball's front from
    its 5th row on)."""
    color, depth = disc_frame([(80, 60)], radius=30, z=0.3)
    yy, xx = np.mgrid[:120, :160]
    d2 = (xx - 80) ** 2 + (yy - 60) ** 2
    inside = d2 <= 900
    c = np.full(color.shape, 60.0)
    c[inside] = 220.0 * (0.7 + 0.3 * np.sqrt(np.clip(1 - d2 / 900, 0, None)))[inside][:, None]
    strip = (np.abs(yy - 60) <= 4) & (np.abs(xx - 80) <= 37) & (strip_z is not None)
    edge = ndimage.binary_dilation(strip, iterations=2) & ~ndimage.binary_erosion(strip, iterations=2)
    rng = np.random.default_rng(0)
    color = np.clip(c + 4 * rng.standard_normal(c.shape), 0, 255).astype(np.uint8)
    if strip_z is not None:
        depth[strip], depth[edge] = strip_z, 0.0
    if board:
        depth[91:] = (0.33 - 0.006 * (yy[91:] - 90)).astype(np.float32)
    return color, depth, (inside & ~strip).astype(np.int32), strip, edge


def test_front_ring_is_the_strip_between_the_masks_halves_and_its_lost_edge():
    """Known answers: outside the mask and within its convex hull, the strip 5 cm in front and the pixels without
    depth within 4 px of it; not the strip's ends beyond the ball (outside the hull), not the background, not the
    ball; in a mask drawn over the strip, the strip's pixels and those without depth beside them; nothing
    when the strip lies behind the ball's front, nor for a board below the ball that comes nearer (outside the
    hull)."""
    from symfruit.segment.colour import convex_hull_mask

    _, depth, labels, strip, edge = strip_ball()
    mask = labels == 1
    ring = front_ring(depth, mask, 600.0)
    assert np.array_equal(ring & ~edge, strip & ~edge & convex_hull_mask(mask) & ~mask)
    assert (ring & edge).any() and not ring[:, :45].any() and not ring[:, 116:].any()
    assert not (ring & mask).any()  # none of the mask's pixels lie in front: the ball's own, or lost beside the strip
    # the halves drawn 3 px over the strip: their pixels on it, with depth in front, and none of the ball's
    yy = np.mgrid[:120, :160][0]
    over = mask | (strip & convex_hull_mask(mask) & (np.abs(yy - 60) >= 2))
    ring, on = front_ring(depth, over, 600.0), over & strip & (depth > 0)
    assert on.any() and np.array_equal(ring & on, on) and not (ring & over & (depth > 0) & ~strip).any()
    assert not front_ring(strip_ball(strip_z=0.32)[1], mask, 600.0).any()  # behind the ball's front
    _, depth, labels, *_ = strip_ball(strip_z=None, board=True)
    assert (depth[100:] < 0.29).all() and not front_ring(depth, labels == 1, 600.0).any()


def test_the_colour_trim_does_not_read_an_occluder_of_the_fruits_colour_as_its_surroundings():
    """Strip64 (docs/strip58.md cause 1): the ring beside the cut edges lies on the strip, which shows the ball's
    white; at the band the two summaries do not separate, at twice it they do, and the colour alone takes the
    halves' band all round (996 of 2,288 px; the ball uncut: none). Given the depth
    (``front_depth``) with ``trim_front_ring`` (the default since stripb64), the strip is left out of the ring and the
    mask is kept as drawn; off, the colour's trim."""
    color, depth, labels, *_ = strip_ball()
    colour_only = trim_labels(color, labels)
    assert (labels == 1).sum() - (colour_only == 1).sum() >= 900
    assert trim_labels(color, labels, FRONT, front_depth=depth, focal=600.0) is labels
    assert trim_labels(color, labels, front_depth=depth, focal=600.0) is labels  # the default
    off = ExtractSettings(trim_front_ring=False)
    assert np.array_equal(trim_labels(color, labels, off, front_depth=depth, focal=600.0), colour_only)
    whole_color, _, whole, *_ = strip_ball(strip_z=None)
    assert trim_labels(whole_color, whole) is whole


def test_the_ring_without_the_occluder_only_gives_back_what_the_colour_took():
    """A trim the colour alone leaves undone is not made with the occluder left out of the ring: under a mask drawn
    3 px over the background all round and cut by the strip, the colour's summaries do not separate at any band and
    the mask stays as drawn; the ring without the strip would separate and take the overshoot (534 px, down to the
    ball's halves), but it only gives back (a support or neighbour read as in front must not start a trim)."""
    from symfruit.core.surface import colour_trim

    color, depth, _, strip, _ = strip_ball()
    yy, xx = np.mgrid[:120, :160]
    grown = (((xx - 80) ** 2 + (yy - 60) ** 2) <= 33**2) & ~strip
    labels = grown.astype(np.int32)
    alone = colour_trim(color, grown, band_px=4.0, wider=(8.0, 12.0), exclude=front_ring(depth, grown, 600.0))
    assert (grown & ~alone).sum() >= 500
    assert trim_labels(color, labels) is labels
    assert trim_labels(color, labels, FRONT, front_depth=depth, focal=600.0) is labels


def test_the_ring_without_the_occluder_gives_back_only_where_it_finds_the_mask_tight():
    """Stripb64 (docs/strip64.md section 6): the colour took the band all round, and the ring without the strip
    takes some of the mask itself (an overshoot: the halves drawn 2 px over the background all round, 352 px). The
    mask overshoots, and the colour's wider cut (1,199 px, 847 of them the ball's limb) stands as the colour alone
    made it, as off: an overshoot the strip hid from the band is as likely wider than the band finds (the rendered
    apple trees: a mask 4 px over its apple, the ring's band taking 2-3 px of it). Where the ring takes nothing (the
    halves drawn tight, the test above), the colour's cut came from the strip alone and is given back."""
    color, depth, _, strip, _ = strip_ball()
    yy, xx = np.mgrid[:120, :160]
    ball = ((xx - 80) ** 2 + (yy - 60) ** 2) <= 900
    grown = (((xx - 80) ** 2 + (yy - 60) ** 2) <= 32**2) & ~strip
    labels = grown.astype(np.int32)
    colour_only = trim_labels(color, labels) == 1
    assert (grown & ~colour_only).sum() == 1199 and (ball & grown & ~colour_only).sum() == 847
    from symfruit.core.surface import colour_trim

    ring = colour_trim(color, grown, band_px=4.0, wider=(8.0, 12.0), exclude=front_ring(depth, grown, 600.0))
    assert np.array_equal(grown & ~ring, grown & ~ball)  # the ring alone finds the overshoot, 352 px
    assert np.array_equal(trim_labels(color, labels, FRONT, front_depth=depth, focal=600.0) == 1, colour_only)


# --- front64: the front ring's fruit surface and the trim done again, worked out once


def _front_ring_before(depth, mask, focal):
    """front_ring as stop 64 (stripb64) wrote it: the fruit's whole surface read wherever something outside the mask
    within its hull lies nearer than its farthest depth less 3 mm (the reference for front64's)."""
    from symfruit.core.surface import _FREE_PX, _free_tol, fruit_surface, within
    from symfruit.segment.colour import convex_hull_mask

    s = ExtractSettings()
    z = np.asarray(depth, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(z) & (z >= s.min_depth) & (z <= s.max_depth) & (z > 0)
        lost = ~(z > 0)
    out = np.zeros(mask.shape, bool)
    seen = z[mask & valid]
    if not seen.size:
        return out
    ahead = ~mask & valid & (z < float(seen.max()) - 0.003) & convex_hull_mask(mask)
    if not ahead.any():
        return out
    zv = np.where(valid, z, 0.0)
    surface = fruit_surface(zv, mask, focal, slab=s.slab, tolerance=s.convex_tolerance, thin=True, clean=True)
    if surface is None:
        return out
    nearer = valid & (zv < surface.front - _free_tol(surface))
    ahead &= nearer
    if not ahead.any():
        return out
    out = ahead | (lost & ~mask & within(ahead, _FREE_PX))
    if (on := nearer & mask).any():
        out |= on | (lost & mask & within(on, _FREE_PX))
    return out


def _front_case(seed):
    """A random :func:`strip_ball` (the strip mostly 5 cm in front of the ball's front, else in front of, at, or
    behind it, or none; a board below half the time), its depth noisy, the mask the ball's halves grown or shrunk a
    few pixels or as they are (the strip's pixels drawn into it a fifth of the time)."""
    rng = np.random.default_rng(seed)
    strip_z = None if rng.random() < 0.1 else float(rng.uniform(0.22, 0.34) if rng.random() < 0.3 else 0.25)
    color, depth, _, strip, _ = strip_ball(strip_z=strip_z, board=bool(rng.random() < 0.5))
    depth = np.where(depth > 0, depth + rng.normal(scale=float(rng.uniform(0.0, 0.002)), size=depth.shape), 0.0)
    yy, xx = np.mgrid[:120, :160]
    r = 30.0 if rng.random() < 0.5 else float(rng.uniform(27.0, 33.0))  # the ball's own outline half the time
    mask = ((xx - 80) ** 2 + (yy - 60) ** 2) <= r * r
    if rng.random() >= 0.2:
        mask &= ~strip
    return color, depth.astype(np.float32), mask


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_front_ring_is_the_one_read_on_the_whole_fruit_surface_s(seed):
    """Front64: the fruit's slab and cap are worked out only where something ahead lies in front of its front (the
    ring is otherwise empty): the same ring as with the whole surface read first, with the kernels and their
    twins."""
    _, depth, mask = _front_case(seed)
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv("SYMFRUIT_KERNELS", raising=False)
        for kernels in ("compiled", "numpy"):
            if kernels == "numpy":
                mp.setenv("SYMFRUIT_KERNELS", "numpy")
            assert np.array_equal(front_ring(depth, mask, 600.0), _front_ring_before(depth, mask, 600.0))


def test_the_front_ring_reads_no_fruit_surface_where_nothing_lies_ahead_of_its_front(monkeypatch):
    """Known answers: a strip 2 cm behind the ball's front (nearer than its farthest depth) leaves the ring empty
    without the fruit's slab and cap (the compiled cap or its twin's apex never reached); a strip in front, one
    surface worked out to the end."""
    import symfruit.core.surface as surface

    reached = []
    for name in ("_surface_compiled", "_surface"):
        real = getattr(surface, name)
        monkeypatch.setattr(surface, name, lambda *a, _real=real, **k: reached.append(1) or _real(*a, **k))
    _, depth, labels, *_ = strip_ball(strip_z=0.32)
    assert not front_ring(depth, labels == 1, 600.0).any() and not reached
    _, depth, labels, *_ = strip_ball()
    assert front_ring(depth, labels == 1, 600.0).any() and len(reached) == 1


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_trim_done_again_given_the_colours_own_trim_is_the_one_worked_out_s(seed):
    """Front64: :func:`trim_mask` given ``kept`` (what the colour alone kept of the mask: the mask less its own cut)
    drops the same pixels as working the colour's trim out again, with the front ring read or given; a ``kept``
    that keeps the whole mask is read (the colour took nothing: nothing is dropped)."""
    color, depth, mask = _front_case(seed)
    labels = mask.astype(np.int32)
    s = ExtractSettings()
    sl = ndimage.find_objects(labels)[0]
    r0, r1, c0, c1 = trim_window(labels.shape, sl, s)
    colour = trim_mask(color, labels, 1, sl, s)
    own = labels[r0:r1, c0:c1] == 1
    kept = own.copy()
    if colour is not None:
        kept[colour[1]] = False
    worked = trim_mask(color, labels, 1, sl, s, focal=600.0, front_depth=depth)
    given_kept = trim_mask(color, labels, 1, sl, s, focal=600.0, front_depth=depth, kept=kept)
    assert (worked is None) == (given_kept is None)
    if worked is not None:
        assert worked[0] == given_kept[0] and np.array_equal(worked[1], given_kept[1])
    assert trim_mask(color, labels, 1, sl, s, focal=600.0, front_depth=depth, kept=own) is None


# --- surf65: own_cap reads the fruit's surface front_ring read on the same drawn mask and depth


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_own_cap_given_the_front_rings_reading_is_its_own_s(seed):
    """A random :func:`_front_case`: the front ring read on a window about the mask (as ``detect._front_trimmed`` reads
    it, ``trim_window``'s), ``own_cap`` on the mask's box (as ``keep_caps`` reads it) given its reading: the same cap as
    without it, with the kernels and their twins; on the box's depth moved back a few millimetres, the reading is not
    taken (the same cap as without it again)."""
    from symfruit.core.raster import mask_box
    from symfruit.extract import trim_window

    _, depth, mask = _front_case(seed)
    rng = np.random.default_rng(seed)
    labels = mask.astype(np.int32)
    box = mask_box(mask)
    if box is None:
        return
    r0, r1, c0, c1 = trim_window(labels.shape, (slice(box[0], box[1]), slice(box[2], box[3])), FRONT)
    a0, a1, b0, b1 = box
    changed = depth.copy()
    changed[a0:a1, b0:b1] += np.float32(rng.uniform(0.005, 0.03)) * (changed[a0:a1, b0:b1] > 0)  # moved back
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv("SYMFRUIT_KERNELS", raising=False)
        for kernels in ("compiled", "numpy"):
            if kernels == "numpy":
                mp.setenv("SYMFRUIT_KERNELS", "numpy")
            read: list = []
            front_ring(depth[r0:r1, c0:c1], mask[r0:r1, c0:c1], 600.0, FRONT, read=read)
            known = read[0] if read else None
            for z in (depth, changed):
                alone = own_cap(z[a0:a1, b0:b1], mask[a0:a1, b0:b1], 600.0, FRONT)
                given_known = own_cap(z[a0:a1, b0:b1], mask[a0:a1, b0:b1], 600.0, FRONT, known=known)
                assert np.array_equal(alone, given_known)
