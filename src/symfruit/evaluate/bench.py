"""The project's benchmark: time :func:`symfruit.complete` on a fixed, seeded partial strawberry view.

``symfruit bench`` prints the median wall time per fruit (one process, after a warm-up) for the
paper's 132 planes and for a 10x denser grid of 1,320 planes, the default ``evidence``, the previous
default ``fused``, ``superellipsoid`` and the simple baselines, on a partial strawberry of 600 and 3,000
points and on a depth-camera view of about 15,000 points.
"""

from __future__ import annotations

import os
import platform
import time
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..methods import DEFAULT_METHOD
from ..methods.complete import complete
from ..settings import Settings
from ..synthetic.views import bench_camera_view, bench_view

__all__ = [
    "DENSE_GRID",
    "STAGES",
    "BenchRow",
    "RecordingRow",
    "bench_camera_view",
    "bench_frame",
    "bench_recording",
    "bench_segment",
    "bench_segment_trees",
    "bench_stages",
    "bench_stream",
    "bench_view",
    "measured_detect",
    "profile_frame",
    "run_bench",
]

#: 10 x 22 x 6 = 1,320 planes: finer depth steps (0.08 len_depth), 2.5 deg about x, 4 deg about y.
DENSE_GRID = {
    "translations": 10,
    "translation_step": 0.08,
    "rotations_x": 22,
    "rotation_x_step": 2.5,
    "rotations_y": 6,
    "rotation_y_step": 4.0,
}


@dataclass(frozen=True)
class BenchRow:
    """One benchmark case: timings in milliseconds per fruit."""

    case: str
    method: str
    planes: int
    points: int
    median_ms: float
    p10_ms: float
    p90_ms: float
    repeat: int
    min_ms: float = float("nan")

    def to_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


def _time(fn: Any, repeat: int) -> np.ndarray:
    for _ in range(min(10, repeat)):
        fn()
    times = np.empty(repeat)
    for i in range(repeat):
        start = time.perf_counter()
        fn()
        times[i] = time.perf_counter() - start
    return times * 1000.0


def _row(case: str, method: str, planes: int, points: int, ms: np.ndarray) -> BenchRow:
    return BenchRow(case, method, planes, points, float(np.median(ms)), float(np.percentile(ms, 10)),
                    float(np.percentile(ms, 90)), len(ms), float(ms.min()))  # fmt: skip


def run_bench(
    *, repeat: int = 200, points: tuple[int, ...] = (600, 3000), camera_points: tuple[int, ...] = (15000,)
) -> list[BenchRow]:
    """Run every case ``repeat`` times; return one row per case.

    ``points``: sizes of the partial strawberry (:func:`bench_view`); ``camera_points``: sizes of the
    depth-camera view (:func:`bench_camera_view`), timed for the default and the fitting methods.
    """
    dense = Settings().replace(paper=DENSE_GRID)
    rows = []
    jobs: list[tuple[int, list[tuple[str, str, Settings, np.ndarray]]]] = []
    for n in points:
        clean, noisy = bench_view(n), bench_view(n, noise=0.001)
        jobs.append((n, [
            ("paper 132 planes", "paper", Settings(), clean),
            ("paper 1,320 planes", "paper", dense, clean),
            ("evidence, clean view", "evidence", Settings(), clean),
            ("evidence, 1 mm noise", "evidence", Settings(), noisy),
            ("fused, clean view", "fused", Settings(), clean),
            ("fused, 1 mm noise", "fused", Settings(), noisy),
            ("superellipsoid", "superellipsoid", Settings(), clean),
            ("sphere", "sphere", Settings(), clean),
            ("ellipsoid", "ellipsoid", Settings(), clean),
            ("raw", "raw", Settings(), clean),
        ]))  # fmt: skip
    for n in camera_points:
        view = bench_camera_view(n)
        jobs.append((len(view), [(f"{m}, camera view", m, Settings(), view)
                                 for m in ("evidence", "fused", "superellipsoid", "sphere", "paper")]))  # fmt: skip
    for n, cases in jobs:
        for name, method, settings, view in cases:
            ms = _time(lambda m=method, s=settings, v=view: complete(v, method=m, settings=s), repeat)
            planes = settings.paper.n_hypotheses if method == "paper" else 0
            rows.append(_row(name, method, planes, n, ms))
    return rows


