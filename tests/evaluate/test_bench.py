"""The benchmark: its dense grid and the segmenter's timing on synthetic photos."""

import pytest

from symfruit.evaluate.bench import DENSE_GRID


def test_dense_grid_is_ten_times_the_papers():
    assert DENSE_GRID["translations"] * DENSE_GRID["rotations_x"] * DENSE_GRID["rotations_y"] == 1320


@pytest.mark.slow
def test_bench_segment_times_24_synthetic_photos():
    from symfruit.evaluate.bench import bench_segment

    row = bench_segment()
    assert row.images == 24 and row.source == "synthetic photos" and row.width == 640 and row.median_ms > 0


@pytest.mark.slow
def test_bench_segment_times_rendered_apple_tree_frames_with_depth():
    from symfruit.evaluate.bench import bench_segment_trees

    row = bench_segment_trees(1, seed=3, repeat=1)
    assert row.images == 1 and (row.width, row.height) == (1920, 1080) and "apple-tree" in row.source
    assert row.median_ms > 0


@pytest.mark.slow
def test_a_frame_through_a_real_camera_is_timed_at_its_resolution():
    from symfruit.evaluate.bench import bench_frame

    row = bench_frame(repeat=1, method="raw", sensor="realsense-d405")
    assert "realsense-d405 1280x720" in row.case and row.median_ms > 0 and row.points >= 1


@pytest.mark.slow
def test_the_frame_profile_lists_detect_and_the_method():
    from symfruit.evaluate.bench import profile_frame

    text = profile_frame(repeat=1, method="raw", top=5)
    assert "method raw" in text and "detect" in text and "tottime" in text


@pytest.mark.slow
def test_a_frame_row_has_its_fastest_run_at_most_its_median():
    from symfruit.evaluate.bench import bench_frame

    row = bench_frame(repeat=3, method="raw")
    assert row.repeat == 3 and 0 < row.min_ms <= row.median_ms <= row.p90_ms


def test_bench_recording_refuses_an_unknown_method_and_a_detect_run_that_failed(tmp_path, monkeypatch):
    from symfruit.errors import InputError, SymfruitError
    from symfruit.evaluate import bench

    with pytest.raises(InputError, match="unknown method 'nope'"):  # before: every frame failed, measured
        bench.bench_recording(1, method="nope", workdir=tmp_path)
    monkeypatch.setattr(bench, "measured_detect", lambda args: (2, float("nan"), "symfruit: error: boom\n"))
    with pytest.raises(SymfruitError, match="detect exited with status 2: symfruit: error: boom"):
        bench.bench_recording(1, workdir=tmp_path)  # before: '1 frames (0 written), peak RSS nan MB', exit 0


def test_bench_stream_times_frames_alone_and_in_a_stream_alternated():
    """Stop 55: ``bench --frame --stream``'s rows: frames/s, CPU and the median frame's time per mode and round."""
    from symfruit.evaluate.bench import bench_stream

    got = bench_stream(3, rounds=2, method="raw")
    assert set(got) == {"detect", "stream"}
    for row in got.values():
        assert set(row) == {"fps", "cpu_ms", "latency_ms"} and all(len(v) == 2 for v in row.values())
        assert all(v > 0 for values in row.values() for v in values)


def test_bench_recording_runs_detect_with_its_fruit_processes(tmp_path, monkeypatch):
    from symfruit.evaluate import bench
    from symfruit.synthetic import scenes

    ran = []
    monkeypatch.setattr(scenes, "write_scenes", lambda folder, n, **kwargs: folder.mkdir())
    monkeypatch.setattr(bench, "measured_detect", lambda args: ran.append(args) or (0, 1.0, ""))
    bench.bench_recording(2, method="raw", workdir=tmp_path, fruit_processes=1)
    bench.bench_recording(2, method="raw", workdir=tmp_path)
    assert ran[0][-2:] == ["--fruit-processes", "1"] and "--fruit-processes" not in ran[1]
