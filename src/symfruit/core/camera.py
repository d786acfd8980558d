"""Pinhole camera model in the REP-103 optical frame (x right, y down, z forward), metres.

Pixel ``(u, v)`` has its centre at integer coordinates: a point projects to
``u = fx * x / z + cx`` and falls into pixel column ``round(u)``.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

import numpy as np

from ..errors import InputError
from .limits import MAX_FOCAL_PX, MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE, shown

__all__ = ["DEFAULT_CAMERA", "MAX_FOCAL_PX", "MAX_IMAGE_PIXELS", "MAX_IMAGE_SIDE", "Camera"]

# The bounds (image side and size, focal length) live with every other bound in .limits.


@dataclass(frozen=True)
class Camera:
    """Pinhole intrinsics.

    Parameters
    ----------
    fx, fy : float
        Focal lengths in pixels, > 0.
    cx, cy : float
        Principal point in pixels.
    width, height : int
        Image size in pixels, > 0.

    Examples
    --------
    >>> cam = Camera(fx=615.0, fy=615.0, cx=320.0, cy=240.0, width=640, height=480)
    >>> cam.project([[0.0, 0.0, 0.5]])
    array([[320., 240.]])
    """

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int

    def __post_init__(self) -> None:
        for name in ("fx", "fy", "cx", "cy"):
            value = getattr(self, name)
            if isinstance(value, bool | str | bytes):  # float() reads True as 1 and "600" as 600 in silence
                raise InputError(f"camera {name} must be a number, got {shown(value)}")
            try:
                value = float(value)
            except (TypeError, ValueError, OverflowError):  # OverflowError: a whole number beyond float's range
                raise InputError(f"camera {name} must be a number, got {shown(value)}") from None
            if not np.isfinite(value):
                raise InputError(f"camera {name} must be finite, got {value!r}")
            object.__setattr__(self, name, value)
        for name in ("width", "height"):
            value = getattr(self, name)
            if isinstance(value, float) and value.is_integer():
                value = int(value)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value <= 0:
                raise InputError(f"camera {name} must be a positive whole number of pixels, got {shown(value)}")
            if value > MAX_IMAGE_SIDE:
                raise InputError(f"camera {name} is {shown(value)} pixels; at most {MAX_IMAGE_SIDE} are supported")
            object.__setattr__(self, name, int(value))
        if self.width * self.height > MAX_IMAGE_PIXELS:
            raise InputError(f"camera image of {self.width}x{self.height} pixels exceeds {MAX_IMAGE_PIXELS:,} pixels")
        if self.fx <= 0 or self.fy <= 0:
            raise InputError(f"camera focal lengths must be positive, got fx={self.fx}, fy={self.fy}")
        if self.fx < 1.0 or self.fy < 1.0:  # under a pixel per radian: no camera (a focal length in metres)
            raise InputError(f"camera focal lengths must be at least 1 pixel, got fx={self.fx:g}, fy={self.fy:g} "
                             "(focal lengths are in pixels, not millimetres or metres)")  # fmt: skip
        if self.fx > MAX_FOCAL_PX or self.fy > MAX_FOCAL_PX:
            raise InputError(f"camera focal lengths must be at most {MAX_FOCAL_PX:g} pixels, got fx={self.fx:g}, "
                             f"fy={self.fy:g}")  # fmt: skip
        for name in ("cx", "cy"):
            if abs(getattr(self, name)) > MAX_FOCAL_PX:
                raise InputError(f"camera {name} = {getattr(self, name):g} is implausible (more than "
                                 f"{MAX_FOCAL_PX:g} pixels from the image corner)")  # fmt: skip

    @property
    def matrix(self) -> np.ndarray:
        """(3, 3) float: the intrinsic matrix K."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def shifted(self, du: float, dv: float) -> Camera:
        """The camera of an image whose content sits ``(du, dv)`` pixels from this camera's: what this camera sees at
        pixel ``(u, v)`` lies at ``(u + du, v + dv)`` there (a depth image registered a few pixels off the colour
        image, :func:`symfruit.extract.register`). Its principal point moves by the shift, so a pixel of that
        image deprojects to the point this camera sees there: the point is in this camera's frame.

        Examples
        --------
        >>> cam = Camera(fx=600.0, fy=600.0, cx=320.0, cy=240.0, width=640, height=480)
        >>> cam.shifted(6, -2).project(cam.deproject([[100.0, 50.0]], [1.0]))
        array([[106.,  48.]])
        """
        shift = []
        for name, value in (("du", du), ("dv", dv)):  # once per frame, not per pixel
            if isinstance(value, bool | str | bytes):  # float() reads True as 1 and "6" as 6 in silence
                raise InputError(f"camera shift {name} must be a number of pixels, got {shown(value)}")
            try:
                value = float(value)
            except (TypeError, ValueError, OverflowError):
                raise InputError(f"camera shift {name} must be a number of pixels, got {shown(value)}") from None
            if not np.isfinite(value):
                raise InputError(f"camera shift {name} must be finite, got {value!r}")
            shift.append(value)
        if shift[0] == 0 and shift[1] == 0:  # a well-registered frame: this camera itself
            return self
        return replace(self, cx=self.cx + shift[0], cy=self.cy + shift[1])

    def to_dict(self) -> dict[str, float | int]:
        """The six intrinsics as a plain dict (the layout :func:`symfruit.io.load_camera` reads)."""
        return asdict(self)

    def project(self, points: np.ndarray) -> np.ndarray:
        """Project camera-frame points to sub-pixel image coordinates.

        Parameters
        ----------
        points : (..., 3) float, metres
            Points with ``z > 0``; other points give non-finite or meaningless coordinates.

        Returns
        -------
        (..., 2) float, pixels
            ``(u, v)`` per point.
        """
        points = np.asarray(points, dtype=np.float64)
        if points.shape[-1:] != (3,):  # (n, 2) was an IndexError from numpy
            raise InputError(f"project needs points of shape (..., 3) in metres, got {points.shape}")
        with np.errstate(divide="ignore", invalid="ignore"):
            inv_z = 1.0 / points[..., 2]
        uv = np.empty(points.shape[:-1] + (2,))  # filled in place: np.stack's overhead is most of a small call
        uv[..., 0] = self.fx * points[..., 0] * inv_z + self.cx
        uv[..., 1] = self.fy * points[..., 1] * inv_z + self.cy
        return uv

    def rays(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Viewing rays through pixels, scaled to ``z = 1``.

        Parameters
        ----------
        u, v : (...) float or int, pixels

        Returns
        -------
        (..., 3) float, ``((u - cx) / fx, (v - cy) / fy, 1)``

        Examples
        --------
        >>> Camera(fx=500.0, fy=500.0, cx=320.0, cy=240.0, width=640, height=480).rays(820.0, 240.0)
        array([1., 0., 1.])
        """
        u, v = np.asarray(u), np.asarray(v)
        # stop 43: text was numpy's UFuncTypeError, coordinates of two shapes np.stack's ValueError
        if u.dtype.kind not in "iuf" or v.dtype.kind not in "iuf":
            raise InputError(f"rays needs pixel coordinates as numbers, got {u.dtype} and {v.dtype}")
        if u.shape != v.shape:
            raise InputError(f"rays needs u and v of one shape, got {u.shape} and {v.shape}")
        x = (u - self.cx) / self.fx
        y = (v - self.cy) / self.fy
        out = np.empty(np.shape(x) + (3,), dtype=np.result_type(x, y, np.float64))  # as np.stack's, in place
        out[..., 0] = x
        out[..., 1] = y
        out[..., 2] = 1.0
        return out

    def deproject(self, uv: np.ndarray, depth: np.ndarray) -> np.ndarray:
        """Lift pixel coordinates with depth to camera-frame points.

        Parameters
        ----------
        uv : (..., 2) float, pixels
        depth : (...) float, metres along z

        Returns
        -------
        (..., 3) float, metres
        """
        uv = np.asarray(uv, dtype=np.float64)
        depth = np.asarray(depth, dtype=np.float64)
        if uv.shape[-1:] != (2,):  # (n, 3) was taken as (u, v) and its third column dropped, (n, 1) an IndexError
            raise InputError(f"deproject needs pixel coordinates of shape (..., 2), got {uv.shape}")
        if uv.shape[:-1] != depth.shape:  # was numpy's 'all input arrays must have the same shape' (np.stack)
            raise InputError(f"deproject needs one depth per pixel: {uv.shape[:-1]} pixels, depth {depth.shape}")
        x = (uv[..., 0] - self.cx) / self.fx * depth
        y = (uv[..., 1] - self.cy) / self.fy * depth
        return np.stack([x, y, depth], axis=-1)


#: Intel RealSense D435 colour stream at 640x480 (typical factory calibration), used when a cloud
#: comes without intrinsics.
DEFAULT_CAMERA = Camera(fx=615.0, fy=615.0, cx=320.0, cy=240.0, width=640, height=480)
