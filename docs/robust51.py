"""Stop 51: bad and adversarial input past stops 43-50's sweeps (robust51).

What the earlier sweeps (docs/robust43.py: the array API; robust47-49: the command line and the readers;
robust50: the writers, damaged run tables, whole-file bags) did not reach, built as an adversary would: intrinsics
that disagree with the image (width and height swapped, a negative focal length, a principal point far outside,
numbers written as text); a frame's depth scale at odd values (zero, negative, a micrometre, a decimetre, text,
true) and depth ``.npy`` of odd dtypes (bool, complex, int64, structured, big-endian, Fortran order, a header
claiming a terabyte); files that are links to ``/dev/zero``, ``/dev/urandom`` or ``/proc``, and a recording
folder holding a link to itself or to another frame; settings YAML that is a billion-laughs alias bomb, holds a
Python tag, duplicate keys, a date where a number goes, or is UTF-16; PLY and OBJ scans with degenerate, huge,
negative or out-of-range faces, and vertices of 1e30; a ROS 1 bag whose header lies about its index position,
connection or chunk count; a ROS 2 bag whose metadata names files outside its folder; ROS image messages whose
``is_bigendian`` is 2 or 255, or whose step is a terabyte; ``symfruit report`` and ``frame_rows`` on NaN, infinite
or partial centres and 400-digit numbers; ``--no-worker-timeout`` at and beyond its bounds; and a whole-file
compressed bag decompressed while another run takes the disk's room.

Cases run in this process under an alarm and are judged as docs/robust47.py judges them (through robust49's
``sweep``): a library call's case returns its value (``result``) or raises a ``SymfruitError`` (``error``); any
other exception is a defect, and so is a result where an error was expected. A case that checks a rule itself
returns ``DEFECT: ...`` when it is broken.

::

    PYTHONPATH=src python docs/robust51.py                 # every case (fixtures in a temporary folder)
    PYTHONPATH=src python docs/robust51.py --only mesh/ --defects
"""

from __future__ import annotations

import json
import os
import shutil
import struct
import sys
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import robust47 as r47
import robust49 as r49

#: A case's alarm (s): a file that is a link to /dev/zero is read for ever without a bound.
LIMIT_S = 60
ROOT, T, fixture, cli, Run = r47.ROOT, r49.T, r49.fixture, r47.cli, r47.Run
camera, camera_text = r47.camera_edit, r47.camera_text  # camera.json changed, or written as this text
BAG1 = ROOT / "examples/realsense/fruit.bag"
CASES: list[tuple[str, str, Callable[[], Any], str]] = []


def add(name: str, expect: str, fn: Callable[[], Any], names: str = "") -> None:
    CASES.append((name, expect, fn, names))


def small() -> Path:
    """The tests' small frame (160x160, one strawberry): a fresh copy per case."""
    sys.path.insert(0, str(ROOT))
    from tests.conftest import small_frame

    return small_frame()


def frame_case(name: str, expect: str, change: Callable[[Path], Any], names: str = "", *extra: Any) -> None:
    """``symfruit detect`` of a copy of the small frame changed by ``change``."""

    def go() -> Any:
        f = fixture(f"frame-{name}")
        shutil.copytree(small(), f)
        change(f)
        o = r49.out(f"frame-{name}")
        return cli("detect", f, "--output", o, "--method", "sphere", *extra, output=o)

    add(f"frame/{name}", expect, go, names)


def depth_npy(make: Callable[[np.ndarray], np.ndarray]) -> Callable[[Path], None]:
    def go(f: Path) -> None:
        from PIL import Image

        with Image.open(f / "depth.png") as im:
            metres = np.asarray(im, np.float64) * 0.001
        (f / "depth.png").unlink()
        np.save(f / "depth.npy", make(metres))

    return go


def _tiff(a: np.ndarray) -> bytes:
    import io

    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(a).save(buf, format="TIFF")
    return buf.getvalue()


def link(name: str, to: str) -> Callable[[Path], None]:
    def go(f: Path) -> None:
        (f / name).unlink()
        os.symlink(to, f / name)

    return go


