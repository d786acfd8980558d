"""Compiled kernels for the fits' loops (issue 19, eighth round; the cone ellipsoid's in the tenth), the observation's
pixel maps (ninth round), a fruit's surface, outline and colour trimming (twelfth round), the observation's edge
normals and silhouette bands and the silhouette's closing (thirteenth round), scipy's feature transform and the
quadric candidates' agreement (fourteenth round), the registration's key ranks and a fruit's depth noise
(fifteenth round), the solid of revolution's direction search, a marched candidate's agreement and the
occlusion's pixel look-ups (sixteenth round), and the registration's exact costs and keys, extraction's depth tests,
colour trimming's regions, the occlusion's windows, the colour segmenter's hulls, labellings and round skins, the
observation's band rays and outline pixels and the surface noise's measures (seventeenth round), and the
occlusion's maps with their nearest point pixels looked for only where they decide, the box of where a fruit may
project, the outline ellipse's acceptance test, the ragged outline's closing, the points' pixels and the colour
segmenter's sphere fits, centre search, depth edges, cells, ripe test's median redness, region grouping, pixel
redness and least areas (eighteenth round), with numba from the optional extra ``fast``.

:func:`compiled` returns the kernels' module, :mod:`symfruit.core._jit`, or None: when numba is not installed, or
when the environment sets ``SYMFRUIT_KERNELS=numpy``. Its callers (:func:`symfruit.core.fits.fit_sphere`,
:func:`~symfruit.core.fits.fit_revolution_slices`, :class:`~symfruit.core.fits.RevolutionInside`,
:func:`~symfruit.core.fits.fit_cone_ellipsoid`, :func:`~symfruit.core.fits.surface_noise`,
:func:`symfruit.core.raster.inner_distance` and :func:`~symfruit.core.raster.outer_distance`,
:meth:`symfruit.core.occlusion.Occlusion.allowed`; the twelfth round's
:func:`symfruit.core.raster.distance_transform`, :func:`symfruit.core.surface.fruit_surface`,
:func:`~symfruit.core.surface.monotone_region`, :func:`~symfruit.core.surface.colour_trim` and
:func:`~symfruit.core.surface.within`; the thirteenth round's :func:`symfruit.core.agreement.observe` and
:func:`symfruit.core.raster.close_ragged`; the fourteenth round's :func:`symfruit.core.raster.nearest_index` and
:func:`symfruit.core.agreement.explain`; the fifteenth round's :meth:`symfruit.core.surface._Outline.ranks` and
:func:`symfruit.core.surface.depth_noise`; the sixteenth round's :func:`symfruit.core.agreement.explain` of a
marched candidate and :meth:`symfruit.core.occlusion.Occlusion.at`; the seventeenth round's
:meth:`symfruit.core.surface._Outline.keys`, :func:`~symfruit.core.surface.registration_shift`,
:func:`~symfruit.core.surface.monotone_region`, :func:`symfruit.extract.extract`,
:func:`symfruit.core.occlusion.occlusion`, :func:`symfruit.core.raster.principal_widths`,
:func:`symfruit.segment.colour.segment`'s hulls, labellings, floods, creases and sphere points,
:func:`symfruit.core.agreement.observe`'s bands and outline, :func:`symfruit.core.fits.noise_measures` and
:func:`symfruit.core.points.column_means`; the eighteenth round's :func:`symfruit.core.occlusion.occlusion`
(:func:`symfruit.core._jit.occlusion_window`, the maps of ``occlusion_maps`` after ``nearest``),
:meth:`symfruit.core.occlusion.Occlusion.extent` (:func:`symfruit.core._jit.allowed_box`, the box of ``allowed``'s
pixels), :func:`symfruit.core.raster.outline_cone`, :func:`~symfruit.core.raster.close_ragged`,
:func:`~symfruit.core.raster.silhouette`, :func:`~symfruit.core.raster.rasterise`,
:func:`symfruit.segment.colour._sphere`, ``_centres``, ``_depth_edges``, ``_cells``, ``_grouped``, ``_least_areas``
and ``_segment_at``'s redness; the twentieth round's :func:`symfruit.core.occlusion.occlusion`
(:func:`symfruit.core._jit.occlusion_at`), :func:`symfruit.core.surface.monotone_region`
(:func:`symfruit.core._jit.monotone_table`) and :func:`symfruit.extract.cluster` (since stop 62 ``_depth_slabs``
in :func:`symfruit.core._jit.clusters`); stop 41's :func:`symfruit.core.occlusion.own_edge`
(:func:`symfruit.core._jit.own_edge`, in :func:`symfruit.core._jit.occlusion_projected` with the maps) and
:func:`~symfruit.core.surface.monotone_region` (:func:`symfruit.core._jit.monotone_at`); stop 42's
:func:`symfruit.core.surface.thin_front` (:func:`symfruit.core._jit.smooth_parts`,
:func:`~symfruit.core._jit.filled_windows`; since stop 45 :func:`~symfruit.core._jit.window_medians`,
:func:`~symfruit.core._jit.reaches_outline`, :func:`~symfruit.core._jit.part_sizes`; since stop 51 all of them in
:func:`~symfruit.core._jit.thin_passes`), stop 51's :func:`symfruit.core.surface.fruit_surface`
(:func:`symfruit.core._jit.mask_values`, :func:`~symfruit.core._jit.surface_cap`) and stop 62's curvature fit of
:func:`~symfruit.core.surface.thin_front` (:func:`symfruit.core._jit.thin_curvature`, to rounding: its answer taken
only where rounding cannot turn it), and stop 63's :func:`symfruit.core.edges.mask_shift` (its masks' outlines, their
windows' colour gradients and distance maps: :func:`symfruit.core._jit.outline_gradient`,
:func:`~symfruit.core._jit.colour_gradient`, :func:`~symfruit.core._jit.capped_distances`)) then run their numpy
twins, the code the kernels
were written from, which stays tested and gives the same results within rounding (the fits' kernels sum in another
order than numpy; the pixel maps', the surface's and the feature transform's are the twins' to the bit; the
observation's edge normals come from Jacobi rotations instead of LAPACK, so they agree to rounding, as the quadrics'
depth RMS does, and the segmenter's sphere fits from Householder reflections instead of LAPACK's SVD, a nanometre
apart, no mask changed on the checks of issue 19's eighteenth round). Nothing
compiles when symfruit is imported: numba is imported by the first fit that asks for a kernel (about half a second),
and each kernel is compiled on its first call (a few seconds in all) or loaded from numba's on-disk cache (beside
the module, or the user's cache directory where that is read-only; without a cache where neither is writable).

>>> compiled() is None or callable(compiled().slice_costs)
True
"""

