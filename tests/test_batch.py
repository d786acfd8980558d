"""Batches over a recording: every frame gets its folder, a bad frame is recorded and the batch goes on,
resume skips finished frames before decoding them, and a killed batch resumes to the same results."""

import errno
import json
import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from PIL import Image

import symfruit
from symfruit import batch
from symfruit.batch import BatchReport, frame_folder_name, run_batch
from symfruit.cli import main
from symfruit.io.sources import FolderSource

from .conftest import EXAMPLE_FRAME, small_frame


def recording(root: Path, *names: str) -> Path:
    """Frame folders ``names`` in ``root``, each the small frame (one strawberry: see conftest.small_frame)."""
    for name in names:
        shutil.copytree(small_frame(), root / name)
    return root


def _fruits(folder: Path) -> dict:
    out = {}
    for path in sorted(folder.glob("*/detections.json")):
        data = json.loads(path.read_text())
        out[path.parent.name] = [{k: v for k, v in f.items() if k != "seconds"} for f in data["fruits"]]
    return out


def test_batch_goes_on_past_a_bad_frame_and_resumes(tmp_path):
    frames = recording(tmp_path / "rec", "f1", "f2", "f3")
    (frames / "f2" / "depth.png").write_bytes(b"not a png")
    out = tmp_path / "out"
    report = run_batch(frames, out, method="raw", progress=False)
    assert report.done == ["f1", "f3"] and list(report.failed) == ["f2"] and not report.ok
    errors = json.loads((out / "errors.json").read_text())
    assert errors["failed"][0]["frame"] == "f2" and "depth.png" in errors["failed"][0]["reason"]
    before = (out / "f1" / "detections.json").read_bytes()
    again = run_batch(frames, out, method="raw", resume=True, progress=False)
    assert again.skipped == ["f1", "f3"] and (out / "f1" / "detections.json").read_bytes() == before


def test_a_fruit_pool_gives_the_same_records_and_is_refused_with_a_cluster(tmp_path):
    from symfruit.errors import InputError
    from symfruit.fruitpool import FruitPool, one_process_reason

    frames = tmp_path / "rec"
    for name in ("f1", "f2"):
        shutil.copytree(EXAMPLE_FRAME, frames / name)
    run_batch(frames, tmp_path / "one", progress=False)
    if one_process_reason(1):
        pytest.skip(f"no worker processes here: {one_process_reason(1)}")
    with FruitPool(1, method=None) as pool:
        pool._caller_shares = False  # the worker does every fruit
        report = run_batch(frames, tmp_path / "two", progress=False, pool=pool)
        assert report.done == ["f1", "f2"] and pool.fruit_elsewhere == report.fruits >= 4
        with pytest.raises(InputError, match="a Dask cluster's workers are one of several processes already"):
            run_batch(frames, tmp_path / "three", progress=False, pool=pool, workers=2)
    assert _fruits(tmp_path / "one") == _fruits(tmp_path / "two")


def outcome(report: BatchReport, output: Path) -> str:
    """A report's frames, errors and counts, its output folder's name left out of them."""
    said = (report.done, report.failed, report.skipped, report.unprocessed, report.stopped, report.fruits)
    return repr(said).replace(str(output), "OUTPUT")


@pytest.mark.parametrize("failing", [ValueError("f3 cannot be written"), OSError(errno.ENOSPC, "No space left")],
                         ids=["a frame fails as it is written", "the disk is full"])  # fmt: skip
def test_a_recording_streamed_with_a_fruit_pool_gives_each_frame_its_outcome(tmp_path, monkeypatch, failing):
    """With a pool the frames go in a stream (issue 19, stop 55: frame n+1 read and segmented before frame n is
    finished, frame n+1 started, frame n written): each frame's records, errors and the report's order are one
    process's; a full disk stops at the frame it hit, the one started after it dropped and not processed."""
    from symfruit.fruitpool import FruitPool, one_process_reason

    if one_process_reason(1):
        pytest.skip(f"no worker processes here: {one_process_reason(1)}")
    frames = tmp_path / "rec"
    for name in ("f1", "f2", "f3", "f4", "f5"):
        shutil.copytree(EXAMPLE_FRAME, frames / name)
    (frames / "f2" / "depth.png").write_bytes(b"not a png")  # refused when read, the frame before in flight
    real = batch.write_detections

    def write_detections(folder, found, **kwargs):
        if folder.name == "f3":
            raise failing
        return real(folder, found, **kwargs)

    monkeypatch.setattr(batch, "write_detections", write_detections)
    one = run_batch(frames, tmp_path / "one", progress=False)
    with FruitPool(1, method=None) as pool:
        pool._caller_shares = False  # the worker does every fruit
        two = run_batch(frames, tmp_path / "two", progress=False, pool=pool)
        each = two.fruits // len(two.done)  # the same frame's fruit; f3's were done too, then not written
        assert pool.fruit_elsewhere == each * (len(two.done) + 1) and each >= 2
        # a full disk at f3 drops f4, started meanwhile: its workers ended (new ones started)
        assert pool.starts == (2 if two.stopped else 1), pool.last_loss
        assert outcome(two, tmp_path / "two") == outcome(one, tmp_path / "one")
        assert list(two.failed) == ["f2", "f3"] and _fruits(tmp_path / "two") == _fruits(tmp_path / "one")
        errors = [(tmp_path / out / "errors.json").read_text().replace(str(tmp_path / out), "OUTPUT")
                  for out in ("one", "two")]  # fmt: skip
        assert errors[0] == errors[1]
        if two.stopped:
            assert two.done == ["f1"] and two.unprocessed == ["f4", "f5"]
        else:
            assert two.done == ["f1", "f4", "f5"]
        monkeypatch.undo()  # resumed: the frames done skipped, the others run again
        (frames / "f2" / "depth.png").write_bytes((frames / "f1" / "depth.png").read_bytes())
        one = run_batch(frames, tmp_path / "one", progress=False, resume=True)
        two = run_batch(frames, tmp_path / "two", progress=False, pool=pool, resume=True)
        assert outcome(two, tmp_path / "two") == outcome(one, tmp_path / "one") and two.ok
        assert two.skipped == (["f1"] if failing.args[0] == errno.ENOSPC else ["f1", "f4", "f5"])
    assert _fruits(tmp_path / "two") == _fruits(tmp_path / "one")


