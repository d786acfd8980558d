"""symfruit.core.limits: every documented bound in one place, the checks, and README's table matching them."""

import re
from pathlib import Path

import numpy as np
import pytest

from symfruit import FileFormatError, InputError
from symfruit.core import limits
from symfruit.core.limits import check_image_size, depth_metres, instance_labels, shown
from symfruit.synthetic import shapes

README = Path(__file__).resolve().parents[2] / "README.md"


def _limits_table() -> dict[str, str]:
    """README's limits table: first cell -> bound cell."""
    text = README.read_text(encoding="utf-8")
    start = text.index("**Limits.**")
    rows = {}
    for line in text[start:].splitlines()[1:]:
        if line.startswith("| ") and not line.startswith("|---") and not line.startswith("| what"):
            cells = [c.strip() for c in line.strip("|").split("|")]
            rows[cells[0]] = cells[1]
        elif rows and not line.startswith("|"):
            break
    return rows


def _numbers(cell: str) -> list[float]:
    """The numbers a cell states, with units: '40 megapixels' is 40e6, '256 MB' is 256 MiB, '1e6' is 1e6."""
    out = []
    for value, unit in re.findall(
        r"(\d[\d,.]*(?:e\d+)?)\s*(megapixels|million|MB|kB|pixels|instances|faces|points)?", cell
    ):
        v = float(value.replace(",", ""))
        out.append(v * {"megapixels": 1e6, "million": 1e6, "MB": 1 << 20, "kB": 1 << 10}.get(unit, 1))
    return out


def test_readme_limits_are_the_enforced_constants():
    table = _limits_table()
    image = _numbers(next(v for k, v in table.items() if k.startswith("an image")))
    assert image[:4] == [
        limits.MAX_IMAGE_PIXELS,
        limits.MAX_IMAGE_SIDE,
        limits.MAX_FOCAL_PX,
        limits.MAX_DISTORTION_COEFFS,
    ]
    assert "16 lens distortion coefficients" in next(v for k, v in table.items() if k.startswith("an image"))
    window = _numbers(next(v for k, v in table.items() if "window" in k))
    assert window == [limits.MAX_WINDOW_PIXELS]
    cloud = _numbers(next(v for k, v in table.items() if k.startswith("a cloud file")))
    assert cloud[:2] == [limits.MAX_CLOUD_POINTS, limits.MAX_TEXT_CLOUD_BYTES]
    mesh = _numbers(next(v for k, v in table.items() if k.startswith("a mesh")))
    assert mesh[:3] == [limits.MAX_CLOUD_POINTS, limits.MAX_FACES, limits.MAX_OBJ_BYTES]
    assert mesh[3:] == [shapes.MIN_SCAN_M * 1000, shapes.MAX_SCAN_M]  # "1 mm-2 m across"
    files = _numbers(next(v for k, v in table.items() if k.startswith("settings")))
    assert files[:3] == [limits.MAX_SETTINGS_BYTES, limits.MAX_TRUTH_BYTES, limits.MAX_COCO_BYTES]
    assert limits.MAX_BAG_METADATA_BYTES == limits.MAX_TRUTH_BYTES  # stated beside the truth file's
    mcap = _numbers(next(v for k, v in table.items() if k.startswith("a ROS 2 bag's MCAP")))
    assert mcap[0] == limits.MAX_BAG_CHUNK_BYTES  # stop 48 (robust48)
    tables = _numbers(next(v for k, v in table.items() if k.startswith("a run's fruit table")))
    assert tables == [limits.MAX_TABLE_ROWS, limits.MAX_TABLE_BYTES]
    masks = _numbers(next(v for k, v in table.items() if k.startswith("fruit per")))
    assert (
        masks[0] == limits.MAX_INSTANCES
        and limits.MAX_LABEL_ID == 2**31 - 1
        and "32 bits" in table["fruit per image (masks)"]
    )


