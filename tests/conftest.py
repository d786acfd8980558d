"""Shared fixtures: known-answer solids seen by the default camera."""

from __future__ import annotations

import numpy as np
import pytest

import symfruit

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
