"""Refit spreads of `evidence`'s centre as confidence features (docs/conf42.md): ``collect`` runs
docs/confidence_features.py's collection and adds, a view, the spread along the line of sight of the completed
centre over refits of the whole completion on subsets of the seen points (random halves; the halves of the visible
cap either side of the outline's major and minor axes, the outline itself kept), and the candidates' back-face
spread under softer weights. ``table`` prints within / pooled Spearman of each feature and formula.

    python docs/conf42.py collect OUT.csv [confidence_features.py collect's options]
    python docs/conf42.py table A.csv [B.csv ...]
    python docs/conf42.py ceiling FIT.csv [A.csv ...]   # a linear mix of every feature, fitted on FIT.csv
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import confidence_features as cf

from symfruit.evaluate import runner
from symfruit.methods.complete import complete as _complete

ARGS: dict = {}


def _keep_args(points, *a, **kw):
    ARGS.update(points=points, kw=kw)
    return _complete(points, *a, **kw)


def _refit(points: np.ndarray, keep: np.ndarray) -> np.ndarray:
    r = _complete(points[keep], **ARGS["kw"])
    return np.concatenate((r.box.centre, [r.box.max[2]]))


def _row(spec, row, caught):
    out = ROW(spec, row, caught)
    base = caught["result"].box
    energies = caught["combined"].energies
    cands = caught["cands"]
    e = np.array([energies[c.name] for c in cands])
    backs = np.array([c.hi[2] for c in cands])
    zc = np.array([0.5 * (c.lo[2] + c.hi[2]) for c in cands])
    for t in (2.0, 4.0, 8.0):
        w = np.exp(-(e - e.min()) / t)
        w /= w.sum()
        out[f"soft{t:g}_back"] = float((w * np.abs(backs - base.max[2])).sum())
        m = float((w * zc).sum())
        out[f"soft{t:g}_zsd"] = float(np.sqrt((w * (zc - m) ** 2).sum()))
    pts = ARGS["points"]
    t0 = time.process_time()
    rng = np.random.default_rng(spec.index * 7919 + len(pts))
    rnd = []
    for _ in range(2):
        perm = rng.permutation(len(pts))
        half = np.zeros(len(pts), bool)
        half[perm[: len(pts) // 2]] = True
        rnd += [_refit(pts, half), _refit(pts, ~half)]
    t1 = time.process_time()
    uv = pts[:, :2] / pts[:, 2:3]
    uv = uv - uv.mean(axis=0)
    _, vec = np.linalg.eigh(uv.T @ uv)
    spat = []
    for axis in (vec[:, 1], vec[:, 0]):  # the halves either side of the minor axis, then of the major axis
        side = uv @ axis > 0
        spat += [_refit(pts, side), _refit(pts, ~side)]
    t2 = time.process_time()
    c0 = np.concatenate((base.centre, [base.max[2]]))
    for name, fits in (("rand", np.array(rnd)), ("spat", np.array(spat))):
        out[f"{name}_zsd"] = float(np.std(fits[:, 2]))
        out[f"{name}_zdev"] = float(np.sqrt(np.mean((fits[:, 2] - c0[2]) ** 2)))
        out[f"{name}_xysd"] = float(np.sqrt(np.sum(np.var(fits[:, :2], axis=0))))
        out[f"{name}_backsd"] = float(np.std(fits[:, 3]))
        out[f"{name}_zmean"] = float(np.mean(fits[:, 2]) - c0[2])
    s = np.array(spat)
    out["spat_long_dz"] = float(abs(s[0, 2] - s[1, 2]))
    out["spat_short_dz"] = float(abs(s[2, 2] - s[3, 2]))
    out["t_rand"], out["t_spat"] = t1 - t0, t2 - t1
    out.update(distance_m=row.distance_m, n_visible=row.n_visible, depth_mm=row.depth_mm, lateral_mm=row.lateral_mm,
               angle_x=row.angle_x, angle_y=row.angle_y, angle_z=row.angle_z,
               back_std=next((c.back_std for c in cands if c.name == "cone" and np.isfinite(c.back_std)), 0.0),
               rim=caught["fuse"]["rim"], fit_back=float(caught["combined"].box.max[2]))  # fmt: skip
    return out


ROW = cf._row

FEATURES = ("rand_zsd", "rand_zdev", "rand_backsd", "rand_xysd", "spat_zsd", "spat_zdev", "spat_backsd",
            "spat_long_dz", "spat_short_dz", "soft2_back", "soft4_back", "soft8_back", "soft2_zsd", "soft4_zsd",
            "soft8_zsd", "prior_spread", "back_std", "noise", "distance_m", "n_visible", "uncertainty")  # fmt: skip


def _formulas():
    def U(k, name):
        return lambda d: np.sqrt(d["uncertainty"] ** 2 + (k * d["elongation"] * d[name]) ** 2)

    out = [("the default", lambda d: d["uncertainty"])]
    for name in ("rand_zsd", "rand_zdev", "spat_zsd", "spat_zdev", "soft2_back", "soft4_back", "soft8_back",
                 "prior_spread", "back_std", "noise"):  # fmt: skip
        for k in (0.5, 1.0, 2.0, 4.0):
            out.append((f"U({k:g} {name})", U(k, name)))
    for k in (0.005, 0.01):
        out.append((f"U({k:g} distance^2)", U(k, "distance2")))
    for k in (0.5, 1.0, 2.0):  # a narrower silhouette, less confident (the reference width sets no rank)
        out.append((f"u x (0.06 m / width)^{k:g}", lambda d, k=k: d["uncertainty"] * (0.06 / d["width"]) ** k))
    return out


def _derived(d: cf.Columns) -> cf.Columns:
    """The prior's own spread as it enters the back face: its share times its deviation (fuse_depth)."""
    d["prior_spread"] = d["p"] * 0.15 * d["width"] / np.maximum(d["contour"], 0.25)
    d["distance2"] = d["distance_m"] ** 2  # metres: a depth camera's axial noise grows with it
    return d


