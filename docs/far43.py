"""Class-5 leaf views (docs/occl42.md: off by over 10 mm with the render's true fruit points) and what the
``evidence`` completion does with them (issue 18, stop 43, docs/far43.md).

    PYTHONPATH=src python docs/far43.py dump SENSOR OCCLUSIONS SEEDS DIR   # the views' inputs, one pickle each
    PYTHONPATH=src python docs/far43.py run DIR OUT.csv [GLOB]              # complete them with this tree

``dump`` rebuilds each view of the camera protocol's leaf table as ``docs/occl42.py`` does (the same draws) and
keeps the runner's points and mask and the ``ideal`` points (every pixel the fruit shows within its true depth);
``run`` completes both with ``evidence`` and writes, per view: the centre deviation (mm) of the runner's and the
ideal input, the ideal result's error along the line of sight (``los``, positive: too far) and across it, the
front's points, the candidates' weights and back faces, the prior's and the fit's back face and deviations.
"""

from __future__ import annotations

import csv
import pickle
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
import occl42 as O  # noqa: E402

from symfruit.evaluate.metrics import score_completion  # noqa: E402
from symfruit.evaluate.protocols import specs  # noqa: E402
from symfruit.extract import extract, register  # noqa: E402
from symfruit.methods.complete import complete  # noqa: E402
from symfruit.occlusion import fruit_occlusion  # noqa: E402
from symfruit.settings import Settings  # noqa: E402


def dump(sensor: str, occs: str, seeds: str, out: Path) -> None:
    st = Settings()
    out.mkdir(parents=True, exist_ok=True)
    for seed in (int(x) for x in seeds.split(",")):
        for kind in O.KINDS:
            for spec in specs("camera", kind, n=10, seed=seed, sensor=sensor,
                              occlusions=tuple(float(x) for x in occs.split(","))):  # fmt: skip
                b = O.build(spec)
                cam0, depth, model = b["cam"], b["depth"], b["model"]
                moved, shift = register(b["mask"].astype(np.int32), depth, cam0, st.extract)
                cam = cam0.shifted(*shift)
                ex = extract(moved > 0, depth, cam, st.extract)
                outline = ex.silhouette if ex.silhouette is not None else moved > 0
                tdu, tdv = (round(x) for x in b["shift"])
                cam_t = cam0.shifted(tdu, tdv)
                mv = lambda a: np.asarray(O.shift_labels(np.asarray(a), tdu, tdv))  # noqa: E731
                seen = mv(b["seen"].astype(np.int32)) > 0
                alone_depth = mv(b["alone_depth"])
                rr, cc = np.nonzero(seen & (depth > 0))
                dz, adz = depth[rr, cc].astype(float), alone_depth[rr, cc]
                okz = np.abs(dz - adz - model.bias(adz)) < np.maximum(4 * model.sigma(adz), 0.004)
                ideal = cam_t.deproject(np.c_[cc[okz], rr[okz]].astype(float), dz[okz])
                rec = dict(sensor=sensor, seed=spec.seed, fruit=spec.fruit, index=spec.index, occ=spec.occlusion,
                           dist=b["distance"], sigma=float(model.sigma(b["distance"])), cam=cam, depth=depth,
                           base_points=ex.points, base_mask=outline, ideal=ideal, sil=moved > 0,
                           truth=b["truth"], surface=b["surface"])  # fmt: skip
                name = f"{sensor}_{spec.seed}_{spec.fruit}_{spec.index}_{spec.occlusion}.pkl"
                (out / name).write_bytes(pickle.dumps(rec))


def one(points, mask, depth, cam, rec, st):  # type: ignore[no-untyped-def]
    if len(points) < st.extract.min_points:
        return None
    occ = fruit_occlusion(depth, mask, points, cam, st.occlusion)
    return complete(points, camera=cam, method="evidence", settings=st, occlusion=occ)


def run(src: Path, out: str, pattern: str = "*") -> None:
    st = Settings()
    rows = []
    for f in sorted(src.glob(pattern + ".pkl")):
        r = pickle.loads(f.read_bytes())
        row = {k: r[k] for k in ("sensor", "seed", "fruit", "index", "occ")}
        row["dist"] = round(r["dist"], 3)
        row["sigma_mm"] = round(1e3 * r["sigma"], 2)
        row["n_ideal"] = len(r["ideal"])
        for tag, pts, mask in (("base", r["base_points"], r["base_mask"]), ("ideal", r["ideal"], r["sil"])):
            res = one(pts, mask, r["depth"], r["cam"], r, st)
            if res is None:
                row[tag] = float("nan")
                continue
            sc = score_completion(res.box, res.points, r["truth"], r["surface"])
            row[tag] = round(float(sc.centre_mm), 2)
            row[tag + "_iou"] = round(float(sc.iou), 3)
            if tag != "ideal":
                continue
            t = r["truth"].centre
            d = res.box.centre - t
            ray = t / np.linalg.norm(t)
            los = float(d @ ray)
            row["los"] = round(1e3 * los, 2)
            row["across"] = round(1e3 * float(np.linalg.norm(d - los * ray)), 2)
            ex = res.extras
            row["true_depth"] = round(1e3 * float(r["truth"].size[2]), 1)
            row["box_depth"] = round(1e3 * float(res.box.size[2]), 1)
            row["width"] = round(1e3 * ex["width"], 1)
            row["back_sd"] = round(1e3 * ex["back_sd"], 2)
            row["contour"] = round(ex["contour"], 2)
            row["rim"] = round(ex["rim"], 2)
            row["true_back"] = round(1e3 * float(r["truth"].max[2] - res.box.min[2]), 1)
            row["front_err"] = round(1e3 * float(res.box.min[2] - r["truth"].min[2]), 1)
            for name, w in ex["weights"].items():
                c = ex["candidates"][name]
                row[f"w_{name}"] = round(w, 2)
                row[f"back_{name}"] = round(1e3 * (c["max"][2] - res.box.min[2]), 1)
                row[f"bstd_{name}"] = None if c["back_std"] is None else round(1e3 * c["back_std"], 2)
            for k in ("noise_mm", "fit_sd", "prior_sd", "n_eff"):
                if k in ex:
                    row[k] = round(ex[k], 3)
        rows.append(row)
    keys: list[str] = []
    for row in rows:
        keys += [k for k in row if k not in keys]
    with open(out, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)


if __name__ == "__main__":
    if sys.argv[1] == "dump":
        dump(sys.argv[2], sys.argv[3], sys.argv[4], Path(sys.argv[5]))
    else:
        run(Path(sys.argv[2]), sys.argv[3], *sys.argv[4:5])
