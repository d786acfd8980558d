"""Completion methods behind one registry.

A method is a function ``(points, camera, settings) -> Completion``; registering it with
:func:`register` makes it available to :func:`symfruit.complete`, the CLI and the evaluation.
Adding a method touches no other method.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..box import Box
from ..camera import Camera
from ..config import Settings
from ..errors import InputError
from ..planes import Plane, Planes

__all__ = ["Completion", "available", "get", "register"]


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
    extras: dict = field(default_factory=dict)


Method = Callable[[np.ndarray, Camera, Settings], Completion]
_REGISTRY: dict[str, Method] = {}


def register(name: str) -> Callable[[Method], Method]:
    """Decorator: make ``fn`` available as method ``name``."""

    def decorate(fn: Method) -> Method:
        if name in _REGISTRY and _REGISTRY[name] is not fn:
            raise ValueError(f"completion method {name!r} is already registered")
        _REGISTRY[name] = fn
        return fn

    return decorate


def get(name: str) -> Method:
    """The method registered as ``name``; raises :class:`InputError` listing the known ones."""
    try:
        return _REGISTRY[name]
    except KeyError:
        raise InputError(f"unknown method {name!r}; available: {', '.join(available())}") from None


def available() -> list[str]:
    """Names of the registered methods, sorted."""
    return sorted(_REGISTRY)


from . import ellipsoid, fused, paper, raw, sphere  # noqa: E402,F401  (register the built-in methods)
