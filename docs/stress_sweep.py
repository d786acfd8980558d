"""Stress sweep of the camera models' artefacts (docs/stress39.md): how `evidence`'s box sides degrade when one
artefact of a camera model is beyond its modelled value, everything else as modelled.

    python docs/stress_sweep.py tree   [--sensor azure-kinect] [--seeds 0 1 2] [--config CW1] [--set NAME=V1,V2 ...]
    python docs/stress_sweep.py camera [--sensor realsense-d435] [--fruit apple,pear] [--n 20] [--set NAME=V1,V2 ...]

``tree``: apple-tree frames (``make_tree_scene``, the annotators' masks given to ``detect``, found apples matched
to the truth by their seen points' box within 3 cm, as ``symfruit evaluate --frames``); per setting, the box's
depth side and larger lateral side against the truth (mean absolute error, mean signed in brackets, mm) by the
apple's visible share, and the 2-D thin-lens estimate's (the mask's larger extent times the median depth over f).
``camera``: the camera protocol on generated fruit (``symfruit evaluate --protocol camera --sensor NAME``), its
mean IoU / centre and the same two sides over all views. Each ``--set`` names a :class:`SensorModel` field and
the values to try (the others stay as modelled; names and bounds: ``symfruit.synthetic.sensors.VARIABLE``, ``bias``
a factor on both bias terms); without ``--set``, the default sweep of each family (``SWEEP``).
A setting's frames are the same scenes (geometry drawn before the sensor), so rows compare like with like.
Development seeds only (0-5): the held-out seeds 100-111 are not for choosing anything.
"""

import argparse
import sys

import numpy as np

from symfruit.core.frame import Frame
from symfruit.detect import detect
from symfruit.evaluate.frames import VISIBILITY_GROUPS, score_frame
from symfruit.evaluate.protocols import specs
from symfruit.evaluate.runner import run
from symfruit.settings import resolve_settings
from symfruit.synthetic.scenes import make_tree_scene
from symfruit.synthetic.sensors import SENSOR_MODELS, SensorModel, varied

#: The default sweep: each artefact at 0, 1, 2 and 3 times its modelled value (or the pixel sizes issue 18 names).
SWEEP = {
    "tof": {
        "rim_invalid_px": [0, 2, 3],
        "flying_share": [0.0, 0.2, 0.3],
        "registration_px": [0.0, 12.0, 18.0],
        "mask_overshoot_px": [0.0, 8.0, 12.0],
        "lateral_px": [0.0, 0.6, 0.9],
        "multipath_bias": [0.0, 0.010, 0.015],
        "bias": [0.0, 2.0, 3.0],  # a factor on bias_const and bias_linear together
        "grazing_dropout": [0.0, 1.0],
        "grazing": [0.4],
    },
    "stereo": {
        "fatten_px": [0, 6, 9],
        "registration_px": [0.0, 4.0, 6.0],
        "mask_overshoot_px": [0.0, 6.0, 9.0],
        "subpixel": [0.16, 0.24],
        "lateral_px": [0.0, 0.6, 0.9],
        "bias": [0.0, 2.0, 3.0],
    },
}


def tree_scores(model: SensorModel, seeds: list[int], settings, distance=(1.2, 2.0)) -> list:
    """Every matched apple's FrameScore (evidence) over the seeds' apple-tree frames through ``model``."""
    scores = []
    for seed in seeds:
        scene = make_tree_scene(seed, sensor=model, distance=distance)
        ripe = [f for f in scene.fruits if f.ripe]
        frame = Frame(f"tree_{seed}", scene.color, scene.depth, scene.camera, masks=scene.masks,
                      truth=[(f.id, f.box) for f in ripe],
                      visible={f.id: float(f.visible) for f in ripe if f.visible is not None})  # fmt: skip
        found = detect(frame, method="raw", settings=settings)
        scores += score_frame(frame, found, ["evidence"], settings)[0]
    return scores


def cell(dz, dl) -> str:
    dz, dl = np.asarray(dz, float), np.asarray(dl, float)
    if not len(dz):
        return "-"
    return f"{np.abs(dz).mean():.1f} ({dz.mean():+.1f}) / {np.abs(dl).mean():.1f} ({dl.mean():+.1f})"


def tree_row(label: str, scores: list) -> str:
    cells, thin = [], []
    for _, lo, hi in VISIBILITY_GROUPS:
        got = [s for s in scores if lo <= s.visible < hi]
        cells.append(cell([s.depth_mm for s in got], [s.lateral_mm for s in got]) + f" (n {len(got)})")
        thin.append(cell([s.thin_depth_mm for s in got], [s.thin_lateral_mm for s in got]))
    iou = np.mean([s.iou for s in scores]) if scores else float("nan")
    centre = np.mean([s.centre_mm for s in scores]) if scores else float("nan")
    head = f"| {label} | {len(scores)} | {iou:.3f} / {centre:.1f} | "
    return head + " | ".join(cells) + " | " + " | ".join(thin) + " |"


