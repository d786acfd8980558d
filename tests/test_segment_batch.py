"""`symfruit segment` and its batch (symfruit.batch.segment_images), label writers, the learned mask sources."""

import importlib.util
import json
import re
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from symfruit import Camera, FileFormatError, InputError, SymfruitError
from symfruit.batch import segment_images
from symfruit.cli import main
from symfruit.synthetic.scenes import make_photo
from symfruit.writers import draw_label_overlay, write_labels

RED = (200, 30, 40)


def _photos(folder, n=2):
    folder.mkdir(parents=True, exist_ok=True)
    for k in range(n):
        color, _ = make_photo([(80, 120, 40, RED), (230, 120, 40, RED)][: k + 1], seed=k)
        Image.fromarray(color).save(folder / f"p{k}.jpg", quality=95)
    return folder


def test_segment_images_writes_16_bit_labels_overlays_and_a_record(tmp_path):
    report = segment_images([_photos(tmp_path / "in")], output=tmp_path / "out")
    assert report.ok and [d.fruit for d in report.done] == [1, 2] and not any(d.used_depth for d in report.done)
    with Image.open(tmp_path / "out" / "p1.png") as img:
        assert img.mode.startswith("I;16") and np.asarray(img).max() == 2
    with Image.open(tmp_path / "out" / "p1_overlay.png") as img:
        assert img.size == (320, 240) and img.mode == "RGB"
    record = json.loads((tmp_path / "out" / "segment.json").read_text())
    assert record["mask_source"] == "colour segmenter" and len(record["images"]) == 2 and record["failed"] == []


def test_a_bad_image_is_reported_and_the_batch_goes_on(tmp_path):
    folder = _photos(tmp_path / "in")
    (folder / "broken.png").write_bytes(b"not a png")
    report = segment_images([folder], output=tmp_path / "out")
    assert not report.ok and len(report.done) == 2
    assert (
        list(report.failed) == [str(folder / "broken.png")]
        and "cannot read image" in report.failed[str(folder / "broken.png")]
    )


def test_a_mask_source_that_raises_is_contained(tmp_path):
    def flaky(color, depth=None, camera=None):
        if color[0, 0, 0] > 0:
            raise RuntimeError("boom")
        return np.zeros(color.shape[:2], np.int32)

    report = segment_images([_photos(tmp_path / "in")], output=tmp_path / "out", masks=flaky)
    assert len(report.failed) == 2 and all("RuntimeError: boom" in v for v in report.failed.values())


def test_label_ids_beyond_16_bits_are_refused_naming_the_image_and_the_limit(tmp_path):
    ids = [70000, 65535]  # p0.jpg, p1.jpg

    def wide(color, depth=None, camera=None):
        labels = np.zeros(color.shape[:2], np.int32)
        labels[:4, :4] = ids.pop(0)
        return labels

    folder = _photos(tmp_path / "in")
    report = segment_images([folder], output=tmp_path / "out", masks=wide)
    assert [d.path.name for d in report.done] == ["p1.jpg"]  # 65535 fits
    failed = report.failed[str(folder / "p0.jpg")]  # before: "out/p0.png: labels must be 0-65535 ..."
    assert failed == (
        f"{folder / 'p0.jpg'}: the mask source (wide) gave label id 70000; a 16-bit label PNG holds "
        "ids up to 65535: number the fruit 1..k"
    )
    assert not (tmp_path / "out" / "p0.png").exists()


def test_a_photo_turned_by_its_exif_orientation_is_segmented_as_displayed_and_stored_depth_refused(tmp_path):
    color, _ = make_photo([(80, 120, 40, RED)], seed=0)  # 320x240, the fruit left of centre
    exif = Image.Exif()
    exif[0x0112] = 8  # shown turned a quarter anticlockwise: 240x320, the fruit below the middle
    (tmp_path / "in").mkdir()
    Image.fromarray(color).save(tmp_path / "in" / "p0.jpg", exif=exif, quality=95)
    report = segment_images([tmp_path / "in"], output=tmp_path / "out")
    with Image.open(tmp_path / "out" / "p0.png") as img:
        labels = np.asarray(img)
    rows = np.nonzero(labels)[0]
    assert report.done[0].fruit == 1 and labels.shape == (320, 240) and rows.mean() > 160 + 60
    depth = tmp_path / "depth"
    depth.mkdir()
    Image.fromarray(np.full((240, 320), 400, np.uint16)).save(depth / "p0.png")  # for the stored pixels
    cam = Camera(fx=600, fy=600, cx=160, cy=120, width=320, height=240)
    bad = segment_images([tmp_path / "in"], output=tmp_path / "o2", depth=depth, camera=cam)
    assert re.search(r"p0\.jpg: its EXIF orientation 8 \(turned a quarter anticlockwise\) is applied on reading "
                     r".*, but p0\.png has 1 \(as stored\)", next(iter(bad.failed.values())))  # fmt: skip


