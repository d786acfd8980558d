"""Table 3 on annotated frames: matching found fruit to the truth, scoring every method, the table."""

import json
import shutil

import numpy as np
import pytest

from symfruit import Box, Camera
from symfruit.detect import detect, frame_masks
from symfruit.evaluate.frames import (
    FrameScore,
    evaluate_frames,
    match,
    score_frame,
    summary_dict,
    table3,
    thin_lens,
)
from symfruit.io import read_frame
from symfruit.settings import Settings

from ..conftest import EXAMPLE_FRAME


def cube(x, y=0.0, z=0.3, size=0.02):
    centre = np.array([x, y, z])
    return Box(centre - size / 2, centre + size / 2)


def test_table3_on_frames(tmp_path):
    shutil.copytree(EXAMPLE_FRAME, tmp_path / "a")
    scores, totals, failed = evaluate_frames(tmp_path, methods=("raw", "paper"))
    assert totals["matched"] == 6 and totals["missed"] == 0 and totals["false"] == 0 and not failed
    raw = np.mean([s.centre_mm for s in scores if s.method == "raw"])
    paper = np.mean([s.centre_mm for s in scores if s.method == "paper"])
    assert paper < raw


def test_matching_minimises_the_total_distance_within_the_gate():
    truth = [cube(0.0), cube(0.02)]
    # Nearest first would pair found 0 with truth 1 (9 mm) and leave found 1 without a truth in the gate
    # (truth 0 is 45 mm away); the assignment pairs both.
    found = [cube(0.011), cube(0.045)]
    assert sorted(match(found, truth)) == [(0, 0), (1, 1)]
    assert match([cube(0.1)], truth) == []  # 80 mm from the nearest: no match
    assert match([cube(0.1)], truth, gate=0.09) == [(0, 1)]
    assert match([None, cube(0.001)], truth) == [(1, 0)]
    twins = match([cube(0.02)] * 2, truth)  # one truth each, never one truth twice
    assert sorted(f for f, _ in twins) == [0, 1] and sorted(t for _, t in twins) == [0, 1]
    assert match([], truth) == [] and match(found, []) == []


def test_frames_without_truth_or_unreadable_are_reported(tmp_path):
    shutil.copytree(EXAMPLE_FRAME, tmp_path / "a")
    shutil.copytree(EXAMPLE_FRAME, tmp_path / "b")
    (tmp_path / "b" / "truth.json").unlink()
    shutil.copytree(EXAMPLE_FRAME, tmp_path / "c")
    (tmp_path / "c" / "depth.png").write_bytes(b"broken")
    scores, totals, failed = evaluate_frames(tmp_path, methods=("raw",))
    assert totals["frames"] == 1 and totals["truth"] == 6 and totals["found"] == 6 and len(scores) == 6
    assert failed["b"] == "no truth.json" and "depth.png" in failed["c"] and set(failed) == {"b", "c"}
    assert {s.frame for s in scores} == {"a"} and all(s.method == "raw" and 0 < s.iou < 1 for s in scores)
    data = summary_dict(scores, totals, failed)
    assert data["totals"] == totals and data["failed"] == failed and len(data["scores"]) == 6
    assert set(data["scores"][0]) == {
        "frame",
        "fruit",
        "truth",
        "method",
        "iou",
        "centre_mm",
        "n_points",
        "truncated",
        "depth_mm",
        "lateral_mm",
        "visible",
        "thin_depth_mm",
        "thin_lateral_mm",
    }
    # the example frame's truth records no visible share: null in summary.json (JSON has no NaN), no table of them
    assert all(row["visible"] is None for row in data["scores"])
    json.dumps(data, allow_nan=False)
    assert all(np.isnan(s.visible) for s in scores) and "how much of each fruit" not in table3(scores, totals, ["raw"])


def test_the_table_is_laid_out_like_the_papers(tmp_path):
    shutil.copytree(EXAMPLE_FRAME, tmp_path / "a")
    scores, totals, _ = evaluate_frames(tmp_path, methods=("raw", "sphere"))
    table = table3(scores, totals, ("raw", "sphere", "paper"))
    lines = table.splitlines()
    assert lines[0] == "# symfruit evaluation: annotated frames (cf. Ge et al. Table 3)"
    assert "1 frames, 6 true fruit, 6 found, 6 matched, 0 missed, 0 false." in lines
    raw = [s for s in scores if s.method == "raw"]
    iou = np.array([s.iou for s in raw])
    assert any(line.startswith(f"| raw | {iou.mean():.3f} | {np.median(iou):.3f} |") for line in lines)
    assert any(line.startswith("| sphere |") for line in lines) and not any("| paper |" in line for line in lines)
    assert "Ge et al. 2020, Table 3 (D435, mean): input points 0.47 / 8.9 mm, completed 0.61 / 5.7 mm." in lines


@pytest.mark.parametrize("gate", [0.0001])
def test_a_tight_gate_matches_nothing(tmp_path, gate):
    shutil.copytree(EXAMPLE_FRAME, tmp_path / "a")
    scores, totals, _ = evaluate_frames(tmp_path, methods=("raw",), gate=gate)
    assert scores == [] and totals["matched"] == 0 and totals["missed"] == 6 and totals["false"] == 6


