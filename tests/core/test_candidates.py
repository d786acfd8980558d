"""The default method's candidate completions: their boxes made consistent with the view, and their evidence."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from symfruit import DEFAULT_CAMERA
from symfruit.core.agreement import observe
from symfruit.core.candidates import REACH, SPHERE_TOLERANCE, candidates, constrain_box
from symfruit.core.fits import fit_sphere
from symfruit.core.planes import PlaneGrid
from symfruit.core.raster import silhouette

from ..conftest import ball_mesh, noisy_cap, rendered_view

coord = st.floats(-0.05, 0.05, allow_nan=False)


@given(st.lists(coord, min_size=12, max_size=12), st.floats(0.0, 1.0))
def test_constrained_boxes_hold_the_seen_box_behind_the_front(values, contour):
    v = np.array(values)
    seen_lo, seen_hi = np.minimum(v[:3], v[3:6]) + [0, 0, 0.4], np.maximum(v[:3], v[3:6]) + [0, 0, 0.4]
    lo, hi = np.minimum(v[6:9], v[9:]) + [0, 0, 0.4], np.maximum(v[6:9], v[9:]) + [0, 0, 0.4]
    front = seen_lo[2] + 0.001
    out_lo, out_hi = constrain_box(lo, hi, seen_lo, seen_hi, front, contour=contour)
    assert out_lo[2] == front and out_hi[2] >= max(seen_hi[2], front)
    assert np.all(out_lo[:2] <= seen_lo[:2]) and np.all(out_hi[:2] >= seen_hi[:2])
    near, far = np.r_[seen_lo[:2], front], np.maximum(seen_hi, np.r_[seen_lo[:2], front])
    reach = REACH / max(contour, 0.5) * (far - near)
    assert np.all(out_hi <= np.maximum(near + reach, far + [0, 0, 1e-4]) + 1e-12)
    assert np.all(out_lo >= np.minimum(far - reach, near) - 1e-12)


def _former_constrain_box(lo, hi, seen_lo, seen_hi, front, *, cone=None, contour=1.0, pull=None):
    """constrain_box as numpy arrays made it before issue 19's sixteenth round (Python floats since)."""
    seen_lo = np.concatenate((seen_lo[:2], [front]))
    seen_hi = np.maximum(seen_hi, seen_lo)
    reach = REACH / max(contour, 0.5) * (seen_hi - seen_lo)
    lo = np.minimum(np.maximum(np.asarray(lo, dtype=np.float64), seen_hi - reach), seen_lo)
    hi = np.maximum(np.minimum(np.asarray(hi, dtype=np.float64), seen_lo + reach), seen_hi)
    lo[2] = front
    hi[2] = max(hi[2], front + 1e-4)
    if cone is not None:
        (u_lo, v_lo, u_hi, v_hi), camera = cone
        zs = np.array([lo[2], hi[2]])
        bound_lo = np.array([((u_lo - camera.cx) / camera.fx * zs).min(), ((v_lo - camera.cy) / camera.fy * zs).min()])
        bound_hi = np.array([((u_hi - camera.cx) / camera.fx * zs).max(), ((v_hi - camera.cy) / camera.fy * zs).max()])
        share = contour if pull is None else pull
        lo[:2] = np.minimum(seen_lo[:2], lo[:2] + share * np.maximum(bound_lo - lo[:2], 0.0))
        hi[:2] = np.maximum(seen_hi[:2], hi[:2] - share * np.maximum(hi[:2] - bound_hi, 0.0))
    return lo, hi


edge = st.one_of(st.floats(-0.06, 0.06), st.sampled_from([0.0, -0.0, 0.4, np.inf, -np.inf, np.nan]))


@given(st.lists(edge, min_size=12, max_size=12), st.floats(0.3, 0.5), st.sampled_from([0.0, 0.3, 1.0, np.float64(0.7)]),
       st.one_of(st.none(), st.lists(st.one_of(st.floats(-50.0, 700.0), st.sampled_from([-np.inf, np.inf, 320.0])),
                                     min_size=4, max_size=4)), st.sampled_from([None, 1.0, 0.5]))  # fmt: skip