def _bench_scene(sensor: str | None, seed: int) -> Any:
    """The benchmark's frame (see :func:`bench_frame`)."""
    from ..core.frame import Frame
    from ..synthetic.scenes import make_scene
    from ..synthetic.sensors import sensor_model

    model = None if sensor is None else sensor_model(sensor)
    scene = make_scene(seed, n_ripe=8, n_unripe=2, sensor=model)
    # Through a camera model the annotators' masks are used (as in the real-frame measurement of issue 18):
    # at 1-2 m the colour segmenter finds few of the 20-40 px berries, which would leave little to time.
    return Frame("bench", scene.color, scene.depth, scene.camera, masks=scene.masks), model


def bench_frame(
    *, repeat: int = 20, seed: int = 0, method: str = DEFAULT_METHOD, sensor: str | None = None, pool: Any = None
) -> BenchRow:
    """Time :func:`symfruit.detect.detect` end to end (segment, extract, complete, box; no file I/O)
    on a 640x480 synthetic frame with 8 ripe strawberries (and 2 unripe ones to ignore); with ``sensor``
    (a key of :data:`symfruit.synthetic.sensors.SENSOR_MODELS`) the frame is rendered through that camera
    model at its colour resolution (1920x1080 or 1280x720) and its annotators' masks are used instead of the
    colour segmenter. ``pool``: :func:`~symfruit.detect.detect`'s (a :class:`~symfruit.fruitpool.FruitPool`)."""
    from ..detect import detect

    frame, model = _bench_scene(sensor, seed)
    found = detect(frame, method=method, pool=pool)
    ms = _time(lambda: detect(frame, method=method, pool=pool), repeat)
    n = sum(d.result is not None for d in found.detections)
    where = "" if model is None else f", {sensor} {model.width}x{model.height}"
    return _row(f"frame, {n} fruit, {method}{where}", method, Settings().paper.n_hypotheses, n, ms)


#: The stages :func:`bench_stages` reports: ``detect``'s own timings (wall) and the thread's CPU time.
STAGES = ("segment", "trim", "register", "extract", "occlusion", "complete", "total", "cpu")


def bench_stages(
    *, repeat: int = 20, seed: int = 0, method: str = DEFAULT_METHOD, sensor: str | None = None, pool: Any = None
) -> dict[str, np.ndarray]:
    """Milliseconds per stage of :func:`bench_frame`'s frame, ``repeat`` runs after a warm-up: each of
    :data:`STAGES` (``detect``'s timings; ``trim`` and ``register`` are part of ``extract``, ``occlusion`` of
    ``complete``; ``cpu`` the CPU time of the calling thread over the frame, which a busy machine disturbs
    less than the wall time; with a ``pool``, :func:`~symfruit.detect.detect`'s, its workers' on their fruit too)."""
    from ..detect import detect

    frame, _ = _bench_scene(sensor, seed)
    for _ in range(min(5, repeat)):
        detect(frame, method=method, pool=pool)
    runs = [detect(frame, method=method, pool=pool).timings for _ in range(repeat)]
    return {stage: np.array([t[stage] for t in runs]) * 1000.0 for stage in STAGES}


def bench_stream(
    frames: int = 100, *, rounds: int = 3, method: str = DEFAULT_METHOD, pool: Any = None
) -> dict[str, dict[str, list[float]]]:
    """Frames per second over ``frames`` benchmark frames (:func:`bench_frame`'s, seeds 0-3 in turn), one after
    another as a recording's, no file I/O: ``detect`` on each (``pool``'s workers sharing each frame's fruit), and
    in a :class:`~symfruit.detect.DetectStream` (the next frame segmented while the workers end the last one's
    fruit; issue 19, stop 55). The two alternate (``rounds`` each, the first mode changing each round) after a
    warm-up of both. Per mode and round: ``fps`` (wall), ``cpu_ms`` (the calling thread's and the workers' CPU per
    frame, ``detect``'s ``cpu``), ``latency_ms`` (the median frame's own wall time, ``total``)."""
    from ..detect import DetectStream, detect

    scenes = [_bench_scene(None, seed)[0] for seed in range(4)]
    seq = [scenes[i % len(scenes)] for i in range(frames)]

    def alone(frames: list[Any]) -> list[Any]:
        return [detect(f, method=method, pool=pool) for f in frames]

    def streamed(frames: list[Any]) -> list[Any]:
        stream, out = DetectStream(pool, method=method), []
        try:
            for f in frames:
                ready = stream.prepare(f)
                found = stream.finish()
                if found is not None:
                    out.append(found)
                stream.start(ready)
            last = stream.finish()
            if last is not None:
                out.append(last)
        finally:
            stream.abandon()
        return out

    modes = {"detect": alone, "stream": streamed}
    for run in modes.values():
        run(seq[:8])
    got: dict[str, dict[str, list[float]]] = {m: {"fps": [], "cpu_ms": [], "latency_ms": []} for m in modes}
    for r in range(rounds):
        for name in ("detect", "stream") if r % 2 == 0 else ("stream", "detect"):
            t = time.perf_counter()
            found = modes[name](seq)
            wall = time.perf_counter() - t
            got[name]["fps"].append(len(found) / wall)
            got[name]["cpu_ms"].append(float(np.mean([f.timings["cpu"] for f in found])) * 1000.0)
            got[name]["latency_ms"].append(float(np.median([f.timings["total"] for f in found])) * 1000.0)
    return got


