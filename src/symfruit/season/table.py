"""The fruit table of a ``detect`` run: ``OUT/detections.parquet`` (one row per fruit per frame) and
``OUT/frames.parquet`` (one row per frame, so that frames without fruit count too).

Both are built from the frames' ``detections.json`` records, never from anything else: the rows of a frame
done in this run come from the record it just wrote (:func:`frame_rows`), the rows of a frame skipped by
``--resume`` from its file (:func:`read_frame_rows`), so a resumed run's table is the table of an
uninterrupted one, with each frame's rows exactly once. :class:`TableWriter` streams the rows into both
files in row groups (memory stays flat over a long recording) and renames them into place only when the
run's table is complete (:mod:`symfruit.io.atomic`); an interrupted run leaves the previous tables.

Units are metres (centre, size) and seconds (``seconds``, the frame's detection time); ``stamp`` is the
colour image's time (UTC nanoseconds) where the recording has one (bags), else null.

=============  ===========================  =====================================================
column         type                         content
=============  ===========================  =====================================================
recording      string                       the recording's name (the input's file or folder name; with
                                            several inputs, its folder in the output, told apart)
frame          string                       the frame's name
stamp          timestamp[ns, UTC], null     the colour image's time
id             int32                        the fruit's id in the frame (1, 2, ...)
centre_x/y/z   float64, null                the completed fruit's box centre, metres, camera frame
size_x/y/z     float64, null                the completed fruit's box size, metres
confidence     float64, null                in [0, 1] (null for methods without one)
reliable       bool, null
method         string, null                 the completion method
mask_area      int64                        pixels of the fruit's mask
points         int64                        visible points extracted under the mask
truncated      bool                         the fruit touches the image border
error          string, null                 why the fruit could not be completed (then no centre)
=============  ===========================  =====================================================

``frames.parquet``: ``recording``, ``frame``, ``stamp``, ``fruit`` (int32, every fruit of the frame),
``located`` (int32, those completed) and ``seconds`` (float64, the frame's detection time).

A run over several recordings also names each recording's input in both files' metadata, under
``symfruit.recordings``: JSON ``{recording: input path as given}`` (:func:`recording_inputs`).
"""

from __future__ import annotations

import contextlib
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ..core.limits import MAX_DEPTH_METRES, MAX_INSTANCES, MAX_TRUTH_BYTES, shown
from ..errors import FileFormatError, SymfruitError

__all__ = [
    "FRAMES_NAME",
    "FRAME_COLUMNS",
    "FRUIT_COLUMNS",
    "INPUTS_KEY",
    "TABLE_NAME",
    "TableWriter",
    "frame_rows",
    "read_frame_rows",
    "recording_inputs",
    "recording_name",
    "write_run_tables",
    "write_tables",
]

#: The files a ``detect`` run writes into its output folder besides the frame folders.
TABLE_NAME = "detections.parquet"
FRAMES_NAME = "frames.parquet"
#: The key of the tables' metadata that names each recording's input (JSON ``{recording: input path}``), written
#: by a run over several recordings.
INPUTS_KEY = "symfruit.recordings"
#: Largest ``detections.json`` read back (bytes): the bound of a ``truth.json``.
MAX_RECORD_BYTES = MAX_TRUTH_BYTES
#: Rows buffered before a row group is written (about 20 MB of rows in Python).
ROW_GROUP = 16_384
#: Largest box side (metres) a record may hold: what ``symfruit report`` reads (``season.report.MAX_SIZE_M``).
MAX_BOX_M = MAX_DEPTH_METRES

#: ``(name, arrow type name)`` of ``detections.parquet``, in order.
FRUIT_COLUMNS: tuple[tuple[str, str], ...] = (
    ("recording", "string"), ("frame", "string"), ("stamp", "timestamp"), ("id", "int32"),
    ("centre_x", "float64"), ("centre_y", "float64"), ("centre_z", "float64"),
    ("size_x", "float64"), ("size_y", "float64"), ("size_z", "float64"),
    ("confidence", "float64"), ("reliable", "bool"), ("method", "string"), ("mask_area", "int64"),
    ("points", "int64"), ("truncated", "bool"), ("error", "string"),
)  # fmt: skip
#: ``(name, arrow type name)`` of ``frames.parquet``, in order.
FRAME_COLUMNS: tuple[tuple[str, str], ...] = (
    ("recording", "string"), ("frame", "string"), ("stamp", "timestamp"), ("fruit", "int32"), ("located", "int32"),
    ("seconds", "float64"),
)  # fmt: skip

