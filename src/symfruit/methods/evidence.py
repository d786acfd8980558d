"""``evidence``: the default method. The candidate completions that best explain what the camera saw.

Why: a sphere is right for round fruit and wrong for a pear; a solid of revolution is right for a pear
and can take the wrong axis on a near-round tomato; a general ellipsoid fitted to a noisy partial view
comes out too thin; mirror symmetry (the paper) is blind to how deep its plane should be. No single
completion is right for every fruit, and the view itself says which ones fit. This method

1. estimates the front depth from a quadric fitted around the nearest part of the surface
   (:func:`~symfruit.core.front.apex_depth`; the noisy minimum of a D435's depths sits 3-4 mm in front of
   the fruit), shared by every candidate;
2. fits the candidates of :mod:`symfruit.core.candidates` (sphere, ellipsoid, solid of revolution,
   optionally the mirror completion, and the raw box);
3. measures every closed candidate against the view (:func:`~symfruit.core.evidence.explain`): its
   predicted silhouette against the seen one, its predicted front depth against the seen depth;
4. weighs the candidates by ``exp(-energy)``: for a closed candidate ``depth_weight * (rms / best rms - 1)
   + silhouette_weight * (inside + contour * outside)``, for the mirror and raw candidates a fixed energy
   (they reproduce the view by construction, so the view cannot rank them; only the closed shapes'
   failure to explain it can), and takes the weighted median of every box face (robust to one wrong
   candidate, unlike a mean);
5. reports a confidence from how well the best closed shape explains the silhouette and how far the
   weighted candidates agree.

No fruit profile is needed: nothing in it depends on the kind of fruit. The design and the ablation
behind every constant are in ``docs/ablation.md``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.box import Box
from ..core.camera import Camera
from ..core.candidates import Candidate, candidates
from ..core.evidence import observe
from ..core.front import apex_depth
from ..core.raster import silhouette
from ..settings import Section, SettingError, setting
from .paper import PaperSettings
from .registry import Completion, register

__all__ = ["Combined", "EvidenceSettings", "combine"]


@dataclass(frozen=True)
class EvidenceSettings(Section):
    """Settings of the default ``evidence`` method.

    Attributes
    ----------
    fit_points : int
        Shapes are fitted to a fixed random subset of at most this many points (the box and the
        silhouette use every point).
    revolution_points : int
        The solid of revolution is fitted to at most this many of them.
    rays, band_rays : int
        Depth rays sampled over the seen points, and rays per silhouette band and side.
    march_steps : int
        Ray-march steps per ray through each candidate.
    depth_weight, silhouette_weight : float
        Energy per unit of relative depth misfit (``rms / best rms - 1``) and per unit share of
        silhouette-band rays a closed candidate gets wrong.
    mirror_energy, raw_energy : float
        Fixed energies of the mirror and raw candidates.
    silhouette_scale, spread_scale : float
        Confidence ``exp(-e / silhouette_scale) * exp(-spread / (spread_scale * size))``, ``e`` the best
        closed candidate's share of silhouette-band rays wrong, ``spread`` the weighted mean distance of
        the candidates' centres from the result's, ``size`` the result's largest side.
    reliable_at : float
        ``reliable`` when the confidence is at least this.
    mirror_candidate : bool
        Add the mirror completion as a candidate (off by default: ~3 ms per fruit for means that moved
        by less than 0.1 mm in the ablation).
    mirror : PaperSettings
        The mirror candidate's grid and rating: 8 depth offsets of 0.1 ``len_depth`` and the reasonable
        region 0.4-1.0 ``Dist_ref`` (the paper's 4 x 0.2 stops short of the symmetry plane of a shallow
        view), rated on 400 points.
    """

    fit_points: int = setting(1000, ge=20, le=1_000_000)
    revolution_points: int = setting(600, ge=20, le=1_000_000)
    rays: int = setting(160, ge=8, le=100_000)
    band_rays: int = setting(64, ge=4, le=100_000)
    march_steps: int = setting(24, ge=4, le=1000)
    depth_weight: float = setting(1.0, ge=0.0, le=1e6)
    silhouette_weight: float = setting(5.0, ge=0.0, le=1e6)
    mirror_energy: float = setting(5.0, ge=0.0, le=1e6)
    raw_energy: float = setting(3.0, ge=0.0, le=1e6)
    silhouette_scale: float = setting(0.15, gt=0.0, le=100.0)
    spread_scale: float = setting(0.1, gt=0.0, le=100.0)
    reliable_at: float = setting(0.25, ge=0.0, le=1.0)
    mirror_candidate: bool = setting(False)
    mirror: PaperSettings = setting(
        PaperSettings(translations=8, translation_step=0.1, j2=0.4, j3=1.0, rating_points=400)
    )

    def check(self) -> None:
        if not isinstance(self.mirror, PaperSettings):
            raise SettingError("mirror", f"must be a paper settings section, got {type(self.mirror).__name__}")
        if self.revolution_points > self.fit_points:
            raise SettingError("revolution_points", "must be <= fit_points")


@dataclass(frozen=True)
class Combined:
    """The weighted completion of one view.

    Attributes
    ----------
    box : Box
    weights, energies : dict of str to float
        Per candidate.
    confidence : float in [0, 1]
    spread : float, metres
        Weighted mean distance of the candidates' box centres from the result's.
    explained : float in [0, 1]
        Share of silhouette-band rays the best closed candidate gets right.
    contour : float in [0, 1]
        The observation's contour share.
    """

    box: Box
    weights: dict[str, float]
    energies: dict[str, float]
    confidence: float
    spread: float
    explained: float
    contour: float


def _weighted_median(values: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Weighted (lower) median of each column of ``values`` (k, m) with weights (k,), vectorised."""
    order = np.argsort(values, axis=0)
    cw = np.cumsum(weights[order], axis=0)
    pick = np.argmax(cw >= 0.5 * weights.sum(), axis=0)
    return np.take_along_axis(values, np.take_along_axis(order, pick[None, :], axis=0), axis=0)[0]


