"""The public entry point: :func:`complete` one fruit's visible points."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .box import Box
from .camera import DEFAULT_CAMERA, Camera
from .config import InputSettings, Settings, from_dict
from .errors import InputError
from .methods import get
from .planes import Plane, Planes

__all__ = ["Result", "check_points", "complete"]


@dataclass(frozen=True)
class Result:
    """A completed fruit.

    Attributes
    ----------
    method : str
    points : (m, 3) float, metres
        Visible plus completed points, camera optical frame.
    visible : (n, 3) float, metres
        The visible points actually used (non-finite rows dropped, large clouds down-sampled).
    box : Box
        Axis-aligned box of the completed fruit.
    plane : Plane or None
        The chosen symmetry plane (mirroring methods only).
    score : float
        The chosen hypothesis's mean score (NaN for methods that do not score).
    scores : (h,) float
        Every hypothesis's mean score.
    planes : Planes or None
        Every hypothesis, in the order of ``scores``.
    seconds : float
        Wall time of the completion.
    n_input, n_dropped : int
        Points given, and non-finite points dropped.
    extras : dict
        Method-specific values.
    settings : Settings
        The effective settings.
    """

    method: str
    points: np.ndarray
    visible: np.ndarray
    box: Box
    plane: Plane | None
    score: float
    scores: np.ndarray
    planes: Planes | None
    seconds: float
    n_input: int
    n_dropped: int
    extras: dict = field(default_factory=dict)
    settings: Settings = field(default_factory=Settings)

    @property
    def centre(self) -> np.ndarray:
        """(3,) float, metres: centre of :attr:`box`."""
        return self.box.centre

    @property
    def confidence(self) -> float | None:
        """How far to trust the box, in [0, 1] (methods that estimate it, e.g. ``fused``), else None."""
        value = self.extras.get("confidence")
        return None if value is None else float(value)

    @property
    def reliable(self) -> bool | None:
        """Whether :attr:`confidence` reaches the method's threshold (None when it has none)."""
        value = self.extras.get("reliable")
        return None if value is None else bool(value)

    def to_dict(self) -> dict[str, Any]:
        """The JSON summary printed by ``symfruit complete --json``."""
        score = None if not np.isfinite(self.score) else float(self.score)
        return {
            "method": self.method,
            "centre": self.centre.tolist(),
            "box": self.box.to_dict(),
            "plane": None if self.plane is None else self.plane.to_dict(),
            "score": score,
            "n_visible": len(self.visible),
            "n_completed": len(self.points),
            "n_dropped": int(self.n_dropped),
            "confidence": self.confidence,
            "reliable": self.reliable,
            "seconds": float(self.seconds),
        }


