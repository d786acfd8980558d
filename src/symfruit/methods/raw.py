"""``raw``: the box of the visible points, what a robot gets without completion."""

from __future__ import annotations

import numpy as np

from ..core.box import Box
from ..core.camera import Camera
from .registry import Completion, register


@register("raw")
def raw(points: np.ndarray, camera: Camera, settings: None) -> Completion:
    """The box of the visible points (no completion)."""
    return Completion(points=points.copy(), box=Box.from_points(points))
