"""symfruit.ros.bag2 and `symfruit detect --ros2-bag`: vision_msgs/msg/Detection3DArray in ROS 2 bags, read back
with rosbags (the bag's own message definitions, no typestore of ours)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from symfruit.cli import main
from symfruit.core.frame import Frame
from symfruit.errors import FileFormatError
from symfruit.ros.bag2 import MSGTYPE, TOPIC, Ros2DetectionBag, frame_header

pytest.importorskip("rosbags")


def read_back(path: Path) -> list[tuple[int, object, object]]:
    """(bag time, connection, message) of every message."""
    from rosbags.highlevel import AnyReader

    with AnyReader([path]) as reader:
        return [(t, c, reader.deserialize(raw, c.msgtype)) for c, t, raw in reader.messages()]


def assert_same(msg, fruits, *, class_id: str) -> None:
    assert len(msg.detections) == len(fruits) > 0
    for det, f in zip(msg.detections, fruits, strict=True):
        assert det.id == str(f.id) and det.header == msg.header
        c, s = det.bbox.center.position, det.bbox.size
        np.testing.assert_allclose([c.x, c.y, c.z], f.centre, rtol=0, atol=1e-12)
        np.testing.assert_allclose([s.x, s.y, s.z], f.size, rtol=0, atol=1e-12)
        assert det.bbox.center.orientation.w == 1.0
        (hyp,) = det.results
        assert hyp.hypothesis.class_id == class_id and hyp.hypothesis.score == f.score
        p = hyp.pose.pose.position
        np.testing.assert_allclose([p.x, p.y, p.z], f.centre, rtol=0, atol=1e-12)


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_write_and_read_back(tmp_path, example_fruits, storage):
    stamps = [1_700_000_000_123_456_789, 1_700_000_000_456_000_000]
    with Ros2DetectionBag(tmp_path / "bag", storage=storage, class_id="strawberry") as bag:
        bag.write(stamps[0], example_fruits)
        bag.write(stamps[1], example_fruits[:2], frame_id="other_frame")
    assert bag.count == 2
    got = read_back(tmp_path / "bag")
    assert [t for t, _, _ in got] == stamps
    assert all(c.topic == TOPIC and c.msgtype == MSGTYPE for _, c, _ in got)
    for (t, _, msg), n, frame_id in zip(got, [len(example_fruits), 2], ["camera_color_optical_frame", "other_frame"],
                                        strict=True):  # fmt: skip
        assert msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec == t
        assert msg.header.frame_id == frame_id
        assert_same(msg, example_fruits[:n], class_id="strawberry")


def test_the_bag_appears_only_when_complete(tmp_path, example_fruits):
    """Written in a hidden folder beside it and renamed into place once closed: a killed run never leaves a bag
    without its metadata.yaml at the path (before: written there directly, frame by frame)."""
    bag = Ros2DetectionBag(tmp_path / "bag").open()
    bag.write(1, example_fruits)
    assert not (tmp_path / "bag").exists() and [p.name[:13] for p in tmp_path.iterdir()] == [".bag.partial-"]
    bag.close()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bag"] and (tmp_path / "bag" / "metadata.yaml").is_file()
    assert len(read_back(tmp_path / "bag")) == 1
    dropped = Ros2DetectionBag(tmp_path / "dropped").open()
    dropped.write(1, example_fruits)
    dropped.close(keep=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bag"]
    raced = Ros2DetectionBag(tmp_path / "raced").open()
    (tmp_path / "raced").mkdir()  # made meanwhile: an empty folder rename() would replace
    with pytest.raises(FileFormatError, match=r"raced: cannot put the ROS 2 bag in place .*appeared"):
        raced.close()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bag", "raced"] and not any((tmp_path / "raced").iterdir())


def test_an_existing_bag_is_not_overwritten_and_storage_is_checked(tmp_path):
    from symfruit import SymfruitError

    (tmp_path / "bag").mkdir()
    with pytest.raises(FileFormatError, match="exists"):
        Ros2DetectionBag(tmp_path / "bag").open()
    with pytest.raises(SymfruitError, match="storage"):
        Ros2DetectionBag(tmp_path / "other", storage="zip")


def test_frame_header(example_images):
    rgb, raw, cam = example_images
    depth = raw.astype(np.float32) / 1000

    def frame(**kw) -> Frame:
        return Frame("f", rgb, depth, cam, **kw)

    assert frame_header(frame(stamp=5, frame_id="cam_optical"), 3) == (5, "cam_optical")  # the colour header
    assert frame_header(frame(stamp=7), 3) == (7, "camera_color_optical_frame")
    assert frame_header(frame(), 3) == (3_000_000_000, "camera_color_optical_frame")  # folders: the index


def write_ros1_bag(path: Path, images, stamps: list[int], *, color_offset: int = 0) -> None:
    """A ROS 1 bag of the example frame (RealSense topic names), recorded 5 ms after each header stamp; the
    colour images' header stamps are ``color_offset`` ns later than the depth images'."""
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC)
    t = ts.types
    rgb, raw, cam = images
    h, w = raw.shape

    def head(i: int, ns: int, frame_id: str):
        stamp = t["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)
        return t["std_msgs/msg/Header"](seq=i, stamp=stamp, frame_id=frame_id)

    with Writer(path) as writer:
        conns = [writer.add_connection(topic, kind, typestore=ts) for topic, kind in (
            ("/camera/color/image_raw", "sensor_msgs/msg/Image"),
            ("/camera/aligned_depth_to_color/image_raw", "sensor_msgs/msg/Image"),
            ("/camera/color/camera_info", "sensor_msgs/msg/CameraInfo"))]  # fmt: skip
        image, roi = t["sensor_msgs/msg/Image"], t["sensor_msgs/msg/RegionOfInterest"]
        for i, ns in enumerate(stamps):
            chead = head(i, ns + color_offset, "camera_color_optical_frame")
            color = image(header=chead, height=h, width=w, encoding="rgb8", is_bigendian=0, step=w * 3,
                          data=rgb.ravel())  # fmt: skip
            depth = image(header=head(i, ns, "camera_depth_optical_frame"), height=h, width=w, encoding="16UC1",
                          is_bigendian=0, step=w * 2, data=raw.view(np.uint8).ravel())  # fmt: skip
            info = t["sensor_msgs/msg/CameraInfo"](
                header=chead, height=h, width=w, distortion_model="plumb_bob", D=np.zeros(5),
                K=np.array([cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1]), R=np.eye(3).ravel(),
                P=np.array([cam.fx, 0, cam.cx, 0, 0, cam.fy, cam.cy, 0, 0, 0, 1, 0]), binning_x=0, binning_y=0,
                roi=roi(x_offset=0, y_offset=0, height=0, width=0, do_rectify=False),
            )  # fmt: skip
            for conn, msg, at in zip(conns, (color, depth, info), (ns + color_offset, ns, ns), strict=True):
                writer.write(conn, at + 5_000_000, ts.serialize_ros1(msg, conn.msgtype))


def test_bag_frames_know_the_colour_header(tmp_path, example_images):
    from symfruit.io.sources import open_source

    write_ros1_bag(tmp_path / "in.bag", example_images, [1_650_000_000_000_000_000], color_offset=1_000_000)
    with open_source(tmp_path / "in.bag") as src:
        frame = src.read(0)
    assert frame.stamp == 1_650_000_000_001_000_000  # the colour image's header, not the depth image's
    assert frame.frame_id == "camera_color_optical_frame"


def test_detect_cli_writes_a_ros2_bag_stamped_like_its_input(tmp_path, example_images, example_fruits, capsys):
    """In the storage asked for (sqlite3; the default, mcap, in the next test; both writers in
    test_write_and_read_back)."""
    stamps = [1_650_000_000_000_000_000, 1_650_000_000_033_333_333]
    write_ros1_bag(tmp_path / "in.bag", example_images, stamps, color_offset=2_000_000)
    out = tmp_path / "out"
    args = ["detect", str(tmp_path / "in.bag"), "--output", str(out), "--ros2-bag", str(out / "bag")]
    assert main([*args, "--ros2-storage", "sqlite3"]) == 0
    assert f"ROS 2 bag: {out / 'bag'} (2 frames on {TOPIC})" in capsys.readouterr().out
    assert [p.suffix for p in (out / "bag").iterdir() if p.suffix in (".db3", ".mcap")] == [".db3"]
    got = read_back(out / "bag")
    assert [t for t, _, _ in got] == [s + 2_000_000 for s in stamps]  # the colour images' header stamps
    for _, _, msg in got:
        assert msg.header.frame_id == "camera_color_optical_frame"
        assert_same(msg, example_fruits, class_id="strawberry")
    assert main(args) == 2  # the bag exists: refused, not appended to
    assert "exists already" in capsys.readouterr().err


def test_detect_cli_ros2_bag_of_a_frame_folder_and_refusals(tmp_path, example_fruits, capsys):
    from symfruit.demo import example_frame

    with example_frame() as folder:
        assert main(["detect", str(folder), "--output", str(tmp_path / "o"), "--ros2-bag", str(tmp_path / "b")]) == 0
        ((t, _, msg),) = read_back(tmp_path / "b")
        assert t == 0 and msg.header.frame_id == "camera_color_optical_frame"  # a folder has no time: index 0
        assert [p.suffix for p in (tmp_path / "b").iterdir() if p.suffix in (".db3", ".mcap")] == [".mcap"]
        assert_same(msg, example_fruits, class_id="strawberry")
        resume = ["detect", str(folder), "--output", str(tmp_path / "o"), "--resume", "--ros2-bag", str(tmp_path / "c")]
        assert main(resume) == 2 and "--resume" in capsys.readouterr().err
        assert not (tmp_path / "c").exists()
    missing = ["detect", str(tmp_path / "none"), "--output", str(tmp_path / "o2"), "--ros2-bag", str(tmp_path / "d")]
    assert main(missing) == 2  # the input cannot be opened: no empty bag is left behind
    assert not (tmp_path / "d").exists()


def test_run_batch_on_frame_sees_every_frame_and_its_failures_are_the_frames(tmp_path):
    from symfruit.batch import run_batch
    from symfruit.synthetic.scenes import write_scenes

    write_scenes(tmp_path / "rec", 3, distinct=1, seed=0, n_ripe=2, n_unripe=0)  # one render, three frames
    names = sorted(p.name for p in (tmp_path / "rec").iterdir())
    seen = []

    def on_frame(index, found):
        seen.append((index, found.frame.name, len(found.detections)))
        if index == 1:
            raise FileFormatError("bag full")

    report = run_batch(tmp_path / "rec", tmp_path / "out", method="raw", progress=False, on_frame=on_frame)
    assert [(i, n) for i, n, _ in seen] == list(enumerate(names)) and all(k > 0 for _, _, k in seen)
    assert report.failed == {names[1]: "bag full"} and report.done == [names[0], names[2]]
    assert not (tmp_path / "out" / names[1] / "detections.json").exists()  # so --resume retries it
    seen.clear()
    run_batch(tmp_path / "rec", tmp_path / "out", method="raw", progress=False, resume=True, on_frame=on_frame)
    assert [i for i, _, _ in seen] == [1]  # resumed: only the frame that was not done


def test_a_bag_under_a_file_is_refused_naming_the_file(tmp_path):
    """Stop 48 (robust48): "cannot create ROS 2 bag ([Errno 17] File exists: '.../notes')", Python's words."""
    from symfruit.errors import OutputError

    (tmp_path / "notes").write_text("x")
    with pytest.raises(OutputError) as info:
        Ros2DetectionBag(tmp_path / "notes" / "bag").open()
    notes = tmp_path / "notes"
    assert str(info.value) == f"{notes / 'bag'}: cannot create ROS 2 bag ({notes} is a file, not a folder)"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes"]
