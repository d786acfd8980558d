"""numpy.linalg's LAPACK calls on small float64 matrices without their wrappers' Python (issue 19, stop 44).

``np.linalg.solve``, ``inv``, ``eig``, ``eigh``, ``eigvalsh`` and ``lstsq`` each check and convert their arguments
in Python (``_makearray``, ``_assert_stacked_square``, ``_commonType``, ``astype``, the result's wrapping) and then
call one generalised ufunc of ``numpy.linalg._umath_linalg`` (LAPACK) inside an ``np.errstate`` that turns its
failure into :class:`numpy.linalg.LinAlgError`. On the 3x3-6x6 matrices of a fruit's completion the checks cost
about as much as LAPACK: 4.3 against 1.1 us for a 3x3 ``solve``, 13.1 against 3.7 for ``eig`` (numpy 2.4,
``time.thread_time`` over 20,000 calls). The functions here call the same generalised ufunc with the same
signature inside the same ``errstate`` for float64 arrays of the expected shapes, and ``np.linalg`` itself for
anything else (another dtype, a stack of matrices, numpy before 2.0, whose ufuncs take other arguments): the same
LAPACK routine on the same values, so the same results to the bit and the same errors. The ``errstate`` is entered
as numpy 2's does it (its context variable set to error settings made once: ``np.errstate`` itself costs as much as
LAPACK's 3x3 ``solve``), or through ``np.errstate`` where this numpy has no such variable.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any, NoReturn

import numpy as np
from numpy.lib import NumpyVersion
from numpy.linalg import LinAlgError

__all__ = ["eig_real", "eigh", "eigvalsh", "inv", "lstsq", "solve", "surely_positive3"]


def _module(name: str) -> Any:
    """The module ``name`` of numpy's internals, or None where this numpy has none such."""
    try:
        return importlib.import_module(name)
    except ImportError:  # pragma: no cover - another numpy's layout
        return None


_ufuncs = _module("numpy.linalg._umath_linalg")

#: The generalised ufuncs called here, where this numpy has them with numpy 2's arguments (None: ``np.linalg``).
_LAPACK: Any = (
    _ufuncs
    if _ufuncs is not None
    and NumpyVersion(np.__version__) >= "2.0.0"
    and all(hasattr(_ufuncs, name) for name in ("solve", "solve1", "inv", "eig", "eigh_lo", "eigvalsh_lo", "lstsq"))
    else None
)


#: float64's machine epsilon, numpy's ``finfo(float64).eps``.
_EPS = float(np.finfo(np.float64).eps)


def _singular(err: str, flag: int) -> NoReturn:
    raise LinAlgError("Singular matrix")


def _unconverged(err: str, flag: int) -> NoReturn:
    raise LinAlgError("Eigenvalues did not converge")


def _lstsq_failed(err: str, flag: int) -> NoReturn:
    raise LinAlgError("SVD did not converge in Linear Least Squares")


#: numpy 2's context variable of the ufuncs' error settings and its maker (None: through ``np.errstate``).
_VAR: Any = None
_MADE: dict[Callable[[str, int], NoReturn], Any] = {}
try:
    _config = _module("numpy._core._ufunc_config")
    _VAR = _config._extobj_contextvar
    for _raise in (_singular, _unconverged, _lstsq_failed):  # every setting but the buffer size (not read here)
        _MADE[_raise] = _config._make_extobj(
            call=_raise, invalid="call", over="ignore", divide="ignore", under="ignore"
        )
except (AttributeError, TypeError):  # pragma: no cover - another numpy's internals
    _VAR = None


def _call(errors: Callable[[str, int], NoReturn], ufunc: Any, signature: str, *args: Any) -> Any:
    """``ufunc(*args, signature=signature)`` inside ``np.errstate(call=errors, invalid="call", over="ignore",
    divide="ignore", under="ignore")`` (numpy.linalg's around each of its LAPACK ufuncs), entered as numpy 2's
    ``errstate`` does: its context variable set to the settings made once, and reset after."""
    if _VAR is None:
        with np.errstate(call=errors, invalid="call", over="ignore", divide="ignore", under="ignore"):
            return ufunc(*args, signature=signature)
    token = _VAR.set(_MADE[errors])
    try:
        return ufunc(*args, signature=signature)
    finally:
        _VAR.reset(token)


def _square(a: Any) -> bool:
    """Whether ``a`` is one float64 square matrix (the fast path's arguments)."""
    return type(a) is np.ndarray and a.dtype == np.float64 and a.ndim == 2 and a.shape[0] == a.shape[1]


