"""Stop 47: bad and adversarial input at the command line and the readers, for what stops 44-46 added and what
real frames bring (1920x1080 frames, depth all zero / NaN / 65535, depth of every kind, masks of one pixel or
touching every border, 255 instances, huge labels, absurd intrinsics, truncated files, settings of wrong types,
unknown keys, folders for files, outputs that cannot be written).

Each case runs ``symfruit.cli.main(argv)`` (or one library call) in this process under an alarm and is classified:

- ``error``: the command refused it in one line ``symfruit: error: ...`` (exit 2, or argparse's usage error);
- ``failed``: a batch recorded the item as failed with a reason of symfruit's own words and went on (exit 1);
- ``result``: it ran (exit 0); a case that expects an error and gets a result is a defect (``wrong silent result``);
- ``DEFECT``: an exception out of ``main``, a hang, a line over 300 characters (the case's folder shown as ``T``),
  a reason in another library's words (``TypeError: ...``), an error where a result was expected, or a message
  that does not name the file the case damaged.

::

    PYTHONPATH=src python docs/robust47.py            # every case (fixtures made in a temporary folder)
    PYTHONPATH=src python docs/robust47.py --only settings/ --defects

``--keep DIR`` makes (or reuses) the fixtures in DIR: the two rendered 1920x1080 frames take a minute.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import io
import json
import re
import shutil
import signal
import sys
import tempfile
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
LIMIT_S = 300
CASES: list[tuple[str, str, Callable[[], Any], str]] = []  # name, expect, call, a text the message must hold
T: Path = Path()  # the fixtures' folder


class Hang(Exception):
    pass


def _alarm(signum: int, frame: Any) -> None:
    raise Hang


@dataclasses.dataclass
class Run:
    rc: int
    out: str
    err: str
    output: Path | None


def cli(*argv: Any, output: Path | None = None) -> Run:
    from symfruit.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main([str(a) for a in argv])
        except SystemExit as exc:  # argparse
            rc = int(exc.code or 0)
    return Run(rc, out.getvalue(), err.getvalue(), output)


def add(name: str, expect: str, fn: Callable[[], Any], names: str = "") -> None:
    CASES.append((name, expect, fn, names))


# --- fixtures --------------------------------------------------------------------------------------------------
def png(path: Path, array: np.ndarray) -> None:
    from PIL import Image

    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(array).save(path)


def frame_copy(base: Path, name: str) -> Path:
    target = T / "cases" / name / "frame"
    if target.exists():
        shutil.rmtree(target)
    shutil.copytree(base, target)
    return target


def out_dir(name: str) -> Path:
    target = T / "out" / name
    if target.exists():
        shutil.rmtree(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    return target


def make_fixtures() -> None:
    """The 640x480 RealSense frame (examples/realsense/aligned_00000), a rendered 1920x1080 strawberry frame
    through the Azure Kinect model (fruit ~200 px at 0.25 m) and an apple-tree frame (fruit ~40 px at 2 m)."""
    from symfruit.synthetic.scenes import write_scenes
    from symfruit.synthetic.sensors import sensor_model

    base = T / "base"
    if not (base / "f640").exists():
        shutil.copytree(ROOT / "examples/realsense/aligned_00000", base / "f640")
    if not (base / "ak").exists():
        write_scenes(base / "ak_tmp", 1, seed=0, sensor=sensor_model("azure-kinect"))
        next((base / "ak_tmp").iterdir()).rename(base / "ak")
    if not (base / "tree").exists():
        write_scenes(base / "tree_tmp", 1, seed=0, sensor=sensor_model("azure-kinect"), tree=True)
        next((base / "tree_tmp").iterdir()).rename(base / "tree")


def B(name: str) -> Path:
    return T / "base" / name


# --- detect on frame folders -----------------------------------------------------------------------------------
def detect_case(name: str, expect: str, base: str, mutate: Callable[[Path], Any] | None, *extra: Any,
                names: str = "") -> None:  # fmt: skip
    def run() -> Run:
        f = frame_copy(B(base), name.replace("/", "_"))
        if mutate is not None:
            mutate(f)
        out = out_dir(name.replace("/", "_"))
        return cli("detect", f, "--output", out, *extra, output=out)

    add(f"detect/{name}", expect, run, names)


def depth_of(f: Path) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(f / "depth.png"))


def set_depth_png(value: Any) -> Callable[[Path], None]:
    def go(f: Path) -> None:
        d = depth_of(f)
        png(f / "depth.png", np.full(d.shape, value, np.uint16))

    return go


def depth_npy(make: Callable[[np.ndarray], np.ndarray]) -> Callable[[Path], None]:
    def go(f: Path) -> None:
        scale = json.loads((f / "camera.json").read_text()).get("depth_scale", 0.001)
        d = depth_of(f).astype(np.float64) * scale
        (f / "depth.png").unlink()
        np.save(f / "depth.npy", make(d))

    return go


def camera_edit(**kw: Any) -> Callable[[Path], None]:
    def go(f: Path) -> None:
        data = json.loads((f / "camera.json").read_text())
        data.update(kw)
        (f / "camera.json").write_text(json.dumps(data))

    return go


def camera_text(text: str) -> Callable[[Path], None]:
    return lambda f: (f / "camera.json").write_text(text)


def truncate(file: str, share: float = 0.5) -> Callable[[Path], None]:
    def go(f: Path) -> None:
        data = (f / file).read_bytes()
        (f / file).write_bytes(data[: int(len(data) * share)])

    return go


def corrupt(file: str, at: float = 0.3, n: int = 64) -> Callable[[Path], None]:
    def go(f: Path) -> None:
        data = bytearray((f / file).read_bytes())
        k = int(len(data) * at)
        data[k : k + n] = np.random.default_rng(0).integers(0, 256, n, dtype=np.uint8).tobytes()
        (f / file).write_bytes(bytes(data))

    return go


def to_folder(file: str) -> Callable[[Path], None]:
    def go(f: Path) -> None:
        (f / file).unlink()
        (f / file).mkdir()

    return go


def masks_png(make: Callable[[int, int], np.ndarray]) -> Callable[[Path], None]:
    def go(f: Path) -> None:
        h, w = depth_of(f).shape
        for old in ("masks.png", "masks.json"):
            (f / old).unlink(missing_ok=True)
        png(f / "masks.png", make(h, w))

    return go


def one_pixel(h: int, w: int) -> np.ndarray:
    m = np.zeros((h, w), np.uint8)
    m[h // 2, w // 2] = 1
    return m


def every_border(h: int, w: int) -> np.ndarray:
    m = np.zeros((h, w), np.uint8)
    m[h // 2 - 20 : h // 2 + 20, :] = 1
    m[:, w // 2 - 20 : w // 2 + 20] = 1
    return m


def grid(n: int, dtype: Any = np.uint8) -> Callable[[int, int], np.ndarray]:
    def make(h: int, w: int) -> np.ndarray:
        m = np.zeros((h, w), dtype)
        side = int(np.ceil(np.sqrt(n)))
        ch, cw = h // side, w // side
        for k in range(n):
            r, c = divmod(k, side)
            m[r * ch + 2 : (r + 1) * ch - 2, c * cw + 2 : (c + 1) * cw - 2] = k + 1
        return m

    return make


def huge_label(h: int, w: int) -> np.ndarray:
    m = np.zeros((h, w), np.uint16)
    m[h // 3 : h // 2, w // 3 : w // 2] = 65535
    return m


def color_resized(w: int, h: int) -> Callable[[Path], None]:
    def go(f: Path) -> None:
        from PIL import Image

        with Image.open(f / "color.png") as img:
            img.convert("RGB").resize((w, h)).save(f / "color.png")

    return go


def detect_cases() -> None:
    for base in ("f640", "ak", "tree"):
        detect_case(f"{base}/good", "result", base, None)
        detect_case(f"{base}/depth-png-8bit", "error", base,
                    lambda f: png(f / "depth.png", (depth_of(f) // 8).astype(np.uint8)), names="depth.png")  # fmt: skip
        detect_case(f"{base}/color-other-size", "error", base, color_resized(1280, 720))
        detect_case(f"{base}/depth-png-all-zero", "error", base, set_depth_png(0))
        detect_case(f"{base}/depth-png-all-65535", "error", base, set_depth_png(65535), names="")
        detect_case(f"{base}/depth-npy-all-nan", "error", base, depth_npy(lambda d: np.full(d.shape, np.nan, "f4")))
        detect_case(f"{base}/depth-npy-all-zero", "error", base, depth_npy(lambda d: np.zeros(d.shape, "f4")))
        detect_case(f"{base}/depth-npy-float32", "result", base, depth_npy(lambda d: d.astype("f4")))
        detect_case(f"{base}/mask-one-pixel", "any", base, masks_png(one_pixel))
        detect_case(f"{base}/mask-every-border", "any", base, masks_png(every_border))
        detect_case(f"{base}/masks-255", "any", base, masks_png(grid(255)))
        detect_case(f"{base}/label-65535", "any", base, masks_png(huge_label))
    b = "f640"
    detect_case("f640/depth-npy-float64", "result", b, depth_npy(lambda d: d))
    detect_case("f640/depth-npy-float16", "any", b, depth_npy(lambda d: d.astype("f2")))
    detect_case(
        "f640/depth-npy-uint16", "error", b, depth_npy(lambda d: (d * 1000).astype(np.uint16)), names="depth.npy"
    )
    detect_case("f640/depth-npy-mm-float", "error", b, depth_npy(lambda d: (d * 1000).astype("f4")))
    detect_case("f640/depth-npy-3d", "error", b, depth_npy(lambda d: d[..., None].astype("f4")), names="depth.npy")
    detect_case("f640/depth-npy-inf", "error", b, depth_npy(lambda d: np.full(d.shape, np.inf, "f4")))
    detect_case("f640/depth-npy-neg", "any", b, depth_npy(lambda d: -d.astype("f4")))
    detect_case("f640/depth-npy-object", "error", b, depth_npy(lambda d: d.astype(object)), names="depth.npy")
    detect_case("f640/depth-npy-truncated", "error", b,
                lambda f: (depth_npy(lambda d: d.astype("f4"))(f), truncate("depth.npy")(f)),
                names="depth.npy")  # fmt: skip
    detect_case("f640/depth-png-8bit", "error", b,
                lambda f: png(f / "depth.png", (depth_of(f) // 8).astype(np.uint8)), names="depth.png")  # fmt: skip
    detect_case("f640/depth-png-rgb", "error", b,
                lambda f: png(f / "depth.png", np.zeros((*depth_of(f).shape, 3), np.uint8)),
                names="depth.png")  # fmt: skip
    detect_case("f640/depth-png-float-tiff-named-png", "error", b,
                lambda f: __import__("PIL.Image").Image.fromarray(depth_of(f).astype("f4") / 1000).save(
                    f / "depth.png", format="TIFF"), names="depth.png")  # fmt: skip
    detect_case("f640/depth-tiff-only", "error", b,
                lambda f: (f / "depth.png").rename(f / "depth.tiff"), names="depth")  # fmt: skip
    detect_case("f640/depth-png-truncated", "error", b, truncate("depth.png"), names="depth.png")
    detect_case("f640/depth-png-corrupt", "error", b, corrupt("depth.png"), names="depth.png")
    detect_case("f640/depth-png-empty", "error", b, truncate("depth.png", 0.0), names="depth.png")
    detect_case("f640/depth-png-folder", "error", b, to_folder("depth.png"), names="depth.png")
    detect_case("f640/depth-smaller", "error", b,
                lambda f: png(f / "depth.png", depth_of(f)[::2, ::2].copy()), names="")  # fmt: skip
    detect_case("f640/color-1920x1080", "error", b, color_resized(1920, 1080), names="")
    detect_case("f640/color-640x480", "error", b, color_resized(640, 480), names="")
    detect_case("f640/color-truncated", "error", b, truncate("color.png"), names="color.png")
    detect_case("f640/color-corrupt", "error", b, corrupt("color.png", 0.5), names="color.png")
    detect_case("f640/color-folder", "error", b, to_folder("color.png"), names="color.png")
    detect_case("f640/color-empty", "error", b, truncate("color.png", 0.0), names="color.png")
    detect_case("f640/color-grey", "any", b,
                lambda f: png(f / "color.png", np.full(depth_of(f).shape, 128, np.uint8)))  # fmt: skip
    for key, value in [("fx", 0), ("fx", -615), ("fx", 1e9), ("fx", 1e-3), ("fy", 1e30), ("cx", -1e6),
                       ("cy", 1e12), ("width", 1920), ("height", 0), ("width", 2**40), ("depth_scale", 0),
                       ("depth_scale", -0.001), ("depth_scale", 1e6), ("depth_scale", 1e-9), ("depth_scale", "mm"),
                       ("fx", "615"), ("fx", None), ("fx", [615]), ("fx", True)]:  # fmt: skip
        detect_case(f"f640/camera-{key}={value}", "error", b, camera_edit(**{key: value}), names="camera.json")
    detect_case("f640/camera-fx-nan", "error", b,
                lambda f: (f / "camera.json").write_text((f / "camera.json").read_text().replace(
                    '"fx": ', '"fx": NaN, "_fx": ', 1)), names="camera.json")  # fmt: skip
    detect_case("f640/camera-fx-inf", "error", b,
                lambda f: (f / "camera.json").write_text((f / "camera.json").read_text().replace(
                    '"fx": ', '"fx": Infinity, "_fx": ', 1)), names="camera.json")  # fmt: skip
    detect_case("f640/camera-truncated", "error", b, truncate("camera.json"), names="camera.json")
    detect_case("f640/camera-empty", "error", b, truncate("camera.json", 0.0), names="camera.json")
    detect_case("f640/camera-list", "error", b, camera_text("[1, 2, 3]"), names="camera.json")
    detect_case("f640/camera-binary", "error", b, camera_text("\x00\x01\xff" * 50), names="camera.json")
    detect_case("f640/camera-folder", "error", b, to_folder("camera.json"), names="camera.json")
    detect_case("f640/camera-yaml-broken", "error", b,
                lambda f: ((f / "camera.json").unlink(), (f / "camera.yaml").write_text("fx: [615\n  fy: :")),
                names="camera.yaml")  # fmt: skip
    detect_case("f640/truth-truncated", "error", b, truncate("truth.json"), names="truth.json")
    detect_case("f640/truth-folder", "error", b, to_folder("truth.json"), names="truth.json")
    detect_case("f640/masks-png-truncated", "error", b,
                lambda f: (masks_png(grid(4))(f), truncate("masks.png")(f)), names="masks.png")  # fmt: skip
    detect_case("f640/masks-png-other-size", "error", b,
                lambda f: png(f / "masks.png", grid(4)(120, 160)), names="masks.png")  # fmt: skip
    detect_case("f640/masks-png-folder", "error", b,
                lambda f: (f / "masks.png").mkdir(), names="masks.png")  # fmt: skip
    detect_case("f640/masks-json-truncated", "error", b,
                lambda f: (f / "masks.json").write_text('{"annotations": [{"segmentation": [[1, 2'),
                names="masks.json")  # fmt: skip
    detect_case("f640/masks-whole", "error", b, masks_png(lambda h, w: np.ones((h, w), np.uint8)), names="")
    detect_case("f640/masks-empty", "any", b, masks_png(lambda h, w: np.zeros((h, w), np.uint8)))
    # options
    detect_case("f640/config-folder", "error", b, None, "--config", T, names=str(T))
    detect_case("f640/config-truncated-yaml", "error", b, None, "--config", T / "settings/truncated.yaml",
                names="truncated.yaml")  # fmt: skip
    detect_case("f640/config-hidden-front-3", "error", b, None, "--config", T / "settings/hidden3.yaml",
                names="hidden_front")  # fmt: skip
    detect_case("f640/config-unknown-key", "error", b, None, "--config", T / "settings/unknown.yaml",
                names="tilt_bend")  # fmt: skip
    detect_case("f640/fruit-missing", "error", b, None, "--fruit", "kiwi", names="kiwi")
    detect_case("f640/fruit-folder", "error", b, None, "--fruit", T, names="")
    detect_case("f640/masks-folder", "error", b, None, "--masks", T / "cases", names="")
    detect_case("f640/masks-maskrcnn-missing", "error", b, None, "--masks", "maskrcnn:/nonexistent.pth")  # fmt: skip
    detect_case("f640/masks-onnx-folder", "error", b, None, "--masks", f"onnx:{T}", names="")
    detect_case("f640/masks-onnx-garbage", "error", b, None, "--masks", f"onnx:{T / 'settings/truncated.yaml'}",
                names="truncated.yaml")  # fmt: skip
    detect_case("f640/method-unknown", "error", b, None, "--method", "evidense", names="evidense")
    detect_case("f640/chunk-0", "error", b, None, "--workers", "1", "--chunk", "0", names="chunk")
    detect_case("f640/workers-0", "error", b, None, "--workers", "0", names="workers")

    def out_is_file() -> Run:
        f = frame_copy(B("f640"), "out-file")
        (T / "out").mkdir(exist_ok=True)
        target = T / "out/a-file"
        target.write_text("x")
        return cli("detect", f, "--output", target)

    add("detect/output-is-a-file", "error", out_is_file, "a-file")

    def out_under_file() -> Run:
        f = frame_copy(B("f640"), "out-under-file")
        (T / "out").mkdir(exist_ok=True)
        (T / "out/b-file").write_text("x")
        return cli("detect", f, "--output", T / "out/b-file/sub")

    add("detect/output-under-a-file", "error", out_under_file, "b-file")
    add("detect/output-proc", "error", lambda: cli("detect", B("f640"), "--output", "/proc/symfruit47"), "/proc")
    add("detect/output-is-input", "error", lambda: cli("detect", B("f640"), "--output", B("f640")), "")

    def batch_with_bad() -> Run:
        rec = T / "cases/batch"
        if rec.exists():
            shutil.rmtree(rec)
        shutil.copytree(B("f640"), rec / "a_good")
        shutil.copytree(B("f640"), rec / "b_bad")
        truncate("depth.png")(rec / "b_bad")
        shutil.copytree(B("f640"), rec / "c_good")
        set_depth_png(0)(rec / "c_good")
        shutil.copytree(B("f640"), rec / "d_good")
        out = out_dir("batch")
        return cli("detect", rec, "--output", out, output=out)

    add("detect/batch-goes-on", "failed", batch_with_bad, "b_bad")


# --- bags ------------------------------------------------------------------------------------------------------
def bag_cases() -> None:
    bag = ROOT / "examples/realsense/fruit.bag"

    def bag_case(name: str, expect: str, make: Callable[[Path], None]) -> None:
        def run() -> Run:
            target = T / "cases" / "bags" / f"{name}.bag"
            target.parent.mkdir(parents=True, exist_ok=True)
            if target.is_dir():
                shutil.rmtree(target)
            make(target)
            return cli("detect", target, "--output", out_dir(f"bag-{name}"), output=T / "out" / f"bag-{name}")

        add(f"bag/{name}", expect, run, f"{name}.bag")

    data = bag.read_bytes()
    bag_case("good", "result", lambda p: p.write_bytes(data))
    for share in (0.05, 0.3, 0.6, 0.95):
        bag_case(f"cut-{share}", "any", lambda p, s=share: p.write_bytes(data[: int(len(data) * s)]))
    bag_case("empty", "error", lambda p: p.write_bytes(b""))
    bag_case("header-only", "error", lambda p: p.write_bytes(data[:13]))
    bag_case("garbage", "error", lambda p: p.write_bytes(np.random.default_rng(1).bytes(100_000)))
    for k, at in enumerate((0.1, 0.5, 0.8)):
        bag_case(f"flipped-{k}", "any", lambda p, a=at: (p.write_bytes(data), corrupt(p.name, a, 256)(p.parent)))
    bag_case("folder", "error", lambda p: p.mkdir())
    bag_case("text", "error", lambda p: p.write_text("#ROSBAG V2.0\nnot a bag at all\n"))

    def ros2_case(name: str, make: Callable[[Path], None]) -> None:
        def run() -> Run:
            target = T / "cases" / "ros2" / name
            if target.exists():
                shutil.rmtree(target)
            target.mkdir(parents=True)
            make(target)
            return cli("detect", target, "--output", out_dir(f"ros2-{name}"))

        add(f"ros2/{name}", "error", run, name)

    ros2_case("metadata-truncated", lambda p: ((p / "metadata.yaml").write_text(
        "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  relative_file_paths: [a"),
        (p / "a.mcap").write_bytes(b"\x89MCAP0\r\n")))  # fmt: skip
    ros2_case("metadata-huge-count", lambda p: ((p / "metadata.yaml").write_text(
        "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  relative_file_paths: [a.mcap]\n"
        "  message_count: 100000000000000000000\n  topics_with_message_count: []\n  duration: {nanoseconds: 1}\n"
        "  starting_time: {nanoseconds_since_epoch: 0}\n"), (p / "a.mcap").write_bytes(b"\x89MCAP0\r\n")))  # fmt: skip
    ros2_case("mcap-garbage", lambda p: ((p / "metadata.yaml").write_text(
        "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  relative_file_paths: [a.mcap]\n"
        "  message_count: 1\n  topics_with_message_count: []\n  duration: {nanoseconds: 1}\n"
        "  starting_time: {nanoseconds_since_epoch: 0}\n"),
        (p / "a.mcap").write_bytes(b"\x89MCAP0\r\n" + b"\x01" * 999)))  # fmt: skip

    def sdk(cut: float) -> Any:
        from symfruit.io.realsense import sdk_aligned

        target = T / "cases/bags" / f"sdk-{cut}.bag"
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data[: int(len(data) * cut)])
        return list(sdk_aligned(target, timeout_ms=2000, attempts=2))

    for cut in (0.0, 0.3, 1.0):
        add(f"sdk/aligned-cut-{cut}", "result" if cut == 1.0 else "error", lambda c=cut: sdk(c), "sdk-")


# --- complete, clouds ------------------------------------------------------------------------------------------
def complete_cases() -> None:
    ply = ROOT / "examples/strawberry_partial.ply"
    data = ply.read_bytes()
    d = T / "cases/clouds"
    d.mkdir(parents=True, exist_ok=True)

    def cloud(name: str, content: bytes | str | None, *extra: Any, expect: str = "error", names: str = "") -> None:
        def run() -> Run:
            target = d / name
            if content is None:
                target.mkdir(exist_ok=True)
            else:
                target.write_bytes(content if isinstance(content, bytes) else content.encode())
            return cli("complete", target, *extra)

        add(f"complete/{name}", expect, run, names if names else name)

    cloud("good.ply", data, expect="result")
    for share in (0.0, 0.1, 0.5, 0.99):
        cloud(f"cut-{share}.ply", data[: int(len(data) * share)])
    head = data.split(b"end_header\n")[0].decode("latin-1")
    cloud("count-huge.ply", re.sub(r"element vertex \d+", "element vertex 4000000000", head) + "end_header\n")
    cloud("count-neg.ply", re.sub(r"element vertex \d+", "element vertex -5", head) + "end_header\n")
    cloud("prop-list.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty list uchar float x\nend_header\n"
          "1 0.1\n1 0.2\n")  # fmt: skip
    cloud("no-xyz.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float a\nend_header\n0.1\n0.2\n")
    cloud("nan.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z"
          "\nend_header\nnan nan nan\nnan nan nan\nnan nan nan\n")  # fmt: skip
    cloud("folder.ply", None)
    cloud("garbage.pcd", np.random.default_rng(2).bytes(5000))
    cloud("garbage.npy", b"\x93NUMPY\x01\x00" + np.random.default_rng(3).bytes(500))
    cloud("text.xyz", "a b c\nd e f\n")
    cloud("mixed.csv", "x,y,z\n0.1,0.2,0.3\n0.1,zz,0.3\n")
    cloud("huge-values.xyz", "\n".join("1e308 1e308 1e308" for _ in range(50)) + "\n")
    cloud("unknown.obj", "v 0 0 0\n")
    cloud("no-suffix", "0 0 0.3\n")
    good = d / "good2.ply"
    good.write_bytes(data)
    for name, extra, names in [("camera-folder", ("--camera", T), str(T)),
                               ("camera-nan", ("--camera", T / "settings/camera-nan.json"), "camera-nan.json"),
                               ("camera-truncated", ("--camera", T / "settings/truncated.yaml"), "truncated.yaml"),
                               ("camera-missing", ("--camera", T / "nope.json"), "nope.json"),
                               ("config-folder", ("--config", T), str(T)),
                               ("output-in-missing-folder", ("--output", T / "nope/x/out"), ""),
                               ("output-is-folder", ("--output", T), ""),
                               ("output-under-file", ("--output", good / "out"), "good2.ply"),
                               ("fruit-folder", ("--fruit", T), ""),
                               ("fruit-truncated", ("--fruit", T / "settings/truncated.yaml"), "truncated.yaml"),
                               ("method-unknown", ("--method", "mirrror"), "mirrror")]:  # fmt: skip
        add(f"complete/{name}", "any" if name.startswith("output-in-missing") else "error",
            lambda extra=extra: cli("complete", good, *extra), names)  # fmt: skip


# --- settings --------------------------------------------------------------------------------------------------
SETTING_VALUES: list[tuple[str, str]] = [
    ("text", "'eleven'"),
    ("nan", ".nan"),
    ("inf", ".inf"),
    ("neg", "-1"),
    ("huge", "1.0e300"),
    ("bigint", "100000000000000000000"),
    ("bool", "true"),
    ("list", "[1, 2]"),
    ("map", "{a: 1}"),
    ("null", "null"),
]


def settings_cases() -> None:
    from symfruit.settings import section_types

    d = T / "settings"
    d.mkdir(parents=True, exist_ok=True)
    (d / "truncated.yaml").write_text("evidence:\n  hidden_front: 'sph")
    (d / "hidden3.yaml").write_text("evidence:\n  hidden_front: 3\n")
    (d / "unknown.yaml").write_text("evidence:\n  tilt_bends: true\n")
    (d / "camera-nan.json").write_text('{"fx": NaN, "fy": 615, "cx": 320, "cy": 240, "width": 640, "height": 480}')
    for name, cls in section_types().items():
        for f in dataclasses.fields(cls):
            if dataclasses.is_dataclass(f.default_factory() if callable(f.default_factory) else f.default):
                continue
            default = f.default
            for label, text in SETTING_VALUES:
                if (label == "null" and "None" in str(f.type)) or (label == "bool" and isinstance(default, bool)):
                    continue  # what the field takes
                if label == "neg" and isinstance(default, float) and f.metadata["bounds"].get("ge", 0) < 0:
                    continue
                if label in ("neg", "huge", "bigint", "nan", "inf") and isinstance(default, str):
                    continue  # the choice's text: the "text" case covers it
                path = d / f"{name}.{f.name}.{label}.yaml"
                path.write_text(f"{name}:\n  {f.name}: {text}\n")
                add(f"settings/{name}.{f.name}={label}", "error", lambda p=path: cli("settings", "--config", p),
                    f"{name}.{f.name}")  # fmt: skip
        # a misspelt key: the message names it and the nearby valid names, in one short line
        for k, f in enumerate(dataclasses.fields(cls)):
            wrong = f.name[:-1] if len(f.name) > 4 else f.name + "s"
            path = d / f"{name}.mis{k}.yaml"  # a short name: the line's length is the message's
            path.write_text(f"{name}:\n  {wrong}: 1\n")
            add(f"settings/{name}.{wrong}=unknown", "error", lambda p=path: cli("settings", "--config", p),
                f.name)  # fmt: skip
    for label, text in [("empty", ""), ("comments", "# nothing\n"), ("list", "- 1\n"), ("tabs", "\tevidence: 1\n"),
                        ("alias-bomb", "a: &a [1,1,1,1,1,1,1,1,1]\nb: &b [*a,*a,*a,*a,*a,*a,*a,*a,*a]\n"
                         "c: &c [*b,*b,*b,*b,*b,*b,*b,*b,*b]\nd: &d [*c,*c,*c,*c,*c,*c,*c,*c,*c]\n"
                         "e: [*d,*d,*d,*d,*d,*d,*d,*d,*d]\n"),
                        ("binary", "\x00\xff\xfe"), ("section-number", "evidence: 3\n"),
                        ("python-tag", "evidence: !!python/object/apply:os.system ['true']\n"),
                        ("dup-key", "evidence:\n  tilt_bend: true\n  tilt_bend: false\n")]:  # fmt: skip
        path = d / f"file-{label}.yaml"
        path.write_bytes(text.encode("latin-1"))
        add(f"settings/file-{label}", "error", lambda p=path: cli("settings", "--config", p), path.name)
    add("settings/config-folder", "error", lambda: cli("settings", "--config", d), str(d))
    add("settings/config-missing", "error", lambda: cli("settings", "--config", d / "nope.yaml"), "nope.yaml")
    add("settings/config-suffix", "error", lambda: cli("settings", "--config", ROOT / "README.md"), "README.md")
    add("settings/fruit-unknown", "error", lambda: cli("settings", "--fruit", "kiwi"), "kiwi")
    add("settings/fruit-folder", "error", lambda: cli("settings", "--fruit", d), "")
    # the largest value each bound allows, used: complete() on the shipped partial strawberry (an allocation of
    # a setting's size would be a MemoryError or a hang here)
    for name, cls in section_types().items():
        for f in dataclasses.fields(cls):
            b = f.metadata.get("bounds", {})
            hi = b.get("le", b.get("lt"))
            if f.type not in ("int", "int | None") or hi is None or name in ("segment", "extract", "occlusion"):
                continue
            method = {"paper": "paper", "evidence": "evidence", "fused": "fused", "superellipsoid":
                      "superellipsoid", "input": "evidence"}.get(name)  # fmt: skip
            if method is None:
                continue
            add(f"use/{name}.{f.name}={hi:g}", "any",
                lambda n=name, k=f.name, v=int(hi), m=method: use_setting(n, k, v, m), "")  # fmt: skip


def use_setting(section: str, key: str, value: int, method: str) -> Any:
    import symfruit
    from symfruit.io.clouds import read_cloud

    pts = read_cloud(ROOT / "examples/strawberry_partial.ply")
    pts = getattr(pts, "points", pts)
    return symfruit.complete(np.asarray(pts), method=method,
                             settings=symfruit.resolve_settings(overrides={section: {key: value}}))  # fmt: skip


# --- segment, evaluate, bench, scenes, report ------------------------------------------------------------------
def command_cases() -> None:
    f640 = B("f640")
    img = T / "cases/images"
    img.mkdir(parents=True, exist_ok=True)
    shutil.copy(f640 / "color.png", img / "a.png")
    (img / "b.png").write_bytes((f640 / "color.png").read_bytes()[:2000])
    shutil.copy(B("ak") / "color.png", img / "c.png")
    depth_dir = T / "cases/depths"
    depth_dir.mkdir(parents=True, exist_ok=True)
    shutil.copy(f640 / "depth.png", depth_dir / "a.png")
    shutil.copy(f640 / "depth.png", depth_dir / "c.png")  # 640x480 beside c's 1920x1080 colour
    seg = ["segment", img]
    add("segment/batch-goes-on", "failed", lambda: cli(*seg, "--output", out_dir("seg1")), "b.png")
    add("segment/depth-without-camera", "error", lambda: cli(*seg, "--output", out_dir("seg2"), "--depth", depth_dir),
        "camera")  # fmt: skip
    for scale in ("nan", "0", "-1", "1e9", "abc", "inf", "1e-300"):
        add(f"segment/depth-scale={scale}", "error",
            lambda s=scale: cli(*seg, "--output", out_dir("seg3"), "--depth", depth_dir, "--camera",
                                f640 / "camera.json", "--depth-scale", s), "depth-scale")  # fmt: skip
    add("segment/depth-other-size", "failed",
        lambda: cli(*seg, "--output", out_dir("seg4"), "--depth", depth_dir, "--camera", f640 / "camera.json"),
        "c.png")  # fmt: skip
    add("segment/camera-folder", "error",
        lambda: cli(*seg, "--output", out_dir("seg5"), "--depth", depth_dir, "--camera", T), str(T))  # fmt: skip
    add("segment/masks-folder-empty", "any",
        lambda: cli(*seg, "--output", out_dir("seg6"), "--masks", T / "settings"), "")  # fmt: skip
    add("segment/masks-coco-truncated", "error",
        lambda: cli(*seg, "--output", out_dir("seg7"), "--masks", T / "settings/camera-nan.json"),
        "camera-nan")  # fmt: skip
    add("segment/output-is-file", "error",
        lambda: cli(*seg, "--output", f640 / "camera.json"), "camera.json")  # fmt: skip
    add("segment/input-missing", "error", lambda: cli("segment", T / "nope.png", "--output", out_dir("seg8")), "nope")
    ev = ["evaluate", "--output", T / "out/ev"]
    for opt, value in [("--n", "0"), ("--n", "-1"), ("--n", "10000000000"), ("--seed", "-1"), ("--seed", "1e3"),
                       ("--occlusion", "x"), ("--occlusion", "2"), ("--occlusion", "nan"), ("--occlusion", "-0.5"),
                       ("--views", "0"), ("--views", "-2"), ("--views", "100000000"), ("--jobs", "0"),
                       ("--jobs", "-3"), ("--jobs", "100000"), ("--fruit", "kiwi"), ("--methods", "evidense"),
                       ("--methods", ""), ("--sensor-set", "rim_invalid_px=nan"),
                       ("--sensor-set", "rim_invalid_px=-1"), ("--sensor-set", "rim_invalid_px=1e9"),
                       ("--sensor-set", "rim_invalid=3"), ("--sensor-set", "flying_share=2"),
                       ("--sensor-set", "=3"), ("--sensor-set", "flying_share")]:  # fmt: skip
        extra = ["--sensor", "azure-kinect"] if opt == "--sensor-set" else []
        add(f"evaluate/camera{opt}={value}", "error",
            lambda o=opt, v=value, e=extra: cli(*ev, "--protocol", "camera", "--quick", "--jobs", "1", *e, o, v)
            if o != "--jobs" else cli(*ev, "--protocol", "camera", "--quick", o, v), "")  # fmt: skip
    add("evaluate/frames-missing", "error", lambda: cli(*ev, "--frames", T / "nope"), "nope")
    add("evaluate/frames-file", "error", lambda: cli(*ev, "--frames", f640 / "color.png"), "color.png")

    def frames_batch() -> Run:
        rec = T / "cases/evframes"
        if rec.exists():
            shutil.rmtree(rec)
        shutil.copytree(f640, rec / "a")
        shutil.copytree(f640, rec / "b")
        truncate("truth.json")(rec / "b")
        shutil.copytree(f640, rec / "c")
        corrupt("depth.png", 0.4)(rec / "c")
        return cli(*ev, "--frames", rec)

    add("evaluate/frames-bad-among-good", "any", frames_batch, "")
    add("evaluate/spheres-file", "error", lambda: cli(*ev, "--spheres", f640 / "color.png"), "color.png")
    add("evaluate/spheres-missing", "error", lambda: cli(*ev, "--spheres", T / "nope"), "nope")
    add("evaluate/spheres-no-masks", "any", lambda: cli(*ev, "--spheres", T / "cases/evframes"), "")
    add("evaluate/masks-images-empty", "error",
        lambda: cli(*ev, "--protocol", "masks", "--images", T / "settings", "--truth", T / "settings/camera-nan.json"),
        "")  # fmt: skip
    add("evaluate/masks-truth-truncated", "error",
        lambda: cli(*ev, "--protocol", "masks", "--images", img, "--truth", T / "settings/truncated.yaml"),
        "truncated.yaml")  # fmt: skip
    add("evaluate/masks-truth-folder", "error",
        lambda: cli(*ev, "--protocol", "masks", "--images", img, "--truth", T), str(T))  # fmt: skip
    add("evaluate/masks-category-nan", "error",
        lambda: cli(*ev, "--protocol", "masks", "--images", ROOT / "examples/photos", "--truth",
                    ROOT / "examples/photos/_annotations.coco.json", "--category", "nan"), "category")  # fmt: skip
    add("evaluate/masks-n-huge", "error", lambda: cli(*ev, "--protocol", "masks", "--n", "1000000000"), "")
    add("evaluate/config-unknown", "error",
        lambda: cli(*ev, "--protocol", "camera", "--quick", "--config", T / "settings/unknown.yaml"),
        "tilt_bend")  # fmt: skip
    for opt, value in [("--repeat", "0"), ("--repeat", "-1"), ("--repeat", "1000000000000"), ("--points", "0"),
                       ("--points", "-5"), ("--points", "1000000000000"), ("--points", "nan")]:  # fmt: skip
        add(f"bench{opt}={value}", "error", lambda o=opt, v=value: cli("bench", o, v), "")
    for value in ("0x0", "abc", "100000x100000", "1920x1080x3", "-640x480", "1x1", "640.5x480"):
        add(f"bench/segment-size={value}", "error" if value != "1x1" else "any",
            lambda v=value: cli("bench", "--segment", "--size", v), "size")  # fmt: skip
    add("bench/segment-images-empty", "error",
        lambda: cli("bench", "--segment", "--images", T / "settings"), "")  # fmt: skip
    add("bench/segment-images-missing", "error",
        lambda: cli("bench", "--segment", "--images", T / "nope"), "nope")  # fmt: skip
    for value in ("0", "-1", "1000000000"):
        add(f"bench/recording={value}", "error", lambda v=value: cli("bench", "--recording", v), "recording")
    add("bench/frame-repeat-0", "error", lambda: cli("bench", "--frame", "--repeat", "0"), "repeat")
    add("bench/workers-0", "error", lambda: cli("bench", "--recording", "2", "--workers", "0"), "workers")
    for opt, value in [("--n", "0"), ("--n", "-1"), ("--n", "1000000000"), ("--ripe", "-1"),
                       ("--ripe", "100000000"), ("--unripe", "-2"), ("--seed", "-1"),
                       ("--sensor-set", "rim_invalid_px=nan")]:  # fmt: skip
        add(f"scenes{opt}={value}", "error",
            lambda o=opt, v=value: cli("scenes", out_dir("scenes"), "--sensor", "azure-kinect", o, v), "")  # fmt: skip
    add("scenes/output-is-file", "error", lambda: cli("scenes", f640 / "camera.json", "--n", "1"), "camera.json")
    add("scenes/plain-colour-strawberry", "error", lambda: cli("scenes", out_dir("scenes2"), "--plain-colour"), "")
    add("report/missing", "error", lambda: cli("report", T / "nope"), "nope")
    add("report/file", "error", lambda: cli("report", f640 / "color.png"), "color.png")
    add("report/not-a-run", "error", lambda: cli("report", f640), "")
    for value in ("a,b", "25,18", "nan", "-1", "", "1e400"):
        add(f"report/classes={value}", "error",
            lambda v=value: cli("report", T / "out/f640_good", "--classes", v), "classes")  # fmt: skip


# --- library calls: the ROS node's frame processor and read_frame at 1920x1080 ---------------------------------
def api_cases() -> None:
    from types import SimpleNamespace

    def hdr() -> SimpleNamespace:
        return SimpleNamespace(stamp=SimpleNamespace(secs=7, nsecs=5), frame_id="cam")

    def img(a: np.ndarray, encoding: str) -> SimpleNamespace:
        a = np.ascontiguousarray(a)
        h, w = a.shape[:2]
        rows = a.reshape(h, -1).view(np.uint8)
        return SimpleNamespace(height=h, width=w, encoding=encoding, is_bigendian=0, step=rows.shape[1],
                               data=rows.tobytes(), header=hdr())  # fmt: skip

    def process(depth: Callable[[np.ndarray], np.ndarray], encoding: str = "16UC1", **kw: Any) -> Any:
        from symfruit.io.frames import read_frame
        from symfruit.ros.core import FrameProcessor

        fr = read_frame(B("tree"))
        cam = fr.camera
        info = SimpleNamespace(width=cam.width, height=cam.height, header=hdr(),
                               K=[kw.get("fx", cam.fx), 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0])  # fmt: skip
        raw = np.nan_to_num(fr.depth * 1000).astype(np.uint16)
        return FrameProcessor(masks="color", fruit="apple").process(img(fr.color, "rgb8"), img(depth(raw), encoding),
                                                                    info)  # fmt: skip

    add("ros/tree-good", "result", lambda: process(lambda r: r))
    add("ros/tree-depth-zero", "error", lambda: process(lambda r: np.zeros_like(r)))
    add("ros/tree-depth-65535", "error", lambda: process(lambda r: np.full_like(r, 65535)))
    add("ros/tree-depth-32FC1-nan", "error",
        lambda: process(lambda r: np.full(r.shape, np.nan, np.float32), "32FC1"))  # fmt: skip
    add("ros/tree-depth-32FC1-mm", "error", lambda: process(lambda r: r.astype(np.float32), "32FC1"))
    add("ros/tree-depth-smaller", "error", lambda: process(lambda r: r[::2, ::2].copy()))
    add("ros/tree-fx-1e9", "error", lambda: process(lambda r: r, fx=1e9))
    add("ros/tree-fx-nan", "error", lambda: process(lambda r: r, fx=float("nan")))
    from symfruit.ros.core import checked_parameters, unknown_parameters

    for key, value in [("depth_scale", "0.001"), ("depth_scale", float("inf")), ("slop", -1.0), ("slop", float("nan")),
                       ("queue_size", 10**30), ("queue_size", 2.5), ("qos", "fast"), ("method", ["a"]),
                       ("fruit", True)]:  # fmt: skip
        add(f"ros/param-{key}={value!r:.12}", "any" if value == "0.001" else "error",
            lambda k=key, v=value: checked_parameters({k: v}), key)  # fmt: skip
    add("ros/param-unknown", "error", lambda: unknown_parameters(["hiden_front"]), "hiden_front")

    def read(name: str) -> Any:
        from symfruit.io.frames import read_frame

        return read_frame(T / "cases" / name / "frame")

    add("api/read-frame-missing", "error", lambda: read("nope"), "nope")


# --- running ---------------------------------------------------------------------------------------------------
_FOREIGN = re.compile(r"(Traceback|\b(?!Symfruit|Input|Config|FileFormat|Output|Setting)[A-Z][A-Za-z]*(Error|Exception|"
                      r"Warning)\b: |\bErrno\b)")  # fmt: skip


def judge(value: Any, expect: str, names: str) -> tuple[str, str]:
    if not isinstance(value, Run):
        return ("DEFECT", f"wrong silent result: {type(value).__name__}") if expect == "error" else ("result", "")
    # the error lines, and a batch's failed items: its summary's "failed ..." lines and errors.json's reasons
    lines = [ln for ln in value.err.splitlines() if ln.strip()]
    lines += [ln.strip() for ln in value.out.splitlines() if ln.strip().startswith(("failed ", "skipped "))]
    record = value.output / "errors.json" if value.output is not None else None
    if record is not None and record.is_file():
        lines += [f"{x.get('frame', x.get('image', ''))}: {x['reason']}" for x in json.loads(record.read_text())
                  ["failed"]]  # fmt: skip
    text = " | ".join(lines)
    shown = text.replace(str(T), "T")
    longest = max((len(ln.replace(str(T), "T")) for ln in lines), default=0)
    if _FOREIGN.search(text):
        return "DEFECT", f"another library's words: {shown[:240]}"
    if longest > 300:
        return "DEFECT", f"a line of {longest} characters: {shown[:200]}"
    if value.rc == 0:
        if expect in ("error", "failed"):
            return "DEFECT", f"wrong silent result (exit 0): {value.out.strip()[-160:]!r}"
        return "result", value.out.strip().splitlines()[-1][:150] if value.out.strip() else ""
    if value.rc == 1:
        kind = "failed"
        if expect == "result":
            return "DEFECT", f"failed what it should take: {shown[:200]}"
    elif value.rc == 2:
        kind = "error"
        if expect == "result":
            return "DEFECT", f"refused what it should take: {shown[:200]}"
    else:
        return "DEFECT", f"exit {value.rc}: {shown[:200]}"
    if names and names.replace(str(T), "T") not in shown and names not in text:
        return "DEFECT", f"does not name {names.replace(str(T), 'T')!r}: {shown[:200]}"
    return kind, shown[:200]


def origin(exc: BaseException) -> str:
    frames = traceback.extract_tb(exc.__traceback__)
    last = frames[-1] if frames else None
    where = f"{last.filename.split('site-packages/')[-1].split('src/')[-1]}:{last.lineno}" if last else "?"
    return f"{type(exc).__module__}.{type(exc).__name__} at {where}: {str(exc)[:160]!r}"


def main() -> int:
    global T
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default="", help="the cases whose name holds one of these (comma-separated)")
    parser.add_argument("--defects", action="store_true", help="print the defects alone")
    parser.add_argument("--keep", type=Path, help="make or reuse the fixtures in this folder")
    args = parser.parse_args()
    import symfruit

    T = args.keep.resolve() if args.keep else Path(tempfile.mkdtemp(prefix="robust47-"))
    T.mkdir(parents=True, exist_ok=True)
    make_fixtures()
    settings_cases()
    detect_cases()
    bag_cases()
    complete_cases()
    command_cases()
    api_cases()
    signal.signal(signal.SIGALRM, _alarm)
    counts = {"error": 0, "failed": 0, "result": 0, "DEFECT": 0}
    for name, expect, fn, names in CASES:
        if not any(part in name for part in args.only.split(",")):
            continue
        signal.alarm(LIMIT_S)
        try:
            value = fn()
            signal.alarm(0)
            kind, text = judge(value, expect, names)
        except symfruit.SymfruitError as exc:
            signal.alarm(0)
            msg = str(exc).replace(str(T), "T")
            if expect == "result":
                kind, text = "DEFECT", f"refused what it should take: {msg[:150]}"
            elif len(msg) > 300:
                kind, text = "DEFECT", f"message of {len(msg)} characters: {msg[:150]}"
            elif names and names.replace(str(T), "T") not in msg:
                kind, text = "DEFECT", f"does not name {names!r}: {msg[:150]}"
            else:
                kind, text = "error", msg[:150]
        except Hang:
            kind, text = "DEFECT", f"hang (over {LIMIT_S} s)"
        except Exception as exc:  # the point of the sweep
            signal.alarm(0)
            kind, text = "DEFECT", origin(exc)
        counts[kind] += 1
        if kind == "DEFECT" or not args.defects:
            sys.stdout.write(f"{kind:6} {name:48} {text}\n")
            sys.stdout.flush()
    sys.stdout.write(f"# {sum(counts.values())} cases: {counts['error']} clear errors, {counts['failed']} failed items "
                     f"reported, {counts['result']} results, {counts['DEFECT']} defects\n")  # fmt: skip
    if not args.keep:
        shutil.rmtree(T, ignore_errors=True)
    return 1 if counts["DEFECT"] else 0


if __name__ == "__main__":
    sys.exit(main())
