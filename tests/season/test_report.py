"""symfruit report: report.md and its plots from a run's tables, numbers a reader can check, written atomically;
tables that are missing, too large or not symfruit's refused by name."""

import json
import re

import numpy as np
import pytest
from PIL import Image

from symfruit import FileFormatError, InputError
from symfruit.cli import main
from symfruit.season.report import PER_RECORDING_PLOTS, PLOTS, diameters_mm, size_classes, write_report
from symfruit.season.table import TableWriter

#: one worker runs the module's tests one after another and writes the shared report once (pytest-xdist, --dist
#: loadgroup: a worker that interleaved other modules' tests would tear the module-scoped fixture down between them);
#: the group of tests/evaluate/test_evaluate.py, whose run draws plots too: one worker imports matplotlib, not both
pytestmark = pytest.mark.xdist_group("evaluate")


def _record(frame: str, sizes: list[tuple[float, float, float]], *, cut: int = 0, failed: int = 0) -> dict:
    fruits = [{"id": k + 1, "mask_area": 900, "n_points": 700, "truncated": k < cut, "centre": [0.0, 0.0, 0.4],
               "box": {"size": list(s)}, "method": "evidence", "confidence": 0.9 - 0.1 * k, "reliable": k % 2 == 0}
              for k, s in enumerate(sizes)]  # fmt: skip
    fruits += [{"id": len(sizes) + k + 1, "mask_area": 30, "n_points": 4, "truncated": False, "error": "too few"}
               for k in range(failed)]  # fmt: skip
    return {"frame": frame, "header": {}, "timings": {"total": 0.1}, "fruits": fruits}


def _run(out):
    """A run of two recordings: 'row1' 3 frames (one without fruit), 'row2' 1 frame; 7 fruit seen, 6 located,
    5 sized (one cut by the border), diameters 16, 20, 24, 30 and 40 mm."""
    from symfruit.season.table import frame_rows

    out.mkdir()
    with TableWriter(out) as table:
        table.add(*frame_rows(_record("a", [(0.016, 0.02, 0.01), (0.02, 0.03, 0.012)], failed=1), "row1"))
        table.add(*frame_rows(_record("b", []), "row1"))
        table.add(*frame_rows(_record("c", [(0.05, 0.05, 0.05), (0.01, 0.02, 0.024)], cut=1), "row1"))
        table.add(*frame_rows(_record("d", [(0.03, 0.02, 0.01), (0.02, 0.02, 0.04)]), "row2"))
    (out / "errors.json").write_text('{"failed": [{"frame": "e", "reason": "broken"}], "stopped": ""}')
    return out


@pytest.fixture
def run(tmp_path):
    """The run of :func:`_run`, the test's own."""
    return _run(tmp_path / "out")


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """``(run, report)``: the run of :func:`_run` and its report, written once for the tests that only read it
    (drawing the plots is most of a report's time)."""
    out = _run(tmp_path_factory.mktemp("report") / "out")
    return out, write_report(out)


def test_the_report_counts_sizes_and_classes_as_a_reader_would(written):
    run, report = written
    assert (report.frames, report.fruit, report.located, report.sized, report.recordings, report.failed_frames) == (
        4, 7, 6, 5, 2, 1)  # fmt: skip
    text = (run / "report" / "report.md").read_text()
    assert "2 recording(s), 4 frames and 7 fruit seen, of which 6 were located" in text
    assert "| row1 | 3 | 2 | 5 | 4 | 1.33 | 2 | 20.0 |" in text  # diameters 16, 20, 24 mm
    assert "| row2 | 1 | 1 | 2 | 2 | 2.00 | 2 | 35.0 |" in text  # 30, 40 mm
    assert "| < 18 mm | 1 | 20.0 % |" in text and "| 18-25 mm | 2 | 40.0 % |" in text
    assert "| >= 25 mm | 2 | 40.0 % |" in text and "1 frame(s) could not be processed" in text
    assert "5 fruit sized: median diameter 24.0 mm" in text
    for name in (*PLOTS, *PER_RECORDING_PLOTS):
        assert f"]({name})" in text
        with Image.open(run / "report" / name) as img:
            assert img.format == "PNG" and img.size[0] >= 600
    assert sorted(p.name for p in (run / "report").iterdir()) == sorted([*PLOTS, *PER_RECORDING_PLOTS, "report.md"])


