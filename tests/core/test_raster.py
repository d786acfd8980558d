import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy import ndimage

from symfruit import Box, Camera, InputError
from symfruit.core.raster import (
    _near_distance,
    fill_holes,
    inner_distance,
    mask_box,
    nearest_index,
    outer_distance,
    rasterise,
    silhouette_coverage,
)

from ..conftest import CENTRE, front_half, sphere_cloud


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


def test_lists_are_accepted_and_wrong_shapes_refused(camera, sphere_view):
    a, b = rasterise(sphere_view, camera), rasterise(sphere_view.tolist(), camera)
    assert np.array_equal(a.mask, b.mask) and np.array_equal(a.near_depth, b.near_depth)
    with pytest.raises(InputError, match="shape"):
        rasterise(sphere_view[:, :2], camera)
    with pytest.raises(InputError, match="at least 1 points"):
        rasterise(np.zeros((0, 3)), camera)


def test_a_given_fill_radius_is_used(camera, sphere_view):
    assert rasterise(sphere_view, camera, fill_radius=4.0).fill_radius == 4.0
    assert rasterise(sphere_view, camera).fill_radius >= 1.0


def test_silhouette_coverage_known_answers(camera):
    visible = front_half(sphere_cloud(n=4000))
    box = Box(CENTRE - 0.02, CENTRE + 0.02)
    full = rasterise(visible, camera)
    assert silhouette_coverage(full, box, camera) > 0.99  # the whole disc was seen
    half = rasterise(visible[visible[:, 0] < CENTRE[0]], camera)
    assert silhouette_coverage(half, box, camera) == pytest.approx(0.5, abs=0.03)
    # A box twice as wide: the seen disc is a quarter of its ellipse.
    assert silhouette_coverage(full, Box(CENTRE - 0.04, CENTRE + 0.04), camera) == pytest.approx(0.25, abs=0.02)
    assert silhouette_coverage(full, Box(CENTRE - [0.02, 0.02, 1.02], CENTRE - [-0.02, -0.02, 0.98]), camera) == 0.0
    aside = Box(CENTRE + [0.18, -0.02, -0.02], CENTRE + [0.22, 0.02, 0.02])  # beside the seen window
    assert silhouette_coverage(full, aside, camera) == 0.0


# --- the seen region alone ------------------------------------------------------------------------------


def test_silhouette_of_a_dense_view_is_its_pixels(camera):
    from symfruit.core.raster import silhouette

    from ..conftest import ball_mesh, rendered_view

    visible, _ = rendered_view(ball_mesh(), [0.0, 0.0, 0.4])
    region = silhouette(visible, camera, pad=8)
    assert region.fill_radius == 0.0 and region.mask.sum() == len(visible)
    rows, cols = np.nonzero(region.mask)
    assert rows.min() == 8 + 2 and cols.min() == 8 + 2  # the margin: pad + 2 pixels (no gap closing)


def test_silhouette_of_a_sparse_cloud_matches_the_rasterised_mask(camera):
    from symfruit.core.raster import silhouette

    rng = np.random.default_rng(1)
    d = rng.normal(size=(1200, 3))
    visible = front_half(0.02 * d / np.linalg.norm(d, axis=1, keepdims=True) + CENTRE)
    region, view = silhouette(visible, camera, pad=0), rasterise(visible, camera)
    assert region.fill_radius == pytest.approx(view.fill_radius)
    assert (region.u0, region.v0) == (view.u0, view.v0) and np.array_equal(region.mask, view.mask)


def test_silhouette_window_stops_at_the_image_edge():
    from symfruit.core.raster import silhouette

    cam = Camera(fx=600, fy=600, cx=80, cy=60, width=160, height=120)
    pts = np.array([[x, y, 0.3] for x in np.linspace(-0.04, -0.03, 25) for y in np.linspace(-0.005, 0.005, 25)])
    region = silhouette(pts, cam, pad=8)
    assert region.u0 == 0 and region.mask[:, 0].any()
    with pytest.raises(InputError, match="no point projects"):
        silhouette(pts + [1.0, 0.0, 0.0], cam)


def test_silhouette_cone_of_a_ball_is_its_tangent_cone(camera):
    from symfruit.core.raster import silhouette, silhouette_cone

    from ..conftest import ball_mesh, rendered_view

    c, r = np.array([0.04, 0.02, 0.4]), 0.035
    visible, _ = rendered_view(ball_mesh(r), c)
    cone, axis = silhouette_cone(silhouette(visible, camera), camera)
    exact = np.linalg.inv(np.outer(c, c) - r * r * np.eye(3))  # the ball's viewing cone (up to scale)
    exact = exact / np.abs(np.linalg.eigvalsh(exact)).max() * np.sign(exact[2, 2] * cone[2, 2])
    np.testing.assert_allclose(cone, exact, atol=0.01)
    ray = c / c[2]
    assert ray @ cone @ ray < 0  # the centre's ray is inside
    np.testing.assert_allclose(axis, ray, atol=0.003)


def test_a_ragged_outline_is_closed_and_a_clean_one_kept(camera):
    from symfruit.core.raster import close_ragged, silhouette

    from ..conftest import ball_mesh, rendered_view

    visible, _ = rendered_view(ball_mesh(), [0.0, 0.0, 0.4])
    clean = silhouette(visible, camera)
    assert close_ragged(clean) is clean  # a clean render's outline is left as it is
    uv = np.rint(camera.project(visible)).astype(int)
    centre = uv.mean(axis=0)
    r = np.linalg.norm(uv - centre, axis=1)
    drop = (r > r.max() - 3) & (np.random.default_rng(0).random(len(r)) < 0.6)  # dropout at the rim
    ragged = silhouette(visible[~drop], camera)
    closed = close_ragged(ragged)
    assert closed is not ragged and closed.mask.sum() > ragged.mask.sum()
    lost = int(clean.mask.sum()) - int(ragged.mask.sum())
    assert 0 <= int(clean.mask.sum()) - int(closed.mask.sum()) < 0.5 * lost  # most of the rim is back


def test_outline_cracks_are_the_pixel_squares_edges():
    from symfruit.core.raster import Silhouette, outline_cracks

    mask = np.zeros((5, 6), bool)
    mask[1:3, 2:5] = True  # a 3 x 2 block of pixels, columns 2-4 and rows 1-2
    cracks = outline_cracks(Silhouette(10, 20, mask, 0.0))
    assert len(cracks) == 2 * 3 + 2 * 2  # its perimeter in pixel edges
    assert cracks[:, 0].min() == 10 + 1.5 and cracks[:, 0].max() == 10 + 4.5
    assert cracks[:, 1].min() == 20 + 0.5 and cracks[:, 1].max() == 20 + 2.5


@given(st.integers(0, 2**32 - 1))
def test_outline_cracks_are_in_the_order_of_the_edges_then_of_the_pixels(seed):
    from symfruit.core.raster import Silhouette, outline_cracks

    rng = np.random.default_rng(seed)
    mask = rng.random(tuple(int(x) for x in rng.integers(1, 30, 2))) < rng.uniform(0.0, 1.0)
    u0, v0 = (int(x) for x in rng.integers(0, 600, 2))
    padded = np.pad(mask, 1)  # the plain formulation: the kept order (above, below, left, right; row-major)
    want = []
    for dr, dc in ((-1, 0), (1, 0), (0, -1), (0, 1)):
        shifted = padded[1 + dr : padded.shape[0] - 1 + dr, 1 + dc : padded.shape[1] - 1 + dc]
        rows, cols = np.nonzero(mask & ~shifted)
        want.append(np.stack((cols + 0.5 * dc + u0, rows + 0.5 * dr + v0), axis=1))
    np.testing.assert_array_equal(outline_cracks(Silhouette(u0, v0, mask, 0.0)), np.vstack(want).astype(np.float64))


