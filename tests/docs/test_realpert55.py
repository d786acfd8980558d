"""docs/realpert55.py: the real Azure Kinect sphere frames perturbed as issue 18's held-back frames differ from them
(stop 55, docs/realpert55.md). Known answers for the perturbations, and on the real frames the conditions the
default holds under: a lost rim up to 3 px wider and masks shifted 10 px across keep every sphere a cube within the
issue's 6 mm for balls, its depth side within 6 mm of the unperturbed mask's diameter."""

import numpy as np
import pytest

from symfruit.core.camera import Camera
from symfruit.core.frame import Frame
from symfruit.detect import detect
from symfruit.io.frames import read_frame
from symfruit.settings import from_dict

from ..conftest import docs_script

#: one worker runs the real frames' detections (pytest-xdist --dist loadgroup), beside test_spheres' own
pytestmark = pytest.mark.xdist_group("real-spheres")


@pytest.fixture(scope="module")
def rp():
    return docs_script("realpert55")


def small_frame():
    depth = np.full((6, 6), 1.0, np.float32)
    depth[0, :3] = [0.0, 0.0, 1.2]  # the top-left 3x3 block: 7 of 9 valid
    depth[:3, 3:] = 0.0
    depth[0, 3:] = [2.0, 2.1, 0.0]  # the top-right block: 2 of 9 valid, fewer than half
    depth[3:, :3] = np.arange(9, dtype=np.float32).reshape(3, 3) * 0.01 + 1.0  # median 1.04
    masks = np.zeros((6, 6), np.int32)
    masks[3:, 3:] = 2
    masks[3:5, 3:6] = 1  # the bottom-right block: six of id 1, three of id 2
    color = np.zeros((6, 6, 3), np.uint8)
    color[:3, :3, 0] = np.arange(9).reshape(3, 3) * 10  # mean 40
    cam = Camera(fx=600.0, fy=610.0, cx=2.5, cy=2.5, width=6, height=6)
    return Frame(name="t", color=color, depth=depth, camera=cam, masks=masks)


def test_binning_takes_the_median_of_valid_depth_the_majority_label_and_the_mean_colour(rp):
    color, depth, masks, _ = rp.binned(small_frame(), 3)
    assert depth.shape == masks.shape == (2, 2) and color.shape == (2, 2, 3)
    assert depth[0, 0] == pytest.approx(1.0)  # the median of 1.2 and six 1.0s
    assert depth[0, 1] == 0.0  # too few valid pixels: none, as the camera gives at a lost rim
    assert depth[1, 0] == pytest.approx(1.04)
    assert masks.tolist() == [[0, 0], [0, 1]]
    assert int(color[0, 0, 0]) == 40 and int(color[1, 1, 0]) == 0


def test_binned_intrinsics_project_a_point_to_the_block_it_fell_in(rp):
    frame = small_frame()
    _, _, _, cam = rp.binned(frame, 3)
    assert (cam.width, cam.height, cam.fx, cam.fy) == (2, 2, 200.0, pytest.approx(610.0 / 3))
    point = np.array([[0.001, -0.002, 1.0]])
    u, v = frame.camera.project(point)[0]
    ub, vb = cam.project(point)[0]
    assert ub == pytest.approx((u + 0.5) / 3 - 0.5) and vb == pytest.approx((v + 0.5) / 3 - 0.5)


def test_masks_grow_onto_the_background_only_and_shift_with_their_pixels(rp):
    frame = small_frame()
    _, _, grown, _ = rp.dilated(frame, 1)
    assert (grown[frame.masks > 0] == frame.masks[frame.masks > 0]).all()  # no sphere's pixels taken
    assert grown[2, 4] == 1 and grown[4, 2] == 1 and grown[0, 0] == 0
    _, _, moved, _ = rp.shifted(frame, -2, 1)
    assert (moved[4:, 1:4] == frame.masks[3:5, 3:6]).all() and (moved[:, 4:] == 0).all() and (moved[3] == 0).all()


