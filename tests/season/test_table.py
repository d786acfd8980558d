"""The fruit tables: one row per fruit from each frame's detections.json record, written atomically, whole after
--resume with each fruit once, and a record that is not one refused by name."""

import json
import os
import shutil

import pyarrow.parquet as pq
import pytest

from symfruit import FileFormatError
from symfruit.batch import run_batch
from symfruit.season.table import FRUIT_COLUMNS, TableWriter, frame_rows, read_frame_rows, recording_name

from ..conftest import small_frame

RECORD = {
    "frame": "f1",
    "header": {"frame_id": "camera_color_optical_frame", "stamp": {"sec": 1700000000, "nanosec": 5}},
    "timings": {"total": 0.25},
    "fruits": [
        {"id": 1, "mask_area": 1500, "n_points": 1200, "truncated": False, "centre": [0.01, -0.02, 0.35],
         "box": {"min": [0, 0, 0], "max": [0.03, 0.04, 0.02], "size": [0.03, 0.04, 0.02]}, "method": "evidence",
         "confidence": 0.8, "reliable": True},
        {"id": 2, "mask_area": 40, "n_points": 3, "truncated": True, "error": "too few points"},
    ],
}  # fmt: skip


def test_a_record_gives_one_row_per_fruit_and_one_per_frame():
    frame, fruits = frame_rows(RECORD, "rec")
    assert frame == {"recording": "rec", "frame": "f1", "stamp": 1_700_000_000_000_000_005, "fruit": 2, "located": 1,
                     "seconds": 0.25}  # fmt: skip
    assert [list(f) for f in fruits] == [[name for name, _ in FRUIT_COLUMNS]] * 2
    assert fruits[0] | {"stamp": None} == {
        "recording": "rec", "frame": "f1", "stamp": None, "id": 1, "centre_x": 0.01, "centre_y": -0.02,
        "centre_z": 0.35, "size_x": 0.03, "size_y": 0.04, "size_z": 0.02, "confidence": 0.8, "reliable": True,
        "method": "evidence", "mask_area": 1500, "points": 1200, "truncated": False, "error": None,
    }  # fmt: skip
    assert fruits[1]["error"] == "too few points" and fruits[1]["centre_x"] is None and fruits[1]["truncated"]


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"fruits": "many"}, "no list of fruits"),
        ({"frame": None}, "no frame name"),
        ({"fruits": [{"id": "one"}]}, r"fruits\[0\].id is str"),
        ({"fruits": [{"id": 1, "centre": [1, 2]}]}, r"fruits\[0\].centre is not three numbers"),
        ({"fruits": [{"id": 2**40}]}, r"fruits\[0\].id is missing or out of range"),
        ({"header": {"stamp": {"sec": -1, "nanosec": 0}}}, "is not a time"),
        ({"fruits": [{"id": 1, "reliable": "yes"}]}, "not true or false"),
        # values no run writes, which `symfruit report` refuses for the whole table (were taken in)
        ({"fruits": [{"id": 1, "box": {"size": [-0.02, 0.04, 0.02]}}]}, r"fruits\[0\].box.size holds -0.02 m"),
        ({"fruits": [{"id": 1, "box": {"size": [0.02, 1e300, 0.02]}}]}, r"box.size holds 1e\+300 m"),
        ({"fruits": [{"id": 1, "confidence": 7.0}]}, r"fruits\[0\].confidence is 7; a confidence is in \[0, 1\]"),
        ({"fruits": [{"id": k} for k in range(1, 1002)]}, "holds 1001 fruits; a frame holds at most 1000"),
        # stop 51 (robust51): a NaN or null coordinate was left empty and the fruit counted as located; a whole
        # number of 400 digits was Python's OverflowError
        (
            {"fruits": [{"id": 1, "centre": [0.0, float("nan"), 0.3]}]},
            r"fruits\[0\].centre is not three finite "
            r"numbers of metres within 100$",
        ),
        ({"fruits": [{"id": 1, "centre": [None, 0.0, 0.3]}]}, r"fruits\[0\].centre is not three finite"),
        ({"fruits": [{"id": 1, "centre": [0.0, 0.0, 1e6]}]}, r"fruits\[0\].centre is not three finite"),
        (
            {"fruits": [{"id": 1, "centre": [10**400, 0.0, 0.3]}]},
            r"fruits\[0\].centre is a whole number beyond a "
            r"float's range$",
        ),
        ({"fruits": [{"id": 1, "confidence": 10**400}]}, r"fruits\[0\].confidence is a whole number beyond"),
        ({"fruits": [{"id": 10**400}]}, r"fruits\[0\].id is 100000000000\.\.\. \(401 digits\), not a whole number$"),
    ],
)
def test_a_record_that_is_not_one_is_refused_by_name(tmp_path, change, message):
    path = tmp_path / "detections.json"
    path.write_text(json.dumps({**RECORD, **change}))
    with pytest.raises(FileFormatError, match=message) as info:
        read_frame_rows(path, "rec")
    assert str(info.value).startswith(str(path))


