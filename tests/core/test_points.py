"""Point arrays at the core's boundary: normalisation (:func:`as_points`) and the fruit checks (:func:`check_cloud`)."""

import re

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from symfruit import InputError
from symfruit.core.points import as_points, check_cloud, subsample

from ..conftest import VISIBLE


def test_lists_tuples_and_integers_become_contiguous_float64():
    for given_points in ([[1, 2, 3], [4, 5, 6]], ((1, 2, 3), (4, 5, 6)), np.array([[1, 2, 3], [4, 5, 6]], np.int32)):
        arr = as_points(given_points)
        assert arr.dtype == np.float64 and arr.shape == (2, 3) and arr.flags.c_contiguous
        assert arr.tolist() == [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]
    strided = np.arange(18, dtype=np.float32).reshape(6, 3)[::2]
    assert as_points(strided).flags.c_contiguous and as_points(strided).tolist() == strided.tolist()


def test_float64_arrays_pass_through_unchanged():
    arr = np.random.default_rng(0).random((5, 3))
    out = as_points(arr)
    assert out is arr or np.shares_memory(out, arr)
    assert np.array_equal(out, arr)


@pytest.mark.parametrize(
    "points, message",
    [
        (np.zeros(3), r"shape \(n, 3\), got \(3,\)"),
        (np.zeros((5, 2)), r"got \(5, 2\)"),
        (np.zeros((5, 4)), r"got \(5, 4\)"),
        (np.zeros((2, 3, 3)), r"got \(2, 3, 3\)"),
        (5.0, r"got \(\)"),
        ([[1, 2], [3, 4, 5]], "numeric"),
        ([["x", "y", "z"]], "numeric"),
        (np.ones((2, 3), complex), "real numbers"),
        (None, "numeric|shape"),
    ],
)
def test_anything_else_is_refused_with_what_was_expected(points, message):
    with pytest.raises(InputError, match=message):
        as_points(points)


def test_minimum_count_and_name_are_in_the_message():
    with pytest.raises(InputError, match="normals must hold at least 4 points, got 2"):
        as_points(np.zeros((2, 3)), min_count=4, name="normals")
    assert as_points(np.zeros((0, 3)), min_count=0).shape == (0, 3)


@given(st.lists(st.tuples(st.integers(-1000, 1000), st.integers(-1000, 1000), st.integers(-1000, 1000)), min_size=1))
def test_integer_lists_keep_their_values(rows):
    assert np.array_equal(as_points(rows), np.array(rows, dtype=np.float64))


def test_a_clean_cloud_passes_unchanged():
    clean, dropped = check_cloud(VISIBLE)
    assert dropped == 0 and np.array_equal(clean, VISIBLE)
    listed, _ = check_cloud(VISIBLE.tolist())
    assert np.array_equal(listed, VISIBLE)


def test_non_finite_rows_are_dropped_and_counted():
    dirty = np.vstack([VISIBLE[:5], [[np.nan, 0, 0.3]], VISIBLE[5:], [[0, np.inf, 0.3], [0, 0, -np.inf]]])
    clean, dropped = check_cloud(dirty)
    assert dropped == 3 and np.array_equal(clean, VISIBLE)


def test_large_clouds_are_down_sampled_to_a_fixed_ordered_subset():
    rng = np.random.default_rng(1)
    d = rng.normal(size=(5000, 3))
    cloud = 0.03 * d / np.linalg.norm(d, axis=1, keepdims=True) + [0.0, 0.0, 0.4]
    a, _ = check_cloud(cloud, max_points=1000)
    b, _ = check_cloud(cloud.copy(), max_points=1000)
    assert len(a) == 1000 and np.array_equal(a, b)
    index = {tuple(p): i for i, p in enumerate(cloud)}
    picked = [index[tuple(p)] for p in a]
    assert picked == sorted(picked)  # a subset of the input rows, in their order


