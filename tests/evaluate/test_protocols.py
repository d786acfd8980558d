"""Evaluation protocols: Algorithm 2 of the paper, and rendered D435-like camera views."""

import numpy as np
import pytest

from symfruit import DEFAULT_CAMERA
from symfruit.evaluate.protocols import PAPER_ANGLES, PAPER_DISTANCE, SENSORS, Spec, build, specs
from symfruit.evaluate.protocols import _inside as inside_polygon
from symfruit.synthetic.sensors import SENSOR_MODELS


def test_paper_protocol_is_algorithm_2():
    all_specs = specs("paper", "strawberry", n=10)
    assert len(all_specs) == 190 and len(PAPER_ANGLES) == 19
    assert PAPER_ANGLES[0] == -45 and PAPER_ANGLES[-1] == 45
    inst = build(all_specs[0])
    assert 100 < len(inst.visible) < 600
    assert inst.truth_box.contains(inst.visible)
    assert np.allclose(inst.truth_box.centre, [0, 0, PAPER_DISTANCE])
    again = build(all_specs[0])
    assert np.array_equal(inst.visible, again.visible)
    # The same 600 points in every pose of a fruit: the truth box volume changes only by rotation.
    other = build(all_specs[9])
    assert len(other.truth_surface) == len(inst.truth_surface) == 600


def test_camera_protocol_instances():
    spec = specs("camera", "strawberry", n=3, occlusions=(0.0, 0.3))
    assert len(spec) == 6
    clear, covered = build(spec[0]), build(spec[3])
    assert clear.hidden == 0.0 and 0.2 < covered.hidden < 0.4
    assert 0.25 <= clear.distance <= 0.6
    assert len(covered.visible) < len(clear.visible)
    # Noisy points lie near the true surface, and inside an enlarged truth box.
    assert clear.truth_box.contains(clear.visible, tol=0.01)
    from scipy.spatial import cKDTree

    d, _ = cKDTree(clear.truth_surface).query(clear.visible)
    assert np.median(d) < 0.003


def test_specs_enumerate_fruits_poses_and_occlusions():
    paper = specs("paper", "apple", n=2, seed=3, angles=(-45, 0, 45))
    assert [(s.index, s.pose) for s in paper] == [(0, 0), (0, 9), (0, 18), (1, 0), (1, 9), (1, 18)]
    assert all(s.protocol == "paper" and s.fruit == "apple" and s.seed == 3 for s in paper)
    camera = specs("camera", "tomato", n=2, occlusions=(0.0, 0.5))
    assert [(s.index, s.pose, s.occlusion) for s in camera] == [(0, 0, 0.0), (1, 1, 0.0), (0, 0, 0.5), (1, 1, 0.5)]
    with pytest.raises(ValueError, match="unknown protocol 'lab'; use paper or camera"):
        specs("lab", "apple", n=1)


def test_views_of_one_generated_fruit():
    camera = specs("camera", "pear", n=6, views=3, sensor="heldback")
    assert [(s.index, s.pose) for s in camera] == [(0, 0), (0, 1), (0, 2), (1, 3), (1, 4), (1, 5)]
    a, b, c = (build(s) for s in camera[:2] + camera[3:4])
    # the same fruit (one shape, its truth surface the same up to pose and place) seen from two views
    assert a.kind == b.kind and len(a.truth_surface) == len(b.truth_surface)
    extent = [np.sort(np.linalg.svd(i.truth_surface - i.truth_surface.mean(0), compute_uv=False)) for i in (a, b, c)]
    assert np.allclose(extent[0], extent[1], rtol=1e-9) and not np.allclose(extent[0], extent[2], rtol=1e-3)
    assert not np.array_equal(a.visible, b.visible)
    assert specs("camera", "pear", n=4) == specs("camera", "pear", n=4, views=1)
    with pytest.raises(ValueError, match="views must be 1-100000"):
        specs("camera", "pear", n=4, views=0)


