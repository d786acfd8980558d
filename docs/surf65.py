"""Replay of the benchmark frame's front rings and kept caps (``detect._front_trimmed`` and ``detect._kept_caps``, the
15 ``fruit_surface`` calls of ``extract.front_ring`` and ``extract.own_cap``) for two source trees, alternated: the
thread's CPU time of the pair a frame, median and least over the rounds (surf65, docs/surf65.md).

    python docs/surf65.py BEFORE/src AFTER/src [--rounds 6] [--repeat 40]

Each round starts a fresh process per tree (``PYTHONPATH``), runs ``detect`` once on ``symfruit bench --frame``'s
frame with the two functions recording their arguments, then times the pair ``--repeat`` times on them (a tree
whose ``_front_trimmed`` takes ``readings`` hands them to ``_kept_caps``, as ``detect`` does).
"""

import argparse
import json
import os
import subprocess
import sys

import numpy as np

CHILD = """
import inspect, json, sys, time
import symfruit.detect as D
from symfruit.evaluate.bench import _bench_scene
repeat = int(sys.argv[1])
frame, _ = _bench_scene(None, 0)
seen = {}
real = {name: getattr(D, name) for name in ("_front_trimmed", "_kept_caps")}
for name, fn in real.items():
    def keep(*a, _name=name, _fn=fn):
        seen[_name] = a
        return _fn(*a)
    setattr(D, name, keep)
D.detect(frame, method="evidence")
for name, fn in real.items():
    setattr(D, name, fn)
shares = "readings" in inspect.signature(D._front_trimmed).parameters
fa, ka = seen["_front_trimmed"], seen["_kept_caps"]
fa, ka = fa[:8], ka[:8]
spent = []
for _ in range(repeat):
    start = time.thread_time()
    readings = {} if shares else None
    D._front_trimmed(*fa, readings) if shares else D._front_trimmed(*fa)
    D._kept_caps(*ka, readings) if shares else D._kept_caps(*ka)
    spent.append(time.thread_time() - start)
print(json.dumps(spent))
"""


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("before", help="the first tree's src folder")
    p.add_argument("after", help="the second tree's src folder")
    p.add_argument("--rounds", type=int, default=6)
    p.add_argument("--repeat", type=int, default=40, help="timed pairs a round and tree")
    args = p.parse_args()
    trees = {"before": os.path.abspath(args.before), "after": os.path.abspath(args.after)}
    spent: dict[str, list[float]] = {name: [] for name in trees}
    for _ in range(args.rounds):
        for name, src in trees.items():
            out = subprocess.run([sys.executable, "-c", CHILD, str(args.repeat)],
                                 env={**os.environ, "PYTHONPATH": src}, capture_output=True, text=True,
                                 check=True)  # fmt: skip
            spent[name] += json.loads(out.stdout.strip().splitlines()[-1])
    sys.stdout.write("front rings and kept caps of the benchmark frame: thread CPU ms, median / least\n")
    for name, values in spent.items():
        ms = np.array(values) * 1e3
        sys.stdout.write(f"{name:>7s} {np.median(ms):7.3f} / {ms.min():7.3f}\n")


if __name__ == "__main__":
    main()
