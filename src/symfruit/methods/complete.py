"""The public entry point: :func:`complete` one fruit's visible points."""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.box import Box
from ..core.camera import DEFAULT_CAMERA, Camera
from ..core.occlusion import Occlusion
from ..core.planes import Plane, Planes
from ..core.points import check_cloud, check_view
from ..errors import InputError
from ..settings import Section, SettingError, Settings, from_dict, setting
from .registry import DEFAULT_METHOD, get

__all__ = ["InputSettings", "Result", "complete"]


@dataclass(frozen=True)
class InputSettings(Section):
    """Checks applied to every cloud before completion.

    Attributes
    ----------
    min_points : int
        Fewest finite points a fruit needs; fewer raise :class:`~symfruit.errors.InputError`.
    max_points : int
        Larger clouds are down-sampled (seeded, reproducible) to this many points.
    max_extent : float, metres
        A cloud wider than this in any axis is refused as "not a single fruit, or in millimetres".
    min_extent : float, metres
        A cloud whose largest extent is smaller than this is refused as "not a fruit, or in the
        wrong units" (e.g. metres read with ``--units mm``).
    """

    min_points: int = setting(10, ge=4, le=1_000_000)
    max_points: int = setting(20000, ge=4, le=5_000_000)
    max_extent: float = setting(1.0, gt=0.0, le=100.0)
    min_extent: float = setting(0.003, gt=0.0, le=100.0)

    def check(self) -> None:
        if self.max_points < self.min_points:
            raise SettingError("max_points", "must be >= min_points")
        if self.min_extent >= self.max_extent:
            raise SettingError("min_extent", "must be smaller than max_extent")


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
    extras: dict[str, Any] = field(default_factory=dict)
    settings: Settings = field(default_factory=lambda: Settings())

    @property
    def centre(self) -> np.ndarray:
        """(3,) float, metres: centre of :attr:`box`."""
        return self.box.centre

    @property
    def confidence(self) -> float | None:
        """How far to trust the box, in [0, 1] (methods that estimate it, e.g. ``evidence``), else None."""
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


def complete(
    points: Any,
    *,
    camera: Camera | Mapping[str, Any] | None = None,
    method: str = DEFAULT_METHOD,
    settings: Settings | Mapping[str, Any] | None = None,
    occlusion: Occlusion | None = None,
) -> Result:
    """Complete one fruit seen from one view and box it.

    Parameters
    ----------
    points : (n, 3) float, metres
        The fruit's visible points in the camera optical frame (x right, y down, z forward).
    camera : Camera or mapping, optional
        Intrinsics of the camera that saw them (a mapping in any layout :func:`symfruit.io.camera_from_dict`
        reads); None means :data:`~symfruit.core.camera.DEFAULT_CAMERA` (Intel D435 colour, 640x480).
    method : str
        A registered method: ``evidence`` (default), ``paper``, ``superellipsoid``, ``sphere``, ``ellipsoid``,
        ``fused`` (the previous default), ``raw``, ...
        (:func:`symfruit.methods.available`).
    settings : Settings or mapping, optional
        Settings (e.g. from :func:`symfruit.resolve_settings`), or a nested mapping of overrides
        (``{"paper": {"rotations_x": 21}}``).
    occlusion : Occlusion, optional
        Where the camera could not have seen this fruit (:func:`symfruit.core.occlusion.occlusion` of the frame's
        depth image and masks; :func:`symfruit.detect.detect` computes it), for the methods that use it
        (``evidence``); the others ignore it. None: the points are all there is.

    Returns
    -------
    Result

    Raises
    ------
    InputError
        For points that cannot be a fruit, an unknown method, or arguments of the wrong type.
    ConfigError
        For invalid settings.

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
    settings = _settings(settings)
    camera = _camera(camera)
    info = get(method)
    if occlusion is not None:
        if not isinstance(occlusion, Occlusion):
            raise InputError(f"occlusion must be a symfruit.core.occlusion.Occlusion or None, got "
                             f"{type(occlusion).__name__}")  # fmt: skip
        if (occlusion.width, occlusion.height) != (camera.width, camera.height):
            raise InputError(f"occlusion is for a {occlusion.width}x{occlusion.height} image, the camera's is "
                             f"{camera.width}x{camera.height}")  # fmt: skip
    try:
        n_input = len(points)
    except TypeError:  # a scalar or 0-d array: check_cloud names the problem
        n_input = 0
    start = time.perf_counter()
    s = settings.input
    clean, n_dropped = check_cloud(points, min_points=s.min_points, max_points=s.max_points,
                                   min_extent=s.min_extent, max_extent=s.max_extent, section="input")  # fmt: skip
    check_view(clean, camera)
    section = settings.section(method) if info.settings is not None else None
    done = info.fn(clean, camera, section, occlusion=occlusion) if info.occlusion else info.fn(clean, camera, section)
    _check_completion(done.box, clean, method, s.max_extent)
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


def _check_completion(box: Box, visible: np.ndarray, method: str, max_extent: float) -> None:
    """A completed box must be finite, hold the visible points and stay a fruit's size."""
    # in Python floats (issue 19, stop 53): the same tests and size as numpy's on the (3,) float64 corners
    lo, hi = box.min.tolist(), box.max.tolist()
    if not (all(map(math.isfinite, lo)) and all(map(math.isfinite, hi))):
        raise InputError(f"method {method!r} gave a non-finite box for these points (degenerate geometry)")
    size = max(b - a for a, b in zip(lo, hi, strict=True))
    if size > max_extent:
        raise InputError(
            f"method {method!r} completed these points to a box {size:.3g} m across, larger than one fruit "
            f"(input.max_extent = {max_extent} m): the visible points do not constrain a fruit (degenerate geometry)"
        )


_DEFAULTS: dict[tuple[Any, ...], Settings] = {}


def _default_settings() -> Settings:
    """``Settings()``, made once per set of registered sections (immutable, so it can be shared)."""
    from ..settings import section_types

    key = tuple(section_types().items())
    if key not in _DEFAULTS:
        _DEFAULTS.clear()
        _DEFAULTS[key] = Settings()
    return _DEFAULTS[key]


def _settings(settings: Any) -> Settings:
    if settings is None:
        return _default_settings()
    if isinstance(settings, Settings):
        return settings
    if isinstance(settings, Mapping):
        return from_dict(settings)
    raise InputError(
        f"settings must be a Settings or a mapping of sections, got {type(settings).__name__} "
        "(to read a file, use symfruit.resolve_settings(config=path))"
    )


def _camera(camera: Any) -> Camera:
    if camera is None:
        return DEFAULT_CAMERA
    if isinstance(camera, Camera):
        return camera
    if isinstance(camera, Mapping):
        from ..io.intrinsics import camera_from_dict

        return camera_from_dict(camera)
    raise InputError(f"camera must be a Camera or a mapping of intrinsics, got {type(camera).__name__}")
