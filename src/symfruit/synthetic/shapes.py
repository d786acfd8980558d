"""Parametric fruit surfaces for tests, benchmarks, scenes and evaluation: metres, seeded.

A fruit is a closed triangle mesh made by revolving a profile about the y axis (the fruit's long
axis; the stem or calyx end at -y, which is "up" in the optical frame), then made imperfect: an
elliptic cross-section, a lopsided bulge, a slight bend, and per-kind detail (a strawberry's dimpled
calyx end, an apple's stem cavity and calyx basin, a tomato's shoulders and ribs). Every fruit is
centred on the centre of its own box. Surface points are sampled uniformly by area.

=========== ===================== ===============================================================
kind        size                  shape
=========== ===================== ===============================================================
strawberry  length 25-50 mm       classes conic, long-conic, globose, wedge (heart); width/length
                                  0.65-1.1; flattened calyx end with a shallow dimple; pointed or
                                  blunt tip
apple       diameter 60-90 mm     height/diameter 0.8-0.95, stem cavity, calyx basin, lopsided
citrus      diameter 60-90 mm     near-spherical, height/diameter 0.88-0.98
tomato      diameter 40-80 mm     oblate (height/diameter 0.65-0.85), shoulders, shallow ribs
pear        length 55-125 mm      two bulbs (neck and body, radius ratio 0.45-0.8) blended by a
                                  p-norm (a smooth waist); leaning, lopsided, elliptic cross-section
lemon       length 55-100 mm      prolate, width/length 0.65-0.85, pointed ends with nipples
peach       diameter 50-90 mm     near-spherical, suture groove, one fuller cheek, stem cavity,
                                  slight tip
plum        length 30-70 mm       oval (width/length 0.78-0.95), shallow suture, flattened sides
banana      length 100-200 mm     curved (sagitta 8-22 % of the length), five-sided, tapered ends:
                                  a fruit no plane mirrors and no closed shape fits
lopsided    diameter 35-130 mm    a generic asymmetric fruit: one side swollen, the axis bent
                                  (mango- or kidney-like)
=========== ===================== ===============================================================

The four original kinds are near-symmetric solids of revolution with a small lean; the other six make
sure a method cannot win only on near-spherical shapes (the real pear of the YCB set, for one, is tilted
and lopsided).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import FileFormatError, SymfruitError

__all__ = [
    "FRUITS",
    "STRAWBERRY_CLASSES",
    "Fruit",
    "apple",
    "banana",
    "citrus",
    "leaf_outline",
    "lemon",
    "load_scans",
    "lopsided",
    "make_fruit",
    "paper_visible",
    "peach",
    "pear",
    "plum",
    "rotation",
    "rotation_x",
    "sample_surface",
    "strawberry",
    "tomato",
]


@dataclass(frozen=True)
class Fruit:
    """A closed fruit surface centred on its own box centre.

    Attributes
    ----------
    vertices : (v, 3) float, metres
    faces : (f, 3) int
    kind : str
        e.g. ``"strawberry/conic"``, ``"apple"``, ``"scan/berry_01"``.
    points : (p, 3) float, optional
        The measured points of a scan that came without a mesh: samples are drawn from these, and
        the mesh is their convex hull (used only to render the scan).
    """

    vertices: np.ndarray
    faces: np.ndarray
    kind: str
    points: np.ndarray | None = None

    def sample(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """(n, 3) float: ``n`` points uniformly distributed over the surface."""
        if self.points is not None:
            return self.points[rng.choice(len(self.points), size=n, replace=n > len(self.points))]
        return sample_surface(self.vertices, self.faces, n, rng)

    def transformed(self, rotation_matrix: np.ndarray, translation: np.ndarray) -> Fruit:
        """The fruit rotated about its centre, then moved by ``translation`` (metres)."""
        pts = None if self.points is None else self.points @ rotation_matrix.T + translation
        return Fruit(self.vertices @ rotation_matrix.T + translation, self.faces, self.kind, pts)


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


def _revolve(
    radius: np.ndarray,
    axial: np.ndarray,
    *,
    n_phi: int = 64,
    squash: float = 1.0,
    bend: float = 0.0,
    lopsided: float = 0.0,
    lopsided_phase: float = 0.0,
    ribs: tuple[int, float] = (0, 0.0),
    lopsided_mid: bool = False,
    groove: tuple[float, float, float] = (0.0, 0.3, 0.0),
    arc: float = 0.0,
    name: str,
) -> Fruit:
    """Closed mesh of the profile ``radius(t), axial(t)`` (t from the top pole to the bottom pole).

    ``squash`` makes the cross-section elliptic (x scaled by it, z by its inverse), ``lopsided``
    swells one side (``1 + lopsided * cos(phi - phase)``; with ``lopsided_mid`` the swelling grows from
    nothing at the poles to its full size at mid-height, ``sin(pi s)``), ``ribs = (count, depth)`` adds
    ribs, ``groove = (depth, width, phase)`` a suture (ring radius times ``1 - depth exp(-(dphi /
    width)^2)`` around ``phi = phase``), ``bend`` curves the axis sideways by ``bend`` times the length at
    the bottom pole, and ``arc`` (1/metres) bends the whole fruit along a circle in the x-y plane, keeping
    cross-sections perpendicular to the bent axis (a banana).
    """
    phi = np.linspace(0.0, 2.0 * np.pi, n_phi, endpoint=False)
    count, depth = ribs
    span = axial[-1] - axial[0]
    s = (axial - axial[0]) / span
    if lopsided_mid:
        scale = (1.0 + depth * np.cos(count * phi))[None, :] + lopsided * np.sin(np.pi * s)[1:-1, None] * np.cos(
            phi - lopsided_phase
        )[None, :]
    else:
        scale = (1.0 + lopsided * np.cos(phi - lopsided_phase) + depth * np.cos(count * phi))[None, :]
    g_depth, g_width, g_phase = groove
    if g_depth:
        dphi = np.angle(np.exp(1j * (phi - g_phase)))
        scale = scale - g_depth * np.exp(-((dphi / g_width) ** 2))[None, :]
    ring_r = radius[1:-1, None] * scale
    ring_y = np.broadcast_to(axial[1:-1, None], ring_r.shape)
    shift = bend * span * s**2
    x = ring_r * np.cos(phi)[None, :] * squash + shift[1:-1, None]
    z = ring_r * np.sin(phi)[None, :] / squash
    rings = np.stack([x, ring_y, z], axis=-1).reshape(-1, 3)
    top = np.array([[shift[0], axial[0], 0.0]])
    bottom = np.array([[shift[-1], axial[-1], 0.0]])
    vertices = np.vstack([top, rings, bottom])
    if arc:
        mid, bend_radius = 0.5 * (axial[0] + axial[-1]), 1.0 / arc
        theta = (vertices[:, 1] - mid) / bend_radius
        dist = bend_radius - vertices[:, 0]
        vertices = np.c_[bend_radius - dist * np.cos(theta), mid + dist * np.sin(theta), vertices[:, 2]]
    n_rings = len(radius) - 2
    j = np.arange(n_phi)
    jn = (j + 1) % n_phi
    faces = [np.stack([np.zeros(n_phi, int), 1 + jn, 1 + j], axis=1)]
    a = 1 + np.arange(n_rings - 1)[:, None] * n_phi
    b = a + n_phi
    faces.append(np.stack([a + j, a + jn, b + j], axis=-1).reshape(-1, 3))
    faces.append(np.stack([a + jn, b + jn, b + j], axis=-1).reshape(-1, 3))
    last = 1 + (n_rings - 1) * n_phi
    faces.append(np.stack([last + j, last + jn, np.full(n_phi, len(vertices) - 1)], axis=1))
    centre = (vertices.min(axis=0) + vertices.max(axis=0)) / 2.0
    return Fruit(vertices=vertices - centre, faces=np.vstack(faces), kind=name)


#: Strawberry classes: (shoulder exponent, tip exponent range, width/length range, cross-section squash).
STRAWBERRY_CLASSES: dict[str, tuple[float, tuple[float, float], tuple[float, float], tuple[float, float]]] = {
    "conic": (0.40, (0.75, 1.0), (0.80, 0.95), (0.95, 1.05)),
    "long-conic": (0.35, (0.9, 1.15), (0.65, 0.80), (0.95, 1.05)),
    "globose": (0.55, (0.45, 0.65), (0.95, 1.10), (0.95, 1.05)),
    "wedge": (0.25, (0.9, 1.2), (0.85, 1.00), (0.82, 0.92)),
}


def strawberry(rng: np.random.Generator, *, shape: str | None = None, length: float | None = None) -> Fruit:
    """A strawberry: flattened calyx end (top, -y) with a shallow dimple, tapering to the tip.

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
    if shape not in STRAWBERRY_CLASSES:
        raise ValueError(f"unknown strawberry class {shape!r}; known: {', '.join(STRAWBERRY_CLASSES)}")
    alpha, beta_range, ratio_range, squash_range = STRAWBERRY_CLASSES[shape]
    length = float(rng.uniform(0.025, 0.050)) if length is None else float(length)
    width = length * rng.uniform(*ratio_range)
    beta = rng.uniform(*beta_range)  # < 0.7: blunt tip, > 0.9: pointed
    t = np.linspace(0.0, 1.0, 72)
    f = t**alpha * (1.0 - t) ** beta
    f /= f.max()
    radius = 0.5 * width * f
    # Flattened calyx end with a shallow dimple: pull the first rings' axial position inward.
    dimple = rng.uniform(0.03, 0.07) * length * np.exp(-((t / 0.09) ** 2))
    axial = t * length + dimple
    return _revolve(
        radius, axial, squash=rng.uniform(*squash_range), bend=rng.uniform(-0.06, 0.06),
        lopsided=rng.uniform(0.0, 0.05), lopsided_phase=rng.uniform(0, 2 * np.pi),
        name=f"strawberry/{shape}",
    )  # fmt: skip


