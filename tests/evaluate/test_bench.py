"""The benchmark's fixed inputs: the seeded partial view and the dense grid."""

import numpy as np
import pytest

from symfruit.evaluate.bench import DENSE_GRID, bench_frame, bench_view


def test_bench_view_is_fixed_and_partial():
    a, b = bench_view(), bench_view()
    assert a.shape == (600, 3) and np.array_equal(a, b)
    assert 0.28 < a[:, 2].min() < a[:, 2].max() < 0.33
    assert not np.array_equal(bench_view(seed=1), a)


def test_dense_grid_is_ten_times_the_papers():
    assert DENSE_GRID["translations"] * DENSE_GRID["rotations_x"] * DENSE_GRID["rotations_y"] == 1320


def test_noisy_views_are_the_clean_view_plus_seeded_noise():
    clean, noisy = bench_view(300), bench_view(300, noise=0.001)
    assert noisy.shape == clean.shape and np.array_equal(noisy, bench_view(300, noise=0.001))
    assert 0.0008 < np.std(noisy - clean) < 0.0012


@pytest.mark.slow
def test_a_frame_through_a_real_camera_is_timed_at_its_resolution():
    row = bench_frame(repeat=1, method="raw", sensor="realsense-d405")
    assert "realsense-d405 1280x720" in row.case and row.median_ms > 0 and row.points >= 1
