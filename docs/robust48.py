"""Stop 48: bad and adversarial input, widened past stop 47's sweep (robust48).

Every command's file inputs missing, empty, a folder, cut short or of the wrong kind; outputs that cannot be
written (a folder where a file goes, a path under a file); camera.json sizes of no image and depth scales of the
wrong unit; depth in millimetres given as metres and the other way round; the ROS node's frame processor fed
malformed messages (encodings, ``step``, sizes, stamps); a batch item that crashes; MCAP files whose records
claim sizes they cannot hold; and writes killed half-way (``complete --output``, ``detect`` of a recording).

Cases run in this process under an alarm, judged as docs/robust47.py judges them (its ``judge``, ``cli`` and
fixture helpers are imported: it builds its cases only when run), except the killed writes, which run the
command line in a child process and kill it. ``DEFECT``: an exception out of ``main``, a hang, a line over 300
characters, another library's words, an error where a result was expected or the other way round, a message
that does not name the damaged file, or (killed writes) a partial output file left under its own name.

::

    PYTHONPATH=src python docs/robust48.py                 # every case (fixtures in a temporary folder)
    PYTHONPATH=src python docs/robust48.py --only ros/ --defects
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import robust47 as r47

ROOT = r47.ROOT
LIMIT_S = 300
CASES: list[tuple[str, str, Callable[[], Any], str]] = []
cli, Run = r47.cli, r47.Run


def add(name: str, expect: str, fn: Callable[[], Any], names: str = "") -> None:
    CASES.append((name, expect, fn, names))


def T() -> Path:
    return r47.T


def _src() -> str:
    """The folder the symfruit under test is imported from (a child process runs the same one)."""
    import symfruit

    return str(Path(symfruit.__file__).resolve().parents[1])


def fixture(name: str) -> Path:
    """A fresh file or folder path for one case (removed if left by an earlier run)."""
    p = T() / "cases48" / name
    if p.is_dir() and not p.is_symlink():
        shutil.rmtree(p)
    elif p.exists() or p.is_symlink():
        p.unlink()
    p.parent.mkdir(parents=True, exist_ok=True)
    return p


def out(name: str) -> Path:
    return r47.out_dir(f"r48-{name}")


# --- the kinds of bad file -----------------------------------------------------------------------------------
def kinds(good: Path, suffix: str, wrong: bytes) -> dict[str, Callable[[Path], None]]:
    """How a file input is damaged: each makes the file at the path it is given (named with ``suffix``)."""
    data = good.read_bytes() if good.is_file() else b""
    return {
        "missing": lambda p: None,
        "empty": lambda p: p.write_bytes(b""),
        "folder": lambda p: p.mkdir(),
        "cut": lambda p: p.write_bytes(data[: max(1, len(data) // 2)]),
        "wrong-kind": lambda p: p.write_bytes(wrong),
        "nul-bytes": lambda p: p.write_bytes(b"\x00" * 4096),
    }


PNG_BYTES = (ROOT / "examples/realsense/aligned_00000/color.png").read_bytes()
TEXT_BYTES = b"these are notes, not data\n" * 20


def file_cases() -> None:
    """Every command's file inputs missing / empty / a folder / cut / of the wrong kind / NUL bytes."""
    ply = ROOT / "examples/strawberry_partial.ply"
    f640 = ROOT / "examples/realsense/aligned_00000"
    cam = f640 / "camera.json"
    settings = T() / "cases48-good.yaml"
    settings.write_text("evidence:\n  rays: 64\n")

    def each(label: str, suffix: str, good: Path, wrong: bytes, argv: Callable[[Path], list[Any]],
             expect: dict[str, str] | None = None,
             output: Callable[[], Path | None] = lambda: None) -> None:  # fmt: skip
        for kind, make in kinds(good, suffix, wrong).items():

            def run(kind: str = kind, make: Callable[[Path], None] = make) -> Run:
                p = fixture(f"{label.replace('/', '_')}-{kind}{suffix}")
                make(p)
                return cli(*argv(p), output=output())

            add(f"{label}/{kind}", (expect or {}).get(kind, "error"), run, f"{label.replace('/', '_')}-{kind}{suffix}")

    each("complete/cloud", ".ply", ply, PNG_BYTES, lambda p: ["complete", p])
    each("complete/cloud-pcd", ".pcd", ply, ply.read_bytes(), lambda p: ["complete", p])
    each("complete/cloud-npy", ".npy", ply, ply.read_bytes(), lambda p: ["complete", p])
    each("complete/cloud-xyz", ".xyz", ply, PNG_BYTES, lambda p: ["complete", p])
    each("complete/camera", ".json", cam, PNG_BYTES, lambda p: ["complete", ply, "--camera", p])
    each("complete/camera-yaml", ".yaml", cam, PNG_BYTES, lambda p: ["complete", ply, "--camera", p])
    each("complete/config", ".yaml", settings, PNG_BYTES, lambda p: ["complete", ply, "--config", p],
         {"empty": "any", "cut": "any"})  # fmt: skip
    each("complete/fruit", ".yaml", settings, PNG_BYTES, lambda p: ["complete", ply, "--fruit", p],
         {"empty": "any", "cut": "any"})  # fmt: skip
    each("settings/config", ".yaml", settings, PNG_BYTES, lambda p: ["settings", "--config", p],
         {"empty": "any", "cut": "any"})  # fmt: skip
    each("settings/config-json", ".json", settings, PNG_BYTES, lambda p: ["settings", "--config", p])
    each("detect/input-png", ".png", f640 / "color.png", TEXT_BYTES, lambda p: ["detect", p, "--output", out("d1")])
    each("detect/input-bag", ".bag", ROOT / "examples/realsense/fruit.bag", PNG_BYTES,
         lambda p: ["detect", p, "--output", out("d2")], {"cut": "any"})  # fmt: skip
    each("detect/config", ".yaml", settings, PNG_BYTES,
         lambda p: ["detect", f640, "--output", out("d3"), "--config", p],
         {"empty": "any", "cut": "any"})  # fmt: skip
    each("detect/masks-png", ".png", f640 / "color.png", TEXT_BYTES,
         lambda p: ["detect", f640, "--output", out("d4"), "--masks", p])  # fmt: skip
    each("detect/masks-json", ".json", cam, PNG_BYTES, lambda p: ["detect", f640, "--output", out("d5"), "--masks", p])
    each("segment/input", ".png", f640 / "color.png", TEXT_BYTES, lambda p: ["segment", p, "--output", out("s1")],
         {"cut": "any"})  # fmt: skip
    each("segment/input-jpg", ".jpg", f640 / "color.png", TEXT_BYTES, lambda p: ["segment", p, "--output", out("s2")],
         {"cut": "any"})  # fmt: skip
    each("segment/depth", ".png", f640 / "depth.png", TEXT_BYTES,
         lambda p: ["segment", f640 / "color.png", "--output", out("s3"), "--depth", p, "--camera", cam],
         {"cut": "any"})  # fmt: skip
    each("segment/camera", ".json", cam, PNG_BYTES,
         lambda p: ["segment", f640 / "color.png", "--output", out("s4"), "--depth", f640 / "depth.png",
                    "--camera", p])  # fmt: skip
    each("segment/masks", ".json", cam, PNG_BYTES,
         lambda p: ["segment", f640 / "color.png", "--output", out("s5"), "--masks", p])  # fmt: skip
    each("evaluate/truth", ".json", cam, PNG_BYTES,
         lambda p: ["evaluate", "--protocol", "masks", "--images", f640, "--truth", p, "--output",
                    out("e1")])  # fmt: skip
    each("evaluate/config", ".yaml", settings, PNG_BYTES,
         lambda p: ["evaluate", "--quick", "--config", p, "--output", out("e2"), "--methods", "raw"],
         {"empty": "any", "cut": "any"})  # fmt: skip
    each("evaluate/frames", "", f640, TEXT_BYTES, lambda p: ["evaluate", "--frames", p, "--output", out("e3")])
    each("bench/images", "", f640, TEXT_BYTES, lambda p: ["bench", "--segment", "--images", p])
    each("demo/config", ".yaml", settings, PNG_BYTES, lambda p: ["demo", "--output", out("demo1"), "--config", p],
         {"empty": "any", "cut": "any"})  # fmt: skip


