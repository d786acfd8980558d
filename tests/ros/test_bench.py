"""symfruit.ros.bench: its statistics, its reading of the node's log line, the example messages, and one
short real run (a master, the node as a subprocess, three frames)."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from symfruit.ros.bench import _LINE, _stats, _summarise


def test_stats_known_answer():
    s = _stats([5.0, 1.0, 3.0, 2.0, 4.0])
    assert s == {"n": 5, "median": 3.0, "p10": 1.4, "p90": 4.6}
    empty = _stats([])
    assert empty["n"] == 0 and np.isnan(empty["median"])


def test_the_node_log_line_is_read():
    line = ("[INFO] [1764619200.1]: symfruit: frame 1003.500000000: 6 fruit in 89.2 ms (detect 88.2 ms, node 0.9 ms: "
            "wait 0.1, decode 0.2, collect 0.0, publish 0.5), 0 dropped so far")  # fmt: skip
    m = _LINE.search(line)
    assert m is not None
    assert m.groups() == ("1003", "500000000", "89.2", "88.2", "0.9", "0.1", "0.2", "0.0", "0.5")
    assert _LINE.search(line.replace("6 fruit", "1 fruit (2 failed)")) is not None


def test_the_summary_reads_closed_loop_frames_only_and_counts_the_open_loop():
    def line(stamp, total, detect, node):
        return (f"symfruit: frame {stamp}.000000000: 2 fruit in {total} ms (detect {detect} ms, node {node} ms: "
                "wait 0.1, decode 0.2, collect 0.3, publish 0.4), 0 dropped so far")  # fmt: skip

    log = "\n".join([line(1000, 9, 9, 9), line(1001, 50.0, 40.0, 2.0), line(1002, 60.0, 44.0, 4.0),
                      line(5000, 99, 99, 99), "an unrelated line"])  # fmt: skip
    out = _summarise({"process_alone_ms": {"median": 30.0}}, log, {1001: 70.0, 1002: 80.0, 1003: 90.0},
                     frames=4, delivered=[0.0, 0.1, 0.3], span=0.5)  # fmt: skip
    assert out["node_total_ms"]["n"] == 2 and out["node_total_ms"]["median"] == 55.0  # warm-up and open loop left out
    assert out["node_overhead_each_ms"] == [2.0, 4.0]
    assert out["node_publish_ms"]["median"] == 0.4
    assert out["end_to_end_ms"]["median"] == 80.0
    assert out["end_to_end_minus_node_detect_ms"]["median"] == 33.0  # (70 - 40, 80 - 44); frame 1003 has no log line
    assert out["end_to_end_minus_detect_alone_ms"] == 50.0
    assert out["open_loop"] == {"sent": 4, "delivered": 3, "dropped": 1, "fps": 4.0}


def test_example_images_are_what_a_camera_driver_publishes(example_images):
    from symfruit.demo import example_frame
    from symfruit.io.frames import read_frame

    rgb, raw, cam = example_images
    assert rgb.dtype == np.uint8 and rgb.shape == (cam.height, cam.width, 3)
    assert raw.dtype == np.dtype("<u2") and raw.shape == (cam.height, cam.width)
    with example_frame() as folder:
        frame = read_frame(folder)
    np.testing.assert_allclose(raw / 1000.0, frame.depth, rtol=0, atol=1e-6)  # millimetres (16UC1); depth is float32
    assert np.array_equal(rgb, frame.color)


def test_a_short_real_run(ros1, tmp_path):
    out = tmp_path / "bench.json"
    proc = subprocess.run([sys.executable, "-m", "symfruit.ros.bench", "--frames", "2", "--method", "raw",
                           "--json", str(out), "--fruit-processes", "0"],
                          capture_output=True, text=True, timeout=600)  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-3000:]
    res = json.loads(out.read_text())
    assert res["frames"] == 2 and res["process_alone_ms"]["n"] == 2 and res["method"] == "raw"
    assert res["node_total_ms"]["n"] == 2 and res["end_to_end_ms"]["n"] == 2
    assert 0.0 <= res["node_overhead_ms"]["median"] < res["node_total_ms"]["median"]
    assert 1 <= res["open_loop"]["delivered"] <= 2  # the last frame is never dropped
    assert "node: overhead" in proc.stdout
    assert res["fruit_processes"] == 0 and "the node's fruit_processes 0" in proc.stdout


def test_bad_counts_and_rates_are_refused_before_anything_starts(capsys):
    from symfruit.ros.bench import main

    for args in (["--rate", "0"], ["--frames", "-5"], ["--frames", "1000000"], ["--rate", "1e9"]):
        with pytest.raises(SystemExit) as stop:
            main(args)
        assert stop.value.code == 2
        assert "--frames must be 1-100000 and --rate in (0, 1000] Hz" in capsys.readouterr().err


def test_the_nodes_fruit_processes_are_bounded_before_anything_starts(capsys):
    from symfruit.ros.bench import main

    for bad in ("-1", "17"):
        with pytest.raises(SystemExit) as stop:
            main(["--fruit-processes", bad])
        assert stop.value.code == 2
        assert f"--fruit-processes must be 0-16, got {bad}" in capsys.readouterr().err


def test_number_options_take_ascii_digits_alone(capsys):
    """Stop 56: ``int()`` and ``float()`` also read another script's digits and ``1_0``; the benchmark's options
    refuse them by name, as every symfruit number option does (``symfruit.cli._whole``, ``_real``)."""
    from symfruit.ros.bench import main

    for args in (["--frames", "٣"], ["--frames", "1_0"], ["--rate", "３0"], ["--fruit-processes", "١"]):
        with pytest.raises(SystemExit) as stop:
            main(args)
        assert stop.value.code == 2
        err = capsys.readouterr().err
        assert "ASCII digits" in err and args[0] in err, (args, err)
