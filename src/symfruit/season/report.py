"""``symfruit report OUT``: what a ``detect`` run found, for someone who never ran it: ``report.md`` and PNG plots
(fruit per frame and per recording, fruit diameters against the size classes fruit is sorted by, confidence).
A run over several recordings (``detect A B ... --output OUT``) is also reported recording by recording: fruit
per frame and the diameters of each, with its size classes.

It reads the run's tables (``OUT/detections.parquet``, ``OUT/frames.parquet``: :mod:`symfruit.season.table`) and
``OUT/errors.json``, each checked against a bound before it is read, and writes every file atomically into
``OUT/report/`` (or the folder named), locked while it writes. Millimetres in the report, as in every
printed report; the tables stay in metres.

A fruit's **diameter** is the larger horizontal side of its completed box, ``max(size_x, size_z)``: the
widest horizontal section of a fruit hanging below its stem seen by a level camera, which is what sizing
rings and grading machines measure ("the maximum diameter of the equatorial section" of the EU marketing
standard for strawberries, whose classes start at 18 mm, Classes I and II, and 25 mm, Extra: the default
classes). Fruit cut by the image border (``truncated``) and fruit that could not be completed have no
diameter here; they are counted, not sized.
"""

from __future__ import annotations

import contextlib
import errno
import itertools
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..core.limits import MAX_DEPTH_METRES, MAX_INSTANCES, MAX_TABLE_BYTES, MAX_TABLE_ROWS, shown
from ..errors import FileFormatError, InputError, OutputError, SymfruitError
from ..io.text import as_path
from .table import FRAME_COLUMNS, FRAMES_NAME, FRUIT_COLUMNS, TABLE_NAME, recording_inputs

__all__ = [
    "DEFAULT_CLASSES_MM",
    "PER_RECORDING_PLOTS",
    "PLOTS",
    "Report",
    "diameters_mm",
    "size_classes",
    "write_report",
]

#: Size class edges (mm) by default: the EU marketing standard's minimum diameters for strawberries.
DEFAULT_CLASSES_MM = (18.0, 25.0)
#: Most rows read from either table, and most bytes of its columns (:mod:`symfruit.core.limits`).
MAX_REPORT_ROWS = MAX_TABLE_ROWS
MAX_REPORT_BYTES = MAX_TABLE_BYTES
#: Recordings drawn one bar each; beyond, the ones with most fruit (the table lists them all).
MAX_BARS = 60
#: Size class edges: at most this many, each at most :data:`MAX_CLASS_MM` (a 10 m fruit); the diameter
#: histogram has at most :data:`MAX_HIST_BINS` bins (1 mm wide where that suffices), however wide the sizes.
MAX_CLASSES = 50
MAX_CLASS_MM = 10_000.0
MAX_HIST_BINS = 400
#: Largest box side (m) a fruit row of the table may hold: one beyond (or negative) is no symfruit box.
MAX_SIZE_M = MAX_DEPTH_METRES
#: The plots, in the order report.md shows them.
PLOTS = ("fruit_per_frame.png", "fruit_per_recording.png", "diameters.png", "confidence.png")
#: The plots added when the run holds more than one recording: one box per recording.
PER_RECORDING_PLOTS = ("fruit_per_frame_by_recording.png", "diameters_by_recording.png")


@dataclass
class Report:
    """What :func:`write_report` found and wrote."""

    folder: Path
    frames: int = 0
    fruit: int = 0
    located: int = 0
    sized: int = 0
    recordings: int = 0
    failed_frames: int = 0
    #: Recordings the run could not read (``errors.json``).
    failed_recordings: int = 0
    written: list[Path] = field(default_factory=list)


def _read(path: Path, columns: Sequence[str]) -> Any:
    """The ``columns`` of a Parquet table, after checking its row count and column sizes against the bounds."""
    import pyarrow.parquet as pq

    from ..io.text import holds_file

    if not holds_file(path):  # a directory or broken link of that name says so, not "no such table"
        if not os.path.lexists(path) and _has_records(path.parent):
            # a run stopped before its end (the tables appear when it ends), or one of a symfruit before the tables
            raise FileFormatError(f"{path}: no such table, but the run's frame records are there (a run stopped "
                                  "before its end, or one by an older symfruit): `symfruit detect INPUT --output "
                                  f"{path.parent} --resume` writes the tables from them without detecting "
                                  "again")  # fmt: skip
        raise FileFormatError(f"{path}: no such table; run `symfruit detect ... --output {path.parent}` first")
    try:
        meta = pq.ParquetFile(path).metadata
        if meta.num_rows > MAX_REPORT_ROWS:
            raise FileFormatError(f"{path}: {meta.num_rows:,} rows; a report reads at most {MAX_REPORT_ROWS:,}")
        names = [meta.schema.column(i).name for i in range(meta.num_columns)]
        missing = [c for c in columns if c not in names]
        if missing:
            raise FileFormatError(f"{path}: not a symfruit table (no column {', '.join(missing)})")
        wanted = {names.index(c) for c in columns}
        size = sum(meta.row_group(g).column(i).total_uncompressed_size for g in range(meta.num_row_groups)
                   for i in wanted)  # fmt: skip
        if size > MAX_REPORT_BYTES:
            raise FileFormatError(f"{path}: its columns hold {size / 2**30:.1f} GB; a report reads at most "
                                  f"{MAX_REPORT_BYTES / 2**30:.0f} GB")  # fmt: skip
        table = pq.read_table(path, columns=list(columns))
    except SymfruitError:
        raise
    except PermissionError:  # pyarrow's "[Errno 13] Failed to open local file 'PATH'. Detail: ..." (robust52)
        raise FileFormatError(f"{path}: cannot read table ({os.strerror(errno.EACCES)})") from None
    except Exception as exc:  # pyarrow's own errors for a corrupt or truncated file
        raise FileFormatError(f"{path}: cannot read table ({type(exc).__name__}: {exc})") from None
    _check_types(path, table)
    return table


