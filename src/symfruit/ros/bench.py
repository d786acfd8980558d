"""Latency benchmark of the ROS 1 node on the example frame: ``python -m symfruit.ros.bench``.

1. ``detect`` alone: :class:`~symfruit.ros.core.FrameProcessor` on the example frame's messages, in
   this process, before anything else runs.
2. Closed loop: a real master, ``symfruit ros`` as a subprocess, this process publishing one frame
   and waiting for its detections before the next: the node's own per-frame split (total, detect,
   node = total - detect: decoding, message building, publishing) from its log, and the end-to-end
   time from publishing to receiving the detections (adds rospy's transport of ~1.5 MB of images).
3. Open loop: frames published at ``--rate`` Hz (a camera's pace) for ``--frames`` frames: frames per
   second the node delivers and how many it dropped (it keeps only the newest waiting frame).
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import threading
import time
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from ..fruitpool import MAX_FRUIT_PROCESSES
from ..methods import DEFAULT_METHOD
from .master import stop_group

__all__ = ["bench_node", "main"]

#: The node's per-frame log line: total, detect, node overhead and its parts (ms).
_LINE = re.compile(
    r"frame (\d+)\.(\d+): \d+ fruit.* in ([\d.]+) ms \(detect ([\d.]+) ms, node ([\d.]+) ms: "
    r"wait ([\d.]+), decode ([\d.]+), collect ([\d.]+), publish ([\d.]+)\)"
)
_PARTS = ("wait", "decode", "collect", "publish")


def _stats(values_ms) -> dict[str, float]:
    v = np.asarray(values_ms, float)
    if not len(v):
        return {"n": 0, "median": float("nan"), "p10": float("nan"), "p90": float("nan")}
    return {
        "n": len(v),
        "median": float(np.median(v)),
        "p10": float(np.percentile(v, 10)),
        "p90": float(np.percentile(v, 90)),
    }


def example_images() -> tuple[np.ndarray, np.ndarray, Any]:
    """The shipped example frame as a camera driver publishes it: (h, w, 3) uint8 RGB, (h, w) uint16
    millimetres, and its :class:`~symfruit.core.camera.Camera`."""
    from ..demo import example_frame
    from ..io.frames import read_frame
    from ..io.images import read_depth_units

    with example_frame() as folder:
        frame = read_frame(folder)
        raw = read_depth_units(folder / "depth.png").astype("<u2")
    return frame.color, raw, frame.camera


def _example_messages(stamp, images=None):
    from sensor_msgs.msg import CameraInfo, Image
    from std_msgs.msg import Header

    rgb, raw, cam = images if images is not None else example_images()
    h, w = raw.shape
    head = Header(stamp=stamp, frame_id="camera_color_optical_frame")
    k = [cam.fx, 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0]
    return (
        Image(header=head, height=h, width=w, encoding="rgb8", is_bigendian=0, step=w * 3, data=rgb.tobytes()),
        Image(header=head, height=h, width=w, encoding="16UC1", is_bigendian=0, step=w * 2, data=raw.tobytes()),
        CameraInfo(header=head, height=h, width=w, K=k),
    )


def bench_node(
    frames: int = 30,
    *,
    rate: float = 30.0,
    method: str = DEFAULT_METHOD,
    fruit: str = "strawberry",
    timeout: float = 120.0,
    fruit_processes: int | None = None,
) -> dict:
    """Run the three measurements; returns their statistics in milliseconds (and fps, drops)."""
    from .core import FrameProcessor
    from .master import RosMaster
    from .node import require_rospy
    from .ros1_msgs import load_vision_msgs

    rospy, _ = require_rospy()
    from sensor_msgs.msg import CameraInfo, Image

    # 1. detect alone
    images = example_images()
    out = _alone(FrameProcessor(method=method, fruit=fruit), _example_messages(rospy.Time(1, 0), images),
                 frames=frames, rate=rate, method=method)  # fmt: skip
    with RosMaster() as master:
        for key in ("ROS_MASTER_URI", "ROS_HOSTNAME", "ROS_HOME", "ROS_LOG_DIR"):
            os.environ[key] = master.env[key]
        rospy.init_node("symfruit_bench", anonymous=True, disable_signals=True)
        vm = load_vision_msgs()
        got: dict[tuple[int, int], float] = {}
        cond = threading.Condition()

        def on_detections(msg):
            with cond:
                got[(msg.header.stamp.secs, msg.header.stamp.nsecs)] = time.perf_counter()
                cond.notify_all()

        sub = rospy.Subscriber("/symfruit/detections", vm.Detection3DArray, on_detections)
        pubs = [
            rospy.Publisher("/camera/color/image_raw", Image, queue_size=10),
            rospy.Publisher("/camera/aligned_depth_to_color/image_raw", Image, queue_size=10),
            rospy.Publisher("/camera/color/camera_info", CameraInfo, queue_size=10),
        ]
        log = master.home / "node.log"
        with open(log, "wb") as handle:
            node = subprocess.Popen(
                [
                    sys.executable,
                    "-m",
                    "symfruit",
                    "ros",
                    f"_method:={method}",
                    f"_fruit:={fruit}",
                    *([] if fruit_processes is None else [f"_fruit_processes:={fruit_processes}"]),
                ],
                env={**master.env, "PYTHONUNBUFFERED": "1"},
                stdout=handle,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
        try:
            deadline = time.monotonic() + timeout
            while not (all(p.get_num_connections() for p in pubs) and sub.get_num_connections()):
                if node.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f"the node did not come up: {log.read_text(errors='replace')[-2000:]}")
                time.sleep(0.01)

            def publish(secs: int, nsecs: int) -> float:
                stamp = rospy.Time(secs, nsecs)
                batch = _example_messages(stamp, images)
                t = time.perf_counter()
                for pub, m in zip(pubs, batch, strict=True):
                    pub.publish(m)
                return t

            # 2. closed loop: one frame at a time
            e2e: dict[int, float] = {}
            for i in range(frames + 1):
                t0 = publish(1000 + i, 0)
                with cond:
                    if not cond.wait_for(partial(got.__contains__, (1000 + i, 0)), timeout):
                        raise RuntimeError(f"no detections for frame {i}: {log.read_text(errors='replace')[-2000:]}")
                if i:  # the first frame warms the node up
                    e2e[1000 + i] = (got[(1000 + i, 0)] - t0) * 1e3
            # 3. open loop at `rate` Hz
            sent_at = []
            start = time.perf_counter()
            for i in range(frames):
                target = start + i / rate
                time.sleep(max(0.0, target - time.perf_counter()))
                sent_at.append(publish(5000 + i, 0))
            with cond:
                cond.wait_for(lambda: (5000 + frames - 1, 0) in got, timeout)  # the last frame is never dropped
            delivered = sorted(t for (s, _), t in got.items() if s >= 5000)
            span = delivered[-1] - sent_at[0] if delivered else float("nan")
        finally:
            stop_group(node, 30)
            rospy.signal_shutdown("bench done")
        log_text = log.read_text(errors="replace")
    # the node's fruit_processes parameter (None: not given, the node's default)
    return {**_summarise(out, log_text, e2e, frames=frames, delivered=delivered, span=span),
            "fruit_processes": fruit_processes}  # fmt: skip


def _alone(core, msgs, *, frames: int, rate: float, method: str) -> dict:
    """The benchmark's first part, shared by both nodes' benchmarks: ``core`` (a ``FrameProcessor``) on the
    same messages ``frames`` times after one warm-up, without a node: wall time per call and ``detect``'s own."""
    core.process(*msgs)
    alone, alone_detect = [], []
    for _ in range(frames):
        t0 = time.perf_counter()
        p = core.process(*msgs)
        alone.append((time.perf_counter() - t0) * 1e3)
        alone_detect.append(p.found.timings["total"] * 1e3)
    return {
        "frames": frames,
        "rate_hz": rate,
        "method": method,
        "process_alone_ms": _stats(alone),
        "detect_alone_ms": _stats(alone_detect),
    }


