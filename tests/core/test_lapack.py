"""numpy.linalg's LAPACK calls without their wrappers (core.lapack): the same values to the bit, the same errors."""

import math

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


# --- stop 64, comp64: a 2x2 eigh by dsyevd's closed form -------------------------------------------------------------

_ULP = 2.0**-53


def _plain(draw: st.DrawFn) -> float:
    """A float of either sign within 1e-90 .. 1e90 in size, or a zero of either sign."""
    if draw(st.integers(0, 9)) == 0:
        return draw(st.sampled_from([0.0, -0.0]))
    return draw(st.sampled_from([1.0, -1.0])) * draw(st.floats(1.0, 10.0)) * 10.0 ** draw(st.integers(-90, 89))


@st.composite
def _matrix2(draw: st.DrawFn) -> tuple[float, float, float]:
    """``(a00, a10, a11)``: independent values, equal or opposite diagonals, small matrices of halves (ties, zeros,
    equal magnitudes), or an off-diagonal near one of dsteqr's split thresholds (``sqrt|a00| sqrt|a11| eps``, then
    ``e^2`` against ``eps^2 |a00| |a11|``)."""
    a, b, c = _plain(draw), _plain(draw), _plain(draw)
    kind = draw(st.integers(0, 5))
    if kind == 1:
        c = a
    elif kind == 2:
        c = -a
    elif kind == 3:
        a, b, c = (0.5 * draw(st.integers(-4, 4)) for _ in range(3))
    elif kind in (4, 5):  # around either threshold, of either sign
        near = (math.sqrt(abs(a)) * math.sqrt(abs(c))) * _ULP * draw(st.floats(0.25, 4.0 if kind == 4 else 1e4))
        b = draw(st.sampled_from([1.0, -1.0])) * near if near > 0.0 else b
    return a, b, c


@settings(max_examples=3000, deadline=None)
@given(_matrix2(), st.floats(-1e3, 1e3))
def test_eigh2_is_numpys_eigh_to_the_bit(abc, upper):
    """:func:`lapack._eigh2` (and :func:`lapack.eigh` of a 2x2 matrix) against ``np.linalg.eigh``: the same values and
    vectors to the bit, zeros' signs included; the upper triangle is not read; None only beyond the plain range."""
    a, b, c = abc
    m = np.array([[a, upper], [b, c]])
    want = np.linalg.eigh(m)
    got = lapack._eigh2(m)
    if got is None:  # only beyond the plain range (a threshold's off-diagonal may fall below it)
        assert not all(v == 0.0 or 1e-100 < abs(v) < 1e100 for v in abc)
    else:
        assert _same(got[0], want[0]) and _same(got[1], want[1])
        assert got[1].flags.c_contiguous and got[1].flags.writeable
    assert all(_same(x, y) for x, y in zip(lapack.eigh(m), want, strict=True))


def test_eigh2_known_answers():
    """Cases a closed form gets wrong by a bit: ``x**2`` by Python's ``pow`` (this one rounds otherwise than the
    product), the QL and QR sweeps' split tests (the same matrix both ways round), a diagonal matrix to sort, zeros;
    and None (LAPACK asked) beyond the plain range or for a value not finite."""
    cases = [
        (0.00014355103579567248, -3.990929287166969e-05, 0.00022483332461465728),
        (0.6031856242596422, -0.7863271781416633, -1.4506275457587698),
        (-1.093187234851072, -1.3329088387526653, -0.5119743923779423),
        (3.0, 0.0, 1.0), (1.0, -0.0, 1.0), (0.0, 0.0, 0.0), (-0.0, 0.0, -0.0), (2.0, 1.0, 2.0), (1.0, 1.0, -1.0),
    ]  # fmt: skip
    for a, c in ((1.0, 4.0), (4.0, 1.0), (1e-3, 7e5), (-2.0, 3.0)):
        edge = math.sqrt(abs(a)) * math.sqrt(abs(c)) * _ULP
        for k in (0.5, 1.0, 1.0 + 2**-50, 2.0, 1e3):
            cases += [(a, k * edge, c), (c, -k * edge, a)]
    for a, b, c in cases:
        m = np.array([[a, 0.0], [b, c]])
        want, got = np.linalg.eigh(m), lapack._eigh2(m)
        assert got is not None and _same(got[0], want[0]) and _same(got[1], want[1]), (a, b, c)
    for bad in (1e-120, 1e120, np.nan, np.inf):
        m = np.array([[1.0, 0.0], [bad, 2.0]])
        assert lapack._eigh2(m) is None
        assert all(_same(x, y) for x, y in zip(lapack.eigh(m), np.linalg.eigh(m), strict=True))
    assert lapack.eigh(np.eye(2))[0].tolist() == [1.0, 1.0]
