"""The frame-wide edge cue of depth-to-colour registration: a scene of boxes and a disc before a wall, colour with
texture of its own, depth moved by a known shift and its objects' outermost pixels lost (a time-of-flight band)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage

from symfruit.core.edges import (
    EDGE_REACH,
    N_BINS,
    _capped_distances,
    _colour_gradient,
    _colour_peaks,
    _edge_distances,
    _mask_costs,
    _moved_costs,
    _outline_samples,
    _padded_costs,
    _shift_costs,
    _squared_median,
    _squared_peaks,
    _window_gradient,
    _window_peaks,
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


# ``_mask_costs`` as stop 62 first wrote it (commit f199e87): each mask's window's whole colour gradient channel by
# channel, its peaks over the whole window and the distance maps over the whole window. The faster version reads
# the same values at fewer pixels (docs/edgespeed62.md) and must match it to the bit.
def reference_mask_costs(
    color: np.ndarray, labels: np.ndarray, *, max_px: int, cap: float, max_points: int
) -> list[tuple[int, np.ndarray, np.ndarray, np.ndarray]]:
    """The reference of :func:`symfruit.core.edges._mask_costs` (the same arguments, ``boxes`` found here)."""
    img = np.asarray(color)
    lab = np.asarray(labels)
    if img.shape[:2] != lab.shape or lab.ndim != 2:
        raise ValueError(f"colour {img.shape[:2]} and masks {lab.shape} differ in size")
    m = int(max_px)
    if m <= 0:
        return []
    h, w = lab.shape
    found = _outline_samples(lab, max_points)  # the outline's pixels: unchanged by the faster version
    if found is None:
        return []
    parts, ks, rows, cols, gx, gy, bins = found
    pad = m + int(np.ceil(cap)) + EDGE_REACH + 1
    windows, seen, pooled = [], np.zeros((h, w), bool), []
    for k, sl in parts:
        mine = ks == k
        if not mine.any():
            continue
        r0, r1 = max(sl[0].start - pad, 0), min(sl[0].stop + pad, h)
        c0, c1 = max(sl[1].start - pad, 0), min(sl[1].stop + pad, w)
        gradient = _colour_gradient(img[r0:r1, c0:c1], 1.0)
        windows.append((k, mine, r0, c0, gradient))
        pooled.append(gradient[2][~seen[r0:r1, c0:c1]])
        seen[r0:r1, c0:c1] = True
    if not windows:
        return []
    threshold = 4.0 * max(float(np.median(np.concatenate(pooled))), 1e-9)
    costs = []
    for k, mine, r0, c0, gradient in windows:
        edges, ebins = _colour_peaks(*gradient, threshold)
        dist = _edge_distances(edges, ebins, cap, bins[mine])
        costs.append((k, mine, _moved_costs(dist, rows[mine] - r0, cols[mine] - c0, bins[mine], m, cap)))
    return [(k, every, gx[mine], gy[mine]) for k, mine, every in costs]


def same_costs(a: list, b: list) -> bool:
    return len(a) == len(b) and all(
        x[0] == y[0] and all(np.array_equal(u, v) for u, v in zip(x[1:], y[1:], strict=True))
        for x, y in zip(a, b, strict=True)
    )


@st.composite
def drawn_masks(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray, int, float, int]:
    """A random frame: discs and boxes of their own colours on a textured background (noise, stripes, a gradient;
    some touching the image's border, some overlapping), their masks drawn off them by a few pixels, the search,
    the cap and the thinning drawn too; colour images in three channels or one, 8-bit or float."""
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    h, w = draw(st.integers(24, 140)), draw(st.integers(24, 160))
    vv, uu = np.mgrid[:h, :w]
    ids = np.zeros((h, w), np.int32)
    for k in range(1, draw(st.integers(1, 6)) + 1):
        cv, cu, r = rng.uniform(-5, h + 5), rng.uniform(-5, w + 5), rng.uniform(2, 40)
        inside = np.hypot(uu - cu, vv - cv) < r if rng.random() < 0.6 else (abs(uu - cu) < r) & (abs(vv - cv) < 0.7 * r)
        ids[inside] = k
    channels = draw(st.sampled_from([3, 1]))
    base = rng.uniform(0, 255, (8, channels))
    img = base[ids] + rng.normal(0, rng.uniform(0, 20), (h, w, channels))
    img += rng.uniform(0, 60) * ((uu // rng.integers(3, 15)) % 2)[..., None] + rng.uniform(-1, 1) * uu[..., None]
    img = np.clip(img, 0, 255)
    img = img.astype(np.uint8) if draw(st.booleans()) else img
    if channels == 1 and draw(st.booleans()):
        img = img[..., 0]
    du, dv = draw(st.integers(-6, 6)), draw(st.integers(-6, 6))
    masks = np.zeros_like(ids)
    masks[max(dv, 0) : h + min(dv, 0), max(du, 0) : w + min(du, 0)] = ids[
        max(-dv, 0) : h - max(dv, 0), max(-du, 0) : w - max(du, 0)
    ]
    if draw(st.booleans()):  # a label with no mask left (moved off the image, or never drawn)
        masks[masks == masks.max()] = 0
    max_px = draw(st.integers(1, 12))
    cap = draw(st.sampled_from([2.0, 3.5, 6.0, 7.2]))
    max_points = draw(st.sampled_from([8000, 300, 40]))
    return img, masks, max_px, cap, max_points


@settings(deadline=None)
@given(drawn_masks())
def test_the_masks_costs_are_the_references_to_the_bit(case):
    """Random frames: every mask's outline pixels, orientation and costs at every shift as the reference's, so the
    same shift at every floor."""
    img, masks, max_px, cap, max_points = case
    kw = {"max_px": max_px, "cap": cap, "max_points": max_points}
    ours = _mask_costs(img, masks, **kw)
    assert same_costs(ours, reference_mask_costs(img, masks, **kw))
    assert same_costs(_mask_costs(img, masks, boxes=ndimage.find_objects(masks), **kw), ours)


@pytest.mark.parametrize("seed", range(3))
def test_the_masks_costs_are_the_references_on_the_scene(seed):
    rng = np.random.default_rng(20 + seed)
    _, ids = scene(rng)
    color = colour(ids, rng)
    for du, dv in ((0, 0), (5, -3), (-9, 8)):
        drawn = moved(ids, du, dv)
        got = _mask_costs(color, drawn, max_px=10, cap=6.0, max_points=8000)
        assert len(got) == 3
        assert same_costs(got, reference_mask_costs(color, drawn, max_px=10, cap=6.0, max_points=8000))


def test_the_padded_gather_is_the_moved_costs():
    rng = np.random.default_rng(12)
    dist = rng.uniform(0.0, 6.0, (N_BINS, 30, 40)).astype(np.float32)
    rows, cols = rng.integers(0, 30, 200), rng.integers(0, 40, 200)
    bins = rng.integers(0, N_BINS, 200)
    padded = np.pad(dist, ((0, 0), (7, 7), (7, 7)), constant_values=np.float32(6.0))
    assert np.array_equal(
        _padded_costs(padded, rows + 7, cols + 7, bins, 7), _moved_costs(dist, rows, cols, bins, 7, 6.0)
    )


# --- stop 63: the compiled window gradient and distance maps against their numpy twins (docs/shift63.md) ----------


def _twins(fn, *args):
    """``fn(*args)`` with the compiled kernels, then with the numpy twins (``SYMFRUIT_KERNELS=numpy``)."""
    pytest.importorskip("numba")
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv("SYMFRUIT_KERNELS", raising=False)  # a run with the twins throughout still compares
        compiled = fn(*args)
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        twin = fn(*args)
    return compiled, twin


def _bit_equal(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and np.array_equal(a, b) and np.array_equal(np.signbit(a), np.signbit(b))


@st.composite
def drawn_windows(draw: st.DrawFn) -> np.ndarray:
    """A colour window: noise, a few flat levels (zero gradients, ties), every channel the same, a channel the
    negative of another (the same magnitude, the opposite gradient: the first must be taken), a channel a part in
    1e15 off another (near ties of ``hypot``), values near underflow; 8-bit or float, 1, 3 or 4 channels (or a
    plain (h, w) image), sizes down to one pixel, some not contiguous."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    h, w = draw(st.integers(1, 30)), draw(st.integers(1, 30))
    nc = draw(st.sampled_from([1, 3, 4]))
    kind = draw(st.sampled_from(["noise", "levels", "same", "negative", "near", "tiny"]))
    img = rng.uniform(0, 255, (h, w, nc))
    if kind == "levels":
        img = rng.integers(0, 3, (h, w, nc)) * 60.0
    elif kind == "same":
        img[:] = img[..., :1]
    elif kind == "negative" and nc > 1:
        img[..., 1] = 255.0 - img[..., 0]
    elif kind == "near" and nc > 1:
        img[..., 1] = img[..., 0] * (1.0 + 1e-15 * rng.integers(-3, 4, (h, w)))
    elif kind == "tiny":
        img *= 1e-300
    if kind in ("noise", "levels", "same", "negative") and draw(st.booleans()):
        img = img.astype(np.uint8)
    if draw(st.booleans()):
        img = img[::-1, ::-1]
    return img[..., 0] if nc == 1 and draw(st.booleans()) else img


@settings(deadline=None)
@given(drawn_windows())
def test_the_window_gradient_kernel_is_the_twins_to_the_bit(window):
    """The compiled window gradient: at every pixel the twin's first strongest channel's (its ``argmax``) gradient
    to the bit, signs of zero too, its ``hypot`` the twin's magnitude and its sum of squares as numpy's."""
    (squares, cx, cy, each), (tmag, tcx, tcy, teach) = _twins(_window_gradient, window)
    assert each is None and cx.shape[0] == 1 and teach is not None
    k = teach.argmax(axis=0)[None]
    assert _bit_equal(cx[0], np.take_along_axis(tcx, k, 0)[0])
    assert _bit_equal(cy[0], np.take_along_axis(tcy, k, 0)[0])
    assert _bit_equal(np.hypot(cx[0], cy[0]), tmag)
    assert _bit_equal(squares, cx[0] * cx[0] + cy[0] * cy[0])


@pytest.mark.parametrize("spoil", [np.nan, np.inf, 1e120])
def test_a_float_image_with_a_nan_an_inf_or_huge_values_is_left_to_the_twin(spoil):
    window = np.random.default_rng(3).uniform(0, 255, (12, 14, 3))
    window[5, 6, 1] = spoil
    compiled, twin = _twins(_window_gradient, window)
    assert compiled[3] is not None  # the twin's own arrays (every channel)
    assert np.array_equal(compiled[0], twin[0], equal_nan=True)


def _mask_costs_twins(img, masks, **kw):
    return _twins(lambda: _mask_costs(img, masks, **kw))


@settings(deadline=None)
@given(drawn_masks(), st.sampled_from(["plain", "near-ties", "flat", "tiny"]))
def test_the_masks_costs_are_the_twins_to_the_bit(case, kind):
    """The masks' costs with the compiled kernels (the magnitudes' median, threshold and peaks from sums of squares)
    and with the twins: the same to the bit. Besides the drawn frames: channels a part in 1e15 apart (near ties of
    ``hypot``), whole-number levels (ties of the median and of the suppression) and values near underflow."""
    img, masks, max_px, cap, max_points = case
    rng = np.random.default_rng(int(masks.sum()) + max_px)
    img = np.asarray(img, dtype=np.float64) if kind != "plain" else img
    if kind == "near-ties" and img.ndim == 3 and img.shape[2] == 3:
        img[..., 1] = img[..., 0] * (1.0 + 1e-15 * rng.integers(-3, 4, img.shape[:2]))
    elif kind == "flat":
        img = np.round(img / 64.0) * 64.0
    elif kind == "tiny":
        img = img * 1e-160
    kw = {"max_px": max_px, "cap": cap, "max_points": max_points}
    ours, twin = _mask_costs_twins(img, masks, **kw)
    assert same_costs(ours, twin)


@settings(deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 60), st.integers(1, 60), st.integers(1, 12),
       st.sampled_from([2.0, 3.5, 6.0, 7.2]))  # fmt: skip
