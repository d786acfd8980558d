"""The frame-wide edge cue of depth-to-colour registration: a scene of boxes and a disc before a wall, colour with
texture of its own, depth moved by a known shift and its objects' outermost pixels lost (a time-of-flight band)."""

import numpy as np
import pytest

from symfruit.core.edges import (
    EDGE_REACH,
    N_BINS,
    _colour_gradient,
    _colour_peaks,
    _mask_costs,
    _moved_costs,
    _shift_costs,
    colour_edges,
    depth_outline,
    edge_shift,
    mask_shift,
)

H, W = 240, 320


def scene(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Depth (metres) and an object id per pixel: a wall at 2 m, two boxes and a disc at 1-1.3 m."""
    vv, uu = np.mgrid[:H, :W]
    ids = np.zeros((H, W), np.int32)
    ids[60:180, 40:120] = 1
    ids[30:110, 190:290] = 2
    ids[np.hypot(uu - 230, vv - 180) < 35] = 3
    depth = np.choose(ids, [2.0, 1.0, 1.3, 1.15]) + rng.normal(0, 0.001, (H, W))
    return depth, ids


def colour(ids: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Each object its own grey, a checkerboard printed on the wall (texture, no depth edge), noise."""
    vv, uu = np.mgrid[:H, :W]
    grey = np.choose(ids, [120.0, 60.0, 180.0, 90.0])
    board = ((uu // 12 + vv // 12) % 2 == 0) & (ids == 0) & (uu < 160) & (vv > 150)
    grey = grey + 40.0 * board + rng.normal(0, 2.0, (H, W))
    return np.clip(np.repeat(grey[..., None], 3, axis=2), 0, 255).astype(np.uint8)


def registered(depth: np.ndarray, ids: np.ndarray, du: int, dv: int, band: int) -> np.ndarray:
    """Depth as the colour camera's pixels get it: what colour pixel (u, v) sees lands at depth pixel
    (u + du, v + dv); every object loses its outermost ``band`` pixels (invalid), and no depth outside a
    field of view 8 px inside the image."""
    from scipy import ndimage

    out = depth.copy()
    objects = ids > 0
    rim = objects & ~ndimage.binary_erosion(objects, iterations=band) if band else np.zeros_like(objects)
    out[rim] = 0.0
    moved = np.zeros_like(out)
    moved[max(dv, 0) : H + min(dv, 0), max(du, 0) : W + min(du, 0)] = out[
        max(-dv, 0) : H - max(dv, 0), max(-du, 0) : W - max(du, 0)
    ]
    moved[:8], moved[-8:], moved[:, :8], moved[:, -8:] = 0.0, 0.0, 0.0, 0.0
    return moved


@pytest.mark.parametrize("shift", [(0, 0), (5, -3), (-7, 6)])
def test_the_sides_find_a_known_shift_with_the_band_cancelled(shift):
    rng = np.random.default_rng(3)
    depth, ids = scene(rng)
    found = edge_shift(registered(depth, ids, *shift, band=2), colour(ids, rng), max_px=12)
    assert found.balanced == (float(shift[0]), float(shift[1]))
    assert found.band == 2.0  # left and right outlines each sit 2 px inside their object
    # a side alone says the shift plus or minus the band, to the pixel on which the colour edge is marked
    assert abs(found.sides["top"][0] - (shift[1] + 2)) <= 1 and abs(found.sides["bottom"][0] - (shift[1] - 2)) <= 1
    assert found.sides["left"][0] - found.sides["right"][0] == 4
    assert all(rise > 0.3 for _, _, rise in found.sides.values())  # sharp: 2 px off costs a third of a pixel


def test_without_a_band_the_whole_frame_optimum_is_the_shift():
    rng = np.random.default_rng(4)
    depth, ids = scene(rng)
    found = edge_shift(registered(depth, ids, 4, 3, band=0), colour(ids, rng), max_px=12)
    assert found.shift == (4, 3) and found.band == 0.0 and min(found.rise) > 0.3
    assert found.cost.shape == (25, 25) and found.cost[3 + 12, 4 + 12] == found.cost.min()


def test_the_outline_is_the_near_side_only():
    rng = np.random.default_rng(5)
    depth, ids = scene(rng)
    z = registered(depth, ids, 0, 0, band=3)
    outline, gx, gy = depth_outline(z)
    # box 1 (rows 60-179, columns 40-119) lost 3 px: its outline is the first valid pixel inside
    assert outline[120, 43] and outline[120, 116] and outline[63, 80] and outline[176, 80]
    assert gx[120, 43] < 0 < gx[120, 116] and gy[63, 80] < 0 < gy[176, 80]  # normals point to the background
    # the wall beside the band (its far side) and along the field of view's edge is no outline
    assert not outline[120, 39] and not outline[120, 121] and not outline[120, 8] and not outline[8, 60]
    assert not outline[ids == 0].any()


def test_a_surface_continuing_across_an_invalid_band_is_no_outline():
    # a dark stripe across the wall (no depth) between two parts of one surface: no farther surface beyond it
    z = np.full((H, W), 2.0) + np.linspace(0, 0.05, H)[:, None]
    z[100:110] = 0.0
    assert not depth_outline(z)[0].any()


def test_texture_alone_gives_colour_edges_the_depth_lacks_and_they_are_tolerated():
    rng = np.random.default_rng(6)
    depth, ids = scene(rng)
    image = colour(ids, rng)
    edges, _ = colour_edges(image)
    assert edges[150:, :150][(ids[150:, :150] == 0)].sum() > 300  # the printed board's edges
    found = edge_shift(registered(depth, ids, -3, 2, band=1), image, max_px=12)
    du, dv = found.balanced
    assert abs(du + 3.0) <= 0.5 and abs(dv - 2.0) <= 0.5  # an odd band: half a pixel, the colour edge's marked pixel


def test_a_frame_without_outlines_says_nothing_and_sizes_must_agree():
    flat = np.full((H, W), 1.5)
    found = edge_shift(flat, np.zeros((H, W, 3), np.uint8), max_px=4)
    assert found.n_outline == 0 and found.balanced == (None, None) and found.band is None
    with pytest.raises(ValueError, match=r"depth \(240, 320\) and colour \(10, 10\) differ in size"):
        edge_shift(flat, np.zeros((10, 10, 3), np.uint8))


def moved(ids: np.ndarray, du: int, dv: int) -> np.ndarray:
    """``ids`` moved by ``(du, dv)`` pixels (0 enters)."""
    out = np.zeros_like(ids)
    out[max(dv, 0) : H + min(dv, 0), max(du, 0) : W + min(du, 0)] = ids[
        max(-dv, 0) : H - max(dv, 0), max(-du, 0) : W - max(du, 0)
    ]
    return out


@pytest.mark.parametrize("shift", [(0, 0), (0, -5), (0, 5), (4, 0), (-3, 4), (8, -7)])
def test_masks_drawn_off_their_objects_are_moved_back_onto_the_colours_edges(shift):
    rng = np.random.default_rng(5)
    _, ids = scene(rng)
    color = colour(ids, rng)
    drawn = moved(ids, *shift)  # the masks drawn `shift` off the objects the colour shows
    assert mask_shift(color, drawn, max_px=10) == (-shift[0], -shift[1])


@pytest.mark.parametrize(("shift", "found"), [((1, 0), (0, 0)), ((0, -1), (0, 0)), ((1, -1), (0, 0)), ((2, 0), (-2, 0)),
                                              ((0, -2), (0, 2)), ((2, 1), (-2, 0))])  # fmt: skip
def test_a_move_under_two_pixels_is_not_told(shift, found):
    """The two sides' mean is told to about a pixel: masks a pixel off stay, two pixels off are moved back."""
    rng = np.random.default_rng(5)
    _, ids = scene(rng)
    assert mask_shift(colour(ids, rng), moved(ids, *shift), max_px=10) == found


def test_one_small_mask_alone_is_not_moved():
    """A side needs MIN_SIDE_PX outline pixels: the disc alone (70 px across, about 30 a side) is not moved by
    default, though its sides do find the shift at the lower floor of stop 61."""
    rng = np.random.default_rng(5)
    _, ids = scene(rng)
    color = colour(ids, rng)
    disc = np.where(ids == 3, 3, 0)
    assert mask_shift(color, moved(disc, 0, -5), max_px=10) == (0, 0)
    assert mask_shift(color, moved(disc, 0, -5), max_px=10, min_side=20) == (0, 5)


@pytest.mark.parametrize("grow", [2, 5])
def test_generous_masks_are_not_moved(grow):
    """A mask grown all round pulls its opposite sides apart (the top up, the bottom down): no axis agrees."""
    from scipy import ndimage

    rng = np.random.default_rng(6)
    _, ids = scene(rng)
    color = colour(ids, rng)
    grown = np.zeros_like(ids)
    for k in (1, 2, 3):
        grown[ndimage.binary_dilation(ids == k, iterations=grow) & (grown == 0)] = k
    assert mask_shift(color, grown, max_px=10) == (0, 0)


def test_one_side_alone_does_not_move_the_masks():
    """Only the upper half of each object differs from the wall (its lower half shares the wall's grey): the top
    sides lie on edges, the bottom ones on none, and a shift along an axis needs both its sides."""
    rng = np.random.default_rng(7)
    _, ids = scene(rng)
    grey = np.full((H, W), 120.0)
    for k in (1, 2, 3):
        rows, cols = np.nonzero(ids == k)
        upper = rows < rows.mean()
        grey[rows[upper], cols[upper]] = 60.0
    color = np.clip(np.repeat((grey + rng.normal(0, 2.0, (H, W)))[..., None], 3, axis=2), 0, 255).astype(np.uint8)
    assert mask_shift(color, moved(ids, 0, -5), max_px=10) == (0, 0)
    assert mask_shift(color, moved(ids, 4, 0), max_px=10) == (-4, 0)  # left and right both lie on edges (above)


def test_mask_shift_needs_masks_and_colour_of_one_size():
    rng = np.random.default_rng(8)
    _, ids = scene(rng)
    assert mask_shift(colour(ids, rng), np.zeros_like(ids)) == (0, 0)  # no mask: nothing to move
    assert mask_shift(colour(ids, rng), ids, max_px=0) == (0, 0)
    assert mask_shift(colour(ids, rng), np.ones_like(ids)) == (0, 0)  # a mask over the whole image has no outline
    with pytest.raises(ValueError, match="differ in size"):
        mask_shift(colour(ids, rng), ids[:-1])


@pytest.mark.parametrize("reach", [EDGE_REACH, EDGE_REACH - 2])
def test_a_window_grown_by_the_edges_reach_finds_the_whole_images_edges(reach):
    """mask_shift reads each mask's colour edges in its own window: inside the window less ``EDGE_REACH``, the
    window's edges (at one threshold) are the whole image's; two pixels less and some are not."""
    rng = np.random.default_rng(9)
    _, ids = scene(rng)
    color = colour(ids, rng)
    gx, gy, mag = _colour_gradient(color, 1.0)
    threshold = 4.0 * float(np.median(mag))
    assert all(
        np.array_equal(a, b) for a, b in zip(colour_edges(color), _colour_peaks(gx, gy, mag, threshold), strict=True)
    )
    whole, whole_bins = _colour_peaks(gx, gy, mag, threshold)
    r0, r1, c0, c1 = 40, 150, 100, 260
    window = _colour_gradient(color[r0:r1, c0:c1], 1.0)
    part, part_bins = _colour_peaks(*window, threshold)
    inner = (slice(reach, -reach), slice(reach, -reach))
    # the gradient reads 5 px (the Gaussian's 4 sigma and the Sobel's pixel), the peaks one more
    same = np.array_equal(window[2][inner], mag[r0:r1, c0:c1][inner])
    assert same == (reach == EDGE_REACH)
    if same:
        assert np.array_equal(part[inner], whole[r0:r1, c0:c1][inner])
        assert np.array_equal(part_bins[inner][part[inner]], whole_bins[r0:r1, c0:c1][inner][part[inner]])


def test_the_gathered_costs_are_the_shift_loops():
    rng = np.random.default_rng(10)
    dist = rng.uniform(0.0, 6.0, (N_BINS, 30, 40)).astype(np.float32)
    rows, cols = rng.integers(0, 30, 200), rng.integers(0, 40, 200)  # near the borders too: off the map costs the cap
    bins = rng.integers(0, N_BINS, 200)
    assert np.array_equal(_moved_costs(dist, rows, cols, bins, 7, 6.0), _shift_costs(dist, rows, cols, bins, 7, 6.0, 1))


def test_the_masks_costs_read_only_the_masks_windows():
    """Colour farther from every mask than its window (the search, the cap and the edges' reach) changes nothing;
    within a window it does."""
    rng = np.random.default_rng(11)
    _, ids = scene(rng)
    color = colour(ids, rng)
    parts = _mask_costs(color, ids, max_px=10, cap=6.0, max_points=8000)
    assert [k for k, *_ in parts] == [1, 2, 3]
    every = np.concatenate([e for _, e, _, _ in parts], axis=2)

    def costs(image: np.ndarray) -> np.ndarray:
        return np.concatenate([e for _, e, _, _ in _mask_costs(image, ids, max_px=10, cap=6.0, max_points=8000)], 2)

    far = color.copy()  # the windows: the masks' boxes grown by 10 + 6 + EDGE_REACH + 1 = 23 px
    far[:, 145:165] = rng.integers(0, 255, (H, 20, 3))
    far[205:, :170] = rng.integers(0, 255, (H - 205, 170, 3))
    assert np.array_equal(costs(far), every)
    near = color.copy()
    near[181:200, 40:120] = rng.integers(0, 255, (19, 80, 3))  # below box 1, within its window
    assert not np.array_equal(costs(near), every)