def test_resume_runs_again_a_frame_whose_record_cannot_be_read_back(tmp_path):
    # a detections.json truncated by a copy was trusted: the frame was skipped, then left out of the tables
    frames = recording(tmp_path / "rec", "f1", "f2")
    out = tmp_path / "out"
    run_batch(frames, out, method="raw", progress=False)
    before = _fruits(out)
    (out / "f2" / "detections.json").write_bytes((out / "f2" / "detections.json").read_bytes()[:300])
    (out / "f1" / "detections.json").write_text('{"frame": "f1"}')  # JSON, but no record
    again = run_batch(frames, out, method="raw", resume=True, progress=False)
    assert again.skipped == [] and again.done == ["f1", "f2"] and again.ok
    assert _fruits(out) == before
    again = run_batch(frames, out, method="raw", resume=True, progress=False)
    assert again.skipped == ["f1", "f2"] and again.ok


def test_resume_runs_again_a_frame_whose_record_is_another_frames(tmp_path):
    """Stop 50 (robust50): a frame folder copied over another's (its record names the other frame) was skipped,
    and the tables listed the other frame twice, this one not at all."""
    import pyarrow.parquet as pq

    frames = recording(tmp_path / "rec", "f1", "f2")
    out = tmp_path / "out"
    run_batch(frames, out, method="raw", progress=False)
    before = _fruits(out)
    (out / "f2" / "detections.json").write_bytes((out / "f1" / "detections.json").read_bytes())
    again = run_batch(frames, out, method="raw", resume=True, progress=False)
    assert again.skipped == ["f1"] and again.done == ["f2"] and again.ok
    assert _fruits(out) == before
    assert pq.read_table(out / "frames.parquet").column("frame").to_pylist() == ["f1", "f2"]


def test_resume_runs_again_a_frame_whose_files_are_gone_or_empty(tmp_path):
    """Stop 57: a frame whose record was whole was skipped even when its overlay or a fruit's cloud had been
    deleted or emptied afterwards; the resumed run then listed it as done without those files."""
    frames = recording(tmp_path / "rec", "f1", "f2", "f3")
    out = tmp_path / "out"
    run_batch(frames, out, method="raw", progress=False)
    before = _fruits(out)
    plys = sorted((out / "f2").glob("fruit_*.ply"))
    assert plys  # the frames have located fruit, so the test reads a cloud
    plys[0].unlink()
    (out / "f3" / "overlay.png").write_bytes(b"")
    again = run_batch(frames, out, method="raw", resume=True, progress=False)
    assert again.skipped == ["f1"] and again.done == ["f2", "f3"] and again.ok
    assert plys[0].stat().st_size > 0 and (out / "f3" / "overlay.png").stat().st_size > 0
    assert _fruits(out) == before
    again = run_batch(frames, out, method="raw", resume=True, progress=False)
    assert again.skipped == ["f1", "f2", "f3"] and again.ok


def test_frame_folder_names_stay_in_their_folder_and_never_collide():
    assert frame_folder_name("f1") == "f1"
    assert frame_folder_name("../../etc/passwd").startswith("etc_passwd+")
    assert frame_folder_name("a b/c").startswith("a_b_c+") and frame_folder_name("...").startswith("frame+")
    assert frame_folder_name("a b") != frame_folder_name("a?b")  # sanitised alike, told apart by the hash


def test_frame_names_from_a_recording_cannot_escape_the_output(tmp_path):
    import shutil

    from symfruit.batch import frame_folder_name, run_batch

    rec = tmp_path / "rec"

    shutil.copytree(small_frame(), rec / "x..y ;$(rm -rf)")
    out = tmp_path / "out"
    report = run_batch(rec, out, method="raw", progress=False)
    assert report.done == ["x..y ;$(rm -rf)"] and (out / frame_folder_name("x..y ;$(rm -rf)")).is_dir()
    written = [p.resolve() for p in out.rglob("*")]
    assert all(str(p).startswith(str(out.resolve())) for p in written)


