"""What extraction keeps of an apple on rendered trees, point class by point class (issue 18 item 2, stop 44,
docs/slab44.md).

    python docs/slab44.py render OUT [--seed 6] [--n 3] [--sensor-set NAME=VALUE,...] [--spur 4]
    python docs/slab44.py classes DIR [--config SETTINGS] [--csv OUT.csv]
    python docs/slab44.py spans FRAME [FRAME ...]

``render``: apple-tree frames as `symfruit scenes OUT --scene apple-tree --seed S --n N --sensor-set ...` (the Azure
Kinect model) with ``--spur`` more leaves around each apple at its own depth (a spur's leaves: centres 1.0-1.6 apple
radii from the apple's centre across the line of sight, -0.3 to +1.0 radii along it; 5-8 cm, tilted up to 60
degrees): the clutter beside and just behind a fruit that an overshooting mask or depth registered off its colour
puts inside the mask at depths within extraction's slab. The spur leaves are drawn from their own seeded stream
(``[seed, 4444]``), so ``--spur 0`` writes the frames `symfruit scenes` writes.

``classes``: every apple `detect` finds (``evidence``, the annotators' masks, ``--config`` as `symfruit evaluate
--config`) matched to the truth as `symfruit evaluate --frames` matches it; per apple the box's depth side and larger
lateral side against the truth's, the 2-D thin-lens estimate's lateral error (``evaluate.frames.thin_lens``), the
depth span of the extracted cloud over the mask's half-width at the cloud's median depth (a convex fruit's visible
cap spans at most about one: a sphere's rim lies a radius behind its front), and the extracted points by class
against the render's truth (the truth box's inscribed ellipsoid grown by 6 mm): ``on`` the fruit, ``behind`` off it
and behind its centre, ``front`` off it and nearer. The box again from the points without ``behind`` and from ``on``
alone (occlusion information rebuilt from the kept points, then ``evidence``): what the foreign points add to the
box. Printed by visible share (``truth.json``'s ``visible``: >= 90 %, 60-90 %, < 60 %), mm, mean absolute (signed).

``spans``: frames without truth (the real lab frames, ``examples/real-frames/lab-spheres-0``): per fruit `detect`
finds (default settings, ``evidence``) the mask's half-width at its cloud's median depth, the cloud's depth span over
it (all points; 1st-99th percentile) and the box. It uses only what `detect` offered before 5c526b6 as well, so it
runs on that tree too (``PYTHONPATH=OLD/src``).
"""

import argparse
import csv
import json
import sys
from pathlib import Path

import numpy as np

MARGIN = 0.006  # metres: a point this far outside the truth's ellipsoid is still the fruit's (noise, the mesh's bumps)
GROUPS = (("visible", 0.9, 1.01), ("partly", 0.6, 0.9), ("mostly", 0.0, 0.6))


def point_classes(points: np.ndarray, centre: np.ndarray, size: np.ndarray, margin: float = MARGIN):
    """``(on, behind, front)`` bool arrays over ``points``: on the ellipsoid inscribed in the box ``centre``,
    ``size`` grown by ``margin`` (relative to its mean half-side), else behind or in front of its centre's depth."""
    half = np.asarray(size, float) / 2
    q = np.sqrt((((np.asarray(points) - centre) / half) ** 2).sum(axis=1))
    on = q <= 1.0 + margin / half.mean()
    behind = ~on & (points[:, 2] > centre[2])
    return on, behind, ~on & ~behind


def spur_leaf_centres(centre: np.ndarray, radius: float, k: int, rng: np.random.Generator) -> np.ndarray:
    """(k, 3) centres of leaves around an apple at ``centre`` of ``radius``: 1.0-1.6 radii from it across the line of
    sight (z), -0.3 to +1.0 radii along it."""
    angle = rng.uniform(0, 2 * np.pi, k)
    reach = rng.uniform(1.0, 1.6, k) * radius
    along = rng.uniform(-0.3, 1.0, k) * radius
    return np.asarray(centre, float) + np.c_[reach * np.cos(angle), reach * np.sin(angle), along]