def test_instances_are_built_from_their_spec_alone():
    spec = Spec("camera", "citrus", 1, 4, 0.0, seed=7)
    a, b = build(spec), build(Spec("camera", "citrus", 1, 4, 0.0, seed=7))
    assert np.array_equal(a.visible, b.visible) and np.array_equal(a.truth_box.min, b.truth_box.min)
    other = build(Spec("camera", "citrus", 1, 4, 0.0, seed=8))
    assert not np.array_equal(other.visible, a.visible)
    assert a.spec == spec and a.kind == "citrus" and -45 <= a.angles[0] <= 45 and -45 <= a.angles[2] <= 45


def test_paper_poses_rotate_the_same_fruit_about_x():
    flat, tilted = build(Spec("paper", "tomato", 0, PAPER_ANGLES.index(0))), build(Spec("paper", "tomato", 0, 0))
    assert tilted.angles == (-45.0, 0.0, 0.0) and flat.angles == (0.0, 0.0, 0.0)
    # The same 600 points, rotated about x by -45 degrees (up to the move of the box centre).
    centred = [s.truth_surface - s.truth_box.centre for s in (flat, tilted)]
    c, s = np.cos(np.radians(-45)), np.sin(np.radians(-45))
    rx = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    rotated = centred[0] @ rx.T
    assert np.allclose(rotated - (rotated.min(axis=0) + rotated.max(axis=0)) / 2, centred[1], atol=1e-12)
    assert flat.distance == PAPER_DISTANCE and flat.camera.width == 640


def test_the_polygon_test_of_the_occluder():
    square = np.array([[0, 0], [4, 0], [4, 4], [0, 4]], float)
    pts = np.array([[1, 1], [3.9, 0.1], [5, 1], [-1, 2], [2, 4.5]], float)
    assert inside_polygon(square, pts).tolist() == [True, True, False, False, False]


def test_the_heldback_sensor_sees_every_pixel_of_the_fruit():
    from symfruit.synthetic.render import render

    from ..conftest import ball_mesh

    noise = SENSORS["heldback"].noise
    assert noise.sigma(0.4) == pytest.approx(0.01 * 0.4**2) and SENSORS["heldback"].distance == (0.30, 0.50)
    ball = ball_mesh().transformed(np.eye(3), np.array([0.0, 0.0, 0.4]))
    shot = render([(ball.vertices, ball.faces)], DEFAULT_CAMERA)
    depth, _ = noise.apply(shot, np.random.default_rng(0))
    seen = shot.ids == 0
    assert np.all(depth[seen] > 0) and np.all(depth[~seen] == 0)  # no dropout, not even at the edge
    z = shot.depth[seen]
    assert np.std((depth[seen] - z) / (0.01 * z**2)) == pytest.approx(1.0, rel=0.05)
    d435, _ = SENSORS["d435"].noise.apply(shot, np.random.default_rng(0))
    assert (d435[seen] == 0).sum() > 0.01 * seen.sum()
    inst = build(Spec("camera", "apple", 0, 2, sensor="heldback"))
    assert 0.30 <= inst.distance <= 0.50


def test_pose_distributions():
    uniform = [build(Spec("camera", "lemon", 0, k, poses="uniform")) for k in range(3)]
    assert all(np.isnan(u.angles[0]) for u in uniform) and len({len(u.visible) for u in uniform}) == 3
    with pytest.raises(ValueError, match="unknown pose distribution"):
        Spec("camera", "lemon", 0, 0, poses="sideways")
    with pytest.raises(ValueError, match="unknown sensor"):
        Spec("camera", "lemon", 0, 0, sensor="kinect")
    with pytest.raises(ValueError, match="camera protocol"):
        Spec("paper", "lemon", 0, 0, poses="uniform")
    # A generated fruit already hangs stem up: "upright" changes nothing for it.
    a, b = build(Spec("camera", "pear", 1, 1)), build(Spec("camera", "pear", 1, 1, poses="upright"))
    assert np.array_equal(a.visible, b.visible)


def test_upright_stands_a_scan_up(tmp_path):
    from symfruit.io import write_ply
    from symfruit.synthetic.shapes import FRUITS

    fruit = FRUITS["lemon"](np.random.default_rng(0))  # long axis along y; stood on end: along z in the file
    write_ply(tmp_path / "lemon.ply", fruit.sample(4000, np.random.default_rng(0))[:, [0, 2, 1]] * [1, 1, -1])
    lying = build(Spec("paper", str(tmp_path), 0, PAPER_ANGLES.index(0)))
    upright = build(Spec("paper", str(tmp_path), 0, PAPER_ANGLES.index(0), poses="upright"))
    assert lying.kind == "scan/lemon"
    assert np.argmax(upright.truth_box.size) == 1 and np.argmax(lying.truth_box.size) == 2