def test_a_leaf_lies_in_front_with_the_frames_noise_and_loses_depth_along_its_edge(rp):
    frame = read_frame(rp.FRAMES / "lab-spheres-0")
    _, over, drawn, _ = rp.leafed(frame, "side", 0.05, cut=False)
    _, _, cut, _ = rp.leafed(frame, "side", 0.05, cut=True)
    assert (drawn == frame.masks).all()
    hidden = (frame.masks == 3) & (cut == 0)
    assert 0.2 < hidden.sum() / (frame.masks == 3).sum() < 0.5  # the left 35 % of its width, less the edge
    seen = frame.depth[(frame.masks == 3) & (frame.depth > 0)]
    leaf = over[hidden & (over > 0)]
    assert len(leaf) and np.abs(np.median(leaf) - (np.percentile(seen, 1) - 0.05)) < 0.002
    sigma = rp.noise_level(frame.depth)  # the frame's own: its depth is smooth to well under its 1 mm unit
    assert 0.0 < sigma < 0.001 and 0.5 * sigma < np.std(leaf) < 2.0 * sigma
    assert (over[hidden] == 0).any()  # its edge holds no depth (the camera's mixed pixels)


def test_a_painted_leaf_changes_the_colour_of_its_own_pixels_alone_and_not_the_depth_or_the_masks(rp):
    """The ``-green`` perturbations (docs/strip58.md): the leaf and its lost edge take a leaf's colour; its depth and
    the masks are the unpainted leaf's to the bit (the paint draws from a stream of its own)."""
    frame = read_frame(rp.FRAMES / "lab-spheres-0")
    for shape in ("strip", "side"):
        color, depth, masks, _ = rp.leafed(frame, shape, 0.05, cut=True)
        painted, depth_p, masks_p, _ = rp.leafed(frame, shape, 0.05, cut=True, paint=rp.LEAF_GREEN)
        assert (color == frame.color).all() and (depth_p == depth).all() and (masks_p == masks).all()
        changed = (painted != frame.color).any(axis=2)
        assert changed.sum() > 1000
        assert np.abs(painted[changed].astype(np.float64).mean(axis=0) - rp.LEAF_GREEN).max() < 2.0
        if shape == "strip":  # (a side leaf lies in part at the depth of the next sphere's surface)
            leaf = (np.abs(depth.astype(np.float64) - frame.depth) > 0.01) | (depth == 0)  # 5 cm in front, no depth
            assert not (changed & ~leaf).any()


def spheres(rp, name, settings=None, frame_name="lab-spheres-0"):
    """Every sphere's box of frame ``frame_name`` (0) under perturbation ``name`` and its reference diameter (mm),
    the unperturbed mask's at the box's depth (the scorer's: ``evaluate_spheres``); ``settings`` as ``detect``'s."""
    frame = read_frame(rp.FRAMES / frame_name)
    color, depth, masks, cam = rp.PERTURBATIONS[name](frame)
    found = detect(Frame(name=name, color=color, depth=depth, camera=cam, masks=masks), method="evidence",
                   settings=settings)  # fmt: skip
    focal = float(np.sqrt(frame.camera.fx * frame.camera.fy))  # the unperturbed mask's pixels: the frame's camera
    out = []
    for d in found.detections:
        assert d.result is not None, d.error
        area = float((frame.masks == d.id).sum())
        out.append((d.id, d.result.box.size * 1000.0, 2000.0 * np.sqrt(area / np.pi) * d.result.box.centre[2] / focal))
    return out


@pytest.mark.parametrize("name", ["rim3", "shift+10x", "shift-5x"])
def test_the_default_keeps_every_sphere_a_cube_under_a_wider_lost_rim_and_masks_shifted_across(rp, name):
    boxes = spheres(rp, name)
    assert len(boxes) == 4
    for k, size, diameter in boxes:
        assert np.ptp(size) <= 6.0 and abs(size[2] - diameter) <= 6.0, (name, k, size, diameter)


