"""symfruit.segment.mask_source: one parser for every mask spec, frames and image sets alike."""

import json

import numpy as np
import pytest
from PIL import Image

from symfruit import InputError
from symfruit.segment import MaskSource, mask_source
from symfruit.synthetic.scenes import make_photo

RED = (200, 30, 40)


@pytest.fixture(scope="module")
def photo():
    color, truth = make_photo([(80, 120, 40, RED), (230, 120, 40, RED)], seed=0)
    return color, truth


def test_auto_takes_a_frames_own_masks_else_the_colour_segmenter(photo):
    color, _ = photo
    own = np.zeros(color.shape[:2], np.int32)
    own[10:20, 10:20] = 1
    source = mask_source("auto")
    labels, word = source(color, own=own)
    assert labels is own and word == "frame masks file"
    labels, word = source(color)
    assert word == "colour segmenter" and len(np.unique(labels[labels > 0])) == 2
    assert np.array_equal(mask_source("color")(color)[0], labels)


def test_a_frames_label_png_and_a_set_of_images_label_folder(photo, tmp_path):
    color, _ = photo
    labels = np.zeros(color.shape[:2], np.uint16)
    labels[5:50, 5:50] = 3
    Image.fromarray(labels).save(tmp_path / "p0.png")
    got, word = mask_source(tmp_path / "p0.png")(color)
    assert word == str(tmp_path / "p0.png") and np.array_equal(got, labels)
    folder = mask_source(tmp_path, images=[tmp_path / "p0.jpg"])
    assert isinstance(folder, MaskSource) and folder.name == str(tmp_path)
    assert np.array_equal(folder(color, name="p0.jpg")[0], labels)
    with pytest.raises(Exception, match=r"no label image for p1\.jpg"):
        folder(color, name="p1.jpg")
    one = mask_source(tmp_path / "p0.png", images=[tmp_path / "x.jpg"])  # one label PNG for one image
    assert np.array_equal(one(color, name="x.jpg")[0], labels)


def test_a_coco_file_gives_each_image_its_annotations_by_name(photo, tmp_path):
    color, _ = photo
    h, w = color.shape[:2]
    coco = {"images": [{"id": 1, "file_name": "a.jpg", "width": w, "height": h}],
            "annotations": [{"id": 1, "image_id": 1, "category_id": 1,
                             "segmentation": [[10, 10, 40, 10, 40, 40, 10, 40]]}],
            "categories": [{"id": 1, "name": "fruit"}]}  # fmt: skip
    (tmp_path / "t.json").write_text(json.dumps(coco))
    source = mask_source(tmp_path / "t.json", images=[tmp_path / "a.jpg"])
    labels, _ = source(color, name="a.jpg")
    assert labels.max() == 1 and labels[25, 25] == 1 and labels[60, 60] == 0


def test_a_coco_file_of_a_recording_gives_each_frame_its_own_image(photo, tmp_path):
    """One COCO file for several frames: each frame its own image's masks, by the frame folder's name (the image's
    file name or folder); a frame it holds no image of is refused, never given another frame's masks."""
    from symfruit import FileFormatError

    color, _ = photo
    h, w = color.shape[:2]
    square = [[10, 10, 40, 10, 40, 40, 10, 40]]
    coco = {"images": [{"id": 1, "file_name": "capture_1/color.png", "width": w, "height": h},
                       {"id": 2, "file_name": "capture_2.png", "width": w, "height": h}],
            "annotations": [{"id": 1, "image_id": 1, "category_id": 1, "segmentation": square},
                            {"id": 2, "image_id": 2, "category_id": 1, "segmentation": [[60, 60, 90, 60, 90, 90]]},
                            {"id": 3, "image_id": 2, "category_id": 1, "segmentation": square}]}  # fmt: skip
    (tmp_path / "all.json").write_text(json.dumps(coco))
    source = mask_source(tmp_path / "all.json")
    first, word = source(color, name="capture_1")
    assert word == str(tmp_path / "all.json") and first.max() == 1 and first[25, 25] == 1 and first[65, 80] == 0
    second, _ = source(color, name="capture_2")
    assert second.max() == 2 and second[25, 25] == 2 and second[65, 80] == 1
    with pytest.raises(FileFormatError, match=r"no image for frame 'capture_3' among its 2 images"):
        source(color, name="capture_3")
    coco["images"][1]["file_name"] = "capture_1.png"  # two images would fit frame capture_1
    (tmp_path / "two.json").write_text(json.dumps(coco))
    with pytest.raises(FileFormatError, match=r"2 images \('capture_1.png', 'capture_1/color.png'\) for frame"):
        mask_source(tmp_path / "two.json")(color, name="capture_1")
    coco["images"], coco["annotations"] = coco["images"][:1], coco["annotations"][:1]  # one image: any frame's
    (tmp_path / "one.json").write_text(json.dumps(coco))
    assert mask_source(tmp_path / "one.json")(color, name="elsewhere")[0][25, 25] == 1


