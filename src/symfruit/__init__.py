"""symfruit: locate fruit from one RGB-D view by completing its hidden side through mirror symmetry.

The package follows the data's way: :mod:`symfruit.io` (files -> arrays), :mod:`symfruit.segment` and
:mod:`symfruit.extract` (frame -> each fruit's points), :func:`complete` (points -> completed fruit and box,
through :mod:`symfruit.methods` and the numerical :mod:`symfruit.core`), :mod:`symfruit.detect` (a whole
frame), :mod:`symfruit.writers` (results -> files), :mod:`symfruit.evaluate` and :mod:`symfruit.cli`.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from .core.box import Box, box_iou, centre_deviation
from .core.camera import DEFAULT_CAMERA, Camera
from .core.planes import Plane
from .errors import ConfigError, FileFormatError, InputError, OutputError, SymfruitError, SymfruitWarning
from .methods import available as available_methods
from .methods.complete import Result, complete
from .settings import Settings, load_settings, resolve_settings

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
    "OutputError",
    "Plane",
    "Result",
    "Settings",
    "SymfruitError",
    "SymfruitWarning",
    "__version__",
    "available_methods",
    "box_iou",
    "centre_deviation",
    "complete",
    "load_settings",
    "resolve_settings",
]
