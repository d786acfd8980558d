"""Candidate confidence features of `evidence`, ranked against the centre error (docs/ablation.md, "Within-fruit
confidence: what no shape explains of the seen depths"): ``collect`` runs the evaluation's own instances
(`symfruit evaluate`'s protocol, sensor, poses, views and seed, the same extraction, the default settings as
``--no-profile``) and writes one CSV row a view of what `evidence` computed on it; ``table`` reads such CSVs and
prints the section's two tables, one column a CSV.

    python docs/confidence_features.py collect OUT.csv --fruit examples/scans --n 190 --pose hanging
                                       [--protocol camera] [--sensor heldback] [--seed 0] [--views 1]
    python docs/confidence_features.py table A.csv [B.csv ...]

(from the repository's root, as ``--fruit examples/scans`` is a path). A row holds the view's fruit (``fruit_id``,
the kind and the fruit's index: its views are ranked among themselves), its centre error (mm), `evidence`'s
confidence, uncertainty and reliable flag, the terms of the uncertainty (``combined_u``, ``moved``, ``recede``,
``elongation``, ``unexplained``), and what the candidate features are made of: the best closed shape's and the
`cone` ellipsoid's robust RMS depth misfit, the points' small-scale noise (``core.fits.surface_noise`` on the sample
`evidence` fits, as it measures it), the prior's share ``p`` of the back face and the shapes' back-face deviation
``fit_sd`` (as ``fuse_depth`` weighs them), the posterior back face's deviation, the box's front and back, the
deepest seen point, the 2nd-98th percentile range of the seen depths, the silhouette's width and its major and minor
widths (metres at the box's distance), the `cone` weight and each candidate's back face. Lengths in metres.

``table`` prints, a column a CSV, the single features' Spearman of the feature (larger: less confident) against
the centre error, mean within each fruit of at least 5 views / pooled; then the formulas' within / pooled Spearman
and the share flagged reliable (uncertainty at most ``reliable_uncertainty``), "-" for within where no fruit has 5
views. The formulas are computed from the collected terms, so the default's row is the uncertainty without the
``unexplained`` term (``unexplained_scale`` 0) and the built row is the default's own uncertainty (the difference
is printed below the tables); last, each CSV's median ratio of the best closed shape's depth RMS to the noise, and
its median ``recede``.
"""

import argparse
import csv
import sys
from collections.abc import Callable

import numpy as np
from scipy.stats import spearmanr

import symfruit.methods.evidence as evidence
from symfruit.core.fits import surface_noise
from symfruit.evaluate import runner
from symfruit.evaluate.protocols import FRUITS, specs
from symfruit.io.atomic import atomic_write
from symfruit.settings import Settings

CLOSED = ("cone", "revolution", "outline")
BACKS = (*CLOSED, "raw")


def collect(args: argparse.Namespace) -> None:
    caught: dict = {}
    complete = runner.complete
    fuse_depth, observe = evidence.fuse_depth, evidence.observe

    def keep_result(*a, **kw):
        caught["result"] = complete(*a, **kw)
        return caught["result"]

    def keep_fusion(combined, cands, region, camera, **kw):
        caught["fused"] = fuse_depth(combined, cands, region, camera, **kw)
        caught.update(combined=combined, cands=cands, fuse=kw)
        return caught["fused"]

    def keep_observed(*a, **kw):  # evidence's (sample, region, camera, ..., dense=points)
        caught.update(sample=a[0], points=kw["dense"])
        return observe(*a, **kw)

    runner.complete = keep_result
    evidence.fuse_depth, evidence.observe = keep_fusion, keep_observed
    settings = Settings()
    fruits = list(FRUITS) if args.fruit == "all" else args.fruit.split(",")
    todo = [spec for fruit in fruits for spec in specs(args.protocol, fruit, n=args.n, seed=args.seed,
                                                        sensor=args.sensor, poses=args.pose,
                                                        views=args.views)]  # fmt: skip
    rows = []
    for k, spec in enumerate(todo):
        caught.clear()
        row = runner._evaluate_instance(spec, ["evidence"], settings)[0]
        if row.error or "fused" not in caught:
            sys.stderr.write(f"view {k} ({row.kind}): {row.error or 'no fusion'}; left out\n")
            continue
        rows.append(_row(spec, row, caught))
        if len(rows) % 50 == 0:
            sys.stderr.write(f"{len(rows)} of {len(todo)} views\n")
    if not rows:
        raise SystemExit("no view completed")
    with atomic_write(args.out, "w") as f:
        out = csv.DictWriter(f, fieldnames=list(rows[0]))
        out.writeheader()
        out.writerows(rows)
    sys.stderr.write(f"{len(rows)} views: {args.out}\n")