def test_a_folder_of_each_frames_masks(photo, tmp_path):
    from symfruit import FileFormatError

    color, _ = photo
    labels = np.zeros(color.shape[:2], np.uint16)
    labels[5:50, 5:50] = 3
    Image.fromarray(labels).save(tmp_path / "frame_1.png")
    (tmp_path / "frame_2").mkdir()
    Image.fromarray(labels * 2).save(tmp_path / "frame_2" / "masks.png")
    source = mask_source(tmp_path)
    got, word = source(color, name="frame_1")
    assert np.array_equal(got, labels) and word == str(tmp_path / "frame_1.png")
    assert np.array_equal(source(color, name="frame_2")[0], labels * 2)
    with pytest.raises(FileFormatError, match=r"no masks for frame 'frame_3' \(frame_3.png, or frame_3/masks.png"):
        source(color, name="frame_3")
    Image.fromarray(labels).save(tmp_path / "frame_2.png")  # and <frame>.png besides <frame>/masks.png: which?
    with pytest.raises(FileFormatError, match=r"holds both .*frame_2\.png and .*frame_2/masks\.png for frame"):
        source(color, name="frame_2")
    (tmp_path / "frame_2.png").unlink()
    (tmp_path / "frame_2" / "masks.json").write_text("{}")
    with pytest.raises(FileFormatError, match=r"holds both .*frame_2/masks\.png and .*frame_2/masks\.json"):
        source(color, name="frame_2")
    Image.fromarray(labels).save(tmp_path / "masks.png")  # a frame folder's own masks file: every frame's
    assert np.array_equal(mask_source(tmp_path)(color, name="frame_2")[0], labels)


def test_a_frame_whose_name_holds_dots_takes_its_own_masks(photo, tmp_path):
    color, _ = photo
    labels = np.zeros(color.shape[:2], np.uint16)
    labels[5:50, 5:50] = 1
    Image.fromarray(labels).save(tmp_path / "day.1.png")
    Image.fromarray(labels * 2).save(tmp_path / "day.2.png")
    Image.fromarray(labels * 3).save(tmp_path / "day.png")
    source = mask_source(tmp_path)
    for name, k in (("day.1", 1), ("day.2", 2), ("day", 3)):  # before: "day.png" for all three
        got, word = source(color, name=name)
        assert got[25, 25] == k and word == str(tmp_path / f"{name}.png")
    h, w = color.shape[:2]
    square, triangle = [[10, 10, 40, 10, 40, 40, 10, 40]], [[60, 60, 90, 60, 90, 90]]
    coco = {"images": [{"id": 1, "file_name": "day/color.png", "width": w, "height": h},
                       {"id": 2, "file_name": "day.2/color.png", "width": w, "height": h}],
            "annotations": [{"id": 1, "image_id": 1, "category_id": 1, "segmentation": square},
                            {"id": 2, "image_id": 2, "category_id": 1, "segmentation": triangle}]}  # fmt: skip
    (tmp_path / "all.json").write_text(json.dumps(coco))
    got = mask_source(tmp_path / "all.json")(color, name="day.2")[0]  # before: frame "day"'s image
    assert got[25, 25] == 0 and got[65, 80] == 1


def test_an_unknown_spec_for_images_names_what_is_accepted(tmp_path):
    with pytest.raises(InputError, match="expected color, maskrcnn:CHECKPOINT"):
        mask_source("auto", images=[tmp_path / "a.jpg"])  # `auto` is a frame's word only
    with pytest.raises(InputError, match=r"one label \.png for one image"):
        mask_source(tmp_path / "nothing.txt", images=[tmp_path / "a.jpg"])
    for images in (None, [tmp_path / "a.jpg"]):  # an empty spec is not the working folder's label PNGs
        with pytest.raises(InputError, match=r"^--masks '': expected color"):
            mask_source("", images=images)


def test_a_label_png_must_turn_on_reading_as_its_colour_image_did(photo, tmp_path):
    color, _ = photo
    labels = np.zeros(color.shape[:2], np.uint8)
    labels[5:50, 5:50] = 1
    exif = Image.Exif()
    exif[0x0112] = 4  # mirrored top-bottom: the size agrees
    Image.fromarray(labels).save(tmp_path / "p0.png", exif=exif)
    for source, name in ((mask_source(tmp_path / "p0.png"), ""), (mask_source(tmp_path, images=[]), "p0.jpg")):
        with pytest.raises(Exception, match=r"p0\.jpg: its EXIF orientation 1 .* but p0\.png has 4 \(mirrored"):
            source(color, name=name, color_file=(tmp_path / "p0.jpg", 1))
        got = source(color, name=name, color_file=(tmp_path / "p0.jpg", 4))[0]
        assert np.array_equal(got, labels[::-1])


@pytest.mark.parametrize("spec", ["missing.png", "foo:bar", "maskrcnn:", "nowhere/"])
def test_a_masks_spec_naming_no_file_or_folder_is_refused_when_the_source_is_made(tmp_path, spec):
    # before: a source made, then every frame failed with 'no such image'
    with pytest.raises(InputError, match="no such file or folder"):
        mask_source(str(tmp_path / spec) if "/" in spec or "." in spec else spec)


def test_a_masks_file_that_is_no_png_or_json_is_refused_when_the_source_is_made(tmp_path):
    from symfruit import FileFormatError

    (tmp_path / "labels.tif").write_bytes(b"")
    with pytest.raises(FileFormatError, match=r"labels\.tif: masks must be a label \.png or a COCO \.json"):
        mask_source(tmp_path / "labels.tif")


def test_a_frames_mask_that_is_a_link_loop_or_a_folder_is_refused_by_name_not_taken_for_none(photo, tmp_path):
    """Robust53: ``detect --masks FOLDER`` whose ``<frame>.png`` was a link that loops (or leads nowhere, or a
    folder) said "no masks for frame" as if nothing had that name."""
    import os

    from symfruit import FileFormatError

    color, _ = photo
    os.symlink("frame_1.png", tmp_path / "frame_1.png")
    os.symlink("gone.png", tmp_path / "frame_2.png")
    (tmp_path / "frame_3.png").mkdir()
    source = mask_source(tmp_path)
    for name, why in (("frame_1", "a link that leads to no file"), ("frame_2", "a link that leads to no file"),
                      ("frame_3", "a directory, not a file")):  # fmt: skip
        with pytest.raises(FileFormatError, match=rf"{name}\.png: {why}"):
            source(color, name=name)
