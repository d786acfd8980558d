"""Axis-aligned 3D boxes (paper section 3.6) and their overlap (paper Eq. 12)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .points import as_points, bounds

__all__ = ["Box", "box_iou", "centre_deviation"]


@dataclass(frozen=True)
class Box:
    """An axis-aligned box in the camera frame.

    Attributes
    ----------
    min, max : (3,) float, metres
        Finite, ``min <= max`` on every axis (a flat box, ``min == max``, is a box); anything else is
        refused with :class:`~symfruit.errors.InputError`.
    """

    min: np.ndarray
    max: np.ndarray

    def __post_init__(self) -> None:
        try:
            lo, hi = (np.asarray(v, dtype=np.float64) for v in (self.min, self.max))
        except (TypeError, ValueError):
            given = f"{self.min!r:.40} and {self.max!r:.40}"
            raise InputError(f"a box needs min and max of 3 numbers, got {given}") from None
        if lo.shape != (3,) or hi.shape != (3,):
            raise InputError(f"a box needs min and max of shape (3,), got {lo.shape} and {hi.shape}")
        lo_list, hi_list = lo.tolist(), hi.tolist()  # six floats: checked in Python, a fifth of numpy's cost
        if not all(map(math.isfinite, lo_list + hi_list)):  # a NaN box has no size, centre or overlap
            raise InputError(f"a box needs finite corners, got min {lo_list} and max {hi_list}")
        for axis, a, b in zip("xyz", lo_list, hi_list, strict=True):
            if a > b:  # its size would be negative, its volume and IoU garbage
                raise InputError(f"a box's min lies beyond its max along {axis}: min {lo_list}, max {hi_list}")
        object.__setattr__(self, "min", lo)
        object.__setattr__(self, "max", hi)

    @classmethod
    def from_points(cls, points: np.ndarray) -> Box:
        """The tightest box around ``points`` : (n, 3) float, n >= 1.

        Raises
        ------
        InputError
            When ``points`` is not an ``(n, 3)`` array with at least one row, or holds NaN or infinity (no box
            bounds them: drop those rows first).
        """
        points = as_points(points, min_count=1)
        lo, hi = bounds(points)
        if not (np.isfinite(lo).all() and np.isfinite(hi).all()):  # NaN would make a box of NaN corners unsaid
            raise InputError("points to box hold NaN or infinite coordinates; drop those rows first")
        return cls(lo, hi)

    @property
    def centre(self) -> np.ndarray:
        """(3,) float, metres."""
        return (self.min + self.max) / 2.0

    @property
    def size(self) -> np.ndarray:
        """(3,) float, metres: extent along x, y, z."""
        return self.max - self.min

    @property
    def volume(self) -> float:
        """Cubic metres."""
        return float(np.prod(self.size))

    def union(self, other: Box) -> Box:
        """The smallest box containing both."""
        _boxes(self, other, "Box.union")
        return Box(min=np.minimum(self.min, other.min), max=np.maximum(self.max, other.max))

    def contains(self, points: np.ndarray, *, tol: float = 0.0) -> bool:
        """Whether every point of ``points`` : (n, 3) lies in the box (within ``tol`` metres)."""
        number = isinstance(tol, int | float | np.integer | np.floating) and not isinstance(tol, bool)
        if not (number and math.isfinite(tol)):  # NaN made every point 'outside', text a UFuncTypeError
            raise InputError(f"Box.contains: tol must be a finite number of metres, got {tol!r:.40}")
        points = as_points(points, min_count=0)
        return bool(np.all(points >= self.min - tol) and np.all(points <= self.max + tol))

    def corners(self) -> np.ndarray:
        """(8, 3) float: the corners, bit i of the index choosing max over min on axis i."""
        bits = (np.arange(8)[:, None] >> np.arange(3)[None, :]) & 1
        return np.where(bits == 1, self.max, self.min)

    def to_dict(self) -> dict[str, list[float]]:
        return {"min": self.min.tolist(), "max": self.max.tolist(), "size": self.size.tolist()}


def box_iou(a: Box, b: Box) -> float:
    """Intersection over union of two axis-aligned boxes (paper Eq. 12), in [0, 1].

    Examples
    --------
    >>> unit = Box(np.zeros(3), np.ones(3))
    >>> box_iou(unit, Box(np.array([0.5, 0, 0]), np.array([1.5, 1, 1])))
    0.3333333333333333
    """
    _boxes(a, b, "box_iou")
    overlap = np.clip(np.minimum(a.max, b.max) - np.maximum(a.min, b.min), 0.0, None)
    inter = float(np.prod(overlap))
    union = a.volume + b.volume - inter
    return inter / union if union > 0 else 0.0


def centre_deviation(a: Box, b: Box) -> float:
    """Euclidean distance between the two box centres, metres."""
    _boxes(a, b, "centre_deviation")
    return float(np.linalg.norm(a.centre - b.centre))


def _boxes(a: object, b: object, what: str) -> None:
    """Refuse anything but two :class:`Box` (arrays have ``max`` and ``min`` methods, not corners)."""
    for box in (a, b):
        if not isinstance(box, Box):
            raise InputError(f"{what} needs two Box (symfruit.Box or Box.from_points), got {type(box).__name__}")