def _row(spec, row, caught: dict) -> dict:
    e, box = caught["result"].extras, caught["result"].box
    combined, cands, kw = caught["combined"], caught["cands"], caught["fuse"]
    s = kw["s"]
    _, back_sd, width = caught["fused"]
    # the prior's share of the back face, as fuse_depth weighs the shapes' back face against the prior
    weights = np.array([combined.weights[c.name] for c in cands])
    backs = np.array([c.hi[2] for c in cands])
    spread = float((weights * np.abs(backs - combined.box.max[2])).sum())
    back_std = next((c.back_std for c in cands if c.name == "cone" and np.isfinite(c.back_std)), 0.0)
    model = width * (s.shape_error + s.rim_error * (1.0 - kw["rim"]))
    fit_sd = float(np.sqrt((s.back_inflation * back_std) ** 2 + (0.5 * spread) ** 2 + model**2))
    prior_sd = s.depth_ratio_sd * width / max(combined.contour, 0.25)
    p = 1.0 / prior_sd**2 / (1.0 / fit_sd**2 + 1.0 / prior_sd**2) if s.depth_ratio_sd > 0 and width > 0 else 0.0
    across = kw["across"]
    distance = 0.5 * float(box.min[2] + box.max[2]) / across.axis[2]
    _, noise, _ = surface_noise(caught["sample"], queries=s.noise_queries)
    z = caught["points"][:, 2]
    by_name = {c.name: c for c in cands}
    rms = [c.agreement.depth for c in cands if c.agreement is not None]
    cone = by_name.get("cone")
    out = dict(
        fruit=spec.fruit, kind=row.kind, fruit_index=spec.index, fruit_id=f"{row.kind}#{spec.index}", pose=spec.pose,
        centre_mm=row.centre_mm, confidence=e["confidence"], uncertainty=e["uncertainty"], reliable=int(e["reliable"]),
        combined_u=combined.uncertainty, moved=0.5 * abs(float(box.max[2] - combined.box.max[2])), recede=e["recede"],
        elongation=e["elongation"], unexplained=e["unexplained"], best_rms=min(rms) if rms else np.nan,
        cone_rms=cone.agreement.depth if cone is not None and cone.agreement is not None else np.nan, noise=noise,
        p=p, fit_sd=fit_sd, back_sd=back_sd, width=width, contour=combined.contour, front=float(box.min[2]),
        back=float(box.max[2]), seen_back=float(kw["seen_back"]),
        depth_range=float(np.percentile(z, 98) - np.percentile(z, 2)), major=across.major * distance,
        minor=across.minor * distance, cone_w=combined.weights.get("cone", 0.0),
    )  # fmt: skip
    for name in BACKS:
        out[f"{name}_back"] = float(by_name[name].hi[2]) if name in by_name else np.nan
    return out


Columns = dict[str, np.ndarray]


def load(path: str) -> Columns:
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise SystemExit(f"{path}: no views")
    cols: Columns = {}
    for key in rows[0]:
        values = [r[key] for r in rows]
        try:
            cols[key] = np.array([float(v) for v in values])
        except ValueError:
            cols[key] = np.array(values)
    return cols


def within(d: Columns, f: np.ndarray) -> float:
    """Mean over fruits of at least 5 views of the Spearman of ``-f`` (the confidence) against the error."""
    found = []
    for fruit in dict.fromkeys(d["fruit_id"]):
        ix = d["fruit_id"] == fruit
        if ix.sum() >= 5 and np.ptp(f[ix]) > 0:
            r = spearmanr(-f[ix], d["centre_mm"][ix])[0]
            if np.isfinite(r):
                found.append(r)
    return float(np.mean(found)) if found else float("nan")


