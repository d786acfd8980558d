"""Stop 64 (docs/grown64.md): what the depth says about a grown mask's overshoot on the real Azure Kinect spheres.

Two probes on the real sphere frames perturbed by ``docs/realpert55.py`` (``OUT/frames/NAME/lab-spheres-K``):

- ``pairs``: for every sphere of a frame, along rays from its mask's centroid in each of ``core.occlusion.SECTORS``
  sectors where the depth does not run on across the outline (a support at the sphere's depth): how far inside the
  mask's outline the sphere's last depth lies (the lost rim, ``rim``), and how far inside it the first pixel seen past
  the sphere lies (``past``; negative: beyond the outline, read up to half the mask's radius out). Each as the median
  over all such sectors and over opposite pairs of them (a pair's mean: a displacement of depth against colour adds
  to one side what it takes from the other). ``shadow``: the band of background the colour camera sees beside the
  sphere and the depth camera does not, ``B f (1 / z_fruit - 1 / z_background)`` with the colour camera ``B`` metres
  along x from the depth camera (``--baseline``, the Azure Kinect's 0.032), and ``past`` with half of it added on
  each pair (times the pair's ``|cos|``: the band lies along x).
- ``variant``: the boxes of ``detect`` (method ``evidence``, default settings) on the frames of a realpert55 output
  folder, with stop 56's partial rule (``core.occlusion._seen_past_in_part``) reading the first pixel seen past beyond
  the mask's outline too (a pair then counts where one side's background starts outside the mask: the pairs' mean is
  a lower bound of the overshoot, never clipped at the outline), and with ``--baseline B`` that lower bound plus half
  the colour camera's shadow. Writes ``OUT/NAME.json`` as ``realpert55.py run`` does, so ``realpert55.py summary
  OUT --compact`` reads it (``none`` is always run: the reference diameters).

    PYTHONPATH=src python docs/grown64.py pairs OUT/frames/none/lab-spheres-0 OUT/frames/dilate5/lab-spheres-0
    PYTHONPATH=src python docs/grown64.py variant OUT64 --frames OUT [--only dilate2,dilate5] [--baseline 0.032]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import realpert55 as RP
from support63 import _continuous, _deepest, _ray

import symfruit.core.occlusion as O
from symfruit.evaluate.spheres import evaluate_spheres
from symfruit.io.frames import read_frame
from symfruit.settings import from_dict

HALF = O.SECTORS // 2


def sector_reads(depth: np.ndarray, mask: np.ndarray, focal: float, baseline: float) -> dict[str, np.ndarray]:
    """Per sector about ``mask``'s centroid (NaN where the depth runs on across the outline or nothing is read):
    ``rim`` the outline's distance beyond the last depth at the fruit's level, ``past`` beyond the first pixel seen
    past (negative: that pixel lies outside the mask), ``shadow`` the colour camera's shadow there (px), ``cos`` the
    sector's ``|cos|``."""
    rs, cs = np.nonzero(mask)
    r0, c0 = rs.mean(), cs.mean()
    radius = float(np.sqrt(mask.sum() / np.pi))
    reach = int(2 * radius) + 60
    deepest = _deepest(depth, mask, focal)
    out = {k: np.full(O.SECTORS, np.nan) for k in ("rim", "past", "shadow", "cos")}
    for s in range(O.SECTORS):
        a = (s + 0.5) * 2 * np.pi / O.SECTORS - np.pi
        out["cos"][s] = abs(np.cos(a))
        rr, cc, e = _ray(mask, r0, c0, a, reach)
        z = depth[rr, cc]
        level = np.flatnonzero((z[: e + 1] > 0) & (z[: e + 1] <= deepest))
        if not len(level):
            continue
        last = int(level[-1])
        if last == e and e + 1 < len(z) and _continuous(z[e], z[e + 1], focal):
            continue  # runs on across the outline
        out["rim"][s] = e - last
        far = np.flatnonzero(z > deepest)
        far = far[far > last]
        if not len(far) or far[0] > e + 0.5 * radius or (z[last + 1 : far[0]] > 0).any():
            continue  # nothing seen past within reach, or something at the fruit's level before it
        first = int(far[0])
        out["past"][s] = e - first + 0.5
        out["shadow"][s] = baseline * focal * (1.0 / z[last] - 1.0 / float(z[first]))
    return out


