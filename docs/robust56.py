"""Stop 56: bad and adversarial input past stops 43-55's sweeps (robust56).

What no earlier sweep built (their lists: docs/robust43.md, docs/robust47.md-robust55.md): stop 55's newest
surfaces first (``symfruit detect --fruit-processes N`` over a recording with a bad frame first, in the middle or
last, where the next frame is read while the workers end the last; ``detect.DetectStream`` called out of turn or
handed what ``prepare`` did not make; ``bench --stream`` at its bounds), cameras of absurd focal length (1 pixel a
radian, 10^6 pixels, the two at once: ``extract.cluster_gap``'s footprint), the real-frames path ``evaluate
--spheres`` with odd masks (none, one pixel, another size, RGB, a sphere in one frame only, every pixel its own
instance), every numeric setting at its lower and its upper bound (a ``detect`` of the tests' small frame each,
by the section's method, under an address-space bound: unbounded memory is a MemoryError here, not a full
machine), number options of other digits than ASCII, temporaries whose names hold '²', and ``detect`` over a
recording interrupted (SIGINT, SIGKILL) at several moments, its outputs then read back (no half-written file).

Cases run in this process under an alarm and are judged as docs/robust55.py judges them (robust49's ``sweep``,
robust55's ``_OTHERS``); a case that checks a rule itself returns ``DEFECT: ...`` when it is broken.

::

    PYTHONPATH=src python docs/robust56.py                      # every case (fixtures in a temporary folder)
    PYTHONPATH=src python docs/robust56.py --only settings/ --defects
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import robust47 as r47
import robust49 as r49
import robust51 as r51
import robust53 as r53
import robust55 as r55

LIMIT_S = 120
#: The sweep's address space (a setting that allocates past it is a MemoryError, a DEFECT, not a full machine).
ADDRESS_SPACE = 8 << 30
ROOT, fixture, cli, Run, small, add = r47.ROOT, r49.fixture, r47.cli, r47.Run, r51.small, r55.add
CASES = r55.CASES  # robust55's ``add`` (its other libraries' words) fills its list: this sweep's alone here
#: robust55's other libraries' words, and those stop 55 left: rosbags' CDR words for a message cut short (and
#: numpy's and struct's under them), a file never compressed called "decompressed", SQLite's for an MCAP file.
r55._OTHERS = re.compile(
    f"{r55._OTHERS.pattern}|Invalid (string|sequence) length|buffer is smaller than requested|unpack_from requires|"
    r"\.db3, decompressed|\.mcap: file is not a database|invalid literal for int"
)


def _recording(name: str, frames: int = 4) -> Path:
    """A recording folder of ``frames`` copies of the small frame (``f_0`` ...): robust53's."""
    return r53.recording(name, frames)


def _written_frames(output: Path) -> list[str]:
    return sorted(p.name for p in output.iterdir() if (p / "detections.json").is_file()) if output.is_dir() else []


