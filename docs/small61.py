"""Stop 61 (docs/small61.md): box by box, two runs of docs/realpert55.py, and apple by apple, two evaluate summaries.

    python docs/small61.py boxes BASE NEW [--only bin2,bin3,bin2-rim1]
    python docs/small61.py trees BASE/summary.json NEW/summary.json

``boxes``: for each perturbation named and each sphere of both frames, ``evidence``'s box in either run (``run OUT
--methods evidence`` of docs/realpert55.py), its not-a-cube (largest side less smallest) and its depth side less the
unperturbed mask's diameter (mm, the ``none`` row of BASE), and whether it is over the 6 mm bar. ``trees``: per
instance matched in both ``symfruit evaluate --frames F --match id`` summaries, the mean centre error, IoU and depth
and lateral sides (mean absolute, signed), how many changed at all and how many moved by more than 1 mm (centre or
depth side), each of those with its visible share and its figures.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

BAR_MM = 6.0  # issue 18's bar for balls (docs/realpert55.py)


def _boxes(run: Path, name: str) -> dict[tuple[str, int], dict]:
    rows = json.loads((run / f"{name}.json").read_text())["rows"]
    return {(r["frame"], r["sphere"]): r for r in rows if r["method"] == "evidence"}


def boxes(base: Path, new: Path, names: list[str]) -> str:
    """The Markdown table of ``boxes`` (module docstring)."""
    ref = {k: r["diameter"] for k, r in _boxes(base, "none").items()}

    def cell(r: dict, k: tuple[str, int]) -> str:
        if r.get("error"):
            return "failed"
        size = np.array(r["size"])
        cube, depth = float(np.ptp(size)), float(size[2] - ref[k])
        over = "over" if cube > BAR_MM or abs(depth) > BAR_MM else "ok"
        return f"{'x'.join(f'{v:.0f}' for v in size)}, {cube:.1f}, {depth:+.1f} ({over})"

    out = [
        "| perturbation | frame, sphere (diameter mm) | base: box, not a cube, depth - d | new |",
        "|---|---|---|---|",
    ]
    for name in names:
        a, b = _boxes(base, name), _boxes(new, name)
        for k in sorted(a):
            row = f"{k[0][-1]}, s{k[1]} ({ref[k]:.0f})"
            out.append(f"| {name} | {row} | {cell(a[k], k)} | {cell(b[k], k)} |")
    return "\n".join(out)


def trees(base: Path, new: Path) -> str:
    """The per-instance comparison of ``trees`` (module docstring)."""

    def load(p: Path) -> dict[tuple[str, int], dict]:
        return {(r["frame"], r["fruit"]): r for r in json.loads(p.read_text())["scores"]}

    a, b = load(base), load(new)
    keys = sorted(set(a) & set(b))
    lines = [f"matched {len(keys)} (base only {len(set(a) - set(b))}, new only {len(set(b) - set(a))})"]
    for f in ("centre_mm", "iou"):
        lines.append(f"{f}: {np.mean([a[k][f] for k in keys]):.4f} -> {np.mean([b[k][f] for k in keys]):.4f}")
    for f in ("depth_mm", "lateral_mm"):
        ma, mb = (np.mean([abs(x[k][f]) for k in keys]) for x in (a, b))
        sa, sb = (np.mean([x[k][f] for k in keys]) for x in (a, b))
        lines.append(f"{f}: mean abs {ma:.2f} -> {mb:.2f}, signed {sa:+.2f} -> {sb:+.2f}")

    def differ(k: tuple[str, int], tol: float) -> bool:
        return any(abs(a[k][f] - b[k][f]) > tol for f in ("centre_mm", "depth_mm"))

    changed = [k for k in keys if differ(k, 1e-6)]
    moved = [k for k in keys if differ(k, 1.0)]
    better = sum(b[k]["centre_mm"] < a[k]["centre_mm"] for k in moved)
    lines.append(f"changed {len(changed)}, moved by more than 1 mm {len(moved)}: centre better {better}, "
                 f"worse {len(moved) - better}")  # fmt: skip
    for k in moved:
        seen = "?" if a[k].get("visible") is None else f"{a[k]['visible']:.2f}"
        lines.append(f"  {k[0]} fruit {k[1]} (visible {seen}): centre {a[k]['centre_mm']:.1f} -> "
                     f"{b[k]['centre_mm']:.1f} mm, depth side {a[k]['depth_mm']:+.1f} -> {b[k]['depth_mm']:+.1f}, "
                     f"lateral {a[k]['lateral_mm']:+.1f} -> {b[k]['lateral_mm']:+.1f}, "
                     f"IoU {a[k]['iou']:.3f} -> {b[k]['iou']:.3f}")  # fmt: skip
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("boxes", help="box by box, two docs/realpert55.py runs")
    p.add_argument("base", type=Path)
    p.add_argument("new", type=Path)
    p.add_argument("--only", default="bin2,bin3,bin2-rim1", help="perturbations, comma-separated")
    t = sub.add_parser("trees", help="apple by apple, two evaluate summaries")
    t.add_argument("base", type=Path)
    t.add_argument("new", type=Path)
    args = parser.parse_args(argv)
    if args.command == "boxes":
        sys.stdout.write(boxes(args.base, args.new, args.only.split(",")) + "\n")
    else:
        sys.stdout.write(trees(args.base, args.new) + "\n")


if __name__ == "__main__":
    main()
