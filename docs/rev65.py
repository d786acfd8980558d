"""The benchmark frame's solid-of-revolution kernels replayed (issue 19, stop 65, docs/rev65.md): record every
``_jit.revolution_search`` and ``_jit.revolution_profile`` call of ``docs/cand65.py``'s recorded candidates calls,
then replay them for their thread CPU time and a digest of what they return.

    PYTHONPATH=src python docs/cand65.py record cands.pkl
    PYTHONPATH=src python docs/rev65.py record cands.pkl kernels.pkl
    PYTHONPATH=src python docs/rev65.py time kernels.pkl [--passes 300]

Run ``time`` with each tree (``PYTHONPATH=BASE/src`` and ``PYTHONPATH=src``), alternated. It prints the digest
(the same on both trees: the same values to the bit) and each kernel's median and least milliseconds a frame.
"""

import argparse
import copy
import hashlib
import pickle
import sys
import time
from typing import Any


def record(calls_path: str, path: str) -> None:
    from symfruit.core import _jit
    from symfruit.core.candidates import candidates

    with open(calls_path, "rb") as f:
        calls = pickle.load(f)
    kept: dict[str, list[Any]] = {"revolution_search": [], "revolution_profile": []}
    originals = {name: getattr(_jit, name) for name in kept}

    def wrapped(name: str) -> Any:
        def call(*args: Any) -> Any:
            kept[name].append(copy.deepcopy(args))
            return originals[name](*args)

        return call

    for name in kept:
        setattr(_jit, name, wrapped(name))
    try:
        for args, kwargs in calls:
            candidates(*args, **kwargs)
    finally:
        for name, fn in originals.items():
            setattr(_jit, name, fn)
    with open(path, "wb") as f:
        pickle.dump(kept, f)
    sys.stdout.write(", ".join(f"{len(v)} {k}" for k, v in kept.items()) + f" calls recorded in {path}\n")


def replay(path: str, passes: int) -> None:
    import numpy as np

    from symfruit.core import _jit

    with open(path, "rb") as f:
        kept = pickle.load(f)
    h = hashlib.sha256()
    for name, calls in kept.items():
        for args in calls:
            out = getattr(_jit, name)(*args)
            for part in out if isinstance(out, tuple) else (out,):
                h.update(np.asarray(part).tobytes())
    sys.stdout.write(f"kernels digest {h.hexdigest()[:16]}\n")
    for name, calls in kept.items():
        fn = getattr(_jit, name)
        spent = []
        for _ in range(passes):
            start = time.thread_time()
            for args in calls:
                fn(*args)
            spent.append(1e3 * (time.thread_time() - start))
        ms = np.array(spent)
        sys.stdout.write(f"{name} {np.median(ms):.3f} / {ms.min():.3f} ms a frame (median / least, {passes} passes)\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    rec = sub.add_parser("record", help="record the kernels' calls of docs/cand65.py's recorded calls")
    rec.add_argument("calls")
    rec.add_argument("kernels")
    timed = sub.add_parser("time", help="thread CPU a frame of the recorded kernel calls, and their digest")
    timed.add_argument("kernels")
    timed.add_argument("--passes", type=int, default=300)
    args = parser.parse_args()
    if args.command == "record":
        record(args.calls, args.kernels)
    else:
        replay(args.kernels, args.passes)


if __name__ == "__main__":
    main()
