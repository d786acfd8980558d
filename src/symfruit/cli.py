"""Command-line interface: ``symfruit complete | detect | report | segment | evaluate | bench | demo | scenes |
settings | methods``.

Thin by design: parse, import lazily, call the library, print. Errors a user can cause print one
line (``symfruit: error: ...``) and exit with status 2; ``--debug`` shows the traceback instead.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import re
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

#: The real camera models of ``--sensor`` (the keys of :data:`symfruit.synthetic.sensors.SENSOR_MODELS`, named here so
#: that building the parser imports nothing heavy; a test checks they agree).
REAL_SENSORS = ("azure-kinect", "realsense-l515", "realsense-d435", "realsense-d405")

if TYPE_CHECKING:
    import numpy as np

__all__ = ["main"]


#: The methods `evaluate` compares unless --methods says otherwise.
_EVALUATED = "raw,sphere,ellipsoid,superellipsoid,paper,fused,evidence"


def _path(text: str) -> Path:
    """A path argument; an empty one (an unset shell variable: ``--output "$OUT"``) is refused, not read as the
    working folder."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path (an unset shell variable?)")
    return Path(text)


#: A plain number as an option's list gives it: ASCII digits (float() also reads '١٨' and 1_8 as 18).
_NUMBER = r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?"


def _whole(text: str) -> int:
    """A whole-number option: ASCII digits, a sign before them (int() alone also reads '٣', '３' and '1_000' as
    their values). Stop 56 (robust56)."""
    if not re.fullmatch(r"\s*[+-]?[0-9]+\s*", text):
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number (ASCII digits 0-9)")
    return int(text)


def _real(text: str) -> float:
    """A number option: float()'s own words (nan and inf are refused by each option's bounds), but of ASCII
    alone and no '_' (float() also reads '٣.٥' and '1_0'). Stop 56 (robust56)."""
    try:
        if not text.isascii() or "_" in text:
            raise ValueError
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number (ASCII digits 0-9, e.g. 0.5 or 1e-3)") from None


def _entries(option: str, text: str, example: str, *, numbers: bool = False) -> list[str]:
    """The comma-separated entries of ``option``, stripped; an empty entry beside others (``a,,b``, a trailing
    comma) and, with ``numbers``, an entry that is no plain number are refused by name (they were dropped or
    misread). No entry at all (``''``, ``,,``) is ``[]``: the caller says what that leaves."""
    import re

    from .errors import InputError

    entries = [x.strip() for x in text.split(",")]
    if not any(entries):
        return []
    for entry in entries:
        if not entry or (numbers and not re.fullmatch(_NUMBER, entry, flags=re.ASCII)):
            what = "an empty entry" if not entry else f"{entry!r} is no number"
            raise InputError(f"{option} {text!r}: {what}; expected {example}")
    return entries