# --- a recording's frames in a stream (stop 55: --fruit-processes) -----------------------------------------------
def stream_cases() -> None:
    breaks: dict[str, Callable[[Path], Any]] = {
        "depth-garbage": lambda f: (f / "depth.png").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(100)),
        "colour-missing": lambda f: (f / "color.png").unlink(),
        "camera-focal-1e12": lambda f: (f / "camera.json").write_text(
            json.dumps({**json.loads((f / "camera.json").read_text()), "fx": 1e12})
        ),
        "depth-all-zero": lambda f: _zero_depth(f),
    }

    def _case(why: str, at: int, processes: int) -> Callable[[], Any]:
        def go() -> Any:
            rec = _recording(f"stream-{why}-{at}-{processes}")
            breaks[why](rec / f"f_{at}")
            o = r49.out(f"stream-{why}-{at}-{processes}")
            run = cli("detect", rec, "--output", o, "--method", "sphere", "--fruit-processes", processes, output=o)
            written = _written_frames(o)
            good = [f"f_{k}" for k in range(4) if k != at]
            if why != "depth-all-zero" and written != good:
                return f"DEFECT: frames written {written}, expected {good} (past the bad frame): {run.err[-160:]}"
            return run

        return go

    for why in breaks:
        for at in (0, 1, 3):
            expect = "any" if why == "depth-all-zero" else "failed"
            add(f"stream/{why}-frame-{at}-of-4-fruit-processes-1", expect, _case(why, at, 1), f"f_{at}")
    add("stream/depth-garbage-frame-1-of-4-no-pool", "failed", _case("depth-garbage", 1, 0), "f_1")

    def bag(cut: int, processes: int) -> Callable[[], Any]:
        def go() -> Any:
            import sqlite3

            sys.path.insert(0, str(ROOT))
            from tests.conftest import disc_frame
            from tests.io.test_bags import write_ros2_bag

            color, depth = disc_frame([(60, 60), (110, 60)], radius=15)
            p = write_ros2_bag(fixture(f"stream-bag-{cut}-{processes}"), color, (depth * 1000).astype(np.uint16),
                               frames=4)  # fmt: skip
            with contextlib.closing(sqlite3.connect(next(p.glob("*.db3")))) as con:  # frame 1's depth cut short
                con.execute(f"update messages set data = substr(data, 1, {cut}) where topic_id = 2 and "
                            "timestamp = 2000001000")  # fmt: skip
                con.commit()
            o = r49.out(f"stream-bag-{cut}-{processes}")
            run = cli("detect", p, "--output", o, "--method", "sphere", "--fruit-processes", processes, output=o)
            if len(_written_frames(o)) != 3:
                return f"DEFECT: {len(_written_frames(o))} frames written, expected 3: {run.err[-160:]}"
            return run

        return go

    for cut in (40, 400):
        for processes in (0, 1):
            add(f"stream/bag-depth-message-cut-to-{cut}-frame-1-of-4-fruit-processes-{processes}", "failed",
                bag(cut, processes), "stream-bag")  # fmt: skip


def _zero_depth(frame: Path) -> None:
    from PIL import Image

    with Image.open(frame / "depth.png") as im:
        shape = (im.height, im.width)
    Image.fromarray(np.zeros(shape, np.uint16)).save(frame / "depth.png")


def stream_api_cases() -> None:
    from symfruit.detect import DetectStream, detect
    from symfruit.fruitpool import FruitPool
    from symfruit.io import read_frame

    def frame() -> Any:
        return read_frame(small())

    def start_with(what: Callable[[], Any]) -> Callable[[], Any]:
        def go() -> Any:
            stream = DetectStream(None, method="sphere")
            stream.start(what())
            return stream.finish()

        return go

    add("streamapi/start-of-a-frame-not-prepared", "error", start_with(frame))
    add("streamapi/start-of-none", "error", start_with(lambda: None))
    add("streamapi/finish-with-none-in-flight", "any", lambda: DetectStream(None).finish())
    add("streamapi/abandon-with-none-in-flight", "any", lambda: DetectStream(None).abandon())
    add("streamapi/pool-the-class", "error", lambda: DetectStream(FruitPool))  # type: ignore[arg-type]
    add("streamapi/method-unknown", "error", lambda: DetectStream(None, method="nope"))
    add("streamapi/prepare-of-a-path", "error", lambda: DetectStream(None).prepare(small()))  # type: ignore[arg-type]

    def twice() -> Any:
        stream = DetectStream(None, method="sphere")
        ready = stream.prepare(frame())
        stream.start(ready)
        try:
            stream.start(ready)
        except RuntimeError as exc:  # a programming error, said so
            if "still in flight" not in str(exc):
                return f"DEFECT: {exc}"
        else:
            return "DEFECT: a second frame started while one is in flight"
        return stream.finish()

    add("streamapi/start-while-in-flight", "any", twice)

    def same_as_detect(processes: int) -> Callable[[], Any]:
        def go() -> Any:
            f = frame()
            alone = detect(f, method="sphere")
            with FruitPool(processes) as pool:
                stream = DetectStream(pool, method="sphere")
                found = []
                for _ in range(3):
                    ready = stream.prepare(f)
                    found.append(stream.finish())
                    stream.start(ready)
                found.append(stream.finish())
                pool.close()
                ready = stream.prepare(f)  # a closed pool: the frame done here
                stream.start(ready)
                found.append(stream.finish())
            got = [d for d in found if d is not None]
            if any(_records(d) != _records(alone) for d in got):
                return "DEFECT: a stream's detections are not detect's"
            return got

        return go

    add("streamapi/three-frames-then-a-closed-pool", "result", same_as_detect(1))

    def leave(value: Any) -> Callable[[], Any]:
        def go() -> Any:
            sys.path.insert(0, str(ROOT))
            from tests.test_fruitpool import four, fruit_task

            task, jobs = fruit_task(four())
            with FruitPool(1, method=None) as pool:
                return pool.start(task, jobs, leave=value).result()

        return go

    for value in ("1", -1.0, float("nan")):
        add(f"streamapi/pool-start-leave-{value}", "error", leave(value))

    def layout(name: str, change: Callable[[Any], dict[str, Any]]) -> None:
        def go() -> Any:
            f = dataclasses.replace(frame(), **change(frame()))
            alone = detect(f, method="evidence")
            with FruitPool(1) as pool:
                stream = DetectStream(pool, method="evidence")
                stream.start(stream.prepare(f))
                streamed = stream.finish()
            if _records(streamed) != _records(alone):
                return "DEFECT: the frame's detections in a stream with a pool are not detect's"
            return streamed

        add(f"streamapi/arrays-{name}", "result", go)

    layout("colour-fortran", lambda f: {"color": np.asfortranarray(f.color)})
    layout("colour-negative-strides", lambda f: {"color": f.color[::-1, ::-1][::-1, ::-1]})
    layout("colour-every-other-column-view", lambda f: {"color": np.repeat(f.color, 2, axis=1)[:, ::2]})
    layout("colour-read-only", lambda f: {"color": _read_only(f.color)})
    layout("colour-broadcast", lambda f: {"color": np.broadcast_to(f.color[:1], f.color.shape)})
    layout("depth-big-endian", lambda f: {"depth": f.depth.astype(">f4")})
    layout("depth-fortran-read-only", lambda f: {"depth": _read_only(np.asfortranarray(f.depth))})
    layout("masks-big-endian-int32", lambda f: {"masks": (f.depth > 0).astype(">i4")})
    layout("masks-uint64-strided", lambda f: {"masks": np.repeat((f.depth > 0).astype(np.uint64), 2, axis=0)[::2]})


