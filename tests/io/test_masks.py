"""Fruit masks from files: instance label PNGs and COCO-style JSON (polygons, uncompressed and compressed RLE),
read safely: sizes in the file checked against the image before anything is allocated."""

import json
import re

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from PIL import Image

from symfruit import FileFormatError, InputError
from symfruit.io import masks as io_masks
from symfruit.io.masks import coco_masks, read_coco, read_masks, rle_decode


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
    "change, error",
    [({"id": 2**40}, r"annotation 1 has id 1099511627776; a fruit's id is a whole number 1 to 2147483647"),
     ({"id": 1.5}, r"annotation 1 has id 1\.5"), ({"id": True}, r"annotation 1 has id True"),
     ({"id": "7"}, r"annotation 1 has id '7'"),
     ({"segmentation": []}, r"annotation 1 has no valid segmentation \(segmentation is an empty list\)"),
     ({"segmentation": None}, r"annotation 1 has no valid segmentation \(segmentation must be polygons \(a list\) "
                              r"or an RLE \(an object\), got null\)$"),  # robust53: was "... is a NoneType"
     ({"segmentation": "abc"}, r"\(segmentation must be polygons \(a list\) or an RLE \(an object\), got 'abc'\)$")],
)  # fmt: skip
def test_a_frames_coco_id_that_cannot_be_a_label_or_an_empty_outline_is_refused(tmp_path, change, error):
    """Before: the id replaced by the annotation's place (matched to another fruit's truth), the fruit without
    an outline dropped, in silence."""
    path = tmp_path / "masks.json"
    path.write_text(json.dumps([{"id": 5, "segmentation": [[2, 2, 5, 2, 5, 5, 2, 5]], **change}]))
    with pytest.raises(FileFormatError, match=error):
        coco_masks(path, (10, 10))


def test_a_frames_coco_image_of_another_size_is_refused(tmp_path):
    """Polygons drawn for a 320x240 image on the frame's 640x480 one were misplaced, unsaid."""
    path = tmp_path / "masks.json"
    coco = {"images": [{"id": 1, "width": 32, "height": 24}], "annotations": [
        {"id": 1, "image_id": 1, "segmentation": [[2, 2, 5, 2, 5, 5, 2, 5]]}]}  # fmt: skip
    path.write_text(json.dumps(coco))
    with pytest.raises(FileFormatError, match=r"masks\.json: its image is 32x24 but the frame's is 16x12"):
        coco_masks(path, (12, 16))
    assert coco_masks(path, (24, 32))[3, 3] == 1


@pytest.mark.parametrize(
    "ids, message",
    [((7, 7), "annotations 1 and 2 would both be fruit 7"), ((None, 1), "annotations 1 and 2 would both be fruit 1"),
     ((2, None), "annotations 1 and 2 would both be fruit 2")],
)  # fmt: skip
def test_two_annotations_that_would_be_one_fruit_are_refused_not_merged(tmp_path, ids, message):
    anns = [{"segmentation": [[x, 0, x + 3, 0, x + 3, 3, x, 3]]} for x in (0, 5)]
    for ann, ident in zip(anns, ids, strict=True):
        if ident is not None:
            ann["id"] = ident
    (tmp_path / "a.json").write_text(json.dumps({"annotations": anns}))
    with pytest.raises(FileFormatError, match=re.escape(message) + r" \(an id given twice, or .*its own id$"):
        coco_masks(tmp_path / "a.json", (10, 10))  # before: both drawn with one label, read as one fruit


