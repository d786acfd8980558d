"""The z-buffer renderer and the RGB-D sensor model: analytic depths and silhouettes at known poses."""

import numpy as np
import pytest

from symfruit import Camera
from symfruit.synthetic.render import Rendering, SensorNoise, render

from ..conftest import fibonacci_sphere

CAM = Camera(fx=600, fy=600, cx=320, cy=240, width=640, height=480)
#: A triangle 0.5 m in front of the camera, facing it: 240 px wide at the base, 240 px high.
TRIANGLE = (np.array([[-0.1, 0.1, 0.5], [0.1, 0.1, 0.5], [0.0, -0.1, 0.5]]), np.array([[0, 1, 2]]))


def test_render_sphere_depth_is_exact():
    from scipy.spatial import ConvexHull

    cam = Camera(fx=600, fy=600, cx=320, cy=240, width=640, height=480)
    hull = ConvexHull(fibonacci_sphere(4000))
    centre = np.array([0.0, 0.0, 0.4])
    shot = render([(hull.points * 0.03 + centre, hull.simplices)], cam)
    assert shot.depth[240, 320] == pytest.approx(0.37, abs=2e-4)
    radius_px = 600 * 0.03 / np.sqrt(0.4**2 - 0.03**2)
    assert (shot.ids == 0).sum() == pytest.approx(np.pi * radius_px**2, rel=0.03)
    assert shot.facing[240, 320] == pytest.approx(1.0, abs=1e-3)
    assert np.all(np.isinf(shot.depth[shot.ids < 0]))


def test_sensor_noise_grows_with_distance():
    noise = SensorNoise()
    assert noise.sigma(0.3) == pytest.approx(0.001) and noise.sigma(0.6) == pytest.approx(0.004)


def test_a_fronto_parallel_triangle_known_depth_silhouette_and_facing():
    shot = render([TRIANGLE], CAM)
    assert isinstance(shot, Rendering) and shot.depth.shape == (480, 640) and shot.ids.shape == (480, 640)
    assert shot.depth[240, 320] == pytest.approx(0.5, abs=1e-12) and shot.ids[240, 320] == 0
    hit = shot.ids == 0
    assert np.allclose(shot.depth[hit], 0.5, atol=1e-12) and np.all(np.isinf(shot.depth[~hit]))
    assert hit.sum() == pytest.approx(0.5 * 240 * 240, rel=0.01)
    rows, cols = np.nonzero(hit)
    assert (rows.min(), rows.max(), cols.min(), cols.max()) == (120, 360, 200, 440)  # the projected corners
    u = np.arange(640) - 320.0
    expected = 1.0 / np.sqrt(1.0 + (u / 600.0) ** 2)  # |cos| of the ray along row 240 against the normal
    row = hit[240]
    assert np.allclose(shot.facing[240, row], expected[row], atol=1e-12) and shot.facing[240, 320] == 1.0


def test_a_tilted_plane_gives_the_ray_plane_intersection():
    # The plane z = 0.5 + 0.5 x, as two triangles; the ray through (u, v) meets it at z = 0.5 / (1 - 0.5 a),
    # a = (u - cx) / fx.
    corners = np.array([[-0.2, -0.2], [0.2, -0.2], [0.2, 0.2], [-0.2, 0.2]])
    vertices = np.c_[corners, 0.5 + 0.5 * corners[:, 0]]
    shot = render([(vertices, np.array([[0, 1, 2], [0, 2, 3]]))], CAM)
    for u, v in [(320, 240), (380, 240), (260, 300), (400, 200), (330, 241)]:
        a = (u - 320) / 600
        assert shot.depth[v, u] == pytest.approx(0.5 / (1 - 0.5 * a), rel=1e-12)
    assert shot.facing[240, 320] == pytest.approx(1 / np.sqrt(1.25))  # normal (0.5, 0, -1) / |.|


def test_the_nearest_surface_wins_and_meshes_keep_their_index():
    behind = (TRIANGLE[0] * [2.0, 2.0, 1.0] + [0.0, 0.0, 0.3], TRIANGLE[1])  # bigger, 0.8 m away
    shot = render([behind, TRIANGLE], CAM)
    assert shot.ids[240, 320] == 1 and shot.depth[240, 320] == pytest.approx(0.5)
    assert shot.ids[380, 320] == 0 and shot.depth[380, 320] == pytest.approx(0.8)  # only the far one there
    assert set(np.unique(shot.ids).tolist()) == {-1, 0, 1}