def test_constrain_box_is_the_former_array_arithmetic_to_the_bit(values, front, contour, pixels, pull):
    """Any box, seen box, front, contour, pixel bounds (unbounded sides included) and pull, NaN and signed zeros
    included: the same numbers as the former numpy arrays gave, bit for bit (a NaN where it gave NaN, whatever its
    sign and payload)."""
    v = np.array(values)
    cone = None if pixels is None else (tuple(pixels), DEFAULT_CAMERA)
    args = (v[:3], v[3:6], v[6:9] + [0, 0, 0.4], v[9:] + [0, 0, 0.4], front)
    with np.errstate(invalid="ignore", over="ignore"):
        got = constrain_box(*args, cone=cone, contour=contour, pull=pull)
        want = _former_constrain_box(*args, cone=cone, contour=contour, pull=pull)
    for a, b in zip(got, want, strict=True):
        assert a.dtype == b.dtype == np.float64 and a.shape == b.shape == (3,)
        assert np.array_equal(np.isnan(a), np.isnan(b))
        ok = ~np.isnan(a)
        assert a[ok].tobytes() == b[ok].tobytes()  # signed zeros too


def test_a_box_wider_than_the_silhouette_cone_is_pulled_back():
    seen_lo, seen_hi = np.array([-0.01, -0.01, 0.39]), np.array([0.01, 0.01, 0.40])
    uv_lo = DEFAULT_CAMERA.project(np.array([[-0.01, -0.01, 0.40]]))[0]
    uv_hi = DEFAULT_CAMERA.project(np.array([[0.01, 0.01, 0.40]]))[0]
    cone = ((uv_lo[0], uv_lo[1], uv_hi[0], uv_hi[1]), DEFAULT_CAMERA)
    lo, hi = constrain_box([-0.03, -0.01, 0.39], [0.03, 0.01, 0.41], seen_lo, seen_hi, 0.39, cone=cone)
    assert lo[0] == pytest.approx(-0.01 * 0.41 / 0.40) and hi[0] == pytest.approx(0.01 * 0.41 / 0.40)
    half = constrain_box([-0.03, -0.01, 0.39], [0.03, 0.01, 0.41], seen_lo, seen_hi, 0.39, cone=cone, contour=0.5)[0]
    assert half[0] == pytest.approx(0.5 * (-0.03 - 0.01 * 0.41 / 0.40))


def test_candidates_of_a_noisy_ball():
    visible, _ = rendered_view(ball_mesh(), [0.01, 0.0, 0.4], noise=0.01, seed=4)
    sample = visible[::8]
    obs = observe(sample, silhouette(visible, DEFAULT_CAMERA), DEFAULT_CAMERA)
    front = 0.4 - 0.035
    cands = candidates(visible, sample=sample, obs=obs, camera=DEFAULT_CAMERA, front=front)
    by = {c.name: c for c in cands}
    assert list(by) == ["sphere", "ellipsoid", "cone", "revolution", "raw"]
    assert all(c.lo[2] == front for c in cands)
    assert by["raw"].agreement is None and by["raw"].hi[2] == pytest.approx(visible[:, 2].max())
    s = by["sphere"]
    assert s.agreement.inside + s.agreement.outside < 0.1 and s.agreement.depth < 0.003
    np.testing.assert_allclose(s.centre, [0.01, 0.0, 0.4], atol=0.002)
    assert s.hi[2] == pytest.approx(0.435, abs=0.003)
    with_mirror = candidates(visible, sample=sample, obs=obs, camera=DEFAULT_CAMERA, front=front,
                             mirror={"grid": PlaneGrid(translations=8, translation_step=0.1)})  # fmt: skip
    assert [c.name for c in with_mirror] == ["sphere", "ellipsoid", "cone", "revolution", "mirror", "raw"]
    cone = by["cone"]  # tangent to the silhouette's cone: its box is the ball's, back face included
    np.testing.assert_allclose(cone.centre, [0.01, 0.0, 0.4], atol=0.001)
    assert cone.hi[2] == pytest.approx(0.435, abs=0.0015)
    # the seen points' bounds handed in: the same candidates to the bit
    seen = (visible.min(axis=0), visible.max(axis=0))
    again = candidates(visible, sample=sample, obs=obs, camera=DEFAULT_CAMERA, front=front, seen=seen)
    assert [c.name for c in again] == list(by)
    for a, b in zip(again, cands, strict=True):
        assert a.lo.tobytes() == b.lo.tobytes() and a.hi.tobytes() == b.hi.tobytes() and a.agreement == b.agreement


