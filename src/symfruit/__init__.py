"""symfruit: locate fruit from one RGB-D view by completing its hidden side through mirror symmetry."""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from .box import Box, box_iou, centre_deviation
from .camera import DEFAULT_CAMERA, Camera
from .complete import Result, complete
from .config import Settings, load_settings
from .errors import ConfigError, FileFormatError, InputError, SymfruitError
from .methods import available as available_methods
from .planes import Plane

try:
    __version__ = version("symfruit")
except PackageNotFoundError:  # pragma: no cover - running from a source tree without install
    __version__ = "0.0.0+unknown"

__all__ = [
    "DEFAULT_CAMERA",
    "Box",
    "Camera",
    "ConfigError",
    "FileFormatError",
    "InputError",
    "Plane",
    "Result",
    "Settings",
    "SymfruitError",
    "__version__",
    "available_methods",
    "box_iou",
    "centre_deviation",
    "complete",
    "load_settings",
]
