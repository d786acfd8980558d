"""Stop 57's diagnosis of `evidence` behind the `ellipsoid` on fruit stood up (docs/upright57.md).

    python docs/upright57.py endon OUT.pkl --fruit pear,lemon,banana,lopsided --n 3 --tilt 90 [--seed 7]
    python docs/upright57.py best SET.pkl [...]
    python docs/upright57.py views SET.pkl KIND
    python docs/upright57.py spheroid [--seed 3]
    python docs/upright57.py profile FRUIT INDEX [--pose upright] [--seed 0]

``endon`` is docs/evid40.py's ``endon`` (generated fruit turned ``--tilt`` degrees about the camera's x axis, then
the paper protocol's 19 poses; the pickle ``evid40.py show`` and ``variants`` read) and also completes every view by
``--others`` (default ``ellipsoid,sphere``) and keeps their (IoU, centre error mm) and the seen points; it prints per
kind ``evidence`` against them (mean IoU / mean centre error mm / views over 10 mm). ``best`` prints, per set and
kind, which closed candidate explains the seen depths best (least depth RMS) how often, its own centre error on
those views and `evidence`'s (does trusting the best-explaining candidate more pay?); it reads any pickle of
``evid40.py collect`` or ``endon``. ``views`` lists an ``endon`` pickle's views of one kind: `evidence` against the
ellipsoid, the seen and true box sizes (mm), and every candidate's weight, centre offset (mm) and agreement.
``spheroid`` completes exact spheroids (600 points on the surface; semi-axes across and along the line of sight
below, the axis along the line of sight at the 0 deg pose) in the paper protocol's 19 poses by `evidence`,
`ellipsoid` and `sphere` (mean / worst centre error, mm, and `evidence`'s worst pose). ``profile`` prints, for the
paper protocol's 19 views of one fruit (``FRUIT`` a kind or a folder of scans, ``INDEX`` which), the solid of
revolution :func:`~symfruit.core.fits.fit_revolution_slices` fits to the visible set as `evidence` samples it: its
axis's angle from the line of sight, its RMS and its slices' radii (mm). Run with ``PYTHONPATH=TREE/src`` from the
repository's root; development seeds only (below 100).
"""

from __future__ import annotations

import argparse
import pickle
import sys
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import evid40
import pear43

import symfruit.methods.evidence as ev
from symfruit.core.box import Box
from symfruit.evaluate import protocols as proto
from symfruit.evaluate.metrics import centre_deviation, score_completion
from symfruit.methods.complete import complete
from symfruit.settings import Settings
from symfruit.synthetic.shapes import paper_visible, rotation_x

View = dict[str, Any]
#: ``spheroid``'s shapes: (semi-axis across, semi-axis along the line of sight when end-on), metres.
SPHEROIDS = ((0.033, 0.050), (0.033, 0.033), (0.033, 0.025), (0.020, 0.045))


def say(*parts: Any) -> None:
    sys.stdout.write(" ".join(str(p) for p in parts) + "\n")


def _row(views: list[View], others: list[str]) -> str:
    cells = [f"evidence {np.mean([v['iou'] for v in views]):.3f} / {np.mean([v['centre_mm'] for v in views]):.2f} / "
             f"{sum(v['centre_mm'] > 10 for v in views)}"]  # fmt: skip
    for m in others:
        r = np.array([v["other"][m] for v in views])
        cells.append(f"{m} {np.nanmean(r[:, 0]):.3f} / {np.nanmean(r[:, 1]):.2f} / {int(np.nansum(r[:, 1] > 10))}")
    return " | ".join(cells)


def endon(out: str, fruits: list[str], n: int, tilt: float, seed: int, others: list[str]) -> int:
    if seed >= 100:
        raise SystemExit("seeds of 100 and up are held out")
    caught, _ = evid40._catching()
    settings = Settings()
    views: list[View] = []
    for kind in fruits:
        # docs/pear43.py's end-on views: evid40.py endon's (the same points, poses and visible halves)
        for number, (_, seen, posed, truth) in enumerate(pear43.endon_views(kind, tilt, n, seed)):
            i, pose = divmod(number, len(proto.PAPER_ANGLES))
            caught.clear()
            result = complete(seen, camera=proto.DEFAULT_CAMERA, method="evidence", settings=settings)
            v = evid40._view(caught, result, score_completion(result.box, result.points, truth, posed), truth, posed,
                             seen)  # fmt: skip
            v.update(kind=kind, fruit_id=f"{kind}#{i}", pose=pose, spec=proto.Spec("paper", kind, i, pose, 0.0, seed),
                     hidden=float("nan"), distance=proto.PAPER_DISTANCE, seen=seen, other={})  # fmt: skip
            for m in others:
                try:
                    r = complete(seen, camera=proto.DEFAULT_CAMERA, method=m, settings=settings)
                    s = score_completion(r.box, r.points, truth, posed)
                    v["other"][m] = (s.iou, s.centre_mm)
                except ValueError:  # a fit that fails (the sphere of a banana's cap)
                    v["other"][m] = (0.0, float("nan"))
            views.append(v)
        say(f"{kind} tilt {tilt:+g}: " + _row([v for v in views if v["kind"] == kind], others))
    with open(out, "wb") as f:
        pickle.dump(views, f)
    return 0


