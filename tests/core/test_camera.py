import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from symfruit import Camera, InputError


def test_principal_point_projects_to_centre(camera):
    assert np.allclose(camera.project([[0.0, 0.0, 0.4]]), [[camera.cx, camera.cy]])


def test_rep103_axes(camera):
    # x right -> larger u, y down -> larger v.
    u, v = camera.project([[0.01, 0.02, 0.5]])[0]
    assert u == pytest.approx(320.0 + 615.0 * 0.02) and v == pytest.approx(240.0 + 615.0 * 0.04)


@given(
    st.floats(-0.5, 0.5),
    st.floats(-0.5, 0.5),
    st.floats(0.05, 5.0),
    st.floats(100, 2000),
    st.floats(100, 2000),
)
def test_deproject_inverts_project(x, y, z, fx, fy):
    cam = Camera(fx=fx, fy=fy, cx=300.5, cy=200.25, width=640, height=480)
    p = np.array([[x, y, z]])
    back = cam.deproject(cam.project(p), p[:, 2])
    assert np.allclose(back, p, atol=1e-9)


def test_matrix_and_dict(camera):
    assert camera.matrix[0, 0] == 615.0 and camera.matrix[1, 2] == 240.0
    assert Camera(**camera.to_dict()) == camera


@pytest.mark.parametrize(
    "bad, message",
    [
        ({"fx": 0.0}, "positive"),
        ({"fy": -1.0}, "positive"),
        ({"width": 0}, "width"),
        ({"height": 2.5}, "height"),
        ({"cx": float("nan")}, "finite"),
        ({"fx": "a"}, "number"),
        ({"fx": "600"}, r"camera fx must be a number, got '600'"),  # float() read text and True in silence
        ({"cy": True}, r"camera cy must be a number, got True"),
        ({"fy": 1e-300}, r"at least 1 pixel, got fx=600, fy=1e-300 \(focal lengths are in pixels"),
        ({"fx": 0.00193}, r"at least 1 pixel"),  # a 1.93 mm lens in metres
        (
            {"cy": 10**400},
            r"camera cy must be a number, got 10{11}\.\.\. \(401 digits\)$",
        ),  # beyond float: not OverflowError
    ],
)
def test_invalid_intrinsics_are_refused(bad, message):
    args = {"fx": 600.0, "fy": 600.0, "cx": 320.0, "cy": 240.0, "width": 640, "height": 480, **bad}
    with pytest.raises(InputError, match=message):
        Camera(**args)


def test_project_and_deproject_keep_leading_shapes(camera):
    grid = np.zeros((4, 5, 3)) + [0.0, 0.0, 0.5]
    assert camera.project(grid).shape == (4, 5, 2)
    assert camera.deproject([[320, 240], [330, 250]], [1, 2]).tolist() == [
        [0.0, 0.0, 1.0],
        [pytest.approx(20 / 615), pytest.approx(20 / 615), 2.0],
    ]


def test_whole_float_sizes_are_taken_and_the_camera_is_frozen():
    cam = Camera(fx=600, fy=600, cx=320, cy=240, width=640.0, height=480.0)
    assert (cam.width, cam.height) == (640, 480) and isinstance(cam.width, int) and isinstance(cam.fx, float)
    with pytest.raises(InputError, match="width"):
        Camera(fx=600, fy=600, cx=320, cy=240, width=True, height=480)
    import dataclasses

    with pytest.raises(dataclasses.FrozenInstanceError):
        cam.fx = 1.0  # type: ignore[misc]


@pytest.mark.parametrize(
    "bad, message",
    [
        ({"width": 100000, "height": 100000}, "width is 100000 pixels; at most 16384"),
        ({"width": 16000, "height": 16000}, "exceeds 40,000,000 pixels"),
        ({"fx": 1e300}, "focal lengths must be at most"),
        ({"cy": -1e300}, "cy = -1e[+]300 is implausible"),
    ],
)
def test_absurd_intrinsics_are_refused_without_numpy_warnings(bad, message):
    import warnings

    args = {"fx": 615.0, "fy": 615.0, "cx": 320.0, "cy": 240.0, "width": 640, "height": 480, **bad}
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a RuntimeWarning from numpy would fail here
        with pytest.raises(InputError, match=message):
            Camera(**args)