def _has_records(folder: Path) -> bool:
    """Whether ``folder`` holds a frame's ``detections.json`` (``F/detections.json`` or, from a run of several
    recordings, ``R/F/detections.json``): the first found is enough."""
    for pattern in ("*/detections.json", "*/*/detections.json"):
        with contextlib.suppress(OSError):
            if next(itertools.islice(folder.glob(pattern), 1), None) is not None:
                return True
    return False


def _check_types(path: Path, table: Any) -> None:
    """Refuse a column whose type is not its kind in a symfruit table (:data:`FRUIT_COLUMNS`,
    :data:`FRAME_COLUMNS`: text, a number, a whole number, true/false), and a frame count left empty, by name:
    not numpy's or Python's words later, on a value turned into a number it is not."""
    import pyarrow.types as pt

    fits = {"string": lambda t: pt.is_string(t) or pt.is_large_string(t), "bool": pt.is_boolean,
            "float64": lambda t: pt.is_floating(t) or pt.is_integer(t), "int32": pt.is_integer,
            "int64": pt.is_integer, "timestamp": pt.is_timestamp}  # fmt: skip
    kinds = dict(FRAME_COLUMNS if path.name == FRAMES_NAME else FRUIT_COLUMNS)
    for name, column in zip(table.column_names, table.columns, strict=True):
        kind = kinds.get(name)
        if kind is not None and not fits[kind](column.type):
            raise FileFormatError(f"{path}: column {name} holds {column.type}, not {kind} (not a symfruit table, or "
                                  "damaged)")  # fmt: skip
        if path.name == FRAMES_NAME and name in ("fruit", "located") and column.null_count:
            raise FileFormatError(f"{path}: column {name} has {column.null_count} empty rows; every frame has its "
                                  "count (not a symfruit table, or damaged)")  # fmt: skip


def diameters_mm(size_x: np.ndarray, size_z: np.ndarray) -> np.ndarray:
    """Fruit diameters (mm) from box sizes (m): the larger horizontal side, ``max(size_x, size_z)``.

    >>> diameters_mm(np.array([0.02, 0.03]), np.array([0.025, 0.01])).tolist()
    [25.0, 30.0]
    """
    return np.round(np.maximum(np.asarray(size_x, float), np.asarray(size_z, float)) * 1000.0, 6)


def size_classes(diameters: np.ndarray, edges: Sequence[float]) -> list[tuple[str, int]]:
    """``(label, count)`` per size class: below the first edge, between edges, at or above the last (mm).

    >>> size_classes(np.array([10.0, 18.0, 20.0, 31.0]), [18, 25])
    [('< 18 mm', 1), ('18-25 mm', 2), ('>= 25 mm', 1)]
    """
    if isinstance(edges, str | bytes) or not isinstance(edges, Sequence | np.ndarray):  # "18" was [1, 8] mm
        raise InputError(f"size classes must be a list of diameters in mm such as [18, 25], got {shown(edges)}")
    if len(edges) > MAX_CLASSES:
        raise InputError(f"size classes: {len(edges)} limits; at most {MAX_CLASSES}")
    bad = next((e for e in edges if isinstance(e, bool) or not isinstance(e, int | float | np.integer | np.floating)),
               None)  # fmt: skip
    if bad is not None:  # True was 1 mm, [18] a TypeError from float()
        raise InputError(f"size classes must be diameters in mm, got {shown(bad)} in {shown(list(edges))}")
    edges = [float(e) for e in edges]
    if not edges or any(not math.isfinite(e) or e <= 0 for e in edges) or sorted(set(edges)) != edges:
        raise InputError(f"size classes must be increasing diameters in mm, got {edges}")
    if edges[-1] > MAX_CLASS_MM:
        raise InputError(f"size classes: a limit of {edges[-1]:g} mm; diameters are in mm, at most "
                         f"{MAX_CLASS_MM:g}")  # fmt: skip
    d = np.asarray(diameters, float)
    counts = np.histogram(d, bins=[-np.inf, *edges, np.inf])[0]
    labels = [f"< {edges[0]:g} mm", *(f"{a:g}-{b:g} mm" for a, b in itertools.pairwise(edges)), f">= {edges[-1]:g} mm"]
    return list(zip(labels, (int(c) for c in counts), strict=True))


