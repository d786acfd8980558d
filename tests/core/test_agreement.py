"""How well a closed shape explains a view: rays, silhouette bands, ray marching, the evidence measures."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from symfruit.core.agreement import Observation, Quadric, explain, intersect_quadric, march, observe
from symfruit.core.raster import silhouette

from ..conftest import ball_mesh, rendered_view


def ball(c, r):
    return lambda x: r - np.linalg.norm(x - c, axis=-1)


def test_march_hits_a_ball_at_its_surface():
    c, r = np.array([0.0, 0.0, 0.4]), 0.03
    rays = np.array([[0.0, 0.0, 1.0], [0.05, 0.0, 1.0], [0.2, 0.0, 1.0]])
    hit, depth = march(ball(c, r), rays, 0.35, 0.45, steps=64)
    assert hit.tolist() == [True, True, False] and np.isnan(depth[2])
    assert depth[0] == pytest.approx(0.37, abs=2e-4)
    # ray (0.05, 0, 1): |z d - c| = r  ->  z^2 (1 + 0.0025) - 0.8 z + 0.16 - 0.0009 = 0
    a, b, cc = 1.0025, -0.8, 0.16 - 0.0009
    assert depth[1] == pytest.approx((-b - np.sqrt(b * b - 4 * a * cc)) / (2 * a), abs=3e-4)
    inside, depth_inside = march(ball(c, r), rays[:1], 0.39, 0.45, steps=8)
    assert inside[0] and depth_inside[0] == 0.39  # the ray starts inside


def test_closed_form_meets_a_ball_where_its_quadratic_says():
    c, r = np.array([0.0, 0.0, 0.4]), 0.03
    rays = np.array([[0.0, 0.0, 1.0], [0.05, 0.0, 1.0], [0.2, 0.0, 1.0]])
    hit, depth = intersect_quadric(c, np.eye(3) / r**2, rays, 0.35, 0.45)
    assert hit.tolist() == [True, True, False] and np.isnan(depth[2])
    assert depth[0] == pytest.approx(0.37, abs=1e-12)
    a, b, cc = 1.0025, -0.8, 0.16 - 0.0009  # |z d - c| = r along d = (0.05, 0, 1)
    assert depth[1] == pytest.approx((-b - np.sqrt(b * b - 4 * a * cc)) / (2 * a), abs=1e-12)


def test_closed_form_tangent_rays_miss_and_a_ray_starting_inside_enters_at_once():
    c, r = np.array([0.0, 0.0, 0.4]), 0.03
    # the ray through (r, 0, 0.4) tangent to the ball's silhouette: x = t z, |t z - 0|^2 + (z - 0.4)^2 = r^2 has a
    # double root where t^2 = r^2 / (0.4^2 - r^2)
    t = r / np.sqrt(0.4**2 - r**2)
    hit, _ = intersect_quadric(c, np.eye(3) / r**2, np.array([[t, 0.0, 1.0], [0.999 * t, 0.0, 1.0]]), 0.3, 0.5)
    assert hit.tolist() == [False, True]
    hit, depth = intersect_quadric(c, np.eye(3) / r**2, np.array([[0.0, 0.0, 1.0]]), 0.39, 0.45)
    assert hit[0] and depth[0] == 0.39  # inside at z0
    hit, _ = intersect_quadric(c, np.eye(3) / r**2, np.array([[0.0, 0.0, 1.0]]), 0.2, 0.36)
    assert not hit[0]  # the ball lies beyond the range
    hit, _ = intersect_quadric(c, np.eye(3) / r**2, np.array([[0.0, 0.0, 1.0]]), 0.44, 0.5)
    assert not hit[0]  # ... or before it


def test_closed_form_with_the_camera_inside_the_ellipsoid():
    # an ellipsoid around the origin (semi-axes 0.1, 0.2, 0.5): along +z from 0 the ray is inside until z = 0.5
    shape = np.diag([1 / 0.1**2, 1 / 0.2**2, 1 / 0.5**2])
    hit, depth = intersect_quadric(np.zeros(3), shape, np.array([[0.0, 0.0, 1.0], [0.1, 0.0, 1.0]]), 0.1, 1.0)
    assert hit.tolist() == [True, True] and depth.tolist() == [0.1, 0.1]
    hit, _ = intersect_quadric(np.zeros(3), shape, np.array([[0.0, 0.0, 1.0]]), 0.6, 1.0)
    assert not hit[0]  # the exit lies before the range


def test_closed_form_meets_a_rotated_ellipsoid_on_its_surface():
    rng = np.random.default_rng(4)
    rot, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    shape = rot @ np.diag(1 / np.array([0.02, 0.035, 0.05]) ** 2) @ rot.T
    c = np.array([0.01, -0.02, 0.45])
    rays = np.c_[rng.uniform(-0.12, 0.08, 200), rng.uniform(-0.15, 0.05, 200), np.ones(200)]
    hit, depth = intersect_quadric(c, shape, rays, 0.3, 0.6)
    assert 20 < hit.sum() < 200
    entry = rays[hit] * depth[hit, None]
    q = Quadric(c, shape)
    assert np.allclose(q(entry), 0.0, atol=1e-9)  # on the surface
    assert np.all(q(rays[hit] * (depth[hit, None] - 1e-4)) < 0)  # and entered there, not left
    assert np.all(q(rays[~hit, None, :] * np.linspace(0.3, 0.6, 301)[None, :, None]) <= 0)  # missed rays stay out


@settings(max_examples=40, deadline=None)
@given(
    st.integers(0, 2**32 - 1),
    st.floats(0.01, 0.06),
    st.floats(1.0, 3.0),
)
def test_closed_form_is_what_a_fine_march_converges_to(seed, size, elongation):
    rng = np.random.default_rng(seed)
    rot, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    semi = size * np.array([1.0, rng.uniform(1.0, elongation), elongation])
    shape = rot @ np.diag(1 / semi**2) @ rot.T
    c = np.r_[rng.uniform(-0.05, 0.05, 2), rng.uniform(0.3, 0.6)]
    rays = np.c_[rng.uniform(-0.3, 0.3, (300, 2)), np.ones(300)]
    z0, z1 = c[2] - 1.2 * semi.max(), c[2] + 1.2 * semi.max()
    hit, depth = intersect_quadric(c, shape, rays, z0, z1)
    steps = 1000  # a step of 0.04-0.4 mm: as fine as the bounds below need (4,000 took four times as long)
    hit_m, depth_m = march(Quadric(c, shape), rays, z0, z1, steps=steps)
    step = (z1 - z0) / (steps - 1)
    assert np.all(hit_m <= hit)  # the march sees no hit the closed form misses
    assert np.all(np.abs(depth[hit_m] - depth_m[hit_m]) <= step)
    # a ray the march misses has a chord shorter than two of its steps
    missed = hit & ~hit_m
    if missed.any():
        a = np.einsum("ni,ij,nj->n", rays[missed], shape, rays[missed])
        b = rays[missed] @ shape @ c
        chord = 2 * np.sqrt(np.maximum(b * b - a * (c @ shape @ c - 1), 0)) / a
        assert np.all(chord <= 2 * step)


def test_explain_uses_the_closed_form_of_a_quadric(camera):
    visible, _ = rendered_view(ball_mesh(), [0.0, 0.0, 0.4], noise=0.0, seed=3)
    region = silhouette(visible, camera)
    obs = observe(visible, region, camera)
    c, r = np.array([0.0, 0.0, 0.4]), 0.035
    box = (c - r, c + r)
    closed = explain(Quadric(c, np.eye(3) / r**2), box, obs, steps=16)
    marched = explain(ball(c, r), box, obs, steps=400)
    assert closed.depth == pytest.approx(marched.depth, abs=2e-4)
    assert closed.inside == pytest.approx(marched.inside, abs=0.02)
    assert closed.outside == pytest.approx(marched.outside, abs=0.02)


def test_observation_of_a_camera_view(camera):
    visible, _ = rendered_view(ball_mesh(), [0.0, 0.0, 0.4], noise=0.01, seed=3)
    obs = observe(visible[::10], silhouette(visible, camera), camera, n_rays=100, n_band=40)
    assert 90 <= len(obs.rays) <= 110 and np.allclose(obs.rays[:, 2], 1.0)
    assert np.allclose(obs.rays * obs.depth[:, None], visible[::10][:: max(1, len(visible[::10]) // 100)])
    assert [len(r) for r in obs.rays_in + obs.rays_out] == [40] * 4
    assert obs.contour > 0.8  # a camera sees a whole fruit's outline as a contour


def test_the_true_ball_explains_the_view_better_than_wrong_ones(camera):
    visible, _ = rendered_view(ball_mesh(), [0.0, 0.0, 0.4], noise=0.01, seed=3)
    obs = observe(visible[::10], silhouette(visible, camera), camera)
    c = np.array([0.0, 0.0, 0.4])
    good = explain(ball(c, 0.035), (c - 0.035, c + 0.035), obs)
    big = explain(ball(c, 0.041), (c - 0.041, c + 0.041), obs)
    off = explain(ball(c + [0.004, 0.0, 0.0], 0.035), (c - 0.035, c + 0.039), obs)
    deep = explain(ball(c + [0.0, 0.0, 0.005], 0.035), (c - 0.03, c + 0.04), obs)
    assert good.inside + good.outside < 0.05 and good.depth < 0.003
    assert big.outside > 0.5 and off.inside + off.outside > 0.3
    assert deep.depth > 2 * good.depth


def test_a_cut_cloud_is_not_a_contour(camera):
    """The paper's visibility rule cuts a clean scan by a plane: much of its edge is not the fruit's outline."""
    from symfruit.evaluate.protocols import Spec, build

    inst = build(Spec("paper", "citrus", 0, 0))
    obs = observe(inst.visible, silhouette(inst.visible, camera), camera)
    assert obs.contour < 0.8


def test_outside_rays_beside_a_cut_are_no_evidence(camera):
    from symfruit.evaluate.protocols import Spec, build

    inst = build(Spec("paper", "citrus", 0, 0))
    obs = observe(inst.visible, silhouette(inst.visible, camera), camera)
    weights = np.concatenate(obs.out_weights)
    assert 0.0 < weights.mean() < 0.9  # part of the edge is the cut, part the fruit's outline
    visible, _ = rendered_view(ball_mesh(), [0.0, 0.0, 0.4], noise=0.01, seed=3)
    whole = observe(visible[::10], silhouette(visible, camera), camera, dense=visible)
    assert np.concatenate(whole.out_weights).mean() > 0.95 and whole.contour > 0.95
    assert len(whole.interior) > 0.8 * len(visible[::10])


def test_an_occluders_edge_is_a_cut_with_the_occlusion_information(camera):
    """A leaf hides the lower third of a ball: from the points alone its edge looks like the ball's outline;
    the frame's depth says it is a cut, its outside rays are no evidence, and the cone is the ball's."""
    from symfruit.core.occlusion import occlusion
    from symfruit.core.raster import silhouette_cone

    from ..conftest import occluded_view

    centre = np.array([0.0, 0.0, 0.4])
    visible, depth, mask, _ = occluded_view(ball_mesh(), centre, below=255, occluder_z=0.33, noise=0.01, seed=2)
    region = silhouette(visible, camera)
    blind = observe(visible[::10], region, camera, dense=visible)
    occ = occlusion(depth, mask, visible, camera)
    seen = observe(visible[::10], region, camera, dense=visible, occlusion=occ)
    assert blind.contour > 0.9 and blind.cone_source == "moments"
    assert 0.55 < seen.contour < 0.85 and seen.cone_source == "contour"
    assert 0.0 < np.concatenate(seen.out_weights).mean() < 0.9
    whole, _ = observe(*_whole_ball(camera)).cone, None
    assert np.abs(seen.cone - whole).max() < np.abs(blind.cone - whole).max() / 3
    rows = np.nonzero(region.mask.any(axis=1))[0] + region.v0
    assert seen.extent is not None and seen.extent[1] == pytest.approx(rows[0] - 0.5)  # the ball's own top
    assert seen.extent[3] > rows[-1] + 40  # below, the ball may reach as far as the leaf (the window) goes
    assert silhouette_cone(region, camera)[0] == pytest.approx(blind.cone)


def test_the_hidden_map_is_made_when_first_read(camera):
    """Issue 19's seventeenth round: an observation with occlusion information makes its window's hidden map (each
    pixel with a hidden pixel within 2 px) on first read, once; without it there is none, and one given is kept."""
    from symfruit.core.occlusion import occlusion

    from ..conftest import occluded_view

    visible, depth, mask, _ = occluded_view(ball_mesh(), np.array([0.0, 0.0, 0.4]), below=255, occluder_z=0.33,
                                            noise=0.01, seed=2)  # fmt: skip
    region = silhouette(visible, camera)
    occ = occlusion(depth, mask, visible, camera)
    seen = observe(visible[::10], region, camera, dense=visible, occlusion=occ)
    assert seen.hidden is None
    made = seen.hidden_map()
    np.testing.assert_array_equal(made, occ.window(region, radius=2))
    assert made.any() and not made.all() and seen.hidden_map() is made
    assert observe(visible[::10], region, camera, dense=visible).hidden_map() is None
    given = np.zeros_like(made)
    assert Observation(rays=seen.rays, depth=seen.depth, rays_in=(), rays_out=(), hidden=given).hidden_map() is given


def _whole_ball(camera):
    visible, _ = rendered_view(ball_mesh(), [0.0, 0.0, 0.4], noise=0.01, seed=2)
    return visible[::10], silhouette(visible, camera), camera


def test_a_view_on_the_image_border_whose_points_round_beyond_it(camera):
    """A fruit cut by the image's last row, its points' sub-pixel projections within half a pixel of the
    border: one that rounds to the row beyond the image is no outline neighbour (it indexed past the window,
    an IndexError on a real pear scan's view touching the border)."""
    rng = np.random.default_rng(2)
    centre = np.array([0.0, (camera.height - 5 - camera.cy) / camera.fy * 0.4, 0.4])
    d = rng.normal(size=(60000, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    pts = centre + 0.03 * d
    pts = pts[(pts - centre)[:, 2] < 0]  # the front half
    v = camera.project(pts)[:, 1]
    pts = pts[v < camera.height - 0.1]  # in the image, some within half a pixel of its last row
    assert (camera.project(pts)[:, 1] > camera.height - 0.5).any()
    region = silhouette(pts, camera)
    obs = observe(pts[::5], region, camera, dense=pts)
    assert obs.contour < 1.0  # the border is a cut


@given(st.integers(0, 2**32 - 1), st.integers(2, 40))
def test_march_samples_every_ray_at_every_depth_as_broadcasting_did(seed, steps):
    """The march's points are made as tiled rows, the same products as ``rays[:, None] * zs[None, :, None]``."""
    rng = np.random.default_rng(seed)
    m = int(rng.integers(1, 60))
    rays = np.c_[rng.normal(0.0, 0.2, (m, 2)), np.ones(m)]
    seen = []

    def inside(x):
        seen.append(x.copy())
        return np.ones(x.shape[:-1])

    z0, z1 = sorted(rng.uniform(0.1, 2.0, 2))
    march(inside, rays, z0, z1, steps=steps)
    zs = np.linspace(z0, z1, steps)
    assert seen[0].shape == (len(rays), steps, 3)
    assert np.array_equal(seen[0], rays[:, None, :] * zs[None, :, None])


def _former_bands(hit_all, depth_all, obs, free=0.01):
    """explain()'s band shares as they were computed before the bands were packed (issue 19): band by band."""
    n = len(obs.rays)
    hits, depths = hit_all[n:], depth_all[n:]
    ins, outs, k = [], [], 0
    for r in obs.rays_in:
        ins.append(1.0 - hits[k : k + len(r)].mean() if len(r) else 0.0)
        k += len(r)
    for i, r in enumerate(obs.rays_out):
        w = np.ones(len(r)) if obs.out_weights is None else obs.out_weights[i]
        wrong = hits[k : k + len(r)] * w
        if obs.out_depth is not None:
            seen = obs.out_depth[i]
            with np.errstate(invalid="ignore"):
                carved = hits[k : k + len(r)] & (depths[k : k + len(r)] < seen - free)
            w = np.where(np.isfinite(seen), 1.0, w)
            wrong = np.where(np.isfinite(seen), carved, wrong)
        outs.append(float(wrong.sum() / w.sum()) if w.sum() > 0 else 0.0)
        k += len(r)
    return float(np.mean(ins)), float(np.mean(outs))


@given(st.integers(0, 2**32 - 1))
def test_packed_bands_give_the_band_by_band_shares(seed):
    """The bands packed once per observation (empty bands, bands of zero weight, no weights, seen depths or
    not): the same shares, to the bit, as band by band."""
    from symfruit.core.agreement import Observation

    rng = np.random.default_rng(seed)

    def rays(k):
        return np.c_[rng.normal(0.0, 0.1, (k, 2)), np.ones(k)]

    sizes_in = [int(rng.integers(0, 30)) * int(rng.random() < 0.8) for _ in range(int(rng.integers(1, 4)))]
    sizes_out = [int(rng.integers(0, 30)) * int(rng.random() < 0.8) for _ in range(int(rng.integers(1, 4)))]
    weights = (
        None if rng.random() < 0.3 else tuple((rng.random(k) < rng.uniform(0, 1)).astype(float) for k in sizes_out)
    )
    seen = None if rng.random() < 0.3 else tuple(np.where(rng.random(k) < 0.4, rng.uniform(0.3, 0.6, k), np.nan)
                                                 for k in sizes_out)  # fmt: skip
    obs = Observation(rays=rays(40), depth=rng.uniform(0.3, 0.6, 40), rays_in=tuple(rays(k) for k in sizes_in),
                      rays_out=tuple(rays(k) for k in sizes_out), out_weights=weights, out_depth=seen)  # fmt: skip
    total = 40 + sum(sizes_in) + sum(sizes_out)
    for _ in range(3):  # the packing is made once and read again
        hit_all = rng.random(total) < rng.uniform(0, 1)
        depth_all = np.where(hit_all, rng.uniform(0.3, 0.6, total), np.nan)

        class Fixed:
            def __init__(self, hit_all, depth_all):
                self.found = hit_all, depth_all

            def __call__(self, x):
                raise AssertionError("not marched")

            def intersect(self, every, z0, z1):
                assert len(every) == total
                return self.found

        got = explain(Fixed(hit_all, depth_all), (np.array([0, 0, 0.3]), np.array([0, 0, 0.6])), obs)
        with np.errstate(invalid="ignore", divide="ignore"):
            assert (got.inside, got.outside) == _former_bands(hit_all, depth_all, obs)


@pytest.mark.parametrize("noise, rim", [(0.0, 2.0), (0.01, 2.0), (0.01, 30.0)])
def test_an_observation_with_its_inner_map_cut_at_a_reach_is_the_same(noise, rim):
    """Issue 19's seventh round: with ``inner_reach`` the region's inner distance map is exact only up to what is
    read of it (+inf beyond), and the observation is the same, ray for ray, as with the whole map."""
    from symfruit import DEFAULT_CAMERA
    from symfruit.core.raster import inner_distance

    visible, _ = rendered_view(ball_mesh(), [0.01, -0.02, 0.4], noise=noise, seed=5)
    region = silhouette(visible, DEFAULT_CAMERA)
    full = observe(visible[::5], region, DEFAULT_CAMERA, dense=visible)
    cut = observe(visible[::5], region, DEFAULT_CAMERA, dense=visible, inner_reach=rim)
    assert cut.inner_reach == max(rim, 8.0) and full.inner_reach == np.inf
    for name in ("rays", "depth", "interior", "cone", "axis"):
        np.testing.assert_array_equal(getattr(cut, name), getattr(full, name))
    assert cut.contour == full.contour
    for a, b in zip(cut.rays_in + cut.rays_out, full.rays_in + full.rays_out, strict=True):
        np.testing.assert_array_equal(a, b)
    within = full.inner <= cut.inner_reach
    np.testing.assert_array_equal(cut.inner[within], full.inner[within])
    assert np.all(np.isinf(cut.inner[~within])) and (~within).any()
    np.testing.assert_array_equal(full.inner, inner_distance(region.mask))


@pytest.mark.parametrize("occluded", [False, True])
def test_the_bands_kept_whole_by_observe_are_the_joined_ones(camera, occluded):
    """Issue 19, stop 45: :func:`observe` keeps its bands whole and ``_bands`` packs those instead of joining the
    per-band tuples again: every packed array the same bytes as the joined ones, with occlusion information (seen
    depths, weights) and without; an observation whose tuples were replaced packs its own."""
    import dataclasses

    from symfruit.core.agreement import _bands

    from ..conftest import occluded_view

    visible, depth, mask, _ = occluded_view(ball_mesh(), np.array([0.0, 0.0, 0.4]), below=255, occluder_z=0.33,
                                            noise=0.01, seed=2)  # fmt: skip
    occ = None
    if occluded:
        from symfruit.core.occlusion import occlusion

        occ = occlusion(depth, mask, visible, camera)
    obs = observe(visible[::10], silhouette(visible, camera), camera, dense=visible, occlusion=occ)
    assert obs._parts is not None and (obs.out_depth is not None) == occluded
    joined = dataclasses.replace(obs, _parts=None)
    kept, made = _bands(obs), _bands(joined)
    assert _bands(obs) is kept  # made once
    for name in ("rays", "n_in", "in_starts", "in_sizes", "in_ok", "out_starts", "out_w", "out_wsum", "out_rays",
                 "out_ok", "seen", "finite"):  # fmt: skip
        a, b = getattr(kept, name), getattr(made, name)
        assert (a is None) == (b is None)
        if a is not None:
            a, b = np.asarray(a), np.asarray(b)
            assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes(), name
    assert made.n_in == sum(len(r) for r in obs.rays_in) > 0 and made.out_w.sum() > 0
    # other tuples than the parts were sliced into: the parts are not read
    cut_depth = None if obs.out_depth is None else tuple(d[:3] for d in obs.out_depth)
    other = dataclasses.replace(obs, rays_out=tuple(r[:3] for r in obs.rays_out),
                                out_weights=tuple(w[:3] for w in obs.out_weights), out_depth=cut_depth)  # fmt: skip
    assert len(_bands(other).rays) == len(obs.rays) + made.n_in + 3 * len(obs.rays_out)


def _masked_view(camera, rim_px: int, cap: float | None = None):
    """A fruit seen whole (nothing in front of it, a backdrop at 1 m): a ball at 0.4 m, or with ``cap`` (metres)
    only its front cap nearer than ``0.4 - cap`` (the rest of the ball is backdrop: the cap's edge faces the camera).
    Its mask is the fruit's pixels, its points those at least ``rim_px`` inside the mask's edge, as ``detect`` takes
    a fruit: extraction leaves out the mask's mixed border (``extract.erode_px``, 1 px), and a time-of-flight camera
    returns no depth on a grazing rim besides. ``(points, own region, region grown to the mask, occlusion)``."""
    from scipy import ndimage

    from symfruit.core.occlusion import occlusion, with_own

    from ..conftest import occluded_view

    _, depth, mask, _ = occluded_view(ball_mesh(), np.array([0.0, 0.0, 0.4]), below=10 * camera.height,
                                      occluder_z=0.3)  # fmt: skip
    if cap is not None:
        depth = np.where(mask & (depth > 0.4 - cap), 1.0, depth)
        mask = mask & (depth < 0.4 - cap)
    kept = ndimage.binary_erosion(mask, np.ones((3, 3), bool), iterations=rim_px)
    depth = np.where(mask & ~kept, 0.0, depth)  # no depth on the border the points were not taken from
    rows, cols = np.nonzero(kept)
    points = camera.deproject(np.c_[cols, rows].astype(float), depth[rows, cols])
    own = silhouette(points, camera)
    occ = occlusion(depth, mask, points, camera, eroded=1)
    return points, own, with_own(own, occ), occ


@pytest.mark.parametrize(("rim_px", "cap"), [(1, 0.02), (10, None)])
def test_edge_normals_do_not_vote_on_a_region_grown_to_the_fruits_mask(camera, rim_px, cap):
    """Issue 18, stop 52 (docs/edges52.md): the edge points whose normals label the outline are the points within
    1.5 px of the region's edge. ``evidence`` grows the region to the fruit's mask (``with_own``) before
    ``observe``, and every point of a fruit ``detect`` extracted lies at least 2 px inside the mask (the eroded
    border), so the normals never vote there: the outline's labels come from the occlusion information alone (none
    hidden near the outline here: all of it a contour). Measured from the points' own edge instead, the normals
    vote: a front cap's edge (1 px eroded) faces the camera, and so does a whole ball's where a time-of-flight
    camera lost its grazing rim (10 px here, the real sphere frames' case): most of the outline would be a cut."""
    points, own, grown, occ = _masked_view(camera, rim_px, cap)
    assert grown.mask.sum() > own.mask.sum()  # the mask reaches beyond the points
    silent = observe(points[::10], grown, camera, dense=points, occlusion=occ, inner_reach=8.0)
    assert silent.contour == 1.0
    voting = observe(points[::10], own, camera, dense=points, occlusion=occ, inner_reach=8.0)
    assert voting.contour < 0.5
