"""Replays for stop 61's speedb61 (issue 19): the outline's edge labels and the occlusion box's opening.

    python docs/speedb61.py record CALLS.pkl        outline_bands' and allowed_box's calls on the benchmark frame
    python docs/speedb61.py time CALLS.pkl [PASSES]  the frame's calls replayed under this PYTHONPATH's tree
    python docs/speedb61.py parts CALLS.pkl [PASSES] old and new pieces alternated in one process (this tree)

``record`` and ``time`` are docs/speeds60.py's (one ``detect`` of ``symfruit bench --frame``'s frame, evidence;
thread CPU time of each pass summed over the frame's calls, fresh copies of the arguments made outside the timer),
for ``symfruit.core._jit:outline_bands`` and ``symfruit.core._jit:allowed_box``. Time under each tree's
``PYTHONPATH``, alternated. ``parts`` needs stop 61's kernels: from the recorded calls it makes the edge points'
look-ups (each call's outside band pixels, and its cracks where it took them) and the hidden boxes' openings, then
times, alternated pass by pass, ``nearest_labels`` against ``nearest_labels_rows``, ``_square_extreme`` twice (the
erosion, then the dilation) against ``open_square``, and the gap's two ``_square_extreme`` dilations (without their
AND: a lower bound of the old cost) against ``near_both``, checking that each pair gives the same answer. Each
figure includes the calls' dispatch from Python (about 1-2 us a call), which the kernels do not pay inside
``outline_bands`` and ``allowed_box``. The labels' look-ups are timed whole, then split: the outside band pixels',
the cracks', and the same calls with no queries (the set-up and the dispatch alone).
"""

import argparse
import importlib.util
import pickle
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

NAMES = ["symfruit.core._jit:outline_bands", "symfruit.core._jit:allowed_box"]


def _speeds60() -> Any:
    spec = importlib.util.spec_from_file_location("speeds60", Path(__file__).with_name("speeds60.py"))
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _pieces(path: str) -> tuple[list[tuple], list[tuple], list[tuple], list[tuple], list[tuple]]:
    from symfruit.core import _jit

    with open(path, "rb") as f:
        calls = pickle.load(f)
    looks, bands, cracks = [], [], []
    for args, _ in calls[NAMES[0]]:
        edge, labels, made, took, _, _ = _jit.outline_bands(*args)
        if labels.shape[0] and made[1].shape[0]:
            bands.append((edge, labels, made[1]))
        if took:
            cracks.append((edge, labels, args[4]))
    looks = bands + cracks
    opens, gaps = [], []
    for args, _ in calls[NAMES[1]]:
        hidden, region, dr, dc, gap, thin = args
        h0, h1, g0, g1 = _jit._box(hidden)
        if thin > 0 and h1 > h0:
            opens.append((np.ascontiguousarray(hidden[h0:h1, g0:g1]), thin))
        # allowed_box's seen pixels, and the hidden ones opened: _joins' inputs to the gap's filters
        h, w = hidden.shape
        seen = np.zeros((h, w), bool)
        rh, rw = region.shape
        a0, a1, b0, b1 = max(dr, 0), min(dr + rh, h), max(dc, 0), min(dc + rw, w)
        seen[a0:a1, b0:b1] = region[a0 - dr : a1 - dr, b0 - dc : b1 - dc]
        s0, s1, t0, t1 = _jit._box(seen)
        if gap > 0 and s1 > s0:
            join = _jit._joins(hidden, seen, s0, s1, t0, t1, 0, thin)
            e0, e1 = max(s0 - 2 * gap, 0), min(s1 + 2 * gap, h)
            f0, f1 = max(t0 - 2 * gap, 0), min(t1 + 2 * gap, w)
            gaps.append((np.ascontiguousarray(seen[e0:e1, f0:f1]), np.ascontiguousarray(join[e0:e1, f0:f1]), gap))
    return looks, opens, gaps, bands, cracks


def _old_open(part: np.ndarray, thin: int) -> np.ndarray:
    from symfruit.core import _jit

    eroded, out = np.empty(part.shape, bool), np.empty(part.shape, bool)
    _jit._square_extreme(part, thin, True, eroded)
    _jit._square_extreme(eroded, thin, False, out)
    return out


