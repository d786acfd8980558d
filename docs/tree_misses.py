"""Why the colour segmenter with depth misses apples on rendered apple trees (issue 18): every ripe apple not
matched at mask IoU 0.5 (as ``docs/tree_masks.py``) is put in one class, the first that holds:

- ``hidden``: under a quarter of the apple's silhouette visible (``SceneFruit.visible``);
- ``tiny``: under 600 visible pixels (a disc under about 28 px across);
- ``none``: no region covers a fifth of its visible pixels (not found at all);
- ``merged``: the region covering most of it covers another apple's pixels as well (a fifth of its own area);
- ``split``: two or more regions each cover a fifth of it, none enough for IoU 0.5;
- ``under``: one region, covering under 0.6 of it (part of the apple: a shaded side, a piece beyond a leaf);
- ``over``: one region, over 1.6 times the apple's pixels (spilling onto leaves or bark);
- ``other``.

Each class is reported with its apples' visible pixels, depth (the box centre), visible share, share of red
pixels (redness 0.25 or more) and HSV value (median of the true pixels; the shaded side is dark) and best IoU.
False regions (matched to no apple) are put by what lies under them, as in ``docs/tree_masks.py``, with their
size in pixels; ``--list`` prints every missed apple.

    python docs/tree_misses.py [--seed 0] [--n 12] [--list]
"""

import argparse
import colorsys
import sys

import numpy as np
from tree_masks import false_kind, match  # docs/tree_masks.py, beside this script

from symfruit.segment.colour import redness, segment
from symfruit.settings import resolve_settings
from symfruit.synthetic.scenes import make_tree_scene

CLASSES = ("hidden", "tiny", "none", "merged", "split", "under", "over", "other")


def classify(area: int, visible: float, cover: np.ndarray, sizes: np.ndarray, foreign: np.ndarray) -> str:
    """The class of one missed apple: ``cover`` its pixels under each region, ``sizes`` each region's pixels,
    ``foreign`` each region's pixels on other apples (ripe or not)."""
    if visible < 0.25:
        return "hidden"
    if area < 600:
        return "tiny"
    big = np.flatnonzero(cover >= 0.2 * area)
    if len(big) == 0:
        return "none"
    k = int(np.argmax(cover))
    if foreign[k] >= 0.2 * area:
        return "merged"
    if len(big) >= 2:
        return "split"
    if cover[k] < 0.6 * area:
        return "under"
    if sizes[k] > 1.6 * area:
        return "over"
    return "other"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--n", type=int, default=12)
    parser.add_argument("--list", action="store_true", help="print every missed apple")
    args = parser.parse_args()
    settings = resolve_settings(fruit="apple").segment
    rows: list[tuple] = []
    false: dict[str, list[int]] = {"on_apple": [], "on_unripe": [], "other": []}
    total = 0
    for seed in range(args.seed, args.seed + args.n):
        frame = make_tree_scene(seed)
        ripe = [f for f in frame.fruits if f.ripe and (frame.labels == f.id).any()]
        unripe = np.array([f.id for f in frame.fruits if not f.ripe])
        ids = np.array([f.id for f in ripe])
        truth = frame.labels[None] == ids[:, None, None]
        total += len(ripe)
        labels = segment(frame.color, frame.depth, frame.camera, settings)
        ious, rids, found, matched = match(truth, labels)
        red = redness(frame.color) >= 0.25
        sizes = np.array([(labels == k).sum() for k in rids])
        on_fruit = np.array([((labels == k) & (frame.labels > 0)).sum() for k in rids])
        for i in np.flatnonzero(~found):
            mask = truth[i]
            area = int(mask.sum())
            cover = np.array([(labels[mask] == k).sum() for k in rids])
            foreign = on_fruit - cover
            f = ripe[i]
            kind = classify(area, f.visible if f.visible is not None else 1.0, cover, sizes, foreign)
            rgb = np.median(frame.color[mask], axis=0) / 255.0
            hue, sat, val = colorsys.rgb_to_hsv(*rgb)
            best = float(ious[i].max()) if ious.shape[1] else 0.0
            seen = float((frame.depth[mask] > 0).mean())
            rows.append((kind, seed, f.id, area, float(f.box.centre[2]), f.visible or 1.0,
                         float(red[mask].mean()), 360 * hue, sat, val, best, seen))  # fmt: skip
        for k, size in zip(rids[~matched], sizes[~matched], strict=True):
            false[false_kind(frame.labels[labels == k], ids, unripe)].append(int(size))
    out = sys.stdout
    out.write(f"seeds {args.seed}-{args.seed + args.n - 1}: {len(rows)} of {total} apples missed\n")
    out.write("class   n  pixels(med)  z(m)  visible  red   hue  sat  value  bestIoU  depth\n")
    for c in CLASSES:
        sel = [r for r in rows if r[0] == c]
        if not sel:
            continue
        m = np.median(np.array([r[3:] for r in sel], float), axis=0)
        out.write(f"{c:7s} {len(sel):2d}  {m[0]:8.0f}  {m[1]:6.2f}  {m[2]:6.2f}  {m[3]:5.2f}  {m[4]:4.0f}  "
                  f"{m[5]:4.2f}  {m[6]:4.2f}  {m[7]:6.2f}  {m[8]:5.2f}\n")  # fmt: skip
    for key, sz in false.items():
        med = f", median {np.median(sz):.0f} px" if sz else ""
        out.write(f"false {key}: {len(sz)}{med}\n")
    if args.list:
        out.write("class seed apple pixels z visible red hue sat value bestIoU depth\n")
        for r in sorted(rows):
            out.write(" ".join(f"{v:.2f}" if isinstance(v, float) else str(v) for v in r) + "\n")


if __name__ == "__main__":
    main()
