"""How much of a method's depth error through the Azure Kinect model is the model's own depth bias, the
annotators' overshooting masks and multipath, and how much is the method's (docs/ablation.md, issue 18 item 3):
the camera protocol on the 7 proxies with each artefact switched off in turn.

    python docs/depth_bias.py [--n 10] [--methods evidence,paper] [--sensor azure-kinect]

Cells: mean IoU, mean centre error (mm), and the mean signed errors (mm; positive: too far or too large) of the
centre's depth, the front and back faces, the depth side and the lateral sides.
"""

import argparse
import dataclasses
import sys

import numpy as np

from symfruit.evaluate import protocols
from symfruit.evaluate.metrics import score_completion
from symfruit.evaluate.protocols import build, specs
from symfruit.evaluate.runner import extract, fruit_occlusion, register
from symfruit.methods.complete import complete
from symfruit.settings import Settings
from symfruit.synthetic.sensors import SENSOR_MODELS

PROXIES = ("strawberry", "apple", "citrus", "lemon", "peach", "pear", "plum")
VARIANTS = {
    "the model": {},
    "no bias": dict(bias_const=0.0, bias_linear=0.0),
    "no bias, exact masks": dict(bias_const=0.0, bias_linear=0.0, mask_overshoot_px=0.0),
    "no bias, exact masks, no multipath": dict(bias_const=0.0, bias_linear=0.0, mask_overshoot_px=0.0,
                                               multipath_bias=0.0),
}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--n", type=int, default=10)
    parser.add_argument("--methods", default="evidence,paper")
    parser.add_argument("--sensor", default="azure-kinect", choices=sorted(SENSOR_MODELS))
    args = parser.parse_args()
    methods = args.methods.split(",")
    settings = Settings()
    sys.stdout.write("| model | method | n | IoU | centre | centre depth | front face | back face | depth side "
                     "| lateral sides (x, y) |\n|---|---|---|---|---|---|---|---|---|---|\n")  # fmt: skip
    base = SENSOR_MODELS[args.sensor]
    try:
        for name, change in VARIANTS.items():
            protocols.SENSOR_MODELS[args.sensor] = dataclasses.replace(base, **change)
            cells: dict[str, list[list[float]]] = {m: [] for m in methods}
            for fruit in PROXIES:
                for spec in specs("camera", fruit, n=args.n, sensor=args.sensor, seed=0):
                    inst = build(spec)
                    assert inst.mask is not None and inst.depth is not None
                    moved, shift = register(inst.mask.astype(np.int32), inst.depth, inst.camera, settings.extract)
                    camera = inst.camera.shifted(*shift)  # as detect: the points in the colour camera's frame
                    ex = extract(moved > 0, inst.depth, camera, settings.extract)
                    if len(ex.points) < settings.extract.min_points:
                        continue
                    mask = ex.silhouette if ex.silhouette is not None else moved > 0
                    occ = fruit_occlusion(inst.depth, mask, ex.points, camera, settings.occlusion)
                    t = inst.truth_box
                    for m in methods:
                        r = complete(ex.points, camera=camera, method=m, settings=settings, occlusion=occ)
                        b = r.box
                        s = score_completion(b, r.points, t, inst.truth_surface)
                        d = 1000 * np.r_[b.centre[2] - t.centre[2], b.min[2] - t.min[2], b.max[2] - t.max[2],
                                         b.size - t.size]  # fmt: skip
                        cells[m].append([s.iou, s.centre_mm, *d])
            for m in methods:
                a = np.mean(cells[m], axis=0)
                sys.stdout.write(f"| {name} | {m} | {len(cells[m])} | {a[0]:.3f} | {a[1]:.1f} | {a[2]:+.1f} | "
                                 f"{a[3]:+.1f} | {a[4]:+.1f} | {a[7]:+.1f} | {a[5]:+.1f}, {a[6]:+.1f} |\n")  # fmt: skip
            sys.stdout.flush()
    finally:
        protocols.SENSOR_MODELS[args.sensor] = base


if __name__ == "__main__":
    main()