def _check_sizes(path: Path, *sizes: np.ndarray) -> None:
    """Refuse a table whose box sides are negative or beyond :data:`MAX_SIZE_M` (NaN: not sized): no completion
    writes them, and a side of 1e300 m made the diameter histogram's bins overflow (1e6 m: a billion bins)."""
    for name, size in zip(("size_x", "size_z"), sizes, strict=True):
        bad = np.flatnonzero(np.isfinite(size) & ((size < 0) | (size > MAX_SIZE_M)) | np.isinf(size))
        if len(bad):
            raise FileFormatError(f"{path}: row {int(bad[0]) + 1} has {name} {size[bad[0]]:g} m; box sides are "
                                  f"metres in [0, {MAX_SIZE_M:g}] (not a symfruit table, or damaged)")  # fmt: skip


def _check_centres(path: Path, fruit: Any) -> np.ndarray:
    """Which fruit have a centre; a table whose centre is NaN, infinite, beyond :data:`MAX_SIZE_M` or given in part
    refused: a fruit not located has none (three empty cells), as :func:`symfruit.season.table.frame_rows` writes.
    A NaN centre (a value, not an empty cell) was counted as located (stop 51, robust51)."""
    given = np.array([fruit.column(f"centre_{a}").is_valid().to_numpy(zero_copy_only=False) for a in "xyz"], bool)
    xyz = np.array([fruit.column(f"centre_{a}").to_numpy(zero_copy_only=False) for a in "xyz"], float)
    bad = np.flatnonzero((given.any(0) & ~given.all(0)) | (given & ~(np.abs(xyz) <= MAX_SIZE_M)).any(0))
    if len(bad):
        k = int(bad[0])
        shown_xyz = ", ".join(f"{xyz[a, k]:g}" if given[a, k] else "empty" for a in range(3))
        raise FileFormatError(f"{path}: row {k + 1} has centre ({shown_xyz}); a located fruit's centre is three "
                              f"numbers of metres within {MAX_SIZE_M:g}, one not located has none (not a symfruit "
                              "table, or damaged)")  # fmt: skip
    return given.all(0).reshape(-1)


def _check_counts(path: Path, fruit: np.ndarray, located: np.ndarray) -> None:
    """Refuse a frames table whose counts no run writes: a frame's fruit 0-:data:`MAX_INSTANCES`, located 0 to its
    fruit (a negative count made "-5 located per frame", a huge one a billion-bin histogram)."""
    bad = np.flatnonzero((fruit < 0) | (fruit > MAX_INSTANCES) | (located < 0) | (located > fruit))
    if len(bad):
        k = int(bad[0])
        raise FileFormatError(f"{path}: row {k + 1} has {int(located[k])} of {int(fruit[k])} fruit located; a "
                              f"frame holds 0-{MAX_INSTANCES} fruit, located 0 to them (not a symfruit table, or "
                              "damaged)")  # fmt: skip


def _check_confidence(path: Path, conf: np.ndarray) -> None:
    """Refuse a detections table whose confidence is outside [0, 1] (NaN: none)."""
    bad = np.flatnonzero(~np.isnan(conf) & ~((conf >= 0) & (conf <= 1)))
    if len(bad):
        raise FileFormatError(f"{path}: row {int(bad[0]) + 1} has confidence {conf[bad[0]]:.4g}; a confidence is in "
                              "[0, 1] (not a symfruit table, or damaged)")  # fmt: skip


