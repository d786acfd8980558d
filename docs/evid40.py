"""Stop 40's per-view diagnosis of `evidence`'s completion where extraction got the front right (docs/evid40.md).

    python docs/evid40.py collect OUT.pkl EVALUATE-ARGS...
    python docs/evid40.py endon OUT.pkl --fruit pear,banana,lemon --n 3 [--tilt 90] [--seed 7]
    python docs/evid40.py show OUT.pkl [--over 10] [--front 6] [--occluded]
    python docs/evid40.py classify OUT.pkl [...] [--over 10] [--front 6]
    python docs/evid40.py variants SET [...] [--variant NAME ...]
    python docs/evid40.py edge SENSOR FRUIT OCCLUSION INDEX [--reach 4]

``collect`` is docs/scans39.py's (``symfruit evaluate EVALUATE-ARGS --methods evidence --no-profile --jobs 1``, every
view's candidates and the inputs of ``combine`` and ``fuse_depth`` kept), keeping also each view's spec, hidden share
and distance, and the extracted points' front (their 2nd percentile depth) against the fruit's true front
(``front_err``, mm). ``endon`` makes the paper protocol's views of generated fruit turned ``--tilt`` degrees about the
camera's x axis first (90: the long axis of a hanging generated fruit towards the camera, as the real scans stand
with ``--pose upright``), then the paper's 19 poses, and completes them as ``evaluate`` does. ``show`` lists the views
over ``--over`` mm whose front is within ``--front`` mm ("front right, completion wrong") with every candidate's
weight, energy, centre error and agreement, and the shapes', prior's, fused and seen back faces against the truth.
``classify`` splits those views by what is wrong (the depth or a lateral axis) and prints, per set and occlusion
level, the mean centre error of the result, of the per-view best candidate (what no weighting can beat), and of the
result with the true back face. ``variants`` replays docs/scans39.py's variants (and ``--set``-style ``NAME=key:value``
settings, and ``contourX``: the contour share read as at least ``X``) on sets ``LABEL=OUT.pkl[:KIND]`` (``KIND``
``p7``, a kind, or ``@OCC`` an occlusion level). ``edge`` rebuilds one camera-protocol view and measures what the
occlusion map calls hidden just outside the fruit's mask (:func:`edge`). Run with
``PYTHONPATH=TREE/src`` from the repository's root.
"""

from __future__ import annotations

import argparse
import dataclasses
import pickle
import sys
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import scans39

import symfruit.methods.evidence as ev
from symfruit.core.box import Box
from symfruit.evaluate import protocols as proto
from symfruit.evaluate import runner
from symfruit.evaluate.metrics import centre_deviation

View = dict[str, Any]


def say(*parts: Any) -> None:
    sys.stdout.write(" ".join(str(p) for p in parts) + "\n")


# Stop 40's rules (with docs/scans39.py's): ``dwcK`` the depth term's weight times ``1 + K clean`` (a clean scan's
# depth residuals are not a depth camera's correlated noise: its misfit ratios mean more), ``TcK`` the temperature
# over ``1 + K clean``; the ``outside`` band term of a sparse cloud (whose edge need not be the silhouette) dropped
# (``noout``), halved (``halfout``) or counted beyond the least of the candidates' (``relout``).
for _k in (0.5, 1.0, 2.0):
    scans39.RULES[f"dwc{_k:g}"] = (lambda k: lambda v, s: dataclasses.replace(
        s, depth_weight=s.depth_weight * (1.0 + k * v["combine"]["clean"])))(_k)  # fmt: skip
    scans39.RULES[f"Tc{_k:g}"] = (lambda k: lambda v, s: dataclasses.replace(
        s, temperature=s.temperature / (1.0 + k * v["combine"]["clean"])))(_k)  # fmt: skip
OUTSIDE = {"noout": 0.0, "halfout": 0.5, "relout": -1.0}


def _outside(v: View, mode: str) -> View:
    """``v`` with its closed candidates' outside share changed by ``mode`` (of :data:`OUTSIDE`) if it is sparse."""
    if scans39._dense(v):
        return v
    least = min((c.agreement.outside for c in v["cands"] if c.agreement is not None), default=0.0)
    cands = []
    for c in v["cands"]:
        a = c.agreement
        if a is not None:
            out = a.outside - least if OUTSIDE[mode] < 0 else OUTSIDE[mode] * a.outside
            c = dataclasses.replace(c, agreement=dataclasses.replace(a, outside=out))
        cands.append(c)
    return {**v, "cands": cands}


