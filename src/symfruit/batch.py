"""Batches: ``detect`` over a recording (a frame folder, a folder of frames or a bag), and ``segment`` over
images (:func:`segment_images`), without losing anything.

Frames are decoded one at a time (:mod:`symfruit.io.sources`), so memory stays flat however long the
recording. Every frame gets its own output folder; a frame that fails, for whatever reason, is recorded in
``errors.json`` with its reason and the batch goes on. A full disk stops the batch cleanly (what was
written stays whole, the frame is reported). Files are written atomically and ``detections.json`` last,
so with ``resume=True`` a re-run skips exactly the frames already done, deciding before it decodes them.
"""

from __future__ import annotations

import contextlib
import errno
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from .core.limits import instance_labels
from .detect import DetectStream, FrameDetections, detect
from .errors import FileFormatError, InputError, OutputError, SymfruitError
from .fruitpool import FruitPool
from .io.atomic import folder_fd
from .io.frames import is_frame_folder
from .io.images import image_suffixes
from .io.outputs import LOCK_NAME, OutputFolder, entry_name, reserve_record, unique_names, write_record
from .io.sources import open_source
from .io.text import as_path, holds_file
from .methods import DEFAULT_METHOD
from .methods.registry import get as get_method
from .progress import Progress
from .season.table import FRAMES_NAME, TABLE_NAME, recording_name, write_run_tables
from .segment import MaskSource, mask_source
from .settings import Settings
from .writers import remove_stale, write_detections

__all__ = [
    "BatchReport",
    "Recording",
    "SegmentReport",
    "SegmentedImage",
    "expand_images",
    "frame_folder_name",
    "list_recordings",
    "plan_recordings",
    "run_batch",
    "segment_images",
]

#: Errors that mean the output cannot take more data: the batch stops instead of failing every frame.
_NO_SPACE = {errno.ENOSPC, errno.EFBIG, errno.EDQUOT}


#: Names a batch keeps for its own files in the output folder (its record, its lock, the fruit tables and the
#: default folder of ``symfruit report``): a frame called so gets a hashed folder name.
BATCH_FILES = ("errors.json", LOCK_NAME, TABLE_NAME, FRAMES_NAME, "report")


def frame_folder_name(name: str, reserved: Sequence[str] = BATCH_FILES) -> str:
    """The output folder name of a frame: ``name`` itself when it is a safe file name (letters, digits,
    ``._-``) that the batch does not keep for its own files (``errors.json``), else a sanitised name, ``+``
    and a short hash of the original. A safe name never holds ``+``, so no two names share a folder however
    the recording grows (:func:`symfruit.io.outputs.entry_name`)."""
    return entry_name(name, reserved=reserved)


@dataclass
class BatchReport:
    """What a batch did: frames done, skipped (resume), failed (with reasons), fruit found; ``stopped`` says
    why the batch ended early (a full disk), empty when it ran to the end."""

    done: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)
    fruits: int = 0
    failed_fruits: int = 0
    stopped: str = ""
    #: Frames not reached because the batch stopped (a full disk): recorded in ``errors.json`` too.
    unprocessed: list[str] = field(default_factory=list)
    #: Recordings (several inputs) that could not be opened, by input path, with the reason.
    failed_recordings: dict[str, str] = field(default_factory=dict)
    #: Several inputs: each input path's folder in the output (its ``recording`` in the tables).
    recordings: dict[str, str] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return not self.failed and not self.stopped and not self.failed_recordings