def _check_agree(output: Path, fruit: Any, frames: Any) -> None:
    """Refuse tables that disagree, as no run writes them (a table edited, or the two from different runs): a row
    without its recording or frame name, a frame listed twice, a fruit (recording, frame, id) twice, a fruit of a
    frame ``frames.parquet`` does not list, and a frame whose fruit and located counts are not its rows' (located:
    no error and a centre, as :func:`symfruit.season.table.frame_rows` counts). Before, each was reported as if
    whole: a fruit twice counted and sized twice, fruit of no frame in the sizes but not per frame, ``None`` a
    recording of its own. Stop 50 (robust50)."""
    import pyarrow as pa
    import pyarrow.compute as pc

    keys = ["recording", "frame"]

    def keyed(table: Any, path: Path, more: list[str]) -> Any:
        """The key columns (refused with a row of no name) as large_string, a join's one type for both tables
        (another tool may write either), and ``more``."""
        columns = {}
        for name in keys:
            if table.column(name).null_count:
                raise FileFormatError(f"{path}: column {name} has {table.column(name).null_count} empty rows; "
                                      "every row names its recording and frame (not a symfruit table, or "
                                      "damaged)")  # fmt: skip
            columns[name] = pc.cast(table.column(name), pa.large_string())
        return pa.table({**columns, **{name: table.column(name) for name in more}})

    frames = keyed(frames, output / FRAMES_NAME, ["fruit", "located"])
    fruit = keyed(fruit, output / TABLE_NAME, ["id", "error", "centre_x"])
    for table, key, what, path in ((frames, keys, "frame", output / FRAMES_NAME),
                                   (fruit, [*keys, "id"], "fruit", output / TABLE_NAME)):  # fmt: skip
        counted = table.select(key).group_by(key).aggregate([([], "count_all")])
        twice = counted.filter(pc.greater(counted.column("count_all"), 1))
        if twice.num_rows:
            row = twice.slice(0, 1).to_pylist()[0]
            named = "/".join(shown(str(row[k]), 60) for k in keys)
            named = f"{row['id']} of frame {named}" if what == "fruit" else named
            raise FileFormatError(f"{path}: {what} {named} is listed {row['count_all']} times; a run "
                                  f"lists each {what} once (not a symfruit table, or damaged)")  # fmt: skip
    located = pc.and_(pc.is_null(fruit.column("error")), pc.is_valid(fruit.column("centre_x")))
    rows = (pa.table({"recording": fruit.column("recording"), "frame": fruit.column("frame"),
                      "located_rows": pc.cast(located, pa.int64())})
            .group_by(keys).aggregate([([], "count_all"), ("located_rows", "sum")]))  # fmt: skip
    listed = frames.append_column("listed", pa.repeat(True, frames.num_rows))
    both = listed.join(rows, keys=keys, join_type="full outer")
    orphan = both.filter(pc.is_null(both.column("listed")))
    if orphan.num_rows:
        row = orphan.slice(0, 1).to_pylist()[0]
        raise FileFormatError(f"{output / TABLE_NAME}: holds {row['count_all']} fruit of frame "
                              f"{shown(str(row['recording']), 60)}/{shown(str(row['frame']), 60)}, which "
                              f"{FRAMES_NAME} does not list (the tables disagree: damaged, or of different "
                              "runs)")  # fmt: skip
    seen = pc.fill_null(both.column("count_all"), 0)
    found = pc.fill_null(both.column("located_rows_sum"), 0)
    off = both.filter(pc.or_(pc.not_equal(pc.cast(both.column("fruit"), pa.int64()), seen),
                             pc.not_equal(pc.cast(both.column("located"), pa.int64()), found)))  # fmt: skip
    if off.num_rows:
        row = off.slice(0, 1).to_pylist()[0]
        raise FileFormatError(f"{output / FRAMES_NAME}: frame {shown(str(row['recording']), 60)}/"
                              f"{shown(str(row['frame']), 60)} counts {row['fruit']} fruit, {row['located']} located, "
                              f"but {TABLE_NAME} holds {row['count_all'] or 0} of its fruit, "
                              f"{row['located_rows_sum'] or 0} located (the tables disagree: damaged, or of different "
                              "runs)")  # fmt: skip


def _errors(output: Path) -> tuple[int, int]:
    """Frames ``errors.json`` lists as failed or not reached, and recordings it lists as not read (0, 0 without
    the file)."""
    from ..io.text import holds_file, read_structured
    from .table import MAX_RECORD_BYTES

    path = output / "errors.json"
    if not holds_file(path):  # a directory or broken link of that name is said, not taken for "no failures"
        return 0, 0
    data = read_structured(path, what="errors.json", max_bytes=MAX_RECORD_BYTES)
    if not isinstance(data, dict):
        raise FileFormatError(f"{path}: not a symfruit errors.json")
    for key in ("failed", "unprocessed", "recordings"):  # {"failed": 5} counted no failed frame
        if key in data and not isinstance(data[key], list):
            raise FileFormatError(f"{path}: not a symfruit errors.json ({key!r} is not a list)")
    count = lambda key: len(data.get(key, []))  # noqa: E731
    return count("failed") + count("unprocessed"), count("recordings")


def _cell(text: str) -> str:
    """``text`` as one Markdown table cell: a ``|`` escaped (it would start another cell: a recording named
    ``row|1`` shifted its row's numbers one column on), a line break as a space (it would end the row)."""
    return " ".join(str(text).replace("|", "\\|").split())


def _mm(value: float) -> str:
    return "-" if not math.isfinite(value) else f"{value:.1f}"


def _check_folder(output: Path, folder: Path) -> None:
    """Refuse a report folder inside the run other than its own ``report`` (the run's root, a recording's or a
    frame's folder: the report's files would mix with the run's, whose next detect run owns that folder)."""
    run, real = os.path.realpath(output), os.path.realpath(folder)
    own = os.path.realpath(output / "report")
    inside = os.path.commonpath([run, real]) == run
    if inside and os.path.commonpath([own, real]) != own:
        raise OutputError(f"{folder}: is inside the run {output} (its own folder, a recording's or a frame's, which "
                          f"a detect run writes); write the report to {output / 'report'} (the default) or outside "
                          "the run")  # fmt: skip


