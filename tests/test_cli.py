"""The command line: round trip on each format, every command, outputs, errors on one line."""

import json
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from symfruit import Settings, __version__
from symfruit.cli import main
from symfruit.io import read_cloud

from .conftest import EXAMPLE_FRAME, EXAMPLES, VISIBLE, front_half, small_frame, sphere_cloud, write_pcd


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
    assert printed["method"] == "evidence" and printed["n_completed"] == 2 * len(VISIBLE)
    assert 0.0 <= printed["confidence"] <= 1.0 and isinstance(printed["reliable"], bool)
    completed = read_cloud(out)
    assert len(completed) == printed["n_completed"]
    # The box holds the completed cloud (the default boxes its candidates' shapes, which may reach beyond it).
    assert np.all(completed.min(axis=0) >= np.array(printed["box"]["min"]) - 1e-6)
    assert np.all(completed.max(axis=0) <= np.array(printed["box"]["max"]) + 1e-6)
    saved = json.loads(out.with_suffix(".json").read_text())
    assert saved["settings"]["paper"]["rotations_x"] == 11 and saved["camera"]["fx"] == 615.0
    assert set(saved["extras"]["weights"]) >= {"sphere", "raw"}
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
        (["evaluate", "--quick", "--jobs", "-1"], "--jobs must be between 1 and 256, got -1"),
        (["evaluate", "--quick", "--seed", "-1"], "--seed must be a whole number >= 0, got -1"),
        (["evaluate", "--protocol", "masks", "--n", "1", "--seed", "-1"], "--seed must be a whole number >= 0, got -1"),
        (["evaluate", "--quick", "--n", "0"], "--n must be between 1 and 100000"),
        (["scenes", "out", "--n", "0"], "--n must be 1-100000, got 0$"),
        (["scenes", "out", "--ripe", "100000"], "--ripe must be 0-50, got 100000$"),  # before: "--n must be ..."
        (["scenes", "out", "--unripe", "-1"], "--unripe must be 0-50, got -1$"),
        (
            ["scenes", "out", "--seed", "1" + "0" * 400],
            r"--seed must be a whole number >= 0 with --seed \+ --n at most 2\*\*63, got 10{11}\.\.\. \(401 digits\)$",
        ),  # before: written, the seed printed whole
        (["scenes", "out", "--seed", str(2**63 - 1), "--n", "2"], r"with --seed \+ --n at most 2\*\*63"),
        (["bench", "--recording", "0"], "--recording must be between 1 and 100000"),
        (["detect", "{sample}", "--output", "o", "--chunk", "0"], "--chunk must be between 1 and 10000"),
        (["evaluate", "--frames", "f", "--match", "id", "--masks", "color"], "--match id needs the frames' own masks"),
        (["bench", "--points", "999999999"], "every --points must be 10-5000000"),  # refused before 30 GB asked for
        (["bench", "--repeat", "0"], "--repeat must be 1-100000, got 0$"),
        (["bench", "--frame", "--repeat", "0"], "--repeat must be 1-100000, got 0$"),  # not: "and every --points"
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


def test_console_script_runs(tmp_path):
    """`python -m symfruit` in a real process, started from a folder that has nothing to do with the package."""
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-m", "symfruit", "--version"], capture_output=True, text=True, check=True,
                          cwd=tmp_path, timeout=300)  # fmt: skip
    assert done.stdout.startswith("symfruit ")


