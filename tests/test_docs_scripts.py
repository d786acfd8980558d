"""The scripts in ``docs/`` that regenerate README's and docs' figures: each still starts and says how it is used.

They are not run here (each is a measurement of minutes); a script that no longer imports against the package, or
lost its command line, would leave a figure that no command written next to it can regenerate."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from .conftest import docs_script

DOCS = Path(__file__).resolve().parents[1] / "docs"
SCRIPTS = sorted(DOCS.glob("*.py"))


def test_there_are_scripts_to_check():
    assert len(SCRIPTS) >= 10 and (DOCS / "eval_boxes.py") in SCRIPTS


@pytest.mark.parametrize("script", SCRIPTS, ids=[s.name for s in SCRIPTS])
def test_a_docs_script_imports_and_prints_its_usage(script, tmp_path):
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    done = subprocess.run([sys.executable, str(script), "--help"], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.startswith("usage:") and not done.stderr
    assert not any(tmp_path.iterdir())  # --help writes nothing


def test_eval_boxes_records_a_box_per_scored_fruit_of_evaluate_frames(tmp_path, monkeypatch):
    """``eval_boxes.py run ... evaluate --frames``: one row per fruit and method, keyed by frame, fruit id and
    method (before: no row at all, so a change could not be compared box by box on frames)."""
    import numpy as np

    import symfruit.evaluate.frames as frames
    from symfruit.core.box import Box

    eval_boxes = docs_script("eval_boxes")
    truth = Box(np.array([0.0, 0.0, 0.3]), np.array([0.03, 0.03, 0.33]))
    boxes = [Box(np.array([0.001 * k, 0.0, 0.3]), np.array([0.03, 0.03, 0.33])) for k in range(3)]

    def score_frame(frame, found, methods, settings, gate=0.03, *, by_id=False):  # as frames.score_frame scores
        out = []
        for (name, fruit, method), box in zip(found, boxes, strict=True):
            out.append(frames.FrameScore(name, fruit, 0, method, frames.box_iou(box, truth), 0.0, 10, False))
        return out, {}

    monkeypatch.setattr(frames, "score_frame", score_frame)
    monkeypatch.setattr(frames, "box_iou", frames.box_iou)  # both put back after the test
    eval_boxes._record_frames(str(tmp_path / "b.csv"))
    found = [("a,1", 4, "raw"), ("a,1", 4, "sphere"), ("b", 7, "raw")]
    scores, _ = frames.score_frame(None, found, ["raw", "sphere"], None)
    assert scores[0].iou == 1.0
    rows = eval_boxes.load(str(tmp_path / "b.csv"))
    assert list(rows) == ["frames|a,1|4|raw", "frames|a,1|4|sphere", "frames|b|7|raw"]
    for values, box in zip(rows.values(), boxes, strict=True):
        assert np.array_equal(values, np.r_[box.min, box.max])


def test_hidden_apples_tables_of_one_small_apple_tree_frame(tmp_path, monkeypatch, capsys):
    """``hidden_apples.py`` on one apple-tree frame of 8 apples (as `symfruit scenes --scene apple-tree --ripe 8`):
    every matched apple in one visible-share column, the mostly hidden ones split by their mask's kind (the frame
    rendered again from its seed, a wrong seed refused) and counted by their front; the settings file read."""
    import re

    from symfruit.synthetic.scenes import write_scenes

    hidden = docs_script("hidden_apples")
    frames = tmp_path / "D"
    write_scenes(frames, 1, seed=4, n_ripe=8, n_unripe=1, tree=True)
    config = tmp_path / "before.yaml"
    config.write_text("evidence:\n  cut_width: 0\n")
    monkeypatch.setattr(sys, "argv", ["hidden_apples.py", "--frames", str(frames), "--seeds", "4", "--config",
                                      str(config)])  # fmt: skip
    hidden.main()
    out = capsys.readouterr().out
    matched = int(re.match(r"(\d+) matched apples; cut_width 0\n", out).group(1))
    groups = [int(n) for n in re.findall(r"(?:visible|partly hidden|mostly hidden) \((\d+)\)", out)]
    assert matched > 0 and len(groups) == 3 and sum(groups) == matched
    kinds = re.findall(r"\| (?:drawn over the leaf|visible part only) \| (\d+) \|", out)
    assert len(kinds) == 2 and sum(map(int, kinds)) == groups[2]
    assert f" of {groups[2]}" in out.split("front over 15 mm behind: ")[1].splitlines()[0]
    by_id = int(re.search(r"--match id\): (\d+) apples, IoU 0\.\d{3}, centre ", out).group(1))
    assert matched <= by_id <= 8
    assert (matched, by_id, kinds) == (7, 7, ["1", "0"])  # this seed's frame: one apple unboxed, one mostly hidden
    monkeypatch.setattr(sys, "argv", ["hidden_apples.py", "--frames", str(frames), "--seeds", "5"])
    with pytest.raises(SystemExit, match="not seed 5's apple-tree frame"):
        hidden.main()


def _slab44():
    return docs_script("slab44")


def test_slab44_classes_points_on_an_apple_behind_it_and_in_front_of_it():
    """``slab44.point_classes``: points on a 70 mm ball's surface (and 5 mm off it) are the fruit's; a leaf 3 cm
    behind its back, beside it, is behind; a point off the ball on its near side is in front."""
    import numpy as np

    sl = _slab44()
    centre, size = np.array([0.1, 0.0, 1.4]), np.full(3, 0.07)
    rng = np.random.default_rng(0)
    d = rng.normal(size=(200, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    surface = centre + 0.035 * d
    outside = centre + 0.040 * d  # 5 mm off: within the 6 mm margin
    foreign = np.array([[0.1, 0.0, 1.4 + 0.035 + 0.03], [0.1 + 0.05, 0.0, 1.41], [0.1 + 0.05, 0.0, 1.39]])
    on, behind, front = sl.point_classes(np.vstack([surface, outside, foreign]), centre, size)
    assert on[:400].all() and not on[400:].any()
    assert behind[400:].tolist() == [True, True, False] and front[400:].tolist() == [False, False, True]
    assert not (on & behind).any() and not (on & front).any() and (on | behind | front).all()


def test_slab44_spur_leaves_lie_around_an_apple_at_its_own_depth():
    """``slab44.spur_leaf_centres``: 1.0-1.6 radii from the apple's centre across the line of sight, -0.3 to +1.0
    radii along it; seeded."""
    import numpy as np

    sl = _slab44()
    centre = np.array([0.2, -0.1, 1.5])
    c = sl.spur_leaf_centres(centre, 0.04, 500, np.random.default_rng(3))
    across = np.linalg.norm(c[:, :2] - centre[:2], axis=1)
    along = c[:, 2] - centre[2]
    assert c.shape == (500, 3)
    assert across.min() >= 0.04 - 1e-12 and across.max() <= 0.064 + 1e-12 and np.ptp(across) > 0.02
    assert along.min() >= -0.012 - 1e-12 and along.max() <= 0.04 + 1e-12
    assert np.array_equal(c, sl.spur_leaf_centres(centre, 0.04, 500, np.random.default_rng(3)))


def _speed_profile(tmp_path, *args: str) -> list[str]:
    """``docs/speed_profile.py ARGS`` run from ``tmp_path`` with this tree's sources: its printed lines."""
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1", "PYTHONPATH": str(DOCS.parent / "src")}
    done = subprocess.run([sys.executable, str(DOCS / "speed_profile.py"), *args], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout.splitlines()


def test_speed_profile_profiles_the_segmenter_on_tree_frames(tmp_path):
    """``speed_profile.py --trees N`` (stop 51): the colour segmenter alone on N apple-tree frames, figures per frame
    (one ``segment`` call a frame)."""
    lines = _speed_profile(tmp_path, "--only", "colour.segment", "--trees", "1", "--frames", "2", "--top", "5")
    assert lines[0].endswith("(2 frames)")
    assert any(line.endswith("1.0 calls  symfruit.segment.colour.segment") for line in lines[1:])


def test_speed_profile_gives_own_times(tmp_path):
    """``speed_profile.py --self`` (stop 52): each function's own time, less the wrapped functions it calls: the
    segmenter's entry point, nearly all of whose time is ``_segment_at``'s, then reads far less than it, and the
    kernels' and the rest's sums are printed."""
    lines = _speed_profile(tmp_path, "--only", "colour.segment", "colour._segment_at", "--trees", "1", "--frames", "1",
                           "--self")  # fmt: skip
    assert lines[1].startswith("own times: the kernels 0.00 ms, the rest ")
    own = {line.split()[-1]: float(line.split()[0]) for line in lines[2:]}
    assert own["symfruit.segment.colour.segment"] < 0.5 * own["symfruit.segment.colour._segment_at"]