def _check_run(output: Path) -> None:
    """Refuse a run folder that is missing or a file in its own words (stop 48, robust48: a file was
    ``FILE/detections.parquet: no such table; run symfruit detect ... --output FILE first``); a run's table
    named instead of its folder is told which folder to name."""
    if not os.path.lexists(output):
        raise FileFormatError(f"{output}: no such folder; `symfruit report` reads the --output folder of a "
                              f"`symfruit detect` run: run `symfruit detect ... --output {output}` first")  # fmt: skip
    if not output.is_dir():
        if output.name in (TABLE_NAME, FRAMES_NAME):
            raise FileFormatError(f"{output}: is a run's table; name the run's folder: `symfruit report "
                                  f"{output.parent}`")  # fmt: skip
        raise FileFormatError(f"{output}: not a folder; `symfruit report` reads the --output folder of a "
                              "`symfruit detect` run (with detections.parquet)")  # fmt: skip


def write_report(
    output: str | Path, *, folder: str | Path | None = None, classes: Sequence[float] = DEFAULT_CLASSES_MM
) -> Report:
    """Write ``report.md`` and the plots (:data:`PLOTS`) of the ``detect`` output folder ``output`` into
    ``folder`` (default ``output/report``).

    Raises
    ------
    SymfruitError
        When the tables are missing, too large or not symfruit's, matplotlib is missing
        (``pip install 'symfruit[plot]'``), or the folder cannot be written.
    """
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise InputError("symfruit report draws its plots with matplotlib: pip install 'symfruit[plot]'") from None
    from ..io.atomic import atomic_write
    from ..io.outputs import OutputFolder

    output = as_path(output, "write_report: the run folder")  # '' was the working folder
    _check_run(output)
    if folder is None and (output / "report").is_symlink():  # the default is the run's own: never a link out of it
        link = output / "report"
        raise OutputError(f"{link}: is a symbolic link (to {os.readlink(link)}); symfruit does not write through "
                          f"links inside {output}: remove it, or name a folder (--output)")  # fmt: skip
    if folder is not None:
        _check_folder(output, Path(folder))
    folder = Path(folder) if folder is not None else output / "report"
    size_classes(np.ones(1), classes)  # checked before anything is read
    fruit = _read(output / TABLE_NAME, ["recording", "frame", "id", "centre_x", "centre_y", "centre_z", "size_x",
                                        "size_z", "confidence", "reliable", "truncated", "error",
                                        "method"])  # fmt: skip
    frames = _read(output / FRAMES_NAME, ["recording", "frame", "fruit", "located"])
    inputs = recording_inputs(fruit.schema.metadata)
    failed, failed_recordings = _errors(output)
    col = {name: fruit.column(name).to_numpy(zero_copy_only=False) for name in fruit.column_names}
    rec_f = frames.column("recording").to_numpy(zero_copy_only=False).astype(str)
    located_f = frames.column("located").to_numpy(zero_copy_only=False).astype(np.int64)
    seen_f = frames.column("fruit").to_numpy(zero_copy_only=False).astype(np.int64)
    centred = _check_centres(output / TABLE_NAME, fruit)
    ok = np.array([e is None for e in col["error"]], bool) & centred  # located: no error and a centre (frame_rows)
    size_x = np.array([np.nan if v is None else v for v in col["size_x"]], float)
    size_z = np.array([np.nan if v is None else v for v in col["size_z"]], float)
    truncated = np.array([bool(v) for v in col["truncated"]], bool)
    _check_sizes(output / TABLE_NAME, size_x, size_z)
    sized = ok & ~truncated & np.isfinite(size_x) & np.isfinite(size_z)
    diam = diameters_mm(size_x[sized], size_z[sized])
    conf = np.array([np.nan if v is None else v for v in col["confidence"]], float)
    _check_confidence(output / TABLE_NAME, conf)
    _check_counts(output / FRAMES_NAME, seen_f, located_f)
    _check_agree(output, fruit, frames)
    reliable = np.array([v is True for v in col["reliable"]], bool)
    methods = sorted({str(m) for m in col["method"] if m is not None})
    recordings = list(dict.fromkeys(rec_f.tolist()))
    report = Report(folder, frames=len(rec_f), fruit=len(ok), located=int(ok.sum()), sized=int(sized.sum()),
                    recordings=len(recordings), failed_frames=failed, failed_recordings=failed_recordings)  # fmt: skip
    rec_fruit = np.asarray(col["recording"]).astype(str)
    per_rec, by_rec = [], []
    sized_at = np.flatnonzero(sized)
    for r, at, fruit_at in zip(recordings, _groups(rec_f, recordings), _groups(rec_fruit[sized_at], recordings),
                               strict=True):  # fmt: skip
        loc, sized_r = located_f[at], sized_at[fruit_at]
        d = diameters_mm(size_x[sized_r], size_z[sized_r])
        per_rec.append((r, len(at), int((loc > 0).sum()), int(seen_f[at].sum()), int(loc.sum()),
                        float(loc.mean()) if len(loc) else math.nan, int(loc.max()) if len(loc) else 0,
                        float(np.median(d)) if len(d) else math.nan))  # fmt: skip
        by_rec.append((r, loc, d))
    classes_rows = size_classes(diam, classes)
    finite_conf = np.isfinite(conf) & ok

    with OutputFolder(folder, inputs=[output / TABLE_NAME, output / FRAMES_NAME, output / "errors.json"],
                      what="report folder") as out:  # fmt: skip
        plots = _plots(plt, rec_f, located_f, per_rec, diam, classes, conf[finite_conf], reliable[finite_conf])
        names = list(PLOTS)
        if len(recordings) > 1:
            plots += _recording_plots(plt, by_rec, classes)
            names += PER_RECORDING_PLOTS
        for name, fig in zip(names, plots, strict=True):
            with atomic_write(folder / name, "wb", root=out) as handle:
                fig.savefig(handle, format="png", dpi=100)
            plt.close(fig)
            report.written.append(folder / name)
        text = _markdown(output, report, per_rec, classes_rows, diam, conf[finite_conf], reliable[finite_conf],
                         methods, truncated_n=int((ok & truncated).sum()), by_rec=by_rec, classes=classes,
                         inputs=inputs)  # fmt: skip
        with atomic_write(folder / "report.md", "w", root=out) as handle:
            handle.write(text)
        report.written.append(folder / "report.md")
    return report