# --- frames: intrinsics against the image, depth scales, depth dtypes, links -----------------------------------
def frame_cases() -> None:
    frame_case("good", "result", lambda f: None)
    frame_case("camera-width-height-swapped", "error", lambda f: camera(width=160, height=161)(f), "camera.json")
    frame_case("camera-fy-negative", "error", camera(fy=-615.0), "camera.json")
    frame_case("camera-fx-text", "error", camera(fx="615"), "camera.json")
    frame_case("camera-cx-far-outside", "any", camera(cx=1e5))
    frame_case("camera-fx-1e-3", "error", camera(fx=1e-3, fy=1e-3), "camera.json")
    frame_case("camera-width-bool", "error", camera(width=True), "camera.json")
    frame_case("camera-json-nan-literal", "error", lambda f: camera_text(
        (f / "camera.json").read_text().replace('"fx": 615.0', '"fx": NaN'))(f), "camera.json")  # fmt: skip
    frame_case("camera-json-duplicate-fx", "any", lambda f: camera_text(
        (f / "camera.json").read_text().replace('"fx": 615.0', '"fx": 615.0, "fx": -1'))(f))  # fmt: skip
    frame_case("camera-ros-layout-other-size", "error", camera_text(json.dumps({
        "image_width": 320, "image_height": 240, "camera_matrix": {"rows": 3, "cols": 3, "data": [615.0, 0, 80, 0,
        615.0, 80, 0, 0, 1]}})), "camera.json")  # fmt: skip
    frame_case("camera-K-and-fx-both", "error", camera(K=[615.0, 0, 80, 0, 615.0, 80, 0, 0, 1]), "camera.json")
    frame_case("camera-K-of-8-numbers", "error", camera_text(json.dumps({"width": 160, "height": 160,
               "K": [615.0, 0, 80, 0, 615.0, 80, 0, 0]})), "camera.json")  # fmt: skip
    frame_case("camera-distortion-nan", "error", camera(distortion=[float("nan")] * 5), "camera.json")
    frame_case("camera-yaml-and-json", "error", lambda f: (f / "camera.yaml").write_text(
        (f / "camera.json").read_text()), "camera")  # fmt: skip
    for label, scale in [("0", 0.0), ("negative", -0.001), ("1e-9", 1e-9), ("1e-6", 1e-6), ("10", 10.0),
                         ("text", "0.001"), ("true", True), ("list", [0.001]), ("1e308", 1e308)]:  # fmt: skip
        frame_case(f"depth_scale-{label}", "error", camera(depth_scale=scale), "camera.json")
    frame_case("depth_scale-0.0001", "any", camera(depth_scale=0.0001))  # a D400 at 0.1 mm: the depth 10x nearer
    frame_case("depth_units-and-scale-disagree", "error", camera(depth_units="mm", depth_scale=0.0001), "camera.json")
    frame_case("depth-npy-bool", "error", depth_npy(lambda d: d > 0), "depth.npy")
    frame_case("depth-npy-complex", "error", depth_npy(lambda d: d.astype(np.complex64)), "depth.npy")
    frame_case("depth-npy-int64-mm", "error", depth_npy(lambda d: (d * 1000).astype(np.int64)), "depth.npy")
    frame_case("depth-npy-structured", "error", depth_npy(lambda d: np.zeros(d.shape, [("z", "f4"), ("c", "f4")])),
               "depth.npy")  # fmt: skip
    frame_case("depth-npy-bigendian", "result", depth_npy(lambda d: d.astype(">f4")))
    frame_case("depth-npy-fortran", "result", depth_npy(lambda d: np.asfortranarray(d.astype("f4"))))
    frame_case("depth-npy-datetime", "error", depth_npy(lambda d: d.astype("datetime64[ms]")), "depth.npy")
    frame_case("depth-npy-0d", "error", depth_npy(lambda d: np.float32(0.3)), "depth.npy")

    def masks(make: Callable[[int, int], Any]) -> Callable[[Path], None]:
        def go(f: Path) -> None:
            made = make(160, 160)
            if isinstance(made, bytes):
                (f / "masks.png").write_bytes(made)
            else:
                made.save(f / "masks.png")

        return go

    from PIL import Image

    disc = np.zeros((160, 160), np.uint16)
    disc[60:100, 60:100] = 1
    frame_case("masks-16bit-one-fruit", "result", masks(lambda h, w: Image.fromarray(disc)))
    frame_case("masks-float-tiff-as-png", "error", masks(lambda h, w: _tiff(disc.astype(np.float32))), "masks.png")
    frame_case("masks-161x160", "error", masks(lambda h, w: Image.fromarray(np.pad(disc, ((0, 1), (0, 0))))),
               "masks.png")  # fmt: skip
    frame_case("masks-transposed-size", "error", masks(lambda h, w: Image.fromarray(disc[:, :120])), "masks.png")
    frame_case("masks-png-of-1x1", "error", masks(lambda h, w: Image.fromarray(disc[:1, :1])), "masks.png")
    frame_case("depth-png-161x160", "error", lambda f: Image.fromarray(np.pad(np.asarray(Image.open(
        f / "depth.png")), ((0, 1), (0, 0)))).save(f / "depth.png"), "depth is 160x161")  # fmt: skip
    frame_case("depth-png-all-one-unit", "error", lambda f: Image.fromarray(np.ones((160, 160), np.uint16)).save(
        f / "depth.png"), "depth")  # fmt: skip
    frame_case("depth-png-8bit-grey", "error", lambda f: Image.fromarray(np.full((160, 160), 200, np.uint8)).save(
        f / "depth.png"), "depth.png")  # fmt: skip

    def lying_npy(f: Path) -> None:
        """A .npy whose header claims a terabyte of float32 and holds 16 bytes."""
        (f / "depth.png").unlink()
        header = "{'descr': '<f4', 'fortran_order': False, 'shape': (500000, 500000), }"
        header += " " * (63 - len(header) % 64) + "\n"
        (f / "depth.npy").write_bytes(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode()
                                      + bytes(16))  # fmt: skip

    frame_case("depth-npy-header-claims-a-terabyte", "error", lying_npy, "depth.npy")
    frame_case("depth-link-to-dev-zero", "error", link("depth.png", "/dev/zero"), "depth.png")
    frame_case("color-link-to-dev-urandom", "error", link("color.png", "/dev/urandom"), "color.png")
    frame_case("camera-link-to-proc", "error", link("camera.json", "/proc/self/status"), "camera.json")
    frame_case("truth-link-to-dev-zero", "any", link("truth.json", "/dev/zero"))

    def recording(name: str, make: Callable[[Path], Any], expect: str = "any") -> None:
        def go() -> Any:
            rec = fixture(f"rec-{name}")
            rec.mkdir()
            shutil.copytree(small(), rec / "a")
            make(rec)
            o = r49.out(f"rec-{name}")
            return cli("detect", rec, "--output", o, "--method", "sphere", output=o)

        add(f"recording/{name}", expect, go)

    recording("holds-a-link-to-itself", lambda rec: os.symlink(rec, rec / "loop"))
    recording("holds-a-link-to-its-parent", lambda rec: os.symlink(rec.parent, rec / "up"))
    recording("holds-a-link-to-another-frame", lambda rec: os.symlink(rec / "a", rec / "b"), "result")
    recording("holds-a-link-to-dev", lambda rec: os.symlink("/dev", rec / "dev"))