def run_batch(
    source: str | Path | Sequence[str | Path],
    output: str | Path,
    *,
    masks: str = "auto",
    method: str = DEFAULT_METHOD,
    settings: Settings | None = None,
    resume: bool = False,
    progress: bool = True,
    on_frame: Callable[[int, FrameDetections], None] | None = None,
    exclude: Sequence[str | Path] = (),
    scheduler: str | None = None,
    workers: int | None = None,
    chunk: int = 4,
    no_worker_timeout: float | None = None,
    silent_worker_timeout: float | None = None,
    pool: FruitPool | None = None,
) -> BatchReport:
    """Detect fruit in every frame of ``source`` and write each frame's results under ``output``, and the
    fruit of every frame done into ``detections.parquet`` and ``frames.parquet`` (:mod:`symfruit.season.table`).

    ``source`` is one recording (a frame folder, a folder of frames or a bag) or several: with one, each frame's
    folder is ``output/<frame>``; with several, ``output/<recording>/<frame>`` (:func:`plan_recordings`), one
    progress bar, ``errors.json`` and pair of tables over all of them, and a recording that cannot be opened is
    recorded (``failed_recordings``, ``errors.json``) while the others go on.

    In this process, or on a Dask cluster (``pip install 'symfruit[cluster]'``): ``scheduler`` (an existing
    one's address, ``tcp://host:port``) or ``workers`` (a local cluster of that many worker processes),
    ``chunk`` frames per task, ``no_worker_timeout`` seconds waited while the cluster has no worker, a worker
    not heard from for ``silent_worker_timeout`` seconds counting as none
    (:func:`symfruit.season.cluster.run_distributed`; ``on_frame`` is not available there).

    ``pool``: a :class:`~symfruit.fruitpool.FruitPool` the caller keeps, each frame's fruit shared with its workers
    (:func:`~symfruit.detect.detect`'s ``pool``; in this process only: refused with a cluster, whose workers are one
    of several processes already).

    ``on_frame(index, found)`` is called with each frame's detections (``index``: its place in the source)
    inside the frame's error boundary, just before its files are written, so ``detections.json`` still marks
    a frame whose every step succeeded; e.g. to append it to a ROS 2 bag
    (:meth:`symfruit.ros.bag2.Ros2DetectionBag.write_frame`); one recording only. Frames skipped by ``resume``
    are not passed. ``exclude``: further outputs of the run (a ROS 2 bag folder) that are no frames if they lie
    in the source, and whose names no frame folder takes if they lie in ``output``; a ``masks`` file or folder
    given as a path is treated so too, and nothing is written into it.

    The output folder is locked while the batch runs (a second batch on it is refused), is never an input
    folder, and nothing is written through a link out of it (:class:`symfruit.io.outputs.OutputFolder`).
    Every frame ends done or recorded in ``errors.json``: failed with its reason, or, after a full disk
    stopped the batch, unprocessed. With several recordings a frame is named ``<recording>/<frame>`` in the
    report and ``errors.json``.

    Raises
    ------
    SymfruitError
        Only when the source itself cannot be opened (one recording; with several: an input that does not
        exist, is given twice or lies in the output folder), the output folder cannot be used (not writable,
        an input folder, held by another run), the cluster cannot be used, or ``method`` or ``masks`` cannot be
        used by any frame (an unknown method; an empty spec, a masks file or folder that does not exist, a model
        or its extra missing); per-frame problems go into the report.
    """
    get_method(method)  # an unknown method or a masks spec no frame can use: refused before any frame, never
    if isinstance(masks, str | Path) and not (  # reported once per frame of a recording
        (scheduler is not None or workers is not None) and str(masks).startswith(("maskrcnn:", "onnx:"))
    ):  # a model is loaded (once: cached) where it runs; on a cluster, by the workers
        mask_source(masks, settings=settings)
    given_masks = _mask_paths(masks)  # read by the run: no frame folder takes their name, nothing is written there
    exclude = [*exclude, *given_masks]
    if scheduler is not None or workers is not None:
        from .season.cluster import run_distributed

        if on_frame is not None:
            raise InputError("on_frame (--ros2-bag) runs in this process: it cannot be combined with a Dask cluster")
        if pool is not None and pool.processes:
            raise InputError("a fruit pool (--fruit-processes) shares the fruit of the frames run in this process: a "
                             "Dask cluster's workers are one of several processes already")  # fmt: skip
        return run_distributed(source, output, scheduler=scheduler, workers=workers, chunk=chunk, masks=masks,
                               method=method, settings=settings, resume=resume, progress=progress,
                               exclude=exclude, no_worker_timeout=no_worker_timeout,
                               silent_worker_timeout=silent_worker_timeout)  # fmt: skip
    for name, value in (("no_worker_timeout", no_worker_timeout), ("silent_worker_timeout", silent_worker_timeout)):
        if value is not None:
            raise InputError(f"{name} (--{name.replace('_', '-')}) is for a Dask cluster (scheduler or workers)")
    settings = settings or Settings()
    output = as_path(output, "run_batch: the output folder")  # '' was the working folder
    report = BatchReport()
    reserved = [*BATCH_FILES, *(_first_part(Path(p), output) for p in exclude)]
    recordings = plan_recordings(source, output, reserved=reserved)
    if len(recordings) > 1:
        report.recordings = {str(r.source): r.name for r in recordings}
    if on_frame is not None and len(recordings) > 1:
        raise InputError("on_frame (--ros2-bag) takes the frames of one recording: give one input")
    skip = [output, *map(Path, exclude)]
    listed, files, folders, held = list_recordings(recordings, skip, report, keep_open=len(recordings) == 1)
    try:
        if is_frame_folder(output):  # a frame left out of the recording as the output is still an input
            folders.append(output)
        out = OutputFolder(output, inputs=[*files, *(p for p in given_masks if p.is_file())],
                           input_folders=[*folders, *(p for p in given_masks if p.is_dir())]).open()  # fmt: skip
    except BaseException:
        if held is not None:
            held.close()
        raise
    keys = [rec.key + n for rec, names in listed for n in names]
    try:
        reserve_record(output / "errors.json", _errors_record({}, keys, "the batch is running (or was killed)",
                       report.failed_recordings, recordings), entries=len(keys), root=out)  # fmt: skip
        with Progress(len(keys), "detect", enabled=progress and len(keys) > 1) as bar:
            for at, (rec, names) in enumerate(listed):
                src = held if held is not None else _reopen(rec, skip, report)
                if src is None:
                    bar.update(len(names))
                    continue
                try:
                    _run_recording(src, rec, names, masks, method, settings, resume, on_frame, reserved, report,
                                   bar, out, pool)  # fmt: skip
                finally:
                    src.close()
                    held = None
                if report.stopped:
                    report.unprocessed += [r.key + n for r, later in listed[at + 1 :] for n in later]
                    break
        _tables(output, [(rec.name, [(rec.key + n, rec.folder / frame_folder_name(n, reserved)) for n in names])
                         for rec, names in listed], out, report, report.recordings)  # fmt: skip
        errors = _errors_record(report.failed, report.unprocessed, report.stopped, report.failed_recordings,
                                recordings)  # fmt: skip
        try:
            how = write_record(output / "errors.json", errors, root=out)
            if how and report.stopped:
                report.stopped += f"; errors.json {how}"
        except SymfruitError as exc:
            report.stopped = report.stopped or f"cannot write {output / 'errors.json'} ({exc})"
    finally:
        if held is not None:
            held.close()
        out.close()
    return report


