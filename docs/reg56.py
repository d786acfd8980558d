"""The registration's outlines part by part (stop 56, docs/reg56.md): ``registration_outline``'s calls captured from
one ``detect`` (``--method evidence``) on each of ``symfruit bench --frame``'s frames ``--seeds`` (0 is the
benchmark's: 9 masks), then replayed ``--rounds`` times. Prints the thread CPU a frame (median and least) of the
calls alone, then of the same calls with each part wrapped in a thread-CPU timer: every kernel the outline calls,
``principal_widths``, ``_mean_curvature`` and ``_free_points`` (the wrappers' own cost lands in "the rest"). With
``--kernels``, each kernel is then replayed alone on its own captured arguments, warm (least of 7 x 100 passes),
with the pieces of the three largest: ``outline_windows`` (``taxicab_within``, ``outline_maps``) and ``thin_passes``
(``thin_counts``, ``smooth_parts`` and ``part_sizes``, ``nearest``, ``window_medians``). The outlines' digest is
printed first: the same in two trees, the same outlines.

    PYTHONPATH=TREE/src python docs/reg56.py [--seeds 0] [--rounds 40] [--kernels]

Run it once per tree, alternating, on one host (thread CPU; the host's load still shows).
"""

import argparse
import collections
import hashlib
import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np

#: the kernels :func:`symfruit.core.surface.registration_outline` calls, directly or through ``fruit_surface``
KERNELS = ("valid_depth", "outline_windows", "mask_mode", "thin_passes", "surface_cap", "cap_outline", "rim_sides",
           "centred_pixels", "column_extents")  # fmt: skip
#: the functions of :mod:`symfruit.core.surface` timed as a whole (numpy, BLAS and LAPACK inside)
WHOLE = ("principal_widths", "_mean_curvature", "_free_points")


def _say(line: str) -> None:
    sys.stdout.write(line + "\n")


def _captured(seeds: list[int]) -> list[tuple[tuple, dict]]:
    import symfruit.core.surface as surface
    import symfruit.detect as detect
    from symfruit.evaluate.bench import _bench_scene

    seen: list[tuple[tuple, dict]] = []
    original = surface.registration_outline

    def kept(*a: Any, **k: Any) -> Any:
        seen.append((a, k))
        return original(*a, **k)

    surface.registration_outline = kept
    try:
        for seed in seeds:
            frame, _ = _bench_scene(None, seed)
            detect.detect(frame, method="evidence")
    finally:
        surface.registration_outline = original
    return seen


def _digest(calls: list[tuple[tuple, dict]]) -> str:
    from symfruit.core.surface import registration_outline

    h = hashlib.sha1()
    for a, k in calls:
        found = registration_outline(*a, **k)
        if found is None:
            h.update(b"none")
            continue
        for part in (found.rows, found.cols, found.inside, found.sides if found.sides is not None else np.zeros(0)):
            h.update(np.ascontiguousarray(part).tobytes())
        h.update(repr(found.band).encode())
    return h.hexdigest()[:16]


def _least(fn: Callable[[], Any], passes: int = 100) -> float:
    best = np.inf
    for _ in range(7):
        start = time.thread_time()
        for _ in range(passes):
            fn()
        best = min(best, (time.thread_time() - start) / passes)
    return best


def _parts(calls: list[tuple[tuple, dict]], rounds: int, frames: int) -> None:
    import symfruit.core.surface as surface
    from symfruit.core.kernels import compiled

    jit = compiled()
    spent: collections.Counter = collections.Counter()
    kept: list[tuple[Any, str, Any]] = []

    def wrap(owner: Any, name: str, key: str) -> None:
        fn = getattr(owner, name)

        def timed(*a: Any, **k: Any) -> Any:
            start = time.thread_time()
            try:
                return fn(*a, **k)
            finally:
                spent[key] += time.thread_time() - start

        kept.append((owner, name, fn))
        setattr(owner, name, timed)

    def replay() -> list[float]:
        took = []
        for _ in range(rounds):
            start = time.thread_time()
            for a, k in calls:
                surface.registration_outline(*a, **k)
            took.append((time.thread_time() - start) / frames)
        return took

    alone = replay()
    _say(f"the outlines alone: {1e3 * np.median(alone):.2f} / {1e3 * min(alone):.2f} ms a frame (median / least)")
    for name in KERNELS:
        wrap(jit, name, f"jit.{name}")
    for name in WHOLE:
        wrap(surface, name, name)
    try:
        wrapped = replay()
    finally:
        for owner, name, fn in reversed(kept):
            setattr(owner, name, fn)
    total = float(np.median(wrapped))
    _say(f"with the parts wrapped: {1e3 * total:.2f} ms a frame (median); each part, ms a frame:")
    parts = {key: spent[key] / (rounds * frames) for key in spent}
    # rim_sides is called inside _free_points, centred_pixels and column_extents inside principal_widths
    nested = sum(parts.get(f"jit.{name}", 0.0) for name in ("rim_sides", "centred_pixels", "column_extents"))
    for key, value in sorted(parts.items(), key=lambda kv: -kv[1]):
        _say(f"  {key:28s} {1e3 * value:6.3f}")
    rest = total - (sum(parts.values()) - nested)  # the median frame less the parts' means: an estimate
    _say(f"  {'the rest (Python, numpy)':28s} {1e3 * rest:6.3f}")