def table(paths: list[str]) -> None:
    data = [_derived(cf.load(p)) for p in paths]
    w = sys.stdout.write
    w("| feature; within / pooled | " + " | ".join(paths) + " |\n" + "|---" * (len(paths) + 1) + "|\n")
    for name in FEATURES:
        cells = [f"{cf._num(cf.within(d, d[name]))} / {cf._num(cf.pooled(d, d[name]))}" for d in data]
        w(f"| {name} | " + " | ".join(cells) + " |\n")
    w("\n| formula; within / pooled / reliable | " + " | ".join(paths) + " |\n" + "|---" * (len(paths) + 1) + "|\n")
    for name, f in _formulas():
        cells = []
        for d in data:
            u = np.asarray(f(d), float)
            cells.append(f"{cf._num(cf.within(d, u))} / {cf._num(cf.pooled(d, u))} / {(u <= 0.0025).mean():.0%}")
        w(f"| {name} | " + " | ".join(cells) + " |\n")


CEILING = ("uncertainty", "front", "width", "best_rms", "p", "noise", "back_sd", "fit_sd", "cone_w", "recede",
           "elongation", "rand_zsd", "spat_zsd", "combined_u", "moved", "depth_range", "minor", "major")  # fmt: skip


def ceiling(paths: list[str]) -> None:
    """Least squares of the log centre error on the logs of :data:`CEILING`, each less its fruit's mean, fitted on
    the first CSV: what a linear mix of every feature reaches within a fruit in the sample it was fitted to."""

    def logs(d: cf.Columns) -> np.ndarray:
        return np.log(np.maximum(np.nan_to_num(np.array([d[n] for n in CEILING]).T), 1e-5))

    def less_means(d: cf.Columns, a: np.ndarray) -> np.ndarray:
        a = a.copy()
        for fruit in dict.fromkeys(d["fruit_id"]):
            ix = d["fruit_id"] == fruit
            a[ix] -= a[ix].mean(axis=0)
        return a

    d = cf.load(paths[0])
    y = less_means(d, np.log(d["centre_mm"])[:, None])[:, 0]
    coef = np.linalg.lstsq(less_means(d, logs(d)), y, rcond=None)[0]
    sys.stdout.write(", ".join(f"{n} {c:+.2f}" for n, c in zip(CEILING, coef, strict=True)) + "\n")
    for path in paths:
        e = cf.load(path)
        f = logs(e) @ coef
        sys.stdout.write(f"{path}: within {cf.within(e, f):+.2f} / pooled {cf.pooled(e, f):+.2f}\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="cmd", required=True)
    cf.collect_arguments(
        sub.add_parser("collect", help="confidence_features.py's collect, with the refit and softer-weight columns")
    )
    t = sub.add_parser("table", help="within / pooled Spearman of each feature and formula, a column a CSV")
    t.add_argument("csv", nargs="+")
    g = sub.add_parser("ceiling", help="a linear mix of every feature fitted on the first CSV, read on each")
    g.add_argument("csv", nargs="+")
    args = parser.parse_args()
    if args.cmd == "collect":
        runner.complete = _keep_args
        cf._row = _row
        cf.collect(args)
    elif args.cmd == "table":
        table(args.csv)
    else:
        ceiling(args.csv)


if __name__ == "__main__":
    main()
