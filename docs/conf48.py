"""Within-fruit confidence of `evidence` on generated fruit (docs/conf48.md): ``collect`` runs docs/conf45.py's
collection (the evaluation's own instances, `evidence` with the defaults) and adds, a view, the render's truth (the
signed centre error along the line of sight and across it, the true box's depth and width) and candidate
uncertainty features (the candidates' centres and back faces along the line of sight, their spread under the
combination's weights, the hidden depth behind the deepest seen point, the prior's pull); ``--renoise`` draws the
sensor's noise afresh (the same fruit, pose and distance), to measure how much of a view's centre error a second
noise draw repeats; ``table`` prints within / pooled Spearman of each feature and formula; ``kinds`` the
within-fruit Spearman of the confidence by kind with each fruit's error spread; ``repeat`` the within-fruit Spearman
between the errors of two collections of the same views (one noise draw against another).

    python docs/conf48.py collect OUT.csv [confidence_features.py collect's options] [--renoise]
    python docs/conf48.py table A.csv [B.csv ...]
    python docs/conf48.py kinds A.csv
    python docs/conf48.py repeat A.csv RENOISED.csv
    python docs/conf48.py among A.csv [B.csv ...] [--group K]
    python docs/conf48.py ceiling --train A.csv [A2.csv ...] --test B.csv [...]
"""

import argparse
import itertools
import sys
from pathlib import Path

import numpy as np
from scipy.stats import spearmanr

sys.path.insert(0, str(Path(__file__).resolve().parent))
import conf45
import confidence_features as cf

from symfruit.evaluate import protocols, runner
from symfruit.synthetic.render import SensorNoise

TRUTH: dict = {}
ROW45 = conf45._row
LOAD45 = conf45.load


def _install(renoise: bool) -> None:
    build, apply = protocols.build, SensorNoise.apply

    def keep_build(spec):
        inst = build(spec)
        TRUTH["box"] = inst.truth_box
        return inst

    def other_noise(self, rendering, rng):  # the same view, another draw of the sensor's noise
        return apply(self, rendering, np.random.default_rng([4848, int(rng.integers(2**31))]))

    runner.build = keep_build
    if renoise:
        SensorNoise.apply = other_noise  # type: ignore[method-assign]


def _row(spec, row, caught: dict) -> dict:
    combined, cands = caught["combined"], caught["cands"]
    box, truth = caught["result"].box, TRUTH["box"]
    out = ROW45(spec, row, caught)  # clears conf45's EXTRA
    out["pose_ix"] = spec.pose
    out["dz_mm"] = 1000 * float(box.centre[2] - truth.centre[2])
    out["dxy_mm"] = 1000 * float(np.hypot(*(box.centre[:2] - truth.centre[:2])))
    out["true_depth"] = float(truth.size[2])
    out["true_width"] = float(truth.size[:2].max())
    out["box_depth"] = float(box.size[2])
    w = np.array([combined.weights.get(c.name, 0.0) for c in cands])
    w = w / max(w.sum(), 1e-300)
    cz = np.array([float(c.centre[2]) for c in cands])
    backs = np.array([float(c.hi[2]) for c in cands])
    out["cand_zsd"] = float(np.sqrt((w * (cz - (w * cz).sum()) ** 2).sum()))
    out["cand_backsd"] = float(np.sqrt((w * (backs - (w * backs).sum()) ** 2).sum()))
    out["hidden_depth"] = float(box.max[2]) - out["seen_back"]
    out["fit_depth"] = float(combined.box.max[2] - combined.box.min[2])
    TRUTH.clear()
    return out


def collect(args: argparse.Namespace) -> None:
    _install(args.renoise)
    conf45._row = _row
    conf45.collect(args)


def load(path: str) -> cf.Columns:
    d = LOAD45(path)
    d["key"] = np.array([f"{a}/{b}" for a, b in zip(d["fruit_id"], d["pose_ix"], strict=True)])
    return d


def kinds(path: str) -> None:
    """The confidence's within-fruit Spearman by kind, and each kind's fruit's median error range (mm)."""
    d = load(path)
    u = d["uncertainty"]
    by: dict[str, list] = {}
    for fruit in dict.fromkeys(d["fruit_id"]):
        ix = d["fruit_id"] == fruit
        err = d["centre_mm"][ix]
        r = spearmanr(-u[ix], err)[0]
        rz = spearmanr(-u[ix], np.abs(d["dz_mm"][ix]))[0]
        by.setdefault(str(d["kind"][ix][0]), []).append((r, rz, np.ptp(err), np.median(err), np.std(d["dz_mm"][ix])))
    w = sys.stdout.write
    w("| kind | fruit | within (centre) | within (|dz|) | error range (mm) | median error | sd of dz within |\n")
    w("|---|---|---|---|---|---|---|\n")
    for k, v in by.items():
        a = np.array(v)
        w(f"| {k} | {len(a)} | {np.nanmean(a[:, 0]):+.2f} | {np.nanmean(a[:, 1]):+.2f} | {np.median(a[:, 2]):.2f} | "
          f"{np.median(a[:, 3]):.2f} | {np.median(a[:, 4]):.2f} |\n")  # fmt: skip


