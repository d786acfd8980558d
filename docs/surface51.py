"""``fruit_surface`` alone on the benchmark frame's calls (docs/surface51.md): its 18 calls of one ``detect`` on
``symfruit bench --frame``'s frame (seed 0: the registration's 9 and extraction's 9) recorded, then replayed
``--rounds`` times; prints the thread CPU per frame, median and least. With ``--depth-mode``, the depth mode alone
on those calls' valid depths instead: numpy's sort with ``_jit.fruit_depth``'s kernel against ``_jit.depth_mode``
(where the tree has it).

    PYTHONPATH=TREE/src python docs/surface51.py [--rounds 100] [--depth-mode]

Run it once per tree, alternating, on one host (thread CPU; the host's load still shows).
"""

import argparse
import sys
import time

import numpy as np


def _calls() -> list:
    import symfruit.core.surface as surface
    import symfruit.detect as detect
    import symfruit.extract as extract
    from symfruit.evaluate.bench import _bench_scene

    calls = []
    own = surface.fruit_surface

    def recorded(*a, **k):
        calls.append((a, k))
        return own(*a, **k)

    surface.fruit_surface = extract.fruit_surface = recorded
    frame, _ = _bench_scene(None, 0)
    detect.detect(frame, method="evidence")
    surface.fruit_surface = extract.fruit_surface = own
    return calls


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=100)
    parser.add_argument("--depth-mode", action="store_true")
    args = parser.parse_args()
    import symfruit.core.surface as surface
    from symfruit.core.kernels import compiled

    calls = _calls()
    if args.depth_mode:
        jit = compiled()
        assert jit is not None, "numba's kernels are needed"
        depths = []
        for (depth, mask, *_), _ in calls:
            v = np.asarray(depth, dtype=np.float64)[mask]
            depths.append(np.ascontiguousarray(v[np.isfinite(v) & (v > 0)]))
        none, shares = np.zeros(0, bool), (0.5, 0.3)
        ways = {"sort + fruit_depth": lambda v: jit.fruit_depth(np.sort(v), v, 20.0, 600.0, 0.001, none, False, shares)}
        if hasattr(jit, "depth_mode"):
            ways["depth_mode"] = lambda v: jit.depth_mode(v, 20.0, 600.0, 0.001, none, False, shares)
        for name, way in ways.items():
            for v in depths:
                way(v)
            spent = []
            for _ in range(args.rounds):
                start = time.thread_time()
                for v in depths:
                    way(v)
                spent.append(time.thread_time() - start)
            sys.stdout.write(f"{name}: {np.median(spent) * 1e3:.3f} / {np.min(spent) * 1e3:.3f} ms a frame\n")
        return
    for a, k in calls:
        surface.fruit_surface(*a, **k)
    spent = []
    for _ in range(args.rounds):
        start = time.thread_time()
        for a, k in calls:
            surface.fruit_surface(*a, **k)
        spent.append(time.thread_time() - start)
    sys.stdout.write(
        f"fruit_surface, {len(calls)} calls: {np.median(spent) * 1e3:.3f} / {np.min(spent) * 1e3:.3f} ms a frame\n"
    )


if __name__ == "__main__":
    main()
