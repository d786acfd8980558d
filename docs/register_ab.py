"""Interleaved A/B of ``register`` and ``trim_labels`` alone on a benchmark frame's own inputs (those ``detect``
hands them, captured once per process): the thread's CPU time per call, median and least, the trees alternated
process by process (stop 42, docs/speedreg42.md).

    python docs/register_ab.py BEFORE/src AFTER/src [--rounds 4] [--calls 20] [--seed 0]

``--seed``: the frame of ``symfruit bench --frame`` (``_bench_scene(None, seed)``; 0 is the benchmark's).
"""

import argparse
import json
import os
import subprocess
import sys

import numpy as np

CHILD = r"""
import json, sys, time
import symfruit.detect as D
from symfruit.evaluate.bench import _bench_scene
frame, _ = _bench_scene(None, int(sys.argv[2]))
seen = {}
trim, register = D.trim_labels, D.register
def keep(name, fn):
    def kept(*a, **k):
        seen[name] = (a, k)
        return fn(*a, **k)
    return kept
D.trim_labels, D.register = keep("trim", trim), keep("register", register)
D.detect(frame, method="evidence")
calls = {"trim": trim, "register": register}
out = {"trim": [], "register": []}
for i in range(3 + int(sys.argv[1])):
    for name, fn in calls.items():
        start = time.thread_time()
        fn(*seen[name][0], **seen[name][1])
        if i >= 3:
            out[name].append(time.thread_time() - start)
print(json.dumps(out))
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument("--rounds", type=int, default=4)
    parser.add_argument("--calls", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    got: dict[str, dict[str, list[float]]] = {t: {"trim": [], "register": []} for t in (args.before, args.after)}
    for i in range(args.rounds):
        for tree in (args.before, args.after) if i % 2 == 0 else (args.after, args.before):
            env = {**os.environ, "PYTHONPATH": tree}
            res = subprocess.run([sys.executable, "-c", CHILD, str(args.calls), str(args.seed)], env=env,
                                 capture_output=True, text=True, check=True)  # fmt: skip
            for name, times in json.loads(res.stdout.strip().splitlines()[-1]).items():
                got[tree][name] += times
    sys.stdout.write(f"seed {args.seed}: thread CPU ms per call, {args.rounds} rounds x {args.calls} calls per tree, "
                     "median / least\n")  # fmt: skip
    for name in ("register", "trim"):
        cells = [f"{1e3 * np.median(got[t][name]):.2f} / {1e3 * min(got[t][name]):.2f}" for t in got]
        sys.stdout.write(f"{name:>9}   before {cells[0]}   after {cells[1]}\n")


if __name__ == "__main__":
    main()
