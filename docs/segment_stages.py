"""Where the colour segmenter's time goes on rendered apple-tree frames (issue 19): the thread's CPU time of each of
its stages per frame (the stage functions of ``symfruit.segment.colour`` wrapped; a stage called inside another is
counted in the outer one alone), and of the whole ``segment`` call, over seeds ``--seed`` on (1920x1080 with depth,
the apple profile's settings, as ``symfruit bench --segment --scene apple-tree``), each frame ``--repeat`` times after
one warm-up pass; means per frame. Run with ``PYTHONPATH=TREE/src`` for another tree.

    python docs/segment_stages.py [--seed 0] [--n 6] [--repeat 5]
"""

import argparse
import collections
import sys
import time

import symfruit.segment.colour as colour
from symfruit.settings import resolve_settings
from symfruit.synthetic.scenes import make_tree_scene

#: The stages timed: what ``_segment_at`` calls, and the set-up in ``segment`` (each name a function of the module).
STAGES = ("_depth", "_coarse_regions", "_red_windows", "_red_pixels", "_least_areas", "_one_fruit", "_ripe_cores",
          "_split", "_merge", "_ground_bodies", "_round_skin", "_join_bodies", "_hull_mask", "_green",
          "_depth_consistent", "_fruit_sized", "redness", "median", "_box_centre")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--n", type=int, default=6)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    spent: collections.Counter[str] = collections.Counter()
    calls: collections.Counter[str] = collections.Counter()
    inside = [0]

    def wrap(name: str) -> None:
        fn = getattr(colour, name)

        def timed(*a, **k):
            if inside[0]:
                return fn(*a, **k)
            inside[0] += 1
            start = time.thread_time()
            try:
                return fn(*a, **k)
            finally:
                spent[name] += time.thread_time() - start
                calls[name] += 1
                inside[0] -= 1

        setattr(colour, name, timed)

    for name in STAGES:
        if hasattr(colour, name):
            wrap(name)
    settings = resolve_settings(fruit="apple").segment
    frames = [make_tree_scene(seed) for seed in range(args.seed, args.seed + args.n)]
    for f in frames:
        colour.segment(f.color, f.depth, f.camera, settings)
    spent.clear()
    calls.clear()
    total = 0.0
    for _ in range(args.repeat):
        for f in frames:
            start = time.thread_time()
            colour.segment(f.color, f.depth, f.camera, settings)
            total += time.thread_time() - start
    runs = args.repeat * len(frames)
    sys.stdout.write(f"segment: {1000 * total / runs:.1f} ms CPU per frame ({runs} runs)\n")
    for name, t in spent.most_common():
        sys.stdout.write(f"  {name:18s} {1000 * t / runs:6.2f} ms  {calls[name] / runs:6.1f} calls\n")
    rest = total - sum(spent.values())
    sys.stdout.write(f"  {'(the rest)':18s} {1000 * rest / runs:6.2f} ms\n")


if __name__ == "__main__":
    main()