def test_the_tables_appear_whole_or_not_at_all(tmp_path):
    with TableWriter(tmp_path) as table:
        table.add(*frame_rows(RECORD, "rec"))
    before = pq.read_table(tmp_path / "detections.parquet")
    assert before.num_rows == 2 and pq.read_table(tmp_path / "frames.parquet").num_rows == 1
    with pytest.raises(RuntimeError), TableWriter(tmp_path) as table:
        table.add(*frame_rows({**RECORD, "frame": "f2"}, "rec"))
        raise RuntimeError("the run dies")
    assert pq.read_table(tmp_path / "detections.parquet").equals(before)  # the earlier table stays
    assert sorted(p.name for p in tmp_path.iterdir()) == ["detections.parquet", "frames.parquet"]


def test_names_that_are_not_utf8_go_into_the_tables_escaped(tmp_path):
    name = os.fsdecode(b"row\xff")  # a folder named with bytes that are not UTF-8: Python keeps "row\udcff"
    with TableWriter(tmp_path) as table:
        table.add(*frame_rows({**RECORD, "frame": name}, name))
    rows = pq.read_table(tmp_path / "frames.parquet", columns=["recording", "frame"]).to_pylist()
    assert rows == [{"recording": "row\\udcff", "frame": "row\\udcff"}]


def test_recording_inputs_named_with_bytes_that_are_not_utf8_come_back_as_the_column_holds_them():
    from symfruit.season.table import INPUTS_KEY, recording_inputs

    name = os.fsdecode(b"row\xfe")
    metadata = {INPUTS_KEY.encode(): json.dumps({name: f"/data/{name}"}).encode()}
    assert recording_inputs(metadata) == {"row\\udcfe": "/data/row\\udcfe"}  # printable, and keys match rows
    assert frame_rows(RECORD, name)[0]["recording"] == "row\\udcfe"


def test_row_groups_stream_and_an_empty_run_has_empty_tables(tmp_path, monkeypatch):
    from symfruit.season import table as module

    monkeypatch.setattr(module, "ROW_GROUP", 3)
    with TableWriter(tmp_path) as table:
        for k in range(4):
            table.add(*frame_rows({**RECORD, "frame": f"f{k}"}, "rec"))
    meta = pq.ParquetFile(tmp_path / "detections.parquet").metadata
    assert meta.num_rows == 8 and meta.num_row_groups >= 2
    with TableWriter(tmp_path / "empty"):
        pass
    assert pq.read_table(tmp_path / "empty" / "detections.parquet").num_rows == 0


