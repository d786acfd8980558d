"""Completion methods: small adapters that unpack their settings section and call :mod:`symfruit.core`.

Importing this package registers the built-in methods; :mod:`.registry` holds the registry itself.
"""

from __future__ import annotations

from . import ellipsoid, evidence, fused, paper, raw, sphere, superellipsoid
from .registry import DEFAULT_METHOD, Completion, MethodInfo, available, get, register

__all__ = [
    "DEFAULT_METHOD",
    "Completion",
    "MethodInfo",
    "available",
    "ellipsoid",
    "evidence",
    "fused",
    "get",
    "paper",
    "raw",
    "register",
    "sphere",
    "superellipsoid",
]
