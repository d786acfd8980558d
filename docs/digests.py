"""Digests that say whether a speed change kept the results bit for bit (issue 19): ``detect``'s records on the
benchmark frames (``symfruit bench --frame``'s frame, seeds 0-2, methods ``evidence`` and ``paper``: every
detection's points, box, scores and extras) and the colour segmenter's labels (strawberry frames of seeds 0-7 with
and without depth, seed 0 through the four camera models, apple-tree frames of seeds 0-3 with depth and the apple
profile). Run it on the tree before and after a change (``SYMFRUIT_KERNELS=numpy`` for the numpy twins); the same
digests mean the same results. The digests depend on the host's libraries (BLAS), so compare on one host.

    python docs/digests.py [records] [labels] [trees] [--fruit-processes N]

``trees`` (not in the default run: about 10 s more): the segmenter's labels of the 1920x1080 apple-tree frames
``docs/speed_ab.py --trees 6`` times (seeds 0-5, ``make_tree_scene``'s default sensor, the apple profile; stop 54).

``--fruit-processes N``: the records with each frame's fruit shared with N worker processes
(:class:`symfruit.fruitpool.FruitPool`, stop 53): the same digest as without them. ``--stream`` (with it): the
frames of each method through a :class:`symfruit.detect.DetectStream` (stop 55: the next frame segmented while
the workers end the last one's fruit), as ``symfruit detect --fruit-processes N`` runs a recording: the same digest.
"""

import argparse
import hashlib
import sys

import numpy as np


def records(fruit_processes: int = 0, stream: bool = False) -> str:
    from symfruit.detect import detect
    from symfruit.evaluate.bench import _bench_scene
    from symfruit.fruitpool import FruitPool

    with FruitPool(fruit_processes) as pool:
        if fruit_processes and not pool.active:
            raise SystemExit(f"--fruit-processes {fruit_processes}: no worker here ({pool.reason})")
        found = _records(_streamed(_bench_scene, pool) if stream else detect, _bench_scene, pool)
        if fruit_processes and not pool.fruit_elsewhere:
            raise SystemExit(f"--fruit-processes {fruit_processes}: the workers did no fruit")
    return found


def _records(detect, bench_scene, pool) -> str:
    h = hashlib.sha256()
    for seed in (0, 1, 2):
        frame, _ = bench_scene(None, seed)
        for method in ("evidence", "paper"):
            for d in detect(frame, method=method, pool=pool).detections:
                h.update(f"{seed}{method}{d.id}{d.error}".encode())
                h.update(np.ascontiguousarray(d.extraction.points, dtype=np.float64).tobytes())
                r = d.result
                if r is None:
                    continue
                h.update(np.ascontiguousarray(r.points, dtype=np.float64).tobytes())
                h.update(np.asarray([r.box.min, r.box.max], dtype=np.float64).tobytes())
                h.update(np.float64(r.score).tobytes())
                h.update(np.ascontiguousarray(r.scores, dtype=np.float64).tobytes())
                for k in sorted(r.extras):
                    v = r.extras[k]
                    h.update(k.encode())
                    numeric = isinstance(v, np.ndarray | float | int)
                    h.update(np.asarray(v).tobytes() if numeric else repr(v).encode())
    return h.hexdigest()[:16]


def _streamed(bench_scene, pool):
    """A ``detect`` for :func:`_records` that gives the detections each method's frames got in a stream, in the
    order :func:`_records` asks for them."""
    from symfruit.detect import DetectStream

    got = {}
    for method in ("evidence", "paper"):
        stream, seeds = DetectStream(pool, method=method), [None, 0, 1, 2]
        for before, seed in zip(seeds, [*seeds[1:], None], strict=True):
            ready = None if seed is None else stream.prepare(bench_scene(None, seed)[0])
            found = stream.finish()
            if found is not None:
                got[before, method] = found
            if ready is not None:
                stream.start(ready)
    order = iter([(seed, method) for seed in (0, 1, 2) for method in ("evidence", "paper")])
    return lambda frame, *, method, pool: got[next(order)]


def labels() -> tuple[str, int]:
    from symfruit.profiles import load_profile
    from symfruit.segment.colour import segment
    from symfruit.synthetic.scenes import make_scene, make_tree_scene
    from symfruit.synthetic.sensors import sensor_model

    h = hashlib.sha256()
    found = 0
    runs = []
    for seed in range(8):
        sc = make_scene(seed, n_ripe=8, n_unripe=2)
        runs += [(sc.color, None, None, None), (sc.color, sc.depth, sc.camera, None)]
    for name in ("azure-kinect", "realsense-l515", "realsense-d435", "realsense-d405"):
        sc = make_scene(0, n_ripe=8, n_unripe=2, sensor=sensor_model(name))
        runs.append((sc.color, sc.depth, sc.camera, None))
    apple = load_profile("apple").segment
    for seed in range(4):
        sc = make_tree_scene(seed, sensor=sensor_model("azure-kinect"))
        runs.append((sc.color, sc.depth, sc.camera, apple))
    for color, depth, camera, settings in runs:
        lab = segment(color, depth, camera, settings)
        h.update(np.ascontiguousarray(lab, dtype=np.int32).tobytes())
        found += int(lab.max())
    return h.hexdigest()[:16], found


def trees(n: int = 6) -> tuple[str, int]:
    from symfruit.segment.colour import segment
    from symfruit.settings import resolve_settings
    from symfruit.synthetic.scenes import make_tree_scene

    settings = resolve_settings(fruit="apple").segment  # as docs/speed_ab.py --trees has them
    h = hashlib.sha256()
    found = 0
    for seed in range(n):
        sc = make_tree_scene(seed)
        lab = segment(sc.color, sc.depth, sc.camera, settings)
        h.update(np.ascontiguousarray(lab, dtype=np.int32).tobytes())
        found += int(lab.max())
    return h.hexdigest()[:16], found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("what", nargs="*", help="records, labels, trees (default: records and labels)")
    parser.add_argument(
        "--fruit-processes",
        type=int,
        default=0,
        metavar="N",
        help="records: each frame's fruit shared with N worker processes (default 0: none)",
    )
    parser.add_argument("--stream", action="store_true", help="records: the frames in a stream (DetectStream)")
    args = parser.parse_args()
    args.what = args.what or ["records", "labels"]
    if not set(args.what) <= {"records", "labels", "trees"}:
        parser.error(f"what: give records, labels and/or trees, got {' '.join(args.what)}")
    if "records" in args.what:
        sys.stdout.write(f"records {records(args.fruit_processes, args.stream)}\n")
    if "labels" in args.what:
        digest, found = labels()
        sys.stdout.write(f"labels {digest} {found} fruit\n")
    if "trees" in args.what:
        digest, found = trees()
        sys.stdout.write(f"trees {digest} {found} fruit\n")


if __name__ == "__main__":
    main()