# --- outputs that cannot be written ----------------------------------------------------------------------------
def output_cases() -> None:
    ply = ROOT / "examples/strawberry_partial.ply"
    f640 = ROOT / "examples/realsense/aligned_00000"

    def blocker(name: str) -> Path:
        """A plain file, whose path a case then writes under."""
        p = fixture(name)
        p.write_text("x")
        return p

    def folder_named(name: str) -> Path:
        p = fixture(name)
        p.mkdir()
        (p / "keep.txt").write_text("kept")
        return p

    add("output/complete-ply-is-a-folder", "error",
        lambda: cli("complete", ply, "--output", folder_named("o1.ply")), "o1.ply")  # fmt: skip
    add("output/complete-under-a-file", "error",
        lambda: cli("complete", ply, "--output", blocker("o2") / "x.ply"), "o2")  # fmt: skip
    add("output/complete-json-sibling-is-a-folder", "error",
        lambda: (folder_named("o3.json"), cli("complete", ply, "--output", T() / "cases48/o3.ply"))[1],
        "o3.json")  # fmt: skip
    add("output/complete-is-the-input", "any", lambda: cli("complete", fixture_copy(ply, "o4.ply"), "--output",
                                                           T() / "cases48/o4.ply"))  # fmt: skip
    add("output/detect-under-a-file", "error", lambda: cli("detect", f640, "--output", blocker("o5") / "x"), "o5")
    add("output/detect-record-is-a-folder", "any", lambda: detect_with_folder_in_place(), "")
    add("output/segment-under-a-file", "error",
        lambda: cli("segment", f640 / "color.png", "--output", blocker("o6") / "x"), "o6")  # fmt: skip
    add("output/segment-label-is-a-folder", "failed", lambda: segment_with_folder_in_place(), "color.png")
    add("output/report-under-a-file", "error",
        lambda: cli("report", a_run(), "--output", blocker("o7") / "x"), "o7")  # fmt: skip
    add("output/report-md-is-a-folder", "error",
        lambda: (folder_named("o8") and (T() / "cases48/o8/report.md").mkdir(),
                 cli("report", a_run(), "--output", T() / "cases48/o8"))[1], "report.md")  # fmt: skip
    add("output/report-is-a-file", "error", lambda: cli("report", a_run(), "--output", blocker("o9")), "o9")
    add("output/scenes-under-a-file", "error", lambda: cli("scenes", blocker("o10") / "x", "--n", "1"), "o10")
    add("output/demo-under-a-file", "error", lambda: cli("demo", "--output", blocker("o11") / "x"), "o11")
    add("output/demo-is-a-file", "error", lambda: cli("demo", "--output", blocker("o12")), "o12")
    add("output/evaluate-under-a-file", "error",
        lambda: cli("evaluate", "--quick", "--methods", "raw", "--output", blocker("o13") / "x"), "o13")  # fmt: skip
    add("output/ros2-bag-exists", "error",
        lambda: cli("detect", f640, "--output", out("o14"), "--ros2-bag", folder_named("o14bag")),
        "o14bag")  # fmt: skip
    add("output/ros2-bag-under-a-file", "error",
        lambda: cli("detect", f640, "--output", out("o15"), "--ros2-bag", blocker("o15bag") / "b"),
        "o15bag")  # fmt: skip


