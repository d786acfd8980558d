"""The built-in segmenter: ripe red fruit by colour, split where fruit touch. No weights needed.

Steps: HSV thresholds (red hue, enough saturation and brightness, so white and green unripe fruit and
the green calyx fall out), an opening and a closing, connected components, splitting of touching fruit
at depth discontinuities and by a distance-transform watershed where a region has a waist, and removal
of regions too small to be a fruit at their depth.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy import ndimage

from .core.camera import Camera
from .settings import Section, register_section, setting

__all__ = ["SegmentSettings", "red_mask", "segment"]

#: Largest morphology or smoothing radius a setting may ask for (pixels).
MAX_RADIUS_PX = 50


@dataclass(frozen=True)
class SegmentSettings(Section):
    """The built-in colour segmenter (:mod:`symfruit.segment`): ripe red fruit, no weights needed.

    Attributes
    ----------
    hue_low, hue_high : float, degrees
        Red hues wrap around 0: a pixel is red when its hue is >= ``hue_low`` or <= ``hue_high``.
    sat_min, val_min : float in [0, 1]
        Least saturation and value (brightness) of a ripe fruit pixel; unripe (white, green) fruit fail.
    open_px, close_px : int
        Radii of the disc opening (removes specks) and closing (fills seeds, glints and the gaps
        thin stems cut).
    min_diameter : float, metres
        Regions smaller than a fruit of this diameter would look at their depth are ignored.
    split : {"both", "depth", "watershed", "none"}
        How touching fruit are split: at depth discontinuities, by a distance-transform watershed
        when the region has a waist, both, or not at all.
    depth_jump : float, metres
        A depth step between neighbouring pixels larger than this separates two fruit.
    crease_curvature : float, 1/metres
        A seam between touching fruit at the same depth shows as a concave crease of the depth
        surface: the smoothed depth's Laplacian below ``-crease_curvature`` (in metres per metre
        squared) separates fruit. Convex fruit surfaces never reach it.
    crease_sigma : float, pixels
        Smoothing of the depth before the crease test (the sensor noise must not look like creases).
    waist : float
        Split two distance-transform peaks only if the region between them narrows below this share
        of the smaller peak's width.
    """

    hue_low: float = setting(340.0, ge=0.0, le=360.0)
    hue_high: float = setting(15.0, ge=0.0, le=360.0)
    sat_min: float = setting(0.45, ge=0.0, le=1.0)
    val_min: float = setting(0.15, ge=0.0, le=1.0)
    open_px: int = setting(1, ge=0, le=MAX_RADIUS_PX)
    close_px: int = setting(2, ge=0, le=MAX_RADIUS_PX)
    min_diameter: float = setting(0.012, gt=0.0, le=1.0)
    split: Literal["both", "depth", "watershed", "none"] = setting("both")
    depth_jump: float = setting(0.015, gt=0.0, le=10.0)
    crease_curvature: float = setting(1500.0, gt=0.0, le=1e7)
    crease_sigma: float = setting(2.0, ge=0.0, le=MAX_RADIUS_PX)
    waist: float = setting(0.75, gt=0.0, le=1.0)


register_section("segment", SegmentSettings)


def red_mask(color: np.ndarray, settings: SegmentSettings | None = None) -> np.ndarray:
    """(h, w) bool: pixels whose colour is ripe-fruit red."""
    from PIL import Image

    s = settings or SegmentSettings()
    hsv = np.asarray(Image.fromarray(color).convert("HSV"))
    hue = hsv[:, :, 0].astype(np.float32) * (360.0 / 256.0)
    red = (hue >= s.hue_low) | (hue <= s.hue_high)
    return red & (hsv[:, :, 1] >= s.sat_min * 255) & (hsv[:, :, 2] >= s.val_min * 255)


def _disc(r: int) -> np.ndarray:
    yy, xx = np.mgrid[-r : r + 1, -r : r + 1]
    return xx * xx + yy * yy <= r * r


def _window(mask: np.ndarray, pad: int) -> tuple[slice, slice] | None:
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if len(rows) == 0:
        return None
    h, w = mask.shape
    return (slice(max(rows[0] - pad, 0), min(rows[-1] + pad + 1, h)),
            slice(max(cols[0] - pad, 0), min(cols[-1] + pad + 1, w)))  # fmt: skip


def segment(
    color: np.ndarray, depth: np.ndarray, camera: Camera, settings: SegmentSettings | None = None
) -> np.ndarray:
    """Instance labels of the ripe fruit in a frame.

    Parameters
    ----------
    color : (h, w, 3) uint8
    depth : (h, w) float, metres (0 = no depth)
    camera : Camera
    settings : SegmentSettings

    Returns
    -------
    (h, w) int32: 0 background, 1..k the fruit, numbered left to right.
    """
    s = settings or SegmentSettings()
    red = red_mask(color, s)
    mask = np.zeros_like(red)
    window = _window(red, pad=2 * (s.open_px + s.close_px) + 2)
    if window is not None:  # morphology only where there is red: the rest of the image stays empty
        part = red[window]
        if s.open_px:
            part = ndimage.binary_opening(part, structure=_disc(s.open_px))
        if s.close_px:
            part = ndimage.binary_closing(part, structure=_disc(s.close_px)) | part
        mask[window] = part
    labels, _ = ndimage.label(mask)
    out = np.zeros(mask.shape, np.int32)
    next_id = 1
    for k, sl in enumerate(ndimage.find_objects(labels), 1):
        if sl is None:
            continue
        sl = (slice(max(sl[0].start - 1, 0), sl[0].stop + 1), slice(max(sl[1].start - 1, 0), sl[1].stop + 1))
        region = labels[sl] == k
        # Depth is trusted only on red pixels: pixels the closing added may be stems or leaves in front.
        parts = _split(region, np.where(red[sl], depth[sl], 0.0), s, camera)
        for part in parts:
            if _big_enough(part, depth[sl], s, camera):
                out[sl][part] = next_id
                next_id += 1
    return _renumber(out, next_id - 1)


def _split(region: np.ndarray, depth: np.ndarray, s: SegmentSettings, camera: Camera) -> list[np.ndarray]:
    parts = [region]
    if s.split in ("depth", "both"):
        focal = float(np.sqrt(camera.fx * camera.fy))
        parts = [p for part in parts for p in _split_depth(part, depth, s, focal)]
    if s.split in ("watershed", "both"):
        parts = [p for part in parts for p in _split_waist(part, s)]
    return parts


def _creases(region: np.ndarray, depth: np.ndarray, s: SegmentSettings, focal: float) -> np.ndarray:
    """Concave creases of the depth surface: where two convex fruit meet, depth peaks across the seam.

    Fruit bulge toward the camera, so inside a fruit the smoothed depth is convex (positive
    Laplacian); the seam between two touching fruit is a sharp ridge of depth (strongly negative).
    """
    valid = region & (depth > 0)
    if valid.sum() < 20:
        return np.zeros(region.shape, bool)
    _, (ri, ci) = ndimage.distance_transform_edt(~valid, return_indices=True)
    filled = depth[ri, ci].astype(np.float64)
    smooth = ndimage.gaussian_filter(filled, s.crease_sigma)
    lap = ndimage.laplace(smooth)
    z = float(np.median(depth[valid]))
    threshold = s.crease_curvature * (z / focal) ** 2  # metres per pixel^2 at this depth
    return region & (lap < -threshold)


def _split_depth(region: np.ndarray, depth: np.ndarray, s: SegmentSettings, focal: float) -> list[np.ndarray]:
    """Cut a region along depth steps larger than ``depth_jump`` and along concave creases."""
    z = np.where(region & (depth > 0), depth, np.nan)
    edge = _creases(region, depth, s, focal)
    for axis in (0, 1):
        dz = np.abs(np.diff(z, axis=axis))
        step = np.nan_to_num(dz, nan=0.0) > s.depth_jump
        if axis == 0:
            edge[:-1] |= step
            edge[1:] |= step
        else:
            edge[:, :-1] |= step
            edge[:, 1:] |= step
    core, n = ndimage.label(region & ~edge)
    if n < 2:
        return [region]
    sizes = ndimage.sum(np.ones_like(core), core, index=np.arange(1, n + 1))
    keep = np.flatnonzero(sizes >= max(20, 0.1 * sizes.max())) + 1
    if len(keep) < 2:
        return [region]
    seeds = np.where(np.isin(core, keep), core, 0)
    _, (ri, ci) = ndimage.distance_transform_edt(seeds == 0, return_indices=True)
    grown = np.where(region, seeds[ri, ci], 0)
    return [grown == k for k in keep]


def _split_waist(region: np.ndarray, s: SegmentSettings) -> list[np.ndarray]:
    """Split a region at a waist between distance-transform peaks (touching round fruit)."""
    edt = ndimage.distance_transform_edt(np.pad(region, 1))[1:-1, 1:-1]
    top = edt.max()
    if top < 3:
        return [region]
    size = max(3, int(top) | 1)
    peaks = (edt == ndimage.maximum_filter(edt, size=size)) & (edt >= 0.5 * top)
    pr, pc = np.nonzero(peaks)
    order = np.argsort(-edt[pr, pc])
    chosen: list[tuple[int, int]] = []
    for i in order:
        p = (int(pr[i]), int(pc[i]))
        if all(not _same_blob(edt, p, q, s.waist) for q in chosen):
            chosen.append(p)
    if len(chosen) < 2:
        return [region]
    # Each pixel goes to the peak whose inscribed disc it lies deepest in (distance / disc radius):
    # for touching round fruit the cut falls at the waist.
    rows, cols = np.nonzero(region)
    peaks = np.array(chosen, dtype=np.float64)
    radii = edt[peaks[:, 0].astype(int), peaks[:, 1].astype(int)]
    d = np.hypot(rows[:, None] - peaks[None, :, 0], cols[:, None] - peaks[None, :, 1]) / radii[None, :]
    owner = np.argmin(d, axis=1)
    parts = []
    for k in range(len(chosen)):
        part = np.zeros(region.shape, bool)
        part[rows[owner == k], cols[owner == k]] = True
        parts.append(part)
    return parts


def _same_blob(edt: np.ndarray, p: tuple[int, int], q: tuple[int, int], waist: float) -> bool:
    """Whether two peaks belong to one fruit: no waist narrower than ``waist`` x the smaller peak."""
    n = int(np.hypot(p[0] - q[0], p[1] - q[1])) + 2
    rows = np.rint(np.linspace(p[0], q[0], n)).astype(int)
    cols = np.rint(np.linspace(p[1], q[1], n)).astype(int)
    return bool(edt[rows, cols].min() >= waist * min(edt[p], edt[q]))


def _big_enough(part: np.ndarray, depth: np.ndarray, s: SegmentSettings, camera: Camera) -> bool:
    z = depth[part & (depth > 0)]
    if len(z) == 0:
        return False
    diameter_px = np.sqrt(camera.fx * camera.fy) * s.min_diameter / float(np.median(z))
    return part.sum() >= np.pi / 4 * diameter_px**2


def _renumber(labels: np.ndarray, n: int) -> np.ndarray:
    """Number fruit left to right (then top to bottom) by their box centres, for stable ids."""
    if n == 0:
        return labels
    slices = ndimage.find_objects(labels, max_label=n)
    centres = [((sl[1].start + sl[1].stop) / 2, (sl[0].start + sl[0].stop) / 2) for sl in slices]
    order = sorted(range(n), key=lambda i: (round(centres[i][0] / 20), centres[i][1]))
    lut = np.zeros(n + 1, np.int32)
    for new, i in enumerate(order, 1):
        lut[i + 1] = new
    return lut[labels]