def test_the_modules_use_the_one_set_of_bounds():
    from symfruit import detect
    from symfruit.core import camera, raster
    from symfruit.io import bags, clouds, frames, images, intrinsics, masks, meshes

    assert camera.MAX_IMAGE_SIDE is limits.MAX_IMAGE_SIDE and images.MAX_IMAGE_PIXELS == limits.MAX_IMAGE_PIXELS
    assert bags.MAX_MESSAGE_PIXELS == frames.MAX_DEPTH_ELEMENTS == limits.MAX_IMAGE_PIXELS
    assert raster.MAX_WINDOW_PIXELS == limits.MAX_WINDOW_PIXELS and clouds.MAX_CLOUD_POINTS == limits.MAX_CLOUD_POINTS
    assert meshes.MAX_FACES == limits.MAX_FACES and masks.MAX_COCO_BYTES == limits.MAX_COCO_BYTES
    assert meshes.MAX_CLOUD_POINTS == limits.MAX_CLOUD_POINTS
    assert detect.MAX_FRUIT_PER_FRAME == masks.MAX_INSTANCES_PER_IMAGE == limits.MAX_INSTANCES
    assert intrinsics.MAX_INTRINSICS_BYTES == limits.MAX_SETTINGS_BYTES
    assert intrinsics.MAX_DISTORTION_COEFFS is limits.MAX_DISTORTION_COEFFS
    from symfruit.segment import colour

    assert colour.MAX_PIECES is limits.MAX_PIECES == limits.MAX_INSTANCES  # README: "at most 1000 candidate pieces"
    assert bags.MAX_BAG_METADATA_BYTES is limits.MAX_BAG_METADATA_BYTES
    assert bags.MAX_BAG_CHUNK_BYTES is limits.MAX_BAG_CHUNK_BYTES


@pytest.mark.parametrize(("w", "h", "message"), [
    (30000, 20, "at most 16384 pixels a side"), (20, 30000, "a side"), (8000, 6000, "at most 40,000,000 pixels"),
    (0, 10, "must not be empty"), ("x", 3, "not whole numbers"),
])  # fmt: skip
def test_image_sizes_beyond_the_bounds_are_refused(w, h, message):
    with pytest.raises(InputError, match=message):
        check_image_size(w, h, "img")
    assert check_image_size(16384, 2000, "img") == (16384, 2000)


def test_label_ids_beyond_32_bits_are_refused_not_truncated():
    labels = np.zeros((4, 4), np.int64)
    labels[0, 0], labels[3, 3] = 1, 2**32 + 1  # truncated to int32 this would be fruit 1 again
    with pytest.raises(InputError, match="beyond 32 bits"):
        instance_labels(labels, "masks")
    with pytest.raises(InputError, match="beyond 32 bits"):
        instance_labels(labels.astype(np.uint64) + np.uint64(2**63), "masks")
    labels[3, 3] = 2**31 - 1  # the largest id is kept as it is
    assert instance_labels(labels, "m").dtype == np.int32 and instance_labels(labels, "m")[3, 3] == 2**31 - 1


def test_more_than_1000_instances_and_bad_labels_are_refused():
    many = (np.arange(40 * 40).reshape(40, 40) % 1500 + 1).astype(np.int32)
    with pytest.raises(FileFormatError, match="1500 instances; at most 1000"):
        instance_labels(many, "x.png", error=FileFormatError)
    sparse = np.zeros((8, 8), np.int64)
    sparse[0, :3] = [5, 10**9, 2**30]  # few fruit with large ids pass
    assert instance_labels(sparse, "m").max() == 2**30
    for bad, message in ((np.full((2, 2), -1), "negative"), (np.ones((2, 2)), "whole numbers"),
                         (np.ones(4, int), r"\(h, w\) image")):  # fmt: skip
        with pytest.raises(InputError, match=message):
            instance_labels(bad, "m")
    assert instance_labels(np.eye(3, dtype=bool), "m").tolist() == np.eye(3, dtype=int).tolist()


