"""Where the camera protocol's extracted fronts lie against the rendered truth (issue 18, stop 43, docs/front43.md).

Each view of ``evaluate --protocol camera --sensor NAME --fruit strawberry,apple,citrus,lemon,peach,pear,plum --n 10
--seed S --no-profile`` is rebuilt with the render's truth kept (:func:`symfruit.evaluate.protocols.real_view`, the
same draws; as docs/occl42.py), put through the runner's steps (register, extract, occlusion information,
``evidence``), and its front as ``evidence`` reads it (``max(nearest depth, apex_depth)``, the box's front face)
compared with the truth's nearest depth. Then an oracle ladder on the extracted points: the front again

- ``o_offsil``: without the points off the fruit's true silhouette (its own render, moved by the model's
  registration offset): a stereo camera's spread edge, flying pixels, what a mask's overshoot reaches;
- ``o_rim``: and without the points within 2 depth pixels of that silhouette's outline that lie more than 3 noise
  deviations (at least 3 mm) in front of the fruit's depth there (mixed pixels at the rim);
- ``o_clean``: every kept point on the fruit with its depth replaced by the rendered depth plus the model's bias (no
  noise).

A view whose front lies more than 3 mm nearer than the truth is classed by the first oracle that brings it within
3 mm (``--ref bias``: against the truth plus the camera model's bias, what the camera measures without noise).

    PYTHONPATH=src python docs/front43.py realsense-d435 0,1 OUT.csv [--ref truth|bias]

Columns (mm, signed, negative: nearer than the truth): ``err`` the front, ``minz`` the nearest point, ``box_front``
/ ``box_back`` the completed box's faces, ``o_*`` the oracles; ``bias_mm`` / ``sigma_mm`` the model's bias and noise
at the truth's front; ``n_off`` points off the silhouette, ``n_int_infront`` interior points more than 3 deviations in
front.
"""

from __future__ import annotations

import argparse
import collections
import csv
import sys

import numpy as np
from scipy import ndimage

from symfruit.core.box import Box
from symfruit.core.front import apex_depth
from symfruit.core.points import subsample
from symfruit.evaluate import protocols as P
from symfruit.evaluate.protocols import specs
from symfruit.extract import extract, register, shift_labels
from symfruit.methods.complete import complete
from symfruit.occlusion import fruit_occlusion
from symfruit.settings import Settings
from symfruit.synthetic.sensors import SENSOR_MODELS, varied

KINDS = ("strawberry", "apple", "citrus", "lemon", "peach", "pear", "plum")


def front_of(points: np.ndarray, st: Settings) -> float:
    """``evidence``'s front: the larger of the nearest depth and the apex quadric's (metres)."""
    if len(points) < 12:
        return float("nan")
    return max(float(points[:, 2].min()), apex_depth(subsample(points, st.evidence.fit_points))[0])


def view(spec: P.Spec, st: Settings) -> dict:
    model = varied(SENSOR_MODELS[spec.sensor], spec.sensor_set)
    v = P.real_view(spec, model)
    posed, out = v.posed, v.out
    truth = Box.from_points(posed.vertices if posed.points is None else posed.points)
    cam0, depth = v.camera, out.depth
    moved, shift = register((np.asarray(out.labels) == 1).astype(np.int32), depth, cam0, st.extract)
    cam = cam0.shifted(*shift)
    ex = extract(moved > 0, depth, cam, st.extract)
    pts = ex.points
    du, dv = (round(x) for x in out.shift)  # the truth in the depth image's pixels

    def moved_by(a: np.ndarray) -> np.ndarray:
        return np.asarray(shift_labels(np.asarray(a), du, dv))

    on = moved_by((v.alone.ids == 0).astype(np.int32)) > 0
    alone_depth = moved_by(np.nan_to_num(v.alone.depth, posinf=0.0))
    uv = cam.project(pts)  # the pixels the points were de-projected from
    c = np.clip(np.round(uv[:, 0]).astype(int), 0, cam0.width - 1)
    r = np.clip(np.round(uv[:, 1]).astype(int), 0, cam0.height - 1)
    zt = float(truth.min[2])
    onfruit = on[r, c]
    rim = onfruit & (ndimage.distance_transform_edt(on)[r, c] <= 2 * model.footprint)
    at = np.maximum(alone_depth[r, c], 0.1)
    infront = pts[:, 2] - (alone_depth[r, c] + model.bias(at)) < -np.maximum(3 * model.sigma(at), 0.003)
    clean = pts[onfruit].copy()
    clean[:, 2] = alone_depth[r[onfruit], c[onfruit]] + model.bias(at[onfruit])
    occ = fruit_occlusion(depth, ex.silhouette, pts, cam, st.occlusion, eroded=st.extract.erode_px)
    box = complete(pts, camera=cam, method="evidence", settings=st, occlusion=occ).box
    mm = 1e3
    return dict(
        sensor=spec.sensor, seed=spec.seed, fruit=spec.fruit, index=spec.index, dist=round(v.distance, 3),
        sigma_mm=float(model.sigma(zt)) * mm, bias_mm=float(model.bias(zt)) * mm, n=len(pts),
        err=(front_of(pts, st) - zt) * mm, minz=(float(pts[:, 2].min()) - zt) * mm,
        box_front=(float(box.min[2]) - zt) * mm, box_back=(float(box.max[2]) - float(truth.max[2])) * mm,
        o_offsil=(front_of(pts[onfruit], st) - zt) * mm,
        o_rim=(front_of(pts[onfruit & ~(rim & infront)], st) - zt) * mm, o_clean=(front_of(clean, st) - zt) * mm,
        n_off=int((~onfruit).sum()), n_rim_infront=int((rim & infront).sum()),
        n_int_infront=int((onfruit & ~rim & infront).sum()),
    )  # fmt: skip


def cause(row: dict, ref: float) -> str:
    for key, name in (("o_offsil", "off the silhouette"), ("o_rim", "rim in front"), ("o_clean", "noise")):
        if row[key] - ref >= -3.0:
            return name
    return "other"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sensor", help="a camera model, e.g. realsense-d435")
    parser.add_argument("seeds", help="seeds, e.g. 0,1")
    parser.add_argument("out", help="the CSV written, one row a view")
    parser.add_argument("--ref", choices=("truth", "bias"), default="truth")
    args = parser.parse_args()
    st = Settings()
    rows = [view(spec, st) for seed in (int(x) for x in args.seeds.split(",")) for kind in KINDS
            for spec in specs("camera", kind, n=10, seed=seed, sensor=args.sensor)]  # fmt: skip
    with open(args.out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    classes: collections.Counter[str] = collections.Counter()
    for row in rows:
        ref = row["bias_mm"] if args.ref == "bias" else 0.0
        if row["err"] - ref < -3.0:
            classes[cause(row, ref)] += 1
    err = np.array([row["err"] for row in rows])
    sys.stdout.write(f"{args.sensor}: front mean {np.nanmean(err):+.2f} mm, sd {np.nanstd(err):.2f}; "
                     f"{sum(classes.values())} of {len(rows)} views > 3 mm nearer than the {args.ref}: "
                     f"{dict(classes)}\n")  # fmt: skip


if __name__ == "__main__":
    main()
