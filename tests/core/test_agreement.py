"""How well a closed shape explains a view: rays, silhouette bands, ray marching, the evidence measures."""

import numpy as np
import pytest

from symfruit.core.agreement import explain, march, observe
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


def _whole_ball(camera):
    visible, _ = rendered_view(ball_mesh(), [0.0, 0.0, 0.4], noise=0.01, seed=2)
    return visible[::10], silhouette(visible, camera), camera
