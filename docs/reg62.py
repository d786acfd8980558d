"""The moved masks' boxes of the benchmark frame (stop 62, reg62): ``detect``'s boxes of the masks moved onto the
depth image (after ``_kept_caps`` gave pixels back), by a pass over the whole image (``_label_boxes``, before) and
within each mask's drawn box moved (``_moved_boxes``, after), alternated in one process on the frame's own labels:
the thread's CPU time of each, median / least over many passes, and the two boxes compared.

    PYTHONPATH=src python docs/reg62.py [--passes 2000] [--kernels numpy]

The compiled kernels' own before/after (``clusters``, ``cap_outline``) are replayed by ``docs/speedt61.py``::

    python docs/speedt61.py record CALLS.pkl clusters cap_outline
    python docs/speedt61.py time CALLS.pkl BEFORE/src/symfruit/core/_jit.py src/symfruit/core/_jit.py
"""

import argparse
import os
import sys
import time

import numpy as np


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--passes", type=int, default=2000, help="timed passes of each (2000)")
    parser.add_argument("--kernels", choices=["compiled", "numpy"], default="compiled", help="SYMFRUIT_KERNELS")
    args = parser.parse_args(argv)
    if args.kernels == "numpy":
        os.environ["SYMFRUIT_KERNELS"] = "numpy"
    import symfruit.detect as detect_module
    from symfruit.evaluate.bench import _bench_scene

    seen: list[tuple] = []
    moved_boxes = detect_module._moved_boxes

    def wrapped(moved: np.ndarray, drawn: list, shift: tuple[int, int]) -> list:
        seen.append((moved.copy(), list(drawn), shift))
        return moved_boxes(moved, drawn, shift)

    detect_module._moved_boxes = wrapped
    frame, _ = _bench_scene(None, 0)
    detect_module.detect(frame, method="evidence")
    detect_module._moved_boxes = moved_boxes
    if not seen:
        sys.stdout.write("the frame's masks were not moved and no pixel was given back: no boxes looked for again\n")
        return
    moved, drawn, shift = seen[-1]
    hi = len(drawn)
    before, after = detect_module._label_boxes(moved, hi), moved_boxes(moved, drawn, shift)
    times: dict[str, list[float]] = {"before": [], "after": []}
    for i in range(args.passes):
        for name in ("before", "after") if i % 2 == 0 else ("after", "before"):
            start = time.thread_time()
            if name == "before":
                detect_module._label_boxes(moved, hi)
            else:
                moved_boxes(moved, drawn, shift)
            times[name].append(time.thread_time() - start)
    sys.stdout.write(f"{hi} masks, {moved.shape[1]}x{moved.shape[0]}, shift {shift}, kernels {args.kernels}: the "
                     f"same boxes {before == after}\n")  # fmt: skip
    for name, spent in times.items():
        ms = np.array(spent) * 1000.0
        sys.stdout.write(f"{name:>6}: {np.median(ms):.4f} / {ms.min():.4f} ms (median / least of {args.passes})\n")


if __name__ == "__main__":
    main()