def test_the_outline_candidate_takes_its_profile_from_the_silhouette():
    from symfruit.synthetic.shapes import FRUITS, rotation

    visible, _ = rendered_view(FRUITS["strawberry"](np.random.default_rng(2)), [0.0, 0.02, 0.35], noise=0.01,
                               rotation=rotation(20, 60, 10), seed=1)  # fmt: skip
    sample = visible[::8]
    region = silhouette(visible, DEFAULT_CAMERA)
    obs = observe(sample, region, DEFAULT_CAMERA, dense=visible)
    cands = candidates(visible, sample=sample, obs=obs, camera=DEFAULT_CAMERA, front=float(visible[:, 2].min()),
                       shapes=("revolution",), region=region, outline_profile="add")  # fmt: skip
    assert [c.name for c in cands] == ["outline", "revolution", "raw"]
    replaced = candidates(visible, sample=sample, obs=obs, camera=DEFAULT_CAMERA, front=float(visible[:, 2].min()),
                          shapes=("revolution",), region=region, outline_profile="replace")  # fmt: skip
    assert [c.name for c in replaced] == ["revolution", "raw"]
    np.testing.assert_allclose(replaced[0].hi, cands[0].hi)


def test_a_box_implausible_for_what_was_seen_is_no_candidate():
    from symfruit.core.candidates import _plausible

    seen_lo, seen_hi = np.array([0.0, 0.0, 0.30]), np.array([0.04, 0.06, 0.33])
    reach = (1.0, 1.0)
    assert _plausible(seen_lo - [0.01, 0.0, 0.0], seen_hi + [0.0, 0.02, 0.05], seen_lo, seen_hi, reach)
    # Hidden depth beyond the deepest seen point: at most one largest lateral side (0.06 m).
    assert not _plausible(seen_lo, seen_hi + [0.0, 0.0, 0.061], seen_lo, seen_hi, reach)
    # A lateral face beyond the seen box by more than the seen extent along that axis (0.04 m in x) ...
    assert not _plausible(seen_lo - [0.041, 0.0, 0.0], seen_hi, seen_lo, seen_hi, reach)
    # ... unless where the fruit can project is known (occlusion information): then it is only clipped.
    assert _plausible(seen_lo - [0.041, 0.0, 0.0], seen_hi, seen_lo, seen_hi, reach, lateral=False)


def _former_plausible(lo, hi, seen_lo, seen_hi, reach, *, lateral=True, width=0.0):
    """_plausible as numpy's (3,) arrays made it before issue 19's nineteenth round (Python floats since)."""
    seen = seen_hi - seen_lo
    if hi[2] - seen_hi[2] > reach[1] * max(seen[0], seen[1], width):
        return False
    if lateral:
        over = np.maximum(seen_lo[:2] - lo[:2], hi[:2] - seen_hi[:2])
        return bool(np.all(over <= reach[0] * seen[:2]))
    return True


def test_plausible_is_the_former_array_arithmetic():
    """The plausibility test in Python floats decides as the former array arithmetic did, on 5,000 boxes around and
    beyond a seen box (faces on the bound, NaN faces, lateral test on and off)."""
    from symfruit.core.candidates import _plausible

    rng = np.random.default_rng(3)
    for i in range(5000):
        seen_lo = rng.normal(0, 0.02, 3) + [0, 0, 0.4]
        seen_hi = seen_lo + rng.uniform(0, 0.05, 3)
        seen = seen_hi - seen_lo
        reach = (float(rng.choice([0.5, 1.0, 2.0])), float(rng.choice([0.5, 1.0, 1.5])))
        lo = seen_lo - seen * rng.choice([0.0, 0.5, reach[0], 3.0], 3)
        hi = seen_hi + seen * rng.choice([0.0, 0.5, reach[0], reach[1], 3.0], 3)
        if i % 50 == 0:
            hi[int(rng.integers(0, 3))] = np.nan
        width = float(rng.choice([0.0, 0.03, 0.08]))
        lateral = bool(i % 3)
        with np.errstate(invalid="ignore"):
            want = _former_plausible(lo, hi, seen_lo, seen_hi, reach, lateral=lateral, width=width)
        assert _plausible(lo, hi, seen_lo, seen_hi, reach, lateral=lateral, width=width) is want
        # the corners as the lists of Python floats candidates() hands it (issue 19, stop 45): the same decision
        listed = (lo.tolist(), hi.tolist(), seen_lo.tolist(), seen_hi.tolist())
        assert _plausible(*listed, reach, lateral=lateral, width=width) is want


