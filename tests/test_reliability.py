"""Reliability: bad inputs get clear errors, properties hold for any cloud, fuzzed files never crash
a reader, batches lose nothing, files cannot be used to attack.

Fuzz and property tests run the hypothesis profile of conftest.py (derandomised in CI; ``make test-long``
for fresh random cases).
"""

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from symfruit import FileFormatError, InputError, SymfruitError, complete
from symfruit.cli import main

from .conftest import CENTRE, EXAMPLE_FRAME, FUZZ_EXAMPLES, front_half, sphere_cloud

VISIBLE = front_half(sphere_cloud())


# --- clouds ------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "points, message",
    [
        (np.c_[np.random.default_rng(0).random((40, 2)) * 0.03, np.full(40, 0.3)], "on a plane"),
        (np.full((30, 3), np.nan), "after dropping 30 non-finite"),
    ],
)
def test_more_bad_clouds(points, message):
    with pytest.raises(InputError, match=message):
        complete(points)


def test_a_million_points_are_down_sampled():
    rng = np.random.default_rng(0)
    d = rng.normal(size=(1_000_000, 3))
    cloud = front_half(0.03 * d / np.linalg.norm(d, axis=1, keepdims=True) + CENTRE)
    start = time.perf_counter()
    result = complete(cloud)
    assert len(result.visible) == 20000 and result.n_input == len(cloud)
    assert time.perf_counter() - start < 30  # generous bound for a loaded CI machine; about 1 s here


finite = st.floats(-0.05, 0.05, allow_nan=False)


@settings()
@given(
    arrays(np.float64, st.tuples(st.integers(0, 60), st.just(3)), elements=finite),
    st.sampled_from(["fused", "paper", "sphere", "ellipsoid", "raw"]),
)
def test_complete_raises_only_documented_errors_and_boxes_every_visible_point(offsets, method):
    cloud = offsets + CENTRE
    try:
        result = complete(cloud, method=method)
    except SymfruitError:
        return
    assert result.box.contains(result.visible, tol=1e-9)
    again = complete(cloud.copy(), method=method)
    assert np.array_equal(again.box.min, result.box.min) and np.array_equal(again.box.max, result.box.max)