@pytest.mark.parametrize(
    "points, kwargs, message",
    [
        (VISIBLE[:8], {}, r"at least 10 points, got 8"),
        (VISIBLE[:8], {"section": "input"}, r"\(input\.min_points sets the limit\)"),
        (np.vstack([VISIBLE[:5], np.full((6, 3), np.nan)]), {}, "got 5 after dropping 6 non-finite"),
        (VISIBLE - [0, 0, 0.34], {}, "at or behind the camera"),
        (VISIBLE * 100, {"section": "input"}, r"too large for one fruit \(input\.max_extent = 1\.0 m\)"),
        (VISIBLE * 0.01 + [0, 0, 0.3], {"min_extent": 0.003}, r"too small for a fruit \(min_extent = 3 mm\)"),
        (np.tile([[0.0, 0.0, 0.3]], (20, 1)), {}, "identical"),
        (np.c_[np.linspace(0, 0.02, 20), np.linspace(0, 0.02, 20), np.full(20, 0.3)], {}, "on a line"),
        (np.c_[np.random.default_rng(0).random((30, 2)) * 0.02, np.full(30, 0.3)], {}, "on a plane"),
    ],
)
def test_what_cannot_be_a_fruit_is_refused(points, kwargs, message):
    with pytest.raises(InputError, match=message):
        check_cloud(points, **kwargs)


def test_limits_are_keywords():
    clean, _ = check_cloud(VISIBLE[:8], min_points=4)
    assert len(clean) == 8
    with pytest.raises(InputError, match="too large"):
        check_cloud(VISIBLE, max_extent=0.01)


@given(st.integers(0, 2**32 - 1), st.integers(1, 80))
def test_perpendicular_basis_is_the_stacked_formulation_bit_for_bit(seed, k):
    from symfruit.core.points import perpendicular_basis

    rng = np.random.default_rng(seed)
    d = rng.normal(size=(k, 3))
    d[0] = [[1.0, 0.0, 0.0], [0.0, -0.0, 1.0], [0.95, 0.3, 0.0]][seed % 3]  # each branch, signed zeros
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    x, y, z = d[:, 0], d[:, 1], d[:, 2]  # the formulation before it was filled column by column
    zero = np.zeros_like(x)
    e1 = np.where((np.abs(x) < 0.9)[:, None], np.stack([zero, z, -y], axis=1), np.stack([-z, zero, x], axis=1))
    e1 /= np.sqrt((e1 * e1).sum(axis=1))[:, None]
    e2 = np.stack([y * e1[:, 2] - z * e1[:, 1], z * e1[:, 0] - x * e1[:, 2], x * e1[:, 1] - y * e1[:, 0]], axis=1)
    got1, got2 = perpendicular_basis(d)
    for got, want in ((got1, e1), (got2, e2)):
        np.testing.assert_array_equal(got, want)
        assert np.array_equal(np.signbit(got), np.signbit(want))


@given(st.integers(0, 2**32 - 1), st.sampled_from([(50, 3), (7, 11, 3), (40, 2), (5, 4)]))
def test_row_norms_are_numpys_bit_for_bit(seed, shape):
    from symfruit.core.points import row_norms

    x = np.random.default_rng(seed).normal(0.0, 10.0 ** np.random.default_rng(seed).uniform(-4, 2), shape)
    np.testing.assert_array_equal(row_norms(x), np.linalg.norm(x, axis=-1))


@given(st.integers(0, 2**32 - 1), st.sampled_from([(50, 3), (1000, 3), (40, 2), (1, 3), (0, 3), (5, 4), (4, 1)]),
       st.sampled_from([np.float64, np.float32]))  # fmt: skip
def test_squared_norms_are_numpys_bit_for_bit(seed, shape, dtype):
    from symfruit.core.points import squared_norms

    rng = np.random.default_rng(seed)
    x = (rng.normal(0.0, 10.0 ** rng.uniform(-4, 2), shape) + rng.uniform(-1, 1)).astype(dtype)
    got, want = squared_norms(x), (x**2).sum(axis=1)
    assert got.dtype == want.dtype and np.array_equal(got, want)