def _pome(
    rng: np.random.Generator,
    *,
    diameter: float,
    height_ratio: float,
    top_cavity: float,
    top_width: float,
    bottom_cavity: float,
    bottom_width: float,
    shoulder: float,
    ribs: tuple[int, float],
    lopsided: float,
    name: str,
) -> Fruit:
    """A round fruit: ellipse profile, cavities at the poles, optional shoulders."""
    theta = np.linspace(0.0, np.pi, 80)
    a, b = diameter / 2.0, diameter * height_ratio / 2.0
    radius = a * np.sin(theta) * (1.0 + shoulder * np.sin(theta) * np.cos(theta))
    axial = -b * np.cos(theta)
    axial = axial + top_cavity * diameter * np.exp(-((theta / top_width) ** 2))
    axial = axial - bottom_cavity * diameter * np.exp(-(((np.pi - theta) / bottom_width) ** 2))
    return _revolve(
        radius, axial, squash=rng.uniform(0.97, 1.03), bend=rng.uniform(-0.02, 0.02),
        lopsided=lopsided, lopsided_phase=rng.uniform(0, 2 * np.pi), ribs=ribs, name=name,
    )  # fmt: skip


def apple(rng: np.random.Generator, *, diameter: float | None = None) -> Fruit:
    """An apple, 60-90 mm: slightly oblate and lopsided, with a stem cavity and a calyx basin."""
    return _pome(
        rng,
        diameter=rng.uniform(0.060, 0.090) if diameter is None else diameter,
        height_ratio=rng.uniform(0.80, 0.95),
        top_cavity=rng.uniform(0.08, 0.14), top_width=0.35,
        bottom_cavity=rng.uniform(0.04, 0.08), bottom_width=0.3,
        shoulder=rng.uniform(0.0, 0.12), ribs=(5, rng.uniform(0.0, 0.015)),
        lopsided=rng.uniform(0.02, 0.06), name="apple",
    )  # fmt: skip


