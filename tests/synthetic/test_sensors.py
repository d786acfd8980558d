"""Sensor models of real RGB-D cameras: each artefact's known answer on a rendered sphere or plane."""

import re
from dataclasses import replace

import numpy as np
import pytest

from symfruit import Camera
from symfruit.synthetic.render import render
from symfruit.synthetic.sensors import (
    SENSOR_MODELS,
    SensorModel,
    annotate,
    apply_sensor,
    correlated_noise,
    sensor_model,
)

from ..conftest import ball_mesh

#: Everything random switched off: the artefact under test is the only one left.
QUIET = dict(sigma_const=0.0, sigma_linear=0.0, bias_const=0.0, bias_linear=0.0, lateral_px=0.0, dropout=0.0,
             grazing_dropout=0.0, flying_share=0.0, multipath_bias=0.0, registration_px=0.0, colour_baseline=0.0,
             mask_overshoot_px=0.0, mask_amodal_share=0.0)  # fmt: skip
SIDE = 240


def window(model: SensorModel) -> Camera:
    """A SIDE x SIDE window at the centre of the model's colour image (fast to render, same optics)."""
    cam = model.camera()
    return Camera(fx=cam.fx, fy=cam.fy, cx=SIDE / 2, cy=SIDE / 2, width=SIDE, height=SIDE)


def sphere_scene(cam: Camera, z: float, *, radius: float = 0.035, behind: float = 0.15):
    """A ball at depth ``z`` (its centre) on the optical axis, a fronto-parallel plane ``behind`` metres behind."""
    ball = ball_mesh(radius)
    vertices, faces = ball.vertices, ball.faces
    back = np.array([[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]]) + [0.0, 0.0, z + behind]
    return render([(vertices + [0.0, 0.0, z], faces), (back, np.array([[0, 1, 2], [0, 2, 3]]))], cam)


def run(model, shot, cam, seed=0, **kw):
    return apply_sensor(model, shot.depth, shot.ids, cam, np.random.default_rng(seed), facing=shot.facing, **kw)


def test_the_four_models_and_their_cameras():
    assert set(SENSOR_MODELS) == {"azure-kinect", "realsense-l515", "realsense-d435", "realsense-d405"}
    ak = sensor_model("azure-kinect").camera()
    assert (ak.width, ak.height) == (1920, 1080) and ak.fx == pytest.approx(960.0)  # 90 deg across 1920 px
    assert sensor_model("realsense-d435").camera().width == 1280
    assert sensor_model("azure-kinect").at(1280, 720).camera().fx == pytest.approx(640.0)
    assert sensor_model("azure-kinect").at(1280, 720).registration_px == pytest.approx(4.0)
    with pytest.raises(ValueError, match="known: azure-kinect"):
        sensor_model("kinect-v1")
    with pytest.raises(ValueError, match="baseline"):
        replace(SENSOR_MODELS["realsense-d435"], baseline=0.0)