@pytest.mark.parametrize(
    "data, message",
    [
        ({"annotations": {"a": 1}}, "expected a COCO 'annotations' list"),
        ({"annotations": [{"id": 1}]}, "annotation 1 has no valid segmentation"),
        ({"annotations": [{"segmentation": {"size": [10, 10], "counts": [5]}}]}, "annotation 1 has no valid"),
        (
            {"annotations": [{"segmentation": {"size": [4, 4], "counts": [16]}}]},
            r"annotation 1: RLE size \[4, 4\] is not the image's \[10, 10\]",
        ),
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


@pytest.mark.parametrize(
    "counts, message",
    [
        ([36, -1], r"whole numbers 0-35, got 36"),  # adds up to 35: a negative run never cancels a longer one
        ([-1, 36], r"whole numbers 0-35, got -1"),
        ([1.5, 33.5], r"whole numbers 0-35, got 1\.5"),  # never cut to 1
        ([True, 34], r"whole numbers 0-35, got True"),
        ([int("9" * 400)], r"got 999999999999\.\.\. \(400 digits\)"),
        (None, r"a list of run lengths or a compressed string, got NoneType"),
        ({"a": 1}, r"got dict"),
        ("\u00e9", r"only ASCII"),
    ],
)  # fmt: skip
def test_rle_counts_that_are_no_run_lengths_are_refused_by_what_they_are(counts, message):
    with pytest.raises(ValueError, match=message):
        rle_decode({"size": [7, 5], "counts": counts})
    assert rle_decode({"size": [7, 5], "counts": np.array([1, 34])}).sum() == 34  # the API's arrays too


def test_a_broken_rle_in_a_masks_file_names_the_file_and_annotation(tmp_path):
    (tmp_path / "m.json").write_text(json.dumps({"annotations": [{"segmentation": {"size": [7, 5], "counts": None}}]}))
    with pytest.raises(FileFormatError, match=r"m\.json: annotation 1 has no valid segmentation \(RLE counts must be"):
        read_masks(tmp_path / "m.json", (7, 5))


def test_other_extensions_are_refused(tmp_path):
    with pytest.raises(FileFormatError, match=r"m\.npy: masks must be a label \.png or a COCO \.json"):
        read_masks(tmp_path / "m.npy", (10, 10))


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


def test_images_that_share_a_file_name_are_told_apart_by_their_folders(tmp_path):
    square = {"id": 1, "image_id": 1, "category_id": 1, "segmentation": [[3, 5, 11, 5, 11, 9, 3, 9]]}
    coco = {"images": [{"id": 1, "file_name": "row1/0001.png"}, {"id": 2, "file_name": "row2\\0001.png"}],
            "annotations": [square]}  # fmt: skip
    c = read_coco(_write(tmp_path, coco))
    assert c.instances("row1/0001.png", (20, 30)).shape == (1, 20, 30)
    assert c.instances("/data/row1/0001.png", (20, 30)).shape == (1, 20, 30)
    assert c.instances("/data/row2/0001.png", (20, 30)).shape == (0, 20, 30)  # before: row1's fruit
    with pytest.raises(FileFormatError, match=r"2 images are named '0001.png' \('row1/0001.png', 'row2\\\\0001.png'\); "
                       r"which one '0001.png' is cannot be told"):  # fmt: skip
        c.instances("0001.png", (20, 30))  # before: row1/0001.png's, whichever was meant
    with pytest.raises(FileFormatError, match=r"which one '/data/row3/0001.png' is cannot be told"):
        c.instances("/data/row3/0001.png", (20, 30))


def test_sizes_in_the_file_are_checked_against_the_image(tmp_path):
    c = read_coco(_write(tmp_path, _coco([[0, 0, 5, 0, 5, 5]])))
    with pytest.raises(FileFormatError, match=r"30x20 in the file but 40x20 on disk$"):
        c.instances("a.jpg", (20, 40))
    # a phone photo annotated on its stored pixels, read as displayed (its EXIF orientation applied): said so
    said = r"\(turned a quarter: images are read as displayed, an EXIF orientation applied; annotate each image as it"
    with pytest.raises(FileFormatError, match=r"30x20 in the file but 20x30 on disk " + said):
        c.instances("a.jpg", (30, 20))
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


def _coco_file(tmp_path, images, annotations, name="c.json"):
    path = tmp_path / name
    path.write_text(json.dumps({"images": images, "annotations": annotations,
                                "categories": [{"id": 1, "name": "strawberry"}]}))  # fmt: skip
    return path


def test_two_images_sharing_an_id_or_a_name_are_refused(tmp_path):
    from symfruit.io.masks import read_coco

    same_id = [{"id": 3, "file_name": "a.png"}, {"id": 3, "file_name": "b.png"}]
    with pytest.raises(FileFormatError, match=r"'a\.png' and 'b\.png' share the image id 3"):
        read_coco(_coco_file(tmp_path, same_id, []))
    same_name = [{"id": 1, "file_name": "a.png"}, {"id": 2, "file_name": "a.png"}]
    with pytest.raises(FileFormatError, match=r"two 'images' entries are named 'a\.png'"):
        read_coco(_coco_file(tmp_path, same_name, []))


def test_annotations_that_are_not_objects_are_refused_not_an_empty_frame(tmp_path):
    from symfruit.io.masks import coco_masks

    path = _coco_file(tmp_path, [{"id": 1, "file_name": "a.png"}], [[1, 2, 3], "x"])
    with pytest.raises(FileFormatError, match="annotation 1 is a list, not an object"):
        coco_masks(path, (10, 10))
    bad_images = tmp_path / "d.json"
    bad_images.write_text(json.dumps({"images": ["a.png"], "annotations": []}))
    with pytest.raises(FileFormatError, match="'images' must be a list of objects"):
        coco_masks(bad_images, (10, 10))


def test_crowd_regions_are_no_instances_and_a_missing_category_is_named(tmp_path):
    from symfruit import InputError
    from symfruit.io.masks import coco_masks, read_coco

    box = [[1, 1, 6, 1, 6, 6, 1, 6]]
    anns = [{"id": 1, "image_id": 1, "category_id": 1, "segmentation": box},
            {"id": 2, "image_id": 1, "category_id": 1, "iscrowd": 1, "segmentation": [[8, 8, 9, 8, 9, 9]]}]  # fmt: skip
    path = _coco_file(tmp_path, [{"id": 1, "file_name": "a.png", "height": 10, "width": 10}], anns)
    coco = read_coco(path)
    assert coco.instances("a.png", (10, 10)).shape == (1, 10, 10)
    crowd, n = coco.crowd("a.png", (10, 10))
    assert n == 1 and crowd[8, 8] and not crowd[2, 2]
    assert set(np.unique(coco_masks(path, (10, 10)))) == {0, 1}
    with pytest.raises(InputError, match=r"no annotation has category 2; the annotations have 1 \(strawberry\)"):
        coco.check_category(2)
    coco.check_category(None)
    coco.check_category(1)


def test_a_label_png_must_carry_the_orientation_of_the_colour_image_it_is_for(tmp_path):
    labels = np.zeros((12, 16), np.uint8)
    labels[2:5, 3:9] = 1
    exif = Image.Exif()
    exif[0x0112] = 3  # half a turn: the size agrees
    Image.fromarray(labels).save(tmp_path / "m.png", exif=exif)
    with pytest.raises(FileFormatError, match=r"c\.jpg: its EXIF orientation 1 .* but m\.png has 3 \(turned half"):
        read_masks(tmp_path / "m.png", (12, 16), color=(tmp_path / "c.jpg", 1))
    # both turned alike: read as displayed; no colour given: read as displayed, unchecked
    assert np.array_equal(read_masks(tmp_path / "m.png", (12, 16), color=("c.jpg", 3)), labels[::-1, ::-1])
    assert np.array_equal(read_masks(tmp_path / "m.png", (12, 16)), labels[::-1, ::-1])


def test_a_category_id_that_is_no_id_is_refused_by_annotation(tmp_path):
    data = {"images": [{"id": 1, "file_name": "a.png"}], "annotations": [
        {"id": 1, "image_id": 1, "category_id": 1, "segmentation": []},
        {"id": 2, "image_id": 1, "category_id": [1], "segmentation": []}]}  # fmt: skip
    (tmp_path / "c.json").write_text(json.dumps(data))
    with pytest.raises(FileFormatError, match=r"c\.json: annotation 2 has category_id \[1\]; a category id is a whole"):
        read_coco(tmp_path / "c.json")  # before: "TypeError: unhashable type: 'list'" out of check_category


@pytest.mark.parametrize(
    "images, image_id, message",
    [
        ([{"file_name": "a.png"}], 1, r"c\.json: the 'images' entry 'a\.png' has no id"),
        ([{"id": 1, "file_name": "a.png"}], 2, r"c\.json: annotation 1 is for image id 2, which no 'images' entry has"),
        ([{"id": 1, "file_name": "a.png"}], None, r"annotation 1 is for image id None"),
    ],
)  # fmt: skip
def test_annotations_that_no_image_would_claim_are_refused_not_dropped(tmp_path, images, image_id, message):
    ann = {"id": 1, "category_id": 1, "segmentation": [], **({} if image_id is None else {"image_id": image_id})}
    (tmp_path / "c.json").write_text(json.dumps({"images": images, "annotations": [ann]}))
    with pytest.raises(FileFormatError, match=message):
        read_coco(tmp_path / "c.json")  # before: read, and the image scored as holding no fruit


@pytest.mark.parametrize("crowd", ["0", "no", 2])
def test_an_iscrowd_that_is_not_0_or_1_is_refused_not_read_as_a_crowd(tmp_path, crowd):
    ann = {"id": 1, "image_id": 1, "category_id": 1, "segmentation": [], "iscrowd": crowd}
    (tmp_path / "c.json").write_text(json.dumps({"images": [{"id": 1, "file_name": "a.png"}], "annotations": [ann]}))
    with pytest.raises(
        FileFormatError, match=rf"c\.json: annotation 1 has iscrowd {re.escape(repr(crowd))}; it is 0 or 1"
    ):
        read_coco(tmp_path / "c.json")  # before: "0" (text) was truthy, the fruit ignored as a crowd region
    with pytest.raises(FileFormatError, match=r"c\.json: annotation 1 has iscrowd"):
        read_masks(tmp_path / "c.json", (4, 4))  # a frame's masks.json alike


def test_a_polygon_of_an_odd_number_of_coordinates_is_refused_naming_the_annotation(tmp_path):
    odd = [[3, 5, 11, 5, 11, 9, 3, 9, 3]]  # before: the last coordinate dropped, the rest drawn
    c = read_coco(_write(tmp_path, _coco(odd)))
    message = r"c\.json: annotation 5 has no valid segmentation \(a polygon has 9 coordinates, an odd number"
    with pytest.raises(FileFormatError, match=message):
        c.instances("a.jpg", (20, 30))
    with pytest.raises(FileFormatError, match=r"m\.json: annotation 1 has no valid segmentation \(a polygon has 9"):
        read_masks(_write(tmp_path, {"annotations": [{"segmentation": odd}]}, "m.json"), (20, 30))  # a frame's masks


@pytest.mark.parametrize("text", ["5", True])
def test_polygon_coordinates_that_are_text_or_booleans_are_refused_not_read_as_numbers(tmp_path, text):
    poly = [[3, 5, 11, 5, 11, 9, 3, 9]]
    poly[0][2] = text
    path = _write(tmp_path, {"annotations": [{"segmentation": poly}]}, "m.json")
    with pytest.raises(FileFormatError, match=r"m\.json: annotation 1 has no valid segmentation \(polygon "
                       r"coordinates must be numbers, got (True|'5')\)"):  # fmt: skip
        read_masks(path, (20, 30))  # before: '5' read as 5 and true as 1


@pytest.mark.parametrize(
    ("rle", "message"),
    [
        (None, r"an RLE is \{'size': \[h, w\], 'counts': \.\.\.\}, got None"),  # before: TypeError (subscript)
        ({"size": [7, 5]}, "an RLE is"),  # before: KeyError 'counts'
        ({"size": [7, 5, 1], "counts": [35]}, "an RLE is"),  # before: ValueError 'too many values to unpack'
        ({"size": [7.5, 5], "counts": [35]}, r"RLE size must be two whole numbers \[h, w\], got \[7.5, 5\]"),  # was 7
        ({"size": ["7", 5], "counts": [35]}, "RLE size must be two whole numbers"),  # before: read as 7
        ({"size": [True, 35], "counts": [35]}, "RLE size must be two whole numbers"),  # before: read as 1
    ],
)
def test_an_rle_that_is_no_mapping_of_whole_size_and_counts_is_refused_by_name(rle, message):
    with pytest.raises(InputError, match=message):
        rle_decode(rle)
    assert rle_decode({"size": (np.int64(7), 5), "counts": [35]}).shape == (7, 5)
