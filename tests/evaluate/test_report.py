"""Reports: the Markdown tables laid out like the paper's, the per-instance CSV, the summary JSON, the plots."""

import csv
import json
import math

import pytest

from symfruit.evaluate.report import PAPER_TABLE2, markdown_table, write_results
from symfruit.evaluate.runner import COLUMNS, Row, summarise


def row(method, iou, centre_mm, *, fruit="strawberry", occlusion=0.0, hidden=0.0, error="", angle_x=0.0,
        depth_mm=float("nan"), lateral_mm=float("nan")):  # fmt: skip
    return Row(protocol="paper", fruit=fruit, kind=fruit, fruit_index=0, pose=0, angle_x=angle_x, angle_y=0.0,
               angle_z=0.0, distance_m=0.3, occlusion=occlusion, hidden=hidden, n_visible=100, method=method, iou=iou,
               centre_mm=centre_mm, chamfer_mm=1.25, f1=0.875, precision=0.9, recall=0.85, seconds=0.0015,
               error=error, depth_mm=depth_mm, lateral_mm=lateral_mm)  # fmt: skip


#: Tests that draw plots run on the worker of tests/evaluate/test_evaluate.py's group, which draws them too: one
#: worker imports matplotlib, not both (pytest-xdist, --dist loadgroup)
PLOTS = pytest.mark.xdist_group("evaluate")

ROWS = [row("raw", 0.5, 10.0, angle_x=-45.0, depth_mm=-20.0, lateral_mm=-3.0),
        row("raw", 0.6, 8.0, angle_x=45.0, depth_mm=-10.0, lateral_mm=1.0),
        row("paper", 0.75, 4.0, angle_x=-45.0), row("paper", float("nan"), float("nan"), error="too few")]  # fmt: skip


def test_paper_table_known_values():
    table = markdown_table(summarise(ROWS), protocol="paper", title="my run")
    lines = table.splitlines()
    assert lines[0] == "# my run" and "## paper protocol: strawberry" in lines and "2 instances." in lines
    # size errors: mean absolute (mean signed)
    assert (
        "| raw | 0.550 | 0.550 | 9.0 | 9.0 | 10.0 | 0 | 0 | 15.0 (-15.0) | 2.0 (-1.0) | 1.25 | 0.875 | 1.50 | 0 |"
        in lines
    )
    assert "| paper | 0.750 | 0.750 | 4.0 | 4.0 | 4.0 | 0 | 0 | - | - | 1.25 | 0.875 | 1.50 | 1 |" in lines
    (ri, rc), (pi, pc) = PAPER_TABLE2["raw"], PAPER_TABLE2["paper"]
    assert f"Ge et al. 2020, Table 2 (mean): input points {ri} / {rc} mm, completed {pi} / {pc} mm." in lines
    other = markdown_table(summarise([row("raw", 0.5, 1.0, fruit="/scans/pears")]), protocol="paper")
    assert other.startswith("# symfruit evaluation") and "## paper protocol: pears" in other and "Table 2" not in other


def test_failed_groups_print_dashes_and_camera_tables_name_the_occlusion():
    rows = [row("raw", float("nan"), float("nan"), error="x", occlusion=0.25, hidden=0.3)]
    table = markdown_table(summarise(rows), protocol="camera")
    assert "## camera protocol: strawberry, occluder target 25% (hidden 30% on average)" in table
    assert "| raw | - | - | - | - | - | - | - | - | - | - | - | - | 1 |" in table and "Table 2" not in table


def test_confidence_lines_appear_for_methods_that_estimate_it():
    rows = [Row(**{**row("fused", 0.5, e).__dict__, "confidence": c}) for c, e in ((0.9, 1.0), (0.5, 2.0), (0.1, 6.0))]
    table = markdown_table(summarise(rows), protocol="paper")
    assert "Confidence of `fused`: Spearman -1.00 against the centre deviation" in table


@PLOTS
def test_every_file_is_written(tmp_path):
    summary = summarise(ROWS)
    written = write_results(tmp_path / "out", ROWS, summary, protocol="paper", meta={"title": "t", "seed": 3})
    names = [p.name for p in written]
    assert names[:3] == ["instances.csv", "summary.json", "table.md"]
    assert {"strawberry-methods.png", "strawberry-by-angle.png"} <= set(names)
    assert all(p.is_file() for p in written)
    with (tmp_path / "out" / "instances.csv").open() as f:
        reader = csv.DictReader(f)
        assert reader.fieldnames == list(COLUMNS)
        rows = list(reader)
    assert [r["method"] for r in rows] == ["raw", "raw", "paper", "paper"]
    assert rows[0]["iou"] == "0.5" and rows[0]["seconds"] == "0.0015" and rows[3]["error"] == "too few"
    data = json.loads((tmp_path / "out" / "summary.json").read_text())  # NaN is written as null
    assert data["seed"] == 3 and data["title"] == "t" and len(data["summary"]) == 2
    assert data["summary"][1]["method"] == "paper" and data["summary"][1]["spearman"] is None
    assert (tmp_path / "out" / "table.md").read_text() == markdown_table(summary, protocol="paper", title="t")
    write_results(tmp_path / "given", ROWS, summary, protocol="paper", meta={}, table="# mine\n")
    assert (tmp_path / "given" / "table.md").read_text() == "# mine\n"


@PLOTS
def test_camera_runs_plot_by_occlusion_when_there_are_levels(tmp_path):
    pytest.importorskip("matplotlib")
    rows = [row(m, 0.5, 2.0, occlusion=o, hidden=o) for m in ("raw", "paper") for o in (0.0, 0.5)]
    rows = [Row(**{**r.__dict__, "protocol": "camera"}) for r in rows]
    written = write_results(tmp_path, rows, summarise(rows), protocol="camera", meta={})
    assert {p.name for p in written} >= {"strawberry-methods.png", "strawberry-by-occlusion.png"}
    assert not math.isnan(summarise(rows)[0]["iou_mean"])