def test_tof_rim_band_width_on_a_sphere():
    model = replace(SENSOR_MODELS["azure-kinect"], **QUIET)
    cam = window(model)
    shot = sphere_scene(cam, 1.0)
    out = run(model, shot, cam)
    row = out.depth[SIDE // 2]
    fruit = shot.ids[SIDE // 2] == 0
    right = int(np.flatnonzero(fruit).max())
    # Invalid run across the right silhouette: the mixed depth pixel, one depth pixel on the fruit's side (stop 44:
    # none on the background's, rim_far_px 0) and the grazing loss inside (none here: QUIET).
    zero = row == 0
    first = right
    while zero[first]:
        first -= 1
    last = right + 1
    while zero[last]:
        last += 1
    width = last - first - 1
    assert 2 * model.footprint - 1 <= width <= 3 * model.footprint + 1
    assert (out.depth[shot.ids == 0] > 0).mean() > 0.7  # the inside keeps its depth
    assert not (out.depth[60:180, 60:180] == 0)[np.hypot(*np.mgrid[-60:60, -60:60]) < 20].any()


def outline_reach(pixels: np.ndarray, pick, within: float = np.inf, sectors: int = 48) -> np.ndarray:
    """In each of ``sectors`` directions about the window's centre, the farthest (``pick`` np.maximum) or nearest
    (np.minimum) radius, colour px, of ``pixels`` within ``within`` px of the centre."""
    vv, uu = np.nonzero(pixels)
    rad = np.hypot(vv - SIDE / 2, uu - SIDE / 2)  # the optical axis (window's cx, cy)
    keep = rad < within
    vv, uu, rad = vv[keep], uu[keep], rad[keep]
    sector = ((np.arctan2(vv - SIDE / 2, uu - SIDE / 2) + np.pi) / (2 * np.pi) * sectors).astype(int)
    out = np.full(sectors, 0.0 if pick is np.maximum else np.inf)
    pick.at(out, sector % sectors, rad)
    return out


def test_tof_rim_is_invalidated_on_the_fruits_side_of_the_edge():
    """Stop 44: the real Azure Kinect frames keep the background's depth up to a sphere's outline and lose the
    sphere's rim inside it: ``rim_invalid_px`` invalidates the nearer surface's side of a mixed pixel only,
    ``rim_far_px`` the farther side's."""
    model = replace(SENSOR_MODELS["azure-kinect"], **{**QUIET, "rim_invalid_px": 2, "rim_far_px": 0})
    cam = window(model)
    shot = sphere_scene(cam, 1.0)
    fp = model.footprint
    r_px = 0.035 * cam.fx / 1.0
    for far_px in (0, 2):
        d = run(replace(model, rim_far_px=far_px), shot, cam).depth
        # the fruit's depth stops this far inside the outline, the background's starts this far outside (medians of
        # 48 directions: the depth grid's squares make single directions differ by a depth pixel)
        stop = r_px - np.median(outline_reach((d > 0) & (d < 1.0 + 0.01), np.maximum))
        start = np.median(outline_reach((d > 1.1) & (d < 1.2), np.minimum, within=r_px + 20)) - r_px
        # the fruit: half the mixed pixel and two depth pixels inside, whatever the far side does
        assert 1.8 * fp <= stop <= 3.5 * fp + 1
        if far_px == 0:
            assert start <= fp  # up to the mixed pixel
        else:
            assert 1.8 * fp <= start <= 3.5 * fp + 1
    # the measured Azure Kinect invalidates nothing on the far side; the L515 (no real frames) keeps its ring about the
    # edge as before stop 44
    assert SENSOR_MODELS["azure-kinect"].rim_far_px == 0 and SENSOR_MODELS["realsense-l515"].rim_far_px == 1


def test_tof_grazing_loss_stops_the_depth_inside_by_the_facing_angle():
    """Stop 44: a time-of-flight pixel whose surface turns from the ray returns too little light: with the Azure
    Kinect's grazing loss (lost below ``|cos|`` 0.3, kept above 0.65, a smooth threshold between), a 70 mm ball at
    0.6 m (57 colour px radius) keeps no depth pixel below 0.3 and every one above 0.65, about half between, so its
    depth stops 3-14 px inside the outline (R (1 - sqrt(1 - c^2)) at c = 0.3 and 0.65), 8 px on average as the real
    frames' sphere 1 (docs/realism44.md)."""
    ak = SENSOR_MODELS["azure-kinect"]
    assert (ak.grazing, ak.grazing_ramp, ak.grazing_dropout) == (0.3, 0.35, 1.0)
    model = replace(ak, **{**QUIET, "grazing_dropout": 1.0, "rim_invalid_px": 0})
    cam = window(model)
    z = 0.6
    shot = sphere_scene(cam, z)
    d = run(model, shot, cam).depth
    ball = shot.ids == 0
    kept = d > 0
    face = shot.facing
    mixed_free = ball & (face > 0.15)  # clear of the mixed pixels on the outline
    # a depth pixel spans 2.3 colour px, |cos| 0.2-0.3 where the rim turns fastest: nearly none kept below 0.2
    assert kept[mixed_free & (face < 0.2)].mean() < 0.03
    assert kept[ball & (face > 0.72)].all()
    between = kept[mixed_free & (face > 0.35) & (face < 0.6)].mean()
    assert 0.3 < between < 0.7
    # where the depth stops, along 48 directions, against the outline
    r_px = 0.035 * cam.fx / np.sqrt(z * z - 0.035**2)
    stop = r_px - outline_reach(kept & ball, np.maximum)
    lo, hi = r_px * (1 - np.sqrt(1 - 0.3**2)), r_px * (1 - np.sqrt(1 - 0.65**2))
    low, high = np.percentile(stop, [10, 90])  # within a depth pixel of the band (single directions: the grid)
    assert lo - model.footprint < low and high < hi + model.footprint
    assert lo + 1 < np.median(stop) < hi - 1
    # the old hard threshold (ramp 0) at 0.2 and 0.5 keeps most of the rim: the depth reaches within 3 px
    old = run(replace(model, grazing=0.2, grazing_dropout=0.5, grazing_ramp=0.0), shot, cam).depth
    assert r_px - np.median(outline_reach((old > 0) & ball, np.maximum)) < 3


def test_tof_flying_pixels_lie_between_fruit_and_background():
    model = replace(SENSOR_MODELS["azure-kinect"], **{**QUIET, "flying_share": 1.0, "rim_invalid_px": 0})
    cam = window(model)
    z, behind = 1.0, 0.15
    shot = sphere_scene(cam, z, behind=behind)
    d = out_depth = run(model, shot, cam).depth
    front, back = z - 0.035, z + behind
    valid = out_depth > 0
    assert np.all((d[valid] >= front - 1e-3) & (d[valid] <= back + 1e-3))
    between = valid & (d > z + 0.01) & (d < back - 0.01)
    assert between.sum() > 20  # a ring of flying pixels...
    ring = np.abs(np.hypot(*(np.mgrid[:SIDE, :SIDE] - SIDE / 2)) - 0.035 * cam.fx / z) < 2 * model.footprint + 1
    assert ring[between].all()  # ...only along the silhouette


def test_stereo_fattening_and_occlusion_band():
    model = replace(SENSOR_MODELS["realsense-d435"], **QUIET)
    cam = window(model)
    z, behind = 0.5, 0.2
    shot = sphere_scene(cam, z, behind=behind)
    d = run(model, shot, cam).depth
    row, fruit = d[SIDE // 2], shot.ids[SIDE // 2] == 0
    cols = np.arange(SIDE)
    left, right = int(np.flatnonzero(fruit).min()), int(np.flatnonzero(fruit).max())
    fringe = (row > 0) & (row < z + 0.05) & ~fruit
    # Right side: foreground depth spreads over the background by about fatten_px depth pixels.
    spread = int((fringe & (cols > right)).sum())
    assert (model.fatten_px - 1) * model.footprint <= spread <= (model.fatten_px + 1) * model.footprint + 1
    # Left side: background the right imager cannot see, f B (1/z_edge - 1/z_far) depth pixels wide, z_edge
    # between the ball's centre and its front.
    fb = model.depth_focal * model.baseline
    band = int(((row == 0) & (cols < left)).sum())
    low, high = fb * (1 / z - 1 / (z + behind)), fb * (1 / (z - 0.035) - 1 / (z + behind))
    assert (low - model.fatten_px - 1) * model.footprint <= band <= (high + 1) * model.footprint
    assert ((row == 0) & (cols > right)).sum() <= model.footprint + 1  # no band on the right (a self-hidden limb pixel)


def test_registration_shift_moves_depth_against_the_masks():
    model = replace(SENSOR_MODELS["azure-kinect"], **{**QUIET, "registration_px": 6.0})
    cam = window(model)
    shot = sphere_scene(cam, 1.0)
    out = run(model, shot, cam, seed=3, labels=(shot.ids == 0).astype(int))
    fg = (out.depth > 0) & (out.depth < 1.05)
    rows, cols = np.nonzero(fg)
    mrows, mcols = np.nonzero(out.labels == 1)
    du, dv = out.shift
    assert np.hypot(du, dv) == pytest.approx(6.0)
    assert cols.mean() - mcols.mean() == pytest.approx(du, abs=1.0)
    assert rows.mean() - mrows.mean() == pytest.approx(dv, abs=1.0)


@pytest.mark.parametrize("name", ["realsense-d435", "azure-kinect"])
def test_noise_and_bias_grow_with_distance_as_the_model_says(name):
    # Independent noise here (noise_corr_px 0): the bias's tolerance counts every depth pixel as one draw.
    model = replace(SENSOR_MODELS[name], lateral_px=0.0, dropout=0.0, registration_px=0.0, colour_baseline=0.0,
                    noise_corr_px=0.0)  # fmt: skip
    cam = window(model)
    plane = np.array([[-2.0, -2.0, 0.0], [2.0, -2.0, 0.0], [2.0, 2.0, 0.0], [-2.0, 2.0, 0.0]])
    measured = {}
    for z in (1.0, 2.0):
        shot = render([(plane + [0.0, 0.0, z], np.array([[0, 1, 2], [0, 2, 3]]))], cam)
        d = run(model, shot, cam, seed=int(z)).depth
        # One value per depth pixel (registration repeats it over its footprint).
        step = int(np.ceil(model.footprint))
        values = d[::step, ::step][d[::step, ::step] > 0].astype(float)
        measured[z] = values.std()
        assert values.std() == pytest.approx(np.hypot(model.sigma(z), 0.001 / np.sqrt(12)), rel=0.1)
        assert values.mean() - z == pytest.approx(float(model.bias(z)), abs=3 * values.std() / np.sqrt(values.size)
                                                  + 3e-4)  # fmt: skip
    if model.family == "stereo":
        assert model.sigma(2.0) / model.sigma(1.0) == pytest.approx(4.0)  # z^2
        assert model.sigma(1.0) == pytest.approx(1.0 * 0.08 / (model.depth_focal * 0.05))
    else:
        assert model.sigma(2.0) - model.sigma(1.0) == pytest.approx(model.sigma_linear)
    assert measured[2.0] > measured[1.0]


def test_multipath_pushes_depth_away_near_a_junction():
    model = replace(SENSOR_MODELS["azure-kinect"], **{**QUIET, "multipath_bias": 0.005, "rim_invalid_px": 0})
    cam = window(model)
    # A ball half sunk in a plane: depth near the junction is pushed away, far from it barely.
    shot = sphere_scene(cam, 1.0, behind=0.0)  # the plane through its centre: a junction along the silhouette
    d = run(model, shot, cam).depth.astype(float)
    clean = np.where(np.isfinite(shot.depth), shot.depth, 0)
    valid = (d > 0) & (clean > 0)
    dist = np.hypot(*(np.mgrid[:SIDE, :SIDE] - SIDE / 2))
    r_px = 0.035 * cam.fx / 1.0
    near = valid & (np.abs(dist - r_px) < 6) & (shot.ids == 1)
    centre = valid & (dist < 5)
    assert (d - clean)[near].mean() > 0.002
    assert abs((d - clean)[centre].mean()) < 0.0015


def test_no_depth_outside_the_depth_cameras_field_of_view():
    model = replace(SENSOR_MODELS["azure-kinect"], **QUIET)  # NFOV 75 deg inside a 90 deg colour image
    full = model.camera()
    cam = Camera(fx=full.fx, fy=full.fy, cx=full.cx, cy=40.0, width=full.width, height=80)  # a strip across
    plane = np.array([[-5.0, -5.0, 1.0], [5.0, -5.0, 1.0], [5.0, 5.0, 1.0], [-5.0, 5.0, 1.0]])
    shot = render([(plane, np.array([[0, 1, 2], [0, 2, 3]]))], cam)
    d = run(model, shot, cam).depth
    edge = full.fx * np.tan(np.radians(37.5))
    cols = np.flatnonzero(d[40] > 0)
    assert cols.min() == pytest.approx(full.cx - edge, abs=3) and cols.max() == pytest.approx(full.cx + edge, abs=3)


def test_masks_overshoot_and_cover_an_occluder():
    model = replace(SENSOR_MODELS["azure-kinect"], mask_overshoot_px=4.0, mask_amodal_share=1.0)
    yy, xx = np.mgrid[:100, :100]
    whole = np.hypot(yy - 50, xx - 50) <= 20
    leaf = xx < 45
    labels = (whole & ~leaf).astype(int)
    masks = annotate(model, labels, np.random.default_rng(0), amodal=whole.astype(int))
    assert (masks[labels == 1] == 1).all() and (masks[whole] == 1).all()  # covers the leaf
    grown = np.hypot(yy - 50, xx - 50)[masks == 1]
    assert grown.max() <= 20 + 4.0 + 1e-9
    plain = annotate(replace(model, mask_amodal_share=0.0, mask_overshoot_px=0.0), labels, np.random.default_rng(0),
                     amodal=whole.astype(int))  # fmt: skip
    assert (plain == labels).all()


def test_seeded_reproducibility():
    model = SENSOR_MODELS["realsense-l515"]
    cam = window(model)
    shot = sphere_scene(cam, 0.8)
    labels = (shot.ids == 0).astype(int)
    a, b = run(model, shot, cam, seed=7, labels=labels), run(model, shot, cam, seed=7, labels=labels)
    c = run(model, shot, cam, seed=8, labels=labels)
    assert np.array_equal(a.depth, b.depth) and np.array_equal(a.labels, b.labels) and a.shift == b.shift
    assert np.array_equal(a.jitter, b.jitter) and not np.array_equal(a.depth, c.depth)
    assert a.depth.dtype == np.float32 and a.depth.shape == (SIDE, SIDE)


def test_sensor_set_parses_checks_and_varies_a_model():
    from symfruit.errors import InputError
    from symfruit.synthetic.sensors import VARIABLE, parse_sensor_set, varied

    ak = SENSOR_MODELS["azure-kinect"]
    changes = parse_sensor_set("rim_invalid_px=3, flying_share=0.3,bias=2")
    assert changes == (("rim_invalid_px", 3.0), ("flying_share", 0.3), ("bias", 2.0))
    model = varied(ak, changes)
    assert model.rim_invalid_px == 3 and isinstance(model.rim_invalid_px, int) and model.flying_share == 0.3
    assert model.bias_const == pytest.approx(2 * ak.bias_const)
    assert model.bias_linear == pytest.approx(2 * ak.bias_linear)
    assert model.name == ak.name and replace(model, rim_invalid_px=1, flying_share=ak.flying_share,
                                             bias_const=ak.bias_const, bias_linear=ak.bias_linear) == ak  # fmt: skip
    assert varied(ak, {}) is ak and varied(ak, {"fatten_px": 4}).fatten_px == 4
    assert all(hasattr(ak, name) for name in VARIABLE if name != "bias")
    for text, message in (
        ("rim_invalid_px=2.5", "rim_invalid_px=2.5: must be a whole number 0 to 10"),
        ("flying_share=1.5", "flying_share=1.5: must be 0 to 1"),
        ("width=3", "width: not a setting of a camera model; known: rim_invalid_px"),
        ("lateral_px=big", "lateral_px=big: 'big' is not a number"),
        ("lateral_px", "'lateral_px': expected NAME=VALUE"),
        ("lateral_px=1,lateral_px=2", "names lateral_px twice"),
        ("bias=2,bias_const=0.001", "bias (a factor on both bias terms) or bias_const/bias_linear, not both"),
    ):
        with pytest.raises(InputError, match=re.escape(message)):
            varied(ak, parse_sensor_set(text))
    with pytest.raises(InputError, match="must be a number"):
        varied(ak, {"lateral_px": True})


def test_a_varied_model_changes_its_artefact_alone():
    """More rim invalidation widens the band without depth and changes nothing else of the frame."""
    from symfruit.synthetic.sensors import varied

    model = replace(SENSOR_MODELS["azure-kinect"], **QUIET)
    cam = window(model)
    shot = sphere_scene(cam, 1.0)
    one, three = run(model, shot, cam), run(varied(model, {"rim_invalid_px": 3}), shot, cam)
    assert (three.depth == 0).sum() > (one.depth == 0).sum()
    assert np.array_equal(three.depth[three.depth > 0], one.depth[three.depth > 0])


def test_lateral_jitter_is_in_the_registered_depth():
    """``lateral_px`` moves each colour pixel's depth sample: the ball's outline becomes ragged by about the
    jitter, its inside and the plane keep their depth, and the other draws are those of ``lateral_px = 0``."""
    base = replace(SENSOR_MODELS["azure-kinect"], **QUIET)
    cam = window(base)
    shot = sphere_scene(cam, 0.6)
    still = run(base, shot, cam, seed=3)
    moved = run(replace(base, lateral_px=1.5), shot, cam, seed=3)
    assert moved.jitter.any() and not still.jitter.any()
    changed = still.depth != moved.depth
    assert 0 < changed.sum() < 0.2 * changed.size
    # Where it changed, the value is the depth of a depth pixel within a few colour pixels (the jitter's 4 sigma).
    reach = int(np.ceil(4 * 1.5 + base.footprint))
    near = np.zeros_like(changed)
    padded = np.pad(still.depth, reach, mode="edge")
    for dv in range(-reach, reach + 1):
        for du in range(-reach, reach + 1):
            shifted = padded[reach + dv : reach + dv + SIDE, reach + du : reach + du + SIDE]
            near[changed] |= shifted[changed] == moved.depth[changed]
    assert near[changed].all()
    # A pixel's jitter decides its sample: pixels whose jitter stays within their own depth pixel keep their depth.
    ratio = base.footprint
    u = np.arange(SIDE)[None, :] + moved.jitter[..., 0]
    v = np.arange(SIDE)[:, None] + moved.jitter[..., 1]
    same_cell = (np.floor(u / ratio) == np.floor(np.arange(SIDE)[None, :] / ratio)) & (
        np.floor(v / ratio) == np.floor(np.arange(SIDE)[:, None] / ratio)
    )
    assert not changed[same_cell].any()


def _acf_length(field: np.ndarray, lags=range(1, 25)) -> float:
    """The lag (pixels, linear between lags) where the autocorrelation along rows and columns falls below 1/e."""
    prev = 1.0
    f = field - field.mean()
    for lag in lags:
        r = float(((f[:, :-lag] * f[:, lag:]).mean() + (f[:-lag] * f[lag:]).mean()) / 2 / f.var())
        if r < 1 / np.e:
            return lag - 1 + (prev - 1 / np.e) / (prev - r)
        prev = r
    return float(lags[-1])


@pytest.mark.parametrize("length", [1.5, 3.5, 6.0])
def test_correlated_noise_has_its_length_and_unit_spread(length):
    """White draws filtered by correlated_noise: unit standard deviation, the autocorrelation exp(-(lag/L)^2) (1/e at
    L, 0.78 at L/2), the same field for the same draws; length 0 hands the draws back untouched."""
    white = np.random.default_rng(5).normal(size=(400, 400))
    field = correlated_noise(white, length)
    assert field.std() == pytest.approx(1.0, abs=0.06)
    assert _acf_length(field) == pytest.approx(length, rel=0.08)
    half = max(1, round(length / 2))
    r = float((field[:, :-half] * field[:, half:]).mean() / field.var())
    assert r == pytest.approx(np.exp(-((half / length) ** 2)), abs=0.05)
    assert np.array_equal(field, correlated_noise(white.copy(), length))
    assert correlated_noise(white, 0.0) is white


def test_correlated_depth_noise_on_a_flat_plane_matches_the_model():
    """The Azure Kinect model with only its noise on: on a fronto-parallel plane at 1 m the depth pixels spread by
    sigma(1 m) and the noise falls to 1/e at noise_corr_px depth pixels; the same seed gives the same frame, and
    noise_corr_px = 0 gives independent pixels of the same spread (the draws themselves unchanged)."""
    base = replace(SENSOR_MODELS["azure-kinect"], **{**QUIET, "sigma_const": 0.002, "sigma_linear": 0.0})
    assert SENSOR_MODELS["azure-kinect"].noise_corr_px == 3.5
    cam = Camera(fx=base.camera().fx, fy=base.camera().fx, cx=300.0, cy=300.0, width=600, height=600)
    plane = np.array([[-2.0, -2.0, 1.0], [2.0, -2.0, 1.0], [2.0, 2.0, 1.0], [-2.0, 2.0, 1.0]])
    shot = render([(plane, np.array([[0, 1, 2], [0, 2, 3]]))], cam)
    ratio = base.footprint
    centres = ((np.arange(int(600 / ratio)) + 0.5) * ratio).astype(int)  # one colour pixel per depth pixel
    for length in (3.5, 0.0):
        model = replace(base, noise_corr_px=length)
        out = run(model, shot, cam, seed=11)
        grid = out.depth[np.ix_(centres, centres)].astype(float) - 1.0
        assert (out.depth[np.ix_(centres, centres)] > 0).all()
        assert grid.std() == pytest.approx(np.hypot(0.002, 0.001 / np.sqrt(12)), rel=0.12)
        measured = _acf_length(grid)
        if length:
            assert measured == pytest.approx(length, rel=0.15)
            assert np.array_equal(out.depth, run(model, shot, cam, seed=11).depth)
            assert not np.array_equal(out.depth, run(model, shot, cam, seed=12).depth)
        else:
            assert measured < 0.7  # independent: below 1/e already at one depth pixel


def test_noise_corr_px_is_set_by_sensor_set():
    from symfruit.errors import InputError
    from symfruit.synthetic.sensors import parse_sensor_set, varied

    d435 = SENSOR_MODELS["realsense-d435"]
    assert d435.noise_corr_px == 4.0 and SENSOR_MODELS["realsense-l515"].noise_corr_px == 0.0
    assert varied(d435, parse_sensor_set("noise_corr_px=0")).noise_corr_px == 0.0
    assert varied(d435, parse_sensor_set("noise_corr_px=7.5")).noise_corr_px == 7.5
    with pytest.raises(InputError, match="noise_corr_px=25: must be 0 to 20"):
        parse_sensor_set("noise_corr_px=25")


def test_an_unknown_sensor_set_name_names_the_near_ones_in_one_short_line():
    """Stop 47 (robust47): every one of the 23 names was listed, `symfruit evaluate ... --sensor-set rim_invalid=3`
    a line of 394 characters."""
    from symfruit.errors import InputError
    from symfruit.synthetic.sensors import parse_sensor_set, sensor_model, varied

    with pytest.raises(InputError) as info:
        varied(sensor_model("azure-kinect"), parse_sensor_set("rim_invalid=3"))
    assert str(info.value) == (
        "--sensor-set rim_invalid: not a setting of a camera model (did you mean 'rim_invalid_px'?); known: "
        "rim_invalid_px, rim_far_px and 21 more (symfruit.synthetic.sensors.VARIABLE)"
    )
