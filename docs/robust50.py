"""Stop 50: bad and adversarial input past stops 43-49's sweeps (robust50).

What the earlier sweeps (docs/robust43.py: the array API; robust47-49: the command line and the readers) did not
reach: the library's writers and helpers (``write_frame`` with images or a camera of other sizes, a camera that
is a mapping, read-only, big-endian and float16 depth; ``write_ply`` of no path, NaN or 6 million points;
``camera_from_dict`` of NaN, zero, negative or huge values; ``Settings``, ``Box``, ``Plane``, ``frame_rows``);
``symfruit report`` on a run whose tables were damaged or disagree (a frame or fruit listed twice, fruit of no
listed frame, counts not their rows', rows without names, empty tables, odd ``--classes``); ``detect --resume``
over a frame folder copied over another; the ROS frame processor's big-endian and padded images and camera infos
of zeros; and the three items stop 49 left: a ROS 2 bag compressed as whole files (a zstd bomb, and an MCAP
inside it whose record claims a terabyte), a ROS 1 chunk that expands past its own stated size, and a Dask
scheduler without workers.

Cases run in this process under an alarm and are judged as docs/robust47.py judges them (its ``judge``, ``cli``
and helpers are imported; robust48's and robust49's classifiers of Python's words too). A library call's case
returns its value (``result``) or raises a ``SymfruitError`` (``error``); any other exception is a defect, and so
is a result where an error was expected. A case that checks a rule itself (a bound, a re-run, the same result)
returns ``DEFECT: ...`` when the rule is broken.

::

    PYTHONPATH=src python docs/robust50.py                 # every case (fixtures in a temporary folder)
    PYTHONPATH=src python docs/robust50.py --only report/ --defects
"""

from __future__ import annotations

import json
import shutil
import sys
import time
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import robust47 as r47
import robust49 as r49

#: A case's alarm (s): the scheduler without workers waited for ever before.
LIMIT_S = 90
#: robust49's helpers: the fixtures' folder (``T()``), a fresh fixture path, an output folder, the command line.
ROOT, T, fixture, cli, Run = r47.ROOT, r49.T, r49.fixture, r47.cli, r47.Run
F640 = ROOT / "examples/realsense/aligned_00000"
CASES: list[tuple[str, str, Callable[[], Any], str]] = []


def add(name: str, expect: str, fn: Callable[[], Any], names: str = "") -> None:
    CASES.append((name, expect, fn, names))


def small() -> tuple[np.ndarray, np.ndarray, Any]:
    sys.path.insert(0, str(ROOT))
    from tests.conftest import SMALL_CAM, disc_frame

    color, depth = disc_frame([(60, 60), (110, 60)], radius=15)
    return color, depth, SMALL_CAM