def test_diameters_and_classes():
    assert diameters_mm(np.array([0.018]), np.array([0.0175])).tolist() == [18.0]
    assert size_classes(np.array([17.99, 18.0, 24.99, 25.0]), [18, 25]) == [("< 18 mm", 1), ("18-25 mm", 2),
                                                                            (">= 25 mm", 1)]  # fmt: skip
    for bad in ([], [25, 18], [0, 10], [18, float("nan")]):
        with pytest.raises(InputError, match="increasing diameters"):
            size_classes(np.ones(1), bad)
    for bad in ("18", None, 18):  # before: "18" read a character at a time as classes 1 and 8 mm; TypeErrors
        with pytest.raises(InputError, match=r"size classes must be a list of diameters in mm such as \[18, 25\]"):
            size_classes(np.ones(1), bad)
    for bad in ([True, 25], [[18], [25]], ["18", "25"]):  # before: True read as 1 mm, float()'s TypeError, "18" taken
        with pytest.raises(InputError, match="size classes must be diameters in mm, got"):
            size_classes(np.ones(1), bad)
    assert size_classes(np.array([20.0]), np.array([18, 25])) == size_classes(np.array([20.0]), (18.0, 25))


def test_the_command_writes_into_the_folder_named(run, tmp_path, capsys):
    assert main(["report", str(run), "--output", str(tmp_path / "season"), "--classes", "20,30,35"]) == 0
    assert "2 recording(s), 4 frames, 7 fruit seen, 6 located, 5 sized" in capsys.readouterr().out
    assert "| 30-35 mm | 1 | 20.0 % |" in (tmp_path / "season" / "report.md").read_text()
    assert main(["report", str(run), "--classes", "big"]) == 2
    assert "--classes 'big'" in capsys.readouterr().err
    assert main(["report", str(tmp_path / "nothing")]) == 2
    assert "nothing: no such folder; `symfruit report` reads the --output folder" in capsys.readouterr().err


@pytest.mark.parametrize("where", ["f0", "rec/f0"])
def test_a_run_without_tables_but_with_frame_records_is_told_to_resume(tmp_path, capsys, where):
    """A run killed before its end (the tables appear when it ends), or one written by a symfruit before the
    tables (2026-12-01): its frames' records are there, and `detect --resume` writes the tables from them."""
    out = tmp_path / "out"
    (out / where).mkdir(parents=True)
    (out / where / "detections.json").write_text(json.dumps(_record("f0", [(0.03, 0.03, 0.03)])))
    assert main(["report", str(out)]) == 2  # before: "no such table; run `symfruit detect ...` first"
    err = capsys.readouterr().err
    assert "no such table, but the run's frame records are there" in err and f"--output {out} --resume" in err


def test_tables_too_large_or_not_ours_are_refused(run, monkeypatch):
    from symfruit.season import report as module

    monkeypatch.setattr(module, "MAX_REPORT_ROWS", 3)
    with pytest.raises(FileFormatError, match="7 rows; a report reads at most 3"):
        write_report(run)
    monkeypatch.undo()
    (run / "frames.parquet").write_bytes(b"PAR1 not really")
    with pytest.raises(FileFormatError, match=r"frames\.parquet: cannot read table"):
        write_report(run)
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq.write_table(pa.table({"x": [1]}), run / "frames.parquet")
    with pytest.raises(FileFormatError, match="not a symfruit table"):
        write_report(run)
    assert not (run / "report").exists()
    (run / "frames.parquet").unlink()
    (run / "frames.parquet").mkdir()  # was "no such table; run `symfruit detect` first"
    with pytest.raises(FileFormatError, match=r"frames\.parquet: a directory, not a file"):
        write_report(run)


def test_box_sides_no_completion_writes_and_unbounded_classes_are_refused(tmp_path):
    # a side of 1e300 m ended the report in an OverflowError (the histogram's bins), 1e6 m asked for a billion
    # bins, a negative one was counted as a sized fruit; --classes 18,1e9 asked for a billion bins too
    from symfruit.season.table import frame_rows

    for side, shown in ((1e300, r"1e\+300"), (-0.02, "-0.02"), (2e3, "2000")):
        out = tmp_path / f"out{side:g}"
        out.mkdir()
        frame, fruits = frame_rows(_record("a", [(0.02, 0.02, 0.02), (0.02, 0.02, 0.02)]), "row1")
        fruits[1]["size_x"] = side  # a table another tool wrote: frame_rows refuses such a record itself
        with TableWriter(out) as table:
            table.add(frame, fruits)
        with pytest.raises(FileFormatError, match=rf"detections\.parquet: row 2 has size_x {shown} m; box sides"):
            write_report(out)
        assert not (out / "report").exists()
    with pytest.raises(InputError, match=r"a limit of 1e\+09 mm; diameters are in mm, at most 10000"):
        size_classes(np.ones(1), [18, 1e9])
    with pytest.raises(InputError, match=r"size classes: 51 limits; at most 50"):
        size_classes(np.ones(1), list(range(1, 52)))


