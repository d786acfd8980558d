"""docs/strip58.py: evidence's depth fusion laid out per fruit (stop 58, docs/strip58.md), on the real Azure Kinect
frame under a strip 5 cm in front that cuts every mask in two (docs/realpert55.py's ``leafstrip5-cut``)."""

import numpy as np
import pytest

import symfruit.detect as detect_module
import symfruit.extract as extract_module
import symfruit.methods.evidence as evidence
from symfruit.io.frames import read_frame

from ..conftest import docs_script

#: one worker runs the real frames' detections (pytest-xdist --dist loadgroup), beside test_realpert55's
pytestmark = pytest.mark.xdist_group("real-spheres")


def test_every_sphere_gets_a_row_of_its_mask_its_region_bridged_across_the_strip_and_its_box(tmp_path, capsys):
    rp, st = docs_script("realpert55"), docs_script("strip58")
    folder = rp.write_perturbed(tmp_path, "leafstrip5-cut") / "lab-spheres-0"
    before = (detect_module._trim_labels, extract_module.across_occluder, evidence.bridged, evidence.fuse_depth)
    st.report(folder, None)
    after = (detect_module._trim_labels, extract_module.across_occluder, evidence.bridged, evidence.fuse_depth)
    assert after == before  # the wrappers are taken out again
    rows = [[c.strip() for c in line.strip("|").split("|")] for line in capsys.readouterr().out.splitlines()]
    masks = read_frame(folder).masks
    assert [int(r[1]) for r in rows] == [1, 2, 3, 4]
    for r in rows:
        drawn, trimmed, region, bridged = (int(x) for x in r[2:6])
        assert drawn == int((masks == int(r[1])).sum()) and trimmed <= drawn
        assert bridged > region  # the strip parts every sphere's region; the pixels behind it join it
        assert len(r[8].split()) == 2 and r[8].split()[1] in ("contour", "moments")
        box = np.array([float(v) for v in r[-1].split("x")])
        assert box.shape == (3,) and (box > 30.0).all() and (box < 230.0).all()  # mm: 60-200 mm spheres
