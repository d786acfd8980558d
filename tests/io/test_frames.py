"""Frame folders on disk: round trips, depth units, truth, and broken frames that name the file."""

import json
import re
import shutil

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

from symfruit import Camera, FileFormatError, InputError, SymfruitError
from symfruit.io.frames import is_frame_folder, read_frame, read_truth, write_frame
from symfruit.synthetic.scenes import make_scene

from ..conftest import EXAMPLE_FRAME, SMALL_CAM, after_its_status_time, disc_frame, set_back

CAM = SMALL_CAM


def test_frame_round_trip_png_and_npy(tmp_path):
    small = Camera(fx=300, fy=300, cx=160, cy=120, width=320, height=240)  # rendering is most of the time
    scene = make_scene(3, n_ripe=2, n_unripe=1, n_leaves=0, camera=small)
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
        # stop 41: before, only "no depth.png or depth.npy" beside a depth.tiff (a float TIFF of metres) or depth.PNG
        (lambda f: (f / "depth.png").rename(f / "depth.tiff"), r"no depth.png or depth.npy; found depth.tiff, not "
         "read"),
        (lambda f: [(f / n).write_bytes((f / "depth.png").read_bytes()) for n in ("Depth.PNG", "depth.png.bak",
                                                                                   "depth.a", "depth.b")]
         + [(f / "depth.png").unlink()],
         r"; found Depth.PNG, depth.a, depth.b and 1 more, not read: only the names above are$"),
        (lambda f: (f / "camera.json").rename(f / "camera.JSON"), r"no camera.json \(intrinsics\); found camera.JSON"),
    ],
)  # fmt: skip
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
    with pytest.raises(InputError, match=rf"^{re.escape(str(tmp_path / 'f'))}: colour is 160x100 but depth is "
                       "160x120; depth must be aligned"):  # fmt: skip
        read_frame(tmp_path / "f")  # the folder named, not the frame's name alone


def test_an_8_bit_depth_picture_is_refused_not_read_as_millimetres(tmp_path):
    color, depth = disc_frame([(80, 60)])
    write_frame(tmp_path / "f", color, depth, CAM)
    Image.fromarray(np.clip(depth / depth.max() * 255, 0, 255).astype(np.uint8)).save(tmp_path / "f" / "depth.png")
    with pytest.raises(FileFormatError, match=rf"^{re.escape(str(tmp_path / 'f' / 'depth.png'))}: depth PNG is 8-bit"):
        read_frame(tmp_path / "f")
    (tmp_path / "f" / "camera.json").write_text(json.dumps({**CAM.to_dict(), "depth_units": "cm"}))
    assert read_frame(tmp_path / "f").depth.max() == pytest.approx(2.55)  # centimetres reach 2.55 m: depth


