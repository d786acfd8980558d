"""Replays of compiled kernels' calls on the benchmark frame (stop 60, speeds60): each named function's calls
recorded from one ``detect`` of ``symfruit bench --frame``'s frame (evidence), then replayed many times, the thread's
CPU time of each pass summed over the frame's calls (fresh copies of the arguments each call, made outside the timer:
kernels write into them).

    python docs/speeds60.py record CALLS.pkl MODULE:NAME ...    e.g. symfruit.core._jit:surface_cap
    python docs/speeds60.py time CALLS.pkl [PASSES]

Record once (in either tree: the kernels' arguments are the same), then time it under each tree's ``PYTHONPATH``,
alternated, e.g. ``PYTHONPATH=/tmp/lead60/base/src python docs/speeds60.py time calls.pkl 200``. A module argument
(a Python-level function handed the kernels' module) is stored as its name and handed back as the module.
"""

import argparse
import copy
import importlib
import pickle
import sys
import time
import types
from typing import Any

import numpy as np

#: A module among the arguments: stored as this tag and its name.
MODULE = "__module__"


def _resolve(name: str) -> tuple[Any, str]:
    module, _, attr = name.partition(":")
    return importlib.import_module(module), attr


def _stored(x: Any) -> Any:
    return (MODULE, x.__name__) if isinstance(x, types.ModuleType) else copy.deepcopy(x)


def _loaded(x: Any) -> Any:
    if isinstance(x, tuple) and len(x) == 2 and x[0] == MODULE:
        return importlib.import_module(x[1])
    return x


def _fresh(x: Any) -> Any:
    return x if isinstance(x, types.ModuleType) else copy.deepcopy(x)


def record(out: str, names: list[str]) -> None:
    import symfruit.detect as detect_module
    from symfruit.evaluate.bench import _bench_scene

    frame, _ = _bench_scene(None, 0)
    for _ in range(3):
        detect_module.detect(frame, method="evidence")
    calls: dict[str, list[tuple[tuple, dict]]] = {n: [] for n in names}
    on = [False]

    def wrapped(fn: Any, name: str) -> Any:
        def call(*args: Any, **kwargs: Any) -> Any:
            if on[0]:
                calls[name].append((tuple(_stored(a) for a in args), copy.deepcopy(kwargs)))
            return fn(*args, **kwargs)

        return call

    for name in names:
        module, attr = _resolve(name)
        setattr(module, attr, wrapped(getattr(module, attr), name))
    on[0] = True
    detect_module.detect(frame, method="evidence")
    on[0] = False
    with open(out, "wb") as f:
        pickle.dump(calls, f)
    for name, found in calls.items():
        sys.stdout.write(f"{name} {len(found)} calls\n")


def replay(path: str, passes: int) -> None:
    with open(path, "rb") as f:
        calls = pickle.load(f)
    for name, found in calls.items():
        module, attr = _resolve(name)
        fn = getattr(module, attr)
        found = [(tuple(_loaded(a) for a in args), kwargs) for args, kwargs in found]
        for args, kwargs in found:  # compiled (or loaded from the cache) before the timing
            fn(*(_fresh(a) for a in args), **copy.deepcopy(kwargs))
        spent = []
        for _ in range(passes):
            total = 0
            for args, kwargs in found:
                a, k = tuple(_fresh(x) for x in args), copy.deepcopy(kwargs)
                start = time.thread_time_ns()
                fn(*a, **k)
                total += time.thread_time_ns() - start
            spent.append(total / 1e6)
        ms = np.array(spent)
        line = f"{name:50s} {len(found):3d} calls  median {np.median(ms):.3f}  least {ms.min():.3f} ms a frame"
        sys.stdout.write(line + "\n")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="what", required=True)
    rec = sub.add_parser("record", help="record the named functions' calls on the benchmark frame")
    rec.add_argument("calls", help="the pickle to write")
    rec.add_argument("names", nargs="+", help="MODULE:NAME of each function, e.g. symfruit.core._jit:surface_cap")
    rep = sub.add_parser("time", help="replay the recorded calls under this PYTHONPATH's tree")
    rep.add_argument("calls", help="the pickle record wrote")
    rep.add_argument("passes", nargs="?", type=int, default=200, help="passes over the frame's calls (200)")
    args = parser.parse_args(argv)
    if args.what == "record":
        record(args.calls, args.names)
    else:
        replay(args.calls, args.passes)


if __name__ == "__main__":
    main()