from __future__ import annotations

import os
from types import ModuleType

__all__ = ["compiled"]

_STATE: dict[str, ModuleType | None] = {}

#: ``os.environ`` and its own dictionary of encoded names (CPython on POSIX), as they were at import, for
#: :func:`compiled`'s look-up of an unset ``SYMFRUIT_KERNELS``; None elsewhere.
_ENVIRON = os.environ
_DATA = getattr(os.environ, "_data", None) if os.name == "posix" else None
_DATA = _DATA if isinstance(_DATA, dict) else None
_KEY = b"SYMFRUIT_KERNELS"


def _setting() -> str:
    """``SYMFRUIT_KERNELS`` as the environment holds it now ("" unset). Read on every call (a test or a caller may
    set it at any time), from ``os.environ``'s own dictionary of encoded names where it has one (CPython on POSIX):
    ``os.environ.get`` of an unset name costs a caught KeyError, about 3 us, and :func:`compiled` is called some
    300 times a frame (issue 19, fifteenth round); elsewhere by ``os.environ.get``."""
    data = getattr(os.environ, "_data", None)
    if os.name == "posix" and isinstance(data, dict):
        raw = data.get(b"SYMFRUIT_KERNELS")
        return "" if raw is None else os.fsdecode(raw)
    return os.environ.get("SYMFRUIT_KERNELS", "")


def compiled() -> ModuleType | None:
    """The compiled kernels' module, or None where the numpy twins are to run (no numba, or
    ``SYMFRUIT_KERNELS=numpy``).

    The environment is read on every call (a test may set it at any time): where ``SYMFRUIT_KERNELS`` is unset
    (the usual case) and the module has been looked for, by one membership test of ``os.environ``'s own dictionary
    and one look-up of the module found, about a third of the full path's cost (some 900 calls a benchmark frame;
    issue 19, twentieth round); set, or on the first call, by :func:`_setting` as before."""
    if _DATA is not None and _KEY not in _DATA and os.environ is _ENVIRON:
        try:
            return _STATE["jit"]
        except KeyError:  # not looked for yet (or the state was reset): below
            pass
    if _setting().lower() == "numpy":
        return None
    if "jit" not in _STATE:
        try:
            from . import _jit
        except ImportError:  # numba (the extra `fast`) is not installed, or not for this numpy
            _STATE["jit"] = None
        else:
            _STATE["jit"] = _jit
    return _STATE["jit"]