@given(st.integers(0, 2**32 - 1), st.sampled_from([np.float64, np.float32]))
def test_median_is_numpys_bit_for_bit(seed, dtype):
    from symfruit.core.points import median

    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 80))
    x = rng.normal(0.0, 1.0, n).round(int(rng.integers(0, 8))).astype(dtype)  # rounded: repeated values
    if rng.random() < 0.2:
        x[rng.integers(0, n)] = rng.choice([np.nan, np.inf, -np.inf])
    got, expected = median(x), np.median(x)
    assert type(got) is type(expected)
    assert got == expected or (np.isnan(got) and np.isnan(expected))


@given(st.integers(0, 2**32 - 1))
def test_median_by_the_compiled_quickselect_is_numpys_in_both_kernel_modes(seed):
    """``median`` of random values (ties, odd and even counts, now and then a NaN, strided views, float32; float64
    by the compiled quickselect where numba is, stop 54) is ``np.median``'s value and type to the bit in both kernel
    modes, the values left as they were."""
    from symfruit.core.points import median

    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 400)) if seed % 5 else int(rng.integers(1, 4))
    values = (
        rng.choice(rng.uniform(0.2, 2.0, int(rng.integers(1, 6))), 2 * n) if seed % 2 else rng.normal(1, 0.1, 2 * n)
    )
    if seed % 7 == 3:
        values[int(rng.integers(0, 2 * n))] = np.nan
    values = values[::2] if seed % 3 == 0 else values[:n]
    values = values.astype(np.float32) if seed % 11 == 5 else values
    kept, want = values.copy(), np.median(values)
    for kernels in ("numba", "numpy"):
        with pytest.MonkeyPatch.context() as mp:
            if kernels == "numpy":
                mp.setenv("SYMFRUIT_KERNELS", "numpy")
            else:
                mp.delenv("SYMFRUIT_KERNELS", raising=False)
            got = median(values)
        assert type(got) is type(want)
        assert np.isnan(got) if np.isnan(want) else np.asarray(got).tobytes() == np.asarray(want).tobytes()
        np.testing.assert_array_equal(values, kept)


SHAPE_PAIRS = [((3,), (3,)), ((3,), (9, 3)), ((9, 3), (9, 3)), ((4, 1, 3), (5, 3))]


@given(st.integers(0, 2**32 - 1), st.sampled_from(SHAPE_PAIRS))
def test_cross_rows_is_numpys_cross_bit_for_bit(seed, shapes):
    from symfruit.core.points import cross_rows

    rng = np.random.default_rng(seed)
    a, b = rng.normal(size=shapes[0]), rng.normal(size=shapes[1])
    got = cross_rows(a, b)
    np.testing.assert_array_equal(got, np.cross(a, b))
    assert got.shape == np.broadcast_shapes(a.shape, b.shape) and got.dtype == np.float64
    assert cross_rows(a.astype(np.float32), b.astype(np.float32)).dtype == np.float32


@given(st.integers(0, 2**32 - 1))
def test_perpendicular_basis_of_one_row_is_that_row_of_many(seed):
    """One float64 row goes through Python floats: the same values as the array path's, signed zeros included."""
    from symfruit.core.points import perpendicular_basis

    rng = np.random.default_rng(seed)
    d = rng.normal(size=(40, 3)) * 10.0 ** rng.uniform(-3, 3, (40, 1))
    d[:20] /= np.linalg.norm(d[:20], axis=1, keepdims=True)
    d[:4] = [[1.0, 0.0, 0.0], [0.0, -0.0, 1.0], [0.95, 0.3, 0.0], [-0.9, 0.0, -0.0]]
    e1, e2 = perpendicular_basis(d)
    for i in range(len(d)):
        o1, o2 = perpendicular_basis(d[i : i + 1])
        assert o1.shape == o2.shape == (1, 3)
        for got, want in ((o1[0], e1[i]), (o2[0], e2[i])):
            assert np.array_equal(got, want) and np.array_equal(np.signbit(got), np.signbit(want))
    with np.errstate(invalid="ignore"):  # a zero row: numpy's NaN, not a Python ZeroDivisionError
        assert np.isnan(perpendicular_basis(np.zeros((1, 3)))[0]).all()


