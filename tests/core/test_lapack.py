"""numpy.linalg's LAPACK calls without their wrappers (core.lapack): the same values to the bit, the same errors."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from symfruit.core import lapack


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal to the bit (NaN where the other is NaN), shape and dtype alike."""
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


def _matrix(seed: int, n: int, symmetric: bool = False) -> np.ndarray:
    a = np.random.default_rng(seed).normal(size=(n, n)) * 10.0 ** np.random.default_rng(seed + 1).integers(-6, 6)
    return a + a.T if symmetric else a


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 10_000), st.integers(1, 7))
def test_every_call_repeats_numpys_to_the_bit(seed, n):
    a, s = _matrix(seed, n), _matrix(seed + 7, n, symmetric=True)
    rhs = np.random.default_rng(seed + 3).normal(size=(n, 2))
    assert _same(lapack.solve(a, rhs), np.linalg.solve(a, rhs))
    assert _same(lapack.solve(a, rhs[:, 0]), np.linalg.solve(a, rhs[:, 0]))
    assert _same(lapack.solve(a[::-1].T, rhs.T[0]), np.linalg.solve(a[::-1].T, rhs.T[0]))  # strided views
    assert _same(lapack.inv(a), np.linalg.inv(a))
    values, vectors = np.linalg.eig(a)
    got = lapack.eig_real(a)
    assert _same(got[0], values.real) and _same(got[1], vectors.real)
    assert all(_same(x, y) for x, y in zip(lapack.eigh(s), np.linalg.eigh(s), strict=True))
    assert _same(lapack.eigvalsh(s), np.linalg.eigvalsh(s))
    assert _same(lapack.eigvalsh(s + np.triu(a, 1)), np.linalg.eigvalsh(s + np.triu(a, 1)))  # the lower triangle
    design = np.random.default_rng(seed + 5).normal(size=(n + 5, n))
    x, _, rank, sv = np.linalg.lstsq(design, rhs[:1].repeat(n + 5, 0)[:, 0] + seed, rcond=None)
    got_x, got_rank, got_sv = lapack.lstsq(design, rhs[:1].repeat(n + 5, 0)[:, 0] + seed)
    assert _same(got_x, x) and got_rank == rank and _same(got_sv, sv)


def test_known_answers():
    a = np.array([[2.0, 1.0], [1.0, 3.0]])
    assert lapack.solve(a, np.array([3.0, 5.0])).tolist() == pytest.approx([0.8, 1.4])
    assert (lapack.inv(np.diag([2.0, 4.0, 8.0])) == np.diag([0.5, 0.25, 0.125])).all()
    assert lapack.eigvalsh(np.diag([3.0, 1.0, 2.0])).tolist() == [1.0, 2.0, 3.0]
    values, vectors = lapack.eig_real(np.array([[0.0, -1.0], [1.0, 0.0]]))  # a rotation: +-i, real parts 0
    assert values.dtype == np.float64 and values.tolist() == [0.0, 0.0] and vectors.dtype == np.float64
    x, rank, sv = lapack.lstsq(np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]), np.array([1.0, 2.0, 3.0]))
    assert x.tolist() == pytest.approx([1.0, 2.0]) and rank == 2 and len(sv) == 2
    _, rank, sv = lapack.lstsq(np.ones((4, 2)), np.arange(4.0))  # rank deficient: no error, rank 1
    assert rank == 1 and sv[1] < 1e-12


def test_the_same_errors():
    singular = np.ones((3, 3))
    for call in (lambda: lapack.solve(singular, np.ones(3)), lambda: lapack.inv(singular)):
        with pytest.raises(np.linalg.LinAlgError, match="Singular matrix"):
            call()
    bad = np.eye(3)
    bad[1, 2] = np.nan
    with pytest.raises(np.linalg.LinAlgError, match="infs or NaNs"):
        lapack.eig_real(bad)
    bad[1, 2] = np.inf
    with pytest.raises(np.linalg.LinAlgError, match="infs or NaNs"):
        lapack.eig_real(bad)
    huge = np.full((2, 2), 1e308)  # finite entries: no error, numpy's values (an eigenvalue beyond float64)
    assert _same(lapack.eig_real(huge)[0], np.linalg.eig(huge)[0].real)
    # the settings are restored after an error: numpy's own again
    before = np.geterr()
    with pytest.raises(np.linalg.LinAlgError):
        lapack.inv(singular)
    assert np.geterr() == before


