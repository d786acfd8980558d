"""Record a Python function's calls in ``detect`` of the benchmark frame, and replay them (issue 19, stop 61).

``record`` runs ``detect`` on ``symfruit bench --frame``'s frame (seed 0, the default method) twice, the second time
with each named function (``module:name``) wrapped so that its arguments are copied before every call, and pickles
the calls. ``replay`` (run with the ``PYTHONPATH`` of the tree to time) calls the function on copies of the recorded
arguments ``--passes`` times and prints the least and median thread CPU per frame, with a digest of every call's
answer (arrays by their bytes, numbers by ``repr``) to compare two trees: the same digest, the same answers, bit for
bit. Alternate the trees' replays (``--rounds``) so that a change in the host's load falls on both::

    PYTHONPATH=/tmp/lead61/base/src python docs/speedp61.py record symfruit.core.raster:free_side_reach --save r.pkl
    python docs/speedp61.py ab r.pkl symfruit.core.raster:free_side_reach /tmp/lead61/base/src src --rounds 4
"""

from __future__ import annotations

import argparse
import copy
import hashlib
import importlib
import os
import pickle
import subprocess
import sys
import time
from typing import Any


def _target(spec: str) -> tuple[Any, str]:
    module, name = spec.split(":")
    return importlib.import_module(module), name


def record(specs: list[str], save: str) -> None:
    import symfruit.detect as detect
    from symfruit.evaluate.bench import _bench_scene

    frame = _bench_scene(None, 0)[0]
    detect.detect(frame)
    calls: dict[str, list[Any]] = {spec: [] for spec in specs}
    for spec in specs:
        module, name = _target(spec)
        original = getattr(module, name)

        def wrapped(*args: Any, _o: Any = original, _s: str = spec, **kwargs: Any) -> Any:
            calls[_s].append(copy.deepcopy((args, kwargs)))
            return _o(*args, **kwargs)

        # every module that imported the function by name calls the wrapper too
        for other in list(sys.modules.values()):
            if getattr(other, "__name__", "").startswith("symfruit") and getattr(other, name, None) is original:
                setattr(other, name, wrapped)
    detect.detect(frame)
    with open(save, "wb") as f:
        pickle.dump(calls, f)
    sys.stdout.write(f"{ {spec: len(c) for spec, c in calls.items()} } calls recorded in {save}\n")


def _digest(value: Any, h: Any) -> None:
    import numpy as np

    if isinstance(value, np.ndarray):
        h.update(str((value.dtype, value.shape)).encode())
        h.update(np.ascontiguousarray(value).tobytes())
    elif isinstance(value, (tuple, list)):
        h.update(b"(")
        for v in value:
            _digest(v, h)
        h.update(b")")
    elif isinstance(value, dict):
        for k in sorted(value, key=repr):
            h.update(repr(k).encode())
            _digest(value[k], h)
    elif hasattr(value, "__dict__"):
        h.update(type(value).__name__.encode())
        _digest(vars(value), h)
    else:
        h.update(repr(value).encode())


def replay(path: str, spec: str, passes: int) -> None:
    import numpy as np

    import symfruit.detect as detect
    from symfruit.evaluate.bench import _bench_scene

    detect.detect(_bench_scene(None, 0)[0])  # compiled kernels loaded, caches warm
    with open(path, "rb") as f:
        calls = pickle.load(f)[spec]
    module, name = _target(spec)
    fn = getattr(module, name)
    h = hashlib.sha256()
    for args, kwargs in copy.deepcopy(calls):
        _digest(fn(*args, **kwargs), h)
    times = []
    for _ in range(passes):
        copies = copy.deepcopy(calls)
        t = time.thread_time()
        for args, kwargs in copies:
            fn(*args, **kwargs)
        times.append(time.thread_time() - t)
    ms = np.array(times) * 1e3
    sys.stdout.write(f"{spec}: {len(calls)} calls, least {ms.min():.4f} median {np.median(ms):.4f} ms a frame, "
                     f"answers {h.hexdigest()[:16]}\n")  # fmt: skip


def ab(path: str, spec: str, trees: list[str], rounds: int, passes: int) -> None:
    for r in range(rounds):
        for tree in trees if r % 2 == 0 else trees[::-1]:
            env = dict(os.environ, PYTHONPATH=tree)
            out = subprocess.run([sys.executable, __file__, "replay", path, spec, "--passes", str(passes)], env=env,
                                 capture_output=True, text=True, check=True).stdout.strip()  # fmt: skip
            sys.stdout.write(f"{tree}: {out}\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    rec = sub.add_parser("record", help="record the calls of module:name functions")
    rec.add_argument("specs", nargs="+")
    rec.add_argument("--save", required=True)
    rep = sub.add_parser("replay", help="replay one function's recorded calls on this PYTHONPATH's tree")
    rep.add_argument("path")
    rep.add_argument("spec")
    rep.add_argument("--passes", type=int, default=200)
    both = sub.add_parser("ab", help="replay on each tree (src directories) in turn, alternated")
    both.add_argument("path")
    both.add_argument("spec")
    both.add_argument("trees", nargs="+")
    both.add_argument("--rounds", type=int, default=4)
    both.add_argument("--passes", type=int, default=200)
    args = parser.parse_args(argv)
    if args.command == "record":
        record(args.specs, args.save)
    elif args.command == "replay":
        replay(args.path, args.spec, args.passes)
    else:
        ab(args.path, args.spec, args.trees, args.rounds, args.passes)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