def solve(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.linalg.solve(a, b)``: the same values and errors."""
    if _LAPACK is None or not _square(a) or type(b) is not np.ndarray or b.dtype != np.float64 or b.ndim > 2:
        return np.linalg.solve(a, b)
    ufunc = _LAPACK.solve1 if b.ndim == 1 else _LAPACK.solve
    return _call(_singular, ufunc, "dd->d", a, b)


def inv(a: np.ndarray) -> np.ndarray:
    """``np.linalg.inv(a)``: the same values and errors."""
    if _LAPACK is None or not _square(a):
        return np.linalg.inv(a)
    return _call(_singular, _LAPACK.inv, "d->d", a)


def eig_real(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(values.real, vectors.real)`` of ``np.linalg.eig(a)`` (its real parts, whether it returns complex values or,
    every imaginary part being 0, real ones): the same values and errors (a matrix not finite raises, as there)."""
    if _LAPACK is None or not _square(a):
        values, vectors = np.linalg.eig(a)
        return values.real, vectors.real
    if not np.isfinite(a).all():  # numpy's _assert_finite
        raise LinAlgError("Array must not contain infs or NaNs")
    values, vectors = _call(_unconverged, _LAPACK.eig, "d->DD", a)
    return values.real, vectors.real


def eigh(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``np.linalg.eigh(a)`` (the lower triangle): ``(values, vectors)``, the same values and errors."""
    if _LAPACK is None or not _square(a):
        values, vectors = np.linalg.eigh(a)
        return values, vectors
    values, vectors = _call(_unconverged, _LAPACK.eigh_lo, "d->dd", a)
    return values, vectors


def eigvalsh(a: np.ndarray) -> np.ndarray:
    """``np.linalg.eigvalsh(a)`` (the lower triangle): the same values and errors."""
    if _LAPACK is None or not _square(a):
        return np.linalg.eigvalsh(a)
    return _call(_unconverged, _LAPACK.eigvalsh_lo, "d->d", a)


def lstsq(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, int, np.ndarray]:
    """``(x, rank, singular values)`` of ``np.linalg.lstsq(a, b, rcond=None)`` for ``a`` (m, n) and ``b`` (m,):
    the same values and errors (its residuals are not returned)."""
    if (
        _LAPACK is None
        or type(a) is not np.ndarray
        or type(b) is not np.ndarray
        or a.dtype != np.float64
        or b.dtype != np.float64
        or a.ndim != 2
        or b.ndim != 1
        or len(b) != len(a)
        or min(a.shape) == 0
    ):
        x, _, rank, sv = np.linalg.lstsq(a, b, rcond=None)
        return x, int(rank), sv
    rcond = _EPS * max(a.shape)  # numpy's default rcond
    x, _, rank, sv = _call(_lstsq_failed, _LAPACK.lstsq, "ddd->ddid", a, b[:, None], rcond)
    return x[:, 0], int(rank), sv


#: :func:`surely_positive3`'s margin: the least of ``tr``, ``e2`` and ``det`` over ``F``, ``F^2`` and ``F^3``.
_MARGIN = 1e-6


def surely_positive3(a: np.ndarray, floor: float = 0.0) -> bool:
    """Whether every eigenvalue :func:`eigvalsh` gives of the 3x3 float64 ``a`` (its lower triangle, as it reads) is
    surely above ``3e-7 F``, ``F`` the sum of the magnitudes of that symmetric matrix's nine entries, decided in Python
    floats without LAPACK (issue 19, stop 62, comp62), and ``F`` above ``floor``; False where it is not sure (then ask
    :func:`eigvalsh`).

    True where the matrix's trace, the sum of its 2x2 principal minors ``e2`` and its determinant, worked out here,
    reach ``1e-6`` times ``F``, ``F^2`` and ``F^3`` (and ``F`` lies within 1e-90 .. 1e90). Why that suffices: every
    eigenvalue is at most ``F`` in size (a row sum), so the rounding of those three sums (a few products of entries,
    each at most ``F^k``) is below ``1e-14 F^k``: the exact ones are positive too, so the characteristic polynomial
    ``x^3 - tr x^2 + e2 x - det`` is negative at every ``x <= 0`` and every eigenvalue is positive; then the least
    is ``det / (l1 l2) >= det / e2 >= (1e-6 - 1e-14) F^3 / (3 F^2) > 3.3e-7 F``. LAPACK's symmetric eigenvalues are
    within a small multiple of ``eps ||a||`` (about 1e-14 F) of the exact ones, so each it gives is above ``3e-7 F``
    and at most ``F (1 + 1e-14)``: a test of the least against 0, or of the least over the greatest against anything
    below ``3e-7``, comes out as it would on :func:`eigvalsh`'s values."""
    if type(a) is not np.ndarray or a.shape != (3, 3) or a.dtype != np.float64:
        return False
    (d0, _, _), (b10, d1, _), (b20, b21, d2) = a.tolist()
    f = abs(d0) + abs(d1) + abs(d2) + 2.0 * (abs(b10) + abs(b20) + abs(b21))
    if not (1e-90 < f < 1e90 and f > floor):  # (NaN too)
        return False
    m12 = d1 * d2 - b21 * b21
    e2 = d0 * d1 - b10 * b10 + d0 * d2 - b20 * b20 + m12
    det = d0 * m12 - b10 * (b10 * d2 - b21 * b20) + b20 * (b10 * b21 - d1 * b20)
    return d0 + d1 + d2 >= _MARGIN * f and e2 >= _MARGIN * f * f and det >= _MARGIN * f * f * f
