"""Stop 48's measurements for issue 18's pears in the paper protocol (docs/paper48.md): whether the seen edge of
stop 47's section cue (``core.candidates.section_ratio``) lies at the sections' widest. Nothing here changes the
library.

    python docs/paper48.py twins
    python docs/paper48.py boxy
    python docs/paper48.py dense KIND INDEX SEED
    python docs/paper48.py truth KIND INDEX SEED [POSE]
    python docs/paper48.py caps
    python docs/paper48.py run STATS.csv BOXES.csv evaluate ARGS... [--config S05.yaml]

The edge statistic: with stop 47's fit in each slice, ``z = z_c - B sqrt(1 - u^2)`` over ``|u| < 0.85``, the
points beyond (``0.85 <= |u| <= 1``, which the fit leaves out) lie ``model - z`` in front of it; their mean over
``B``, averaged over the slices by points. A section cut at its widest follows the model to the edge (about 0);
one cut in front of its widest ends in front of the model, its edge not parallel to the line of sight (positive).

``twins`` prints the cue and the edge statistic on the paper-visible part of round sections cut 0-0.3 of the
radius in front of their widest, each next to the ellipse cut at its widest whose seen sag over half-width is
the same (600-point surfaces, 12 each). ``boxy`` prints them on round sections that are superellipses
(``|x|^p + |z|^p = r^p``, as deep as wide) cut at their widest. ``dense`` prints them on a paper protocol view
(poses 4, 9, 14) sampled 600, 2400 and 9600 points with the protocol's own cut plane. ``truth`` slices a 60
000-point sample of the whole fruit in one pose (default 9, 0 deg) at seven heights: the section's width and
depth, the seen half-width over the section's, the seen front's sag over the seen half-width, how far the cut
lies in front of the depth of the points within 1.5 mm of the section's lateral extremes (mm; biased: about 4 mm
on a section cut exactly at its widest), and the back's distance from there over the front's. ``run`` is
docs/eval_boxes.py's ``run`` with the solid of revolution's sections left circular where the edge statistic
exceeds ``P48_GATE`` or falls below ``P48_FLOOR`` (defaults: never), and ``SECTION_CLIP`` replaced by
``P48_CLIP`` (``lo:hi``); every view's cue and edge statistic is written to STATS.csv. Run with
``PYTHONPATH=TREE/src`` from the repository's root. ``caps`` prints, per paper view of the strawberries and
bananas (seeds 0 and 1) and the scans' banana, the exponent ``p`` of the seen points' height over the cut plane,
``h = H (1 - u^2)^p`` across the outline (about 0.5 for a half cut through the axis, 1 for a thin cap).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def _say(line: str) -> None:
    sys.stdout.write(line + "\n")


def cue(points: np.ndarray, direction: np.ndarray, *, bins: int = 8, span: float = 0.6, inner: float = 0.85,
        min_sag: float = 0.6) -> tuple[float, float]:  # fmt: skip
    """``(ratio, edge)``: :func:`symfruit.core.candidates.section_ratio`'s ratio (its code, to the bit) and the
    edge statistic (nan where the cue returns 1 for want of slices)."""
    q = np.asarray(points, dtype=np.float64)
    d = np.asarray(direction, dtype=np.float64)
    n = float(np.hypot(d[0], d[1]))
    if n < 0.5 or len(q) < 3 * bins:
        return 1.0, math.nan
    e = d[:2] / n
    q = q - q.mean(axis=0)
    s, t, z = q[:, :2] @ e, q[:, :2] @ np.array([-e[1], e[0]]), q[:, 2]
    lo, hi = np.quantile(s, [0.5 - 0.5 * span, 0.5 + 0.5 * span])
    idx = np.floor((s - lo) / (hi - lo) * bins).astype(np.int64)
    keep = (idx >= 0) & (idx < bins)
    idx, s, t, z = idx[keep], s[keep], t[keep], z[keep]
    count = np.bincount(idx, minlength=bins)
    order = np.lexsort((t, idx))
    first = order[np.minimum(np.searchsorted(idx[order], np.arange(bins)), len(t) - 1)]
    last = order[np.maximum(np.searchsorted(idx[order], np.arange(bins), side="right") - 1, 0)]
    good = (count >= 8) & (t[last] > t[first])
    a, mid, at = 0.5 * (t[last] - t[first]), 0.5 * (t[last] + t[first]), 0.5 * (s[first] + s[last])
    if good.sum() < 3:
        return 1.0, math.nan
    w = np.sqrt(good.astype(np.float64))
    design = np.stack([np.ones(bins), at, at * at], axis=1) * w[:, None]
    ca = np.linalg.lstsq(design, np.where(good, a, 0.0) * w, rcond=None)[0]
    cm = np.linalg.lstsq(design, np.where(good, mid, 0.0) * w, rcond=None)[0]
    u = (t - (cm[0] + cm[1] * s + cm[2] * s * s)) / np.maximum(ca[0] + ca[1] * s + ca[2] * s * s, 1e-9)
    root = np.sqrt(np.clip(1.0 - u * u, 0.0, 1.0))
    m = (np.abs(u) < inner).astype(np.float64)
    s1, sw, sww = np.bincount(idx, m, bins), np.bincount(idx, root * m, bins), np.bincount(idx, root * root * m, bins)
    sz, swz = np.bincount(idx, z * m, bins), np.bincount(idx, root * z * m, bins)
    det = s1 * sww - sw * sw
    good &= det > 1e-12 * np.maximum(s1, 1.0) ** 2
    det = np.where(good, det, 1.0)
    zc, depth = (sww * sz - sw * swz) / det, (sw * sz - s1 * swz) / det
    centre = np.bincount(idx, s, bins) / np.maximum(count, 1)
    half = ca[0] + ca[1] * centre + ca[2] * centre * centre
    z_lo, z_hi = np.full(bins, np.inf), np.full(bins, -np.inf)
    np.minimum.at(z_lo, idx, z)
    np.maximum.at(z_hi, idx, z)
    good &= (half > 0.3 * float(np.where(good, a, 0.0).max())) & (z_hi - z_lo > min_sag * half)
    if good.sum() < 3:
        return 1.0, math.nan
    weight = count * good
    w = np.sqrt(weight.astype(np.float64))
    slope = float(np.linalg.lstsq(np.stack([np.ones(bins), centre], axis=1) * w[:, None], zc * w, rcond=None)[0][1])
    ratio = depth / np.where(good, half, 1.0) / math.sqrt(1.0 + slope * slope)
    ranked = np.argsort(np.where(good, ratio, np.inf))
    total = np.cumsum((weight * np.where(good, half, 0.0))[ranked])
    k = float(ratio[ranked][np.searchsorted(total, 0.5 * total[-1])])
    outer = ((np.abs(u) >= inner) & (np.abs(u) <= 1.0) & good[idx]).astype(np.float64)
    ahead = (zc[idx] - depth[idx] * root - z) / np.maximum(depth[idx], 1e-9)
    n_out = np.bincount(idx, outer, bins)
    per_slice = np.bincount(idx, ahead * outer, bins) / np.maximum(n_out, 1.0)
    use = weight * (n_out > 0)
    return k, float((per_slice * use).sum() / use.sum()) if use.sum() > 0 else math.nan


def _surface(ratio: float, n: int, seed: int) -> np.ndarray:
    """``n`` points about uniform over an ellipsoid 33 mm across, 45 along y, ``33 ratio`` deep, 0.3 m away."""
    rng = np.random.default_rng(seed)
    u = rng.normal(size=(40 * n, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    radii = np.array([0.033, 0.045, 0.033 * ratio])
    g = 1.0 / np.linalg.norm(u / radii, axis=1)
    return (u * radii)[rng.random(len(u)) < g / g.max()][:n] + [0.0, 0.0, 0.3]


def twins() -> None:
    from symfruit.core.fits import fit_revolution_slices

    _say("| section | cut in front of the widest (of the depth radius) | seen points | seen sag over half-width | "
         "cue, mean +- sd | edge statistic, mean +- sd |")  # fmt: skip
    _say("|---|---|---|---|---|---|")
    for h in (0.0, 0.1, 0.2, 0.3):
        flat = (1.0 - h) / math.sqrt(1.0 - h * h)  # the ellipse whose seen arc is as deep over as wide
        for label, ratio, cut in (("round", 1.0, h), (f"ellipse {flat:.3f}", flat, 0.0)):
            if h == 0.0 and label != "round":
                continue
            found = []
            for seed in range(12):
                p = _surface(ratio, 600, seed)
                seen = p[p[:, 2] < 0.3 - cut * 0.033 * ratio]
                found.append((*cue(seen, fit_revolution_slices(seen).direction), len(seen)))
            a = np.array(found)
            _say(f"| {label} | {cut:.1f} | {a[:, 2].mean():.0f} | {flat if cut else ratio:.3f} | "
                 f"{a[:, 0].mean():.3f} +- {a[:, 0].std():.3f} | {np.nanmean(a[:, 1]):.3f} +- "
                 f"{np.nanstd(a[:, 1]):.3f} |")  # fmt: skip


def boxy() -> None:
    from symfruit.core.fits import fit_revolution_slices

    _say("| section exponent p (2: a circle) | cue, mean +- sd | edge statistic, mean +- sd |")
    _say("|---|---|---|")
    for p in (2.0, 2.15, 2.3, 2.6, 3.0):
        found = []
        for seed in range(12):
            rng = np.random.default_rng(seed)
            y, angle = rng.uniform(-1.0, 1.0, 4000), rng.uniform(0.0, 2.0 * np.pi, 4000)
            keep = rng.random(4000) < np.sqrt(1.0 - y * y)  # about even over the surface along y
            y, angle = y[keep], angle[keep]
            r = 0.033 * np.sqrt(1.0 - y * y)  # 33 mm across at the middle, 45 mm half-length
            c, s = np.cos(angle), np.sin(angle)
            pts = np.c_[r * np.sign(c) * np.abs(c) ** (2.0 / p), 0.045 * y, r * np.sign(s) * np.abs(s) ** (2.0 / p)]
            pts = pts[rng.permutation(len(pts))[:600]] + [0.0, 0.0, 0.3]
            seen = pts[pts[:, 2] < 0.3]  # cut at the widest: the plane through the axis
            found.append(cue(seen, fit_revolution_slices(seen).direction))
        a = np.array(found)
        _say(f"| {p} | {a[:, 0].mean():.3f} +- {a[:, 0].std():.3f} | {np.nanmean(a[:, 1]):+.3f} +- "
             f"{np.nanstd(a[:, 1]):.3f} |")  # fmt: skip


def dense(kind: str, index: int, seed: int) -> None:
    from symfruit.core.box import Box
    from symfruit.core.fits import fit_revolution_slices
    from symfruit.evaluate.protocols import _KIND_IDS, PAPER_ANGLES, Spec, _fruit
    from symfruit.synthetic.shapes import rotation_x

    _say("| pose (deg) | 600 points: cue / edge | 2400 | 9600 |")
    _say("|---|---|---|---|")
    for pose in (4, 9, 14):
        fruit = _fruit(Spec("paper", kind, index, pose, 0.0, seed))
        pts = fruit.sample(600, np.random.default_rng([seed, 1000 + _KIND_IDS.get(kind, 99), index]))
        turn = rotation_x(float(PAPER_ANGLES[pose]))
        posed = pts @ turn.T
        shift = -Box.from_points(posed).centre + [0.0, 0.0, 0.3]
        posed = posed + shift
        lo, hi = posed[np.argmin(posed[:, 1])], posed[np.argmax(posed[:, 1])]  # the protocol's cut plane
        normal = np.cross(hi - lo, [1.0, 0.0, 0.0])
        normal = -normal if normal[2] > 0 else normal
        cells = []
        for n in (600, 2400, 9600):
            d = fruit.sample(n, np.random.default_rng(7)) @ turn.T + shift
            seen = d[(d - lo) @ normal > 0]
            k, e = cue(seen, fit_revolution_slices(seen[:: max(1, len(seen) // 600)]).direction)
            cells.append(f"{k:.3f} / {e:+.3f}")
        _say(f"| {PAPER_ANGLES[pose]} | " + " | ".join(cells) + " |")


def truth(kind: str, index: int, seed: int, pose: int) -> None:
    from symfruit.core.box import Box
    from symfruit.evaluate.protocols import _KIND_IDS, PAPER_ANGLES, Spec, _fruit
    from symfruit.synthetic.shapes import rotation_x

    fruit = _fruit(Spec("paper", kind, index, pose, 0.0, seed))
    pts = fruit.sample(600, np.random.default_rng([seed, 1000 + _KIND_IDS.get(kind, 99), index]))
    turn = rotation_x(float(PAPER_ANGLES[pose]))
    posed = pts @ turn.T
    shift = -Box.from_points(posed).centre + [0.0, 0.0, 0.3]
    posed = posed + shift
    full = fruit.sample(60000, np.random.default_rng(5)) @ turn.T + shift
    lo, hi = posed[np.argmin(posed[:, 1])], posed[np.argmax(posed[:, 1])]
    normal = np.cross(hi - lo, [1.0, 0.0, 0.0])
    normal = -normal if normal[2] > 0 else normal
    seen = (full - lo) @ normal > 0
    _say("| y (mm) | width, depth (mm) | depth / width | seen half-width / widest | seen sag / seen half-width | "
         "cut in front of the widest (mm) | back / front from the widest |")  # fmt: skip
    _say("|---|---|---|---|---|---|---|")
    for yc in np.linspace(*np.quantile(full[:, 1], [0.2, 0.8]), 7):
        band = np.abs(full[:, 1] - yc) < 0.002
        b, sb = full[band], full[band & seen]
        if len(sb) < 10:
            continue
        width, depth = float(np.ptp(b[:, 0])), float(np.ptp(b[:, 2]))
        half = 0.5 * float(np.ptp(sb[:, 0]))
        rim = b[(b[:, 0] > b[:, 0].max() - 0.0015) | (b[:, 0] < b[:, 0].min() + 0.0015), 2].mean()
        edge = sb[(sb[:, 0] > sb[:, 0].max() - 0.0015) | (sb[:, 0] < sb[:, 0].min() + 0.0015), 2].mean()
        _say(f"| {yc * 1e3:.1f} | {width * 1e3:.1f}, {depth * 1e3:.1f} | {depth / width:.3f} | "
             f"{half / (0.5 * width):.3f} | {(edge - sb[:, 2].min()) / half:.3f} | {(rim - edge) * 1e3:+.1f} | "
             f"{(b[:, 2].max() - rim) / (rim - b[:, 2].min()):.3f} |")  # fmt: skip


def _cap_power(points: np.ndarray) -> tuple[float, float]:
    """``(p, height)``: the exponent of the seen points' height over the cut plane across the outline, and the
    greatest height (m). The plane ``z = c0 + c1 x + c2 y`` is fitted to the deepest 30 % of the points, 6 rounds."""
    design = np.c_[np.ones(len(points)), points[:, :2]]
    keep = np.ones(len(points), dtype=bool)
    for _ in range(6):
        coef = np.linalg.lstsq(design[keep], points[keep, 2], rcond=None)[0]
        r = points[:, 2] - design @ coef
        keep = r > np.quantile(r, 0.7)
    coef = np.linalg.lstsq(design[keep], points[keep, 2], rcond=None)[0]
    normal = np.array([-coef[1], -coef[2], 1.0]) / math.hypot(1.0, coef[1], coef[2])
    height = (design @ coef - points[:, 2]) * normal[2]
    e1 = np.cross(normal, [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    flat = np.c_[points @ e1, points @ np.cross(normal, e1)]
    flat -= flat.mean(axis=0)
    axes = np.linalg.eigh(np.cov(flat.T))[1]
    s, t = flat @ axes[:, 1], flat @ axes[:, 0]
    lo, hi = np.quantile(s, [0.2, 0.8])
    idx = np.floor((s - lo) / (hi - lo) * 8).astype(np.int64)
    us, hs = [], []
    for b in range(8):
        m = idx == b
        if m.sum() >= 8:
            us.append((t[m] - 0.5 * (t[m].max() + t[m].min())) / (0.5 * np.ptp(t[m])))
            hs.append(height[m] / max(float(height[m].max()), 1e-6))
    u, h = np.concatenate(us), np.concatenate(hs)
    m = (np.abs(u) < 0.9) & (h > 0.02)
    return float(np.polyfit(np.log(1.0 - u[m] ** 2), np.log(h[m]), 1)[0]), float(np.ptp(height))


def caps() -> None:
    from symfruit.evaluate.protocols import build, specs

    found: dict[str, list[float]] = {}
    for kind, seeds, n in (("strawberry", (0, 1), 3), ("banana", (0, 1), 3), ("examples/scans", (0,), 1)):
        for seed in seeds:
            for sp in specs("paper", kind, n=n, seed=seed):
                p, height = _cap_power(build(sp).visible)
                label = "real banana" if kind == "examples/scans" else kind
                if kind == "strawberry":
                    label += ", seen under 12 mm deep" if height < 0.012 else ", deeper"
                found.setdefault(label, []).append(p)
    _say("| views | n | p: median [min, max] |")
    _say("|---|---|---|")
    for label, ps in found.items():
        a = np.array(ps)
        _say(f"| {label} | {len(a)} | {np.median(a):.2f} [{a.min():.2f}, {a.max():.2f}] |")


def run(stats: str, argv: list[str]) -> int:
    import eval_boxes

    import symfruit.core.candidates as cands
    import symfruit.evaluate.runner as runner

    gate = float(os.environ.get("P48_GATE", "inf"))
    floor = float(os.environ.get("P48_FLOOR", "-inf"))
    if os.environ.get("P48_CLIP"):
        lo, hi = (float(x) for x in os.environ["P48_CLIP"].split(":"))
        cands.SECTION_CLIP = (lo, hi)
    open(stats, "w").close()
    current = {"key": ""}
    evaluate_one, sectioned = runner._evaluate, cands._sectioned

    def evaluate(spec: Any, methods: Any, settings: Any) -> Any:
        current["key"] = f"{spec.fruit}|{spec.index}|{spec.pose}"
        return evaluate_one(spec, methods, settings)

    def gated(fit: Any, rev: Any) -> Any:
        pts = fit.sample[:: max(1, len(fit.sample) // fit.revolution_points)]
        k, e = cue(pts, rev.direction)
        out = rev if (e > gate or e < floor) else sectioned(fit, rev)
        with open(stats, "a") as f:
            f.write(f"{current['key']},{k:.4f},{e:.4f},{len(pts)},{int(out is rev)}\n")
        return out

    runner._evaluate = evaluate
    cands._sectioned = gated
    return eval_boxes.run(argv[0], argv[1:])


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="paper48.py", description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)  # fmt: skip
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("twins", help="round sections cut in front of their widest against flat ones cut at it")
    sub.add_parser("boxy", help="round superelliptic sections cut at their widest")
    one = sub.add_parser("dense", help="one paper protocol fruit sampled denser")
    one.add_argument("kind")
    one.add_argument("index", type=int)
    one.add_argument("seed", type=int)
    cut = sub.add_parser("truth", help="one paper protocol fruit's sections against the cut")
    cut.add_argument("kind")
    cut.add_argument("index", type=int)
    cut.add_argument("seed", type=int)
    cut.add_argument("pose", type=int, nargs="?", default=9)
    sub.add_parser("caps", help="the seen height's profile over the cut plane: caps against halves")
    go = sub.add_parser("run", help="docs/eval_boxes.py run with the edge gate (P48_GATE, P48_CLIP)")
    go.add_argument("stats", help="the per-view cue and edge statistic CSV to write")
    go.add_argument("command_line", nargs=argparse.REMAINDER, help="BOXES.csv evaluate ARGS...")
    args = parser.parse_args(argv)
    if args.command == "twins":
        twins()
        return 0
    if args.command == "boxy":
        boxy()
        return 0
    if args.command == "dense":
        dense(args.kind, args.index, args.seed)
        return 0
    if args.command == "caps":
        caps()
        return 0
    if args.command == "truth":
        truth(args.kind, args.index, args.seed, args.pose)
        return 0
    return run(args.stats, args.command_line)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
