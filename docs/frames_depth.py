"""Signed errors of the centre's depth and of the front and back faces on annotated frames (Table 3's matched
fruit), per method: how far back a method's boxes sit (docs/ablation.md, issue 18 item 3).

    python docs/frames_depth.py FRAMES [--methods raw,paper,evidence]

e.g. after ``symfruit scenes F --n 6 --sensor azure-kinect``. Cells: mean (mm; positive: too far) over the
matched fruit.
"""

import argparse
import sys

import numpy as np

from symfruit.detect import detect
from symfruit.evaluate.frames import match
from symfruit.io.sources import open_source
from symfruit.methods.complete import complete
from symfruit.settings import Settings


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("frames")
    parser.add_argument("--methods", default="raw,paper,evidence")
    args = parser.parse_args()
    methods = args.methods.split(",")
    settings = Settings()
    rows: dict[str, list[list[float]]] = {m: [] for m in methods}
    src = open_source(args.frames)
    try:
        for index, _ in enumerate(src.names()):
            frame = src.read(index)
            truth = frame.truth or []
            found = detect(frame, method="raw", settings=settings)
            ok = [d for d in found.detections if d.result is not None]
            for i, j in match([d.visible_box for d in ok], [b for _, b in truth]):
                d, t = ok[i], truth[j][1]
                for m in methods:
                    b = complete(d.extraction.points, camera=found.camera, method=m, settings=settings,
                                 occlusion=d.occlusion).box  # fmt: skip
                    rows[m].append([1000 * (b.centre[2] - t.centre[2]), 1000 * (b.min[2] - t.min[2]),
                                    1000 * (b.max[2] - t.max[2])])  # fmt: skip
    finally:
        src.close()
    sys.stdout.write("| method | fruit | centre depth (mm) | front face (mm) | back face (mm) |\n")
    sys.stdout.write("|---|---|---|---|---|\n")
    for m in methods:
        a = np.mean(rows[m], axis=0)
        sys.stdout.write(f"| {m} | {len(rows[m])} | {a[0]:+.1f} | {a[1]:+.1f} | {a[2]:+.1f} |\n")


if __name__ == "__main__":
    main()
