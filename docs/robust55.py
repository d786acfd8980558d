"""Stop 55: bad and adversarial input past stops 43-53's sweeps (robust55).

What no earlier sweep tried (their lists: docs/robust47.md-robust53.md): PLY files of plyfile's short type names
(``u1``, ``f4``), of types PLY lacks, of coordinates that are lists, big-endian, faces only, headers of 200,000
properties; meshes whose faces are big-endian, of a float count, of two corners; OBJ in Latin-1; images that are
animations (APNG, GIF) as colour, depth and labels, PNGs whose text or colour-profile chunks decompress past
Pillow's bounds, whose chunk lengths run past the file or whose checksums are wrong, EXIF orientations past 8;
ROS 2 sqlite3 bags cut short, emptied, whose rows hold text, without their database or its tables, whose metadata
names the other storage; ROS 1 bags (plain, bz2 and lz4 chunks) cut short in their index, zeroed inside, of no
frame or no depth message, of a depth topic of another type; ``--scheduler`` addresses whose host can be no name,
and the warnings a frame gives on a Dask worker.

Cases run in this process under an alarm and are judged as docs/robust47.py judges them (through robust49's
``sweep``); every case's message is also searched for the words of the libraries under symfruit that earlier judges
let through (``_OTHERS``: Pillow's ``MAX_TEXT_CHUNK``, apsw's ``CorruptError``, rosbags' ``Bag index looks
damaged``, the codec's, numpy's ``setting an array element``, plyfile's list of type names, ...). A case that checks
a rule itself returns ``DEFECT: ...`` when it is broken.

::

    PYTHONPATH=src python docs/robust55.py                 # every case (fixtures in a temporary folder)
    PYTHONPATH=src python docs/robust55.py --only ros1/ --defects
"""

from __future__ import annotations

import contextlib
import re
import shutil
import sqlite3
import struct
import sys
import warnings
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import robust47 as r47
import robust49 as r49
import robust51 as r51

LIMIT_S = 120
ROOT, fixture, cli, Run, small = r47.ROOT, r49.fixture, r47.cli, r47.Run, r51.small
CASES: list[tuple[str, str, Callable[[], Any], str]] = []
#: Words of the libraries under symfruit (and of Python) that robust47-53's judges let through.
_OTHERS = re.compile(
    r"MAX_TEXT_CHUNK|MAX_TEXT_MEMORY|Truncated File Read|codec can't|Bag index looks damaged|AssertionError|"
    r"CorruptError|setting an array element|not in \['|unsupported operand|string argument without|'idna'|"
    r"maybe: ipv6|SymfruitWarning: "
)


def _error() -> type[Exception]:
    from symfruit import SymfruitError

    return SymfruitError


def _said(value: Any) -> str:
    """Everything a case said: an error's message, or a run's output and errors.json."""
    if not isinstance(value, Run):
        return ""
    said = value.err + value.out
    record = value.output / "errors.json" if value.output is not None else None
    if record is not None and record.is_file():
        said += record.read_text()
    return said


def add(name: str, expect: str, fn: Callable[[], Any], names: str = "") -> None:
    def checked() -> Any:
        try:
            value = fn()
        except _error() as exc:
            if found := _OTHERS.search(str(exc)):
                return (
                    f"DEFECT: another library's words ({found.group(0)!r}): {str(exc).replace(str(r47.T), 'T')[:160]}"
                )
            raise
        if found := _OTHERS.search(_said(value)):
            return (
                f"DEFECT: another library's words ({found.group(0)!r}): {_said(value).replace(str(r47.T), 'T')[-200:]}"
            )
        return value

    CASES.append((name, expect, checked, names))


def _written(name: str, data: bytes) -> Path:
    p = fixture(name)
    p.write_bytes(data)
    return p


