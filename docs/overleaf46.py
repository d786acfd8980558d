"""Why an apple of the apple-tree frames scored by its mask's label is off (stop 46, docs/overleaf46.md): per apple
its centre error by label, and for every apple over ``--over`` mm (default 15) the cause a rule assigns.

    python docs/overleaf46.py --frames D [D2 ...] --seeds 0 [6 ...] [--config SETTINGS] [--over 15] [--out rows.jsonl]

The frames are rendered again (one seed per folder, as docs/hidden45.py) to know, per colour pixel, which surface the
camera saw and its clean depth, and the registration offset the sensor model drew. Read from them:

- ``leaf px``: pixels of the mask as drawn whose surface is not the apple and lies in front of the apple's true
  centre (a leaf, a stem or another apple in front: the mask drawn over it);
- ``ahead``: the share of the extracted points more than 10 mm in front of the apple's true box;
- ``own``: the mask's (as registered) pixels whose depth lies within 10 mm of the apple's true box in depth
  and their count against the points within 10 mm of the true box (``kept``);
- ``reg``: the registration ``detect`` applied against the model's drawn offset (px, the larger axis).

Causes, the first that holds: ``leaf taken`` (``ahead`` over a fifth: leaf pixels inside the mask taken as the
fruit's surface), ``own dropped`` (fewer than half the ``own`` pixels kept as points), ``occluder unknown`` (the mask
holds leaf pixels, over a tenth of it, the points are the apple's: the outline over the leaf read as the apple's own,
the cut and the prior's width taken from it), ``registration`` (the applied shift over 3 px off the drawn one),
else ``other``.
"""

import argparse
import collections
import json
import sys
from pathlib import Path

import numpy as np

import symfruit.synthetic.scenes as scenes_module
from symfruit.detect import detect
from symfruit.evaluate.frames import match, score_frame
from symfruit.io.sources import open_source
from symfruit.settings import resolve_settings

RENDERED: dict = {}
_render, _apply = scenes_module.render, scenes_module.apply_sensor


def _recording_render(*args, **kwargs):
    shot = _render(*args, **kwargs)
    RENDERED.setdefault("shot", shot)  # the scene's own render (the apples rendered alone follow it)
    return shot


def _recording_apply(*args, **kwargs):
    RENDERED["sensed"] = out = _apply(*args, **kwargs)
    return out


scenes_module.render, scenes_module.apply_sensor = _recording_render, _recording_apply


def apples(folder: str, seed: int, settings) -> list[dict]:
    rows = []
    src = open_source(folder)
    try:
        for index, name in enumerate(src.names()):
            frame = src.read(index)
            truth = dict(frame.truth or [])
            found = detect(frame, method="evidence", settings=settings)
            fruits = json.loads((Path(folder) / name / "truth.json").read_text())["fruits"]
            ripe = sum(bool(f["ripe"]) for f in fruits)
            RENDERED.clear()
            scene = scenes_module.make_tree_scene(seed + index, n_apples=ripe, n_green=len(fruits) - ripe)
            shot, sensed = RENDERED["shot"], RENDERED["sensed"]
            ids, clean = shot.ids, np.where(np.isfinite(shot.depth), shot.depth, np.inf)
            drawn = np.asarray(frame.masks) if frame.masks is not None else scene.masks
            mesh = {f.id: f.mesh_index for f in scene.fruits}
            du, dv = sensed.shift
            ok = [d for d in found.detections if d.result is not None]
            gated = {ok[i].id for i, _ in match([d.visible_box for d in ok], list(truth.values()))}
            scores = {s.fruit: s for s in score_frame(frame, found, ["evidence"], settings, by_id=True)[0]}
            depth = np.asarray(frame.depth, dtype=np.float64)
            for d in ok:
                if d.id not in truth or d.id not in scores:
                    continue
                t, box, pts = truth[d.id], d.result.box, d.extraction.points
                as_drawn = drawn == d.id
                leaf = as_drawn & (ids != mesh[d.id]) & (clean < float(t.centre[2]))
                z = depth[d.mask]
                own = int(np.count_nonzero((z > t.min[2] - 0.01) & (z < t.max[2] + 0.01)))
                near = np.all((pts > t.min - 0.01) & (pts < t.max + 0.01), axis=1)
                rows.append({
                    "frame": seed + index, "id": int(d.id), "gated": d.id in gated,
                    "visible": frame.visible.get(d.id, float("nan")), "centre": scores[d.id].centre_mm,
                    "iou": scores[d.id].iou, "sizes": (1000 * (box.size - t.size)).tolist(),
                    "front": 1000 * float(box.min[2] - t.min[2]), "mask": int(as_drawn.sum()),
                    "leaf_px": int(leaf.sum()), "ahead": float(np.mean(pts[:, 2] < t.min[2] - 0.01)),
                    "points": len(pts), "kept": int(near.sum()), "own": own,
                    "shift": list(found.registration), "drawn_shift": [float(du), float(dv)],
                    "reg": float(max(abs(found.registration[0] - du), abs(found.registration[1] - dv))),
                    "seen_past": bool(d.occlusion is not None and d.occlusion.seen_past),
                })  # fmt: skip
    finally:
        src.close()
    return rows


