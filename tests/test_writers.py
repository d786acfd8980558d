"""Every file symfruit writes: a completion's PLY and JSON, a frame's detections (ROS 2
``vision_msgs/Detection3DArray``), PLYs and overlay, and results folders with a ``latest`` link."""

import datetime
import json
import os
import stat
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest
from plyfile import PlyData

from symfruit import FileFormatError, complete
from symfruit.detect import FrameDetections
from symfruit.writers import (
    OPTICAL_FRAME,
    check_results_root,
    detections_record,
    draw_overlay,
    new_results_folder,
    write_detections,
    write_result,
)

from .conftest import VISIBLE

#: The fields of ``vision_msgs/BoundingBox3D`` (geometry_msgs/Pose center, geometry_msgs/Vector3 size).
BOUNDING_BOX_3D = {
    "center": {"position": {"x", "y", "z"}, "orientation": {"x", "y", "z", "w"}},
    "size": {"x", "y", "z"},
}


@pytest.fixture
def found(example_found):
    return example_found


def test_outputs_map_onto_detection3d(tmp_path, found):
    written = write_detections(tmp_path, found)
    assert {p.name for p in written} >= {"detections.json", "overlay.png", "fruit_001.ply"}
    data = json.loads((tmp_path / "detections.json").read_text())
    assert data["header"]["frame_id"] == "camera_color_optical_frame" and data["frame"] == "example_frame"
    fruit = data["fruits"][0]
    for key in (
        "id",
        "mask_area",
        "n_points",
        "centre",
        "box",
        "method",
        "plane",
        "score",
        "truncated",
        "bbox",
    ):
        assert key in fruit
    bbox = fruit["bbox"]
    assert [bbox["center"]["position"][k] for k in "xyz"] == fruit["centre"]
    assert [bbox["size"][k] for k in "xyz"] == fruit["box"]["size"]
    assert bbox["center"]["orientation"] == {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}
    from PIL import Image

    overlay = np.asarray(Image.open(tmp_path / "overlay.png"))
    assert overlay.shape == (480, 640, 3)
    assert (np.abs(overlay.astype(int) - [0, 220, 255]).sum(axis=2) == 0).sum() > 100  # cyan cuboids drawn


def test_every_record_is_a_bounding_box_3d_in_the_optical_frame(found):
    data = detections_record(found)
    assert data["header"] == {"frame_id": OPTICAL_FRAME} and data["units"] == "metres"
    assert data["camera"] == found.frame.camera.to_dict() and "settings" not in data
    assert [f["id"] for f in data["fruits"]] == [d.id for d in found.detections]
    for fruit, d in zip(data["fruits"], found.detections, strict=True):
        bbox = fruit["bbox"]
        assert set(bbox) == set(BOUNDING_BOX_3D) and set(bbox["size"]) == BOUNDING_BOX_3D["size"]
        assert {k: set(v) for k, v in bbox["center"].items()} == BOUNDING_BOX_3D["center"]
        lo, hi = np.array(fruit["box"]["min"]), np.array(fruit["box"]["max"])
        centre = np.array([bbox["center"]["position"][k] for k in "xyz"])
        size = np.array([bbox["size"][k] for k in "xyz"])
        assert np.allclose(centre, (lo + hi) / 2) and np.allclose(size, hi - lo) and np.all(size > 0)
        assert fruit["n_points"] == len(d.extraction.points) and fruit["visible_box"] == d.visible_box.to_dict()
    json.dumps(data, allow_nan=False)  # plain JSON, no NaN


def test_stamps_go_into_the_header_and_failures_into_the_record(found):
    stamped = replace(found, frame=replace(found.frame, stamp=1_700_000_000_123_456_789))
    assert detections_record(stamped)["header"]["stamp"] == {"sec": 1_700_000_000, "nanosec": 123_456_789}
    failed = replace(found.detections[0], result=None, error="too few points")
    record = detections_record(replace(found, detections=[failed]))["fruits"][0]
    assert record["error"] == "too few points" and "bbox" not in record and record["id"] == failed.id
    from symfruit import Settings

    assert detections_record(found, settings=Settings())["settings"] == Settings().to_dict()


