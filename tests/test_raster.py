import numpy as np
import pytest

from symfruit import Camera, InputError
from symfruit.core.raster import rasterise

from .conftest import CENTRE, front_half, sphere_cloud


def test_sparse_sphere_gives_a_solid_disc(camera):
    rng = np.random.default_rng(0)
    d = rng.normal(size=(1200, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    visible = front_half(0.02 * d + CENTRE)  # ~600 random points
    view = rasterise(visible, camera)
    radius_px = camera.fx * 0.02 / CENTRE[2]  # silhouette radius (front half, ignoring perspective)
    area = view.mask.sum()
    assert area == pytest.approx(np.pi * radius_px**2, rel=0.12)
    # Solid: no hole, one component.
    from scipy import ndimage

    assert ndimage.label(view.mask)[1] == 1
    assert np.array_equal(ndimage.binary_fill_holes(view.mask), view.mask)


def test_depth_is_the_nearest_surface(camera):
    visible = front_half(sphere_cloud(n=4000))
    view = rasterise(visible, camera)
    h, w = view.mask.shape
    rows, cols = np.nonzero(view.mask)
    u, v = cols + view.u0, rows + view.v0
    seen = view.near_depth.reshape(h, w)[rows, cols]
    # Exact depth of the sphere's front along each pixel's ray, where the ray hits the sphere.
    rays = camera.deproject(np.c_[u, v], np.ones(len(u)))
    rays /= np.linalg.norm(rays, axis=1, keepdims=True)
    b = rays @ CENTRE
    disc = b**2 - (CENTRE @ CENTRE - 0.02**2)
    hit = disc > (0.002 / 0.02) ** 2 * 0.02**2  # away from the rim
    t = b[hit] - np.sqrt(disc[hit])
    truth = t * rays[hit, 2]
    assert np.median(np.abs(seen[hit] - truth)) < 0.5e-3


def test_distances_outside_the_mask(camera, sphere_view):
    view = rasterise(sphere_view, camera)
    dist = view.dist.reshape(view.mask.shape)
    assert np.all(dist[view.mask] == 0)
    assert np.all(dist[~view.mask] >= 1)
    nu = view.near_u.reshape(view.mask.shape)
    nv = view.near_v.reshape(view.mask.shape)
    assert view.mask[(nv - view.v0).astype(int), (nu - view.u0).astype(int)].all()


def test_fruit_cut_by_the_image_edge_is_not_eroded():
    cam = Camera(fx=615, fy=615, cx=320, cy=240, width=640, height=480)
    cloud = front_half(sphere_cloud(centre=np.array([0.0, 0.0, 0.35]), n=3000), np.array([0.0, 0.0, 0.35]))
    small = Camera(fx=615, fy=615, cx=10, cy=240, width=640, height=480)  # sphere centred on column 10
    view = rasterise(cloud, small)
    assert view.u0 == 0 and view.mask[:, 0].sum() > 0.8 * view.mask[:, 12].sum()
    assert rasterise(cloud, cam).mask.sum() > view.mask.sum()


def test_nothing_in_the_image_is_an_error(camera):
    with pytest.raises(InputError, match="no point projects"):
        rasterise(np.array([[5.0, 5.0, 0.3], [5.1, 5.0, 0.3]]), camera)