@pytest.mark.parametrize("name", ["color.png", "depth.png", "camera.json", "truth.json"])
def test_truncated_frame_files(tmp_path, name):

    from symfruit.io.frames import read_frame

    frame = tmp_path / "frame"
    shutil.copytree(EXAMPLE_FRAME, frame)
    data = (frame / name).read_bytes()
    (frame / name).write_bytes(data[: len(data) // 2])
    with pytest.raises(SymfruitError, match=name.split(".")[0]):
        read_frame(frame)


def test_intrinsics_not_matching_the_image(tmp_path):

    from symfruit.io.frames import read_frame

    frame = tmp_path / "frame"
    shutil.copytree(EXAMPLE_FRAME, frame)
    cam = json.loads((frame / "camera.json").read_text())
    (frame / "camera.json").write_text(json.dumps({**cam, "height": 720}))
    with pytest.raises(InputError, match=r"intrinsics are for 640x720 but the images are 640x480"):
        read_frame(frame)
    (frame / "camera.json").write_text(json.dumps({**cam, "fx": -5}))
    with pytest.raises(FileFormatError, match="focal lengths must be positive"):
        read_frame(frame)


def test_the_example_frame(example):
    assert example.name == "example_frame" and example.color.shape == (480, 640, 3)
    assert example.depth.dtype == np.float32 and example.masks is None and example.source == str(EXAMPLE_FRAME)
    assert len(example.truth) == 6 and all(isinstance(fid, int) for fid, _ in example.truth)
    assert is_frame_folder(EXAMPLE_FRAME) and not is_frame_folder(EXAMPLE_FRAME.parent)
    assert not is_frame_folder(EXAMPLE_FRAME / "color.png")


@pytest.mark.parametrize("units, scale", [("m", 1.0), ("mm", 0.001), ("0.1mm", 0.0001), ("cm", 0.01)])
def test_depth_units_and_scale(tmp_path, units, scale):
    color, depth = disc_frame([(80, 60)])
    write_frame(tmp_path / "f", color, depth, CAM)
    raw = np.asarray(Image.open(tmp_path / "f" / "depth.png")).astype(np.float32)
    (tmp_path / "f" / "camera.json").write_text(json.dumps({**CAM.to_dict(), "depth_units": units}))
    if units == "m":  # millimetre values declared as metres: 1000 m to every pixel is refused, not used
        with pytest.raises(InputError, match="look like millimetres"):
            read_frame(tmp_path / "f")
    else:
        assert np.array_equal(read_frame(tmp_path / "f").depth, raw * np.float32(scale))
    (tmp_path / "f" / "camera.json").write_text(json.dumps({**CAM.to_dict(), "depth_scale": 0.0002}))
    assert np.array_equal(read_frame(tmp_path / "f").depth, raw * np.float32(0.0002))
    # both, agreeing: read; disagreeing (before: depth_units taken, depth_scale ignored in silence): refused
    (tmp_path / "f" / "camera.json").write_text(
        json.dumps({**CAM.to_dict(), "depth_scale": scale, "depth_units": units})
    )
    if units != "m":
        assert np.array_equal(read_frame(tmp_path / "f").depth, raw * np.float32(scale))
    (tmp_path / "f" / "camera.json").write_text(
        json.dumps({**CAM.to_dict(), "depth_scale": 0.0002, "depth_units": units})
    )
    message = rf"camera\.json: depth_scale 0\.0002 and depth_units '{units}' \({scale:g} m\) disagree; which one"
    with pytest.raises(InputError, match=message):
        read_frame(tmp_path / "f")


@pytest.mark.parametrize("scale", [0, 1.5, -0.001, True, "0.001"])
def test_bad_depth_scales_are_refused(tmp_path, scale):
    color, depth = disc_frame([(80, 60)])
    write_frame(tmp_path / "f", color, depth, CAM)
    (tmp_path / "f" / "camera.json").write_text(json.dumps({**CAM.to_dict(), "depth_scale": scale}))
    with pytest.raises(InputError, match=r"camera\.json: depth_scale must be metres per unit in \(0, 1\]"):
        read_frame(tmp_path / "f")


@pytest.mark.parametrize(
    "stated, said",
    [({"depth_scale": 10**400}, r"depth_scale must be .* got 100000000000\.\.\. \(401 digits\)$"),
     ({"depth_units": ["mm"] * 100_000}, r"unknown depth_units \['mm', .*\(600000 characters\); use one of")],
)  # fmt: skip
def test_a_huge_depth_scale_or_units_is_refused_in_a_message_of_bounded_length(tmp_path, stated, said):
    color, depth = disc_frame([(80, 60)])
    write_frame(tmp_path / "f", color, depth, CAM)
    (tmp_path / "f" / "camera.json").write_text(json.dumps({**CAM.to_dict(), **stated}))
    with pytest.raises(InputError, match=said) as caught:
        read_frame(tmp_path / "f")
    assert len(str(caught.value)) < 400  # before: the 401 digits, or the whole list of 600,000 characters


def test_depth_npy_is_checked_and_cleaned(tmp_path):
    color, depth = disc_frame([(80, 60)])
    write_frame(tmp_path / "f", color, depth, CAM)
    (tmp_path / "f" / "depth.png").unlink()
    dirty = depth.astype(np.float64)
    dirty[0, :3] = [np.nan, np.inf, -np.inf]
    np.save(tmp_path / "f" / "depth.npy", dirty)
    read = read_frame(tmp_path / "f").depth
    assert read.dtype == np.float32 and read[0, :3].tolist() == [0.0, 0.0, 0.0]
    assert np.array_equal(read[1:], depth[1:])
    np.save(tmp_path / "f" / "depth.npy", depth.astype(np.int32))
    with pytest.raises(FileFormatError, match="depth must be a 2-D float array in metres"):
        read_frame(tmp_path / "f")


def test_a_flt_max_depth_npy_is_no_depth_not_a_runtime_warning(tmp_path):
    """float32 3e38 (FLT_MAX, a sentinel of no depth) overflowed the median of the units check: a numpy
    RuntimeWarning (an error under pytest). Beyond 1e6 m it is no depth, as inf and NaN are."""
    from symfruit.core.limits import depth_metres
    from symfruit.io.frames import read_depth_npy

    color, depth = disc_frame([(80, 60)])
    write_frame(tmp_path / "f", color, depth, CAM)
    (tmp_path / "f" / "depth.png").unlink()
    sentinel = depth.astype(np.float32)
    sentinel[sentinel > 0] = 3e38
    sentinel[0, :2] = [2e6, -3e38]
    np.save(tmp_path / "f" / "depth.npy", sentinel)
    frame = read_frame(tmp_path / "f")
    assert not frame.depth.any()
    depth_metres(frame.depth, "f")  # the frame's own check, as detect makes it
    sentinel[5, 5] = 1e6  # the bound itself is read (and a frame of it refused by the units check)
    np.save(tmp_path / "f" / "depth.npy", sentinel)
    assert read_depth_npy(tmp_path / "f" / "depth.npy")[5, 5] == np.float32(1e6)


def test_truth_keeps_the_ripe_fruit_with_their_ids(tmp_path):
    path = tmp_path / "truth.json"
    path.write_text(json.dumps({"fruits": [
        {"id": 7, "min": [0, 0, 0.3], "max": [0.02, 0.03, 0.33]},
        {"id": 8, "ripe": False, "min": [0, 0, 0.3], "max": [0.02, 0.03, 0.33]},
        {"min": [0.1, 0, 0.3], "max": [0.12, 0.02, 0.32]},
    ]}))  # fmt: skip
    truth = read_truth(path)
    assert [fid for fid, _ in truth] == [7, 3]  # the unripe one is no target; a missing id is the position
    assert truth[0][1].size.tolist() == pytest.approx([0.02, 0.03, 0.03])
    for bad, message in [
        ({"fruits": [{"min": [0, 0], "max": [1, 1]}]}, "three finite numbers"),
        ({"fruits": [{"id": "a", "min": [0, 0, 0], "max": [1, 1, 1]}]}, "id must be a whole number"),
        ({"fruits": {"a": 1}}, "'fruits' is not a list"),
        ({"fruits": [3]}, "fruit 1 is not an object"),
        ({"fruits": [{"min": [0, 0, 0]}]}, "'max'"),
        ({"fruits": [{"min": [0, 0, 0], "max": [1, 1, 1], "visible": 1.5}]}, "visible must be a share in"),
        ({"fruits": [{"min": [0, 0, 0], "max": [1, 1, 1], "visible": True}]}, "visible must be a share in"),
        ({"fruits": [{"min": [0, 0, 0], "max": [1, 1, 1], "visible": "all"}]}, "visible must be a share in"),
    ]:
        path.write_text(json.dumps(bad))
        with pytest.raises(FileFormatError, match=rf"truth\.json: expected .*{message}"):
            read_truth(path)


def test_a_frame_knows_how_much_of_each_true_fruit_is_seen(tmp_path):
    color, depth = disc_frame([(40, 60)])
    fruits = [{"id": 4, "min": [0, 0, 0.3], "max": [0.02, 0.03, 0.33], "visible": 0.25},
              {"id": 9, "min": [0, 0, 0.3], "max": [0.02, 0.03, 0.33]},
              {"id": 5, "ripe": False, "min": [0, 0, 0.3], "max": [0.02, 0.03, 0.33], "visible": 1}]  # fmt: skip
    write_frame(tmp_path / "f", color, depth, CAM, truth={"fruits": fruits})
    frame = read_frame(tmp_path / "f")
    assert [fid for fid, _ in frame.truth] == [4, 9] and frame.visible == {4: 0.25}  # no share, no target: none
    write_frame(tmp_path / "g", color, depth, CAM)
    assert read_frame(tmp_path / "g").visible == {}


def test_masks_written_with_the_frame_come_back(tmp_path):
    color, depth = disc_frame([(40, 60), (120, 60)])
    labels = np.zeros((120, 160), np.int32)
    labels[40:80, 20:60] = 1
    labels[40:80, 100:140] = 300  # needs 16 bits
    write_frame(tmp_path / "f", color, depth, CAM, masks=labels)
    assert np.array_equal(read_frame(tmp_path / "f").masks, labels)


@pytest.mark.parametrize(
    "truth, message",
    [
        ({"fruits": [{"min": [0.0, 0.0], "max": [0.1, 0.1, 0.4]}]}, "three finite numbers"),
        ({"fruits": [5]}, "fruit 1 is not an object"),
        ({"fruits": "none"}, "'fruits' is not a list"),
        ({"fruits": [{"min": [0, 0, 0.3], "max": [0.1, 0.1, 0.4], "id": "one"}]}, "id must be a whole number"),
        (
            {"fruits": [{"min": [0.1, 0, 0.3], "max": [0.0, 0.1, 0.4]}]},
            r"fruit 1: min \[0\.1, 0\.0, 0\.3\] lies beyond max",
        ),
        (
            {"fruits": [{"min": [10, 20, 300], "max": [40, 50, 340]}]},
            "more than 100 m from the camera; boxes are in metres",
        ),
        ({"fruits": [{"min": [-1e308] * 3, "max": [1e308] * 3}]}, "more than 100 m from the camera"),
        ({"fruits": [{"min": [10**400, 0, 0.3], "max": [0.1, 0.1, 0.4]}]}, "int too large to convert to float"),
        ({"fruits": [{"min": [0, 0, 0.3], "max": [0.1, 0.1, 0.4], "id": 2**40}]}, "id must be a whole number in 1-"),
        # stop 41: before, taken, though no mask label is 0 (the background): never matched, by --match id or any
        ({"fruits": [{"min": [0, 0, 0.3], "max": [0.1, 0.1, 0.4], "id": 0}]}, r"fruit 1: id 0 is no mask label"),
        ({"fruits": [{"min": [0, 0, 0.3], "max": [0.1, 0.1, 0.4], "id": 1},
                     {"min": [0, 0, 0.3], "max": [0.1, 0.1, 0.4], "id": 0, "ripe": False}]},
         r"fruit 2: id 0 is no mask label \(0 is the background"),
        ({"fruits": [{"min": [0, 0, 0.3], "max": [0.1, 0.1, 0.4], "id": -1}]}, "id must be a whole number in 1-"),
        # a misspelt key was dropped: "rip": false counted an unripe fruit as a target
        ({"fruits": [{"min": [0, 0, 0.3], "max": [0.1, 0.1, 0.4], "rip": False}]}, r"unknown key 'rip'; did you "
         "mean 'ripe'"),
        ({"fruits": [{"min": [0, 0, 0.3], "max": [0.1, 0.1, 0.4], "Visible": 0.5}]}, "did you mean 'visible'"),
        # before: "false" or 0 is not False, so an unripe fruit counted as a target
        ({"fruits": [{"min": [0, 0, 0.3], "max": [0.1, 0.1, 0.4], "ripe": "false"}]}, r"fruit 1: ripe must be true "
         "or false, got 'false'"),
        ({"fruits": [{"min": [0, 0, 0.3], "max": [0.1, 0.1, 0.4], "ripe": 0}]}, r"ripe must be true or false, got 0"),
        # before: two fruits of one id (one mask label), one of them matched by --match id and the other missed
        ({"fruits": [{"min": [0, 0, 0.3], "max": [0.1, 0.1, 0.4], "id": 3},
                     {"min": [0, 0, 0.3], "max": [0.1, 0.1, 0.4], "id": 3, "ripe": False}]},
         r"fruit 2: id 3 is fruit 1's too; each fruit has its own id"),
        ({"fruits": [{"min": [0, 0, 0.3], "max": [0.1, 0.1, 0.4], "id": 2},
                     {"min": [0, 0, 0.3], "max": [0.1, 0.1, 0.4]}]}, r"fruit 2: id 2 is fruit 1's too"),  # its number
        # before: numpy read the text "0.3" as 0.3 and true as 1 (metre)
        ({"fruits": [{"min": [0, 0, "0.3"], "max": [0.1, 0.1, 0.4]}]}, r"fruit 1: min must be three numbers, got "
         r"\[0, 0, '0\.3'\]"),
        ({"fruits": [{"min": [0, 0, 0.3], "max": [0.1, 0.1, True]}]}, r"fruit 1: max must be three numbers"),
    ],
)  # fmt: skip
def test_malformed_truth_names_the_file(tmp_path, truth, message):
    path = tmp_path / "truth.json"
    path.write_text(json.dumps(truth))
    with pytest.raises(FileFormatError, match=rf"truth\.json: expected .*{message}"):
        read_truth(path)


def test_truth_keys_other_tools_write_beside_the_read_ones_are_left_alone(tmp_path):
    fruit = {"id": 3, "ripe": True, "kind": "strawberry", "centre": [0.05, 0.05, 0.35], "size": [0.1] * 3,
             "min": [0, 0, 0.3], "max": [0.1, 0.1, 0.4], "visible_box": {}, "mask_area": 10, "score": 0.5}  # fmt: skip
    (tmp_path / "truth.json").write_text(json.dumps({"fruits": [fruit]}))
    assert [i for i, _ in read_truth(tmp_path / "truth.json")] == [3]


def test_an_unreadable_truth_file_is_named(tmp_path, monkeypatch):
    color, depth = disc_frame([(80, 60)])
    write_frame(tmp_path / "f", color, depth, SMALL_CAM, truth={"fruits": []})
    real_open = open

    def refuse(path, *args, **kwargs):  # root reads any file, so the permission error is simulated
        if str(path).endswith("truth.json"):
            raise PermissionError(13, "Permission denied")
        return real_open(path, *args, **kwargs)

    monkeypatch.setattr("builtins.open", refuse)
    with pytest.raises(FileFormatError, match=r"truth\.json: cannot read truth file \(Permission denied\)"):
        read_frame(tmp_path / "f")


def test_an_npz_named_depth_npy_is_refused(tmp_path):
    color, depth = disc_frame([(80, 60)])
    write_frame(tmp_path / "f", color, depth, SMALL_CAM)
    (tmp_path / "f" / "depth.png").unlink()
    np.savez(tmp_path / "d.npz", depth=depth)
    (tmp_path / "d.npz").rename(tmp_path / "f" / "depth.npy")
    with pytest.raises(FileFormatError, match=r"depth\.npy: is an \.npz archive"):
        read_frame(tmp_path / "f")


@pytest.mark.parametrize("mode, suffix", [("P", "png"), ("CMYK", "jpg"), ("RGBA", "png")])
def test_colour_in_any_mode_gives_the_same_fruit(tmp_path, example, mode, suffix):
    from symfruit.detect import detect

    folder = tmp_path / "f"
    shutil.copytree(EXAMPLE_FRAME, folder)
    (folder / "color.png").unlink()
    img = Image.fromarray(example.color).convert(mode)
    img.save(folder / f"color.{suffix}", **({"quality": 98} if suffix == "jpg" else {}))
    frame = read_frame(folder)
    assert frame.color.shape == example.color.shape and frame.color.dtype == np.uint8
    found = detect(frame, method="raw")
    assert len(found.detections) == 6  # what the RGB frame gives (a palette or a JPEG shifts colours a little)


_LEAVES = st.none() | st.booleans() | st.integers(-5, 5) | st.floats(allow_nan=False, allow_infinity=False)
_KEYS = st.sampled_from(["fruits", "min", "max", "id", "ripe"])
_JSON = st.recursive(
    _LEAVES | st.text(max_size=4),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(_KEYS, inner, max_size=4),
    max_leaves=20,
)


@settings()
@given(_JSON)
def test_truth_survives_any_json(tmp_path, data):
    path = tmp_path / "truth.json"
    path.write_text(json.dumps(data))
    try:
        truth = read_truth(path)
    except SymfruitError:
        return
    assert all(isinstance(k, int) and box.min.shape == (3,) for k, box in truth)


def test_a_phone_photo_turned_by_its_exif_orientation_must_agree_with_depth_and_intrinsics(tmp_path):
    cam = Camera(fx=50, fy=50, cx=20, cy=15, width=40, height=30)
    yy, xx = np.mgrid[0:30, 0:40]
    color = np.stack([xx * 6, yy * 8, np.full_like(xx, 128)], axis=2).astype(np.uint8)  # smooth: JPEG keeps it
    depth = np.full((30, 40), 0.5, np.float32)

    def tagged(img, path, orientation):
        exif = Image.Exif()
        exif[0x0112] = orientation
        img.save(path, exif=exif, quality=95)

    for orientation, does in ((6, "turned a quarter clockwise"), (3, "turned half around")):  # 3: sizes agree
        folder = tmp_path / f"o{orientation}"
        write_frame(folder, color, depth, cam)
        (folder / "color.png").unlink()
        tagged(Image.fromarray(color), folder / "color.jpg", orientation)
        said = (rf"o{orientation}/color\.jpg: its EXIF orientation {orientation} \({does}\) is applied on reading "
                r"\(images are read as displayed\), but depth\.png has 1 \(as stored\): depth registered to the "
                r"stored pixels would meet other pixels")  # fmt: skip
        with pytest.raises(FileFormatError, match=said):
            read_frame(folder)
    # depth tagged alike: both read as displayed; intrinsics for the stored pixels are then said to be so
    folder = tmp_path / "o6"
    with Image.open(folder / "depth.png") as img:
        tagged(img.copy(), folder / "depth.png", 6)
    said = (r"color\.jpg: its EXIF orientation 6 turns it a quarter on reading .*40x30 stored, 30x40 shown\), but "
            r"the intrinsics \(camera\.json\) is for the stored 40x30")  # fmt: skip
    with pytest.raises(FileFormatError, match=said):
        read_frame(folder)
    (folder / "camera.json").write_text(json.dumps(Camera(fx=50, fy=50, cx=15, cy=20, width=30, height=40).to_dict()))
    frame = read_frame(folder)
    assert frame.color.shape == (40, 30, 3) and frame.depth.shape == (40, 30)
    assert np.abs(frame.color.astype(int) - np.rot90(color, -1)).max() <= 8  # JPEG: close, not equal


@pytest.mark.parametrize("name", ["color.png", "depth.png", "camera.json", "masks.png", "truth.json"])
@pytest.mark.parametrize("kind", ["directory", "link loop", "dangling link"])
def test_a_frame_file_that_is_no_file_is_refused_by_name_not_taken_as_missing(tmp_path, name, kind):
    # a masks.png or truth.json folder was "no masks" / "no truth" (colour segmenter, no scores), in silence
    frame = tmp_path / "f"
    color, depth = disc_frame([(80, 60)])
    write_frame(frame, color, depth, CAM, truth={"fruits": []}, masks=np.zeros((120, 160), np.int32))
    (frame / name).unlink()
    if kind == "directory":
        (frame / name).mkdir()
    else:
        (frame / name).symlink_to(name if kind == "link loop" else "gone.png")
    why = "a directory, not a file" if kind == "directory" else "a link that leads to no file"
    with pytest.raises(FileFormatError, match=rf"f/{re.escape(name)}: {why}"):
        read_frame(frame)


def test_a_frames_masks_png_must_carry_the_colour_images_exif_orientation(tmp_path):
    # a mirrored or half-turned mask keeps the size: the size check alone paired it with the wrong pixels
    color, depth = disc_frame([(80, 60)])
    labels = np.zeros((120, 160), np.uint8)
    labels[40:80, 60:100] = 1
    folder = write_frame(tmp_path / "f", color, depth, CAM, masks=labels)
    exif = Image.Exif()
    exif[0x0112] = 2  # mirrored left-right on reading
    Image.fromarray(labels).save(folder / "masks.png", exif=exif)
    said = (
        r"f/color\.png: its EXIF orientation 1 \(as stored\) is applied on reading \(images are read as "
        r"displayed\), but masks\.png has 2 \(mirrored left-right\): labels registered to the stored pixels"
    )
    with pytest.raises(FileFormatError, match=said):
        read_frame(folder)
    exif[0x0112] = 1
    Image.fromarray(labels).save(folder / "masks.png", exif=exif)
    frame = read_frame(folder)
    assert np.array_equal(frame.masks, labels)
    assert frame.extras["color_file"] == (str(folder / "color.png"), 1)


def test_read_depth_is_the_one_depth_reader_of_frames_and_segment(tmp_path):
    from symfruit.batch import _read_depth
    from symfruit.io.frames import read_depth

    units = np.arange(12, dtype=np.uint16).reshape(3, 4) * 1000
    Image.fromarray(units).save(tmp_path / "d.png")
    color = (tmp_path / "c.png", 1)
    d32 = read_depth(tmp_path / "d.png", 0.001, color=color)
    d64 = read_depth(tmp_path / "d.png", 0.001, color=color, dtype=np.float64)
    assert d32.dtype == np.float32 and np.array_equal(d32, units.astype(np.float32) * np.float32(0.001))
    assert d64.dtype == np.float64 and np.array_equal(d64, units * 0.001)
    assert np.array_equal(_read_depth(tmp_path / "d.png", 0.001, (3, 4), tmp_path / "c.png", 1), d64)
    np.save(tmp_path / "d.npy", np.full((3, 4), 0.5, np.float32))
    assert read_depth(tmp_path / "d.npy", 0.001, color=color, dtype=np.float64).dtype == np.float64
    with pytest.raises(FileFormatError, match=r"c\.png: its EXIF orientation 6 .* but d\.png has 1"):
        read_depth(tmp_path / "d.png", 0.001, color=(tmp_path / "c.png", 6))
    with pytest.raises(FileFormatError, match=r"d\.png: depth is 4x3, the image 3x4"):
        _read_depth(tmp_path / "d.png", 0.001, (4, 3), tmp_path / "c.png", 1)


def test_depth_units_that_are_not_text_and_float64_depth_beyond_float32_are_no_python_errors(tmp_path):
    color, depth = disc_frame([(80, 60)])
    write_frame(tmp_path / "f", color, depth, CAM)
    cam = json.loads((tmp_path / "f" / "camera.json").read_text())
    for units in (["m"], {"m": 1}):
        (tmp_path / "f" / "camera.json").write_text(json.dumps({**cam, "depth_units": units}))
        with pytest.raises(InputError, match=r"camera\.json: unknown depth_units \[?\{?'m'"):  # not "unhashable"
            read_frame(tmp_path / "f")
    (tmp_path / "f" / "camera.json").write_text(json.dumps(cam))
    (tmp_path / "f" / "depth.png").unlink()
    huge = depth.astype(np.float64)
    huge[:10] = 1e300  # beyond float32: no depth there, never a RuntimeWarning (an error under pytest)
    np.save(tmp_path / "f" / "depth.npy", huge)
    got = read_frame(tmp_path / "f").depth
    assert not got[:10].any() and np.array_equal(got[10:], depth[10:])


@pytest.mark.parametrize(
    "extra, first, second",
    [("depth.npy", "depth.png", "depth.npy"), ("camera.yaml", "camera.json", "camera.yaml"),
     ("masks.json", "masks.png", "masks.json"), ("color.jpg", "color.png", "color.jpg")],
)  # fmt: skip
def test_a_frame_holding_two_depth_intrinsics_or_mask_files_is_refused(tmp_path, extra, first, second):
    frame = tmp_path / "f"
    shutil.copytree(EXAMPLE_FRAME, frame)
    Image.fromarray(np.zeros((480, 640), np.uint8)).save(frame / "masks.png")
    if extra == "depth.npy":  # depth that disagrees with depth.png: which one is meant?
        np.save(frame / extra, np.full((480, 640), 0.5))
    elif extra == "camera.yaml":
        (frame / extra).write_text("fx: 600\nfy: 600\ncx: 320\ncy: 240\nwidth: 640\nheight: 480\n")
    elif extra == "color.jpg":  # before: color.png taken in silence
        Image.new("RGB", (640, 480)).save(frame / extra)
    else:
        (frame / extra).write_text('{"annotations": []}')
    with pytest.raises(FileFormatError, match=rf"f: holds both {first} and {second}; which one is meant\? Keep one"):
        read_frame(frame)  # before: the first read, the other ignored in silence
    (frame / extra).unlink()
    assert read_frame(frame).camera.fx == 615.0


def test_the_depth_scale_an_intrinsics_file_states(tmp_path):
    from symfruit.io.frames import file_depth_scale

    for stated, scale in (({"depth_scale": 0.0001}, 0.0001), ({"depth_units": "cm"}, 0.01), ({}, None)):
        (tmp_path / "cam.json").write_text(json.dumps({**CAM.to_dict(), **stated}))
        assert file_depth_scale(tmp_path / "cam.json") == scale
    (tmp_path / "cam.json").write_text(json.dumps({**CAM.to_dict(), "depth_scale": 7}))
    with pytest.raises(InputError, match=r"cam\.json: depth_scale must be metres per unit in \(0, 1\], got 7"):
        file_depth_scale(tmp_path / "cam.json")


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"depth_scale": 0}, r"depth_scale must be metres per unit in \(0, 1\], got 0"),  # before: 65535s written
        ({"depth_scale": float("nan")}, r"depth_scale must be metres per unit in \(0, 1\], got nan"),
        ({"depth": np.full((4, 5), 70.0, np.float32)}, "depth reaches 70 m, beyond 65535 units of 0.001 m"),
        ({"depth": np.full((4, 5), 500, np.uint16)}, "depth is uint16; depth must be float metres"),
        ({"color": np.zeros((4, 5, 3))}, r"colour must be \(h, w, 3\) uint8 RGB, got float64"),
        ({"masks": np.full((4, 5), 70000)}, "masks hold label 70000; a 16-bit masks.png holds 0-65535"),  # wrapped
        ({"masks": np.full((4, 5), -1)}, "masks hold negative labels"),  # before: written as 65535
    ],
)
def test_write_frame_refuses_what_the_folder_would_read_back_as_something_else(tmp_path, changes, message):
    camera = Camera(fx=100, fy=100, cx=2.5, cy=2, width=5, height=4)
    args = {"color": np.zeros((4, 5, 3), np.uint8), "depth": np.full((4, 5), 0.5, np.float32), **changes}
    kwargs = {k: args.pop(k) for k in ("depth_scale", "masks") if k in args}
    with pytest.raises(InputError, match=message):
        write_frame(tmp_path / "f", args["color"], args["depth"], camera, **kwargs)
    assert not (tmp_path / "f").exists()  # refused before anything was written