def test_binned_three_times_every_sphere_keeps_its_points_and_the_small_ones_are_cubes(rp):
    """At 3 x 3 binning (5 mm a pixel at 1.5 m) extraction's fixed 6 mm clustering distance broke spheres 1 and 4 into
    single pixels and both failed (6 of 1,033 points kept); the distance is now four pixel footprints there
    (``extract.cluster_gap``). Sphere 1 comes out 198 x 175 x 185 mm (its bottom on the board; docs/realpert55.md,
    section 4): only the 125 and 60 mm spheres are held to the 6 mm bar."""
    boxes = spheres(rp, "bin3")
    assert len(boxes) == 4
    for k, size, diameter in boxes:
        if k in (2, 4):
            assert np.ptp(size) <= 6.0 and abs(size[2] - diameter) <= 6.0, (k, size, diameter)


def test_a_mask_drawn_two_pixels_wide_is_trimmed_where_the_camera_saw_past_opposite_sides(rp):
    """Stop 56 (docs/overshoot56.md): frame 0's masks grown by 2 px. Sphere 1 (200 mm, 120 px at 1.4 m) is seen
    past over part of its outline only (a third or more holds no depth or the board), so stop 43's rule leaves the
    mask; where opposite sides are both seen past the mask holds 3 px of background, taken off all round
    (``core.occlusion._seen_past_in_part``). Its box, 207 x 205 x 206 mm before (depth side 7.9 mm over the
    unperturbed mask's diameter), is within the 6 mm bar. Spheres 3 and 4 (white on the white checkerboard and
    board) are seen past on one side only: no opposite pair, the mask left as drawn."""
    boxes = {k: (size, diameter) for k, size, diameter in spheres(rp, "dilate2")}
    size, diameter = boxes[1]
    assert np.ptp(size) <= 6.0 and abs(size[2] - diameter) <= 6.0, (size, diameter)


def test_a_mask_drawn_ten_pixels_wide_and_seen_past_all_round_fits_the_shapes_to_the_trimmed_outline(rp):
    """Stop 58 (docs/grown58.md): frame 0's masks grown by 10 px. Sphere 1 (200 mm, 120 px at 1.4 m) is seen past
    nearly all round, and stop 43's rule cut the mask to a 199 x 194 mm outline, but the shapes were fitted to the
    mask as drawn (their box 238 x 244 x 290 mm): the box, 207 x 212 x 206 mm before (depth side 7.8 mm over the
    unperturbed mask's diameter), is now within the 6 mm bar. Spheres 3 and 4 (white on white, seen past over their
    tops only) stay as drawn (docs/overshoot56.md, left open)."""
    boxes = {k: (size, diameter) for k, size, diameter in spheres(rp, "dilate10")}
    size, diameter = boxes[1]
    assert np.ptp(size) <= 6.0 and abs(size[2] - diameter) <= 6.0, (size, diameter)


def test_a_strip_in_front_across_every_sphere_leaves_the_larger_ones_cubes(rp):
    """Stop 56 (docs/strip56.md): a strip 5 cm in front across the middle fifth of every sphere, the mask drawn over
    it, parted each sphere's points in two, and extraction kept the nearer half (sphere 1 205 x 153 x 170 mm for
    198). Both halves are now kept (``core.surface.across_occluder``): the 200, 125 and 65 mm spheres' depth sides are
    within 6 mm of the diameter and the boxes within 6.5 mm of a cube (sphere 2 125 x 126 x 120). The 60 mm sphere's
    depth side stays 53 mm (docs/strip56.md, left open)."""
    boxes = spheres(rp, "leafstrip5-over")
    assert len(boxes) == 4
    for k, size, diameter in boxes:
        if k in (1, 2, 3):
            assert np.ptp(size) <= 6.5 and abs(size[2] - diameter) <= 6.0, (k, size, diameter)


@pytest.mark.parametrize("frame_name", ["lab-spheres-0", "lab-spheres-1"])
def test_a_strip_in_front_cutting_every_mask_in_two_grows_no_sphere(rp, frame_name):
    """Stop 57 (docs/strip57.md): the strip of the test above, the mask cut by it (each mask in two pieces). The
    silhouette's parts were read as the fruit's whole outline: the moment ellipse of two pieces (frame 1's 123 mm
    sphere: 106 x 125 mm) explained the outline worse than the solids fitted to the points, which grew (that sphere
    149 x 135 x 126 mm, frame 0's 59 mm sphere 74 x 75 x 60). The hidden pixels between the parts are now the
    fruit's (``core.occlusion.bridged``): no side of any box exceeds its sphere's diameter by more than 6 mm."""
    boxes = spheres(rp, "leafstrip5-cut", frame_name=frame_name)
    assert len(boxes) == 4
    for k, size, diameter in boxes:
        assert size.max() <= diameter + 6.0, (k, size, diameter)


