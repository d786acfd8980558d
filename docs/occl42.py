"""Where the camera protocol's leaf views go wrong (issue 18, stop 42, docs/occl42.md): each view of
``evaluate --protocol camera --sensor NAME --fruit strawberry,apple,citrus,tomato,lemon,peach,plum --occlusion ...
--n 10 --seed S --methods evidence`` rebuilt with what the render knows (which pixels are the fruit's, its depth alone,
the registration offset the model drew), and completed again with parts of the input made right.

    PYTHONPATH=src python docs/occl42.py SENSOR 0.25,0.5 OUT.csv [SEEDS]

Columns (centre deviations, mm; NaN: too few points): ``base`` the runner's steps (register, extract, occlusion
information, ``evidence``); ``clean`` the extracted points without those more than 4 noise deviations (at least 4 mm)
in front of the fruit's true depth at their pixel or on the leaf's pixels; ``ideal`` every pixel the fruit shows with
depth within that of its true depth (the extraction an oracle would make), the same mask and occlusion information;
``ideal_truemask`` the same with the fruit's true visible pixels as the mask; ``ideal_cleandepth`` that and the
occlusion information from the render's depth (no camera artefacts); ``truereg`` / ``noreg`` the runner's steps
with the mask moved by the model's true registration offset / not moved. ``n_leaf``: extracted points classed
the leaf's; ``shift`` / ``true``: the registration's estimate and the model's offset (pixels, rounded).
"""

from __future__ import annotations

import argparse
import csv

import numpy as np

from symfruit.core.box import Box
from symfruit.core.camera import Camera
from symfruit.evaluate import protocols as P
from symfruit.evaluate.metrics import score_completion
from symfruit.evaluate.protocols import specs
from symfruit.extract import extract, register, shift_labels
from symfruit.methods.complete import complete
from symfruit.occlusion import fruit_occlusion
from symfruit.settings import Settings
from symfruit.synthetic.sensors import SENSOR_MODELS, varied

KINDS = ("strawberry", "apple", "citrus", "tomato", "lemon", "peach", "plum")


def build(spec: P.Spec) -> dict:
    """``protocols._real_camera``'s view (:func:`symfruit.evaluate.protocols.real_view`, the same draws), with the
    render's truth kept."""
    model = varied(SENSOR_MODELS[spec.sensor], spec.sensor_set)
    v = P.real_view(spec, model)
    posed, shot, alone, out = v.posed, v.shot, v.alone, v.out
    truth = Box.from_points(posed.vertices if posed.points is None else posed.points)
    surface = posed.sample(P.TRUTH_POINTS, np.random.default_rng([spec.seed, 3000, spec.index]))
    return dict(model=model, cam=v.camera, ids=shot.ids, clean=np.nan_to_num(shot.depth, posinf=0.0),
                alone=alone.ids == 0, alone_depth=np.nan_to_num(alone.depth, posinf=0.0), seen=shot.ids == 0,
                depth=out.depth, mask=np.asarray(out.labels) == 1, truth=truth, surface=surface,
                distance=v.distance, shift=out.shift)  # fmt: skip


def centre_mm(points: np.ndarray, mask: np.ndarray, depth: np.ndarray, cam: Camera, b: dict, st: Settings) -> float:
    if len(points) < st.extract.min_points:
        return float("nan")
    occ = fruit_occlusion(depth, mask, points, cam, st.occlusion)
    result = complete(points, camera=cam, method="evidence", settings=st, occlusion=occ)
    return float(score_completion(result.box, result.points, b["truth"], b["surface"]).centre_mm)


def runner(mask: np.ndarray, depth: np.ndarray, cam: Camera, b: dict, st: Settings) -> tuple[float, np.ndarray]:
    ex = extract(mask, depth, cam, st.extract)
    outline = ex.silhouette if ex.silhouette is not None else mask
    return centre_mm(ex.points, outline, depth, cam, b, st), ex.points