def test_what_cannot_be_seen_renders_nothing():
    empty = render([], CAM)
    assert np.all(np.isinf(empty.depth)) and np.all(empty.ids == -1) and np.all(empty.facing == 0)
    behind = render([(TRIANGLE[0] * [1, 1, -1], TRIANGLE[1])], CAM)  # behind the camera: skipped
    assert np.all(behind.ids == -1)
    aside = render([(TRIANGLE[0] + [5.0, 0.0, 0.0], TRIANGLE[1])], CAM)  # outside the image
    assert np.all(aside.ids == -1)
    flat = render([(np.array([[0, 0, 0.5], [0.1, 0, 0.5], [0.2, 0, 0.5]]), np.array([[0, 1, 2]]))], CAM)
    assert np.all(flat.ids == -1)  # a degenerate triangle has no area
    assert np.all(render([(TRIANGLE[0], np.zeros((0, 3), int))], CAM).ids == -1)


def test_batches_do_not_change_the_image():
    from scipy.spatial import ConvexHull

    hull = ConvexHull(fibonacci_sphere(1000))
    mesh = [(hull.points * 0.03 + [0.0, 0.0, 0.4], hull.simplices)]
    a, b = render(mesh, CAM), render(mesh, CAM, max_candidates=50)
    assert np.array_equal(a.depth, b.depth) and np.array_equal(a.ids, b.ids) and np.array_equal(a.facing, b.facing)


def test_sensor_noise_is_seeded_and_a_perfect_sensor_returns_the_ideal_depth():
    shot = render([TRIANGLE], CAM)
    noise = SensorNoise()
    a, jitter_a = noise.apply(shot, np.random.default_rng(3))
    b, jitter_b = noise.apply(shot, np.random.default_rng(3))
    assert np.array_equal(a, b) and np.array_equal(jitter_a, jitter_b) and jitter_a.shape == (480, 640, 2)
    assert np.all(a[shot.ids < 0] == 0)  # no return where nothing was hit
    seen = (shot.ids == 0) & (a > 0)
    assert 0.0005 < np.std(a[seen] - 0.5) < 0.003  # sigma(0.5) = 2.8 mm
    perfect = SensorNoise(axial_at_03=0.0, lateral_px=0.0, edge_dropout=0.0, grazing_dropout=0.0, dropout=0.0)
    depth, jitter = perfect.apply(shot, np.random.default_rng(0))
    assert np.array_equal(depth, np.where(shot.ids == 0, shot.depth, 0.0)) and not jitter.any()
    edges = SensorNoise(axial_at_03=0.0, lateral_px=0.0, edge_dropout=1.0, grazing_dropout=0.0, dropout=0.0)
    depth, _ = edges.apply(shot, np.random.default_rng(0))
    assert depth[240, 320] == 0.5 and depth[360, 320] == 0.0  # the silhouette's bottom edge drops out


# --- stop 45, apples45: a colour camera's photometry (Photometric)
_OFF = dict(exposure_ev=0.0, cast_deg=0.0, shadow_share=0.0, specular=0.0, full_well=0.0, blur_px=0.0, jpeg_quality=0)


def _flat(value=(0.6, 0.32, 0.2), shape=(64, 96)):
    return np.broadcast_to(np.asarray(value, float), (*shape, 3)).copy()


def test_photometric_with_every_effect_off_keeps_the_colours():
    from symfruit.synthetic.render import Photometric

    out = Photometric(**_OFF).apply(_flat(), np.zeros((64, 96)), 1000.0, np.random.default_rng(0))
    assert out.dtype == np.uint8 and out.shape == (64, 96, 3)
    assert np.array_equal(out[0, 0], [153, 82, 51]) and (out == out[0, 0]).all()  # 0.6, 0.32, 0.2 of 255, rounded


