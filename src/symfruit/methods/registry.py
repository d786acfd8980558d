"""The registry of completion methods.

A method is a function ``(points, camera, section) -> Completion``; ``section`` is the method's own
settings section (or None when it has none). A method registered with ``occlusion=True`` is called as
``fn(points, camera, section, occlusion=...)`` and receives the frame's occlusion information
(:class:`~symfruit.core.occlusion.Occlusion`, or None when the caller has none); the others never see it.
Registering it with :func:`register` makes it available to :func:`symfruit.complete`, the CLI and the
evaluation, and makes its settings section part of :class:`~symfruit.settings.Settings`. Adding a method
touches no other method.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.box import Box
from ..core.planes import Plane, Planes
from ..errors import InputError
from ..settings import register_section

__all__ = ["DEFAULT_METHOD", "Completion", "MethodInfo", "available", "get", "register"]

#: The method used wherever none is named (the API, the CLI, the ROS node, the benchmarks).
DEFAULT_METHOD = "evidence"


@dataclass(frozen=True)
class Completion:
    """What a method returns (``complete`` adds timing and input bookkeeping).

    Attributes
    ----------
    points : (m, 3) float, metres
        Visible plus completed points.
    box : Box
    plane : Plane or None
        The chosen symmetry plane, for methods that mirror.
    score : float
        The chosen hypothesis's mean score (NaN for methods that do not score).
    scores : (h,) float
        Every hypothesis's score, in hypothesis order (empty for methods that do not score).
    planes : Planes or None
        Every hypothesis.
    extras : dict
        Method-specific values (e.g. a fitted radius), JSON-serialisable.
    """

    points: np.ndarray
    box: Box
    plane: Plane | None = None
    score: float = float("nan")
    scores: np.ndarray = field(default_factory=lambda: np.empty(0))
    planes: Planes | None = None
    extras: dict[str, Any] = field(default_factory=dict)


Method = Callable[..., Completion]


@dataclass(frozen=True)
class MethodInfo:
    """A registered method: its function, the settings section it reads (its name), if any, and whether it
    takes the frame's occlusion information."""

    name: str
    fn: Method
    settings: type | None
    occlusion: bool = False

    @property
    def summary(self) -> str:
        """The first line of the method's docstring."""
        doc = (self.fn.__doc__ or "").strip().splitlines()
        return doc[0] if doc else ""


_REGISTRY: dict[str, MethodInfo] = {}


def register(name: str, *, settings: type | None = None, occlusion: bool = False) -> Callable[[Method], Method]:
    """Decorator: make ``fn`` available as method ``name``, reading the settings section ``name`` of type
    ``settings`` (a :class:`~symfruit.settings.Section` dataclass; registered as a section here); with
    ``occlusion``, ``fn`` takes the keyword ``occlusion`` (see the module)."""

    def decorate(fn: Method) -> Method:
        if name in _REGISTRY and _REGISTRY[name].fn is not fn:
            raise ValueError(f"completion method {name!r} is already registered")
        if settings is not None:
            register_section(name, settings)
        _REGISTRY[name] = MethodInfo(name, fn, settings, occlusion)
        return fn

    return decorate


def get(name: str) -> MethodInfo:
    """The method registered as ``name``; raises :class:`InputError` listing the known ones."""
    try:
        return _REGISTRY[name]
    except (KeyError, TypeError):
        raise InputError(f"unknown method {name!r}; available: {', '.join(available())}") from None


def available() -> list[str]:
    """Names of the registered methods, sorted."""
    return sorted(_REGISTRY)