def profile_frame(
    *, repeat: int = 5, seed: int = 0, method: str = DEFAULT_METHOD, sensor: str | None = None, top: int = 30
) -> str:
    """A deterministic profile (:mod:`cProfile`) of :func:`bench_frame`'s frame, ``repeat`` runs after a
    warm-up: the ``top`` functions by their own time and by cumulative time, as text (times per frame)."""
    import cProfile
    import io
    import pstats

    from ..detect import detect

    frame, _ = _bench_scene(sensor, seed)
    detect(frame, method=method)
    profiler = cProfile.Profile()
    profiler.enable()
    for _ in range(repeat):
        detect(frame, method=method)
    profiler.disable()
    out = io.StringIO()
    stats = pstats.Stats(profiler, stream=out)
    out.write(f"cProfile of {repeat} frames, method {method} (times are totals over the {repeat} frames)\n")
    stats.sort_stats("tottime").print_stats(top)
    stats.sort_stats("cumulative").print_stats(top)
    return out.getvalue()


@dataclass(frozen=True)
class SegmentRow:
    """Time of the colour segmenter per image (milliseconds; one process, after a warm-up)."""

    images: int
    source: str
    width: int
    height: int
    median_ms: float
    p90_ms: float
    max_ms: float

    def to_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


def bench_segment(
    images: str | Path | None = None, *, size: tuple[int, int] = (640, 480), limit: int = 1000, repeat: int = 1
) -> SegmentRow:
    """Time :func:`symfruit.segment.colour.segment` (colour alone) per image, the images resized to ``size``
    (width, height) before timing.

    ``images`` is a folder of photographs (the first ``limit`` in name order); without it, 24 seeded
    synthetic photos (:func:`symfruit.synthetic.scenes.make_photo`: one to three fruit with seeds, highlights and a
    calyx). Each image is timed ``repeat`` times and its fastest run kept.
    """
    from PIL import Image

    from ..segment.colour import segment

    if images is not None:
        from ..batch import expand_images
        from ..io.images import read_color

        paths = expand_images([images])[: max(1, limit)]

        def load(path: Path) -> np.ndarray:
            return np.asarray(Image.fromarray(read_color(path)).resize(size, Image.Resampling.BILINEAR))

        frames: Iterable[np.ndarray] = (load(p) for p in paths)  # one at a time: 1000 1080p images are 6 GB
        first = load(paths[0])
        source = str(images)
    else:
        from ..synthetic.scenes import make_photo

        rng = np.random.default_rng(0)
        photos = []
        for k in range(24):
            n = 1 + k % 3
            r = float(rng.uniform(0.08, 0.14)) * size[1]
            fruit = [(float(rng.uniform(r, size[0] - r)), float(rng.uniform(r, size[1] - r)), r, (200, 35, 45))
                     for _ in range(n)]  # fmt: skip
            photos.append(make_photo(fruit, shape=(size[1], size[0]), seed=k, calyx=True)[0])
        frames, first = photos, photos[0]
        source = "synthetic photos"
    segment(first)
    ms = []
    for frame in frames:
        best = float("inf")
        for _ in range(max(1, repeat)):
            start = time.perf_counter()
            segment(frame)
            best = min(best, time.perf_counter() - start)
        ms.append(best * 1000.0)
    t = np.array(ms)
    return SegmentRow(len(t), source, size[0], size[1], float(np.median(t)), float(np.percentile(t, 90)),
                      float(t.max()))  # fmt: skip


