"""Depth registered to colour: librealsense's lens models (against the SDK's own functions when pyrealsense2
imports), and known-answer alignments of a plane and a sphere seen by a depth camera with known extrinsics."""

import warnings

import numpy as np
import pytest

from symfruit import Camera, InputError
from symfruit.core.align import Lens, align_depth, deproject, project, transform

DEPTH = Camera(fx=200.0, fy=200.0, cx=79.5, cy=59.5, width=160, height=120)
COLOR = Camera(fx=260.0, fy=255.0, cx=81.0, cy=58.0, width=160, height=120)
COEFFS = (0.08, -0.12, 0.0015, -0.001, 0.02)


def rot_y(deg: float) -> np.ndarray:
    a = np.radians(deg)
    return np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])


def pixels(cam: Camera, n: int, rng: np.random.Generator) -> np.ndarray:
    return np.c_[rng.uniform(0, cam.width - 1, n), rng.uniform(0, cam.height - 1, n)]


@pytest.mark.parametrize("model", ["none", "brown_conrady", "inverse_brown_conrady"])
def test_deprojected_pixels_project_back(model):
    lens = Lens(COLOR, model, COEFFS)
    uv = pixels(COLOR, 500, np.random.default_rng(1))
    depth = np.random.default_rng(2).uniform(0.2, 2.0, 500)
    pts = deproject(lens, uv, depth)
    assert np.allclose(pts[:, 2], depth)
    if model == "inverse_brown_conrady":
        # librealsense projects this model with the *modified* forward formula, which its 10-step
        # deprojection does not invert exactly: the round trip is only as good as the SDK's own
        assert np.abs(project(lens, pts) - uv).max() < 0.5
    else:
        assert np.abs(project(lens, pts) - uv).max() < 1e-3


def test_a_pinhole_lens_is_the_camera_model():
    pts = np.array([[0.05, -0.02, 0.4], [-0.1, 0.07, 1.3]])
    assert np.allclose(project(Lens(COLOR), pts), COLOR.project(pts))
    assert np.allclose(deproject(Lens(COLOR), COLOR.project(pts), pts[:, 2]), pts)


@pytest.mark.parametrize("model", ["none", "brown_conrady", "modified_brown_conrady", "inverse_brown_conrady"])
def test_lens_models_agree_with_the_sdk(model):
    rs = pytest.importorskip("pyrealsense2")
    intr = rs.intrinsics()
    intr.width, intr.height, intr.fx, intr.fy, intr.ppx, intr.ppy = 160, 120, COLOR.fx, COLOR.fy, COLOR.cx, COLOR.cy
    intr.model, intr.coeffs = getattr(rs.distortion, model), list(COEFFS)
    lens = Lens(COLOR, model, COEFFS)
    rng = np.random.default_rng(3)
    pts = np.c_[rng.uniform(-0.2, 0.2, 50), rng.uniform(-0.15, 0.15, 50), rng.uniform(0.3, 1.0, 50)]
    sdk = np.array([rs.rs2_project_point_to_pixel(intr, p.tolist()) for p in pts])
    assert np.abs(project(lens, pts) - sdk).max() < 1e-3  # float32 in the SDK
    if model != "modified_brown_conrady":
        uv, z = pixels(COLOR, 50, rng), rng.uniform(0.3, 1.0, 50)
        sdk = np.array(
            [rs.rs2_deproject_pixel_to_point(intr, p.tolist(), float(d)) for p, d in zip(uv, z, strict=True)]
        )
        assert np.abs(deproject(lens, uv, z) - sdk).max() < 1e-5


def test_a_fronto_parallel_plane_moves_by_the_baseline_and_leaves_a_hole_not_a_smear():
    depth = np.full((DEPTH.height, DEPTH.width), 0.5)
    depth[:, :20] = 0.0  # the sensor saw nothing there
    same = Lens(DEPTH)
    out = align_depth(depth, same, same, np.eye(3), np.array([0.02, 0.0, 0.0]))
    shift = DEPTH.fx * 0.02 / 0.5  # 8 px: colour sits 2 cm to the left of depth (x grows to the right)
    assert np.allclose(out[out > 0], 0.5)
    cols = np.flatnonzero((out > 0).any(axis=0))
    assert cols.min() == 20 + int(shift) and cols.max() == DEPTH.width - 1
    assert (out[:, : 20 + int(shift)] == 0).all()  # the hole moved with the plane and stayed a hole
    assert (out[:, 20 + int(shift) :] > 0).all()  # and nothing else is missing