def render(out: str, seed: int, n: int, sensor_set: str | None, spur: int) -> None:
    from symfruit.io.frames import write_frame
    from symfruit.synthetic import scenes
    from symfruit.synthetic.sensors import SENSOR_MODELS, parse_sensor_set, varied

    sensor = SENSOR_MODELS["azure-kinect"]
    if sensor_set:
        sensor = varied(sensor, parse_sensor_set(sensor_set))
    render0, shade0 = scenes.render, scenes._shade
    state: dict = {}

    def with_spurs(meshes, camera):  # make_tree_scene renders the frame, then each fruit alone: the frame once
        if spur and state.get("done") != state["seed"]:
            state["done"] = state["seed"]
            rng = np.random.default_rng([state["seed"], 4444])
            apples = [v for v, _ in meshes if len(v) > 300 and np.ptp(v, axis=0).max() < 0.13]
            added = []
            for v in apples:
                for c in spur_leaf_centres(v.mean(axis=0), 0.5 * float(np.ptp(v, axis=0).max()), spur, rng):
                    tilt = scenes.rotation(rng.uniform(-60, 60), rng.uniform(-60, 60), 0)
                    added.append(scenes._leaf(c, rng.uniform(0.05, 0.08), rng.uniform(0, np.pi), tilt))
            state["added"] = len(added)
            meshes.extend(added)
        return render0(meshes, camera)

    def shade(shot, colours, rng):
        extra = np.random.default_rng([state["seed"], 4445])
        leaves = [(extra.uniform(0.22, 0.33), extra.uniform(0.55, 0.8), extra.uniform(0.3, 0.55))
                  for _ in range(state.get("added", 0) if spur else 0)]  # fmt: skip
        return shade0(shot, list(colours) + leaves, rng)

    scenes.render, scenes._shade = with_spurs, shade
    try:
        for i in range(n):
            state["seed"], state["added"] = seed + i, 0
            sc = scenes.make_tree_scene(seed + i, sensor=sensor)
            write_frame(Path(out) / f"scene_{i:05d}", sc.color, sc.depth, sc.camera, truth=sc.truth(), masks=sc.masks)
            sys.stdout.write(f"scene_{i:05d}: seed {seed + i}, {state['added']} spur leaves\n")
            sys.stdout.flush()
    finally:
        scenes.render, scenes._shade = render0, shade0