def test_a_cloud_beyond_any_depth_cameras_reach_or_of_booleans_is_refused():
    # a fruit-sized cloud 1e6 m off was called "a streak along the line of sight"; a boolean mask read as 1 m / 0 m
    front = np.asarray(VISIBLE)
    assert check_cloud(front)[0].shape == front.shape
    for offset in ([1e6, 0, 0], [0, 0, 1e6], [0, -150, 0]):
        with pytest.raises(
            InputError,
            match=r"the points lie up to 1[0-9.e+]+ m from the camera, beyond any depth camera's reach \(100 m\)",
        ):
            check_cloud(front + offset)
    for z in (1e-9, 5e-324):  # one stray point at 5e-324 m ended 'evidence' in numpy's "data must be finite"
        with pytest.raises(InputError, match=r"1 of \d+ points are nearer the camera than 1 mm \(z as small as"):
            check_cloud(np.vstack([front, [[0.01, 0.01, z]]]))
    with pytest.raises(InputError, match=r"points must be x, y, z in metres, got a boolean array"):
        check_cloud(front > 0.01)


def test_a_masked_coordinate_is_none_and_its_row_dropped_not_the_value_under_the_mask():
    rng = np.random.default_rng(3)
    d = rng.normal(size=(600, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    front = 0.015 * d[d[:, 2] < 0] + [0.0, 0.0, 0.3]
    pts = np.vstack([front, np.tile([0.5, 0.5, 2.0], (20, 1))])  # 20 stray points, their z masked
    mask = np.zeros(pts.shape, bool)
    mask[len(front) :, 2] = True
    clean, dropped = check_cloud(np.ma.masked_array(pts, mask=mask))
    assert dropped == 20 and len(clean) == len(front)  # before: the strays read, 'the cloud is 1.71 m across'
    assert np.isnan(as_points(np.ma.masked_array(pts, mask=mask))[-1, 2])


@pytest.mark.parametrize("dtype", ["datetime64[s]", "timedelta64[ms]"])
def test_times_are_refused_as_points(dtype):
    with pytest.raises(InputError, match=f"points must be x, y, z in metres, got {re.escape(dtype)} times"):
        as_points(np.ones((20, 3)).astype(dtype))  # before: read as counts of seconds, 'behind the camera'


def test_as_points_hands_back_an_array_that_is_already_points():
    """A C-ordered float64 (n, 3) array is returned as it is (what the checks made of it before: the same array);
    too few rows are still refused, and a view, another dtype or a masked array still go through the checks."""
    p = np.random.default_rng(0).normal(size=(5, 3))
    assert as_points(p) is p
    with pytest.raises(InputError, match="at least 6"):
        as_points(p, min_count=6)
    assert as_points(p[::2]).flags.c_contiguous and np.array_equal(as_points(p[::2]), p[::2])
    assert as_points(p.astype(np.float32)).dtype == np.float64
    masked = np.ma.masked_array(p, mask=np.eye(5, 3, dtype=bool))
    assert np.isnan(as_points(masked)[0, 0]) and type(as_points(masked)) is np.ndarray


@pytest.mark.parametrize(
    "points",
    [
        [["0.01", "0.0", "0.3"]] * 20,
        np.array([["0.01", "0.0", "0.3"]] * 20),
        np.array([[b"0.01", b"0.0", b"0.3"]] * 20),
        np.array([[0.01, "0.0", 0.3]] * 20, dtype=object),
        "0.01 0.0 0.3",
    ],
    ids=["list of text", "str array", "bytes array", "object array with text", "one string"],
)
def test_text_is_refused_not_parsed_as_numbers(points):
    with pytest.raises(InputError, match=r"^points must be a numeric \(n, 3\) array of x, y, z in metres, got text"):
        as_points(points)  # before: numpy parsed '0.3' as 0.3 (the one string: 'must be a numeric (n, 3) array')
    assert as_points(np.array([[0.01, 0.0, 0.3]], dtype=object)).dtype == np.float64  # numbers in objects: fine


def test_subsample_draws_as_a_new_generator_does():
    """The kept generator set back to its seed's state draws what ``np.random.default_rng(seed)`` draws, call after
    call, whatever was drawn between (other sizes, other seeds), in another thread too."""
    import threading

    rng = np.random.default_rng(7)
    points = rng.normal(size=(5000, 3))
    for _trial in range(30):
        size, n, seed = int(rng.integers(10, 5000)), int(rng.integers(1, 3000)), int(rng.integers(0, 3))
        cloud = points[:size]
        want = cloud if size <= n else cloud[np.sort(np.random.default_rng(seed).choice(size, size=n, replace=False))]
        np.testing.assert_array_equal(subsample(cloud, n, seed=seed), want)
    found = []
    thread = threading.Thread(target=lambda: found.append(subsample(points, 100, seed=1)))
    thread.start()
    thread.join(600)
    np.testing.assert_array_equal(
        found[0], points[np.sort(np.random.default_rng(1).choice(5000, size=100, replace=False))]
    )


@pytest.mark.parametrize("size", [10, 3000, 10_000, 10_001, 20_000, 20_049, 50_000])
def test_subsample_is_a_shuffled_choices_rows_about_the_cut_offs(size):
    """Without the drawn values' shuffle where numpy's choice takes the same branch either way, the same rows as the
    shuffled choice sorted: sizes at, below and above a fiftieth and a twentieth of populations about 10,000 (between
    those cut-offs the branch is the shuffle's: it fails when the shuffle is left out there too)."""
    idx = np.arange(size, dtype=np.float64)
    counts = {1, 2, size // 50, size // 50 + 1, size // 20, size // 20 + 1, size // 3, size - 1}
    for n in sorted(c for c in counts if 1 <= c < size):
        for seed in (0, 5):
            want = np.sort(np.random.default_rng(seed).choice(size, size=n, replace=False))
            np.testing.assert_array_equal(subsample(idx, n, seed=seed), want.astype(np.float64))


def test_subsample_takes_the_indexed_rows():
    """The rows ``take`` copies are the indexed rows, byte for byte: of a strided view, of float32 points, of a
    column-ordered array; a 1-D array's elements likewise."""
    rng = np.random.default_rng(3)
    base = rng.normal(size=(4000, 6))
    keep = np.sort(np.random.default_rng(0).choice(2000, size=300, replace=False))
    for cloud in (base[::2, 1:4], base[:2000, :3].astype(np.float32), np.asfortranarray(base[:2000, 3:])):
        got = subsample(cloud, 300)
        assert got.dtype == cloud.dtype and got.tobytes() == cloud[keep].tobytes()
    got = subsample(np.arange(20.0), 5)
    assert np.array_equal(got, np.arange(20.0)[np.sort(np.random.default_rng(0).choice(20, size=5, replace=False))])


def _former_check(points: np.ndarray) -> str:
    """check_cloud's spread tests as they were before stop 62: LAPACK's eigenvalues always (the message, or "")."""
    centred = points - points.mean(axis=0)
    s0, s1, s2 = np.linalg.eigvalsh(centred.T @ centred).tolist()
    if s2 <= 1e-18 * len(points):
        return "identical"
    if s1 <= 1e-12 * s2:
        return "on a line"
    if s0 <= 1e-12 * s2:
        return "on a plane"
    return ""


@given(st.integers(0, 2**32 - 1), st.floats(-16.0, 0.0), st.floats(-16.0, 0.0), st.integers(10, 400))
def test_check_cloud_spread_decided_without_lapack_is_the_former_rule(seed, flat, thin, n):
    """Stop 62: the spread tests are decided without LAPACK where ``lapack.surely_positive3`` says every variance is
    far above them; clouds flattened or thinned to any degree (planes, lines, their neighbours) raise or pass as
    with LAPACK's eigenvalues always."""
    rng = np.random.default_rng(seed)
    axes, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    local = rng.normal(size=(n, 3)) * [0.02, 0.02 * 10.0**thin, 0.02 * 10.0**flat]
    points = local @ axes.T + [0.0, 0.0, 0.5]
    want = _former_check(points)
    if want:
        with pytest.raises(InputError, match=want):
            check_cloud(points, min_extent=0.0)
    else:
        check_cloud(points, min_extent=0.0)