def bench_segment_trees(n: int = 6, *, seed: int = 0, repeat: int = 3) -> SegmentRow:
    """Time :func:`symfruit.segment.colour.segment` with depth on ``n`` rendered apple-tree frames
    (:func:`symfruit.synthetic.scenes.make_tree_scene`, seeds ``seed`` on: 1920x1080 through the Azure Kinect
    model, about 30 apples among 2,500 leaves) with the apple profile's segmenter settings; each frame
    timed ``repeat`` times and its fastest run kept (the frames are rendered before any timing)."""
    from ..segment.colour import segment
    from ..settings import resolve_settings
    from ..synthetic.scenes import make_tree_scene

    settings = resolve_settings(fruit="apple").segment
    frames = [make_tree_scene(seed + k) for k in range(max(1, n))]
    segment(frames[0].color, frames[0].depth, frames[0].camera, settings)
    ms = []
    for f in frames:
        best = float("inf")
        for _ in range(max(1, repeat)):
            start = time.perf_counter()
            segment(f.color, f.depth, f.camera, settings)
            best = min(best, time.perf_counter() - start)
        ms.append(best * 1000.0)
    t = np.array(ms)
    h, w = frames[0].color.shape[:2]
    return SegmentRow(len(t), "rendered apple-tree frames", w, h, float(np.median(t)),
                      float(np.percentile(t, 90)), float(t.max()))  # fmt: skip


@dataclass(frozen=True)
class RecordingRow:
    """Peak memory and speed of ``symfruit detect`` over a generated recording (in a child process)."""

    frames: int
    method: str
    seconds: float
    peak_rss_mb: float
    frames_done: int
    #: On a local Dask cluster (``workers``): the peak of each worker process (MB), the time to start the
    #: cluster (not in ``seconds``), and the cost of one task round trip without work (ms).
    workers: int = 0
    worker_peak_mb: tuple[float, ...] = ()
    startup_seconds: float = 0.0
    task_overhead_ms: float = 0.0
    task_wall_ms: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


#: Run in the child of :func:`bench_recording`: ``symfruit detect``, then the child's own peak RSS (the high
#: water mark of its memory map, ``VmHWM``; ``ru_maxrss`` would also count the parent it was forked from).
_MEASURED_DETECT = """
import json, resource, sys
from symfruit.cli import main
status = main(sys.argv[1:])
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
files = float("nan")
try:
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM:"):
            peak = int(line.split()[1]) / 1024.0
        elif line.startswith("RssFile:"):
            files = int(line.split()[1]) / 1024.0
except OSError:
    pass
print(json.dumps({"status": status, "peak_rss_mb": peak, "file_rss_mb": files}))
"""


def measured_detect(args: list[str], *, timeout: float | None = None, own: bool = False) -> tuple[int, float, str]:
    """Run ``symfruit detect ARGS`` in a child process: ``(exit status, its peak RSS in MB, its stderr)``.

    ``own``: the peak less the files the child has mapped and resident at its end (``RssFile``: its shared
    libraries' pages, numba's and LLVM's some 180 MB among them, whose resident share follows the page cache,
    not the run: a freshly installed environment read about 75 MB more than an older one for the same run; stop
    61), NaN where the kernel does not say."""
    import json
    import subprocess
    import sys

    proc = subprocess.run([sys.executable, "-c", _MEASURED_DETECT, "detect", *args], capture_output=True, text=True,
                          timeout=timeout, check=False)  # fmt: skip
    lines = proc.stdout.strip().splitlines()
    if proc.returncode != 0 or not lines:
        return proc.returncode, float("nan"), proc.stderr
    data = json.loads(lines[-1])
    peak = float(data["peak_rss_mb"]) - (float(data.get("file_rss_mb", float("nan"))) if own else 0.0)
    return int(data["status"]), peak, proc.stderr