# --- stop 47, pearview47


def _half_ellipsoid(ratio: float, angle: float, n: int, seed: int) -> tuple[np.ndarray, float]:
    """The paper's visible half (:func:`~symfruit.synthetic.shapes.paper_visible`) of ``n`` points on an ellipsoid,
    35 mm across, 45 along its axis (y, turned ``angle`` degrees about x), ``35 ratio`` deep, 0.3 m away; and its
    back face's depth."""
    from symfruit.synthetic.shapes import paper_visible, rotation_x

    rng = np.random.default_rng(seed)
    u = rng.normal(size=(40 * n, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    radii = np.array([0.035, 0.045, 0.035 * ratio])
    g = 1.0 / np.linalg.norm(u / radii, axis=1)  # about uniform over the surface
    p = (u * radii)[rng.random(len(u)) < g / g.max()][:n] @ rotation_x(angle).T + [0.0, 0.0, 0.3]
    return p[paper_visible(p)], float(p[:, 2].max())


@pytest.mark.parametrize(("ratio", "angle"), [(0.85, 0.0), (1.0, 0.0), (1.15, 0.0), (0.85, 20.0), (1.15, 20.0)])
def test_the_section_ratio_is_read_off_the_seen_half(ratio, angle):
    from symfruit.core.candidates import section_ratio
    from symfruit.core.fits import fit_revolution_slices

    seen, _ = _half_ellipsoid(ratio, angle, 4000, 3)
    assert section_ratio(seen, fit_revolution_slices(seen).direction) == pytest.approx(ratio, abs=0.03)


def test_no_section_ratio_along_the_line_of_sight_or_on_a_thin_cap():
    from symfruit.core.candidates import section_ratio

    seen, _ = _half_ellipsoid(0.85, 0.0, 4000, 3)
    assert section_ratio(seen, np.array([0.0, 0.4, np.sqrt(0.84)])) == 1.0  # the axis 66 deg out of the image
    cap = seen[seen[:, 2] < seen[:, 2].min() + 0.004]  # 4 mm of the front: no slice seen deep enough
    assert section_ratio(cap, np.array([0.0, 1.0, 0.0])) == 1.0


def test_sections_bring_the_solids_back_to_a_flattened_fruits():
    seen, back = _half_ellipsoid(0.85, 0.0, 1200, 5)
    obs = observe(seen, silhouette(seen, DEFAULT_CAMERA), DEFAULT_CAMERA)
    kwargs = {"sample": seen, "obs": obs, "camera": DEFAULT_CAMERA, "front": float(seen[:, 2].min()),
              "shapes": ("revolution",)}  # fmt: skip
    circles = {c.name: c for c in candidates(seen, **kwargs)}["revolution"]
    flat = {c.name: c for c in candidates(seen, **kwargs, sections=1.0)}["revolution"]
    # circles through a section 0.85 as deep as wide: about 35 * 2 * 0.15 = 10 mm too deep
    assert circles.hi[2] - back > 0.006
    assert abs(flat.hi[2] - back) < 0.3 * (circles.hi[2] - back)
    assert flat.lo.tolist()[:2] == pytest.approx(circles.lo.tolist()[:2], abs=0.002)
    again = {c.name: c for c in candidates(seen, **kwargs, sections=0.0)}["revolution"]
    assert again.hi.tobytes() == circles.hi.tobytes()  # 0: the circles, to the bit


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_sphere_candidates_stop_leaves_its_sphere_within_the_stop(seed):
    """The sphere candidate's Gauss-Newton stops at a step of ``SPHERE_TOLERANCE`` (10 um; stop 55, docs/fast55.md),
    not ``fit_sphere``'s 0.1 um: on noisy caps of 15-60 mm spheres its centre and radius lie within that of the
    0.1 um stop's (2.5 um at most over 300 such caps: each step moves them less than the last)."""
    points, _ = noisy_cap(seed)
    (c, r), (c0, r0) = fit_sphere(points, tolerance=SPHERE_TOLERANCE), fit_sphere(points)
    assert SPHERE_TOLERANCE == 1e-5
    assert float(np.abs(c - c0).max()) < SPHERE_TOLERANCE and abs(r - r0) < SPHERE_TOLERANCE
