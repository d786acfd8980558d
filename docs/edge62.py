"""Stop 62, helper edge62: ``extract.mask_edge_px`` (masks drawn a few pixels off their fruit, all one way, moved
back onto the colour's edges; :func:`symfruit.core.edges.mask_shift`) read in a window about each mask, and
whether one shift a mask would be right (docs/edge62.md).

    python docs/edge62.py cue FOLDER [FOLDER ...] [--base SRC]
    python docs/edge62.py real [--base SRC]

``cue``: for every frame folder (``scene_*`` under each FOLDER, or the folder itself), the frame's shift
(``mask_shift``, ``max_px`` 10), the thread CPU seconds it took, and the shift each mask alone would read (the same
rule on one mask's outline, its sides needing ``--min-side`` pixels, 20 by default as at stop 61: the what-if of
section 2), those not ``(0, 0)`` listed. ``--base SRC``: also the shift
and CPU seconds of ``mask_shift`` as another source tree has it (e.g. ``../main/src``: the whole window's version
of stop 61). ``real``: the same on both real Azure Kinect sphere frames under every perturbation of
``docs/realpert55.py``.
"""

import argparse
import importlib.util
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
MAX_PX = 10


def say(text: str) -> None:
    sys.stdout.write(text)
    sys.stdout.flush()


def _base_edges(src: str):
    """``symfruit.core.edges`` as the source tree ``src`` has it (loaded beside this tree's)."""
    name = "edge62_base_edges"
    spec = importlib.util.spec_from_file_location(name, Path(src) / "symfruit" / "core" / "edges.py",
                                                  submodule_search_locations=None)  # fmt: skip
    module = importlib.util.module_from_spec(spec)
    module.__package__ = "symfruit.core"  # its relative imports: this tree's raster module
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


#: The least outline pixels a side of one mask alone needs in the what-if (``--min-side``; stop 61's floor, 20).
MIN_SIDE = [20]


def per_mask(color: np.ndarray, masks: np.ndarray) -> dict[int, tuple[int, int]]:
    """The shift each mask alone reads (``mask_shift``'s rule on its own outline pixels and window, its sides
    needing ``MIN_SIDE[0]`` pixels)."""
    from symfruit.core import edges

    parts = edges._mask_costs(color, masks, max_px=MAX_PX, cap=6.0, max_points=8000)
    return {k: edges._decide(every, gx, gy, MAX_PX, 6.0, 0.7, MIN_SIDE[0]) for k, every, gx, gy in parts}


def _timed(fn, *args):
    start = time.thread_time()
    out = fn(*args)
    return out, time.thread_time() - start


def _line(name: str, color: np.ndarray, masks: np.ndarray, base) -> str:
    from symfruit.core.edges import mask_shift

    found, cpu = _timed(lambda c, m: mask_shift(c, m, max_px=MAX_PX), color, masks)
    mine = per_mask(color, masks)
    moved = {k: v for k, v in mine.items() if v != (0, 0)}
    out = f"{name}: frame {found} {cpu:.3f} s; masks {len(mine)}, alone moved {len(moved)} {moved}"
    if base is not None:
        old, old_cpu = _timed(lambda c, m: base.mask_shift(c, m, max_px=MAX_PX), color, masks)
        out += f"; base {old} {old_cpu:.3f} s"
    return out


def cue(folders: list[str], base) -> None:
    from symfruit.io.frames import read_frame

    for folder in folders:
        found = sorted(Path(folder).glob("scene_*")) or [Path(folder)]
        for path in found:
            frame = read_frame(path)
            if frame.masks is None:  # the colour segmenter's masks: mask_edge_px does not act on them
                say(f"{path}: no masks\n")
                continue
            say(_line(str(path), frame.color, frame.masks, base) + "\n")


def real(base) -> None:
    from symfruit.io.frames import read_frame

    spec = importlib.util.spec_from_file_location("realpert55", HERE / "realpert55.py")
    rp = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(rp)
    for name in rp.PERTURBATIONS:
        for k in (0, 1):
            color, _, masks, _ = rp.PERTURBATIONS[name](read_frame(rp.FRAMES / f"lab-spheres-{k}"))
            say(_line(f"{name} frame {k}", color, masks, base) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    one = sub.add_parser("cue", help="the frame's and each mask's shift on frame folders")
    one.add_argument("folders", nargs="+")
    two = sub.add_parser("real", help="the same on the real sphere frames' perturbations")
    for p in (one, two):
        p.add_argument("--base", help="another source tree's mask_shift too (its src folder)")
        p.add_argument("--min-side", type=int, default=20, help="a side's least pixels for one mask alone (20)")
    args = parser.parse_args()
    MIN_SIDE[0] = args.min_side
    base = _base_edges(args.base) if args.base else None
    if args.command == "cue":
        cue(args.folders, base)
    else:
        real(base)


if __name__ == "__main__":
    main()
