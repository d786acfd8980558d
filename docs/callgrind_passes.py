"""The work issue 19's instruction counts are taken on, ``N`` passes of it, for ``valgrind --tool=callgrind``: the
count of 3 passes less that of 1, halved, is one pass without the start-up (imports, rendering the frames).

    for n in 1 3; do OPENBLAS_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file=cg.$n \\
        .venv/bin/python docs/callgrind_passes.py WHAT $n; done
    # then (summary of cg.3 - summary of cg.1) / 2: `grep -m1 ^summary: cg.N`

WHAT: ``dense`` (five completions of ``symfruit bench``'s dense camera view, ``evidence``), ``frames`` (the
``evidence`` completions of the benchmark frames of seeds 0 and 1, their inputs taken from ``detect`` once and
replayed) or ``trees`` (the colour segmenter with depth on the rendered apple-tree frames of seeds 0-2, 1920x1080,
the apple profile's settings, as ``symfruit bench --segment --scene apple-tree``; divide by 3 for one frame).
Run with ``PYTHONPATH=TREE/src`` to count another tree. (numpy cannot use AVX-512 under valgrind, so its
sorts count more than they cost natively: check a change that trades sorts for other work in CPU time too,
``docs/speed_ab.py``.)
"""

import argparse
import sys

import symfruit.detect as detect_module
from symfruit.evaluate.bench import _bench_scene
from symfruit.methods.complete import complete
from symfruit.synthetic.views import bench_camera_view


def frame_inputs() -> list[tuple]:
    got: list[tuple] = []
    run = detect_module.complete

    def record(points, *args, **kwargs):
        got.append((points, kwargs))
        return run(points, *args, **kwargs)

    detect_module.complete = record
    try:
        for seed in (0, 1):
            frame, _ = _bench_scene(None, seed)
            detect_module.detect(frame, method="evidence")
    finally:
        detect_module.complete = run
    return got


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("what", choices=("dense", "frames", "trees"), help="the work (above)")
    parser.add_argument("n", type=int, help="how many passes of it (1 or more)")
    args = parser.parse_args()
    what, n = args.what, args.n
    if n < 1:
        parser.error(f"n must be 1 or more, got {n}")
    if what == "trees":
        from symfruit.segment.colour import segment
        from symfruit.settings import resolve_settings
        from symfruit.synthetic.scenes import make_tree_scene

        settings = resolve_settings(fruit="apple").segment
        trees = [make_tree_scene(seed) for seed in range(3)]
        for _ in range(n):
            for f in trees:
                segment(f.color, f.depth, f.camera, settings)
        sys.exit(0)
    work = frame_inputs() if what == "frames" else [(bench_camera_view(), {})] * 5
    for _ in range(n):
        for points, kwargs in work:
            complete(points, **kwargs)