def test_bench_runs_and_reports(capsys):
    assert main(["bench", "--repeat", "2", "--points", "200", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["rows"]
    assert [r["method"] for r in rows] == ["paper", "paper", "evidence", "evidence", "fused", "fused", "superellipsoid",
                                           "sphere", "ellipsoid", "raw", "evidence", "fused", "superellipsoid",
                                           "sphere", "paper"]  # fmt: skip
    assert 14000 < rows[-1]["points"] < 16000  # the depth-camera view
    assert [r["planes"] for r in rows][:2] == [132, 1320]
    assert all(r["median_ms"] > 0 for r in rows)


def test_bench_frame_times_one_method_or_profiles_it(capsys, monkeypatch):
    import functools

    from symfruit.evaluate import bench

    # both commands render the same synthetic frame: render it once
    monkeypatch.setattr(bench, "_bench_scene", functools.cache(bench._bench_scene))
    assert main(["bench", "--frame", "--method", "raw", "--repeat", "1", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["rows"]
    assert [r["method"] for r in rows] == ["raw"] and rows[0]["min_ms"] > 0
    assert rows[0]["points"] >= 6 and rows[0]["median_ms"] > 0  # the fruit located in the frame of 8 ripe ones
    assert main(["bench", "--frame", "--method", "raw", "--repeat", "1", "--profile"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("cProfile of 1 frames, method raw") and "detect" in out
    # the stages of that frame's detect, as detect times them: computed once here, the runs above timed it for real
    from symfruit import detect as detect_module

    real, found = detect_module.detect, {}

    def detect_once(frame, *, method, pool=None):
        if (id(frame), method) not in found:
            found[(id(frame), method)] = real(frame, method=method)
        return found[(id(frame), method)]

    monkeypatch.setattr(detect_module, "detect", detect_once)
    assert main(["bench", "--frame", "--method", "raw", "--repeat", "2", "--stages", "--json"]) == 0
    stages = json.loads(capsys.readouterr().out)["stages"]["raw"]
    assert set(stages) == {"segment", "trim", "register", "extract", "occlusion", "complete", "total", "cpu"}
    assert all(len(v) == 2 for v in stages.values())
    assert all(t >= s for t, s in zip(stages["total"], stages["segment"], strict=True))
    assert main(["bench", "--frame", "--method", "raw", "--repeat", "1", "--stages"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1].split() == ["stage", "raw"] and [ln.split()[0] for ln in lines[2:]][-1] == "cpu"
    assert len(found) == 1  # one frame, one method


def test_cli_detect_and_evaluate_frames(tmp_path, capsys):
    """(`demo` runs as a command in tests/test_demo.py, `bench --frame` in the test above.)"""
    assert main(["detect", str(EXAMPLE_FRAME), "--output", str(tmp_path / "d"), "--method", "raw"]) == 0
    assert (tmp_path / "d" / "example_frame" / "detections.json").exists()
    frames = str(EXAMPLE_FRAME.parent)
    assert main(["evaluate", "--frames", frames, "--methods", "raw,paper", "--output", str(tmp_path)]) == 0
    assert "Table 3" in capsys.readouterr().out
    assert main(["detect", str(tmp_path / "nothing"), "--output", str(tmp_path / "x")]) == 2


def test_detect_with_fruit_processes_writes_the_same_detections(tmp_path, capsys):
    """``detect --fruit-processes 1``: the same records (the workers warm up meanwhile: whether they take a fruit of
    these few frames is the host's; tests/test_fruitpool.py and test_batch.py check the workers' fruit) and no worker
    left afterwards."""
    import multiprocessing

    for name, extra in (("one", []), ("two", ["--fruit-processes", "1"])):
        assert main(["detect", str(EXAMPLE_FRAME), "--output", str(tmp_path / name), *extra]) == 0
    one, two = ((tmp_path / n / "example_frame" / "detections.json").read_text() for n in ("one", "two"))
    strip = lambda text: [{k: v for k, v in f.items() if k != "seconds"} for f in json.loads(text)["fruits"]]  # noqa: E731
    assert strip(one) == strip(two) and len(strip(one)) >= 2
    assert not [p for p in multiprocessing.active_children() if p.name == "symfruit-fruit"]
    assert "no worker process" not in capsys.readouterr().out


def test_evaluate_frames_goes_on_past_a_bad_frame_and_exits_1(tmp_path, capsys):
    frames = tmp_path / "frames"
    shutil.copytree(EXAMPLE_FRAME, frames / "good")
    shutil.copytree(EXAMPLE_FRAME, frames / "torn")
    (frames / "torn" / "depth.png").write_bytes(b"\x89PNG\r\n\x1a\n torn off")
    code = main(["evaluate", "--frames", str(frames), "--methods", "raw", "--output", str(tmp_path / "r")])
    out = capsys.readouterr().out
    assert code == 1  # as detect: the table is of the good frame, the torn one is named
    assert "skipped torn" in out and "Table 3" in out


def test_evaluate_command(tmp_path, capsys, monkeypatch):
    from symfruit.evaluate import report

    monkeypatch.setattr(report, "write_plots", lambda *a, **k: [])  # as without matplotlib (plots: tests/evaluate)
    assert (
        main(["evaluate", "--quick", "--output", str(tmp_path), "--jobs", "1", "--methods", "raw,paper", "--n", "1"])
        == 0
    )
    out = capsys.readouterr().out
    assert "| raw |" in out and "results: " in out
    assert main(["evaluate", "--fruit", "kiwi"]) == 2
    assert "not a fruit kind" in capsys.readouterr().err
    assert main(["evaluate", "--methods", "raw,nope"]) == 2
    assert main(["evaluate", "--protocol", "camera", "--occlusion", "0,1.5"]) == 2
    assert main(["evaluate", "--quick", "--no-profile", "--methods", "fused", "--output", str(tmp_path), "--jobs", "1",
                 "--n", "1"]) == 0  # fmt: skip
    saved = json.loads((tmp_path / "latest" / "settings.json").read_text())["settings"]["strawberry"]
    assert saved["fused"]["revolution"] is False  # the defaults, not the strawberry profile
    capsys.readouterr()
    assert main(["evaluate", "--pose", "uniform"]) == 2  # the paper protocol has its own poses
    assert "camera protocol" in capsys.readouterr().err
    assert main(["evaluate", "--views", "3"]) == 2  # the paper protocol's fruit have their own 19 views
    assert main(["evaluate", "--protocol", "camera", "--views", "0"]) == 2
    assert "--views must be 1-100000, and more than 1 only with --protocol camera" in capsys.readouterr().err
    assert main(["evaluate", "--protocol", "camera", "--sensor", "heldback", "--n", "2", "--views", "2", "--methods",
                 "raw", "--output", str(tmp_path), "--jobs", "1", "--fruit", "plum"]) == 0  # fmt: skip
    rows = (tmp_path / "latest" / "instances.csv").read_text().splitlines()
    assert [r.split(",")[3] for r in rows[1:]] == ["0", "0"]  # fruit_index: both views of fruit 0


def test_cli_fruit_profile(tmp_path, capsys):
    import json

    from symfruit.cli import main

    np.save(tmp_path / "a.npy", front_half(sphere_cloud()))
    assert (
        main(["complete", str(tmp_path / "a.npy"), "--fruit", "citrus", "--json", "--output", str(tmp_path / "o.ply")])
        == 0
    )
    capsys.readouterr()
    saved = json.loads((tmp_path / "o.json").read_text())
    assert saved["settings"]["fused"]["depth_ratio"] == 1.1
    assert main(["complete", str(tmp_path / "a.npy"), "--fruit", "banana"]) == 2


def test_odd_path_names(tmp_path, capsys):
    from symfruit.io import write_ply

    odd = Path(os.fsdecode(bytes(tmp_path) + b"/fr\xfcit \xe2\x80\x94 [1].ply"))  # Latin-1 byte: not UTF-8
    write_ply(odd, VISIBLE)
    assert main(["complete", str(odd), "--json"]) == 0
    capsys.readouterr()
    missing = Path(os.fsdecode(bytes(tmp_path) + b"/n\xfcll.ply"))
    assert main(["complete", str(missing)]) == 2
    err = capsys.readouterr().err
    assert "no such file" in err and err.count("\n") == 1


def test_output_folder_that_cannot_be_written(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    np.save(tmp_path / "a.npy", VISIBLE)
    assert main(["complete", str(tmp_path / "a.npy"), "--output", str(blocker / "out.ply")]) == 2
    assert "cannot write to folder" in capsys.readouterr().err
    assert main(["detect", str(EXAMPLE_FRAME), "--output", str(blocker / "out")]) == 2
    assert "cannot write to folder" in capsys.readouterr().err


def test_detect_exits_1_when_a_frame_failed_and_names_it(tmp_path, capsys):
    rec = tmp_path / "rec"
    shutil.copytree(small_frame(), rec / "good")  # one fruit
    shutil.copytree(small_frame(), rec / "bad")
    (rec / "bad" / "color.png").write_bytes(b"broken")
    assert main(["detect", str(rec), "--output", str(tmp_path / "out"), "--method", "raw"]) == 1
    out = capsys.readouterr().out
    assert "frames: 1 done, 0 skipped (resume), 1 failed; fruit: 1 located, 0 failed" in out
    assert "  failed bad: " in out and "color.png" in out and f"results: {tmp_path / 'out'}" in out
    assert main(["detect", str(rec), "--output", str(tmp_path / "out"), "--method", "nope"]) == 2


def test_settings_prints_the_resolved_settings(tmp_path, capsys):
    import yaml

    config = tmp_path / "s.yaml"
    config.write_text("fused:\n  mirror_weight: 0.3\n")
    assert main(["settings", "--fruit", "strawberry", "--config", str(config)]) == 0
    printed = yaml.safe_load(capsys.readouterr().out)
    assert printed["fused"]["revolution"] is True and printed["fused"]["mirror_weight"] == 0.3
    assert list(printed) == list(Settings().to_dict())  # every section, in order


def test_complete_refuses_an_output_folder_and_prints_a_table(tmp_path, capsys):
    np.save(tmp_path / "a.npy", VISIBLE)
    (tmp_path / "taken.ply").mkdir()
    assert main(["complete", str(tmp_path / "a.npy"), "--output", str(tmp_path / "taken.ply")]) == 2
    assert "--output is a folder" in capsys.readouterr().err
    assert main(["complete", str(tmp_path / "a.npy"), "--output", str(tmp_path / "o.ply")]) == 0
    out = capsys.readouterr().out
    for label in ("method", "centre", "size", "box min", "box max", "confidence", "points", "time", "written"):
        assert any(line.startswith(label) for line in out.splitlines()), label
    assert f"written    {tmp_path / 'o.ply'} and {tmp_path / 'o.json'}" in out


def test_complete_names_the_file_of_a_cloud_it_cannot_use(tmp_path, capsys):
    rng = np.random.default_rng(0)
    flat = np.c_[rng.uniform(-0.03, 0.03, (200, 2)), np.full(200, 0.5)]
    np.save(tmp_path / "flat.npy", flat)
    np.save(tmp_path / "behind.npy", VISIBLE * [1.0, 1.0, -1.0])
    assert main(["complete", str(tmp_path / "flat.npy")]) == 2
    assert f"{tmp_path / 'flat.npy'}: all points lie on a plane" in capsys.readouterr().err
    assert main(["complete", str(tmp_path / "behind.npy")]) == 2
    assert f"{tmp_path / 'behind.npy'}: " in capsys.readouterr().err


def test_complete_prints_a_symfruit_warning_as_one_line(tmp_path, capsys):
    np.save(tmp_path / "c.npy", VISIBLE)
    camera = json.loads((EXAMPLES / "camera.json").read_text())
    (tmp_path / "cam.json").write_text(json.dumps(camera | {"coeffs": [0.06, -0.1, 0.001, -0.0008, 0.02]}))
    assert main(["complete", str(tmp_path / "c.npy"), "--camera", str(tmp_path / "cam.json")]) == 0
    err = capsys.readouterr().err
    assert err.startswith(f"symfruit: warning: {tmp_path / 'cam.json'}: non-zero distortion coefficients 'coeffs'")
    assert err.count("\n") == 1 and "SymfruitWarning" not in err


# with the Dask cluster's tests (tests/season/test_cluster.py): the refusal of --workers 0 imports dask.distributed,
# half a second of CPU on a worker that would otherwise never import it (pytest-xdist, --dist loadgroup)
@pytest.mark.xdist_group("cluster")
def test_bench_arguments_are_checked(capsys):
    assert main(["bench", "--repeat", "0"]) == 2
    assert main(["bench", "--points", "5"]) == 2
    assert main(["bench", "--recording", "0"]) == 2
    assert "--recording must be between 1 and 100000 frames" in capsys.readouterr().err
    assert main(["bench", "--segment", "--size", "640"]) == 2
    assert "--size must be WIDTHxHEIGHT, e.g. 1920x1080, got '640'" in capsys.readouterr().err
    assert main(["bench", "--segment", "--size", "0x480"]) == 2  # the image size limits of every reader
    assert "--size" in capsys.readouterr().err
    pytest.importorskip("distributed")
    assert main(["bench", "--recording", "1", "--workers", "0"]) == 2
    assert "--workers must be between 1 and 256, got 0" in capsys.readouterr().err


def test_bench_segment_times_synthetic_photos_or_a_folder_of_them(tmp_path, capsys):
    """The segmenter's timing at a small size (the benchmark's 640x480 runs in `make test-slow`)."""
    from PIL import Image

    assert main(["bench", "--segment", "--size", "96x72"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("symfruit bench --segment: 24 synthetic photos at 96x72, colour alone, one process: median ")
    photos = tmp_path / "photos"
    photos.mkdir()
    for k, size in enumerate([(200, 150), (120, 90)]):
        Image.new("RGB", size, (40, 120, 30)).save(photos / f"p{k}.png")
    assert main(["bench", "--segment", "--images", str(photos), "--size", "64x48", "--json"]) == 0
    row = json.loads(capsys.readouterr().out)["segment"]
    assert row["images"] == 2 and row["source"] == str(photos) and (row["width"], row["height"]) == (64, 48)
    assert 0 < row["median_ms"] <= row["p90_ms"] <= row["max_ms"]


def test_bench_recording_reports_what_its_detect_child_measured(capsys, monkeypatch):
    """One frame through the benchmark's `symfruit detect` run, its peak memory reported. The child is run here as
    the command itself, in this process, with the arguments the benchmark gives it (a real child and its peak
    memory: tests/test_batch.py::test_memory_stays_flat_over_a_recording); the small frame stands in for the
    generated one (rendering it is tested in tests/synthetic)."""
    from symfruit.evaluate import bench
    from symfruit.synthetic import scenes

    def small_recording(folder, n, **kwargs):
        assert n == 1 and kwargs["n_ripe"] == 8  # what the benchmark asks for
        shutil.copytree(small_frame(), folder / "scene_00000")

    ran = []

    def detect_here(args, *, timeout=None):
        status = main(["detect", *args])
        ran.append((args, status, capsys.readouterr().out))
        return status, 123.0, ""

    monkeypatch.setattr(scenes, "write_scenes", small_recording)
    monkeypatch.setattr(bench, "measured_detect", detect_here)
    assert main(["bench", "--recording", "1", "--method", "raw"]) == 0
    out = capsys.readouterr().out
    ((args, status, said),) = ran
    assert status == 0 and args[-2:] == ["--method", "raw"] and "frames: 1 done" in said
    assert out.startswith("symfruit bench --recording: 1 frames (1 written), method raw: ")
    assert float(out.split("peak RSS ")[1].split(" MB")[0]) == 123.0


def test_no_command_prints_help(capsys):
    assert main([]) == 2
    assert "usage: symfruit" in capsys.readouterr().out


def test_inputs_claiming_huge_sizes_fail_cleanly_inside_a_memory_limit(tmp_path):
    """Each file claims gigabytes; in a child capped at 2 GB of address space every one must end in a
    one-line error with status 2, never a MemoryError or a kill: the sizes are checked before allocating."""
    import resource
    import struct
    import subprocess
    import sys

    files = {}
    pcd = tmp_path / "big.pcd"
    head = b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 4000000\nHEIGHT 1\nPOINTS 4000000\n"
    pcd.write_bytes(head + b"DATA binary_compressed\n" + struct.pack("<II", 64, 48_000_000) + b"\0" * 64)
    files[pcd] = "binary_compressed sizes do not match"
    ply = tmp_path / "big.ply"
    ply.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    b"property float z\nelement face 4000000000\nproperty list uchar int vertex_indices\nend_header\n"
                    + bytes(36))  # fmt: skip
    files[ply] = "4000000000 face rows"
    npy = tmp_path / "big.npy"
    with npy.open("wb") as handle:
        np.lib.format.write_array_header_1_0(
            handle, {"descr": "<f8", "fortran_order": False, "shape": (100000, 100000)}
        )
    files[npy] = "header promises"
    cam = tmp_path / "cam.json"
    cam.write_text('{"fx": 615, "fy": 615, "cx": 320, "cy": 240, "width": 100000, "height": 100000}')
    sample = str(EXAMPLES / "strawberry_partial.ply")

    def cap() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))

    runs = [[str(path)] for path in files] + [[sample, "--camera", str(cam)]]
    messages = [*files.values(), "width is 100000 pixels"]
    # one child runs the command once per file (a child per file cost a second each of start-up): its status
    # and what it wrote to stderr, each run's on one JSON line
    child = (
        "import contextlib, io, json, sys\nfrom symfruit.cli import main\nfor args in json.loads(sys.argv[1]):\n"
        "    err = io.StringIO()\n    with contextlib.redirect_stderr(err):\n"
        "        status = main(['complete', *args])\n    print(json.dumps([status, err.getvalue()]), flush=True)\n"
    )
    proc = subprocess.run([sys.executable, "-c", child, json.dumps(runs)], capture_output=True, text=True,
                          preexec_fn=cap, timeout=120)  # fmt: skip
    assert proc.returncode == 0 and not proc.stderr, proc.stderr
    results = [json.loads(line) for line in proc.stdout.splitlines()]
    assert len(results) == len(runs)
    for (status, err), message in zip(results, messages, strict=True):
        assert status == 2 and err.count("\n") == 1, err
        assert err.startswith("symfruit: error: ") and message in err


def _one_line_error(capsys, *needles):
    err = capsys.readouterr().err
    assert err.startswith("symfruit: error: ") and err.count("\n") == 1 and "Traceback" not in err, err
    assert all(n in err for n in needles), err


def test_complete_json_to_an_output_whose_json_is_a_folder_is_one_line(tmp_path, capsys):
    np.save(tmp_path / "a.npy", VISIBLE)
    (tmp_path / "o.json").mkdir()
    assert main(["complete", str(tmp_path / "a.npy"), "--json", "--output", str(tmp_path / "o.ply")]) == 2
    _one_line_error(capsys, "o.json: is a folder")
    assert not (tmp_path / "o.ply").exists()  # neither half of the result is written
    (tmp_path / "d.ply").mkdir()
    assert main(["complete", str(tmp_path / "d.ply"), "--json"]) == 2
    _one_line_error(capsys, "not a regular file")


def test_an_unwritable_output_is_exit_2_for_every_writing_command(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    photo = tmp_path / "p.png"
    from PIL import Image

    Image.new("RGB", (32, 24), (200, 30, 40)).save(photo)
    for args in (["detect", str(EXAMPLE_FRAME), "--output", str(blocker)],
                 ["segment", str(photo), "--output", str(blocker / "o")],
                 ["demo", "--output", str(blocker)], ["scenes", str(blocker), "--n", "1"]):  # fmt: skip
        assert main(args) == 2, args
        _one_line_error(capsys, "cannot write to folder")


def test_a_second_writer_on_one_output_folder_is_exit_2(tmp_path, capsys):
    from symfruit.io.outputs import OutputFolder

    with OutputFolder(tmp_path / "out"):
        for args in (["detect", str(EXAMPLE_FRAME), "--output", str(tmp_path / "out"), "--method", "raw"],
                     ["demo", "--output", str(tmp_path / "out"), "--method", "raw"],
                     ["scenes", str(tmp_path / "out"), "--n", "1"]):  # fmt: skip
            assert main(args) == 2, args
            _one_line_error(capsys, "another symfruit run", "is writing into this output folder")
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == []


def test_detect_refuses_writing_into_its_input_and_names_a_linked_frame(tmp_path, capsys):
    rec = tmp_path / "rec"
    shutil.copytree(small_frame(), rec / "f1")
    assert main(["detect", str(rec), "--output", str(rec), "--method", "raw"]) == 2
    _one_line_error(capsys, "also an input folder")
    (tmp_path / "out").mkdir()
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "out" / "f1").symlink_to(tmp_path / "elsewhere")
    assert main(["detect", str(rec), "--output", str(tmp_path / "out"), "--method", "raw"]) == 1
    assert "f1: is a symbolic link" in capsys.readouterr().out and not list((tmp_path / "elsewhere").iterdir())


def test_evaluate_masks_with_a_category_no_annotation_has_is_exit_2(tmp_path, capsys):
    photos = EXAMPLES / "photos"
    truth = str(photos / "_annotations.coco.json")
    args = ["evaluate", "--protocol", "masks", "--images", str(photos), "--truth", truth, "--category", "77"]
    assert main([*args, "--output", str(tmp_path)]) == 2
    _one_line_error(capsys, "no annotation has category 77")


@pytest.mark.parametrize("protocol", ["paper", "camera", "masks"])
def test_evaluate_refuses_a_results_root_that_is_a_file_before_it_evaluates(tmp_path, capsys, monkeypatch, protocol):
    import symfruit.evaluate

    def no_work(**kwargs):
        raise AssertionError("evaluated before the results root was checked")

    monkeypatch.setattr(symfruit.evaluate, "evaluate", no_work)
    (tmp_path / "results").write_text("")
    quick = ["--quick"] if protocol != "masks" else []  # (--protocol masks has no --quick)
    assert main(["evaluate", "--protocol", protocol, *quick, "--output", str(tmp_path / "results")]) == 2
    _one_line_error(capsys, "results: cannot create a results folder (the results root is a file)")


def test_a_frame_folder_named_with_bytes_that_are_not_utf8_is_run_and_reported(tmp_path, capsys):
    rec = tmp_path / "rec"
    shutil.copytree(EXAMPLE_FRAME, rec / "good")
    bad = rec / os.fsdecode(b"bad\xff")
    bad.mkdir()
    (bad / "color.png").write_bytes(b"")  # fails: its name is printed and written into the tables
    assert main(["detect", str(rec), "--output", str(tmp_path / "out"), "--method", "raw"]) == 1
    out = capsys.readouterr().out  # pytest's capture is strict UTF-8, as a terminal in a UTF-8 locale is
    assert "failed bad\\udcff: " in out and "frames: 1 done" in out
    assert (tmp_path / "out" / "frames.parquet").is_file()


@pytest.mark.parametrize(
    "args",
    [["detect", "", "--output", "out"], ["detect", "rec", "--output", ""], ["segment", "a.png", "--output", ""],
     ["scenes", ""], ["evaluate", "--quick", "--output", ""], ["complete", "a.ply", "--config", " "]],
)  # fmt: skip
def test_an_empty_path_is_refused_not_read_as_the_working_folder(tmp_path, capsys, monkeypatch, args):
    monkeypatch.chdir(tmp_path)  # `--output "$OUT"` with OUT unset would write here
    with pytest.raises(SystemExit) as stop:
        main(args)
    assert stop.value.code == 2 and "an empty path (an unset shell variable?)" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_settings_and_bench_refuse_bad_input_in_one_line(tmp_path, capsys):
    (tmp_path / "big.yaml").write_text("a: [" + "1, " * 400_000 + "1]\n")
    assert main(["settings", "--config", str(tmp_path / "big.yaml")]) == 2
    _one_line_error(capsys, "larger than")
    assert main(["bench", "--points", "3"]) == 2
    _one_line_error(capsys, "--points")


def test_a_ros2_bag_written_inside_the_recording_is_no_failed_frame(tmp_path, capsys):
    pytest.importorskip("rosbags")
    rec = tmp_path / "rec"
    shutil.copytree(small_frame(), rec / "f1")
    args = ["detect", str(rec), "--output", str(tmp_path / "out"), "--method", "raw", "--ros2-bag", str(rec / "bag")]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "frames: 1 done, 0 skipped (resume), 0 failed" in out and (rec / "bag" / "metadata.yaml").is_file()
    assert main(["detect", str(rec), "--output", str(tmp_path / "o2"), "--method", "raw"]) == 0  # a later run too
    assert "frames: 1 done, 0 skipped (resume), 0 failed" in capsys.readouterr().out


def test_the_cli_names_every_real_camera_model():
    from symfruit.cli import REAL_SENSORS
    from symfruit.synthetic.sensors import SENSOR_MODELS

    assert REAL_SENSORS == tuple(SENSOR_MODELS)


def test_scenes_of_an_apple_tree_go_through_the_azure_kinect_by_default(tmp_path, capsys, monkeypatch):
    """The arguments alone (rendering a 1920x1080 canopy is tested in tests/synthetic)."""
    from symfruit.synthetic import scenes

    calls, kept, looks = [], [], []

    def fake(folder, n, **kwargs):
        sensor = kwargs["sensor"]
        calls.append((n, kwargs["seed"], kwargs["n_ripe"], kwargs["n_unripe"], sensor and sensor.name, kwargs["tree"]))
        kept.append(sensor)
        looks.append(kwargs.get("photometric", "default"))
        return [folder / f"scene_{i:05d}" for i in range(n)]

    monkeypatch.setattr(scenes, "write_scenes", fake)
    assert main(["scenes", str(tmp_path / "t"), "--scene", "apple-tree", "--n", "2", "--seed", "6"]) == 0
    assert main(["scenes", str(tmp_path / "u"), "--scene", "apple-tree", "--n", "1", "--ripe", "3",
                 "--sensor", "realsense-l515"]) == 0  # fmt: skip
    assert main(["scenes", str(tmp_path / "v"), "--n", "1"]) == 0
    assert main(["scenes", str(tmp_path / "x"), "--scene", "apple-tree", "--n", "1", "--sensor-set",
                 "rim_invalid_px=3"]) == 0  # fmt: skip
    assert calls == [
        (2, 6, 30, 4, "azure-kinect", True),
        (1, 0, 3, 4, "realsense-l515", True),
        (1, 0, 6, 2, None, False),
        (1, 0, 30, 4, "azure-kinect", True),
    ]
    assert kept[-1].rim_invalid_px == 3 and kept[0].rim_invalid_px == 1
    assert looks == ["default"] * 4  # the colour camera's effects unless asked otherwise
    assert main(["scenes", str(tmp_path / "y"), "--scene", "apple-tree", "--n", "1", "--plain-colour"]) == 0
    assert looks[-1] is None  # the frames of stops 30-44
    out = capsys.readouterr().out
    assert main(["scenes", str(tmp_path / "z"), "--n", "1", "--plain-colour"]) == 2
    assert "--plain-colour is for --scene apple-tree" in capsys.readouterr().err
    assert "wrote 2 apple-tree frames to" in out and "(seeds 6-7, azure-kinect at 1920x1080 with masks.png)" in out
    with pytest.raises(SystemExit):
        main(["scenes", str(tmp_path / "w"), "--scene", "pear-tree"])


@pytest.mark.slow
def test_scenes_through_a_real_camera_then_table_3_on_them(tmp_path, capsys):
    out = tmp_path / "frames"
    assert main(["scenes", str(out), "--n", "1", "--ripe", "2", "--unripe", "0", "--sensor", "realsense-d405"]) == 0
    assert "realsense-d405 at 1280x720 with masks.png" in capsys.readouterr().out
    assert (out / "scene_00000" / "masks.png").is_file()
    code = main(["evaluate", "--frames", str(out), "--methods", "raw,evidence", "--output", str(tmp_path / "r")])
    assert code == 0
    assert "2 true fruit" in capsys.readouterr().out


# with the tests that draw plots (tests/evaluate, tests/season/test_report.py): its `symfruit report` imports
# matplotlib, half a second of CPU on a worker that would otherwise never import it (pytest-xdist, --dist loadgroup)
@pytest.mark.xdist_group("evaluate")
def test_detect_takes_several_recordings(tmp_path, capsys):
    for parent in ("a", "b"):
        shutil.copytree(small_frame(), tmp_path / parent / "frames" / "f1")  # one fruit each
    shutil.copytree(small_frame(), tmp_path / "row2" / "f1")
    out = tmp_path / "out"
    inputs = [str(tmp_path / "a" / "frames"), str(tmp_path / "b" / "frames"), str(tmp_path / "row2")]
    assert main(["detect", *inputs, "--output", str(out), "--method", "raw"]) == 0
    text, err = capsys.readouterr()
    assert "frames: 3 done, 0 skipped (resume), 0 failed; fruit: 3 located, 0 failed" in text
    assert "detect: 3/3" in err and "/1 " not in err  # one progress bar over every recording's frames
    assert text.count(" (its name is shared or not a plain file name)") == 2 and f"-> {out / 'frames+'}" in text
    assert "one folder per recording, in it one per frame" in text
    assert (out / "row2" / "f1" / "detections.json").is_file()
    (tmp_path / "empty").mkdir()
    assert main(["detect", str(tmp_path / "row2"), str(tmp_path / "empty"), "--output", str(tmp_path / "o2"),
                 "--method", "raw"]) == 1  # fmt: skip
    assert f"recording not read {tmp_path / 'empty'}: " in capsys.readouterr().out
    assert main(["detect", str(tmp_path / "row2"), str(out / "row2"), "--output", str(out)]) == 2
    assert "lies inside the output folder" in capsys.readouterr().err
    assert main(["detect", *inputs[1:], "--output", str(tmp_path / "o3"), "--ros2-bag", str(tmp_path / "bag")]) == 2
    assert "give one input with it" in capsys.readouterr().err and not (tmp_path / "bag").exists()
    pytest.importorskip("matplotlib")
    assert main(["report", str(out)]) == 0
    assert "report: 3 recording(s), 3 frames, 3 fruit seen" in capsys.readouterr().out
    report = (out / "report" / "report.md").read_text()
    assert "| row2 | 1 | 1 | 1 | 1 | 1.00 | 1 |" in report and f"- `row2`: `{inputs[2]}`" in report
    assert report.count("- `frames+") == 2 and f"`: `{inputs[0]}`" in report
    for name in ("fruit_per_frame_by_recording.png", "diameters_by_recording.png"):
        assert f"]({name})" in report and (out / "report" / name).is_file()


def _red_photo(tmp_path):
    """A 32x24 photograph with one red fruit and its labels; the folders photos/ and labels/ made."""
    (tmp_path / "photos").mkdir()
    (tmp_path / "labels").mkdir()
    color = np.zeros((24, 32, 3), np.uint8)
    color[6:14, 2:12] = (200, 20, 20)
    labels = np.zeros((24, 32), np.uint8)
    labels[6:14, 2:12] = 1
    return color, labels


def test_evaluate_masks_reads_label_pngs_by_name_and_checks_their_orientation_and_size(tmp_path, capsys):
    from PIL import Image

    color, labels = _red_photo(tmp_path)
    Image.fromarray(color).save(tmp_path / "photos" / "p0.png")
    Image.fromarray(labels).save(tmp_path / "labels" / "p0.png")
    box = [[2, 6, 11, 6, 11, 13, 2, 13]]
    coco = {"images": [{"id": 1, "file_name": "p0.png", "height": 24, "width": 32}],
            "annotations": [{"id": 1, "image_id": 1, "category_id": 1, "segmentation": box}]}  # fmt: skip
    (tmp_path / "t.json").write_text(json.dumps(coco))
    photos, truth, found = str(tmp_path / "photos"), str(tmp_path / "t.json"), str(tmp_path / "labels")
    args = ["evaluate", "--protocol", "masks", "--images", photos, "--truth", truth, "--masks", found,
            "--output", str(tmp_path / "res")]  # fmt: skip
    assert main(args) == 0  # found by the photograph's name (before: "labels/.png: no label image for")
    assert "1 true fruit, 1 found" in capsys.readouterr().out
    turned = Image.fromarray(color)
    exif = turned.getexif()
    exif[0x0112] = 3  # half a turn: the sizes agree, the pixels do not
    turned.save(tmp_path / "photos" / "p0.png", exif=exif)
    assert main(args) == 2
    _one_line_error(capsys, "photos/p0.png: its EXIF orientation 3 (turned half around)", "but p0.png has 1")
    Image.fromarray(color).save(tmp_path / "photos" / "p0.png")
    Image.fromarray(labels[:, :30]).save(tmp_path / "labels" / "p0.png")
    assert main(args) == 2
    _one_line_error(capsys, "labels/p0.png: labels are 30x24, the image 32x24")


def test_evaluate_masks_goes_on_past_a_bad_photograph_and_names_it(tmp_path, capsys):
    from PIL import Image

    color, labels = _red_photo(tmp_path)
    for name in ("p0", "p1"):
        Image.fromarray(color).save(tmp_path / "photos" / f"{name}.png")
    Image.fromarray(labels).save(tmp_path / "labels" / "p0.png")
    Image.fromarray(labels[:, :30]).save(tmp_path / "labels" / "p1.png")  # not the photograph's size
    (tmp_path / "photos" / "p2.png").write_bytes(b"not a png")
    box = [[2, 6, 11, 6, 11, 13, 2, 13]]
    coco = {
        "images": [{"id": k, "file_name": f"p{k}.png"} for k in range(3)],
        "annotations": [{"id": k + 1, "image_id": k, "category_id": 1, "segmentation": box} for k in range(3)],
    }
    (tmp_path / "t.json").write_text(json.dumps(coco))
    photos, truth, found = str(tmp_path / "photos"), str(tmp_path / "t.json"), str(tmp_path / "labels")
    args = ["evaluate", "--protocol", "masks", "--images", photos, "--truth", truth, "--masks", found,
            "--output", str(tmp_path / "res")]  # fmt: skip
    assert main(args) == 1  # before: exit 2 at p1.png, nothing scored
    out = capsys.readouterr().out
    assert "1 images (2 skipped, below), 1 true fruit, 1 found" in out
    assert "skipped p1.png: " in out and "labels/p1.png: labels are 30x24, the image 32x24" in out
    assert "skipped p2.png: " in out and "photos/p2.png" in out
    summary = json.loads(next((tmp_path / "res").glob("*/summary.json")).read_text())
    assert sorted(summary["failed"]) == ["p1.png", "p2.png"] and summary["summary"]["skipped_images"] == 2


@pytest.mark.parametrize(
    "args, message",
    [(["bench", "--workers", "2"], "bench --workers is for --recording; here it would be ignored"),
     (["bench", "--frame", "--recording", "3"], "--recording and --frame are two kinds of bench; give one"),
     (["bench", "--sensor", "azure-kinect"], "bench --sensor is for --frame"),
     (["bench", "--segment", "--method", "raw"], "bench --method is for --frame or --recording"),
     (["bench", "--recording", "2", "--repeat", "3"], "bench --repeat is for the cloud bench"),
     (["bench", "--frame", "--points", "100"], "bench --points is for the cloud bench"),
     (["bench", "--images", "x"], "bench --images is for --segment"),
     (["bench", "--frame", "--profile", "--stages"], "--profile and --stages do not go together"),
     (["bench", "--frame", "--profile", "--json"], "--profile and --json do not go together"),
     (["bench", "--segment", "--scene", "apple-tree", "--size", "64x48"], "--scene and --size do not go together"),
     (["evaluate", "--match", "id"], "evaluate --match is for --frames"),
     (["evaluate", "--frames", "x", "--spheres", "y"], "--frames and --spheres are two evaluations"),
     (["evaluate", "--frames", "x", "--protocol", "masks"], "--frames and --protocol masks are two evaluations"),
     (["evaluate", "--truth", "t.json"], "evaluate --truth is for --protocol masks"),
     (["evaluate", "--masks", "color"], "evaluate --masks is for --frames, --spheres or --protocol masks"),
     (["evaluate", "--protocol", "masks", "--category", "2"], "--category is for --protocol masks with --images"),
     (["evaluate", "--protocol", "masks", "--images", "a", "--truth", "b", "--no-depth"], "--no-depth is for"),
     (["evaluate", "--protocol", "masks", "--images", "a", "--truth", "b", "--n", "3"], "evaluate --n is for the"),
     (["evaluate", "--protocol", "masks", "--images", "a", "--truth", "b", "--seed", "3"], "--seed is for the paper"),
     (["evaluate", "--frames", "f", "--n", "3"], "--n is for the paper and camera protocols and --protocol masks"),
     (["evaluate", "--protocol", "masks", "--methods", "raw"], "evaluate --methods is for --frames, --spheres and"),
     (["evaluate", "--protocol", "masks", "--quick"], "evaluate --quick is for the paper and camera protocols"),
     (["evaluate", "--spheres", "s", "--jobs", "2"], "evaluate --jobs is for the paper and camera protocols"),
     (["evaluate", "--frames", "f", "--pose", "upright"], "evaluate --pose is for the paper and camera protocols"),
     (["evaluate", "--occlusion", "0.25"], "evaluate --occlusion is for --protocol camera"),
     (["evaluate", "--protocol", "paper", "--sensor", "heldback"], "evaluate --sensor is for --protocol camera"),
     (["evaluate", "--frames", "f", "--views", "3"], "evaluate --views is for --protocol camera"),
     (["evaluate", "--protocol", "camera", "--sensor-set", "fatten_px=4"], "evaluate --sensor-set is for --protocol "
      "camera with a real camera model"),
     (["evaluate", "--protocol", "camera", "--sensor", "azure-kinect", "--sensor-set", "rim_invalid_px=11"],
      "--sensor-set rim_invalid_px=11: must be a whole number 0 to 10"),
     (["scenes", "o", "--sensor-set", "fatten_px=4"], "scenes --sensor-set changes a real camera model: give"),
     (["evaluate", "--spheres", "s", "--no-profile"], "evaluate --no-profile is for the protocols and --frames"),
     (["evaluate", "--spheres", "s", "--fruit", "apple"], "evaluate --fruit is for the protocols and --frames"),
     (["evaluate", "--frames", "f", "--fruit", "apple,pear"], "--fruit 'apple,pear': give one fruit kind"),
     (["evaluate", "--frames", "f", "--fruit", "all"], "--fruit 'all': give one fruit kind"),
     (["segment", "a.png", "--output", "o", "--camera", "c.json"], "segment --camera is for --depth; here it would"),
     (["segment", "a.png", "--output", "o", "--depth-scale", "0.0001"], "segment --depth-scale is for --depth"),
     (["segment", "a.png", "--output", "o", "--depth", "d.png", "--camera", "c.json", "--masks", "labels"],
      "segment --depth is for --masks color (the colour segmenter; --masks labels does not use depth)"),
     (["detect", "rec", "--output", "o", "--ros2-storage", "sqlite3"], "--ros2-storage (the storage of --ros2-bag) is"),
     (["detect", "rec", "--output", "o", "--ros2-bag", "o"], "--ros2-bag o holds --output o: the bag's files and"),
     (["detect", "rec", "--output", "b/o", "--ros2-bag", "b"], "--ros2-bag b holds --output b/o"),
     (["detect", "rec", "--output", "o", "--fruit-processes", "17"], "--fruit-processes must be a whole number from 0 "
      "to 16, got 17"),
     (["detect", "rec", "--output", "o", "--fruit-processes", "-1"], "--fruit-processes must be a whole number"),
     (["detect", "rec", "--output", "o", "--fruit-processes", "1", "--workers", "2"], "--fruit-processes shares each "
      "frame's fruit with processes of this one: a Dask cluster's workers (--scheduler, --workers) are one of"),
     (["bench", "--fruit-processes", "1"], "bench --fruit-processes is for --frame or --recording; here it would "
      "be ignored"),
     (["bench", "--stream", "5"], "bench --stream is for --frame; here it would be ignored"),
     (["bench", "--frame", "--stream", "5", "--stages"], "--stream and --stages do not go"),
     (["bench", "--recording", "3", "--workers", "2", "--fruit-processes", "1"], "--fruit-processes shares each "
      "frame's fruit in one process; --workers runs"),
     (["bench", "--frame", "--fruit-processes", "17"], "--fruit-processes must be a whole number from 0 to 16"),
     (["bench", "--frame", "--profile", "--fruit-processes", "1"], "--profile and --fruit-processes do not go")],
)  # fmt: skip
def test_options_the_chosen_run_would_ignore_are_refused(tmp_path, capsys, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)  # before: run without them (bench --workers 2: the cloud bench, one process)
    assert main([*args, "--output", "res"] if args[0] == "evaluate" else args) == 2
    _one_line_error(capsys, message)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("extra, profile", [([], True), (["--no-profile"], False)])
def test_evaluate_frames_honours_no_profile(tmp_path, capsys, monkeypatch, extra, profile):
    import symfruit.evaluate.frames as frames
    from symfruit.settings import resolve_settings

    seen = []

    def fake(folder, methods, masks, settings, by_id):
        seen.append(settings)
        return {}, {}, {}

    monkeypatch.setattr(frames, "evaluate_frames", fake)
    monkeypatch.setattr(frames, "table3", lambda *a: "table")
    monkeypatch.setattr(frames, "summary_dict", lambda *a: {})
    main(["evaluate", "--frames", str(tmp_path), "--fruit", "apple", *extra, "--output", str(tmp_path / "r")])
    # before: --no-profile was accepted and the apple profile used all the same
    assert (seen[0].to_dict() == resolve_settings(fruit="apple").to_dict()) is profile
    assert (seen[0].to_dict() == resolve_settings().to_dict()) is not profile


def test_evaluate_goes_on_past_a_bad_scan_names_it_and_exits_1(tmp_path, capsys):
    from symfruit.io import write_ply

    scans = tmp_path / "scans"
    write_ply(scans / "a.ply", sphere_cloud())
    (scans / "b.xyz").write_text("1 2\n")  # not x y z
    args = ["evaluate", "--fruit", str(scans), "--methods", "raw", "--n", "1", "--quick", "--jobs", "1"]
    assert main([*args, "--output", str(tmp_path / "r")]) == 1  # before: 2, the whole evaluation refused
    out = capsys.readouterr().out
    assert "## paper protocol: a\n\n7 instances." in out and "protocol: b" not in out  # a's 7 --quick poses
    assert f"skipped {scans / 'b.xyz'}: {scans / 'b.xyz'}" in out


@pytest.mark.parametrize("extra, profile", [([], True), (["--no-profile"], False)])
def test_evaluate_masks_honours_no_profile(tmp_path, monkeypatch, extra, profile):
    import symfruit.segment as segment
    from symfruit.settings import resolve_settings

    seen = []

    class Seen(Exception):
        pass

    def fake(spec, settings=None, **kwargs):
        seen.append(settings)
        raise Seen  # the segmenter's settings are all this test needs: no scene is rendered

    monkeypatch.setattr(segment, "mask_source", fake)
    with pytest.raises(Seen):
        main(["evaluate", "--protocol", "masks", "--n", "1", *extra, "--output", str(tmp_path / "r")])
    assert (seen[0].to_dict() == resolve_settings(fruit="strawberry").to_dict()) is profile
    assert (seen[0].to_dict() == resolve_settings().to_dict()) is not profile


@pytest.mark.parametrize("target", ["cloud", "camera", "config", "link"])
def test_complete_never_writes_its_result_over_an_input(tmp_path, capsys, target):
    from symfruit.core.camera import DEFAULT_CAMERA
    from symfruit.io.clouds import write_ply

    write_ply(tmp_path / "a.ply", VISIBLE)
    (tmp_path / "cam.json").write_text(json.dumps(DEFAULT_CAMERA.to_dict()))
    (tmp_path / "s.json").write_text('{"fused": {"mirror_weight": 0.3}}')
    (tmp_path / "link.ply").symlink_to(tmp_path / "a.ply")
    output = {"cloud": "a.ply", "camera": "cam.ply", "config": "s.ply", "link": "link.ply"}[target]
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    args = ["complete", str(tmp_path / "a.ply"), "--camera", str(tmp_path / "cam.json"), "--config",
            str(tmp_path / "s.json"), "--output", str(tmp_path / output)]  # fmt: skip
    assert main(args) == 2  # before: exit 0, the cloud (or the intrinsics, the settings) written over
    _one_line_error(capsys, "is an input of this run", "choose another output name")
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()} == before


@pytest.mark.parametrize(
    "stated, given, used",
    [({"depth_scale": 0.0001}, None, 0.0001), ({"depth_units": "cm"}, None, 0.01), ({}, None, 0.001),
     ({}, "0.0002", 0.0002), ({"depth_units": "mm"}, "0.001", 0.001), ({"depth_scale": 0.0001}, "0.001", None)],
)  # fmt: skip
def test_segment_reads_depth_by_the_camera_files_depth_scale(tmp_path, capsys, monkeypatch, stated, given, used):
    import symfruit.batch
    from symfruit.core.camera import DEFAULT_CAMERA

    seen = []

    class Report:
        done, failed, fruit, stopped, ok, mask_source = [], {}, 0, None, True, "colour segmenter"

    monkeypatch.setattr(symfruit.batch, "segment_images", lambda *a, **k: seen.append(k["depth_scale"]) or Report)
    (tmp_path / "cam.json").write_text(json.dumps({**DEFAULT_CAMERA.to_dict(), **stated}))
    args = [
        "segment",
        "a.png",
        "--output",
        str(tmp_path / "o"),
        "--depth",
        "d.png",
        "--camera",
        str(tmp_path / "cam.json"),
    ]
    code = main([*args, *(["--depth-scale", given] if given else [])])
    if used is None:  # two depth scales that disagree: which one is meant?
        assert code == 2 and not seen
        _one_line_error(capsys, "segment --depth-scale 0.001 and", "cam.json's depth scale 0.0001 disagree")
    else:  # before: the camera file's depth_scale ignored, 0.001 used whatever it said
        assert code == 0 and seen == [used]
    capsys.readouterr()
    for bad in ("nan", "-1", "0", "2"):  # named as no depth scale, not as one disagreeing with the file's (was)
        assert main([*args, "--depth-scale", bad]) == 2 and len(seen) == (used is not None)
        _one_line_error(capsys, "segment --depth-scale must be metres per unit in (0, 1], got", bad)


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--methods", "", "--methods '' names nothing"),  # before: an evaluation of no method, exit 0
        ("--methods", ",,", "--methods ',,' names nothing"),
        ("--fruit", ",", "--fruit ',' names nothing"),  # before: an evaluation of no fruit, exit 0
        ("--fruit", "", "--fruit '' names nothing"),  # before: taken as the default, strawberry
        ("--methods", "raw,raw", "--methods names 'raw' twice"),
        ("--methods", "raw,,paper", "--methods 'raw,,paper': an empty entry"),  # before: raw and paper, unsaid
        ("--fruit", "strawberry,", "--fruit 'strawberry,': an empty entry"),  # before: strawberry, unsaid
    ],
)
def test_evaluate_refuses_an_option_naming_no_fruit_or_method_or_one_twice(tmp_path, capsys, option, value, message):
    assert main(["evaluate", "--quick", option, value, "--output", str(tmp_path / "r")]) == 2
    _one_line_error(capsys, message)
    assert not (tmp_path / "r").exists()


def test_evaluate_refuses_an_occlusion_level_given_twice(tmp_path, capsys):
    args = ["evaluate", "--quick", "--protocol", "camera", "--output", str(tmp_path / "r"), "--occlusion"]
    assert main([*args, "0,0.5,0.50"]) == 2  # before: the level's views run twice, its row of twice as many
    _one_line_error(capsys, "--occlusion names the level 0.5 twice")
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize("command", [["complete", "cloud.ply"], ["detect", "rec", "--output", "out"], ["demo"]])
def test_an_empty_method_is_refused_not_read_as_the_default(tmp_path, monkeypatch, capsys, command):
    monkeypatch.chdir(tmp_path)
    assert main([*command, "--method", ""]) == 2  # before: the default method ran, exit 0
    assert "unknown method ''" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("classes", "what"),
    [
        ("18,,25", "an empty entry"),  # before: read as 18,25 in silence
        ("18,25,", "an empty entry"),
        ("١٨,25", "'١٨' is no number"),  # before: Arabic-Indic digits read as 18
        ("1_8,25", "'1_8' is no number"),  # before: read as 18
        ("nan", "'nan' is no number"),
    ],
)
def test_report_classes_refuse_an_empty_entry_or_what_is_no_plain_number(tmp_path, capsys, classes, what):
    assert main(["report", str(tmp_path / "run"), f"--classes={classes}"]) == 2
    assert f"--classes {classes!r}: {what}; expected diameters in mm" in capsys.readouterr().err
    assert main(["report", str(tmp_path / "run"), "--classes", " 18, 2.5e1 "]) == 2  # read: on to the missing run
    assert "run: no such folder" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("value", "what"),
    [("0,٠.٥", "'٠.٥' is no number"), ("0,0.5_0", "'0.5_0' is no number"), ("0,,0.5", "an empty entry")],
)
def test_evaluate_occlusion_levels_are_plain_numbers(tmp_path, capsys, value, what):
    # before: Arabic-Indic digits and 0.5_0 were read as 0.5 by float(); an empty entry was 'expected numbers'
    assert main(["evaluate", "--protocol", "camera", "--occlusion", value, "--output", str(tmp_path / "r")]) == 2
    _one_line_error(capsys, f"--occlusion {value!r}: {what}; expected numbers such as 0,0.25,0.5")
    assert not (tmp_path / "r").exists()


def test_a_failed_frame_named_with_a_line_break_is_one_printed_line(tmp_path, capsys):
    rec = tmp_path / "rec"
    shutil.copytree(small_frame(), rec / "x\n  failed y")  # a folder name is any bytes but / and NUL
    (rec / "x\n  failed y" / "depth.png").write_bytes(b"broken")
    shutil.copytree(small_frame(), rec / "ok\r\nz")
    assert main(["detect", str(rec), "--output", str(tmp_path / "out"), "--method", "raw"]) == 1
    out = capsys.readouterr().out.splitlines()
    # before: "  failed x", "  failed y: .../x", "  failed y/depth.png: ...": one failure read as three
    assert [line for line in out if line.startswith("  failed")] == [
        f"  failed x\\n  failed y: {rec}/x\\n  failed y/depth.png: cannot read image (not of an image format Pillow "
        "reads, PNG, JPEG, TIFF, ...; or its header is damaged)"
    ]


def test_a_name_too_long_for_the_system_is_one_short_line_not_a_traceback(tmp_path, capsys):
    """Stop 49 (robust49): a path of 5,000 characters (or a name part over 255 bytes) was pathlib's OSError
    `[Errno 36] File name too long` out of `main` for detect, complete, segment, evaluate --frames, settings
    --fruit and --masks; a refusal naming such a path was a line of 5,000 characters."""
    long = "x" * 5000
    frame = small_frame()
    for argv in (
        ["detect", long, "--output", tmp_path / "o"],
        ["detect", frame, "--output", tmp_path / long],
        ["complete", f"{long}.ply"],
        ["segment", f"{long}.png", "--output", tmp_path / "o"],
        ["evaluate", "--frames", long, "--output", tmp_path / "o"],
        ["complete", EXAMPLES / "strawberry_partial.ply", "--output", f"{long}.ply"],
        ["complete", EXAMPLES / "strawberry_partial.ply", "--camera", f"{long}.json"],
        ["settings", "--fruit", long],
        ["detect", frame, "--output", tmp_path / "o", "--masks", f"{long}.png"],
    ):
        assert main([str(a) for a in argv]) == 2, argv
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and len(err[0]) < 300 and "Errno" not in err[0], err
        assert re.search(r"\.\.\.x+(\.[a-z]+)?'? \(5,\d{3} characters\)", err[0]), err
    assert main(["settings", "--fruit", long]) == 2
    assert "no fruit profile 'xxxx" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (["scenes", "OUT", "--n", "٣"], "argument --n: '٣' is not a whole number (ASCII digits 0-9)"),
        (["scenes", "OUT", "--seed", "３"], "argument --seed: '３' is not a whole number (ASCII digits 0-9)"),
        (["scenes", "OUT", "--n", "1_0"], "argument --n: '1_0' is not a whole number (ASCII digits 0-9)"),
        (["scenes", "OUT", "--n", "3.0"], "argument --n: '3.0' is not a whole number (ASCII digits 0-9)"),
        (["detect", "IN", "--output", "OUT", "--workers", "٢"], "argument --workers: '٢' is not a whole number"),
        (["bench", "--segment", "--size", "٣٢٠x٢٤٠"], "--size must be WIDTHxHEIGHT, e.g. 1920x1080, got '٣٢٠x٢٤٠'"),
        (["detect", "IN", "--output", "OUT", "--workers", "1", "--no-worker-timeout", "٣٠"],
         "argument --no-worker-timeout: '٣٠' is not a number (ASCII digits 0-9, e.g. 0.5 or 1e-3)"),
        (["detect", "IN", "--output", "OUT", "--workers", "1", "--no-worker-timeout", "3_0"],
         "argument --no-worker-timeout: '3_0' is not a number"),
    ],
)  # fmt: skip
def test_a_number_option_of_other_digits_than_ascii_is_refused_not_read(tmp_path, capsys, argv, said):
    """Stop 56 (robust56): Python's int() and float() read Arabic-Indic ('٣'), full-width ('３') digits and '1_0'
    as their values, so `--n ٣` made 3 frames and `--no-worker-timeout ٣٠` waited 30 s (stop 55 left it: only the
    scheduler's port refused them); and '\\u00b2', which str.isdigit() takes, int() refuses. Now every number option
    takes ASCII digits alone, as --classes does (stop 48), before anything is read or written."""
    argv = [str(tmp_path / a) if a in ("IN", "OUT") else a for a in argv]
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's refusal
        code = exc.code
    assert code == 2
    assert said in capsys.readouterr().err
    assert not (tmp_path / "OUT").exists()
