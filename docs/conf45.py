"""Whole-pipeline quantities as confidence features of `evidence` (docs/conf45.md): ``collect`` runs
docs/confidence_features.py's collection (the evaluation's own instances, `evidence` with the defaults) and adds, a
view, what the pipeline already computed that may say the view is broken or ambiguous: the prior's pull on the back
face in the two estimates' deviations, the outline's lateral extent against the shapes' box, the share of the mask
without depth and the share the mask overshoots the fruit by, the registration shift, the candidates' energy margin
and weights' entropy; ``table`` prints within / pooled Spearman of each feature and formula and the `reliable` flag's
precision / recall for views off by more than 4 and 10 mm.

    python docs/conf45.py collect OUT.csv [confidence_features.py collect's options] [--occlusion 0,0.25,0.5]
    python docs/conf45.py table A.csv [B.csv ...]
"""

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import confidence_features as cf

import symfruit.methods.evidence as evidence
from symfruit.evaluate import runner
from symfruit.evaluate.protocols import specs

EXTRA: dict = {}
ROW = cf._row


def _install() -> None:
    """Wrap what `evidence` and the runner call, keeping what they return in :data:`EXTRA`."""
    observe, close_ragged, register = evidence.observe, evidence.close_ragged, runner.register

    def keep_observed(*a, **kw):
        obs = observe(*a, **kw)
        EXTRA.update(region=a[1], camera=a[2], occlusion=kw.get("occlusion"), obs=obs)
        return obs

    def keep_ragged(*a, **kw):
        EXTRA["seen_region"] = close_ragged(*a, **kw)
        return EXTRA["seen_region"]

    def keep_register(*a, **kw):
        moved, shift = register(*a, **kw)
        EXTRA["shift"] = shift
        return moved, shift

    evidence.observe, evidence.close_ragged, runner.register = keep_observed, keep_ragged, keep_register


def _row(spec, row, caught: dict) -> dict:
    out = ROW(spec, row, caught)
    combined, cands, kw = caught["combined"], caught["cands"], caught["fuse"]
    s = kw["s"]
    box = caught["result"].box
    fit_back, front = float(combined.box.max[2]), float(combined.box.min[2])
    width = out["width"]
    prior_sd = s.depth_ratio_sd * width / max(combined.contour, 0.25)
    prior_back = front + s.depth_ratio * width
    out["gap"] = prior_back - fit_back  # signed: the prior deeper than the shapes
    out["gap_z"] = (prior_back - fit_back) / float(np.hypot(out["fit_sd"], prior_sd))
    # the outline's lateral extent (at the fused box's distance, as fuse_depth reads it) against the shapes' box
    across = kw["across"]
    dist = 0.5 * float(box.min[2] + box.max[2]) / across.axis[2]
    sil_lo, sil_hi = dist * (across.axis[:2] + across.lo), dist * (across.axis[:2] + across.hi)
    d_lo, d_hi = sil_lo - combined.box.min[:2], sil_hi - combined.box.max[:2]
    ext_sil, ext_box = sil_hi - sil_lo, combined.box.max[:2] - combined.box.min[:2]
    out["lat_dis"] = float(np.abs(np.r_[d_lo, d_hi]).max())
    out["lat_ratio"] = float(np.abs(np.log(ext_sil / np.maximum(ext_box, 1e-6))).max())
    out["lat_signed"] = float(np.log(ext_sil / np.maximum(ext_box, 1e-6)).mean())  # > 0: the outline wider
    # the mask's pixels without depth, the share it overshoots the fruit by, the camera seeing past it
    region, seen, occ, cam = EXTRA["region"], EXTRA["seen_region"], EXTRA["occlusion"], EXTRA["camera"]
    uv = np.rint(cam.project(caught["points"])).astype(np.int64)
    n_px = len(np.unique(uv[:, 0] * 100_000 + uv[:, 1]))
    own = occ.own if occ is not None and occ.own is not None else region.mask
    n_own = max(int(np.count_nonzero(own)), 1)
    out["nodepth"] = max(0.0, 1.0 - n_px / n_own)
    out["region_px"] = int(np.count_nonzero(region.mask))
    out["seen_px"] = int(np.count_nonzero(seen.mask))
    over = None if occ is None else occ.overshoot
    out["overshoot"] = 0.0 if over is None else float(np.count_nonzero(over)) / n_own
    out["seen_past"] = int(bool(occ is not None and occ.seen_past))
    out["cone_moments"] = int(EXTRA["obs"].cone_source == "moments")
    shift = EXTRA.get("shift", (0, 0))
    out["shift_px"] = float(np.hypot(*shift))
    # the candidates: energy margin of the best closed one over the next, the weights' entropy, the box's weight
    e = combined.energies
    closed = sorted(e[c.name] for c in cands if c.agreement is not None)
    out["margin"] = closed[1] - closed[0] if len(closed) > 1 else 10.0
    w = np.array(list(combined.weights.values()))
    out["entropy"] = float(-(w * np.log(np.maximum(w, 1e-300))).sum())
    out["raw_w"] = float(combined.weights.get("raw", 0.0))
    out["wrong"] = 2.0 * (1.0 - combined.explained)
    out["spread"] = combined.spread
    out["back_std"] = next((c.back_std for c in cands if c.name == "cone" and np.isfinite(c.back_std)), 0.0)
    out["size"] = float(combined.box.size.max())
    out["rim"] = float(kw["rim"])
    out.update(hidden=row.hidden, n_visible=row.n_visible, distance_m=row.distance_m, depth_mm=row.depth_mm,
               lateral_mm=row.lateral_mm, occl=spec.occlusion, iou=row.iou)  # fmt: skip
    EXTRA.clear()
    return out


