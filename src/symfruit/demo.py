"""``symfruit demo``: detect the fruit of the shipped example frame and compare with its truth."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .box import centre_deviation
from .config import Settings
from .detect import detect, write_detections
from .errors import FileFormatError
from .evaluate.frames import match
from .io.frames import read_frame

__all__ = ["example_frame", "run_demo"]


def example_frame() -> Path:
    """The shipped example frame: ``examples/frame`` of the source tree (or of the working folder)."""
    for base in (Path.cwd(), Path(__file__).resolve().parents[2]):
        folder = base / "examples" / "frame"
        if (folder / "color.png").is_file():
            return folder
    raise FileFormatError("the example frame (examples/frame) is not here; run from a clone of the repository")


def run_demo(output: Path, *, method: str = "fused", fruit: str | None = "strawberry") -> int:
    """Detect, write the outputs, print a per-fruit table; returns the exit status."""
    frame = read_frame(example_frame())
    settings = Settings()
    if fruit:
        from .profiles import load_profile

        settings = load_profile(fruit)
    found = detect(frame, method=method, settings=settings)
    write_detections(output, found, settings=settings)
    truth = frame.truth or []
    ok = [d for d in found.detections if d.result is not None]
    pairs = dict(match([d.visible_box for d in ok], [b for _, b in truth]))
    print(f"symfruit demo: {frame.name} ({frame.camera.width}x{frame.camera.height}), "
          f"{len(found.detections)} fruit found, {len(truth)} ripe fruit in the truth, method {method}")  # fmt: skip
    print(f"{'fruit':>5} {'points':>6}  {'centre x, y, z (mm)':<24} {'size x, y, z (mm)':<20} "
          f"{'raw err':>8} {'completed err':>13}")  # fmt: skip
    raw_err, done_err = [], []
    for i, d in enumerate(ok):
        c, s = d.result.centre * 1000, d.result.box.size * 1000
        line = f"{d.id:>5} {len(d.extraction.points):>6}  {c[0]:7.1f} {c[1]:7.1f} {c[2]:7.1f}  "
        line += f"{s[0]:5.1f} {s[1]:5.1f} {s[2]:5.1f}  "
        if i in pairs:
            tbox = truth[pairs[i]][1]
            e_raw = centre_deviation(d.visible_box, tbox) * 1000
            e_done = centre_deviation(d.result.box, tbox) * 1000
            raw_err.append(e_raw)
            done_err.append(e_done)
            line += f"{e_raw:6.1f} mm {e_done:10.1f} mm"
        else:
            line += f"{'-':>8} {'-':>13}  (no true fruit matched)"
        print(line + (" (truncated)" if d.extraction.truncated else ""))
    for d in found.detections:
        if d.result is None:
            print(f"{d.id:>5} failed: {d.error}")
    if raw_err:
        print(f"mean centre error: raw {np.mean(raw_err):.1f} mm, completed {np.mean(done_err):.1f} mm")
    print(f"time: {found.timings['total'] * 1000:.0f} ms (segment {found.timings['segment'] * 1000:.0f}, "
          f"extract {found.timings['extract'] * 1000:.0f}, "
          f"complete {found.timings['complete'] * 1000:.0f})")  # fmt: skip
    print(f"overlay: {output / 'overlay.png'}")
    print(f"detections: {output / 'detections.json'}")
    return 0
