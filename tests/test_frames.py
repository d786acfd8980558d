"""Frames on disk, the segmenter, mask sources, extraction, bags."""

import json

import numpy as np
import pytest

from symfruit import Camera, FileFormatError, InputError
from symfruit.extract import ExtractSettings, cluster, extract
from symfruit.io.frames import read_frame, write_frame
from symfruit.io.masks import read_masks, rle_decode
from symfruit.io.sources import open_source
from symfruit.scenes import make_scene
from symfruit.segment import segment

from .conftest import EXAMPLE_FRAME

CAM = Camera(fx=600, fy=600, cx=80, cy=60, width=160, height=120)


def disc_frame(centres, radius=20, z=0.3, colour=(200, 20, 30)):
    color = np.full((120, 160, 3), 90, np.uint8)
    depth = np.full((120, 160), 1.0, np.float32)
    yy, xx = np.mgrid[:120, :160]
    for cx, cy in centres:
        inside = (xx - cx) ** 2 + (yy - cy) ** 2 <= radius**2
        color[inside] = colour
        r_m = radius * z / 600
        d2 = ((xx - cx) ** 2 + (yy - cy) ** 2) * (z / 600) ** 2
        depth[inside] = np.minimum(depth[inside], (z - np.sqrt(np.clip(r_m**2 - d2, 0, None)))[inside])
    return color, depth


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


def test_frame_round_trip_png_and_npy(tmp_path):
    scene = make_scene(3, n_ripe=2, n_unripe=1, n_leaves=0)
    write_frame(tmp_path / "a", scene.color, scene.depth, scene.camera, truth=scene.truth(), masks=scene.labels)
    frame = read_frame(tmp_path / "a")
    assert np.array_equal(frame.color, scene.color)
    assert np.abs(frame.depth - scene.depth).max() <= 0.0005 + 1e-6  # millimetre units
    assert frame.masks.max() == scene.labels.max() and len(frame.truth) == 2
    np.save(tmp_path / "a" / "depth.npy", scene.depth)
    (tmp_path / "a" / "depth.png").unlink()
    assert np.array_equal(read_frame(tmp_path / "a").depth, scene.depth)


@pytest.mark.parametrize(
    "break_it, message",
    [
        (lambda f: (f / "color.png").unlink(), "no color.png"),
        (lambda f: (f / "depth.png").unlink(), "no depth.png or depth.npy"),
        (lambda f: (f / "camera.json").unlink(), "no camera.json"),
        (lambda f: (f / "depth.png").write_bytes(b"\x89PNG\r\n garbage"), "cannot read image"),
        (
            lambda f: (f / "camera.json").write_text(json.dumps({**CAM.to_dict(), "width": 320})),
            "intrinsics are for 320x120",
        ),
        (
            lambda f: (f / "camera.json").write_text(json.dumps({**CAM.to_dict(), "depth_units": "furlong"})),
            "unknown depth_units",
        ),
        (lambda f: (f / "truth.json").write_text("{"), "truth.json"),
    ],
)
def test_bad_frames_name_the_file(tmp_path, break_it, message):
    color, depth = disc_frame([(80, 60)])
    write_frame(tmp_path / "f", color, depth, CAM, truth={"fruits": []})
    break_it(tmp_path / "f")
    with pytest.raises((FileFormatError, InputError), match=message):
        read_frame(tmp_path / "f")


def test_colour_and_depth_of_different_sizes(tmp_path):
    from PIL import Image

    color, depth = disc_frame([(80, 60)])
    write_frame(tmp_path / "f", color, depth, CAM)
    Image.fromarray(color[:100]).save(tmp_path / "f" / "color.png")
    with pytest.raises(InputError, match="depth must be aligned"):
        read_frame(tmp_path / "f")


def test_iter_frames_reports_bad_frames_and_goes_on(tmp_path):
    color, depth = disc_frame([(80, 60)])
    for name in ("a", "b", "c"):
        write_frame(tmp_path / name, color, depth, CAM)
    (tmp_path / "b" / "depth.png").unlink()
    src = open_source(tmp_path)
    assert src.names() == ["a", "b", "c"]
    assert src.read(0).name == "a" and src.read(2).name == "c"
    with pytest.raises(FileFormatError, match="depth"):
        src.read(1)


def test_label_png_and_coco_masks(tmp_path):
    from PIL import Image

    labels = np.zeros((120, 160), np.uint8)
    labels[10:30, 10:40] = 1
    labels[50:90, 60:100] = 2
    Image.fromarray(labels).save(tmp_path / "masks.png")
    assert np.array_equal(read_masks(tmp_path / "masks.png", (120, 160)), labels)
    coco = {
        "images": [{"id": 7, "width": 160, "height": 120}],
        "annotations": [
            {"id": 1, "image_id": 7, "segmentation": [[10, 10, 39, 10, 39, 29, 10, 29]]},
            {"id": 2, "image_id": 7, "segmentation": {"size": [120, 160], "counts": rle_counts(labels == 2)}},
            {"id": 3, "image_id": 7, "segmentation": {"size": [120, 160], "counts": rle_string(labels == 2)}},
        ],
    }
    (tmp_path / "masks.json").write_text(json.dumps(coco))
    got = read_masks(tmp_path / "masks.json", (120, 160))
    assert np.array_equal(got == 1, labels == 1)
    assert np.array_equal(got == 3, labels == 2)  # drawn last, over annotation 2
    with pytest.raises(FileFormatError, match="masks are 160x120, the image 10x10"):
        read_masks(tmp_path / "masks.png", (10, 10))


