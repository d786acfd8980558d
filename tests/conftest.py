"""Shared fixtures and helpers: known-answer solids seen by the default camera, the shipped example data,
and the hypothesis profiles.

Property and fuzz tests run the derandomised ``ci`` profile by default: the same cases on every run,
``SYMFRUIT_FUZZ_EXAMPLES`` of them (default 40), so a failure in CI is a failure on every machine. The
``long`` profile (``make test-long``, or ``SYMFRUIT_HYPOTHESIS=long``) draws fresh random cases, 1,000 per
test unless ``SYMFRUIT_FUZZ_EXAMPLES`` says otherwise.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

import symfruit

_QUIET = [HealthCheck.too_slow, HealthCheck.function_scoped_fixture, HealthCheck.data_too_large]
settings.register_profile(
    "ci", derandomize=True, database=None, deadline=None, suppress_health_check=_QUIET, print_blob=True,
    max_examples=int(os.environ.get("SYMFRUIT_FUZZ_EXAMPLES", "40")),
)  # fmt: skip
settings.register_profile(
    "long", derandomize=False, deadline=None, suppress_health_check=_QUIET, print_blob=True,
    max_examples=int(os.environ.get("SYMFRUIT_FUZZ_EXAMPLES", "1000")),
)  # fmt: skip
settings.load_profile(os.environ.get("SYMFRUIT_HYPOTHESIS", "ci"))

#: Examples per property test under the loaded profile (tests that are costlier run a share of it).
FUZZ_EXAMPLES = settings.default.max_examples

#: The repository's examples folder (sample cloud, camera) and the demo frame shipped as package data.
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
EXAMPLE_FRAME = Path(symfruit.__file__).resolve().parent / "data" / "example_frame"

CENTRE = np.array([0.01, -0.02, 0.35])


def fibonacci_sphere(n: int) -> np.ndarray:
    """(n, 3) unit vectors spread evenly over the sphere (deterministic)."""
    i = np.arange(n) + 0.5
    phi = np.arccos(1.0 - 2.0 * i / n)
    theta = np.pi * (1.0 + 5**0.5) * i
    return np.c_[np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)]


def sphere_cloud(radius: float = 0.02, n: int = 1200, centre: np.ndarray = CENTRE) -> np.ndarray:
    return radius * fibonacci_sphere(n) + centre


def ellipsoid_cloud(axes=(0.018, 0.025, 0.015), n: int = 1200, centre: np.ndarray = CENTRE) -> np.ndarray:
    return fibonacci_sphere(n) * np.asarray(axes) + centre


def revolution_cloud(centre: np.ndarray = CENTRE) -> np.ndarray:
    """An egg-like solid of revolution about y: r(y) = R sqrt(1 - (y/L)^2) (1 + 0.3 y/L)."""
    t = np.linspace(-1.0, 1.0, 60)[1:-1]
    phi = np.linspace(0.0, 2.0 * np.pi, 40, endpoint=False)
    tt, pp = np.meshgrid(t, phi)
    r = 0.02 * np.sqrt(1.0 - tt**2) * (1.0 + 0.3 * tt)
    pts = np.c_[(r * np.cos(pp)).ravel(), (0.025 * tt).ravel(), (r * np.sin(pp)).ravel()]
    return pts + centre


def front_half(cloud: np.ndarray, centre: np.ndarray = CENTRE) -> np.ndarray:
    """The half facing the camera (z below the centre's)."""
    return cloud[cloud[:, 2] < centre[2]]


@pytest.fixture
def camera() -> symfruit.Camera:
    return symfruit.DEFAULT_CAMERA


@pytest.fixture
def sphere_view() -> np.ndarray:
    return front_half(sphere_cloud())