def test_other_arguments_go_to_numpy():
    a32 = np.eye(3, dtype=np.float32) * 2
    assert _same(lapack.inv(a32), np.linalg.inv(a32))  # float32 stays float32, as numpy keeps it
    stack = np.stack([np.eye(3) * k for k in (1.0, 2.0)])
    assert _same(lapack.eigvalsh(stack), np.linalg.eigvalsh(stack))
    assert _same(lapack.solve(np.eye(2).tolist(), [1.0, 2.0]), np.linalg.solve(np.eye(2), [1.0, 2.0]))
    with pytest.raises(np.linalg.LinAlgError):
        lapack.inv(np.ones((2, 3)))


# --- stop 62, comp62: a 3x3 symmetric matrix's eigenvalues surely above 0, without LAPACK ---------------------------


def _symmetric3(seed: int, kind: str) -> np.ndarray:
    """A symmetric 3x3 matrix: positive definite of any condition up to 1e14, indefinite, singular, or a fruit's
    scatter, at a scale from 1e-30 to 1e30, rotated at random."""
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    if kind == "definite":
        values = 10.0 ** rng.uniform(-14.0, 0.0, 3)
    elif kind == "indefinite":
        values = rng.normal(size=3)
    elif kind == "singular":
        values = np.array([0.0, *rng.uniform(0.1, 1.0, 2)])
    else:  # a cloud's scatter (points on a cap, some flat)
        pts = rng.normal(size=(int(rng.integers(10, 400)), 3)) * [1.0, 1.0, 10.0 ** rng.uniform(-8.0, 0.0)]
        centred = pts - pts.mean(axis=0)
        return (centred.T @ centred) * 10.0 ** rng.uniform(-30.0, 30.0)
    return (q * values) @ q.T * 10.0 ** rng.uniform(-30.0, 30.0)


@settings(max_examples=400, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(["definite", "indefinite", "singular", "scatter"]))
def test_surely_positive_matrices_have_eigvalshs_least_above_the_bound(seed, kind):
    """Where :func:`lapack.surely_positive3` says so, every eigenvalue ``eigvalsh`` gives is above ``3e-7`` times the
    entries' summed magnitudes ``F`` (so above 0 and above ``1e-12`` times the greatest, ``check_cloud``'s and
    ``fit_ellipsoid``'s tests), and ``F`` is above the floor; an asymmetric upper triangle is not read."""
    a = _symmetric3(seed, kind)
    a = np.tril(a) + np.triu(np.random.default_rng(seed + 1).normal(size=(3, 3)) * np.abs(a).max(), 1)  # not read
    low = np.tril(a)
    f = float(np.abs(low + np.tril(low, -1).T).sum())
    values = np.linalg.eigvalsh(a)
    if lapack.surely_positive3(a):
        assert values[0] > 3e-7 * f and values[0] > 1e-12 * values[2] and (values > 0).all()
    floor = f * 10.0 ** np.random.default_rng(seed + 2).uniform(-2.0, 2.0)
    if lapack.surely_positive3(a, floor=floor):
        assert f > floor


def test_surely_positive_known_answers():
    """True on well-conditioned positive definite matrices (so the tests above can fail), False on indefinite,
    singular, nearly singular (condition 1e9), non-finite or wrongly shaped ones and below the floor."""
    rng = np.random.default_rng(5)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    for values in ([1.0, 2.0, 3.0], [0.04, 0.5, 1.0], [1e-3, 1.0, 1.0]):
        assert lapack.surely_positive3((q * values) @ q.T * 1e-4)
    assert lapack.surely_positive3(np.diag([1.0, 2.0, 3.0]), floor=5.9)
    assert not lapack.surely_positive3(np.diag([1.0, 2.0, 3.0]), floor=6.0)
    for values in ([-1e-3, 1.0, 1.0], [0.0, 1.0, 1.0], [1e-9, 1.0, 1.0], [-1.0, -1.0, 3.0]):
        assert not lapack.surely_positive3((q * values) @ q.T)
    assert not lapack.surely_positive3(np.array([[1.0, 10.0, 0.0], [10.0, 1.0, 0.0], [0.0, 0.0, 1.0]]))
    assert not lapack.surely_positive3(np.diag([1.0, np.nan, 1.0]))
    assert not lapack.surely_positive3(np.diag([1.0, np.inf, 1.0]))
    assert not lapack.surely_positive3(np.eye(2))
    assert not lapack.surely_positive3(np.eye(3, dtype=np.float32))
    assert not lapack.surely_positive3(np.eye(3) * 1e-95)