def citrus(rng: np.random.Generator, *, diameter: float | None = None) -> Fruit:
    """An orange, 60-90 mm: near-spherical, slightly oblate."""
    return _pome(
        rng,
        diameter=rng.uniform(0.060, 0.090) if diameter is None else diameter,
        height_ratio=rng.uniform(0.88, 0.98),
        top_cavity=rng.uniform(0.0, 0.02), top_width=0.2,
        bottom_cavity=rng.uniform(0.0, 0.015), bottom_width=0.2,
        shoulder=0.0, ribs=(0, 0.0), lopsided=rng.uniform(0.0, 0.02), name="citrus",
    )  # fmt: skip


def tomato(rng: np.random.Generator, *, diameter: float | None = None) -> Fruit:
    """A tomato, 40-80 mm: oblate, with shoulders by the stem and shallow ribs."""
    return _pome(
        rng,
        diameter=rng.uniform(0.040, 0.080) if diameter is None else diameter,
        height_ratio=rng.uniform(0.65, 0.85),
        top_cavity=rng.uniform(0.03, 0.07), top_width=0.3,
        bottom_cavity=rng.uniform(0.0, 0.02), bottom_width=0.25,
        shoulder=rng.uniform(0.05, 0.15), ribs=(int(rng.integers(4, 8)), rng.uniform(0.01, 0.03)),
        lopsided=rng.uniform(0.0, 0.04), name="tomato",
    )  # fmt: skip


