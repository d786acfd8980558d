"""Synthetic RGB-D scenes of hanging strawberries: seeded, with truth that holds what was rendered."""

import numpy as np
import pytest

from symfruit import Camera
from symfruit.segment.colour import ripe_seeds
from symfruit.synthetic.render import SensorNoise
from symfruit.synthetic.scenes import Scene, SceneFruit, make_scene, write_scenes

PERFECT = SensorNoise(axial_at_03=0.0, lateral_px=0.0, edge_dropout=0.0, grazing_dropout=0.0, dropout=0.0)


#: one worker computes the module's expensive fixture once (pytest-xdist, --dist loadgroup; session scope, as
#: a worker interleaves other modules' tests and would tear a module-scoped fixture down between them)
pytestmark = pytest.mark.xdist_group("scenes")


@pytest.fixture(scope="session")
def exact():
    return make_scene(4, noise=PERFECT)


def test_the_same_seed_gives_the_same_scene():
    cam = Camera(fx=300, fy=300, cx=160, cy=120, width=320, height=240)  # small: rendering is most of the time
    a, b = (make_scene(2, n_ripe=3, n_unripe=1, n_leaves=1, camera=cam) for _ in range(2))
    assert np.array_equal(a.color, b.color) and np.array_equal(a.depth, b.depth)
    assert np.array_equal(a.labels, b.labels) and a.truth() == b.truth()
    c = make_scene(3, n_ripe=3, n_unripe=1, n_leaves=1, camera=cam)
    assert not np.array_equal(a.color, c.color) and a.truth() != c.truth()


def test_images_and_labels_have_the_cameras_size():
    cam = Camera(fx=400, fy=400, cx=160, cy=120, width=320, height=240)
    scene = make_scene(0, n_ripe=2, n_unripe=1, n_leaves=0, camera=cam)
    assert isinstance(scene, Scene) and scene.camera == cam
    assert scene.color.shape == (240, 320, 3) and scene.color.dtype == np.uint8
    assert scene.depth.shape == (240, 320) and scene.depth.dtype == np.float32 and scene.labels.dtype == np.int32
    assert set(np.unique(scene.labels).tolist()) <= {0, 1, 2, 3}


def test_truth_boxes_contain_the_rendered_fruit_points(exact):
    assert [f.id for f in exact.fruits] == list(range(1, 9))
    for fruit in exact.fruits:
        rows, cols = np.nonzero((exact.labels == fruit.id) & (exact.depth > 0))
        assert len(rows) > 50  # every fruit is seen
        points = exact.camera.deproject(np.c_[cols, rows].astype(float), exact.depth[rows, cols].astype(float))
        assert fruit.box.contains(points, tol=1e-4), fruit.id  # float32 depth: 0.1 mm
        # ... and the seen points reach across most of the box (the box is the fruit's, not a bigger one).
        assert np.ptp(points[:, 0]) > 0.7 * fruit.box.size[0] and np.ptp(points[:, 1]) > 0.7 * fruit.box.size[1]


def test_noisy_depth_stays_near_the_exact_one(exact):
    noisy = make_scene(4)
    assert np.array_equal(noisy.labels, exact.labels)
    both = (noisy.depth > 0) & (exact.depth > 0) & (exact.labels > 0)
    error = noisy.depth[both] - exact.depth[both]
    assert abs(float(np.median(error))) < 0.0005 and float(np.percentile(np.abs(error), 99)) < 0.02
    assert (noisy.depth[exact.labels > 0] == 0).mean() > (exact.depth[exact.labels > 0] == 0).mean()  # dropouts


def test_unripe_fruit_are_flagged_and_not_red(exact):
    ripe = [f for f in exact.fruits if f.ripe]
    unripe = [f for f in exact.fruits if not f.ripe]
    assert len(ripe) == 6 and len(unripe) == 2 and all(isinstance(f, SceneFruit) for f in exact.fruits)
    _, red = ripe_seeds(exact.color)  # the pixels the segmenter takes as ripe-red
    for f in ripe:
        assert red[exact.labels == f.id].mean() > 0.8
    for f in unripe:
        assert red[exact.labels == f.id].mean() < 0.02
    truth = exact.truth()["fruits"]
    assert [t["ripe"] for t in truth] == [f.ripe for f in exact.fruits]
    assert truth[0]["kind"].startswith("strawberry/") and truth[0]["centre"] == exact.fruits[0].box.centre.tolist()
    assert set(truth[0]) == {"id", "ripe", "kind", "centre", "min", "max", "size"}