def fixture_copy(src: Path, name: str) -> Path:
    p = fixture(name)
    shutil.copy(src, p)
    return p


_RUN: list[Path] = []


def a_run() -> Path:
    """A detect run of the small example frame (made once)."""
    if not _RUN:
        o = out("run")
        cli("detect", ROOT / "examples/realsense/aligned_00000", "--output", o)
        _RUN.append(o)
    return _RUN[0]


def detect_with_folder_in_place() -> Run:
    """A recording of two frames whose first frame's detections.json is a folder in the output (a user's
    leftover): refused by name, or replaced."""
    rec = fixture("rec2")
    for n in ("a", "b"):
        shutil.copytree(ROOT / "examples/realsense/aligned_00000", rec / n)
    o = out("o16")
    (o / "a" / "detections.json").mkdir(parents=True)
    return cli("detect", rec, "--output", o, output=o)


def segment_with_folder_in_place() -> Run:
    o = out("o17")
    (o / "color.png").mkdir(parents=True)
    return cli("segment", ROOT / "examples/realsense/aligned_00000/color.png", "--output", o, output=o)


# --- camera.json and depth units -------------------------------------------------------------------------------
def camera_cases() -> None:
    b = "f640"
    for key, value, expect in [("width", -320, "error"), ("width", 320.5, "error"), ("width", "320", "error"),
                               ("width", 240, "error"), ("height", 320, "error"), ("width", 640, "error"),
                               ("width", 160, "error"), ("cx", 1e5, "any"), ("cx", -5000, "any"),
                               ("cy", float("nan"), "error"), ("fy", 1.0, "any"), ("fx", 1e5, "any"),
                               ("fx", 1e7, "error"), ("depth_scale", 1.0, "error"), ("depth_scale", 0.001, "any"),
                               ("depth_scale", 1e-5, "any"), ("depth_scale", 1e-7, "error"),
                               ("depth_scale", float("inf"), "error"), ("k1", 1e9, "any"),
                               ("distortion", [1e9] * 5, "any"), ("distortion", [0.0] * 100, "error"),
                               ("width", 10**400, "error")]:  # fmt: skip
        name = f"camera/{key}={value!r:.16}"
        if isinstance(value, float) and not np.isfinite(value):
            edit = camera_raw(key, "NaN" if np.isnan(value) else "Infinity")
        else:
            edit = r47.camera_edit(**{key: value})
        detect48(name, expect, b, edit, names="camera.json" if expect == "error" else "")
    detect48("camera/no-width-height", "any", b, camera_drop("width", "height"))
    detect48("camera/no-fx", "error", b, camera_drop("fx"), names="camera.json")
    detect48("camera/no-depth-scale", "any", b, camera_drop("depth_scale"))
    detect48("camera/extra-keys", "any", b, r47.camera_edit(model="D435", serial=123))
    detect48("camera/duplicate-fx", "any", b,
             lambda f: (f / "camera.json").write_text(
                 (f / "camera.json").read_text().replace('"fx"', '"fx": 1, "fx"', 1)))  # fmt: skip
    detect48("camera/utf16", "error", b,
             lambda f: (f / "camera.json").write_bytes((f / "camera.json").read_text().encode("utf-16")),
             names="camera.json")  # fmt: skip
    detect48("camera/bom", "any", b,
             lambda f: (f / "camera.json").write_bytes(b"\xef\xbb\xbf" + (f / "camera.json").read_bytes()))  # fmt: skip
    # depth units: millimetres as metres and metres as millimetres, in every file kind
    detect48("depth/npy-centimetres", "error", b, r47.depth_npy(lambda d: (d * 100).astype("f4")), names="depth")
    detect48("depth/npy-kilometres", "error", b, r47.depth_npy(lambda d: (d / 1000).astype("f4")), names="depth")
    detect48("depth/png-metres-as-units", "error", b, depth_png_metres, names="depth")
    detect48("depth/png-scale-1", "error", b, r47.camera_edit(depth_scale=1.0), names="")
    detect48("depth/png-scale-mm-for-0.1mm", "any", b, r47.camera_edit(depth_scale=0.001))
    detect48("depth/npy-mm-int32", "error", b, r47.depth_npy(lambda d: (d * 1000).astype(np.int32)), names="depth")
    detect48("depth/npy-metres-int", "error", b, r47.depth_npy(lambda d: np.rint(d).astype(np.int64)), names="depth")
    detect48("depth/npy-negative-all", "error", b, r47.depth_npy(lambda d: -np.abs(d).astype("f4") - 0.1), names="")


def bomb_cases() -> None:
    """Images whose header claims 400 megapixels in a 48 kB file (a 1-bit 20000 x 20000 PNG): refused from the
    header, before Pillow decodes (allocates) them, as colour, depth and masks of a frame and as segment's input."""

    def bomb(name: str) -> Callable[[Path], None]:
        def go(f: Path) -> None:
            from PIL import Image

            Image.new("1", (20000, 20000)).save(f / name, optimize=True)

        return go

    for name in ("color.png", "depth.png", "masks.png"):
        detect48(f"bomb/{name}", "error", "f640", bomb(name), names=name)

    def segment_bomb() -> Run:
        p = fixture("bomb.png")
        bomb("bomb.png")(p.parent)
        o = out("bomb")
        return cli("segment", p, "--output", o, output=o)

    add("bomb/segment-input", "failed", segment_bomb, "bomb.png")