def test_counts_numpy_computed_are_written_as_json_numbers(tmp_path, found):
    """Stop 50 (robust50): an extraction's counts computed by numpy (``n_other_clusters`` of a mask whose points
    behind the fruit are dropped, an ``np.int64``) failed the frame: ``TypeError: Object of type int64 is not JSON
    serializable`` (robust49's ``--masks`` PNG cases on 35f8d31)."""
    d = found.detections[0]
    ex = replace(d.extraction, mask_area=np.int64(d.extraction.mask_area), n_invalid=np.int64(3),
                 n_other_clusters=np.int64(684), truncated=np.bool_(False))  # fmt: skip
    numpy_counts = replace(found, detections=[replace(d, extraction=ex), *found.detections[1:]])
    write_detections(tmp_path / "f", numpy_counts)
    fruit = json.loads((tmp_path / "f" / "detections.json").read_text())["fruits"][0]
    assert (fruit["n_dropped_clusters"], fruit["n_invalid_depth"], fruit["truncated"]) == (684, 3, False)


def test_a_rerun_with_fewer_fruit_leaves_exactly_its_own_files(tmp_path, found):
    write_detections(tmp_path, found)
    assert len(list(tmp_path.glob("fruit_*.ply"))) == 6
    (tmp_path / ".detections.json.abc123.tmp").write_text("{half")  # a killed run's temporary file
    (tmp_path / "notes.txt").write_text("mine")  # not a frame output: kept
    fewer = replace(found, detections=found.detections[:2])
    written = write_detections(tmp_path, fewer)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["detections.json", "fruit_001.ply", "fruit_002.ply",
                                                          "notes.txt", "overlay.png"]  # fmt: skip
    assert [p.name for p in written] == ["fruit_001.ply", "fruit_002.ply", "overlay.png", "detections.json"]
    assert len(json.loads((tmp_path / "detections.json").read_text())["fruits"]) == 2


def test_fruit_clouds_label_visible_and_completed_points(tmp_path, found):
    write_detections(tmp_path, found)
    d = found.detections[0]
    vertex = PlyData.read(str(tmp_path / f"fruit_{d.id:03d}.ply"))["vertex"]
    labels = np.asarray(vertex["label"])
    n_vis = len(d.result.visible)
    assert len(labels) == len(d.result.points) and not labels[:n_vis].any() and labels[n_vis:].all()
    assert np.allclose(np.c_[vertex["x"], vertex["y"], vertex["z"]], d.result.points, atol=1e-6)


def test_the_overlay_is_the_frame_with_boxes_drawn(found):
    img = draw_overlay(found)
    assert img.size == (640, 480) and img.mode == "RGB"
    pixels = np.asarray(img)
    assert not np.array_equal(pixels, found.frame.color)
    assert (np.abs(pixels.astype(int) - [255, 170, 0]).sum(axis=2) == 0).sum() > 100  # orange visible boxes
    empty = draw_overlay(FrameDetections(found.frame, []))
    same = np.asarray(empty)[:440] == found.frame.color[:440]  # only the legend at the bottom is drawn
    assert same.all()


def test_write_result_writes_the_cloud_and_its_record(tmp_path):
    result = complete(VISIBLE, method="sphere")
    ply, record = write_result(tmp_path / "out" / "fruit.ply", result, meta={"input": "fruit.npy", "units": "m"})
    assert (ply, record) == (tmp_path / "out" / "fruit.ply", tmp_path / "out" / "fruit.json")
    vertex = PlyData.read(str(ply))["vertex"]
    assert len(vertex) == len(result.points) and int(np.sum(vertex["label"])) == len(result.points) - len(VISIBLE)
    data = json.loads(record.read_text())
    assert data["input"] == "fruit.npy" and data["units"] == "m" and data["method"] == "sphere"
    assert data["extras"]["radius"] == result.extras["radius"] and data["settings"] == result.settings.to_dict()
    assert data["centre"] == result.centre.tolist() and data["n_completed"] == len(result.points)
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["fruit.json", "fruit.ply"]