def _run_recording(
    src: Any, rec: Recording, names: list[str], masks: str, method: str, settings: Settings, resume: bool,
    on_frame: Callable[[int, FrameDetections], None] | None, reserved: Sequence[str], report: BatchReport,
    bar: Progress, out: OutputFolder, pool: FruitPool | None = None,
) -> None:  # fmt: skip
    """The frames ``names`` of one recording, in this process, each in its error boundary."""
    now = src.names()
    where = {n: i for i, n in enumerate(now)} if now != names else None  # changed since it was listed
    with once_per_recording(str(rec.source)) as current:
        if pool is not None and pool.active:  # frames in a stream: the next one segmented beside the workers
            _stream_recording(src, rec, names, where, masks, method, settings, resume, on_frame, reserved, report,
                              bar, out, pool, current)  # fmt: skip
            return
        for index, name in enumerate(names):
            current[0] = name
            if not _one(src, rec, index, name, names, where, masks, method, settings, resume, on_frame, reserved,
                        report, bar, out, pool):  # fmt: skip
                return


def _stream_recording(
    src: Any, rec: Recording, names: list[str], where: dict[str, int] | None, masks: str, method: str,
    settings: Settings, resume: bool, on_frame: Callable[[int, FrameDetections], None] | None,
    reserved: Sequence[str], report: BatchReport, bar: Progress, out: OutputFolder, pool: FruitPool,
    current: list[str],
) -> None:  # fmt: skip
    """:func:`_run_recording`'s frames with an active ``pool``, in a :class:`~symfruit.detect.DetectStream` (issue
    19, stop 55, docs/pipe55.md): frame n+1 is read and segmented while the workers end frame n's fruit; then frame
    n is finished, frame n+1 started (the workers left a share of its fruit), and frame n written meanwhile. Each
    frame keeps its error boundary, its errors and warnings (a frame's reading and segmentation errors are its own,
    its fruit's come when it is finished, its files' when it is written), and the report lists the frames in their
    order. At most one frame is in flight beside the one read; a full disk or an interrupt drops the one in flight
    (the pool's workers ended, as after an interrupt within a frame), listed as not processed."""
    stream = DetectStream(pool, masks=masks, method=method, settings=settings)
    flight: tuple[int, str, Path] | None = None  # the frame started and not finished: its index, name and folder

    def guarded(work: Callable[[], Any], name: str, folder: Path, failed: dict[str, str]) -> tuple[bool, Any, str]:
        current[0] = name
        return _guarded(work, item=rec.key + name, failed=failed, target=folder, at=f"frame {rec.key + name}",
                        cleanup=partial(_clear_frame, folder, out))  # fmt: skip

    try:
        for index, name in enumerate([*names, None]):  # None: the last frame's end
            later: dict[str, str] = {}  # this frame's failure, recorded after the frame before's outcome
            folder = rec.folder / frame_folder_name(name, reserved) if name is not None else rec.folder
            skip = name is not None and resume and frame_done(folder, name)
            ready: Any = None
            if name is not None and not skip:

                def prepared(index: int = index, name: str = name) -> Any:
                    return stream.prepare(_read(src, rec, index, name, where))

                ready = guarded(prepared, name, folder, later)[1]  # nothing written: never a full disk's stop
            found = None
            if flight is not None:  # the frame before finished: its fruit's error is its own
                done, found, _ = guarded(stream.finish, flight[1], flight[2], report.failed)
                if not done:
                    bar.update()
            started = None
            if ready is not None and name is not None and guarded(partial(stream.start, ready), name, folder, later)[0]:
                started = (index, name, folder)
            if flight is not None and found is not None:  # written while the workers do this frame's fruit
                written = partial(_written, flight[2], flight[0], found, on_frame, settings)
                done, _, report.stopped = guarded(written, flight[1], flight[2], report.failed)
                if report.stopped:  # this frame, started or not, and those after it are not processed
                    report.unprocessed = [rec.key + n for n in names[flight[0] + 1 :]]
                    return
                _counted(report, rec.key + flight[1], done, found)
                bar.update()
            flight = started
            report.failed.update(later)
            if skip:
                report.skipped.append(rec.key + str(name))
            if name is not None and started is None:  # skipped or failed
                bar.update()
    finally:
        stream.abandon()  # a full disk or an interrupt: the frame in flight dropped


def _read(src: Any, rec: Recording, index: int, name: str, where: dict[str, int] | None) -> Any:
    """Frame ``name`` (``index`` when the recording was listed) of ``rec``: ``where`` its index now, where the
    recording changed since it was listed (a frame gone since is refused)."""
    if where is not None and name not in where:
        raise FileFormatError(f"{rec.source}: frame {name} is gone from the recording since the run began")
    return src.read(index if where is None else where[name])


def _written(folder: Path, index: int, found: FrameDetections, on_frame: Callable[[int, FrameDetections], None] | None,
             settings: Settings) -> FrameDetections:  # fmt: skip
    """A frame's detections given to ``on_frame`` and written into ``folder``; returned."""
    if on_frame is not None:
        on_frame(index, found)
    write_detections(folder, found, settings=settings)
    return found


def _counted(report: BatchReport, key: str, done: bool, found: FrameDetections | None) -> None:
    """A frame's outcome in ``report``: done, with its fruit counted (a failed one was recorded by :func:`_guarded`)."""
    if done and found is not None:
        report.done.append(key)
        report.fruits += sum(d.result is not None for d in found.detections)
        report.failed_fruits += sum(d.result is None for d in found.detections)