def test_the_capped_distances_kernel_is_the_twins_to_the_bit(seed, h, w, m, cap):
    """Random edges and points (some bins without points, some without edges): every map the twin's to the bit."""
    rng = np.random.default_rng(seed)
    n_edges, n_points = int(rng.integers(0, h * w // 3 + 2)), int(rng.integers(1, 80))
    rows, cols = rng.integers(0, h, n_edges), rng.integers(0, w, n_edges)
    ebins = rng.integers(0, N_BINS, n_edges)
    points = (rng.integers(0, h, n_points), rng.integers(0, w, n_points), rng.integers(0, N_BINS, n_points))
    if rng.random() < 0.5:  # points of a few bins only
        points = (points[0], points[1], points[2] % int(rng.integers(1, 4)))
    compiled, twin = _twins(_capped_distances, (h, w), rows, cols, ebins, cap, points, m)
    assert compiled.dtype == twin.dtype == np.float32
    assert np.array_equal(compiled, twin)


def _near_ties(rng: np.random.Generator, shape: tuple[int, ...], bases: int) -> tuple[np.ndarray, np.ndarray]:
    """Gradients ``(gx, gy)`` each a few units in the last place off one of a few ``bases`` (signs and zeros
    among them): their sums of squares and ``hypot``s tie, or order the other way round, or tie in one and not
    the other, everywhere."""
    bx, by = rng.uniform(-100, 100, bases), rng.uniform(-100, 100, bases)
    bx[rng.random(bases) < 0.2] = 0.0
    pick = rng.integers(0, bases, shape)
    gx, gy = bx[pick], by[pick]
    for g in (gx, gy):
        for _ in range(3):
            step = rng.integers(-1, 2, shape)
            g[step > 0] = np.nextafter(g[step > 0], np.inf)
            g[step < 0] = np.nextafter(g[step < 0], -np.inf)
    return gx, gy


@given(st.integers(0, 2**32 - 1), st.integers(1, 400), st.integers(1, 6))
def test_the_median_from_the_sums_of_squares_is_numpys_of_the_magnitudes(seed, n, bases):
    """Near ties of every kind about the median, odd and even counts, a single value, zeros: the same median."""
    rng = np.random.default_rng(seed)
    gx, gy = _near_ties(rng, (n,), bases)
    squares, mag = gx * gx + gy * gy, np.hypot(gx, gy)

    def band(lo: float, hi: float) -> np.ndarray:
        return mag[(squares >= lo) & (squares <= hi)]

    assert _bit_equal(np.float64(_squared_median(squares, band)), np.float64(np.median(mag)))


@given(st.integers(0, 2**32 - 1), st.integers(3, 30), st.integers(3, 30), st.integers(1, 5))
def test_the_peaks_from_the_sums_of_squares_are_the_window_peaks(seed, h, w, bases):
    """Near ties with the threshold (one of the magnitudes, or a unit in the last place off one) and between
    neighbours along the gradient: the same edges and bins as the twin's from the magnitudes."""
    rng = np.random.default_rng(seed)
    gx, gy = _near_ties(rng, (h, w), bases)
    mag = np.hypot(gx, gy)
    threshold = float(np.nextafter(mag.flat[rng.integers(0, h * w)], (np.inf, -np.inf, 0.0)[rng.integers(0, 3)]))
    threshold = max(threshold, 1e-3)
    part = (int(rng.integers(0, h)), int(rng.integers(1, h + 1)), int(rng.integers(0, w)), int(rng.integers(1, w + 1)))
    ours = _squared_peaks(gx * gx + gy * gy, gx, gy, threshold, part)
    twin = _window_peaks(mag, gx[None], gy[None], mag[None], threshold, part)
    assert all(np.array_equal(a, b) for a, b in zip(ours, twin, strict=True))


def test_the_median_of_a_pair_whose_sums_of_squares_order_them_the_other_way():
    """Two gradients a unit in the last place apart whose sums of squares order them unlike their ``hypot``s, and a
    third far above: the median is the middle ``hypot``, not that of the middle sum of squares."""
    rng = np.random.default_rng(5)
    x, y = rng.uniform(1, 100, 20000), rng.uniform(1, 100, 20000)
    x2, y2 = np.nextafter(x, np.inf), np.nextafter(y, -np.inf)
    q1, q2, h1, h2 = x * x + y * y, x2 * x2 + y2 * y2, np.hypot(x, y), np.hypot(x2, y2)
    i = int(np.flatnonzero((q1 < q2) & (h1 > h2))[0])
    gx, gy = np.array([x[i], x2[i], 1e3]), np.array([y[i], y2[i], 1e3])
    squares, mag = gx * gx + gy * gy, np.hypot(gx, gy)
    assert _squared_median(squares, lambda lo, hi: mag[(squares >= lo) & (squares <= hi)]) == np.median(mag) == h1[i]


@settings(deadline=None)
@given(drawn_masks(), st.booleans())
def test_the_outline_samples_kernel_is_the_twins_to_the_bit(case, given_boxes):
    """The masks' outline pixels, their labels, the smoothed masks' gradient at them and their bins, with the
    compiled kernel (the outline alone) and with the twin (the whole box): the same to the bit."""
    _, masks, _, _, max_points = case
    boxes = ndimage.find_objects(masks) if given_boxes else None
    ours, twin = _twins(lambda: _outline_samples(masks, max_points, boxes))
    assert (ours is None) == (twin is None)
    if ours is not None:
        assert ours[0] == twin[0]
        assert all(_bit_equal(a, b) for a, b in zip(ours[1:], twin[1:], strict=True))
