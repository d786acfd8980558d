"""The demo: the shipped example frame, found and scored against its truth, from any folder."""

import json
import subprocess
import sys

import pytest

from symfruit.demo import FRAME_SEED, example_frame, run_demo

from .conftest import EXAMPLE_FRAME

#: one worker runs the module's tests one after another and runs the demo once (pytest-xdist, --dist loadgroup: a
#: worker that interleaved other modules' tests would tear the module-scoped fixture down between them)
pytestmark = pytest.mark.xdist_group("demo")


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo") / "out"
    return run_demo(out), out


def test_the_demo_finds_the_six_ripe_fruit(demo):
    report, _ = demo
    assert report.n_truth == 6 and len(report.found.detections) == 6 and len(report.located) == 6
    assert set(report.errors) == {d.id for d in report.located} and all(e is not None for e in report.errors.values())
    raw, completed = report.mean_errors()
    assert completed < 0.75 * raw  # measured (fused, no profile): raw 10.4 mm, completed 6.7 mm
    assert report.found.frame.name == "example_frame"


def test_the_demo_writes_its_outputs(demo):
    report, out = demo
    assert report.output == out
    names = sorted(p.name for p in out.iterdir())
    assert names == ["detections.json", *(f"fruit_{k:03d}.ply" for k in range(1, 7)), "overlay.png"]
    data = json.loads((out / "detections.json").read_text())
    assert len(data["fruits"]) == 6 and data["settings"]["fused"]["revolution"] is False  # defaults, no profile


def test_the_frame_ships_as_package_data():
    with example_frame() as folder:
        assert folder.resolve() == EXAMPLE_FRAME
        assert {"color.png", "depth.png", "camera.json", "truth.json"} <= {p.name for p in folder.iterdir()}
    assert FRAME_SEED == 1


def test_the_demo_works_from_an_unrelated_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    report = run_demo("relative/out", method="raw")
    assert len(report.located) == 6 and (tmp_path / "relative" / "out" / "detections.json").is_file()
    done = subprocess.run([sys.executable, "-m", "symfruit", "demo", "--output", "cli", "--method", "raw"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "6 fruit found, 6 ripe fruit in the truth, method raw" in done.stdout
    assert "mean centre error: raw" in done.stdout and "overlay:" in done.stdout
    assert (tmp_path / "cli" / "overlay.png").is_file() and (tmp_path / "cli" / "detections.json").is_file()
