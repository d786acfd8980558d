"""Stop 49: bad and adversarial input past stops 43-48's sweeps (robust49).

New kinds of file input, given to every command's file inputs (as docs/robust48.py's ``kinds`` are): a FIFO
(a reader that opens it waits for a writer for ever), a symbolic link to itself (a loop), a dangling link,
JSON and YAML nested 100,000 deep, numbers of 5,000 digits; then frames whose depth or masks PNG is of an
unexpected mode (palette, 1-bit, grey with alpha, 16-bit grey as colour, CMYK JPEG named .png), a PNG header
of width 0, frame and recording names that are no UTF-8 or hold a newline, paths of 5,000 characters, a folder
of 2,000 empty frame folders, outputs that are a FIFO or a link to a file elsewhere, and an MCAP chunk that
expands past its stated size (a decompression bomb). A local Dask cluster whose frame kills every worker is
tested in ``tests/season/test_cluster.py`` (a minute a run; not repeated here).

Cases run in this process under an alarm and are judged as docs/robust47.py judges them (its ``judge``, ``cli``
and helpers are imported; robust48's classifier of Python's words too).

::

    PYTHONPATH=src python docs/robust49.py                 # every case (fixtures in a temporary folder)
    PYTHONPATH=src python docs/robust49.py --only fifo --defects
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import signal
import struct
import sys
import tempfile
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import robust47 as r47
import robust48 as r48

ROOT = r47.ROOT
#: A case's alarm (s): a FIFO that is opened for reading blocks until this fires.
LIMIT_S = 60
CASES: list[tuple[str, str, Callable[[], Any], str]] = []
cli, Run = r47.cli, r47.Run
F640 = ROOT / "examples/realsense/aligned_00000"
PLY = ROOT / "examples/strawberry_partial.ply"
CAM = F640 / "camera.json"


def add(name: str, expect: str, fn: Callable[[], Any], names: str = "") -> None:
    CASES.append((name, expect, fn, names))


def T() -> Path:
    return r47.T


def fixture(name: str) -> Path:
    p = T() / "cases49" / name
    if p.is_dir() and not p.is_symlink():
        shutil.rmtree(p)
    elif p.exists() or p.is_symlink():
        p.unlink()
    p.parent.mkdir(parents=True, exist_ok=True)
    return p


def out(name: str) -> Path:
    return r47.out_dir(f"r49-{name}")


# --- the new kinds of bad file ---------------------------------------------------------------------------------
def deep_json(p: Path) -> None:
    p.write_text("[" * 100_000 + "]" * 100_000)


def deep_yaml(p: Path) -> None:
    p.write_text("a: " + "[" * 100_000 + "]" * 100_000 + "\n")


def long_number(p: Path) -> None:
    text = "1" + "0" * 5000
    p.write_text(json.dumps({"fx": 615.0, "fy": 615.0, "cx": 320.0, "cy": 240.0, "width": 640, "height": 480})
                 .replace("640", text))  # fmt: skip


def kinds(suffix: str) -> dict[str, Callable[[Path], None]]:
    structured = suffix in (".json", ".yaml", ".yml")
    made: dict[str, Callable[[Path], None]] = {
        "fifo": lambda p: os.mkfifo(p),
        "link-loop": lambda p: p.symlink_to(p.name),
        "link-dangling": lambda p: p.symlink_to(p.name + ".gone"),
    }
    if structured:
        made["deep-json"] = deep_json
        made["deep-yaml"] = deep_yaml
        made["long-number"] = long_number
    return made


def file_cases() -> None:
    settings = T() / "cases49-good.yaml"
    settings.write_text("evidence:\n  rays: 64\n")

    def each(label: str, suffix: str, argv: Callable[[Path], list[Any]], output: Callable[[], Any] = lambda: None,
             expect: dict[str, str] | None = None) -> None:  # fmt: skip
        for kind, make in kinds(suffix).items():

            def run(kind: str = kind, make: Callable[[Path], None] = make) -> Run:
                p = fixture(f"{label.replace('/', '_')}-{kind}{suffix}")
                make(p)
                return cli(*argv(p), output=output())

            add(f"file/{label}/{kind}", (expect or {}).get(kind, "error"), run,
                f"{label.replace('/', '_')}-{kind}{suffix}")  # fmt: skip

    each("complete/cloud", ".ply", lambda p: ["complete", p])
    each("complete/cloud-npy", ".npy", lambda p: ["complete", p])
    each("complete/cloud-xyz", ".xyz", lambda p: ["complete", p])
    each("complete/camera", ".json", lambda p: ["complete", PLY, "--camera", p])
    each("complete/camera-yaml", ".yaml", lambda p: ["complete", PLY, "--camera", p])
    each("settings/config", ".yaml", lambda p: ["settings", "--config", p])
    each("settings/config-json", ".json", lambda p: ["settings", "--config", p])
    each("detect/input-png", ".png", lambda p: ["detect", p, "--output", out("d1")])
    each("detect/input-bag", ".bag", lambda p: ["detect", p, "--output", out("d2")])
    each("detect/config", ".yaml", lambda p: ["detect", F640, "--output", out("d3"), "--config", p])
    each("detect/masks-json", ".json", lambda p: ["detect", F640, "--output", out("d5"), "--masks", p])
    each("segment/input", ".png", lambda p: ["segment", p, "--output", out("s1")])
    each(
        "segment/camera",
        ".json",
        lambda p: ["segment", F640 / "color.png", "--output", out("s4"), "--depth", F640 / "depth.png", "--camera", p],
    )
    each("segment/masks", ".json", lambda p: ["segment", F640 / "color.png", "--output", out("s5"), "--masks", p])
    each(
        "evaluate/truth",
        ".json",
        lambda p: ["evaluate", "--protocol", "masks", "--images", F640, "--truth", p, "--output", out("e1")],
    )
    each(
        "evaluate/config",
        ".yaml",
        lambda p: ["evaluate", "--quick", "--config", p, "--output", out("e2"), "--methods", "raw"],
    )

    # a frame folder whose own files are of these kinds (each file of the frame in turn)
    for file in ("color.png", "depth.png", "camera.json"):
        for kind, make in kinds(Path(file).suffix).items():

            def frame(file: str = file, make: Callable[[Path], None] = make, kind: str = kind) -> Run:
                f = fixture(f"frame-{file}-{kind}")
                shutil.copytree(F640, f)
                (f / file).unlink()
                make(f / file)
                return cli("detect", f, "--output", out(f"fr-{file}-{kind}"), "--method", "sphere")

            add(f"frame/{file}/{kind}", "error", frame, file)


# --- images of unexpected modes and headers --------------------------------------------------------------------
def _png_chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def png_of_size(width: int, height: int) -> bytes:
    """A PNG whose header states ``width`` x ``height`` (8-bit grey) and holds one empty row of data."""
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + _png_chunk(b"IHDR", ihdr) + _png_chunk(b"IDAT", zlib.compress(b"\0"))
            + _png_chunk(b"IEND", b""))  # fmt: skip


def image_cases() -> None:
    from PIL import Image

    depth = np.asarray(Image.open(F640 / "depth.png"))
    labels = np.zeros(depth.shape, np.uint8)
    labels[200:260, 300:360] = 1

    def frame_with(name: str, file: str, save: Callable[[Path], None], expect: str, names: str = "") -> None:
        def run() -> Run:
            f = fixture(f"img-{name}")
            shutil.copytree(F640, f)
            (f / file).unlink()
            save(f / file)
            return cli("detect", f, "--output", out(f"img-{name}"), "--method", "sphere")

        add(f"image/{name}", expect, run, names or file)

    frame_with(
        "depth-palette",
        "depth.png",
        lambda p: Image.fromarray((depth // 256).astype(np.uint8)).convert("P").save(p),
        "error",
    )
    frame_with("depth-1bit", "depth.png", lambda p: Image.fromarray(depth > 0).save(p), "error")
    frame_with(
        "depth-grey-alpha",
        "depth.png",
        lambda p: Image.fromarray(np.dstack([(depth // 256).astype(np.uint8)] * 2), "LA").save(p),
        "error",
    )
    frame_with("depth-width-0", "depth.png", lambda p: p.write_bytes(png_of_size(0, 480)), "error")
    frame_with("colour-width-0", "color.png", lambda p: p.write_bytes(png_of_size(0, 480)), "error")
    frame_with("colour-1x1", "color.png", lambda p: Image.new("RGB", (1, 1)).save(p), "error", names="colour")
    frame_with(
        "colour-cmyk-jpeg-as-png",
        "color.png",
        lambda p: Image.open(F640 / "color.png").convert("CMYK").save(p, "JPEG"),
        "any",
    )
    frame_with("colour-16bit-grey", "color.png", lambda p: Image.fromarray(depth).save(p), "any")

    def masks_with(name: str, save: Callable[[Path], None], expect: str) -> None:
        def run() -> Run:
            p = fixture(f"masks-{name}.png")
            save(p)
            return cli("detect", F640, "--output", out(f"m-{name}"), "--method", "sphere", "--masks", p)

        add(f"masks/{name}", expect, run, f"masks-{name}.png")

    masks_with("palette", lambda p: Image.fromarray(labels).convert("P").save(p), "any")
    masks_with("rgb", lambda p: Image.fromarray(np.dstack([labels * 255] * 3)).save(p), "any")
    masks_with("1bit", lambda p: Image.fromarray(labels > 0).save(p), "any")
    masks_with("width-0", lambda p: p.write_bytes(png_of_size(0, 480)), "error")
    masks_with("other-size", lambda p: Image.fromarray(labels[:100, :100]).save(p), "error")


# --- names, many frames, outputs ------------------------------------------------------------------------------
def name_cases() -> None:
    def recording_named(name: bytes, label: str) -> None:
        def run() -> Run:
            rec = fixture(f"rec-{label}")
            rec.mkdir()
            target = os.path.join(os.fsencode(rec), name)
            shutil.copytree(F640, os.fsdecode(target))
            shutil.copytree(F640, rec / "plain_00001")
            o = out(f"names-{label}")
            return cli("detect", rec, "--output", o, "--method", "sphere", output=o)

        add(f"names/{label}", "any", run)

    recording_named(b"scene_\xff\xfe", "not-utf8")
    recording_named(b"scene\nnewline", "newline")
    recording_named(b"scene \t tab", "tab")
    recording_named(b"-rf", "dash")
    recording_named("scène_ü_日本".encode(), "unicode")

    def empty_frames() -> Run:
        rec = fixture("empty-frames")
        for k in range(2000):
            (rec / f"f_{k:05d}").mkdir(parents=True)
        o = out("empty-frames")
        return cli("detect", rec, "--output", o, "--method", "sphere", output=o)

    add("names/2000-empty-frame-folders", "error", empty_frames, "empty-frames")

    long = "x" * 5000
    for label, argv in [
        ("detect-input", ["detect", long, "--output", "OUT"]),
        ("detect-output", ["detect", F640, "--output", f"OUT/{long}"]),
        ("complete-cloud", ["complete", f"{long}.ply"]),
        ("complete-output", ["complete", PLY, "--output", f"{long}.ply"]),
        ("complete-camera", ["complete", PLY, "--camera", f"{long}.json"]),
        ("segment-input", ["segment", f"{long}.png", "--output", "OUT"]),
        ("evaluate-frames", ["evaluate", "--frames", long, "--output", "OUT"]),
        ("settings-fruit", ["settings", "--fruit", long]),
        ("settings-config", ["settings", "--config", f"{long}.yaml"]),
        ("detect-masks", ["detect", F640, "--output", "OUT", "--masks", f"{long}.png"]),
        ("report-run", ["report", long]),
    ]:

        def too_long(label: str = label, argv: list[Any] = argv) -> Run:
            o = out(f"long-{label}")
            return cli(*[str(a).replace("OUT", str(o)) for a in argv])

        add(f"names/5000-characters/{label}", "error", too_long, "characters)")

    def output_fifo() -> Run:
        p = fixture("out.fifo")
        os.mkfifo(p)
        return cli("detect", F640, "--output", p, "--method", "sphere")

    add("output/detect-fifo", "error", output_fifo, "out.fifo")

    def complete_fifo() -> Run:
        p = fixture("c.ply")
        os.mkfifo(p)
        return cli("complete", PLY, "--output", p)

    add("output/complete-fifo", "error", complete_fifo, "c.ply")

    def complete_link() -> Run:
        elsewhere = fixture("elsewhere.ply")
        elsewhere.write_text("precious\n")
        p = fixture("link.ply")
        p.symlink_to(elsewhere)
        return cli("complete", PLY, "--output", p)  # followed to its target, as writers._named_target says

    add("output/complete-link-to-a-file", "any", complete_link)

    def report_fifo() -> Run:
        p = fixture("report-out.fifo")
        os.mkfifo(p)
        return cli("report", F640, "--output", p)

    add("output/report-fifo", "error", report_fifo)


# --- bags: decompression bombs ------------------------------------------------------------------------------
def bag_cases() -> None:
    def mcap_bomb() -> Run:
        sys.path.insert(0, str(ROOT))
        from tests.conftest import disc_frame
        from tests.io.test_bags import _mcap_records, write_ros2_bag

        color, depth = disc_frame([(60, 60), (110, 60)], radius=15)
        good = fixture("bag-good")
        write_ros2_bag(good, color, (depth * 1000).astype(np.uint16), frames=2, storage="mcap",
                       compression=("storage", "zstd"))  # fmt: skip
        mcap = next(good.glob("*.mcap"))
        raw = bytearray(mcap.read_bytes())
        records = _mcap_records(bytes(raw))
        chunk = next(r for r in records if r[1] == 0x06)
        stated = int.from_bytes(raw[chunk[0] + 9 + 16 : chunk[0] + 9 + 24], "little") // 4
        raw[chunk[0] + 9 + 16 : chunk[0] + 9 + 24] = stated.to_bytes(8, "little")
        for pos, op, length in records:
            if op == 0x08:
                raw[pos + 9 + length - 8 : pos + 9 + length] = stated.to_bytes(8, "little")
        mcap.write_bytes(bytes(raw))
        o = out("mcap-bomb")
        run = cli("detect", good, "--output", o, output=o)
        if "expands past its stated" not in run.err and "expands past its stated" not in run.out:
            return f"DEFECT: the chunk is decompressed whole before it is refused: {run.err.strip()[-200:]}"  # type: ignore[return-value]
        return run

    add("bag/mcap-zstd-chunk-expands-past-its-size", "error", mcap_bomb, "bag-good")


#: Python's words robust48's classifier lets through, read in this sweep's output.
_PYTHON_SPEAK = re.compile(r"set_int_max_str_digits|\bbe a [aeiou]\w+ file\b|cannot identify image file")


def sweep(cases: list[tuple[str, str, Callable[[], Any], str]], *, only: str = "", defects: bool = False,
          limit: int = LIMIT_S, width: int = 48) -> dict[str, int]:  # fmt: skip
    """Run ``cases`` (those whose name holds one of ``only``'s comma-separated parts) under a ``limit`` s alarm,
    judge each (robust47's ``judge``, robust48's and this sweep's Python's words), print a line each (the defects
    alone with ``defects``) and the counts; return the counts. robust50 runs its cases through it too."""
    import symfruit

    signal.signal(signal.SIGALRM, r47._alarm)
    counts = {"error": 0, "failed": 0, "result": 0, "DEFECT": 0}
    for name, expect, fn, names in cases:
        if not any(part in name for part in only.split(",")):
            continue
        signal.alarm(limit)
        try:
            value = fn()
            signal.alarm(0)
            if isinstance(value, str) and value.startswith("DEFECT"):
                kind, text = "DEFECT", value.removeprefix("DEFECT: ")
            else:
                kind, text = r47.judge(value, expect, names)
        except symfruit.SymfruitError as exc:
            signal.alarm(0)
            msg = str(exc).replace(str(r47.T), "T")
            kind, text = ("DEFECT", f"refused what it should take: {msg[:150]}") if expect == "result" else (
                "error", msg[:150])  # fmt: skip
            if len(msg) > 300 or r47._FOREIGN.search(msg):
                kind, text = "DEFECT", f"message of {len(msg)} characters or another library's words: {msg[:150]}"
        except r47.Hang:
            kind, text = "DEFECT", f"hang (over {limit} s)"
        except Exception as exc:  # the point of the sweep
            signal.alarm(0)
            kind, text = "DEFECT", r47.origin(exc)
        if kind != "DEFECT" and (said := r48._PYTHON_SPEAK.search(text) or _PYTHON_SPEAK.search(text)):
            kind, text = "DEFECT", f"Python's words ({said.group(0)!r}): {text[:150]}"
        counts[kind] += 1
        if kind == "DEFECT" or not defects:
            sys.stdout.write(f"{kind:6} {name:{width}} {text}\n")
            sys.stdout.flush()
    sys.stdout.write(f"# {sum(counts.values())} cases: {counts['error']} clear errors, {counts['failed']} failed items "
                     f"reported, {counts['result']} results, {counts['DEFECT']} defects\n")  # fmt: skip
    return counts


def run_main(doc: str, builds: tuple[Callable[[], None], ...], cases: list[tuple[str, str, Callable[[], Any], str]],
             *, prefix: str, limit: int, width: int) -> int:  # fmt: skip
    """A later sweep's command line (robust50, robust51): ``--only``, ``--defects``, ``--keep``; its ``builds``
    fill ``cases``, run through :func:`sweep`; exit 1 when a case is a defect."""
    import logging
    import warnings

    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--only", default="", help="the cases whose name holds one of these (comma-separated)")
    parser.add_argument("--defects", action="store_true", help="print the defects alone")
    parser.add_argument("--keep", type=Path, help="make or reuse the fixtures in this folder")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    logging.getLogger("distributed").setLevel(logging.CRITICAL)
    r47.T = args.keep.resolve() if args.keep else Path(tempfile.mkdtemp(prefix=prefix))
    r47.T.mkdir(parents=True, exist_ok=True)
    for build in builds:
        build()
    counts = sweep(cases, only=args.only, defects=args.defects, limit=limit, width=width)
    if not args.keep:
        shutil.rmtree(r47.T, ignore_errors=True)
    return 1 if counts["DEFECT"] else 0


def main() -> int:
    return run_main(__doc__ or "", (file_cases, image_cases, name_cases, bag_cases), CASES, prefix="robust49-",
                    limit=LIMIT_S, width=48)  # fmt: skip


if __name__ == "__main__":
    sys.exit(main())
