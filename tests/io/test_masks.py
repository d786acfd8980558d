"""COCO instance masks read safely (symfruit.io.masks): sizes checked against the image before allocating."""

import json

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from symfruit import FileFormatError
from symfruit.io import masks as io_masks
from symfruit.io.masks import coco_masks, read_coco, rle_decode


def _write(tmp_path, data, name="c.json"):
    path = tmp_path / name
    path.write_text(json.dumps(data))
    return path


def _coco(segmentation, *, height=20, width=30, file_name="dir/a.jpg"):
    return {
        "images": [{"id": 1, "file_name": file_name, "height": height, "width": width}],
        "annotations": [{"id": 5, "image_id": 1, "category_id": 1, "segmentation": segmentation}],
        "categories": [{"id": 1, "name": "fruit"}],
    }


def rle_counts(mask):
    flat = mask.T.ravel().astype(np.int8)  # COCO runs go down the columns, starting with zeros
    change = np.flatnonzero(np.diff(np.r_[0, flat, 1 - flat[-1]]))
    return np.diff(np.r_[0, change]).tolist()


def test_instances_from_polygons_and_rle_by_base_name(tmp_path):
    mask = np.zeros((20, 30), bool)
    mask[5:10, 3:12] = True
    coco = _coco([[3, 5, 11, 5, 11, 9, 3, 9]])
    coco["annotations"].append({"id": 6, "image_id": 1, "category_id": 2,
                                "segmentation": {"size": [20, 30], "counts": rle_counts(mask)}})  # fmt: skip
    c = read_coco(_write(tmp_path, coco))
    assert c.categories == {1: "fruit"} and [e["id"] for e in c.entries()] == [1]
    got = c.instances("a.jpg", (20, 30))  # the base name finds "dir/a.jpg"
    assert got.shape == (1, 20, 30) and np.array_equal(got[0], mask)
    both = c.instances("some/where/a.jpg", (20, 30), category=None)
    assert both.shape == (2, 20, 30) and np.array_equal(both[1], mask)
    with pytest.raises(FileFormatError, match="no image"):
        c.instances("b.jpg", (20, 30))


def test_sizes_in_the_file_are_checked_against_the_image(tmp_path):
    c = read_coco(_write(tmp_path, _coco([[0, 0, 5, 0, 5, 5]])))
    with pytest.raises(FileFormatError, match="30x20 in the file but 40x20 on disk"):
        c.instances("a.jpg", (20, 40))
    huge = _coco({"size": [100000, 100000], "counts": [10**10]})  # would allocate 10 GB if trusted
    c = read_coco(_write(tmp_path, huge, "huge.json"))
    with pytest.raises(FileFormatError, match="RLE size"):
        c.instances("a.jpg", (20, 30))
    with pytest.raises(FileFormatError, match="RLE size"):
        coco_masks(tmp_path / "huge.json", (20, 30))


def test_bad_segmentations_name_the_annotation(tmp_path):
    for seg in ([[0, 0, "x", 1, 2, 2]], [[0, 0, float("nan"), 1, 2, 2]], "polygon", {"size": [20, 30], "counts": [1]}):
        text = json.dumps(_coco(seg)).replace("NaN", "NaN")
        path = tmp_path / "bad.json"
        path.write_text(text)
        with pytest.raises(FileFormatError, match="annotation 5"):
            read_coco(path).instances("a.jpg", (20, 30))


def test_not_coco_and_too_large_files_are_refused(tmp_path, monkeypatch):
    with pytest.raises(FileFormatError, match="'images' and 'annotations'"):
        read_coco(_write(tmp_path, {"images": []}))
    with pytest.raises(FileFormatError, match="file_name"):
        read_coco(_write(tmp_path, {"images": [{"id": 1}], "annotations": []}))
    (tmp_path / "broken.json").write_text("{")
    with pytest.raises(FileFormatError, match="not valid JSON"):
        read_coco(tmp_path / "broken.json")
    monkeypatch.setattr(io_masks, "MAX_COCO_BYTES", 100)
    with pytest.raises(FileFormatError, match="larger than"):
        read_coco(_write(tmp_path, _coco([[0, 0, 5, 0, 5, 5]] * 20)))


def test_too_many_annotations_for_one_image_are_refused(tmp_path, monkeypatch):
    coco = _coco([[0, 0, 5, 0, 5, 5]])
    coco["annotations"] *= 5
    monkeypatch.setattr(io_masks, "MAX_INSTANCES_PER_IMAGE", 3)
    with pytest.raises(FileFormatError, match="at most 3"):
        read_coco(_write(tmp_path, coco)).instances("a.jpg", (20, 30))


def test_rle_decoder_bounds_and_string_form():
    mask = np.zeros((7, 5), bool)
    mask[2:5, 1:3] = True
    assert np.array_equal(rle_decode({"size": [7, 5], "counts": rle_counts(mask)}), mask)
    with pytest.raises(ValueError, match="out of range"):
        rle_decode({"size": [10**6, 10**6], "counts": [1]})
    with pytest.raises(ValueError):
        rle_decode({"size": [7, 5], "counts": "\x7f\x7f"})  # a truncated compressed string


_json = st.recursive(
    st.none() | st.booleans() | st.integers(-(10**12), 10**12) | st.floats(allow_nan=True) | st.text(max_size=8),
    lambda inner: (
        st.lists(inner, max_size=6) | st.dictionaries(st.sampled_from(["size", "counts", "x"]), inner, max_size=3)
    ),
    max_leaves=20,
)


@given(segmentation=_json, height=st.one_of(st.integers(-5, 50), st.text(max_size=3)), width=st.integers(1, 40))
def test_any_annotation_gives_masks_or_a_file_format_error(tmp_path_factory, segmentation, height, width):
    path = tmp_path_factory.mktemp("fuzz") / "c.json"
    coco = _coco(segmentation, height=height, width=width)
    path.write_text(json.dumps(coco))
    try:
        masks = read_coco(path).instances("a.jpg", (20, 30))
    except FileFormatError:
        return
    assert masks.dtype == bool and masks.shape == (1, 20, 30)