def test_a_leaf_cutting_a_third_of_every_mask_leaves_the_largest_sphere_as_deep_as_it_is_wide_by_the_ellipse(rp):
    """Stop 56 (docs/strip56.md): a leaf 5 cm in front over the left 35 % of every sphere, the mask cut by it. The
    depth prior's width is the cut silhouette's (65 % and 100 % of the diameter: sphere 1 184 x 196 x 169 mm for
    198); with ``evidence.cut_prior: ellipse`` (not the default) it is the ellipse through the outline's free arcs:
    sphere 1's depth side within 6 mm of its diameter. Stop 57 (docs/cutprior57.md): with ``cut_prior: sides`` (the
    ellipse read only on the cut, left, side; the default since) the 200 and 125 mm spheres' depth sides within 3 and
    12 mm (``outline``, the default before: 20-30 mm short)."""
    from symfruit.settings import from_dict

    was = from_dict({"evidence": {"cut_prior": "outline"}})
    boxes = {k: (size, diameter) for k, size, diameter in spheres(rp, "leafside5-cut", was)}
    assert boxes[1][0][2] < boxes[1][1] - 20.0  # the default before stop 57: the cut silhouette's width
    assert boxes[2][0][2] < boxes[2][1] - 15.0
    told = from_dict({"evidence": {"cut_prior": "ellipse"}})
    size, diameter = {k: (size, d) for k, size, d in spheres(rp, "leafside5-cut", told)}[1]
    assert abs(size[2] - diameter) <= 6.0, (size, diameter)
    sides = {k: (size, d) for k, size, d in spheres(rp, "leafside5-cut")}  # the default since stop 57
    assert abs(sides[1][0][2] - sides[1][1]) <= 3.0, sides[1]
    # 9 mm short on cutprior57's branch; 11.3 with stop 57's support radius merged (half the larger side: the cut
    # sphere's reach is longer, its depth 2.4 mm shorter; docs/shift57.md), against 25 mm with ``outline``
    assert abs(sides[2][0][2] - sides[2][1]) <= 12.0, sides[2]


def test_a_leaf_cutting_a_third_of_every_mask_leaves_the_larger_spheres_as_wide_as_they_are_across_the_cut(rp):
    """Stop 58 (docs/cut58.md): the leaf of the test above. The box's side across the cut (x) was pulled towards the
    cut silhouette's left face, the leaf's edge, though the shapes fitted the sphere whole there (sphere 1
    183 x 196 x 198 mm for 198, its cone 196 mm wide; ``cut_faces: region``). With ``cut_faces: sides`` (the default)
    that face is where the ellipse through the free arcs ends: the 200 mm sphere's x side within 3 mm of its diameter,
    the 125 mm sphere's within 10 (from 15 short); the free sides (y) as they were."""
    from symfruit.settings import from_dict

    was = {
        k: (size, d) for k, size, d in spheres(rp, "leafside5-cut", from_dict({"evidence": {"cut_faces": "region"}}))
    }
    now = {k: (size, d) for k, size, d in spheres(rp, "leafside5-cut")}
    assert was[1][0][0] < was[1][1] - 10.0 and was[2][0][0] < was[2][1] - 10.0, (was[1], was[2])
    assert abs(now[1][0][0] - now[1][1]) <= 3.0, now[1]
    assert abs(now[2][0][0] - now[2][1]) <= 10.0, now[2]
    for k in (1, 2):
        assert now[k][0][1] == pytest.approx(was[k][0][1], abs=0.5)


