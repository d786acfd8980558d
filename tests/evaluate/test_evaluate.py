"""The evaluation entry point (:func:`symfruit.evaluate.evaluate`): the quick run CI relies on, every output,
the camera protocol with occlusion, scan folders, and the full paper protocol (slow)."""

import csv
import json
import re

import numpy as np
import pytest

from symfruit.errors import InputError
from symfruit.evaluate import evaluate

#: one worker computes the module's expensive fixture once (pytest-xdist, --dist loadgroup; session scope, as
#: a worker interleaves other modules' tests and would tear a module-scoped fixture down between them)
pytestmark = pytest.mark.xdist_group("evaluate")


@pytest.fixture(scope="session")
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
    methods = {"raw", "sphere", "ellipsoid", "superellipsoid", "paper", "fused", "evidence"}
    assert len(rows) == 28 * len(methods) and {r["method"] for r in rows} == methods
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["settings"]["strawberry"]["paper"]["translations"] == 4 and summary["instances"] == 28
    assert summary["settings"]["strawberry"]["fused"]["revolution"] is True  # the strawberry profile
    table = (folder / "table.md").read_text()
    assert "| paper |" in table and "Table 2" in table
    from PIL import Image

    assert Image.open(folder / "strawberry-by-angle.png").size[0] > 600


def test_camera_run_with_occlusion_and_every_fruit(tmp_path, monkeypatch):
    from symfruit.evaluate import report

    plotted = []  # what the plots are drawn from (drawing them: test_report.py, by occlusion level too)
    monkeypatch.setattr(report, "write_plots", lambda folder, rows, *, protocol: plotted.append((protocol, rows)) or [])
    result = evaluate(protocol="camera", fruits=("apple", "citrus", "tomato"), n=1, occlusions=(0.0, 0.4),
                      methods=("raw", "paper"), output=tmp_path, jobs=1, progress=False)  # fmt: skip
    assert len(result.rows) == 3 * 1 * 2 * 2
    assert not any(r.error for r in result.rows)
    assert (result.folder / "instances.csv").exists() and plotted == [("camera", result.rows)]
    assert "occluder target 40%" in result.table


def test_scan_folder_runs_both_protocols(tmp_path):
    from symfruit.io import write_ply
    from symfruit.synthetic.shapes import FRUITS

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


def test_a_bad_scan_is_left_out_and_named_the_others_evaluated(tmp_path):
    from symfruit.io import write_ply
    from symfruit.synthetic.shapes import FRUITS

    scans = tmp_path / "scans"
    berry = FRUITS["strawberry"](np.random.default_rng(0))
    write_ply(scans / "berry0.ply", berry.sample(3000, np.random.default_rng(0)))
    (scans / "berry1.ply").write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 9\n")  # torn
    result = evaluate(protocol="paper", fruits=(str(scans),), n=5, methods=("raw",), output=tmp_path / "r",
                      jobs=1, progress=False)  # fmt: skip
    # before: the whole evaluation refused for berry1.ply
    assert len(result.rows) == 19 and {r.kind for r in result.rows} == {"scan/berry0"}
    bad = str(scans / "berry1.ply")
    assert list(result.skipped) == [bad] and result.skipped[bad].startswith(bad)
    assert json.loads((result.folder / "settings.json").read_text())["skipped_scans"] == result.skipped


@pytest.mark.slow
@pytest.mark.parametrize("fruit", ["strawberry", "apple", "citrus", "tomato"])
def test_full_paper_protocol(fruit):
    result = evaluate(protocol="paper", fruits=(fruit,), output=None, progress=False)
    by = {s["method"]: s for s in result.summary}
    assert by["raw"]["n"] == 190
    assert by["paper"]["iou_mean"] > by["raw"]["iou_mean"] + 0.1
    assert by["paper"]["centre_mm_mean"] < by["raw"]["centre_mm_mean"]


def test_settings_given_are_used_for_every_fruit_and_nothing_is_written_without_an_output(tmp_path):
    from symfruit import Settings

    mine = Settings().replace(paper={"translations": 2})
    result = evaluate(protocol="paper", fruits=("apple", "tomato"), n=1, methods=("paper",), settings=mine,
                      output=None, jobs=1, progress=False)  # fmt: skip
    assert result.folder is None and len(result.rows) == 2 * 19
    assert {r.fruit for r in result.rows} == {"apple", "tomato"} and not any(r.error for r in result.rows)
    assert "## paper protocol: apple" in result.table and "## paper protocol: tomato" in result.table


def test_a_config_file_is_laid_over_each_fruits_profile(tmp_path, monkeypatch):
    from symfruit.evaluate import report

    monkeypatch.setattr(report, "write_plots", lambda *a, **k: [])  # as without matplotlib (plots: tests above)
    config = tmp_path / "s.yaml"
    config.write_text("fused:\n  depth_ratio: 1.7\n")
    result = evaluate(protocol="paper", fruits=("strawberry", "apple"), n=1, methods=("raw",), config=config,
                      output=tmp_path / "out", jobs=1, progress=False, quick=True)  # fmt: skip
    saved = json.loads((result.folder / "settings.json").read_text())["settings"]
    assert saved["strawberry"]["fused"]["depth_ratio"] == 1.7 and saved["strawberry"]["fused"]["revolution"] is True
    assert saved["apple"]["fused"]["depth_ratio"] == 1.7 and saved["apple"]["fused"]["mirror_weight"] == 0.25
    assert saved["apple"]["fused"]["mirror"]["translations"] == 4  # the apple profile's nested mirror section


