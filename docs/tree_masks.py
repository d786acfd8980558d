"""Where the colour segmenter with depth finds and misses apples on rendered apple trees (issue 18): each ripe
apple is counted as showing mostly red skin (at least half its visible pixels of redness 0.25 or more) or
mostly its yellow-green side; each false region as lying mostly on a ripe apple (a partial mask), on an
unripe green apple, or on neither (bark, leaves). Matching as ``symfruit evaluate --protocol masks`` (mask
IoU 0.5, one to one), with the apple profile's segmenter settings; CPU time per frame (the fastest of
``--repeat`` runs, median over frames).

    python docs/tree_masks.py [--seed 0] [--n 12] [--repeat 1]
"""

import argparse
import sys
import time

import numpy as np

from symfruit.evaluate.masks import mask_ious, match_masks
from symfruit.segment.colour import redness, segment
from symfruit.settings import resolve_settings
from symfruit.synthetic.scenes import make_tree_scene


def match(truth: np.ndarray, labels: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(ious, ids, found, matched)``: the truth masks (k, h, w) against the segmenter's regions as ``symfruit
    evaluate --protocol masks`` matches them (IoU 0.5, one to one), which truth masks were found and which
    regions matched one (also docs/tree_misses.py's)."""
    ious, ids = mask_ious(truth, labels)
    pairs = match_masks(ious)
    found = np.zeros(len(truth), bool)
    found[pairs[:, 0]] = True
    matched = np.zeros(len(ids), bool)
    matched[pairs[:, 1]] = True
    return ious, ids, found, matched


def false_kind(under: np.ndarray, ripe: np.ndarray, unripe: np.ndarray) -> str:
    """Where a false region lies (``under``: the true labels of its pixels): mostly (over 30 %) on a ripe apple,
    else mostly on an unripe one, else on neither."""
    if np.isin(under, ripe).mean() > 0.3:
        return "on_apple"
    return "on_unripe" if np.isin(under, unripe).mean() > 0.3 else "other"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--n", type=int, default=12)
    parser.add_argument("--repeat", type=int, default=1, help="timed runs per frame (the fastest kept)")
    args = parser.parse_args()
    settings = resolve_settings(fruit="apple").segment
    count = dict.fromkeys(("red", "red_found", "yellow", "yellow_found", "regions", "on_apple", "on_unripe",
                           "other"), 0)  # fmt: skip
    cpu = []
    for seed in range(args.seed, args.seed + args.n):
        frame = make_tree_scene(seed)
        ripe = np.array([f.id for f in frame.fruits if f.ripe])
        unripe = np.array([f.id for f in frame.fruits if not f.ripe])
        truth = frame.labels[None] == ripe[:, None, None]
        truth = truth[truth.reshape(len(ripe), -1).any(axis=1)]
        best = float("inf")
        for _ in range(max(1, args.repeat)):
            start = time.process_time()
            labels = segment(frame.color, frame.depth, frame.camera, settings)
            best = min(best, time.process_time() - start)
        cpu.append(1000 * best)
        _, ids, found, matched = match(truth, labels)
        red = redness(frame.color) >= 0.25
        for mask, hit in zip(truth, found, strict=True):
            kind = "red" if red[mask].mean() >= 0.5 else "yellow"
            count[kind] += 1
            count[kind + "_found"] += int(hit)
        count["regions"] += len(ids)
        for k in ids[~matched]:
            count[false_kind(frame.labels[labels == k], ripe, unripe)] += 1
    total, hits = count["red"] + count["yellow"], count["red_found"] + count["yellow_found"]
    false = count["on_apple"] + count["on_unripe"] + count["other"]
    sys.stdout.write(
        f"seeds {args.seed}-{args.seed + args.n - 1}: {hits} of {total} apples found ({hits / total:.1%}); "
        f"mostly red {count['red_found']} of {count['red']}, yellow-green side {count['yellow_found']} of "
        f"{count['yellow']}; {false} of {count['regions']} found false ({count['on_apple']} partial masks of an "
        f"apple, {count['on_unripe']} on unripe apples, {count['other']} on bark or leaves); "
        f"{np.median(cpu):.0f} ms CPU per frame (median)\n"
    )


if __name__ == "__main__":
    main()