def _two_bulbs(r_top: float, r_bottom: float, gap: float, p: float, n: int = 96) -> tuple[np.ndarray, np.ndarray]:
    """Profile ``(radius, axial)`` of two spheres (radii ``r_top``, ``r_bottom``, centres ``gap`` apart on the
    axis) joined by the p-norm of their ring radii: a smooth waist, round poles."""
    y0, y1 = -r_top, gap + r_bottom
    t = 0.5 - 0.5 * np.cos(np.linspace(0.0, np.pi, n))  # samples clustered at the poles
    y = y0 + (y1 - y0) * t
    ra = np.sqrt(np.clip(r_top**2 - y**2, 0.0, None))
    rb = np.sqrt(np.clip(r_bottom**2 - (y - gap) ** 2, 0.0, None))
    r = (ra**p + rb**p) ** (1.0 / p)
    r[0] = r[-1] = 0.0
    return r, y


def _round(diameter: float, height_ratio: float, cavity: float, tip: float) -> tuple[np.ndarray, np.ndarray]:
    """Profile ``(radius, axial)`` of an ellipse with a stem cavity at the top pole and a tip at the bottom."""
    theta = np.linspace(0.0, np.pi, 90)
    a, b = diameter / 2.0, diameter * height_ratio / 2.0
    r = a * np.sin(theta)
    y = -b * np.cos(theta)
    y += cavity * diameter * np.exp(-((theta / 0.35) ** 2))
    y += tip * diameter * np.exp(-(((np.pi - theta) / 0.25) ** 2))
    r[0] = r[-1] = 0.0
    return r, y


def pear(rng: np.random.Generator) -> Fruit:
    """A pear, 55-125 mm long: a narrow neck bulb and a wide body bulb, leaning and lopsided."""
    r_body = rng.uniform(0.024, 0.040)
    r_neck = r_body * rng.uniform(0.45, 0.8)
    gap = r_body * rng.uniform(0.7, 1.4)
    r, y = _two_bulbs(r_neck, r_body, gap, rng.uniform(1.8, 3.5))
    return _revolve(
        r, y, name="pear", n_phi=72, squash=rng.uniform(0.93, 1.07), bend=rng.uniform(-0.12, 0.12),
        lopsided=rng.uniform(0.0, 0.08), lopsided_phase=rng.uniform(0, 2 * np.pi), lopsided_mid=True,
    )  # fmt: skip


def lemon(rng: np.random.Generator) -> Fruit:
    """A lemon, 55-100 mm long (nipples included): prolate, pointed ends, a nipple at one or both poles."""
    length = rng.uniform(0.055, 0.085)
    width = length * rng.uniform(0.65, 0.85)
    u = -np.cos(np.linspace(0.0, np.pi, 96))  # -1 .. 1 along the axis, clustered at the poles
    r = 0.5 * width * (1.0 - u**2) ** rng.uniform(0.5, 0.75)  # exponent > 0.5: pointed ends
    nipple_top, nipple_bottom = rng.uniform(0.0, 0.08), rng.uniform(0.03, 0.12)
    y = 0.5 * length * u
    y -= nipple_top * length * np.exp(-(((u + 1.0) / 0.12) ** 2))
    y += nipple_bottom * length * np.exp(-(((1.0 - u) / 0.12) ** 2))
    return _revolve(
        r, y, name="lemon", n_phi=72, squash=rng.uniform(0.95, 1.05), bend=rng.uniform(-0.05, 0.05),
        lopsided=rng.uniform(0.0, 0.05), lopsided_phase=rng.uniform(0, 2 * np.pi), lopsided_mid=True,
    )  # fmt: skip


def peach(rng: np.random.Generator) -> Fruit:
    """A peach, 50-90 mm across: near-spherical, a suture groove, one fuller cheek, a stem cavity, a slight tip."""
    d = rng.uniform(0.055, 0.080)
    r, y = _round(d, rng.uniform(0.88, 1.05), rng.uniform(0.04, 0.09), rng.uniform(0.0, 0.04))
    phase = rng.uniform(0, 2 * np.pi)
    return _revolve(
        r, y, name="peach", n_phi=72, squash=rng.uniform(0.92, 1.04), bend=rng.uniform(-0.04, 0.04),
        lopsided=rng.uniform(0.02, 0.07), lopsided_phase=phase + np.pi / 2, lopsided_mid=True,
        groove=(rng.uniform(0.03, 0.08), rng.uniform(0.12, 0.3), phase),
    )  # fmt: skip