Row = dict[str, Any]


def schema(columns: Sequence[tuple[str, str]]) -> Any:
    """The pyarrow schema of ``columns`` (:data:`FRUIT_COLUMNS` or :data:`FRAME_COLUMNS`)."""
    import pyarrow as pa

    kinds = {"string": pa.string(), "timestamp": pa.timestamp("ns", tz="UTC"), "int32": pa.int32(),
             "int64": pa.int64(), "float64": pa.float64(), "bool": pa.bool_()}  # fmt: skip
    return pa.schema([(name, kinds[kind]) for name, kind in columns])


def _number(value: Any, what: str, *, whole: bool = False) -> Any:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise FileFormatError(f"{what} is {type(value).__name__}, not a number")
    if whole:
        if not isinstance(value, int) or not -(2**62) <= value <= 2**62:
            raise FileFormatError(f"{what} is {shown(value)}, not a whole number")  # 400 digits were 400 (robust51)
        return value
    try:
        value = float(value)
    except OverflowError:  # a whole number of hundreds of digits, which JSON holds: not OverflowError (robust51)
        raise FileFormatError(f"{what} is a whole number beyond a float's range") from None
    return value if math.isfinite(value) else None


def _flag(value: Any, what: str) -> bool | None:
    if value is None or isinstance(value, bool):
        return value
    raise FileFormatError(f"{what} is {value!r}, not true or false")


def _text(value: Any, what: str) -> str | None:
    if value is None or isinstance(value, str):
        return _utf8(value)
    raise FileFormatError(f"{what} is {type(value).__name__}, not text")


def _utf8(value: str | None) -> str | None:
    """``value`` as Parquet can hold it: a name that is not valid UTF-8 (a folder named with other bytes,
    kept by Python as lone surrogates) with those characters written as backslash escapes."""
    if value is None:
        return None
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:
        return value.encode("utf-8", "backslashreplace").decode("utf-8")
    return value


def _triple(value: Any, what: str) -> list[float | None]:
    if value is None:
        return [None, None, None]
    if not isinstance(value, list) or len(value) != 3:
        raise FileFormatError(f"{what} is not three numbers")
    return [_number(v, what) for v in value]


def _stamp(header: Any) -> int | None:
    stamp = header.get("stamp") if isinstance(header, Mapping) else None
    if stamp is None:
        return None
    if not isinstance(stamp, Mapping):
        raise FileFormatError("header.stamp is not {sec, nanosec}")
    sec = _number(stamp.get("sec"), "header.stamp.sec", whole=True)
    nsec = _number(stamp.get("nanosec"), "header.stamp.nanosec", whole=True)
    if sec is None or nsec is None or not 0 <= nsec < 1_000_000_000 or not 0 <= sec < 2**33:
        raise FileFormatError(f"header.stamp {sec}.{nsec} is not a time")
    return int(sec) * 1_000_000_000 + int(nsec)


