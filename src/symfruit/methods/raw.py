"""``raw``: the box of the visible points, what a robot gets without completion."""

from __future__ import annotations

import numpy as np

from ..box import Box
from ..camera import Camera
from ..config import Settings
from . import Completion, register


@register("raw")
def raw(points: np.ndarray, camera: Camera, settings: Settings) -> Completion:
    """Return the visible points unchanged and their box."""
    return Completion(points=points.copy(), box=Box.from_points(points))