def camera_raw(key: str, literal: str) -> Callable[[Path], None]:
    def go(f: Path) -> None:
        data = json.loads((f / "camera.json").read_text())
        data[key] = 0
        text = json.dumps(data).replace(f'"{key}": 0', f'"{key}": {literal}')
        (f / "camera.json").write_text(text)

    return go


def camera_drop(*keys: str) -> Callable[[Path], None]:
    def go(f: Path) -> None:
        data = json.loads((f / "camera.json").read_text())
        for k in keys:
            data.pop(k, None)
        (f / "camera.json").write_text(json.dumps(data))

    return go


def depth_png_metres(f: Path) -> None:
    """The depth written as whole metres in a 16-bit PNG (0, 1, 2 at depth_scale 0.001: millimetres)."""
    d = r47.depth_of(f).astype(np.float64) * json.loads((f / "camera.json").read_text())["depth_scale"]
    r47.png(f / "depth.png", np.rint(d).astype(np.uint16))
    r47.camera_edit(depth_scale=0.001)(f)


def detect48(name: str, expect: str, base: str, mutate: Callable[[Path], Any] | None, names: str = "") -> None:
    def run() -> Run:
        f = r47.frame_copy(r47.B(base), "r48_" + name.replace("/", "_"))
        if mutate is not None:
            mutate(f)
        o = out(name.replace("/", "_"))
        return cli("detect", f, "--output", o, output=o)

    add(name, expect, run, names)


# --- the ROS node's frame processor ----------------------------------------------------------------------------
def ros_cases() -> None:
    """``FrameProcessor.process`` on duck-typed messages of the small example frame, each damaged one way."""

    def hdr(sec: Any = 7, nsec: Any = 5, frame_id: Any = "cam") -> SimpleNamespace:
        return SimpleNamespace(stamp=SimpleNamespace(sec=sec, nanosec=nsec), frame_id=frame_id)

    def img(a: np.ndarray, encoding: str, **kw: Any) -> SimpleNamespace:
        a = np.ascontiguousarray(a)
        h, w = a.shape[:2]
        rows = a.reshape(h, -1).view(np.uint8)
        fields = dict(height=h, width=w, encoding=encoding, is_bigendian=0, step=rows.shape[1], data=rows.tobytes(),
                      header=hdr())  # fmt: skip
        fields.update(kw)
        return SimpleNamespace(**fields)

    def base() -> tuple[np.ndarray, np.ndarray, Any]:
        from symfruit.io.frames import read_frame

        fr = read_frame(r47.B("f640"))
        return fr.color, np.nan_to_num(fr.depth * 1000).astype(np.uint16), fr.camera

    def process(color: Callable[[SimpleNamespace], Any] = lambda m: m, depth: Callable[[SimpleNamespace], Any] =
                lambda m: m, info: Callable[[SimpleNamespace], Any] = lambda m: m) -> Any:  # fmt: skip
        from symfruit.ros.core import FrameProcessor

        c, d, cam = base()
        i = SimpleNamespace(width=cam.width, height=cam.height, header=hdr(), distortion_model="plumb_bob",
                            d=[0.0] * 5, k=[cam.fx, 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0])  # fmt: skip
        return FrameProcessor(masks="color", fruit="strawberry").process(
            color(img(c, "rgb8")), depth(img(d, "16UC1")), info(i)
        )

    def setf(**kw: Any) -> Callable[[SimpleNamespace], SimpleNamespace]:
        return lambda m: SimpleNamespace(**{**vars(m), **kw})

    add("ros/good", "result", lambda: process())
    for enc in ("bgr8", "rgba8", "mono8", "mono16", "16UC1", "32FC1", "yuv422", "jpeg", "", "RGB8", "bayer_rggb8"):
        add(f"ros/colour-encoding={enc!r}", "any" if enc in ("bgr8", "rgba8", "mono8", "yuv422", "RGB8") else "error",
            lambda e=enc: process(color=setf(encoding=e)), "")  # fmt: skip
    for enc in ("rgb8", "mono16", "8UC1", "32FC1", "64FC1", "16SC1", "", None, 16):
        add(f"ros/depth-encoding={enc!r}", "any" if enc == "mono16" else "error",
            lambda e=enc: process(depth=setf(encoding=e)), "")  # fmt: skip
    for field, value in [("step", 0), ("step", 1), ("step", 10**12), ("step", -960), ("step", 961), ("step", 2.5),
                         ("step", "960"), ("height", 0), ("height", 10**9), ("width", 0), ("width", -1),
                         ("width", 10**6), ("height", None), ("is_bigendian", 1), ("is_bigendian", 7)]:  # fmt: skip
        add(f"ros/colour-{field}={value!r}", "error" if field != "is_bigendian" else "any",
            lambda f=field, v=value: process(color=setf(**{f: v})), "")  # fmt: skip
        add(f"ros/depth-{field}={value!r}", "error" if field != "is_bigendian" else "any",
            lambda f=field, v=value: process(depth=setf(**{f: v})), "")  # fmt: skip
    add("ros/colour-data-short", "error", lambda: process(color=lambda m: setf(data=m.data[:-1])(m)))
    add("ros/colour-data-long", "any", lambda: process(color=lambda m: setf(data=m.data + b"\x00" * 9)(m)))
    add("ros/colour-data-empty", "error", lambda: process(color=setf(data=b"")))
    add("ros/colour-data-list", "any", lambda: process(color=lambda m: setf(data=list(m.data))(m)))
    add("ros/colour-data-text", "error", lambda: process(color=setf(data="abc")))
    add("ros/colour-data-none", "error", lambda: process(color=setf(data=None)))
    add("ros/depth-data-odd", "error", lambda: process(depth=lambda m: setf(data=m.data[:-1])(m)))
    add("ros/depth-step-padded", "any", lambda: process(depth=lambda m: padded(m, 64)))
    add("ros/colour-step-padded", "any", lambda: process(color=lambda m: padded(m, 3)))
    add("ros/depth-bigendian-really", "any",
        lambda: process(depth=lambda m: setf(
            is_bigendian=1, data=np.frombuffer(m.data, "<u2").byteswap().tobytes())(m)))  # fmt: skip
    # stamps: colour and depth far apart, in the future, negative, of the wrong type
    add("ros/stamps-apart-1h", "any", lambda: process(depth=setf(header=hdr(sec=3607))))
    add("ros/stamp-negative", "any", lambda: process(color=setf(header=hdr(sec=-5))))
    add("ros/stamp-nsec-over", "any", lambda: process(color=setf(header=hdr(nsec=2 * 10**9))))
    add("ros/stamp-text", "any", lambda: process(color=setf(header=hdr(sec="7"))))
    add("ros/stamp-huge", "any", lambda: process(color=setf(header=hdr(sec=10**30))))
    add("ros/header-none", "any", lambda: process(color=setf(header=None)))
    add("ros/frame-id-none", "any", lambda: process(color=setf(header=hdr(frame_id=None))))
    add("ros/frame-id-long", "any", lambda: process(color=setf(header=hdr(frame_id="x" * 100_000))))
    add("ros/frames-differ", "any", lambda: process(depth=setf(header=hdr(frame_id="camera_depth_optical_frame"))))
    # camera info
    for field, value in [("k", [1.0] * 8), ("k", [float("nan")] * 9), ("k", [[308, 0, 160], [0, 308, 119], [0, 0, 1]]),
                         ("k", None), ("k", "abc"), ("k", [0.0] * 9), ("d", [1e9] * 5), ("d", [0.0] * 10**6),
                         ("d", [float("nan")] * 5), ("distortion_model", "equidistant"), ("distortion_model", None),
                         ("width", 640), ("height", 10**12), ("width", -320)]:  # fmt: skip
        add(f"ros/info-{field}={value!r:.24}", "any" if field in ("d", "distortion_model") and value in (
            [1e9] * 5, "equidistant", None) else "error",
            lambda f=field, v=value: process(info=setf(**{f: v})), "")  # fmt: skip

    def fisheye_warned() -> str:
        import warnings

        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            process(info=setf(distortion_model="equidistant"))
        if not any("fisheye" in str(w.message) for w in said):
            raise AssertionError("a fisheye CameraInfo (d all 0) taken as pinhole without a word")
        return "warned"

    add("ros/info-fisheye-warned", "result", fisheye_warned)