# --- settings files an adversary writes ----------------------------------------------------------------------------
def settings_cases() -> None:
    def config(name: str, text: str | bytes, expect: str = "error") -> None:
        def go() -> Any:
            path = fixture(f"{name}.yaml")
            path.write_bytes(text if isinstance(text, bytes) else text.encode())
            return cli("settings", "--config", path)

        add(f"settings/{name}", expect, go, f"{name}.yaml" if expect == "error" else "")

    laughs = "a: &a [1, 1, 1, 1, 1, 1, 1, 1, 1]\n" + "".join(
        f"{chr(98 + k)}: &{chr(98 + k)} [{', '.join([f'*{chr(97 + k)}'] * 9)}]\n" for k in range(9))  # fmt: skip
    config("billion-laughs", laughs)
    config("billion-laughs-in-a-section", laughs.replace("a: &a", "x: &a", 1).replace("\nb:", "\nevidence:\n  b:", 1))
    config("python-tag", "evidence: !!python/object/apply:os.system ['true']\n")
    config("duplicate-section", "evidence: {}\nevidence: {}\n", "any")
    config("date-for-a-number", "extract:\n  min_points: 2001-12-14\n")
    config("depth-1e-400", "extract:\n  min_depth: 1.0e-400\n", "any")  # YAML reads 0.0: no least depth
    config("hex-int", "extract:\n  erode_px: 0x2\n", "any")  # YAML 1.1 reads 2
    config("sexagesimal", "extract:\n  min_points: 1:30\n", "any")  # YAML 1.1 reads 90
    config("bool-as-1", "occlusion:\n  enabled: 1\n")
    config("bool-as-yes-text", "occlusion:\n  enabled: 'yes'\n")
    config("int-as-30.5", "extract:\n  min_points: 30.5\n")
    config("depth-range-inverted", "extract:\n  min_depth: 2.0\n  max_depth: 0.5\n")
    config("section-a-list", "extract: [1, 2]\n")
    config("top-level-a-list", "- extract\n")
    config("empty-file", "", "any")
    config("only-a-comment", "# nothing\n", "any")
    config("null-document", "null\n", "any")
    config("bom-then-yaml", "\ufeffextract: {}\n", "any")
    config("utf16", "evidence: {}\n".encode("utf-16"), "any")
    config("merge-key", "base: &b {min_points: 5}\nextract:\n  <<: *b\n")
    config("key-of-100k-characters", "x" * 100_000 + ": 1\n")
    config("tab-indented", "extract:\n\tmin_points: 5\n")
    config("document-stream", "extract: {}\n---\nextract: {}\n")


