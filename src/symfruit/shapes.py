"""Parametric fruit surfaces for tests, benchmarks and evaluation, in metres, seeded.

A fruit is a closed triangle mesh built by revolving a profile about the y axis (the fruit's long
axis, calyx or stem end at -y, which is "up" in the optical frame), with a slightly elliptic cross
section and a slight bend so it is not an exact solid of revolution. Surface points are sampled
uniformly by area.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Fruit", "paper_visible", "rotation_x", "sample_surface", "strawberry"]


@dataclass(frozen=True)
class Fruit:
    """A closed fruit surface centred on its own box centre.

    Attributes
    ----------
    vertices : (v, 3) float, metres
    faces : (f, 3) int
    kind : str
    """

    vertices: np.ndarray
    faces: np.ndarray
    kind: str

    def sample(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """(n, 3) float: ``n`` points uniformly distributed over the surface."""
        return sample_surface(self.vertices, self.faces, n, rng)


def _revolve(
    radius: np.ndarray, axial: np.ndarray, n_phi: int, squash: float, bend: float
) -> tuple[np.ndarray, np.ndarray]:
    """Mesh of a profile ``radius(t), axial(t)`` (t from pole to pole, radius 0 at both ends)."""
    phi = np.linspace(0.0, 2.0 * np.pi, n_phi, endpoint=False)
    ring_r = radius[1:-1, None]
    ring_y = axial[1:-1, None]
    x = ring_r * np.cos(phi)[None, :] * squash
    z = ring_r * np.sin(phi)[None, :] / squash
    y = np.broadcast_to(ring_y, x.shape)
    span = axial[-1] - axial[0]
    x = x + bend * span * ((ring_y - axial[0]) / span) ** 2
    rings = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    top = np.array([[bend * 0.0, axial[0], 0.0]])
    bottom = np.array([[bend * span, axial[-1], 0.0]])
    vertices = np.vstack([top, rings, bottom])
    n_rings = len(radius) - 2
    faces = []
    j = np.arange(n_phi)
    jn = (j + 1) % n_phi
    faces.append(np.stack([np.zeros(n_phi, int), 1 + jn, 1 + j], axis=1))
    for i in range(n_rings - 1):
        a, b = 1 + i * n_phi, 1 + (i + 1) * n_phi
        faces.append(np.stack([a + j, a + jn, b + j], axis=1))
        faces.append(np.stack([a + jn, b + jn, b + j], axis=1))
    last = 1 + (n_rings - 1) * n_phi
    faces.append(np.stack([last + j, last + jn, np.full(n_phi, len(vertices) - 1)], axis=1))
    return vertices, np.vstack(faces)


def sample_surface(vertices: np.ndarray, faces: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
    """Sample ``n`` points uniformly by area on a triangle mesh; (n, 3) float."""
    tri = vertices[faces]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    pick = rng.choice(len(faces), size=n, p=area / area.sum())
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    t = tri[pick]
    return t[:, 0] + u[:, None] * (t[:, 1] - t[:, 0]) + v[:, None] * (t[:, 2] - t[:, 0])


#: Profile exponents (shoulder, tip) and width/length ratio range per strawberry shape class.
STRAWBERRY_CLASSES = {
    "conic": (0.40, 0.85, (0.80, 0.95)),
    "long-conic": (0.35, 1.00, (0.65, 0.80)),
    "globose": (0.55, 0.60, (0.95, 1.10)),
    "wedge": (0.25, 1.10, (0.85, 1.00)),
}


def strawberry(rng: np.random.Generator, *, shape: str | None = None, length: float | None = None) -> Fruit:
    """A strawberry-like surface: flattened calyx end with a shallow dimple, tapering to the tip.

    Parameters
    ----------
    rng : numpy.random.Generator
    shape : {"conic", "long-conic", "globose", "wedge"}, optional
        Shape class; random when None.
    length : float, metres, optional
        Calyx-to-tip length; uniform in 25-50 mm when None.
    """
    if shape is None:
        shape = str(rng.choice(list(STRAWBERRY_CLASSES)))
    alpha, beta, ratio_range = STRAWBERRY_CLASSES[shape]
    length = float(rng.uniform(0.025, 0.050)) if length is None else float(length)
    width = length * rng.uniform(*ratio_range)
    t = np.linspace(0.0, 1.0, 64)
    f = t**alpha * (1.0 - t) ** beta
    f /= f.max()
    radius = 0.5 * width * f
    # Flattened calyx end with a shallow dimple: pull the axial position of the first rings inward.
    dimple = 0.06 * length * np.exp(-((t / 0.08) ** 2))
    axial = t * length + dimple
    axial[0] = dimple[0] * 0.6
    vertices, faces = _revolve(
        radius, axial, 48, squash=rng.uniform(0.95, 1.05), bend=rng.uniform(-0.06, 0.06)
    )
    centre = (vertices.min(axis=0) + vertices.max(axis=0)) / 2.0
    return Fruit(vertices=vertices - centre, faces=faces, kind=f"strawberry/{shape}")


def rotation_x(degrees: float) -> np.ndarray:
    """(3, 3) rotation about the camera x axis."""
    a = np.radians(degrees)
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def paper_visible(points: np.ndarray) -> np.ndarray:
    """The paper's visibility rule (section 4.1, Fig. 6b): boolean mask of the visible points.

    The plane through the lowest- and highest-y points that contains the x direction splits the
    cloud; the part on the camera's side (smaller z) is visible.
    """
    lo, hi = points[np.argmin(points[:, 1])], points[np.argmax(points[:, 1])]
    normal = np.cross(hi - lo, [1.0, 0.0, 0.0])
    if normal[2] > 0:
        normal = -normal
    return (points - lo) @ normal > 0