@pytest.mark.parametrize("name", ["fruit.txt", "fruit", "fruit.PLY.json"])
def test_write_result_refuses_other_extensions(tmp_path, name):
    with pytest.raises(FileFormatError, match=r"the output must end in \.ply"):
        write_result(tmp_path / name, complete(VISIBLE, method="raw"))
    assert list(tmp_path.iterdir()) == []


def test_write_result_refuses_a_folder(tmp_path):
    (tmp_path / "taken.ply").mkdir()
    with pytest.raises(FileFormatError, match=r"taken\.ply: is a folder; give a file name ending in \.ply"):
        write_result(tmp_path / "taken.ply", complete(VISIBLE, method="raw"))
    assert write_result(tmp_path / "UPPER.PLY", complete(VISIBLE, method="raw"))[1].name == "UPPER.json"


def test_write_result_follows_a_link_the_user_named_and_writes_its_target_atomically(tmp_path):
    elsewhere = tmp_path / "store"
    elsewhere.mkdir()
    (elsewhere / "fruit.ply").write_text("old")
    (tmp_path / "out.ply").symlink_to(elsewhere / "fruit.ply")
    (tmp_path / "out.json").symlink_to(elsewhere / "record.json")  # a link to a file not yet there
    ply, record = write_result(tmp_path / "out.ply", complete(VISIBLE, method="raw"))
    # before: both links replaced by regular files, the targets left as they were
    assert (tmp_path / "out.ply").is_symlink() and (tmp_path / "out.json").is_symlink()
    assert (ply, record) == (elsewhere / "fruit.ply", elsewhere / "record.json")
    assert PlyData.read(str(tmp_path / "out.ply"))["vertex"].count == len(VISIBLE)
    assert json.loads((tmp_path / "out.json").read_text())["method"] == "raw"
    assert sorted(p.name for p in elsewhere.iterdir()) == ["fruit.ply", "record.json"]  # no temporary left


@pytest.mark.parametrize("how", ["fifo", "link to a fifo", "link into a missing folder"])
def test_write_result_refuses_a_pipe_and_a_link_to_nowhere_without_replacing_it(tmp_path, how):
    from symfruit import OutputError

    if how == "fifo":
        os.mkfifo(tmp_path / "out.ply")
    elif how == "link to a fifo":
        os.mkfifo(tmp_path / "pipe")
        (tmp_path / "out.ply").symlink_to(tmp_path / "pipe")
    else:
        (tmp_path / "out.ply").symlink_to(tmp_path / "gone" / "fruit.ply")
    why = {
        "fifo": r"out\.ply: is a pipe, not a file",
        "link to a fifo": r"out\.ply: is a pipe \(through the link",
        "link into a missing folder": r"out\.ply: is a link to .*gone/fruit\.ply, whose folder .* does not exist",
    }
    before = sorted((p.name, p.is_symlink(), stat.S_IFMT(p.lstat().st_mode)) for p in tmp_path.iterdir())
    with pytest.raises(OutputError, match=why[how]):  # before: replaced by a regular file (a dangling link: ok)
        write_result(tmp_path / "out.ply", complete(VISIBLE, method="raw"))
    assert sorted((p.name, p.is_symlink(), stat.S_IFMT(p.lstat().st_mode)) for p in tmp_path.iterdir()) == before


class FixedClock(datetime.datetime):
    @classmethod
    def now(cls, tz=None):
        return cls(2024, 5, 6, 7, 8, 9)