def test_a_serial_run_writes_the_tables_and_resume_keeps_each_fruit_once(tmp_path):
    rec = tmp_path / "rec"
    for name in ("f1", "f2", "f3"):
        shutil.copytree(small_frame(), rec / name)  # one fruit each
    (rec / "f2" / "depth.png").write_bytes(b"broken")
    out = tmp_path / "out"
    report = run_batch(rec, out, method="raw", progress=False)
    rows = pq.read_table(out / "detections.parquet").to_pylist()
    assert len(rows) == report.fruits == 2 and {r["frame"] for r in rows} == {"f1", "f3"}
    assert {r["recording"] for r in rows} == {"rec"} and all(r["method"] == "raw" for r in rows)
    json_centres = [f["centre"] for f in json.loads((out / "f1" / "detections.json").read_text())["fruits"]]
    assert [[r["centre_x"], r["centre_y"], r["centre_z"]] for r in rows if r["frame"] == "f1"] == json_centres
    shutil.copytree(small_frame(), rec / "f2", dirs_exist_ok=True)
    again = run_batch(rec, out, method="raw", resume=True, progress=False)
    assert again.done == ["f2"] and again.skipped == ["f1", "f3"]
    rows = pq.read_table(out / "detections.parquet").to_pylist()
    assert len(rows) == 3 and len({(r["frame"], r["id"]) for r in rows}) == 3
    assert pq.read_table(out / "frames.parquet").column("frame").to_pylist() == ["f1", "f2", "f3"]
    (out / "f3" / "detections.json").write_text('{"frame": "f3", "fruits": 7}')  # damaged since: run again
    damaged = run_batch(rec, out, method="raw", resume=True, progress=False)
    assert damaged.done == ["f3"] and damaged.skipped == ["f1", "f2"] and damaged.ok
    assert {r["frame"] for r in pq.read_table(out / "detections.parquet").to_pylist()} == {"f1", "f2", "f3"}
    record = json.loads((out / "f1" / "detections.json").read_text())
    record["fruits"][0]["box"]["size"][0] = -0.02  # no completion writes it: `symfruit report` refused the run
    (out / "f1" / "detections.json").write_text(json.dumps(record))
    tampered = run_batch(rec, out, method="raw", resume=True, progress=False)
    assert tampered.done == ["f1"] and tampered.skipped == ["f2", "f3"] and tampered.ok  # before: f1 skipped
    assert min(r["size_x"] for r in pq.read_table(out / "detections.parquet").to_pylist()) > 0


def test_a_frame_named_like_a_table_gets_a_folder_of_its_own(tmp_path):
    rec = tmp_path / "rec"
    shutil.copytree(small_frame(), rec / "detections.parquet")
    report = run_batch(rec, tmp_path / "out", method="raw", progress=False)
    assert report.ok and (tmp_path / "out" / "detections.parquet").is_file()
    assert [p.name.startswith("detections.parquet+") for p in (tmp_path / "out").iterdir() if p.is_dir()] == [True]


def test_the_recording_is_named_by_its_input():
    assert recording_name("/data/season/row_12.bag") == "row_12.bag" and recording_name("rec/") == "rec"


def test_a_table_that_cannot_be_opened_leaves_the_earlier_runs_tables_as_they_were(tmp_path, monkeypatch):
    """Robust53 (``detect --resume`` into an output whose frames.parquet became a folder): the second table could
    not be opened, and the first, opened, was put in place of the earlier run's detections.parquet as its header
    alone (4 bytes, no table), its writer left to say "Exception ignored in ParquetWriter.__del__" at exit. Now
    neither table is touched and no writer is left open."""
    import gc
    import sys

    from symfruit import SymfruitError

    with TableWriter(tmp_path) as table:  # an earlier run's tables
        table.add(*frame_rows(RECORD, "rec"))
    before = (tmp_path / "detections.parquet").read_bytes()
    (tmp_path / "frames.parquet").unlink()
    (tmp_path / "frames.parquet").mkdir()
    unraised: list = []
    monkeypatch.setattr(sys, "unraisablehook", unraised.append)
    with pytest.raises(SymfruitError, match=r"frames\.parquet: is a folder"), TableWriter(tmp_path):
        pass
    gc.collect()
    assert (tmp_path / "detections.parquet").read_bytes() == before
    assert not unraised, [str(u.exc_value) for u in unraised]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["detections.parquet", "frames.parquet"]  # no temporary
