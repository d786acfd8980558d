"""Stop 53: bad and adversarial input past stops 43-52's sweeps (robust53).

What no earlier sweep tried (their lists: docs/robust47.md-robust52.md): ``detect --resume`` into an output
folder whose own files were damaged since (errors.json, the two tables, a frame's detections.json cut short,
emptied, made a folder or of another shape); settings YAML in another encoding (UTF-16, a byte-order mark, Latin-1),
several YAML documents, an empty file; camera files whose distortion is a million numbers or text;
``evaluate --spheres`` on frames whose masks hold thousands of labels or a sphere with no depth; files changed
while a batch reads them, each way (grown, replaced, rewritten, removed: the frame must fail by name and the batch
go on; stop 53 makes that so), and a photo folder whose photos are links to one file.

Cases run in this process under an alarm and are judged as docs/robust47.py judges them (through robust49's
``sweep``); a case that checks a rule itself returns ``DEFECT: ...`` when it is broken.

::

    PYTHONPATH=src python docs/robust53.py                 # every case (fixtures in a temporary folder)
    PYTHONPATH=src python docs/robust53.py --only resume/ --defects
"""

from __future__ import annotations

import json
import os
import shutil
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import robust47 as r47
import robust49 as r49
import robust51 as r51

LIMIT_S = 90
ROOT, fixture, cli, Run, small = r47.ROOT, r49.fixture, r47.cli, r47.Run, r51.small
CASES: list[tuple[str, str, Callable[[], Any], str]] = []


def add(name: str, expect: str, fn: Callable[[], Any], names: str = "") -> None:
    CASES.append((name, expect, fn, names))


def recording(name: str, frames: int = 3) -> Path:
    """A recording of ``frames`` copies of the small frame, f_0, f_1, ..."""
    rec = fixture(name)
    for k in range(frames):
        shutil.copytree(small(), rec / f"f_{k}")
    return rec


def done_frames(out: Path) -> list[str]:
    import pyarrow.parquet as pq

    try:
        return sorted(pq.read_table(out / "frames.parquet").column("frame").to_pylist())
    except Exception as exc:  # the case's own check: its tables unreadable
        return [f"unreadable frames.parquet ({type(exc).__name__})"]


def readable(table: Path) -> bool:
    import pyarrow.parquet as pq

    try:
        pq.read_table(table)
    except Exception:  # the case's own check: any failure is a table that cannot be read
        return False
    return True


