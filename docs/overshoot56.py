"""Stop 56 (docs/overshoot56.md): a generous mask on the real Azure Kinect frames, read by its outline's sectors.

    PYTHONPATH=src python docs/overshoot56.py lateral OUT [OUT2]   # after docs/realpert55.py run OUT
    PYTHONPATH=src python docs/overshoot56.py sectors FRAME        # e.g. OUT/frames/dilate5/lab-spheres-0

``lateral``: per perturbation of ``docs/realpert55.py run OUT`` (``evidence`` boxes), the larger lateral side and
the 2D thin-lens estimate (the perturbed mask's fitted circle at the box's depth, the scorer's ``diameter``), both
less the *unperturbed* mask's diameter: mean abs (signed mean) in mm, and the boxes whose lateral side is farther off
than the thin-lens estimate. With ``OUT2`` (another tree's run), its lateral side and boxes worse than its own
thin-lens estimate beside. The thin-lens estimate is of the mask ``detect`` used (after the colour trim).

``sectors``: ``detect`` the frame with ``evidence`` and, for every mask whose overshoot is looked for in the depth
(the colour left it whole) on a time-of-flight view, the outline read in :data:`symfruit.core.occlusion.SECTORS`
sectors about the points' centroid (``symfruit.core.occlusion._seen_past``'s reading): per sector the mask's
farthest pixel (``reach``), the farthest point pixel (``last``), the nearest pixel seen past (``first``), where
both are found the overshoot past halfway (``halfway``: ``reach - (last + first) / 2``, stop 43's edge) and the
mask's pixels seen past (``inside``: ``reach - first + 1/2``, stop 56's reading), and whether the band holds depth
not seen past (a support or the fruit's own surface, ``level``); then the largest arc without a sector seen past,
the opposite pairs both seen past, and whether stop 43's or stop 56's rule cut the mask.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np


def _rows(out: Path, name: str) -> list[dict]:
    return json.loads((out / f"{name}.json").read_text())["rows"]


def lateral(out: Path, other: Path | None = None) -> str:
    reference = {(r["frame"], r["sphere"]): r["diameter"] for r in _rows(out, "none")}
    head = "| perturbation | thin-lens - diameter (mm) | `evidence` lateral - diameter (mm) | worse than thin-lens |"
    lines = [
        head + (" OUT2's `evidence` lateral, worse than its thin-lens |" if other else ""),
        "|---|---|---|---|" + ("---|" if other else ""),
    ]
    for path in sorted(out.glob("*.json"), key=lambda p: (p.stem != "none", p.stem)):
        rows = _rows(out, path.stem)
        ref = np.array([reference[(r["frame"], r["sphere"])] for r in rows])
        thin = np.array([r["diameter"] for r in rows]) - ref
        lat = np.array([max(r["size"][:2]) for r in rows]) - ref
        cells = [f"{np.abs(a).mean():.1f} ({a.mean():+.1f})" for a in (thin, lat)]
        line = f"| {path.stem} | {cells[0]} | {cells[1]} | {int(np.sum(np.abs(lat) > np.abs(thin)))} / {len(rows)} |"
        if other is not None and (other / path.name).exists():
            b = np.array([max(r["size"][:2]) for r in _rows(other, path.stem)]) - ref
            thin2 = np.array([r["diameter"] for r in _rows(other, path.stem)]) - ref
            line += f" {np.abs(b).mean():.1f} ({b.mean():+.1f}), {int(np.sum(np.abs(b) > np.abs(thin2)))} worse |"
        lines.append(line)
    return "\n".join(lines) + "\n"


def sectors(frame_dir: Path) -> str:
    import symfruit.core.occlusion as oc
    from symfruit.detect import detect
    from symfruit.io import read_frame

    calls: list[tuple[dict, np.ndarray | None]] = []
    seen_past = oc._seen_past

    def spy(own, seen, d, band, points, focal, eroded, tolerance, sectors=oc.SECTORS, *, ahead=None):
        out = seen_past(own, seen, d, band, points, focal, eroded, tolerance, sectors, ahead=ahead)
        calls.append(({"own": own, "seen": seen, "d": d, "band": band, "points": points, "focal": focal,
                       "tolerance": tolerance, "ahead": ahead}, out))  # fmt: skip
        return out

    oc._seen_past = spy
    try:
        detect(read_frame(frame_dir), method="evidence")
    finally:
        oc._seen_past = seen_past
    n = oc.SECTORS
    lines = []
    for c, out in calls:
        own, seen, d, band, points = c["own"], c["seen"], c["d"], c["band"], c["points"]
        front = float(points[:, 2].min())
        half = 0.5 * np.sqrt(4.0 * np.count_nonzero(own) / np.pi) * front / c["focal"]
        past = band & (np.where(band, d, 0.0) > front + half + c["tolerance"])
        past &= ~oc._joined(own, seen, d, c["focal"], c["tolerance"])
        rs, cs = np.nonzero(seen)
        vv, uu = np.nonzero(own)
        ang = np.arctan2(vv - rs.mean(), uu - cs.mean())
        sec = np.minimum(((ang + np.pi) / (2 * np.pi) * n).astype(np.intp), n - 1)
        rad = np.hypot(vv - rs.mean(), uu - cs.mean())
        reach, last, first = np.zeros(n), np.full(n, -np.inf), np.full(n, np.inf)
        np.maximum.at(reach, sec, rad + 0.5)
        m, p = seen[vv, uu], past[vv, uu]
        np.maximum.at(last, sec[m], rad[m])
        np.minimum.at(first, sec[p], rad[p])
        level = band & ~past & (~c["ahead"] if c["ahead"] is not None else True)
        support = np.zeros(n, bool)
        support[sec[level[vv, uu]]] = True
        both = np.isfinite(last) & np.isfinite(first) & (first > last)
        at = np.flatnonzero(both)
        gap = int(np.diff(np.r_[at, at[0] + n]).max()) if len(at) else n
        pairs = int(np.count_nonzero(both[: n // 2] & both[n // 2 :]))
        lines.append(f"mask {2 * np.sqrt(np.count_nonzero(own) / np.pi):.1f} px across at {front:.3f} m: "
                     f"{int(both.sum())} sectors seen past, largest arc without {gap} of {n}, opposite pairs "
                     f"{pairs}, cut: {'no' if out is None else int(out.sum())} px")  # fmt: skip

        def row(name: str, a: np.ndarray, fmt: str = "{:4.0f}") -> str:
            return f"  {name:8s}" + "".join(fmt.format(x) if np.isfinite(x) else "   ." for x in a)

        with np.errstate(invalid="ignore"):
            halfway = np.where(both, reach - 0.5 * (last + first), np.nan)
        inside = np.where(both, reach - first + 0.5, np.nan)
        lines += [row("reach", reach), row("last", last), row("first", first), row("halfway", halfway, "{:4.1f}"),
                  row("inside", inside, "{:4.1f}"), row("level", np.where(support, 1.0, np.nan))]  # fmt: skip
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    a = sub.add_parser("lateral")
    a.add_argument("out", type=Path)
    a.add_argument("other", type=Path, nargs="?")
    b = sub.add_parser("sectors")
    b.add_argument("frame", type=Path)
    args = ap.parse_args(argv)
    sys.stdout.write(lateral(args.out, args.other) if args.cmd == "lateral" else sectors(args.frame))


if __name__ == "__main__":
    main()