def test_a_label_png_for_a_photo_must_carry_its_exif_orientation(tmp_path):
    # half a turn keeps the size: the labels were paired with the other end of the photo in silence
    color, _ = make_photo([(80, 120, 40, RED)], seed=0)
    exif = Image.Exif()
    exif[0x0112] = 3
    for folder in ("in", "labels"):
        (tmp_path / folder).mkdir()
    Image.fromarray(color).save(tmp_path / "in" / "p0.jpg", exif=exif, quality=95)
    labels = np.zeros(color.shape[:2], np.uint8)
    labels[80:160, 40:120] = 1
    Image.fromarray(labels).save(tmp_path / "labels" / "p0.png")
    bad = segment_images([tmp_path / "in"], output=tmp_path / "o1", masks=tmp_path / "labels")
    assert not bad.done and re.search(r"p0\.jpg: its EXIF orientation 3 \(turned half around\) .* but p0\.png has 1 "
                                      r"\(as stored\): labels registered", next(iter(bad.failed.values())))  # fmt: skip
    Image.fromarray(labels).save(tmp_path / "labels" / "p0.png", exif=exif)  # turned alike: read as displayed
    good = segment_images([tmp_path / "in"], output=tmp_path / "o2", masks=tmp_path / "labels")
    assert good.done[0].fruit == 1 and not good.failed


def test_a_depth_entry_that_is_no_file_is_refused_not_passed_over_for_colour_alone(tmp_path):
    folder = _photos(tmp_path / "in", n=1)
    depth = tmp_path / "depth"
    depth.mkdir()
    (depth / "p0.png").mkdir()  # was "no depth for p0": segmented on colour alone, in silence
    cam = Camera(fx=600, fy=600, cx=160, cy=120, width=320, height=240)
    report = segment_images([folder], output=tmp_path / "out", depth=depth, camera=cam)
    assert not report.done and re.search(r"depth/p0\.png: a directory, not a file", next(iter(report.failed.values())))
    (folder / "loop.jpg").symlink_to("loop.jpg")
    with pytest.raises(FileFormatError, match=r"loop\.jpg: a link that leads to no file"):
        segment_images([folder / "loop.jpg"], output=tmp_path / "o2")


def test_depth_from_a_folder_is_used_and_needs_a_camera(tmp_path):
    folder = _photos(tmp_path / "in", n=1)
    depth = tmp_path / "depth"
    depth.mkdir()
    Image.fromarray(np.full((240, 320), 400, np.uint16)).save(depth / "p0.png")
    cam = Camera(fx=600, fy=600, cx=160, cy=120, width=320, height=240)
    report = segment_images([folder], output=tmp_path / "out", depth=depth, camera=cam)
    assert report.done[0].used_depth and report.done[0].fruit == 1
    np.save(depth / "p0.npy", np.full((240, 320), 0.4))
    (depth / "p0.png").unlink()
    assert segment_images([folder], output=tmp_path / "o2", depth=depth, camera=cam).done[0].used_depth
    np.save(depth / "p0.npy", np.full((10, 10), 0.4))
    bad = segment_images([folder], output=tmp_path / "o3", depth=depth, camera=cam)
    assert "depth is" in next(iter(bad.failed.values()))
    with pytest.raises(InputError, match="camera"):
        segment_images([folder], output=tmp_path / "out", depth=depth)
    Image.fromarray(np.full((240, 320), 200, np.uint8)).save(depth / "p0.png")  # an 8-bit depth picture
    (depth / "p0.npy").unlink()
    eight = segment_images([folder], output=tmp_path / "o4", depth=depth, camera=cam)
    assert "p0.png: depth PNG is 8-bit" in next(iter(eight.failed.values()))  # recorded, the batch went on


