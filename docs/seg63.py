"""The colour segmenter with depth on rendered apple trees, two source trees compared apple by apple (docs/seg63.md).

    PYTHONPATH=BEFORE/src python docs/seg63.py run OUT_A [--seed 0] [--n 12]
    PYTHONPATH=src python docs/seg63.py run OUT_B [--seed 0] [--n 12]
    python docs/seg63.py compare OUT_A OUT_B [--seed 0] [--n 12] [--list]

``run`` segments ``make_tree_scene(seed)`` with the apple profile and saves each frame's labels (``labels_S.npy``);
``compare`` prints, for each, ``docs/tree_masks.py``'s counts (found at mask IoU 0.5, mostly red and yellow-green
sides, false regions by what lies under them), the mean best-match IoU, the misses by ``docs/tree_misses.py``'s
classes (``--list``: each missed apple of OUT_B), and every apple whose best IoU moved by more than 0.01.
"""

import argparse
import sys
from collections import Counter
from pathlib import Path

import numpy as np
from tree_masks import false_kind, match  # docs/, beside this script
from tree_misses import classify

from symfruit.segment.colour import redness, segment
from symfruit.settings import resolve_settings
from symfruit.synthetic.scenes import make_tree_scene

say = sys.stdout.write


def run(out: Path, seeds: range) -> None:
    out.mkdir(parents=True, exist_ok=True)
    settings = resolve_settings(fruit="apple").segment
    for seed in seeds:
        frame = make_tree_scene(seed)
        np.save(out / f"labels_{seed}.npy", segment(frame.color, frame.depth, frame.camera, settings))


def score(out: Path, seeds: range, listed: bool) -> dict[tuple[int, int], float]:
    """Print one tree's counts; return each apple's best IoU by (seed, apple id)."""
    count = dict.fromkeys(("red", "red_found", "yellow", "yellow_found", "regions", "on_apple", "on_unripe",
                           "other"), 0)  # fmt: skip
    best: dict[tuple[int, int], float] = {}
    kinds: Counter[str] = Counter()
    for seed in seeds:
        frame = make_tree_scene(seed)
        labels = np.load(out / f"labels_{seed}.npy")
        ripe_fruit = [f for f in frame.fruits if f.ripe and (frame.labels == f.id).any()]
        ripe = np.array([f.id for f in frame.fruits if f.ripe])
        unripe = np.array([f.id for f in frame.fruits if not f.ripe])
        ids = np.array([f.id for f in ripe_fruit])
        truth = frame.labels[None] == ids[:, None, None]
        ious, rids, found, matched = match(truth, labels)
        red = redness(frame.color) >= 0.25
        sizes = np.array([(labels == k).sum() for k in rids])
        on_fruit = np.array([((labels == k) & (frame.labels > 0)).sum() for k in rids])
        for i, mask in enumerate(truth):
            kind = "red" if red[mask].mean() >= 0.5 else "yellow"
            count[kind] += 1
            count[kind + "_found"] += int(found[i])
            best[(seed, int(ids[i]))] = float(ious[i].max()) if ious.shape[1] else 0.0
            if not found[i]:
                cover = np.array([(labels[mask] == k).sum() for k in rids])
                visible = ripe_fruit[i].visible
                why = classify(int(mask.sum()), 1.0 if visible is None else visible, cover, sizes, on_fruit - cover)
                kinds[f"{why} ({kind})"] += 1
                if listed:
                    say(f"  missed {seed}/{ids[i]}: {kind}, {why}, best IoU {best[(seed, int(ids[i]))]:.2f}\n")
        count["regions"] += len(rids)
        for k in rids[~matched]:
            count[false_kind(frame.labels[labels == k], ripe, unripe)] += 1
    total, hits = count["red"] + count["yellow"], count["red_found"] + count["yellow_found"]
    false = count["on_apple"] + count["on_unripe"] + count["other"]
    say(f"{out}: {hits} of {total} found ({hits / total:.1%}), mean best-match IoU {np.mean(list(best.values())):.3f}; "
        f"mostly red {count['red_found']} of {count['red']}, yellow-green side {count['yellow_found']} of "
        f"{count['yellow']}; {false} of {count['regions']} false ({count['on_apple']} partial, {count['on_unripe']} "
        f"unripe, {count['other']} other)\n  misses: {dict(sorted(kinds.items()))}\n")  # fmt: skip
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("command", choices=("run", "compare"))
    parser.add_argument("dirs", nargs="+", type=Path, help="run: OUT; compare: OUT_A OUT_B")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--n", type=int, default=12)
    parser.add_argument("--list", action="store_true", help="compare: list OUT_B's missed apples")
    args = parser.parse_args()
    seeds = range(args.seed, args.seed + args.n)
    if args.command == "run":
        run(args.dirs[0], seeds)
        return
    if len(args.dirs) != 2:
        parser.error("compare takes OUT_A OUT_B")
    before = score(args.dirs[0], seeds, False)
    after = score(args.dirs[1], seeds, args.list)
    for key, a in before.items():
        b = after.get(key, 0.0)
        if abs(a - b) > 0.01:
            mark = " gained" if a < 0.5 <= b else " lost" if b < 0.5 <= a else ""
            say(f"  {key[0]}/{key[1]}: {a:.2f} -> {b:.2f}{mark}\n")


if __name__ == "__main__":
    main()