def pooled(d: Columns, f: np.ndarray) -> float:
    return float(spearmanr(-f, d["centre_mm"], nan_policy="omit")[0])


def unexplained(d: Columns, rms: np.ndarray, misfit_noise: float = 2.0) -> np.ndarray:
    return np.sqrt(np.maximum(0.0, np.nan_to_num(rms) ** 2 - (misfit_noise * d["noise"]) ** 2))


def ambiguity(d: Columns, k: float = 1.6) -> np.ndarray:
    """A fruit of aspect up to ``k`` whose outline has aspect ``e`` is 1 to sqrt(k^2 + 1 - e^2) minor widths deep."""
    e = d["major"] / d["minor"]
    return d["minor"] * (np.sqrt(np.maximum(k**2 + 1 - e**2, 1.0)) - 1)


def robust_recede(d: Columns) -> np.ndarray:
    return d["contour"] * np.maximum(0.0, d["depth_range"] - 0.5 * d["width"])


def backs_range(d: Columns, names: tuple[str, ...]) -> np.ndarray:
    backs = np.vstack([d[f"{n}_back"] for n in names])  # NaN: not fitted on that view
    return np.nan_to_num(np.fmax.reduce(backs, axis=0) - np.fmin.reduce(backs, axis=0))


FEATURES: list[tuple[str, Callable[[Columns], np.ndarray]]] = [
    ("`unexplained` (best closed shape's depth RMS beyond 2 x noise)", lambda d: unexplained(d, d["best_rms"])),
    ("the best closed shape's depth RMS", lambda d: np.nan_to_num(d["best_rms"])),
    ("the points' small-scale noise", lambda d: d["noise"]),
    ("the prior's share of the back face `p`", lambda d: d["p"]),
    ("the back's sensitivity to the prior's ratio, `p x 0.15 x width`", lambda d: d["p"] * 0.15 * d["width"]),
    ("extrapolated depth in the shapes' own deviations, `(back - deepest seen) / fit_sd`",
     lambda d: (d["back"] - d["seen_back"]) / d["fit_sd"]),
    ("unweighted range of the closed shapes' back faces", lambda d: backs_range(d, CLOSED)),
    ("range of every candidate's back face, the raw box's too", lambda d: backs_range(d, BACKS)),
    ("the `cone` ellipsoid's weight", lambda d: np.nan_to_num(d["cone_w"])),
    ("robust seen depth range over width (2nd-98th percentile)", lambda d: d["depth_range"] / d["width"]),
    ("the box's depth over the silhouette's width", lambda d: (d["back"] - d["front"]) / d["width"]),
    ("orientation ambiguity `minor (sqrt(1.6^2 + 1 - e^2) - 1)`, `e` = major / minor", ambiguity),
]  # fmt: skip


def formulas() -> list[tuple[str, Callable[[Columns], np.ndarray]]]:
    s = Settings().evidence

    def U(d: Columns, extra=0.0, recede_scale: float = s.recede_scale) -> np.ndarray:
        """The default's uncertainty without ``unexplained``, one more term under the square root."""
        return d["elongation"] * np.sqrt(d["combined_u"] ** 2 + d["moved"] ** 2 + (recede_scale * d["recede"]) ** 2
                                         + np.asarray(extra) ** 2)  # fmt: skip

    return [
        ("the default (`u`)", U),
        ("`recede_scale` 0.2", lambda d: U(d, recede_scale=0.2)),
        ("`U(0.2 x robust recede)` (the 2nd-98th percentile depth range less half the width, times the contour "
         "share)", lambda d: U(d, 0.2 * robust_recede(d))),
        ("robust recede x 0.3 in place of `recede`, and 2 x noise",
         lambda d: U(d, np.hypot(0.3 * robust_recede(d), 2 * d["noise"]), recede_scale=0.0)),
        ("`u x (1 + p)`", lambda d: U(d) * (1 + d["p"])),
        ("`u x (1 + 2 p)`", lambda d: U(d) * (1 + 2 * d["p"])),
        ("`U(2 p x 0.15 x width)`", lambda d: U(d, 2 * d["p"] * 0.15 * d["width"])),
        ("`U(0.5 fit_sd)` (the shapes' back-face deviation in `fuse_depth`)", lambda d: U(d, 0.5 * d["fit_sd"])),
        ("`U(back_sd)` (the fused back face's deviation)", lambda d: U(d, d["back_sd"])),
        ("`U(0.1 x orientation ambiguity, k 1.6)`", lambda d: U(d, 0.1 * ambiguity(d))),
        ("`U(the cone fit's depth RMS)`, no noise floor", lambda d: U(d, np.nan_to_num(d["cone_rms"]))),
        ("`U(the cone fit's RMS beyond 2 x noise)`", lambda d: U(d, unexplained(d, d["cone_rms"]))),
        ("`U(unexplained)`, `misfit_noise` 1.5", lambda d: U(d, unexplained(d, d["best_rms"], 1.5))),
        ("`U(unexplained)`, `misfit_noise` 3", lambda d: U(d, unexplained(d, d["best_rms"], 3.0))),
        ("**`U(unexplained)`, `misfit_noise` 2: built**",
         lambda d: U(d, s.unexplained_scale * unexplained(d, d["best_rms"], s.misfit_noise))),
    ]  # fmt: skip


