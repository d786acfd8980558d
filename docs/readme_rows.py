"""Print README table rows from evaluation results folders (``instances.csv`` of ``symfruit evaluate``).

Cells: mean IoU / mean centre error (mm) / worst view (mm) / views off by more than 10 mm / views whose IoU
is below the raw box's (``--cells sizes``: depth side / larger lateral side, mean absolute error in mm and, in
brackets, the mean signed error).

    python docs/readme_rows.py LABEL=RESULTS/latest ...              # one row per folder
    python docs/readme_rows.py --by fruit RESULTS/latest             # one row per fruit, then the groups
    python docs/readme_rows.py --by occlusion RESULTS/latest         # one row per occlusion level
    python docs/readme_rows.py --by level RESULTS/latest             # per level: the 7 proxies, each other kind
    python docs/readme_rows.py --confidence LABEL=RESULTS/latest ...  # the confidence table of evidence

``--confidence`` cells: pooled Spearman of confidence against centre error / mean within-fruit Spearman (each
generated fruit's or scan's views ranked among themselves; what a robot choosing between views of one fruit
needs), mean error of all views, of the 80 % most confident, share flagged reliable, mean error of the
reliable / unreliable views, views off by more than 10 mm that were flagged unreliable.
"""

import argparse
import csv
import sys
from collections import defaultdict

import numpy as np

METHODS = ("raw", "sphere", "ellipsoid", "superellipsoid", "paper", "fused", "evidence")
PROXIES = ("strawberry", "apple", "citrus", "lemon", "peach", "pear", "plum")


def key(r):
    return (r["fruit"], r["fruit_index"], r["pose"], r["occlusion"])


def label(r):
    return r["kind"] if r["kind"].startswith("scan/") else r["fruit"]


def cells(rows, methods, kind):
    raw = {key(r): float(r["iou"]) for r in rows if r["method"] == "raw" and not r["error"]}
    out = []
    for m in methods:
        mine = [r for r in rows if r["method"] == m]
        ok = [r for r in mine if not r["error"]]
        failed = len(mine) - len(ok)
        if not ok:
            out.append("-")
            continue
        if kind == "sizes":
            dz = np.array([float(r["depth_mm"]) for r in ok])
            dl = np.array([float(r["lateral_mm"]) for r in ok])
            cell = f"{np.abs(dz).mean():.1f} ({dz.mean():+.1f}) / {np.abs(dl).mean():.1f} ({dl.mean():+.1f})"
        else:
            iou = np.array([float(r["iou"]) for r in ok])
            dev = np.array([float(r["centre_mm"]) for r in ok])
            below = sum(m != "raw" and float(r["iou"]) < raw.get(key(r), -1) - 1e-9 for r in ok)
            cell = f"{iou.mean():.3f} / {dev.mean():.2f} / {dev.max():.0f} / {(dev > 10).sum()} / {below}"
        out.append(cell + (f" ({failed} failed)" if failed else ""))
    return out


def row(name, rows, methods, kind):
    n = len({key(r) for r in rows})
    return f"| {name} | {n} | " + " | ".join(cells(rows, methods, kind)) + " |\n"


def confidence_row(name, rows, method="evidence"):
    from scipy.stats import spearmanr

    ok = [r for r in rows if r["method"] == method and not r["error"] and r["confidence"] not in ("", "nan")]
    conf = np.array([float(r["confidence"]) for r in ok])
    err = np.array([float(r["centre_mm"]) for r in ok])
    rel = np.array([r["reliable"] == "True" for r in ok])
    pooled = spearmanr(conf, err)[0]
    per = defaultdict(list)
    for i, r in enumerate(ok):
        per[(r["kind"], r["fruit_index"])].append(i)
    within = [spearmanr(conf[ix], err[ix])[0] for ix in per.values() if len(ix) >= 5 and np.ptp(conf[ix]) > 0]
    within = [w for w in within if np.isfinite(w)]
    top = err[np.argsort(-conf, kind="stable")[: max(1, round(0.8 * len(err)))]]
    mean = lambda a: f"{a.mean():.2f}" if len(a) else "-"  # noqa: E731
    big = err > 10
    cells = [f"{pooled:+.2f}", f"{np.mean(within):+.2f} ({len(within)})" if within else "-", f"{err.mean():.2f}",
             f"{top.mean():.2f}", f"{rel.mean():.0%}", f"{mean(err[rel])} / {mean(err[~rel])}",
             f"{(big & ~rel).sum()}/{big.sum()}"]  # fmt: skip
    return f"| {name} | {len(ok)} | " + " | ".join(cells) + " |\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folders", nargs="+", help="LABEL=FOLDER (one row each) or FOLDER (with --by)")
    parser.add_argument("--by", choices=("fruit", "occlusion", "level"),
                        help="one row per fruit, per occlusion level, or per level and group (the 7 proxies, then "
                        "each other kind)")  # fmt: skip
    parser.add_argument("--methods", default=",".join(METHODS))
    parser.add_argument("--cells", choices=("scores", "sizes"), default="scores")
    parser.add_argument("--confidence", action="store_true", help="the confidence table of evidence")
    args = parser.parse_args()
    methods = [m for m in args.methods.split(",") if m]
    for arg in args.folders:
        name, folder = arg.split("=", 1) if "=" in arg else ("", arg)
        with open(f"{folder}/instances.csv") as handle:
            rows = [r for r in csv.DictReader(handle) if r["method"] in methods]
        if args.confidence:
            sys.stdout.write(confidence_row(name, rows))
            continue
        if args.by is None:
            sys.stdout.write(row(name, rows, methods, args.cells))
            continue
        groups = defaultdict(list)
        if args.by == "level":  # README's "Camera views with a leaf in front"
            for r in rows:
                kind = "7 held-back proxies" if r["fruit"] in PROXIES else label(r)
                groups[f"{float(r['occlusion']):.0%}, {kind}"].append(r)
            for g in sorted(groups, key=lambda k: (float(k.split("%")[0]), "proxies" not in k, k)):
                sys.stdout.write(row(g.replace("%", " %", 1), groups[g], methods, args.cells))
            continue
        for r in rows:
            groups[label(r) if args.by == "fruit" else f"{float(r['occlusion']):.0%}"].append(r)
        for g in sorted(groups, key=lambda k: (k.startswith("scan/"), k)):
            sys.stdout.write(row(g, groups[g], methods, args.cells))
        if args.by == "fruit" and len(groups) > 1 and not any(g.startswith("scan/") for g in groups):
            sys.stdout.write(
                row("**7 held-back proxies**", [r for r in rows if r["fruit"] in PROXIES], methods, args.cells)
            )
            if "banana" in groups:
                sys.stdout.write(
                    row("**all but banana**", [r for r in rows if r["fruit"] != "banana"], methods, args.cells)
                )
            sys.stdout.write(row(f"**all {len(groups)} kinds**", rows, methods, args.cells))


if __name__ == "__main__":
    main()
