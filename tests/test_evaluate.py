"""The evaluation: protocols, the quick run CI relies on, reports and the command."""

import csv
import json

import numpy as np
import pytest

from symfruit.cli import main
from symfruit.evaluate import evaluate
from symfruit.evaluate.protocols import PAPER_ANGLES, PAPER_DISTANCE, build, specs


def test_paper_protocol_is_algorithm_2():
    all_specs = specs("paper", "strawberry", n=10)
    assert len(all_specs) == 190 and len(PAPER_ANGLES) == 19
    assert PAPER_ANGLES[0] == -45 and PAPER_ANGLES[-1] == 45
    inst = build(all_specs[0])
    assert 100 < len(inst.visible) < 600
    assert inst.truth_box.contains(inst.visible)
    assert np.allclose(inst.truth_box.centre, [0, 0, PAPER_DISTANCE])
    again = build(all_specs[0])
    assert np.array_equal(inst.visible, again.visible)
    # The same 600 points in every pose of a fruit: the truth box volume changes only by rotation.
    other = build(all_specs[9])
    assert len(other.truth_surface) == len(inst.truth_surface) == 600


def test_camera_protocol_instances():
    spec = specs("camera", "strawberry", n=3, occlusions=(0.0, 0.3))
    assert len(spec) == 6
    clear, covered = build(spec[0]), build(spec[3])
    assert clear.hidden == 0.0 and 0.2 < covered.hidden < 0.4
    assert 0.25 <= clear.distance <= 0.6
    assert len(covered.visible) < len(clear.visible)
    # Noisy points lie near the true surface, and inside an enlarged truth box.
    assert clear.truth_box.contains(clear.visible, tol=0.01)
    from scipy.spatial import cKDTree

    d, _ = cKDTree(clear.truth_surface).query(clear.visible)
    assert np.median(d) < 0.003


@pytest.fixture(scope="module")
def quick_paper(tmp_path_factory):
    root = tmp_path_factory.mktemp("results")
    return evaluate(protocol="paper", quick=True, output=root, jobs=2, progress=False), root


def test_quick_paper_run_orders_methods_as_the_paper(quick_paper):
    result, _ = quick_paper
    by = {s["method"]: s for s in result.summary}
    assert by["raw"]["n"] == 28
    # The paper's finding (Table 2): completion improves both IoU and centre deviation over raw.
    assert by["paper"]["iou_mean"] > by["raw"]["iou_mean"] + 0.05
    assert by["paper"]["centre_mm_mean"] < by["raw"]["centre_mm_mean"] - 0.5
    assert by["ellipsoid"]["iou_mean"] > by["raw"]["iou_mean"]


def test_quick_paper_run_writes_every_output(quick_paper):
    result, root = quick_paper
    folder = result.folder
    assert (root / "latest").resolve() == folder.resolve()
    names = {p.name for p in folder.iterdir()}
    assert {"instances.csv", "summary.json", "table.md", "settings.json"} <= names
    assert {"strawberry-methods.png", "strawberry-by-angle.png"} <= names
    with (folder / "instances.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 28 * 5 and {r["method"] for r in rows} == {"raw", "sphere", "ellipsoid", "paper", "fused"}
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["settings"]["strawberry"]["paper"]["translations"] == 4 and summary["instances"] == 28
    assert summary["settings"]["strawberry"]["fused"]["revolution"] is True  # the strawberry profile
    table = (folder / "table.md").read_text()
    assert "| paper |" in table and "Table 2" in table
    from PIL import Image

    assert Image.open(folder / "strawberry-by-angle.png").size[0] > 600


def test_camera_run_with_occlusion_and_every_fruit(tmp_path):
    result = evaluate(protocol="camera", fruits=("apple", "citrus", "tomato"), n=2, occlusions=(0.0, 0.4),
                      methods=("raw", "paper"), output=tmp_path, jobs=1, progress=False)  # fmt: skip
    assert len(result.rows) == 3 * 2 * 2 * 2
    assert not any(r.error for r in result.rows)
    assert (result.folder / "apple-by-occlusion.png").exists()
    assert "occluder target 40%" in result.table


def test_scan_folder_runs_both_protocols(tmp_path):
    from symfruit.io import write_ply
    from symfruit.shapes import FRUITS

    scans = tmp_path / "scans"
    for i in range(2):
        fruit = FRUITS["strawberry"](np.random.default_rng(i))
        write_ply(scans / f"berry{i}.ply", fruit.sample(3000, np.random.default_rng(i)))
    paper = evaluate(protocol="paper", fruits=(str(scans),), n=5, methods=("raw", "paper"),
                     output=None, jobs=1, progress=False)  # fmt: skip
    assert len(paper.rows) == 2 * 19 * 2 and paper.rows[0].kind == "scan/berry0"
    camera = evaluate(protocol="camera", fruits=(str(scans),), n=3, methods=("raw",), output=None,
                      jobs=1, progress=False)  # fmt: skip
    assert len(camera.rows) == 3 and all(r.n_visible > 50 for r in camera.rows)


def test_evaluate_command(tmp_path, capsys):
    assert main(["evaluate", "--quick", "--output", str(tmp_path), "--jobs", "1", "--methods", "raw,paper"]) == 0
    out = capsys.readouterr().out
    assert "| raw |" in out and "results: " in out
    assert main(["evaluate", "--fruit", "banana"]) == 2
    assert "not a fruit kind" in capsys.readouterr().err
    assert main(["evaluate", "--methods", "raw,nope"]) == 2
    assert main(["evaluate", "--protocol", "camera", "--occlusion", "0,1.5"]) == 2


@pytest.mark.slow
@pytest.mark.parametrize("fruit", ["strawberry", "apple", "citrus", "tomato"])
def test_full_paper_protocol(fruit):
    result = evaluate(protocol="paper", fruits=(fruit,), output=None, progress=False)
    by = {s["method"]: s for s in result.summary}
    assert by["raw"]["n"] == 190
    assert by["paper"]["iou_mean"] > by["raw"]["iou_mean"] + 0.1
    assert by["paper"]["centre_mm_mean"] < by["raw"]["centre_mm_mean"]
