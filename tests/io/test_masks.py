"""Fruit masks from files: instance label PNGs and COCO-style JSON (polygons, uncompressed and compressed RLE)."""

import json

import numpy as np
import pytest

from symfruit import FileFormatError
from symfruit.io.masks import coco_masks, read_masks, rle_decode


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


def test_a_frame_folder_gives_its_masks_file(tmp_path):
    from PIL import Image

    labels = np.zeros((12, 16), np.uint8)
    labels[2:5, 3:9] = 4
    Image.fromarray(labels).save(tmp_path / "masks.png")
    assert np.array_equal(read_masks(tmp_path, (12, 16)), labels)
    (tmp_path / "masks.png").unlink()
    coco = {"annotations": [{"segmentation": {"size": [12, 16], "counts": [12 * 16]}}]}  # all background
    (tmp_path / "masks.json").write_text(json.dumps(coco))
    assert not read_masks(tmp_path, (12, 16)).any()


def test_coco_uses_the_first_image_and_ids_or_order(tmp_path):
    square = [[2, 2, 5, 2, 5, 5, 2, 5]]
    coco = {
        "images": [{"id": 3}, {"id": 4}],
        "annotations": [
            {"id": 9, "image_id": 3, "segmentation": square},
            {"image_id": 4, "segmentation": [[0, 0, 9, 0, 9, 9, 0, 9]]},  # another image: ignored
            {"id": -1, "image_id": 3, "segmentation": [[7, 7, 9, 7, 9, 9, 7, 9]]},  # no usable id: its order
        ],
    }
    path = tmp_path / "a.json"
    path.write_text(json.dumps(coco))
    labels = coco_masks(path, (10, 10))
    assert set(np.unique(labels)) == {0, 2, 9}  # 2: second of this image's annotations
    assert (labels == 9).sum() == 16 and labels[3, 3] == 9 and labels[8, 8] == 2 and labels[0, 0] == 0
    bare = tmp_path / "bare.json"
    bare.write_text(json.dumps([{"segmentation": square}]))  # a plain list of annotations
    assert (coco_masks(bare, (10, 10)) == 1).sum() == 16


@pytest.mark.parametrize(
    "data, message",
    [
        ({"annotations": {"a": 1}}, "expected a COCO 'annotations' list"),
        ({"annotations": [{"id": 1}]}, "annotation 1 has no valid segmentation"),
        ({"annotations": [{"segmentation": {"size": [10, 10], "counts": [5]}}]}, "annotation 1 has no valid"),
        ({"annotations": [{"segmentation": {"size": [4, 4], "counts": [16]}}]}, "annotation 1 is 4x4, the image 10x10"),
    ],
)
def test_bad_coco_files_name_the_file_and_annotation(tmp_path, data, message):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    with pytest.raises(FileFormatError, match=rf"bad\.json: {message}"):
        read_masks(path, (10, 10))


def test_rle_counts_must_cover_the_image():
    with pytest.raises(ValueError, match="add up to 5, expected 35"):
        rle_decode({"size": [7, 5], "counts": [5]})


def test_other_extensions_are_refused(tmp_path):
    with pytest.raises(FileFormatError, match=r"m\.npy: masks must be a label \.png or a COCO \.json"):
        read_masks(tmp_path / "m.npy", (10, 10))