@given(st.lists(st.text(min_size=0, max_size=30), min_size=2, max_size=8, unique=True))
def test_frame_folder_names_are_safe_and_distinct(names):
    folders = [frame_folder_name(n) for n in names]
    assert len(set(folders)) == len(folders)
    for folder in folders:
        assert re.fullmatch(r"[A-Za-z0-9._+-]+", folder) and folder not in (".", "..") and len(folder) <= 109


def test_a_name_that_looks_like_a_hashed_name_does_not_collide():
    hashed = frame_folder_name("a b")  # "a_b+<8 hex digits>"
    assert frame_folder_name(hashed) != hashed


def test_an_unexpected_error_in_one_frame_is_recorded_and_the_batch_goes_on(tmp_path, monkeypatch):
    rec = recording(tmp_path / "rec", "f1", "f2", "f3")
    real = batch.detect

    def detect(frame, **kwargs):
        if frame.name == "f2":
            raise RuntimeError("the segmenter fell over")
        return real(frame, **kwargs)

    monkeypatch.setattr(batch, "detect", detect)
    report = run_batch(rec, tmp_path / "out", method="raw", progress=False)
    assert report.done == ["f1", "f3"] and report.failed == {"f2": "RuntimeError: the segmenter fell over"}
    assert not report.ok and report.stopped == "" and report.fruits == 2 and report.failed_fruits == 0  # one each
    errors = json.loads((tmp_path / "out" / "errors.json").read_text())
    assert errors == {"failed": [{"frame": "f2", "reason": "RuntimeError: the segmenter fell over"}], "stopped": ""}
    assert not (tmp_path / "out" / "f2").exists()


def test_resume_decides_before_decoding(tmp_path, monkeypatch):
    rec = recording(tmp_path / "rec", "a", "b")
    out = tmp_path / "out"
    reads = []
    real = FolderSource.read

    def read(self, index):
        reads.append(self.names()[index])
        return real(self, index)

    monkeypatch.setattr(FolderSource, "read", read)
    run_batch(rec, out, method="raw", progress=False)
    assert reads == ["a", "b"]
    shutil.rmtree(out / "a")
    reads.clear()
    again = run_batch(rec, out, method="raw", resume=True, progress=False)
    assert reads == ["a"]  # finished frames are never decoded
    assert again.skipped == ["b"] and again.done == ["a"] and again.ok
    reads.clear()
    run_batch(rec, out, method="raw", resume=False, progress=False)
    assert reads == ["a", "b"]  # without resume every frame is redone


def test_an_output_folder_inside_the_recording_is_not_a_frame(tmp_path):
    rec = recording(tmp_path / "rec", "f1", "f2")
    out = rec / "out"
    for _ in range(2):  # the second time, out/ holds frame-like folders of results
        report = run_batch(rec, out, method="raw", progress=False)
        assert report.done == ["f1", "f2"] and report.ok
    assert sorted(p.name for p in out.iterdir()) == ["detections.parquet", "errors.json", "f1", "f2", "frames.parquet"]


def test_a_rerun_with_fewer_fruit_leaves_no_stale_clouds(tmp_path):
    rec = tmp_path / "rec"
    shutil.copytree(EXAMPLE_FRAME, rec / "f1")  # six fruit
    out = tmp_path / "out"
    run_batch(rec, out, method="raw", progress=False)
    assert sorted(p.name for p in (out / "f1").glob("fruit_*.ply")) == [f"fruit_{k:03d}.ply" for k in range(1, 7)]
    from symfruit.io.frames import read_frame
    from symfruit.segment.colour import segment

    frame = read_frame(rec / "f1")
    labels = segment(frame.color, frame.depth, frame.camera)
    labels[labels > 2] = 0  # the frame's own masks now hold two fruit
    Image.fromarray(labels.astype(np.uint8)).save(rec / "f1" / "masks.png")
    report = run_batch(rec, out, method="raw", progress=False)
    assert report.fruits == 2
    assert sorted(p.name for p in (out / "f1").iterdir()) == ["detections.json", "fruit_001.ply", "fruit_002.ply",
                                                              "overlay.png"]  # fmt: skip


def test_errors_json_when_nothing_failed_and_when_the_disk_is_full(tmp_path, monkeypatch):
    rec = recording(tmp_path / "rec", "f1", "f2", "f3")
    report = run_batch(rec, tmp_path / "ok", method="raw", progress=False)
    assert report.ok and json.loads((tmp_path / "ok" / "errors.json").read_text()) == {"failed": [], "stopped": ""}
    real = batch.write_detections

    def write_detections(folder, found, **kwargs):
        if folder.name == "f2":
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(folder, found, **kwargs)

    monkeypatch.setattr(batch, "write_detections", write_detections)
    report = run_batch(rec, tmp_path / "full", method="raw", progress=False)
    assert report.done == ["f1"] and list(report.failed) == ["f2"] and not report.ok  # f3 is not attempted
    assert report.failed["f2"] == f"cannot write {tmp_path / 'full' / 'f2'}: No space left on device"
    assert report.stopped == "stopped at frame f2: the output is full (No space left on device)"
    errors = json.loads((tmp_path / "full" / "errors.json").read_text())
    assert errors["stopped"] == report.stopped and errors["failed"][0]["frame"] == "f2"


