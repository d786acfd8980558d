"""Stop 64, helper reg64: :func:`symfruit.core.edges.mask_shift`'s distance maps (``_jit.capped_distances``) on frames
with masks, recorded for ``docs/speedt61.py time`` and timed end to end against another source tree
(docs/reg64.md).

    python docs/reg64.py record CALLS.pkl [--trees FOLDER ...] [--no-bench] [--no-real]
    python docs/speedt61.py time CALLS.pkl OLD/_jit.py NEW/_jit.py --passes 3
    python docs/reg64.py ab BASE/src src --trees FOLDER ... [--rounds 4]

``record``: every ``jit.capped_distances`` call of ``mask_shift`` (the masks' boxes given, as ``detect`` calls it) on
every ``scene_*`` with masks under each ``--trees`` folder, the benchmark frame with its annotators' masks through the
three camera models and the two real Azure Kinect sphere frames under every perturbation of ``docs/realpert55.py``,
in ``docs/speedt61.py``'s format (its ``time`` replays them on two ``_jit.py`` files and compares the outputs byte
for byte). ``ab``: ``mask_shift``'s thread CPU a tree frame, each tree in a fresh process (``PYTHONPATH``), the two
alternated round by round, three passes over the frames a round; median and least.
"""

import argparse
import copy
import importlib.util
import json
import os
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent

CHILD = r"""
import json, sys, time
from pathlib import Path
from scipy import ndimage
from symfruit.core import edges
from symfruit.io.frames import read_frame
frames = [read_frame(p) for folder in sys.argv[1:] for p in sorted(Path(folder).glob("scene_*"))]
frames = [f for f in frames if f.masks is not None]
for f in frames[:2]:
    edges.mask_shift(f.color, f.masks, boxes=ndimage.find_objects(f.masks))
spent = []
for _ in range(3):
    for f in frames:
        boxes = ndimage.find_objects(f.masks)
        start = time.thread_time()
        edges.mask_shift(f.color, f.masks, boxes=boxes)
        spent.append(time.thread_time() - start)
print(json.dumps(spent))
"""


def _frames(trees: list[str], bench: bool, real: bool) -> list[tuple[np.ndarray, np.ndarray]]:
    from symfruit.io.frames import read_frame

    found = []
    for folder in trees:
        for path in sorted(Path(folder).glob("scene_*")):
            frame = read_frame(path)
            if frame.masks is not None:
                found.append((frame.color, frame.masks))
    if bench:
        from symfruit.evaluate.bench import _bench_scene

        for sensor in ("azure-kinect", "realsense-d435", "realsense-d405"):
            frame, _ = _bench_scene(sensor, 0)
            found.append((frame.color, frame.masks))
    if real:
        spec = importlib.util.spec_from_file_location("realpert55", HERE / "realpert55.py")
        assert spec is not None and spec.loader is not None
        rp = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(rp)
        for name in rp.PERTURBATIONS:
            for k in (0, 1):
                color, _, masks, _ = rp.PERTURBATIONS[name](read_frame(rp.FRAMES / f"lab-spheres-{k}"))
                found.append((color, masks))
    return found


def record(out: str, trees: list[str], bench: bool, real: bool) -> None:
    from scipy import ndimage

    import symfruit.core._jit as jit
    from symfruit.core import edges

    frames = _frames(trees, bench, real)
    calls: dict[str, list] = {"capped_distances": []}
    kernel = jit.capped_distances

    def recorded(*args, **kwargs):
        calls["capped_distances"].append((copy.deepcopy(args), copy.deepcopy(kwargs)))
        return kernel(*args, **kwargs)

    jit.capped_distances = recorded
    for color, masks in frames:
        edges.mask_shift(color, masks, boxes=ndimage.find_objects(masks))
    with open(out, "wb") as f:
        pickle.dump(calls, f)
    sys.stdout.write(f"{len(frames)} frames, {len(calls['capped_distances'])} calls\n")


def ab(base: str, new: str, trees: list[str], rounds: int) -> None:
    spent: dict[str, list[float]] = {base: [], new: []}
    for r in range(rounds):
        for src in (base, new) if r % 2 == 0 else (new, base):
            env = dict(os.environ, PYTHONPATH=src)
            run = subprocess.run([sys.executable, "-c", CHILD, *trees], env=env, capture_output=True, text=True,
                                 check=True)  # fmt: skip
            spent[src] += json.loads(run.stdout.strip().splitlines()[-1])
    for src, values in spent.items():
        ms = 1e3 * np.array(values)
        sys.stdout.write(f"{src}: mask_shift a tree frame, thread CPU ms median {np.median(ms):.1f} least "
                         f"{ms.min():.1f} ({len(ms)} frames)\n")  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="what", required=True)
    rec = sub.add_parser("record", help="record mask_shift's capped_distances calls (docs/speedt61.py's format)")
    rec.add_argument("calls", help="the pickle to write")
    rec.add_argument("--trees", nargs="*", default=[], help="folders of frames with masks (scene_* under each)")
    rec.add_argument("--no-bench", action="store_true", help="leave out the benchmark frame's three cameras")
    rec.add_argument("--no-real", action="store_true", help="leave out the perturbed real sphere frames")
    cmp = sub.add_parser("ab", help="mask_shift's CPU a tree frame, two source trees alternated")
    cmp.add_argument("base", help="the before tree's src")
    cmp.add_argument("new", help="the after tree's src")
    cmp.add_argument("--trees", nargs="+", required=True, help="folders of frames with masks (scene_* under each)")
    cmp.add_argument("--rounds", type=int, default=4)
    args = parser.parse_args(argv)
    if args.what == "record":
        record(args.calls, args.trees, not args.no_bench, not args.no_real)
    else:
        ab(args.base, args.new, args.trees, args.rounds)


if __name__ == "__main__":
    main()