def test_write_frame_refuses_an_empty_folder_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    color, depth = disc_frame([(80, 60)])
    with pytest.raises(InputError, match="write_frame: the frame folder is an empty path"):
        write_frame("", color, depth, SMALL_CAM)  # before: color.png, depth.png, camera.json into the working folder
    assert not list(tmp_path.iterdir())


def test_a_frame_whose_camera_json_does_not_fit_its_images_names_camera_json(tmp_path):
    """Stop 47 (robust47): the frame folder alone was named for intrinsics of another size, and depth.png for a
    camera.json depth_scale of 1e-9 ("give the depth scale its units stand for", which camera.json states)."""
    from symfruit.io.frames import read_frame

    frame = tmp_path / "frame"
    shutil.copytree(EXAMPLE_FRAME, frame)
    cam = json.loads((frame / "camera.json").read_text())
    (frame / "camera.json").write_text(json.dumps({**cam, "width": 1920}))
    with pytest.raises(InputError) as info:
        read_frame(frame)
    assert str(info.value) == (f"{frame / 'camera.json'}: intrinsics are for 1920x480 but the images are 640x480; "
                               "give the colour camera's intrinsics at the images' size")  # fmt: skip
    (frame / "camera.json").write_text(json.dumps({**cam, "depth_scale": 1e-9}))
    with pytest.raises(InputError) as info:
        read_frame(frame)
    assert str(info.value) == (f"{frame / 'camera.json'}: depth_scale 1e-09 m per unit: depth.png's 16-bit units "
                               "would reach only 6.55e-05 m, and no camera measures depth that finely (0.001 for "
                               "millimetres)")  # fmt: skip


