"""Candidate completions of one view, each with its box and how well it explains the view.

Every candidate is a different assumption about the hidden side:

``sphere``
    a ball (least-squares sphere, geometric refinement);
``ellipsoid``
    a general ellipsoid (Li-Griffiths, any orientation);
``cone``
    the ellipsoid whose outline is the silhouette (tangent to its viewing cone) and whose front best fits
    the seen depths (:func:`symfruit.core.fits.fit_cone_ellipsoid`);
``outline``
    the same solid of revolution with its radii read off the silhouette's outline
    (:func:`symfruit.core.fits.outline_radii`), when the outline is given;
``revolution``
    a solid of revolution (:func:`symfruit.core.fits.fit_revolution_slices`): its axis from slice circles,
    its profile from the seen arcs, an end left unseen closed by symmetry about the widest slice;
``mirror``
    the paper's mirror symmetry (:func:`symfruit.core.symmetry.complete_by_symmetry`), optional;
``raw``
    nothing hidden: the box of what was seen.

Closed candidates (sphere, ellipsoid, solid of revolution) are measured against the view by
:func:`symfruit.core.agreement.explain`. All boxes share the front depth estimated from the data
(:func:`symfruit.core.front.apex_depth`) and otherwise contain every seen point.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..errors import InputError
from . import lapack
from .agreement import Agreement, Inside, Observation, Quadric, explain
from .camera import Camera
from .fits import (
    Revolution,
    RevolutionInside,
    ScaledCloud,
    box_and_profile,
    ellipsoid_half_extents,
    fit_cone_ellipsoid,
    fit_ellipsoid,
    fit_revolution_slices,
    fit_sphere,
    outline_radii,
    scaled_cloud,
)
from .kernels import compiled
from .points import as_points, bounds
from .raster import Silhouette, View
from .symmetry import complete_by_symmetry

__all__ = ["REACH", "SHAPES", "Candidate", "candidates", "constrain_box", "section_ratio"]

#: No face of a candidate's box lies farther than this many seen extents from the opposite seen face (see
#: :func:`constrain_box`).
REACH = 3.0
#: ... and :data:`REACH` ``/ REACH_FLOOR`` where the outline is mostly cut.
REACH_FLOOR = 0.5
#: The closed candidates, in the order they are fitted.
SHAPES = ("sphere", "ellipsoid", "cone", "revolution")
#: The sphere candidate's Gauss-Newton stops once a step moves its centre and radius by less than this, metres
#: (:func:`~symfruit.core.fits.fit_sphere`'s ``tolerance``; issue 19, stop 55: 10 um instead of its default 0.1 um,
#: about two steps fewer a fit; each step moves it less than the last, docs/fast55.md).
SPHERE_TOLERANCE = 1e-5


@dataclass(frozen=True)
class Candidate:
    """One completion hypothesis.

    Attributes
    ----------
    name : str
    lo, hi : (3,) float, metres
        Its box (see :func:`constrain_box`).
    agreement : Agreement or None
        How it explains the view (closed candidates only).
    centre : (3,) float, metres
        Its own centre estimate (the shape's centre; the box centre for mirror and raw).
    back_std : float, metres
        Standard deviation of its back face from its own fit, where the fit says (the ``cone``
        ellipsoid); NaN otherwise.
    """

    name: str
    lo: np.ndarray
    hi: np.ndarray
    agreement: Agreement | None
    centre: np.ndarray
    back_std: float = float("nan")


def constrain_box(
    lo: np.ndarray,
    hi: np.ndarray,
    seen_lo: np.ndarray,
    seen_hi: np.ndarray,
    front: float,
    *,
    cone: tuple[tuple[float, float, float, float], Camera] | None = None,
    contour: float = 1.0,
    pull: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """A candidate's box made consistent with the view: ``(lo (3,), hi (3,))``, metres.

    1. joined with the seen points' box, its front face set to ``front``;
    2. no face beyond :data:`REACH` ``/ max(contour, REACH_FLOOR)`` times the seen extent from the opposite seen
       face: a camera's view of a convex fruit shows about half its extent along every axis (front to rim
       in depth, a little less under perspective: a ball's rim lies ``r^2 / d`` in front of its centre;
       the whole silhouette across); where the seen edge is partly a cut (``contour`` < 1) less may be
       seen. This only stops runaway fits;
    3. with ``cone = ((u_min, v_min, u_max, v_max), camera)``, the silhouette's pixel box: lateral faces
       beyond the silhouette's viewing cone (widest over the box's depth range) are pulled back, by the
       share ``pull`` (default ``contour``: the whole fruit projects inside its silhouette, as far as its
       edge is a contour; with occlusion information the box is where the fruit can project at all, and
       ``pull = 1`` brings every side back to it).
    """
    if (jit := compiled()) is not None:  # the compiled twin of what follows (issue 19, nineteenth round)
        arrays = [np.asarray(x, dtype=np.float64) for x in (lo, hi, seen_lo, seen_hi)]
        if all(x.shape == (3,) for x in arrays):
            if cone is None:
                box, intrinsics, share = _NO_CONE, _NO_CONE, 0.0
            else:
                (u_lo, v_lo, u_hi, v_hi), camera = cone
                box = np.array((u_lo, v_lo, u_hi, v_hi), dtype=np.float64)
                intrinsics = np.array((camera.cx, camera.cy, camera.fx, camera.fy), dtype=np.float64)
                share = float(contour if pull is None else pull)
            out = jit.constrain_box(*arrays, float(front), REACH / max(contour, REACH_FLOOR), box, intrinsics, share)
            return out[0], out[1]
    # Component by component in Python floats (issue 19, sixteenth round): the arithmetic of numpy's (3,) arrays
    # (np.minimum / np.maximum as _lesser / _greater: NaN carried, the second of equals), without some 40 numpy
    # calls' overhead on three numbers (about 40 calls a frame).
    s_lo = np.asarray(seen_lo, dtype=np.float64).tolist()
    s_lo[2] = float(front)
    s_hi = [_greater(a, b) for a, b in zip(np.asarray(seen_hi, dtype=np.float64).tolist(), s_lo, strict=True)]
    scale = REACH / max(contour, REACH_FLOOR)
    reach = [scale * (a - b) for a, b in zip(s_hi, s_lo, strict=True)]
    out_lo = [_lesser(_greater(a, h - r), s) for a, h, r, s in
              zip(np.asarray(lo, dtype=np.float64).tolist(), s_hi, reach, s_lo, strict=True)]  # fmt: skip
    out_hi = [_greater(_lesser(a, s + r), h) for a, s, r, h in
              zip(np.asarray(hi, dtype=np.float64).tolist(), s_lo, reach, s_hi, strict=True)]  # fmt: skip
    out_lo[2] = float(front)
    out_hi[2] = float(max(out_hi[2], front + 1e-4))
    if cone is not None:
        (u_lo, v_lo, u_hi, v_hi), camera = cone
        z0, z1 = out_lo[2], out_hi[2]
        a, b = (u_lo - camera.cx) / camera.fx, (v_lo - camera.cy) / camera.fy
        bound_lo = (_lesser(a * z0, a * z1), _lesser(b * z0, b * z1))  # each row's .min() of the two depths
        a, b = (u_hi - camera.cx) / camera.fx, (v_hi - camera.cy) / camera.fy
        bound_hi = (_greater(a * z0, a * z1), _greater(b * z0, b * z1))
        share = contour if pull is None else pull
        for i in range(2):
            out_lo[i] = float(_lesser(s_lo[i], out_lo[i] + share * _greater(bound_lo[i] - out_lo[i], 0.0)))
            out_hi[i] = float(_greater(s_hi[i], out_hi[i] - share * _greater(out_hi[i] - bound_hi[i], 0.0)))
    return np.array(out_lo), np.array(out_hi)


#: No silhouette box for :func:`symfruit.core._jit.constrain_box` (read-only).
_NO_CONE = np.empty(0)
_NO_CONE.flags.writeable = False


def _lesser(a: float, b: float) -> float:
    """``np.minimum`` of two numbers: NaN where either is, ``b`` where they are equal (as for signed zeros)."""
    return a if a < b or a != a else b


def _greater(a: float, b: float) -> float:
    """``np.maximum`` of two numbers: NaN where either is, ``b`` where they are equal."""
    return a if a > b or a != a else b


def _floats(x: np.ndarray | list[float]) -> list[float]:
    """A (3,) box corner as three Python floats (a list of them as it is)."""
    return x if isinstance(x, list) else np.asarray(x, dtype=np.float64).tolist()


def _plausible(lo: np.ndarray | list[float], hi: np.ndarray | list[float], seen_lo: np.ndarray | list[float],
               seen_hi: np.ndarray | list[float], reach: tuple[float, float], *, lateral: bool = True,
               width: float = 0.0) -> bool:  # fmt: skip
    """Whether a box could be the fruit's: its hidden depth beyond the deepest seen point at most
    ``reach[1]`` times the seen box's largest lateral side (or ``width``, the silhouette's, when larger), and
    (``lateral``) no lateral face beyond the seen box by more than ``reach[0]`` times the seen extent along that
    axis. Each corner a (3,) float array or a list of its three values as Python floats (``tolist()``'s, made once
    by the caller; issue 19, stop 45)."""
    # In Python floats (issue 19, nineteenth round): the same differences and products as numpy's on the (3,)
    # arrays, np.maximum as _greater
    (l0, l1, _), (h0, h1, h2) = _floats(lo), _floats(hi)
    (s0, s1, _), (t0, t1, t2) = _floats(seen_lo), _floats(seen_hi)
    seen = (t0 - s0, t1 - s1)
    if h2 - t2 > reach[1] * max(seen[0], seen[1], width):
        return False
    if lateral:
        return _greater(s0 - l0, h0 - t0) <= reach[0] * seen[0] and _greater(s1 - l1, h1 - t1) <= reach[0] * seen[1]
    return True


def candidates(
    points: np.ndarray,
    *,
    sample: np.ndarray,
    obs: Observation,
    camera: Camera,
    front: float,
    mirror: Mapping[str, Any] | None = None,
    view: View | None = None,
    revolution_points: int = 600,
    revolution_coarse: int = 64,
    steps: int = 24,
    shapes: tuple[str, ...] = SHAPES,
    explained: float | None = None,
    region: Silhouette | None = None,
    outline_profile: str = "off",
    plausible: tuple[float, float] | None = None,
    width: float = 0.0,
    seen: tuple[np.ndarray, np.ndarray] | None = None,
    sections: float = 0.0,
) -> list[Candidate]:
    """Fit and measure every candidate of one view.

    Parameters
    ----------
    points : (n, 3) float, metres
        All seen points (their box bounds every candidate's box).
    sample : (m, 3) float, metres
        A spread subset the shapes are fitted to.
    obs : Observation
        The view reduced for :func:`~symfruit.core.agreement.explain`.
    camera : Camera
    front : float, metres
        The shared front depth (nearest surface point).
    mirror : mapping, optional
        Keyword options of :func:`~symfruit.core.symmetry.complete_by_symmetry` for the mirror candidate
        (fitted to ``sample``); None leaves it out.
    view : View, optional
        ``sample`` rasterised, for the mirror candidate (made when needed).
    revolution_points : int
        The solid of revolution is fitted to at most this many points of ``sample``.
    revolution_coarse : int
        Directions of its coarse axis search over the hemisphere (besides the ellipsoids' axes).
    steps : int
        Ray-march steps of the evidence.
    shapes : tuple of str
        The closed candidates to fit, of :data:`SHAPES`.
    region : Silhouette, optional
        The seen region, for the ``outline`` candidate.
    outline_profile : {"off", "add", "replace"}
        With ``region``: add the ``outline`` candidate, replace the solid of revolution's profile with the
        outline's, or neither.
    plausible : (float, float), optional
        ``(lateral, depth)``: a closed candidate whose fitted box reaches beyond the seen box by more than
        ``lateral`` seen extents on a lateral side (not checked when ``obs.extent`` bounds where the fruit can
        project), or whose back lies more than ``depth`` times the seen box's largest lateral side behind
        the deepest seen point, is left out: implausible for what was seen (a runaway fit).
    width : float, metres
        The silhouette's larger width across the line of sight, when it is known to be wider than the seen
        points (a fruit's mask whose rim holds no depth, or whose part behind a leaf the mask covers): the
        hidden depth is measured against it where it is larger than the seen box's largest lateral side.
    explained : float, optional
        When the ``cone`` ellipsoid gets at most this share of the silhouette-band rays wrong, the view is
        explained and the solid of revolution is not fitted (no other shape can explain the outline better).
    seen : ((3,), (3,)) float, metres, optional
        :func:`~symfruit.core.points.bounds` of ``points``, when the caller has them (not read again; issue 19,
        stop 42).
    sections : float in [0, 1]
        How far the solid of revolution's sections go from circles towards the depth-over-width ratio the view
        shows (:func:`section_ratio`; refitted squashed across its axis, clipped to :data:`SECTION_CLIP`): 0
        circles (as before stop 47); meant for clouds whose seen edge lies at the sections' widest (the paper's
        visibility cut), not for a camera's rim, which perspective puts in front of it.

    Returns
    -------
    list of Candidate, in the order sphere, ellipsoid, cone, revolution, [mirror,] raw (a shape whose fit
    fails or runs away is left out).
    """
    points = as_points(points, min_count=4)
    sample = as_points(sample, min_count=4, name="sample")
    seen_lo, seen_hi = bounds(points) if seen is None else seen
    extent = float((seen_hi - seen_lo).max())
    pull: float | None = None
    if obs.extent is not None:
        # With occlusion information: as far as the fruit can project (the seen region and what may hide it).
        u_lo, v_lo, u_hi, v_hi = (float(x) for x in obs.extent)
        cone, pull = ((u_lo, v_lo, u_hi, v_hi), camera), 1.0
    else:  # the seen points' pixel box
        cone = (_projected_box(points, max(1, len(points) // 4000), camera), camera)
    fit = _Fitting(sample, obs, camera, front, extent, region, outline_profile, revolution_points,
                   revolution_coarse, sections=sections)  # fmt: skip
    constrain = _constrainer(seen_lo, seen_hi, front, cone, obs.contour, pull)
    out: list[Candidate] = []
    seen_floats = _floats(seen_lo), _floats(seen_hi)  # once for every candidate's plausibility
    for name, (fitter, failures) in _FITTERS.items():
        if name not in shapes or _explained(out, explained):
            continue
        try:
            for shape in fitter(fit):
                lo, hi = np.asarray(shape.lo, dtype=np.float64), np.asarray(shape.hi, dtype=np.float64)
                lo_, hi_ = lo.tolist(), hi.tolist()  # Python floats: the same tests as numpy's on (3,) arrays
                finite = all(map(math.isfinite, lo_)) and all(map(math.isfinite, hi_))
                if not finite or max(b - a for a, b in zip(lo_, hi_, strict=True)) > 10 * extent:
                    continue  # a degenerate fit (e.g. an ellipsoid through nearly flat points)
                if plausible is not None and not _plausible(lo_, hi_, seen_floats[0], seen_floats[1], plausible,
                                                            lateral=obs.extent is None, width=width):  # fmt: skip
                    continue
                ev = explain(shape.inside, (lo, hi), obs, steps=steps)
                box = constrain(lo, hi)
                out.append(Candidate(shape.name, *box, ev, np.asarray(shape.centre, dtype=np.float64),
                                     shape.back_std))  # fmt: skip
        except failures:
            pass

    if mirror is not None:
        mirrored = complete_by_symmetry(sample, camera, **mirror, view=view)
        back = mirrored.points[len(sample) :]
        lo, hi = constrain(back.min(axis=0), back.max(axis=0))
        out.append(Candidate("mirror", lo, hi, None, 0.5 * (lo + hi)))

    lo, hi = constrain_box(seen_lo, seen_hi, seen_lo, seen_hi, front)
    out.append(Candidate("raw", lo, hi, None, 0.5 * (lo + hi)))
    return out


def _projected_box(points: np.ndarray, step: int, camera: Camera) -> tuple[float, float, float, float]:
    """``(u_min - 0.5, v_min - 0.5, u_max + 0.5, v_max + 0.5)`` of ``points[::step]`` ((n, 3) float64, n >= 1)
    projected by ``camera``: by the compiled twin :func:`symfruit.core._jit.projected_box` where numba is (one pass
    over the rows, the same values; issue 19, stop 42), else from :meth:`~symfruit.core.camera.Camera.project`."""
    if (jit := compiled()) is not None:
        box = jit.projected_box(points, step, float(camera.fx), float(camera.fy), float(camera.cx), float(camera.cy))
        u_lo, v_lo, u_hi, v_hi = box.tolist()
        return u_lo, v_lo, u_hi, v_hi
    uv = camera.project(points[::step])
    return (float(uv[:, 0].min() - 0.5), float(uv[:, 1].min() - 0.5), float(uv[:, 0].max() + 0.5),
            float(uv[:, 1].max() + 0.5))  # fmt: skip


def _constrainer(
    seen_lo: np.ndarray, seen_hi: np.ndarray, front: float, cone: tuple[tuple[float, float, float, float], Camera],
    contour: float, pull: float | None,
) -> Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:  # fmt: skip
    """``constrain_box(lo, hi, seen_lo, seen_hi, front, cone=cone, contour=contour, pull=pull)`` as a function of
    ``lo, hi``: with the kernels, their arguments but the box made once per view and the kernel called straight for
    each candidate's float64 (3,) box (the same call as :func:`constrain_box`'s, without its checks and conversions
    each time; issue 19, stop 41), else :func:`constrain_box` itself."""
    jit = compiled()
    seen = np.asarray(seen_lo), np.asarray(seen_hi)
    if jit is None or not all(x.dtype == np.float64 and x.shape == (3,) for x in seen):

        def twin(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            return constrain_box(lo, hi, seen_lo, seen_hi, front, cone=cone, contour=contour, pull=pull)

        return twin
    (u_lo, v_lo, u_hi, v_hi), camera = cone
    box = np.array((u_lo, v_lo, u_hi, v_hi), dtype=np.float64)
    intrinsics = np.array((camera.cx, camera.cy, camera.fx, camera.fy), dtype=np.float64)
    args = (seen[0], seen[1], float(front), REACH / max(contour, REACH_FLOOR), box, intrinsics,
            float(contour if pull is None else pull))  # fmt: skip
    kernel = jit.constrain_box

    def fast(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if lo.dtype == np.float64 and hi.dtype == np.float64 and lo.shape == hi.shape == (3,):
            out = kernel(lo, hi, *args)
            return out[0], out[1]
        return constrain_box(lo, hi, seen_lo, seen_hi, front, cone=cone, contour=contour, pull=pull)

    return fast


def _explained(out: list[Candidate], explained: float | None) -> bool:
    """Whether the ``cone`` ellipsoid, just fitted, gets at most ``explained`` of the band rays wrong (then no
    other shape can explain the outline better)."""
    if explained is None or not out or out[-1].name != "cone" or (ev := out[-1].agreement) is None:
        return False
    return ev.inside + ev.outside <= explained


@dataclass
class _Fitting:
    """What every shape's fitter reads; ``axes`` collects the ellipsoids' axes for the solid of revolution's
    axis search."""

    sample: np.ndarray
    obs: Observation
    camera: Camera
    front: float
    extent: float
    region: Silhouette | None
    outline_profile: str
    revolution_points: int
    revolution_coarse: int
    axes: list[np.ndarray] = field(default_factory=list)
    cloud: ScaledCloud | None = None
    sections: float = 0.0

    def scaled(self) -> ScaledCloud:
        """:func:`~symfruit.core.fits.scaled_cloud` of the sample, made once for the sphere and the ellipsoid (issue
        19, twentieth round)."""
        if self.cloud is None:
            self.cloud = scaled_cloud(self.sample)
        return self.cloud


@dataclass(frozen=True)
class _Shape:
    """A fitted closed shape: its own box (before :func:`constrain_box`), inside test and centre."""

    name: str
    lo: np.ndarray
    hi: np.ndarray
    inside: Inside
    centre: np.ndarray
    back_std: float = float("nan")


_EYE3 = np.eye(3)
_EYE3.flags.writeable = False


def _sphere(fit: _Fitting) -> Iterator[_Shape]:
    c, r = fit_sphere(fit.sample, scaled=fit.scaled(), tolerance=SPHERE_TOLERANCE)
    yield _Shape("sphere", c - r, c + r, Quadric(c, _EYE3 / r**2), c)  # np.eye(3)'s values, made once


def _ellipsoid(fit: _Fitting) -> Iterator[_Shape]:
    ce, shape = fit_ellipsoid(fit.sample, scaled=fit.scaled())
    with np.errstate(invalid="ignore"):
        half = ellipsoid_half_extents(shape)
    fit.axes.append(lapack.eigh(shape)[1].T)
    yield _Shape("ellipsoid", ce - half, ce + half, Quadric(ce, shape), ce)


def _cone(fit: _Fitting) -> Iterator[_Shape]:
    obs = fit.obs
    if obs.cone is None or obs.axis is None or obs.interior is None or len(obs.interior) < 8:
        return
    found = fit_cone_ellipsoid(obs.interior, cone=obs.cone, axis=obs.axis, front=fit.front, extent=fit.extent)
    cc, cs = found.centre, found.shape
    ch = np.sqrt(cs.diagonal())  # np.diag's values
    inv = lapack.inv(cs)
    fit.axes.append(lapack.eigh(cs)[1].T)
    yield _Shape("cone", cc - ch, cc + ch, Quadric(cc, inv), cc, found.back_std)


def _revolution(fit: _Fitting) -> Iterator[_Shape]:
    rev = fit_revolution_slices(fit.sample[:: max(1, len(fit.sample) // fit.revolution_points)],
                                extra_directions=np.concatenate(fit.axes) if fit.axes else None,
                                coarse=fit.revolution_coarse)  # fmt: skip
    if fit.sections > 0.0:
        rev = _sectioned(fit, rev)
    if fit.region is not None and fit.outline_profile != "off":
        region = fit.region
        r_out = outline_radii(rev, region.mask, (region.u0, region.v0), fit.camera, hidden=fit.obs.hidden_map())
        shaped = replace(rev, radii=np.where(np.isfinite(r_out) & np.isfinite(rev.radii), r_out, rev.radii))
        if fit.outline_profile == "replace":
            rev = shaped
        else:
            olo, ohi, *profile = box_and_profile(shaped)
            yield _Shape("outline", olo, ohi, RevolutionInside(shaped, profile=(profile[0], profile[1])),
                         0.5 * (olo + ohi))  # fmt: skip
    lo, hi, t, r = box_and_profile(rev)  # the box and the profile its march reads, in one call (issue 19, stop 41)
    yield _Shape("revolution", lo, hi, RevolutionInside(rev, profile=(t, r)), 0.5 * (lo + hi))


#: The section ratio :func:`candidates`' ``sections`` may move the solid of revolution to (its sections' depth over
#: width), after the share.
SECTION_CLIP = (0.85, 1.15)


def section_ratio(points: np.ndarray, direction: np.ndarray, *, bins: int = 8, span: float = 0.6,
                  inner: float = 0.85, min_sag: float = 0.6) -> float:  # fmt: skip
    """The depth-over-width ratio of a solid of revolution's sections as the seen points show it (issue 18, stop 47,
    docs/pearview47.md); 1 where they cannot tell.

    The points (n, 3), metres, the camera at the origin looking along +z, are sliced by planes along the line of
    sight across ``direction``'s image direction (``bins`` slices over the middle ``span`` of the points along it).
    In each slice the lateral extremes give the half-width ``a`` and the middle (both as quadratics along the axis,
    so that the profile's change within a slice does not read as depth), and the depths are fitted as ``z = z_c - B
    sqrt(1 - u^2)``, ``u`` the lateral offset over ``a`` (points beyond ``inner`` of it left out: a sparse sample's
    extremes fall short of the widest point, where ``u`` is most sensitive). That presumes the seen edge lies at the
    sections' widest (``z_c``): the paper's visibility cut through the axis, an orthographic view's rim. The
    slices' ``z_c`` along the axis give its tilt out of the image plane, and each slice's ratio is ``B cos(tilt) /
    a``; the result is their median weighted by points and width. A slice seen less than ``min_sag`` of its
    half-width deep (a cap cut off near its front) is left out. With the axis within 60 degrees of the line of
    sight or fewer than three slices left, 1.
    """
    q = np.asarray(points, dtype=np.float64)
    d = np.asarray(direction, dtype=np.float64)
    n = float(np.hypot(d[0], d[1]))
    if n < 0.5 or len(q) < 3 * bins:
        return 1.0
    e = d[:2] / n
    q = q - q.mean(axis=0)
    s, t, z = q[:, :2] @ e, q[:, :2] @ np.array([-e[1], e[0]]), q[:, 2]
    lo, hi = np.quantile(s, [0.5 - 0.5 * span, 0.5 + 0.5 * span])
    if not hi > lo:
        return 1.0
    idx = np.floor((s - lo) / (hi - lo) * bins).astype(np.int64)
    keep = (idx >= 0) & (idx < bins)
    idx, s, t, z = idx[keep], s[keep], t[keep], z[keep]
    count = np.bincount(idx, minlength=bins)
    order = np.lexsort((t, idx))  # by slice, then across: each slice's first and last are its extremes
    first = order[np.minimum(np.searchsorted(idx[order], np.arange(bins)), len(t) - 1)]
    last = order[np.maximum(np.searchsorted(idx[order], np.arange(bins), side="right") - 1, 0)]
    good = count >= 8
    a, mid, at = 0.5 * (t[last] - t[first]), 0.5 * (t[last] + t[first]), 0.5 * (s[first] + s[last])
    good &= a > 0.0
    if good.sum() < 3:
        return 1.0
    w = np.sqrt(good.astype(np.float64))
    design = np.stack([np.ones(bins), at, at * at], axis=1) * w[:, None]
    ca = np.linalg.lstsq(design, np.where(good, a, 0.0) * w, rcond=None)[0]
    cm = np.linalg.lstsq(design, np.where(good, mid, 0.0) * w, rcond=None)[0]
    u = (t - (cm[0] + cm[1] * s + cm[2] * s * s)) / np.maximum(ca[0] + ca[1] * s + ca[2] * s * s, 1e-9)
    root = np.sqrt(np.clip(1.0 - u * u, 0.0, 1.0))
    m = (np.abs(u) < inner).astype(np.float64)
    s1, sw, sww = np.bincount(idx, m, bins), np.bincount(idx, root * m, bins), np.bincount(idx, root * root * m, bins)
    sz, swz = np.bincount(idx, z * m, bins), np.bincount(idx, root * z * m, bins)
    det = s1 * sww - sw * sw
    good &= det > 1e-12 * np.maximum(s1, 1.0) ** 2
    det = np.where(good, det, 1.0)
    zc, depth = (sww * sz - sw * swz) / det, (sw * sz - s1 * swz) / det
    centre = np.bincount(idx, s, bins) / np.maximum(count, 1)
    half = ca[0] + ca[1] * centre + ca[2] * centre * centre
    z_lo, z_hi = np.full(bins, np.inf), np.full(bins, -np.inf)
    np.minimum.at(z_lo, idx, z)
    np.maximum.at(z_hi, idx, z)
    good &= (half > 0.3 * float(np.where(good, a, 0.0).max())) & (z_hi - z_lo > min_sag * half)
    if good.sum() < 3:
        return 1.0
    weight = count * good
    w = np.sqrt(weight.astype(np.float64))
    slope = float(np.linalg.lstsq(np.stack([np.ones(bins), centre], axis=1) * w[:, None], zc * w, rcond=None)[0][1])
    ratio = depth / np.where(good, half, 1.0) / math.sqrt(1.0 + slope * slope)
    ranked = np.argsort(np.where(good, ratio, np.inf))
    total = np.cumsum((weight * np.where(good, half, 0.0))[ranked])
    return float(ratio[ranked][np.searchsorted(total, 0.5 * total[-1])])


def _sectioned(fit: _Fitting, rev: Revolution) -> Revolution:
    """``rev`` refitted with the sections :func:`section_ratio` reads, ``fit.sections`` of the way from circles,
    squashed across its axis only (the line of sight's part perpendicular to it: its length is not squashed, as
    :func:`~symfruit.core.fits.fit_revolution_slices`' ``ratio`` would along the line of sight); ``rev`` where they
    are near circles, the axis is near the line of sight, or the refit's back moves against its sections (flatter
    and deeper: another axis found)."""
    pts = fit.sample[:: max(1, len(fit.sample) // fit.revolution_points)]
    k = 1.0 + fit.sections * (section_ratio(pts, rev.direction) - 1.0)
    k = min(max(k, SECTION_CLIP[0]), SECTION_CLIP[1])
    centre = pts.mean(axis=0)
    deep = centre / max(float(np.linalg.norm(centre)), 1e-12)
    deep = deep - float(deep @ rev.direction) * rev.direction
    size = float(np.linalg.norm(deep))
    if abs(k - 1.0) <= 0.02 or size < 0.3:
        return rev
    deep = deep / size
    q = pts - centre
    found = fit_revolution_slices(centre + q + np.multiply.outer((1.0 / k - 1.0) * (q @ deep), deep),
                                  extra_directions=np.concatenate(fit.axes) if fit.axes else None,
                                  coarse=fit.revolution_coarse)  # fmt: skip
    p = found.point - centre
    out = Revolution(centre + p + (k - 1.0) * float(p @ deep) * deep, found.direction, found.edges, found.radii,
                     found.cost, k, deep)  # fmt: skip
    # flatter sections make the solid no deeper, rounder ones no shallower: else the refit found another axis
    # (a runaway the circles' own fit was spared), and the circles stand
    moved = float(box_and_profile(out)[1][2] - box_and_profile(rev)[1][2])
    return out if moved * (k - 1.0) >= 0.0 else rev


_Fitter = Callable[[_Fitting], Iterator[_Shape]]
_LINALG: tuple[type[Exception], ...] = (InputError, np.linalg.LinAlgError)

#: Each closed shape's fitter, in :data:`SHAPES` order, and the errors that leave it out (a failed fit, or its
#: measurement, drops that shape and what it had still to yield): a fitter yields the shapes it fits (the
#: solid of revolution may yield the ``outline`` one first).
_FITTERS: dict[str, tuple[_Fitter, tuple[type[Exception], ...]]] = {
    "sphere": (_sphere, (InputError,)),
    "ellipsoid": (_ellipsoid, _LINALG),
    "cone": (_cone, _LINALG),
    "revolution": (_revolution, (InputError,)),
}