def plum(rng: np.random.Generator) -> Fruit:
    """A plum, 30-70 mm long: oval, flattened across the suture, a shallow groove."""
    length = rng.uniform(0.035, 0.060)
    r, y = _round(length * rng.uniform(0.78, 0.95), rng.uniform(1.05, 1.28), rng.uniform(0.02, 0.05),
                  rng.uniform(0.0, 0.03))  # fmt: skip
    phase = rng.uniform(0, 2 * np.pi)
    return _revolve(
        r, y, name="plum", n_phi=72, squash=rng.uniform(0.85, 0.97), bend=rng.uniform(-0.06, 0.06),
        lopsided=rng.uniform(0.0, 0.05), lopsided_phase=phase + np.pi / 2, lopsided_mid=True,
        groove=(rng.uniform(0.015, 0.05), rng.uniform(0.12, 0.3), phase),
    )  # fmt: skip


def banana(rng: np.random.Generator) -> Fruit:
    """A banana, 120-200 mm along its curve (100-200 mm end to end): tapered, five-sided, bent (no plane
    mirrors it)."""
    length = rng.uniform(0.12, 0.20)
    radius = length * rng.uniform(0.09, 0.12)
    t = 0.5 - 0.5 * np.cos(np.linspace(0.0, np.pi, 96))
    r = radius * np.sin(np.pi * t) ** rng.uniform(0.3, 0.5) * (1.0 - 0.35 * t**3)
    r[0] = r[-1] = 0.0
    sagitta = length * rng.uniform(0.08, 0.22)
    return _revolve(
        r, t * length, name="banana", n_phi=72, squash=rng.uniform(0.9, 1.1), ribs=(5, rng.uniform(0.02, 0.05)),
        arc=8.0 * sagitta / length**2 * rng.choice([-1.0, 1.0]),
    )  # fmt: skip


def lopsided(rng: np.random.Generator) -> Fruit:
    """A generic asymmetric fruit, 35-130 mm across (40-90 mm before its swelling): an egg whose one side is
    swollen and whose axis is bent (mango- or kidney-like)."""
    r_body = rng.uniform(0.040, 0.090) / 2.0
    r_top = r_body * rng.uniform(0.6, 1.0)
    r, y = _two_bulbs(r_top, r_body, r_body * rng.uniform(0.2, 0.8), rng.uniform(2.0, 4.0))
    return _revolve(
        r, y, name="lopsided", n_phi=72, squash=rng.uniform(0.85, 1.15), bend=rng.uniform(-0.2, 0.2),
        lopsided=rng.uniform(0.06, 0.15), lopsided_phase=rng.uniform(0, 2 * np.pi), lopsided_mid=True,
    )  # fmt: skip


#: Fruit generators by kind: ``FRUITS[kind](rng) -> Fruit``; the first four are the original kinds (with
#: fruit profiles), the others widen the evaluation to elongated, grooved, asymmetric and curved fruit.
FRUITS: dict[str, Callable[[np.random.Generator], Fruit]] = {
    "strawberry": strawberry,
    "apple": apple,
    "citrus": citrus,
    "tomato": tomato,
    "pear": pear,
    "lemon": lemon,
    "peach": peach,
    "plum": plum,
    "banana": banana,
    "lopsided": lopsided,
}


def make_fruit(kind: str, rng: np.random.Generator) -> Fruit:
    """A random fruit of ``kind`` (a key of :data:`FRUITS`)."""
    try:
        return FRUITS[kind](rng)
    except KeyError:
        raise ValueError(f"unknown fruit kind {kind!r}; known: {', '.join(FRUITS)}") from None