def _summarise(out: dict, log_text: str, e2e: dict[int, float], *, frames: int, delivered: list[float],
               span: float) -> dict:  # fmt: skip
    """The node's per-frame timings (its log lines of the closed-loop frames), end to end and the open loop's
    delivery, added to ``out`` (the ROS 1 and ROS 2 benchmarks report alike)."""
    lines = [m.groups() for m in map(_LINE.search, log_text.splitlines()) if m]
    closed = {int(g[0]): tuple(map(float, g[2:])) for g in lines if 1001 <= int(g[0]) < 5000}
    out["node_total_ms"] = _stats([c[0] for c in closed.values()])
    out["node_detect_ms"] = _stats([c[1] for c in closed.values()])
    out["node_overhead_ms"] = _stats([c[2] for c in closed.values()])
    out["node_overhead_each_ms"] = [c[2] for _, c in sorted(closed.items())]
    for k, part in enumerate(_PARTS, 3):
        out[f"node_{part}_ms"] = _stats([c[k] for c in closed.values()])
    out["end_to_end_ms"] = _stats(list(e2e.values()))
    # per frame: everything but the node's own detect() (transport both ways, decoding, messages)
    out["end_to_end_minus_node_detect_ms"] = _stats([e2e[k] - closed[k][1] for k in e2e if k in closed])
    out["end_to_end_minus_detect_alone_ms"] = out["end_to_end_ms"]["median"] - out["process_alone_ms"]["median"]
    out["open_loop"] = {
        "sent": frames,
        "delivered": len(delivered),
        "dropped": frames - len(delivered),
        "fps": (len(delivered) - 1) / span if len(delivered) > 1 else float("nan"),
    }
    return out