def test_results_folders_never_collide_and_latest_follows(tmp_path, monkeypatch):
    from symfruit import writers

    monkeypatch.setattr(writers._dt, "datetime", FixedClock)
    first = new_results_folder(tmp_path, "paper")
    second = new_results_folder(tmp_path, "paper")
    third = new_results_folder(tmp_path, "paper")
    other = new_results_folder(tmp_path, "camera")
    names = [p.name for p in (first, second, third, other)]
    assert names == ["20240506-070809-paper", "20240506-070809-paper-2", "20240506-070809-paper-3",
                     "20240506-070809-camera"]  # fmt: skip
    assert all(p.is_dir() for p in (first, second, third, other))
    latest = tmp_path / "latest"
    assert latest.is_symlink() and os.readlink(latest) == other.name and latest.resolve() == other.resolve()
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []  # no temporary link left


def test_a_results_root_that_cannot_be_written_is_named(tmp_path, found):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(FileFormatError, match=r"file: cannot create a results folder"):
        new_results_folder(blocker, "paper")
    with pytest.raises(FileFormatError, match=r"frame: .*file is a file, not a folder"):  # not: "(Not a directory)"
        write_detections(blocker / "frame", found)


PEAK = """
import resource, sys
import numpy as np
from PIL import Image
w, h = int(sys.argv[2]), int(sys.argv[3])
Image.new("RGB", (w, h), (200, 30, 40)).save(sys.argv[1] + "/big.png", compress_level=1)
from symfruit.io.images import read_color
from symfruit.writers import write_label_overlay, write_labels
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
color = read_color(sys.argv[1] + "/big.png")
labels = np.zeros((h, w), np.int32)
labels[h // 4 : h // 2, w // 4 : w // 2] = 1
write_labels(sys.argv[1] + "/big_labels.png", labels)
write_label_overlay(sys.argv[1] + "/big_overlay.png", color, labels)
print((resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - base) * 1024 / (w * h))
"""


@pytest.mark.parametrize("size", [(3200, 2400), pytest.param((7200, 5400), marks=pytest.mark.slow)])
def test_reading_a_large_photo_and_drawing_its_overlay_stays_within_a_few_bytes_a_pixel(tmp_path, size):
    # Measured in a child process (peak resident memory): the image itself is 3 bytes a pixel, its labels 4;
    # full-size float temporaries cost 50 (a 39-megapixel photo peaked at 2 GB).
    run = subprocess.run([sys.executable, "-c", PEAK, str(tmp_path), *map(str, size)], capture_output=True,
                         text=True, timeout=600)  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert float(run.stdout) < 20.0


def test_the_overlay_tints_each_fruit_where_the_colour_image_shows_it():
    """Depth registered 6 px right of the colour: the masks move onto the depth image, and the overlay moves them
    back onto the colour image's pixels (tinted 6 px to the right of the fruit before)."""
    from symfruit.core.frame import Frame
    from symfruit.detect import detect

    from .conftest import SMALL_CAM, disc_frame

    color, depth = disc_frame([(70, 60)], radius=22)
    moved = np.full_like(depth, 1.0)
    moved[:, 6:] = depth[:, :-6]
    yy, xx = np.mgrid[:120, :160]
    masks = ((xx - 70) ** 2 + (yy - 60) ** 2 <= 22**2).astype(np.int32)
    found = detect(Frame("shifted", color, moved, SMALL_CAM, masks=masks), method="raw")
    assert found.registration == (6, 0)
    tinted = np.any(np.asarray(draw_overlay(found)) != color, axis=2)
    assert tinted[60, 50] and tinted[60, 89]  # the disc's left and right ends in the colour image
    assert not tinted[60, 95]  # beside the disc, where the moved mask reached (it ends at column 98)


