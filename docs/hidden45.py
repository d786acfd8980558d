"""Which stage puts an apple of the apple-tree frames off (stop 45, docs/hidden45.md): per apple matched by its mask's
label, its errors and the stage a rule assigns, counted for the mostly hidden apples (< 60 % seen) matched by
centre and for every apple over 30 mm off by label.

    python docs/hidden45.py --frames D [D2 ...] --seeds 0 [6 ...] [--config SETTINGS] [--out rows.jsonl]

Stages, first that holds: ``extraction`` (over a fifth of the points lie more than 10 mm outside the truth's box:
the mask, drawn over the leaf in front, gave extraction the leaf), ``mask merged`` (the mask covers another apple's
visible pixels, over a tenth of its own), ``seen-past cut`` (the time-of-flight overshoot cut,
:func:`symfruit.core.occlusion.overshoot`, took pixels), ``prior width`` (the width the prior reads over 12 mm off
the truth's lateral geometric mean), ``front hidden`` (the box front over 10 mm behind the truth's), ``back`` (the
box back over 10 mm off), else ``within``. The visible pixels come from the frame rendered again (as
docs/hidden_apples.py: ``--seeds``, one per folder).
"""

import argparse
import collections
import json
import sys
from pathlib import Path

import numpy as np

import symfruit.methods.evidence as evidence_module
from symfruit.detect import detect
from symfruit.evaluate.frames import match, score_frame
from symfruit.io.sources import open_source
from symfruit.settings import resolve_settings
from symfruit.synthetic.scenes import make_tree_scene

FUSED: dict = {}
_fuse = evidence_module.fuse_depth


def _recording_fuse(combined, cands, region, camera, **kwargs):
    box, sd, width = _fuse(combined, cands, region, camera, **kwargs)
    FUSED[tuple(np.round(np.r_[box.min, box.max], 9))] = max(combined.weights, key=combined.weights.get)
    return box, sd, width


evidence_module.fuse_depth = _recording_fuse


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
            labels = make_tree_scene(seed + index, n_apples=ripe, n_green=len(fruits) - ripe).labels
            ok = [d for d in found.detections if d.result is not None]
            gated = {ok[i].id for i, _ in match([d.visible_box for d in ok], list(truth.values()))}
            scores = {s.fruit: s for s in score_frame(frame, found, ["evidence"], settings, by_id=True)[0]}
            for d in ok:
                if d.id not in truth or d.id not in scores:
                    continue
                t, box, x, pts = truth[d.id], d.result.box, d.result.extras, d.extraction.points
                vis, occ = labels == d.id, d.occlusion
                other = (labels > 0) & ~vis
                cut = 0 if occ is None or occ.overshoot is None else int(occ.overshoot.sum())
                off = np.any((pts < t.min - 0.01) | (pts > t.max + 0.01), axis=1).mean()
                rows.append({
                    "frame": seed + index, "id": int(d.id), "gated": d.id in gated,
                    "visible": frame.visible.get(d.id, float("nan")), "centre": scores[d.id].centre_mm,
                    "iou": scores[d.id].iou, "front": 1000 * float(box.min[2] - t.min[2]),
                    "back": 1000 * float(box.max[2] - t.max[2]), "sizes": (1000 * (box.size - t.size)).tolist(),
                    "width": 1000 * (x["width"] - float(np.sqrt(t.size[0] * t.size[1]))),
                    "mask": int(d.mask.sum()), "visible_px": int(vis.sum()), "merged": int((d.mask & other).sum()),
                    "off": float(off), "cut": cut, "seen_past": bool(occ is not None and occ.seen_past),
                    "thin_lateral": scores[d.id].thin_lateral_mm,
                    "winner": FUSED.get(tuple(np.round(np.r_[box.min, box.max], 9)), ""),
                })  # fmt: skip
    finally:
        src.close()
    return rows


def stage(r: dict) -> str:
    if r["off"] > 0.2:
        return "extraction: points off the apple (its mask drawn over the leaf in front)"
    if r["merged"] > 0.1 * r["visible_px"]:
        return "mask merged with another apple"
    if r["seen_past"] and r["cut"] > 0:
        return "occlusion: seen-past cut"
    if abs(r["width"]) > 12:
        return "prior width over 12 mm off"
    if r["front"] > 10:
        return "completion: front hidden (box front over 10 mm behind)"
    if abs(r["back"]) > 10:
        return "completion: back over 10 mm off"
    return "within"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", nargs="+", required=True)
    parser.add_argument("--seeds", nargs="+", type=int, required=True)
    parser.add_argument("--config")
    parser.add_argument("--out")
    args = parser.parse_args()
    settings = resolve_settings(config=args.config)
    rows = [r for folder, seed in zip(args.frames, args.seeds, strict=True) for r in apples(folder, seed, settings)]
    if args.out:
        Path(args.out).write_text("\n".join(json.dumps(r) for r in rows) + "\n")
    groups = {
        "mostly hidden (< 60 % seen), matched by centre": [r for r in rows if r["visible"] < 0.6 and r["gated"]],
        "by label, over 30 mm": [r for r in rows if r["centre"] > 30],
    }
    for title, chosen in groups.items():
        sys.stdout.write(f"\n{title}: {len(chosen)}\n")
        for name, n in collections.Counter(stage(r) for r in chosen).most_common():
            sys.stdout.write(f"  {n:3d}  {name}\n")
    for lo, hi, title in ((0.9, 2.0, "visible"), (0.6, 0.9, "partly hidden"), (0.0, 0.6, "mostly hidden")):
        v = [r for r in rows if lo <= r["visible"] < hi and r["gated"]]
        if v:
            mean = {k: np.mean([r[k] for r in v]) for k in ("front", "back", "width")}
            sys.stdout.write(f"{title} (n {len(v)}): box front {mean['front']:+.1f}, back {mean['back']:+.1f}, "
                             f"prior width - truth's {mean['width']:+.1f} mm (mean signed)\n")  # fmt: skip


if __name__ == "__main__":
    main()
