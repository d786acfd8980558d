"""Replays of ``fruit_surface``'s calls on the benchmark frame, two source trees alternated (stop 62, surf62).

``record`` runs ``detect`` (evidence) on ``symfruit bench --frame``'s frame and keeps the arguments of every
``symfruit.core.surface.fruit_surface`` call of one frame (the registration's, looked up in ``core.surface``, and
extraction's and ``own_cap``'s, looked up in ``symfruit.extract``: 24 on that frame). ``time`` replays them in child
processes, one per tree and round, the trees alternated, each child ``--passes`` passes over the calls after three
unmeasured ones, the thread's CPU time of each pass (a frame's calls); it prints the median and least per tree, and
checks that both trees give the same surfaces (pixels, front, radius, noise and apex, byte for byte).

    python docs/surf62.py record CALLS.pkl
    python docs/surf62.py time CALLS.pkl BEFORE/src AFTER/src [--rounds 6] [--passes 100]
"""

import argparse
import copy
import json
import os
import pickle
import subprocess
import sys

import numpy as np

CHILD = """
import hashlib, json, pickle, sys, time
import numpy as np
import symfruit.core.surface as S
calls = pickle.load(open(sys.argv[1], "rb"))
passes = int(sys.argv[2])
def run():
    return [S.fruit_surface(*a, **k) for a, k in calls]
for _ in range(3):
    got = run()
h = hashlib.sha256()
for s in got:
    if s is None:
        h.update(b"none")
    else:
        h.update(np.ascontiguousarray(s.pixels).tobytes())
        h.update(np.array([s.front, s.radius, s.noise, *s.apex], dtype=np.float64).tobytes())
spent = []
for _ in range(passes):
    start = time.thread_time()
    run()
    spent.append(time.thread_time() - start)
print(json.dumps({"spent": spent, "digest": h.hexdigest()[:16]}))
"""


def record(out: str) -> None:
    import symfruit.core.surface as surface
    import symfruit.detect as detect_module
    import symfruit.extract as extract
    from symfruit.evaluate.bench import _bench_scene

    frame, _ = _bench_scene(None, 0)
    for _ in range(2):
        detect_module.detect(frame, method="evidence")
    calls = []
    on = [False]
    original = surface.fruit_surface

    def kept(*args, **kwargs):
        if on[0]:
            calls.append((copy.deepcopy(args), copy.deepcopy(kwargs)))
        return original(*args, **kwargs)

    surface.fruit_surface = kept
    extract.fruit_surface = kept
    on[0] = True
    detect_module.detect(frame, method="evidence")
    on[0] = False
    with open(out, "wb") as f:
        pickle.dump(calls, f)
    sys.stdout.write(f"{len(calls)} calls\n")


def time_trees(calls: str, before: str, after: str, rounds: int, passes: int) -> None:
    trees = {"before": os.path.abspath(before), "after": os.path.abspath(after)}
    spent: dict[str, list[float]] = {name: [] for name in trees}
    digests: dict[str, set[str]] = {name: set() for name in trees}
    for r in range(rounds):
        for name in trees if r % 2 == 0 else list(trees)[::-1]:
            out = subprocess.run(
                [sys.executable, "-c", CHILD, calls, str(passes)],
                env={**os.environ, "PYTHONPATH": trees[name]}, capture_output=True, text=True, check=True,
            )  # fmt: skip
            found = json.loads(out.stdout)
            spent[name] += found["spent"]
            digests[name].add(found["digest"])
    sys.stdout.write(f"fruit_surface's calls of one frame, thread CPU us a frame, {rounds} rounds x {passes} passes\n")
    for name in trees:
        v = np.array(spent[name]) * 1e6
        sys.stdout.write(
            f"{name:>7} median {np.median(v):7.0f}  least {v.min():7.0f}  surfaces {sorted(digests[name])}\n"
        )
    same = digests["before"] == digests["after"] and len(digests["before"]) == 1
    sys.stdout.write("the same surfaces\n" if same else "SURFACES DIFFER\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    rec = sub.add_parser("record", help="keep one benchmark frame's fruit_surface calls")
    rec.add_argument("calls")
    tim = sub.add_parser("time", help="replay them on two source trees, alternated")
    tim.add_argument("calls")
    tim.add_argument("before")
    tim.add_argument("after")
    tim.add_argument("--rounds", type=int, default=6)
    tim.add_argument("--passes", type=int, default=100)
    args = parser.parse_args()
    if args.command == "record":
        record(args.calls)
    else:
        time_trees(args.calls, args.before, args.after, args.rounds, args.passes)


if __name__ == "__main__":
    main()
