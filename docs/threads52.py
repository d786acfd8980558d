"""Stop 52 (issue 19, docs/threads52.md): does the second core pay for a frame's fruit? Wall and CPU time of
``detect`` on the benchmark frame (``symfruit bench --frame``'s) with its fruit on one thread or on two, the two
alternated round by round; or with half of the fruit in a second, forked and warm, process (the frame's arrays and
the fruit's labels copied into memory both map, the rest pickled to it, its detections pickled back with their
masks cut to their boxes; ``--pickled``: everything pickled through the pool's pipe); or ``docs/digests.py``'s
records digest with ``detect``'s threads forced.

    python docs/threads52.py threads [--method evidence] [--rounds 6] [--repeat 15] [--threads 2]
    python docs/threads52.py processes [--method evidence] [--rounds 6] [--repeat 15] [--pickled]
    python docs/threads52.py digests [--threads 2]
    python docs/threads52.py memory [--frames 400] [--threads 2]

Wall time is what the question is about, and on a machine other work keeps busy it says little: the figures of
docs/threads52.md were taken as ``chrt -f 5 env OPENBLAS_NUM_THREADS=1 python docs/threads52.py ...`` (real-time
priority: the two cores as on a quiet machine for the seconds it runs; OpenBLAS on one thread, else two Python
threads each calling a two-thread OpenBLAS oversubscribe the two cores).
"""

import argparse
import os
import sys
import time
from functools import partial

import numpy as np


def _say(text: str) -> None:
    sys.stdout.write(text + "\n")


def _frame(method: str):
    from symfruit.detect import detect
    from symfruit.evaluate.bench import _bench_scene

    frame, _ = _bench_scene(None, 0)
    for _ in range(3):
        detect(frame, method=method)
    return frame


def _ab(run_a, run_b, rounds: int, repeat: int) -> dict[str, list[tuple[float, dict]]]:
    """Wall seconds and timings of each run, the two alternated (a b, b a, ...)."""
    found: dict[str, list[tuple[float, dict]]] = {"a": [], "b": []}
    for r in range(rounds):
        for name in ("a", "b") if r % 2 == 0 else ("b", "a"):
            run = run_a if name == "a" else run_b
            for _ in range(repeat):
                start = time.perf_counter()
                timings = run().timings
                found[name].append((time.perf_counter() - start, timings))
    return found


def _print(label: str, runs: list[tuple[float, dict]]) -> None:
    wall = np.array([w for w, _ in runs]) * 1e3
    cpu = np.array([t["cpu"] for _, t in runs]) * 1e3
    # the fruit's part of the frame: its wall time, and the fruit's own wall times summed
    part = np.array([t["total"] - t["segment"] - t["trim"] - t["register"] for _, t in runs]) * 1e3
    summed = np.array([t["extract"] - t["trim"] - t["register"] + t["complete"] for _, t in runs]) * 1e3
    _say(f"{label:<30} wall median {np.median(wall):6.1f} least {wall.min():6.1f} ms, cpu median "
          f"{np.median(cpu):6.1f}; the fruit's part: wall {np.median(part):5.1f}, each fruit's summed "
          f"{np.median(summed):5.1f}")  # fmt: skip


def threads(method: str, rounds: int, repeat: int, count: int) -> None:
    from symfruit.detect import detect

    frame = _frame(method)
    found = _ab(partial(detect, frame, method=method, threads=1),
                partial(detect, frame, method=method, threads=count), rounds, repeat)  # fmt: skip
    _say(f"{method}, load {os.getloadavg()[0]:.1f}, {rounds} rounds of {repeat} frames each")
    _print("fruit on 1 thread", found["a"])
    _print(f"fruit on {count} threads", found["b"])