def test_a_sphere_lands_where_it_should_in_colour():
    centre, radius = np.array([0.03, -0.01, 0.45]), 0.04
    rotation, translation = rot_y(3.0), np.array([-0.025, 0.002, 0.004])
    depth_lens, color_lens = Lens(DEPTH), Lens(COLOR, "inverse_brown_conrady", COEFFS)

    def sphere_depth(cam: Camera, c: np.ndarray) -> np.ndarray:
        v, u = np.mgrid[0 : cam.height, 0 : cam.width]
        d = np.c_[(u.ravel() - cam.cx) / cam.fx, (v.ravel() - cam.cy) / cam.fy, np.ones(u.size)]
        b, cc = d @ c, c @ c - radius**2
        disc = b**2 - (d * d).sum(axis=1) * cc
        t = (b - np.sqrt(np.maximum(disc, 0))) / (d * d).sum(axis=1)
        return np.where(disc > 0, t, 0.0).reshape(cam.height, cam.width)

    depth = sphere_depth(DEPTH, centre)
    out = align_depth(depth, depth_lens, color_lens, rotation, translation)
    seen = out > 0
    # the sphere's centre, moved into colour and projected through the distorted lens
    expected = project(color_lens, transform(centre[None], rotation, translation))[0]
    v, u = np.nonzero(seen)
    assert np.hypot(u.mean() - expected[0], v.mean() - expected[1]) < 0.6
    # every aligned depth is the sphere's surface in the colour frame: deproject and measure the radius
    pts = deproject(color_lens, np.c_[u, v].astype(float), out[seen])
    c_colour = transform(centre[None], rotation, translation)[0]
    err = np.abs(np.linalg.norm(pts - c_colour, axis=1) - radius)
    footprint = 0.5 * 0.45 / DEPTH.fx * 4  # half a depth pixel, and the slope near the rim
    assert np.median(err) < 1e-3 and np.percentile(err, 95) < footprint


def test_the_nearest_depth_wins_where_two_land_on_one_pixel():
    depth = np.full((DEPTH.height, DEPTH.width), 1.0)
    depth[40:80, 60:100] = 0.3  # a near square in front of a far wall
    out = align_depth(depth, Lens(DEPTH), Lens(DEPTH), np.eye(3), np.array([0.03, 0.0, 0.0]))
    near = (out > 0) & (out < 0.5)
    # the square moves 20 px, the wall 6 px: the wall pixels it now covers are hidden behind it
    assert np.allclose(out[near], 0.3) and near[60, 60 + 20 : 100 + 20].all() and near.sum() == 40 * 40
    assert (out[60, 100 + 20 : 140] == np.float32(1.0)).all()
    # and the wall the depth camera could not see behind the square (6 to 20 px after its old edge) is a hole
    assert (out[60, 60 + 6 : 60 + 20] == 0).all() and (out[60, 40 : 60 + 6] == np.float32(1.0)).all()


def test_z_is_the_colour_cameras_or_the_depth_cameras():
    depth = np.full((DEPTH.height, DEPTH.width), 0.5)
    out = align_depth(depth, Lens(DEPTH), Lens(DEPTH), np.eye(3), np.array([0.0, 0.0, 0.01]))
    assert np.allclose(out[out > 0], 0.51)
    sdk = align_depth(depth, Lens(DEPTH), Lens(DEPTH), np.eye(3), np.array([0.0, 0.0, 0.01]), z="depth")
    assert np.allclose(sdk[sdk > 0], 0.5)


def test_bad_inputs_are_refused():
    with pytest.raises(InputError, match="unknown lens model 'fisheye'"):
        Lens(DEPTH, "fisheye")
    with pytest.raises(InputError, match="five finite numbers"):
        Lens(DEPTH, "brown_conrady", (0.1, 0.2))
    with pytest.raises(InputError, match="cannot be deprojected"):
        deproject(Lens(DEPTH, "modified_brown_conrady"), np.zeros((1, 2)), np.ones(1))
    with pytest.raises(InputError, match="depth image is 10x10, its intrinsics 160x120"):
        align_depth(np.ones((10, 10)), Lens(DEPTH), Lens(COLOR), np.eye(3), np.zeros(3))
    with pytest.raises(InputError, match="extrinsics"):
        align_depth(np.ones((120, 160)), Lens(DEPTH), Lens(COLOR), np.full((3, 3), np.nan), np.zeros(3))
    with pytest.raises(InputError, match="z must be"):
        align_depth(np.ones((120, 160)), Lens(DEPTH), Lens(COLOR), np.eye(3), np.zeros(3), z="both")
    assert not align_depth(np.zeros((120, 160)), Lens(DEPTH), Lens(COLOR), np.eye(3), np.zeros(3)).any()


@pytest.mark.parametrize(
    "color_lens, translation",
    [
        (Lens(COLOR, "brown_conrady", (1e30,) * 5), np.zeros(3)),  # a recorded lens model gone wild
        (Lens(COLOR), np.array([1e12, 0.0, 0.0])),  # everything lands far off the image
    ],
)
def test_depth_landing_far_off_the_colour_image_is_dropped_without_overflow(color_lens, translation):
    depth = np.full((DEPTH.height, DEPTH.width), 0.5)
    with np.errstate(all="raise"), warnings.catch_warnings():
        warnings.simplefilter("error")  # no "invalid value encountered in cast" from far-off pixel indices
        out = align_depth(depth, Lens(DEPTH), color_lens, np.eye(3), translation)
        # a wide depth lens whose distortion denominator 1 + k1 r^2 passes 0 (k1 = -1): divides by zero
        wide = Camera(fx=60.0, fy=60.0, cx=79.5, cy=59.5, width=160, height=120)
        wild = Lens(wide, "brown_conrady", (-1.0, 0, 0, 0, 0))
        assert np.isfinite(align_depth(depth, wild, color_lens, np.eye(3), translation)).all()
    assert out.shape == (COLOR.height, COLOR.width) and np.isfinite(out).all()
    if translation[0]:
        assert not out.any()