def test_coco_and_label_folders_as_mask_sources(tmp_path):
    folder = _photos(tmp_path / "in", n=1)
    coco = {"images": [{"id": 1, "file_name": "p0.jpg", "height": 240, "width": 320}],
            "annotations": [{"id": 1, "image_id": 1, "category_id": 1,
                             "segmentation": [[40, 80, 120, 80, 120, 160, 40, 160]]}]}  # fmt: skip
    (tmp_path / "t.json").write_text(json.dumps(coco))
    report = segment_images([folder], output=tmp_path / "out", masks=tmp_path / "t.json")
    assert report.done[0].fruit == 1 and report.mask_source.endswith("t.json")
    labels = tmp_path / "labels"
    labels.mkdir()
    write_labels(labels / "p0.png", np.eye(240, 320, dtype=np.int32) * 3)
    assert segment_images([folder], output=tmp_path / "o2", masks=labels).done[0].fruit == 1
    with pytest.raises(InputError, match="--masks"):
        segment_images([folder], output=tmp_path / "o3", masks="nonsense")


def test_photos_of_one_name_in_two_folders_take_each_its_own_coco_entry(tmp_path):
    for row in ("row1", "row2"):
        _photos(tmp_path / row, n=1)
    coco = {"images": [{"id": 1, "file_name": "row1/p0.jpg"}, {"id": 2, "file_name": "row2/p0.jpg"}],
            "annotations": [{"id": 1, "image_id": 1, "category_id": 1,
                             "segmentation": [[40, 80, 120, 80, 120, 160, 40, 160]]}]}  # fmt: skip
    (tmp_path / "t.json").write_text(json.dumps(coco))
    report = segment_images([tmp_path / "row1", tmp_path / "row2"], output=tmp_path / "out", masks=tmp_path / "t.json")
    # before: both found by the file name p0.jpg alone, so row2/p0.jpg took row1/p0.jpg's fruit
    assert {d.path.parent.name: d.fruit for d in report.done} == {"row1": 1, "row2": 0}


def test_label_writer_and_overlay_refuse_what_does_not_fit(tmp_path):
    with pytest.raises(FileFormatError, match="0-65535"):
        write_labels(tmp_path / "a.png", np.full((4, 4), 70000))
    with pytest.raises(FileFormatError, match=r"\.png"):
        write_labels(tmp_path / "a.jpg", np.zeros((4, 4), np.int32))
    with pytest.raises(FileFormatError, match="integer"):
        write_labels(tmp_path / "a.png", np.zeros((4, 4)))
    with pytest.raises(FileFormatError):
        draw_label_overlay(np.zeros((4, 4, 3), np.uint8), np.zeros((5, 5), np.int32))


@pytest.mark.skipif(importlib.util.find_spec("torch") is not None, reason="torch is installed")
def test_maskrcnn_without_torch_says_which_extra_through_segment(tmp_path, capsys):
    folder = _photos(tmp_path / "in", n=1)
    with pytest.raises(SymfruitError, match=r"symfruit\[seg\]"):
        segment_images([folder], output=tmp_path / "out", masks="maskrcnn:model.pth")
    assert main(["segment", str(folder), "--output", str(tmp_path / "out"), "--masks", "maskrcnn:model.pth"]) == 2
    assert "symfruit[seg]" in capsys.readouterr().err


