"""Stop 46's diagnosis of `evidence`'s centre error in the paper protocol (docs/paper46.md).

    python docs/paper46.py collect OUT.pkl EVALUATE-ARGS...      (docs/evid40.py's collect)
    python docs/paper46.py where OUT.pkl [...]                     (where the centre error comes from)
    python docs/paper46.py views OUT.pkl [--kind K] [--over 3]     (one line a view)
    python docs/paper46.py candidates OUT.pkl [...]                (each candidate's faces against the truth)
    python docs/paper46.py variants LABEL=OUT.pkl[:KIND] [...] --variant NAME[+key:value,...] [...]

``collect`` is docs/evid40.py's (``symfruit evaluate EVALUATE-ARGS --methods evidence --no-profile --jobs 1``,
every view's candidates and the inputs of ``combine`` and ``fuse_depth`` kept; a pickle: read only your own).
``where`` splits each kind's mean squared centre error into its lateral part (x, y) and its part along the line
of sight (z), and the latter into the front face's and the back face's errors (the box centre's z error is half
their sum); it prints, per kind, the mean centre error of the result, of the weighted median before the prior
(``combine``), of the best candidate of each view (what no weighting beats), of the result with the true back
face, and with the true front face, and which candidate holds the most weight. ``views`` prints one line a view
(pose, error, its xyz parts, front and back face errors, the winner and every candidate's weight and back face
against the truth). ``candidates`` prints, per kind, each candidate's mean signed and absolute front, back and
lateral face errors and its mean weight. ``variants`` replays ``combine`` and ``fuse_depth`` on each set (``KIND``: one
kind, as ``where`` names it) under a rule (:data:`RULES`, :data:`TRIMS`, ``closed25`` or ``default``) and `evidence`'s
settings changed by ``+key:value,...``; cells mean IoU / mean centre error (mm) / views over 10 mm (``default``
reproduces ``evaluate``'s figures). Run with ``PYTHONPATH=TREE/src`` from the repository's root.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import evid40

import symfruit.methods.evidence as ev
from symfruit.core.box import Box
from symfruit.evaluate.metrics import centre_deviation

View = dict[str, Any]
say = evid40.say


def _kind(v: View) -> str:
    return str(v["kind"]).split("/")[-1]


def _replay(v: View, s: ev.EvidenceSettings) -> tuple[Any, Box]:
    comb = ev.combine(v["cands"], s=s, **v["combine"])
    box, _, _ = ev.fuse_depth(comb, v["cands"], None, None, s=s, **v["fuse"])  # type: ignore[arg-type]
    return comb, box


def _parts(box: Box, truth: Box) -> np.ndarray:
    """(dx, dy, dz, front, back) mm: the centre's error and the front and back faces' (box minus truth)."""
    d = 1000.0 * (box.centre - truth.centre)
    return np.array([d[0], d[1], d[2], 1000.0 * (box.min[2] - truth.min[2]), 1000.0 * (box.max[2] - truth.max[2])])


def _with_z(box: Box, truth: Box, face: int) -> float:
    """Centre error (mm) of ``box`` with its front (``face`` 0) or back (1) face moved to the truth's."""
    lo, hi = box.min.copy(), box.max.copy()
    if face == 0:
        lo[2] = min(float(truth.min[2]), hi[2] - 1e-4)
    else:
        hi[2] = max(float(truth.max[2]), lo[2] + 1e-4)
    return 1000.0 * centre_deviation(Box(lo, hi), truth)