# --- detect --resume into an output folder damaged since --------------------------------------------------------
def resume_cases() -> None:
    def resumed(name: str, damage: Callable[[Path], Any], expect: str, names: str = "") -> None:
        """A run of three frames, its output ``damage``d, then ``detect --resume``: either a clear error naming
        the damaged file, or the three frames in the tables, each once."""

        def go() -> Any:
            rec = recording(f"resume-{name}-rec")
            out = r49.out(f"resume-{name}")
            first = cli("detect", rec, "--output", out, "--method", "sphere", output=out)
            if first.rc:
                return f"DEFECT: the first run failed: {first.err[-200:]}"
            tables = {t: (out / t).read_bytes() for t in ("detections.parquet", "frames.parquet")}
            damage(out)  # the tables it leaves whole must stay readable, whatever the run does
            kept = [t for t, data in tables.items() if (out / t).is_file() and (out / t).read_bytes() == data]
            again = cli("detect", rec, "--output", out, "--method", "sphere", "--resume", output=out)
            if again.rc == 0 and done_frames(out) != ["f_0", "f_1", "f_2"]:
                return f"DEFECT: resumed, the tables list {done_frames(out)}"
            if broken := [t for t in kept if not readable(out / t)]:  # a table whole, the earlier one or a new one
                return f"DEFECT: the earlier run's {broken} left unreadable: {again.err[-150:]}"
            if "Exception ignored" in again.err:
                return f"DEFECT: Python's words at exit: {again.err[-200:]}"
            return again

        add(f"resume/{name}", expect, go, names)

    def cut(file: str, keep: float = 0.5) -> Callable[[Path], None]:
        def go(out: Path) -> None:
            p = out / file
            data = p.read_bytes()
            p.write_bytes(data[: int(len(data) * keep)])

        return go

    def text(file: str, content: str) -> Callable[[Path], None]:
        return lambda out: (out / file).write_text(content)

    def folder(file: str) -> Callable[[Path], None]:
        def go(out: Path) -> None:
            (out / file).unlink()
            (out / file).mkdir()

        return go

    resumed("errors-json-cut-short", cut("errors.json"), "any", "errors.json")
    resumed("errors-json-a-list", text("errors.json", "[1, 2, 3]"), "any", "errors.json")
    resumed("errors-json-null", text("errors.json", "null"), "any", "errors.json")
    resumed("errors-json-failed-a-list", text("errors.json", '{"failed": [1, 2]}'), "any", "errors.json")
    resumed("errors-json-a-folder", folder("errors.json"), "any", "errors.json")
    resumed("errors-json-200-mb-of-spaces", lambda out: (out / "errors.json").write_bytes(b" " * 200_000_000),
            "any", "errors.json")  # fmt: skip
    resumed("frames-parquet-cut-short", cut("frames.parquet"), "any", "frames.parquet")
    resumed("frames-parquet-empty", cut("frames.parquet", 0), "any", "frames.parquet")
    resumed("frames-parquet-a-folder", folder("frames.parquet"), "any", "frames.parquet")
    resumed("detections-parquet-cut-short", cut("detections.parquet"), "any", "detections.parquet")
    resumed("detections-parquet-text", text("detections.parquet", "frame,fruit\nf_0,1\n"), "any",
            "detections.parquet")  # fmt: skip
    resumed("frame-detections-json-cut-short", cut("f_1/detections.json"), "any", "detections.json")
    resumed("frame-detections-json-empty", cut("f_1/detections.json", 0), "any", "detections.json")
    resumed("frame-detections-json-a-list", text("f_1/detections.json", "[]"), "any", "detections.json")
    resumed("frame-detections-json-a-folder", folder("f_1/detections.json"), "any", "detections.json")

    def other_table(file: str) -> Callable[[Path], None]:
        def go(out: Path) -> None:
            import pyarrow as pa
            import pyarrow.parquet as pq

            pq.write_table(pa.table({"frame": ["f_0"], "x": [1.0]}), out / file)

        return go

    resumed("frames-parquet-of-other-columns", other_table("frames.parquet"), "any", "frames.parquet")
    resumed("detections-parquet-of-other-columns", other_table("detections.parquet"), "any", "detections.parquet")
    resumed("errors-json-a-link-to-dev-zero", lambda out: ((out / "errors.json").unlink(), os.symlink(
        "/dev/zero", out / "errors.json")), "any", "errors.json")  # fmt: skip
    resumed("frame-folder-removed", lambda out: shutil.rmtree(out / "f_1"), "any")
    resumed("frame-folder-a-file", lambda out: (shutil.rmtree(out / "f_1"), (out / "f_1").write_text("x")), "any",
            "f_1")  # fmt: skip


# --- settings in other encodings and shapes ---------------------------------------------------------------------
def settings_cases() -> None:
    def config(name: str, data: bytes, expect: str = "error") -> None:
        def go() -> Any:
            path = fixture(f"{name}.yaml")
            path.write_bytes(data)
            return cli("settings", "--config", path)

        add(f"settings/{name}", expect, go, f"{name}.yaml" if expect == "error" else "")

    body = "evidence:\n  rays: 64\n"
    config("utf-16", body.encode("utf-16"), "any")
    config("utf-8-bom", b"\xef\xbb\xbf" + body.encode(), "result")
    config("latin-1-comment", ("# réglages\n" + body).encode("latin-1"), "any")
    config("two-documents", (body + "---\n" + "evidence:\n  rays: 8\n").encode())
    config("empty", b"", "any")
    config("only-a-comment", b"# nothing\n", "any")
    config("a-nul-byte", body.encode() + b"\0", "error")
    config("a-list", b"- evidence\n- rays\n", "error")
    config("a-scalar", b"64\n", "error")
    config("tabs-for-indent", b"evidence:\n\trays: 64\n", "error")
    config("crlf-lines", body.replace("\n", "\r\n").encode(), "result")

    def a_folder() -> Any:
        path = fixture("settings-folder.yaml")
        path.mkdir()
        return cli("settings", "--config", path)

    add("settings/a-folder", "error", a_folder, "settings-folder.yaml")


# --- camera files: distortion of another size or type -----------------------------------------------------------
def camera_cases() -> None:
    def distortion(name: str, value: Any, expect: str, names: str = "camera.json") -> None:
        def change(f: Path) -> None:
            data = json.loads((f / "camera.json").read_text())
            data["coeffs"] = value  # RealSense's name, read beside a flat camera.json's fx, fy, cx, cy
            (f / "camera.json").write_text(json.dumps(data))

        frame_case(f"distortion-{name}", expect, change, names)

    distortion("a-million-zeros", [0.0] * 1_000_000, "any", "")
    distortion("text", "plumb_bob", "error")
    distortion("nested", [[0.1, 0.2]], "error")
    distortion("nan", [float("nan"), 0, 0, 0, 0], "error")
    distortion("1e300", [1e300, 0, 0, 0, 0], "any", "")
    distortion("none", None, "any", "")