def _catching() -> tuple[dict[str, Any], Any]:
    """Wrap ``combine`` and ``fuse_depth`` to keep their inputs; returns the dict they fill and an undo."""
    caught: dict[str, Any] = {}
    combine, fuse_depth = ev.combine, ev.fuse_depth

    def keep_combine(cands: Any, **kw: Any) -> Any:
        caught["combine"] = {k: v for k, v in kw.items() if k != "s"}
        return combine(cands, **kw)

    def keep_fusion(combined: Any, cands: Any, region: Any, camera: Any, **kw: Any) -> Any:
        caught.update(cands=cands, fuse={k: v for k, v in kw.items() if k != "s"})
        return fuse_depth(combined, cands, region, camera, **kw)

    ev.combine, ev.fuse_depth = keep_combine, keep_fusion  # type: ignore[assignment]

    def undo() -> None:
        ev.combine, ev.fuse_depth = combine, fuse_depth

    return caught, undo


def _view(caught: dict[str, Any], result: Any, score: Any, truth: Box, surface: np.ndarray, seen: np.ndarray) -> View:
    e = result.extras
    z = np.percentile(seen[:, 2], [2, 50, 98])
    return dict(cands=caught["cands"], combine=caught["combine"], fuse=caught["fuse"], truth=(truth.min, truth.max),
                centre_mm=score.centre_mm, iou=score.iou, recede=e["recede"], elongation=e["elongation"],
                unexplained=e["unexplained"], confidence=e["confidence"], z=z, n=len(seen),
                front_err=1000.0 * (float(z[0]) - float(surface[:, 2].min())),
                box=(result.box.min.copy(), result.box.max.copy()))  # fmt: skip


def collect(out: str, argv: list[str]) -> int:
    from symfruit.cli import main

    caught, _ = _catching()
    views: list[View] = []
    score, complete, instance = runner.score_completion, runner.complete, runner._evaluate_instance

    def keep_result(*a: Any, **kw: Any) -> Any:
        caught["result"] = r = complete(*a, **kw)
        caught["seen"] = np.asarray(a[0])
        return r

    def keep_score(box: Box, points: np.ndarray, truth_box: Box, truth_surface: np.ndarray) -> Any:
        s = score(box, points, truth_box, truth_surface)
        if "fuse" in caught:
            views.append(_view(caught, caught["result"], s, truth_box, truth_surface, caught["seen"]))
        caught.clear()
        return s

    def keep_instance(spec: Any, methods: Any, settings: Any) -> Any:
        rows = instance(spec, methods, settings)
        for r in rows:
            if not r.error and views and "kind" not in views[-1]:
                views[-1].update(kind=r.kind, fruit_id=f"{r.kind}#{r.fruit_index}", pose=r.pose, spec=spec,
                                 hidden=r.hidden, distance=r.distance_m)  # fmt: skip
        return rows

    runner.score_completion, runner.complete, runner._evaluate_instance = keep_score, keep_result, keep_instance  # type: ignore[assignment]
    code = main(["evaluate", *argv, "--methods", "evidence", "--no-profile", "--jobs", "1"])
    kept = [v for v in views if "kind" in v]
    with open(out, "wb") as f:
        pickle.dump(kept, f)
    sys.stderr.write(f"{len(kept)} views: {out} (evaluate exit {code})\n")
    return int(code or 0)


