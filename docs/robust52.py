"""Stop 52: bad and adversarial input past stops 43-51's sweeps (robust52).

First what no sweep could try as root (root reads every file whatever its mode): each kind of input made
unreadable (mode 000) and read by an unprivileged user (this process's effective user and group set to 65534,
nobody, for the call alone, and back): a frame's colour, depth, camera and masks, a frame folder or recording
that cannot be listed, settings YAML, camera files, clouds, ROS 1 and ROS 2 bags, scans, photo folders, COCO
files, and output folders that cannot be written. Each must be one line naming the file, a batch going on past it.

Then adversarial inputs the earlier sweeps did not try: FIFOs and link loops given where a frame's masks or a
photo folder's photo go; files that grow or shrink while read; a depth PNG whose header promises more rows than
its data holds; colour of 16 bits a channel; NaN and infinite intrinsics in every place they are read (camera.json
keys, a ROS-layout K, camera YAML, the ``complete --camera`` file); settings YAML with anchors and aliases,
duplicate keys, wrong types nested deep; masks whose labels pass int32; COCO files whose RLE is of the wrong
length or whose image size is 0; colour and depth one pixel apart in size; camera.json of 0 or negative size.

Cases run in this process under an alarm and are judged as docs/robust47.py judges them (through robust49's
``sweep``); a case that checks a rule itself returns ``DEFECT: ...`` when it is broken.

::

    PYTHONPATH=src python docs/robust52.py                 # every case (fixtures in a temporary folder)
    PYTHONPATH=src python docs/robust52.py --only nobody/ --defects
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import struct
import sys
import threading
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import robust47 as r47
import robust49 as r49
import robust51 as r51

LIMIT_S = 60
ROOT, fixture, cli, Run, small = r47.ROOT, r49.fixture, r47.cli, r47.Run, r51.small
camera, camera_text = r47.camera_edit, r47.camera_text
BAG1 = ROOT / "examples/realsense/fruit.bag"
PLY = ROOT / "examples/strawberry_partial.ply"
PHOTOS = ROOT / "examples/photos"
COCO = PHOTOS / "_annotations.coco.json"
SCANS = ROOT / "examples/scans"
NOBODY = 65534
CASES: list[tuple[str, str, Callable[[], Any], str]] = []


def add(name: str, expect: str, fn: Callable[[], Any], names: str = "") -> None:
    CASES.append((name, expect, fn, names))


def as_nobody(*argv: Any, output: Path | None = None) -> Run:
    """``symfruit ARGV`` run as the nobody user (``setpriv --reuid=65534 --regid=65534 --clear-groups``; HOME
    /nonexistent as nobody's is), this tree's ``src`` on its path, the kernels' numpy twins
    (``SYMFRUIT_KERNELS=numpy``: nobody can write no numba cache, and compiling them all takes minutes)."""
    import subprocess

    import symfruit  # the tree swept (PYTHONPATH), for nobody's process too

    env = {**os.environ, "HOME": "/nonexistent", "PYTHONPATH": str(Path(symfruit.__file__).resolve().parents[1]),
           "SYMFRUIT_KERNELS": "numpy", "MPLCONFIGDIR": str(r47.T / "nobody-out")}  # fmt: skip
    done = subprocess.run(["setpriv", f"--reuid={NOBODY}", f"--regid={NOBODY}", "--clear-groups", sys.executable,
                           "-W", "ignore", "-m", "symfruit", *map(str, argv)], capture_output=True, text=True,
                          env=env, timeout=LIMIT_S)  # fmt: skip
    err = "\n".join(ln for ln in done.stderr.splitlines() if not ln.startswith(("detect: ", "segment: ")))
    return Run(done.returncode, done.stdout, err, output)


def frame_copy(name: str) -> Path:
    """A copy of the small frame where nobody reaches it."""
    f = fixture(f"nobody-copy-{name}")
    shutil.copytree(small(), f)
    return f


def reachable() -> None:
    """The fixtures' folder open to nobody (mkdtemp makes it 0700) and a writable folder for its outputs."""
    r47.T.chmod(0o755)
    (r47.T / "cases49").mkdir(exist_ok=True)
    (r47.T / "cases49").chmod(0o755)
    (r47.T / "nobody-out").mkdir(exist_ok=True)
    (r47.T / "nobody-out").chmod(0o1777)


def nout(name: str) -> Path:
    target = r47.T / "nobody-out" / name
    shutil.rmtree(target, ignore_errors=True)
    return target


def locked(path: Path) -> Path:
    path.chmod(0o000)
    return path


# --- read by nobody: unreadable inputs, unwritable outputs -----------------------------------------------------
def nobody_cases() -> None:
    def frame(file: str) -> Callable[[], Any]:
        def go() -> Any:
            reachable()
            f = fixture(f"nobody-frame-{file}")
            shutil.copytree(small(), f)
            if file == "masks.png":
                from PIL import Image

                Image.fromarray(np.zeros((160, 160), np.uint8)).save(f / "masks.png")
            locked(f / file)
            o = nout(f"frame-{file}")
            return as_nobody("detect", f, "--output", o, "--method", "sphere", output=o)

        return go

    for file in ("color.png", "depth.png", "camera.json", "masks.png"):
        add(f"nobody/frame-{file}", "error", frame(file), file)
    add("nobody/frame-truth.json", "any", frame("truth.json"))  # the truth is not detect's

    def recording(what: str) -> Callable[[], Any]:
        """A recording of three frames, the second's ``what`` unreadable: the batch goes on past it."""

        def go() -> Any:
            reachable()
            rec = fixture(f"nobody-rec-{what}")
            for k in range(3):
                shutil.copytree(small(), rec / f"f_{k}")
            rec.chmod(0o755)
            locked(rec / "f_1" if what == "folder" else rec / "f_1" / what)
            o = nout(f"rec-{what}")
            run = as_nobody("detect", rec, "--output", o, "--method", "sphere", output=o)
            done = sorted(p.parent.name for p in o.glob("*/detections.json"))
            if done != ["f_0", "f_2"]:
                return f"DEFECT: the batch did not go on past the unreadable item (done: {done}): {run.err[-200:]}"
            return run

        return go

    for what in ("depth.png", "color.png", "camera.json", "folder"):
        add(f"nobody/recording-{what}", "failed", recording(what), "f_1")

    def whole_recording() -> Any:
        reachable()
        rec = fixture("nobody-rec-unlistable")
        shutil.copytree(small(), rec / "f_0")
        locked(rec)
        o = nout("rec-unlistable")
        return as_nobody("detect", rec, "--output", o, "--method", "sphere", output=o)

    add("nobody/recording-unlistable", "error", whole_recording, "nobody-rec-unlistable")

    def of_file(name: str, suffix: str, make: Callable[[Path], None], argv: Callable[[Path], list[Any]]) -> None:
        def go() -> Any:
            reachable()
            p = fixture(f"nobody-{name}{suffix}")
            make(p)
            locked(p)
            return as_nobody(*argv(p))

        add(f"nobody/{name}", "error", go, f"nobody-{name}{suffix}")

    def text(content: str) -> Callable[[Path], None]:
        return lambda p: p.write_text(content)

    cam = (ROOT / "examples/camera.json").read_text()
    of_file("settings-config", ".yaml", text("evidence:\n  rays: 64\n"), lambda p: ["settings", "--config", p])
    of_file("detect-config", ".yaml", text("evidence:\n  rays: 64\n"),
            lambda p: ["detect", frame_copy("dc"), "--output", nout("dc"), "--config", p])  # fmt: skip
    of_file("complete-camera", ".json", text(cam), lambda p: ["complete", PLY, "--camera", p])
    of_file("complete-cloud-ply", ".ply", lambda p: shutil.copy(PLY, p), lambda p: ["complete", p])
    of_file("complete-cloud-npy", ".npy", lambda p: np.save(p, np.random.default_rng(0).normal(size=(500, 3))),
            lambda p: ["complete", p])  # fmt: skip
    of_file("detect-masks-png", ".png", lambda p: shutil.copy(small() / "color.png", p),
            lambda p: ["detect", frame_copy("dm"), "--output", nout("dm"), "--masks", p])  # fmt: skip
    of_file("segment-photo", ".jpg", lambda p: shutil.copy(next(PHOTOS.glob("*.jpg")), p),
            lambda p: ["segment", p, "--output", nout("sp")])  # fmt: skip
    of_file("segment-masks-coco", ".json", lambda p: shutil.copy(COCO, p),
            lambda p: ["segment", PHOTOS, "--output", nout("sc"), "--masks", p])  # fmt: skip
    of_file(
        "evaluate-truth-coco",
        ".json",
        lambda p: shutil.copy(COCO, p),
        lambda p: ["evaluate", "--protocol", "masks", "--images", PHOTOS, "--truth", p, "--output", nout("et")],
    )
    of_file("ros1-bag", ".bag", lambda p: shutil.copy(BAG1, p),
            lambda p: ["detect", p, "--output", nout("b1"), "--method", "sphere"])  # fmt: skip

    def ros2(what: str) -> Any:
        reachable()
        sys.path.insert(0, str(ROOT))
        from tests.conftest import disc_frame
        from tests.io.test_bags import write_ros2_bag

        color, depth = disc_frame([(60, 60)], radius=15)
        b = fixture(f"nobody-ros2-{what}")
        write_ros2_bag(b, color, (depth * 1000).astype(np.uint16), frames=1, storage="mcap")
        b.chmod(0o755)
        locked(b if what == "folder" else b / "metadata.yaml" if what == "metadata" else next(b.glob("*.mcap")))
        o = nout(f"ros2-{what}")
        return as_nobody("detect", b, "--output", o, "--method", "sphere", output=o)

    for what in ("metadata", "mcap", "folder"):
        add(f"nobody/ros2-bag-{what}", "error", lambda what=what: ros2(what), f"nobody-ros2-{what}")

    def scans() -> Any:
        reachable()
        folder = fixture("nobody-scans")
        folder.mkdir()
        folder.chmod(0o755)
        for scan in SCANS.glob("*.ply"):
            shutil.copy(scan, folder)
        locked(folder / "016_pear.ply")
        return as_nobody(
            "evaluate",
            "--protocol",
            "paper",
            "--fruit",
            folder,
            "--n",
            "1",
            "--methods",
            "raw",
            "--output",
            nout("scans"),
        )

    add("nobody/scan-in-a-folder", "error", scans, "016_pear.ply")

    def photos() -> Any:
        reachable()
        folder = fixture("nobody-photos")
        folder.mkdir()
        folder.chmod(0o755)
        for photo in sorted(PHOTOS.glob("*.jpg"))[:3]:
            shutil.copy(photo, folder)
        bad = locked(sorted(folder.glob("*.jpg"))[1])
        o = nout("photos")
        run = as_nobody("segment", folder, "--output", o, output=o)
        done = sorted(o.glob("*")) if o.is_dir() else []
        if len([p for p in done if p.stem.split(".")[0] != bad.stem]) < 2 or bad.name not in run.err + run.out:
            return f"DEFECT: the batch did not go on past {bad.name} or did not name it: {run.err[-160:]} {done}"
        return run

    add("nobody/photo-folder-one-unreadable", "failed", photos, "")

    def unwritable(name: str, argv: Callable[[Path], list[Any]], names: str = "ro") -> None:
        def go() -> Any:
            reachable()
            ro = fixture(f"nobody-ro-{name}")
            ro.mkdir()
            ro.chmod(0o555)
            return as_nobody(*argv(ro))

        add(f"nobody/output-unwritable-{name}", "error", go, names)

    unwritable("detect-inside", lambda ro: ["detect", frame_copy("ro1"), "--output", ro / "o", "--method", "sphere"])
    unwritable("detect-itself", lambda ro: ["detect", frame_copy("ro2"), "--output", ro, "--method", "sphere"])
    unwritable("complete", lambda ro: ["complete", PLY, "--output", ro / "c.ply"])
    unwritable("segment", lambda ro: ["segment", next(PHOTOS.glob("*.jpg")), "--output", ro / "s"])
    unwritable("scenes", lambda ro: ["scenes", ro / "s", "--n", "1"])

    def report() -> Any:
        reachable()
        run_folder = fixture("nobody-run")
        o = nout("run-for-report")
        cli("detect", small(), "--output", o, "--method", "sphere")
        shutil.copytree(o, run_folder)
        run_folder.chmod(0o755)
        locked(run_folder / "detections.parquet")
        return as_nobody("report", run_folder, "--output", nout("report"))

    add("nobody/report-table-unreadable", "error", report, "detections.parquet")


# --- adversarial inputs -----------------------------------------------------------------------------------------
def frame_case(name: str, expect: str, change: Callable[[Path], Any], names: str = "", *extra: Any) -> None:
    """robust51's: ``symfruit detect`` of a copy of the small frame changed by ``change``, a case of this sweep."""
    r51.frame_case(name, expect, change, names, *extra)
    CASES.append(r51.CASES.pop())


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def png16(rows: np.ndarray, *, height: int | None = None) -> bytes:
    """A 16-bit grey PNG of ``rows``, its header stating ``height`` rows (default: as many as it holds)."""
    h, w = rows.shape
    raw = b"".join(b"\0" + r.astype(">u2").tobytes() for r in rows)
    ihdr = struct.pack(">IIBBBBB", w, height or h, 16, 0, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", ihdr) + _chunk(b"IDAT", zlib.compress(raw)) + _chunk(b"IEND", b"")


def frame_cases() -> None:
    from PIL import Image

    def depth_rows(f: Path) -> np.ndarray:
        with Image.open(f / "depth.png") as im:
            return np.asarray(im)

    frame_case("good", "result", lambda f: None)
    frame_case("depth-png-header-promises-more-rows", "error",
               lambda f: (f / "depth.png").write_bytes(png16(depth_rows(f)[:80], height=160)), "depth.png")  # fmt: skip
    frame_case("depth-png-header-promises-a-million-rows", "error",
               lambda f: (f / "depth.png").write_bytes(png16(depth_rows(f)[:4], height=1_000_000)),
               "depth.png")  # fmt: skip

    def colour16(f: Path) -> None:
        with Image.open(f / "color.png") as im:
            rgb = np.asarray(im.convert("RGB")).astype(np.uint16) * 257
        # 16 bits a channel: PIL writes none, so by hand (colour type 2, depth 16)
        h, w, _ = rgb.shape
        raw = b"".join(b"\0" + r.astype(">u2").tobytes() for r in rgb)
        ihdr = struct.pack(">IIBBBBB", w, h, 16, 2, 0, 0, 0)
        (f / "color.png").write_bytes(b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", ihdr) + _chunk(b"IDAT", zlib.compress(
            raw)) + _chunk(b"IEND", b""))  # fmt: skip

    frame_case("colour-16-bit-rgb", "any", colour16, "color.png")
    frame_case("colour-one-pixel-wider", "error", lambda f: Image.fromarray(np.pad(np.asarray(Image.open(
        f / "color.png").convert("RGB")), ((0, 0), (0, 1), (0, 0)))).save(f / "color.png"),
        "colour is 161x160")  # fmt: skip
    frame_case("depth-one-pixel-taller", "error", lambda f: Image.fromarray(np.pad(depth_rows(f), ((0, 1), (0, 0))))
               .save(f / "depth.png"), "depth")  # fmt: skip
    frame_case("depth-one-pixel-narrower", "error", lambda f: Image.fromarray(np.ascontiguousarray(
        depth_rows(f)[:, :-1])).save(f / "depth.png"), "depth")  # fmt: skip
    for key in ("fx", "fy", "cx", "cy"):
        for value in (float("nan"), float("inf"), -float("inf")):  # written as JSON's NaN and Infinity literals
            frame_case(f"camera-{key}-{value}", "error", camera(**{key: value}), "camera.json")
    for key, value in (("width", 0), ("height", 0), ("width", -160), ("height", -1), ("width", 2**40)):
        frame_case(f"camera-{key}={value}", "error", camera(**{key: value}), "camera.json")
    frame_case("camera-ros-K-nan", "error", camera_text(json.dumps({
        "image_width": 160, "image_height": 160, "camera_matrix": {"rows": 3, "cols": 3, "data": [float("nan"), 0,
        80, 0, 615.0, 80, 0, 0, 1]}})), "camera.json")  # fmt: skip
    frame_case("camera-ros-K-inf", "error", camera_text(json.dumps({
        "image_width": 160, "image_height": 160, "K": [615.0, 0, float("inf"), 0, 615.0, 80, 0, 0, 1]})),
        "camera.json")  # fmt: skip
    frame_case("camera-yaml-fx-nan", "error", lambda f: ((f / "camera.json").unlink(), (f / "camera.yaml").write_text(
        "fx: .nan\nfy: 615.0\ncx: 80\ncy: 80\nwidth: 160\nheight: 160\n")), "camera.yaml")  # fmt: skip
    frame_case("camera-yaml-cy-inf", "error", lambda f: ((f / "camera.json").unlink(), (f / "camera.yaml").write_text(
        "fx: 615.0\nfy: 615.0\ncx: 80\ncy: .inf\nwidth: 160\nheight: 160\n")), "camera.yaml")  # fmt: skip
    frame_case("camera-depth_scale-nan", "error", camera(depth_scale=float("nan")), "camera.json")

    def label_tiff(value: int) -> Callable[[Path], None]:
        """masks.png a TIFF of 32-bit labels (the widest Pillow keeps; it reads 2^32-1 as -1)."""

        def go(f: Path) -> None:
            import io

            labels = np.zeros((160, 160), np.uint32)
            labels[60:100, 60:100] = value
            buf = io.BytesIO()
            Image.fromarray(labels).save(buf, format="TIFF")
            (f / "masks.png").write_bytes(buf.getvalue())

        return go

    frame_case("masks-label-2^31-1", "any", label_tiff(2**31 - 1), "masks")
    frame_case("masks-label-2^32-1", "error", label_tiff(2**32 - 1), "masks.png")
    frame_case("masks-is-a-fifo", "error", lambda f: os.mkfifo(f / "masks.png"), "masks.png")
    frame_case("masks-link-loop", "error", lambda f: os.symlink("masks.png", f / "masks.png"), "masks.png")
    frame_case("camera-is-a-fifo", "error", lambda f: ((f / "camera.json").unlink(), os.mkfifo(f / "camera.json")),
               "camera.json")  # fmt: skip