def test_a_camera_json_depth_scale_of_metres_for_millimetre_units_names_camera_json(tmp_path):
    """Stop 48 (robust48): a depth_scale of 1 (metres per unit) over a millimetre depth.png was "FOLDER: depth is
    7009 m typically; depth must be metres (... multiply by the depth scale first)", the frame folder alone, when
    the scale camera.json states is what is wrong."""
    from symfruit.io.frames import read_frame

    frame = tmp_path / "frame"
    shutil.copytree(EXAMPLE_FRAME, frame)
    cam = json.loads((frame / "camera.json").read_text())
    (frame / "camera.json").write_text(json.dumps({**cam, "depth_scale": 1.0}))
    with pytest.raises(InputError) as info:
        read_frame(frame)
    typical = str(info.value).split("depth is ")[-1].split(" m typically")[0]
    assert 100 < float(typical) < 65535
    assert str(info.value) == (f"{frame / 'camera.json'}: at its depth scale, 1 m per unit, depth.png's depth is "
                               f"{typical} m typically: its units look like millimetres or finer; state their scale "
                               "(0.001 for millimetres)")  # fmt: skip
    (frame / "camera.json").write_text(json.dumps({**cam, "depth_scale": 0.01}))  # centimetres: up to 655 m, read
    assert read_frame(frame).depth.shape == (480, 640)