def _within(d: cf.Columns, f: np.ndarray, err: np.ndarray | None = None) -> float:
    """Mean over fruits of the within-fruit Spearman of ``-f`` (the confidence) against ``err`` (the centre error)."""
    err = d["centre_mm"] if err is None else err
    found = []
    for fruit in dict.fromkeys(d["fruit_id"]):
        ix = d["fruit_id"] == fruit
        if ix.sum() >= 5 and np.ptp(f[ix]) > 0:
            found.append(spearmanr(-f[ix], err[ix])[0])
    return float(np.nanmean(found))


def _paired(a_path: str, b_path: str) -> tuple[cf.Columns, cf.Columns]:
    a, b = load(a_path), load(b_path)
    ib = {k: i for i, k in enumerate(b["key"])}
    j = np.array([ib[k] for k in a["key"]])  # the same views, by fruit and view number
    return a, {k: v[j] for k, v in b.items()}


def repeat(a_path: str, b_path: str) -> None:
    """Two noise draws of the same views: how far a view's error repeats (within-fruit Spearman of the errors), the
    confidence of one draw against the other's error, the within-fruit variance of the signed depth error split into
    the pose's part (what both draws share) and the noise's, and features against the error's parts."""
    a, b = _paired(a_path, b_path)
    w = sys.stdout.write
    per_a, per_b, rep = [], [], []
    sys_var, noise_var = [], []
    for fruit in dict.fromkeys(a["fruit_id"]):
        ix = a["fruit_id"] == fruit
        rep.append(spearmanr(a["centre_mm"][ix], b["centre_mm"][ix])[0])
        per_a.append(spearmanr(-a["uncertainty"][ix], a["centre_mm"][ix])[0])
        per_b.append(spearmanr(-b["uncertainty"][ix], b["centre_mm"][ix])[0])
        m, h = 0.5 * (a["dz_mm"][ix] + b["dz_mm"][ix]), 0.5 * (a["dz_mm"][ix] - b["dz_mm"][ix])
        sys_var.append(np.var(m) - np.mean(h**2))
        noise_var.append(2 * np.mean(h**2))
    pa, pb = np.array(per_a), np.array(per_b)
    w(f"{a_path} / {b_path}: {len(pa)} fruit; confidence within {pa.mean():+.2f} / {pb.mean():+.2f} (per-fruit sd "
      f"{pa.std():.2f}, standard error {pa.std() / np.sqrt(len(pa)):.3f}; per fruit, one draw against the other "
      f"r = {np.corrcoef(pa, pb)[0, 1]:+.2f}); errors of the two draws within a fruit {np.nanmean(rep):+.2f}; "
      f"A's confidence against B's error {_within(a, a['uncertainty'], b['centre_mm']):+.2f}; mean |error A - "
      f"error B| {np.mean(np.abs(a['centre_mm'] - b['centre_mm'])):.2f} mm; within-fruit variance of the signed "
      f"depth error (mm^2): the pose's {np.mean(sys_var):.2f}, the noise's {np.mean(noise_var):.2f}\n")  # fmt: skip
    mean_err = 0.5 * (a["centre_mm"] + b["centre_mm"])
    noise_part = np.abs(a["dz_mm"] - b["dz_mm"])
    pose_dz = 0.5 * (a["dz_mm"] + b["dz_mm"])
    w("| feature | own error | mean error of the two draws | noise's part, abs(dz A - dz B) "
      "| pose's part, abs(mean dz) | signed: Spearman(feature, mean dz) |\n|---|---|---|---|---|---|\n")  # fmt: skip
    for name in ("uncertainty", "back_std", "combined_u", "unexplained", "p", "moved", "lat_dis", "distance_m",
                 "noise", "elongation", "recede", "spread", "cand_zsd", "hidden_depth", "width", "box_depth",
                 "true_depth"):  # fmt: skip
        x = a[name]
        signed = -_within(a, x, pose_dz)  # Spearman(feature, signed error): _within ranks -feature
        w(f"| {name} | {_within(a, x):+.2f} | {_within(a, x, mean_err):+.2f} | {_within(a, x, noise_part):+.2f} | "
          f"{_within(a, x, np.abs(pose_dz)):+.2f} | {signed:+.2f} |\n")  # fmt: skip