def _print(res: dict, title: str = "symfruit ROS node benchmark") -> None:
    rows = [
        ("detect alone (core.process)", res["process_alone_ms"]),
        ("  of which detect()", res["detect_alone_ms"]),
        ("node: total per frame", res["node_total_ms"]),
        ("node: detect()", res["node_detect_ms"]),
        ("node: overhead (total - detect)", res["node_overhead_ms"]),
        ("  wait for the worker thread", res["node_wait_ms"]),
        ("  decode the three messages", res["node_decode_ms"]),
        ("  collect the fruit (bbox_record)", res["node_collect_ms"]),
        ("  build and publish the outputs", res["node_publish_ms"]),
        ("end to end (publish -> detections)", res["end_to_end_ms"]),
        ("end to end - node detect() (per frame)", res["end_to_end_minus_node_detect_ms"]),
    ]
    workers = res.get("fruit_processes")
    said = "its default" if workers is None else workers
    print(f"{title}: example frame 640x480, method {res['method']}, {res['frames']} frames, the node's "
          f"fruit_processes {said}")  # fmt: skip
    print(f"{'':<38} {'median ms':>10} {'p10':>8} {'p90':>8}")
    for name, s in rows:
        print(f"{name:<38} {s['median']:>10.1f} {s['p10']:>8.1f} {s['p90']:>8.1f}")
    ol = res["open_loop"]
    print(f"end to end (median) minus detect alone (median): {res['end_to_end_minus_detect_alone_ms']:.1f} ms")
    print(
        f"open loop at {res['rate_hz']:g} Hz: {ol['delivered']} of {ol['sent']} frames delivered "
        f"({ol['dropped']} dropped), {ol['fps']:.1f} frames/s"
    )


def run_main(argv: list[str] | None, prog: str, description: str, bench: Any, title: str) -> int:
    """The command line of both node benchmarks (``bench``: :func:`bench_node` or ``bench_node2``): parse and bound
    the options before anything starts, run, print under ``title``, write ``--json`` atomically."""
    from ..cli import _real, _whole  # ASCII digits alone, as every symfruit number option (stop 56)

    parser = argparse.ArgumentParser(prog=prog, description=description)
    parser.add_argument("--frames", type=_whole, default=30)
    parser.add_argument("--rate", type=_real, default=30.0, help="open-loop publishing rate, Hz (default 30)")
    parser.add_argument("--method", default=DEFAULT_METHOD)
    parser.add_argument("--json", type=Path, help="also write the figures to this JSON file")
    parser.add_argument("--fruit-processes", type=_whole, default=None, metavar="N",
                        help="the node's fruit_processes parameter, 0-16 (default: the node's own, 1)")  # fmt: skip
    args = parser.parse_args(argv)
    if not 1 <= args.frames <= 100_000 or not 0 < args.rate <= 1000:
        parser.error(f"--frames must be 1-100000 and --rate in (0, 1000] Hz, got {args.frames} and {args.rate:g}")
    if args.fruit_processes is not None and not 0 <= args.fruit_processes <= MAX_FRUIT_PROCESSES:
        parser.error(f"--fruit-processes must be 0-{MAX_FRUIT_PROCESSES}, got {args.fruit_processes}")
    res = bench(args.frames, rate=args.rate, method=args.method, fruit_processes=args.fruit_processes)
    _print(res, title=title)
    if args.json:
        import json

        from ..io.atomic import atomic_write

        with atomic_write(args.json, "w") as handle:  # whole or not at all, like every file symfruit writes
            handle.write(json.dumps(res, indent=2))
    return 0


def main(argv: list[str] | None = None) -> int:
    return run_main(argv, "python -m symfruit.ros.bench", __doc__.splitlines()[0], bench_node,
                    "symfruit ROS node benchmark")  # fmt: skip


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
