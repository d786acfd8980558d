"""The command line: round trip on each format, outputs, errors on one line."""

import json
from pathlib import Path

import numpy as np
import pytest

from symfruit import __version__
from symfruit.cli import main
from symfruit.io import read_cloud

from .conftest import EXAMPLES, front_half, sphere_cloud
from .test_io import write_pcd

VISIBLE = front_half(sphere_cloud())


def write(path: Path, points: np.ndarray) -> None:
    if path.suffix == ".ply":
        from symfruit.io import write_ply

        write_ply(path, points)
    elif path.suffix == ".pcd":
        write_pcd(path, points, "binary")
    elif path.suffix == ".npy":
        np.save(path, points)
    else:
        sep = "," if path.suffix == ".csv" else " "
        path.write_text("\n".join(sep.join(f"{v:.17g}" for v in p) for p in points))


@pytest.mark.parametrize("ext", [".ply", ".pcd", ".xyz", ".txt", ".csv", ".npy"])
def test_complete_json_round_trip(tmp_path, capsys, ext):
    cloud = tmp_path / f"fruit{ext}"
    write(cloud, VISIBLE)
    out = tmp_path / "out" / "fruit.ply"
    assert main(["complete", str(cloud), "--json", "--output", str(out)]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert set(printed) >= {
        "method",
        "centre",
        "box",
        "plane",
        "score",
        "n_visible",
        "n_completed",
        "seconds",
    }
    assert printed["method"] == "fused" and printed["n_completed"] == 2 * len(VISIBLE)
    assert 0.0 <= printed["confidence"] <= 1.0 and isinstance(printed["reliable"], bool)
    completed = read_cloud(out)
    assert len(completed) == printed["n_completed"]
    # The box holds the completed cloud (fused boxes its fitted shape, which may reach beyond it).
    assert np.all(completed.min(axis=0) >= np.array(printed["box"]["min"]) - 1e-6)
    assert np.all(completed.max(axis=0) <= np.array(printed["box"]["max"]) + 1e-6)
    saved = json.loads(out.with_suffix(".json").read_text())
    assert saved["settings"]["paper"]["rotations_x"] == 11 and saved["camera"]["fx"] == 615.0
    assert saved["extras"]["regime"] in ("clean", "noisy")
    assert saved["centre"] == printed["centre"]


def test_complete_table_with_camera_config_and_units(tmp_path, capsys):
    cloud = tmp_path / "mm.npy"
    np.save(cloud, VISIBLE * 1000.0)
    config = tmp_path / "s.yaml"
    config.write_text("paper:\n  rotations_x: 5\n")
    code = main(
        [
            "complete",
            str(cloud),
            "--units",
            "mm",
            "--camera",
            str(EXAMPLES / "camera.json"),
            "--config",
            str(config),
            "--method",
            "paper",
        ]
    )
    assert code == 0
    out = capsys.readouterr().out
    assert "best of 60 planes" in out and "centre" in out and " mm" in out


@pytest.mark.parametrize("method", ["raw", "sphere"])
def test_other_methods(tmp_path, capsys, method):
    cloud = tmp_path / "a.npy"
    np.save(cloud, VISIBLE)
    assert main(["complete", str(cloud), "--method", method, "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["plane"] is None and printed["score"] is None


def test_embedded_sample(capsys):
    assert main(["complete", str(EXAMPLES / "strawberry_partial.ply"), "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["n_visible"] == 600


@pytest.mark.parametrize(
    "args, message",
    [
        (["complete", "missing.ply"], "missing.ply: no such file"),
        (["complete", "x.obj"], "unknown cloud extension"),
        (["complete", "{sample}", "--method", "nope"], "unknown method 'nope'"),
        (["complete", "{sample}", "--output", "x.txt"], "must end in .ply"),
        (
            ["complete", "{sample}", "--units", "mm"],
            "too small for a fruit; check the units|too small for a fruit",
        ),
        (["complete", "{sample}", "--camera", "nocam.json"], "nocam.json: no such intrinsics file"),
    ],
)
def test_errors_are_one_line_with_status_2(capsys, args, message):
    args = [a.replace("{sample}", str(EXAMPLES / "strawberry_partial.ply")) for a in args]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith("symfruit: error: ") and err.count("\n") == 1
    assert "Traceback" not in err
    import re

    assert re.search(message, err)


def test_debug_shows_the_exception():
    from symfruit import FileFormatError

    with pytest.raises(FileFormatError):
        main(["--debug", "complete", "missing.ply"])


def test_version_settings_methods(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["--version"])
    assert exit_info.value.code == 0 and __version__ in capsys.readouterr().out
    assert main(["settings"]) == 0
    import yaml

    assert yaml.safe_load(capsys.readouterr().out)["paper"]["translations"] == 4
    assert main(["methods"]) == 0
    assert {"paper", "raw", "sphere"} <= {line.split()[0] for line in capsys.readouterr().out.splitlines()}


def test_console_script_runs():
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-m", "symfruit", "--version"], capture_output=True, text=True, check=True)
    assert done.stdout.startswith("symfruit ")


def test_bench_runs_and_reports(capsys):
    assert main(["bench", "--repeat", "2", "--points", "200", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["rows"]
    assert [r["method"] for r in rows] == ["paper", "paper", "fused", "fused", "sphere", "ellipsoid", "raw"]
    assert [r["planes"] for r in rows][:2] == [132, 1320]
    assert all(r["median_ms"] > 0 for r in rows)
