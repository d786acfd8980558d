"""Where `evidence`'s depth side comes from through a real camera model (docs/ablation.md, "Too deep through the
time-of-flight models"): the camera protocol (as `symfruit evaluate --protocol camera --sensor NAME`), every view's
depth side taken apart into the parts of `evidence` that set its back face.

    python docs/depth_side.py [--sensor azure-kinect] [--fruit strawberry,apple,...] [--n 10] [--exact-masks]
                              [--evidence KEY=VALUE ...]

Per view: the depth side's error ``E`` (box depth minus the truth's, mm). The back face is the candidates' back
(the weighted median, ``fit``) and the prior ``front + width`` fused by inverse variances with the prior's share
``p``, then held behind the deepest seen point; so ``E = p (width - D) + (1 - p) (fit depth - D) + clamp``, where
``D`` is the true depth extent; ``width - D`` splits into the width's own error against the truth's lateral
extent (geometric mean of its x and y sides: what the mask and the registration add) and the truth's ``W - D``
(what the ratio 1.0 misses for this kind). ``--exact-masks``: the annotators' masks neither overshoot nor cover an
occluder (``mask_overshoot_px = 0``, ``mask_amodal_share = 0``); ``--evidence KEY=VALUE``: a setting of `evidence`
changed. Rows: all views, by kind, by distance, by the rim coverage (``extras["rim"]``: the share of the silhouette's
rim holding depth, relative to its interior). Columns: mm, except ``p``, ``rim``, ``contour`` and the ``cone``
candidate's weight ``cone w``.
"""

import argparse
import dataclasses
import itertools
import sys

import numpy as np

from symfruit.core.box import Box
from symfruit.detect import detect
from symfruit.evaluate import protocols
from symfruit.evaluate.frames import match
from symfruit.evaluate.protocols import build, specs
from symfruit.extract import extract, register
from symfruit.io.sources import open_source
from symfruit.methods.complete import complete
from symfruit.methods.evidence import _weighted_median
from symfruit.occlusion import fruit_occlusion
from symfruit.settings import Settings
from symfruit.synthetic.sensors import SENSOR_MODELS

PROXIES = "strawberry,apple,citrus,lemon,peach,pear,plum"
COLUMNS = ("E", "E_abs", "p", "prior part", "fit part", "clamp", "width - W", "W - D", "fit depth - D", "rim",
           "contour", "cone w")  # fmt: skip


def views(sensor: str, fruit: str, n: int, settings: Settings):
    for spec in specs("camera", fruit, n=n, sensor=sensor, seed=0):
        inst = build(spec)
        assert inst.mask is not None and inst.depth is not None
        moved, shift = register(inst.mask.astype(np.int32), inst.depth, inst.camera, settings.extract)
        camera = inst.camera.shifted(*shift)
        ex = extract(moved > 0, inst.depth, camera, settings.extract)
        if len(ex.points) < settings.extract.min_points:
            continue
        mask = ex.silhouette if ex.silhouette is not None else moved > 0
        occ = fruit_occlusion(inst.depth, mask, ex.points, camera, settings.occlusion)
        r = complete(ex.points, camera=camera, method="evidence", settings=settings, occlusion=occ)
        yield inst, r


def frame_views(folder: str, settings: Settings):
    """Every matched fruit of annotated frames (as `symfruit evaluate --frames`): truth box, result, visible share."""
    src = open_source(folder)
    try:
        for index, _ in enumerate(src.names()):
            frame = src.read(index)
            truth = frame.truth or []
            found = detect(frame, method="evidence", settings=settings)
            ok = [d for d in found.detections if d.result is not None]
            for i, j in match([d.visible_box for d in ok], [b for _, b in truth]):
                tid, tbox = truth[j]
                yield tbox, ok[i].result, frame.visible.get(tid, float("nan"))
    finally:
        src.close()


def row(t: Box, r, settings: Settings) -> list[float]:
    s = settings.evidence
    x, box = r.extras, r.box
    cands = x["candidates"]
    names = list(cands)
    w = np.array([x["weights"][k] for k in names])
    faces = np.array([np.r_[cands[k]["min"], cands[k]["max"]] for k in names])
    fit = _weighted_median(faces, w)
    front = float(box.min[2])
    depth_true = float(t.size[2])
    width_true = float(np.sqrt(t.size[0] * t.size[1]))
    width = float(x["width"])
    prior_sd = s.depth_ratio_sd * width / max(float(x["contour"]), 0.25)
    p = min(1.0, (float(x["back_sd"]) / prior_sd) ** 2) if s.depth_ratio_sd > 0 else 0.0
    fit_depth = float(fit[5]) - front
    fused = p * s.depth_ratio * width + (1 - p) * fit_depth
    e = float(box.size[2]) - depth_true
    cone = float(x["weights"].get("cone", 0.0))
    return [1000 * v for v in (e, abs(e))] + [p] + [1000 * v for v in (
        p * (s.depth_ratio * width - depth_true), (1 - p) * (fit_depth - depth_true),
        float(box.size[2]) - fused, width - width_true, width_true - depth_true, fit_depth - depth_true)] + [
        float(x["rim"]), float(x["contour"]), cone]  # fmt: skip


