"""Hidden apples' boxes (docs/ablation.md, "Hidden apples' boxes (issue 18, stop 38)"): what `evidence` makes of
each apple of apple-tree frames (`symfruit scenes D --scene apple-tree --n 6 --seed 0`), by visible share.

    python docs/hidden_apples.py --frames D [D12 ...] [--seeds 0 [12 ...]] [--config SETTINGS]

Each frame's apples are found and completed as `symfruit evaluate --frames D --methods evidence` finds them
(``detect``'s masks, colour-trimmed) and matched to the truth by the centre of their seen points' box. Tables
(mm; mean absolute error, the mean signed in brackets, against the truth's box):

1. the width the depth prior could read against the truth's depth side: the geometric mean of the silhouette's
   two widths across the line of sight (``prior_width`` with a whole outline) and the larger width alone, both
   at the distance ``evidence`` reads them at;
2. the mostly hidden apples (< 60 % seen) split by the annotators' mask: drawn over the leaf in front (over
   1.25 times the apple's visible pixels, plus 30) or the visible part alone; their depth side's signed error
   and the geometric-mean width's against the truth's (the geometric mean of its two lateral sides). Needs the
   frames' seeds (``--seeds``, as given to `symfruit scenes --seed`, one per folder): the visible pixels are
   rendered again (``make_tree_scene``);
3. the box's front against the truth's, and the apples whose front lies over ``--far`` mm behind it (the
   nearest part of the apple hidden);
4. every apple matched by its mask's label instead (as `symfruit evaluate --match id`: ``score_frame(...,
   by_id=True)``): IoU / centre mean (median), and how many are over 30 mm off.

``--config``: a settings file (as `symfruit evaluate --config`), e.g. ``evidence: {cut_width: 1}`` for the apple
profile's width (the default is 0, the geometric mean; stop 38's figures were taken with 1 as the default, their
"before" with ``cut_width: 0``). Table 1 and table 2's widths do not depend on ``cut_width``.
"""

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from symfruit.core.occlusion import with_own
from symfruit.core.raster import across_sight, close_ragged, silhouette
from symfruit.detect import detect
from symfruit.evaluate.frames import match, score_frame
from symfruit.io.sources import open_source
from symfruit.methods.evidence import prior_width
from symfruit.settings import Settings, resolve_settings
from symfruit.synthetic.scenes import make_tree_scene

GROUPS = {"visible": (0.9, 2.0), "partly hidden": (0.6, 0.9), "mostly hidden": (0.0, 0.6)}


def apples(folder: str, seed: int | None, settings: Settings):
    """Per matched apple a dict of signed errors (mm) and its visible share; and every id-matched score."""
    s = settings.evidence
    rows, by_id = [], []
    src = open_source(folder)
    try:
        for index, name in enumerate(src.names()):
            frame = src.read(index)
            truth = frame.truth or []
            found = detect(frame, method="evidence", settings=settings)
            by_id += score_frame(frame, found, ["evidence"], settings, by_id=True)[0]
            labels = None
            if seed is not None:  # the frame rendered again, as `symfruit scenes` wrote it (its apple counts)
                fruits = json.loads((Path(folder) / name / "truth.json").read_text())["fruits"]
                ripe = sum(bool(f["ripe"]) for f in fruits)
                scene = make_tree_scene(seed + index, n_apples=ripe, n_green=len(fruits) - ripe)
                if frame.masks is None or not np.array_equal(scene.masks, frame.masks):
                    raise SystemExit(f"{folder}/{name}: not seed {seed + index}'s apple-tree frame (masks differ)")
                labels = scene.labels
            ok = [d for d in found.detections if d.result is not None]
            for i, j in match([d.visible_box for d in ok], [b for _, b in truth]):
                d, (tid, t) = ok[i], truth[j]
                box, x = d.result.box, d.result.extras
                points = d.extraction.points
                region = close_ragged(silhouette(points, found.camera), radius=s.ragged_close_px, ragged=s.ragged_at)
                if d.occlusion is not None:
                    region = with_own(region, d.occlusion)
                across = across_sight(region, found.camera)
                dist = x["width"] / prior_width(across, x["contour"], s.cut_width)  # evidence's distance
                geo, big = dist * np.sqrt(across.minor * across.major), dist * across.major
                amodal = None
                if labels is not None:
                    amodal = bool((frame.masks == d.id).sum() > 1.25 * (labels == tid).sum() + 30)
                rows.append({
                    "visible": frame.visible.get(tid, float("nan")), "amodal": amodal,
                    "depth": 1000 * (box.size[2] - t.size[2]), "front": 1000 * (box.min[2] - t.min[2]),
                    "geo - D": 1000 * (geo - t.size[2]), "big - D": 1000 * (big - t.size[2]),
                    "geo - W": 1000 * (geo - np.sqrt(t.size[0] * t.size[1])),
                })  # fmt: skip
    finally:
        src.close()
    return rows, by_id