def sync_cases() -> None:
    """The ROS 2 node's pairing of colour, depth and camera info by stamp (``ApproximateSync``, no ROS needed):
    stamps apart, missing, of text, NaN, huge, out of order, a flood; each case returns what was paired, and a
    pair of stamps beyond the slop, an exception or an unbounded queue raises."""
    from symfruit.io.bags import header_stamp
    from symfruit.ros.sync import ApproximateSync

    def msg(sec: Any, nanosec: Any = 0) -> SimpleNamespace:
        return SimpleNamespace(header=SimpleNamespace(stamp=SimpleNamespace(sec=sec, nanosec=nanosec)))

    def both(sec: Any) -> list[tuple[int, Any]]:
        """Depth and camera info (topics 1 and 2) stamped ``sec``."""
        return [(1, msg(sec)), (2, msg(sec))]

    def paired(feed: list[tuple[int, Any]], slop: float = 0.01, queue: int = 5) -> str:
        sets: list[tuple[Any, ...]] = []
        sync = ApproximateSync(3, lambda *m: sets.append(m), slop=slop, queue_size=queue)
        for topic, m in feed:
            sync.add(topic, m)
            if any(len(q) > queue for q in getattr(sync, "_queues", [])):
                raise AssertionError("a queue grew past queue_size")
        for members in sets:
            stamps = [header_stamp(m) * 1e-9 for m in members]
            if max(stamps) - min(stamps) > slop + 1e-9:
                raise AssertionError(f"paired stamps {stamps} beyond the slop {slop}")
        return f"{len(sets)} sets; late {sync.late}, unstamped {sync.unstamped}, resets {sync.resets}"

    add("sync/good", "result", lambda: paired([(t, msg(5)) for t in (0, 1, 2)]))
    add("sync/apart-1s", "result", lambda: paired([(0, msg(5)), (1, msg(6)), (2, msg(5))]))
    add("sync/apart-1h", "result", lambda: paired([(0, msg(5)), (1, msg(3605)), (2, msg(5))]))
    for bad in ("5", None, float("nan"), float("inf"), -5, 10**30, 2.5, [5]):
        add(f"sync/stamp-{bad!r}", "result",
            lambda b=bad: paired([(0, msg(b)), *both(5), (0, msg(6)), *both(6)]))  # fmt: skip
    add("sync/nanosec-over", "result", lambda: paired([(0, msg(5, 3 * 10**9)), (1, msg(8)), (2, msg(8))]))
    add("sync/no-header", "result", lambda: paired([(0, SimpleNamespace()), (1, msg(5)), (2, msg(5))]))
    add("sync/out-of-order", "result",
        lambda: paired([(0, msg(9)), *both(9), (0, msg(8)), *both(8)]))  # fmt: skip
    add("sync/clock-reset", "result",
        lambda: paired([(0, msg(9000)), *both(9000), (0, msg(1)), *both(1)]))  # fmt: skip
    add("sync/flood-one-topic", "result", lambda: paired([(0, msg(k)) for k in range(100_000)]))