def test_an_ellipse_is_recovered_from_part_of_its_outline(camera):
    from symfruit.core.raster import Silhouette, outline_cone, silhouette_cone

    vv, uu = np.mgrid[:120, :140]
    a, b, cu, cv = 40.0, 25.0, 70.0, 60.0
    full = ((uu - cu) / a) ** 2 + ((vv - cv) / b) ** 2 <= 1.0
    seen = full & (vv < cv + 5)  # an occluder hides the lower part
    t = np.linspace(np.pi, 2 * np.pi, 200)  # the upper, seen arc of the outline (v = cv + b sin t < cv)
    arc = np.c_[cu + a * np.cos(t), cv + b * np.sin(t)]
    region = Silhouette(250, 180, seen, 0.0)
    cone, axis = outline_cone(region, camera, arc + [250, 180])
    whole, whole_axis = silhouette_cone(Silhouette(250, 180, full, 0.0), camera)
    assert np.allclose(cone, whole, atol=0.02) and np.allclose(axis, whole_axis, atol=2e-3)
    cut, _ = silhouette_cone(region, camera)
    assert not np.allclose(cut, whole, atol=0.02)  # the cut region's moments are not the fruit's
    assert outline_cone(region, camera, arc[:5] + [250, 180]) is None  # too few points
    line = np.c_[np.linspace(0, 100, 50), np.linspace(0, 50, 50)]
    assert outline_cone(region, camera, line + [250, 180]) is None  # no ellipse through a line
    small = np.c_[cu + 5 * np.cos(t), cv + 5 * np.sin(t)]
    assert outline_cone(region, camera, small + [250, 180]) is None  # would not hold the seen region
    with pytest.raises(InputError, match="shape"):
        outline_cone(region, camera, np.zeros((10, 3)))


def test_nearest_index_takes_scipys_pick_among_equally_near_pixels():
    """The upper of two in a column, the left of two in a row, the least column first otherwise (flat indices)."""
    assert nearest_index(np.array([[0, 1, 1, 1, 0]], bool)).tolist() == [[0, 0, 0, 4, 4]]
    assert nearest_index(np.array([[0], [1], [1], [1], [0]], bool)).ravel().tolist() == [0, 0, 0, 4, 4]
    corners = np.array([[1, 1, 0], [1, 1, 1], [0, 1, 1]], bool)
    assert nearest_index(corners).tolist() == [[6, 2, 2], [6, 6, 2], [6, 6, 6]]


@given(st.integers(0, 2**32 - 1))
def test_the_inner_distance_over_the_masks_box_is_the_whole_images(seed):
    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 30, 2))
    mask = np.zeros((h, w), bool)
    r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
    mask[r0 : r0 + int(rng.integers(1, 12)), c0 : c0 + int(rng.integers(1, 12))] = True  # touching a border or not
    mask &= rng.random((h, w)) < rng.uniform(0.6, 1.0)
    assert np.array_equal(inner_distance(mask), ndimage.distance_transform_edt(mask))


@given(st.integers(0, 2**32 - 1), st.floats(0.0, 12.0))
def test_the_outer_distance_within_reach_is_the_whole_images(seed, reach):
    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 40, 2))
    mask = np.zeros((h, w), bool)
    r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
    mask[r0 : r0 + int(rng.integers(1, 12)), c0 : c0 + int(rng.integers(1, 12))] = True
    mask &= rng.random((h, w)) < rng.uniform(0.3, 1.0)
    want = ndimage.distance_transform_edt(~mask)
    got = outer_distance(mask, reach)
    near = want <= reach
    assert np.array_equal(got[near], want[near]) and np.all(got[~near] > reach)
    if not mask.any():
        assert np.array_equal(got, want)


@given(st.integers(0, 2**32 - 1), st.floats(0.0, 200.0), st.floats(0.0, 1.0))
def test_the_near_distance_is_scipys_within_reach_to_the_bit(seed, reach, density):
    """Issue 19's seventh round: the distance to the nearest true pixel by row and column shifts up to the reach
    is scipy's Euclidean distance transform wherever that is within reach (scattered pixels, any density, a
    reach below a pixel to beyond the window; int16 and, past about 127 px, int64 arithmetic), +inf beyond."""
    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 50, 2))
    mask = rng.random((h, w)) < density * density
    if not mask.any():
        mask[int(rng.integers(0, h)), int(rng.integers(0, w))] = True
    want = ndimage.distance_transform_edt(~mask)
    got = _near_distance(mask, reach)
    near = want <= reach
    assert np.array_equal(got[near], want[near]) and np.all(np.isinf(got[~near]))


@given(st.integers(0, 2**32 - 1), st.floats(0.0, 30.0))
def test_the_inner_distance_within_a_reach_is_the_whole_images(seed, reach):
    """``inner_distance(mask, reach)``: scipy's values, to the bit, where they are at most ``reach``; +inf beyond;
    0 outside the mask (masks touching the window's border or not, with holes, full)."""
    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 40, 2))
    mask = np.zeros((h, w), bool)
    r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
    mask[r0 : r0 + int(rng.integers(1, 30)), c0 : c0 + int(rng.integers(1, 30))] = True
    mask &= rng.random((h, w)) < rng.uniform(0.6, 1.0)
    want = ndimage.distance_transform_edt(mask)
    got = inner_distance(mask, reach)
    near = want <= reach
    assert np.array_equal(got[near], want[near]) and np.all(np.isinf(got[~near]) | (got[~near] == want[~near]))
    assert np.all(got[~near] > reach)
    full = np.ones((h, w), bool)
    assert np.array_equal(inner_distance(full, reach), ndimage.distance_transform_edt(full))


def test_the_inner_distance_of_an_empty_or_full_mask_is_the_whole_images():
    for mask in (np.zeros((7, 9), bool), np.ones((7, 9), bool)):
        np.testing.assert_array_equal(inner_distance(mask), ndimage.distance_transform_edt(mask))


