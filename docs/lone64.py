"""What ``evidence.lost_rim`` costs the lone generated fruit through the camera models (issue 18, stop 64,
docs/lone64.md): the camera protocol's views (as ``symfruit evaluate --protocol camera --sensor NAME --fruit
PROXIES --n N``), each completed by `evidence` under several settings, with what :func:`fuse_depth` read.

    python docs/lone64.py run OUT.jsonl [--sensors azure-kinect,...] [--fruit KINDS] [--n 10]
                          [--variant NAME=JSON ...]
    python docs/lone64.py summary OUT.jsonl [OUT.jsonl ...] [--by sensor|kind|both]

``--variant``: a name and an ``evidence`` settings object, e.g. ``pull='{"lost_rim": "pull"}'``, ``default='{}'``
(default: ``bound``, ``pull`` and ``least``). ``--fruit examples/scans --n 20``: the real scans' rows. Per view and
variant: centre error and IoU (as the evaluation scores them), the box's depth side less the truth's (``dz``), and the
fusion's terms: the shapes' back and the prior's back less the true back (``fit``, ``prior``, mm, the front taken as the
box's), the rim coverage, the outline's elongation (major / minor width), whether the bound applied and, under
``lost_rim: cap``, how far the cap said prolate (``prolate``; docs/tilt64.md). ``--grow PX``: every mask grown by a
disc of PX pixels first (an annotator's overshoot).
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

import numpy as np
from scipy import ndimage

import symfruit.methods.evidence as ev
from symfruit.evaluate.metrics import score_completion
from symfruit.evaluate.protocols import build, specs
from symfruit.extract import extract, register
from symfruit.methods.complete import complete
from symfruit.occlusion import fruit_occlusion
from symfruit.settings import Settings

PROXIES = "strawberry,apple,citrus,lemon,peach,pear,plum"
SENSORS = "azure-kinect,realsense-l515,realsense-d435,realsense-d405"
_seen: dict[str, float] = {}
_original = ev.fuse_depth


def _recording(combined: Any, cands: Any, region: Any, camera: Any, **kw: Any) -> Any:
    box, back_sd, width = _original(combined, cands, region, camera, **kw)
    s, across = kw["s"], kw.get("across")
    front = float(combined.box.min[2])
    _seen.update(
        front=front, fit_back=float(combined.box.max[2]), prior_back=front + s.depth_ratio * width, width=width,
        rim=float(kw.get("rim", 1.0)), back=float(box.max[2]),
        elong=float(across.major / max(across.minor, 1e-12)) if across is not None else float("nan"),
        prolate=kw.get("prolate"),
    )  # fmt: skip
    return box, back_sd, width


def run(args: argparse.Namespace) -> None:
    variants = dict(v.split("=", 1) for v in args.variant) or {
        name: f'{{"lost_rim": "{name}"}}' for name in ("bound", "pull", "least")
    }
    settings = {k: Settings().replace(evidence=json.loads(v)) if v != "{}" else Settings() for k, v in variants.items()}
    ev.fuse_depth = _recording
    base = Settings()
    out = open(args.out, "w")
    out.write(json.dumps({"variants": variants}) + "\n")
    for sensor in args.sensors.split(","):
        for fruit in args.fruit.split(","):
            for spec in specs("camera", fruit, n=args.n, sensor=sensor, seed=args.seed):
                inst = build(spec)
                assert inst.mask is not None and inst.depth is not None
                moved, shift = register(inst.mask.astype(np.int32), inst.depth, inst.camera, base.extract)
                camera = inst.camera.shifted(*shift)
                ex = extract(moved > 0, inst.depth, camera, base.extract)
                if len(ex.points) < base.extract.min_points:
                    continue
                mask = ex.silhouette if ex.silhouette is not None else moved > 0
                if args.grow > 0:  # an annotator's mask, overshooting the fruit by a disc of ``grow`` pixels
                    d = np.arange(-args.grow, args.grow + 1)
                    mask = ndimage.binary_dilation(mask, structure=d[:, None] ** 2 + d[None, :] ** 2 <= args.grow**2)
                occ = fruit_occlusion(inst.depth, mask, ex.points, camera, base.occlusion, eroded=base.extract.erode_px)
                t = inst.truth_box
                row: dict[str, Any] = {"sensor": sensor, "kind": inst.kind, "index": spec.index,
                                       "truth": [float(v) for v in t.size]}  # fmt: skip
                for name, st in settings.items():
                    r = complete(ex.points, camera=camera, method="evidence", settings=st, occlusion=occ)
                    sc = score_completion(r.box, r.points, t, inst.truth_surface)
                    true_back, true_front = float(t.max[2]), float(t.min[2])
                    row[name] = {
                        "centre": sc.centre_mm, "iou": sc.iou, "size": [float(v) for v in r.box.size],
                        "dz": 1000 * float(r.box.size[2] - t.size[2]), "back": 1000 * (_seen["back"] - true_back),
                        "fit": 1000 * (_seen["fit_back"] - true_back),
                        "prior": 1000 * (_seen["prior_back"] - true_back),
                        "front": 1000 * (_seen["front"] - true_front), "rim": _seen["rim"], "elong": _seen["elong"],
                        "bounded": _seen["fit_back"] < _seen["prior_back"] and _seen["rim"] < 1.0,
                        "prolate": _seen["prolate"],
                    }  # fmt: skip
                out.write(json.dumps(row) + "\n")
                out.flush()
    out.close()


def summary(args: argparse.Namespace) -> None:
    rows: list[dict[str, Any]] = []
    names: list[str] = []
    for path in args.out:
        with open(path) as f:
            lines = [json.loads(x) for x in f if x.strip()]
        names = names or list(lines[0]["variants"])
        rows += lines[1:]
    keys = {
        "sensor": lambda r: r["sensor"],
        "kind": lambda r: r["kind"],
        "both": lambda r: f"{r['sensor']} {r['kind']}",
    }
    key = keys[args.by]
    groups: dict[str, list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault(key(r), []).append(r)
    cols = ("iou", "centre", "dz", "front", "back", "fit", "prior", "rim", "elong")
    head = " | ".join(f"{n} {c}" for n in names for c in ("iou", "centre", "dz"))
    sys.stdout.write(f"| group | n | {head} | front | fit | prior | rim | elong | bounded |\n")
    for g, rs in groups.items():
        cells = [f"{np.mean([r[n][c] for r in rs]):.3f}" if c == "iou" else f"{np.mean([r[n][c] for r in rs]):+.2f}"
                 for n in names for c in ("iou", "centre", "dz")]  # fmt: skip
        n0 = names[0]
        extra = [f"{np.mean([r[n0][c] for r in rs]):+.1f}" for c in cols[3:4] + cols[5:7]]
        extra += [f"{np.mean([r[n0][c] for r in rs]):.2f}" for c in cols[7:]]
        extra.append(str(sum(r[n0]["bounded"] for r in rs)))
        sys.stdout.write(f"| {g} | {len(rs)} | " + " | ".join(cells + extra) + " |\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="complete every view under each variant; write OUT.jsonl (a line a view)")
    r.add_argument("out")
    r.add_argument("--sensors", default=SENSORS)
    r.add_argument("--fruit", default=PROXIES)
    r.add_argument("--n", type=int, default=10)
    r.add_argument("--seed", type=int, default=0)
    r.add_argument("--variant", action="append", default=[], metavar="NAME=JSON")
    r.add_argument("--grow", type=int, default=0, help="grow each mask by a disc of this many pixels (overshoot)")
    s = sub.add_parser("summary", help="mean figures per group and variant")
    s.add_argument("out", nargs="+")
    s.add_argument("--by", choices=("sensor", "kind", "both"), default="sensor")
    args = parser.parse_args(argv)
    (run if args.cmd == "run" else summary)(args)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