def test_depth_in_raw_units_is_refused_with_a_clear_message():
    mm = np.full((48, 64), 450, np.uint16)
    with pytest.raises(InputError, match="uint16; depth must be float metres"):
        depth_metres(mm, "frame")
    with pytest.raises(InputError, match="look like millimetres"):
        depth_metres(mm.astype(np.float32), "frame")
    ok = np.where(np.arange(64) % 2, 0.45, np.nan).astype(np.float32)[None].repeat(48, 0)
    assert depth_metres(ok, "frame") is ok and depth_metres(np.zeros((3, 3)), "f").shape == (3, 3)


def test_a_long_bad_value_is_shown_shortened_in_messages():
    assert shown(640) == "640" and shown(np.int64(7)) == "7" and shown(-(10**50)) == "-10000000000... (51 digits)"
    assert shown("x" * 50) == "'xxxxxxxxxxxxxxxxxxx... (52 characters)" and shown(2.5) == "2.5"
    assert shown(10**5000) == "a whole number of about 5001 digits"  # repr() itself refuses beyond 4300 digits
    for width, height, message in (
        (10**400, 480, r"^w: image is 10{11}\.\.\. \(401 digits\)x480 pixels; at most 16384 pixels a side are read$"),
        (-(10**400), 480, r"^w: image is -10{10}\.\.\. \(401 digits\)x480 pixels; it must not be empty$"),
        ("x" * 400, 480, r"^w: image size 'x{19}\.\.\. \(402 characters\)x480 is not whole numbers"),
    ):  # before: every digit printed
        with pytest.raises(InputError, match=message):
            check_image_size(width, height, "w")


def test_a_masked_arrays_masked_pixels_are_no_depth_and_background_not_the_values_under_the_mask():
    from symfruit.core.limits import depth_metres, instance_labels, unmasked

    depth = np.ma.masked_array(np.full((4, 5), 0.5, np.float32), mask=np.zeros((4, 5), bool))
    depth.mask[1, 2] = True
    got = depth_metres(depth, "frame f")
    assert type(got) is np.ndarray and got[1, 2] == 0 and (got > 0).sum() == 19  # before: 0.5 m, as if measured
    labels = np.ma.masked_array(np.arange(20).reshape(4, 5) % 3, mask=np.arange(20).reshape(4, 5) % 3 == 2)
    got = instance_labels(labels, "frame f: masks")
    assert set(np.unique(got).tolist()) == {0, 1}  # before: label 2 read from under its mask
    assert unmasked(np.ma.masked_array([1, 2], mask=[False, True]), np.nan).tolist()[0] == 1.0
    assert np.isnan(unmasked(np.ma.masked_array([1, 2], mask=[False, True]), np.nan)[1])
    plain = np.ones(3)
    assert unmasked(plain, 0) is plain and unmasked(np.ma.masked_array(plain), 0).tolist() == [1.0, 1.0, 1.0]


def test_the_typical_depth_is_np_medians():
    """``typical_depth`` (``core.points.median`` of its sample since stop 53) against ``np.median`` of the same strided
    sample's valid pixels: float32 and float64 images of 1x1 to 1080x1920 with NaN, infinite, 0 and negative pixels
    among the depths, odd and even counts: the same value, bit for bit; None where none is valid."""
    from symfruit.core.limits import typical_depth

    rng = np.random.default_rng(53)
    for shape in [(1, 1), (2, 3), (7, 9), (480, 640), (480, 641), (1080, 1920)]:
        for dtype in (np.float32, np.float64):
            z = (0.2 + 3 * rng.random(shape)).astype(dtype)
            z[rng.random(shape) < 0.3] = rng.choice([0.0, -1.0, np.nan, np.inf, -np.inf])
            stride = max(1, int(np.sqrt(z.size / 8_000)))
            sample = z[::stride, ::stride].ravel()
            with np.errstate(invalid="ignore"):
                valid = sample[np.isfinite(sample) & (sample > 0)]
            got = typical_depth(z)
            assert (got is None) if len(valid) == 0 else got == float(np.median(valid))
    assert typical_depth(np.full((4, 4), np.nan)) is None