def test_an_errors_json_that_is_not_ours_is_refused_not_counted_as_no_failures(run):
    (run / "errors.json").write_text('{"failed": 5}')  # counted no failed frame
    with pytest.raises(FileFormatError, match=r"errors\.json: not a symfruit errors\.json \('failed' is not a list\)"):
        write_report(run)
    (run / "errors.json").unlink()
    (run / "errors.json").mkdir()
    with pytest.raises(FileFormatError, match=r"errors\.json: a directory, not a file"):
        write_report(run)


def test_without_matplotlib_the_message_names_the_extra(run, monkeypatch):
    import builtins

    real = builtins.__import__

    def no_matplotlib(name, *args, **kwargs):
        if name.startswith("matplotlib"):
            raise ImportError(name)
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_matplotlib)
    with pytest.raises(InputError, match=r"pip install 'symfruit\[plot\]'"):
        write_report(run)


def test_each_recording_gets_its_sizes_and_a_run_of_one_recording_no_boxes(written, run, tmp_path):
    text = written[1].folder.joinpath("report.md").read_text()
    assert "| recording | fruit sized | 10 % below (mm) | median (mm) | 10 % above (mm) | < 18 mm | 18-25 mm | " in text
    assert "| row1 | 3 | 16.8 | 20.0 | 23.2 | 1 | 2 | 0 |" in text  # diameters 16, 20, 24 mm
    assert "| row2 | 2 | 31.0 | 35.0 | 39.0 | 0 | 0 | 2 |" in text  # 30, 40 mm
    (run / "errors.json").write_text('{"failed": [], "stopped": "", "recordings": [{"recording": "x", "input": "x", '
                                     '"reason": "not a bag"}]}')  # fmt: skip
    report = write_report(run, folder=tmp_path / "again")
    assert report.failed_recordings == 1 and report.failed_frames == 0
    assert "1 recording(s) could not be read (see `errors.json`)" in (tmp_path / "again" / "report.md").read_text()
    from symfruit.season.table import frame_rows

    one = tmp_path / "one"
    one.mkdir()
    with TableWriter(one) as table:
        table.add(*frame_rows(_record("a", [(0.02, 0.02, 0.02)]), "row1"))
    single = write_report(one)
    assert sorted(p.name for p in single.folder.iterdir()) == sorted([*PLOTS, "report.md"])
    assert "Sizes per recording" not in (single.folder / "report.md").read_text()


def test_a_report_folder_that_links_out_of_the_run_is_refused_not_written_through(run, tmp_path, capsys):
    (tmp_path / "elsewhere").mkdir()
    (run / "report").symlink_to(tmp_path / "elsewhere")
    assert main(["report", str(run)]) == 2
    err = capsys.readouterr().err
    assert f"{run / 'report'}: is a symbolic link (to {tmp_path / 'elsewhere'}); symfruit does not write" in err
    assert not list((tmp_path / "elsewhere").iterdir())
    assert main(["report", str(run), "--output", str(run / "report")]) == 0  # named: the user's own choice
    assert (tmp_path / "elsewhere" / "report.md").is_file()


@pytest.mark.parametrize("inside", [".", "row1", "row1/a", "row1/../row2/d"])
def test_a_report_folder_inside_the_run_other_than_its_own_is_refused(run, capsys, inside):
    (run / "row1" / "a").mkdir(parents=True)
    (run / "row2" / "d").mkdir(parents=True)
    before = sorted(str(p.relative_to(run)) for p in run.rglob("*"))
    assert main(["report", str(run), "--output", str(run / inside)]) == 2  # before: written into the frame's folder
    err = capsys.readouterr().err
    assert f"{run / inside}: is inside the run {run} (its own folder, a recording's or a frame's" in err
    assert sorted(str(p.relative_to(run)) for p in run.rglob("*")) == before