def classes(folder: str, config: str | None, out: str | None) -> list[dict]:
    from symfruit.core.box import box_iou, centre_deviation
    from symfruit.detect import detect
    from symfruit.evaluate.frames import match, thin_lens
    from symfruit.io.sources import open_source
    from symfruit.methods.complete import complete
    from symfruit.occlusion import fruit_occlusion
    from symfruit.settings import resolve_settings

    settings = resolve_settings(config=config) if config else resolve_settings()
    drawn = settings.extract.colour_trim_px == 0  # as detect: a mask the colour did not trim is as drawn
    src = open_source(folder)
    rows: list[dict] = []

    def sides(box, t):
        return (box.size[2] - t.size[2]) * 1000, (box.size[:2].max() - t.size[:2].max()) * 1000

    for index, name in enumerate(src.names()):
        frame = src.read(index)
        truth = frame.truth or []
        recorded = json.loads((Path(folder) / name / "truth.json").read_text())["fruits"]
        visible = {f["id"]: f.get("visible", np.nan) for f in recorded}
        found = detect(frame, method="evidence", settings=settings)
        ok = [d for d in found.detections if d.result is not None]
        cam = found.camera
        others = np.zeros(frame.depth.shape, bool)
        for d in found.detections:
            others |= d.mask
        for i, j in match([d.visible_box for d in ok], [b for _, b in truth]):
            d, (tid, t) = ok[i], truth[j]
            p = d.extraction.points
            on, behind, front = point_classes(p, t.centre, t.size)
            rr, cc = np.nonzero(d.mask)
            half = 0.5 * max(np.ptp(cc) + 1, np.ptp(rr) + 1) * float(np.median(p[:, 2])) / cam.fx
            dz, dl = sides(d.result.box, t)
            row = dict(frame=index, id=tid, visible=visible.get(tid, np.nan), iou=box_iou(d.result.box, t),
                       centre=centre_deviation(d.result.box, t) * 1000, depth=dz, lateral=dl,
                       thin=(thin_lens(d.mask, p, cam) - t.size[:2].max()) * 1000,
                       span_half=float(np.ptp(p[:, 2])) / half, n=len(p), behind=int(behind.sum()),
                       front=int(front.sum()))  # fmt: skip
            for label, keep in (("no_behind", ~behind), ("on_only", on)):
                row[f"{label}_depth"] = row[f"{label}_lateral"] = np.nan
                if keep.all():
                    row[f"{label}_depth"], row[f"{label}_lateral"] = dz, dl
                elif keep.sum() >= settings.extract.min_points:
                    occ = fruit_occlusion(frame.depth, d.mask, p[keep], cam, settings.occlusion, others=others,
                                          checked=True, eroded=settings.extract.erode_px, drawn=drawn)  # fmt: skip
                    r = complete(p[keep], camera=cam, method="evidence", settings=settings, occlusion=occ)
                    row[f"{label}_depth"], row[f"{label}_lateral"] = sides(r.box, t)
            rows.append(row)
    src.close()
    if out and rows:
        with open(out, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    return rows


def table(rows: list[dict]) -> str:
    """The rows by visible share: depth / lateral, mean absolute (signed) mm, per column."""
    r = {k: np.array([row[k] for row in rows], float) for k in rows[0]}
    lines = [f"{len(rows)} apples, IoU {r['iou'].mean():.3f}, centre {r['centre'].mean():.1f} mm",
             "| seen | n | box depth / lateral | thin-lens lateral | without behind | on the fruit only "
             "| span / half-width | behind, front share |",
             "|---|---|---|---|---|---|---|---|"]  # fmt: skip

    def cell(k, g):
        x = r[k][g]
        x = x[np.isfinite(x)]
        return f"{np.abs(x).mean():.1f} ({x.mean():+.1f})" if len(x) else "-"

    for label, lo, hi in GROUPS:
        g = (r["visible"] >= lo) & (r["visible"] < hi)
        if g.any():
            n = r["n"][g].sum()
            lines.append(f"| {label} | {g.sum()} | {cell('depth', g)} / {cell('lateral', g)} | {cell('thin', g)} | "
                         f"{cell('no_behind_depth', g)} / {cell('no_behind_lateral', g)} | "
                         f"{cell('on_only_depth', g)} / {cell('on_only_lateral', g)} | "
                         f"{r['span_half'][g].mean():.2f} | "
                         f"{r['behind'][g].sum() / n:.3f}, {r['front'][g].sum() / n:.3f} |")  # fmt: skip
    return "\n".join(lines)


def spans(folders: list[str]) -> None:
    from symfruit.detect import detect
    from symfruit.io.sources import open_source
    from symfruit.settings import resolve_settings

    out = sys.stdout
    out.write("| frame | fruit | mask half-width (mm) | depth span (mm) | span / half (1-99 %) | box (mm) |\n")
    out.write("|---|---|---|---|---|---|\n")
    for folder in folders:
        src = open_source(folder)
        for index, name in enumerate(src.names()):
            frame = src.read(index)
            found = detect(frame, method="evidence", settings=resolve_settings())
            cam = getattr(found, "camera", frame.camera)
            for d in found.detections:
                if d.result is None:
                    continue
                z = d.extraction.points[:, 2]
                rows, cols = np.nonzero(d.mask)
                half = 0.5 * max(np.ptp(cols) + 1, np.ptp(rows) + 1) * float(np.median(z)) / cam.fx
                inner = np.percentile(z, 99) - np.percentile(z, 1)
                box = " x ".join(f"{v * 1000:.0f}" for v in d.result.box.size)
                where = name if name == Path(folder).name else f"{Path(folder).name}/{name}"
                out.write(f"| {where} | {d.id} | {half * 1000:.1f} | {np.ptp(z) * 1000:.1f} | "
                          f"{np.ptp(z) / half:.2f} ({inner / half:.2f}) | {box} |\n")  # fmt: skip
        src.close()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="what", required=True)
    a = sub.add_parser("render", help="apple-tree frames with spur leaves")
    a.add_argument("out")
    a.add_argument("--seed", type=int, default=6)
    a.add_argument("--n", type=int, default=3)
    a.add_argument("--sensor-set", default=None)
    a.add_argument("--spur", type=int, default=4)
    b = sub.add_parser("classes", help="the extracted points by class, per apple")
    b.add_argument("folder")
    b.add_argument("--config", default=None)
    b.add_argument("--csv", default=None)
    c = sub.add_parser("spans", help="the depth span of each fruit's cloud in frames without truth")
    c.add_argument("frames", nargs="+")
    args = ap.parse_args()
    if args.what == "spans":
        spans(args.frames)
    elif args.what == "render":
        render(args.out, args.seed, args.n, args.sensor_set, args.spur)
    else:
        rows = classes(args.folder, args.config, args.csv)
        if not rows:
            sys.exit("no apple matched")
        sys.stdout.write(table(rows) + "\n")


if __name__ == "__main__":
    main()