def _groups(keys: np.ndarray, names: Sequence[str]) -> list[np.ndarray]:
    """The positions of ``keys`` equal to each of ``names``, in order (each in its keys' order; a key none of
    ``names`` is in no group): one sort, not a pass over every key for each name, which made a report of many
    recordings quadratic (32,000 one-frame recordings: 39 s).

    >>> [g.tolist() for g in _groups(np.array(["b", "a", "b", "c"]), ["a", "b"])]
    [[1], [0, 2]]
    """
    index = {name: k for k, name in enumerate(names)}
    group = np.fromiter((index.get(key, -1) for key in keys.tolist()), np.int64, len(keys))
    order = np.argsort(group, kind="stable")
    bounds = np.searchsorted(group[order], np.arange(len(names) + 1))
    return [order[a:b] for a, b in itertools.pairwise(bounds)]


def _binned(values: np.ndarray, most: int = 2000) -> tuple[np.ndarray, np.ndarray]:
    """``(x, y)``: the values themselves, or their means over ``most`` equal runs of a long sequence."""
    n = len(values)
    if n <= most:
        return np.arange(n), values.astype(float)
    edges = np.linspace(0, n, most + 1).astype(int)
    sums = np.add.reduceat(values.astype(float), edges[:-1])
    return (edges[:-1] + edges[1:]) / 2.0, sums / np.diff(edges)