def test_a_report_is_ok_only_without_failures_or_a_stop():
    assert BatchReport().ok and BatchReport(done=["a"], skipped=["b"]).ok
    assert not BatchReport(failed={"a": "x"}).ok and not BatchReport(stopped="full").ok


def test_a_source_that_cannot_be_opened_or_an_output_that_cannot_be_made_raises(tmp_path):
    from symfruit import FileFormatError

    with pytest.raises(FileFormatError, match="no such frame folder, folder of frames or bag"):
        run_batch(tmp_path / "missing", tmp_path / "out", progress=False)
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(FileFormatError, match="cannot write to folder"):
        run_batch(EXAMPLE_FRAME, blocker / "out", progress=False)


#: Runs ``symfruit detect ARGS`` and SIGKILLs itself while writing the ``detections.json`` of frame
#: ``sys.argv[1]``: after that frame's clouds and overlay, with its record half written to a temporary file.
KILLED_WHILE_WRITING = """
import os, signal, sys
from pathlib import Path

import symfruit.writers as writers
from symfruit.io.atomic import atomic_write

real = writers.write_json


def write_json(path, data):
    path = Path(path)
    if path.name == "detections.json" and path.parent.name == sys.argv[1]:
        with atomic_write(path, "w") as handle:
            handle.write('{"frame": ')
            handle.flush()
            os.kill(os.getpid(), signal.SIGKILL)
    real(path, data)


writers.write_json = write_json
from symfruit.cli import main

sys.exit(main(sys.argv[2:]))
"""


def test_killed_batch_resumes_to_identical_results(tmp_path, capsys):
    rec = recording(tmp_path / "rec", *(f"f{i}" for i in range(4)))
    whole, part = tmp_path / "whole", tmp_path / "part"
    cmd = ["detect", str(rec), "--method", "raw"]
    assert main([*cmd, "--output", str(whole)]) == 0
    # Killed at a fixed moment, the worst one: frame f2's outputs written but its record still a temporary file.
    killed = subprocess.run([sys.executable, "-c", KILLED_WHILE_WRITING, "f2", *cmd, "--output", str(part)],
                            capture_output=True, text=True, timeout=300)  # fmt: skip
    assert killed.returncode == -signal.SIGKILL, killed.stderr
    done_before = len(list(part.glob("*/detections.json")))
    assert done_before == 2  # f0, f1
    for path in part.glob("*/detections.json"):  # a file that exists is whole (written atomically)
        assert json.loads(path.read_text())["fruits"]
    assert [p.name.startswith(".detections.json.") for p in part.rglob("*.tmp")] == [True]  # the half-written record
    capsys.readouterr()
    assert main([*cmd, "--output", str(part), "--resume"]) == 0
    assert f"{done_before} skipped" in capsys.readouterr().out
    assert _fruits(part) == _fruits(whole)
    assert not list(part.rglob("*.tmp"))  # the resumed run removed what the kill left half-written
    assert {p.name for p in part.rglob("*")} == {p.name for p in whole.rglob("*")}


def test_a_file_size_limit_stops_the_batch_cleanly_and_keeps_what_was_written(tmp_path):
    """A real RLIMIT_FSIZE (what a full disk looks like to a writer): a one-line report, no traceback, the
    frames already done untouched, errors.json saying where it stopped."""

    rec = tmp_path / "rec"
    # the example frame: its overlay is larger than the limit, every other file smaller
    shutil.copytree(EXAMPLE_FRAME, rec / "f1")
    out = tmp_path / "out"
    args = ["detect", str(rec), "--output", str(out), "--method", "raw"]
    assert main(args) == 0  # f1 in this process; f2, the same frame added now, in the limited child
    shutil.copytree(EXAMPLE_FRAME, rec / "f2")
    before = {p: p.read_bytes() for p in (out / "f1").iterdir()}
    # (not much less: under `pytest --cov` the child also writes its coverage data, some tens of kB)
    size = 100_000
    assert all((p.stat().st_size < size) == (p.name != "overlay.png") for p in (out / "f1").iterdir())

    # the limit set by a child of its own, which then becomes the command (a preexec_fn runs Python between fork and
    # exec, which may deadlock where the test process runs other threads: flake54)
    limited = (f"import os, resource, sys; resource.setrlimit(resource.RLIMIT_FSIZE, ({size}, {size})); "
               "os.execv(sys.executable, [sys.executable, '-m', 'symfruit', *sys.argv[1:]])")  # fmt: skip
    proc = subprocess.run([sys.executable, "-c", limited, *args, "--resume"], capture_output=True, text=True,
                          timeout=600)  # fmt: skip
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    assert "symfruit: stopped at frame f2: the output is full (File too large)" in proc.stderr
    assert {p: p.read_bytes() for p in (out / "f1").iterdir()} == before
    assert not (out / "f2" / "detections.json").exists() and not list(out.rglob("*.tmp"))
    assert json.loads((out / "errors.json").read_text())["failed"][0]["frame"] == "f2"