# --- the library's writers and helpers --------------------------------------------------------------------------
def api_cases() -> None:
    import symfruit
    from symfruit.io import camera_from_dict, write_frame, write_ply
    from symfruit.season.table import frame_rows

    pts = np.random.default_rng(0).normal(size=(300, 3)) * 0.01 + [0, 0, 0.3]

    def ply(points: Any, **kw: Any) -> Callable[[], Any]:
        return lambda: write_ply(fixture("w.ply"), points, **kw)

    add("api/write_ply/path-none", "error", lambda: write_ply(None, pts))  # type: ignore[arg-type]
    add("api/write_ply/path-empty", "error", lambda: write_ply("", pts))
    add("api/write_ply/nan", "any", ply(np.full((5, 3), np.nan)))
    add("api/write_ply/empty", "any", ply(np.zeros((0, 3))))
    add("api/write_ply/int", "any", ply(np.ones((5, 3), int)))
    add("api/write_ply/bigendian", "result", ply(pts.astype(">f8")))
    add("api/write_ply/readonly", "result", ply(np.require(pts, requirements="C").copy().view()))
    add("api/write_ply/labels-2^40", "error", ply(pts, labels=np.full(len(pts), 2**40)))
    add("api/write_ply/6e6-points", "any", ply(np.zeros((6_000_000, 3), np.float32)))

    color, depth, cam = small()

    def frame(**change: Any) -> Callable[[], Any]:
        def go() -> Any:
            args = {"color": color, "depth": depth, "camera": cam, **change}
            return write_frame(fixture("wf"), **args)

        return go

    ro = depth.copy()
    ro.flags.writeable = False
    add("api/write_frame/good", "result", frame())
    add("api/write_frame/depth-smaller", "error", frame(depth=depth[:60]))
    add("api/write_frame/depth-transposed", "error", frame(depth=np.ascontiguousarray(depth.T)))
    add("api/write_frame/masks-smaller", "error", frame(masks=np.zeros((60, 160), np.uint8)))
    d435 = symfruit.Camera(fx=615.0, fy=615.0, cx=320.0, cy=240.0, width=640, height=480)
    add("api/write_frame/camera-other-size", "error", frame(camera=d435))
    add("api/write_frame/camera-mapping", "error", frame(camera=cam.to_dict()))
    add("api/write_frame/depth-nan", "result", frame(depth=np.where(depth > 0, np.nan, depth)))
    add("api/write_frame/depth-negative", "any", frame(depth=-depth))
    add("api/write_frame/depth-float16", "result", frame(depth=depth.astype(np.float16)))
    add("api/write_frame/depth-bigendian", "result", frame(depth=depth.astype(">f4")))
    add("api/write_frame/depth-readonly", "result", frame(depth=ro))
    add("api/write_frame/depth-noncontig", "result", frame(depth=np.repeat(depth, 2, axis=1)[:, ::2]))
    add("api/write_frame/depth-uint16-mm", "error", frame(depth=(depth * 1000).astype(np.uint16)))
    add("api/write_frame/depth-100m", "error", frame(depth=depth * 500))
    add("api/write_frame/masks-2^40", "error", frame(masks=np.full(depth.shape, 2**40)))
    add("api/write_frame/depth_scale-nan", "error", frame(depth_scale=float("nan")))

    base = {"fx": 615.0, "fy": 615.0, "cx": 320.0, "cy": 240.0, "width": 640, "height": 480}
    for key, value in [("fx", float("nan")), ("fx", -1.0), ("fx", 0.0), ("fy", float("inf")), ("width", 0),
                       ("width", -5), ("width", 1.5), ("height", True), ("cx", "a"), ("fx", None), ("fx", [1.0]),
                       ("width", 10**20), ("fx", 1e-300), ("cx", 1e300)]:  # fmt: skip
        add(f"api/camera_from_dict/{key}={value!r:.12}", "error",
            lambda key=key, value=value: camera_from_dict({**base, key: value}))  # fmt: skip
    add("api/camera_from_dict/list", "error", lambda: camera_from_dict([1, 2]))

    def said_with_an() -> Any:
        try:
            symfruit.Settings(evidence=5)  # type: ignore[arg-type]
        except symfruit.ConfigError as exc:
            if " a E" in str(exc):
                return f"DEFECT: Python's article: {exc}"
            raise
        return "DEFECT: taken"

    add("api/Settings/section-int", "error", said_with_an)
    add("api/Box/nan", "error", lambda: symfruit.Box([np.nan, 0, 0], [1, 1, 1]))
    add("api/Box/min-beyond-max", "error", lambda: symfruit.Box([1, 0, 0], [0, 1, 1]))
    add("api/Box/contains-1e6", "result", lambda: symfruit.Box(np.zeros(3), np.ones(3)).contains(np.zeros((10**6, 3))))
    add("api/box_iou/arrays", "error", lambda: symfruit.box_iou(np.zeros(3), np.ones(3)))  # type: ignore[arg-type]
    add("api/Plane/zero-normal", "error", lambda: symfruit.Plane(np.zeros(3), np.zeros(3)))
    add("api/Plane/nan", "error", lambda: symfruit.Plane(np.zeros(3), [np.nan, 0, 1]))

    record = {"frame": "f", "fruits": [{"id": 1, "centre": [0.0, 0.0, 0.3], "box": {"size": [0.03, 0.03, 0.03]},
                                        "error": None}]}  # fmt: skip

    def rows(edit: Callable[[dict], Any]) -> Callable[[], Any]:
        def go() -> Any:
            r = json.loads(json.dumps(record))
            edit(r)
            return frame_rows(r, "rec")

        return go

    add("api/frame_rows/good", "result", rows(lambda r: None))
    add("api/frame_rows/size-text", "error", rows(lambda r: r["fruits"][0]["box"].update(size=["a", 1, 1])))
    add("api/frame_rows/size-negative", "error", rows(lambda r: r["fruits"][0]["box"].update(size=[-1, 1, 1])))
    add("api/frame_rows/id-10^30", "error", rows(lambda r: r["fruits"][0].update(id=10**30)))
    add("api/frame_rows/frame-int", "error", rows(lambda r: r.update(frame=5)))
    add("api/frame_rows/fruit-none", "error", rows(lambda r: r.update(fruits=[None])))