def test_cli_segment_evaluate_masks_and_bench_segment(tmp_path, capsys):
    folder = _photos(tmp_path / "in")
    assert main(["segment", str(folder), "--output", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert "p1.jpg: 2 fruit (colour alone" in out and "segment (colour segmenter): 2 images, 3 fruit, 0 failed" in out
    coco = {"images": [{"id": 1, "file_name": "p0.jpg", "height": 240, "width": 320}],
            "annotations": [{"id": 1, "image_id": 1, "category_id": 1,
                             "segmentation": [[40, 80, 120, 80, 120, 160, 40, 160]]}]}  # fmt: skip
    (tmp_path / "t.json").write_text(json.dumps(coco))
    args = ["evaluate", "--protocol", "masks", "--images", str(folder), "--truth", str(tmp_path / "t.json")]
    assert main([*args, "--output", str(tmp_path / "res")]) == 0
    out = capsys.readouterr().out
    assert "1 true fruit" in out and "mean best-match IoU" in out
    assert (tmp_path / "res" / "latest" / "worst.png").is_file()
    assert main(["evaluate", "--protocol", "masks", "--images", str(folder), "--output", str(tmp_path)]) == 2
    assert "needs both" in capsys.readouterr().err
    assert main(["bench", "--segment", "--images", str(folder), "--json"]) == 0  # the 24 synthetic: test_bench
    row = json.loads(capsys.readouterr().out)["segment"]
    assert row["images"] == 2 and row["width"] == 640 and row["median_ms"] > 0


def _photo(path, k=0, fmt=None):
    color, _ = make_photo([(80, 120, 40, RED), (230, 120, 40, RED)][: k + 1], seed=k)
    Image.fromarray(color).save(path, format=fmt)
    return color


def test_stems_that_collide_get_names_that_cannot(tmp_path):
    folder = tmp_path / "in"
    folder.mkdir()
    for k, name in enumerate(["a.png", "a-2.png", "a.jpg", "a_overlay.png"]):
        _photo(folder / name, k % 2)
    report = segment_images([folder], output=tmp_path / "out")
    assert report.ok and len(report.done) == 4
    written = [p for d in report.done for p in d.written]
    assert len(set(written)) == 8 and all(p.is_file() for p in written)  # nothing written twice
    for d in report.done:  # every label image is its own image's: its fruit count
        with Image.open(d.written[0]) as img:
            assert int(np.asarray(img).max()) == d.fruit
    record = json.loads((tmp_path / "out" / "segment.json").read_text())
    assert sorted(w for i in record["images"] for w in i["written"]) == sorted(map(str, written))


def test_the_input_folder_as_output_is_refused_and_the_photos_stay(tmp_path):
    from symfruit import OutputError

    folder = _photos(tmp_path / "in")
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    with pytest.raises(OutputError, match="also an input folder"):
        segment_images([folder], output=folder)
    with pytest.raises(OutputError, match="also an input folder"):
        segment_images([folder / "p0.jpg"], output=folder)
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before
    assert main(["segment", str(folder), "--output", str(folder)]) == 2


def test_a_folder_yields_every_format_read_when_named(tmp_path):
    folder = tmp_path / "in"
    folder.mkdir()
    _photo(folder / "g.gif", fmt="GIF")
    _photo(folder / "p.ppm", fmt="PPM")
    (folder / "notes.txt").write_text("not an image")
    (folder / ".hidden.png").write_bytes(b"")
    report = segment_images([folder], output=tmp_path / "out")
    assert sorted(d.path.name for d in report.done) == ["g.gif", "p.ppm"] and report.ok


def test_intrinsics_of_another_resolution_are_refused_with_depth(tmp_path):
    folder = _photos(tmp_path / "in", n=1)
    depth = tmp_path / "depth"
    depth.mkdir()
    Image.fromarray(np.full((240, 320), 400, np.uint16)).save(depth / "p0.png")
    cam = Camera(fx=900, fy=900, cx=640, cy=360, width=1280, height=720)
    report = segment_images([folder], output=tmp_path / "out", depth=depth, camera=cam)
    assert not report.done and "intrinsics (--camera) are for 1280x720 but the image is 320x240" in next(
        iter(report.failed.values())
    )


def test_mask_sources_beyond_the_bounds_are_refused(tmp_path):
    folder = _photos(tmp_path / "in", n=1)
    labels = tmp_path / "labels"
    labels.mkdir()
    many = (np.arange(240 * 320).reshape(240, 320) % 1500 + 1).astype(np.uint16)
    Image.fromarray(many).save(labels / "p0.png")
    report = segment_images([folder], output=tmp_path / "out", masks=labels)
    assert "1500 instances; at most 1000" in next(iter(report.failed.values()))

    def huge_ids(color, depth=None, camera=None):
        out = np.zeros(color.shape[:2], np.int64)
        out[:10, :10], out[-10:, -10:] = 1, 2**32 + 1
        return out

    report = segment_images([folder], output=tmp_path / "o2", masks=huge_ids)
    assert "beyond 32 bits" in next(iter(report.failed.values())) and not (tmp_path / "o2" / "p0.png").exists()


def test_an_image_beyond_16384_pixels_a_side_is_refused_by_name(tmp_path):
    Image.new("RGB", (30000, 20), (200, 30, 40)).save(tmp_path / "wide.png")
    report = segment_images([tmp_path / "wide.png"], output=tmp_path / "out")
    assert (
        "wide.png: image is 30000x20 pixels; at most 16384 pixels a side" in report.failed[str(tmp_path / "wide.png")]
    )


def test_a_full_disk_records_every_image(tmp_path, monkeypatch):
    import errno

    from symfruit import OutputError, batch

    folder = _photos(tmp_path / "in", n=2)
    _photo(folder / "p2.png")

    def full(path, labels):
        raise OutputError(f"{path}: cannot write (No space left on device)", errno.ENOSPC)

    monkeypatch.setattr("symfruit.writers.write_labels", full)
    report = batch.segment_images([folder], output=tmp_path / "out")
    assert len(report.failed) == 1 and len(report.unprocessed) == 2 and "output is full" in report.stopped
    record = json.loads((tmp_path / "out" / "segment.json").read_text())
    assert len(record["failed"]) + len(record["unprocessed"]) == 3


def test_an_entry_named_as_an_image_that_is_no_file_is_reported_not_left_out(tmp_path):
    import os

    folder = _photos(tmp_path / "in", n=1)
    (folder / "gone.png").symlink_to(tmp_path / "nowhere.png")  # a dangling link
    (folder / "loop.png").symlink_to("loop.png")  # a link to itself
    os.mkfifo(folder / "pipe.png")  # reading it would wait for a writer
    (folder / "sub.png").mkdir()  # a folder: not an image, left out
    report = segment_images([folder], output=tmp_path / "out")
    assert [d.path.name for d in report.done] == ["p0.jpg"]
    assert sorted(Path(k).name for k in report.failed) == ["gone.png", "loop.png", "pipe.png"]
    assert "pipe.png: is a pipe or a socket" in report.failed[str(folder / "pipe.png")]


def test_one_depth_file_for_several_images_or_a_device_as_depth_is_refused_before_any_image(tmp_path):
    camera = Camera(fx=100, fy=100, cx=20, cy=15, width=40, height=30)
    for name in ("a.png", "b.png"):
        Image.fromarray(np.zeros((30, 40, 3), np.uint8)).save(tmp_path / name)
    Image.fromarray(np.full((30, 40), 500, np.uint16)).save(tmp_path / "depth.png")
    images = [tmp_path / "a.png", tmp_path / "b.png"]
    with pytest.raises(InputError, match="is one file but there are 2 images"):  # before: each image failed so
        segment_images(images, output=tmp_path / "out", depth=tmp_path / "depth.png", camera=camera, progress=False)
    with pytest.raises(FileFormatError, match="/dev/zero: not a regular file"):  # before: the image failed
        segment_images(images[:1], output=tmp_path / "out", depth="/dev/zero", camera=camera, progress=False)
    assert not (tmp_path / "out").exists()


def test_a_depth_folder_holding_no_images_depth_is_refused_not_read_as_colour_alone(tmp_path):
    """Stop 48 (robust48): `segment --depth FOLDER` of a folder holding none of the images' depth (a wrong
    folder) segmented every image on colour alone, said only in the summary's note."""
    folder = _photos(tmp_path / "in", n=2)
    depth = tmp_path / "depth"
    depth.mkdir()
    Image.fromarray(np.full((240, 320), 400, np.uint16)).save(depth / "other.png")
    cam = Camera(fx=600, fy=600, cx=160, cy=120, width=320, height=240)
    with pytest.raises(FileFormatError) as info:
        segment_images([folder], output=tmp_path / "out", depth=depth, camera=cam)
    assert str(info.value) == (f"{depth}: holds the depth of none of the 2 image(s) (looked for p0.png / .npy / "
                               "p0_depth.png / .npy): is it the depth folder?")  # fmt: skip
    assert not (tmp_path / "out").exists()
    Image.fromarray(np.full((240, 320), 400, np.uint16)).save(depth / "p1_depth.png")  # one image's: as before
    report = segment_images([folder], output=tmp_path / "out", depth=depth, camera=cam)
    assert [d.used_depth for d in report.done] == [False, True]