def _read_only(a: np.ndarray) -> np.ndarray:
    a = a.copy()
    a.flags.writeable = False
    return a


def _records(found: Any) -> str:
    """A frame's detections as ``detections.json`` holds them, less the times."""
    from symfruit.writers import detections_record

    record = detections_record(found)
    record.pop("timings", None)
    for fruit in record.get("fruits", []):
        fruit.pop("seconds", None)
    return json.dumps(record, sort_keys=True, default=str)


# --- what stop 55 left: a bag's storage of the other kind, a message cut short ------------------------------------
def left_cases() -> None:
    import sqlite3

    def bag(name: str, expect: str, change: Callable[[Path], Any], storage: str = "sqlite3") -> None:
        def go() -> Any:
            sys.path.insert(0, str(ROOT))
            from tests.conftest import disc_frame
            from tests.io.test_bags import write_ros2_bag

            color, depth = disc_frame([(60, 60), (110, 60)], radius=15)
            p = write_ros2_bag(fixture(f"left-{name}"), color, (depth * 1000).astype(np.uint16), frames=3,
                               storage=storage)  # fmt: skip
            change(p)
            o = r49.out(f"left-{name}")
            return cli("detect", p, "--output", o, "--method", "sphere", output=o)

        add(f"left/{name}", expect, go, f"left-{name}")

    def retitle(old: str, new: str) -> Callable[[Path], None]:
        return lambda p: (p / "metadata.yaml").write_text((p / "metadata.yaml").read_text().replace(old, new))

    def cut(topic: int, size: int) -> Callable[[Path], None]:
        def go(p: Path) -> None:
            with contextlib.closing(sqlite3.connect(next(p.glob("*.db3")))) as con:
                con.execute(f"update messages set data = substr(data, 1, {size}) where topic_id = {topic}")
                con.commit()

        return go

    bag("sqlite-named-mcap", "error", retitle("storage_identifier: sqlite3", "storage_identifier: mcap"))
    bag("mcap-named-sqlite3", "error", retitle("storage_identifier: mcap", "storage_identifier: sqlite3"), "mcap")
    bag("mcap-file-a-ros1-bag", "error", lambda p: next(p.glob("*.mcap")).write_bytes(b"#ROSBAG V2.0\n" + bytes(4000)),
        "mcap")  # fmt: skip
    for topic, what in ((3, "camera-info"), (2, "depth"), (1, "colour")):
        for size in (3, 40, 200):
            bag(f"{what}-messages-cut-to-{size}-bytes", "failed", cut(topic, size))


