"""The benchmark's fixed views: seeded, partial, the noisy one the clean one plus seeded noise."""

import numpy as np

from symfruit.synthetic.views import bench_camera_view, bench_view


def test_bench_view_is_fixed_and_partial():
    a, b = bench_view(), bench_view()
    assert a.shape == (600, 3) and np.array_equal(a, b)
    assert 0.28 < a[:, 2].min() < a[:, 2].max() < 0.33
    assert not np.array_equal(bench_view(seed=1), a)


def test_noisy_views_are_the_clean_view_plus_seeded_noise():
    clean, noisy = bench_view(300), bench_view(300, noise=0.001)
    assert noisy.shape == clean.shape and np.array_equal(noisy, bench_view(300, noise=0.001))
    assert 0.0008 < np.std(noisy - clean) < 0.0012


def test_the_camera_view_has_about_the_asked_points_and_is_fixed():
    a = bench_camera_view(2000)
    assert abs(len(a) - 2000) < 0.1 * 2000 and np.array_equal(a, bench_camera_view(2000))