def test_write_frame_refuses_images_and_a_camera_of_other_sizes_before_writing(tmp_path):
    """Stop 50 (robust50): depth or masks of another size than the colour image, and a camera for another image
    size, were written (a folder read_frame then refuses); a camera given as a mapping was an AttributeError
    (``'dict' object has no attribute 'to_dict'``) after the images were written."""
    color, depth = disc_frame([(60, 60)], radius=15)
    cases = [
        (dict(depth=depth[:60]), r"depth is 160x60, the colour image 160x120; a frame's images are of one size"),
        (dict(masks=np.zeros((60, 160), np.uint8)), r"masks are 160x60, the colour image 160x120"),
        (dict(camera=Camera(fx=600.0, fy=600.0, cx=320.0, cy=240.0, width=640, height=480)),
         r"the camera is for 640x480 images, the colour image is 160x120"),
        (dict(camera=SMALL_CAM.to_dict()), r"camera must be a symfruit.Camera \(symfruit.io.camera_from_dict makes "
                                           r"one from a mapping\), got dict"),
    ]  # fmt: skip
    for k, (change, said) in enumerate(cases):
        args = {"color": color, "depth": depth, "camera": SMALL_CAM, **change}
        with pytest.raises(InputError, match=rf"^write_frame {re.escape(str(tmp_path / str(k)))}: {said}"):
            write_frame(tmp_path / str(k), **args)
        assert not (tmp_path / str(k)).exists()
    write_frame(tmp_path / "good", color, depth, SMALL_CAM, masks=np.zeros(depth.shape, np.uint8))
    assert read_frame(tmp_path / "good").depth.shape == depth.shape