# --- meshes (a folder of complete scans, as evaluate --fruit FOLDER reads it) ----------------------------------
def mesh_cases() -> None:
    rng = np.random.default_rng(5)
    d = rng.normal(size=(300, 3))
    sphere = 0.02 * d / np.linalg.norm(d, axis=1, keepdims=True)

    def ply(vertices: np.ndarray, faces: list[list[int]] | None, *, count: str = "uchar", index: str = "int",
            big: bool = False, faces_said: int | None = None) -> bytes:  # fmt: skip
        order = ">" if big else "<"
        head = ["ply", f"format binary_{'big' if big else 'little'}_endian 1.0", f"element vertex {len(vertices)}",
                "property float x", "property float y", "property float z"]  # fmt: skip
        if faces is not None:
            head += [f"element face {len(faces) if faces_said is None else faces_said}",
                     f"property list {count} {index} vertex_indices"]  # fmt: skip
        body = np.asarray(vertices, f"{order}f4").tobytes()
        c, i = {"uchar": "B", "uint": "I", "int": "i"}[count], {"int": "i", "uint": "I", "uchar": "B"}[index]
        for face in faces or []:
            body += struct.pack(f"{order}{c}{len(face)}{i}", len(face), *face)
        return ("\n".join([*head, "end_header"]) + "\n").encode() + body

    from scipy.spatial import ConvexHull

    hull = ConvexHull(sphere).simplices.tolist()

    def scans(name: str, files: dict[str, bytes | str], expect: str = "error", names: str = "") -> None:
        def go() -> Any:
            from symfruit.synthetic.shapes import load_scans

            folder = fixture(f"scans-{name}")
            folder.mkdir()
            for file, data in files.items():
                (folder / file).write_bytes(data if isinstance(data, bytes) else data.encode())
            fruits = load_scans(folder)
            for fruit in fruits:  # what the protocols draw from a scan: points over its surface
                fruit.sample(200, np.random.default_rng(0))
            return fruits

        add(f"mesh/{name}", expect, go, names)

    scans("good", {"s.ply": ply(sphere, hull)}, "result")
    scans("big-endian", {"s.ply": ply(sphere, hull, big=True)}, "result")
    scans("faces-all-degenerate", {"s.ply": ply(sphere, [[k, k, k] for k in range(300)])})
    scans("face-index-out-of-range", {"s.ply": ply(sphere, [*hull[:-1], [0, 1, 10**6]])})
    scans("face-index-negative", {"s.ply": ply(sphere, [*hull[:-1], [0, 1, -5]])})
    scans("face-of-255-corners", {"s.ply": ply(sphere, [list(range(255))])}, "any")
    scans("face-count-claims-4e9", {"s.ply": ply(sphere, [[0, 1, 2]], count="uint")[:-12]
                                    + struct.pack("<I", 4_000_000_000)})  # fmt: skip
    scans("face-element-lies", {"s.ply": ply(sphere, hull[:5], faces_said=10**9)})
    scans("face-of-two-corners", {"s.ply": ply(sphere, [[0, 1]] * 50)}, "any")
    scans("vertices-1e30", {"s.ply": ply(sphere * 1e32, hull)})
    scans("vertices-all-one-point", {"s.ply": ply(np.zeros((300, 3)), hull)})
    scans("vertices-on-a-plane", {"s.ply": ply(np.c_[sphere[:, :2], np.zeros(300)], None)})
    scans("obj-face-index-0", {"s.obj": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"})
    scans("obj-face-relative-beyond", {"s.obj": "".join(f"v {x} {y} {z}\n" for x, y, z in sphere) + "f -1 -2 -900\n"})
    scans("obj-face-of-one-corner", {"s.obj": "".join(f"v {x} {y} {z}\n" for x, y, z in sphere) + "f 1\n"}, "any")
    scans("obj-vertex-nan", {"s.obj": "".join(f"v {x} {y} {z}\n" for x, y, z in sphere) + "v nan 0 0\n"})
    scans("one-good-one-bad", {"a.ply": ply(sphere, hull), "b.ply": b"ply\nformat ascii 1.0\nend_header\n"}, "any")


# --- bags whose headers lie -------------------------------------------------------------------------------------
def bag_cases() -> None:
    data = BAG1.read_bytes()

    def field(raw: bytes, name: bytes, value: bytes) -> bytes:
        """``raw`` with the first header field ``name=`` given ``value`` (same length)."""
        at = raw.find(b"=".join([name, b""]))
        assert at > 0, name
        at += len(name) + 1
        return raw[:at] + value + raw[at + len(value) :]

    def bag(name: str, make: Callable[[bytes], bytes], names: str = "") -> None:
        def go() -> Any:
            path = fixture(f"{name}.bag")
            path.write_bytes(make(data))
            o = r49.out(f"bag-{name}")
            return cli("detect", path, "--output", o, "--method", "sphere", output=o)

        add(f"bag/{name}", "error", go, names or f"{name}.bag")

    bag("ros1-index_pos-past-the-end", lambda b: field(b, b"index_pos", struct.pack("<Q", 2**62)))
    bag("ros1-index_pos-zero", lambda b: field(b, b"index_pos", struct.pack("<Q", 0)))
    bag("ros1-conn_count-2^31", lambda b: field(b, b"conn_count", struct.pack("<I", 2**31)))
    bag("ros1-chunk_count-2^31", lambda b: field(b, b"chunk_count", struct.pack("<I", 2**31)))
    bag("ros1-bag-header-length-2^31", lambda b: b[:13] + struct.pack("<I", 2**31) + b[17:])
    bag("ros1-op-changed", lambda b: field(b, b"op", b"\x07"))
    bag("ros1-version-3", lambda b: b.replace(b"#ROSBAG V2.0", b"#ROSBAG V3.0", 1))

    def ros2(name: str, files: str, expect: str = "error") -> None:
        def go() -> Any:
            sys.path.insert(0, str(ROOT))
            from tests.conftest import disc_frame
            from tests.io.test_bags import write_ros2_bag

            color, depth = disc_frame([(60, 60)], radius=15)
            b = fixture(f"ros2-{name}")
            write_ros2_bag(b, color, (depth * 1000).astype(np.uint16), frames=1, storage="mcap")
            meta = (b / "metadata.yaml").read_text()
            own = next(b.glob("*.mcap")).name
            (b / "metadata.yaml").write_text(meta.replace(f"- {own}", files.replace("OWN", own)))
            o = r49.out(f"ros2-{name}")
            return cli("detect", b, "--output", o, "--method", "sphere", output=o)

        add(f"bag/{name}", expect, go, f"ros2-{name}" if expect == "error" else "")

    ros2("ros2-metadata-names-etc-hostname", "- /etc/hostname")
    ros2("ros2-metadata-names-a-parent-file", "- ../../OWN", "any")  # rosbags takes the name alone: its own file
    ros2("ros2-metadata-names-its-file-twice", "- OWN\n  - OWN", "any")
    ros2("ros2-metadata-names-dev-zero", "- /dev/zero")

    def file_room_taken() -> Any:
        """Two runs decompress a whole-file-compressed bag at once: the other takes the room after this one began."""
        from symfruit.io import bags

        sys.path.insert(0, str(ROOT))
        from tests.conftest import disc_frame
        from tests.io.test_bags import write_ros2_bag

        try:
            from compression import zstd  # type: ignore[import-not-found]
        except ImportError:
            from backports import zstd
        color, depth = disc_frame([(60, 60)], radius=15)
        good = fixture("file-room-good")
        write_ros2_bag(good, color, (depth * 1000).astype(np.uint16), frames=2, storage="mcap",
                       compression=("file", "zstd"))  # fmt: skip
        packed = next(good.glob("*.mcap.zstd"))
        b = fixture("file-room")
        b.mkdir()
        (b / "metadata.yaml").write_text((good / "metadata.yaml").read_text())
        (b / packed.name).write_bytes(zstd.compress(zstd.decompress(packed.read_bytes()) + bytes(64 << 20)))
        room = bags.bag_file_room
        rooms = iter([1 << 30])
        bags.bag_file_room = lambda: next(rooms, -1)
        try:
            o = r49.out("file-room")
            run = cli("detect", b, "--output", o, output=o)
        finally:
            bags.bag_file_room = room
        if "fell below" not in run.err:
            return f"DEFECT: decompressed on past the room another run took: {run.err.strip()[-160:]}"
        return run

    add("bag/ros2-file-compressed-while-another-run-takes-the-room", "error", file_room_taken, "file-room")


# --- ROS image messages --------------------------------------------------------------------------------------------
def ros_cases() -> None:
    from symfruit.ros.bench import example_images

    rgb, raw, cam = example_images()
    h, w = raw.shape
    header = SimpleNamespace(stamp=SimpleNamespace(sec=7, nanosec=5), frame_id="cam")

    def img(a: np.ndarray, kind: str, **change: Any) -> SimpleNamespace:
        a = np.ascontiguousarray(a)
        rows = a.reshape(a.shape[0], -1).view(np.uint8)
        msg = SimpleNamespace(height=a.shape[0], width=a.shape[1], encoding=kind, is_bigendian=0,
                              step=rows.shape[1], data=rows.tobytes(), header=header)  # fmt: skip
        for k, v in change.items():
            setattr(msg, k, v)
        return msg

    info = SimpleNamespace(width=w, height=h, header=header, distortion_model="plumb_bob",
                           k=[cam.fx, 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0], d=[0.0] * 5)  # fmt: skip
    procs: list[Any] = []

    def proc() -> Any:
        if not procs:
            from symfruit.ros.core import FrameProcessor

            procs.append(FrameProcessor(masks="color", method="sphere"))
        return procs[0]

    def frame(colour: dict[str, Any], depth: dict[str, Any]) -> Callable[[], Any]:
        return lambda: proc().process(img(rgb, "rgb8", **colour), img(raw, "16UC1", **depth), info)

    add("ros/good", "result", frame({}, {}))
    for flag in (2, 255, "1", None):
        add(f"ros/depth-is_bigendian={flag!r}", "error", frame({}, {"is_bigendian": flag}), "depth image")
    add("ros/colour-is_bigendian=2", "error", frame({"is_bigendian": 2}, {}), "colour image")
    add("ros/depth-step-a-terabyte", "error", frame({}, {"step": 2**40}), "depth image")
    add("ros/depth-height-2^31", "error", frame({}, {"height": 2**31, "width": 1}), "depth image")
    add("ros/depth-encoding-with-a-space", "error", frame({}, {"encoding": "16UC1 "}), "depth image")
    add("ros/depth-data-memoryview", "result", frame({}, {"data": memoryview(raw.tobytes())}))


# --- run tables: centres and numbers no run writes ------------------------------------------------------------------
def table_cases() -> None:
    from symfruit.season.table import frame_rows

    def rows(**fruit: Any) -> Callable[[], Any]:
        record = {"frame": "f", "fruits": [{"id": 1, "box": {"size": [0.03, 0.03, 0.03]}, **fruit}]}
        return lambda: frame_rows(json.loads(json.dumps(record)), "rec")

    add("table/centre-nan-in-part", "error", rows(centre=[0.0, float("nan"), 0.3]))
    add("table/centre-null-in-part", "error", rows(centre=[None, 0.0, 0.3]))
    add("table/centre-1e6-m", "error", rows(centre=[0.0, 0.0, 1e6]))
    add("table/centre-400-digits", "error", rows(centre=[10**400, 0.0, 0.3]))
    add("table/confidence-400-digits", "error", rows(centre=[0.0, 0.0, 0.3], confidence=10**400))
    add("table/id-400-digits", "error", rows(centre=[0.0, 0.0, 0.3], id=10**400))

    def report(name: str, change: dict[str, Any]) -> None:
        def go() -> Any:
            import pyarrow as pa
            import pyarrow.parquet as pq

            sys.path.insert(0, str(ROOT))
            from tests.season.test_report import _run

            run = fixture(f"report-{name}")
            _run(run)
            t = pq.read_table(run / "detections.parquet")
            edited = [dict(r, **change) if k == 0 else r for k, r in enumerate(t.to_pylist())]
            pq.write_table(pa.Table.from_pylist(edited, schema=t.schema), run / "detections.parquet")
            return cli("report", run)

        add(f"report/{name}", "error", go, "detections.parquet")

    report("centre-nan", {"centre_x": float("nan")})
    report("centre-inf", {"centre_z": float("inf")})
    report("centre-in-part", {"centre_y": None})
    report("centre-1e6-m", {"centre_x": 1e6})


# --- the command line at its bounds -------------------------------------------------------------------------------
def cli_cases() -> None:
    def detect(name: str, expect: str, *extra: Any, names: str = "") -> None:
        def go() -> Any:
            o = r49.out(f"cli-{name}")
            return cli("detect", small(), "--output", o, "--method", "sphere", *extra, output=o)

        add(f"cli/detect-{name}", expect, go, names)

    for value in ("0", "-1", "0.5", "nan", "inf", "-inf", "1e9", "86401", "1e400", "30s"):
        detect(f"no-worker-timeout={value}", "error", "--workers", "1", "--no-worker-timeout", value,
               names="no-worker-timeout")  # fmt: skip
    detect("no-worker-timeout-without-a-cluster", "error", "--no-worker-timeout", "30", names="no-worker-timeout")
    detect("chunk=10001", "error", "--workers", "1", "--chunk", "10001", names="chunk")
    detect("workers=257", "error", "--workers", "257", names="workers")
    detect("workers=2^63", "error", "--workers", str(2**63), names="workers")
    for value in ("-1", "2^64", "1e3"):
        add(f"cli/scenes-seed={value}", "error",
            lambda v=value: cli("scenes", r49.out("cli-scenes"), "--seed", str(2**64) if v == "2^64" else v, "--n",
                                "1"), "seed")  # fmt: skip
    add("cli/scenes-n=100001", "error", lambda: cli("scenes", r49.out("cli-scenes-n"), "--n", "100001"), "--n")
    add("cli/scenes-ripe=51", "error", lambda: cli("scenes", r49.out("cli-scenes-r"), "--ripe", "51"), "--ripe")
    add("cli/evaluate-views=100001", "error", lambda: cli("evaluate", "--protocol", "camera", "--views", "100001",
                                                          "--output", r49.out("cli-ev")), "views")  # fmt: skip
    add("cli/evaluate-jobs=257", "error", lambda: cli("evaluate", "--protocol", "paper", "--jobs", "257",
                                                      "--output", r49.out("cli-ev2")), "jobs")  # fmt: skip
    add("cli/bench-repeat=100001", "error", lambda: cli("bench", "--repeat", "100001"), "repeat")
    add("cli/bench-points=5000001", "error", lambda: cli("bench", "--points", "5000001"), "points")

    def many_classes() -> Any:
        sys.path.insert(0, str(ROOT))
        from tests.season.test_report import _run

        run = fixture("report-classes")
        _run(run)
        return cli("report", run, "--classes", ",".join(str(k) for k in range(1, 10_001)))

    add("cli/report-classes-of-10000", "error", many_classes, "classes")
    add("cli/segment-depth-scale=nan", "error", lambda: cli(
        "segment", small() / "color.png", "--output", r49.out("cli-seg"), "--depth", small() / "depth.png",
        "--camera", small() / "camera.json", "--depth-scale", "nan"), "depth")  # fmt: skip
    add("cli/segment-depth-scale=0", "error", lambda: cli(
        "segment", small() / "color.png", "--output", r49.out("cli-seg0"), "--depth", small() / "depth.png",
        "--camera", small() / "camera.json", "--depth-scale", "0"), "depth")  # fmt: skip


def main() -> int:
    return r49.run_main(
        __doc__,
        (frame_cases, settings_cases, mesh_cases, bag_cases, ros_cases, table_cases, cli_cases),
        CASES,
        prefix="robust51-",
        limit=LIMIT_S,
        width=56,
    )


if __name__ == "__main__":
    sys.exit(main())