LOGS = ("uncertainty", "combined_u", "unexplained", "p", "back_std", "noise", "distance_m", "n_visible", "width",
        "elongation", "cand_zsd", "hidden_depth", "lat_dis", "fit_depth", "box_depth", "depth_range", "seen_depth",
        "front", "recede", "moved", "fit_sd", "cone_w", "spread")  # fmt: skip
SUBSET_POOL = ("combined_u", "unexplained", "p", "back_std", "distance_m", "n_visible", "width", "box_depth",
               "fit_depth", "lat_dis", "elongation", "moved", "noise", "cand_zsd")  # fmt: skip


def _logs(d: cf.Columns, names: tuple[str, ...]) -> np.ndarray:
    d = {**d, "seen_depth": d["seen_back"] - d["front"]}
    return np.log(np.maximum(np.abs(np.array([d[n] for n in names], float).T), 1e-5))


def _demeaned(d: cf.Columns, x: np.ndarray) -> np.ndarray:
    x = x.copy()
    for fruit in dict.fromkeys(d["fruit_id"]):
        ix = d["fruit_id"] == fruit
        x[ix] -= x[ix].mean(0)
    return x


def ceiling(train: list[str], test: list[str]) -> None:
    """Least squares of the log centre error on the logs of the features, each less its fruit's mean, fitted on
    ``train`` and read on every CSV as a within-fruit ranking: all of :data:`LOGS`, then the uncertainty with every
    subset of up to 3 of :data:`SUBSET_POOL`, the 8 best on ``train`` (chosen there, read on ``test``)."""
    data = {p: load(p) for p in (*train, *test)}
    y = np.concatenate([_demeaned(data[p], np.log(data[p]["centre_mm"])[:, None])[:, 0] for p in train])
    w = sys.stdout.write

    def fit(names: tuple[str, ...]) -> np.ndarray:
        x = np.vstack([_demeaned(data[p], _logs(data[p], names)) for p in train])
        return np.linalg.lstsq(x, y, rcond=None)[0]

    coef = fit(LOGS)
    w("all: " + ", ".join(f"{p} {_within(data[p], _logs(data[p], LOGS) @ coef):+.2f}" for p in data) + "\n")
    w("  coefficients: " + ", ".join(f"{n} {c:+.2f}" for n, c in zip(LOGS, coef, strict=True)) + "\n")
    found = []
    for k in (1, 2, 3):
        for sub in itertools.combinations(SUBSET_POOL, k):
            names = ("uncertainty", *sub)
            c = fit(names)
            score = np.mean([_within(data[p], _logs(data[p], names) @ c) for p in train])
            found.append((score, names, c))
    found.sort(key=lambda f: f[0])
    for score, names, c in found[:8]:
        cells = ", ".join(f"{p} {_within(data[p], _logs(data[p], names) @ c):+.2f}" for p in test)
        w(f"{score:+.3f} on train: {' '.join(f'{n} {x:+.2f}' for n, x in zip(names, c, strict=True))}; {cells}\n")


FEATURES = (*conf45.FEATURES, "cand_zsd", "cand_backsd", "hidden_depth", "dz_mm", "dxy_mm", "true_depth")


def among(paths: list[str], group: int = 0) -> None:
    """A confidence among one fruit's views (a multi-view use; not `evidence`'s per-view `u`): each view's `u` times
    the fruit's median box size over its own, size ``width^2 x box depth`` (or ``(width^3 x box depth)^0.5``): the
    fruit does not change size between views, and a view whose box comes out smaller than its others' is the
    under-extended one. Within / pooled Spearman, the share reliable at 3 mm and the views over 4 mm said reliable.
    ``group``: a fruit's views taken ``group`` at a time (views 0 to group - 1, ...), as fewer views of a fruit."""
    w = sys.stdout.write
    w("| size, power | " + " | ".join(paths) + " |\n" + "|---" * (len(paths) + 1) + "|\n")
    for label, size, k in (("base", None, 0.0), ("width^2 x box depth, 1", 2.0, 1.0),
                           ("(width^3 x box depth)^0.5, 1", 3.0, 0.5)):  # fmt: skip
        cells = []
        for p in paths:
            d = load(p)
            if group:
                d["fruit_id"] = np.array([f"{f}/{int(v) // group}" for f, v in zip(d["fruit_id"], d["pose_ix"],
                                                                                  strict=True)])  # fmt: skip
            u = d["uncertainty"].copy()
            if size is not None:
                s = (d["width"] ** size * d["box_depth"]) ** k
                rel = np.empty_like(u)
                for fruit in dict.fromkeys(d["fruit_id"]):
                    ix = d["fruit_id"] == fruit
                    rel[ix] = np.median(s[ix]) / s[ix]
                u = u * rel
            r = u <= 0.003
            cells.append(f"{_within(d, u):+.2f} / {cf.pooled(d, u):+.2f} / {r.mean():.0%} / "
                         f"{int((r & (d['centre_mm'] > 4)).sum())}")  # fmt: skip
        w(f"| {label} | " + " | ".join(cells) + " |\n")