@contextlib.contextmanager
def once_per_recording(source: str) -> Any:
    """Show each of symfruit's warnings once per recording, not once per frame: a folder of frames whose
    ``camera.json`` files all give lens distortion warned on every frame, 10,000 lines for 10,000 frames (bags
    warn once already). Warnings that differ only by the frame folder's name (``.../NAME/...``, the name held
    in the list yielded, set by the caller per frame) are one; how many were not shown is said at the end. Only
    what would be shown is counted: the filters (``error``, ``ignore``) apply as before."""
    import warnings

    from .errors import SymfruitWarning

    current: list[str] = [""]
    seen: dict[str, int] = {}
    with warnings.catch_warnings():  # restores showwarning on leaving
        show = warnings.showwarning

        def once(message: Any, category: type[Warning], filename: str, lineno: int, file: Any = None,
                 line: str | None = None) -> None:  # fmt: skip
            if issubclass(category, SymfruitWarning):
                text = str(message)
                key = text.replace(f"{os.sep}{current[0]}{os.sep}", f"{os.sep}*{os.sep}") if current[0] else text
                if key in seen:
                    seen[key] += 1
                    return
                seen[key] = 0
            show(message, category, filename, lineno, file, line)

        warnings.showwarning = once
        yield current
    more = sum(seen.values())
    if more:
        warnings.warn(f"{source}: {more} more frame{'s' if more != 1 else ''} gave a warning above (each is shown "
                      "for its first frame only)", SymfruitWarning, stacklevel=2)  # fmt: skip


def _one(
    src: Any, rec: Recording, index: int, name: str, names: list[str], where: dict[str, int] | None, masks: str,
    method: str, settings: Settings, resume: bool, on_frame: Callable[[int, FrameDetections], None] | None,
    reserved: Sequence[str], report: BatchReport, bar: Progress, out: OutputFolder, pool: FruitPool | None = None,
) -> bool:  # fmt: skip
    """Frame ``name`` (``index``) of a recording in its error boundary (:func:`_run_recording`); False when
    the batch stops."""
    key = rec.key + name
    folder = rec.folder / frame_folder_name(name, reserved)
    if resume and frame_done(folder, name):
        report.skipped.append(key)
        bar.update()
        return True

    def one_frame(index: int = index, name: str = name, folder: Path = folder) -> FrameDetections:
        found = detect(_read(src, rec, index, name, where), masks=masks, method=method, settings=settings, pool=pool)
        return _written(folder, index, found, on_frame, settings)

    clear = partial(_clear_frame, folder, out)
    done, found, report.stopped = _guarded(one_frame, item=key, failed=report.failed, target=folder,
                                           at=f"frame {key}", cleanup=clear)  # fmt: skip
    if report.stopped:
        report.unprocessed = [rec.key + n for n in names[index + 1 :]]
        return False
    _counted(report, key, done, found)
    bar.update()
    return True


def frame_done(folder: Path, name: str | None = None) -> bool:
    """Whether a frame's output ``folder`` holds a whole ``detections.json`` record (``--resume`` skips it): one
    that cannot be read back into the tables (truncated by a copy, a crash outside symfruit's atomic writes,
    another tool), or (``name`` given) the record of another frame (a folder copied over), means the frame is run
    again, not skipped and then left out of the tables or listed under the other frame's name. So does a record
    whose files are gone or empty (``overlay.png``, a located fruit's ``fruit_NNN.ply``: deleted or truncated by
    another program after the run; symfruit writes each atomically before the record), so a resumed run leaves
    every frame it counts as done with all its files."""
    from .season.table import read_frame_rows

    if not (folder / "detections.json").is_file():
        return False
    try:
        row, fruits = read_frame_rows(folder / "detections.json", "")
    except SymfruitError:
        return False
    if name is not None and row["frame"] != name:
        return False
    files = ["overlay.png"] + [
        f"fruit_{f['id']:03d}.ply" for f in fruits if f["error"] is None and f["centre_x"] is not None
    ]
    return all(_nonempty_file(folder / n) for n in files)


def _nonempty_file(path: Path) -> bool:
    try:
        return path.is_file() and path.stat().st_size > 0
    except OSError:  # a name too long, a folder without search permission: not there for the run
        return False


@dataclass(frozen=True)
class Recording:
    """One input of a run and where its frames go: ``folder`` is the output folder itself with one input, else
    ``OUT/<name>``; ``name`` fills the tables' ``recording`` column; ``key`` prefixes its frames' names in the
    report and ``errors.json`` (``""`` with one input, else ``<name>/``)."""

    source: Path
    name: str
    folder: Path
    key: str = ""