#: Run in the child of :func:`bench_recording` with ``workers``: a local Dask cluster (as ``detect --workers``
#: starts), the cost of trivial task round trips, the detect run on it, then every process's peak memory.
_MEASURED_CLUSTER = """
import json, sys, time
import distributed
from symfruit.batch import run_batch
from symfruit.season.cluster import Job, Outcome, Part, local_cluster, worker_peak_mb
from symfruit.settings import resolve_settings
from symfruit.season.table import frame_rows


def empty_task(job, part):  # a detect task's arguments and answer (six fruit), without the work
    fruit = {"id": 1, "centre": [0.0, 0.0, 0.4], "box": {"size": [0.03, 0.03, 0.03]}, "mask_area": 900,
             "n_points": 800, "truncated": False, "method": "evidence", "confidence": 0.9, "reliable": True}
    frame, fruits = frame_rows({"frame": part.names[0], "fruits": [fruit] * 6}, job.recording)
    return [Outcome(part.indices[0], part.names[0], "done", frame=frame, fruits=fruits)]


rec, out, method, workers = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
settings = resolve_settings(fruit="strawberry")
t0 = time.perf_counter()
with local_cluster(workers) as cluster, distributed.Client(cluster) as client:
    client.wait_for_workers(workers)
    client.run(lambda: __import__("symfruit.season.cluster"))
    startup = time.perf_counter() - t0
    job = Job("bench", rec, rec, out, "rec", (), (), (), "auto", method, settings)
    n = 400
    cpu = lambda: sum(client.run(time.process_time).values())
    c0, w0, t1 = time.process_time(), cpu(), time.perf_counter()
    futures = [client.submit(empty_task, job, Part((k,), (f"f{k}",), (f"{out}/f{k}",)), pure=False) for k in range(n)]
    for future in distributed.as_completed(futures):
        future.result()
    wall = (time.perf_counter() - t1) / n * 1000.0
    overhead = ((time.process_time() - c0) + (cpu() - w0)) / n * 1000.0
    del futures
    t2 = time.perf_counter()
    report = run_batch(rec, out, method=method, settings=settings, progress=False, scheduler=cluster.scheduler_address)
    seconds = time.perf_counter() - t2
    peaks = sorted(client.run(worker_peak_mb).values())
print(json.dumps({"seconds": seconds, "startup": startup, "overhead_ms": overhead, "wall_ms": wall,
                  "workers": peaks, "client": worker_peak_mb(), "done": len(report.done)}))
"""


def bench_recording(
    frames: int = 500, *, method: str = DEFAULT_METHOD, workdir: str | Path | None = None, workers: int | None = None,
    fruit_processes: int = 0,
) -> RecordingRow:  # fmt: skip
    """Run ``symfruit detect`` on a generated ``frames``-frame recording in a child process and report its
    peak resident memory and wall time: memory must not grow with ``frames``. With ``workers``, on a local Dask
    cluster of that many processes (127.0.0.1): the client's peak, each worker's, the start-up time, and the
    overhead of one task: 400 tasks that take and return what a detect task does but do no work, their CPU
    time (client with its scheduler, and the workers) and their wall time, per task. ``fruit_processes``:
    ``detect --fruit-processes`` (the frames then go in a stream; the workers' start is in the time and the
    child's peak, theirs not)."""
    import json
    import subprocess
    import sys
    import tempfile

    from ..errors import SymfruitError
    from ..methods import get

    get(method)  # an unknown method refused before the recording is made, not measured as frames that all fail
    with tempfile.TemporaryDirectory(dir=workdir) as tmp:
        from ..synthetic.scenes import write_scenes

        rec = Path(tmp) / "rec"
        write_scenes(rec, frames, distinct=4, n_ripe=8, n_unripe=2)
        out = Path(tmp) / "out"
        if workers is None:
            start = time.perf_counter()
            extra = ["--fruit-processes", str(fruit_processes)] if fruit_processes else []
            status, peak, err = measured_detect([str(rec), "--output", str(out), "--method", method, *extra])
            seconds = time.perf_counter() - start
            if status != 0:  # a run that failed is no measurement: before, '0 written, peak RSS nan MB', exit 0
                said = err.strip().splitlines()[-1:] or ["(nothing on stderr)"]
                raise SymfruitError(f"bench --recording: detect exited with status {status}: {said[0]}")
            done = len(list(out.glob("*/detections.json")))
            return RecordingRow(frames, method, seconds, peak, done)
        proc = subprocess.run([sys.executable, "-c", _MEASURED_CLUSTER, str(rec), str(out), method, str(workers)],
                              capture_output=True, text=True, check=False)  # fmt: skip
        lines = proc.stdout.strip().splitlines()
        if proc.returncode != 0 or not lines:
            raise SymfruitError(f"the cluster benchmark failed: {proc.stderr.strip()[-500:]}")
        data = json.loads(lines[-1])
    return RecordingRow(frames, method, float(data["seconds"]), float(data["client"]), int(data["done"]), workers,
                        tuple(data["workers"]), float(data["startup"]), float(data["overhead_ms"]),
                        float(data["wall_ms"]))  # fmt: skip


def machine() -> dict[str, Any]:
    """What the numbers were measured on."""
    return {
        "python": platform.python_version(),
        "numpy": np.__version__,
        "machine": platform.machine(),
        "cpus": os.cpu_count(),
    }
