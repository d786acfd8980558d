"""The benchmark's fixed inputs: the seeded partial view, the dense grid, generated recordings."""

import numpy as np

from symfruit.bench import DENSE_GRID, bench_view, make_recording


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


def test_a_generated_recording_repeats_its_scenes_cheaply(tmp_path):
    import os

    from symfruit.io.sources import open_source

    rec = make_recording(tmp_path / "rec", 5, distinct=2)
    src = open_source(rec)
    assert src.names() == [f"frame_{i:05d}" for i in range(5)]
    for i in (2, 4):  # frame i repeats scene i % 2
        for name in ("color.png", "depth.png", "camera.json", "truth.json"):
            a, b = rec / f"frame_{i:05d}" / name, rec / f"frame_{i % 2:05d}" / name
            assert a.read_bytes() == b.read_bytes()
            assert os.path.samefile(a, b) or a.stat().st_nlink == 1  # a hard link where the file system has them
    assert not np.array_equal(src.read(0).color, src.read(1).color)
    assert len(src.read(3).truth) == 8