def changing_cases() -> None:
    """Files that grow or shrink while they are read: a thread rewrites them as fast as it can."""

    def churn(path: Path, versions: list[bytes], stop: threading.Event) -> None:
        k = 0
        while not stop.is_set():
            with contextlib.suppress(OSError):
                with open(path, "r+b") as fh:
                    fh.truncate(0)
                    fh.write(versions[k % len(versions)])
            k += 1

    def changing(name: str, file: str, short: Callable[[bytes], bytes]) -> None:
        def go() -> Any:
            f = fixture(f"changing-{name}")
            rec = f
            for k in range(4):
                shutil.copytree(small(), rec / f"f_{k}")
            path = rec / "f_1" / file
            whole = path.read_bytes()
            stop = threading.Event()
            versions = [whole, short(whole), whole + bytes(len(whole))]  # whole, cut short, grown with zeros
            thread = threading.Thread(target=churn, args=(path, versions, stop), daemon=True)
            thread.start()
            o = r49.out(f"changing-{name}")
            try:
                run = cli("detect", rec, "--output", o, "--method", "sphere", output=o)
            finally:
                stop.set()
                thread.join()
            done = sorted(p.parent.name for p in o.glob("*/detections.json"))
            if not {"f_0", "f_2", "f_3"} <= set(done):
                return f"DEFECT: the batch did not go on past the changing file (done: {done}): {run.err[-200:]}"
            return run

        add(f"changing/{name}", "any", go)

    changing("depth.png", "depth.png", lambda b: b[: len(b) // 3])
    changing("color.png", "color.png", lambda b: b[: len(b) // 2])
    changing("camera.json", "camera.json", lambda b: b[: len(b) // 2])


def settings_cases() -> None:
    def config(name: str, text: str, expect: str = "error") -> None:
        def go() -> Any:
            path = fixture(f"{name}.yaml")
            path.write_text(text)
            return cli("settings", "--config", path)

        add(f"settings/{name}", expect, go, f"{name}.yaml" if expect == "error" else "")

    # a key list repeated by aliases: each level 10 of the one before, a billion strings at the top
    chain = "a: &a " + json.dumps(["x" * 10] * 10) + "\n" + "".join(
        f"{chr(98 + k)}: &{chr(98 + k)} [{', '.join([f'*{chr(97 + k)}'] * 10)}]\n" for k in range(8))  # fmt: skip
    config("aliases-of-long-strings", "evidence:\n  rays: 64\n" + chain)
    config("alias-as-a-value-of-a-known-key", "x: &big [" + ", ".join(["1"] * 1000) + "]\nevidence:\n  rays: *big\n")
    config("alias-a-whole-section", "base: &b\n  rays: 64\nevidence: *b\n")
    config("duplicate-key-in-a-section", "evidence:\n  rays: 64\n  rays: -1\n")
    config("wrong-type-nested-deep", "evidence:\n  rays: {a: {b: {c: [1, 2, {d: 3}]}}}\n")
    config("section-nested-in-a-section", "evidence:\n  evidence:\n    rays: 64\n")
    config("number-key", "evidence:\n  1: 64\n")
    config("null-key", "evidence:\n  ~: 64\n")
    config("complex-key", "evidence:\n  ? [rays]\n  : 64\n")
    config("rays-a-huge-int", "evidence:\n  rays: " + "9" * 400 + "\n")
    config("rays-nan", "evidence:\n  rays: .nan\n")
    config("depth-inf", "extract:\n  max_depth: .inf\n")
    config("binary-tag", "evidence:\n  rays: !!binary aGVsbG8=\n")
    config("set-tag", "evidence: !!set {rays}\n")


def coco_cases() -> None:
    coco = json.loads(COCO.read_text())

    def case(name: str, change: Callable[[dict[str, Any]], None], expect: str = "error") -> None:
        def go() -> Any:
            data = json.loads(json.dumps(coco))
            change(data)
            path = fixture(f"coco-{name}.json")
            path.write_text(json.dumps(data))
            folder = fixture(f"coco-{name}-photos")
            shutil.copytree(PHOTOS, folder)
            o = r49.out(f"coco-{name}")
            return cli("evaluate", "--protocol", "masks", "--images", folder, "--truth", path, "--output", o)

        add(f"coco/{name}", expect, go, f"coco-{name}.json" if expect == "error" else "")

    def missing_photo() -> Any:  # the dataset's own long names: a line each photo left out
        folder = fixture("coco-missing-photos")
        shutil.copytree(PHOTOS, folder)
        gone = folder / coco["images"][0]["file_name"]
        gone.unlink()
        o = r49.out("coco-missing")
        return cli("evaluate", "--protocol", "masks", "--images", folder, "--truth", COCO, "--output", o)

    add("coco/a-listed-photo-missing", "failed", missing_photo, coco["images"][0]["file_name"])

    def rle(counts: Any, size: Any = None) -> Callable[[dict[str, Any]], None]:
        def go(data: dict[str, Any]) -> None:
            image = data["images"][0]
            ann = next(a for a in data["annotations"] if a["image_id"] == image["id"])
            ann["segmentation"] = {"counts": counts, "size": size or [image["height"], image["width"]]}
            ann["iscrowd"] = 1

        return go

    area = lambda data: data["images"][0]["height"] * data["images"][0]["width"]  # noqa: E731
    case("rle-too-short", lambda d: rle([10, 20])(d), "error")
    case("rle-too-long", lambda d: rle([0, area(d) + 1000])(d), "error")
    case("rle-negative-run", lambda d: rle([5, -3, area(d) - 2])(d), "error")
    case("rle-size-disagrees", lambda d: rle([0, area(d)], [10, 10])(d), "error")
    case("rle-counts-a-huge-number", lambda d: rle([0, 10**30])(d), "error")
    case("rle-compressed-string-garbage", lambda d: rle("\x00\x01ÿ")(d), "error")
    case("image-width-0", lambda d: d["images"][0].update(width=0), "error")
    case("image-height-negative", lambda d: d["images"][0].update(height=-5), "error")
    case("polygon-of-nan", lambda d: d["annotations"][0].update(segmentation=[[float("nan")] * 8]), "error")
    case("polygon-of-1e300", lambda d: d["annotations"][0].update(segmentation=[[1e300] * 8]), "any")
    case("annotation-id-10^30", lambda d: d["annotations"][0].update(id=10**30), "any")
    case("category-id-2^63", lambda d: [a.update(category_id=2**63) for a in d["annotations"]], "any")
    case("image-id-10^30", lambda d: (d["images"][0].update(id=10**30), [a.update(image_id=10**30) for a in
         d["annotations"] if a["image_id"] == 14]), "any")  # fmt: skip


def main() -> int:
    return r49.run_main(
        __doc__ or "",
        (nobody_cases, frame_cases, changing_cases, settings_cases, coco_cases),
        CASES,
        prefix="robust52-",
        limit=LIMIT_S,
        width=56,
    )


if __name__ == "__main__":
    sys.exit(main())
