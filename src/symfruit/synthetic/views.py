"""The benchmark's fixed views (:mod:`symfruit.evaluate.bench`): a seeded partial strawberry as the paper saw
it and a depth-camera view of an orange."""

from __future__ import annotations

import numpy as np

from .shapes import paper_visible, rotation_x, strawberry

__all__ = ["bench_camera_view", "bench_view"]


def bench_view(n_points: int = 600, *, seed: int = 0, noise: float = 0.0) -> np.ndarray:
    """A fixed partial view of a conic strawberry (35 mm long) 0.3 m in front of the default camera.

    The berry is tilted 10 degrees about x; the paper's visibility rule keeps the front; ``n_points``
    of the visible surface points are kept, then moved by Gaussian noise of ``noise`` metres (0: a
    clean scan; 0.001: what a D435 gives at 0.3 m). Same ``seed``, same points.

    Returns
    -------
    (n_points, 3) float, metres
    """
    rng = np.random.default_rng(seed)
    fruit = strawberry(rng, shape="conic", length=0.035)
    dense = fruit.sample(max(4 * n_points, 2000), rng) @ rotation_x(10.0).T + [0.0, 0.0, 0.3]
    visible = dense[paper_visible(dense)]
    view = visible[np.sort(rng.choice(len(visible), size=n_points, replace=False))]
    return view + rng.normal(scale=noise, size=view.shape) if noise > 0 else view


def bench_camera_view(n_points: int = 15000, *, seed: int = 0) -> np.ndarray:
    """A fixed depth-camera view of a 75 mm orange with about ``n_points`` points.

    The fruit is rendered by the default camera (640x480, ``fx = fy = 615``) at the distance where its
    silhouette covers about ``n_points`` pixels, one point per pixel, with axial noise of ``0.01 z^2``
    metres (the ``heldback`` sensor of the evaluation). Same ``seed``, same points.

    Returns
    -------
    (n, 3) float, metres, n within a few per cent of ``n_points``
    """
    from ..core.camera import DEFAULT_CAMERA as cam
    from .render import render
    from .shapes import citrus

    rng = np.random.default_rng(seed)
    fruit = citrus(rng, diameter=0.075)
    radius = 0.5 * float(np.ptp(fruit.vertices[:, 0]))
    distance = radius * cam.fx * float(np.sqrt(np.pi / n_points))
    posed = fruit.transformed(rotation_x(20.0), np.array([0.0, 0.0, distance]))
    shot = render([(posed.vertices, posed.faces)], cam)
    rows, cols = np.nonzero(shot.ids == 0)
    z = shot.depth[rows, cols]
    z = z + rng.normal(size=z.shape) * 0.01 * z**2
    return cam.deproject(np.c_[cols, rows].astype(np.float64), z)
