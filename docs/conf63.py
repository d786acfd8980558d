"""Within-fruit confidence of `evidence` on generated fruit and the shared scans (docs/conf63.md, issue 18 item 3):
``collect`` is docs/conf48.py's collection (the evaluation's own instances, `evidence` with the defaults, the
render's truth; ``--renoise`` another draw of the sensor's depth noise) with more columns a view: the uncertainty's
``cut`` and ``lateral`` terms, the dense points' and fitted sample's counts, and ``core.raster.axis_tilt``'s reading of
the front (its sag over a round section's ``tilt_cap``, the midline's slope, and their jackknife deviations over 6
sectors; off in `evidence` by default, read here only). ``table`` prints the within-fruit /
pooled Spearman of the issue's per-view quantities (larger: less confident) and of candidate formulas, a column a
CSV; ``parts`` splits a feature's within-fruit ranking into the error's pose part and noise part (two noise draws of
the same views); ``weights`` refits the scales of `u`'s own terms within fruit; ``ceiling`` fits within-fruit least
squares of the log error on logs of quantities without the box's size, every subset of up to three with `u`.

    python docs/conf63.py collect OUT.csv [confidence_features.py collect's options] [--renoise]
    python docs/conf63.py table A.csv [B.csv ...]
    python docs/conf63.py parts A.csv RENOISED.csv
    python docs/conf63.py weights --train A.csv [...] --test B.csv [...]
    python docs/conf63.py ceiling --train A.csv [...] --test B.csv [...]
"""

import argparse
import itertools
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import conf45
import conf48
import confidence_features as cf

from symfruit.core.raster import axis_tilt

ROW48 = conf48._row
Columns = cf.Columns


def _row(spec, row, caught: dict) -> dict:
    e = caught["result"].extras
    n_points, n_sample = len(caught["points"]), len(caught["sample"])
    # the front's tilt and sag (off in `evidence` by default: read here, nothing of the box depends on it)
    tilt = axis_tilt(caught["sample"], conf45.EXTRA["seen_region"], conf45.EXTRA["camera"], caught["fuse"]["across"],
                     blocks=6)  # fmt: skip
    out = ROW48(spec, row, caught)
    out.update(cut=float(e["cut"]), lateral=float(e["lateral"]), n_points=n_points, n_sample=n_sample,
               tilt_cap=tilt.cap, tilt_slope=float(np.hypot(tilt.slope_major, tilt.slope_minor)),
               tilt_slope_major=tilt.slope_major, tilt_cap_sd=tilt.cap_sd, tilt_slope_sd=tilt.slope_sd,
               tilt_count=tilt.count)  # fmt: skip
    return out


def collect(args: argparse.Namespace) -> None:
    conf48._install(args.renoise)
    conf45._row = _row  # conf45.collect hands it to confidence_features; it calls conf48's and conf45's rows
    conf45.collect(args)


def load(path: str) -> Columns:
    d = conf48.load(path)
    d["seen_depth"] = d["seen_back"] - d["front"]
    d["ratio_seen"] = d["seen_depth"] / d["width"]  # seen depth over the silhouette's width
    d["ratio_box"] = d["box_depth"] / d["width"]
    d["prior_sd"] = 0.15 * d["width"] / np.maximum(d["contour"], 0.25)  # the depth prior's spread, as fuse_depth's
    d["uncut"] = 1.0 - d["contour"]  # the outline's cut share
    d["inv_points"] = 1.0 / d["n_points"]
    d["u_no_elongation"] = d["uncertainty"] / d["elongation"]
    return d


FEATURES = ("uncertainty", "u_no_elongation", "elongation", "combined_u", "moved", "recede", "unexplained",
            "lateral", "cut", "uncut", "cand_backsd", "cand_zsd", "spread", "back_std", "fit_sd", "p", "prior_sd",
            "inv_points", "distance_m", "noise", "ratio_seen", "ratio_box", "hidden_depth", "cone_w", "width",
            "box_depth", "tilt_cap", "tilt_slope", "tilt_cap_sd", "tilt_slope_sd")  # fmt: skip


def _cell(d: Columns, f: Callable[[Columns], np.ndarray]) -> str:
    try:
        x = f(d)
    except KeyError:  # a column a CSV collected before it was added does not hold
        return "-"
    return f"{cf._num(cf.within(d, x))} / {cf._num(cf.pooled(d, x))}"


def _cells(data: dict[str, Columns], f: Callable[[Columns], np.ndarray]) -> str:
    return " | ".join(_cell(d, f) for d in data.values())


def _head(data: dict[str, Columns], first: str) -> str:
    names = [Path(p).stem for p in data]
    return f"| {first} | " + " | ".join(names) + " |\n" + "|---" * (len(names) + 1) + "|\n"