def _ball_mask(camera, centre, radius):
    """The exact silhouette (pixel centres) of a ball: rays within its viewing cone's half-angle."""
    v, u = np.mgrid[0 : camera.height, 0 : camera.width].astype(float)
    d = np.stack([(u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, np.ones_like(u)], axis=-1)
    c = np.asarray(centre, dtype=float)
    cos = (d @ c) / (np.linalg.norm(d, axis=-1) * np.linalg.norm(c))
    return cos >= np.sqrt(1.0 - (radius / np.linalg.norm(c)) ** 2)


def test_across_sight_measures_a_ball_off_axis_by_its_diameter():
    from symfruit.core.raster import Silhouette, across_sight, principal_widths

    cam = Camera(fx=960.0, fy=960.0, cx=960.0, cy=540.0, width=1920, height=1080)  # the Azure Kinect's 90 deg
    radius, dist = 0.03, 1.2
    for angle in (0.0, 20.0, 38.0):  # degrees off the optical axis, to the right
        a = np.radians(angle)
        centre = dist * np.array([np.sin(a), 0.0, np.cos(a)])
        mask = _ball_mask(cam, centre, radius)
        rows, cols = np.nonzero(mask)
        window = mask[rows.min() : rows.max() + 1, cols.min() : cols.max() + 1]
        region = Silhouette(int(cols.min()), int(rows.min()), window, 0.0)
        across = across_sight(region, cam)
        pixel = dist / cam.fx  # metres per pixel there
        assert across.minor * dist == pytest.approx(2 * radius, abs=1.5 * pixel)
        assert across.major * dist == pytest.approx(2 * radius, abs=1.5 * pixel)
        np.testing.assert_allclose(across.axis, centre / dist, atol=1e-3)
        # The silhouette's box about the ball's point on the axis is the ball's box (its x side, too).
        x_lo, x_hi = dist * (across.axis[0] + across.lo[0]), dist * (across.axis[0] + across.hi[0])
        assert x_lo == pytest.approx(centre[0] - radius, abs=1.5 * pixel)
        assert x_hi == pytest.approx(centre[0] + radius, abs=1.5 * pixel)
        # Pixel widths times depth over f are stretched by 1 / cos(angle) along the direction off the axis.
        major_px = max(principal_widths(region.mask))
        stretch = major_px * centre[2] / cam.fx / (2 * radius)
        assert stretch == pytest.approx(1.0 / np.cos(a), rel=0.04)


def test_across_sight_rejects_an_empty_region(camera):
    from symfruit.core.raster import Silhouette, across_sight

    with pytest.raises(InputError, match="empty"):
        across_sight(Silhouette(0, 0, np.zeros((4, 4), bool), 0.0), camera)


def test_fill_holes_is_scipys():
    rng = np.random.default_rng(5)
    for _ in range(20):
        mask = ndimage.binary_opening(rng.random((40, 50)) < 0.55)
        assert np.array_equal(fill_holes(mask), ndimage.binary_fill_holes(mask))
    ring = np.zeros((9, 9), bool)
    ring[2:7, 2:7] = True
    ring[4, 4] = False  # one hole: filled; an empty and a full image stay as they are
    assert (
        fill_holes(ring)[4, 4]
        and not fill_holes(np.zeros((5, 5), bool)).any()
        and fill_holes(np.ones((5, 5), bool)).all()
    )


@given(st.integers(0, 2**32 - 1))
def test_principal_widths_are_the_covariance_s_extents_bit_for_bit(seed):
    from symfruit.core.raster import principal_widths

    rng = np.random.default_rng(seed)
    h, w = (int(x) for x in rng.integers(1, 200, 2))
    mask = rng.random((h, w)) < rng.uniform(0.0, 1.0)
    rows, cols = np.nonzero(mask)
    if len(rows) >= 2:  # the former formulation: the coordinates' mean subtracted, numpy's own column means
        xy = np.stack((cols, rows), axis=1).astype(np.float64)
        xy -= xy.mean(axis=0)
        _, vec = np.linalg.eigh(xy.T @ xy)
        p = xy @ vec
        assert principal_widths(mask) == (float(np.ptp(p[:, 0]) + 1.0), float(np.ptp(p[:, 1]) + 1.0))
    r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
    if mask[r0:, c0:].sum() == mask.sum():  # a window holding the whole mask: the same widths at its origin
        assert principal_widths(mask[r0:, c0:], origin=(r0, c0)) == principal_widths(mask)


@given(st.integers(0, 2**32 - 1), st.integers(1, 12), st.integers(1, 12), st.floats(0.0, 0.3))
def test_mask_box_is_the_extent_of_the_true_pixels(seed, h, w, fill):
    mask = np.random.default_rng(seed).random((h, w)) < fill
    box = mask_box(mask)
    if not mask.any():
        assert box is None
        return
    rows, cols = np.nonzero(mask)
    assert box == (rows.min(), rows.max() + 1, cols.min(), cols.max() + 1)
    r0, r1, c0, c1 = box
    assert mask[r0:r1, c0:c1].sum() == mask.sum() and all(isinstance(x, int) for x in box)


@given(st.integers(0, 2**32 - 1))
def test_what_a_region_keeps_is_what_a_fresh_region_works_out(seed):
    """Moments and outline are made once per region: the cone, the widths across the line of sight and the
    outline of a region asked again are those of a fresh copy, and what is kept is read-only."""
    from symfruit.core.raster import Silhouette, across_sight, outline_cracks, silhouette_cone

    rng = np.random.default_rng(seed)
    cam = Camera(fx=600.0, fy=600.0, cx=320.0, cy=240.0, width=640, height=480)
    mask = ndimage.binary_opening(rng.random((30, 40)) < 0.7)
    if not mask.any():
        mask[5:9, 5:12] = True
    u0, v0 = int(rng.integers(0, 600)), int(rng.integers(0, 450))
    kept = Silhouette(u0, v0, mask, 0.0)
    for _ in range(2):
        fresh = Silhouette(u0, v0, mask.copy(), 0.0)
        for a, b in zip(silhouette_cone(kept, cam), silhouette_cone(fresh, cam), strict=True):
            assert np.array_equal(a, b)
        a, b = across_sight(kept, cam), across_sight(fresh, cam)
        assert np.array_equal(a.lo, b.lo) and np.array_equal(a.hi, b.hi) and (a.minor, a.major) == (b.minor, b.major)
        assert np.array_equal(outline_cracks(kept), outline_cracks(fresh))
    assert not outline_cracks(kept).flags.writeable


@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40))
def test_fill_holes_over_the_masks_box_is_scipys(seed, h, w):
    """Labelled over the mask's box grown by a pixel: the same holes wherever the mask lies in the image (its box
    at the border, in a corner, a pixel wide, or a mask with rings inside rings)."""
    rng = np.random.default_rng(seed)
    mask = np.zeros((h, w), bool)
    r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
    r1, c1 = int(rng.integers(r0 + 1, h + 1)), int(rng.integers(c0 + 1, w + 1))
    mask[r0:r1, c0:c1] = rng.random((r1 - r0, c1 - c0)) < rng.uniform(0.3, 0.9)
    yy, xx = np.mgrid[:h, :w]
    for radius in rng.uniform(1, 12, int(rng.integers(0, 4))):  # rings: holes with islands with holes
        mask ^= np.abs(np.hypot(yy - rng.uniform(0, h), xx - rng.uniform(0, w)) - radius) < 0.8
    assert np.array_equal(fill_holes(mask), ndimage.binary_fill_holes(mask))


@given(st.integers(0, 2**32 - 1), st.integers(1, 30), st.integers(1, 30))
def test_interior_is_scipys_erosion(seed, h, w):
    from symfruit.core.raster import interior

    mask = np.random.default_rng(seed).random((h, w)) < np.random.default_rng(seed + 1).uniform(0.2, 1.0)
    assert np.array_equal(interior(mask), ndimage.binary_erosion(mask))
    assert np.array_equal(interior(np.ones((h, w), bool)), ndimage.binary_erosion(np.ones((h, w), bool)))


@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40), st.integers(1, 7))
def test_eroded_is_scipys_iterated_erosion(seed, h, w, iterations):
    from symfruit.core.raster import eroded

    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[:h, :w]
    # a blob (what a fruit's mask is) or speckle
    if rng.random() < 0.5:
        mask = np.hypot(yy - rng.uniform(0, h), xx - rng.uniform(0, w)) < rng.uniform(1, 25)
    else:
        mask = rng.random((h, w)) < rng.uniform(0.2, 1.0)
    assert np.array_equal(eroded(mask, iterations), ndimage.binary_erosion(mask, iterations=iterations))


@pytest.mark.parametrize("kernels", ["", "numpy"])
@pytest.mark.parametrize("every", [False, True])
@given(seed=st.integers(0, 2**32 - 1))
def test_the_square_filter_is_scipys_minimum_or_maximum_filter(kernels, every, seed):
    """:func:`square_filter` with the compiled kernel and with its numpy twin: scipy's filter of the square, outside
    the image false (a square touching the border is not all true), on masks of any density and size."""
    import os

    from symfruit.core.raster import square_filter

    rng = np.random.default_rng(seed)
    h, w = rng.integers(1, 40, 2)
    mask = rng.random((h, w)) < rng.uniform(0.0, 1.0)
    radius = int(rng.integers(0, 6))
    filt = ndimage.minimum_filter if every else ndimage.maximum_filter
    want = filt(mask, size=2 * radius + 1, mode="constant", cval=False)
    before = os.environ.pop("SYMFRUIT_KERNELS", None)
    try:
        if kernels:
            os.environ["SYMFRUIT_KERNELS"] = kernels
        got = square_filter(mask, radius, every=every)
    finally:
        os.environ.pop("SYMFRUIT_KERNELS", None)
        if before is not None:
            os.environ["SYMFRUIT_KERNELS"] = before
    assert got.dtype == bool and np.array_equal(got, want)


def test_inverse2_is_numpys_inv():
    """:func:`symfruit.core.raster.inverse2` against ``np.linalg.inv`` on 20,000 random 2x2 matrices (symmetric
    positive definite as a silhouette's scaled covariance, and not; rows to swap; scales 1e-4 to 1e4): the same
    values (OpenBLAS's ``dgesv`` with the identity on the right: to the bit where it runs its Haswell kernels; its
    AVX-512 kernels round otherwise, so within 4 epsilons times the condition number of the largest entry, the
    rounding bound of an inverse); None where numpy must answer."""
    from symfruit.core.raster import inverse2

    rng = np.random.default_rng(3)
    for i in range(20_000):
        m = rng.normal(size=(2, 2)) * 10.0 ** rng.integers(-4, 5)
        if i % 2:
            m = m @ m.T + np.eye(2) / 12.0
        got = inverse2(m)
        assert got is not None
        want = np.linalg.inv(m)
        assert np.abs(got - want).max() <= 4.0 * np.finfo(float).eps * np.linalg.cond(m) * np.abs(want).max()
    assert inverse2(np.array([[0.0, 1.0], [0.0, 2.0]])) is None  # singular: numpy raises
    assert inverse2(np.array([[1.0, 2.0], [2.0, 4.0]])) is None
    assert (
        inverse2(np.array([[np.inf, 0.0], [0.0, 1.0]])) is None
        and inverse2(np.array([[1e-120, 0.0], [0.0, 1.0]])) is None
    )


