"""Symmetry planes: the paper's hypotheses (section 3.3) and mirroring (section 3.4)."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .points import as_points

__all__ = ["PAPER_GRID", "Plane", "PlaneGrid", "Planes", "hypothesis_planes", "mirror", "mirror_xyz"]


@dataclass(frozen=True)
class Plane:
    """A plane ``{p : normal . (p - point) = 0}`` (paper Eq. 1).

    Attributes
    ----------
    point : (3,) float, metres
    normal : (3,) float, unit length
        A normal of another length is divided by its length (the same plane); a zero one is refused.
    """

    point: np.ndarray
    normal: np.ndarray

    def __post_init__(self) -> None:  # one Plane per completion (the chosen one); the hypotheses are Planes
        for name in ("point", "normal"):
            try:
                value = np.asarray(getattr(self, name), dtype=np.float64)
            except (TypeError, ValueError):
                raise InputError(f"plane {name} must be 3 numbers, got {getattr(self, name)!r}") from None
            if value.shape != (3,) or not np.isfinite(value).all():
                raise InputError(f"plane {name} must be 3 finite numbers, got {value.tolist()}")
            object.__setattr__(self, name, value)  # lists kept as lists had no to_dict (AttributeError 'tolist')
        normal = self.normal
        if not np.any(normal):
            raise InputError("plane normal must not be zero: it has no direction")
        length2 = sum(x * x for x in normal.tolist())  # Python floats: 1e300 squared is inf, no warning
        if abs(length2 - 1.0) > 1e-9:  # unit as documented: readers of to_dict() take it as one
            normal = normal / np.abs(normal).max()  # scaled first: 1e-300 or 1e300 would under/overflow the norm
            object.__setattr__(self, "normal", normal / np.sqrt(normal @ normal))

    def to_dict(self) -> dict[str, list[float]]:
        return {"point": self.point.tolist(), "normal": self.normal.tolist()}


@dataclass(frozen=True)
class Planes:
    """A batch of ``h`` planes with the parameters that made them.

    Attributes
    ----------
    points : (h, 3) float, metres
    normals : (h, 3) float, unit length
    offsets : (h,) float, metres
        Translation of the plane point along +z from the centroid.
    angles_x, angles_y : (h,) float, degrees
        Rotations of the normal about x, then about y.
    """

    points: np.ndarray
    normals: np.ndarray
    offsets: np.ndarray
    angles_x: np.ndarray
    angles_y: np.ndarray

    def __len__(self) -> int:
        return len(self.normals)

    def __getitem__(self, index: int) -> Plane:
        return Plane(point=self.points[index].copy(), normal=self.normals[index].copy())


@dataclass(frozen=True)
class PlaneGrid:
    """The paper's grid of ``m * j * k`` symmetry-plane hypotheses (section 3.2; paper: 4, 0.2, 0, 11, 5, 3, 5).

    Attributes
    ----------
    translations : int
        ``m``, steps of the plane along +z.
    translation_step : float
        One step, as a share of the points' z extent.
    translation_first : float
        Offset of the first translation, in steps.
    rotations_x, rotations_y : int
        ``j`` and ``k``, angles about x and y centred on zero: ``(i - (j - 1) / 2) * step``.
    rotation_x_step, rotation_y_step : float, degrees
    """

    translations: int = 4
    translation_step: float = 0.2
    translation_first: float = 0.0
    rotations_x: int = 11
    rotation_x_step: float = 5.0
    rotations_y: int = 3
    rotation_y_step: float = 5.0

    def __len__(self) -> int:
        return self.translations * self.rotations_x * self.rotations_y


#: The paper's grid (4, 0.2, 0, 11, 5, 3, 5): 132 planes.
PAPER_GRID = PlaneGrid()


def _centred(count: int, step: float) -> np.ndarray:
    return (np.arange(count) - (count - 1) / 2.0) * step


def hypothesis_planes(points: np.ndarray, grid: PlaneGrid = PAPER_GRID) -> Planes:
    """Generate the paper's ``m * j * k`` symmetry-plane hypotheses.

    The initial plane (section 3.2) passes through the centroid of ``points`` with normal +z. Its point
    is moved along +z by ``(translation_first + i) * translation_step * len_depth`` for ``i < m``
    (``len_depth`` is the z extent of the points), and its normal is rotated
    ``n = R_y(b) @ R_x(a) @ (0, 0, 1)`` by angles centred on zero. The paper's Eq. 3 prints a
    rotation about z, which would leave the +z normal unchanged; it is read as the typo it is.

    Parameters
    ----------
    points : (n, 3) float, metres
        Visible points in the camera frame.
    grid : PlaneGrid
        ``m`` (``translations``), ``translation_step``, ``translation_first``, ``j``, ``k`` and the steps.

    Returns
    -------
    Planes
        Ordered translation-major, then angle about x, then angle about y.
    """
    points = as_points(points, min_count=1)
    centroid = points.mean(axis=0)
    z = points[:, 2]
    len_depth = float(z.max() - z.min())
    steps, a, b, normals = _grid(grid)
    off = steps * (grid.translation_step * len_depth)
    plane_points = np.empty((len(off), 3))
    plane_points[:] = centroid
    plane_points[:, 2] += off
    return Planes(points=plane_points, normals=normals.copy(), offsets=off, angles_x=a, angles_y=b)


@functools.lru_cache(maxsize=64)
def _grid(grid: PlaneGrid) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Translation steps, angles and normals of a hypothesis grid (cached: they depend on settings only)."""
    steps = grid.translation_first + np.arange(grid.translations, dtype=np.float64)
    ax = _centred(grid.rotations_x, grid.rotation_x_step)
    ay = _centred(grid.rotations_y, grid.rotation_y_step)
    off, a, b = (g.ravel() for g in np.meshgrid(steps, ax, ay, indexing="ij"))
    ar, br = np.radians(a), np.radians(b)
    normals = np.stack([np.cos(ar) * np.sin(br), -np.sin(ar), np.cos(ar) * np.cos(br)], axis=1)
    for arr in (off, a, b, normals):
        arr.flags.writeable = False
    return off, a, b, normals