def pairs(paths: list[Path], baseline: float) -> str:
    lines = ["| frame | sphere | mask radius (px) | rim, all / pairs (px) | past, all / pairs (px) | pairs read "
             "| shadow (px) | past + shadow / 2, pairs (px) |", "|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for path in paths:
        frame = read_frame(path)
        depth = np.asarray(frame.depth, dtype=np.float64)
        focal = float(np.sqrt(frame.camera.fx * frame.camera.fy))
        labels = np.asarray(frame.masks)
        for k in range(1, int(labels.max()) + 1):
            m = labels == k
            r = sector_reads(depth, m, focal, baseline)
            rim_p = 0.5 * (r["rim"][:HALF] + r["rim"][HALF:])
            past_p = 0.5 * (r["past"][:HALF] + r["past"][HALF:])
            corr = past_p + 0.25 * (r["shadow"][:HALF] + r["shadow"][HALF:]) * r["cos"][:HALF]
            n = int(np.isfinite(past_p).sum())

            def med(v: np.ndarray) -> str:
                return f"{np.nanmedian(v):+.1f}" if np.isfinite(v).any() else "-"

            lines.append(f"| {path.parent.name}/{path.name} | {k} | {np.sqrt(m.sum() / np.pi):.1f} "
                         f"| {med(r['rim'])} / {med(rim_p)} | {med(r['past'])} / {med(past_p)} | {n} "
                         f"| {med(r['shadow'])} | {med(corr)} |")  # fmt: skip
    return "\n".join(lines) + "\n"


class _Variant:
    """Stop 56's partial rule with the first pixel seen past read beyond the mask's outline (and, with ``baseline``,
    half the colour camera's shadow added to each pair)."""

    def __init__(self, baseline: float) -> None:
        self.baseline = baseline
        self.ctx: dict[str, Any] = {}
        self.log: list[tuple[int, int, float]] = []
        self._seen_past = O._seen_past

    def seen_past(self, own: np.ndarray, seen: np.ndarray, d: np.ndarray, band: np.ndarray, points: np.ndarray,
                  focal: float, eroded: int, tolerance: float, sectors: int = O.SECTORS, *,
                  ahead: np.ndarray | None = None) -> np.ndarray | None:  # fmt: skip
        self.ctx = {"own": own, "seen": seen, "d": d, "points": points, "focal": focal, "tolerance": tolerance}
        return self._seen_past(own, seen, d, band, points, focal, eroded, tolerance, sectors, ahead=ahead)

    def part(self, own: np.ndarray, band: np.ndarray, past: np.ndarray, ahead: np.ndarray | None,
             is_joined: np.ndarray, sec: np.ndarray, rad: np.ndarray, vv: np.ndarray, uu: np.ndarray,
             last: np.ndarray, first: np.ndarray, both: np.ndarray, eroded: int) -> np.ndarray | None:  # fmt: skip
        c = self.ctx
        d, focal, points, seen = c["d"], c["focal"], c["points"], c["seen"]
        sectors = len(last)
        half = sectors // 2
        front = float(points[:, 2].min())
        width = np.sqrt(4.0 * np.count_nonzero(own) / np.pi)
        deep = front + 0.5 * width * front / focal + c["tolerance"]
        rs, cs = np.nonzero(seen)
        r0, c0 = rs.mean(), cs.mean()
        reach = np.zeros(sectors)
        np.maximum.at(reach, sec, rad + 0.5)
        ov, ou = np.nonzero(~own & np.isfinite(d) & (d > 0))  # outside the mask, with depth
        osec = np.minimum(((np.arctan2(ov - r0, ou - c0) + np.pi) / (2 * np.pi) * sectors).astype(np.intp),
                          sectors - 1)  # fmt: skip
        orad = np.hypot(ov - r0, ou - c0)
        far = d[ov, ou] > deep
        first_out, level_out = np.full(sectors, np.inf), np.full(sectors, np.inf)
        np.minimum.at(first_out, osec[far], orad[far])
        np.minimum.at(level_out, osec[~far], orad[~far])
        level = band & ~past
        if ahead is not None:
            level &= ~ahead
        at_level = np.zeros(sectors, bool)
        at_level[sec[level[vv, uu]]] = True
        # seen past beyond the outline (within half the mask's radius), nothing at the fruit's level before it
        beyond = (~both & ~at_level & np.isfinite(last) & (first_out < level_out)
                  & (first_out - reach < 0.25 * width))  # fmt: skip
        read = both | beyond
        start = np.where(beyond, first_out, first)
        at = np.flatnonzero(read | at_level)
        if len(at) < 2 or np.diff(np.r_[at, at[0] + sectors]).max() > sectors // 3:
            return None
        pair = read[:half] & read[half:]
        if np.count_nonzero(pair) < O.PAIRS:
            return None
        over = reach - start + 0.5
        mean = 0.5 * (over[:half] + over[half:])
        if self.baseline > 0:
            # the colour camera's shadow beside the fruit: half of it on a pair's mean, along x
            zb = np.full(sectors, np.nan)
            for s in np.flatnonzero(read):
                inside = (sec == s) & past[vv, uu] if both[s] else None
                if inside is not None and inside.any():
                    j = np.argmin(np.where(inside, rad, np.inf))
                    zb[s] = d[vv[j], uu[j]]
                else:
                    sel = (osec == s) & far
                    j = np.argmin(np.where(sel, orad, np.inf))
                    zb[s] = d[ov[j], ou[j]]
            zf = front + 0.5 * width * front / focal
            shadow = self.baseline * focal * (1.0 / zf - 1.0 / zb)
            angle = (np.arange(half) + 0.5) * (2 * np.pi / sectors) - np.pi
            mean = mean + 0.25 * (shadow[:half] + shadow[half:]) * np.abs(np.cos(angle))
        by = float(np.median(mean[pair]))
        self.log.append((int(both.sum()), int(beyond.sum()), round(by, 2)))
        if not by >= O.LEAST_OVERSHOOT_PX:
            return None
        cut = np.where(both, np.minimum(by, over), by)
        drop = np.zeros(own.shape, bool)
        out = ~is_joined & (rad > (reach - cut)[sec])
        drop[vv[out], uu[out]] = True
        if eroded > 0:
            drop &= ~O.square_filter(own & ~drop, eroded)
        return drop if drop.any() else None


def variant(out: Path, frames: Path, names: list[str], baseline: float) -> None:
    v = _Variant(baseline)
    O._seen_past, O._seen_past_in_part = v.seen_past, v.part
    out.mkdir(parents=True, exist_ok=True)
    for name in dict.fromkeys(["none", *names]):
        failed: dict[str, str] = {}
        v.log.clear()
        rows = evaluate_spheres(frames / "frames" / name, methods=("evidence",), failed=failed, settings=from_dict({}))
        (out / f"{name}.json").write_text(json.dumps({"failed": failed, "rows": [r.__dict__ for r in rows]}))
        sys.stderr.write(f"{name}: {len(rows)} boxes; partial rule (sectors seen past inside, beyond, overshoot px) "
                         f"{v.log}\n")  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    p = sub.add_parser("pairs", help="the lost rim and the first pixel seen past against each sphere's outline")
    p.add_argument("frames", type=Path, nargs="+")
    p.add_argument("--baseline", type=float, default=0.032, help="colour camera along x from the depth camera, m")
    v = sub.add_parser("variant", help="detect's boxes with the partial rule reading past the outline")
    v.add_argument("out", type=Path)
    v.add_argument("--frames", type=Path, required=True, help="a realpert55 output folder holding frames/NAME/")
    v.add_argument("--only", default="", help="comma-separated perturbations (default: all)")
    v.add_argument("--baseline", type=float, default=0.0, help="add half the colour camera's shadow (m; 0: none)")
    a = ap.parse_args(argv)
    if a.cmd == "pairs":
        sys.stdout.write(pairs(a.frames, a.baseline))
    else:
        variant(a.out, a.frames, [n for n in a.only.split(",") if n] or list(RP.PERTURBATIONS), a.baseline)


if __name__ == "__main__":
    main()
