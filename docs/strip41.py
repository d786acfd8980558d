"""docs/strip41.md's per-instance figures.

python docs/strip41.py frames FRAMES A.csv B.csv
    every fruit whose box moved between two ``docs/eval_boxes.py run`` CSVs of ``evaluate --frames FRAMES``: its
    centre error and depth side error (mm) against the frame's truth.json, and its visible share
python docs/strip41.py camera SENSOR SEED N [KIND:INDEX ...]
    a replica of the camera protocol at 0 % hidden (register, extract, fruit_occlusion, complete, score, as
    /work/notes/lead40/diag.py): per view the centre error, the centre's offset (x, y, z), the box's and the
    truth's sides, the points' extent, the mask's principal widths at the truth's depth, and what ``thin_front``
    did; ``KIND:INDEX`` limits it to those views
"""

import argparse
import csv
import json
import sys

import numpy as np

KINDS = ("strawberry", "apple", "citrus", "tomato", "lemon", "peach", "plum")


def frames(root: str, a: str, b: str) -> None:
    def load(path: str) -> dict[str, np.ndarray]:
        with open(path) as f:
            return {row[0]: np.array([float(v) for v in row[1:]]) for row in csv.reader(f)}

    before, after = load(a), load(b)
    truth: dict[str, dict] = {}

    def err(box: np.ndarray, fruit: dict) -> str:
        centre = (box[:3] + box[3:]) / 2
        off = 1000 * float(np.linalg.norm(centre - np.array(fruit["centre"])))
        return f"centre {off:5.1f} depth side {1000 * ((box[5] - box[2]) - fruit['size'][2]):+6.1f}"

    for key in sorted(set(before) | set(after)):
        _, scene, fid, _ = key.split("|")
        if scene not in truth:
            with open(f"{root}/{scene}/truth.json") as f:
                truth[scene] = {t["id"]: t for t in json.load(f)["fruits"]}
        fruit = truth[scene][int(fid)]
        if key in before and key in after and np.max(np.abs(before[key] - after[key])) <= 1e-4:
            continue
        was = err(before[key], fruit) if key in before else "unmatched"
        now = err(after[key], fruit) if key in after else "unmatched"
        sys.stdout.write(f"{scene} id {fid} seen {fruit['visible']:.2f}: {was}  ->  {now}\n")


def camera(sensor: str, seed: int, n: int, only: list[str]) -> None:
    from symfruit.core import surface
    from symfruit.core.raster import principal_widths
    from symfruit.evaluate.metrics import score_completion
    from symfruit.evaluate.protocols import Spec, build
    from symfruit.extract import extract, register
    from symfruit.methods.complete import complete
    from symfruit.occlusion import fruit_occlusion
    from symfruit.settings import Settings

    log: dict = {}
    thin_front = surface.thin_front

    def traced(*args, **kwargs):
        out = thin_front(*args, **kwargs)
        log["thin"] = None if out is None else (round(1000 * (out[0] - args[3]), 1), int(out[1].sum()))
        return out

    surface.thin_front = traced
    st = Settings()
    for kind in KINDS:
        for i in range(n):
            if only and f"{kind}:{i}" not in only:
                continue
            log.clear()
            inst = build(Spec("camera", kind, i, i, 0.0, seed, sensor, "hanging"))
            moved, shift = register(inst.mask.astype(np.int32), inst.depth, inst.camera, st.extract)
            cam = inst.camera.shifted(*shift)
            ex = extract(moved > 0, inst.depth, cam, st.extract)
            sil = ex.silhouette if ex.silhouette is not None else moved > 0
            occl = fruit_occlusion(inst.depth, sil, ex.points, cam, st.occlusion)
            r = complete(ex.points, camera=cam, method="evidence", settings=st, occlusion=occl)
            s = score_completion(r.box, r.points, inst.truth_box, inst.truth_surface)
            tb = inst.truth_box
            d = ((r.box.min + r.box.max) / 2 - (tb.min + tb.max) / 2) * 1000
            z = float(np.median(inst.truth_surface[:, 2]))
            minor, major = principal_widths(inst.mask)
            mm = 1000 * z / cam.fx
            box, sides = (r.box.max - r.box.min) * 1000, (tb.max - tb.min) * 1000
            extent = np.ptp(ex.points, axis=0) * 1000
            sys.stdout.write(
                f"{kind:10s} {i:2d} centre {s.centre_mm:5.1f} d {d.round(1)} box {box.round(1)} truth {sides.round(1)} "
                f"points {extent.round(1)} mask {minor * mm:.1f} x {major * mm:.1f} z {z:.2f} shift {shift} "
                f"thin {log.get('thin')}\n"
            )
            sys.stdout.flush()


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="what", required=True)
    f = sub.add_parser("frames", help="per-instance moves of two eval_boxes.py frame CSVs against the truth")
    f.add_argument("root")
    f.add_argument("a")
    f.add_argument("b")
    c = sub.add_parser("camera", help="the camera protocol's replica at 0 %% hidden")
    c.add_argument("sensor")
    c.add_argument("seed", type=int)
    c.add_argument("n", type=int)
    c.add_argument("views", nargs="*", help="KIND:INDEX")
    args = parser.parse_args()
    if args.what == "frames":
        frames(args.root, args.a, args.b)
    else:
        camera(args.sensor, args.seed, args.n, args.views)
