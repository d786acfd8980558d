"""Stop 62, helper edgespeed62: :func:`symfruit.core.edges.mask_shift` (``extract.mask_edge_px``, on by default)
timed against another source tree's on frames with masks, and checked to give the same costs and shifts
(docs/edgespeed62.md).

    python docs/edgespeed62.py --base ../main/src [--rounds 8] [--trees FOLDER ...] [--no-real] [--no-bench]

Frames: the benchmark frame with its annotators' masks through the three camera models
(``symfruit.evaluate.bench._bench_scene``), every ``scene_*`` with masks under each ``--trees`` folder, and the
two real Azure Kinect sphere frames under every perturbation of ``docs/realpert55.py`` (timed only unperturbed
and ``shift+5y``; all checked). Each frame: both trees' ``mask_shift`` with the masks' boxes given (as ``detect``
calls it), alternated ``--rounds`` times in one process, the thread's CPU milliseconds (median and least), and
whether the outline pixels' costs at every shift (``_mask_costs``) and the shift are the same to the bit.
"""

import argparse
import importlib.util
import sys
import time
from pathlib import Path

import numpy as np
from scipy import ndimage

HERE = Path(__file__).resolve().parent
MAX_PX = 10


def say(text: str) -> None:
    sys.stdout.write(text + "\n")
    sys.stdout.flush()


def other_edges(src: str):
    """``symfruit.core.edges`` as the source tree ``src`` has it (loaded beside this tree's; its relative imports
    this tree's)."""
    name = "edgespeed62_base_edges"
    spec = importlib.util.spec_from_file_location(name, Path(src) / "symfruit" / "core" / "edges.py")
    module = importlib.util.module_from_spec(spec)
    module.__package__ = "symfruit.core"
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def same_costs(a: list, b: list) -> bool:
    return len(a) == len(b) and all(
        x[0] == y[0] and all(np.array_equal(u, v) for u, v in zip(x[1:], y[1:], strict=True))
        for x, y in zip(a, b, strict=True)
    )


def compare(name: str, color: np.ndarray, masks: np.ndarray, base, rounds: int) -> bool:
    """One frame's line: CPU ms of both trees' ``mask_shift`` (alternated), the shifts, and whether the costs and
    shifts are the same. ``rounds`` 0: checked only."""
    from symfruit.core import edges

    boxes = ndimage.find_objects(masks)
    kw = {"max_px": MAX_PX, "cap": 6.0, "max_points": 8000}
    same = same_costs(base._mask_costs(color, masks, **kw), edges._mask_costs(color, masks, **kw))
    shifts = [f(color, masks, max_px=MAX_PX, boxes=boxes) for f in (base.mask_shift, edges.mask_shift)]
    same = same and shifts[0] == shifts[1]
    line = (
        f"{name}: {len(boxes)} masks, shift {shifts[0]} -> {shifts[1]}, costs and shift {'same' if same else 'DIFFER'}"
    )
    if rounds:
        spent: list[list[float]] = [[], []]
        for _ in range(rounds):
            for i, fn in enumerate((base.mask_shift, edges.mask_shift)):
                start = time.thread_time()
                fn(color, masks, max_px=MAX_PX, boxes=boxes)
                spent[i].append(1e3 * (time.thread_time() - start))
        (a, b) = (np.median(s) for s in spent)
        least = f"least {min(spent[0]):.2f} -> {min(spent[1]):.2f}"
        line += f"; cpu ms median {a:.2f} -> {b:.2f} ({100 * (b / a - 1):+.0f} %), {least}"
    say(line)
    return same


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--base", required=True, help="the other source tree's src folder (the 'before')")
    parser.add_argument("--rounds", type=int, default=8, help="timing rounds a frame, alternated (0: check only)")
    parser.add_argument("--trees", nargs="*", default=[], help="folders of frames with masks (scene_* under each)")
    parser.add_argument("--no-real", action="store_true", help="skip the real frames")
    parser.add_argument("--no-bench", action="store_true", help="skip the benchmark frames")
    args = parser.parse_args()
    base = other_edges(args.base)
    from symfruit.io.frames import read_frame

    differ = 0
    if not args.no_bench:
        from symfruit.evaluate.bench import _bench_scene

        for sensor in ("azure-kinect", "realsense-d435", "realsense-d405"):
            frame, _ = _bench_scene(sensor, 0)
            differ += not compare(f"bench {sensor} {frame.color.shape[1]}x{frame.color.shape[0]}", frame.color,
                                  frame.masks, base, args.rounds)  # fmt: skip
    for folder in args.trees:
        for path in sorted(Path(folder).glob("scene_*")):
            frame = read_frame(path)
            if frame.masks is not None:
                differ += not compare(str(path), frame.color, frame.masks, base, args.rounds)
    if not args.no_real:
        spec = importlib.util.spec_from_file_location("realpert55", HERE / "realpert55.py")
        rp = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(rp)
        for name in rp.PERTURBATIONS:
            for k in (0, 1):
                color, _, masks, _ = rp.PERTURBATIONS[name](read_frame(rp.FRAMES / f"lab-spheres-{k}"))
                timed = args.rounds if name in ("none", "shift+5y") else 0
                differ += not compare(f"real {name} frame {k}", color, masks, base, timed)
    say(f"frames whose costs or shift differ: {differ}")


if __name__ == "__main__":
    main()