def _new_open(part: np.ndarray, thin: int) -> np.ndarray:
    from symfruit.core import _jit

    out = np.empty(part.shape, bool)
    _jit.open_square(part, thin, out)
    return out


def _old_filters(seen: np.ndarray, join: np.ndarray, gap: int) -> tuple[np.ndarray, np.ndarray]:
    """The two filters ``_joins`` ran before (timed without its AND and OR, which ran in the kernel: the old side's
    figure is a lower bound)."""
    from symfruit.core import _jit

    out = join.copy()  # (the copy on both sides: near_both writes in place)
    grown, near = np.empty(seen.shape, bool), np.empty(seen.shape, bool)
    _jit._square_extreme(seen, gap, False, grown)
    _jit._square_extreme(out, gap, False, near)
    return grown, near


def _old_gap(seen: np.ndarray, join: np.ndarray, gap: int) -> np.ndarray:
    grown, near = _old_filters(seen, join, gap)
    return join | (grown & near)


def _new_gap(seen: np.ndarray, join: np.ndarray, gap: int) -> np.ndarray:
    from symfruit.core import _jit

    out = join.copy()
    _jit.near_both(seen, out, gap)
    return out


def parts(path: str, passes: int) -> None:
    from symfruit.core import _jit

    looks, opens, gaps, bands, cracks = _pieces(path)
    none = [(edge, labels, queries[:0]) for edge, labels, queries in looks]  # the set-up and dispatch alone
    for edge, labels, queries in looks:  # the same answers (where sure; the same unsure)
        f0, u0 = _jit.nearest_labels(edge, labels, queries)
        f1, u1 = _jit.nearest_labels_rows(edge, labels, queries)
        assert np.array_equal(u0, u1) and np.array_equal(f0[~u0], f1[~u1])
    for part, thin in opens:
        assert np.array_equal(_old_open(part, thin), _new_open(part, thin))
    for seen, join, gap in gaps:
        assert np.array_equal(_old_gap(seen, join, gap), _new_gap(seen, join, gap))
    pairs = {
        "nearest_labels": ([(_jit.nearest_labels, c) for c in looks], [(_jit.nearest_labels_rows, c) for c in looks]),
        " of it bands": ([(_jit.nearest_labels, c) for c in bands], [(_jit.nearest_labels_rows, c) for c in bands]),
        " of it cracks": ([(_jit.nearest_labels, c) for c in cracks], [(_jit.nearest_labels_rows, c) for c in cracks]),
        " no queries": ([(_jit.nearest_labels, c) for c in none], [(_jit.nearest_labels_rows, c) for c in none]),
        "opening": ([(_old_open, c) for c in opens], [(_new_open, c) for c in opens]),
        "gap filters": ([(_old_filters, c) for c in gaps], [(_new_gap, c) for c in gaps]),
    }
    for name, (old, new) in pairs.items():
        spent: dict[str, list[float]] = {"old": [], "new": []}
        for _ in range(passes):
            for which, found in (("old", old), ("new", new)):
                total = 0
                for fn, args in found:
                    start = time.thread_time_ns()
                    fn(*args)
                    total += time.thread_time_ns() - start
                spent[which].append(total / 1e3)
        o, n = np.array(spent["old"]), np.array(spent["new"])
        sys.stdout.write(f"{name:16s} {len(old):3d} calls  old median {np.median(o):.1f} least {o.min():.1f}  "
                         f"new median {np.median(n):.1f} least {n.min():.1f} us a frame\n")  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="what", required=True)
    rec = sub.add_parser("record", help="record outline_bands' and allowed_box's calls on the benchmark frame")
    rec.add_argument("calls", help="the pickle to write")
    for what, text in (("time", "replay the recorded calls under this PYTHONPATH's tree"),
                       ("parts", "old and new pieces, alternated, in this tree")):  # fmt: skip
        rep = sub.add_parser(what, help=text)
        rep.add_argument("calls", help="the pickle record wrote")
        rep.add_argument("passes", nargs="?", type=int, default=200, help="passes over the frame's calls (200)")
    args = parser.parse_args(argv)
    if args.what == "record":
        _speeds60().record(args.calls, NAMES)
    elif args.what == "time":
        _speeds60().replay(args.calls, args.passes)
    else:
        parts(args.calls, args.passes)


if __name__ == "__main__":
    main()