def cell(values: list[float]) -> str:
    v = np.asarray(values, float)
    return f"{np.abs(v).mean():.1f} ({v.mean():+.1f})" if len(v) else "-"


def signed(values: list[float]) -> str:
    return f"{np.mean(values):+.1f}" if values else "-"


def table(title: str, head: list[str], rows: list[list[str]]) -> None:
    sys.stdout.write(f"\n| {title} | " + " | ".join(head) + " |\n|" + "---|" * (len(head) + 1) + "\n")
    for row in rows:
        sys.stdout.write("| " + " | ".join(row) + " |\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", nargs="+", required=True, help="folders of apple-tree frames (`symfruit scenes`)")
    parser.add_argument("--seeds", nargs="+", type=int, help="their `symfruit scenes --seed`, one per folder "
                        "(for table 2; without it, table 2 is left out)")  # fmt: skip
    parser.add_argument("--config", help="settings file (YAML/JSON), as `symfruit evaluate --config`")
    parser.add_argument("--far", type=float, default=15.0, help="table 3: a front this far behind (mm) is counted")
    args = parser.parse_args()
    if args.seeds is not None and len(args.seeds) != len(args.frames):
        parser.error(f"--seeds: one per --frames folder ({len(args.frames)}), got {len(args.seeds)}")
    settings = resolve_settings(config=args.config)
    seeds = args.seeds or [None] * len(args.frames)
    rows, by_id = [], []
    for folder, seed in zip(args.frames, seeds, strict=True):
        r, b = apples(folder, seed, settings)
        rows += r
        by_id += b
    group = {g: [r for r in rows if lo <= r["visible"] < hi] for g, (lo, hi) in GROUPS.items()}
    out = sys.stdout
    out.write(f"{len(rows)} matched apples; cut_width {settings.evidence.cut_width:g}\n")
    table("width the prior could read", [f"{g} ({len(v)})" for g, v in group.items()], [
        [name] + [cell([r[key] for r in v]) for v in group.values()]
        for name, key in (("geometric mean of the silhouette's two widths", "geo - D"),
                          ("the larger width alone", "big - D"))])  # fmt: skip
    mostly = group["mostly hidden"]
    if args.seeds is not None:
        kinds = {"drawn over the leaf": True, "visible part only": False}
        split = {name: [r for r in mostly if r["amodal"] is kind] for name, kind in kinds.items()}
        table("mostly hidden, mask", ["n", "depth side (signed)", "width - truth's (signed)"], [
            [name, str(len(v)), signed([r["depth"] for r in v]), signed([r["geo - W"] for r in v])]
            for name, v in split.items()])  # fmt: skip
    table("box front behind the truth's (mean)", list(group), [["mm"] + [signed([r["front"] for r in v])
                                                                          for v in group.values()]])  # fmt: skip
    far = sorted(r["front"] for r in mostly if r["front"] > args.far)
    span = f" ({far[0]:.0f}-{far[-1]:.0f} mm)" if far else ""
    out.write(f"\nmostly hidden with the front over {args.far:g} mm behind: {len(far)} of {len(mostly)}{span}\n")
    c = np.array([s.centre_mm for s in by_id])
    iou = np.mean([s.iou for s in by_id]) if by_id else float("nan")
    out.write(f"\nmatched by the mask's label (--match id): {len(c)} apples, IoU {iou:.3f}, centre {c.mean():.1f} mm "
              f"(median {np.median(c):.1f}), {(c > 30).sum()} over 30 mm\n")  # fmt: skip


if __name__ == "__main__":
    main()