def endon(out: str, fruits: list[str], n: int, tilt: float, seed: int) -> int:
    from symfruit.evaluate.metrics import score_completion
    from symfruit.methods.complete import complete
    from symfruit.settings import Settings

    caught, _ = _catching()
    settings = Settings()
    views: list[View] = []
    for kind in fruits:
        for i in range(n):
            fruit = proto._fruit(proto.Spec("paper", kind, i, 0, 0.0, seed))
            rng = np.random.default_rng([seed, 1000 + proto._KIND_IDS.get(kind, 99), i])  # as the paper protocol
            points = fruit.sample(600, rng) @ proto.rotation_x(tilt).T
            for pose, angle in enumerate(proto.PAPER_ANGLES):
                posed = points @ proto.rotation_x(float(angle)).T
                posed = posed - Box.from_points(posed).centre + [0.0, 0.0, proto.PAPER_DISTANCE]
                seen = posed[proto.paper_visible(posed)]
                caught.clear()
                result = complete(seen, camera=proto.DEFAULT_CAMERA, method="evidence", settings=settings)
                truth = Box.from_points(posed)
                s = score_completion(result.box, result.points, truth, posed)
                v = _view(caught, result, s, truth, posed, seen)
                spec = proto.Spec("paper", kind, i, pose, 0.0, seed)
                v.update(kind=kind, fruit_id=f"{kind}#{i}", pose=pose, spec=spec, hidden=float("nan"),
                         distance=proto.PAPER_DISTANCE)  # fmt: skip
                views.append(v)
    with open(out, "wb") as f:
        pickle.dump(views, f)
    sys.stderr.write(f"{len(views)} views: {out}\n")
    return 0


def _load(path: str) -> list[View]:
    with open(path, "rb") as f:
        views: list[View] = pickle.load(f)
    for v in views:
        v["fuse"].pop("seen_deep", None)
    return views


def _picked(views: list[View], over: float, front: float, occluded: bool) -> list[View]:
    return [v for v in views if v["centre_mm"] > over and abs(v["front_err"]) <= front
            and (not occluded or v["spec"].occlusion > 0)]  # fmt: skip


def show(path: str, over: float, front: float, occluded: bool) -> None:
    views = _load(path)
    s = ev.EvidenceSettings()
    picked = _picked(views, over, front, occluded)
    say(f"{len(picked)} of {len(views)} views over {over} mm with the front within {front} mm "
          f"({sum(v['centre_mm'] > over for v in views)} over)")  # fmt: skip
    for v in picked:
        sp = v["spec"]
        tmin, tmax = v["truth"]
        tc = 0.5 * (tmin + tmax)
        comb = ev.combine(v["cands"], s=s, **v["combine"])
        box, _, width = ev.fuse_depth(comb, v["cands"], None, None, s=s, **v["fuse"])  # type: ignore[arg-type]
        d = 1000 * (box.centre - tc)
        say(f"{sp.fruit:10s} i{sp.index} pose {sp.pose} occ {sp.occlusion} hid {v['hidden']:.2f} dist "
              f"{v['distance']:.2f} err {v['centre_mm']:5.1f} iou {v['iou']:.2f} front {v['front_err']:+5.1f} "
              f"d(xyz) {d[0]:+6.1f} {d[1]:+6.1f} {d[2]:+6.1f} contour {comb.contour:.2f} "
              f"size {np.round(1000 * box.size, 1)} true {np.round(1000 * (tmax - tmin), 1)}")  # fmt: skip
        prior = 1000 * (box.min[2] + s.depth_ratio * width - tmax[2])
        say(f"    back vs truth (mm): shapes {1000 * (comb.box.max[2] - tmax[2]):+6.1f} fused "
              f"{1000 * (box.max[2] - tmax[2]):+6.1f} prior {prior:+6.1f} "
              f"seen {1000 * (v['fuse']['seen_back'] - tmax[2]):+6.1f}; prior width {1000 * width:.1f}, "
              f"rim {v['fuse']['rim']:.2f}")  # fmt: skip
        for c in v["cands"]:
            dc = 1000 * (0.5 * (c.lo + c.hi) - tc)
            a = c.agreement
            say(f"    {c.name:10s} w {comb.weights[c.name]:.2f} e {comb.energies[c.name]:6.2f} centre "
                  f"{np.linalg.norm(dc):5.1f} ({dc[0]:+5.1f} {dc[1]:+5.1f} {dc[2]:+5.1f}) size "
                  f"{np.round(1000 * (c.hi - c.lo), 1)}"
                  + ("" if a is None
                     else f" depth rms {1000 * a.depth:.2f} in {a.inside:.2f} out {a.outside:.2f}"))  # fmt: skip