def plan_recordings(
    sources: str | Path | Sequence[str | Path], output: str | Path, *, reserved: Sequence[str] = BATCH_FILES
) -> list[Recording]:
    """The recordings of a run on ``sources`` (one path or several) writing into ``output``.

    One input keeps the layout of a one-recording run: frames straight under ``output``, the recording named
    by its input (:func:`symfruit.season.table.recording_name`). Several inputs each get a folder
    ``output/<name>``, named by :func:`symfruit.io.outputs.unique_names`: the input's file or folder name where
    it is a safe name no other input shares (and not one of the run's own files, ``reserved``), else the
    cleaned name, ``+`` and a hash of its full path; that name is also its ``recording`` in the tables. The
    names depend on the inputs given, so a ``--resume`` gives the same ones.

    Raises
    ------
    InputError
        For no input, or an input given twice (the same file or folder).
    FileFormatError
        For an input that does not exist (checked before anything runs).
    OutputError
        For an input that is the output folder or lies inside it.
    """
    given: Sequence[Any] = [sources] if isinstance(sources, (str, bytes, os.PathLike)) else sources  # bytes: one
    paths = [as_path(s, "the recording") for s in given]  # '' was the working folder
    if not paths:
        raise InputError("no recording given: name one or more frame folders, folders of frames or bags")
    output = as_path(output, "plan_recordings: the output folder")  # '' was the working folder
    if len(paths) == 1:
        return [Recording(paths[0], recording_name(paths[0]), output)]
    home = os.path.realpath(output)
    seen: dict[str, Path] = {}
    for path in paths:
        if not os.path.lexists(path):
            raise FileFormatError(f"{path}: no such frame folder, folder of frames or bag")
        real = os.path.realpath(path)
        if real == home or real.startswith(home.rstrip(os.sep) + os.sep):
            where = "is" if real == home else "lies inside"
            raise OutputError(f"{path}: this input {where} the output folder {output}; its frames would mix with "
                              "the results: choose an output folder outside every input")  # fmt: skip
        if real in seen:
            raise InputError(f"{path}: the same recording as {seen[real]}; give each recording once")
        seen[real] = path
    names = unique_names([recording_name(p) for p in paths], list(seen), reserved=reserved)
    return [Recording(p, n, output / n, n + "/") for p, n in zip(paths, names, strict=True)]


def list_recordings(
    recordings: Sequence[Recording],
    exclude: Sequence[Path],
    report: BatchReport,
    *,
    keep_open: bool = False,
    inspect: Callable[[Recording, Any, list[Path], list[Path]], None] | None = None,
) -> tuple[list[tuple[Recording, list[str]]], list[Path], list[Path], Any]:
    """Open every recording to list its frames (names only, nothing decoded) and the files and folders the
    run must not write into: ``(listed, files, folders, held)``.

    With one recording, one that cannot be opened raises (as always); with several, it is recorded in
    ``report.failed_recordings`` and left out. ``keep_open``: ``held`` is the one recording still open, for
    the run to read (else ``None``; every recording is closed again). ``inspect(recording, source, files,
    folders)`` is called on each recording listed, while it is open.
    """
    listed: list[tuple[Recording, list[str]]] = []
    files: list[Path] = []
    folders: list[Path] = []
    held = None
    single = len(recordings) == 1
    for rec in recordings:
        try:
            src = open_source(rec.source, exclude=exclude)
        except Exception as exc:
            if single:
                raise
            report.failed_recordings[str(rec.source)] = _reason(exc)
            continue
        try:
            more_files, more_folders = _source_inputs(src)
            names = src.names()
            if inspect is not None:
                inspect(rec, src, more_files, more_folders)
        except Exception as exc:
            src.close()
            if single:
                raise
            report.failed_recordings[str(rec.source)] = _reason(exc)
            continue
        files += more_files
        folders += more_folders
        listed.append((rec, names))
        if keep_open and single:
            held = src
        else:
            src.close()
    return listed, files, folders, held


def _reopen(rec: Recording, exclude: Sequence[Path], report: BatchReport) -> Any:
    """A recording opened again to read its frames (``None``, recorded, when it cannot be any more)."""
    try:
        return open_source(rec.source, exclude=exclude)
    except Exception as exc:
        report.failed_recordings[str(rec.source)] = _reason(exc)
        return None


def _reason(exc: BaseException) -> str:
    return str(exc) if isinstance(exc, SymfruitError) else f"{type(exc).__name__}: {exc}"


def _tables(output: Path, recordings: list[tuple[str, list[tuple[str, Path]]]], out: OutputFolder,
            report: Any, inputs: dict[str, str]) -> None:  # fmt: skip
    """Write the fruit tables of every frame done (:func:`symfruit.season.table.write_run_tables`; per recording
    its name and its frames ``(key, folder)``; ``inputs``: input path to recording name) into ``report``'s run:
    a record that cannot be read back is a failed frame, a table that cannot be written stops the run."""
    try:
        bad = write_run_tables(output, recordings, root=out, inputs={v: k for k, v in inputs.items()})
    except SymfruitError as exc:
        report.stopped = report.stopped or f"cannot write the run's tables ({exc})"  # exc names the table
        return
    for name, reason in bad.items():
        report.failed[name] = reason
        for kept in (report.done, report.skipped):
            if name in kept:
                kept.remove(name)


def _errors_record(
    failed: dict[str, str],
    unprocessed: list[str],
    stopped: str,
    failed_recordings: dict[str, str] | None = None,
    recordings: Sequence[Recording] = (),
) -> dict[str, Any]:
    """``errors.json``: every failed frame with its reason, why the batch stopped, (when it did) every frame
    it did not reach, and (several inputs) every recording that could not be opened: its input and the
    folder it would have had."""
    record: dict[str, Any] = {"failed": [{"frame": k, "reason": v} for k, v in failed.items()], "stopped": stopped}
    if unprocessed:
        record["unprocessed"] = unprocessed
    if failed_recordings:
        named = {str(r.source): r.name for r in recordings}
        record["recordings"] = [{"recording": named.get(k, k), "input": k, "reason": v}
                                for k, v in failed_recordings.items()]  # fmt: skip
    return record


def _source_inputs(src: Any) -> tuple[list[Path], list[Path]]:
    """What a batch must not write over or into: the source's files and folders (a recording's frames)."""
    path = Path(src.path)
    folders = list(src.folders()) if hasattr(src, "folders") else []
    return ([], [path, *folders]) if path.is_dir() else ([path], folders)


