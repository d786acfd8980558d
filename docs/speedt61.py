"""Replays of compiled kernels' calls on the benchmark frame, two ``_jit.py`` files alternated (stop 61, speedt61;
after docs/speeds60.py): each named kernel's calls recorded from one ``detect`` of ``symfruit bench --frame``'s frame
(evidence), then replayed on each file's kernels in turn, many passes, the thread's CPU time of each pass summed
over the frame's calls (fresh copies of the arguments each call, made outside the timer: kernels write into them),
and the two files' outputs compared byte for byte.

    python docs/speedt61.py record CALLS.pkl NAME ...       e.g. thin_passes revolution_search noise_measures
    python docs/speedt61.py time CALLS.pkl OLD/_jit.py NEW/_jit.py [--passes 200] [--only NAME ...]

``NAME`` is a kernel of ``symfruit.core._jit`` that Python code calls (``jit.NAME``). The record also replays, as
``window_medians``, the 5 x 5 medians of the ``thin_passes`` calls that reach them (stage 2: past stages 0 and 1,
at least 60 ``ok`` pixels and ``3 noise > 3 mm``), on the depth and ``ok`` pixels they read. Each ``_jit.py`` is
copied to a directory of its own before it is imported (numba's cache is keyed by the file's path).
"""

import argparse
import copy
import hashlib
import importlib.util
import os
import pickle
import shutil
import sys
import tempfile
import time
from typing import Any

import numpy as np


def record(out: str, names: list[str]) -> None:
    import symfruit.core._jit as jit
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
                calls[name].append((copy.deepcopy(args), copy.deepcopy(kwargs)))
            return fn(*args, **kwargs)

        return call

    for name in names:
        setattr(jit, name, wrapped(getattr(jit, name), name))
    on[0] = True
    detect_module.detect(frame, method="evidence")
    on[0] = False
    if "thin_passes" in calls:
        calls["window_medians"] = [((d, ok, np.empty(int(ok.sum()))), {}) for d, ok in _median_calls(jit, calls)]
    with open(out, "wb") as f:
        pickle.dump(calls, f)
    for name, found in calls.items():
        sys.stdout.write(f"{name} {len(found)} calls\n")


def _median_calls(jit: Any, calls: dict) -> list[tuple[np.ndarray, np.ndarray]]:
    """The depth and ``ok`` pixels of each recorded ``thin_passes`` call that reaches its 5 x 5 medians (its stage 2:
    stage 0 and 1 passed through as the kernel does, then ``3 noise > 3 mm`` and at least 60 ``ok`` pixels)."""
    found = []
    for args, _ in calls["thin_passes"]:
        depth, mask, front, join, noise, stage, ok, counts, labels = copy.deepcopy(args)
        if stage == 0:
            first, rows, cols = jit.thin_counts(depth, mask, front, join, ok)
            counts[:] = first
            if rows.shape[0] >= 30 and not jit.reaches_outline(mask, rows, cols):
                continue
            stage = 1
        if stage == 1:
            count = jit.smooth_parts(depth, mask, join, labels)
            if jit._sheet_sizes(labels, count, depth, front, join)[0]:
                continue
        if 3.0 * noise > 0.003 and counts[0] >= 60:
            found.append((depth, ok))
    return found


def _load(path: str, tag: str) -> Any:
    """``path`` (a ``_jit.py``) copied to a directory of its own and imported as a module named after ``tag``."""
    where = os.path.join(tempfile.gettempdir(), "speedt61-replay", tag)
    os.makedirs(where, exist_ok=True)
    target = os.path.join(where, f"_jit_{tag}.py")
    with open(path, "rb") as f:
        text = f.read()
    if not os.path.exists(target) or open(target, "rb").read() != text:
        shutil.copyfile(path, target)
    spec = importlib.util.spec_from_file_location(f"_jit_{tag}", target)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def _digest(x: Any) -> str:
    h = hashlib.sha256()
    for item in x if isinstance(x, tuple | list) else (x,):
        if isinstance(item, np.ndarray):
            h.update(item.tobytes())
        else:
            h.update(repr(item).encode())
    return h.hexdigest()[:16]


def replay(path: str, jits: list[str], passes: int, only: list[str] | None) -> None:
    with open(path, "rb") as f:
        calls = pickle.load(f)
    modules = [_load(p, f"t{i}") for i, p in enumerate(jits)]
    for name, found in calls.items():
        if only and name not in only:
            continue
        outs = []
        for module in modules:  # compiled (or loaded from the cache) before the timing; outputs (and arguments) kept
            fn = getattr(module, name)
            digest = []
            for args, kwargs in found:
                a = copy.deepcopy(args)
                digest.append(_digest(fn(*a, **copy.deepcopy(kwargs))) + _digest(a))
            outs.append(digest)
        same = all(o == outs[0] for o in outs)
        spent: list[list[float]] = [[] for _ in modules]
        for _ in range(passes):
            for m, module in enumerate(modules):
                fn = getattr(module, name)
                total = 0
                for args, kwargs in found:
                    a, k = copy.deepcopy(args), copy.deepcopy(kwargs)
                    start = time.thread_time_ns()
                    fn(*a, **k)
                    total += time.thread_time_ns() - start
                spent[m].append(total / 1e6)
        figures = "  ".join(f"{np.median(s):.3f} / {np.min(s):.3f}" for s in spent)
        sys.stdout.write(f"{name:24s} {len(found):3d} calls  median / least ms a frame: {figures}  same: {same}\n")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="what", required=True)
    rec = sub.add_parser("record", help="record the named kernels' calls on the benchmark frame")
    rec.add_argument("calls", help="the pickle to write")
    rec.add_argument("names", nargs="+", help="kernels of symfruit.core._jit, e.g. thin_passes")
    rep = sub.add_parser("time", help="replay the recorded calls on each _jit.py, alternated")
    rep.add_argument("calls", help="the pickle record wrote")
    rep.add_argument("jits", nargs="+", help="the _jit.py files to compare")
    rep.add_argument("--passes", type=int, default=200, help="passes over the frame's calls (200)")
    rep.add_argument("--only", nargs="*", help="the kernels to replay (all recorded)")
    args = parser.parse_args(argv)
    if args.what == "record":
        record(args.calls, args.names)
    else:
        replay(args.calls, args.jits, args.passes, args.only)


if __name__ == "__main__":
    main()