@pytest.mark.parametrize(
    ("frames", "ripe", "method"),
    [(4, 3, "sphere"), pytest.param(40, 8, "evidence", marks=pytest.mark.slow)],
)
def test_memory_stays_flat_over_a_recording(tmp_path, frames, ripe, method):
    """Peak resident memory of a detect child (its own VmHWM) over a recording stays far under the bound the
    issue sets for 2,000 frames; frames are decoded one at a time. The quick case: 4 frames (one scene, rendered
    once) completed with the sphere; the slow one: 40 frames (two scenes) of 8 fruit with the default method."""
    from symfruit.evaluate.bench import measured_detect
    from symfruit.synthetic.scenes import write_scenes

    write_scenes(tmp_path / "rec", frames, distinct=1 if frames < 10 else 2, n_ripe=ripe)
    # one frame first, in a child of its own: numba compiles the kernels a fresh clone has not cached yet, which
    # took the slow case's peak to 493 MB once (stop 61); the measured run then reads them from the cache
    first = sorted(p for p in (tmp_path / "rec").iterdir() if p.is_dir())[0]
    status, _, err = measured_detect([str(first), "--output", str(tmp_path / "warm"), "--method", method], timeout=600)
    assert status == 0, err
    args = [str(tmp_path / "rec"), "--output", str(tmp_path / "out"), "--method", method]
    # the child's own peak, its mapped files' resident pages left out: those follow the page cache (a fresh clone's
    # newly installed libraries read some 75 MB more for the same run, 400 MB in all for the slow case; stop 61)
    status, peak_mb, err = measured_detect(args, timeout=600, own=True)
    assert status == 0, err
    assert len(list((tmp_path / "out").glob("*/detections.json"))) == frames
    assert 30 < peak_mb < 400  # measured at stop 61: 148 MB (the quick case) and 192 MB (the slow one), either way


def test_a_frame_folder_that_links_out_of_the_output_is_refused_and_recorded(tmp_path):
    rec = recording(tmp_path / "rec", "f1", "f2")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "f1").symlink_to(elsewhere, target_is_directory=True)
    report = run_batch(rec, tmp_path / "out", method="raw", progress=False)
    assert report.done == ["f2"] and "f1: is a symbolic link" in report.failed["f1"]
    assert list(elsewhere.iterdir()) == []  # nothing written (or removed) outside the output folder
    errors = json.loads((tmp_path / "out" / "errors.json").read_text())
    assert [e["frame"] for e in errors["failed"]] == ["f1"]


def test_a_frame_named_like_the_batchs_own_files_cannot_take_them(tmp_path):
    rec = recording(tmp_path / "rec", "errors.json", "f2")
    shutil.copytree(EXAMPLE_FRAME, rec / ".symfruit.lock")  # hidden: not a frame at all
    (rec / "errors.json" / "depth.png").unlink()  # this frame fails: its record must survive
    report = run_batch(rec, tmp_path / "out", method="raw", progress=False)
    assert report.done == ["f2"] and list(report.failed) == ["errors.json"]
    errors = json.loads((tmp_path / "out" / "errors.json").read_text())
    assert [e["frame"] for e in errors["failed"]] == ["errors.json"] and "depth" in errors["failed"][0]["reason"]
    assert (tmp_path / "out" / "errors.json").is_file()


def test_a_second_batch_on_one_output_folder_is_refused_at_once(tmp_path):
    from symfruit import OutputError
    from symfruit.io.outputs import OutputFolder

    rec = recording(tmp_path / "rec", "f1")
    with OutputFolder(tmp_path / "out"), pytest.raises(OutputError, match=r"another symfruit run .* is writing"):
        run_batch(rec, tmp_path / "out", method="raw", progress=False)
    assert not (tmp_path / "out" / "f1").exists()
    assert run_batch(rec, tmp_path / "out", method="raw", progress=False).done == ["f1"]  # released


def test_the_output_may_not_be_the_recording_or_one_of_its_frames(tmp_path):
    from symfruit import OutputError

    rec = recording(tmp_path / "rec", "f1", "f2")
    before = sorted(p.name for p in (rec / "f1").iterdir())
    for output in (rec, rec / "f1"):
        with pytest.raises(OutputError, match="also an input folder"):
            run_batch(rec, output, method="raw", progress=False)
    with pytest.raises(OutputError, match="also an input folder"):
        run_batch(rec / "f1", rec / "f1", method="raw", progress=False)
    assert sorted(p.name for p in (rec / "f1").iterdir()) == before