def test_a_leaf_cutting_a_third_of_the_66_mm_sphere_no_longer_runs_its_box_far_below_the_widest_extent_seen(rp):
    """Stop 59 (docs/leafcut59.md): the leaf of the tests above, frame 1. A solid of revolution (weight 0.9) reaches
    38 mm below sphere 3's cut silhouette, down behind the leaf, and the box was 106 mm tall for 66 (``cut_reach:
    contour``: the bottom face pulled in by the prior's share times the contour share squared, 0.1). With ``widest``
    (the default) the part of the box beyond the outline's widest extent seen is pulled in by the prior's share
    (0.7): within 15 mm of the diameter. The other spheres' y sides move by 1 mm at most. Both read with stop 62's
    registration and depth fusion (``occluder_edges`` off, ``lost_rim: pull``), where the contrast was measured; the
    defaults since stop 63 keep sphere 3 within 15 mm too."""
    from symfruit.settings import from_dict

    stop62 = {"extract": {"occluder_edges": False}, "evidence": {"lost_rim": "pull"}}
    before = from_dict({**stop62, "evidence": {"lost_rim": "pull", "cut_reach": "contour"}})
    was = {k: (size, d) for k, size, d in spheres(rp, "leafside5-cut", before, "lab-spheres-1")}
    now = {k: (size, d) for k, size, d in spheres(rp, "leafside5-cut", from_dict(stop62), "lab-spheres-1")}
    assert was[3][0][1] > was[3][1] + 30.0, was[3]
    assert now[3][0][1] < now[3][1] + 15.0, now[3]
    for k in (1, 2, 4):
        assert now[k][0][1] == pytest.approx(was[k][0][1], abs=1.0), (k, now[k], was[k])
    default = {k: (size, d) for k, size, d in spheres(rp, "leafside5-cut", None, "lab-spheres-1")}
    assert default[3][0][1] < default[3][1] + 15.0, default[3]


@pytest.mark.parametrize("frame_name", ["lab-spheres-0", "lab-spheres-1"])
def test_a_leaf_cutting_a_third_of_the_small_spheres_leaves_them_cubes_by_the_circle_through_their_free_arcs(
    rp, frame_name
):
    """Stop 60 (docs/cut60.md): the leaf of the tests above. Spheres 3 and 4 (66 and 60 mm, 59 and 43 px across) had
    no ellipse through their free arcs (docs/cut58.md 1.3), so the depth prior read the cut region's geometric mean
    (54 and 47 mm), and the boxes were over the issue's 6 mm bar (frame 1: 58 x 79 x 62 and 39 x 61 x 44 mm;
    ``cut_circle: off``). The circle through the free arcs (``free``, the default) gives the prior the diameter: each a
    cube within 6 mm, its depth side within 6 mm of the unperturbed mask's diameter; the large spheres (their
    ellipses accepted) unchanged to the bit. Both read with stop 62's registration and depth fusion, where the
    contrast was measured (with ``lost_rim: bound`` the prior holds these depths without the circle too); the
    defaults since stop 63 keep spheres 3 and 4 cubes as well."""
    from symfruit.settings import from_dict

    stop62 = {"extract": {"occluder_edges": False}, "evidence": {"lost_rim": "pull"}}
    before = from_dict({**stop62, "evidence": {"lost_rim": "pull", "cut_circle": "off"}})
    was = {k: (size, d) for k, size, d in spheres(rp, "leafside5-cut", before, frame_name)}
    now = {k: (size, d) for k, size, d in spheres(rp, "leafside5-cut", from_dict(stop62), frame_name)}
    default = {k: (size, d) for k, size, d in spheres(rp, "leafside5-cut", None, frame_name)}
    for k in (3, 4):
        assert np.ptp(was[k][0]) > 6.0 or abs(was[k][0][2] - was[k][1]) > 6.0, (k, was[k])
        assert np.ptp(now[k][0]) <= 6.0 and abs(now[k][0][2] - now[k][1]) <= 6.0, (k, now[k])
        assert np.ptp(default[k][0]) <= 6.0 and abs(default[k][0][2] - default[k][1]) <= 6.0, (k, default[k])
    for k in (1, 2):
        assert np.asarray(now[k][0]).tolist() == np.asarray(was[k][0]).tolist(), (k, now[k], was[k])


# --- stop 56, support56: a support at the fruit's own depth is no occluder