@pytest.mark.parametrize(
    "table, column, value, message",
    [
        ("detections.parquet", "confidence", 1e300, r"detections\.parquet: row 1 has confidence 1e\+300; a confidence "
         r"is in \[0, 1\]"),
        ("detections.parquet", "confidence", -0.5, r"row 1 has confidence -0\.5"),
        ("frames.parquet", "located", -5, r"frames\.parquet: row 1 has -5 of 3 fruit located; a frame holds 0-1000 "
         r"fruit, located 0 to them \(not a symfruit table, or damaged\)"),
        ("frames.parquet", "fruit", 2**31 - 1, r"row 1 has 2 of 2147483647 fruit located"),
    ],
)  # fmt: skip
def test_counts_and_confidences_no_run_writes_are_refused_not_reported(run, table, column, value, message):
    import pyarrow as pa
    import pyarrow.parquet as pq

    t = pq.read_table(run / table)
    k = t.schema.get_field_index(column)
    t = t.set_column(k, t.schema.field(k), pa.array([value] * t.num_rows, type=t.schema.field(k).type))
    pq.write_table(t, run / table)
    with pytest.raises(FileFormatError, match=message):
        write_report(run)
    assert not (run / "report").exists()


@pytest.mark.parametrize(
    "table, column, values, message",
    [("detections.parquet", "size_x", "a", r"column size_x holds string, not float64"),  # before: ValueError
     ("detections.parquet", "reliable", "yes", r"column reliable holds string, not bool"),  # before: all unreliable
     ("frames.parquet", "fruit", 1.5, r"column fruit holds double, not int32"),  # before: read as 1
     ("frames.parquet", "located", None, r"column located has 4 empty rows; every frame has its count")],
)  # fmt: skip
def test_columns_of_another_type_are_refused_by_name(run, table, column, values, message):
    import pyarrow as pa
    import pyarrow.parquet as pq

    t = pq.read_table(run / table)
    k = t.schema.get_field_index(column)
    kind = pa.int32() if values is None else None
    t = t.set_column(k, column, pa.array([values] * t.num_rows, type=kind))
    pq.write_table(t, run / table)
    with pytest.raises(FileFormatError, match=rf"{table}: {message} \(not a symfruit table, or damaged\)$"):
        write_report(run)
    assert not (run / "report").exists()


def test_write_report_refuses_an_empty_run_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match="write_report: the run folder is an empty path"):
        write_report("")  # before: the working folder read as the run ('./detections.parquet: no such table')


def test_rows_are_grouped_by_recording_in_one_sort_keeping_their_order():
    from symfruit.season.report import _groups

    keys = np.array(["b", "a", "b", "c", "a", "b"])
    assert [g.tolist() for g in _groups(keys, ["a", "b"])] == [[1, 4], [0, 2, 5]]  # "c": in no group
    assert [g.tolist() for g in _groups(keys[:0], ["a"])] == [[]]


def test_a_recording_name_holding_a_bar_or_a_line_break_stays_in_its_table_cell(tmp_path):
    from symfruit.season.table import frame_rows

    out = tmp_path / "out"
    out.mkdir()
    with TableWriter(out) as table:
        table.add(*frame_rows(_record("a", [(0.02, 0.03, 0.012)]), "row|1"))
        table.add(*frame_rows(_record("b", [(0.03, 0.02, 0.01)]), "row\n2"))
    write_report(out)
    rows = [line for line in (out / "report" / "report.md").read_text().splitlines() if line.startswith("| row")]
    # before: "| row|1 | 1 | ..." (its numbers one column on) and a row cut in two by the line break
    assert rows[0].startswith("| row\\|1 | 1 | 1 | 1 | 1 |") and rows[1].startswith("| row 2 | 1 | 1 | 1 | 1 |")
    assert len(rows) == 4 and all(row.replace("\\|", "").count("|") == rows[0].replace("\\|", "").count("|")
                                  for row in rows[:2])  # fmt: skip


def test_a_run_that_is_a_file_or_a_runs_table_is_said_to_be_so(run, tmp_path, capsys):
    """Stop 48 (robust48): a file was "FILE/detections.parquet: no such table; run `symfruit detect ... --output
    FILE` first"."""
    text = tmp_path / "notes.txt"
    text.write_text("x")
    assert main(["report", str(text)]) == 2
    said = "not a folder; `symfruit report` reads the --output folder of a `symfruit detect` run (with detections"
    assert capsys.readouterr().err.strip() == f"symfruit: error: {text}: {said}.parquet)"
    assert main(["report", str(run / "detections.parquet")]) == 2
    assert f"is a run's table; name the run's folder: `symfruit report {run}`" in capsys.readouterr().err
    (tmp_path / "empty").mkdir()
    assert main(["report", str(tmp_path / "empty")]) == 2  # a folder without tables: as before
    assert "empty/detections.parquet: no such table; run `symfruit detect" in capsys.readouterr().err


def _edited(run, table, edit):
    import pyarrow as pa
    import pyarrow.parquet as pq

    t = pq.read_table(run / table)
    rows = edit(t.to_pylist())
    pq.write_table(pa.Table.from_pylist(rows, schema=t.schema) if rows else t.schema.empty_table(), run / table)


