"""Stop 59 (docs/reg59.md): how far each fruit's box moves when the frame's registration shift is one pixel other.

For every frame of ``--frames`` (rendered frames with ``truth.json`` and a masks file), ``detect`` runs with the shift
the registration finds, then with the shift forced to each of its 8 neighbours (``symfruit.detect.register`` replaced
by the masks moved by that shift). Each fruit matched by id is completed by ``evidence`` (as ``symfruit evaluate
--match id``): one line per fruit with its centre deviation from the truth and its points at the registered shift, the
largest move of its box centre between the registered shift and a neighbour, and the centre deviation and points
there. The last line counts the fruit whose box moves by more than ``--bar`` mm.

    PYTHONPATH=src python docs/reg59.py --frames F [--config '{"evidence": {"cut_width": 1}}'] [--bar 5] [--only 4]
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

import numpy as np


def _say(line: str) -> None:
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


#: per fruit id: its box centre (mm), centre deviation from the truth (mm) and its points
Fruit = dict[int, tuple[np.ndarray, float, int]]


def _boxes(frame: Any, settings: Any, shift: tuple[int, int] | None) -> tuple[Fruit, tuple[int, int]]:
    """``frame``'s fruit with the registration's shift (``shift`` None) or with ``shift`` forced, and the shift."""
    import symfruit.detect as det
    from symfruit.evaluate.frames import score_frame
    from symfruit.extract import register, shift_labels
    from symfruit.methods.complete import complete

    used: list[tuple[int, int]] = []

    def forced(labels: np.ndarray, depth: np.ndarray, camera: Any, s: Any, **kw: Any) -> Any:
        if shift is None:
            moved, found = register(labels, depth, camera, s, **kw)
            used.append(found)
            return moved, found
        used.append(shift)
        return shift_labels(labels, *shift), shift

    det.register = forced  # type: ignore[assignment]
    try:
        got = det.detect(frame, method="raw", settings=settings)
    finally:
        det.register = register  # type: ignore[assignment]
    scores, _ = score_frame(frame, got, ["evidence"], settings, by_id=True)
    found = {d.id: d for d in got.detections if d.result is not None}
    out: Fruit = {}
    for sc in scores:
        d = found[sc.fruit]
        box = complete(d.extraction.points, camera=got.camera, method="evidence", settings=settings,
                       occlusion=d.occlusion).box  # fmt: skip
        out[sc.fruit] = (np.asarray(box.centre) * 1000.0, sc.centre_mm, sc.n_points)
    return out, used[0]


def main(argv: list[str] | None = None) -> int:
    from symfruit.io.sources import open_source
    from symfruit.settings import from_dict

    p = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    p.add_argument("--frames", required=True)
    p.add_argument("--config", default='{"evidence": {"cut_width": 1}}', help="settings as JSON")
    p.add_argument("--bar", type=float, default=5.0, help="a move counted above this (mm)")
    p.add_argument("--only", default="", help="frame indices, comma separated (default all)")
    args = p.parse_args(argv)
    settings = from_dict(json.loads(args.config))
    src = open_source(args.frames)
    only = {int(i) for i in args.only.split(",") if i}
    over = total = 0
    try:
        for index, name in enumerate(src.names()):
            if only and index not in only:
                continue
            frame = src.read(index)
            base, (du, dv) = _boxes(frame, settings, None)
            near = {(du + a, dv + b): _boxes(frame, settings, (du + a, dv + b))[0]
                    for a in (-1, 0, 1) for b in (-1, 0, 1) if (a, b) != (0, 0)}  # fmt: skip
            _say(f"{name}: registered shift ({du}, {dv})")
            for fruit, (centre, err, n) in sorted(base.items()):
                worst, at, at_err, at_n = 0.0, (du, dv), err, n
                for shift, fruits in near.items():
                    if fruit in fruits and (move := float(np.linalg.norm(fruits[fruit][0] - centre))) > worst:
                        worst, at, (_, at_err, at_n) = move, shift, fruits[fruit]
                total += 1
                over += worst > args.bar
                _say(f"  fruit {fruit:3d}: centre {err:6.1f} mm, {n:5d} pts; largest move {worst:6.1f} mm at {at} "
                     f"(centre {at_err:6.1f} mm, {at_n} pts){'  *' if worst > args.bar else ''}")  # fmt: skip
    finally:
        src.close()
    _say(f"fruit moving more than {args.bar:g} mm with a shift one pixel other: {over} of {total}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
