"""The D435 camera model's fronts and back faces on stored views (issue 18 items 2-3, stop 44, docs/stereo44.md).

``dump`` rebuilds each view of ``evaluate --protocol camera --sensor SENSOR --fruit
strawberry,apple,citrus,lemon,peach,pear,plum --n 10 --seed S --no-profile`` with the render's truth
(:func:`symfruit.evaluate.protocols.real_view`, the same draws; as docs/front43.py) and stores the runner's points,
camera and occlusion information with the truth's box and the model's bias and noise at the truth's front. The
others read the stored views:

    PYTHONPATH=src python docs/stereo44.py dump realsense-d435 0 VIEWS.pkl
    PYTHONPATH=src python docs/stereo44.py fronts VIEWS.pkl   # needs commit 815ada6 (apex_depth measure, reverted)
    PYTHONPATH=src python docs/stereo44.py boxes VIEWS.pkl base|truth|minor   # evidence's box against the truth
    PYTHONPATH=src python docs/stereo44.py widths VIEWS.pkl          # the outline's width against the truth's

``boxes``: ``truth`` hands ``evidence`` the truth's front (its ``apex_depth`` replaced, no point nearer: far43's
oracle), ``minor`` reads the depth prior's width as the outline's smaller width on a whole outline; per view and as
means (mm, signed: the box's front, back and depth against the truth's, the larger lateral side, the prior's width
and the closed candidates' weighted depth against the true depth, the centre's error).
``widths``: the prior's width (:func:`symfruit.methods.evidence.prior_width` of a whole outline) of the points'
region, with the fruit's mask, and with the mask trimmed of its overshoot, against the geometric mean of the true
box's lateral sides (mm and colour pixels).
"""

from __future__ import annotations

import argparse
import pickle
import sys

import numpy as np

import symfruit.methods.evidence as E
from symfruit.core.box import Box
from symfruit.core.front import apex_depth
from symfruit.core.points import subsample
from symfruit.core.raster import across_sight
from symfruit.evaluate import protocols as P
from symfruit.evaluate.protocols import specs
from symfruit.extract import extract, register
from symfruit.methods.complete import complete
from symfruit.occlusion import fruit_occlusion
from symfruit.settings import Settings
from symfruit.synthetic.sensors import SENSOR_MODELS, varied

KINDS = ("strawberry", "apple", "citrus", "lemon", "peach", "pear", "plum")


def say(*parts: object) -> None:
    sys.stdout.write(" ".join(str(p) for p in parts) + "\n")


def dump(sensor: str, seeds: str, out: str) -> None:
    st = Settings()
    rows = []
    for seed in (int(s) for s in seeds.split(",")):
        for kind in KINDS:
            for spec in specs("camera", kind, n=10, seed=seed, sensor=sensor):
                model = varied(SENSOR_MODELS[spec.sensor], spec.sensor_set)
                v = P.real_view(spec, model)
                truth = Box.from_points(v.posed.vertices if v.posed.points is None else v.posed.points)
                labels = (np.asarray(v.out.labels) == 1).astype(np.int32)
                moved, shift = register(labels, v.out.depth, v.camera, st.extract)
                cam = v.camera.shifted(*shift)
                ex = extract(moved > 0, v.out.depth, cam, st.extract)
                occ = fruit_occlusion(v.out.depth, ex.silhouette, ex.points, cam, st.occlusion,
                                      eroded=st.extract.erode_px)  # fmt: skip
                zt = float(truth.min[2])
                rows.append(dict(seed=seed, fruit=kind, index=spec.index, dist=v.distance, pts=ex.points, cam=cam,
                                 occ=occ, tmin=truth.min.copy(), tmax=truth.max.copy(), bias=float(model.bias(zt)),
                                 sigma=float(model.sigma(zt))))  # fmt: skip
    with open(out, "wb") as f:
        pickle.dump(rows, f)


def fronts(rows: list) -> None:
    far = np.array([r["dist"] for r in rows]) > 1.3
    bias = np.array([r["bias"] for r in rows]) * 1e3
    for measure in (0.0, 0.25, 0.5):
        e = np.array([(max(r["pts"][:, 2].min(), apex_depth(subsample(r["pts"], 1000), measure=measure)[0])
                       - r["tmin"][2]) * 1e3 for r in rows])  # fmt: skip
        say(f"measure {measure}: front mean {e.mean():+.2f} sd {e.std():.2f} mm, > 3 mm too near {(e < -3).sum()}"
              f" (> 7 mm {(e < -7).sum()}) of {len(e)}; against truth + bias {np.mean(e - bias):+.2f}; beyond 1.3 m"
              f" {e[far].mean():+.2f}")  # fmt: skip


