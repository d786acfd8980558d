"""The demo: the shipped example frame, found and scored against its truth, from any folder."""

import json

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


def test_the_demo_works_from_an_unrelated_folder(tmp_path, monkeypatch, capsys):
    """`symfruit demo` (the command, in this process) with a relative output folder, run from a folder that has
    nothing to do with the package: the frame comes from the package data. (That `python -m symfruit` starts from
    an unrelated folder is checked by tests/test_cli.py::test_console_script_runs, a real process.)"""
    from symfruit.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(["demo", "--output", "relative/out", "--method", "raw"]) == 0
    out = capsys.readouterr().out
    assert "6 fruit found, 6 ripe fruit in the truth, method raw" in out
    assert "mean centre error: raw" in out and "overlay:" in out and " failed: " not in out  # all six located
    folder = tmp_path / "relative" / "out"
    assert (folder / "overlay.png").is_file() and (folder / "detections.json").is_file()
    fruits = json.loads((folder / "detections.json").read_text())["fruits"]
    assert len(fruits) == 6 and not any("error" in f for f in fruits)


def test_the_demo_never_writes_into_its_own_frame_folder(tmp_path, monkeypatch):
    import contextlib
    import shutil

    from symfruit import demo
    from symfruit.errors import OutputError

    copy = tmp_path / "example_frame"  # a copy stands in for the package data, which a failure would write into
    shutil.copytree(EXAMPLE_FRAME, copy)
    monkeypatch.setattr(demo, "example_frame", lambda: contextlib.nullcontext(copy))
    before = sorted(p.name for p in copy.iterdir())
    with pytest.raises(OutputError, match=r"example_frame: the output folder is also an input folder"):
        run_demo(copy, method="raw")  # before: fruit_00k.ply, overlay.png, detections.json written beside its images
    assert sorted(p.name for p in copy.iterdir()) == before


def test_the_demo_refuses_an_empty_output_path(tmp_path, monkeypatch):
    from symfruit import InputError

    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match="demo: the output folder is an empty path"):
        run_demo("")  # before: detections, clouds and overlay written into the working folder
    assert not list(tmp_path.iterdir())