def _plots(plt: Any, rec_f: np.ndarray, located_f: np.ndarray, per_rec: list[tuple], diam: np.ndarray,
           classes: Sequence[float], conf: np.ndarray, reliable: np.ndarray) -> list[Any]:  # fmt: skip
    figs = []
    fig, ax = plt.subplots(figsize=(9, 3.5))
    x, y = _binned(located_f)
    ax.plot(x, y, lw=1, color="tab:red", marker="o" if len(x) <= 100 else None, ms=3)
    ax.xaxis.get_major_locator().set_params(integer=True)
    ax.yaxis.get_major_locator().set_params(integer=True)
    starts = [i for i in range(1, len(rec_f)) if rec_f[i] != rec_f[i - 1]]
    for s in starts[:MAX_BARS]:
        ax.axvline(s, color="grey", lw=0.5, ls=":")
    averaged = " (mean over runs of frames)" if len(located_f) > 2000 else ""
    ax.set(xlabel="frame (in recording order; dotted lines: a new recording)", ylabel="fruit located",
           title=f"Fruit per frame{averaged}")  # fmt: skip
    ax.set_ylim(bottom=0)
    fig.tight_layout()
    figs.append(fig)

    fig, ax = plt.subplots(figsize=(9, 3.5))
    shown = sorted(per_rec, key=lambda r: -r[4])[:MAX_BARS] if len(per_rec) > MAX_BARS else per_rec
    ax.bar(range(len(shown)), [r[4] for r in shown], color="tab:red")
    ax.set_xticks(range(len(shown)), [str(r[0])[:24] for r in shown], rotation=45 if len(shown) > 4 else 0,
                  ha="right" if len(shown) > 4 else "center", fontsize=8)  # fmt: skip
    more = f" (the {MAX_BARS} with most fruit of {len(per_rec)})" if len(per_rec) > MAX_BARS else ""
    ax.set(ylabel="fruit located", title=f"Fruit per recording{more}")
    ax.yaxis.get_major_locator().set_params(integer=True)
    fig.tight_layout()
    figs.append(fig)

    fig, ax = plt.subplots(figsize=(9, 3.5))
    if len(diam):
        lo, hi = math.floor(min(diam.min(), classes[0]) - 1), math.ceil(max(diam.max(), classes[-1]) + 1)
        width = max(1, math.ceil((hi - lo) / MAX_HIST_BINS))  # 1 mm bins where at most MAX_HIST_BINS suffice
        ax.hist(diam, bins=np.arange(lo, hi + width, width, dtype=float), color="tab:red", alpha=0.8)
    for edge in classes:
        ax.axvline(edge, color="black", ls="--", lw=1)
    for label, count in size_classes(diam, classes):
        ax.plot([], [], " ", label=f"{label}: {count}")
    ax.legend(title="size class: fruit", fontsize=8, loc="upper right")
    ax.yaxis.get_major_locator().set_params(integer=True)
    ax.set(xlabel="diameter (mm): larger horizontal side of the completed box", ylabel="fruit",
           title="Fruit diameters; dashed lines: size class limits")  # fmt: skip
    fig.tight_layout()
    figs.append(fig)

    fig, ax = plt.subplots(figsize=(9, 3.5))
    if len(conf):
        bins = np.linspace(0, 1, 21)
        ax.hist([conf[reliable], conf[~reliable]], bins=bins, stacked=True, color=["tab:green", "tab:orange"],
                label=["reliable", "not reliable"])  # fmt: skip
        ax.legend(fontsize=8)
        ax.yaxis.get_major_locator().set_params(integer=True)
    else:
        ax.text(0.5, 0.5, "the method used gives no confidence", ha="center", va="center", transform=ax.transAxes)
    ax.set(xlabel="confidence", ylabel="fruit", title="Confidence of the located fruit", xlim=(0, 1))
    fig.tight_layout()
    figs.append(fig)
    return figs


def _shown(by_rec: list[tuple[str, np.ndarray, np.ndarray]]) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """The recordings drawn one box each: all, or the :data:`MAX_BARS` with most fruit located (in run order)."""
    if len(by_rec) <= MAX_BARS:
        return by_rec
    keep = set(sorted(range(len(by_rec)), key=lambda k: -int(by_rec[k][1].sum()))[:MAX_BARS])
    return [r for k, r in enumerate(by_rec) if k in keep]


def _recording_plots(plt: Any, by_rec: list[tuple[str, np.ndarray, np.ndarray]], classes: Sequence[float]) -> list[Any]:
    """Fruit located per frame and fruit diameters, one box per recording (:data:`PER_RECORDING_PLOTS`)."""
    shown = _shown(by_rec)
    more = f" (the {MAX_BARS} with most fruit of {len(by_rec)})" if len(shown) < len(by_rec) else ""
    labels = [str(r[0])[:24] for r in shown]
    figs: list[Any] = []
    for what, k in (("fruit located per frame", 1), ("diameter (mm)", 2)):
        fig, ax = plt.subplots(figsize=(9, 3.8))
        data = [np.asarray(r[k], float) for r in shown]
        filled = [x for x in range(len(data)) if len(data[x])]
        if filled:
            ax.boxplot([data[x] for x in filled], positions=filled, widths=0.6, showmeans=True,
                       medianprops={"color": "tab:red"})  # fmt: skip
        ticks = [f"{label}\nn={len(x)}" for label, x in zip(labels, data, strict=True)]
        ax.set_xticks(range(len(shown)), ticks, rotation=45 if len(shown) > 4 else 0,
                      ha="right" if len(shown) > 4 else "center", fontsize=8)  # fmt: skip
        ax.set_xlim(-0.7, len(shown) - 0.3)
        if k == 1:
            ax.yaxis.get_major_locator().set_params(integer=True)
            ax.set_ylim(bottom=0)
            ax.set(ylabel=what, title=f"Fruit per frame, by recording{more}; box: quartiles, triangle: mean, n: frames")
        else:
            for edge in classes:
                ax.axhline(edge, color="black", ls="--", lw=1)
            ax.set(ylabel=what, title=f"Fruit diameters, by recording{more}; dashed: size class limits, n: fruit sized")
        fig.tight_layout()
        figs.append(fig)
    return figs


