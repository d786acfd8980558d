"""docs/shift61.py and ``extract.mask_edge_px`` on the real Azure Kinect sphere frames (stop 61, docs/shift61.md):
masks moved 5 px up are cut by the colour trim at the top (the cupboards, right) and at the bottom (the spheres' own
shaded limb, wrong) and stay short; moved back onto the colour's edges first, every sphere is within the issue's
6 mm bar and its box where the unperturbed mask's is."""

import numpy as np
import pytest

from symfruit.core.edges import mask_shift
from symfruit.core.frame import Frame
from symfruit.detect import detect
from symfruit.io.frames import read_frame
from symfruit.settings import from_dict

from ..conftest import docs_script

#: one worker runs the real frames' detections (pytest-xdist --dist loadgroup), beside test_spheres' own
pytestmark = pytest.mark.xdist_group("real-spheres")


@pytest.fixture(scope="module")
def rp():
    return docs_script("realpert55")


def test_the_quadrants_split_an_outline_by_its_side():
    quadrants = docs_script("shift61")._quadrants
    rows, cols = np.array([0.0, 10.0, 5.0, 5.0]), np.array([5.0, 5.0, 0.0, 10.0])
    q = quadrants(rows, cols, 5.0, 5.0)
    assert [int(np.flatnonzero(q[k])[0]) for k in ("top", "bottom", "left", "right")] == [0, 1, 2, 3]


@pytest.mark.parametrize(("name", "shift"), [("none", (0, 0)), ("shift-5y", (0, 5)), ("shift+5y", (0, -5)),
                                             ("shift+10x", (-10, 0)), ("dilate5", (0, 0))])  # fmt: skip
def test_the_real_masks_are_moved_back_by_their_shift_and_grown_ones_stay(rp, name, shift):
    color, _, masks, _ = rp.PERTURBATIONS[name](read_frame(rp.FRAMES / "lab-spheres-0"))
    assert mask_shift(color, masks, max_px=10) == shift


def test_masks_moved_up_are_short_without_mask_edge_px_and_whole_moved_back_by_default(rp):
    frame = read_frame(rp.FRAMES / "lab-spheres-0")
    color, depth, masks, cam = rp.PERTURBATIONS["shift-5y"](frame)
    perturbed = Frame(name="shift-5y", color=color, depth=depth, camera=cam, masks=masks)
    focal = float(np.sqrt(cam.fx * cam.fy))
    base = {d.id: d.result.box for d in detect(frame, method="evidence").detections}
    off = from_dict({"extract": {"mask_edge_px": 0}})
    short = {d.id: d.result.box.size[1] * 1000.0 for d in detect(perturbed, method="evidence", settings=off).detections}
    assert short[2] < 120.0  # the 126 mm sphere: its top trimmed, its bottom 5 px short and trimmed again
    found = detect(perturbed, method="evidence")  # mask_edge_px 10 by default (stop 62, docs/edge62.md)
    assert len(found.detections) == 4
    for d in found.detections:
        size = d.result.box.size * 1000.0
        diameter = 2000.0 * np.sqrt(float((frame.masks == d.id).sum()) / np.pi) * d.result.box.centre[2] / focal
        assert np.ptp(size) <= 6.0 and abs(size[2] - diameter) <= 6.0, (d.id, size, diameter)
        assert np.abs(d.result.box.centre - base[d.id].centre).max() < 0.002  # where the unperturbed box is
