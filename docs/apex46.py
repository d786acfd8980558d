"""Where the completed box's front lies against the truth's on the apple-tree frames (stop 46, docs/apex46.md).

    python docs/apex46.py dump --frames D [D2 ...] --config SETTINGS --out rows.npz
    python docs/apex46.py table rows.npz [rows2.npz ...]

``dump`` finds and completes every apple of the frames as ``symfruit evaluate --frames D --methods evidence``
does (``detect``'s masks) and stores, per apple matched to the truth by the centre of its seen points' box (the
3 cm gate) or only by its mask's label, its visible share, the truth's front (the nearest depth of the apple), the
box's front, the shared front ``evidence`` handed the candidates (``max(nearest seen depth, apex_depth)``), the
nearest seen depth, ``apex_depth``'s value and the fit sample's points (so that other front estimators can be
measured on the same points, ``table``).

``table`` prints, over the apples matched by centre in every file given, the mean signed front error (box front -
truth's, mm; positive: behind the truth) by visible share (visible >= 90 %, partly 60-90 %, mostly hidden < 60 %),
with the estimators of ``ESTIMATORS`` recomputed on the stored points, and the box's centre error (mean / median)
and back face's error. Run on frames rendered with parts of the sensor model switched off
(``symfruit scenes D --scene apple-tree --n 6 --seed S --sensor-set bias=0,...``), the differences between the
rows split the front's error into its parts.
"""

import argparse
import sys

import numpy as np

import symfruit.methods.evidence as evidence_module
from symfruit.core.front import apex_depth, sphere_front
from symfruit.detect import detect
from symfruit.evaluate.frames import match
from symfruit.io.sources import open_source
from symfruit.settings import resolve_settings

SEEN: dict = {}
_apex = evidence_module.apex_depth
_fuse = evidence_module.fuse_depth
LAST: dict = {}


def _recording_apex(sample, **kwargs):
    z, at = _apex(sample, **kwargs)
    LAST.clear()
    LAST.update(sample=np.array(sample, dtype=np.float64), apex=z)
    return z, at


def _recording_fuse(combined, cands, region, camera, **kwargs):
    box, sd, width = _fuse(combined, cands, region, camera, **kwargs)
    SEEN[tuple(np.round(np.r_[box.min, box.max], 9))] = dict(LAST, width=width, contour=float(combined.contour))
    return box, sd, width


evidence_module.apex_depth = _recording_apex
evidence_module.fuse_depth = _recording_fuse


def dump(folders: list[str], settings) -> dict:
    names = ("frame", "id", "gated", "visible", "truth_front", "truth_back", "box_front", "apex", "nearest", "width",
             "contour", "size", "centre", "back")  # fmt: skip
    rows: dict[str, list] = {k: [] for k in names}
    samples = []
    for f_index, folder in enumerate(folders):
        src = open_source(folder)
        try:
            for index in range(len(src.names())):
                frame = src.read(index)
                truth = dict(frame.truth or [])
                found = detect(frame, method="evidence", settings=settings)
                ok = [d for d in found.detections if d.result is not None]
                gated = {ok[i].id for i, _ in match([d.visible_box for d in ok], list(truth.values()))}
                for d in ok:
                    rec = SEEN.get(tuple(np.round(np.r_[d.result.box.min, d.result.box.max], 9)))
                    if d.id not in truth or rec is None:
                        continue
                    t = truth[d.id]
                    pts = np.asarray(d.extraction.points)
                    box = d.result.box
                    values = (100 * f_index + index, d.id, d.id in gated, frame.visible.get(d.id, np.nan),
                              t.min[2], t.max[2], box.min[2], rec["apex"], pts[:, 2].min(), rec["width"],
                              rec["contour"], float(np.sqrt(t.size[0] * t.size[1])),
                              float(np.linalg.norm(box.centre - t.centre)), box.max[2] - t.max[2])  # fmt: skip
                    for key, value in zip(rows, values, strict=True):
                        rows[key].append(value)
                    samples.append(rec["sample"])
        finally:
            src.close()
    out = {k: np.array(v) for k, v in rows.items()}
    out["offsets"] = np.cumsum([0] + [len(s) for s in samples])
    out["points"] = np.concatenate(samples)
    return out


def _base(p: np.ndarray, width: float) -> float:
    return max(float(p[:, 2].min()), apex_depth(p)[0])


#: name -> front (metres) from the fit sample's points and the prior's width (``fuse_depth``'s, metres): the
#: shared front of the base, the nearest seen point, ``apex_depth`` alone, and the sphere as wide as the prior's
#: width that best fits the points (:func:`symfruit.core.front.sphere_front`) for every apple
ESTIMATORS = {"shared front (base)": _base, "nearest seen": lambda p, w: float(p[:, 2].min()),
              "apex_depth alone": lambda p, w: apex_depth(p)[0],
              "sphere of the prior width": lambda p, w: sphere_front(p, 0.5 * w)[0]}  # fmt: skip

GROUPS = {"visible": (0.9, 2.0), "partly hidden": (0.6, 0.9), "mostly hidden": (0.0, 0.6)}


def table(paths: list[str]) -> None:
    """The table of the module docstring per file, over the apples matched by centre in every file given."""
    data = [dict(np.load(path)) for path in paths]
    keys = [set(zip(d["frame"][d["gated"]].tolist(), d["id"][d["gated"]].tolist(), strict=True)) for d in data]
    common = set.intersection(*keys)
    for path, d in zip(paths, data, strict=True):
        points = [d["points"][a:b] for a, b in zip(d["offsets"][:-1], d["offsets"][1:], strict=True)]
        here = np.array([(f, i) in common for f, i in zip(d["frame"].tolist(), d["id"].tolist(), strict=True)])
        sys.stdout.write(f"\n{path}: {int(d['gated'].sum())} matched by centre of {len(points)}, "
                         f"{int(here.sum())} matched in every file\n")  # fmt: skip
        d["gated"] = here
        heads = ["box front", *ESTIMATORS]
        sys.stdout.write("  group (n): " + " | ".join(heads) + "  (mean signed mm; sd)\n")
        fronts = {name: np.array([f(p, w) for p, w in zip(points, d["width"], strict=True)])
                  for name, f in ESTIMATORS.items()}  # fmt: skip
        for group, (lo, hi) in GROUPS.items():
            sel = d["gated"] & (d["visible"] >= lo) & (d["visible"] < hi)
            cells = []
            for z in (d["box_front"], *fronts.values()):
                e = 1000 * (z[sel] - d["truth_front"][sel])
                cells.append(f"{e.mean():+.2f} ({e.std():.2f})")
            if "centre" in d:
                c = 1000 * d["centre"][sel]
                cells.append(f"centre {c.mean():.2f} / {np.median(c):.2f}, back {1000 * d['back'][sel].mean():+.2f}")
            sys.stdout.write(f"  {group} ({int(sel.sum())}): " + " | ".join(cells) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("dump")
    p.add_argument("--frames", nargs="+", required=True)
    p.add_argument("--config")
    p.add_argument("--out", required=True)
    p = sub.add_parser("table")
    p.add_argument("paths", nargs="+")
    args = parser.parse_args()
    if args.command == "dump":
        np.savez_compressed(args.out, **dump(args.frames, resolve_settings(config=args.config)))
    else:
        table(args.paths)


if __name__ == "__main__":
    main()