def load_scans(folder: str | Path, *, failed: dict[str, str] | None = None) -> list[Fruit]:
    """Load complete fruit scans from a folder as an evaluation set.

    Every ``.ply``, ``.pcd``, ``.xyz``, ``.txt``, ``.csv``, ``.npy`` (point clouds) and ``.obj`` or
    meshed ``.ply`` (triangle meshes) file is one fruit, in metres, in any pose: each is centred on
    its box centre. Files are taken in name order. A cloud without faces is rendered (``camera``
    protocol) through its convex hull, which suits fruit, being nearly convex; its own points are
    what is sampled (``paper`` protocol) and what the truth is measured on.

    ``failed``: when given, a scan that cannot be read (a broken file, too few points, flat) is left out and
    recorded there (its path: the reason), and the others are loaded; without it the first bad scan is raised.

    Raises
    ------
    FileFormatError
        When the folder is missing or holds no readable scan; a bad file names itself.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise FileFormatError(f"{folder}: no such folder of fruit scans")
    fruits = []
    for path in sorted(folder.iterdir()):
        suffix = path.suffix.lower()
        if suffix not in (".ply", ".pcd", ".xyz", ".txt", ".csv", ".npy", ".obj"):
            continue
        try:
            fruits.append(_load_scan(path, suffix))
        except SymfruitError as exc:
            if failed is None:
                raise
            failed[str(path)] = str(exc)
    if not fruits:
        bad = f"; {len(failed)} not readable, the first: {next(iter(failed.values()))}" if failed else ""
        raise FileFormatError(f"{folder}: no fruit scans found (.ply, .pcd, .xyz, .txt, .csv, .npy, .obj){bad}")
    return fruits


#: The sizes of a complete fruit scan (m, its box's longest side): a scan in millimetres, or of nothing, is refused.
MIN_SCAN_M, MAX_SCAN_M = 0.001, 2.0


def _area(vertices: np.ndarray, faces: np.ndarray) -> float:
    """The total area (m^2) of a triangle mesh's faces."""
    tri = vertices[faces]
    return float(0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).sum())


def _load_scan(path: Path, suffix: str) -> Fruit:
    """One scan of :func:`load_scans`, centred on its box centre; a bad one raises naming ``path``."""
    from ..io import read_cloud, read_mesh

    vertices, faces = read_mesh(path) if suffix in (".obj", ".ply") else (read_cloud(path), None)
    if len(vertices) < 100:
        raise FileFormatError(f"{path}: a complete scan needs at least 100 points, got {len(vertices)}")
    across = float((vertices.max(axis=0) - vertices.min(axis=0)).max())
    if not MIN_SCAN_M <= across <= MAX_SCAN_M:  # 1e30 m was taken; a scan in millimetres made fruit of metres
        raise FileFormatError(f"{path}: the scan is {across:.3g} m across; fruit scans are in metres, "
                              f"{MIN_SCAN_M:g}-{MAX_SCAN_M:g} m across (millimetres, or no fruit?)")  # fmt: skip
    if faces is not None and len(faces) and not _area(vertices, faces) > 0:
        # every face a point or a line: sampling it was numpy's "Probabilities contain NaN" (robust51)
        raise FileFormatError(f"{path}: the mesh's {len(faces):,} faces have no area (each a point or a line)")
    centre = (vertices.min(axis=0) + vertices.max(axis=0)) / 2.0
    vertices = vertices - centre
    kind = f"scan/{path.stem}"
    if faces is None or len(faces) == 0:
        from scipy.spatial import ConvexHull, QhullError

        try:
            hull = ConvexHull(vertices)
        except QhullError:
            raise FileFormatError(f"{path}: the scan's points are flat or degenerate") from None
        return Fruit(vertices, hull.simplices.astype(np.int64), kind, points=vertices)
    return Fruit(vertices, faces, kind)


def rotation_x(degrees: float) -> np.ndarray:
    """(3, 3) rotation about the camera x axis."""
    a = np.radians(degrees)
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rotation(rx: float, ry: float, rz: float) -> np.ndarray:
    """(3, 3) rotation ``R_z(rz) @ R_y(ry) @ R_x(rx)``, angles in degrees."""
    x, y, z = np.radians([rx, ry, rz])
    rot_y = np.array([[np.cos(y), 0.0, np.sin(y)], [0.0, 1.0, 0.0], [-np.sin(y), 0.0, np.cos(y)]])
    rot_z = np.array([[np.cos(z), -np.sin(z), 0.0], [np.sin(z), np.cos(z), 0.0], [0.0, 0.0, 1.0]])
    return rot_z @ rot_y @ rotation_x(np.degrees(x))


def leaf_outline(length: float, width: float, n: int = 40) -> np.ndarray:
    """(n, 3) float: a flat, pointed-oval leaf outline in the x-y plane, centred on the origin."""
    t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return np.c_[length / 2 * np.cos(t), width / 2 * np.sin(t) * np.abs(np.sin(t)) ** 0.3, np.zeros_like(t)]


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