def camera_row(label: str, rows: list) -> str:
    ok = [r for r in rows if not r.error]
    dz = [r.depth_mm for r in ok]
    dl = [r.lateral_mm for r in ok]
    iou = np.mean([r.iou for r in ok]) if ok else float("nan")
    centre = np.mean([r.centre_mm for r in ok]) if ok else float("nan")
    return f"| {label} | {len(ok)} ({len(rows) - len(ok)} failed) | {iou:.3f} / {centre:.2f} | {cell(dz, dl)} |"


def camera_rows(sensor: str, changes: tuple, fruits: list[str], n: int, seed: int, settings_for, jobs: int) -> list:
    """The camera protocol through the model ``sensor`` with ``changes`` (as ``evaluate --sensor-set``)."""
    rows = []
    for fruit in fruits:
        these = specs("camera", fruit, n=n, seed=seed, sensor=sensor, sensor_set=changes)
        rows += run(these, ["evidence"], settings_for(fruit), jobs=jobs, progress=False)
    return rows


def parse_sets(items: list[str] | None, family: str) -> dict[str, list[float]]:
    if not items:
        return SWEEP[family]
    out = {}
    for item in items:
        name, _, values = item.partition("=")
        out[name.strip()] = [float(v) for v in values.split(",") if v.strip()]
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("what", choices=("tree", "camera"))
    parser.add_argument("--sensor", default=None, help="a camera model (default azure-kinect for tree, "
                        "realsense-d435 for camera)")  # fmt: skip
    parser.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2], help="tree: frame seeds (0-5)")
    parser.add_argument("--distance", nargs=2, type=float, default=(1.2, 2.0), help="tree: canopy front, metres")
    parser.add_argument("--config", help="settings file, as `symfruit evaluate --config` (tree: e.g. CW1)")
    parser.add_argument("--fruit", default="apple,pear", help="camera: fruit kinds or a scan folder, comma-separated")
    parser.add_argument("--n", type=int, default=20, help="camera: views per kind")
    parser.add_argument("--seed", type=int, default=0, help="camera: seed")
    parser.add_argument("--no-profile", action="store_true", help="camera: no fruit profile (the tables' setting)")
    parser.add_argument("--jobs", type=int, default=1, help="camera: worker processes (default 1)")
    parser.add_argument("--set", nargs="*", dest="sets", help="NAME=V1,V2,...: a model field and values to try")
    parser.add_argument("--no-base", action="store_true", help="leave out the model as it is")
    args = parser.parse_args()
    sensor = args.sensor or ("azure-kinect" if args.what == "tree" else "realsense-d435")
    base = SENSOR_MODELS[sensor]
    if any(s > 5 for s in args.seeds):
        parser.error("development seeds 0-5 only (the held-out frames are seeds 100-111)")
    runs = [] if args.no_base else [("as modelled", ())]
    for name, values in parse_sets(args.sets, base.family).items():
        for value in values:
            runs.append((f"{name} = {value:g}", ((name, value),)))
    out = sys.stdout
    if args.what == "tree":
        settings = resolve_settings(config=args.config)
        groups = [g for g, _, _ in VISIBILITY_GROUPS]
        out.write(f"apple-tree frames, seeds {args.seeds}, {sensor}, distance {args.distance}; cells: depth side / "
                  f"larger lateral side, mean abs (signed) mm\n\n")  # fmt: skip
        out.write("| setting | matched | IoU / centre (mm) | " + " | ".join(f"evidence, {g}" for g in groups) + " | "
                  + " | ".join(f"thin-lens, {g}" for g in groups) + " |\n|" + "---|" * 9 + "\n")  # fmt: skip
        out.flush()
        for label, changes in runs:
            model = varied(base, changes)
            out.write(tree_row(label, tree_scores(model, args.seeds, settings, tuple(args.distance))) + "\n")
            out.flush()
    else:
        from symfruit.profiles import available_profiles

        def settings_for(fruit: str):
            use = None if args.no_profile or fruit not in available_profiles() else fruit
            return resolve_settings(fruit=use, config=args.config)

        fruits = args.fruit.split(",")
        out.write(f"camera protocol, {sensor}, {fruits}, n {args.n}, seed {args.seed}; cells: IoU / centre (mm); "
                  f"depth side / larger lateral side, mean abs (signed) mm\n\n")  # fmt: skip
        out.write("| setting | views | IoU / centre | depth / lateral (mm) |\n|---|---|---|---|\n")
        out.flush()
        for label, changes in runs:
            rows = camera_rows(sensor, changes, fruits, args.n, args.seed, settings_for, args.jobs)
            out.write(camera_row(label, rows) + "\n")
            out.flush()


if __name__ == "__main__":
    main()