@pytest.mark.parametrize("name", ["shift+5y", "bin2-rim1"])
def test_the_66_mm_sphere_on_its_board_is_a_cube_with_its_mask_down_on_the_board(rp, name):
    """Sphere 3 (66 mm) stands on a board. With its mask moved 5 px down onto the board (``shift+5y``), or binned 2x2
    with a lost rim a pixel wider (its mask a few pixels down after registration), the board just below it, at its own
    depth, was read as something that may hide it: a solid of revolution reaching 25-33 mm down behind the board won,
    the box 84-94 mm tall. The board's face lies half a radius behind the sphere's front, and behind it a round fruit
    can reach only 13-17 % of its radius (``occlusion.supports``, ``core.occlusion.support_reach``; stop 56,
    docs/support56.md): a cube within 6 mm, as every sphere at ``shift+5y``; at ``bin2-rim1`` every sphere with the
    200 mm sphere's shaded limb kept (``trim_keeps_surface``, on by default since stop 61: docs/small61.md)."""
    boxes = spheres(rp, name)
    assert len(boxes) == 4
    for k, size, diameter in boxes:  # binned, without trim_keeps_surface the 200 mm sphere was 182 mm tall
        assert np.ptp(size) <= 6.0 and abs(size[2] - diameter) <= 6.0, (name, k, size, diameter)


# --- stop 57, shift57: the 200 mm sphere's shaded lower limb taken by the colour trim


def test_binned_the_colour_trim_takes_the_200_mm_spheres_lower_limb_unless_it_keeps_the_fruits_surface(rp):
    """Stop 57 (docs/shift57.md): binned 3 x 3, the colour trim takes about 100 px of the 200 mm sphere's shaded lower
    half (the band, 4 binned px, reaches three times as far into the limb as at full resolution, where it takes
    none): the box 198 x 175 x 185 mm with ``trim_keeps_surface`` off. Those pixels' depth lies on the sphere's own
    convex cap, and the cut is one side of the mask (29 % of its outline); with ``trim_keeps_surface`` (on by default
    since stop 61, the pixels given back after the registration: docs/small61.md) they are kept and every sphere is
    within 6 mm of a cube and of its diameter."""
    from symfruit.settings import from_dict

    short = {k: size for k, size, _ in spheres(rp, "bin3", from_dict({"extract": {"trim_keeps_surface": False}}))}[1]
    assert short[1] < 190.0  # the colour alone: the limb taken
    boxes = spheres(rp, "bin3")  # the default
    assert len(boxes) == 4
    for k, size, diameter in boxes:
        assert np.ptp(size) <= 6.0 and abs(size[2] - diameter) <= 6.0, (k, size, diameter)


# --- stop 58, trim58: the fruit's cap keeps pixels of a one-sided colour cut alone


def test_grown_5_px_the_colour_cut_lies_all_round_and_the_fruits_cap_keeps_none_of_it(rp):
    """Stop 58 (docs/trim58.md): grown 5 px, every mask's colour cut lies all round its outline (85-100 %), and with
    ``trim_keeps_surface`` the cap keeps none of it, though near the 200 mm sphere's bottom the depth sits 5-11 px
    below its colour edge and its cap runs on over the overshoot there (stop 57's rule kept it: 200 x 208 x 204 mm,
    sphere 2 126 x 140 x 129). Stop 62 (docs/grown62.md): of frame 0's 200 mm sphere the colour cuts 5 px all round
    but 12 px at its shaded bottom, 7 px of the sphere itself (the colour's trim alone: 200 x 187 x 192 mm, its centre
    6 mm high); what it cut deeper than the 5 px is given back where it lies on the cap: 200 x 199 x 198 mm (its
    unperturbed box 200 x 198 x 198), and none of the overshoot."""
    from symfruit.settings import from_dict

    boxes = {k: size for k, size, _ in spheres(rp, "dilate5", from_dict({"extract": {"trim_keeps_surface": True}}))}
    assert 193.0 < boxes[1][1] < 203.0 and boxes[2][1] < 135.0


# --- stop 61, small61: the fruit's cap keeps the limb after the registration, which it cannot move


