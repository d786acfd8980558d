"""One RGB-D frame: the pipeline's unit of work checks that its images, intrinsics and masks agree."""

import numpy as np
import pytest

from symfruit import Box, Camera, InputError
from symfruit.core.frame import MAX_STAMP_NS, Frame

from ..conftest import SMALL_CAM, disc_frame

COLOR, DEPTH = disc_frame([(80, 60)])


def test_a_consistent_frame_keeps_what_it_is_given():
    masks = np.zeros((120, 160), np.int32)
    truth = [(1, Box(np.zeros(3), np.ones(3)))]
    frame = Frame("f", COLOR, DEPTH, SMALL_CAM, masks=masks, truth=truth, source="here", stamp=5)
    assert frame.color is COLOR and frame.depth is DEPTH and frame.masks is masks and frame.truth == truth
    assert (frame.source, frame.stamp, frame.extras) == ("here", 5, {})
    stamped = Frame("f", COLOR, DEPTH, SMALL_CAM, stamp=np.int64(MAX_STAMP_NS - 1))  # the last time there is
    assert type(stamped.stamp) is int and stamped.stamp == MAX_STAMP_NS - 1
    bare = Frame("g", COLOR, DEPTH, SMALL_CAM)
    assert bare.masks is None and bare.truth is None and bare.source == "" and bare.stamp is None


@pytest.mark.parametrize(
    "change, message",
    [
        ({"color": COLOR.astype(np.float32)}, r"frame f: colour must be \(h, w, 3\) uint8 RGB, got float32"),
        ({"color": COLOR[:, :, 0]}, r"colour must be \(h, w, 3\) uint8 RGB, got uint8 \(120, 160\)"),
        ({"color": np.dstack([COLOR, COLOR[:, :, :1]])}, r"got uint8 \(120, 160, 4\)"),
        ({"depth": DEPTH[None]}, r"depth must be a 2-D image, got shape \(1, 120, 160\)"),
        ({"color": COLOR[:100]}, "colour is 160x100 but depth is 160x120; depth must be aligned"),
        ({"depth": DEPTH[:, :150], "color": COLOR[:, :150]}, "intrinsics are for 160x120 but the images are 150x120"),
        ({"masks": np.zeros((120, 150), np.int32)}, "masks are 150x120, the image 160x120"),
    ],
)
def test_inconsistent_frames_are_refused_by_name(change, message):
    args = {"name": "f", "color": COLOR, "depth": DEPTH, "camera": SMALL_CAM, **change}
    with pytest.raises(InputError, match=message):
        Frame(**args)


@pytest.mark.parametrize(
    "change, message",
    [
        ({"camera": SMALL_CAM.to_dict()}, "camera must be a symfruit Camera .* got dict"),
        ({"camera": "camera.json"}, "got str"),
        ({"depth": np.rint(DEPTH * 1000).astype(np.uint16)}, "depth is uint16; depth must be float metres"),
        ({"depth": DEPTH * 1000}, "look like millimetres"),
        ({"masks": np.where(DEPTH > 0, 2**40, 0)}, "beyond 32 bits"),
        ({"masks": np.zeros((120, 160))}, "whole numbers"),
        ({"stamp": -5}, r"stamp -5 ns is not a time \(0 to 2\*\*33 s after 1970\)"),
        ({"stamp": MAX_STAMP_NS}, "is not a time"),
        ({"stamp": 1.5e9}, "stamp must be whole nanoseconds since the epoch, got float"),
        ({"stamp": True}, "got bool"),
    ],
)
def test_api_inputs_of_the_wrong_kind_or_units_are_refused(change, message):
    args = {"name": "f", "color": COLOR, "depth": DEPTH, "camera": SMALL_CAM, **change}
    with pytest.raises(InputError, match=message):
        Frame(**args)


@pytest.mark.parametrize("name", [None, 5, b"frame"])
def test_a_frame_name_that_is_no_text_is_refused(name):
    cam = Camera(fx=50, fy=50, cx=4, cy=3, width=8, height=6)
    with pytest.raises(InputError, match="a frame's name must be text"):  # before: taken, then the run's table
        Frame(name, np.zeros((6, 8, 3), np.uint8), np.zeros((6, 8), np.float32), cam)  # refused the frame's record


@pytest.mark.parametrize(
    "change, message",
    [
        ({"frame_id": 5}, "frame_id must be text .* got int"),  # before: written as 5 into detections.json
        ({"truth": [(1, "box")]}, r"truth must be a list of \(id, Box\) pairs"),  # before: AttributeError when scored
        ({"truth": "x"}, "truth must be a list"),
        ({"truth": [(True, Box(np.zeros(3), np.ones(3)))]}, "truth must be a list"),
        ({"truth": [(1.5, Box(np.zeros(3), np.ones(3)))]}, "truth must be a list"),
        ({"visible": {1: 5.0}}, r"visible must map fruit ids to shares in \[0, 1\]"),  # before: a share of 500 %
        ({"visible": {1: float("nan")}}, "visible must map"),
        ({"visible": "x"}, "visible must map"),
        ({"extras": None}, "extras must be a dict, got NoneType"),
    ],
)
def test_truth_visible_shares_frame_id_and_extras_of_another_kind_are_refused(change, message):
    args = {"name": "f", "color": COLOR, "depth": DEPTH, "camera": SMALL_CAM, **change}
    with pytest.raises(InputError, match=message):
        Frame(**args)
    kept = Frame("f", COLOR, DEPTH, SMALL_CAM, truth=[(np.int64(2), Box(np.zeros(3), np.ones(3)))],
                 visible={2: 0.5, np.int64(3): 1}, frame_id="camera_color_optical_frame")  # fmt: skip
    assert kept.visible == {2: 0.5, 3: 1} and kept.frame_id == "camera_color_optical_frame"