# --- symfruit report on damaged runs ------------------------------------------------------------------------------
def run_fixture() -> Path:
    run = T() / "base50" / "run"
    if not (run / "frames.parquet").exists():
        rec = T() / "base50" / "rec"
        for k in range(3):
            if not (rec / f"f_{k}").exists():
                shutil.copytree(F640, rec / f"f_{k}")
        done = cli("detect", rec, "--output", run, "--method", "sphere")
        if done.rc:
            raise RuntimeError(f"the run fixture failed: {done.err[-300:]}")
    return run


def report_cases() -> None:
    def damaged(name: str, table: str | None, edit: Callable[[list[dict]], list[dict]] | None, expect: str,
                names: str = "", argv: tuple[str, ...] = ()) -> None:  # fmt: skip
        def go() -> Run:
            import pyarrow as pa
            import pyarrow.parquet as pq

            d = fixture(f"report-{name}")
            shutil.copytree(run_fixture(), d)
            for t in ([table] if table else ["detections", "frames"]) if edit else []:
                p = d / f"{t}.parquet"
                read = pq.read_table(p)
                rows = edit(read.to_pylist())  # type: ignore[misc]
                pq.write_table(pa.Table.from_pylist(rows, schema=read.schema) if rows else read.schema.empty_table(),
                               p)  # fmt: skip
            return cli("report", d, *argv)

        add(f"report/{name}", expect, go, names)

    def at(col: str, value: Any, k: int = 0) -> Callable[[list[dict]], list[dict]]:
        return lambda rows: [dict(r, **{col: value}) if i == k else r for i, r in enumerate(rows)]

    damaged("fruit-of-an-unknown-recording", "detections", at("recording", "other"), "error", "detections.parquet")
    damaged("fruit-of-an-unknown-frame", "detections", at("frame", "nope"), "error", "detections.parquet")
    damaged("frame-listed-twice", "frames", lambda r: [*r, r[0]], "error", "frames.parquet")
    damaged("fruit-listed-twice", "detections", lambda r: [*r, r[0]], "error", "detections.parquet")
    damaged("counts-above-the-rows", "frames", lambda r: [dict(r[0], fruit=5, located=5), *r[1:]], "error",
            "frames.parquet")  # fmt: skip
    damaged("located-not-the-rows", "detections", at("error", "failed"), "error", "frames.parquet")
    damaged("frame-recording-null", "frames", at("recording", None), "error", "frames.parquet")
    damaged("frame-name-null", "frames", at("frame", None), "error", "frames.parquet")
    damaged("fruit-recording-null", "detections", at("recording", None), "error", "detections.parquet")
    damaged("no-fruit-rows", "detections", lambda r: [], "error", "frames.parquet")
    damaged("no-frame-rows", "frames", lambda r: [], "error", "detections.parquet")
    damaged("both-tables-empty", None, lambda r: [], "any")
    damaged("size-nan", "detections", at("size_x", float("nan")), "result")
    damaged("method-of-100000-characters", "detections", lambda r: [dict(x, method="m" * 100_000) for x in r], "any")
    damaged("recording-with-a-bar-and-a-newline", None, lambda r: [dict(x, recording="a\nb|c") for x in r], "result")
    damaged("seconds-negative", "frames", at("seconds", -5.0), "any")

    def large_string() -> Run:  # another tool's text type for the names: the tables compared alike
        import pyarrow as pa
        import pyarrow.parquet as pq

        d = fixture("report-large-string")
        shutil.copytree(run_fixture(), d)
        t = pq.read_table(d / "frames.parquet")
        k = t.schema.get_field_index("recording")
        pq.write_table(t.set_column(k, pa.field("recording", pa.large_string()), t.column(k).cast(pa.large_string())),
                       d / "frames.parquet")  # fmt: skip
        return cli("report", d)

    add("report/names-of-large_string", "result", large_string)
    for label, classes in [("descending", "25,18"), ("nan", "18,nan"), ("empty", ""), ("1e400", "18,1e400"),
                           ("text", "small,large"), ("zero", "0,18")]:  # fmt: skip
        damaged(f"classes-{label}", None, None, "error", "", ("--classes", classes))

    def copied_over() -> Any:
        d = fixture("resume-copied")
        shutil.copytree(run_fixture(), d)
        (d / "f_2" / "detections.json").write_bytes((d / "f_0" / "detections.json").read_bytes())
        again = cli("detect", T() / "base50" / "rec", "--output", d, "--method", "sphere", "--resume", output=d)
        import pyarrow.parquet as pq

        names = pq.read_table(d / "frames.parquet").column("frame").to_pylist()
        if sorted(names) != ["f_0", "f_1", "f_2"]:
            return f"DEFECT: a frame folder copied over another is skipped: the tables list {names}"
        return again

    add("resume/a-frame-folder-copied-over-another", "result", copied_over)