def test_binned_2x_the_limb_is_kept_after_the_registration_and_moves_no_shift(rp):
    """Stop 61 (docs/small61.md): binned 2 x 2, frame 1 registers by (1, 4) px with the colour's trim, and the
    200 mm sphere's shaded limb, which that trim takes, is given back after the registration (``extract.keep_caps``,
    the default): the same shift as with ``trim_keeps_surface`` off, the sphere 198 x 196 x 197 mm (off: 198 x 182 x
    189), and with a pool of one worker (each mask trimmed on it, the limb given back here) the same boxes. With
    stop 62's registration (``occluder_edges`` off), where the shift was (1, 4); since stop 63 it is (0, 0)."""
    from symfruit.fruitpool import FruitPool
    from symfruit.settings import from_dict

    frame = read_frame(rp.FRAMES / "lab-spheres-1")
    color, depth, masks, cam = rp.PERTURBATIONS["bin2"](frame)
    binned = Frame(name="bin2", color=color, depth=depth, camera=cam, masks=masks)
    stop62 = {"extract": {"occluder_edges": False}}
    kept = detect(binned, method="evidence", settings=from_dict(stop62))
    off = detect(binned, method="evidence", settings=from_dict({"extract": {"occluder_edges": False,
                                                                          "trim_keeps_surface": False}}))  # fmt: skip
    assert kept.registration == off.registration == (1, 4)
    assert detect(binned, method="raw").registration == (0, 0)
    tall = {d.id: d.result.box.size[1] * 1000.0 for d in kept.detections}
    short = {d.id: d.result.box.size[1] * 1000.0 for d in off.detections}
    assert short[1] < 185.0 and tall[1] > 194.0
    with FruitPool(1, method=None) as pool:
        pooled = detect(binned, method="evidence", settings=from_dict(stop62), pool=pool)
    assert pooled.registration == kept.registration
    for a, b in zip(kept.detections, pooled.detections, strict=True):
        assert np.array_equal(a.mask, b.mask) and np.allclose(a.result.box.min, b.result.box.min, atol=1e-9)


def test_the_centre_offsets_are_distances_to_the_same_methods_unperturbed_box(rp):
    """Stop 61: how far a box sits from where the unperturbed frame put the same sphere's box (the sizes alone did
    not show a mask drawn 5 px off moving its box with it); boxes without a centre or a reference are left out."""
    from symfruit.evaluate.spheres import SphereBox

    none = {("f", 1, "evidence"): SphereBox("f", 1, "evidence", (60.0,) * 3, 60.0, centre=(0.0, 0.0, 1000.0)),
            ("f", 2, "evidence"): SphereBox("f", 2, "evidence", (np.nan,) * 3, np.nan, "failed")}  # fmt: skip
    rows = [SphereBox("f", 1, "evidence", (60.0,) * 3, 60.0, centre=(3.0, 4.0, 1000.0)),  # 5 mm off
            SphereBox("f", 1, "evidence", (60.0,) * 3, 60.0, centre=(0.0, 0.0, 988.0)),  # 12 mm nearer
            SphereBox("f", 1, "evidence", (60.0,) * 3, 60.0),  # no centre recorded
            SphereBox("f", 2, "evidence", (60.0,) * 3, 60.0, centre=(0.0, 0.0, 1.0)),  # its reference failed
            SphereBox("g", 1, "evidence", (60.0,) * 3, 60.0, centre=(0.0, 0.0, 1.0))]  # no reference  # fmt: skip
    assert rp.centre_offsets(rows, none).tolist() == pytest.approx([5.0, 12.0])
    assert rp._mean_worst(rp.centre_offsets(rows, none)) == "8.5 / 12.0" and rp._mean_worst(np.array([])) == "-"


# --- stop 62, leaf62: a leaf's lost edge is not the fruit's silhouette for the registration


CUT_SHIFTS = [
    ("leafstrip5-cut", "lab-spheres-0", (-4, 3)),
    ("leafstrip5-cut", "lab-spheres-1", (0, 5)),
    ("leafside5-cut-green", "lab-spheres-1", (-1, 11)),
]


