"""``symfruit demo``: detect the fruit of the shipped example frame and compare them with its truth.

The frame ships as package data (``symfruit/data/example_frame``), so the demo runs from any folder
however symfruit was installed; ``examples/make_sample.py`` regenerates it from :data:`FRAME_SEED`.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

from .core.box import centre_deviation
from .detect import Detection, FrameDetections, detect
from .evaluate.frames import match
from .io.frames import read_frame
from .io.outputs import OutputFolder
from .io.text import as_path
from .methods import DEFAULT_METHOD
from .settings import Settings
from .writers import write_detections

__all__ = ["FRAME_SEED", "DemoReport", "example_frame", "run_demo"]

#: Seed of the shipped frame (:func:`symfruit.synthetic.scenes.make_scene`: touching fruit, leaves in front).
FRAME_SEED = 1


@contextlib.contextmanager
def example_frame() -> Iterator[Path]:
    """The shipped example frame folder, as a real path for the duration of the ``with`` block."""
    with resources.as_file(resources.files("symfruit") / "data" / "example_frame") as path:
        yield Path(path)


@dataclass(frozen=True)
class DemoReport:
    """What the demo found: the detections, the ripe fruit of the truth, and per-fruit centre errors
    (mm) of the visible box and of the completed box against the matched true fruit (None: unmatched)."""

    found: FrameDetections
    n_truth: int
    errors: dict[int, tuple[float, float] | None]
    output: Path

    @property
    def located(self) -> list[Detection]:
        return [d for d in self.found.detections if d.result is not None]

    def mean_errors(self) -> tuple[float, float] | None:
        """Mean centre error (mm) of the raw and the completed boxes over the matched fruit."""
        pairs = [e for e in self.errors.values() if e is not None]
        return (float(np.mean([p[0] for p in pairs])), float(np.mean([p[1] for p in pairs]))) if pairs else None


def run_demo(output: str | Path, *, method: str = DEFAULT_METHOD, settings: Settings | None = None) -> DemoReport:
    """Detect the example frame's fruit, write the outputs to ``output``, score them against the truth."""
    from .methods.registry import get

    get(method)  # an unknown method refused before the output folder is made
    output = as_path(output, "demo: the output folder")  # '' was the working folder
    with example_frame() as folder:
        frame = read_frame(folder)
        source = Path(folder)  # the frame's folder, an input: never written into (--output it is refused)
        inputs = [p for p in source.iterdir() if p.is_file()]
    settings = settings or Settings()
    with OutputFolder(output, inputs=inputs, input_folders=[source]):  # checked before the work; locked, no link
        found = detect(frame, method=method, settings=settings)
        write_detections(output, found, settings=settings)
    truth = frame.truth or []
    ok = [d for d in found.detections if d.result is not None]
    pairs = dict(match([d.visible_box for d in ok], [b for _, b in truth]))
    errors: dict[int, tuple[float, float] | None] = {}
    for i, d in enumerate(ok):
        if i in pairs and d.result is not None and d.visible_box is not None:
            tbox = truth[pairs[i]][1]
            errors[d.id] = (centre_deviation(d.visible_box, tbox) * 1000, centre_deviation(d.result.box, tbox) * 1000)
        else:
            errors[d.id] = None
    return DemoReport(found=found, n_truth=len(truth), errors=errors, output=output)