def cause(r: dict) -> str:
    if r["ahead"] > 0.2:
        return "leaf taken (leaf pixels inside the mask taken as the fruit's surface)"
    if r["kept"] < 0.5 * r["own"]:
        return "own dropped (the fruit's own pixels dropped)"
    if r["leaf_px"] > 0.1 * r["mask"]:
        return "occluder unknown (the mask drawn over a leaf, points the apple's)"
    if r["reg"] > 3:
        return "registration"
    return "other"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", nargs="+", required=True)
    parser.add_argument("--seeds", nargs="+", type=int, required=True)
    parser.add_argument("--config")
    parser.add_argument("--over", type=float, default=15.0)
    parser.add_argument("--out")
    args = parser.parse_args()
    settings = resolve_settings(config=args.config)
    rows = [r for folder, seed in zip(args.frames, args.seeds, strict=True) for r in apples(folder, seed, settings)]
    if args.out:
        Path(args.out).write_text("\n".join(json.dumps(r) for r in rows) + "\n")
    centre = np.array([r["centre"] for r in rows])
    matched = [r["centre"] for r in rows if r["gated"]]
    sys.stdout.write(f"by label: {len(rows)} apples, centre mean / median {centre.mean():.2f} / "
                     f"{np.median(centre):.2f} mm, over 15 mm {int((centre > 15).sum())}, over 30 mm "
                     f"{int((centre > 30).sum())}; gated {len(matched)}, {np.mean(matched):.2f} mm\n")  # fmt: skip
    for lo, hi in ((args.over, 30.0), (30.0, np.inf)):
        chosen = [r for r in rows if lo < r["centre"] <= hi]
        sys.stdout.write(f"\nover {lo:g} mm{'' if hi == np.inf else f' to {hi:g}'}: {len(chosen)}\n")
        for name, n in collections.Counter(cause(r) for r in chosen).most_common():
            sys.stdout.write(f"  {n:3d}  {name}\n")
        for r in sorted(chosen, key=lambda r: -r["centre"]):
            sys.stdout.write(f"    seed {r['frame']:3d} id {r['id']:2d}: {r['centre']:6.1f} mm, seen "
                             f"{r['visible']:.2f}, mask {r['mask']} px (leaf {r['leaf_px']}), points "
                             f"{r['points']} (ahead {r['ahead']:.2f}, on the apple {r['kept']} of {r['own']}), "
                             f"shift {r['shift']} drawn ({r['drawn_shift'][0]:.1f}, {r['drawn_shift'][1]:.1f}), "
                             f"front {r['front']:+.0f} mm: {cause(r).split(' (')[0]}\n")  # fmt: skip


if __name__ == "__main__":
    main()
