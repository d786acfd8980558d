"""How colour trimming (``symfruit.core.surface.colour_trim``) treats real annotators' masks: the shared
strawberry photos' COCO masks as they are (they should stay) and grown by 2 and 4 px (they should shrink
back). Prints the mean error of the trimmed mask's equivalent diameter against the annotated one.

    python docs/trim_check.py [--photos DIR] [--every N]
"""

import argparse
import sys
from pathlib import Path

import numpy as np
from scipy import ndimage

from symfruit.core.surface import colour_trim
from symfruit.io.images import read_color
from symfruit.io.masks import read_coco


def labels_of(instances: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """(h, w) labels of ``CocoSet.instances``' (n, h, w) masks; the first of two overlapping keeps a pixel."""
    out = np.zeros(shape, np.int32)
    for i, m in enumerate(instances, 1):
        out[m & (out == 0)] = i
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--photos", type=Path, default=Path("../shared/data/strawberry-photos/train"))
    parser.add_argument("--every", type=int, default=4, help="every Nth photo in name order")
    args = parser.parse_args()
    coco = read_coco(args.photos / "_annotations.coco.json")
    names = sorted(p.name for p in args.photos.glob("*.jpg"))[:: args.every]
    errors: dict[int, list[float]] = {0: [], 2: [], 4: []}
    for name in names:
        color = read_color(args.photos / name)
        labels = labels_of(coco.instances(name, color.shape[:2]), color.shape[:2])
        for k, sl in enumerate(ndimage.find_objects(labels), 1):
            if sl is None:
                continue
            r0, r1 = max(sl[0].start - 12, 0), sl[0].stop + 12
            c0, c1 = max(sl[1].start - 12, 0), sl[1].stop + 12
            mask = labels[r0:r1, c0:c1] == k
            if mask.sum() < 200:
                continue
            diameter = 2 * np.sqrt(mask.sum() / np.pi)
            for grow in errors:
                grown = ndimage.binary_dilation(mask, iterations=grow) if grow else mask
                grown &= (labels[r0:r1, c0:c1] == 0) | mask  # not onto another fruit
                band = min(4.0, 0.2 * np.sqrt(grown.sum() / np.pi))
                kept = colour_trim(color[r0:r1, c0:c1], grown, band_px=band)
                errors[grow].append(2 * np.sqrt(kept.sum() / np.pi) - diameter)
    for grow, values in errors.items():
        v = np.array(values)
        sys.stdout.write(
            f"masks grown by {grow} px: {len(v)} fruit, trimmed diameter - annotated: mean "
            f"{v.mean():+.2f} px, mean abs {np.abs(v).mean():.2f} px (untrimmed: {2 * grow:+d} px)\n"
        )


if __name__ == "__main__":
    main()