@pytest.mark.parametrize(
    "table, edit, message",
    [
        ("frames.parquet", lambda r: [*r, r[0]], r"frames\.parquet: frame 'row1'/'a' is listed 2 times; a run lists "
         r"each frame once \(not a symfruit table, or damaged\)$"),
        ("detections.parquet", lambda r: [*r, r[0]], r"detections\.parquet: fruit 1 of frame 'row1'/'a' is listed 2 "
         r"times"),
        ("detections.parquet", lambda r: [dict(r[0], frame="zz"), *r[1:]], r"detections\.parquet: holds 1 fruit of "
         r"frame 'row1'/'zz', which frames\.parquet does not list \(the tables disagree: damaged, or of different "
         r"runs\)$"),
        ("frames.parquet", lambda r: [], r"detections\.parquet: holds \d fruit of frame 'row1'/'a', which"),
        ("detections.parquet", lambda r: [], r"frames\.parquet: frame 'row1'/'a' counts 3 fruit, 2 located, but "
         r"detections\.parquet holds 0 of its fruit, 0 located"),
        ("detections.parquet", lambda r: [dict(r[0], error="failed"), *r[1:]], r"frame 'row1'/'a' counts 3 fruit, 2 "
         r"located, but detections\.parquet holds 3 of its fruit, 1 located"),
        ("frames.parquet", lambda r: [dict(r[0], recording=None), *r[1:]], r"frames\.parquet: column recording has 1 "
         r"empty rows; every row names its recording and frame"),
        ("detections.parquet", lambda r: [dict(r[0], frame=None), *r[1:]], r"detections\.parquet: column frame has 1 "
         r"empty rows"),
    ],
)  # fmt: skip
def test_tables_that_disagree_are_refused_not_reported_as_whole(run, table, edit, message):
    """Stop 50 (robust50): a fruit listed twice was counted and sized twice, a frame listed twice counted twice,
    fruit of a frame frames.parquet does not list sized but in no frame, counts not their rows' reported as they
    stood, a row without its recording a recording 'None' of its own: each a report in silence."""
    _edited(run, table, edit)
    with pytest.raises(FileFormatError, match=message):
        write_report(run)
    assert not (run / "report").exists()


@pytest.mark.parametrize(
    "change, shown",
    [
        ({"centre_x": float("nan")}, "nan, "),
        ({"centre_z": float("inf")}, ", inf"),
        ({"centre_y": -float("inf")}, "-inf"),
        ({"centre_x": 1e6}, "1e+06"),
        ({"centre_y": None}, "empty"),
    ],
)
def test_a_centre_of_nan_inf_or_in_part_is_refused_not_counted_as_located(run, change, shown):
    """Stop 51 (robust51): a NaN centre (a value, not empty) was a located fruit, in the report's counts as in the
    tables' agreement; a centre given in part, or of a million metres, too."""
    _edited(run, "detections.parquet", lambda r: [dict(r[0], **change), *r[1:]])
    with pytest.raises(
        FileFormatError,
        match=rf"detections\.parquet: row 1 has centre \(.*{re.escape(shown)}.*\); "
        r"a located fruit's centre is three numbers of metres within \d+, one not located has none",
    ):
        write_report(run)
    assert not (run / "report").exists()


def test_tables_whose_names_are_of_the_other_text_type_are_compared_alike(run):
    """Another tool may write a name column as large_string: the tables' join took it for another key type
    (pyarrow's ``ArrowInvalid: Incompatible data types for corresponding join field keys``)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    t = pq.read_table(run / "frames.parquet")
    k = t.schema.get_field_index("recording")
    pq.write_table(t.set_column(k, pa.field("recording", pa.large_string()), t.column(k).cast(pa.large_string())),
                   run / "frames.parquet")  # fmt: skip
    assert write_report(run).frames == 4


def test_a_table_this_user_may_not_read_is_refused_in_its_words_not_pyarrows(unreadable_place):
    """Stop 52 (robust52): pyarrow's "PermissionError: [Errno 13] Failed to open local file 'PATH'. Detail:
    [errno 13] Permission denied" inside ours, read as a user who may not."""
    from ..conftest import refusal_unprivileged

    path = unreadable_place / "detections.parquet"
    path.write_bytes(b"PAR1")
    said = refusal_unprivileged(
        "from symfruit.season.report import _read; _read(__import__('pathlib').Path(P0), ['x'])", path)  # fmt: skip
    assert said == f"refused: {path}: cannot read table (Permission denied)"