def test_a_bag_the_run_writes_inside_the_recording_is_no_frame(tmp_path):
    rec = recording(tmp_path / "rec", "f1")
    (rec / "bag").mkdir()
    (rec / "bag" / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
    report = run_batch(rec, tmp_path / "out", method="raw", progress=False, exclude=[rec / "bag"])
    assert report.ok and report.done == ["f1"]


def test_a_full_disk_leaves_every_frame_done_or_recorded(tmp_path, monkeypatch):
    from symfruit import OutputError

    rec = recording(tmp_path / "rec", "f1", "f2", "f3", "f4")
    real = batch.write_detections

    def write(folder, found, **kwargs):
        if folder.name == "f2":
            (folder / "fruit_001.ply").parent.mkdir(parents=True, exist_ok=True)
            (folder / "fruit_001.ply").write_text("half")  # written before the disk filled up
            raise OutputError(f"{folder}/overlay.png: cannot write (No space left on device)", errno.ENOSPC)
        return real(folder, found, **kwargs)

    monkeypatch.setattr(batch, "write_detections", write)
    report = run_batch(rec, tmp_path / "out", method="raw", progress=False)
    assert report.done == ["f1"] and list(report.failed) == ["f2"] and report.unprocessed == ["f3", "f4"]
    assert "output is full" in report.stopped
    errors = json.loads((tmp_path / "out" / "errors.json").read_text())
    recorded = {e["frame"] for e in errors["failed"]} | set(errors["unprocessed"])
    assert recorded | {"f1"} == {"f1", "f2", "f3", "f4"} and not (tmp_path / "out" / "f2" / "fruit_001.ply").exists()


def test_a_frame_that_fails_on_a_rerun_keeps_no_old_results(tmp_path):
    rec = recording(tmp_path / "rec", "f1")
    assert run_batch(rec, tmp_path / "out", method="raw", progress=False).ok
    (rec / "f1" / "depth.png").write_bytes(b"broken")
    report = run_batch(rec, tmp_path / "out", method="raw", progress=False)
    assert list(report.failed) == ["f1"] and sorted(p.name for p in (tmp_path / "out" / "f1").iterdir()) == []


# --- several recordings in one run ---------------------------------------------------------------------------


def _rows(out: Path) -> list[tuple]:
    import pyarrow.parquet as pq

    rows = pq.read_table(out / "detections.parquet").to_pylist()
    return [(r["recording"], r["frame"], r["id"], r["centre_x"], r["size_x"]) for r in rows]


def test_several_recordings_each_get_a_folder_even_when_they_share_a_name(tmp_path):
    a = recording(tmp_path / "a" / "frames", "f1", "f2")
    b = recording(tmp_path / "b" / "frames", "f1")
    row = tmp_path / "row 3"  # one frame folder as a recording, its name not a plain file name
    shutil.copytree(EXAMPLE_FRAME, row)
    out = tmp_path / "out"
    report = run_batch([a, b, row], out, method="raw", progress=False)
    names = {str(a): "", str(b): "", str(row): ""}
    names.update(report.recordings)
    fa, fb, fr = names[str(a)], names[str(b)], names[str(row)]
    assert fa.startswith("frames+") and fb.startswith("frames+") and fa != fb and fr.startswith("row_3+")
    assert report.ok and report.done == [f"{fa}/f1", f"{fa}/f2", f"{fb}/f1", f"{fr}/row 3"] and report.fruits == 9
    assert sorted(p.name for p in out.iterdir()) == sorted(
        ["detections.parquet", "errors.json", "frames.parquet", fa, fb, fr])  # fmt: skip
    assert sorted(p.name for p in (out / fa).iterdir()) == ["f1", "f2"]
    assert sorted(p.name for p in (out / fr).iterdir()) == [frame_folder_name("row 3")]
    single = run_batch(b, tmp_path / "single", method="raw", progress=False)  # the same frames, alone
    assert single.done == ["f1"] and _fruits(out / fb) == _fruits(tmp_path / "single")
    rows = _rows(out)
    assert len(rows) == 9 and len(set((r[0], r[1], r[2]) for r in rows)) == 9  # one fruit each, six in "row 3"
    assert [(r[0], r[1]) for r in rows] == [(fa, "f1"), (fa, "f2"), (fb, "f1"), *[(fr, "row 3")] * 6]
    assert [r[2:] for r in rows if r[0] == fb] == [r[2:] for r in _rows(tmp_path / "single")]
    import pyarrow.parquet as pq

    from symfruit.season.table import recording_inputs

    for table in ("detections.parquet", "frames.parquet"):  # which input each recording is, in the metadata
        assert recording_inputs(pq.read_schema(out / table).metadata) == {fa: str(a), fb: str(b), fr: str(row)}
    assert recording_inputs(pq.read_schema(tmp_path / "single" / "detections.parquet").metadata) == {}


def test_one_input_in_a_list_keeps_the_layout_of_one_recording(tmp_path):
    rec = recording(tmp_path / "rec", "f1")
    report = run_batch([rec], tmp_path / "out", method="raw", progress=False)
    assert report.done == ["f1"] and report.recordings == {} and (tmp_path / "out" / "f1" / "detections.json").is_file()
    assert {r[0] for r in _rows(tmp_path / "out")} == {"rec"}


def test_a_bad_recording_among_good_ones_is_recorded_and_the_run_goes_on(tmp_path):
    good = recording(tmp_path / "good", "f1", "f2")
    (good / "f2" / "depth.png").write_bytes(b"not a png")
    other = recording(tmp_path / "other", "f1")
    notes = tmp_path / "notes.txt"
    notes.write_text("not a recording")
    out = tmp_path / "out"
    report = run_batch([good, notes, other], out, method="raw", progress=False)
    assert report.done == ["good/f1", "other/f1"] and list(report.failed) == ["good/f2"] and not report.ok
    assert list(report.failed_recordings) == [str(notes)] and "neither a frame folder" in report.failed_recordings[
        str(notes)]  # fmt: skip
    errors = json.loads((out / "errors.json").read_text())
    assert [e["frame"] for e in errors["failed"]] == ["good/f2"] and "depth.png" in errors["failed"][0]["reason"]
    assert [(e["recording"], e["input"]) for e in errors["recordings"]] == [("notes.txt", str(notes))]
    assert {(r[0], r[1]) for r in _rows(out)} == {("good", "f1"), ("other", "f1")}
    assert not (out / "notes.txt").exists()


def test_resume_over_several_recordings_redoes_only_what_is_missing_and_keeps_each_fruit_once(tmp_path, monkeypatch):
    a = recording(tmp_path / "a", "f1", "f2")
    b = recording(tmp_path / "b", "f1")
    out = tmp_path / "out"
    first = run_batch([a, b], out, method="raw", progress=False)
    whole = _rows(out)
    assert first.ok and len(whole) == 3
    shutil.rmtree(out / "a" / "f2")  # as a run killed before a/f2 and b/f1 would have left it, had b been done
    reads = []
    real = FolderSource.read

    def read(self, index):
        reads.append((self.path.name, self.names()[index]))
        return real(self, index)

    monkeypatch.setattr(FolderSource, "read", read)
    again = run_batch([a, b], out, method="raw", resume=True, progress=False)
    assert reads == [("a", "f2")] and again.done == ["a/f2"] and again.skipped == ["a/f1", "b/f1"] and again.ok
    assert _rows(out) == whole  # every fruit once, in the same order


def test_an_input_in_the_output_given_twice_or_missing_is_refused_before_anything_is_written(tmp_path):
    from symfruit import FileFormatError, InputError, OutputError

    rec = recording(tmp_path / "rec", "f1")
    out = tmp_path / "out"
    inside = recording(out / "old", "f1")
    with pytest.raises(OutputError, match="this input is the output folder"):
        run_batch([rec, out], out, method="raw", progress=False)
    with pytest.raises(OutputError, match="this input lies inside the output folder"):
        run_batch([rec, inside], out, method="raw", progress=False)
    with pytest.raises(InputError, match="the same recording as"):
        run_batch([rec, tmp_path / "." / "rec"], tmp_path / "o2", method="raw", progress=False)
    with pytest.raises(FileFormatError, match="no such frame folder"):
        run_batch([rec, tmp_path / "missing"], tmp_path / "o2", method="raw", progress=False)
    with pytest.raises(InputError, match="no recording given"):
        run_batch([], tmp_path / "o2", method="raw", progress=False)
    assert sorted(p.name for p in out.iterdir()) == ["old"] and not (tmp_path / "o2").exists()


def test_recording_folders_never_take_the_runs_own_names(tmp_path):
    from symfruit.batch import plan_recordings

    inputs = [tmp_path / p for p in ("data/errors.json", "data/report", "x/row1", "y/row1", "z/row2.bag")]
    for path in inputs:
        path.mkdir(parents=True)
    plans = plan_recordings(inputs, tmp_path / "out")
    names = [p.name for p in plans]
    assert names[0].startswith("errors.json+") and names[1].startswith("report+")
    assert names[2].startswith("row1+") and names[3].startswith("row1+") and names[2] != names[3]
    assert names[4] == "row2.bag" and plans[4].folder == tmp_path / "out" / "row2.bag"
    assert [p.key for p in plans] == [n + "/" for n in names]
    assert plan_recordings(inputs, tmp_path / "out") == plans  # the same inputs, the same names (--resume)


def test_a_full_disk_in_one_recording_leaves_the_later_recordings_recorded_as_not_reached(tmp_path, monkeypatch):
    from symfruit import OutputError

    a = recording(tmp_path / "a", "f1", "f2", "f3")
    b = recording(tmp_path / "b", "f1")
    real = batch.write_detections

    def write(folder, found, **kwargs):
        if folder.parent.name == "a" and folder.name == "f2":
            raise OutputError(f"{folder}/overlay.png: cannot write (No space left on device)", errno.ENOSPC)
        return real(folder, found, **kwargs)

    monkeypatch.setattr(batch, "write_detections", write)
    report = run_batch([a, b], tmp_path / "out", method="raw", progress=False)
    assert report.done == ["a/f1"] and list(report.failed) == ["a/f2"] and report.unprocessed == ["a/f3", "b/f1"]
    assert "stopped at frame a/f2: the output is full" in report.stopped
    errors = json.loads((tmp_path / "out" / "errors.json").read_text())
    assert errors["unprocessed"] == ["a/f3", "b/f1"] and not (tmp_path / "out" / "b").exists()


def test_a_frame_named_as_the_bag_the_run_writes_in_the_output_gets_a_folder_of_its_own(tmp_path):
    rec = recording(tmp_path / "rec", "f1", "bag")
    out = tmp_path / "out"
    (out / "bag").mkdir(parents=True)
    (out / "bag" / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")  # the bag's own file
    report = run_batch(rec, out, method="raw", progress=False, exclude=[out / "bag"])
    assert report.ok and report.done == ["bag", "f1"]
    (renamed,) = [p for p in out.iterdir() if p.name.startswith("bag+")]
    assert (renamed / "detections.json").is_file() and sorted(p.name for p in (out / "bag").iterdir()) == [
        "metadata.yaml"
    ]


def test_a_masks_folder_in_the_output_is_an_input_no_frame_writes_into(tmp_path):
    from symfruit.io.frames import read_frame
    from symfruit.segment import segment

    rec = recording(tmp_path / "rec", "f1", "masks", "overlay")
    out = tmp_path / "out"
    (out / "masks").mkdir(parents=True)
    labels = segment(read_frame(rec / "f1").color).astype(np.uint16)
    for name in ("f1", "masks", "overlay"):
        Image.fromarray(labels).save(out / "masks" / f"{name}.png")
    before = {p.name: p.read_bytes() for p in (out / "masks").iterdir()}
    report = run_batch(rec, out, masks=str(out / "masks"), method="raw", progress=False)
    assert report.ok and report.done == ["f1", "masks", "overlay"]
    # before: frame "masks" wrote its detections.json, fruit PLYs and overlay.png into the masks folder, its
    # overlay.png over frame "overlay"'s label image
    assert {p.name: p.read_bytes() for p in (out / "masks").iterdir()} == before
    (renamed,) = [p for p in out.iterdir() if p.name.startswith("masks+")]
    assert (renamed / "detections.json").is_file()


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"masks": ""}, "--masks ''"),
        ({"masks": "missing.png"}, "no such file or folder"),
        ({"masks": "onnx:missing.onnx"}, "missing.onnx"),
        ({"method": "nope"}, "unknown method 'nope'"),
    ],
)
def test_a_masks_spec_or_method_no_frame_can_use_is_refused_before_any_frame(tmp_path, monkeypatch, kwargs, message):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(symfruit.SymfruitError, match=re.escape(message)):  # before: each frame failed with it
        run_batch(EXAMPLE_FRAME, tmp_path / "out", progress=False, **kwargs)
    assert not (tmp_path / "out").exists()


