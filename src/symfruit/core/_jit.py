"""The compiled kernels behind :mod:`symfruit.core.kernels` (numba; imported only when a kernel is first asked for).

Each kernel is a whole loop of :mod:`symfruit.core.fits` written out element by element, with its numpy twin
there (the tests compare the two). ``error_model="numpy"``: a division by zero gives inf or NaN as numpy's
does, where the twin's ``np.errstate`` lets it, instead of raising. No ``fastmath``: IEEE arithmetic, though
sums run in another order than numpy's pairwise ones (results agree to rounding, not to the bit).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, cast

import numba
import numba.extending
import numpy as np


def _njit(func: Callable[..., Any]) -> Any:
    """``numba.njit`` with the compiled code cached on disk (beside this file, or in the user's cache directory
    when that is not writable, e.g. a read-only site-packages); without the cache when numba finds no writable
    directory at all (it raises then), so a kernel is never what fails."""
    try:
        return numba.njit(cache=True, error_model="numpy", nogil=True)(func)
    except RuntimeError:
        return numba.njit(error_model="numpy", nogil=True)(func)


def _njit_inlined(func: Callable[..., Any]) -> Any:
    """:func:`_njit` for a small helper that kernels call inside their loops with arrays: inlined into each caller at
    numba's level (``inline="always"``), so that no call passes the arrays (each such call paid their reference
    counts; stop 43, speedext43). The same operations in the same order: the same values, bit for bit."""
    try:
        return numba.njit(cache=True, error_model="numpy", nogil=True, inline="always")(func)
    except RuntimeError:
        return numba.njit(error_model="numpy", nogil=True, inline="always")(func)


@_njit
def solve(a: np.ndarray, b: np.ndarray, x: np.ndarray) -> bool:
    """Solve ``a x = b`` for a small square ``a`` by Gaussian elimination with partial pivoting (``a`` and ``b``
    are overwritten); False, ``x`` untouched, when a pivot is exactly zero (numpy's ``solve`` raises there)."""
    n = a.shape[0]
    for col in range(n):
        piv = col
        best = abs(a[col, col])
        for row in range(col + 1, n):
            if abs(a[row, col]) > best:
                piv, best = row, abs(a[row, col])
        if best == 0.0:
            return False
        if piv != col:
            for j in range(n):
                a[col, j], a[piv, j] = a[piv, j], a[col, j]
            b[col], b[piv] = b[piv], b[col]
        for row in range(col + 1, n):
            f = a[row, col] / a[col, col]
            if f != 0.0:
                for j in range(col, n):
                    a[row, j] -= f * a[col, j]
                b[row] -= f * b[col]
    for row in range(n - 1, -1, -1):
        s = b[row]
        for j in range(row + 1, n):
            s -= a[row, j] * x[j]
        x[row] = s / a[row, row]
    return True


@_njit
def _pivot(x: np.ndarray, lo: int, hi: int) -> float:
    """The median of ``x[lo]``, ``x[hi]`` and the value midway between them: a selection's pivot."""
    a, b, c = x[lo], x[(lo + hi) >> 1], x[hi]
    if a > b:
        a, b = b, a
    if b > c:
        b = c
        if a > b:
            b = a
    return b


@_njit
def select(x: np.ndarray, kth: int) -> None:
    """Reorder ``x`` (n,) in place so that ``x[kth]`` is its ``kth`` smallest value, none larger before it and none
    smaller after (quickselect, median-of-three pivots: a partition without ``np.partition``'s copy, half its
    time on a few hundred values)."""
    lo, hi = 0, x.shape[0] - 1
    while hi > lo:
        b = _pivot(x, lo, hi)
        i, j = lo, hi
        while i <= j:
            while x[i] < b:
                i += 1
            while x[j] > b:
                j -= 1
            if i <= j:
                x[i], x[j] = x[j], x[i]
                i += 1
                j -= 1
        if kth <= j:
            hi = j
        elif kth >= i:
            lo = i
        else:
            return


@_njit
def _sorted_sample(src: np.ndarray, lo: int, size: int, count: int, out: np.ndarray) -> None:
    """``out[:count]``: ``count`` evenly spaced values of ``src[lo:lo + size]`` (the first and the last among them),
    sorted by insertion."""
    for i in range(count):
        v = src[lo + (i * (size - 1)) // (count - 1)]
        j = i
        while j > 0 and out[j - 1] > v:
            out[j] = out[j - 1]
            j -= 1
        out[j] = v


@_njit
def kth_smallest(x: np.ndarray, kth: int, a: np.ndarray, b: np.ndarray) -> float:
    """The ``kth`` smallest value of ``x`` (n,) (``np.partition(x, kth)[kth]``), ``x`` left as it is; ``a`` and
    ``b`` (n,) scratch. Quickselect without its branches (issue 19, sixteenth round): :func:`select`'s
    comparisons go either way at random, and their mispredictions were most of its time. Each round takes 15
    evenly spaced values as a sample, brackets ``kth``'s share of them by the sample's values two places either
    side, and in one pass counts the values below the bracket and copies those within it to a scratch array
    (every value written, the count advanced by the comparison); when ``kth`` falls outside the bracket (or the
    bracket keeps everything), a three-way pass about one sampled value (the lower values to the front, the
    higher to the back, the rest equal to it) takes its place. Both passes keep at least one value fewer, or
    end; the last 32 values or fewer are sorted by insertion. The values compared are ``x``'s, so the result is
    exactly the ``kth`` smallest (NaN, which no comparison orders, counts as equal to the pivots there)."""
    size = x.shape[0]
    src, dst, other = x, a, b
    lo = 0
    sample = np.empty(32)
    while size > 32:
        _sorted_sample(src, lo, size, 15, sample)
        r = (kth * 14 + (size - 1) // 2) // (size - 1)  # kth's place among the 15
        p = sample[r]
        below = sample[r - 2] if r >= 2 else -np.inf
        above = sample[r + 2] if r <= 12 else np.inf
        if below < above:
            n_lo = 0
            m = 0
            for i in range(lo, lo + size):
                v = src[i]
                dst[m] = v
                m += (v >= below) & (v <= above)
                n_lo += v < below
            if n_lo <= kth < n_lo + m and m < size:
                kth -= n_lo
                lo, size = 0, m
                src, dst, other = dst, other, dst
                continue
            p = below if kth < n_lo else above if kth >= n_lo + m else p
        n_lo = 0
        n_hi = 0
        top = size - 1
        for i in range(lo, lo + size):  # three ways about p, into dst's front and back
            v = src[i]
            dst[n_lo] = v
            n_lo += v < p
            dst[top - n_hi] = v
            n_hi += v > p
        if kth < n_lo:
            lo, size = 0, n_lo
        elif kth < size - n_hi:
            return p
        else:
            kth -= size - n_hi
            lo, size = size - n_hi, n_hi
        src, dst, other = dst, other, dst
    if size == 1:
        return src[lo]
    _sorted_sample(src, lo, size, size, sample)
    return sample[kth]


@_njit
def smallest_mean(x: np.ndarray, keep: int, a: np.ndarray, b: np.ndarray) -> float:
    """The mean of the ``keep`` smallest values of ``x`` (n,), ``1 <= keep <= n`` (``x`` left as it is; ``a``, ``b``
    (n,) scratch): those below the ``keep``-th smallest (:func:`kth_smallest`) added in ``x``'s order, then that
    value times the places left (its ties), over ``keep``. The same values as the mean of a partition's first
    ``keep``, added in another order."""
    return _smallest_mean_at(x, keep, a, b)[0]


@_njit
def slice_costs(q: np.ndarray, dirs: np.ndarray, bins: int) -> np.ndarray:
    """:func:`symfruit.core.fits._slice_costs`: the robust slice-circle cost (k,) of every direction (k, 3) for
    centred points ``q`` (n, 3), one direction at a time over the points (the twin's (k, n) passes fused), each
    direction's lower 80 % of the squared distances averaged by :func:`smallest_mean` (issue 19, sixteenth round;
    :func:`select` and a sum of its first places before: the same values, added in another order)."""
    # slice_costs_below never bounds a cost against a NaN least, nor takes one as less: every cost, the same bits
    return slice_costs_below(q, dirs, bins, np.nan, np.nan)[0]


@_njit
def _least(costs: np.ndarray) -> int:
    """``np.argmin(costs)``: the first NaN, else the first least value."""
    best = 0
    for i in range(costs.shape[0]):
        if math.isnan(costs[i]):
            return i
        if costs[i] < costs[best]:
            best = i
    return best


@_njit
def revolution_search(q: np.ndarray, dirs: np.ndarray, bins: int, caps: np.ndarray) -> np.ndarray:
    """:func:`symfruit.core.fits.fit_revolution_slices`' direction search in one call (issue 19, sixteenth round):
    the least :func:`slice_costs` of the coarse directions ``dirs`` (k, 3), then for each of the refining caps
    ``caps`` (r, m, 3) (:func:`symfruit.core.fits._cap_local`'s, about ``+z``) the least of the best direction so
    far and the cap turned about it (:func:`symfruit.core.fits._cap`: the basis of
    :func:`~symfruit.core.points.perpendicular_basis`, each row ``l0 e1 + l1 e2 + l2 d`` summed left to right, where
    BLAS's product may round it otherwise, flipped to ``z >= 0``). Returns the chosen direction (3,). The best
    direction so far is not costed again (issue 19, eighteenth round: its cost is known, unless the cap's flip turned
    it), nor is a direction finished whose cost is surely above the least so far (:func:`slice_costs_below`, issue 19,
    twentieth round: the same pick, 2.1 against 4.2 ms a benchmark frame)."""
    costs, least, at = slice_costs_below(q, dirs, bins, np.inf, np.nan)  # issue 19, twentieth round
    pick = _least(costs)
    best = dirs[pick].copy()
    best_cost = costs[pick]
    best_at = at if best_cost == least else np.nan  # its keep-th smallest distance (not where the pick is NaN)
    m = caps.shape[1]
    cand = np.empty((m + 1, 3))
    for r in range(caps.shape[0]):
        x, y, z = best[0], best[1], best[2]
        if abs(x) < 0.9:  # the basis of core.points.perpendicular_basis
            a, b, c = 0.0, z, -y
        else:
            a, b, c = -z, 0.0, x
        norm = math.sqrt(a * a + b * b + c * c)
        a, b, c = a / norm, b / norm, c / norm
        f, g, h = y * c - z * b, z * a - x * c, x * b - y * a
        cand[0, 0], cand[0, 1], cand[0, 2] = x, y, z
        for i in range(m):
            l0, l1, l2 = caps[r, i, 0], caps[r, i, 1], caps[r, i, 2]
            c0 = l0 * a + l1 * f + l2 * x
            c1 = l0 * b + l1 * g + l2 * y
            c2 = l0 * c + l1 * h + l2 * z
            if c2 < 0:
                c0, c1, c2 = -c0, -c1, -c2
            cand[i + 1, 0], cand[i + 1, 1], cand[i + 1, 2] = c0, c1, c2
        costs = np.empty(m + 1)
        if cand[0, 2] < 0:
            cand[0, 0], cand[0, 1], cand[0, 2] = -x, -y, -z
            costs[:], least, at = slice_costs_below(q, cand, bins, np.inf, np.nan)
        else:  # the best direction so far, as it was: its cost is known (each direction's cost is its own)
            costs[0] = best_cost
            costs[1:], least, at = slice_costs_below(q, cand[1:], bins, best_cost, best_at)
        pick = _least(costs)
        best = cand[pick].copy()
        best_cost = costs[pick]
        best_at = at if best_cost == least else np.nan
    return best


@_njit
def sphere_steps(
    q: np.ndarray, c: np.ndarray, r: float, iterations: int, tolerance: float, scale: float
) -> tuple[float, bool]:
    """:func:`symfruit.core.fits.fit_sphere`'s Gauss-Newton on the residuals ``|q - c| - r`` (``c`` (3,) updated in
    place; it stops once a step times ``scale`` is under ``tolerance``): the radius and True, or False where the
    4x4 normal equations are singular (the twin then takes a least-squares step, so the caller runs the twin)."""
    n = q.shape[0]
    jtj = np.empty((4, 4))
    g = np.empty(4)
    step = np.empty(4)
    # Each step in two loops (issue 19, stop 60): the distances, the Jacobian's rows and the residuals first, point by
    # point from the points' columns (a loop the processor's vector instructions run: their square roots and
    # divisions round as the scalar ones), then the sums, each added in the points' order as before: the same bits,
    # 0.20 against 0.08 ms a benchmark frame replayed.
    q0, q1, q2 = _columns3(q)
    j0s, j1s, j2s, rs = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    for _ in range(iterations):
        c0, c1, c2 = c[0], c[1], c[2]
        for i in range(n):
            d0, d1, d2 = q0[i] - c0, q1[i] - c1, q2[i] - c2
            dist = max(math.sqrt(d0 * d0 + d1 * d1 + d2 * d2), 1e-12)
            j0s[i], j1s[i], j2s[i] = -d0 / dist, -d1 / dist, -d2 / dist
            rs[i] = dist - r
        a00 = a01 = a02 = a03 = a11 = a12 = a13 = a22 = a23 = g0 = g1 = g2 = g3 = 0.0
        for i in range(n):
            j0, j1, j2, res = j0s[i], j1s[i], j2s[i], rs[i]
            a00 += j0 * j0
            a01 += j0 * j1
            a02 += j0 * j2
            a03 -= j0
            a11 += j1 * j1
            a12 += j1 * j2
            a13 -= j1
            a22 += j2 * j2
            a23 -= j2
            g0 -= j0 * res
            g1 -= j1 * res
            g2 -= j2 * res
            g3 += res
        jtj[0, 0], jtj[0, 1], jtj[0, 2], jtj[0, 3] = a00, a01, a02, a03
        jtj[1, 1], jtj[1, 2], jtj[1, 3] = a11, a12, a13
        jtj[2, 2], jtj[2, 3] = a22, a23
        g[0], g[1], g[2], g[3] = g0, g1, g2, g3
        jtj[3, 3] = float(n)
        for a in range(4):
            for b in range(a):
                jtj[a, b] = jtj[b, a]
        if not solve(jtj, g, step):
            return r, False
        c[0] += step[0]
        c[1] += step[1]
        c[2] += step[2]
        r = abs(r + step[3])
        largest = 0.0
        for a in range(4):
            largest = max(largest, abs(step[a]))
        if largest * scale < tolerance:
            break
    return r, True


@_njit
def _per_slice(sums: np.ndarray, cnt: np.ndarray) -> None:
    """Each slice's sums (3, b) divided by its count (b,), in place: the slice means."""
    for s in range(cnt.shape[0]):
        sums[0, s] /= cnt[s]
        sums[1, s] /= cnt[s]
        sums[2, s] /= cnt[s]


@_njit
def revolution_steps(w: np.ndarray, which: np.ndarray, cnt: np.ndarray, a2: np.ndarray, steps: int) -> None:
    """:func:`symfruit.core.fits.fit_revolution_slices`' Gauss-Newton on the axis position ``a2`` (2,), updated in
    place: the points' plane coordinates ``w`` (n, 2) about the axis at ``a2`` less their slice's mean distance
    (slice ``which`` (n,), ``cnt`` (b,) its points, at least 1). Each step's distances and Jacobian rows in a loop of
    their own (it vectorises), then the slices' sums in the points' order (issue 19, stop 65, rev65: the same bits,
    with :func:`revolution_profile`'s last distances so split too, 0.24 against 0.17 ms a benchmark frame's
    profiles, replayed)."""
    n, b = w.shape[0], cnt.shape[0]
    rho = np.empty(n)
    j0 = np.empty(n)
    j1 = np.empty(n)
    sums = np.empty((3, b))
    jtj = np.empty((2, 2))
    g = np.empty(2)
    step = np.empty(2)
    w0, w1 = w[:, 0].copy(), w[:, 1].copy()
    for _ in range(steps):
        # the distances and the Jacobian's rows first, point by point from the columns (a loop the processor's vector
        # instructions run: their square roots and divisions round as the scalar ones), then the slices' sums in the
        # points' order as before (issue 19, stop 65, rev65: the same bits)
        c0, c1 = a2[0], a2[1]
        for i in range(n):
            d0, d1 = w0[i] - c0, w1[i] - c1
            r = max(math.sqrt(d0 * d0 + d1 * d1), 1e-12)
            rho[i], j0[i], j1[i] = r, -d0 / r, -d1 / r
        sums[:] = 0.0
        for i in range(n):
            s = which[i]
            sums[0, s] += rho[i]
            sums[1, s] += j0[i]
            sums[2, s] += j1[i]
        _per_slice(sums, cnt)
        a11 = a12 = a22 = g0 = g1 = 0.0
        for i in range(n):
            s = which[i]
            res = rho[i] - sums[0, s]
            x0 = j0[i] - sums[1, s]
            x1 = j1[i] - sums[2, s]
            a11 += x0 * x0
            a12 += x0 * x1
            a22 += x1 * x1
            g0 -= x0 * res
            g1 -= x1 * res
        if abs(a11 * a22 - a12 * a12) < 1e-30:
            break
        jtj[0, 0], jtj[0, 1], jtj[1, 0], jtj[1, 1] = a11, a12, a12, a22
        g[0], g[1] = g0, g1
        if not solve(jtj, g, step):
            break
        a2[0] += step[0]
        a2[1] += step[1]
        if max(abs(step[0]), abs(step[1])) < 1e-7:
            break


@_njit
def revolution_profile(
    q: np.ndarray, best: np.ndarray, e1: np.ndarray, e2: np.ndarray, bins: int, steps: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, bool]:
    """:func:`symfruit.core.fits._revolution_profile`: for centred points ``q`` (n, 3) about the axis direction
    ``best`` (plane basis ``e1``, ``e2``), the axis position in the plane (2,), the slice borders (b + 1,), the
    slices' radii (b,) and the robust cost, and True; False where the algebraic start's 2x2 system is singular
    (the twin's least squares then takes the minimum-norm solution, so the caller runs the twin)."""
    n = q.shape[0]
    t = np.empty(n)
    w = np.empty((n, 2))
    m0 = m1 = 0.0
    for i in range(n):
        p0, p1, p2 = q[i, 0], q[i, 1], q[i, 2]
        t[i] = p0 * best[0] + p1 * best[1] + p2 * best[2]
        w[i, 0] = p0 * e1[0] + p1 * e1[1] + p2 * e1[2]
        w[i, 1] = p0 * e2[0] + p1 * e2[1] + p2 * e2[2]
        m0 += w[i, 0]
        m1 += w[i, 1]
    m0 /= n
    m1 /= n
    edges = np.linspace(t.min(), t.max(), bins + 1)
    which = np.searchsorted(edges, t, side="right") - 1
    counts = np.zeros(bins)
    sums = np.zeros((3, bins))
    for i in range(n):
        s = min(max(which[i], 0), bins - 1)
        which[i] = s
        counts[s] += 1.0
        x0, x1 = w[i, 0] - m0, w[i, 1] - m1
        sums[0, s] += x0 * x0 + x1 * x1
        sums[1, s] += x0
        sums[2, s] += x1
    cnt = np.maximum(counts, 1.0)
    _per_slice(sums, cnt)
    # the algebraic start: least squares of 2 dw . a = dy by its normal equations
    a11 = a12 = a22 = g0 = g1 = 0.0
    for i in range(n):
        s = which[i]
        x0, x1 = w[i, 0] - m0, w[i, 1] - m1
        dy = x0 * x0 + x1 * x1 - sums[0, s]
        d0, d1 = 2.0 * (x0 - sums[1, s]), 2.0 * (x1 - sums[2, s])
        a11 += d0 * d0
        a12 += d0 * d1
        a22 += d1 * d1
        g0 += d0 * dy
        g1 += d1 * dy
    lhs = np.array([[a11, a12], [a12, a22]])
    rhs = np.array([g0, g1])
    a2 = np.empty(2)
    radii = np.empty(bins)
    # nearly singular (the normal equations' condition past 1e10): the twin's least squares decides
    if not a11 * a22 - a12 * a12 > 1e-20 * (a11 + a22) ** 2 or not solve(lhs, rhs, a2):
        return a2, edges, radii, 0.0, False
    a2[0] += m0
    a2[1] += m1
    revolution_steps(w, which, cnt, a2, steps)
    rho = np.empty(n)
    mean_r = np.zeros(bins)
    c0, c1 = a2[0], a2[1]
    for i in range(n):  # the distances apart from the slices' sums (a loop that vectorises; rev65)
        d0, d1 = w[i, 0] - c0, w[i, 1] - c1
        rho[i] = math.sqrt(d0 * d0 + d1 * d1)
    for i in range(n):
        mean_r[which[i]] += rho[i]
    for s in range(bins):
        mean_r[s] /= cnt[s]
        radii[s] = mean_r[s] if counts[s] >= 3 else np.nan
    for i in range(n):
        d = rho[i] - mean_r[which[i]]
        rho[i] = d * d
    keep = max(1, int(0.8 * n))
    select(rho, keep - 1)
    total = 0.0
    for i in range(keep):
        total += rho[i]
    return a2, edges, radii, total / keep, True


@_njit
def revolution_march(
    point: np.ndarray, direction: np.ndarray, t_prof: np.ndarray, r_prof: np.ndarray, rays: np.ndarray, z0: float,
    z1: float, steps: int,
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.core.agreement.march` into a solid of revolution (axis ``point``, ``direction``; closed profile
    ``t_prof``, ``r_prof``) along rays (m, 3), each ray stopped at its first step inside: ``(hit (m,), depth (m,))``."""
    m, k = rays.shape[0], t_prof.shape[0]
    zs = np.linspace(z0, z1, steps)
    hit = np.zeros(m, np.bool_)
    depth = np.full(m, np.nan)
    p0, p1, p2 = point[0], point[1], point[2]
    d0, d1, d2 = direction[0], direction[1], direction[2]
    first, last = t_prof[0], t_prof[k - 1]
    for i in range(m):
        a, b, c = rays[i, 0], rays[i, 1], rays[i, 2]
        before = 0.0
        j = 0  # the slice of the last step (the steps walk along the axis monotonically: a short walk each)
        for s in range(steps):
            z = zs[s]
            # core.fits.revolution_inside of the point z * ray (np.interp's rule: 0 outside the profile)
            r0, r1, r2 = a * z - p0, b * z - p1, c * z - p2
            t = r0 * d0 + r1 * d1 + r2 * d2
            o0, o1, o2 = r0 - t * d0, r1 - t * d1, r2 - t * d2
            rho = math.sqrt(o0 * o0 + o1 * o1 + o2 * o2)
            if t < first or t > last or math.isnan(t):
                r = 0.0
            elif t == last:
                r = r_prof[k - 1]
            else:  # the last j with t_prof[j] <= t (np.searchsorted(side="right") - 1)
                while j > 0 and t_prof[j] > t:
                    j -= 1
                while j < k - 2 and t_prof[j + 1] <= t:
                    j += 1
                r = r_prof[j] + (r_prof[j + 1] - r_prof[j]) / (t_prof[j + 1] - t_prof[j]) * (t - t_prof[j])
            f = r - rho - (max(first - t, 0.0) + max(t - last, 0.0))
            if f > 0:
                hit[i] = True
                if s == 0:
                    depth[i] = zs[0]
                else:
                    frac = -before / (f - before) if f != before else 0.0
                    depth[i] = zs[s - 1] + min(max(frac, 0.0), 1.0) * (zs[s] - zs[s - 1])
                break
            before = f
    return hit, depth


#: :func:`near_distance`'s largest whole reach (``floor(reach)``) searched by passes along the rows (each costs every
#: pixel two steps, where the walk's search stops at the nearest column; stop 64, reg64).
_NEAR_PASSES_MOST = 16


@_njit
def near_distance(mask: np.ndarray, reach: float, want: bool, out: np.ndarray) -> None:
    """:func:`symfruit.core.raster._near_distance` of the pixels of ``mask`` (h, w) equal to ``want`` (the twin's
    true pixels), written into ``out`` (h, w): each pixel's distance to the nearest such pixel where that is at most
    ``reach``, +inf elsewhere. The same whole-number squared distances as the twin's shifts (each column's distance
    to its nearest pixel, capped past the reach, by two sweeps; then the nearest over ``2 floor(reach) + 1``
    columns), and the same square roots: the twin's values to the bit. Since issue 19's eighteenth round the column
    sweeps run row by row (each column's last wanted row kept), and a pixel's search over the columns starts at the
    nearest column within its row whose distance is not capped (nearer columns are all capped, and a capped
    column's term is never less than the pixel's own): the same least term. Since issue 19's stop 41 (speedobs41) a
    row's uncapped columns are found by one walk along it (each run of capped pixels between two of them knows both,
    a pixel beyond reach of both is +inf at once) instead of two passes of running gaps, and the sweeps select
    without a branch: 0.14-0.19 against 0.08-0.15 ms on a dense view's window, the same values. Since stop 64 (reg64),
    for a reach of at most :data:`_NEAR_PASSES_MOST` pixels, the rows' least terms are found by ``2 floor(reach)``
    plain passes along each row (one a column offset and side: the least of ``g + t * t`` over the same columns, in
    whole numbers, so the same least), which numba vectorises, instead of that walk and search, which branch at
    every pixel: the same values; the benchmark frame's 9 Python-level calls (reach 8.6-13) 0.170 -> 0.114 ms and
    its 24 ``surface_cap`` calls (``deep_px`` 3-16) 1.45 -> 1.35 ms, replayed."""
    h, w = mask.shape
    k = math.floor(reach)
    cap = k + 1
    cap2 = cap * cap
    g2 = np.empty((h, w), np.int64)
    last = np.empty(w, np.int64)
    last[:] = -cap
    for r in range(h):
        for c in range(w):
            lc = r if mask[r, c] == want else last[c]
            last[c] = lc
            g2[r, c] = min(r - lc, cap)
    last[:] = h - 1 + cap
    for r in range(h - 1, -1, -1):
        for c in range(w):
            lc = r if mask[r, c] == want else last[c]
            last[c] = lc
            d = min(g2[r, c], lc - r)
            g2[r, c] = d * d
    limit = reach * reach
    inf = np.inf
    if k <= _NEAR_PASSES_MOST:  # the rows by passes, each a column offset and side (stop 64, reg64)
        least = np.empty(w, np.int64)
        for r in range(h):
            g = g2[r]
            o = out[r]
            for c in range(w):
                least[c] = g[c]  # at most cap2: the column's own term (a capped one is the search's start)
            for t in range(1, min(k, w - 1) + 1):
                tt = t * t
                for c in range(w - t):  # indices from 0 up: numba vectorises it (c - t would not)
                    least[c + t] = min(least[c + t], g[c] + tt)
                for c in range(w - t):
                    least[c] = min(least[c], g[c + t] + tt)
            for c in range(w):
                b = least[c]
                o[c] = math.sqrt(float(b)) if b <= limit else inf
        return
    for r in range(h):
        g = g2[r]
        o = out[r]
        # columns below the cap, one after the other: a pixel's search reaches from its own column to the nearest such
        # column on each side, within k
        prev = -(k + 2)  # the last column below the cap so far
        c = 0
        while c < w:
            # the next column below the cap at or after c
            nxt = c
            while nxt < w and g[nxt] >= cap2:
                nxt += 1
            # pixels c .. nxt - 1 are capped: their nearest uncapped columns are prev and nxt
            for q in range(c, nxt):
                dl = q - prev
                dr = nxt - q if nxt < w else k + 2
                if dl > k and dr > k:
                    o[q] = inf
                    continue
                best = cap2
                t0 = min(dl, dr)
                for t in range(t0, k + 1):
                    tt = t * t
                    if tt >= best:
                        break
                    if q - t >= 0 and g[q - t] + tt < best:
                        best = g[q - t] + tt
                    if q + t < w and g[q + t] + tt < best:
                        best = g[q + t] + tt
                o[q] = math.sqrt(float(best)) if best <= limit else inf
            if nxt >= w:
                break
            # column nxt is below the cap
            best = g[nxt]
            if best == 0:
                o[nxt] = 0.0
            else:
                for t in range(1, k + 1):
                    tt = t * t
                    if tt >= best:
                        break
                    if nxt - t >= 0 and g[nxt - t] + tt < best:
                        best = g[nxt - t] + tt
                    if nxt + t < w and g[nxt + t] + tt < best:
                        best = g[nxt + t] + tt
                o[nxt] = math.sqrt(float(best)) if best <= limit else inf
            prev = nxt
            c = nxt + 1


@_njit
def square_filter(src: np.ndarray, radius: int, every: bool, out: np.ndarray) -> None:
    """``out`` (h, w) bool: the minimum (``every``: all of the square true) or maximum (any true) of ``src`` (h, w)
    over the ``2 radius + 1`` square about each pixel, outside the array false (``ndimage.minimum_filter`` /
    ``maximum_filter`` with ``mode="constant", cval=False``). Since issue 19's stop 48 (compspeed48) by
    :func:`_square_any` (the last deciding pixel's index along each row, then down each column) where running
    counts kept two (h, w) arrays of counts: the same pixels (the whole square true is no false pixel within the
    array, with the square wholly within it), 46 against 25 us on a dense view's window."""
    h, w = src.shape
    if not every:
        _square_any(src, radius, True, out)
        return
    _square_any(src, radius, False, out)
    for r in range(h):
        inside_r = r >= radius and r + radius < h
        for c in range(w):
            out[r, c] = inside_r and c >= radius and c + radius < w and not out[r, c]


@_njit
def _square_any(src: np.ndarray, radius: int, want: bool, out: np.ndarray) -> None:
    """``out`` (h, w) bool: whether a pixel of ``src`` (h, w) bool equal to ``want`` lies within the ``2 radius + 1``
    square about each pixel, clipped to the array (the twin: ``ndimage.maximum_filter(src == want, 2 radius + 1,
    mode="constant")``, :func:`symfruit.core.raster.square_filter`'s). Along each row the index of the last such
    pixel up to ``radius`` columns ahead decides a pixel (it is in the square when at most ``radius`` columns
    behind), then down each column the last row whose row-wise result is true, likewise (issue 19, stop 48,
    compspeed48: no counts, no (h, w) array of them; the rows' pass selects without a branch)."""
    h, w = src.shape
    t = radius
    far = -(2 * t + 2)  # an index no pixel's square reaches
    rows = np.empty((h, w), np.bool_)
    for r in range(h):
        last = far
        s = src[r]
        o = rows[r]
        for c in range(w):
            last = c if s[c] == want else last
            if c >= t:
                o[c - t] = last >= c - 2 * t
        for c in range(max(w, t), w + t):
            o[c - t] = last >= c - 2 * t
    last_row = np.full(w, far, np.int64)
    for rr in range(h + t):
        if rr < h:
            x = rows[rr]
            for c in range(w):
                last_row[c] = rr if x[c] else last_row[c]
        p = rr - t
        if p >= 0:
            o = out[p]
            for c in range(w):
                o[c] = last_row[c] >= p - t


@_njit
def _box(mask: np.ndarray) -> tuple[int, int, int, int]:
    """``(r0, r1, c0, c1)`` of a bool image's true pixels (stops exclusive), ``(0, 0, 0, 0)`` when none."""
    h, w = mask.shape
    r0, r1, c0, c1 = h, 0, w, 0
    for r in range(h):
        for c in range(w):
            if mask[r, c]:
                r0, r1 = min(r0, r), r + 1
                c0, c1 = min(c0, c), max(c1, c + 1)
    return (r0, r1, c0, c1) if r1 > 0 else (0, 0, 0, 0)


@_njit_inlined
def _rows_box(mask: np.ndarray) -> tuple[int, int, int, int]:
    """:func:`_box` of ``mask`` (h, w) bool, each row or'ed whole without a jump (several pixels at once) and the first
    and last pixel walked to from its ends where it holds one (stop 60, speeds60): the same box."""
    h, w = mask.shape
    r0, r1, c0, c1 = _mask_box_in(mask, 0, 0, h, w)
    return (r0, r1, c0, c1) if r1 > 0 else (0, 0, 0, 0)


@_njit
def allowed(hidden: np.ndarray, seen: np.ndarray, gap: int, thin: int) -> np.ndarray:
    """:meth:`symfruit.core.occlusion.Occlusion.allowed` of a window's ``hidden`` and ``seen`` pixels (h, w) bool
    (``seen`` not empty): the 8-connected parts of ``hidden`` (opened by a ``2 thin + 1`` square when ``thin >
    0``, over the hidden pixels' box), ``seen`` and their joins across ``gap`` (over the seen pixels' box grown
    by ``2 gap``, as the twin's filters) that hold a seen pixel, by a flood fill from the seen pixels; the twin's
    pixels exactly (booleans)."""
    s0, s1, t0, t1 = _box(seen)
    join = _joins(hidden, seen, s0, s1, t0, t1, gap, thin)
    return _flood_box(join, seen, s0, s1, t0, t1)[0]


@_njit
def _joins(
    hidden: np.ndarray, seen: np.ndarray, s0: int, s1: int, t0: int, t1: int, gap: int, thin: int
) -> np.ndarray:  # fmt: skip
    """:func:`allowed`'s and :func:`allowed_box`'s pixels a fill from the seen pixels may cross: ``hidden`` opened
    by a ``2 thin + 1`` square over its box (when ``thin > 0``), and the pixels within ``gap`` of both a seen and
    such a pixel, over the seen pixels' box ``s0:s1, t0:t1`` grown by ``2 gap`` (the twin's filters,
    :func:`_square_extreme`'s pixels)."""
    h, w = hidden.shape
    join = hidden.copy()
    if thin > 0:
        h0, h1, g0, g1 = _rows_box(hidden)  # _box's, each row or'ed whole (stop 65, look65)
        if h1 > h0:
            open_square(hidden[h0:h1, g0:g1], thin, join[h0:h1, g0:g1])  # one sweep (stop 61, speedb61)
    if gap > 0:
        e0, e1 = max(s0 - 2 * gap, 0), min(s1 + 2 * gap, h)
        f0, f1 = max(t0 - 2 * gap, 0), min(t1 + 2 * gap, w)
        near_both(seen[e0:e1, f0:f1], join[e0:e1, f0:f1], gap)  # one sweep (stop 61, speedb61)
    return join


@_njit_inlined
def _row_grown(row: np.ndarray, radius: int, out: np.ndarray) -> None:
    """``out`` (w,) bool: ``row`` (w,) bool dilated by ``2 radius + 1`` pixels (beyond the row: false), from the index
    of the last true pixel, as :func:`_square_extreme`'s row pass."""
    w = row.shape[0]
    last = -(2 * radius + 2)
    for c in range(w + radius):
        if c < w and row[c]:
            last = c
        p = c - radius
        if p >= 0:
            out[p] = last >= p - radius


@_njit
def near_both(seen: np.ndarray, join: np.ndarray, radius: int) -> None:
    """``join |= grown(seen) & grown(join)``, in place, ``grown`` a ``2 radius + 1`` square's dilation (``radius >=
    1``; beyond the arrays: false), both (h, w) bool, the dilation of ``join`` as it was on entry:
    :func:`_joins`' pixels within ``gap`` of both a seen and a hidden pixel, :func:`_square_extreme`'s pixels
    (``scipy.ndimage.maximum_filter``'s). Issue 19, stop 61 (speedb61): one sweep down the rows instead of two
    filters of two passes each and their AND: row ``r`` of each is dilated along the row, each column keeps the
    last row whose dilated pixel is true, and row ``p = r - radius`` is then final (a true pixel within ``radius``
    rows of it lies at row ``r`` or above). A row is written ``radius`` rows after it was read, and no row is read
    again: the dilation reads ``join`` as it was."""
    h, w = seen.shape
    t = radius
    none = -(2 * t + 2)
    last_s = np.full(w, none, np.int64)  # each column's last row whose row-dilated seen pixel is true
    last_j = np.full(w, none, np.int64)
    row_s = np.empty(w, np.bool_)
    row_j = np.empty(w, np.bool_)
    for r in range(h + t):
        if r < h:
            _row_grown(seen[r], t, row_s)
            _row_grown(join[r], t, row_j)
            for c in range(w):
                last_s[c] = r if row_s[c] else last_s[c]
                last_j[c] = r if row_j[c] else last_j[c]
        p = r - t
        if p >= 0:
            o = join[p]
            low = p - t
            for c in range(w):
                o[c] |= (last_s[c] >= low) & (last_j[c] >= low)


@_njit
def _flood_box(
    join: np.ndarray, seen: np.ndarray, s0: int, s1: int, t0: int, t1: int
) -> tuple[np.ndarray, int, int, int, int]:  # fmt: skip
    """The 8-connected flood fill from the ``seen`` pixels (all within ``s0:s1, t0:t1``) over ``join``: the pixels
    reached (the seen ones included) and their box ``(r0, r1, c0, c1)``, stops exclusive (:func:`allowed`,
    :func:`allowed_box`)."""
    h, w = join.shape
    reached = seen.copy()
    stack = np.empty(h * w, np.int64)
    top = 0
    for r in range(s0, s1):
        for c in range(t0, t1):
            if seen[r, c]:
                stack[top] = r * w + c
                top += 1
    r0, r1, c0, c1 = s0, s1, t0, t1
    while top > 0:
        top -= 1
        r, c = divmod(stack[top], w)
        for ddr in range(-1, 2):
            rr = r + ddr
            if rr < 0 or rr >= h:
                continue
            for ddc in range(-1, 2):
                cc = c + ddc
                if cc < 0 or cc >= w or reached[rr, cc]:
                    continue
                if join[rr, cc]:
                    reached[rr, cc] = True
                    r0, r1 = min(r0, rr), max(r1, rr + 1)
                    c0, c1 = min(c0, cc), max(c1, cc + 1)
                    stack[top] = rr * w + cc
                    top += 1
    return reached, r0, r1, c0, c1


@_njit_inlined
def _scatter(points: np.ndarray, idx: np.ndarray, n: int, out: np.ndarray) -> None:
    """The scatter matrix (3, 3) of ``points[idx[:n]]`` about their mean (the sum of the outer products of their
    deviations, not divided by ``n``), into ``out``: summed in ``idx``'s order."""
    m0 = m1 = m2 = 0.0
    for t in range(n):
        j = idx[t]
        m0 += points[j, 0]
        m1 += points[j, 1]
        m2 += points[j, 2]
    m0, m1, m2 = m0 / n, m1 / n, m2 / n
    c00 = c01 = c02 = c11 = c12 = c22 = 0.0
    for t in range(n):
        j = idx[t]
        e0, e1, e2 = points[j, 0] - m0, points[j, 1] - m1, points[j, 2] - m2
        c00 += e0 * e0
        c01 += e0 * e1
        c02 += e0 * e2
        c11 += e1 * e1
        c12 += e1 * e2
        c22 += e2 * e2
    out[0, 0], out[0, 1], out[0, 2] = c00, c01, c02
    out[1, 0], out[1, 1], out[1, 2] = c01, c11, c12
    out[2, 0], out[2, 1], out[2, 2] = c02, c12, c22


@_njit_inlined
def _covariances_at(points: np.ndarray, best_i: np.ndarray, small: int, large: int, scatter: np.ndarray,
                    out_small: np.ndarray, out_large: np.ndarray, q: int) -> None:  # fmt: skip
    """Query ``q``'s covariances of its ``small`` and ``large`` nearest (``best_i``, nearest first) into
    ``out_small[q]`` and ``out_large[q]`` (``scatter`` a (3, 3) scratch): :func:`neighbour_covariances` and
    :func:`grid_covariances` alike."""
    for kk, out in ((small, out_small), (large, out_large)):
        _scatter(points, best_i, kk, scatter)
        for r in range(3):
            for c in range(3):
                out[q, r, c] = scatter[r, c] / kk


@_njit
def neighbour_covariances(points: np.ndarray, step: int, small: int, large: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`symfruit.core.fits._neighbour_covariances`: for each query point ``points[::step]``, the covariances
    (3, 3) of its ``small`` and its ``large`` nearest points (itself among them; ``small <= large <= n``), each
    about its own mean: ``(m, 3, 3), (m, 3, 3)``. The nearest by brute force (every squared distance, the
    nearest ``large`` kept in order, ties by index: the same points as the twin's search tree but where a tie
    straddles the last place), not a search tree: a few thousand points are fewer operations than building one.
    Since the sixteenth round of issue 19 the ``large``-th least distance is found first (:func:`kth_smallest`)
    and only the points no farther are put in order (by insertion, ties by index): the same points in the same
    order as inserting every point into the ``large`` kept (which it does where a distance is NaN), in about
    half the time."""
    n = points.shape[0]
    m = (n + step - 1) // step
    out_small = np.empty((m, 3, 3))
    out_large = np.empty((m, 3, 3))
    best_d = np.empty(n)
    best_i = np.empty(n, np.int64)
    dist = np.empty(n)
    scratch_a = np.empty(n)
    scratch_b = np.empty(n)
    scatter = np.empty((3, 3))
    for q in range(m):
        x, y, z = points[q * step, 0], points[q * step, 1], points[q * step, 2]
        finite = True
        for j in range(n):
            dx, dy, dz = points[j, 0] - x, points[j, 1] - y, points[j, 2] - z
            dist[j] = dx * dx + dy * dy + dz * dz
            finite &= not math.isnan(dist[j])
        if finite:  # the points within the large-th distance, in order (ties by index)
            limit = kth_smallest(dist, large - 1, scratch_a, scratch_b)
            count = 0
            for j in range(n):
                d = dist[j]
                if d <= limit:
                    slot = count
                    count += 1
                    while slot > 0 and best_d[slot - 1] > d:
                        best_d[slot] = best_d[slot - 1]
                        best_i[slot] = best_i[slot - 1]
                        slot -= 1
                    best_d[slot] = d
                    best_i[slot] = j
        else:  # every point offered to the large kept in order
            count = 0
            for j in range(n):
                d = dist[j]
                if count == large:
                    if not d < best_d[large - 1]:
                        continue
                    slot = large - 1
                else:
                    slot = count
                    count += 1
                while slot > 0 and best_d[slot - 1] > d:  # insertion: the kept ones stay sorted, ties in index order
                    best_d[slot] = best_d[slot - 1]
                    best_i[slot] = best_i[slot - 1]
                    slot -= 1
                best_d[slot] = d
                best_i[slot] = j
        _covariances_at(points, best_i, small, large, scatter, out_small, out_large, q)
    return out_small, out_large


@_njit
def inside_px(
    points: np.ndarray, fx: float, fy: float, cx: float, cy: float, u0: int, v0: int, inner: np.ndarray
) -> np.ndarray:
    """:func:`symfruit.core.agreement._inside_px`: the distance map ``inner`` (h, w) at each point's (n, 3) pixel
    (:meth:`~symfruit.core.camera.Camera.project`'s arithmetic, rounded half to even, less the window's corner
    ``u0``, ``v0``, clipped to the window): the twin's values to the bit. A coordinate numpy's integer conversion
    cannot hold (NaN, infinite, past 2^63) becomes its smallest integer there, and so here, the corner's
    subtraction wrapping around as numpy's does."""
    h, w = inner.shape
    n = points.shape[0]
    out = np.empty(n)
    big = 9.223372036854775808e18  # 2^63
    least = np.int64(-9223372036854775808)
    for i in range(n):
        inv_z = 1.0 / points[i, 2]
        u = np.rint(fx * points[i, 0] * inv_z + cx)
        v = np.rint(fy * points[i, 1] * inv_z + cy)
        iu = np.int64(u) if -big <= u < big else least
        iv = np.int64(v) if -big <= v < big else least
        out[i] = inner[min(max(iv - np.int64(v0), 0), h - 1), min(max(iu - np.int64(u0), 0), w - 1)]
    return out


@_njit
def occluded_at(
    u: np.ndarray, v: np.ndarray, hidden: np.ndarray, u0: int, v0: int, width: int, height: int, radius: int
) -> np.ndarray:
    """:meth:`symfruit.core.occlusion.Occlusion.at`: whether each pixel ``(u, v)`` (m,) (rounded half to even) lies
    within ``radius`` of the image's border or has a hidden pixel of the window ``hidden`` (h, w) at ``(u0, v0)``
    within ``radius`` (a square; the window's own pixels alone), by looking through the square (issue 19,
    sixteenth round; the twin filters the hidden pixels' map over the pixels' box): the twin's booleans. A
    coordinate numpy's integer conversion cannot hold (NaN, infinite, past 2^63) becomes its smallest integer
    there, and so here, as :func:`inside_px` does."""
    h, w = hidden.shape
    n = u.shape[0]
    out = np.empty(n, np.bool_)
    big = 9.223372036854775808e18  # 2^63
    least = np.int64(-9223372036854775808)
    for i in range(n):
        fu, fv = np.rint(u[i]), np.rint(v[i])
        col = np.int64(fu) if -big <= fu < big else least
        row = np.int64(fv) if -big <= fv < big else least
        o = col < radius or col >= width - radius or row < radius or row >= height - radius
        c, r = col - np.int64(u0), row - np.int64(v0)
        if not o and 0 <= c < w and 0 <= r < h:
            if radius <= 0:
                o = hidden[r, c]
            else:
                for rr in range(max(r - radius, 0), min(r + radius + 1, h)):
                    for cc in range(max(c - radius, 0), min(c + radius + 1, w)):
                        if hidden[rr, cc]:
                            o = True
                            break
                    if o:
                        break
        out[i] = o
    return out


@_njit
def rim_coverage(
    points: np.ndarray, fx: float, fy: float, cx: float, cy: float, u0: int, v0: int, mask: np.ndarray,
    inner: np.ndarray, width: float, fill: int,
) -> float:  # fmt: skip
    """:func:`symfruit.methods.evidence.rim_coverage` once its rim width and distance map are known: the share of the
    region's (``mask`` (h, w) at ``(u0, v0)``) rim pixels (``inner <= width``) holding a point's pixel
    (:meth:`~symfruit.core.camera.Camera.project`'s arithmetic, rounded half to even, as :func:`inside_px`; a point
    off the window holds none), over the share of its other pixels, at most 1 (1 where either part is empty or no
    other pixel holds a point); with ``fill > 0`` a point holds the ``2 fill + 1`` square about its pixel (the
    twin's maximum filter: its reflected border repeats pixels already within the square, as the window's edge
    cut here). Counts of whole numbers and the twin's two divisions: its value to the bit (issue 19, sixteenth
    round). The points' pixels by :func:`point_pixels`, then :func:`rim_coverage_pixels`."""
    col, row = point_pixels(points, fx, fy, cx, cy)
    return rim_coverage_pixels(col, row, u0, v0, mask, inner, width, fill)


@_njit
def cone_residuals(
    params: np.ndarray, cone: np.ndarray, axis: np.ndarray, rays: np.ndarray, ray_cone: np.ndarray, z: np.ndarray,
    out: np.ndarray,
) -> None:  # fmt: skip
    """The depth residuals (k, n) into ``out`` of :func:`symfruit.core.fits.fit_cone_ellipsoid`: ``z`` less the front
    of each ellipsoid of :func:`symfruit.core.fits._cone_fronts` (parameters (k, 4)) along each ray, 0.05 for an
    invalid ellipsoid's row, 0.02 where a ray misses (or the logistic has saturated: ``gap`` 0, no front). By
    :func:`_cone_residuals_of` on the rays' columns."""
    r0, r1, r2 = _columns3(rays)
    _cone_residuals_of(params, cone, axis, r0, r1, r2, ray_cone, z, out)


@_njit
def _columns3(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The three columns of ``p`` (n, 3), each a contiguous copy."""
    n = p.shape[0]
    c0, c1, c2 = np.empty(n), np.empty(n), np.empty(n)
    for i in range(n):
        c0[i], c1[i], c2[i] = p[i, 0], p[i, 1], p[i, 2]
    return c0, c1, c2


@_njit
def _cone_residuals_of(
    params: np.ndarray, cone: np.ndarray, axis: np.ndarray, r0: np.ndarray, r1: np.ndarray, r2: np.ndarray,
    ray_cone: np.ndarray, z: np.ndarray, out: np.ndarray,
) -> None:  # fmt: skip
    """:func:`cone_residuals` with the rays given as their three columns (n,) each: the same operations on the same
    values, ray by ray; read from contiguous columns, the loop over the rays runs in the processor's vector
    instructions (a vector's division and square root round as the scalar ones do: the same bits), where the
    rays' (n, 3) rows kept it scalar (issue 19, stop 60: 6.9 against 1.6 us a call of five rows of 231 rays)."""
    k, n = params.shape[0], r0.shape[0]
    for j in range(k):
        e = math.exp(params[j, 2])
        m0 = (axis[0] + params[j, 0]) * e
        m1 = (axis[1] + params[j, 1]) * e
        m2 = axis[2] * e
        c0 = m0 * cone[0, 0] + m1 * cone[1, 0] + m2 * cone[2, 0]
        c1 = m0 * cone[0, 1] + m1 * cone[1, 1] + m2 * cone[2, 1]
        c2 = m0 * cone[0, 2] + m1 * cone[1, 2] + m2 * cone[2, 2]
        qq = -(c0 * m0 + c1 * m1 + c2 * m2)
        if not qq > 0:
            for i in range(n):
                out[j, i] = 0.05
            continue
        lam = qq / (1.0 + math.exp(-min(max(params[j, 3], -50.0), 50.0)))
        gap = lam - qq
        for i in range(n):
            rcm = c0 * r0[i] + c1 * r1[i] + c2 * r2[i]
            a = ray_cone[i] / lam - rcm * rcm / (lam * gap)
            b = rcm / gap
            c = -lam / gap
            disc = b * b - a * c
            res = z[i] - (b - math.sqrt(disc)) / a if disc >= 0 else np.nan
            out[j, i] = res if math.isfinite(res) else 0.02


@_njit
def huber_cost(res: np.ndarray, huber: float) -> float:
    """The Huber cost of one row of residuals (``fit_cone_ellipsoid``'s ``cost``)."""
    total = 0.0
    for i in range(res.shape[0]):
        a = abs(res[i])
        total += 0.5 * res[i] * res[i] if a <= huber else huber * (a - 0.5 * huber)
    return total


@_njit
def _weighted_normal(
    both: np.ndarray, huber: float, step: np.ndarray, w: np.ndarray, jac: np.ndarray, jtj: np.ndarray
) -> None:
    """The Huber weights ``w`` (n,) of the residuals ``both[0]``, the forward-difference Jacobian ``jac`` (4, n) from
    the residuals at each step ``both[1:]``, and ``J^T W J`` into ``jtj`` (4, 4), as the twin forms them."""
    n = both.shape[1]
    for i in range(n):
        ri = both[0, i]
        a = abs(ri)
        w[i] = 1.0 if a <= huber else huber / max(a, 1e-12)
        for b in range(4):
            jac[b, i] = (both[b + 1, i] - ri) / step[b]
    # the ten sums in one pass (issue 19, stop 60): each the same terms added in the same order as ten passes of
    # one sum each, but ten independent chains of additions in flight instead of one at a time (a chain waits on
    # its last addition's latency), the same bits
    s00 = s01 = s02 = s03 = s11 = s12 = s13 = s22 = s23 = s33 = 0.0
    for i in range(n):
        wi = w[i]
        j0, j1, j2, j3 = jac[0, i], jac[1, i], jac[2, i], jac[3, i]
        t0, t1, t2, t3 = j0 * wi, j1 * wi, j2 * wi, j3 * wi
        s00 += t0 * j0
        s01 += t0 * j1
        s02 += t0 * j2
        s03 += t0 * j3
        s11 += t1 * j1
        s12 += t1 * j2
        s13 += t1 * j3
        s22 += t2 * j2
        s23 += t2 * j3
        s33 += t3 * j3
    jtj[0, 0], jtj[0, 1], jtj[0, 2], jtj[0, 3] = s00, s01, s02, s03
    jtj[1, 0], jtj[1, 1], jtj[1, 2], jtj[1, 3] = s01, s11, s12, s13
    jtj[2, 0], jtj[2, 1], jtj[2, 2], jtj[2, 3] = s02, s12, s22, s23
    jtj[3, 0], jtj[3, 1], jtj[3, 2], jtj[3, 3] = s03, s13, s23, s33


@_njit
def cone_fit(
    grid: np.ndarray, cone: np.ndarray, axis: np.ndarray, rays: np.ndarray, ray_cone: np.ndarray, z: np.ndarray,
    step: np.ndarray, huber: float, iterations: int, tolerance: float, tau_max: float,
) -> tuple[np.ndarray, np.ndarray, int]:  # fmt: skip
    """:func:`symfruit.core.fits.fit_cone_ellipsoid`'s grid search and Levenberg-Marquardt (its twin the numpy loop
    there), the shape parameter bounded by ``tau_max`` (an active set of one
    bound): the parameters (4,), the residuals at them and at each finite-difference step (5, n), and a status:
    0 done, 1 no finite cost on the grid, 2 a singular damped system (numpy's ``solve`` raises there; the caller
    runs the twin). The grid's pick by :func:`cone_grid_best` (issue 19, twentieth round)."""
    n = rays.shape[0]
    r0, r1, r2 = _columns3(rays)  # once for every row (issue 19, stop 60: _cone_residuals_of)
    best = _cone_grid_best_of(grid, cone, axis, r0, r1, r2, ray_cone, z, huber)  # issue 19, twentieth round
    at = np.empty((5, 4))
    both = np.empty((5, n))
    if best < 0:
        return at[0], both, 1
    p = grid[best].copy()
    for a in range(5):
        for b in range(4):
            at[a, b] = p[b] + step[b] if a == b + 1 else p[b]
    _cone_residuals_of(at, cone, axis, r0, r1, r2, ray_cone, z, both)
    trial_both = np.empty((5, n))
    current = huber_cost(both[0], huber)
    mu = 1e-2
    jac = np.empty((4, n))
    w = np.empty(n)
    jtj = np.empty((4, 4))
    g = np.empty(4)
    lhs4, rhs4, x4 = np.empty((4, 4)), np.empty(4), np.empty(4)
    lhs3, rhs3, x3 = np.empty((3, 3)), np.empty(3), np.empty(3)
    trial = np.empty(4)
    for _ in range(iterations):
        done = False
        _weighted_normal(both, huber, step, w, jac, jtj)
        g0 = g1 = g2 = g3 = 0.0  # the four sums in one pass, as _weighted_normal's (issue 19, stop 60)
        for i in range(n):
            wi, ri = w[i], both[0, i]
            g0 += jac[0, i] * wi * ri
            g1 += jac[1, i] * wi * ri
            g2 += jac[2, i] * wi * ri
            g3 += jac[3, i] * wi * ri
        g[0], g[1], g[2], g[3] = g0, g1, g2, g3
        improved = False
        # at the bound with the cost falling beyond it, tau stays there and the other three are solved for alone
        free = 3 if p[3] >= tau_max and g[3] < 0 else 4
        lhs, rhs, x = (lhs3, rhs3, x3) if free == 3 else (lhs4, rhs4, x4)
        while mu < 1e6:
            for a in range(free):
                for b in range(free):
                    lhs[a, b] = jtj[a, b]
                lhs[a, a] += mu * (jtj[a, a] + 1e-12)
                rhs[a] = g[a]
            if not solve(lhs, rhs, x):
                return p, both, 2
            for b in range(4):
                trial[b] = p[b] - x[b] if b < free else p[b]
            if trial[3] > tau_max:
                trial[3] = tau_max
            for a in range(5):
                for b in range(4):
                    at[a, b] = trial[b] + step[b] if a == b + 1 else trial[b]
            _cone_residuals_of(at, cone, axis, r0, r1, r2, ray_cone, z, trial_both)
            new = huber_cost(trial_both[0], huber)
            if new < current:
                p = trial.copy()
                both, trial_both = trial_both, both
                mu = max(mu / 3.0, 1e-7)
                improved = True
                done = current - new < tolerance * current
                current = new
                break
            mu *= 4.0
        if not improved or done:
            break
    return p, both, 0


@_njit
def _cone_shape(
    p: np.ndarray, cone: np.ndarray, axis: np.ndarray, cone_inv: np.ndarray, m: np.ndarray, shape: np.ndarray
) -> bool:
    """:func:`symfruit.core.fits.cone_ellipsoid` of one parameter vector ``p`` (4,): its centre into ``m`` (3,) and
    its shape into ``shape`` (3, 3) (NaN where the centre falls outside the cone), and whether it is valid."""
    e = math.exp(p[2])
    m[0] = e * (axis[0] + p[0])
    m[1] = e * (axis[1] + p[1])
    m[2] = e * (axis[2] + 0.0)
    q = 0.0
    for j in range(3):
        q += (m[0] * cone[0, j] + m[1] * cone[1, j] + m[2] * cone[2, j]) * m[j]
    q = -q
    valid = q > 0
    lam = (q if valid else np.nan) / (1.0 + math.exp(-min(max(p[3], -50.0), 50.0)))
    for a in range(3):
        for b in range(3):
            shape[a, b] = lam * cone_inv[a, b] + m[a] * m[b]
    return valid


@_njit
def cone_result(
    p: np.ndarray, both: np.ndarray, step: np.ndarray, huber: float, cone: np.ndarray, axis: np.ndarray,
    cone_inv: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, bool, float, float]:  # fmt: skip
    """The end of :func:`symfruit.core.fits.fit_cone_ellipsoid` after :func:`cone_fit`, from its parameters ``p`` (4,)
    and residuals ``both`` (5, n): the centre (3,), the shape (3, 3), whether it is valid, the back face's standard
    deviation (the parameters' covariance ``sigma^2 (J^T W J)^-1`` carried to ``z_c + sqrt(S_zz)`` by finite
    differences; NaN where the 4x4 matrix is singular, as the twin's where numpy's ``inv`` raises) and the rms."""
    n = both.shape[1]
    m = np.empty(3)
    shape = np.empty((3, 3))
    valid = _cone_shape(p, cone, axis, cone_inv, m, shape)
    if not valid:
        return m, shape, False, np.nan, np.nan
    w = np.empty(n)
    jac = np.empty((4, n))
    jtj = np.empty((4, 4))
    _weighted_normal(both, huber, step, w, jac, jtj)
    top = bottom = 0.0
    for i in range(n):
        top += w[i] * both[0, i] * both[0, i]
        bottom += w[i]
    sigma2 = top / max(bottom - 4.0, 1.0)
    for a in range(4):
        jtj[a, a] += 1e-18
    cov = np.empty((4, 4))
    lhs = np.empty((4, 4))
    unit = np.empty(4)
    col = np.empty(4)
    singular = False
    for b in range(4):  # the inverse, column by column (element loops: slice copies cost seconds to compile)
        for a in range(4):
            for c in range(4):
                lhs[a, c] = jtj[a, c]
            unit[a] = 1.0 if a == b else 0.0
        if not solve(lhs, unit, col):
            singular = True
            break
        for a in range(4):
            cov[a, b] = sigma2 * col[a]
    if singular:  # numpy's inv raises: the twin's covariance is NaN
        for a in range(4):
            for c in range(4):
                cov[a, c] = np.nan
    back = m[2] + math.sqrt(shape[2, 2])
    grad = np.empty(4)
    mb = np.empty(3)
    sb = np.empty((3, 3))
    pb = np.empty(4)
    all_valid = True
    for b in range(4):
        for a in range(4):
            pb[a] = p[a] + step[a] if a == b else p[a]
        all_valid = _cone_shape(pb, cone, axis, cone_inv, mb, sb) and all_valid
        grad[b] = (mb[2] + math.sqrt(sb[2, 2]) - back) / step[b]
    var = 0.0
    for b in range(4):
        s = 0.0
        for a in range(4):
            s += grad[a] * cov[a, b]
        var += s * grad[b]
    if var < 0.0:
        var = 0.0
    return m, shape, True, math.sqrt(var) if all_valid else np.nan, math.sqrt(sigma2)


@_njit
def distance(mask: np.ndarray, want: bool, out: np.ndarray) -> None:
    """``ndimage.distance_transform_edt`` of the pixels of ``mask`` (h, w) not equal to ``want`` (the twin's input:
    each pixel's distance to the nearest pixel equal to ``want``, 0 on those), written into ``out`` (h, w); ``mask``
    must hold such a pixel. Meijster's exact transform in whole numbers: each column's distance to its nearest such
    pixel by two sweeps down the rows, then each row's lower envelope of the parabolas ``(u - i)^2 + g(i)^2``; the
    same squared distances as scipy's exact feature transform, and the same square roots: its values to the bit."""
    h, w = mask.shape
    big = h + w  # farther than any pixel of the image: a column without such a pixel
    g = np.empty((h, w), np.int64)
    for c in range(w):
        g[0, c] = 0 if mask[0, c] == want else big
    for r in range(1, h):
        for c in range(w):
            g[r, c] = 0 if mask[r, c] == want else g[r - 1, c] + 1
    for r in range(h - 2, -1, -1):
        for c in range(w):
            if g[r + 1, c] + 1 < g[r, c]:
                g[r, c] = g[r + 1, c] + 1
    f = np.empty(w, np.int64)
    s = np.empty(w, np.int64)  # the envelope's parabolas (their columns), left to right
    t = np.empty(w, np.int64)  # where each of them starts to be the least
    d2 = np.empty(w, np.int64)
    for r in range(h):
        for c in range(w):
            f[c] = g[r, c] * g[r, c]
        _envelope(f, w, s, t, d2)  # the row's lower envelope of the parabolas
        for u in range(w):
            out[r, u] = math.sqrt(float(d2[u]))


@_njit
def nearest(image: np.ndarray, out: np.ndarray) -> None:
    """Each pixel's flat index (``row * w + col``) of the false pixel of ``image`` (h, w) bool nearest to it, the
    one ``ndimage.distance_transform_edt(image, return_indices=True)`` picks, into ``out`` (h, w) int64 (-1
    everywhere when ``image`` holds no false pixel).

    scipy's exact feature transform (Maurer, Qi and Raghavan) in two passes, with its choices among equally near
    pixels: each column's nearest false pixel, the upper of two as near (here by a sweep down the rows and one up,
    row by row); then each row's lower envelope of the parabolas ``(u - c)^2 + (r - row(c))^2`` of its columns, a
    parabola dropped when its predecessor and successor leave it nowhere least (scipy's test, in whole numbers: its
    doubles of whole numbers are exact), and each pixel's the envelope's first parabola no farther than the next.
    Property-tested against scipy, ties included. A false pixel is its own nearest (the only one at distance 0): it
    is written at once, the walk left where it was (a later column's walk from an earlier parabola stops at the same
    one: along the envelope the distances fall, then rise): about a seventh of its time off on the segmenter's split
    windows (stop 51, seg51)."""
    h, w = image.shape
    near = np.empty((h, w), np.int64)  # the nearest false pixel's row in each pixel's column, -1: none
    for c in range(w):
        near[0, c] = -1 if image[0, c] else 0
    for r in range(1, h):
        for c in range(w):
            near[r, c] = near[r - 1, c] if image[r, c] else r
    below = np.full(w, -1, np.int64)  # the nearest false pixel at or below, row by row from the bottom
    for r in range(h - 1, -1, -1):
        row, im = near[r], image[r]
        for c in range(w):  # selects, no branch a pixel (stop 55)
            b = below[c] if im[c] else r
            below[c] = b
            a = row[c]
            row[c] = b if (b >= 0) & ((a < 0) | (b - r < r - a)) else a  # as near: the upper one stays
    env = np.empty(w, np.int64)  # the envelope's columns, left to right
    for r in range(h):
        row = near[r]
        top = _row_envelope(row, r, env)
        if top < 0:  # no false pixel in the image: nothing to point to
            out[r, :] = -1
            continue
        k = 0
        for u in range(w):
            if row[u] == r:  # a false pixel: its own nearest
                out[r, u] = r * w + u
                continue
            i = env[k]  # the first parabola no farther than the next, walking on from the previous column's
            dr, dc = row[i] - r, i - u
            best = dr * dr + dc * dc
            while k < top:
                i = env[k + 1]
                dr, dc = row[i] - r, i - u
                d = dr * dr + dc * dc
                if best <= d:
                    break
                best = d
                k += 1
            i = env[k]
            out[r, u] = row[i] * w + i


@_njit
def _row_envelope(row: np.ndarray, r: int, env: np.ndarray) -> int:
    """:func:`nearest`'s row pass: into ``env`` the columns of the lower envelope of the parabolas
    ``(u - c)^2 + (r - row[c])^2`` of the columns ``c`` with a nearest row (``row[c] >= 0``), left to right, a
    parabola dropped when its predecessor and successor leave it nowhere least (scipy's test, in whole numbers);
    the last entry's index (-1: no column has one). Shared with :func:`occlusion_window`."""
    top = -1
    for u in range(len(row)):
        if row[u] < 0:
            continue
        dw = row[u] - r
        wr = dw * dw
        while top >= 1:
            i1, i0 = env[top], env[top - 1]
            a, b = i1 - i0, u - i1
            c = a + b
            d0, d1 = row[i0] - r, row[i1] - r
            if c * (d1 * d1) - b * (d0 * d0) - a * wr - a * b * c <= 0:
                break
            top -= 1
        top += 1
        env[top] = u
    return top


@_njit
def taxicab_within(mask: np.ndarray, reach: int, out: np.ndarray) -> None:
    """``ndimage.distance_transform_cdt(~mask, metric="taxicab") <= reach`` (``mask`` (h, w) not empty) into ``out``
    (h, w) bool: the pixels at most ``reach`` steps along rows and columns from a pixel of ``mask``, by the two
    sweeps of the city-block chamfer (exact for this metric), in whole numbers."""
    h, w = mask.shape
    big = h + w
    d = np.empty((h, w), np.int64)
    for r in range(h):
        for c in range(w):
            v = 0 if mask[r, c] else big
            if r > 0 and d[r - 1, c] + 1 < v:
                v = d[r - 1, c] + 1
            if c > 0 and d[r, c - 1] + 1 < v:
                v = d[r, c - 1] + 1
            d[r, c] = v
    for r in range(h - 1, -1, -1):
        for c in range(w - 1, -1, -1):
            v = d[r, c]
            if r + 1 < h and d[r + 1, c] + 1 < v:
                v = d[r + 1, c] + 1
            if c + 1 < w and d[r, c + 1] + 1 < v:
                v = d[r, c + 1] + 1
            d[r, c] = v
            out[r, c] = v <= reach


@_njit
def colour_features(color: np.ndarray, where: np.ndarray) -> np.ndarray:
    """:func:`symfruit.core.surface.colour_trim`'s features (n, 3) of the pixels ``where`` (h, w) bool of ``color``
    (h, w, 3) uint8, in the pixels' order: chromaticity ``r / t``, ``g / t`` and brightness ``0.25 t / 765`` with
    ``t = r + g + b + 1``, each operation the twin's in its order (the same values to the bit)."""
    h, w = where.shape
    n = 0
    for r in range(h):
        for c in range(w):
            n += where[r, c]
    out = np.empty((n, 3))
    i = 0
    for r in range(h):
        for c in range(w):
            if where[r, c]:
                red, green, blue = float(color[r, c, 0]), float(color[r, c, 1]), float(color[r, c, 2])
                total = red + green + blue + 1.0
                out[i, 0] = red / total
                out[i, 1] = green / total
                out[i, 2] = 0.25 * total / (3 * 255.0)
                i += 1
    return out


@_njit_inlined
def _nearest_centre(x: np.ndarray, i: int, c: np.ndarray) -> tuple[int, float]:
    """The first centre of ``c`` (k, 3) nearest row ``i`` of ``x``, and its squared distance (the twin's terms in
    their order)."""
    best, least = 0, np.inf
    for j in range(c.shape[0]):
        d0, d1, d2 = x[i, 0] - c[j, 0], x[i, 1] - c[j, 1], x[i, 2] - c[j, 2]
        d = d0 * d0 + d1 * d1 + d2 * d2
        if d < least or j == 0:
            best, least = j, d
    return best, least


@_njit
def kmeans(x: np.ndarray, c: np.ndarray, iterations: int) -> np.ndarray:
    """:func:`symfruit.core.surface.colour_trim`'s summary: up to ``iterations`` rounds of k-means of the rows of
    ``x`` (n, 3) from the centres ``c`` (k, 3), stopped when the labels repeat; the new centres (k, 3). Each row's
    label the first nearest centre (``np.argmin``), each centre the mean of its rows added in order (the twin's
    ``bincount``), a centre without rows kept: the twin's values to the bit."""
    n, k = x.shape[0], c.shape[0]
    c = c.copy()
    label = np.empty(n, np.int64)
    last = np.empty(n, np.int64)
    count = np.empty(k, np.int64)
    total = np.empty((k, 3))
    for it in range(iterations):
        same = it > 0
        for i in range(n):
            label[i] = _nearest_centre(x, i, c)[0]
            same = same and label[i] == last[i]
        if same:
            break
        last[:] = label
        count[:] = 0
        total[:] = 0.0
        for i in range(n):
            count[label[i]] += 1
            for a in range(3):
                total[label[i], a] += x[i, a]
        for j in range(k):
            if count[j] > 0:
                for a in range(3):
                    c[j, a] = total[j, a] / count[j]
    return c


@_njit
def nearer_fruit(x: np.ndarray, fruit: np.ndarray, ground: np.ndarray, margin: float) -> np.ndarray:
    """(n,) bool: ``margin`` times each row of ``x``'s (n, 3) least squared distance to the centres ``fruit`` is at
    most its least to the centres ``ground`` (:func:`symfruit.core.surface.colour_trim`'s test; the same values)."""
    n = x.shape[0]
    out = np.empty(n, np.bool_)
    for i in range(n):
        out[i] = margin * _nearest_centre(x, i, fruit)[1] <= _nearest_centre(x, i, ground)[1]
    return out


@_njit
def least_median(image: np.ndarray, rows: np.ndarray, cols: np.ndarray, size: int) -> int:
    """``np.argmin(median_at(image, rows, cols, size=size))`` (:func:`symfruit.core.surface.median_at`; ``image``
    (h, w) without NaN, at least one pixel): the first of the pixels ``(rows, cols)`` whose ``size`` x ``size``
    median (odd ``size``, edges repeated) is least. A pixel is passed over without its median when fewer than half
    of its window's values lie below the least median so far (its median is then no less: not the first least);
    the others' medians by an insertion sort, the same order statistic as the twin's partition."""
    return _least_median_of(image, np.ones((1, 1), np.bool_), False, rows, cols, rows.shape[0], size)


@_njit
def _least_median_of(
    image: np.ndarray, near: np.ndarray, masked: bool, rows: np.ndarray, cols: np.ndarray, n: int, size: int,
) -> int:  # fmt: skip
    """:func:`least_median`'s pass over the first ``n`` pixels ``(rows, cols)`` (in raster order, or any order: the
    counts below are made again wherever the row changes); with ``masked``, a window's pixel outside ``near`` ((h, w)
    bool) counts as +inf (:func:`surface_apex`'s depth where near).

    Since issue 19's nineteenth round the values the windows read are copied once, edges repeated and +inf where not
    ``near``, into an array over the pixels' box grown by the windows' half size, and a window's count of values
    at or below the least is the sum of ``size`` column counts, each column's values in the window's rows, counted
    once per row of pixels and again after the least falls (instead of reading each window's values).

    Since stop 60 (speeds60) the pass starts from the median of the pixel whose own value is least (the first of
    them): a near-least median from the start, so the least rarely falls and a row's counts are the last row's with
    one row taken off and one added. A pixel takes the least from the one holding it where its median is smaller, or
    equal and it comes first; a window with at most ``size * size // 2`` values at or below the least has a median
    above it and is passed over. Every median at or below the least is taken, so the pixel found is the first of the
    least median, the same pixel as the pass from the first pixel."""
    h, w = image.shape
    half = size // 2
    middle = size * size // 2
    if n == 0:
        return -1
    rmin, rmax, cmin, cmax = rows[0], rows[0], cols[0], cols[0]
    for i in range(n):
        rmin, rmax = min(rmin, rows[i]), max(rmax, rows[i])
        cmin, cmax = min(cmin, cols[i]), max(cmax, cols[i])
    vh, vw = rmax - rmin + size, cmax - cmin + size
    vals = np.empty((vh, vw))
    for a in range(vh):
        rr = min(max(rmin - half + a, 0), h - 1)
        for b in range(vw):
            cc = min(max(cmin - half + b, 0), w - 1)
            vals[a, b] = image[rr, cc] if not masked or near[rr, cc] else np.inf
    window = np.empty(size * size)
    seed = 0  # the first pixel whose own value is least
    lowest = np.inf
    for i in range(n):
        v = vals[rows[i] - rmin + half, cols[i] - cmin + half]
        if v < lowest:
            lowest, seed = v, i
    best, least = seed, _window_median(vals, rows[seed] - rmin, cols[seed] - cmin, size, window)
    counts = np.zeros(vw, np.int64)  # per column of ``vals``: its values at or below ``least`` in the window rows
    counted = -1  # the window rows ``counts`` holds (their first row in ``vals``); -1: none, or the least fell
    for i in range(n):
        if i == seed:
            continue
        r0, c0 = rows[i] - rmin, cols[i] - cmin  # the window's first row and column in ``vals``
        if counted != r0:
            if counted >= 0 and r0 == counted + 1:  # one row on: the row left taken off, the row entered added
                for b in range(vw):
                    counts[b] += np.int64(vals[r0 + size - 1, b] <= least) - np.int64(vals[counted, b] <= least)
            else:
                counts[:] = 0
                for a in range(r0, r0 + size):
                    for b in range(vw):
                        counts[b] += vals[a, b] <= least
            counted = r0
        below = 0
        for b in range(c0, c0 + size):
            below += counts[b]
        if below <= middle:
            continue  # at most ``middle`` values at or below the least: the median is above it
        m = _window_median(vals, r0, c0, size, window)
        if m < least or (m == least and i < best):
            best, least = i, m
            counted = -1
    return best


@_njit_inlined
def _window_median(vals: np.ndarray, r0: int, c0: int, size: int, window: np.ndarray) -> float:
    """The median of the ``size`` x ``size`` values of ``vals`` from row ``r0``, column ``c0`` (``window`` (size *
    size,) their sorted copy, by insertion: :func:`_least_median_of`'s)."""
    k = 0
    for a in range(size):
        for b in range(size):
            window[k] = vals[r0 + a, c0 + b]
            k += 1
    for a in range(1, k):
        v = window[a]
        b = a
        while b > 0 and window[b - 1] > v:
            window[b] = window[b - 1]
            b -= 1
        window[b] = v
    return window[size * size // 2]


@_njit_inlined
def _distance_order(d2: np.ndarray, n: int, top: int) -> np.ndarray:
    """The indices of ``d2`` (n,) in order of distance, ties by position (a stable counting sort; ``top`` its largest
    value): :func:`_counting_orders`' first order, and :func:`monotone_at`'s walk by distance alone."""
    count = np.zeros(top + 2, np.int64)
    for i in range(n):
        count[d2[i] + 1] += 1
    for v in range(top + 1):
        count[v + 1] += count[v]
    by_d2 = np.empty(n, np.int64)
    for i in range(n):
        by_d2[count[d2[i]]] = i
        count[d2[i]] += 1
    return by_d2


@_njit_inlined
def _counting_orders(d2: np.ndarray, sector: np.ndarray, n: int, top: int, bins: int) -> tuple[np.ndarray, np.ndarray]:
    """The two stable counting sorts of :func:`monotone` and :func:`monotone_at`: the indices of ``d2`` (n,) in order
    of distance (ties by position; ``top`` its largest value), and each of the ``bins`` sectors' first place when
    ordered by ``sector`` (n,) (``start`` (bins + 1,), the places still to be taken as the caller fills them)."""
    by_d2 = _distance_order(d2, n, top)
    start = np.zeros(bins + 1, np.int64)
    for i in range(n):
        start[sector[i] + 1] += 1
    for s in range(bins):
        start[s + 1] += start[s]
    return by_d2, start


@_njit
def monotone(
    depth: np.ndarray, rows: np.ndarray, cols: np.ndarray, sector: np.ndarray, d2: np.ndarray, bins: int,
    tolerance: float, out: np.ndarray,
) -> None:  # fmt: skip
    """:func:`symfruit.core.surface.monotone_region` after its sectors: the pixels ``(rows, cols)`` (n,) of ``depth``
    (h, w), in sectors ``sector`` (n,) of ``bins`` at squared distances ``d2`` (n,) from the apex, marked in ``out``
    (h, w) bool where their sector's depth has not yet fallen more than ``tolerance`` below its running maximum.
    The twin's order (by sector, then distance, then position: two stable counting sorts) and its arithmetic (the
    running maximum of ``z + offset`` less the offset, each sector offset above the ones before): its pixels."""
    n = rows.shape[0]
    top = 0
    for i in range(n):
        top = max(top, d2[i])
    by_d2, start = _counting_orders(d2, sector, n, top, bins)
    order = np.empty(n, np.int64)
    for j in range(n):
        i = by_d2[j]
        order[start[sector[i]]] = i
        start[sector[i]] += 1
    z = np.empty(n)
    biggest = 0.0
    for j in range(n):
        i = order[j]
        z[j] = float(depth[rows[i], cols[i]])
        biggest = max(biggest, abs(z[j]))
    scale = 2.0 * (biggest + tolerance + 1.0)
    running = -np.inf
    last = -1
    fallen = False
    for j in range(n):
        i = order[j]
        s = sector[i]
        if s != last:
            last, fallen = s, False
        offset = s * scale
        running = max(running, z[j] + offset)
        if z[j] < (running - offset) - tolerance:
            fallen = True
        if not fallen:
            out[rows[i], cols[i]] = True


@_njit
def outline_costs(
    ranks: np.ndarray, values: np.ndarray, at: np.ndarray, shifts: np.ndarray, width: int, keep: int, band: float
) -> np.ndarray:  # fmt: skip
    """(k,) :meth:`symfruit.core.surface._Outline.cost` with ``exact=False`` of each shift (k, 2) ``(dv, du)``: the
    outline points' flat indices ``at`` (n,) into the padded map's ranks ``ranks`` (each distance's place among the
    map's distinct distances, :meth:`~symfruit.core.surface._Outline.ranks`) moved back by the shift, counted per
    rank (a row's ranks span a few hundred places); the median (np.median's two middle places, walked to on the
    counts) of their values ``values`` (ascending, one per rank), its band (clipped to 0 .. ``band``) and the
    mean of the ``keep`` deviations from it nearest the band, taken a rank at a time from the band outward, the
    nearer side first (:meth:`~symfruit.core.surface._Outline._nearest_mean`'s run of sorted values, whose
    deviations are the ``keep`` smallest). The twin's medians and bands and the same deviations, summed as count
    times deviation per rank: within ``keep`` units in the last place of the twin's fast costs, as those are of
    the exact ones (issue 19, fifteenth round; the twelfth round's kernel sorted each row's keys by counting and
    summed the run value by value, 1.5-2x slower)."""
    k = shifts.shape[0]
    out = np.empty(k)
    count = np.zeros(values.shape[0], np.int64)
    row = np.empty(at.shape[0], np.int64)  # the row's ranks, to clear their counts (not the whole span) after it
    for s in range(k):
        out[s] = _fast_cost(ranks, values, at, shifts[s, 0] * width + shifts[s, 1], keep, band, count, row)
    return out


@_njit
def key_ranks(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The places of whole-number ``keys`` (n,) among their distinct values (int32) and the value of each place,
    ``sign * sqrt(|key|)`` ascending: :meth:`symfruit.core.surface._Outline.ranks`' twin, marking the keys present
    and counting them up in two passes (the same places and values)."""
    n = keys.shape[0]
    low, top = np.int64(0), np.int64(0)
    if n:
        low, top = np.int64(keys[0]), np.int64(keys[0])
    for i in range(n):
        low, top = min(low, np.int64(keys[i])), max(top, np.int64(keys[i]))
    place = np.zeros(top - low + 1, np.int64)
    for i in range(n):
        place[np.int64(keys[i]) - low] = 1
    m = 0
    for v in range(top - low + 1):
        if place[v]:
            place[v] = m
            m += 1
        else:
            place[v] = -1
    values = np.empty(m)
    ranks = np.empty(n, np.int32)
    for v in range(top - low + 1):
        if place[v] >= 0:
            whole = float(v + low)
            values[place[v]] = np.sign(whole) * np.sqrt(abs(whole))
    for i in range(n):
        ranks[i] = place[np.int64(keys[i]) - low]
    return ranks, values


@_njit
def _median_of(x: np.ndarray) -> float:
    """np.median of ``x`` (n >= 1, no NaN), reordering it: :func:`select` at the middle place, the place below it
    (even ``n``) the largest before it, their sum halved (:func:`symfruit.core.points.median`'s value bit for bit)."""
    h = x.shape[0] // 2
    select(x, h)
    return _selected_median(x, h)


@_njit
def _selected_median(x: np.ndarray, h: int) -> float:
    """The median of ``x`` (n,) once a selection has put its ``h = n // 2``-th smallest value at ``x[h]`` and the
    smaller ones before it: that value, or (even ``n``) its sum with the largest before it halved."""
    if x.shape[0] % 2:
        return x[h]
    below = x[0]
    for i in range(1, h):
        below = max(below, x[i])
    return (below + x[h]) / 2.0


@_njit
def depth_noise(depth: np.ndarray, mask: np.ndarray) -> tuple[int, float]:
    """:func:`symfruit.core.surface.depth_noise`'s differences and their median absolute deviation: how many
    differences it takes (``n``) and the deviation (NaN when ``n < 10`` or a difference is NaN). The twin's
    differences (the same subtractions, the moved ones where at least 20 are) and its medians (order statistics, the
    middle two's sum halved): its deviation bit for bit."""
    h, w = depth.shape
    diff = np.empty(max(h * (w - 1), 0))
    n = 0
    moved = 0
    for r in range(h):
        for c in range(w - 1):
            a, b = depth[r, c + 1], depth[r, c]
            if mask[r, c + 1] and mask[r, c] and a > 0 and b > 0:
                diff[n] = a - b
                moved += diff[n] != 0
                n += 1
    if moved >= 20:
        kept = 0
        for i in range(n):
            if diff[i] != 0:
                diff[kept] = diff[i]
                kept += 1
        n = kept
    if n < 10:
        return n, np.nan
    x = diff[:n]
    for i in range(n):
        if np.isnan(x[i]):
            return n, np.nan
    return n, deviation_median(x)  # the same medians without branches (stop 49)


@_njit
def _flood(image: np.ndarray, out: np.ndarray, stack: np.ndarray, top: int) -> None:
    """Mark in ``out`` every pixel of ``image`` 4-connected through ``image`` to the marked pixels on ``stack`` (the
    first ``top`` of it, flat indices)."""
    h, w = image.shape
    while top > 0:
        top -= 1
        r, c = divmod(stack[top], w)
        for rr, cc in ((r - 1, c), (r + 1, c), (r, c - 1), (r, c + 1)):
            if 0 <= rr < h and 0 <= cc < w and image[rr, cc] and not out[rr, cc]:
                out[rr, cc] = True
                stack[top] = rr * w + cc
                top += 1


@_njit
def connected(image: np.ndarray, seeds: np.ndarray, out: np.ndarray) -> None:
    """``out`` (h, w) bool: the pixels of the pieces of ``image`` (h, w) bool (4-connected, as ``ndimage.label``'s
    default) holding a pixel of ``seeds`` (h, w) bool, by a flood fill: the twins' ``label`` and look-up, the same
    pixels."""
    h, w = image.shape
    stack = np.empty(h * w, np.int64)
    top = 0
    for r in range(h):
        for c in range(w):
            out[r, c] = image[r, c] and seeds[r, c]
            if out[r, c]:
                stack[top] = r * w + c
                top += 1
    _flood(image, out, stack, top)


@_njit
def filled(mask: np.ndarray, out: np.ndarray) -> None:
    """``out`` (h, w) bool, not sharing memory with ``mask``: ``mask`` (h, w) bool with its holes filled (the
    4-connected pieces of its background not reaching the array's edge, :func:`symfruit.core.raster.fill_holes`'
    labelling): the same pixels.

    Since issue 19's stop 48 (compspeed48) by each row's span from its first to its last mask pixel: the background
    before and after the span reaches the edge along the row, so ``out`` starts as the spans, and only the background
    inside a span is flooded (set false again), from those pixels of it on the first or last row or beside a pixel
    outside the span of the row above or below (a span's background has mask pixels at both of its row's ends, so it
    leaves its span only upwards or downwards). The flood of the whole background from a ring around the array
    (the eighteenth round's) walked every pixel outside the mask: 57 against 20 us on a dense view's window."""
    h, w = mask.shape
    first = np.empty(h, np.int64)
    last = np.empty(h, np.int64)
    for r in range(h):
        row = mask[r]
        o = out[r]
        f = 0
        while f < w and not row[f]:
            f += 1
        e = w - 1
        while e > f and not row[e]:
            e -= 1
        if f == w:  # no mask pixel in the row: an empty span
            e = -1
        first[r], last[r] = f, e
        for c in range(w):
            o[c] = f <= c and c <= e
    stack = np.empty(h * w, np.int64)
    top = 0
    for r in range(h):
        for c in range(first[r] + 1, last[r]):
            if not mask[r, c] and (r == 0 or r == h - 1 or not out[r - 1, c] or not out[r + 1, c]):
                out[r, c] = False
                stack[top] = r * w + c
                top += 1
    while top > 0:
        top -= 1
        i = stack[top]
        r, c = i // w, i % w
        if r > 0 and out[r - 1, c] and not mask[r - 1, c]:
            out[r - 1, c] = False
            stack[top] = i - w
            top += 1
        if r < h - 1 and out[r + 1, c] and not mask[r + 1, c]:
            out[r + 1, c] = False
            stack[top] = i + w
            top += 1
        if c > 0 and out[r, c - 1] and not mask[r, c - 1]:
            out[r, c - 1] = False
            stack[top] = i - 1
            top += 1
        if c < w - 1 and out[r, c + 1] and not mask[r, c + 1]:
            out[r, c + 1] = False
            stack[top] = i + 1
            top += 1


@_njit
def _least_vector(a: np.ndarray, v: np.ndarray) -> int:
    """The eigenvectors of the symmetric ``a`` (3, 3) into the columns of ``v`` (3, 3) by cyclic Jacobi rotations
    (``a`` left diagonal, its eigenvalues there); returns the column of the least eigenvalue. Orthogonal to
    rounding however close the eigenvalues, as LAPACK's are (a closed form is not)."""
    for i in range(3):
        for j in range(3):
            v[i, j] = 1.0 if i == j else 0.0
    for _ in range(32):
        off = a[0, 1] * a[0, 1] + a[0, 2] * a[0, 2] + a[1, 2] * a[1, 2]
        if off <= 1e-36 * (a[0, 0] * a[0, 0] + a[1, 1] * a[1, 1] + a[2, 2] * a[2, 2]):
            break
        for p, q in ((0, 1), (0, 2), (1, 2)):
            apq = a[p, q]
            if apq == 0.0:
                continue
            theta = (a[q, q] - a[p, p]) / (2.0 * apq)
            t = 1.0 / (abs(theta) + math.sqrt(theta * theta + 1.0))
            if theta < 0.0:
                t = -t
            c = 1.0 / math.sqrt(t * t + 1.0)
            s = t * c
            for k in range(3):  # a J
                akp, akq = a[k, p], a[k, q]
                a[k, p] = c * akp - s * akq
                a[k, q] = s * akp + c * akq
            for k in range(3):  # J^T a
                apk, aqk = a[p, k], a[q, k]
                a[p, k] = c * apk - s * aqk
                a[q, k] = s * apk + c * aqk
            for k in range(3):  # v J
                vkp, vkq = v[k, p], v[k, q]
                v[k, p] = c * vkp - s * vkq
                v[k, q] = s * vkp + c * vkq
    least = 0
    if a[1, 1] < a[least, least]:
        least = 1
    if a[2, 2] < a[least, least]:
        least = 2
    return least


@_njit
def contour_pixels(
    points: np.ndarray, depth_px: np.ndarray, fx: float, fy: float, cx: float, cy: float, u0: int, v0: int, h: int,
    w: int, count: int, half: int,
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.core.agreement._contour_pixels`: ``(uv (m, 2), contour (m,) bool)`` of up to ``count`` edge
    points (within 1.5 px of the region's edge, ``depth_px``) of a cloud with about a point per pixel: whether the
    plane of the points on the ``(2 half + 1)^2`` pixels around each (at least 6 of them; a pixel met twice holds
    the later point) is within 60 degrees of containing its ray. The same points and pixels as the twin (the
    projection's arithmetic, rounded half to even); the covariances summed in another order and their least
    eigenvector by Jacobi rotations instead of LAPACK's ``eigh``, so a normal agrees to rounding, not to the bit."""
    n = points.shape[0]
    near = np.empty(n, np.int64)
    m = 0
    for i in range(n):
        if depth_px[i] <= half + 1.5:
            near[m] = i
            m += 1
    big = 9.223372036854775808e18  # 2^63: numpy's integer conversion as in inside_px
    least = np.int64(-9223372036854775808)
    us = np.empty(m)
    vs = np.empty(m)
    rows = np.empty(m, np.int64)
    cols = np.empty(m, np.int64)
    ok = np.empty(m, np.bool_)
    edge = np.empty(m, np.int64)
    n_edge = 0
    for k in range(m):
        i = near[k]
        inv_z = 1.0 / points[i, 2]
        u = fx * points[i, 0] * inv_z + cx
        v = fy * points[i, 1] * inv_z + cy
        us[k], vs[k] = u, v
        ru, rv = np.rint(u), np.rint(v)
        col = (np.int64(ru) if -big <= ru < big else least) - np.int64(u0) + half
        row = (np.int64(rv) if -big <= rv < big else least) - np.int64(v0) + half
        cols[k], rows[k] = col, row
        ok[k] = half <= col < w + half and half <= row < h + half
        if depth_px[i] <= 1.5 and ok[k]:
            edge[n_edge] = k
            n_edge += 1
    if n_edge < 3:
        return np.empty((0, 2)), np.empty(0, np.bool_)
    step = max(1, n_edge // count)
    width = w + 2 * half
    grid = np.full((h + 2 * half) * width, -1, np.int64)
    for k in range(m):
        if ok[k]:
            grid[rows[k] * width + cols[k]] = near[k]  # the later point keeps the pixel, as the twin's assignment
    n_out = (n_edge + step - 1) // step
    uv = np.empty((n_out, 2))
    contour = np.empty(n_out, np.bool_)
    nb = np.empty((2 * half + 1) * (2 * half + 1), np.int64)
    a = np.empty((3, 3))
    vec = np.empty((3, 3))
    kept = 0
    for e in range(0, n_edge, step):
        k = edge[e]
        cnt = 0
        for dr in range(-half, half + 1):
            for dc in range(-half, half + 1):
                j = grid[(rows[k] + dr) * width + cols[k] + dc]
                if j >= 0:
                    nb[cnt] = j
                    cnt += 1
        if cnt < 6:
            continue
        _scatter(points, nb, cnt, a)
        col = _least_vector(a, vec)
        i = near[k]
        x, y, z = points[i, 0], points[i, 1], points[i, 2]
        r = math.sqrt(x * x + y * y + z * z)
        uv[kept, 0], uv[kept, 1] = us[k], vs[k]
        contour[kept] = abs(vec[0, col] * (x / r) + vec[1, col] * (y / r) + vec[2, col] * (z / r)) < 0.5
        kept += 1
    return uv[:kept], contour[:kept]


@_njit
def band_pixels(dist: np.ndarray, bands: np.ndarray, n_band: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`symfruit.core.agreement._band_pixels`: ``(rc (m, 2), sizes (k,))``, each band's pixels of ``dist``
    (h, w) within half a pixel of ``bands[i]`` in row-major order, more than ``n_band`` of them thinned to the twin's
    ``np.linspace(0, count - 1, n_band)`` picks (its arithmetic: ``i * step``, the last the last pixel, truncated):
    the same pixels."""
    h, w = dist.shape
    k = bands.shape[0]
    found = np.empty(h * w, np.int64)
    out = np.empty((k * min(h * w, max(n_band, 0)), 2), np.int64)
    sizes = np.zeros(k, np.int64)
    m = 0
    for b in range(k):
        lo, hi = bands[b] - 0.5, bands[b] + 0.5
        count = 0
        for r in range(h):
            for c in range(w):
                d = dist[r, c]
                if d > lo and d <= hi:
                    found[count] = r * w + c
                    count += 1
        take = count if count <= n_band else n_band
        if count > n_band and n_band > 1:
            step = (count - 1) / (n_band - 1)
        for i in range(take):
            if count <= n_band:
                j = i
            elif i == n_band - 1 and n_band > 1:
                j = count - 1  # linspace's endpoint is ``stop`` itself
            elif n_band == 1:
                j = 0
            else:
                j = np.int64(i * step)
            out[m, 0] = found[j] // w
            out[m, 1] = found[j] % w
            m += 1
        sizes[b] = take
    return out[:m], sizes


@_njit
def close_square(hit: np.ndarray, half: int, out: np.ndarray) -> None:
    """``out`` (h, w) bool: ``hit`` (h, w) bool closed by the ``2 half + 1`` square, as
    :func:`symfruit.core.raster._closed_mask`'s two box means (a dilation, outside the array false, then an erosion
    with the array's edge pixels repeated beyond it: all of the square's pixels within the array), ``hit`` kept: the
    same pixels. Since issue 19's stop 48 (compspeed48) each step by :func:`_square_any` (the dilation: a true pixel
    within the clipped square; the erosion: no false dilated pixel there) where running counts along the rows and
    down the columns kept (h, w) arrays of them: 95 against 49 us on a dense view's 157 x 167 window."""
    h, w = hit.shape
    grown = np.empty((h, w), np.bool_)
    _square_any(hit, half, True, grown)
    _square_any(grown, half, False, out)  # a false dilated pixel within the square
    for r in range(h):
        for c in range(w):
            out[r, c] = not out[r, c] or hit[r, c]


@_njit
def explain_quadric(
    centre: np.ndarray,
    shape: np.ndarray,
    rays: np.ndarray,
    z0: float,
    z1: float,
    depth: np.ndarray,
    keep: int,
    in_starts: np.ndarray,
    in_sizes: np.ndarray,
    out_starts: np.ndarray,
    out_w: np.ndarray,
    out_wsum: np.ndarray,
    seen: np.ndarray,
    free: float,
) -> tuple[float, float, float]:
    """:func:`symfruit.core.agreement.explain` of a :class:`~symfruit.core.agreement.Quadric` (``centre`` (3,),
    ``shape`` (3, 3)): ``(depth RMS, inside, outside)``, each ray met in closed form (``intersect_quadric``'s
    roots) in one pass. ``rays`` (m, 3): the depth rays (``depth`` (n,), their seen depths), the inside bands' and
    the outside bands' rays one after the other (:class:`~symfruit.core.agreement._Bands`); ``keep`` the trimmed
    RMS's count (at least 1, at most n); each band's first ray and size (``in_starts``, ``in_sizes``; the outside
    bands' sizes from their starts), the outside rays' weights, each outside band's weight and the outside rays'
    seen depths (``seen``: NaN where none; empty without). The twin's arithmetic but for the order of the trimmed RMS's
    sum and of the products making each ray's quadratic (numpy's ``einsum`` and BLAS there): the depth RMS within
    rounding of the twin's (grazing rays' roots the most), the band shares, counts of whole numbers (the outside
    weights are 0 or 1), equal."""
    m = rays.shape[0]
    s = np.empty(3)
    for i in range(3):
        s[i] = shape[i, 0] * centre[0] + shape[i, 1] * centre[1] + shape[i, 2] * centre[2]
    c = centre[0] * s[0] + centre[1] * s[1] + centre[2] * s[2] - 1.0
    hit = np.empty(m, np.bool_)
    at = np.empty(m)
    # the rays' columns, the shape's nine numbers named: each ray's quadratic the same nine terms added in the same
    # order, in a loop the processor's vector instructions run (issue 19, stop 60: 0.09 against 0.06 ms a benchmark
    # frame replayed)
    r0, r1, r2 = _columns3(rays)
    s00, s01, s02 = shape[0, 0], shape[0, 1], shape[0, 2]
    s10, s11, s12 = shape[1, 0], shape[1, 1], shape[1, 2]
    s20, s21, s22 = shape[2, 0], shape[2, 1], shape[2, 2]
    for k in range(m):
        x, y, z = r0[k], r1[k], r2[k]
        a = 0.0
        a += x * s00 * x
        a += x * s01 * y
        a += x * s02 * z
        a += y * s10 * x
        a += y * s11 * y
        a += y * s12 * z
        a += z * s20 * x
        a += z * s21 * y
        a += z * s22 * z
        b = x * s[0] + y * s[1] + z * s[2]
        disc = b * b - a * c
        root = math.sqrt(disc) if disc > 0.0 else 0.0
        near, far = (b - root) / a, (b + root) / a
        hit[k] = disc > 0.0 and near < z1 and far > z0
        at[k] = max(near, z0) if hit[k] else np.nan
    return agreement(hit, at, z0, z1, depth, keep, in_starts, in_sizes, out_starts, out_w, out_wsum, seen, free)


@_njit
def agreement(
    hit: np.ndarray,
    at: np.ndarray,
    z0: float,
    z1: float,
    depth: np.ndarray,
    keep: int,
    in_starts: np.ndarray,
    in_sizes: np.ndarray,
    out_starts: np.ndarray,
    out_w: np.ndarray,
    out_wsum: np.ndarray,
    seen: np.ndarray,
    free: float,
) -> tuple[float, float, float]:
    """:func:`symfruit.core.agreement.explain`'s measures from where each ray meets the candidate (``hit`` (m,)
    bool, ``at`` (m,) its entry depth): ``(depth RMS, inside, outside)``, the rays and bands as
    :func:`explain_quadric`'s (which ends here; the solids of revolution's marched rays since issue 19's
    sixteenth round). The trimmed RMS by :func:`smallest_mean` (within rounding of the twin's partition and
    mean), the band shares from counts of whole numbers (the outside weights are 0 or 1): the twin's."""
    n = depth.shape[0]
    m = hit.shape[0]
    r2 = np.empty(n)
    for k in range(n):
        r = depth[k] - at[k] if hit[k] else z1 - z0
        r2[k] = r * r
    rms = math.sqrt(smallest_mean(r2, keep, np.empty(n), np.empty(n)))
    n_bands = in_starts.shape[0]
    inside = 0.0
    for j in range(n_bands):
        size = in_sizes[j]
        if size > 0:
            count = 0
            for k in range(n + in_starts[j], n + in_starts[j] + size):
                count += hit[k]
            inside += 1.0 - count / size
    inside = inside / n_bands if n_bands else np.nan
    base = n
    for j in range(n_bands):
        base += in_sizes[j]
    n_out = m - base
    k_bands = out_starts.shape[0]
    outside = 0.0
    for j in range(k_bands):
        start = out_starts[j]
        stop = out_starts[j + 1] if j + 1 < k_bands else n_out
        if stop > start and out_wsum[j] > 0:
            wrong = 0.0
            for k in range(start, stop):
                if seen.shape[0] and math.isfinite(seen[k]):  # free space in front of an occluder
                    wrong += 1.0 if hit[base + k] and at[base + k] < seen[k] - free else 0.0
                elif hit[base + k]:
                    wrong += out_w[k]
            outside += wrong / out_wsum[j]
    outside = outside / k_bands if k_bands else np.nan
    return rms, inside, outside


@_njit
def outline_cracks(mask: np.ndarray, u0: int, v0: int) -> np.ndarray:
    """:func:`symfruit.core.raster.outline_cracks` of the region ``mask`` (h, w) bool whose top-left pixel is ``(u0,
    v0)``: (m, 2) the midpoints of the pixel edges between a region pixel and a 4-neighbour outside it (beyond the
    window: outside), those above their pixel, then below, left and right, each row-major, as the twin's four
    ``np.nonzero`` passes give them; half-integers, the same values. Two passes: the counts, then the points. Since
    issue 19's stop 48 (compspeed48) the first pass keeps each pixel's four tests as bits of a code, without a
    branch, and the second reads the codes (no test again for every region pixel): 66 against 38 us on a dense
    view's window, the same points."""
    h, w = mask.shape
    code = np.empty((h, w), np.uint8)
    n0 = n1 = n2 = n3 = 0
    for r in range(h):
        row = mask[r]
        up = mask[r - 1] if r > 0 else row
        down = mask[r + 1] if r < h - 1 else row
        top, bottom = r == 0, r == h - 1
        o = code[r]
        for c in range(w):
            m = row[c]
            above = m and (top or not up[c])
            below = m and (bottom or not down[c])
            left = m and (c == 0 or not row[c - 1])
            right = m and (c == w - 1 or not row[c + 1])
            n0 += above
            n1 += below
            n2 += left
            n3 += right
            o[c] = above | (below << 1) | (left << 2) | (right << 3)
    at0, at1, at2, at3 = 0, n0, n0 + n1, n0 + n1 + n2
    out = np.empty((at3 + n3, 2))
    for r in range(h):
        o = code[r]
        for c in range(w):
            k = o[c]
            if k:
                if k & 1:
                    out[at0, 0], out[at0, 1] = c + (0.0 + u0), r + (-0.5 + v0)
                    at0 += 1
                if k & 2:
                    out[at1, 0], out[at1, 1] = c + (0.0 + u0), r + (0.5 + v0)
                    at1 += 1
                if k & 4:
                    out[at2, 0], out[at2, 1] = c + (-0.5 + u0), r + (0.0 + v0)
                    at2 += 1
                if k & 8:
                    out[at3, 0], out[at3, 1] = c + (0.5 + u0), r + (0.0 + v0)
                    at3 += 1
    return out


@_njit
def cloud_spread(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(min (3,), max (3,), scatter (3, 3))`` of the rows of ``points`` (n, 3), ``n >= 1``: the columns' least and
    greatest values (exactly :func:`symfruit.core.points.bounds`'s) and the sums of the products of the rows'
    deviations from their mean (the twin's ``centred.T @ centred``, within rounding: these sums run row by row, the
    mean's too), in two passes over the points without the centred copy. The sums run in scalars, not in the arrays
    they end in (issue 19, stop 40: the same additions in the same order, so the same values, without a store and a
    load of each sum per point: 95 against 30 us on a dense view's 14,000 points)."""
    n = points.shape[0]
    lo0, lo1, lo2 = points[0, 0], points[0, 1], points[0, 2]
    hi0, hi1, hi2 = lo0, lo1, lo2
    m0 = m1 = m2 = 0.0
    for i in range(n):
        x, y, z = points[i, 0], points[i, 1], points[i, 2]
        m0 += x
        m1 += y
        m2 += z
        if x < lo0:
            lo0 = x
        if x > hi0:
            hi0 = x
        if y < lo1:
            lo1 = y
        if y > hi1:
            hi1 = y
        if z < lo2:
            lo2 = z
        if z > hi2:
            hi2 = z
    m0 /= n
    m1 /= n
    m2 /= n
    s00 = s01 = s02 = s11 = s12 = s22 = 0.0
    for i in range(n):
        a, b, c = points[i, 0] - m0, points[i, 1] - m1, points[i, 2] - m2
        s00 += a * a
        s01 += a * b
        s02 += a * c
        s11 += b * b
        s12 += b * c
        s22 += c * c
    lo = np.empty(3)
    hi = np.empty(3)
    lo[0], lo[1], lo[2] = lo0, lo1, lo2
    hi[0], hi[1], hi[2] = hi0, hi1, hi2
    s = np.empty((3, 3))
    s[0, 0], s[0, 1], s[0, 2] = s00, s01, s02
    s[1, 0], s[1, 1], s[1, 2] = s01, s11, s12
    s[2, 0], s[2, 1], s[2, 2] = s02, s12, s22
    return lo, hi, s


@_njit
def occlusion_maps(
    depth: np.ndarray,
    mask: np.ndarray,
    own_z: np.ndarray,
    nearest: np.ndarray,
    others: np.ndarray,
    tolerance: float,
    steps: np.ndarray,
    hidden: np.ndarray,
    seen: np.ndarray,
) -> None:
    """:func:`symfruit.core.occlusion.occlusion`'s maps of one window, into ``hidden`` (h, w) bool and ``seen`` (h,
    w) float (what the camera saw, NaN: nothing): ``depth`` (h, w) the frame's depth there (metres; 0 or not
    finite: none), ``mask`` (h, w) the fruit's own pixels, ``own_z`` (h, w) its points' least depth per pixel (+inf:
    none), ``nearest`` (h, w) each pixel's flat index of its nearest point pixel (:func:`nearest`), ``others`` (h,
    w) other fruit's pixels ((0, 0): none), ``steps`` (k, 2) the offsets ``(dr, dc)`` a pixel without depth looks
    through, nearest first (``_offsets``; none: no fill). A pixel without depth, not the fruit's, takes the depth
    of its first offset with depth in the window (the twin's ``_fill``: depths as read, not as filled); a pixel is
    hidden when what was seen is nearer than the fruit's depth at its nearest point pixel plus ``tolerance``, or it
    is another fruit's and not clearly behind, never when it is the fruit's own. The twin's comparisons on the same
    values: the same maps, bit for bit."""
    h, w = mask.shape
    valid = np.empty((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            x = np.float64(depth[r, c])
            own = mask[r, c] or math.isfinite(own_z[r, c])
            ok = math.isfinite(x) and x > 0.0 and not own
            valid[r, c] = ok
            seen[r, c] = x if ok else np.nan
    k = steps.shape[0]
    flat_z = own_z.ravel()
    with_others = others.shape[0] > 0
    for r in range(h):
        for c in range(w):
            own = mask[r, c] or math.isfinite(own_z[r, c])
            x = seen[r, c]
            if not own and not valid[r, c]:
                for j in range(k):
                    rr, cc = r + steps[j, 0], c + steps[j, 1]
                    if 0 <= rr < h and 0 <= cc < w and valid[rr, cc]:
                        x = seen[rr, cc]  # a valid pixel's depth is never a filled one
                        seen[r, c] = x
                        break
            ref = flat_z[nearest[r, c]] + tolerance
            hide = False
            if not own:
                hide = x < ref or (with_others and others[r, c] and not x >= ref)
            hidden[r, c] = hide


# --- issue 19, seventeenth round: the completion ---


@_njit
def band_rays(
    dist: np.ndarray, bands: np.ndarray, n_band: int, u0: int, v0: int, fx: float, fy: float, cx: float, cy: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`symfruit.core.agreement._band_rays`: :func:`band_pixels`' pixels of ``dist`` (a window at ``u0, v0``)
    as image coordinates ``uv`` (m, 2) and their viewing rays (m, 3) ``((u - cx) / fx, (v - cy) / fy, 1)``, and the
    bands' sizes (k,): the same operations on each pixel as the twin's, so the same values."""
    rc, sizes = band_pixels(dist, bands, n_band)
    m = rc.shape[0]
    uv = np.empty((m, 2))
    rays = np.empty((m, 3))
    for i in range(m):
        u = float(rc[i, 1] + u0)
        v = float(rc[i, 0] + v0)
        uv[i, 0], uv[i, 1] = u, v
        rays[i, 0] = (u - cx) / fx
        rays[i, 1] = (v - cy) / fy
        rays[i, 2] = 1.0
    return uv, rays, sizes


@_njit
def least_eigenvalue(m: np.ndarray, a: np.ndarray) -> float:
    """The least eigenvalue of the symmetric ``m`` (3, 3) (``np.linalg.eigvalsh(m)[0]`` to rounding: LAPACK's and
    this one's differ in the last bits), by cyclic Jacobi rotations on the scratch ``a`` (3, 3) until no
    off-diagonal element is left that would change a diagonal one (Numerical Recipes' ``jacobi``: each eigenvalue
    to its own relative precision, where LAPACK's is absolute; NaN in, NaN out)."""
    for r in range(3):
        for c in range(3):
            a[r, c] = m[r, c]
    for _ in range(50):
        if a[0, 1] == 0.0 and a[0, 2] == 0.0 and a[1, 2] == 0.0:
            break
        for p, q in ((0, 1), (0, 2), (1, 2)):
            apq = a[p, q]
            if apq == 0.0:
                continue
            app, aqq = a[p, p], a[q, q]
            g = 100.0 * abs(apq)
            if abs(app) + g == abs(app) and abs(aqq) + g == abs(aqq):  # below both diagonal elements' last bit
                a[p, q] = a[q, p] = 0.0
                continue
            theta = 0.5 * (aqq - app) / apq
            if abs(theta) > 1e150:
                t = 0.5 / theta
            else:
                t = 1.0 / (abs(theta) + math.sqrt(theta * theta + 1.0))
                if theta < 0.0:
                    t = -t
            if not math.isfinite(t):  # NaN in the matrix
                return math.nan
            cs = 1.0 / math.sqrt(t * t + 1.0)
            sn = t * cs
            a[p, p] = app - t * apq
            a[q, q] = aqq + t * apq
            a[p, q] = a[q, p] = 0.0
            r = 3 - p - q  # the third index
            arp, arq = a[r, p], a[r, q]
            a[r, p] = a[p, r] = cs * arp - sn * arq
            a[r, q] = a[q, r] = sn * arp + cs * arq
    return min(a[0, 0], a[1, 1], a[2, 2])


@_njit
def noise_measures(points: np.ndarray, step: int, small: int, large: int) -> tuple[float, float]:
    """:func:`symfruit.core.fits.noise_measures`: :func:`symfruit.core.fits.surface_noise`'s ``ratio`` and ``noise``
    in one call,
    the neighbourhoods' covariances of :func:`neighbour_covariances`, their least eigenvalues by
    :func:`least_eigenvalue` (the twin's ``eigh`` and ``eigvalsh``: to rounding) and the medians of those (the
    twin's :func:`~symfruit.core.points.median`: the middle value, or the mean of the middle two; NaN where one
    is NaN)."""
    cov_small, cov_large = grid_covariances(points, step, small, large)  # stop 43: neighbour_covariances' values
    scratch = np.empty((3, 3))
    small_res, large_res = _median_root(cov_small, scratch), _median_root(cov_large, scratch)
    # the twin's Python max(small, 1e-15): the first argument unless the second is greater (NaN kept)
    return large_res / (1e-15 if 1e-15 > small_res else small_res), small_res


@_njit
def _median_root(cov: np.ndarray, scratch: np.ndarray) -> float:
    """The square root of the median of the least eigenvalues of ``cov`` (m, 3, 3) by :func:`least_eigenvalue`
    (``scratch`` (3, 3)): the middle value or the mean of the middle two, NaN where one is NaN, 0 below 0 (the
    twin's Python ``max(x, 0.0)``: the first argument unless the second is greater); :func:`noise_measures`' and
    :func:`noise_level`'s."""
    m = cov.shape[0]
    least = np.empty(m)
    for q in range(m):
        least[q] = least_eigenvalue(cov[q], scratch)
    x = np.sort(least)  # NaN last, as numpy sorts
    h = m // 2
    if m == 0 or math.isnan(x[m - 1]):
        res = math.nan
    elif m % 2:
        res = x[h]
    else:
        res = (x[h - 1] + x[h]) / 2.0
    return 0.0 if 0.0 > res else math.sqrt(res)


@_njit
def noise_level(points: np.ndarray, step: int, small: int, large: int) -> float:
    """``noise_measures(points, step, small, large)[1]`` (:func:`symfruit.core.fits.noise_level`), the same value to
    the bit, without the ``large`` neighbourhoods (issue 19, stop 48, compspeed48): each query's ``small`` nearest
    are the first ``small`` in the order of distance, ties by index, of any set of points holding them, so
    :func:`grid_covariances` asked for ``small`` of them (its grid sized for ``small``, its search bounded by the
    ``small``-th distance) finds the same points in the same order, and their covariances and least eigenvalues
    are the same operations on them. A coordinate that is not finite (NaN distances, whose order is the brute
    force's insertion's) goes to :func:`noise_measures` whole."""
    n = points.shape[0]
    for i in range(n):
        if not (math.isfinite(points[i, 0]) and math.isfinite(points[i, 1]) and math.isfinite(points[i, 2])):
            return noise_measures(points, step, small, large)[1]
    cov_small, _ = grid_covariances(points, step, small, small)
    return _median_root(cov_small, np.empty((3, 3)))


@_njit
def outline_uv(mask: np.ndarray, count: int, u0: int, v0: int) -> np.ndarray:
    """:func:`symfruit.core.agreement._outline_uv`: the image coordinates (m, 2) of every ``max(1, k // (2 count))``-th
    of the ``k`` outline pixels of ``mask`` (h, w) bool (a mask pixel with a 4-neighbour outside it or beyond the
    array: ``mask & ~interior(mask)``), row-major from the first, at ``(col + u0, row + v0)``: the same pixels."""
    h, w = mask.shape
    rows = np.empty(h * w, np.int64)
    cols = np.empty(h * w, np.int64)
    k = 0
    for r in range(h):
        for c in range(w):
            if mask[r, c] and not (
                r > 0 and r < h - 1 and c > 0 and c < w - 1
                and mask[r - 1, c] and mask[r + 1, c] and mask[r, c - 1] and mask[r, c + 1]
            ):  # fmt: skip
                rows[k], cols[k] = r, c
                k += 1
    step = max(1, k // (2 * count))
    m = (k + step - 1) // step
    uv = np.empty((m, 2))
    for i in range(m):
        uv[i, 0] = float(cols[i * step] + u0)
        uv[i, 1] = float(rows[i * step] + v0)
    return uv


@_njit
def column_means(p: np.ndarray) -> np.ndarray:
    """:func:`symfruit.core.points.column_means`: ``p.mean(axis=0)`` of a C-ordered (n, k) array, ``k`` of 2 or more
    (numpy adds such an array's rows one after the other, its columns side by side, then divides by ``n``: the same
    sums; a single column it sums pairwise, not so)."""
    n, k = p.shape
    out = np.zeros(k)
    for i in range(n):
        for j in range(k):
            out[j] += p[i, j]
    for j in range(k):
        out[j] /= n
    return out


# --- issue 19, nineteenth round (stop 39): observation and rasters ---


@_njit
def nearest_labels(points: np.ndarray, labels: np.ndarray, queries: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`symfruit.core.agreement._labels_at`: ``(found (m,) bool, unsure (m,) bool)``, the label (``labels`` (k,)
    bool) of the point of ``points`` (k, 2) nearest each row of ``queries`` (m, 2), the squared distances as
    ``scipy.spatial.cKDTree`` takes them (``dx * dx + dy * dy``, the same roundings); ``unsure`` where a query's
    nearest points (equally near to the bit) carry both labels (the tree's pick among them, the first it meets, is
    its own to make). The points are searched outwards from the query's place in their order along x, up to where
    ``dx * dx`` alone passes the nearest yet (a farther point's distance is no less): every point as near as the
    nearest is met, whatever the order."""
    k = points.shape[0]
    m = queries.shape[0]
    order = np.argsort(points[:, 0])
    xs = np.empty(k)
    ys = np.empty(k)
    ls = np.empty(k, np.bool_)
    for i in range(k):
        xs[i], ys[i], ls[i] = points[order[i], 0], points[order[i], 1], labels[order[i]]
    found = np.empty(m, np.bool_)
    unsure = np.zeros(m, np.bool_)
    for j in range(m):
        qx, qy = queries[j, 0], queries[j, 1]
        best = np.inf
        label = False
        mixed = False
        start = np.searchsorted(xs, qx)
        for direction in (1, -1):
            i = start if direction == 1 else start - 1
            while 0 <= i < k:
                dx = qx - xs[i]
                if dx * dx > best:
                    break
                dy = qy - ys[i]
                d = dx * dx + dy * dy
                if d < best:
                    best = d
                    label = ls[i]
                    mixed = False
                elif d == best and ls[i] != label:
                    mixed = True
                i += direction
        found[j] = label
        unsure[j] = mixed
    return found, unsure


@_njit
def nearest_labels_rows(points: np.ndarray, labels: np.ndarray, queries: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`nearest_labels` of ``points`` (k, 2) given in row order (sorted by y, then by x within a y: as
    :func:`outline_uv` makes them), without sorting them: ``(found (m,) bool, unsure (m,) bool)``, the same ``unsure``
    and, where not ``unsure``, the same ``found`` (where ``unsure``, the label of one of the equally near points, which
    the callers replace). Issue 19, stop 61 (speedb61): the points of each y are searched from the query's x outwards
    while ``dx * dx + dy * dy`` is at most the nearest yet (farther along the row it cannot fall: rounding is
    monotone), the rows from the query's y outwards until ``dy * dy`` alone passes it (a farther row's distance is no
    less), as :func:`nearest_labels` does along x: every point as near as the nearest is met, the same squared
    distances. An outline's row holds a few points, so a query near it reads a few rows and a few points of each,
    where the sweep along x read every point of the rows its x crosses."""
    k = points.shape[0]
    m = queries.shape[0]
    xs = np.empty(k)
    ys = np.empty(k)  # each row's y
    starts = np.empty(k + 1, np.int64)
    g = 0
    for i in range(k):
        xs[i] = points[i, 0]
        y = points[i, 1]
        if g == 0 or y != ys[g - 1]:
            ys[g] = y
            starts[g] = i
            g += 1
    starts[g] = k
    row_y = ys[:g]
    found = np.empty(m, np.bool_)
    unsure = np.zeros(m, np.bool_)
    for j in range(m):
        qx, qy = queries[j, 0], queries[j, 1]
        best = np.inf
        label = False
        mixed = False
        start = np.searchsorted(row_y, qy)
        for direction in (1, -1):
            gi = start if direction == 1 else start - 1
            while 0 <= gi < g:
                dy = qy - row_y[gi]
                dyy = dy * dy
                if dyy > best:
                    break
                a, b = starts[gi], starts[gi + 1]
                at, hi = a, b  # the first point of the row at or right of qx (np.searchsorted's, without a view)
                while at < hi:
                    mid = (at + hi) >> 1
                    if xs[mid] < qx:
                        at = mid + 1
                    else:
                        hi = mid
                for side in (1, -1):
                    i = at if side == 1 else at - 1
                    while a <= i < b:
                        dx = qx - xs[i]
                        d = dx * dx + dyy
                        if d > best:
                            break
                        if d < best:
                            best = d
                            label = labels[i]
                            mixed = False
                        elif d == best and labels[i] != label:  # (not so for a NaN distance: no point's)
                            mixed = True
                        i += side
                gi += direction
        found[j] = label
        unsure[j] = mixed
    return found, unsure


@_njit
def column_bounds(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, bool]:
    """:func:`symfruit.core.points.bounds` of ``p`` (n, k) float, ``n >= 1``: ``(min (k,), max (k,), sure)``, each
    column's least and greatest value in one pass over the rows (selects, no branches; NaN where the column holds a
    NaN, as numpy's reductions give). ``sure`` is False where a bound is zero: numpy's vectorised reduction may keep
    either sign of a zero (its lanes meet the values in another order), so the caller asks numpy then."""
    n, k = p.shape
    lo = np.empty(k)
    hi = np.empty(k)
    sure = True
    if k == 3:  # points: the three columns' chains side by side in one pass over the rows (the same values in the
        # same order each; 20 against 50 us on 14,000 points, issue 19, stop 42), then the checks below
        _column_bounds3(p, lo, hi)
    for j in range(k):
        if k == 3:
            a, b, bad = lo[j], hi[j], 0.0  # NaN where the column holds one (``a != a`` below)
        else:
            a = b = p[0, j]
            bad = 0.0  # NaN once a value is
            for i in range(n):
                x = p[i, j]
                a = x if x < a else a
                b = x if x > b else b
                bad = bad if x == x else x
        if bad != bad or a != a:
            a = b = np.nan
        elif a == 0.0 or b == 0.0:
            sure = False
        lo[j] = a
        hi[j] = b
    return lo, hi, sure


@_njit
def mirrored(points: np.ndarray, centre2: np.ndarray, out: np.ndarray) -> None:
    """``out`` (2 n, 3): the rows of ``points`` (n, 3), then ``centre2 - points`` (each point's mirror image through
    half of ``centre2`` (3,)), as :func:`symfruit.methods.evidence.evidence` writes them column by column: the same
    copies and differences, in one pass."""
    n = points.shape[0]
    a, b, c = centre2[0], centre2[1], centre2[2]
    for i in range(n):
        x, y, z = points[i, 0], points[i, 1], points[i, 2]
        out[i, 0] = x
        out[i, 1] = y
        out[i, 2] = z
        out[n + i, 0] = a - x
        out[n + i, 1] = b - y
        out[n + i, 2] = c - z


# --- issue 19, stop 40 (speedobs40): the dense view's points projected once ---


@_njit
def point_pixels(points: np.ndarray, fx: float, fy: float, cx: float, cy: float) -> tuple[np.ndarray, np.ndarray]:
    """``(col (n,), row (n,))`` int64: each point's (n, 3) pixel, :meth:`~symfruit.core.camera.Camera.project`'s
    arithmetic rounded half to even and converted as numpy converts it (a coordinate that is NaN, infinite or past
    2^63 becomes its smallest integer), as :func:`inside_px`, :func:`rim_coverage` and :func:`image_pixels` take
    it: one projection of a view's points that they share (issue 19, stop 40)."""
    n = points.shape[0]
    col = np.empty(n, np.int64)
    row = np.empty(n, np.int64)
    big = 9.223372036854775808e18  # 2^63
    least = np.int64(-9223372036854775808)
    for i in range(n):
        inv_z = 1.0 / points[i, 2]
        u = np.rint(fx * points[i, 0] * inv_z + cx)
        v = np.rint(fy * points[i, 1] * inv_z + cy)
        col[i] = np.int64(u) if -big <= u < big else least
        row[i] = np.int64(v) if -big <= v < big else least
    return col, row


@_njit
def inside_px_of(col: np.ndarray, row: np.ndarray, u0: int, v0: int, inner: np.ndarray) -> np.ndarray:
    """:func:`inside_px` of the points whose pixels :func:`point_pixels` gave: the distance map ``inner`` (h, w) at
    each pixel less the window's corner ``u0``, ``v0`` (wrapping around as numpy's subtraction does), clipped to
    the window: the same values."""
    h, w = inner.shape
    n = col.shape[0]
    out = np.empty(n)
    for i in range(n):
        out[i] = inner[min(max(row[i] - np.int64(v0), 0), h - 1), min(max(col[i] - np.int64(u0), 0), w - 1)]
    return out


@_njit
def rim_coverage_pixels(
    col: np.ndarray, row: np.ndarray, u0: int, v0: int, mask: np.ndarray, inner: np.ndarray, width: float, fill: int
) -> float:
    """:func:`rim_coverage` of the points whose pixels :func:`point_pixels` gave: the points' pixels marked, then
    one pass over the window counting the rim's and the rest's pixels and those of each holding a point (the
    former made the rim's map and counted it before marking the points: the same whole numbers, so the same
    value)."""
    h, w = mask.shape
    hit = np.zeros((h, w), np.bool_)
    for i in range(col.shape[0]):
        c = col[i] - np.int64(u0)
        r = row[i] - np.int64(v0)
        if 0 <= c < w and 0 <= r < h:
            hit[r, c] = True
    if fill > 0:
        grown = np.empty((h, w), np.bool_)
        square_filter(hit, fill, False, grown)
        hit = grown
    n_rim = n_rest = hit_rim = hit_rest = 0
    for r in range(h):
        for c in range(w):
            if mask[r, c]:
                if inner[r, c] <= width:
                    n_rim += 1
                    hit_rim += hit[r, c]
                else:
                    n_rest += 1
                    hit_rest += hit[r, c]
    if n_rim == 0 or n_rest == 0:
        return 1.0
    interior = hit_rest / n_rest
    if interior <= 0:
        return 1.0
    share = hit_rim / n_rim / interior
    return share if share < 1.0 else 1.0


@_njit
def pixel_box(col: np.ndarray, row: np.ndarray) -> tuple[int, int, int, int]:
    """``(c0, c1, r0, r1)``: the least and greatest of ``col`` (n,) and of ``row`` (n,) int64, ``n >= 1``, in one pass
    (:func:`symfruit.core.raster.silhouette`'s four reductions: the same whole numbers)."""
    c0 = c1 = col[0]
    r0 = r1 = row[0]
    for i in range(col.shape[0]):
        c, r = col[i], row[i]
        c0 = c if c < c0 else c0
        c1 = c if c > c1 else c1
        r0 = r if r < r0 else r0
        r1 = r if r > r1 else r1
    return c0, c1, r0, r1


@_njit
def mark_pixels(col: np.ndarray, row: np.ndarray, u0: int, v0: int, h: int, w: int) -> np.ndarray:
    """(h, w) bool: the pixels ``(row - v0, col - u0)`` of a window at ``u0, v0`` marked (every one in the window:
    :func:`symfruit.core.raster.silhouette`'s flat-index assignment)."""
    hit = np.zeros((h, w), np.bool_)
    for i in range(col.shape[0]):
        hit[row[i] - v0, col[i] - u0] = True
    return hit


# --- issue 19, eighteenth round (stop 38): the completion ---


@_njit
def ellipse_holds(
    mask: np.ndarray, u0: int, v0: int, cu: float, cv: float, a00: float, a01: float, a11: float
) -> tuple[int, int]:
    """:func:`symfruit.core.raster.outline_cone`'s acceptance test: ``(n, held)``, the pixels of ``mask`` (h, w)
    bool (a window at ``u0, v0``) and how many of them the ellipse holds, ``a00 u^2 + 2 a01 u v + a11 v^2 <= 1 +
    1e-9`` about its centre ``(cu, cv)``, each term as the twin's numpy expression rounds it (left to right, ``2
    a01`` first), so the same pixels; one pass over the window instead of the twin's coordinate arrays."""
    h, w = mask.shape
    n = 0
    held = 0
    b01 = 2 * a01
    for r in range(h):
        v = float(r + v0) - cv
        for c in range(w):
            if mask[r, c]:
                u = float(c + u0) - cu
                n += 1
                held += a00 * u * u + b01 * u * v + a11 * v * v <= 1.0 + 1e-9
    return n, held


@_njit
def close_ragged(mask: np.ndarray, radius: int) -> tuple[np.ndarray, int, int]:
    """:func:`symfruit.core.raster.close_ragged`'s closing and counts: ``(closed (h, w) bool, added, outline)``,
    ``mask`` (h, w) bool padded by ``radius`` pixels, closed by the ``2 radius + 1`` square (:func:`close_square`),
    its holes filled over the closed mask's box grown by a pixel (:func:`filled`, as
    :func:`~symfruit.core.raster.fill_holes`), the padding cut off again; ``added`` the pixels it adds to ``mask``,
    ``outline`` the mask's outline pixels (``mask & ~interior(mask)``). The twin's steps, the same pixels, in one
    call.

    Since issue 19's stop 40 the closing runs over the mask's box grown by ``radius + 1`` pixels (within the padded
    array) alone: the dilation reaches ``radius`` pixels beyond the box, so that part's outer ring is not dilated,
    and a pixel whose square reaches beyond the part meets that ring and is not in the erosion, as in the whole
    array; nothing beyond the part is dilated, closed or a hole (0.34 against 0.23 ms on a dense view's window)."""
    h, w = mask.shape
    hp, wp = h + 2 * radius, w + 2 * radius
    closed = np.zeros((h, w), np.bool_)
    outline = 0
    m0, m1, n0, n1 = h, 0, w, 0  # the mask's box (rows m0:m1, columns n0:n1)
    for r in range(h):
        for c in range(w):
            m = mask[r, c]
            if m:
                m0, m1 = min(m0, r), r + 1
                n0, n1 = min(n0, c), max(n1, c + 1)
                if not (
                    r > 0 and r < h - 1 and c > 0 and c < w - 1
                    and mask[r - 1, c] and mask[r + 1, c] and mask[r, c - 1] and mask[r, c + 1]
                ):  # fmt: skip
                    outline += 1
    if m1 == 0:  # an empty mask: nothing closes
        return closed, 0, 0
    # the part, in the padded array's rows and columns
    g = radius + 1
    s0, s1 = max(m0 + radius - g, 0), min(m1 + radius + g, hp)
    t0, t1 = max(n0 + radius - g, 0), min(n1 + radius + g, wp)
    hs, ws = s1 - s0, t1 - t0
    part = np.zeros((hs, ws), np.bool_)
    for i in range(hs):
        r = s0 + i - radius
        if 0 <= r < h:
            for j in range(ws):
                c = t0 + j - radius
                if 0 <= c < w:
                    part[i, j] = mask[r, c]
    shut = np.empty((hs, ws), np.bool_)
    close_square(part, radius, shut)
    full = shut.copy()
    r0, r1, c0, c1 = _box(shut)
    if r1 > 0:
        r0, r1 = max(r0 - 1, 0), min(r1 + 1, hs)
        c0, c1 = max(c0 - 1, 0), min(c1 + 1, ws)
        filled(shut[r0:r1, c0:c1], full[r0:r1, c0:c1])
    added = 0
    for i in range(hs):
        r = s0 + i - radius
        if 0 <= r < h:
            for j in range(ws):
                c = t0 + j - radius
                if 0 <= c < w and full[i, j]:
                    closed[r, c] = True
                    added += not mask[r, c]
    return closed, added, outline


@_njit
def image_pixels(
    points: np.ndarray, fx: float, fy: float, cx: float, cy: float, width: int, height: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`symfruit.core.raster._pixels`: the pixel column and row (whole numbers) and depth of each point of
    ``points`` (n, 3) that projects into the ``width`` x ``height`` image, in the points' order
    (:meth:`~symfruit.core.camera.Camera.project`'s arithmetic, rounded half to even, as :func:`inside_px` takes
    it): the twin's pixels. A coordinate that is NaN or rounds outside the image leaves its point out, as the
    twin's integer conversion and bounds do."""
    n = points.shape[0]
    col = np.empty(n, np.int64)
    row = np.empty(n, np.int64)
    z = np.empty(n)
    m = 0
    for i in range(n):
        inv_z = 1.0 / points[i, 2]
        u = np.rint(fx * points[i, 0] * inv_z + cx)
        v = np.rint(fy * points[i, 1] * inv_z + cy)
        if u >= 0.0 and u < width and v >= 0.0 and v < height:
            col[m] = np.int64(u)
            row[m] = np.int64(v)
            z[m] = points[i, 2]
            m += 1
    return col[:m], row[:m], z[:m]


# --- issue 19, nineteenth round (stop 39): the candidates ---


def _fma_intrinsic(typingctx: Any, a: Any, b: Any, c: Any) -> Any:
    """``_fma(a, b, c)``: ``a * b + c`` rounded once (LLVM's ``llvm.fma.f64``; in software where the CPU has no FMA
    unit), the multiply-add OpenBLAS's kernels run on a few short products, so that a kernel repeating such a product
    gets its values. Float64 arguments only."""
    sig = numba.types.float64(numba.types.float64, numba.types.float64, numba.types.float64)

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        from numba.core import cgutils  # its llvmlite.ir, the IR numba builds (llvmlite is numba's own dependency)

        double = cgutils.ir.DoubleType()
        fn = builder.module.declare_intrinsic("llvm.fma", [double], cgutils.ir.FunctionType(double, [double] * 3))
        return builder.call(fn, args)

    return sig, codegen


_fma = cast(Callable[[float, float, float], float], numba.extending.intrinsic(_fma_intrinsic))


def _add4_intrinsic(typingctx: Any, arr: Any, off: Any, a: Any, b: Any, c: Any, d: Any) -> Any:
    """``_add4(arr, off, a, b, c, d)``: ``arr``'s four float64 from the flat place ``off`` on (a C-ordered array's)
    each plus its own of ``a, b, c, d``, in one vector load, addition and store (LLVM's ``<4 x double>``; issue 19,
    stop 60, revol60). Each lane's addition is the scalar one, rounded as it (IEEE), so the four sums are the same
    as four ``+=``; numba's vectoriser does not pair such scattered updates itself. ``off`` is not checked."""
    f8 = numba.types.float64
    sig = numba.types.void(arr, numba.types.intp, f8, f8, f8, f8)

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        from numba.core import cgutils  # its llvmlite.ir, the IR numba builds (llvmlite is numba's own dependency)

        ir = cgutils.ir
        ary = context.make_array(signature.args[0])(context, builder, args[0])
        vty = ir.VectorType(ir.DoubleType(), 4)
        ptr = builder.bitcast(builder.gep(ary.data, [args[1]]), vty.as_pointer())
        terms = ir.Constant(vty, ir.Undefined)
        for k in range(4):
            terms = builder.insert_element(terms, args[2 + k], ir.Constant(ir.IntType(32), k))
        builder.store(builder.fadd(builder.load(ptr, align=8), terms), ptr, align=8)
        return context.get_dummy_value()

    return sig, codegen


_add4 = cast(Callable[..., None], numba.extending.intrinsic(_add4_intrinsic))


def _pair_sums_intrinsic(
    typingctx: Any, u: Any, v: Any, idx: Any, sums: Any, du: Any, dv: Any, dy: Any
) -> Any:  # fmt: skip
    """``_pair_sums(u, v, idx, sums, du, dv, dy)``: :func:`slice_costs_below`'s loop over the points of a pair of
    directions, the two directions the two lanes of LLVM's ``<2 x double>`` (issue 19, stop 62, comp62). ``u``, ``v``
    (n, 2) float64 and ``idx`` (n, 2) int64 hold each point's plane coordinates and slice for direction 0 in column 0
    and direction 1 in column 1 (C-ordered: a point's two in one vector load), ``sums`` (2, b, 4) each direction's
    slices' counts and means of ``u``, ``v`` and ``u^2 + v^2``. For each point, lane by lane, ``du = u - mean u``,
    ``dv = v - mean v`` and ``dy = (u u + v v) - mean (u^2 + v^2)`` are stored to ``du``, ``dv``, ``dy`` (n, 2) (one
    vector store each) and added to the running sums ``du du``, ``du dv``, ``dv dv``, ``du dy``, ``dv dy``, in the
    points' order; returns ``(a11, a12, a22, e1, e2)`` of direction 0, then of direction 1. Each lane's operations are
    the scalar loop's in its order, rounded as they are (IEEE; no contraction into multiply-adds), so the sums are
    the scalar loop's to the bit. The loop was bound by its loads and stores (12 and 6 a point, 2 directions), not its
    arithmetic: the vector loads and stores take it to 9 and 3 (numba's vectoriser does not pack two chains of sums
    itself). Indices are not checked."""
    f8 = numba.types.float64
    sig = numba.types.UniTuple(f8, 10)(u, v, idx, sums, du, dv, dy)

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        from numba.core import cgutils  # its llvmlite.ir, the IR numba builds (llvmlite is numba's own dependency)

        ir = cgutils.ir
        arrays = [context.make_array(ty)(context, builder, val) for ty, val in zip(signature.args, args, strict=True)]
        pu, pv, pidx, psums, pdu, pdv, pdy = (a.data for a in arrays)
        n = cgutils.unpack_tuple(builder, arrays[0].shape, 2)[0]
        bins = cgutils.unpack_tuple(builder, arrays[3].shape, 3)[1]
        i64, i32 = ir.IntType(64), ir.IntType(32)
        vty, ity = ir.VectorType(ir.DoubleType(), 2), ir.VectorType(i64, 2)
        lanes = (ir.Constant(i32, 0), ir.Constant(i32, 1))
        four = ir.Constant(i64, 4)
        accs = [cgutils.alloca_once_value(builder, ir.Constant(vty, [0.0, 0.0])) for _ in range(5)]

        def row(ptr: Any, i: Any, ty: Any) -> Any:  # the point's two values as one vector
            return builder.bitcast(builder.gep(ptr, [builder.mul(i, ir.Constant(i64, 2))]), ty.as_pointer())

        with cgutils.for_range(builder, n) as loop:
            i = loop.index
            uu = builder.load(row(pu, i, vty), align=8)
            vv = builder.load(row(pv, i, vty), align=8)
            slices = builder.load(row(pidx, i, ity), align=8)
            at0 = builder.mul(builder.extract_element(slices, lanes[0]), four)
            at1 = builder.mul(builder.add(bins, builder.extract_element(slices, lanes[1])), four)

            def mean(k: int) -> Any:  # direction 0's slice mean k, direction 1's
                a = builder.load(builder.gep(psums, [builder.add(at0, ir.Constant(i64, k))]))
                b = builder.load(builder.gep(psums, [builder.add(at1, ir.Constant(i64, k))]))
                both = builder.insert_element(ir.Constant(vty, ir.Undefined), a, lanes[0])
                return builder.insert_element(both, b, lanes[1])

            d_u = builder.fsub(uu, mean(1))
            d_v = builder.fsub(vv, mean(2))
            d_y = builder.fsub(builder.fadd(builder.fmul(uu, uu), builder.fmul(vv, vv)), mean(3))
            builder.store(d_u, row(pdu, i, vty), align=8)
            builder.store(d_v, row(pdv, i, vty), align=8)
            builder.store(d_y, row(pdy, i, vty), align=8)
            for acc, (x, y) in zip(accs, ((d_u, d_u), (d_u, d_v), (d_v, d_v), (d_u, d_y), (d_v, d_y)), strict=True):
                builder.store(builder.fadd(builder.load(acc), builder.fmul(x, y)), acc)
        out = [builder.extract_element(builder.load(acc), lane) for lane in lanes for acc in accs]
        return context.make_tuple(builder, signature.return_type, out)

    return sig, codegen


_pair_sums = cast(Callable[..., tuple[float, ...]], numba.extending.intrinsic(_pair_sums_intrinsic))


@_njit
def _tangent(
    u: float, v: float, axis: np.ndarray, basis: np.ndarray, cx: float, cy: float, fx: float, fy: float
) -> tuple[float, float]:
    """``across_sight``'s ``tangent`` of one pixel ``(u, v)``: the ray ``((u - cx) / fx, (v - cy) / fy, 1)`` over
    its product with ``axis``, times ``basis.T``, as OpenBLAS (Haswell kernels) forms the twin's ``r @ basis.T``
    (each element ``r2 b2 + (r1 b1 + r0 b0)``, two multiply-adds) and ``r @ axis`` (``r2 a2 + (r0 a0 + r1 a1)``)."""
    r0 = (u - cx) / fx
    r1 = (v - cy) / fy
    den = _fma(1.0, axis[2], _fma(r0, axis[0], r1 * axis[1]))
    s = _fma(1.0, basis[0, 2], _fma(r1, basis[0, 1], r0 * basis[0, 0])) / den
    t = _fma(1.0, basis[1, 2], _fma(r1, basis[1, 1], r0 * basis[1, 0])) / den
    return s, t


@_njit
def across_frame(
    mu0: float, mu1: float, cov: np.ndarray, cx: float, cy: float, fx: float, fy: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`symfruit.core.raster.across_sight` up to its ``eigh``: the unit ray through the centroid ``(mu0, mu1)``
    (3,), the tangent basis (2, 3) and the pixels' covariance ``cov`` (2, 2) carried to tangent coordinates, ``jac
    @ cov @ jac.T`` (2, 2), each value the twin's (numpy's norms of 3-vectors sum left to right; the 2x2 products are
    OpenBLAS's ``a1 b1 + a0 b0`` multiply-adds)."""
    axis = np.empty(3)
    axis[0] = (mu0 - cx) / fx
    axis[1] = (mu1 - cy) / fy
    axis[2] = 1.0
    norm = math.sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2])
    for i in range(3):
        axis[i] = axis[i] / norm
    basis = np.empty((2, 3))
    basis[0, 0] = axis[2]
    basis[0, 1] = 0.0
    basis[0, 2] = -axis[0]
    norm = math.sqrt(basis[0, 0] * basis[0, 0] + basis[0, 1] * basis[0, 1] + basis[0, 2] * basis[0, 2])
    for i in range(3):
        basis[0, i] = basis[0, i] / norm
    basis[1, 0] = axis[1] * basis[0, 2] - axis[2] * basis[0, 1]
    basis[1, 1] = axis[2] * basis[0, 0] - axis[0] * basis[0, 2]
    basis[1, 2] = axis[0] * basis[0, 1] - axis[1] * basis[0, 0]
    s0, t0 = _tangent(mu0 + 0.0, mu1 + 0.0, axis, basis, cx, cy, fx, fy)
    su, tu = _tangent(mu0 + 1.0, mu1 + 0.0, axis, basis, cx, cy, fx, fy)
    sv, tv = _tangent(mu0 + 0.0, mu1 + 1.0, axis, basis, cx, cy, fx, fy)
    jac = np.empty((2, 2))
    jac[0, 0], jac[1, 0] = su - s0, tu - t0
    jac[0, 1], jac[1, 1] = sv - s0, tv - t0
    left = np.empty((2, 2))
    for i in range(2):
        for j in range(2):
            left[i, j] = _fma(jac[i, 1], cov[1, j], jac[i, 0] * cov[0, j])
    out = np.empty((2, 2))
    for i in range(2):
        for j in range(2):
            out[i, j] = _fma(left[i, 1], jac[j, 1], left[i, 0] * jac[j, 0])
    return axis, basis, out


@_njit
def across_extent(
    cracks: np.ndarray, axis: np.ndarray, basis: np.ndarray, vec: np.ndarray, cx: float, cy: float, fx: float,
    fy: float,
) -> tuple[np.ndarray, np.ndarray, float, float]:  # fmt: skip
    """:func:`symfruit.core.raster.across_sight` after its ``eigh``: the outline's points ``cracks`` (m, 2), pixels,
    in tangent coordinates, their least and greatest values along ``e1`` and ``e2`` (2,) each, and their widths along
    the eigenvectors ``vec`` (2, 2, columns), the first and the second: each value the twin's (``edge @ vec`` as
    OpenBLAS's multiply-adds)."""
    lo = np.full(2, np.inf)
    hi = np.full(2, -np.inf)
    p_lo = np.full(2, np.inf)
    p_hi = np.full(2, -np.inf)
    nan = False
    for i in range(cracks.shape[0]):
        s, t = _tangent(cracks[i, 0], cracks[i, 1], axis, basis, cx, cy, fx, fy)
        if s != s or t != t:
            nan = True
        lo[0], hi[0] = min(lo[0], s), max(hi[0], s)
        lo[1], hi[1] = min(lo[1], t), max(hi[1], t)
        for j in range(2):
            p = _fma(t, vec[1, j], s * vec[0, j])
            if p != p:
                nan = True
            p_lo[j], p_hi[j] = min(p_lo[j], p), max(p_hi[j], p)
    if nan:  # numpy's reductions carry a NaN through
        lo[:], hi[:], p_lo[:], p_hi[:] = np.nan, np.nan, np.nan, np.nan
    return lo, hi, p_hi[0] - p_lo[0], p_hi[1] - p_lo[1]


@_njit
def _lesser(a: float, b: float) -> float:
    """``np.minimum`` of two numbers (:func:`symfruit.core.candidates._lesser`): NaN where either is, ``b`` where
    they are equal."""
    return a if a < b or a != a else b


@_njit
def _greater(a: float, b: float) -> float:
    """``np.maximum`` of two numbers (:func:`symfruit.core.candidates._greater`)."""
    return a if a > b or a != a else b


@_njit
def constrain_box(
    lo: np.ndarray, hi: np.ndarray, seen_lo: np.ndarray, seen_hi: np.ndarray, front: float, scale: float,
    cone: np.ndarray, intrinsics: np.ndarray, share: float,
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.core.candidates.constrain_box` (its twin, in Python floats): the same operations in the same
    order on the same IEEE doubles, so the same box. ``scale`` is ``REACH / max(contour, REACH_FLOOR)``; ``cone`` the
    silhouette's pixel box ``(u_min, v_min, u_max, v_max)``, or empty for none; ``intrinsics`` ``(cx, cy, fx, fy)``;
    ``share`` the pull's."""
    s_lo = np.empty(3)
    s_hi = np.empty(3)
    out_lo = np.empty(3)
    out_hi = np.empty(3)
    for i in range(3):
        s_lo[i] = seen_lo[i]
    s_lo[2] = front
    for i in range(3):
        s_hi[i] = _greater(seen_hi[i], s_lo[i])
        reach = scale * (s_hi[i] - s_lo[i])
        out_lo[i] = _lesser(_greater(lo[i], s_hi[i] - reach), s_lo[i])
        out_hi[i] = _greater(_lesser(hi[i], s_lo[i] + reach), s_hi[i])
    out_lo[2] = front
    top = front + 1e-4
    out_hi[2] = top if top > out_hi[2] else out_hi[2]  # Python's max(out_hi[2], top): the first unless top is larger
    if cone.shape[0] == 4:
        cx, cy, fx, fy = intrinsics[0], intrinsics[1], intrinsics[2], intrinsics[3]
        z0, z1 = out_lo[2], out_hi[2]
        a, b = (cone[0] - cx) / fx, (cone[1] - cy) / fy
        bound_lo0, bound_lo1 = _lesser(a * z0, a * z1), _lesser(b * z0, b * z1)
        a, b = (cone[2] - cx) / fx, (cone[3] - cy) / fy
        bound_hi0, bound_hi1 = _greater(a * z0, a * z1), _greater(b * z0, b * z1)
        out_lo[0] = _lesser(s_lo[0], out_lo[0] + share * _greater(bound_lo0 - out_lo[0], 0.0))
        out_hi[0] = _greater(s_hi[0], out_hi[0] - share * _greater(out_hi[0] - bound_hi0, 0.0))
        out_lo[1] = _lesser(s_lo[1], out_lo[1] + share * _greater(bound_lo1 - out_lo[1], 0.0))
        out_hi[1] = _greater(s_hi[1], out_hi[1] - share * _greater(out_hi[1] - bound_hi1, 0.0))
    return out_lo, out_hi


@_njit
def cone_rays(points: np.ndarray, cone: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`symfruit.core.fits.fit_cone_ellipsoid`'s rays: every point (n, 3) over its depth (n, 3), each ray's
    ``r^T C r`` (n,) for the viewing cone ``cone`` (3, 3) and the depths (n,), contiguous; the twin's values (its
    ``rays @ cone`` as OpenBLAS's two multiply-adds from the first term, the row sums of three left to right)."""
    n = points.shape[0]
    rays = np.empty((n, 3))
    ray_cone = np.empty(n)
    z = np.empty(n)
    for i in range(n):
        depth = points[i, 2]
        r0, r1, r2 = points[i, 0] / depth, points[i, 1] / depth, depth / depth
        rays[i, 0], rays[i, 1], rays[i, 2] = r0, r1, r2
        c0 = _fma(r2, cone[2, 0], _fma(r1, cone[1, 0], r0 * cone[0, 0]))
        c1 = _fma(r2, cone[2, 1], _fma(r1, cone[1, 1], r0 * cone[0, 1]))
        c2 = _fma(r2, cone[2, 2], _fma(r1, cone[1, 2], r0 * cone[0, 2]))
        ray_cone[i] = c0 * r0 + c1 * r1 + c2 * r2
        z[i] = depth
    return rays, ray_cone, z


# --- issue 19, twentieth round (stop 40): the candidates ---


@_njit_inlined
def _smallest_mean_at(x: np.ndarray, keep: int, a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """:func:`smallest_mean` of ``x`` (the same value, worked out the same way) and the ``keep``-th smallest value it
    found on the way."""
    thr = kth_smallest(x, keep - 1, a, b)
    total = 0.0
    count = 0
    for i in range(x.shape[0]):
        v = x[i]
        lt = v < thr
        total += v if lt else 0.0
        count += lt
    return (total + (keep - count) * thr) / keep, thr


#: :func:`slice_costs_below`'s margin (relative) on its bound: far above the rounding of a sum of fewer than
#: :data:`_BOUNDED_POINTS` terms, so that a direction is only left unfinished where its cost is surely larger.
_BOUND_MARGIN = 1e-9
_BOUNDED_POINTS = 1_000_000


@_njit_inlined
def _range4(t: np.ndarray, n: int) -> tuple[float, float]:
    """The least and the greatest of ``t[:n]`` as :func:`slice_costs_below` took them until stop 48 (``lo = min(lo,
    t[i])`` from ``inf``, ``hi = max(hi, t[i])`` from ``-inf``: a NaN is passed over), in four interleaved runs
    joined at the end (stop 49, compspeed49: four chains of comparisons instead of one, the solid of revolution's
    search about 15 % faster). The least and the greatest of a set of numbers do not depend on the order they are
    met in, but for the sign of a zero; :func:`slice_costs_below` reads them only as ``t - lo`` and ``hi - lo``,
    which are the same for either zero (``x - 0.0 == x - (-0.0)``; ``0.0 - 0.0`` and ``-0.0 - (-0.0)`` are both
    ``0.0``), so the slices and costs are the same to the bit."""
    l0 = l1 = l2 = l3 = np.inf
    h0 = h1 = h2 = h3 = -np.inf
    i = 0
    while i + 4 <= n:
        a0, a1, a2, a3 = t[i], t[i + 1], t[i + 2], t[i + 3]
        l0, l1, l2, l3 = min(l0, a0), min(l1, a1), min(l2, a2), min(l3, a3)
        h0, h1, h2, h3 = max(h0, a0), max(h1, a1), max(h2, a2), max(h3, a3)
        i += 4
    while i < n:
        l0, h0 = min(l0, t[i]), max(h0, t[i])
        i += 1
    return min(min(l0, l1), min(l2, l3)), max(max(h0, h1), max(h2, h3))


@_njit_inlined
def _clipped_sum4(w: np.ndarray, n: int, thr: float) -> tuple[float, bool]:
    """``sum(min(w[:n], thr))`` (a NaN counted as ``thr``) and whether every ``w[:n]`` is below ``inf``, for
    :func:`slice_costs_below`'s bound: in four interleaved running sums, joined as ``(s0 + s1) + (s2 + s3)`` (stop
    49, compspeed49; one running sum until stop 48). Another order of the same additions: the sum differs from the
    one-chain sum by rounding alone, far inside the bound's :data:`_BOUND_MARGIN`, and the bound only decides which
    directions' costs are not finished, none of them the least (so the search's pick is the same, bit for bit)."""
    s0 = s1 = s2 = s3 = 0.0
    finite = True
    i = 0
    while i + 4 <= n:
        w0, w1, w2, w3 = w[i], w[i + 1], w[i + 2], w[i + 3]
        finite &= (w0 < np.inf) & (w1 < np.inf) & (w2 < np.inf) & (w3 < np.inf)
        s0 += w0 if w0 < thr else thr
        s1 += w1 if w1 < thr else thr
        s2 += w2 if w2 < thr else thr
        s3 += w3 if w3 < thr else thr
        i += 4
    while i < n:
        w0 = w[i]
        finite &= w0 < np.inf
        s0 += w0 if w0 < thr else thr
        i += 1
    return (s0 + s1) + (s2 + s3), finite


@_njit
def slice_costs_below(
    q: np.ndarray, dirs: np.ndarray, bins: int, best: float, thr: float
) -> tuple[np.ndarray, float, float]:
    """:func:`slice_costs` of the directions ``dirs`` (k, 3) for centred points ``q`` (n, 3), each cost the same value
    worked out the same way, but for the directions whose cost is surely larger than the least known before them
    (``best``, the least of an earlier call, with ``thr`` its ``keep``-th smallest squared distance; then the least
    found here): their cost is ``inf``, their trimmed mean (the selection, more than half the work) not taken (issue
    19, twentieth round). So ``_least`` of the costs (with ``best`` before them, where it came from the same search)
    picks the direction it would pick from every cost. Returns the costs (k,) and the least known after them and its
    ``keep``-th smallest value (``best``, ``thr`` as given where none is less).

    The bound: for the squared distances ``v`` (n,) (each at least 0) and any ``T >= 0``, the sum of the ``keep``
    smallest is at least ``sum(min(v, T)) - (n - keep) T`` (each of the ``keep`` smallest is at least its ``min``,
    each other ``min`` at most ``T``), equal at ``T`` = the ``keep``-th smallest; ``T`` is the best direction's (a
    worse direction's threshold is mostly above it, where the bound is weaker but still holds). A direction is left
    unfinished only where every distance is finite, ``n`` is below :data:`_BOUNDED_POINTS` and the bound exceeds
    ``keep best`` by :data:`_BOUND_MARGIN`, far beyond the rounding of either sum. The projections run apart from
    the axis's range (the loops without a reduction vectorise), on the points' columns.

    Two directions at a time (issue 19, stop 60): their projections, slices, slice means, normal equations and squared
    distances in the same loops over the points, each direction's values the same operations in the same order as
    alone (two independent chains of sums in flight instead of one), then each finished or bounded in turn, in
    ``dirs``' order, as before (a lone last direction is worked out as both of a pair, kept once); the same costs and
    picks, about 10 % less time. Each slice's four sums of a point in one vector addition (:func:`_add4`; revol60:
    the same sums, 0.94 against 0.82 ms a benchmark frame's ``revolution_search``, replayed). The pair's values are
    kept side by side, a point's two in a row, and the normal equations' loop runs both directions in the two lanes
    of a vector (:func:`_pair_sums`; stop 62, comp62: the same sums, 0.84 against 0.74 ms, replayed)."""
    k, n = dirs.shape[0], q.shape[0]
    out = np.empty(k)
    q0 = q[:, 0].copy()
    q1 = q[:, 1].copy()
    q2 = q[:, 2].copy()
    t = np.empty((2, n))
    # a point's values of both directions side by side (n, 2): one vector load or store in _pair_sums (stop 62)
    u2 = np.empty((n, 2))
    v2 = np.empty((n, 2))
    du2 = np.empty((n, 2))
    dv2 = np.empty((n, 2))
    dy2 = np.empty((n, 2))
    idx2 = np.empty((n, 2), np.int64)
    dist2 = np.empty((2, n))
    scratch_a = np.empty(n)
    scratch_b = np.empty(n)
    sums = np.empty((2, bins, 4))  # each slice's count and sums of u, v and u^2 + v^2, then their means
    keep = max(1, int(0.8 * n))
    bounded = n < _BOUNDED_POINTS
    for j0 in range(0, k, 2):
        pair = min(2, k - j0)
        j1 = j0 + 1 if pair == 2 else j0
        x0, y0, z0 = dirs[j0, 0], dirs[j0, 1], dirs[j0, 2]
        x1, y1, z1 = dirs[j1, 0], dirs[j1, 1], dirs[j1, 2]
        a0, b0, c0, f0, g0, h0 = _plane_basis(x0, y0, z0)
        a1, b1, c1, f1, g1, h1 = _plane_basis(x1, y1, z1)
        for i in range(n):
            p0, p1, p2 = q0[i], q1[i], q2[i]
            t[0, i] = x0 * p0 + y0 * p1 + z0 * p2
            u2[i, 0] = a0 * p0 + b0 * p1 + c0 * p2
            v2[i, 0] = f0 * p0 + g0 * p1 + h0 * p2
            t[1, i] = x1 * p0 + y1 * p1 + z1 * p2
            u2[i, 1] = a1 * p0 + b1 * p1 + c1 * p2
            v2[i, 1] = f1 * p0 + g1 * p1 + h1 * p2
        lo0, hi0 = _range4(t[0], n)
        lo1, hi1 = _range4(t[1], n)
        span0 = max(hi0 - lo0, 1e-12)
        span1 = max(hi1 - lo1, 1e-12)
        sums[:] = 0.0
        for i in range(n):  # (at least 0: a NaN's slice, which numba's int leaves undefined, the first)
            idx2[i, 0] = max(min(int((t[0, i] - lo0) / span0 * bins), bins - 1), 0)
            idx2[i, 1] = max(min(int((t[1, i] - lo1) / span1 * bins), bins - 1), 0)
        for i in range(n):  # each slice's four sums in one vector addition (stop 60, revol60: the same sums)
            s, r = idx2[i, 0], idx2[i, 1]
            ua, va, ub, vb = u2[i, 0], v2[i, 0], u2[i, 1], v2[i, 1]
            _add4(sums, s * 4, 1.0, ua, va, ua * ua + va * va)
            _add4(sums, (bins + r) * 4, 1.0, ub, vb, ub * ub + vb * vb)
        for e in range(2):
            for s in range(bins):
                d = max(sums[e, s, 0], 1.0)
                sums[e, s, 1] /= d
                sums[e, s, 2] /= d
                sums[e, s, 3] /= d
        a11, a12, a22, e1, e2, c11, c12, c22, d1, d2 = _pair_sums(u2, v2, idx2, sums, du2, dv2, dy2)
        au0, av0 = _slice_centre(a11, a12, a22, e1, e2)
        au1, av1 = _slice_centre(c11, c12, c22, d1, d2)
        for i in range(n):
            res = dy2[i, 0] - 2.0 * (au0 * du2[i, 0] + av0 * dv2[i, 0])
            ru = u2[i, 0] - au0
            rv = v2[i, 0] - av0
            rho2 = max(ru * ru + rv * rv, 1e-12) * 4.0
            dist2[0, i] = res * res / rho2
            res = dy2[i, 1] - 2.0 * (au1 * du2[i, 1] + av1 * dv2[i, 1])
            ru = u2[i, 1] - au1
            rv = v2[i, 1] - av1
            rho2 = max(ru * ru + rv * rv, 1e-12) * 4.0
            dist2[1, i] = res * res / rho2
        for e in range(pair):
            j = j0 + e
            dd = dist2[e]
            if bounded and best < np.inf:  # best is finite (not NaN), so is thr
                total, finite = _clipped_sum4(dd, n, thr)
                if finite and total * (1.0 - _BOUND_MARGIN) - (n - keep) * thr * (1.0 + _BOUND_MARGIN) > \
                        keep * best * (1.0 + _BOUND_MARGIN):  # fmt: skip
                    out[j] = np.inf
                    continue
            cost, at = _smallest_mean_at(dd, keep, scratch_a, scratch_b)
            out[j] = cost
            if cost < best:
                best, thr = cost, at
    return out, best, thr


@_njit_inlined
def _plane_basis(x: float, y: float, z: float) -> tuple[float, float, float, float, float, float]:
    """The plane basis ``(a, b, c)``, ``(f, g, h)`` of the direction ``(x, y, z)`` as
    :func:`~symfruit.core.points.perpendicular_basis` makes it (:func:`slice_costs_below`'s)."""
    if abs(x) < 0.9:
        a, b, c = 0.0, z, -y
    else:
        a, b, c = -z, 0.0, x
    norm = math.sqrt(a * a + b * b + c * c)
    a, b, c = a / norm, b / norm, c / norm
    return a, b, c, y * c - z * b, z * a - x * c, x * b - y * a


@_njit_inlined
def _slice_centre(a11: float, a12: float, a22: float, b1: float, b2: float) -> tuple[float, float]:
    """The axis' place in the plane from :func:`slice_costs_below`'s 2x2 normal equations (a determinant not above
    1e-30 in size taken as 1e-30)."""
    det = a11 * a22 - a12 * a12
    if not abs(det) > 1e-30:
        det = 1e-30
    return 0.5 * (a22 * b1 - a12 * b2) / det, 0.5 * (a11 * b2 - a12 * b1) / det


@_njit
def cone_grid_best(
    grid: np.ndarray, cone: np.ndarray, axis: np.ndarray, rays: np.ndarray, ray_cone: np.ndarray, z: np.ndarray,
    huber: float,
) -> int:  # fmt: skip
    """:func:`cone_fit`'s grid search: the first row of ``grid`` (k, 4) whose :func:`huber_cost` of its
    :func:`cone_residuals` is least (-1 where none is finite), by :func:`_cone_grid_best_of` on the rays' columns."""
    r0, r1, r2 = _columns3(rays)
    return _cone_grid_best_of(grid, cone, axis, r0, r1, r2, ray_cone, z, huber)


#: :func:`_cone_grid_best_of`'s rays a block: the terms of a block are worked out in one vectorised loop, then added.
_GRID_BLOCK = 32


@_njit
def _cone_grid_best_of(
    grid: np.ndarray, cone: np.ndarray, axis: np.ndarray, r0: np.ndarray, r1: np.ndarray, r2: np.ndarray,
    ray_cone: np.ndarray, z: np.ndarray, huber: float,
) -> int:  # fmt: skip
    """:func:`cone_grid_best` of the rays' three columns (n,): each row's residuals and cost worked out as in
    :func:`cone_residuals` and :func:`huber_cost`, ray by ray in order, but a row given up once its cost so far
    reaches the least so far (issue 19, twentieth round: each term is at least 0, so a float sum never falls again,
    and a row whose cost is not below the least is not picked; about 60 % of the grid's rays on the benchmark
    frame's fits). Since stop 60 (issue 19) the terms of :data:`_GRID_BLOCK` rays at a time are worked out in a loop
    of their own (vectorised, as :func:`_cone_residuals_of`'s), then added in order, and a row is given up at the
    end of a block: the same terms, the same sums of those finished, the same pick (0.27 against 0.13 ms a
    benchmark frame, replayed)."""
    k, n = grid.shape[0], r0.shape[0]
    best, current = -1, np.inf
    terms = np.empty(_GRID_BLOCK)
    for j in range(k):
        e = math.exp(grid[j, 2])
        m0 = (axis[0] + grid[j, 0]) * e
        m1 = (axis[1] + grid[j, 1]) * e
        m2 = axis[2] * e
        c0 = m0 * cone[0, 0] + m1 * cone[1, 0] + m2 * cone[2, 0]
        c1 = m0 * cone[0, 1] + m1 * cone[1, 1] + m2 * cone[2, 1]
        c2 = m0 * cone[0, 2] + m1 * cone[1, 2] + m2 * cone[2, 2]
        qq = -(c0 * m0 + c1 * m1 + c2 * m2)
        total = 0.0
        if not qq > 0:  # an invalid ellipsoid's row: 0.05 throughout
            for _ in range(n):
                total += 0.5 * 0.05 * 0.05 if 0.05 <= huber else huber * (0.05 - 0.5 * huber)
                if total >= current:
                    break
        else:
            lam = qq / (1.0 + math.exp(-min(max(grid[j, 3], -50.0), 50.0)))
            gap = lam - qq
            for start in range(0, n, _GRID_BLOCK):
                size = min(_GRID_BLOCK, n - start)
                for t in range(size):
                    i = start + t
                    rcm = c0 * r0[i] + c1 * r1[i] + c2 * r2[i]
                    a = ray_cone[i] / lam - rcm * rcm / (lam * gap)
                    b = rcm / gap
                    c = -lam / gap
                    disc = b * b - a * c
                    res = z[i] - (b - math.sqrt(disc)) / a if disc >= 0 else np.nan
                    res = res if math.isfinite(res) else 0.02
                    r = abs(res)
                    terms[t] = 0.5 * res * res if r <= huber else huber * (r - 0.5 * huber)
                for t in range(size):
                    total += terms[t]
                if total >= current:
                    break
        if total < current:  # the first least, as np.argmin
            best, current = j, total
    return best


@_njit
def scaled_cloud(p: np.ndarray) -> tuple[np.ndarray, float, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`symfruit.core.fits.scaled_cloud` of a C-ordered (n, 3) float64 cloud, ``n >= 1``: its mean (3,)
    (:func:`column_means`), its scale (the root of the mean squared distance from the mean, numpy's pairwise sum;
    1 where that is 0), the centred and scaled points ``q`` (n, 3), the sphere fit's design ``[2 q, 1]`` (n, 4) and
    right-hand side ``|q|^2`` (n,) and the ellipsoid fit's design (n, 10), each value numpy's expressions' bit for bit
    (issue 19, twentieth round: the two fits' beginnings, once, in one call; 14 numpy calls a fit before)."""
    n = p.shape[0]
    mean = column_means(p)
    c = np.empty((n, 3))
    sq = np.empty(n)
    for i in range(n):
        x, y, z = p[i, 0] - mean[0], p[i, 1] - mean[1], p[i, 2] - mean[2]
        c[i, 0], c[i, 1], c[i, 2] = x, y, z
        sq[i] = x * x + y * y + z * z
    scale = math.sqrt((0.0 + _pairwise_sum(sq, 0, n)) / n)
    if scale == 0.0:
        scale = 1.0
    q = np.empty((n, 3))
    a = np.empty((n, 4))
    b = np.empty(n)
    d = np.empty((n, 10))
    for i in range(n):
        x, y, z = c[i, 0] / scale, c[i, 1] / scale, c[i, 2] / scale
        q[i, 0], q[i, 1], q[i, 2] = x, y, z
        a[i, 0], a[i, 1], a[i, 2], a[i, 3] = 2.0 * x, 2.0 * y, 2.0 * z, 1.0
        b[i] = x * x + y * y + z * z
        d[i, 0], d[i, 1], d[i, 2] = x * x, y * y, z * z
        d[i, 3], d[i, 4], d[i, 5] = 2.0 * y * z, 2.0 * x * z, 2.0 * x * y
        d[i, 6], d[i, 7], d[i, 8], d[i, 9] = 2.0 * x, 2.0 * y, 2.0 * z, 1.0
    return mean, scale, q, a, b, d


# --- issue 19, stop 41 (speedcand41): the candidates ---


@_njit
def _least_nan(x: np.ndarray) -> float:
    """``x.min()`` of a non-empty array: NaN where any value is."""
    m = x[0]
    for i in range(1, x.shape[0]):
        v = x[i]
        if m == m and (v < m or v != v):
            m = v
    return m


@_njit
def _greatest_nan(x: np.ndarray) -> float:
    """``x.max()`` of a non-empty array: NaN where any value is."""
    m = x[0]
    for i in range(1, x.shape[0]):
        v = x[i]
        if m == m and (v > m or v != v):
            m = v
    return m


@_njit
def revolution_box(
    point: np.ndarray, direction: np.ndarray, edges: np.ndarray, radii: np.ndarray, close: bool, flat: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`symfruit.core.fits.revolution_box` and the profile it is the box of in one call (issue 19, stop 41):
    ``(lo (3,), hi (3,), t (m,), r (m,))``, :func:`~symfruit.core.fits.closed_profile`'s ``t`` and ``r`` and
    :func:`~symfruit.core.fits._rings_box`'s box of their rings, each value the twin's (element by element the same
    operations; the boxes' least and greatest values, NaN where any is). ``flat``: :func:`~symfruit.core.fits._flat`,
    how far an end slice may fall short of the widest and still be closed by symmetry (issue 18, stop 42)."""
    b = radii.shape[0]
    mid = np.empty(b)
    count = 0
    for j in range(b):
        mid[j] = 0.5 * (edges[j] + edges[j + 1])
        count += math.isfinite(radii[j])
    t = np.empty(count)
    r = np.empty(count)
    k = 0
    for j in range(b):
        if math.isfinite(radii[j]):
            t[k], r[k] = mid[j], radii[j]
            k += 1
    if count < 2:
        t = np.empty(2)
        t[0], t[1] = edges[0], edges[b]
        r = np.zeros(2)
    else:
        widest = 0
        for j in range(1, count):  # np.argmax: the first greatest (every radius here is finite)
            if r[j] > r[widest]:
                widest = j
        floor = r[widest] - flat
        tail = True  # every radius from the widest to the last within ``flat`` of it
        for j in range(widest + 1, count):
            if not r[j] >= floor:
                tail = False
        head = True  # likewise from the first to the widest
        for j in range(widest):
            if not r[j] >= floor:
                head = False
        along = direction[2]
        endon = along * along >= 0.5  # the axis nearer the line of sight than the image plane
        tail = widest == count - 1 or (endon and along > 0 and tail)
        head = widest == 0 or (endon and along < 0 and head)
        if close and tail:
            t2, r2 = np.empty(2 * count - 1), np.empty(2 * count - 1)
            last = t[count - 1]
            for j in range(count):
                t2[j], r2[j] = t[j], r[j]
            for j in range(count - 1):  # 2 t[-1] - t[:-1][::-1]
                t2[count + j] = 2 * last - t[count - 2 - j]
                r2[count + j] = r[count - 2 - j]
            t, r = t2, r2
        elif close and head:
            t2, r2 = np.empty(2 * count - 1), np.empty(2 * count - 1)
            first = t[0]
            for j in range(count - 1):  # 2 t[0] - t[1:][::-1]
                t2[j] = 2 * first - t[count - 1 - j]
                r2[j] = r[count - 1 - j]
            for j in range(count):
                t2[count - 1 + j], r2[count - 1 + j] = t[j], r[j]
            t, r = t2, r2
    m = t.shape[0]
    lo = np.empty(3)
    hi = np.empty(3)
    low = np.empty(m)
    high = np.empty(m)
    for c in range(3):
        d = direction[c]
        spread = 1.0 - d * d  # direction**2
        spread = math.sqrt(spread if spread > 0.0 or spread != spread else 0.0)  # np.clip(..., 0.0, None)
        for j in range(m):
            centre = point[c] + t[j] * d
            reach = r[j] * spread
            low[j] = centre - reach
            high[j] = centre + reach
        lo[c] = _least_nan(low)
        hi[c] = _greatest_nan(high)
    return lo, hi, t, r


# --- issue 19, stop 42 (speedcomp42): the completion's per-call overhead ---------------------------------------


@_njit
def projected_box(points: np.ndarray, step: int, fx: float, fy: float, cx: float, cy: float) -> np.ndarray:
    """:func:`symfruit.core.candidates._projected_box`: ``(u_min - 0.5, v_min - 0.5, u_max + 0.5, v_max + 0.5)`` of the
    rows ``points[::step]`` (n, 3) projected by :meth:`~symfruit.core.camera.Camera.project`'s arithmetic
    (``fx * x * (1 / z) + cx``, left to right), in one pass without the (m, 2) array; NaN in a coordinate's two
    bounds where one of its values is (numpy's reductions propagate it). ``n >= 1``."""
    n = points.shape[0]
    out = np.empty(4)
    u_lo = v_lo = math.inf
    u_hi = v_hi = -math.inf
    nan_u = nan_v = False
    for i in range(0, n, step):
        inv_z = 1.0 / points[i, 2]
        u = fx * points[i, 0] * inv_z + cx
        v = fy * points[i, 1] * inv_z + cy
        if u != u:
            nan_u = True
        if v != v:
            nan_v = True
        u_lo = u if u < u_lo else u_lo
        u_hi = u if u > u_hi else u_hi
        v_lo = v if v < v_lo else v_lo
        v_hi = v if v > v_hi else v_hi
    if nan_u:
        u_lo = u_hi = math.nan
    if nan_v:
        v_lo = v_hi = math.nan
    out[0] = u_lo - 0.5
    out[1] = v_lo - 0.5
    out[2] = u_hi + 0.5
    out[3] = v_hi + 0.5
    return out


@_njit
def _column_bounds3(p: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> None:
    """:func:`column_bounds`' pass over an (n, 3) ``p``, ``n >= 1``: each column's least and greatest value into
    ``lo`` and ``hi`` (3,), NaN in both where the column holds a NaN; each column's values met in row order, as
    :func:`column_bounds` meets them one column at a time."""
    a0 = b0 = p[0, 0]
    a1 = b1 = p[0, 1]
    a2 = b2 = p[0, 2]
    n0 = n1 = n2 = 0.0  # NaN once a value of the column is
    for i in range(p.shape[0]):
        x, y, z = p[i, 0], p[i, 1], p[i, 2]
        a0 = x if x < a0 else a0
        b0 = x if x > b0 else b0
        n0 = n0 if x == x else x
        a1 = y if y < a1 else a1
        b1 = y if y > b1 else b1
        n1 = n1 if y == y else y
        a2 = z if z < a2 else a2
        b2 = z if z > b2 else b2
        n2 = n2 if z == z else z
    lo[0] = a0 if n0 == n0 else n0
    hi[0] = b0 if n0 == n0 else n0
    lo[1] = a1 if n1 == n1 else n1
    hi[1] = b1 if n1 == n1 else n1
    lo[2] = a2 if n2 == n2 else n2
    hi[2] = b2 if n2 == n2 else n2


# --- stop 43, speedcomp43: the noise measure's neighbourhoods from a grid ------------------------------------------


@_njit
def _grid_read(
    sx: np.ndarray, sy: np.ndarray, sz: np.ndarray, sj: np.ndarray, starts: np.ndarray, d1: int, d2: int, x: float,
    y: float, z: float, n0: int, m0: int, n1: int, m1: int, n2: int, m2: int, a0: int, b0: int, a1: int, b1: int,
    a2: int, b2: int, skip: bool, count: int, cand_d: np.ndarray, cand_j: np.ndarray,
) -> int:  # fmt: skip
    """:func:`grid_covariances`' read of the cells ``[n0, m0] x [n1, m1] x [n2, m2]`` (those of ``[a0, b0] x [a1, b1]
    x [a2, b2]`` left out where ``skip``: read before): each point's squared distance to ``(x, y, z)`` (the brute
    force's sum) and index appended to ``cand_d``, ``cand_j`` after their first ``count``; returns the new count."""
    for i0 in range(n0, m0 + 1):
        for i1 in range(n1, m1 + 1):
            row = (i0 * d1 + i1) * d2
            if skip and a0 <= i0 <= b0 and a1 <= i1 <= b1:  # the cells of this column outside [a2, b2]
                spans = ((n2, a2 - 1), (b2 + 1, m2))
            else:
                spans = ((n2, m2), (0, -1))
            for lo2, hi2 in spans:
                if lo2 > hi2:
                    continue
                for t in range(starts[row + lo2], starts[row + hi2 + 1]):
                    dx, dy, dz = sx[t] - x, sy[t] - y, sz[t] - z
                    cand_d[count] = dx * dx + dy * dy + dz * dz
                    cand_j[count] = sj[t]
                    count += 1
    return count


@_njit
def grid_covariances(points: np.ndarray, step: int, small: int, large: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`neighbour_covariances` (its numpy twin :func:`symfruit.core.fits._neighbour_covariances`) with each
    query's distances taken only to the points of the grid cells about it: the same neighbourhoods in the same
    order, so the same covariances to the bit. The cells are cubes of 1.5 times the radius that holds ``large``
    points on a surface as wide as the cloud's two larger extents (a fruit's seen side). A query first reads the
    ``3^3`` cells about its own (more rings of cells until they hold ``large`` points); the ``large``-th least of
    those distances (:func:`kth_smallest`) bounds the brute force's, so every point as near as the brute force's
    ``large``-th lies in the box of that distance about the query (plus a millionth of a cell for rounding: a
    cell's index is monotone in the coordinate), whose cells are read next; the ``large``-th least of all those
    read is then the brute force's. The points no farther are put in order of their distance, ties by index, as
    the brute force's insertion in index order puts them. A cloud with a coordinate not finite, of zero extent, or
    whose grid would have over ``4 n + 64`` cells goes to :func:`neighbour_covariances` whole (stop 43: a
    benchmark frame's nine calls 1.41 against 1.01-1.06 ms of thread CPU; 1.0 or 2.0 times the radius were
    slower: more rings or more points read). Each ``large``-th is taken from the candidates no farther than a bound
    known to hold ``large`` of them (issue 19, stop 60, revol60: the same value; 0.77 against 0.68 ms a benchmark
    frame's ``noise_measures``, replayed)."""
    n = points.shape[0]
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for i in range(n):
        for a in range(3):
            v = points[i, a]
            if not math.isfinite(v):
                return neighbour_covariances(points, step, small, large)
            lo[a] = min(lo[a], v)
            hi[a] = max(hi[a], v)
    ext = np.sort(hi - lo)  # least first
    if ext[1] > 0.0:
        area = ext[2] * ext[1]
    else:  # on a line: as wide as it is long over the points' count
        area = ext[2] * ext[2] / n
    h = 1.5 * math.sqrt(area * large / (math.pi * n))
    if not (h > 0.0 and math.isfinite(h)):
        return neighbour_covariances(points, step, small, large)
    inv_h = 1.0 / h
    dims = np.empty(3, np.int64)
    total = 1.0
    for a in range(3):
        d = (hi[a] - lo[a]) * inv_h
        if not d < 4.0 * n + 64.0:
            return neighbour_covariances(points, step, small, large)
        dims[a] = int(d) + 1
        total *= dims[a]
    if total > 4.0 * n + 64.0:
        return neighbour_covariances(points, step, small, large)
    d0, d1, d2 = dims[0], dims[1], dims[2]
    cell = np.empty((n, 3), np.int64)
    starts = np.zeros(d0 * d1 * d2 + 1, np.int64)
    for i in range(n):
        for a in range(3):
            cell[i, a] = min(int((points[i, a] - lo[a]) * inv_h), dims[a] - 1)
        starts[(cell[i, 0] * d1 + cell[i, 1]) * d2 + cell[i, 2] + 1] += 1
    for c in range(d0 * d1 * d2):
        starts[c + 1] += starts[c]
    fill = starts[:-1].copy()
    sx = np.empty(n)
    sy = np.empty(n)
    sz = np.empty(n)
    sj = np.empty(n, np.int64)
    for i in range(n):  # the points by cell, each cell's in index order
        c = (cell[i, 0] * d1 + cell[i, 1]) * d2 + cell[i, 2]
        t = fill[c]
        fill[c] += 1
        sx[t], sy[t], sz[t], sj[t] = points[i, 0], points[i, 1], points[i, 2], i
    m = (n + step - 1) // step
    out_small = np.empty((m, 3, 3))
    out_large = np.empty((m, 3, 3))
    cand_d = np.empty(n)
    cand_j = np.empty(n, np.int64)
    best_d = np.empty(n)
    best_i = np.empty(n, np.int64)
    scratch_a = np.empty(n)
    scratch_b = np.empty(n)
    scatter = np.empty((3, 3))
    near_d = np.empty(n)
    near_j = np.empty(n, np.int64)
    margin = 1e-6 * h
    guess = 2.0 * (h / 1.5) ** 2
    for q in range(m):
        x, y, z = points[q * step, 0], points[q * step, 1], points[q * step, 2]
        c0, c1, c2 = cell[q * step, 0], cell[q * step, 1], cell[q * step, 2]
        count = 0
        reach = 1
        a0 = b0 = c0
        a1 = b1 = c1
        a2 = b2 = c2
        while count < large:  # a block of cells about the query's own with at least large points
            n0, m0 = max(c0 - reach, 0), min(c0 + reach, d0 - 1)
            n1, m1 = max(c1 - reach, 0), min(c1 + reach, d1 - 1)
            n2, m2 = max(c2 - reach, 0), min(c2 + reach, d2 - 1)
            count = _grid_read(sx, sy, sz, sj, starts, d1, d2, x, y, z, n0, m0, n1, m1, n2, m2, a0, b0, a1, b1,
                               a2, b2, reach > 1, count, cand_d, cand_j)  # fmt: skip
            a0, b0, a1, b1, a2, b2 = n0, m0, n1, m1, n2, m2
            reach += 1
        # every point as near as the large-th of those lies within the box of that distance about the query
        # (the large-th of those no farther than a guess, where at least large are: the same value, since every one
        # beyond the guess is beyond it; the guess twice the squared radius that holds large points on the cloud's
        # surface, the grid's own, about twice large points; issue 19, stop 60, revol60)
        within = 0
        for t in range(count):
            d = cand_d[t]
            near_d[within] = d
            within += d <= guess
        if within >= large:
            limit = kth_smallest(near_d[:within], large - 1, scratch_a, scratch_b)
        else:
            limit = kth_smallest(cand_d[:count], large - 1, scratch_a, scratch_b)
        r = math.sqrt(limit) + margin
        n0 = max(min(int((x - r - lo[0]) * inv_h), d0 - 1), 0)
        n1 = max(min(int((y - r - lo[1]) * inv_h), d1 - 1), 0)
        n2 = max(min(int((z - r - lo[2]) * inv_h), d2 - 1), 0)
        m0 = max(min(int((x + r - lo[0]) * inv_h), d0 - 1), 0)
        m1 = max(min(int((y + r - lo[1]) * inv_h), d1 - 1), 0)
        m2 = max(min(int((z + r - lo[2]) * inv_h), d2 - 1), 0)
        read = count
        count = _grid_read(sx, sy, sz, sj, starts, d1, d2, x, y, z, min(n0, a0), max(m0, b0), min(n1, a1),
                           max(m1, b1), min(n2, a2), max(m2, b2), a0, b0, a1, b1, a2, b2, True, count, cand_d,
                           cand_j)  # fmt: skip
        # those within the block's large-th first gathered without a branch (every one written, the count advanced
        # by the comparison: most are beyond it, at random; issue 19, stop 60), in the candidates' order
        within = 0
        for t in range(count):
            d = cand_d[t]
            near_d[within] = d
            near_j[within] = cand_j[t]
            within += d <= limit
        if count > read:  # (none more: the block's large-th is the large-th of all)
            # the large-th of all is the large-th of those gathered (issue 19, stop 60, revol60): at least large of
            # them (the block's large least) are no farther than the block's large-th, which is at least the
            # large-th of all, and every one the farther is beyond it; so the same value, from a fifth of the
            # candidates or so
            limit = kth_smallest(near_d[:within], large - 1, scratch_a, scratch_b)
            kept = 0
            for t in range(within):  # those within the limit of all, in the same order
                d = near_d[t]
                near_d[kept] = d
                near_j[kept] = near_j[t]
                kept += d <= limit
            within = kept
        # then put in order of distance, ties by index (an order of distinct pairs, each point read once): each one's
        # place the count of those before it in that order, a loop without a branch that the processor's vector
        # instructions run, in place of an insertion sort's (issue 19, stop 60, revol60: the same order; 0.68 against
        # 0.61 ms a benchmark frame's noise_measures, replayed); the insertion sort kept where ties at the limit leave
        # over four times large within it (a lattice's: the count's cost goes as their square, the sort's as their
        # number where they come nearly in order)
        if within <= 4 * large:
            for t in range(within):
                d = near_d[t]
                j = near_j[t]
                place = 0
                for w in range(within):
                    e = near_d[w]
                    place += (e < d) | ((e == d) & (near_j[w] < j))
                if place < large:  # (only the large nearest are read)
                    best_i[place] = j
        else:
            for t in range(within):
                d = near_d[t]
                j = near_j[t]
                slot = t
                while slot > 0 and (best_d[slot - 1] > d or (best_d[slot - 1] == d and best_i[slot - 1] > j)):
                    best_d[slot] = best_d[slot - 1]
                    best_i[slot] = best_i[slot - 1]
                    slot -= 1
                best_d[slot] = d
                best_i[slot] = j
        _covariances_at(points, best_i, small, large, scatter, out_small, out_large, q)
    return out_small, out_large


# --- issue 19, sixteenth round: extraction's clustering and a fruit's depth mode ---------------------------------


@_njit
def clusters(points: np.ndarray, distance: float) -> tuple[np.ndarray, bool]:
    """:func:`symfruit.extract.cluster` of ``points`` (n, 3) float64: each point's cluster, 0 the largest, and True;
    or an empty array and False where the twin is to run instead (a depth slab's grid of cubes over 2e7 cells,
    whose clusters the twin links through a tree and numbers otherwise, or a coordinate that is not finite).

    The twin's steps on the same values: the points cut into slabs where consecutive depths (in their order) differ
    by more than ``distance`` (:func:`_depth_slabs`); in each slab the cubes of side ``distance / 2`` from the slab's
    least corner (the same subtraction, division and floor), the occupied cubes numbered as ``ndimage.label``
    numbers them with the 26-neighbourhood (by the first cube of each cluster in the grid's raster order: a flood
    fill from each unnumbered occupied cube met in that order); the clusters ranked by a stable sort of their sizes,
    largest first. The same labels.

    Since issue 19's stop 62 (reg62): the slabs come from buckets of the depths, not a sort (a slab's cubes and
    clusters do not depend on the order of its points: only which points it holds), and the grid is padded by one
    empty cube on every side, so a cube's 26 neighbours are fixed flat offsets away with no bounds tests and no
    divisions (the padded grid's raster order is the grid's: the same clusters, numbered alike)."""
    n = points.shape[0]
    empty = np.zeros(0, np.int64)
    for i in range(n):
        for j in range(3):
            if not math.isfinite(points[i, j]):
                return empty, False
    if n == 0:
        return empty, True
    voxel = distance / 2.0
    order, ends = _depth_slabs(points, distance)
    labels = np.empty(n, np.int64)
    offsets = np.empty(26, np.int64)
    next_label = 0
    lo = 0
    for hi in ends:
        if hi - lo == 1:
            labels[order[lo]] = next_label
            next_label += 1
            lo = hi
            continue
        least = np.empty(3)
        for j in range(3):
            least[j] = points[order[lo], j]
        for k in range(lo + 1, hi):
            for j in range(3):
                least[j] = min(least[j], points[order[k], j])
        cx, cy, cz = np.empty(hi - lo, np.int64), np.empty(hi - lo, np.int64), np.empty(hi - lo, np.int64)
        a, b, d = 0, 0, 0
        for k in range(lo, hi):
            p = order[k]
            x = np.int64(math.floor((points[p, 0] - least[0]) / voxel))
            y = np.int64(math.floor((points[p, 1] - least[1]) / voxel))
            z = np.int64(math.floor((points[p, 2] - least[2]) / voxel))
            cx[k - lo], cy[k - lo], cz[k - lo] = x, y, z
            a, b, d = max(a, x), max(b, y), max(d, z)
        a, b, d = a + 1, b + 1, d + 1
        if float(a) * float(b) * float(d) > 2e7:
            return empty, False
        pb, pd = b + 2, d + 2  # the padded grid's sizes along y and z
        grid = np.zeros((a + 2) * pb * pd, np.int64)  # 0: empty, -1: occupied, k > 0: cluster k
        cells = np.empty(hi - lo, np.int64)
        for k in range(hi - lo):
            cells[k] = ((cx[k] + 1) * pb + cy[k] + 1) * pd + cz[k] + 1
            grid[cells[k]] = -1
        m = 0
        for dx in range(-1, 2):
            for dy in range(-1, 2):
                for dz in range(-1, 2):
                    if dx != 0 or dy != 0 or dz != 0:
                        offsets[m] = (dx * pb + dy) * pd + dz
                        m += 1
        stack = np.empty(hi - lo, np.int64)  # each occupied cube is pushed once
        count = 0
        for x in range(1, a + 1):
            for y in range(1, b + 1):
                row = (x * pb + y) * pd
                for f in range(row + 1, row + d + 1):
                    if grid[f] != -1:
                        continue
                    count += 1
                    grid[f] = count
                    stack[0] = f
                    size = 1
                    while size > 0:
                        size -= 1
                        g = stack[size]
                        for o in range(26):
                            e = g + offsets[o]
                            if grid[e] == -1:
                                grid[e] = count
                                stack[size] = e
                                size += 1
        for k in range(hi - lo):
            labels[order[lo + k]] = grid[cells[k]] - 1 + next_label
        next_label += count
        lo = hi
    counts = np.zeros(next_label, np.int64)
    for i in range(n):
        counts[labels[i]] += 1
    rank = np.empty(next_label, np.int64)
    by_size = np.argsort(-counts, kind="mergesort")
    for r in range(next_label):
        rank[by_size[r]] = r
    out = np.empty(n, np.int64)
    for i in range(n):
        out[i] = rank[labels[i]]
    return out, True


@_njit_inlined
def _count_below(z: np.ndarray, x: float, right: bool) -> int:
    """``np.searchsorted(z, x, side)`` of sorted ``z`` without NaN: how many values are below ``x`` (``right``: at
    most ``x``), by bisection."""
    lo, hi = 0, z.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if z[mid] < x or (right and z[mid] == x):
            lo = mid + 1
        else:
            hi = mid
    return lo


@_njit_inlined
def _leaf_share(z: np.ndarray, kept: np.ndarray, leaf: np.ndarray, edges: np.ndarray, k: int, n_bins: int) -> float:
    """:func:`symfruit.core.surface.fruit_depth`'s ``leaf_share(k)``: the same counts, the same quotient. The depths
    between the edges counted on ``z``, the depths sorted, by bisection, or where ``z`` is empty on ``kept`` by a pass
    (:func:`depth_mode`, stop 51): the same whole numbers."""
    lo, hi = edges[max(k - 1, 0)], edges[min(k + 2, n_bins)]
    count = 0
    if z.shape[0] > 0:
        between = _count_below(z, hi, True) - _count_below(z, lo, False)
        if between < 10:
            return 0.0
        for j in range(kept.shape[0]):
            if leaf[j] and kept[j] >= lo and kept[j] <= hi:
                count += 1
    else:  # both counts in the one pass (the depths from lo to hi, lo <= hi: as many as the sorted ones between)
        between = 0
        for j in range(kept.shape[0]):
            inside = kept[j] >= lo and kept[j] <= hi
            between += inside
            count += leaf[j] and inside
        if between < 10:
            return 0.0
    return count / between


@_njit
def fruit_depth(
    z: np.ndarray, kept: np.ndarray, radius_px: float, focal: float, noise: float, leaf: np.ndarray, with_leafy: bool,
    leafy_shares: tuple[float, float],
) -> tuple[float, float, bool]:  # fmt: skip
    """:func:`symfruit.core.surface.fruit_depth` from its valid depths ``kept`` (n,) float64 as they are and sorted
    (``z``; numpy's sort is the faster), ``leaf`` (n,) bool aligned with ``kept`` where ``with_leafy``
    (``leafy_shares``: its :data:`~symfruit.core.surface.LEAFY`): ``(front, radius, True)``, or ``(nan, nan, False)``
    where the twin is to run instead (a histogram range numpy widens; no depth between the front bin's edges). The
    twin's steps on the same values: the median, the bin width (Python's ``max`` and ``min``: the same choices), the
    edges as ``np.linspace`` makes them (``i * step + lo``, the last one ``hi``), the counts between them by
    bisection, the three-bin masses (``np.convolve``'s ``"same"`` window of sums of whole numbers: exact), the
    peaks, the leaf test's shares (the same counts and quotients), the walk nearer and the 5 % quantile's
    interpolation: the same numbers, bit for bit."""
    n = z.shape[0]
    if n < 10:
        return np.nan, np.nan, True
    half = n // 2
    median = z[half] if n % 2 else (z[half - 1] + z[half]) / 2.0
    ok, n_bins, _, edges = _mode_edges(z[0], z[n - 1], median, radius_px, focal, noise)
    if not ok:
        return np.nan, np.nan, False
    at = np.empty(n_bins + 1, np.int64)
    for k in range(n_bins):
        at[k] = _count_below(z, edges[k], False)
    at[n_bins] = _count_below(z, edges[n_bins], True)
    found, a_edge, b_edge = _mode_bin(at, n, z, kept, leaf, edges, with_leafy, leafy_shares)
    if not found:
        return np.nan, np.nan, False
    a, b = _count_below(z, a_edge, False), _count_below(z, b_edge, True)
    size = b - a
    if size < 1:
        return np.nan, np.nan, False
    if size == 1:
        front = z[a]
    else:
        where = (size - 1) * 0.05
        below = np.int64(np.floor(where))
        t = where - below
        za, zb = z[a + below], z[a + below + 1]
        front = zb - (zb - za) * (1.0 - t) if t >= 0.5 else za + (zb - za) * t
    return front, radius_px * front / focal, True


@_njit
def surface_apex(
    own: np.ndarray, iterations: int, near: np.ndarray, depth: np.ndarray, mask: np.ndarray, r0: int, c0: int,
    size: int,
) -> tuple[int, int]:  # fmt: skip
    """:func:`symfruit.core.surface.fruit_surface`'s apex: row and column (in the window) of the first least ``size``
    x ``size`` median (edges repeated) of the window's depth where ``near`` (+inf elsewhere) among the core pixels:
    the mask's box ``own`` (at ``r0``, ``c0`` in the window) eroded ``iterations`` times by the cross (beyond the box
    not in it: :func:`symfruit.core.raster.eroded`) and ``near``; without any, the pixels of ``near`` and ``mask``,
    or of ``near``. The twin's pixels in its (raster) order and :func:`least_median`'s pass: the same pixel.

    Since issue 19's nineteenth round the erosion is one taxicab distance map of the box instead of ``iterations``
    passes: eroding by the cross ``k`` times keeps the pixels whose every pixel within ``k`` steps along rows and
    columns is the mask's, those farther than ``k`` steps from a pixel not the mask's (or beyond the box), and the
    city-block chamfer's two sweeps give those distances exactly (:func:`taxicab_within`'s, capped past ``k``).

    Since stop 64 (ext64) the erosion is ``iterations`` passes of the cross again, over a uint8 copy of the box
    framed by a pixel not the mask's (beyond the box not in it): each pass an and of five reads that the compiler
    runs on many pixels at once, where the chamfer's row sweeps carried a running count from pixel to pixel (2.4
    against about 5 us a fruit on the benchmark frame's boxes). A pixel is kept by ``k`` passes of the cross exactly
    where every pixel within ``k`` taxicab steps is the mask's, the distance map's test: the same pixels, gathered
    in the same raster order."""
    bh, bw = own.shape
    a = np.zeros((bh + 2, bw + 2), np.uint8)
    b = np.zeros((bh + 2, bw + 2), np.uint8)
    for r in range(bh):
        for c in range(bw):
            a[r + 1, c + 1] = own[r, c]
    for _ in range(iterations):
        for r in range(1, bh + 1):
            for c in range(1, bw + 1):
                b[r, c] = a[r, c] & a[r - 1, c] & a[r + 1, c] & a[r, c - 1] & a[r, c + 1]
        a, b = b, a
    h, w = near.shape
    rows = np.empty(h * w, np.int64)
    cols = np.empty(h * w, np.int64)
    n = 0
    for r in range(bh):
        for c in range(bw):
            if a[r + 1, c + 1] and near[r + r0, c + c0]:
                rows[n], cols[n] = r + r0, c + c0
                n += 1
    if n == 0:
        both = False
        for r in range(h):
            for c in range(w):
                both = both or (near[r, c] and mask[r, c])
        for r in range(h):
            for c in range(w):
                if near[r, c] and (mask[r, c] or not both):
                    rows[n], cols[n] = r, c
                    n += 1
    best = _least_median_of(depth, near, True, rows, cols, n, size)
    return rows[best], cols[best]


@_njit
def depth_step(depth: np.ndarray, mask: np.ndarray) -> float:
    """:func:`symfruit.core.surface.depth_step`: the least non-zero ``|right - left|`` of horizontally neighbouring
    pixels of ``mask`` that both hold depth (``> 0``), 0 with none. The twin's differences (NaN ones left out, as its
    ``> 0`` leaves them): the same least, bit for bit."""
    h, w = depth.shape
    best = np.inf
    found = False
    for r in range(h):
        for c in range(w - 1):
            a, b = depth[r, c + 1], depth[r, c]
            if mask[r, c + 1] and mask[r, c] and a > 0 and b > 0:
                d = abs(a - b)
                if d > 0 and (not found or d < best):
                    best, found = d, True
    return float(best) if found else 0.0


@_njit
def near_pixels(depth: np.ndarray, region: np.ndarray, low: float, high: float, out: np.ndarray) -> bool:
    """``out`` (h, w) bool: :func:`symfruit.core.surface.fruit_surface`'s pixels of ``region`` with depth (``depth``
    made 0 where it has none) within ``low`` .. ``high``, the twin's comparisons; whether there is any."""
    h, w = depth.shape
    some = False
    for r in range(h):
        for c in range(w):
            # the four tests and'ed without a jump (stop 60, speeds60: the compiler runs the row on several pixels
            # at once; the same comparisons, so the same pixels)
            z = depth[r, c]
            hit = region[r, c] & (z > 0) & (z >= low) & (z <= high)
            out[r, c] = hit
            some |= hit
    return some


# --- issue 19, twentieth round (stop 40): the occlusion maps in one pass ---


@_njit
def _occlusion_box(
    uv: np.ndarray,
    points: np.ndarray,
    pad: int,
    depth: np.ndarray,
    mask: np.ndarray,
    others: np.ndarray,
    tolerance: float,
    steps: np.ndarray,
) -> tuple[bool, int, int, np.ndarray, np.ndarray, np.ndarray, int, int]:  # fmt: skip
    """:func:`occlusion_at`, with the points' own depths over their pixels' box and the box's top-left pixel in the
    window: ``(found, u0, v0, hidden, seen, own_z, p0, q0)`` (stop 42: the occlusion kernel, ``occlusion_edge_boxed``
    from stop 45 to stop 60, read them instead of projecting the points again)."""
    height, width = mask.shape
    n = uv.shape[0]
    cmin, cmax, rmin, rmax = width, -1, height, -1
    low, high = np.inf, -np.inf
    for i in range(n):
        z = points[i, 2]
        low, high = min(low, z), max(high, z)
        u, v = np.rint(uv[i, 0]), np.rint(uv[i, 1])
        if u >= 0 and u < width and v >= 0 and v < height:
            c, r = int(u), int(v)
            cmin, cmax, rmin, rmax = min(cmin, c), max(cmax, c), min(rmin, r), max(rmax, r)
    if cmax < 0:
        return False, 0, 0, np.empty((0, 0), np.bool_), np.empty((0, 0)), np.empty((0, 0)), 0, 0
    span_u, span_v = cmax - cmin + pad, rmax - rmin + pad
    u0, v0 = max(cmin - span_u, 0), max(rmin - span_v, 0)
    u1, v1 = min(cmax + span_u + 1, width), min(rmax + span_v + 1, height)
    h, w = v1 - v0, u1 - u0
    p0, p1, q0, q1 = rmin - v0, rmax + 1 - v0, cmin - u0, cmax + 1 - u0  # the point pixels' box in the window
    mb, nb = p1 - p0, q1 - q0
    own_z = np.full((mb, nb), np.inf)
    for i in range(n):
        u, v = np.rint(uv[i, 0]), np.rint(uv[i, 1])
        if u >= 0 and u < width and v >= 0 and v < height:
            r, c = int(v) - rmin, int(u) - cmin
            z = points[i, 2]
            if z < own_z[r, c]:
                own_z[r, c] = z
    hidden = np.empty((h, w), np.bool_)
    seen = np.empty((h, w))
    _occlusion_pass(depth, mask, others, v0, u0, own_z, p0, q0, tolerance, steps, low, high, hidden, seen)
    return True, u0, v0, hidden, seen, own_z, p0, q0


@_njit
def occlusion_at(
    uv: np.ndarray,
    points: np.ndarray,
    pad: int,
    depth: np.ndarray,
    mask: np.ndarray,
    others: np.ndarray,
    tolerance: float,
    steps: np.ndarray,
) -> tuple[bool, int, int, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`own_depths` then :func:`occlusion_window` in one kernel (issue 19, twentieth round): ``depth``, ``mask``
    and ``others`` (or (0, 0)) are the whole (H, W) images, read in place; the points' own depths are kept over their
    pixels' box alone (no pixel outside it holds one), not as an (h, w) map of +inf the window pass reads again.
    ``(found, u0, v0, hidden, seen)``: the window's top-left pixel and its maps, :func:`occlusion_window`'s to the
    bit (``low`` and ``high`` the points' least and greatest depth, all of them); found False when no point falls
    in the image. Since stop 42 the window's pass is :func:`occlusion_window`'s own (:func:`_occlusion_pass`, on
    the images' window in place)."""
    found, u0, v0, hidden, seen, _, _, _ = _occlusion_box(uv, points, pad, depth, mask, others, tolerance, steps)
    return found, u0, v0, hidden, seen


@_njit
def _reach_fill(
    join: np.ndarray, seen: np.ndarray, s0: int, s1: int, t0: int, t1: int, stack: np.ndarray
) -> tuple[bool, int, int, int, int]:  # fmt: skip
    """:func:`_reach_box`'s fill with the pending runs' seeds on ``stack`` (k,) int64, its length fixed: ``(ok, r0, r1,
    c0, c1)``, ok False (and no box) when the fill needed more than ``k`` pending seeds. Until stop 48 the fill grew
    its stack by ``np.concatenate`` in the loop, and the stack's reassignment there made every pass of the loop about
    four times slower (the benchmark frame's 9 fills 0.60 against 0.15 ms, docs/occspeed48.md); the same steps in
    the same order otherwise, so the same box. Since stop 65 (look65) the pixels a run may still take are one map,
    ``avail`` (``join`` copied, the seen pixels, all within their box, cleared), each pixel cleared as it is
    reached: one read where ``not reached and join and not seen`` made three, and the copy where the reached map
    was zeroed. ``avail`` is that test's value at every step, so the same steps and the same box."""
    h, w = join.shape
    avail = join.copy()  # join's pixels not seen and not reached yet (the seen ones lie within their box)
    for r in range(s0, s1):
        for c in range(t0, t1):
            avail[r, c] = avail[r, c] and not seen[r, c]
    cap = stack.shape[0]
    top = 0
    r0, r1, c0, c1 = s0, s1, t0, t1
    for r in range(max(s0 - 1, 0), min(s1 + 1, h)):
        for c in range(max(t0 - 1, 0), min(t1 + 1, w)):
            if not avail[r, c]:
                continue
            beside = False
            for rr in range(max(r - 1, 0), min(r + 2, h)):
                for cc in range(max(c - 1, 0), min(c + 2, w)):
                    if seen[rr, cc]:
                        beside = True
            if beside:
                if top == cap:
                    return False, 0, 0, 0, 0
                stack[top] = r * w + c
                top += 1
    while top > 0:
        top -= 1
        r, c = divmod(stack[top], w)
        if not avail[r, c]:  # reached since it was pushed
            continue
        # the run through (r, c) of pixels the fill may cross, not reached yet
        a = c
        while a > 0 and avail[r, a - 1]:
            a -= 1
        b = c + 1
        while b < w and avail[r, b]:
            b += 1
        for x in range(a, b):
            avail[r, x] = False
        r0, r1 = min(r0, r), max(r1, r + 1)
        c0, c1 = min(c0, a), max(c1, b)
        for rr in (r - 1, r + 1):  # the new runs it touches above and below (one seed a run)
            if rr < 0 or rr >= h:
                continue
            inside = False
            for x in range(max(a - 1, 0), min(b + 1, w)):
                ok = avail[rr, x]
                if ok and not inside:
                    if top == cap:
                        return False, 0, 0, 0, 0
                    stack[top] = rr * w + x
                    top += 1
                inside = ok
    return True, r0, r1, c0, c1


@_njit
def _reach_box(join: np.ndarray, seen: np.ndarray, s0: int, s1: int, t0: int, t1: int) -> tuple[int, int, int, int]:
    """:func:`_flood_box`'s box alone, from the fill's edge and by runs (issue 19, twentieth round): the pixels a fill
    from the ``seen`` ones (all within ``s0:s1, t0:t1``) reaches over ``join`` are the seen ones and the pixels of
    ``join`` not seen that are 8-connected through such pixels to one beside a seen pixel (a path through a seen
    pixel starts again beside it). So the fill starts from those beside the seen ones, never visits the seen
    pixels' insides, and takes a row's run of such pixels at once (a scanline fill: the runs of the rows above and
    below that touch it, diagonals included, are its neighbours). ``(r0, r1, c0, c1)``, stops exclusive:
    :func:`_flood_box`'s."""
    # stop 48: a fixed stack (:func:`_reach_fill`); 1,024 seeds hold every fill of the benchmark frame (at most 263
    # pushed). Each pixel is pushed at most once from the seen pixels' edge and, for a run of L pixels, at most
    # L + 3 <= 4 L times from it (one seed a run of the rows above and below it within L + 2 columns): 5 h w always
    # suffices, so the second try never fails.
    h, w = join.shape
    ok, r0, r1, c0, c1 = _reach_fill(join, seen, s0, s1, t0, t1, np.empty(1024, np.int64))
    if not ok:
        ok, r0, r1, c0, c1 = _reach_fill(join, seen, s0, s1, t0, t1, np.empty(5 * h * w + 16, np.int64))
    return r0, r1, c0, c1


@_njit
def monotone_table(
    depth: np.ndarray, rows: np.ndarray, cols: np.ndarray, dy: np.ndarray, dx: np.ndarray, table: np.ndarray,
    reach: int, bins: int, tolerance: float, out: np.ndarray,
) -> None:  # fmt: skip
    """:func:`monotone_rays` with each pixel's sector read from ``table`` (2 reach + 1, 2 reach + 1), the sector of
    every offset ``(dy, dx)`` within ``reach`` as :func:`monotone_rays` works it out from numpy's ``arctan2``
    (:func:`symfruit.core.surface._sector_table`), instead of numpy's ``arctan2`` of every pixel (issue 19, twentieth
    round). The same sectors, so the same pixels."""
    n = rows.shape[0]
    sector = np.empty(n, np.int64)
    d2 = np.empty(n, np.int64)
    for i in range(n):
        a, b = np.int64(dy[i]), np.int64(dx[i])
        sector[i] = np.int64(table[a + reach, b + reach])
        d2[i] = a * a + b * b
    monotone(depth, rows, cols, sector, d2, bins, tolerance, out)


@_njit
def _depth_slabs(points: np.ndarray, distance: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`clusters`' slabs of ``points`` (n, 3, n >= 1, finite): an order of the points (n,) in which the slabs
    are runs, ascending in depth, and each run's end ``(m,)`` (the last ``n``). A slab ends where the next depth
    in ascending order (``points[:, 2]``) lies more than ``distance`` beyond it (the twin's
    ``np.diff(sorted) > distance``).

    Issue 19, stop 62 (reg62), instead of a stable sort: the depths are put in buckets a quarter ``distance`` wide
    from the least (bucket ``floor((z - least) / width)``, the last one closed). The bucket is monotone in the depth
    as rounded, so every depth of a bucket is at most every depth of a later one, and the sorted depths are the
    buckets' depths bucket after bucket: the pairs of consecutive sorted depths that straddle two buckets are a
    bucket's greatest depth and the next non-empty bucket's least, and those within a bucket differ by about a
    quarter ``distance`` (never more than ``distance``). So the slabs end at the same points, and each holds the
    same points (in bucket order, not sorted within a bucket: a slab's cubes and clusters do not depend on it). Where
    the buckets would outnumber four points each (a few far points) or ``distance`` is not above 0, by the stable
    sort."""
    n = points.shape[0]
    lo, hi = points[0, 2], points[0, 2]
    for i in range(1, n):
        lo, hi = min(lo, points[i, 2]), max(hi, points[i, 2])
    width = distance / 4.0
    span = (hi - lo) / width
    if not (distance > 0.0 and span < 4 * n + 16):
        order = np.argsort(points[:, 2], kind="mergesort")
        ends = np.empty(n, np.int64)
        m = 0
        for k in range(1, n):
            if points[order[k], 2] - points[order[k - 1], 2] > distance:
                ends[m] = k
                m += 1
        ends[m] = n
        return order, ends[: m + 1]
    bins = np.int64(math.floor(span)) + 1
    start = np.zeros(bins + 1, np.int64)  # counts, then each bucket's first place in the order
    least = np.full(bins, np.inf)
    most = np.full(bins, -np.inf)
    at = np.empty(n, np.int64)
    for i in range(n):
        z = points[i, 2]
        k = min(np.int64(math.floor((z - lo) / width)), bins - 1)
        at[i] = k
        start[k + 1] += 1
        least[k] = min(least[k], z)
        most[k] = max(most[k], z)
    for k in range(bins):
        start[k + 1] += start[k]
    ends = np.empty(bins, np.int64)
    m = 0
    last = -1  # the last non-empty bucket
    for k in range(bins):
        if start[k + 1] == start[k]:
            continue
        if last >= 0 and least[k] - most[last] > distance:
            ends[m] = start[k]
            m += 1
        last = k
    ends[m] = n
    order = np.empty(n, np.int64)
    for i in range(n):
        order[start[at[i]]] = i
        start[at[i]] += 1
    return order, ends[: m + 1]


# --- issue 19, stop 41 (speedext41): the occlusion's own edge, and the occlusion in one call ---


@_njit
def _row_min(x: np.ndarray, k: int, out: np.ndarray) -> None:
    """``out`` (h, w): the least of ``x`` (h, w) over the ``2 k + 1`` pixels of its row about each pixel, +inf
    outside the array (``ndimage.minimum_filter1d`` along the rows, ``mode="constant", cval=inf``; a least is exact in
    any order), by van Herk's blocks: the least from each block's start and to each block's end."""
    h, w = x.shape
    size = 2 * k + 1
    n = w + 2 * k  # the row padded by k on each side
    fwd = np.empty(n)
    bwd = np.empty(n)
    for r in range(h):
        for i in range(n):
            c = i - k
            v = x[r, c] if 0 <= c < w else np.inf
            fwd[i] = v if i % size == 0 else min(fwd[i - 1], v)
        for i in range(n - 1, -1, -1):
            c = i - k
            v = x[r, c] if 0 <= c < w else np.inf
            bwd[i] = v if (i % size == size - 1 or i == n - 1) else min(bwd[i + 1], v)
        for c in range(w):  # the padded window [c, c + 2k]: to its first block's end, from its last block's start
            out[r, c] = min(bwd[c], fwd[c + size - 1])


@_njit_inlined
def _support_scale(z: np.ndarray, r0: int, r1: int, c0: int, c1: int, focal: float) -> tuple[float, float, float]:
    """``(front, r_px, r_m)`` of :func:`_support_reach`: the least of the own depths ``z`` (+inf where none), half the
    larger side of the own pixels' box ``r0:r1, c0:c1`` (pixels, :func:`symfruit.core.occlusion.support_radius`) and
    that in metres at the front (0 without ``focal``)."""
    front = np.inf
    for i in range(z.shape[0]):
        for j in range(z.shape[1]):
            front = min(front, z[i, j])
    r_px = 0.5 * max(r1 - r0, c1 - c0)
    return front, r_px, r_px * front / focal if focal > 0.0 else 0.0


@_njit_inlined
def _support_reach(d: float, front: float, r_px: float, r_m: float) -> float:
    """Pixels: how far past its outline a round fruit (front ``front``, radius ``r_px`` pixels, ``r_m`` metres) may
    still continue behind a surface meeting it at seen depth ``d`` (:func:`symfruit.core.occlusion.support_reach`,
    the same arithmetic)."""
    k = min(max((d - front) / r_m, 0.0), 1.0)
    return r_px * (1.0 - math.sqrt(k * (2.0 - k)))


@_njit_inlined
def _band_walk(cand: np.ndarray, mine: np.ndarray, count: int, band: int, hidden: np.ndarray, b0: int,
               a0: int, reach: np.ndarray) -> int:  # fmt: skip
    """The band of :func:`own_edge` and :func:`_own_edge_in_box` runs on from the fruit's own pixels ``mine`` (m, n):
    a breadth-first walk through the ``count`` candidates ``cand`` (m, n) beside them, ``band`` steps deep; the
    pixels reached in more steps than their ``reach`` (m, n) are cleared in ``hidden`` at ``(b0, a0)`` and their
    number returned."""
    m, n = cand.shape
    queue = np.empty(count, np.int64)
    reached = np.zeros((m, n), np.bool_)
    end = 0
    for r in range(m):
        for c in range(n):
            if cand[r, c]:
                end = _band_first(mine, reached, queue, end, r, c)
    return _band_spread(cand, queue, end, reached, band, hidden, b0, a0, reach)


@_njit_inlined
def _band_walk_listed(cand: np.ndarray, mine: np.ndarray, count: int, band: int, hidden: np.ndarray, b0: int,
                      a0: int, reach: np.ndarray, at: np.ndarray, n_at: int) -> int:  # fmt: skip
    """:func:`_band_walk` with the candidates looked for at the flat indices ``at[:n_at]`` (ascending: raster order)
    alone, a superset of them, not over every pixel of ``cand``: the same walk from the same first step in the same
    order (stop 65, occl65)."""
    m, n = cand.shape
    queue = np.empty(count, np.int64)
    reached = np.zeros((m, n), np.bool_)
    end = 0
    for i in range(n_at):
        p = at[i]
        r, c = p // n, p - (p // n) * n
        if cand[r, c]:
            end = _band_first(mine, reached, queue, end, r, c)
    return _band_spread(cand, queue, end, reached, band, hidden, b0, a0, reach)


@_njit_inlined
def _band_first(mine: np.ndarray, reached: np.ndarray, queue: np.ndarray, end: int, r: int, c: int) -> int:
    """The band walk's first step at the candidate ``(r, c)``: queued (its flat index at ``queue[end]``) and marked
    ``reached`` where one of its eight neighbours or itself is the fruit's own (``mine``) and it is not yet; the
    queue's new end (:func:`_band_walk`, :func:`_band_walk_listed`)."""
    m, n = mine.shape
    for dr in range(-1, 2):
        rr = r + dr
        if 0 <= rr < m:
            for dc in range(-1, 2):
                cc = c + dc
                if 0 <= cc < n and mine[rr, cc] and not reached[r, c]:
                    reached[r, c] = True
                    queue[end] = r * n + c
                    end += 1
    return end


@_njit_inlined
def _band_spread(cand: np.ndarray, queue: np.ndarray, end: int, reached: np.ndarray, band: int, hidden: np.ndarray,
                 b0: int, a0: int, reach: np.ndarray) -> int:  # fmt: skip
    """:func:`_band_walk`'s walk on from its first step (``queue[:end]``, flat indices in ``cand``'s (m, n), each
    ``reached``): the pixels reached in more steps than their ``reach`` cleared in ``hidden`` at ``(b0, a0)``, their
    number returned."""
    m, n = cand.shape
    cleared = 0
    for i in range(end):  # the first step
        r, c = queue[i] // n, queue[i] % n
        if reach[r, c] < 1.0:
            hidden[b0 + r, a0 + c] = False
            cleared += 1
    start = 0
    for step in range(2, band + 1):
        stop = end
        for i in range(start, stop):
            r, c = queue[i] // n, queue[i] % n
            for dr in range(-1, 2):
                rr = r + dr
                if 0 <= rr < m:
                    for dc in range(-1, 2):
                        cc = c + dc
                        if 0 <= cc < n and cand[rr, cc] and not reached[rr, cc]:
                            reached[rr, cc] = True
                            queue[end] = rr * n + cc
                            end += 1
                            if reach[rr, cc] < step:
                                hidden[b0 + rr, a0 + cc] = False
                                cleared += 1
        start = stop
        if start == end:
            break
    return cleared


@_njit
def own_edge(
    hidden: np.ndarray,
    own: np.ndarray,
    own_z: np.ndarray,
    depth: np.ndarray,
    others: np.ndarray,
    tolerance: float,
    band: int,
    supports: bool,
    focal: float,
) -> int:  # fmt: skip
    """:func:`symfruit.core.occlusion.own_edge` in one pass, ``hidden`` (h, w) bool cleared in place (the number of
    pixels cleared returned): ``own`` (h, w) bool, ``own_z`` and ``depth`` (h, w) float, ``others`` (h, w) bool or
    (0, 0) for none. The same steps over the own pixels' box grown by ``2 band + 1`` (its square filters by
    :func:`_square_extreme`, the own depths' least by :func:`_row_min` then down the columns at the candidates alone),
    and the band's run from the own pixels (``ndimage.binary_dilation`` of them by ``band`` steps of the 3 x 3 square
    within the candidates and own pixels) a breadth-first walk from the candidates beside them, ``band`` steps deep:
    the twin's pixels, bit for bit (issue 19, stop 41: the eight dilation passes and scipy's minimum filter were
    most of the occlusion maps' time)."""
    h, w = hidden.shape
    if band <= 0:
        return 0
    r0, r1, c0, c1 = h, 0, w, 0
    for r in range(h):
        for c in range(w):
            if own[r, c]:
                r0, r1 = min(r0, r), r + 1
                c0, c1 = min(c0, c), max(c1, c + 1)
    if r1 == 0:
        return 0
    g = 2 * band + 1
    b0, b1, a0, a1 = max(r0 - g, 0), min(r1 + g, h), max(c0 - g, 0), min(c1 + g, w)
    m, n = b1 - b0, a1 - a0
    with_others = others.shape[0] > 0
    mine = np.empty((m, n), np.bool_)
    hid = np.empty((m, n), np.bool_)
    for r in range(m):
        for c in range(n):
            mine[r, c] = own[b0 + r, a0 + c]
            hid[r, c] = hidden[b0 + r, a0 + c]
    near = np.empty((m, n), np.bool_)
    _square_extreme(mine, band, False, near)
    cand = np.empty((m, n), np.bool_)
    any_cand = False
    for r in range(m):
        for c in range(n):
            x = hid[r, c] and near[r, c] and not mine[r, c] and not (with_others and others[b0 + r, a0 + c])
            cand[r, c] = x
            any_cand |= x
    if not any_cand:
        return 0
    # the band ends: something not hiding the fruit lies just beyond, and nothing hidden runs on past the band; with
    # ``supports`` a band that runs on (a support) is cleared too, past the reach the fruit may continue behind it
    free = np.empty((m, n), np.bool_)
    past = np.empty((m, n), np.bool_)
    for r in range(m):
        for c in range(n):
            free[r, c] = not hid[r, c] and not mine[r, c]
            past[r, c] = hid[r, c] and not near[r, c]
    ends = np.empty((m, n), np.bool_)
    _square_extreme(free, band + 1, False, ends)
    runs = np.empty((m, n), np.bool_)
    _square_extreme(past, band, False, runs)
    front, r_px, r_m = _support_scale(own_z, r0, r1, c0, c1, focal)
    reach = np.zeros((m, n))
    any_cand = False
    for r in range(m):
        for c in range(n):
            if cand[r, c] and not (ends[r, c] and not runs[r, c]):
                if supports and r_m > 0.0 and r_m < np.inf:
                    reach[r, c] = _support_reach(np.float64(depth[b0 + r, a0 + c]), front, r_px, r_m)
                elif not supports:
                    cand[r, c] = False
            any_cand |= cand[r, c]
    if not any_cand:
        return 0
    # not clearly nearer than the own depths within the band's square
    zs = np.empty((m, n))
    for r in range(m):
        for c in range(n):
            zs[r, c] = own_z[b0 + r, a0 + c]
    rowmin = np.empty((m, n))
    _row_min(zs, band, rowmin)
    count = 0
    for r in range(m):
        for c in range(n):
            if cand[r, c]:
                z = np.inf
                for rr in range(max(r - band, 0), min(r + band + 1, m)):
                    z = min(z, rowmin[rr, c])
                x = np.float64(depth[b0 + r, a0 + c]) >= z - tolerance  # NaN: not the fruit's
                cand[r, c] = x
                count += x
    if count == 0:
        return 0
    return _band_walk(cand, mine, count, band, hidden, b0, a0, reach)


@_njit
def monotone_at(
    depth: np.ndarray, keep: np.ndarray, r0: int, c0: int, table: np.ndarray, reach: int, bins: int,
    tolerance: float, out: np.ndarray,
) -> int:  # fmt: skip
    """:func:`ray_pixels` then :func:`monotone_table` in one call, the pixels' rows, columns and offsets never boxed
    (issue 19, stop 41: four arrays a call, twice a fruit's surface): ``out`` (h, w) bool (all false on entry) gets
    :func:`symfruit.core.surface.monotone_region`'s pixels, the same ones; the number of ``keep``'s pixels
    returned."""
    h, w = keep.shape
    n = 0
    for r in range(h):
        for c in range(w):
            n += keep[r, c]
    if n == 0:
        return 0
    # stop 60 (speeds60): each pixel's flat index, depth, sector and squared distance read in raster order, and the
    # two stable counting sorts of :func:`monotone` (by distance, then by sector) moving the pixels' index, depth and
    # sector to their places (no index looked up twice), the rays then walked in order: the same order (sector, then
    # distance, then position), the same arithmetic on the same depths, so the same pixels
    at, sector, d2 = np.empty(n, np.int64), np.empty(n, np.int64), np.empty(n, np.int64)
    z = np.empty(n)  # ``at``: row and column in one number (row times 2^32 plus column), taken apart where written
    biggest = 0.0
    top = 0
    i = 0
    for r in range(h):
        a = np.int64(r - r0)
        for c in range(w):
            if keep[r, c]:
                b = np.int64(c - c0)
                at[i] = (np.int64(r) << 32) | np.int64(c)
                v = float(depth[r, c])
                z[i] = v
                biggest = max(biggest, abs(v))
                sector[i] = np.int64(table[a + reach, b + reach])
                q = a * a + b * b
                d2[i] = q
                top = max(top, q)
                i += 1
    scale = 2.0 * (biggest + tolerance + 1.0)
    if tolerance >= 0.0 and biggest < np.inf and bins * scale + biggest < 2.0**40:
        # stop 62 (surf62): the rays walked in order of distance alone, each sector's running maximum and fall kept
        # apart (the pixels never moved to sector order). Within a sector the order is the same (the distance sort
        # is stable: distance, then position). Across sectors the walk below carries its running maximum over, but
        # it never reaches into the next sector: a sector's offset lies ``scale`` above the last one's, and its depths
        # ``z + offset`` lie above every earlier ``z' + offset'`` by at least ``scale - 2 biggest = 2 (tolerance + 1)
        # >= 2`` less the roundings (a few units in the last place of numbers below 2^40: under 2^-10), so a
        # sector's first pixel takes its own value there as here. Finite depths (no NaN: ``biggest`` would not be
        # finite) and a tolerance of 0 or more, else the walk below: the same arithmetic, so the same pixels
        by_d2 = _distance_order(d2, n, top)
        high = np.full(bins, -np.inf)
        cut = np.zeros(bins, np.bool_)
        for j in range(n):
            i = by_d2[j]
            s = sector[i]
            offset = s * scale
            peak = max(high[s], z[i] + offset)
            high[s] = peak
            gone = cut[s] | (z[i] < (peak - offset) - tolerance)
            cut[s] = gone
            if not gone:
                a = at[i]
                out[a >> 32, a & 0xFFFFFFFF] = True
        return n
    by_d2, start = _counting_orders(d2, sector, n, top, bins)
    at_s, sec_s, z_s = np.empty(n, np.int64), np.empty(n, np.int64), np.empty(n)
    for j in range(n):
        i = by_d2[j]
        s = sector[i]
        k = start[s]
        start[s] = k + 1
        at_s[k], sec_s[k], z_s[k] = at[i], s, z[i]
    running = -np.inf
    last = -1
    fallen = False
    for j in range(n):
        s = sec_s[j]
        if s != last:
            last, fallen = s, False
        offset = s * scale
        running = max(running, z_s[j] + offset)
        if z_s[j] < (running - offset) - tolerance:
            fallen = True
        if not fallen:
            a = at_s[j]
            out[a >> 32, a & 0xFFFFFFFF] = True
    return n


# --- stop 42, speedext42: the occlusion window's one pass, the thin-front test's parts and median ---------------


# inlined into its two callers at numba's level: called, it cost occlusion_at 6-8 % (its loops optimised apart)
@_njit_inlined
def _occlusion_pass(
    depth: np.ndarray,
    mask: np.ndarray,
    others: np.ndarray,
    v0: int,
    u0: int,
    own_z: np.ndarray,
    p0: int,
    q0: int,
    tolerance: float,
    steps: np.ndarray,
    low: float,
    high: float,
    hidden: np.ndarray,
    seen: np.ndarray,
) -> int:  # fmt: skip
    """The pass :func:`occlusion_window` and :func:`occlusion_at` share (stop 42: they held it twice): the window is
    ``hidden``'s (h, w) pixels from ``(v0, u0)`` of the images ``depth``, ``mask`` and ``others`` (or (0, 0)), read
    in place (views of a window would be strided arrays, 10 % slower); ``own_z`` the points' own depths over their
    pixels' box, whose top-left pixel is ``(p0, q0)`` in the window (+inf where none: no point pixel lies outside
    it), ``low`` and ``high`` the points' least and greatest depth. ``hidden`` and ``seen`` get
    :func:`occlusion_window`'s maps; the number of rows whose nearest point pixels were looked for is returned."""
    h, w = hidden.shape
    p1, q1 = p0 + own_z.shape[0], q0 + own_z.shape[1]
    lo, hi = low + tolerance, high + tolerance
    k = steps.shape[0]
    with_others = others.shape[0] > 0
    # issue 19, twentieth round: whether a pixel may lend its depth (neither the fruit's nor without depth) is worked
    # out once a pixel, not once per offset that reads it; the point pixels' box bounds the column sweeps (no point
    # pixel lies outside it, so no column's nearest changes); a pixel waits for its nearest point pixel when its
    # seen depth lies in [lo, hi) (read back from ``seen``), not by a map of its own
    lend = np.empty((h, w), np.bool_)
    own = np.empty((h, w), np.bool_)  # the fruit's own pixels (its mask's and its point pixels)
    # stop 65 (occl65): the mask's pixels first along each whole row without a branch, then the point pixels' box
    # alone; a pixel has depth where 0 < y < inf (NaN compares False: math.isfinite(y) and y > 0, the same pixels)
    for r in range(h):
        for c in range(w):
            o = mask[v0 + r, u0 + c]
            y = np.float64(depth[v0 + r, u0 + c])
            own[r, c] = o
            lend[r, c] = (not o) & (y > 0.0) & (y < np.inf)
            seen[r, c] = np.nan if o else y  # NaN for now where it has no depth of its own (below)
        if p0 <= r < p1:
            for c in range(q0, q1):
                if math.isfinite(own_z[r - p0, c - q0]):
                    own[r, c] = True
                    lend[r, c] = False
                    seen[r, c] = np.nan
    rows = np.zeros(h, np.bool_)
    # stop 60 (obsv60): each row's first and last waiting column, so that the walk below reads that span alone (it
    # skips every other pixel): the same pixels walked in the same order
    first = np.empty(h, np.int64)
    final = np.empty(h, np.int64)
    # stop 65 (occl65): a row at a time, its pixels without depth (neither the fruit's nor lending) filled first, from
    # their first offset with depth, then every pixel's hidden bit and whether it waits decided without a branch
    # (numba vectorises the loop; the first and last waiting columns a least and a greatest): the fruit's own pixels
    # are NaN in ``seen`` (never nearer, never waiting) and ``not own`` keeps another fruit's mark off them, so the
    # same bits as the branches deciding one pixel at a time (NaN: hidden where another fruit's; nearer than ``lo``:
    # hidden; else not, waiting below ``hi``)
    for r in range(h):
        holes = False
        for c in range(w):
            holes |= (not lend[r, c]) & (not own[r, c])
        if holes:
            for c in range(w):
                if not lend[r, c] and not own[r, c]:
                    x = np.nan
                    for j in range(k):
                        rr, cc = r + steps[j, 0], c + steps[j, 1]
                        if 0 <= rr < h and 0 <= cc < w and lend[rr, cc]:  # a pixel with depth: its own, never filled
                            x = np.float64(depth[v0 + rr, u0 + cc])
                            break
                    seen[r, c] = x
        a, b = w, -1
        if with_others:
            for c in range(w):
                x = seen[r, c]
                hidden[r, c] = (x < lo) | ((x != x) & others[v0 + r, u0 + c] & (not own[r, c]))
                wait = (x >= lo) & (x < hi)
                a = min(a, c if wait else w)
                b = max(b, c if wait else -1)
        else:
            for c in range(w):
                x = seen[r, c]
                hidden[r, c] = x < lo
                wait = (x >= lo) & (x < hi)
                a = min(a, c if wait else w)
                b = max(b, c if wait else -1)
        if b >= 0:
            rows[r] = True
            first[r], final[r] = a, b
    # nearest()'s column pass (each pixel's nearest point pixel in its column, the upper of two as near), kept for
    # the rows looked at alone and the point pixels' columns alone (q0 to q1: no other column has a nearest row):
    # the nearest at or above by a sweep down, the nearest below by a sweep up, each over the point pixels' rows
    # (beyond them its state does not change)
    place = np.full(h, -1, np.int64)
    count = 0
    for r in range(h):
        if rows[r]:
            place[r] = count
            count += 1
    nb = max(q1 - q0, 0)
    near = np.full((count, nb), -1, np.int64)  # column q0 + j's nearest row, -1: none
    run = np.full(nb, -1, np.int64)
    for r in range(p0, h):
        if r < p1:
            for j in range(nb):
                if math.isfinite(own_z[r - p0, j]):
                    run[j] = r
        kr = place[r]
        if kr >= 0:
            for j in range(nb):
                near[kr, j] = run[j]
    run[:] = -1
    for r in range(p1 - 1, -1, -1):
        if r >= p0:
            for j in range(nb):
                if math.isfinite(own_z[r - p0, j]):
                    run[j] = r
        kr = place[r]
        if kr >= 0:
            for j in range(nb):
                a, b = near[kr, j], run[j]
                if b >= 0 and (a < 0 or b - r < r - a):
                    near[kr, j] = b
    env = np.empty(max(nb, 1), np.int64)
    done = 0
    for r in range(h):
        if not rows[r]:
            continue
        done += 1
        row = near[place[r]]
        top = _row_envelope(row, r, env)  # nearest()'s row pass, columns counted from q0: the same envelope (its
        # tests are on differences of columns), and the same walk along it, taken at the waiting pixels alone: the
        # walk moves on to the next parabola only while that is strictly nearer, and the next's lead over the last
        # grows along the row, so the parabola it stops at for a pixel is the same whether it walked every pixel
        # before or only some of them
        q = 0
        for u in range(first[r], final[r] + 1):
            x = seen[r, u]
            if not (x >= lo and x < hi):  # decided without its nearest point pixel (NaN: never waits)
                continue
            i = env[q]
            dr, dc = row[i] - r, i + q0 - u
            best = dr * dr + dc * dc
            while q < top:
                i = env[q + 1]
                dr, dc = row[i] - r, i + q0 - u
                d = dr * dr + dc * dc
                if best <= d:
                    break
                best = d
                q += 1
            i = env[q]
            ref = own_z[row[i] - p0, i] + tolerance
            hidden[r, u] = x < ref or (with_others and others[v0 + r, u0 + u] and not x >= ref)
    return done


@_njit
def smooth_parts(depth: np.ndarray, mask: np.ndarray, join: float, labels: np.ndarray) -> int:
    """:func:`symfruit.core.surface._smooth_parts` into ``labels`` ((h, w) int32, every pixel written) and the number
    of parts: the pixels of ``mask`` with depth (above 0) none of whose 4 neighbours in the mask with depth lies
    more than ``join`` from it, joined 4-connected and numbered from 1 in the raster order of each part's first
    pixel (``ndimage.label``'s numbering, so the same labels; stop 42).

    Since stop 49 (regspeed49) the steps are found row by row without branches, as the twin finds them (a step between
    two neighbours with depth, ``|a - b| > join``, takes both out; ``|a - b|`` is ``|b - a|`` to the bit), and the
    flood keeps rows and columns apart instead of dividing flat indices: the same pixels and labels (the benchmark
    frame's 28 calls 0.79 -> 0.47 ms). Since stop 63 (reg63) the parts are labelled by a union-find raster pass, not a
    flood (the same labels; the frame's 24 first calls 0.56 -> 0.31 ms replayed at load 11, docs/reg63.md)."""
    h, w = depth.shape
    ok = np.empty((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            ok[r, c] = mask[r, c] and depth[r, c] > 0
    smooth = np.empty((h, w), np.bool_)
    down = np.zeros(w, np.bool_)  # a step between rows r and r + 1, per column
    up = np.zeros(w, np.bool_)  # a step between rows r - 1 and r
    side = np.zeros(w + 1, np.bool_)  # side[c + 1]: a step between columns c and c + 1 (none at 0 and w)
    for r in range(h):
        for c in range(w):
            up[c] = down[c]
        if r + 1 < h:
            for c in range(w):
                down[c] = ok[r, c] & ok[r + 1, c] & (abs(depth[r + 1, c] - depth[r, c]) > join)
        else:
            for c in range(w):
                down[c] = False
        for c in range(w - 1):
            side[c + 1] = ok[r, c] & ok[r, c + 1] & (abs(depth[r, c + 1] - depth[r, c]) > join)
        for c in range(w):
            smooth[r, c] = ok[r, c] & ~(up[c] | down[c] | side[c] | side[c + 1])
    # stop 63 (reg63): the parts by one raster pass with a union-find of provisional labels (a pixel takes its upper
    # or left neighbour's, both joined), then each provisional label's root numbered in the order the roots came,
    # instead of a flood from each part's first pixel. A part's first pixel in raster order has neither neighbour in
    # the part, so it opens a new label, the part's least; a union keeps the lesser root, so each root is its part's
    # first pixel's label and the roots come in raster order of the parts' first pixels: ndimage.label's numbering,
    # the same labels
    parent = np.empty(h * w + 2, np.int32)  # a provisional label per pixel at most (label 0 unused)
    n = 0
    for r in range(h):
        for c in range(w):
            if not smooth[r, c]:
                labels[r, c] = 0
                continue
            above = labels[r - 1, c] if r > 0 else 0
            before = labels[r, c - 1] if c > 0 else 0
            if above == 0 and before == 0:
                n += 1
                parent[n] = n
                labels[r, c] = n
            elif before == 0 or above == before:
                labels[r, c] = above
            elif above == 0:
                labels[r, c] = before
            else:
                a = above
                while parent[a] != a:
                    a = parent[a]
                b = before
                while parent[b] != b:
                    b = parent[b]
                if a < b:
                    parent[b] = a
                elif b < a:
                    parent[a] = b
                labels[r, c] = min(a, b)
    count = 0
    for i in range(1, n + 1):  # roots numbered in their order; every other label takes its root's (a lesser one)
        p = parent[i]
        if p == i:
            count += 1
            parent[i] = -count
        else:
            while p > 0:
                p = parent[p]
            parent[i] = p
    parent[0] = 0  # no part: 0
    for r in range(h):
        for c in range(w):
            labels[r, c] = -parent[labels[r, c]]
    return count


@_njit
def filled_windows(depth: np.ndarray, ok: np.ndarray, size: int, values: np.ndarray) -> None:
    """``values`` ((n, size * size) float64, n the pixels of ``ok``, which must hold one): row ``i`` the ``size`` x
    ``size`` window (odd ``size``, edges repeated; row by row) of ``depth`` around the ``i``-th pixel of ``ok`` in
    raster order (``np.nonzero``'s), every pixel not ``ok`` taking its nearest ``ok`` pixel's depth
    (``ndimage.distance_transform_edt(~ok, return_indices=True)``'s pixel, by :func:`nearest`):
    :func:`symfruit.core.surface.median_at`'s values in :func:`symfruit.core.surface.thin_front`, the same ones in
    the same places (stop 42; numpy's partition then takes their medians: its SIMD selection is faster than
    :func:`select` or a sort here). The filled depth is laid out once with the edges repeated, as
    :func:`_least_median_of` does."""
    h, w = ok.shape
    idx = np.empty((h, w), np.int64)
    nearest(np.logical_not(ok), idx)
    half = size // 2
    vals = np.empty((h + 2 * half, w + 2 * half))
    for a in range(h + 2 * half):
        rr = min(max(a - half, 0), h - 1)
        for b in range(w + 2 * half):
            i = idx[rr, min(max(b - half, 0), w - 1)]
            vals[a, b] = np.float64(depth[i // w, i % w])
    n = 0
    for r in range(h):
        for c in range(w):
            if ok[r, c]:
                k = 0
                for a in range(size):
                    for b in range(size):
                        values[n, k] = vals[r + a, c + b]
                        k += 1
                n += 1


# --- stop 43, speedext43: the thin-front test's counts, front pixels and lagged differences ---------------------


@_njit
def thin_counts(
    depth: np.ndarray, mask: np.ndarray, front: float, join: float, ok: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.core.surface.thin_front`'s first pass over a mask (h, w) bool and its depth (h, w) float64
    (:func:`symfruit.core.surface._thin_counts`' twin): ``ok`` (h, w) bool written in place (the mask's pixels with
    depth above 0); the counts (5,) int64: ``ok``'s pixels, then of the vertical and of the horizontal neighbours
    both ``ok``, how many pairs and how many of them hold equal depths; and the rows and columns (raster order,
    ``np.nonzero``'s) of the ``ok`` pixels within ``join`` of ``front``. Whole numbers and the same comparisons:
    the twin's, bit for bit (stop 43)."""
    h, w = mask.shape
    counts = np.zeros(5, np.int64)
    # stop 60 (speeds60): the first pass's counts moved on by each test's outcome (no jump to foresee): the same
    n_ok = 0
    n_front = 0
    for r in range(h):
        for c in range(w):
            z = depth[r, c]
            good = mask[r, c] & (z > 0)
            ok[r, c] = good
            n_ok += good
            n_front += good & (abs(z - front) <= join)
    counts[0] = n_ok
    rows = np.empty(n_front, np.int64)
    cols = np.empty(n_front, np.int64)
    k = 0
    for r in range(h):
        for c in range(w):
            if ok[r, c]:
                if r > 0 and ok[r - 1, c]:
                    counts[1] += 1
                    counts[2] += depth[r, c] == depth[r - 1, c]
                if c > 0 and ok[r, c - 1]:
                    counts[3] += 1
                    counts[4] += depth[r, c] == depth[r, c - 1]
                if abs(depth[r, c] - front) <= join:
                    rows[k], cols[k] = r, c
                    k += 1
    return counts, rows, cols


@_njit
def lag_differences(medians: np.ndarray, ok: np.ndarray, mask: np.ndarray, lag: int, smooth: np.ndarray) -> np.ndarray:
    """:func:`symfruit.core.surface.thin_front`'s smoothed depth and its noise's differences
    (:func:`symfruit.core.surface._lag_differences`' twin): ``smooth`` (h, w) written in place, 0 but at the pixels
    of ``ok`` (h, w) bool, which take ``medians`` (n,) in raster order; and the differences (m,) ``smooth[r, c + lag]
    - smooth[r, c]`` where both pixels are ``mask``'s (h, w) bool and both values above 0, in raster order: the
    twin's subtractions in its order, bit for bit (stop 43)."""
    h, w = ok.shape
    k = 0
    for r in range(h):
        for c in range(w):
            if ok[r, c]:
                smooth[r, c] = medians[k]
                k += 1
            else:
                smooth[r, c] = 0.0
    out = np.empty(max(h * (w - lag), 0))
    m = 0
    for r in range(h):
        for c in range(w - lag):
            a, b = smooth[r, c + lag], smooth[r, c]
            if mask[r, c + lag] and mask[r, c] and a > 0 and b > 0:
                out[m] = a - b
                m += 1
    return out[:m]


# --- issue 19, seventeenth round: registration, trimming, extraction, occlusion ---------------------------------


@_njit
def signed_keys(inside: np.ndarray, pad: int, reach: int) -> tuple[np.ndarray, bool, float]:
    """:meth:`symfruit.core.surface._Outline.keys`' twin in one pass: the map ``inside`` (h, w) as whole numbers
    ``sign * rint(d * d)`` padded by ``pad`` pixels of ``-reach**2`` (int32, flattened); whether every value comes
    back exactly from its key (``sqrt(key) == |d|``, each key below ``2**31 - 1``; else the keys are no use and the
    twin's answer is None), and the largest key (at least ``reach**2``). The same keys, whole numbers."""
    h, w = inside.shape
    width = w + 2 * pad
    out = np.empty((h + 2 * pad) * width, np.int32)
    floor = -(reach * reach)
    top = float(reach * reach)
    if top >= 2147483647.0:
        return out, False, top
    for i in range(out.shape[0]):
        out[i] = floor
    for r in range(h):
        base = (r + pad) * width + pad
        for c in range(w):
            d = inside[r, c]
            whole = np.rint(d * d)
            if not whole < 2147483647.0 or math.sqrt(whole) != abs(d):
                return out, False, top
            top = max(top, whole)
            out[base + c] = -np.int32(whole) if d < 0 else np.int32(whole)
    return out, True, top


@_njit
def outline_deviations(
    ranks: np.ndarray, values: np.ndarray, at: np.ndarray, shifts: np.ndarray, width: int, band: float
) -> np.ndarray:  # fmt: skip
    """(k, n) each outline point's deviation from the band of each shift (k, 2) ``(dv, du)``, as
    :meth:`symfruit.core.surface._Outline._cost` has it before its exact trimmed mean: the points' flat indices
    ``at`` (n,) into the padded map's ranks ``ranks`` (:meth:`~symfruit.core.surface._Outline.ranks`) moved back by
    the shift, their values ``values[rank]`` (the map's values bit for bit), the median of the row (np.median's
    two middle places, walked to on the counts of the ranks, as :func:`outline_costs` does; the values of the
    twin's middle keys), the band (the median clipped to 0 .. ``band``) and ``|value - band|``: the twin's
    deviations, bit for bit, whose partition and mean numpy then takes as the twin does."""
    k, n = shifts.shape[0], at.shape[0]
    size = values.shape[0]
    out = np.empty((k, n))
    count = np.zeros(size, np.int64)
    row = np.empty(n, np.int64)
    lower, upper = (n - 1) // 2, n // 2
    for s in range(k):
        offset = shifts[s, 0] * width + shifts[s, 1]
        low = size
        for j in range(n):
            r = np.int64(ranks[at[j] - offset])
            row[j] = r
            count[r] += 1
            low = min(low, r)
        b, seen = low, count[low]
        while seen <= lower:
            b += 1
            seen += count[b]
        first = values[b]
        if seen <= upper:
            b += 1
            while count[b] == 0:
                b += 1
            second = values[b]
        else:
            second = first
        median = 0.5 * (first + second) if n % 2 == 0 else second
        middle = min(max(median, 0.0), band)
        for j in range(n):
            out[s, j] = abs(values[row[j]] - middle)
            count[row[j]] = 0
    return out


@_njit
def monotone_rays(
    depth: np.ndarray, rows: np.ndarray, cols: np.ndarray, angle: np.ndarray, dy: np.ndarray, dx: np.ndarray,
    bins: int, per_radian: float, tolerance: float, out: np.ndarray,
) -> None:  # fmt: skip
    """:func:`symfruit.core.surface.monotone_region` from the directions ``angle`` (n,) (numpy's ``arctan2(dy, dx)``
    of the pixels' offsets ``dy``, ``dx`` from the apex) on: each pixel's sector ``floor((angle + pi) *
    per_radian) % bins`` (``per_radian = bins / (2 pi)``) and squared distance ``dy^2 + dx^2``, as the twin works
    them out, then :func:`monotone`. The same pixels."""
    n = rows.shape[0]
    sector = np.empty(n, np.int64)
    d2 = np.empty(n, np.int64)
    for i in range(n):
        sector[i] = np.int64(math.floor((angle[i] + np.pi) * per_radian)) % bins
        d2[i] = np.int64(dy[i]) * np.int64(dy[i]) + np.int64(dx[i]) * np.int64(dx[i])
    monotone(depth, rows, cols, sector, d2, bins, tolerance, out)


@_njit
def rim_sides(
    dv: np.ndarray, du: np.ndarray, radius: np.ndarray, angle: np.ndarray, bins: int, per_radian: float,
    free: np.ndarray,
) -> np.ndarray:  # fmt: skip
    """(4, 2) int: :func:`symfruit.core.surface._free_points`' sides from the outline points' offsets ``dv``, ``du``
    (n,) from their centroid, their distances ``radius`` (numpy's ``hypot``) and directions ``angle`` (numpy's
    ``arctan2(dv, du)``): the rim (:func:`~symfruit.core.surface._rim`: in each of ``bins`` directions, bin
    ``min(int((angle + pi) * per_radian), bins - 1)``, the farthest point, the first of equally far ones), and of
    its points on the top, bottom, left and right side how many are ``free`` and how many there are. The twin's
    points and counts."""
    n = dv.shape[0]
    best = np.full(bins, -1, np.int64)
    for i in range(n):
        b = min(np.int64((angle[i] + np.pi) * per_radian), bins - 1)
        if best[b] < 0 or radius[i] > radius[best[b]]:
            best[b] = i
    sides = np.zeros((4, 2), np.int64)
    for b in range(bins):
        i = best[b]
        if i < 0:
            continue
        if abs(dv[i]) >= abs(du[i]):
            side = 0 if dv[i] < 0 else 1 if dv[i] > 0 else -1
        else:
            side = 2 if du[i] < 0 else 3 if du[i] > 0 else -1
        if side >= 0:
            sides[side, 1] += 1
            if free[i]:
                sides[side, 0] += 1
    return sides


@_njit
def valid_depth(
    depth: np.ndarray, core: np.ndarray, low: float, high: float, valid_depth: np.ndarray, usable: np.ndarray
) -> tuple[int, int]:  # fmt: skip
    """:func:`symfruit.extract.extract`'s depth tests in one pass: ``valid_depth`` (h, w) the depth where it is finite
    and within ``low`` .. ``high`` (0 elsewhere), ``usable`` (h, w) the pixels of ``core`` with such depth; how many
    of ``core``'s pixels have none, and how many are usable. The twin's comparisons: the same maps and counts."""
    h, w = depth.shape
    n_invalid = n_usable = 0
    for r in range(h):
        for c in range(w):
            z = depth[r, c]
            ok = np.isfinite(z) and z >= low and z <= high
            valid_depth[r, c] = z if ok else 0.0
            usable[r, c] = core[r, c] and ok
            if core[r, c]:
                if ok:
                    n_usable += 1
                else:
                    n_invalid += 1
    return n_invalid, n_usable


@_njit
def pixel_points(
    keep: np.ndarray, also: np.ndarray, depth: np.ndarray, cx: float, cy: float, fx: float, fy: float
) -> np.ndarray:  # fmt: skip
    """(n, 3) :meth:`symfruit.core.camera.Camera.deproject` of the pixels of ``keep & also`` (h, w) bool in raster
    order (``np.nonzero``'s) at their ``depth``: ``x = (u - cx) / fx * z``, ``y = (v - cy) / fy * z``, the same
    arithmetic, bit for bit."""
    h, w = keep.shape
    n = 0
    for r in range(h):
        for c in range(w):
            if keep[r, c] and also[r, c]:
                n += 1
    out = np.empty((n, 3))
    i = 0
    for r in range(h):
        for c in range(w):
            if keep[r, c] and also[r, c]:
                z = float(depth[r, c])
                out[i, 0] = (float(c) - cx) / fx * z
                out[i, 1] = (float(r) - cy) / fy * z
                out[i, 2] = z
                i += 1
    return out


@_njit
def trim_regions(
    inner: np.ndarray, mask: np.ndarray, band_px: float, deep: float, ring_px: float, fruit: np.ndarray,
    ring: np.ndarray, band: np.ndarray,
) -> tuple[int, int, int]:  # fmt: skip
    """:func:`symfruit.core.surface.colour_trim`'s three regions from the mask's distance map ``inner`` (h, w): the
    fruit ``band_px < inner <= deep``, the ring of pixels outside ``mask`` at most ``ring_px`` from it
    (:func:`near_distance`'s distances, :func:`symfruit.core.surface.within`'s test) and the band ``inner <=
    band_px`` of the mask, written into ``fruit``, ``ring`` and ``band`` (h, w) bool; how many pixels each holds.
    The twin's comparisons: the same pixels."""
    h, w = mask.shape
    near = np.empty((h, w))
    near_distance(mask, ring_px, True, near)
    n_fruit = n_ring = n_band = 0
    for r in range(h):
        for c in range(w):
            d = inner[r, c]
            f = d > band_px and d <= deep
            g = (not mask[r, c]) and near[r, c] <= ring_px
            b = mask[r, c] and d <= band_px
            fruit[r, c], ring[r, c], band[r, c] = f, g, b
            n_fruit += f
            n_ring += g
            n_band += b
    return n_fruit, n_ring, n_band


@_njit
def own_depths(
    uv: np.ndarray, points: np.ndarray, width: int, height: int, pad: int
) -> tuple[bool, int, int, int, int, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.core.occlusion.occlusion`'s window and the fruit's own depths in it: each point's pixel (its
    projection ``uv`` (n, 2) rounded half to even, as ``np.rint``; those within the ``width`` x ``height`` image),
    the window (the pixels' box grown by its own size plus ``pad``, clipped to the image) and, per window pixel, the
    least depth (``points[:, 2]``) of the points on it (+inf on none; a least is exact in any order) and whether it
    has none. ``(False, ...)`` when no point falls in the image. The twin's window and maps, bit for bit."""
    n = uv.shape[0]
    cmin, cmax, rmin, rmax = width, -1, height, -1
    for i in range(n):
        u, v = np.rint(uv[i, 0]), np.rint(uv[i, 1])
        if u >= 0 and u < width and v >= 0 and v < height:
            c, r = int(u), int(v)
            cmin, cmax, rmin, rmax = min(cmin, c), max(cmax, c), min(rmin, r), max(rmax, r)
    if cmax < 0:
        return False, 0, 0, 0, 0, np.empty((0, 0)), np.empty((0, 0), np.bool_)
    span_u, span_v = cmax - cmin + pad, rmax - rmin + pad
    u0, v0 = max(cmin - span_u, 0), max(rmin - span_v, 0)
    u1, v1 = min(cmax + span_u + 1, width), min(rmax + span_v + 1, height)
    own = np.full((v1 - v0, u1 - u0), np.inf)
    for i in range(n):
        u, v = np.rint(uv[i, 0]), np.rint(uv[i, 1])
        if u >= 0 and u < width and v >= 0 and v < height:
            r, c = int(v) - v0, int(u) - u0
            z = points[i, 2]
            if z < own[r, c]:
                own[r, c] = z
    unseen = np.empty(own.shape, np.bool_)
    for r in range(own.shape[0]):
        for c in range(own.shape[1]):
            unseen[r, c] = not np.isfinite(own[r, c])
    return True, u0, v0, u1, v1, own, unseen


@_njit
def centred_pixels(mask: np.ndarray, r0: int, c0: int) -> np.ndarray:
    """(n, 2) :func:`symfruit.core.raster.principal_widths`' centred coordinates: the column and row (at ``r0``,
    ``c0`` in a larger image) of each pixel of ``mask`` (h, w) bool in raster order, less their means (the whole-number
    sums divided by the count, as the twin has them): the twin's array, bit for bit; with fewer than two pixels an
    empty (0, 2) array (stop 62, surf62: the caller no longer counts them first)."""
    h, w = mask.shape
    n = 0
    su = sv = 0
    for r in range(h):
        for c in range(w):
            m = mask[r, c]
            n += m
            su += (c + c0) * m
            sv += (r + r0) * m
    if n < 2:
        return np.empty((0, 2))
    mu, mv = float(su) / n, float(sv) / n
    # each pixel's values written and the count moved on by the mask (no jump to foresee; a row to spare for the
    # pixels after the last): the same values in the same rows
    out = np.empty((n + 1, 2))
    i = 0
    for r in range(h):
        for c in range(w):
            out[i, 0] = float(c + c0) - mu
            out[i, 1] = float(r + r0) - mv
            i += mask[r, c]
    return out[:n]


@_njit
def positive_depth(depth: np.ndarray, out: np.ndarray) -> None:
    """``out`` (h, w): ``depth`` where it is finite and above 0, 0 elsewhere (:func:`symfruit.core.surface.
    fruit_surface`'s ``np.where(np.isfinite(depth) & (depth > 0), depth, 0.0)``, the same values)."""
    h, w = depth.shape
    for r in range(h):
        for c in range(w):
            z = depth[r, c]
            out[r, c] = z if np.isfinite(z) and z > 0 else 0.0


# --- issue 19, eighteenth round (stop 38): registration, extraction, occlusion ---------------------------------------


@_njit
def occlusion_window(
    depth: np.ndarray,
    mask: np.ndarray,
    own_z: np.ndarray,
    others: np.ndarray,
    tolerance: float,
    steps: np.ndarray,
    low: float,
    high: float,
    hidden: np.ndarray,
    seen: np.ndarray,
) -> int:
    """:func:`occlusion_maps` after :func:`nearest` of ``~isfinite(own_z)`` (which must hold a finite pixel), in one
    kernel that looks for a pixel's nearest point pixel only where it decides (issue 19, eighteenth round): the
    same ``hidden`` and ``seen``, bit for bit. ``low`` and ``high`` bound every finite ``own_z`` from below and
    above (the points' least and greatest depth). Returns the number of rows whose nearest point pixels were
    looked for.

    A pixel's reference is its nearest point pixel's depth plus ``tolerance``, so it lies between ``low`` and
    ``high`` plus ``tolerance`` (``lo``, ``hi``; rounding is monotone): a pixel that is the fruit's, without depth
    (it is hidden when another fruit's), nearer than ``lo`` (hidden) or at least ``hi`` (not hidden, not even
    another fruit's) is decided without it. The rest (a few per cent of a window: a leaf, a support or a neighbour
    at the fruit's depth) take it from :func:`nearest`'s two passes, its column pass over the window and its row
    pass (each row's lower envelope) on the rows holding such a pixel alone. A pixel without depth takes that of
    its first offset with depth (:func:`occlusion_maps`' fill; whether a pixel has depth is worked out where it is
    looked at)."""
    h, w = mask.shape
    p0, p1, q0, q1 = h, 0, w, 0  # the point pixels' box
    for r in range(h):
        for c in range(w):
            if math.isfinite(own_z[r, c]):
                p0, p1 = min(p0, r), r + 1
                q0, q1 = min(q0, c), max(q1, c + 1)
    # stop 42: the pass shared with occlusion_at (the window's maps from the own depths over the point pixels' box)
    return _occlusion_pass(depth, mask, others, 0, 0, own_z[p0:p1, q0:q1], p0, q0, tolerance, steps, low, high,
                           hidden, seen)  # fmt: skip


@_njit
def open_square(src: np.ndarray, radius: int, out: np.ndarray) -> None:
    """``out`` (h, w) bool: ``src`` (h, w) bool opened by a ``2 radius + 1`` square, outside the array background
    (:func:`symfruit.core.occlusion.open_square`'s pixels, ``scipy.ndimage.binary_opening``'s): the union of the
    squares of side ``k = 2 radius + 1`` that lie wholly in ``src`` and in the array. ``out`` may not overlap ``src``.

    Issue 19, stop 61 (speedb61): one sweep down the rows instead of :func:`_square_extreme`'s erosion and dilation
    (four passes, each along the rows and down the columns). At row ``r`` each column's run of ``src`` pixels ending
    there is counted; the columns of ``k`` or more side by side whose runs are ``k`` or longer are those of a square
    whose last row is ``r``, and each column keeps the last such row. A pixel ``k - 1`` rows up, at ``p = r - k +
    1``, is in a square exactly when its column's last such row is at least ``p``: a square covering it ends
    between ``p`` and ``p + k - 1 = r``, all rows seen by then. The rows after the last (no square ends there)
    write the array's last ``k - 1`` rows."""
    h, w = src.shape
    k = 2 * radius + 1
    run = np.zeros(w, np.int32)  # each column's run of src pixels ending at this row
    last = np.full(w, -k, np.int64)  # each column's last row a square ends on
    for r in range(h + k - 1):
        if r < h:
            row = src[r]
            tall = 0  # the columns whose runs are k or longer (none: no square ends on this row)
            for c in range(w):
                n = min(run[c] + 1, k) if row[c] else 0  # k or more alike: capped
                run[c] = n
                tall += n == k
            side = 0  # columns side by side whose runs are k or longer
            for c in range(w if tall >= k else 0):
                side = side + 1 if run[c] == k else 0
                if side >= k:
                    last[c] = r
                    if side == k:  # the square's first k - 1 columns too
                        for j in range(c - k + 1, c):
                            last[j] = r
        p = r - k + 1
        if p >= 0:
            o = out[p]
            for c in range(w):
                o[c] = last[c] >= p


@_njit
def _square_extreme(src: np.ndarray, radius: int, every: bool, out: np.ndarray) -> None:
    """:func:`square_filter`'s ``out``, the same pixels, from the index of the last pixel that decides along each row
    and then down each column (the last false one for ``every``, the last true one else; beyond the array is
    false), with a row of indices where :func:`square_filter` keeps two (h, w) arrays of counts."""
    h, w = src.shape
    t = radius
    horiz = np.empty((h, w), np.bool_)
    for r in range(h):
        last = -1 if every else -(2 * t + 2)
        for c in range(w + t):
            if c < w and src[r, c] != every:
                last = c
            p = c - t
            if p >= 0:
                horiz[r, p] = (last < p - t and c < w) if every else last >= p - t
    last_row = np.full(w, -1 if every else -(2 * t + 2), np.int64)
    for rr in range(h + t):
        if rr < h:
            for c in range(w):
                if horiz[rr, c] != every:
                    last_row[c] = rr
        p = rr - t
        if p >= 0:
            for c in range(w):
                out[p, c] = (last_row[c] < p - t and rr < h) if every else last_row[c] >= p - t


@_njit
def allowed_box(
    hidden: np.ndarray, region: np.ndarray, dr: int, dc: int, gap: int, thin: int
) -> tuple[bool, int, int, int, int]:  # fmt: skip
    """:meth:`symfruit.core.occlusion.Occlusion.extent`'s box of :func:`allowed` (issue 19, eighteenth round): the
    seen pixels are ``region`` (rh, rw) bool placed at row ``dr`` and column ``dc`` of the window (clipped to it),
    the opening and the joins are :func:`allowed`'s (by :func:`_square_extreme`, the same pixels) and the flood fill
    keeps the box of what it reaches, not an image of it. ``(found, r0, r1, c0, c1)``: the box of the allowed
    pixels (stops exclusive), or found False when no seen pixel lies in the window."""
    h, w = hidden.shape
    rh, rw = region.shape
    a0, a1 = max(dr, 0), min(dr + rh, h)
    b0, b1 = max(dc, 0), min(dc + rw, w)
    if a1 <= a0 or b1 <= b0:  # the region wholly off the window
        return False, 0, 0, 0, 0
    # the seen pixels' box, each row or'ed whole (stop 65, look65: the box the pixel by pixel scan found)
    s0, s1, t0, t1 = _mask_box_in(region, a0 - dr, b0 - dc, a1 - a0, b1 - b0)
    if s1 <= s0:
        return False, 0, 0, 0, 0
    s0, s1, t0, t1 = s0 + a0, s1 + a0, t0 + b0, t1 + b0
    seen = np.zeros((h, w), np.bool_)
    for r in range(s0, s1):
        for c in range(t0, t1):
            seen[r, c] = region[r - dr, c - dc]
    join = _joins(hidden, seen, s0, s1, t0, t1, gap, thin)
    r0, r1, c0, c1 = _reach_box(join, seen, s0, s1, t0, t1)  # _flood_box's box (issue 19, twentieth round)
    return True, r0, r1, c0, c1


# --- issue 19, nineteenth round (stop 39): registration, extraction, occlusion ---


@_njit
def outline_pixels(cap: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns (int64, raster order: ``np.nonzero``'s) of the pixels of ``cap`` (h, w) bool not in its
    interior (:func:`symfruit.core.raster.interior`: a pixel whose four neighbours are all ``cap``'s, beyond the array
    none): ``np.nonzero(cap & ~interior(cap))``, the same pixels."""
    h, w = cap.shape
    n = 0
    for r in range(h):
        for c in range(w):
            if cap[r, c] and not (0 < r < h - 1 and 0 < c < w - 1 and cap[r - 1, c] and cap[r + 1, c]
                                  and cap[r, c - 1] and cap[r, c + 1]):  # fmt: skip
                n += 1
    rows, cols = np.empty(n, np.int64), np.empty(n, np.int64)
    i = 0
    for r in range(h):
        for c in range(w):
            if cap[r, c] and not (0 < r < h - 1 and 0 < c < w - 1 and cap[r - 1, c] and cap[r + 1, c]
                                  and cap[r, c - 1] and cap[r, c + 1]):  # fmt: skip
                rows[i], cols[i] = r, c
                i += 1
    return rows, cols


@_njit
def ray_pixels(keep: np.ndarray, r0: int, c0: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Rows and columns (int64, raster order: ``np.nonzero``'s) of the pixels of ``keep`` (h, w) bool and their
    offsets from ``(r0, c0)``, ``rows - r0`` and ``cols - c0``: :func:`symfruit.core.surface.monotone_region`'s
    pixels, the same numbers."""
    h, w = keep.shape
    n = 0
    for r in range(h):
        for c in range(w):
            n += keep[r, c]
    rows, cols = np.empty(n, np.int64), np.empty(n, np.int64)
    dy, dx = np.empty(n, np.int64), np.empty(n, np.int64)
    i = 0
    for r in range(h):
        for c in range(w):
            if keep[r, c]:
                rows[i], cols[i], dy[i], dx[i] = r, c, r - r0, c - c0
                i += 1
    return rows, cols, dy, dx


@_njit
def free_outline(
    depth: np.ndarray, cap: np.ndarray, rows: np.ndarray, cols: np.ndarray, far: float, reach: float, pad: int,
    tol: float = np.inf,
) -> np.ndarray:  # fmt: skip
    """(n,) bool: :func:`symfruit.core.surface._free_points`' free points of the outline ``(rows, cols)`` (n >= 1):
    on the outline's box grown by ``pad`` (clipped to the array), the gap (the pixels not ``cap``'s whose ``depth``
    is at most 0 or at least ``far``), each point free where its distance to the gap is within ``reach`` (as
    :func:`symfruit.core.surface.within` has it: :func:`near_distance`'s square root of the least squared distance
    where that is at most ``reach ** 2``, compared with ``reach``). The same points as the twin's.

    Since issue 19's stop 60 (speedr60) each point looks only at the gap pixels about it instead of a distance map of
    the whole box read at the points: a gap pixel within ``reach`` lies within ``floor(reach)`` rows and columns, and
    whether the least squared distance ``d`` passes (``d <= reach ** 2`` and ``sqrt(d) <= reach``) is whether any
    does (both tests grow with ``d``). The gap is read within the box alone, as the map was made there. Since stop 62
    (reg62) the offsets that pass, on each row ``dr`` of them, are the columns ``|dc| <= m(dr)`` (both tests grow
    with ``|dc|``), and each row of the box holds its running count of gap pixels: whether a point has a gap pixel in
    reach is whether one of its ``2 floor(reach) + 1`` rows counts any within its columns (one difference a row,
    not up to some 50 pixels read a point): the same points.

    Since stop 62 (leaf62) a gap pixel without depth counts only where no pixel other than ``cap``'s within ``reach``
    of it (anywhere in the array) holds depth nearer than the point's own by more than ``tol`` (the twin's
    :func:`symfruit.core.surface._occluders_edge`): a lost band beside something in front is that occluder's edge.
    A gap pixel seen past (at least ``far``) counts as before; ``tol`` infinite (the default, ``extract.occluder_edges``
    off): the former points, by the row counts. With ``tol`` finite (:func:`_free_outline_occluders`; stop 63,
    occw63) the row counts of the pixels seen past and of those without depth tell most points, and only the points
    with a pixel without depth in reach and none seen past look at those pixels, each one's nearest such depth worked
    out once, when first asked."""
    h, w = cap.shape
    rmin, rmax, cmin, cmax = rows[0], rows[0], cols[0], cols[0]
    for i in range(rows.shape[0]):
        rmin, rmax = min(rmin, rows[i]), max(rmax, rows[i])
        cmin, cmax = min(cmin, cols[i]), max(cmax, cols[i])
    r0, c0 = max(rmin - pad, 0), max(cmin - pad, 0)
    r1, c1 = min(rmax + pad + 1, h), min(cmax + pad + 1, w)
    k = math.floor(reach)
    limit = reach * reach
    free = np.zeros(rows.shape[0], np.bool_)
    half = np.full(2 * k + 1, -1, np.int64)  # m(dr): the offsets of row dr in reach are |dc| <= m(dr) (-1: none)
    for dr in range(-k, k + 1):
        for dc in range(k + 1):
            d = dr * dr + dc * dc
            if d <= limit and math.sqrt(float(d)) <= reach:
                half[dr + k] = dc
    if tol < np.inf:
        return _free_outline_occluders(depth, cap, rows, cols, far, tol, r0, r1, c0, c1, k, half, free)
    counts = np.zeros((max(r1 - r0, 0), max(c1 - c0, 0) + 1), np.int32)  # each row's gap pixels before a column
    for rr in range(r0, r1):
        acc = 0
        for cc in range(c0, c1):
            if not cap[rr, cc]:
                z = depth[rr, cc]
                if z <= 0 or z >= far:
                    acc += 1
            counts[rr - r0, cc - c0 + 1] = acc
    for i in range(rows.shape[0]):
        r, c = rows[i], cols[i]
        for dr in range(-k, k + 1):
            a, b = _reach_span(half, k, dr, r, c, r0, r1, c0, c1)
            rr = r + dr
            if a < b and counts[rr - r0, b - c0] > counts[rr - r0, a - c0]:
                free[i] = True
                break
    return free


@_njit_inlined
def _reach_span(
    half: np.ndarray, k: int, dr: int, r: int, c: int, r0: int, r1: int, c0: int, c1: int
) -> tuple[int, int]:
    """The columns ``[a, b)`` of row ``r + dr`` within the box ``r0:r1, c0:c1`` in reach of the point ``(r, c)``
    (``half`` and ``k`` as :func:`free_outline` makes them); ``a >= b`` where none is."""
    m = half[dr + k]
    rr = r + dr
    if m < 0 or rr < r0 or rr >= r1:
        return 0, 0
    return max(c - m, c0), min(c + m + 1, c1)


@_njit
def _free_outline_occluders(
    depth: np.ndarray, cap: np.ndarray, rows: np.ndarray, cols: np.ndarray, far: float, tol: float, r0: int, r1: int,
    c0: int, c1: int, k: int, half: np.ndarray, free: np.ndarray,
) -> np.ndarray:  # fmt: skip
    """:func:`free_outline` with ``tol`` finite (``extract.occluder_edges``; stop 62, leaf62): a gap pixel without
    depth counts only where no depth off the cap within ``reach`` of it is nearer than the point's own by more than
    ``tol``; ``free`` (n,) False, filled and returned. The box ``r0:r1, c0:c1``, ``k = floor(reach)`` and ``half``
    (m(dr): the offsets of row ``dr`` in reach are ``|dc| <= m(dr)``, -1 none) as :func:`free_outline` has them.

    Since stop 63 (occw63) each row of the box holds two running counts, of the pixels seen past (at least ``far``)
    and of those without depth (at most 0), where the former path holds one: a point with a pixel seen past in
    reach is free, one with neither kind is not (the occluder test cannot make it free), both by
    ``2 floor(reach) + 1`` differences. Only the points left (a pixel without depth in reach, none seen past) look at
    those pixels, row by row (the rows whose count holds one), each one's nearest depth off the cap worked out once,
    when first asked, from the depth above 0 off the cap of the box grown by ``k`` (made when first needed). Stop
    62's walk read up to some 50 pixels a point, nearest first, for every point: the same points (any order finds
    whether one passes)."""
    h, w = cap.shape
    bh, bw = max(r1 - r0, 0), max(c1 - c0, 0)
    past = np.zeros((bh, bw + 1), np.int32)  # each row's pixels seen past before a column
    lost = np.zeros((bh, bw + 1), np.int32)  # and its pixels without depth
    for rr in range(r0, r1):
        a_past, a_lost = 0, 0
        for cc in range(c0, c1):
            if not cap[rr, cc]:
                z = depth[rr, cc]
                if z >= far:
                    a_past += 1
                elif z <= 0:
                    a_lost += 1
            past[rr - r0, cc - c0 + 1] = a_past
            lost[rr - r0, cc - c0 + 1] = a_lost
    g0, g1, e0, e1 = max(r0 - k, 0), min(r1 + k, h), max(c0 - k, 0), min(c1 + k, w)
    other = np.empty((0, 0))  # the depth above 0 off the cap (+inf elsewhere) of the box grown by k, when first needed
    nearest = np.empty((0, 0))  # the least of it within reach of each pixel of the box without depth (NaN: not yet)
    for i in range(rows.shape[0]):
        r, c = rows[i], cols[i]
        some_lost = False
        for dr in range(-k, k + 1):
            a, b = _reach_span(half, k, dr, r, c, r0, r1, c0, c1)
            rr = r + dr
            if a < b:
                if past[rr - r0, b - c0] > past[rr - r0, a - c0]:
                    free[i] = True
                    break
                if lost[rr - r0, b - c0] > lost[rr - r0, a - c0]:
                    some_lost = True
        if free[i] or not some_lost:
            continue
        if other.shape[0] == 0:
            other = np.full((g1 - g0, e1 - e0), np.inf)
            for r2 in range(g0, g1):
                for c2 in range(e0, e1):
                    if not cap[r2, c2]:
                        z2 = depth[r2, c2]
                        if z2 > 0:
                            other[r2 - g0, c2 - e0] = z2
            nearest = np.full((bh, bw), np.nan)
        bound = depth[r, c] - tol
        for dr in range(-k, k + 1):  # the pixels without depth in reach (no pixel seen past is): is one free?
            a, b = _reach_span(half, k, dr, r, c, r0, r1, c0, c1)
            rr = r + dr
            if a >= b or lost[rr - r0, b - c0] == lost[rr - r0, a - c0]:
                continue
            for cc in range(a, b):
                if cap[rr, cc] or not depth[rr, cc] <= 0:
                    continue
                m2 = nearest[rr - r0, cc - c0]
                if m2 != m2:  # first asked: the least depth above 0 about it, off the cap (anywhere in the array)
                    m2 = np.inf
                    for dr2 in range(-k, k + 1):
                        m3 = half[dr2 + k]
                        r2 = rr + dr2
                        if m3 < 0 or r2 < 0 or r2 >= h:
                            continue
                        for c2 in range(max(cc - m3, 0), min(cc + m3 + 1, w)):
                            v = other[r2 - g0, c2 - e0]
                            if v < m2:
                                m2 = v
                    nearest[rr - r0, cc - c0] = m2
                if not m2 < bound:  # not an occluder's lost edge: this silhouette's
                    free[i] = True
                    break
            if free[i]:
                break
    return free


# --- issue 19, twentieth round (stop 40): registration and trimming ---------------------------------------------


@_njit_inlined
def _envelope(f: np.ndarray, w: int, s: np.ndarray, t: np.ndarray, d2: np.ndarray) -> None:
    """``d2[u]`` (w,) the least ``(u - i)^2 + f[i]`` over the columns ``i`` of one row (``f`` (w,) whole numbers): the
    lower envelope of the parabolas, :func:`distance`'s second phase (``s``, ``t`` (w,) its scratch);
    :func:`_envelope_of` over every column."""
    _envelope_of(f, 0, w - 1, w, s, t, d2)


@_njit_inlined
def _envelope_of(f: np.ndarray, lo: int, hi: int, w: int, s: np.ndarray, t: np.ndarray, d2: np.ndarray) -> None:
    """``d2[u]`` (w,) the least ``(u - i)^2 + f[i]`` over the columns ``lo <= i <= hi`` alone (``0 <= lo <= hi < w``),
    for every column ``u`` of the row (stop 46, regspeed46): :func:`_envelope`'s steps with the parabolas of those
    columns only, over the same domain. Where every other column's parabola lies above one of these everywhere (the
    caller's columns without a mask pixel, whose ``f`` exceeds any squared distance within the image), the same
    least, so the same numbers as :func:`_envelope` over the whole row."""
    q = _hull(f, lo, hi, w, s, t)
    for u in range(w - 1, -1, -1):
        a = u - s[q]
        d2[u] = a * a + f[s[q]]
        if u == t[q]:
            q -= 1


@_njit_inlined
def _hull(f: np.ndarray, lo: int, hi: int, w: int, s: np.ndarray, t: np.ndarray) -> int:
    """:func:`_envelope_of`'s lower envelope of the parabolas ``(u - i)^2 + f[i]`` of the columns ``lo <= i <= hi``
    over the columns ``0 <= u < w``: its last parabola's place ``q``; parabola ``j <= q`` (column ``s[j]``) is the
    least from column ``t[j]`` (``t[0] = 0``, ascending) up to the next one's start (``w`` after the last)."""
    q = 0
    s[0] = lo
    t[0] = 0
    for u in range(lo + 1, hi + 1):
        while q >= 0:
            a, b = t[q] - s[q], t[q] - u
            if a * a + f[s[q]] <= b * b + f[u]:
                break
            q -= 1
        if q < 0:
            q = 0
            s[0] = u
        else:
            i = s[q]
            start = 1 + (u * u - i * i + f[u] - f[i]) // (2 * (u - i))
            if start < w:
                q += 1
                s[q] = u
                t[q] = start
    return q


@_njit_inlined
def _hull_of(f: np.ndarray, sites: np.ndarray, n: int, w: int, s: np.ndarray, t: np.ndarray) -> int:
    """:func:`_hull` of the parabolas of the columns ``sites[:n]`` alone (ascending, ``n >= 1``): the same steps over
    those columns (the lower envelope of any ascending columns)."""
    q = 0
    s[0] = sites[0]
    t[0] = 0
    for m in range(1, n):
        u = sites[m]
        while q >= 0:
            a, b = t[q] - s[q], t[q] - u
            if a * a + f[s[q]] <= b * b + f[u]:
                break
            q -= 1
        if q < 0:
            q = 0
            s[0] = u
        else:
            i = s[q]
            start = 1 + (u * u - i * i + f[u] - f[i]) // (2 * (u - i))
            if start < w:
                q += 1
                s[q] = u
                t[q] = start
    return q


@_njit
def outline_maps(
    mask: np.ndarray, pad: int, reach: int, inner: np.ndarray, inside: np.ndarray
) -> tuple[bool, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.core.surface._outline`'s maps of a mask (h, w) bool holding pixels of both kinds, in one call:
    ``inner`` (h, w) its distance map (:func:`symfruit.core.raster.inner_distance`, 0 off the mask) and ``inside``
    (h, w) the signed one (``inner - distance_transform(~mask)``: ``-`` each outside pixel's distance to the mask),
    written in place; and, where its whole-number keys fit 16 bits, :meth:`symfruit.core.surface._Outline.keys` of
    pad ``pad`` and reach ``reach`` (int16, flattened) and :meth:`~symfruit.core.surface._Outline.ranks` (the places
    and values): ``(True, keys, ranks, values)``; else ``(False, ...)`` with those left empty.

    Both transforms are :func:`distance`'s (Meijster's, in whole numbers): one column pass for both (each pixel's
    distance along its column to the nearest pixel of the other kind), then each row's lower envelope of the
    parabolas for the mask's pixels (over the row's mask pixels and one column either side: the columns beyond are
    farther outside pixels) and for the others (rows without such pixels skipped: their distances are 0; since stop
    46 over the parabolas of the mask's columns alone, :func:`_envelope_of`: a column without a mask pixel has a
    column distance of at least ``h + w``, so its parabola is above every other column's everywhere). The same
    least squared distances, so the same square roots (read off the ranks' values where there are ranks), keys,
    places and values as the twins', bit for bit."""
    h, w = mask.shape
    big = h + w  # farther than any pixel: a column without a pixel of the other kind
    g = np.empty((h, w), np.int64)
    for c in range(w):
        g[0, c] = big
    for r in range(1, h):
        for c in range(w):
            g[r, c] = g[r - 1, c] + 1 if mask[r, c] == mask[r - 1, c] else 1
    for r in range(h - 2, -1, -1):
        for c in range(w):
            if mask[r, c] != mask[r + 1, c]:
                g[r, c] = 1
            elif g[r + 1, c] + 1 < g[r, c]:
                g[r, c] = g[r + 1, c] + 1
    key = np.empty((h, w), np.int64)  # sign * the squared distance: + on the mask, - off it
    f = np.empty(w, np.int64)
    s = np.empty(w, np.int64)
    t = np.empty(w, np.int64)
    d2 = np.empty(w, np.int64)
    floor = -(reach * reach)
    top = reach * reach
    low, high = (floor, floor) if pad > 0 else (np.int64(2**62), -np.int64(2**62))
    firsts, lasts, n_ins = np.empty(h, np.int64), np.empty(h, np.int64), np.empty(h, np.int64)
    lo_c, hi_c = w, -1  # the mask's first and last column: the outside pixels' only sites (stop 46)
    for r in range(h):
        first, last, n_in = w, -1, 0
        for c in range(w):
            if mask[r, c]:
                first, last, n_in = min(first, c), c, n_in + 1
        firsts[r], lasts[r], n_ins[r] = first, last, n_in
        lo_c, hi_c = min(lo_c, first), max(hi_c, last)
    for r in range(h):
        first, last, n_in = firsts[r], lasts[r], n_ins[r]
        if last >= 0:  # the mask's pixels: their envelope over their columns and one more either side
            a, b = max(first - 1, 0), min(last + 1, w - 1)
            for c in range(a, b + 1):
                f[c - a] = g[r, c] * g[r, c] if mask[r, c] else 0
            _envelope(f, b + 1 - a, s, t, d2)
            for c in range(first, last + 1):
                if mask[r, c]:
                    k = d2[c - a]
                    key[r, c] = k
                    top, high = max(top, k), max(high, k)
        if n_in < w:  # outside pixels in the row: their envelope over the whole row, of the mask's columns' parabolas
            for c in range(lo_c, hi_c + 1):
                f[c] = 0 if mask[r, c] else g[r, c] * g[r, c]
            _envelope_of(f, lo_c, hi_c, w, s, t, d2)
            for c in range(w):
                if not mask[r, c]:
                    k = d2[c]
                    key[r, c] = -k
                    top, low = max(top, k), min(low, -k)
    return _outline_keys(mask, key, pad, reach, top, low, high, inner, inside)


@_njit
def _outline_keys(
    mask: np.ndarray, key: np.ndarray, pad: int, reach: int, top: int, low: int, high: int, inner: np.ndarray,
    inside: np.ndarray,
) -> tuple[bool, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`outline_maps`' maps, keys and ranks from the whole-number keys ``key`` (h, w) int64 (sign * the squared
    distance: + on ``mask``, - off it), their largest magnitude ``top`` and their least and largest ``low``,
    ``high`` (with ``-reach ** 2`` where ``pad`` is above 0): what :func:`outline_maps` returns (shared with
    :func:`outline_windows`)."""
    h, w = mask.shape
    floor = -(reach * reach)
    low, high = min(low, high), max(low, high)  # a map of one kind of pixel only: one of them still unset
    if top >= 2**15 - 1:  # no 16-bit keys: the maps alone, by their square roots
        for r in range(h):
            for c in range(w):
                k = key[r, c]
                d = math.sqrt(float(k if k >= 0 else -k))
                inner[r, c] = d if mask[r, c] else 0.0
                inside[r, c] = d if mask[r, c] else -d
        return False, np.empty(0, np.int16), np.empty(0, np.int32), np.empty(0)
    place = np.zeros(high - low + 1, np.int64)
    if pad > 0:
        place[floor - low] = 1
    for r in range(h):
        for c in range(w):
            place[key[r, c] - low] = 1
    m = 0
    for v in range(high - low + 1):
        if place[v]:
            place[v] = m
            m += 1
        else:
            place[v] = -1
    values = np.empty(m)
    for v in range(high - low + 1):
        if place[v] >= 0:
            whole = float(v + low)
            values[place[v]] = np.sign(whole) * np.sqrt(abs(whole))
    width = w + 2 * pad
    keys = np.empty((h + 2 * pad) * width, np.int16)
    ranks = np.empty((h + 2 * pad) * width, np.int32)
    border = place[floor - low] if pad > 0 else 0
    for r in range(h + 2 * pad):  # the border: all of the first and last pad rows, pad columns either side between
        whole_row = r < pad or r >= h + pad
        for c in range(width):
            if whole_row or c < pad or c >= pad + w:
                keys[r * width + c] = floor
                ranks[r * width + c] = border
    for r in range(h):
        base = (r + pad) * width + pad
        for c in range(w):
            k = key[r, c]
            i = place[k - low]
            d = values[i]  # sign * sqrt(|k|): the square root itself, or its negative
            inner[r, c] = d if mask[r, c] else 0.0
            inside[r, c] = d
            keys[base + c] = k
            ranks[base + c] = i
    return True, keys, ranks, values


@_njit
def connected_at(image: np.ndarray, r: int, c: int, out: np.ndarray) -> None:
    """``out`` (h, w) bool: the piece of ``image`` (h, w) bool (4-connected) holding its pixel ``(r, c)`` (which must
    be ``image``'s): :func:`connected` with that pixel alone for seed, without a seed image and its scan (the same
    pixels)."""
    h, w = image.shape
    for i in range(h):
        for j in range(w):
            out[i, j] = False
    out[r, c] = True
    stack = np.empty(h * w, np.int64)
    stack[0] = r * w + c
    _flood(image, out, stack, 1)


@_njit
def trim_features(
    color: np.ndarray, inner: np.ndarray, mask: np.ndarray, band_px: float, deep: float, ring_px: float,
    fruit: np.ndarray, band: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, int]:  # fmt: skip
    """:func:`trim_regions` (the fruit and band written into ``fruit`` and ``band`` (h, w) bool, the ring not kept)
    and :func:`colour_features` of the fruit's and the ring's pixels of ``color`` (h, w, 3) uint8 in one call: the
    features (n, 3) and (m, 3) in raster order, and how many pixels the band holds (the same pixels and values)."""
    h, w = mask.shape
    near = np.empty((h, w))
    # stop 60 (speeds60): the distances over the mask's box grown by the reach and a pixel alone, +inf beyond it (no
    # mask pixel lies within the reach of a pixel outside it; inside it each column's nearest mask pixel and each
    # row's uncapped columns are the whole window's, the columns and rows left out all capped): the same values
    r0, r1, c0, c1 = _rows_box(mask)
    near[:] = np.inf
    if r1 > 0:
        g = math.floor(ring_px) + 1
        a0, a1, b0, b1 = max(r0 - g, 0), min(r1 + g, h), max(c0 - g, 0), min(c1 + g, w)
        near_distance(mask[a0:a1, b0:b1], ring_px, True, near[a0:a1, b0:b1])
    n_fruit = n_ring = n_band = 0
    for r in range(h):
        for c in range(w):
            d = inner[r, c]
            f = d > band_px and d <= deep
            b = mask[r, c] and d <= band_px
            fruit[r, c], band[r, c] = f, b
            n_fruit += f
            n_ring += (not mask[r, c]) and near[r, c] <= ring_px
            n_band += b
    f_fruit, f_ring = np.empty((n_fruit, 3)), np.empty((n_ring, 3))
    i = j = 0
    for r in range(h):
        for c in range(w):
            ring = (not mask[r, c]) and near[r, c] <= ring_px
            if fruit[r, c] or ring:
                red, green, blue = float(color[r, c, 0]), float(color[r, c, 1]), float(color[r, c, 2])
                total = red + green + blue + 1.0
                out = f_fruit if fruit[r, c] else f_ring
                k = i if fruit[r, c] else j
                out[k, 0] = red / total
                out[k, 1] = green / total
                out[k, 2] = 0.25 * total / (3 * 255.0)
                if fruit[r, c]:
                    i += 1
                else:
                    j += 1
    return f_fruit, f_ring, n_band


@_njit
def trim_summary(x: np.ndarray, pick: np.ndarray, start: np.ndarray, iterations: int) -> np.ndarray:
    """:func:`symfruit.core.surface._colour_trim`'s summary of the rows ``pick`` (m,) of ``x`` (n, 3): :func:`kmeans`
    of ``x[pick]`` from its rows ``start`` (k,), gathered here instead of by numpy (the same rows, so the same
    centres)."""
    m = pick.shape[0]
    rows = np.empty((m, 3))
    for i in range(m):
        for a in range(3):
            rows[i, a] = x[pick[i], a]
    c = np.empty((start.shape[0], 3))
    for j in range(start.shape[0]):
        for a in range(3):
            c[j, a] = rows[start[j], a]
    return kmeans(rows, c, iterations)


@_njit
def trim_separation(fruit: np.ndarray, ring: np.ndarray, fc: np.ndarray, bc: np.ndarray) -> tuple[int, int]:
    """How many rows of ``fruit`` (n, 3) are nearer the fruit's centres ``fc`` than the surroundings' ``bc``
    (:func:`nearer_fruit`, margin 1) and how many rows of ``ring`` (m, 3) are not: the counts behind
    :func:`symfruit.core.surface._colour_trim`'s two accuracies (``mean()`` of those booleans: the count over the
    rows), without their arrays."""
    n_fruit = 0
    for i in range(fruit.shape[0]):
        n_fruit += 1.0 * _nearest_centre(fruit, i, fc)[1] <= _nearest_centre(fruit, i, bc)[1]
    n_ring = 0
    for i in range(ring.shape[0]):
        n_ring += not (1.0 * _nearest_centre(ring, i, fc)[1] <= _nearest_centre(ring, i, bc)[1])
    return n_fruit, n_ring


@_njit
def trim_band(
    color: np.ndarray, mask: np.ndarray, band: np.ndarray, fc: np.ndarray, bc: np.ndarray, margin: float,
    out: np.ndarray,
) -> None:  # fmt: skip
    """``out`` (h, w) bool: ``mask`` with each pixel of ``band`` (h, w) bool kept only where its colour feature
    (:func:`colour_features`' arithmetic) is nearer the fruit's centres ``fc`` than the surroundings' ``bc`` by
    ``margin`` (:func:`nearer_fruit`): :func:`symfruit.core.surface._colour_trim`'s ``keep[band] = is_fruit(
    feature(color, band), margin)`` in one pass, the same pixels."""
    h, w = mask.shape
    x = np.empty((1, 3))
    for r in range(h):
        for c in range(w):
            if band[r, c]:
                red, green, blue = float(color[r, c, 0]), float(color[r, c, 1]), float(color[r, c, 2])
                total = red + green + blue + 1.0
                x[0, 0] = red / total
                x[0, 1] = green / total
                x[0, 2] = 0.25 * total / (3 * 255.0)
                out[r, c] = margin * _nearest_centre(x, 0, fc)[1] <= _nearest_centre(x, 0, bc)[1]
            else:
                out[r, c] = mask[r, c]


# --- issue 19, stop 41 (speedreg41): the registration's fast costs of every outline in one call ---------------


@_njit
def _fast_cost(
    ranks: np.ndarray, values: np.ndarray, at: np.ndarray, offset: int, keep: int, band: float, count: np.ndarray,
    row: np.ndarray,
) -> float:  # fmt: skip
    """:func:`outline_costs`' cost of one shift, the points' flat indices ``at`` (n,) moved back by ``offset`` (``dv *
    width + du``): ``count`` (the ranks' counts, all 0) and ``row`` (n,) its scratch, ``count`` left all 0."""
    n = at.shape[0]
    size = values.shape[0]
    lower, upper = (n - 1) // 2, n // 2  # np.median's two middle places (one when n is odd)
    low, top = size, -1
    for j in range(n):  # the points' ranks, their least and largest, then their counts: three plain loops (stop
        row[j] = ranks[at[j] - offset]  # 60: about a tenth faster than one loop doing all three; the same numbers)
    for j in range(n):
        r = row[j]
        low, top = min(low, r), max(top, r)
    for j in range(n):
        count[row[j]] += 1
    b, seen = low, count[low]  # the rank holding place `lower`, and how many places lie up to its end
    while seen <= lower:
        b += 1
        seen += count[b]
    first = float(values[b])
    if seen <= upper:  # place `upper` is in the next rank that holds any
        b += 1
        while count[b] == 0:
            b += 1
        second = float(values[b])
    else:
        second = first
    median = 0.5 * (first + second) if n % 2 == 0 else second
    middle = min(max(median, 0.0), band)
    # the first rank at or above the band (bisected: values ascend), the one below it: the nearer one taken first
    right = low + np.searchsorted(values[low : top + 1], middle)
    left = right - 1
    need = keep
    total = 0.0
    while need > 0:
        while left >= low and count[left] == 0:
            left -= 1
        while right <= top and count[right] == 0:
            right += 1
        below = middle - float(values[left]) if left >= low else np.inf
        above = float(values[right]) - middle if right <= top else np.inf
        if below < above:
            take = min(int(count[left]), need)
            total += take * below
            left -= 1
        else:
            take = min(int(count[right]), need)
            total += take * above
            right += 1
        need -= take
    for j in range(n):
        count[row[j]] = 0
    return total / keep


@_njit
def frame_costs(
    ranks: np.ndarray, values: np.ndarray, at: np.ndarray, starts: np.ndarray, widths: np.ndarray,
    keeps: np.ndarray, bands: np.ndarray, axes: np.ndarray, order: np.ndarray, shifts: np.ndarray, stage: int,
    best: int, upper: float, slack: float, out: np.ndarray,
) -> np.ndarray:  # fmt: skip
    """Fast costs (:func:`outline_costs`'s, each the same number) of a frame's ``m`` outlines into ``out`` (m, k), in
    one call each stage of :meth:`symfruit.core.surface._FrameCosts.least` (issue 19, stop 41; its numpy twin is
    ``_FrameCosts._twin_stage``). Outline ``o``'s ranks, values and points are ``ranks[starts[o, 0]:starts[o + 1,
    0]]``, ``values[starts[o, 1]:...]`` and ``at[starts[o, 2]:...]`` (``starts`` (m + 1, 3)), its padded width
    ``widths[o]``, with ``keeps[o]`` and ``bands[o]``; each shift (k, 2) ``(dv, du)`` costed as far as the outline
    tells it (``axes`` (m, 2) bool: as :func:`symfruit.core.surface._told`, the cost of the shift with its untold
    part 0, each distinct one once).

    The outlines are costed in the order ``order`` (m,) (a permutation; stop 42), each into its own row. ``stage`` 0:
    the first outline ``f = order[0]`` at every shift (row ``f``), returning ``[np.argmin(row f)]``; 1: every other
    outline at the shift ``best`` (column ``best``), returning ``[best]``; 2: with row ``f`` and column ``best``
    written, each further outline, in order, at the shifts whose costs summed so far (in that order) are at most
    the limit (:func:`prune_limit` of ``upper``, a frame cost at some shift, and ``slack``; row ``f``'s shifts within
    it to start), returning those left (ascending), whose columns hold every outline's cost. After each outline but
    the last, the shift left of least sum so far (the first such) is costed by every outline not yet (stop 42): its
    frame cost (the outlines' costs summed in the rows' order, over ``m``) lowers ``upper`` and the limit when it is
    less. 3:
    as 2 without a limit (every outline at every shift). Other entries of ``out`` are not written."""
    m, k = out.shape
    span = 0
    for s in range(k):
        span = max(span, abs(shifts[s, 0]), abs(shifts[s, 1]))
    seen = np.zeros(2 * span + 1, np.bool_)  # a one-axis outline's cost per value of its told axis
    cached = np.empty(2 * span + 1)
    size, n_max = 1, 1
    for o in range(m):
        size = max(size, starts[o + 1, 1] - starts[o, 1])
        n_max = max(n_max, starts[o + 1, 2] - starts[o, 2])
    count = np.zeros(size, np.int64)
    row = np.empty(n_max, np.int64)

    def once(o: int, s: int) -> float:
        dv = shifts[s, 0] if axes[o, 0] else 0
        du = shifts[s, 1] if axes[o, 1] else 0
        rk = ranks[starts[o, 0] : starts[o + 1, 0]]
        va = values[starts[o, 1] : starts[o + 1, 1]]
        pts = at[starts[o, 2] : starts[o + 1, 2]]
        return _fast_cost(rk, va, pts, dv * widths[o] + du, keeps[o], bands[o], count, row)

    def told(o: int, s: int) -> float:
        if axes[o, 0] and axes[o, 1]:
            return once(o, s)
        i = (shifts[s, 0] if axes[o, 0] else 0) + (shifts[s, 1] if axes[o, 1] else 0) + span  # one of them is 0
        if not seen[i]:
            cached[i] = once(o, s)
            seen[i] = True
        return cached[i]

    first = order[0]
    if stage == 0:
        least, at_least = 0, np.inf
        for s in range(k):
            c = told(first, s)
            out[first, s] = c
            if c < at_least or (math.isnan(c) and not math.isnan(at_least)):  # np.argmin's: the first least or NaN
                least, at_least = s, c
        return np.array([least], np.int64)
    if stage == 1:
        for n in range(1, m):
            seen[:] = False
            out[order[n], best] = told(order[n], best)
        return np.array([best], np.int64)
    prune = stage == 2
    limit = prune_limit(upper, slack, m) if prune else np.inf
    full = np.zeros(k, np.bool_)  # the shifts every outline is costed at already
    if prune:
        full[best] = True
    alive = np.empty(k, np.int64)
    summed = np.empty(k)
    n_alive = 0
    for s in range(k):
        if not prune or out[first, s] <= limit:
            alive[n_alive] = s
            summed[n_alive] = out[first, s]
            n_alive += 1
    for n in range(1, m):
        o = order[n]
        seen[:] = False
        kept = 0
        for i in range(n_alive):
            s = alive[i]
            if not full[s]:
                out[o, s] = told(o, s)
            total = summed[i] + out[o, s]
            if not prune or total <= limit:
                alive[kept] = s
                summed[kept] = total
                kept += 1
        n_alive = kept
        if prune and n < m - 1 and n_alive > 1:
            j = 0
            for i in range(1, n_alive):
                if summed[i] < summed[j]:
                    j = i
            s = alive[j]
            if not full[s]:
                for p in range(n + 1, m):
                    out[order[p], s] = once(order[p], s)
                full[s] = True
                total = 0.0
                for p in range(m):
                    total += out[p, s]
                mean = total / m
                if mean < upper:
                    upper, limit = mean, prune_limit(mean, slack, m)
    return alive[:n_alive].copy()


# --- stop 42, speedreg42: the registration's pruning bound -----------------------------------------------------------


@_njit
def prune_limit(upper: float, slack: float, count: int) -> float:
    """:func:`symfruit.core.surface._limit`'s twin: the bound of ``count`` outlines' fast costs summed at a shift that
    can be the least one, from a frame cost ``upper`` (the same expression, the same number)."""
    return (upper + 2.0 * slack + 1e-9 * (1.0 + upper)) * count


@_njit
def trim_kept(
    color: np.ndarray, mask: np.ndarray, band: np.ndarray, fruit: np.ndarray, fc: np.ndarray, bc: np.ndarray,
    margin: float, out: np.ndarray,
) -> None:  # fmt: skip
    """``out`` (h, w) bool: :func:`symfruit.core.surface._colour_trim`'s last step in one call (stop 42): the band's
    test (:func:`trim_band`), the pieces holding a pixel of ``fruit`` (:func:`connected`) and their holes filled
    (:func:`filled` over the pieces' box grown by a pixel, as :func:`symfruit.core.raster.fill_holes`), without the
    Python-level calls, box and copies between them: the same pixels."""
    h, w = mask.shape
    keep = np.empty((h, w), np.bool_)
    trim_band(color, mask, band, fc, bc, margin, keep)
    connected(keep, fruit, out)
    r0, r1, c0, c1 = _box(out)
    if r1 == 0:
        return
    r0, r1, c0, c1 = max(r0 - 1, 0), min(r1 + 1, h), max(c0 - 1, 0), min(c1 + 1, w)
    pieces = out[r0:r1, c0:c1].copy()
    filled(pieces, out[r0:r1, c0:c1])


# --- issue 19, sixteenth round: the colour segmenter's red pixels and windows --------------------------------------


@_njit
def _root(parent: np.ndarray, i: int) -> int:
    """The root of ``i`` in a union-find forest, the path halved on the way (:func:`join_boxes`, :func:`_union`)."""
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


@_njit
def join_boxes(boxes: np.ndarray) -> np.ndarray:
    """:func:`symfruit.segment.colour._join_boxes` of ``boxes`` (n, 4) int64 rows ``(r0, r1, c0, c1)``: (m, 4). The
    twin's rounds: the boxes that overlap along one axis and overlap or abut along the other joined (the same
    connected groups, found by union-find instead of scipy's graph), each group's bounding box, ordered by its top row
    and then by the least left column of its boxes on that row (no two groups share both); the boxes as they are
    once no two join. Whole numbers: the same boxes in the same order."""
    b = boxes.copy()
    while b.shape[0] > 0:
        n = b.shape[0]
        parent = np.arange(n)
        joined = False
        for i in range(n):
            for j in range(i + 1, n):
                rows_over = b[i, 0] < b[j, 1] and b[j, 0] < b[i, 1]
                rows_touch = b[i, 0] <= b[j, 1] and b[j, 0] <= b[i, 1]
                cols_over = b[i, 2] < b[j, 3] and b[j, 2] < b[i, 3]
                cols_touch = b[i, 2] <= b[j, 3] and b[j, 2] <= b[i, 3]
                if (rows_over and cols_touch) or (rows_touch and cols_over):
                    joined = True
                    ri, rj = _root(parent, i), _root(parent, j)
                    if ri != rj:
                        parent[max(ri, rj)] = min(ri, rj)
        if not joined:
            break
        group = np.empty(n, np.int64)
        slot = np.full(n, -1, np.int64)
        m = 0
        for i in range(n):
            r = _root(parent, i)
            if slot[r] < 0:
                slot[r] = m
                m += 1
            group[i] = slot[r]
        big = np.iinfo(np.int64).max
        top = np.full(m, big, np.int64)
        left = np.full(m, big, np.int64)
        first = np.full(m, big, np.int64)
        bottom = np.zeros(m, np.int64)
        right = np.zeros(m, np.int64)
        for i in range(n):
            g = group[i]
            top[g] = min(top[g], b[i, 0])
            left[g] = min(left[g], b[i, 2])
            bottom[g] = max(bottom[g], b[i, 1])
            right[g] = max(right[g], b[i, 3])
        for i in range(n):
            g = group[i]
            if b[i, 0] == top[g]:
                first[g] = min(first[g], b[i, 2])
        by_first = np.argsort(first, kind="mergesort")
        order = by_first[np.argsort(top[by_first], kind="mergesort")]
        out = np.empty((m, 4), np.int64)
        for k in range(m):
            g = order[k]
            out[k, 0], out[k, 1], out[k, 2], out[k, 3] = top[g], bottom[g], left[g], right[g]
        b = out
    return b


@_njit
def red_pixels(
    c: np.ndarray, low: np.ndarray, high: np.ndarray, sqrt3: float, tan_hue: float
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.segment.colour._red_pixels` of ``c`` (h, w, 3) uint8 (a window of an image, any strides) with
    its tables ``low``, ``high`` (256,) int16 and the hue test's ``sqrt(3)`` and ``tan(hue_max)``: the flat indices
    (ascending, in the window) of the weakly and the strongly red pixels. Pixel by pixel, the twin's tests on the same
    whole numbers and products: the same pixels."""
    h, w = c.shape[0], c.shape[1]
    weak = np.empty(h * w, np.int64)
    strong = np.empty(h * w, np.int64)
    n_weak = n_strong = 0
    for r in range(h):
        for q in range(w):
            red = np.int64(c[r, q, 0])
            kind = _red_kind(red, np.int64(c[r, q, 1]), np.int64(c[r, q, 2]), low[red], high[red], sqrt3, tan_hue)
            if kind == 0:
                continue
            weak[n_weak] = r * w + q
            n_weak += 1
            if kind == 2:
                strong[n_strong] = r * w + q
                n_strong += 1
    return weak[:n_weak].copy(), strong[:n_strong].copy()


@_njit
def _red_kind(red: int, green: int, blue: int, low: int, high: int, sqrt3: float, tan_hue: float) -> int:
    """The red tests of a pixel (:func:`red_pixels`' and :func:`red_regions_once`'s, on the twin's whole numbers and
    products) from its channels and the tables' entries at its red (``low[red]``, ``high[red]``): 0 not red, 1 weakly
    red, 2 strongly red too. Whole numbers, no arrays: with the image and tables as arguments it was not inlined and
    their reference counts were taken and dropped on every call (6 increfs, 13 decrefs in its caller's loop), per
    pixel 15 of a 1920x1080 tree frame's 58 ms (stop 42)."""
    most = max(green, blue)
    if red <= most or most > low:
        return 0
    if most <= high and sqrt3 * float(green - blue) < tan_hue * float(2 * red - green - blue):
        return 2
    return 1


@_njit
def window_points(
    mask: np.ndarray, depth: np.ndarray, r0: int, c0: int, cx: float, cy: float, focal: float, most: int
) -> np.ndarray:  # fmt: skip
    """:func:`symfruit.segment.colour._points`: (n, 3) the camera-frame points of the pixels of ``mask`` with depth
    (``depth > 0``) in a window at ``(r0, c0)``, in raster order; at most ``most`` of them, picked as the twin's
    ``np.linspace(0, n - 1, most)`` truncated (``k * step``, the last ``n - 1``). The same products and quotients:
    the same points."""
    h, w = mask.shape
    rows = np.empty(h * w, np.int64)
    cols = np.empty(h * w, np.int64)
    n = 0
    for r in range(h):
        for c in range(w):
            if mask[r, c] and depth[r, c] > 0:
                rows[n], cols[n] = r, c
                n += 1
    m = n
    if n > most:
        m = most
        step = float(n - 1) / (most - 1)
        for k in range(most):
            at = n - 1 if k == most - 1 else np.int64(k * step + 0.0)
            rows[k], cols[k] = rows[at], cols[at]
    out = np.empty((m, 3))
    for k in range(m):
        z = depth[rows[k], cols[k]]
        out[k, 0] = float(cols[k] + c0) - cx
        out[k, 0] = out[k, 0] * z / focal
        out[k, 1] = float(rows[k] + r0) - cy
        out[k, 1] = out[k, 1] * z / focal
        out[k, 2] = z
    return out


@_njit
def sphere_inliers(p: np.ndarray, centre: np.ndarray, radius: float) -> np.ndarray:
    """:func:`symfruit.segment.colour._sphere`'s points ``p`` (n, 3; n >= 1, finite) kept after a fit: those whose
    distance off the sphere (``|row_norm(p - centre) - radius|``, the twin's terms in its order) is at most 3 x
    1.4826 times the median distance (:func:`_median_of`'s value: np.median's), or 1e-4. The same points."""
    n = p.shape[0]
    res = np.empty(n)
    for i in range(n):
        a, b, c = p[i, 0] - centre[0], p[i, 1] - centre[1], p[i, 2] - centre[2]
        res[i] = abs(math.sqrt(a * a + b * b + c * c) - radius)
    limit = 3.0 * median_of_quick(res) * 1.4826  # _median_of's value (stop 49)
    if 1e-4 > limit:
        limit = 1e-4
    keep = 0
    for i in range(n):
        keep += res[i] <= limit
    out = np.empty((keep, 3))
    k = 0
    for i in range(n):
        if res[i] <= limit:
            out[k, 0], out[k, 1], out[k, 2] = p[i, 0], p[i, 1], p[i, 2]
            k += 1
    return out


# --- issue 19, seventeenth round: the colour segmenter ------------------------------------------------------------


@_njit_inlined
def _row_ends(mask: np.ndarray, r: int) -> tuple[int, int]:
    """``(first, last)``: the columns of row ``r``'s first and last true pixel of ``mask`` (h, w) bool, found from both
    ends of the row; ``(-1, -1)`` where it holds none."""
    w = mask.shape[1]
    first = -1
    for c in range(w):
        if mask[r, c]:
            first = c
            break
    if first < 0:
        return -1, -1
    last = first
    for c in range(w - 1, first, -1):
        if mask[r, c]:
            last = c
            break
    return first, last


@_njit
def hull_vertices(mask: np.ndarray) -> np.ndarray:
    """:func:`symfruit.segment.colour._hull_vertices` of a 2-d bool ``mask``: (m, 2) float64 ``(x, y)`` vertices of
    the convex hull of its rows' end pixels (every pixel's hull), counter-clockwise in ``(x, y)`` and starting at the
    least ``(y, x)`` (the first row's first pixel), without vertices in the middle of an edge: the vertices that the
    twin's Qhull gives, rolled to that start. Andrew's monotone chain on the row ends, which come sorted by ``(y, x)``;
    its cross products in whole numbers. A (0, 2) array where the hull is degenerate (fewer than three vertices:
    the twin's None)."""
    h = mask.shape[0]
    pts = np.empty((2 * h, 2), np.int64)  # (y, x) of the row ends, sorted
    n = 0
    for r in range(h):
        first, last = _row_ends(mask, r)
        if first < 0:
            continue
        pts[n, 0], pts[n, 1] = r, first
        n += 1
        if last != first:
            pts[n, 0], pts[n, 1] = r, last
            n += 1
    if n < 3:
        return np.empty((0, 2))
    chain = np.empty((2 * n + 1, 2), np.int64)
    k = 0
    for i in range(n):  # one side, then the other (counter-clockwise in (y, x): clockwise in (x, y))
        while k >= 2 and ((chain[k - 1, 0] - chain[k - 2, 0]) * (pts[i, 1] - chain[k - 2, 1])
                          - (chain[k - 1, 1] - chain[k - 2, 1]) * (pts[i, 0] - chain[k - 2, 0])) <= 0:  # fmt: skip
            k -= 1
        chain[k, 0], chain[k, 1] = pts[i, 0], pts[i, 1]
        k += 1
    lower = k + 1
    for i in range(n - 2, -1, -1):
        while k >= lower and ((chain[k - 1, 0] - chain[k - 2, 0]) * (pts[i, 1] - chain[k - 2, 1])
                              - (chain[k - 1, 1] - chain[k - 2, 1]) * (pts[i, 0] - chain[k - 2, 0])) <= 0:  # fmt: skip
            k -= 1
        chain[k, 0], chain[k, 1] = pts[i, 0], pts[i, 1]
        k += 1
    m = k - 1  # the chain ends where it began
    if m < 3:
        return np.empty((0, 2))
    out = np.empty((m, 2))
    out[0, 0], out[0, 1] = float(chain[0, 1]), float(chain[0, 0])
    for j in range(1, m):  # reversed, from the same start: counter-clockwise in (x, y)
        out[j, 0], out[j, 1] = float(chain[m - j, 1]), float(chain[m - j, 0])
    return out


@_njit
def green_pixels(c: np.ndarray, leaf_hue: int) -> np.ndarray:
    """:func:`symfruit.segment.colour._green` of ``c`` (h, w, 3) uint8 (a window of an image, any strides): (h, w) bool,
    green the largest channel and a third above the smallest; with ``leaf_hue`` >= 0 also of a hue of at least that
    many degrees (:func:`symfruit.segment.colour._leaf`: ``60 (G - R) >= (leaf_hue - 60) (G - min(R, B))``). The
    twin's tests on the same whole numbers: the same pixels."""
    h, w = c.shape[0], c.shape[1]
    out = np.zeros((h, w), np.bool_)
    for r in range(h):
        for q in range(w):
            red, green, blue = np.int64(c[r, q, 0]), np.int64(c[r, q, 1]), np.int64(c[r, q, 2])
            if green <= red or green < blue:
                continue
            over = green - min(red, blue)
            if 3 * over >= green and (leaf_hue < 0 or 60 * (green - red) >= (leaf_hue - 60) * over):
                out[r, q] = True
    return out


@_njit
def flood(allowed: np.ndarray, seeds: np.ndarray) -> np.ndarray:
    """(h, w) bool: the pixels of ``allowed`` (h, w) bool 4-connected (through ``allowed``) to a pixel of ``seeds``
    (h, w) bool that is itself allowed: the union of the components of ``ndimage.label(allowed)`` that hold a seed
    (the segmenter's twins label the window and read the seeds' labels). A depth-first walk over those components
    alone, each pixel pushed once."""
    h, w = allowed.shape
    out = np.zeros((h, w), np.bool_)
    stack = np.empty(h * w, np.int64)
    top = 0
    for r in range(h):
        for c in range(w):
            if seeds[r, c] and allowed[r, c] and not out[r, c]:
                out[r, c] = True
                stack[top] = r * w + c
                top += 1
    while top > 0:
        top -= 1
        r, c = divmod(stack[top], w)
        if r > 0 and allowed[r - 1, c] and not out[r - 1, c]:
            out[r - 1, c] = True
            stack[top] = (r - 1) * w + c
            top += 1
        if r + 1 < h and allowed[r + 1, c] and not out[r + 1, c]:
            out[r + 1, c] = True
            stack[top] = (r + 1) * w + c
            top += 1
        if c > 0 and allowed[r, c - 1] and not out[r, c - 1]:
            out[r, c - 1] = True
            stack[top] = r * w + c - 1
            top += 1
        if c + 1 < w and allowed[r, c + 1] and not out[r, c + 1]:
            out[r, c + 1] = True
            stack[top] = r * w + c + 1
            top += 1
    return out


@_njit
def _pairwise_block(a: np.ndarray, lo: int, n: int) -> float:
    """numpy's ``pairwise_sum`` of one block ``a[lo:lo + n]`` (n <= 128): below 8 values one by one from 0, else
    in eight lanes, the lanes summed pairwise, then the rest one by one."""
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[lo + i]
        return res
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    i = 8
    while i < n - (n % 8):
        r0 += a[lo + i]
        r1 += a[lo + i + 1]
        r2 += a[lo + i + 2]
        r3 += a[lo + i + 3]
        r4 += a[lo + i + 4]
        r5 += a[lo + i + 5]
        r6 += a[lo + i + 6]
        r7 += a[lo + i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@_njit
def _pairwise_sum(a: np.ndarray, lo: int, n: int) -> float:
    """numpy's sum of ``a[lo:lo + n]`` (float64, any stride) in its order: blocks of at most 128
    (:func:`_pairwise_block`), a longer run split at half its length rounded down to a multiple of 8 and the two
    halves' sums added (numpy's recursive ``pairwise_sum``, walked here with a stack: numba's cache does not keep a
    recursive function); ``np.sum`` of a 1-d float64 array starts from 0 and adds this. The same value bit for bit."""
    if n <= 128:
        return _pairwise_block(a, lo, n)
    los = np.empty(64, np.int64)
    ns = np.empty(64, np.int64)
    state = np.zeros(64, np.int64)
    vals = np.empty(64)
    top, nv = 0, 0
    los[0], ns[0], state[0] = lo, n, 0
    top = 1
    while top > 0:
        k = top - 1
        m = ns[k]
        if m <= 128:
            vals[nv] = _pairwise_block(a, los[k], m)
            nv += 1
            top -= 1
            continue
        half = m // 2
        half -= half % 8
        if state[k] == 0:  # the left half first
            state[k] = 1
            los[top], ns[top], state[top] = los[k], half, 0
            top += 1
        elif state[k] == 1:  # then the right
            state[k] = 2
            los[top], ns[top], state[top] = los[k] + half, m - half, 0
            top += 1
        else:  # both summed: left + right
            vals[nv - 2] = vals[nv - 2] + vals[nv - 1]
            nv -= 1
            top -= 1
    return vals[0]


@_njit
def _variance(a: np.ndarray) -> float:
    """``np.var(a)`` of a 1-d float64 array (n >= 1): the mean by numpy's sum over n, the squared deviations summed
    as numpy sums them, over n. The same value bit for bit."""
    n = a.shape[0]
    mean = (0.0 + _pairwise_sum(a, 0, n)) / n
    dev = np.empty(n)
    for i in range(n):
        d = a[i] - mean
        dev[i] = d * d
    return (0.0 + _pairwise_sum(dev, 0, n)) / n


@_njit
def sphere_points(
    mask: np.ndarray, depth: np.ndarray, r0: int, c0: int, cx: float, cy: float, focal: float, most: int
) -> tuple[np.ndarray, float]:  # fmt: skip
    """:func:`symfruit.segment.colour._sphere` up to its first fit: the points of :func:`window_points` and their
    spread (``sqrt(2 (var x + var y))``, numpy's variances), the points within twice the spread of their median depth
    kept; none (and spread 0) with fewer than 20 points. The same points and spread, bit for bit."""
    p = window_points(mask, depth, r0, c0, cx, cy, focal, most)
    n = p.shape[0]
    if n < 20:
        return np.empty((0, 3)), 0.0
    spread = math.sqrt(_variance(p[:, 0]) + _variance(p[:, 1])) * math.sqrt(2.0)
    zm = median_of_quick(p[:, 2])  # _median_of's value (stop 49)
    keep = 0
    for i in range(n):
        keep += abs(p[i, 2] - zm) <= 2.0 * spread
    out = np.empty((keep, 3))
    k = 0
    for i in range(n):
        if abs(p[i, 2] - zm) <= 2.0 * spread:
            out[k, 0], out[k, 1], out[k, 2] = p[i, 0], p[i, 1], p[i, 2]
            k += 1
    return out, spread


@_njit
def peaks(edt: np.ndarray, radius: int, least: float) -> np.ndarray:
    """:func:`symfruit.segment.colour._centres`' peaks of a distance map ``edt`` (h, w) float64: (h, w) bool, the
    pixels at least ``least`` deep and as deep as every pixel of the ``2 radius + 1`` square about them, the square
    cut at the image's edges (``ndimage.maximum_filter``'s "reflect" mode only repeats pixels inside it). Each pixel
    deep enough is compared with its square's pixels, nearest rows first, until one is deeper (most are not peaks and
    have a deeper neighbour; issue 19, twentieth round: the square's maxima, rows then columns, for every pixel before):
    the same comparisons of the same values, the same pixels."""
    h, w = edt.shape
    out = np.zeros((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            v = edt[r, c]
            if v < least:
                continue
            c0, c1 = max(c - radius, 0), min(c + radius, w - 1)
            peak = True
            for d in range(2 * radius + 1):
                q = r + (d + 1) // 2 if d % 2 else r - d // 2  # rows r, r + 1, r - 1, r + 2, ...
                if q < 0 or q >= h:
                    continue
                for j in range(c0, c1 + 1):
                    if edt[q, j] > v:
                        peak = False
                        break
                if not peak:
                    break
            out[r, c] = peak
    return out


@_njit
def _union(parent: np.ndarray, a: int, b: int) -> int:
    """Join the trees of ``a`` and ``b`` under the smaller root; that root."""
    a, b = _root(parent, a), _root(parent, b)
    if a == b:
        return a
    if b < a:
        a, b = b, a
    parent[b] = a
    return a


@_njit
def label(mask: np.ndarray, eight: bool) -> tuple[np.ndarray, int]:
    """``ndimage.label(mask)`` of a 2-d bool ``mask`` (``eight``: ``structure=np.ones((3, 3))``, else the
    4-neighbourhood): (h, w) int32 labels 1..n numbered by their first pixel in raster order, as scipy numbers them,
    and n: the set pixels' flat indices gathered in one raster pass and labelled by :func:`_label_pixels` (the
    labelling :func:`red_regions_once` shares, stop 42)."""
    h, w = mask.shape
    at = np.empty(h * w, np.int64)
    k = 0
    for r in range(h):
        for c in range(w):
            at[k] = r * w + c  # kept when set: no branch
            k += 1 if mask[r, c] else 0
    out = np.zeros((h, w), np.int32)
    return out, _label_pixels(out, at[:k], eight)


@_njit
def _reflected(i: int, n: int) -> int:
    """The index that ``i`` reads in a line of ``n`` values extended by scipy's "reflect" mode (d c b a | a b c d |
    d c b a: the edge value repeated). Inside the line, ``i`` itself without a division (called for every pixel of the
    segmenter's crease test and smoothing: four divisions a pixel were a third of the depth edges' time; stop 42)."""
    if 0 <= i < n:
        return i
    if n == 1:
        return 0
    i %= 2 * n
    return i if i < n else 2 * n - 1 - i


@_njit
def _correlate_line(line: np.ndarray, weights: np.ndarray, symmetric: bool, out: np.ndarray) -> None:
    """``ndimage.correlate1d`` of one line (mode "reflect", origin 0) into ``out``, in scipy's order: the line
    extended by reflection into a buffer, then for symmetric weights (of odd length) the middle product, then each
    pair of values the same distance either side added and times their weight, outermost first; else the last
    product, then each product from the first on."""
    n = line.shape[0]
    size = weights.shape[0]
    half = size // 2
    last = size - half - 1
    ext = np.empty(n + half + last)
    for i in range(-half, n + last):
        ext[i + half] = line[_reflected(i, n)]
    # each product and sum in that order for every value at once (the order of one value's sum is kept: the same
    # values), along views of the buffer (indices from 0 up: no check for negative ones), which numba vectorises; a
    # value at a time it was one chain of dependent additions (stop 43: the rows' pass 0.65 to 0.45 ms a tree frame)
    if symmetric:
        mid = weights[half]
        e0 = ext[half : half + n]
        for k in range(n):
            out[k] = e0[k] * mid
        for j in range(half, 0, -1):  # outermost first
            wt = weights[half - j]
            e1, e2 = ext[half - j : half - j + n], ext[half + j : half + j + n]
            for k in range(n):
                out[k] += (e1[k] + e2[k]) * wt
    else:
        wt = weights[half + last]
        e0 = ext[half + last : half + last + n]
        for k in range(n):
            out[k] = e0[k] * wt
        for j in range(size - 1):
            wt = weights[j]
            e1 = ext[j : j + n]
            for k in range(n):
                out[k] += e1[k] * wt


@_njit
def creases(filled: np.ndarray, weights: np.ndarray, symmetric: bool, region: np.ndarray, limit: float) -> np.ndarray:
    """:func:`symfruit.segment.colour._creases` from the gap-filled depth ``filled`` (h, w) float64: the pixels of
    ``region`` where the Laplacian (``ndimage.laplace``'s second differences, rows' plus columns') of the depth
    smoothed by ``weights`` (:func:`~symfruit.segment.colour._gaussian`'s, along the rows then the columns;
    ``symmetric`` as scipy finds them) lies below ``limit``. scipy's correlations in scipy's order (mode "reflect"):
    the same values and pixels, the Laplacian worked out on the region's pixels alone."""
    return _creased(_smoothed(filled, weights, symmetric), region, limit)


@_njit
def _smoothed(filled: np.ndarray, weights: np.ndarray, symmetric: bool) -> np.ndarray:
    """(h, w): ``filled`` correlated with ``weights`` along the columns (:func:`_correlate_columns`) then along the
    rows (:func:`_correlate_line`), scipy's order and mode "reflect" (:func:`creases`, :func:`depth_edges`)."""
    h, w = filled.shape
    across = np.empty((h, w))
    _correlate_columns(filled, weights, symmetric, across)
    smooth = np.empty((h, w))
    for r in range(h):  # along axis 1
        _correlate_line(across[r], weights, symmetric, smooth[r])
    return smooth


@_njit
def _creased(smooth: np.ndarray, region: np.ndarray, limit: float) -> np.ndarray:
    """(h, w) bool: the pixels of ``region`` where ``ndimage.laplace``'s second differences of ``smooth`` (rows'
    plus columns', mode "reflect", in its order) lie below ``limit`` (:func:`creases`, :func:`depth_edges`)."""
    h, w = smooth.shape
    out = np.zeros((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            if not region[r, c]:
                continue
            down = smooth[r, c] * -2.0
            down += (smooth[_reflected(r - 1, h), c] + smooth[_reflected(r + 1, h), c]) * 1.0
            side = smooth[r, c] * -2.0
            side += (smooth[r, _reflected(c - 1, w)] + smooth[r, _reflected(c + 1, w)]) * 1.0
            out[r, c] = down + side < limit
    return out


@_njit
def round_skin(
    z: np.ndarray,
    color: np.ndarray,
    owner: np.ndarray,
    k: int,
    part: np.ndarray,
    r0: int,
    c0: int,
    rc: float,
    cc: float,
    reach2: float,
    deep_limit: float,
    zm: float,
    step: float,
    jump: float,
    leaf_hue: int,
) -> np.ndarray:
    """:func:`symfruit.segment.colour._round_skin`'s grown skin in its window at ``(r0, c0)`` (``z`` depth, ``color``
    uint8, ``owner`` ids, ``part`` the red part, all (h, w)): the pixels 4-connected to the part's pixels within
    ``jump`` of ``zm`` through pixels that are the part's or candidates (within ``reach2`` squared pixels of
    ``(rc, cc)``, with depth within ``deep_limit`` of ``zm``, not leaf green, of no fruit but ``k``), none of them on
    a step larger than ``step`` to a 4-neighbour; and the part. The twin's tests pixel by pixel (its squared
    distances, differences and whole-number colour tests): the same pixels."""
    h, w = z.shape
    allowed = np.zeros((h, w), np.bool_)
    seeds = np.zeros((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            zc = z[r, c]
            if r > 0 and abs(z[r - 1, c] - zc) > step:
                continue
            if r + 1 < h and abs(z[r + 1, c] - zc) > step:
                continue
            if c > 0 and abs(z[r, c - 1] - zc) > step:
                continue
            if c + 1 < w and abs(z[r, c + 1] - zc) > step:
                continue
            if part[r, c]:
                allowed[r, c] = True
                seeds[r, c] = abs(zc - zm) <= jump
                continue
            if not (zc > 0 and abs(zc - zm) <= deep_limit and (owner[r, c] == 0 or owner[r, c] == k)):
                continue
            dy, dx = float(r + r0) - rc, float(c + c0) - cc
            if dy * dy + dx * dx > reach2:
                continue
            red, green, blue = np.int64(color[r, c, 0]), np.int64(color[r, c, 1]), np.int64(color[r, c, 2])
            if green > red and green >= blue:
                over = green - min(red, blue)
                if 3 * over >= green and 60 * (green - red) >= (leaf_hue - 60) * over:
                    continue  # leaf green
            allowed[r, c] = True
    skin = flood(allowed, seeds)
    for r in range(h):
        for c in range(w):
            if part[r, c]:
                skin[r, c] = True
    return skin


# --- issue 19, eighteenth round: the colour segmenter's ground-colour candidates ----------------------------------


@_njit
def ground_steps(ground: np.ndarray, depth: np.ndarray, size: int, jump: float) -> np.ndarray:
    """``ground & ~_steps(_gap_filled(depth, size), jump)`` of :mod:`symfruit.segment.colour`: (h, w) bool, the
    pixels of ``ground`` (h, w) bool not on a depth step. ``depth`` (h, w) float64, 0 where none (never NaN nor
    negative): a pixel without depth takes the largest depth of the ``size`` box about it (clipped at the border),
    none where that is 0 too (the twin's NaN: no step); a step is a 4-neighbour's depth more than ``jump`` away, both
    with depth. Maxima and differences of the same numbers: the twin's pixels. Row by row, the box's column maxima
    then its row maxima, each inner loop along a row (numba vectorises those, not a loop over the box)."""
    h, w = depth.shape
    half = size // 2
    filled = np.empty((h, w))
    col = np.empty(w)
    for r in range(h):
        for q in range(w):
            col[q] = depth[r, q]
        for k in range(max(r - half, 0), min(r + half + 1, h)):
            for q in range(w):
                u = depth[k, q]
                col[q] = u if u > col[q] else col[q]
        for q in range(w):
            filled[r, q] = col[q]
        for d in range(1, min(half, w - 1) + 1):
            for q in range(w - d):
                u = col[q + d]
                filled[r, q] = u if u > filled[r, q] else filled[r, q]
            for q in range(d, w):
                u = col[q - d]
                filled[r, q] = u if u > filled[r, q] else filled[r, q]
        for q in range(w):
            v = depth[r, q]
            filled[r, q] = v if v > 0.0 else filled[r, q]
    edge = np.zeros((h, w), np.bool_)
    for r in range(h):
        if r + 1 < h:
            for q in range(w):
                a, b = filled[r, q], filled[r + 1, q]
                step = (a > 0.0) & (b > 0.0) & (abs(b - a) > jump)
                edge[r, q] |= step
                edge[r + 1, q] |= step
        for q in range(w - 1):
            a, b = filled[r, q], filled[r, q + 1]
            step = (a > 0.0) & (b > 0.0) & (abs(b - a) > jump)
            edge[r, q] |= step
            edge[r, q + 1] |= step
    out = np.empty((h, w), np.bool_)
    for r in range(h):
        for q in range(w):
            out[r, q] = ground[r, q] and not edge[r, q]
    return out


# --- issue 19, eighteenth round (stop 38): the segmenter's split and maps ---------------------------------------


@_njit
def sphere_solve(p: np.ndarray, sol: np.ndarray) -> bool:
    """The algebraic sphere's least squares of :func:`symfruit.segment.colour._sphere`: ``sol`` (4,) minimising
    ``|[2 p, 1] sol - |p|^2|`` for points ``p`` (n, 3; n >= 4), by Householder reflections of the (n, 4) system and
    back substitution (LAPACK's ``gelsd`` there, an SVD: the same solution to rounding, not to the bit). False,
    ``sol`` untouched, when a column is (nearly) dependent on those before it: the reflected diagonal under 1e-9 of
    the largest (``lstsq`` then gives the least-norm solution, which the twin is left to find)."""
    n = p.shape[0]
    a = np.empty((4, n))  # the system's columns as rows: each reflection runs along contiguous memory
    b = np.empty(n)
    for i in range(n):
        x, y, z = p[i, 0], p[i, 1], p[i, 2]
        a[0, i], a[1, i], a[2, i], a[3, i] = 2.0 * x, 2.0 * y, 2.0 * z, 1.0
        b[i] = x * x + y * y + z * z
    diag = np.empty(4)
    for k in range(4):
        s = 0.0
        for i in range(k, n):
            s += a[k, i] * a[k, i]
        norm = math.sqrt(s)
        if norm == 0.0:
            return False
        alpha = -norm if a[k, k] >= 0.0 else norm
        v0 = a[k, k] - alpha
        vv = s - a[k, k] * a[k, k] + v0 * v0  # |v|^2, v = column k from row k on, less alpha at its first place
        a[k, k] = v0
        diag[k] = alpha
        for j in range(k + 1, 4):
            d = 0.0
            for i in range(k, n):
                d += a[k, i] * a[j, i]
            f = 2.0 * d / vv
            for i in range(k, n):
                a[j, i] -= f * a[k, i]
        d = 0.0
        for i in range(k, n):
            d += a[k, i] * b[i]
        f = 2.0 * d / vv
        for i in range(k, n):
            b[i] -= f * a[k, i]
    largest = 0.0
    for k in range(4):
        largest = max(largest, abs(diag[k]))
    for k in range(4):
        if not abs(diag[k]) > 1e-9 * largest:
            return False
    x = np.empty(4)
    for k in range(3, -1, -1):
        s = b[k]
        for j in range(k + 1, 4):
            s -= a[j, k] * x[j]
        x[k] = s / diag[k]
    for k in range(4):
        sol[k] = x[k]
    return True


@_njit
def sphere_fit(
    mask: np.ndarray, depth: np.ndarray, r0: int, c0: int, cx: float, cy: float, focal: float, most: int,
    fit: np.ndarray,
) -> int:  # fmt: skip
    """:func:`symfruit.segment.colour._sphere` in one call: the points and spread of :func:`sphere_points`, the
    algebraic fit (:func:`sphere_solve`), the points off it dropped (:func:`sphere_inliers`), the fit again, and
    the twin's test of a fruit-like cap (the radius within 0.25-4 times the spread). 1 with the centre and radius
    in ``fit`` (4,), 0 for the twin's None, -1 where :func:`sphere_solve` leaves the system to the twin's
    ``lstsq``. A non-finite fit is None, as the twin's NaN threshold keeps no point."""
    p, spread = sphere_points(mask, depth, r0, c0, cx, cy, focal, most)
    sol = np.zeros(4)
    centre = np.zeros(3)
    radius = 0.0
    for it in range(2):
        if p.shape[0] < 20:
            return 0
        if not sphere_solve(p, sol):
            return -1
        centre[0], centre[1], centre[2] = sol[0], sol[1], sol[2]
        q = sol[3] + (centre[0] * centre[0] + centre[1] * centre[1] + centre[2] * centre[2])
        radius = math.sqrt(q) if q > 0.0 else (0.0 if q <= 0.0 else q)  # max(q, 0) keeps a NaN, as Python's does
        if not (np.isfinite(centre[0]) and np.isfinite(centre[1]) and np.isfinite(centre[2])
                and np.isfinite(radius)):  # fmt: skip
            return 0
        if it == 0:
            p = sphere_inliers(p, centre, radius)
    if not (0.25 * spread <= radius <= 4.0 * spread):
        return 0
    fit[0], fit[1], fit[2], fit[3] = centre[0], centre[1], centre[2], radius
    return 1


@_njit
def _on_path(edt: np.ndarray, p: int, q: int, centres: np.ndarray, m: int, t: float) -> bool:
    """:func:`symfruit.segment.colour._on_path`: whether the straight path from ``(p, q)`` to one of the first ``m``
    ``centres`` (rows ``row, col, ...``) stays deeper than ``t``, its pixels ``np.rint`` of the twin's
    ``np.linspace`` (``i * step + start``, the last the end itself: the same pixels)."""
    for k in range(m):
        a, b = int(centres[k, 0]), int(centres[k, 1])
        n = max(abs(a - p), abs(b - q)) + 1
        dr, dc = float(a) - float(p), float(b) - float(q)
        sr, sc = dr / n, dc / n
        lowest = np.inf
        for i in range(n + 1):
            if i == n:
                r, c = a, b
            else:
                yr = (i / n) * dr if sr == 0.0 else i * sr
                yc = (i / n) * dc if sc == 0.0 else i * sc
                r, c = int(np.rint(yr + p)), int(np.rint(yc + q))
            v = edt[r, c]
            lowest = v if v < lowest else lowest
        if lowest > t:
            return True
    return False


@_njit
def _separate(edt: np.ndarray, p: int, q: int, centres: np.ndarray, m: int, t: float, budget: np.ndarray) -> bool:
    """:func:`symfruit.segment.colour._separate`: whether ``(p, q)`` lies in another 4-connected component of
    ``edt > t`` than each of the first ``m`` ``centres``; a path that stays above ``t`` joins them, and with no
    labelling left in ``budget[0]`` it is taken as joined. The component walked by :func:`flood`."""
    if _on_path(edt, p, q, centres, m, t):
        return False
    if budget[0] <= 0:
        return False
    budget[0] -= 1
    above = edt > t
    if not above[p, q]:
        for k in range(m):
            if not above[int(centres[k, 0]), int(centres[k, 1])]:
                return False
        return True
    seed = np.zeros(edt.shape, np.bool_)
    seed[p, q] = True
    reached = flood(above, seed)
    for k in range(m):
        if reached[int(centres[k, 0]), int(centres[k, 1])]:
            return False
    return True


@_njit
def centre_search(edt: np.ndarray, radius: int, least: float, loose: float, waist: float, budget: int) -> np.ndarray:
    """:func:`symfruit.segment.colour._centres` after its distance map ``edt``: its :func:`peaks` (``radius``,
    ``least``), in raster order then by depth, deepest first (a stable sort, as the twin's), and the walk over the
    first 400 of them: a peak inside a kept centre's inscribed disc is skipped, one not separated from the kept
    centres at ``loose`` times its depth (:func:`_separate`, ``budget`` labellings in all) too; a kept one is firm
    when separated at ``waist`` times its depth as well; at most 8 kept. (k, 4) rows ``row, col, radius, firm``
    (whole numbers and the map's values: the twin's centres)."""
    h, w = edt.shape
    found = peaks(edt, radius, least)
    n = 0
    for r in range(h):
        for c in range(w):
            n += found[r, c]
    at = np.empty(n, np.int64)
    neg = np.empty(n)
    k = 0
    for r in range(h):
        for c in range(w):
            if found[r, c]:
                at[k] = r * w + c
                neg[k] = -edt[r, c]
                k += 1
    order = np.argsort(neg, kind="mergesort")
    centres = np.empty((8, 4))
    m = 0
    left = np.full(1, budget, np.int64)
    for i in order[:400]:
        p, q = at[i] // w, at[i] % w
        depth = edt[p, q]
        inside = False
        for j in range(m):
            a, b, ra = centres[j, 0], centres[j, 1], centres[j, 2]
            if (p - a) ** 2 + (q - b) ** 2 <= ra * ra:
                inside = True
                break
        if inside:
            continue
        firm = True
        if m > 0:
            if not _separate(edt, p, q, centres, m, loose * depth, left):
                continue
            if waist < loose:
                firm = _separate(edt, p, q, centres, m, waist * depth, left)
        centres[m, 0], centres[m, 1], centres[m, 2], centres[m, 3] = p, q, depth, 1.0 if firm else 0.0
        m += 1
        if m >= 8 or left[0] <= 0:
            break
    return centres[:m].copy()


@_njit
def _correlate_columns(image: np.ndarray, weights: np.ndarray, symmetric: bool, out: np.ndarray) -> None:
    """``ndimage.correlate1d(image, weights, 0)`` (mode "reflect") of an (h, w) float64 image into ``out``: each
    value's products and sums in :func:`_correlate_line`'s order (scipy's), worked a whole row at a time (rows
    ``r + j`` reflected at the edges) instead of one gathered column at a time: the same values."""
    h, w = image.shape
    half = weights.shape[0] // 2
    last = weights.shape[0] - half - 1
    for r in range(h):
        if symmetric:
            mid = weights[half]
            for c in range(w):
                out[r, c] = image[r, c] * mid
            for j in range(-half, 0):
                a, b, wt = _reflected(r + j, h), _reflected(r - j, h), weights[half + j]
                for c in range(w):
                    out[r, c] += (image[a, c] + image[b, c]) * wt
        else:
            a, wt = _reflected(r + last, h), weights[half + last]
            for c in range(w):
                out[r, c] = image[a, c] * wt
            for j in range(-half, last):
                a, wt = _reflected(r + j, h), weights[half + j]
                for c in range(w):
                    out[r, c] += image[a, c] * wt


@_njit
def depth_edges(
    filled: np.ndarray, weights: np.ndarray, symmetric: bool, limit: float, region: np.ndarray, depth: np.ndarray,
    seen: np.ndarray, jump: float,
) -> np.ndarray:  # fmt: skip
    """:func:`symfruit.segment.colour._depth_edges` from the gap-filled depth ``filled``: the pixels of ``region`` on
    a crease (:func:`creases`' test, its smoothing's first pass by :func:`_correlate_columns`) or on a depth step
    (``depth`` of two 4-neighbours both ``seen`` more than ``jump`` apart: the twin's NaN elsewhere never steps).
    The same values and pixels."""
    h, w = filled.shape
    out = _creased(_smoothed(filled, weights, symmetric), region, limit)
    for r in range(h):
        for c in range(w):
            if not region[r, c] or out[r, c]:
                continue
            z = depth[r, c]
            if not seen[r, c]:
                continue
            if (r > 0 and seen[r - 1, c] and abs(z - depth[r - 1, c]) > jump) or (
                r + 1 < h and seen[r + 1, c] and abs(depth[r + 1, c] - z) > jump) or (
                c > 0 and seen[r, c - 1] and abs(z - depth[r, c - 1]) > jump) or (
                c + 1 < w and seen[r, c + 1] and abs(depth[r, c + 1] - z) > jump):  # fmt: skip
                out[r, c] = True
    return out


@_njit
def cells(region: np.ndarray, centres: np.ndarray, loose: float) -> np.ndarray:
    """:func:`symfruit.segment.colour._cells` before its masks: (h, w) int32, each pixel of ``region`` (h, w) bool
    numbered by its cell (1..k), 0 outside. ``centres`` (k, 3) rows ``row, col, radius``. The region's distance map
    (:func:`distance` of it padded by a pixel, by :func:`inner_distance` since stop 48), its 4-connected pieces
    deeper than ``loose`` times the least radius (:func:`label`), each deep pixel to the centre of least power
    ``(r - row)^2 + (c - col)^2 - radius^2`` (the first of equals, as ``np.argmin``) when in that centre's piece, the
    centres' own pixels to them, every region pixel to its nearest core pixel (:func:`nearest`, scipy's choice). The
    twin's sums in its order: the same cells."""
    h, w = region.shape
    k = centres.shape[0]
    dist = np.empty((h, w))
    inner_distance(region, dist)  # the padded map's inside (stop 48)
    least = centres[0, 2]
    for j in range(1, k):
        least = min(least, centres[j, 2])
    t = loose * least
    above = np.empty((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            above[r, c] = dist[r, c] > t
    deep, _ = label(above, False)
    at = np.empty(k, np.int32)
    for j in range(k):
        at[j] = deep[int(centres[j, 0]), int(centres[j, 1])]
    cores = np.zeros((h, w), np.int32)
    for r in range(h):
        for c in range(w):
            if deep[r, c] == 0:
                continue
            best, least_power = 0, np.inf
            for j in range(k):
                dr, dc, rad = r - centres[j, 0], c - centres[j, 1], centres[j, 2]
                power = dr * dr + dc * dc - rad * rad
                if power < least_power:
                    best, least_power = j, power
            if deep[r, c] == at[best]:
                cores[r, c] = best + 1
    for j in range(k):
        cores[int(centres[j, 0]), int(centres[j, 1])] = j + 1
    free = np.empty((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            free[r, c] = cores[r, c] == 0
    near = np.empty((h, w), np.int64)
    nearest(free, near)
    out = np.zeros((h, w), np.int32)
    flat = cores.ravel()  # read by the flat index itself: no division a pixel (stop 48)
    for r in range(h):
        for c in range(w):
            if region[r, c]:
                out[r, c] = flat[near[r, c]]
    return out


@_njit
def _redness_at(color: np.ndarray, r: int, c: int) -> np.float32:
    """The float32 redness ``(R - max(G, B)) / max(R, 1)`` of pixel ``(r, c)`` of ``color`` (h, w, >= 3) uint8, as
    :func:`symfruit.segment.colour.redness` has it (:func:`red_median` and :func:`red_ripe`)."""
    x = np.float32(color[r, c, 0])
    gb = np.float32(max(color[r, c, 1], color[r, c, 2]))
    one = np.float32(1.0)
    return (x - gb) / (x if x > one else one)


@_njit
def red_median(color: np.ndarray, red: np.ndarray) -> float:
    """``median(redness(color[red]))`` of :func:`symfruit.segment.colour._segment_at`'s ripe test: the float32
    redness ``(R - max(G, B)) / max(R, 1)`` of the pixels of ``red`` (h, w) bool in ``color`` (h, w, >= 3) uint8, and
    their median as ``core.points.median`` takes it (the middle value by :func:`select`, or the float32 mean of the
    middle two); NaN without a pixel. The same float32 operations: the same value."""
    h, w = red.shape
    n = 0
    for r in range(h):
        for c in range(w):
            n += red[r, c]
    if n == 0:
        return np.nan
    values = np.empty(n, np.float32)
    k = 0
    for r in range(h):
        for c in range(w):
            if red[r, c]:
                values[k] = _redness_at(color, r, c)
                k += 1
    half = n // 2
    select(values, half)  # a quickselect: several times faster than a sort on a fruit's thousands of pixels
    if n % 2:
        return float(values[half])
    below = values[0]
    for i in range(1, half):
        below = max(below, values[i])
    return float((below + values[half]) / np.float32(2.0))


@_njit
def grouped(labels: np.ndarray, keep: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`symfruit.segment.colour._grouped`: the places in ``labels`` (n,) of the labels that ``keep`` marks,
    grouped by label in ascending order, each label's in their own order (a counting sort: stable, as the twin's
    ``argsort``); the labels present, and where each one's run starts (one more: the count). The same arrays."""
    m = keep.shape[0]
    count = np.zeros(m + 1, np.int64)
    for i in range(labels.shape[0]):
        k = labels[i]
        if keep[k]:
            count[k + 1] += 1
    ids = 0
    for k in range(m):
        ids += count[k + 1] > 0
        count[k + 1] += count[k]
    at = np.empty(count[m], np.int64)
    fill = count[:m].copy()
    for i in range(labels.shape[0]):
        k = labels[i]
        if keep[k]:
            at[fill[k]] = i
            fill[k] += 1
    present = np.empty(ids, labels.dtype)
    first = np.empty(ids + 1, np.int64)
    j = 0
    for k in range(m):
        if count[k + 1] > count[k]:
            present[j] = k
            first[j] = count[k]
            j += 1
    first[ids] = count[m]
    return present, at, first


@_njit
def redness_at(color: np.ndarray, at: np.ndarray) -> np.ndarray:
    """``redness(color.reshape(-1, 3).take(at, axis=0))`` of :mod:`symfruit.segment.colour`: (n,) float32, the
    redness ``(R - max(G, B)) / max(R, 1)`` of the pixels at flat (row-major) indices ``at`` of ``color`` (h, w, >= 3)
    uint8, any strides. The same float32 operations: the same values."""
    w = color.shape[1]
    out = np.empty(at.shape[0], np.float32)
    one = np.float32(1.0)
    for i in range(at.shape[0]):
        r, c = at[i] // w, at[i] % w
        x = np.float32(color[r, c, 0])
        gb = np.float32(max(color[r, c, 1], color[r, c, 2]))
        out[i] = (x - gb) / (x if x > one else one)
    return out


@_njit
def least_areas(labels: np.ndarray, depth: np.ndarray, n: int, diameter_px_m: float, z_typical: float) -> np.ndarray:
    """:func:`symfruit.segment.colour._least_areas`: (n + 1,) the least fruit's area (pixels) at each label's mean
    depth (``z_typical`` without depth), from the labels (k,) and depths (k,) of a window's region pixels: the depths
    above 0 summed label by label in their order (``np.bincount``'s), over their count; ``pi / 4 (d / z)^2``. The
    same values."""
    count = np.zeros(n + 1)
    total = np.zeros(n + 1)
    for i in range(labels.shape[0]):
        z = depth[i]
        if z > 0:
            count[labels[i]] += 1.0
            total[labels[i]] += z
    quarter = np.pi / 4
    out = np.empty(n + 1)
    for k in range(n + 1):
        z = total[k] / max(count[k], 1.0) if count[k] > 0 else z_typical
        x = diameter_px_m / z
        out[k] = quarter * (x * x)
    return out


# --- issue 19, nineteenth round (stop 39): the colour segmenter ---


@_njit
def depth_window(given: np.ndarray) -> np.ndarray:
    """:class:`symfruit.segment.colour._Depth`'s window: (h, w) float64, each depth of ``given`` (h, w) float, any
    strides, where it is positive and below infinity (NaN is neither), else 0: the values of
    ``np.where(_usable(given), given.astype(np.float64), 0.0)`` (the comparisons in the depth's own type, the cast
    exact), in one pass instead of five."""
    h, w = given.shape
    out = np.empty((h, w), np.float64)
    for r in range(h):
        for c in range(w):
            v = given[r, c]
            out[r, c] = np.float64(v) if v > 0 and v < np.inf else 0.0
    return out


@_njit
def depth_at(given: np.ndarray, flat: np.ndarray) -> np.ndarray:
    """:meth:`symfruit.segment.colour._Depth.take`: the depths of ``given`` (n,) float at ``flat`` (k,), each as
    float64 where positive and below infinity, else 0 (the same values)."""
    out = np.empty(flat.shape[0], np.float64)
    for i in range(flat.shape[0]):
        v = given[flat[i]]
        out[i] = np.float64(v) if v > 0 and v < np.inf else 0.0
    return out


@_njit
def ground_pixels(color: np.ndarray, ground_hue: int, leaf_hue: int, dark: int) -> np.ndarray:
    """:func:`symfruit.segment.colour._ground` of ``color`` (h, w, >= 3) uint8, any strides: (h, w) bool, blue the
    least channel, the largest a third above it and above ``dark``, of a hue from ``ground_hue`` up to (not
    including) ``leaf_hue`` degrees, by the twin's whole-number tests (no value of 8-bit channels overflows its int16
    arithmetic: the same pixels), :func:`_is_ground`'s tests. Each row's channels are copied into three contiguous
    rows of whole numbers first and tested there: a loop over contiguous values, which the compiler vectorises, not
    one reading a window's or a strided grid's channels pixel by pixel (stop 54: 0.39 to 0.17 ms on a 1920x1080 tree
    frame's coarse grid, 0.52 to 0.23 ms on 600x300 windows)."""
    h, w = color.shape[0], color.shape[1]
    out = np.empty((h, w), np.bool_)
    red_row, green_row, blue_row = np.empty(w, np.int32), np.empty(w, np.int32), np.empty(w, np.int32)
    ground, leaf, least = np.int32(ground_hue), np.int32(leaf_hue - 60), np.int32(dark)
    for r in range(h):
        for c in range(w):
            red_row[c], green_row[c], blue_row[c] = color[r, c, 0], color[r, c, 1], color[r, c, 2]
        line = out[r]
        for c in range(w):
            red, green, blue = red_row[c], green_row[c], blue_row[c]
            top = max(red, green)
            gb, rb = green - blue, red - blue
            line[c] = ((blue <= min(red, green)) & (3 * (top - blue) >= top) & (top > least) & (60 * gb >= ground * rb)
                       & ((red >= green) | (60 * (green - red) < leaf * gb)))  # fmt: skip
    return out


@_njit
def _empty_or_nan(values: np.ndarray) -> bool:
    """Whether ``values`` (n,) is empty or holds a NaN: where the medians of :func:`median_values` and
    :func:`median_quick` are NaN."""
    for i in range(values.shape[0]):
        if np.isnan(values[i]):
            return True
    return values.shape[0] == 0


@_njit
def median_values(values: np.ndarray) -> float:
    """``core.points.median`` of ``values`` (n,) float64 (overwritten: reordered): NaN when a value is NaN or there is
    none, else the middle value (:func:`select`) or the mean of the middle two, halved as the twin halves it."""
    return np.nan if _empty_or_nan(values) else _median_of(values)


@_njit
def masked_depths(mask: np.ndarray, z: np.ndarray) -> tuple[int, np.ndarray]:
    """The pixels of ``mask`` (h, w) bool and the depths ``z[mask & (z > 0)]`` of ``z`` (h, w) float64, in raster
    order (the twin's boolean index): their count and the (k,) depths."""
    h, w = mask.shape
    n = 0
    k = 0
    for r in range(h):
        for c in range(w):
            if mask[r, c]:
                n += 1
                k += z[r, c] > 0
    out = np.empty(k, np.float64)
    j = 0
    for r in range(h):
        for c in range(w):
            if mask[r, c] and z[r, c] > 0:
                out[j] = z[r, c]
                j += 1
    return n, out


@_njit
def masked_median(mask: np.ndarray, z: np.ndarray) -> tuple[int, int, float]:
    """The count of ``mask`` (h, w) bool's pixels, of those with depth (``z`` (h, w) float64 above 0), and
    ``core.points.median`` of their depths (NaN without any): the twin's ``mask.sum()``, ``len(z[mask & (z > 0)])``
    and its median, the same values (the median by :func:`median_quick`, the same value: 1.04 to 0.95 ms a tree frame
    over its 69 calls; stop 54)."""
    n, values = masked_depths(mask, z)
    return n, values.shape[0], median_quick(values)


@_njit
def depth_consistent(hull: np.ndarray, part: np.ndarray, z: np.ndarray, jump: float) -> np.ndarray:
    """:func:`symfruit.segment.colour._depth_consistent`: ``part | (hull & ~off)``, ``off`` the pixels with depth
    farther than ``jump`` from the median depth of ``part``'s pixels with depth (``hull`` itself when none has): the
    twin's median and comparisons, the same pixels (a copy)."""
    _, values = masked_depths(part, z)
    if values.shape[0] == 0:
        return hull.copy()
    zm = median_values(values)
    h, w = hull.shape
    out = np.empty((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            d = z[r, c]
            out[r, c] = part[r, c] or (hull[r, c] and not (d > 0 and abs(d - zm) > jump))
    return out


@_njit
def mask_centre(mask: np.ndarray) -> tuple[int, float, float]:
    """The count of ``mask`` (h, w) bool's pixels and the mean of their rows and of their columns: ``rows.mean()``,
    ``cols.mean()`` of ``np.nonzero(mask)`` (whole numbers summed exactly in any order below 2**53, then one
    division by the count, as numpy's mean of integers; NaN without a pixel)."""
    h, w = mask.shape
    n = 0
    sr = 0
    sc = 0
    for r in range(h):
        for c in range(w):
            if mask[r, c]:
                n += 1
                sr += r
                sc += c
    if n == 0:
        return 0, np.nan, np.nan
    return n, float(sr) / float(n), float(sc) / float(n)


@_njit
def blush_rim(
    part: np.ndarray,
    z: np.ndarray,
    color: np.ndarray,
    owner: np.ndarray,
    k: int,
    pad: int,
    z_part: np.ndarray,
    jump: float,
    ground_hue: int,
    leaf_hue: int,
    dark: int,
) -> np.ndarray:
    """:func:`symfruit.segment.colour._blush_rim`'s test in its padded window (``part`` the red part (h, w) bool,
    ``z`` depth float64, ``color`` uint8, ``owner`` ids, ``z_part`` (n,) the part's depths, left as they are, whose
    median is ``zm``): the ring of ground-colour
    pixels (free: ``owner`` 0 or ``k``) and the other pixels with depth within ``pad`` of the part and not of it, at
    least 20 of each, the ring's median depth in front of ``zm`` by more than ``jump`` and the others' within
    ``jump`` of it: then the ring's pixels within ``jump`` of the ring's median depth ((h, w) bool), else a (0, 0)
    array. The twin's pixels, medians and comparisons: the same answer."""
    h, w = part.shape
    beside = np.empty((h, w), np.bool_)
    square_filter(part, pad, False, beside)
    # each pixel beside the part with depth: 1 the ring (ground colour, free), 2 another, 3 ground colour of another
    # fruit; the colour tested there alone (:func:`_is_ground`), not over the whole window (stop 43)
    kind = np.zeros((h, w), np.int8)
    n_ring = 0
    n_other = 0
    for r in range(h):
        for c in range(w):
            if beside[r, c] and not part[r, c] and z[r, c] > 0:
                if _is_ground(color[r, c, 0], color[r, c, 1], color[r, c, 2], ground_hue, leaf_hue, dark):
                    if owner[r, c] == 0 or owner[r, c] == k:
                        kind[r, c] = 1
                        n_ring += 1
                    else:
                        kind[r, c] = 3
                else:
                    kind[r, c] = 2
                    n_other += 1
    none = np.zeros((0, 0), np.bool_)
    if n_ring < 20 or n_other < 20:
        return none
    ring_z = np.empty(n_ring, np.float64)
    other_z = np.empty(n_other, np.float64)
    i = 0
    j = 0
    for r in range(h):
        for c in range(w):
            if kind[r, c] == 1:
                ring_z[i] = z[r, c]
                i += 1
            elif kind[r, c] == 2:
                other_z[j] = z[r, c]
                j += 1
    zm = median_values(z_part.copy())
    front = median_values(ring_z)
    if zm - front <= jump or abs(zm - median_values(other_z)) > jump:
        return none
    near = np.zeros((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            near[r, c] = kind[r, c] == 1 and abs(z[r, c] - front) <= jump
    return near


@_njit
def median_values32(values: np.ndarray) -> np.float32:
    """:func:`median_values` of (n,) float32 values (reordered), in float32 as the twin takes it: the middle value, or
    the float32 mean of the middle two; NaN when a value is NaN or there is none."""
    n = values.shape[0]
    if n == 0:
        return np.float32(np.nan)
    for i in range(n):
        if np.isnan(values[i]):
            return np.float32(np.nan)
    half = n // 2
    select(values, half)
    if n % 2:
        return values[half]
    below = values[0]
    for i in range(1, half):
        below = max(below, values[i])
    return (below + values[half]) / np.float32(2.0)


@_njit
def region_medians(first: np.ndarray, depth: np.ndarray, red: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`symfruit.segment.colour._one_fruit`'s medians of regions whose pixels' depths ``depth`` (k,) float64 (0:
    none) and rednesses ``red`` (k,) float32 run from ``first[i]`` to ``first[i + 1]``: each region's count of depths
    above 0, their median (NaN without), and the float32 median of its rednesses, as ``core.points.median`` takes
    them (the same values)."""
    n = first.shape[0] - 1
    zmed = np.empty(n, np.float64)
    nz = np.zeros(n, np.int64)
    rmed = np.empty(n, np.float32)
    for i in range(n):
        a, b = first[i], first[i + 1]
        k = 0
        for j in range(a, b):
            k += depth[j] > 0
        values = np.empty(k, np.float64)
        k = 0
        for j in range(a, b):
            if depth[j] > 0:
                values[k] = depth[j]
                k += 1
        nz[i] = k
        zmed[i] = median_quick(values)  # the same value (stop 54)
        rmed[i] = median_values32(red[a:b].copy())
    return zmed, nz, rmed


@_njit
def hidden_count(rest: np.ndarray, depth: np.ndarray, front: float, size: int) -> int:
    """:func:`symfruit.segment.colour._convex_outline`'s hidden pixels: how many pixels of ``rest`` (h, w) bool have
    a depth (``depth`` (h, w) float64 where above 0, else the least depth above 0 in the ``size`` box about the
    pixel, edges repeated as ``ndimage.minimum_filter(..., mode="nearest")`` repeats them, infinity without one)
    below ``front``. The twin filters the whole window; the box is read here at the pixels of ``rest`` without
    depth alone (a least value is exact in any order: the same count)."""
    h, w = rest.shape
    lo = size // 2
    hi = size - 1 - lo
    n = 0
    for r in range(h):
        for c in range(w):
            if not rest[r, c]:
                continue
            v = depth[r, c]
            if not v > 0:
                v = np.inf
                for i in range(r - lo, r + hi + 1):
                    ri = min(max(i, 0), h - 1)
                    for j in range(c - lo, c + hi + 1):
                        d = depth[ri, min(max(j, 0), w - 1)]
                        if d > 0 and d < v:
                            v = d
            n += v < front
    return n


# --- issue 19, twentieth round (stop 40): the colour segmenter's split, up to its centres, in two calls -----------


@_njit
def _filled_box(mask: np.ndarray) -> np.ndarray:
    """:func:`symfruit.core.raster.fill_holes` of ``mask`` (h, w) bool: a copy with its holes filled by :func:`filled`
    on the mask's box grown by a pixel (clipped), the twin's call: the same pixels."""
    h, w = mask.shape
    out = mask.copy()
    r0, r1, c0, c1 = _box(mask)
    if r1 == 0:
        return out
    r0, r1, c0, c1 = max(r0 - 1, 0), min(r1 + 1, h), max(c0 - 1, 0), min(c1 + 1, w)
    filled(mask[r0:r1, c0:c1], out[r0:r1, c0:c1])
    return out


@_njit
def split_seen(region: np.ndarray, depth: np.ndarray) -> tuple[np.ndarray, int, float]:
    """:func:`symfruit.segment.colour._split`'s start with depth: the region (h, w) bool with its holes filled
    (:func:`_filled_box`, the twin's ``fill_holes``), how many of its pixels have depth (``depth`` (h, w) float64
    above 0) and ``core.points.median`` of those depths (NaN without any; :func:`masked_median`'s values, the median
    by :func:`median_quick` since stop 49): the twin's values."""
    full = _filled_box(region)
    _, values = masked_depths(full, depth)
    return full, values.shape[0], median_quick(values)


@_njit
def split_centres(
    region: np.ndarray, depth: np.ndarray, weights: np.ndarray, symmetric: bool, limit: float, jump: float,
    radius: int, least: float, loose: float, waist: float, budget: int,
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.segment.colour._split` with depth from its filled ``region`` (h, w) bool and ``depth`` (h, w)
    float64 (0: none) to its centres: the depth edges (:func:`depth_edges` of the depth filled from the nearest pixel
    with depth of the region, scipy's choice, :func:`nearest`), the region less them with its holes filled
    (:func:`_filled_box`), its distance map (:func:`distance` of it padded by a pixel, by :func:`inner_distance` since
    stop 48) and, when that reaches
    ``least``, the :func:`centre_search` (``radius`` the whole part of ``least``). Returns the edges (h, w) bool and the
    centres (k, 4) (none when the map stays below ``least``): the twin's calls in one, the same values."""
    h, w = region.shape
    seen = np.empty((h, w), np.bool_)
    free = np.empty((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            seen[r, c] = region[r, c] and depth[r, c] > 0
            free[r, c] = not seen[r, c]
    near = np.empty((h, w), np.int64)
    nearest(free, near)
    fill = np.empty((h, w))
    flat = depth.ravel()  # read by the flat index itself: no division a pixel (stop 48)
    for r in range(h):
        for c in range(w):
            fill[r, c] = flat[near[r, c]]
    edges = depth_edges(fill, weights, symmetric, limit, region, depth, seen, jump)
    cut = np.empty((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            cut[r, c] = region[r, c] and not edges[r, c]
    carved = _filled_box(cut)
    edt = np.empty((h, w))
    inner_distance(carved, edt)  # the padded map's inside (stop 48)
    top = -np.inf
    for r in range(h):
        for c in range(w):
            top = max(top, edt[r, c])
    if top < least:
        return edges, np.empty((0, 4))
    return edges, centre_search(edt, radius, least, loose, waist, budget)


# --- stop 41, speedseg41: the colour segmenter's red regions in one pass ---------------------------------------------


@_njit
def red_regions_once(
    c: np.ndarray, low: np.ndarray, high: np.ndarray, sqrt3: float, tan_hue: float
) -> tuple[np.ndarray, np.ndarray, int, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip  # noqa: E501
    """:func:`symfruit.segment.colour._red_regions`' values (the twin's): one raster pass over
    the window making each pixel's red tests (:func:`red_pixels`' whole numbers and products) and gathering the weak
    and strong pixels, then the weak pixels labelled with eight neighbours by :func:`_label_pixels` (:func:`label`'s
    labelling: the same numbers), over the weak pixels alone, not every pixel of a window that may span most of a
    1920x1080 image (issue 19, stop 41; the labelling shared with :func:`label` since stop 42)."""
    h, w = c.shape[0], c.shape[1]
    weak_at, strong_at = red_pixels(c, low, high, sqrt3, tan_hue)
    n_weak, n_strong = weak_at.shape[0], strong_at.shape[0]
    mask = np.zeros((h, w), np.bool_)
    mask_flat = mask.reshape(-1)
    for i in range(n_weak):
        mask_flat[weak_at[i]] = True
    out = np.zeros((h, w), np.int32)
    m = _label_pixels(out, weak_at, True)
    flat = out.reshape(-1)
    lab = np.empty(n_weak, np.int32)
    rows = np.empty(n_weak, np.int64)
    cols = np.empty(n_weak, np.int64)
    sizes = np.zeros(m + 1, np.int64)
    r = 0
    for i in range(n_weak):  # the rows without a division: the pixels come in raster order (stop 55)
        p = weak_at[i]
        while p >= (r + 1) * w:
            r += 1
        rows[i], cols[i], lab[i] = r, p - r * w, flat[p]
        sizes[lab[i]] += 1
    seeded = np.zeros(m + 1, np.bool_)
    for i in range(n_strong):
        seeded[flat[strong_at[i]]] = True
    seeded[0] = False
    return mask, out, m, weak_at, strong_at, lab, seeded, sizes, rows, cols


@_njit
def claim(out: np.ndarray, hull: np.ndarray) -> tuple[np.ndarray, int, int, int, int]:
    """:func:`symfruit.segment.colour._claim`: a found fruit's ``hull`` (h, w) bool takes the pixels of ``out`` (h, w)
    ints, its window of the image's labels, that are still 0, unless those are fewer than half its pixels (the
    twin's float comparison of the counts): then they are set to -1 and returned with their box ``(row_start,
    row_stop, col_start, col_stop)``, else a (0, 0) array and zeros. The twin's pixels, in one pass over the window
    and one over the hull's, not five numpy passes and a box's two reductions (issue 19, stop 41)."""
    h, w = hull.shape
    n_hull = 0
    n_free = 0
    for r in range(h):
        for c in range(w):
            if hull[r, c]:
                n_hull += 1
                if out[r, c] == 0:
                    n_free += 1
    if n_free < 0.5 * n_hull:
        return np.zeros((0, 0), np.bool_), 0, 0, 0, 0
    free = np.zeros((h, w), np.bool_)
    r0, r1, c0, c1 = h, 0, w, 0
    for r in range(h):
        for c in range(w):
            if hull[r, c] and out[r, c] == 0:
                free[r, c] = True
                out[r, c] = -1
                r0, r1 = min(r0, r), max(r1, r + 1)
                c0, c1 = min(c0, c), max(c1, c + 1)
    if r1 == 0:
        r0 = c0 = 0
    return free, r0, r1, c0, c1


# --- stop 42, speedseg42: one labelling for label and red_regions_once; the segmenter's kernels -----------------------


@_njit
def _label_pixels(out: np.ndarray, at: np.ndarray, eight: bool) -> int:
    """Label the pixels at the flat indices ``at`` (ascending) of ``out`` (h, w) int32, C-contiguous, all 0 on entry,
    as ``ndimage.label`` of the mask they make (``eight``: ``structure=np.ones((3, 3))``, else the 4-neighbourhood):
    labels 1..m numbered by their first pixel in raster order, as scipy numbers them; returns m. One pass over the
    pixels joining each with its labelled neighbours above and to the left (union-find, :func:`_union`; with eight
    neighbours the one above joins all three of the others already, else the left and upper-left ones are joined and
    the upper-right one may join them), one numbering the roots in the order their first pixels come. The one
    labelling of :func:`label` and :func:`red_regions_once` (stop 42: one call a window, the pixels' loop inside)."""
    w = out.shape[1]
    flat = out.reshape(-1)  # a view: ``out`` is C-contiguous
    parent = np.empty(len(at) + 1, np.int64)
    n = 0
    r = 0
    for i in range(len(at)):
        p = at[i]
        while p >= (r + 1) * w:  # the row, without a division: the pixels come in raster order
            r += 1
        c = p - r * w
        up = flat[p - w] if r > 0 else 0
        if eight:
            if up:
                own = up
            else:
                left = flat[p - 1] if c > 0 else 0
                own = left if left else (flat[p - w - 1] if r > 0 and c > 0 else 0)
                right = flat[p - w + 1] if r > 0 and c + 1 < w else 0
                if right:
                    own = _union(parent, own, right) if own else right
        else:
            left = flat[p - 1] if c > 0 else 0
            if up and left:
                own = _union(parent, up, left) if up != left else up
            else:
                own = up if up else left
        if own == 0:
            n += 1
            parent[n] = n
            own = n
        flat[p] = own
    final = np.zeros(n + 1, np.int32)
    m = 0
    for i in range(len(at)):
        root = _root(parent, flat[at[i]])
        if final[root] == 0:
            m += 1
            final[root] = m
        flat[at[i]] = final[root]
    return m


# --- stop 43, speedseg43: the colour segmenter's ground-colour test on whole numbers -------------------------------


@_njit
def _is_ground(red: int, green: int, blue: int, ground_hue: int, leaf_hue: int, dark: int) -> bool:
    """:func:`ground_pixels`' test of one pixel from its channels: blue the least, the largest channel a third above
    it and above ``dark``, a hue from ``ground_hue`` up to (not including) ``leaf_hue`` degrees (the twin's whole
    numbers). Whole numbers, no arrays (a helper called per pixel with arrays takes and drops their reference
    counts on every call, stop 42's ``_red_kind``), and the tests joined by ``&``, not ``and``: no branch a pixel,
    0.73 to 0.46 ms of ``ground_pixels`` a 1920x1080 tree frame (stop 43); shared with :func:`blush_rim`, which tests
    the pixels beside a red part alone."""
    red, green, blue = np.int64(red), np.int64(green), np.int64(blue)
    top = max(red, green)
    gb, rb = green - blue, red - blue
    return bool(
        (blue <= min(red, green))
        & (3 * (top - blue) >= top)
        & (top > dark)
        & (60 * gb >= ground_hue * rb)
        & ((red >= green) | (60 * (green - red) < (leaf_hue - 60) * gb))
    )


# --- stop 44, speedcand44: the outline ellipse's design ---------------------------------------------------------------


@_njit
def conic_design(p: np.ndarray) -> tuple[np.ndarray, float, np.ndarray, np.ndarray]:
    """:func:`symfruit.core.raster._conic_design` of a C-ordered (m, 2) float64 array of outline points, ``m >= 1``:
    their mean (:func:`column_means`), their scale (the root of the mean squared distance from the mean, numpy's
    pairwise sum, as :func:`scaled_cloud` takes it; 1 where that is 0), and the direct ellipse fit's designs
    ``[x^2, x y, y^2]`` and ``[x, y, 1]`` (m, 3) of the centred and scaled points: each value the twin's numpy
    expressions' bit for bit, in one call (17 numpy calls there; issue 19, stop 44)."""
    n = p.shape[0]
    mean = column_means(p)
    sq = np.empty(n)
    for i in range(n):
        x, y = p[i, 0] - mean[0], p[i, 1] - mean[1]
        sq[i] = x * x + y * y
    scale = math.sqrt((0.0 + _pairwise_sum(sq, 0, n)) / n)
    if scale == 0.0:
        scale = 1.0
    d1 = np.empty((n, 3))
    d2 = np.empty((n, 3))
    for i in range(n):
        x, y = (p[i, 0] - mean[0]) / scale, (p[i, 1] - mean[1]) / scale
        d1[i, 0], d1[i, 1], d1[i, 2] = x * x, x * y, y * y
        d2[i, 0], d2[i, 1], d2[i, 2] = x, y, 1.0
    return mean, scale, d1, d2


@_njit
def overshoot_band(own: np.ndarray, depth: np.ndarray, rows: np.ndarray, cols: np.ndarray, z: np.ndarray,
                   tolerance: float, reach: int, own_z: np.ndarray, band: np.ndarray,
                   ahead: np.ndarray) -> tuple[int, int, int]:  # fmt: skip
    """:func:`symfruit.core.occlusion.overshoot`'s maps in one pass (twin: ``occlusion._overshoot_band``, the same
    values, bit for bit): ``own_z`` (h, w) the least of the points' depths ``z`` at their pixels (``rows``,
    ``cols``, inside the window; +inf elsewhere), ``band`` (h, w) the mask's pixels (``own``) beyond the points'
    with depth (``depth`` finite and above 0), ``ahead`` (h, w) the band's pixels clearly in front of the fruit
    (nearer by ``tolerance`` than both the nearest point pixel's depth and the least of the own depths within
    ``reach`` pixels); returns the band's pixel count, how many of its pixels are not ahead but nearer than the
    nearest point pixel's depth (the spread), and the mask's pixels beyond the points'.

    The nearest point pixel is scipy's feature transform's over the box of the mask and the points' pixels
    (:func:`nearest`); the least own depth within ``reach`` is a minimum over the square, worked out along the rows
    of the points' pixels' box alone (+inf beyond it), then down the columns at the band's pixels alone, not scipy's
    17 x 17 filter over the window (minima are exact, in any order)."""
    h, w = own.shape
    for r in range(h):
        for c in range(w):
            own_z[r, c] = np.inf
    s0, s1, t0, t1 = h, 0, w, 0  # the box of the points' pixels
    for i in range(z.shape[0]):
        r, c, v = rows[i], cols[i], z[i]
        if v < own_z[r, c] or v != v:  # np.minimum's: NaN propagates
            own_z[r, c] = v
    n_beyond = 0
    n_band = 0
    b0, b1, a0, a1 = h, 0, w, 0  # the box of the mask and the points' pixels
    for r in range(h):
        for c in range(w):
            seen = math.isfinite(own_z[r, c])
            if seen:
                s0, s1, t0, t1 = min(s0, r), max(s1, r + 1), min(t0, c), max(t1, c + 1)
            if seen or own[r, c]:
                b0, b1, a0, a1 = min(b0, r), max(b1, r + 1), min(a0, c), max(a1, c + 1)
            ahead[r, c] = False
            band[r, c] = False
            if own[r, c] and not seen:
                n_beyond += 1
                d = float(depth[r, c])
                if math.isfinite(d) and d > 0:
                    band[r, c] = True
                    n_band += 1
    if n_band == 0:
        return 0, 0, n_beyond
    bh, bw = b1 - b0, a1 - a0
    image = np.empty((bh, bw), np.bool_)
    for r in range(bh):
        for c in range(bw):
            image[r, c] = not math.isfinite(own_z[b0 + r, a0 + c])
    index = np.empty((bh, bw), np.int64)
    nearest(image, index)
    # the least own depth along each row within reach, over the rows and the reach of the points' pixels' box
    q0, q1 = max(t0 - reach, 0), min(t1 + reach, w)
    along = np.full((max(s1 - s0, 0), max(q1 - q0, 0)), np.inf)
    for r in range(s0, s1):
        for c in range(q0, q1):
            m = np.inf
            for k in range(max(c - reach, t0), min(c + reach + 1, t1)):
                if own_z[r, k] < m:
                    m = own_z[r, k]
            along[r - s0, c - q0] = m
    spread = 0
    for r in range(b0, b1):
        for c in range(a0, a1):
            if not band[r, c]:
                continue
            near = np.inf
            if q0 <= c < q1:
                for k in range(max(r - reach, s0), min(r + reach + 1, s1)):
                    if along[k - s0, c - q0] < near:
                        near = along[k - s0, c - q0]
            j = index[r - b0, c - a0]
            if j < 0:  # no point pixel with a finite depth: np.take's last
                j += bh * bw
            ref = own_z[b0 + j // bw, a0 + j % bw]
            d = float(depth[r, c])
            front = ref if ref < near else near
            if d < front - tolerance:
                ahead[r, c] = True
            elif d < ref:
                spread += 1
    return n_band, spread, n_beyond


@_njit
def peel(own: np.ndarray, drop: np.ndarray, out: np.ndarray) -> None:
    """``out`` (h, w) bool: the pixels of ``drop`` joined (8-connected, through ``drop``) to a pixel of ``drop`` on
    the mask's border (a pixel of its 3 x 3 square not in ``own`` or beyond the window): the twin's
    ``ndimage.binary_propagation`` from ``drop & ~square_filter(own, 1, every=True)`` within ``drop``
    (``occlusion._peel``), by one flood fill instead of dilations until nothing changes."""
    h, w = own.shape
    stack = np.empty(h * w, np.int64)
    n = 0
    for r in range(h):
        for c in range(w):
            out[r, c] = False
    for r in range(h):
        for c in range(w):
            if not drop[r, c]:
                continue
            border = r == 0 or c == 0 or r == h - 1 or c == w - 1
            if not border:
                for dr in range(-1, 2):
                    for dc in range(-1, 2):
                        if not own[r + dr, c + dc]:
                            border = True
            if border:
                out[r, c] = True
                stack[n] = r * w + c
                n += 1
    while n > 0:
        n -= 1
        r, c = stack[n] // w, stack[n] % w
        for rr in range(max(r - 1, 0), min(r + 2, h)):
            for cc in range(max(c - 1, 0), min(c + 2, w)):
                if drop[rr, cc] and not out[rr, cc]:
                    out[rr, cc] = True
                    stack[n] = rr * w + cc
                    n += 1


# --- stop 44, speedseg44: the colour segmenter's hull fill, Pillow's scan lines ----------------------------------


@_njit_inlined
def _round_up(x: float) -> int:
    """Pillow's ``ROUND_UP`` of a float32 ``x`` (half away from zero; its ``x + 0.5F`` a float32 sum: the sum of
    two float32 numbers worked out in float64 and rounded once to float32 is the float32 sum, double rounding being
    innocuous for a sum, product or quotient when the wider format has 2p + 2 bits or more)."""
    if x >= 0.0:
        return math.floor(np.float32(x + 0.5))
    return -math.floor(np.float32(abs(x) + 0.5))


@_njit_inlined
def _round_down(x: float) -> int:
    """Pillow's ``ROUND_DOWN`` of a float32 ``x`` (half towards zero), as :func:`_round_up`."""
    if x >= 0.0:
        return math.ceil(np.float32(x - 0.5))
    return -math.ceil(np.float32(abs(x) - 0.5))


@_njit_inlined
def _roundf(x: float) -> float:
    """C's ``roundf`` of a float32 ``x``: half away from zero (``abs(x) + 0.5`` is exact in float64)."""
    r = math.floor(abs(x) + 0.5)
    return np.float32(r if x >= 0.0 else -r)


@_njit_inlined
def _hline(out: np.ndarray, x0: int, y: int, x1: int) -> None:
    """Pillow's ``hline8``: ``out[y, x0..x1]`` set, clipped to the image (none when ``x0 > x1``)."""
    h, w = out.shape
    if y < 0 or y >= h:
        return
    if x0 < 0:
        x0 = 0
    elif x0 >= w:
        return
    if x1 < 0:
        return
    if x1 >= w:
        x1 = w - 1
    for x in range(x0, x1 + 1):
        out[y, x] = True


@_njit_inlined
def _edge_x(edges: np.ndarray, slope: np.ndarray, e: int, y: int) -> float:
    """Where edge ``e`` crosses row ``y``: Pillow's float32 ``(y - y0) dx + x0`` (the product and the sum each worked
    out in float64, exact for these whole numbers and float32 slopes, and rounded once to float32)."""
    return np.float32(np.float32(np.float64(y - edges[e, 1]) * slope[e]) + np.float64(edges[e, 0]))


@_njit
def polygon_fill(vertices: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """``mask`` (h, w) bool with the polygon of whole-number vertices ``vertices`` (m, 2) float64 ``(x, y)`` filled in,
    as Pillow draws it (``ImageDraw.polygon(..., fill=1, outline=1)`` on an "L" image: the outline's ink is the
    fill's, so Pillow draws the fill alone): :func:`symfruit.segment.colour._fill_polygon`'s pixels or ``mask``'s.
    Pillow's scan-line fill (``ImagingDrawPolygon`` and ``polygon_generic`` of its ``Draw.c``) step by step: the
    edges (a horizontal edge following another in the same direction joined to it; horizontal edges drawn at once),
    each row's float32 crossings (:func:`_edge_x`), an edge's lower end counted twice but on the last row, a crossing
    at a corner where two edges meet moved to within a pixel of the next (or, on an edge's lower end, the previous)
    row's, the crossings sorted and filled pairwise from ``ROUND_UP`` to ``ROUND_DOWN``. One call instead of
    Pillow's image, drawing and copy (stop 44). A (0, 0) array when a vertex is not a whole number (Pillow rounds
    those)."""
    h = mask.shape[0]
    m = vertices.shape[0]
    xy = np.empty((m, 2), np.int64)
    for i in range(m):
        for k in range(2):
            xy[i, k] = int(vertices[i, k])
            if xy[i, k] != vertices[i, k]:
                return np.empty((0, 0), np.bool_)
    out = mask.copy()
    if m == 0:
        return out
    edges = np.empty((m, 6), np.int64)  # per edge: x0, y0, xmin, ymin, xmax, ymax
    slope = np.zeros(m, np.float32)
    n = 0
    i = 0
    while i < m - 1:
        x0, y0, x1, y1 = xy[i, 0], xy[i, 1], xy[i + 1, 0], xy[i + 1, 1]
        if y0 == y1 and i != 0 and y0 == xy[i - 1, 1]:  # a horizontal edge after another
            if x1 > x0 and x0 > xy[i - 1, 0]:
                edges[n - 1, 4] = x1
                i += 1
                continue
            if x1 < x0 and x0 < xy[i - 1, 0]:
                edges[n - 1, 2] = x1
                i += 1
                continue
        _add_edge(edges, slope, n, x0, y0, x1, y1)
        n += 1
        i += 1
    if xy[i, 0] != xy[0, 0] or xy[i, 1] != xy[0, 1]:
        _add_edge(edges, slope, n, xy[i, 0], xy[i, 1], xy[0, 0], xy[0, 1])
        n += 1
    ymin, ymax = h - 1, 0
    table = np.empty(n, np.int64)
    count = 0
    for e in range(n):
        ymin = min(ymin, edges[e, 3])
        ymax = max(ymax, edges[e, 5])
        if edges[e, 3] == edges[e, 5]:
            _hline(out, edges[e, 2], edges[e, 3], edges[e, 4])
            continue
        table[count] = e
        count += 1
    ymin = max(ymin, 0)
    ymax = min(ymax, h)
    xx = np.empty(2 * count + 1, np.float32)
    for y in range(ymin, ymax + 1):
        j = 0
        for t in range(count):
            e = table[t]
            if y < edges[e, 3] or y > edges[e, 5]:
                continue
            xx[j] = _edge_x(edges, slope, e, y)
            j += 1
            if y == edges[e, 5] and y < ymax:
                xx[j] = xx[j - 1]
                j += 1
            elif (y == edges[e, 3] or y == edges[e, 5]) and slope[e] != 0.0:  # a corner with an earlier edge
                for u in range(t):
                    o = table[u]
                    if (y != edges[o, 3] and y != edges[o, 5]) or slope[o] == 0.0:
                        continue
                    if _roundf(xx[j - 1]) != _roundf(_edge_x(edges, slope, o, y)):
                        continue
                    near = y - 1 if y == edges[e, 5] else y + 1
                    if near < edges[o, 3] or near > edges[o, 5]:
                        continue
                    a = _edge_x(edges, slope, e, near)
                    b = _edge_x(edges, slope, o, near)
                    v = xx[j - 1]
                    if v > np.float32(a + 1.0) and v > np.float32(b + 1.0):
                        xx[j - 1] = np.float32(_roundf(max(a, b)) + 1.0)
                    elif v < np.float32(a - 1.0) and v < np.float32(b - 1.0):
                        xx[j - 1] = np.float32(_roundf(min(a, b)) - 1.0)
                    break
        for a in range(1, j):  # insertion sort: a row crosses a few edges
            v = xx[a]
            b = a - 1
            while b >= 0 and xx[b] > v:
                xx[b + 1] = xx[b]
                b -= 1
            xx[b + 1] = v
        for a in range(1, j, 2):
            _hline(out, _round_up(xx[a - 1]), y, _round_down(xx[a]))
    return out


@_njit_inlined
def _add_edge(edges: np.ndarray, slope: np.ndarray, n: int, x0: int, y0: int, x1: int, y1: int) -> None:
    """Pillow's ``add_edge``: edge ``n`` from ``(x0, y0)`` to ``(x1, y1)``, its slope ``dx / dy`` a float32 quotient
    (0 for a horizontal edge)."""
    edges[n, 0], edges[n, 1] = x0, y0
    edges[n, 2], edges[n, 4] = min(x0, x1), max(x0, x1)
    edges[n, 3], edges[n, 5] = min(y0, y1), max(y0, y1)
    slope[n] = np.float32(0.0) if y0 == y1 else np.float32(np.float64(x1 - x0) / np.float64(y1 - y0))


@_njit
def depth_window_at(given: np.ndarray, rows: tuple[int, int, int], cols: tuple[int, int, int]) -> np.ndarray:
    """:func:`depth_window` of the window ``given[r0:r1:rs, c0:c1:cs]`` of a C-contiguous depth image ``given``
    (h, w) float, ``rows`` and ``cols`` the ``(start, stop, step)`` of ``slice.indices`` (steps positive): the same
    values. Read through the whole image's rows, not a window's view of unknown strides: with a step of one, each
    row's loop runs over contiguous values, which numba vectorises (100 random windows of a 1920x1080 tree frame's
    depth, 5.95 to 4.06 ms in one process; 4.7 to 2.1 ns a pixel on windows of 150 pixels; stop 44)."""
    r0, r1, rs = rows
    c0, c1, cs = cols
    out = np.empty((max(r1 - r0 + rs - 1, 0) // rs, max(c1 - c0 + cs - 1, 0) // cs), np.float64)
    for i in range(out.shape[0]):
        row = given[r0 + i * rs]
        line = out[i]
        if cs == 1:
            for c in range(out.shape[1]):
                v = row[c0 + c]
                line[c] = np.float64(v) if (v > 0) & (v < np.inf) else 0.0
        else:
            for c in range(out.shape[1]):
                v = row[c0 + c * cs]
                line[c] = np.float64(v) if (v > 0) & (v < np.inf) else 0.0
    return out


@_njit
def bulge_sums(
    labels: np.ndarray, rows: np.ndarray, cols: np.ndarray, depth: np.ndarray, n: int, cx: float, cy: float,
    focal: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """The sums of :func:`symfruit.segment.colour._bulging`'s least squares, the twin's ``np.bincount`` calls in one
    pass each: for pieces ``0..n`` (``labels`` of pixels at ``rows``, ``cols`` with ``depth``, 0: none, those left
    out) their counts, the normal matrices (n + 1, 4, 4) of the columns ``1, x, y, x^2 + y^2`` (camera-frame metres,
    ``(col - cx) z / focal``, less the piece's mean), the right sides (n + 1, 4) against ``z`` and the sums of
    ``z^2``. Each bin's sum runs over its pixels in their order, as ``np.bincount``'s loop adds its weights, and each
    weight is the twin's product: the same values (stop 44)."""
    k = 0
    for i in range(depth.shape[0]):
        k += depth[i] > 0
    lab = np.empty(k, np.int64)
    x = np.empty(k)
    y = np.empty(k)
    z = np.empty(k)
    j = 0
    for i in range(depth.shape[0]):
        if depth[i] > 0:
            lab[j], z[j] = labels[i], depth[i]
            x[j] = (float(cols[i]) - cx) * depth[i] / focal
            y[j] = (float(rows[i]) - cy) * depth[i] / focal
            j += 1
    count = np.zeros(n + 1)
    sx = np.zeros(n + 1)
    sy = np.zeros(n + 1)
    for i in range(k):
        count[lab[i]] += 1.0
        sx[lab[i]] += x[i]
        sy[lab[i]] += y[i]
    for b in range(n + 1):
        safe = max(count[b], 1.0)
        sx[b] /= safe
        sy[b] /= safe
    m = np.zeros((n + 1, 4, 4))
    rhs = np.zeros((n + 1, 4))
    zz = np.zeros(n + 1)
    v = np.empty(4)
    for i in range(k):
        b = lab[i]
        xi = x[i] - sx[b]
        yi = y[i] - sy[b]
        v[0], v[1], v[2], v[3] = 1.0, xi, yi, xi * xi + yi * yi
        for p in range(4):
            for q in range(p, 4):
                m[b, p, q] += v[p] * v[q]
            rhs[b, p] += v[p] * z[i]
        zz[b] += z[i] * z[i]
    for b in range(n + 1):
        for p in range(4):
            for q in range(p + 1, 4):
                m[b, q, p] = m[b, p, q]
    return count, m, rhs, zz


# --- stop 45, speedreg45 ------------------------------------------------------------------------------------------
# thin_front's 5 x 5 medians of the filled depth by a selection network, without numpy's partition of the windows


#: Stop 61 (speedt61): :func:`window_medians`' three networks, each (i, j, kind) in order (kind 0 the smaller of two
#: wires to the first and the larger to the second, 1 the smaller alone, 2 the larger alone). ``SORT5`` sorts five
#: values (nine pairs, the least for five): each column of five of a pair of neighbouring windows. ``MID20`` takes
#: four sorted columns ``m0``..``m19`` (``m[5 j + i]`` the ``i``-th least of column ``j``) and leaves their 8th to
#: 13th least (of 20) in ``m8, m5, m9, m12, m13, m14``: Batcher's odd-even merges of the columns two by two and then
#: of the two tens, pruned back from those six wires and then pair by pair while an exhaustive test of every input of
#: 0 and 1 with sorted columns (6^4) still passed (51 pairs). Two neighbouring windows share four columns, so one
#: ``MID20`` serves both. ``MEDIAN11`` takes a sorted column ``f0``..``f4`` (the window's fifth) and those six
#: ``f5``..``f10`` and leaves the 6th least of the 11 in ``f10`` (made the same way from Batcher's merge of a five and
#: a six, 10 pairs): the window's 13th least of 25, its median, since seven of the four columns' values lie at or
#: below their 8th least and seven at or above their 13th. Exact by the 0-1 principle (a comparator network selects
#: the median of every input if it does of every input of 0 and 1): all 2^25 windows of 0 and 1 checked through the
#: three networks in both ways a window is made (the shared columns its last four or its first four),
#: tests/core/test_kernels.py. (6 x 9 + 51 + 2 x 10) / 2 = 62.5 pairs a window against the 113 of stop 45's network
#: on each window's 25 values (Batcher's sort of 32 pruned back from the median, ``MEDIAN25`` in git's history).
# fmt: off
SORT5 = (
    (0, 1, 0), (3, 4, 0), (2, 4, 0), (2, 3, 0), (0, 3, 0), (0, 2, 0), (1, 4, 0), (1, 3, 0), (1, 2, 0),
)
MID20 = (
    (0, 5, 0), (4, 9, 0), (4, 5, 0), (2, 7, 0), (2, 4, 0), (7, 5, 0), (1, 6, 0), (3, 8, 0), (3, 6, 0), (1, 2, 0),
    (3, 4, 0), (6, 7, 0), (8, 5, 0), (10, 15, 0), (14, 19, 0), (14, 15, 0), (12, 17, 0), (12, 14, 0), (17, 15, 0),
    (11, 16, 0), (13, 18, 0), (13, 16, 0), (11, 12, 0), (13, 14, 0), (16, 17, 0), (18, 15, 0), (0, 10, 2), (5, 15, 1),
    (5, 10, 0), (4, 14, 0), (4, 5, 2), (14, 10, 1), (2, 12, 2), (7, 17, 1), (7, 12, 0), (7, 5, 2), (12, 14, 0),
    (1, 11, 2), (9, 19, 1), (9, 11, 0), (6, 16, 0), (6, 9, 2), (16, 11, 1), (3, 13, 2), (8, 18, 1), (8, 13, 0),
    (8, 9, 0), (13, 16, 1), (8, 5, 0), (9, 12, 0), (13, 14, 0),
)
MEDIAN11 = (
    (0, 5, 2), (4, 9, 1), (4, 5, 2), (2, 7, 2), (7, 5, 1), (1, 6, 2), (10, 6, 1), (3, 8, 1), (3, 10, 2), (10, 7, 1),
)
# fmt: on


@_njit_inlined
def _median_with(
    f0: float, f1: float, f2: float, f3: float, f4: float,
    f5: float, f6: float, f7: float, f8: float, f9: float, f10: float,
) -> float:  # fmt: skip
    """The 6th least of ``f0``..``f4`` (sorted) and ``f5``..``f10`` (sorted) by :data:`MEDIAN11` (stop 61)."""
    f5 = max(f0, f5)
    f4 = min(f4, f9)
    f5 = max(f4, f5)
    f7 = max(f2, f7)
    f7 = min(f7, f5)
    f6 = max(f1, f6)
    f10 = min(f10, f6)
    f3 = min(f3, f8)
    f10 = max(f3, f10)
    f10 = min(f10, f7)
    return f10


#: :func:`near_filled`'s offsets ``(dr, dc)``: every one within a squared distance of 8 but (0, 0), by squared distance,
#: then column offset, then row offset: scipy's feature transform's choice among equally near pixels (the least
#: column, then the least row; :func:`symfruit.core.occlusion._offsets`' order; checked against the transform in
#: tests/core/test_kernels.py).
NEAR8 = tuple(
    sorted(
        ((dr, dc) for dr in range(-2, 3) for dc in range(-2, 3) if 0 < dr * dr + dc * dc <= 8),
        key=lambda o: (o[0] * o[0] + o[1] * o[1], o[1], o[0]),
    )
)


@_njit
def near_filled(depth: np.ndarray, ok: np.ndarray, out: np.ndarray) -> None:
    """``out`` (h, w) float64: ``depth`` (h, w) at the pixels of ``ok`` (h, w) bool; at each other pixel with an ``ok``
    pixel within a squared distance of 8 (every pixel within two rows and two columns of an ``ok`` pixel), the depth
    of the ``ok`` pixel ``ndimage.distance_transform_edt(~ok, return_indices=True)`` picks for it (:func:`nearest`'s),
    looked for through :data:`NEAR8`, nearest first, scipy's choice among equally near ones; 0 elsewhere (no ``ok``
    pixel that near: :func:`window_medians` reads none of them for a median it keeps). Stop 59, speedx59: a look
    around the pixels without depth instead of a feature transform of every pixel of the window."""
    h, w = ok.shape
    first = np.full(h, w, np.int64)  # each row's first and last ok column (w, -1: none)
    last = np.full(h, -1, np.int64)
    for r in range(h):
        for c in range(w):
            if ok[r, c]:
                first[r] = min(first[r], c)
                last[r] = c
    for r in range(h):
        # a pixel with an ok pixel within two rows and two columns lies within two columns of those rows' ok spans
        lo, hi = w, -1
        for q in range(max(r - 2, 0), min(r + 3, h)):
            lo, hi = min(lo, first[q] - 2), max(hi, last[q] + 2)
        for c in range(w):
            if ok[r, c]:
                out[r, c] = np.float64(depth[r, c])
                continue
            out[r, c] = 0.0
            if c < lo or c > hi:
                continue
            for dr, dc in NEAR8:
                a, b = r + dr, c + dc
                if 0 <= a < h and 0 <= b < w and ok[a, b]:
                    out[r, c] = np.float64(depth[a, b])
                    break


@_njit
def window_medians(depth: np.ndarray, ok: np.ndarray, medians: np.ndarray) -> None:
    """``medians`` ((n,) float64, n the pixels of ``ok`` (h, w) bool, which must hold one): the median of the 5 x 5
    window (edges repeated) of ``depth`` (h, w) float64 around each pixel of ``ok`` in raster order, every pixel not
    ``ok`` taking its nearest ``ok`` pixel's depth (:func:`nearest`, scipy's feature transform): what
    :func:`filled_windows` and numpy's ``np.partition(values, 12, axis=1)[:, 12]`` give, the same values (a median is
    one of the window's values, whichever way it is selected), by a selection network on the 25 values in registers,
    the windows never laid out (stop 45, speedreg45: 0.70 against 0.86 + 0.59 ms a frame for the partition
    and the windows, thread CPU on the benchmark frame's 14 calls, a busy machine). Its numpy twin:
    :func:`symfruit.core.surface._window_medians`. Every value must be a number (no NaN: ``thin_front``'s depth
    above 0 is).

    Since stop 59 (speedx59) the filled depth is :func:`near_filled`'s, not a feature transform of the whole window
    (:func:`nearest`): a window around an ``ok`` pixel reads pixels within two rows and two columns of it alone (edges
    repeated: a clamped pixel lies nearer still), whose nearest ``ok`` pixel lies within a squared distance of 8, the
    only ones it looks through; the same values in every ``ok`` pixel's window, so the same medians (the values of
    other windows, computed with them and never kept, may differ).

    Since stop 61 (speedt61) two neighbouring windows share a network: their six columns of five sorted
    (:data:`SORT5`), the four they share merged once (:data:`MID20`), each window's median from those and its own
    fifth column (:data:`MEDIAN11`): 62.5 pairs a window against 113, on several pairs at once (replayed on the
    benchmark frame's 18 calls: 0.59 -> 0.43 ms, docs/speedt61.md)."""
    h, w = ok.shape
    src = np.empty((h, w))
    near_filled(depth, ok, src)
    # the depth with its edges repeated (two rows above and below, two columns to each side) in its even and its odd
    # columns: ``split[0, a, k]`` the padded column 2 k (the depth's 2 k - 2), ``split[1, a, k]`` the padded 2 k + 1
    half = w // 2 + 3
    split = np.empty((2, h + 4, half))
    for a in range(h + 4):
        rr = min(max(a - 2, 0), h - 1)
        for k in range(half):
            split[0, a, k] = src[rr, min(max(2 * k - 2, 0), w - 1)]
            split[1, a, k] = src[rr, min(max(2 * k - 1, 0), w - 1)]
    # stop 61 (speedt61): each row's windows from its first to its last ``ok`` pixel two at a time, the windows
    # 2 k and 2 k + 1 (padded columns 2 k to 2 k + 5): their six columns of five sorted (SORT5), the four they share
    # merged once (MID20), each window's median from its own fifth column and those (MEDIAN11): the same 25 values'
    # median (see MID20), so the same value. No branch in the loop, and unsigned indices (no test for a negative
    # index), so that the compiler runs it on several pairs at once (with signed ones it did not vectorise it)
    row = np.empty(2 * half)
    one, two = np.uint64(1), np.uint64(2)
    n = 0
    for r in range(h):
        first, last = w, -1
        for c in range(w):
            if ok[r, c]:
                first, last = min(first, c), c
        if last < first:
            continue
        e0, e1, e2, e3, e4 = split[0, r], split[0, r + 1], split[0, r + 2], split[0, r + 3], split[0, r + 4]
        o0, o1, o2, o3, o4 = split[1, r], split[1, r + 1], split[1, r + 2], split[1, r + 3], split[1, r + 4]
        for pair in range(first // 2, last // 2 + 1):
            k = np.uint64(pair)
            a0, a1, a2, a3, a4 = e0[k], e1[k], e2[k], e3[k], e4[k]
            a0, a1 = min(a0, a1), max(a0, a1)
            a3, a4 = min(a3, a4), max(a3, a4)
            a2, a4 = min(a2, a4), max(a2, a4)
            a2, a3 = min(a2, a3), max(a2, a3)
            a0, a3 = min(a0, a3), max(a0, a3)
            a0, a2 = min(a0, a2), max(a0, a2)
            a1, a4 = min(a1, a4), max(a1, a4)
            a1, a3 = min(a1, a3), max(a1, a3)
            a1, a2 = min(a1, a2), max(a1, a2)
            m0, m1, m2, m3, m4 = o0[k], o1[k], o2[k], o3[k], o4[k]
            m0, m1 = min(m0, m1), max(m0, m1)
            m3, m4 = min(m3, m4), max(m3, m4)
            m2, m4 = min(m2, m4), max(m2, m4)
            m2, m3 = min(m2, m3), max(m2, m3)
            m0, m3 = min(m0, m3), max(m0, m3)
            m0, m2 = min(m0, m2), max(m0, m2)
            m1, m4 = min(m1, m4), max(m1, m4)
            m1, m3 = min(m1, m3), max(m1, m3)
            m1, m2 = min(m1, m2), max(m1, m2)
            m5, m6, m7, m8, m9 = e0[k + one], e1[k + one], e2[k + one], e3[k + one], e4[k + one]
            m5, m6 = min(m5, m6), max(m5, m6)
            m8, m9 = min(m8, m9), max(m8, m9)
            m7, m9 = min(m7, m9), max(m7, m9)
            m7, m8 = min(m7, m8), max(m7, m8)
            m5, m8 = min(m5, m8), max(m5, m8)
            m5, m7 = min(m5, m7), max(m5, m7)
            m6, m9 = min(m6, m9), max(m6, m9)
            m6, m8 = min(m6, m8), max(m6, m8)
            m6, m7 = min(m6, m7), max(m6, m7)
            m10, m11, m12, m13, m14 = o0[k + one], o1[k + one], o2[k + one], o3[k + one], o4[k + one]
            m10, m11 = min(m10, m11), max(m10, m11)
            m13, m14 = min(m13, m14), max(m13, m14)
            m12, m14 = min(m12, m14), max(m12, m14)
            m12, m13 = min(m12, m13), max(m12, m13)
            m10, m13 = min(m10, m13), max(m10, m13)
            m10, m12 = min(m10, m12), max(m10, m12)
            m11, m14 = min(m11, m14), max(m11, m14)
            m11, m13 = min(m11, m13), max(m11, m13)
            m11, m12 = min(m11, m12), max(m11, m12)
            m15, m16, m17, m18, m19 = e0[k + two], e1[k + two], e2[k + two], e3[k + two], e4[k + two]
            m15, m16 = min(m15, m16), max(m15, m16)
            m18, m19 = min(m18, m19), max(m18, m19)
            m17, m19 = min(m17, m19), max(m17, m19)
            m17, m18 = min(m17, m18), max(m17, m18)
            m15, m18 = min(m15, m18), max(m15, m18)
            m15, m17 = min(m15, m17), max(m15, m17)
            m16, m19 = min(m16, m19), max(m16, m19)
            m16, m18 = min(m16, m18), max(m16, m18)
            m16, m17 = min(m16, m17), max(m16, m17)
            b0, b1, b2, b3, b4 = o0[k + two], o1[k + two], o2[k + two], o3[k + two], o4[k + two]
            b0, b1 = min(b0, b1), max(b0, b1)
            b3, b4 = min(b3, b4), max(b3, b4)
            b2, b4 = min(b2, b4), max(b2, b4)
            b2, b3 = min(b2, b3), max(b2, b3)
            b0, b3 = min(b0, b3), max(b0, b3)
            b0, b2 = min(b0, b2), max(b0, b2)
            b1, b4 = min(b1, b4), max(b1, b4)
            b1, b3 = min(b1, b3), max(b1, b3)
            b1, b2 = min(b1, b2), max(b1, b2)
            m0, m5 = min(m0, m5), max(m0, m5)
            m4, m9 = min(m4, m9), max(m4, m9)
            m4, m5 = min(m4, m5), max(m4, m5)
            m2, m7 = min(m2, m7), max(m2, m7)
            m2, m4 = min(m2, m4), max(m2, m4)
            m7, m5 = min(m7, m5), max(m7, m5)
            m1, m6 = min(m1, m6), max(m1, m6)
            m3, m8 = min(m3, m8), max(m3, m8)
            m3, m6 = min(m3, m6), max(m3, m6)
            m1, m2 = min(m1, m2), max(m1, m2)
            m3, m4 = min(m3, m4), max(m3, m4)
            m6, m7 = min(m6, m7), max(m6, m7)
            m8, m5 = min(m8, m5), max(m8, m5)
            m10, m15 = min(m10, m15), max(m10, m15)
            m14, m19 = min(m14, m19), max(m14, m19)
            m14, m15 = min(m14, m15), max(m14, m15)
            m12, m17 = min(m12, m17), max(m12, m17)
            m12, m14 = min(m12, m14), max(m12, m14)
            m17, m15 = min(m17, m15), max(m17, m15)
            m11, m16 = min(m11, m16), max(m11, m16)
            m13, m18 = min(m13, m18), max(m13, m18)
            m13, m16 = min(m13, m16), max(m13, m16)
            m11, m12 = min(m11, m12), max(m11, m12)
            m13, m14 = min(m13, m14), max(m13, m14)
            m16, m17 = min(m16, m17), max(m16, m17)
            m18, m15 = min(m18, m15), max(m18, m15)
            m10 = max(m0, m10)
            m5 = min(m5, m15)
            m5, m10 = min(m5, m10), max(m5, m10)
            m4, m14 = min(m4, m14), max(m4, m14)
            m5 = max(m4, m5)
            m14 = min(m14, m10)
            m12 = max(m2, m12)
            m7 = min(m7, m17)
            m7, m12 = min(m7, m12), max(m7, m12)
            m5 = max(m7, m5)
            m12, m14 = min(m12, m14), max(m12, m14)
            m11 = max(m1, m11)
            m9 = min(m9, m19)
            m9, m11 = min(m9, m11), max(m9, m11)
            m6, m16 = min(m6, m16), max(m6, m16)
            m9 = max(m6, m9)
            m16 = min(m16, m11)
            m13 = max(m3, m13)
            m8 = min(m8, m18)
            m8, m13 = min(m8, m13), max(m8, m13)
            m8, m9 = min(m8, m9), max(m8, m9)
            m13 = min(m13, m16)
            m8, m5 = min(m8, m5), max(m8, m5)
            m9, m12 = min(m9, m12), max(m9, m12)
            m13, m14 = min(m13, m14), max(m13, m14)
            row[k + k] = _median_with(a0, a1, a2, a3, a4, m8, m5, m9, m12, m13, m14)
            row[k + k + one] = _median_with(b0, b1, b2, b3, b4, m8, m5, m9, m12, m13, m14)
        for c in range(first, last + 1):
            if ok[r, c]:
                medians[n] = row[c]
                n += 1


@_njit
def reaches_outline(mask: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> bool:
    """Whether one of the pixels ``(rows, cols)`` (int arrays, within ``mask`` (h, w) bool) lies on ``mask``'s outline:
    a pixel of the mask with a 4-neighbour outside it or beyond the array. The twin,
    :func:`symfruit.core.surface._reaches_outline`, is ``(mask & ~interior(mask))[rows, cols].any()``; here the
    neighbours of the listed pixels alone are read, and the first found ends it (stop 45, speedreg45)."""
    h, w = mask.shape
    for k in range(rows.shape[0]):
        r, c = rows[k], cols[k]
        if not mask[r, c]:
            continue
        if r == 0 or c == 0 or r == h - 1 or c == w - 1:
            return True
        if not (mask[r - 1, c] and mask[r + 1, c] and mask[r, c - 1] and mask[r, c + 1]):
            return True
    return False


@_njit
def part_sizes(
    parts: np.ndarray, count: int, depth: np.ndarray, front: float, join: float
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.core.surface._behind_sheet`'s counts of a partition ``parts`` (h, w) int (0 none, 1..``count``)
    in one pass: ``sizes`` (count + 1,) int64, ``np.bincount(parts.ravel(), minlength=count + 1)``, and ``near``
    (count + 1,), the same count of the parts' pixels whose ``depth`` (h, w) lies within ``join`` of ``front``
    (``np.bincount(parts[(parts > 0) & (np.abs(depth - front) <= join)], minlength=count + 1)``; 0 at 0). Whole
    numbers: the twin's, :func:`symfruit.core.surface._part_sizes` (stop 45, speedreg45)."""
    sizes = np.zeros(count + 1, np.int64)
    near = np.zeros(count + 1, np.int64)
    h, w = parts.shape
    for r in range(h):
        for c in range(w):
            p = parts[r, c]
            sizes[p] += 1
            if p > 0 and abs(depth[r, c] - front) <= join:
                near[p] += 1
    return sizes, near


# --- stop 45, speedcomp45


@_njit
def revolution_directions(dirs: np.ndarray, extra: np.ndarray) -> np.ndarray:
    """:func:`symfruit.core.fits._revolution_directions`: the coarse directions ``dirs`` (k, 3) followed by the
    ``extra`` ones (m, 3), each of those divided by its norm (``np.linalg.norm(extra, axis=1)``: numpy sums a row of
    three squares left to right) and turned to ``z >= 0`` (times -1.0 where the unit vector's ``z`` is negative, times
    1.0 elsewhere, as the twin multiplies): the same values, one call for five."""
    k, m = dirs.shape[0], extra.shape[0]
    out = np.empty((k + m, 3))
    for i in range(k):
        for c in range(3):
            out[i, c] = dirs[i, c]
    for i in range(m):
        x, y, z = extra[i, 0], extra[i, 1], extra[i, 2]
        norm = math.sqrt((x * x + y * y) + z * z)
        ux, uy, uz = x / norm, y / norm, z / norm
        sign = -1.0 if uz < 0 else 1.0
        out[k + i, 0] = ux * sign
        out[k + i, 1] = uy * sign
        out[k + i, 2] = uz * sign
    return out


@_njit
def apex_near(p: np.ndarray, front: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`symfruit.core.front.apex_depth`'s seed and squared image-plane distances: ``seed``, the mean of the
    ``x, y`` of the rows ``front`` of ``p`` (n, 3) (as :func:`column_means` of those rows: summed in order from 0,
    divided by their count), and ``d2`` (n,), each row's ``(x - seed_x)^2 + (y - seed_y)^2`` (the two squares added
    as :func:`symfruit.core.points.squared_norms` adds them): the twin's values, one call for six."""
    seed = np.zeros(2)
    for i in range(front.shape[0]):
        seed[0] += p[front[i], 0]
        seed[1] += p[front[i], 1]
    seed[0] /= front.shape[0]
    seed[1] /= front.shape[0]
    n = p.shape[0]
    d2 = np.empty(n)
    for i in range(n):
        dx = p[i, 0] - seed[0]
        dy = p[i, 1] - seed[1]
        d2[i] = dx * dx + dy * dy
    return seed, d2


@_njit
def apex_design(p: np.ndarray, pick: np.ndarray, seed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`symfruit.core.front.apex_depth`'s least squares: the design (k, 6) of the rows ``pick`` of ``p`` (n, 3),
    columns ``1, x, y, x x, x y, y y`` with ``x, y`` less ``seed`` (the twin's differences and products), and their
    depths (k,): one call for eight."""
    k = pick.shape[0]
    a = np.empty((k, 6))
    z = np.empty(k)
    for r in range(k):
        i = pick[r]
        x = p[i, 0] - seed[0]
        y = p[i, 1] - seed[1]
        a[r, 0] = 1.0
        a[r, 1] = x
        a[r, 2] = y
        a[r, 3] = x * x
        a[r, 4] = x * y
        a[r, 5] = y * y
        z[r] = p[i, 2]
    return a, z


# --- stop 45, speedocc45 ---------------------------------------------------------------------------------------------


@_njit_inlined
def _box_any(table: np.ndarray, r: int, c: int, k: int, m: int, n: int) -> bool:
    """Whether the summed-area ``table`` ((m + 1, n + 1) counts) holds a pixel within ``k`` (a square) of ``(r, c)``
    in its (m, n) image, the square clipped to the image (outside it, nothing)."""
    r0, r1, c0, c1 = max(r - k, 0), min(r + k + 1, m), max(c - k, 0), min(c + k + 1, n)
    return table[r1, c1] - table[r0, c1] - table[r1, c0] + table[r0, c0] > 0


@_njit
def _own_edge_in_box(
    hidden: np.ndarray,
    mask: np.ndarray,
    v0: int,
    u0: int,
    box_z: np.ndarray,
    p0: int,
    q0: int,
    seen: np.ndarray,
    others: np.ndarray,
    tolerance: float,
    band: int,
    supports: bool,
    focal: float,
    f0: int,
    f1: int,
    e0: int,
    e1: int,
) -> int:  # fmt: skip
    """:func:`own_edge` on :func:`occlusion_projected`'s maps, without the window's own depths and own pixels as (h, w)
    maps (issue 19, stop 45): ``hidden`` (h, w) bool cleared in place (the number of pixels cleared returned), the
    fruit's own pixels read from ``mask`` (the whole image, the window at ``(v0, u0)``; their box within the window
    given, rows ``f0:f1`` and columns ``e0:e1``, ``f1 <= f0``: none, stop 60) and ``box_z`` (the points' own depths
    over their pixels' box, at ``(p0, q0)`` in the window, +inf where none), ``seen`` the window's depths, ``others``
    the whole image's or (0, 0). The same pixels as :func:`own_edge`, by fewer passes over the own pixels' box grown
    by ``2 band + 1``: its three square filters (any pixel within a square) are read from summed-area tables of the
    own, the free and the past pixels (counts, exact), the last two at the candidates alone; the own depths' least
    within ``band`` from their row minima over the points' box alone (+inf elsewhere, so the same least); the band's
    run from the own pixels :func:`own_edge`'s walk. Until stop 61 (speedb61) it was the body of ``own_edge_boxed``,
    which found the mask's box itself, and of ``occlusion_edge_boxed`` (:func:`occlusion_at` then the own edge),
    which :func:`occlusion_projected` replaced at stop 60."""
    h, w = hidden.shape
    if band <= 0:
        return 0
    mb, nb = box_z.shape
    with_others = others.shape[0] > 0
    # the own pixels' box: the mask's within the window and the points' box (every one of its rows and columns holds
    # a point pixel: it is their box)
    r0, r1, c0, c1 = p0, p0 + mb, q0, q0 + nb
    if mb == 0 or nb == 0:
        r0, r1, c0, c1 = h, 0, w, 0
    if f1 > f0:
        r0, r1, c0, c1 = min(r0, f0), max(r1, f1), min(c0, e0), max(c1, e1)
    if r1 <= r0:
        return 0
    g = 2 * band + 1
    b0, b1, a0, a1 = max(r0 - g, 0), min(r1 + g, h), max(c0 - g, 0), min(c1 + g, w)
    m, n = b1 - b0, a1 - a0
    pb, qb = p0 - b0, q0 - a0  # the points' box in the grown box
    mine = np.empty((m, n), np.bool_)
    t_mine = np.zeros((m + 1, n + 1), np.int32)
    t_free = np.zeros((m + 1, n + 1), np.int32)
    for r in range(m):
        run_m, run_f = 0, 0
        inr = pb <= r < pb + mb
        for c in range(n):
            x = mask[v0 + b0 + r, u0 + a0 + c] or (inr and qb <= c < qb + nb and math.isfinite(box_z[r - pb, c - qb]))
            mine[r, c] = x
            run_m += x
            run_f += not x and not hidden[b0 + r, a0 + c]
            t_mine[r + 1, c + 1] = t_mine[r, c + 1] + run_m
            t_free[r + 1, c + 1] = t_free[r, c + 1] + run_f
    # the candidates (hidden, near the own pixels, neither theirs nor another fruit's) and the past pixels' table
    t_past = np.zeros((m + 1, n + 1), np.int32)
    cand = np.zeros((m, n), np.bool_)
    at = np.empty(m * n, np.int64)  # stop 65 (occl65): the candidates' flat indices, raster order
    count = 0
    for r in range(m):
        run_p = 0
        for c in range(n):
            hid = hidden[b0 + r, a0 + c]
            if hid:
                near = _box_any(t_mine, r, c, band, m, n)
                if near:
                    if not mine[r, c] and not (with_others and others[v0 + b0 + r, u0 + a0 + c]):
                        cand[r, c] = True
                        at[count] = r * n + c
                        count += 1
                else:
                    run_p += 1
            t_past[r + 1, c + 1] = t_past[r, c + 1] + run_p
    if count == 0:
        return 0
    # the own depths' least along the rows of the points' box, within band of each column (+inf beyond: no point
    # pixel lies outside the box)
    wide = nb + 2 * band
    rowmin = np.full((max(mb, 1), max(wide, 1)), np.inf)
    # stop 65 (occl65): each own depth taken into the 2 band + 1 places of the padded row that reach it, not a padded
    # copy and van Herk's blocks (a remainder a place); a least is exact in any order (no NaN: +inf or a depth)
    size = 2 * band + 1
    for i in range(mb):
        out = rowmin[i]
        for j in range(nb):
            v = box_z[i, j]
            if v < np.inf:
                for t in range(j, j + size):
                    out[t] = min(out[t], v)
    front, r_px, r_m = _support_scale(box_z, r0, r1, c0, c1, focal)
    reach = np.zeros((m, n))
    listed = count
    count = 0
    for i in range(listed):  # the candidates alone (stop 65), in raster order
        r = at[i] // n
        c = at[i] - r * n
        if True:
            # the band ends: something not hiding the fruit lies just beyond, and nothing hidden runs on past it; with
            # ``supports`` a band that runs on (a support) is cleared too, past the reach the fruit may continue behind
            ends = _box_any(t_free, r, c, band + 1, m, n) and not _box_any(t_past, r, c, band, m, n)
            x = supports or ends
            if not ends and supports and r_m > 0.0 and r_m < np.inf:
                reach[r, c] = _support_reach(np.float64(seen[b0 + r, a0 + c]), front, r_px, r_m)
            if x:  # not clearly nearer than the own depths within the band's square
                z = np.inf
                j = c - qb + band  # this column's place in the padded rows (column qb - band is their first)
                if mb > 0 and 0 <= j < wide:
                    for rr in range(max(r - band, pb), min(r + band + 1, pb + mb)):
                        z = min(z, rowmin[rr - pb, j])
                x = np.float64(seen[b0 + r, a0 + c]) >= z - tolerance  # NaN: not the fruit's
            cand[r, c] = x
            count += x
    if count == 0:
        return 0
    return _band_walk_listed(cand, mine, count, band, hidden, b0, a0, reach, at, listed)


@_njit
def label_boxes(labels: np.ndarray, n: int) -> np.ndarray:
    """(n, 4) int64: the box ``(r0, r1, c0, c1)`` (stops exclusive) of each label 1..n of ``labels`` (h, w) integers,
    ``r1 = 0`` for a label without pixels; labels beyond ``n`` and below 1 are background. What
    ``ndimage.find_objects(labels, n)`` finds, in one pass along the rows, each row's run of one label read as one
    (issue 19, stop 45: find_objects cost 0.6 ms on a 640x480 frame, a fifth of ``detect``'s own work)."""
    out = np.zeros((n, 4), np.int64)
    h, w = labels.shape
    for k in range(n):
        out[k, 0], out[k, 2] = h, w
    for r in range(h):
        some = 0
        for c in range(w):  # a row of background alone is skipped after one pass numba vectorises
            some |= labels[r, c]
        if some == 0:
            continue
        c = 0
        while c < w:
            if c + 32 <= w:  # 32 pixels of background at once
                block = 0
                for j in range(c, c + 32):
                    block |= labels[r, j]
                if block == 0:
                    c += 32
                    continue
            v = labels[r, c]
            if v < 1 or v > n:
                c += 1
                continue
            start = c
            c += 1
            while c < w and labels[r, c] == v:
                c += 1
            k = v - 1
            out[k, 0] = min(out[k, 0], r)
            out[k, 1] = r + 1
            out[k, 2] = min(out[k, 2], start)
            out[k, 3] = max(out[k, 3], c)
    return out


@_njit
def boxes_within(labels: np.ndarray, windows: np.ndarray) -> np.ndarray:
    """(n, 4) int64: the box ``(r0, r1, c0, c1)`` (stops exclusive) of each label 1..n of ``labels`` (h, w) integers
    looked for within its window ``windows[k - 1]`` ``(r0, r1, c0, c1)`` alone (an empty one, ``r1 <= r0`` or
    ``c1 <= c0``: none), ``r1 = 0`` for a label without pixels there: :func:`label_boxes`' where every label's pixels
    lie within its window (issue 19, stop 62: ``detect``'s boxes of the masks moved onto the depth image, within
    their drawn boxes moved, not a pass over the whole image)."""
    n = windows.shape[0]
    out = np.zeros((n, 4), np.int64)
    h, w = labels.shape
    for k in range(n):
        r0, r1 = max(windows[k, 0], 0), min(windows[k, 1], h)
        c0, c1 = max(windows[k, 2], 0), min(windows[k, 3], w)
        top, bottom, left, right = h, 0, w, -1
        for r in range(r0, r1):
            first = c0
            while first < c1 and labels[r, first] != k + 1:  # the row's first pixel of the label ...
                first += 1
            if first == c1:
                continue
            last = c1 - 1
            while labels[r, last] != k + 1:  # ... and its last (one there is)
                last -= 1
            top, bottom = min(top, r), r + 1
            left, right = min(left, first), max(right, last)
        if bottom > 0:
            out[k, 0], out[k, 1], out[k, 2], out[k, 3] = top, bottom, left, right + 1
    return out


# --- stop 46, regspeed46: the principal widths' extents -----------------------------------------------------------


@_njit
def column_extents(p: np.ndarray) -> tuple[float, float]:
    """``(np.ptp(p[:, 0]), np.ptp(p[:, 1]))`` of ``p`` (n, 2) float64, ``n >= 1``, in one pass: each column's greatest
    less its least (NaN where the column holds a NaN, as numpy's maximum and minimum propagate it). A greatest and a
    least are values of the column, whatever the order they are found in: the same difference, but where both are
    zeros of either sign (then a zero, whose sign :func:`symfruit.core.raster.principal_widths` loses adding 1)."""
    lo0, hi0, lo1, hi1 = p[0, 0], p[0, 0], p[0, 1], p[0, 1]
    nan0, nan1 = False, False
    for i in range(p.shape[0]):
        a, b = p[i, 0], p[i, 1]
        nan0 = nan0 or a != a
        nan1 = nan1 or b != b
        lo0, hi0 = min(lo0, a), max(hi0, a)
        lo1, hi1 = min(lo1, b), max(hi1, b)
    return (np.nan if nan0 else hi0 - lo0), (np.nan if nan1 else hi1 - lo1)


# --- stop 46, segspeed46: the colour segmenter's cut moved onto the depth edges, its edge test at the cut alone -------


@_njit
def follow_edges(
    region: np.ndarray, edges: np.ndarray, owner: np.ndarray, m: int, purity: float
) -> tuple[np.ndarray, bool]:
    """:func:`symfruit.segment.colour._follow_edges` from the ``region`` (h, w) bool, its depth ``edges`` (h, w) bool
    and the parts' ``owner`` map (h, w) int64 (0: none, 1..m): the pieces of the region less the edges labelled with
    four neighbours (:func:`label`, ``ndimage.label``'s), each (piece, owner) pair's pixels counted, a piece going
    whole to the owner holding most of it (the first of equal counts, ``argmax``'s) when that holds at least
    ``purity`` of its owned pixels (the twin's float comparison of whole counts), the other pixels of a piece to their
    own owner, edge pixels and the outside to none; then every region pixel to its :func:`nearest` seed's owner
    (``ndimage.distance_transform_edt``'s choice). Returns the grown map (h, w) int64 (0 outside the region) and
    True, or an empty map and False where the twin keeps the parts as they are (fewer than two pieces, or no seed).
    The twin's values in one call, not some fifteen numpy passes over the window (stop 46)."""
    h, w = region.shape
    cut = np.empty((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            cut[r, c] = region[r, c] and not edges[r, c]
    pieces, n = label(cut, False)
    if n < 2:
        return np.zeros((0, 0), np.int64), False
    counts = np.zeros((n + 1, m + 1), np.int64)
    for r in range(h):
        for c in range(w):
            counts[pieces[r, c], owner[r, c]] += 1
    major = np.empty(n + 1, np.int64)
    pure = np.empty(n + 1, np.bool_)
    for p in range(n + 1):
        best, total = 1, 0
        for k in range(1, m + 1):
            total += counts[p, k]
            if counts[p, k] > counts[p, best]:
                best = k
        major[p] = best
        pure[p] = counts[p, best] >= purity * max(total, 1)
    seeds = np.zeros((h, w), np.int64)
    free = np.empty((h, w), np.bool_)
    any_seed = False
    for r in range(h):
        for c in range(w):
            p = pieces[r, c]
            if p != 0:  # a piece's pixel lies in the region
                seeds[r, c] = major[p] if pure[p] else owner[r, c]
            free[r, c] = seeds[r, c] == 0
            any_seed = any_seed or seeds[r, c] != 0
    if not any_seed:
        return np.zeros((0, 0), np.int64), False
    near = np.empty((h, w), np.int64)
    nearest(free, near)
    grown = np.zeros((h, w), np.int64)
    flat = seeds.ravel()  # read by the flat index itself: no division a pixel (stop 48)
    for r in range(h):
        for c in range(w):
            if region[r, c]:
                grown[r, c] = flat[near[r, c]]
    return grown, True


@_njit
def near_edge_cut(a: np.ndarray, b: np.ndarray, edges: np.ndarray) -> int:
    """:func:`symfruit.segment.colour._supported`'s test of the cut between two cells ``a`` and ``b`` (h, w) bool:
    the cut is the pixels of either within the other's 8-neighbourhood (the twin's ``_dilate(square=True)``), and it
    runs along the depth ``edges`` (h, w) bool when at least half of its pixels lie within two 4-neighbour steps of an
    edge pixel (the twin's ``_dilate(_dilate(edges))``, read at the cut alone: ``mean() >= 0.5`` of whole counts is
    ``2 * near >= cut``). Returns -1 without a cut, 1 along the edges, 0 not. Only where the two cells' boxes, grown by
    a pixel, meet is looked at (the cut lies there)."""
    h, w = a.shape
    ar0, ar1, ac0, ac1 = h, -1, w, -1
    br0, br1, bc0, bc1 = h, -1, w, -1
    for r in range(h):
        for c in range(w):
            if a[r, c]:
                ar0, ar1, ac0, ac1 = min(ar0, r), max(ar1, r), min(ac0, c), max(ac1, c)
            if b[r, c]:
                br0, br1, bc0, bc1 = min(br0, r), max(br1, r), min(bc0, c), max(bc1, c)
    r0, r1 = max(max(ar0, br0) - 1, 0), min(min(ar1, br1) + 2, h)
    c0, c1 = max(max(ac0, bc0) - 1, 0), min(min(ac1, bc1) + 2, w)
    n_cut = 0
    n_near = 0
    for r in range(r0, r1):
        for c in range(c0, c1):
            if not (a[r, c] or b[r, c]):
                continue
            other = b if a[r, c] else a  # a pixel of both is within the other's neighbourhood: itself
            hit = False
            for i in range(max(r - 1, 0), min(r + 2, h)):
                for j in range(max(c - 1, 0), min(c + 2, w)):
                    if other[i, j]:
                        hit = True
                        break
                if hit:
                    break
            if not hit:
                continue
            n_cut += 1
            near = False
            for i in range(max(r - 2, 0), min(r + 3, h)):
                d = 2 - abs(i - r)
                for j in range(max(c - d, 0), min(c + d + 1, w)):
                    if edges[i, j]:
                        near = True
                        break
                if near:
                    break
            n_near += 1 if near else 0
    if n_cut == 0:
        return -1
    return 1 if 2 * n_near >= n_cut else 0


@_njit
def surface_hull(
    vertices: np.ndarray, part: np.ndarray, owner: np.ndarray, k: int, color: np.ndarray, surface: bool
) -> np.ndarray:
    """:func:`symfruit.segment.colour._surface_hull`: the hull polygon ``vertices`` (m, 2) float64 filled over the
    piece's ``part`` (h, w) bool (:func:`polygon_fill`, Pillow's pixels), less the pixels another piece owns
    (``owner`` (h, w) ints, the window of the whole image's map: 0 or ``k`` are free) and, with ``surface``, less the
    green pixels (:func:`green_pixels`' test on ``color`` (h, w, 3) uint8) that are not the part's. The twin's
    pixels in one pass over the filled window, not six numpy passes and a green map. A (0, 0) array when a vertex is
    not a whole number (the twin's Pillow then)."""
    out = polygon_fill(vertices, part)
    if out.shape[0] != part.shape[0] or out.shape[1] != part.shape[1]:
        return out
    h, w = part.shape
    for r in range(h):
        for c in range(w):
            if not out[r, c]:
                continue
            o = owner[r, c]
            keep = o == 0 or o == k
            if keep and surface and not part[r, c]:
                red, green, blue = np.int64(color[r, c, 0]), np.int64(color[r, c, 1]), np.int64(color[r, c, 2])
                keep = not (green > red and green >= blue and 3 * (green - min(red, blue)) >= green)
            out[r, c] = keep
    return out


@_njit
def green_in_hull(vertices: np.ndarray, union: np.ndarray, color: np.ndarray) -> int:
    """:func:`symfruit.segment.colour._green_in_hull`: how many pixels of the hull polygon ``vertices`` (m, 2) float64
    filled over ``union`` (h, w) bool (:func:`polygon_fill`) lie outside ``union`` and are green (:func:`green_pixels`'
    test on ``color`` (h, w, 3) uint8); -1 when a vertex is not a whole number (the twin's Pillow then)."""
    out = polygon_fill(vertices, union)
    if out.shape[0] != union.shape[0] or out.shape[1] != union.shape[1]:
        return -1
    h, w = union.shape
    n = 0
    for r in range(h):
        for c in range(w):
            if out[r, c] and not union[r, c]:
                red, green, blue = np.int64(color[r, c, 0]), np.int64(color[r, c, 1]), np.int64(color[r, c, 2])
                n += 1 if green > red and green >= blue and 3 * (green - min(red, blue)) >= green else 0
    return n


# --- stop 47, extspeed47: the hidden front's sphere residuals, thin_front's noise deviation -------------------------


@_njit
def sphere_residuals(p: np.ndarray, c: np.ndarray, r: float, jac: np.ndarray, resid: np.ndarray) -> None:
    """:func:`symfruit.core.front.sphere_front`'s Jacobian and residuals at the centre ``c`` (3,), the radius ``r``, of
    the points ``p`` (n, 3) float64: ``jac`` (n, 3) gets ``diff / -dist`` and ``resid`` (n,) ``dist - r``, where
    ``diff = p - c`` and ``dist`` is ``sqrt(diff[:, 0]^2 + diff[:, 1]^2 + diff[:, 2]^2)`` (added in that order, as
    :func:`symfruit.core.points.squared_norms` adds them) and at least 1e-12 (NaN kept, as ``np.maximum`` keeps it).
    The twin's (:func:`symfruit.core.front._sphere_residuals`) operations one by one, so its values bit for bit; the
    products ``jac.T @ jac`` and ``jac.T @ resid`` stay numpy's (OpenBLAS's last bits are the CPU's, stop 42)."""
    c0, c1, c2 = c[0], c[1], c[2]
    for i in range(p.shape[0]):
        d0, d1, d2 = p[i, 0] - c0, p[i, 1] - c1, p[i, 2] - c2
        total = d0 * d0
        total += d1 * d1
        total += d2 * d2
        dist = math.sqrt(total)
        if not (dist >= 1e-12 or dist != dist):
            dist = 1e-12
        neg = -dist
        jac[i, 0] = d0 / neg
        jac[i, 1] = d1 / neg
        jac[i, 2] = d2 / neg
        resid[i] = dist - r


@_njit
def sphere_front_behind(p: np.ndarray, r: float, iterations: int, tolerance: float, front: float) -> bool:
    """Whether :func:`symfruit.core.front.sphere_front`'s front ``z`` of the points ``p`` (n, 3) float64 with the radius
    ``r`` (``iterations``, ``tolerance``) surely lies behind ``front``: ``z >= front``, decided without its BLAS and
    LAPACK calls (issue 19, stop 63: ``hidden_front`` of :mod:`symfruit.methods.evidence` then keeps ``front``, on
    seven of the benchmark frame's nine fruit). False: not sure (the caller fits as before).

    The same Gauss-Newton from the same start (the points' mean, ``r`` deeper), its sums in the points' order: each
    step the twin's to rounding. The twin stops at its first step below ``tolerance`` on every axis. This one goes on
    until a step is below ``tolerance / 64``, and is sure only where:

    - no step before its first stop lies within a thousandth of ``tolerance`` above it, so the twin, whose steps
      differ by rounding, stops at the same step or the one after;
    - from that first stop on, every step is at most half the one before: the steps of a contraction, all that
      follow a step summing to at most it. So the twin's stopped centre lies within ``2 tolerance`` of the centre
      this one ends at, and that centre within ``tolerance / 64`` of the limit;
    - the front at its end lies behind ``front`` by more than ``4 tolerance``.

    Also not sure: fewer than 4 points, a radius not above 0, a front or tolerance not finite, a first stop within 3
    steps of ``iterations`` (the twin might not stop), 40 steps more without settling, a pivot of the 3x3 normal
    equations under 1e-10 times the greatest (where the twin might take its least-squares step), or a value not
    finite."""
    n = p.shape[0]
    if n < 4 or not (r > 0.0 and math.isfinite(r) and tolerance > 0.0 and math.isfinite(tolerance)
                     and math.isfinite(front)):  # fmt: skip
        return False
    q0, q1, q2 = _columns3(p)
    c0 = c1 = c2 = 0.0
    for i in range(n):
        c0 += q0[i]
        c1 += q1[i]
        c2 += q2[i]
    c0, c1, c2 = c0 / n, c1 / n, c2 / n + r
    j0s, j1s, j2s, rs = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    a = np.empty((3, 3))
    g = np.empty(3)
    x = np.empty(3)
    stopped = False
    last = np.inf
    for k in range(iterations + 40):
        for i in range(n):  # the distances, Jacobian rows and residuals (a loop the vector units run)
            d0, d1, d2 = q0[i] - c0, q1[i] - c1, q2[i] - c2
            dist = max(math.sqrt(d0 * d0 + d1 * d1 + d2 * d2), 1e-12)
            j0s[i], j1s[i], j2s[i] = -d0 / dist, -d1 / dist, -d2 / dist
            rs[i] = dist - r
        a00 = a01 = a02 = a11 = a12 = a22 = g0 = g1 = g2 = 0.0
        for i in range(n):
            j0, j1, j2, res = j0s[i], j1s[i], j2s[i], rs[i]
            a00 += j0 * j0
            a01 += j0 * j1
            a02 += j0 * j2
            a11 += j1 * j1
            a12 += j1 * j2
            a22 += j2 * j2
            g0 -= j0 * res
            g1 -= j1 * res
            g2 -= j2 * res
        a[0, 0], a[0, 1], a[0, 2] = a00, a01, a02
        a[1, 0], a[1, 1], a[1, 2] = a01, a11, a12
        a[2, 0], a[2, 1], a[2, 2] = a02, a12, a22
        g[0], g[1], g[2] = g0, g1, g2
        if not solve(a, g, x):
            return False
        top = max(abs(a[0, 0]), abs(a[1, 1]), abs(a[2, 2]))
        if not (min(abs(a[0, 0]), abs(a[1, 1]), abs(a[2, 2])) > 1e-10 * top):  # NaN: not sure
            return False
        c0, c1, c2 = c0 + x[0], c1 + x[1], c2 + x[2]
        step = max(abs(x[0]), abs(x[1]), abs(x[2]))
        if not math.isfinite(step):
            return False
        if stopped:
            if step > 0.5 * last:
                return False
            if step < tolerance / 64.0:
                return c2 - r > front + 4.0 * tolerance
        elif step < tolerance:  # the twin's stop
            if k >= iterations - 3:
                return False
            stopped = True
        elif step < 1.001 * tolerance:  # the twin's rounding might stop it here, before this one
            return False
        last = step
    return False


@_njit
def median_deviation(x: np.ndarray) -> float:
    """``median(abs(x - median(x)))`` of ``x`` (n,) float64, ``n >= 1`` (:func:`symfruit.core.points.median`'s
    values: order statistics, the middle two's sum halved; NaN when a value is NaN), reordering and overwriting ``x``:
    :func:`symfruit.core.surface.thin_front`'s noise deviation of its smoothed depth's differences in one call instead
    of two partitions and two passes (stop 47; :func:`depth_noise`'s medians)."""
    n = x.shape[0]
    for i in range(n):
        if np.isnan(x[i]):
            return np.nan
    return deviation_median(x)  # the same medians without branches (stop 49)


# --- stop 47, segspeed47: the round skin's reach test -----------------------------------------------------------------


@_njit
def at_reach(skin: np.ndarray, r_off: int, c_off: int, rc: float, cc: float, limit: float) -> bool:
    """:func:`symfruit.segment.colour._at_reach` of ``skin`` (h, w) bool in a window at ``(r_off, c_off)``: whether a
    pixel of it lies on the window's edge, or (unless its box's farthest corner lies within) farther than
    ``sqrt(limit)`` (the twin's ``(reach - 1) ** 2``) from ``(rc, cc)``. The twin's box (:func:`mask_box`'s), its
    corner's and pixels' offsets, sums and comparisons in float64: the same answer, in one pass over the window
    and one over the box instead of two reductions, a ``nonzero`` and four array sums (stop 47)."""
    h, w = skin.shape
    r0, r1, c0, c1 = _box(skin)
    if r1 == 0:
        return False
    if r0 == 0 or c0 == 0 or r1 == h or c1 == w:
        return True
    dy = max(abs(float(r0 + r_off) - rc), abs(float(r1 - 1 + r_off) - rc))
    dx = max(abs(float(c0 + c_off) - cc), abs(float(c1 - 1 + c_off) - cc))
    if dy * dy + dx * dx <= limit:
        return False
    tr, tc = float(r0 + r_off) - rc, float(c0 + c_off) - cc
    for r in range(r0, r1):
        dr = float(r - r0) + tr
        for c in range(c0, c1):
            if skin[r, c]:
                dc = float(c - c0) + tc
                if dr * dr + dc * dc > limit:
                    return True
    return False


# --- stop 47, yellowfast47: the depth camera's short gaps bridged, window by window


@_njit
def bridge_gaps(z: np.ndarray, r0: int, r1: int, c0: int, c1: int, reach: float, out: np.ndarray) -> None:
    """:class:`symfruit.segment.colour._BridgedDepth`'s window ``z[r0:r1, c0:c1]`` into ``out`` (r1 - r0, c1 - c0)
    float64: ``z`` (h, w) float a depth image (a pixel has depth where its value is above 0 and below infinity, as
    :class:`symfruit.segment.colour._Depth` reads it; the whole image or a window of it padded by more than
    ``reach``), each pixel's depth as float64, and each pixel without depth the depth of the nearest pixel with
    depth when that lies within ``reach`` pixels, else 0; among as near pixels the one scipy's feature transform
    (:func:`nearest`) picks: the leftmost column's, in it the upper.

    Its twin, :func:`symfruit.segment.colour._bridged`, runs the feature transform over the padded window; here
    only the disc within ``reach`` counts (stop 47, yellowfast47). Each column's rows to its nearest pixel with
    depth within ``k = floor(reach)`` rows, above (a sweep down the rows) and below (a sweep up), counted in int32
    runs that restart at 0 on depth, ``k + 1`` when none (the upper of two as near); then, row by row, every
    pixel's least key over the ``2k + 1`` columns about it, a column's key its squared distance shifted left by
    ``sh`` bits and its offset ``+ k`` in the low bits (the least squared distance, then the leftmost column: the
    same choice as weighing the columns left to right, a later one taken only when strictly nearer), and the pixels
    without depth whose least squared distance is within ``reach ** 2`` take that pixel's depth. Every loop but the
    last runs over whole rows without a branch on the pixel (stop 49, treeseg49: about half the time of weighing
    the columns pixel by pixel). Since stop 53 (seg53) a row with depth throughout is copied alone, and a row where
    at most a quarter of the pixels lack depth has those pixels' columns weighed one by one, the same choice (the
    apple-tree frames 0-2's windows: 40 % of their pixels lack depth, a fifth of their rows a few of them; the
    recorded calls 3.0 -> 2.7 ms a frame)."""
    h, w = z.shape
    if r1 <= r0 or c1 <= c0:
        return
    k = int(reach)
    lim = int(reach * reach)  # an integer squared distance is within reach ** 2 when within its floor
    ra, rb = max(r0 - k, 0), min(r1 + k, h)
    ca, cb = max(c0 - k, 0), min(c1 + k, w)
    nw = c1 - c0
    n = nw + 2 * k  # the columns c0 - k .. c1 + k - 1; those outside the image have no depth
    off, m = ca - (c0 - k), cb - ca
    none = np.int32(k + 1)
    sh = 1
    while (1 << sh) <= 2 * k:
        sh += 1
    low = (1 << sh) - 1
    up = np.full((r1 - r0, n), none, np.int32)  # each pixel's column: rows up to its nearest depth, none: beyond k
    run = np.full(n, none, np.int32)
    seen = run[off : off + m]
    for r in range(ra, r1):
        row = z[r, ca:cb]
        for j in range(m):
            v = row[j]
            t = seen[j] + 1
            seen[j] = 0 if (v > 0) & (v < np.inf) else (t if t < none else none)
        if r >= r0:
            up[r - r0] = run
    run[:] = none  # now rows down to the nearest depth
    far = np.int32(1 << 24)  # a key beyond any squared distance within reach
    cost = np.empty(n, np.int32)
    key = np.empty(nw, np.int32)
    kk = np.int32((k * k) << sh)
    gaps = np.empty(nw, np.int64)  # the row's columns without depth
    for r in range(rb - 1, r0 - 1, -1):
        row = z[r, ca:cb]
        for j in range(m):
            v = row[j]
            t = seen[j] + 1
            seen[j] = 0 if (v > 0) & (v < np.inf) else (t if t < none else none)
        if r >= r1:
            continue
        dst = out[r - r0]
        given = z[r, c0:c1]
        g = 0
        for j in range(nw):  # the depths, and the columns without one (written over: no branch on the pixel)
            v = given[j]
            ok = (v > 0) & (v < np.inf)
            dst[j] = np.float64(v) if ok else 0.0
            gaps[g] = j
            g += 0 if ok else 1
        if g == 0:
            continue  # a row with depth throughout: nothing to bridge (stop 53, seg53)
        above = up[r - r0]
        if 4 * g <= nw:
            # few pixels without depth: each one's least key over the 2k + 1 columns about it alone, the columns left
            # to right and a later one taken only when strictly nearer (the same choice as the keys' below; seg53)
            for i in range(g):
                j = gaps[i]
                best = lim + 1
                bd = 0
                for d in range(-k, k + 1):
                    a = above[j + k + d]
                    b = run[j + k + d]
                    near = a if a < b else b
                    if near <= k:
                        q = near * near + d * d
                        if q < best:
                            best, bd = q, d
                if best <= lim:
                    a = above[j + k + bd]
                    b = run[j + k + bd]
                    dst[j] = np.float64(z[r - a if a <= b else r + b, c0 + j + bd])
            continue
        for j in range(n):
            a = above[j]
            b = run[j]
            near = a if a < b else b
            cost[j] = (near * near) << sh if near <= k else far
        for j in range(nw):  # the leftmost column, offset -k: its low bits 0
            key[j] = cost[j] + kk
        for d in range(-k + 1, k + 1):
            add = np.int32(((d * d) << sh) + d + k)
            shifted = cost[k + d : k + d + nw]
            for j in range(nw):
                x = shifted[j] + add
                y = key[j]
                key[j] = x if x < y else y
        for i in range(g):
            j = gaps[i]
            best = key[j]
            if (best >> sh) <= lim:
                d = (best & low) - k
                a = above[j + k + d]
                b = run[j + k + d]
                dst[j] = np.float64(z[r - a if a <= b else r + b, c0 + j + d])


# --- stop 48, seg640_48: the colour segmenter's split at 640x480 ------------------------------------------------------


@_njit
def inner_distance(mask: np.ndarray, out: np.ndarray) -> None:
    """Into ``out`` (h, w) the distance map of ``mask`` (h, w) bool padded by a pixel of False, its inside: each mask
    pixel's distance to the nearest pixel off the mask or outside the array, 0 off the mask (``distance(pad, False,
    dist)[1:-1, 1:-1]`` of :func:`distance` over the padded copy, ``ndimage.distance_transform_edt(np.pad(mask, 1))``'s
    inside). Without the padded copy: the columns' distances with the border rows as the pixels off the mask, then
    each row's lower envelope (:func:`_envelope`) run by run of the row's mask pixels, over the run's columns and the
    pixel off the mask either side (distance 0): a column beyond those lies farther along the row than the run's end
    that bounds it, so its parabola is nowhere below the least one. The same least squared distances, so the same
    square roots, bit for bit, at about two thirds of the padded map's time (the split's windows)."""
    h, w = mask.shape
    g = np.empty((h, w), np.int64)
    for c in range(w):
        g[0, c] = 1 if mask[0, c] else 0
    for r in range(1, h):
        for c in range(w):
            g[r, c] = g[r - 1, c] + 1 if mask[r, c] else 0
    for c in range(w):
        if g[h - 1, c] > 1:
            g[h - 1, c] = 1
    for r in range(h - 2, -1, -1):
        for c in range(w):
            if g[r + 1, c] + 1 < g[r, c]:
                g[r, c] = g[r + 1, c] + 1
    f = np.empty(w + 2, np.int64)
    s = np.empty(w + 2, np.int64)
    t = np.empty(w + 2, np.int64)
    d2 = np.empty(w + 2, np.int64)
    for r in range(h):
        c = 0
        while c < w:
            if not mask[r, c]:
                out[r, c] = 0.0
                c += 1
                continue
            a = c
            while c < w and mask[r, c]:
                c += 1
            n = c - a + 2  # the run a..c-1 and the pixels off the mask at a-1 and c (f = 0), locally 0..n-1
            f[0] = 0
            for i in range(a, c):
                f[i - a + 1] = g[r, i] * g[r, i]
            f[n - 1] = 0
            _envelope(f, n, s, t, d2)
            for i in range(a, c):
                out[r, i] = math.sqrt(float(d2[i - a + 1]))


@_njit
def red_ripe(color: np.ndarray, red: np.ndarray, least: np.float32) -> bool:
    """Whether :func:`red_median` of the pixels of ``red`` (h, w) bool in ``color`` (h, w, >= 3) uint8 reaches ``least``
    (float32), compared in float32 (:func:`symfruit.segment.colour._ripe`'s test), mostly without the median: the
    middle value of an odd count reaches it exactly when no more than half the values (``n // 2``) lie below it; of an
    even count, the float32 mean of the middle two reaches it when both do (fewer than ``n // 2`` values below: their
    sum rounds to no less than twice ``least``). Otherwise (an even count with half or more below: the mean may still
    round up to it) the median itself as :func:`red_median` has it. The same answer, without the quickselect for a
    ripe fruit (stop 48)."""
    h, w = red.shape
    n = 0
    below = 0
    for r in range(h):
        for c in range(w):
            if red[r, c]:
                n += 1
                below += _redness_at(color, r, c) < least
    if n == 0:
        return False  # the median is NaN
    half = n // 2
    if n % 2:
        return below <= half
    if below < half:
        return True
    return np.float32(red_median(color, red)) >= least


@_njit
def group_boxes(at: np.ndarray, first: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """:func:`symfruit.segment.colour._group_boxes`' boxes: for each group ``i`` of the pixels ``at[first[i]:first[i +
    1]]`` (indices into ``rows`` and ``cols``; every group holds one or more), the least and one past the greatest row
    and column, (k, 4) int64 rows ``r0, r1, c0, c1`` (the twin's ``reduceat`` minima and maxima: the same numbers) in
    one call, not a dozen numpy ones a window (stop 48)."""
    k = first.shape[0] - 1
    out = np.empty((k, 4), np.int64)
    for i in range(k):
        j = at[first[i]]
        r0 = r1 = rows[j]
        c0 = c1 = cols[j]
        for m in range(first[i] + 1, first[i + 1]):
            j = at[m]
            r, c = rows[j], cols[j]
            r0, r1 = min(r0, r), max(r1, r)
            c0, c1 = min(c0, c), max(c1, c)
        out[i, 0], out[i, 1], out[i, 2], out[i, 3] = r0, r1 + 1, c0, c1 + 1
    return out


# --- stop 49, regspeed49: the surface's noise medians by a selection without branches ---------------------------------


@_njit
def select_lomuto(x: np.ndarray, kth: int) -> None:
    """:func:`select`'s contract (``x`` (n,), no NaN, reordered in place so that ``x[kth]`` is its ``kth`` smallest
    value, none larger before it and none smaller after) by partitions without branches: each pass swaps every value
    in turn to the end of the run below the pivot (a median of three) and moves that end on by the comparison's
    outcome (Lomuto's scheme, its test a number added, not a jump the processor mispredicts half the time on noise).
    Where no value lies below the pivot, a second pass gathers the values equal to it, so that many equal values (a
    depth camera's whole units) end the search. Which value lies at ``kth`` does not depend on the method, so
    :func:`median_lomuto`'s median is :func:`_median_of`'s bit for bit (stop 49: the benchmark frame's 18
    :func:`depth_noise` calls 0.8 -> 0.4 ms)."""
    lo, hi = 0, x.shape[0] - 1
    while hi > lo:
        b = _pivot(x, lo, hi)
        i = lo  # the values below the pivot b to x[lo:i]
        for j in range(lo, hi + 1):
            v = x[j]
            x[j] = x[i]
            x[i] = v
            i += v < b
        if kth < i:
            hi = i - 1
            continue
        if i > lo:
            lo = i
            continue
        e = lo  # none below b: the values equal to it (b among them) to x[lo:e]
        for j in range(lo, hi + 1):
            v = x[j]
            x[j] = x[e]
            x[e] = v
            e += v <= b
        if kth < e:
            return
        lo = e


@_njit
def median_lomuto(x: np.ndarray) -> float:
    """:func:`_median_of` (``x`` (n,), n >= 1, no NaN, reordered) by :func:`select_lomuto`: the same value."""
    h = x.shape[0] // 2
    select_lomuto(x, h)
    return _selected_median(x, h)


@_njit
def deviation_median(x: np.ndarray) -> float:
    """``median(abs(x - median(x)))`` of ``x`` (n,) (n >= 1, no NaN; reordered and overwritten) as :func:`depth_noise`
    and :func:`median_deviation` take it, by :func:`median_lomuto`: the same value. With an infinity among the values
    (whose deviation from an infinite median is NaN, and :func:`_median_of`'s value among NaN depends on how it left
    the values) by :func:`_median_of` both times, as before."""
    n = x.shape[0]
    finite = True
    for i in range(n):
        finite &= np.isfinite(x[i])
    middle = median_lomuto(x) if finite else _median_of(x)
    for i in range(n):
        x[i] = abs(x[i] - middle)
    return median_lomuto(x) if finite else _median_of(x)


@_njit
def finite_positive(values: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """:func:`symfruit.core.surface.fruit_depth`'s valid depths: ``ok`` (n,) bool written, whether each of ``values``
    (n,) float64 is finite and above 0, and those values in their order (``values[ok]``, numpy's
    ``np.isfinite(values) & (values > 0)``: the same pixels and values) in two passes instead of four numpy ones."""
    n = values.shape[0]
    m = 0
    for i in range(n):
        v = values[i]
        good = np.isfinite(v) and v > 0
        ok[i] = good
        m += good
    kept = np.empty(m)
    j = 0
    for i in range(n):
        if ok[i]:
            kept[j] = values[i]
            j += 1
    return kept


# --- stop 49, treeseg49: the bridged skin's trim ---------------------------------------------------------------------


@_njit
def bridged_trim(skin: np.ndarray, z: np.ndarray, part: np.ndarray, r0: int, c0: int) -> tuple[np.ndarray, bool]:
    """:func:`symfruit.segment.colour._bridged_skin`'s trim of a skin grown over bridged depth: ``skin`` (h, w) bool
    less its pixels without depth (``z`` (h, w) float64, 0: none) outside the convex hull of its pixels with depth
    and of ``part`` (ph, pw) bool at ``(r0, c0)`` (:func:`hull_vertices`, then :func:`polygon_fill` as Pillow fills
    it), and whether that was worked out: False when a hull vertex is not a whole number (never: the twin draws
    it). When every skin pixel has depth no hull is drawn: the skin is returned as it is, the twin's pixels."""
    h, w = skin.shape
    core = np.empty((h, w), np.bool_)
    gap = False
    for r in range(h):
        for c in range(w):
            seen = z[r, c] > 0
            core[r, c] = skin[r, c] and seen
            gap |= skin[r, c] and not seen
    if not gap:
        return skin, True
    for r in range(part.shape[0]):
        for c in range(part.shape[1]):
            if part[r, c]:
                core[r0 + r, c0 + c] = True
    v = hull_vertices(core)
    if len(v) == 0:
        hull = core
    else:
        hull = polygon_fill(v, core)
        if hull.shape != core.shape:
            return skin, False
    out = np.empty((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            out[r, c] = skin[r, c] and (z[r, c] > 0 or hull[r, c])
    return out, True


# --- stop 49, seg640_49: the colour segmenter's found pieces at 640x480 in fewer calls --------------------------------


@_njit
def piece_ripe(color: np.ndarray, part: np.ndarray, weak: np.ndarray, least: np.float32) -> bool:
    """:func:`symfruit.segment.colour._segment_at`'s ripe test of a piece: :func:`red_ripe` of its red pixels ``part &
    weak`` ((h, w) bool each) in ``color`` (h, w, >= 3) uint8 (False without one: the twin's ``red.any()``), without
    the red mask made and tested in numpy first: the same answer (stop 49)."""
    h, w = part.shape
    red = np.empty((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            red[r, c] = part[r, c] and weak[r, c]
    return red_ripe(color, red, least)


@_njit
def median_quick(values: np.ndarray) -> float:
    """:func:`median_values` of ``values`` (n,) float64 (left as they are) by :func:`median_of_quick`: NaN when a value
    is NaN or there is none. The same value (stop 49)."""
    return np.nan if _empty_or_nan(values) else median_of_quick(values)


@_njit
def median_of_quick(values: np.ndarray) -> float:
    """:func:`_median_of` of ``values`` (n >= 1, no NaN; left as they are) by :func:`kth_smallest`, the quickselect
    without branches, instead of :func:`select` (whose comparisons, going either way at random, cost most of its time):
    the middle value, or the mean of the middle two halved as the twin halves it; of an even count the lower middle
    value is the largest value below the upper one when that many lie below it, else the upper one itself (a tie).
    Order statistics, so the same value (stop 49)."""
    n = values.shape[0]
    half = n // 2
    upper = kth_smallest(values, half, np.empty(n), np.empty(n))
    if n % 2:
        return upper
    below = upper
    less = 0
    for i in range(n):
        v = values[i]
        if v < upper:
            less += 1
            if less == 1 or v > below:
                below = v
    if less < half:  # the place below the middle holds a value equal to it
        below = upper
    return (below + upper) / 2.0


@_njit
def piece_hull(
    vertices: np.ndarray, part: np.ndarray, weak: np.ndarray, owner: np.ndarray, k: int, color: np.ndarray,
    surface: bool, z: np.ndarray, jump: float,
) -> tuple[np.ndarray, int, int, float]:  # fmt: skip
    """A ripe piece's hull and what its size test reads, in one call (:func:`symfruit.segment.colour._segment_at` with
    depth and without the round fruit's skin): :func:`surface_hull` of the piece's ``part`` (h, w) bool, then
    :func:`depth_consistent` of it against the piece's red pixels (``part & weak``) and the depths ``z`` (h, w)
    float64, then :func:`masked_median` of the hull: the hull (h, w) bool, its pixel count, how many of them have
    depth and their median depth. The twin's calls in one, the same values; a (0, 0) hull where
    :func:`surface_hull` gives one (a vertex not a whole number: the twin then fills by Pillow). The medians by
    :func:`median_quick`; where no pixel of the hull but its red ones has depth (the hull holds them all), the hull's
    median depth is the red pixels' own, not taken again (stop 49)."""
    hull = surface_hull(vertices, part, owner, k, color, surface)
    h, w = part.shape
    if hull.shape[0] != h or hull.shape[1] != w:
        return hull, 0, 0, np.nan
    n = 0
    for r in range(h):
        for c in range(w):
            n += part[r, c] and weak[r, c] and z[r, c] > 0
    if n > 0:  # depth_consistent against the red pixels' median depth (none with depth: the hull as it is)
        values = np.empty(n, np.float64)
        j = 0
        for r in range(h):
            for c in range(w):
                if part[r, c] and weak[r, c] and z[r, c] > 0:
                    values[j] = z[r, c]
                    j += 1
        zm = median_quick(values)
        area = 0
        other = 0  # the hull's pixels with depth that are not red
        for r in range(h):
            for c in range(w):
                d = z[r, c]
                red = part[r, c] and weak[r, c]
                keep = red or (hull[r, c] and not (d > 0 and abs(d - zm) > jump))
                hull[r, c] = keep
                area += keep
                other += keep and not red and d > 0
        if other == 0:  # the hull's pixels with depth are the red ones: their median
            return hull, area, n, zm
    area, depths = masked_depths(hull, z)
    return hull, area, depths.shape[0], median_quick(depths)


# --- stop 50, speed50: the backdrop's ring in one call ---------------------------------------------------------------


@_njit
def backdrop_counts(
    mask: np.ndarray, depth: np.ndarray, a0: int, a1: int, b0: int, b1: int, step: int, grow: int, z: float, r: float
) -> tuple[int, int, int, int]:  # fmt: skip
    """:func:`symfruit.extract.backdrop`'s counts in one call: ``(around, count, behind, level)`` over the ring of the
    sampled window ``mask[a0:a1:step, b0:b1:step]`` (``mask`` and ``depth`` the (h, w) image, read in place): the
    pixels with a mask pixel within ``grow`` of them (the ``2 grow + 1`` square, :func:`square_filter`'s) but none
    within 1. ``around`` the ring's pixels, ``count`` those whose depth (as float64) is finite and above 0, ``behind``
    of those the ones deeper than ``z + r``, ``level`` the ones with ``|depth - z| <= r``: the twin's boolean index and
    its counts (whole numbers, in any order the same), its float64 sum and comparisons."""
    rows = (a1 - a0 + step - 1) // step
    cols = (b1 - b0 + step - 1) // step
    m = np.empty((rows, cols), np.bool_)
    for i in range(rows):
        for j in range(cols):
            m[i, j] = mask[a0 + i * step, b0 + j * step]
    wide = np.empty((rows, cols), np.bool_)
    near = np.empty((rows, cols), np.bool_)
    _square_any(m, grow, True, wide)
    _square_any(m, 1, True, near)
    zr = z + r
    around = count = behind = level = 0
    for i in range(rows):
        for j in range(cols):
            if wide[i, j] and not near[i, j]:
                around += 1
                y = np.float64(depth[a0 + i * step, b0 + j * step])
                if math.isfinite(y) and y > 0.0:
                    count += 1
                    behind += y > zr
                    level += abs(y - z) <= r
    return around, count, behind, level


# --- stop 50, outline50: the registration's per-fruit outline in fewer calls ----------------------------------------


@_njit
def outline_windows(
    mask: np.ndarray, reach: int, grown: np.ndarray, inner: np.ndarray, inside: np.ndarray
) -> tuple[bool, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.core.surface._outline`'s maps of a mask (h, w) bool holding pixels of both kinds, in one call:
    ``grown`` (h, w) bool the pixels within ``reach`` taxicab steps of the mask (:func:`taxicab_within`) and
    :func:`outline_maps` of pad and reach ``reach`` (``inner`` and ``inside`` written in place, its keys and ranks
    returned): the same pixels and numbers.

    Since issue 19's stop 60 (speedr60) in fewer passes than the two kernels one after the other:
    - the column pass of :func:`outline_maps` (each pixel's distance along its column to the nearest pixel of the
      other kind) serves the taxicab window too: a pixel's taxicab distance to the mask is the least over the
      columns of the column gap plus the column distance (0 on the mask), two sweeps along each row (whole
      numbers, exact: the same pixels as the chamfer's two sweeps over the image);
    - the outside pixels' envelope of a row takes, of each run of mask pixels, its two ends alone (the nearest mask
      pixel of the row to an outside pixel ends a run) and no column without a mask pixel (farther than any); it is
      read off segment by segment straight into the keys over the whole row (the mask's pixels get other values
      there), then the mask pixels' envelope, read off alike, puts their keys over them. Every value an outside or
      a mask pixel keeps is the least over the parabolas that can be least, so the same whole number, and the
      largest and least keys are taken over the same pixels;
    - the rest as :func:`outline_maps`."""
    pad = reach
    h, w = mask.shape
    big = h + w
    g = np.empty((h, w), np.int64)
    for c in range(w):
        g[0, c] = big
    for r in range(1, h):
        for c in range(w):
            g[r, c] = g[r - 1, c] + 1 if mask[r, c] == mask[r - 1, c] else 1
    firsts, lasts, n_ins = np.empty(h, np.int64), np.empty(h, np.int64), np.empty(h, np.int64)
    lo_c, hi_c = w, -1  # the mask's first and last column: the outside pixels' only sites (stop 46)
    for r in range(h):
        first, last, n_in = w, -1, 0
        for c in range(w):
            if mask[r, c]:
                first, last, n_in = min(first, c), c, n_in + 1
        firsts[r], lasts[r], n_ins[r] = first, last, n_in
        lo_c, hi_c = min(lo_c, first), max(hi_c, last)
    for r in range(h - 2, -1, -1):
        for c in range(w):
            if mask[r, c] != mask[r + 1, c]:
                g[r, c] = 1
            elif g[r + 1, c] + 1 < g[r, c]:
                g[r, c] = g[r + 1, c] + 1
    key = np.empty((h, w), np.int64)
    f = np.empty(w, np.int64)
    s = np.empty(w, np.int64)
    t = np.empty(w, np.int64)
    row = np.empty(w, np.int64)
    sites = np.empty(w, np.int64)
    floor = -(reach * reach)
    top = reach * reach
    low, high = (floor, floor) if pad > 0 else (np.int64(2**62), -np.int64(2**62))
    for r in range(h):
        first, last, n_in = firsts[r], lasts[r], n_ins[r]
        # taxicab: the column distances to the mask (0 on it), then the row's two sweeps
        d = 2 * big
        for c in range(w):
            v = 0 if mask[r, c] else g[r, c]
            d = min(v, d + 1)
            row[c] = d
        d = 2 * big
        for c in range(w - 1, -1, -1):
            d = min(row[c], d + 1)
            grown[r, c] = d <= reach
        if n_in < w:  # outside: the row's outside pixels (the mask's pixels written here too, over-written below)
            n = 0
            for c in range(lo_c, hi_c + 1):
                if mask[r, c]:  # of a run of mask pixels, its ends alone
                    if c == lo_c or c == hi_c or not mask[r, c - 1] or not mask[r, c + 1]:
                        f[c] = 0
                        sites[n] = c
                        n += 1
                elif g[r, c] < big:  # a column without a mask pixel is farther than any
                    f[c] = g[r, c] * g[r, c]
                    sites[n] = c
                    n += 1
            q = _hull_of(f, sites, n, w, s, t)
            end = w
            for j in range(q, -1, -1):
                i = s[j]
                fi = f[i]
                for u in range(t[j], end):
                    a = u - i
                    key[r, u] = -(a * a + fi)
                end = t[j]
            least = 0
            for u in range(w):
                least = min(least, 0 if mask[r, u] else key[r, u])
            top, low = max(top, -least), min(low, least)
        if last >= 0:  # the mask's pixels
            a, b = max(first - 1, 0), min(last + 1, w - 1)
            for c in range(a, b + 1):
                f[c - a] = g[r, c] * g[r, c] if mask[r, c] else 0
            q = _hull(f, 0, b - a, b + 1 - a, s, t)
            end = b + 1 - a
            most = 0
            for j in range(q, -1, -1):
                i = s[j]
                fi = f[i]
                for u in range(max(t[j], first - a), min(end, last + 1 - a)):
                    e = u - i
                    k = e * e + fi
                    inside_pixel = mask[r, a + u]
                    key[r, a + u] = k if inside_pixel else key[r, a + u]
                    most = max(most, k if inside_pixel else 0)
                end = t[j]
            top, high = max(top, most), max(high, most)
    return _outline_keys(mask, key, pad, reach, top, low, high, inner, inside)


@_njit
def cap_outline(
    pixels: np.ndarray, r: int, c: int, depth: np.ndarray, far: float, reach: float, pad: int, least: int,
    tol: float = np.inf,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.core.surface._outline`'s cap and its outline in one call: the piece of ``pixels`` (h, w) bool
    holding its pixel ``(r, c)`` (which must be ``pixels``'): :func:`connected_at`'s; its outline's rows and columns
    (raster order): :func:`outline_pixels`'; and, where there are at least ``least`` of them, which are free
    (:func:`free_outline` over ``depth`` (h, w) float64 with ``far``, ``reach``, ``pad`` and ``tol``; else an empty
    array):
    the same pixels and points.

    Since issue 19's stop 60 (speedr60) the flood keeps each pixel's row and column (no division of a flat index)
    and the piece's box, and the outline is looked for within that box alone, in one pass: the cap is a few
    thousand pixels of a window of some ten thousand."""
    h, w = pixels.shape
    cap = np.zeros((h, w), np.bool_)
    cap[r, c] = True
    stack_r = np.empty(h * w, np.int64)
    stack_c = np.empty(h * w, np.int64)
    stack_r[0], stack_c[0] = r, c
    top, count = 1, 1
    rmin, rmax, cmin, cmax = r, r, c, c
    while top > 0:
        top -= 1
        pr, pc = stack_r[top], stack_c[top]
        rmin, rmax, cmin, cmax = min(rmin, pr), max(rmax, pr), min(cmin, pc), max(cmax, pc)
        for rr, cc in ((pr - 1, pc), (pr + 1, pc), (pr, pc - 1), (pr, pc + 1)):
            if 0 <= rr < h and 0 <= cc < w and pixels[rr, cc] and not cap[rr, cc]:
                cap[rr, cc] = True
                stack_r[top], stack_c[top] = rr, cc
                top += 1
                count += 1
    rows_at, cols_at = np.empty(count, np.int64), np.empty(count, np.int64)
    n = 0
    for i in range(rmin, rmax + 1):
        inner_r = 0 < i < h - 1
        for j in range(cmin, cmax + 1):
            if cap[i, j] and not (inner_r and 0 < j < w - 1 and cap[i - 1, j] and cap[i + 1, j] and cap[i, j - 1]
                                  and cap[i, j + 1]):  # fmt: skip
                rows_at[n], cols_at[n] = i, j
                n += 1
    rows, cols = rows_at[:n].copy(), cols_at[:n].copy()
    if n < least:
        return rows, cols, np.empty(0, np.bool_)
    return rows, cols, free_outline(depth, cap, rows, cols, far, reach, pad, tol)


# --- stop 50, observe50: the completion's observe in fewer calls -----------------------------------------------------


@_njit
def first_nearest_label(points: np.ndarray, labels: np.ndarray, qx: float, qy: float) -> bool:
    """The label (``labels`` (k,) bool) of the point of ``points`` (k, 2, k >= 1) nearest ``(qx, qy)``, the first in
    ``points``' order among those equally near: :func:`symfruit.core.agreement._first_nearest` of one query, its
    squared distances (``dx * dx + dy * dy``, the query less the point) and ``np.argmin``'s pick (the first least;
    a NaN distance is taken as least, the first of them). Issue 19, stop 65 (look65): the ties of labels that
    :func:`observe_bands` and :func:`outline_bands` left to their caller are resolved in the call."""
    best = np.inf
    at = -1
    for j in range(points.shape[0]):
        dx = qx - points[j, 0]
        dy = qy - points[j, 1]
        d = dx * dx + dy * dy
        if d != d:  # argmin's first NaN
            at = j
            break
        if at < 0 or d < best:
            best, at = d, j
    return labels[at] if at >= 0 else False


@_njit
def observe_maps(mask: np.ndarray, inner_reach: float, outer_reach: float) -> tuple[bool, np.ndarray, np.ndarray]:
    """:func:`symfruit.core.agreement.observe`'s two distance maps of ``mask`` (h, w) bool in one call: ``(done,
    inner, outer)``, ``inner`` :func:`symfruit.core.raster.inner_distance` with ``reach`` ``inner_reach`` and
    ``outer`` :func:`symfruit.core.raster.outer_distance` with ``reach`` ``outer_reach``: the mask's box (the rows and
    columns holding a true pixel, :func:`~symfruit.core.raster.mask_box`'s), each map's part of the image (the box
    grown by 1 and by ``ceil(outer_reach) + 1``, clipped) by :func:`near_distance` in place, 0 and +inf elsewhere:
    the same pixels and values. ``done`` False (the maps unset) where those functions take another path: an empty
    mask, or a grown box holding no pixel outside the mask (the whole transform)."""
    h, w = mask.shape
    r0 = h
    r1 = -1
    c0 = w
    c1 = -1
    for r in range(h):
        first, last = _row_ends(mask, r)
        if first < 0:
            continue
        r0 = min(r0, r)
        r1 = r
        c0 = min(c0, first)
        c1 = max(c1, last)
    inner = np.zeros((h, w))
    outer = np.empty((h, w))
    if r1 < 0:
        return False, inner, outer
    r1 += 1
    c1 += 1
    a0, a1, b0, b1 = max(r0 - 1, 0), min(r1 + 1, h), max(c0 - 1, 0), min(c1 + 1, w)
    full = True
    for r in range(a0, a1):
        for c in range(b0, b1):
            if not mask[r, c]:
                full = False
                break
        if not full:
            break
    if full:
        return False, inner, outer
    near_distance(mask[a0:a1, b0:b1], inner_reach, False, inner[a0:a1, b0:b1])
    m = math.ceil(outer_reach) + 1
    outer[:] = np.inf
    a0, a1, b0, b1 = max(r0 - m, 0), min(r1 + m, h), max(c0 - m, 0), min(c1 + m, w)
    near_distance(mask[a0:a1, b0:b1], outer_reach, True, outer[a0:a1, b0:b1])
    return True, inner, outer


@_njit
def hidden_seen(
    u: np.ndarray, v: np.ndarray, hidden: np.ndarray, depth: np.ndarray, u0: int, v0: int, width: int, height: int
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """:meth:`symfruit.core.occlusion.Occlusion.seen_at` in one call: ``(hid, seen)``, ``hid`` (m,) bool
    :func:`occluded_at` of the pixels ``(u, v)`` (m,) with radius 0, ``seen`` (m,) float64 where ``hid``, the depth
    ``depth`` (h, w) (the window ``hidden``'s; (0, 0): none) holds at the pixel (rounded half to even, as
    ``occluded_at``; NaN off the window), NaN elsewhere: the twin's values (the depth's value as float64)."""
    hid = occluded_at(u, v, hidden, u0, v0, width, height, 0)
    n = u.shape[0]
    h, w = depth.shape
    seen = np.empty(n)
    big = 9.223372036854775808e18  # 2^63
    least = np.int64(-9223372036854775808)
    for i in range(n):
        seen[i] = np.nan
        if hid[i]:
            fu, fv = np.rint(u[i]), np.rint(v[i])
            col = (np.int64(fu) if -big <= fu < big else least) - np.int64(u0)
            row = (np.int64(fv) if -big <= fv < big else least) - np.int64(v0)
            if 0 <= col < w and 0 <= row < h:
                seen[i] = np.float64(depth[row, col])
    return hid, seen


# ---- bands51 (issue 19, stop 51): core.agreement.observe's bands, both sides, in one call ----


@_njit
def observe_bands(
    rays: np.ndarray, inner: np.ndarray, outer: np.ndarray, bands: np.ndarray, n_band: int, u0: int, v0: int,
    fx: float, fy: float, cx: float, cy: float, edge_uv: np.ndarray, labels: np.ndarray, occluded: bool,
    hidden: np.ndarray, depth: np.ndarray, h_u0: int, h_v0: int, width: int, height: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
           np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.core.agreement._observed_bands`: the inside bands' (``inner``) and outside bands' (``outer``)
    :func:`band_rays`, the outside pixels' :func:`hidden_seen` (``occluded``: ``hidden``, ``depth`` at ``h_u0,
    h_v0``) and :func:`nearest_labels` of the edge points (``edge_uv`` (k, 2), ``labels`` (k,); none: every label
    true), packed as :func:`symfruit.core.agreement._bands_of_parts` packs them. Returns ``(every (n + a + b, 3):
    rays then both sides' band rays, uv (b, 2) the outside pixels, in_sizes, in_starts, out_sizes, out_starts,
    unsure (b,) bool: all false (since stop 65 a tie of labels between equally near edge points is resolved here,
    as the caller did: :func:`first_nearest_label`; a hidden pixel's label is not read), weight (b,): 1.0 where the
    label is true and the pixel not hidden, else 0.0, seen (b,): the depth seen where hidden (NaN elsewhere), finite
    (b,) bool, wsum (k,): each outside band's sum of 1.0 where finite else the weight)``: the same values as the pieces
    called one by one (the sums are of whole numbers, exact in any order)."""
    return _observe_bands(rays, inner, outer, bands, n_band, u0, v0, fx, fy, cx, cy, edge_uv, labels, occluded,
                          hidden, depth, h_u0, h_v0, width, height, False)  # fmt: skip


@_njit
def _observe_bands(
    rays: np.ndarray, inner: np.ndarray, outer: np.ndarray, bands: np.ndarray, n_band: int, u0: int, v0: int,
    fx: float, fy: float, cx: float, cy: float, edge_uv: np.ndarray, labels: np.ndarray, occluded: bool,
    hidden: np.ndarray, depth: np.ndarray, h_u0: int, h_v0: int, width: int, height: int, rows: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
           np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`observe_bands`; ``rows``: the edge points are in row order (:func:`outline_uv`'s, from
    :func:`outline_bands`), their labels looked up by :func:`nearest_labels_rows` (stop 61: the same labels where
    sure, the same ``unsure``)."""
    _, rays_in, in_sizes = band_rays(inner, bands, n_band, u0, v0, fx, fy, cx, cy)
    uv, rays_out, out_sizes = band_rays(outer, bands, n_band, u0, v0, fx, fy, cx, cy)
    n, a, b = rays.shape[0], rays_in.shape[0], rays_out.shape[0]
    every = np.empty((n + a + b, 3))
    every[:n] = rays
    every[n : n + a] = rays_in
    every[n + a :] = rays_out
    k = in_sizes.shape[0]
    in_starts = np.zeros(k, np.int64)
    out_starts = np.zeros(k, np.int64)
    for i in range(1, k):
        in_starts[i] = in_starts[i - 1] + in_sizes[i - 1]
        out_starts[i] = out_starts[i - 1] + out_sizes[i - 1]
    if labels.shape[0] and b:
        found, unsure = nearest_labels_rows(edge_uv, labels, uv) if rows else nearest_labels(edge_uv, labels, uv)
    else:
        found, unsure = np.ones(b, np.bool_), np.zeros(b, np.bool_)
    if occluded and b:
        hid, seen = hidden_seen(uv[:, 0].copy(), uv[:, 1].copy(), hidden, depth, h_u0, h_v0, width, height)
    else:
        hid, seen = np.zeros(b, np.bool_), np.full(b, np.nan)
    weight = np.empty(b)
    finite = np.empty(b, np.bool_)
    for i in range(b):
        if unsure[i] and not hid[i]:  # a tie of labels: the first nearest edge point's (stop 65, look65)
            found[i] = first_nearest_label(edge_uv, labels, uv[i, 0], uv[i, 1])
        unsure[i] = False
        weight[i] = 1.0 if found[i] and not hid[i] else 0.0
        finite[i] = occluded and np.isfinite(seen[i])
    wsum = np.zeros(k)
    for j in range(k):
        for i in range(out_starts[j], out_starts[j] + out_sizes[j]):
            wsum[j] += 1.0 if finite[i] else weight[i]
    return every, uv, in_sizes, in_starts, out_sizes, out_starts, unsure, weight, seen, finite, wsum


@_njit
def outline_bands(
    mask: np.ndarray, count: int, radius: int, base: bool, cracks: np.ndarray, share: float, rays: np.ndarray,
    inner: np.ndarray, outer: np.ndarray, bands: np.ndarray, n_band: int, u0: int, v0: int, fx: float, fy: float,
    cx: float, cy: float, hidden: np.ndarray, depth: np.ndarray, h_u0: int, h_v0: int, width: int, height: int,
) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
           np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray], bool, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.core.agreement._outline_bands`: with occlusion information and every edge normal's label
    ``base`` (none: true), ``observe``'s edge labels, bands and the outline cracks' labels in one call. The edge
    points are :func:`outline_uv`'s (``count``) labelled ``base`` where no hidden pixel lies within ``radius``
    (:func:`occluded_at`; ``_occluded_edges``); then :func:`observe_bands` of them; then, where ``share`` is at most
    the share of true labels and that share is below 1, :func:`nearest_labels_rows` of ``cracks`` (k, 2). Returns ``(uv,
    labels, observe_bands' tuple, took, found, unsure)`` (``found``, ``unsure`` empty where not ``took``; the cracks'
    ties resolved as the bands' by :func:`first_nearest_label`, ``unsure`` all false): the
    pieces' values."""
    edge = outline_uv(mask, count, u0, v0)
    m = edge.shape[0]
    occ = occluded_at(edge[:, 0].copy(), edge[:, 1].copy(), hidden, h_u0, h_v0, width, height, radius)
    labels = np.empty(m, np.bool_)
    n_true = 0
    for i in range(m):
        labels[i] = base and not occ[i]
        n_true += labels[i]
    # the edge points are outline_uv's, in row order: their labels by rows (nearest_labels_rows; stop 61, speedb61)
    made = _observe_bands(rays, inner, outer, bands, n_band, u0, v0, fx, fy, cx, cy, edge, labels, True, hidden,
                          depth, h_u0, h_v0, width, height, True)  # fmt: skip
    took = m > 0 and share <= n_true / m < 1.0
    if took:
        found, unsure = nearest_labels_rows(edge, labels, cracks)
        for j in range(found.shape[0]):  # a tie of labels: the first nearest edge point's (stop 65, look65)
            if unsure[j]:
                found[j] = first_nearest_label(edge, labels, cracks[j, 0], cracks[j, 1])
                unsure[j] = False
    else:
        found, unsure = np.zeros(0, np.bool_), np.zeros(0, np.bool_)
    return edge, labels, made, took, found, unsure


@_njit
def observe_edges(
    mask: np.ndarray, reach: float, out_reach: float, points: np.ndarray, dense: np.ndarray, col: np.ndarray,
    row: np.ndarray, given: int, fx: float, fy: float, cx: float, cy: float, u0: int, v0: int, count: int, half: int,
) -> tuple[bool, np.ndarray, np.ndarray, np.ndarray, np.ndarray, bool, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.core.agreement._observed_edges`: ``observe``'s first steps in one call, each the kernel it called
    before: :func:`observe_maps` of ``mask`` (a window at ``u0, v0``); :func:`inside_px` of ``points`` in the inside
    map; that of ``dense`` (``given`` 0: none, the points' own; 1: projected; 2: at its pixels ``col``, ``row``,
    :func:`inside_px_of`); and where the edge cloud has about a point per pixel (at least half as many points as
    ``mask`` pixels), :func:`contour_pixels` of it. ``(done, inner, outer, depth_px, edge_px, grid, uv, contour)``:
    ``done`` False where ``observe_maps`` declines (nothing else made), ``grid`` False where the cloud is sparser
    (``uv``, ``contour`` empty)."""
    done, inner, outer = observe_maps(mask, reach, out_reach)
    none2, none1 = np.empty((0, 2)), np.empty(0, np.bool_)
    if not done:
        return False, inner, outer, np.empty(0), np.empty(0), False, none2, none1
    depth_px = inside_px(points, fx, fy, cx, cy, u0, v0, inner)
    edge = points if given == 0 else dense
    if given == 0:
        edge_px = depth_px
    elif given == 1:
        edge_px = inside_px(dense, fx, fy, cx, cy, u0, v0, inner)
    else:
        edge_px = inside_px_of(col, row, u0, v0, inner)
    filled = 0
    for r in range(mask.shape[0]):
        for c in range(mask.shape[1]):
            filled += mask[r, c]
    grid = edge.shape[0] >= 0.5 * filled
    if not grid:
        return True, inner, outer, depth_px, edge_px, False, none2, none1
    h, w = mask.shape
    uv, contour = contour_pixels(edge, edge_px, fx, fy, cx, cy, u0, v0, h, w, count, half)
    return True, inner, outer, depth_px, edge_px, True, uv, contour


# --- stop 51, seg51: the colour segmenter's speed (issue 19) ----------------------------------------------------------


@_njit
def largest_surface(part: np.ndarray, depth: np.ndarray, jump: float) -> np.ndarray:
    """:func:`symfruit.segment.colour._largest_surface`: of the pixels of ``part`` (h, w) bool with depth (``depth``
    (h, w) float64 above 0), those on no depth step (a 4-neighbour with depth more than ``jump`` off, the twin's
    ``_steps`` of the depth with NaN where there is none), their largest 4-connected piece (:func:`label`'s numbers,
    the first of equal sizes, as ``argmax``); a (0, 0) array with fewer than 20 pixels with depth or no piece. The
    twin's pixels in one call, not a dozen numpy passes over the window."""
    h, w = part.shape
    seen = np.empty((h, w), np.bool_)
    count = 0
    for r in range(h):
        for c in range(w):
            seen[r, c] = part[r, c] and depth[r, c] > 0
            count += 1 if seen[r, c] else 0
    if count < 20:
        return np.zeros((0, 0), np.bool_)
    flat = np.empty((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            ok = seen[r, c]
            if ok:
                z = depth[r, c]
                if (r > 0 and seen[r - 1, c] and abs(z - depth[r - 1, c]) > jump) or (
                    r + 1 < h and seen[r + 1, c] and abs(depth[r + 1, c] - z) > jump) or (
                    c > 0 and seen[r, c - 1] and abs(z - depth[r, c - 1]) > jump) or (
                    c + 1 < w and seen[r, c + 1] and abs(depth[r, c + 1] - z) > jump):  # fmt: skip
                    ok = False
            flat[r, c] = ok
    lab, n = label(flat, False)
    if n == 0:
        return np.zeros((0, 0), np.bool_)
    sizes = np.zeros(n + 1, np.int64)
    for r in range(h):
        for c in range(w):
            sizes[lab[r, c]] += 1
    best = 1
    for k in range(2, n + 1):
        if sizes[k] > sizes[best]:
            best = k
    out = np.empty((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            out[r, c] = lab[r, c] == best
    return out


@_njit
def label_flat(mask: np.ndarray, eight: bool) -> tuple[np.ndarray, int, np.ndarray, np.ndarray]:
    """:func:`symfruit.segment.colour._labelled`: :func:`label` of ``mask`` (h, w) bool (``eight``: with eight
    neighbours), its number of labels, and the labelled pixels' flat indices (ascending, int64) and labels (int32):
    ``np.flatnonzero`` of the labels and their values there, the twin's arrays, in one pass over the labels instead
    of three numpy passes."""
    out, n = label(mask, eight)
    flat = out.reshape(-1)
    k = 0
    for i in range(flat.shape[0]):
        k += 1 if flat[i] != 0 else 0
    pixels = np.empty(k, np.int64)
    labels = np.empty(k, np.int32)
    k = 0
    for i in range(flat.shape[0]):
        if flat[i] != 0:
            pixels[k] = i
            labels[k] = flat[i]
            k += 1
    return out, n, pixels, labels


@_njit
def widest_pair(vertices: np.ndarray) -> float:
    """:func:`symfruit.segment.colour._extent`'s largest squared distance between two of the ``vertices`` (m, 2)
    float64 (m >= 1): each pair's differences squared and summed as the twin's ``(d * d).sum(axis=2)`` sums its two
    terms, the largest of them; the same value without the (m, m, 2) arrays (a round fruit's merge asks for some 36
    extents a tree frame)."""
    m = vertices.shape[0]
    best = -np.inf
    for i in range(m):
        x, y = vertices[i, 0], vertices[i, 1]
        for j in range(m):
            dx, dy = x - vertices[j, 0], y - vertices[j, 1]
            best = max(best, dx * dx + dy * dy)
    return best


# --- stop 51, surface51: thin_front's passes in one call -------------------------------------------------------------

#: :func:`thin_passes`' answers: the test ends, None (``THIN_NONE``); the front pixels want the curvature fit
#: (``THIN_FIT``); the first partition, then the one of the 5 x 5 median, wants the rest of ``_behind_sheet``
#: (``THIN_SHEET``, ``THIN_SMOOTHED``).
THIN_NONE, THIN_FIT, THIN_SHEET, THIN_SMOOTHED = 0, 1, 2, 3


@_njit_inlined
def _sheet_sizes(
    labels: np.ndarray, count: int, depth: np.ndarray, front: float, join: float
) -> tuple[bool, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.core.surface._behind_sheet`'s tests before its fits on the partition ``labels`` (0 none,
    1..``count``): whether they pass (False where it returns None: fewer than two parts, no part near ``front``, the
    sheet (the first part holding the most pixels near it, ``np.argmax``'s) under 30 pixels, no other part holding
    ``max(30, 0.1 n_sheet)``), and :func:`part_sizes`' counts. Whole numbers: the same answer."""
    if count < 2:
        return False, np.zeros(0, np.int64), np.zeros(0, np.int64)
    sizes, near = part_sizes(labels, count, depth, front, join)
    sheet = 0
    best = 0
    for k in range(1, count + 1):
        if near[k] > best:
            sheet, best = k, near[k]
    if sheet == 0:
        return False, sizes, near
    n_sheet = sizes[sheet]
    if n_sheet < 30:
        return False, sizes, near
    largest = 0
    for k in range(1, count + 1):
        if k != sheet and sizes[k] > largest:
            largest = sizes[k]
    return not (largest < 30 or largest < 0.1 * n_sheet), sizes, near


@_njit
def thin_passes(
    depth: np.ndarray,
    mask: np.ndarray,
    front: float,
    join: float,
    noise: float,
    stage: int,
    ok: np.ndarray,
    counts: np.ndarray,
    labels: np.ndarray,
) -> tuple[int, np.ndarray, np.ndarray, int, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`symfruit.core.surface.thin_front`'s passes between its fits in one call, each the kernel it called (the
    same pixels, parts and numbers): ``(answer, rows, cols, count, sizes, near)``, ``answer`` one of ``THIN_*``.

    ``stage`` 0 from the start: :func:`thin_counts` (``ok`` (h, w) bool and ``counts`` (5,) int64 written in place,
    the front pixels ``rows, cols`` returned) and, with at least 30 front pixels, :func:`reaches_outline`; where they
    do not reach the mask's outline, ``THIN_FIT`` (the caller fits them and comes back with stage 1). Stage 1:
    :func:`smooth_parts` of ``depth`` joined at ``join`` into ``labels`` (h, w) int32 and :func:`_sheet_sizes`;
    passed, ``THIN_SHEET`` with ``count``, ``sizes`` and ``near`` (the caller's ``_behind_sheet`` goes on; stage 2
    when it finds nothing). Stage 2: with three ``noise`` deviations above 3 mm and at least 60 pixels with depth,
    the 5 x 5 median (:func:`window_medians`), its lagged differences (:func:`lag_differences`, at least 20), their
    deviation (:func:`median_deviation`), the narrower join ``min(join, max(3 sigma, 0.003))`` and, narrower than
    ``join``, the parts of the median joined at it with :func:`_sheet_sizes`: ``THIN_SMOOTHED`` where it passes.
    ``THIN_NONE`` wherever ``thin_front`` returns None (stop 51)."""
    none = np.zeros(0, np.int64)
    if stage == 0:
        found, rows, cols = thin_counts(depth, mask, front, join, ok)
        counts[:] = found
        if rows.shape[0] >= 30 and not reaches_outline(mask, rows, cols):
            return THIN_FIT, rows, cols, 0, none, none
        stage = 1
    if stage == 1:
        count = smooth_parts(depth, mask, join, labels)
        passed, sizes, near = _sheet_sizes(labels, count, depth, front, join)
        if passed:
            return THIN_SHEET, none, none, count, sizes, near
    if 3.0 * noise <= 0.003 or counts[0] < 60:
        return THIN_NONE, none, none, 0, none, none
    medians = np.empty(counts[0])
    window_medians(depth, ok, medians)
    smooth = np.empty(depth.shape)
    diff = lag_differences(medians, ok, mask, 5, smooth)
    if diff.shape[0] < 20:
        return THIN_NONE, none, none, 0, none, none
    sigma = 1.4826 * median_deviation(diff) / math.sqrt(2.0)
    wide = 3.0 * sigma
    if 0.003 > wide:
        wide = 0.003
    if not wide < join:
        return THIN_NONE, none, none, 0, none, none
    count = smooth_parts(smooth, mask, wide, labels)
    passed, sizes, near = _sheet_sizes(labels, count, depth, front, join)
    if passed:
        return THIN_SMOOTHED, none, none, count, sizes, near
    return THIN_NONE, none, none, 0, none, none


@_njit
def thin_curvature(
    rows: np.ndarray, cols: np.ndarray, depth: np.ndarray, focal: float
) -> tuple[bool, float, float, float]:
    """:func:`symfruit.core.surface._mean_curvature` of the pixels ``rows, cols`` (n,) int64 of ``depth`` (h, w)
    float64 (each above 0; at most 2,048 of them, as the twin draws them): ``(done, kappa, error, condition)``, the
    inverse depth's least-squares quadratic by its normal equations summed pixel by pixel and inverted by Gauss-Jordan
    elimination with partial pivoting (the twin's BLAS and LAPACK: the same fit, its sums in another order, so to
    rounding, not to the bit), ``condition`` the normal matrix's 1-norm condition number (the rounding's scale);
    ``done`` False where a pivot is exactly 0 (the twin's ``LinAlgError``). The median and means are the twin's
    values (:func:`median_quick`; whole-number sums; stop 62, cap62)."""
    n = rows.shape[0]
    z = np.empty(n)
    rs = 0
    cs = 0
    for i in range(n):
        z[i] = depth[rows[i], cols[i]]
        rs += rows[i]
        cs += cols[i]
    zm = median_quick(z)
    r0 = float(rs) / n
    c0 = float(cs) / n
    scale = zm / focal
    # the normal matrix's 21 sums and the right side's 6 (columns 1, x, y, x x, x y, y y)
    sx = sy = sxx = sxy = syy = 0.0
    sxxx = sxxy = sxyy = syyy = 0.0
    sxxxx = sxxxy = sxxyy = sxyyy = syyyy = 0.0
    b0 = b1 = b2 = b3 = b4 = b5 = 0.0
    for i in range(n):
        x = (cols[i] - c0) * scale
        y = (rows[i] - r0) * scale
        xx, xy, yy = x * x, x * y, y * y
        w = 1.0 / z[i]
        sx += x
        sy += y
        sxx += xx
        sxy += xy
        syy += yy
        sxxx += xx * x
        sxxy += xx * y
        sxyy += xy * y
        syyy += yy * y
        sxxxx += xx * xx
        sxxxy += xx * xy
        sxxyy += xx * yy
        sxyyy += xy * yy
        syyyy += yy * yy
        b0 += w
        b1 += x * w
        b2 += y * w
        b3 += xx * w
        b4 += xy * w
        b5 += yy * w
    m = np.empty((6, 6))
    m[0, 0], m[0, 1], m[0, 2], m[0, 3], m[0, 4], m[0, 5] = float(n), sx, sy, sxx, sxy, syy
    m[1, 1], m[1, 2], m[1, 3], m[1, 4], m[1, 5] = sxx, sxy, sxxx, sxxy, sxyy
    m[2, 2], m[2, 3], m[2, 4], m[2, 5] = syy, sxxy, sxyy, syyy
    m[3, 3], m[3, 4], m[3, 5] = sxxxx, sxxxy, sxxyy
    m[4, 4], m[4, 5] = sxxyy, sxyyy
    m[5, 5] = syyyy
    for j in range(6):
        for k in range(j):
            m[j, k] = m[k, j]
    norm = 0.0
    for k in range(6):
        t = 0.0
        for j in range(6):
            t += abs(m[j, k])
        norm = max(norm, t)
    inv = np.eye(6)
    for col in range(6):
        piv = col
        best = abs(m[col, col])
        for row in range(col + 1, 6):
            if abs(m[row, col]) > best:
                piv, best = row, abs(m[row, col])
        if best == 0.0:
            return False, np.nan, np.inf, np.inf
        if piv != col:
            for j in range(6):
                m[col, j], m[piv, j] = m[piv, j], m[col, j]
                inv[col, j], inv[piv, j] = inv[piv, j], inv[col, j]
        p = m[col, col]
        for j in range(6):
            m[col, j] /= p
            inv[col, j] /= p
        for row in range(6):
            f = m[row, col]
            if row != col and f != 0.0:
                for j in range(6):
                    m[row, j] -= f * m[col, j]
                    inv[row, j] -= f * inv[col, j]
    inverse_norm = 0.0
    for k in range(6):
        t = 0.0
        for j in range(6):
            t += abs(inv[j, k])
        inverse_norm = max(inverse_norm, t)
    rhs = (b0, b1, b2, b3, b4, b5)
    coef = np.zeros(6)
    for j in range(6):
        t = 0.0
        for k in range(6):
            t += inv[j, k] * rhs[k]
        coef[j] = t
    rss = 0.0
    for i in range(n):
        x = (cols[i] - c0) * scale
        y = (rows[i] - r0) * scale
        res = 1.0 / z[i] - (
            coef[0] + coef[1] * x + coef[2] * y + coef[3] * (x * x) + coef[4] * (x * y) + coef[5] * (y * y)
        )
        rss += res * res
    var = rss / max(n - 6, 1)
    kappa = -zm * zm * (coef[3] + coef[5])
    error = zm * zm * math.sqrt(max(var * (inv[3, 3] + inv[5, 5] + 2.0 * inv[3, 5]), 0.0))
    return True, kappa, error, norm * inverse_norm


# --- stop 51, surface51: fruit_surface's measures of the mask's depth, and its cap, in one call each -----------------


@_njit
def mask_values(
    depth: np.ndarray, mask: np.ndarray, leafy: np.ndarray, with_leafy: bool, floor: float
) -> tuple[float, np.ndarray, np.ndarray, float]:  # fmt: skip
    """:func:`symfruit.core.surface.fruit_surface`'s measures of a mask's depth before the depth mode in one call, each
    the kernel or numpy step it took (the same numbers, bit for bit): ``(noise, kept, leaf, step)``. ``noise``:
    :func:`symfruit.core.surface.depth_noise` of ``depth`` (h, w) float64 under ``mask`` (h, w) bool with ``floor``
    (:func:`depth_noise`'s deviation); ``kept``: the mask's depths finite and above 0 in raster order
    (``depth[mask]``'s :func:`finite_positive`), ``leaf`` ``leafy`` (h, w) bool at them where ``with_leafy`` (else
    empty), as :func:`symfruit.core.surface.fruit_depth` takes them (:func:`depth_mode`'s); ``step``:
    :func:`depth_step` (stop 51)."""
    n, mad, step = _noise_step(depth, mask)
    noise = floor
    if n < 10:
        if 0.002 > noise:
            noise = 0.002
    else:
        x = 1.4826 * mad / math.sqrt(2.0)
        if x > noise:
            noise = x
    # stop 60 (speeds60): the depths kept in one pass, each pixel's value written and the count moved on by the test
    # (no jump to foresee), the arrays cut to the count: the same values in the same order
    h, w = depth.shape
    room = np.empty(h * w)
    leaf_room = np.empty(h * w if with_leafy else 0, np.bool_)
    m = 0
    for r in range(h):
        for c in range(w):
            v = np.float64(depth[r, c])
            room[m] = v
            if with_leafy:
                leaf_room[m] = leafy[r, c]
            m += mask[r, c] & np.isfinite(v) & (v > 0)
    return noise, room[:m], leaf_room[: m if with_leafy else 0], step


@_njit_inlined
def _noise_step(depth: np.ndarray, mask: np.ndarray) -> tuple[int, float, float]:
    """:func:`depth_noise`'s ``(n, deviation)`` and :func:`depth_step`'s step in one pass over the neighbours (stop 60,
    speeds60): the differences ``right - left`` of the pairs both in ``mask`` and above 0 gathered (each written, the
    count moved on by the test), the step their least non-zero magnitude (``abs`` of ``a - b`` is ``|b - a|`` to the
    bit; a NaN difference, two infinite depths, is left out as there), read before the medians reorder them: the same
    numbers as the two kernels."""
    h, w = depth.shape
    # stop 62 (surf62): the differences gathered twice in the one pass, all of them and those not 0 (the ones kept
    # where 20 or more move), with the step's least and whether one is NaN read there too, instead of three more
    # passes over them: the same differences in the same order, the same step and the same test
    diff = np.empty(max(h * (w - 1), 0))
    moving = np.empty(max(h * (w - 1), 0))
    n = 0
    moved = 0
    best = np.inf
    found = False
    nan = False
    for r in range(h):
        for c in range(w - 1):
            a, b = depth[r, c + 1], depth[r, c]
            d = a - b
            both = mask[r, c + 1] & mask[r, c] & (a > 0) & (b > 0)
            diff[n] = d
            moving[moved] = d
            n += both
            moved += both & (d != 0)
            e = abs(d)
            found |= both & (e > 0)
            best = min(best, e) if both and e > 0 else best
            nan |= both & (d != d)
    step = float(best) if found else 0.0
    x = diff[:n]
    if moved >= 20:
        n = moved
        x = moving[:n]
    if n < 10 or nan:
        return n, np.nan, step
    return n, deviation_median(x), step


@_njit
def surface_cap(
    depth: np.ndarray,
    region: np.ndarray,
    mask: np.ndarray,
    r0: int,
    c0: int,
    r1: int,
    c1: int,
    iterations: int,
    low: float,
    high: float,
    inner: np.ndarray,
    have_inner: bool,
    deep_px: float,
    table: np.ndarray,
    bins: int,
    tolerance: float,
    near: np.ndarray,
    out: np.ndarray,
) -> tuple[int, int, int]:  # fmt: skip
    """:func:`symfruit.core.surface.fruit_surface` from its slab on, in one call, each step the kernel it called (the
    same pixels): ``near`` (h, w) bool the pixels of ``region`` with ``depth`` within ``low`` .. ``high``
    (:func:`near_pixels`), the apex (:func:`surface_apex` of the mask's box ``r0:r1, c0:c1`` eroded ``iterations``
    times, 5 x 5 medians) and ``out`` (h, w) bool, all false on entry, the convex cap from the apex
    (:func:`monotone_at` with the sector ``table`` of ``bins`` sectors and ``tolerance``) or'd with the pixels of
    ``near`` deeper than ``deep_px`` in the mask's distance map ``inner`` (h, w) float64: the caller's where
    ``have_inner``, else made here as :func:`symfruit.core.raster.inner_distance` with reach ``max(deep_px, 0)``
    makes it (:func:`near_distance` over the mask's box, ``r0:r1, c0:c1``, grown by a pixel; ``inner`` all 0 on
    entry). ``(answer, row, column)``, ``answer`` 0 where ``near`` is empty (no surface), 1 done, 2 the apex found
    but ``out`` left to the caller (the table too small for the apex's farthest pixel, or ``tolerance`` not finite:
    ``monotone_region``'s other paths), 3 as 2 with ``inner`` left to the caller too (the grown box all the mask's:
    ``inner_distance``'s other path; stop 51). Since stop 64 (ext64), where ``out`` is done here without the
    caller's map, the pixels deeper than ``deep_px`` are told by :func:`deep_pixels` (the same pixels) and ``inner``
    is left as it came; it is made only for answer 2."""
    if not near_pixels(depth, region, low, high, near):
        return 0, 0, 0
    r, c = surface_apex(mask[r0:r1, c0:c1], iterations, near, depth, mask, r0, c0, 5)
    h, w = near.shape
    a0, a1, b0, b1 = max(r0 - 1, 0), min(r1 + 1, h), max(c0 - 1, 0), min(c1 + 1, w)
    if not have_inner:
        full = True
        for i in range(a0, a1):
            for j in range(b0, b1):
                full &= mask[i, j]
        if full:
            return 3, r, c
    reach = max(max(abs(r), abs(h - 1 - r)), max(abs(c), abs(w - 1 - c)))
    half = (table.shape[0] - 1) // 2
    if not math.isfinite(tolerance) or reach > half:
        if not have_inner:
            near_distance(mask[a0:a1, b0:b1], max(deep_px, 0.0), False, inner[a0:a1, b0:b1])
        return 2, r, c
    monotone_at(depth, near, r, c, table, half, bins, tolerance, out)
    if not have_inner and deep_px >= 0.0 and deep_px < 2.0**20:
        # stop 64 (ext64): the deep pixels told without the distance map (``inner`` left as it came)
        deep_pixels(mask, a0, a1, b0, b1, deep_px, near, out)
        return 1, r, c
    if not have_inner:
        near_distance(mask[a0:a1, b0:b1], max(deep_px, 0.0), False, inner[a0:a1, b0:b1])
    for i in range(h):
        for j in range(w):
            out[i, j] |= near[i, j] & (inner[i, j] > deep_px)  # without a jump (stop 60, speeds60): the same pixels
    return 1, r, c


@_njit
def deep_pixels(
    mask: np.ndarray, a0: int, a1: int, b0: int, b1: int, deep_px: float, near: np.ndarray, out: np.ndarray
) -> None:  # fmt: skip
    """``out |= near & (inner > deep_px)`` over the box ``a0:a1, b0:b1`` of ``mask`` (h, w) bool, ``inner`` its
    :func:`near_distance` to the pixels not ``mask``'s within the box (reach ``deep_px``, ``0 <= deep_px < 2^20``;
    beyond the box ``inner`` is 0, never deeper), without the map (stop 64, ext64: :func:`surface_cap`'s last step).

    ``inner > deep_px`` fails exactly where the least squared distance ``b`` (a whole number) has ``b <= deep_px^2``
    (the float product, ``near_distance``'s limit) and ``sqrt(b) <= deep_px``: both hold for every whole number up to
    some ``top`` and for none above it (each test keeps the order of ``b``; ``floor(deep_px)^2`` passes both), so a
    pixel is deep exactly where no pixel not the mask's lies within a squared distance ``top``. That is looked for
    as ``near_distance`` does (the columns' distances to such a pixel, capped past ``floor(deep_px)``; within a row,
    the columns in reach, nearest first, a capped run passed over to its ends), but only at the pixels of ``near``
    not yet in ``out``, stopping at the first column within ``top``: the same pixels."""
    k = math.floor(deep_px)
    cap = np.int64(k + 1)
    cap2 = cap * cap
    limit = deep_px * deep_px
    top = cap2 - 1
    while not (top <= limit and math.sqrt(float(top)) <= deep_px):
        top -= 1
    m, n = a1 - a0, b1 - b0
    # each column's distance to the nearest pixel not the mask's above and below (capped), squared
    g2 = np.empty((m, n), np.int64)
    run = np.empty(n, np.int64)
    run[:] = cap
    for r in range(m):
        for c in range(n):
            v = min(run[c] + 1, cap) if mask[a0 + r, b0 + c] else 0
            run[c] = v
            g2[r, c] = v
    run[:] = cap
    for r in range(m - 1, -1, -1):
        for c in range(n):
            v = min(run[c] + 1, cap) if mask[a0 + r, b0 + c] else 0
            run[c] = v
            x = min(g2[r, c], v)
            g2[r, c] = x * x
    for r in range(m):
        g = g2[r]
        prev = -(k + 2)  # the last column below the cap so far
        c = 0
        while c < n:
            nxt = c  # the next column below the cap at or after c
            while nxt < n and g[nxt] >= cap2:
                nxt += 1
            for q in range(c, min(nxt + 1, n)):
                i, j = a0 + r, b0 + q
                if not near[i, j] or out[i, j]:
                    continue
                if q == nxt:  # below the cap: its own column first
                    if g[q] <= top:
                        continue
                    t0 = 1
                else:  # capped: the columns below the cap nearest on either side, prev and nxt
                    dl = q - prev
                    dr = nxt - q if nxt < n else k + 2
                    if dl > k and dr > k:
                        out[i, j] = True
                        continue
                    t0 = min(dl, dr)
                hit = False
                for t in range(t0, k + 1):
                    tt = t * t
                    if tt > top:
                        break
                    if (q - t >= 0 and g[q - t] + tt <= top) or (q + t < n and g[q + t] + tt <= top):
                        hit = True
                        break
                out[i, j] = not hit
            if nxt >= n:
                break
            prev = nxt
            c = nxt + 1


@_njit
def depth_mode(
    kept: np.ndarray, radius_px: float, focal: float, noise: float, leaf: np.ndarray, with_leafy: bool,
    leafy_shares: tuple[float, float],
) -> tuple[float, float, bool]:  # fmt: skip
    """:func:`fruit_depth` of the valid depths ``kept`` (n,) float64 (no NaN) without sorting them: the same numbers,
    bit for bit. Each value of the sorted depths it reads is found without the sort: the ends as the least and
    greatest (found while the depths are copied), the median and the front's two order statistics by
    :func:`select_lomuto` (a value, or the same two halved; which value lies at a place does not depend on how it is
    selected), each edge's count below it (``np.searchsorted``'s) as the number of values whose place among the
    edges (guessed from the bin width and moved until the edges agree, the edges never falling) is at most its own,
    the depths between two edges gathered by a pass. ``(front, radius, done)`` as :func:`fruit_depth` gives them
    (stop 51; stop 52, register52: the selections without branches and one pass fewer, the same numbers)."""
    n = kept.shape[0]
    if n < 10:
        return np.nan, np.nan, True
    # the ends found while the depths are copied, the median by the selection without branches on the copy (stop 52,
    # register52: the same values; the even median's lower middle is the greatest value before the upper one)
    work = np.empty(n)
    z_first = kept[0]
    z_last = kept[0]
    for i in range(n):
        v = kept[i]
        work[i] = v
        if v < z_first:
            z_first = v
        if v > z_last:
            z_last = v
    median = median_lomuto(work)
    ok, n_bins, width, edges = _mode_edges(z_first, z_last, median, radius_px, focal, noise)
    if not ok:
        return np.nan, np.nan, False
    lo, hi = edges[0], edges[n_bins]
    # a value's place among the first n_bins edges: how many of them lie at or below it (they never fall); it lies
    # below edge k exactly where k is at least its place. Guessed from the bin width, then moved while an edge says
    # otherwise (a step or none: branches a processor foresees, where a bisection's are a coin's toss each)
    places = np.zeros(n_bins + 1, np.int64)
    top = 0
    for v in kept:
        guess = (v - lo) / width if width > 0 else 0.0
        a = int(min(max(guess, 0.0), float(n_bins)))
        while a > 0 and edges[a - 1] > v:
            a -= 1
        while a < n_bins and edges[a] <= v:
            a += 1
        places[a] += 1
        top += v <= hi
    at = np.empty(n_bins + 1, np.int64)
    run = 0
    for k in range(n_bins):
        run += places[k]
        at[k] = run
    at[n_bins] = top
    found, a_edge, b_edge = _mode_bin(at, n, np.empty(0), kept, leaf, edges, with_leafy, leafy_shares)
    if not found:
        return np.nan, np.nan, False
    # the depths from a_edge to b_edge (a_edge <= b_edge: as many as the counts below each give) gathered into the
    # median's copy in one pass, each written and kept by the comparison's outcome (stop 52: no branch to foresee)
    size = 0
    for v in kept:
        work[size] = v
        size += (v >= a_edge) & (v <= b_edge)
    if size < 1:
        return np.nan, np.nan, False
    inside = work[:size]
    if size == 1:
        front = inside[0]
    else:
        where = (size - 1) * 0.05
        below = np.int64(np.floor(where))
        t = where - below
        select_lomuto(inside, below)  # z[below] and z[below + 1] of the sorted depths: the value there, the least after
        za, zb = inside[below], inside[below + 1]
        for i in range(below + 2, size):
            if inside[i] < zb:
                zb = inside[i]
        front = zb - (zb - za) * (1.0 - t) if t >= 0.5 else za + (zb - za) * t
    return front, radius_px * front / focal, True


@_njit_inlined
def _mode_edges(
    z_first: float, z_last: float, median: float, radius_px: float, focal: float, noise: float
) -> tuple[bool, int, float, np.ndarray]:  # fmt: skip
    """:func:`fruit_depth`'s bins of the depths from ``z_first`` to ``z_last`` (their least and greatest) with their
    ``median``: ``(ok, n_bins, width, edges)``, the edges as ``np.linspace`` makes them (``i * width + lo``, the last
    one the range's end) and their width; ``ok`` False where the twin is to run instead (a bin count ``int()``
    refuses, a range numpy widens). Shared by :func:`fruit_depth` and :func:`depth_mode` (stop 51)."""
    radius = radius_px * median / focal
    step = radius / 3.0
    if 0.004 > step:
        step = 0.004
    if 2.0 * noise > step:
        step = 2.0 * noise
    c = np.ceil((z_last - z_first) / step)
    if not math.isfinite(c):  # the twin's int() refuses it
        return False, 0, 0.0, np.empty(0)
    if 1 > c:
        c = 1.0
    if 4096 < c:
        c = 4096.0
    n_bins = int(c)
    lo, hi = z_first, z_first + n_bins * step
    if not lo < hi:
        return False, 0, 0.0, np.empty(0)
    delta = hi - lo
    width = delta / n_bins
    edges = np.empty(n_bins + 1)
    for k in range(n_bins + 1):
        edges[k] = (k / n_bins * delta if width == 0 else k * width) + lo
    edges[n_bins] = hi
    return True, n_bins, width, edges


@_njit_inlined
def _mode_bin(
    at: np.ndarray, n: int, z: np.ndarray, kept: np.ndarray, leaf: np.ndarray, edges: np.ndarray, with_leafy: bool,
    leafy_shares: tuple[float, float],
) -> tuple[bool, float, float]:  # fmt: skip
    """:func:`fruit_depth`'s front bin from the counts below each edge ``at`` (n_bins + 1,) of the ``n`` depths: the
    three-bin masses (``np.convolve``'s ``"same"`` window of sums of whole numbers: exact), the first peak holding
    half the largest mass, the leaf test's shares (``leaf`` aligned with ``kept``; counted on ``z``, the depths sorted,
    or on ``kept`` where ``z`` is empty: the same whole numbers) and the walk nearer over filled bins: ``(found,
    a_edge, b_edge)``, the depths of the front's quantile lying from ``a_edge`` to ``b_edge`` (both included);
    ``found`` False where no peak is met. Shared by :func:`fruit_depth` and :func:`depth_mode` (stop 51)."""
    n_bins = at.shape[0] - 1
    counts = np.empty(n_bins, np.int64)
    for k in range(n_bins):
        counts[k] = at[k + 1] - at[k]
    # np.convolve(counts, np.ones(3), mode="same"): max(n_bins, 3) values of the full convolution from the shorter
    # array's half length on (with fewer than 3 bins the ones are the longer array, and the masses run past the bins)
    size = max(n_bins, 3)
    offset = 1 if n_bins >= 3 else 0
    mass = np.zeros(size)
    for k in range(size):
        j = k + offset  # the full convolution's place: the bins j - 2 .. j
        s = 0.0
        for q in range(max(j - 2, 0), min(j, n_bins - 1) + 1):
            s += counts[q]
        mass[k] = s
    top = mass.max()
    i = -1
    for k in range(size):
        after = mass[k + 1] if k + 1 < size else -1.0
        before = mass[k - 1] if k > 0 else -1.0
        if mass[k] >= after and mass[k] >= before and mass[k] >= 0.5 * top:
            i = k
            break
    if i < 0 or i >= n_bins:  # not met (the twin's masses run past the bins by two at most, its peak never)
        return False, 0.0, 0.0
    if with_leafy and _leaf_share(z, kept, leaf, edges, i, n_bins) >= leafy_shares[0]:
        for k in range(i + 1, n_bins):
            after = mass[k + 1] if k + 1 < size else -1.0
            before = mass[k - 1] if k > 0 else -1.0
            if not (mass[k] >= after and mass[k] >= before and mass[k] >= 0.1 * top):
                continue
            if _leaf_share(z, kept, leaf, edges, k, n_bins) < leafy_shares[1] and mass[k] >= 10:
                i = k
                break
    least = 0.01 * n
    if 2 > least:
        least = 2.0
    first = i
    while first > 0 and counts[first - 1] >= least:
        first -= 1
    lo = edges[first]
    if first < i and counts[i] >= least:
        # the walk read at every phase (stop 59, docs/reg59.md): the depths it walked over, sorted, and the last gap
        end = edges[min(i + 1, n_bins)]
        width = edges[1] - edges[0]
        if z.shape[0] > 0:  # the depths sorted: the run is a slice of them (the gather's values, in order)
            run = z[_count_below(z, lo, False) : _count_below(z, end, False)]
            gap = gap_before(run, _count_below(run, edges[i], False), least, width)
        elif i + 1 < n_bins and no_gap(kept, lo, end, edges[i], width, least):
            gap = -np.inf  # what gap_before finds where no window can hold fewer than least (stop 59, lead)
        else:
            m = 0
            for v in kept:
                m += (v >= lo) & (v < end)
            run = np.empty(m)
            m = 0
            for v in kept:
                if v >= lo and v < end:
                    run[m] = v
                    m += 1
            run.sort()
            below = 0
            while below < m and run[below] < edges[i]:
                below += 1
            gap = gap_before(run, below, least, width)
        if gap > lo:
            first = i
            while first > 0 and counts[first - 1] >= least and edges[first] > gap:
                first -= 1
            lo = max(edges[first], min(gap, end)) if first < i else edges[first]
    return True, lo, edges[first + 1] if first < i else edges[min(i + 2, n_bins)]


#: :func:`no_gap`'s parts of a bin: a window a bin wide holds all but three of them whole, wherever it starts.
GAP_PARTS = 16


@_njit
def no_gap(kept: np.ndarray, lo: float, end: float, start_end: float, width: float, least: float) -> bool:
    """True where :func:`gap_before` on the sorted depths of ``kept`` from ``lo`` up to ``end`` (the starts: those
    below ``start_end``; ``end - start_end`` a bin ``width`` or more) would find no window: read without sorting them
    (stop 59: the sort was 0.8 ms of a 33 ms frame). The depths are counted in parts of ``width / GAP_PARTS``; a
    window from a start in part ``s`` holds every depth of parts ``s + 2`` to ``s + GAP_PARTS - 2`` (a part's place
    off by one at its edges by rounding included: those depths lie more than 0.9 part after the start and more than
    0.9 part before the window's end), so where each such run of parts holds ``least`` depths or more, every window
    does. False where one may not (then :func:`gap_before` decides, on the sorted depths), and where the walk spans
    more parts than twice the depths (the parts' counts would cost more than the sort, and their memory is bounded by
    the depths')."""
    t = np.int64(np.ceil(least))
    part = width / GAP_PARTS
    span = (end - lo) / part
    if not span < 2 * kept.shape[0] + 64:  # more parts than depths (a walk over many bins; NaN): the sort is cheaper
        return False
    n_parts = np.int64(span) + 2
    counts = np.zeros(n_parts + 1, np.int64)
    for v in kept:
        if v >= lo and v < end:
            q = np.int64((v - lo) / part)
            counts[min(max(q, 0), n_parts - 1) + 1] += 1
    for q in range(n_parts):  # running sums: counts[q] the depths of the parts before q
        counts[q + 1] += counts[q]
    last = min(np.int64((start_end - lo) / part) + 1, n_parts - 1)
    for s_ in range(last + 1):
        a, b = s_ + 2, s_ + GAP_PARTS - 1  # the parts a .. b - 1
        if b > n_parts:
            return False
        if counts[b] - counts[a] < t:
            return False
    return True


@_njit
def gap_before(run: np.ndarray, below: int, least: float, width: float) -> float:
    """:func:`symfruit.core.surface._gap_before`: the depth after the last window ``width`` wide after one of the
    first ``below`` of the sorted depths ``run`` holding fewer than ``least`` of them (+inf past the end, -inf
    without one); the same comparisons."""
    t = np.int64(np.ceil(least))
    n = run.shape[0]
    for j in range(below - 1, -1, -1):
        if j + t >= n or run[j + t] - run[j] > width:
            return run[j + 1] if j + 1 < n else np.inf
    return -np.inf


# --- stop 52, register52: fruit_surface's mask box, measures and depth mode in one call ------------------------------


@_njit
def mask_mode(
    depth: np.ndarray, mask: np.ndarray, leafy: np.ndarray, with_leafy: bool, floor: float, focal: float,
    leafy_shares: tuple[float, float],
) -> tuple[bool, int, int, int, int, int, float, np.ndarray, np.ndarray, float, float, float, bool]:  # fmt: skip
    """:func:`symfruit.core.surface.fruit_surface`'s first steps on a window in one call, each the code it ran (the
    same numbers, bit for bit): the box of ``mask`` (h, w) bool (:func:`symfruit.core.raster.mask_box`), the count of
    its pixels, then on the box :func:`mask_values` of ``depth`` (h, w) float64 (``leafy`` (h, w) bool where
    ``with_leafy``; ``floor`` the noise's) and :func:`depth_mode` of its depths with the mask's equivalent radius
    ``sqrt(count / pi)`` and ``focal``. ``(found, r0, r1, c0, c1, count, noise, kept, leaf, step, front, radius,
    done)``: ``found`` False for an empty mask (nothing else set); ``kept`` and ``leaf`` as :func:`mask_values` gives
    them, for :func:`symfruit.core.surface.fruit_depth` where ``done`` is False (stop 52: two kernels' calls and
    ``mask_box``'s numpy steps, 20-40 us a fruit, in one)."""
    h, w = mask.shape
    # stop 60 (speeds60): each row or-ed whole, then its first and last pixel walked to from its ends: the same box
    r0, r1, c0, c1 = _mask_box_in(mask, 0, 0, h, w)
    none = np.empty(0)
    if r1 == 0:
        return False, 0, 0, 0, 0, 0, 0.0, none, np.empty(0, np.bool_), 0.0, np.nan, np.nan, True
    own = mask[r0:r1, c0:c1]
    count = 0
    for r in range(r1 - r0):
        for c in range(c1 - c0):
            count += own[r, c]
    radius_px = math.sqrt(count / np.pi)
    leaf_box = leafy[r0:r1, c0:c1] if with_leafy else leafy
    noise, kept, leaf, step = mask_values(depth[r0:r1, c0:c1], own, leaf_box, with_leafy, floor)
    front, radius, done = depth_mode(kept, radius_px, focal, noise, leaf, with_leafy, leafy_shares)
    return True, r0, r1, c0, c1, count, noise, kept, leaf, step, front, radius, done


# --- stop 52, round52: the round fruit's pieces in fewer calls --------------------------------------------------------


@_njit
def hull_area_of(v: np.ndarray) -> float:
    """:func:`symfruit.segment.colour._hull_area_of` of hull vertices ``v`` (m, 2) float64 (x, y), m >= 1: the
    polygon's area (the shoelace sums ``x . roll(y, -1)`` and ``y . roll(x, -1)``) plus half its perimeter (numpy's
    ``np.hypot`` of the edges, libm's ``hypot`` as numba calls it, summed pairwise as numpy sums) plus 1. The two dot
    products are sums of whole numbers below 2 ** 53 when every vertex is a whole number of at most 2 ** 15 in size
    (a hull's vertices are pixel centres): exact, so the same in any order as numpy's BLAS ``ddot`` sums them; -1.0
    for other vertices (the twin's numpy then). The same value (stop 52)."""
    m = v.shape[0]
    for i in range(m):
        for j in range(2):
            a = v[i, j]
            if not (abs(a) <= 32768.0 and a == math.floor(a)):
                return -1.0
    sx = 0.0
    sy = 0.0
    edges = np.empty(m)
    for i in range(m):
        n = i + 1 if i + 1 < m else 0
        sx += v[i, 0] * v[n, 1]
        sy += v[i, 1] * v[n, 0]
        edges[i] = np.hypot(v[n, 0] - v[i, 0], v[n, 1] - v[i, 1])
    area = 0.5 * abs(sx - sy)
    perimeter = 0.0 + _pairwise_sum(edges, 0, m)
    return area + 0.5 * perimeter + 1.0


@_njit
def skin_seed(
    hull: np.ndarray,
    z: np.ndarray,
    r0: int,
    c0: int,
    color: np.ndarray,
    owner: np.ndarray,
    k: int,
    pad: int,
    jump: float,
    ground_hue: int,
    leaf_hue: int,
    dark: int,
) -> tuple[bool, np.ndarray, int, float, int, float, float]:
    """:func:`symfruit.segment.colour._round_skin`'s start for a red part (``hull`` (h, w) bool, its window at row
    ``r0`` and column ``c0`` of the window padded by ``pad`` about it, whose depth ``z`` float64, ``color`` uint8 and
    ``owner`` ids are given): the part's depths (:func:`masked_depths`), :func:`blush_rim`'s test (made with 20 of
    them or more), then what the growth starts from: whether the blush test moved the part to the padded window
    (then the part with the ring's pixels beside it, else ``hull`` itself), how many depths it grows from (the part's,
    or the ring pixels' taken), their median (:func:`median_values`, the twin's ``core.points.median``) and the
    mask's :func:`mask_centre`. The twin's calls in one, the same values (stop 52)."""
    h, w = hull.shape
    _, z_part = masked_depths(hull, z[r0 : r0 + h, c0 : c0 + w])
    mask = hull
    moved = False
    if z_part.shape[0] >= 20:
        zh, zw = z.shape
        part = np.zeros((zh, zw), np.bool_)
        part[r0 : r0 + h, c0 : c0 + w] = hull
        near = blush_rim(part, z, color, owner, k, pad, z_part, jump, ground_hue, leaf_hue, dark)
        if near.shape[0] == zh and near.shape[1] == zw:
            moved = True
            mask = part | near
            _, z_part = masked_depths(near, z)  # the ring's pixels all have depth: ``z[near]``
    n = z_part.shape[0]
    zm = median_values(z_part) if n >= 20 else np.nan
    count, mr, mc = mask_centre(mask) if n >= 20 else (0, np.nan, np.nan)
    return moved, mask, n, zm, count, mr, mc


@_njit
def round_piece(
    color: np.ndarray,
    part: np.ndarray,
    weak: np.ndarray,
    least: np.float32,
    vertices: np.ndarray,
    owner: np.ndarray,
    k: int,
    surface: bool,
    z: np.ndarray,
    jump: float,
) -> tuple[int, np.ndarray]:
    """:func:`symfruit.segment.colour._segment_at`'s first tests of a round fruit's found piece (``part`` (h, w) bool,
    the ``k``-th) in one call: its red pixels ``part & weak`` ripe (:func:`red_ripe` in ``color`` (h, w, 3) uint8
    against ``least``; none: not), then its hull (:func:`surface_hull` of the hull ``vertices`` over ``owner``'s
    window) less the pixels far from the red pixels' median depth in ``z`` (h, w) float64 (:func:`depth_consistent`).
    Returns 0 and a (0, 0) array (not ripe), 1 and the hull, or 2 (a vertex not a whole number: the twin's Pillow
    then). The twin's calls in one, the same answer and pixels (stop 52)."""
    h, w = part.shape
    red = np.empty((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            red[r, c] = part[r, c] and weak[r, c]
    if not red_ripe(color, red, least):
        return 0, np.zeros((0, 0), np.bool_)
    hull = surface_hull(vertices, part, owner, k, color, surface)
    if hull.shape[0] != h or hull.shape[1] != w:
        return 2, hull
    return 1, depth_consistent(hull, red, z, jump)


@_njit
def bridged_solid(
    skin: np.ndarray, z: np.ndarray, part: np.ndarray, r0: int, c0: int, solidity: float
) -> tuple[np.ndarray, int]:
    """:func:`bridged_trim` of a skin grown over bridged depth, then :func:`symfruit.segment.colour._bridged_skin`'s
    test of the trimmed skin: whether its pixel count falls below ``solidity`` times its hull's area
    (:func:`hull_vertices`, :func:`hull_area_of`; the count itself without a hull). Returns the skin and 0 (the trim
    not worked out: the twin's numpy then, the skin as given), 1 (the skin one convex outline), 2 (it is not) or 3
    (the area not worked out: a vertex not a whole number). The twin's calls in one, the same pixels and answer
    (stop 52)."""
    out, done = bridged_trim(skin, z, part, r0, c0)
    if not done:
        return out, 0
    h, w = out.shape
    count = 0
    for r in range(h):
        for c in range(w):
            count += out[r, c]
    v = hull_vertices(out)
    area = float(count) if len(v) == 0 else hull_area_of(v)
    if area < 0.0:
        return out, 3
    return out, 2 if count < solidity * area else 1


# --- issue 19, stop 53 (complete53) ---


@_njit_inlined
def _row_any(m8: np.ndarray, r: int, w: int) -> bool:
    """Whether row ``r`` of ``m8`` (h, w) uint8 holds a byte that is not 0: its bytes or-ed together (a loop without an
    exit, which the compiler vectorises)."""
    acc = np.uint8(0)
    for c in range(w):
        acc |= m8[r, c]
    return acc != 0


@_njit
def mask_box(mask: np.ndarray) -> tuple[bool, int, int, int, int]:
    """:func:`symfruit.core.raster.mask_box` of a C-ordered (h, w) bool image: ``(found, r0, r1, c0, c1)``, the first
    row and column holding a true pixel and the stops after the last (exclusive); found False (and zeros) when none
    is true. The first and the last row with a true pixel from the top and from the bottom (:func:`_row_any`), then
    the rows between or-ed into one row of bytes and its first and last byte that is not 0: the same whole numbers
    as the twin's two reductions and ``nonzero`` (a byte not 0 is true in both), in one pass over the rows up to the
    last true one and none over those below it (issue 19, stop 53)."""
    h, w = mask.shape
    m8 = mask.view(np.uint8)
    r0 = -1
    for r in range(h):
        if _row_any(m8, r, w):
            r0 = r
            break
    if r0 < 0:
        return False, 0, 0, 0, 0
    r1 = r0 + 1
    for r in range(h - 1, r0, -1):
        if _row_any(m8, r, w):
            r1 = r + 1
            break
    acc = np.zeros(w, np.uint8)
    for r in range(r0, r1):
        for c in range(w):
            acc[c] |= m8[r, c]
    c0 = 0
    while acc[c0] == 0:
        c0 += 1
    c1 = w
    while acc[c1 - 1] == 0:
        c1 -= 1
    return True, r0, r1, c0, c1


# --- stop 53, seg53: a round skin's flood with its part's copy and its reach test ------------------------------------


@_njit
def skin_flood(
    z: np.ndarray,
    color: np.ndarray,
    owner: np.ndarray,
    k: int,
    hull: np.ndarray,
    pr: int,
    pc: int,
    r0: int,
    c0: int,
    rc: float,
    cc: float,
    reach2: float,
    deep_limit: float,
    zm: float,
    step: float,
    jump: float,
    leaf_hue: int,
    limit: float,
) -> tuple[np.ndarray, bool]:
    """:func:`symfruit.segment.colour._skin_flood` and the reach test after it in one call: the red part ``hull``
    (a bool window of its own) copied into the flood's window (``z``, ``color``, ``owner`` (h, w), at ``(r0, c0)``
    in the image) at ``(pr, pc)``, :func:`round_skin`'s skin grown from it (its arguments after ``part``), and, when
    ``limit`` is 0 or more, :func:`at_reach`'s answer for the skin (its ``limit``, the twin's ``(reach - 1) ** 2``;
    False when not asked). The same skin and answer as the calls (stop 53, seg53: not the part's window made and
    filled by numpy, nor a second call)."""
    part = np.zeros(z.shape, np.bool_)
    part[pr : pr + hull.shape[0], pc : pc + hull.shape[1]] = hull
    skin = round_skin(z, color, owner, k, part, r0, c0, rc, cc, reach2, deep_limit, zm, step, jump, leaf_hue)
    return skin, limit >= 0.0 and at_reach(skin, r0, c0, rc, cc, limit)


# --- stop 55, seg55: a red window's regions, their depths, sizes and boxes in one call ------------------------------


@_njit
def window_regions(
    c: np.ndarray, low: np.ndarray, high: np.ndarray, sqrt3: float, tan_hue: float, given: np.ndarray, r0: int,
    c0: int, diameter_px_m: float, z_typical: float,
) -> tuple[np.ndarray, np.ndarray, int, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip  # noqa: E501
    """:func:`symfruit.segment.colour._window_regions` with depth: the red window ``c`` (h, w, 3) uint8 at ``(r0,
    c0)`` of an image whose depth is ``given`` (H, W) float, C-contiguous, as handed over. :func:`red_regions_once`'s
    mask and labels, how many weak pixels there are and each region's size (m + 1,); then, when a region holds a
    strong pixel, the weak pixels' flat indices in the image and their depths (:func:`depth_at`'s values), the least
    fruit's area at each region's depth (:func:`least_areas`) and the regions kept (seeded, and at least a quarter of
    that area) as :func:`grouped` gives them (their labels, pixels and runs) with their boxes (:func:`group_boxes`);
    with no region seeded those last six are empty. The twin's calls in one: the same arrays, not five calls and the
    numpy between them a window (stop 55, seg55)."""
    mask, out, m, weak_at, _, lab, seeded, sizes, rows, cols = red_regions_once(c, low, high, sqrt3, tan_hue)
    n = weak_at.shape[0]
    any_seeded = False
    for k in range(m + 1):
        any_seeded = any_seeded or seeded[k]
    if not any_seeded:
        none = np.empty(0, np.int64)
        return mask, out, n, sizes, none, np.empty(0), np.empty(0, lab.dtype), none, none, np.empty((0, 4), np.int64)
    width = given.shape[1]
    flat = given.reshape(-1)
    image_at = np.empty(n, np.int64)
    for i in range(n):
        image_at[i] = (rows[i] + r0) * width + (cols[i] + c0)
    zw = depth_at(flat, image_at)
    least = least_areas(lab, zw, m, diameter_px_m, z_typical)
    keep = np.empty(m + 1, np.bool_)
    for k in range(m + 1):
        keep[k] = seeded[k] and sizes[k] >= 0.25 * least[k]
    ids, at, first = grouped(lab, keep)
    boxes = group_boxes(at, first, rows, cols) if at.shape[0] > 0 else np.empty((0, 4), np.int64)
    return mask, out, n, sizes, image_at, zw, ids, at, first, boxes


# --- stop 58, speed58: a large round region's ripe cores, before their labels ----------------------------------------


@_njit
def _uniform_line(line: np.ndarray, size: int, out: np.ndarray) -> None:
    """``ndimage.uniform_filter1d(line, size)`` (mode "reflect", origin 0) of a float32 ``line`` into float32 ``out``:
    scipy's running sum in float64 (the first ``size`` values of the reflected line summed, then each step adding the
    entering value less the leaving one), each value that sum divided by ``size`` and rounded to float32 as scipy
    writes it. The same bits (20,000 random lines of 1-60 values and sizes 1-11, scipy 1.17)."""
    n = line.shape[0]
    half = size // 2
    tmp = 0.0
    for i in range(size):
        tmp += np.float64(line[_reflected(i - half, n)])
    out[0] = np.float32(tmp / size)
    for i in range(1, n):
        tmp += np.float64(line[_reflected(i + size - 1 - half, n)]) - np.float64(line[_reflected(i - 1 - half, n)])
        out[i] = np.float32(tmp / size)


@_njit
def ripe_core(color: np.ndarray, region: np.ndarray, size: int, ripe: np.float32) -> np.ndarray:
    """:func:`symfruit.segment.colour._ripe_cores`' core of a large region: the pixels of ``region`` (h, w) bool whose
    float32 redness (:func:`_redness_at`, ``redness``'s) of ``color`` (h, w, >= 3) uint8 averaged by
    ``ndimage.uniform_filter(red, size)`` (along the columns, then the rows, each pass rounded to float32:
    :func:`_uniform_line`'s values) reaches ``ripe`` (a float32 comparison, as numpy makes it against a setting):
    the twin's three whole-window passes and their arrays in one call (stop 58, speed58), the same pixels."""
    h, w = region.shape
    red = np.empty((w, h), np.float32)  # each column as a contiguous line
    for r in range(h):
        for c in range(w):
            red[c, r] = _redness_at(color, r, c)
    down = np.empty((h, w), np.float32)
    line = np.empty(h, np.float32)
    for c in range(w):
        _uniform_line(red[c], size, line)
        for r in range(h):
            down[r, c] = line[r]
    out = np.zeros((h, w), np.bool_)
    mean = np.empty(w, np.float32)
    for r in range(h):
        _uniform_line(down[r], size, mean)
        for c in range(w):
            out[r, c] = region[r, c] and mean[c] >= ripe
    return out


@_njit
def piece_sums(
    labels: np.ndarray, depth: np.ndarray, at: np.ndarray, n: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`symfruit.segment.colour._piece_discs`' three ``np.bincount`` calls in one pass: for pieces ``0..n``
    (``labels`` (m,) of the pixels at flat indices ``at`` (m,) of a depth image ``depth`` (flat, float64, 0: none)),
    each one's pixel count (float64), the sum of its depths and how many of them are above 0 (float64), each bin's sum
    over its pixels in their order as ``np.bincount``'s loop adds its weights: the same values, without the depths'
    gathered copy (stop 58, speed58)."""
    count = np.zeros(n + 1)
    total = np.zeros(n + 1)
    seen = np.zeros(n + 1)
    for i in range(labels.shape[0]):
        k = labels[i]
        z = depth[at[i]]
        count[k] += 1.0
        total[k] += z
        seen[k] += 1.0 if z > 0 else 0.0
    return count, total, seen


# --- stop 59, speedc59: the completion ---


@_njit
def in_pieces(mask: np.ndarray) -> bool:
    """Whether ``mask`` (h, w) bool holds two or more pieces of 8-connected true pixels:
    ``scipy.ndimage.label(mask, np.ones((3, 3), bool))[1] >= 2``, the same answer (the twin in
    :func:`symfruit.core.occlusion.bridged`), without labelling every pixel: each row's runs of true pixels, then a
    flood over the runs from the first (a run meets one in the row above or below where their columns overlap or
    touch at a corner) and the runs it reaches counted against all (False for none or one piece; stop 59,
    speedc59)."""
    h, w = mask.shape
    cap = h * ((w + 1) // 2)  # the most runs a row of w pixels holds, times the rows
    row_at = np.empty(h + 1, np.int64)  # the first run of each row, and the end
    c0 = np.empty(cap, np.int64)
    c1 = np.empty(cap, np.int64)
    n = 0
    for r in range(h):
        row_at[r] = n
        c = 0
        while c < w:
            if mask[r, c]:
                s = c
                c += 1
                while c < w and mask[r, c]:
                    c += 1
                c0[n], c1[n] = s, c
                n += 1
            else:
                c += 1
    row_at[h] = n
    if n < 2:
        return False
    row = np.empty(n, np.int64)
    for r in range(h):
        for k in range(row_at[r], row_at[r + 1]):
            row[k] = r
    reached = np.zeros(n, np.bool_)
    stack = np.empty(n, np.int64)  # each run is pushed once at most
    reached[0] = True
    stack[0] = 0
    top = 1
    count = 1
    while top > 0:
        top -= 1
        k = stack[top]
        r = row[k]
        for rr in (r - 1, r + 1):
            if rr < 0 or rr >= h:
                continue
            for j in range(row_at[rr], row_at[rr + 1]):
                # 8-neighbours: the columns [c0, c1) overlap or touch at a corner
                if not reached[j] and c0[j] <= c1[k] and c0[k] <= c1[j]:
                    reached[j] = True
                    stack[top] = j
                    top += 1
                    count += 1
    return count < n


# --- stop 60, speedo60: the occlusion's points projected in the kernel, the own edge on the mask's box ---------


@_njit_inlined
def _mask_box_in(mask: np.ndarray, v0: int, u0: int, h: int, w: int) -> tuple[int, int, int, int]:
    """The box of ``mask``'s pixels within its (h, w) window at ``(v0, u0)``, in the window: ``(r0, r1, c0, c1)``
    (stops exclusive; ``r1 <= r0``: none), what ``own_edge_boxed``'s scan found (until stop 61), each row's pixels
    OR-ed (no branch a pixel) and its first and last pixel looked for only where it holds one (also
    :func:`_rows_box`'s and :func:`mask_mode`'s box, the window the whole image)."""
    r0, r1, c0, c1 = h, 0, w, 0
    for r in range(h):
        some = False
        for c in range(w):
            some |= mask[v0 + r, u0 + c]
        if some:
            a = 0
            while not mask[v0 + r, u0 + a]:
                a += 1
            b = w - 1
            while not mask[v0 + r, u0 + b]:
                b -= 1
            r0, r1 = min(r0, r), r + 1
            c0, c1 = min(c0, a), max(c1, b + 1)
    return r0, r1, c0, c1


@_njit
def occlusion_projected(
    points: np.ndarray,
    fx: float,
    fy: float,
    cx: float,
    cy: float,
    pad: int,
    depth: np.ndarray,
    mask: np.ndarray,
    others: np.ndarray,
    tolerance: float,
    steps: np.ndarray,
    band: int,
    supports: bool,
    focal: float,
) -> tuple[bool, int, int, np.ndarray, np.ndarray]:  # fmt: skip
    """:func:`occlusion_at` then :func:`own_edge` on its maps (until stop 61 ``occlusion_edge_boxed``, of pixel
    coordinates) of ``points`` (n, 3) projected by a camera of intrinsics ``fx, fy, cx, cy``
    (:meth:`symfruit.core.camera.Camera.project`'s arithmetic, in its order: ``fx x (1 / z) + cx``, the same
    coordinates, each point's pixel worked out once, not twice), the window's maps by :func:`_occlusion_pass` and
    the own edge by :func:`_own_edge_in_box` on the mask's box :func:`_mask_box_in` finds: ``(found, u0, v0, hidden,
    seen)``, the same maps bit for bit (issue 19, stop 60: :func:`symfruit.core.occlusion.occlusion` no longer
    projects the points in numpy, some 10-20 us a fruit)."""
    height, width = mask.shape
    n = points.shape[0]
    none = (False, 0, 0, np.empty((0, 0), np.bool_), np.empty((0, 0)))
    cmin, cmax, rmin, rmax = width, -1, height, -1
    low, high = np.inf, -np.inf
    pcol = np.empty(n, np.int64)  # each point's pixel, -1: outside the image
    prow = np.empty(n, np.int64)
    for i in range(n):
        z = points[i, 2]
        low, high = min(low, z), max(high, z)
        inv = 1.0 / z
        u, v = np.rint(fx * points[i, 0] * inv + cx), np.rint(fy * points[i, 1] * inv + cy)
        if u >= 0 and u < width and v >= 0 and v < height:
            c, r = int(u), int(v)
            pcol[i], prow[i] = c, r
            cmin, cmax, rmin, rmax = min(cmin, c), max(cmax, c), min(rmin, r), max(rmax, r)
        else:
            pcol[i] = -1
    if cmax < 0:
        return none
    span_u, span_v = cmax - cmin + pad, rmax - rmin + pad
    u0, v0 = max(cmin - span_u, 0), max(rmin - span_v, 0)
    u1, v1 = min(cmax + span_u + 1, width), min(rmax + span_v + 1, height)
    h, w = v1 - v0, u1 - u0
    p0, q0 = rmin - v0, cmin - u0  # the point pixels' box in the window
    own_z = np.full((rmax + 1 - rmin, cmax + 1 - cmin), np.inf)
    for i in range(n):
        if pcol[i] >= 0:
            r, c = prow[i] - rmin, pcol[i] - cmin
            z = points[i, 2]
            if z < own_z[r, c]:
                own_z[r, c] = z
    hidden = np.empty((h, w), np.bool_)
    seen = np.empty((h, w))
    _occlusion_pass(depth, mask, others, v0, u0, own_z, p0, q0, tolerance, steps, low, high, hidden, seen)
    if band <= 0:
        return True, u0, v0, hidden, seen
    some = False
    for r in range(h):
        for c in range(w):
            some |= hidden[r, c]
        if some:
            break
    if some:
        f0, f1, e0, e1 = _mask_box_in(mask, v0, u0, h, w)
        _own_edge_in_box(hidden, mask, v0, u0, own_z, p0, q0, seen, others, tolerance, band, supports, focal, f0, f1,
                         e0, e1)  # fmt: skip
    return True, u0, v0, hidden, seen


@_njit
def _difference_rows(s: np.ndarray, out: np.ndarray) -> None:
    """``ndimage.correlate1d(s, [-1, 0, 1], 1)`` (mode "reflect") of an (h, w) image into ``out``: scipy takes the
    weights as antisymmetric, so each value is the middle one times 0, plus the left less the right one times -1;
    the inner columns along views of the rows (numba vectorises them), the two end ones reflected."""
    h, w = s.shape
    for r in range(h):
        row, o = s[r], out[r]
        for c in (0, w - 1):
            v = row[c] * 0.0
            v += (row[_reflected(c - 1, w)] - row[_reflected(c + 1, w)]) * -1.0
            o[c] = v
        if w > 2:
            a, mid, b, oo = row[0 : w - 2], row[1 : w - 1], row[2:w], o[1 : w - 1]
            for k in range(w - 2):
                v = mid[k] * 0.0
                v += (a[k] - b[k]) * -1.0
                oo[k] = v


@_njit
def _difference_columns(s: np.ndarray, out: np.ndarray) -> None:
    """``ndimage.correlate1d(s, [-1, 0, 1], 0)`` (mode "reflect") of an (h, w) image into ``out``, as
    :func:`_difference_rows` along the columns: a whole row at a time."""
    h, w = s.shape
    for r in range(h):
        a, mid, b, o = s[_reflected(r - 1, h)], s[r], s[_reflected(r + 1, h)], out[r]
        for k in range(w):
            v = mid[k] * 0.0
            v += (a[k] - b[k]) * -1.0
            o[k] = v


@_njit
def _spread_rows(d: np.ndarray, out: np.ndarray) -> None:
    """``ndimage.correlate1d(d, [1, 2, 1], 1)`` (mode "reflect") of an (h, w) image into ``out`` (symmetric: the
    middle value times 2, plus the pair's sum times 1), as :func:`_difference_rows`."""
    h, w = d.shape
    for r in range(h):
        row, o = d[r], out[r]
        for c in (0, w - 1):
            v = row[c] * 2.0
            v += (row[_reflected(c - 1, w)] + row[_reflected(c + 1, w)]) * 1.0
            o[c] = v
        if w > 2:
            a, mid, b, oo = row[0 : w - 2], row[1 : w - 1], row[2:w], o[1 : w - 1]
            for k in range(w - 2):
                v = mid[k] * 2.0
                v += (a[k] + b[k]) * 1.0
                oo[k] = v


@_njit
def _spread_columns(d: np.ndarray, out: np.ndarray) -> None:
    """``ndimage.correlate1d(d, [1, 2, 1], 0)`` (mode "reflect") of an (h, w) image into ``out``, a whole row at a
    time."""
    h, w = d.shape
    for r in range(h):
        a, mid, b, o = d[_reflected(r - 1, h)], d[r], d[_reflected(r + 1, h)], out[r]
        for k in range(w):
            v = mid[k] * 2.0
            v += (a[k] + b[k]) * 1.0
            o[k] = v


@_njit
def colour_gradient(
    window: np.ndarray, weights: np.ndarray, symmetric: bool, squares: np.ndarray, gx: np.ndarray, gy: np.ndarray
) -> None:
    """:func:`symfruit.core.edges._window_gradient` of a colour window (h, w, c) of finite values under 1e100, into
    ``gx`` and ``gy`` (h, w), the strongest channel's gradient, and ``squares`` (h, w), its ``gx * gx + gy * gy``.
    Each channel is smoothed by ``weights`` (``ndimage.gaussian_filter``'s at sigma 1, ``symmetric`` as scipy finds
    them) along the columns then the rows (:func:`_smoothed`), then differenced as ``ndimage.sobel`` does it
    (``[-1, 0, 1]`` along one axis, :func:`_difference_rows`, then ``[1, 2, 1]`` along the other,
    :func:`_spread_columns`), all in scipy's order and mode "reflect": the twin's gradients to the bit.

    The strongest channel is the first whose ``hypot`` is the greatest (the twin's running maximum and ``argmax``).
    ``hypot`` (libm's, as numpy's) costs some 10-14 ns a value against a fraction of one for a sum of squares, so
    channels are told apart by their sums of squares where those differ by more than a part in 1e10 (far beyond
    their rounding, a few parts in 1e16, and ``hypot``'s, under one in 1e16: the larger sum is the larger
    ``hypot``); only near ties and values near underflow compare ``hypot`` itself: the same channels. The magnitude
    itself is left to the caller (:func:`symfruit.core.edges._squared_median`, ``_squared_peaks``), which needs
    ``hypot`` only where a comparison is that close."""
    h, w, nc = window.shape
    ch = np.empty((h, w))
    exact = np.empty((h, w))  # the strongest channel's hypot where worked out, else -1
    d = np.empty((h, w))
    cx = np.empty((h, w))
    cy = np.empty((h, w))
    q = np.empty(w)
    for k in range(nc):
        for r in range(h):
            for c in range(w):
                ch[r, c] = float(window[r, c, k])
        s = _smoothed(ch, weights, symmetric)
        _difference_rows(s, d)
        _spread_columns(d, cx)
        _difference_columns(s, d)
        _spread_rows(d, cy)
        for r in range(h):
            x, y, best = cx[r], cy[r], squares[r]
            for c in range(w):
                q[c] = x[c] * x[c] + y[c] * y[c]
            if k == 0:
                for c in range(w):
                    best[c], exact[r, c], gx[r, c], gy[r, c] = q[c], -1.0, x[c], y[c]
                continue
            for c in range(w):
                a, b = q[c], best[c]
                safe = 1e-290 < b and 1e-290 < a
                if safe and a > b * (1.0 + 1e-10):
                    best[c], exact[r, c], gx[r, c], gy[r, c] = a, -1.0, x[c], y[c]
                elif safe and a < b * (1.0 - 1e-10):
                    continue
                else:  # a near tie (or a value near underflow): hypot decides, strictly, as the twin's
                    e = exact[r, c]
                    if e < 0.0:
                        e = math.hypot(gx[r, c], gy[r, c])
                        exact[r, c] = e
                    m = math.hypot(x[c], y[c])
                    if m > e:
                        best[c], exact[r, c], gx[r, c], gy[r, c] = a, m, x[c], y[c]


@_njit
def capped_distances(
    rows: np.ndarray, cols: np.ndarray, ebins: np.ndarray, cap: float, prow: np.ndarray, pcol: np.ndarray,
    pbins: np.ndarray, m: int, dist: np.ndarray,
) -> None:  # fmt: skip
    """:func:`symfruit.core.edges._capped_distances` into ``dist`` (n_bins, h + 2 m, w + 2 m) float32, filled with
    ``cap`` by the caller: for every orientation bin some point ``(prow, pcol, pbins)`` has, the edges ``(rows, cols)``
    whose bin ``ebins`` is within one of it and within the points' box grown by ``m + ceil(cap)``, their distances
    within the cap (:func:`near_distance`) capped at ``cap``, written at the box offset by ``m``. The twin's steps in
    one call (its masks, boxes and copies were half its time): the same values."""
    nb = dist.shape[0]
    h, w = dist.shape[1] - 2 * m, dist.shape[2] - 2 * m
    reach = m + math.ceil(cap)
    lo_r = np.full(nb, h + reach, np.int64)
    hi_r = np.full(nb, -reach - 1, np.int64)
    lo_c = np.full(nb, w + reach, np.int64)
    hi_c = np.full(nb, -reach - 1, np.int64)
    for i in range(prow.shape[0]):
        b = pbins[i]
        lo_r[b] = min(lo_r[b], prow[i])
        hi_r[b] = max(hi_r[b], prow[i])
        lo_c[b] = min(lo_c[b], pcol[i])
        hi_c[b] = max(hi_c[b], pcol[i])
    for b in range(nb):
        if hi_r[b] < lo_r[b]:
            continue
        r0, r1 = max(lo_r[b] - reach, 0), min(hi_r[b] + reach + 1, h)
        c0, c1 = max(lo_c[b] - reach, 0), min(hi_c[b] + reach + 1, w)
        if r1 <= r0 or c1 <= c0:
            continue
        edges = np.zeros((r1 - r0, c1 - c0), np.bool_)
        some = False
        for i in range(rows.shape[0]):
            apart = (ebins[i] - b) % nb
            if (apart <= 1 or apart == nb - 1) and r0 <= rows[i] < r1 and c0 <= cols[i] < c1:
                edges[rows[i] - r0, cols[i] - c0] = True
                some = True
        if not some:
            continue
        if cap <= _CAPPED_MAP_MOST:  # by passes along the rows (stop 64, reg64: the same values)
            _capped_map(edges, cap, dist[b, m + r0 : m + r1, m + c0 : m + c1])
            continue
        away = np.empty((r1 - r0, c1 - c0))
        near_distance(edges, cap, True, away)
        for r in range(r1 - r0):
            for c in range(c1 - c0):
                v = away[r, c]
                dist[b, m + r0 + r, m + c0 + c] = np.float32(v if v < cap else cap)


#: :func:`capped_distances`' largest cap for :func:`_capped_map` (a table of ``(floor(cap) + 1) ** 2 + 1`` values a
#: map; 32-bit squared distances); a larger one takes :func:`near_distance` (the same values).
_CAPPED_MAP_MOST = 64.0


@_njit_inlined
def _capped_map(edges: np.ndarray, cap: float, out: np.ndarray) -> None:
    """:func:`capped_distances`' map of one bin: ``out`` (h, w) float32 each pixel's distance to the nearest pixel of
    ``edges`` (h, w) bool, capped at ``cap``: :func:`near_distance`'s of reach ``cap``, then capped as a float32, to
    the bit (stop 64, reg64).

    The same whole-number squared distances as :func:`near_distance`'s (each column's distance to its nearest edge
    pixel, capped at ``floor(cap) + 1``, by two sweeps; then the least of ``g + t * t`` over the columns within
    ``floor(cap)``), but its row search, which branched at every pixel (its early ends skip only terms that cannot be
    less), is here ``2 floor(cap)`` plain passes along the row, one a column offset and side, each a running least
    that numba vectorises (the same least: whole numbers, the same terms); the columns' distances in 32 bits. Each
    squared distance then reads its value from a table made once a map: ``sqrt(d)`` where ``d <= cap * cap`` (else
    +inf), then ``cap`` where not less, as a float32, as :func:`capped_distances` took it from
    :func:`near_distance`. ``cap`` at most :data:`_CAPPED_MAP_MOST`. The passes' indices all count up from 0 (``best[c
    + t]`` from ``g[c]``): written as ``g[c - t]``, numba's test for a negative index kept the loop from vectorising,
    at twice the time."""
    h, w = edges.shape
    k = math.floor(cap)
    top = k + 1
    top2 = top * top
    limit = cap * cap
    table = np.empty(top2 + 1, np.float32)
    for d in range(top2 + 1):
        v = math.sqrt(float(d)) if d <= limit else np.inf
        table[d] = np.float32(v if v < cap else cap)
    g2 = np.empty((h, w), np.int32)
    last = np.empty(w, np.int32)
    last[:] = -top
    for r in range(h):
        rr = np.int32(r)
        cut = np.int32(top)
        for c in range(w):
            lc = rr if edges[r, c] else last[c]
            last[c] = lc
            g2[r, c] = min(rr - lc, cut)
    last[:] = h - 1 + top
    for r in range(h - 1, -1, -1):
        rr = np.int32(r)
        for c in range(w):
            lc = rr if edges[r, c] else last[c]
            last[c] = lc
            d = min(g2[r, c], lc - rr)
            g2[r, c] = d * d
    best = np.empty(w, np.int32)
    for r in range(h):
        g = g2[r]
        for c in range(w):
            best[c] = g[c]  # at most top2: the column's own term, and no term beyond the cap counts
        for t in range(1, min(k, w - 1) + 1):
            tt = np.int32(t * t)
            for c in range(w - t):
                best[c + t] = min(best[c + t], g[c] + tt)
            for c in range(w - t):
                best[c] = min(best[c], g[c + t] + tt)
        o = out[r]
        for c in range(w):
            o[c] = table[best[c]]


@_njit_inlined
def _across(s: np.ndarray, r: int, left: int, c: int, right: int) -> float:
    """``correlate1d(s, [-1, 0, 1], 1)`` at ``(r, c)``, its neighbours' columns given: scipy's antisymmetric sum."""
    v = s[r, c] * 0.0
    v += (s[r, left] - s[r, right]) * -1.0
    return v


@_njit_inlined
def _down(s: np.ndarray, up: int, r: int, down: int, c: int) -> float:
    """``correlate1d(s, [-1, 0, 1], 0)`` at ``(r, c)``, its neighbours' rows given."""
    v = s[r, c] * 0.0
    v += (s[up, c] - s[down, c]) * -1.0
    return v


@_njit
def outline_gradient(
    labels: np.ndarray, k: int, r0: int, r1: int, c0: int, c1: int, weights: np.ndarray, symmetric: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`symfruit.core.edges._outline_samples` of one mask, ``labels == k`` within ``[r0:r1, c0:c1]``: its outline
    pixels (the mask's pixels with a 4-neighbour in the box outside it, ``ndimage.binary_erosion``'s cross with
    ``border_value=1``) in row-major order, their rows and columns (the box's), and the gradient of the mask smoothed
    by ``weights`` (``ndimage.gaussian_filter``'s, ``symmetric`` as scipy finds them; along the columns then the
    rows, :func:`_smoothed`) at them: ``ndimage.sobel``'s along the columns ``gx`` and the rows ``gy``, worked out
    at the outline pixels alone in scipy's order and mode "reflect" (as :func:`colour_gradient`'s): the twin's values
    to the bit."""
    h, w = r1 - r0, c1 - c0
    inside = np.empty((h, w))
    for r in range(h):
        for c in range(w):
            inside[r, c] = 1.0 if labels[r0 + r, c0 + c] == k else 0.0
    count = 0
    edge = np.zeros((h, w), np.bool_)
    for r in range(h):
        for c in range(w):
            if inside[r, c] == 0.0:
                continue
            if (r > 0 and inside[r - 1, c] == 0.0) or (r + 1 < h and inside[r + 1, c] == 0.0) or (
                    c > 0 and inside[r, c - 1] == 0.0) or (c + 1 < w and inside[r, c + 1] == 0.0):  # fmt: skip
                edge[r, c] = True
                count += 1
    rows = np.empty(count, np.int64)
    cols = np.empty(count, np.int64)
    gx = np.empty(count)
    gy = np.empty(count)
    if count == 0:
        return rows, cols, gx, gy
    s = _smoothed(inside, weights, symmetric)
    i = 0
    for r in range(h):
        for c in range(w):
            if not edge[r, c]:
                continue
            # sobel(axis=1): [-1, 0, 1] along the rows r - 1, r, r + 1 (reflected), then [1, 2, 1] across them;
            # sobel(axis=0): [-1, 0, 1] down the columns c - 1, c, c + 1, then [1, 2, 1] along them
            up, down = _reflected(r - 1, h), _reflected(r + 1, h)
            left, right = _reflected(c - 1, w), _reflected(c + 1, w)
            x = _across(s, r, left, c, right) * 2.0
            x += (_across(s, up, left, c, right) + _across(s, down, left, c, right)) * 1.0
            y = _down(s, up, r, down, c) * 2.0
            y += (_down(s, up, r, down, left) + _down(s, up, r, down, right)) * 1.0
            rows[i], cols[i], gx[i], gy[i] = r, c, x, y
            i += 1
    return rows, cols, gx, gy


@_njit
def padded_costs(
    dist: np.ndarray, rows: np.ndarray, cols: np.ndarray, bins: np.ndarray, m: int, out: np.ndarray
) -> None:
    """:func:`symfruit.core.edges._padded_costs` into ``out`` (2m+1, 2m+1, n): each point's ``(2m+1, 2m+1)`` window
    of its bin's map ``dist`` (padded by ``m``; ``rows, cols`` the padded maps' own), copied a point at a time along
    the map's rows instead of gathered through a strided view and transposed: the same values."""
    s = 2 * m + 1
    for p in range(rows.shape[0]):
        b, r, c = bins[p], rows[p] - m, cols[p] - m
        for i in range(s):
            row = dist[b, r + i]
            for j in range(s):
                out[i, j, p] = row[c + j]


# --- stop 65, cand65: the outline's radii of a solid of revolution in one call --------------------------------------


@_njit
def outline_radii(
    point: np.ndarray, axis: np.ndarray, edges: np.ndarray, fx: float, fy: float, cx: float, cy: float,
    s: np.ndarray, u0: float, v0: float, mask: np.ndarray, hidden: np.ndarray, use_hidden: bool, step: float,
) -> np.ndarray:  # fmt: skip
    """:func:`symfruit.core.fits.outline_radii` (its walks :func:`symfruit.core.fits._first_out`) for the solid's
    ``point`` (3,), its (squashed) ``axis`` (3,) and slice borders ``edges`` (b + 1,), the camera's intrinsics, the
    walk's steps ``s`` (m,) (``np.arange(step, reach, step)``), the window's corner ``u0``, ``v0`` and ``mask`` (h,
    w) bool, and ``hidden`` (h, w) bool where ``use_hidden``: each slice's radius (b,), the twin's values to the bit
    (issue 19, stop 65, cand65: some 40 numpy calls on (b,) and (b, m) arrays each a few microseconds, one call here).

    Each value is the twin's expression in the same order: the ring's centre ``point + mid axis``, the cross product
    and the norms as :func:`~symfruit.core.points.cross_rows` and :func:`~symfruit.core.points.row_norms` make them
    (the squares summed left to right, numpy's order on an axis of 3), the projections as
    :meth:`~symfruit.core.camera.Camera.project`'s, each walk's steps rounded half to even (a coordinate numpy's
    integer conversion cannot hold becomes its smallest integer, off the window, as there), its first step out of the
    mask (or off the window) and that step's pixel, else step 0's, and the least squares' sums of three products left
    to right, as numpy sums a row of three."""
    b = edges.shape[0] - 1
    h, w = mask.shape
    m = s.shape[0]
    big = 9.223372036854775808e18  # 2^63
    least = np.int64(-9223372036854775808)
    radii = np.empty(max(b, 0))
    found = np.empty(2)
    for j in range(b):
        mid = 0.5 * (edges[j] + edges[j + 1])
        c0 = point[0] + mid * axis[0]
        c1 = point[1] + mid * axis[1]
        c2 = point[2] + mid * axis[2]
        e0 = axis[1] * c2 - axis[2] * c1
        e1 = axis[2] * c0 - axis[0] * c2
        e2 = axis[0] * c1 - axis[1] * c0
        norm = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        norm = 1e-12 if norm < 1e-12 else norm  # np.maximum's: NaN kept
        e0, e1, e2 = e0 / norm, e1 / norm, e2 / norm
        inv_z = 1.0 / c2
        uu = fx * c0 * inv_z + cx
        vv = fy * c1 * inv_z + cy
        p0, p1, p2 = c0 + 1e-3 * e0, c1 + 1e-3 * e1, c2 + 1e-3 * e2
        inv_p = 1.0 / p2
        du = (fx * p0 * inv_p + cx) - uu
        dv = (fy * p1 * inv_p + cy) - vv
        norm = math.sqrt(du * du + dv * dv)
        norm = 1e-12 if norm < 1e-12 else norm
        du, dv = du / norm, dv / norm
        for side in range(2):
            sign = 1.0 if side == 0 else -1.0
            wu, wv = (du, dv) if side == 0 else (-du, -dv)
            start = inside = False
            first = -1
            row = col = np.int64(0)
            for k in range(m):
                fu = np.rint(uu + s[k] * wu - u0)
                fv = np.rint(vv + s[k] * wv - v0)
                cc = np.int64(fu) if -big <= fu < big else least
                rr = np.int64(fv) if -big <= fv < big else least
                within = cc >= 0 and cc < w and rr >= 0 and rr < h
                hit = within and mask[rr, cc]
                if k == 0:
                    start, row, col, inside = hit, rr, cc, within
                if not hit:
                    first, row, col, inside = k, rr, cc, within
                    break
            ok = start and first >= 0 and inside
            first = max(first, 0)
            if use_hidden and hidden[min(max(row, 0), h - 1), min(max(col, 0), w - 1)]:
                ok = False
            edge_px = (first - 0.5) * step
            bu = uu + sign * edge_px * du
            bv = vv + sign * edge_px * dv
            x = (bu - cx) / fx
            y = (bv - cy) / fy
            a11 = e0 * e0 + e1 * e1 + e2 * e2
            a12 = -(e0 * x + e1 * y + e2 * 1.0)
            a22 = x * x + y * y + 1.0 * 1.0
            b1 = -(e0 * c0 + e1 * c1 + e2 * c2)
            b2 = x * c0 + y * c1 + 1.0 * c2
            det = a11 * a22 - a12 * a12
            sv = (a22 * b1 - a12 * b2) / (det if abs(det) > 1e-18 else math.nan)
            found[side] = sign * sv if ok else math.nan
        f0, f1 = found[0], found[1]
        r = 0.5 * (f0 + f1) if math.isfinite(f0) and math.isfinite(f1) else math.nan
        radii[j] = r if r > 0 else math.nan
    return radii


@_njit
def revolution_points(pts: np.ndarray, every: int) -> tuple[bool, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`symfruit.core.fits.fit_revolution_slices`' points before its search, for C-ordered (n, 3) float64
    ``pts`` (issue 19, stop 65, cand65): ``(True, centre (3,), q (n, 3), qs (m, 3))``, the centre
    (:func:`column_means`), the points less it and every ``every``-th of those (``q[::every]``, C-ordered: the
    search's argument), or ``(False, ...)`` where a coordinate is not finite (the caller then drops those rows as
    before). One call for ``np.isfinite(pts).all()``, the mean, the difference and the copy."""
    n = pts.shape[0]
    for i in range(n):
        if not (math.isfinite(pts[i, 0]) and math.isfinite(pts[i, 1]) and math.isfinite(pts[i, 2])):
            return False, np.empty(0), np.empty((0, 3)), np.empty((0, 3))
    centre = column_means(pts)
    q = np.empty((n, 3))
    for i in range(n):
        q[i, 0] = pts[i, 0] - centre[0]
        q[i, 1] = pts[i, 1] - centre[1]
        q[i, 2] = pts[i, 2] - centre[2]
    qs = np.empty(((n + every - 1) // every, 3))
    for i in range(qs.shape[0]):
        qs[i, 0], qs[i, 1], qs[i, 2] = q[i * every, 0], q[i * every, 1], q[i * every, 2]
    return True, centre, q, qs


# --- issue 19, stop 65 (glue65): outline_circle's elementwise glue ---


@_njit
def circle_design(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """:func:`symfruit.core.raster.outline_circle`'s points about their mean, for a C-ordered (n, 2) float64 ``p``,
    ``n >= 1``: ``(mu (2,), x (n,), y (n,), z (n,), mean(z))``, ``mu`` :func:`column_means`, ``x, y`` the coordinates
    less it, ``z = x x + y y`` and its mean by numpy's pairwise sum: the values of ``p[:, 0] - mu[0]``, ``x * x + y *
    y`` and ``z.mean()`` bit for bit, in one call (seven numpy calls before)."""
    n = p.shape[0]
    mu = column_means(p)
    x = np.empty(n)
    y = np.empty(n)
    z = np.empty(n)
    for i in range(n):
        a, b = p[i, 0] - mu[0], p[i, 1] - mu[1]
        x[i], y[i] = a, b
        z[i] = a * a + b * b
    return mu, x, y, z, (0.0 + _pairwise_sum(z, 0, n)) / n


@_njit
def circle_mean_square(x: np.ndarray, y: np.ndarray, cu: float, cv: float, r: float) -> float:
    """:func:`symfruit.core.raster.outline_circle`'s mean squared distance of the points ``(x, y)`` (n,) from the
    circle about ``(cu, cv)`` of radius ``r``, ``n >= 1``: ``off = np.sqrt((x - cu) ** 2 + (y - cv) ** 2) - r`` and
    ``(off * off).mean()`` (numpy's pairwise sum), the same value bit for bit in one call (eight numpy calls before)."""
    n = x.shape[0]
    sq = np.empty(n)
    for i in range(n):
        du, dv = x[i] - cu, y[i] - cv
        off = math.sqrt(du * du + dv * dv) - r
        sq[i] = off * off
    return (0.0 + _pairwise_sum(sq, 0, n)) / n