@given(st.integers(0, 2**32 - 1), st.sampled_from([(), (5,), (7, 3), (0,)]))
def test_project_and_rays_are_the_stacked_formulas_bit_for_bit(seed, shape):
    rng = np.random.default_rng(seed)
    cam = Camera(fx=612.3, fy=611.9, cx=321.7, cy=239.2, width=640, height=480)
    p = rng.normal(size=(*shape, 3))
    p[..., 2] = rng.uniform(0.1, 2.0, shape)
    want = np.stack([cam.fx * p[..., 0] * (1.0 / p[..., 2]) + cam.cx, cam.fy * p[..., 1] * (1.0 / p[..., 2]) + cam.cy],
                    axis=-1)  # fmt: skip
    np.testing.assert_array_equal(cam.project(p), want)
    v = np.full(shape, 200.0)
    floats = rng.normal(0.0, 300.0, shape)
    for u in (floats, rng.integers(0, 640, shape), floats.astype(np.float32)):
        x, y = (np.asarray(u) - cam.cx) / cam.fx, (v - cam.cy) / cam.fy
        want = np.stack([x, y, np.ones_like(x, dtype=np.float64)], axis=-1)
        got = cam.rays(u, v)
        assert got.dtype == want.dtype
        np.testing.assert_array_equal(got, want)


@given(st.floats(-20, 20), st.floats(-20, 20), st.floats(-0.3, 0.3), st.floats(-0.2, 0.2), st.floats(0.2, 3.0))
def test_a_shifted_camera_sees_every_point_shifted_and_deprojects_it_back(du, dv, x, y, z):
    cam = Camera(fx=600.0, fy=590.0, cx=320.0, cy=240.0, width=640, height=480)
    moved = cam.shifted(du, dv)
    p = np.array([[x, y, z]])
    np.testing.assert_allclose(moved.project(p), cam.project(p) + [du, dv], atol=1e-9)
    np.testing.assert_allclose(moved.deproject(moved.project(p), [z]), p, atol=1e-12)
    assert (moved.fx, moved.fy, moved.width, moved.height) == (cam.fx, cam.fy, cam.width, cam.height)
    assert cam.shifted(0, 0) is cam


@pytest.mark.parametrize(
    ("du", "dv", "what"),
    [("a", 0, "du must be a number"), (0, "6", "dv must be a number"), (True, 0, "du must be a number"),
     (None, 0, "du must be a number"), (0, float("nan"), "dv must be finite"), (float("inf"), 0, "du must be finite")],
)  # fmt: skip
def test_a_shift_that_is_no_finite_number_is_refused_by_name(du, dv, what):
    cam = Camera(fx=600.0, fy=590.0, cx=320.0, cy=240.0, width=640, height=480)
    with pytest.raises(InputError, match=f"camera shift {what}"):
        cam.shifted(du, dv)
    assert cam.shifted(np.int64(6), np.float32(-2.0)).cx == 326.0 and cam.shifted(np.int64(0), 0.0) is cam


def test_project_and_deproject_refuse_coordinates_of_another_shape_by_name(camera):
    with pytest.raises(InputError, match=r"project needs points of shape \(\.\.\., 3\) in metres, got \(2, 2\)"):
        camera.project([[0.0, 0.4], [0.01, 0.4]])  # before: IndexError from numpy
    with pytest.raises(InputError, match=r"deproject needs pixel coordinates of shape \(\.\.\., 2\), got \(1, 3\)"):
        camera.deproject([[320.0, 240.0, 0.4]], [0.4])  # before: the third column dropped in silence
    with pytest.raises(InputError, match=r"deproject needs one depth per pixel: \(3,\) pixels, depth \(2,\)"):
        camera.deproject(np.zeros((3, 2)), [0.4, 0.5])  # before: numpy's broadcast ValueError
    with pytest.raises(InputError, match=r"one depth per pixel: \(3,\) pixels, depth \(\)"):
        camera.deproject(np.zeros((3, 2)), 0.4)  # before: numpy's 'all input arrays must have the same shape'


# --- stop 43, robust43


def test_rays_refuse_text_and_coordinates_of_two_shapes():
    """Before: numpy's UFuncTypeError for text, np.stack's ValueError for u and v of two shapes."""
    cam = Camera(fx=500.0, fy=500.0, cx=320.0, cy=240.0, width=640, height=480)
    with pytest.raises(InputError, match="rays needs pixel coordinates as numbers, got <U1"):
        cam.rays("a", "b")
    with pytest.raises(InputError, match=r"rays needs u and v of one shape, got \(3,\) and \(2,\)"):
        cam.rays(np.zeros(3), np.zeros(2))
    np.testing.assert_array_equal(cam.rays(np.array([820]), np.array([240.0])), [[1.0, 0.0, 1.0]])
