"""Stop 62, true62 (docs/true62.md): the real sphere frames' leaf perturbations at their true registration.

``boxes OUT NAMES``: every box of a ``docs/realpert55.py run OUT`` folder under the perturbations ``NAMES``
(comma-separated) against the unperturbed run's diameter, those over the 6 mm bar marked. ``sheet FRAME ID``: the
sheet test behind the mask ``ID`` of a frame folder (the parts, the sheet's and each part's curvature times the
radius, what :func:`symfruit.core.surface.thin_front` returns). ``trees A B``: two ``symfruit evaluate --output``
folders apple by apple (mean IoU, centre, depth side; the apples that moved).
"""

from __future__ import annotations

import argparse
import glob
import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np


def say(text: str) -> None:
    sys.stdout.write(text + "\n")


def boxes(out: Path, names: list[str]) -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import realpert55 as rp

    ref = {(r.frame, r.sphere, r.method): r.diameter for r in rp.load(out, "none")}
    for name in names:
        for r in rp.load(out, name):
            if r.error:
                say(f"{name:22s} {r.frame[-1]} s{r.sphere} failed: {r.error[:70]}")
                continue
            r = replace(r, diameter=ref[(r.frame, r.sphere, r.method)])
            over = "OVER" if r.cube_mm > rp.BAR_MM or abs(r.depth_mm) > rp.BAR_MM else ""
            size = "x".join(f"{v:.0f}" for v in r.size)
            say(f"{name:22s} {r.frame[-1]} s{r.sphere} {size:>12s} d {r.diameter:5.1f} not a cube {r.cube_mm:4.1f} "
                  f"depth {r.depth_mm:+5.1f} {over}")  # fmt: skip


def sheet(frame_dir: Path, k: int) -> None:
    import symfruit.core.surface as S
    from symfruit.extract import extract
    from symfruit.io.frames import read_frame

    frame = read_frame(frame_dir)
    depth, mask = np.asarray(frame.depth, np.float64), frame.masks == k
    fits: list[tuple[float, float]] = []
    behind_sheet, mean_curvature, curvature = S._behind_sheet, S._mean_curvature, S._InverseQuadratic.curvature

    def traced_sheet(*args, **kwargs):  # type: ignore[no-untyped-def]
        fits.clear()
        found = behind_sheet(*args, **kwargs)
        radius = args[4]
        say(f"  behind_sheet: front {args[3]:.3f} m, radius {radius * 1000:.1f} mm; fits (kappa R, error R): "
              + ", ".join(f"{a * radius:.3f} +- {b * radius:.3f}" for a, b in fits)
              + f" -> {None if found is None else round(found[0], 4)}")  # fmt: skip
        return found

    def traced_mean(*args):  # type: ignore[no-untyped-def]
        fits.append(mean_curvature(*args))
        return fits[-1]

    def traced_curvature(self):  # type: ignore[no-untyped-def]
        fits.append(curvature(self))
        return fits[-1]

    S._behind_sheet, S._mean_curvature, S._InverseQuadratic.curvature = traced_sheet, traced_mean, traced_curvature
    try:
        points = extract(mask, depth, frame.camera).points
    finally:
        S._behind_sheet, S._mean_curvature, S._InverseQuadratic.curvature = behind_sheet, mean_curvature, curvature
    seen = depth[mask & (depth > 0)]
    say(f"mask {k}: {int(mask.sum())} px, depth 1st / 50th percentile {np.percentile(seen, 1):.3f} / "
          f"{np.median(seen):.3f} m; {len(points)} points, nearest {points[:, 2].min():.3f} m")  # fmt: skip


def trees(a: str, b: str) -> None:
    def load(folder: str) -> dict[tuple[str, int], dict]:
        found = sorted(glob.glob(f"{folder}/*/summary.json"))[-1]
        rows = json.loads(Path(found).read_text())["scores"]
        return {(s["frame"], s["fruit"]): s for s in rows if s["method"] == "evidence"}

    first, second = load(a), load(b)
    keys = sorted(set(first) & set(second))
    for name, d in (("A", first), ("B", second)):
        depth = np.array([d[k]["depth_mm"] for k in keys])
        say(f"{name}: {len(d)} apples, IoU {np.mean([d[k]['iou'] for k in keys]):.4f}, centre "
              f"{np.mean([d[k]['centre_mm'] for k in keys]):.4f} mm, depth side {np.abs(depth).mean():.3f} "
              f"({depth.mean():+.3f}) mm")  # fmt: skip
    moved = [k for k in keys if first[k]["iou"] != second[k]["iou"] or first[k]["centre_mm"] != second[k]["centre_mm"]]
    say(f"{len(moved)} apples moved, {sum(abs(first[k]['centre_mm'] - second[k]['centre_mm']) > 1 for k in moved)} "
          "by more than 1 mm")  # fmt: skip
    for k in moved:
        x, y = first[k], second[k]
        say(f"  {k}: IoU {x['iou']:.3f} -> {y['iou']:.3f}, centre {x['centre_mm']:.1f} -> {y['centre_mm']:.1f} mm")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("boxes", help="every box of a realpert55 run, those over the 6 mm bar marked")
    p.add_argument("out", type=Path)
    p.add_argument("names", help="comma-separated perturbations")
    p = sub.add_parser("sheet", help="the sheet test behind one mask of a frame folder")
    p.add_argument("frame", type=Path)
    p.add_argument("id", type=int)
    p = sub.add_parser("trees", help="two evaluate --output folders apple by apple")
    p.add_argument("a")
    p.add_argument("b")
    args = parser.parse_args(argv)
    if args.command == "boxes":
        boxes(args.out, args.names.split(","))
    elif args.command == "sheet":
        sheet(args.frame, args.id)
    else:
        trees(args.a, args.b)


if __name__ == "__main__":
    main()