def test_an_empty_recording_or_output_path_is_refused_not_read_as_the_working_folder(tmp_path, monkeypatch):
    from symfruit import InputError
    from symfruit.batch import segment_images

    monkeypatch.chdir(tmp_path)
    shutil.copytree(small_frame(), tmp_path / "f1")
    with pytest.raises(InputError, match="run_batch: the output folder is an empty path"):
        run_batch("f1", "", method="raw", progress=False)  # before: the results written into the working folder
    for source in ("", ["f1", ""]):  # before: '.: neither a frame folder ...', the working folder as a recording
        with pytest.raises(InputError, match="the recording is an empty path"):
            run_batch(source, "out", method="raw", progress=False)
    with pytest.raises(InputError, match="segment_images: the output folder is an empty path"):
        segment_images(["f1/color.png"], output="")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f1"]  # nothing written
    assert run_batch(b"f1", "out", method="raw", progress=False).done == ["f1"]  # a bytes path is one recording


def test_a_warning_every_frame_gives_is_shown_once_per_recording(tmp_path, capsys):
    """Intrinsics that put the principal point outside the image: a warning per frame read. Before (stop 41):
    one line per frame (10,000 for a folder of 10,000 frames with distorted lenses)."""
    rec = recording(tmp_path / "rec", "a", "b", "c")
    for name in "abc":  # the small frame's own cx -80 is filtered out of every test (conftest)
        cam = json.loads((rec / name / "camera.json").read_text())
        (rec / name / "camera.json").write_text(json.dumps({**cam, "cx": -81.0}))
    assert main(["detect", str(rec), "--output", str(tmp_path / "out"), "--method", "raw"]) == 0
    err = capsys.readouterr().err
    assert err.count("principal point") == 1 and f"{rec}/a/camera.json: the principal point" in err
    assert f"symfruit: warning: {rec}: 2 more frames gave a warning above (each is shown for its first frame" in err
    with pytest.warns(symfruit.SymfruitWarning, match="principal point") as caught:  # other filters as before
        run_batch(rec, tmp_path / "out2", method="raw", progress=False)
    assert [str(w.message).count("principal point") for w in caught] == [1, 0]
