"""Depth registered to a colour camera: RealSense lens models and a z-buffered depth reprojection.

The lens models are librealsense's own (``include/librealsense2/rsutil.h``, ``rs2_project_point_to_pixel``
and ``rs2_deproject_pixel_to_point``), vectorised, so a recording plays the same here as in the SDK:

==========================  ==========================================================================
model                       what the coefficients ``k1, k2, p1, p2, k3`` do
==========================  ==========================================================================
``none``                    nothing (pinhole)
``brown_conrady``           forward Brown-Conrady: projection distorts (tangential terms on the ideal
                            point); deprojection undoes it with 10 fixed-point iterations
``modified_brown_conrady``  forward, tangential terms on the radially distorted point; projection only
``inverse_brown_conrady``   the coefficients map distorted to ideal: deprojection iterates 10 times
                            (librealsense's loop) and projection applies the modified forward formula,
                            exactly as the SDK does
==========================  ==========================================================================

:func:`align_depth` moves every valid depth pixel into the colour image as librealsense's ``rs2::align``
does (``src/proc/align.cpp``, ``align_images``): the pixel's top-left and bottom-right corners are
deprojected at its depth, moved by the depth-to-colour extrinsics, projected into colour and rounded, and
the colour pixels of that rectangle take the nearest depth (a z-buffer); when the depth image has at least
as many pixels per degree as colour, each depth pixel writes one colour pixel only, as the SDK's SSE path
does. A depth pixel therefore covers exactly its own footprint: pixels no depth pixel lands on (no depth,
or a disocclusion seen by colour but hidden from the depth camera) stay 0, nothing is smeared across them.
Three deliberate differences from the SDK: the value written is the point's depth *in the colour camera*
(the SDK copies the depth camera's z, off by the extrinsic's z translation and tilt; ``z="depth"`` gives
the SDK's); a footprint cut by the image border is clipped rather than dropped; and the one-pixel case
maps the pixel's centre where the SDK maps its top-left corner (half a pixel up and left). The comparison
with the SDK is in the README (RealSense recordings).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from .camera import Camera

__all__ = ["LENS_MODELS", "MAX_FOOTPRINT", "Lens", "align_depth", "deproject", "project", "transform"]

#: Distortion models understood, by librealsense's ``rs2_distortion_to_string`` name.
LENS_MODELS = {
    "None": "none",
    "Brown Conrady": "brown_conrady",
    "Modified Brown Conrady": "modified_brown_conrady",
    "Inverse Brown Conrady": "inverse_brown_conrady",
}
#: Largest side (colour pixels) of one depth pixel's footprint; larger ones (a point a few mm in front of
#: the colour camera) are dropped, as they would paint one depth over a whole patch of the image.
MAX_FOOTPRINT = 16


@dataclass(frozen=True)
class Lens:
    """A camera's intrinsics and distortion as librealsense records them.

    Parameters
    ----------
    camera : Camera
        Pinhole part: ``fx, fy`` (pixels), ``cx, cy`` (librealsense's ``ppx, ppy``), image size.
    model : str
        One of the values of :data:`LENS_MODELS` (``"none"``, ``"brown_conrady"``, ...).
    coeffs : (5,) float
        ``k1, k2, p1, p2, k3``.
    """

    camera: Camera
    model: str = "none"
    coeffs: tuple[float, ...] = field(default=(0.0, 0.0, 0.0, 0.0, 0.0))

    def __post_init__(self) -> None:
        if self.model not in LENS_MODELS.values():
            raise InputError(f"unknown lens model {self.model!r}; known: {', '.join(LENS_MODELS.values())}")
        coeffs = tuple(float(c) for c in self.coeffs)
        if len(coeffs) != 5 or not all(np.isfinite(coeffs)):
            raise InputError(f"lens coefficients must be five finite numbers (k1, k2, p1, p2, k3), got {coeffs}")
        object.__setattr__(self, "coeffs", coeffs)


def _forward(x: np.ndarray, y: np.ndarray, c: tuple[float, ...], *, modified: bool) -> tuple[np.ndarray, np.ndarray]:
    """rsutil.h's forward distortion of normalised coordinates (``modified``: tangential on ``x * f``)."""
    r2 = x * x + y * y
    f = 1 + c[0] * r2 + c[1] * r2 * r2 + c[4] * r2 * r2 * r2
    xf, yf = x * f, y * f
    tx, ty = (xf, yf) if modified else (x, y)
    dx = xf + 2 * c[2] * tx * ty + c[3] * (r2 + 2 * tx * tx)
    dy = yf + 2 * c[3] * tx * ty + c[2] * (r2 + 2 * ty * ty)
    return dx, dy


def project(lens: Lens, points: np.ndarray) -> np.ndarray:
    """Pixel coordinates of camera-frame points (``rs2_project_point_to_pixel``).

    Parameters
    ----------
    lens : Lens
    points : (n, 3) float, metres, ``z > 0``

    Returns
    -------
    (n, 2) float, pixels ``(u, v)``; non-finite where ``z == 0``.
    """
    points = np.asarray(points, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        x, y = points[:, 0] / points[:, 2], points[:, 1] / points[:, 2]
    if not any(lens.coeffs):  # every model is the identity then
        pass
    elif lens.model in ("modified_brown_conrady", "inverse_brown_conrady"):
        x, y = _forward(x, y, lens.coeffs, modified=True)
    elif lens.model == "brown_conrady":
        x, y = _forward(x, y, lens.coeffs, modified=False)
    cam = lens.camera
    return np.stack([x * cam.fx + cam.cx, y * cam.fy + cam.cy], axis=-1)


def deproject(lens: Lens, uv: np.ndarray, depth: np.ndarray) -> np.ndarray:
    """Camera-frame points of pixels at a depth (``rs2_deproject_pixel_to_point``).

    Parameters
    ----------
    lens : Lens
        Not ``modified_brown_conrady`` (librealsense cannot deproject it either).
    uv : (n, 2) float, pixels
    depth : (n,) float, metres along z

    Returns
    -------
    (n, 3) float, metres
    """
    if lens.model == "modified_brown_conrady":
        raise InputError("a 'Modified Brown Conrady' lens cannot be deprojected (librealsense refuses it too)")
    uv = np.asarray(uv, dtype=np.float64)
    cam, c = lens.camera, lens.coeffs
    x0 = (uv[:, 0] - cam.cx) / cam.fx
    y0 = (uv[:, 1] - cam.cy) / cam.fy
    x, y = x0, y0
    if lens.model in ("brown_conrady", "inverse_brown_conrady") and any(c):
        for _ in range(10):  # librealsense's fixed count ("10 iterations determined empirically")
            r2 = x * x + y * y
            icdist = 1.0 / (1 + ((c[4] * r2 + c[1]) * r2 + c[0]) * r2)
            # inverse_brown_conrady takes the tangential terms at x / icdist, brown_conrady at x itself
            xq, yq = (x / icdist, y / icdist) if lens.model == "inverse_brown_conrady" else (x, y)
            delta_x = 2 * c[2] * xq * yq + c[3] * (r2 + 2 * xq * xq)
            delta_y = 2 * c[3] * xq * yq + c[2] * (r2 + 2 * yq * yq)
            x, y = (x0 - delta_x) * icdist, (y0 - delta_y) * icdist
    depth = np.asarray(depth, dtype=np.float64)
    return np.stack([x * depth, y * depth, depth], axis=-1)


def transform(points: np.ndarray, rotation: np.ndarray, translation: np.ndarray) -> np.ndarray:
    """``rotation @ p + translation`` for each point (``rs2_transform_point_to_point``); (n, 3) metres."""
    p = np.asarray(points, dtype=np.float64)
    r, t = np.asarray(rotation, dtype=np.float64), np.asarray(translation, dtype=np.float64)
    # column by column: a (n, 3) @ (3, 3) product goes through BLAS, much slower for this shape
    return np.stack([p[:, 0] * r[i, 0] + p[:, 1] * r[i, 1] + p[:, 2] * r[i, 2] + t[i] for i in range(3)], axis=-1)


def _fov(cam: Camera) -> tuple[float, float]:
    """Horizontal and vertical field of view in degrees (``rs2_fov``)."""
    h = np.degrees(np.arctan2(cam.cx + 0.5, cam.fx) + np.arctan2(cam.width - (cam.cx + 0.5), cam.fx))
    v = np.degrees(np.arctan2(cam.cy + 0.5, cam.fy) + np.arctan2(cam.height - (cam.cy + 0.5), cam.fy))
    return float(h), float(v)


def _denser(depth: Camera, color: Camera) -> bool:
    """Whether the depth image has at least as many pixels per degree as colour, in both directions."""
    dh, dv = _fov(depth)
    ch, cv = _fov(color)
    return depth.width / dh >= color.width / ch and depth.height / dv >= color.height / cv


def align_depth(
    depth: np.ndarray,
    depth_lens: Lens,
    color_lens: Lens,
    rotation: np.ndarray,
    translation: np.ndarray,
    *,
    z: str = "color",
) -> np.ndarray:
    """Depth seen by the colour camera: each depth pixel's footprint, z-buffered (module docstring).

    Parameters
    ----------
    depth : (h_d, w_d) float, metres; 0 (or not finite) where the sensor returned nothing
    depth_lens, color_lens : Lens
        ``depth_lens.camera`` must match ``depth``'s size; the result has ``color_lens.camera``'s.
    rotation : (3, 3) float
    translation : (3,) float, metres
        Depth-to-colour extrinsics: ``p_color = rotation @ p_depth + translation``.
    z : {"color", "depth"}
        The value written: the point's depth along the colour camera's axis (right for everything that
        deprojects the result with the colour intrinsics), or the depth camera's reading as ``rs2::align``
        copies it (to compare with the SDK pixel for pixel).

    Returns
    -------
    (h_c, w_c) float32, metres along the colour camera's z; 0 where no depth pixel lands.
    """
    depth = np.asarray(depth)
    dcam, ccam = depth_lens.camera, color_lens.camera
    if depth.shape != (dcam.height, dcam.width):
        raise InputError(f"depth image is {depth.shape[1]}x{depth.shape[0]}, its intrinsics {dcam.width}x{dcam.height}")
    if z not in ("color", "depth"):
        raise InputError(f"z must be 'color' or 'depth', got {z!r}")
    rotation, translation = np.asarray(rotation, dtype=np.float64), np.asarray(translation, dtype=np.float64)
    if rotation.shape != (3, 3) or translation.shape != (3,) or not np.isfinite(rotation).all():
        raise InputError("extrinsics must be a finite (3, 3) rotation and a (3,) translation")
    flat = depth.ravel().astype(np.float64)
    idx = np.flatnonzero(np.isfinite(flat) & (flat > 0))
    out = np.full(ccam.height * ccam.width, np.inf)
    if len(idx):
        zd = flat[idx]
        u, v = (idx % dcam.width).astype(np.float64), (idx // dcam.width).astype(np.float64)

        def corner(offset: float) -> tuple[np.ndarray, np.ndarray]:
            pts = transform(deproject(depth_lens, np.c_[u + offset, v + offset], zd), rotation, translation)
            px = project(color_lens, pts)
            return np.floor(px[:, 0] + 0.5), np.floor(px[:, 1] + 0.5)

        # a wild recorded lens model (a distortion denominator of 0, coefficients of 1e9) sends some pixels to
        # inf or NaN: they are dropped below (``ok``), without numpy's floating-point warnings on the way
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            if _denser(dcam, ccam):  # one colour pixel per depth pixel: the one its centre lands in
                x0, y0 = corner(0.0)
                x1, y1 = x0, y0
            else:
                x0, y0 = corner(-0.5)
                x1, y1 = corner(0.5)
            centre = transform(deproject(depth_lens, np.c_[u, v], zd), rotation, translation)
            zc = centre[:, 2] if z == "color" else zd
            ok = np.isfinite(x0) & np.isfinite(y0) & np.isfinite(x1) & np.isfinite(y1) & (centre[:, 2] > 0)
            ok &= (x1 - x0 < MAX_FOOTPRINT) & (y1 - y0 < MAX_FOOTPRINT)
            # footprints wholly outside the colour image cover no pixel (the spans below would be empty); left
            # out here so that far-off ones (a wild lens model's) are never cast to pixel indices
            ok &= (x1 >= 0) & (y1 >= 0) & (x0 <= ccam.width - 1) & (y0 <= ccam.height - 1)
        x0, y0 = np.maximum(x0[ok], 0), np.maximum(y0[ok], 0)
        x1, y1 = np.minimum(x1[ok], ccam.width - 1), np.minimum(y1[ok], ccam.height - 1)
        zc = zc[ok]
        span_x = (x1 - x0 + 1).astype(np.int64)
        span_y = (y1 - y0 + 1).astype(np.int64)
        x0i, y0i = x0.astype(np.int64), y0.astype(np.int64)
        for dy in range(int(span_y.max(initial=0))):
            for dx in range(int(span_x.max(initial=0))):
                hit = (dx < span_x) & (dy < span_y)
                np.minimum.at(out, (y0i[hit] + dy) * ccam.width + x0i[hit] + dx, zc[hit])
    out[~np.isfinite(out)] = 0.0
    return out.reshape(ccam.height, ccam.width).astype(np.float32)