def processes(method: str, rounds: int, repeat: int, pickled: bool) -> None:
    import multiprocessing
    from multiprocessing import shared_memory

    import symfruit.detect as D

    frame = _frame(method)
    # the frame's arrays and the fruit's labels go through memory both processes map (made before the fork), the
    # rest pickled; ``pickled``: everything pickled through the pool's pipe, the detections' whole-image masks too
    sizes = {"depth": frame.depth.nbytes, "color": frame.color.nbytes, "labels": frame.depth.size * 4,
             "fruit_px": frame.depth.size}  # fmt: skip
    shm = shared_memory.SharedMemory(create=True, size=sum(sizes.values()))
    _SHARED.update(buf=shm.buf, shape=frame.depth.shape, sizes=sizes)
    pool = multiprocessing.get_context("fork").Pool(1)  # forked once, warm: its kernels loaded as here
    pool.apply(os.getpid)
    in_threads = D._in_threads

    def split(fruit, jobs, workers):  # every other fruit in the second process, the rest here at the same time
        if pickled:
            there = pool.apply_async(_run, (fruit, jobs[1::2]))
        else:
            views = _views()
            for name, a in (("depth", fruit.frame.depth), ("color", fruit.frame.color), ("labels", fruit.labels),
                            ("fruit_px", fruit.fruit_px)):  # fmt: skip
                np.copyto(views[name], a)
            light = object.__new__(type(fruit))
            light.__dict__.update(fruit.__dict__, labels=None, fruit_px=None, frame=None)
            rest = {k: v for k, v in fruit.frame.__dict__.items() if k not in ("depth", "color", "masks")}
            there = pool.apply_async(_run_shared, (light, rest, jobs[1::2]))
        here = [(*fruit(k, sl)[:4], 0.0) for k, sl in jobs[0::2]]  # their CPU is this thread's, counted already
        theirs = there.get() if pickled else [_unpacked(d) for d in there.get()]
        return [here[i // 2] if i % 2 == 0 else theirs[i // 2] for i in range(len(jobs))]

    try:
        D._in_threads = split
        one, two = D.detect(frame, method=method), D.detect(frame, method=method, threads=2)
        same = all(np.array_equal(a.extraction.points, b.extraction.points) and a.error == b.error and
                   np.array_equal(a.mask, b.mask) and
                   (a.result is None or np.array_equal(a.result.points, b.result.points))
                   for a, b in zip(one.detections, two.detections, strict=True))  # fmt: skip
        found = _ab(partial(D.detect, frame, method=method, threads=1),
                    partial(D.detect, frame, method=method, threads=2), rounds, repeat)  # fmt: skip
    finally:
        D._in_threads = in_threads
        pool.terminate()
        _SHARED.clear()
        shm.close()
        shm.unlink()
    how = "everything pickled" if pickled else "the arrays in shared memory"
    _say(f"{method}, load {os.getloadavg()[0]:.1f}, {rounds} rounds of {repeat} frames each, {how}; the same "
         f"detections: {same}")  # fmt: skip
    _print("one process", found["a"])
    _print("half of the fruit in another", found["b"])


_SHARED: dict = {}


def _views() -> dict[str, np.ndarray]:
    buf, shape, sizes, at, out = _SHARED["buf"], _SHARED["shape"], _SHARED["sizes"], 0, {}
    for name, dtype, full in (("depth", np.float32, shape), ("color", np.uint8, (*shape, 3)),
                              ("labels", np.int32, shape), ("fruit_px", np.bool_, shape)):  # fmt: skip
        out[name] = np.ndarray(full, dtype, buffer=buf, offset=at)
        at += sizes[name]
    return out


def _run(fruit, jobs):
    return [fruit(k, sl) for k, sl in jobs]


def _run_shared(light, rest, jobs):
    from symfruit.core.frame import Frame

    views = _views()
    frame = object.__new__(Frame)
    frame.__dict__.update(rest, depth=views["depth"], color=views["color"], masks=None)
    light.__dict__.update(frame=frame, labels=views["labels"], fruit_px=views["fruit_px"])
    return [_packed(d) for d in _run(light, jobs)]


def _packed(done):
    """A fruit's task's answer with its whole-image mask cut to the mask's box (and no view of shared memory)."""
    d = done[0]
    rows, cols = np.flatnonzero(d.mask.any(axis=1)), np.flatnonzero(d.mask.any(axis=0))
    box = (rows[0], rows[-1] + 1, cols[0], cols[-1] + 1) if len(rows) else (0, 0, 0, 0)
    same = d.extraction.silhouette is d.mask
    ex = d.extraction.__dict__ | {"silhouette": None}
    return (d.__dict__ | {"mask": None, "extraction": ex}, d.mask.shape, box, d.mask[box[0] : box[1], box[2] : box[3]],
            same, done[1:])  # fmt: skip


def _unpacked(packed):
    from symfruit.detect import Detection
    from symfruit.extract import Extraction

    fields, shape, box, window, same, times = packed
    mask = np.zeros(shape, bool)
    mask[box[0] : box[1], box[2] : box[3]] = window
    ex = object.__new__(Extraction)
    ex.__dict__.update(fields["extraction"], silhouette=mask if same else None)
    d = object.__new__(Detection)
    d.__dict__.update(fields, mask=mask, extraction=ex)
    return (d, *times)


def digests(count: int) -> None:
    import symfruit.detect as D

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import digests as digests_module

    D.detect = partial(D.detect, threads=count)
    _say(f"records {digests_module.records()} (the fruit on {count} threads)")


def memory(frames: int, count: int) -> None:
    """The resident set after frames 10, 50, 100, ... of ``detect`` on the benchmark frame, its fruit on ``count``
    threads (a pool made and shut down per frame: nothing should grow)."""
    from symfruit.detect import detect
    from symfruit.evaluate.bench import _bench_scene

    frame, _ = _bench_scene(None, 0)
    page = os.sysconf("SC_PAGE_SIZE")
    for i in range(1, frames + 1):
        detect(frame, method="evidence", threads=count)
        if i in (10, 50) or i % 100 == 0 or i == frames:
            with open("/proc/self/statm") as f:
                rss = int(f.read().split()[1]) * page / 2**20
            _say(f"threads {count}, frame {i}: resident {rss:.1f} MB")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("what", choices=("threads", "processes", "digests", "memory"))
    parser.add_argument("--frames", type=int, default=400, help="memory: frames")
    parser.add_argument("--method", default="evidence")
    parser.add_argument("--rounds", type=int, default=6)
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--pickled", action="store_true", help="processes: everything through the pool's pipe")
    args = parser.parse_args()
    if args.what == "threads":
        threads(args.method, args.rounds, args.repeat, args.threads)
    elif args.what == "processes":
        processes(args.method, args.rounds, args.repeat, args.pickled)
    elif args.what == "digests":
        digests(args.threads)
    else:
        memory(args.frames, args.threads)


if __name__ == "__main__":
    main()