def frame_case(name: str, expect: str, change: Callable[[Path], Any], names: str = "", *extra: Any) -> None:
    """robust51's: ``symfruit detect`` of a copy of the small frame changed by ``change``, a case of this sweep."""
    r51.frame_case(name, expect, change, names, *extra)
    CASES.append(r51.CASES.pop())


# --- a frame's masks.json (COCO of one image) and a folder of masks ---------------------------------------------
def masks_cases() -> None:
    def coco(annotations: list[dict[str, Any]], images: list[dict[str, Any]] | None = None) -> Callable[[Path], None]:
        def go(f: Path) -> None:
            data = {"images": images or [{"id": 1, "file_name": "color.png", "width": 160, "height": 160}],
                    "annotations": [{"image_id": 1, "category_id": 1, **a} for a in annotations],
                    "categories": [{"id": 1, "name": "fruit"}]}  # fmt: skip
            (f / "masks.json").write_text(json.dumps(data))

        return go

    square = [[60.0, 60.0, 100.0, 60.0, 100.0, 100.0, 60.0, 100.0]]
    ring = np.linspace(0, 2 * np.pi, 200_000, endpoint=False)
    many = [[float(v) for xy in zip(80 + 20 * np.cos(ring), 80 + 20 * np.sin(ring), strict=True) for v in xy]]
    frame_case("masks-json-a-polygon-of-200000-points", "any", coco([{"id": 1, "segmentation": many}]))
    frame_case("masks-json-2000-annotations", "any", coco([{"id": k + 1, "segmentation": square}
                                                           for k in range(2000)]), "masks.json")  # fmt: skip
    frame_case("masks-json-polygon-of-huge-ints", "any", coco([{"id": 1, "segmentation": [[10**30] * 8]}]))
    frame_case("masks-json-polygon-of-text", "error", coco([{"id": 1, "segmentation": [["a"] * 8]}]), "masks.json")
    frame_case(
        "masks-json-two-images",
        "any",
        coco(
            [{"id": 1, "segmentation": square}],
            [
                {"id": 1, "file_name": "color.png", "width": 160, "height": 160},
                {"id": 2, "file_name": "color.png", "width": 160, "height": 160},
            ],
        ),
    )  # the first image's (coco_masks)
    frame_case("masks-json-rle-of-the-wrong-size", "error", coco([{"id": 1, "iscrowd": 0, "segmentation": {
        "counts": [0, 100], "size": [10, 10]}}]), "masks.json")  # fmt: skip
    frame_case(
        "masks-json-crowd-rle-of-the-wrong-size",
        "any",
        coco([{"id": 1, "iscrowd": 1, "segmentation": {"counts": [0, 100], "size": [10, 10]}}]),
    )  # a crowd region is no fruit: left out unread, as COCO does
    frame_case("masks-json-bbox-only", "any", coco([{"id": 1, "bbox": [60, 60, 40, 40]}]))
    frame_case("masks-json-segmentation-null", "error", coco([{"id": 1, "segmentation": None}]), "masks.json")

    def folder_of_masks(name: str, make: Callable[[Path, Path], Any], expect: str, names: str = "") -> None:
        def go() -> Any:
            from PIL import Image

            rec = recording(f"masks-folder-{name}-rec", 2)
            masks = fixture(f"masks-folder-{name}")
            masks.mkdir()
            labels = np.zeros((160, 160), np.uint8)
            labels[60:100, 60:100] = 1
            for k in range(2):
                Image.fromarray(labels).save(masks / f"f_{k}.png")
            make(rec, masks)
            o = r49.out(f"masks-folder-{name}")
            return cli("detect", rec, "--output", o, "--method", "sphere", "--masks", masks, output=o)

        add(f"masks-folder/{name}", expect, go, names)

    folder_of_masks("good", lambda rec, m: None, "result")
    folder_of_masks("a-frame-png-beside-its-folder", lambda rec, m: ((m / "f_1").mkdir(), shutil.copy(
        m / "f_1.png", m / "f_1" / "masks.png")), "failed", "f_1")  # fmt: skip
    folder_of_masks("one-of-another-size", lambda rec, m: __import__("PIL.Image").Image.fromarray(
        np.ones((80, 80), np.uint8)).save(m / "f_1.png"), "failed", "f_1.png")  # fmt: skip
    folder_of_masks("one-missing", lambda rec, m: (m / "f_1.png").unlink(), "any")
    folder_of_masks("one-a-link-loop", lambda rec, m: ((m / "f_1.png").unlink(), os.symlink(
        "f_1.png", m / "f_1.png")), "failed", "f_1.png")  # fmt: skip
    folder_of_masks("one-a-text-file", lambda rec, m: (m / "f_1.png").write_text("labels"), "failed", "f_1.png")


