"""The tree segmenter's missed yellow-green apple sides (issue 18, docs/seg65.md): cached renders, runs with two
experimental rules, apple-by-apple comparisons and oracle completions. Nothing here changes ``symfruit``; the rules
are patched in (``--seen``) or applied to saved labels (``band``), to measure what they would find.

    PYTHONPATH=src python docs/seg65.py cache FRAMES --seed 0 --n 24      # make_tree_scene(seed), pickled once
    PYTHONPATH=src python docs/seg65.py run FRAMES OUT --seed 0 --n 24 [--seen] [--set NAME=VALUE ...]
    PYTHONPATH=src python docs/seg65.py band FRAMES IN OUT --seed 0 --n 24
    PYTHONPATH=src python docs/seg65.py compare FRAMES A B --seed 0 --n 12
    PYTHONPATH=src python docs/seg65.py missed FRAMES LABELS --seed 0 --n 24
    PYTHONPATH=src python docs/seg65.py oracle FRAMES LABELS --seed 0 --n 12

``run`` segments each cached frame with the apple profile and saves ``labels_S.npy``; ``--seen`` patches
``_ground_steps`` so that a ground-colour pixel with no depth within ``GAP_PX`` (its gap-filled depth NaN, where no
step can be seen) is no candidate of a ground-colour body; ``--set`` sets a module constant of
``symfruit.segment.colour`` (``GROUND_BEHIND=0``). ``band`` grows each found region that has 20 or more pixels of
depth over the pixels without depth that are ground colour, not leaf, not found, and of a skin colour of this frame
(hue and saturation bins more frequent on the found fruit's ground-colour pixels with depth than on the frame's other
ground-colour pixels with depth, every 4th pixel; apples54's Bayes rule), connected to it, within the largest fruit's
diameter (``round_max_diameter`` at its median depth) of its centre; the growth is kept when the whole is no larger
than the largest fruit's disc and fills ``GROUND_SOLIDITY`` of its hull. ``compare`` prints ``docs/tree_masks.py``'s
counts for both and every apple whose best IoU moved by more than 0.01. ``missed`` lists each missed yellow-green side
with depth and what its missed pixels are. ``oracle`` counts how many yellow-green sides the region over each would
find if given the apple's own pixels without depth, or its own pixels at the region's depth.
"""

import argparse
import os
import pickle
import sys
from pathlib import Path
from typing import Any

import numpy as np
from scipy import ndimage
from tree_masks import false_kind, match  # docs/, beside this script
from tree_misses import classify

import symfruit.segment.colour as col
from symfruit.settings import resolve_settings
from symfruit.synthetic.scenes import make_tree_scene

say = sys.stdout.write


def frame(frames: Path, seed: int) -> Any:
    with open(frames / f"frame{seed}.pkl", "rb") as f:
        return pickle.load(f)


def cache(frames: Path, seeds: range) -> None:
    frames.mkdir(parents=True, exist_ok=True)
    for seed in seeds:
        path = frames / f"frame{seed}.pkl"
        if not path.exists():
            with open(path.with_suffix(".tmp"), "wb") as f:
                pickle.dump(make_tree_scene(seed), f)
            os.replace(path.with_suffix(".tmp"), path)


def seen_steps() -> None:
    """Patch ``_ground_steps``: at full resolution (``GAP_PX``), no pixel without depth within the box."""
    original = col._ground_steps

    def patched(color: np.ndarray, depth: np.ndarray, size: int, jump: float) -> np.ndarray:
        out = original(color, depth, size, jump)
        if size == col.GAP_PX:
            out &= ~np.isnan(col._gap_filled(depth, size))
        return out

    col._ground_steps = patched


def run(frames: Path, out: Path, seeds: range, seen: bool, values: list[str]) -> None:
    if seen:
        seen_steps()
    for item in values:
        name, value = item.split("=")
        setattr(col, name, float(value))
    out.mkdir(parents=True, exist_ok=True)
    settings = resolve_settings(fruit="apple").segment
    for seed in seeds:
        fr = frame(frames, seed)
        np.save(out / f"labels_{seed}.npy", col.segment(fr.color, fr.depth, fr.camera, settings))