def padded(m: SimpleNamespace, pad: int) -> SimpleNamespace:
    rows = np.frombuffer(m.data, np.uint8).reshape(m.height, m.step)
    wide = np.zeros((m.height, m.step + pad), np.uint8)
    wide[:, : m.step] = rows
    return SimpleNamespace(**{**vars(m), "step": m.step + pad, "data": wide.tobytes()})


# --- batches: an item that crashes -----------------------------------------------------------------------------
def batch_cases() -> None:
    """A bug inside one item (an exception of no kind of ours, a MemoryError, a RecursionError, a full disk's
    OSError) fails that item, reported in the summary and errors.json, and the batch goes on to the others (a
    full disk stops it, saying so). The case's value is what was found; a broken rule raises."""
    import symfruit.batch as batch

    def check(run: Run, exc: BaseException, items: int = 3) -> str:
        kept = [run.output / n for n in ("errors.json", "segment.json")] if run.output is not None else []
        record = next((json.loads(k.read_text()) for k in kept if k.is_file()), {})
        failed = record.get("failed", [])
        full = isinstance(exc, OSError) and exc.errno == 28
        if run.rc != 1 or len(failed) != 1:
            raise AssertionError(f"exit {run.rc}, {len(failed)} failed recorded: {run.err.strip()[-200:]!r}")
        reason = failed[0]["reason"]
        if (type(exc).__name__ not in reason and not full) or len(reason) > 300:
            raise AssertionError(f"the failed item's reason: {reason[:200]!r}")
        if full and "output is full" not in run.err:
            raise AssertionError(f"a full disk not said: {run.err.strip()[-200:]!r}")
        return f"1 of {items} failed ({reason[:60]}), the batch went on" + (", stopped: full" if full else "")

    crashes = (RuntimeError("boom"), MemoryError(), RecursionError("deep"), ZeroDivisionError("x"), KeyError("k"),
               OSError(28, "No space left on device"))  # fmt: skip
    for exc in crashes:

        def run(exc: BaseException = exc) -> str:
            rec = fixture(f"crash-{type(exc).__name__}")
            for n in ("a", "b", "c"):
                shutil.copytree(ROOT / "examples/realsense/aligned_00000", rec / n)
            real, calls = batch.detect, [0]

            def detect(*a: Any, **k: Any) -> Any:
                calls[0] += 1
                if calls[0] == 2:
                    raise exc
                return real(*a, **k)

            o = out(f"crash-{type(exc).__name__}")
            batch.detect = detect  # type: ignore[assignment]
            try:
                return check(cli("detect", rec, "--output", o, output=o), exc)
            finally:
                batch.detect = real  # type: ignore[assignment]

        add(f"batch/detect-item-raises-{type(exc).__name__}", "result", run, "")

    def seg(exc: BaseException) -> str:
        imgs = fixture(f"segcrash-{type(exc).__name__}")
        imgs.mkdir()
        for n in ("a", "b", "c"):
            shutil.copy(ROOT / "examples/realsense/aligned_00000/color.png", imgs / f"{n}.png")
        real, calls = batch._labeller, [0]

        def labeller(*a: Any, **k: Any) -> Any:
            inner, word = real(*a, **k)

            def go(*x: Any, **y: Any) -> Any:
                calls[0] += 1
                if calls[0] == 2:
                    raise exc
                return inner(*x, **y)

            return go, word

        o = out(f"segcrash-{type(exc).__name__}")
        batch._labeller = labeller  # type: ignore[assignment]
        try:
            return check(cli("segment", imgs, "--output", o, output=o), exc)
        finally:
            batch._labeller = real  # type: ignore[assignment]

    for exc in crashes:
        add(f"batch/segment-item-raises-{type(exc).__name__}", "result", lambda e=exc: seg(e), "")

    def jobs_worker_dies() -> str:
        """``evaluate --jobs 2`` whose worker dies (``os._exit``, as the OOM killer ends it) on one instance."""
        import symfruit.evaluate.runner as runner

        parent, real = os.getpid(), runner._evaluate

        def dies(spec: Any, methods: Any, settings: Any) -> Any:
            if spec.index == 3 and os.getpid() != parent:
                os._exit(9)
            return real(spec, methods, settings)

        o = out("jobs-dies")
        runner._evaluate = dies  # type: ignore[assignment]  # the workers are forked: they see it
        try:
            run = cli("evaluate", "--quick", "--methods", "raw", "--jobs", "2", "--output", o)
        finally:
            runner._evaluate = real  # type: ignore[assignment]
        if run.rc != 0:
            raise AssertionError(f"exit {run.rc}: {run.err.strip()[-200:]!r}")
        table = next(o.glob("*/instances.csv")).read_text().splitlines()
        died = [line for line in table if "worker process ended abruptly" in line]
        if not 0 < len(died) < len(table) - 1:
            raise AssertionError(f"{len(died)} rows of a dead worker among {len(table) - 1}")
        return f"{len(died)} of {len(table) - 1} rows (the instances numbered 3) say their worker died; the rest ran"

    add("batch/evaluate-jobs-worker-dies", "result", jobs_worker_dies)