# --- PLY clouds and meshes ----------------------------------------------------------------------------------------
def ply_cases() -> None:
    from symfruit.io import read_cloud, read_mesh

    pts = np.random.default_rng(0).normal(0, 0.02, (200, 3)) + [0, 0, 0.3]
    xyz = "property float x\nproperty float y\nproperty float z\n"

    def header(fmt: str, n: int, props: str = xyz, rest: str = "") -> str:
        return f"ply\nformat {fmt} 1.0\nelement vertex {n}\n{props}{rest}end_header\n"

    def cloud(name: str, expect: str, text: str, body: bytes = b"") -> None:
        add(f"ply/{name}", expect, lambda: read_cloud(_written(f"{name}.ply", text.encode() + body)), f"{name}.ply")

    def mesh(name: str, expect: str, text: str, body: bytes = b"", suffix: str = ".ply") -> None:
        add(f"mesh/{name}", expect, lambda: read_mesh(_written(f"{name}{suffix}", text.encode() + body)),
            f"{name}{suffix}")  # fmt: skip

    rows = np.zeros(200, dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("r", "u1"), ("g", "u1"), ("b", "u1")])
    rows["x"], rows["y"], rows["z"] = pts.T
    short = "property f4 x\nproperty f4 y\nproperty f4 z\nproperty u1 red\nproperty u1 green\nproperty b1 blue\n"
    cloud("short-type-names", "result", header("binary_little_endian", 200, short), rows.tobytes())
    cloud("short-type-names-a-byte-short", "error", header("binary_little_endian", 200, short), rows.tobytes()[:-1])
    cloud("type-int64", "error", header("ascii", 3, "property int64 x\nproperty float y\nproperty float z\n"),
          b"1 2 3\n4 5 6\n7 8 9\n")  # fmt: skip
    cloud("type-listy", "error", header("ascii", 3, xyz + "property listy q\n"), b"1 2 3 0\n4 5 6 0\n7 8 9 0\n")
    cloud("x-a-list", "error", header("ascii", 3, "property list uchar float x\nproperty float y\nproperty float z\n"),
          b"1 1 2 3\n1 4 5 6\n1 7 8 9\n")  # fmt: skip
    cloud("big-endian", "result", header("binary_big_endian", 200), pts.astype(">f4").tobytes())
    cloud("big-endian-double", "result", header("binary_big_endian", 200, xyz.replace("float", "double")),
          pts.astype(">f8").tobytes())  # fmt: skip
    cloud("faces-only", "error", "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
          "end_header\n", b"3 0 1 2\n")  # fmt: skip
    cloud("no-vertex", "any", header("ascii", 0))
    cloud("two-x", "error", header("ascii", 3, "property float x\n" + xyz), b"1 1 2 3\n1 4 5 6\n1 7 8 9\n")
    cloud("format-2.0", "error", header("ascii", 3).replace("1.0", "2.0"), b"1 2 3\n4 5 6\n7 8 9\n")
    cloud("ascii-row-too-long", "error", header("ascii", 3), b"1 2 3 4\n4 5 6\n7 8 9\n")
    many = "".join(f"property float p{k}\n" for k in range(200_000))
    cloud("200000-properties", "error", header("binary_little_endian", 1, many + xyz), b"\0" * 800_012)
    cloud("nan-big-endian", "any", header("binary_big_endian", 3), np.full((3, 3), np.nan, ">f4").tobytes())
    tri = "element face 1\nproperty list uchar int vertex_indices\n"
    corners = b"0 0 0\n1 0 0\n0 1 0\n"
    mesh("face-past-the-vertices", "error", header("ascii", 3, xyz, tri), corners + b"3 0 1 5\n")
    mesh("face-negative", "error", header("ascii", 3, xyz, tri), corners + b"3 0 1 -1\n")
    mesh("face-type-int64", "error", header("ascii", 3, xyz, tri.replace("int ", "int64 ")), corners + b"3 0 1 2\n")
    mesh(
        "face-big-endian",
        "result",
        header("binary_big_endian", 3, xyz, tri),
        np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], ">f4").tobytes() + b"\x03" + np.array([0, 1, 2], ">i4").tobytes(),
    )
    mesh("face-count-float", "any", header("ascii", 3, xyz, tri.replace("uchar", "float")), corners + b"3 0 1 2\n")
    mesh("face-of-two-corners", "any", header("ascii", 3, xyz, tri), corners + b"2 0 1\n")
    mesh(
        "face-count-4e9",
        "error",
        header("binary_little_endian", 3, xyz, tri.replace("uchar", "uint")),
        np.zeros((3, 3), "<f4").tobytes() + struct.pack("<I", 4_000_000_000) + np.array([0, 1, 2], "<i4").tobytes(),
    )
    mesh("obj-latin-1", "error", "", b"# caf\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", ".obj")
    mesh("obj-face-of-two", "any", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", b"", ".obj")
    mesh("obj-face-past-the-start", "error", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", b"", ".obj")


# --- images -------------------------------------------------------------------------------------------------------
def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def image_cases() -> None:
    from PIL import Image

    from symfruit.io.images import read_color, read_depth_units, read_labels

    rng = np.random.default_rng(0)
    rgb = rng.integers(0, 255, (40, 50, 3), dtype=np.uint8)
    d16 = rng.integers(300, 1000, (40, 50)).astype(np.uint16)
    readers = {"colour": read_color, "depth": read_depth_units, "labels": read_labels}

    def saved(name: str, frames: list[Any], **kw: Any) -> Path:
        p = fixture(name)
        frames[0].save(p, format=kw.pop("format", None) or "PNG", save_all=len(frames) > 1,
                       append_images=frames[1:], **kw)  # fmt: skip
        return p

    def image(name: str, expect: str, use: str, make: Callable[[], Path]) -> None:
        add(f"image/{name}-as-{use}", expect, lambda: readers[use](make()), name)

    image("apng-of-two", "error", "depth", lambda: saved("apng.png", [Image.fromarray(d16), Image.fromarray(d16 + 5)]))
    image("apng-of-two", "result", "colour", lambda: saved("apngc.png", [Image.fromarray(rgb), Image.fromarray(rgb)]))
    gif = [Image.fromarray((rgb[..., 0] > 128).astype(np.uint8)), Image.fromarray((rgb[..., 1] > 128).astype(np.uint8))]
    image("gif-named-png", "error", "labels", lambda: saved("gif.png", gif, format="GIF"))
    image("gif-named-png", "result", "colour", lambda: saved("gifc.png", gif, format="GIF"))
    image("la", "result", "colour", lambda: saved("la.png", [Image.fromarray(rgb[..., 0]).convert("LA")]))
    image("16-bit-grey", "result", "colour", lambda: saved("i16.png", [Image.fromarray(d16)]))
    image("float-tiff", "error", "colour", lambda: saved("f.tiff", [Image.fromarray(d16.astype(np.float32))],
                                                         format="TIFF"))  # fmt: skip
    image("palette", "error", "depth", lambda: saved("p.png", [Image.fromarray(rgb).convert("P")]))

    def exif(orientation: int) -> Path:
        im = Image.fromarray(rgb)
        tags = im.getexif()
        tags[0x0112] = orientation
        return saved(f"exif{orientation}.jpg", [im], format="JPEG", exif=tags.tobytes())

    for orientation in (6, 9, 65535):
        image(f"exif-orientation-{orientation}", "result", "colour", lambda o=orientation: exif(o))
    plain = fixture("plain.png")
    Image.fromarray(rgb).save(plain)
    data = plain.read_bytes()

    def with_chunk(name: str, chunk: bytes, after: bool = False) -> Callable[[], Path]:
        at = len(data) - 12 if after else 8 + 25
        return lambda: _written(name, data[:at] + chunk + data[at:])

    huge = zlib.compress(b"\0" * 5_000_000)
    for use in ("colour", "depth"):
        image("icc-profile-of-5-mb", "error", use, with_chunk(f"icc-{use}.png", _chunk(b"iCCP", b"p\0\0" + huge)))
        image("ztxt-of-5-mb-after-the-pixels", "error", use,
              with_chunk(f"ztxt-{use}.png", _chunk(b"zTXt", b"k\0\0" + huge), after=True))  # fmt: skip
    image("80-ztxt-of-900-kb", "error", "colour", with_chunk("many.png", b"".join(
        _chunk(b"zTXt", b"k%d\0\0" % i + zlib.compress(b"a" * 900_000)) for i in range(80))))  # fmt: skip
    image("text-of-20-mb-uncompressed", "result", "colour",
          with_chunk("t20.png", _chunk(b"tEXt", b"k\0" + b"a" * 20_000_000)))  # fmt: skip
    image("chunk-length-past-the-end", "error", "colour",
          with_chunk("length.png", struct.pack(">I", 0x7FFFFFFF) + b"tEXtk\0abc"))  # fmt: skip
    image("chunk-checksum-wrong", "error", "colour", with_chunk("crc.png", _chunk(b"tEXt", b"k\0abc")[:-4] + bytes(4)))
    image("exif-chunk-of-10-mb", "result", "colour", with_chunk("exif.png", _chunk(b"eXIf", b"MM\0*" + bytes(10**7))))

    def crc_said_as_damaged_chunk() -> Any:
        try:
            read_color(with_chunk("crc2.png", _chunk(b"tEXt", b"k\0abc")[:-4] + bytes(4))())
        except _error() as exc:
            if "no image, or a damaged header" in str(exc):
                return f"DEFECT: a whole header called damaged for a chunk's checksum: {str(exc)[-120:]}"
            raise
        return "DEFECT: read"

    add("image/chunk-checksum-wrong-said-so", "error", crc_said_as_damaged_chunk, "crc2.png")


# --- ROS 2 bags ---------------------------------------------------------------------------------------------------
def _bag_run(name: str, bag: Path) -> Run:
    o = r49.out(name)
    return cli("detect", bag, "--output", o, "--method", "sphere", output=o)


def ros2_cases() -> None:
    sys.path.insert(0, str(ROOT))
    from tests.conftest import disc_frame
    from tests.io.test_bags import write_ros2_bag

    color, depth = disc_frame([(60, 60), (110, 60)], radius=15)
    mm = (depth * 1000).astype(np.uint16)

    def bag(name: str, expect: str, change: Callable[[Path], Any], storage: str = "sqlite3") -> None:
        def go() -> Any:
            p = fixture(f"ros2-{name}")
            write_ros2_bag(p, color, mm, frames=3, storage=storage)
            change(p)
            return _bag_run(f"ros2-{name}", p)

        add(f"ros2/{name}", expect, go, f"ros2-{name}")

    def db(p: Path) -> Path:
        return next(p.glob("*.db3"))

    def cut(share: float, suffix: str = ".db3") -> Callable[[Path], None]:
        def go(p: Path) -> None:
            f = next(p.glob(f"*{suffix}"))
            f.write_bytes(f.read_bytes()[: int(f.stat().st_size * share)])

        return go

    def sql(*statements: str) -> Callable[[Path], None]:
        def go(p: Path) -> None:
            with contextlib.closing(sqlite3.connect(db(p))) as con:
                for s in statements:
                    con.execute(s)
                con.commit()

        return go

    bag("sqlite-whole", "result", lambda p: None)
    for share in (0.1, 0.5, 0.9, 0.99):
        bag(f"sqlite-cut-to-{share:.0%}", "error", cut(share))
    bag("sqlite-no-messages", "error", sql("delete from messages"))
    bag("sqlite-messages-cut-to-40-bytes", "failed", sql("update messages set data = substr(data, 1, 40)"))
    bag("sqlite-messages-text", "error", sql("update messages set data = 'hello'"))
    bag("sqlite-timestamps-text", "error", sql("update messages set timestamp = 'x'"))
    bag("sqlite-message-of-no-topic", "any", sql("update messages set topic_id = 99 where id = 1"))
    bag("sqlite-without-topics-table", "error", sql("drop table topics"))
    bag("sqlite-of-garbage", "error", lambda p: db(p).write_bytes(b"SQLite format 3\0" + b"\xff" * 5000))
    bag("sqlite-database-missing", "error", lambda p: db(p).unlink())
    bag("sqlite-junk-wal-beside", "result", lambda p: Path(f"{db(p)}-wal").write_bytes(bytes(100)))

    def retitle(old: str, new: str) -> Callable[[Path], None]:
        return lambda p: (p / "metadata.yaml").write_text((p / "metadata.yaml").read_text().replace(old, new))

    bag("sqlite-named-mcap", "error", retitle("storage_identifier: sqlite3", "storage_identifier: mcap"))
    bag("mcap-named-sqlite3", "error", retitle("storage_identifier: mcap", "storage_identifier: sqlite3"), "mcap")
    bag("mcap-cut-to-97%", "error", cut(0.97, ".mcap"), "mcap")
    bag("mcap-count-of-9e11", "any", retitle("message_count: 9", "message_count: 900000000000"), "mcap")

    def escape(p: Path) -> None:
        meta = (p / "metadata.yaml").read_text()
        (p / "metadata.yaml").write_text(re.sub(r"relative_file_paths:\n(\s+- )\S+",
                                                r"relative_file_paths:\n\1../../../etc/passwd", meta))  # fmt: skip

    bag("mcap-file-path-out-of-the-bag", "error", escape, "mcap")


# --- ROS 1 bags ---------------------------------------------------------------------------------------------------
def ros1_cases() -> None:
    sys.path.insert(0, str(ROOT))
    from tests.io.test_bags import _ros1_bag

    def bag(name: str, expect: str, compression: str | None, change: Callable[[bytes], bytes]) -> None:
        def go() -> Any:
            whole = _ros1_bag(fixture(f"ros1-{name}-whole.bag"), compression).read_bytes()
            p = _written(f"ros1-{name}.bag", change(whole))
            return _bag_run(f"ros1-{name}", p)

        add(f"ros1/{name}", expect, go, f"ros1-{name}.bag")

    for compression in (None, "BZ2", "LZ4"):
        kind = (compression or "plain").lower()
        bag(f"{kind}-whole", "result", compression, lambda d: d)
        for share in (0.5, 0.95, 0.999):
            bag(f"{kind}-cut-to-{share:.1%}", "error", compression, lambda d, s=share: d[: int(len(d) * s)])
        for at in (0.3, 0.6):
            bag(f"{kind}-64-bytes-zeroed-at-{at:.0%}", "any", compression,
                lambda d, a=at: d[: int(len(d) * a)] + bytes(64) + d[int(len(d) * a) + 64 :])  # fmt: skip


# --- Dask: scheduler addresses, the workers' warnings ----------------------------------------------------------------
def cluster_cases() -> None:
    def address(name: str, scheduler: str) -> None:
        def go() -> Any:
            o = r49.out(f"address-{name}")
            return cli("detect", small(), "--output", o, "--method", "raw", "--scheduler", scheduler, output=o)

        add(f"cluster/address-{name}", "error", go)

    address("bracket-unclosed", "tcp://[::1")
    address("bracket-unopened", "tcp://::1]:8786")
    address("name-part-of-300", f"tcp://{'a' * 300}:1")
    address("name-of-400", f"tcp://{'ab.' * 133}c:1")
    address("name-part-empty", "tcp://a..b:8786")

    def workers_warn() -> Any:
        rec = fixture("warning-rec")
        for k in range(3):
            shutil.copytree(small(), rec / f"f_{k}")  # its principal point lies outside the image: a warning a frame
        o = r49.out("warning-rec")
        with warnings.catch_warnings():
            warnings.simplefilter("default")
            run = cli("detect", rec, "--output", o, "--method", "raw", "--workers", "1", output=o)
        if run.rc == 0 and (run.err.count("principal point") != 1 or "2 more frames gave a warning" not in run.err):
            return f"DEFECT: the workers' warnings not given by the client once a recording: {run.err[-200:]!r}"
        return run

    add("cluster/workers-warnings-once-a-recording", "result", workers_warn)


def main() -> int:
    return r49.run_main(__doc__ or "", (ply_cases, image_cases, ros2_cases, ros1_cases, cluster_cases), CASES,
                        prefix="robust55-", limit=LIMIT_S, width=56)  # fmt: skip


if __name__ == "__main__":
    sys.exit(main())