# --- the ROS frame processor ----------------------------------------------------------------------------------------
def ros_cases() -> None:
    from symfruit.ros.bench import example_images

    rgb, raw, cam = example_images()
    h, w = raw.shape
    header = SimpleNamespace(stamp=SimpleNamespace(sec=7, nanosec=5), frame_id="cam")

    def img(a: np.ndarray, encoding: str, *, big: int = 0, pad: int = 0) -> SimpleNamespace:
        a = np.ascontiguousarray(a)
        rows = a.reshape(a.shape[0], -1).view(np.uint8)
        rows = np.pad(rows, ((0, 0), (0, pad)))
        return SimpleNamespace(height=a.shape[0], width=a.shape[1], encoding=encoding, is_bigendian=big,
                               step=rows.shape[1], data=rows.tobytes(), header=header)  # fmt: skip

    def info(k: list[float] | None = None, d: list[float] | None = None) -> SimpleNamespace:
        k = k or [cam.fx, 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0]
        return SimpleNamespace(width=w, height=h, header=header, distortion_model="plumb_bob", k=k, d=d or [0.0] * 5)

    procs: list[Any] = []

    def proc() -> Any:
        if not procs:
            from symfruit.ros.core import FrameProcessor

            procs.append(FrameProcessor(masks="color", method="sphere"))
        return procs[0]

    def boxes(done: Any) -> list[Any]:
        return [np.round(np.r_[f.centre, f.size], 9).tolist() for f in done.fruits]

    def same_as_little(depth_msg: Callable[[], SimpleNamespace]) -> Callable[[], Any]:
        def go() -> Any:
            little = proc().process(img(rgb, "rgb8"), img(raw, "16UC1"), info())
            other = proc().process(img(rgb, "rgb8"), depth_msg(), info())
            if boxes(little) != boxes(other):
                return "DEFECT: the depth read otherwise than its little-endian twin"
            return other

        return go

    add("ros/depth-16UC1-bigendian", "result", same_as_little(lambda: img(raw.astype(">u2"), "16UC1", big=1)))
    add("ros/depth-32FC1-bigendian", "result",
        same_as_little(lambda: img((raw * np.float32(0.001)).astype(">f4"), "32FC1", big=1)))  # fmt: skip
    add("ros/depth-16UC1-rows-padded", "result", same_as_little(lambda: img(raw, "16UC1", pad=64)))
    add("ros/colour-rows-padded", "result", lambda: proc().process(img(rgb, "rgb8", pad=7), img(raw, "16UC1"), info()))
    add("ros/depth-is_bigendian-2", "any", lambda: proc().process(img(rgb, "rgb8"), img(raw, "16UC1", big=2), info()))
    add("ros/info-k-zeros", "error", lambda: proc().process(img(rgb, "rgb8"), img(raw, "16UC1"), info(k=[0.0] * 9)))
    add("ros/info-d-inf", "error",
        lambda: proc().process(img(rgb, "rgb8"), img(raw, "16UC1"), info(d=[float("inf")] * 5)))  # fmt: skip
    add("ros/depth-all-65535", "any",
        lambda: proc().process(img(rgb, "rgb8"), img(np.full_like(raw, 65535), "16UC1"), info()))  # fmt: skip
    add("ros/depth-one-pixel-wide", "error", lambda: proc().process(img(rgb, "rgb8"), img(raw[:, :1], "16UC1"), info()))