def test_the_widths_of_the_ellipse_recovered_from_part_of_an_outline_are_the_whole_outlines(camera):
    """Stop 56: :func:`cone_widths` of the cone :func:`outline_cone` fits to the upper arc of an 80 x 50 px ellipse
    are its widths (pixels over the focal length, near the optical axis), where the cut region's moment ellipse
    reads its lower half short; a cone that is no ellipse across the line of sight has none."""
    from symfruit.core.raster import Silhouette, cone_widths, outline_cone, silhouette_cone

    vv, uu = np.mgrid[:120, :140]
    a, b, cu, cv = 40.0, 25.0, 70.0, 60.0
    full = ((uu - cu) / a) ** 2 + ((vv - cv) / b) ** 2 <= 1.0
    t = np.linspace(np.pi, 2 * np.pi, 200)
    arc = np.c_[cu + a * np.cos(t), cv + b * np.sin(t)] + [camera.cx - cu, camera.cy - cv]
    region = Silhouette(int(camera.cx - cu), int(camera.cy - cv), full & (vv < cv + 5), 0.0)
    minor, major = cone_widths(*outline_cone(region, camera, arc))
    assert minor * camera.fy == pytest.approx(2 * b, rel=0.01) and major * camera.fx == pytest.approx(2 * a, rel=0.01)
    cut_minor, _ = cone_widths(*silhouette_cone(region, camera))
    assert cut_minor * camera.fy < 0.75 * 2 * b
    assert cone_widths(np.diag([1.0, -1.0, -1.0]), np.array([0.0, 0.0, 1.0])) is None  # a hyperbola across it


def test_outline_cone_is_the_same_with_its_kernels_and_without(camera, monkeypatch):
    """Arcs of ellipses at crack midpoints (half pixels), some accepted, some not: the same cone and axis to the bit
    with the compiled design (core._jit.conic_design, where numba is) and with its numpy twin (issue 19, stop 44)."""
    from symfruit.core.raster import Silhouette, outline_cone

    vv, uu = np.mgrid[:120, :140]
    rng = np.random.default_rng(5)
    found = 0
    for a, b, cut in ((40.0, 25.0, 5.0), (30.0, 30.0, -10.0), (50.0, 20.0, 15.0), (35.0, 28.0, 0.0)):
        full = ((uu - 70.0) / a) ** 2 + ((vv - 60.0) / b) ** 2 <= 1.0
        region = Silhouette(250, 180, full & (vv < 60.0 + cut), 0.0)
        t = np.sort(rng.uniform(np.pi, 2 * np.pi, 150))
        arc = np.round(np.c_[70.0 + a * np.cos(t), 60.0 + b * np.sin(t)] * 2.0) / 2.0 + [250, 180]
        for pts in (arc, arc[::3], arc + rng.normal(scale=0.7, size=arc.shape)):
            monkeypatch.delenv("SYMFRUIT_KERNELS", raising=False)
            got = outline_cone(region, camera, pts)
            monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
            twin = outline_cone(region, camera, pts)
            assert (got is None) == (twin is None)
            if got is not None and twin is not None:
                found += 1
                assert got[0].tobytes() == twin[0].tobytes() and got[1].tobytes() == twin[1].tobytes()
    assert found >= 4


def _spheroid_front(a, c, tilt_deg, roll_deg, *, noise=0.0, seed=0, dist=0.4):
    """A spheroid's seen front (half-axes ``a`` across, ``c`` along its axis, the axis tilted ``tilt_deg`` out of the
    image plane and turned ``roll_deg`` in it), one ray per pixel of a 640 x 480 camera, depth noise ``noise``
    metres (seeded), and its true depth half-extent."""
    from symfruit.core.camera import Camera

    cam = Camera(fx=600.0, fy=600.0, cx=320.0, cy=240.0, width=640, height=480)
    t, r = np.radians(tilt_deg), np.radians(roll_deg)
    u = np.array([np.cos(t) * np.cos(r), np.cos(t) * np.sin(r), np.sin(t)])
    q = np.eye(3) / a**2 + np.outer(u, u) * (1.0 / c**2 - 1.0 / a**2)
    centre = np.array([0.01, -0.005, dist])
    uu, vv = np.meshgrid(np.arange(640.0), np.arange(480.0))
    d = cam.rays(uu.ravel(), vv.ravel()).reshape(-1, 3)
    qa = np.einsum("ni,ij,nj->n", d, q, d)
    qb = -2.0 * d @ q @ centre
    qc = centre @ q @ centre - 1.0
    disc = qb * qb - 4.0 * qa * qc
    hit = disc > 0
    z = (-qb[hit] - np.sqrt(disc[hit])) / (2.0 * qa[hit])
    pts = d[hit] * z[:, None]
    pts *= (1.0 + noise * np.random.default_rng(seed).standard_normal(len(pts)) / pts[:, 2])[:, None]
    return pts, cam, float(np.sqrt(np.linalg.inv(q)[2, 2]))


@pytest.mark.parametrize(
    ("a", "c", "tilt", "noise", "geometric_off"),
    [(0.03, 0.05, 0, 0.0, True), (0.03, 0.05, 30, 0.0016, False), (0.03, 0.05, 55, 0.0016, True),
     (0.04, 0.028, 0, 0.0016, True), (0.04, 0.028, 25, 0.0016, False), (0.03, 0.03, 40, 0.0016, False)],
)  # fmt: skip
def test_axis_tilt_finds_a_spheroids_depth(a, c, tilt, noise, geometric_off):
    from symfruit.core.raster import across_sight, axis_tilt, silhouette

    pts, cam, depth = _spheroid_front(a, c, tilt, 30.0, noise=noise)
    region = silhouette(pts, cam)
    across = across_sight(region, cam)
    t = axis_tilt(pts, region, cam, across)
    assert t.count > 1000
    # the half-widths are at the front's median distance, nearer than the centre: compare ratios to the outline
    scale = a / t.minor if c >= a else a / t.major
    assert t.half_depth() * scale == pytest.approx(depth, rel=0.07)
    geometric = float(np.sqrt(t.major * t.minor)) * scale
    if geometric_off:  # the outline's geometric mean (the prior's width before) is off by more than the tolerance
        assert abs(geometric / depth - 1.0) > 0.1
    if c > a:  # a prolate spheroid: its midline slopes along the outline's major axis, by tan(tilt)(1 - a^2/M^2)
        assert abs(t.slope_minor) < 0.05
        expected = np.tan(np.radians(tilt)) * (1.0 - (t.minor / t.major) ** 2)
        assert abs(t.slope_major) == pytest.approx(expected, abs=0.05)


def test_tilt_half_depths_know_the_spheroids_formula():
    from symfruit.core.raster import Tilt

    # a prolate spheroid a = 30, c = 50 mm tilted 40 deg: outline major sqrt(c^2 cos^2 + a^2 sin^2), midline slope
    a, c, th = 0.03, 0.05, np.radians(40.0)
    major = np.sqrt(c**2 * np.cos(th) ** 2 + a**2 * np.sin(th) ** 2)
    slope = np.tan(th) * (1.0 - a**2 / major**2)
    t = Tilt(major, a, slope, 0.0, 1.0, 0.0, 500)
    prolate, oblate = t.half_depths()
    assert prolate == pytest.approx(np.sqrt(c**2 * np.sin(th) ** 2 + a**2 * np.cos(th) ** 2), rel=1e-12)
    assert oblate == pytest.approx(major, rel=1e-12)
    # its cap is the prolate's own: the depth is the prolate's
    cap = np.sqrt(1.0 + slope**2 * major**2 / (major**2 - a**2))
    assert Tilt(major, a, slope, 0.0, cap, 0.0, 500).half_depth() == pytest.approx(prolate, rel=1e-9)
    # no estimate: the geometric mean of the two
    assert Tilt(major, a, slope, 0.0, cap, 0.0, 0).half_depth() == pytest.approx(np.sqrt(prolate * oblate))


def _eroded(region, px):
    """``region`` with ``px`` pixels taken off its rim (a time-of-flight camera's lost band)."""
    from scipy import ndimage

    from symfruit.core.raster import Silhouette

    return Silhouette(region.u0, region.v0, ndimage.binary_erosion(region.mask, iterations=px), region.fill_radius)