def view(spec: P.Spec, st: Settings) -> dict:
    b = build(spec)
    cam0, depth, model = b["cam"], b["depth"], b["model"]
    moved, shift = register(b["mask"].astype(np.int32), depth, cam0, st.extract)
    cam = cam0.shifted(*shift)
    base, pts = runner(moved > 0, depth, cam, b, st)
    # the truth in the depth image's pixels: moved by the model's registration offset
    tdu, tdv = (round(x) for x in b["shift"])
    cam_t = cam0.shifted(tdu, tdv)

    def moved_by(a: np.ndarray) -> np.ndarray:
        return np.asarray(shift_labels(np.asarray(a), tdu, tdv))

    ids = moved_by(b["ids"] + 1) - 1
    alone, seen = moved_by(b["alone"].astype(np.int32)) > 0, moved_by(b["seen"].astype(np.int32)) > 0
    alone_depth = moved_by(b["alone_depth"])
    uv = cam_t.project(pts)
    c = np.clip(np.round(uv[:, 0]).astype(int), 0, cam0.width - 1)
    r = np.clip(np.round(uv[:, 1]).astype(int), 0, cam0.height - 1)
    ad = alone_depth[r, c]
    tol = np.maximum(4 * model.sigma(np.maximum(ad, 0.1)), 0.004)
    leaf = (alone[r, c] & (pts[:, 2] - ad - model.bias(np.maximum(ad, 0.1)) < -tol)) | (ids[r, c] == 1)
    good = ~leaf & alone[r, c]
    rr, cc = np.nonzero(seen & (depth > 0))
    dz, adz = depth[rr, cc].astype(float), alone_depth[rr, cc]
    okz = np.abs(dz - adz - model.bias(adz)) < np.maximum(4 * model.sigma(adz), 0.004)
    ideal = cam_t.deproject(np.c_[cc[okz], rr[okz]].astype(float), dz[okz])
    sil = moved > 0
    return dict(
        seed=spec.seed, fruit=spec.fruit, index=spec.index, occ=spec.occlusion, dist=round(b["distance"], 3),
        mask_px=int(b["mask"].sum()), seen_px=int(b["seen"].sum()),
        mask_leaf_px=int((b["mask"] & (b["ids"] == 1)).sum()),
        n=len(pts), n_leaf=int(leaf.sum()), shift=f"{shift[0]}/{shift[1]}", true=f"{tdu}/{tdv}", base=base,
        clean=centre_mm(pts[good], sil, depth, cam, b, st), ideal=centre_mm(ideal, sil, depth, cam, b, st),
        ideal_truemask=centre_mm(ideal, seen, depth, cam_t, b, st),
        ideal_cleandepth=centre_mm(ideal, b["seen"], b["clean"], cam0, b, st),
        truereg=runner(np.asarray(shift_labels(b["mask"].astype(np.int32), tdu, tdv)) > 0, depth, cam_t, b, st)[0],
        noreg=runner(b["mask"], depth, cam0, b, st)[0],
    )  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description="Where the camera protocol's leaf views go wrong (docs/occl42.md).")
    parser.add_argument("sensor", help="a camera model, e.g. realsense-d435")
    parser.add_argument("occlusions", help="leaf levels, e.g. 0.25,0.5")
    parser.add_argument("out", help="the CSV written, one row a view")
    parser.add_argument("seeds", nargs="?", default="0", help="seeds, e.g. 0,1 (default 0)")
    args = parser.parse_args()
    sensor, occs, out = args.sensor, tuple(float(x) for x in args.occlusions.split(",")), args.out
    seeds = [int(x) for x in args.seeds.split(",")]
    st = Settings()
    rows = [view(spec, st) for seed in seeds for kind in KINDS
            for spec in specs("camera", kind, n=10, seed=seed, occlusions=occs, sensor=sensor)]  # fmt: skip
    with open(out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


if __name__ == "__main__":
    main()
