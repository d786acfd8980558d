"""Interleaved A/B timing of ``detect`` on the benchmark frame (``symfruit bench --frame``) for two source trees:
the thread's CPU time per frame and per stage (each stage function of ``symfruit.detect`` wrapped), median and
least over every frame, the trees alternated round by round so that a machine shared with other work disturbs
both alike. CPU time, not wall time: a busy machine stretches the wall time far more.

    python docs/speed_ab.py BEFORE/src AFTER/src [--method evidence] [--rounds 6] [--frames 10]

e.g. ``python docs/speed_ab.py ../main/src src``. Each round starts a fresh process per tree (``PYTHONPATH``).
``--sensor NAME``: the frame rendered through that camera model with its annotators' masks (``symfruit bench
--frame --sensor``), which ``extract.mask_edge_px`` reads.
``--fits`` adds the completion's three iterative fits as stages (the solid of revolution's, the cone ellipsoid's
and the sphere's, all of their calls in a frame), ``--wrap MODULE:NAME ...`` any other function as a stage (where
the caller looks it up, e.g. ``symfruit.methods.evidence:observe``), or a method (``MODULE:Class.name``, e.g.
``symfruit.core.occlusion:Occlusion.extent``). With ``--dense`` the dense camera view of
``symfruit bench`` (about 14,000 points) is timed instead: the thread's CPU time of each ``complete``, ``--frames``
per round.
With ``--trees N`` the colour segmenter alone is timed instead, on N rendered apple-tree frames (1920x1080 with
depth, the apple profile's settings, as ``symfruit bench --segment --scene apple-tree``): the thread's CPU time
of each frame, ``--frames`` times per round.
"""

import argparse
import json
import os
import subprocess
import sys

import numpy as np

#: ``symfruit.detect`` names wrapped, and the stage each one is.
STAGES = {"frame_masks": "segment", "trim_labels": "trim", "register": "register", "_extract_window": "extract",
          "fruit_occlusion": "occlusion", "complete": "complete"}  # fmt: skip

CHILD = """
import importlib, json, sys, time
import symfruit.detect as D
from symfruit.evaluate.bench import _bench_scene
method, frames, stages = sys.argv[1], int(sys.argv[2]), json.loads(sys.argv[3])
sensor = sys.argv[4] if len(sys.argv) > 4 and sys.argv[4] else None
spent = {}
def wrap(name, stage):
    module, _, name = name.rpartition(":")
    module = importlib.import_module(module) if module else D
    *owners, name = name.split(".")
    for owner in owners:  # a method: MODULE:Class.name
        module = getattr(module, owner)
    fn = getattr(module, name)
    def timed(*a, **k):
        start = time.thread_time()
        try:
            return fn(*a, **k)
        finally:
            spent[stage] = spent.get(stage, 0.0) + time.thread_time() - start
    setattr(module, name, timed)
for name, stage in stages.items():
    wrap(name, stage)
frame, _ = _bench_scene(sensor, 0)
for _ in range(5):
    D.detect(frame, method=method)
rows = []
for _ in range(frames):
    spent.clear()
    start = time.thread_time()
    D.detect(frame, method=method)
    rows.append({"cpu": time.thread_time() - start, **spent})
print(json.dumps(rows))
"""


#: ``--fits``: the completion's iterative fits, wrapped where ``symfruit.core.candidates`` calls them.
FITS = {"symfruit.core.candidates:fit_revolution_slices": "revolution", "symfruit.core.candidates:fit_cone_ellipsoid":
        "cone", "symfruit.core.candidates:fit_sphere": "sphere"}  # fmt: skip

DENSE = """
import json, sys, time
from symfruit.methods.complete import complete
from symfruit.synthetic.views import bench_camera_view
method, repeat = sys.argv[1], int(sys.argv[2])
points = bench_camera_view()
for _ in range(5):
    complete(points, method=method)
rows = []
for _ in range(repeat):
    start = time.thread_time()
    complete(points, method=method)
    rows.append({"dense": time.thread_time() - start})
print(json.dumps(rows))
"""

TREES = """
import json, sys, time
from symfruit.segment.colour import segment
from symfruit.settings import resolve_settings
from symfruit.synthetic.scenes import make_tree_scene
n, repeat = int(sys.argv[1]), int(sys.argv[2])
settings = resolve_settings(fruit="apple").segment
frames = [make_tree_scene(k) for k in range(n)]
segment(frames[0].color, frames[0].depth, frames[0].camera, settings)
rows = []
for _ in range(repeat):
    for f in frames:
        start = time.thread_time()
        segment(f.color, f.depth, f.camera, settings)
        rows.append({"segment": time.thread_time() - start})
print(json.dumps(rows))
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument("--method", default="evidence")
    parser.add_argument("--rounds", type=int, default=6)
    parser.add_argument("--frames", type=int, default=10)
    parser.add_argument("--trees", type=int, default=0, help="time the segmenter on this many apple-tree frames")
    parser.add_argument("--fits", action="store_true", help="the completion's fits as stages too")
    parser.add_argument("--dense", action="store_true", help="time the dense camera view's completion instead")
    parser.add_argument("--wrap", nargs="*", default=[], help="MODULE:NAME functions timed as stages too")
    parser.add_argument("--sensor", default="", help="the frame through this camera model, its annotators' masks used")
    args = parser.parse_args()
    stages = {**STAGES, **FITS} if args.fits else dict(STAGES)
    stages.update({name: name.rpartition(":")[2] for name in args.wrap})
    trees = {"before": os.path.abspath(args.before), "after": os.path.abspath(args.after)}
    found: dict[str, list[dict[str, float]]] = {name: [] for name in trees}
    for r in range(args.rounds):
        for name in trees if r % 2 == 0 else list(trees)[::-1]:
            child = [CHILD, args.method, str(args.frames), json.dumps(stages), args.sensor]
            if args.trees:
                child = [TREES, str(args.trees), str(args.frames)]
            elif args.dense:
                child = [DENSE, args.method, str(args.frames)]
            out = subprocess.run(
                [sys.executable, "-c", *child],
                env={**os.environ, "PYTHONPATH": trees[name]}, capture_output=True, text=True, check=True,
            )  # fmt: skip
            found[name] += json.loads(out.stdout)
    if args.trees:
        sys.stdout.write(f"colour segmenter, {args.trees} apple-tree frames: thread CPU ms per frame, {args.rounds} "
                         f"rounds x {args.frames} per frame and tree, median / least\n")  # fmt: skip
    elif args.dense:
        sys.stdout.write(f"the dense camera view, method {args.method}: thread CPU ms per completion, {args.rounds} "
                         f"rounds x {args.frames} per tree, median / least\n")  # fmt: skip
    else:
        where = f" ({args.sensor}, annotators' masks)" if args.sensor else ""
        sys.stdout.write(f"detect{where}, method {args.method}: thread CPU ms per frame, {args.rounds} rounds x "
                         f"{args.frames} frames per tree, median / least\n")  # fmt: skip
    rows = ["segment"] if args.trees else ["dense"] if args.dense else ["cpu", *stages.values()]
    for stage in rows:
        cells = []
        for name in trees:
            v = np.array([row.get(stage, 0.0) for row in found[name]]) * 1000.0
            cells.append(f"{name} {np.median(v):7.1f} / {v.min():7.1f}")
        sys.stdout.write(f"{stage:>10}   " + "   ".join(cells) + "\n")


if __name__ == "__main__":
    main()