def test_axis_tilt_scales_an_eroded_outline_to_the_whole_one():
    from symfruit.core.raster import across_sight, axis_tilt, silhouette

    # an oblate spheroid 40 x 28 mm seen side on: cap major / minor = 1.43, depth its major half-width
    pts, cam, depth = _spheroid_front(0.04, 0.028, 0, 30.0, noise=0.0)
    whole = silhouette(pts, cam)
    part = _eroded(whole, 4)
    rows, cols = (np.rint(cam.project(pts)[:, ::-1]).astype(int) - [part.v0, part.u0]).T
    inner = pts[part.mask[rows, cols]]
    across = across_sight(whole, cam)
    clean = axis_tilt(pts, whole, cam, across)
    eroded = axis_tilt(inner, part, cam, across)
    fixed = axis_tilt(inner, part, cam, across, outer=whole)
    # the eroded outline reads the front as flatter than it is (its cap falls towards the prolate's 1)
    assert eroded.cap < clean.cap - 0.1
    assert fixed.cap == pytest.approx(clean.cap, abs=0.05)
    assert fixed.major == pytest.approx(clean.major, rel=0.02) and fixed.minor == pytest.approx(clean.minor, rel=0.02)
    assert fixed.half_depth() / fixed.major == pytest.approx(depth / 0.04, rel=0.05)
    # an outer outline the same as the region's changes nothing (but rounding)
    same = axis_tilt(pts, whole, cam, across, outer=whole)
    assert same.count == clean.count and same.cap == pytest.approx(clean.cap, rel=1e-12)


def test_block_jackknife_knows_a_mean_and_correlated_noise():
    from symfruit.core.raster import _block_jackknife

    # the mean of 8 blocks of equal size: the jackknife variance is the blocks' means' variance over 8 (sample SD)
    rng = np.random.default_rng(0)
    group = np.repeat(np.arange(8), 50)
    b = rng.standard_normal(400) + np.repeat(rng.standard_normal(8), 50)  # a shared offset per block
    means = np.array([b[group == g].mean() for g in range(8)])
    got = _block_jackknife(np.ones((400, 1)), b, group, 8)
    assert got[0] == pytest.approx(means.var(ddof=1) / 8, rel=1e-9)
    # independent residuals would say 1/400 of the total variance: the block offsets make it several times more
    assert got[0] > 3.0 * b.var() / 400
    # empty blocks are left out
    assert _block_jackknife(np.ones((400, 1)), b, group, 10)[0] == pytest.approx(got[0], rel=1e-9)


def test_tilt_share_shrinks_to_the_geometric_mean_when_the_cap_cannot_tell():
    from symfruit.core.raster import Tilt

    # a level midline: prolate depth minor (cap 1), oblate major (cap major / minor); the cap says oblate
    sure = Tilt(0.04, 0.034, 0.0, 0.0, 0.04 / 0.034, 0.0, 500)
    assert sure.half_depth() == pytest.approx(0.04, rel=1e-9)
    # the cap known to no better than the two hypotheses are apart: halfway (in log) back to the geometric mean
    gap = np.log(0.04 / 0.034)
    unsure = Tilt(0.04, 0.034, 0.0, 0.0, 0.04 / 0.034, 0.0, 500, cap_sd=gap * 0.04 / 0.034)
    assert unsure.half_depth() == pytest.approx(0.04**0.75 * 0.034**0.25, rel=1e-9)
    hopeless = Tilt(0.04, 0.034, 0.0, 0.0, 0.04 / 0.034, 0.0, 500, cap_sd=100.0)
    assert hopeless.half_depth() == pytest.approx(np.sqrt(0.04 * 0.034), rel=1e-6)


def test_tilt_oblate_share_reads_prolate_lying_and_oblate_side_on():
    from symfruit.core.raster import Tilt, across_sight, axis_tilt, silhouette

    # a level midline: the prolate spheroid's cap is 1, the oblate's major / minor, the share the log between
    assert Tilt(0.04, 0.034, 0.0, 0.0, 1.0, 0.0, 500).oblate_share() == 0.0
    assert Tilt(0.04, 0.034, 0.0, 0.0, 0.04 / 0.034, 0.0, 500).oblate_share() == pytest.approx(1.0, rel=1e-12)
    assert Tilt(0.04, 0.034, 0.0, 0.0, np.sqrt(0.04 / 0.034), 0.0, 500).oblate_share() == pytest.approx(0.5)
    assert Tilt(0.04, 0.034, 0.0, 0.0, 2.0, 0.0, 500).oblate_share() == 1.0  # clipped
    # no estimate, or a round outline (the two caps agree): nothing said
    assert Tilt(0.04, 0.034, 0.0, 0.0, 1.0, 0.0, 0).oblate_share() is None
    assert Tilt(0.04, 0.04, 0.0, 0.0, 1.0, 0.0, 500).oblate_share() is None
    # the cap known to no better than the two hypotheses are apart: halfway back to a half
    gap = np.log(0.04 / 0.034)
    unsure = Tilt(0.04, 0.034, 0.0, 0.0, 0.04 / 0.034, 0.0, 500, cap_sd=gap * 0.04 / 0.034)
    assert unsure.oblate_share() == pytest.approx(0.75, rel=1e-9)
    # fitted fronts: a prolate spheroid 30 x 50 mm lying in the image, an oblate 40 x 28 mm seen side on
    for a, c, want in ((0.03, 0.05, 0.0), (0.04, 0.028, 1.0)):
        pts, cam, _ = _spheroid_front(a, c, 0, 30.0, noise=0.0016)
        region = silhouette(pts, cam)
        share = axis_tilt(pts, region, cam, across_sight(region, cam)).oblate_share()
        assert share is not None and abs(share - want) < 0.2