def _mask_paths(masks: Any) -> list[Path]:
    """The file or folder a ``masks`` spec reads (a label PNG, a COCO JSON, a folder of each frame's masks),
    or nothing (``auto``, ``color``, a model, a :class:`MaskSource`)."""
    if not isinstance(masks, str | Path):
        return []
    if str(masks) in ("auto", "color") or str(masks).startswith(("maskrcnn:", "onnx:")):
        return []
    path = Path(masks)
    return [path] if path.exists() else []


def _first_part(path: Path, output: Path) -> str:
    """The name under ``output`` that ``path`` takes (its first part there), or ``""``."""
    try:
        rel = Path(os.path.realpath(path)).relative_to(os.path.realpath(output))
    except ValueError:
        return ""
    return rel.parts[0] if rel.parts else ""


def _clear_frame(folder: Path, out: OutputFolder) -> None:
    """Remove what a frame that failed left in its folder (its outputs of this run or an earlier one)."""
    if folder.is_dir() and not folder.is_symlink():
        with contextlib.suppress(SymfruitError, OSError):
            remove_stale(folder, keep=[])


#: Image file suffixes taken from a folder by :func:`segment_images`: every format read when named
#: (:func:`symfruit.io.images.image_suffixes`; GIF, PPM, TIFF, WebP, ...).
IMAGE_SUFFIXES = tuple(sorted(image_suffixes()))

#: A mask source as :func:`segment_images` calls it: ``(color, depth=, camera=) -> (h, w) int labels``.
Masker = Callable[..., np.ndarray]


@dataclass(frozen=True)
class SegmentedImage:
    """One image :func:`segment_images` segmented: fruit found, whether depth rules ran (False: colour
    alone), the segmentation time (milliseconds) and the files written."""

    path: Path
    fruit: int
    used_depth: bool
    ms: float
    written: tuple[Path, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        return {"image": str(self.path), "fruit": self.fruit, "depth": self.used_depth, "ms": round(self.ms, 3),
                "written": [str(p) for p in self.written]}  # fmt: skip


@dataclass
class SegmentReport:
    """What :func:`segment_images` did: the images done, the ones that failed (with reasons), and why it
    stopped early (a full disk), empty when it ran to the end."""

    done: list[SegmentedImage] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)
    stopped: str = ""
    mask_source: str = ""
    #: Images not reached because the batch stopped (a full disk): recorded in ``segment.json`` too.
    unprocessed: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not self.failed and not self.stopped

    @property
    def fruit(self) -> int:
        return sum(d.fruit for d in self.done)


def expand_images(paths: Sequence[str | Path]) -> list[Path]:
    """Image files from files and folders (a folder's images in name order, not recursive: every file in a
    format that is read when named, :data:`IMAGE_SUFFIXES`; hidden files are left out). An entry with an
    image's name that is no regular file (a dangling link, a link loop, a pipe) is listed too, so that the
    batch reports it as failed instead of leaving it out unsaid; a sub-folder is not an image.

    Raises
    ------
    FileFormatError
        For a path that does not exist, or when no image is found.
    """
    out: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            listed = [q for q in p.iterdir() if q.suffix.lower() in IMAGE_SUFFIXES and not q.name.startswith(".")]
            out += sorted(q for q in listed if not q.is_dir())
        elif holds_file(p):  # a dangling or looping link is said to be one
            out.append(p)
        else:
            raise FileFormatError(f"{p}: no such image or folder")
    if not out:
        raise FileFormatError("no images found in " + ", ".join(str(p) for p in paths))
    return out


def _read_depth(path: Path, scale: float, shape: tuple[int, int], image: Path, orientation: int) -> np.ndarray:
    """Depth in metres (float64) from ``.npy`` (metres) or a 16-bit PNG (``scale`` metres per unit), of ``shape`` (that
    of ``image`` as read, its EXIF ``orientation`` applied: the depth's must be the same;
    :func:`symfruit.io.frames.read_depth`)."""
    from .io.frames import read_depth

    depth = read_depth(path, scale, color=(image, orientation), dtype=np.float64)
    if depth.shape != shape:
        raise FileFormatError(f"{path}: depth is {depth.shape[1]}x{depth.shape[0]}, the image {shape[1]}x{shape[0]}")
    return depth


def _depth_file(image: Path, depth: Path | None, n_images: int) -> Path | None:
    if depth is None:
        return None
    if depth.is_dir():
        for name in (image.stem, image.stem + "_depth"):
            for suffix in (".png", ".npy"):
                if holds_file(depth / (name + suffix)):  # one that is no file is refused, not passed over
                    return depth / (name + suffix)
        return None
    if n_images != 1:
        raise InputError(f"--depth {depth} is one file but there are {n_images} images: give a folder of depth images")
    return depth


def _depth_named(image: Path, folder: Path) -> bool:
    """Whether ``folder`` holds an entry named as ``image``'s depth (one that is no file counts: its image fails
    by name)."""
    try:
        return _depth_file(image, folder, 0) is not None
    except SymfruitError:
        return True


