"""Class-5 leaf views (docs/occl42.md: off by over 10 mm with the render's true fruit points) and what the
``evidence`` completion does with them (issue 18, stop 43, docs/far43.md).

    PYTHONPATH=src python docs/far43.py dump SENSOR OCCLUSIONS SEEDS DIR   # the views' inputs, one pickle each
    PYTHONPATH=src python docs/far43.py run DIR OUT.csv [GLOB]              # complete them with this tree
    PYTHONPATH=src python docs/far43.py variants DIR [GLOB]                 # the ideal input under variants

``dump`` rebuilds each view of the camera protocol's leaf table as ``docs/occl42.py`` does (the same draws) and
keeps the runner's points and mask and the ``ideal`` points (every pixel the fruit shows within its true depth);
``run`` completes both with ``evidence`` and writes, per view: the centre deviation (mm) of the runner's and the
ideal input (and, where the ideal input is over 10 mm off, of the same pixels at the render's true depth,
``true``, and at that depth plus the model's systematic error, ``biased``), the ideal points' mean depth error and
that of their nearest 2 % (``res_mean``, ``res_near``, mm), the ideal result's error along the line of sight
(``los``, positive: too far) and across it, its front face's error, the prior's width, the candidates' weights and
back faces (behind the box's front face). ``variants`` completes the ideal input with the depth prior off, strong
(``depth_ratio_sd`` 0.03) and weak (0.3), and with the true front face in place of ``apex_depth``'s (an oracle, not a
method), and prints the mean centre deviation (views over 10 mm) and signed error along the line of sight by hidden
share and distance (up to / beyond 1.3 m).
"""

from __future__ import annotations

import csv
import pickle
import sys
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
import occl42 as O

from symfruit.evaluate.metrics import score_completion
from symfruit.evaluate.protocols import specs
from symfruit.extract import extract, register
from symfruit.methods.complete import complete
from symfruit.occlusion import fruit_occlusion
from symfruit.settings import Settings


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
                seen = np.asarray(O.shift_labels(b["seen"].astype(np.int32), tdu, tdv)) > 0
                alone_depth = np.asarray(O.shift_labels(b["alone_depth"], tdu, tdv))
                rr, cc = np.nonzero(seen & (depth > 0))
                dz, adz = depth[rr, cc].astype(float), alone_depth[rr, cc]
                okz = np.abs(dz - adz - model.bias(adz)) < np.maximum(4 * model.sigma(adz), 0.004)
                uv = np.c_[cc[okz], rr[okz]].astype(float)
                ideal = cam_t.deproject(uv, dz[okz])
                # the same pixels at the render's depth, and at that depth plus the model's systematic error
                true = cam_t.deproject(uv, adz[okz])
                biased = cam_t.deproject(uv, adz[okz] + model.bias(adz[okz]))
                rec = dict(sensor=sensor, seed=spec.seed, fruit=spec.fruit, index=spec.index, occ=spec.occlusion,
                           dist=b["distance"], sigma=float(model.sigma(b["distance"])), cam=cam, depth=depth,
                           base_points=ex.points, base_mask=outline, ideal=ideal, sil=moved > 0,
                           true=true, biased=biased, residual=dz[okz] - adz[okz],
                           truth=b["truth"], surface=b["surface"])  # fmt: skip
                name = f"{sensor}_{spec.seed}_{spec.fruit}_{spec.index}_{spec.occlusion}.pkl"
                (out / name).write_bytes(pickle.dumps(rec))


def one(points, mask, depth, cam, rec, st):
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
            res_ = r["residual"]
            near = np.argsort(r["ideal"][:, 2])[: max(1, int(0.02 * len(res_)))]
            row["res_mean"] = round(1e3 * float(res_.mean()), 2)  # the ideal points' depth error, mm
            row["res_near"] = round(1e3 * float(res_[near].mean()), 2)  # ... of their nearest 2 %
            if sc.centre_mm > 10:  # the same pixels at their true depth (and with the model's bias)
                for alt in ("true", "biased"):
                    got = one(r[alt], r["sil"], r["depth"], r["cam"], r, st)
                    if got is not None:
                        row[alt] = round(float(score_completion(got.box, got.points, r["truth"],
                                                                r["surface"]).centre_mm), 2)  # fmt: skip
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