def collect(args: argparse.Namespace) -> None:
    """docs/confidence_features.py's ``collect`` with ``--occlusion`` levels (the leaf tables)."""
    _install()
    cf._row = _row
    occl = tuple(float(x) for x in args.occlusion.split(","))
    real = specs

    def with_occlusion(*a, **kw):
        return real(*a, occlusions=occl, **kw)

    cf.specs = with_occlusion
    cf.collect(args)


def load(path: str) -> cf.Columns:
    d = cf.load(path)
    d["aspect"] = d["major"] / d["minor"]
    return d


FEATURES = ("uncertainty", "combined_u", "moved", "recede", "unexplained", "elongation", "aspect", "p", "gap",
            "gap_z", "lat_dis", "lat_ratio", "lat_signed", "nodepth", "overshoot", "seen_past", "contour", "shift_px",
            "margin", "entropy", "raw_w", "wrong", "spread", "back_std", "rim", "width", "noise", "best_rms",
            "hidden", "distance_m", "n_visible")  # fmt: skip


def flag_table(d: cf.Columns, reliable: np.ndarray) -> str:
    """``unreliable`` as a detector of views off by more than 4 and 10 mm: recall (of the views over, how many are
    flagged unreliable) and precision (of the views flagged unreliable, how many are over); then the share flagged
    reliable among the views under 2 mm."""
    err, flag = d["centre_mm"], ~reliable
    cells = []
    for t in (4.0, 10.0):
        bad = err > t
        cells.append(f">{t:g} mm: recall {(bad & flag).sum()}/{bad.sum()}, precision {(bad & flag).sum()}/{flag.sum()}")
    good = err < 2.0
    cells.append(f"reliable under 2 mm {(reliable & good).sum()}/{good.sum()}")
    return "; ".join(cells)


def table(paths: list[str], formulas: dict) -> None:
    data = [load(p) for p in paths]
    w = sys.stdout.write
    w("| feature; within / pooled | " + " | ".join(paths) + " |\n" + "|---" * (len(paths) + 1) + "|\n")
    for name in FEATURES:
        cells = [f"{cf._num(cf.within(d, d[name]))} / {cf._num(cf.pooled(d, d[name]))}" for d in data]
        w(f"| {name} | " + " | ".join(cells) + " |\n")
    w("\n| formula; within / pooled / reliable | " + " | ".join(paths) + " |\n" + "|---" * (len(paths) + 1) + "|\n")
    for name, (f, rel) in formulas.items():
        cells = []
        for d in data:
            u = np.asarray(f(d), float)
            r = np.asarray(rel(d, u), bool)
            cells.append(f"{cf._num(cf.within(d, u))} / {cf._num(cf.pooled(d, u))} / {r.mean():.0%}")
        w(f"| {name} | " + " | ".join(cells) + " |\n")
    w("\n")
    for name, (f, rel) in formulas.items():
        for path, d in zip(paths, data, strict=True):
            u = np.asarray(f(d), float)
            w(f"{name} | {path}: {flag_table(d, np.asarray(rel(d, u), bool))}\n")


def U(d: cf.Columns, us: float = 1.0, cut: float = 0.0, lat: float = 0.0) -> np.ndarray:
    """`evidence`'s uncertainty recomputed from the collected terms (``unexplained_scale`` ``us``, ``cut_scale``
    ``cut``, ``lateral_scale`` ``lat``; the rest the defaults'), whichever tree collected the CSV."""
    return d["elongation"] * np.sqrt(d["combined_u"] ** 2 + d["moved"] ** 2 + (0.1 * d["recede"]) ** 2
                                     + (us * d["unexplained"]) ** 2 + (cut * (1 - d["contour"]) * d["size"]) ** 2
                                     + (lat * d["lat_dis"]) ** 2)  # fmt: skip


def _at(t: float):
    return lambda d, u: u <= t


FORMULAS: dict = {
    "stop 44 (2.5 mm)": (lambda d: U(d), _at(0.0025)),
    "unexplained x 2 (2.5 mm)": (lambda d: U(d, us=2.0), _at(0.0025)),
    "unexplained x 3 (2.5 mm)": (lambda d: U(d, us=3.0), _at(0.0025)),
    "+ cut 0.1 (2.5 mm)": (lambda d: U(d, us=1.0, cut=0.1), _at(0.0025)),
    "+ lateral 0.5 (2.5 mm)": (lambda d: U(d, us=1.0, lat=0.5), _at(0.0025)),
    "x 2, cut 0.1, lateral 0.5 (2.5 mm)": (lambda d: U(d, us=2.0, cut=0.1, lat=0.5), _at(0.0025)),
    "x 3, cut 0.1, lateral 0.5 (2.5 mm)": (lambda d: U(d, us=3.0, cut=0.1, lat=0.5), _at(0.0025)),
    "x 3, cut 0.1, lateral 0.5 (3 mm)": (lambda d: U(d, us=3.0, cut=0.1, lat=0.5), _at(0.003)),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="cmd", required=True)
    c = cf.collect_arguments(sub.add_parser("collect", help="confidence_features.py's collect, more columns"))
    c.add_argument("--occlusion", default="0", help="leaf occlusion levels, comma-separated")
    t = sub.add_parser("table", help="within / pooled Spearman of each feature and formula, a column a CSV")
    t.add_argument("csv", nargs="+")
    args = parser.parse_args()
    if args.cmd == "collect":
        collect(args)
    else:
        table(args.csv, FORMULAS)


if __name__ == "__main__":
    main()