# --- cameras of absurd focal length --------------------------------------------------------------------------------
def camera_cases() -> None:
    def focal(name: str, **change: float) -> None:
        def go() -> Any:
            f = fixture(f"camera-{name}")
            shutil.copytree(small(), f)
            cam = json.loads((f / "camera.json").read_text())
            (f / "camera.json").write_text(json.dumps({**cam, **change}))
            o = r49.out(f"camera-{name}")
            return cli("detect", f, "--output", o, "--method", "evidence", output=o)

        add(f"camera/{name}", "any", go, f"camera-{name}")

    focal("fx-fy-1", fx=1.0, fy=1.0)
    focal("fx-fy-1e6", fx=1e6, fy=1e6)
    focal("fx-1-fy-1e6", fx=1.0, fy=1e6)
    focal("fx-1e6-fy-1", fx=1e6, fy=1.0)
    focal("fx-fy-1-centred", fx=1.0, fy=1.0, cx=80.0, cy=80.0)
    focal("cx-cy-1e6", cx=1e6, cy=-1e6)

    def gap(name: str, fx: float, fy: float) -> None:
        def go() -> Any:
            from symfruit.core.camera import Camera
            from symfruit.extract import cluster_gap

            pts = np.random.default_rng(0).normal(0, 0.02, (500, 3)) + [0, 0, 0.5]
            value = cluster_gap(pts, Camera(fx=fx, fy=fy, cx=0.0, cy=0.0, width=10, height=10), 0.006)
            if not np.isfinite(value) or value < 0.006:
                return f"DEFECT: cluster_gap {value!r}"
            return value

        add(f"camera/cluster-gap-{name}", "result", go)

    gap("fx-fy-1", 1.0, 1.0)
    gap("fx-fy-1e6", 1e6, 1e6)
    gap("fx-1-fy-1e6", 1.0, 1e6)


# --- evaluate --spheres with odd masks ---------------------------------------------------------------------------
def spheres_cases() -> None:
    from PIL import Image

    real = ROOT / "examples" / "real-frames"

    def spheres(name: str, expect: str, change: Callable[[Path], Any], names: str = "") -> None:
        def go() -> Any:
            f = fixture(f"spheres-{name}")
            for k in (0, 1):
                shutil.copytree(real / f"lab-spheres-{k}", f / f"lab-spheres-{k}")
            change(f)
            o = r49.out(f"spheres-{name}")
            return cli("evaluate", "--spheres", f, "--output", o, "--methods", "sphere", output=o)

        add(f"spheres/{name}", expect, go, names or f"spheres-{name}")

    def masks(f: Path, k: int = 0) -> np.ndarray:
        with Image.open(f / f"lab-spheres-{k}" / "masks.png") as im:
            return np.asarray(im)

    def save(f: Path, a: np.ndarray, k: int = 0) -> None:
        Image.fromarray(a).save(f / f"lab-spheres-{k}" / "masks.png")

    spheres("as-shipped", "result", lambda f: None)
    spheres("masks-all-zero", "any", lambda f: save(f, np.zeros_like(masks(f))))
    spheres("masks-all-zero-both", "any", lambda f: [save(f, np.zeros_like(masks(f, k)), k) for k in (0, 1)])
    spheres("a-sphere-one-pixel", "any", lambda f: save(f, _one_pixel(masks(f))))
    spheres("masks-of-another-size", "error", lambda f: save(f, masks(f)[:-8, :-8]))
    spheres("masks-rgb", "any", lambda f: save(f, np.dstack([masks(f)] * 3).astype(np.uint8)))
    spheres(
        "masks-16-bit-ids-65535",
        "any",
        lambda f: save(f, np.where(masks(f) > 0, 65535 - masks(f).astype(np.uint16), 0).astype(np.uint16)),
    )
    spheres("a-sphere-in-one-frame-only", "any", lambda f: save(f, np.where(masks(f) == masks(f).max(), 0, masks(f))))
    spheres("every-pixel-its-own-instance", "any", lambda f: save(f, _noise_ids(masks(f))))
    spheres("masks-missing-in-one", "any", lambda f: (f / "lab-spheres-1" / "masks.png").unlink())
    spheres("depth-all-zero", "any", lambda f: _zero_depth(f / "lab-spheres-0"), "lab-spheres-0")


