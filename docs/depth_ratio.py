"""The true depth extent of generated and scanned fruit over their silhouette's widths, per kind (docs/ablation.md,
"The ratio the prior is about"): ``python docs/depth_ratio.py [--n 20]``."""

import argparse
import sys

import numpy as np

from symfruit.core.raster import across_sight, silhouette
from symfruit.evaluate.protocols import build, specs

KINDS = "apple,citrus,peach,tomato,strawberry,lopsided,lemon,pear,plum".split(",")


def ratios(fruit: str, n: int, pose: str) -> dict[str, np.ndarray]:
    out: dict[str, list[tuple[float, float, float]]] = {}
    for spec in specs("camera", fruit, n=n, seed=0, sensor="heldback", poses=pose):
        inst = build(spec)
        region = silhouette(inst.visible, inst.camera)
        across = across_sight(region, inst.camera)  # the widths the prior uses (tangent units)
        minor, major = across.minor, across.major
        scale = inst.truth_box.centre[2] / across.axis[2]
        depth = inst.truth_box.size[2]
        out.setdefault(inst.kind, []).append((depth / (minor * scale), depth / (major * scale),
                                              depth / (np.sqrt(minor * major) * scale)))  # fmt: skip
    return {k: np.array(v) for k, v in out.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--n", type=int, default=20)
    args = parser.parse_args()
    sys.stdout.write("| kind | depth / minor width | depth / major width | depth / geometric mean |\n")
    sys.stdout.write("|---|---|---|---|\n")
    rows = [(f, "hanging") for f in KINDS] + [("examples/scans", p) for p in ("hanging", "upright", "uniform")]
    for fruit, pose in rows:
        for kind, r in sorted(ratios(fruit, args.n, pose).items()):
            cells = " | ".join(f"{r[:, i].mean():.2f} +- {r[:, i].std():.2f}" for i in range(3))
            label = kind if fruit in KINDS else f"{kind}, {pose}"
            sys.stdout.write(f"| {label} | {cells} |\n")


if __name__ == "__main__":
    main()
