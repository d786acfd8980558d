"""The benchmark frame's candidates replayed (issue 19, stop 65, docs/cand65.md): record the calls of
:func:`symfruit.core.candidates.candidates` of one ``detect`` of ``symfruit bench --frame``'s frame (method
``evidence``), then replay them for their thread CPU time or a digest of what they return.

    PYTHONPATH=src python docs/cand65.py record cands.pkl
    PYTHONPATH=src python docs/cand65.py time cands.pkl [--passes 300]
    PYTHONPATH=src python docs/cand65.py digest cands.pkl

Run ``record`` once with either tree (the stages before the candidates are the same), then ``time`` and ``digest``
with each tree (``PYTHONPATH=BASE/src`` and ``PYTHONPATH=src``), alternated: a machine shared with other work moves
every figure. ``time`` prints the median, least and mean milliseconds of thread CPU a frame (the frame's nine calls,
each pass after one warm pass). ``digest`` hashes every candidate's name, box, centre, back deviation and agreement:
the same digest on both trees means the same candidates to the bit.
"""

import argparse
import copy
import hashlib
import pickle
import sys
import time
from typing import Any


def record(path: str) -> None:
    import symfruit.detect as detect_module
    import symfruit.methods.evidence as evidence_module
    from symfruit.evaluate.bench import _bench_scene

    frame, _ = _bench_scene(None, 0)
    calls: list[tuple[tuple[Any, ...], dict[str, Any]]] = []
    original = evidence_module.candidates

    def kept(*args: Any, **kwargs: Any) -> Any:
        calls.append((copy.deepcopy(args), copy.deepcopy(kwargs)))
        return original(*args, **kwargs)

    evidence_module.candidates = kept
    try:
        detect_module.detect(frame, method="evidence")
    finally:
        evidence_module.candidates = original
    with open(path, "wb") as f:
        pickle.dump(calls, f)
    sys.stdout.write(f"{len(calls)} candidates calls recorded in {path}\n")


def _calls(path: str) -> list[tuple[tuple[Any, ...], dict[str, Any]]]:
    with open(path, "rb") as f:
        return pickle.load(f)


def replay_time(path: str, passes: int) -> None:
    import numpy as np

    from symfruit.core.candidates import candidates

    calls = _calls(path)
    for args, kwargs in calls:
        candidates(*args, **kwargs)
    spent = []
    for _ in range(passes):
        start = time.thread_time()
        for args, kwargs in calls:
            candidates(*args, **kwargs)
        spent.append(1e3 * (time.thread_time() - start))
    ms = np.array(spent)
    sys.stdout.write(f"candidates {np.median(ms):.3f} / {ms.min():.3f} / {ms.mean():.3f} ms a frame "
                     f"(median / least / mean, {passes} passes)\n")  # fmt: skip


def digest(path: str) -> None:
    from symfruit.core.candidates import candidates

    h = hashlib.sha256()
    for args, kwargs in _calls(path):
        for c in candidates(*args, **kwargs):
            h.update(repr((c.name, c.lo.tobytes(), c.hi.tobytes(), c.centre.tobytes(), c.back_std,
                           repr(c.agreement))).encode())  # fmt: skip
    sys.stdout.write(f"candidates digest {h.hexdigest()[:16]}\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("record", help="record the benchmark frame's candidates calls").add_argument("calls")
    timed = sub.add_parser("time", help="thread CPU a frame of the recorded calls")
    timed.add_argument("calls")
    timed.add_argument("--passes", type=int, default=300)
    sub.add_parser("digest", help="a digest of the recorded calls' candidates").add_argument("calls")
    args = parser.parse_args()
    if args.command == "record":
        record(args.calls)
    elif args.command == "time":
        replay_time(args.calls, args.passes)
    else:
        digest(args.calls)


if __name__ == "__main__":
    main()