@pytest.mark.parametrize("sensor", ["azure-kinect", "realsense-l515", "realsense-d435", "realsense-d405"])
def test_quick_camera_run_through_each_real_camera(sensor):
    ev = evaluate(protocol="camera", fruits=("apple",), methods=("raw", "sphere", "evidence"), n=3, sensor=sensor,
                  output=None, jobs=1, progress=False)  # fmt: skip
    by = {s["method"]: s for s in ev.summary}
    assert all(s["failed"] == 0 and s["n"] == 3 for s in by.values())
    assert 0.1 < by["raw"]["iou_mean"] < by["evidence"]["iou_mean"] < 1.0  # completion still helps
    assert f"{sensor} sensor" in ev.table
    assert all(r.n_visible > 30 for r in ev.rows)


@pytest.mark.slow
@pytest.mark.parametrize("sensor", ["azure-kinect", "realsense-l515", "realsense-d435", "realsense-d405"])
def test_camera_run_through_each_real_camera_on_the_proxies(sensor):
    fruits = ("strawberry", "apple", "citrus", "lemon", "peach", "pear", "plum")
    ev = evaluate(protocol="camera", fruits=fruits, methods=("raw", "evidence"), n=4, sensor=sensor, output=None,
                  jobs=2, progress=False)  # fmt: skip
    rows = [r for r in ev.rows if r.method == "evidence"]
    assert sum(bool(r.error) for r in rows) <= 2
    raw = np.mean([r.iou for r in ev.rows if r.method == "raw" and not r.error])
    assert raw < np.mean([r.iou for r in rows if not r.error])


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"methods": ()}, "methods is empty"),
        ({"fruits": []}, "fruits is empty"),
        ({"methods": "sphere"}, "methods must be a list of names, got str"),  # before: six unknown methods s, p, h...
        ({"fruits": "apple"}, "fruits must be a list of names, got str"),
        ({"methods": ("raw", "raw")}, "methods lists 'raw' twice"),
        ({"fruits": ("apple", "apple")}, "fruits lists 'apple' twice"),
        ({"methods": ("nope",)}, "unknown method 'nope'"),  # before: a table row of errors
        ({"protocol": "masks"}, "unknown protocol 'masks'"),  # before: ValueError
        ({"n": 0}, "n must be a whole number 1-100000, got 0"),  # before: an empty table
        ({"n": -1}, "n must be a whole number 1-100000, got -1"),
        ({"n": 10**9}, "n must be a whole number 1-100000"),  # before: a billion instances
        ({"n": 1.5}, "n must be a whole number"),  # before: TypeError from range()
        ({"views": 0}, "views must be a whole number"),  # before: ValueError
        ({"seed": -1}, "seed must be a whole number 0-"),
        ({"jobs": 10**6}, "jobs must be a whole number 1-256"),
        ({"occlusions": ()}, "occlusions must be a non-empty list"),
        ({"occlusions": (float("nan"),)}, "occlusion levels must be numbers in [0, 1), got nan"),
        ({"occlusions": (1.5,)}, "occlusion levels must be numbers in [0, 1), got 1.5"),
        ({"sensor": "nope"}, "unknown sensor 'nope'"),  # before: ValueError
        ({"poses": "uniform"}, "poses must be one of"),  # the paper protocol's own poses; before: ValueError
        ({"settings": "apple"}, "settings must be a Settings"),  # before: every row an error
    ],
)
def test_evaluate_refuses_arguments_it_cannot_run_with_before_any_work(kwargs, message, tmp_path):
    args = {"protocol": "paper", "quick": True, "methods": ("raw",), "output": tmp_path / "r", "progress": False}
    with pytest.raises(InputError, match=re.escape(message)):
        evaluate(**{**args, **kwargs})
    assert not (tmp_path / "r").exists()  # refused before a results folder was made


def test_a_camera_model_varied_by_sensor_set(tmp_path):
    """``sensor_set`` reaches every view, is named in the title and settings.json, and is refused where no real camera
    model is evaluated."""
    kw = dict(protocol="camera", fruits=["plum"], methods=["raw"], n=1, sensor="azure-kinect", jobs=1, progress=False)
    base = evaluate(**kw, output=None)
    wider = evaluate(**kw, sensor_set={"rim_invalid_px": 3}, output=tmp_path)
    assert wider.rows[0].n_visible < base.rows[0].n_visible
    assert "(sensor set: rim_invalid_px=3)" in wider.table
    assert json.loads((wider.folder / "settings.json").read_text())["sensor_set"] == {"rim_invalid_px": 3.0}
    with pytest.raises(InputError, match="sensor_set changes a real camera model of the camera protocol"):
        evaluate(**{**kw, "sensor": "heldback"}, sensor_set={"rim_invalid_px": 3}, output=None)
    with pytest.raises(InputError, match="flying_share=2: must be 0 to 1"):
        evaluate(**kw, sensor_set=[("flying_share", 2)], output=None)