def boxes(rows: list, mode: str) -> None:
    st = Settings()
    kept: dict = {}
    fuse = E.fuse_depth

    def fuse_kept(combined, cands, *a, **k):  # type: ignore[no-untyped-def]
        kept["fit"] = float(combined.box.max[2] - combined.box.min[2])
        return fuse(combined, cands, *a, **k)

    E.fuse_depth = fuse_kept  # type: ignore[assignment]
    if mode == "minor":

        def minor(across, contour, cut_width=1.0):  # type: ignore[no-untyped-def]
            small, big = sorted((float(across.minor), float(across.major)))
            cut = min(max(1.0 - float(contour), 0.0), 1.0) ** 2 * cut_width
            return big * (small / big) ** (1.0 - cut)

        E.prior_width = minor  # type: ignore[assignment]
    out = []
    for r in rows:
        pts = r["pts"]
        if mode == "truth":
            zt = float(r["tmin"][2])
            E.apex_depth = lambda s, zt=zt: (zt, np.array([0.0, 0.0, zt]))  # type: ignore[assignment,misc]
            pts = pts.copy()
            pts[:, 2] = np.maximum(pts[:, 2], zt)
        c = complete(pts, camera=r["cam"], method="evidence", settings=st, occlusion=r["occ"])
        b, x, lo, hi = c.box, c.extras, r["tmin"], r["tmax"]
        depth = hi[2] - lo[2]
        row = dict(front=b.min[2] - lo[2], back=b.max[2] - hi[2], depth=b.max[2] - b.min[2] - depth,
                   lateral=max(b.max[0] - b.min[0], b.max[1] - b.min[1]) - max(hi[0] - lo[0], hi[1] - lo[1]),
                   width=x["width"] - depth, fit=kept["fit"] - depth,
                   centre=float(np.linalg.norm(b.centre - 0.5 * (lo + hi))))  # fmt: skip
        out.append(row)
        say(r["fruit"], r["index"], f"{r['dist']:.2f} m", " ".join(f"{k} {1e3 * v:+.1f}" for k, v in row.items()))
    means = " ".join(f"{k} {1e3 * np.mean([o[k] for o in out]):+.2f}" for k in out[0])
    over = sum(o["centre"] > 0.01 for o in out)
    say(f"{mode}: mean {means}; centre over 10 mm {over}")
    for kind in KINDS:
        sel = [o for o, r in zip(out, rows, strict=True) if r["fruit"] == kind]
        say(f"  {kind}: depth {1e3 * np.mean([o['depth'] for o in sel]):+.1f}"
              f" centre {1e3 * np.mean([o['centre'] for o in sel]):.1f}")  # fmt: skip


def widths(rows: list) -> None:
    res = []
    for r in rows:
        pts, cam, occ = r["pts"], r["cam"], r["occ"]
        seen = E.silhouette(pts, cam)
        regions = [seen, E.with_own(seen, occ)]
        has = occ.overshoot is not None and occ.overshoot.any()
        regions.append(E.with_own(seen, occ, trimmed=True) if has else regions[1])
        t = r["tmax"] - r["tmin"]
        z = 0.5 * (r["tmin"][2] + r["tmax"][2])
        row = []
        for reg in regions:
            a = across_sight(reg, cam)
            row.append(E.prior_width(a, 1.0) * z / a.axis[2] - np.sqrt(t[0] * t[1]))
        res.append([*row, z / cam.fx])
    a = np.array(res)
    mm, px = a[:, :3].mean(0) * 1e3, (a[:, :3] / a[:, 3:]).mean(0)
    say(f"width - true lateral (mm / colour px): points' region {mm[0]:+.2f} / {px[0]:+.2f}, with the mask"
          f" {mm[1]:+.2f} / {px[1]:+.2f}, the mask trimmed {mm[2]:+.2f} / {px[2]:+.2f}")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("dump", help="store the camera protocol's views with the render's truth")
    d.add_argument("sensor")
    d.add_argument("seed")
    d.add_argument("out")
    sub.add_parser("fronts", help="the fronts' errors (needs commit 815ada6)").add_argument("views")
    b = sub.add_parser("boxes", help="evidence's boxes against the truth")
    b.add_argument("views")
    b.add_argument("variant", choices=("base", "truth", "minor"))
    sub.add_parser("widths", help="the outline's width against the truth's").add_argument("views")
    args = parser.parse_args()
    if args.cmd == "dump":
        dump(args.sensor, args.seed, args.out)
        return
    with open(args.views, "rb") as f:
        rows = pickle.load(f)
    if args.cmd == "fronts":
        fronts(rows)
    elif args.cmd == "boxes":
        boxes(rows, args.variant)
    else:
        widths(rows)


if __name__ == "__main__":
    main()
