"""The shared strawberry photographs' two halves (README, "Segmentation on photographs"): half 0 to develop on,
half 1 held out.

    python docs/photo_halves.py [IMAGES_DIR]     # default ../shared/data/strawberry-photos/train

Roboflow exports several augmented copies of one source photograph (``NAME_jpg.rf.HASH.jpg``); a split by image
would put copies of one photograph on both sides. So the halves split by source photograph: half ``crc32(NAME) %
2``, ``NAME`` the file name before ``_jpg`` (the whole name where there is none). For each half and for all the
photographs, one README row from the masks protocol as ``symfruit evaluate --protocol masks --images DIR --truth
DIR/_annotations.coco.json`` runs it (the colour segmenter with the strawberry profile): mean best-match IoU,
matched at IoU 0.5, false among the found, ms per image (median / p90, machine-dependent).
"""

import argparse
import json
import sys
import zlib
from pathlib import Path

from symfruit.evaluate.masks import evaluate_masks
from symfruit.segment import mask_source
from symfruit.settings import resolve_settings

say = sys.stdout.write


def half(file_name: str) -> int:
    """Which half a photograph belongs to: by its source photograph's name."""
    return zlib.crc32(file_name.split("_jpg")[0].encode()) % 2


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("images", nargs="?", default="../shared/data/strawberry-photos/train")
    args = parser.parse_args()
    images = Path(args.images)
    truth = images / "_annotations.coco.json"
    names = [im["file_name"] for im in json.loads(truth.read_text())["images"]]
    labeller = mask_source("color", settings=resolve_settings(fruit="strawberry"), images=())

    def run(color, depth=None, camera=None, name="", color_file=None):
        return labeller(color, depth, camera, name=name, color_file=color_file)[0]

    say("| data | mean best-match IoU | matched at IoU 0.5 | false (of found) | ms per image, median / p90 |\n")
    say("|---|---|---|---|---|\n")
    for label, chosen in (
        ("half 0", [n for n in names if half(n) == 0]),
        ("half 1", [n for n in names if half(n) == 1]),
        ("all", names),
    ):
        s = evaluate_masks(images, truth, run, names=chosen, files=True).summary
        say(f"| {label} ({s['images']} images) | {s['mean_best_iou']:.3f} | {s['matched']:,} / {s['true_fruit']:,} "
              f"({s['matched_share']:.1%}) | {s['false']} / {s['detections']:,} ({s['false_share']:.1%}) | "
              f"{s['ms_median']:.1f} / {s['ms_p90']:.1f} |\n")  # fmt: skip
        sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