def variants(src: Path, pattern: str = "*") -> None:
    import dataclasses

    import symfruit.methods.evidence as ev

    st = Settings()
    kinds = {"base": st, "prior off": st.replace(evidence=dataclasses.replace(st.evidence, depth_ratio_sd=0.0)),
             "prior strong": st.replace(evidence=dataclasses.replace(st.evidence, depth_ratio_sd=0.03)),
             "prior weak": st.replace(evidence=dataclasses.replace(st.evidence, depth_ratio_sd=0.3)),
             "oracle front": st}  # fmt: skip
    apex = ev.apex_depth
    oracle: dict[str, float | None] = {"front": None}

    def apex_or_truth(points: np.ndarray, **kw: Any) -> tuple[float, np.ndarray]:
        z, at = apex(points, **kw)
        return (z, at) if oracle["front"] is None else (oracle["front"], at)

    ev.apex_depth = apex_or_truth
    table: dict[tuple[float, bool], list[list[float]]] = {}
    for f in sorted(src.glob(pattern + ".pkl")):
        r = pickle.loads(f.read_bytes())
        pts = r["ideal"]
        if len(pts) < st.extract.min_points:
            continue
        occ = fruit_occlusion(r["depth"], r["sil"], pts, r["cam"], st.occlusion)
        t = r["truth"].centre
        ray = t / np.linalg.norm(t)
        row = []
        for name, s_ in kinds.items():
            oracle["front"] = float(r["truth"].min[2]) if name == "oracle front" else None
            res = complete(pts, camera=r["cam"], method="evidence", settings=s_, occlusion=occ)
            sc = score_completion(res.box, res.points, r["truth"], r["surface"])
            row += [float(sc.centre_mm), 1e3 * float((res.box.centre - t) @ ray)]
        table.setdefault((r["occ"], r["dist"] > 1.3), []).append(row)
    ev.apex_depth = apex
    sys.stdout.write("variants: " + ", ".join(kinds) + "\n")
    for (occ_, far), rows in sorted(table.items()):
        v = np.array(rows)
        means, over, los = v[:, 0::2].mean(0), (v[:, 0::2] > 10).sum(0), v[:, 1::2].mean(0)
        cells = ", ".join(f"{m:.2f} ({o}) {x:+.1f}" for m, o, x in zip(means, over, los, strict=True))
        sys.stdout.write(f"hidden {occ_:.2f} {'beyond' if far else 'up to'} 1.3 m, {len(v)} views: {cells}\n")


def main(argv: list[str]) -> None:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    d = sub.add_parser("dump", help="the views' inputs, one pickle each")
    d.add_argument("sensor")
    d.add_argument("occlusions", help="hidden shares, e.g. 0,0.5")
    d.add_argument("seeds", help="e.g. 0,1")
    d.add_argument("folder", type=Path)
    r = sub.add_parser("run", help="complete the dumped views with this tree")
    r.add_argument("folder", type=Path)
    r.add_argument("out", help="CSV to write")
    r.add_argument("glob", nargs="?")
    v = sub.add_parser("variants", help="the ideal input under variants")
    v.add_argument("folder", type=Path)
    v.add_argument("glob", nargs="?")
    a = parser.parse_args(argv)
    if a.command == "dump":
        dump(a.sensor, a.occlusions, a.seeds, a.folder)
    elif a.command == "variants":
        variants(a.folder, *([a.glob] if a.glob else []))
    else:
        run(a.folder, a.out, *([a.glob] if a.glob else []))


if __name__ == "__main__":
    main(sys.argv[1:])
