"""Why a fruit behind a strip comes out short in depth: ``evidence``'s depth fusion laid out per fruit (issue 18,
stop 58, docs/strip58.md).

    PYTHONPATH=src python docs/strip58.py FRAME_DIR... [--config JSON]

For every fruit of every frame folder (``docs/realpert55.py run OUT`` writes them under ``OUT/frames/NAME/``) one
line: the mask's pixels as drawn, as the colour trim left them, and the region ``evidence`` reads (the points'
silhouette joined with the mask) before and after :func:`~symfruit.core.occlusion.bridged`; the points kept and the
parts :func:`~symfruit.core.surface.across_occluder` joined, with the last part it weighed: whether the joint fit found
one convex surface (its test 2: the curvature, the residuals, the facing edges) and that fit's mean curvature times
the fruit's radius (a sheet under 0.3); the outline's contour share and where the viewing cone came from;
the region's widths across the line of sight and the prior's width (mm); the candidate with the most weight, that
weight and its box (mm); the candidates' fused back face and the prior's, each as a depth from the front (mm) with its
standard deviation; and the box. Read alongside ``fuse_depth``'s docstring: its back face is the inverse-variance mean
of the two, and the prior's spread is ``depth_ratio_sd * width / max(contour, 0.25)``.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

import symfruit.core.surface as surface
import symfruit.detect as detect_module
import symfruit.extract as extract_module
import symfruit.methods.evidence as evidence
from symfruit.detect import detect
from symfruit.io.frames import read_frame
from symfruit.settings import from_dict


def say(text: str) -> None:
    sys.stdout.write(text)


class Spy:
    """Wraps the functions whose inputs explain a fruit's depth and keeps what they saw, per fruit in call order."""

    def __init__(self) -> None:
        self.rows: list[dict[str, Any]] = []
        self.now: dict[str, Any] = {}
        self.trimmed: dict[int, int] = {}

    @contextlib.contextmanager
    def installed(self) -> Iterator[Spy]:
        """The wrappers in place while the block runs, the functions restored after it."""
        trim, across, one = detect_module._trim_labels, extract_module.across_occluder, surface._one_surface
        bridged, combine, fuse = evidence.bridged, evidence.combine, evidence.fuse_depth

        def spy_trim(color, labels, *args, **kwargs):  # type: ignore[no-untyped-def]
            out, which = trim(color, labels, *args, **kwargs)
            self.trimmed = {int(k): int(np.count_nonzero((labels == k) & (out != k))) for k in which}
            return out, which

        def spy_one(rows, cols, z, a, b, tol, focal, radius):  # type: ignore[no-untyped-def]
            ok = one(rows, cols, z, a, b, tol, focal, radius)
            fit = surface._InverseQuadratic(rows[a | b], cols[a | b], z[a | b], focal)
            kappa = fit.curvature()[0] * radius if fit.inverse is not None else math.nan
            self.now.setdefault("tests", []).append(f"({int(b.sum())}: one surface {ok}, k*R {kappa:.2f})")
            return ok

        def spy_across(depth, rows, cols, labels, keep, *args, **kwargs):  # type: ignore[no-untyped-def]
            self.now = {"tests": []}
            joined = across(depth, rows, cols, labels, keep, *args, **kwargs)
            counts = np.bincount(labels)
            self.now["parts"] = "+".join(str(int(counts[k])) for k in np.flatnonzero(joined))
            return joined

        def spy_bridged(region, occ, **kwargs):  # type: ignore[no-untyped-def]
            out = bridged(region, occ, **kwargs)
            # the fruit's last extraction's parts (a first pass on what lies behind it is extracted again)
            self.rows.append({"region": int(region.mask.sum()), "bridged": int(out.mask.sum()), "join": self.now})
            self.now = {}
            return out

        def spy_combine(cands, **kwargs):  # type: ignore[no-untyped-def]
            self.rows[-1]["cone"] = kwargs.get("cone_source")
            return combine(cands, **kwargs)

        def spy_fuse(combined, cands, region, camera, *, s, **kwargs):  # type: ignore[no-untyped-def]
            box, sd, width = fuse(combined, cands, region, camera, s=s, **kwargs)
            across = kwargs["across"]
            z = float(combined.box.centre[2]) / float(across.axis[2])
            front = float(combined.box.min[2])
            top = max(combined.weights, key=combined.weights.get)
            cand = next(c for c in cands if c.name == top)
            self.rows[-1].update(
                contour=combined.contour, widths=(across.minor * z * 1e3, across.major * z * 1e3), width=width * 1e3,
                top=top, weight=combined.weights[top], top_box=(cand.hi - cand.lo) * 1e3,
                fit=(float(combined.box.max[2]) - front) * 1e3, prior=s.depth_ratio * width * 1e3,
                prior_sd=s.depth_ratio_sd * width / max(combined.contour, 0.25) * 1e3, box=box.size * 1e3,
            )  # fmt: skip
            return box, sd, width

        detect_module._trim_labels, extract_module.across_occluder = spy_trim, spy_across
        surface._one_surface = spy_one
        evidence.bridged, evidence.combine, evidence.fuse_depth = spy_bridged, spy_combine, spy_fuse
        try:
            yield self
        finally:
            detect_module._trim_labels, extract_module.across_occluder = trim, across
            surface._one_surface = one
            evidence.bridged, evidence.combine, evidence.fuse_depth = bridged, combine, fuse


def mm(values: Any) -> str:
    return "x".join(f"{v:.0f}" for v in values)


def report(folder: Path, settings: Any) -> None:
    """One table row per fruit of the frame folder ``folder`` (``detect``'s ``evidence`` under ``settings``)."""
    frame = read_frame(folder)
    with Spy().installed() as spy:
        found = detect(frame, method="evidence", settings=settings)  # one fruit after another: no pool
    done = [d for d in found.detections if d.result is not None and d.occlusion is not None]
    for d, row in zip(done, spy.rows, strict=True):
        drawn = int((frame.masks == d.id).sum())
        join = row["join"]
        say(f"| {folder.name} | {d.id} | {drawn} | {drawn - spy.trimmed.get(d.id, 0)} | {row['region']} | "
            f"{row['bridged']} | {len(d.extraction.points)} | {join.get('parts', '-')} "
            f"{' '.join(join.get('tests', []))} | {row['contour']:.2f} {row['cone']} | {mm(row['widths'])}, "
            f"{row['width']:.0f} | {row['top']} {row['weight']:.2f} {mm(row['top_box'])} | {row['fit']:.0f} / "
            f"{row['prior']:.0f} +- {row['prior_sd']:.0f} | {mm(row['box'])} |\n")  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("frames", type=Path, nargs="+", help="frame folders (or folders of frame folders)")
    ap.add_argument("--config", default="", help="settings as JSON text")
    args = ap.parse_args(argv)
    settings = from_dict(json.loads(args.config) if args.config else {})
    say(
        "| frame | fruit | mask px | trimmed | region | bridged | points | parts joined (tests) | contour, cone | "
        "widths, prior width (mm) | top candidate, weight, box (mm) | fit / prior depth (mm) +- prior sd | box (mm) |\n"
    )
    say("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
    for folder in args.frames:
        subs = sorted(p for p in folder.iterdir() if (p / "camera.json").exists())
        for one in subs or [folder]:
            report(one, settings)


if __name__ == "__main__":
    main()