def _kernels(calls: list[tuple[tuple, dict]], frames: int) -> None:
    import symfruit.core.surface as surface
    from symfruit.core.kernels import compiled

    jit = compiled()
    got: dict[str, list[tuple]] = {name: [] for name in ("outline_windows", "mask_mode", "thin_passes", "surface_cap",
                                                         "cap_outline")}  # fmt: skip
    originals = {name: getattr(jit, name) for name in got}

    def keeper(name: str) -> Callable[..., Any]:
        def kept(*a: Any) -> Any:
            got[name].append(tuple(x.copy() if isinstance(x, np.ndarray) else x for x in a))
            return originals[name](*a)

        return kept

    for name in got:
        setattr(jit, name, keeper(name))
    try:
        for a, k in calls:
            surface.registration_outline(*a, **k)
    finally:
        for name, fn in originals.items():
            setattr(jit, name, fn)
    _say("each kernel alone on its captured arguments, warm, ms a frame (least of 7 x 100):")
    for name, args in got.items():
        fn = originals[name]
        _say(f"  {name:28s} {1e3 * _least(lambda fn=fn, args=args: [fn(*a) for a in args]) / frames:6.3f}")
    masks = [(a[0], a[1]) for a in got["outline_windows"]]
    pieces = {
        "taxicab_within": lambda: [jit.taxicab_within(m, r, np.empty(m.shape, bool)) for m, r in masks],
        "outline_maps": lambda: [jit.outline_maps(m, r, r, np.empty(m.shape), np.empty(m.shape)) for m, r in masks],
    }
    thin = got["thin_passes"]  # (depth, mask, front, join, noise, stage, ok, counts, labels)
    oks = []
    for depth, mask, front, join, *_ in thin:
        ok = np.empty(depth.shape, bool)
        jit.thin_counts(depth, mask, front, join, ok)
        oks.append(ok)

    def parts() -> None:
        for depth, mask, front, join, *_, labels in thin:
            count = jit.smooth_parts(depth, mask, join, labels)
            jit.part_sizes(labels, count, depth, front, join)

    pieces["thin_counts"] = lambda: [jit.thin_counts(a[0], a[1], a[2], a[3], np.empty(a[0].shape, bool)) for a in thin]
    pieces["smooth_parts + part_sizes"] = parts
    pieces["nearest"] = lambda: [jit.nearest(~ok, np.empty(ok.shape, np.int64)) for ok in oks]
    pieces["window_medians"] = lambda: [
        jit.window_medians(a[0], ok, np.empty(int(np.count_nonzero(ok)))) for a, ok in zip(thin, oks, strict=True)
    ]
    _say("their pieces, the same way (thin_passes' on every call's mask, whichever stage it ends at):")
    for name, fn in pieces.items():
        _say(f"  {name:28s} {1e3 * _least(fn) / frames:6.3f}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0])
    parser.add_argument("--rounds", type=int, default=40)
    parser.add_argument("--kernels", action="store_true")
    args = parser.parse_args()
    from symfruit.core.kernels import compiled

    if compiled() is None:
        sys.stderr.write("numba's kernels are needed (SYMFRUIT_KERNELS=numpy is set or numba is missing)\n")
        return 2
    calls = _captured(args.seeds)
    frames = len(args.seeds)
    _say(f"{len(calls)} outlines on {frames} frame(s); digest {_digest(calls)}")
    _parts(calls, args.rounds, frames)
    if args.kernels:
        _kernels(calls, frames)
    return 0


if __name__ == "__main__":
    sys.exit(main())
