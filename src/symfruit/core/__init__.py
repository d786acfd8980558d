"""The numerical core: arrays in, arrays and small result objects out.

Imports numpy and scipy only; knows no settings objects, files or command line. The stages:
:mod:`.camera` (pinhole model), :mod:`.points` (input checks), :mod:`.box`, :mod:`.planes` (hypotheses,
mirroring), :mod:`.raster` (what the camera saw), :mod:`.rating` (Algorithm 1), :mod:`.symmetry` (the
paper's completion), :mod:`.fits` (sphere, ellipsoids, solid of revolution).
"""

from __future__ import annotations

from .box import Box, box_iou, centre_deviation
from .camera import DEFAULT_CAMERA, Camera
from .fits import (
    ellipsoid_half_extents,
    fit_aligned_ellipsoid,
    fit_ellipsoid,
    fit_revolution,
    fit_sphere,
    surface_noise,
)
from .planes import Plane, Planes, hypothesis_planes, mirror
from .points import as_points, check_cloud
from .raster import View, rasterise, silhouette_coverage
from .rating import LOCATIONS, Rating, Table1, rate_planes, rate_points
from .symmetry import SymmetryCompletion, complete_by_symmetry

__all__ = [
    "DEFAULT_CAMERA",
    "LOCATIONS",
    "Box",
    "Camera",
    "Plane",
    "Planes",
    "Rating",
    "SymmetryCompletion",
    "Table1",
    "View",
    "as_points",
    "box_iou",
    "centre_deviation",
    "check_cloud",
    "complete_by_symmetry",
    "ellipsoid_half_extents",
    "fit_aligned_ellipsoid",
    "fit_ellipsoid",
    "fit_revolution",
    "fit_sphere",
    "hypothesis_planes",
    "mirror",
    "rasterise",
    "rate_planes",
    "rate_points",
    "silhouette_coverage",
    "surface_noise",
]