def where(paths: list[str]) -> None:
    s = ev.EvidenceSettings()
    say(
        "| set | kind | n | centre | combine | best cand. | true back | true front | lateral / z share of "
        "squared error | z: front / back (mean signed mm) | z: front / back share of z^2 | winner (most weight) |"
    )
    say("|---" * 12 + "|")
    for path in paths:
        views = evid40._load(path)
        kinds = sorted({_kind(v) for v in views})
        for kind in [*kinds, "all"]:
            group = [v for v in views if kind == "all" or _kind(v) == kind]
            rows, comb_err, best, tb, tf, winners = [], [], [], [], [], {}
            for v in group:
                truth = Box(*v["truth"])
                comb, box = _replay(v, s)
                rows.append(_parts(box, truth))
                comb_err.append(1000.0 * centre_deviation(comb.box, truth))
                best.append(evid40._best(v)[0])
                tb.append(_with_z(box, truth, 1))
                tf.append(_with_z(box, truth, 0))
                top = max(comb.weights, key=comb.weights.__getitem__)
                winners[top] = winners.get(top, 0) + 1
            r = np.array(rows)
            err = np.linalg.norm(r[:, :3], axis=1)
            lat, z2 = (r[:, :2] ** 2).sum(), (r[:, 2] ** 2).sum()
            # z = (front + back) / 2: z^2 = front^2/4 + back^2/4 + front*back/2; the cross term split evenly
            f2 = (r[:, 3] ** 2 / 4 + r[:, 3] * r[:, 4] / 4).sum()
            b2 = (r[:, 4] ** 2 / 4 + r[:, 3] * r[:, 4] / 4).sum()
            win = ", ".join(f"{k} {n}" for k, n in sorted(winners.items(), key=lambda kv: -kv[1]))
            say(f"| {Path(path).stem} | {kind} | {len(group)} | {err.mean():.2f} | {np.mean(comb_err):.2f} | "
                f"{np.mean(best):.2f} | {np.mean(tb):.2f} | {np.mean(tf):.2f} | "
                f"{lat / (lat + z2):.2f} / {z2 / (lat + z2):.2f} | {r[:, 3].mean():+.2f} / {r[:, 4].mean():+.2f} | "
                f"{f2 / max(z2, 1e-12):.2f} / {b2 / max(z2, 1e-12):.2f} | {win} |")  # fmt: skip


def views(path: str, kind: str | None, over: float) -> None:
    s = ev.EvidenceSettings()
    for v in evid40._load(path):
        if kind is not None and _kind(v) != kind:
            continue
        truth = Box(*v["truth"])
        comb, box = _replay(v, s)
        p = _parts(box, truth)
        err = float(np.linalg.norm(p[:3]))
        if err < over:
            continue
        cands = " ".join(f"{c.name[:4]} {comb.weights[c.name]:.2f} {1000 * (c.hi[2] - truth.max[2]):+.1f}"
                         for c in v["cands"])  # fmt: skip
        say(f"{v['fruit_id']:14s} pose {v['pose']:2d} err {err:5.2f} xyz {p[0]:+5.1f} {p[1]:+5.1f} {p[2]:+5.1f} "
            f"front {p[3]:+5.1f} back {p[4]:+5.1f} (shapes {1000 * (comb.box.max[2] - truth.max[2]):+5.1f}) "
            f"contour {comb.contour:.2f} | {cands}")  # fmt: skip


def candidates(paths: list[str]) -> None:
    s = ev.EvidenceSettings()
    say(
        "| set | kind | candidate | n | weight | front (signed / abs mm) | back (signed / abs) | lateral abs | centre |"
    )
    say("|---" * 9 + "|")
    for path in paths:
        views_ = evid40._load(path)
        for kind in sorted({_kind(v) for v in views_}):
            stats: dict[str, list[list[float]]] = {}
            for v in views_:
                if _kind(v) != kind:
                    continue
                truth = Box(*v["truth"])
                comb = ev.combine(v["cands"], s=s, **v["combine"])
                for c in v["cands"]:
                    b = Box(c.lo, c.hi)
                    p = _parts(b, truth)
                    lat = 1000.0 * np.abs(np.concatenate([c.lo[:2] - truth.min[:2], c.hi[:2] - truth.max[:2]]))
                    stats.setdefault(c.name, []).append(
                        [comb.weights[c.name], p[3], p[4], float(lat.mean()), float(np.linalg.norm(p[:3]))]
                    )
            for name, rows in stats.items():
                a = np.array(rows)
                say(f"| {Path(path).stem} | {kind} | {name} | {len(a)} | {a[:, 0].mean():.2f} | "
                    f"{a[:, 1].mean():+.2f} / {np.abs(a[:, 1]).mean():.2f} | {a[:, 2].mean():+.2f} / "
                    f"{np.abs(a[:, 2]).mean():.2f} | {a[:, 3].mean():.2f} | {a[:, 4].mean():.2f} |")  # fmt: skip