def _one_pixel(m: np.ndarray) -> np.ndarray:
    out = m.copy()
    k = int(out.max())
    ys, xs = np.nonzero(out == k)
    out[out == k] = 0
    out[ys[0], xs[0]] = k
    return out


def _noise_ids(m: np.ndarray) -> np.ndarray:
    ids = np.random.default_rng(0).integers(1, 255, m.shape).astype(np.uint8)
    return np.where(m > 0, ids, 0).astype(np.uint8)


# --- every numeric setting at its bounds -------------------------------------------------------------------------
#: The method a section's settings are used by (the others: evidence, which reads extract, occlusion, segment, input).
_METHOD = {"paper": "paper", "fused": "fused", "superellipsoid": "superellipsoid", "sphere": "sphere"}


def settings_cases() -> None:
    from symfruit.settings import _sections

    for section, cls in _sections().items():
        for f in dataclasses.fields(cls):
            bounds = f.metadata.get("bounds", {})
            for op, limit in bounds.items():
                value: float = limit
                if op in ("gt", "lt"):  # just inside an open bound
                    value = limit + (1e-9 if op == "gt" else -1e-9)
                default = getattr(cls(), f.name)
                if isinstance(default, int) and not isinstance(default, bool):
                    value = int(limit) + (1 if op == "gt" else -1 if op == "lt" else 0)
                add(f"settings/{section}.{f.name}={value:g}", "any", _at_bound(section, f.name, value))


def _at_bound(section: str, name: str, value: float) -> Callable[[], Any]:
    def go() -> Any:
        from symfruit import Settings
        from symfruit.detect import detect
        from symfruit.io import read_frame

        settings = Settings().replace(**{section: {name: value}})  # a cross-field rule may refuse it, by name
        return detect(read_frame(small()), method=_METHOD.get(section, "evidence"), settings=settings)

    return go


# --- number options, temporaries' names ----------------------------------------------------------------------------
def option_cases() -> None:
    def option(name: str, *argv: Any) -> None:
        def go() -> Any:
            o = r49.out(f"option-{name}")
            return cli(*[o if a == "OUT" else small() if a == "IN" else a for a in argv], output=o)

        add(f"option/{name}", "error", go)

    option("n-arabic-indic", "scenes", "OUT", "--n", "٣")
    option("seed-full-width", "scenes", "OUT", "--seed", "３")
    option("workers-underscore", "detect", "IN", "--output", "OUT", "--workers", "1_0")
    option("fruit-processes-arabic", "detect", "IN", "--output", "OUT", "--fruit-processes", "١")
    option("timeout-arabic", "detect", "IN", "--output", "OUT", "--workers", "1", "--no-worker-timeout", "٣٠")
    option("bench-stream-0", "bench", "--frame", "--stream", "0")
    option("bench-stream-negative", "bench", "--frame", "--stream", "-3")
    option("bench-stream-huge", "bench", "--frame", "--stream", "1000000000")
    option("bench-stream-without-frame", "bench", "--stream", "3")
    option("bench-fruit-processes-17", "bench", "--frame", "--fruit-processes", "17")
    option("bench-size-arabic", "bench", "--segment", "--size", "٣٢٠x٢٤٠")

    def temporary() -> Any:
        o = r49.out("temporary-superscript")
        first = cli("detect", small(), "--output", o, "--method", "raw", output=o)
        if first.rc != 0:
            return first
        (o / "small_frame" / ".overlay.png.\u00b2-1.tmp").write_bytes(b"x")
        return cli("detect", small(), "--output", o, "--method", "raw", output=o)

    add("option/a-temporary-named-with-a-superscript-two", "any", temporary)


