"""Where the camera could not have seen a fruit: the occlusion information (known answers on rendered and
hand-made depth images), and where the fruit may project."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy import ndimage

from symfruit.core.camera import Camera
from symfruit.core.occlusion import Occlusion, bridged, occlusion, open_square, with_own
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


def _disk_under_strip(hidden_strip: bool):
    """A 61 px disk (radius 30) in a 80 x 80 window at (10, 20) of a 200 x 150 image, a strip 11 px high across its
    middle (rows 35-45 of the window) reaching 8 px past it on both sides: the region is the disk less the strip,
    the strip hidden (something in front) or not (seen behind)."""
    yy, xx = np.mgrid[:80, :80]
    disk = (yy - 40) ** 2 + (xx - 40) ** 2 <= 30**2
    strip = (np.abs(yy - 40) <= 5) & (np.abs(xx - 40) <= 38)
    hidden = strip if hidden_strip else np.zeros_like(strip)
    return disk, strip, Silhouette(10, 20, disk & ~strip, 0.0), Occlusion(10, 20, hidden, 200, 150)


@pytest.mark.parametrize("kernels", ["", "numpy"])
def test_the_hidden_pixels_between_a_silhouettes_parts_are_the_fruits(monkeypatch, kernels):
    """Stop 57 (docs/strip57.md): a strip in front across a round fruit parts its silhouette in two; the strip's
    pixels between the parts are the fruit's (the disk back, but its two side columns whose disk pixels lie all
    behind the strip; nothing of the strip beyond the disk). The pieces counted by the kernel and by the twin's
    labels (stop 59)."""
    monkeypatch.setenv("SYMFRUIT_KERNELS", kernels)
    disk, strip, region, occ = _disk_under_strip(True)
    out = bridged(region, occ, radius=0)
    assert (out.u0, out.v0, out.mask.shape) == (10, 20, (80, 80))
    assert not (out.mask & ~disk).any()
    assert out.mask[strip & disk].sum() == (strip & disk).sum() - 2  # the strip's pixels of the disk, but 2
    missing = np.nonzero(disk & ~out.mask)
    assert (np.abs(missing[1] - 40) == 30).all()  # the disk's side columns 10 and 70 (a pixel each)


@pytest.mark.parametrize("kernels", ["", "numpy"])
def test_what_is_seen_between_a_silhouettes_parts_or_beside_one_part_is_left_out(monkeypatch, kernels):
    """The strip's pixels seen behind the fruit (no occluder: the parts are apart) are not the fruit's; nor is a
    hidden bite out of the side of a silhouette in one piece (a leaf cutting it: no pixel lies between two parts).
    In both kernel modes (stop 59)."""
    monkeypatch.setenv("SYMFRUIT_KERNELS", kernels)
    _, _, region, occ = _disk_under_strip(False)
    assert bridged(region, occ) is region
    disk, strip, _, occ = _disk_under_strip(True)
    bitten = disk & ~(strip & (np.arange(80) < 40)[None, :])  # the strip over the left half only: one piece
    one = Silhouette(10, 20, bitten, 0.0)
    assert bridged(one, occ) is one


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


def _uncached_at(occ: Occlusion, u: np.ndarray, v: np.ndarray, radius: int) -> np.ndarray:
    """What :meth:`Occlusion.at` answered before its grown maps were kept: the filter run on every call."""
    col, row = np.rint(u).astype(np.intp), np.rint(v).astype(np.intp)
    out = (col < radius) | (col >= occ.width - radius) | (row < radius) | (row >= occ.height - radius)
    hidden = occ.hidden
    if radius > 0 and hidden.any():
        hidden = ndimage.maximum_filter(hidden, size=2 * radius + 1, mode="constant", cval=False)
    h, w = hidden.shape
    c, r = col - occ.u0, row - occ.v0
    inside = (c >= 0) & (c < w) & (r >= 0) & (r < h)
    out[inside] |= hidden[r[inside], c[inside]]
    return out


@given(st.integers(0, 2**32 - 1), st.integers(0, 5))
def test_kept_grown_maps_answer_as_the_filter_run_every_time(seed, radius):
    rng = np.random.default_rng(seed)
    h, w = int(rng.integers(1, 25)), int(rng.integers(1, 25))
    u0, v0 = int(rng.integers(0, 40 - w + 1)), int(rng.integers(0, 30 - h + 1))
    occ = Occlusion(u0, v0, rng.random((h, w)) < rng.uniform(0.0, 0.3), 40, 30)
    u, v = rng.uniform(-3, 43, 200), rng.uniform(-3, 33, 200)
    for _ in range(2):  # made, then kept
        assert np.array_equal(occ.at(u, v, radius=radius), _uncached_at(occ, u, v, radius))
    rh, rw = int(rng.integers(1, 30)), int(rng.integers(1, 40))
    region = Silhouette(int(rng.integers(-5, 40)), int(rng.integers(-5, 30)), np.ones((rh, rw), bool), 0.0)
    vv, uu = np.mgrid[region.v0 : region.v0 + rh, region.u0 : region.u0 + rw]
    expected = _uncached_at(occ, uu.ravel().astype(float), vv.ravel().astype(float), radius).reshape(rh, rw)
    assert np.array_equal(occ.window(region, radius=radius), expected)
    assert not occ.grown(max(radius, 1)).flags.writeable or not occ.hidden.any()


def test_filling_pixels_without_depth_is_skipped_only_when_there_are_none():
    depth, disc, points = _disc_frame(background=0.302)  # background at the fruit's depth: hidden
    holes = depth.copy()
    holes[14:17, 9:11] = 0.0  # beside the disc (its left edge is at u = 14), no depth: takes a neighbour's
    # (without the support rule: a background at the fruit's depth running on from its outline is one, stop 56)
    full = occlusion(depth, disc, points, CAM, supports=False)
    holed = occlusion(holes, disc, points, CAM, supports=False)
    assert full.hidden[14 - full.v0 : 17 - full.v0, 9 - full.u0 : 11 - full.u0].all()
    assert np.array_equal(full.hidden, holed.hidden)
    assert np.isfinite(holed.depth[14 - holed.v0, 9 - holed.u0])


def _allowed_whole_window(occ: Occlusion, region: Silhouette, gap: int, thin: int) -> np.ndarray:
    """:meth:`Occlusion.allowed` as it was: the opening, both filters and the labels over the whole window, the
    kept labels by ``np.isin``."""
    h, w = occ.hidden.shape
    hidden = open_square(occ.hidden, 2 * thin + 1) if thin > 0 and occ.hidden.any() else occ.hidden
    seen = np.zeros((h, w), dtype=bool)
    for r in range(region.mask.shape[0]):
        for c in range(region.mask.shape[1]):
            rr, cc = region.v0 + r - occ.v0, region.u0 + c - occ.u0
            if 0 <= rr < h and 0 <= cc < w:
                seen[rr, cc] = region.mask[r, c]
    if not seen.any():
        return seen
    allowed = hidden.copy()
    if gap > 0:
        size = 2 * gap + 1
        grown = ndimage.maximum_filter(seen, size=size, mode="constant", cval=False)
        allowed |= grown & ndimage.maximum_filter(hidden, size=size, mode="constant", cval=False)
    allowed |= seen
    labels, _ = ndimage.label(allowed, structure=np.ones((3, 3), bool))
    keep = np.unique(labels[seen])
    return np.isin(labels, keep[keep > 0])


@given(st.integers(0, 2**32 - 1), st.integers(0, 4), st.integers(0, 3))
def test_allowed_on_the_seen_box_is_allowed_on_the_whole_window(seed, gap, thin):
    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 40, 2))
    hidden = rng.random((h, w)) < rng.uniform(0, 0.5)
    if seed % 2:  # hidden pixels in part of the window only (the opening and the labels run over their box)
        r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
        hidden[:r0] = False
        hidden[:, c0 + int(rng.integers(1, w + 1)) :] = False
    occ = Occlusion(int(rng.integers(0, 10)), int(rng.integers(0, 10)), hidden, 60, 60)
    rh, rw = (int(x) for x in rng.integers(1, 20, 2))
    mask = rng.random((rh, rw)) < rng.uniform(0.1, 1.0)
    region = Silhouette(int(rng.integers(-5, 40)), int(rng.integers(-5, 40)), mask, 0.0)
    assert np.array_equal(occ.allowed(region, gap=gap, thin=thin), _allowed_whole_window(occ, region, gap, thin))


@given(st.integers(0, 2**32 - 1))
def test_the_depth_fill_takes_the_pixel_the_feature_transform_picks(seed):
    from symfruit.core.occlusion import _fill

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(8, 60, 2))
    yy, xx = np.mgrid[:h, :w]
    own = np.hypot(yy - rng.uniform(0, h), xx - rng.uniform(0, w)) < rng.uniform(0, 15)
    # scattered dropout and a hole: many pixels at equal distances from several valid ones
    valid = (rng.random((h, w)) > rng.uniform(0.0, 0.7)) & ~own
    valid &= np.hypot(yy - rng.uniform(0, h), xx - rng.uniform(0, w)) > rng.uniform(0, 10)
    if not valid.any() or (valid | own).all():
        return
    d = np.where(valid, rng.uniform(0.3, 0.6, (h, w)), np.nan)
    reach = int(rng.integers(1, 6))
    dist, (vr, vc) = ndimage.distance_transform_edt(~valid, return_indices=True)
    expected = np.where(~valid & ~own & (dist <= reach), d[vr, vc], d)
    np.testing.assert_array_equal(_fill(d, valid, own, reach), expected)


@given(st.integers(0, 2**32 - 1), st.integers(0, 6))
def test_grown_part_is_the_grown_map_cut_to_its_box(seed, radius):
    """The filter run over a box grown by the radius alone gives the whole window's filter's values there."""
    rng = np.random.default_rng(seed)
    h, w = int(rng.integers(1, 40)), int(rng.integers(1, 40))
    occ = Occlusion(0, 0, rng.random((h, w)) < rng.uniform(0.0, 0.2), 60, 50)
    full = occ.hidden
    if radius:
        full = ndimage.maximum_filter(occ.hidden, size=2 * radius + 1, mode="constant", cval=False)
    for _ in range(3):
        r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
        r1, c1 = int(rng.integers(r0 + 1, h + 1)), int(rng.integers(c0 + 1, w + 1))
        assert np.array_equal(occ.grown_part(radius, r0, r1, c0, c1), full[r0:r1, c0:c1])
    occ.grown(radius)  # kept: then cut from it
    assert np.array_equal(occ.grown_part(radius, 0, h, 0, w), full)


def test_a_checked_depth_gives_the_same_occlusion_and_only_an_unchecked_one_is_sampled():
    depth, disc, points = _disc_frame()
    a, b = occlusion(depth, disc, points, CAM), occlusion(depth, disc, points, CAM, checked=True)
    assert (a.u0, a.v0) == (b.u0, b.v0) and np.array_equal(a.hidden, b.hidden)
    assert np.array_equal(a.depth, b.depth, equal_nan=True) and np.array_equal(a.own, b.own)
    with pytest.raises(InputError, match="millimetres"):
        occlusion(depth * 1000.0, disc, points, CAM)
    with pytest.raises(InputError, match="depth and mask images"):  # the shapes are checked either way
        occlusion(depth[:-1], disc, points, CAM, checked=True)


def test_the_fruits_own_pixels_among_the_others_change_nothing():
    depth, disc, points = _disc_frame(background=0.302)
    others = np.zeros_like(disc)
    others[10:30, 5:12] = True  # another fruit beside it
    a = occlusion(depth, disc, points, CAM, others=others)
    b = occlusion(depth, disc, points, CAM, others=others | disc)
    assert a.hidden.any() and np.array_equal(a.hidden, b.hidden)


# --- stop 40, occl40: an active-stereo camera's fattened edge is the fruit's own, not an occluder

BIG = Camera(fx=300.0, fy=300.0, cx=40.0, cy=30.0, width=80, height=60)


def _fattened(band_px: int = 3, background: float = 1.0):
    """An 80x60 depth image: a disc of radius 15 px at 0.3 m centred on (40, 30), its depth spread ``band_px``
    pixels over the background around it (as an active-stereo camera's correlation window does)."""
    vv, uu = np.mgrid[:60, :80]
    r2 = (uu - 40) ** 2 + (vv - 30) ** 2
    disc = r2 <= 15**2
    depth = np.full((60, 80), background)
    depth[r2 <= (15 + band_px) ** 2] = 0.3
    rows, cols = np.nonzero(disc)
    points = BIG.deproject(np.c_[cols, rows].astype(float), np.full(len(rows), 0.3))
    return depth, disc, points, r2


@pytest.mark.parametrize("kernels", ["default", "numpy"])
def test_a_fattened_edge_is_the_fruits_own_and_a_leaf_in_front_is_not(kernels, monkeypatch):
    if kernels == "numpy":
        monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    depth, disc, points, r2 = _fattened()
    ring = (r2 > 15**2) & (r2 <= 18**2)
    assert hidden_image(occlusion(depth, disc, points, BIG, band=0))[ring].all()  # the map without the post-step
    assert not hidden_image(occlusion(depth, disc, points, BIG)).any()  # the fruit's own edge: nothing hidden
    # a leaf 3 cm in front, beside the disc's right side, no wider than the band: clearly nearer, hidden
    leaf = ring & (np.mgrid[:60, :80][1] > 50)
    depth[leaf] = 0.27
    full = hidden_image(occlusion(depth, disc, points, BIG))
    assert full[leaf].all() and not full[ring & ~leaf].any()


def _ball_on_a_box(face: float):
    """An 80x60 depth image through :data:`BIG`: a ball of radius 15 px (15 mm) whose centre lies 0.3 m away, seen by a
    time-of-flight camera (no depth on the outer 15 % of its radius; its mask the whole disc), standing on a box whose
    front face (every row below the ball's centre, beside and below it, to the image's border) lies at ``face``;
    the background at 1 m. ``(depth, disc, points, rows, cols)``; the ball's front is at 0.285 m."""
    rows, cols = np.mgrid[:60, :80]
    rho = np.hypot(cols - 40, rows - 30)  # pixels; a pixel is 1 mm at 0.3 m
    disc = rho <= 15
    depth = np.where((rows > 30) & ~disc, face, 1.0)
    seen = rho <= 0.85 * 15
    depth[seen] = 0.3 - np.sqrt(0.015**2 - (rho[seen] * 0.001) ** 2)
    depth[disc & ~seen] = 0.0
    r, c = np.nonzero(seen)
    points = BIG.deproject(np.c_[c, r].astype(float), depth[r, c])
    return depth, disc, points, rows, cols


@pytest.mark.parametrize("kernels", ["default", "numpy"])
def test_a_support_at_the_fruits_depth_hides_no_more_than_a_round_fruit_can_reach_behind_it(kernels, monkeypatch):
    """Stop 56: a ball standing on a box whose front face lies 0.45 of a radius behind the ball's front (the real
    66 mm sphere's board: 0.44-0.5), meeting its outline at its own depth and running on to the image's border. Behind
    that face a round fruit may continue 17 % of its radius past where the face meets it (:func:`support_reach`:
    2.6 px here):
    those pixels stay hidden, the rest of the band is cleared, and beyond the band the face is as it was.
    Without the rule (``supports`` off, stop 40's) the whole face is hidden beside the outline. A face at the ball's
    front (a leaf lying on it: it may hide the ball to its whole radius) and a face 3 cm in front of it (a step: an
    occluder) stay hidden."""
    from symfruit.core.occlusion import support_reach

    if kernels == "numpy":
        monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    depth, disc, points, rows, cols = _ball_on_a_box(0.2916)
    # the ball's own pixels' box is 31 px a side (radius 15.5 px), its front 0.285 m: 0.448 of a radius behind it
    assert support_reach(np.array([0.2916]), 0.285, 15.5, 15.5 * 0.285 / 300.0)[0] == pytest.approx(2.57, abs=0.01)
    gap = ndimage.distance_transform_cdt(~disc, metric="chessboard")  # steps from the ball's pixels
    face = (rows > 30) & ~disc
    full = hidden_image(occlusion(depth, disc, points, BIG))
    below = face & (np.abs(cols - 40) <= 3)  # straight below the ball, where the walk's steps are the distance
    # cleared from 3 px on, as far as an own depth lies within the band (the points end 2-3 px inside the outline)
    assert full[below & (gap <= 2)].all() and not full[below & (gap >= 3) & (gap <= 5)].any()
    assert full[face & (gap > 10)].all()  # beyond the band: not joined to the ball any more, as it was
    assert hidden_image(occlusion(depth, disc, points, BIG, supports=False))[face & (gap <= 8)].all()
    for at in (0.285, 0.255):  # at the ball's front, and 3 cm in front of it
        depth, disc, points, rows, cols = _ball_on_a_box(at)
        assert hidden_image(occlusion(depth, disc, points, BIG))[face].all()


@pytest.mark.parametrize("kernels", ["default", "numpy"])
def test_an_overshooting_mask_is_trimmed_where_the_camera_spreads_the_fruits_depth(kernels, monkeypatch):
    """Stop 42: a mask 3 px wider than the fruit's points, its ring mostly at the fruit's depth (an active-stereo
    camera's spread edge, a little nearer than the rim), overshoots by that ring, peeled from the border inwards:
    not where something lies clearly in front (an amodal mask over a leaf), not a pixel inside the points' region;
    a ring mostly without depth (a time-of-flight camera's lost rim) overshoots by nothing; the mask's border
    extraction never took points from stays the fruit's."""
    if kernels == "numpy":
        monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    vv, uu = np.mgrid[:60, :80]
    r2 = (uu - 40) ** 2 + (vv - 30) ** 2
    disc, mask = r2 <= 15**2, r2 <= 18**2
    ring = mask & ~disc
    hole = (vv == 30) & (uu == 40)  # no point there, the fruit's depth
    depth = np.full((60, 80), 1.0)  # the background
    depth[mask] = 0.3 + 0.0002 * r2[mask]  # a rounded front, the rim 4.5 cm behind its apex ...
    depth[ring] = 0.3 + 0.0002 * 12**2  # ... its depth 3 px in spread over the ring
    rows, cols = np.nonzero(disc & ~hole)
    points = BIG.deproject(np.c_[cols, rows].astype(float), depth[rows, cols])
    top, right = ring & (vv < 20) & (uu <= 53), ring & (uu > 53)
    depth[top] = 0.25  # a leaf in front under an amodal mask
    depth[right] = 1.0  # the background, where the mask runs past the spread band

    def overshoot_of(depth, **kw):
        occ = occlusion(depth, mask, points, BIG, **kw)
        if occ.overshoot is None:
            return None
        out = np.zeros((60, 80), bool)
        out[occ.v0 : occ.v0 + occ.overshoot.shape[0], occ.u0 : occ.u0 + occ.overshoot.shape[1]] = occ.overshoot
        return out

    over = overshoot_of(depth, eroded=0)
    assert over is not None and over[ring & ~top].all() and not over[~ring | top].any()
    # the ring extraction never took points from (1 px by default) stays next to what is kept
    kept = ndimage.binary_dilation(mask & ~over, structure=np.ones((3, 3), bool))
    assert np.array_equal(overshoot_of(depth), over & ~kept)
    assert overshoot_of(depth, trim_own=False) is None  # switched off
    tof = depth.copy()
    tof[ring & (uu > 30)] = 0.0  # most of the ring without depth: the mask is the only measure of the rim
    assert overshoot_of(tof) is None
    region = Silhouette(0, 0, disc, 0.0)
    occ = occlusion(depth, mask, points, BIG)
    assert with_own(region, occ).mask.sum() == mask.sum()
    assert with_own(region, occ, trimmed=True).mask.sum() == (mask & ~(over & ~kept)).sum()


@pytest.mark.parametrize("kernels", ["default", "numpy"])
def test_a_mask_overshooting_where_a_time_of_flight_camera_saw_past_the_fruit_is_trimmed(kernels, monkeypatch):
    """Stop 43: a fruit whose points reach 12 px from its centre, a ring of 4 px without depth (the mixed pixels a
    time-of-flight camera invalidates on both sides of its edge at 14 px), the background 0.7 m behind, a mask drawn
    20 px wide: the mask beyond halfway between the last point (12 px) and the first pixel seen past (16 px) is
    overshoot (the border ring extraction never took points from is given back). The same background seen past
    one side alone (a registration a few pixels off) is no overshoot, nor is a ring without depth all round."""
    if kernels == "numpy":
        monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    vv, uu = np.mgrid[:60, :80]
    r = np.hypot(uu - 40, vv - 30)
    disc, mask = r <= 12, r <= 20
    depth = np.full((60, 80), 1.0)  # the background
    depth[disc] = 0.3 + 0.0002 * r[disc] ** 2
    depth[(r > 12) & (r < 16)] = 0.0  # the invalidated ring
    rows, cols = np.nonzero(disc)
    points = BIG.deproject(np.c_[cols, rows].astype(float), depth[rows, cols])
    occ = occlusion(depth, mask, points, BIG, eroded=0)
    assert occ.overshoot is not None and occ.seen_past
    over = np.zeros((60, 80), bool)
    over[occ.v0 : occ.v0 + occ.overshoot.shape[0], occ.u0 : occ.u0 + occ.overshoot.shape[1]] = occ.overshoot
    kept = mask & ~over
    radius = np.sqrt(kept.sum() / np.pi)
    assert 13.5 < radius < 15.0  # halfway: 14 px
    assert not over[r <= 13.5].any() and over[mask & (r > 15)].all()
    one_side = depth.copy()
    one_side[mask & ~disc & (uu < 40)] = 0.0  # seen past on the right only
    assert occlusion(one_side, mask, points, BIG).overshoot is None
    nothing = depth.copy()
    nothing[mask & ~disc] = 0.0  # the mask's band all without depth: the mask is the only measure
    assert occlusion(nothing, mask, points, BIG).overshoot is None


@pytest.mark.parametrize("kernels", ["default", "numpy"])
def test_a_curved_fruits_mask_is_not_read_by_sectors(kernels, monkeypatch):
    """Stop 43: the sectors about the points' centroid give one edge per direction only on a star-shaped silhouette.
    A fruit curved as a banana seen from the side (an arch 8 px thick), receding from 0.30 to 0.45 m along its length,
    whose points are its near part (the slab extraction keeps), a 2 px ring without depth round it, the background
    beyond, a mask 5 px wider all round: read by sectors (the gate off), the arch's own far part (its depth beyond
    the front plus half the mask's width) is taken for the background seen past, and more than half the arch is
    cut off (stop 43; since stop 44 the surface test keeps it, the gate off); the mask fills under :data:`STAR_SHARE`
    of its star polygon, so it is not cut. A 3:1 ellipse (convex) with the background seen past all round is still
    trimmed, to within its ring."""
    import symfruit.core.occlusion as core_occlusion

    if kernels == "numpy":
        monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    vv, uu = np.mgrid[:60, :80]
    r = np.hypot(uu - 40, vv - 62)
    angle = np.degrees(np.arctan2(uu - 40, 62 - vv))
    arch = (r >= 22) & (r <= 30) & (np.abs(angle) <= 60)

    def view(fruit, fruit_depth, points_at):
        mask = ndimage.binary_dilation(fruit, iterations=5)
        ring = ndimage.binary_dilation(fruit, iterations=2) & ~fruit
        depth = np.full(fruit.shape, 1.0)
        depth[ring] = 0.0
        depth[fruit] = fruit_depth
        rows, cols = np.nonzero(points_at)
        return depth, mask, BIG.deproject(np.c_[cols, rows].astype(float), depth[rows, cols])

    recede = 0.3 + 0.15 * (angle[arch] + 60) / 120
    depth, mask, points = view(arch, recede, arch & (np.where(arch, 0.3 + 0.15 * (angle + 60) / 120, 1) < 0.36))
    assert occlusion(depth, mask, points, BIG, eroded=0).overshoot is None
    with monkeypatch.context() as patched:
        patched.setattr(core_occlusion, "STAR_SHARE", 0.0)
        occ = occlusion(depth, mask, points, BIG, eroded=0)
    cut = np.zeros(mask.shape, bool)
    if occ.overshoot is not None:
        cut[occ.v0 : occ.v0 + occ.overshoot.shape[0], occ.u0 : occ.u0 + occ.overshoot.shape[1]] = occ.overshoot
    # what the gate kept from happening (over half the arch cut) the surface test keeps since stop 44: the arch's
    # far part is joined to its points, and none of its pixels with depth is cut
    assert not (cut & arch & (depth > 0)).any()
    ellipse = ((uu - 40) / 21.0) ** 2 + ((vv - 30) / 7.0) ** 2 <= 1.0
    depth, mask, points = view(ellipse, 0.3, ellipse)
    occ = occlusion(depth, mask, points, BIG, eroded=0)
    assert occ.overshoot is not None and occ.seen_past
    kept = mask.copy()
    kept[occ.v0 : occ.v0 + occ.overshoot.shape[0], occ.u0 : occ.u0 + occ.overshoot.shape[1]] &= ~occ.overshoot
    assert ellipse.sum() < kept.sum() < ndimage.binary_dilation(ellipse, iterations=3).sum()


# --- stop 42, speedext42


def test_the_occlusion_made_without_checks_is_the_checked_one():
    """occlusion()'s maps made by Occlusion._made: equal to the dataclass made with its checks from the same fields,
    the same fields and types, and a cache of its own for the grown maps."""

    rng = np.random.default_rng(42)
    hidden, own = rng.random((12, 15)) < 0.3, rng.random((12, 15)) < 0.2
    seen = rng.random((12, 15))
    made = Occlusion._made(np.int64(3), 4, hidden, 40, 30, own, seen)
    checked = Occlusion(3, 4, hidden, 40, 30, own=own, depth=seen)
    assert made == checked and type(made.u0) is int and type(made.v0) is int
    assert made.own is own and made.depth is seen and made._grown == {} and made._grown is not checked._grown
    np.testing.assert_array_equal(made.grown(1), checked.grown(1))
    over = rng.random((12, 15)) < 0.1  # with the mask's overshoot (stop 42, sil42)
    assert Occlusion._made(3, 4, hidden, 40, 30, own, seen, over) == Occlusion(3, 4, hidden, 40, 30, own=own,
                                                                               depth=seen, overshoot=over)  # fmt: skip
    assert made.overshoot is None


# --- stop 43, robust43


@pytest.mark.parametrize(
    ("key", "value"),
    [("tolerance", float("nan")), ("tolerance", "0.005"), ("tolerance", 2.0), ("reach", -1), ("reach", 10**9),
     ("reach", 2.5), ("pad", 16.0), ("pad", -1), ("band", 2.5), ("band", True), ("eroded", -1)],
)  # fmt: skip
def test_occlusion_refuses_parameters_it_cannot_use_naming_them(key, value):
    """Before: NaN and a negative reach were taken in silence, a reach of 10**9 was numpy's MemoryError (exbibytes
    of offsets) and a band of 2.5 a TypeError from slicing."""
    depth, disc, points = _disc_frame()
    with pytest.raises(InputError, match=f"occlusion: {key} must be"):
        occlusion(depth, disc, points, CAM, **{key: value})
    fine = occlusion(depth, disc, points, CAM, reach=np.int64(3), pad=np.int32(16), tolerance=np.float32(0.005))
    np.testing.assert_array_equal(fine.hidden, occlusion(depth, disc, points, CAM).hidden)


def test_occlusion_of_non_finite_points_is_refused_without_numpys_warning(monkeypatch):
    """Before: the numpy twin cast NaN pixels to integers, and numpy's RuntimeWarning 'invalid value encountered in
    cast' reached the caller before the InputError."""
    import warnings

    depth, disc, _ = _disc_frame()
    for kernels in ("", "numpy"):
        monkeypatch.setenv("SYMFRUIT_KERNELS", kernels)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            with pytest.raises(InputError, match="occlusion: no point of the fruit projects into the image"):
                occlusion(depth, disc, np.full((10, 3), np.nan), CAM)


# --- stop 44, guard44

WIDE = Camera(fx=300.0, fy=300.0, cx=80.0, cy=60.0, width=160, height=120)  # 1 mm a pixel at 0.3 m


def _tof_view(fruit, fruit_depth, behind, ring=2, grow=5, flying=False):
    """A time-of-flight view of ``fruit`` (its depth ``fruit_depth``, an image) before ``behind`` (an image): the
    mixed pixels ``ring`` px either side of its edge without depth (``flying``: those outside it at the depth
    halfway between the fruit's nearest and the background), a mask drawn ``grow`` px wider, the points the
    fruit's pixels with depth one px inside, within 1.3 mask radii of its front (extraction's slab)."""
    depth = np.where(fruit, fruit_depth, behind)
    inner = fruit & ~ndimage.binary_erosion(fruit, iterations=ring)
    outer = ndimage.binary_dilation(fruit, iterations=ring) & ~fruit
    depth[inner | outer] = 0.0
    if flying:
        near = -ndimage.grey_dilation(np.where(fruit, -fruit_depth, -np.inf), size=2 * ring + 3)
        depth[outer] = 0.5 * (behind[outer] + near[outer])
    mask = ndimage.binary_dilation(fruit, iterations=grow)
    core = ndimage.binary_erosion(fruit & (depth > 0), iterations=1)
    front = fruit_depth[core].min()
    core &= fruit_depth <= front + 1.3 * np.sqrt(mask.sum() / np.pi) * front / WIDE.fx
    rows, cols = np.nonzero(core)
    return depth, mask, WIDE.deproject(np.c_[cols, rows].astype(float), depth[rows, cols])


def _cut(depth, mask, points):
    occ = occlusion(depth, mask, points, WIDE, eroded=1)
    cut = np.zeros(mask.shape, bool)
    if occ.overshoot is not None:
        cut[occ.v0 : occ.v0 + occ.overshoot.shape[0], occ.u0 : occ.u0 + occ.overshoot.shape[1]] = occ.overshoot
    return cut, occ.seen_past


@pytest.mark.parametrize("kernels", ["default", "numpy"])
def test_a_fruits_own_surface_joined_to_its_points_is_never_seen_past(kernels, monkeypatch):
    """Stop 44: background seen past a silhouette lies a depth step behind the fruit's edge; a fruit's own surface
    receding beyond extraction's slab is joined to its points by steps a surface makes. An arch 8 px thick on a
    22-30 px radius receding from 0.30 to 0.45 m along its length (a banana's far end) and a pear seen end-on, its
    neck towards the camera (its body's rim 70 mm behind the neck's tip, past the front plus half the mask's width),
    both with the star gate off: no pixel of either fruit with depth is cut (of the arch, under a tenth: some of its
    mixed pixels without depth; stop 43 cut 189 of its 437 pixels and 428 of the pear's 2177); the mask drawn 5 px
    wider is still trimmed beyond them. A ball before a wall, also with flying pixels all round its edge instead of
    none, is trimmed to within its ring."""
    import symfruit.core.occlusion as core_occlusion

    if kernels == "numpy":
        monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    monkeypatch.setattr(core_occlusion, "STAR_SHARE", 0.0)
    vv, uu = np.mgrid[:120, :160].astype(float)
    wall = np.full(vv.shape, 0.9)
    r, a = np.hypot(uu - 80, vv - 70), np.degrees(np.arctan2(uu - 80, 70 - vv))
    arch = (r >= 22) & (r <= 30) & (np.abs(a) <= 60)
    depth, mask, points = _tof_view(arch, 0.30 + 0.15 * (a + 60) / 120, wall)
    cut, seen_past = _cut(depth, mask, points)
    assert seen_past and not (cut & (depth > 0) & arch).any() and (cut & arch).sum() < 0.1 * arch.sum()
    assert (cut & ~arch).sum() > 0.4 * (mask & ~arch).sum()
    rho = np.hypot(uu - 80, vv - 60) * 0.4 / 300.0  # metres across the line of sight at 0.4 m
    pear = rho <= 0.035
    depth, mask, points = _tof_view(pear, 0.40 + 0.070 * (np.clip(rho, 0, 0.035) / 0.035) ** (1 / 0.6), wall)
    cut, seen_past = _cut(depth, mask, points)
    assert seen_past and not (cut & pear).any() and (cut & ~pear).sum() > 0.6 * (mask & ~pear).sum()
    db = np.hypot(uu - 80, vv - 60)
    ball = db <= 16
    zball = 0.30 + 0.001 * (16 - np.sqrt(np.clip(256 - db**2, 0, None)))
    for ring, flying in ((2, False), (1, True)):
        depth, mask, points = _tof_view(ball, zball, wall, ring=ring, flying=flying)
        cut, seen_past = _cut(depth, mask, points)
        kept = np.sqrt((mask & ~cut).sum() / np.pi)
        assert seen_past and not (cut & ball).any() and 16.0 <= kept <= 16.0 + ring + 1.0


# --- stop 45, hidden45


@pytest.mark.parametrize("kernels", ["default", "numpy"])
def test_a_leaf_over_the_fruits_edge_is_no_mixed_gap(kernels, monkeypatch):
    """Stop 45: a ball 16 px in radius before a wall, its mixed pixels 2 px either side of its edge without depth, a
    leaf in front over its right rim (u 86-95, 15 rows; its own edge without depth), the mask drawn 4 px wider over
    the leaf (an annotator's whole outline). Seen past all round; in the leaf's sectors the gap between the last
    point and the background is the leaf's, and halfway across it (stop 43-44) cut 65 of the ball's pixels under
    the leaf (the right side read at 91 px instead of 96). The edge there is the background less half the gap of
    the sectors without a leaf: no ball pixel is cut, the mask beyond the ball still is (at least 3/4 of it)."""
    if kernels == "numpy":
        monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    vv, uu = np.mgrid[:120, :160].astype(float)
    db = np.hypot(uu - 80, vv - 60)
    ball = db <= 16
    depth = np.where(ball, 0.30 + 0.001 * (16 - np.sqrt(np.clip(256 - db**2, 0, None))), 0.9)
    depth[ndimage.binary_dilation(ball, iterations=2) & ~ndimage.binary_erosion(ball, iterations=2)] = 0.0
    leaf = (uu >= 86) & (uu <= 95) & (np.abs(vv - 60) <= 7)
    depth[leaf] = 0.25
    depth[ndimage.binary_dilation(leaf) & ~leaf] = 0.0
    mask = ndimage.binary_dilation(ball, iterations=4)
    rows, cols = np.nonzero(ndimage.binary_erosion(ball & (depth > 0.26), iterations=1))
    points = WIDE.deproject(np.c_[cols, rows].astype(float), depth[rows, cols])
    cut, seen_past = _cut(depth, mask, points)
    assert seen_past and not (cut & ball).any()
    assert (cut & ~ball).sum() > 0.75 * (mask & ~ball).sum()
    assert np.nonzero((mask & ~cut & leaf.any(axis=1)[:, None]).any(axis=0))[0].max() == 96


# --- stop 47, robust47


@pytest.mark.parametrize("dtype", [">f8", ">f4", "f2"])
def test_occlusion_reads_a_big_endian_or_float16_depth_as_its_native_float(dtype):
    """Before: numba's TypingError from the kernels the depth went to as given (``python docs/robust43.py``:
    occlusion/depth-float16, occlusion/depth-bigendian)."""
    depth, disc, points = _disc_frame()
    depth[12:18, :22] = 0.25  # a bar in front of the disc's left half
    native = depth.astype(dtype).astype(np.dtype(dtype).newbyteorder("="))
    want = occlusion(native, disc, points, CAM, trim_own=True)
    got = occlusion(depth.astype(dtype), disc, points, CAM, trim_own=True)
    assert want.hidden.any()
    np.testing.assert_array_equal(got.hidden, want.hidden)
    assert (got.u0, got.v0) == (want.u0, want.v0)


def _on_a_board(grow: int, shift: int = 0, board_row: int = 33):
    """A fruit whose points reach 12 px from its centre (40, 30), a ring of 4 px without depth (a time-of-flight
    camera's mixed pixels either side of its edge at 14 px), the background 0.7 m behind, and a board at the fruit's
    own depth from ``board_row`` down running on under it (no ring there: it meets the fruit at its depth); the
    mask drawn ``grow`` px past the edge, ``shift`` px to the right of the depth."""
    vv, uu = np.mgrid[:60, :80]
    r = np.hypot(uu - 40, vv - 30)
    disc = r <= 12
    depth = np.full((60, 80), 1.0)
    depth[disc] = 0.3 + 0.0002 * r[disc] ** 2
    depth[(r > 12) & (r < 16)] = 0.0
    depth[(vv >= board_row) & ~disc] = 0.33
    mask = np.hypot(uu - 40 - shift, vv - 30) <= 14 + grow
    rows, cols = np.nonzero(disc)
    points = BIG.deproject(np.c_[cols, rows].astype(float), depth[rows, cols])
    return depth, mask, points, r


@pytest.mark.parametrize("kernels", ["default", "numpy"])
def test_a_mask_overshooting_onto_a_board_and_where_the_camera_saw_past_is_trimmed_by_the_opposite_sides(
    kernels, monkeypatch
):
    """Stop 56: a fruit on a board at its own depth (the board runs on under the lower half of its outline, so the
    camera saw past it over no more than two thirds: stop 43's rule does not fire) with a mask drawn 6 px wide. The
    overshoot read on opposite sides where the camera saw past it (the mask's pixels seen past, from 16 px to 20 px:
    its overshoot past the edge at 14 px less the 2 px the camera invalidated outside the edge) is taken off all
    round but the board's pixels joined to the fruit's, which are never cut: the kept radius that of the first pixel
    seen past. A mask drawn right (to 14 px) loses nothing; a mask drawn right but 3 px off the depth (a
    registration or a parallax: seen past on one side deeper than on the other) loses nothing either, the opposite
    sides' displacements cancelling; nor does a mask whose band holds no depth over a third of the outline (the
    mask the only measure there)."""
    if kernels == "numpy":
        monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    depth, mask, points, r = _on_a_board(6)
    occ = occlusion(depth, mask, points, BIG, eroded=0)
    assert occ.overshoot is not None and occ.seen_past
    over = np.zeros((60, 80), bool)
    over[occ.v0 : occ.v0 + occ.overshoot.shape[0], occ.u0 : occ.u0 + occ.overshoot.shape[1]] = occ.overshoot
    vv, _ = np.mgrid[:60, :80]
    top = mask & (vv < 30)  # the half above the board: a half disc of the kept radius
    radius = np.sqrt(2 * (top & ~over).sum() / np.pi)
    assert 15.0 < radius < 16.5
    assert not over[r <= 15.5].any() and over[top & (r > 16.5)].all()
    for drawn in (_on_a_board(0), _on_a_board(0, shift=3)):
        assert occlusion(*drawn[:3], BIG, eroded=0).overshoot is None
    depth, mask, points, r = _on_a_board(6)
    _, uu = np.mgrid[:60, :80]
    depth[mask & (r > 12) & (uu > 44) & (vv < 33)] = 0.0  # the right side's band without depth
    assert occlusion(depth, mask, points, BIG, eroded=0).overshoot is None


@given(grow=st.integers(0, 8), shift=st.integers(-4, 4), board_row=st.integers(31, 38))
def test_a_partly_seen_past_mask_is_never_cut_inside_the_fruits_edge(grow, shift, board_row):
    """Stop 56: the mask's pixels seen past are its overshoot less the mixed pixels outside the edge, and a
    displacement of the mask against the depth cancels on opposite sides: however wide the mask is drawn, however
    far off the depth and wherever the board begins, no pixel within the fruit's edge (14 px) is cut."""
    depth, mask, points, r = _on_a_board(grow, shift=shift, board_row=board_row)
    occ = occlusion(depth, mask, points, BIG, eroded=0)
    if occ.overshoot is not None:
        over = np.zeros((60, 80), bool)
        over[occ.v0 : occ.v0 + occ.overshoot.shape[0], occ.u0 : occ.u0 + occ.overshoot.shape[1]] = occ.overshoot
        assert not over[r <= 14.0].any()


def _ball_under_a_leaf(lying: float):
    """:func:`_ball_on_a_box`'s ball with a flat leaf lying on it ``lying`` of its radius behind its front, over every
    row below its centre (no step: the leaf meets the ball's surface), running on to the image's border: the ball's
    mask is what the leaf leaves of it (its upper half and the cap in front of the leaf), 31 px wide and 22 px tall
    for ``lying`` 0.1. ``(depth, mask, points, rows, cols)``."""
    depth, disc, _, rows, cols = _ball_on_a_box(1.0)
    leaf_z = 0.285 + lying * 0.015
    ball = np.where(depth > 0.0, depth, np.inf)  # the lost rim lies behind the leaf there too
    ball[~disc] = np.inf
    under = (rows > 30) & ~(disc & (ball < leaf_z))  # the leaf, but where the ball pokes through it
    depth = np.where(under, leaf_z, depth)
    mask = disc & ~under
    r, c = np.nonzero(mask & (depth > 0.0) & (depth < leaf_z))
    points = BIG.deproject(np.c_[c, r].astype(float), depth[r, c])
    return depth, mask, points, rows, cols


def test_the_support_radius_is_half_the_larger_side_of_the_fruits_box():
    """Stop 57: a fruit cut along one axis keeps its radius along the other (half the mean side was short of it)."""
    from symfruit.core.occlusion import support_radius

    assert support_radius((0, 22, 0, 31)) == 15.5 and support_radius((3, 43, 5, 25)) == 20.0


@pytest.mark.parametrize("kernels", ["default", "numpy"])
def test_a_leaf_lying_on_a_cut_fruit_stays_hidden_as_far_as_the_whole_fruit_reaches_behind_it(kernels, monkeypatch):
    """Stop 57 (docs/shift57.md): the ball under a flat leaf lying on it a tenth of its radius behind its front, over
    its lower half; its mask is what the leaf leaves (31 x 22 px). Behind the leaf the ball reaches 15 (1 - sqrt(0.19))
    = 8.5 px past the cap poking through it, the whole band: the leaf stays hidden there. With the radius half the mean
    side of the cut mask's box (13.25 px, stop 56) the reach was 7.0 px and the band's last two steps were cleared."""
    if kernels == "numpy":
        monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    depth, mask, points, rows, cols = _ball_under_a_leaf(0.1)
    box = np.nonzero(mask.any(axis=1))[0], np.nonzero(mask.any(axis=0))[0]
    assert (box[0][-1] - box[0][0] + 1, box[1][-1] - box[1][0] + 1) == (22, 31)
    gap = ndimage.distance_transform_cdt(~mask, metric="chessboard")
    below = (rows > 36) & (np.abs(cols - 40) <= 2) & (gap <= 8)  # straight below the cap, within the band
    assert below.sum() >= 20
    assert hidden_image(occlusion(depth, mask, points, BIG))[below].all()