def _rim_contour(v: View, s: ev.EvidenceSettings) -> tuple[View, ev.EvidenceSettings]:
    """The rim coverage times the contour share: a cut edge holds points, but not the fruit's own rim."""
    return {**v, "fuse": {**v["fuse"], "rim": v["fuse"]["rim"] * v["combine"]["contour"]}}, s


def _sparse(rule: Any) -> Any:
    """``rule`` on a sparse cloud's views only (no ``cone`` candidate: evidence fits it only on a dense one)."""

    def sparse(v: View, s: ev.EvidenceSettings) -> tuple[View, ev.EvidenceSettings]:
        return rule(v, s) if not any(c.name == "cone" for c in v["cands"]) else (v, s)

    return sparse


def _rim_cut2(v: View, s: ev.EvidenceSettings) -> tuple[View, ev.EvidenceSettings]:
    """The rim coverage times ``1 - cut^2`` (``cut = 1 - contour``): the rim a cut leaves seen, by the sagitta."""
    cut = 1.0 - v["combine"]["contour"]
    return {**v, "fuse": {**v["fuse"], "rim": v["fuse"]["rim"] * (1.0 - cut * cut)}}, s


def _rim_quarter(v: View, s: ev.EvidenceSettings) -> tuple[View, ev.EvidenceSettings]:
    """The rim coverage times ``min(1, contour / 0.25)``: the prior's floor of the contour share (``fuse_depth``'s
    ``max(contour, 0.25)``) read for the shapes too: below it, little of the fruit's own rim was seen."""
    return {**v, "fuse": {**v["fuse"], "rim": v["fuse"]["rim"] * min(1.0, v["combine"]["contour"] / 0.25)}}, s


def _rim_pow(k: float) -> Any:
    def rule(v: View, s: ev.EvidenceSettings) -> tuple[View, ev.EvidenceSettings]:
        cut = 1.0 - v["combine"]["contour"]
        return {**v, "fuse": {**v["fuse"], "rim": v["fuse"]["rim"] * (1.0 - cut**k)}}, s

    return rule


def _elongated_sd(v: View, s: ev.EvidenceSettings) -> tuple[View, ev.EvidenceSettings]:
    """The prior's relative deviation with half the outline's width gap (``major - minor`` over the prior's width)
    added in quadrature: an elongated outline's depth is anywhere between its two widths."""
    a = v["fuse"]["across"]
    small, big = sorted((float(a.minor), float(a.major)))
    w = ev.prior_width(a, v["combine"]["contour"], s.cut_width)
    sd = float(np.hypot(s.depth_ratio_sd, 0.5 * (big - small) / max(w, 1e-12)))
    return v, __import__("dataclasses").replace(s, depth_ratio_sd=sd)


def _both(*rules: Any) -> Any:
    def rule(v: View, s: ev.EvidenceSettings) -> tuple[View, ev.EvidenceSettings]:
        for r in rules:
            v, s = r(v, s)
        return v, s

    return rule


#: Per-view replays: ``(view, settings) -> (view, settings)``.
RULES: dict[str, Any] = {
    "rimc": _rim_contour,
    "rimc_sparse": _sparse(_rim_contour),
    "rimcut2": _rim_cut2,
    "rimq": _rim_quarter,
    **{f"rimcut{k}": _rim_pow(float(k)) for k in (4, 8)},
    "elsd": _elongated_sd,
    "rimq_elsd": _both(_rim_quarter, _elongated_sd),
}


def _trimmed(values: np.ndarray, weights: np.ndarray, lo: float, hi: float) -> float:
    """Weighted mean of ``values`` over the weighted quantiles ``lo``-``hi`` (each value's share of the weight
    that falls inside, so the median's alone as ``lo``, ``hi`` -> 0.5)."""
    order = np.argsort(values, kind="stable")
    v, w = values[order], weights[order] / weights.sum()
    upper = np.cumsum(w)
    lower = upper - w
    part = np.clip(np.minimum(upper, hi) - np.maximum(lower, lo), 0.0, None)
    return float((part * v).sum() / part.sum()) if part.sum() > 0 else float(np.median(v))


#: Replays of ``combine``'s back face: ``NAME -> (lo, hi)`` weighted quantiles averaged.
TRIMS = {"trim25": (0.25, 0.75), "trim35": (0.35, 0.65), "trim15": (0.15, 0.85), "trim25all": (0.25, 0.75, 1)}