def _true_back(v: View) -> float:
    """The centre error (mm) of the result with its back face moved to the truth's."""
    lo, hi = (np.array(x, dtype=float) for x in v["box"])
    hi[2] = max(float(v["truth"][1][2]), lo[2] + 1e-4)
    return 1000.0 * centre_deviation(Box(lo, hi), Box(*v["truth"]))


def _best(v: View) -> tuple[float, str]:
    t = Box(*v["truth"])
    return min((1000.0 * centre_deviation(Box(c.lo, c.hi), t), c.name) for c in v["cands"])


def classify(paths: list[str], over: float, front: float) -> None:
    s = ev.EvidenceSettings()
    say("| set | occlusion | views (front right) | result | best candidate | true back face | over 10 mm "
          "(front right) | of them: depth / lateral | best candidate <= 6 mm | winner (most weight) |")  # fmt: skip
    say("|---" * 10 + "|")
    for path in paths:
        views = [v for v in _load(path) if abs(v["front_err"]) <= front]
        for occ in sorted({v["spec"].occlusion for v in views}):
            group = [v for v in views if v["spec"].occlusion == occ]
            bad = [v for v in group if v["centre_mm"] > over]
            depth = lateral = near = 0
            winners: dict[str, int] = {}
            for v in bad:
                d = np.abs(v["box"][0] + v["box"][1] - v["truth"][0] - v["truth"][1]) / 2
                depth += int(d[2] >= max(d[0], d[1]))
                lateral += int(d[2] < max(d[0], d[1]))
                near += int(_best(v)[0] <= 6.0)
                w = ev.combine(v["cands"], s=s, **v["combine"]).weights
                top = max(w, key=w.__getitem__)
                winners[top] = winners.get(top, 0) + 1
            res = np.mean([v["centre_mm"] for v in group])
            best = np.mean([_best(v)[0] for v in group])
            tb = np.mean([_true_back(v) for v in group])
            win = ", ".join(f"{k} {n}" for k, n in sorted(winners.items(), key=lambda kv: -kv[1]))
            say(f"| {Path(path).stem} | {occ:g} | {len(group)} | {res:.2f} | {best:.2f} | {tb:.2f} | {len(bad)} | "
                  f"{depth} / {lateral} | {near} | {win} |")  # fmt: skip


def variants(sets: list[str], names: list[str]) -> None:
    loaded: list[tuple[str, list[View]]] = []
    for spec in sets:
        label, _, rest = spec.partition("=")
        path, _, kind = rest.partition(":")
        views = _load(path)
        if kind.startswith("@"):
            views = [v for v in views if v["spec"].occlusion == float(kind[1:])]
        elif kind == "p7":
            views = [v for v in views if v["kind"].split("/")[0] in scans39.P7]
        elif kind:
            views = [v for v in views if v["kind"] == kind]
        loaded.append((label, views))
    say("| variant | " + " | ".join(f"{label} ({len(views)})" for label, views in loaded) + " |")
    say("|---" * (len(loaded) + 1) + "|")
    for name in names:
        key, _, kv = name.partition("=")
        over = {k: float(x) for k, x in (item.split(":") for item in kv.split(","))} if kv else {}
        s = dataclasses.replace(ev.EvidenceSettings(), **scans39.VARIANTS.get(key, {}), **over)
        rule = key if key in scans39.RULES else "default"
        floor = float(key[7:]) if key.startswith("contour") and key[7:8].isdigit() else None
        cells = []
        for _, views in loaded:
            if floor is not None:  # the contour share read as at least ``floor`` (weights and prior alike)
                views = [{**v, "combine": {**v["combine"], "contour": max(floor, v["combine"]["contour"])}}
                         for v in views]  # fmt: skip
            if key in OUTSIDE:
                views = [_outside(v, key) for v in views]
            r = np.array([scans39.evaluate_view(v, s, rule) for v in views])
            w = scans39.within(np.array([v["fruit_id"] for v in views]), r[:, 2], r[:, 1])
            cells.append(f"{r[:, 0].mean():.3f} / {r[:, 1].mean():.2f} / {(r[:, 1] > 10).sum()}"
                         + (f" / {w:+.2f}" if np.isfinite(w) else ""))  # fmt: skip
        say(f"| {name} | " + " | ".join(cells) + " |")