def _u(d: cf.Columns, extra: float | np.ndarray = 0.0, us: float = 3.0) -> np.ndarray:
    """`evidence`'s uncertainty (stop 45's terms, docs/conf45.py's ``U``) with one more term under the root."""
    return np.sqrt(conf45.U(d, us=us, cut=0.1, lat=0.5) ** 2 + (d["elongation"] * np.asarray(extra)) ** 2)


def _at(t: float):
    return lambda d, u: u <= t


FORMULAS: dict = {
    "stop 45 (the base)": (lambda d: _u(d), _at(0.003)),
    "+ 2 back_std": (lambda d: _u(d, 2 * d["back_std"]), _at(0.003)),
    "+ 4 back_std": (lambda d: _u(d, 4 * d["back_std"]), _at(0.003)),
    "+ 2 noise": (lambda d: _u(d, 2 * d["noise"]), _at(0.003)),
    "+ 4 noise": (lambda d: _u(d, 4 * d["noise"]), _at(0.003)),
    "+ p x 0.15 x width": (lambda d: _u(d, d["p"] * 0.15 * d["width"]), _at(0.003)),
    "+ 2 p x 0.15 x width": (lambda d: _u(d, 2 * d["p"] * 0.15 * d["width"]), _at(0.003)),
    "+ 0.5 fit_sd": (lambda d: _u(d, 0.5 * d["fit_sd"]), _at(0.003)),
    "+ back_sd": (lambda d: _u(d, d["back_sd"]), _at(0.003)),
    "+ cand_zsd": (lambda d: _u(d, d["cand_zsd"]), _at(0.003)),
    "+ 2 cand_zsd": (lambda d: _u(d, 2 * d["cand_zsd"]), _at(0.003)),
    "+ 0.1 hidden_depth": (lambda d: _u(d, 0.1 * d["hidden_depth"]), _at(0.003)),
    "+ 0.5 abs(fit depth - width)": (lambda d: _u(d, 0.5 * np.abs(d["fit_depth"] - d["width"])), _at(0.003)),
    "+ 0.5 abs(gap)": (lambda d: _u(d, 0.5 * np.abs(d["gap"])), _at(0.003)),
    "unexplained_scale 5": (lambda d: _u(d, us=5.0), _at(0.003)),
    "x (0.06 m / width)^0.5": (lambda d: _u(d) * (0.06 / d["width"]) ** 0.5, _at(0.003)),
    "/ (width x box depth) (size)": (lambda d: _u(d) / (d["width"] * d["box_depth"]), lambda d, u: u < 0),
    "/ (width^2 x box depth) (size)": (lambda d: _u(d) / (d["width"] ** 2 * d["box_depth"]), lambda d, u: u < 0),
    "/ (width^3 x box depth)^0.5 (size)": (lambda d: _u(d) / (d["width"] ** 3 * d["box_depth"]) ** 0.5,
                                           lambda d, u: u < 0),
}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="cmd", required=True)
    c = cf.collect_arguments(sub.add_parser("collect", help="conf45.py's collect, with the truth and more columns"))
    c.add_argument("--occlusion", default="0", help="leaf occlusion levels, comma-separated")
    c.add_argument("--renoise", action="store_true", help="another draw of the sensor's depth noise")
    t = sub.add_parser("table", help="within / pooled Spearman of each feature and formula, a column a CSV")
    t.add_argument("csv", nargs="+")
    k = sub.add_parser("kinds", help="the confidence's within-fruit Spearman by kind")
    k.add_argument("csv")
    r = sub.add_parser("repeat", help="within-fruit Spearman of the errors of two noise draws")
    r.add_argument("a")
    r.add_argument("b")
    m = sub.add_parser("among", help="u times the fruit's median box size over the view's")
    m.add_argument("csv", nargs="+")
    m.add_argument("--group", type=int, default=0, help="a fruit's views this many at a time (0: all)")
    g = sub.add_parser("ceiling", help="least squares of the log error on logs of features, within fruit")
    g.add_argument("--train", nargs="+", required=True)
    g.add_argument("--test", nargs="+", required=True)
    args = parser.parse_args()
    if args.cmd == "collect":
        collect(args)
    elif args.cmd == "kinds":
        kinds(args.csv)
    elif args.cmd == "repeat":
        repeat(args.a, args.b)
    elif args.cmd == "among":
        among(args.csv, args.group)
    elif args.cmd == "ceiling":
        ceiling(args.train, args.test)
    else:
        conf45.FEATURES = FEATURES
        conf45.load = load
        conf45.table(args.csv, FORMULAS)


if __name__ == "__main__":
    main()