def best(paths: list[str]) -> None:
    for path in paths:
        views: list[View] = evid40._load(path)
        for kind in sorted({v["kind"] for v in views}):
            stats: dict[str, list[tuple[float, float]]] = {}
            for v in (v for v in views if v["kind"] == kind):
                closed = [c for c in v["cands"] if c.agreement is not None]
                if not closed:
                    continue
                top = min(closed, key=lambda c: c.agreement.depth)
                err = 1000.0 * centre_deviation(Box(top.lo, top.hi), Box(*v["truth"]))
                stats.setdefault(top.name, []).append((err, v["centre_mm"]))
            cells = [f"{name} {len(x)} views, {np.mean([a for a, _ in x]):.2f} against {np.mean([b for _, b in x]):.2f}"
                     for name, x in sorted(stats.items(), key=lambda kv: -len(kv[1]))]  # fmt: skip
            say(f"| {Path(path).stem} | {kind} | " + "; ".join(cells) + " |")


def views(path: str, kind: str) -> None:
    s = ev.EvidenceSettings()
    for v in (v for v in evid40._load(path) if v["kind"] == kind):
        t = Box(*v["truth"])
        comb = ev.combine(v["cands"], s=s, **v["combine"])
        e_iou, e_c = v["other"].get("ellipsoid", (float("nan"), float("nan")))
        seen = v["seen"]
        row = (f"{v['fruit_id']} pose {v['pose']:2d}: evidence {v['iou']:.2f} / {v['centre_mm']:5.1f}, ellipsoid "
               f"{e_iou:.2f} / {e_c:5.1f}; seen {np.round(1000 * (seen.max(0) - seen.min(0)))} true "
               f"{np.round(1000 * t.size)} |")  # fmt: skip
        for c in v["cands"]:
            d = 1000.0 * (0.5 * (c.lo + c.hi) - t.centre)
            a = c.agreement
            row += f" {c.name} w {comb.weights[c.name]:.2f} ({d[0]:+.0f} {d[1]:+.0f} {d[2]:+.0f})" + (
                "" if a is None else f" rms {1000 * a.depth:.1f} in {a.inside:.2f} out {a.outside:.2f}"
            )
        say(row)


def spheroid(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for across, along in SPHEROIDS:
        u = rng.normal(size=(600, 3))
        points = u / np.linalg.norm(u, axis=1)[:, None] * [across, across, along]
        errors: dict[str, list[float]] = {}
        for angle in proto.PAPER_ANGLES:
            posed = points @ rotation_x(float(angle)).T
            posed = posed - Box.from_points(posed).centre + [0.0, 0.0, proto.PAPER_DISTANCE]
            seen = posed[paper_visible(posed)]
            truth = Box.from_points(posed)
            for m in ("evidence", "ellipsoid", "sphere"):
                r = complete(seen, camera=proto.DEFAULT_CAMERA, method=m)
                errors.setdefault(m, []).append(score_completion(r.box, r.points, truth, posed).centre_mm)
        worst = np.argmax(errors["evidence"])
        say(f"| {2000 * across:.0f} x {2000 * along:.0f} mm | "
            + " | ".join(f"{np.mean(e):.2f} / {np.max(e):.1f}" for e in errors.values())
            + f" | pose {worst} |")  # fmt: skip


def profile(fruit: str, index: int, poses: str, seed: int) -> None:
    from symfruit.core.fits import _flat, fit_revolution_slices
    from symfruit.core.points import subsample

    s = ev.EvidenceSettings()
    for pose in range(len(proto.PAPER_ANGLES)):
        seen = proto.build(proto.Spec("paper", fruit, index, pose, 0.0, seed, "d435", poses)).visible
        sample = subsample(seen, s.fit_points)
        rev = fit_revolution_slices(sample[:: max(1, len(sample) // s.revolution_points)], coarse=s.revolution_coarse)
        angle = float(np.degrees(np.arccos(min(1.0, abs(float(rev.direction[2]))))))
        say(f"pose {pose:2d}: axis {angle:4.1f} deg from the line of sight, rms {1000 * _flat(rev):.2f}, radii "
            f"{np.round(1000 * rev.radii, 1).tolist()}")  # fmt: skip


def main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    e = sub.add_parser("endon")
    e.add_argument("out")
    e.add_argument("--fruit", default="pear,lemon,banana,lopsided")
    e.add_argument("--n", type=int, default=3)
    e.add_argument("--tilt", type=float, default=90.0)
    e.add_argument("--seed", type=int, default=7)
    e.add_argument("--others", default="ellipsoid,sphere")
    b = sub.add_parser("best")
    b.add_argument("sets", nargs="+")
    w = sub.add_parser("views")
    w.add_argument("set")
    w.add_argument("kind")
    s = sub.add_parser("spheroid")
    s.add_argument("--seed", type=int, default=3)
    f = sub.add_parser("profile")
    f.add_argument("fruit")
    f.add_argument("index", type=int)
    f.add_argument("--pose", default="upright")
    f.add_argument("--seed", type=int, default=0)
    a = p.parse_args(argv)
    if getattr(a, "seed", 0) >= 100:
        raise SystemExit("seeds of 100 and up are held out")
    if a.cmd == "endon":
        return endon(a.out, a.fruit.split(","), a.n, a.tilt, a.seed, [m for m in a.others.split(",") if m])
    if a.cmd == "best":
        best(a.sets)
    elif a.cmd == "views":
        views(a.set, a.kind)
    elif a.cmd == "profile":
        profile(a.fruit, a.index, a.pose, a.seed)
    else:
        spheroid(a.seed)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
