"""Where the benchmark frame's time goes, function by function: every function of ``symfruit`` (module-level
functions, the methods of its classes with ``--methods``, and the compiled kernels' Python-level calls) wrapped in a
``time.thread_time`` timer, then ``detect`` run on the benchmark frame (``symfruit bench --frame``); prints each
function's inclusive thread CPU per frame and its calls per frame, the largest first.

    python docs/speed_profile.py [--only SUBSTRING ...] [--methods] [--frames 8] [--top 60] [--method evidence]
                                 [--trees N] [--self]

e.g. ``PYTHONPATH=src python docs/speed_profile.py --only evidence agreement candidates jit.``. cProfile cannot
time this code (with a profiler hook set, numba's calls take a slow path, README "Speed", stop 48); these wrappers
can, at a cost: each wrapped call adds about a microsecond, so a frame timed with every function wrapped reads
about half again its own time, and a small function called often reads high. ``--only`` wraps only the functions
whose qualified name holds one of the substrings (``jit.NAME`` for a kernel): the fewer wrapped, the nearer the
figures are to the frame's own. Inclusive times: a function's callees are counted in it too; with ``--self``, each
function's own time (less that of the wrapped functions it calls), and the sums of the kernels' and the rest's (the
wrappers' own cost lands in the rest). A function looked up before the wrappers were set (a method's entry in
``symfruit.methods``' registry, a kernel called from another kernel) is not seen: wrap its callees. Compare figures
within one run (thread CPU, the host's load still shows). With ``--trees N`` the colour segmenter alone is profiled
instead, on N rendered apple-tree frames (1920x1080 with depth, the apple profile's settings, as ``docs/speed_ab.py
--trees``): figures per tree frame.
"""

import argparse
import importlib
import pkgutil
import sys
import time
import types
from collections import Counter, defaultdict
from typing import Any

#: Modules left out (optional dependencies, entry points, plots): nothing of the frame runs in them.
SKIP = ("ros", "dask", "cli", "__main__", "viz", "plot")


#: ``--self``: the time of each wrapped call still open spent in the wrapped calls it made (one entry a call).
_OPEN: list[float] = []
_SELF = [False]


def _timed(fn: Any, key: str, spent: dict[str, float], calls: Counter) -> Any:
    def timed(*a: Any, **k: Any) -> Any:
        start = time.thread_time()
        _OPEN.append(0.0)
        try:
            return fn(*a, **k)
        finally:
            took = time.thread_time() - start
            inner = _OPEN.pop()
            spent[key] += took - inner if _SELF[0] else took
            calls[key] += 1
            if _OPEN:
                _OPEN[-1] += took

    timed.__wrapped__ = fn  # type: ignore[attr-defined]
    return timed


def _wrap_all(only: list[str], methods: bool, spent: dict[str, float], calls: Counter) -> int:
    """Every wanted function of every ``symfruit`` module replaced by its timed wrapper wherever a module holds it;
    the number wrapped."""
    import symfruit

    def wanted(key: str) -> bool:
        return not only or any(part in key for part in only)

    made: dict[int, Any] = {}
    for info in pkgutil.walk_packages(symfruit.__path__, "symfruit."):
        if any(part in info.name for part in SKIP):
            continue
        try:
            module = importlib.import_module(info.name)
        except ImportError:  # an optional extra not installed
            continue
        for name, obj in list(vars(module).items()):
            if methods and isinstance(obj, type) and obj.__module__ == module.__name__:
                for attr, fn in list(vars(obj).items()):
                    key = f"{obj.__module__}.{obj.__qualname__}.{attr}"
                    if isinstance(fn, types.FunctionType) and not attr.startswith("__") and wanted(key):
                        setattr(obj, attr, _timed(fn, key, spent, calls))
                continue
            if isinstance(obj, types.FunctionType) and obj.__module__.startswith("symfruit"):
                key = f"{obj.__module__}.{obj.__qualname__}"
            elif type(obj).__name__ == "CPUDispatcher":  # a numba kernel, as Python calls it
                key = f"jit.{name}"
            else:
                continue
            # core.lapack's error callbacks are keys of its settings table: not replaced
            if (module.__name__.endswith(".lapack") and name.startswith("_")) or not wanted(key):
                continue
            if id(obj) not in made:
                made[id(obj)] = _timed(obj, key, spent, calls)
            setattr(module, name, made[id(obj)])
    return len(made)


def _frame(method: str) -> Any:
    """``detect`` on the benchmark frame, as a call of no arguments."""
    import symfruit.detect as detect
    from symfruit.evaluate.bench import _bench_scene

    frame, _ = _bench_scene(None, 0)
    return lambda: detect.detect(frame, method=method)


def _trees(n: int) -> Any:
    """The colour segmenter on ``n`` rendered apple-tree frames (as ``docs/speed_ab.py --trees``), as a call of no
    arguments: one call segments each frame once."""
    import symfruit.segment.colour as colour
    from symfruit.settings import resolve_settings
    from symfruit.synthetic.scenes import make_tree_scene

    settings = resolve_settings(fruit="apple").segment
    frames = [make_tree_scene(k) for k in range(n)]

    def run() -> None:
        for f in frames:
            colour.segment(f.color, f.depth, f.camera, settings)

    return run


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", nargs="*", default=[], help="wrap only names holding one of these")
    parser.add_argument("--methods", action="store_true", help="wrap the methods of symfruit's classes too")
    parser.add_argument("--frames", type=int, default=8)
    parser.add_argument("--top", type=int, default=60)
    parser.add_argument("--method", default="evidence")
    parser.add_argument("--self", action="store_true", help="each function's own time: less that of the wrapped "
                        "functions it calls (the kernels' with jit.)")  # fmt: skip
    parser.add_argument("--trees", type=int, default=0, help="profile the colour segmenter on this many apple-tree "
                        "frames instead (1920x1080 with depth, the apple profile; --frames times each)")  # fmt: skip
    args = parser.parse_args(argv)
    spent: dict[str, float] = defaultdict(float)
    calls: Counter = Counter()
    _SELF[0] = args.self
    run = _trees(args.trees) if args.trees else _frame(args.method)
    run()  # compiled kernels compiled before any is wrapped: a kernel calling a wrapped one no longer types
    count = _wrap_all(args.only, args.methods, spent, calls)
    for _ in range(1 if args.trees else 3):  # warm-up: compiled kernels loaded, caches made
        run()
    spent.clear()
    calls.clear()
    start = time.thread_time()
    for _ in range(args.frames):
        run()
    frames = args.frames * max(args.trees, 1)  # with --trees, each run segments every tree frame
    per = (time.thread_time() - start) / frames
    lines = [f"{count} functions wrapped; frame {per * 1e3:.1f} ms thread CPU with the wrappers ({frames} frames)"]
    if args.self:
        kernels = sum(v for k, v in spent.items() if k.startswith("jit."))
        lines.append(f"own times: the kernels {kernels / frames * 1e3:.2f} ms, the rest "
                     f"{(sum(spent.values()) - kernels) / frames * 1e3:.2f} ms a frame")  # fmt: skip
    for key, seconds in sorted(spent.items(), key=lambda kv: -kv[1])[: args.top]:
        lines.append(f"{seconds / frames * 1e3:8.2f} ms {calls[key] / frames:8.1f} calls  {key}")
    sys.stdout.write("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