def edge(sensor: str, fruit: str, occlusion: float, index: int, reach: int) -> None:
    """What the occlusion map calls hidden in a ring of ``reach`` pixels about a camera-protocol view's fruit mask,
    and how deep it is against the nearest seen point of the fruit (a stereo camera's fattened edge reads as an
    occluder at the fruit's own depth, and every outline pixel within ``occluded_px`` of one is a cut)."""
    from scipy import ndimage

    from symfruit.extract import extract, register
    from symfruit.occlusion import fruit_occlusion
    from symfruit.settings import Settings

    st = Settings()
    inst = proto.build(proto.Spec("camera", fruit, index, index, occlusion, 0, sensor, "hanging"))
    assert inst.mask is not None and inst.depth is not None
    moved, shift = register(inst.mask.astype(np.int32), inst.depth, inst.camera, st.extract)
    camera = inst.camera.shifted(*shift)
    ex = extract(moved > 0, inst.depth, camera, st.extract)
    mask = ex.silhouette if ex.silhouette is not None else moved > 0
    occ = fruit_occlusion(inst.depth, mask, ex.points, camera, st.occlusion)
    hidden, own = occ.hidden, occ.own
    assert own is not None and occ.depth is not None
    ring = ndimage.binary_dilation(own, iterations=reach) & ~own
    uv = camera.project(ex.points)
    col, row = np.rint(uv[:, 0]).astype(int) - occ.u0, np.rint(uv[:, 1]).astype(int) - occ.v0
    ok = (col >= 0) & (col < hidden.shape[1]) & (row >= 0) & (row < hidden.shape[0])
    z = np.full(hidden.shape, np.nan)
    z[row[ok], col[ok]] = ex.points[ok, 2]
    _, (ri, ci) = ndimage.distance_transform_edt(np.isnan(z), return_indices=True)
    diff = 1000.0 * (occ.depth - z[ri, ci])[hidden & ring]
    pct = np.round(np.nanpercentile(diff, [5, 25, 50, 75, 95]), 1) if diff.size else "-"
    say(f"{sensor} {fruit} i{index} occ {occlusion:g}: ring {ring.sum()} px, hidden {(hidden & ring).sum()} "
          f"({(hidden & ring).sum() / max(ring.sum(), 1):.2f}); hidden minus nearest seen depth (mm), "
          f"5/25/50/75/95 %: "
          f"{pct}; fruit seen {1000 * ex.points[:, 2].min():.0f}-{1000 * ex.points[:, 2].max():.0f} mm")  # fmt: skip


def main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("collect")
    c.add_argument("out")
    c.add_argument("evaluate", nargs=argparse.REMAINDER)
    e = sub.add_parser("endon")
    e.add_argument("out")
    e.add_argument("--fruit", default="pear,banana,lemon")
    e.add_argument("--n", type=int, default=3)
    e.add_argument("--tilt", type=float, default=90.0)
    e.add_argument("--seed", type=int, default=7)
    m = sub.add_parser("show")
    m.add_argument("path")
    m.add_argument("--over", type=float, default=10.0)
    m.add_argument("--front", type=float, default=6.0)
    m.add_argument("--occluded", action="store_true")
    k = sub.add_parser("classify")
    k.add_argument("paths", nargs="+")
    k.add_argument("--over", type=float, default=10.0)
    k.add_argument("--front", type=float, default=6.0)
    r = sub.add_parser("variants")
    r.add_argument("sets", nargs="+")
    r.add_argument("--variant", action="append")
    g = sub.add_parser("edge")
    g.add_argument("sensor")
    g.add_argument("fruit")
    g.add_argument("occlusion", type=float)
    g.add_argument("index", type=int)
    g.add_argument("--reach", type=int, default=4)
    a = p.parse_args(argv)
    if a.cmd == "edge":
        edge(a.sensor, a.fruit, a.occlusion, a.index, a.reach)
        return 0
    if a.cmd == "collect":
        return collect(a.out, a.evaluate)
    if a.cmd == "endon":
        return endon(a.out, a.fruit.split(","), a.n, a.tilt, a.seed)
    if a.cmd == "show":
        show(a.path, a.over, a.front, a.occluded)
    elif a.cmd == "classify":
        classify(a.paths, a.over, a.front)
    else:
        variants(a.sets, a.variant or ["default"])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
