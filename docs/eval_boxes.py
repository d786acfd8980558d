"""Run ``symfruit evaluate`` and write every completion's box next to its results, then compare two such runs
instance by instance: how many boxes moved by more than a tolerance (issue 19's accuracy check for changes that
may move results: every instance within 0.1 mm, box faces and centre).

    python docs/eval_boxes.py run BOXES.csv evaluate --protocol camera --sensor heldback --fruit all --n 30 ...
    python docs/eval_boxes.py compare BEFORE.csv AFTER.csv [--tolerance-mm 0.1] [--list]

``run`` takes ``symfruit evaluate``'s own arguments (``--jobs`` included: each worker appends its rows); the
box rows are ``key, min x/y/z, max x/y/z`` in metres, the key the instance (kind, fruit, pose, occlusion) and the
method; with ``evaluate --frames FOLDER`` the key is ``frames``, the frame, the fruit's id and the method (every
fruit matched to the truth). Run it with ``PYTHONPATH=TREE/src`` to measure another tree.
"""

import argparse
import csv
import os
import sys

import numpy as np


def run(boxes: str, argv: list[str]) -> int:
    import symfruit.evaluate.runner as runner
    from symfruit.cli import main

    os.makedirs(os.path.dirname(os.path.abspath(boxes)), exist_ok=True)
    open(boxes, "w").close()
    evaluate_one, score = runner._evaluate, runner.score_completion
    scored: list = []

    def keep_box(box, *args, **kwargs):
        scored.append(box)
        return score(box, *args, **kwargs)

    def evaluate_with_boxes(spec, methods, settings):
        scored.clear()
        rows = evaluate_one(spec, methods, settings)
        with open(boxes, "a") as out:  # one line per row, appended: workers write whole lines
            for r in rows:
                key = f"{r.kind}|{r.fruit_index}|{r.pose}|{r.occlusion}|{r.method}"
                box = None if r.error else scored.pop(0)
                values = [float("nan")] * 6 if box is None else [float(v) for v in (*box.min, *box.max)]
                out.write(key + "," + ",".join(repr(v) for v in values) + "\n")
        return rows

    runner.score_completion = keep_box
    runner._evaluate = evaluate_with_boxes
    _record_frames(boxes)
    return main(argv)


def _record_frames(boxes: str) -> None:
    """``evaluate --frames``: one row per scored fruit and method, keyed ``frames|frame|fruit id|method`` (the box
    each score is made of: score_frame scores a box by box_iou once, in the order of its scores)."""
    import symfruit.evaluate.frames as frames

    iou, score_frame = frames.box_iou, frames.score_frame
    seen: list = []

    def keep_box(box, truth):
        seen.append(box)
        return iou(box, truth)

    def score_with_boxes(*args, **kwargs):
        seen.clear()
        scores, counts = score_frame(*args, **kwargs)
        with open(boxes, "a", newline="") as out:
            rows = csv.writer(out)  # a frame's name may hold a comma: quoted, as load's csv.reader reads it
            for s, box in zip(scores, seen, strict=True):
                values = (repr(float(v)) for v in (*box.min, *box.max))
                rows.writerow([f"frames|{s.frame}|{s.fruit}|{s.method}", *values])
        return scores, counts

    frames.box_iou = keep_box
    frames.score_frame = score_with_boxes


def load(path: str) -> dict[str, np.ndarray]:
    with open(path) as f:
        return {row[0]: np.array([float(v) for v in row[1:]]) for row in csv.reader(f)}


def compare(before: str, after: str, tolerance_mm: float, listed: bool = False) -> int:
    a, b = load(before), load(after)
    keys = sorted(set(a) & set(b))
    moved, worst = 0, 0.0
    lines = []
    for k in keys:
        if np.isnan(a[k]).all() and np.isnan(b[k]).all():
            continue
        faces = np.abs(b[k] - a[k]) * 1000.0
        centre = np.linalg.norm(((b[k][:3] - a[k][:3]) + (b[k][3:] - a[k][3:])) / 2.0) * 1000.0  # 0 when equal
        d = float(max(np.nanmax(faces) if np.isfinite(faces).any() else np.inf, centre))
        worst = max(worst, d)
        moved += int(not d <= tolerance_mm)
        if listed and not d <= tolerance_mm:
            lines.append(f"  {k}: {d:.3f} mm\n")
    sys.stdout.write(
        f"{len(keys)} instances in both ({len(a)} before, {len(b)} after); {moved} moved by more than "
        f"{tolerance_mm:g} mm (a box face or the centre); the largest move {worst:.4g} mm\n"
    )
    sys.stdout.write("".join(lines))
    return 0


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("boxes")
    r.add_argument("evaluate", nargs=argparse.REMAINDER)
    c = sub.add_parser("compare")
    c.add_argument("before")
    c.add_argument("after")
    c.add_argument("--tolerance-mm", type=float, default=0.1)
    c.add_argument("--list", action="store_true", help="every instance moved beyond the tolerance, and how far")
    args = parser.parse_args()
    if args.cmd == "run":
        sys.exit(run(args.boxes, args.evaluate))
    sys.exit(compare(args.before, args.after, args.tolerance_mm, args.list))
