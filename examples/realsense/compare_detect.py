"""``detect`` on the RealSense recording against ``detect`` on the same frame perfectly aligned.

    python examples/realsense/compare_detect.py [examples/realsense]

Frame 0 of ``fruit.bag`` (depth from the depth camera, aligned by symfruit) and ``aligned_00000/`` (the same
colour image, depth rendered by the colour camera itself), each fruit matched to its nearest: the centre
distance and the largest box side difference per method (mm), and each one's centre error against truth.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from symfruit.detect import detect
from symfruit.io.frames import read_frame, read_truth
from symfruit.io.sources import open_source


def main(folder: Path) -> None:
    with open_source(folder / "fruit.bag") as src:
        bag = src.read(0)
    ideal = read_frame(folder / "aligned_00000")
    truth = np.array([box.centre for _, box in read_truth(folder / "aligned_00000" / "truth.json")])
    sys.stdout.write("| method | bag vs aligned: centre (mm) | largest side difference (mm) "
                     "| centre error vs truth, bag / aligned (mm) |\n|---|---|---|---|\n")  # fmt: skip
    for method in ("raw", "sphere", "evidence"):
        a, b = (
            [d.result.box for d in detect(f, method=method).detections if d.result is not None] for f in (bag, ideal)
        )
        cb = np.array([box.centre for box in b])
        pairs = [(box, b[int(np.argmin(np.linalg.norm(cb - box.centre, axis=1)))]) for box in a]
        centre = [1000 * np.linalg.norm(x.centre - y.centre) for x, y in pairs]
        side = [1000 * np.abs(x.size - y.size).max() for x, y in pairs]
        err = [[1000 * np.linalg.norm(truth - box.centre, axis=1).min() for box in boxes] for boxes in (a, b)]
        sys.stdout.write(
            f"| {method} | {' '.join(f'{v:.1f}' for v in centre)} | {' '.join(f'{v:.1f}' for v in side)} "
            f"| {np.mean(err[0]):.1f} / {np.mean(err[1]):.1f} |\n"
        )


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent)
