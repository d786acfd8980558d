"""Print README rows (cells: mean IoU / mean centre error mm / worst mm / views > 10 mm / views below raw)
from camera-protocol results folders: ``python docs/sensor_rows.py LABEL=RESULTS/latest ...``."""

import csv
import sys
from collections import defaultdict

import numpy as np

METHODS = ("raw", "sphere", "ellipsoid", "superellipsoid", "paper", "fused", "evidence")

for arg in sys.argv[1:]:
    label, folder = arg.split("=", 1)
    rows = list(csv.DictReader(open(f"{folder}/instances.csv")))
    key = lambda r: (r["fruit"], r["fruit_index"], r["pose"], r["occlusion"])  # noqa: E731
    raw = {key(r): float(r["iou"]) for r in rows if r["method"] == "raw" and not r["error"]}
    by = defaultdict(list)
    for r in rows:
        by[r["method"]].append(r)
    cells = []
    for m in METHODS:
        ok = [r for r in by[m] if not r["error"]]
        iou = np.array([float(r["iou"]) for r in ok])
        dev = np.array([float(r["centre_mm"]) for r in ok])
        below = sum(m != "raw" and float(r["iou"]) < raw.get(key(r), -1) - 1e-9 for r in ok)
        failed = len(by[m]) - len(ok)
        cell = f"{iou.mean():.3f} / {dev.mean():.2f} / {dev.max():.0f} / {(dev > 10).sum()} / {below}"
        cells.append(cell + (f" ({failed} failed)" if failed else ""))
    sys.stdout.write(f"| {label} | {len(by['raw'])} | " + " | ".join(cells) + " |\n")