def test_photometric_exposure_scales_linear_light_by_at_most_its_stops():
    from symfruit.synthetic.render import Photometric

    p = Photometric(**{**_OFF, "exposure_ev": 0.5})
    for seed in range(5):
        out = p.apply(_flat((0.5, 0.5, 0.5)), np.zeros((64, 96)), 1000.0, np.random.default_rng(seed))
        linear = (out[0, 0, 0] / 255) ** 2.2 / 0.5**2.2
        assert 2**-0.5 - 0.02 <= linear <= 2**0.5 + 0.02
        assert (out == out[0, 0]).all() and out[0, 0, 0] == out[0, 0, 1] == out[0, 0, 2]  # grey stays grey


def test_photometric_white_balance_error_is_an_angle_up_to_cast_deg():
    from symfruit.synthetic.render import _cast

    rng = np.random.default_rng(1)
    angles = []
    for _ in range(200):
        g = _cast(8.0, rng)
        assert g.mean() == pytest.approx(1.0)
        angles.append(np.degrees(np.arccos(g.sum() / np.sqrt(3.0) / np.linalg.norm(g))))
    assert max(angles) <= 8.0 + 1e-9 and 3.0 <= np.median(angles) <= 5.0  # uniform in 0-8 degrees: median 4
    assert np.array_equal(_cast(0.0, rng), np.ones(3))


def test_photometric_leaf_shadows_cover_their_share_in_patches_of_their_size():
    from scipy import ndimage

    from symfruit.synthetic.render import Photometric, _shadow_mask

    mask = _shadow_mask(540, 960, 40.0, 0.33, np.random.default_rng(2))
    assert mask.mean() == pytest.approx(0.33, abs=0.03)
    labels, _ = ndimage.label(mask)
    sizes = np.bincount(labels.ravel())[1:]
    assert 20 <= np.sqrt(np.median(sizes[sizes > 50])) <= 200  # patches of tens of pixels, not specks nor halves
    p = Photometric(**{**_OFF, "shadow_share": 0.33})
    out = p.apply(_flat((0.5, 0.5, 0.5), (540, 960)), np.zeros((540, 960)), 40.0 / 0.07, np.random.default_rng(2))
    shade = out[:, :, 0] < 100
    assert shade.mean() == pytest.approx(0.33, abs=0.03)
    assert (out[shade][:, 2] > out[shade][:, 0]).all()  # skylight is bluer than sunlight
    assert out[~shade][:, 0].min() > 128  # auto exposure: the sunlit parts brighter than 0.5 (128)


def test_photometric_specular_highlight_is_near_white_on_red_skin():
    from symfruit.synthetic.render import Photometric

    spec = np.zeros((64, 96))
    spec[30:34, 40:44] = 1.0
    out = Photometric(**{**_OFF, "specular": 0.6}).apply(_flat(), spec, 1000.0, np.random.default_rng(0))
    assert (out[31, 41] >= 200).all() and out[31, 41].min() >= 0.7 * out[31, 41].max()
    assert np.abs(out[0, 0].astype(int) - [153, 82, 51]).max() <= 1  # auto exposure: the spot is small


def test_photometric_noise_grows_with_the_signal_and_jpeg_keeps_a_flat_colour():
    from symfruit.synthetic.render import Photometric

    p = Photometric(**{**_OFF, "full_well": 16000.0, "read_noise": 5.0})
    dark = p.apply(_flat((0.1, 0.1, 0.1)), np.zeros((64, 96)), 1000.0, np.random.default_rng(3)).astype(float)
    bright = p.apply(_flat((0.8, 0.8, 0.8)), np.zeros((64, 96)), 1000.0, np.random.default_rng(3)).astype(float)
    assert 0.1 < dark.std() and 0.1 < bright.std()  # visible, a level or more
    e_dark, e_bright = 0.1**2.2 * 16000, 0.8**2.2 * 16000
    assert bright.std() / dark.std() == pytest.approx(
        (np.sqrt(e_bright) * 0.8 / e_bright) / (np.sqrt(e_dark) * 0.1 / e_dark), rel=0.25
    )  # shot noise, gamma-coded
    out = Photometric(**{**_OFF, "jpeg_quality": 90}).apply(_flat(), np.zeros((64, 96)), 1000.0,
                                                             np.random.default_rng(0))  # fmt: skip
    assert np.abs(out.astype(int) - [153, 82, 51]).max() <= 3
