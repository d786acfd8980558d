"""Run ``detect`` over a recording (a frame folder, a folder of frames or a bag) without losing anything.

Every frame gets its own output folder; a frame that fails is recorded in ``errors.json`` with its
reason and the batch goes on. Files are written atomically and ``detections.json`` last, so with
``resume=True`` a re-run skips exactly the frames already done.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from .config import Settings
from .detect import detect, write_detections
from .errors import SymfruitError
from .io import write_json
from .io.frames import iter_frames
from .progress import Progress

__all__ = ["BatchReport", "run_batch", "safe_name"]


def safe_name(name: str) -> str:
    """A file name derived from an input name that cannot leave its folder (no separators, no ``..``)."""
    clean = re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._")
    return clean[:120] or "frame"


@dataclass
class BatchReport:
    """What a batch did: frames done, skipped (resume), failed (with reasons), fruit found."""

    done: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)
    fruits: int = 0
    failed_fruits: int = 0

    @property
    def ok(self) -> bool:
        return not self.failed


def run_batch(
    source: str | Path,
    output: str | Path,
    *,
    masks: str = "auto",
    method: str = "fused",
    settings: Settings | None = None,
    resume: bool = False,
    progress: bool = True,
) -> BatchReport:
    """Detect fruit in every frame of ``source`` and write each frame's results under ``output``."""
    settings = settings or Settings()
    output = Path(output)
    report = BatchReport()
    frames = list(iter_frames(source))
    used: set[str] = set()
    with Progress(len(frames), "detect", enabled=progress and len(frames) > 1) as bar:
        for name, frame in frames:
            folder_name = safe_name(name)
            while folder_name in used:
                folder_name += "_"
            used.add(folder_name)
            folder = output / folder_name
            if resume and (folder / "detections.json").is_file():
                report.skipped.append(name)
                bar.update()
                continue
            try:
                if isinstance(frame, Exception):
                    raise frame
                found = detect(frame, masks=masks, method=method, settings=settings)
                write_detections(folder, found, settings=settings)
                report.done.append(name)
                report.fruits += sum(d.result is not None for d in found.detections)
                report.failed_fruits += sum(d.result is None for d in found.detections)
            except SymfruitError as exc:
                report.failed[name] = str(exc)
            bar.update()
    write_json(output / "errors.json", {"failed": [{"frame": k, "reason": v} for k, v in report.failed.items()]})
    return report