def table(title: str, groups: dict[str, list[list[float]]]) -> None:
    head = " | ".join(COLUMNS)
    sys.stdout.write(f"\n{title}\n\n| group | n | {head} |\n|" + "---|" * (len(COLUMNS) + 2) + "\n")
    for name, rows in groups.items():
        if not rows:
            continue
        a = np.mean(rows, axis=0)
        cells = [f"{v:+.1f}" if i not in (1, 2, 9, 10, 11) else f"{v:.2f}" if i >= 2 else f"{v:.1f}"
                 for i, v in enumerate(a)]  # fmt: skip
        sys.stdout.write(f"| {name} | {len(rows)} | " + " | ".join(cells) + " |\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sensor", default="azure-kinect", choices=sorted(SENSOR_MODELS))
    parser.add_argument("--fruit", default=PROXIES, help="kinds, or a scan folder (examples/scans)")
    parser.add_argument("--n", type=int, default=10)
    parser.add_argument("--exact-masks", action="store_true")
    parser.add_argument("--frames", help="annotated frames instead (`symfruit scenes` output): the matched fruit, "
                        "`detect`'s masks (colour-trimmed), rows by the visible share instead of the rim")  # fmt: skip
    parser.add_argument("--evidence", action="append", default=[], metavar="KEY=VALUE",
                        help="an `evidence` setting changed (a number), e.g. rim_error=0; may be repeated")  # fmt: skip
    args = parser.parse_args()
    change = {k: float(v) for k, v in (item.split("=", 1) for item in args.evidence)}
    settings = Settings().replace(evidence=change) if change else Settings()
    base = SENSOR_MODELS[args.sensor]
    if args.exact_masks:
        protocols.SENSOR_MODELS[args.sensor] = dataclasses.replace(base, mask_overshoot_px=0.0, mask_amodal_share=0.0)
    out: list[tuple[str, float, float, list[float]]] = []
    if args.frames:
        for t, r, visible in frame_views(args.frames, settings):
            out.append(("frame fruit", float(t.centre[2]), visible, row(t, r, settings)))
        table("all matched fruit", {"all": [o[3] for o in out]})
        groups = {"visible (>= 90 %)": (0.9, 1.01), "partly hidden (60-90 %)": (0.6, 0.9), "mostly hidden": (0, 0.6)}
        table("by visible share", {k: [o[3] for o in out if lo <= o[2] < hi] for k, (lo, hi) in groups.items()})
        bins = [(0.0, 0.25), (0.25, 0.5), (0.5, 0.75), (0.75, 1.01)]
        table("visible (>= 90 %), by rim coverage", {f"{lo:.2f}-{min(hi, 1):.2f}": [
            o[3] for o in out if o[2] >= 0.9 and lo <= o[3][9] < hi] for lo, hi in bins})  # fmt: skip
        return
    try:
        for fruit in args.fruit.split(","):
            for inst, r in views(args.sensor, fruit, args.n, settings):
                out.append((inst.kind, inst.distance, float(r.extras["rim"]), row(inst.truth_box, r, settings)))
    finally:
        protocols.SENSOR_MODELS[args.sensor] = base
    table("all views", {"all": [o[3] for o in out]})
    kinds = sorted({o[0] for o in out})
    table("by kind", {k: [o[3] for o in out if o[0] == k] for k in kinds})
    edges = np.quantile([o[1] for o in out], [0, 1 / 3, 2 / 3, 1])
    terciles = {f"{lo:.2f}-{hi:.2f}": [o[3] for o in out if lo <= o[1] <= hi and (o[1] > lo or lo == edges[0])]
                for lo, hi in itertools.pairwise(edges)}  # fmt: skip
    table("by distance (terciles, m)", terciles)
    bins = [(0.0, 0.25), (0.25, 0.5), (0.5, 0.75), (0.75, 1.01)]
    table("by rim coverage", {f"{lo:.2f}-{min(hi, 1):.2f}": [o[3] for o in out if lo <= o[2] < hi] for lo, hi in bins})


if __name__ == "__main__":
    main()
