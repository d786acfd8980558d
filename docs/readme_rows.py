"""Print README table rows from evaluation results folders (``instances.csv`` of ``symfruit evaluate``).

Cells: mean IoU / mean centre error (mm) / worst view (mm) / views off by more than 10 mm / views whose IoU
is below the raw box's (``--cells sizes``: depth side / larger lateral side, mean absolute error in mm and, in
brackets, the mean signed error).

    python docs/readme_rows.py LABEL=RESULTS/latest ...              # one row per folder
    python docs/readme_rows.py --by fruit RESULTS/latest             # one row per fruit, then the groups
    python docs/readme_rows.py --by occlusion RESULTS/latest         # one row per occlusion level
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


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folders", nargs="+", help="LABEL=FOLDER (one row each) or FOLDER (with --by)")
    parser.add_argument("--by", choices=("fruit", "occlusion"), help="one row per fruit or occlusion level")
    parser.add_argument("--methods", default=",".join(METHODS))
    parser.add_argument("--cells", choices=("scores", "sizes"), default="scores")
    args = parser.parse_args()
    methods = [m for m in args.methods.split(",") if m]
    for arg in args.folders:
        name, folder = arg.split("=", 1) if "=" in arg else ("", arg)
        with open(f"{folder}/instances.csv") as handle:
            rows = [r for r in csv.DictReader(handle) if r["method"] in methods]
        if args.by is None:
            sys.stdout.write(row(name, rows, methods, args.cells))
            continue
        groups = defaultdict(list)
        for r in rows:
            groups[label(r) if args.by == "fruit" else f"{float(r['occlusion']):.0%}"].append(r)
        for g in sorted(groups, key=lambda k: (k.startswith("scan/"), k)):
            sys.stdout.write(row(g, groups[g], methods, args.cells))
        if args.by == "fruit" and len(groups) > 1 and not any(g.startswith("scan/") for g in groups):
            sys.stdout.write(row("**7 held-back proxies**", [r for r in rows if r["fruit"] in PROXIES], methods,
                                 args.cells))
            if "banana" in groups:
                sys.stdout.write(row("**all but banana**", [r for r in rows if r["fruit"] != "banana"], methods,
                                     args.cells))
            sys.stdout.write(row(f"**all {len(groups)} kinds**", rows, methods, args.cells))


if __name__ == "__main__":
    main()
