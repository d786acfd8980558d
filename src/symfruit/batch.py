"""Run ``detect`` over a recording (a frame folder, a folder of frames or a bag) without losing anything.

Frames are decoded one at a time (:mod:`symfruit.io.sources`), so memory stays flat however long the
recording. Every frame gets its own output folder; a frame that fails, for whatever reason, is recorded in
``errors.json`` with its reason and the batch goes on. A full disk stops the batch cleanly (what was
written stays whole, the frame is reported). Files are written atomically and ``detections.json`` last,
so with ``resume=True`` a re-run skips exactly the frames already done, deciding before it decodes them.
"""

from __future__ import annotations

import errno
import hashlib
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from .detect import FrameDetections, detect
from .errors import FileFormatError, SymfruitError
from .io.atomic import write_json
from .io.sources import open_source
from .progress import Progress
from .settings import Settings
from .writers import write_detections

__all__ = ["BatchReport", "frame_folder_name", "run_batch"]

#: Errors that mean the output cannot take more data: the batch stops instead of failing every frame.
_NO_SPACE = {errno.ENOSPC, errno.EFBIG, errno.EDQUOT}


def frame_folder_name(name: str) -> str:
    """The output folder name of a frame: ``name`` itself when it is a safe file name, else a sanitised
    name plus a short hash of the original, so two names never share a folder however the recording grows."""
    clean = re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._")[:100]
    if clean == name and name:
        return name
    digest = hashlib.sha1(name.encode("utf-8", "surrogateescape")).hexdigest()[:8]
    return f"{clean or 'frame'}-{digest}"


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

    @property
    def ok(self) -> bool:
        return not self.failed and not self.stopped


def run_batch(
    source: str | Path,
    output: str | Path,
    *,
    masks: str = "auto",
    method: str = "fused",
    settings: Settings | None = None,
    resume: bool = False,
    progress: bool = True,
    on_frame: Callable[[int, FrameDetections], None] | None = None,
) -> BatchReport:
    """Detect fruit in every frame of ``source`` and write each frame's results under ``output``.

    ``on_frame(index, found)`` is called with each frame's detections (``index``: its place in the source)
    inside the frame's error boundary, just before its files are written, so ``detections.json`` still marks
    a frame whose every step succeeded; e.g. to append it to a ROS 2 bag
    (:meth:`symfruit.ros.bag2.Ros2DetectionBag.write_frame`). Frames skipped by ``resume`` are not passed.

    Raises
    ------
    SymfruitError
        Only when the source itself cannot be opened; per-frame problems go into the report.
    """
    settings = settings or Settings()
    output = Path(output)
    report = BatchReport()
    src = open_source(source, exclude=[output])
    try:
        output.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        src.close()
        raise FileFormatError(f"{output}: cannot write to folder ({exc.strerror or exc})") from None
    for stale in output.glob(".*.tmp"):  # a killed run's half-written errors.json
        stale.unlink(missing_ok=True)
    try:
        names = src.names()
        with Progress(len(names), "detect", enabled=progress and len(names) > 1) as bar:
            for index, name in enumerate(names):
                folder = output / frame_folder_name(name)
                if resume and (folder / "detections.json").is_file():
                    report.skipped.append(name)
                    bar.update()
                    continue
                try:
                    found = detect(src.read(index), masks=masks, method=method, settings=settings)
                    if on_frame is not None:
                        on_frame(index, found)
                    write_detections(folder, found, settings=settings)
                except SymfruitError as exc:
                    report.failed[name] = str(exc)
                except OSError as exc:
                    if exc.errno in _NO_SPACE:
                        report.failed[name] = f"cannot write {folder}: {exc.strerror}"
                        report.stopped = f"stopped at frame {name}: the output is full ({exc.strerror})"
                        break
                    report.failed[name] = f"{type(exc).__name__}: {exc}"
                except Exception as exc:  # the per-frame error boundary: record anything and go on
                    report.failed[name] = f"{type(exc).__name__}: {exc}"
                else:
                    report.done.append(name)
                    report.fruits += sum(d.result is not None for d in found.detections)
                    report.failed_fruits += sum(d.result is None for d in found.detections)
                bar.update()
    finally:
        src.close()
    errors = {"failed": [{"frame": k, "reason": v} for k, v in report.failed.items()], "stopped": report.stopped}
    try:
        write_json(output / "errors.json", errors)
    except (SymfruitError, OSError) as exc:
        report.stopped = report.stopped or f"cannot write {output / 'errors.json'} ({exc})"
    return report