def _change(path, how: str) -> None:
    """Change ``path`` as another program would while it is read: grow it, replace it with a copy of itself,
    rewrite it the same size (a newer modification time, or its times set back after) or remove it."""
    import os

    if how == "grown":
        with open(path, "ab") as f:
            f.write(b"\0" * 10)
    elif how == "replaced":
        shutil.copyfile(path, f"{path}.new")
        os.replace(f"{path}.new", path)
    elif how == "rewritten":
        st = os.stat(path)
        os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000))
    elif how == "set back":
        set_back(path)
    else:
        os.remove(path)


CHANGES = {
    "grown": r"its size went from ([\d,]+) to \1 bytes",  # the size said (filled in by the test)
    "replaced": r"it was replaced by another file",
    "rewritten": r"it was rewritten: its modification time changed",
    "set back": r"it was rewritten: its modification time was set back",  # flake54: not seen before
    "removed": r"it was removed",
}


@pytest.mark.parametrize("how", list(CHANGES))
def test_a_file_changed_while_the_frame_is_read_fails_the_frame_naming_it(tmp_path, monkeypatch, how):
    """Robust53: a frame's colour image changed after it was read and before the frame was whole (another
    program writing the folder) was taken as it was: the frame paired one moment's colour with another's depth.
    Now each file is looked at before and after, and one that changed fails the frame, naming it and how. The
    change is made by the reader of the depth (no race)."""
    import symfruit.io.frames as frames

    folder = tmp_path / "f"
    shutil.copytree(EXAMPLE_FRAME, folder)
    size = (folder / "color.png").stat().st_size
    after_its_status_time(folder / "color.png")  # "set back" is seen by it alone
    real = frames.read_depth

    def depth_then_change(*args, **kwargs):
        depth = real(*args, **kwargs)
        _change(folder / "color.png", how)
        return depth

    monkeypatch.setattr(frames, "read_depth", depth_then_change)
    said = CHANGES[how].replace(r"([\d,]+) to \1", f"{size:,} to {size + 10:,}")
    colour = re.escape(str(folder / "color.png"))
    with pytest.raises(FileFormatError, match=rf"^{colour}: changed while the frame was read \({said}\); it is being "
                       "written or replaced: read it again once it is whole$"):  # fmt: skip
        read_frame(folder)
    monkeypatch.setattr(frames, "read_depth", real)
    if how != "removed":
        assert read_frame(folder).color.shape  # read again once still: read