def _num(x: float) -> str:
    return "-" if not np.isfinite(x) else f"{x:+.2f}"


def table(args: argparse.Namespace) -> None:
    data = [load(path) for path in args.csv]
    head = "| {} | " + " | ".join(args.csv) + " |"
    rule = "|---" * (len(data) + 1) + "|"
    out = sys.stdout
    out.write(head.format("feature (larger: less confident); within / pooled Spearman") + "\n" + rule + "\n")
    for name, f in FEATURES:
        cells = []
        for d in data:
            x = np.asarray(f(d), float)
            cells.append(f"{_num(within(d, x))} / {_num(pooled(d, x))}")
        out.write(f"| {name} | " + " | ".join(cells) + " |\n")
    reliable_at = Settings().evidence.reliable_uncertainty
    out.write("\n" + head.format("formula; within / pooled Spearman / reliable") + "\n" + rule + "\n")
    for name, f in formulas():
        cells = []
        for d in data:
            u = np.asarray(f(d), float)
            cells.append(f"{_num(within(d, u))} / {_num(pooled(d, u))} / {(u <= reliable_at).mean():.0%}")
        out.write(f"| {name} | " + " | ".join(cells) + " |\n")
    # the built row, recomputed from the terms, is the default's own uncertainty as collected
    built = formulas()[-1][1]
    gap = max(float(np.max(np.abs(built(d) - d["uncertainty"]))) for d in data)
    out.write(f"\nthe built row against the collected uncertainty: largest difference {1000 * gap:.2g} mm\n")
    out.write("\non the median view: the best closed shape's depth RMS over the points' small-scale noise; `recede`\n")
    for path, d in zip(args.csv, data, strict=True):
        ratio = float(np.nanmedian(d["best_rms"] / d["noise"]))
        out.write(f"{path}: {ratio:.2f}; {1000 * float(np.median(d['recede'])):.1f} mm\n")


def collect_arguments(c: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """The ``collect`` command's arguments (docs/conf42.py's ``collect`` takes the same)."""
    c.add_argument("out", help="the CSV to write")
    c.add_argument("--protocol", default="camera", choices=("camera", "paper"))
    c.add_argument("--fruit", default="examples/scans", help="a scan folder, generated kinds (comma-separated) or all")
    c.add_argument("--n", type=int, default=190)
    c.add_argument("--pose", default="hanging")
    c.add_argument("--sensor", default="heldback")
    c.add_argument("--seed", type=int, default=0)
    c.add_argument("--views", type=int, default=1, help="views a generated fruit")
    return c


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="cmd", required=True)
    collect_arguments(
        sub.add_parser("collect", help="run the evaluation's instances, write a CSV of per-view quantities")
    )
    t = sub.add_parser("table", help="print the feature and formula tables from collected CSVs")
    t.add_argument("csv", nargs="+")
    args = parser.parse_args()
    collect(args) if args.cmd == "collect" else table(args)


if __name__ == "__main__":
    main()
