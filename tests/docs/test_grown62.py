"""docs/grown62.py (stop 62, docs/grown62.md): the real frame 0 with its masks grown 5 px, stage by stage."""

import re

import numpy as np
import pytest

from ..conftest import docs_script

#: one worker runs the real frames' detections (pytest-xdist --dist loadgroup), beside test_realpert55's own
pytestmark = pytest.mark.xdist_group("real-spheres")


def test_grown_5_px_the_colour_cuts_the_200_mm_spheres_bottom_deeper_and_the_cap_gives_that_back(tmp_path):
    """Drawn 5 px wide all round. The colour cuts the 200 mm sphere's mask 5 px deep on three sides and 12 px at its
    shaded bottom; what lies deeper than the 5 px comes back on its cap (the base left the bottom 7 px short, the box's
    centre 6.8 mm high). The white 66 mm sphere on the white board: no stage cuts anything, and its box grows with its
    front face where it was, its centre moving back by half its depth side's growth (the stop's diagnosis)."""
    rp, g = docs_script("realpert55"), docs_script("grown62")
    none, grown = rp.write_perturbed(tmp_path, "none"), rp.write_perturbed(tmp_path, "dilate5")
    reference = g.stages(none / "lab-spheres-0")
    got = g.stages(grown / "lab-spheres-0")
    text = g.report(reference, got)
    assert "out L+5 R+5 T+5 B+5" in text.splitlines()[1]  # sphere 1 as drawn
    colour = [line for line in text.splitlines() if line.strip().startswith("colour")]
    assert re.search(r"B-7 ", colour[0])  # the colour's cut of sphere 1: 7 px into its bottom
    s1 = got[1].masks["moved+caps"]
    rows = np.flatnonzero(s1.any(axis=1))
    bottom = np.flatnonzero(reference[1].masks["drawn"].any(axis=1))[-1]
    assert abs(int(rows[-1]) - int(bottom)) <= 1
    assert np.linalg.norm(got[1].box.centre - reference[1].box.centre) < 0.002
    s3 = got[3]
    assert all(m.sum() == s3.masks["drawn"].sum() for m in s3.masks.values())
    front = s3.box.centre[2] - s3.box.size[2] / 2 - reference[3].box.centre[2] + reference[3].box.size[2] / 2
    growth = s3.box.size[2] - reference[3].box.size[2]
    assert abs(front) < 0.001 and growth > 0.01
    assert s3.box.centre[2] - reference[3].box.centre[2] == pytest.approx(growth / 2, abs=0.001)