def test_a_results_root_that_cannot_hold_a_results_folder_is_refused_before_anything_is_made(tmp_path):
    (tmp_path / "file").write_text("")
    with pytest.raises(FileFormatError, match=r"file: cannot create a results folder \(the results root is a file\)"):
        check_results_root(tmp_path / "file")
    with pytest.raises(FileFormatError, match=r"file/a/b: .*lies below .*file, which is a file"):
        check_results_root(tmp_path / "file" / "a" / "b")
    check_results_root(tmp_path / "new" / "deeper")  # to be made: fine, and nothing made yet
    check_results_root(tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]


def test_a_result_is_never_written_over_an_input(tmp_path):
    from symfruit.errors import OutputError
    from symfruit.writers import check_result_paths

    (tmp_path / "cloud.ply").write_text("ply")
    (tmp_path / "cam.json").write_text("{}")
    inputs = [tmp_path / "cloud.ply", tmp_path / "cam.json", None]
    for output in ("cloud.ply", "cam.ply", "sub/../cloud.ply"):  # the cloud, or its .json the intrinsics
        with pytest.raises(OutputError, match=r"is an input of this run .*choose another output name"):
            check_result_paths(tmp_path / output, inputs)
    assert check_result_paths(tmp_path / "out.ply", inputs) == (tmp_path / "out.ply", tmp_path / "out.json")
    assert [p.read_text() for p in inputs[:2]] == ["ply", "{}"]


def test_the_label_overlay_and_label_png_refuse_what_they_would_draw_or_write_wrong(tmp_path):
    from symfruit.writers import draw_label_overlay, write_labels

    color, labels = np.zeros((4, 5, 3), np.uint8), np.zeros((4, 5), np.int32)
    labels[1, 1] = 2
    cases = [
        ((color, labels.astype(float) + 0.5), {}, "instance labels must be whole numbers"),  # before: drawn as 2
        ((color, labels - 5), {}, "masks hold negative labels"),  # before: -5 drawn as background
        ((color[..., :2], labels), {}, "must be RGB"),  # before: numpy's broadcast ValueError
        ((np.full((4, 5, 3), 0.5), labels), {}, r"8-bit colour \(whole numbers 0-255\), got float64"),  # was black
        ((np.full((4, 5, 3), 1000), labels), {}, "8-bit colour"),  # before: clipped to white in silence
        ((color, labels), {"alpha": float("nan")}, "alpha must be a tint strength in"),  # before: drawn anyway
        ((color, labels), {"alpha": "a"}, "alpha must be a tint strength"),  # before: TypeError
        ((np.zeros((0, 0, 3), np.uint8), np.zeros((0, 0), np.int32)), {}, "must not be empty"),  # was IndexError
    ]
    for args, kwargs, message in cases:
        with pytest.raises(FileFormatError, match=message):
            draw_label_overlay(*args, **kwargs)
    whole = np.asarray(draw_label_overlay(color.astype(np.int64) + 100, labels > 0))  # 8-bit values, one fruit
    assert whole.shape == (4, 5, 3) and whole[0, 0].tolist() == [100, 100, 100]
    with pytest.raises(FileFormatError, match="labels are a 0x0 image; no PNG is empty"):
        write_labels(tmp_path / "l.png", np.zeros((0, 0), np.int32))  # before: Pillow's 'cannot write empty image'
    assert not list(tmp_path.iterdir())


def test_an_empty_output_path_is_refused_not_read_as_the_working_folder(tmp_path, monkeypatch):
    from symfruit import InputError
    from symfruit.writers import check_results_root, new_results_folder, write_detections, write_result

    monkeypatch.chdir(tmp_path)
    for call, what in [
        (lambda: write_detections("", None), "write_detections: the frame folder"),  # before: into the working folder
        (lambda: check_results_root(""), "the results root"),
        (lambda: new_results_folder("", "paper"), "new_results_folder: the results root"),
        (lambda: write_result("", None), "write_result: the output file"),
    ]:
        with pytest.raises(InputError, match=f"{what} is an empty path"):
            call()
    assert not list(tmp_path.iterdir())
