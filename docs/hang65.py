"""Stop 65, helper hang65 (issue 18): the depth prior read across gravity (``evidence.prior_axis: gravity``).

``sides SUMMARY.json ...``: per ``symfruit evaluate --frames`` run (its ``summary.json``), the fruit's IoU, centre
and box sides (mean absolute error, mean signed error in brackets, mm) over all matched fruit and by how much of
each the camera sees (visible >= 0.9, partly 0.6-0.9, mostly hidden < 0.6), as the run's table.md gives them.
``paired BEFORE.json AFTER.json``: per fruit matched in both, the change of the depth side's signed error and of
the IoU, by visibility group (median and mean), and how many fruit moved. ``faces FRAMES CONFIG.yaml ...``: the
evaluation of ``symfruit evaluate --frames FRAMES --match id --methods evidence --config CONFIG.yaml`` again, with
each box's front and back face against the truth's (signed, mm: positive is farther from the camera), by group.

Reruns (text):

    printf 'evidence: {cut_width: 1, prior_axis: gravity}\\n' > CWG.yaml
    symfruit evaluate --frames TREES --match id --methods evidence --config CWG.yaml --output OUT
    python docs/hang65.py sides OUT/latest/summary.json /tmp/lead65/shared/eval-trees0/latest/summary.json
    python docs/hang65.py paired BEFORE/latest/summary.json OUT/latest/summary.json
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

GROUPS = (("all", 0.0, 2.0), ("visible", 0.9, 2.0), ("partly", 0.6, 0.9), ("mostly hidden", 0.0, 0.6))


def _scores(path: str) -> list[dict[str, Any]]:
    return [r for r in json.loads(Path(path).read_text())["scores"] if r.get("truth") is not None]


def _ma(x: np.ndarray) -> str:
    return f"{np.mean(np.abs(x)):.1f} ({np.mean(x):+.1f})" if len(x) else "-"


def _say(text: str) -> None:
    sys.stdout.write(text + "\n")


def sides(paths: list[str]) -> None:
    _say("| run | group | n | IoU | centre (mm) | depth side (mm) | larger lateral side (mm) |")
    _say("|---|---|---|---|---|---|---|")
    for path in paths:
        rows = _scores(path)
        for name, lo, hi in GROUPS:
            g = [r for r in rows if lo <= r["visible"] < hi]
            iou = np.mean([r["iou"] for r in g])
            centre = np.mean([r["centre_mm"] for r in g])
            depth = np.array([r["depth_mm"] for r in g])
            lateral = np.array([r["lateral_mm"] for r in g])
            _say(f"| {path} | {name} | {len(g)} | {iou:.3f} | {centre:.2f} | {_ma(depth)} | {_ma(lateral)} |")


def paired(before: str, after: str) -> None:
    key = lambda r: (r["frame"], r["truth"])  # noqa: E731
    old = {key(r): r for r in _scores(before)}
    _say("| group | n | moved | depth signed error change, median / mean (mm) | IoU change, mean |")
    _say("|---|---|---|---|---|")
    new = [r for r in _scores(after) if key(r) in old]
    for name, lo, hi in GROUPS:
        g = [(old[key(r)], r) for r in new if lo <= r["visible"] < hi]
        d = np.array([b["depth_mm"] - a["depth_mm"] for a, b in g])
        i = np.array([b["iou"] - a["iou"] for a, b in g])
        moved = int(np.sum(np.abs(d) > 0.05))
        _say(f"| {name} | {len(g)} | {moved} | {np.median(d):+.2f} / {np.mean(d):+.2f} | {np.mean(i):+.4f} |")


def faces(frames: str, configs: list[str], visible: float) -> None:
    from symfruit.evaluate import frames as fr
    from symfruit.settings import resolve_settings

    _say("| config | group | n | front (mm) | back (mm) | centre depth (mm) | depth side (mm) |")
    _say("|---|---|---|---|---|---|---|")
    truth = {}
    for f in sorted(Path(frames).glob("*/truth.json")):
        for x in json.loads(f.read_text())["fruits"]:
            truth[(f.parent.name, x["id"])] = x
    complete_of = fr.complete
    for config in configs:
        boxes: list[Any] = []

        def complete(*args: Any, boxes: list[Any] = boxes, **kwargs: Any) -> Any:
            result = complete_of(*args, **kwargs)  # raises: no score, no box
            boxes.append(result.box)
            return result

        fr.complete = complete
        try:
            scores, _totals, _failed = fr.evaluate_frames(
                frames, methods=["evidence"], settings=resolve_settings(config=config), by_id=True
            )
        finally:
            fr.complete = complete_of
        if len(scores) != len(boxes):
            raise SystemExit(f"{len(scores)} scores, {len(boxes)} boxes: cannot pair them")
        for name, lo, hi in (("all", 0.0, 2.0), ("visible", visible, 2.0), ("not visible", 0.0, visible)):
            out = []
            for s, b in zip(scores, boxes, strict=True):
                if not lo <= s.visible < hi:
                    continue
                x = truth[(s.frame, s.truth)]
                front, back = 1000 * (b.min[2] - x["min"][2]), 1000 * (b.max[2] - x["max"][2])
                out.append((front, back, 0.5 * (front + back), back - front))
            o = np.array(out)
            cols = " | ".join(_ma(o[:, k]) for k in range(4))
            _say(f"| {Path(config).name} | {name} | {len(o)} | {cols} |")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("sides", help="IoU, centre and box sides by visibility group of evaluate summaries")
    s.add_argument("runs", nargs="+")
    q = sub.add_parser("paired", help="per-fruit change of the depth side and IoU from BEFORE to AFTER")
    q.add_argument("before")
    q.add_argument("after")
    f = sub.add_parser("faces", help="evaluate FRAMES again per CONFIG: the boxes' front and back against the truth")
    f.add_argument("frames")
    f.add_argument("configs", nargs="+")
    f.add_argument("--visible", type=float, default=0.9)
    a = p.parse_args()
    if a.cmd == "sides":
        sides(a.runs)
    elif a.cmd == "paired":
        paired(a.before, a.after)
    else:
        faces(a.frames, a.configs, a.visible)


if __name__ == "__main__":
    main()