def _labeller(
    masks: str | Path | MaskSource | Masker, settings: Settings | None, images: Sequence[Path]
) -> tuple[Callable[[Path, np.ndarray, np.ndarray | None, Any, int], np.ndarray], str]:
    """What :func:`segment_images` runs on each image ``(path, color, depth, camera, orientation) -> labels``
    (``orientation``: the image's EXIF orientation, which a label file read for it must carry too), and a word on
    it: a callable ``(color, depth=, camera=) -> labels`` as it is, anything else through
    :func:`symfruit.segment.mask_source` (checked here, before any image)."""
    if callable(masks) and not isinstance(masks, MaskSource):
        fn = masks
        return (
            lambda path, color, depth, camera, turned=1: np.asarray(fn(color, depth=depth, camera=camera))
        ), getattr(masks, "__name__", "callable")
    source = masks if isinstance(masks, MaskSource) else mask_source(masks, settings=settings, images=images)
    # named by its path: a COCO's row2/0001.png is not row1/0001.png (by file name alone it took row1's fruit)
    return (
        lambda path, color, depth, camera, turned=1: source(
            color, depth, camera, name=str(path), color_file=(path, turned)
        )[0]
    ), source.name


T = TypeVar("T")


def _guarded(
    work: Callable[[], T],
    *,
    item: str,
    failed: dict[str, str],
    target: Path,
    at: str,
    cleanup: Callable[[], None] | None = None,
) -> tuple[bool, T | None, str]:
    """One item of a batch inside its error boundary: ``(done, result, stop)``.

    A :class:`~symfruit.errors.SymfruitError`, an ``OSError`` or any other exception is recorded in
    ``failed[item]``, ``cleanup()`` removes what the item left (so a failed item keeps no results, of this run
    or an earlier one) and the batch goes on; a full disk (``ENOSPC``, ``EFBIG``, ``EDQUOT``, also as an
    :class:`~symfruit.errors.OutputError`'s ``errno``) while writing ``target`` also returns ``stop``, the
    reason to stop the batch (``at``: where, e.g. ``frame 0007``).
    """
    try:
        return True, work(), ""
    except (SymfruitError, OSError) as exc:
        if cleanup is not None:
            cleanup()
        code = getattr(exc, "errno", None)
        if code in _NO_SPACE:
            why = os.strerror(code)
            failed[item] = f"cannot write {target}: {why}"
            return False, None, f"stopped at {at}: the output is full ({why})"
        failed[item] = str(exc) if isinstance(exc, SymfruitError) else f"{type(exc).__name__}: {exc}"
    except Exception as exc:  # the per-item error boundary: record anything and go on
        if cleanup is not None:
            cleanup()
        failed[item] = f"{type(exc).__name__}: {exc}"
    return False, None, ""