def rle_counts(mask):
    """COCO uncompressed RLE: run lengths down the columns, starting with a run of zeros."""
    flat = mask.T.ravel().astype(int)
    edges = np.flatnonzero(np.diff(flat)) + 1
    runs = np.diff(np.r_[0, edges, len(flat)]).tolist()
    return ([0] + runs) if flat[0] == 1 else runs


def rle_string(mask):
    """COCO's compressed RLE string (maskApi.c rleToString), to test the decoder."""
    counts = rle_counts(mask)
    out = []
    for i, x in enumerate(counts):
        if i > 2:
            x -= counts[i - 2]
        more = True
        while more:
            c = x & 0x1F
            x >>= 5
            more = (x != -1) if (c & 0x10) else (x != 0)
            if more:
                c |= 0x20
            out.append(chr(c + 48))
    return "".join(out)


def test_rle_decoder_matches_known_mask():
    mask = np.zeros((7, 5), bool)
    mask[2:5, 1:3] = True
    mask[6, 4] = True
    counts = rle_counts(mask)
    assert sum(counts) == 35
    assert np.array_equal(rle_decode({"size": [7, 5], "counts": counts}), mask)
    assert np.array_equal(rle_decode({"size": [7, 5], "counts": rle_string(mask)}), mask)


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


def test_tiny_ros2_bag(tmp_path):
    rosbags = pytest.importorskip("rosbags")  # noqa: F841
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    Image, Info = ts.types["sensor_msgs/msg/Image"], ts.types["sensor_msgs/msg/CameraInfo"]
    Header, Time = ts.types["std_msgs/msg/Header"], ts.types["builtin_interfaces/msg/Time"]
    RoI = ts.types["sensor_msgs/msg/RegionOfInterest"]
    color, depth = disc_frame([(60, 60), (110, 60)], radius=15)
    mm = (depth * 1000).astype(np.uint16)
    path = tmp_path / "bag"
    with Writer(path, version=9) as writer:
        c_col = writer.add_connection("/camera/color/image_raw", "sensor_msgs/msg/Image", typestore=ts)
        c_dep = writer.add_connection("/camera/aligned_depth_to_color/image_raw", "sensor_msgs/msg/Image", typestore=ts)
        c_inf = writer.add_connection("/camera/color/camera_info", "sensor_msgs/msg/CameraInfo", typestore=ts)
        for i in range(2):
            t = 1_000_000_000 * (i + 1)
            head = Header(stamp=Time(sec=i + 1, nanosec=0), frame_id="camera_color_optical_frame")
            info = Info(header=head, height=120, width=160, distortion_model="plumb_bob", d=np.zeros(5),
                        k=np.array([600.0, 0, 80, 0, 600, 60, 0, 0, 1]), r=np.eye(3).ravel(),
                        p=np.array([600.0, 0, 80, 0, 0, 600, 60, 0, 0, 0, 1, 0]), binning_x=0, binning_y=0,
                        roi=RoI(x_offset=0, y_offset=0, height=0, width=0, do_rectify=False))  # fmt: skip
            writer.write(c_inf, t, ts.serialize_cdr(info, "sensor_msgs/msg/CameraInfo"))
            img = Image(header=head, height=120, width=160, encoding="rgb8", is_bigendian=0, step=480,
                        data=color.ravel())  # fmt: skip
            writer.write(c_col, t, ts.serialize_cdr(img, "sensor_msgs/msg/Image"))
            dep = Image(header=head, height=120, width=160, encoding="16UC1", is_bigendian=0, step=320,
                        data=mm.view(np.uint8).ravel())  # fmt: skip
            writer.write(c_dep, t + 1000, ts.serialize_cdr(dep, "sensor_msgs/msg/Image"))
    src = open_source(path)
    assert len(src) == 2
    frame = src.read(0)
    assert np.array_equal(frame.color, color) and np.allclose(frame.depth, mm / 1000.0)
    assert frame.camera == CAM
    from symfruit.detect import detect

    found = detect(frame, method="raw")
    assert len(found.detections) == 2 and all(d.result is not None for d in found.detections)


def test_maskrcnn_without_torch_says_which_extra():
    import importlib.util

    if importlib.util.find_spec("torch") is not None:
        pytest.skip("torch is installed")
    from symfruit import SymfruitError
    from symfruit.segment_maskrcnn import load_maskrcnn

    with pytest.raises(SymfruitError, match=r"symfruit\[seg\]"):
        load_maskrcnn("model.pth")