def test_a_generated_recording_repeats_its_scenes_cheaply(tmp_path):
    import os

    from symfruit.io.sources import open_source

    write_scenes(tmp_path / "rec", 5, distinct=2, n_ripe=3, n_unripe=1)  # two renders of four fruit
    rec = tmp_path / "rec"
    src = open_source(rec)
    assert src.names() == [f"scene_{i:05d}" for i in range(5)]
    for i in (2, 4):  # frame i repeats scene i % 2
        for name in ("color.png", "depth.png", "camera.json", "truth.json"):
            a, b = rec / f"scene_{i:05d}" / name, rec / f"scene_{i % 2:05d}" / name
            assert a.read_bytes() == b.read_bytes()
            assert os.path.samefile(a, b) or a.stat().st_nlink == 1  # a hard link where the file system has them
    assert not np.array_equal(src.read(0).color, src.read(1).color)
    assert len(src.read(3).truth) == 3  # the ripe fruit


def test_write_scenes_never_writes_through_a_link_and_holds_its_folder(tmp_path):
    from symfruit import OutputError
    from symfruit.io.outputs import OutputFolder

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "scene_00000").symlink_to(elsewhere, target_is_directory=True)
    with pytest.raises(OutputError, match="scene_00000: is a symbolic link"):
        write_scenes(tmp_path / "out", 1, n_ripe=1, n_unripe=0, n_leaves=0)
    assert list(elsewhere.iterdir()) == []
    with OutputFolder(tmp_path / "o2"), pytest.raises(OutputError, match="another symfruit run"):
        write_scenes(tmp_path / "o2", 1)


def test_a_scene_through_a_real_camera_has_its_resolution_and_the_annotators_masks():
    from symfruit.synthetic.sensors import SENSOR_MODELS

    model = SENSOR_MODELS["realsense-d405"]
    scene = make_scene(2, n_ripe=3, n_unripe=1, n_leaves=1, sensor=model)  # seeded: tests/synthetic/test_sensors
    assert scene.color.shape == (720, 1280, 3) and scene.depth.shape == scene.masks.shape == (720, 1280)
    ripe = [f.id for f in scene.fruits if f.ripe]
    assert set(np.unique(scene.masks)) <= {0, *ripe}  # unripe fruit are not annotated
    for k in ripe:
        own = scene.labels == k
        if own.any():
            assert (scene.masks[own] == k).mean() > 0.95 and (scene.masks == k).sum() >= own.sum()
    z = np.array([f.box.centre[2] for f in scene.fruits])
    assert 0.24 <= z.min() and z.max() <= 0.52 and np.ptp(z) <= 0.1  # one cluster within the D405 range


@pytest.fixture(scope="module")
def tree():
    from symfruit.synthetic.scenes import make_tree_scene
    from symfruit.synthetic.sensors import sensor_model

    # a quarter of the Azure Kinect's 1920x1080 (the same fields of view), fewer leaves: quick to render
    return make_tree_scene(3, sensor=sensor_model("azure-kinect").at(480, 270), n_apples=12, n_green=2, n_leaves=600)


def test_an_apple_tree_frame_has_apples_of_their_size_at_their_depth(tree):
    assert tree.color.shape == (270, 480, 3) and tree.depth.shape == (270, 480) and tree.labels.shape == (270, 480)
    assert [f.kind for f in tree.fruits] == ["apple"] * 14 and sum(f.ripe for f in tree.fruits) == 12
    for f in tree.fruits:
        assert 0.055 <= f.box.size.max() <= 0.095  # 60-90 mm apples (their stems not in the box)
        assert 1.1 <= f.box.centre[2] <= 2.5
    # seen whole near the middle of the view (no perspective stretch), an apple spans about fx * diameter / z px
    cam = tree.camera
    middle = [f for f in tree.fruits if abs(f.box.centre[0] / f.box.centre[2] * cam.fx) < 0.25 * cam.width]
    f = max(middle, key=lambda f: int((tree.labels == f.id).sum()))
    rows, cols = np.nonzero(tree.labels == f.id)
    expected = tree.camera.fx * f.box.size[:2].max() / f.box.centre[2]
    assert 0.6 * expected <= max(np.ptp(rows), np.ptp(cols)) + 1 <= 1.2 * expected
    # its depth is mostly the apple's front (registration and the rim let some background in)
    z = tree.depth[rows, cols]
    assert (
        np.median(np.abs(z[z > 0] - f.box.centre[2])) < 0.05 and np.mean(np.abs(z[z > 0] - f.box.centre[2]) < 0.1) > 0.7
    )


