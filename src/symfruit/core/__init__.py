"""The numerical core: arrays in, arrays and small result objects out.

Imports numpy and scipy only; knows no settings objects, files or command line. The stages:
:mod:`.camera` (pinhole model), :mod:`.points` (input checks), :mod:`.box`, :mod:`.planes` (hypotheses,
mirroring), :mod:`.raster` (what the camera saw), :mod:`.rating` (Algorithm 1), :mod:`.symmetry` (the
paper's completion), :mod:`.fits` (sphere, ellipsoids, solids of revolution), :mod:`.superellipsoid`
(Marangoz et al.'s fit), :mod:`.front` (the front surface's depth), :mod:`.agreement` (how well a closed
shape explains the view), :mod:`.candidates` (the default method's candidate completions), :mod:`.occlusion`
(where a frame's camera could not have seen a fruit: its occlusion information), :mod:`.frame` (one RGB-D
frame). A module's main function (``candidates.candidates``, ``occlusion.occlusion``) is not re-exported
here, so that ``symfruit.core.candidates`` stays the module.
"""

from __future__ import annotations

from .agreement import Agreement, Observation, explain, march, observe
from .box import Box, box_iou, centre_deviation
from .camera import DEFAULT_CAMERA, Camera
from .candidates import Candidate, constrain_box
from .fits import (
    Revolution,
    ellipsoid_half_extents,
    fit_aligned_ellipsoid,
    fit_ellipsoid,
    fit_revolution,
    fit_revolution_slices,
    fit_sphere,
    revolution_box,
    revolution_inside,
    surface_noise,
)
from .front import apex_depth
from .occlusion import Occlusion
from .planes import Plane, PlaneGrid, Planes, hypothesis_planes, mirror
from .points import as_points, check_cloud
from .raster import Silhouette, View, rasterise, silhouette, silhouette_coverage
from .rating import LOCATIONS, Rating, Table1, rate_planes, rate_points
from .superellipsoid import Superellipsoid, fit_superellipsoid, missing_surface, superellipsoid_box
from .symmetry import SymmetryCompletion, complete_by_symmetry

__all__ = [
    "DEFAULT_CAMERA",
    "LOCATIONS",
    "Agreement",
    "Box",
    "Camera",
    "Candidate",
    "Observation",
    "Occlusion",
    "Plane",
    "PlaneGrid",
    "Planes",
    "Rating",
    "Revolution",
    "Silhouette",
    "Superellipsoid",
    "SymmetryCompletion",
    "Table1",
    "View",
    "apex_depth",
    "as_points",
    "box_iou",
    "centre_deviation",
    "check_cloud",
    "complete_by_symmetry",
    "constrain_box",
    "ellipsoid_half_extents",
    "explain",
    "fit_aligned_ellipsoid",
    "fit_ellipsoid",
    "fit_revolution",
    "fit_revolution_slices",
    "fit_sphere",
    "fit_superellipsoid",
    "hypothesis_planes",
    "march",
    "mirror",
    "missing_surface",
    "observe",
    "rasterise",
    "rate_planes",
    "rate_points",
    "revolution_box",
    "revolution_inside",
    "silhouette",
    "silhouette_coverage",
    "superellipsoid_box",
    "surface_noise",
]