def test_the_thin_lens_estimate_is_the_masks_larger_extent_at_the_median_depth():
    cam = Camera(fx=500.0, fy=400.0, cx=50.0, cy=50.0, width=100, height=100)
    mask = np.zeros((100, 100), bool)
    mask[40:60, 30:80] = True  # 50 px wide, 20 px tall
    points = np.array([[0.0, 0.0, 0.9], [0.0, 0.0, 1.0], [0.0, 0.0, 1.5]])
    assert thin_lens(mask, points, cam) == pytest.approx(50 / 500.0 * 1.0)
    mask[:] = False
    mask[10:90, 45:50] = True  # 80 px tall over fy 400 beats 5 px wide over fx 500
    assert thin_lens(mask, points, cam) == pytest.approx(80 / 400.0 * 1.0)
    assert np.isnan(thin_lens(np.zeros((100, 100), bool), points, cam))


def test_sizes_by_how_much_of_each_fruit_is_seen(tmp_path):
    shutil.copytree(EXAMPLE_FRAME, tmp_path / "a")
    truth = tmp_path / "a" / "truth.json"
    data = json.loads(truth.read_text())
    ripe = [f for f in data["fruits"] if f.get("ripe", True)]
    for f, seen in zip(ripe, [1.0, 0.95, 0.7, 0.5, 0.2, 0.9], strict=True):
        f["visible"] = seen
    truth.write_text(json.dumps(data))
    scores, totals, _ = evaluate_frames(tmp_path, methods=("raw", "sphere"))
    assert sorted({s.visible for s in scores}) == [0.2, 0.5, 0.7, 0.9, 0.95, 1.0]
    raw = [s for s in scores if s.method == "raw"]
    table = table3(scores, totals, ("raw", "sphere")).splitlines()
    head = table.index("| method | visible (>= 90 % seen) | partly hidden (60-90 %) | mostly hidden (< 60 %) |")

    def cell(group, depth, lateral):
        dz, dl = np.array([getattr(s, depth) for s in group]), np.array([getattr(s, lateral) for s in group])
        return f"{np.abs(dz).mean():.1f} ({dz.mean():+.1f}) / {np.abs(dl).mean():.1f} ({dl.mean():+.1f}) (n {len(dz)})"

    groups = [[s for s in raw if s.visible >= 0.9], [s for s in raw if 0.6 <= s.visible < 0.9],
              [s for s in raw if s.visible < 0.6]]  # fmt: skip
    assert [len(g) for g in groups] == [3, 1, 2]
    assert table[head + 2] == "| thin-lens (reference) | " + " | ".join(
        cell(g, "thin_depth_mm", "thin_lateral_mm") for g in groups) + " |"  # fmt: skip
    assert table[head + 3] == "| raw | " + " | ".join(cell(g, "depth_mm", "lateral_mm") for g in groups) + " |"
    assert table[head + 4].startswith("| sphere | ")
    # the thin-lens reference is the same for every method of a fruit, and near the truth on this frame
    by_fruit = {(s.frame, s.fruit): s.thin_lateral_mm for s in raw}
    assert all(s.thin_lateral_mm == by_fruit[(s.frame, s.fruit)] for s in scores)
    assert all(abs(s.thin_lateral_mm) < 10 for s in raw)
    assert isinstance(raw[0], FrameScore)


def test_found_fruit_can_be_matched_to_the_truth_by_their_masks_label(tmp_path):
    """``by_id``: the frame's own masks carry the truth's ids; every completed fruit is scored, however far its
    seen points' box lies from the truth (here every true box is moved 10 cm: nothing within the centre gate)."""
    shutil.copytree(EXAMPLE_FRAME, tmp_path / "a")
    truth = tmp_path / "a" / "truth.json"
    data = json.loads(truth.read_text())
    for f in data["fruits"]:
        f["min"][0] += 0.1
        f["max"][0] += 0.1
    truth.write_text(json.dumps(data))
    frame = read_frame(tmp_path / "a")
    labels, _ = frame_masks(frame, "color")
    ids = [tid for tid, _ in frame.truth]
    found = detect(frame, masks=np.where(labels > 0, np.asarray(ids)[np.clip(labels - 1, 0, len(ids) - 1)], 0))
    assert sorted(d.id for d in found.detections) == sorted(ids)
    scores, counts = score_frame(frame, found, ["raw"], Settings())
    assert scores == [] and counts["matched"] == 0  # by centre: all beyond the gate
    scores, counts = score_frame(frame, found, ["raw"], Settings(), by_id=True)
    assert counts["matched"] == 6 and sorted(s.truth for s in scores) == sorted(ids)
    assert all(s.fruit == s.truth and s.centre_mm > 50 for s in scores)
    # a frame without its own masks file: the colour segmenter's labels are no truth ids, the frame is not scored
    scores, totals, failed = evaluate_frames(tmp_path, methods=("raw",), by_id=True)
    assert scores == [] and totals["frames"] == 0 and "no masks file to match the truth by label" in failed["a"]


@pytest.mark.parametrize(("kwargs", "message"), [({"masks": "missing.png"}, "no such file or folder"),
                                                 ({"methods": ("raw", "nope")}, "unknown method 'nope'")])  # fmt: skip
def test_evaluate_frames_refuses_masks_or_a_method_no_frame_can_use_before_any_frame(tmp_path, kwargs, message):
    from symfruit import SymfruitError

    shutil.copytree(EXAMPLE_FRAME, tmp_path / "a")
    with pytest.raises(SymfruitError, match=message):  # before: every frame skipped with the reason, or errors
        evaluate_frames(tmp_path, **kwargs)
