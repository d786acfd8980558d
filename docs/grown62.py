"""Stop 62 (docs/grown62.md): where a grown mask's box moves, stage by stage, on the real Azure Kinect sphere frames.

For every sphere of a frame perturbed by ``docs/realpert55.py`` (``OUT/frames/NAME/lab-spheres-K``) and of the
same frame unperturbed, ``detect``'s stages are run one by one as ``detect`` runs them (``symfruit.detect``'s own
helpers): the masks as drawn, after the colour trim, after the registration and ``extract.keep_caps``, as
extracted, and the outline the occlusion maps read when they trimmed it (``seen-past``: stop 43 or 56's rule; the
fruit's width is read from it). Each stage's mask is printed against the unperturbed mask: its pixels, how far its
extent lies out of the unperturbed one's on each side (left, right, top, bottom; pixels, + outward) and how far its
centroid moved (pixels). Then the box: its centre's move, its sizes' change and its front face's move against the
unperturbed box (mm).

    PYTHONPATH=src python docs/realpert55.py run OUT --only none,dilate2,dilate5,dilate10 --methods evidence
    PYTHONPATH=src python docs/grown62.py stages OUT/frames/none/lab-spheres-0 OUT/frames/dilate5/lab-spheres-0
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import NamedTuple

import numpy as np

from symfruit import detect as D
from symfruit.core.box import Box
from symfruit.io.frames import read_frame


class Sphere(NamedTuple):
    """One sphere's stages (name -> whole-image bool mask, in order), the frame's shift and its box (None: none)."""

    masks: dict[str, np.ndarray]
    shift: tuple[int, int]
    box: Box | None


def stages(path: Path) -> dict[int, Sphere]:
    """Every sphere of the frame folder ``path`` through ``detect``'s stages, with the default settings."""
    frame = read_frame(path)
    settings = D._default_settings()
    prep = D._prepare(frame, "auto", "evidence", settings, None)
    labels, boxes = prep.labels, prep.boxes
    trimmed, cut = labels, set[int]()
    if frame.color is not None:
        trimmed, cut = D._trim_labels(frame.color, labels, settings.extract, boxes)
    kept_boxes = [D._box_within(trimmed, k, sl) if k in cut else sl for k, sl in enumerate(boxes, 1)]
    moved, shift = D.register(trimmed, frame.depth, frame.camera, settings.extract, boxes=kept_boxes)
    moved = D._kept_caps(frame, labels, trimmed, moved, cut, boxes, shift, settings.extract)
    found = D._start(prep, None).result()
    out = {}
    for d in found.detections:
        k = d.id
        masks = {"drawn": labels == k, "colour": trimmed == k, "moved+caps": moved == k, "extracted": d.mask}
        occ = d.occlusion
        if occ is not None and occ.overshoot is not None and occ.overshoot.any() and occ.own is not None:
            outline = np.zeros_like(d.mask)
            h, w = occ.own.shape
            outline[occ.v0 : occ.v0 + h, occ.u0 : occ.u0 + w] = occ.own & ~occ.overshoot
            masks["seen-past" if occ.seen_past else "spread"] = outline
        out[k] = Sphere(masks, shift, d.result.box if d.result is not None else None)
    return out


def _extent(mask: np.ndarray) -> tuple[np.ndarray, float, float]:
    rows, cols = np.nonzero(mask)
    return np.array([cols.min(), cols.max(), rows.min(), rows.max()]), float(cols.mean()), float(rows.mean())


def report(reference: dict[int, Sphere], perturbed: dict[int, Sphere]) -> str:
    """The stages of ``perturbed`` against ``reference``'s drawn masks and boxes, as text."""
    lines = []
    for k, s in perturbed.items():
        e0, x0, y0 = _extent(reference[k].masks["drawn"])
        lines.append(f"sphere {k}: shift {s.shift}")
        for name, m in s.masks.items():
            if not m.any():
                lines.append(f"  {name:11s} no pixel")
                continue
            e, x, y = _extent(m)
            o = (e - e0) * np.array([-1, 1, -1, 1])
            lines.append(f"  {name:11s} {int(m.sum()):6d} px  out L{o[0]:+d} R{o[1]:+d} T{o[2]:+d} B{o[3]:+d}  "
                         f"centroid {x - x0:+.1f}, {y - y0:+.1f} px")  # fmt: skip
        ref = reference[k].box
        if s.box is not None and ref is not None:
            dc = (s.box.centre - ref.centre) * 1000.0
            ds = (s.box.size - ref.size) * 1000.0
            front = (s.box.centre[2] - s.box.size[2] / 2 - ref.centre[2] + ref.size[2] / 2) * 1000.0
            lines.append(f"  box: centre moved {np.round(dc, 1).tolist()} ({np.linalg.norm(dc):.1f}) mm, sizes "
                         f"{np.round(ds, 1).tolist()} mm, front face {front:+.1f} mm")  # fmt: skip
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("stages", help="each stage's mask and the box against the unperturbed frame's")
    s.add_argument("reference", type=Path, help="the unperturbed frame folder")
    s.add_argument("frames", type=Path, nargs="+", help="perturbed frame folders")
    a = ap.parse_args(argv)
    reference = stages(a.reference)
    for path in a.frames:
        sys.stdout.write(f"== {path}\n" + report(reference, stages(path)))


if __name__ == "__main__":
    main()
