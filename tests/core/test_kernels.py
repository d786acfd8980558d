"""The compiled kernels (numba, the extra ``fast``) against their numpy twins in ``symfruit.core.fits``,
``symfruit.core.raster`` and ``symfruit.core.occlusion``, seeded and property-tested; the switch to the twins
(``SYMFRUIT_KERNELS=numpy``, no numba); no compilation at import.

The fits' kernels sum in another order than numpy, so they agree with the twins to rounding, not to the bit; a fit
iterates on its sums, so whole fits are compared to a nanometre (the evaluation's rule is 0.1 mm). The pixel maps'
kernels (whole numbers, booleans) are compared to the bit.
"""

import math
import os
import subprocess
import sys
import types

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from symfruit.core import kernels
from symfruit.core.fits import _slice_costs, fit_cone_ellipsoid, fit_revolution_slices, fit_sphere
from symfruit.synthetic.shapes import FRUITS, rotation

from ..conftest import CENTRE, random_sphere, rendered_view

numba = pytest.importorskip("numba")
from symfruit.core import _jit  # noqa: E402  (numba is there: the module may be imported)


def _both(monkeypatch, fn, *args, **kwargs):
    """``fn(*args, **kwargs)`` with the kernels, then with the numpy twins."""
    monkeypatch.delenv("SYMFRUIT_KERNELS", raising=False)  # a run with the twins throughout still compares
    compiled = fn(*args, **kwargs)
    monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    twin = fn(*args, **kwargs)
    monkeypatch.delenv("SYMFRUIT_KERNELS")
    return compiled, twin


# --- the switch -------------------------------------------------------------------------------------------


def test_the_environment_switches_to_the_numpy_twins(monkeypatch):
    monkeypatch.delenv("SYMFRUIT_KERNELS", raising=False)
    assert kernels.compiled() is _jit
    for value in ("numpy", "NumPy"):
        monkeypatch.setenv("SYMFRUIT_KERNELS", value)
        assert kernels.compiled() is None
    monkeypatch.setenv("SYMFRUIT_KERNELS", "")
    assert kernels.compiled() is _jit


def test_without_numba_the_twins_run(monkeypatch):
    """numba missing (or unusable with this numpy): no kernels, and every fit still works (its twin)."""
    import symfruit.core

    monkeypatch.setattr(kernels, "_STATE", {})
    monkeypatch.delattr(symfruit.core, "_jit")
    monkeypatch.setitem(sys.modules, "symfruit.core._jit", None)  # `from . import _jit` raises ImportError
    assert kernels.compiled() is None
    centre, radius = fit_sphere(random_sphere(200, seed=1))
    assert np.allclose(centre, CENTRE) and radius == pytest.approx(0.03)


def test_importing_symfruit_compiles_nothing():
    code = "import sys, symfruit, symfruit.core.fits, symfruit.detect; print('numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=600)
    assert out.stdout.strip() == "False"


def test_no_writable_cache_directory_compiles_without_a_cache(monkeypatch):
    """numba raises when it finds no directory to cache in (a read-only install and home): the kernel is then
    compiled without the cache instead of failing."""
    calls = []

    def njit(**options):
        calls.append(options)
        if options.get("cache"):
            raise RuntimeError("cannot cache function: no locator available")
        return lambda func: ("compiled", func)

    monkeypatch.setattr(_jit, "numba", types.SimpleNamespace(njit=njit))
    assert _jit._njit(len) == ("compiled", len)
    assert [c.get("cache", False) for c in calls] == [True, False]


# --- small helpers ----------------------------------------------------------------------------------------


@given(st.integers(0, 2**32 - 1), st.integers(1, 300), st.booleans())
def test_select_partitions_in_place(seed, n, ties):
    rng = np.random.default_rng(seed)
    x = rng.normal(size=n)
    if ties:
        x = np.round(x * 2.0)
    kth = int(rng.integers(n))
    y = x.copy()
    _jit.select(y, kth)
    assert np.array_equal(np.sort(y), np.sort(x))  # a permutation
    assert y[kth] == np.sort(x)[kth]
    assert (y[:kth] <= y[kth]).all() and (y[kth + 1 :] >= y[kth]).all()


@given(st.integers(0, 2**32 - 1), st.integers(1, 700), st.sampled_from(["normal", "ties", "sorted", "reversed",
                                                                        "equal", "heavy"]))  # fmt: skip
def test_kth_smallest_is_the_partitions(seed, n, kind):
    rng = np.random.default_rng(seed)
    x = {"normal": rng.normal(size=n), "ties": rng.integers(0, 4, n).astype(float), "sorted": np.sort(rng.random(n)),
         "reversed": np.sort(rng.random(n))[::-1].copy(), "equal": np.full(n, 0.25),
         "heavy": rng.standard_exponential(n) ** 4}[kind]  # fmt: skip
    before = x.copy()
    for kth in {0, n - 1, int(rng.integers(n)), max(0, int(0.8 * n) - 1)}:
        assert _jit.kth_smallest(x, kth, np.empty(n), np.empty(n)) == np.partition(x, kth)[kth]
    assert np.array_equal(x, before)  # left as it was


@given(st.integers(0, 2**32 - 1), st.integers(1, 600), st.booleans())
def test_smallest_mean_is_the_mean_of_a_partitions_first_places(seed, n, ties):
    rng = np.random.default_rng(seed)
    x = rng.standard_exponential(n) ** 2
    if ties:
        x = np.round(x, 1)
    keep = int(rng.integers(1, n + 1))
    want = np.partition(x, keep - 1)[:keep].mean()
    assert _jit.smallest_mean(x, keep, np.empty(n), np.empty(n)) == pytest.approx(want, rel=1e-13, abs=1e-300)


@given(st.integers(0, 2**32 - 1), st.integers(1, 5))
def test_solve_is_numpys_solve(seed, n):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(n, n)) + n * np.eye(n) * rng.choice([-1.0, 1.0])
    b = rng.normal(size=n)
    x = np.empty(n)
    assert _jit.solve(a.copy(), b.copy(), x)
    np.testing.assert_allclose(x, np.linalg.solve(a, b), rtol=1e-9, atol=1e-12)


def test_solve_refuses_a_singular_matrix():
    x = np.full(3, 7.0)
    assert not _jit.solve(np.array([[1.0, 2.0, 0.0], [2.0, 4.0, 0.0], [0.0, 0.0, 1.0]]), np.ones(3), x)
    assert (x == 7.0).all()


# --- the solid of revolution ------------------------------------------------------------------------------


@given(st.integers(0, 2**32 - 1), st.integers(1, 90), st.integers(60, 300))
def test_slice_costs_are_the_twins(seed, k, n):
    """At five points a slice or more, as the fit's 240 in 12 (with a point or two per slice the 2x2 system is
    singular and both costs are rounding noise amplified by the determinant's floor)."""
    rng = np.random.default_rng(seed)
    scale = rng.uniform(0.001, 0.1)
    q = rng.normal(size=(n, 3)) * scale
    q[: n // 3] = np.round(q[: n // 3], 3)  # repeated coordinates: ties in the slices and the partition
    dirs = rng.normal(size=(k, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    fast, twin = _jit.slice_costs(q, dirs, 12), _slice_costs(q, dirs, 12)
    np.testing.assert_allclose(fast, twin, rtol=1e-7, atol=1e-12 * scale**2)


@given(st.integers(0, 2**32 - 1), st.integers(30, 400), st.integers(0, 6), st.integers(0, 2))
def test_revolution_search_is_the_searchs_steps(seed, n, extra, refine):
    """The search in one call: the coarse directions' least cost, then each cap's about the best so far, as the
    twin's loop takes them (each cap's rows within rounding: BLAS may sum the twin's product otherwise)."""
    from symfruit.core.fits import _COARSE, _cap, _cap_locals

    rng = np.random.default_rng(seed)
    points = FRUITS["pear"](rng).sample(2 * n, rng) @ rotation(*rng.uniform(0.0, 360.0, 3)).T
    q = points[points[:, 2] <= np.median(points[:, 2])]  # the half nearer a camera looking along +z
    q = np.ascontiguousarray(q - q.mean(axis=0))
    more = rng.normal(size=(extra, 3))
    more /= np.linalg.norm(more, axis=1, keepdims=True)
    dirs = np.ascontiguousarray(np.vstack([_COARSE, more * np.where(more[:, 2:3] < 0, -1.0, 1.0)]))
    spreads = (12.0, 4.0, 1.5)[:refine]
    best = dirs[int(np.argmin(_jit.slice_costs(q, dirs, 12)))]
    for spread in spreads:
        cand = _cap(best, spread, 16)
        best = cand[int(np.argmin(_jit.slice_costs(q, cand, 12)))]
    found = _jit.revolution_search(q, dirs, 12, _cap_locals(spreads, 16))
    np.testing.assert_allclose(found, best, atol=1e-14)


@pytest.mark.parametrize("kind,seed", [("strawberry", 0), ("apple", 1), ("pear", 2), ("lemon", 3), ("citrus", 4)])
def test_revolution_fit_is_the_twins(monkeypatch, kind, seed):
    fruit = FRUITS[kind](np.random.default_rng(seed))
    visible, _ = rendered_view(fruit, [0.01 * seed, -0.01, 0.35 + 0.02 * seed], noise=0.002 * (seed % 3),
                               rotation=rotation(10 * seed, 20, 30 * seed), seed=seed)  # fmt: skip
    fast, twin = _both(monkeypatch, fit_revolution_slices, visible)
    np.testing.assert_allclose(fast.direction, twin.direction, atol=1e-12)
    np.testing.assert_allclose(fast.point, twin.point, atol=1e-9)  # a nanometre
    np.testing.assert_allclose(fast.radii, twin.radii, atol=1e-9)
    np.testing.assert_allclose(fast.edges, twin.edges, atol=1e-9)
    assert fast.cost == pytest.approx(twin.cost, rel=1e-6)


@given(st.integers(0, 2**32 - 1), st.integers(20, 400), st.floats(0.0, 0.003))
def test_revolution_profile_is_the_twins(seed, n, noise):
    """The profile about a given direction (its algebraic start, Gauss-Newton, slices and cost) of a noisy
    circular cylinder's visible side, tilted at random."""
    from symfruit.core.fits import _revolution_profile
    from symfruit.core.points import perpendicular_basis

    rng = np.random.default_rng(seed)
    phi, h = rng.uniform(-1.2, 1.2, n), rng.uniform(-0.03, 0.03, n)
    radius = rng.uniform(0.01, 0.04)
    local = np.c_[radius * np.sin(phi), h, -radius * np.cos(phi)] + rng.normal(scale=noise, size=(n, 3))
    rot, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    q = local @ rot.T
    q -= q.mean(axis=0)
    best = rot[:, 1] + rng.normal(scale=0.02, size=3)  # about the axis, as the search leaves it
    best /= np.linalg.norm(best)
    e1, e2 = perpendicular_basis(best[None, :])
    fast = _jit.revolution_profile(q, best, e1[0], e2[0], 16, 5)
    twin = _revolution_profile(q, best, e1[0], e2[0], 16, 5)
    assert fast[4] and twin[4]
    np.testing.assert_allclose(fast[0], twin[0], atol=1e-10)
    np.testing.assert_allclose(fast[1], twin[1], atol=1e-15)
    np.testing.assert_allclose(fast[2], twin[2], atol=1e-10)
    assert fast[3] == pytest.approx(twin[3], rel=1e-6, abs=1e-18)


def _revolution_steps_fused(w, which, cnt, a2, steps):
    """The kernel's Gauss-Newton as it was until stop 65 (each point's distance and its slices' sums in one loop),
    in Python floats: the values the kernel's split loops (rev65) must give to the bit."""
    n, b = len(w), len(cnt)
    w, which, cnt = w.tolist(), which.tolist(), cnt.tolist()
    for _ in range(steps):
        sums = [[0.0] * b for _ in range(3)]
        rho, j0, j1 = [0.0] * n, [0.0] * n, [0.0] * n
        for i in range(n):
            d0, d1 = w[i][0] - a2[0], w[i][1] - a2[1]
            r = max(math.sqrt(d0 * d0 + d1 * d1), 1e-12)
            rho[i], j0[i], j1[i] = r, -d0 / r, -d1 / r
            s = which[i]
            sums[0][s] += r
            sums[1][s] += j0[i]
            sums[2][s] += j1[i]
        means = [[sums[k][s] / cnt[s] for s in range(b)] for k in range(3)]
        a11 = a12 = a22 = g0 = g1 = 0.0
        for i in range(n):
            s = which[i]
            res, x0, x1 = rho[i] - means[0][s], j0[i] - means[1][s], j1[i] - means[2][s]
            a11 += x0 * x0
            a12 += x0 * x1
            a22 += x1 * x1
            g0 -= x0 * res
            g1 -= x1 * res
        if abs(a11 * a22 - a12 * a12) < 1e-30:
            break
        step = np.empty(2)
        if not _jit.solve(np.array([[a11, a12], [a12, a22]]), np.array([g0, g1]), step):
            break
        a2[0] += step[0]
        a2[1] += step[1]
        if max(abs(step[0]), abs(step[1])) < 1e-7:
            break


@settings(max_examples=150)
@given(st.integers(0, 2**32 - 1), st.integers(1, 300), st.integers(1, 16), st.integers(0, 6))
def test_the_revolution_steps_kernel_is_its_fused_loop_to_the_bit(seed, n, bins, steps):
    """rev65 split the kernel's Gauss-Newton loop (the distances, then the slices' sums): the same axis position,
    bit for bit, as the former fused loop, for points about an axis off the start, slices some of them empty, and
    a start on a point (its distance taken as 1e-12)."""
    rng = np.random.default_rng(seed)
    phi = rng.uniform(-np.pi, np.pi, n)
    w = np.c_[np.cos(phi), np.sin(phi)] * rng.uniform(0.01, 0.04, (n, 1)) + rng.normal(scale=0.003, size=(n, 2))
    which = rng.integers(0, bins, n)
    cnt = np.maximum(np.bincount(which, minlength=bins), 1).astype(np.float64)
    start = w[0].copy() if seed % 5 == 0 else rng.normal(scale=0.005, size=2)
    fast, slow = start.copy(), start.tolist()
    _jit.revolution_steps(w, which, cnt, fast, steps)
    _revolution_steps_fused(w, which, cnt, slow, steps)
    assert fast.tobytes() == np.array(slow).tobytes()


@given(st.integers(0, 2**32 - 1), st.integers(20, 400))
def test_the_revolution_profile_kernels_radii_are_the_fused_loops(seed, n):
    """The profile's radii (each slice's mean distance from the axis it found, the distances worked out apart from
    their sums since rev65) to the bit: the distances from the axis and their sums in the points' order, in Python
    floats, from the kernel's own plane coordinates and slices."""
    rng = np.random.default_rng(seed)
    phi, h = rng.uniform(-1.2, 1.2, n), rng.uniform(-0.03, 0.03, n)
    q = np.c_[0.03 * np.sin(phi), h, -0.03 * np.cos(phi)] + rng.normal(scale=0.002, size=(n, 3))
    q -= q.mean(axis=0)
    best, e1, e2 = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
    a2, edges, radii, _, ok = _jit.revolution_profile(q, best, e1, e2, 16, 5)
    assert ok
    t = q @ best
    which = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, 15).tolist()
    total, count = [0.0] * 16, [0] * 16
    for p, s in zip(q.tolist(), which, strict=True):
        u, v = p[0] * e1[0] + p[1] * e1[1] + p[2] * e1[2], p[0] * e2[0] + p[1] * e2[1] + p[2] * e2[2]
        d0, d1 = u - a2[0], v - a2[1]
        total[s] += math.sqrt(d0 * d0 + d1 * d1)
        count[s] += 1
    want = [total[s] / max(count[s], 1) if count[s] >= 3 else math.nan for s in range(16)]
    assert radii.tobytes() == np.array(want).tobytes()


def test_revolution_profile_of_points_on_a_line_leaves_it_to_the_twin():
    """Every point on the axis: the algebraic start's 2x2 system is singular; the kernel says so (the twin's
    least squares takes its minimum-norm solution) and fit_revolution_slices runs the twin."""
    from symfruit.core.fits import _revolution_profile

    q = np.c_[np.zeros(30), np.linspace(-0.02, 0.02, 30), np.zeros(30)]
    best, e1, e2 = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
    assert not _jit.revolution_profile(q, best, e1, e2, 16, 5)[4]
    a2, _, radii, cost, _ = _revolution_profile(q, best, e1, e2, 16, 5)
    assert np.allclose(a2, 0.0) and np.allclose(radii[np.isfinite(radii)], 0.0) and cost == pytest.approx(0.0)


# --- the sphere -------------------------------------------------------------------------------------------


@given(st.integers(0, 2**32 - 1), st.floats(0.01, 0.06), st.floats(0.0, 0.002), st.floats(20.0, 90.0))
def test_sphere_fit_is_the_twins(seed, radius, noise, cap_deg):
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(400, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    d = d[d[:, 2] < -np.cos(np.radians(cap_deg))]
    if len(d) < 20:
        return
    pts = radius * d + CENTRE + rng.normal(scale=noise, size=d.shape)
    with pytest.MonkeyPatch.context() as mp:
        (c, r), (c_twin, r_twin) = _both(mp, fit_sphere, pts)
    assert np.linalg.norm(c - c_twin) < 1e-9 and abs(r - r_twin) < 1e-9


def test_sphere_steps_of_an_exact_sphere_stay_on_it():
    pts = random_sphere(300, radius=0.04, seed=2) - CENTRE
    c = np.array([0.003, -0.002, 0.001])
    r, ok = _jit.sphere_steps(pts, c, 0.035, 20, 1e-12, 1.0)
    assert ok and r == pytest.approx(0.04, abs=1e-12)
    np.testing.assert_allclose(c, 0.0, atol=1e-12)


def test_sphere_steps_report_a_singular_system():
    """Every point at the centre: the Jacobian's direction columns are zero, the normal equations singular."""
    c = np.zeros(3)
    _, ok = _jit.sphere_steps(np.zeros((10, 3)), c, 1.0, 5, 1e-7, 1.0)
    assert not ok


# --- the cone ellipsoid -----------------------------------------------------------------------------------


def _cone_view(kind: str, seed: int, noise: float = 0.01, turn: tuple[float, float, float] | None = None):
    from symfruit import DEFAULT_CAMERA
    from symfruit.core.raster import silhouette, silhouette_cone

    fruit = FRUITS[kind](np.random.default_rng(seed))
    turn = (10 * seed, 20, 30 * seed) if turn is None else turn
    visible, _ = rendered_view(fruit, [0.01 * seed, -0.01, 0.35 + 0.03 * seed], noise=noise, rotation=rotation(*turn),
                               seed=seed)  # fmt: skip
    cone, axis = silhouette_cone(silhouette(visible, DEFAULT_CAMERA), DEFAULT_CAMERA)
    return visible, cone, axis, float(visible[:, 2].min()), float(np.ptp(visible, axis=0).max())


@given(st.integers(0, 2**32 - 1))
def test_cone_residuals_are_the_twins(seed):
    """Shape parameters within the fit's reach (its grid spans -4..4): beyond about 20 the logistic's gap
    ``lambda - q`` has lost its digits and a ray near tangency may hit in one path and miss in the other."""
    from symfruit.core.fits import _cone_fronts

    visible, cone, axis, _, _ = _cone_view("apple", 1)
    rng = np.random.default_rng(seed)
    pts = visible[rng.choice(len(visible), 50, replace=False)]
    rays, z = pts / pts[:, 2:3], np.ascontiguousarray(pts[:, 2])
    ray_cone = ((rays @ cone) * rays).sum(axis=1)
    params = np.c_[rng.normal(0.0, 0.02, (30, 2)), np.log(rng.uniform(0.2, 0.8, 30)), rng.uniform(-10, 10, 30)]
    params[0, 3] = 60.0  # a saturated logistic: no front on any ray (the twin's NaN rows)
    params[1, :2] = 1.0  # a centre outside the cone: no ellipsoid (the twin's invalid rows)
    fronts, valid = _cone_fronts(params, cone, axis, rays, ray_cone)
    twin = np.where(valid[:, None], z[None, :] - fronts, 0.05)
    twin = np.where(np.isfinite(twin), twin, 0.02)
    out = np.empty_like(twin)
    _jit.cone_residuals(params, cone, axis, rays, ray_cone, z, out)
    np.testing.assert_allclose(out, twin, atol=1e-8)  # 10 nm: the front's root cancels a few digits
    assert (out[0] == 0.02).all() and (out[1] == 0.05).all()
    assert _jit.huber_cost(out[2], 0.003) == pytest.approx(
        np.where(np.abs(out[2]) <= 0.003, 0.5 * out[2] ** 2, 0.003 * (np.abs(out[2]) - 0.0015)).sum(), rel=1e-12
    )


@given(st.integers(0, 2**32 - 1))
def test_cone_shape_is_cone_ellipsoid(seed):
    from symfruit.core.fits import cone_ellipsoid

    _, cone, axis, _, _ = _cone_view("pear", 2)
    rng = np.random.default_rng(seed)
    p = np.array([*rng.normal(0.0, 0.05, 2), np.log(rng.uniform(0.2, 0.8)), rng.uniform(-60, 60)])
    m, shape, valid = cone_ellipsoid(p[None], cone, axis)
    got_m, got_shape = np.empty(3), np.empty((3, 3))
    assert _jit._cone_shape(p, cone, axis, np.linalg.inv(cone), got_m, got_shape) == valid[0]
    np.testing.assert_allclose(got_m, m[0], rtol=1e-14)
    np.testing.assert_allclose(got_shape, shape[0], rtol=1e-9, atol=1e-15)  # NaN where invalid, in both


_CONE_VIEWS = [(kind, seed) for kind in ("strawberry", "apple", "pear", "lemon", "plum", "banana") for seed in range(3)]


@pytest.mark.parametrize("kind,seed", _CONE_VIEWS)
def test_cone_fit_is_the_twins(monkeypatch, kind, seed):
    visible, cone, axis, front, extent = _cone_view(kind, seed, turn=(10 * seed + 7, 20 + 13 * seed, 30 * seed))
    fast, twin = _both(monkeypatch, fit_cone_ellipsoid, visible, cone=cone, axis=axis, front=front, extent=extent)
    np.testing.assert_allclose(fast.centre, twin.centre, rtol=0, atol=1e-9)  # a nanometre (measured: under 4e-12)
    np.testing.assert_allclose(np.sqrt(np.diag(fast.shape)), np.sqrt(np.diag(twin.shape)), rtol=0, atol=1e-9)
    assert fast.back_std == pytest.approx(twin.back_std, rel=1e-6) and fast.rms == pytest.approx(twin.rms, rel=1e-6)


def test_cone_fit_at_the_thickness_bound_is_the_twins(monkeypatch):
    """The banana whose unbounded fit is a flat disc (tests/core/test_fits.py): the kernel's fit stops at the
    bound, tau held there by the active set as in the twin, and both agree to a nanometre."""
    from symfruit.core.fits import _cone_grid, cone_thickness_bound

    visible, cone, axis, front, extent = _cone_view("banana", 3, turn=(30, 60, 20))
    fast, twin = _both(monkeypatch, fit_cone_ellipsoid, visible, cone=cone, axis=axis, front=front, extent=extent)
    np.testing.assert_allclose(fast.centre, twin.centre, rtol=0, atol=1e-9)
    np.testing.assert_allclose(np.sqrt(np.diag(fast.shape)), np.sqrt(np.diag(twin.shape)), rtol=0, atol=1e-9)
    pts = visible[:: -(-len(visible) // 300)]
    rays, z = pts / pts[:, 2:3], np.ascontiguousarray(pts[:, 2])
    tau_max = cone_thickness_bound(cone, 0.25)
    grid = _cone_grid(front, extent)
    np.minimum(grid[:, 3], tau_max, out=grid[:, 3])
    step = np.array([1e-4, 1e-4, 1e-4, 1e-3])
    args = (grid, cone, axis, rays, ((rays @ cone) * rays).sum(axis=1), z, step, 0.003, 10, 1e-4)
    p, _, status = _jit.cone_fit(*args, tau_max)
    assert status == 0 and p[3] == tau_max  # held at the bound
    p_free, _, _ = _jit.cone_fit(*args, np.inf)
    assert p_free[3] > tau_max + 10.0  # unbounded, it runs on into the disc


def test_cone_fit_of_points_outside_the_cone_is_the_twins(monkeypatch):
    """Points whose rays no ellipsoid of the cone meets: every residual is the misses' constant, so the costs
    stay finite and the fit goes on; both paths end where they start, the grid's first best."""
    visible, cone, axis, front, extent = _cone_view("apple", 1, noise=0.0)
    far = visible + np.array([0.5, 0.0, 0.0])  # the points' rays outside the cone
    fast, twin = _both(monkeypatch, fit_cone_ellipsoid, far, cone=cone, axis=axis, front=front, extent=extent)
    np.testing.assert_allclose(fast.centre, twin.centre, rtol=0, atol=1e-9)


# --- marching a solid of revolution -----------------------------------------------------------------------


def _lemon_revolution(seed: int):
    rng = np.random.default_rng(seed)
    fruit = FRUITS["lemon"](rng)
    visible, _ = rendered_view(fruit, [0.01, -0.01, 0.35], noise=0.001, rotation=rotation(10 * seed, 40, 30 * seed),
                               seed=seed)  # fmt: skip
    return fit_revolution_slices(visible), visible


@given(st.integers(0, 2**32 - 1), st.integers(12, 40), st.booleans())
def test_revolution_march_is_the_twins(seed, steps, close):
    from symfruit.core.agreement import march
    from symfruit.core.fits import RevolutionInside, closed_profile

    rev, visible = _lemon_revolution(seed % 4)
    rng = np.random.default_rng(seed)
    centre = visible.mean(axis=0)
    rays = np.c_[centre[:2] / centre[2] + rng.normal(0.0, 0.08, (200, 2)), np.ones(200)]  # hits and misses
    z0, z1 = float(visible[:, 2].min()) - 0.03, float(visible[:, 2].max()) + 0.05
    inside = RevolutionInside(rev, close=close)
    t, r = closed_profile(rev, close=close)
    hit, depth = _jit.revolution_march(rev.point, rev.direction, t, r, rays, z0, z1, steps)
    hit_twin, depth_twin = march(inside, rays, z0, z1, steps=steps)
    assert np.array_equal(hit, hit_twin) and hit.any() and not hit.all()
    np.testing.assert_allclose(depth[hit], depth_twin[hit], atol=1e-12)
    assert np.isnan(depth[~hit]).all()


def test_revolution_inside_marches_its_rays_only_with_the_kernels(monkeypatch):
    from symfruit.core.fits import RevolutionInside, revolution_inside

    monkeypatch.delenv("SYMFRUIT_KERNELS", raising=False)  # a run with the twins throughout still has the kernels here
    rev, visible = _lemon_revolution(1)
    inside = RevolutionInside(rev)
    assert np.array_equal(inside(visible), revolution_inside(rev, visible))
    rays = visible[::50] / visible[::50, 2:3]
    hit, depth = inside.march(rays, 0.2, 0.5, 24)
    assert hit.shape == depth.shape == (len(rays),) and hit.mean() > 0.8  # most rays through seen points meet it
    monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    assert inside.march(rays, 0.2, 0.5, 24) is None  # explain() then marches with core.agreement.march


# --- the observation's pixel maps (core.raster, core.occlusion) ---------------------------------------------


def _blobs(rng: np.random.Generator, h: int, w: int, share: float) -> np.ndarray:
    """(h, w) bool: random pixels grown into blobs of a few pixels (edges, holes, thin parts and isolated pixels)."""
    from scipy import ndimage

    seeds = rng.random((h, w)) < share
    return ndimage.binary_dilation(seeds, iterations=int(rng.integers(0, 4))) if seeds.any() else seeds


@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40), st.floats(0.0, 24.0), st.booleans())
def test_near_distance_is_the_twins_to_the_bit(seed, h, w, reach, want):
    from symfruit.core.raster import _near_distance

    rng = np.random.default_rng(seed)
    mask = _blobs(rng, h, w, rng.uniform(0.0, 0.1))
    out = np.full((h, w), -1.0)
    _jit.near_distance(mask, reach, want, out)
    assert np.array_equal(out, _near_distance(mask == want, reach))


def _capped_reference(edges: np.ndarray, cap: float) -> np.ndarray:
    """:func:`symfruit.core._jit.capped_distances`' map before stop 64: :func:`symfruit.core._jit.near_distance` of
    reach ``cap``, capped at ``cap`` as a float32."""
    away = np.empty(edges.shape)
    _jit.near_distance(edges, cap, True, away)
    return np.where(away < cap, away, cap).astype(np.float32)


@given(st.integers(0, 2**32 - 1), st.integers(1, 50), st.integers(1, 50),
       st.one_of(st.floats(0.0, 16.0), st.sampled_from([0.0, 0.5, 1.0, 2.0, 6.0, 7.2, 64.0])))  # fmt: skip
def test_the_capped_map_is_near_distances_capped_to_the_bit(seed, h, w, cap):
    """stop 64 (reg64): :func:`symfruit.core._jit._capped_map`'s passes along the rows give the map
    :func:`symfruit.core._jit.near_distance`'s search gave, to the bit: sparse and dense edges (blobs, lines, single
    pixels, none, all), whole and fractional caps, caps wider than the map, maps of one row or column."""
    rng = np.random.default_rng(seed)
    kind = int(rng.integers(0, 4))
    if kind == 0:
        edges = _blobs(rng, h, w, rng.uniform(0.0, 0.1))
    elif kind == 1:  # thin lines, as colour edges lie
        edges = np.zeros((h, w), bool)
        for _ in range(int(rng.integers(1, 5))):
            r, c = int(rng.integers(0, h)), int(rng.integers(0, w))
            edges[r, :] |= rng.random(w) < 0.8
            edges[:, c] |= rng.random(h) < 0.8
    elif kind == 2:
        edges = rng.random((h, w)) < rng.uniform(0.0, 1.0)
    else:
        edges = np.full((h, w), bool(rng.integers(0, 2)))
    out = np.full((h, w), -1.0, np.float32)
    _jit._capped_map(edges, cap, out)
    ref = _capped_reference(edges, cap)
    assert out.dtype == ref.dtype and np.array_equal(out, ref) and np.array_equal(np.signbit(out), np.signbit(ref))


@pytest.mark.parametrize("cap", [0.0, 1.0, 2.9, 6.0, 6.5, 7.99])
def test_the_capped_map_reads_each_offset_on_both_sides(cap):
    """A single edge pixel: every pixel's capped Euclidean distance to it, at distances on both sides along the row
    (each offset's pass, the last one, ``floor(cap)``, too: it counts where the cap is not whole), across the rows
    (the columns' sweeps), and at the cap itself (``sqrt(36)`` is 6, kept)."""
    edges = np.zeros((19, 25), bool)
    edges[9, 12] = True
    out = np.empty(edges.shape, np.float32)
    _jit._capped_map(edges, cap, out)
    rr, cc = np.mgrid[:19, :25]
    want = np.minimum(np.sqrt((rr - 9.0) ** 2 + (cc - 12.0) ** 2), cap).astype(np.float32)
    assert np.array_equal(out, want)


def test_the_distance_maps_are_the_twins_to_the_bit(monkeypatch):
    """inner_distance and outer_distance, with the kernel and with the numpy twin: the same maps, to the bit, and
    within reach scipy's transform's."""
    from scipy import ndimage

    from symfruit.core.raster import inner_distance, outer_distance

    rng = np.random.default_rng(5)
    mask = np.zeros((70, 90), bool)
    mask[10:60, 15:80] = _blobs(rng, 50, 65, 0.3)
    for reach in (2.5, 5.5, 10.7):
        inner, inner_twin = _both(monkeypatch, inner_distance, mask, reach)
        outer, outer_twin = _both(monkeypatch, outer_distance, mask, reach)
        assert np.array_equal(inner, inner_twin) and np.array_equal(outer, outer_twin)
        near = outer <= reach
        assert near.any() and np.array_equal(outer[near], ndimage.distance_transform_edt(~mask)[near])
        assert np.array_equal(inner[inner <= reach], ndimage.distance_transform_edt(mask)[inner <= reach])


@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40), st.integers(0, 6), st.booleans())
def test_square_filter_is_scipys(seed, h, w, radius, every):
    from scipy import ndimage

    mask = _blobs(np.random.default_rng(seed), h, w, 0.3)
    out = np.empty((h, w), bool)
    _jit.square_filter(mask, radius, every, out)
    scipys = ndimage.minimum_filter if every else ndimage.maximum_filter
    assert np.array_equal(out, scipys(mask, size=2 * radius + 1, mode="constant", cval=False))


@given(st.integers(0, 2**32 - 1), st.integers(0, 5), st.booleans())
def test_occluded_at_is_the_twins(seed, radius, cached):
    """Occlusion.at by the kernel (each pixel's square looked through) against the twin (the grown map over the
    pixels' box, or the whole window's when made before): pixels inside and outside the window and the image,
    on its border, half-way between two, and NaN or infinite ones."""
    from symfruit.core.occlusion import Occlusion

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 50, 2))
    hidden = _blobs(rng, h, w, rng.uniform(0.0, 0.2))
    occ = Occlusion(int(rng.integers(0, 20)), int(rng.integers(0, 20)), hidden, 80, 75)
    u, v = rng.uniform(-5, 85, 300), rng.uniform(-5, 80, 300)
    u[::7], v[::5] = np.round(u[::7]) + 0.5, np.round(v[::5])  # ties of the rounding, whole pixels
    u[:4], v[4:8] = [np.nan, np.inf, -np.inf, 1e30], [np.nan, -np.inf, np.inf, -1e30]
    if cached:
        occ.grown(radius)
    with pytest.MonkeyPatch.context() as mp, np.errstate(invalid="ignore"):
        fast, twin = _both(mp, occ.at, u, v, radius=radius)
        one, one_twin = _both(mp, occ.at, u[10:11], v[10:11], radius=radius)
    assert fast.dtype == twin.dtype == bool and np.array_equal(fast, twin) and np.array_equal(one, one_twin)


@given(st.integers(0, 2**32 - 1), st.integers(1, 5))
def test_grown_occlusion_is_the_twins(seed, radius):
    """Occlusion.at with a radius and Occlusion.window (their grown maps, filtered by the kernel or by scipy)."""
    from symfruit.core.occlusion import Occlusion
    from symfruit.core.raster import Silhouette

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(8, 60, 2))
    occ = Occlusion(3, 4, _blobs(rng, h, w, rng.uniform(0.0, 0.15)), 100, 90)
    u, v = rng.uniform(-5, 105, 200), rng.uniform(-5, 95, 200)
    region = Silhouette(int(rng.integers(0, 50)), int(rng.integers(0, 50)), np.ones((20, 30), bool), 0.0)
    with pytest.MonkeyPatch.context() as mp:
        at, at_twin = _both(mp, occ.at, u, v, radius=radius)
        window, window_twin = _both(mp, occ.window, region, radius=radius)
        grown, grown_twin = _both(mp, lambda r: Occlusion(3, 4, occ.hidden, 100, 90).grown(r), radius)  # not cached
    assert np.array_equal(at, at_twin) and np.array_equal(window, window_twin) and np.array_equal(grown, grown_twin)


@given(st.integers(0, 2**32 - 1), st.integers(0, 4), st.booleans(), st.booleans())
def test_occlusion_maps_are_the_twins_to_the_bit(seed, reach, single, with_others):
    """core.occlusion.occlusion with the kernels and with the numpy twins: the same hidden pixels and seen depths,
    bit for bit, on random depth images (a background, surfaces in front of and behind the fruit, dropouts as 0
    and NaN, float32 and float64), the fruit's mask larger than its points' pixels, other fruit or none, points
    on the image's edges."""
    from symfruit.core.camera import Camera
    from symfruit.core.occlusion import occlusion

    rng = np.random.default_rng(seed)
    camera = Camera(fx=300.0, fy=300.0, cx=40.0, cy=30.0, width=80, height=60)
    depth = np.where(_blobs(rng, 60, 80, 0.02), rng.uniform(0.3, 0.45), 1.0) + rng.normal(0.0, 0.01, (60, 80))
    depth[rng.random((60, 80)) < rng.uniform(0.0, 0.4)] = 0.0
    depth[rng.random((60, 80)) < 0.05] = np.nan
    depth = depth.astype(np.float32 if single else np.float64)
    u = rng.uniform(-0.4, 79.4, 300) if rng.random() < 0.2 else rng.normal(rng.uniform(10, 70), 6.0, 300)
    v = rng.normal(rng.uniform(10, 50), 5.0, 300)
    z = rng.uniform(0.38, 0.42, 300)
    points = np.column_stack(((u - 40.0) * z / 300.0, (v - 30.0) * z / 300.0, z))
    ok = (np.rint(u) >= 0) & (np.rint(u) < 80) & (np.rint(v) >= 0) & (np.rint(v) < 60)
    if not ok.any():
        return
    mask = np.zeros((60, 80), bool)
    mask[np.rint(v[ok]).astype(int), np.rint(u[ok]).astype(int)] = True
    mask &= rng.random((60, 80)) < 0.9
    mask |= _blobs(rng, 60, 80, 0.01) & (rng.random() < 0.5)
    others = _blobs(rng, 60, 80, 0.03) if with_others else None
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, occlusion, depth, mask, points, camera, others=others, reach=reach)
    assert (fast.u0, fast.v0) == (twin.u0, twin.v0) and np.array_equal(fast.hidden, twin.hidden)
    assert np.array_equal(fast.own, twin.own) and fast.depth.tobytes() == twin.depth.tobytes()


@given(st.integers(0, 2**32 - 1), st.integers(0, 3), st.integers(0, 4))
def test_allowed_pixels_are_the_twins(seed, gap, thin):
    """Occlusion.allowed (and so extent) with the kernel and with the numpy twin: the same pixels, on random hidden
    blobs and seen regions reaching out of the window."""
    from symfruit.core.occlusion import Occlusion
    from symfruit.core.raster import Silhouette

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(8, 60, 2))
    occ = Occlusion(3, 4, _blobs(rng, h, w, rng.uniform(0.0, 0.15)), 100, 90)
    rh, rw = (int(x) for x in rng.integers(3, 30, 2))
    region = Silhouette(int(rng.integers(0, 50)), int(rng.integers(0, 50)), _blobs(rng, rh, rw, 0.2), 0.0)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, occ.allowed, region, gap=gap, thin=thin)
        assert np.array_equal(fast, twin)
        box, box_twin = _both(mp, occ.extent, region, gap=gap, thin=thin)
    assert np.array_equal(box, box_twin)


@given(st.integers(0, 2**32 - 1), st.integers(0, 300))
def test_inside_px_is_the_twins_to_the_bit(seed, n):
    """Points in the window, beyond it, on pixel centres' half-way marks (rounded half to even), and ones whose
    pixel numpy's integers cannot hold (NaN, infinite, z = 0, past 2^63)."""
    from symfruit.core.agreement import _inside_px
    from symfruit.core.camera import Camera
    from symfruit.core.raster import Silhouette

    rng = np.random.default_rng(seed)
    cam = Camera(fx=500.0, fy=480.0, cx=64.0, cy=48.0, width=128, height=96)
    inner = rng.random((40, 50)) * 10.0
    region = Silhouette(int(rng.integers(0, 80)), int(rng.integers(0, 60)), inner > 1.0, 0.0)
    uv = np.c_[rng.uniform(-20, 150, n), rng.uniform(-20, 120, n)]
    uv[: n // 4] = np.round(uv[: n // 4]) + 0.5  # half-way: numpy's rint rounds to even
    z = rng.uniform(0.2, 1.0, n)
    pts = np.c_[(uv[:, 0] - 64.0) / 500.0 * z, (uv[:, 1] - 48.0) / 480.0 * z, z]
    odd = [np.nan, np.inf, -np.inf, 0.0, 1e300, -1e300, 1e-300]
    for i in range(min(n, 2 * len(odd))):
        pts[i, i % 3] = odd[i % len(odd)]
    with pytest.MonkeyPatch.context() as mp, np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        fast, twin = _both(mp, _inside_px, pts, region, cam, inner)
    assert np.array_equal(fast, twin)


@pytest.mark.parametrize("name", ["apple", "banana", "strawberry"])
@pytest.mark.parametrize("noise", [0.0, 0.004])
def test_contour_pixels_are_the_twins(name, noise):
    """A depth camera's view of a tilted fruit (a point per pixel, noisy or not): the same edge pixels and the
    same contour labels as the twin's ``eigh``."""
    from symfruit import DEFAULT_CAMERA as cam
    from symfruit.core.agreement import _contour_pixels, _inside_px
    from symfruit.core.raster import inner_distance, silhouette

    fruit = FRUITS[name](np.random.default_rng(1))
    pts, _ = rendered_view(fruit, CENTRE, noise=noise, rotation=rotation(0.3, 1.0, 0.2), seed=3)
    region = silhouette(pts, cam)
    depth_px = _inside_px(pts, region, cam, inner_distance(region.mask))
    with pytest.MonkeyPatch.context() as mp:
        (uv, contour), (uv_twin, contour_twin) = _both(mp, _contour_pixels, pts, depth_px, region, cam, 150)
    assert len(uv) > 50 and contour.any()
    assert np.array_equal(uv, uv_twin) and np.array_equal(contour, contour_twin)


@given(st.integers(0, 2**32 - 1), st.integers(0, 2500), st.integers(1, 60), st.integers(1, 3))
@settings(deadline=None)
def test_contour_pixels_are_the_twins_on_random_clouds(seed, n, count, half):
    """Points on a random bumpy surface, some pixels met twice (the later point keeps it), some beyond the
    window, random distances inside the edge: the same pixels and labels as the twin's."""
    from symfruit.core.agreement import _contour_pixels
    from symfruit.core.camera import Camera
    from symfruit.core.raster import Silhouette

    rng = np.random.default_rng(seed)
    cam = Camera(fx=500.0, fy=480.0, cx=64.0, cy=48.0, width=128, height=96)
    u0, v0 = (int(x) for x in rng.integers(0, 30, 2))
    region = Silhouette(u0, v0, np.ones((40, 50), bool), 0.0)
    uv = np.c_[rng.integers(u0 - 3, u0 + 53, n), rng.integers(v0 - 3, v0 + 43, n)] + rng.uniform(-0.45, 0.45, (n, 2))
    uv[: n // 5] = uv[n // 5 : 2 * (n // 5)] + 0.1  # the same pixels again
    z = 0.5 + 0.02 * np.sin(uv[:, 0] / rng.uniform(2, 20)) + rng.normal(0.0, 1e-3, n)
    pts = np.c_[(uv[:, 0] - 64.0) / 500.0 * z, (uv[:, 1] - 48.0) / 480.0 * z, z]
    depth_px = rng.choice([0.0, 1.0, 1.5, 2.0, 3.0, 6.0], n)
    with pytest.MonkeyPatch.context() as mp:
        (uv_f, contour), (uv_twin, contour_twin) = _both(mp, _contour_pixels, pts, depth_px, region, cam, count, half)
    assert np.array_equal(uv_f, uv_twin) and np.array_equal(contour, contour_twin)


@given(
    st.integers(0, 2**32 - 1),
    st.lists(st.sampled_from([0.5, 1.0, 2.0, 2.3, 5.0, 8.0]), min_size=1, max_size=4),
    st.integers(0, 100),
)
def test_band_pixels_are_the_twins_to_the_bit(seed, bands, n_band):
    """Distance maps of whole and half pixels (on the bands' half-way marks), +inf and NaN pixels, bands that
    overlap or repeat, more and fewer pixels than ``n_band``: the same pixels in the same order."""
    from symfruit.core.agreement import _band_pixels

    rng = np.random.default_rng(seed)
    dist = rng.integers(0, 20, (int(rng.integers(1, 60)), int(rng.integers(1, 60)))) * 0.5
    dist[rng.random(dist.shape) < 0.1] = np.inf
    dist[rng.random(dist.shape) < 0.05] = np.nan
    with pytest.MonkeyPatch.context() as mp:
        (rc, sizes), (rc_twin, sizes_twin) = _both(mp, _band_pixels, dist, tuple(bands), n_band)
    assert rc.dtype == rc_twin.dtype and np.array_equal(rc, rc_twin) and np.array_equal(sizes, sizes_twin)


@given(st.integers(0, 2**32 - 1), st.integers(1, 7), st.floats(0.0, 1.0))
def test_closed_masks_are_the_twins_to_the_bit(seed, half, share):
    """Random masks (empty to full, some narrower than the square, pixels on the array's edge): the same closing
    and filled holes as the twin's two box means."""
    from symfruit.core.raster import _closed_mask

    rng = np.random.default_rng(seed)
    hit = rng.random((int(rng.integers(1, 50)), int(rng.integers(1, 50)))) < share
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _closed_mask, hit, half)
    assert fast.dtype == twin.dtype == bool and np.array_equal(fast, twin)


@given(st.integers(0, 2**32 - 1), st.floats(1e-9, 1.0))
def test_least_vector_is_eighs(seed, gap):
    """Random symmetric matrices, the least two eigenvalues ``gap`` apart relative to the largest: the least
    eigenvalue and (where the gap leaves it defined) its eigenvector as LAPACK's, to rounding."""
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    lam = np.array([1.0, 1.0 + gap, 2.0 + rng.random()]) * 10.0 ** rng.uniform(-8, 2)
    a = (q * lam) @ q.T
    a = 0.5 * (a + a.T)
    w, vec = np.linalg.eigh(a)
    work, v = a.copy(), np.empty((3, 3))
    least = _jit._least_vector(work, v)
    scale = lam.max()
    assert abs(work[least, least] - w[0]) <= 1e-12 * scale
    assert np.linalg.norm(a @ v[:, least] - w[0] * v[:, least]) <= 1e-12 * scale
    assert np.allclose(v.T @ v, np.eye(3), atol=1e-13)
    if gap > 1e-3:
        assert abs(abs(v[:, least] @ vec[:, 0]) - 1.0) <= 1e-9 / gap


# --- the surface's noise (core.fits.surface_noise) ----------------------------------------------------------


@given(st.integers(0, 2**32 - 1), st.integers(3, 400), st.integers(1, 60), st.integers(1, 12), st.integers(0, 40))
def test_neighbour_covariances_are_the_twins(seed, n, step, small, extra):
    """Random points (a tenth of them repeated: ties at distance 0, as a duplicated point gives): the same
    neighbourhoods' covariances as the search tree's, within rounding."""
    from symfruit.core.fits import _neighbour_covariances

    rng = np.random.default_rng(seed)
    pts = rng.normal(size=(n, 3)) * rng.uniform(0.001, 0.1)
    pts[: n // 10] = pts[n // 10 : 2 * (n // 10)]
    large = max(min(small + extra, n), 2)  # as surface_noise's (a search for one neighbour returns a flat array)
    small = min(small, large)
    fast = _jit.neighbour_covariances(pts, step, small, large)
    twin = _neighbour_covariances(pts, step, small, large)
    for a, b in zip(fast, twin, strict=True):
        assert a.shape == b.shape == (len(pts[::step]), 3, 3)
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-15 * float(np.abs(b).max()))


@given(st.integers(0, 2**32 - 1), st.integers(2, 300), st.integers(1, 40), st.integers(1, 30), st.booleans())
def test_neighbour_covariances_keep_the_nearest_in_order_ties_by_index(seed, n, step, large, nan):
    """The nearest ``large`` of each query in the order of a stable sort of the distances (ties by index), their
    scatter summed in that order: bit for bit, on a lattice's whole-number coordinates (ties everywhere); with a
    NaN coordinate the kernel falls back to offering every point in turn (checked here only to run)."""
    rng = np.random.default_rng(seed)
    pts = rng.integers(0, 4, size=(n, 3)).astype(np.float64) * 0.001
    large = min(large, n)
    small = int(rng.integers(1, large + 1))
    if nan:
        pts[int(rng.integers(n)), int(rng.integers(3))] = np.nan
    fast_small, fast_large = _jit.neighbour_covariances(pts, step, small, large)
    scatter = np.empty((3, 3))
    for row, q in enumerate(range(0, n, step)):
        d = ((pts - pts[q]) ** 2).sum(axis=1)
        order = np.argsort(d, kind="stable")  # NaN last
        if nan and np.isnan(d).any():
            continue  # the insertion's own handling of NaN (the former kernel's), not a sort's
        for kk, fast in ((small, fast_small), (large, fast_large)):
            _jit._scatter(pts, order, kk, scatter)
            assert np.array_equal(fast[row], scatter / kk)


@pytest.mark.parametrize("kind,noise,queries", [("apple", 0.0, 120), ("pear", 0.002, 40), ("banana", 0.001, 7)])
def test_surface_noise_is_the_twins(monkeypatch, kind, noise, queries):
    from symfruit.core.fits import surface_noise

    fruit = FRUITS[kind](np.random.default_rng(3))
    visible, _ = rendered_view(fruit, [0.01, -0.01, 0.4], noise=noise, rotation=rotation(10, 20, 30), seed=3)
    (ratio, res, normals), (ratio_twin, res_twin, normals_twin) = _both(monkeypatch, surface_noise, visible,
                                                                       queries=queries)  # fmt: skip
    assert ratio == pytest.approx(ratio_twin, rel=1e-12) and res == pytest.approx(res_twin, rel=1e-12)
    np.testing.assert_allclose(normals, normals_twin, atol=1e-9)


def test_surface_noise_searches_a_tree_past_the_brute_forces_bound(monkeypatch):
    """Past _BRUTE_NEIGHBOURS distances the twin's search tree runs even with the kernels (the same results)."""
    from symfruit.core import fits

    monkeypatch.delenv("SYMFRUIT_KERNELS", raising=False)  # the kernels are there (numba is, above)
    pts = random_sphere(300, seed=4)
    monkeypatch.setattr(fits, "_neighbour_covariances", lambda *a: (_ for _ in ()).throw(AssertionError("tree")))
    fits.surface_noise(pts, queries=30)  # 300 x 30 distances: the kernel
    monkeypatch.setattr(fits, "_BRUTE_NEIGHBOURS", 300 * 30 - 1)
    with pytest.raises(AssertionError, match="tree"):
        fits.surface_noise(pts, queries=30)


def _ball_behind_a_leaf(seed: int):
    """A ball's view partly behind a leaf (seeded): its centre, the visible points, their silhouette and the frame's
    occlusion maps (the marched and the closed-form agreement tests' view)."""
    from symfruit.core.camera import DEFAULT_CAMERA as camera
    from symfruit.core.occlusion import occlusion
    from symfruit.core.raster import silhouette

    from ..conftest import ball_mesh, occluded_view

    centre = np.array([0.01 * seed, -0.005, 0.4])
    visible, depth, mask, _ = occluded_view(ball_mesh(), centre, below=250 + 5 * seed, occluder_z=0.33, noise=0.01,
                                            seed=seed)  # fmt: skip
    return centre, visible, silhouette(visible, camera), occlusion(depth, mask, visible, camera)


@pytest.mark.parametrize("seed", range(4))
def test_explain_of_a_quadric_is_the_twins(monkeypatch, seed):
    """Spheres and rotated ellipsoids about the truth, beside it, around the camera, missing every ray and reaching
    in front of the leaf, against views with and without the frame's depth beside the fruit (outside rays on an
    occluder: free space); the depth RMS within rounding (its sums' order; grazing rays' roots), the band shares
    from whole counts: equal."""
    from symfruit.core.agreement import Quadric, explain, observe
    from symfruit.core.camera import DEFAULT_CAMERA as camera

    rng = np.random.default_rng(seed)
    centre, visible, region, occ = _ball_behind_a_leaf(seed)
    views = [observe(visible[::10], region, camera, dense=visible, occlusion=o) for o in (None, occ)]
    for obs in views:
        for k in range(16):
            r = rng.uniform(0.02, 0.05) if k < 12 else rng.uniform(0.055, 0.085)  # the last: fronts about the leaf's
            c = centre + rng.normal(0.0, 0.01, 3) * (k % 4 != 0)
            if k == 10:
                c = np.array([0.0, 0.0, 0.05])  # the camera inside
            if k == 11:
                c = centre + [0.5, 0.0, 0.0]  # no ray meets it
            axes = rng.uniform(0.6, 1.6, 3) * r
            turn = rotation(*rng.uniform(0.0, 180.0, 3))
            shape = turn @ np.diag(1.0 / axes**2) @ turn.T if k % 2 else np.eye(3) / r**2
            quadric = Quadric(c, shape)
            box = (c - axes.max(), c + axes.max())
            fast, twin = _both(monkeypatch, explain, quadric, box, obs)
            assert fast.depth == pytest.approx(twin.depth, rel=1e-9, abs=1e-15)
            assert (fast.inside, fast.outside) == (twin.inside, twin.outside)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_explain_of_a_solid_of_revolution_is_the_twins(monkeypatch, seed):
    """The measures of marched rays (:func:`symfruit.core._jit.agreement`) against the twin's numpy ones, the rays
    met alike (the march kernel's hits are the twin's): solids of revolution fitted to the view and moved about
    it, with and without the frame's depth beside the fruit; the depth RMS within rounding, the shares equal."""
    from dataclasses import replace

    from symfruit.core import agreement
    from symfruit.core.agreement import explain, observe
    from symfruit.core.camera import DEFAULT_CAMERA as camera
    from symfruit.core.fits import RevolutionInside, revolution_box

    rng = np.random.default_rng(seed)
    _, visible, region, occ = _ball_behind_a_leaf(seed)
    rev = fit_revolution_slices(visible[::3])
    for o in (None, occ):
        obs = observe(visible[::10], region, camera, dense=visible, occlusion=o)
        for k in range(6):
            moved = replace(rev, point=rev.point + rng.normal(0.0, 0.006, 3) * (k > 0), radii=rev.radii * (1 + 0.1 * k))
            inside = RevolutionInside(moved)
            box = revolution_box(moved)
            monkeypatch.delenv("SYMFRUIT_KERNELS", raising=False)  # the kernel's march, whatever the run's setting
            marched = inside.march(agreement._bands(obs).rays, float(box[0][2]) - 1e-3, float(box[1][2]) + 1e-3, 24)
            assert marched is not None
            monkeypatch.setattr(RevolutionInside, "march", lambda self, *a, hits=marched: hits)  # the same hits
            fast, twin = _both(monkeypatch, explain, inside, box, obs)
            monkeypatch.undo()
            assert fast.depth == pytest.approx(twin.depth, rel=1e-9, abs=1e-15)
            assert (fast.inside, fast.outside) == (twin.inside, twin.outside)


@given(st.integers(0, 2**32 - 1), st.integers(1, 60), st.integers(1, 60), st.sampled_from([0.0, 0.5, 1.0, 3.0]),
       st.booleans())  # fmt: skip
def test_rim_coverage_is_the_twins_to_the_bit(seed, h, w, fill_radius, given_map):
    """evidence.rim_coverage by the kernel against the twin: random regions (blobs: empty rims or interiors too),
    points on pixels inside and outside the window and on rounding ties, one at NaN, sparse clouds' filled points
    (the twin's maximum filter with its reflected border) and dense ones, with the distance map given or made."""
    from symfruit.core.camera import DEFAULT_CAMERA as camera
    from symfruit.core.raster import Silhouette, inner_distance
    from symfruit.methods.evidence import rim_coverage

    rng = np.random.default_rng(seed)
    mask = _blobs(rng, h, w, rng.uniform(0.05, 0.6))
    region = Silhouette(int(rng.integers(0, 500)), int(rng.integers(0, 400)), mask, fill_radius)
    n = int(rng.integers(1, 2 * h * w + 2))
    u = region.u0 + rng.integers(-3, w + 3, n) + rng.choice([0.0, 0.5, -0.5, 0.3], n)
    v = region.v0 + rng.integers(-3, h + 3, n) + rng.choice([0.0, 0.5, -0.4], n)
    z = rng.uniform(0.3, 0.6, n)
    points = np.stack(((u - camera.cx) * z / camera.fx, (v - camera.cy) * z / camera.fy, z), axis=1)
    points[0, 0] = np.nan
    inner = inner_distance(mask) if given_map else None
    with pytest.MonkeyPatch.context() as mp, np.errstate(invalid="ignore"):
        fast, twin = _both(mp, rim_coverage, points, region, camera, inner=inner)
    assert fast == twin and type(fast) is type(twin) is float


# --- the fruit's surface, the registration's outlines and colour trimming (core.surface, core.raster) -------


@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40), st.booleans())
def test_distance_is_scipys_transform_to_the_bit(seed, h, w, want):
    """Random blobs (whole rows and columns without a pixel of the kind, single pixels, thin parts)."""
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    mask = _blobs(rng, h, w, rng.uniform(0.0, 0.2))
    if rng.random() < 0.2:
        mask = rng.random((h, w)) < rng.uniform(0.0, 1.0)
    if not (mask == want).any():
        mask[int(rng.integers(0, h)), int(rng.integers(0, w))] = want
    out = np.full((h, w), -1.0)
    _jit.distance(mask, want, out)
    assert np.array_equal(out, ndimage.distance_transform_edt(mask != want))


def test_distance_transform_is_scipys_with_and_without_the_kernel(monkeypatch):
    """raster.distance_transform (and so inner_distance without a reach) on both paths: scipy's map to the bit; an
    image without a false pixel, and an empty one, are left to scipy."""
    from scipy import ndimage

    from symfruit.core.raster import distance_transform, inner_distance

    rng = np.random.default_rng(11)
    for image in (_blobs(rng, 90, 70, 0.3), np.ones((5, 7), bool), np.zeros((4, 3), bool), np.zeros((0, 3), bool)):
        fast, twin = _both(monkeypatch, distance_transform, image)
        assert np.array_equal(fast, twin) and np.array_equal(fast, ndimage.distance_transform_edt(image))
    mask = np.zeros((60, 80), bool)
    mask[5:50, 10:75] = _blobs(rng, 45, 65, 0.4)
    fast, twin = _both(monkeypatch, inner_distance, mask)
    assert np.array_equal(fast, twin) and np.array_equal(fast, ndimage.distance_transform_edt(mask))


@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40), st.integers(0, 3))
def test_nearest_is_scipys_feature_transform_to_the_pixel(seed, h, w, kind):
    """Blobs, speckle, a few lone pixels and lattices of pixels (equally near pixels everywhere: the tie rule)."""
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    if kind == 0:
        image = ~_blobs(rng, h, w, rng.uniform(0.0, 0.2))
    elif kind == 1:
        image = rng.random((h, w)) < rng.uniform(0.0, 1.0)
    else:
        image = np.ones((h, w), bool)
        step = int(rng.integers(1, 7))
        if kind == 2:
            image[rng.integers(0, h, 3), rng.integers(0, w, 3)] = False
        else:
            image[::step, ::step] = rng.random(image[::step, ::step].shape) < 0.4
    if image.all():
        image[int(rng.integers(0, h)), int(rng.integers(0, w))] = False
    out = np.full((h, w), -2, np.int64)
    _jit.nearest(image, out)
    rows, cols = ndimage.distance_transform_edt(image, return_distances=False, return_indices=True)
    assert np.array_equal(out, rows * w + cols)
    _jit.nearest(np.ones((h, w), bool), out)  # nothing to point to
    assert (out == -1).all()


def test_nearest_index_is_scipys_with_and_without_the_kernel(monkeypatch):
    """raster.nearest_index on both paths: scipy's picks."""
    from scipy import ndimage

    from symfruit.core.raster import nearest_index

    rng = np.random.default_rng(5)
    for image in (~_blobs(rng, 120, 90, 0.02), rng.random((31, 17)) < 0.9, np.array([[True, False]])):
        fast, twin = _both(monkeypatch, nearest_index, image)
        rows, cols = ndimage.distance_transform_edt(image, return_distances=False, return_indices=True)
        assert np.array_equal(fast, twin) and np.array_equal(fast, rows * image.shape[1] + cols)


@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40))
def test_outline_cracks_are_the_twins_to_the_bit(seed, h, w):
    """Blobs and speckle touching the window's edges, at random window origins: the same points in the same order."""
    from symfruit.core.raster import Silhouette, outline_cracks

    rng = np.random.default_rng(seed)
    mask = _blobs(rng, h, w, rng.uniform(0.0, 0.3)) if rng.random() < 0.5 else rng.random((h, w)) < rng.random()
    u0, v0 = (int(x) for x in rng.integers(0, 600, 2))
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, lambda: outline_cracks(Silhouette(u0, v0, mask, 0.0)))
    assert fast.shape == twin.shape and fast.tobytes() == twin.tobytes()


@given(st.integers(0, 2**32 - 1), st.integers(1, 3000))
def test_cloud_spread_is_the_bounds_and_the_twins_scatter(seed, n):
    """Random clouds far from the origin (the mean's rounding matters most there): numpy's bounds exactly, the
    scatter within rounding of the centred product."""
    from symfruit.core.points import bounds, mean_point

    rng = np.random.default_rng(seed)
    points = rng.normal(0.0, rng.uniform(1e-4, 0.05), (n, 3)) * rng.uniform(0.1, 1.0, 3) + [0.1, -0.2, 0.6]
    lo, hi, scatter = _jit.cloud_spread(points)
    want_lo, want_hi = bounds(points)
    centred = points - mean_point(points)
    twin = centred.T @ centred
    assert np.array_equal(lo, want_lo) and np.array_equal(hi, want_hi)
    assert np.allclose(scatter, twin, rtol=1e-9, atol=1e-12 * np.abs(twin).max())


def test_check_cloud_is_the_twins(monkeypatch):
    """The same clean points, and the same refusals of clouds on a plane, on a line, of one point, and behind or
    too near the camera, with and without the kernel."""
    from symfruit.core.limits import MIN_DEPTH_METRES
    from symfruit.core.points import check_cloud
    from symfruit.errors import InputError

    rng = np.random.default_rng(2)
    cloud = rng.normal(0.0, 0.02, (500, 3)) + [0.0, 0.0, 0.5]
    cloud[::7] = np.nan
    fast, twin = _both(monkeypatch, check_cloud, cloud)
    assert fast[1] == twin[1] == 72 and np.array_equal(fast[0], twin[0])
    flat = cloud[1:200].copy()
    flat[:, 2] = 0.5
    line = np.outer(np.linspace(0.0, 1.0, 50), [0.01, 0.02, 0.03]) + [0.0, 0.0, 0.5]
    same = np.tile([0.0, 0.0, 0.5], (20, 1))
    behind, near = cloud[1:200] - [0.0, 0.0, 0.49], cloud[1:200].copy()
    near[:, 2] = MIN_DEPTH_METRES / 2 + np.abs(near[:, 2] - 0.5) * 0.05  # in front, some nearer than a camera reads
    for bad, said in ((flat, "plane"), (line, "line"), (same, "identical"), (behind, "behind"), (near, "nearer")):
        for env in ("", "numpy"):
            monkeypatch.setenv("SYMFRUIT_KERNELS", env)
            with pytest.raises(InputError, match=said):
                check_cloud(bad[np.isfinite(bad).all(axis=1)])
    monkeypatch.delenv("SYMFRUIT_KERNELS")


@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40), st.integers(0, 30))
def test_taxicab_within_is_scipys(seed, h, w, reach):
    from scipy import ndimage

    from symfruit.core.surface import _taxicab_within

    rng = np.random.default_rng(seed)
    mask = _blobs(rng, h, w, rng.uniform(0.0, 0.1))
    mask[int(rng.integers(0, h)), int(rng.integers(0, w))] = True
    out = np.empty((h, w), bool)
    _jit.taxicab_within(mask, reach, out)
    expected = ndimage.distance_transform_cdt(~mask, metric="taxicab") <= reach
    assert np.array_equal(out, expected)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _taxicab_within, mask, reach)
    assert np.array_equal(fast, expected) and np.array_equal(twin, expected)


@given(st.integers(0, 2**32 - 1), st.sampled_from([1, 3, 5]))
def test_least_median_is_the_twins_first_least_median(seed, size):
    """Coarse values (many equal medians: the first least is the one), +inf (pixels outside the slab), windows over
    the image's edges."""
    from symfruit.core.surface import median_at

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 30, 2))
    image = rng.choice([0.3, 0.31, 0.32, np.inf], size=(h, w), p=[0.2, 0.3, 0.3, 0.2])
    if rng.random() < 0.5:
        image = image + rng.normal(0, 0.01, (h, w)).round(2)
    rows, cols = np.nonzero(rng.random((h, w)) < 0.5)
    if not len(rows):
        rows, cols = np.array([h // 2]), np.array([w // 2])
    expected = int(np.argmin(median_at(image, rows, cols, size=size)))
    assert _jit.least_median(image, rows, cols, size) == expected


@given(st.integers(0, 2**32 - 1), st.sampled_from([np.float64, np.float32]), st.sampled_from([8, 72]))
def test_monotone_region_is_the_twins(seed, dtype, bins):
    """Coarse depths (equal depths, equal distances from the apex), holes in the kept pixels, the apex anywhere."""
    from symfruit.core.surface import monotone_region

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 60, 2))
    depth = np.round(rng.uniform(0.4, 0.45, (h, w)), int(rng.integers(2, 5))).astype(dtype)
    keep = rng.random((h, w)) < rng.uniform(0.3, 1.0)
    apex = (int(rng.integers(0, h)), int(rng.integers(0, w)))
    tol = float(rng.choice([0.0, 0.003, 0.0105, 0.02]))
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, monotone_region, depth, keep, apex, tol, bins=bins)
    assert np.array_equal(fast, twin)


@given(st.integers(0, 2**32 - 1), st.integers(1, 400), st.integers(1, 4), st.integers(1, 6))
def test_colour_trims_features_k_means_and_test_are_the_twins_to_the_bit(seed, n, k, iterations):
    """Colours on a coarse grid (equal features, rows as near two centres: the first is taken) and centres that
    lose every row (kept)."""
    from symfruit.core.surface import _colour_features, _kmeans, _nearer_fruit

    rng = np.random.default_rng(seed)
    color = rng.choice(np.arange(0, 256, 51), size=(int(rng.integers(1, 30)), int(rng.integers(1, 30)), 3))
    color = color.astype(np.uint8)
    where = rng.random(color.shape[:2]) < 0.5
    assert np.array_equal(_jit.colour_features(color, where), _colour_features(color, where))
    x = _colour_features(rng.choice(np.arange(0, 256, 51), size=(n, 1, 3)).astype(np.uint8), np.ones((n, 1), bool))
    c = np.concatenate([x[rng.integers(0, n, k)], [[5.0, 5.0, 5.0]]])  # the last centre far from every row
    assert np.array_equal(_jit.kmeans(x, c, iterations), _kmeans(x, c, iterations))
    fruit, ground = x[rng.integers(0, n, k)], x[rng.integers(0, n, k)] + rng.choice([0.0, 0.01])
    for margin in (1.0, 0.5):
        assert np.array_equal(_jit.nearer_fruit(x, fruit, ground, margin), _nearer_fruit(x, fruit, ground, margin))


def _ball_frame(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(depth, mask, colour) of a noisy red ball on a table before a green wall, its mask drawn a pixel off
    and overshooting by two (a 160 x 120 frame)."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[:120, :160].astype(np.float64)
    cu, cv, r = 80 + rng.uniform(-10, 10), 60 + rng.uniform(-8, 8), rng.uniform(14, 30)
    d2 = ((xx - cu) ** 2 + (yy - cv) ** 2) / r**2
    disc = d2 <= 1.0
    depth = np.where(yy > cv, np.minimum(0.8, 0.5 + r * 0.5 / 600 - (yy - cv - r) * 0.002), 0.8)
    depth = np.where(disc, 0.5 + r * 0.5 / 600 * (1.0 - np.sqrt(np.clip(1.0 - d2, 0.0, None))), depth)
    depth = depth + rng.normal(0.0, 0.001, depth.shape)
    depth[disc & (d2 > 0.85**2)] = 0.0  # the rim a time-of-flight camera invalidates
    colour = np.where(disc[..., None], [200, 30, 30], [40, 160, 60]) + rng.integers(0, 30, (120, 160, 3))
    du, dv = (int(x) for x in rng.integers(-1, 2, 2))
    mask = np.roll(((xx - cu) ** 2 + (yy - cv) ** 2) <= (r + 2) ** 2, (dv, du), axis=(0, 1))
    return depth, mask, colour.astype(np.uint8)


@pytest.mark.parametrize("seed", range(4))
def test_the_surface_outline_and_colour_trim_are_the_twins(monkeypatch, seed):
    """fruit_surface, the registration's outline and colour_trim with the kernels and with the numpy twins: the same
    pixels, numbers and maps, to the bit."""
    from symfruit.core.surface import _outline, colour_trim, fruit_surface, within

    depth, mask, colour = _ball_frame(seed)
    surface, surface_twin = _both(monkeypatch, fruit_surface, depth, mask, 600.0)
    assert np.array_equal(surface.pixels, surface_twin.pixels)
    assert (surface.front, surface.radius, surface.noise, surface.apex) == (
        surface_twin.front, surface_twin.radius, surface_twin.noise, surface_twin.apex)  # fmt: skip
    outline, outline_twin = _both(monkeypatch, _outline, depth, mask, 600.0, 20)
    for a, b in ((outline.rows, outline_twin.rows), (outline.cols, outline_twin.cols),
                 (outline.inside, outline_twin.inside)):  # fmt: skip
        assert np.array_equal(a, b)
    trimmed, trimmed_twin = _both(monkeypatch, colour_trim, colour, mask, band_px=4.0)
    assert np.array_equal(trimmed, trimmed_twin) and not np.array_equal(trimmed, mask)
    for radius in (0.0, 2.5, 5.0):
        fast, twin = _both(monkeypatch, within, mask, radius)
        assert np.array_equal(fast, twin)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([4, 30, 900, 20000]), st.sampled_from([0.7, 0.5, 1.0, 0.01]))
def test_the_outlines_fast_costs_are_the_twins_within_their_sums_rounding(seed, top, trim):
    """The registration's fast costs (exact=False) of random maps of whole-number squares (int16 keys; ties) with
    the kernel and with the numpy twin: the same run of values summed in another order, so within rounding (the
    shift is then chosen by the exact costs, which the kernel leaves to numpy: the same shift)."""
    from symfruit.core.surface import _Outline

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(5, 60, 2))
    inside = np.sqrt(rng.integers(1, top, (h, w)).astype(float)) * rng.choice([-1.0, 1.0], (h, w))
    n = int(rng.integers(1, 320))
    outline = _Outline(rng.integers(0, h, n), rng.integers(0, w, n), inside, float(rng.uniform(0.0, 6.0)))
    reach = int(rng.integers(1, 25))
    shifts = rng.integers(-reach, reach + 1, (int(rng.integers(1, 60)), 2))
    keys = outline.keys(reach, reach)
    assert keys is not None and keys.dtype == np.int16  # the kernel's case
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, outline.cost, shifts, reach, trim, exact=False)
    np.testing.assert_allclose(fast, twin, rtol=1e-13, atol=0.0)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([4, 30, 900, 40000]), st.integers(1, 25))
def test_the_outlines_ranks_are_the_twins(seed, top, reach):
    """The places of a padded map's distinct keys and their values (int16 and int32 keys, the pad's key among
    them): the same arrays bit for bit; and a map with its keys made again gives the same fast costs."""
    from symfruit.core.surface import _Outline

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 60, 2))
    inside = np.sqrt(rng.integers(0, top, (h, w)).astype(float)) * rng.choice([-1.0, 1.0], (h, w))
    with pytest.MonkeyPatch.context() as mp:
        (ranks, values), (ranks_twin, values_twin) = _both(
            mp, lambda: _Outline(np.zeros(1, int), np.zeros(1, int), inside, 3.0).ranks(reach, reach)
        )
    assert ranks.dtype == ranks_twin.dtype == np.int32
    np.testing.assert_array_equal(ranks, ranks_twin)
    np.testing.assert_array_equal(values, values_twin)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([0.0, 0.3, 0.9, 0.995]), st.sampled_from([0.0, 0.5, 0.97]))
def test_the_depth_noise_is_the_twins(seed, repeated, holes):
    """Depth with repeated neighbours (few moved differences), pixels without depth, few pixels, an infinite depth
    (NaN differences), a window of the image (not contiguous): the same noise bit for bit."""
    from symfruit.core.surface import depth_noise

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 50, 2))
    depth = np.round(0.6 + rng.normal(0.0, 0.002, (h, w)), int(rng.integers(3, 7)))
    depth[rng.random((h, w)) < repeated] = 0.6
    depth[rng.random((h, w)) < holes] = 0.0
    if rng.random() < 0.2:
        depth[rng.integers(0, h), rng.integers(0, w)] = np.inf
    mask = rng.random((h, w)) < 0.9
    r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
    with pytest.MonkeyPatch.context() as mp:
        for d, m in ((depth, mask), (depth[r0:, c0:], mask[r0:, c0:])):
            noise, twin = _both(mp, depth_noise, d, m, floor=float(rng.choice([0.0, 0.0005])))
            assert noise == twin or (np.isnan(noise) and np.isnan(twin))


@pytest.mark.parametrize("seed", range(4))
def test_the_registration_shift_is_the_twins(monkeypatch, seed):
    """Balls apart, their depth a few pixels off their masks (noisy or not, rims without depth): the same shift."""
    from symfruit.core.surface import registration_shift

    from .test_surface import ball

    rng = np.random.default_rng(seed)
    depth = np.full((120, 160), 0.8)
    labels = np.zeros((120, 160), np.int32)
    for k, centre in enumerate(((35, 35), (110, 40), (70, 90))):
        d, disc = ball(centre=centre, radius_px=int(rng.integers(10, 20)), front=float(rng.uniform(0.4, 0.6)),
                       rim=float(rng.uniform(0.0, 0.2)))  # fmt: skip
        depth = np.where(disc, np.minimum(depth, d), depth)
        labels[disc] = k + 1
    if seed % 2:
        depth = depth + rng.normal(0.0, 0.001, depth.shape)
    shift = (int(rng.integers(-4, 5)), int(rng.integers(-4, 5)))
    moved = np.roll(depth, shift, axis=(0, 1))
    fast, twin = _both(monkeypatch, registration_shift, moved, labels, 600.0, max_px=10)
    assert fast == twin == (shift[1], shift[0])


@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40))
def test_filled_and_connected_are_the_labellings(seed, h, w):
    """Random blobs and speckle (pieces touching the edge, holes, pieces meeting at a corner only: apart, as the
    4-connected labelling has them)."""
    from scipy import ndimage

    from symfruit.core.raster import fill_holes
    from symfruit.core.surface import _connected

    rng = np.random.default_rng(seed)
    mask = _blobs(rng, h, w, rng.uniform(0.0, 0.3)) if rng.random() < 0.5 else rng.random((h, w)) < rng.random()
    out = np.empty((h, w), bool)
    _jit.filled(mask, out)
    assert np.array_equal(out, ndimage.binary_fill_holes(mask))
    seeds = rng.random((h, w)) < rng.uniform(0.0, 0.05)
    labels, _ = ndimage.label(mask)
    expected = np.isin(labels, np.unique(labels[seeds & mask]))
    _jit.connected(mask, seeds, out)
    assert np.array_equal(out, expected)
    at = (int(rng.integers(0, h)), int(rng.integers(0, w)))
    with pytest.MonkeyPatch.context() as mp:
        for fast, twin in (
            _both(mp, fill_holes, mask),
            _both(mp, _connected, mask, seeds),
            _both(mp, _connected, mask, at),
        ):
            assert np.array_equal(fast, twin)
    assert np.array_equal(_connected(mask, at), labels == labels[at])


# --- issue 19, sixteenth round: clustering, a fruit's depth mode and apex, the segmenter's red pixels, windows and
# sphere points


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([0.002, 0.006, 0.02]), st.booleans())
def test_clusters_are_the_twins(seed, distance, rounded):
    """Clouds of one to four blobs, depth slabs apart or not, lone points, coordinates on a millimetre grid (ties in
    depth and cubes): the same labels, the largest cluster 0."""
    from symfruit.extract import cluster

    rng = np.random.default_rng(seed)
    parts = [rng.normal(rng.uniform(-0.05, 0.05, 3) + [0, 0, 0.8], rng.choice([0.001, 0.005, 0.02]),
                        (int(rng.integers(1, 400)), 3)) for _ in range(int(rng.integers(1, 5)))]  # fmt: skip
    points = np.concatenate(parts)
    if rounded:
        points = np.round(points, 3)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, cluster, points, distance)
    assert fast.dtype == twin.dtype == np.int64
    np.testing.assert_array_equal(fast, twin)
    labels, done = _jit.clusters(points, distance)
    assert done and np.array_equal(labels, twin)


def test_clusters_leave_a_sparse_slab_and_non_finite_points_to_the_twin():
    """A slab whose grid of cubes would pass 2e7 cells (the twin links those through a tree): the kernel declines,
    and ``cluster`` gives the twin's labels; a coordinate that is not finite: the kernel declines too."""
    from symfruit.extract import cluster

    rng = np.random.default_rng(0)
    far = np.concatenate([rng.normal(0.0, 0.002, (50, 3)), rng.normal(0.0, 0.002, (50, 3)) + [30.0, 30.0, 0.001]])
    assert not _jit.clusters(far, 0.006)[1]
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, cluster, far, 0.006)
    np.testing.assert_array_equal(fast, twin)
    assert set(fast.tolist()) == {0, 1}
    for bad in (np.nan, np.inf):
        points = rng.normal(0.0, 0.01, (40, 3))
        points[3, 1] = bad
        assert not _jit.clusters(points, 0.006)[1]


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([5, 10, 11, 30, 400, 3000]), st.integers(0, 3),
       st.sampled_from([0.0005, 0.002, 0.1]))  # fmt: skip
def test_fruit_depth_is_the_twins_to_the_bit(seed, n, kind, noise):
    """Depths of one to three surfaces, spread wide (up to the 4096 bins' bound) or over fewer than three bins
    (numpy's masses then run past the bins), on a millimetre grid or not, with pixels without depth, with and
    without the leaf test: the same front and radius, bit for bit."""
    from symfruit.core.surface import fruit_depth

    rng = np.random.default_rng(seed)
    if kind == 0:
        values = rng.uniform(0.1, float(rng.choice([0.2, 3.0, 60.0])), n)
    elif kind == 1:
        values = 0.8 + rng.integers(0, 3, n) * 0.001
    else:
        values = np.concatenate([rng.normal(rng.uniform(0.3, 2.0), rng.choice([0.0005, 0.003, 0.03]), n)
                                 for _ in range(kind)])  # fmt: skip
    if rng.random() < 0.5:
        values = np.round(values, 3)
    values[rng.random(len(values)) < 0.1] = rng.choice([0.0, np.nan, -1.0])
    leafy = None if rng.random() < 0.3 else (rng.random(len(values)) < rng.random()) | (values < np.nanmedian(values))
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, fruit_depth, values, float(rng.uniform(1.0, 80.0)), float(rng.uniform(300.0, 1500.0)),
                           noise=noise, leafy=leafy)  # fmt: skip
    assert np.array_equal(np.array(fast), np.array(twin), equal_nan=True)


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_fruit_depths_walk_at_every_phase_is_the_twins_to_the_bit(seed, rounded):
    """A fruit and a leaf in front a gap of about one bin apart, a few pixels far nearer setting the bins' phase (the
    walk nearer meets the gap on the grid or between its edges): ``fruit_depth``'s kernel, ``depth_mode`` on the
    depths unsorted and the numpy twin give the same front and radius, bit for bit."""
    from symfruit.core.surface import fruit_depth

    rng = np.random.default_rng(seed)
    gap = float(rng.uniform(0.0, 0.03))
    n = int(rng.choice([40, 400, 1500]))
    values = np.r_[1.675 + rng.uniform(0.0, 0.035, n), rng.uniform(1.615, 1.675 - gap, int(rng.integers(1, n))),
                   rng.uniform(1.3, 1.4, int(rng.integers(0, 20)))]  # fmt: skip
    if rounded:
        values = np.round(values, 3)
    rng.shuffle(values)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, fruit_depth, values, 26.0, 1200.0, noise=0.001)
    assert np.array_equal(np.array(fast), np.array(twin), equal_nan=True)
    got = _jit.depth_mode(values, 26.0, 1200.0, 0.001, np.zeros(0, bool), False, (0.5, 0.3))
    assert got[2] and np.array_equal(np.array(got[:2]), np.array(fast))


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_no_gap_only_where_gap_before_finds_none(seed, rounded):
    """``no_gap``, the walk's look for a gap without sorting, says "none" only where ``gap_before`` on the sorted
    depths finds none (a gap a bin wide or narrower, ties on a millimetre grid, windows starting near the parts'
    edges), and the numpy twin's ``_gap_before`` finds what the kernel does."""
    from symfruit.core.surface import _gap_before

    rng = np.random.default_rng(seed)
    width = float(rng.uniform(0.002, 0.02))
    lo = float(rng.uniform(0.3, 2.0))
    bins = int(rng.integers(1, 5))
    start_end = lo + bins * width
    end = start_end + width
    gap_at = lo + float(rng.uniform(0.0, bins * width))
    gap = float(rng.uniform(0.0, 1.5 * width))
    values = rng.uniform(lo, end, int(rng.integers(20, 600)))
    values = values[(values < gap_at) | (values > gap_at + gap)]
    values = np.r_[values, rng.uniform(lo - 0.1, lo, 5), rng.uniform(end, end + 0.05, 5)]
    if rounded:
        values = np.round(values, 3)
    least = max(2.0, 0.01 * float(rng.integers(len(values), 20 * len(values))))
    run = np.sort(values[(values >= lo) & (values < end)])
    below = int(np.searchsorted(run, start_end, side="left"))
    found = _jit.gap_before(run, below, least, width)
    assert _gap_before(run, below, least, width) == found
    if _jit.no_gap(values, lo, end, start_end, width, least):
        assert found == -np.inf


def test_no_gap_counts_no_more_parts_than_twice_the_depths():
    """A walk over more bins than the depths could fill (a histogram of many narrow bins): ``no_gap`` leaves it to
    the sort instead of counting parts by the billion (its memory bounded by the depths'); NaN bounds likewise."""
    values = np.linspace(1.0, 1.2, 50)
    assert not _jit.no_gap(values, 1.0, 1.0 + 1e12, 1.0 + 1e12 - 1e-3, 1e-3, 2.0)
    assert not _jit.no_gap(values, 1.0, np.nan, 1.1, 1e-3, 2.0)
    assert _jit.no_gap(values, 1.0, 1.2, 1.1, 0.1, 2.0)  # 50 depths over two bins of 0.1: no window too empty


def test_no_gap_reads_a_fruits_depths_without_a_gap():
    """A round fruit's depths from its front to a bin past the starts (no gap: a window a bin wide always holds
    many): ``no_gap`` says so, so the sort is skipped; a gap a bin wide among them: it does not."""
    rng = np.random.default_rng(7)
    r = 0.04
    x, y = rng.uniform(-r, r, (2, 4000))
    inside = x**2 + y**2 < (0.9 * r) ** 2
    depth = 1.5 - np.sqrt(r**2 - x[inside] ** 2 - y[inside] ** 2)
    lo, width = float(depth.min()), r / 3
    assert _jit.no_gap(depth, lo, lo + 2 * width, lo + width, width, 0.01 * len(depth))
    cut = depth[(depth < lo + 0.4 * width) | (depth > lo + 1.45 * width)]
    assert not _jit.no_gap(cut, lo, lo + 2 * width, lo + width, width, 0.01 * len(cut))


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_fruit_surfaces_apex_is_the_twins(seed):
    """Noisy caps (flat ties on a millimetre grid), scattered masks, pixels without depth, masks wide enough to be
    eroded more than four times, looked for beyond the mask or not: the same surface, apex and numbers."""
    from symfruit.core.surface import fruit_surface

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(8, 90, 2))
    yy, xx = np.mgrid[:h, :w]
    cy, cx, r = rng.uniform(0, h), rng.uniform(0, w), rng.uniform(3.0, 45.0)
    inside = np.maximum(r * r - (yy - cy) ** 2 - (xx - cx) ** 2, 0.0)
    mask = (inside > 0) | (rng.random((h, w)) < rng.choice([0.0, 0.1]))
    z0 = rng.uniform(0.4, 2.0)
    depth = z0 - 0.001 * np.sqrt(inside) + rng.normal(0.0, rng.choice([0.0, 0.0005, 0.003]), (h, w))
    if rng.random() < 0.5:
        depth = np.round(depth, 3)
    depth[rng.random((h, w)) < rng.choice([0.0, 0.1, 0.5])] = 0.0
    region = None if rng.random() < 0.5 else np.ones((h, w), bool)
    leafy = None if rng.random() < 0.5 else rng.random((h, w)) < 0.3
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, fruit_surface, depth, mask, 600.0, region=region, leafy=leafy,
                           tolerance=float(rng.choice([3.0, 0.5, np.inf])))  # fmt: skip
    assert (fast is None) == (twin is None)
    if fast is not None:
        assert np.array_equal(fast.pixels, twin.pixels)
        assert (fast.front, fast.radius, fast.noise, fast.apex) == (twin.front, twin.radius, twin.noise, twin.apex)


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_depth_step_is_the_twins(seed, single):
    """Depth rounded to 1-5 decimals with pixels without depth and an infinite one (NaN differences, left out),
    float64 or float32, a window of it (strided): the same least step, bit for bit."""
    from symfruit.core.surface import depth_step

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 40, 2))
    depth = np.round(0.8 + rng.normal(0.0, 0.003, (h, w)), int(rng.integers(1, 6)))
    depth[rng.random((h, w)) < 0.2] = 0.0
    if rng.random() < 0.3:
        depth[rng.integers(0, h), rng.integers(0, w)] = np.inf
    if single:
        depth = depth.astype(np.float32)
    mask = rng.random((h, w)) < 0.8
    with pytest.MonkeyPatch.context() as mp, np.errstate(invalid="ignore"):  # inf - inf in the twin
        for d, m in ((depth, mask), (depth[:, 1:], mask[:, 1:])):
            fast, twin = _both(mp, depth_step, d, m)
            assert fast == twin and type(fast) is type(twin) is float


# --- issue 19, seventeenth round: registration, trimming, extraction, occlusion


def _whole_map(rng: np.random.Generator, h: int, w: int, top: int) -> np.ndarray:
    """(h, w) signed square roots of whole numbers below ``top`` (a map of distance transforms' values; zeros, ties)."""
    return np.sqrt(rng.integers(0, top, (h, w)).astype(float)) * rng.choice([-1.0, 1.0], (h, w))


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([4, 900, 40000, 2**31]), st.integers(0, 3))
def test_the_outlines_keys_are_the_twins(seed, top, spoil):
    """Maps of whole-number squares (int16 and int32 keys), beyond int32 (no keys), with a value that is no square
    root of a whole number, NaN or inf (no keys), empty: the same padded keys or None, bit for bit."""
    from symfruit.core.surface import _Outline

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(0, 50, 2))
    inside = _whole_map(rng, h, w, top)
    if spoil and inside.size:
        inside[rng.integers(0, h), rng.integers(0, w)] = (np.sqrt(2.5), np.nan, -np.inf)[spoil - 1]
    reach, pad = int(rng.integers(1, 30)), int(rng.integers(0, 40))
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, lambda: _Outline(np.zeros(1, int), np.zeros(1, int), inside, 3.0).keys(pad, reach))
    assert (fast is None) == (twin is None)
    if twin is not None:
        assert fast.dtype == twin.dtype
        np.testing.assert_array_equal(fast, twin)
    if spoil and inside.size:  # a value that does not come back from its key: no keys
        assert twin is None


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([4, 30, 900]), st.sampled_from([0.7, 0.5, 1.0, 0.01]))
def test_the_outlines_exact_costs_are_the_twins_to_the_bit(seed, top, trim):
    """The registration's exact costs of random maps of whole-number squares (16-bit keys; zeros of both signs, ties,
    odd and even point counts, one point, shifts beyond the window) with the deviations from the kernel and from
    the padded map: the same costs, bit for bit, in one block or several."""
    from symfruit.core import surface
    from symfruit.core.surface import _Outline

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 60, 2))
    inside = _whole_map(rng, h, w, top)
    n = int(rng.integers(1, 320))
    rows, cols, band = rng.integers(0, h, n), rng.integers(0, w, n), float(rng.choice([0.0, rng.uniform(0.0, 6.0)]))
    reach = int(rng.integers(1, 25))
    shifts = rng.integers(-reach - 3, reach + 4, (int(rng.integers(1, 60)), 2))
    with pytest.MonkeyPatch.context() as mp:
        if rng.random() < 0.3:
            mp.setattr(surface, "_BLOCK", int(rng.integers(1, 2000)))
        fast, twin = _both(mp, lambda: _Outline(rows, cols, inside, band).cost(shifts, reach, trim))
    assert _Outline(rows, cols, inside, band).keys(reach + 3, reach).dtype == np.int16  # the kernel's case
    np.testing.assert_array_equal(fast.view(np.int64), twin.view(np.int64))


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans(), st.booleans())
def test_told_costs_each_shift_as_its_told_axes_have_it(seed, tell_v, exact):
    """``_told`` of an outline that tells one axis or none: each shift costs what it costs with its untold part
    zeroed (each row's cost depends on that row alone), with and without the kernels."""
    from symfruit.core.surface import _Outline, _told

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(5, 50, 2))
    inside, n = _whole_map(rng, h, w, 900), int(rng.integers(1, 200))
    sides = np.array([[3, 4], [3, 4], [3, 4], [3, 4]])
    sides[int(rng.integers(0, 2)) + (0 if tell_v else 2), 0] = 0  # one side of the other axis not free
    if rng.random() < 0.3:
        sides[int(rng.integers(0, 2)) + (2 if tell_v else 0), 0] = 0  # neither axis told
    outline = _Outline(rng.integers(0, h, n), rng.integers(0, w, n), inside, 2.5, sides)
    shifts = rng.integers(-6, 7, (int(rng.integers(0, 50)), 2))
    zeroed = shifts * np.array(outline.axes, dtype=shifts.dtype)
    with pytest.MonkeyPatch.context() as mp:
        for kernels in ("", "numpy"):
            mp.setenv("SYMFRUIT_KERNELS", kernels)
            found = _told(outline, shifts, 6, 0.7, exact)
            expected = outline.cost(zeroed, 6, 0.7, exact=exact) if len(shifts) else np.zeros(0)
            np.testing.assert_array_equal(found, expected)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_free_points_and_sides_are_the_twins(seed):
    """Random outlines (a noisy ring, points in a line, repeated points: ties in distance and direction) about a
    cap: the same free points and the same counts of each side's free and all rim points."""
    from symfruit.core.surface import Surface, _free_points

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(20, 90, 2))
    n = int(rng.integers(12, 300))
    if rng.random() < 0.2:
        rows, cols = np.full(n, h // 2), rng.integers(0, w, n)
    else:
        t = rng.uniform(0, 2 * np.pi, n)
        r = rng.uniform(3.0, min(h, w) / 2 - 1) + rng.integers(-2, 3, n) * rng.choice([0.0, 1.0])
        rows = np.clip(np.rint(h / 2 + r * np.sin(t)), 0, h - 1).astype(np.intp)
        cols = np.clip(np.rint(w / 2 + r * np.cos(t)), 0, w - 1).astype(np.intp)
    cap = np.zeros((h, w), bool)
    cap[rows, cols] = True
    depth = np.where(rng.random((h, w)) < 0.5, 0.0, rng.choice([0.5, 0.9], (h, w)))
    surface = Surface(cap, 0.6, 0.03, 0.001, (h // 2, w // 2))
    with pytest.MonkeyPatch.context() as mp:
        (free, sides), (free_twin, sides_twin) = _both(mp, _free_points, depth, cap, rows, cols, surface)
    np.testing.assert_array_equal(free, free_twin)
    assert sides.dtype == sides_twin.dtype and sides.shape == (4, 2)
    np.testing.assert_array_equal(sides, sides_twin)


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 200), st.sampled_from([8, 12, 40]))
def test_rim_sides_take_the_first_of_equally_far_points(seed, n, bins):
    """Offsets on a small grid (many equally far points in one direction, on both sides of a diagonal, on an axis):
    the kernel's sides are those of the twin's rim (:func:`symfruit.core.surface._rim`'s lexsort: the first of the
    farthest) counted side by side."""
    rng = np.random.default_rng(seed)
    dv, du = (rng.integers(-4, 5, n).astype(float) for _ in range(2))
    free = rng.random(n) < 0.5
    radius = np.hypot(dv, du)
    angle = np.arctan2(dv, du)
    at = np.minimum(((angle + np.pi) * (bins / (2.0 * np.pi))).astype(np.intp), bins - 1)
    order = np.lexsort((-radius, at))
    outer = np.sort(order[np.r_[True, at[order][1:] != at[order][:-1]]])
    along_v = np.abs(dv[outer]) >= np.abs(du[outer])
    a, b = dv[outer], du[outer]
    sides = (along_v & (a < 0), along_v & (a > 0), ~along_v & (b < 0), ~along_v & (b > 0))
    expected = np.array([(np.count_nonzero(free[outer] & side), np.count_nonzero(side)) for side in sides])
    np.testing.assert_array_equal(_jit.rim_sides(dv, du, radius, angle, bins, bins / (2.0 * np.pi), free), expected)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans(), st.sampled_from([0, 1, 3]))
def test_extractions_depth_tests_and_points_are_the_twins(seed, single, erode):
    """Depth with NaN, inf, 0, pixels nearer and farther than the range, float32 or float64, masks of a few pixels
    (no surface looked for) or many, a camera off the window's centre: the same points, bit for bit, and counts."""
    from symfruit.core.camera import Camera
    from symfruit.extract import ExtractSettings, extract

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(2, 60, 2))
    depth = rng.uniform(0.05, 3.5, (h, w))
    depth[rng.random((h, w)) < 0.1] = rng.choice([0.0, np.nan, np.inf, -np.inf])
    if single:
        depth = depth.astype(np.float32)
    mask = rng.random((h, w)) < rng.choice([0.05, 0.9])
    camera = Camera(fx=float(rng.uniform(300, 900)), fy=float(rng.uniform(300, 900)), cx=float(rng.uniform(-5, w)),
                    cy=float(rng.uniform(-5, h)), width=w, height=h)  # fmt: skip
    s = ExtractSettings(erode_px=erode, min_points=4)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, extract, mask, depth, camera, s)
    assert fast.points.dtype == twin.points.dtype and fast.points.shape == twin.points.shape
    np.testing.assert_array_equal(fast.points.view(np.int64), twin.points.view(np.int64))
    assert (fast.mask_area, fast.n_invalid, fast.n_border, fast.n_other_clusters) == (
        twin.mask_area, twin.n_invalid, twin.n_border, twin.n_other_clusters)  # fmt: skip
    z = np.asarray(depth, dtype=np.float64)
    valid, usable = np.empty((h, w)), np.empty((h, w), bool)
    n_invalid, n_usable = _jit.valid_depth(z, mask, 0.1, 3.0, valid, usable)
    ok = np.isfinite(z) & (z >= 0.1) & (z <= 3.0)
    assert (n_invalid, n_usable) == (int((mask & ~ok).sum()), int((mask & ok).sum()))
    np.testing.assert_array_equal(valid, np.where(ok, z, 0.0))
    np.testing.assert_array_equal(usable, mask & ok)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([0.5, 1.0, 2.6, 4.0]))
def test_colour_trims_regions_are_the_twins(seed, band_px):
    """Random blobs (holes, thin parts, pieces at the edge, too few pixels for a ring or a fruit) on random colours
    with a red disc: colour_trim with the kernels and with the twins gives the same pixels, and the regions' kernel
    numpy's comparisons."""
    from symfruit.core.raster import inner_distance
    from symfruit.core.surface import colour_trim, within

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(3, 70, 2))
    mask = _blobs(rng, h, w, float(rng.uniform(0.01, 0.2)))
    yy, xx = np.mgrid[:h, :w]
    disc = (yy - h / 2) ** 2 + (xx - w / 2) ** 2 < (min(h, w) / 3) ** 2
    colour = np.where(disc[..., None], [200, 30, 30], [40, 160, 60]) + rng.integers(0, 40, (h, w, 3))
    with pytest.MonkeyPatch.context() as mp:
        trimmed, twin = _both(mp, colour_trim, colour.astype(np.uint8), mask | disc, band_px=band_px)
    np.testing.assert_array_equal(trimmed, twin)
    inner = inner_distance(mask)
    regions = [np.empty((h, w), bool) for _ in range(3)]
    counts = _jit.trim_regions(inner, mask, band_px, 3.0 * band_px + 1, band_px + 1.0, *regions)
    expected = ((inner > band_px) & (inner <= 3.0 * band_px + 1), ~mask & within(mask, band_px + 1),
                mask & (inner <= band_px))  # fmt: skip
    for found, want in zip(regions, expected, strict=True):
        np.testing.assert_array_equal(found, want)
    assert counts == tuple(int(x.sum()) for x in expected)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 3), st.sampled_from([0, 5, 16]))
def test_the_occlusion_window_and_own_depths_are_the_twins(seed, reach, pad):
    """Points projecting onto pixel centres and halfway between them (np.rint's ties to even), several on one pixel
    (the least depth), off the image, with infinite or NaN coordinates, none in the image: the same window and maps
    bit for bit, or the same error."""
    from symfruit.core.camera import Camera
    from symfruit.core.occlusion import occlusion
    from symfruit.errors import InputError

    rng = np.random.default_rng(seed)
    camera = Camera(fx=200.0, fy=200.0, cx=30.0, cy=20.0, width=60, height=40)
    n = int(rng.integers(1, 200))
    u = rng.integers(-3, 63, n) + rng.choice([0.0, 0.5, -0.5, 0.25], n)
    v = rng.integers(-3, 43, n) + rng.choice([0.0, 0.5, -0.5], n)
    z = np.round(rng.uniform(0.3, 0.5, n), int(rng.integers(2, 6)))
    points = np.column_stack(((u - 30.0) * z / 200.0, (v - 20.0) * z / 200.0, z))
    if rng.random() < 0.3:
        points[rng.integers(0, n), int(rng.integers(0, 3))] = rng.choice([np.inf, -np.inf, np.nan])
    if rng.random() < 0.1:
        points[:, 0] = 50.0  # every point far off the image
    depth = rng.uniform(0.2, 1.0, (40, 60))
    depth[rng.random((40, 60)) < 0.2] = 0.0
    mask = rng.random((40, 60)) < 0.1
    results = []
    with pytest.MonkeyPatch.context() as mp:
        for kernels in ("", "numpy"):
            mp.setenv("SYMFRUIT_KERNELS", kernels)
            try:
                with np.errstate(invalid="ignore", over="ignore"):
                    results.append(occlusion(depth, mask, points, camera, reach=reach, pad=pad))
            except InputError as exc:
                results.append(str(exc))
    fast, twin = results
    if isinstance(twin, str):
        assert fast == twin
        return
    assert (fast.u0, fast.v0) == (twin.u0, twin.v0) and fast.hidden.shape == twin.hidden.shape
    assert np.array_equal(fast.hidden, twin.hidden) and fast.depth.tobytes() == twin.depth.tobytes()
    with np.errstate(invalid="ignore", over="ignore"):
        uv = camera.project(points)
    found, u0, v0, u1, v1, own, unseen = _jit.own_depths(uv, points, 60, 40, pad)
    assert found and (u0, v0, u1 - u0, v1 - v0) == (twin.u0, twin.v0, twin.hidden.shape[1], twin.hidden.shape[0])
    np.testing.assert_array_equal(unseen, ~np.isfinite(own))


@given(st.integers(0, 2**32 - 1), st.sampled_from([0.0, 0.1, 0.5]), st.sampled_from([0.8, 3.0, np.inf]))
def test_the_registrations_valid_depth_is_the_twins(seed, low, high):
    """The registration's window depth by the extraction's kernel with ``z > 0 and z >= low`` as ``z >= max(low, the
    least positive double)``, and fruit_surface's depth above 0: subnormal, zero, negative, NaN and infinite depths,
    the twins' maps bit for bit."""
    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 40, 2))
    z = rng.uniform(-0.2, 4.0, (h, w))
    z[rng.random((h, w)) < 0.3] = rng.choice([0.0, -0.0, 5e-324, 1e-310, -5e-324, np.nan, np.inf, -np.inf])
    valid = np.empty((h, w))
    _jit.valid_depth(z, rng.random((h, w)) < 0.5, max(low, 5e-324), high, valid, np.empty((h, w), bool))
    with np.errstate(invalid="ignore"):
        twin = np.where(np.isfinite(z) & (z > 0) & (z >= low) & (z <= high), z, 0.0)
        positive = np.where(np.isfinite(z) & (z > 0), z, 0.0)
    assert valid.tobytes() == twin.tobytes()
    _jit.positive_depth(z, valid)  # fruit_surface's depth: the same values
    assert valid.tobytes() == positive.tobytes()


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 60), st.integers(1, 60))
def test_principal_widths_are_the_twins_to_the_bit(seed, h, w):
    """Random blobs and speckle (none, one or two pixels, a line), at the origin or placed in a larger image: the
    same widths bit for bit, and the kernel's centred coordinates numpy's."""
    from symfruit.core.raster import principal_widths

    rng = np.random.default_rng(seed)
    mask = _blobs(rng, h, w, float(rng.uniform(0.0, 0.2))) if rng.random() < 0.7 else rng.random((h, w)) < 0.02
    if rng.random() < 0.1:
        mask = np.zeros((h, w), bool)
        mask[rng.integers(0, h), :] = True
    origin = (0, 0) if rng.random() < 0.3 else (int(rng.integers(0, 900)), int(rng.integers(0, 1500)))
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, principal_widths, mask, origin=origin)
    assert fast == twin and all(type(x) is float for x in fast)
    if mask.sum() >= 2:
        rows, cols = np.nonzero(mask)
        xy = np.column_stack((cols + origin[1], rows + origin[0])).astype(np.float64)
        xy -= np.array([int(xy[:, 0].sum()), int(xy[:, 1].sum())], dtype=np.float64) / len(rows)
        assert _jit.centred_pixels(mask, origin[0], origin[1]).tobytes() == xy.tobytes()
    else:  # fewer than two pixels: none (principal_widths counts them then)
        assert _jit.centred_pixels(mask, origin[0], origin[1]).shape == (0, 2)


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 40))
def test_joined_boxes_are_the_twins(seed, n):
    """Random boxes on small and large grids (chains that join over several rounds, boxes that only touch at a
    corner, none): the same boxes in the same order, as Python ints."""
    from symfruit.segment.colour import _join_boxes

    rng = np.random.default_rng(seed)
    size = int(rng.choice([10, 30, 100]))
    boxes = [(int(a), int(a + rng.integers(1, 8)), int(c), int(c + rng.integers(1, 8)))
             for a, c in zip(rng.integers(0, size, n), rng.integers(0, size, n), strict=True)]  # fmt: skip
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _join_boxes, list(boxes))
    assert fast == twin
    assert all(type(x) is int for box in fast for x in box)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans(), st.booleans())
def test_red_pixels_are_the_twins(seed, window, own_settings):
    """Random colours (many of them reddish), a window of an image (strided) or a whole one, the default settings
    or others: the same weak and strong pixels."""
    from symfruit.segment.colour import SegmentSettings, _red_pixels

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 70, 2))
    image = rng.integers(0, 256, (h + 6, w + 6, 3), dtype=np.uint8)
    image[..., 0] = np.maximum(image[..., 0], rng.integers(0, 256, (h + 6, w + 6)).astype(np.uint8))
    c = image[3 : 3 + h, 2 : 2 + w] if window else image
    s = SegmentSettings()
    if own_settings:
        s = SegmentSettings(red_low=float(rng.uniform(0.05, 0.4)), red_high=float(rng.uniform(0.4, 0.7)),
                            hue_max=float(rng.uniform(5.0, 40.0)), dark=int(rng.integers(0, 60)))  # fmt: skip
    with pytest.MonkeyPatch.context() as mp:
        (weak, strong), (weak_twin, strong_twin) = _both(mp, _red_pixels, c, s)
    assert weak.dtype == weak_twin.dtype and strong.dtype == strong_twin.dtype
    np.testing.assert_array_equal(weak, weak_twin)
    np.testing.assert_array_equal(strong, strong_twin)
    assert len(strong) > 0


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([1500, 300, 50]), st.booleans())
def test_the_segmenters_sphere_points_and_fit_are_the_twins(seed, most, single):
    """A noisy cap with speckle and pixels without depth, float64 or float32 depth, more pixels than ``most`` or
    fewer: the same points, bit for bit, and the same sphere to a nanometre (the kernel's least squares by Householder
    reflections, the twin's by LAPACK's SVD; issue 19, eighteenth round)."""
    from symfruit.segment.colour import _Geometry, _points, _sphere

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(5, 120, 2))
    yy, xx = np.mgrid[:h, :w]
    cy, cx, r = rng.uniform(0, h), rng.uniform(0, w), rng.uniform(3.0, 60.0)
    inside = np.maximum(r * r - (yy - cy) ** 2 - (xx - cx) ** 2, 0.0)
    mask = (inside > 0) | (rng.random((h, w)) < 0.05)
    depth = rng.uniform(0.4, 2.0) - 0.001 * np.sqrt(inside) + rng.normal(0.0, 0.002, (h, w))
    depth[rng.random((h, w)) < 0.2] = 0.0
    if single:
        depth = depth.astype(np.float32)
    geo = _Geometry(float(rng.uniform(300, 1500)), float(rng.uniform(0, 480)), float(rng.uniform(0, 640)))
    origin = (int(rng.integers(0, 400)), int(rng.integers(0, 600)))
    with pytest.MonkeyPatch.context() as mp:
        points, points_twin = _both(mp, _points, mask, depth, geo, origin, most)
        fit, fit_twin = _both(mp, _sphere, mask, depth, geo, origin, most)
    assert points.dtype == points_twin.dtype == np.float64
    np.testing.assert_array_equal(points, points_twin)
    assert (fit is None) == (fit_twin is None)
    if fit is not None:
        np.testing.assert_allclose(fit[0], fit_twin[0], rtol=0, atol=1e-9)
        assert abs(fit[1] - fit_twin[1]) <= 1e-9


@pytest.mark.parametrize("seed", range(3))
def test_extraction_is_the_twins(monkeypatch, seed):
    """A ball's extraction (the border's erosion, the surface, the clusters) with the kernels and with the numpy
    twins: the same points and counts."""
    from symfruit.core.camera import Camera
    from symfruit.extract import extract

    depth, mask, _ = _ball_frame(seed)
    h, w = mask.shape
    camera = Camera(fx=600.0, fy=600.0, cx=w / 2.0, cy=h / 2.0, width=w, height=h)
    fast, twin = _both(monkeypatch, extract, mask, depth, camera)
    np.testing.assert_array_equal(fast.points, twin.points)
    assert (fast.n_invalid, fast.n_border, fast.n_other_clusters) == (twin.n_invalid, twin.n_border,
                                                                       twin.n_other_clusters)  # fmt: skip
    assert len(fast.points) > 100


# --- issue 19, seventeenth round: the colour segmenter --------------------------------------------------------------


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(["speckle", "disc", "line", "pixel", "strided"]))
def test_the_segmenters_hull_vertices_are_the_twins(seed, kind):
    """Speckle of any density, a disc, a line (no hull), one pixel, a strided view: the monotone chain's vertices are
    Qhull's, counter-clockwise from the least (y, x), and so is the filled hull, bit for bit."""
    from symfruit.segment.colour import _hull_area, _hull_vertices, convex_hull_mask

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 90, 2))
    mask = rng.random((h, w)) < rng.uniform(0.001, 0.9)
    if kind == "disc":
        yy, xx = np.mgrid[:h, :w]
        mask = (yy - rng.uniform(0, h)) ** 2 + (xx - rng.uniform(0, w)) ** 2 <= rng.uniform(0.5, 40.0) ** 2
    elif kind in ("line", "pixel"):
        mask = np.zeros((h, w), bool)
        mask[rng.integers(0, h), : rng.integers(1, w + 1) if kind == "line" else 1] = True
        mask = mask.T.copy() if rng.random() < 0.5 else mask
    elif kind == "strided":
        mask = mask[:: int(rng.integers(1, 3)), :: int(rng.integers(2, 4))]
    with pytest.MonkeyPatch.context() as mp:
        v, v_twin = _both(mp, _hull_vertices, mask)
        hull, hull_twin = _both(mp, convex_hull_mask, mask)
        area, area_twin = _both(mp, _hull_area, mask)
    assert (v is None) == (v_twin is None)
    if kind in ("line", "pixel"):
        assert v is None
    if v is not None:
        assert v.dtype == v_twin.dtype == np.float64
        np.testing.assert_array_equal(v, v_twin)
        assert (v[0, 1], v[0, 0]) == min((y, x) for x, y in v.tolist())  # the start: the least (y, x)
        x, y = v[:, 0], v[:, 1]
        assert np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)) > 0  # counter-clockwise in (x, y)
    np.testing.assert_array_equal(hull, hull_twin)
    assert area == area_twin


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("window", [False, True])
def test_the_segmenters_green_and_leaf_pixels_are_the_twins(seed, window):
    """Random colours with green the largest channel as often as not, whole or a strided window: the same green and
    leaf-green pixels, and some of each."""
    from symfruit.segment.colour import _green, _leaf

    rng = np.random.default_rng(seed)
    image = rng.integers(0, 256, (70, 90, 3), dtype=np.uint8)
    image[..., 1] = np.maximum(image[..., 1], rng.integers(0, 256, (70, 90)).astype(np.uint8))
    c = image[3:60, 2:80:2] if window else image
    with pytest.MonkeyPatch.context() as mp:
        green, green_twin = _both(mp, _green, c)
        leaf, leaf_twin = _both(mp, _leaf, c)
    assert green.dtype == green_twin.dtype == leaf.dtype == leaf_twin.dtype == np.bool_
    np.testing.assert_array_equal(green, green_twin)
    np.testing.assert_array_equal(leaf, leaf_twin)
    assert 0 < leaf.sum() < green.sum() < green.size


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(0.2, 0.8), st.floats(0.0, 0.05))
def test_the_flood_is_the_labelling_of_the_seeds_components(seed, density, seeded):
    """Random pixels allowed (clusters of every size) and seeds (some outside the allowed pixels): the flood is the
    union of ``ndimage.label``'s components (4-connected) that hold a seed, bit for bit, and holds no seed outside."""
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 70, 2))
    allowed = rng.random((h, w)) < density
    seeds = rng.random((h, w)) < seeded
    lab, n = ndimage.label(allowed)
    held = np.zeros(n + 1, bool)
    held[lab[seeds]] = True
    held[0] = False
    got = _jit.flood(allowed, seeds)
    assert got.dtype == np.bool_
    np.testing.assert_array_equal(got, held[lab])
    assert not (got & ~allowed).any()


def test_the_round_skin_and_the_waist_test_are_the_twins(monkeypatch):
    """A red cap on a yellow apple, a leaf across it (the skin's flood stops there), and two discs joined by a
    neck (the waist test's flood, below and above the neck's depth): the same skin and answers with the kernels and
    with the twins, and the known ones."""
    from symfruit.core.raster import distance_transform
    from symfruit.segment.colour import SegmentSettings, _Depth, _Geometry, _round_skin, _separate

    h, w = 120, 160
    yy, xx = np.mgrid[:h, :w]
    disc = (yy - 60) ** 2 + (xx - 70) ** 2 <= 40**2
    depth = np.where(disc, 0.8 - 0.0004 * np.sqrt(np.maximum(40**2 - (yy - 60) ** 2 - (xx - 70) ** 2, 0)), 1.5)
    color = np.zeros((h, w, 3), np.uint8)
    color[disc] = (200, 180, 40)  # yellow skin
    color[(yy - 60) ** 2 + (xx - 60) ** 2 <= 15**2] = (200, 30, 30)  # the red part
    color[:, 82:86] = (40, 150, 40)  # a leaf over the skin
    red = (yy - 60) ** 2 + (xx - 60) ** 2 <= 15**2
    s = SegmentSettings(round_fruit=True)
    geo = _Geometry(600.0, 60.0, 80.0)
    owner = np.zeros((h, w), np.int16)
    owner[20:30, 50:70] = 2  # another fruit's red pixels
    depth[85:95, 50:70] -= 0.05  # a step in front
    sl = (slice(40, 80), slice(40, 80))
    fast, twin = _both(monkeypatch, _round_skin, sl, red[sl], _Depth(depth), color, geo, s, owner, 1)
    assert fast[0] == twin[0]
    np.testing.assert_array_equal(fast[1], twin[1])
    grown = np.zeros((h, w), bool)
    grown[fast[0]] = fast[1]
    assert grown[60, 35] and grown[60, 79] and not grown[60, 84] and not grown[60, 88]  # not past the leaf
    assert grown.sum() > 2 * red.sum() and not grown[20:30, 50:70].any() and not grown[85:95, 50:70].any()
    two = ((yy - 60) ** 2 + (xx - 40) ** 2 <= 30**2) | ((yy - 60) ** 2 + (xx - 115) ** 2 <= 25**2)
    two |= (abs(yy - 60) <= 4) & (xx > 40) & (xx < 115)  # a neck 9 pixels wide
    edt = distance_transform(two)
    centres = [(60, 40, float(edt[60, 40]), True)]
    for t, want in ((6.0, True), (3.0, False), (27.0, True)):  # above the neck, below it, above the smaller peak
        got = _both(monkeypatch, _separate, edt, (60, 115), centres, t, [5])
        assert got == (want, want)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 3000))
def test_numpys_sum_and_variance_are_the_twins_bit_for_bit(seed, n):
    """numpy's pairwise sum and variance of a strided column, every length from one lane to several blocks: the
    same values bit for bit (the segmenter's sphere spread rests on them)."""
    rng = np.random.default_rng(seed)
    col = (rng.normal(size=(n, 3)) * rng.uniform(1e-3, 10.0) + rng.uniform(-5.0, 5.0))[:, int(rng.integers(0, 3))]
    assert _jit._pairwise_sum(col, 0, n) + 0.0 == np.sum(col)
    assert _jit._variance(col) == np.var(col)


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 12), st.booleans())
def test_the_segmenters_peaks_are_scipys(seed, radius, ties):
    """A map of random depths (whole numbers: ties) on images smaller and larger than the square: the peaks are the
    pixels at least ``least`` deep that ``ndimage.maximum_filter`` (mode "reflect") leaves as they are."""
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 60, 2))
    edt = rng.uniform(0.0, 30.0, (h + 2, w + 2))
    edt = np.floor(edt / 3.0) if ties else edt
    edt = edt[1:-1, 1:-1]  # a view, as the segmenter's
    least = float(rng.uniform(0.0, 6.0))
    want = (edt >= ndimage.maximum_filter(edt, size=2 * radius + 1)) & (edt >= least)
    np.testing.assert_array_equal(_jit.peaks(edt, radius, least), want)
    assert want.any() or edt.max() < least


@pytest.mark.parametrize("seed", range(3))
def test_the_segmenters_centres_are_the_twins(monkeypatch, seed):
    """Three to five overlapping discs of random sizes: the same centres with the kernels and with the twins, coarse
    or not; and at least two."""
    from symfruit.segment.colour import _centres

    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[:140, :200]
    region = np.zeros((140, 200), bool)
    for _ in range(int(rng.integers(3, 6))):
        region |= (yy - rng.uniform(30, 110)) ** 2 + (xx - rng.uniform(30, 170)) ** 2 <= rng.uniform(12, 35) ** 2
    for coarse, least in ((True, 10.0), (False, 4.0)):
        fast, twin = _both(monkeypatch, _centres, region, least, 0.6, 0.9, coarse=coarse)
        assert fast == twin
        assert len(fast) >= 2


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(0.02, 0.9), st.booleans(), st.booleans())
def test_the_labelling_is_scipys(seed, density, eight, strided):
    """Random masks of every density, whole or a strided view, 4- or 8-connected: ``ndimage.label``'s labels (the
    same numbers: by the first pixel in raster order) and count, int32."""
    from scipy import ndimage

    from symfruit.segment.colour import _label

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 70, 2))
    mask = rng.random((h, w)) < density
    mask = mask[::2, 1::3] if strided else mask
    want, n = ndimage.label(mask, structure=np.ones((3, 3), bool) if eight else None)
    got, m = _jit.label(mask, eight)
    assert got.dtype == want.dtype == np.int32
    np.testing.assert_array_equal(got, want)
    assert m == n
    with pytest.MonkeyPatch.context() as mp:
        (fast, k), (twin, k_twin) = _both(mp, _label, mask, eight=eight)
    np.testing.assert_array_equal(fast, twin)
    assert k == k_twin == n


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.sampled_from([0.0, 0.7, 2.0, 3.3]))
def test_the_correlation_and_the_creases_are_scipys(seed, n, sigma):
    """scipy's ``correlate1d`` (mode "reflect") of lines shorter and longer than the weights, symmetric or not: the
    same values bit for bit; and a noisy depth of two touching caps: the same creases with the kernel and the
    twin (the Gaussian's smoothing, then the Laplacian), some of them along the seam."""
    from scipy import ndimage

    from symfruit.segment.colour import SegmentSettings, _creases, _gaussian_weights

    rng = np.random.default_rng(seed)
    line = rng.normal(size=n) * rng.uniform(0.01, 3.0)
    for weights, symmetric in (_gaussian_weights(max(sigma, 0.5)), (rng.normal(size=int(rng.integers(1, 9))), False)):
        out = np.empty(n)
        _jit._correlate_line(line, weights, symmetric, out)
        np.testing.assert_array_equal(out, ndimage.correlate1d(line, weights, mode="reflect"))
    h, w = 50, 80
    yy, xx = np.mgrid[:h, :w]
    caps = np.minimum(np.hypot(yy - 25, xx - 22), np.hypot(yy - 25, xx - 58))
    depth = 0.5 + 0.0003 * caps**2 + rng.normal(0.0, 0.0003, (h, w))
    region = caps < 22
    valid = region & (rng.random((h, w)) > 0.1)
    s = SegmentSettings(crease_sigma=sigma)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _creases, region, depth, valid, 0.5, s, 600.0)
    np.testing.assert_array_equal(fast, twin)
    if sigma >= 2.0:
        assert fast[20:30, 38:42].any() and not fast[17:33, 14:30].any()  # the seam, not a cap's middle


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("window", [False, True])
def test_the_segmenters_red_regions_are_the_twins(seed, window):
    """Blobs of red over random colours, whole or a strided window: the same weak mask, labels, region sizes, seeds,
    rows and columns (values and types) with the kernel and with the twins; several regions, some seeded."""
    from symfruit.segment.colour import SegmentSettings, _red_regions

    rng = np.random.default_rng(seed)
    image = rng.integers(0, 256, (90, 120, 3), dtype=np.uint8)
    yy, xx = np.mgrid[:90, :120]
    for _ in range(6):
        blob = (yy - rng.uniform(0, 90)) ** 2 + (xx - rng.uniform(0, 120)) ** 2 <= rng.uniform(3, 15) ** 2
        image[blob] = (int(rng.integers(120, 256)), int(rng.integers(0, 90)), int(rng.integers(0, 90)))
    c = image[5:80, 3:110:2] if window else image
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _red_regions, c, SegmentSettings())
    assert fast is not None and twin is not None
    assert fast[2] == twin[2] > 3 and fast[4].sum() >= 2
    for a, b in zip(fast, twin, strict=True):
        if isinstance(a, np.ndarray):
            assert a.dtype == b.dtype
            np.testing.assert_array_equal(a, b)


# --- issue 19, seventeenth round: the completion -------------------------------------------------------------------


@given(
    st.integers(0, 2**32 - 1),
    st.lists(st.sampled_from([0.5, 1.0, 2.0, 2.3, 5.0, 8.0]), min_size=1, max_size=4),
    st.integers(0, 100),
)
def test_band_rays_are_the_twins_to_the_bit(seed, bands, n_band):
    """The band pixels' image coordinates and viewing rays (a window anywhere in the image, a camera of unequal
    focal lengths and a fractional principal point): the same values, in the same order, as the twin's."""
    from symfruit.core.agreement import _band_rays
    from symfruit.core.camera import Camera
    from symfruit.core.raster import Silhouette

    rng = np.random.default_rng(seed)
    dist = rng.integers(0, 20, (int(rng.integers(1, 60)), int(rng.integers(1, 60)))) * 0.5
    dist[rng.random(dist.shape) < 0.1] = np.inf
    dist[rng.random(dist.shape) < 0.05] = np.nan
    cam = Camera(fx=float(rng.uniform(300, 900)), fy=float(rng.uniform(300, 900)), cx=float(rng.uniform(200, 400)),
                 cy=float(rng.uniform(150, 300)), width=640, height=480)  # fmt: skip
    region = Silhouette(int(rng.integers(0, 500)), int(rng.integers(0, 400)), np.ones(dist.shape, bool), 0.0)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _band_rays, dist, tuple(bands), n_band, region, cam)
    for a, b in zip(fast, twin, strict=True):
        assert a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b)
    assert len(fast[0]) == fast[2].sum() and (len(fast[0]) == 0 or np.all(fast[1][:, 2] == 1.0))


@given(st.integers(0, 2**32 - 1), st.floats(-12.0, 0.0), st.booleans())
def test_least_eigenvalue_is_eigvalshs(seed, log_small, repeated):
    """Symmetric 3x3 matrices, positive semi-definite as covariances are, with a least eigenvalue down to 1e-12 of
    the largest (a clean scan's flat neighbourhood), a repeated one, diagonal ones: LAPACK's least eigenvalue within
    its own rounding (a few units of the largest one's last place)."""
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    values = np.array([10.0**log_small, 0.5 if not repeated else 10.0**log_small, 1.0]) * rng.uniform(1e-8, 1e-4)
    m = (q * values) @ q.T
    m = 0.5 * (m + m.T)
    for mat in (m, np.diag(values[::-1])):
        got = _jit.least_eigenvalue(mat, np.empty((3, 3)))
        assert got == pytest.approx(np.linalg.eigvalsh(mat)[0], abs=64 * np.finfo(float).eps * values.max())
    assert np.isnan(_jit.least_eigenvalue(np.full((3, 3), np.nan), np.empty((3, 3))))


@pytest.mark.parametrize("kind,noise,queries", [("apple", 0.0, 120), ("pear", 0.002, 40), ("banana", 0.001, 7),
                                                 ("apple", 0.0005, 40)])  # fmt: skip
def test_noise_measures_are_the_twins(monkeypatch, kind, noise, queries):
    """The surface-noise ratio and noise in one compiled call: surface_noise's to rounding (the least eigenvalues of
    clean scans' flat neighbourhoods are LAPACK's to its absolute precision), and the twin itself under
    ``SYMFRUIT_KERNELS=numpy``; a cloud past the brute force's bound goes to the twin."""
    from symfruit.core import fits

    fruit = FRUITS[kind](np.random.default_rng(3))
    visible, _ = rendered_view(fruit, [0.01, -0.01, 0.4], noise=noise, rotation=rotation(10, 20, 30), seed=3)
    (ratio, level), (ratio_twin, level_twin) = _both(monkeypatch, fits.noise_measures, visible, queries=queries)
    assert isinstance(ratio, float) and ratio == pytest.approx(ratio_twin, rel=1e-11)
    assert isinstance(level, float) and level > 0 and level == pytest.approx(level_twin, rel=1e-9, abs=1e-12)
    monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    assert (ratio_twin, level_twin) == fits.surface_noise(visible, queries=queries)[:2]
    monkeypatch.delenv("SYMFRUIT_KERNELS")
    monkeypatch.setattr(fits, "_BRUTE_NEIGHBOURS", 0)
    assert fits.noise_measures(visible, queries=queries) == fits.surface_noise(visible, queries=queries)[:2]


@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40), st.floats(0.0, 1.0), st.integers(1, 200))
def test_outline_pixels_are_the_twins_to_the_bit(seed, h, w, share, count):
    """Random masks (empty to full, touching the array's edges, one pixel wide), thinned to ``2 count`` or not: the
    same outline pixels, in the same order, at the same image coordinates."""
    from symfruit.core.agreement import _outline_uv
    from symfruit.core.raster import Silhouette

    rng = np.random.default_rng(seed)
    region = Silhouette(int(rng.integers(0, 600)), int(rng.integers(0, 400)), rng.random((h, w)) < share, 0.0)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _outline_uv, region, count)
    assert fast.dtype == twin.dtype == np.float64 and fast.shape == twin.shape and np.array_equal(fast, twin)


@given(st.integers(0, 2**32 - 1), st.integers(1, 3000), st.integers(1, 4), st.booleans())
def test_column_means_are_numpys_to_the_bit(seed, n, k, strided):
    """Rows of points far from the origin and near it, one row, a strided view (left to numpy): ``mean(axis=0)``'s
    values, bit for bit, with the kernels and without."""
    from symfruit.core.points import column_means

    rng = np.random.default_rng(seed)
    p = rng.normal(0.0, 10.0 ** rng.uniform(-4, 1), (n, k)) + rng.uniform(-1, 1, k)
    if strided:
        p = np.repeat(p, 2, axis=0)[::2]
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, column_means, p)
    assert np.array_equal(fast, p.mean(axis=0)) and np.array_equal(twin, p.mean(axis=0))


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([3, 7]), st.booleans())
def test_the_ground_colour_candidates_are_the_twins(seed, size, strided):
    """Random colours (yellow to leaf green and others) over a depth of two surfaces with holes and a band without
    depth between them, whole or a strided view of the colour: the same ground-colour pixels off the depth steps with
    the kernel and with the twins (``_ground``, ``_gap_filled``, ``_steps``); some kept, some dropped on a step."""
    from symfruit.segment.colour import _ground, _ground_steps

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 60, 2))
    image = rng.integers(0, 256, (2 * h, 3 * w, 3), dtype=np.uint8)
    image[rng.random(image.shape[:2]) < 0.5] = (200, 190, 40)  # a yellow ground colour
    c = image[::2, 1::3] if strided else image[:h, :w]
    depth = np.where(np.arange(w) < w // 2, 0.8, 1.1) + rng.normal(0.0, 0.004, (h, w))
    depth[rng.random((h, w)) < 0.2] = 0.0
    depth[:, w // 2 : w // 2 + int(rng.integers(0, 3))] = 0.0  # filled over: a step at its nearer edge
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _ground_steps, c, depth, size, 0.02)
    np.testing.assert_array_equal(fast, twin)
    assert fast.dtype == bool and fast.shape == (h, w)
    assert not (fast & ~_ground(c)).any()
    if h >= 8 and w >= 8:
        assert fast.any() and (_ground(c) & ~fast).any()


# --- issue 19, eighteenth round (stop 38): registration, extraction, occlusion -------------------------------------


def _steps_within(reach: int) -> np.ndarray:
    """core.occlusion's offsets within ``reach``, nearest first, as the kernels read them."""
    from symfruit.core.occlusion import _steps

    return _steps(reach)


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 30), st.integers(1, 30), st.integers(0, 3), st.booleans(),
       st.booleans(), st.sampled_from([0.0, 0.005, -0.005]), st.floats(0.0, 0.05))  # fmt: skip
def test_the_occlusion_window_is_the_maps_after_the_nearest_pixels(seed, h, w, reach, single, with_others, tol, spread):
    """occlusion_window against occlusion_maps after nearest of the points' pixels: the same hidden pixels and seen
    depths, bit for bit, on windows whose depths and point depths come from a few values (ties between equally near
    point pixels of different depths, depths on the bounds), dropouts as 0 and NaN, float32 and float64, with other
    fruit or without, bounds at the points' least and greatest depth or wider; and some rows looked at, not all."""
    rng = np.random.default_rng(seed)
    own_z = np.full((h, w), np.inf)
    n = int(rng.integers(1, max(2, h * w // 3)))
    own_z[rng.integers(0, h, n), rng.integers(0, w, n)] = rng.choice([0.5, 0.51, 0.52, 0.53], n)
    depth = rng.choice([0.0, np.nan, 0.49, 0.5, 0.505, 0.51, 0.515, 0.52, 0.525, 0.53, 0.535, 0.6], (h, w))
    depth = depth.astype(np.float32 if single else np.float64)
    mask = rng.random((h, w)) < 0.2
    others = rng.random((h, w)) < 0.3 if with_others else np.zeros((0, 0), bool)
    steps = _steps_within(reach)
    near = np.empty((h, w), np.int64)
    _jit.nearest(~np.isfinite(own_z), near)
    hidden, seen = np.empty((h, w), bool), np.empty((h, w))
    _jit.occlusion_maps(depth, mask, own_z, near, others, tol, steps, hidden, seen)
    finite = own_z[np.isfinite(own_z)]
    hid, sn = np.empty((h, w), bool), np.empty((h, w))
    rows = _jit.occlusion_window(depth, mask, own_z, others, tol, steps, float(finite.min()) - spread,
                                 float(finite.max()) + spread, hid, sn)  # fmt: skip
    assert np.array_equal(hid, hidden) and sn.tobytes() == seen.tobytes()
    assert 0 <= rows <= h


def test_the_occlusion_window_skips_rows_that_do_not_need_the_nearest_pixels():
    """A window whose only pixel between the bounds (plus the tolerance) sits on one row: that row alone is looked
    at; a pixel nearer than them is hidden without it, the background behind them is not."""
    own_z = np.full((20, 30), np.inf)
    own_z[8:12, 10:15] = 0.5
    depth = np.full((20, 30), 1.0)
    depth[3, 20] = 0.51  # behind the fruit's 0.5 + 0.005: not hidden, once its nearest point pixel is known
    depth[5, 2] = 0.502  # nearer than the least bound plus the tolerance
    hidden, seen = np.empty((20, 30), bool), np.empty((20, 30))
    none = np.zeros((0, 0), bool)
    assert _jit.occlusion_window(depth, np.zeros((20, 30), bool), own_z, none, 0.005, _steps_within(3), 0.5, 0.52,
                                 hidden, seen) == 1  # fmt: skip
    assert hidden.sum() == 1 and hidden[5, 2]


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40), st.integers(0, 4), st.integers(0, 4))
def test_the_allowed_box_is_the_box_of_the_allowed_pixels(seed, h, w, gap, thin):
    """allowed_box against the box of allowed's pixels (mask_box; not found for no seen pixel in the window), on
    random hidden pixels and seen regions placed partly or wholly outside the window; and _square_extreme's filters
    against square_filter's, pixel for pixel."""
    from symfruit.core.raster import mask_box

    rng = np.random.default_rng(seed)
    hidden = rng.random((h, w)) < rng.choice([0.1, 0.4, 0.7, 0.9])
    rh, rw = (int(x) for x in rng.integers(1, 25, 2))
    region = rng.random((rh, rw)) < rng.choice([0.05, 0.5, 0.9])
    dr, dc = int(rng.integers(-rh - 2, h + 2)), int(rng.integers(-rw - 2, w + 2))
    for every in (True, False):
        want, got = np.empty((h, w), bool), np.empty((h, w), bool)
        _jit.square_filter(hidden, thin, every, want)
        _jit._square_extreme(hidden, thin, every, got)
        assert np.array_equal(got, want)
    seen = np.zeros((h, w), bool)
    a0, a1, b0, b1 = max(dr, 0), min(dr + rh, h), max(dc, 0), min(dc + rw, w)
    if a1 > a0 and b1 > b0:
        seen[a0:a1, b0:b1] = region[a0 - dr : a1 - dr, b0 - dc : b1 - dc]
    found = _jit.allowed_box(hidden, region, dr, dc, gap, thin)
    if not seen.any():
        assert not found[0]
        return
    assert found[0] and tuple(found[1:]) == mask_box(_jit.allowed(hidden, seen, gap, thin))


# --- issue 19, eighteenth round (stop 38): the completion -----------------------------------------------------------


@given(st.integers(0, 2**32 - 1), st.sampled_from([0.0, 0.5, 0.25]), st.sampled_from([1.0, 2.0, 4.0, 3.0]))
def test_the_ellipse_holds_the_twins_pixels(seed, centre_frac, radius):
    """:func:`symfruit.core._jit.ellipse_holds` against the twin's numpy expression on random windows (a corner
    anywhere, holes) and ellipses whose terms reach exactly 1 on the pixel grid (whole-number offsets over radii of
    powers of two: pixels on the ellipse, ties at its edge, and just beyond it): the same count, to the pixel."""
    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 40, 2))
    mask = rng.random((h, w)) < rng.uniform(0.0, 1.0)
    u0, v0 = int(rng.integers(0, 600)), int(rng.integers(0, 400))
    cu = u0 + float(rng.integers(0, w)) + centre_frac
    cv = v0 + float(rng.integers(0, h)) + centre_frac
    a00, a11 = 1.0 / radius**2, 1.0 / (2.0 * radius) ** 2
    a01 = float(rng.choice([0.0, 0.0, 1.0 / 64.0, float(rng.normal(0.0, 0.01))]))
    n, held = _jit.ellipse_holds(mask, u0, v0, cu, cv, a00, a01, a11)
    rows, cols = np.nonzero(mask)
    u, v = cols + u0 - np.float64(cu), rows + v0 - np.float64(cv)
    a2 = np.array([[a00, a01], [a01, a11]])
    twin = (a2[0, 0] * u * u + 2 * a2[0, 1] * u * v + a2[1, 1] * v * v) <= 1.0 + 1e-9
    assert n == len(rows) and held == int(twin.sum())


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(0.0, 0.6))
def test_outline_cones_are_the_twins(seed, cut):
    """:func:`symfruit.core.raster.outline_cone` with the kernel and with the twins, on pixel ellipses (some cut by
    a straight edge, the fit on the rest of the outline) in windows anywhere in the image: the same cone and axis
    to the bit, or None alike."""
    from symfruit.core.camera import Camera
    from symfruit.core.raster import Silhouette, outline_cone, outline_cracks

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(20, 90, 2))
    rr, cc = np.mgrid[0:h, 0:w]
    a, b, t = rng.uniform(5, h / 2), rng.uniform(5, w / 2), rng.uniform(0, np.pi)
    y, x = rr - h / 2 + 0.5, cc - w / 2 + 0.5
    mask = ((x * np.cos(t) + y * np.sin(t)) / b) ** 2 + ((-x * np.sin(t) + y * np.cos(t)) / a) ** 2 <= 1.0
    mask &= cc >= cut * w
    region = Silhouette(int(rng.integers(0, 500)), int(rng.integers(0, 350)), mask, 0.0)
    cam = Camera(fx=600.0, fy=610.0, cx=319.5, cy=240.25, width=640, height=480)
    cracks = outline_cracks(region)
    points = cracks[cracks[:, 0] > region.u0 + cut * w + 1.0]
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, outline_cone, region, cam, points)
    assert (fast is None) == (twin is None)
    if fast is not None and twin is not None:
        assert np.array_equal(fast[0], twin[0]) and np.array_equal(fast[1], twin[1])


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 5), st.floats(0.0, 0.9), st.floats(0.0, 1.0))
def test_close_ragged_is_the_twins(seed, radius, holes, ragged):
    """:func:`symfruit.core.raster.close_ragged` with the kernel and with the twins, on discs with dropped pixels
    (a ragged rim, holes, pixels at the window's edge) and on random masks: the same region, closed or not, to the
    pixel, with the same fill radius."""
    from symfruit.core.raster import Silhouette, close_ragged

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 70, 2))
    rr, cc = np.mgrid[0:h, 0:w]
    if rng.random() < 0.7:
        mask = (rr - rng.uniform(0, h)) ** 2 + (cc - rng.uniform(0, w)) ** 2 <= rng.uniform(1, 40) ** 2
        mask &= rng.random((h, w)) >= holes * rng.random((h, w))
    else:
        mask = rng.random((h, w)) < holes
    region = Silhouette(int(rng.integers(0, 500)), int(rng.integers(0, 400)), mask, float(rng.choice([0.0, 2.5])))
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, close_ragged, region, radius=radius, ragged=ragged)
    assert (fast is region) == (twin is region)
    assert (fast.u0, fast.v0, fast.fill_radius) == (twin.u0, twin.v0, twin.fill_radius)
    assert fast.mask.dtype == twin.mask.dtype == bool and np.array_equal(fast.mask, twin.mask)


@given(st.integers(0, 2**32 - 1), st.integers(1, 300))
def test_image_pixels_are_the_twins(seed, n):
    """:func:`symfruit.core.raster._pixels` with the kernel and with the twins: points projecting onto half pixels
    (exact ties of the rounding, on a camera whose arithmetic is exact there), onto the image's edges and beyond
    them, behind the camera, at depth 0 and NaN: the same columns, rows and depths, in the same order (or the same
    error when none projects into the image)."""
    from symfruit.core.camera import Camera
    from symfruit.core.raster import _pixels
    from symfruit.errors import InputError

    rng = np.random.default_rng(seed)
    cam = Camera(fx=512.0, fy=512.0, cx=319.5, cy=240.0, width=640, height=480)
    z = rng.choice([0.25, 0.5, 1.0, 2.0], n)
    u = rng.integers(-3, 645, n) + rng.choice([0.0, 0.5, -0.5, 0.25, 0.4999], n)
    v = rng.integers(-3, 485, n) + rng.choice([0.0, 0.5, -0.5, 0.75], n)
    pts = np.stack(((u - 319.5) * z / 512.0, (v - 240.0) * z / 512.0, z), axis=1)
    odd = rng.random(n)
    pts[odd < 0.05, 2] = 0.0
    pts[(odd >= 0.05) & (odd < 0.1), 2] *= -1.0
    pts[(odd >= 0.1) & (odd < 0.13), int(rng.integers(0, 3))] = np.nan
    with pytest.MonkeyPatch.context() as mp, np.errstate(invalid="ignore"):  # the twin's cast of NaN warns
        try:
            fast, twin = _both(mp, _pixels, pts, cam)
        except InputError:
            mp.setenv("SYMFRUIT_KERNELS", "numpy")
            with pytest.raises(InputError, match="no point projects"):
                _pixels(pts, cam)
            return
    for a, b in zip(fast, twin, strict=True):
        assert a.dtype == b.dtype and np.array_equal(a, b)
    assert len(fast[0]) and fast[0].min() >= 0 and fast[0].max() < 640 and fast[1].max() < 480


# --- issue 19, eighteenth round (stop 38): the segmenter's split -----------------------------------------------


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(4, 2000), st.floats(0.005, 0.3))
def test_the_segmenters_sphere_solve_is_lstsq_to_rounding(seed, n, radius):
    """Points on a noisy cap of a sphere (near or far, a few or many): the kernel's Householder least squares is
    numpy's ``lstsq`` (LAPACK's SVD) to a nanometre in the centre and radius."""
    rng = np.random.default_rng(seed)
    centre = np.array([rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), rng.uniform(0.4, 3.0)])
    d = rng.normal(size=(n, 3))
    d[:, 2] = -np.abs(d[:, 2]) - 0.3  # the side facing the camera
    p = centre + radius * d / np.linalg.norm(d, axis=1)[:, None] + rng.normal(0.0, 0.001 * radius, (n, 3))
    sol = np.full(4, np.nan)
    assert _jit.sphere_solve(p, sol)
    want, *_ = np.linalg.lstsq(np.concatenate((2.0 * p, np.ones((n, 1))), axis=1), (p * p).sum(axis=1), rcond=None)
    np.testing.assert_allclose(sol[:3], want[:3], rtol=0, atol=1e-9)
    r, r_want = np.sqrt(sol[3] + sol[:3] @ sol[:3]), np.sqrt(want[3] + want[:3] @ want[:3])
    assert abs(r - r_want) <= 1e-9


def test_a_flat_depth_leaves_the_sphere_to_lstsq(monkeypatch):
    """A flat disc (every point at one depth: the depth column is the constant column times 2z, a singular system):
    the kernel refuses it and ``_sphere`` gives the numpy code's answer, bit for bit; and ``sphere_solve`` refuses
    points on a line."""
    from symfruit.segment.colour import _Geometry, _sphere, _sphere_lstsq

    yy, xx = np.mgrid[:60, :60]
    disc = (yy - 30) ** 2 + (xx - 30) ** 2 <= 25**2
    depth = np.where(disc, 0.7, 0.0)
    geo = _Geometry(600.0, 30.0, 30.0)
    fit = np.empty(4)
    assert _jit.sphere_fit(disc, depth, 0, 0, 30.0, 30.0, 600.0, 1500, fit) == -1
    fast, twin = _both(monkeypatch, _sphere, disc, depth, geo, (0, 0))
    want = _sphere_lstsq(disc, depth, geo, (0, 0))
    assert (fast is None) == (twin is None) == (want is None)
    if want is not None:
        assert np.array_equal(fast[0], want[0]) and fast[1] == want[1]
    line = np.stack([np.linspace(0.0, 1.0, 30)] * 3, axis=1) + np.array([0.0, 0.0, 1.0])
    assert not _jit.sphere_solve(line, np.empty(4))


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([0.5, 0.6, 0.9]), st.sampled_from([0.6, 0.9]), st.booleans())
def test_the_segmenters_centre_search_is_the_twins(seed, waist, loose, coarse):
    """Two to six discs of random sizes, some joined by necks, some apart, in a window of random shape; random
    least radii and waists (below, at and above the loose share): the same centres, firm or not, with the kernel
    and with the twins (the peaks, the stable order, the straight paths, the labellings and their budget)."""
    from symfruit.segment.colour import _centres

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(20, 160, 2))
    yy, xx = np.mgrid[:h, :w]
    region = np.zeros((h, w), bool)
    for _ in range(int(rng.integers(2, 7))):
        region |= (yy - rng.uniform(0, h)) ** 2 + (xx - rng.uniform(0, w)) ** 2 <= rng.uniform(3, 30) ** 2
    if rng.random() < 0.5:  # a neck
        r = int(rng.integers(0, h))
        region[max(r - int(rng.integers(0, 4)), 0) : r + 1] = True
    least = float(rng.uniform(1.0, 12.0))
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _centres, region, least, waist, loose, coarse=coarse)
    assert fast == twin


def test_the_centre_search_keeps_the_walks_rules(monkeypatch):
    """Two discs joined by a neck 9 px wide (about 5 px deep: below a 0.5 share of the smaller disc's 25, above a 0.1
    share) and a disc apart: three centres at a loose share of 0.9, the neck's one firm at a waist of 0.5 but not at
    0.1 (the neck joins them above 2.5 px); the answers the twins give, and the known ones."""
    from symfruit.segment.colour import _centres

    yy, xx = np.mgrid[:120, :260]
    region = ((yy - 60) ** 2 + (xx - 40) ** 2 <= 30**2) | ((yy - 60) ** 2 + (xx - 115) ** 2 <= 25**2)
    region |= (abs(yy - 60) <= 4) & (xx > 40) & (xx < 115)
    region |= (yy - 60) ** 2 + (xx - 210) ** 2 <= 20**2
    for waist, firm in ((0.1, False), (0.5, True)):
        fast, twin = _both(monkeypatch, _centres, region, 5.0, waist, 0.9, coarse=False)
        assert fast == twin
        assert [c[:2] for c in fast] == [(60, 40), (60, 115), (60, 210)]
        assert [c[3] for c in fast] == [True, firm, True]


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([0.0, 0.7, 2.0, 3.3]), st.booleans())
def test_the_segmenters_depth_edges_are_the_twins(seed, sigma, read_only):
    """Two fruit-like caps, one in front of the other (a step), with pixels without depth and speckle, in a window of
    random shape (a line of pixels to a hundred): the same crease and step pixels with the kernel and with the twins
    (scipy's correlations and Laplacian, ``_steps`` over NaN), read-only depth windows too."""
    from symfruit.segment.colour import SegmentSettings, _depth_edges

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 100, 2))
    yy, xx = np.mgrid[:h, :w]
    depth = np.full((h, w), 0.9)
    for _ in range(2):
        cy, cx, r, z = rng.uniform(0, h), rng.uniform(0, w), rng.uniform(3, 40), rng.uniform(0.5, 1.0)
        cap = z - 0.002 * np.sqrt(np.maximum(r * r - (yy - cy) ** 2 - (xx - cx) ** 2, 0.0))
        depth = np.where((yy - cy) ** 2 + (xx - cx) ** 2 <= r * r, np.minimum(depth, cap), depth)
    depth += rng.normal(0.0, 0.001, (h, w))
    depth[rng.random((h, w)) < 0.15] = 0.0
    if read_only:
        depth.flags.writeable = False
    region = rng.random((h, w)) < 0.9
    seen = region & (depth > 0)
    if seen.sum() < 20:
        return
    zm = float(np.median(depth[seen]))
    s = SegmentSettings(crease_sigma=sigma, crease_curvature=float(rng.uniform(100.0, 3000.0)),
                        depth_jump=float(rng.uniform(0.005, 0.1)))  # fmt: skip
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _depth_edges, region, depth, seen, zm, s, 600.0)
    np.testing.assert_array_equal(fast, twin)
    assert not (fast & ~region).any()


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 9), st.integers(0, 4))
def test_the_column_correlation_is_scipys(seed, size, origin_shift):
    """Random images (a row to 60 rows) and weights, symmetric or not: ``ndimage.correlate1d`` along the columns
    (mode "reflect"), bit for bit."""
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 60, 2))
    image = rng.normal(size=(h, w))
    weights = rng.normal(size=size)
    symmetric = bool(origin_shift % 2)
    if symmetric and size % 2:
        weights = (weights + weights[::-1]) / 2.0
    symmetric = symmetric and size % 2 == 1
    out = np.empty((h, w))
    _jit._correlate_columns(image, weights, symmetric, out)
    np.testing.assert_array_equal(out, ndimage.correlate1d(image, weights, 0))


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([0.5, 0.9, 1.0]))
def test_the_segmenters_cells_are_the_twins(seed, loose):
    """Two to five overlapping discs and centres among their deepest pixels, random looseness: the same cells
    with the kernel and with the twins."""
    from symfruit.core.raster import distance_transform
    from symfruit.segment.colour import _cells

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(10, 120, 2))
    yy, xx = np.mgrid[:h, :w]
    region = np.zeros((h, w), bool)
    for _ in range(int(rng.integers(2, 6))):
        region |= (yy - rng.uniform(0, h)) ** 2 + (xx - rng.uniform(0, w)) ** 2 <= rng.uniform(3, 30) ** 2
    edt = distance_transform(region)
    rows, cols = np.nonzero(edt >= max(1.0, 0.5 * edt.max()))
    if len(rows) < 2:
        return
    pick = rng.choice(len(rows), size=min(len(rows), int(rng.integers(2, 5))), replace=False)
    centres = [(int(rows[i]), int(cols[i]), float(edt[rows[i], cols[i]])) for i in pick]
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _cells, region, centres, loose)
    assert len(fast) == len(twin) and all(np.array_equal(a, b) for a, b in zip(fast, twin, strict=True))
    assert len(fast) >= 1 and not (np.logical_or.reduce(fast) ^ region).any()


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_the_ripe_tests_median_redness_is_the_twins(seed, strided):
    """Random colours (dark ones, R = 0, R below G and B) under a random mask, an odd or even count, a strided view:
    the kernel's median redness is ``median(redness(...))`` of the twin, bit for bit."""
    from symfruit.core.points import median
    from symfruit.segment.colour import redness

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 40, 2))
    image = rng.integers(0, 256, (2 * h, 2 * w, 4), dtype=np.uint8)
    image[rng.random(image.shape[:2]) < 0.1, 0] = 0
    c = image[::2, 1::2, :3] if strided else np.ascontiguousarray(image[:h, :w, :3])
    red = rng.random((h, w)) < rng.uniform(0.0, 1.0)
    got = _jit.red_median(c, red)
    if not red.any():
        assert np.isnan(got)
        return
    want = median(redness(c[red]))
    assert want.dtype == np.float32 and got == float(want)


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 12), st.booleans())
def test_a_running_mean_is_scipys_uniform_filter_to_the_bit(seed, size, strided):
    """Random float32 lines (1 value to some thousands, shorter and longer than the filter, some values far apart),
    any size: ``_uniform_line`` gives ``ndimage.uniform_filter1d``'s float32 values bit for bit (its running sum, not a
    mean updated step by step, which differs in the last bit)."""
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    n = int(rng.choice([int(rng.integers(1, 2 * size + 2)), int(rng.integers(1, 3000))]))
    line = (rng.standard_normal(2 * n if strided else n) * rng.choice([1e-3, 1.0, 1e4])).astype(np.float32)
    line = line[::2] if strided else line
    out = np.empty(n, np.float32)
    _jit._uniform_line(line, size, out)
    assert out.tobytes() == ndimage.uniform_filter1d(line, size).tobytes()


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_a_large_regions_ripe_cores_are_the_twins(seed, strided):
    """Random colours (reddish to any) in windows of 1 to 120 pixels a side under a random region, the ripe threshold
    one of the smoothed redness's own values (the equality the ``>=`` must keep) or a setting's: the kernel's core
    is ``region & (uniform_filter(redness(color), 5) >= ripe)`` of the twin, and ``_ripe_cores`` of a region larger
    than the largest fruit gives the same cores with the kernels and with the twins."""
    from scipy import ndimage

    from symfruit.segment.colour import CORE_SMOOTH_PX, SegmentSettings, _ripe_cores, redness

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 121, 2))
    image = rng.integers(0, 256, (2 * h, 2 * w, 3), dtype=np.uint8)
    image[..., 0] = np.maximum(image[..., 0], rng.integers(0, 256))
    color = image[::2, ::2] if strided else np.ascontiguousarray(image[:h, :w])
    region = rng.random((h, w)) < rng.uniform(0.3, 1.0)
    smooth = ndimage.uniform_filter(redness(color), CORE_SMOOTH_PX)
    ripe = float(rng.choice([smooth.ravel()[rng.integers(smooth.size)], 0.35]))
    got = _jit.ripe_core(color, region, CORE_SMOOTH_PX, np.float32(ripe))
    np.testing.assert_array_equal(got, region & (smooth >= np.float32(ripe)))
    s = SegmentSettings(ripe_median=0.35, round_fruit=True)
    depth = np.where(region, 1.0, 0.0)
    with pytest.MonkeyPatch.context() as mp:  # a focal of 100 px at 1 m: the largest fruit's disc of some 100 px
        fast, twin = _both(mp, _ripe_cores, region, color, depth, s, 100.0, 1.0)
    assert len(fast) == len(twin) and all(np.array_equal(a, b) for a, b in zip(fast, twin, strict=True))


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([np.int32, np.int64]))
def test_the_ground_pieces_discs_are_the_twins(seed, dtype):
    """Random pieces (none to thousands of pixels, some pieces absent, some pixels without depth, depths of every
    scale): ``_piece_discs``' counts and disc areas with the kernel's one pass are the twin's ``np.bincount`` sums,
    bit for bit."""
    from symfruit.segment.colour import _piece_discs

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 80, 2))
    depth = rng.uniform(0.2, 3.0, (h, w)) * rng.choice([1e-3, 1.0, 1e3])
    depth[rng.random((h, w)) < rng.uniform(0.0, 0.6)] = 0.0
    at = np.flatnonzero(rng.random(h * w) < rng.uniform(0.0, 1.0))
    n = int(rng.integers(1, 40))
    labels = rng.integers(1, n + 1, len(at)).astype(dtype)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _piece_discs, labels, depth, at, n, float(rng.uniform(100.0, 2000.0)))
    for a, b in zip(fast, twin, strict=True):
        assert a.dtype == b.dtype == np.float64 and a.tobytes() == b.tobytes()


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([np.int32, np.int64]))
def test_the_segmenters_grouping_is_the_twins(seed, dtype):
    """Random labels (none to many, some labels absent) and a random choice of those kept: the same labels, places
    and run starts, of the same types, with the kernel's counting sort and with the twin's stable argsort."""
    from symfruit.segment.colour import _grouped

    rng = np.random.default_rng(seed)
    m = int(rng.integers(1, 50))
    labels = rng.integers(0, m, int(rng.integers(0, 3000))).astype(dtype)
    keep = rng.random(m) < rng.uniform(0.0, 1.0)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _grouped, labels, keep)
    for a, b in zip(fast, twin, strict=True):
        assert a.dtype == b.dtype
        np.testing.assert_array_equal(a, b)


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_the_segmenters_pixel_redness_and_least_areas_are_the_twins(seed, strided):
    """Random colours at random flat indices of a whole or a strided image: ``redness_at`` is ``redness`` of the
    gathered pixels bit for bit; random labels and depths (some without, some labels with none): ``_least_areas``
    with the kernel and with the twin, the same values."""
    from symfruit.segment.colour import _least_areas, redness

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 40, 2))
    image = rng.integers(0, 256, (2 * h, 2 * w, 3), dtype=np.uint8)
    image[rng.random(image.shape[:2]) < 0.1, 0] = 0
    c = image[::2, 1::2] if strided else np.ascontiguousarray(image[:h, :w])
    at = rng.integers(0, h * w, int(rng.integers(0, 200)))
    want = redness(np.ascontiguousarray(c).reshape(-1, 3).take(at, axis=0))
    got = _jit.redness_at(c, at)
    assert got.dtype == want.dtype == np.float32
    np.testing.assert_array_equal(got, want)
    n = int(rng.integers(0, 30))
    labels = rng.integers(0, n + 1, int(rng.integers(0, 500))).astype(np.int32)
    depth = np.where(rng.random(len(labels)) < 0.3, 0.0, rng.uniform(0.3, 3.0, len(labels)))
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _least_areas, labels, depth, n, 0.06 * 900.0, 1.2)
    assert fast.dtype == twin.dtype and fast.shape == twin.shape == (n + 1,)
    np.testing.assert_array_equal(fast, twin)


# --- stop 39, observation


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_the_nearest_edge_labels_are_the_trees(seed, grid):
    """Random edge points and queries, on whole pixels (many equally near points) or anywhere, labels mixed: where the
    kernel is sure, the labels of ``cKDTree``'s picks; it is unsure exactly where equally near points carry both
    labels; ``_labels_at`` gives the tree's labels where the nearest points share their label, and among equally near
    points of both labels the first one's (stop 55: not the tree's pick), with the kernels and with the twins."""
    from scipy.spatial import cKDTree

    from symfruit.core.agreement import _labels_at

    rng = np.random.default_rng(seed)
    k, m = int(rng.integers(1, 60)), int(rng.integers(0, 200))
    if grid:
        edge = rng.integers(0, 12, (k, 2)).astype(np.float64)
        queries = rng.integers(-3, 15, (m, 2)).astype(np.float64)
    else:
        edge = rng.uniform(0, 40, (k, 2))
        queries = rng.uniform(-5, 45, (m, 2))
    labels = rng.random(k) < rng.uniform(0.0, 1.0)
    want = labels[cKDTree(edge).query(queries)[1]] if m else np.zeros(0, bool)
    found, unsure = _jit.nearest_labels(edge, labels, queries)
    d2 = ((queries[:, None, :] - edge[None, :, :]) ** 2).sum(axis=2)
    ties = [labels[d2[j] == d2[j].min()] for j in range(m)]
    np.testing.assert_array_equal(unsure, [t.any() and not t.all() for t in ties])
    np.testing.assert_array_equal(found[~unsure], want[~unsure])
    first = np.array([t[0] for t in ties], bool)  # the first of the equally near points in the edge points' order
    np.testing.assert_array_equal(first[~unsure], want[~unsure])
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _labels_at, edge, labels, queries)
    np.testing.assert_array_equal(fast, first)
    np.testing.assert_array_equal(twin, first)


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 4))
def test_the_column_bounds_are_numpys(seed, k):
    """Random columns with NaN, infinities, zeros of either sign and ties: ``bounds`` with the kernel is numpy's
    column minima and maxima to the bit (the signs of zeros included), and the kernel says when it is not sure."""
    from symfruit.core.points import bounds

    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 300))
    p = rng.normal(size=(n, k)) * 10.0 ** rng.integers(-3, 3)
    for special in (np.nan, np.inf, -np.inf, 0.0, -0.0):
        if rng.random() < 0.25:
            p[rng.integers(0, n, int(rng.integers(1, 3))), rng.integers(0, k)] = special
    if rng.random() < 0.2:
        p = np.abs(p)
    lo, hi, sure = _jit.column_bounds(p)
    want_lo = np.array([p[:, j].min() for j in range(k)])
    want_hi = np.array([p[:, j].max() for j in range(k)])
    if sure:
        assert lo.tobytes() == want_lo.tobytes() and hi.tobytes() == want_hi.tobytes()
    else:
        assert ((want_lo == 0) | (want_hi == 0)).any()
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, bounds, p)
    for a, b in zip(fast, twin, strict=True):
        assert a.tobytes() == b.tobytes()


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_mirrored_points_are_the_columns_differences(seed):
    """``mirrored`` writes the points, then ``2 c - p`` column by column: the numpy expression's values to the bit."""
    rng = np.random.default_rng(seed)
    p = rng.normal(size=(int(rng.integers(0, 500)), 3))
    centre2 = rng.normal(size=3)
    out = np.empty((2 * len(p), 3))
    _jit.mirrored(p, centre2, out)
    want = np.concatenate((p, centre2[None, :] - p))
    assert out.tobytes() == want.tobytes()


# --- stop 39, candidates


def _ulps(a, b):
    """The largest distance in units in the last place between two float arrays (0: the same bits, NaN alike)."""
    a, b = np.atleast_1d(np.asarray(a, dtype=np.float64)), np.atleast_1d(np.asarray(b, dtype=np.float64))
    assert a.shape == b.shape and np.array_equal(np.isnan(a), np.isnan(b))
    ok = ~np.isnan(a)
    return int(np.abs(a[ok].view(np.int64) - b[ok].view(np.int64)).max(initial=0))


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_across_sight_is_the_twins(seed, disc):
    """:func:`symfruit.core.raster.across_sight` with the kernels (``across_frame``, ``across_extent``) and with the
    twin, on discs, ellipses and random masks anywhere in the image of a camera with unequal focal lengths: the same
    axis, basis, bounds and widths. The kernels repeat OpenBLAS's multiply-adds of the twin's small products as its
    Haswell kernels order them (the same bits there); OpenBLAS picks its kernels by the CPU, and on one with AVX-512
    (its SkylakeX kernels) the products round otherwise: on 6,000 cases there the bounds differed by up to 130 and
    the widths by up to 800 machine epsilons of the silhouette's extent (a few 1e-14; the axis and basis within 4
    ulps). Hence the bounds and widths are compared to 1e-11 of the extent (about 45,000 epsilons, under a
    billionth of a pixel's width here), the unit vectors to 1e-13."""
    from symfruit.core.camera import Camera
    from symfruit.core.raster import Silhouette, across_sight

    rng = np.random.default_rng(seed)
    cam = Camera(fx=float(rng.uniform(300, 900)), fy=float(rng.uniform(300, 900)), cx=float(rng.uniform(200, 440)),
                 cy=float(rng.uniform(150, 330)), width=640, height=480)  # fmt: skip
    h, w = (int(x) for x in rng.integers(1, 90, 2))
    if disc:
        rr, cc = np.mgrid[0:h, 0:w]
        a, b, t = rng.uniform(1, 50), rng.uniform(1, 50), rng.uniform(0, np.pi)
        x, y = cc - rng.uniform(0, w), rr - rng.uniform(0, h)
        mask = ((x * np.cos(t) + y * np.sin(t)) / a) ** 2 + ((y * np.cos(t) - x * np.sin(t)) / b) ** 2 <= 1.0
    else:
        mask = rng.random((h, w)) < rng.uniform(0.05, 1.0)
    if not mask.any():
        mask[int(rng.integers(0, h)), int(rng.integers(0, w))] = True
    region = Silhouette(int(rng.integers(-50, 600)), int(rng.integers(-50, 440)), mask, 0.0)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, across_sight, region, cam)
    extent = max(np.abs(twin.lo).max(), np.abs(twin.hi).max())
    for name, tol in (("axis", 1e-13), ("basis", 1e-13), ("lo", 1e-11 * extent), ("hi", 1e-11 * extent),
                      ("minor", 1e-11 * extent), ("major", 1e-11 * extent)):  # fmt: skip
        assert np.abs(np.asarray(getattr(fast, name)) - getattr(twin, name)).max() <= tol, name
    assert isinstance(fast.minor, float) and isinstance(fast.major, float)


def test_across_sight_kernels_tangent_is_numpys_products():
    """``_tangent``, the kernels' tangent coordinates of one pixel, against the twin's ``(rays @ basis.T) / (rays @
    axis)`` on 400 random rays (OpenBLAS's ``(m, 3) @ (3, 2)`` and ``(m, 3) @ (3,)``), within 4 ulps (here: the same
    bits)."""
    rng = np.random.default_rng(5)
    uv = rng.normal(size=(400, 2)) * 100.0
    axis, basis = rng.normal(size=3), rng.normal(size=(2, 3))
    tangent = np.array([_jit._tangent(u, v, axis, basis, 3.0, -2.0, 7.0, 5.0) for u, v in uv.tolist()])
    rays = np.stack(((uv[:, 0] - 3.0) / 7.0, (uv[:, 1] + 2.0) / 5.0, np.ones(len(uv))), axis=1)
    twin = (rays @ basis.T) / (rays @ axis)[:, None]
    assert _ulps(tangent, twin) <= 4


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans(), st.sampled_from([None, 1.0, 0.3]))
def test_constrain_box_is_the_twins(seed, with_cone, pull):
    """:func:`symfruit.core.candidates.constrain_box` with the kernel and with its twin in Python floats: boxes
    beyond, within and across the seen box, equal faces, signed zeros and NaN faces, contour shares below, at and
    above the floor, with and without the silhouette's cone: the same boxes, bit for bit."""
    from symfruit.core.camera import Camera
    from symfruit.core.candidates import constrain_box

    rng = np.random.default_rng(seed)

    def vec():
        v = rng.choice([rng.normal(0, 0.05), 0.0, -0.0, 0.01, np.nan], p=[0.8, 0.05, 0.05, 0.05, 0.05], size=3)
        return v + np.array([0.0, 0.0, 0.4]) * (rng.random() < 0.8)

    seen_lo = rng.normal(0, 0.03, 3) + [0, 0, 0.35]
    seen_hi = seen_lo + rng.choice([0.0, 0.02, 0.05], 3) * rng.random(3)
    lo, hi = vec(), vec()
    if rng.random() < 0.3:
        lo, hi = seen_lo.copy(), seen_hi.copy()
    cone = None
    if with_cone:
        cam = Camera(fx=600.0, fy=610.0, cx=319.5, cy=241.0, width=640, height=480)
        u, v = (float(x) for x in rng.uniform(100, 500, 2))
        cone = ((u - 20.0, v - 15.0, u + float(rng.uniform(0, 40)), v + 30.0), cam)
    front = float(rng.choice([seen_lo[2], seen_lo[2] - 0.003, 0.4]))
    contour = float(rng.choice([0.0, 0.3, 0.5, 0.9, 1.0]))
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, constrain_box, lo, hi, seen_lo, seen_hi, front, cone=cone, contour=contour, pull=pull)
    for a, b in zip(fast, twin, strict=True):
        assert a.shape == b.shape == (3,) and a.dtype == b.dtype == np.float64
        assert np.array_equal(a.view(np.int64), b.view(np.int64))


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 400), st.booleans())
def test_cone_rays_are_the_twins(seed, n, strided):
    """``cone_rays`` (the cone fit's rays, their ``r^T C r`` and depths) against the twin's ``points / z``, ``((rays
    @ cone) * rays).sum(axis=1)`` and ``points[:, 2]`` on random points, every other row of a larger array too, and
    random symmetric cones: within 4 ulps (the same bits on this project's machines, OpenBLAS's Haswell kernels)."""
    rng = np.random.default_rng(seed)
    pts = rng.normal(0, 0.05, (2 * n if strided else n, 3)) + [0.0, 0.0, 0.4]
    pts = pts[::2] if strided else pts
    m = rng.normal(size=(3, 3))
    cone = m + m.T
    rays, ray_cone, z = _jit.cone_rays(pts, cone)
    twin_rays = pts / pts[:, 2:3]
    assert _ulps(rays, twin_rays) <= 4 and _ulps(ray_cone, ((twin_rays @ cone) * twin_rays).sum(axis=1)) <= 4
    assert np.array_equal(z, pts[:, 2]) and z.flags.c_contiguous and rays.flags.c_contiguous


# --- stop 39, segmenter


def _odd_depths(rng, shape, dtype):
    """Depths with what a depth image may hold beside metres: 0, negatives, -0.0, NaN and both infinities."""
    z = rng.uniform(0.2, 3.0, shape).astype(dtype)
    special = np.array([0.0, -0.0, -1.0, np.nan, np.inf, -np.inf], dtype)
    pick = rng.random(shape) < 0.2
    z[pick] = rng.choice(special, int(pick.sum()))
    return z


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([np.float32, np.float64]))
def test_the_segmenters_depth_reads_are_the_twins(seed, dtype):
    """A depth image with invalid values of every kind, read through ``_Depth`` as windows (contiguous and strided)
    and at flat indices: the same float64 values to the bit with the kernels and with the twin's ``np.where``."""
    from symfruit.segment.colour import _Depth

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 60, 2))
    z = np.ascontiguousarray(_odd_depths(rng, (h, w), dtype))
    r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
    step = int(rng.integers(1, 4))
    at = rng.integers(0, h * w, int(rng.integers(0, 100)))
    for window in ((slice(r0, h), slice(c0, w)), (slice(None, None, step), slice(None, None, step))):
        with pytest.MonkeyPatch.context() as mp:
            fast, twin = _both(mp, lambda win=window: _Depth(z)[win])
        assert fast.dtype == twin.dtype == np.float64
        np.testing.assert_array_equal(fast.view(np.uint64), twin.view(np.uint64))
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, lambda: _Depth(z).take(at))
    assert fast.dtype == twin.dtype == np.float64
    np.testing.assert_array_equal(fast.view(np.uint64), twin.view(np.uint64))


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_the_segmenters_ground_colour_is_the_twins(seed, strided):
    """Random colours (and yellow-green ones near the hue bounds), whole or strided: the same ground-colour pixels."""
    from symfruit.segment.colour import _ground

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 50, 2))
    image = rng.integers(0, 256, (2 * h, 2 * w, 4), dtype=np.uint8)
    yellow = rng.random((2 * h, 2 * w)) < 0.5
    image[yellow, 2] = image[yellow, 2] // 4
    c = image[::2, 1::2, :3] if strided else np.ascontiguousarray(image[:h, :w, :3])
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _ground, c)
    assert fast.dtype == twin.dtype == bool
    np.testing.assert_array_equal(fast, twin)


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([np.float32, np.float64]))
def test_the_segmenters_medians_are_the_twins(seed, dtype):
    """Values with ties, of odd and even counts (one included; none gives NaN), some with a NaN: ``median_values``
    (float64) and ``median_values32`` (float32) give ``core.points.median``'s value to the bit, NaN where it is NaN."""
    from symfruit.core.points import median

    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 60))
    kernel = _jit.median_values if dtype == np.float64 else _jit.median_values32
    assert np.isnan(kernel(np.zeros(0, dtype)))  # none: NaN (numpy's median warns and gives NaN)
    x = rng.choice(rng.uniform(0.0, 2.0, max(n // 3, 1)), n).astype(dtype)
    if rng.random() < 0.1:
        x[int(rng.integers(0, n))] = np.nan
    want = median(x)
    got = kernel(x.copy())
    if np.isnan(want):
        assert np.isnan(got)
    else:
        assert type(want)(got) == want and np.dtype(type(want)) == np.dtype(dtype)


def _depth_patch(rng, h, w):
    """A window's depths with holes (0) and a step, and a random mask over it."""
    z = rng.uniform(1.0, 1.1, (h, w))
    z[rng.random((h, w)) < 0.15] = 0.0
    z[: int(rng.integers(0, h + 1))] += rng.choice([0.0, 0.05])
    return z, rng.random((h, w)) < rng.uniform(0.0, 1.0)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_segmenters_masked_depth_tests_are_the_twins(seed):
    """Random masks over depths with holes and steps: ``_fruit_sized``, ``_largest_area`` and ``_depth_consistent``
    with the kernels and with the twins give the same answers, areas and pixels; ``mask_centre`` the mean row and
    column of ``np.nonzero`` to the bit."""
    from symfruit.segment.colour import SegmentSettings, _depth_consistent, _fruit_sized, _largest_area

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 40, 2))
    z, mask = _depth_patch(rng, h, w)
    part = mask & (rng.random((h, w)) < 0.5)
    s = SegmentSettings(round_fruit=True, min_diameter=float(rng.uniform(0.005, 0.03)))
    focal = float(rng.uniform(300.0, 2000.0))
    with pytest.MonkeyPatch.context() as mp:
        assert len({_both(mp, _fruit_sized, mask, z, s, focal, 4.0, 1.5)[k] for k in (0, 1)}) == 1
        fast, twin = _both(mp, _largest_area, mask, z, s, focal, 1.5)
        assert fast == twin
        fast, twin = _both(mp, _depth_consistent, mask, part, z, 0.015)
        np.testing.assert_array_equal(fast, twin)
    n, mr, mc = _jit.mask_centre(mask)
    rows, cols = np.nonzero(mask)
    assert n == len(rows)
    if n:
        assert mr == rows.mean() and mc == cols.mean()


def _blush_scene(rng, front: bool):
    """A red crescent (piece 1 of ``owner``) on a window's left with yellow-green skin beside it, in front of the
    crescent's depth (``front``) or at it, the rest leaf green at the crescent's depth; noise, holes and a piece of
    another fruit's pixels in the ring."""
    h, w = (int(x) for x in rng.integers(30, 60, 2))
    yy, xx = np.mgrid[0:h, 0:w]
    cy, cx, r = h / 2, w / 2, min(h, w) / 3
    disc = (yy - cy) ** 2 + (xx - cx) ** 2 <= r * r
    hull = disc & (xx < cx - 0.5 * r)
    color = np.zeros((h, w, 3), np.uint8)
    color[...] = (60, 140, 50)  # leaf green
    color[disc] = (200, 190, 40)  # ground colour
    color[hull] = (200, 30, 30)
    z = 2.0 + rng.normal(0.0, 0.002, (h, w))
    z[disc & ~hull] -= 0.05 if front else 0.0
    z[rng.random((h, w)) < 0.1] = 0.0
    owner = np.zeros((h, w), np.int16)
    owner[hull] = 1
    owner[disc & (yy < cy - 0.8 * r)] = int(rng.choice([0, 2]))
    return hull, z, color, owner


def _blush_window(rng, front: bool, holes: float = 0.0):
    """``_blush_scene`` (with a share ``holes`` of its depth missing besides) placed at random in an image 20 pixels
    wider and taller, and its crescent's box: the crescent's mask in its window, the window, and the image's depth,
    colour and owner."""
    hull, z, color, owner = _blush_scene(rng, front)
    h, w = hull.shape
    if holes:
        z[rng.random((h, w)) < holes] = 0.0
    r0, c0 = int(rng.integers(0, 10)), int(rng.integers(0, 10))
    big_z = np.zeros((h + 20, w + 20))
    big_z[r0 : r0 + h, c0 : c0 + w] = z
    big_c = np.zeros((h + 20, w + 20, 3), np.uint8)
    big_c[r0 : r0 + h, c0 : c0 + w] = color
    big_o = np.zeros((h + 20, w + 20), np.int16)
    big_o[r0 : r0 + h, c0 : c0 + w] = owner
    rows, cols = np.nonzero(hull)
    box = (slice(rows.min(), rows.max() + 1), slice(cols.min(), cols.max() + 1))
    sl = (slice(box[0].start + r0, box[0].stop + r0), slice(box[1].start + c0, box[1].stop + c0))
    return hull[box], sl, big_z, big_c, big_o


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_the_segmenters_blush_rim_is_the_twins(seed, front):
    """A blush crescent beside ground colour in front of it (the rim's test holds) or at its depth (it does not), in
    the middle of an image or against its border: ``_blush_rim`` with the kernel and with the twin gives the same
    window, mask and depths."""
    from symfruit.segment.colour import SegmentSettings, _blush_rim, _Depth

    part, sl, big_z, big_c, big_o = _blush_window(np.random.default_rng(seed), front)
    z_part = big_z[sl][part & (big_z[sl] > 0)]
    s = SegmentSettings(round_fruit=True, ground_colour=True)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _blush_rim, sl, part, z_part, _Depth(big_z), big_c, s, big_o, 1)
    assert fast[0] == twin[0]
    np.testing.assert_array_equal(fast[1], twin[1])
    np.testing.assert_array_equal(fast[2].view(np.uint64), twin[2].view(np.uint64))
    if front:
        assert fast[0] != sl  # the test held: the ring in front was taken
    else:
        assert fast[0] == sl


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_segmenters_region_medians_are_the_twins(seed):
    """Regions of random sizes (one pixel to many, some without depth) with depths and rednesses: ``_one_fruit`` with
    the kernel's medians and with the twin's, the same regions one fruit and ripe."""
    from symfruit.segment.colour import SegmentSettings, _one_fruit

    rng = np.random.default_rng(seed)
    sizes = rng.integers(1, 400, int(rng.integers(0, 12)))
    first = np.concatenate(([0], np.cumsum(sizes))).astype(np.int64)
    depth = np.where(rng.random(int(first[-1])) < 0.3, 0.0, rng.uniform(1.0, 2.0, int(first[-1])))
    for i in np.flatnonzero(rng.random(len(sizes)) < 0.2):
        depth[first[i] : first[i + 1]] = 0.0
    red = rng.choice(np.array([0.1, 0.2, 0.25, 0.5], np.float32), int(first[-1]))
    s = SegmentSettings(round_fruit=True, ripe_median=float(rng.choice([0.2, 0.25, 0.3])))
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _one_fruit, first, sizes, depth, red, s, 900.0, 1.5)
    for a, b in zip(fast, twin, strict=True):
        np.testing.assert_array_equal(a, b)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_merges_near_pieces_by_table_are_the_rows(seed):
    """Random pieces (boxes near and apart, small and large): the pairs the merge tests, from one table and row by
    row, the same and in the same order."""
    from symfruit.segment import colour

    rng = np.random.default_rng(seed)
    pieces = []
    for _ in range(int(rng.integers(1, 40))):
        r0, c0 = (int(x) for x in rng.integers(0, 300, 2))
        h, w = (int(x) for x in rng.integers(1, 40, 2))
        pieces.append(colour._Piece((slice(r0, r0 + h), slice(c0, c0 + w)), rng.random((h, w)) < 0.7, 1))
    table = colour._near_pieces(pieces)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(colour, "NEAR_TABLE", 0)
        rows = colour._near_pieces(pieces)
    assert [table(i) for i in range(len(pieces))] == [rows(i) for i in range(len(pieces))]


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_ground_pieces_convex_outline_is_the_twins(seed):
    """A disc with a bite out of it (a leaf across it: nearer, farther or at the disc's depth, its rim without depth),
    with holes in the depth and against the window's edges: ``_convex_outline`` with the kernel's count of hidden
    pixels and with the twin's minimum filter, the same answer; the count itself the twin's."""
    from scipy import ndimage

    from symfruit.segment.colour import GAP_PX, _convex_outline, _hull_mask, _hull_vertices

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(8, 50, 2))
    yy, xx = np.mgrid[0:h, 0:w]
    cy, cx, r = rng.uniform(0, h), rng.uniform(0, w), rng.uniform(3, max(h, w))
    disc = (yy - cy) ** 2 + (xx - cx) ** 2 <= r * r
    bite = np.abs(xx - cx - rng.uniform(-r, r)) < rng.uniform(1, r)
    part = disc & ~bite
    depth = rng.uniform(1.0, 1.02, (h, w))
    depth[bite] += rng.choice([-0.1, 0.0, 0.1])
    depth[rng.random((h, w)) < rng.uniform(0.0, 0.6)] = 0.0
    vertices = _hull_vertices(part)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _convex_outline, part, vertices, depth, 0.015)
    assert fast == twin
    if vertices is not None:
        rest = _hull_mask(vertices, part) & ~part
        front = float(rng.uniform(0.9, 1.1))
        near = ndimage.minimum_filter(np.where(depth > 0, depth, np.inf), size=GAP_PX, mode="nearest")
        want = int((rest & (np.where(depth > 0, depth, near) < front)).sum())
        assert _jit.hidden_count(rest, depth, front, GAP_PX) == want


# --- stop 39, registration


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([1, 3, 5]), st.booleans())
def test_least_median_counts_below_the_least_by_columns_in_any_order(seed, size, shuffled):
    """The least median's column counts (issue 19, nineteenth round): pixels in raster order, or shuffled and repeated
    (the counts made again wherever the row changes), on coarse values (equal medians: the first least is the one)
    with +inf, on windows over the image's edges: the twin's first least median."""
    from symfruit.core.surface import median_at

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 70, 2))
    image = rng.choice([0.3, 0.31, 0.32, np.inf], size=(h, w), p=[0.2, 0.3, 0.3, 0.2])
    if rng.random() < 0.5:
        image = image + rng.normal(0, 0.01, (h, w)).round(2)
    rows, cols = np.nonzero(rng.random((h, w)) < rng.uniform(0.05, 1.0))
    if not len(rows):
        rows, cols = np.array([h // 2]), np.array([w // 2])
    if shuffled:
        pick = rng.integers(0, len(rows), int(rng.integers(1, 2 * len(rows) + 1)))
        rows, cols = rows[pick], cols[pick]
    expected = int(np.argmin(median_at(image, rows, cols, size=size)))
    assert _jit.least_median(image, rows, cols, size) == expected


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 9))
def test_surface_apex_erodes_by_one_taxicab_map(seed, iterations):
    """The apex's core by one taxicab distance map of the box (issue 19, nineteenth round) on random masks with holes,
    eroded 1-9 times, boxes anywhere in the window: the pixel of the twin's erosion, pixels and least median."""
    from symfruit.core.raster import eroded
    from symfruit.core.surface import median_at

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(3, 60, 2))
    yy, xx = np.mgrid[:h, :w]
    cy, cx, r = rng.uniform(0, h), rng.uniform(0, w), rng.uniform(2.0, 40.0)
    mask = ((yy - cy) ** 2 + (xx - cx) ** 2 <= r * r) & (rng.random((h, w)) >= rng.choice([0.0, 0.02]))
    if not mask.any():
        mask[h // 2, w // 2] = True
    near = mask & (rng.random((h, w)) >= rng.choice([0.0, 0.1]))
    if not near.any():
        near[np.nonzero(mask)[0][0], np.nonzero(mask)[1][0]] = True
    depth = np.round(rng.uniform(0.5, 0.52, (h, w)), 3)
    rs, cs = np.nonzero(mask)
    r0, r1, c0, c1 = rs.min(), rs.max() + 1, cs.min(), cs.max() + 1
    own = mask[r0:r1, c0:c1]
    core = eroded(own, iterations) & near[r0:r1, c0:c1]
    if core.any():
        rows, cols = np.nonzero(core)
        rows, cols = rows + r0, cols + c0
    else:
        rows, cols = np.nonzero(near & mask if (near & mask).any() else near)
    first = int(np.argmin(median_at(np.where(near, depth, np.inf), rows, cols, size=5)))
    got = _jit.surface_apex(own, iterations, near, depth, mask, int(r0), int(c0), 5)
    assert (int(got[0]), int(got[1])) == (int(rows[first]), int(cols[first]))


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_outline_and_ray_pixels_are_nonzeros(seed, full):
    """Random masks (empty, full, touching the array's edges, one row or column): ``outline_pixels`` is
    ``np.nonzero(cap & ~interior(cap))`` and ``ray_pixels`` ``np.nonzero(keep)`` with the offsets from a pixel
    anywhere, the same numbers and dtypes."""
    from symfruit.core.raster import interior

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 40, 2))
    cap = np.ones((h, w), bool) if full else rng.random((h, w)) < rng.uniform(0.0, 1.0)
    rows, cols = _jit.outline_pixels(cap)
    want = np.nonzero(cap & ~interior(cap))
    for got, expected in zip((rows, cols), want, strict=True):
        assert got.dtype == expected.dtype
        np.testing.assert_array_equal(got, expected)
    r0, c0 = int(rng.integers(-5, h + 5)), int(rng.integers(-5, w + 5))
    found = _jit.ray_pixels(cap, r0, c0)
    rr, cc = np.nonzero(cap)
    for got, expected in zip(found, (rr, cc, rr - r0, cc - c0), strict=True):
        assert got.dtype == expected.dtype
        np.testing.assert_array_equal(got, expected)


# --- stop 40, speedcand40


@given(st.integers(0, 2**32 - 1), st.integers(1, 90), st.integers(20, 400), st.sampled_from(["none", "loose", "tight"]))
def test_slice_costs_below_are_slice_costs_or_surely_above_the_least(seed, k, n, known):
    """Every direction it finishes has :func:`slice_costs`'s cost to the bit; every one it leaves (``inf``) has a cost
    above the least known before it (``best``, or one found here), so the least (first least) is the same pick; the
    least and its ``keep``-th smallest distance come back. On a pear's near half (directions near the axis cost
    little, others much more) and on noise (costs close together)."""
    rng = np.random.default_rng(seed)
    if seed % 2:
        points = FRUITS["pear"](rng).sample(2 * n, rng) @ rotation(*rng.uniform(0.0, 360.0, 3)).T
        q = points[points[:, 2] <= np.median(points[:, 2])]
    else:
        q = rng.normal(size=(n, 3)) * rng.uniform(0.001, 0.1)
        q[: n // 3] = np.round(q[: n // 3], 3)  # ties in the slices and the selection
    q = np.ascontiguousarray(q - q.mean(axis=0))
    dirs = rng.normal(size=(k, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    every = _jit.slice_costs(q, dirs, 12)
    best, thr = np.inf, np.nan
    if known != "none":  # the least of other directions, with its keep-th smallest distance
        other = rng.normal(size=(3, 3))
        other /= np.linalg.norm(other, axis=1, keepdims=True)
        if known == "tight":
            other[0] = dirs[int(np.argmin(every))]  # the least itself: every other direction may be left
        costs = _jit.slice_costs(q, other, 12)
        j = int(np.argmin(costs))
        _, best, thr = _jit.slice_costs_below(q, other[j : j + 1], 12, np.inf, np.nan)  # its keep-th distance too
        assert best == costs[j]
    got, least, at = _jit.slice_costs_below(q, dirs, 12, best, thr)
    done = np.isfinite(got)
    np.testing.assert_array_equal(got[done], every[done])
    assert (every[~done] > min(best, every[done].min(initial=np.inf))).all()
    assert least == min(best, every.min())
    assert _jit._least(np.r_[best, got]) == _jit._least(np.r_[best, every])
    if least < best:
        assert at == at  # a threshold comes with the least found here


@given(st.integers(0, 2**32 - 1), st.integers(8, 300), st.integers(1, 60))
def test_cone_grid_best_is_the_first_least_huber_cost(seed, n, k):
    """The grid's pick, each row given up once its cost reaches the least so far, is the first least
    :func:`huber_cost` of every row's :func:`cone_residuals` (rows with invalid ellipsoids, saturated logistics,
    ties between equal rows among them)."""
    visible, cone, axis, _, _ = _cone_view("apple", 1)
    rng = np.random.default_rng(seed)
    pts = visible[rng.choice(len(visible), min(n, len(visible)), replace=False)]
    rays, z = np.ascontiguousarray(pts / pts[:, 2:3]), np.ascontiguousarray(pts[:, 2])
    ray_cone = ((rays @ cone) * rays).sum(axis=1)
    grid = np.c_[rng.normal(0.0, 0.01, (k, 2)), np.log(rng.uniform(0.2, 0.8, k)), rng.uniform(-10, 10, k)]
    grid[rng.random(k) < 0.1, 3] = 60.0  # saturated: no front on any ray
    grid[rng.random(k) < 0.1, :2] = 1.0  # a centre outside the cone: no ellipsoid
    if k > 2:
        grid[-1] = grid[int(rng.integers(k - 1))]  # a tie: the first is picked
    huber = float(rng.choice([0.003, 0.02, 1.0]))
    res = np.empty((k, len(rays)))
    _jit.cone_residuals(grid, cone, axis, rays, ray_cone, z, res)
    costs = np.array([_jit.huber_cost(row, huber) for row in res])
    want = int(np.argmin(costs)) if np.isfinite(costs).any() else -1
    assert _jit.cone_grid_best(grid, cone, axis, rays, ray_cone, z, huber) == want


@given(st.integers(0, 2**32 - 1), st.integers(1, 1200), st.sampled_from(["normal", "flat", "one point", "offset"]))
def test_scaled_cloud_is_the_twins_bit_for_bit(monkeypatch, seed, n, kind):
    """The two algebraic fits' beginnings in one call: the mean, the scale (numpy's pairwise sum, 1 for a single
    point), the scaled points and both designs, numpy's values to the bit (beyond 128 points the pairwise sum's
    splits matter)."""
    from symfruit.core.fits import scaled_cloud

    rng = np.random.default_rng(seed)
    points = rng.normal(size=(n, 3)) * rng.uniform(0.001, 0.1, 3)
    if kind == "flat":
        points[:, 2] = 0.0
    elif kind == "one point":
        points[:] = points[0]
    elif kind == "offset":
        points += [0.1, -0.2, 0.6]
    fast, twin = _both(monkeypatch, scaled_cloud, points)
    assert fast.scale == twin.scale
    for name in ("mean", "q", "sphere_design", "sphere_rhs", "ellipsoid_design"):
        got, want = getattr(fast, name), getattr(twin, name)
        assert got.shape == want.shape and got.flags.c_contiguous
        np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("kind,seed", [("strawberry", 0), ("apple", 1), ("pear", 2), ("lemon", 3)])
def test_the_fits_given_their_scaled_cloud_are_the_fits(kind, seed):
    """A sphere and an ellipsoid fitted with the sample's :func:`scaled_cloud` made by the caller are the fits without
    it, to the bit."""
    from symfruit.core.fits import fit_ellipsoid, scaled_cloud

    fruit = FRUITS[kind](np.random.default_rng(seed))
    visible, _ = rendered_view(fruit, [0.01 * seed, -0.01, 0.35], noise=0.001 * seed, seed=seed)
    cloud = scaled_cloud(visible)
    for fit in (fit_sphere, fit_ellipsoid):
        for got, want in zip(fit(visible, scaled=cloud), fit(visible), strict=True):
            np.testing.assert_array_equal(got, want)


# --- stop 40, speedobs40


@given(st.integers(0, 2**32 - 1), st.integers(1, 60), st.integers(1, 60), st.sampled_from([0.0, 0.5, 1.0, 3.0]),
       st.booleans())  # fmt: skip
def test_the_shared_pixels_give_the_same_rim_coverage_and_inside_distances(seed, h, w, fill_radius, given_map):
    """``point_pixels`` is numpy's rounded projection converted as numpy converts it (NaN included), and
    ``rim_coverage`` and ``_inside_px`` from those pixels are their values from the points (kernel and twin), on
    rim_coverage's random regions and points (inside and outside the window, on rounding ties, one at NaN)."""
    from symfruit.core.agreement import _inside_px
    from symfruit.core.camera import DEFAULT_CAMERA as camera
    from symfruit.core.raster import Silhouette, inner_distance, point_pixels
    from symfruit.methods.evidence import rim_coverage

    rng = np.random.default_rng(seed)
    mask = _blobs(rng, h, w, rng.uniform(0.05, 0.6))
    region = Silhouette(int(rng.integers(0, 500)), int(rng.integers(0, 400)), mask, fill_radius)
    n = int(rng.integers(1, 2 * h * w + 2))
    u = region.u0 + rng.integers(-3, w + 3, n) + rng.choice([0.0, 0.5, -0.5, 0.3], n)
    v = region.v0 + rng.integers(-3, h + 3, n) + rng.choice([0.0, 0.5, -0.4], n)
    z = rng.uniform(0.3, 0.6, n)
    points = np.stack(((u - camera.cx) * z / camera.fx, (v - camera.cy) * z / camera.fy, z), axis=1)
    points[0, 0] = np.nan
    pixels = point_pixels(points, camera)
    with np.errstate(invalid="ignore"):
        uv = np.rint(camera.project(points))
        want = uv[:, 0].astype(np.int64), uv[:, 1].astype(np.int64)
    assert pixels is not None
    for got, expected in zip(pixels, want, strict=True):
        assert got.dtype == np.int64
        np.testing.assert_array_equal(got, expected)
    inner = inner_distance(mask) if given_map else None
    with pytest.MonkeyPatch.context() as mp, np.errstate(invalid="ignore"):
        fast, twin = _both(mp, rim_coverage, points, region, camera, inner=inner, pixels=pixels)
        assert fast == twin == rim_coverage(points, region, camera, inner=inner) and type(fast) is float
        full = inner_distance(mask)
        shared, own = _both(mp, _inside_px, points, region, camera, full, pixels)
    assert np.array_equal(shared, own) and np.array_equal(shared, _inside_px(points, region, camera, full))


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_a_silhouette_from_the_shared_pixels_is_the_same(seed, off_image):
    """``silhouette`` given the points' pixels (and its compiled box and marks) is the one it makes from the points
    alone, with the kernels and with the twins: sparse and dense clouds, some points off the image (the pixels are
    then not used) or none."""
    from symfruit.core.camera import Camera
    from symfruit.core.raster import point_pixels, silhouette

    rng = np.random.default_rng(seed)
    cam = Camera(fx=300.0, fy=310.0, cx=80.5, cy=60.0, width=160, height=120)
    n = int(rng.integers(1, 3000))
    z = rng.uniform(0.3, 0.6, n)
    spread = 90.0 if off_image else 40.0
    u = cam.cx + rng.normal(0.0, spread / 3, n).clip(-spread, spread)
    v = cam.cy + rng.normal(0.0, spread / 4, n).clip(-spread, spread)
    points = np.stack(((u - cam.cx) * z / cam.fx, (v - cam.cy) * z / cam.fy, z), axis=1)
    pixels = point_pixels(points, cam)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, silhouette, points, cam, pixels=pixels)
        plain, _ = _both(mp, silhouette, points, cam)
    for a in (twin, plain):
        assert (fast.u0, fast.v0, fast.fill_radius) == (a.u0, a.v0, a.fill_radius)
        assert fast.mask.dtype == a.mask.dtype == bool and np.array_equal(fast.mask, a.mask)


@settings(max_examples=120, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 5), st.floats(0.0, 0.9))
def test_close_ragged_closes_and_counts_as_the_twins_steps(seed, radius, holes):
    """The kernel's closing over the mask's box grown by ``radius + 1`` alone: the closed mask, the pixels it adds and
    the outline's pixels are the twin's (the padded mask closed and its holes filled, ``mask & ~interior(mask)``),
    whether or not the closing is kept, for masks touching the window's edges, empty, full or scattered."""
    from symfruit.core.raster import _closed_mask, interior

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 60, 2))
    rr, cc = np.mgrid[0:h, 0:w]
    kind = rng.random()
    if kind < 0.6:
        mask = (rr - rng.uniform(-5, h + 5)) ** 2 + (cc - rng.uniform(-5, w + 5)) ** 2 <= rng.uniform(1, 40) ** 2
        mask &= rng.random((h, w)) >= holes * rng.random((h, w))
    elif kind < 0.7:
        mask = np.ones((h, w), bool)
    else:
        mask = rng.random((h, w)) < holes
    closed, added, outline = _jit.close_ragged(mask, radius)
    padded = np.zeros((h + 2 * radius, w + 2 * radius), dtype=bool)
    padded[radius:-radius, radius:-radius] = mask
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        want = _closed_mask(padded, radius)[radius:-radius, radius:-radius]
    assert closed.dtype == bool and np.array_equal(closed, want)
    assert added == int((want & ~mask).sum()) and outline == int((mask & ~interior(mask)).sum())


@given(st.integers(0, 2**32 - 1), st.integers(1, 400))
def test_the_cloud_checks_without_the_finiteness_pass_are_the_twins(seed, n):
    """``check_cloud`` skips its finiteness pass when the compiled spread's diagonal is finite: the same clean points
    and dropped count as the twin's, with NaN and infinite coordinates (either sign) in some rows or none."""
    from symfruit.core.points import check_cloud

    rng = np.random.default_rng(seed)
    points = rng.normal(0.0, 0.02, (n + 12, 3)) + [0.0, 0.0, 0.4]
    for _ in range(int(rng.integers(0, 4))):
        points[rng.integers(0, len(points)), rng.integers(0, 3)] = rng.choice([np.nan, np.inf, -np.inf])
    with pytest.MonkeyPatch.context() as mp:
        (fast, fast_dropped), (twin, twin_dropped) = _both(mp, check_cloud, points, min_points=10)
    assert fast_dropped == twin_dropped and np.array_equal(fast, twin)


# --- stop 40, speedreg40


def _blob_mask(rng: np.random.Generator, h: int, w: int) -> np.ndarray:
    """A mask of both kinds of pixel: a disc, speckle, a whole row or a lone hole (rows and windows that are all mask
    or all background, holes in a row spanning the window)."""
    kind = int(rng.integers(0, 4))
    if kind == 0:
        yy, xx = np.mgrid[:h, :w]
        mask = (yy - rng.uniform(0, h)) ** 2 + (xx - rng.uniform(0, w)) ** 2 < rng.uniform(1, 40) ** 2
    elif kind == 1:
        mask = rng.random((h, w)) < rng.uniform(0.05, 0.95)
    elif kind == 2:
        mask = np.zeros((h, w), bool)
        mask[int(rng.integers(0, h)), :] = True
    else:
        mask = np.ones((h, w), bool)
        mask[int(rng.integers(0, h)), int(rng.integers(0, w))] = False
    if mask.all() or not mask.any():
        mask[0, 0] = not mask[0, 0]
    return mask


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 25), st.booleans())
def test_the_outlines_maps_keys_and_ranks_are_the_twins_to_the_bit(seed, reach, wide):
    """``outline_maps`` on masks of every shape (wide windows: keys beyond 16 bits, no keys then): the mask's distance
    map (``inner_distance``), the signed map (``inner - distance_transform(~mask)``), and the padded keys, places and
    values of ``_Outline.keys`` and ``_Outline.ranks``, the same arrays and dtypes bit for bit."""
    from symfruit.core.raster import distance_transform, inner_distance
    from symfruit.core.surface import _Outline

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 200 if wide else 60, 2))
    mask = _blob_mask(rng, h, w)
    inner, inside = np.empty(mask.shape), np.empty(mask.shape)
    pad = reach + int(rng.integers(0, 3))
    ok, keys, ranks, values = _jit.outline_maps(mask, pad, reach, inner, inside)
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        want_inner = inner_distance(mask)
        want_inside = want_inner - distance_transform(~mask)
        twin = _Outline(np.zeros(1, np.int64), np.zeros(1, np.int64), want_inside, 1.0)
        want_keys = twin.keys(pad, reach)
        assert np.array_equal(inner, want_inner) and np.array_equal(inside, want_inside)
        assert want_keys is not None
        assert ok == (want_keys.dtype == np.int16)
        if ok:
            want_ranks, want_values = twin.ranks(pad, reach)
            assert keys.dtype == want_keys.dtype and np.array_equal(keys, want_keys)
            assert ranks.dtype == want_ranks.dtype and np.array_equal(ranks, want_ranks)
            assert np.array_equal(values, want_values)


@pytest.mark.parametrize("seed", range(4))
def test_the_outlines_keys_and_ranks_made_with_its_maps_are_its_own(monkeypatch, seed):
    """The keys and ranks ``_outline`` keeps from its maps' kernel are those ``_Outline.keys`` and ``ranks`` make from
    its signed map, and its costs (fast and exact) the same numbers."""
    from symfruit.core.surface import _Outline, _outline

    depth, mask, _ = _ball_frame(seed)
    outline = _outline(depth, mask, 600.0, 20)
    assert outline is not None and ("keys", 20, 20) in outline._padded and (20, 20) in outline._ranks
    again = _Outline(outline.rows, outline.cols, outline.inside, outline.band, outline.sides)
    assert np.array_equal(outline.keys(20, 20), again.keys(20, 20))
    for got, want in zip(outline.ranks(20, 20), again.ranks(20, 20), strict=True):
        assert got.dtype == want.dtype and np.array_equal(got, want)
    shifts = np.random.default_rng(seed).integers(-20, 21, (50, 2))
    for exact in (False, True):
        assert np.array_equal(outline.cost(shifts, 20, 0.7, exact=exact), again.cost(shifts, 20, 0.7, exact=exact))


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 900), st.integers(1, 4), st.integers(1, 6))
def test_colour_trims_summary_separation_and_band_are_the_twins_to_the_bit(seed, n, k, iterations):
    """Colours on a coarse grid (equal features, rows as near two centres): ``trim_summary`` is ``kmeans`` of the
    picked rows from ``np.linspace``'s starts, ``trim_separation`` the counts of ``nearer_fruit`` (margin 1) over
    the fruit's rows and against it over the ring's, ``trim_band`` the mask with its band's pixels replaced by their
    test, bit for bit."""
    from symfruit.core.surface import _colour_features, _kmeans, _nearer_fruit, _spread

    rng = np.random.default_rng(seed)
    grid = np.arange(0, 256, 51)
    x = _colour_features(rng.choice(grid, size=(n, 1, 3)).astype(np.uint8), np.ones((n, 1), bool))
    pick = rng.choice(n, min(n, int(rng.integers(1, 500))), replace=False)
    rows = x[pick]
    want = _kmeans(rows, rows[np.linspace(0, len(rows) - 1, k).astype(int)], iterations)
    assert np.array_equal(_jit.trim_summary(x, pick, _spread(len(pick), k), iterations), want)
    m = int(rng.integers(1, 300))
    ring = _colour_features(rng.choice(grid, size=(m, 1, 3)).astype(np.uint8), np.ones((m, 1), bool))
    fc, bc = x[rng.integers(0, n, k)], x[rng.integers(0, n, k)] + rng.choice([0.0, 0.01])
    counts = _jit.trim_separation(x, ring, fc, bc)
    assert counts == (int(_nearer_fruit(x, fc, bc, 1.0).sum()), int((~_nearer_fruit(ring, fc, bc, 1.0)).sum()))
    color = rng.choice(grid, size=(int(rng.integers(1, 30)), int(rng.integers(1, 30)), 3)).astype(np.uint8)
    mask = rng.random(color.shape[:2]) < 0.7
    band = mask & (rng.random(mask.shape) < 0.5)
    for margin in (1.0, 0.5):
        keep = mask.copy()
        keep[band] = _nearer_fruit(_colour_features(color, band), fc, bc, margin)
        out = np.empty(mask.shape, bool)
        _jit.trim_band(color, mask, band, fc, bc, margin, out)
        assert np.array_equal(out, keep)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_trims_regions_with_their_features_and_one_seeds_piece_are_the_twins(seed):
    """``trim_features``: ``trim_regions``' fruit and band and ``colour_features`` of its fruit and ring, bit for bit;
    ``connected_at``: ``connected`` with a seed image of that pixel alone."""
    from symfruit.core.raster import inner_distance

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 50, 2))
    mask = _blob_mask(rng, h, w)
    color = rng.integers(0, 256, (h, w + 3, 3)).astype(np.uint8)[:, 1 : w + 1]  # a window of a wider image
    inner = inner_distance(mask)
    band_px = float(rng.uniform(0.5, 8.0))
    fruit, ring, band = (np.empty(mask.shape, bool) for _ in range(3))
    counts = _jit.trim_regions(inner, mask, band_px, 3.0 * band_px + 1, band_px + 1.0, fruit, ring, band)
    got_fruit, got_band = np.empty(mask.shape, bool), np.empty(mask.shape, bool)
    f_fruit, f_ring, n_band = _jit.trim_features(color, inner, mask, band_px, 3.0 * band_px + 1, band_px + 1.0,
                                                 got_fruit, got_band)  # fmt: skip
    assert np.array_equal(got_fruit, fruit) and np.array_equal(got_band, band) and n_band == counts[2]
    assert np.array_equal(f_fruit, _jit.colour_features(color, fruit)) and len(f_fruit) == counts[0]
    assert np.array_equal(f_ring, _jit.colour_features(color, ring)) and len(f_ring) == counts[1]
    r, c = (int(x) for x in np.argwhere(mask)[int(rng.integers(0, mask.sum()))])
    seeds = np.zeros(mask.shape, bool)
    seeds[r, c] = True
    want, got = np.empty(mask.shape, bool), np.empty(mask.shape, bool)
    _jit.connected(mask, seeds, want)
    _jit.connected_at(mask, r, c, got)
    assert np.array_equal(got, want)


# --- stop 40, speedext40


def test_the_switch_is_read_on_every_call_after_the_kernels_are_found(monkeypatch):
    """compiled()'s look-up of an unset SYMFRUIT_KERNELS: the environment set or unset between calls (os.environ as
    tests set it, and through monkeypatch) still switches, and a reset state is looked for again."""
    import os

    monkeypatch.delenv("SYMFRUIT_KERNELS", raising=False)
    assert kernels.compiled() is _jit and kernels.compiled() is _jit
    os.environ["SYMFRUIT_KERNELS"] = "numpy"
    try:
        assert kernels.compiled() is None
    finally:
        del os.environ["SYMFRUIT_KERNELS"]
    assert kernels.compiled() is _jit
    monkeypatch.setenv("SYMFRUIT_KERNELS", "NUMPY")
    assert kernels.compiled() is None
    monkeypatch.delenv("SYMFRUIT_KERNELS")
    monkeypatch.setattr(kernels, "_STATE", {})
    assert kernels.compiled() is _jit and kernels._STATE == {"jit": _jit}


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40), st.integers(0, 3), st.integers(0, 20),
       st.booleans(), st.booleans(), st.sampled_from([0.0, 0.005, -0.005]))  # fmt: skip
def test_the_occlusion_at_is_own_depths_then_the_window(seed, h, w, reach, pad, single, with_others, tol):
    """occlusion_at against own_depths then occlusion_window with the points' least and greatest depth: the same
    window, hidden pixels and seen depths, bit for bit; points off the image, points sharing a pixel, depths from a
    few values (ties, depths on the bounds), dropouts as 0 and NaN, float32 and float64 images, other fruit or not."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 60))
    uv = np.stack((rng.uniform(-5, w + 5, n), rng.uniform(-5, h + 5, n)), axis=1)
    if rng.random() < 0.5:
        uv = np.round(uv * 2) / 2  # halves: np.rint's ties to even
    points = np.zeros((n, 3))
    points[:, 2] = rng.choice([0.5, 0.51, 0.52, 0.53], n)
    depth = rng.choice([0.0, np.nan, 0.49, 0.5, 0.505, 0.51, 0.515, 0.52, 0.525, 0.53, 0.535, 0.6], (h, w))
    depth = depth.astype(np.float32 if single else np.float64)
    mask = rng.random((h, w)) < 0.2
    others = rng.random((h, w)) < 0.3 if with_others else np.zeros((0, 0), bool)
    steps = _steps_within(reach)
    found, u0, v0, u1, v1, own_z, _ = _jit.own_depths(uv, points, w, h, pad)
    got = _jit.occlusion_at(uv, points, pad, depth, mask, others, tol, steps)
    assert got[0] == found
    if not found:
        return
    hidden, seen = np.empty((v1 - v0, u1 - u0), bool), np.empty((v1 - v0, u1 - u0))
    near = others[v0:v1, u0:u1] if with_others else others
    _jit.occlusion_window(np.ascontiguousarray(depth[v0:v1, u0:u1]), np.ascontiguousarray(mask[v0:v1, u0:u1]),
                          own_z, np.ascontiguousarray(near), tol, steps, float(points[:, 2].min()),
                          float(points[:, 2].max()), hidden, seen)  # fmt: skip
    assert (got[1], got[2]) == (u0, v0)
    assert got[3].dtype == bool and np.array_equal(got[3], hidden) and got[4].tobytes() == seen.tobytes()


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40))
def test_the_reach_box_is_the_flood_box(seed, h, w):
    """_reach_box (the fill from the seen pixels' edge, by runs) against _flood_box's box on random joins and seen
    regions (join and seen overlapping, seen pixels scattered or a block, touching the edges)."""
    rng = np.random.default_rng(seed)
    join = rng.random((h, w)) < rng.uniform(0.0, 0.9)
    seen = np.zeros((h, w), bool)
    if rng.random() < 0.5:
        r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
        seen[r0 : r0 + int(rng.integers(1, 10)), c0 : c0 + int(rng.integers(1, 10))] = True
    else:
        seen = rng.random((h, w)) < 0.1
    if not seen.any():
        seen[h // 2, w // 2] = True
    rows, cols = np.nonzero(seen)
    box = (int(rows.min()), int(rows.max()) + 1, int(cols.min()), int(cols.max()) + 1)
    want = _jit._flood_box(join, seen, *box)[1:]
    assert tuple(int(x) for x in _jit._reach_box(join, seen, *box)) == tuple(int(x) for x in want)


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([8, 72, 7, 360]))
def test_the_sectors_from_the_table_are_the_arctan2_ones(seed, bins):
    """monotone_region's sectors read off _sector_table against monotone_rays' from numpy's arctan2: the same pixels,
    on random caps with the apex anywhere (outside the window too), offsets on the axes and diagonals (where a
    direction falls on a sector's edge), tables grown as a larger offset is asked for and none beyond the bound."""
    from symfruit.core import surface

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 90, 2))
    keep = rng.random((h, w)) < rng.uniform(0.1, 1.0)
    depth = rng.choice([0.5, 0.501, 0.503, 0.51], (h, w))
    apex = (int(rng.integers(-5, h + 5)), int(rng.integers(-5, w + 5)))
    rows, cols, dy, dx = _jit.ray_pixels(keep, *apex)
    want = np.zeros((h, w), bool)
    _jit.monotone_rays(depth, rows, cols, np.arctan2(dy, dx), dy, dx, bins, bins / (2.0 * np.pi), 0.002, want)
    reach = max(abs(apex[0]), abs(h - 1 - apex[0]), abs(apex[1]), abs(w - 1 - apex[1]))
    table = surface._sector_table(bins, reach)
    r = (table.shape[0] - 1) // 2
    assert r >= reach and table.dtype == np.int16
    got = np.zeros((h, w), bool)
    _jit.monotone_table(depth, rows, cols, dy, dx, table, r, bins, 0.002, got)
    np.testing.assert_array_equal(got, want)
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv("SYMFRUIT_KERNELS", raising=False)
        np.testing.assert_array_equal(surface.monotone_region(depth, keep, apex, 0.002, bins=bins), want)
        mp.setattr(surface, "_SECTOR_REACH", 0)  # beyond the tables' bound: arctan2 per pixel
        assert surface._sector_table(bins, 1) is None
        np.testing.assert_array_equal(surface.monotone_region(depth, keep, apex, 0.002, bins=bins), want)


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 400), st.sampled_from([0.001, 0.004, 0.006, 0.02]),
       st.floats(0.001, 0.2), st.sampled_from(["spread", "few", "far"]))  # fmt: skip
def test_depth_slabs_are_the_sorted_depths_slabs_and_the_clusters_are_the_twins(seed, n, distance, spread, kind):
    """_depth_slabs (stop 62) cuts the points into the slabs of their sorted depths: each run of its order holds the
    points of one run of the sorted depths between gaps over ``distance``, in ascending order of depth (depths drawn
    from a few values, gaps just over and under ``distance``, a few points far behind: its stable sort), and clusters
    gives the numpy twin's labels either way."""
    from symfruit.extract import cluster

    rng = np.random.default_rng(seed)
    points = rng.uniform(-0.03, 0.03, (n, 3))
    points[:, 2] = 0.5 + (rng.choice(rng.uniform(0.0, spread, 8), n) if kind == "few" else rng.uniform(0.0, spread, n))
    if rng.random() < 0.3 and n > 2:  # a gap of about the distance
        points[: n // 2, 2] += rng.choice([distance * (1 - 1e-12), distance * (1 + 1e-12), 1.5 * distance])
    if kind == "far":  # more buckets than four a point: the stable sort
        points[: max(1, n // 10), 2] += rng.uniform(2.0, 5.0, max(1, n // 10))
    order, ends = _jit._depth_slabs(points, distance)
    assert np.array_equal(np.sort(order), np.arange(n)) and ends[-1] == n and (np.diff(ends) > 0).all()
    z = np.sort(points[:, 2], kind="stable")
    want = np.r_[np.flatnonzero(np.diff(z) > distance) + 1, n]
    np.testing.assert_array_equal(ends, want)
    for lo, hi in zip(np.r_[0, ends[:-1]], ends, strict=True):  # each run: the sorted depths' run, as a multiset
        np.testing.assert_array_equal(np.sort(points[order[lo:hi], 2]), z[lo:hi])
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, cluster, points, distance)
    np.testing.assert_array_equal(fast, twin)
    labels, done = _jit.clusters(points, distance)
    assert done and np.array_equal(labels, twin)


def test_clusters_of_no_points_and_of_one():
    """No points: no labels (done); one point: label 0."""
    labels, done = _jit.clusters(np.zeros((0, 3)), 0.006)
    assert done and labels.dtype == np.int64 and len(labels) == 0
    labels, done = _jit.clusters(np.array([[0.0, 0.0, 0.5]]), 0.006)
    assert done and labels.tolist() == [0]


# --- stop 40, speedseg40


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([0.0, 2.0, 3.3]), st.booleans())
def test_the_segmenters_split_up_to_its_centres_is_the_twins(seed, sigma, holes):
    """Two to four fruit-like caps at random depths, some touching, with holes, pixels without depth and speckle, in a
    window of random shape: ``split_seen`` is ``fill_holes``, the count of the region's pixels with depth and their
    median, ``split_centres`` the twins' depth edges, carved region and centres (``_depth_edges``, ``fill_holes``,
    ``_centres`` without coarsening), and ``_split`` cuts the same parts with the kernels and with the twins."""
    from symfruit.core.points import median
    from symfruit.core.raster import fill_holes
    from symfruit.segment import colour

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(8, 120, 2))
    yy, xx = np.mgrid[:h, :w]
    depth = np.zeros((h, w))
    region = np.zeros((h, w), bool)
    for _ in range(int(rng.integers(2, 5))):
        cy, cx, r, z = rng.uniform(0, h), rng.uniform(0, w), rng.uniform(4, 35), rng.uniform(0.4, 0.6)
        disc = (yy - cy) ** 2 + (xx - cx) ** 2 <= r * r
        cap = z - 0.001 * np.sqrt(np.maximum(r * r - (yy - cy) ** 2 - (xx - cx) ** 2, 0.0))
        depth = np.where(disc & ((depth == 0) | (cap < depth)), cap, depth)
        region |= disc
    depth += rng.normal(0.0, 0.0005, (h, w)) * (depth > 0)
    depth[rng.random((h, w)) < 0.1] = 0.0
    if holes:
        region &= rng.random((h, w)) < 0.97
    depth = np.where(region, depth, 0.0)
    s = colour.SegmentSettings(crease_sigma=sigma)
    geo = colour._Geometry(600.0, h / 2, w / 2)
    full, k, zm = _jit.split_seen(region, depth)
    want = fill_holes(region)
    np.testing.assert_array_equal(full, want)
    seen = want & (depth > 0)
    assert k == int(seen.sum())
    if k:
        assert zm == float(median(depth[seen]))
    if k >= 20:
        least = max(0.25 * geo.focal * s.min_diameter / zm, 2.0)
        weights, symmetric = colour._gaussian_weights(sigma) if sigma > 0 else (np.ones(1), True)
        limit = -s.crease_curvature * (zm / geo.focal) ** 2
        edges, found = _jit.split_centres(full, depth, weights, symmetric, limit, s.depth_jump, int(least), least,
                                          colour.CANDIDATE_WAIST, s.waist, colour.MAX_WAIST_TESTS)  # fmt: skip
        with pytest.MonkeyPatch.context() as mp:
            mp.setenv("SYMFRUIT_KERNELS", "numpy")
            twin_edges = colour._depth_edges(full, depth, seen, float(zm), s, geo.focal)
            carved = fill_holes(full & ~twin_edges)
            twin = colour._centres(carved, least, s.waist, colour.CANDIDATE_WAIST, coarse=False)
        np.testing.assert_array_equal(edges, twin_edges)
        assert [(int(a), int(b), float(r), bool(f)) for a, b, r, f in found.tolist()] == twin
    with pytest.MonkeyPatch.context() as mp:
        fast, twin_parts = _both(mp, colour._split, region, depth, s, geo, (3, 5), 50.0)
    assert len(fast) == len(twin_parts) and all(np.array_equal(a, b) for a, b in zip(fast, twin_parts, strict=True))


# --- stop 41, speedreg41


def _frame_outlines(seed: int, reach: int):
    """:func:`tests.core.test_surface.ball_outlines` told along at least one axis."""
    from .test_surface import ball_outlines

    return [found for found in ball_outlines(seed, reach) if any(found.axes)]


@pytest.mark.parametrize("seed", range(8))
def test_the_frames_fast_costs_are_the_outlines_to_the_bit(seed):
    """``frame_costs`` (issue 19, stop 41): every stage's costs are ``_told``'s fast costs of each outline (its
    one-axis outlines' too), bit for bit; the pruned stage leaves every shift the numpy search can take and the same
    costs in their columns; and ``_FrameCosts.least`` is the index of its numpy twin's (``_told`` outline by outline,
    stop 42; pruned with more than ``_PRUNE_FROM`` shifts) and of the search's plain ``least`` (fewer), on whole
    grids, one-axis grids, and a few shifts, ties included."""
    from symfruit.core import _jit, surface

    reach, trim = 10, 0.7
    outlines = _frame_outlines(seed, reach)
    assert len(outlines) >= 3
    # one-axis outlines among them (a fruit on a board tells one axis): their axes as _free_points might count them
    outlines[1].__dict__["axes"] = (True, False)
    outlines[2].__dict__["axes"] = (False, True)

    def cost(shifts, exact=True):
        return np.mean([surface._told(o, shifts, reach, trim, exact) for o in outlines], axis=0)

    frame = surface._FrameCosts.of(outlines, reach, trim)
    assert frame.jit is not None
    twin = surface._FrameCosts(outlines, reach, trim)  # the numpy stages
    rng = np.random.default_rng(seed)
    coarse = np.arange(-reach, reach + 1, 2)
    grids = [np.stack(np.meshgrid(coarse, coarse, indexing="ij"), -1).reshape(-1, 2),
             np.stack(np.meshgrid(coarse, [0], indexing="ij"), -1).reshape(-1, 2),
             rng.integers(-reach, reach + 1, (int(rng.integers(1, 30)), 2)),
             np.zeros((40, 2), np.int64)]  # fmt: skip
    for grid in grids:
        grid = grid.astype(np.int64)
        want = np.array([surface._told(o, grid, reach, trim, False) for o in outlines])
        out = np.full((len(outlines), len(grid)), np.nan)
        f = int(frame.order[0])  # the outline of fewest points first (stop 42)
        assert len(outlines[f].rows) == min(len(o.rows) for o in outlines)
        best = int(frame._stage(grid, 0, -1, 0.0, 0.0, out)[0])
        assert best == int(np.argmin(want[f])) and np.array_equal(out[f], want[f])
        frame._stage(grid, 1, best, 0.0, 0.0, out)
        assert np.array_equal(out[:, best], want[:, best])
        everything = frame._stage(grid, 3, -1, 0.0, 0.0, out.copy())
        assert np.array_equal(everything, np.arange(len(grid)))
        sums = want.sum(axis=0)
        slack = 1e-10
        for upper in (float(np.quantile(sums, 0.3)) / len(outlines), float(want[:, best].mean())):
            limit = surface._limit(upper, slack, len(outlines))
            assert limit == _jit.prune_limit(upper, slack, len(outlines))
            stage = out.copy()
            alive = frame._stage(grid, 2, best, upper, slack, stage)
            summed = np.cumsum(want[frame.order], axis=0)  # every shift left has its sums in order within the limit
            within = np.flatnonzero((summed <= limit).all(axis=0))
            assert np.isin(alive, within).all() and np.array_equal(stage[:, alive], want[:, alive])
            # the bound lowered by the frame costs it found: no shift as cheap as the least of those dropped
            least_sum = sums[within].min() if len(within) else np.inf
            assert np.isin(within[sums[within] <= least_sum + 1e-9], alive).all()
            twin_out = out.copy()
            assert np.array_equal(twin._stage(grid, 2, best, upper, slack, twin_out), alive)
            assert np.array_equal(twin_out, stage, equal_nan=True)
        if len(outlines) == 1 or len(grid) <= surface._PRUNE_FROM:  # the plain search
            fast = cost(grid, exact=False)
            near = np.flatnonzero(fast <= fast.min() + 2e-10 * (1.0 + float(np.abs(fast).max())))
            assert twin.least(grid, cost) == (int(near[np.argmin(cost(grid[near]))]) if len(near) > 1 else int(near[0]))
        assert frame.least(grid, cost) == twin.least(grid, cost)


def test_the_frames_fast_costs_wait_for_16_bit_keys(monkeypatch):
    """No compiled ``_FrameCosts`` with the numpy twins, nor for an outline whose map has no 16-bit keys (the search
    costs those outlines by ``_told``); ``registration_shift`` finds the same shift with it and without it."""
    from symfruit.core import surface
    from symfruit.core.surface import registration_shift

    from .test_surface import F, three_balls_moved

    outlines = _frame_outlines(0, 10)
    monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    assert surface._FrameCosts.of(outlines, 10, 0.7).jit is None
    monkeypatch.delenv("SYMFRUIT_KERNELS")
    assert surface._FrameCosts.of(outlines, 10, 0.7).jit is not None
    wide = outlines[0]
    monkeypatch.setitem(wide._padded, ("keys", 10, 10), wide.keys(10, 10).astype(np.int32))
    assert surface._FrameCosts.of(outlines, 10, 0.7).jit is None
    moved, labels = three_balls_moved()
    assert registration_shift(moved.astype(np.float32), labels, F, max_px=10) == (-2, 3)
    found = registration_shift(moved, labels, F, max_px=10)
    monkeypatch.setattr(surface._FrameCosts, "of", classmethod(lambda cls, *a: cls(*a)))  # the numpy stages
    assert registration_shift(moved, labels, F, max_px=10) == found == (-2, 3)


# --- stop 41, speedobs41


@pytest.mark.parametrize("seed", range(6))
def test_near_distance_on_fruit_sized_windows_is_the_twins_to_the_bit(seed):
    """stop 41's row walk of :func:`symfruit.core._jit.near_distance` on windows as large as a dense view's (ragged
    discs and ellipses 40-150 px across, holes, a second blob), both sides, the reaches observation asks for and
    more: the numpy twin's values to the bit."""
    from symfruit.core.raster import _near_distance

    rng = np.random.default_rng(seed)
    h, w = int(rng.integers(40, 170)), int(rng.integers(40, 170))
    rr, cc = np.mgrid[:h, :w]
    a, b = rng.uniform(0.2, 0.5) * h, rng.uniform(0.2, 0.5) * w
    mask = ((rr - h / 2) / a) ** 2 + ((cc - w / 2) / b) ** 2 <= 1.0
    mask &= rng.random((h, w)) > rng.uniform(0.0, 0.05)  # dropped pixels: holes and a ragged edge
    mask |= _blobs(rng, h, w, 0.002)
    for reach in (0.0, 1.0, 2.5, 5.5, 8.0, 10.3, 13.0, 15.0, 16.0, 16.9, 17.0, 24.5):  # both sides of stop 64's passes
        for want in (False, True):
            out = np.full((h, w), -1.0)
            _jit.near_distance(mask, reach, want, out)
            assert np.array_equal(out, _near_distance(mask == want, reach))


# --- stop 41, speedext41


def _edge_case(seed: int, band: int):
    """A window with a fruit's own pixels, a ring of hidden pixels at its depth beside them (some running on, some
    behind a gap), other fruit, depths with NaN and the own depths (+inf off the points' pixels)."""
    rng = np.random.default_rng(seed)
    h, w = int(rng.integers(20, 70)), int(rng.integers(20, 70))
    rr, cc = np.mgrid[0:h, 0:w]
    r0, c0, rad = rng.uniform(0.3, 0.7) * h, rng.uniform(0.3, 0.7) * w, rng.uniform(4, 15)
    dist = np.hypot(rr - r0, cc - c0)
    own = dist <= rad
    own_z = np.where(own & (rng.random((h, w)) < 0.9), 0.5 + 0.01 * rng.random((h, w)), np.inf)
    depth = np.where(rng.random((h, w)) < 0.5, 0.5 + rng.normal(0.0, 0.01, (h, w)), 0.8)
    depth[rng.random((h, w)) < 0.1] = np.nan
    hidden = ~own & (((dist <= rad + rng.uniform(1, band + 4)) & (rng.random((h, w)) < 0.95))
                     | (rng.random((h, w)) < rng.uniform(0.0, 0.3)))  # fmt: skip
    others = (rng.random((h, w)) < 0.05) if rng.random() < 0.5 else None
    return hidden, own, own_z, depth, others


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**31 - 1), st.integers(0, 9), st.booleans(), st.sampled_from([0.0, 300.0, 1000.0]))
def test_the_own_edge_kernel_clears_the_twins_pixels(seed, band, supports, focal):
    from symfruit.core.occlusion import own_edge

    hidden, own, own_z, depth, others = _edge_case(seed, band)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, own_edge, hidden, own, own_z, depth, others, 0.005, band, supports, focal)
    np.testing.assert_array_equal(fast, twin)
    np.testing.assert_array_equal(hidden, _edge_case(seed, band)[0])  # its input is left alone


def test_the_row_minimum_kernel_is_scipys_minimum_filter():
    from scipy import ndimage

    rng = np.random.default_rng(41)
    for k in range(0, 9):
        x = np.where(rng.random((7, 23)) < 0.6, rng.random((7, 23)), np.inf)
        out = np.empty_like(x)
        _jit._row_min(x, k, out)
        want = ndimage.minimum_filter1d(x, size=2 * k + 1, axis=1, mode="constant", cval=np.inf)
        np.testing.assert_array_equal(out, want)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**31 - 1), st.sampled_from([0, 3, 8]), st.booleans(), st.booleans())
def test_the_occlusion_in_one_call_gives_the_twins_maps(seed, band, with_others, single):
    """core.occlusion.occlusion (jit.occlusion_projected: the maps, the own depths and own_edge in one kernel) against
    the numpy twins on a disc fruit whose depth the sensor spread a few pixels past its mask (a fattened edge), a
    leaf in front, another fruit beside, dropouts: the same window, hidden pixels and seen depths, bit for bit."""
    from symfruit.core.camera import Camera
    from symfruit.core.occlusion import occlusion

    rng = np.random.default_rng(seed)
    camera = Camera(fx=300.0, fy=300.0, cx=40.0, cy=30.0, width=80, height=60)
    rr, cc = np.mgrid[0:60, 0:80]
    r0, c0, rad = rng.uniform(15, 45), rng.uniform(20, 60), rng.uniform(5, 12)
    dist = np.hypot(rr - r0, cc - c0)
    zf = 0.4 + 0.0005 * dist
    depth = np.where(dist <= rad + rng.uniform(0, 6), zf, 1.0) + rng.normal(0.0, 0.001, (60, 80))
    leaf = (np.abs(rr - rng.uniform(0, 60)) < rng.uniform(0, 4)) & (cc > rng.uniform(0, 80))
    depth = np.where(leaf, 0.3, depth)
    depth[rng.random((60, 80)) < 0.05] = 0.0
    depth = depth.astype(np.float32 if single else np.float64)
    mask = (dist <= rad) & ~leaf
    sel = mask & (rng.random((60, 80)) < 0.9)
    if not sel.any():
        return
    v, u = np.nonzero(sel)
    z = zf[sel]
    points = np.column_stack(((u - 40.0) * z / 300.0, (v - 30.0) * z / 300.0, z))
    others = (np.hypot(rr - r0, cc - c0 - 2 * rad - 3) <= rad) if with_others else None
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, occlusion, depth, mask, points, camera, others=others, band=band)
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        plain = occlusion(depth, mask, points, camera, others=others, band=0)
    assert (fast.u0, fast.v0) == (twin.u0, twin.v0) and np.array_equal(fast.hidden, twin.hidden)
    assert np.array_equal(fast.own, twin.own) and fast.depth.tobytes() == twin.depth.tobytes()
    if band == 0:
        assert np.array_equal(fast.hidden, plain.hidden)


def test_the_occlusion_in_one_call_clears_a_fattened_edge():
    """The case the test above draws from, fixed: a disc whose depth runs 3 px past its mask onto background; the
    ring is hidden without the band and cleared with it, by the kernel and by the twin."""
    from symfruit.core.camera import Camera
    from symfruit.core.occlusion import occlusion

    camera = Camera(fx=300.0, fy=300.0, cx=40.0, cy=30.0, width=80, height=60)
    rr, cc = np.mgrid[0:60, 0:80]
    dist = np.hypot(rr - 30, cc - 40)
    depth = np.where(dist <= 13, 0.4, 1.0)
    mask = dist <= 10
    v, u = np.nonzero(mask)
    points = np.column_stack(((u - 40.0) * 0.4 / 300.0, (v - 30.0) * 0.4 / 300.0, np.full(len(u), 0.4)))
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, occlusion, depth, mask, points, camera, band=8)
        bare, _ = _both(mp, occlusion, depth, mask, points, camera, band=0)
    assert bare.hidden.sum() > 100 and not fast.hidden.any() and not twin.hidden.any()


def _monotone_at_against_the_table(depth, keep, apex, bins, reach, tol):
    """monotone_at's pixels (returned), asserted to be ray_pixels then monotone_table's with the sector table of
    ``bins`` and ``reach``, and its count every kept pixel."""
    from symfruit.core import surface

    table = surface._sector_table(bins, reach)
    r = (table.shape[0] - 1) // 2
    rows, cols, dy, dx = _jit.ray_pixels(keep, *apex)
    want = np.zeros(keep.shape, bool)
    _jit.monotone_table(depth, rows, cols, dy, dx, table, r, bins, tol, want)
    got = np.zeros(keep.shape, bool)
    assert _jit.monotone_at(depth, keep, apex[0], apex[1], table, r, bins, tol, got) == int(keep.sum())
    np.testing.assert_array_equal(got, want)
    return got


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([8, 72, 7]), st.sampled_from([0.0, 0.002, np.inf]))
def test_monotone_at_is_ray_pixels_then_the_table(seed, bins, tol):
    """monotone_at (one call) against ray_pixels then monotone_table, and monotone_region with the kernels against
    its twin: the same pixels, the apex anywhere (outside the window too), no kept pixel, an infinite tolerance."""
    from symfruit.core import surface

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 70, 2))
    keep = rng.random((h, w)) < rng.choice([0.0, rng.uniform(0.1, 1.0)])
    depth = rng.choice([0.5, 0.501, 0.503, 0.51], (h, w))
    apex = (int(rng.integers(-5, h + 5)), int(rng.integers(-5, w + 5)))
    reach = max(abs(apex[0]), abs(h - 1 - apex[0]), abs(apex[1]), abs(w - 1 - apex[1]))
    if np.isfinite(tol):
        _monotone_at_against_the_table(depth, keep, apex, bins, reach, tol)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, surface.monotone_region, depth, keep, apex, tol, bins=bins)
    np.testing.assert_array_equal(fast, twin)


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([8, 72, 7]), st.sampled_from([0.0, 0.002, 5.0, -0.001, -3.0]),
       st.sampled_from([1.0, -1.0, 1e6, 1e12, 1e14]))  # fmt: skip
def test_monotone_at_by_distance_alone_is_the_sector_walk(seed, bins, tol, size):
    """monotone_at's walk in order of distance alone, each sector's maximum kept apart (stop 62, surf62: tolerance 0
    or more, finite depths below 2^40 with the sectors' offsets), and its walk in sector order (elsewhere) against
    ray_pixels then monotone_table: the same pixels, with negative depths, negative tolerances, depths near and past
    the bound, ties, and depths falling and rising along the rays."""
    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 60, 2))
    keep = rng.random((h, w)) < rng.uniform(0.2, 1.0)
    depth = size * (0.5 + rng.choice([0.0, 0.001, 0.003, 0.01, -0.002], (h, w)) * rng.uniform(0.5, 2.0))
    if rng.random() < 0.3:
        depth = np.round(depth, 3)
    apex = (int(rng.integers(0, h)), int(rng.integers(0, w)))
    reach = max(apex[0], h - 1 - apex[0], apex[1], w - 1 - apex[1])
    got = _monotone_at_against_the_table(depth, keep, apex, bins, reach, tol)
    if size == 1.0 and tol == 0.002 and keep.sum() > 50:
        assert 0 < got.sum()  # the test reaches kept pixels


# --- stop 41, speedcand41


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 20), st.booleans(), st.sampled_from(["any", "first", "last"]))
def test_revolution_box_and_profile_are_the_twins(seed, bins, close, widest):
    """:func:`symfruit.core.fits.box_and_profile` with the kernel and with its twin (:func:`closed_profile` and the
    rings' box): the same profile and box bit for bit, on profiles with unseen (NaN) slices, fewer than two seen ones,
    the widest slice first or last (closed by symmetry) or inside, axes along a coordinate axis (no spread there) and
    tilted ones; and :func:`revolution_box` is its box."""
    from symfruit.core.fits import Revolution, box_and_profile, revolution_box

    rng = np.random.default_rng(seed)
    direction = rng.normal(size=3) if rng.random() < 0.8 else np.eye(3)[int(rng.integers(3))] * rng.choice([-1, 1])
    direction = direction / np.linalg.norm(direction)
    edges = np.sort(rng.normal(0.0, 0.03, bins + 1))
    radii = rng.uniform(0.001, 0.04, bins)
    if widest == "first":
        radii = np.sort(radii)[::-1].copy()
    elif widest == "last":
        radii = np.sort(radii)
    radii[rng.random(bins) < 0.2] = np.nan
    rev = Revolution(rng.normal(0.0, 0.05, 3) + [0, 0, 0.4], direction, edges, radii, 0.0)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, box_and_profile, rev, close=close)
        box = _both(mp, revolution_box, rev, close=close)
    for a, b in zip(fast, twin, strict=True):
        assert a.dtype == b.dtype == np.float64 and a.shape == b.shape
        assert np.array_equal(a.view(np.int64), b.view(np.int64))
    for got, want in zip(box[0] + box[1], twin[:2] + twin[:2], strict=True):
        assert np.array_equal(got.view(np.int64), want.view(np.int64))


def test_a_solid_of_revolution_marches_the_profile_it_was_given():
    """:class:`~symfruit.core.fits.RevolutionInside` given its :func:`closed_profile` (the candidates hand it the one
    :func:`box_and_profile` made) marches the same rays to the same depths as one that works it out itself."""
    from symfruit.core.fits import RevolutionInside, box_and_profile

    rng = np.random.default_rng(3)
    points = FRUITS["pear"](rng).sample(800, rng) + CENTRE
    rev = fit_revolution_slices(points[points[:, 2] <= np.median(points[:, 2])])
    _, _, t, r = box_and_profile(rev)
    rays = np.column_stack([rng.uniform(-0.1, 0.1, (300, 2)), np.ones(300)])
    given_, own = RevolutionInside(rev, profile=(t, r)), RevolutionInside(rev)
    for a, b in zip(given_.march(rays, 0.3, 0.6, 24), own.march(rays, 0.3, 0.6, 24), strict=True):
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f")


@pytest.mark.parametrize("with_extent", [False, True])
def test_candidates_constrain_their_boxes_as_constrain_box_does(monkeypatch, with_extent):
    """The candidates' boxes by the kernel called straight (:func:`symfruit.core.candidates._constrainer`) are
    :func:`~symfruit.core.candidates.constrain_box`'s, bit for bit, with and without the kernels, for boxes of every
    kind (float64 or not, the silhouette's cone from the seen points or from where the fruit can project)."""
    from symfruit.core.camera import Camera
    from symfruit.core.candidates import _constrainer, constrain_box

    cam = Camera(fx=600.0, fy=610.0, cx=319.5, cy=241.0, width=640, height=480)
    rng = np.random.default_rng(7)
    seen_lo = rng.normal(0, 0.03, 3) + [0, 0, 0.35]
    seen_hi = seen_lo + rng.uniform(0.0, 0.05, 3)
    cone = ((100.0, 120.5, 180.0, 210.0) if with_extent else (90.5, 99.5, 170.5, 201.5), cam)
    pull = 1.0 if with_extent else None
    for kernels_on in (True, False):
        if not kernels_on:
            monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
        for contour in (0.2, 0.7, 1.0):
            constrain = _constrainer(seen_lo, seen_hi, 0.349, cone, contour, pull)
            for _ in range(20):
                lo, hi = seen_lo + rng.normal(0, 0.02, 3), seen_hi + rng.normal(0, 0.02, 3)
                if rng.random() < 0.2:
                    lo, hi = lo.astype(np.float32), hi.astype(np.float32)
                got = constrain(lo, hi)
                want = constrain_box(lo, hi, seen_lo, seen_hi, 0.349, cone=cone, contour=contour, pull=pull)
                for a, b in zip(got, want, strict=True):
                    assert np.array_equal(a.view(np.int64), b.view(np.int64))


# --- stop 41, speedseg41


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("window", [False, True])
def test_the_red_regions_in_one_pass_are_the_twins(seed, window):
    """Red blobs, rings, combs and U shapes (regions whose provisional labels join late, from the right above) over
    random colours and weak specks, whole or a strided window: :func:`_jit.red_regions_once` gives
    :func:`_jit.red_pixels`' pixels and the numpy twin's values and types (``_red_regions`` with
    ``SYMFRUIT_KERNELS=numpy``)."""
    from symfruit.segment.colour import SegmentSettings, _red_regions, _red_tables

    rng = np.random.default_rng(100 + seed)
    h, w = 120, 150
    image = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
    image[rng.random((h, w)) < 0.05] = (200, 40, 30)  # specks, some seeded
    yy, xx = np.mgrid[:h, :w]
    for _ in range(5):
        cy, cx, r = rng.uniform(0, h), rng.uniform(0, w), rng.uniform(4, 25)
        d = (yy - cy) ** 2 + (xx - cx) ** 2
        shape = d <= r * r if rng.random() < 0.5 else (d <= r * r) & (d >= (0.6 * r) ** 2)  # discs and rings
        image[shape] = (int(rng.integers(120, 256)), int(rng.integers(0, 90)), int(rng.integers(0, 90)))
    image[60:62, 10:70] = (190, 30, 30)  # a comb: teeth joined by a bar below them
    image[40:62, 10:70:6] = (190, 30, 30)
    image[20:50, 100] = image[20:50, 130] = (150, 80, 60)  # a U: two arms meeting at the bottom
    image[50, 100:131] = (150, 80, 60)
    c = image[3:117, 2:149:2] if window else image
    s = SegmentSettings()
    low, high = _red_tables(s.red_low, s.red_high, s.dark, s.dark_chroma)
    args = (low, high, float(np.sqrt(3.0)), float(np.tan(np.radians(s.hue_max))))
    once = _jit.red_regions_once(c, *args)
    assert int(once[2]) > 10 and once[6].sum() >= 2
    weak, strong = _jit.red_pixels(c, *args)
    np.testing.assert_array_equal(once[3], weak)
    np.testing.assert_array_equal(once[4], strong)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _red_regions, c, s)
    for a, b in zip(fast, twin, strict=True):
        if isinstance(a, np.ndarray):
            assert a.dtype == b.dtype
            np.testing.assert_array_equal(a, b)
        else:
            assert a == b


def test_the_red_regions_in_one_pass_without_red():
    """A window without a weak pixel: no labels, an empty list of pixels, the background's size alone."""
    from symfruit.segment.colour import SegmentSettings, _red_tables

    s = SegmentSettings()
    low, high = _red_tables(s.red_low, s.red_high, s.dark, s.dark_chroma)
    c = np.zeros((7, 9, 3), np.uint8)
    c[..., 1] = 200
    mask, labels, n, weak, strong, lab, seeded, sizes, rows, cols = _jit.red_regions_once(
        c, low, high, float(np.sqrt(3.0)), float(np.tan(np.radians(s.hue_max)))
    )
    assert n == 0 and not mask.any() and not labels.any() and len(weak) == len(strong) == len(lab) == 0
    assert sizes.tolist() == [0] and seeded.tolist() == [False] and len(rows) == len(cols) == 0


@pytest.mark.parametrize("seed", range(6))
def test_a_found_fruits_claim_is_the_twins(seed):
    """Hulls over a label window partly taken (by a larger fruit, -1, or by numbers), strided as ``out[sl]`` is, some
    mostly inside what is taken, one empty: the same answer, the same pixels set to -1 in the window, the same box
    as :func:`symfruit.core.raster.mask_box` of the freed pixels, with the kernel and with the twin."""
    from symfruit.segment.colour import _claim

    rng = np.random.default_rng(200 + seed)
    image = np.zeros((80, 90), np.int32)
    image[rng.random((80, 90)) < 0.1] = -1
    image[10:40, 20:60] = 3  # a larger fruit over most of the window's upper left
    hulls = [rng.random((50, 60)) < p for p in (0.0, 0.3, 0.9)]
    yy, xx = np.mgrid[:50, :60]
    hulls.append((yy - 25) ** 2 + (xx - 30) ** 2 <= 20**2)
    answers = []
    for hull in hulls:
        got = []
        for env in ("", "numpy"):
            with pytest.MonkeyPatch.context() as mp:
                mp.setenv("SYMFRUIT_KERNELS", env)
                out = image.copy()
                claimed = _claim(out[5:55, 12:72], hull)
                got.append((out, claimed))
        (out_a, a), (out_b, b) = got
        np.testing.assert_array_equal(out_a, out_b)
        assert (a is None) == (b is None)
        if a is not None:
            assert a[0].dtype == b[0].dtype and np.array_equal(a[0], b[0]) and a[1] == b[1]
        answers.append(a is not None)
    assert answers == [True, True, True, False]  # the disc lies mostly under the larger fruit


# --- stop 42, speedreg42


@pytest.mark.parametrize("seed", range(4))
def test_the_pruning_limit_and_the_tightened_stage_are_their_twins(seed):
    """``prune_limit`` is ``surface._limit`` to the bit; the pruned stage, whose bound falls to the frame cost at the
    least running sum after each outline (the outlines costed fewest points first), leaves the twin's shifts with the
    twin's costs written, a subset of those the first bound leaves that holds every shift within the margin of the
    least frame cost; and the search's index is the same as costing every outline at every shift."""
    from symfruit.core import _jit, surface

    rng = np.random.default_rng(seed)
    for upper, slack, count in zip(rng.uniform(0, 30, 50), rng.uniform(0, 1e-8, 50), rng.integers(1, 12, 50),
                                   strict=True):  # fmt: skip
        assert _jit.prune_limit(float(upper), float(slack), int(count)) == surface._limit(upper, slack, int(count))
    reach, trim = 10, 0.7
    outlines = _frame_outlines(seed, reach)
    outlines[-1].__dict__["axes"] = (False, True)  # a one-axis outline among them
    frame, twin = surface._FrameCosts.of(outlines, reach, trim), surface._FrameCosts(outlines, reach, trim)
    assert frame.jit is not None and twin.jit is None
    # fewest points first, then the outlines that tell one axis alone, then the rest (stop 48, regspeed48)
    fewest = np.argsort([len(o.rows) for o in outlines], kind="stable")
    one_axis = [i for i in fewest[1:] if not all(outlines[i].axes)]
    assert len(outlines) - 1 in frame.order[: 1 + len(one_axis)].tolist()  # the one made one-axis above comes early
    rest = [i for i in fewest[1:] if all(outlines[i].axes)]
    assert frame.order.tolist() == [int(fewest[0]), *map(int, one_axis), *map(int, rest)]
    assert np.array_equal(twin.order, frame.order)
    coarse = np.arange(-reach, reach + 1, 2)
    grid = np.stack(np.meshgrid(coarse, coarse, indexing="ij"), -1).reshape(-1, 2).astype(np.int64)
    want = np.array([surface._told(o, grid, reach, trim, False) for o in outlines])
    out = np.full(want.shape, np.nan)
    best = int(frame._stage(grid, 0, -1, 0.0, 0.0, out)[0])
    frame._stage(grid, 1, best, 0.0, 0.0, out)
    upper, slack = float(want[:, best].mean()), 1e-10
    mine, theirs = out.copy(), out.copy()
    alive = frame._stage(grid, 2, best, upper, slack, mine)
    assert np.array_equal(twin._stage(grid, 2, best, upper, slack, theirs), alive)
    assert np.array_equal(mine, theirs, equal_nan=True)
    written = ~np.isnan(mine)
    assert np.array_equal(mine[written], want[written])
    limit = surface._limit(upper, slack, len(outlines))
    first_bound = np.flatnonzero((np.cumsum(want[frame.order], axis=0) <= limit).all(axis=0))
    assert np.isin(alive, first_bound).all()
    means = want.mean(axis=0)
    assert np.isin(np.flatnonzero(means <= means.min() + 1e-9), alive).all()

    def cost(shifts, exact=True):
        return np.mean([surface._told(o, shifts, reach, trim, exact) for o in outlines], axis=0)

    fast = cost(grid, exact=False)
    near = np.flatnonzero(fast <= fast.min() + 2e-10 * (1.0 + float(np.abs(fast).max())))
    full = int(near[np.argmin(cost(grid[near]))]) if len(near) > 1 else int(near[0])
    assert frame.least(grid, cost) == twin.least(grid, cost) == full


@pytest.mark.parametrize("seed", range(6))
def test_trim_kept_is_the_band_test_the_pieces_and_their_holes_by_the_twins(seed, monkeypatch):
    """``trim_kept`` (stop 42): the band's test, the pieces holding a fruit pixel and their holes filled in one call,
    the numpy twins' pixels (``keep[band] = _nearer_fruit(...)``, ``_connected``, ``fill_holes``): ragged discs on a
    noisy image whose band test cuts pieces off and leaves holes, fruit seeds in some pieces, none at all."""
    from symfruit.core import _jit
    from symfruit.core.raster import inner_distance
    from symfruit.core.surface import _colour_features, _connected, _nearer_fruit, fill_holes

    rng = np.random.default_rng(seed)
    h, w = int(rng.integers(30, 90)), int(rng.integers(30, 90))
    yy, xx = np.mgrid[:h, :w]
    mask = np.hypot(yy - h / 2, xx - w / 2) < rng.uniform(8, 0.45 * min(h, w)) + rng.normal(0, 1.5, (h, w))
    color = rng.integers(0, 256, (h, w, 3)).astype(np.uint8)
    inner = inner_distance(mask)
    band_px = float(rng.uniform(2, 5))
    band = mask & (inner <= band_px) | (mask & (rng.random((h, w)) < 0.05))  # a few holes inside too
    fruit = (inner > band_px) & (inner <= 3 * band_px + 1) & (rng.random((h, w)) < (0.0 if seed == 5 else 0.3))
    fc, bc = rng.random((3, 3)), rng.random((2, 3))
    margin = float(rng.uniform(0.5, 1.5))
    out = np.empty((h, w), bool)
    _jit.trim_kept(color, mask, band, fruit, fc, bc, margin, out)
    monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    keep = mask.copy()
    keep[band] = _nearer_fruit(_colour_features(color, band), fc, bc, margin)
    want = fill_holes(_connected(keep, fruit))
    assert np.array_equal(out, want)
    assert (out != keep).any() or seed == 5  # the fill or the pieces changed something


# --- stop 42, speedseg42


@pytest.mark.parametrize("eight", [False, True])
@pytest.mark.parametrize("seed", range(4))
def test_the_shared_labelling_of_set_pixels_is_scipys(seed, eight):
    """:func:`_jit._label_pixels` (the labelling :func:`_jit.label` and :func:`_jit.red_regions_once` share) from the
    flat indices of a mask's set pixels: ``ndimage.label``'s labels and count, on random masks, a U and a comb whose
    provisional labels join late, a one-row and a one-column mask, and no pixel at all."""
    from scipy import ndimage

    rng = np.random.default_rng(420 + seed)
    u = np.zeros((9, 11), bool)
    u[1:8, 2] = u[1:8, 8] = u[7, 2:9] = True  # two arms joined at the bottom: one label for both
    comb = np.zeros((8, 13), bool)
    comb[0:7, 0:13:3] = True
    comb[7, :] = True
    masks = [rng.random((31, 47)) < d for d in (0.1, 0.45, 0.8)] + [u, comb, rng.random((1, 40)) < 0.5]
    masks += [rng.random((40, 1)) < 0.5, np.zeros((5, 6), bool)]
    for mask in masks:
        want, n = ndimage.label(mask, structure=np.ones((3, 3), bool) if eight else None)
        out = np.zeros(mask.shape, np.int32)
        m = _jit._label_pixels(out, np.flatnonzero(mask).astype(np.int64), eight)
        np.testing.assert_array_equal(out, want)
        assert m == n
    assert m == 0 and n == 0  # the last mask: no pixel


def test_the_red_kind_of_every_colour_is_the_twins():
    """:func:`_jit._red_kind` from a pixel's channels and its tables' entries, on every red level with green and
    blue on a grid of 0-255 (and equal to red, one below it): the numpy twin's weak and strong pixels
    (``_red_pixels`` with ``SYMFRUIT_KERNELS=numpy``), 1 for weak alone and 2 for strong."""
    from symfruit.segment.colour import SegmentSettings, _red_pixels, _red_tables

    s = SegmentSettings()
    low, high = _red_tables(s.red_low, s.red_high, s.dark, s.dark_chroma)
    levels = np.unique(np.concatenate((np.arange(0, 256, 15), [1, 2, 41, 254, 255])))
    r, g, b = np.meshgrid(np.arange(256), levels, levels, indexing="ij")
    image = np.stack((r, g, b), axis=-1).reshape(256, -1, 3).astype(np.uint8)
    image[:, :2] = np.stack((np.arange(256), np.arange(256), np.maximum(np.arange(256) - 1, 0)), -1)[:, None]
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        weak, strong = _red_pixels(image, s)
    want = np.zeros(image.shape[:2], np.int64).ravel()
    want[weak] = 1
    want[strong] = 2
    sqrt3, tan_hue = float(np.sqrt(3.0)), float(np.tan(np.radians(s.hue_max)))
    got = [_jit._red_kind(int(p[0]), int(p[1]), int(p[2]), int(low[p[0]]), int(high[p[0]]), sqrt3, tan_hue)
           for p in image.reshape(-1, 3)]  # fmt: skip
    np.testing.assert_array_equal(np.array(got), want)
    assert (want == 1).any() and (want == 2).any()


def test_the_red_pixels_of_every_colour_are_the_twins():
    """:func:`_jit.red_pixels` on every red level with green and blue on a grid of 0-255 (and equal to red, one below
    it), the image whole, a strided window of it and a black one: the numpy twin's weak and strong pixels, in the same
    order; some of each kind, and none of them only where the image is black (stop 65)."""
    from symfruit.segment.colour import SegmentSettings, _red_pixels

    s = SegmentSettings()
    levels = np.unique(np.concatenate((np.arange(0, 256, 15), [1, 2, 41, 254, 255])))
    r, g, b = np.meshgrid(np.arange(256), levels, levels, indexing="ij")
    image = np.stack((r, g, b), axis=-1).reshape(256, -1, 3).astype(np.uint8)
    image[:, :2] = np.stack((np.arange(256), np.arange(256), np.maximum(np.arange(256) - 1, 0)), -1)[:, None]
    for c in (image, image[3:-5, 7:-2], np.zeros((4, 5, 3), np.uint8)):
        with pytest.MonkeyPatch.context() as mp:
            (weak, strong), (weak_twin, strong_twin) = _both(mp, _red_pixels, c, s)
        np.testing.assert_array_equal(weak, weak_twin)
        np.testing.assert_array_equal(strong, strong_twin)
        assert (len(weak) > len(strong) > 0) == (c.any())


def test_the_reflected_index_is_scipys_reflect_mode():
    """:func:`_jit._reflected` for lines of 1-6 values and indices from three lines before to three after: numpy's
    "symmetric" padding (scipy's "reflect": the edge value repeated) of the line's own indices, inside the line the
    index itself."""
    for n in range(1, 7):
        padded = np.pad(np.arange(n), 3 * n, mode="symmetric")
        for i in range(-3 * n, 4 * n):
            assert _jit._reflected(i, n) == padded[i + 3 * n]


# --- stop 42, speedcomp42


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 7))
def test_the_projected_box_is_the_projections_bounds(seed, step):
    """Points with NaN, infinities, a zero depth and ties, every ``step``-th taken: the kernel's pixel box (the
    candidates' silhouette box without occlusion information) is the one of ``Camera.project``'s coordinates to the
    bit, with the kernel and with the twin; a 3-point cloud's known answer."""
    from symfruit import DEFAULT_CAMERA as cam
    from symfruit.core.candidates import _projected_box

    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 200))
    p = rng.normal(size=(n, 3)) * [0.05, 0.05, 0.02] + [0.0, 0.0, 0.4]
    for special in (np.nan, np.inf, -np.inf, 0.0):
        if rng.random() < 0.2:
            p[rng.integers(0, n), rng.integers(0, 3)] = special
    if rng.random() < 0.3:
        p[: n // 2] = p[0]  # ties
    uv = cam.project(p[::step])
    with np.errstate(invalid="ignore"):
        want = np.array([uv[:, 0].min() - 0.5, uv[:, 1].min() - 0.5, uv[:, 0].max() + 0.5, uv[:, 1].max() + 0.5])
    got = _jit.projected_box(p, step, cam.fx, cam.fy, cam.cx, cam.cy)
    assert got.tobytes() == want.tobytes()
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _projected_box, p, step, cam)
    assert np.array(fast).tobytes() == np.array(twin).tobytes() == want.tobytes()
    known = np.array([[0.0, 0.0, 0.5], [0.05, -0.025, 0.5], [-0.1, 0.1, 1.0]])
    f, c = cam.fx, cam.cx
    want = [c - 0.1 * f - 0.5, cam.cy - 0.05 * f - 0.5, c + 0.1 * f + 0.5, cam.cy + 0.1 * f + 0.5]
    assert _jit.projected_box(known, 1, f, f, c, cam.cy).tolist() == want


def test_the_column_bounds_of_points_meet_every_column_in_one_pass():
    """(n, 3) points (the one-pass path) against (n, 3) columns met one at a time (the same array as (n, 4) with a
    column more): the same bounds to the bit, NaN in a column's two bounds alone, infinities kept."""
    p = np.array([[1.0, -2.0, 3.0], [-4.0, np.inf, 0.5], [2.5, 7.0, np.nan], [1.0, -2.5, 0.25]])
    lo, hi, sure = _jit.column_bounds(p)
    assert sure and lo[:2].tolist() == [-4.0, -2.5] and hi[:2].tolist() == [2.5, np.inf]
    assert np.isnan(lo[2]) and np.isnan(hi[2])
    wide = np.column_stack((p, np.ones(4)))  # four columns: the column-by-column path
    lo4, hi4, _ = _jit.column_bounds(wide)
    assert lo.tobytes() == lo4[:3].tobytes() and hi.tobytes() == hi4[:3].tobytes()
    first_nan = np.array([[np.nan, 1.0, 2.0], [1.0, 1.0, 2.0]])  # a NaN first in its column
    lo, hi, _ = _jit.column_bounds(first_nan)
    assert np.isnan(lo[0]) and np.isnan(hi[0]) and lo[1:].tolist() == [1.0, 2.0]


# --- stop 42, scan42


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(2, 20), st.booleans(), st.sampled_from(["first", "last"]))
def test_revolution_box_closes_ends_within_the_fits_rms_as_its_twin(seed, bins, close, end):
    """:func:`symfruit.core.fits.box_and_profile` with the kernel and with its twin on profiles whose end slices fall
    short of the widest by about the fit's RMS (``sqrt(cost)``: some within it, closed by symmetry, some beyond it,
    left as they are), with unseen (NaN) slices: the same profile and box bit for bit."""
    from symfruit.core.fits import Revolution, box_and_profile

    rng = np.random.default_rng(seed)
    direction = rng.normal(size=3)
    direction = direction / np.linalg.norm(direction)
    edges = np.sort(rng.normal(0.0, 0.03, bins + 1))
    radii = np.sort(rng.uniform(0.005, 0.04, bins))
    rms = float(rng.uniform(0.0002, 0.002))
    tail = int(rng.integers(1, 4))
    radii[-tail:] = radii.max() - rng.uniform(0.0, 2.0 * rms, min(tail, bins))  # short by 0-2 RMS
    if end == "first":
        radii = radii[::-1].copy()
    radii[rng.random(bins) < 0.15] = np.nan
    rev = Revolution(rng.normal(0.0, 0.05, 3) + [0, 0, 0.4], direction, edges, radii, rms**2)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, box_and_profile, rev, close=close)
    for a, b in zip(fast, twin, strict=True):
        assert a.dtype == b.dtype == np.float64 and a.shape == b.shape
        assert np.array_equal(a.view(np.int64), b.view(np.int64))


# --- stop 42, speedext42


def _parts_case(seed: int):
    """A window of depths from a few values (steps between them, ties), dropouts, a mask, a join."""
    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(1, 40, 2))
    depth = rng.choice([0.0, 0.5, 0.501, 0.52, 0.6], size=(h, w))
    if rng.random() < 0.5:
        depth = depth + rng.normal(0.0, 0.002, (h, w))
    depth[rng.random((h, w)) < 0.1] = 0.0
    mask = rng.random((h, w)) < rng.uniform(0.3, 1.0)
    return depth, mask, float(rng.choice([0.003, 0.01, 0.05]))


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_the_smooth_parts_kernel_gives_the_twins_labels(seed):
    """smooth_parts against _smooth_parts' twin (ndimage.label's numbering): the same labels, count and type."""
    from symfruit.core.surface import _smooth_parts

    depth, mask, join = _parts_case(seed)
    with pytest.MonkeyPatch.context() as mp:
        (fast, n_fast), (twin, n_twin) = _both(mp, _smooth_parts, depth, mask, join)
    assert n_fast == n_twin and fast.dtype == twin.dtype
    np.testing.assert_array_equal(fast, twin)


def test_the_smooth_parts_kernel_parts_a_step_and_numbers_in_raster_order():
    """Known answer: a plane at 0.5 m with a square at 0.6 m: the square is one part, the plane around it another,
    the pixels either side of the step in neither; the part met first in raster order is 1."""
    depth = np.full((8, 9), 0.5)
    depth[3:6, 5:8] = 0.6
    mask = np.ones((8, 9), bool)
    labels = np.empty((8, 9), np.int32)
    assert _jit.smooth_parts(depth, mask, 0.01, labels) == 2
    assert labels[0, 0] == 1 and labels[4, 6] == 2
    assert labels[4, 4] == 0 and labels[4, 5] == 0 and labels[2, 6] == 0 and labels[3, 6] == 0
    assert (labels == 2).sum() == 1  # the square's one pixel with no neighbour across the step


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_the_smooth_parts_are_ndimage_labels_of_any_shape(seed):
    """smooth_parts' union-find numbering (stop 63, reg63) on a depth without steps (every mask pixel smooth) is
    ndimage.label's 4-connected labelling of the mask: random masks of any density, one row or one column, a
    checkerboard (the most parts), combs and spirals whose branches meet only further down (parts joined late)."""
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(1, 48, 2))
    kind = int(rng.integers(0, 5))
    if kind == 0:
        mask = rng.random((h, w)) < rng.uniform(0.2, 0.9)
    elif kind == 1:
        mask = (np.add.outer(np.arange(h), np.arange(w)) % 2 == 0) | (rng.random((h, w)) < 0.05)
    elif kind == 2:  # a comb: teeth down from the top, joined at the bottom (or not)
        mask = np.zeros((h, w), bool)
        mask[:, :: int(rng.integers(2, 5))] = True
        mask[-1, :] = rng.random() < 0.7
    elif kind == 3:  # a spiral-like maze: rings joined at random gaps
        yy, xx = np.mgrid[0:h, 0:w]
        ring = np.maximum(np.abs(yy - h // 2), np.abs(xx - w // 2)) % 2 == 0
        mask = ring | (rng.random((h, w)) < 0.08)
    else:
        mask = np.zeros((h, w), bool)
        mask[rng.integers(0, h, 4 * (h + w)), rng.integers(0, w, 4 * (h + w))] = True
    if rng.random() < 0.2:
        mask = mask[:1] if rng.random() < 0.5 else mask[:, :1]
    mask = np.ascontiguousarray(mask)
    depth = np.full(mask.shape, 0.5)
    labels = np.full(mask.shape, -7, np.int32)
    count = _jit.smooth_parts(depth, mask, 0.01, labels)
    want, n = ndimage.label(mask)
    assert count == n
    np.testing.assert_array_equal(labels, want)


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_the_filled_windows_are_median_ats_values(seed):
    """filled_windows against the twin's nearest pixels (scipy's feature transform) and median_at's windows: the
    same values in the same places, so the same medians."""
    from scipy import ndimage

    depth, mask, _ = _parts_case(seed)
    ok = mask & (depth > 0)
    if not ok.any():
        ok[0, 0], depth[0, 0] = True, 0.5
    rows, cols = np.nonzero(ok)
    values = np.empty((len(rows), 25))
    _jit.filled_windows(depth, ok, 5, values)
    _, (ri, ci) = ndimage.distance_transform_edt(~ok, return_indices=True)
    filled = depth[ri, ci]
    off = np.arange(5) - 2
    r = np.clip(rows[:, None, None] + off[None, :, None], 0, depth.shape[0] - 1)
    c = np.clip(cols[:, None, None] + off[None, None, :], 0, depth.shape[1] - 1)
    np.testing.assert_array_equal(values, filled[r, c].reshape(len(rows), 25))


@pytest.mark.parametrize("seed", range(3))
def test_the_thin_fronts_median_partition_is_the_twins(seed):
    """thin_front with the kernels and with the twins on a flat sheet 1 cm in front of a cap, noise of 2 mm and a
    join of 15 mm bridging the step (so the parts are found again on the 5 x 5 median, smooth_parts and
    filled_windows both run): the same front and sheet; the sheet is found, the fruit's front behind it."""
    from symfruit.core.surface import thin_front

    rng = np.random.default_rng(seed)
    rr, cc = np.mgrid[0:60, 0:60]
    d2 = (rr - 30.0) ** 2 + (cc - 30.0) ** 2
    mask = d2 <= 27**2
    depth = np.where(mask, 0.6 + d2 * 2e-5, 0.0) + rng.normal(0.0, 0.002, (60, 60))
    sheet = mask & (cc < 25)
    depth[sheet] = 0.59 + rng.normal(0.0, 0.002, int(sheet.sum()))
    depth[~mask] = 0.0
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, thin_front, depth, mask, 600.0, 0.59, 0.02, 0.015, 0.002)
    assert fast is not None and twin is not None
    assert fast[0] == twin[0] and fast[0] > 0.595
    np.testing.assert_array_equal(fast[1], twin[1])
    assert fast[1].sum() > 0.9 * sheet.sum()


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 30), st.integers(1, 30), st.integers(0, 3), st.booleans(),
       st.booleans(), st.integers(0, 5))  # fmt: skip
def test_the_occlusion_at_is_the_occlusion_window_on_its_window(seed, h, w, reach, single, with_others, pad):
    """occlusion_at (whole images read in place, the own depths over the points' box) and occlusion_window (the
    window's images and own depths map) run one pass, _occlusion_pass: the same maps, bit for bit, on the window
    occlusion_at picks; and occlusion_projected without a band, of points that project to the same pixels (a camera
    at the image's corner, focal length 300), is occlusion_at."""
    rng = np.random.default_rng(seed)
    big_h, big_w = h + 10, w + 12
    n = int(rng.integers(1, max(2, h * w // 4)))
    uv = np.stack((rng.integers(0, w, n) + 5.2, rng.integers(0, h, n) + 4.7), axis=1).astype(np.float64)
    points = np.zeros((n, 3))
    points[:, 2] = rng.choice([0.5, 0.51, 0.52, 0.53], n)
    depth = rng.choice([0.0, np.nan, 0.49, 0.5, 0.505, 0.51, 0.52, 0.53, 0.6], (big_h, big_w))
    depth = depth.astype(np.float32 if single else np.float64)
    mask = rng.random((big_h, big_w)) < 0.2
    others = rng.random((big_h, big_w)) < 0.3 if with_others else np.zeros((0, 0), bool)
    steps = _steps_within(reach)
    found, u0, v0, hidden, seen = _jit.occlusion_at(uv, points, pad, depth, mask, others, 0.005, steps)
    assert found
    hh, ww = hidden.shape
    own_z = np.full((hh, ww), np.inf)
    np.minimum.at(own_z, (np.rint(uv[:, 1]).astype(int) - v0, np.rint(uv[:, 0]).astype(int) - u0), points[:, 2])
    hid, sn = np.empty((hh, ww), bool), np.empty((hh, ww))
    win = (slice(v0, v0 + hh), slice(u0, u0 + ww))
    _jit.occlusion_window(np.ascontiguousarray(depth[win]), np.ascontiguousarray(mask[win]), own_z,
                          np.ascontiguousarray(others[win]) if with_others else others, 0.005, steps,
                          float(points[:, 2].min()), float(points[:, 2].max()), hid, sn)  # fmt: skip
    assert np.array_equal(hid, hidden) and sn.tobytes() == seen.tobytes()
    # x and y to project at uv (a few ulps off at most: rint takes the same pixel, uv being 0.2 or 0.3 off a whole one)
    seen_from = np.column_stack((uv * points[:, 2:] / 300.0, points[:, 2]))
    edge = _jit.occlusion_projected(seen_from, 300.0, 300.0, 0.0, 0.0, pad, depth, mask, others, 0.005, steps, 0,
                                    True, 300.0)  # fmt: skip
    assert edge[:3] == (found, u0, v0) and np.array_equal(edge[3], hidden) and edge[4].tobytes() == seen.tobytes()


# --- stop 43, speedext43


def test_the_helpers_called_in_loops_are_inlined():
    """The small helpers kernels call inside their loops with arrays are inlined at numba's level (each call paid the
    arrays' reference counts): ``inline="always"`` on every one."""
    for name in ("_scatter", "_nearest_centre", "_count_below", "_leaf_share", "_smallest_mean_at", "_envelope"):
        assert getattr(_jit, name).targetoptions.get("inline") == "always", name


@pytest.mark.parametrize("seed", range(4))
def test_the_inlined_nearest_centre_keeps_the_twins_clusters_and_ties(seed):
    """kmeans, nearer_fruit, trim_separation and trim_band (all through the inlined _nearest_centre) against the
    numpy twins on colour features with repeated rows and a repeated centre (a tie: the first centre wins): the same
    centres, pixels and counts, bit for bit."""
    from symfruit.core.surface import _colour_features, _kmeans, _nearer_fruit

    rng = np.random.default_rng(seed)
    color = rng.integers(0, 256, (30, 40, 3)).astype(np.uint8)
    color[::3, ::2] = color[0, 0]  # repeated features
    band = rng.random((30, 40)) < 0.4
    mask = band | (rng.random((30, 40)) < 0.3)
    x = _colour_features(color, band)
    c = x[rng.choice(len(x), 3, replace=False)].copy()
    c[2] = c[0]  # two equal centres: the first is every such row's
    assert _jit.kmeans(x, c, 5).tobytes() == _kmeans(x, c, 5).tobytes()
    fc, bc = x[:2].copy(), np.concatenate((x[:1], x[5:7]))
    for margin in (1.0, 1.3):
        near = _jit.nearer_fruit(x, fc, bc, margin)
        np.testing.assert_array_equal(near, _nearer_fruit(x, fc, bc, margin))
        out = np.empty((30, 40), bool)
        _jit.trim_band(color, mask, band, fc, bc, margin, out)
        expected = mask.copy()
        expected[band] = near
        np.testing.assert_array_equal(out, expected)
    ring = x[::-1].copy()
    n_fruit, n_ring = _jit.trim_separation(x, ring, fc, bc)
    assert n_fruit == int(_nearer_fruit(x, fc, bc, 1.0).sum())
    assert n_ring == int((~_nearer_fruit(ring, fc, bc, 1.0)).sum())


def test_the_inlined_count_below_is_searchsorted():
    """_count_below is np.searchsorted on either side, ties and the ends included."""
    z = np.array([0.5, 0.5, 0.6, 0.7, 0.7, 0.7, 0.9])
    for x in (0.4, 0.5, 0.55, 0.7, 0.9, 1.0):
        assert _jit._count_below(z, x, False) == np.searchsorted(z, x, "left")
        assert _jit._count_below(z, x, True) == np.searchsorted(z, x, "right")


@pytest.mark.parametrize("seed", range(3))
def test_the_inlined_leaf_share_keeps_fruit_depths_leaf_test(seed, monkeypatch):
    """fruit_depth with leaf-green pixels (the inlined _leaf_share and _count_below) against its twin: a leaf's peak
    in front of the fruit passed over, the same front and radius, bit for bit."""
    from symfruit.core.surface import fruit_depth

    rng = np.random.default_rng(seed)
    leaf_z = rng.normal(0.50, 0.002, 300)
    fruit_z = rng.normal(0.56, 0.004, 500)
    values = np.round(np.concatenate((leaf_z, fruit_z, [0.0, np.nan])), 3)  # whole millimetres: ties
    leafy = np.zeros(len(values), bool)
    leafy[: len(leaf_z)] = rng.random(len(leaf_z)) < 0.9
    fast, twin = _both(monkeypatch, fruit_depth, values, 30.0, 600.0, noise=0.002, leafy=leafy)
    assert fast == twin
    assert fast[0] > 0.54  # the leaf in front passed over


def test_the_inlined_scatter_and_smallest_mean_on_whole_numbers():
    """_scatter (neighbour_covariances) and _smallest_mean_at (smallest_mean) on whole numbers, where every sum is
    exact: the scatter matrix about the mean, and the mean of the keep smallest with the keep-th (ties included)."""
    pts = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 4.0, 0.0], [2.0, 4.0, 8.0]])
    out = np.empty((3, 3))
    _jit._scatter(pts, np.array([3, 0, 1, 2]), 4, out)
    dev = pts - pts.mean(axis=0)
    np.testing.assert_array_equal(out, dev.T @ dev)
    small, large = _jit.neighbour_covariances(pts, 1, 4, 4)
    np.testing.assert_array_equal(small[0], dev.T @ dev / 4)
    np.testing.assert_array_equal(large[3], dev.T @ dev / 4)
    x = np.array([5.0, 1.0, 3.0, 3.0, 9.0, 3.0, 0.0])
    a, b = np.empty(7), np.empty(7)
    for keep, mean, kth in ((1, 0.0, 0.0), (3, 4.0 / 3.0, 3.0), (4, 7.0 / 4.0, 3.0), (6, 15.0 / 6.0, 5.0)):
        assert _jit._smallest_mean_at(x, keep, a, b) == (mean, kth)
        assert _jit.smallest_mean(x, keep, a, b) == mean


@pytest.mark.parametrize("seed", range(5))
def test_the_inlined_envelope_is_the_least_parabola(seed):
    """_envelope (outline_maps' and distance's rows) against the brute-force least (u - i)^2 + f[i] on whole
    numbers: equal."""
    rng = np.random.default_rng(seed)
    for w in (1, 2, 7, 40):
        f = rng.integers(0, 50, w).astype(np.int64) ** 2
        s, t, d2 = (np.empty(w, np.int64) for _ in range(3))
        _jit._envelope(f, w, s, t, d2)
        u = np.arange(w)
        np.testing.assert_array_equal(d2, ((u[:, None] - u[None, :]) ** 2 + f[None, :]).min(axis=1))


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 25), st.integers(1, 25), st.booleans())
def test_the_thin_counts_are_the_twins(seed, h, w, view):
    """thin_counts against _thin_counts on depths from a few values (ties between neighbours, a camera's repeated
    pixels), no depth, NaN and infinities, on an array or a strided view of one: the same ok pixels, counts and front
    pixels."""
    from symfruit.core.surface import _thin_counts

    rng = np.random.default_rng(seed)
    depth = rng.choice([0.0, np.nan, np.inf, -0.1, 0.5, 0.501, 0.505, 0.52, 0.6], (h + 3, w + 2))
    mask = rng.random((h + 3, w + 2)) < 0.7
    if view:
        depth, mask = depth[1 : h + 1, 2:], mask[1 : h + 1, 2:]
    front, join = float(rng.choice([0.5, 0.505])), float(rng.choice([0.0, 0.004, 0.02]))
    ok = np.empty(depth.shape, bool)
    counts, rows, cols = _jit.thin_counts(depth, mask, front, join, ok)
    twin_ok, twin_counts, twin_rows, twin_cols = _thin_counts(depth, mask, front, join)
    np.testing.assert_array_equal(ok, twin_ok)
    np.testing.assert_array_equal(counts, twin_counts)
    np.testing.assert_array_equal(rows, twin_rows)
    np.testing.assert_array_equal(cols, twin_cols)


def test_the_thin_counts_known_answer():
    """A 2 x 3 mask with depth everywhere, the left column repeated down and the top row's first two equal: 6 pixels,
    3 vertical pairs (1 equal), 4 horizontal pairs (1 equal); the pixels within 1.5 mm of 0.5 m."""
    depth = np.array([[0.5, 0.5, 0.52], [0.5, 0.501, 0.53]])
    ok = np.empty((2, 3), bool)
    counts, rows, cols = _jit.thin_counts(depth, np.ones((2, 3), bool), 0.5, 0.0015, ok)
    assert ok.all() and counts.tolist() == [6, 3, 1, 4, 1]
    assert rows.tolist() == [0, 0, 1, 1] and cols.tolist() == [0, 1, 0, 1]


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 25), st.integers(1, 25), st.integers(1, 6))
def test_the_lag_differences_are_the_twins(seed, h, w, lag):
    """lag_differences against _lag_differences (medians from a strided column, as thin_front's partition gives
    them; zeros and negative values among them): the same smoothed image and differences, bit for bit."""
    from symfruit.core.surface import _lag_differences

    rng = np.random.default_rng(seed)
    ok = rng.random((h, w)) < 0.6
    mask = ok | (rng.random((h, w)) < 0.2)
    table = rng.choice([0.0, -0.01, 0.5, 0.5 + 1e-9, 0.51, 0.6], (int(ok.sum()), 3))
    smooth = np.full((h, w), np.nan)
    diff = _jit.lag_differences(table[:, 1], ok, mask, lag, smooth)
    twin_smooth, twin_diff = _lag_differences(table[:, 1], ok, mask, lag)
    assert smooth.tobytes() == twin_smooth.tobytes() and diff.tobytes() == twin_diff.tobytes()


# --- stop 43, speedseg43


def test_the_ground_colour_test_of_every_colour_is_the_twins():
    """Every colour on a grid of each channel's levels (0-255 in steps of 5, and the levels about the tests'
    bounds): :func:`_jit.ground_pixels` (each pixel's :func:`_jit._is_ground`, whole numbers, no branch) gives the
    twin's pixels (``_ground`` with ``SYMFRUIT_KERNELS=numpy``), some ground colour and some not."""
    from symfruit.segment.colour import _ground

    levels = np.unique(np.concatenate((np.arange(0, 256, 5), [39, 40, 41, 42, 127, 128, 254])))
    r, g, b = np.meshgrid(levels, levels, levels, indexing="ij")
    image = np.stack((r, g, b), axis=-1).reshape(len(levels), -1, 3).astype(np.uint8)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _ground, image)
    np.testing.assert_array_equal(fast, twin)
    assert 0 < int(twin.sum()) < twin.size // 2
    assert _jit._is_ground(200, 190, 40, 40, 90, 40) and not _jit._is_ground(60, 140, 50, 40, 90, 40)


@pytest.mark.parametrize("taken", [0.0, 0.6, 1.0])
def test_the_blush_rim_beside_another_fruits_ground_colour_is_the_twins(taken):
    """A blush crescent before ground colour in front of it, that ground colour a share ``taken`` of another fruit's
    (``owner`` 2: neither the ring nor the other pixels): ``_blush_rim`` with the kernel (each pixel beside the part
    tested there alone) and with the twin, the same window, mask and depths; none of it taken, the ring joins the
    part, all of it, the part stays as it was."""
    from symfruit.segment.colour import SegmentSettings, _blush_rim, _Depth

    rng = np.random.default_rng(43)
    hull, z, color, owner = _blush_scene(rng, True)
    h, w = hull.shape
    xx = np.mgrid[:h, :w][1]
    ground = (color == (200, 190, 40)).all(axis=2)
    owner[ground & (xx < taken * w + (taken == 1.0))] = 2
    rows, cols = np.nonzero(hull)
    sl = (slice(rows.min(), rows.max() + 1), slice(cols.min(), cols.max() + 1))
    part = hull[sl]
    z_part = z[sl][part & (z[sl] > 0)]
    s = SegmentSettings(round_fruit=True, ground_colour=True)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _blush_rim, sl, part, z_part, _Depth(z), color, s, owner, 1)
    assert fast[0] == twin[0]
    np.testing.assert_array_equal(fast[1], twin[1])
    np.testing.assert_array_equal(fast[2].view(np.uint64), twin[2].view(np.uint64))
    if taken in (0.0, 1.0):  # none taken: the ring in front is taken; all of it another's: the part as it was
        assert (fast[0] == sl) == (taken == 1.0)


@pytest.mark.parametrize("n", [1, 2, 5, 8, 9, 30, 200])
def test_the_correlation_along_views_is_scipys_on_lines_of_every_length(n):
    """:func:`_jit._correlate_line` (every value's products at once along views of its buffer) against scipy's
    ``correlate1d`` (mode "reflect"): the same values bit for bit, for lines shorter than, as long as and longer than
    the weights, symmetric (the Gaussian's of sigma 2, 17 weights) or not (even and odd counts)."""
    from scipy import ndimage

    from symfruit.segment.colour import _gaussian_weights

    rng = np.random.default_rng(n)
    line = rng.normal(size=n) * 0.37 + 1.3
    for weights, symmetric in ((_gaussian_weights(2.0)[0], True), (rng.normal(size=4), False),
                               (rng.normal(size=7), False)):  # fmt: skip
        out = np.empty(n)
        _jit._correlate_line(line, weights, symmetric, out)
        scipy = ndimage.correlate1d(line, weights, mode="reflect")
        np.testing.assert_array_equal(out.view(np.uint64), scipy.view(np.uint64))


# --- stop 43, speedcomp43 ---------------------------------------------------------------------------------------


def _cloud(kind: int, n: int, rng: np.random.Generator) -> np.ndarray:
    """A test cloud for the grid's neighbourhoods: 0 a blob, 1 a lattice's whole millimetres (ties everywhere),
    2 a sphere's near cap, 3 a depth image's pixel grid on three depth steps, 4 points on a line (or one point
    repeated), 5 two blobs a metre apart; a tenth of the points repeated (ties at distance 0)."""
    if kind == 0:
        pts = rng.normal(size=(n, 3)) * rng.uniform(0.001, 0.1)
    elif kind == 1:
        pts = rng.integers(0, int(rng.integers(1, 12)), size=(n, 3)).astype(np.float64) * 0.001
    elif kind == 2:
        v = rng.normal(size=(n, 3))
        v /= np.linalg.norm(v, axis=1, keepdims=True)
        v[:, 2] = -np.abs(v[:, 2])
        pts = v * 0.04 + np.array([0.01, -0.02, 0.5])
    elif kind == 3:
        k = int(np.sqrt(n)) + 1
        u, w = np.meshgrid(np.arange(k), np.arange(k))
        pts = np.stack((u.ravel()[:n] * 0.001, w.ravel()[:n] * 0.001, 0.5 + 1e-4 * rng.integers(0, 3, n)), axis=1)
    elif kind == 4:
        pts = np.zeros((n, 3))
        pts[:, 0] = rng.uniform(0.0, 0.1, n) if rng.random() < 0.8 else 0.0
    else:
        pts = rng.normal(size=(n, 3)) * 0.001 + rng.choice([0.0, 1.0], size=(n, 1))
    pts[: n // 10] = pts[n // 10 : 2 * (n // 10)]
    return np.ascontiguousarray(pts)


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 5), st.integers(3, 1200), st.integers(1, 40), st.integers(1, 40),
       st.booleans())  # fmt: skip
def test_grid_covariances_are_the_brute_forces_to_the_bit(seed, kind, n, step, large, nan):
    """The grid's neighbourhoods (grid_covariances, the noise measure's) are the brute force's
    (neighbour_covariances), bit for bit, on blobs, lattices, caps, pixel grids, lines and far-apart clusters,
    and within rounding the numpy twin's; a NaN coordinate sends the call to the brute force."""
    from symfruit.core.fits import _neighbour_covariances

    rng = np.random.default_rng(seed)
    pts = _cloud(kind, n, rng)
    if nan:
        pts[int(rng.integers(n)), int(rng.integers(3))] = np.nan
    large = min(large, n)
    small = int(rng.integers(1, large + 1))
    grid = _jit.grid_covariances(pts, step, small, large)
    brute = _jit.neighbour_covariances(pts, step, small, large)
    for a, b in zip(grid, brute, strict=True):
        assert a.shape == b.shape == (len(pts[::step]), 3, 3)
        assert a.tobytes() == b.tobytes()
    if not nan and large >= 2:
        twin = _neighbour_covariances(pts, step, small, large)
        for a, b in zip(grid, twin, strict=True):
            np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-15 * float(np.abs(b).max()))


def test_grid_covariances_many_ties_at_the_limit_are_the_brute_forces():
    """A lattice of eight places, each held by about 120 points (every query's neighbours all at distance 0, over four
    times ``large`` of them within the limit: the insertion sort's path; revol60) and a noisy cap (the places counted:
    the other path): the brute force's neighbourhoods, bit for bit."""
    rng = np.random.default_rng(5)
    lattice = rng.integers(0, 2, size=(1000, 3)).astype(np.float64) * 0.001
    cap = _cloud(2, 1000, rng) + rng.normal(scale=5e-4, size=(1000, 3))
    for pts, large in ((lattice, 5), (cap, 30)):
        grid = _jit.grid_covariances(pts, 7, 3, large)
        brute = _jit.neighbour_covariances(pts, 7, 3, large)
        for a, b in zip(grid, brute, strict=True):
            assert a.tobytes() == b.tobytes()


def test_grid_covariances_known_neighbourhoods_on_a_line():
    """Points 1 mm apart on x (a grid of seven cells along it): the three nearest of the first point are the first
    three (variance 2/3 mm^2 along x), of an inner point itself and its two sides (the same); two nearest of the
    first: itself and the next (1/4 mm^2)."""
    pts = np.zeros((10, 3))
    pts[:, 0] = np.arange(10) * 0.001
    small, large = _jit.grid_covariances(pts, 4, 2, 3)
    assert small.shape == large.shape == (3, 3, 3)
    for q in range(3):
        assert large[q, 0, 0] == pytest.approx(2e-6 / 3, rel=1e-12)
        assert np.count_nonzero(large[q]) == 1
    assert small[0, 0, 0] == pytest.approx(0.25e-6, rel=1e-12)
    assert small[1, 0, 0] == pytest.approx(0.25e-6, rel=1e-12)  # 4 mm: 3 and 4 or 4 and 5, either a 1 mm pair


def test_noise_measures_read_the_grids_neighbourhoods():
    """noise_measures (the default method's call) on a noisy cap: the same ratio and noise, to the bit, as the least
    eigenvalues' medians of the brute force's neighbourhoods (the kernel's own arithmetic on them)."""
    rng = np.random.default_rng(3)
    pts = _cloud(2, 1000, rng) + rng.normal(scale=5e-4, size=(1000, 3))
    step, small, large = 8, 8, 30
    ratio, noise = _jit.noise_measures(pts, step, small, large)
    cov_small, cov_large = _jit.neighbour_covariances(pts, step, small, large)
    a = np.empty((3, 3))
    least_small = np.median([_jit.least_eigenvalue(c, a) for c in cov_small])
    least_large = np.median([_jit.least_eigenvalue(c, a) for c in cov_large])
    assert noise == np.sqrt(max(least_small, 0.0))
    assert ratio == np.sqrt(max(least_large, 0.0)) / max(noise, 1e-15)
    assert 0.0 < noise < 1e-3 and ratio > 1.0


# --- stop 44, revol44


@given(st.integers(0, 2**32 - 1), st.sampled_from([0.7, 0.85, 1.25]), st.booleans())
def test_a_squashed_revolution_marches_and_boxes_as_its_twins(seed, ratio, close):
    """Issue 18, stop 44: a solid of revolution squashed along the line of sight (elliptic sections) is marched by
    the kernel on its rays and axis mapped into the circular solid; the numpy twin marches its inside test. The same
    hits and depths; :func:`box_and_profile` (the kernel's profile, the squashed rings' box) is its twin's."""
    import dataclasses

    from symfruit.core.agreement import march
    from symfruit.core.fits import RevolutionInside, box_and_profile

    circles, visible = _lemon_revolution(seed % 4)
    centre = visible.mean(axis=0)
    rev = dataclasses.replace(circles, ratio=ratio, deep=centre / np.linalg.norm(centre))
    rng = np.random.default_rng(seed)
    rays = np.c_[centre[:2] / centre[2] + rng.normal(0.0, 0.08, (200, 2)), np.ones(200)]
    z0, z1 = float(visible[:, 2].min()) - 0.03, float(visible[:, 2].max()) + 0.05
    inside = RevolutionInside(rev, close=close)
    marched = inside.march(rays, z0, z1, steps=24)
    assert marched is not None
    hit, depth = marched
    hit_twin, depth_twin = march(inside, rays, z0, z1, steps=24)
    assert np.array_equal(hit, hit_twin) and hit.any() and not hit.all()
    np.testing.assert_allclose(depth[hit], depth_twin[hit], atol=1e-12)
    plain = march(RevolutionInside(circles, close=close), rays, z0, z1, steps=24)
    assert not np.array_equal(plain[1][hit], depth[hit])  # the squash moved the surface
    mp = pytest.MonkeyPatch()
    try:
        fast, twin = _both(mp, box_and_profile, rev, close=close)
    finally:
        mp.undo()
    for a, b in zip(fast, twin, strict=True):
        np.testing.assert_array_equal(a, b)


# --- stop 44, speedcand44


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 10_000), st.integers(1, 400), st.sampled_from(["cracks", "normal", "same", "nan"]))
def test_conic_design_is_its_twins_to_the_bit(seed, m, kind):
    """The outline ellipse's design (core.raster.outline_cone's first step) against its numpy twin byte for byte:
    crack midpoints (half-integers, as outline_cone reads them), scattered pixels, one repeated point (scale 1)
    and a NaN."""
    from symfruit.core.raster import _conic_design

    rng = np.random.default_rng(seed)
    if kind == "cracks":
        pts = rng.integers(0, 640, size=(m, 2)) + rng.choice([0.0, 0.5], size=(m, 2))
    elif kind == "same":
        pts = np.tile(rng.normal(size=(1, 2)) * 300.0, (m, 1))
    else:
        pts = rng.normal(size=(m, 2)) * 10.0 ** rng.integers(-3, 4) + 320.0
        if kind == "nan":
            pts[rng.integers(m), rng.integers(2)] = np.nan
    got, twin = _jit.conic_design(pts), _conic_design(pts)
    assert type(got[1]) is float and (got[1] == twin[1] or (np.isnan(got[1]) and np.isnan(twin[1])))
    for a, b in zip((got[0], got[2], got[3]), (twin[0], twin[2], twin[3]), strict=True):
        assert a.shape == b.shape and a.tobytes() == b.tobytes()


def test_conic_design_known_values():
    """Four points on a square about (10, 20) at distance sqrt(2): mean (10, 20), scale sqrt(2), the designs of
    (+-1, +-1) / sqrt(2); a single point: scale 1 and the designs of the origin."""
    pts = np.array([[9.0, 19.0], [11.0, 19.0], [9.0, 21.0], [11.0, 21.0]])
    mean, scale, d1, d2 = _jit.conic_design(pts)
    assert mean.tolist() == [10.0, 20.0] and scale == np.sqrt(2.0)
    x, y = (pts[:, 0] - 10.0) / np.sqrt(2.0), (pts[:, 1] - 20.0) / np.sqrt(2.0)
    assert d1.tolist() == np.stack((x * x, x * y, y * y), axis=1).tolist()
    assert d2.tolist() == np.stack((x, y, np.ones(4)), axis=1).tolist()
    mean, scale, d1, d2 = _jit.conic_design(np.array([[3.0, 4.0]]))
    assert mean.tolist() == [3.0, 4.0] and scale == 1.0 and d1.tolist() == [[0.0, 0.0, 0.0]]
    assert d2.tolist() == [[0.0, 0.0, 1.0]]


# --- stop 44, speedocc44


def _overshoot_case(seed: int, wide: bool):
    """A window for overshoot's maps: a disc-like mask (or random pixels), points' pixels on its inner part (some
    outside the mask, repeated pixels with other depths: ties and minima), the depth a cap with steps, dropouts
    (0, NaN, inf), pixels in front and behind; float32 or float64, a strided view or not."""
    rng = np.random.default_rng(seed)
    h, w = int(rng.integers(1, 40)), int(rng.integers(1, 40))
    rr, cc = np.mgrid[:h, :w]
    r0, c0, rad = rng.uniform(0, h), rng.uniform(0, w), rng.uniform(1, 20)
    dist = np.hypot(rr - r0, cc - c0)
    own = dist < rad if rng.random() < 0.8 else rng.random((h, w)) < 0.5
    inner = np.flatnonzero((dist < rad * rng.uniform(0.2, 1.1)).ravel() | (rng.random(h * w) < 0.05))
    n = int(rng.integers(1, 3 * max(len(inner), 1) + 1))
    at = rng.choice(inner, size=n) if len(inner) else rng.integers(0, h * w, size=n)
    rows, cols = (at // w).astype(np.intp), (at % w).astype(np.intp)
    z = np.round(1.0 + 0.002 * dist.ravel()[at] + rng.normal(scale=0.002, size=n), 3)
    depth = np.round(1.0 + 0.002 * dist + rng.choice([-0.05, 0.0, 0.0, 0.003, 0.2], size=(h, w)), 3)
    drop = rng.random((h, w))
    depth[drop < 0.2] = 0.0
    depth[(drop >= 0.2) & (drop < 0.25)] = np.nan
    depth[(drop >= 0.25) & (drop < 0.27)] = np.inf
    depth = depth.astype(rng.choice([np.float32, np.float64]))
    if wide:  # a view of a wider image, as overshoot reads the frame's depth
        big = np.zeros((h, 2 * w + 3), depth.dtype)
        big[:, 3::2] = depth
        depth = big[:, 3::2]
    return own, depth, rows, cols, z, float(rng.choice([0.0, 0.002, 0.005])), int(rng.integers(0, 9))


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_overshoot_band_is_the_twins(seed, wide):
    """overshoot_band (overshoot's maps: the own depths, the band, what lies ahead, the band's, the spread's and the
    beyond pixels' counts) is its numpy twin's, bit for bit, on windows with ties, dropouts, NaN and inf depth,
    float32 and strided depth, any reach."""
    from symfruit.core.occlusion import _overshoot_band

    own, depth, rows, cols, z, tolerance, reach = _overshoot_case(seed, wide)
    h, w = own.shape
    maps = [(np.empty((h, w)), np.empty((h, w), bool), np.empty((h, w), bool)) for _ in range(2)]
    got = _jit.overshoot_band(own, depth, rows, cols, z, tolerance, reach, *maps[0])
    want = _overshoot_band(own, depth, rows, cols, z, tolerance, reach, *maps[1])
    assert got == want
    for a, b in zip(maps[0], maps[1], strict=True):
        assert a.tobytes() == b.tobytes()


def test_overshoot_band_known_answer():
    """A 1 x 7 row: points at columns 2 and 3 (depths 1.0 and 0.9, the nearer twice at column 3); the mask columns
    0-5. Column 1 (depth 0.95) is beyond the points with depth: nearer than its nearest point pixel's (1.0) but not
    by the tolerance, a spread pixel; column 0 (0.5) lies ahead; column 4 (0) holds none; column 5 (0.895): its
    nearest point pixel is column 3 (0.9), within reach 2 also 0.9, so not ahead by 0.01 but nearer: spread."""
    own = np.array([[1, 1, 1, 1, 1, 1, 0]], bool)
    depth = np.array([[0.5, 0.95, 1.0, 0.9, 0.0, 0.895, 0.7]])
    rows, cols = np.zeros(3, np.intp), np.array([2, 3, 3], np.intp)
    z = np.array([1.0, 0.95, 0.9])
    own_z, band, ahead = np.empty((1, 7)), np.empty((1, 7), bool), np.empty((1, 7), bool)
    assert _jit.overshoot_band(own, depth, rows, cols, z, 0.01, 2, own_z, band, ahead) == (3, 2, 4)
    assert np.array_equal(own_z[0], [np.inf, np.inf, 1.0, 0.9, np.inf, np.inf, np.inf])
    assert np.array_equal(band[0], [1, 1, 0, 0, 0, 1, 0])
    assert np.array_equal(ahead[0], [1, 0, 0, 0, 0, 0, 0])


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_peel_is_the_twins_propagation(seed):
    """peel (a flood fill from the mask's border through the pixels to drop) gives scipy's binary_propagation's
    pixels (occlusion._peel), on random masks and drops, rings and holes included."""
    from symfruit.core.occlusion import _peel

    rng = np.random.default_rng(seed)
    h, w = int(rng.integers(1, 30)), int(rng.integers(1, 30))
    own = rng.random((h, w)) < rng.uniform(0.3, 1.0)
    drop = own & (rng.random((h, w)) < rng.uniform(0.1, 0.9))
    out = np.empty((h, w), bool)
    _jit.peel(own, drop, out)
    assert np.array_equal(out, _peel(own, drop))


def test_peel_keeps_a_pocket_inside():
    """A full 7 x 7 mask: a ring on its border and a pocket at its centre, apart; the ring is peeled, the pocket (no
    pixel of it on the border, none joined to one) stays."""
    own = np.ones((7, 7), bool)
    drop = np.zeros((7, 7), bool)
    drop[0, :] = drop[:, 0] = True
    drop[3, 3] = True
    out = np.empty((7, 7), bool)
    _jit.peel(own, drop, out)
    want = drop.copy()
    want[3, 3] = False
    assert np.array_equal(out, want)


# --- stop 44, speedseg44


def _polygon_masks(rng, n):
    """``n`` masks whose hulls a segmenter meets: noisy discs and ellipses (5-400 pixels across), sparse specks, single
    rows and columns, a few scattered pixels."""
    for t in range(n):
        h, w = (int(v) for v in rng.integers(1, 60 if t % 5 else 400, 2))
        yy, xx = np.mgrid[:h, :w]
        kind = t % 4
        if kind == 0:
            cy, cx = rng.random(2) * (h, w)
            r = rng.uniform(0.05, 1.0) * max(h, w) * 0.5
            mask = ((yy - cy) ** 2 * rng.uniform(0.3, 3.0) + (xx - cx) ** 2 <= r * r) & (rng.random((h, w)) < 0.9)
        elif kind == 1:
            mask = rng.random((h, w)) < rng.random() * 0.2
        elif kind == 2:
            mask = np.zeros((h, w), bool)
            mask[rng.integers(0, h, 4), rng.integers(0, w, 4)] = True
        else:
            mask = np.zeros((h, w), bool)
            if t % 8 == 3:
                mask[int(rng.integers(0, h)), :] = rng.random(w) < 0.5
            else:
                mask[:, int(rng.integers(0, w))] = rng.random(h) < 0.5
        yield mask


@pytest.mark.parametrize("seed", range(4))
def test_the_hull_fill_is_pillows(seed):
    """:func:`_jit.polygon_fill` (Pillow's scan-line fill, written out) gives Pillow's pixels: ``_hull_mask`` with the
    kernel and with the twin (Pillow's drawing, ``SYMFRUIT_KERNELS=numpy``) on 600 masks' hulls, the same pixels; and
    on polygons of any whole-number vertices (any order, repeated vertices, horizontal runs, partly or wholly off the
    image), the kernel over an empty mask against ``_fill_polygon``."""
    from symfruit.segment.colour import _fill_polygon, _hull_mask, _hull_vertices, _pillow_fill

    if not _pillow_fill():
        pytest.skip("a Pillow older than 12.1 fills polygons otherwise (the kernel is not used with it)")
    rng = np.random.default_rng(seed)
    hulls = 0
    for mask in _polygon_masks(rng, 600):
        vertices = _hull_vertices(mask)
        with pytest.MonkeyPatch.context() as mp:
            fast, twin = _both(mp, _hull_mask, vertices, mask)
        np.testing.assert_array_equal(fast, twin)
        hulls += vertices is not None and int(twin.sum()) > int(mask.sum())
    assert hulls > 200
    for t in range(600):
        h, w = (int(v) for v in rng.integers(1, 40, 2))
        vertices = rng.integers(-10, 50, (int(rng.integers(2, 9)), 2)).astype(np.float64)
        if t % 3 == 0:
            vertices[:, 1] = np.round(vertices[:, 1] / 8) * 8  # horizontal edges, some in a row
        if t % 5 == 0:
            vertices[1] = vertices[0]
        fast = _jit.polygon_fill(vertices, np.zeros((h, w), bool))
        np.testing.assert_array_equal(fast, _fill_polygon(vertices, (h, w)))


def test_the_hull_fill_known_answers():
    """The doctest's right triangle (15 pixels: the legs and the hypotenuse included); a thin sliver's corner, where
    Pillow joins a corner's two crossings to the next row's (rows 6 and 7 of the triangle (24, 6), (33, 10), (36, 12):
    pixels 24-25, then 26); a vertex that is not a whole number: no fill (the caller's Pillow draws it)."""
    tri = np.array([[0.0, 0.0], [4.0, 0.0], [0.0, 4.0]])
    assert int(_jit.polygon_fill(tri, np.zeros((5, 5), bool)).sum()) == 15
    sliver = _jit.polygon_fill(np.array([[24.0, 6.0], [33.0, 10.0], [36.0, 12.0]]), np.zeros((13, 41), bool))
    assert np.flatnonzero(sliver[6]).tolist() == [24, 25]
    assert np.flatnonzero(sliver[7]).tolist() == [26]
    assert _jit.polygon_fill(np.array([[0.0, 0.0], [4.5, 0.0], [0.0, 4.0]]), np.zeros((5, 5), bool)).shape == (0, 0)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_the_depth_windows_read_along_the_image_are_the_twins(dtype):
    """``_Depth``'s windows read along the whole image's rows (:func:`_jit.depth_window_at`) against the twin's
    (``np.where`` over the window, ``SYMFRUIT_KERNELS=numpy``), bit for bit: NaN, infinite, negative and -0.0 depths
    0, the rest as float64; plain windows, windows past the border, empty ones, every other or fourth pixel, and the
    whole image; and against :func:`_jit.depth_window` of the window's view."""
    from symfruit.segment.colour import _Depth

    rng = np.random.default_rng(44)
    z = rng.uniform(0.3, 2.0, (61, 83)).astype(dtype)
    z[rng.random(z.shape) < 0.1] = 0.0
    for bad in (np.nan, np.inf, -np.inf, -0.5, -0.0):
        z[rng.random(z.shape) < 0.03] = bad
    windows = [(slice(3, 20), slice(5, 60)), (slice(50, 99), slice(70, 200)), (slice(9, 4), slice(0, 10)),
               (slice(None, None, 4), slice(None, None, 4)), (slice(1, None, 2), slice(2, 77, 3)),
               (slice(None), slice(None)), (slice(0, 1), slice(82, 83))]  # fmt: skip
    for window in windows:
        with pytest.MonkeyPatch.context() as mp:
            fast, twin = _both(mp, lambda w: _Depth(z)[w], window)
        assert fast.dtype == twin.dtype == np.float64 and fast.shape == twin.shape == z[window].shape
        assert fast.tobytes() == twin.tobytes()
        rows, cols = window[0].indices(61), window[1].indices(83)
        assert _jit.depth_window_at(z, rows, cols).tobytes() == _jit.depth_window(z[window]).tobytes()
    assert (_Depth(z)[windows[0]] > 0).sum() > 0.7 * z[windows[0]].size


@pytest.mark.parametrize("seed", range(3))
def test_the_bulge_sums_are_the_bincounts(seed):
    """``_bulging`` with :func:`_jit.bulge_sums` (one pass per sum) and with the twin's ``np.bincount`` calls: the same
    answers on caps of balls (bulging), planes and saddles, some pixels without depth, some pieces too small;
    and the sums themselves are the twin's bincounts to the bit."""
    from symfruit.segment.colour import SegmentSettings, _bulging, _Geometry

    rng = np.random.default_rng(seed)
    n = 12
    size = rng.integers(5, 300, n + 1)
    labels = np.repeat(np.arange(n + 1), size)
    rng.shuffle(labels)
    centre = rng.integers(20, 250, (n + 1, 2)) * 4  # each piece a patch of the grid's pixels 40 px about its centre
    rows = centre[labels, 0] + rng.integers(-10, 11, len(labels)) * 4
    cols = centre[labels, 1] + rng.integers(-10, 11, len(labels)) * 4
    geo = _Geometry(1400.0, 540.0, 960.0)
    dx, dy = (cols - centre[labels, 1]) * 0.9 / geo.focal, (rows - centre[labels, 0]) * 0.9 / geo.focal
    shape = labels % 3  # 0: a 4 cm ball's cap towards the camera, 1: a slanted plane, 2: a saddle
    cap = 0.9 + 0.04 - np.sqrt(np.maximum(0.04**2 - dx**2 - dy**2, 0.0))
    depth = np.where(shape == 0, cap, np.where(shape == 1, 0.9 + 0.3 * dx, 0.9 + 20 * dx * dy))
    depth += rng.normal(0, 2e-4, len(labels))
    depth[rng.random(len(labels)) < 0.1] = 0.0
    s = SegmentSettings(round_fruit=True, ground_colour=True)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _bulging, labels, rows, cols, depth, n, geo, s)
    np.testing.assert_array_equal(fast, twin)
    kind = np.arange(n + 1) % 3
    assert fast[kind == 0].all() and not fast[kind == 1].any()  # the caps bulge, the planes do not
    count, m, rhs, zz = _jit.bulge_sums(labels, rows, cols, depth, n, geo.cx, geo.cy, geo.focal)
    ok = depth > 0
    lab, z = labels[ok], depth[ok]
    x = (cols[ok] - geo.cx) * z / geo.focal
    x = x - (np.bincount(lab, weights=x, minlength=n + 1) / np.maximum(count, 1.0))[lab]
    assert count.tobytes() == np.bincount(lab, minlength=n + 1).astype(np.float64).tobytes()
    assert m[:, 1, 1].tobytes() == np.bincount(lab, weights=x * x, minlength=n + 1).tobytes()
    assert rhs[:, 1].tobytes() == np.bincount(lab, weights=x * z, minlength=n + 1).tobytes()
    assert zz.tobytes() == np.bincount(lab, weights=z * z, minlength=n + 1).tobytes()


# --- stop 45, speedreg45


def _median_of_25_bits(extra_first: bool, mid: tuple = _jit.MID20) -> np.ndarray:
    """window_medians' networks on all 2^25 windows of 0 and 1 (wire ``5 r + c`` the window's row r, column c; each
    wire a bit per window, a min an AND, a max an OR): the five columns sorted (SORT5), four of them merged (MID20:
    the last four where ``extra_first``, the window then the pair's first; else the first four), the result with the
    fifth column (MEDIAN11); the wire left in ``f10``, packed 64 windows to a word."""
    word = np.arange(2**19, dtype=np.uint64)  # window x's bit k: within a 64-bit word for k < 6, of the word beyond
    low = [sum(1 << b for b in range(64) if (b >> k) & 1) for k in range(6)]
    v = [np.full(2**19, low[k], np.uint64) for k in range(6)]
    v += [np.where((word >> np.uint64(k - 6)) & np.uint64(1), ~np.uint64(0), np.uint64(0)) for k in range(6, 25)]

    def run(wires, network):
        for i, j, kind in network:
            lo, hi = wires[i] & wires[j], wires[i] | wires[j]
            if kind in (0, 1):
                wires[i] = lo
            if kind in (0, 2):
                wires[j] = hi
        return wires

    columns = [run([v[5 * r + c] for r in range(5)], _jit.SORT5) for c in range(5)]
    four, extra = (columns[1:], columns[0]) if extra_first else (columns[:4], columns[4])
    m = run([x for column in four for x in column], mid)
    f = run(list(extra) + [m[8], m[5], m[9], m[12], m[13], m[14]], _jit.MEDIAN11)
    return f[10]


@pytest.mark.parametrize("extra_first", [True, False])
def test_the_shared_median_networks_select_the_median_of_every_25_bits(extra_first):
    """SORT5, MID20 and MEDIAN11 put the median in f10 for all 2^25 windows of 0 and 1, whichever four columns are
    the shared ones (the 0-1 principle: then for every window, stop 61); MID20 one pair short is wrong on some."""
    x = np.arange(2**25, dtype=np.uint32)
    expect = np.packbits(np.bitwise_count(x) >= 13, bitorder="little").view(np.uint64)
    assert len(_jit.SORT5) == 9 and len(_jit.MID20) == 51 and len(_jit.MEDIAN11) == 10
    assert np.array_equal(_median_of_25_bits(extra_first), expect)
    short = _jit.MID20[:20] + _jit.MID20[21:]
    assert not np.array_equal(_median_of_25_bits(extra_first, short), expect)


def test_the_window_medians_kernel_runs_the_shared_networks():
    """window_medians' written-out pairs: SORT5 on a0..a4 (the pair's first column) and b0..b4 (its last), SORT5 on
    each of m0..m4, .., m15..m19 and then MID20, in their order; _median_with's are MEDIAN11's on f0..f10 and it
    returns f10; the pair's two windows take their own column and MID20's six wires as _median_of_25_bits hands
    them, from the padded columns 2 k to 2 k + 5 in order."""
    import inspect
    import re

    def pairs(function, v):
        found = []
        for line in inspect.getsource(function.py_func).splitlines():
            if m := re.fullmatch(rf"\s*{v}(\d+), {v}(\d+) = min\({v}\1, {v}\2\), max\({v}\1, {v}\2\)", line):
                found.append((int(m[1]), int(m[2]), 0))
            elif m := re.fullmatch(rf"\s*{v}(\d+) = min\({v}\1, {v}(\d+)\)", line):
                found.append((int(m[1]), int(m[2]), 1))
            elif m := re.fullmatch(rf"\s*{v}(\d+) = max\({v}(\d+), {v}\1\)", line):
                found.append((int(m[2]), int(m[1]), 2))
        return found

    sorts = [(i + 5 * j, k + 5 * j, kind) for j in range(4) for i, k, kind in _jit.SORT5]
    assert pairs(_jit.window_medians, "a") == pairs(_jit.window_medians, "b") == list(_jit.SORT5)
    assert pairs(_jit.window_medians, "m") == sorts + list(_jit.MID20)
    assert pairs(_jit._median_with, "f") == list(_jit.MEDIAN11)
    assert "return f10" in inspect.getsource(_jit._median_with.py_func)
    source = inspect.getsource(_jit.window_medians.py_func)
    loads = re.findall(r"(\w)(\d+), \w\d+, \w\d+, \w\d+, \w\d+ = (\w)0\[(k(?: \+ \w+)?)\]", source)
    assert loads == [
        ("a", "0", "e", "k"), ("m", "0", "o", "k"), ("m", "5", "e", "k + one"), ("m", "10", "o", "k + one"),
        ("m", "15", "e", "k + two"), ("b", "0", "o", "k + two"),
    ]  # fmt: skip
    assert "row[k + k] = _median_with(a0, a1, a2, a3, a4, m8, m5, m9, m12, m13, m14)" in source
    assert "row[k + k + one] = _median_with(b0, b1, b2, b3, b4, m8, m5, m9, m12, m13, m14)" in source


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_the_shared_window_medians_are_the_twins_on_scattered_rows(seed):
    """window_medians (stop 61: columns sorted once, windows two at a time) against its numpy twin _window_medians
    to the bit, on windows 1-23 pixels wide whose rows' first and last ok pixels fall on even and odd columns (a
    row's last pair of windows one past the image), of depths drawn from 1-6 values (ties) or continuous."""
    from symfruit.core.surface import _window_medians

    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(1, 24, 2))
    ok = rng.random((h, w)) < rng.choice([0.05, 0.3, 0.7, 1.0])
    if not ok.any():
        ok[int(rng.integers(h)), int(rng.integers(w))] = True
    levels = int(rng.integers(0, 7))
    depth = rng.integers(1, levels + 1, (h, w)) * 0.25 if levels else rng.random((h, w)) + 0.1
    medians = np.empty(int(ok.sum()))
    _jit.window_medians(depth, ok, medians)
    assert medians.tobytes() == _window_medians(depth, ok).tobytes()


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_the_window_medians_are_the_partitions(seed):
    """window_medians against _window_medians (scipy's nearest pixels, median_at's partition) and against
    filled_windows' windows partitioned: the same medians to the bit, on windows of a few depths (ties, steps),
    dropouts, masks down to one pixel and windows a pixel wide."""
    from symfruit.core.surface import _window_medians

    depth, mask, _ = _parts_case(seed)
    ok = mask & (depth > 0)
    if not ok.any():
        ok[0, 0], depth[0, 0] = True, 0.5
    medians = np.empty(int(ok.sum()))
    _jit.window_medians(depth, ok, medians)
    assert medians.tobytes() == _window_medians(depth, ok).tobytes()
    values = np.empty((len(medians), 25))
    _jit.filled_windows(depth, ok, 5, values)
    assert medians.tobytes() == np.partition(values, 12, axis=1)[:, 12].tobytes()


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_near_filled_picks_scipys_nearest_pixel(seed):
    """near_filled against scipy's feature transform at every pixel within two rows and two columns of an ok pixel
    (the pixels window_medians reads for a median it keeps): the same pixel's depth, ties included (sparse ok pixels
    of distinct depths, so that another of equally near pixels shows); 0 at the pixels farther from every ok pixel."""
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(1, 30, 2))
    ok = rng.random((h, w)) < rng.choice([0.02, 0.1, 0.3, 0.6, 0.95])
    if not ok.any():
        ok[int(rng.integers(h)), int(rng.integers(w))] = True
    depth = rng.random((h, w)) + 0.1
    out = np.full((h, w), np.nan)
    _jit.near_filled(depth, ok, out)
    _, (ri, ci) = ndimage.distance_transform_edt(~ok, return_indices=True)
    near = ndimage.maximum_filter(ok, size=5, mode="constant")
    assert out[near].tobytes() == depth[ri, ci][near].tobytes()
    assert (out[~near] == 0.0).all()


def test_near_filled_of_a_known_image():
    """Two ok pixels at (0, 0) and (2, 2) of a 3 x 5 image: (1, 1) is as near to both and takes the least column's
    (0, 0), (0, 2) and (2, 0) likewise; (1, 2) and (2, 1) are nearer to (2, 2); (0, 4) is 2.8 px from (2, 2);
    every pixel lies within two rows and two columns of one of them."""
    depth = np.arange(15.0).reshape(3, 5) + 1.0
    ok = np.zeros((3, 5), bool)
    ok[0, 0] = ok[2, 2] = True
    out = np.empty((3, 5))
    _jit.near_filled(depth, ok, out)
    a, b = depth[0, 0], depth[2, 2]
    assert out.tolist() == [[a, a, a, b, b], [a, a, b, b, b], [a, b, b, b, b]]


def test_the_window_medians_of_a_known_image():
    """A 5 x 7 image of the numbers 1..35 in raster order, every pixel ok: at (2, 3) the window holds rows 0-4 and
    columns 1-5, whose median is the middle row's middle value, 18; at the corner (0, 0) the edges repeat rows 0, 0,
    0, 1, 2 and columns 0, 0, 0, 1, 2: the median is 3 (the values 1 x 9, 2 x 3, 3 x 3, 8 x 3, 9, 10, 15 x 3, 16, 17).
    A pixel not ok takes its nearest ok pixel's depth."""
    depth = np.arange(1.0, 36.0).reshape(5, 7)
    ok = np.ones((5, 7), bool)
    medians = np.empty(35)
    _jit.window_medians(depth, ok, medians)
    assert medians[2 * 7 + 3] == 18.0 and medians[0] == 3.0
    ok[:, 3:] = False  # columns 3-6 take column 2's depths
    medians = np.empty(15)
    _jit.window_medians(depth, ok, medians)
    filled = np.repeat(depth[:, 2:3], 7, axis=1)
    filled[:, :3] = depth[:, :3]
    expect = [np.median(np.pad(filled, 2, mode="edge")[r : r + 5, c : c + 5]) for r in range(5) for c in range(3)]
    assert medians.tolist() == expect


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_reaches_outline_is_the_twins(seed):
    """reaches_outline against _reaches_outline (the outline of interior()): the same answer on random masks and
    pixels of them, some on the array's border."""
    from symfruit.core.surface import _reaches_outline

    _, mask, _ = _parts_case(seed)
    rng = np.random.default_rng(seed)
    rows, cols = np.nonzero(mask)
    pick = rng.random(len(rows)) < rng.uniform(0.0, 0.3)
    rows, cols = rows[pick], cols[pick]
    assert _jit.reaches_outline(mask, rows, cols) == _reaches_outline(mask, rows, cols)


def test_reaches_outline_of_a_square():
    """A 5 x 5 square in a 9 x 9 mask: its centre is not on the outline, its corner is; a square filling the array
    reaches it at the array's border."""
    mask = np.zeros((9, 9), bool)
    mask[2:7, 2:7] = True
    centre, corner = (np.array([4, 3]), np.array([4, 4])), (np.array([4, 2]), np.array([4, 2]))
    assert not _jit.reaches_outline(mask, *centre) and _jit.reaches_outline(mask, *corner)
    whole = np.ones((9, 9), bool)
    assert not _jit.reaches_outline(whole, np.array([4]), np.array([4]))
    assert _jit.reaches_outline(whole, np.array([0]), np.array([4]))
    assert not _jit.reaches_outline(mask, np.zeros(0, np.int64), np.zeros(0, np.int64))


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_the_part_sizes_are_the_twins_bincounts(seed):
    """part_sizes against _part_sizes (two np.bincount calls) on smooth_parts' partitions of random windows: the same
    counts, of the same type."""
    from symfruit.core.surface import _part_sizes

    depth, mask, join = _parts_case(seed)
    parts = np.empty(depth.shape, np.int32)
    count = int(_jit.smooth_parts(depth, mask, join, parts))
    front = float(np.random.default_rng(seed).choice([0.5, 0.52, 0.6]))
    sizes, near = _jit.part_sizes(parts, count, depth, front, join)
    twin_sizes, twin_near = _part_sizes(parts, count, depth, front, join)
    assert sizes.dtype == twin_sizes.dtype == near.dtype == twin_near.dtype
    np.testing.assert_array_equal(sizes, twin_sizes)
    np.testing.assert_array_equal(near, twin_near)


def test_the_part_sizes_of_two_parts():
    """Parts 1 (3 pixels, depths 0.5) and 2 (2 pixels, 0.6) and 4 pixels of none: the sizes 4, 3, 2; within 5 mm of
    0.6 only part 2's."""
    parts = np.array([[1, 1, 0], [1, 0, 2], [0, 0, 2]], np.int32)
    depth = np.where(parts == 2, 0.6, np.where(parts == 1, 0.5, 0.6))
    sizes, near = _jit.part_sizes(parts, 2, depth, 0.6, 0.005)
    assert sizes.tolist() == [4, 3, 2] and near.tolist() == [0, 0, 2]


# --- stop 45, speedcomp45


@pytest.mark.parametrize("seed", range(4))
def test_the_revolution_directions_are_the_twins(seed):
    """:func:`_jit.revolution_directions` and its twin (``np.linalg.norm``, the flip to ``z >= 0``, ``np.vstack``):
    the same bytes on the coarse directions with 1-9 extra ones across twelve orders of magnitude, some with ``z``
    negative, zero or the vector zero (NaN both ways); and known values."""
    from symfruit.core.fits import _COARSE, _revolution_directions

    rng = np.random.default_rng(seed)
    for m in (1, 3, 6, 9):
        extra = rng.normal(size=(m, 3)) * 10.0 ** rng.uniform(-6, 6, (m, 1))
        extra[0, 2] = -abs(extra[0, 2])
        if m > 3:
            extra[1, 2], extra[2] = 0.0, 0.0
        with pytest.MonkeyPatch.context() as mp, np.errstate(invalid="ignore"):  # the zero vector: 0 / 0
            fast, twin = _both(mp, _revolution_directions, _COARSE, extra)
        assert fast.shape == twin.shape == (len(_COARSE) + m, 3)
        assert fast.tobytes() == twin.tobytes()
        assert fast[len(_COARSE)][2] >= 0
    got = _jit.revolution_directions(np.zeros((0, 3)), np.array([[0.0, 3.0, -4.0], [6.0, 0.0, 8.0]]))
    np.testing.assert_array_equal(got, [[-0.0, -0.6, 0.8], [0.6, 0.0, 0.8]])


@pytest.mark.parametrize("seed", range(4))
def test_the_apex_kernels_are_the_twins(seed):
    """``apex_depth`` with :func:`_jit.apex_near` and :func:`_jit.apex_design` and with the twins: the same depth and
    apex to the bit on noisy caps of spheres (the fit's inputs are the same bytes, so LAPACK gets the same matrix);
    the kernels' values those of the twin's expressions; and a known answer (a paraboloid's vertex)."""
    from symfruit.core.front import apex_depth
    from symfruit.core.points import column_means, squared_norms

    rng = np.random.default_rng(seed)
    pts = random_sphere(n=int(rng.integers(200, 3000)), seed=seed)
    pts = pts[pts[:, 2] < CENTRE[2]]
    pts = np.ascontiguousarray(pts + rng.normal(0, 5e-4, pts.shape))
    with pytest.MonkeyPatch.context() as mp:
        (z_fast, apex_fast), (z_twin, apex_twin) = _both(mp, apex_depth, pts)
    assert z_fast == z_twin and apex_fast.tobytes() == apex_twin.tobytes()
    front = np.argpartition(pts[:, 2], 9)[:10]
    seed_, d2 = _jit.apex_near(pts, front)
    assert seed_.tobytes() == column_means(pts[front, :2]).tobytes()
    assert d2.tobytes() == squared_norms(pts[:, :2] - seed_).tobytes()
    pick = np.argpartition(d2, 40)[:41]
    a, z = _jit.apex_design(pts, pick, seed_)
    x, y = pts[pick, 0] - seed_[0], pts[pick, 1] - seed_[1]
    assert a.tobytes() == np.stack((np.ones_like(x), x, y, x * x, x * y, y * y), axis=1).tobytes()
    assert z.tobytes() == pts[pick, 2].tobytes()
    g = np.stack(np.meshgrid(np.linspace(-0.02, 0.02, 21), np.linspace(-0.02, 0.02, 21)), -1).reshape(-1, 2)
    bowl = np.column_stack((g + 0.003, 0.4 + 5.0 * ((g[:, 0] - 0.001) ** 2 + g[:, 1] ** 2)))
    z_min, apex = apex_depth(np.ascontiguousarray(bowl))
    assert z_min == pytest.approx(0.4, abs=1e-9) and apex[:2] == pytest.approx([0.004, 0.003], abs=1e-6)


# --- stop 45, speedocc45


def _fattened_scene(rng, h, w, with_others):
    """A disc fruit whose depth the sensor spread a few pixels past its mask, a leaf in front, another fruit beside,
    dropouts, on an (h, w) image: ``(uv, points, depth, mask, others)``, ``points`` projecting at ``uv`` by a camera
    of focal length 300 at the image's corner."""
    rr, cc = np.mgrid[0:h, 0:w]
    r0, c0, rad = rng.uniform(0, h), rng.uniform(0, w), rng.uniform(2, 12)
    dist = np.hypot(rr - r0, cc - c0)
    zf = 0.4 + 0.0005 * dist
    depth = np.where(dist <= rad + rng.uniform(0, 9), zf, rng.choice([0.4, 1.0])) + rng.normal(0.0, 0.001, (h, w))
    leaf = (np.abs(rr - rng.uniform(0, h)) < rng.uniform(0, 4)) & (cc > rng.uniform(0, w))
    depth = np.where(leaf, rng.choice([0.3, 0.4]), depth)
    depth[rng.random((h, w)) < rng.choice([0.0, 0.05, 0.3])] = rng.choice([0.0, np.nan])
    mask = (dist <= rad) & ~leaf
    sel = (dist <= rad + rng.integers(-2, 3)) & (rng.random((h, w)) < 0.9)  # the points' pixels: not quite the mask's
    if not sel.any():
        sel[int(min(r0, h - 1)), int(min(c0, w - 1))] = True
    v, u = np.nonzero(sel)
    z = zf[sel] + rng.choice([0.0, 0.004, -0.01], len(u))
    uv = np.column_stack((u + rng.uniform(-0.4, 0.4, len(u)), v + rng.uniform(-0.4, 0.4, len(u))))
    points = np.column_stack((uv[:, 0] * z / 300.0, uv[:, 1] * z / 300.0, z))
    others = (
        (np.hypot(rr - r0, cc - c0 - 2 * rad - rng.integers(0, 5)) <= rad) if with_others else np.zeros((0, 0), bool)
    )
    return uv, points, depth, mask, others


def test_the_boxed_own_edge_known_answers():
    """A disc whose depth runs 3 px past its mask onto background: the ring (hidden without the band) cleared, every
    pixel of it, and _own_edge_in_box returns their count; with the ring 2 cm in front of the fruit (a leaf), it stays;
    with a leaf at the fruit's depth running on past the band to the right, the ring stays on its middle row and is
    cleared on the other side (stop 40's rule, ``supports`` off); with ``supports`` (stop 56) too: the leaf lies at
    the fruit's front (this flat fruit's every depth), where a fruit may continue behind it to its whole radius, past
    the band."""
    h, w = 60, 80
    rr, cc = np.mgrid[0:h, 0:w]
    dist = np.hypot(rr - 30, cc - 40)
    mask = dist <= 10
    v, u = np.nonzero(mask)
    points = np.column_stack((u * 0.4 / 300.0, v * 0.4 / 300.0, np.full(len(u), 0.4)))
    steps, none = _steps_within(3), np.zeros((0, 0), bool)
    ring = (dist > 10) & (dist <= 13)

    def both(depth, supports=False):
        bare = _jit.occlusion_projected(points, 300.0, 300.0, 0.0, 0.0, 16, depth, mask, none, 0.005, steps, 0,
                                        supports, 300.0)  # fmt: skip
        return bare, _jit.occlusion_projected(points, 300.0, 300.0, 0.0, 0.0, 16, depth, mask, none, 0.005, steps, 8,
                                              supports, 300.0)  # fmt: skip

    bare, (found, u0, v0, hidden, seen) = both(np.where(dist <= 13, 0.4, 1.0))
    assert found and int(bare[3].sum()) == int(ring.sum()) and not hidden.any()
    again = bare[3].copy()
    box_z = np.where(mask[20:41, 30:51], 0.4, np.inf)
    f0, f1, e0, e1 = 20 - v0, 41 - v0, 30 - u0, 51 - u0  # the disc's box in the window
    count = _jit._own_edge_in_box(again, mask, v0, u0, box_z, 20 - v0, 30 - u0, seen, none, 0.005, 8, False, 300.0,
                                  f0, f1, e0, e1)  # fmt: skip
    assert count == int(ring.sum()) and not again.any()
    bare, front = both(np.where(dist <= 10, 0.4, np.where(dist <= 13, 0.38, 1.0)))
    assert int(bare[3].sum()) == int(ring.sum()) and np.array_equal(front[3], bare[3])
    leaf = (np.abs(rr - 30) <= 1) & (cc > 40)
    bare, cut = both(np.where((dist <= 13) | leaf, 0.4, 1.0))
    kept = np.zeros((h, w), bool)
    kept[cut[2] : cut[2] + cut[3].shape[0], cut[1] : cut[1] + cut[3].shape[1]] = cut[3]
    assert kept[30, 51:54].all() and not kept[ring & (cc < 40)].any()  # the leaf's middle row beside the fruit
    bare, cut = both(np.where((dist <= 13) | leaf, 0.4, 1.0), supports=True)
    kept[:] = False
    kept[cut[2] : cut[2] + cut[3].shape[0], cut[1] : cut[1] + cut[3].shape[1]] = cut[3]
    assert kept[30, 51:54].all() and not kept[ring & (cc < 40)].any()


def test_the_label_boxes_known_answer():
    """Three labels, one missing, one in the last column and row, a run longer than the 32-pixel blocks: the boxes,
    stops exclusive, r1 = 0 for the missing one."""
    labels = np.zeros((5, 70), np.int32)
    labels[1:3, 2:40] = 1
    labels[4, 69] = 3
    labels[0, 35] = 3
    got = _jit.label_boxes(labels, 4)
    assert got.tolist() == [[1, 3, 2, 40], [5, 0, 70, 0], [0, 5, 35, 70], [5, 0, 70, 0]]


def _random_labels(rng: np.random.Generator, h: int, w: int, top: int) -> np.ndarray:
    """(h, w) int32 labels 0..``top``: up to 7 rectangles of random labels from 1, then a random share of pixels
    (none, 1 % or 30 %) given a random label from 0 (runs across blocks, sparse and dense labels)."""
    labels = np.zeros((h, w), np.int32)
    for _ in range(int(rng.integers(0, 8))):
        r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
        labels[r0 : r0 + int(rng.integers(1, 20)), c0 : c0 + int(rng.integers(1, 80))] = rng.integers(1, top + 1)
    labels[rng.random((h, w)) < rng.choice([0.0, 0.01, 0.3])] = rng.integers(0, top + 1)
    return labels


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**31 - 1), st.integers(1, 50), st.integers(1, 130), st.integers(1, 12))
def test_the_label_boxes_are_find_objects(seed, h, w, n):
    """label_boxes against ``ndimage.find_objects`` on random label images: sparse and dense labels, runs across the
    32-pixel blocks, labels without pixels, labels above the count asked for (background to both)."""
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    labels = _random_labels(rng, h, w, n + 2)
    if rng.random() < 0.5:
        labels = labels[:, ::-1]  # a strided view
    got = _jit.label_boxes(labels, n)
    want = ndimage.find_objects(np.where(labels <= n, labels, 0), n)
    for k in range(n):
        sl = want[k]
        expect = [h, 0, w, 0] if sl is None else [sl[0].start, sl[0].stop, sl[1].start, sl[1].stop]
        assert got[k].tolist() == expect


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**31 - 1), st.integers(1, 50), st.integers(1, 130), st.integers(1, 12))
def test_the_boxes_within_windows_are_find_objects(seed, h, w, n):
    """boxes_within (stop 62) against ``ndimage.find_objects`` on random label images whose labels each lie within a
    window holding their box (grown by 0-5 pixels, beyond the image on some sides, empty for a label without
    pixels or at random for one with none): the same boxes, r1 = 0 for a label without pixels; and a window cut
    short of a label's box finds the box of its pixels within the window alone."""
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    labels = _random_labels(rng, h, w, n)
    want = ndimage.find_objects(labels, n)
    windows = np.zeros((n, 4), np.int64)
    for k, sl in enumerate(want):
        if sl is None:
            if rng.random() < 0.5:  # a window over pixels of other labels alone
                windows[k] = (0, h, 0, w)
            continue
        grow = rng.integers(0, 6, 4)
        windows[k] = (sl[0].start - grow[0], sl[0].stop + grow[1], sl[1].start - grow[2], sl[1].stop + grow[3])
    got = _jit.boxes_within(labels, windows)
    for k in range(n):
        sl = want[k]
        expect = [0, 0, 0, 0] if sl is None else [sl[0].start, sl[0].stop, sl[1].start, sl[1].stop]
        assert got[k].tolist() == expect
    cut = windows.copy()
    cut[:, 1] = np.maximum(cut[:, 0], cut[:, 1] - 2)  # the boxes' last two rows left out
    got = _jit.boxes_within(labels, cut)
    for k in range(n):
        r0, r1, c0, c1 = (int(v) for v in cut[k])
        r0, r1, c0, c1 = max(r0, 0), min(r1, h), max(c0, 0), min(c1, w)
        part = ndimage.find_objects((labels[r0:r1, c0:c1] == k + 1).astype(np.int32)) if r0 < r1 and c0 < c1 else []
        expect = [0, 0, 0, 0] if not part or part[0] is None else [
            r0 + part[0][0].start, r0 + part[0][0].stop, c0 + part[0][1].start, c0 + part[0][1].stop]  # fmt: skip
        assert got[k].tolist() == expect


# --- stop 46, regspeed46


@pytest.mark.parametrize("seed", range(6))
def test_the_envelope_of_some_columns_is_their_least_parabola_over_the_whole_row(seed):
    """_envelope_of (outline_maps' outside pixels) against the brute-force least (u - i)^2 + f[i] over the columns
    lo..hi alone, at every column u of the row (left and right of them too): equal; and where the other columns'
    parabolas lie above (f of at least (h + w)^2, as outline_maps' columns without a mask pixel), _envelope's over
    the whole row."""
    rng = np.random.default_rng(seed)
    for w in (1, 2, 7, 40, 90):
        lo = int(rng.integers(0, w))
        hi = int(rng.integers(lo, w))
        f = rng.integers(0, 30, w).astype(np.int64) ** 2
        s, t, d2 = (np.empty(w, np.int64) for _ in range(3))
        _jit._envelope_of(f, lo, hi, w, s, t, d2)
        u, i = np.arange(w), np.arange(lo, hi + 1)
        np.testing.assert_array_equal(d2, ((u[:, None] - i[None, :]) ** 2 + f[None, lo : hi + 1]).min(axis=1))
        far = f.copy()
        far[:lo] = (30 + w) ** 2 + rng.integers(0, 5, lo)
        far[hi + 1 :] = (30 + w) ** 2 + rng.integers(0, 5, w - hi - 1)
        whole = np.empty(w, np.int64)
        _jit._envelope(far, w, s, t, whole)
        np.testing.assert_array_equal(d2, whole)


def test_the_outline_maps_of_a_pixel_in_a_wide_window_are_its_distances():
    """A mask of one pixel in a window wider and taller than it (columns without a mask pixel either side): every
    outside pixel's signed distance is minus its distance to that pixel, the pixel's own 1 (and the twin's)."""
    from symfruit.core.raster import distance_transform, inner_distance

    mask = np.zeros((5, 9), bool)
    mask[2, 4] = True
    inner, inside = np.empty(mask.shape), np.empty(mask.shape)
    ok, keys, ranks, values = _jit.outline_maps(mask, 3, 3, inner, inside)
    rr, cc = np.mgrid[0:5, 0:9]
    want = -np.sqrt(((rr - 2) ** 2 + (cc - 4) ** 2).astype(np.float64))
    want[2, 4] = 1.0
    np.testing.assert_array_equal(inside, want)
    assert inside[0, 0] == -np.sqrt(20.0) and inside[4, 8] == -np.sqrt(20.0)
    np.testing.assert_array_equal(inner, np.where(mask, 1.0, 0.0))
    assert ok and keys[(2 + 3) * 15 + 4 + 3] == 1 and values[ranks[(2 + 3) * 15 + 4 + 3]] == 1.0
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        np.testing.assert_array_equal(inside, inner_distance(mask) - distance_transform(~mask))


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 40))
def test_the_column_extents_are_numpys_ptp(seed, n):
    """column_extents against np.ptp of each column on values with ties, zeros of both signs, infinities and NaN:
    the same numbers (NaN where numpy's is), but for a zero's sign (principal_widths adds 1: no sign left)."""
    rng = np.random.default_rng(seed)
    p = rng.choice([0.0, -0.0, 1.5, -2.25, 3.0, 1e300, -1e-300, np.inf, -np.inf, np.nan], (n, 2), p=[0.15, 0.15]
                   + [0.68 / 7] * 7 + [0.02])  # fmt: skip
    if rng.random() < 0.5:
        p = rng.normal(0.0, 50.0, (n, 2))
    got = _jit.column_extents(np.ascontiguousarray(p))
    for j in (0, 1):
        with np.errstate(invalid="ignore"):  # inf - inf: NaN, as the kernel's
            want = np.ptp(p[:, j])
        assert (np.isnan(got[j]) and np.isnan(want)) or got[j] + 1.0 == want + 1.0 or got[j] == want


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_principal_widths_with_the_extents_kernel_are_the_twins(seed):
    """raster.principal_widths with its kernels (centred pixels, column_extents) and with SYMFRUIT_KERNELS=numpy on
    random blobs at an origin: the same two floats, bit for bit; and a known answer (a 5 x 14 rectangle)."""
    from symfruit.core.raster import principal_widths

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(2, 50, 2))
    mask = _blob_mask(rng, h, w)
    origin = (int(rng.integers(0, 500)), int(rng.integers(0, 500)))
    got = principal_widths(mask, origin=origin)
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        want = principal_widths(mask, origin=origin)
    assert got == want
    m = np.zeros((9, 20), bool)
    m[2:7, 3:17] = True
    assert principal_widths(m) == (5.0, 14.0)


# --- stop 46, segspeed46


def _two_fruit_region(rng):
    """A region the segmenter's split meets (two or three overlapping noisy discs in a 20-90 px window), depth edges
    across it (a circular rim, straight lines, scattered pixels, or none) and its cells (a cut by the nearest of the
    discs' centres, some parts empty or a speck)."""
    h, w = (int(v) for v in rng.integers(20, 90, 2))
    yy, xx = np.mgrid[:h, :w]
    k = int(rng.integers(2, 4))
    centres = rng.random((k, 2)) * (h, w)
    radii = rng.uniform(0.15, 0.45, k) * min(h, w)
    d2 = (yy[..., None] - centres[:, 0]) ** 2 + (xx[..., None] - centres[:, 1]) ** 2
    region = ((d2 <= radii**2).any(axis=2)) & (rng.random((h, w)) < rng.choice([1.0, 0.97]))
    kind = int(rng.integers(0, 4))
    if kind == 0:
        edges = np.abs(np.sqrt(d2[..., 0]) - radii[0]) < rng.uniform(0.5, 1.5)
    elif kind == 1:
        edges = np.zeros((h, w), bool)
        for _ in range(int(rng.integers(1, 4))):
            if rng.random() < 0.5:
                edges[int(rng.integers(0, h)), :] = True
            else:
                edges[:, int(rng.integers(0, w))] = True
    elif kind == 2:
        edges = rng.random((h, w)) < rng.uniform(0.02, 0.3)
    else:
        edges = np.zeros((h, w), bool)
    edges &= region if rng.random() < 0.8 else True
    nearest_centre = d2.argmin(axis=2)
    parts = [region & (nearest_centre == j) for j in range(k)]
    if rng.random() < 0.2:
        parts[-1] = np.zeros((h, w), bool)
        parts[-1][int(rng.integers(0, h)), int(rng.integers(0, w))] = True
    return region, edges, parts


@pytest.mark.parametrize("seed", range(3))
def test_following_the_depth_edges_is_the_twins(seed):
    """``_follow_edges`` with :func:`_jit.follow_edges` and with its numpy twin on 300 regions: the same parts, pixel
    for pixel and in order (fewer than two pieces, pure and mixed pieces, edges all over the region, parts that are a
    speck); and most of them moved the cut."""
    from symfruit.segment.colour import _follow_edges

    rng = np.random.default_rng(seed)
    moved = 0
    for _ in range(300):
        region, edges, parts = _two_fruit_region(rng)
        with pytest.MonkeyPatch.context() as mp:
            fast, twin = _both(mp, _follow_edges, parts, region, edges)
        assert len(fast) == len(twin)
        for a, b in zip(fast, twin, strict=True):
            np.testing.assert_array_equal(a, b)
        moved += fast is not parts
    assert moved > 150


def test_following_the_depth_edges_known_answer(monkeypatch):
    """A 6x21 region cut by a depth edge down column 10 into two pieces, the parts split at column 9: the left piece
    (54 of its 60 pixels the first part's: 0.9, pure) goes whole to the first part, the right one to the second, and
    the edge column, equally near both, to the left seed (scipy's choice); with the twin the same. One piece: the
    parts as they were."""
    from symfruit.segment.colour import _follow_edges

    region = np.ones((6, 21), bool)
    edges = np.zeros((6, 21), bool)
    edges[:, 10] = True
    first = np.zeros((6, 21), bool)
    first[:, :9] = True
    owner = np.where(first, 1, 2).astype(np.int64)
    grown, moved = _jit.follow_edges(region, edges, owner, 2, 0.9)
    assert moved and (grown[:, :11] == 1).all() and (grown[:, 11:] == 2).all()
    fast, twin = _both(monkeypatch, _follow_edges, [first, ~first], region, edges)
    for a, b, k in zip(fast, twin, (1, 2), strict=True):
        np.testing.assert_array_equal(a, grown == k)
        np.testing.assert_array_equal(b, grown == k)
    assert not _jit.follow_edges(region, np.zeros((6, 21), bool), owner, 2, 0.9)[1]


@pytest.mark.parametrize("seed", range(3))
def test_the_cut_along_the_edges_is_the_twins(seed):
    """:func:`_jit.near_edge_cut` against ``_supported``'s numpy test on 400 pairs of cells: no cut (-1, cells apart),
    a cut with at least half of its pixels within two 4-neighbour steps of an edge (1) or not (0), ties included."""
    from symfruit.segment.colour import _dilate

    rng = np.random.default_rng(seed)
    seen = set()
    for t in range(400):
        _, edges, parts = _two_fruit_region(rng)
        a, b = parts[0], parts[1]
        if t % 7 == 0:  # apart: no cut
            b = np.zeros_like(a)
            b[-1, -1] = not _dilate(a, square=True)[-1, -1]
        cut = (a & _dilate(b, square=True)) | (b & _dilate(a, square=True))
        want = -1 if not cut.any() else int(_dilate(_dilate(edges))[cut].mean() >= 0.5)
        assert _jit.near_edge_cut(a, b, edges) == want
        seen.add(want)
    assert seen == {-1, 0, 1}


@pytest.mark.parametrize("seed", range(3))
def test_the_surface_hull_and_its_green_are_the_twins(seed):
    """``_surface_hull`` and ``_green_in_hull`` with :func:`_jit.surface_hull` and :func:`_jit.green_in_hull` and
    with their twins (Pillow's fill and numpy's masks) on 400 masks' hulls: random colours (a third of the pixels
    green), owner maps with other pieces, this piece (``k``) and none, with and without the surface rule; the same
    pixels and counts, and the rules take pixels off."""
    from symfruit.segment.colour import _green_in_hull, _hull_vertices, _pillow_fill, _surface_hull

    if not _pillow_fill():
        pytest.skip("a Pillow older than 12.1 fills polygons otherwise (the kernels are not used with it)")
    rng = np.random.default_rng(seed)
    taken = counted = 0
    for t, mask in enumerate(_polygon_masks(rng, 400)):
        h, w = mask.shape
        colour = rng.integers(0, 256, (h, w, 3)).astype(np.uint8)
        green = rng.random((h, w)) < 0.3
        colour[green, 1] = np.maximum(colour[green, 1], 200)
        colour[green, 0] //= 2
        owner = rng.choice(np.array([0, 0, 3, 5], np.int16), (h, w)) if t % 3 else np.zeros((h, w), np.int16)
        vertices = _hull_vertices(mask)
        for surface in (True, False):
            with pytest.MonkeyPatch.context() as mp:
                fast, twin = _both(mp, _surface_hull, vertices, mask, owner, 3, colour, surface)
            np.testing.assert_array_equal(fast, twin)
            taken += vertices is not None and int(twin.sum()) < int(_jit.polygon_fill(vertices, mask).sum())
        with pytest.MonkeyPatch.context() as mp:
            fast_n, twin_n = _both(mp, _green_in_hull, vertices, mask, colour)
        assert fast_n == twin_n
        counted += twin_n > 0
    assert taken > 100 and counted > 50


def test_the_surface_hull_known_answer():
    """A 5x5 square's corners as the part (its hull the whole square): a green pixel inside the hull off the part is
    left out with the surface rule and kept without it, a pixel another piece owns is left out, the part's own green
    pixel is kept; the green count outside the part is 1."""
    part = np.zeros((5, 5), bool)
    part[[0, 0, 4, 4], [0, 4, 0, 4]] = True
    colour = np.full((5, 5, 3), (200, 40, 30), np.uint8)
    colour[2, 2] = colour[0, 0] = (30, 180, 40)  # green: inside the hull, and a pixel of the part
    owner = np.zeros((5, 5), np.int16)
    owner[1, 3] = 7
    owner[3, 1] = 2
    vertices = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]])
    got = _jit.surface_hull(vertices, part, owner, 2, colour, True)
    want = np.ones((5, 5), bool)
    want[2, 2] = want[1, 3] = False
    np.testing.assert_array_equal(got, want)
    want[2, 2] = True
    np.testing.assert_array_equal(_jit.surface_hull(vertices, part, owner, 2, colour, False), want)
    assert _jit.green_in_hull(vertices, part, colour) == 1


# --- stop 47, extspeed47


@pytest.mark.parametrize("seed", range(4))
def test_the_sphere_residuals_are_the_twins(seed):
    """:func:`_jit.sphere_residuals` against ``front._sphere_residuals`` bit for bit: noisy caps of spheres of 1-1,000
    points at random centres, a point at the centre (its distance clipped to 1e-12), a NaN point (NaN kept)."""
    from symfruit.core.front import _sphere_residuals

    rng = np.random.default_rng(seed)
    for t in range(60):
        n = int(rng.integers(1, 1000))
        p = rng.normal(size=(n, 3)) * rng.uniform(0.001, 0.1) + rng.uniform(-0.2, 0.8, 3)
        c = p.mean(axis=0) + rng.normal(size=3) * 0.05
        if t % 5 == 0:
            p[0] = c
        if t % 7 == 0:
            p[-1, int(rng.integers(3))] = np.nan
        r = float(rng.uniform(0.01, 0.1))
        jac, resid = np.empty((n, 3)), np.empty(n)
        _jit.sphere_residuals(p, c, r, jac, resid)
        twin_jac = np.empty((n, 3))
        twin_resid = _sphere_residuals(p, c, r, twin_jac)
        np.testing.assert_array_equal(jac.view(np.int64), twin_jac.view(np.int64))  # the bits, NaN and zeros' signs
        np.testing.assert_array_equal(resid.view(np.int64), twin_resid.view(np.int64))
    p = np.array([[0.0, 0.0, 1.0], [3.0, 4.0, 1.0]])
    jac, resid = np.empty((2, 3)), np.empty(2)
    _jit.sphere_residuals(p, np.array([0.0, 0.0, 1.0]), 2.0, jac, resid)
    np.testing.assert_array_equal(resid, [1e-12 - 2.0, 3.0])  # the first at the centre, the second 5 away
    np.testing.assert_array_equal(jac[1], [-0.6, -0.8, -0.0])


@pytest.mark.parametrize("seed", range(3))
def test_the_sphere_front_is_the_twins(monkeypatch, seed):
    """``sphere_front`` with the kernel and with the twin: the same front and apex to the bit, on caps of noisy spheres
    seen from the camera (a leaf's hole cut out of some), as ``evidence.hidden_front`` fits them."""
    from symfruit.core.front import sphere_front

    rng = np.random.default_rng(seed)
    for t in range(20):
        radius = float(rng.uniform(0.02, 0.05))
        centre = np.array([rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), rng.uniform(0.4, 1.2)])
        d = rng.normal(size=(int(rng.integers(20, 1200)), 3))
        d /= np.linalg.norm(d, axis=1)[:, None]
        d = d[d[:, 2] < -0.2]  # the cap towards the camera
        if t % 2:
            d = d[d[:, 0] > -0.3]  # a leaf over part of it
        p = centre + radius * d + rng.normal(scale=0.0007, size=d.shape)
        fast, twin = _both(monkeypatch, sphere_front, p, radius * float(rng.uniform(0.9, 1.1)))
        assert fast[0] == twin[0]
        np.testing.assert_array_equal(fast[1], twin[1])
        assert abs(fast[0] - (centre[2] - radius)) < 0.01


def _cap_for_the_sphere_front(seed, n, cap, noise, leaf, stretch):
    """A seeded cap of a 15-60 mm sphere facing the camera at 0.3-1.5 m (``n`` points, ``cap`` rad from its front,
    ``noise`` metres of Gaussian noise, the points with ``x`` direction below ``leaf`` dropped, the cap stretched by
    ``stretch`` along the line of sight: not a sphere) and its radius."""
    rng = np.random.default_rng(seed)
    radius = float(rng.uniform(0.015, 0.06))
    centre = np.array([rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), rng.uniform(0.3, 1.5)])
    polar, around = np.arccos(rng.uniform(np.cos(cap), 1.0, n)), rng.uniform(0.0, 2.0 * np.pi, n)
    d = np.stack([np.sin(polar) * np.cos(around), np.sin(polar) * np.sin(around), -stretch * np.cos(polar)], axis=1)
    d = d[d[:, 0] >= leaf]
    return np.ascontiguousarray(centre + radius * d + rng.normal(0.0, noise, d.shape)), radius


@settings(max_examples=300, deadline=None)
@given(
    seed=st.integers(0, 2**31),
    n=st.integers(4, 1200),
    cap=st.floats(0.05, 1.6),
    noise=st.sampled_from([0.0, 1e-5, 3e-4, 0.001, 0.003, 0.01]),
    leaf=st.sampled_from([-2.0, -0.5, 0.0, 0.4, 0.8]),
    stretch=st.sampled_from([1.0, 0.3, 2.0, 0.0]),
    scale=st.floats(0.3, 3.0),
    tolerance=st.sampled_from([1e-5, 1e-7, 1e-3]),
    iterations=st.sampled_from([20, 3, 6]),
    off=st.floats(-20.0, 20.0),
)
@example(seed=0, n=600, cap=1.0, noise=0.001, leaf=-2.0, stretch=1.0, scale=1.0, tolerance=1e-5, iterations=20,
         off=5.0)  # fmt: skip
def test_sphere_front_behind_only_where_the_fits_front_is(seed, n, cap, noise, leaf, stretch, scale, tolerance,
                                                          iterations, off):  # fmt: skip
    """:func:`_jit.sphere_front_behind` (issue 19, stop 63) says True only where ``sphere_front``'s front (BLAS's and
    LAPACK's Gauss-Newton) is at least ``front``: caps of spheres wide and narrow, clean and noisy, cut by a leaf,
    flattened to a disc or stretched (no sphere fits), a radius off by 0.3-3 times, tolerances of 1 um to 1 mm, few
    iterations, and ``front`` put within 20 tolerances of that fit's front either side (where the fit's own stop
    decides)."""
    from symfruit import InputError
    from symfruit.core.front import sphere_front

    p, radius = _cap_for_the_sphere_front(seed, n, cap, noise, leaf, stretch)
    if len(p) < 4:
        return
    r = radius * scale
    try:
        z, _ = sphere_front(p, r, iterations=iterations, tolerance=tolerance)
    except (InputError, np.linalg.LinAlgError):  # refused or failed: the kernel must not be sure
        z = math.nan
    front = z - off * tolerance if math.isfinite(z) else 0.5
    behind = _jit.sphere_front_behind(p, r, iterations, tolerance, front)
    assert not behind or z >= front


def test_sphere_front_behind_known_answers(monkeypatch):
    """Sure of a front 1 mm in front of ``sphere_front``'s on noisy caps (so the test above is not vacuous: 30 of 30),
    not sure at that front or 3 tolerances in front of it, nor for inputs ``sphere_front`` refuses or takes otherwise;
    without numba, or with ``SYMFRUIT_KERNELS=numpy``, never."""
    from symfruit.core.front import sphere_front, sphere_front_behind

    from ..conftest import noisy_cap

    for seed in range(30):
        p, radius = noisy_cap(seed)
        z, _ = sphere_front(p, radius, tolerance=1e-5)
        assert sphere_front_behind(p, radius, z - 0.001, tolerance=1e-5)
        assert not sphere_front_behind(p, radius, z, tolerance=1e-5)
        assert not sphere_front_behind(p, radius, z - 3e-5, tolerance=1e-5)
    p, radius = noisy_cap(0)
    z, _ = sphere_front(p, radius, tolerance=1e-5)
    front = z - 0.001
    assert not sphere_front_behind(p, 0.0, front) and not sphere_front_behind(p, -radius, front)
    assert not sphere_front_behind(p, math.nan, front) and not sphere_front_behind(p, radius, math.nan)
    assert not sphere_front_behind(p[:3], radius, front)
    assert not sphere_front_behind(p.astype(np.float32), radius, front)  # sphere_front converts it: not here
    assert not sphere_front_behind(np.asfortranarray(p), radius, front)
    q = p.copy()
    q[5, 2] = math.nan
    assert not sphere_front_behind(q, radius, front)
    assert not _jit.sphere_front_behind(p, radius, 20, 0.0, front)
    assert not _jit.sphere_front_behind(p, radius, 2, 1e-5, front)  # the first stop too near the last step
    monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
    assert not sphere_front_behind(p, radius, front, tolerance=1e-5)


def test_the_median_deviation_is_the_twins():
    """:func:`_jit.median_deviation` against ``points.median(abs(x - points.median(x)))`` bit for bit: odd and even
    counts, ties, zeros of both signs, a NaN (NaN); and a known answer."""
    from symfruit.core.points import median

    rng = np.random.default_rng(0)
    for t in range(300):
        n = int(rng.integers(1, 400))
        x = rng.normal(size=n) * 0.002 if t % 3 else rng.integers(-4, 5, n) * 0.001
        if t % 11 == 0:
            x[: n // 2] = -0.0
        if t % 13 == 0:
            x[int(rng.integers(n))] = np.nan
        want = median(np.abs(x - median(x)))
        got = _jit.median_deviation(x.copy())
        assert (np.isnan(got) and np.isnan(want)) or np.float64(got).view(np.int64) == np.float64(want).view(np.int64)
    assert _jit.median_deviation(np.array([1.0, 2.0, 4.0, 8.0])) == 1.5  # median 3; deviations 2, 1, 1, 5


# --- stop 47, segspeed47


def test_the_round_skins_reach_test_against_its_twin():
    """``_at_reach`` with its kernel and with numpy on random skins (discs, blobs, specks, empty, touching the window's
    edge or not) about random centres and reaches, the window at random offsets: the same answer each time, both
    answers and each of the twin's three ways to decide among them."""
    from symfruit.segment.colour import _at_reach

    rng = np.random.default_rng(47)
    answers = {True: 0, False: 0}
    for _ in range(600):
        h, w = (int(v) for v in rng.integers(3, 60, 2))
        r0, c0 = (int(v) for v in rng.integers(0, 500, 2))
        yy, xx = np.mgrid[:h, :w]
        kind = rng.integers(0, 4)
        if kind == 0:  # a disc, inside the window or running over its edge
            cy, cx, rad = rng.uniform(-2, h + 2), rng.uniform(-2, w + 2), rng.uniform(1, 20)
            skin = (yy - cy) ** 2 + (xx - cx) ** 2 <= rad**2
        elif kind == 1:  # a disc well inside the window
            rad = rng.uniform(1, max(min(h, w) / 2 - 2, 1.5))
            skin = (yy - h / 2) ** 2 + (xx - w / 2) ** 2 <= rad**2
            skin[[0, -1], :] = skin[:, [0, -1]] = False
        elif kind == 2:  # specks
            skin = rng.random((h, w)) < rng.uniform(0, 0.3)
        else:
            skin = np.zeros((h, w), bool)
        skin = skin if rng.random() < 0.8 else np.asfortranarray(skin)
        rc, cc = r0 + rng.uniform(-5, h + 5), c0 + rng.uniform(-5, w + 5)
        reach = float(rng.uniform(1, 40))
        big = (slice(r0, r0 + h), slice(c0, c0 + w))
        with pytest.MonkeyPatch.context() as mp:
            fast, twin = _both(mp, _at_reach, skin, big, rc, cc, reach)
        assert fast == twin and isinstance(fast, bool)
        answers[twin] += 1
    assert min(answers.values()) > 100


def test_the_round_skins_reach_test_known_answer():
    """A 3x3 skin in the middle of a 9x9 window at (10, 20), about its centre (14, 24): within a reach of 3.9 (its
    corners 1.42 px off, inside 2.9), not within 2.4 (outside 1.4); on the window's edge always."""
    skin = np.zeros((9, 9), bool)
    skin[3:6, 3:6] = True
    assert not _jit.at_reach(skin, 10, 20, 14.0, 24.0, (3.9 - 1.0) ** 2)
    assert _jit.at_reach(skin, 10, 20, 14.0, 24.0, (2.4 - 1.0) ** 2)
    skin[0, 4] = True
    assert _jit.at_reach(skin, 10, 20, 14.0, 24.0, 100.0)
    assert not _jit.at_reach(np.zeros((9, 9), bool), 10, 20, 14.0, 24.0, 0.0)


# --- stop 47, yellowfast47


@pytest.mark.parametrize("seed", [0, 1])
def test_the_bridged_depth_is_the_twins(seed):
    """:func:`_jit.bridge_gaps` on a depth as handed over (float32 or float64; 0, negative, -0.0, NaN and infinite
    values without depth) and its twin ``_bridged`` on the cleaned depth (the feature transform: scipy's with the
    twins, :func:`_jit.nearest` with the kernels) on 600 windows padded by 4 px (less at the image's edges), the
    depths of four values (equally near pixels of other depths everywhere: the choice among them counts), none, a
    twentieth, a fifth to nearly all of the pixels without depth (rows with depth throughout, rows whose few pixels
    without depth are weighed one by one, rows weighed whole: stop 53): the same values, gaps filled and gaps left."""
    from symfruit.segment.colour import BRIDGE_PX, _bridged

    rng = np.random.default_rng(seed)
    filled = left = 0
    bad = np.array([0.0, -0.0, -1.0, np.nan, np.inf, -np.inf])
    for t in range(600):
        h, w = (int(v) for v in rng.integers(1, 40, 2))
        given = rng.choice(np.array([0.5, 1.25, 2.0, 3.5]), (h, w))
        gap = rng.random((h, w)) < rng.choice([0.0, 0.05, 0.2, 0.6, 0.9, 0.97])  # rows with none, a few, most
        given[gap] = rng.choice(bad, int(gap.sum()))
        given = given.astype(np.float32 if t % 2 else np.float64)
        r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
        r1, c1 = int(rng.integers(r0 + 1, h + 1)), int(rng.integers(c0 + 1, w + 1))
        out = np.empty((r1 - r0, c1 - c0))
        _jit.bridge_gaps(given, r0, r1, c0, c1, BRIDGE_PX, out)
        clean = np.maximum(np.nan_to_num(given.astype(np.float64), nan=0, posinf=0, neginf=0), 0)
        a, b = max(r0 - 4, 0), max(c0 - 4, 0)
        padded = clean[a : r1 + 4, b : c1 + 4]
        inner = (slice(r0 - a, r1 - a), slice(c0 - b, c1 - b))
        with pytest.MonkeyPatch.context() as mp:
            fast, twin = _both(mp, _bridged, padded, inner)
        np.testing.assert_array_equal(out, twin)
        np.testing.assert_array_equal(fast, twin)
        assert not np.signbit(out).any()
        filled += int((gap[r0:r1, c0:c1] & (out > 0)).sum())
        left += int((gap[r0:r1, c0:c1] & (out == 0)).sum())
    assert filled > 5_000 and left > 1_000


def test_the_bridged_depth_known_answer():
    """A pixel without depth 2 px from depths 1 (left), 2 (right) and 3 (above) takes the left one's (the leftmost
    column's of those as near); with the left one gone and 4 below, the upper one's of its column (3), not the
    right one's; a pixel whose nearest depth is 4 px off keeps 0, 3 px off (or 3 and 1 across) is filled, 3 and 2
    across is not (13 > 3.5^2); depth is kept, NaN is none."""
    z = np.zeros((9, 9))
    z[4, 2], z[4, 6], z[2, 4] = 1.0, 2.0, 3.0
    out = np.empty((9, 9))
    _jit.bridge_gaps(z, 0, 9, 0, 9, 3.5, out)
    assert out[4, 4] == 1.0 and out[4, 2] == 1.0
    z[4, 2], z[6, 4] = np.nan, 4.0
    _jit.bridge_gaps(z, 0, 9, 0, 9, 3.5, out)
    assert out[4, 4] == 3.0 and out[4, 2] == 3.0  # (2, 4) and (4, 6) 8 off, the left one's column first
    row = np.zeros((1, 12))
    row[0, 0] = 5.0
    got = np.empty((1, 12))
    _jit.bridge_gaps(row, 0, 1, 0, 12, 3.5, got)
    np.testing.assert_array_equal(got[0], [5.0] * 4 + [0.0] * 8)
    z = np.zeros((5, 5), np.float32)
    z[0, 0] = 6.0
    got = np.empty((4, 4))
    _jit.bridge_gaps(z, 1, 5, 1, 5, 3.5, got)
    assert got[2, 0] == 6.0 and got[2, 1] == 0.0  # (3, 1) from the depth: 10 <= 12.25; (3, 2): 13 > 12.25


# --- stop 48, seg640_48


def test_the_inner_distance_is_the_padded_maps():
    """:func:`_jit.inner_distance` of 600 random masks (1-40 px a side; specks, discs, full and empty masks, rows and
    columns of one pixel) against its twin, ``ndimage.distance_transform_edt`` of the mask padded by a pixel (its
    inside), and against :func:`_jit.distance` of the padded copy, as the split's kernels had it: the same values, bit
    for bit."""
    from scipy import ndimage

    rng = np.random.default_rng(48)
    deep = 0
    for t in range(600):
        h, w = (int(v) for v in rng.integers(1, 41, 2))
        if t % 3 == 0:  # a disc or two, off centre
            rr, cc = np.mgrid[:h, :w]
            mask = np.zeros((h, w), bool)
            for _ in range(int(rng.integers(1, 3))):
                r, c, rad = rng.uniform(0, h), rng.uniform(0, w), rng.uniform(0.5, 25.0)
                mask |= (rr - r) ** 2 + (cc - c) ** 2 <= rad * rad
        else:
            mask = rng.random((h, w)) < rng.choice([0.0, 0.3, 0.7, 0.95, 1.0])
        out = np.full((h, w), np.nan)
        _jit.inner_distance(mask, out)
        twin = ndimage.distance_transform_edt(np.pad(mask, 1))[1:-1, 1:-1]
        np.testing.assert_array_equal(out, twin)
        padded = np.empty((h + 2, w + 2))
        _jit.distance(np.pad(mask, 1), False, padded)
        np.testing.assert_array_equal(out, padded[1:-1, 1:-1])
        deep += int((out > 2).sum())
    assert deep > 10_000


def test_the_inner_distance_known_answer():
    """A 5x7 mask all set: each pixel's distance to the array's edge (the padding), 3 at the middle; a pixel cleared
    at (2, 1): 0 there, 1 beside it, the middle (2, 3) 2 from it, (1, 3) 2 from the top edge (sqrt(5) from the cleared
    pixel), (1, 2) sqrt(2) from it."""
    mask = np.ones((5, 7), bool)
    out = np.empty((5, 7))
    _jit.inner_distance(mask, out)
    np.testing.assert_array_equal(out[2], [1.0, 2.0, 3.0, 3.0, 3.0, 2.0, 1.0])
    np.testing.assert_array_equal(out[:, 3], [1.0, 2.0, 3.0, 2.0, 1.0])
    mask[2, 1] = False
    _jit.inner_distance(mask, out)
    assert out[2, 1] == 0.0 and out[2, 2] == 1.0 and out[2, 3] == 2.0 and out[1, 3] == 2.0
    assert out[1, 2] == np.sqrt(2.0) and out[0, 0] == 1.0


@pytest.mark.parametrize("seed", [0, 1])
def test_the_ripe_test_is_the_twins(seed):
    """:func:`_jit.red_ripe` on 2,000 random windows (1-30 px a side, views of a larger image; colours drawn from a few
    values so that rednesses repeat, 0-100 % of the pixels red, odd and even counts) against its twin,
    ``median(redness(color[red]))`` reaching the threshold in float32, and against :func:`_jit.red_median`'s: the
    thresholds the window's own rednesses, the float32 means of two of them (a median of an even count lands there)
    and their float32 neighbours, and settings as 0.2: the same answers, ripe and not."""
    from symfruit.core.points import median
    from symfruit.segment.colour import redness

    rng = np.random.default_rng(seed)
    ripe = unripe = 0
    for _ in range(2000):
        h, w = (int(v) for v in rng.integers(1, 31, 2))
        levels = rng.choice(np.arange(256), int(rng.integers(2, 8)))
        color = rng.choice(levels, (h + 3, w + 4, 3)).astype(np.uint8)[1 : h + 1, 2 : w + 2]  # a window's view
        red = rng.random((h, w)) < rng.choice([0.0, 0.05, 0.5, 1.0])
        values = redness(color[red]).astype(np.float32) if red.any() else np.zeros(0, np.float32)
        pool = [np.float32(0.2), np.float32(0.35), np.float32(-1.0)]
        if len(values):
            a, b = rng.choice(values, 2)
            mean = (a + b) / np.float32(2.0)
            pool += [a, b, mean, np.nextafter(mean, np.float32(2.0)), np.nextafter(mean, np.float32(-2.0))]
            pool.append(np.float32(median(values)))
        for least in pool:
            least = np.float32(least)
            got = _jit.red_ripe(color, red, least)
            twin = bool(np.float32(median(values)) >= least) if len(values) else False
            assert got == twin
            assert got == bool(np.float32(_jit.red_median(color, red)) >= least)
            ripe += got
            unripe += not got
    assert ripe > 1000 and unripe > 1000


def test_the_ripe_test_known_answer():
    """Rednesses 0.5, 0.5, 0.25, 0 (R 200 less G 100, 100, 150, 200): the median of four is (0.25 + 0.5) / 2 = 0.375,
    ripe at 0.375, not at the next float32 above; without the last pixel (three, median 0.5) ripe at 0.5; no pixel:
    not ripe."""
    color = np.array([[[200, 100, 0], [200, 100, 50], [200, 150, 0], [200, 200, 0]]], np.uint8)
    red = np.ones((1, 4), bool)
    assert _jit.red_ripe(color, red, np.float32(0.375))
    assert not _jit.red_ripe(color, red, np.nextafter(np.float32(0.375), np.float32(1.0)))
    red[0, 3] = False
    assert _jit.red_ripe(color, red, np.float32(0.5)) and not _jit.red_ripe(color, red, np.float32(0.51))
    assert not _jit.red_ripe(color, np.zeros((1, 4), bool), np.float32(-1.0))


def test_the_group_boxes_are_the_twins(monkeypatch):
    """``_group_boxes`` (:func:`_jit.group_boxes`) of the kept labels of 300 random label sets (1-3,000 pixels, up to
    40 labels, a third kept, rows and columns up to 2,000) against its twin, ``reduceat``'s minima and maxima: the same
    boxes in the same order; and a known answer."""
    from symfruit.segment.colour import _group_boxes, _grouped

    rng = np.random.default_rng(48)
    boxes = 0
    for _ in range(300):
        n = int(rng.integers(1, 3001))
        k = int(rng.integers(1, 41))
        labels = rng.integers(1, k + 1, n)
        keep = rng.random(k + 1) < 0.35
        rows, cols = rng.integers(0, 2000, n), rng.integers(0, 2000, n)
        grouped = _grouped(labels, keep)
        fast, twin = _both(monkeypatch, _group_boxes, *grouped, rows, cols)
        assert list(fast.items()) == list(twin.items())
        boxes += len(fast)
    assert boxes > 1000
    labels, rows, cols = np.array([2, 1, 2, 2]), np.array([5, 0, 3, 9]), np.array([1, 4, 7, 2])
    found = _group_boxes(*_grouped(labels, np.array([False, True, True])), rows, cols)
    assert found == {1: (slice(0, 1), slice(4, 5)), 2: (slice(3, 10), slice(1, 8))}


# --- stop 48, occspeed48


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 30), st.integers(1, 30), st.integers(1, 40))
def test_the_reach_fill_on_a_fixed_stack_is_the_flood_box_or_says_it_ran_out(seed, h, w, cap):
    """_reach_fill with a stack of ``cap`` seeds: either ok and _flood_box's box, or not ok (it needed more); with
    5 h w + 16 seeds (_reach_box's second try) always ok. Random joins and seen pixels, scattered."""
    rng = np.random.default_rng(seed)
    join = rng.random((h, w)) < rng.uniform(0.0, 0.95)
    seen = rng.random((h, w)) < rng.uniform(0.01, 0.3)
    if not seen.any():
        seen[h // 2, w // 2] = True
    rows, cols = np.nonzero(seen)
    box = (int(rows.min()), int(rows.max()) + 1, int(cols.min()), int(cols.max()) + 1)
    want = tuple(int(x) for x in _jit._flood_box(join, seen, *box)[1:])
    ok, *got = _jit._reach_fill(join, seen, *box, np.empty(cap, np.int64))
    assert not ok or tuple(int(x) for x in got) == want
    ok, *got = _jit._reach_fill(join, seen, *box, np.empty(5 * h * w + 16, np.int64))
    assert ok and tuple(int(x) for x in got) == want


def test_the_reach_box_past_its_first_stack_known_answer():
    """A seen row of 1,100 pixels in a 3 x 1,200 window of join pixels has 2,200 pixels beside it, more than the
    first try's 1,024 seeds: the second try gives the whole window's box, as _flood_box; a lone join pixel two rows
    below a seen one (a gap between) is not reached, one diagonally beside it is."""
    join = np.ones((3, 1200), bool)
    seen = np.zeros((3, 1200), bool)
    seen[1, 50:1150] = True
    box = (1, 2, 50, 1150)
    assert not _jit._reach_fill(join, seen, *box, np.empty(1024, np.int64))[0]
    assert tuple(int(x) for x in _jit._reach_box(join, seen, *box)) == (0, 3, 0, 1200)
    assert tuple(int(x) for x in _jit._flood_box(join, seen, *box)[1:]) == (0, 3, 0, 1200)
    join = np.zeros((5, 5), bool)
    seen = np.zeros((5, 5), bool)
    seen[1, 1] = True
    join[3, 1] = True  # row 2 between is not join's
    assert tuple(int(x) for x in _jit._reach_box(join, seen, 1, 2, 1, 2)) == (1, 2, 1, 2)
    join[2, 2] = True  # diagonally beside the seen pixel, and beside (3, 1)
    assert tuple(int(x) for x in _jit._reach_box(join, seen, 1, 2, 1, 2)) == (1, 4, 1, 3)


# --- stop 48, compspeed48


@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40), st.integers(0, 45), st.booleans())
def test_square_any_is_its_twins(seed, h, w, radius, want):
    """Blobs (edges, holes, thin parts; squares wider than the array): the pixels with one equal to ``want`` within
    the square clipped to the array, as the twin's maximum filter of ``src == want`` finds them."""
    from scipy import ndimage

    src = _blobs(np.random.default_rng(seed), h, w, 0.3)
    out = np.empty((h, w), bool)
    _jit._square_any(src, radius, want, out)
    assert np.array_equal(out, ndimage.maximum_filter(src == want, size=2 * radius + 1, mode="constant", cval=False))


def test_square_any_known_answer():
    """One true pixel at (1, 4) of a 4 x 7 array, radius 2: true over rows 0-3 and columns 2-6 (clipped), false
    elsewhere; ``want`` False on a full array: nothing."""
    src = np.zeros((4, 7), bool)
    src[1, 4] = True
    out = np.empty((4, 7), bool)
    _jit._square_any(src, 2, True, out)
    want = np.zeros((4, 7), bool)
    want[:, 2:] = True
    assert np.array_equal(out, want)
    _jit._square_any(np.ones((4, 7), bool), 2, False, out)
    assert not out.any()


def test_filled_spans_known_answers():
    """A square ring holds a hole of 3 x 3; with a gap in its wall the inside reaches the edge (not a hole); a
    winding corridor from a ring's inside out through another ring's wall, upwards then down: no hole either. On a
    strided view, as the callers' boxes are."""
    ring = np.zeros((7, 7), bool)
    ring[1, 1:6] = ring[5, 1:6] = ring[1:6, 1] = ring[1:6, 5] = True
    out = np.empty((7, 7), bool)
    _jit.filled(ring, out)
    want = ring.copy()
    want[2:5, 2:5] = True
    assert np.array_equal(out, want)
    ring[3, 5] = False  # a gap in the right wall
    _jit.filled(ring, out)
    assert np.array_equal(out, ring)
    # the inside of the outer ring (rows 1-9, columns 1-11) joins the edge only through the column-10 corridor's
    # top, which the inner wall's row 2 hides from the rows below
    m = np.zeros((11, 13), bool)
    m[0, :] = m[10, :] = m[:, 0] = m[:, 12] = True
    m[0, 10] = False  # the way out: up column 10 to the top edge
    m[2, 1:10] = True
    m[2:9, 9] = True  # a wall: the room below row 2, left of column 9, reaches column 10 only along row 9
    out = np.empty(m.shape, bool)
    _jit.filled(m, out)
    assert np.array_equal(out, m)
    m[9, 1:9] = True  # the room closed at its bottom: rows 3-8, columns 1-8 are a hole
    _jit.filled(m, out)
    want = m.copy()
    want[3:9, 1:9] = True
    assert np.array_equal(out, want)
    big = np.zeros((13, 26), bool)
    big[1:12, ::2] = m
    view, got = big[1:12, ::2], np.empty((11, 13), bool)
    _jit.filled(view, got)
    assert np.array_equal(got, want)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(3, 1200), st.integers(3, 150), st.sampled_from(["blob", "grid", "flat"]))
def test_noise_level_is_noise_measures_noise_to_the_bit(seed, n, queries, kind):
    """Clouds as a view's (a pixel grid's ties straddling the 8th place among them, a flat one): the kernel's noise
    level is ``noise_measures``' second value byte for byte, and the twin's (``SYMFRUIT_KERNELS=numpy``) is that."""
    from symfruit.core.fits import noise_level, noise_measures

    rng = np.random.default_rng(seed)
    if kind == "blob":
        p = rng.normal(size=(n, 3)) * [0.03, 0.03, 0.01] + [0.0, 0.0, 0.5]
    elif kind == "grid":
        u, v = rng.integers(0, 30, n), rng.integers(0, 30, n)
        p = np.stack([u * 1e-3, v * 1e-3, 0.5 + np.round(rng.normal(0.0, 1e-3, n), 4)], axis=1)
    else:
        p = rng.normal(size=(n, 3))
        p[:, 2] = 0.0
    step, k_large = max(1, n // queries), min(30, n)
    got = _jit.noise_level(p, step, min(8, k_large), k_large)
    assert np.float64(got).tobytes() == np.float64(_jit.noise_measures(p, step, min(8, k_large), k_large)[1]).tobytes()
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, lambda: (noise_level(p, queries=queries), noise_measures(p, queries=queries)[1]))
    assert np.float64(fast[0]).tobytes() == np.float64(fast[1]).tobytes()
    assert np.float64(twin[0]).tobytes() == np.float64(twin[1]).tobytes()


def test_noise_level_known_answer():
    """Points on a plane have no noise (0, exactly: the least eigenvalue's median clipped at 0); a NaN point sends
    the kernel to the whole measure, whose noise it returns."""
    rng = np.random.default_rng(5)
    plane = np.zeros((400, 3))
    plane[:, :2] = rng.normal(size=(400, 2))
    assert _jit.noise_level(plane, 10, 8, 30) == _jit.noise_measures(plane, 10, 8, 30)[1]
    assert _jit.noise_level(plane, 10, 8, 30) < 1e-12
    bumpy = plane.copy()
    bumpy[:, 2] = rng.normal(0.0, 0.01, 400)
    bumpy[7, 0] = np.nan
    want = _jit.noise_measures(bumpy, 10, 8, 30)[1]
    got = _jit.noise_level(bumpy, 10, 8, 30)
    assert np.float64(got).tobytes() == np.float64(want).tobytes()


def test_outline_cracks_known_answer():
    """An L of three pixels at window (u0, v0) = (10, 20): the cracks above, then below, left and right, each
    row-major, at half-integers."""
    mask = np.zeros((3, 3), bool)
    mask[1, 1] = mask[2, 1] = mask[2, 2] = True
    got = _jit.outline_cracks(mask, 10, 20)
    want = [[11, 20.5], [12, 21.5]] + [[11, 22.5], [12, 22.5]] + [[10.5, 21], [10.5, 22]] + [[11.5, 21], [12.5, 22]]
    np.testing.assert_array_equal(got, want)


# --- stop 49, compspeed49: the solid of revolution's search in interleaved runs ------------------------------------


def _range_one_run(t: np.ndarray) -> tuple[float, float]:
    """``slice_costs_below``'s range until stop 48: ``min``/``max`` from ``inf``/``-inf`` in one run (numba's and
    Python's ``min(a, b)``: ``b`` only where ``b < a``, so a NaN is passed over)."""
    lo, hi = np.inf, -np.inf
    for x in t.tolist():
        lo = x if x < lo else lo
        hi = x if x > hi else hi
    return lo, hi


@given(st.integers(0, 2**32 - 1), st.integers(0, 40), st.sampled_from(["normal", "specials", "zeros"]))
def test_range4_is_the_one_run_range(seed, n, kind):
    """The four interleaved runs give the one run's least and greatest (any length, the tail shorter than four; NaN
    passed over, infinities, both zeros); where a zero's sign differs, ``t - lo`` and ``hi - lo`` are the same bits,
    which is all that :func:`slice_costs_below` reads of them."""
    rng = np.random.default_rng(seed)
    t = rng.normal(size=n)
    if kind == "specials" and n:
        t[rng.random(n) < 0.3] = rng.choice([np.nan, np.inf, -np.inf, 0.0, -0.0])
    elif kind == "zeros":
        t = rng.choice([0.0, -0.0, 1.0, -1.0], size=n)
    lo, hi = _jit._range4(t, n)
    want_lo, want_hi = _range_one_run(t)
    assert lo == want_lo and hi == want_hi
    with np.errstate(invalid="ignore"):
        for got, want in (((t - lo), (t - want_lo)), (np.float64(hi - lo), np.float64(want_hi - want_lo))):
            np.testing.assert_array_equal(np.asarray(got).view(np.int64), np.asarray(want).view(np.int64))


def test_range4_known_answer():
    """A NaN first and last, the extremes in the tail beyond the last four."""
    t = np.array([np.nan, 3.0, -1.0, 2.0, 0.5, -7.5, 9.0, np.nan])
    assert _jit._range4(t, 8) == (-7.5, 9.0)
    assert _jit._range4(t, 1) == (np.inf, -np.inf)  # nothing but a NaN: the starting values
    assert _jit._range4(t, 6) == (-7.5, 3.0)


@given(st.integers(0, 2**32 - 1), st.integers(0, 600), st.floats(1e-6, 10.0))
def test_clipped_sum4_is_the_clipped_sum(seed, n, thr):
    """Every value clipped at ``thr`` (a NaN counted as ``thr``) and summed, to rounding (another order of the same
    additions), and whether all are below infinity."""
    rng = np.random.default_rng(seed)
    w = rng.exponential(thr, size=n)
    if n and seed % 3 == 0:
        w[rng.integers(n)] = rng.choice([np.nan, np.inf])
    total, finite = _jit._clipped_sum4(w, n, thr)
    clipped = [x if x < thr else thr for x in w.tolist()]
    assert total == pytest.approx(math.fsum(clipped), rel=1e-13, abs=0.0)
    assert finite == bool((w < np.inf).all())


def test_clipped_sum4_known_answer():
    """Five values (a tail of one beyond four), two clipped at 1."""
    w = np.array([0.25, 2.0, 0.5, 0.125, 3.0])
    assert _jit._clipped_sum4(w, 5, 1.0) == (0.25 + 1.0 + 0.5 + 0.125 + 1.0, True)
    w[1] = np.inf
    assert _jit._clipped_sum4(w, 5, 1.0) == (2.875, False)


# --- stop 49, regspeed49 ------------------------------------------------------------------------------------------


def _noise_values(seed: int) -> np.ndarray:
    """Values as the surface's noise medians meet them: a few whole depth units (many ties), noise, a step among equal
    values, or infinities."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 400))
    kind = seed % 4
    if kind == 0:
        return rng.normal(size=n)
    if kind == 1:
        return rng.integers(-3, 4, n) * 0.001
    if kind == 2:
        x = np.full(n, 0.5)
        x[rng.integers(0, n, max(1, n // 10))] = rng.normal(size=max(1, n // 10))
        return x
    return rng.choice([1.0, 2.0, np.inf, -np.inf], n)


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_the_branchless_selection_is_the_quickselect_s(seed):
    """select_lomuto puts the kth smallest value at kth, none larger before and none smaller after: the value select
    puts there; median_lomuto is _median_of's value, deviation_median the two medians' of the former kernels and of
    points.median (without infinities), to the bit."""
    from symfruit.core.points import median

    x = _noise_values(seed)
    k = int(np.random.default_rng(seed + 1).integers(0, len(x)))
    a, b = x.copy(), x.copy()
    _jit.select(a, k)
    _jit.select_lomuto(b, k)
    assert a[k] == b[k] and (b[:k] <= b[k]).all() and (b[k + 1 :] >= b[k]).all()
    assert np.array_equal(np.sort(b), np.sort(x))  # reordered, nothing lost
    assert np.float64(_jit.median_lomuto(x.copy())).tobytes() == np.float64(_jit._median_of(x.copy())).tobytes()
    before = x.copy()
    middle = _jit._median_of(before)
    with np.errstate(invalid="ignore"):
        before = np.abs(before - middle)
    want = _jit._median_of(before)
    assert np.float64(_jit.deviation_median(x.copy())).tobytes() == np.float64(want).tobytes()
    if np.isfinite(x).all():
        assert np.float64(want).tobytes() == np.float64(median(np.abs(x - median(x)))).tobytes()


def test_the_branchless_selection_known_answers():
    """Known medians: one value, two, all equal, an odd run with ties, an even one (the middle two halved)."""
    assert _jit.median_lomuto(np.array([3.0])) == 3.0
    assert _jit.median_lomuto(np.array([4.0, 1.0])) == 2.5
    assert _jit.median_lomuto(np.full(9, 0.25)) == 0.25
    assert _jit.median_lomuto(np.array([5.0, 1.0, 1.0, 3.0, 1.0, 9.0, 3.0])) == 3.0
    assert _jit.median_lomuto(np.array([5.0, 1.0, 2.0, 8.0])) == 3.5
    # |x - 3| of 1, 1, 1, 3, 3, 5, 9: 2, 2, 2, 0, 0, 2, 6 -> 2
    assert _jit.deviation_median(np.array([5.0, 1.0, 1.0, 3.0, 1.0, 9.0, 3.0])) == 2.0


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_finite_positive_is_the_twin_s(seed):
    """finite_positive: numpy's np.isfinite(v) & (v > 0) and v[ok], to the bit (NaN, infinities, zeros of both signs,
    negative values, none left or all)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(0, 300))
    v = rng.choice([np.nan, np.inf, -np.inf, 0.0, -0.0, -1.5, 5e-324, 0.7, 1.25, 3.0], n)
    some = rng.random(n) < 0.5  # fruit's depths among them
    v[some] = rng.uniform(0.1, 3.0, int(np.count_nonzero(some)))
    ok = np.empty(n, bool)
    kept = _jit.finite_positive(v, ok)
    want = np.isfinite(v) & (v > 0)
    assert np.array_equal(ok, want)
    assert kept.dtype == np.float64 and kept.tobytes() == v[want].tobytes()


# --- stop 49, treeseg49


@pytest.mark.parametrize("reach", [0.5, 1.0, 2.5, 3.5, 5.0, 7.2])
def test_the_bridged_depth_at_any_reach(reach):
    """:func:`_jit.bridge_gaps` at reaches other than ``BRIDGE_PX`` (its keys' low bits widen with the reach) against
    a pixel-by-pixel search of the disc: each pixel without depth takes the depth of the least (squared distance,
    column, row) pixel with depth within ``reach``, else 0; windows at the image's edges, depths of three values."""
    rng = np.random.default_rng(int(reach * 10))
    for _ in range(60):
        h, w = (int(v) for v in rng.integers(1, 30, 2))
        z = rng.choice(np.array([0.75, 1.5, 2.25]), (h, w)).astype(np.float32)
        z[rng.random((h, w)) < rng.choice([0.5, 0.8, 0.95])] = 0.0
        r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
        r1, c1 = int(rng.integers(r0 + 1, h + 1)), int(rng.integers(c0 + 1, w + 1))
        got = np.empty((r1 - r0, c1 - c0))
        _jit.bridge_gaps(z, r0, r1, c0, c1, reach, got)
        rows, cols = np.nonzero(z > 0)
        want = z[r0:r1, c0:c1].astype(np.float64)
        for i, j in zip(*np.nonzero(want == 0), strict=True):
            d2 = (rows - (r0 + i)) ** 2 + (cols - (c0 + j)) ** 2
            if len(d2) and d2.min() <= reach * reach:
                best = np.lexsort((rows, cols, d2))[0]
                want[i, j] = z[rows[best], cols[best]]
        np.testing.assert_array_equal(got, want)


def test_the_bridged_depth_of_an_empty_window():
    """An empty window of :func:`_jit.bridge_gaps` writes nothing and does not fail."""
    out = np.empty((0, 3))
    _jit.bridge_gaps(np.ones((4, 4)), 2, 2, 0, 3, 3.5, out)
    assert out.shape == (0, 3)


def _trim_twin(skin, z, part, r0, c0):
    """:func:`symfruit.segment.colour._bridged_skin`'s trim in numpy (its code without the kernel)."""
    from symfruit.segment.colour import convex_hull_mask

    core = skin & (z > 0)
    core[r0 : r0 + part.shape[0], c0 : c0 + part.shape[1]] |= part
    return skin & ((z > 0) | convex_hull_mask(core))


def _trim_case(rng):
    """A skin to trim (a disc, specks), its depth with gaps (none to 95 %), and a part of it inside or on its edge at
    ``(r0, c0)``: ``skin, z, part, r0, c0``."""
    h, w = (int(v) for v in rng.integers(1, 40, 2))
    yy, xx = np.mgrid[:h, :w]
    r = rng.uniform(1, 20)
    skin = (yy - rng.uniform(0, h)) ** 2 + (xx - rng.uniform(0, w)) ** 2 <= r * r
    skin |= rng.random((h, w)) < rng.choice([0.0, 0.05, 0.3])
    z = rng.uniform(0.5, 2.0, (h, w))
    z[rng.random((h, w)) < rng.choice([0.0, 0.1, 0.5, 0.95])] = 0.0
    ph, pw = int(rng.integers(1, h + 1)), int(rng.integers(1, w + 1))
    r0, c0 = int(rng.integers(0, h - ph + 1)), int(rng.integers(0, w - pw + 1))
    part = (rng.random((ph, pw)) < rng.choice([0.0, 0.2, 0.9])) & skin[r0 : r0 + ph, c0 : c0 + pw]
    return skin, z, part, r0, c0


@pytest.mark.parametrize("seed", [0, 1])
def test_the_bridged_trim_is_the_twins(seed):
    """:func:`_jit.bridged_trim` against the numpy trim (Pillow's fill and Qhull with the twins) on 300 skins: discs
    and blobs with gaps in their depth, parts inside and on the edge, specks, empty skins, skins with depth
    throughout (returned as they are)."""
    from symfruit.segment.colour import _pillow_fill

    if not _pillow_fill():
        pytest.skip("the kernel follows Pillow 12.1's fill")
    rng = np.random.default_rng(seed)
    kept = cut = 0
    for _ in range(300):
        skin, z, part, r0, c0 = _trim_case(rng)
        with pytest.MonkeyPatch.context() as mp:
            _, twin = _both(mp, _trim_twin, skin, z, part, r0, c0)
        got, done = _jit.bridged_trim(skin, z, part, r0, c0)
        assert done
        np.testing.assert_array_equal(got, twin)
        kept += int(np.array_equal(got, skin))
        cut += int(not np.array_equal(got, skin))
    assert kept > 30 and cut > 30


def test_the_bridged_trim_known_answer():
    """A skin whose pixels without depth lie inside the hull of those with depth keeps them; one outside (the band
    beyond the rim) is dropped, unless the part reaches past it; a skin with depth throughout is returned itself."""
    skin = np.zeros((5, 9), bool)
    skin[1:4, 1:8] = True
    z = np.where(skin, 1.0, 0.0)
    z[2, 4] = 0.0  # a gap inside
    z[1:4, 7] = 0.0  # a band at the right
    part = np.zeros((1, 1), bool)
    got, done = _jit.bridged_trim(skin, z, part, 0, 0)
    assert done and got[2, 4] and not got[1:4, 7].any() and got[1:4, 1:7].all()
    part[0, 0] = True
    got, _ = _jit.bridged_trim(skin, z, part, 2, 7)  # the part on the band's middle pixel: that pixel is kept
    assert got[2, 7] and not got[1, 7] and not got[3, 7]
    full = np.ones((3, 3), bool)
    same, _ = _jit.bridged_trim(full, np.ones((3, 3)), part, 0, 0)
    assert same is full


# --- stop 49, seg640_49


def test_the_quick_median_is_the_twins():
    """:func:`_jit.median_quick` of 3,000 random arrays (0-3,000 values; drawn from a few values so that they tie, or
    spread; odd and even counts; now and then a NaN) against ``core.points.median`` (``np.median``'s value) and
    :func:`_jit.median_values`, and :func:`_jit.median_of_quick` against :func:`_jit._median_of` without NaN: the same
    value bit for bit (NaN where a value is NaN or there is none), the values left as they were; and a known
    answer."""
    from symfruit.core.points import median

    rng = np.random.default_rng(49)
    ties = 0
    for t in range(3000):
        n = int(rng.integers(0, 3001)) if t % 4 else int(rng.integers(0, 6))
        if t % 3 == 0:
            values = rng.choice(rng.uniform(0.2, 2.0, int(rng.integers(1, 6))), n)
        else:
            values = rng.normal(0.5, 0.05, n)
        if t % 50 == 7 and n:
            values[int(rng.integers(0, n))] = np.nan
        kept = values.copy()
        got = _jit.median_quick(values)
        np.testing.assert_array_equal(values, kept)
        twin = median(values) if n else np.nan  # (np.median warns without a value)
        assert (np.isnan(got) and np.isnan(twin)) or got == twin
        assert np.array_equal(got, _jit.median_values(values.copy()), equal_nan=True)
        if n and not np.isnan(values).any():  # the sphere fits' median (no NaN there)
            assert _jit.median_of_quick(values) == _jit._median_of(values.copy()) == got
        ties += n % 2 == 0 and n > 0 and len(np.unique(values)) < n
    assert ties > 300
    assert _jit.median_quick(np.array([3.0, 1.0, 2.0, 1.0])) == 1.5
    assert _jit.median_quick(np.array([2.0, 1.0, 2.0, 2.0])) == 2.0
    assert _jit.median_quick(np.array([5.0])) == 5.0 and np.isnan(_jit.median_quick(np.zeros(0)))


def _random_piece(rng, h, w):
    """A found piece's inputs as ``_segment_at`` hands them over: a blob and a speck as the part, its weak (red)
    pixels, an owner map's window (other pieces' numbers, 0 and the piece's own 3), a colour window (views of a larger
    image, some pixels green) and depths (float64, holes of 0, an outlying patch), and the part's hull vertices."""
    from symfruit.segment.colour import _hull_vertices

    rr, cc = np.mgrid[:h, :w]
    r, c, rad = rng.uniform(0, h), rng.uniform(0, w), rng.uniform(0.5, 0.6 * max(h, w) + 1.0)
    part = (rr - r) ** 2 + (cc - c) ** 2 <= rad * rad
    part |= rng.random((h, w)) < 0.02
    weak = part & (rng.random((h, w)) < rng.choice([0.0, 0.6, 0.95, 1.0]))
    owner = rng.choice(np.array([0, 0, 0, 3, 5], np.int16), (h, w))
    big = rng.integers(0, 256, (h + 2, w + 3, 3)).astype(np.uint8)
    big[rng.random((h + 2, w + 3)) < 0.2] = (40, 180, 50)  # green: a calyx or a leaf
    color = big[1 : h + 1, 2 : w + 2]
    z = rng.normal(0.6, 0.01, (h, w))
    if rng.random() < 0.5:  # a step: the fruit behind
        z[rng.uniform(0, 1, (h, w)) < 0.3] += 0.08
    z[rng.random((h, w)) < rng.choice([0.0, 0.1, 1.0])] = 0.0
    if rng.random() < 0.3:  # depth only on the red pixels (all of the hull's depths red)
        z[~weak] = 0.0
    if rng.random() < 0.3:  # whole millimetres: ties
        z = np.round(z, 3)
    return part, weak, owner, color, z, _hull_vertices(part)


def _twin_hull(vertices, part, owner, color, surface, red, z, jump):
    """What :func:`_jit.piece_hull`'s hull stands for: ``_surface_hull`` (piece number 3), then ``_depth_consistent``
    against the red pixels."""
    from symfruit.segment.colour import _depth_consistent, _surface_hull

    return _depth_consistent(_surface_hull(vertices, part, owner, 3, color, surface), red, z, jump)


def test_the_piece_calls_are_the_twins(monkeypatch):
    """:func:`_jit.piece_ripe` and :func:`_jit.piece_hull` on 800 random pieces (1-40 px a side, see
    ``_random_piece``) against the calls they stand for, with the kernels and their numpy twins: ``red.any()`` and
    ``_ripe`` of ``part & weak``; ``_surface_hull``, ``_depth_consistent`` against the red pixels and the hull's pixel
    count, count with depth and median depth (``core.points.median``): the same answers, hulls and values."""
    from symfruit.core.points import median
    from symfruit.segment.colour import _ripe

    rng = np.random.default_rng(49)
    hulls = ripe = shared = 0
    for t in range(800):
        h, w = (int(v) for v in rng.integers(1, 41, 2))
        part, weak, owner, color, z, vertices = _random_piece(rng, h, w)
        least = np.float32(rng.choice([0.2, 0.35, -1.0]))
        red = part & weak
        got = _jit.piece_ripe(color, part, weak, least)
        assert got == (red.any() and _ripe(color, red, float(least)))
        ripe += got
        if vertices is None:
            continue
        surface, jump = bool(t % 3), float(rng.choice([0.02, 0.05]))
        hull, area, valid, zm = _jit.piece_hull(vertices, part, weak, owner, 3, color, surface, z, jump)
        for twin in _both(monkeypatch, _twin_hull, vertices, part, owner, color, surface, red, z, jump):
            np.testing.assert_array_equal(hull, twin)
        depths = z[hull & (z > 0)]
        assert area == int(hull.sum()) and valid == len(depths)
        assert (valid == 0 and np.isnan(zm)) or zm == median(depths)
        hulls += valid > 0
        shared += valid > 0 and np.array_equal(hull & (z > 0), red & (z > 0))
    assert ripe > 100 and hulls > 300 and shared > 80


def test_the_piece_hull_known_answer():
    """A 2x4 part in a 3x4 window, its hull the part; depths 1.0, 1.0, 1.2 on three red pixels and 1.1 on the one that
    is not red (the other row without depth): the red median 1.0, the pixel that is not red 0.1 off it, dropped
    beyond a jump of 0.05 (7 pixels, the median the red one's) and kept within 0.2 (8 pixels, the median of four
    depths, (1.0 + 1.1) / 2); a part's pixel that another piece owns stays when it is red."""
    from symfruit.segment.colour import _hull_vertices

    part = np.zeros((3, 4), bool)
    part[:2] = True
    weak = part.copy()
    weak[0, 3] = False
    z = np.zeros((3, 4))
    z[0] = [1.0, 1.0, 1.2, 1.1]
    color = np.zeros((3, 4, 3), np.uint8)
    color[..., 0] = 200
    vertices = _hull_vertices(part)
    owner = np.zeros((3, 4), np.int16)
    hull, area, valid, zm = _jit.piece_hull(vertices, part, weak, owner, 1, color, True, z, 0.05)
    assert hull.tolist() == weak.tolist() and (area, valid, zm) == (7, 3, 1.0)
    owner[1, 0] = 2
    hull, area, valid, zm = _jit.piece_hull(vertices, part, weak, owner, 1, color, True, z, 0.2)
    assert hull.tolist() == part.tolist() and (area, valid, zm) == (8, 4, (1.0 + 1.1) / 2)
    assert _jit.piece_ripe(color, part, weak, np.float32(0.99))
    assert not _jit.piece_ripe(color, part, ~part, np.float32(-1.0))


# --- stop 50, speed50: the backdrop's ring ---------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(6))
def test_backdrop_counts_are_the_twins(monkeypatch, seed):
    """:func:`symfruit.extract.backdrop` by :func:`_jit.backdrop_counts` and by its numpy twin on random masks (a disc
    of 2-40 px radius, cut by the image's edge or not, a few pixels flipped) over depth that is float32 or float64,
    with NaN, 0 and negative pixels, around random points' depths: the same shares and counts (NaN where no ring pixel
    holds depth), whatever the ring's sampling step."""
    from symfruit.extract import backdrop

    rng = np.random.default_rng(seed)
    found = 0
    for t in range(40):
        h, w = (int(v) for v in rng.integers(20, 160, 2))
        rr, cc = np.mgrid[:h, :w]
        radius = float(rng.uniform(2, 40))
        mask = (rr - rng.uniform(-10, h + 10)) ** 2 + (cc - rng.uniform(-10, w + 10)) ** 2 <= radius**2
        mask ^= rng.random((h, w)) < 0.01
        dtype = np.float32 if t % 2 else np.float64
        depth = rng.choice([0.4, 0.5, 0.6, 2.0], size=(h, w)) + rng.normal(0, 0.05, (h, w))
        depth[rng.random((h, w)) < 0.1] = rng.choice([0.0, np.nan, -1.0])
        depth = depth.astype(dtype)
        points = np.column_stack((rng.normal(size=(50, 2)), rng.uniform(0.4, 0.6, 50)))
        kernel, twin = _both(monkeypatch, backdrop, points, mask, depth, float(rng.uniform(300, 900)))
        assert np.array_equal(np.array(kernel, float), np.array(twin, float), equal_nan=True), (t, kernel, twin)
        assert type(kernel[2]) is int or kernel[2] == 0
        found += kernel[2] > 0
    assert found > 20


# --- stop 50, outline50: the registration's outline in fewer calls ------------------------------------------------


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 25), st.booleans())
def test_outline_windows_are_the_taxicab_window_and_the_outline_maps_to_the_bit(seed, reach, wide):
    """``outline_windows`` on masks of every shape: the grown window is scipy's taxicab distance within ``reach``, the
    maps, keys, places and values those of ``outline_maps`` with pad and reach ``reach``, the same arrays bit for
    bit."""
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 200 if wide else 60, 2))
    mask = _blob_mask(rng, h, w)
    grown, inner, inside = np.empty(mask.shape, bool), np.empty(mask.shape), np.empty(mask.shape)
    found = _jit.outline_windows(mask, reach, grown, inner, inside)
    assert np.array_equal(grown, ndimage.distance_transform_cdt(~mask, metric="taxicab") <= reach)
    want_inner, want_inside = np.empty(mask.shape), np.empty(mask.shape)
    want = _jit.outline_maps(mask, reach, reach, want_inner, want_inside)
    assert np.array_equal(inner, want_inner) and np.array_equal(inside, want_inside) and found[0] == want[0]
    for got, expected in zip(found[1:], want[1:], strict=True):
        assert got.dtype == expected.dtype and np.array_equal(got, expected)


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 40))
def test_cap_outline_is_the_caps_outline_and_its_free_points_to_the_bit(seed, least):
    """``cap_outline`` on random caps (blobs with holes, several pieces, touching the array's edges) over depth with
    holes, pixels behind and in front: the cap is the apex's piece (``ndimage.label``'s), its outline
    ``np.nonzero(cap & ~interior(cap))``, and its free points ``_free_points``' numpy twin's, whenever the outline holds
    at least ``least`` points (none computed below)."""
    from scipy import ndimage

    from symfruit.core.raster import interior
    from symfruit.core.surface import _FREE_PX, Surface, _free_far, _free_points, _free_tol

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(2, 90, 2))
    pixels = _blob_mask(rng, h, w) if rng.random() < 0.5 else rng.random((h, w)) < rng.uniform(0.3, 0.9)
    if not pixels.any():
        pixels[0, 0] = True
    where = np.flatnonzero(pixels)
    r, c = divmod(int(where[rng.integers(0, len(where))]), w)
    depth = rng.choice([0.0, 0.45, 0.5, 0.55, 0.7], size=(h, w)) + rng.normal(0, 0.01, (h, w))
    depth[depth < 0.1] = 0.0
    surface = Surface(pixels, 0.5, float(rng.uniform(0.01, 0.08)), float(rng.uniform(0.0, 0.004)), (r, c))
    rows, cols, free = _jit.cap_outline(pixels, r, c, depth, _free_far(surface), _FREE_PX, int(_FREE_PX) + 1, least,
                                        _free_tol(surface))  # fmt: skip
    labels, _ = ndimage.label(pixels)
    cap = labels == labels[r, c]
    want_rows, want_cols = np.nonzero(cap & ~interior(cap))
    assert np.array_equal(rows, want_rows) and np.array_equal(cols, want_cols)
    if len(rows) < least:
        assert len(free) == 0
        return
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        want_free, _ = _free_points(depth, cap, want_rows, want_cols, surface, tol=_free_tol(surface))
    assert free.dtype == want_free.dtype and np.array_equal(free, want_free)


def _free_outline_case(
    rng: np.random.Generator, size: int, *, negative: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """``(depth, cap, rows, cols, far)`` for the ``free_outline`` tests: a random cap (a blob or scattered pixels) up to
    ``size`` pixels a side over depth with holes, pixels behind and in front and NaN, its outline's points or (three
    times in ten) points anywhere, repeated too; with ``negative`` the holes are -0.2 m one time in five (else 0)."""
    from symfruit.core.raster import interior

    h, w = (int(x) for x in rng.integers(2, size, 2))
    cap = _blob_mask(rng, h, w) if rng.random() < 0.5 else rng.random((h, w)) < rng.uniform(0.3, 0.9)
    if not cap.any():
        cap[0, 0] = True
    rows, cols = np.nonzero(cap & ~interior(cap))
    if rng.random() < 0.3:  # points anywhere, repeated too
        n = int(rng.integers(1, 40))
        rows, cols = rng.integers(0, h, n).astype(np.int64), rng.integers(0, w, n).astype(np.int64)
    depth = rng.choice([0.0, 0.45, 0.5, 0.55, 0.7], size=(h, w)) + rng.normal(0, 0.01, (h, w))
    depth[depth < 0.1] = -0.2 if negative and rng.random() >= 0.8 else 0.0
    depth[rng.random((h, w)) < 0.02] = np.nan
    return depth, cap, rows, cols, float(rng.uniform(0.45, 0.6))


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(0.0, 6.5), st.integers(0, 8))
def test_free_outline_is_the_gaps_distance_map_read_at_the_points(seed, reach, pad):
    """``free_outline`` (stop 60: each point's look at the gap pixels about it; stop 62: by each row's running count
    of gap pixels) on random caps over depth with holes, pixels behind and in front, any reach (whole or not) and
    pad (below the reach too), at the outline's points or at points anywhere: the points within ``reach`` of the gap
    made on the points' box grown by ``pad``, as the twin finds them (``within``'s numpy dilation of that gap, read
    at the points), bit for bit."""
    from symfruit.core.surface import within

    depth, cap, rows, cols, far = _free_outline_case(np.random.default_rng(seed), 70)
    free = _jit.free_outline(depth, cap, rows, cols, far, reach, pad)
    r0, c0 = max(int(rows.min()) - pad, 0), max(int(cols.min()) - pad, 0)
    box = (slice(r0, int(rows.max()) + pad + 1), slice(c0, int(cols.max()) + pad + 1))
    gap = ~cap[box] & ((depth[box] <= 0) | (depth[box] >= far))
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        want = within(gap, reach)[rows - r0, cols - c0]
    assert free.dtype == want.dtype and np.array_equal(free, want)


def test_free_outline_known_answers():
    """A 5 x 5 cap in a window without depth but two pixels in front: its outline's points are all free at reach 1
    (the pixel beside each is a gap) but the two points beside those pixels; none is free where the whole window
    holds depth in front; the corner points need reach sqrt(2) where only the diagonal pixels are gaps."""
    cap = np.zeros((9, 9), bool)
    cap[2:7, 2:7] = True
    rows, cols = np.nonzero(cap & ~np.pad(np.ones((3, 3), bool), 3))
    depth = np.zeros((9, 9))
    depth[4, 1] = depth[4, 7] = 0.4  # in front of the fruit's far depth
    free = _jit.free_outline(depth, cap, rows, cols, 0.5, 1.0, 2)
    assert not free[(rows == 4) & ((cols == 2) | (cols == 6))].any()
    assert free[~((rows == 4) & ((cols == 2) | (cols == 6)))].all()
    assert not _jit.free_outline(np.full((9, 9), 0.4), cap, rows, cols, 0.5, 4.0, 5).any()
    diagonal = np.full((9, 9), 0.4)
    diagonal[1, 1] = 0.0
    corner = (rows == 2) & (cols == 2)
    for reach, want in ((1.0, False), (1.4, False), (math.sqrt(2.0), True), (2.0, True)):
        got = _jit.free_outline(diagonal, cap, rows, cols, 0.5, reach, 3)
        assert got[corner].all() == want and not got[~corner].any()


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(0.0, 0.02))
def test_free_outline_with_a_tolerance_is_the_numpy_twins(seed, noise):
    """``free_outline`` with a finite tolerance (stop 62: a lost pixel within reach of depth nearer than the point
    by more than it is an occluder's edge, not a silhouette's) on random caps over depth with holes, pixels behind
    and in front and NaN: ``_free_points``' numpy twin's points, bit for bit; with no tolerance (infinite) the
    former points, which are never fewer."""
    from symfruit.core.raster import interior
    from symfruit.core.surface import _FREE_PX, Surface, _free_far, _free_points, _free_tol

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(2, 70, 2))
    cap = _blob_mask(rng, h, w) if rng.random() < 0.5 else rng.random((h, w)) < rng.uniform(0.3, 0.9)
    if not cap.any():
        cap[0, 0] = True
    rows, cols = np.nonzero(cap & ~interior(cap))
    depth = rng.choice([0.0, 0.45, 0.5, 0.55, 0.7], size=(h, w)) + rng.normal(0, 0.01, (h, w))
    depth[depth < 0.1] = 0.0
    depth[rng.random((h, w)) < 0.02] = np.nan
    surface = Surface(cap, 0.5, float(rng.uniform(0.01, 0.08)), noise, (int(rows[0]), int(cols[0])))
    far, tol, pad = _free_far(surface), _free_tol(surface), int(_FREE_PX) + 1
    free = _jit.free_outline(depth, cap, rows, cols, far, _FREE_PX, pad, tol)
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        want, _ = _free_points(depth, cap, rows, cols, surface, tol=tol)
        former, _ = _free_points(depth, cap, rows, cols, surface)
    assert free.dtype == want.dtype and np.array_equal(free, want)
    before = _jit.free_outline(depth, cap, rows, cols, far, _FREE_PX, pad, np.inf)
    assert np.array_equal(before, former) and not (free & ~before).any()


def _free_outline_walk(depth, cap, rows, cols, far, reach, pad, tol):
    """Stop 62's (leaf62) ``free_outline`` with ``tol`` finite, kept as the test's reference (plain Python): each
    point looks at every gap pixel of its box within ``reach`` (``d <= reach ** 2`` and ``sqrt(d) <= reach``); one
    seen past (at least ``far``) makes it free, and so does one without depth (at most 0) unless a pixel off the cap
    within ``reach`` of that pixel (anywhere in the array) holds depth above 0 nearer than the point's by more than
    ``tol``."""
    h, w = cap.shape
    r0, c0 = max(int(rows.min()) - pad, 0), max(int(cols.min()) - pad, 0)
    r1, c1 = min(int(rows.max()) + pad + 1, h), min(int(cols.max()) + pad + 1, w)
    k = math.floor(reach)
    offsets = [(dr, dc) for dr in range(-k, k + 1) for dc in range(-k, k + 1)
               if dr * dr + dc * dc <= reach * reach and math.sqrt(float(dr * dr + dc * dc)) <= reach]  # fmt: skip
    free = np.zeros(len(rows), bool)
    for i, (r, c) in enumerate(zip(rows.tolist(), cols.tolist(), strict=True)):
        bound = depth[r, c] - tol
        for dr, dc in offsets:
            rr, cc = r + dr, c + dc
            if not (r0 <= rr < r1 and c0 <= cc < c1) or cap[rr, cc]:
                continue
            z = depth[rr, cc]
            if z >= far:
                free[i] = True
                break
            if z <= 0:
                near = [depth[rr + a, cc + b] for a, b in offsets
                        if 0 <= rr + a < h and 0 <= cc + b < w and not cap[rr + a, cc + b]]  # fmt: skip
                m = min([x for x in near if x > 0], default=np.inf)
                if not m < bound:
                    free[i] = True
                    break
    return free


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(0.0, 6.5), st.integers(0, 8), st.floats(0.0, 0.2))
def test_free_outline_with_a_tolerance_is_stop_62s_walk(seed, reach, pad, tol):
    """``free_outline`` with ``tol`` finite (stop 63, occw63: the row counts of pixels seen past and without depth
    first, the occluder test on the points left) on random caps over depth with holes, pixels behind, in front and
    NaN (the point's own too), any reach, pad and tolerance, at the outline's points or at points anywhere: stop
    62's walk's points (:func:`_free_outline_walk`), bit for bit."""
    depth, cap, rows, cols, far = _free_outline_case(np.random.default_rng(seed), 50, negative=True)
    free = _jit.free_outline(depth, cap, rows, cols, far, reach, pad, tol)
    want = _free_outline_walk(depth, cap, rows, cols, far, reach, pad, tol)
    assert free.dtype == want.dtype and np.array_equal(free, want)


def test_free_outline_reads_a_lost_band_beside_something_in_front_as_a_junction():
    """A cap (columns 8-13 of a 12 x 18 window) at 0.5 m; beyond its right side no depth (a silhouette); beyond its
    left side two columns without depth, then a leaf over columns 0-5. With the leaf at 0.45 m (in front) the left
    side's points are not free (the band is the leaf's lost edge, a junction: stop 62), but they are without the
    tolerance (infinite: the rule before), with the leaf at 0.6 m (behind the fruit's rim but nearer than ``far``:
    nothing in front) and with the leaf's band six columns wide (its depth beyond the reach of the band's nearest
    pixel). The right side's points are free throughout."""
    cap = np.zeros((12, 18), bool)
    cap[:, 8:14] = True
    rows, cols = np.nonzero(cap & np.isin(np.arange(18), (8, 13))[None, :])
    left = cols == 8
    for leaf, band, want in ((0.45, 2, False), (0.6, 2, True), (0.45, 6, True)):
        depth = np.zeros((12, 18))
        depth[cap] = 0.5
        depth[:, : 8 - band] = leaf
        free = _jit.free_outline(depth, cap, rows, cols, 0.7, 4.0, 5, 0.003)
        assert (free[left] == want).all() and free[~left].all()
        assert _jit.free_outline(depth, cap, rows, cols, 0.7, 4.0, 5, np.inf).all()


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("reach", [6, 20])
def test_the_registrations_outline_is_the_twins_to_the_bit(monkeypatch, seed, reach):
    """``_outline`` (its window, maps, cap, outline and free points by ``outline_windows`` and ``cap_outline``) with
    the kernels and with the numpy twins on a ball's frame: the same points, signed map, band and sides."""
    from symfruit.core.surface import _outline

    depth, mask, _ = _ball_frame(seed)
    outline, twin = _both(monkeypatch, _outline, depth, mask, 600.0, reach)
    assert outline is not None and twin is not None
    for a, b in ((outline.rows, twin.rows), (outline.cols, twin.cols), (outline.inside, twin.inside),
                 (outline.sides, twin.sides)):  # fmt: skip
        assert np.array_equal(a, b)
    assert outline.band == twin.band


# --- stop 50, observe50: the completion's observe in fewer calls --------------------------------------------------


@settings(max_examples=120, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(0.0, 14.0), st.floats(0.5, 9.0), st.booleans())
def test_observe_maps_are_the_inner_and_outer_distance_to_the_bit(seed, inner_reach, outer_reach, wide):
    """``observe_maps`` on masks of every shape (discs cut by the window's edge, speckle, a whole row, a lone hole,
    empty, full): wherever it says it is done, its maps are ``inner_distance`` and ``outer_distance``'s numpy twins',
    bit for bit; it declines exactly where those take another path (an empty mask, a grown box with no pixel outside
    the mask); and ``distance_maps`` gives the twins' maps either way."""
    from symfruit.core.raster import distance_maps, inner_distance, mask_box, outer_distance

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 160 if wide else 40, 2))
    kind = int(rng.integers(0, 6))
    mask = _blob_mask(rng, h, w) if kind < 4 else np.full((h, w), kind == 5)
    done, inner, outer = _jit.observe_maps(mask, inner_reach, outer_reach)
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        want_inner, want_outer = inner_distance(mask, inner_reach), outer_distance(mask, outer_reach)
        box = mask_box(mask)
        declines = box is None or mask[max(box[0] - 1, 0) : box[1] + 1, max(box[2] - 1, 0) : box[3] + 1].all()
    assert done is not declines
    if done:
        assert np.array_equal(inner, want_inner) and np.array_equal(outer, want_outer)
    got_inner, got_outer = distance_maps(mask, inner_reach, outer_reach)
    assert np.array_equal(got_inner, want_inner) and np.array_equal(got_outer, want_outer)


@pytest.mark.parametrize("seed", range(40))
def test_hidden_seen_is_the_occlusions_at_and_depth_at(monkeypatch, seed):
    """``Occlusion.seen_at`` (``hidden_seen``) with the kernels and with the numpy twins on random windows, depths
    (none, float32, float64, with NaN) and pixels (half-way ones, off the window, off the image): the same hidden
    pixels, and where hidden the same depths (float64), NaN elsewhere; the twin's are ``at`` and ``depth_at``."""
    from symfruit.core.occlusion import Occlusion

    rng = np.random.default_rng(seed)
    width, height = (int(x) for x in rng.integers(20, 120, 2))
    h, w = int(rng.integers(1, height + 1)), int(rng.integers(1, width + 1))
    v0, u0 = int(rng.integers(0, height - h + 1)), int(rng.integers(0, width - w + 1))
    hidden = rng.random((h, w)) < rng.uniform(0.0, 0.8)
    kind = seed % 3
    depth = None if kind == 0 else rng.uniform(0.3, 2.0, (h, w)).astype(np.float32 if kind == 1 else np.float64)
    if depth is not None:
        depth[rng.random((h, w)) < 0.1] = np.nan
    occ = Occlusion(u0, v0, hidden, width, height, depth=depth)
    m = int(rng.integers(0, 300))
    u = np.round(rng.uniform(-5, width + 5, m) * 2) / 2
    v = np.round(rng.uniform(-5, height + 5, m) * 2) / 2
    (hid, seen), (want_hid, want_seen) = _both(monkeypatch, occ.seen_at, u, v)
    assert hid.dtype == bool and np.array_equal(hid, want_hid) and np.array_equal(hid, occ.at(u, v))
    assert seen.dtype == want_seen.dtype == np.float64 and np.array_equal(seen, want_seen, equal_nan=True)
    with monkeypatch.context() as mp:
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        want = np.where(want_hid, occ.depth_at(u, v), np.nan)
    assert np.array_equal(seen, want, equal_nan=True)


# --- stop 51, bands51: observe's bands, both sides, in one call ---------------------------------------------------


def _observation_parts(obs):
    """Every array and number of an observation's bands and of what ``explain`` reads of them (``_bands``)."""
    from symfruit.core.agreement import _bands

    b = _bands(obs)
    return [obs.inner, obs.interior, *obs.rays_in, *obs.rays_out, *(obs.out_weights or ()), *(obs.out_depth or ()),
            obs.out_depth is None, b.rays, b.n_in, b.in_starts, b.in_sizes, b.in_ok, b.out_starts, b.out_w, b.out_wsum,
            b.out_rays, b.out_ok, b.seen, b.finite, obs.contour, obs.cone, obs.rays]  # fmt: skip


def _same_bits(a, b) -> bool:
    """Arrays of one dtype and shape with the same values (NaN where NaN), or equal other values (None, numbers)."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return (isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape
                and np.array_equal(a, b, equal_nan=a.dtype.kind == "f"))  # fmt: skip
    return type(a) is type(b) and a == b


@pytest.mark.parametrize("seed", range(36))
def test_observe_edges_and_bands_are_the_steps_made_one_by_one(monkeypatch, seed):
    """``observe`` with its fused calls and with the steps called one by one, with the kernels and with the numpy
    twins, on views of a ball (a cloud sparser than the pixels or about one point a pixel) with and without occlusion
    information (no depth, float32 and float64 depth with NaN; hidden pixels scattered so that edge labels mix and tie),
    bands that overlap, bands past the map and one ray per band. The fused calls: ``observe_edges``
    (``_observed_edges``, where an inside reach is given: the distance maps, both ``_inside_px`` and
    ``_contour_pixels``), ``observe_bands`` (``_observed_bands``: ``bands_of`` on both sides, ``_band_rays``,
    ``Occlusion.seen_at``, ``_labels_at``, then ``_bands_of_parts``) or with occlusion information ``outline_bands``
    (``_outline_bands``: ``_occluded_edges``, the bands and the cracks' ``_labels_at``). The same maps, interior
    points, rays, weights, seen depths, packed bands, contour share, cracks and cone to the bit."""
    from symfruit.core import agreement
    from symfruit.core.camera import Camera
    from symfruit.core.occlusion import Occlusion
    from symfruit.core.raster import point_pixels, silhouette

    rng = np.random.default_rng(seed)
    camera = Camera(500.0, 500.0, 80.0, 60.0, 160, 120)
    centre = np.array([rng.uniform(-0.05, 0.05), rng.uniform(-0.04, 0.04), rng.uniform(0.3, 0.5)])
    d = rng.normal(size=(3000 if seed % 2 else 30000, 3))  # sparser than the pixels, or about one point a pixel
    ball = 0.03 * d / np.linalg.norm(d, axis=1, keepdims=True) + centre
    visible = ball[ball[:, 2] < centre[2]]  # the near half
    region = silhouette(visible, camera)
    occ = None
    if seed % 4:
        u0, v0 = int(rng.integers(0, region.u0 + 1)), int(rng.integers(0, region.v0 + 1))
        w, h = int(rng.integers(1, camera.width - u0 + 1)), int(rng.integers(1, camera.height - v0 + 1))
        hidden = rng.random((h, w)) < rng.uniform(0.0, 0.4)
        depth = None if seed % 4 == 1 else rng.uniform(0.2, 0.6, (h, w)).astype(np.float32 if seed % 4 == 2 else float)
        if depth is not None:
            depth[rng.random((h, w)) < 0.1] = np.nan
        occ = Occlusion(u0, v0, hidden, camera.width, camera.height, depth=depth)
    bands = [(2.0, 5.0), (3.0,), (2.0, 2.5, 9.0), (1.0, 40.0)][seed // 4 % 4]  # with each kind of occlusion
    n_band = [64, 5, 1, 400][int(rng.integers(0, 4))]
    kwargs = {"n_band": n_band, "bands": bands, "occlusion": occ, "dense": visible if seed % 3 else None,
              "inner_reach": [None, 3.0, 12.0][seed % 3]}  # fmt: skip
    if seed % 3 and seed % 2:
        kwargs["dense_pixels"] = point_pixels(visible, camera)
    made = []

    def counted(real):
        def call(*args):
            found = real(*args)
            made.append((real.__name__, found is not None))
            return found

        return call

    cone_points = []
    real_cone, real_edges = agreement.outline_cone, agreement._observed_edges

    def outline_cone(region, camera, points):  # the cracks beside contour edges, as each path picked them
        cone_points.append(points)
        return real_cone(region, camera, points)

    def observed(mp, packed):
        for name in ("_observed_bands", "_outline_bands"):  # the pieces one by one where not packed
            mp.setattr(agreement, name, counted(getattr(agreement, name)) if packed else (lambda *args: None))
        mp.setattr(agreement, "_observed_edges", counted(real_edges) if packed else (lambda *args: None))
        mp.setattr(agreement, "outline_cone", outline_cone)
        cone_points.clear()
        obs = agreement.observe(visible[::7], region, camera, **kwargs)
        parts = obs._parts
        assert parts is not None and (parts.packed is not None) == packed
        if packed:  # the parts it holds pack to the same bands
            remade = vars(agreement._bands_of_parts(obs.rays, parts)).values()
            assert all(_same_bits(a, b) for a, b in zip(_observation_parts(obs)[-15:-3], remade, strict=True))
        return [*_observation_parts(obs), *cone_points]

    with monkeypatch.context() as mp:
        got, want = observed(mp, True), observed(mp, False)
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        twin = observed(mp, False)
    # with occlusion information the outline's edges, labels and bands in one call, where the normals' labels allow
    # the maps, depths inside the edge and edge normals in one call where an inside reach is given
    edges = [("_observed_edges", True)] if kwargs["inner_reach"] is not None else []
    assert made in (edges + [("_observed_bands", True)], edges + [("_outline_bands", True)],
                    edges + [("_outline_bands", False), ("_observed_bands", True)])  # fmt: skip
    assert made[len(edges)][0] == ("_observed_bands" if occ is None else "_outline_bands")
    assert all(_same_bits(a, b) for a, b in zip(got, want, strict=True))
    # the numpy twins' bands: the same (their edge labels come from the same outline pixels wherever occlusion is given)
    if occ is not None:
        assert all(_same_bits(a, b) for a, b in zip(got[:-3 - len(cone_points)], twin[:-3 - len(cone_points)],
                                                    strict=True))  # fmt: skip


@pytest.mark.parametrize("seed", range(24))
def test_outline_bands_are_the_occluded_edges_bands_and_crack_labels(seed):
    """``_outline_bands`` (``outline_bands``) against ``_occluded_edges``, ``_observed_bands`` and the cracks'
    ``_labels_at`` called one by one, for edge normals' labels none, all true, all false (those it takes) and mixed
    (it declines): the same outline pixels, labels, bands and crack labels (ties: the tree's pick) to the bit."""
    from symfruit.core import agreement
    from symfruit.core.camera import Camera
    from symfruit.core.occlusion import Occlusion
    from symfruit.core.raster import distance_maps, outline_cracks, silhouette

    rng = np.random.default_rng(seed)
    camera = Camera(500.0, 500.0, 80.0, 60.0, 160, 120)
    centre = np.array([rng.uniform(-0.05, 0.05), rng.uniform(-0.04, 0.04), rng.uniform(0.3, 0.5)])
    d = rng.normal(size=(3000, 3))
    ball = 0.03 * d / np.linalg.norm(d, axis=1, keepdims=True) + centre
    region = silhouette(ball[ball[:, 2] < centre[2]], camera)
    h, w = camera.height, camera.width
    hidden = rng.random((h, w)) < rng.uniform(0.0, 0.3)
    occ = Occlusion(0, 0, hidden, w, h, depth=rng.uniform(0.2, 0.6, (h, w)).astype(np.float32))
    inner, outer = distance_maps(region.mask, 8.0, 5.5)
    rays = rng.normal(size=(int(rng.integers(0, 30)), 3))
    kind = seed % 4
    normals = rng.uniform(0, w, (int(rng.integers(1, 40)), 2)) if kind else np.empty((0, 2))
    labels = [None, np.ones(len(normals), bool), np.zeros(len(normals), bool), rng.random(len(normals)) < 0.5][kind]
    labels = np.empty(0, bool) if labels is None else labels
    if kind == 3:
        labels[:2] = True, False  # mixed
    count, radius, share, bands = (
        int(rng.integers(5, 150)),
        int(rng.integers(0, 6)),
        float(rng.uniform(0, 1)),
        (2.0, 5.0),
    )
    jit = kernels.compiled()
    want_kept: dict = {}
    got = agreement._outline_bands(jit, rays, inner, outer, bands, 64, region, camera, normals, labels, occ, count,
                                   radius, share)  # fmt: skip
    if kind == 3:
        assert got is None
        return
    uv, is_contour = agreement._occluded_edges(region, occ, normals, labels, count, radius)
    want = agreement._observed_bands(jit, rays, inner, outer, bands, 64, region, camera, uv, is_contour, occ)
    contour = np.count_nonzero(is_contour) / len(is_contour) if len(is_contour) else 1.0
    cracks = outline_cracks(region)
    want_cracks = agreement._labels_at(uv, is_contour, cracks, want_kept) if share <= contour < 1.0 else None
    assert _same_bits(got[0], uv) and _same_bits(got[1], is_contour)
    for a, b in zip(got[2][:4], want[:4], strict=True):
        assert all(_same_bits(x, y) for x, y in zip(a, b, strict=True))
    assert all(_same_bits(x, y) for x, y in zip(vars(got[2][4]).values(), vars(want[4]).values(), strict=True))
    assert (got[3] is None) == (want_cracks is None)
    if want_cracks is not None:
        assert _same_bits(got[3], want_cracks)


# --- stop 51, seg51: the colour segmenter's speed


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_largest_surface_is_the_twins(seed):
    """``_largest_surface`` (a ground-colour body's surface without depth steps, :func:`_jit.largest_surface`) with the
    kernels and with the twins on random masks over depths with holes and steps (several values: equal pieces, the
    first kept; fewer than 20 pixels with depth: none): the same pixels."""
    from symfruit.segment.colour import _largest_surface

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 40, 2))
    z, mask = _depth_patch(rng, h, w)
    z[rng.random((h, w)) < rng.uniform(0.0, 0.3)] += rng.choice([0.02, 0.05, 0.1])  # steps inside, some at the limit
    jump = float(rng.choice([0.015, 0.02, 0.05]))
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _largest_surface, mask, z, jump)
    assert (fast is None) == (twin is None)
    if fast is not None:
        assert fast.dtype == bool and np.array_equal(fast, twin)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_labelled_pixels_are_the_twins(seed):
    """``_labelled`` (:func:`_jit.label_flat`) with the kernels and with the twins on random masks: the same labels,
    count, flat indices and labels there, of the same types."""
    from symfruit.segment.colour import _labelled

    rng = np.random.default_rng(seed)
    mask = rng.random(tuple(int(x) for x in rng.integers(1, 40, 2))) < rng.uniform(0.0, 1.0)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _labelled, mask)
    assert fast[1] == twin[1]
    for a, b in ((fast[0], twin[0]), (fast[2], twin[2]), (fast[3], twin[3])):
        assert a.dtype == b.dtype and np.array_equal(a, b)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_extent_is_the_twins(seed):
    """``_extent`` (:func:`_jit.widest_pair`) with the kernels and with the twins on a random mask's hull vertices and
    on random float vertices: the same value."""
    from symfruit.segment.colour import _extent, _hull_vertices

    rng = np.random.default_rng(seed)
    mask = rng.random(tuple(int(x) for x in rng.integers(1, 40, 2))) < rng.uniform(0.0, 0.3)
    with pytest.MonkeyPatch.context() as mp:
        vertices = _hull_vertices(mask)
        fast, twin = _both(mp, _extent, vertices, mask)
        assert fast == twin
        points = rng.uniform(-50.0, 50.0, (int(rng.integers(1, 30)), 2))
        fast, twin = _both(mp, _extent, points, mask)
        assert fast == twin


# --- stop 51, surface51: thin_front's passes in one call -----------------------------------------------------------


def _sheet_scene(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[int, int, int, int]]:
    """(depth, mask, window depth, box) of a fruit's cap seen at 0.4-1.5 m: alone, behind a flat or tilted sheet a few
    mm to 3 cm in front over part of its mask (cut at the mask or running on beyond it), with a patch behind, noise of
    0-3 mm, depth repeated from a coarser camera's pixels or rounded to millimetres, holes; the mask cut through its
    front or not. ``depth`` and ``mask`` are the mask's box of the window (``box``: rows and columns there)."""
    h, w = (int(x) for x in rng.integers(40, 110, 2))
    rr, cc = np.mgrid[:h, :w].astype(np.float64)
    cy, cx = rng.uniform(0.35, 0.65) * h, rng.uniform(0.35, 0.65) * w
    r_px = rng.uniform(0.15, 0.35) * min(h, w)
    d2 = (rr - cy) ** 2 + (cc - cx) ** 2
    disc = d2 <= r_px**2
    z0 = rng.uniform(0.4, 1.5)
    r_m = r_px * z0 / 600.0
    depth = np.where(disc, z0 + r_m - np.sqrt(np.clip(r_m**2 - d2 * (z0 / 600.0) ** 2, 0.0, None)), 0.0)
    depth = np.where(disc, depth, z0 + rng.uniform(0.05, 0.4))  # what lies behind
    mask = disc.copy()
    if rng.random() < 0.3:
        mask &= cc <= cx + rng.uniform(-0.3, 0.6) * r_px  # cut through its front: the front reaches the outline
    kind = int(rng.integers(0, 4))
    if kind:
        a = rng.uniform(0, 2 * np.pi)
        side = np.cos(a) * (cc - cx) + np.sin(a) * (rr - cy) < rng.uniform(-0.5, 0.6) * r_px
        sheet = side & (disc if kind == 1 else np.ones_like(disc))
        tilt = rng.uniform(-1.0, 1.0) * 1e-4 if kind == 3 else 0.0
        depth = np.where(sheet, z0 - rng.uniform(0.004, 0.03) + tilt * (cc - cx), depth)
    if rng.random() < 0.3:
        patch = (np.abs(rr - cy - 0.5 * r_px) < 3) & (np.abs(cc - cx) < 6)
        depth = np.where(patch, depth + 0.2, depth)
    noise = float(rng.choice([0.0, 0.0005, 0.001, 0.002, 0.003]))
    depth = depth + rng.normal(0.0, noise, depth.shape)
    coarse = int(rng.integers(1, 3))
    if coarse > 1:  # a coarser camera's pixels repeated
        depth = np.repeat(np.repeat(depth[::coarse, ::coarse], coarse, 0), coarse, 1)[:h, :w]
    if rng.random() < 0.3:
        depth = np.round(depth * 1000.0) / 1000.0
    depth[rng.random(depth.shape) < rng.uniform(0.0, 0.1)] = 0.0
    rows, cols = np.nonzero(mask)
    r0, r1, c0, c1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
    return depth[r0:r1, c0:c1].copy(), mask[r0:r1, c0:c1].copy(), depth, (int(r0), int(c0), int(h), int(w))


def _thin_case(rng: np.random.Generator) -> tuple[tuple, dict]:
    """``thin_front``'s arguments on a :func:`_sheet_scene`, as ``fruit_surface`` makes them (its noise, front, radius
    and the convexity test's tolerance as the join; with the window's depth as ``around`` or not)."""
    from symfruit.core.surface import Around, depth_noise, fruit_depth

    depth, mask, window, (r0, c0, _, _) = _sheet_scene(rng)
    noise = depth_noise(depth, mask)
    radius_px = float(np.sqrt(np.count_nonzero(mask) / np.pi))
    front, radius = fruit_depth(depth[mask], radius_px, 600.0, noise=noise)
    join = max(3.0 * noise, 0.003) + float(rng.choice([0.0, 0.001]))
    big = np.zeros(window.shape, bool)
    big[r0 : r0 + mask.shape[0], c0 : c0 + mask.shape[1]] = mask
    around = Around(window, big, r0, c0) if rng.random() < 0.5 else None
    return (depth, mask, 600.0, front, radius, join, noise), {"around": around}


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_thin_front_by_its_passes_in_one_call_is_the_twins_to_the_bit(seed):
    """``thin_front`` (``thin_passes``: the counts, the outline test, both partitions and their sizes, the 5 x 5
    median and its noise in one call, the fits in numpy between) with the kernels and with the numpy twins on caps
    alone and behind sheets of every kind: the same answer, front and sheet pixels, bit for bit."""
    from symfruit.core.surface import thin_front

    args, kwargs = _thin_case(np.random.default_rng(seed))
    if not np.isfinite(args[3]):
        return
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, thin_front, *args, **kwargs)
    assert (fast is None) == (twin is None)
    if fast is not None:
        assert fast[0] == twin[0] and fast[1].dtype == twin[1].dtype and np.array_equal(fast[1], twin[1])


# --- stop 62, cap62: thin_front's curvature fit compiled, its answer taken where rounding cannot turn it


def _curved_pixels(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(rows, cols, depth)``: 10-2,048 pixels of a blob (a disc, a band, scattered) on a ball's cap, a tilted plane
    or a saddle at 0.3-2 m, with noise of 0-3 mm (``depth`` (h, w), above 0 at the pixels)."""
    h, w = (int(x) for x in rng.integers(20, 120, 2))
    rr, cc = np.mgrid[:h, :w].astype(np.float64)
    cy, cx = rng.uniform(0.3, 0.7) * h, rng.uniform(0.3, 0.7) * w
    z0, scale = rng.uniform(0.3, 2.0), rng.uniform(0.3, 2.0) / 600.0
    x, y = (cc - cx) * scale, (rr - cy) * scale
    kind = int(rng.integers(0, 3))
    if kind == 0:
        r_m = rng.uniform(0.02, 0.2)
        depth = z0 + r_m - np.sqrt(np.clip(r_m**2 - x**2 - y**2, 0.0, None))
    elif kind == 1:
        depth = z0 + rng.uniform(-0.5, 0.5) * x + rng.uniform(-0.5, 0.5) * y
    else:
        depth = z0 + rng.uniform(1.0, 10.0) * (x**2 - y**2)
    depth = np.clip(depth + rng.normal(0.0, float(rng.choice([0.0, 0.001, 0.003])), depth.shape), 0.05, None)
    shape = int(rng.integers(0, 3))
    if shape == 0:
        keep = (rr - cy) ** 2 + (cc - cx) ** 2 <= rng.uniform(2.0, 0.45 * min(h, w)) ** 2
    elif shape == 1:
        keep = np.abs(rr - cy) <= rng.uniform(1.0, 6.0)
    else:
        keep = rng.random((h, w)) < rng.uniform(0.05, 1.0)
    rows, cols = np.nonzero(keep)
    if len(rows) > 2048:
        some = np.sort(rng.choice(len(rows), 2048, replace=False))
        rows, cols = rows[some], cols[some]
    return rows, cols, depth


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_thin_curvature_is_the_twins_fit_to_rounding(seed):
    """``thin_curvature`` on the pixels of a ball's cap, a plane or a saddle (a disc, a band or scattered, 10-2,048
    of them, noise or none): the twin's (``_mean_curvature``) curvature and standard error to 10 times the rounding's
    scale, their size times the condition number it reports (at least 1) times the double's epsilon (3,000 seeds: at
    most 0.64 times; ``_clearly_convex`` trusts it 1e4 times that far from its bound); where the twin's fit is
    singular, no answer."""
    from symfruit.core.surface import _mean_curvature

    rows, cols, depth = _curved_pixels(np.random.default_rng(seed))
    if len(rows) < 10:
        return
    done, kappa, error, condition = _jit.thin_curvature(rows, cols, depth, 600.0)
    want_kappa, want_error = _mean_curvature(rows, cols, depth[rows, cols], 600.0)
    if not done:
        assert not np.isfinite(want_kappa)
        return
    assert condition >= 1.0
    if not np.isfinite(want_kappa):  # the twin's LAPACK found the matrix singular where the kernel's pivots did not
        assert condition > 1e12
        return
    tol = 10.0 * (abs(want_kappa) + abs(want_error) + 1.0) * condition * np.finfo(np.float64).eps
    assert kappa == pytest.approx(want_kappa, abs=tol) and error == pytest.approx(want_error, abs=tol)


def test_thin_curvature_known_answers():
    """A ball's cap within half its radius reads its inverse radius, a tilted plane nothing, as the twin's; one row
    of pixels (no y at all) is singular, for both."""
    from symfruit.core.surface import _mean_curvature

    yy, xx = np.mgrid[:120, :160]
    d2 = (xx - 80.0) ** 2 + (yy - 60.0) ** 2
    r_m, front = 20 * 0.5 / 600.0, 0.5
    depth = np.where(d2 <= 400, front + r_m - np.sqrt(np.clip(r_m**2 - d2 * (front / 600.0) ** 2, 0, None)), 1.0)
    rows, cols = np.nonzero(d2 <= 100)
    done, kappa, error, _ = _jit.thin_curvature(rows, cols, depth, 600.0)
    assert done and kappa * r_m == pytest.approx(1.0, abs=0.1) and error * r_m < 0.05
    assert kappa == pytest.approx(_mean_curvature(rows, cols, depth[rows, cols], 600.0)[0], rel=1e-9)
    plane = 1.0 / (2.0 - 1e-3 * xx + 5e-4 * yy)
    done, kappa, error, _ = _jit.thin_curvature(rows, cols, plane, 600.0)
    assert done and abs(kappa * r_m) < 1e-6 and error * r_m < 1e-6
    line = np.full(40, 60, np.int64), np.arange(60, 100, dtype=np.int64)
    done, kappa, _, _ = _jit.thin_curvature(*line, depth, 600.0)
    assert not done and not np.isfinite(_mean_curvature(*line, depth[line], 600.0)[0])


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([None, -1e-15, 0.0, 1e-15, 1e-9, -1e-6, 1e-3]))
def test_clearly_convex_answers_as_the_twins_fit_even_at_the_bound(seed, at):
    """``_clearly_convex`` (the compiled fit where its answer is certain, else the twin's) answers as the twin's test
    ``(kappa - 2 inflate error) radius >= THIN[0]`` on the twin's fit, on any pixels (more than 2,048: both draw the
    same), and with the radius put at the bound (``at``: its relative offset there), where rounding decides."""
    from symfruit.core.surface import THIN, _clearly_convex, _mean_curvature

    rng = np.random.default_rng(seed)
    rows, cols, depth = _curved_pixels(rng)
    if len(rows) < 10:
        return
    if rng.random() < 0.2:  # more than the fit's 2,048 pixels: both draw the same ones
        rows, cols = np.nonzero(depth > 0)
    inflate = float(rng.uniform(1.0, 2.0))
    kappa, error = _mean_curvature(rows, cols, depth[rows, cols], 600.0)
    radius = float(rng.uniform(0.01, 0.2))
    if at is not None and np.isfinite(kappa) and kappa - 2.0 * inflate * error > 0:
        radius = THIN[0] / (kappa - 2.0 * inflate * error) * (1.0 + at)
    want = bool((kappa - 2.0 * inflate * error) * radius >= THIN[0])
    assert _clearly_convex(_jit, rows, cols, depth, 600.0, inflate, radius) == want


def test_thin_passes_reach_every_answer_and_give_the_twins_parts():
    """``thin_passes`` on 120 :func:`_sheet_scene` cases reaches each of its answers, and where it hands a partition
    back, its labels, sizes and near counts are ``_smooth_parts``' and ``_part_sizes``' numpy twins' (of the depth at
    the join, or of the 5 x 5 median at its narrower join); where it asks for the fit, the pixels are
    ``_thin_counts``'; its counts and ``ok`` always are."""
    import symfruit.core.surface as surface

    seen = set()
    for seed in range(120):
        (depth, mask, _, front, _, join, noise), _ = _thin_case(np.random.default_rng(seed))
        if not np.isfinite(front):
            continue
        with pytest.MonkeyPatch.context() as mp:
            mp.setenv("SYMFRUIT_KERNELS", "numpy")
            want_ok, want_counts, want_rows, want_cols = surface._thin_counts(depth, mask, front, join)
            parts, count = surface._smooth_parts(depth, mask, join)
            smooth, diff = surface._lag_differences(surface._window_medians(depth, want_ok), want_ok, mask, 5)
            sigma = 1.4826 * float(surface.median(np.abs(diff - surface.median(diff)))) / np.sqrt(2.0) if len(
                diff) else 0.0  # fmt: skip
            narrow = min(join, max(3.0 * sigma, 0.003))
            smoothed, smooth_count = surface._smooth_parts(smooth, mask, narrow)
        ok, counts, labels = np.empty(depth.shape, bool), np.empty(5, np.int64), np.empty(depth.shape, np.int32)
        answers = []
        for stage in (0, 1, 2):
            answer, rows, cols, n, sizes, near = _jit.thin_passes(depth, mask, front, join, noise, stage, ok, counts,
                                                                  labels)  # fmt: skip
            assert np.array_equal(ok, want_ok) and np.array_equal(counts, want_counts)
            answers.append(answer)
            if answer == _jit.THIN_FIT:
                assert np.array_equal(rows, want_rows) and np.array_equal(cols, want_cols)
            if answer in (_jit.THIN_SHEET, _jit.THIN_SMOOTHED):
                p, k = (parts, count) if answer == _jit.THIN_SHEET else (smoothed, smooth_count)
                assert n == k and np.array_equal(labels, p)
                want_sizes, want_near = surface._part_sizes(p, k, depth, front, join)
                assert np.array_equal(sizes, want_sizes) and np.array_equal(near, want_near)
        # stage 0 goes on as stage 1 unless it asks for the fit, stage 1 as stage 2 unless it hands a partition back
        assert answers[0] in (_jit.THIN_FIT, answers[1]) and answers[1] in (_jit.THIN_SHEET, answers[2])
        assert answers[2] in (_jit.THIN_NONE, _jit.THIN_SMOOTHED)
        seen.update(answers)
    assert seen == {_jit.THIN_NONE, _jit.THIN_FIT, _jit.THIN_SHEET, _jit.THIN_SMOOTHED}


# --- stop 51, surface51: fruit_surface's depth mode and its cap in one call each -----------------------------------


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans(), st.booleans())
def test_mask_values_are_the_noise_depths_and_step_to_the_bit(seed, with_leafy, odd):
    """``mask_values`` (then ``depth_mode`` on its depths) on :func:`_sheet_scene`'s masks (with leaf pixels
    or not; with NaN, infinite and negative depths, and few pixels, or not): ``depth_noise``'s and ``depth_step``'s
    numpy twins' numbers, and the mask's depths and leaf pixels as ``fruit_depth`` keeps them (its twin's front and
    radius from them, bit for bit, wherever its kernel says it is done)."""
    from symfruit.core.surface import LEAFY, depth_noise, depth_step, fruit_depth

    rng = np.random.default_rng(seed)
    depth, mask, _, _ = _sheet_scene(rng)
    if odd:
        depth[rng.random(depth.shape) < 0.05] = rng.choice([np.nan, np.inf, -0.5])
        mask &= rng.random(mask.shape) < rng.choice([0.02, 0.5, 1.0])
    leafy = rng.random(depth.shape) < rng.uniform(0.0, 1.0)
    radius_px = float(np.sqrt(np.count_nonzero(mask) / np.pi))
    noise, kept, leaf, step = _jit.mask_values(depth, mask, leafy if with_leafy else np.zeros((0, 0), bool),
                                               with_leafy, 0.0005)  # fmt: skip
    front, radius, done = _jit.depth_mode(kept, radius_px, 600.0, noise, leaf, with_leafy,
                                          (float(LEAFY[0]), float(LEAFY[1])))  # fmt: skip
    with pytest.MonkeyPatch.context() as mp, np.errstate(invalid="ignore"):  # inf - inf: NaN, left out there
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        want_noise = depth_noise(depth, mask)
        want = fruit_depth(depth[mask], radius_px, 600.0, noise=want_noise, leafy=leafy[mask] if with_leafy else None)
        want_step = depth_step(depth, mask)
    assert noise == want_noise and step == want_step
    valid = np.isfinite(depth[mask]) & (depth[mask] > 0)
    assert np.array_equal(kept, depth[mask][valid]) and np.array_equal(leaf, leafy[mask][valid] if with_leafy else [])
    if done:
        assert np.array_equal((front, radius), want, equal_nan=True)
    else:
        assert math.isnan(front) and math.isnan(radius)


def _surface_case(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, dict]:
    """A window's depth and mask (:func:`_sheet_scene`'s) and ``fruit_surface``'s keywords as its callers give them:
    the registration's (a region grown beyond the mask, the mask's distance map, no unit, ``thin``) or extraction's
    (leaf pixels, ``thin`` and ``crossing``; the convexity test off, an infinite tolerance, now and then)."""
    from scipy import ndimage

    from symfruit.core.raster import inner_distance

    _, _, depth, (r0, c0, h, w) = _sheet_scene(rng)
    _, mask, _, _ = _sheet_scene(np.random.default_rng(int(rng.integers(2**32))))
    big = np.zeros((h, w), bool)
    mh, mw = min(mask.shape[0], h - r0), min(mask.shape[1], w - c0)
    big[r0 : r0 + mh, c0 : c0 + mw] = mask[:mh, :mw]
    if rng.random() < 0.5:
        grown = ndimage.binary_dilation(big, iterations=int(rng.integers(1, 8)))
        return depth, big, {"region": grown, "inner": inner_distance(big), "step": 0.0, "thin": True}
    leafy = rng.random((h, w)) < rng.uniform(0.0, 1.0)
    tolerance = np.inf if rng.random() < 0.2 else 3.0
    return depth, big, {"leafy": leafy, "thin": True, "crossing": True, "tolerance": tolerance}


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_fruit_surface_by_its_compiled_measures_and_cap_is_the_twins_to_the_bit(seed, fresh):
    """``fruit_surface`` (``mask_values``, ``thin_passes`` and ``surface_cap`` with the fits and the principal widths
    between) with the kernels and with the numpy twins, as the registration and extraction call it on a cap alone
    and behind sheets: the same pixels, front, radius, noise and apex, bit for bit; ``fresh``: the sectors' table
    not made yet (so the first cap reaching beyond 64 px from its apex is left to ``monotone_region``, which grows
    it)."""
    import symfruit.core.surface as surface

    depth, mask, kwargs = _surface_case(np.random.default_rng(seed))
    with pytest.MonkeyPatch.context() as mp:
        if fresh:
            mp.setattr(surface, "_SECTORS", {})
        fast, twin = _both(mp, surface.fruit_surface, depth, mask, 600.0, **kwargs)
    assert (fast is None) == (twin is None)
    if fast is not None:
        assert (fast.front, fast.radius, fast.noise, fast.apex) == (twin.front, twin.radius, twin.noise, twin.apex)
        assert fast.pixels.dtype == twin.pixels.dtype and np.array_equal(fast.pixels, twin.pixels)


def test_surface_cap_reaches_each_answer():
    """``surface_cap`` on a disc's depth: no pixel in the slab (0); the cap done (1), its pixels ``monotone_region``'s
    or'd with the deep ones (the distance map given, or told without it: stop 64); left to the caller (2), the map
    made in the call as ``inner_distance`` makes it where none was given, with the tolerance infinite or the
    sectors' table too small for the apex's farthest pixel, the apex the same; and (3) the map left to the caller too
    where the mask fills its box grown by a pixel."""
    from scipy import ndimage

    from symfruit.core.raster import inner_distance
    from symfruit.core.surface import _sector_table, monotone_region

    yy, xx = np.mgrid[:90, :150]
    d2 = (yy - 45.0) ** 2 + (xx - 75.0) ** 2
    mask = d2 <= 30.0**2
    depth = np.where(mask, 0.5 + d2 * 1e-5, 0.9)
    inner = ndimage.distance_transform_edt(mask)
    table = _sector_table(72, 80)
    mid = table.shape[0] // 2
    small = table[mid - 40 : mid + 41, mid - 40 : mid + 41].copy()  # offsets within 40 px alone
    answers = []
    for low, high, tol, tab in ((0.1, 0.2, 0.003, table), (0.49, 0.6, 0.003, table), (0.49, 0.6, np.inf, table),
                                (0.49, 0.6, 0.003, small)):  # fmt: skip
        near, out = np.empty(mask.shape, bool), np.zeros(mask.shape, bool)
        for have in (True, False):
            made = inner.copy() if have else np.zeros(mask.shape)
            out[:] = False
            answer, r, c = _jit.surface_cap(depth, mask, mask, 15, 45, 76, 106, 4, low, high, made, have, 8.0, tab,
                                            72, tol, near, out)  # fmt: skip
            answers.append(answer)
            if answer:
                assert (r, c) == (45, 75) and np.array_equal(near, mask & (depth >= low) & (depth <= high))
            if answer == 1:
                deep = (inner if have else inner_distance(mask, 8.0)) > 8.0
                assert np.array_equal(out, monotone_region(depth, near, (45, 75), tol) | (near & deep))
                assert have or not made.any()  # stop 64: the deep pixels told without the map (deep_pixels)
            if answer == 2:
                assert have or np.array_equal(made, inner_distance(mask, 8.0))  # the caller's to read
    assert answers == [0, 0, 1, 1, 2, 2, 2, 2]
    full = np.ones(mask.shape, bool)  # its box grown by a pixel (clipped) all the mask's
    near, out = np.empty(mask.shape, bool), np.zeros(mask.shape, bool)
    answer, r, c = _jit.surface_cap(depth, full, full, 0, 0, 90, 150, 4, 0.49, 0.6, np.zeros(mask.shape), False, 8.0,
                                    table, 72, 0.003, near, out)  # fmt: skip
    assert answer == 3 and not out.any()


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 4), st.booleans())
def test_the_depth_mode_without_the_sort_is_fruit_depths_to_the_bit(seed, kind, with_leafy):
    """``depth_mode`` (the depths not sorted) on depths of every kind (a fruit before a background, three layers,
    millimetre steps with many equal values, a few depths, one value over and over, far-apart outliers; leaf pixels
    or not): ``fruit_depth``'s kernel's numbers on the sorted depths, and where that declines it declines too; the
    numpy twin's front and radius wherever it is done."""
    from symfruit.core.surface import LEAFY, fruit_depth

    rng = np.random.default_rng(seed)
    n = int(rng.choice([3, 9, 10, 11, 12, 40, 400, 3000]))
    if kind == 0:
        kept = np.concatenate((rng.uniform(0.5, 0.53, n), rng.uniform(0.6, 1.2, int(rng.integers(0, n + 1)))))
    elif kind == 1:
        kept = np.concatenate([rng.normal(z, 0.003, int(rng.integers(1, n + 1))) for z in (0.45, 0.5, 0.8)])
    elif kind == 2:
        kept = np.round(rng.uniform(0.5, 0.6, n) * 1000.0) / 1000.0
    elif kind == 3:
        kept = np.full(n, rng.uniform(0.3, 2.0))
    else:
        kept = np.concatenate((rng.uniform(0.5, 0.52, n), rng.uniform(5.0, 60.0, 3)))
    kept = np.abs(kept) + 1e-6
    rng.shuffle(kept)
    leaf = rng.random(len(kept)) < rng.uniform(0.0, 1.0) if with_leafy else np.zeros(0, bool)
    shares = (float(LEAFY[0]), float(LEAFY[1]))
    radius_px, noise = float(rng.uniform(3.0, 60.0)), float(rng.choice([0.0005, 0.002, 0.01]))
    got = _jit.depth_mode(kept, radius_px, 600.0, noise, leaf, with_leafy, shares)
    want = _jit.fruit_depth(np.sort(kept), kept, radius_px, 600.0, noise, leaf, with_leafy, shares)
    assert got[2] == want[2] and np.array_equal(got[:2], want[:2], equal_nan=True)
    if got[2]:
        with pytest.MonkeyPatch.context() as mp:
            mp.setenv("SYMFRUIT_KERNELS", "numpy")
            twin = fruit_depth(kept, radius_px, 600.0, noise=noise, leafy=leaf if with_leafy else None)
        assert np.array_equal(got[:2], twin, equal_nan=True)


# --- stop 52, register52: fruit_surface's mask box, measures and depth mode in one call ------------------------------


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans(), st.booleans(), st.integers(0, 9))
def test_mask_mode_is_the_box_measures_and_depth_mode_to_the_bit(seed, with_leafy, odd, where):
    """``mask_mode`` on a window holding one of :func:`_sheet_scene`'s masks (anywhere in it, at its border, or
    none: ``where`` 0), with leaf pixels or not, with NaN, infinite and negative depths and sparse masks or not: the
    box ``mask_box`` finds, the mask's count, ``mask_values``' noise, depths, leaf pixels and step on that box and
    ``depth_mode``'s front and radius, bit for bit; and the numpy twins' (``mask_box``, ``depth_noise``,
    ``depth_step``, ``fruit_depth``) wherever the depth mode is done."""
    from symfruit.core.raster import mask_box
    from symfruit.core.surface import LEAFY, depth_noise, depth_step, fruit_depth

    rng = np.random.default_rng(seed)
    _, mask, depth, (r0, c0, h, w) = _sheet_scene(rng)
    depth = np.ascontiguousarray(depth, dtype=np.float64)
    window = np.zeros(depth.shape, bool)
    if where:  # the mask moved to a corner or an edge now and then (boxes from row or column 0, or to the end)
        a = 0 if where == 1 else depth.shape[0] - min(mask.shape[0], depth.shape[0]) if where == 2 else min(r0, h)
        b = 0 if where == 3 else depth.shape[1] - min(mask.shape[1], depth.shape[1]) if where == 4 else min(c0, w)
        mh, mw = min(mask.shape[0], depth.shape[0] - a), min(mask.shape[1], depth.shape[1] - b)
        window[a : a + mh, b : b + mw] = mask[:mh, :mw]
    if odd:
        depth[rng.random(depth.shape) < 0.05] = rng.choice([np.nan, np.inf, -0.5])
        window &= rng.random(depth.shape) < rng.choice([0.02, 0.5, 1.0])
    leafy = rng.random(depth.shape) < rng.uniform(0.0, 1.0)
    shares = (float(LEAFY[0]), float(LEAFY[1]))
    got = _jit.mask_mode(depth, window, leafy if with_leafy else np.zeros((0, 0), bool), with_leafy, 0.0005, 615.0,
                         shares)  # fmt: skip
    box = mask_box(window)
    assert got[0] == (box is not None)
    if box is None:
        return
    assert got[1:5] == box and got[5] == np.count_nonzero(window)
    own, own_depth, own_leaf = (x[box[0] : box[1], box[2] : box[3]] for x in (window, depth, leafy))
    radius_px = float(np.sqrt(np.count_nonzero(own) / np.pi))
    noise, kept, leaf, step = _jit.mask_values(own_depth, own, own_leaf if with_leafy else np.zeros((0, 0), bool),
                                               with_leafy, 0.0005)  # fmt: skip
    mode = _jit.depth_mode(kept, radius_px, 615.0, noise, leaf, with_leafy, shares)
    assert got[6] == noise and got[9] == step and np.array_equal(got[7], kept) and np.array_equal(got[8], leaf)
    assert got[12] == mode[2] and np.array_equal(got[10:12], mode[:2], equal_nan=True)
    with pytest.MonkeyPatch.context() as mp, np.errstate(invalid="ignore"):  # inf - inf: NaN, left out there
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        assert mask_box(window) == box
        want_noise = depth_noise(own_depth, own)
        want = fruit_depth(own_depth[own], radius_px, 615.0, noise=want_noise,
                           leafy=own_leaf[own] if with_leafy else None)  # fmt: skip
        want_step = depth_step(own_depth, own)
    assert got[6] == want_noise and got[9] == want_step
    if got[12]:
        assert np.array_equal(got[10:12], want, equal_nan=True)


def test_mask_mode_of_a_known_mask():
    """A 5 x 4 block of depth 0.5 m (one pixel with none) at rows 3-7, columns 2-5 of a 12 x 10 window: its box and
    count, the 19 depths kept, and the front at 0.5 m; an empty mask: none found."""
    depth = np.full((12, 10), 0.9)
    depth[3:8, 2:6] = 0.5
    depth[4, 3] = 0.0
    mask = np.zeros((12, 10), bool)
    mask[3:8, 2:6] = True
    found, r0, r1, c0, c1, count, _, kept, _, _, front, radius, done = _jit.mask_mode(
        depth, mask, np.zeros((0, 0), bool), False, 0.0005, 600.0, (0.5, 0.3))  # fmt: skip
    assert found and (r0, r1, c0, c1) == (3, 8, 2, 6) and count == 20
    assert np.array_equal(kept, np.full(19, 0.5)) and done and front == 0.5
    assert radius == pytest.approx(math.sqrt(20 / math.pi) * 0.5 / 600.0)
    assert not _jit.mask_mode(depth, np.zeros((12, 10), bool), np.zeros((0, 0), bool), False, 0.0005, 600.0,
                              (0.5, 0.3))[0]  # fmt: skip


def test_the_kernels_load_where_numba_finds_no_folder_to_cache_them():
    """Stop 52 (robust52): a user who can write neither beside the installed package nor a home of their own (the
    nobody user, HOME=/nonexistent, a root-owned site-packages) got numba's traceback ("cannot cache function
    '_occlusion_pass': no locator available") from every command that runs a kernel: one kernel was decorated with
    numba.njit(cache=True) itself, not through _njit_inlined's fallback to no cache. Here numba is left no cache
    locator at all and the kernels module imported (nothing compiles until a kernel is called)."""
    import subprocess
    import sys

    code = ("import numba.core.caching as c; c.CacheImpl._locator_classes = []; import symfruit.core._jit as j; "
            "print('loaded', len([k for k in vars(j).values() if hasattr(k, 'py_func')]))")  # fmt: skip
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})  # fmt: skip
    assert done.returncode == 0, done.stderr[-300:]
    assert done.stdout.startswith("loaded ") and int(done.stdout.split()[1]) > 10


# --- stop 52, round52: the round fruit's pieces in fewer calls


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_hull_area_is_the_twins(seed):
    """``_hull_area_of`` (:func:`_jit.hull_area_of`) with the kernels and with the twins on random masks' hull vertices
    (whole numbers), on random whole-number polygons (1 to 300 vertices: numpy's sum one by one, in eight lanes and
    split in halves) out to the kernel's bound of 2 ** 15 and past it (the twin's numpy then), and on vertices that
    are not whole numbers (numpy too): the same value."""
    from symfruit.segment.colour import _hull_area, _hull_area_of, _hull_vertices

    rng = np.random.default_rng(seed)
    shape = tuple(int(x) for x in rng.integers(1, 400, 2))
    yy, xx = np.indices(shape)
    r = rng.uniform(0.5, 0.6) * min(shape)
    mask = ((yy - shape[0] / 2) ** 2 + (xx - shape[1] / 2) ** 2 <= r * r) | (rng.random(shape) < 0.001)
    big = float(rng.choice([64.0, 32768.0, 32769.0, 1e6]))
    polygons = [
        rng.integers(-int(big), int(big) + 1, (int(rng.integers(1, 300)), 2)).astype(np.float64),
        rng.uniform(0.0, 100.0, (int(rng.integers(1, 30)), 2)),
        np.round(rng.uniform(0.0, 100.0, (int(rng.integers(1, 30)), 2)) * 2.0) / 2.0,
    ]
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _hull_area, mask)
        assert fast == twin
        for v in [_hull_vertices(mask), *polygons]:
            fast, twin = _both(mp, _hull_area_of, v, mask)
            assert type(fast) is float and fast == twin


def test_the_hull_area_of_a_square():
    """The hull of a filled 3 x 4 block: its pixels, 12 (the centres' rectangle 2 x 3, half its perimeter 5, 1)."""
    from symfruit.segment.colour import _hull_area_of

    v = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 2.0], [0.0, 2.0]])
    assert _jit.hull_area_of(v) == _hull_area_of(v, np.ones((3, 4), bool)) == 12.0
    assert _jit.hull_area_of(v + 0.5) == -1.0


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans(), st.sampled_from([0.0, 0.5, 0.97]))
def test_the_skin_seed_is_the_twins(seed, front, holes):
    """A blush crescent beside ground colour in front of it or at its depth (``_blush_scene``), with more depth missing
    (too few depths to grow from: none is taken): ``_skin_seed`` (:func:`_jit.skin_seed`) gives the window, mask,
    depth count, median depth and centre of the twin's calls (the part's depths, ``_blush_rim``, ``median``,
    ``np.nonzero``'s means), bit for bit, and ``_round_skin`` the same skin with the kernels and with the twins."""
    from symfruit.core.points import median
    from symfruit.segment.colour import SegmentSettings, _blush_rim, _Depth, _Geometry, _round_skin, _skin_seed

    part, sl, big_z, big_c, big_o = _blush_window(np.random.default_rng(seed), front, holes)
    h, w = big_z.shape
    s = SegmentSettings(round_fruit=True, ground_colour=True)
    got = _skin_seed(sl, part, _Depth(big_z), big_c, s, big_o, 1)
    assert got is not None
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        assert _skin_seed(sl, part, _Depth(big_z), big_c, s, big_o, 1) is None
        z_sl = big_z[sl]
        window, mask, z_part = _blush_rim(sl, part, z_sl[part & (z_sl > 0)], _Depth(big_z), big_c, s, big_o, 1)
    assert got[0] == window and got[1].dtype == bool and np.array_equal(got[1], mask) and got[2] == len(z_part)
    if len(z_part) >= 20:
        rows, cols = np.nonzero(mask)
        want = (float(median(z_part)), int(mask.sum()), float(rows.mean()), float(cols.mean()))
        assert np.array_equal(np.array(got[3:]).view(np.uint64), np.array(want).view(np.uint64))
    if not front or holes > 0.9:
        assert window == sl  # the ring at the crescent's depth, or too few depths to tell
    elif holes == 0.0:
        assert window != sl  # the ring in front taken
    geo = _Geometry(600.0, h / 2, w / 2)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _round_skin, sl, part, _Depth(big_z), big_c, geo, s, big_o, 1)
    assert fast[0] == twin[0] and np.array_equal(fast[1], twin[1])


def test_the_round_piece_is_the_twins(monkeypatch):
    """:func:`_jit.round_piece` on 600 random pieces (``_random_piece``) against the calls it stands for, with the
    kernels and their numpy twins: ``red.any()`` and ``_ripe`` of ``part & weak`` (0: not ripe), then
    ``_surface_hull`` and ``_depth_consistent`` against the red pixels (1 and the hull): the same answers and hulls."""
    from symfruit.segment.colour import _pillow_fill, _ripe

    if not _pillow_fill():
        pytest.skip("the kernel follows Pillow 12.1's fill")
    rng = np.random.default_rng(52)
    unripe = hulls = 0
    for t in range(600):
        h, w = (int(v) for v in rng.integers(1, 41, 2))
        part, weak, owner, color, z, vertices = _random_piece(rng, h, w)
        if vertices is None:
            continue
        least = np.float32(rng.choice([0.2, 0.35, -1.0]))
        red = part & weak
        surface, jump = bool(t % 3), float(rng.choice([0.02, 0.05]))
        state, hull = _jit.round_piece(color, part, weak, least, vertices, owner, 3, surface, z, jump)
        if not (red.any() and _ripe(color, red, float(least))):
            assert state == 0 and hull.shape == (0, 0)
            unripe += 1
            continue
        assert state == 1
        for twin in _both(monkeypatch, _twin_hull, vertices, part, owner, color, surface, red, z, jump):
            np.testing.assert_array_equal(hull, twin)
        hulls += 1
    state, _ = _jit.round_piece(color, part, weak, np.float32(-1.0), vertices + 0.5, owner, 3, True, z, 0.02)
    assert state == 2  # not whole numbers: Pillow's fill
    assert unripe > 50 and hulls > 60


@pytest.mark.parametrize("seed", [0, 1])
def test_the_bridged_solid_is_the_twins(seed):
    """:func:`_jit.bridged_solid` against the numpy trim and ``_bridged_skin``'s test (the trimmed skin's pixel count
    below ``GROUND_SOLIDITY`` of ``_hull_area``, Pillow's fill, Qhull and numpy with the twins) on 300 skins
    (``_trim_case``), and on random solidities: the same pixels and answers."""
    from symfruit.segment.colour import _hull_area, _pillow_fill

    if not _pillow_fill():
        pytest.skip("the kernel follows Pillow 12.1's fill")
    rng = np.random.default_rng(seed)
    answers = set()
    for _ in range(300):
        skin, z, part, r0, c0 = _trim_case(rng)
        solidity = float(rng.choice([0.75, rng.uniform(0.0, 1.2)]))
        with pytest.MonkeyPatch.context() as mp:
            mp.setenv("SYMFRUIT_KERNELS", "numpy")
            twin = _trim_twin(skin, z, part, r0, c0)
            want = 2 if twin.sum() < solidity * _hull_area(twin) else 1
        got, state = _jit.bridged_solid(skin, z, part, r0, c0, solidity)
        np.testing.assert_array_equal(got, twin)
        assert state == want
        answers.add(state)
    assert answers == {1, 2}


# --- stop 53, complete53 ---


@settings(max_examples=300, deadline=None)
@given(
    h=st.integers(0, 40),
    w=st.integers(0, 70),
    share=st.sampled_from([0.0, 0.002, 0.02, 0.3, 1.0]),
    seed=st.integers(0, 2**16),
)
def test_mask_box_is_the_twins(h, w, share, seed):
    """:func:`_jit.mask_box` against its numpy twin (``raster._mask_box``: the reductions and ``nonzero``) on random
    masks of 0-40 by 0-70 pixels, empty to full, with a lone pixel or a blob placed anywhere (at the edges too), and
    as the byte values numpy may hold in a bool image (not 0 or 1): the same box, None where none is true; the
    strided view takes the twin and gives the same."""
    from symfruit.core.raster import _mask_box, mask_box

    rng = np.random.default_rng(seed)
    mask = rng.random((h, w)) < share
    if h and w and seed % 3 == 0:  # a lone pixel or a small blob anywhere
        r, c = int(rng.integers(0, h)), int(rng.integers(0, w))
        mask[max(r - 1, 0) : r + int(rng.integers(1, 3)), c : c + int(rng.integers(1, 4))] = True
    found, r0, r1, c0, c1 = _jit.mask_box(mask)
    want = _mask_box(mask)
    assert (want is None and not found and (r0, r1, c0, c1) == (0, 0, 0, 0)) or (found and (r0, r1, c0, c1) == want)
    assert mask_box(mask) == want
    assert mask_box(mask[:, ::2]) == _mask_box(mask[:, ::2])  # not C-ordered: the twin
    bytes_ = mask.view(np.uint8) * np.uint8(1 + seed % 200)  # true pixels held as other bytes than 1
    odd = bytes_.view(bool)
    found, r0, r1, c0, c1 = _jit.mask_box(odd)
    assert (None if not found else (r0, r1, c0, c1)) == _mask_box(odd) == want


def test_mask_box_known_answers():
    """A blob's box, a lone pixel in each corner, a full and an empty image, a row and a column."""
    m = np.zeros((6, 8), bool)
    m[1:3, 2:7] = True
    assert _jit.mask_box(m) == (True, 1, 3, 2, 7)
    for r, c in ((0, 0), (0, 7), (5, 0), (5, 7)):
        m = np.zeros((6, 8), bool)
        m[r, c] = True
        assert _jit.mask_box(m) == (True, r, r + 1, c, c + 1)
    assert _jit.mask_box(np.ones((3, 4), bool)) == (True, 0, 3, 0, 4)
    assert _jit.mask_box(np.zeros((3, 4), bool))[0] is False
    assert _jit.mask_box(np.zeros((0, 4), bool))[0] is False
    assert _jit.mask_box(np.ones((1, 9), bool)) == (True, 0, 1, 0, 9)
    assert _jit.mask_box(np.ones((9, 1), bool)) == (True, 0, 9, 0, 1)


# --- stop 53, seg53


def test_the_skin_flood_is_the_twins():
    """``_skin_flood`` with :func:`_jit.skin_flood` (the part's copy, the flood and the reach test in one call) and
    with the twins (numpy's flood, then ``_at_reach``'s numpy test) on 300 random red parts of a yellow apple with
    a leaf across it, another fruit's pixels and a step in front, their windows at the image's edges or not, the
    reach from a few pixels to past the image: the same window, depth and skin, and the same reach answer (False
    where not asked, as the twins do not work it out); both answers come up, and skins grown past their parts."""
    from symfruit.segment.colour import SegmentSettings, _at_reach, _Depth, _skin_flood

    rng = np.random.default_rng(53)
    h, w = 90, 120
    yy, xx = np.mgrid[:h, :w]
    s = SegmentSettings(round_fruit=True)
    answers, grown = set(), 0
    for _ in range(300):
        ry, rx, rad = int(rng.integers(0, h)), int(rng.integers(0, w)), int(rng.integers(8, 40))
        disc = (yy - ry) ** 2 + (xx - rx) ** 2 <= rad**2
        depth = np.where(disc, 0.8 - 0.0004 * np.sqrt(np.maximum(rad**2 - (yy - ry) ** 2 - (xx - rx) ** 2, 0)), 1.5)
        depth[rng.random((h, w)) < 0.05] = 0.0
        color = rng.integers(0, 256, (h, w, 3)).astype(np.uint8)
        color[disc] = (200, 180, 40)
        leaf = int(rng.integers(0, w - 4))
        color[:, leaf : leaf + 4] = (40, 150, 40)
        owner = np.zeros((h, w), np.int16)
        owner[rng.random((h, w)) < 0.02] = 2
        depth[int(rng.integers(0, h)) :, int(rng.integers(0, w)) :] -= 0.05
        r0, c0 = int(rng.integers(0, h - 1)), int(rng.integers(0, w - 1))
        sl = (slice(r0, int(rng.integers(r0 + 1, min(r0 + 30, h) + 1))),
              slice(c0, int(rng.integers(c0 + 1, min(c0 + 30, w) + 1))))  # fmt: skip
        part = rng.random((sl[0].stop - r0, sl[1].stop - c0)) < 0.7
        part = part if rng.random() < 0.9 else np.asfortranarray(part)
        zm = float(np.median(depth[sl][part & (depth[sl] > 0)])) if (part & (depth[sl] > 0)).any() else 0.8
        reach = float(rng.choice([2.0, 6.5, 15.0, 40.0, 200.0]))
        grow = (r0 + part.shape[0] / 2, c0 + part.shape[1] / 2, reach, float(rng.choice([0.02, 0.3])), zm)
        asked = bool(rng.random() < 0.8)
        with pytest.MonkeyPatch.context() as mp:
            fast, twin = _both(mp, _skin_flood, sl, part, _Depth(depth), color, s, owner, 1, grow, asked)
            mp.setenv("SYMFRUIT_KERNELS", "numpy")
            want = _at_reach(twin[2], twin[0], grow[0], grow[1], reach) if asked else None
        assert fast[0] == twin[0]
        np.testing.assert_array_equal(fast[1], twin[1])
        np.testing.assert_array_equal(fast[2], twin[2])
        assert fast[3] is want and twin[3] is None
        answers.add(want)
        grown += int(fast[2].sum() > part.sum())
    assert answers == {True, False, None} and grown > 50


def test_the_skin_flood_known_answer():
    """:func:`_jit.skin_flood` of a 3x3 part in the middle of a flat 20x20 window of one depth: the skin is the disc of
    the reach about the centre; a reach of 5 px stops it (the disc's pixels lie past 4), one past the window stops it
    at the window's edge, neither asked is False."""
    z = np.full((20, 20), 1.0)
    color = np.full((20, 20, 3), (200, 180, 40), np.uint8)
    owner = np.zeros((20, 20), np.int16)
    part = np.ones((3, 3), bool)
    args = (z, color, owner, 1, part, 9, 9, 0, 0, 10.0, 10.0)
    skin, at = _jit.skin_flood(*args, 25.0, 0.1, 1.0, 0.01, 0.02, 80, 16.0)
    yy, xx = np.mgrid[:20, :20]
    np.testing.assert_array_equal(skin, (yy - 10.0) ** 2 + (xx - 10.0) ** 2 <= 25.0)
    assert at
    assert _jit.skin_flood(*args, 400.0, 0.1, 1.0, 0.01, 0.02, 80, 19.0**2)[1]  # on the window's edge
    assert not _jit.skin_flood(*args, 25.0, 0.1, 1.0, 0.01, 0.02, 80, -1.0)[1]


# --- stop 54, seg54


@pytest.mark.parametrize("view", ["whole", "grid", "window", "rgba"])
def test_the_ground_colour_test_of_all_colours_in_any_layout_is_the_twins(view):
    """All 2**24 colours in a 4096x4096 image, read whole, as the coarse grid's strided view (every 4th pixel of every
    4th row, as ``_ground_bodies`` reads it), as a window of it, and from a 4-channel image: :func:`_jit.ground_pixels`
    (each row's channels copied into rows of whole numbers and tested there, stop 54) gives the twin's pixels."""
    from symfruit.segment.colour import _ground

    rgb = np.arange(2**24, dtype=np.uint32).reshape(4096, 4096)
    image = np.stack(((rgb >> 16) & 255, (rgb >> 8) & 255, rgb & 255), axis=-1).astype(np.uint8)
    if view == "rgba":
        image = np.concatenate((image[:1024], np.full((1024, 4096, 1), 7, np.uint8)), axis=2)
    else:
        image = {"whole": image, "grid": image[1::4, 2::4], "window": image[3:-5, 9:-11]}[view]
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, _ground, image)
    np.testing.assert_array_equal(fast, twin)
    assert 0 < int(twin.sum()) < twin.size // 2


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_masked_and_region_medians_of_tied_depths_are_core_points_medians(seed):
    """Depths drawn from a few values (ties, even and odd counts, none): :func:`_jit.masked_median`'s and
    :func:`_jit.region_medians`' depth medians (by :func:`_jit.median_quick` since stop 54) are ``core.points.median``
    of the same depths to the bit, NaN without any."""
    from symfruit.core.points import median

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 30, 2))
    z = rng.choice([0.0, 0.8, 0.8 + 2**-40, 1.25, 1.5, 3.0], (h, w), p=[0.3, 0.2, 0.1, 0.2, 0.1, 0.1])
    mask = rng.random((h, w)) < rng.uniform(0.0, 1.0)
    n, k, zm = _jit.masked_median(mask, z)
    values = z[mask & (z > 0)]
    assert (n, k) == (int(mask.sum()), len(values))
    if len(values):
        assert np.float64(zm).tobytes() == np.float64(median(values)).tobytes()
    else:
        assert np.isnan(zm)
    sizes = rng.integers(0, 12, int(rng.integers(1, 8)))
    first = np.concatenate(([0], np.cumsum(sizes))).astype(np.int64)
    depth = z.ravel()[: int(first[-1])] if first[-1] <= z.size else rng.choice([0.0, 1.0, 2.0], int(first[-1]))
    red = np.zeros(len(depth), np.float32)
    zmed, nz, _ = _jit.region_medians(first, np.ascontiguousarray(depth), red)
    for i in range(len(sizes)):
        part = depth[first[i] : first[i + 1]]
        part = part[part > 0]
        assert nz[i] == len(part)
        if len(part):
            assert np.float64(zmed[i]).tobytes() == np.float64(median(part)).tobytes()
        else:
            assert np.isnan(zmed[i])


# --- stop 55, seg55


def _red_scene(rng, h, w):
    """Random colours with red discs, rings and specks (some strongly red), and a depth image of them (float32 or
    float64) with holes (0, NaN, infinite and negative depths) and some regions without any depth."""
    image = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
    image[rng.random((h, w)) < 0.04] = (200, 40, 30)
    yy, xx = np.mgrid[:h, :w]
    depth = rng.uniform(0.3, 3.0, (h, w))
    for _ in range(int(rng.integers(0, 7))):
        cy, cx, r = rng.uniform(0, h), rng.uniform(0, w), rng.uniform(2, 30)
        d = (yy - cy) ** 2 + (xx - cx) ** 2
        shape = d <= r * r if rng.random() < 0.6 else (d <= r * r) & (d >= (0.6 * r) ** 2)
        image[shape] = (int(rng.integers(120, 256)), int(rng.integers(0, 90)), int(rng.integers(0, 90)))
        depth[shape] = 0.0 if rng.random() < 0.15 else rng.uniform(0.2, 4.0)
    holes = rng.random((h, w))
    depth[holes < 0.1] = 0.0
    depth[(holes >= 0.1) & (holes < 0.12)] = np.nan
    depth[(holes >= 0.12) & (holes < 0.13)] = np.inf
    depth[(holes >= 0.13) & (holes < 0.14)] = -1.0
    return image, depth.astype(rng.choice([np.float32, np.float64]))


@pytest.mark.parametrize("seed", range(40))
def test_a_red_windows_regions_in_one_call_are_the_twins(seed):
    """Random scenes of red discs, rings and specks over depth with holes (float32 and float64), windows anywhere
    (at the image's edges, the whole image, a single pixel), least diameters that keep all, some or none of the
    regions, typical depths near and far: ``_window_regions`` with the kernels (one :func:`_jit.window_regions`
    call) gives the numpy twins' values (``SYMFRUIT_KERNELS=numpy``: ``_red_regions``, the depths, ``_least_areas``,
    ``_grouped``, ``_group_boxes``), None without a weak pixel."""
    from symfruit.segment.colour import SegmentSettings, _Depth, _window_regions

    rng = np.random.default_rng(5500 + seed)
    h, w = int(rng.integers(1, 90)), int(rng.integers(1, 110))
    image, depth = _red_scene(rng, h, w)
    given = np.ascontiguousarray(depth)
    s = SegmentSettings(min_diameter=float(rng.choice([0.001, 0.02, 0.05, 0.5])))
    focal, z_typical = float(rng.uniform(200, 1500)), float(rng.choice([0.4, 1.0, 2.5]))
    for _ in range(12):
        r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
        r1, c1 = int(rng.integers(r0 + 1, h + 1)), int(rng.integers(c0 + 1, w + 1))
        win = (slice(r0, r1), slice(c0, c1))
        with pytest.MonkeyPatch.context() as mp:
            fast, twin = _both(mp, _window_regions, image, win, _Depth(given), s, focal, 4.0, z_typical)
        if twin is None:
            assert fast is None
            continue
        assert fast is not None
        for a, b in zip(fast[:-1], twin[:-1], strict=True):
            if b is None:
                assert a is None
                continue
            np.testing.assert_array_equal(a, b)
            if b.size:
                assert a.dtype == b.dtype
        assert fast[-1] == twin[-1]  # the kept regions' boxes


def test_the_red_windows_regions_cover_every_case():
    """``_window_regions`` with the kernels on windows chosen to hold no red, red without a strong pixel, a strong
    region too small to keep and one kept: None, then no region kept, then the kept one's box (its numpy twin's)."""
    from symfruit.segment.colour import SegmentSettings, _Depth, _window_regions

    image = np.zeros((60, 80, 3), np.uint8)
    image[..., 1] = 200  # green
    image[5:9, 5:9] = (140, 90, 80)  # weakly red, no strong pixel
    image[20:22, 20:22] = (220, 10, 10)  # a strong speck
    image[30:50, 40:70] = (220, 10, 10)  # a strong fruit
    depth = np.full((60, 80), 1.0, np.float32)
    s, z = SegmentSettings(min_diameter=0.02), _Depth(depth)
    found = {}
    windows = {"green": (slice(50, 60), slice(0, 30)), "weak": (slice(0, 12), slice(0, 12)),
               "speck": (slice(15, 25), slice(15, 25)), "fruit": (slice(25, 60), slice(35, 80))}  # fmt: skip
    for name, win in windows.items():
        with pytest.MonkeyPatch.context() as mp:
            found[name] = _both(mp, _window_regions, image, win, z, s, 600.0, 4.0, 1.0)
    assert found["green"] == (None, None)
    for name in ("weak", "speck"):
        fast, twin = found[name]
        assert len(fast[5]) == len(twin[5]) == 0 and fast[-1] == twin[-1] == {}
    fast, twin = found["fruit"]
    assert fast[-1] == twin[-1] == {1: (slice(5, 25), slice(5, 35))}
    np.testing.assert_array_equal(fast[4], np.ones(600))  # the fruit's depths


# --- stop 59, speedc59


@settings(max_examples=300, deadline=None)
@given(
    h=st.integers(0, 30),
    w=st.integers(0, 40),
    share=st.sampled_from([0.0, 0.05, 0.3, 0.6, 0.9, 1.0]),
    seed=st.integers(0, 2**16),
)
def test_in_pieces_is_the_labels_count(h, w, share, seed):
    """:func:`_jit.in_pieces` against its twin, ``ndimage.label(mask, np.ones((3, 3), bool))[1] >= 2`` (the test of
    :func:`symfruit.core.occlusion.bridged`), on random masks of 0-30 by 0-40 pixels, empty to full, and on blobs
    that touch at a corner only or are one pixel apart (8-connectivity: one piece, two pieces), at every edge."""
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    mask = rng.random((h, w)) < share
    assert _jit.in_pieces(mask) == (ndimage.label(mask, np.ones((3, 3), bool))[1] >= 2)
    if h >= 2 and w >= 2:  # two blobs meeting at a corner, then one pixel apart
        r, c = int(rng.integers(1, h)), int(rng.integers(1, w))
        for gap in (0, 1):
            two = np.zeros((h, w), bool)
            two[:r, :c] = True
            two[r + gap :, c + gap :] = True
            want = ndimage.label(two, np.ones((3, 3), bool))[1] >= 2
            assert _jit.in_pieces(two) == want
            assert want == (gap == 1 and r + 1 < h and c + 1 < w)


def test_in_pieces_known_answers():
    """None, one pixel, a ring (one piece around a hole), two pixels diagonal (one piece) and a knight's move apart
    (two), a comb whose teeth meet only in a row far below."""
    assert not _jit.in_pieces(np.zeros((0, 3), bool))
    assert not _jit.in_pieces(np.zeros((4, 5), bool))
    one = np.zeros((4, 5), bool)
    one[2, 3] = True
    assert not _jit.in_pieces(one)
    ring = np.ones((6, 6), bool)
    ring[2:4, 2:4] = False
    assert not _jit.in_pieces(ring)
    diagonal = np.eye(5, dtype=bool)
    assert not _jit.in_pieces(diagonal)
    knight = np.zeros((4, 4), bool)
    knight[0, 0] = knight[1, 2] = True
    assert _jit.in_pieces(knight)
    comb = np.zeros((8, 9), bool)
    comb[:6, ::2] = True
    assert _jit.in_pieces(comb)
    comb[7, :] = True
    assert _jit.in_pieces(comb)  # row 6 is empty: the teeth and the back apart
    comb[6, 0] = True
    assert _jit.in_pieces(comb)  # the first tooth joined to the back, the others not
    comb[6, 1::2] = True
    assert not _jit.in_pieces(comb)  # every tooth joined at a corner of row 6's pixels between them


# --- stop 60, speeds60: the surface kernels without jumps


def test_least_median_seeded_at_a_spike_takes_the_first_least_median():
    """The pass starts from the pixel whose own value is least: a spike there (its window's median not the least) is
    passed over; of two windows with the least median, before and after the seed, the first is taken; all medians
    +inf: the first pixel."""
    image = np.full((9, 12), 0.5)
    image[1:6, 0:5] = 0.45  # a block of 0.45: the windows about its pixels take the median 0.45, the least
    image[1:6, 7:12] = 0.45  # the same block again about (3, 9): the same median, after it
    image[3, 9] = 0.1  # the least own value, a spike: the seed, whose median is 0.45 too, but it comes later
    rows, cols = np.nonzero(np.ones(image.shape, bool))
    from symfruit.core.surface import median_at

    medians = median_at(image, rows, cols, size=5)
    seed = int(np.argmin(image[rows, cols]))
    want = int(np.argmin(medians))
    assert (rows[seed], cols[seed]) == (3, 9) and medians[seed] == medians[want] == 0.45 and want < seed
    assert _jit.least_median(image, rows, cols, 5) == want
    assert _jit.least_median(image, rows[seed:], cols[seed:], 5) == 0  # the seed first: its own tie kept
    assert _jit.least_median(np.full((4, 4), np.inf), rows[:16] % 4, cols[:16] % 4, 5) == 0


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_noise_step_is_depth_noise_and_depth_step(seed, odd):
    """``_noise_step`` (mask_values' one pass): ``depth_noise``'s count and deviation and ``depth_step``'s step, with
    whole-millimetre and continuous depths, NaN, infinite (two neighbours infinite: a NaN difference), negative and
    zero depths, few pixels; and flat depths with fewer than 20 differences not 0 (all of them read then, the zeros
    too: stop 62, surf62 gathers both sets in its one pass)."""
    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 40, 2))
    depth = rng.uniform(0.4, 0.6, (h, w))
    if rng.random() < 0.5:
        depth = np.round(depth, 3)
    if rng.random() < 0.3:  # flat, a few steps
        depth = np.full((h, w), 0.5)
        depth[rng.random((h, w)) < rng.choice([0.005, 0.02, 0.1])] = 0.501
    if odd:
        for value in (np.nan, np.inf, -0.2, 0.0):
            depth[rng.random((h, w)) < 0.05] = value
    mask = rng.random((h, w)) < rng.uniform(0.05, 1.0)
    n, mad, step = _jit._noise_step(depth, mask)
    n_want, mad_want = _jit.depth_noise(depth, mask)
    assert n == n_want and ((np.isnan(mad) and np.isnan(mad_want)) or mad == mad_want)
    assert step == _jit.depth_step(depth, mask)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_rows_box_is_the_box(seed):
    """``_rows_box`` (each row or'ed whole, then walked from its ends): ``_box``'s box, (0, 0, 0, 0) for none."""
    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(0, 30, 2))
    mask = rng.random((h, w)) < rng.choice([0.0, 0.002, 0.05, 0.5])
    assert _jit._rows_box(mask) == _jit._box(mask)


# --- stop 60, speedo60


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2**31 - 1), st.integers(0, 9), st.booleans(), st.booleans(), st.integers(6, 70),
       st.integers(6, 90), st.sampled_from([0.005, 0.0, 0.02]), st.integers(0, 3), st.booleans(),
       st.sampled_from([(300.0, 300.0, 0.0, 0.0), (310.5, 295.25, 2.5, -1.75)]))  # fmt: skip
@example(543, 3, False, False, 49, 81, 0.005, 0, True, (310.5, 295.25, 2.5, -1.75))
def test_the_projected_occlusion_is_the_boxed_one(seed, band, with_others, single, h, w, tolerance, reach, supports,
                                                  intrinsics):  # fmt: skip
    """occlusion_projected (the points projected in the kernel, the own edge on the mask's box found once, its square
    filters from summed-area tables, the own depths' least from the points' box alone, no window-sized own maps)
    against occlusion_at of Camera.project's coordinates (the same window and seen depths; the own edge clears hidden
    pixels only: without a band the same hidden pixels, with one fewer or as many) and against occlusion's numpy twin
    (own_edge on the window's maps): the same window, hidden pixels and seen depths, bit for bit; fruit at the image's
    border, fattened edges, leaves at the fruit's depth, other fruit, dropouts, bands 0-9, a camera whose centre is
    off the image's corner (points that project outside the image) and whose focal lengths differ (the focal length
    occlusion() hands on is their geometric mean). Until stop 61 the reference was occlusion_edge_boxed (the same
    kernel on Camera.project's coordinates), removed there: the twin is the reference now."""
    from symfruit.core.camera import Camera
    from symfruit.core.occlusion import occlusion

    rng = np.random.default_rng(seed)
    _, points, depth, mask, others = _fattened_scene(rng, h, w, with_others)
    depth = depth.astype(np.float32 if single else np.float64)
    steps = _steps_within(reach)
    fx, fy, cx, cy = intrinsics
    camera = Camera(fx=fx, fy=fy, cx=cx, cy=cy, width=w, height=h)
    focal = float(np.sqrt(fx * fy))  # as occlusion() hands it on (the support's reach reads it)
    got = _jit.occlusion_projected(points, fx, fy, cx, cy, 16, depth, mask, others, tolerance, steps, band, supports,
                                   focal)  # fmt: skip
    want = _jit.occlusion_at(camera.project(points), points, 16, depth, mask, others, tolerance, steps)
    assert got[:3] == want[:3]
    if not want[0]:
        return
    assert got[4].tobytes() == want[4].tobytes() and not (got[3] & ~want[3]).any()
    if band == 0:
        assert got[3].tobytes() == want[3].tobytes()
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SYMFRUIT_KERNELS", "numpy")
        twin = occlusion(depth, mask, points, camera, others=others if with_others else None, tolerance=tolerance,
                         reach=reach, band=band, trim_own=False, supports=supports)  # fmt: skip
    assert (twin.u0, twin.v0) == got[1:3] and twin.hidden.tobytes() == got[3].tobytes()
    assert np.array_equal(twin.depth, got[4], equal_nan=True)


def test_the_projected_occlusion_known_answers():
    """No point in the image: not found. A disc whose depth runs 3 px past its mask onto background: the ring hidden
    without the band, cleared with it (every pixel); a leaf 2 cm in front across the disc's
    row 30 stays hidden, and the pixels without depth beside it take the leaf's depth (the first offset with depth).
    The sweep's mask box and the hidden flag: a window with nothing hidden leaves the own edge out."""
    h, w = 60, 80
    rr, cc = np.mgrid[0:h, 0:w]
    dist = np.hypot(rr - 30, cc - 40)
    mask = dist <= 10
    v, u = np.nonzero(mask)
    points = np.column_stack((u * 0.4 / 300.0, v * 0.4 / 300.0, np.full(len(u), 0.4)))
    steps, none = _steps_within(3), np.zeros((0, 0), bool)

    def run(depth, band=8, pts=points):
        return _jit.occlusion_projected(pts, 300.0, 300.0, 0.0, 0.0, 16, depth, mask, none, 0.005, steps, band,
                                        False, 300.0)  # fmt: skip

    assert not run(np.ones((h, w)), pts=points + np.array([10.0, 0.0, 0.0]))[0]
    depth = np.where(dist <= 13, 0.4, 1.0)
    bare = run(depth, band=0)
    found, u0, v0, hidden, seen = run(depth)
    assert found and int(bare[3].sum()) == int(((dist > 10) & (dist <= 13)).sum()) and not hidden.any()
    assert np.isnan(seen[mask[v0 : v0 + hidden.shape[0], u0 : u0 + hidden.shape[1]]]).all()
    leaf = (np.abs(rr - 30) <= 1) & (cc > 52)
    depth = np.where(leaf, 0.38, np.where(dist <= 10, 0.4, 1.0))
    depth[30, 60] = 0.0  # a dropout on the leaf: the leaf's depth, hidden
    found, u0, v0, hidden, seen = run(depth)
    assert hidden[30 - v0, 60 - u0] and seen[30 - v0, 60 - u0] == 0.38
    assert hidden[29 - v0 : 32 - v0, 53 - u0 : 70 - u0].all() and int(hidden.sum()) == int(leaf[v0:, u0:].sum())
    nothing = np.where(dist <= 10, 0.4, 1.0)
    assert not run(nothing)[3].any()


# --- stop 60, speedc60: the same loops, laid out for the processor's vector instructions and independent sums --------


@given(st.integers(0, 2**32 - 1), st.integers(1, 9), st.integers(20, 300))
def test_slice_costs_of_a_pair_are_each_directions_alone(seed, k, n):
    """:func:`slice_costs_below` works two directions at a time: each cost is, to the bit, the cost of its direction
    worked out alone (a call of one direction, which works it as both of a pair), whatever its neighbour; an odd
    count's last direction too."""
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(n, 3)) * rng.uniform(0.001, 0.1)
    q[: n // 3] = np.round(q[: n // 3], 3)  # ties in the slices
    q = np.ascontiguousarray(q - q.mean(axis=0))
    dirs = rng.normal(size=(k, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    if k > 1:
        dirs[1] = dirs[0]  # a pair of the same direction
    alone = np.array([_jit.slice_costs(q, dirs[j : j + 1], 12)[0] for j in range(k)])
    assert _jit.slice_costs(q, dirs, 12).tobytes() == alone.tobytes()


def _cone_residual(c: tuple[float, float, float], lam: float, gap: float, ray: np.ndarray, ray_cone: float,
                   z: float) -> float:  # fmt: skip
    """One ray's residual as :func:`_jit.cone_residuals` worked it out before stop 60, in numpy's float64 scalars
    (IEEE doubles, a division by zero inf or NaN as the kernel's: the same operations, the same bits)."""
    f = np.float64
    with np.errstate(all="ignore"):
        rcm = f(c[0]) * f(ray[0]) + f(c[1]) * f(ray[1]) + f(c[2]) * f(ray[2])
        lam_, gap_ = f(lam), f(gap)
        a = f(ray_cone) / lam_ - rcm * rcm / (lam_ * gap_)
        b = rcm / gap_
        cc = -lam_ / gap_
        disc = b * b - a * cc
        res = f(z) - (b - np.sqrt(disc)) / a if disc >= 0 else f(np.nan)
    return float(res) if math.isfinite(res) else 0.02


@given(st.integers(0, 2**32 - 1), st.integers(1, 80))
def test_cone_residuals_from_columns_are_the_rays_arithmetic(seed, n):
    """The residuals read from the rays' columns (a vectorised loop) are, to the bit, each ray's arithmetic done
    alone in Python floats (the form before stop 60), on valid and invalid ellipsoids and saturated logistics."""
    visible, cone, axis, _, _ = _cone_view("apple", 1)
    rng = np.random.default_rng(seed)
    pts = visible[rng.choice(len(visible), n, replace=False)]
    rays, z = np.ascontiguousarray(pts / pts[:, 2:3]), np.ascontiguousarray(pts[:, 2])
    ray_cone = ((rays @ cone) * rays).sum(axis=1)
    params = np.c_[rng.normal(0.0, 0.02, (6, 2)), np.log(rng.uniform(0.2, 0.8, 6)), rng.uniform(-10, 10, 6)]
    params[0, 3] = 60.0
    params[1, :2] = 1.0
    out = np.empty((6, n))
    _jit.cone_residuals(params, cone, axis, rays, ray_cone, z, out)
    for j, (p0, p1, p2, p3) in enumerate(params.tolist()):
        e = math.exp(p2)
        m = ((float(axis[0]) + p0) * e, (float(axis[1]) + p1) * e, float(axis[2]) * e)
        c = tuple(m[0] * float(cone[0, i]) + m[1] * float(cone[1, i]) + m[2] * float(cone[2, i]) for i in range(3))
        qq = -(c[0] * m[0] + c[1] * m[1] + c[2] * m[2])
        if not qq > 0:
            want = [0.05] * n
        else:
            lam = qq / (1.0 + math.exp(-min(max(p3, -50.0), 50.0)))
            want = [_cone_residual(c, lam, lam - qq, rays[i], float(ray_cone[i]), float(z[i])) for i in range(n)]
        assert out[j].tobytes() == np.array(want).tobytes()


def _sphere_steps_before(q: np.ndarray, c: list[float], r: float, iterations: int, tolerance: float,
                         scale: float) -> tuple[float, bool]:  # fmt: skip
    """:func:`_jit.sphere_steps` as it was before stop 60 (one loop a step, its sums in the matrix), in Python floats
    (``c`` updated in place)."""
    n = len(q)
    for _ in range(iterations):
        jtj, g = np.zeros((4, 4)), np.zeros(4)
        for x0, x1, x2 in q.tolist():
            d0, d1, d2 = x0 - c[0], x1 - c[1], x2 - c[2]
            dist = max(math.sqrt(d0 * d0 + d1 * d1 + d2 * d2), 1e-12)
            j0, j1, j2 = -d0 / dist, -d1 / dist, -d2 / dist
            res = dist - r
            for (a, b), v in (((0, 0), j0 * j0), ((0, 1), j0 * j1), ((0, 2), j0 * j2), ((1, 1), j1 * j1),
                              ((1, 2), j1 * j2), ((2, 2), j2 * j2)):  # fmt: skip
                jtj[a, b] += v
            jtj[0, 3] -= j0
            jtj[1, 3] -= j1
            jtj[2, 3] -= j2
            g[0] -= j0 * res
            g[1] -= j1 * res
            g[2] -= j2 * res
            g[3] += res
        jtj[3, 3] = float(n)
        jtj = np.triu(jtj) + np.triu(jtj, 1).T
        step = np.empty(4)
        if not _jit.solve(jtj, g, step):
            return r, False
        for a in range(3):
            c[a] += float(step[a])
        r = abs(r + float(step[3]))
        if max(abs(float(s)) for s in step) * scale < tolerance:
            break
    return r, True


@given(st.integers(0, 2**32 - 1), st.integers(4, 60), st.floats(0.0, 0.003))
@settings(max_examples=40)
def test_sphere_steps_are_the_former_loop(seed, n, noise):
    """The Gauss-Newton's distances and Jacobian in a loop of their own, its sums after: the same centre, radius and
    answer, to the bit, as the one loop before stop 60."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    q = np.ascontiguousarray(0.03 * d * np.c_[1.0, 1.0, 0.4] + rng.normal(scale=noise, size=(n, 3)))
    c = rng.normal(scale=0.005, size=3)
    want_c = c.tolist()
    want = _sphere_steps_before(q, want_c, 0.025, 6, 1e-9, 1.0)
    got = _jit.sphere_steps(q, c, 0.025, 6, 1e-9, 1.0)
    assert got == want and c.tolist() == want_c


@given(st.integers(0, 2**32 - 1), st.integers(1, 60))
@settings(max_examples=40)
def test_explain_quadric_rays_quadratic_is_the_former_sum(seed, m):
    """Each ray's quadratic ``r^T A r`` from the rays' columns, its nine terms named: the depth RMS and the band
    shares, to the bit, of the nested sum over the rows before stop 60 (worked out here in Python floats and handed
    to :func:`_jit.agreement` as the kernel hands its own)."""
    rng = np.random.default_rng(seed)
    shape = rng.normal(size=(3, 3))
    shape = shape @ shape.T + np.eye(3)
    shape /= 0.03**2
    centre = np.array([0.0, 0.0, 0.4]) + rng.normal(scale=0.01, size=3)
    rays = np.c_[centre[:2] / centre[2] + rng.normal(scale=0.04, size=(m, 2)), np.ones(m)]  # most meet it
    z0, z1 = 0.3, 0.5
    depth = rng.uniform(z0, z1, m)
    empty_i, empty_f = np.zeros(0, np.int64), np.zeros(0)
    args = (z0, z1, depth, max(1, m // 2), empty_i, empty_i, empty_i, empty_f, empty_f, empty_f, 0.0)
    s = [sum(float(shape[i, j]) * float(centre[j]) for j in range(3)) for i in range(3)]  # left to right, as there
    c = float(centre[0]) * s[0] + float(centre[1]) * s[1] + float(centre[2]) * s[2] - 1.0
    hit, at = np.empty(m, bool), np.empty(m)
    for k, ray in enumerate(rays.tolist()):
        a = 0.0
        for i in range(3):
            for j in range(3):
                a += ray[i] * float(shape[i, j]) * ray[j]
        b = ray[0] * s[0] + ray[1] * s[1] + ray[2] * s[2]
        disc = b * b - a * c
        root = math.sqrt(disc) if disc > 0.0 else 0.0
        near, far = (b - root) / a, (b + root) / a
        hit[k] = disc > 0.0 and near < z1 and far > z0
        at[k] = max(near, z0) if hit[k] else math.nan
    want = _jit.agreement(hit, at, *args)
    assert np.array(_jit.explain_quadric(centre, shape, rays, *args)).tobytes() == np.array(want).tobytes()


# --- stop 60, revol60: the slices' sums in vector additions, the noise's neighbours ordered by counting ------------


def _former_slice_cost(q: np.ndarray, d: np.ndarray, bins: int) -> float:
    """One direction's slice cost as :func:`_jit.slice_costs_below` worked it out before revol60, in Python floats (IEEE
    doubles: the same operations in the same order, the same bits): each slice's four sums added point by point in
    the points' order, then the trimmed mean of the squared distances by the kernel's own selection."""
    n = q.shape[0]
    x, y, z = (float(c) for c in d)
    if abs(x) < 0.9:
        a, b, c = 0.0, z, -y
    else:
        a, b, c = -z, 0.0, x
    norm = math.sqrt(a * a + b * b + c * c)
    a, b, c = a / norm, b / norm, c / norm
    f, g, h = y * c - z * b, z * a - x * c, x * b - y * a
    pts = [(float(p[0]), float(p[1]), float(p[2])) for p in q]
    t = [x * p0 + y * p1 + z * p2 for p0, p1, p2 in pts]
    u = [a * p0 + b * p1 + c * p2 for p0, p1, p2 in pts]
    v = [f * p0 + g * p1 + h * p2 for p0, p1, p2 in pts]
    lo, hi = min(t), max(t)
    span = max(hi - lo, 1e-12)
    idx = [min(int((ti - lo) / span * bins), bins - 1) for ti in t]
    sums = [[0.0] * 4 for _ in range(bins)]
    for i in range(n):
        s = sums[idx[i]]
        s[0] += 1.0
        s[1] += u[i]
        s[2] += v[i]
        s[3] += u[i] * u[i] + v[i] * v[i]
    for s in sums:
        w = max(s[0], 1.0)
        s[1], s[2], s[3] = s[1] / w, s[2] / w, s[3] / w
    a11 = a12 = a22 = e1 = e2 = 0.0
    cu, cv, cy = [], [], []
    for i in range(n):
        s = sums[idx[i]]
        du, dv, dy = u[i] - s[1], v[i] - s[2], u[i] * u[i] + v[i] * v[i] - s[3]
        cu.append(du)
        cv.append(dv)
        cy.append(dy)
        a11 += du * du
        a12 += du * dv
        a22 += dv * dv
        e1 += du * dy
        e2 += dv * dy
    det = a11 * a22 - a12 * a12
    if not abs(det) > 1e-30:
        det = 1e-30
    au, av = 0.5 * (a22 * e1 - a12 * e2) / det, 0.5 * (a11 * e2 - a12 * e1) / det
    dist2 = np.empty(n)
    for i in range(n):
        res = cy[i] - 2.0 * (au * cu[i] + av * cv[i])
        ru, rv = u[i] - au, v[i] - av
        dist2[i] = res * res / (max(ru * ru + rv * rv, 1e-12) * 4.0)
    return float(_jit.smallest_mean(dist2, max(1, int(0.8 * n)), np.empty(n), np.empty(n)))


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 6), st.integers(20, 120), st.sampled_from([1, 5, 12]))
def test_slice_costs_in_vector_sums_are_the_former_scatter(seed, k, n, bins):
    """The slices' sums taken four at a time in one vector addition (revol60) give, to the bit, the costs of the
    former point-by-point scatter (Python floats), with tied coordinates and a direction along x (the other basis)."""
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(n, 3)) * rng.uniform(0.001, 0.1)
    q[: n // 3] = np.round(q[: n // 3], 3)
    q = np.ascontiguousarray(q - q.mean(axis=0))
    dirs = rng.normal(size=(k, 3))
    dirs[0] = (1.0, 0.0, 0.0)
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    former = np.array([_former_slice_cost(q, dirs[j], bins) for j in range(k)])
    assert _jit.slice_costs(q, np.ascontiguousarray(dirs), bins).tobytes() == former.tobytes()


@given(st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64), min_size=8, max_size=8),
       st.integers(0, 2))  # fmt: skip
def test_add4_is_four_scalar_additions(values, at):
    """``_add4`` adds four numbers to four consecutive places of an array, each lane as the scalar ``+=`` (signed
    zeros, infinities and NaN's bits alike), the places about them untouched."""

    @numba.njit
    def run(arr: np.ndarray, off: int, a: float, b: float, c: float, d: float) -> None:
        _jit._add4(arr, off, a, b, c, d)

    arr = np.full((3, 4), 7.0)
    arr[at] = values[:4]
    want = arr.copy()
    with np.errstate(all="ignore"):
        for i in range(4):
            want[at, i] = np.float64(want[at, i]) + np.float64(values[4 + i])
    run(arr, at * 4, *values[4:])
    assert arr.tobytes() == want.tobytes()


# --- stop 61, speedb61: the outline's edge labels by rows, the occlusion box's opening in one sweep -----------------


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(["grid", "anywhere", "outline"]))
def test_the_row_ordered_nearest_labels_are_the_sweeps(seed, kind):
    """nearest_labels_rows (edge points in row order, searched row by row from the query's) against nearest_labels
    (sorted along x, swept) and the squared distances to every point (numpy): the same unsure queries, exactly where
    the equally near points carry both labels, and the same labels where sure, which are the labels of
    ``_first_nearest`` (the numpy twin's rule). Points on whole pixels (many equally near), anywhere (rows of one
    point) and an outline's pixels (outline_uv) with the cracks' half-integer queries, labels mixed or all alike."""
    from symfruit.core.agreement import _first_nearest

    rng = np.random.default_rng(seed)
    if kind == "outline":
        h, w = (int(x) for x in rng.integers(1, 40, 2))
        mask = np.zeros((h, w), bool)
        rr, cc = np.mgrid[0:h, 0:w]
        for _ in range(int(rng.integers(1, 4))):
            mask |= np.hypot(rr - rng.uniform(0, h), cc - rng.uniform(0, w)) < rng.uniform(1, 15)
        mask |= rng.random((h, w)) < rng.uniform(0, 0.1)
        if not mask.any():
            mask[0, 0] = True
        u0, v0 = (int(x) for x in rng.integers(0, 50, 2))
        edge = _jit.outline_uv(mask, int(rng.integers(1, 200)), u0, v0)
        queries = np.concatenate((_jit.outline_cracks(mask, u0, v0),
                                  rng.integers(-6, 46, (int(rng.integers(0, 100)), 2)).astype(np.float64)))  # fmt: skip
    else:
        k, m = int(rng.integers(1, 80)), int(rng.integers(0, 200))
        if kind == "grid":
            edge = rng.integers(0, 12, (k, 2)).astype(np.float64)
            queries = rng.integers(-3, 15, (m, 2)) + rng.choice([0.0, 0.5], (m, 2))
        else:
            edge = rng.uniform(0, 40, (k, 2))
            queries = rng.uniform(-5, 45, (m, 2))
        edge = np.unique(edge[np.lexsort((edge[:, 0], edge[:, 1]))], axis=0)  # distinct points, in row order
        edge = edge[np.lexsort((edge[:, 0], edge[:, 1]))]
    labels = rng.random(len(edge)) < rng.choice([0.0, rng.uniform(0.0, 1.0), 1.0])
    found, unsure = _jit.nearest_labels_rows(edge, labels, queries)
    want_found, want_unsure = _jit.nearest_labels(edge, labels, queries)
    assert found.shape == unsure.shape == (len(queries),)
    np.testing.assert_array_equal(unsure, want_unsure)
    np.testing.assert_array_equal(found[~unsure], want_found[~unsure])
    d2 = (queries[:, None, 0] - edge[None, :, 0]) ** 2 + (queries[:, None, 1] - edge[None, :, 1]) ** 2
    ties = [labels[d2[j] == d2[j].min()] for j in range(len(queries))]
    np.testing.assert_array_equal(unsure, [t.any() and not t.all() for t in ties])
    if len(queries):
        np.testing.assert_array_equal(found[~unsure], _first_nearest(edge, labels, queries)[~unsure])


def test_the_row_ordered_nearest_labels_known_answers():
    """Edge points (0, 0) true and (4, 0) false, (2, 3) true: a query at (2, 0) is equally near both ends of the first
    row (unsure), one at (1, 0) is the true end's, one at (3, 1) the false end's, one at (2, 2) the lone third row's
    (1 away, the ends sqrt(5)), one far below the last row's; none left out when a row holds one point. A query with
    a NaN coordinate is no point's (false, sure), as nearest_labels has it."""
    edge = np.array([[0.0, 0.0], [4.0, 0.0], [2.0, 3.0]])
    labels = np.array([True, False, True])
    queries = np.array([[2.0, 0.0], [1.0, 0.0], [3.0, 1.0], [2.0, 2.0], [2.0, 40.0], [-9.0, -9.0], [np.nan, 0.0],
                        [1.0, np.nan]])  # fmt: skip
    found, unsure = _jit.nearest_labels_rows(edge, labels, queries)
    assert unsure.tolist() == [True, False, False, False, False, False, False, False]
    assert found[1:].tolist() == [True, False, True, True, True, False, False]
    want_found, want_unsure = _jit.nearest_labels(edge, labels, queries)
    assert np.array_equal(unsure, want_unsure) and np.array_equal(found[1:], want_found[1:])


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 5))
def test_the_one_sweep_opening_is_open_square(seed, radius):
    """open_square (one sweep down the rows: each column's run, the columns side by side whose runs are long enough,
    each column's last square) against core.occlusion.open_square (scipy's minimum then maximum filter, the numpy
    twin) and scipy's binary_opening: the same pixels on noise, blobs, full and empty images, thin lines and images
    narrower or shorter than the square, into a view of a larger array (as _joins writes it)."""
    from scipy import ndimage

    from symfruit.core.occlusion import open_square

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 50, 2))
    kind = seed % 4
    if kind == 0:
        mask = rng.random((h, w)) < rng.uniform(0.0, 1.0)
    elif kind == 1:
        rr, cc = np.mgrid[0:h, 0:w]
        mask = np.zeros((h, w), bool)
        for _ in range(int(rng.integers(1, 5))):
            mask |= np.hypot(rr - rng.uniform(0, h), cc - rng.uniform(0, w)) < rng.uniform(0, 15)
        mask &= rng.random((h, w)) > rng.uniform(0, 0.05)
    elif kind == 2:
        mask = np.full((h, w), bool(rng.random() < 0.7))
    else:
        mask = ndimage.binary_dilation(rng.random((h, w)) < 0.02, iterations=int(rng.integers(1, 6)))
        mask[:, int(rng.integers(0, w))] = True  # a line one pixel wide
    size = 2 * radius + 1
    big = np.ones((h + 3, w + 5), bool)
    out = big[1 : h + 1, 2 : w + 2]
    _jit.open_square(mask, radius, out)
    want = open_square(mask, size)
    np.testing.assert_array_equal(out, want)
    np.testing.assert_array_equal(out, ndimage.binary_opening(mask, structure=np.ones((size, size), bool)))
    assert big[0].all() and big[h + 1 :].all() and big[:, :2].all() and big[:, w + 2 :].all()  # the view alone


def test_the_one_sweep_opening_known_answers():
    """A 3x3 square and a 2-wide bar opened by a 3x3 square: the square stays, the bar goes; an L of two 3x3 squares
    overlapping in a corner pixel keeps both squares whole, and the pixel beside them that lies in no square goes."""
    mask = np.zeros((8, 10), bool)
    mask[1:4, 1:4] = True
    mask[5:7, 0:10] = True
    out = np.empty_like(mask)
    _jit.open_square(mask, 1, out)
    want = np.zeros_like(mask)
    want[1:4, 1:4] = True
    np.testing.assert_array_equal(out, want)
    mask = np.zeros((7, 7), bool)
    mask[0:3, 0:3] = True
    mask[2:5, 2:5] = True
    mask[5, 4] = True
    out = np.empty_like(mask)
    _jit.open_square(mask, 1, out)
    want = mask.copy()
    want[5, 4] = False
    np.testing.assert_array_equal(out, want)


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 5))
def test_the_gap_join_in_one_sweep_is_the_filters(seed, radius):
    """near_both (``join |= grown(seen) & grown(join)`` in one sweep down the rows, in place) against scipy's maximum
    filters (the numpy twin's, Occlusion.allowed) and _square_extreme's: the same pixels, the dilation of ``join`` as
    it was on entry, nothing written outside the view; sparse and dense pixels, images smaller than the square."""
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 50, 2))
    seen = rng.random((h, w)) < rng.choice([0.0, 0.02, rng.uniform(0.0, 1.0)])
    join = rng.random((h, w)) < rng.choice([0.0, 0.02, rng.uniform(0.0, 1.0)])
    size = 2 * radius + 1
    grown = ndimage.maximum_filter(seen, size=size, mode="constant", cval=False)
    want = join | (grown & ndimage.maximum_filter(join, size=size, mode="constant", cval=False))
    filtered = np.empty((h, w), bool)
    _jit._square_extreme(join, radius, False, filtered)
    assert np.array_equal(want, join | (grown & filtered))
    big = np.zeros((h + 4, w + 2), bool)
    big[2 : h + 2, 1 : w + 1] = join
    _jit.near_both(seen, big[2 : h + 2, 1 : w + 1], radius)
    np.testing.assert_array_equal(big[2 : h + 2, 1 : w + 1], want)
    assert not big[:2].any() and not big[h + 2 :].any() and not big[:, 0].any() and not big[:, w + 1 :].any()


# --- stop 62, comp62: the normal equations' sums of a pair of directions in the two lanes of a vector ---------------


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 40), st.integers(1, 6), st.booleans())
def test_pair_sums_are_the_scalar_loops_sums(seed, n, bins, odd):
    """``_pair_sums`` gives, to the bit, each direction's five sums of the scalar loop it replaced (Python floats, the
    points in order: differences from the slices' means, then the products added), and stores the same differences;
    values from tiny to huge, ties, signed zeros, infinities and NaN among them."""

    @numba.njit
    def run(u: np.ndarray, v: np.ndarray, idx: np.ndarray, sums: np.ndarray, du: np.ndarray, dv: np.ndarray,
            dy: np.ndarray) -> tuple[float, ...]:  # fmt: skip
        return _jit._pair_sums(u, v, idx, sums, du, dv, dy)

    rng = np.random.default_rng(seed)
    u = rng.normal(size=(n, 2)) * 10.0 ** rng.integers(-150, 150, size=(n, 2))
    v = np.round(rng.normal(size=(n, 2)), 2)
    if odd and n:
        u[rng.integers(0, n), rng.integers(0, 2)] = rng.choice([np.inf, -np.inf, np.nan, -0.0])
    idx = rng.integers(0, bins, size=(n, 2))
    sums = rng.normal(size=(2, bins, 4))
    du, dv, dy = (np.full((n, 2), 7.0) for _ in range(3))
    got = run(u, v, idx, sums, du, dv, dy)
    want = []
    with np.errstate(all="ignore"):
        for e in range(2):
            acc = [0.0] * 5
            for i in range(n):
                s = int(idx[i, e])
                a, b = float(u[i, e]), float(v[i, e])
                x = a - float(sums[e, s, 1])
                y = b - float(sums[e, s, 2])
                z = (a * a + b * b) - float(sums[e, s, 3])
                assert np.float64(x).tobytes() == du[i, e].tobytes() and np.float64(y).tobytes() == dv[i, e].tobytes()
                assert np.float64(z).tobytes() == dy[i, e].tobytes()
                for k, term in enumerate((x * x, x * y, y * y, x * z, y * z)):
                    acc[k] = acc[k] + term
            want += acc
    assert np.array(got).tobytes() == np.array(want).tobytes()


# --- stop 64, ext64 ---


def _taxicab_core(own: np.ndarray, iterations: int) -> np.ndarray:
    """The pixels of ``own`` (h, w) bool farther than ``iterations`` taxicab steps from every pixel not its own
    (beyond the array not its own): stop 60's distance map, by brute force."""
    h, w = own.shape
    far = np.zeros((h, w), bool)
    yy, xx = np.mgrid[-1 : h + 1, -1 : w + 1]
    framed = np.zeros((h + 2, w + 2), bool)
    framed[1:-1, 1:-1] = own
    ys, xs = yy[~framed], xx[~framed]
    for r in range(h):
        for c in range(w):
            far[r, c] = bool((np.abs(ys - r) + np.abs(xs - c)).min() > iterations)
    return far


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 12))
def test_surface_apex_core_by_passes_of_the_cross(seed, iterations):
    """Stop 64: the apex's core by ``iterations`` passes of the cross (no distance map) keeps the pixels farther than
    ``iterations`` taxicab steps from any pixel not the box's mask (brute force), on random boxes of 1-30 rows and
    columns (full, empty of core, with holes, one row or column) anywhere in a window, eroded 0-12 times: the apex
    is the first least 5 x 5 median among those core pixels that are near, as the twin's pass finds it."""
    from symfruit.core.surface import median_at

    rng = np.random.default_rng(seed)
    bh, bw = (int(x) for x in rng.integers(1, 31, 2))
    kind = int(rng.integers(0, 3))
    own = np.ones((bh, bw), bool) if kind == 0 else rng.random((bh, bw)) >= (0.03 if kind == 1 else 0.3)
    r0, c0 = (int(x) for x in rng.integers(0, 6, 2))
    h, w = r0 + bh + int(rng.integers(0, 6)), c0 + bw + int(rng.integers(0, 6))
    mask = np.zeros((h, w), bool)
    mask[r0 : r0 + bh, c0 : c0 + bw] = own
    near = (rng.random((h, w)) >= rng.choice([0.0, 0.1])) & (mask | (rng.random((h, w)) < 0.2))
    if not near.any():
        near[r0, c0] = True
    depth = np.round(rng.uniform(0.5, 0.52, (h, w)), 3)
    core = np.zeros((h, w), bool)
    core[r0 : r0 + bh, c0 : c0 + bw] = _taxicab_core(own, iterations)
    core &= near
    if core.any():
        rows, cols = np.nonzero(core)
    else:
        rows, cols = np.nonzero(near & mask if (near & mask).any() else near)
    first = int(np.argmin(median_at(np.where(near, depth, np.inf), rows, cols, size=5)))
    got = _jit.surface_apex(mask[r0 : r0 + bh, c0 : c0 + bw], iterations, near, depth, mask, r0, c0, 5)
    assert (int(got[0]), int(got[1])) == (int(rows[first]), int(cols[first]))


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_deep_pixels_are_the_distance_maps(seed):
    """Stop 64: ``deep_pixels`` ors into ``out`` the pixels of ``near`` whose ``near_distance`` to the box's pixels not
    the mask's lies beyond ``deep_px``, as ``surface_cap`` did with the map: random masks (sparse holes, a single
    pixel out, none out), boxes anywhere, ``near`` and ``out`` random, ``deep_px`` any, a whole number, a square
    root or one just below it (where the float limit and the root disagree first)."""
    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 40, 2))
    mask = rng.random((h, w)) < rng.uniform(0.5, 1.0)
    kind = int(rng.integers(0, 4))
    if kind in (1, 3):  # one to three pixels out: distances met exactly at the limit
        mask[:] = True
        for _ in range(1 if kind == 1 else int(rng.integers(2, 4))):
            mask[rng.integers(0, h), rng.integers(0, w)] = False
    elif kind == 2:
        mask[:] = True
    near = rng.random((h, w)) < rng.uniform(0.3, 1.0)
    a0, b0 = int(rng.integers(0, h)), int(rng.integers(0, w))
    a1, b1 = int(rng.integers(a0 + 1, h + 1)), int(rng.integers(b0 + 1, w + 1))
    root = math.sqrt(int(rng.integers(1, 400)))
    deep_px = float(rng.choice([rng.uniform(0, 20), float(rng.integers(0, 20)), root, np.nextafter(root, 0)]))
    before = rng.random((h, w)) < rng.choice([0.0, 0.3])
    inner = np.zeros((h, w))
    _jit.near_distance(mask[a0:a1, b0:b1], deep_px, False, inner[a0:a1, b0:b1])
    want = before | (near & (inner > deep_px))
    got = before.copy()
    _jit.deep_pixels(mask, a0, a1, b0, b1, deep_px, near, got)
    np.testing.assert_array_equal(got, want)


def test_deep_pixels_known_answer():
    """Stop 64: one pixel out of a full mask, ``deep_px`` 4: the pixels at a distance of exactly 4 (the same row or
    column) are not deeper, those beyond are, those nearer are not; ``out``'s pixels stay, beyond the box none is
    added, and the pixels not ``near`` are left."""
    mask = np.ones((20, 20), bool)
    mask[10, 10] = False
    near = np.ones((20, 20), bool)
    near[0, 0] = False
    out = np.zeros((20, 20), bool)
    out[10, 11] = True
    _jit.deep_pixels(mask, 1, 20, 0, 20, 4.0, near, out)
    rr, cc = np.mgrid[:20, :20]
    d2 = (rr - 10) ** 2 + (cc - 10) ** 2
    want = (d2 > 16) & near
    want[0, :] = False  # beyond the box
    want[10, 11] = True
    np.testing.assert_array_equal(out, want)


# --- stop 65, look65


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 30), st.integers(1, 30), st.integers(1, 12))
def test_the_reach_fill_leaves_its_maps_as_they_came(seed, h, w, cap):
    """_reach_fill's map of the pixels a run may still take is its own (join copied): join and seen are left as they
    came whether the fill ends or runs out of seeds, so _reach_box's second try reads them whole; its box is
    _flood_box's."""
    rng = np.random.default_rng(seed)
    join = rng.random((h, w)) < rng.uniform(0.2, 0.95)
    seen = rng.random((h, w)) < rng.uniform(0.01, 0.3)
    if not seen.any():
        seen[h // 2, w // 2] = True
    rows, cols = np.nonzero(seen)
    box = (int(rows.min()), int(rows.max()) + 1, int(cols.min()), int(cols.max()) + 1)
    join_in, seen_in = join.copy(), seen.copy()
    _jit._reach_fill(join, seen, *box, np.empty(cap, np.int64))
    assert np.array_equal(join, join_in) and np.array_equal(seen, seen_in)
    got = tuple(int(x) for x in _jit._reach_box(join, seen, *box))
    assert got == tuple(int(x) for x in _jit._flood_box(join_in, seen_in, *box)[1:])
    assert np.array_equal(join, join_in) and np.array_equal(seen, seen_in)


def test_the_allowed_box_off_the_window_and_at_its_corners_known_answer():
    """allowed_box with the region wholly off each side of the window (not found), and one seen pixel at each corner
    of the window near a hidden run (the box of the run and the pixel where a gap joins them); the seen box is found
    by rows."""
    hidden = np.zeros((6, 8), bool)
    region = np.ones((2, 3), bool)
    for dr, dc in ((-2, 0), (6, 0), (0, -3), (0, 8), (-5, -9), (7, 9)):
        assert not _jit.allowed_box(hidden, region, dr, dc, 2, 0)[0]
    hidden[2, 1:7] = True  # a run along row 2
    one = np.zeros((3, 3), bool)
    one[1, 1] = True  # the region's one seen pixel at (dr + 1, dc + 1)
    assert tuple(_jit.allowed_box(hidden, one, -1, -1, 1, 0)) == (True, 0, 3, 0, 7)  # (0, 0): the run 2 rows down
    assert tuple(_jit.allowed_box(hidden, one, -1, 6, 1, 0)) == (True, 0, 3, 1, 8)  # (0, 7)
    assert tuple(_jit.allowed_box(hidden, one, 4, -1, 1, 0)) == (True, 5, 6, 0, 1)  # (5, 0): 3 rows off, no join
    assert tuple(_jit.allowed_box(hidden, one, 4, -1, 2, 0)) == (True, 2, 6, 0, 7)  # a gap of 2 joins
    assert tuple(_jit.allowed_box(hidden, one, 4, 6, 2, 0)) == (True, 2, 6, 1, 8)  # (5, 7)
    assert tuple(_jit.allowed_box(hidden, one, 4, 6, 0, 0)) == (True, 5, 6, 7, 8)  # no gap: the pixel alone


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 30))
def test_first_nearest_label_is_first_nearests(seed, k, m):
    """first_nearest_label (the kernels' pick among equally near edge points of both labels) against the numpy twin's
    _first_nearest, query by query: points on whole pixels of a small grid (many equally near), queries on whole and
    half pixels, now and then a point with a NaN coordinate (argmin takes the first NaN) or an infinite one."""
    from symfruit.core.agreement import _first_nearest

    rng = np.random.default_rng(seed)
    points = rng.integers(0, 6, (k, 2)).astype(np.float64)
    labels = rng.random(k) < 0.5
    queries = rng.integers(0, 12, (m, 2)) / 2.0
    if rng.random() < 0.2:
        points[int(rng.integers(0, k)), int(rng.integers(0, 2))] = rng.choice([np.nan, np.inf, -np.inf])
    want = _first_nearest(points, labels, queries)
    got = np.array([_jit.first_nearest_label(points, labels, float(qx), float(qy)) for qx, qy in queries])
    assert np.array_equal(got, want)


def test_first_nearest_label_known_answer():
    """Two points equally near (1 px either side of the query): the first one's label, either way round; a nearer
    point later in the order wins; a NaN point wins wherever it lies (np.argmin's first NaN)."""
    points = np.array([[0.0, 0.0], [2.0, 0.0], [1.0, 0.5]])
    assert not _jit.first_nearest_label(points[:2], np.array([False, True]), 1.0, 0.0)
    assert _jit.first_nearest_label(points[:2], np.array([True, False]), 1.0, 0.0)
    assert _jit.first_nearest_label(points, np.array([False, False, True]), 1.0, 0.0)
    points[1, 0] = np.nan
    assert _jit.first_nearest_label(points, np.array([False, True, False]), 1.0, 0.0)


# --- stop 65, cand65


def _outline_case(seed):
    """A solid of revolution, a window's mask and hidden pixels, a camera and a step for ``outline_radii``: rings in
    front of the camera, on its plane (z 0) or behind it, NaN borders, squashed sections, masks of blobs, noise, full
    or empty, walks from inside and outside the window."""
    from symfruit.core.camera import Camera
    from symfruit.core.fits import Revolution
    from symfruit.core.raster import silhouette

    rng = np.random.default_rng(seed)
    camera = Camera(fx=float(rng.uniform(200, 900)), fy=float(rng.uniform(200, 900)), cx=float(rng.uniform(100, 400)),
                    cy=float(rng.uniform(100, 300)), width=640, height=480)  # fmt: skip
    b = int(rng.integers(0, 20))
    point = np.array([rng.normal(0.0, 0.04), rng.normal(0.0, 0.04), rng.uniform(0.15, 0.9)])
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    edges = np.sort(rng.normal(0.0, 0.03, b + 1))
    kind = rng.random()
    if kind < 0.05:
        edges[int(rng.integers(b + 1))] = np.nan
    elif kind < 0.1:
        point[2] = -edges[0] * direction[2]  # the first ring's centre on the camera's plane
    ratio, deep = 1.0, None
    if rng.random() < 0.3:
        ratio, deep = float(rng.uniform(0.7, 1.3)), point / np.linalg.norm(point)
    rev = Revolution(point, direction, edges, np.full(b, 0.02), 0.0, ratio, deep)
    shape = rng.random()
    blob = point + rng.normal(0.0, rng.uniform(0.005, 0.04), (400, 3)) * [1.0, 1.0, 0.2]
    uv = camera.project(blob)
    blob = blob[(blob[:, 2] > 0.05) & (uv[:, 0] > 0) & (uv[:, 0] < 639) & (uv[:, 1] > 0) & (uv[:, 1] < 479)]
    if shape < 0.5 and len(blob):  # the silhouette of a blob about the solid's point
        region = silhouette(blob, camera)
        mask, origin = region.mask, (region.u0, region.v0)
    else:
        h, w = (int(x) for x in rng.integers(1, 60, 2))
        u, v = camera.project(point)
        origin = (int(u) - int(rng.integers(0, w)), int(v) - int(rng.integers(0, h)))
        mask = np.ones((h, w), bool) if shape < 0.6 else np.zeros((h, w), bool) if shape < 0.65 else \
            rng.random((h, w)) < rng.uniform(0.5, 1.0)  # fmt: skip
    hidden = rng.random(mask.shape) < 0.15 if rng.random() < 0.4 else None
    step = [0.25, 0.5, 1.0, 1, 0.3][int(rng.integers(5))]
    return rev, mask, origin, camera, step, hidden


@settings(max_examples=400, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_outline_radii_kernel_is_the_twins_to_the_bit(seed):
    """:func:`symfruit.core.fits.outline_radii` with :func:`symfruit.core._jit.outline_radii` and with its numpy twin
    (the walks of ``_first_out``): the same radii bit for bit (NaN where the twin's are) on random solids, masks,
    hidden pixels, cameras and steps."""
    from symfruit.core.fits import outline_radii

    rev, mask, origin, camera, step, hidden = _outline_case(seed)
    with pytest.MonkeyPatch.context() as mp, np.errstate(all="ignore"):  # the twin's casts of NaN warn
        fast, twin = _both(mp, outline_radii, rev, mask, origin, camera, step=step, hidden=hidden)
    assert fast.dtype == twin.dtype == np.float64 and fast.shape == twin.shape
    assert fast.tobytes() == twin.tobytes()


def test_the_outline_radii_kernel_reads_a_fruits_outline():
    """The kernel's radii of a rendered lemon's solid are its twin's, most of them finite (so the test above is not
    only about NaN), and a hidden pixel where a walk leaves the mask takes that slice's radius away in both."""
    from symfruit import DEFAULT_CAMERA
    from symfruit.core.fits import outline_radii
    from symfruit.core.raster import silhouette

    fruit = FRUITS["lemon"](np.random.default_rng(1))
    visible, _ = rendered_view(fruit, [0.02, 0.0, 0.35], noise=0.01, rotation=rotation(10, 30, 60), seed=3)
    rev = fit_revolution_slices(visible[::10])
    region = silhouette(visible, DEFAULT_CAMERA)
    args = (rev, region.mask, (region.u0, region.v0), DEFAULT_CAMERA)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, outline_radii, *args)
    assert fast.tobytes() == twin.tobytes() and np.isfinite(fast).sum() >= 0.6 * len(fast)
    hidden = ~region.mask  # every pixel off the fruit hidden: every walk leaves onto one
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, outline_radii, *args, hidden=hidden)
    assert fast.tobytes() == twin.tobytes() and np.isnan(fast).all()


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 300), st.integers(1, 7), st.sampled_from(["finite", "nan", "inf"]))
def test_the_revolution_points_are_numpys(seed, n, every, kind):
    """:func:`symfruit.core._jit.revolution_points`: False where a coordinate is not finite, else the points' mean (as
    :func:`~symfruit.core.points.column_means` gives it, numpy's ``mean(axis=0)``), the points less it and every
    ``every``-th of those, each bit for bit numpy's."""
    rng = np.random.default_rng(seed)
    pts = rng.normal(0.0, 0.03, (n, 3)) + [0.0, 0.0, 0.4]
    if kind != "finite":
        pts[int(rng.integers(n)), int(rng.integers(3))] = np.nan if kind == "nan" else -np.inf
    ok, centre, q, qs = _jit.revolution_points(pts, every)
    assert ok == (kind == "finite")
    if ok:
        want = pts - pts.mean(axis=0)
        assert centre.tobytes() == pts.mean(axis=0).tobytes() and q.tobytes() == want.tobytes()
        assert qs.flags.c_contiguous and qs.tobytes() == np.ascontiguousarray(want[::every]).tobytes()


@pytest.mark.parametrize("ratio", [1.0, 0.8])
def test_a_solid_of_revolution_of_points_not_all_finite_is_that_of_the_finite_ones(ratio):
    """:func:`~symfruit.core.fits.fit_revolution_slices` with a NaN or an infinite coordinate among the points (the
    kernels' one-call start declines them) fits the finite points alone, as before, with the kernels and with the
    twins; fewer than 20 finite points raise."""
    from symfruit.core.fits import fit_revolution_slices as fit
    from symfruit.errors import InputError

    rng = np.random.default_rng(5)
    points = FRUITS["pear"](rng).sample(700, rng) + CENTRE
    points = points[points[:, 2] <= np.median(points[:, 2])]
    spoilt = points.copy()
    spoilt[[3, 40, 41], [0, 2, 1]] = [np.nan, np.inf, -np.inf]
    kept = np.delete(points, [3, 40, 41], axis=0)
    with pytest.MonkeyPatch.context() as mp:
        fast, twin = _both(mp, fit, spoilt, ratio=ratio)
        alone = _both(mp, fit, kept, ratio=ratio)
    for got, want in ((fast, alone[0]), (twin, alone[1])):  # (the kernels' and the twin's solids differ in rounding)
        for name in ("point", "direction", "edges", "radii"):
            assert getattr(got, name).tobytes() == getattr(want, name).tobytes()
        assert got.cost == want.cost
    with pytest.raises(InputError):
        fit(np.vstack([points[:19], spoilt[40:41]]))


# --- stop 65 (glue65): outline_circle's elementwise glue ---------------------------------------------------


@pytest.mark.parametrize("n", [3, 7, 8, 9, 60, 129, 300, 1031])
def test_circle_design_and_mean_square_are_numpys_expressions_to_the_bit(n):
    """:func:`_jit.circle_design` and :func:`_jit.circle_mean_square` give the values of the numpy expressions they
    replace in :func:`~symfruit.core.raster.outline_circle` bit for bit: the points about their mean, ``z`` and its
    mean, the mean squared distance from the circle (numpy's pairwise sums: more than 8 and more than 128 values
    take its other branches; a sum left to right differs from 9 values on)."""
    rng = np.random.default_rng(n)
    for _ in range(20):
        centre = rng.uniform(-300.0, 900.0, size=2)
        t = rng.uniform(0.0, rng.uniform(0.5, 2.0 * np.pi), size=n)
        r = rng.uniform(3.0, 200.0)
        pts = np.column_stack((centre[0] + r * np.cos(t), centre[1] + r * np.sin(t)))
        pts = np.round(pts + rng.normal(scale=rng.uniform(0.0, 2.0), size=pts.shape)) + 0.5 * rng.integers(
            0, 2, pts.shape
        )
        mu, x, y, z, z_mean = _jit.circle_design(pts)
        mu0 = pts.mean(axis=0)
        x0, y0 = pts[:, 0] - mu0[0], pts[:, 1] - mu0[1]
        z0 = x0 * x0 + y0 * y0
        for got, want in ((mu, mu0), (x, x0), (y, y0), (z, z0)):
            assert got.tobytes() == want.tobytes()
        assert z_mean == float(z0.mean())
        cu, cv, rr = rng.normal(scale=3.0), rng.normal(scale=3.0), r * rng.uniform(0.8, 1.2)
        off = np.sqrt((x0 - cu) ** 2 + (y0 - cv) ** 2) - rr
        assert _jit.circle_mean_square(x, y, cu, cv, rr) == float((off * off).mean())