# --- detect interrupted ------------------------------------------------------------------------------------------
def interrupt_cases() -> None:
    def interrupted(how: signal.Signals, after: float, processes: int) -> Callable[[], Any]:
        def go() -> Any:
            rec = _recording(f"interrupt-{how.name}-{after}-{processes}", frames=6)
            o = r49.out(f"interrupt-{how.name}-{after}-{processes}")
            env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p.endswith("src"))}
            argv = [sys.executable, "-m", "symfruit", "detect", str(rec), "--output", str(o), "--method", "evidence",
                    "--fruit-processes", str(processes)]  # fmt: skip
            proc = subprocess.Popen(argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                    start_new_session=True)  # fmt: skip
            time.sleep(after)
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, how) if how == signal.SIGKILL else proc.send_signal(how)
            try:
                _, err = proc.communicate(timeout=90)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.communicate()
                return f"DEFECT: still running 90 s after {how.name}"
            if how == signal.SIGINT and b"Traceback" in err:
                return f"DEFECT: a traceback on {how.name}: {err.decode(errors='replace')[-200:]}"
            said = err.decode(errors="replace").strip().splitlines()
            if broken := _outputs_whole(o):
                return broken
            first = f"exit {proc.returncode}, {len(_written_frames(o))} frames written"
            again = cli("detect", rec, "--output", o, "--method", "evidence", "--resume", output=o)  # takes it up
            if again.rc != 0 or (broken := _outputs_whole(o)):
                return broken or f"DEFECT: --resume after {how.name}: exit {again.rc}: {again.err[-200:]}"
            import pyarrow.parquet as pq

            rows = pq.read_table(o / "frames.parquet").num_rows
            if _written_frames(o) != [f"f_{k}" for k in range(6)] or rows != 6:
                return f"DEFECT: --resume after {how.name}: {len(_written_frames(o))} frames written, {rows} rows"
            return f"{first} ({said[-1:]}); --resume: 6 frames, 6 rows"

        return go

    for how in (signal.SIGINT, signal.SIGKILL):
        for after in (2.5, 4.0, 6.0):
            for processes in (0, 1):
                add(f"interrupt/{how.name}-after-{after}s-fruit-processes-{processes}", "any",
                    interrupted(how, after, processes))  # fmt: skip


def resume_cases() -> None:
    def cut(name: str) -> Callable[[], Any]:
        def go() -> Any:
            import pyarrow.parquet as pq

            rec = _recording(f"resume-{name.replace('/', '-')}", frames=3)
            o = r49.out(f"resume-{name.replace('/', '-')}")
            first = cli("detect", rec, "--output", o, "--method", "raw", output=o)
            if first.rc != 0:
                return first
            data = (o / name).read_bytes()
            (o / name).write_bytes(data[: len(data) // 2])  # a run killed while it wrote it (no atomic rename)
            again = cli("detect", rec, "--output", o, "--method", "raw", "--resume", output=o)
            if broken := _outputs_whole(o):
                return broken
            if again.rc == 0 and any(pq.read_table(o / t).num_rows != 3 for t in ("frames.parquet",
                                                                                  "detections.parquet")):  # fmt: skip
                return "DEFECT: --resume left a table without its rows"
            return again

        return go

    for name in ("frames.parquet", "detections.parquet", "errors.json", "f_1/detections.json"):
        add(f"resume/{name.replace('/', '-')}-cut-in-half", "any", cut(name))


def _outputs_whole(o: Path) -> str | None:
    """DEFECT text where a final-named output of ``o`` cannot be read whole (a temporary may be left)."""
    import pyarrow.parquet as pq

    if not o.is_dir():
        return None
    for p in o.rglob("*"):
        if p.name.startswith(".") or not p.is_file():
            continue
        try:
            if p.suffix == ".json":
                json.loads(p.read_text())
            elif p.suffix == ".parquet":
                pq.read_table(p)
            elif p.suffix == ".png":
                from PIL import Image

                with Image.open(p) as im:
                    im.load()
            elif p.suffix == ".ply":
                from symfruit.io import read_cloud

                read_cloud(p)
        except Exception as exc:  # the point of the case
            return f"DEFECT: {p.relative_to(o)} half-written ({type(exc).__name__}: {str(exc)[:100]})"
    return None


def main() -> int:
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    if soft == resource.RLIM_INFINITY:
        resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, hard))
    builds = (left_cases, stream_cases, stream_api_cases, camera_cases, spheres_cases, option_cases, interrupt_cases,
              resume_cases, settings_cases)  # fmt: skip
    return r49.run_main(__doc__ or "", builds, CASES, prefix="robust56-", limit=LIMIT_S, width=60)


if __name__ == "__main__":
    sys.exit(main())