def test_an_apple_trees_ripe_apples_are_red_its_green_ones_not(tree):
    strong, _ = ripe_seeds(tree.color)
    for f in tree.fruits:
        seen = tree.labels == f.id
        if seen.sum() >= 30:
            share = strong[seen].mean()
            assert share < 0.05 if not f.ripe else True, f.id
    ripe_seen = np.isin(tree.labels, [f.id for f in tree.fruits if f.ripe])
    assert strong[ripe_seen].mean() > 0.4  # most ripe skin is red (bicolour apples show green too)
    leaves = (tree.labels == 0) & (tree.depth > 0)
    assert strong[leaves].mean() < 0.02
    assert tree.masks is not None and set(np.unique(tree.masks)) <= {0, *(f.id for f in tree.fruits if f.ripe)}


def test_an_apple_trees_ripe_apples_say_how_much_of_them_is_seen(tree):
    """``visible``: the apple's seen pixels over its pixels rendered alone (truth.json's ``visible``)."""
    ripe = [f for f in tree.fruits if f.ripe]
    assert all(f.visible is not None and 0.0 <= f.visible <= 1.0 for f in ripe)
    assert all(f.visible is None for f in tree.fruits if not f.ripe)  # no target, not measured
    for f in ripe:
        seen = int((tree.labels == f.id).sum())
        assert (seen == 0) == (f.visible == 0.0)
        assert f.to_dict()["visible"] == pytest.approx(f.visible, abs=1e-4)
    # an apple with nothing in front of it is seen whole; some of the canopy's apples are hidden in part
    shares = sorted(f.visible for f in ripe)
    assert shares[-1] > 0.97 and shares[0] < 0.8


def test_a_written_apple_tree_frame_carries_its_truth_and_masks(tmp_path, monkeypatch):
    from symfruit.io.frames import read_frame
    from symfruit.synthetic import scenes
    from symfruit.synthetic.sensors import sensor_model

    calls, make = [], scenes.make_tree_scene

    def small_tree(seed, *, sensor=None, n_apples=30, n_green=4, photometric=None):
        calls.append((seed, sensor.name, n_apples, n_green))
        return make(seed, sensor=sensor.at(320, 180), n_apples=n_apples, n_green=n_green, n_leaves=200,
                    photometric=photometric)  # fmt: skip

    monkeypatch.setattr(scenes, "make_tree_scene", small_tree)
    [folder] = write_scenes(tmp_path / "t", 1, seed=5, n_ripe=4, n_unripe=1, sensor=sensor_model("azure-kinect"),
                            tree=True)  # fmt: skip
    assert calls == [(5, "azure-kinect", 4, 1)]
    frame = read_frame(folder)
    assert frame.masks is not None and len(frame.truth) == 4 and set(frame.visible) == {fid for fid, _ in frame.truth}


def test_a_scene_without_ripe_fruit_or_without_any_fruit_is_made_not_a_numpy_error():
    small = Camera(fx=300, fy=300, cx=160, cy=120, width=320, height=240)
    unripe_only = make_scene(2, n_ripe=0, n_unripe=2, n_leaves=2, camera=small)
    assert [f.ripe for f in unripe_only.fruits] == [False, False] and unripe_only.labels.any()
    empty = make_scene(2, n_ripe=0, n_unripe=0, n_leaves=2, camera=small)  # leaves hang in front of fruit: none
    assert empty.fruits == [] and not empty.labels.any()