def _scaled(name: str, a: float) -> Callable[[Columns], np.ndarray]:
    return lambda d: d["uncertainty"] * np.maximum(d[name], 1e-4) ** a


def _plus(name: str, k: float) -> Callable[[Columns], np.ndarray]:
    return lambda d: np.hypot(d["uncertainty"], k * d["elongation"] * d[name])


FORMULAS: dict[str, Callable[[Columns], np.ndarray]] = {
    "`u` (the base)": lambda d: d["uncertainty"],
    "`u` without the elongation factor": lambda d: d["u_no_elongation"],
    "`u` x points^-0.25": _scaled("inv_points", 0.25),
    "`u` x distance^0.5": _scaled("distance_m", 0.5),
    "`u` x (seen depth / width)^0.25": _scaled("ratio_seen", 0.25),
    "`u` x p^0.5": _scaled("p", 0.5),
    "`u` x cone weight^0.25": _scaled("cone_w", 0.25),
    "+ 2 `noise`": _plus("noise", 2.0),
    "+ `cand_backsd`": _plus("cand_backsd", 1.0),
    "+ 0.1 `prior_sd`": _plus("prior_sd", 0.1),
    "`u` x (1 + 0.5 cone weight)": lambda d: d["uncertainty"] * (1 + 0.5 * d["cone_w"]),
    "`u` x (1 + 2 cap_sd)": lambda d: d["uncertainty"] * (1 + 2 * d["tilt_cap_sd"]),
    "+ 0.6 cap_sd x width": lambda d: np.hypot(d["uncertainty"], 0.6 * d["elongation"] * d["tilt_cap_sd"] * d["width"]),
    "+ 0.0025 (distance / 0.3 m)^2 (the sensor's axial noise)": lambda d: np.hypot(
        d["uncertainty"], 0.0025 * (d["distance_m"] / 0.3) ** 2
    ),
}


def table(paths: list[str]) -> None:
    data = {p: load(p) for p in paths}
    w = sys.stdout.write
    w(_head(data, "feature; within / pooled"))
    for name in FEATURES:
        w(f"| {name} | {_cells(data, lambda d, n=name: d[n])} |\n")
    w("\n" + _head(data, "formula; within / pooled"))
    for label, f in FORMULAS.items():
        w(f"| {label} | {_cells(data, f)} |\n")


def parts(a_path: str, b_path: str) -> None:
    """Each feature's within-fruit Spearman against the error's pose part (the absolute mean of the two draws' signed
    depth errors) and noise part (their absolute difference), and the noise draw's own difference as a feature."""
    a, b = load(a_path), load(b_path)
    ib = {k: i for i, k in enumerate(b["key"])}
    j = np.array([ib[k] for k in a["key"]])  # the same views, by fruit and view number
    b = {k: v[j] for k, v in b.items()}
    pose = np.abs(0.5 * (a["dz_mm"] + b["dz_mm"]))
    noise = np.abs(a["dz_mm"] - b["dz_mm"])
    w = sys.stdout.write
    w("| feature | own error | pose part | noise part |\n|---|---|---|---|\n")
    for name in (n for n in FEATURES if n in a):
        x = a[name]
        w(f"| {name} | {conf48._within(a, x):+.2f} | {conf48._within(a, x, pose):+.2f} | "
          f"{conf48._within(a, x, noise):+.2f} |\n")  # fmt: skip
    u, s = a["uncertainty"], noise / 1000.0
    w(f"\nthe other draw's abs(dz A - dz B) as a feature of A (one parametric-bootstrap draw): within "
      f"{cf.within(a, s):+.2f}, pooled {cf.pooled(a, s):+.2f}; hypot(u, 2 x it): within "
      f"{cf.within(a, np.hypot(u, 2 * s)):+.2f}, pooled {cf.pooled(a, np.hypot(u, 2 * s)):+.2f} (u alone "
      f"{cf.within(a, u):+.2f} / {cf.pooled(a, u):+.2f})\n")  # fmt: skip


TERMS = {"combined_u": 1.0, "moved": 1.0, "recede": 0.1, "unexplained": 3.0, "cut": 0.1, "lateral": 0.5}


def _u(d: Columns, scales: dict[str, float], power: float) -> np.ndarray:
    """`evidence`'s ``u`` from the collected terms, each scaled, the elongation factor raised to ``power``."""
    return d["elongation"] ** power * np.sqrt(sum((k * d[t]) ** 2 for t, k in scales.items()))