# --- evaluate --spheres on masks of many labels or none with depth ----------------------------------------------
def spheres_cases() -> None:
    from PIL import Image

    def spheres(name: str, masks: Callable[[np.ndarray], np.ndarray], expect: str, names: str = "") -> None:
        def go() -> Any:
            rec = fixture(f"spheres-{name}")
            shutil.copytree(small(), rec / "f_0")
            depth = np.asarray(Image.open(rec / "f_0" / "depth.png"))
            Image.fromarray(masks(depth)).save(rec / "f_0" / "masks.png")
            o = r49.out(f"spheres-{name}")
            return cli("evaluate", "--spheres", rec, "--output", o, "--methods", "sphere", output=o)

        add(f"spheres/{name}", expect, go, names)

    def labels_every_pixel(depth: np.ndarray) -> np.ndarray:  # 25,600 labels of one pixel each
        return (np.arange(depth.size).reshape(depth.shape) + 1).astype(np.uint16)

    def label_without_depth(depth: np.ndarray) -> np.ndarray:
        m = np.zeros(depth.shape, np.uint8)
        m[depth == 0] = 1
        return m

    def whole_image(depth: np.ndarray) -> np.ndarray:
        return np.ones(depth.shape, np.uint8)

    spheres("a-label-each-pixel", labels_every_pixel, "any")
    spheres("a-label-where-no-depth", label_without_depth, "any")
    spheres("one-label-the-whole-image", whole_image, "any")


# --- files changed while a batch reads them, each way: the frame fails by name, the batch goes on --------------
def changing_cases() -> None:
    import symfruit.io.frames as frames

    def changed(name: str, file: str, change: Callable[[Path], Any]) -> None:
        def go() -> Any:
            rec = recording(f"changing-{name}", 3)
            real = frames.read_depth

            def depth_then_change(path: Path, *args: Any, **kwargs: Any) -> Any:
                depth = real(path, *args, **kwargs)
                if path.parent.name == "f_1":
                    change(path.parent / file)
                return depth

            o = r49.out(f"changing-{name}")
            frames.read_depth = depth_then_change  # the change made by the reader: no race
            try:
                run = cli("detect", rec, "--output", o, "--method", "sphere", output=o)
            finally:
                frames.read_depth = real
            if done_frames(o) != ["f_0", "f_2"]:
                return f"DEFECT: the batch did not fail f_1 alone (done: {done_frames(o)}): {run.err[-200:]}"
            return run

        add(f"changing/{name}", "failed", go, file)

    def grow(p: Path) -> None:
        with open(p, "ab") as f:
            f.write(bytes(100))

    def replace(p: Path) -> None:
        shutil.copyfile(p, f"{p}.new")
        os.replace(f"{p}.new", p)

    def rewrite(p: Path) -> None:
        st = os.stat(p)
        os.utime(p, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000))

    changed("color-grown", "color.png", grow)
    changed("color-replaced", "color.png", replace)
    changed("camera-rewritten", "camera.json", rewrite)
    changed("depth-grown-after-it-was-read", "depth.png", grow)
    changed("masks-appeared", "masks.png", lambda p: shutil.copyfile(p.parent / "depth.png", p))


# --- photo folders ----------------------------------------------------------------------------------------------
def photo_cases() -> None:
    photos = ROOT / "examples/photos"

    def links_to_one() -> Any:
        folder = fixture("photos-links")
        folder.mkdir()
        first = sorted(photos.glob("*.jpg"))[0]
        for k in range(3):
            os.symlink(first, folder / f"p{k}.jpg")
        o = r49.out("photos-links")
        return cli("segment", folder, "--output", o, output=o)

    add("photos/three-links-to-one-photo", "any", links_to_one)

    def photo_named_like_an_output() -> Any:
        folder = fixture("photos-named")
        folder.mkdir()
        first = sorted(photos.glob("*.jpg"))[0]
        shutil.copy(first, folder / "masks.png.jpg")
        shutil.copy(first, folder / "a.jpg")
        o = r49.out("photos-named")
        return cli("segment", folder, "--output", o, output=o)

    add("photos/a-photo-named-like-an-output", "any", photo_named_like_an_output)


def main() -> int:
    return r49.run_main(
        __doc__ or "",
        (resume_cases, settings_cases, camera_cases, masks_cases, spheres_cases, changing_cases, photo_cases),
        CASES,
        prefix="robust53-",
        limit=LIMIT_S,
        width=52,
    )


if __name__ == "__main__":
    sys.exit(main())