def frame_rows(record: Mapping[str, Any], recording: str) -> tuple[Row, list[Row]]:
    """The ``frames.parquet`` row and the ``detections.parquet`` rows of one frame's ``detections.json``
    record (:func:`symfruit.writers.detections_record`).

    Raises
    ------
    FileFormatError
        When the record is not one (a field missing or of the wrong type), saying which.
    """
    if not isinstance(record, Mapping) or not isinstance(record.get("fruits"), list):
        raise FileFormatError("not a detections.json record (no list of fruits)")
    frame = _text(record.get("frame"), "frame")
    recording = _utf8(recording) or ""
    if frame is None:
        raise FileFormatError("not a detections.json record (no frame name)")
    stamp = _stamp(record.get("header"))
    if len(record["fruits"]) > MAX_INSTANCES:  # no run writes more; the report would refuse the whole table
        raise FileFormatError(f"holds {len(record['fruits'])} fruits; a frame holds at most {MAX_INSTANCES}")
    fruits: list[Row] = []
    for k, fruit in enumerate(record["fruits"]):
        where = f"fruits[{k}]"
        if not isinstance(fruit, Mapping):
            raise FileFormatError(f"{where} is not an object")
        box = fruit.get("box")
        size = box.get("size") if isinstance(box, Mapping) else None
        error = _text(fruit.get("error"), f"{where}.error")
        centre, extent = _triple(fruit.get("centre"), f"{where}.centre"), _triple(size, f"{where}.box.size")
        fruits.append({
            "recording": recording, "frame": frame, "stamp": stamp, "id": _number(fruit.get("id"), f"{where}.id",
            whole=True), "centre_x": centre[0], "centre_y": centre[1], "centre_z": centre[2], "size_x": extent[0],
            "size_y": extent[1], "size_z": extent[2], "confidence": _number(fruit.get("confidence"),
            f"{where}.confidence"), "reliable": _flag(fruit.get("reliable"), f"{where}.reliable"),
            "method": _text(fruit.get("method"), f"{where}.method"),
            "mask_area": _number(fruit.get("mask_area"), f"{where}.mask_area", whole=True),
            "points": _number(fruit.get("n_points"), f"{where}.n_points", whole=True),
            "truncated": bool(_flag(fruit.get("truncated"), f"{where}.truncated")), "error": error,
        })  # fmt: skip
        if fruits[-1]["id"] is None or not -(2**31) <= fruits[-1]["id"] < 2**31:
            raise FileFormatError(f"{where}.id is missing or out of range")
        # values no completion writes: taken into the tables, they made `symfruit report` refuse the whole run
        if fruit.get("centre") is not None and any(v is None or not abs(v) <= MAX_BOX_M for v in centre):
            # a NaN, inf or null coordinate was left empty and the fruit counted as located (robust51)
            raise FileFormatError(f"{where}.centre is not three finite numbers of metres within {MAX_BOX_M:g}")
        bad = next((v for v in extent if v is not None and not 0 <= v <= MAX_BOX_M), None)
        if bad is not None:
            raise FileFormatError(f"{where}.box.size holds {bad:g} m; box sides are metres in [0, {MAX_BOX_M:g}]")
        conf = fruits[-1]["confidence"]
        if conf is not None and not 0 <= conf <= 1:
            raise FileFormatError(f"{where}.confidence is {conf:g}; a confidence is in [0, 1]")
    timings = record.get("timings")
    seconds = _number(timings.get("total"), "timings.total") if isinstance(timings, Mapping) else None
    located = sum(f["error"] is None and f["centre_x"] is not None for f in fruits)
    row = {"recording": recording, "frame": frame, "stamp": stamp, "fruit": len(fruits), "located": located,
           "seconds": seconds}  # fmt: skip
    return row, fruits


def read_frame_rows(path: str | Path, recording: str) -> tuple[Row, list[Row]]:
    """:func:`frame_rows` of a ``detections.json`` file (read with a size bound).

    Raises
    ------
    FileFormatError
        Naming the file, when it cannot be read or is not a record.
    """
    from ..io.text import read_structured

    path = Path(path)
    data = read_structured(path, what="detections.json", max_bytes=MAX_RECORD_BYTES)
    try:
        return frame_rows(data, recording)
    except SymfruitError as exc:
        raise FileFormatError(f"{path}: {exc}") from None