def weights(train: list[str], test: list[str]) -> None:
    """Coordinate search of `u`'s term scales (x 0, 1/4, 1/2, 1, 2, 4 of the default) and the elongation's power
    (0-4) for the mean within-fruit Spearman on ``train``, the pooled Spearman kept within 0.01 of the base's."""
    data = {p: load(p) for p in (*train, *test)}
    for p, d in data.items():
        if not np.allclose(_u(d, TERMS, 1.0), d["uncertainty"], rtol=1e-6, atol=1e-9):
            raise SystemExit(f"{p}: u recomputed from its terms differs from the collected one")
    pooled0 = np.mean([cf.pooled(data[p], data[p]["uncertainty"]) for p in train])

    def score(scales: dict[str, float], power: float) -> float:
        if np.mean([cf.pooled(data[p], _u(data[p], scales, power)) for p in train]) > pooled0 + 0.01:
            return np.inf
        return float(np.mean([cf.within(data[p], _u(data[p], scales, power)) for p in train]))

    scales, power = dict(TERMS), 1.0
    for _ in range(3):
        for t in TERMS:
            tries = [{**scales, t: TERMS[t] * m} for m in (0, 0.25, 0.5, 1, 2, 4)]
            scales = min(tries, key=lambda s: score(s, power))
        power = min((0.0, 0.5, 1.0, 2.0, 4.0), key=lambda q: score(scales, q))
    w = sys.stdout.write
    w(f"found: {scales}, elongation power {power}\n" + _head(data, "scales; within / pooled"))
    w(f"| base | {_cells(data, lambda d: d['uncertainty'])} |\n")
    w(f"| found | {_cells(data, lambda d: _u(d, scales, power))} |\n")


NO_SIZE = ("combined_u", "moved", "unexplained", "p", "back_std", "noise", "distance_m", "n_points", "elongation",
           "cand_zsd", "cand_backsd", "lateral", "recede", "fit_sd", "cone_w", "spread", "ratio_seen",
           "ratio_box")  # fmt: skip


def _logs(d: Columns, names: tuple[str, ...]) -> np.ndarray:
    return np.log(np.maximum(np.abs(np.array([d[n] for n in names], float).T), 1e-5))


def ceiling(train: list[str], test: list[str]) -> None:
    """Within-fruit least squares of the log centre error on the logs of ``u`` and up to three of :data:`NO_SIZE`
    (quantities without the box's or the silhouette's size), fitted on ``train``; the 8 best there, read on all."""
    data = {p: load(p) for p in (*train, *test)}
    y = np.concatenate([conf48._demeaned(data[p], np.log(data[p]["centre_mm"])[:, None])[:, 0] for p in train])

    def fit(names: tuple[str, ...]) -> np.ndarray:
        x = np.vstack([conf48._demeaned(data[p], _logs(data[p], names)) for p in train])
        return np.linalg.lstsq(x, y, rcond=None)[0]

    found = []
    for k in (0, 1, 2, 3):
        for sub in itertools.combinations(NO_SIZE, k):
            names = ("uncertainty", *sub)
            c = fit(names)
            found.append((np.mean([cf.within(data[p], _logs(data[p], names) @ c) for p in train]), names, c))
    found.sort(key=lambda f: f[0])
    w = sys.stdout.write
    w(_head(data, "log mix; within / pooled"))
    for _, names, c in [*found[:8], next(f for f in found if len(f[1]) == 1)]:
        label = " ".join(f"{n} {x:+.2f}" for n, x in zip(names, c, strict=True))
        w(f"| {label} | {_cells(data, lambda d, n=names, c=c: _logs(d, n) @ c)} |\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="cmd", required=True)
    c = cf.collect_arguments(sub.add_parser("collect", help="conf48.py's collect, with more columns"))
    c.add_argument("--occlusion", default="0", help="leaf occlusion levels, comma-separated")
    c.add_argument("--renoise", action="store_true", help="another draw of the sensor's depth noise")
    t = sub.add_parser("table", help="within / pooled Spearman of features and formulas, a column a CSV")
    t.add_argument("csv", nargs="+")
    r = sub.add_parser("parts", help="features against the error's pose and noise parts (two noise draws)")
    r.add_argument("a")
    r.add_argument("b")
    for name, text in (("weights", "refit u's term scales within fruit"), ("ceiling", "within-fruit log mixes")):
        g = sub.add_parser(name, help=text)
        g.add_argument("--train", nargs="+", required=True)
        g.add_argument("--test", nargs="+", required=True)
    args = parser.parse_args()
    if args.cmd == "collect":
        collect(args)
    elif args.cmd == "table":
        table(args.csv)
    elif args.cmd == "parts":
        parts(args.a, args.b)
    elif args.cmd == "weights":
        weights(args.train, args.test)
    else:
        ceiling(args.train, args.test)


if __name__ == "__main__":
    main()