def hue_sat(color: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    c = color.astype(np.float32)
    r, g, b = c[..., 0], c[..., 1], c[..., 2]
    top, low = np.maximum(np.maximum(r, g), b), np.minimum(np.minimum(r, g), b)
    d = np.maximum(top - low, 1)
    hue = np.where(top == r, 60 * (g - b) / d, np.where(top == g, 120 + 60 * (b - r) / d, 240 + 60 * (r - g) / d))
    return hue % 360, (top - low) / np.maximum(top, 1)


def skin_bins(color: np.ndarray) -> np.ndarray:
    """Each pixel's bin: 8 of hue over 40-80 degrees by 8 of saturation over 1/3-1 (apples54's bins)."""
    hue, sat = hue_sat(color)
    return np.clip(((hue - 40) / 5).astype(int), 0, 7) * 8 + np.clip(((sat - 1 / 3) * 12).astype(int), 0, 7)


def band(frames: Path, src: Path, out: Path, seeds: range) -> None:
    out.mkdir(parents=True, exist_ok=True)
    s = resolve_settings(fruit="apple").segment
    for seed in seeds:
        fr = frame(frames, seed)
        labels = np.load(src / f"labels_{seed}.npy")
        z = fr.depth
        ground = col._ground(fr.color)
        bins = skin_bins(fr.color)
        grid = np.zeros_like(ground)
        grid[::4, ::4] = True
        on = np.bincount(bins[ground & (labels > 0) & (z > 0)], minlength=64).astype(float)
        off = np.bincount(bins[ground & grid & (labels == 0) & (z > 0)], minlength=64).astype(float)
        grown = labels.copy()
        if on.sum() >= 100 and off.sum() >= 100:
            skin = ground & (on / on.sum() > off / off.sum())[bins] & (z <= 0) & ~col._leaf(fr.color)
            for k, sl in enumerate(ndimage.find_objects(labels), 1):
                if sl is not None:
                    _grow(grown, k, sl, skin, z, fr.camera.fx, s)
        np.save(out / f"labels_{seed}.npy", grown)


def _grow(labels: np.ndarray, k: int, sl: tuple[slice, slice], skin: np.ndarray, z: np.ndarray, focal: float,
          s: Any) -> None:  # fmt: skip
    region = labels[sl] == k
    zr = z[sl][region & (z[sl] > 0)]
    if len(zr) < 20:
        return
    far = s.round_max_diameter * focal / float(np.median(zr))
    rows, cols = np.nonzero(region)
    cy, cx = rows.mean() + sl[0].start, cols.mean() + sl[1].start
    pad = int(far) + 2
    win = (slice(max(int(cy) - pad, 0), int(cy) + pad), slice(max(int(cx) - pad, 0), int(cx) + pad))
    region = labels[win] == k
    yy, xx = np.indices(region.shape)
    disc = (yy + win[0].start - cy) ** 2 + (xx + win[1].start - cx) ** 2 <= far**2
    parts, _ = ndimage.label(region | (skin[win] & disc & (labels[win] == 0)))
    whole = np.isin(parts, np.unique(parts[region]))
    added = whole & ~region
    if not added.any() or whole.sum() > np.pi / 4 * far**2:
        return
    if whole.sum() < col.GROUND_SOLIDITY * col._hull_area(whole):
        return
    labels[win][added] = k


def truths(fr: Any) -> tuple[list[Any], np.ndarray]:
    ripe = [f for f in fr.fruits if f.ripe and (fr.labels == f.id).any()]
    ids = np.array([f.id for f in ripe])
    return ripe, fr.labels[None] == ids[:, None, None]


def score(frames: Path, out: Path, seeds: range) -> dict[tuple[int, int], float]:
    count = dict.fromkeys(("red", "red_found", "yellow", "yellow_found", "regions", "on_apple", "on_unripe",
                           "other"), 0)  # fmt: skip
    best: dict[tuple[int, int], float] = {}
    ious_all = []
    for seed in seeds:
        fr = frame(frames, seed)
        labels = np.load(out / f"labels_{seed}.npy")
        ripe_fruit, truth = truths(fr)
        ripe = np.array([f.id for f in fr.fruits if f.ripe])
        unripe = np.array([f.id for f in fr.fruits if not f.ripe])
        ious, ids, found, matched = match(truth, labels)
        red = col.redness(fr.color) >= 0.25
        for i, mask in enumerate(truth):
            kind = "red" if red[mask].mean() >= 0.5 else "yellow"
            count[kind] += 1
            count[kind + "_found"] += int(found[i])
            best[(seed, ripe_fruit[i].id)] = float(ious[i].max()) if ious.shape[1] else 0.0
            ious_all.append(best[(seed, ripe_fruit[i].id)])
        count["regions"] += len(ids)
        for k in ids[~matched]:
            count[false_kind(fr.labels[labels == k], ripe, unripe)] += 1
    total, hits = count["red"] + count["yellow"], count["red_found"] + count["yellow_found"]
    false = count["on_apple"] + count["on_unripe"] + count["other"]
    say(f"{out}: {hits} of {total} found, mean best IoU {np.mean(ious_all):.3f}; mostly red {count['red_found']} of "
        f"{count['red']}, yellow-green side {count['yellow_found']} of {count['yellow']}; {false} of "
        f"{count['regions']} false ({count['on_apple']} partial, {count['on_unripe']} unripe, {count['other']} "
        "other)\n")  # fmt: skip
    return best


def compare(frames: Path, a: Path, b: Path, seeds: range) -> None:
    before, after = score(frames, a, seeds), score(frames, b, seeds)
    for key, x in before.items():
        y = after.get(key, 0.0)
        if abs(x - y) > 0.01:
            mark = " GAINED" if x < 0.5 <= y else " LOST" if y < 0.5 <= x else ""
            say(f"  {key[0]}/{key[1]} {x:.2f} -> {y:.2f}{mark}\n")


def missed(frames: Path, out: Path, seeds: range) -> None:
    for seed in seeds:
        fr = frame(frames, seed)
        labels = np.load(out / f"labels_{seed}.npy")
        ripe, truth = truths(fr)
        ious, ids, found, _ = match(truth, labels)
        red, z = col.redness(fr.color) >= 0.25, fr.depth
        ground, leaf = col._ground(fr.color), col._leaf(fr.color)
        sizes = np.array([(labels == k).sum() for k in ids])
        on_fruit = np.array([((labels == k) & (fr.labels > 0)).sum() for k in ids])
        for i, f in enumerate(ripe):
            mask = truth[i]
            visible = f.visible if f.visible is not None else 1.0
            if found[i] or red[mask].mean() >= 0.5 or (z[mask] <= 0).mean() >= 0.95:
                continue
            cover = np.array([(labels[mask] == k).sum() for k in ids])
            kind = classify(int(mask.sum()), visible, cover, sizes, on_fruit - cover)
            k = int(np.argmax(cover)) if len(cover) else -1
            region = labels == ids[k] if k >= 0 and cover[k] > 0 else np.zeros_like(mask)
            miss = mask & ~region
            n = max(int(miss.sum()), 1)
            say(f"{seed}/{f.id} {kind} visible {visible:.2f} px {int(mask.sum())} IoU "
                f"{float(ious[i].max()) if ious.shape[1] else 0.0:.2f} without depth {(z[mask] <= 0).mean():.2f}; "
                f"missed px {int(miss.sum())}: without depth {(miss & (z <= 0)).sum() / n:.2f}, ground colour "
                f"{(miss & ground).sum() / n:.2f}, leaf hue {(miss & leaf).sum() / n:.2f}\n")  # fmt: skip


def oracle(frames: Path, out: Path, seeds: range) -> None:
    count = dict.fromkeys(("sides", "found", "own_gaps", "own_gaps_7px", "own_depth", "both"), 0)
    for seed in seeds:
        fr = frame(frames, seed)
        labels = np.load(out / f"labels_{seed}.npy")
        ripe, truth = truths(fr)
        red, z = col.redness(fr.color) >= 0.25, fr.depth
        for f, mask in zip(ripe, truth, strict=True):
            visible = f.visible if f.visible is not None else 1.0
            if red[mask].mean() >= 0.5 or (z[mask] <= 0).mean() > 0.95 or visible < 0.25:
                continue
            count["sides"] += 1
            ks, n = np.unique(labels[mask], return_counts=True)
            n, ks = n[ks > 0], ks[ks > 0]
            if len(ks) == 0:
                continue
            region = labels == ks[np.argmax(n)]
            near = ndimage.binary_dilation(region, iterations=7)
            zr = float(np.median(z[region & (z > 0)])) if (region & (z > 0)).any() else 0.0
            gaps, depth = region | (mask & (z <= 0)), region | (mask & (z > 0) & (np.abs(z - zr) < 0.05))
            for key, r in (("found", region), ("own_gaps", gaps), ("own_gaps_7px", region | (mask & (z <= 0) & near)),
                           ("own_depth", depth), ("both", gaps | depth)):  # fmt: skip
                count[key] += int((r & mask).sum() / (r | mask).sum() >= 0.5)
    say(f"{out} seeds {seeds.start}-{seeds.stop - 1}: {count}\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("command", choices=("cache", "run", "band", "compare", "missed", "oracle"))
    parser.add_argument("paths", nargs="+", type=Path, help="FRAMES, then the label folders the command names")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--n", type=int, default=12)
    parser.add_argument("--seen", action="store_true", help="run: patch in the seen-steps rule")
    parser.add_argument("--set", nargs="*", default=[], help="run: NAME=VALUE, a constant of segment.colour")
    args = parser.parse_args()
    seeds = range(args.seed, args.seed + args.n)
    frames, rest = args.paths[0], args.paths[1:]
    if args.command == "cache":
        cache(frames, seeds)
    elif args.command == "run":
        run(frames, rest[0], seeds, args.seen, args.set)
    elif args.command == "band":
        band(frames, rest[0], rest[1], seeds)
    elif args.command == "compare":
        compare(frames, rest[0], rest[1], seeds)
    elif args.command == "missed":
        missed(frames, rest[0], seeds)
    else:
        oracle(frames, rest[0], seeds)


if __name__ == "__main__":
    main()