def test_write_scenes_refuses_an_empty_output_path(tmp_path, monkeypatch):
    from symfruit import InputError

    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match="write_scenes: the output folder is an empty path"):
        write_scenes("", 1)  # before: scene_00000 written into the working folder
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("links", [True, False])
def test_repeated_frames_are_put_in_place_atomically_never_written_into(tmp_path, monkeypatch, links):
    import os

    out = tmp_path / "out"
    write_scenes(out, 2, distinct=1, n_ripe=1, n_unripe=0, n_leaves=0)
    keep = tmp_path / "keep.png"  # a file outside the output folder that an earlier frame file is a link to
    keep.write_bytes(b"not to be touched")
    (out / "scene_00001" / "color.png").unlink()
    os.link(keep, out / "scene_00001" / "color.png")
    if not links:  # a file system without hard links: the copies must be atomic too

        def no_link(*args, **kwargs):
            raise OSError(1, "Operation not permitted")

        monkeypatch.setattr(os, "link", no_link)
    write_scenes(out, 2, distinct=1, n_ripe=1, n_unripe=0, n_leaves=0)
    assert keep.read_bytes() == b"not to be touched"  # before: the copy was written into the linked file
    first, second = (sorted(p.name for p in (out / f"scene_0000{i}").iterdir()) for i in (0, 1))
    assert first == second  # no temporary left
    for name in first:
        a, b = out / "scene_00000" / name, out / "scene_00001" / name
        assert a.read_bytes() == b.read_bytes() and os.path.samefile(a, b) is links


def test_an_apple_trees_colour_camera_changes_the_colours_alone(tree):
    """``photometric=None``: the colours of stops 30-44 bit for bit (the digest of the base tree's frame); the
    colour camera's effects (the default) draw from an RNG of their own, so depth and labels stay the same."""
    import hashlib

    from symfruit.synthetic.scenes import make_tree_scene
    from symfruit.synthetic.sensors import sensor_model

    old = make_tree_scene(3, sensor=sensor_model("azure-kinect").at(480, 270), n_apples=12, n_green=2, n_leaves=600,
                          photometric=None)  # fmt: skip
    assert hashlib.sha256(old.color.tobytes()).hexdigest()[:16] == "b6d5367255a030f3"
    # the depth since stop 48 (an apple's stem is its own surface for the multipath, docs/azure48.md; cd188c0c62d0254a)
    assert hashlib.sha256(old.depth.tobytes()).hexdigest()[:16] == "5ac1b77560cd0bc2"
    assert np.array_equal(old.depth, tree.depth) and np.array_equal(old.labels, tree.labels)
    assert np.array_equal(old.masks, tree.masks) and old.truth() == tree.truth()
    changed = np.abs(old.color.astype(int) - tree.color).max(axis=2) > 8
    assert changed.mean() > 0.3  # shadows, exposure, white balance: most of the frame


def test_a_fruits_own_parts_are_its_surface_for_multipath():
    from symfruit.synthetic.scenes import _sensor_surfaces

    ids = np.array([[-1, 0, 1, 2], [3, 4, 5, 5]])
    # meshes 1 and 2 are fruit 0's calyx and stem, mesh 5 fruit 4's stem; -1 (nothing) stays
    assert _sensor_surfaces(ids, {1: 0, 2: 0, 5: 4}).tolist() == [[-1, 0, 0, 0], [3, 4, 4, 4]]
    assert _sensor_surfaces(ids, {}) is ids


def test_a_berrys_calyx_and_stem_push_no_multipath_into_it():
    """Through the Azure Kinect model, multipath adds 5 mm at the junction of two surfaces decaying over 2 cm; a
    berry's calyx disc and stem (separate meshes) were such junctions and put every berry 3 mm back (docs/azure48.md).
    Without leaves in front, the clutter lies 2-20 cm behind: the berries' depth is that without multipath."""
    from dataclasses import replace

    from symfruit.synthetic.sensors import sensor_model

    model = sensor_model("azure-kinect").at(960, 540)
    on = make_scene(1, n_ripe=4, n_unripe=0, n_leaves=0, sensor=model)
    off = make_scene(1, n_ripe=4, n_unripe=0, n_leaves=0, sensor=replace(model, multipath_bias=0.0))  # same draws
    for f in on.fruits:
        seen = (on.labels == f.id) & (on.depth > 0) & (off.depth > 0)
        assert seen.sum() > 200
        added = on.depth[seen] - off.depth[seen]
        assert np.median(added) == 0.0 and added.mean() < 0.0005  # the stop-47 scenes: 3 mm on every berry
