"""symfruit.ros.bench2 (`make ros2-bench`): one short real run in the ROS 2 venv (the node as a subprocess, one
frame), read like the ROS 1 benchmark's (its statistics and log-line reading are tested in test_bench.py)."""

from __future__ import annotations

import json
import subprocess


def test_a_short_real_run(ros2_python, tmp_path):
    out = tmp_path / "bench.json"
    proc = subprocess.run([ros2_python, "-m", "symfruit.ros.bench2", "--frames", "1", "--method", "raw",
                           "--json", str(out), "--fruit-processes", "0"],
                          capture_output=True, text=True, timeout=600)  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-3000:]
    res = json.loads(out.read_text())
    assert res["frames"] == 1 and res["process_alone_ms"]["n"] == 1
    assert res["node_total_ms"]["n"] == 1 and res["end_to_end_ms"]["n"] == 1
    assert 0.0 <= res["node_overhead_ms"]["median"] < res["node_total_ms"]["median"]
    assert res["end_to_end_ms"]["median"] > res["node_detect_ms"]["median"] > 0
    assert res["open_loop"]["delivered"] == 1  # the last frame is never dropped
    assert res["fruit_processes"] == 0
    assert proc.stdout.startswith("symfruit ROS 2 node benchmark") and "node: overhead" in proc.stdout


def test_a_rate_of_zero_is_refused_before_anything_starts(ros2_python):
    proc = subprocess.run([ros2_python, "-m", "symfruit.ros.bench2", "--rate", "0"], capture_output=True, text=True,
                          timeout=120)  # fmt: skip
    assert proc.returncode == 2 and "--rate in (0, 1000] Hz, got 30 and 0" in proc.stderr
