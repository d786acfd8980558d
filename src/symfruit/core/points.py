"""Point arrays at the boundary: normalise what a caller hands in, and check that it can be a fruit.

Every exported core function starts with :func:`as_points`, so a list, a tuple or an integer array works
and anything else fails with an :class:`~symfruit.errors.InputError` that says what was expected, not with
an error from deep inside numpy.
"""

from __future__ import annotations

import math
import threading
from typing import Any

import numpy as np

from ..errors import InputError
from . import lapack
from .kernels import compiled
from .limits import MAX_DEPTH_METRES, MIN_DEPTH_METRES, unmasked

__all__ = [
    "as_points",
    "bounds",
    "check_cloud",
    "check_view",
    "column_means",
    "cross_rows",
    "mean_point",
    "median",
    "perpendicular_basis",
    "row_norms",
    "squared_norms",
    "subsample",
]


def bounds(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(min (k,), max (k,))`` of the columns of ``points`` (n, k), exactly ``points.min(axis=0)`` and
    ``points.max(axis=0)``, column by column: numpy reduces a C-ordered ``(n, 3)`` array along its first
    axis some 20 times slower than three contiguous-stride column reductions."""
    p = np.asarray(points)
    if p.ndim == 2 and len(p) and p.dtype == np.float64 and p.flags.c_contiguous and (jit := compiled()) is not None:
        # one compiled pass over the rows (issue 19, nineteenth round: 12 against 60 us on 14,000 points); numpy's
        # where a bound is zero (its sign is numpy's to pick)
        lo, hi, sure = jit.column_bounds(p)
        if sure:
            return lo, hi
    return (np.array([p[:, i].min() for i in range(p.shape[1])]),
            np.array([p[:, i].max() for i in range(p.shape[1])]))  # fmt: skip


def row_norms(x: np.ndarray) -> np.ndarray:
    """``np.linalg.norm(x, axis=-1)`` of vectors of 2 or 3 components, term by term: numpy sums so short an axis
    left to right, so the values are the same, in a fifth of the time of its short-axis reduction."""
    x = np.asarray(x)
    if x.shape[-1] not in (2, 3) or x.dtype.kind != "f":
        return np.linalg.norm(x, axis=-1)
    total = x[..., 0] * x[..., 0] + x[..., 1] * x[..., 1]
    if x.shape[-1] == 3:
        total += x[..., 2] * x[..., 2]
    return np.sqrt(total)


def cross_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.cross(a, b)`` of 3-vectors along the last axis (broadcast), term by term into one array: the same
    products and differences, so the same values, without np.cross's overhead (some 20 us a call, several times
    the arithmetic on the few vectors the fits and rays cross)."""
    a, b = np.asarray(a), np.asarray(b)
    out = np.empty(np.broadcast_shapes(a.shape, b.shape), dtype=np.result_type(a, b, 0.0))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def median(values: np.ndarray) -> Any:
    """``np.median(values)`` of a 1-d float array, the same value bit for bit: one partition at the two middle
    places (and the last, where a NaN would sort) and the mean of the middle two in the array's own type, without
    np.median's general-axis machinery (20-40 us a call, several times the partition on a fruit's pixels); of
    float64 values where numba is, by :func:`symfruit.core._jit.median_quick` (the same order statistics, the values
    left as they are; 0.15 to 0.05 ms for a 1920x1080 tree frame's 17,000 grid depths, and less call overhead on a
    few hundred: stop 54, moved here from the colour segmenter's own wrapper). NaN when a value is NaN or there is
    none (np.median's warning where there is none)."""
    x = np.asarray(values)
    n = len(x)
    if n == 0 or x.ndim != 1 or x.dtype.kind != "f":
        return np.median(x)
    if x.dtype == np.float64 and (jit := compiled()) is not None:
        return np.float64(jit.median_quick(np.ascontiguousarray(x)))
    h = n // 2
    part = np.partition(x, (h - 1, h, n - 1) if n % 2 == 0 else (h, n - 1))
    if np.isnan(part[-1]):
        return part.dtype.type(np.nan)
    # np.mean of the two: their sum in the array's type, halved (exact); of one: itself
    return part[h] if n % 2 else (part[h - 1] + part[h]) / part.dtype.type(2)


def column_means(points: np.ndarray) -> np.ndarray:
    """(k,) float: ``points.mean(axis=0)`` of a float64 (n, k) array, the same value bit for bit: by the compiled twin
    :func:`symfruit.core._jit.column_means` where numba is installed, the array is C-ordered and ``k`` is 2 or 3
    (numpy's own reduction of such an array adds its rows in order; its call costs some 20 us on a few hundred
    points, 1 us compiled; one column it sums pairwise), else by numpy (issue 19, seventeenth round)."""
    p = np.asarray(points)
    if (p.ndim == 2 and len(p) and p.shape[1] in (2, 3) and p.dtype == np.float64 and p.flags.c_contiguous
            and (jit := compiled()) is not None):  # fmt: skip
        return jit.column_means(p)
    return p.mean(axis=0)


def squared_norms(x: np.ndarray) -> np.ndarray:
    """``(x**2).sum(axis=1)`` of rows of 2 or 3 float components, term by term (numpy sums so short an axis left to
    right: the same values, in a quarter of the time of its short-axis reduction)."""
    x = np.asarray(x)
    if x.ndim != 2 or x.shape[1] not in (2, 3) or x.dtype.kind != "f":
        return (x**2).sum(axis=1)
    total = x[:, 0] * x[:, 0]
    total += x[:, 1] * x[:, 1]
    if x.shape[1] == 3:
        total += x[:, 2] * x[:, 2]
    return total


def mean_point(points: np.ndarray) -> np.ndarray:
    """(k,) float: the mean of the rows of ``points`` (n, k), as a matrix-vector product (see :func:`bounds`)."""
    p = np.asarray(points, dtype=np.float64)
    return np.ones(len(p)) @ p / len(p)


def as_points(points: Any, *, min_count: int = 1, name: str = "points") -> np.ndarray:
    """``points`` as a C-contiguous ``(n, 3)`` float64 array with ``n >= min_count``.

    Parameters
    ----------
    points : array_like, (n, 3), metres
    min_count : int
        Fewest rows accepted.
    name : str
        What to call the argument in error messages.

    Raises
    ------
    InputError
        When ``points`` is not numeric (text is refused, even text of numbers: numpy would parse it), not real,
        not ``(n, 3)``, or has fewer than ``min_count`` rows.

    A masked coordinate of a :class:`numpy.ma.MaskedArray` is NaN (no measurement: :func:`check_cloud` drops its
    row and counts it), never the value the mask hides.

    Examples
    --------
    >>> as_points([[0, 0, 1]]).dtype
    dtype('float64')
    """
    if (type(points) is np.ndarray and points.dtype == np.float64 and points.ndim == 2 and points.shape[1] == 3
            and points.flags.c_contiguous and len(points) >= min_count):  # fmt: skip
        return points  # already what the steps below make of it (the same array): a fruit's completion asks ~12 times
    if isinstance(points, np.ndarray) and np.iscomplexobj(points):
        raise InputError(f"{name} must be real numbers, got a complex array")
    if isinstance(points, np.ndarray) and points.dtype.kind == "b":  # True/False would read as 1 m / 0 m
        raise InputError(f"{name} must be x, y, z in metres, got a boolean array (a mask?)")
    if isinstance(points, np.ndarray) and points.dtype.kind in "mM":  # numpy reads them as counts of time units
        raise InputError(f"{name} must be x, y, z in metres, got {points.dtype} times")
    if isinstance(points, np.ma.MaskedArray) and points.dtype.kind in "iuf":
        points = unmasked(points, np.nan)  # a masked coordinate is none: its row dropped as non-finite
    points = _refuse_text(points, name)  # numpy parses '0.3' (and b'0.3') as a number: the API takes numbers only
    try:
        arr = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a numeric (n, 3) array of x, y, z in metres") from None
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise InputError(f"{name} must have shape (n, 3), got {arr.shape}")
    if len(arr) < min_count:
        raise InputError(f"{name} must hold at least {min_count} points, got {len(arr)}")
    return np.ascontiguousarray(arr)


def _refuse_text(points: Any, name: str) -> Any:
    """``points`` (as an array where it was nested sequences, so they are converted once), refused where it holds
    a ``str`` or ``bytes`` anywhere."""
    if not isinstance(points, (str, bytes, np.ndarray)):
        try:
            points = np.asarray(points)
        except (TypeError, ValueError):  # ragged or worse: the conversion that follows names it
            return points
    if (
        isinstance(points, (str, bytes))
        or points.dtype.kind in "SU"
        or (points.dtype.kind == "O" and any(isinstance(v, (str, bytes)) for v in points.ravel()))
    ):  # an object array: numbers and text mixed
        raise InputError(f"{name} must be a numeric (n, 3) array of x, y, z in metres, got text (parse it first)")
    return points


def check_cloud(
    points: Any,
    *,
    min_points: int = 10,
    max_points: int = 20000,
    min_extent: float = 0.003,
    max_extent: float = 1.0,
    section: str = "",
) -> tuple[np.ndarray, int]:
    """Validate one fruit's visible points and return ``(clean (n, 3) float64 points, n_dropped)``.

    Non-finite rows are dropped (and counted); clouds over ``max_points`` are down-sampled with a
    fixed seed. Raises :class:`InputError` for anything a fruit cannot be: wrong shape, too few
    points, points at or behind the camera, nearer than :data:`MIN_DEPTH_METRES` or beyond any depth camera's
    reach (:data:`MAX_DEPTH_METRES`), all points identical or on a line or a plane, or a cloud wider than
    ``max_extent`` (most often a cloud in millimetres) or narrower than ``min_extent``.

    The bounds and the spread's scatter matrix come from one compiled pass where numba is installed
    (:func:`symfruit.core._jit.cloud_spread`: the same bounds, the scatter within rounding; 0.15 against 0.35 ms
    for a dense camera view's 14,000 points); the clean points are the same either way.

    Parameters
    ----------
    points : (n, 3) float, metres, camera optical frame
    min_points, max_points : int
    min_extent, max_extent : float, metres
    section : str
        The settings section the limits come from (e.g. ``"input"``), named in the messages.
    """
    arr = as_points(points, min_count=0)
    n_dropped = 0
    scatter = None
    jit = compiled() if len(arr) >= max(min_points, 1) else None
    if jit is not None:
        # the bounds and the spread first: a scatter matrix whose diagonal is finite is one of finite points alone (a
        # NaN or an infinity makes its column's sum of squares NaN), so the finiteness pass is not needed then (issue
        # 19, stop 40: np.isfinite over a dense view's 42,000 values and its reduction, some 25 us)
        lo, hi, scatter = jit.cloud_spread(arr)
        if not (math.isfinite(scatter[0, 0]) and math.isfinite(scatter[1, 1]) and math.isfinite(scatter[2, 2])):
            scatter = None
    if scatter is None and not np.isfinite(arr).all():
        finite = np.isfinite(arr).all(axis=1)
        n_dropped = int(len(arr) - finite.sum())
        arr = arr[finite]
    key = f"{section}." if section else ""
    if len(arr) < min_points:
        extra = f" after dropping {n_dropped} non-finite" if n_dropped else ""
        limit = f" ({key}min_points sets the limit)" if section else ""
        raise InputError(f"a fruit needs at least {min_points} points, got {len(arr)}{extra}{limit}")
    if scatter is None:  # (else made above, of these points)
        if len(arr) and (jit := compiled()) is not None:  # the bounds and the spread in one compiled pass
            lo, hi, scatter = jit.cloud_spread(arr)
        else:
            lo, hi = bounds(arr)
    # the tests below in Python floats (issue 19, stop 53): the same comparisons, differences and greatest values as
    # numpy's on the (3,) bounds (finite: the rows that are not were dropped above)
    lo_, hi_ = lo.tolist(), hi.tolist()
    if lo_[2] <= 0:  # the least depth (the bounds are numpy's minima and maxima exactly)
        behind = int((arr[:, 2] <= 0).sum())
        raise InputError(
            f"{behind} of {len(arr)} points are at or behind the camera (z <= 0); points must be in "
            "the camera optical frame (x right, y down, z forward), in metres"
        )
    extent = max(b - a for a, b in zip(lo_, hi_, strict=True))
    if extent > max_extent:
        raise InputError(
            f"the cloud is {extent:.3g} m across, too large for one fruit ({key}max_extent = {max_extent} m); "
            "if it is in millimetres, use --units mm (or divide by 1000)"
        )
    reach = max(abs(x) for x in lo_ + hi_)
    if reach > MAX_DEPTH_METRES:  # a fruit-sized cloud a kilometre off: beyond any depth camera, a wrong origin
        raise InputError(
            f"the points lie up to {reach:.3g} m from the camera, beyond any depth camera's reach "
            f"({MAX_DEPTH_METRES:g} m); points must be in the camera optical frame, in metres"
        )
    if extent < min_extent:
        if extent == 0:
            raise InputError("all points are identical; a fruit needs points spread over its surface")
        raise InputError(
            f"the cloud is only {extent * 1000:.3g} mm across, too small for a fruit ({key}min_extent = "
            f"{min_extent * 1000:g} mm); check the units (--units m for metres)"
        )
    # after the extents: a cloud in metres read as millimetres (--units mm) is told its units, not its depth
    if lo_[2] < MIN_DEPTH_METRES:
        near = int((arr[:, 2] < MIN_DEPTH_METRES).sum())
        raise InputError(
            f"{near} of {len(arr)} points are nearer the camera than {MIN_DEPTH_METRES * 1000:g} mm (z as small as "
            f"{arr[:, 2].min():.3g} m), which no depth camera measures; drop them (stray or flying pixels)"
        )
    if scatter is None:
        centred = arr - mean_point(arr)
        scatter = centred.T @ centred
    if lapack.surely_positive3(scatter, floor=1e-11 * len(arr)):
        # every variance above 3e-7 times the entries' magnitudes, themselves above 1e-11 n: each test below passes on
        # eigvalsh's values, decided without LAPACK (issue 19, stop 62)
        return subsample(arr, max_points), n_dropped
    s0, s1, s2 = lapack.eigvalsh(scatter).tolist()  # ascending variances (times n)
    if s2 <= 1e-18 * len(arr):
        raise InputError("all points are identical; a fruit needs points spread over its surface")
    if s1 <= 1e-12 * s2:
        raise InputError("all points lie on a line; a fruit needs points spread over its surface")
    if s0 <= 1e-12 * s2:
        raise InputError(
            "all points lie on a plane; a fruit's visible surface is curved (is this a depth image "
            "of a flat object, or a cloud with its depth dropped?)"
        )
    return subsample(arr, max_points), n_dropped


def check_view(points: np.ndarray, camera: Any, *, min_pixels: int = 3) -> None:
    """Refuse a cloud that cannot be a fruit's visible surface in this camera's image.

    A fruit's surface seen by a camera spreads over many pixels; a cloud whose points all fall within
    fewer than ``min_pixels`` pixels across in both image directions is a streak along the line of sight
    (flying pixels, or points that are not a surface), and any completion of it is meaningless.

    Parameters
    ----------
    points : (n, 3) float, metres, ``z > 0``
    camera : Camera

    Raises
    ------
    InputError
    """
    points = as_points(points, min_count=1)
    lo, hi = bounds(points)
    if hi[2] > 0 and max(camera.fx * (hi[0] - lo[0]), camera.fy * (hi[1] - lo[1])) / hi[2] >= min_pixels:
        return  # a lower bound of the span in pixels already passes: no need to project every point
    uv_lo, uv_hi = bounds(camera.project(points))
    span = uv_hi - uv_lo
    if not np.all(np.isfinite(span)) or span.max() < min_pixels:
        raise InputError(
            f"the visible points fall within {span.max():.1f} pixels of the image (fewer than {min_pixels} across): "
            "a streak along the line of sight, not a fruit's surface"
        )


def subsample(points: np.ndarray, n: int | None, *, seed: int = 0) -> np.ndarray:
    """At most ``n`` rows of ``points``: a fixed random subset (seeded, so the same cloud always gives the
    same subset), in the original order; ``points`` itself when it is small enough or ``n`` is None."""
    if n is None or len(points) <= n:
        return points
    keep = np.sort(_generator(seed).choice(len(points), size=n, replace=False, shuffle=_shuffled(len(points), n)))
    # take along the first axis: the same rows as indexing by ``keep``, without the general indexing's set-up (2 against
    # 10 us for a dense view's 1,000 of 14,000 points; issue 19, stop 48)
    return points.take(keep, axis=0) if isinstance(points, np.ndarray) else points[keep]


def _shuffled(population: int, size: int) -> bool:
    """``shuffle`` for :func:`subsample`'s ``Generator.choice(population, size, replace=False)`` whose rows it sorts:
    False where numpy 2's choice takes the same branch either way (issue 19, stop 53): Floyd's algorithm (a
    population of at most 10,000, or a size at most a fiftieth of it), whose ``shuffle`` only permutes the drawn
    values after drawing them, or the tail shuffle (a size above a twentieth), which does not read it; the same
    values, so the same sorted rows, without shuffling them (docs/complete53.md). True (choice's default)
    between the two cut-offs, where ``shuffle`` picks the branch."""
    return 10_000 < population and population // 50 < size <= population // 20


#: Per thread: ``{seed: (generator, its state when new)}`` (:func:`_generator`).
_SEEDED = threading.local()


def _generator(seed: int) -> np.random.Generator:
    """``np.random.default_rng(seed)`` as it is when new: a generator kept per thread and seed, its bit generator's
    state set back to the one it had when made (the same draws; 1 against 40 us of seeding a new one, which a
    fruit's completion did once; issue 19, nineteenth round). Another seed than a whole number: a new generator."""
    if type(seed) is not int:
        return np.random.default_rng(seed)
    kept = getattr(_SEEDED, "by_seed", None)
    if kept is None or len(kept) > 16:
        kept = _SEEDED.by_seed = {}
    found = kept.get(seed)
    if found is None:
        made = np.random.default_rng(seed)
        kept[seed] = (made, made.bit_generator.state)
        return made
    generator, state = found
    generator.bit_generator.state = state
    return generator


def perpendicular_basis(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors completing each unit row of ``d`` (k, 3) to an orthonormal basis: ``e1, e2`` (k, 3),
    ``e2 = d x e1``."""
    if d.shape == (1, 3) and d.dtype == np.float64 and (one := _perpendicular_one(d)) is not None:
        return one
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    use_x = np.abs(x) < 0.9  # cross with (1, 0, 0) where d is not near x, else with (0, 1, 0)
    # Filled column by column (np.stack and a where over stacked rows cost more calls than the arithmetic): the
    # same values, e1 = (0, z, -y) or (-z, 0, x) normalised, e2 = d x e1.
    e1 = np.empty((len(d), 3), dtype=np.result_type(d, 0.0))
    e1[:, 0] = np.where(use_x, 0.0, -z)
    e1[:, 1] = np.where(use_x, z, 0.0)
    e1[:, 2] = np.where(use_x, -y, x)
    e1 /= row_norms(e1)[:, None]
    return e1, cross_rows(d, e1)


def _perpendicular_one(d: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """:func:`perpendicular_basis` of one float64 row (1, 3) in Python floats: the same operations in the same
    order (IEEE double arithmetic, a correctly rounded square root), so the same values, in a tenth of the time
    of some fifteen numpy calls on three numbers (the solid of revolution's fit asks for about six a fruit).
    None for a zero row (numpy divides by zero where Python would raise)."""
    x, y, z = d[0].tolist()  # Python floats, the same values (a generator of float() on numpy scalars cost more)
    if abs(x) < 0.9:
        a, b, c = 0.0, z, -y
    else:
        a, b, c = -z, 0.0, x
    norm = math.sqrt(a * a + b * b + c * c)
    if norm == 0.0:
        return None
    a, b, c = a / norm, b / norm, c / norm
    e1 = np.array([[a, b, c]])
    e2 = np.array([[y * c - z * b, z * a - x * c, x * b - y * a]])
    return e1, e2
