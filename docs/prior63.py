"""Where two runs' boxes of the annotated frames lie against the truth along the line of sight (issue 18, stop 63,
docs/prior63.md): per visibility group, the mean error of the box's front face, of its back face and of its centre's
depth (box less truth, mm: positive is behind), and the mean centre distance, for each run; then the fruit whose
centre moved by more than 1 mm.

    python docs/eval_boxes.py run A.csv evaluate --frames FRAMES --match id --methods evidence --config CW1.yaml ...
    python docs/eval_boxes.py run B.csv evaluate --frames FRAMES --match id --methods evidence --config B.yaml ...
    python docs/prior63.py FRAMES A.csv B.csv [--bias 0.002 0.001]

``FRAMES`` is the folder of frames with their ``truth.json`` (``symfruit scenes FRAMES --scene apple-tree ...``).
"""

import argparse
import csv
import json
import sys
from pathlib import Path

import numpy as np

GROUPS = (("visible (>= 90 %)", 0.9, 1.01), ("partly hidden (60-90 %)", 0.6, 0.9), ("mostly hidden (< 60 %)", 0.0, 0.6))


def load(path: Path) -> dict[tuple[str, int], np.ndarray]:
    """``eval_boxes.py run``'s rows of ``evaluate --frames`` (key ``frames|FRAME|ID|METHOD``): (frame, id) -> the box's
    six faces (min x, y, z, max x, y, z), metres."""
    with open(path) as f:
        return {
            (r[0].split("|")[1], int(r[0].split("|")[2])): np.array([float(v) for v in r[1:7]]) for r in csv.reader(f)
        }


def faces(frames: Path, a: Path, b: Path, bias: tuple[float, float] = (0.0, 0.0)) -> str:
    """The table and the list (see the module). ``bias``: ``(const, linear)`` of a range bias ``const + linear * z``
    (metres, positive too far) taken off both runs' boxes first (moved nearer by the bias at the truth's centre
    depth), as a camera calibrated for it would see them."""
    boxes = load(a), load(b)
    rows = []
    for frame, fid in sorted(set(boxes[0]) & set(boxes[1])):
        truth = {f["id"]: f for f in json.loads((frames / frame / "truth.json").read_text())["fruits"]}[fid]
        lo, hi, centre = (np.array(truth[k]) for k in ("min", "max", "centre"))
        errs = []
        for run in boxes:
            box = run[(frame, fid)].copy()
            box[[2, 5]] -= bias[0] + bias[1] * centre[2]
            off = 0.5 * (box[:3] + box[3:]) - centre
            errs.append(
                (1e3 * (box[2] - lo[2]), 1e3 * (box[5] - hi[2]), 1e3 * off[2], 1e3 * float(np.linalg.norm(off)))
            )
        rows.append((frame, fid, float(truth["visible"]), errs))
    lines = ["| group | n | front (mm) | back A / B (mm) | centre depth A / B (mm) | centre distance A / B (mm) |",
             "|---|---|---|---|---|---|"]  # fmt: skip
    for name, low, high in (("all", 0.0, 1.01), *GROUPS):
        g = [r for r in rows if low <= r[2] < high]
        if not g:
            continue
        m = np.array([[e for run in r[3] for e in run] for r in g]).mean(axis=0)
        lines.append(f"| {name} | {len(g)} | {m[0]:+.2f} | {m[1]:+.2f} / {m[5]:+.2f} | {m[2]:+.2f} / {m[6]:+.2f} "
                     f"| {m[3]:.2f} / {m[7]:.2f} |")  # fmt: skip
    lines.append("")
    for frame, fid, vis, (ea, eb) in sorted(rows, key=lambda r: r[3][1][3] - r[3][0][3]):
        if abs(eb[3] - ea[3]) > 1.0:
            lines.append(f"{frame} fruit {fid} ({vis:.0%} seen): front {ea[0]:+.1f}, "
                         f"back {ea[1]:+.1f} -> {eb[1]:+.1f}, centre {ea[3]:.1f} -> {eb[3]:.1f} mm")  # fmt: skip
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("frames", type=Path, help="the frames' folder (each frame's truth.json)")
    p.add_argument("a", type=Path, help="eval_boxes.py's rows of the first run")
    p.add_argument("b", type=Path, help="eval_boxes.py's rows of the second run")
    p.add_argument("--bias", type=float, nargs=2, default=(0.0, 0.0), metavar=("CONST", "LINEAR"),
                   help="a range bias CONST + LINEAR * z (m, m/m) taken off the boxes first (the Azure Kinect "
                   "model's, which renders the trees: 0.002 0.001)")  # fmt: skip
    args = p.parse_args(argv)
    sys.stdout.write(faces(args.frames, args.a, args.b, tuple(args.bias)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