@settings(max_examples=max(10, FUZZ_EXAMPLES // 4))
@given(st.floats(-0.05, 0.15), st.sampled_from(["fused", "paper", "sphere", "raw"]))
def test_translation_along_the_optical_axis_moves_the_box_with_it(shift, method):
    a = complete(VISIBLE, method=method)
    b = complete(VISIBLE + [0.0, 0.0, shift], method=method)
    # Perspective changes the rasterised view a little, so the tolerance is a few millimetres.
    assert np.allclose(b.centre, a.centre + [0.0, 0.0, shift], atol=0.004)


# --- files -------------------------------------------------------------------------------------------


def read_any(path: Path) -> None:
    from symfruit.io import load_camera, read_cloud
    from symfruit.io.frames import read_frame

    if path.suffix in (".json", ".yaml") and path.parent.name != "frame":
        load_camera(path)
    elif path.is_dir():
        read_frame(path)
    else:
        read_cloud(path)


@settings()
@given(st.binary(max_size=2048), st.sampled_from([".ply", ".pcd", ".xyz", ".csv", ".npy", ".json", ".yaml"]))
def test_readers_survive_random_bytes(tmp_path, data, suffix):
    path = tmp_path / f"fuzz{suffix}"
    path.write_bytes(data)
    try:
        read_any(path)
    except SymfruitError:
        pass


@settings()
@given(st.sampled_from(["ply", "pcd", "npy"]), st.integers(1, 400), st.integers(0, 255), st.integers(0, 10_000))
def test_readers_survive_corrupted_valid_files(tmp_path, kind, cut, byte, where):
    from symfruit.io import write_ply

    from .test_io import POINTS, write_pcd

    path = tmp_path / f"c.{kind}"
    if kind == "ply":
        write_ply(path, POINTS)
    elif kind == "pcd":
        write_pcd(path, POINTS, "binary_compressed")
    else:
        np.save(path, POINTS)
    data = bytearray(path.read_bytes())
    data[where % len(data)] = byte
    path.write_bytes(bytes(data[: max(1, len(data) - cut)]))
    try:
        read_any(path)
    except SymfruitError:
        pass


@pytest.mark.parametrize("name", ["color.png", "depth.png", "camera.json", "truth.json"])
def test_truncated_frame_files(tmp_path, name):
    import shutil

    from symfruit.io.frames import read_frame

    frame = tmp_path / "frame"
    shutil.copytree(EXAMPLE_FRAME, frame)
    data = (frame / name).read_bytes()
    (frame / name).write_bytes(data[: len(data) // 2])
    with pytest.raises(SymfruitError, match=name.split(".")[0]):
        read_frame(frame)


def test_corrupt_bag(tmp_path):
    pytest.importorskip("rosbags")
    from symfruit.io.sources import open_source

    bag = tmp_path / "broken.bag"
    bag.write_bytes(b"#ROSBAG V2.0\n" + np.random.default_rng(0).bytes(300))
    with pytest.raises(FileFormatError, match=r"broken\.bag"):
        open_source(bag)


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


# --- images and intrinsics ---------------------------------------------------------------------------


def test_an_empty_mask_gives_no_fruit_and_no_error():
    from symfruit.detect import detect
    from symfruit.io.frames import read_frame

    frame = read_frame(EXAMPLE_FRAME)
    found = detect(frame, masks=lambda f, s: np.zeros(f.depth.shape, np.int32))
    assert found.detections == []


def test_intrinsics_not_matching_the_image(tmp_path):
    import shutil

    from symfruit.io.frames import read_frame

    frame = tmp_path / "frame"
    shutil.copytree(EXAMPLE_FRAME, frame)
    cam = json.loads((frame / "camera.json").read_text())
    (frame / "camera.json").write_text(json.dumps({**cam, "height": 720}))
    with pytest.raises(InputError, match=r"intrinsics are for 640x720 but the images are 640x480"):
        read_frame(frame)
    (frame / "camera.json").write_text(json.dumps({**cam, "fx": -5}))
    with pytest.raises(FileFormatError, match="focal lengths must be positive"):
        read_frame(frame)


# --- batches -----------------------------------------------------------------------------------------


def _fruits(folder: Path) -> dict:
    out = {}
    for path in sorted(folder.glob("*/detections.json")):
        data = json.loads(path.read_text())
        out[path.parent.name] = [{k: v for k, v in f.items() if k != "seconds"} for f in data["fruits"]]
    return out


def test_killed_batch_resumes_to_identical_results(tmp_path):
    import shutil

    rec = tmp_path / "rec"
    for i in range(6):
        shutil.copytree(EXAMPLE_FRAME, rec / f"f{i}")
    whole, part = tmp_path / "whole", tmp_path / "part"
    cmd = [sys.executable, "-m", "symfruit", "detect", str(rec), "--method", "raw"]
    subprocess.run([*cmd, "--output", str(whole)], check=True, capture_output=True)
    proc = subprocess.Popen([*cmd, "--output", str(part)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 120
    while time.time() < deadline and not (part / "f1" / "detections.json").exists():
        time.sleep(0.05)
    proc.kill()  # at whatever moment: every assertion below holds for any of them
    proc.wait()
    done_before = len(list(part.glob("*/detections.json")))
    assert 1 <= done_before <= 6
    for path in part.glob("*/detections.json"):  # a file that exists is whole (written atomically)
        assert json.loads(path.read_text())["fruits"]
    done = subprocess.run([*cmd, "--output", str(part), "--resume"], capture_output=True, text=True)
    assert done.returncode == 0 and f"{done_before} skipped" in done.stdout
    assert _fruits(part) == _fruits(whole)
    assert not list(part.rglob("*.tmp"))  # the resumed run removed what the kill left half-written
    assert {p.name for p in part.rglob("*")} == {p.name for p in whole.rglob("*")}


# --- attacks -----------------------------------------------------------------------------------------


def test_no_eval_or_pickle_anywhere():
    import re

    src = Path(__file__).resolve().parents[1] / "src" / "symfruit"
    text = "\n".join(p.read_text() for p in src.rglob("*.py"))
    assert not re.search(r"(?<![.\w])(eval|exec)\(", text)
    assert not re.search(r"import pickle|pickle\.load|allow_pickle=True|yaml\.load\(|yaml\.unsafe_load", text)
    assert text.count("allow_pickle=False") >= 2 and "weights_only=True" in text


def test_frame_names_from_a_recording_cannot_escape_the_output(tmp_path):
    import shutil

    from symfruit.batch import frame_folder_name, run_batch

    rec = tmp_path / "rec"

    shutil.copytree(EXAMPLE_FRAME, rec / "x..y ;$(rm -rf)")
    out = tmp_path / "out"
    report = run_batch(rec, out, method="raw", progress=False)
    assert report.done == ["x..y ;$(rm -rf)"] and (out / frame_folder_name("x..y ;$(rm -rf)")).is_dir()
    written = [p.resolve() for p in out.rglob("*")]
    assert all(str(p).startswith(str(out.resolve())) for p in written)
