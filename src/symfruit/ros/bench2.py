"""Latency benchmark of the ROS 2 node on the example frame: ``python -m symfruit.ros.bench2`` (``make ros2-bench``,
in the ROS 2 venv).

The same three measurements as the ROS 1 benchmark (:mod:`symfruit.ros.bench`), on ROS 2:

1. ``detect`` alone: :class:`~symfruit.ros.core.FrameProcessor` on the example frame's messages, in this
   process, before anything else runs.
2. Closed loop: ``symfruit ros2`` as a subprocess, this process publishing one frame as the RealSense wrapper
   does (:class:`~symfruit.ros.camera2.Camera`) and waiting for its detections before the next: the node's own
   per-frame split from its log (total, detect, node = total - detect: waiting for the worker, decoding,
   collecting, building and publishing), and the end-to-end time from publishing to receiving the detections
   (adds Fast DDS's transport of ~1.5 MB of images and the detections back).
3. Open loop: frames published at ``--rate`` Hz for ``--frames`` frames: frames per second delivered and how
   many the node dropped (it keeps only the newest waiting frame).

Both processes discover on this machine only, on a domain of their own (:func:`~symfruit.ros.camera2.domain_lease`).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from ..methods import DEFAULT_METHOD
from .bench import _alone, _summarise, example_images, run_main
from .master import stop_group

__all__ = ["bench_node2", "main"]


def bench_node2(
    frames: int = 30,
    *,
    rate: float = 30.0,
    method: str = DEFAULT_METHOD,
    fruit: str = "strawberry",
    timeout: float = 120.0,
    fruit_processes: int | None = None,
) -> dict:
    """Run the three measurements; returns their statistics in milliseconds (and fps, drops), with the keys of
    :func:`symfruit.ros.bench.bench_node`."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor

    from .camera2 import Camera, Listener, domain_lease, frame_messages, isolated_env, use_writer_profile
    from .core import FrameProcessor

    # 1. detect alone
    images = example_images()
    # rclpy's messages, as the node receives them
    out = _alone(FrameProcessor(method=method, fruit=fruit), frame_messages(images, 1), frames=frames, rate=rate,
                 method=method)  # fmt: skip
    with domain_lease() as domain, tempfile.TemporaryDirectory(prefix="symfruit-ros2-bench-") as home:
        env = isolated_env(domain, Path(home))
        for key in ("ROS_AUTOMATIC_DISCOVERY_RANGE", "ROS_DOMAIN_ID", "RMW_IMPLEMENTATION"):  # this process too
            os.environ[key] = env[key]
        use_writer_profile()  # the camera's writers repair a lost fragment in 50 ms, not 3 s (camera2)
        context = rclpy.Context()
        rclpy.init(context=context, domain_id=domain)
        node = rclpy.create_node("symfruit_bench", context=context)
        camera, listener = Camera(node, images), Listener(node, points=False, markers=False)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        spinner = threading.Thread(target=executor.spin, daemon=True)
        spinner.start()
        log = Path(home) / "node.log"
        with open(log, "wb") as handle:
            cmd = [sys.executable, "-m", "symfruit", "ros2", "--ros-args", "-p", f"method:={method}", "-p",
                   f"fruit:={fruit}",
                   *([] if fruit_processes is None else ["-p", f"fruit_processes:={fruit_processes}"])]  # fmt: skip
            proc = subprocess.Popen(cmd, env=env, stdout=handle, stderr=subprocess.STDOUT, start_new_session=True)
        try:
            deadline = time.monotonic() + timeout
            while not (camera.matched() and listener.matched(node)):
                if proc.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f"the node did not come up: {log.read_text(errors='replace')[-2000:]}")
                time.sleep(0.01)  # the graph has no event to wait on

            # 2. closed loop: one frame at a time
            e2e: dict[int, float] = {}
            for i in range(frames + 1):
                t0 = camera.publish(1000 + i)
                got = listener.wait("detections", 1000 + i, 0, timeout)
                if got is None:
                    raise RuntimeError(f"no detections for frame {i}: {log.read_text(errors='replace')[-2000:]}")
                if i:  # the first frame warms the node up
                    e2e[1000 + i] = (got[0] - t0) * 1e3
            # 3. open loop at `rate` Hz
            sent_at = []
            start = time.perf_counter()
            for i in range(frames):
                time.sleep(max(0.0, start + i / rate - time.perf_counter()))
                sent_at.append(camera.publish(5000 + i))
            listener.wait("detections", 5000 + frames - 1, 0, timeout)  # the last frame is never dropped
            with listener.cond:
                got_at = [(key, t) for key, (t, _) in listener.got.items()]
            delivered = sorted(t for (kind, s, _), t in got_at if kind == "detections" and s >= 5000)
            span = delivered[-1] - sent_at[0] if delivered else float("nan")
        finally:
            stop_group(proc, 30)
            executor.shutdown()
            node.destroy_node()
            spinner.join(10)
            rclpy.try_shutdown(context=context)
            context.destroy()
        log_text = log.read_text(errors="replace")
    # the node's fruit_processes parameter (None: not given, the node's default)
    return {**_summarise(out, log_text, e2e, frames=frames, delivered=delivered, span=span),
            "fruit_processes": fruit_processes}  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    return run_main(argv, "python -m symfruit.ros.bench2", __doc__.splitlines()[0], bench_node2,
                    "symfruit ROS 2 node benchmark")  # fmt: skip


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