class TableWriter:
    """Streams rows into ``OUT/detections.parquet`` and ``OUT/frames.parquet``; both appear (atomically) when
    the block ends without an error, and neither when it fails. ``inputs``: each recording's input path by
    its name, kept in both files' metadata (:data:`INPUTS_KEY`; :func:`recording_inputs`).

    Examples
    --------
    >>> with TableWriter(out_folder) as table:  # doctest: +SKIP
    ...     table.add(*frame_rows(record, "rec"))
    """

    def __init__(self, output: str | Path, *, root: Any = None, inputs: Mapping[str, str] | None = None) -> None:
        self.output = Path(output)
        self.root = root
        self.inputs = dict(inputs or {})
        self.frames = 0
        self.fruits = 0
        self._stack = contextlib.ExitStack()
        self._writers: dict[str, Any] = {}
        self._buffers: dict[str, list[Row]] = {TABLE_NAME: [], FRAMES_NAME: []}
        self._schemas: dict[str, Any] = {}

    def __enter__(self) -> TableWriter:
        import pyarrow.parquet as pq

        from ..io.atomic import atomic_write

        try:
            for name, columns in ((TABLE_NAME, FRUIT_COLUMNS), (FRAMES_NAME, FRAME_COLUMNS)):
                handle = self._stack.enter_context(atomic_write(self.output / name, "wb", root=self.root))
                self._schemas[name] = schema(columns)
                if self.inputs:
                    self._schemas[name] = self._schemas[name].with_metadata({INPUTS_KEY: json.dumps(self.inputs)})
                self._writers[name] = pq.ParquetWriter(handle, self._schemas[name])
        except BaseException as err:  # the first table's temporary file dropped, its writer closed (robust53: the
            # stack closed without the error put the first table's header alone in place of an earlier run's table,
            # and its writer, left open, said "Exception ignored in ParquetWriter.__del__" at exit)
            self._abort(type(err), err, err.__traceback__)
            raise
        return self

    def add(self, frame: Row, fruits: Sequence[Row]) -> None:
        """Add one frame's row and its fruit rows (:func:`frame_rows`)."""
        self._buffers[FRAMES_NAME].append(frame)
        self._buffers[TABLE_NAME].extend(fruits)
        self.frames += 1
        self.fruits += len(fruits)
        for name, rows in self._buffers.items():
            if len(rows) >= ROW_GROUP:
                self._flush(name)

    def _flush(self, name: str) -> None:
        import pyarrow as pa

        rows = self._buffers[name]
        if rows:
            columns = {field.name: [r[field.name] for r in rows] for field in self._schemas[name]}
            self._writers[name].write_table(pa.table(columns, schema=self._schemas[name]))
            rows.clear()

    def __exit__(self, kind: Any, exc: Any, tb: Any) -> None:
        if kind is not None:
            self._abort(kind, exc, tb)
            return
        try:
            for name in self._writers:
                self._flush(name)
            for writer in self._writers.values():
                writer.close()  # the footer: the file is whole only now
        except BaseException as err:
            self._abort(type(err), err, err.__traceback__)  # an OSError comes back as an OutputError
            raise
        self._stack.close()  # both renamed into place

    def _abort(self, kind: Any, exc: Any, tb: Any) -> None:
        """Drop both temporary files (the tables of an earlier run stay)."""
        for writer in self._writers.values():
            with contextlib.suppress(Exception):
                writer.close()
        self._stack.__exit__(kind, exc, tb)


def recording_inputs(metadata: Mapping[bytes, bytes] | None) -> dict[str, str]:
    """Each recording's input path by its name, from a table's metadata (empty when it names none, as after a
    run over one recording, or when it is not what :class:`TableWriter` writes)."""
    raw = (metadata or {}).get(INPUTS_KEY.encode())
    try:
        data = json.loads(raw.decode("utf-8")) if raw else {}
    except (UnicodeDecodeError, ValueError):
        return {}
    if not isinstance(data, dict):
        return {}
    # names and paths that are not UTF-8 come back escaped, as the tables' recording column holds them
    return {str(_utf8(k)): str(_utf8(v)) for k, v in data.items() if isinstance(k, str) and isinstance(v, str)}


def recording_name(source: str | Path) -> str:
    """The ``recording`` column of a run on ``source``: the input's file or folder name."""
    return Path(source).absolute().name or str(source)


def write_tables(
    output: str | Path, frames: Sequence[tuple[str, Path]], recording: str, *, root: Any = None
) -> dict[str, str]:
    """Write both tables from the ``detections.json`` of every frame ``(name, folder)`` that has one, in
    order (the frames of the run that are done, by this run or by the one it resumed): one recording's
    :func:`write_run_tables`.

    Returns
    -------
    dict
        Frames whose ``detections.json`` could not be read into the table, with the reason (left out).

    Raises
    ------
    OutputError
        When a table cannot be written (then neither is replaced).
    """
    return write_run_tables(output, [(recording, frames)], root=root)


def write_run_tables(
    output: str | Path,
    recordings: Sequence[tuple[str, Sequence[tuple[str, Path]]]],
    *,
    root: Any = None,
    inputs: Mapping[str, str] | None = None,
) -> dict[str, str]:
    """Write both tables over several recordings, each ``(recording, frames)`` with ``frames`` as in
    :func:`write_tables` (``name`` there is how a frame is reported, e.g. ``rec/frame``); the rows keep
    the recordings' order and each one's frame order. ``inputs``: as :class:`TableWriter` takes it.

    Returns
    -------
    dict
        Frames (by ``name``) whose ``detections.json`` could not be read into the table, with the reason.

    Raises
    ------
    OutputError
        When a table cannot be written (then neither is replaced).
    """
    bad: dict[str, str] = {}
    with TableWriter(output, root=root, inputs=inputs) as table:
        for recording, frames in recordings:
            for name, folder in frames:
                path = Path(folder) / "detections.json"
                if not path.is_file():
                    continue
                try:
                    table.add(*read_frame_rows(path, recording))
                except SymfruitError as exc:
                    bad[name] = f"{exc} (left out of {TABLE_NAME})"
    return bad