def test_a_view_with_an_occluder_keeps_its_depth_and_mask():
    from symfruit.occlusion import OcclusionSettings, fruit_occlusion

    clear, covered = (
        build(Spec("camera", "apple", 0, 0, 0.0, sensor="heldback")),
        build(Spec("camera", "apple", 0, 0, 0.4, sensor="heldback")),
    )
    assert clear.depth is None and clear.mask is None  # the held-back measurement: points and camera only
    assert covered.depth is not None and covered.mask.sum() == len(covered.visible)
    occ = fruit_occlusion(covered.depth, covered.mask, covered.visible, covered.camera, OcclusionSettings())
    assert occ is not None and occ.hidden.sum() > 0.2 * covered.mask.sum()
    assert fruit_occlusion(covered.depth, covered.mask, covered.visible, covered.camera,
                           OcclusionSettings(enabled=False)) is None  # fmt: skip


@pytest.mark.parametrize("name", list(SENSOR_MODELS))
def test_a_real_camera_view_is_extracted_under_the_annotators_mask(name):
    model = SENSOR_MODELS[name]
    inst = build(Spec("camera", "apple", 0, 0, 0.25, 0, name))
    again = build(Spec("camera", "apple", 0, 0, 0.25, 0, name))
    assert np.array_equal(inst.depth, again.depth) and np.array_equal(inst.visible, again.visible)
    cam, full = inst.camera, model.camera()
    assert inst.extract and inst.depth.shape == inst.mask.shape == (cam.height, cam.width)
    assert cam.fx == full.fx and cam.width <= full.width and cam.height <= full.height  # a window of the frame
    assert model.distance[0] <= inst.distance <= model.distance[1] and 0.1 < inst.hidden < 0.5
    assert inst.depth.dtype == np.float32 and (inst.depth == 0).any()  # holes: the camera's artefacts
    assert len(inst.visible) == ((inst.depth > 0) & inst.mask).sum()
    # Through the camera the mask's pixels are no longer all the fruit's own surface.
    far = inst.visible[:, 2] > inst.truth_box.max[2] + 0.005
    near = inst.visible[:, 2] < inst.truth_box.min[2] - 0.005
    assert (far | near).any()


def test_real_camera_sensors_are_named_in_specs():
    with pytest.raises(ValueError, match="azure-kinect"):
        Spec("camera", "apple", 0, 0, sensor="kinect")
    assert {s.sensor for s in specs("camera", "plum", n=2, sensor="realsense-d405")} == {"realsense-d405"}


def test_a_camera_view_through_a_varied_model():
    """``sensor_set``: the same view (fruit, pose, clutter) through the model with one artefact changed."""
    base = build(Spec("camera", "apple", 0, 0, 0.0, 0, "azure-kinect"))
    wider = build(Spec("camera", "apple", 0, 0, 0.0, 0, "azure-kinect", sensor_set=(("rim_invalid_px", 3),)))
    assert np.array_equal(wider.truth_box.min, base.truth_box.min) and np.array_equal(wider.mask, base.mask)
    assert ((wider.depth > 0) & wider.mask).sum() < ((base.depth > 0) & base.mask).sum()
    assert {s.sensor_set for s in specs("camera", "plum", n=2, sensor="realsense-d435",
                                        sensor_set=(("fatten_px", 6),))} == {(("fatten_px", 6.0),)}  # fmt: skip
    with pytest.raises(ValueError, match="sensor_set changes a real camera model"):
        Spec("camera", "apple", 0, 0, sensor="heldback", sensor_set=(("fatten_px", 6),))
    with pytest.raises(ValueError, match="fatten_px=99: must be a whole number 0 to 20"):
        Spec("camera", "apple", 0, 0, sensor="realsense-d435", sensor_set=(("fatten_px", 99),))