def _add_complete(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("complete", help="complete one fruit's partial cloud and box it")
    p.add_argument("cloud", type=_path, help="PLY, PCD, XYZ/TXT/CSV or NPY file of the visible points")
    p.add_argument(
        "--camera",
        type=_path,
        help="intrinsics (JSON/YAML: plain, RealSense, Open3D, ROS); default: Intel D435 colour 640x480",
    )
    p.add_argument("--method", default=None, help="completion method (see `symfruit methods`; default evidence)")
    p.add_argument("--fruit", help="fruit profile: strawberry, apple, citrus, tomato, or a profile file (.yaml)")
    p.add_argument("--config", type=_path, help="settings file (YAML/JSON; see `symfruit settings`), over the profile")
    p.add_argument("--units", choices=("m", "mm"), default="m", help="units of the input cloud")
    p.add_argument(
        "--output",
        type=_path,
        help="write the completed cloud to OUT.ply and the result with the effective settings to OUT.json",
    )
    p.add_argument("--json", action="store_true", help="print the result as JSON")


def _add_bench(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("bench", help="time `complete` on a fixed partial strawberry (the project benchmark)")
    p.add_argument("--repeat", type=_whole, default=None, help="timed runs per case (default 200)")
    p.add_argument("--points", type=_whole, nargs="+", default=None, help="cloud sizes (default 600 3000)")
    p.add_argument("--json", action="store_true", help="print the rows as JSON")
    p.add_argument("--frame", action="store_true", help="time a whole 640x480 frame with 8 fruit instead")
    p.add_argument("--sensor", choices=REAL_SENSORS, default=None,
                   help="with --frame: the frame through a real camera model, at its resolution")  # fmt: skip
    p.add_argument("--recording", type=_whole, metavar="N",
                   help="instead: peak memory and time of `detect` over a generated N-frame recording")  # fmt: skip
    p.add_argument("--method", default=None,
                   help="with --frame: only this method (default paper, fused and evidence); with --recording: the "
                   "completion method (default evidence)")  # fmt: skip
    p.add_argument("--profile", action="store_true",
                   help="with --frame: print a cProfile of the frame instead (5 runs of --method)")  # fmt: skip
    p.add_argument("--stages", action="store_true",
                   help="with --frame: median and least wall time of each stage of `detect` and the thread's CPU "
                   "time per frame (--repeat runs of each method)")  # fmt: skip
    p.add_argument("--workers", type=_whole, metavar="W",
                   help="with --recording: on a local Dask cluster of W processes (symfruit[cluster])")  # fmt: skip
    p.add_argument("--fruit-processes", type=_whole, default=None, metavar="N",
                   help="with --frame or --recording: each frame's fruit shared with N worker processes, started "
                   "and warmed up before the timing with --frame (0-16, default 0; as symfruit detect "
                   "--fruit-processes)")  # fmt: skip
    p.add_argument("--stream", type=_whole, default=None, metavar="F",
                   help="with --frame: frames per second over F frames one after another, each alone and in a "
                   "stream (the next frame segmented while the fruit workers end the last), alternated --repeat "
                   "times (default 3)")  # fmt: skip
    p.add_argument(
        "--segment",
        action="store_true",
        help="instead: time the colour segmenter per image at --size (photos from --images, else synthetic)",
    )
    p.add_argument("--images", type=_path, help="with --segment: a folder of photographs (resized to --size)")
    p.add_argument("--size", default=None, metavar="WxH",
                   help="with --segment: the image size timed (default 640x480; e.g. 1920x1080)")  # fmt: skip
    p.add_argument("--scene", choices=("apple-tree",), default=None,
                   help="with --segment: rendered apple-tree frames with depth (1920x1080, apple profile) instead "
                   "of photos")  # fmt: skip


def _add_evaluate(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("evaluate", help="run an evaluation protocol and write tables, CSV, JSON and plots")
    p.add_argument(
        "--protocol",
        choices=("paper", "camera", "masks"),
        default=None,
        help="paper: Ge et al. Algorithm 2 (19 poses about x); camera: rendered D435-like views; masks: mask "
        "quality of a segmenter on photographs (--images, --truth) or on rendered scenes (--n, --seed)",
    )
    p.add_argument(
        "--fruit",
        default=None,
        help="a generated kind (strawberry, apple, citrus, tomato, pear, lemon, peach, plum, banana, lopsided), "
        "all, or a folder of complete scans (one table row per scan); comma-separated; with --frames: the one "
        "fruit profile of the frames (default strawberry)",
    )
    p.add_argument("--methods", help="comma-separated methods (default: " + _EVALUATED + ")")
    p.add_argument(
        "--n", type=_whole, help="fruits (paper; default 10) or views per occlusion level (camera; default 100)"
    )
    p.add_argument("--seed", type=_whole, default=None, help="first seed (default 0)")
    p.add_argument("--occlusion", help="camera protocol: occluder levels, e.g. 0,0.25,0.5 (default 0)")
    p.add_argument("--sensor", choices=("d435", "heldback", *REAL_SENSORS),
                   help="camera protocol: d435 (noise, edge dropout, 0.25-0.6 m), heldback (issue 11's measurement: "
                   "0.01 z^2 noise, no dropout, 0.3-0.5 m), or a real camera model (symfruit.synthetic.sensors: rim "
                   "invalidation or edge fattening, flying pixels, registration, masks that overshoot, clutter; "
                   "1920x1080 or 1280x720, 0.25-2 m; default d435)")  # fmt: skip
    p.add_argument("--sensor-set", metavar="NAME=VALUE,...",
                   help="camera protocol with a real camera model: change its artefacts, e.g. rim_invalid_px=3,"
                   "flying_share=0.3 (a camera not modelled, or how far the model's values matter; names and bounds: "
                   "symfruit.synthetic.sensors.VARIABLE; docs/stress39.md)")  # fmt: skip
    p.add_argument("--pose", choices=("hanging", "upright", "uniform"),
                   help="pose distribution: hanging (stem up; scans as in their file), upright (scans stood up "
                   "first), uniform (any orientation; camera protocol); default hanging")  # fmt: skip
    p.add_argument("--views", type=_whole,
                   help="camera protocol, generated kinds: views of each fruit (default 1: every view a new fruit; "
                   "more rank confidence among one fruit's views, as the scans' views are)")  # fmt: skip
    p.add_argument("--output", type=_path, default=Path("results"), help="results root (default results/)")
    p.add_argument("--quick", action="store_true", help="paper and camera protocols: a handful of instances, well "
                   "under a minute")  # fmt: skip
    p.add_argument("--jobs", type=_whole, help="paper and camera protocols: worker processes (default: all CPUs)")
    p.add_argument("--config", type=_path, help="settings file for the methods")
    p.add_argument(
        "--no-profile",
        action="store_true",
        help="every method's defaults for every fruit (as complete() without settings), no fruit profile",
    )
    p.add_argument("--frames", type=_path, help="instead of a protocol: Table 3 on a folder of frames with truth.json")
    p.add_argument("--match", choices=("centre", "id"), default=None,
                   help="--frames: match found fruit to the truth by their seen points' box centre within 3 cm "
                   "(default, Table 3's protocol) or by mask label = truth id (the frames' own masks drawn for the "
                   "truth, as those of `symfruit scenes --sensor`/`--scene apple-tree`: every completed fruit "
                   "scored)")  # fmt: skip
    p.add_argument("--spheres", type=_path,
                   help="instead of a protocol: real frames of spheres without truth (one mask per sphere, the same "
                   "ids in every frame): how far each box is from a cube and how far the frames disagree, e.g. "
                   "examples/real-frames")  # fmt: skip
    p.add_argument("--masks", default=None,
                   help="with --frames: mask source (see `symfruit detect`; default auto); with --spheres: mask files "
                   "only (default auto: each frame's own; a frame without one is skipped); with --protocol masks: "
                   "color (default), maskrcnn:CHECKPOINT or onnx:MODEL")  # fmt: skip
    p.add_argument("--images", type=_path, help="masks protocol: folder of photographs")
    p.add_argument("--truth", type=_path, help="masks protocol: COCO JSON of the photographs' instance masks")
    p.add_argument("--category", type=_whole, default=None,
                   help="masks protocol: COCO category id of the fruit (default 1; -1: every annotation)")  # fmt: skip
    p.add_argument("--no-depth", action="store_true", help="masks protocol on rendered scenes: colour alone")
    p.add_argument("--scene", choices=("strawberry", "apple-tree"), default=None,
                   help="masks protocol on rendered scenes: table-top strawberries (default) or an apple tree's "
                   "canopy at 1.2-2 m through the Azure Kinect model (1920x1080; use with --fruit apple)")  # fmt: skip


def _add_detect(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("detect", help="locate the fruit of RGB-D frames: frame folders, folders of frames or bags")
    p.add_argument("inputs", nargs="+", type=_path, metavar="INPUT",
                   help="a recording: frame folder (color.png, depth.png, camera.json), folder of them, or bag; "
                   "several: each recording's frames go into OUT/<recording>/")  # fmt: skip
    p.add_argument(
        "--masks",
        default="auto",
        help="auto (the frame's masks file, else colour), color, a label PNG or COCO JSON, maskrcnn:CHECKPOINT.pth "
        "or onnx:MODEL.onnx",
    )
    p.add_argument("--method", default=None, help="completion method (see `symfruit methods`; default evidence)")
    p.add_argument("--output", type=_path, required=True,
                   help="output folder (one sub-folder per frame; with several inputs one per recording)")  # fmt: skip
    p.add_argument("--fruit", default="strawberry", help="fruit profile (default strawberry) or a profile file")
    p.add_argument("--config", type=_path, help="settings file (YAML/JSON), over the profile")
    p.add_argument("--resume", action="store_true",
                   help="skip frames whose detections.json is a whole record (one that cannot be read back, "
                   "truncated by a copy, is run again)")  # fmt: skip
    p.add_argument("--fruit-processes", type=_whole, default=None, metavar="N",
                   help="share each frame's fruit with N worker processes kept for the run (0-16, default 0; 1 on "
                   "two cores: about a fifth off a frame's detection once they are warm, docs/proc53.md); not with "
                   "--scheduler or --workers")  # fmt: skip
    _add_ros2_bag_options(p)
    _add_cluster_options(p)
    p = sub.add_parser("segment", help="instance masks of the ripe fruit in images (colour alone, or with depth)")
    p.add_argument("inputs", nargs="+", type=_path, help="images or folders of images")
    p.add_argument("--output", type=_path, required=True, help="folder for <stem>.png (16-bit labels) and "
                   "<stem>_overlay.png")  # fmt: skip
    p.add_argument("--masks", default="color", help="color (default), maskrcnn:CHECKPOINT.pth, onnx:MODEL.onnx, a COCO "
                   ".json or a folder of label PNGs")  # fmt: skip
    p.add_argument("--depth", type=_path, help="a depth image, or a folder of <stem>.png (16-bit) / <stem>.npy (m)")
    p.add_argument("--camera", type=_path, help="with --depth: intrinsics file (needed)")
    p.add_argument("--depth-scale", type=_real, default=None, help="with --depth: metres per unit of 16-bit depth "
                   "(default: the --camera file's depth_scale or depth_units, else 0.001)")  # fmt: skip
    p.add_argument("--fruit", default="strawberry", help="fruit profile (default strawberry) or a profile file")
    p.add_argument("--config", type=_path, help="settings file (YAML/JSON), over the profile")
    p = sub.add_parser("demo", help="detect the fruit of the shipped example frame and compare with its truth")
    p.add_argument("--output", type=_path, default=Path("out/demo"), help="output folder (default out/demo)")
    p.add_argument("--method", default=None, help="completion method (default evidence)")
    p.add_argument("--fruit", default="strawberry", help="fruit profile (default strawberry) or a profile file")
    p.add_argument("--config", type=_path, help="settings file (YAML/JSON), over the profile")


def _add_ros2_bag_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--ros2-bag", type=_path, metavar="BAG",
                   help="also write the detections into this new ROS 2 bag folder (vision_msgs/msg/Detection3DArray "
                   "on /symfruit/detections, stamped like the input frames)")  # fmt: skip
    p.add_argument("--ros2-storage", choices=("mcap", "sqlite3"), default=None,
                   help="storage of --ros2-bag (default mcap)")  # fmt: skip


def _add_cluster_options(p: argparse.ArgumentParser) -> None:
    where = p.add_mutually_exclusive_group()
    where.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run the frames on this Dask cluster (tcp://HOST:PORT; "
        "pip install 'symfruit[cluster]' here and on the workers, which must see the same paths)",
    )
    where.add_argument("--workers", type=_whole, metavar="N", help="run the frames on a local Dask cluster of N worker "
                       "processes (127.0.0.1)")  # fmt: skip
    p.add_argument("--chunk", type=_whole, default=None, metavar="N",
                   help="with --scheduler or --workers: frames per task (default 4)")  # fmt: skip
    p.add_argument("--no-worker-timeout", type=_real, default=None, metavar="S",
                   help="with --scheduler or --workers: seconds to wait while the cluster has no worker (for the "
                   "first one, and at any time during the run, after which the frames not done are recorded "
                   "unprocessed and the run stops); 1 to 86400, default 60 with --scheduler, 300 with --workers "
                   "(its workers restart themselves)")  # fmt: skip
    p.add_argument("--silent-worker-timeout", type=_real, default=None, metavar="S",
                   help="with --scheduler or --workers: a worker the scheduler has not heard from for S seconds "
                   "counts as none (as a paused one does); 10 to 86400, default 60")  # fmt: skip


def _add_report(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("report", help="report.md and plots of what a detect run found (fruit counts, sizes)")
    p.add_argument("run", type=_path, help="the output folder of `symfruit detect` (with detections.parquet)")
    p.add_argument("--output", type=_path, help="folder for report.md and the plots (default RUN/report)")
    p.add_argument("--classes", default="18,25", help="size class limits, diameters in mm (default 18,25: the EU "
                   "strawberry classes)")  # fmt: skip


def _add_ros(sub: argparse._SubParsersAction) -> None:
    # Everything after `ros` belongs to the node (name:=value, __name:=, --help): no option prefix of ours.
    p = sub.add_parser("ros", help="run the ROS 1 node (see `symfruit ros --help`)", add_help=False, prefix_chars="+")
    p.add_argument("ros_args", nargs=argparse.REMAINDER, help="ROS remappings and _param:=value")
    p = sub.add_parser("ros2", help="run the ROS 2 node (see `symfruit ros2 --help`)", add_help=False, prefix_chars="+")
    p.add_argument("ros_args", nargs=argparse.REMAINDER, help="--ros-args -p name:=value -r from:=to")


def _parser() -> argparse.ArgumentParser:
    from . import __version__

    parser = argparse.ArgumentParser(
        prog="symfruit",
        description="Locate fruit from one RGB-D view by completing its hidden side through mirror symmetry.",
    )
    parser.add_argument("--version", action="version", version=f"symfruit {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    _add_complete(sub)
    _add_bench(sub)
    _add_evaluate(sub)
    _add_detect(sub)
    _add_report(sub)
    _add_ros(sub)
    p = sub.add_parser("scenes", help="render synthetic annotated RGB-D frames of hanging strawberries or of an "
                       "apple tree (with truth)")  # fmt: skip
    p.add_argument("output", type=_path, help="folder to write scene_00000, scene_00001, ... into")
    p.add_argument("--n", type=_whole, default=12, help="frames (default 12)")
    p.add_argument("--seed", type=_whole, default=0, help="seed of the first frame; frame k uses seed + k (default 0)")
    p.add_argument("--scene", choices=("strawberry", "apple-tree"), default=None,
                   help="hanging strawberries (default) or an apple tree's canopy at 1.2-2 m through a real camera "
                   "model (the Azure Kinect unless --sensor), with the annotators' masks.png")  # fmt: skip
    p.add_argument("--ripe", type=_whole, default=None,
                   help="ripe fruit per frame (default 6 strawberries, 30 apples)")  # fmt: skip
    p.add_argument("--unripe", type=_whole, default=None,
                   help="unripe (white or green) fruit per frame (default 2 strawberries, 4 apples)")  # fmt: skip
    p.add_argument("--sensor", choices=REAL_SENSORS, default=None,
                   help="through a real camera model (symfruit.synthetic.sensors) at its resolution, fruit at "
                   "its working distances within 0.25-2 m, with the annotators' masks.png (default: the 640x480 "
                   "D435-like frames; apple trees: the Azure Kinect)")  # fmt: skip
    p.add_argument("--sensor-set", metavar="NAME=VALUE,...",
                   help="with a real camera model (--sensor or --scene apple-tree): change its artefacts, e.g. "
                   "rim_invalid_px=3,flying_share=0.3 (names and bounds: "
                   "symfruit.synthetic.sensors.VARIABLE)")  # fmt: skip
    p.add_argument("--plain-colour", action="store_true",
                   help="apple trees: the colour image without the colour camera's effects (exposure, "
                   "white-balance cast, leaf shadows, highlights, noise, softness, JPEG; "
                   "symfruit.synthetic.render.Photometric): the frames of stops 30-44, for their tables; depth, "
                   "masks and truth are the same either way")  # fmt: skip
    p = sub.add_parser("settings", help="print the effective settings as YAML (defaults, --fruit, then --config)")
    p.add_argument("--fruit", help="fruit profile: strawberry, apple, citrus, tomato, or a profile file (.yaml)")
    p.add_argument("--config", type=_path, help="settings file (YAML/JSON), over the profile")
    sub.add_parser("methods", help="list the completion methods")
    return parser


def _fmt(values: Sequence[float] | np.ndarray, scale: float = 1000.0) -> str:
    return "(" + ", ".join(f"{v * scale:.1f}" for v in values) + ")"


def _method(args: argparse.Namespace) -> str:
    """``--method``, or the default method when it is not given (an empty ``--method ''`` is given: refused by the
    method registry as an unknown method, never read as the default)."""
    from .methods import DEFAULT_METHOD

    return str(DEFAULT_METHOD if args.method is None else args.method)


def _settings_for(args: argparse.Namespace, fruit: str | None = None):
    """Defaults, then the fruit profile (``--fruit``), then ``--config``: :func:`symfruit.resolve_settings`."""
    from .settings import resolve_settings

    return resolve_settings(fruit=fruit if fruit is not None else getattr(args, "fruit", None),
                            config=getattr(args, "config", None))  # fmt: skip


def _complete(args: argparse.Namespace) -> int:
    from .core.camera import DEFAULT_CAMERA
    from .errors import InputError
    from .io import load_camera, read_cloud
    from .methods import get
    from .methods.complete import complete
    from .writers import check_result_paths, write_result

    get(_method(args))  # an unknown method refused before the work, not blamed on the cloud file
    settings = _settings_for(args)
    camera = load_camera(args.camera) if args.camera else DEFAULT_CAMERA
    profile = Path(args.fruit) if args.fruit and Path(args.fruit).is_file() else None  # a profile file
    inputs = [args.cloud, args.camera, args.config, profile]
    if args.output is not None:
        _check_output_file(args.output, ".ply")
        check_result_paths(args.output, inputs)  # before the work: never over the cloud, intrinsics or settings
    points = read_cloud(args.cloud)
    if args.units == "mm":
        points = points / 1000.0
    try:
        result = complete(points, camera=camera, method=_method(args), settings=settings)
    except InputError as exc:  # the cloud's own fault (too few points, flat, behind the camera): name the file
        raise InputError(f"{args.cloud}: {exc}") from None
    written = None
    if args.output is not None:
        meta = {"input": str(args.cloud), "units": args.units, "camera": camera.to_dict()}
        written = write_result(args.output, result, meta=meta, inputs=inputs)
    if args.json:
        print(json.dumps(result.to_dict(), indent=2))
        return 0
    box = result.box
    print(f"{'method':<10} {result.method}")
    print(f"{'centre':<10} {_fmt(box.centre)} mm")
    print(f"{'size':<10} {_fmt(box.size)} mm")
    print(f"{'box min':<10} {_fmt(box.min)} mm")
    print(f"{'box max':<10} {_fmt(box.max)} mm")
    if result.plane is not None:
        print(f"{'plane':<10} point {_fmt(result.plane.point)} mm, normal {_fmt(result.plane.normal, 1.0)}")
        if len(result.scores):
            print(f"{'score':<10} {result.score:.3f} (best of {len(result.scores)} planes)")
    if result.confidence is not None:
        print(f"{'confidence':<10} {result.confidence:.2f} ({'reliable' if result.reliable else 'not reliable'})")
    dropped = f", {result.n_dropped} non-finite dropped" if result.n_dropped else ""
    print(f"{'points':<10} {len(result.visible)} visible -> {len(result.points)} completed{dropped}")
    print(f"{'time':<10} {result.seconds * 1000:.2f} ms")
    if written is not None:
        print(f"{'written':<10} {written[0]} and {written[1]}")
    return 0


def _check_output_file(path: Path, suffix: str) -> None:
    from .errors import FileFormatError

    if path.suffix.lower() != suffix:
        raise FileFormatError(f"{path}: --output must end in {suffix}")
    if path.is_dir():
        raise FileFormatError(f"{path}: --output is a folder; give a file name ending in {suffix}")


def _check_bench_options(args: argparse.Namespace) -> None:
    """Refuse options the chosen kind of bench would ignore, and two kinds at once (one took over, unsaid)."""
    from .errors import InputError

    kinds = [k for k, on in (("--segment", args.segment), ("--recording", args.recording is not None),
                             ("--frame", args.frame)) if on]  # fmt: skip
    if len(kinds) > 1:
        raise InputError(f"bench: {' and '.join(kinds)} are two kinds of bench; give one")
    kind = kinds[0] if kinds else None
    rules = (  # option, given, the kinds of bench it is for (None: the cloud bench)
        ("--points", args.points is not None, (None,)),
        ("--repeat", args.repeat is not None, (None, "--frame")),
        ("--sensor", args.sensor is not None, ("--frame",)),
        ("--method", args.method is not None, ("--frame", "--recording")),
        ("--profile", args.profile, ("--frame",)),
        ("--stages", args.stages, ("--frame",)),
        ("--workers", args.workers is not None, ("--recording",)),
        ("--fruit-processes", args.fruit_processes is not None, ("--frame", "--recording")),
        ("--stream", args.stream is not None, ("--frame",)),
        ("--images", args.images is not None, ("--segment",)),
        ("--size", args.size is not None, ("--segment",)),
        ("--scene", args.scene is not None, ("--segment",)),
    )
    for option, given, kinds_for in rules:
        if given and kind not in kinds_for:
            need = " or ".join(k or "the cloud bench (no --frame, --recording or --segment)" for k in kinds_for)
            raise InputError(f"bench {option} is for {need}; here it would be ignored")
    for a, b, on in (("--profile", "--stages", args.profile and args.stages),
                     ("--stream", "--stages", args.stream is not None and (args.stages or args.profile)),
                     ("--stream", "--sensor", args.stream is not None and args.sensor is not None),
                     ("--profile", "--fruit-processes", args.profile and args.fruit_processes is not None),
                     ("--profile", "--json", args.profile and args.json),
                     ("--scene", "--images", args.scene is not None and args.images is not None),
                     ("--scene", "--size", args.scene is not None and args.size is not None)):  # fmt: skip
        if on:
            raise InputError(f"bench {a} and {b} do not go together ({a} would take over, {b} ignored)")


def _bench(args: argparse.Namespace) -> int:
    from .core.limits import MAX_CLOUD_POINTS, shown
    from .errors import InputError
    from .evaluate.bench import machine, run_bench

    _check_bench_options(args)
    rounds = 3 if args.repeat is None else args.repeat  # --frame --stream's (alternated modes)
    args.repeat = 200 if args.repeat is None else args.repeat
    args.points = [600, 3000] if args.points is None else args.points
    args.size = "640x480" if args.size is None else args.size
    if not 1 <= args.repeat <= 100_000:  # --points is the cloud bench's alone: not named to --frame's runs
        raise InputError(f"--repeat must be 1-100000, got {shown(args.repeat)}")
    if any(not 10 <= n <= MAX_CLOUD_POINTS for n in args.points):
        raise InputError(f"every --points must be 10-{MAX_CLOUD_POINTS} (the most a cloud file may hold)")
    if args.segment:
        from .core.limits import check_image_size
        from .evaluate.bench import bench_segment

        try:
            width, height = (_whole(v) for v in str(args.size).lower().split("x"))
        except (ValueError, argparse.ArgumentTypeError):
            raise InputError(f"--size must be WIDTHxHEIGHT, e.g. 1920x1080, got {args.size!r}") from None
        check_image_size(width, height, "--size")
        if args.scene is not None:
            from .evaluate.bench import bench_segment_trees

            row = bench_segment_trees()
        else:
            row = bench_segment(args.images, size=(width, height))
        if args.json:
            print(json.dumps({"machine": machine(), "segment": row.to_dict()}, indent=2))
            return 0
        alone = "with depth" if args.scene is not None else "colour alone"
        print(f"symfruit bench --segment: {row.images} {row.source} at {row.width}x{row.height}, {alone}, "
              f"one process: median {row.median_ms:.2f} ms, p90 {row.p90_ms:.2f} ms, max {row.max_ms:.1f} ms "
              "per image")  # fmt: skip
        return 0
    if args.recording is not None:
        from .evaluate.bench import bench_recording

        if not 1 <= args.recording <= 100_000:
            raise InputError("--recording must be between 1 and 100000 frames")
        if args.workers is not None:
            from .season.cluster import local_cluster, require_distributed

            require_distributed()
            if not 1 <= args.workers <= 256:
                local_cluster(args.workers)  # refuses with the message of detect --workers
        if args.workers is not None and args.fruit_processes:
            raise InputError("bench --recording: --fruit-processes shares each frame's fruit in one process; "
                             "--workers runs frames on a cluster whose workers are one of several already")  # fmt: skip
        rec = bench_recording(args.recording, method=_method(args), workers=args.workers,
                              fruit_processes=_fruit_processes(args))  # fmt: skip
        if args.json:
            print(json.dumps({"machine": machine(), "recording": rec.to_dict()}, indent=2))
            return 0
        if rec.workers:
            peaks = ", ".join(f"{p:.0f}" for p in rec.worker_peak_mb)
            print(f"symfruit bench --recording --workers {rec.workers}: {rec.frames} frames ({rec.frames_done} "
                  f"written), method {rec.method}: {rec.seconds:.1f} s, {rec.frames / rec.seconds:.2f} frames/s "
                  f"(cluster start {rec.startup_seconds:.1f} s not included); peak RSS per worker {peaks} MB, client "
                  f"{rec.peak_rss_mb:.0f} MB; overhead per task {rec.task_overhead_ms:.1f} ms CPU (client, scheduler "
                  f"and worker together), {rec.task_wall_ms:.1f} ms wall per empty task")  # fmt: skip
            return 0
        pooled = f", --fruit-processes {args.fruit_processes}" if args.fruit_processes else ""
        print(f"symfruit bench --recording: {rec.frames} frames ({rec.frames_done} written), method {rec.method}"
              f"{pooled}: {rec.seconds:.1f} s, {rec.frames / rec.seconds:.1f} frames/s, "
              f"peak RSS {rec.peak_rss_mb:.0f} MB")  # fmt: skip
        return 0
    if args.frame:
        from .evaluate.bench import profile_frame
        from .fruitpool import FruitPool

        if args.profile:
            print(profile_frame(repeat=min(args.repeat, 5), method=_method(args), sensor=args.sensor))
            return 0
        methods = (_method(args),) if args.method is not None else ("paper", "fused", "evidence")
        fruit_processes = _fruit_processes(args)
        with FruitPool(fruit_processes, method=methods[0]) as pool:
            if fruit_processes and not pool.active:
                raise InputError(f"bench --fruit-processes {fruit_processes}: no worker process here ({pool.reason})")
            if fruit_processes and not args.json:
                print(f"symfruit bench --frame: {fruit_processes} fruit worker process"
                      f"{'es' if fruit_processes > 1 else ''} started and warm in {pool.started_s:.1f} s")  # fmt: skip
            if args.stream is not None:
                return _bench_stream(args, methods[0], pool, min(rounds, 100))
            return _bench_frame(args, methods, pool)
    rows = run_bench(repeat=args.repeat, points=tuple(args.points))
    return _bench_rows(args, rows)


def _bench_frame(args: argparse.Namespace, methods: tuple[str, ...], pool: Any) -> int:
    """``symfruit bench --frame`` (but for ``--profile``), each frame's fruit shared with ``pool``'s workers."""
    from .evaluate.bench import bench_frame, machine

    if args.stages:
        import numpy as np

        from .evaluate.bench import STAGES, bench_stages

        found = {m: bench_stages(repeat=min(args.repeat, 200), method=m, sensor=args.sensor, pool=pool)
                 for m in methods}  # fmt: skip
        if args.json:
            print(json.dumps({"machine": machine(), "stages": {m: {k: v.tolist() for k, v in ms.items()}
                                                               for m, ms in found.items()}}))  # fmt: skip
            return 0
        runs = len(next(iter(found.values()))["total"])
        print(f"symfruit bench --frame --stages: ms per frame over {runs} runs after a warm-up, median / least; "
              "wall time per stage, CPU time of the thread ('cpu', and the fruit workers' on their fruit); trim and "
              "register are part of extract, occlusion of complete")  # fmt: skip
        print(f"{'stage':<10}" + "".join(f"{m:>22}" for m in methods))
        for stage in STAGES:
            cells = "".join(f"{np.median(found[m][stage]):>13.1f} / {found[m][stage].min():>6.1f}" for m in methods)
            print(f"{stage:<10}{cells}")
        return 0
    rows = [bench_frame(repeat=min(args.repeat, 50), method=m, sensor=args.sensor, pool=pool) for m in methods]
    return _bench_rows(args, rows)


def _bench_stream(args: argparse.Namespace, method: str, pool: Any, rounds: int) -> int:
    """``symfruit bench --frame --stream F``: frames per second, each frame alone against frames in a stream."""
    import numpy as np

    from .errors import InputError
    from .evaluate.bench import bench_stream, machine

    if not 2 <= args.stream <= 100_000:
        raise InputError(f"--stream must be 2-100000 frames, got {args.stream}")
    got = bench_stream(args.stream, rounds=rounds, method=method, pool=pool)
    if args.json:
        print(json.dumps({"machine": machine(), "stream": got}))
        return 0
    print(f"symfruit bench --frame --stream {args.stream}: {method}, {_processes(args)}, {rounds} rounds alternated; "
          "frames/s (wall) each round, median CPU ms per frame (this thread and the workers) and median frame's "
          "own wall ms")  # fmt: skip
    for name, row in got.items():
        fps = ", ".join(f"{v:.1f}" for v in row["fps"])
        print(f"{name:<8} {fps} frames/s (median {np.median(row['fps']):.1f}); cpu {np.median(row['cpu_ms']):.1f} "
              f"ms, frame {np.median(row['latency_ms']):.1f} ms")  # fmt: skip
    return 0


def _processes(args: argparse.Namespace) -> str:
    """Where ``bench``'s rows ran, for its header line."""
    n = getattr(args, "fruit_processes", None) or 0
    return f"the fruit shared with {n} worker process{'es' if n > 1 else ''}" if n else "one process"


def _bench_rows(args: argparse.Namespace, rows: list[Any]) -> int:
    """The rows of ``symfruit bench`` or ``bench --frame`` printed (``--json``: as JSON)."""
    from .evaluate.bench import machine

    if args.json:
        print(json.dumps({"machine": machine(), "rows": [r.to_dict() for r in rows]}, indent=2))
        return 0
    info = machine()
    print(
        f"symfruit bench: median of {rows[0].repeat} runs per {'frame' if args.frame else 'fruit'}, "
        f"{_processes(args)} "
        f"(Python {info['python']}, numpy {info['numpy']}, {info['cpus']} CPUs)"
    )
    print(f"{'case':<26} {'points':>6} {'planes':>6} {'median ms':>10} {'min':>8} {'p10':>8} {'p90':>8}")
    for r in rows:
        print(f"{r.case:<26} {r.points:>6} {r.planes:>6} {r.median_ms:>10.2f} {r.min_ms:>8.2f} {r.p10_ms:>8.2f} "
              f"{r.p90_ms:>8.2f}")  # fmt: skip
    return 0


def _check_evaluate_options(args: argparse.Namespace) -> None:
    """Refuse options the chosen evaluation would ignore (``--frames`` and ``--spheres`` together, or either with
    a ``--protocol``: one took over, unsaid), then fill in the defaults."""
    from .errors import InputError

    kinds = [k for k, on in (("--frames", args.frames is not None), ("--spheres", args.spheres is not None),
                             (f"--protocol {args.protocol}", args.protocol is not None)) if on]  # fmt: skip
    if len(kinds) > 1:
        raise InputError(f"evaluate: {' and '.join(kinds)} are two evaluations; give one")
    masks, photos = args.protocol == "masks", args.images is not None or args.truth is not None
    generated = not (masks and photos) and args.frames is None and args.spheres is None  # what --n and --seed make
    protocols = not masks and args.frames is None and args.spheres is None  # the paper and camera protocols
    camera = protocols and args.protocol == "camera"
    rules = (  # option, given, where it counts, what that is
        ("--match", args.match is not None, args.frames is not None, "--frames"),
        ("--masks", args.masks is not None, masks or args.frames is not None or args.spheres is not None,
         "--frames, --spheres or --protocol masks"),
        ("--images", args.images is not None, masks, "--protocol masks"),
        ("--truth", args.truth is not None, masks, "--protocol masks"),
        ("--category", args.category is not None, masks and photos, "--protocol masks with --images and --truth"),
        ("--no-depth", args.no_depth, masks and not photos, "--protocol masks on rendered scenes (no --images)"),
        ("--scene", args.scene is not None, masks and not photos, "--protocol masks on rendered scenes (no --images)"),
        ("--n", args.n is not None, generated, "the paper and camera protocols and --protocol masks on scenes"),
        ("--seed", args.seed is not None, generated, "the paper and camera protocols and --protocol masks on scenes"),
        ("--methods", args.methods is not None, not masks, "--frames, --spheres and the paper and camera protocols"),
        ("--quick", args.quick, protocols, "the paper and camera protocols"),
        ("--jobs", args.jobs is not None, protocols, "the paper and camera protocols"),
        ("--pose", args.pose is not None, protocols, "the paper and camera protocols"),
        ("--occlusion", args.occlusion is not None, camera, "--protocol camera"),
        ("--sensor", args.sensor is not None, camera, "--protocol camera"),
        ("--sensor-set", args.sensor_set is not None, camera and args.sensor in REAL_SENSORS,
         f"--protocol camera with a real camera model (--sensor {'/'.join(REAL_SENSORS)})"),
        ("--views", args.views is not None, camera, "--protocol camera"),
        ("--fruit", args.fruit is not None, args.spheres is None,
         "the protocols and --frames (--spheres use no profile)"),
        ("--no-profile", args.no_profile, args.spheres is None,
         "the protocols and --frames (--spheres use no profile)"),
    )  # fmt: skip
    for option, given, counts, need in rules:
        if given and not counts:
            raise InputError(f"evaluate {option} is for {need}; here it would be ignored")
    if args.frames is not None and args.fruit is not None:
        from .synthetic.shapes import FRUITS

        if args.fruit.strip() not in FRUITS:  # a list, all or a folder of scans: the frames have one profile
            raise InputError(f"evaluate --frames --fruit {args.fruit!r}: give one fruit kind (its profile is the "
                             "frames')")  # fmt: skip
    args.fruit = "strawberry" if args.fruit is None else args.fruit  # an empty --fruit is refused, not the default
    args.protocol = args.protocol or "paper"
    args.match = args.match or "centre"
    args.category = 1 if args.category is None else args.category
    args.scene = args.scene or "strawberry"
    args.seed = 0 if args.seed is None else args.seed
    args.methods = _EVALUATED if args.methods is None else args.methods
    args.occlusion = "0" if args.occlusion is None else args.occlusion
    args.sensor = args.sensor or "d435"
    args.pose = args.pose or "hanging"
    args.views = 1 if args.views is None else args.views


def _line(text: str) -> str:
    """One printed line per item: a line break in a name or reason (a frame folder named with one) shown as
    ``\\n``; printed as it stood, one failed frame read as several, the second a frame of another name."""
    return text.replace("\r", "\\r").replace("\n", "\\n")


def _evaluate(args: argparse.Namespace) -> int:
    from .errors import InputError
    from .evaluate import evaluate
    from .methods import get
    from .synthetic.sensors import parse_sensor_set
    from .synthetic.shapes import FRUITS
    from .writers import check_results_root

    _check_evaluate_options(args)
    check_results_root(args.output)  # before the work, not after it
    if args.protocol == "masks":
        return _evaluate_masks(args)
    fruits = _entries("--fruit", args.fruit, "fruit kinds or folders such as strawberry,apple")  # a,,b: refused
    if fruits == ["all"]:
        fruits = list(FRUITS)
    for fruit in fruits:
        if fruit not in FRUITS and not Path(fruit).is_dir():
            raise InputError(f"--fruit {fruit!r}: not a fruit kind ({', '.join(FRUITS)}, all) nor a folder of scans")
    methods = _entries("--methods", args.methods, "method names such as raw,paper")  # raw,,paper: refused
    for method in methods:
        get(method)
    for option, names in (("--fruit", fruits), ("--methods", methods)):  # nothing to evaluate: an empty table
        if not names:
            raise InputError(f"{option} {getattr(args, option[2:])!r} names nothing; give at least one")
        if len(set(names)) < len(names):
            twice = next(name for name in names if names.count(name) > 1)
            raise InputError(f"{option} names {twice!r} twice")
    occlusions = [float(x) for x in _entries("--occlusion", args.occlusion, "numbers such as 0,0.25,0.5", numbers=True)]
    if any(not 0.0 <= x < 1.0 for x in occlusions):
        raise InputError("--occlusion levels must be in [0, 1)")
    if len(set(occlusions)) < len(occlusions):  # as --methods: the same views again, counted as more of them
        level = next(x for x in occlusions if occlusions.count(x) > 1)
        raise InputError(f"--occlusion names the level {level:g} twice")
    if args.n is not None and not 1 <= args.n <= 100_000:
        raise InputError("--n must be between 1 and 100000")
    if args.protocol == "paper" and args.pose == "uniform":
        raise InputError("--pose uniform is for the camera protocol (the paper protocol has its own 19 poses)")
    if not 1 <= args.views <= 100_000 or (args.views > 1 and args.protocol != "camera"):
        raise InputError("--views must be 1-100000, and more than 1 only with --protocol camera")
    if not 0 <= args.seed < 2**63:
        from .core.limits import shown

        raise InputError(f"--seed must be a whole number >= 0, got {shown(args.seed)}")
    if args.jobs is not None and not 1 <= args.jobs <= 256:
        raise InputError(f"--jobs must be between 1 and 256, got {args.jobs}")
    if args.spheres is not None:
        return _evaluate_spheres(args, methods, _plain_settings(args))
    if args.frames is not None:
        from .profiles import available_profiles

        profile = fruits[0] if len(fruits) == 1 and fruits[0] in available_profiles() else None
        settings = _plain_settings(args) if args.no_profile else _settings_for(args, profile)
        return _evaluate_frames(args, methods, settings)
    result = evaluate(
        protocol=args.protocol, fruits=fruits, methods=methods, n=args.n, seed=args.seed,
        occlusions=occlusions, sensor=args.sensor, poses=args.pose, views=args.views, quick=args.quick,
        sensor_set=parse_sensor_set(args.sensor_set) if args.sensor_set is not None else (),
        config=args.config, output=args.output, jobs=args.jobs,
        settings=_plain_settings(args) if args.no_profile else None,
    )  # fmt: skip
    print(result.table)
    for name, reason in result.skipped.items():
        print(_line(f"skipped {name}: {reason}"))
    print(f"results: {result.folder}")
    return 1 if result.skipped else 0  # as detect: the evaluation went on past a bad scan, and says so


def _plain_settings(args: argparse.Namespace):
    """The defaults with ``--config`` over them, no fruit profile."""
    from .settings import resolve_settings

    return resolve_settings(config=args.config)


def _evaluate_frames(args: argparse.Namespace, methods: list[str], settings) -> int:
    from .errors import InputError
    from .evaluate.frames import evaluate_frames, summary_dict, table3
    from .io import atomic_write, write_json
    from .writers import new_results_folder

    masks = args.masks or "auto"
    by_id = args.match == "id"
    if by_id and masks != "auto":
        raise InputError("--match id needs the frames' own masks (their labels are the truth's ids): leave --masks out")
    scores, totals, failed = evaluate_frames(args.frames, methods=methods, masks=masks, settings=settings, by_id=by_id)
    table = table3(scores, totals, methods)
    folder = new_results_folder(args.output, "frames")
    write_json(folder / "summary.json", {**summary_dict(scores, totals, failed), "settings": settings.to_dict()})
    with atomic_write(folder / "table.md", "w") as handle:
        handle.write(table)
    print(table)
    for name, reason in failed.items():
        print(_line(f"skipped {name}: {reason}"))
    print(f"results: {folder}")
    return 1 if failed else 0  # as detect: the batch went on past a bad frame, and says so


def _evaluate_spheres(args: argparse.Namespace, methods: list[str], settings) -> int:
    from .evaluate.spheres import evaluate_spheres, spheres_table
    from .io import atomic_write, write_json
    from .writers import new_results_folder

    failed: dict[str, str] = {}
    rows = evaluate_spheres(args.spheres, methods=methods, masks=args.masks or "auto", settings=settings,
                            failed=failed)  # fmt: skip
    table, summary = spheres_table(rows, methods)
    folder = new_results_folder(args.output, "spheres")
    write_json(folder / "summary.json", {"source": str(args.spheres), "methods": summary, "failed": failed,
                                         "settings": settings.to_dict()})  # fmt: skip
    with atomic_write(folder / "table.md", "w") as handle:
        handle.write(table)
    print(table)
    for name, reason in failed.items():
        print(_line(f"skipped {name}: {reason}"))
    print(f"results: {folder}")
    if not rows and not failed:  # every frame read, none with a sphere: exit 1 without a word before (stop 56)
        print(_line(f"symfruit: {args.spheres}: no frame's masks hold a sphere (every mask is empty): "
                    "nothing was evaluated"), file=sys.stderr)  # fmt: skip
    return 1 if failed or not rows else 0


def _evaluate_masks(args: argparse.Namespace) -> int:
    from .errors import InputError
    from .evaluate.masks import evaluate_masks, evaluate_scene_masks
    from .writers import new_results_folder, write_mask_report

    if args.no_profile:
        settings = _plain_settings(args)
    else:
        settings = _settings_for(args, "strawberry" if args.fruit == "strawberry" else None)
    from .segment import mask_source

    labeller = mask_source(args.masks or "color", settings=settings, images=())
    source = labeller.name

    def run(color: np.ndarray, depth: np.ndarray | None = None, camera: object = None, name: str = "",
            color_file: tuple[str, int] | None = None) -> np.ndarray:  # fmt: skip
        return labeller(color, depth, camera, name=name, color_file=color_file)[0]

    if args.images is not None or args.truth is not None:
        if args.images is None or args.truth is None:
            raise InputError("--protocol masks needs both --images DIR and --truth COCO.json")
        category = None if args.category < 0 else args.category
        # each photograph's name and orientation: --masks label PNGs are found by name and must turn as it does
        ev = evaluate_masks(args.images, args.truth, run, category=category, files=True)
        meta = {"images": str(args.images), "truth": str(args.truth), "category": category, "depth": False}
        what = f"{args.images}"
    else:
        if args.n is not None and not 1 <= args.n <= 10_000:
            raise InputError("--n must be 1-10000 scenes")
        if not 0 <= args.seed < 2**63:
            from .core.limits import shown

            raise InputError(f"--seed must be a whole number >= 0, got {shown(args.seed)}")
        n = args.n or 20
        ev = evaluate_scene_masks(range(args.seed, args.seed + n), run, depth=not args.no_depth, scene=args.scene)
        meta = {"scenes": n, "seed": args.seed, "depth": not args.no_depth, "scene": args.scene}
        what = (f"rendered {args.scene} scenes {args.seed}-{args.seed + n - 1} "
                f"({'colour alone' if args.no_depth else 'with depth'})")  # fmt: skip
    folder = new_results_folder(args.output, "masks")
    write_mask_report(folder, ev, meta={**meta, "mask_source": source, "settings": settings.to_dict()["segment"]})
    s = ev.summary
    iou = "-" if s["mean_best_iou"] is None else f"{s['mean_best_iou']:.3f}"
    share = "-" if s["matched_share"] is None else f"{s['matched_share']:.1%}"
    ms = "" if s["ms_median"] is None else f"; {s['ms_median']:.1f} ms per image (median), {s['ms_p90']:.1f} (p90)"
    skipped = f" ({s['skipped_images']} skipped, below)" if s.get("skipped_images") else ""
    print(f"masks ({source}) on {what}: {s['images']} images{skipped}, {s['true_fruit']} true fruit, {s['detections']} "
          f"found; mean best-match IoU {iou}; matched {s['matched']} ({share}), missed {s['missed']}, false "
          f"{s['false']} ({s['false_share']:.1%} of found){ms}")  # fmt: skip
    if s.get("crowd_regions"):
        print(f"{s['crowd_regions']} crowd regions (iscrowd) ignored as COCO does: not counted as fruit, and "
              f"{s['ignored_in_crowd']} regions found in them counted neither matched nor false")  # fmt: skip
    for name, reason in ev.failed.items():
        print(_line(f"skipped {name}: {reason}"))
    print(f"results: {folder} (masks.csv, summary.json, worst.png)")
    return 1 if ev.failed else 0


def _segment(args: argparse.Namespace) -> int:
    from .batch import segment_images
    from .errors import InputError
    from .io import load_camera

    # depth is the colour segmenter's alone: a model or mask files label the colour image without it
    rules = (("--camera", args.camera is not None, args.depth is not None, "--depth"),
             ("--depth-scale", args.depth_scale is not None, args.depth is not None, "--depth"),
             ("--depth", args.depth is not None, args.masks == "color", "--masks color (the colour segmenter; "
              f"--masks {args.masks} does not use depth)"))  # fmt: skip
    for option, given, counts, need in rules:
        if given and not counts:
            raise InputError(f"segment {option} is for {need}; here it would be ignored")
    camera = load_camera(args.camera) if args.camera else None
    from .io.frames import file_depth_scale

    if args.depth_scale is not None and not 0 < args.depth_scale <= 1:  # named as such, not as two that disagree
        raise InputError(f"segment --depth-scale must be metres per unit in (0, 1], got {args.depth_scale:g}")
    stated = file_depth_scale(args.camera) if args.camera else None  # as a frame's camera.json: read, not ignored
    if stated is not None and args.depth_scale is not None and stated != args.depth_scale:
        raise InputError(f"segment --depth-scale {args.depth_scale:g} and {args.camera}'s depth scale {stated:g} "
                         "disagree; which one is meant? Give one")  # fmt: skip
    depth_scale = args.depth_scale if args.depth_scale is not None else stated if stated is not None else 0.001
    report = segment_images(args.inputs, output=args.output, masks=args.masks, depth=args.depth, camera=camera,
                            depth_scale=depth_scale, settings=_settings_for(args), progress=True)  # fmt: skip
    if len(report.done) <= 20:
        for d in report.done:
            print(_line(f"{d.path.name}: {d.fruit} fruit ({'colour + depth' if d.used_depth else 'colour alone'}, "
                        f"{d.ms:.1f} ms)"))  # fmt: skip
    for name, reason in report.failed.items():
        print(_line(f"  failed {name}: {reason}"))
    alone = sum(not d.used_depth for d in report.done)
    note = ""
    if alone and report.mask_source == "colour segmenter":
        note = (f"; {alone} on colour alone (no depth split; least fruit = segment.min_area_share of the image, "
                "whole outlines)")  # fmt: skip
    ms = sorted(d.ms for d in report.done)
    median = f", {ms[len(ms) // 2]:.1f} ms per image (median)" if ms else ""
    print(f"segment ({report.mask_source}): {len(report.done)} images, {report.fruit} fruit, {len(report.failed)} "
          f"failed{note}{median}; labels and overlays in {args.output}")  # fmt: skip
    if report.stopped:
        print(_line(f"symfruit: {report.stopped}"), file=sys.stderr)
    return 0 if report.ok else 1


def _fruit_processes(args: argparse.Namespace) -> int:
    """``--fruit-processes`` checked (0 when not given)."""
    from .fruitpool import check_fruit_processes

    return 0 if args.fruit_processes is None else check_fruit_processes(args.fruit_processes, "--fruit-processes")


def _detect(args: argparse.Namespace) -> int:
    from .batch import run_batch
    from .errors import InputError
    from .methods import get

    get(_method(args))
    if args.chunk is not None and not 1 <= args.chunk <= 10_000:  # refused whether or not a cluster uses it
        raise InputError(f"--chunk must be between 1 and 10000 frames per task, got {args.chunk}")
    if args.chunk is not None and not args.scheduler and args.workers is None:
        raise InputError("--chunk (frames per Dask task) is for --scheduler or --workers; here it would be ignored")
    from .season.cluster import check_no_worker_timeout, check_silent_worker_timeout

    for option, value, check, what in (
        ("--no-worker-timeout", args.no_worker_timeout, check_no_worker_timeout, "the wait for a Dask worker"),
        ("--silent-worker-timeout", args.silent_worker_timeout, check_silent_worker_timeout,
         "when a Dask worker not heard from counts as none"),
    ):  # fmt: skip
        if value is None:  # refused whether or not a cluster uses it, before anything is read
            continue
        check(value)
        if not args.scheduler and args.workers is None:
            raise InputError(f"{option} ({what}) is for --scheduler or --workers; here it would be ignored")
    fruit_processes = _fruit_processes(args)
    if fruit_processes and (args.scheduler or args.workers is not None):
        raise InputError("--fruit-processes shares each frame's fruit with processes of this one: a Dask cluster's "
                         "workers (--scheduler, --workers) are one of several processes already")  # fmt: skip
    settings = _settings_for(args)
    if (args.scheduler or args.workers is not None) and args.ros2_bag is not None:
        raise InputError("--ros2-bag is written by this process frame by frame: it cannot be combined with "
                         "--scheduler or --workers")  # fmt: skip
    if len(args.inputs) > 1 and args.ros2_bag is not None:
        raise InputError("--ros2-bag holds the frames of one recording: give one input with it")
    if args.ros2_storage is not None and args.ros2_bag is None:
        raise InputError("--ros2-storage (the storage of --ros2-bag) is for --ros2-bag; here it would be ignored")
    if args.ros2_bag is not None:
        bag_at, out_at = os.path.realpath(args.ros2_bag), os.path.realpath(args.output)
        if os.path.commonpath([bag_at, out_at]) == bag_at:  # the bag's folder would hold the run's files
            raise InputError(f"--ros2-bag {args.ros2_bag} holds --output {args.output}: the bag's files and the "
                             "run's would share a folder; give the bag a folder of its own (e.g. OUT/bag)")  # fmt: skip
    from .fruitpool import FruitPool

    # the workers warm up while the first frames run here alone (wait=False): no frame waits for them
    with _ros2_bag(args) as bag, FruitPool(fruit_processes, method=_method(args), wait=False) as pool:
        source = args.inputs[0] if len(args.inputs) == 1 else args.inputs
        report = run_batch(source, args.output, masks=args.masks, method=_method(args), settings=settings,
                           resume=args.resume, on_frame=None if bag is None else bag.write_frame,
                           exclude=[] if bag is None else [args.ros2_bag], scheduler=args.scheduler,
                           workers=args.workers, chunk=args.chunk or 4,
                           no_worker_timeout=args.no_worker_timeout,
                           silent_worker_timeout=args.silent_worker_timeout, pool=pool)  # fmt: skip
    if fruit_processes and pool.reason != "the pool is closed":
        print(_line(f"  --fruit-processes {fruit_processes}: no worker process ({pool.reason})"))
    print(f"frames: {len(report.done)} done, {len(report.skipped)} skipped (resume), {len(report.failed)} failed; "
          f"fruit: {report.fruits} located, {report.failed_fruits} failed")  # fmt: skip
    for name, reason in report.failed.items():
        print(_line(f"  failed {name}: {reason}"))
    renamed = {k: v for k, v in report.recordings.items() if v != Path(k).absolute().name}
    for given, folder in renamed.items():
        print(_line(f"  recording {given} -> {args.output / folder} (its name is shared or not a plain file name)"))
    for name, reason in report.failed_recordings.items():
        print(_line(f"  recording not read {name}: {reason}"))
    if report.unprocessed:
        print(f"  not processed: {len(report.unprocessed)} frames (listed in errors.json)")
    if report.stopped:
        print(_line(f"symfruit: {report.stopped}"), file=sys.stderr)
    per = "per frame" if len(args.inputs) == 1 else "per recording, in it one per frame"
    print(f"results: {args.output} (one folder {per}; every fruit in detections.parquet)")
    if bag is not None:
        print(f"ROS 2 bag: {args.ros2_bag} ({bag.count} frames on {bag.topic})")
    return 0 if report.ok else 1


@contextlib.contextmanager
def _ros2_bag(args: argparse.Namespace) -> Iterator[Any]:
    """The ``--ros2-bag`` writer (None without the option); a bag left by a batch that could not start is
    removed again."""
    if args.ros2_bag is None:
        yield None
        return
    from .errors import InputError
    from .ros.bag2 import Ros2DetectionBag

    if args.resume:
        raise InputError("--ros2-bag writes every frame into a new bag; it cannot be combined with --resume")
    bag = Ros2DetectionBag(args.ros2_bag, storage=args.ros2_storage or "mcap", class_id=Path(args.fruit).stem).open()
    try:
        yield bag
    except BaseException:
        bag.close(keep=bag.count > 0)  # the frames done, in place complete; none: no bag
        raise
    bag.close()


def _demo(args: argparse.Namespace) -> int:
    from .demo import run_demo

    report = run_demo(args.output, method=_method(args), settings=_settings_for(args))
    found = report.found
    frame = found.frame
    print(f"symfruit demo: {frame.name} ({frame.camera.width}x{frame.camera.height}), {len(found.detections)} fruit "
          f"found, {report.n_truth} ripe fruit in the truth, method {_method(args)}")  # fmt: skip
    print(f"{'fruit':>5} {'points':>6}  {'centre x, y, z (mm)':<24} {'size x, y, z (mm)':<20} "
          f"{'raw err':>8} {'completed err':>13}")  # fmt: skip
    for d in report.located:
        assert d.result is not None
        c, size = d.result.centre * 1000, d.result.box.size * 1000
        line = f"{d.id:>5} {len(d.extraction.points):>6}  {c[0]:7.1f} {c[1]:7.1f} {c[2]:7.1f}  "
        line += f"{size[0]:5.1f} {size[1]:5.1f} {size[2]:5.1f}  "
        err = report.errors.get(d.id)
        line += f"{err[0]:6.1f} mm {err[1]:10.1f} mm" if err else f"{'-':>8} {'-':>13}  (no true fruit matched)"
        print(line + (" (truncated)" if d.extraction.truncated else ""))
    for d in found.detections:
        if d.result is None:
            print(f"{d.id:>5} failed: {d.error}")
    means = report.mean_errors()
    if means:
        print(f"mean centre error: raw {means[0]:.1f} mm, completed {means[1]:.1f} mm")
    t = found.timings
    print(f"time: {t['total'] * 1000:.0f} ms (segment {t['segment'] * 1000:.0f}, extract {t['extract'] * 1000:.0f}, "
          f"complete {t['complete'] * 1000:.0f})")  # fmt: skip
    print(f"overlay: {report.output / 'overlay.png'}")
    print(f"detections: {report.output / 'detections.json'}")
    return 0


def _scenes(args: argparse.Namespace) -> int:
    from .core.limits import shown
    from .errors import InputError
    from .synthetic.scenes import write_scenes

    tree = args.scene == "apple-tree"
    ripe = (30 if tree else 6) if args.ripe is None else args.ripe
    unripe = (4 if tree else 2) if args.unripe is None else args.unripe
    for option, value, low, high in (("--n", args.n, 1, 100_000), ("--ripe", ripe, 0, 50), ("--unripe", unripe, 0, 50)):
        if not low <= value <= high:  # the option given named, not all three
            raise InputError(f"{option} must be {low}-{high}, got {shown(value)}")
    if not 0 <= args.seed <= 2**63 - args.n:  # as evaluate's seeds: every frame's seed below 2**63
        raise InputError(f"--seed must be a whole number >= 0 with --seed + --n at most 2**63, got {shown(args.seed)}")
    sensor = None
    if args.sensor_set is not None and args.sensor is None and not tree:
        raise InputError("scenes --sensor-set changes a real camera model: give --sensor or --scene apple-tree")
    if args.sensor is not None or tree:
        from .synthetic.sensors import parse_sensor_set, sensor_model, varied

        sensor = sensor_model(args.sensor or "azure-kinect")
        if args.sensor_set is not None:
            sensor = varied(sensor, parse_sensor_set(args.sensor_set))
    if args.plain_colour and not tree:
        raise InputError(
            "scenes --plain-colour is for --scene apple-tree (the strawberry frames have no camera effects)"
        )
    if args.plain_colour:
        folders = write_scenes(args.output, args.n, seed=args.seed, n_ripe=ripe, n_unripe=unripe, sensor=sensor,
                               tree=tree, photometric=None)  # fmt: skip
    else:  # the colour camera's effects, write_scenes' default
        folders = write_scenes(args.output, args.n, seed=args.seed, n_ripe=ripe, n_unripe=unripe, sensor=sensor,
                               tree=tree)  # fmt: skip
    what = "apple-tree frames" if tree else "frames"
    through = f", {sensor.name} at {sensor.width}x{sensor.height} with masks.png" if sensor is not None else ""
    print(f"wrote {len(folders)} {what} to {args.output} (seeds {args.seed}-{args.seed + args.n - 1}{through})")
    return 0


def _report(args: argparse.Namespace) -> int:
    from .season.report import write_report

    # 18,,25 was read as 18,25 and '١٨' (Arabic-Indic digits) or 1_8 as 18, unsaid
    classes = [float(x) for x in _entries("--classes", args.classes, "diameters in mm such as 18,25", numbers=True)]
    r = write_report(args.run, folder=args.output, classes=classes)
    print(f"report: {r.recordings} recording(s), {r.frames} frames, {r.fruit} fruit seen, {r.located} located, "
          f"{r.sized} sized; {r.folder / 'report.md'} and {len(r.written) - 1} plots")  # fmt: skip
    return 0


def _ros(args: argparse.Namespace) -> int:
    from .ros.node import main as ros_main

    return ros_main(args.ros_args)


def _ros2(args: argparse.Namespace) -> int:
    from .ros.node2 import main as ros2_main

    return ros2_main(args.ros_args)


def _settings(args: argparse.Namespace) -> int:
    import yaml

    print(yaml.safe_dump(_settings_for(args).to_dict(), sort_keys=False), end="")
    return 0


def _methods(args: argparse.Namespace) -> int:
    from .methods import available, get

    for name in available():
        print(f"{name:<10} {get(name).summary}")
    return 0


_COMMANDS = {
    "complete": _complete,
    "bench": _bench,
    "evaluate": _evaluate,
    "detect": _detect,
    "report": _report,
    "segment": _segment,
    "demo": _demo,
    "scenes": _scenes,
    "ros": _ros,
    "ros2": _ros2,
    "settings": _settings,
    "methods": _methods,
}


def _printable_names() -> None:
    """Let names that are not valid UTF-8 (a folder named with other bytes, which Python keeps as lone
    surrogates) be printed as backslash escapes where the terminal's encoding would refuse them (a UTF-8
    locale other than C), instead of a traceback after the work is done."""
    for stream in (sys.stdout, sys.stderr):
        if getattr(stream, "errors", None) == "strict" and hasattr(stream, "reconfigure"):
            stream.reconfigure(errors="backslashreplace")


def _show_warnings(own: type[Warning]) -> None:
    """Print symfruit's own warnings as one line, ``symfruit: warning: ...``, not Python's file:line form."""
    import warnings

    shown = warnings.showwarning
    if getattr(shown, "symfruit", False):  # main() called again in one process
        return

    def show(
        message: Warning | str,
        category: type[Warning],
        filename: str,
        lineno: int,
        file: TextIO | None = None,
        line: str | None = None,
    ) -> None:
        if issubclass(category, own):
            print(f"symfruit: warning: {message}".replace("\n", " "), file=file or sys.stderr)
        else:
            shown(message, category, filename, lineno, file, line)

    show.symfruit = True  # type: ignore[attr-defined]
    warnings.showwarning = show


#: Longest word (a path, a name) an error line shows whole; a longer one is shown by its two ends.
LONGEST_WORD = 120


def _short_words(message: str) -> str:
    """``message`` with each word (a run without spaces: a path) longer than :data:`LONGEST_WORD` shown by its
    ends and its length: a path of 5,000 characters made an error line of 5,000 (stop 49, robust49)."""

    def short(m: re.Match[str]) -> str:
        word = m.group(0).rstrip(":;,")
        return f"{word[:30]}...{word[-15:]} ({len(word):,} characters){m.group(0)[len(word) :]}"

    return re.sub(rf"[^ ]{{{LONGEST_WORD + 1},}}", short, message)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``symfruit`` console script; returns the exit status."""
    _printable_names()
    parser = _parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    from .errors import SymfruitError, SymfruitWarning

    _show_warnings(SymfruitWarning)
    try:
        return _COMMANDS[args.command](args)
    except SymfruitError as exc:
        if args.debug:
            raise
        message = f"symfruit: error: {_short_words(str(exc))}".replace("\n", " ")
        # Paths that are not valid UTF-8 must not crash the error report itself.
        print(message.encode("utf-8", "backslashreplace").decode("utf-8"), file=sys.stderr)
        return 2
    except OSError as exc:  # a name no file system holds, met by pathlib's exists()/is_file() anywhere
        import errno

        if exc.errno != errno.ENAMETOOLONG or args.debug:
            raise
        name = os.fsdecode(exc.filename) if exc.filename is not None else "a path"
        message = (f"symfruit: error: {_short_words(name)}: a file name longer than this system takes "
                   f"({len(name):,} characters; at most 255 bytes a name and 4096 a path)")  # fmt: skip
        print(message.encode("utf-8", "backslashreplace").decode("utf-8"), file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("symfruit: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into e.g. `head`: not an error of ours
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