# --- what stop 49 left: bags compressed as whole files, ROS 1 chunk sizes, a scheduler without workers -------------
def bag_cases() -> None:
    def zstd_module() -> Any:
        try:
            from compression import zstd  # type: ignore[import-not-found]
        except ImportError:
            from backports import zstd
        return zstd

    def file_bag(name: str, payload: Callable[[bytes], bytes]) -> Path:
        sys.path.insert(0, str(ROOT))
        from tests.io.test_bags import write_ros2_bag

        color, depth, _ = small()
        good = fixture(f"{name}-good")
        write_ros2_bag(good, color, (depth * 1000).astype(np.uint16), frames=2, storage="mcap",
                       compression=("file", "zstd"))  # fmt: skip
        packed = next(good.glob("*.mcap.zstd"))
        bag = fixture(name)
        bag.mkdir()
        (bag / "metadata.yaml").write_text((good / "metadata.yaml").read_text())
        zstd = zstd_module()
        (bag / packed.name).write_bytes(zstd.compress(payload(zstd.decompress(packed.read_bytes()))))
        return bag

    def file_bomb() -> Any:
        from symfruit.io import bags

        bag = file_bag("file-bomb", lambda plain: plain + bytes(256 << 20))  # 256 MB of zeros in ~10 kB
        room = getattr(bags, "bag_file_room", None)
        if room is not None:
            bags.bag_file_room = lambda: 16 << 20  # type: ignore[attr-defined]  # a disk of 16 MB free
        try:
            o = r49.out("file-bomb")
            run = cli("detect", bag, "--output", o, output=o)
        finally:
            if room is not None:
                bags.bag_file_room = room  # type: ignore[attr-defined]
        if "expands past" not in run.err:
            return f"DEFECT: decompressed whole (256 MB) to the disk before it was read: {run.err.strip()[-160:]}"
        return run

    add("bag/ros2-file-compressed-bomb", "error", file_bomb, "file-bomb")

    def file_record() -> Any:
        def claim(plain: bytes) -> bytes:
            raw = bytearray(plain)
            raw[9:17] = (1 << 40).to_bytes(8, "little")  # the MCAP header record claims a TB
            return bytes(raw)

        bag = file_bag("file-record", claim)
        o = r49.out("file-record")
        run = cli("detect", bag, "--output", o, output=o)
        if "record at byte" not in run.err:
            return f"DEFECT: rosbags asked for the TB the record claims: {run.err.strip()[-160:]}"
        return run

    add("bag/ros2-file-compressed-record-of-a-terabyte", "error", file_record, "file-record")

    def ros1_stated() -> Any:
        sys.path.insert(0, str(ROOT))
        from tests.io.test_realsense import rewrite

        path = rewrite(fixture("stated.bag"))
        data = bytearray(path.read_bytes())
        field, at = b"\x09\x00\x00\x00size=", 0
        while (at := data.find(field, at)) >= 0:
            at += len(field)
            data[at : at + 4] = (int.from_bytes(data[at : at + 4], "little") // 2).to_bytes(4, "little")
        path.write_bytes(bytes(data))
        o = r49.out("stated")
        return cli("detect", path, "--output", o, output=o)

    add("bag/ros1-chunk-past-its-stated-size", "error", ros1_stated, "stated.bag")

    def no_workers() -> Any:
        from distributed import LocalCluster

        import symfruit.season.cluster as cluster

        cluster.NO_WORKER_TIMEOUT = 5.0  # type: ignore[attr-defined]  # read at the call (60 s by default)
        with LocalCluster(n_workers=0, processes=False, protocol="tcp://", host="127.0.0.1",
                          dashboard_address=None, scheduler_kwargs=cluster.LOCAL_SCHEDULER_HTTP) as empty:  # fmt: skip
            o = r49.out("no-workers")
            start = time.monotonic()
            run = cli("detect", T() / "base50" / "rec", "--output", o, "--method", "sphere", "--scheduler",
                      empty.scheduler_address, output=o)  # fmt: skip
            if time.monotonic() - start > 30:
                return f"DEFECT: waited {time.monotonic() - start:.0f} s"
            return run

    add("dask/a-scheduler-without-workers", "error", no_workers, "no worker")


def main() -> int:
    return r49.run_main(
        __doc__, (api_cases, report_cases, ros_cases, bag_cases), CASES, prefix="robust50-", limit=LIMIT_S, width=52
    )


if __name__ == "__main__":
    sys.exit(main())