def mirror_xyz(
    points: np.ndarray, plane_points: np.ndarray, normals: np.ndarray, *, dtype: type = np.float64
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mirror every point through every plane; the coordinates as three contiguous ``(h, n)`` arrays.

    The hot path of the ``paper`` method: one ``(h, 3) @ (3, n)`` product and three fused updates,
    no ``(h, n, 3)`` temporaries. See :func:`mirror` for the maths.
    """
    q = np.atleast_2d(np.asarray(plane_points, dtype=np.float64))
    n = np.atleast_2d(np.asarray(normals, dtype=np.float64))
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    p = np.asarray(points, dtype=np.float64)
    # Work relative to the points' mean so single precision keeps micrometre accuracy.
    origin = p.mean(axis=0)
    pt = (p - origin).T.astype(dtype)  # (3, n)
    twice = (2.0 * n).astype(dtype)  # (h, 3)
    offset = np.einsum("hi,hi->h", q - origin, n).astype(dtype)
    signed = n.astype(dtype) @ pt  # (h, n): signed distance of each point to each plane
    signed -= offset[:, None]
    out = []
    for axis in range(3):
        coord = np.multiply(signed, -twice[:, axis : axis + 1])
        coord += pt[axis][None, :]
        coord += dtype(origin[axis])
        out.append(coord)
    return out[0], out[1], out[2]


def mirror(points: np.ndarray, plane_points: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Mirror every point through every plane (paper Eqs. 4-5): ``p' = p - 2 ((p - q) . n) n``.

    Parameters
    ----------
    points : (n, 3) float
    plane_points : (h, 3) or (3,) float
        A point on each plane.
    normals : (h, 3) or (3,) float
        Normal of each plane (normalised here).

    Returns
    -------
    (h, n, 3) float, or (n, 3) for a single plane
    """
    p = as_points(points, min_count=0)
    n = np.asarray(normals, dtype=np.float64)
    q = np.asarray(plane_points, dtype=np.float64)
    if n.shape[-1:] != (3,) or q.shape[-1:] != (3,) or n.ndim > 2 or q.ndim > 2:
        raise InputError(f"planes need points and normals of shape (3,) or (h, 3), got {q.shape} and {n.shape}")
    if not np.all(np.linalg.norm(np.atleast_2d(n), axis=1) > 0):
        raise InputError("a plane normal must not be zero")
    if n.ndim == 1:  # one plane: the direct formula
        n = n / np.linalg.norm(n)
        return p - 2.0 * ((p - q) @ n)[:, None] * n
    return np.stack(mirror_xyz(p, q, n), axis=-1)