def check_points(points: Any, settings: InputSettings | None = None) -> tuple[np.ndarray, int]:
    """Validate a cloud at the boundary and return ``(clean (n, 3) float64 points, n_dropped)``.

    Non-finite rows are dropped (and counted); clouds over ``max_points`` are down-sampled with a
    fixed seed. Raises :class:`InputError` for anything a fruit cannot be: wrong shape, too few
    points, points at or behind the camera, all points identical or on a line, or a cloud wider
    than ``max_extent`` (most often a cloud in millimetres).
    """
    s = settings or InputSettings()
    try:
        arr = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError("points must be a numeric (n, 3) array of x, y, z in metres") from None
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise InputError(f"points must have shape (n, 3), got {arr.shape}")
    finite = np.isfinite(arr).all(axis=1)
    n_dropped = 0
    if not finite.all():
        n_dropped = int(len(arr) - finite.sum())
        arr = arr[finite]
    if len(arr) < s.min_points:
        extra = f" after dropping {n_dropped} non-finite" if n_dropped else ""
        raise InputError(
            f"a fruit needs at least {s.min_points} points, got {len(arr)}{extra} (input.min_points sets the limit)"
        )
    if arr[:, 2].min() <= 0:
        behind = int((arr[:, 2] <= 0).sum())
        raise InputError(
            f"{behind} of {len(arr)} points are at or behind the camera (z <= 0); points must be in "
            "the camera optical frame (x right, y down, z forward), in metres"
        )
    extent = float((arr.max(axis=0) - arr.min(axis=0)).max())
    if extent > s.max_extent:
        raise InputError(
            f"the cloud is {extent:.3g} m across, too large for one fruit (input.max_extent = "
            f"{s.max_extent} m); if it is in millimetres, use --units mm (or divide by 1000)"
        )
    if extent < s.min_extent:
        if extent == 0:
            raise InputError("all points are identical; a fruit needs points spread over its surface")
        raise InputError(
            f"the cloud is only {extent * 1000:.3g} mm across, too small for a fruit (input.min_extent = "
            f"{s.min_extent * 1000:g} mm); check the units (--units m for metres)"
        )
    centred = arr - arr.mean(axis=0)
    spread = np.linalg.eigvalsh(centred.T @ centred)  # ascending variances (times n)
    if spread[2] <= 1e-18 * len(arr):
        raise InputError("all points are identical; a fruit needs points spread over its surface")
    if spread[1] <= 1e-12 * spread[2]:
        raise InputError("all points lie on a line; a fruit needs points spread over its surface")
    if spread[0] <= 1e-12 * spread[2]:
        raise InputError(
            "all points lie on a plane; a fruit's visible surface is curved (is this a depth image "
            "of a flat object, or a cloud with its depth dropped?)"
        )
    if len(arr) > s.max_points:
        keep = np.random.default_rng(0).choice(len(arr), size=s.max_points, replace=False)
        arr = arr[np.sort(keep)]
    return arr, n_dropped


def complete(
    points: Any,
    *,
    camera: Camera | None = None,
    method: str = "fused",
    settings: Settings | dict | None = None,
) -> Result:
    """Complete one fruit seen from one view and box it.

    Parameters
    ----------
    points : (n, 3) float, metres
        The fruit's visible points in the camera optical frame (x right, y down, z forward).
    camera : Camera, optional
        Intrinsics of the camera that saw them; None means :data:`~symfruit.camera.DEFAULT_CAMERA`
        (Intel D435 colour, 640x480).
    method : str
        A registered method: ``fused`` (default), ``paper``, ``sphere``, ``ellipsoid``, ``raw``, ...
        (:func:`symfruit.methods.available`).
    settings : Settings or dict, optional
        Settings, or a nested dict of overrides (``{"paper": {"rotations_x": 21}}``).

    Returns
    -------
    Result

    Examples
    --------
    >>> import numpy as np, symfruit
    >>> rng = np.random.default_rng(0)
    >>> d = rng.normal(size=(600, 3)); d /= np.linalg.norm(d, axis=1, keepdims=True)
    >>> front = 0.015 * d[d[:, 2] < 0] + [0.0, 0.0, 0.3]
    >>> r = symfruit.complete(front, method="sphere")
    >>> np.round(r.centre, 3).tolist()
    [0.0, 0.0, 0.3]
    """
    if settings is None:
        settings = Settings()
    elif isinstance(settings, dict):
        settings = from_dict(settings)
    fn = get(method)
    camera = DEFAULT_CAMERA if camera is None else camera
    n_input = len(points) if hasattr(points, "__len__") else 0
    start = time.perf_counter()
    clean, n_dropped = check_points(points, settings.input)
    done = fn(clean, camera, settings)
    seconds = time.perf_counter() - start
    return Result(
        method=method,
        points=done.points,
        visible=clean,
        box=done.box,
        plane=done.plane,
        score=done.score,
        scores=done.scores,
        planes=done.planes,
        seconds=seconds,
        n_input=n_input,
        n_dropped=n_dropped,
        extras=done.extras,
        settings=settings,
    )