def test_axis_tilt_blocks_measure_the_fits_uncertainty():
    from symfruit.core.raster import across_sight, axis_tilt, silhouette

    pts, cam, _ = _spheroid_front(0.03, 0.05, 30, 30.0, noise=0.0016)
    region = silhouette(pts, cam)
    across = across_sight(region, cam)
    plain = axis_tilt(pts, region, cam, across)
    t = axis_tilt(pts, region, cam, across, blocks=8)
    # the same fit, with a cap SD that independent noise of 1.6 mm keeps small, and a slope SD no smaller
    assert (t.cap, t.slope_major, t.count) == (plain.cap, plain.slope_major, plain.count)
    assert plain.cap_sd == 0.0 and 0.0 < t.cap_sd < 0.05 and t.slope_sd >= plain.slope_sd
    # noise correlated over blocks of the front (a camera's, over a few pixels): a larger cap SD
    rng = np.random.default_rng(1)
    uv = cam.project(pts)
    patch = rng.standard_normal((100, 100))[(uv[:, 1] // 12).astype(int), (uv[:, 0] // 12).astype(int)]
    lumpy = pts * (1.0 + 0.003 * patch / pts[:, 2])[:, None]
    assert axis_tilt(lumpy, region, cam, across, blocks=8).cap_sd > 2.0 * t.cap_sd


def test_bracket_tilt_is_unsure_by_half_the_outlines_disagreement():
    from symfruit.core.raster import Tilt, bracket_tilt

    inner = Tilt(0.036, 0.030, 0.10, 0.02, 0.9, 0.01, 800, 0.02)  # the eroded outline: flatter
    outer = Tilt(0.040, 0.034, 0.14, 0.00, 1.3, 0.01, 900, 0.03)  # the grown mask: rounder than round
    b = bracket_tilt(inner, outer)
    assert b.major == pytest.approx(np.sqrt(0.036 * 0.040)) and b.minor == pytest.approx(np.sqrt(0.030 * 0.034))
    assert b.cap == pytest.approx(np.sqrt(0.9 * 1.3)) and b.count == 800
    assert (b.slope_major, b.slope_minor, b.slope_sd) == pytest.approx((0.12, 0.01, 0.02))
    assert b.cap_sd == pytest.approx(np.hypot(0.03, 0.5 * np.log(1.3 / 0.9) * b.cap))
    # agreeing fits: the fit's own uncertainty; one without an estimate: the other
    same = bracket_tilt(outer, outer)
    assert same.cap == pytest.approx(1.3) and same.cap_sd == pytest.approx(0.03)
    assert bracket_tilt(Tilt(0.04, 0.03, 0.0, 0.0, 1.0, 0.0, 0), outer) is outer
    # the disagreement pulls the depth towards the geometric mean more than the outer fit alone would
    lone = Tilt(b.major, b.minor, 0.0, 0.0, b.cap, 0.0, 800)
    gm = np.sqrt(b.major * b.minor)
    unsure = Tilt(b.major, b.minor, 0.0, 0.0, b.cap, 0.0, 800, b.cap_sd)
    assert abs(np.log(unsure.half_depth() / gm)) < abs(np.log(lone.half_depth() / gm))


def test_axis_tilt_bend_reads_a_bowed_midline_and_naught_on_a_spheroid():
    from symfruit.core.raster import across_sight, axis_tilt, silhouette

    # a prolate spheroid 30 x 50 mm lying across the line of sight (turned 30 deg in the image): its midline is
    # straight, so the bend is naught within its noise
    pts, cam, _ = _spheroid_front(0.03, 0.05, 0, 30.0, noise=0.0016)
    region = silhouette(pts, cam)
    across = across_sight(region, cam)
    straight = axis_tilt(pts, region, cam, across, bend=True)
    assert abs(straight.bend) < 3.0 * straight.bend_sd + 0.2
    assert straight.half_depth() == pytest.approx(axis_tilt(pts, region, cam, across).half_depth(), rel=0.03)
    # the same front bowed away from the camera by k p^2 (p along the axis): a banana's sagitta of k M^2 = 10 mm
    k = 0.010 / 0.05**2
    axis = np.array([np.cos(np.radians(30.0)), np.sin(np.radians(30.0))])
    p = (pts[:, :2] - pts[:, :2].mean(axis=0)) @ axis
    bowed = pts * (1.0 + k * p**2 / pts[:, 2])[:, None]
    t = axis_tilt(bowed, region, cam, across, bend=True)
    assert t.bend == pytest.approx(k, rel=0.1) and t.bend_sd < 0.1 * k
    # the depth half-extent grows by half the sagitta beyond its noise, times the outline's elongation
    # 1 - minor^2 / major^2 (0.64 here: a near-round outline's major axis is no axis that bends)
    want = 0.5 * (abs(t.bend) - t.bend_sd) * (t.major**2 - t.minor**2)
    assert want == pytest.approx(0.5 * 0.010 * 0.64, rel=0.15)
    assert t.half_depths()[0] - straight.half_depths()[0] == pytest.approx(want, abs=0.001)


# --- stop 57, cutprior57: a cut outline's width read side by side


def _cut_disc(keep_from: float):
    """A 40 px disc about (50, 50) seen right of column ``keep_from`` (a leaf over the rest): its region, outline,
    which of the outline is the disc's own (not the cut's straight edge), and a 100 px camera."""
    from symfruit.core.raster import Silhouette, outline_cracks

    cam = Camera(fx=500.0, fy=500.0, cx=50.0, cy=50.0, width=100, height=100)
    v, u = np.mgrid[:100, :100]
    mask = ((u - 50.0) ** 2 + (v - 50.0) ** 2 <= 400.0) & (u >= keep_from)
    region = Silhouette(0, 0, mask, 0.0)
    cracks = outline_cracks(region)
    return region, cracks, cracks[:, 0] > keep_from - 0.4, cam


def _circle_cone(cam, r: float, cu: float = 50.0, cv: float = 50.0):
    conic = np.array([[1.0, 0.0, -cu], [0.0, 1.0, -cv], [-cu, -cv, cu * cu + cv * cv - r * r]])
    return cam.matrix.T @ conic @ cam.matrix


def test_a_disc_cut_on_one_side_reaches_the_ellipse_there_and_keeps_its_seen_extent_across():
    """Stop 57 (docs/cutprior57.md): a leaf hides the left 30 % of a 40 px disc (the region 27 x 41 px between its
    outline's pixel edges). The ellipse through the free arcs is the disc: the cut (left) side reaches it, the right
    side and the vertical extent are the disc's own contour and stay, so the fruit is 40.5 / 27 as wide and as tall:
    the stretch is the square root of 1.5. The moment ellipse of the cut region would read 27 px across."""
    from symfruit.core.raster import free_side_stretch

    region, cracks, free, cam = _cut_disc(44.0)
    assert np.ptp(cracks[:, 0]) == 27.0 and np.ptp(cracks[:, 1]) == 41.0
    stretch = free_side_stretch(cracks, free, _circle_cone(cam, 20.0), cam, region)
    assert stretch**2 == pytest.approx(40.5 / 27.0, rel=1e-9)
    # nothing cut: nothing moves, whatever the ellipse
    assert free_side_stretch(cracks, np.ones(len(cracks), bool), _circle_cone(cam, 30.0), cam, region) == 1.0


def test_an_ellipse_too_large_moves_only_the_cut_side_and_no_axis_past_the_widest_seen():
    """Stop 57: an ellipse fitted wider than the fruit (radius 30 px for a 20 px disc, as a partial arc's fit can be)
    leaves the free sides where they are seen; the cut side reaches it, but the axis no longer than the region's
    widest extent (41 px, the uncut vertical): 41 / 27. A smaller ellipse than the region never narrows it."""
    from symfruit.core.raster import free_side_stretch

    region, cracks, free, cam = _cut_disc(44.0)
    assert free_side_stretch(cracks, free, _circle_cone(cam, 30.0), cam, region) ** 2 == pytest.approx(41.0 / 27.0)
    assert free_side_stretch(cracks, free, _circle_cone(cam, 5.0), cam, region) == 1.0


def test_a_cut_outline_whose_ellipse_centre_is_hidden_keeps_the_cut_regions_width():
    """Stop 57: a leaf over the left 60 % of the disc hides its centre (a round fruit's nearest point): the front read
    from the seen points lies behind the fruit's, and a full width from it would put the back face too far, so with
    the region given nothing moves; without it the cut side reaches the ellipse."""
    from symfruit.core.raster import free_side_stretch

    region, cracks, free, cam = _cut_disc(52.0)
    cone = _circle_cone(cam, 20.0)
    assert free_side_stretch(cracks, free, cone, cam, region) == 1.0
    assert free_side_stretch(cracks, free, cone, cam) > 1.2


# --- stop 58, cut58: the cut side's lateral face, where the fruit ends behind the cut


def test_a_disc_cut_on_one_side_gains_the_ellipses_outermost_point_there_and_keeps_the_rest_as_seen():
    """Stop 58 (docs/cut58.md): the disc of stop 57's test, its left 30 % hidden. The whole outline
    :func:`free_side_reach` reads is the seen one and the ellipse's leftmost point, (30, 50): the fruit's extent,
    40.5 x 41 px, its stretch stop 57's. Nothing cut: no outline."""
    from symfruit.core.raster import free_side_reach

    region, cracks, free, cam = _cut_disc(44.0)
    stretch, outline = free_side_reach(cracks, free, _circle_cone(cam, 20.0), cam, region)
    assert stretch**2 == pytest.approx(40.5 / 27.0, rel=1e-9)
    np.testing.assert_array_equal(outline[: len(cracks)], cracks)
    np.testing.assert_allclose(outline[len(cracks) :], [[30.0, 50.0]], rtol=0, atol=1e-9)
    assert free_side_reach(cracks, np.ones(len(cracks), bool), _circle_cone(cam, 20.0), cam, region) == (1.0, None)


def test_a_disc_cut_on_both_sides_shares_the_capped_length_between_them():
    """Stop 58: a leaf on either side leaves the disc's middle 13 px (columns 44-56). An ellipse fitted too large
    (radius 30 px) reaches 30 px either side of the centre; the axis is capped at the widest seen extent (the uncut
    vertical, 41 px), and the 28 px it may grow are shared in proportion to the two sides' reach (equal here): the
    outline gains the points 14 px beyond either cut edge on the ellipse's diameter across them, (29.5, 50) and
    (70.5, 50)."""
    from symfruit.core.raster import Silhouette, free_side_reach, outline_cracks

    cam = Camera(fx=500.0, fy=500.0, cx=50.0, cy=50.0, width=100, height=100)
    v, u = np.mgrid[:100, :100]
    mask = ((u - 50.0) ** 2 + (v - 50.0) ** 2 <= 400.0) & (u >= 44) & (u <= 56)
    region = Silhouette(0, 0, mask, 0.0)
    cracks = outline_cracks(region)
    free = (cracks[:, 0] > 43.6) & (cracks[:, 0] < 56.4)
    stretch, outline = free_side_reach(cracks, free, _circle_cone(cam, 30.0), cam, region)
    assert stretch**2 == pytest.approx(41.0 / 13.0, rel=1e-9)
    np.testing.assert_allclose(outline[len(cracks) :], [[29.5, 50.0], [70.5, 50.0]], rtol=0, atol=1e-9)


def test_an_oblique_cut_adds_the_ellipses_extreme_point_inside_its_box():
    """Stop 58: a leaf over a disc's upper left, cut along a diagonal (the region's principal axes oblique). The
    points added lie on the ellipse (the disc), so the outline's box is within the disc's on every side: the cut edge
    itself carried out along the oblique axis would have stuck out past the disc across it."""
    from symfruit.core.raster import Silhouette, free_side_reach, outline_cracks

    cam = Camera(fx=500.0, fy=500.0, cx=50.0, cy=50.0, width=100, height=100)
    v, u = np.mgrid[:100, :100]
    mask = ((u - 50.0) ** 2 + (v - 50.0) ** 2 <= 400.0) & (u + v >= 90)
    region = Silhouette(0, 0, mask, 0.0)
    cracks = outline_cracks(region)
    free = cracks.sum(axis=1) > 90.6
    stretch, outline = free_side_reach(cracks, free, _circle_cone(cam, 20.0), cam, region)
    assert stretch > 1.1
    added = outline[len(cracks) :]
    assert len(added) == 1
    np.testing.assert_allclose(np.hypot(*(added - 50.0).T), 20.0, atol=1e-9)  # on the disc's circle
    assert outline[:, 0].min() >= 29.5 and outline[:, 1].min() >= 29.5


def test_the_tangent_extent_of_a_regions_outline_is_across_sights():
    """:func:`tangent_extent` reads outline points as :func:`across_sight` reads its region's (here off the optical
    axis, where the tangent frame is not the image's)."""
    from symfruit.core.raster import Silhouette, across_sight, outline_cracks, tangent_extent

    cam = Camera(fx=500.0, fy=500.0, cx=320.0, cy=240.0, width=640, height=480)
    v, u = np.mgrid[:60, :80]
    region = Silhouette(500, 30, ((u - 40.0) / 35.0) ** 2 + ((v - 30.0) / 25.0) ** 2 <= 1.0, 0.0)
    across = across_sight(region, cam)
    lo, hi = tangent_extent(outline_cracks(region), across, cam)
    np.testing.assert_allclose(lo, across.lo, rtol=0, atol=1e-12)
    np.testing.assert_allclose(hi, across.hi, rtol=0, atol=1e-12)


def _straight_cut_disc(r: float, cut: float, size: int = 100):
    """A digitised disc of radius ``r`` px about (50, 50) (pixel centres within it), a straight edge hiding its
    left ``cut`` of its width: the cut region, its outline's crack points and which of them are the disc's own."""
    from symfruit.core.raster import Silhouette, outline_cracks

    v, u = np.mgrid[:size, :size]
    edge = 50.0 - r + cut * 2.0 * r
    region = Silhouette(0, 0, ((u - 50.0) ** 2 + (v - 50.0) ** 2 <= r * r) & (u >= edge), 0.0)
    cracks = outline_cracks(region)
    return region, cracks, cracks[:, 0] > np.ceil(edge) - 0.5 + 1e-9  # the pixel edges on the cut are not free


@pytest.mark.parametrize(("r", "cut"), [(21.5, 0.35), (29.5, 0.35), (13.0, 0.3), (40.0, 0.45)])
def test_a_disc_cut_by_a_straight_edge_gives_the_circle_of_its_diameter(r, cut):
    """Stop 60 (docs/cut60.md): a digitised disc (26-80 px across, the real spheres' 43 and 59 px among them) with a
    straight edge hiding its left 30-45 %: the circle through its free arcs (:func:`outline_circle`) is the disc's, to
    a pixel across, where the cut region's geometric-mean width is 0.75-0.85 of it; and the cone's widths across the
    line of sight are its diameter over the focal length. Read side by side (:func:`free_side_stretch`, the cut side
    reaching the circle) the cut region's widths give the diameter too, to a pixel."""
    from symfruit.core.raster import cone_widths, free_side_stretch, outline_circle

    cam = Camera(fx=500.0, fy=500.0, cx=50.0, cy=50.0, width=100, height=100)
    region, cracks, free = _straight_cut_disc(r, cut)
    cone, axis = outline_circle(region, cam, cracks[free])
    minor, major = cone_widths(cone, axis)
    assert minor * cam.fx == pytest.approx(major * cam.fx, abs=1e-3)  # a circle (near the optical axis)
    assert minor * cam.fx == pytest.approx(2.0 * r, abs=1.0)
    widths = np.ptp(cracks, axis=0)
    assert np.sqrt(widths.prod()) < 0.9 * 2.0 * r  # what the cut region reads
    # read side by side (the prior's width, evidence's cut_circle): the cut side reaches the circle, the rest stays
    stretch = free_side_stretch(cracks, free, cone, cam, region)
    assert np.sqrt(widths.prod()) * stretch == pytest.approx(2.0 * r, abs=1.0)


def test_an_elongated_or_scattered_outline_gives_no_circle():
    """:func:`outline_circle` is None where the points stray from their circle by more than a digitised outline's
    half pixel (an ellipse 2 : 1, and the disc's arcs scattered by a pixel), too few, a line, or a circle that would
    not hold the region; and the point array's shape is checked."""
    from symfruit.core.raster import Silhouette, outline_circle, outline_cracks

    cam = Camera(fx=500.0, fy=500.0, cx=50.0, cy=50.0, width=100, height=100)
    region, cracks, free = _straight_cut_disc(21.5, 0.35)
    pts = cracks[free]
    assert outline_circle(region, cam, pts) is not None
    rng = np.random.default_rng(0)
    assert outline_circle(region, cam, pts + rng.normal(scale=1.0, size=pts.shape)) is None  # ragged
    assert outline_circle(region, cam, pts[:10]) is None  # too few
    assert outline_circle(region, cam, pts, fit_px=0.0) is None
    v, u = np.mgrid[:100, :100]
    oval = Silhouette(0, 0, ((u - 50.0) / 40.0) ** 2 + ((v - 50.0) / 20.0) ** 2 <= 1.0, 0.0)
    ring = outline_cracks(oval)
    assert outline_circle(oval, cam, ring[ring[:, 0] > 40.0]) is None  # an ellipse 2 : 1
    line = np.c_[np.linspace(30.0, 70.0, 40), np.full(40, 50.0)]
    assert outline_circle(region, cam, line) is None
    t = np.linspace(0.0, np.pi, 40)
    small = np.c_[50.0 + 5.0 * np.cos(t), 50.0 + 5.0 * np.sin(t)]
    assert outline_circle(region, cam, small) is None  # would not hold the region
    with pytest.raises(InputError, match="shape"):
        outline_circle(region, cam, np.zeros((30, 3)))


def test_outline_circles_acceptance_is_the_same_with_its_kernels_and_without(monkeypatch):
    """The circle's acceptance counts the region's pixels by ``core._jit.ellipse_holds`` where numba is and by its
    numpy twin: the same cone to the bit, accepted or not alike."""
    from symfruit.core.raster import outline_circle

    cam = Camera(fx=500.0, fy=500.0, cx=50.0, cy=50.0, width=100, height=100)
    for r, cut in ((21.5, 0.35), (13.0, 0.3), (40.0, 0.45)):
        region, cracks, free = _straight_cut_disc(r, cut)
        for pts in (cracks[free], cracks[free][::2], cracks[free] * 0.9 + 5.0):
            monkeypatch.delenv("SYMFRUIT_KERNELS", raising=False)
            got = outline_circle(region, cam, pts)
            monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
            twin = outline_circle(region, cam, pts)
            assert (got is None) == (twin is None)
            if got is not None and twin is not None:
                assert got[0].tobytes() == twin[0].tobytes() and got[1].tobytes() == twin[1].tobytes()


@given(
    n=st.integers(2, 300),
    k=st.integers(2, 3),
    seed=st.integers(0, 2**32 - 1),
    scale=st.floats(1e-3, 1e3),
    transposed=st.booleans(),
)
def test_covariance_is_numpys_cov_to_the_bit(n, k, seed, scale, transposed):
    """``_covariance`` (free_side_reach's and axis_tilt's, stop 61) is ``np.cov`` bit for bit, on C-ordered rows and
    on the transpose of C-ordered points (the callers' ``pts.T``), offset far from 0 as pixel coordinates are."""
    from symfruit.core.raster import _covariance

    rng = np.random.default_rng(seed)
    pts = rng.normal(size=(n, k)) * scale + rng.uniform(-500.0, 500.0, size=k)
    m = pts.T if transposed else np.ascontiguousarray(pts.T)
    got, want = _covariance(m), np.cov(m)
    assert got.shape == want.shape == (k, k)
    assert got.tobytes() == want.tobytes()


# --- stop 65, glue65: free_side_reach's 2x2 algebra in closed forms, its free shares as counts; the pixel count once


def _former_free_side_reach(cracks, free, cone, camera, region=None, *, tie_px=1.0):
    """:func:`free_side_reach` before stop 65 (glue65): LAPACK's eigvalsh and solve, ``ok[at].mean() > 0.5``, the
    quadratic form read twice."""
    import math

    from symfruit.core import lapack
    from symfruit.core.raster import _covariance

    pts = np.asarray(cracks, dtype=np.float64)
    ok = np.asarray(free, dtype=bool)
    if len(pts) < 3 or ok.all() or not ok.any():
        return 1.0, None
    inv_k = lapack.inv(camera.matrix)
    conic = inv_k.T @ np.asarray(cone, dtype=np.float64) @ inv_k
    a, b = conic[:2, :2], conic[:2, 2]
    eig = lapack.eigvalsh(a)
    if not np.isfinite(conic).all() or eig[0] <= 0.0:
        return 1.0, None
    centre = -lapack.solve(a, b)
    k = float(centre @ a @ centre - conic[2, 2])
    if not k > 0.0:
        return 1.0, None
    if region is not None:
        cu, cv = round(float(centre[0])) - region.u0, round(float(centre[1])) - region.v0
        h, w = region.mask.shape
        if not (0 <= cu < w and 0 <= cv < h and region.mask[cv, cu]):
            return 1.0, None
    a_inv = lapack.inv(a)
    _, axes = lapack.eigh(_covariance(pts.T))
    stretch = 1.0
    projs = [pts @ e for e in axes.T]
    spans = [(float(proj.min()), float(proj.max())) for proj in projs]
    widest = max(hi - lo for lo, hi in spans)
    ends = []
    for e, proj, (lo, hi) in zip(axes.T, projs, spans, strict=True):
        reach = math.sqrt(k * float(e @ a_inv @ e))
        mid = float(centre @ e)
        at_lo, at_hi = proj <= lo + tie_px, proj >= hi - tie_px
        new_lo = lo if ok[at_lo].mean() > 0.5 else min(lo, mid - reach)
        new_hi = hi if ok[at_hi].mean() > 0.5 else max(hi, mid + reach)
        if hi > lo:
            length = max(min(new_hi - new_lo, widest), hi - lo)
            stretch *= length / (hi - lo)
            grown = (new_hi - new_lo) - (hi - lo)
            keep = (length - (hi - lo)) / grown if grown > 0.0 else 0.0
            conjugate = (a_inv @ e) / float(e @ a_inv @ e)
            for side, target in ((lo, lo - keep * (lo - new_lo)), (hi, hi + keep * (new_hi - hi))):
                if target != side:
                    ends.append(centre + (target - mid) * conjugate)
    stretch = math.sqrt(stretch)
    return stretch, (np.vstack((pts, *ends)) if ends and stretch > 1.0 else None)


def test_free_side_reach_is_the_former_functions_to_the_bit():
    """Stop 65 (docs/glue65.md): the 2x2 eigenvalues and centre by :func:`eigenvalues2` and :func:`solve2`, the free
    share of each extreme as counts (``2 s > n``), the quadratic form ``e^T A^-1 e`` once: the stretch and the outline
    the former function gave, bytes equal, on 400 seeded cut ellipses (oblique, off-centre, fitted too large or too
    small), their outlines' free labels drawn so that ties (exactly half the extreme free) occur."""
    from symfruit.core.raster import Silhouette, free_side_reach, outline_cracks

    rng = np.random.default_rng(65)
    cam = Camera(fx=600.0, fy=610.0, cx=63.3, cy=47.9, width=128, height=96)
    v, u = np.mgrid[:96, :128]
    moved = ties = 0
    for _ in range(400):
        cu, cv = rng.uniform(40.0, 88.0), rng.uniform(35.0, 61.0)
        ra, rb, th = rng.uniform(6.0, 25.0), rng.uniform(6.0, 25.0), rng.uniform(0.0, np.pi)
        c, s = np.cos(th), np.sin(th)
        du, dv = u - cu, v - cv
        mask = ((c * du + s * dv) / ra) ** 2 + ((-s * du + c * dv) / rb) ** 2 <= 1.0
        cut = rng.uniform(-1.0, 1.0, size=2)
        mask &= cut[0] * du + cut[1] * dv <= rng.uniform(0.0, 0.8) * max(ra, rb) * np.hypot(*cut)
        if mask.sum() < 10:
            continue
        region = Silhouette(0, 0, mask, 0.0)
        cracks = outline_cracks(region)
        free = rng.random(len(cracks)) < rng.uniform(0.2, 0.9)
        # the fitted ellipse: the fruit's, grown or shrunk, shifted a little
        grow = rng.uniform(0.7, 1.4)
        r1, r2 = ra * grow, rb * grow * rng.uniform(0.9, 1.1)
        rot = np.array([[c, s], [-s, c]])
        a2 = rot.T @ np.diag([1.0 / r1**2, 1.0 / r2**2]) @ rot
        ctr = np.array([cu, cv]) + rng.normal(scale=1.0, size=2)
        conic = np.block([[a2, (-a2 @ ctr)[:, None]], [(-a2 @ ctr)[None, :], np.array([[ctr @ a2 @ ctr - 1.0]])]])
        cone = cam.matrix.T @ conic @ cam.matrix
        for reg in (region, None):
            got, want = free_side_reach(cracks, free, cone, cam, reg), _former_free_side_reach(cracks, free, cone, cam,
                                                                                             reg)  # fmt: skip
            assert got[0] == want[0]
            assert (got[1] is None) == (want[1] is None)
            if got[1] is not None:
                assert got[1].tobytes() == want[1].tobytes()
                moved += 1
        _, axes = np.linalg.eigh(np.cov(cracks.T))
        for e in axes.T:
            proj = cracks @ e
            for at in (proj <= proj.min() + 1.0, proj >= proj.max() - 1.0):
                ties += 2 * np.count_nonzero(free[at]) == np.count_nonzero(at)
    assert moved > 200 and ties > 20


def test_a_regions_pixels_are_counted_once_and_are_the_masks_count():
    """Stop 65: :func:`pixel_count` is ``np.count_nonzero`` of the mask, kept with the region; :func:`rim_width` of a
    region is its mask's."""
    from symfruit.core.raster import Silhouette, pixel_count
    from symfruit.methods.evidence import rim_width

    rng = np.random.default_rng(7)
    for _ in range(20):
        mask = rng.random((int(rng.integers(1, 60)), int(rng.integers(1, 60)))) < rng.uniform(0.0, 1.0)
        region = Silhouette(3, 4, mask, 0.0)
        assert pixel_count(region) == np.count_nonzero(mask) == region._made["pixels"]
        assert pixel_count(region) is region._made["pixels"]
        for band in (0.15, 0.5, 2.0):
            assert rim_width(region, band) == rim_width(mask, band) == max(2.0, band * np.sqrt(mask.sum() / np.pi))


def test_outline_circle_is_the_same_cone_with_the_kernels_and_the_twins(monkeypatch):
    """Stop 65 (docs/glue65.md): :func:`outline_circle` with its two compiled steps (the points about their mean, the
    mean squared distance from the circle) and with the numpy expressions they replace: the same cone and axis, bytes
    equal, or None alike, on 300 seeded cut discs with noisy outlines (some refused as ragged)."""
    from symfruit.core.raster import Silhouette, outline_circle, outline_cracks

    pytest.importorskip("numba")
    rng = np.random.default_rng(650)
    cam = Camera(fx=600.0, fy=610.0, cx=63.3, cy=47.9, width=128, height=96)
    v, u = np.mgrid[:96, :128]
    found = refused = 0
    for _ in range(300):
        cu, cv, r = rng.uniform(40.0, 88.0), rng.uniform(35.0, 61.0), rng.uniform(8.0, 30.0)
        mask = (u - cu) ** 2 + (v - cv) ** 2 <= r * r
        mask &= u >= cu - r + rng.uniform(0.3, 1.2) * r
        region = Silhouette(0, 0, mask, 0.0)
        cracks = outline_cracks(region)
        free = cracks[:, 0] > cu - r + rng.uniform(0.3, 1.2) * r + 0.6
        pts = cracks[free] + rng.normal(scale=rng.uniform(0.0, 0.6), size=(int(free.sum()), 2))
        got = outline_circle(region, cam, pts)
        monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")
        want = outline_circle(region, cam, pts)
        monkeypatch.delenv("SYMFRUIT_KERNELS")
        assert (got is None) == (want is None)
        if got is None:
            refused += 1
            continue
        found += 1
        assert got[0].tobytes() == want[0].tobytes() and got[1].tobytes() == want[1].tobytes()
    assert found > 100 and refused > 20