def _trim_patch(lo: float, hi: float, every: int = 0) -> Any:
    wm = ev._weighted_median

    def patched(values: np.ndarray, weights: np.ndarray, *, listed: Any = None) -> np.ndarray:
        out = wm(values, weights, listed=listed)
        for j in range(6) if every else (5,):
            out[j] = _trimmed(values[:, j], weights, lo, hi)
        return out

    return patched


_COMBINE = ev.combine


def _closed_combine(cands: Any, **kw: Any) -> Any:
    """``combine`` with the back face the midmean (0.25) of the closed candidates' alone (the raw box left out)."""
    import dataclasses

    c = _COMBINE(cands, **kw)
    w = np.array([c.weights[x.name] for x in cands])
    backs = np.array([x.hi[2] for x in cands])
    closed = np.array([x.agreement is not None for x in cands])
    if closed.sum() >= 2:
        hi = c.box.max.copy()
        hi[2] = max(ev.midmean(backs[closed], w[closed], 0.25), float(c.box.min[2]) + 1e-4)
        c = dataclasses.replace(c, box=Box(c.box.min, hi))
    return c


def variants(sets: list[str], names: list[str]) -> None:
    """docs/evid40.py's variants with this script's :data:`RULES` (``NAME+key:value,...`` adds settings)."""
    loaded = []
    for spec in sets:
        label, _, rest = spec.partition("=")
        path, _, kind = rest.partition(":")
        vs = evid40._load(path)
        loaded.append((label, [v for v in vs if not kind or _kind(v) == kind]))
    say("| variant | " + " | ".join(f"{label} ({len(vs)})" for label, vs in loaded) + " |")
    say("|---" * (len(loaded) + 1) + "|")
    for name in names:
        key, _, kv = name.partition("+")
        over = {k: (float(x) if x.replace(".", "").isdigit() else x) for k, x in
                (item.split(":") for item in kv.split(","))} if kv else {}  # fmt: skip
        base = ev.EvidenceSettings().model_copy(update=over) if hasattr(ev.EvidenceSettings, "model_copy") else \
            __import__("dataclasses").replace(ev.EvidenceSettings(), **over)  # fmt: skip
        cells = []
        if key == "closed25":
            ev.combine = _closed_combine  # type: ignore[assignment]
        if key in TRIMS:
            ev._weighted_median = _trim_patch(*TRIMS[key])  # type: ignore[assignment]
        for _, vs in loaded:
            r = []
            for v in vs:
                v2, s2 = RULES[key](v, base) if key in RULES else (v, base)
                truth = Box(*v2["truth"])
                _, box = _replay(v2, s2)
                from symfruit.evaluate.metrics import box_iou

                r.append((box_iou(box, truth), 1000.0 * centre_deviation(box, truth)))
            a = np.array(r)
            cells.append(f"{a[:, 0].mean():.3f} / {a[:, 1].mean():.2f} / {(a[:, 1] > 10).sum()}")
        say(f"| {name} | " + " | ".join(cells) + " |")
        ev._weighted_median = _WM  # type: ignore[assignment]
        ev.combine = _COMBINE  # type: ignore[assignment]


_WM = ev._weighted_median


def main(argv: list[str]) -> int:
    if argv[:1] == ["collect"]:
        return evid40.collect(argv[1], argv[2:])
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    w = sub.add_parser("where")
    w.add_argument("paths", nargs="+")
    vw = sub.add_parser("views")
    vw.add_argument("path")
    vw.add_argument("--kind")
    vw.add_argument("--over", type=float, default=0.0)
    c = sub.add_parser("candidates")
    c.add_argument("paths", nargs="+")
    va = sub.add_parser("variants")
    va.add_argument("sets", nargs="+", help="LABEL=OUT.pkl[:KIND]")
    va.add_argument("--variant", action="append", default=[])
    a = p.parse_args(argv)
    if a.cmd == "where":
        where(a.paths)
    elif a.cmd == "variants":
        variants(a.sets, a.variant or ["default"])
    elif a.cmd == "views":
        views(a.path, a.kind, a.over)
    else:
        candidates(a.paths)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