def test_a_file_cut_while_read_is_refused_as_changed_not_in_the_parsers_words(tmp_path, monkeypatch):
    """A depth PNG cut to a third while it is decoded fails the decoder; the change is the reason said."""
    import symfruit.io.images as images

    folder = tmp_path / "f"
    shutil.copytree(EXAMPLE_FRAME, folder)
    real = images._open

    def cut_then_open(source, label):
        if str(source).endswith("depth.png"):
            data = source.read_bytes()
            source.write_bytes(data[: len(data) // 3])
        return real(source, label)

    monkeypatch.setattr(images, "_open", cut_then_open)
    with pytest.raises(FileFormatError, match=r"depth\.png: changed while the frame was read \(its size went from"):
        read_frame(folder)


def test_a_batch_goes_on_past_a_frame_changed_while_it_was_read(tmp_path, monkeypatch):
    """Three frames, the second's depth grown while the frame is read: it fails by name, the others are done."""
    import symfruit.io.frames as frames
    from symfruit.batch import run_batch

    from ..conftest import small_frame

    rec = tmp_path / "rec"
    for k in range(3):
        shutil.copytree(small_frame(), rec / f"f_{k}")
    real = frames.read_depth

    def depth_then_change(path, *args, **kwargs):
        depth = real(path, *args, **kwargs)
        if path.parent.name == "f_1":
            _change(path, "grown")
        return depth

    monkeypatch.setattr(frames, "read_depth", depth_then_change)
    report = run_batch(rec, tmp_path / "out", method="raw", progress=False)
    assert sorted(report.done) == ["f_0", "f_2"]
    assert list(report.failed) == ["f_1"]
    assert report.failed["f_1"].startswith(f"{rec / 'f_1' / 'depth.png'}: changed while the frame was read (its size")
