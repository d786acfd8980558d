"""The benchmark frame's completions replayed (issue 19, stop 62, docs/comp62.md): record ``complete``'s calls of one
``detect`` of ``symfruit bench --frame``'s frame, then replay them for their thread CPU time, for LAPACK's share call
by call (each ``core.lapack`` call's thread CPU inside the frame, by routine, caller and shape), or for the arrays the
compiled kernels return (each one boxed into a new numpy array on return).

    PYTHONPATH=src python docs/comp62.py record calls.pkl
    PYTHONPATH=src python docs/comp62.py time calls.pkl [--passes 60]
    PYTHONPATH=src python docs/comp62.py lapack calls.pkl [--passes 200]
    PYTHONPATH=src python docs/comp62.py boxes calls.pkl

Run ``record`` with the tree whose inputs are wanted (the base's and the branch's give the same calls where the
stages before the completion are unchanged), and the others with each tree to compare, alternated (a machine shared
with other work moves every figure).
"""

import argparse
import collections
import copy
import pickle
import sys
import time
from typing import Any


def _calls(path: str) -> list[tuple[tuple[Any, ...], dict[str, Any]]]:
    with open(path, "rb") as f:
        return pickle.load(f)


def record(path: str) -> None:
    import symfruit.detect as detect_module
    from symfruit.evaluate.bench import _bench_scene

    frame, _ = _bench_scene(None, 0)
    calls: list[tuple[tuple[Any, ...], dict[str, Any]]] = []
    original = detect_module.complete

    def kept(*args: Any, **kwargs: Any) -> Any:
        calls.append((copy.deepcopy(args), copy.deepcopy(kwargs)))
        return original(*args, **kwargs)

    detect_module.complete = kept
    try:
        detect_module.detect(frame, method="evidence")
    finally:
        detect_module.complete = original
    with open(path, "wb") as f:
        pickle.dump(calls, f)
    sys.stdout.write(f"{len(calls)} completions recorded in {path}\n")


def replay_time(path: str, passes: int) -> None:
    from symfruit.methods.complete import complete

    calls = _calls(path)
    for args, kwargs in calls:
        complete(*args, **kwargs)
    times = []
    for _ in range(passes):
        start = time.thread_time()
        for args, kwargs in calls:
            complete(*args, **kwargs)
        times.append(time.thread_time() - start)
    times.sort()
    sys.stdout.write(f"completions: median {1e3 * times[len(times) // 2]:.3f} least {1e3 * times[0]:.3f} ms a frame\n")


def lapack_share(path: str, passes: int) -> None:
    from symfruit.core import lapack
    from symfruit.methods.complete import complete

    calls = _calls(path)
    for args, kwargs in calls:
        complete(*args, **kwargs)
    spent: collections.Counter[tuple[str, str, tuple[int, ...]]] = collections.Counter()
    count: collections.Counter[tuple[str, str, tuple[int, ...]]] = collections.Counter()
    original = lapack._call

    def timed(errors: Any, ufunc: Any, signature: str, *args: Any) -> Any:
        start = time.thread_time_ns()
        try:
            return original(errors, ufunc, signature, *args)
        finally:
            key = (ufunc.__name__, sys._getframe(2).f_code.co_name, tuple(getattr(args[0], "shape", ())))
            spent[key] += time.thread_time_ns() - start
            count[key] += 1

    lapack._call = timed
    try:
        for _ in range(passes):
            for args, kwargs in calls:
                complete(*args, **kwargs)
    finally:
        lapack._call = original
    sys.stdout.write("us a frame  calls  (routine, caller, shape)\n")
    for key, ns in spent.most_common():
        sys.stdout.write(f"{ns / passes / 1e3:10.1f}  {count[key] / passes:5.1f}  {key}\n")
    total, made = sum(spent.values()) / passes / 1e3, sum(count.values()) / passes
    sys.stdout.write(f"LAPACK in all: {total:.1f} us a frame, {made:.0f} calls\n")


def boxes(path: str) -> None:
    import numpy as np

    from symfruit.core import _jit
    from symfruit.methods.complete import complete

    calls = _calls(path)
    arrays: collections.Counter[str] = collections.Counter()
    made: collections.Counter[str] = collections.Counter()

    def counted(out: Any) -> int:
        if isinstance(out, np.ndarray):
            return 1
        return sum(counted(x) for x in out) if isinstance(out, (tuple, list)) else 0

    originals = {name: f for name, f in vars(_jit).items() if hasattr(f, "py_func")}

    def wrapped(name: str, kernel: Any) -> Any:
        def call(*args: Any, **kwargs: Any) -> Any:
            out = kernel(*args, **kwargs)
            arrays[name] += counted(out)
            made[name] += 1
            return out

        return call

    for name, kernel in originals.items():
        setattr(_jit, name, wrapped(name, kernel))
    try:
        for args, kwargs in calls:
            complete(*args, **kwargs)
    finally:
        for name, kernel in originals.items():
            setattr(_jit, name, kernel)
    sys.stdout.write(f"{sum(arrays.values())} arrays returned by {sum(made.values())} kernel calls (a frame)\n")
    for name, n in arrays.most_common(20):
        sys.stdout.write(f"{n:6d} arrays {made[name]:5d} calls  {name}\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("what", choices=["record", "time", "lapack", "boxes"])
    parser.add_argument("calls", help="the recorded completions (a pickle)")
    parser.add_argument("--passes", type=int, default=None)
    a = parser.parse_args()
    if a.what == "record":
        record(a.calls)
    elif a.what == "time":
        replay_time(a.calls, a.passes or 60)
    elif a.what == "lapack":
        lapack_share(a.calls, a.passes or 200)
    else:
        boxes(a.calls)


if __name__ == "__main__":
    main()
