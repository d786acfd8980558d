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
    ],
)
def test_invalid_intrinsics_are_refused(bad, message):
    args = {"fx": 600.0, "fy": 600.0, "cx": 320.0, "cy": 240.0, "width": 640, "height": 480, **bad}
    with pytest.raises(InputError, match=message):
        Camera(**args)