@pytest.mark.parametrize(("name", "frame_name", "off_shift"), CUT_SHIFTS)
def test_a_leaf_cutting_the_masks_moves_them_only_where_its_lost_edge_reads_as_a_silhouette(
    rp, name, frame_name, off_shift
):
    """Stop 62 (docs/leaf62.md): with a strip or a leaf 5 cm in front cutting every mask, the registration moved the
    masks 3-11 px (the real frames are registered to 0): the band of depth the camera loses along the leaf's edge
    was read as the spheres' silhouettes. With ``extract.occluder_edges`` (the default since stop 63) it is a
    junction and the frame keeps its masks; with a pool of one worker (each mask's outline found on it) the same
    shift."""
    from symfruit.fruitpool import FruitPool
    from symfruit.settings import from_dict

    frame = read_frame(rp.FRAMES / frame_name)
    color, depth, masks, cam = rp.PERTURBATIONS[name](frame)
    cut = Frame(name=name, color=color, depth=depth, camera=cam, masks=masks)
    off = from_dict({"extract": {"occluder_edges": False}})
    assert detect(cut, method="raw", settings=off).registration == off_shift
    assert detect(cut, method="raw").registration == (0, 0)
    with FruitPool(1, method=None) as pool:
        assert detect(cut, method="raw", pool=pool).registration == (0, 0)


@pytest.mark.parametrize("frame_name", ["lab-spheres-0", "lab-spheres-1"])
def test_a_leaf_drawn_into_the_60_mm_spheres_mask_is_passed_over_though_its_flattened_cap_reads_below_a_fruits(
    rp, frame_name
):
    """Stop 62 (docs/true62.md): a leaf 5 cm in front of the left 35 % of every sphere, the mask drawn over it, at
    the frames' true registration (no shift). The 60 mm sphere's mask holds the leaf (347 px, flat: its curvature 0)
    and the sphere (562 px behind it). The time-of-flight camera flattens that cap: its fit reads a curvature of 0.18
    / R, 12 standard errors above 0 but below a fruit's (``THIN[1]``) and even a sheet's bound (``THIN[0]``), so
    nothing behind the leaf was taken and extraction kept the leaf alone (every point at one depth: the completion
    failed, "all points lie on a plane"). Behind a sheet told flat a part convex at two standard errors and more
    curved than the sheet is now the fruit."""
    from symfruit.extract import extract

    frame = read_frame(rp.FRAMES / frame_name)
    _, depth, masks, cam = rp.PERTURBATIONS["leafside5-over"](frame)
    z = np.asarray(depth, np.float64)
    mask = masks == 4
    leaf = float(np.percentile(z[mask & (z > 0)], 1))  # the leaf's depth: the nearest in the mask
    points = extract(mask, z, cam).points
    assert len(points) >= 400
    assert float(np.min(points[:, 2])) > leaf + 0.04  # the sphere's, 5 cm behind the leaf


@pytest.mark.parametrize("name", ["leafstrip5-cut", "leafstrip5-cut-green"])
def test_a_strip_cutting_every_mask_in_two_leaves_every_sphere_a_cube_by_the_ring_without_the_strip(rp, name):
    """Strip64 (docs/strip64.md): the strip of the test above, unpainted (the sphere's own white) or painted a leaf's
    green. The colour trim compared each cut mask's band with a ring lying on the strip, and took the 125 mm
    sphere's band all round (unpainted: 120 x 121 x 116 mm) or its shaded lower limb (painted: the halves then not
    joined, 121 x 102 x 109). Done again after the registration with the strip left out of the ring
    (``extract.trim_front_ring``, on by default since stripb64), every sphere of frame 0 is a cube within 6 mm of its
    diameter; off, sphere 2 is not (its depth side 10 mm short, or 20 mm across)."""
    off = from_dict({"extract": {"trim_front_ring": False}})
    for k, size, diameter in spheres(rp, name):
        assert np.ptp(size) <= 6.0 and abs(size[2] - diameter) <= 6.0, (name, k, size, diameter)
    size, diameter = next((size, d) for k, size, d in spheres(rp, name, settings=off) if k == 2)
    assert np.ptp(size) > 6.0 or abs(size[2] - diameter) > 6.0, (size, diameter)