def _markdown(output: Path, r: Report, per_rec: list[tuple], classes_rows: list[tuple[str, int]], diam: np.ndarray,
              conf: np.ndarray, reliable: np.ndarray, methods: list[str], *, truncated_n: int,
              by_rec: Sequence[tuple[str, np.ndarray, np.ndarray]] = (), classes: Sequence[float] = DEFAULT_CLASSES_MM,
              inputs: dict[str, str] | None = None) -> str:  # fmt: skip
    share = lambda n, d: f"{100.0 * n / d:.1f} %" if d else "-"  # noqa: E731
    lines = [
        f"# Fruit found in `{output}`",
        "",
        f"symfruit located fruit in RGB-D camera frames: for each fruit it completed the side the camera could not "
        f"see and measured the fruit's box (its centre and size). This report covers {r.recordings} recording(s), "
        f"{r.frames:,} frames and {r.fruit:,} fruit seen, of which {r.located:,} were located (completed); "
        f"completion method: {', '.join(methods) or '-'}."
        + (f" {r.failed_frames:,} frame(s) could not be processed (see `errors.json`)." if r.failed_frames else "")
        + (
            f" {r.failed_recordings:,} recording(s) could not be read (see `errors.json`)."
            if r.failed_recordings
            else ""
        ),
        "",
        "Sizes are in millimetres. A fruit's **diameter** is the larger horizontal side of its completed box, the "
        "widest horizontal section of a hanging fruit, which is what sizing rings and grading machines measure. "
        f"Fruit cut by the image border ({truncated_n:,}) and fruit that could not be completed are counted but "
        "not sized.",
        "",
        "## Fruit per recording",
        "",
        "| recording | frames | frames with fruit | fruit seen | fruit located | located per frame (mean) | most in "
        "one frame | median diameter (mm) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for rec, n, with_fruit, seen, located, mean, most, med in per_rec:
        lines.append(f"| {_cell(rec)} | {n:,} | {with_fruit:,} | {seen:,} | {located:,} | "
                     f"{'-' if not math.isfinite(mean) else f'{mean:.2f}'} | {most} | {_mm(med)} |")  # fmt: skip
    shown = [rec for rec, *_ in per_rec if rec in (inputs or {})]
    if shown:
        lines += ["", "Each recording's input (a name with `+` and a hash is shared by several inputs or is not a "
                  "plain file name):", ""]  # fmt: skip
        lines += [f"- `{rec}`: `{(inputs or {})[rec]}`" for rec in shown]
    lines += ["", "![fruit per frame](fruit_per_frame.png)", "", "![fruit per recording](fruit_per_recording.png)", ""]
    if len(by_rec) > 1:
        lines += ["![fruit per frame, by recording](fruit_per_frame_by_recording.png)", ""]
    lines += ["## Sizes", ""]
    if len(diam):
        p10, p50, p90 = np.percentile(diam, [10, 50, 90])
        lines += [f"{len(diam):,} fruit sized: median diameter {p50:.1f} mm (10 % are below {p10:.1f} mm, 10 % above "
                  f"{p90:.1f} mm).", ""]  # fmt: skip
    else:
        lines += ["No fruit could be sized.", ""]
    lines += ["| size class (diameter) | fruit | share |", "|---|---|---|"]
    for label, count in classes_rows:
        lines.append(f"| {label} | {count:,} | {share(count, len(diam))} |")
    lines += ["", "![fruit diameters](diameters.png)", ""]
    if len(by_rec) > 1:
        lines += _sizes_by_recording(by_rec, classes)
    lines += ["## Confidence", ""]
    if len(conf):
        lines += [f"How far to trust each located fruit's box: {len(conf):,} fruit have a confidence (median "
                  f"{np.median(conf):.2f}); {int(reliable.sum()):,} ({share(int(reliable.sum()), len(conf))}) are "
                  "marked reliable, the others' centres may be off by more than a few millimetres.", ""]  # fmt: skip
    else:
        lines += ["The completion method used gives no confidence (the default method, `evidence`, does).", ""]
    lines += ["![confidence](confidence.png)", "",
              f"Made by `symfruit report` from `{TABLE_NAME}` (one row per fruit, metres) and `{FRAMES_NAME}` (one "
              "row per frame) in the output folder.", ""]  # fmt: skip
    return "\n".join(lines)


def _sizes_by_recording(by_rec: Sequence[tuple[str, np.ndarray, np.ndarray]], classes: Sequence[float]) -> list[str]:
    """The ``report.md`` section of diameters recording by recording: percentiles and size classes."""
    labels = [label for label, _ in size_classes(np.zeros(0), classes)]
    lines = ["### Sizes per recording", "",
             "| recording | fruit sized | 10 % below (mm) | median (mm) | 10 % above (mm) | "
             + " | ".join(labels) + " |", "|---|---|---|---|---|" + "---|" * len(labels)]  # fmt: skip
    for rec, _, d in by_rec:
        p10, p50, p90 = np.percentile(d, [10, 50, 90]) if len(d) else (math.nan,) * 3
        counts = " | ".join(f"{c:,}" for _, c in size_classes(d, classes))
        lines.append(f"| {_cell(rec)} | {len(d):,} | {_mm(p10)} | {_mm(p50)} | {_mm(p90)} | {counts} |")
    return [*lines, "", "![fruit diameters, by recording](diameters_by_recording.png)", ""]