def segment_images(
    paths: Sequence[str | Path],
    *,
    output: str | Path,
    masks: str | Path | MaskSource | Masker = "color",
    depth: str | Path | None = None,
    camera: Any = None,
    depth_scale: float = 0.001,
    settings: Settings | None = None,
    progress: bool = False,
) -> SegmentReport:
    """Instance masks for images (files or folders): ``<stem>.png`` (16-bit labels, 0 background, 1..k
    fruit) and ``<stem>_overlay.png`` per image under ``output``, and ``segment.json`` (every image's
    result and every failure).

    Output names never collide: a stem two images share (``a.png``, ``a.jpg``; or one name in two folders)
    or one that is another image's overlay name (``a_overlay``) becomes ``<stem>+<hash of its path>``
    (:func:`symfruit.io.outputs.unique_names`); ``segment.json`` lists what each image wrote. The output
    folder may not be an input folder (the photos', the depth's or the masks'), is locked while the batch
    runs, and nothing is written over an input or through a link out of it.

    Parameters
    ----------
    paths : image files or folders
    output : folder
    masks : a spec of :func:`symfruit.segment.mask_source`, a :class:`~symfruit.segment.MaskSource`, or a callable
        ``(color, depth=, camera=) -> labels``
    depth : file or folder, optional
        Depth for the images (a folder: ``<stem>.png`` / ``<stem>.npy`` / ``<stem>_depth.*``); 16-bit PNG
        depth is ``depth_scale`` metres per unit, ``.npy`` is metres. Images without depth are segmented
        on colour alone (``used_depth`` False: no depth split, the size rule a share of the image).
    camera : Camera-like (``fx``, ``fy``; ``cx``, ``cy``), needed with ``depth``
        With ``width`` and ``height`` (a :class:`~symfruit.core.camera.Camera`) they must be the size of each
        image segmented with depth (intrinsics of another resolution are refused, as ``detect`` does).
    settings : Settings, optional
    progress : bool

    Each image has its own error boundary, as in :func:`run_batch`: an image that cannot be read or
    segmented is reported in ``failed`` and the batch goes on; a full disk stops it cleanly.

    Raises
    ------
    SymfruitError
        Only for the batch as a whole: no images, depth without a camera, an unusable mask source or
        output folder.
    """
    from .io.images import read_color_oriented, turned_mismatch
    from .writers import MAX_LABEL_PNG_ID, write_label_overlay, write_labels

    images = expand_images(paths)
    depth_path = Path(depth) if depth is not None else None
    if depth_path is not None:
        if camera is None:
            raise InputError("segment: depth needs a camera (--camera: fx, fy) to turn metres into pixels")
        if not depth_path.exists():
            raise FileFormatError(f"{depth_path}: no such depth image or folder")
        if not depth_path.is_dir():
            holds_file(depth_path)  # a pipe or device named as the depth image is refused by name, here
            if len(images) != 1:  # before: refused once per image, each image failed with it
                raise InputError(f"--depth {depth_path} is one file but there are {len(images)} images: give a "
                                 "folder of depth images")  # fmt: skip
        elif not any(_depth_named(p, depth_path) for p in images):  # a folder of no image's depth
            # (stop 48, robust48: every image was segmented on colour alone, said in the summary's note alone)
            raise FileFormatError(f"{depth_path}: holds the depth of none of the {len(images)} image(s) (looked for "
                                  f"{images[0].stem}.png / .npy / {images[0].stem}_depth.png / .npy): is it the "
                                  "depth folder?")  # fmt: skip
    if not (np.isfinite(depth_scale) and 0 < depth_scale <= 1.0):
        raise InputError(f"depth_scale must be in (0, 1] metres per unit, got {depth_scale}")
    labeller, source = _labeller(masks, settings, images)
    output = as_path(output, "segment_images: the output folder")  # '' was the working folder
    inputs: list[Path] = list(images)
    folders: list[Path] = sorted({p.parent for p in images})
    for extra in (depth_path, None if callable(masks) else Path(str(masks))):
        if extra is not None and extra.is_dir():
            folders.append(extra)
        elif extra is not None and extra.is_file():
            inputs.append(extra)
    stems = unique_names([p.stem for p in images], [os.path.realpath(p) for p in images], derived=["_overlay"])
    report = SegmentReport(mask_source=source)
    with OutputFolder(output, inputs=inputs, input_folders=folders, what="output folder") as out:
        reserve_record(output / "segment.json", _segment_record(source, report, [str(p) for p in images],
                       "the batch is running (or was killed)"), entries=len(images), root=out)  # fmt: skip
        with Progress(len(images), "segment", enabled=progress and len(images) > 1) as bar:
            for index, (path, stem) in enumerate(zip(images, stems, strict=True)):
                targets = (output / f"{stem}.png", output / f"{stem}_overlay.png")

                def one_image(path: Path = path, targets: tuple[Path, Path] = targets) -> SegmentedImage:
                    color, turned = read_color_oriented(path)
                    dfile = _depth_file(path, depth_path, len(images))
                    z = _read_depth(dfile, depth_scale, color.shape[:2], path, turned) if dfile is not None else None
                    if z is not None:
                        _check_camera(camera, color.shape[:2], path)
                    t0 = time.perf_counter()
                    labels = np.asarray(labeller(path, color, z, camera if z is not None else None, turned))
                    ms = (time.perf_counter() - t0) * 1000.0
                    if labels.shape != color.shape[:2]:
                        turned_mismatch(path, color.shape, {"the mask source's labels": labels.shape})
                        raise InputError(f"{path.name}: the mask source gave labels {labels.dtype} {labels.shape}, "
                                         f"the image is {color.shape[1]}x{color.shape[0]}")  # fmt: skip
                    labels = instance_labels(labels, f"{path.name}: the mask source's labels")
                    top = int(labels.max()) if labels.size else 0
                    if top > MAX_LABEL_PNG_ID:  # refused, not renumbered: a label's id is what masks match by
                        raise InputError(f"{path}: the mask source ({source}) gave label id {top}; a 16-bit label "
                                         f"PNG holds ids up to {MAX_LABEL_PNG_ID}: number the fruit 1..k")  # fmt: skip
                    written = (write_labels(targets[0], labels),
                               write_label_overlay(targets[1], color, labels))  # fmt: skip
                    used = z is not None and bool((z > 0).any())
                    return SegmentedImage(path, len(np.unique(labels[labels > 0])), used, ms, written)

                done, image, report.stopped = _guarded(one_image, item=str(path), failed=report.failed,
                                                       target=output, at=path.name,
                                                       cleanup=partial(_remove, targets, out))  # fmt: skip
                if report.stopped:
                    report.unprocessed = [str(p) for p in images[index + 1 :]]
                    break
                if done and image is not None:
                    report.done.append(image)
                bar.update()
        try:
            how = write_record(output / "segment.json", _segment_record(source, report, report.unprocessed,
                               report.stopped), root=out)  # fmt: skip
            if how and report.stopped:
                report.stopped += f"; segment.json {how}"
        except SymfruitError as exc:
            report.stopped = report.stopped or f"cannot write {output / 'segment.json'} ({exc})"
    return report


def _segment_record(source: str, report: SegmentReport, unprocessed: list[str], stopped: str) -> dict[str, Any]:
    """``segment.json``: every image done (what it wrote), every failure, every image not reached."""
    record = {"mask_source": source, "images": [d.to_dict() for d in report.done],
              "failed": [{"image": k, "reason": v} for k, v in report.failed.items()], "stopped": stopped}  # fmt: skip
    if unprocessed:
        record["unprocessed"] = unprocessed
    return record


def _check_camera(camera: Any, shape: tuple[int, ...], path: Path) -> None:
    """Intrinsics with a size must be for this image's size (as ``detect`` refuses them for a frame)."""
    w, h = getattr(camera, "width", None), getattr(camera, "height", None)
    if w is not None and h is not None and (int(w), int(h)) != (shape[1], shape[0]):
        from .io.images import turned_mismatch

        turned_mismatch(path, shape, {"the intrinsics (--camera)": (int(h), int(w))})
        raise InputError(f"{path}: the intrinsics (--camera) are for {w}x{h} but the image is {shape[1]}x{shape[0]}; "
                         "give the intrinsics of this resolution")  # fmt: skip


def _remove(paths: Sequence[Path], out: OutputFolder) -> None:
    """Remove an image's outputs left from a failed attempt (never through a link; never an input)."""
    for path in paths:
        with contextlib.suppress(SymfruitError, OSError):
            out.check(path)
            with folder_fd(path.parent, root=out, create=False) as fd:
                with contextlib.suppress(FileNotFoundError, IsADirectoryError):
                    os.unlink(path.name, dir_fd=fd)