def combine(cands: list[Candidate], *, contour: float, s: EvidenceSettings) -> Combined:
    """Weigh the candidates by their evidence and take the weighted median box (see the module)."""
    closed = [c for c in cands if c.evidence is not None]
    energies: dict[str, float] = {}
    best_rms = max(min((c.evidence.depth for c in closed if c.evidence is not None), default=1.0), 1e-6)
    for c in cands:
        ev = c.evidence
        if ev is None:
            energies[c.name] = s.mirror_energy if c.name == "mirror" else s.raw_energy
        else:
            energies[c.name] = s.depth_weight * (ev.depth / best_rms - 1.0) + s.silhouette_weight * (
                ev.inside + contour * ev.outside
            )
    names = [c.name for c in cands]
    e = np.array([energies[n] for n in names])
    w = np.exp(-(e - e.min()))
    w /= w.sum()
    faces = np.array([np.r_[c.lo, c.hi] for c in cands])
    box_faces = _weighted_median(faces, w)
    box = Box(box_faces[:3], box_faces[3:])
    centres = 0.5 * (faces[:, :3] + faces[:, 3:])
    spread = float((w * np.linalg.norm(centres - box.centre, axis=1)).sum())
    wrong = min((c.evidence.inside + contour * c.evidence.outside for c in closed if c.evidence is not None),
                default=2.0)  # fmt: skip
    size = max(float(box.size.max()), 1e-9)
    confidence = float(np.exp(-wrong / s.silhouette_scale) * np.exp(-spread / (s.spread_scale * size)))
    return Combined(box, dict(zip(names, w.tolist(), strict=True)), energies, confidence, spread,
                    1.0 - wrong / 2.0, contour)  # fmt: skip


@register("evidence", settings=EvidenceSettings)
def evidence(points: np.ndarray, camera: Camera, settings: EvidenceSettings) -> Completion:
    """Candidates weighed by how well they explain the view; weighted-median box; confidence."""
    s = settings
    sample = points
    if len(points) > s.fit_points:
        sample = points[np.sort(np.random.default_rng(0).choice(len(points), s.fit_points, replace=False))]
    region = silhouette(points, camera)
    obs = observe(sample, region, camera, n_rays=s.rays, n_band=s.band_rays)
    apex, _ = apex_depth(sample)
    front = max(float(points[:, 2].min()), apex)
    cands = candidates(
        points, sample=sample, obs=obs, camera=camera, front=front,
        mirror=s.mirror.options() if s.mirror_candidate else None,
        revolution_points=s.revolution_points, steps=s.march_steps,
    )  # fmt: skip
    combined = combine(cands, contour=obs.contour, s=s)
    box = combined.box
    extras: dict[str, Any] = {
        "confidence": combined.confidence,
        "reliable": combined.confidence >= s.reliable_at,
        "weights": combined.weights,
        "energies": combined.energies,
        "spread": combined.spread,
        "explained": combined.explained,
        "contour": combined.contour,
        "candidates": {
            c.name: {
                "min": c.lo.tolist(), "max": c.hi.tolist(),
                "evidence": None if c.evidence is None else [c.evidence.depth, c.evidence.inside, c.evidence.outside],
            }
            for c in cands
        },
    }  # fmt: skip
    completed = np.vstack([points, 2.0 * box.centre - points])
    return Completion(points=completed, box=box, extras=extras)
