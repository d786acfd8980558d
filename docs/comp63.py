"""``hidden_front``'s calls of the benchmark frame's completions replayed (issue 19, stop 63, docs/comp63.md): record
them from one ``detect`` of ``symfruit bench --frame``'s frame (``evidence``), then replay them for their thread CPU
time and a digest of their answers (the same digest on two trees: the same fronts, bit for bit); or, for each call,
how far the sphere's front lies behind the nearest surface and whether ``sphere_front_behind`` is sure of it.

    PYTHONPATH=src python docs/comp63.py record fronts.pkl
    PYTHONPATH=src python docs/comp63.py time fronts.pkl [--passes 400]
    PYTHONPATH=src python docs/comp63.py sure fronts.pkl

Run ``record`` with either tree (the stages before the completion are the same), ``time`` with each tree to compare,
alternated (a machine shared with other work moves every figure).
"""

import argparse
import copy
import hashlib
import pickle
import sys
import time
from typing import Any


def _calls(path: str) -> list[tuple[tuple[Any, ...], dict[str, Any]]]:
    with open(path, "rb") as f:
        return pickle.load(f)


def record(path: str) -> None:
    import symfruit.methods.evidence as evidence_module
    from symfruit.detect import detect
    from symfruit.evaluate.bench import _bench_scene

    frame, _ = _bench_scene(None, 0)
    calls: list[tuple[tuple[Any, ...], dict[str, Any]]] = []
    original = evidence_module.hidden_front

    def kept(*args: Any, **kwargs: Any) -> Any:
        calls.append((copy.deepcopy(args), copy.deepcopy(kwargs)))
        return original(*args, **kwargs)

    evidence_module.hidden_front = kept
    try:
        detect(frame, method="evidence")
    finally:
        evidence_module.hidden_front = original
    with open(path, "wb") as f:
        pickle.dump(calls, f)
    sys.stdout.write(f"{len(calls)} hidden_front calls recorded in {path}\n")


def replay_time(path: str, passes: int) -> None:
    from symfruit.methods.evidence import hidden_front

    calls = _calls(path)
    answers = [hidden_front(*args, **kwargs) for args, kwargs in calls]
    digest = hashlib.sha256(repr([float(a).hex() for a in answers]).encode()).hexdigest()[:16]
    times = []
    for _ in range(passes):
        start = time.thread_time()
        for args, kwargs in calls:
            hidden_front(*args, **kwargs)
        times.append(time.thread_time() - start)
    times.sort()
    sys.stdout.write(f"hidden_front, {len(calls)} calls: median {1e6 * times[len(times) // 2]:.1f} least "
                     f"{1e6 * times[0]:.1f} us a frame; answers {digest}\n")  # fmt: skip


def sure(path: str) -> None:
    from symfruit.core.front import sphere_front, sphere_front_behind
    from symfruit.methods.evidence import FRONT_TOLERANCE

    for args, _ in _calls(path):
        sample, front, width = args[0], float(args[1]), float(args[2])
        diameter = width * front
        diameter = width * (front + 0.5 * diameter)  # hidden_front's sphere, as it works it out
        z, _ = sphere_front(sample, 0.5 * diameter, tolerance=FRONT_TOLERANCE)
        behind = sphere_front_behind(sample, 0.5 * diameter, front, tolerance=FRONT_TOLERANCE)
        sys.stdout.write(f"{len(sample):5d} points: the sphere's front {1e3 * (z - front):+.3f} mm behind the "
                         f"nearest surface; sure it is behind: {behind}\n")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("action", choices=("record", "time", "sure"))
    parser.add_argument("calls", help="the recorded hidden_front calls (a pickle)")
    parser.add_argument("--passes", type=int, default=400)
    a = parser.parse_args()
    if a.action == "record":
        record(a.calls)
    elif a.action == "time":
        replay_time(a.calls, a.passes)
    else:
        sure(a.calls)


if __name__ == "__main__":
    main()