# --- MCAP records --------------------------------------------------------------------------------------------
def mcap_cases() -> None:
    """A rosbag2 MCAP bag (3 frames) whose records claim sizes it cannot hold."""

    def good() -> Path:
        target = T() / "cases48/mcap-source"
        if not target.exists():
            sys.path.insert(0, str(ROOT))
            from tests.conftest import disc_frame
            from tests.io.test_bags import write_ros2_bag

            color, depth = disc_frame([(60, 60), (110, 60)], radius=15)
            write_ros2_bag(target, color, (depth * 1000).astype(np.uint16), frames=3, storage="mcap")
        return target

    def records(data: bytes) -> list[tuple[int, int, int]]:
        pos, found = 8, []
        while pos < len(data) - 8:
            op, n = data[pos], int.from_bytes(data[pos + 1 : pos + 9], "little")
            found.append((pos, op, n))
            if op == 0x02:
                break
            pos += 9 + n
        return found

    def case(name: str, expect: str, edit: Callable[[bytearray, list[tuple[int, int, int]]], None]) -> None:
        def run() -> Run:
            src = good()
            bag = fixture(f"mcap-{name}")
            shutil.copytree(src, bag)
            f = bag / "mcap-source.mcap"
            raw = bytearray(f.read_bytes())
            edit(raw, records(bytes(raw)))
            f.write_bytes(bytes(raw))
            return cli("detect", bag, "--output", out(f"mcap-{name}"))

        add(f"mcap/{name}", expect, run, f"mcap-{name}")

    def put(at: Callable[[list[tuple[int, int, int]]], int], value: int) -> Callable[[bytearray, Any], None]:
        def go(raw: bytearray, recs: list[tuple[int, int, int]]) -> None:
            struct.pack_into("<Q", raw, at(recs), value)

        return go

    def first(op: int) -> Callable[[list[tuple[int, int, int]]], int]:
        return lambda recs: next(r[0] for r in recs if r[1] == op)

    def index_end(recs: list[tuple[int, int, int]]) -> int:
        r = next(r for r in recs if r[1] == 0x08)
        return r[0] + 9 + r[2] - 8

    case("good", "result", lambda raw, recs: None)
    for value in (16 << 30, 2**63, 2**64 - 1):
        case(f"header-length-{value}", "error", put(lambda recs: 9, value))
        case(f"chunk-length-{value}", "error", put(lambda recs: first(0x06)(recs) + 1, value))
        case(f"chunk-unpacked-{value}", "error", put(lambda recs: first(0x06)(recs) + 9 + 16, value))
        case(f"index-unpacked-{value}", "error", put(index_end, value))
        case(f"index-packed-{value}", "error", put(lambda recs: index_end(recs) - 8, value))
        case(f"index-offset-{value}", "error", put(lambda recs: first(0x08)(recs) + 9 + 16, value))
        case(f"message-index-length-{value}", "error", put(lambda recs: first(0x07)(recs) + 1, value))
        case(f"summary-offset-{value}", "error", put(lambda recs: first(0x02)(recs) + 9, value))
    case("summary-offset-mid-record", "error", put(lambda recs: first(0x02)(recs) + 9, 44))
    case("chunk-packed-over-record", "error",
         lambda raw, recs: struct.pack_into("<Q", raw, first(0x06)(recs) + 9 + 32 + 4, 10**6))  # fmt: skip
    case("end-magic-only-cut", "error", lambda raw, recs: raw.__delitem__(slice(len(raw) // 2, len(raw) - 8)))


# --- writes killed half-way ------------------------------------------------------------------------------------
def killed_cases() -> None:
    """The command line in a child process, killed (SIGKILL) after a delay: no output file may be left
    partial under its own name (a ``.NAME.PID-TOKEN.tmp`` may stay; the next run clears it)."""
    env = {**os.environ, "PYTHONPATH": _src() + os.pathsep + os.environ.get("PYTHONPATH", "")}
    big = None

    def big_cloud() -> Path:
        nonlocal big
        if big is None:
            big = T() / "cases48/big.ply"
            from symfruit.io.clouds import write_ply

            rng = np.random.default_rng(0)
            d = rng.normal(size=(400_000, 3))
            d = 0.03 * d / np.linalg.norm(d, axis=1, keepdims=True) + [0, 0, 0.3]
            write_ply(big, d[d[:, 2] < 0.3])
        return big

    def whole(p: Path) -> str:
        """Why the file is partial, or '' when it is whole."""
        try:
            if p.suffix == ".json":
                json.loads(p.read_text())
            elif p.suffix == ".ply":
                from symfruit.io.clouds import read_cloud

                read_cloud(p)
            elif p.suffix == ".png":
                from PIL import Image

                with Image.open(p) as im:
                    im.load()
            elif p.suffix == ".parquet":
                import pyarrow.parquet as pq

                pq.read_table(p)
        except Exception as exc:
            return f"{type(exc).__name__}"
        return ""

    def clear(target: Path) -> None:
        if target.is_dir():
            shutil.rmtree(target)
        for q in target.parent.iterdir() if target.suffix else []:
            if q.is_file() and target.stem in q.name:
                q.unlink()

    def killed(argv: list[str], target: Path, shares: tuple[float, ...]) -> Any:
        """A whole run first (its wall time ``D``), then runs killed at ``share * D`` each."""
        clear(target)
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "symfruit", *argv], env=env, capture_output=True, check=True)
        whole_run = time.perf_counter() - start
        bad, whole_files, temporaries, absent = [], 0, 0, 0
        delays = [round(share * whole_run, 2) for share in shares]
        for delay in delays:
            clear(target)
            p = subprocess.Popen([sys.executable, "-m", "symfruit", *argv], env=env, stdout=subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL)  # fmt: skip
            time.sleep(delay)
            p.send_signal(signal.SIGKILL)
            p.wait()
            if target.suffix:
                files = [q for q in target.parent.iterdir() if q.is_file() and target.stem in q.name]
            else:
                files = [q for q in target.rglob("*") if q.is_file()] if target.exists() else []
            absent += not files
            for q in files:
                if q.name.endswith(".tmp"):
                    temporaries += 1
                elif why := whole(q):
                    bad.append(f"{q.relative_to(T())} partial after {delay} s ({why})")
                else:
                    whole_files += 1
        if bad:
            raise AssertionError("; ".join(bad[:3]))
        return (f"a whole run {whole_run:.1f} s; {len(delays)} kills at {min(delays)}-{max(delays)} s: "
                f"{whole_files} whole files, {temporaries} temporaries left, {absent} kills before any file; "
                "no partial file")  # fmt: skip

    out_ply = T() / "cases48/killed/out.ply"
    out_ply.parent.mkdir(parents=True, exist_ok=True)
    add("killed/complete-output", "result",
        lambda: killed(["complete", str(big_cloud()), "--method", "sphere", "--output", str(out_ply)], out_ply,
                       (0.5, 0.8, 0.9, 0.95, 0.98, 0.99)))  # fmt: skip

    def recording() -> Path:
        rec = T() / "cases48/killed-rec"
        if not rec.exists():
            for n in range(6):
                shutil.copytree(ROOT / "examples/realsense/aligned_00000", rec / f"f{n}")
        return rec

    o = T() / "cases48/killed/detect"
    add("killed/detect-recording", "result",
        lambda: killed(["detect", str(recording()), "--output", str(o)], o, (0.4, 0.6, 0.75, 0.9, 0.97)))  # fmt: skip


# --- memory over a long recording ----------------------------------------------------------------------------
def memory_cases() -> None:
    """``bench --recording N`` (``detect`` over a generated N-frame recording, in a child process: its peak
    resident memory) at 4 and 24 frames: the peak may not grow with the recording (at most 10 %)."""
    env = {**os.environ, "PYTHONPATH": _src() + os.pathsep + os.environ.get("PYTHONPATH", "")}

    def peak(n: int) -> float:
        done = subprocess.run([sys.executable, "-m", "symfruit", "bench", "--recording", str(n)], env=env,
                              capture_output=True, text=True, check=True)  # fmt: skip
        return float(re.search(r"peak RSS (\d+(?:\.\d+)?) MB", done.stdout).group(1))  # type: ignore[union-attr]

    def flat() -> str:
        short, long = peak(4), peak(24)
        if long > 1.10 * short:
            raise AssertionError(f"peak RSS {short:.0f} MB over 4 frames, {long:.0f} MB over 24")
        return f"peak RSS {short:.0f} MB over 4 frames, {long:.0f} MB over 24"

    add("memory/recording-4-vs-24", "result", flat)


# --- running ---
#: Words of Python or a codec the robust47 classifier lets through, read in its output in stop 48.
_PYTHON_SPEAK = re.compile(r"codec can't|NoneType|\bnot a [aeiou]\w+ file\b|\bposition \d+: invalid")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default="", help="the cases whose name holds one of these (comma-separated)")
    parser.add_argument("--defects", action="store_true", help="print the defects alone")
    parser.add_argument("--keep", type=Path, help="make or reuse the fixtures in this folder (robust47's too)")
    args = parser.parse_args()
    import symfruit

    r47.T = args.keep.resolve() if args.keep else Path(tempfile.mkdtemp(prefix="robust48-"))
    r47.T.mkdir(parents=True, exist_ok=True)
    base = r47.T / "base"
    if not (base / "f640").exists():
        shutil.copytree(ROOT / "examples/realsense/aligned_00000", base / "f640")
    for build in (
        file_cases,
        output_cases,
        camera_cases,
        bomb_cases,
        ros_cases,
        sync_cases,
        batch_cases,
        mcap_cases,
        killed_cases,
        memory_cases,
    ):
        build()
    signal.signal(signal.SIGALRM, r47._alarm)
    counts = {"error": 0, "failed": 0, "result": 0, "DEFECT": 0}
    for name, expect, fn, names in CASES:
        if not any(part in name for part in args.only.split(",")):
            continue
        signal.alarm(LIMIT_S)
        try:
            value = fn()
            signal.alarm(0)
            kind, text = r47.judge(value, expect, names)
            if isinstance(value, str):
                text = value
        except symfruit.SymfruitError as exc:
            signal.alarm(0)
            msg = str(exc).replace(str(r47.T), "T")
            if expect == "result":
                kind, text = "DEFECT", f"refused what it should take: {msg[:150]}"
            elif len(msg) > 300:
                kind, text = "DEFECT", f"message of {len(msg)} characters: {msg[:150]}"
            elif r47._FOREIGN.search(msg):
                kind, text = "DEFECT", f"another library's words: {msg[:150]}"
            else:
                kind, text = "error", msg[:150]
        except r47.Hang:
            kind, text = "DEFECT", f"hang (over {LIMIT_S} s)"
        except Exception as exc:  # the point of the sweep
            signal.alarm(0)
            kind, text = "DEFECT", r47.origin(exc)
        if kind != "DEFECT" and (said := _PYTHON_SPEAK.search(text)):
            kind, text = "DEFECT", f"Python's words ({said.group(0)!r}): {text[:150]}"
        counts[kind] += 1
        if kind == "DEFECT" or not args.defects:
            sys.stdout.write(f"{kind:6} {name:48} {text}\n")
            sys.stdout.flush()
    sys.stdout.write(f"# {sum(counts.values())} cases: {counts['error']} clear errors, {counts['failed']} failed items "
                     f"reported, {counts['result']} results, {counts['DEFECT']} defects\n")  # fmt: skip
    if not args.keep:
        shutil.rmtree(r47.T, ignore_errors=True)
    return 1 if counts["DEFECT"] else 0


if __name__ == "__main__":
    sys.exit(main())
