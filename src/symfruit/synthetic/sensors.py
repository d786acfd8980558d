"""Models of real RGB-D cameras for synthetic frames: time-of-flight (Azure Kinect DK, RealSense L515)
and active stereo (RealSense D435, D405), every artefact a parameter with its value and source.

:class:`SensorModel` describes a camera (colour resolution and intrinsics, the depth sensor's own
resolution, noise, edges, registration) and the annotators' masks and the clutter of the scenes it is
used in; :func:`apply_sensor` turns a clean render (:func:`symfruit.synthetic.render.render`) at the colour
camera's resolution into the registered depth image and masks that camera and its annotators give.
:data:`SENSOR_MODELS` holds the four cameras.

What :func:`apply_sensor` does, in order (the depth camera's own pixels are coarser than the colour
image's: ``footprint = f_colour / f_depth`` colour pixels each, and every edge artefact is sized in
depth pixels):

1. samples the clean depth on the depth camera's grid (each depth pixel sees the colour pixel at its
   centre) and marks *mixed* depth pixels, whose footprint spans a depth step larger than
   ``edge_step`` or a surface and nothing;
2. time-of-flight: a mixed pixel is a *flying pixel* (depth the footprint's mean: between the fruit and
   what is behind it) with probability ``flying_share``, otherwise invalid, and valid pixels within
   ``rim_invalid_px`` depth pixels of a mixed one on the nearer surface's side (``rim_far_px`` on the farther
   side's) are invalidated (the depth engine's mixed-pixel filter: the real Azure Kinect frames keep the
   background's depth up to the outline, ``docs/realism44.md``); active stereo: the foreground's depth
   spreads ``fatten_px`` depth pixels over the background (the matching window straddles the edge) and
   background the right imager cannot see is invalid (the stereo occlusion band, ``baseline`` and the
   disparities decide its width);
3. multipath (time-of-flight): depth pushed away from the camera near where two surfaces meet,
   ``multipath_bias`` at the junction decaying over ``multipath_range``;
4. axial noise and bias growing with distance (:meth:`SensorModel.sigma`, :meth:`SensorModel.bias`), the noise
   correlated over ``noise_corr_px`` depth pixels (a Gaussian autocorrelation: the depth engine's filtering, a
   stereo matcher's window), grazing-angle dropout (time of flight: wherever the surface turns
   further from the ray than a threshold that varies smoothly between ``grazing`` and ``grazing + grazing_ramp``)
   and random dropout, no depth outside the depth camera's field of
   view, millimetre quantisation;
5. registers depth to colour: nearest depth pixel per colour pixel, shifted by ``registration_px``
   (in a direction drawn per frame), with the parallax band a depth camera ``colour_baseline`` away
   from the colour camera cannot see left invalid;
6. masks as annotators draw them: each fruit's mask grown by up to ``mask_overshoot_px`` and, with
   probability ``mask_amodal_share``, drawn over an occluding leaf (the fruit's whole outline).

Values come from the datasheets and papers cited next to each; where a value is a judgement the
docstring says so. Two real Azure Kinect frames (``../shared/data/real-frames``) were used to check the
time-of-flight model, not to tune it (``docs/sensors.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy import ndimage, special

from ..core.camera import Camera
from ..core.raster import distance_transform
from ..errors import InputError

__all__ = [
    "SENSOR_MODELS",
    "VARIABLE",
    "SensorFrame",
    "SensorModel",
    "apply_sensor",
    "checked_sensor_set",
    "correlated_noise",
    "parse_sensor_set",
    "sensor_model",
    "varied",
]

#: Sources cited by the models (short keys used in the field docs).
SOURCES = {
    "AK-HW": "Microsoft, Azure Kinect DK hardware specification, learn.microsoft.com/azure/kinect-dk/"
    "hardware-specification (depth modes, fields of view, operating range, systematic and random error)",
    "AK-DEPTH": "Microsoft, Azure Kinect DK depth camera, learn.microsoft.com/azure/kinect-dk/depth-camera "
    "(invalidation of mixed pixels, multipath)",
    "TOLGYESSY": "Tolgyessy et al., Evaluation of the Azure Kinect and its comparison to Kinect V1 and "
    "Kinect V2, Sensors 21(2):413, 2021 (precision, accuracy, flying pixels, multipath)",
    "D400-DS": "Intel RealSense D400 series product family datasheet, doc. 337029 (baselines, fields of "
    "view, resolutions, minimum distance)",
    "D400-TUNE": "Grunnet-Jepsen, Sweetser, Woodfill, Tuning depth cameras for best performance, Intel "
    "white paper (RMS error = z^2 * subpixel / (f * baseline), subpixel about 0.08)",
    "L515-DS": "Intel RealSense LiDAR camera L515 datasheet (resolutions, fields of view, range, accuracy "
    "and precision)",
    "HALMETSCHLAGER": "Halmetschlager-Funek et al., An empirical evaluation of ten depth cameras, IEEE RAM "
    "26(1), 2019 (bias and noise against distance, edge behaviour)",
    "LOURENCO": "Lourenco and Araujo, Intel RealSense SR305, D415 and L515: experimental evaluation and "
    "comparison of depth estimation, VISAPP 2021",
    "KESELMAN": "Keselman, Woodfill, Grunnet-Jepsen, Bhowmik, Intel RealSense stereoscopic depth cameras, CVPR "
    "workshops 2017, arXiv:1705.05548 (the D400's depth from a correlation of image windows)",
    "ISSUE18": "issue 18: the held-back Azure Kinect frames of apples on a tree and the shared lab frames",
}


@dataclass(frozen=True)
class SensorModel:
    """A depth camera, its registration to the colour camera, its annotators and its scenes.

    Pixel sizes named ``*_px`` are depth-camera pixels unless the field says colour pixels; colour-pixel
    sizes are given for the model's own colour resolution (:meth:`at` rescales them).

    Attributes
    ----------
    name : str
    family : str
        ``"tof"`` (time of flight) or ``"stereo"`` (active stereo).
    width, height : int, colour pixels
        The colour stream the depth is registered to (native colour resolutions: Azure Kinect 1280x720
        up to 3840x2160 [AK-HW]; L515 and D435 1920x1080 [L515-DS, D400-DS]; D405 1280x720 from its
        left imager [D400-DS]).
    colour_hfov, colour_vfov : float, degrees
        The colour camera's field of view; the pinhole intrinsics follow (:meth:`camera`). Azure Kinect
        90 x 59 (16:9 modes) [AK-HW]; L515 70 x 43 [L515-DS]; D435 69 x 42 [D400-DS]; D405 87 x 58 (the
        depth imager's) [D400-DS].
    depth_width : int, depth pixels
        The depth image's width (Azure Kinect NFOV unbinned 640x576 [AK-HW]; L515 1024x768 [L515-DS];
        D435 and D405 1280x720 [D400-DS]).
    depth_hfov, depth_vfov : float, degrees
        The depth camera's field of view: no depth outside it. Azure Kinect NFOV 75 x 65 [AK-HW]; L515
        70 x 55 [L515-DS]; D435 87 x 58, D405 87 x 58 [D400-DS].
    distance : (float, float), metres
        Where the fruit are placed: the camera's working range within 0.25-2 m (issue 18). Azure Kinect
        NFOV from 0.5 m [AK-HW]; L515 from 0.25 m [L515-DS]; D435 from 0.28 m at 1280x720 [D400-DS];
        D405 ideal 0.07-0.5 m [D400-DS].
    sigma_const, sigma_linear : float, metres and metres per metre
        Time of flight: axial noise standard deviation ``sigma_const + sigma_linear * z``. Azure Kinect:
        the specification bounds it at 17 mm [AK-HW]; Tolgyessy et al. measured about 1-2 mm (NFOV
        unbinned, up to 3 m) [TOLGYESSY]: 0.6 mm + 0.6 mm/m (judgement within those). L515: precision
        2.5 mm at 1 m rising to 15.5 mm at 9 m (1 sigma) [L515-DS]: 1.0 mm + 1.5 mm/m.
    subpixel, baseline : float, pixels and metres
        Active stereo: axial noise ``z^2 * subpixel / (f_depth * baseline)`` [D400-TUNE]; subpixel RMS
        0.08 (the white paper's typical value for a well-textured scene) [D400-TUNE]; baseline D435
        50 mm, D405 18 mm [D400-DS].
    noise_corr_px : float, depth pixels
        Correlation length of the axial noise: its autocorrelation is ``exp(-(lag / noise_corr_px)^2)`` (1/e at
        ``noise_corr_px``; white noise Gaussian-filtered with ``noise_corr_px / 2`` and rescaled, so the per-pixel
        standard deviation stays :meth:`sigma`); 0: independent per depth pixel. Azure Kinect 3.5: MEASURED on the
        shared lab frames (``../shared/data/real-frames``): residuals of planes fitted to flat background patches
        fall to 1/e at 8 colour pixels (1920x1080), i.e. 3.5 of this model's depth pixels (footprint 2.30;
        ``docs/sensors.md``, ``python -m symfruit.evaluate.sensorcheck``). D435 and D405 4 (from sources, not
        measured: the D4's depth is a correlation of windows of the two images [KESELMAN], so neighbours share most
        of a window and its error; a 7-pixel window, the half-window ``fatten_px`` = 3 already assumed, a box
        correlation falling to 1/e at 0.63 x 7 = 4.4 px; judgement 4). L515 0 (no measurement, no source).
    bias_const, bias_linear : float, metres and metres per metre
        Systematic depth error ``bias_const + bias_linear * z`` (positive: too far). Azure Kinect: < 11 mm
        + 0.1 % of distance [AK-HW], typical units a few mm [TOLGYESSY]: 2 mm + 0.1 % (judgement). L515:
        about 5 mm up to 14 mm at 9 m [L515-DS]: 2 mm + 0.1 % (judgement). Stereo: the D400 datasheet
        bounds absolute error at 2 % of z; Halmetschlager-Funek et al. report sub-percent bias at short
        range [HALMETSCHLAGER]: 0.3 % (judgement).
    lateral_px : float, colour pixels
        Standard deviation of the lateral jitter of each de-projected pixel (judgement, as the
        project's existing models: 0.3 px). Applied in the registered depth: each colour pixel takes the depth
        pixel under its jittered position (what a camera's depth image holds; the scenes write it and the camera
        protocol extracts from it), returned as :attr:`SensorFrame.jitter`, not to be added again.
    edge_step : float, metres
        A depth pixel whose footprint spans more depth than this is *mixed* (judgement: 1.5 cm, above
        the depth range of a fruit's own slope inside one depth pixel at working distances).
    rim_invalid_px : int, depth pixels
        Time of flight: valid pixels this close to a mixed one *on the nearer surface's side* (the fruit's: depth
        more than ``edge_step`` in front of what the mixed pixel straddles) are invalidated [AK-DEPTH: the depth
        engine invalidates mixed pixels and their neighbourhood]; 1 (judgement; with the grazing loss below the
        modelled rim loss matches the lab frames', ``docs/realism44.md``).
    rim_far_px : int, depth pixels
        Time of flight: the same on the farther surface's side (the background's). 0: MEASURED on the shared lab
        frames (``../shared/data/real-frames``, ``python docs/realism44.py``): the background's depth reaches the
        spheres' colour outline within about 1 colour pixel where no parallax band lies (sphere 1's left side 3 px
        inside, its right side 5 px outside with the 3.4 px band the 32 mm colour baseline leaves, the 2 px
        registration across between them; docs/realism44.md), i.e. no ring of invalid pixels outside the
        silhouette. Before stop 44 both sides were invalidated (``rim_invalid_px`` about the edge).
        L515 1, as before stop 44 (no real L515 frames; see ``grazing``).
    flying_share : float
        Time of flight: share of mixed pixels that survive the filter with a depth between the fruit and
        what is behind (flying pixels [TOLGYESSY, AK-DEPTH]). Azure Kinect 0.005: MEASURED, none on the lab frames
        (0 of about 1,750 pixels with depth within 4 px of the spheres' free outlines per frame, two frames; the
        model at 0.1 put 5-10 there per sphere, so the frames bound it below about 0.006; docs/realism44.md; before
        stop 44 0.1, a judgement). L515 0.3 (judgement: flying pixels are a known L515 artefact, [LOURENCO]; no
        real L515 frames).
    fatten_px : int, depth pixels
        Active stereo: the foreground's depth spreads this far over the background (half the D4
        matching window; judgement: 3, an object looks about 2 x 3 depth pixels wider, [HALMETSCHLAGER]).
    grazing, grazing_dropout, grazing_ramp : float
        A pixel whose surface faces the ray at ``|cos| < grazing + grazing_ramp * u`` returns no depth with
        probability ``grazing_dropout``; ``u`` is uniform in 0-1, a smooth field over the image (a normal field
        correlated over ``max(noise_corr_px, 2)`` depth pixels, :func:`correlated_noise`, through its CDF), so the
        depth stops along a wavy line where the rim turns away: a time-of-flight pixel's return falls with ``|cos|``
        (a diffuse surface) and the depth engine invalidates low returns [AK-DEPTH: pixels with too little signal
        are invalid]. ``grazing_ramp`` 0: a hard threshold, drawn per pixel (the stereo models: 0.2 and 0.5,
        judgement). Azure Kinect 0.3, 1.0, 0.35 (lost below ``|cos|`` 0.3, kept above 0.65, half lost at 0.475):
        MEASURED on the shared lab frames' free outlines (``python docs/realism44.py``; sphere 1, 120 px across at
        1.51 m, its left and right sides: share of pixels with depth 0.02, 0.06, 0.09, 0.20, 0.36, 0.62, 0.94, 1.00
        in ``|cos|`` bins 0-0.1, ..., 0.6-0.7, 0.7-0.85; the depth stops 8 px inside the colour outline (6 and 10
        px, the 2 px registration across between them), the outer 13 % of the radius; the white polystyrene
        spheres, so a darker fruit skin loses no less). Before stop 44: 0.2 and 0.5, a judgement that stopped the
        depth 3 px inside. L515 0.2, 0.5, 0 as before stop 44 (a judgement: no real L515 frames, and the L515 is a
        scanning MEMS lidar whose low-return and mixed-pixel handling the Azure Kinect's frames do not measure; the
        Azure Kinect's values on it moved its camera-model table 4.91 -> 4.29 mm and the real scans through it
        10.45 -> 12.41 mm, docs/realism44.md: a model choice the data here cannot settle).
    dropout : float
        Probability that any pixel returns no depth (judgement: 0.005).
    multipath_bias, multipath_range : float, metres
        Time of flight: depth pushed away from the camera near a junction of two surfaces (a fruit
        touching a leaf or the surface it lies on), ``multipath_bias * exp(-d / multipath_range)`` at a
        lateral distance ``d`` from the junction [TOLGYESSY: multipath in concave corners; AK-DEPTH];
        Azure Kinect 5 mm over 2 cm (judgement), L515 3 mm over 2 cm (judgement). Stereo: 0.
    registration_px : float, colour pixels
        Depth registered this far off the colour image (a direction drawn per frame): Azure Kinect 6 px
        at 1920x1080 (judgement between issue 18's "a few pixels" and the 11-17 px measured on the lab
        frames, ``docs/sensors.md``); L515 4 px (judgement); D435 2 px at 1280x720 (factory calibrated
        colour-to-depth extrinsics, judgement); D405 0 (colour from the depth imager itself [D400-DS]).
    colour_baseline : float, metres
        Distance from the depth camera to the colour camera along x: background just beside a nearer
        object, seen by the colour camera but hidden from the depth camera, has no registered depth.
        Azure Kinect about 32 mm [AK-HW, the extrinsics' translation]; L515 about 25 mm (judgement from
        the module's drawing [L515-DS]); D435 15 mm (RGB to left imager [D400-DS]); D405 0.
    mask_overshoot_px : float, colour pixels
        Each fruit's mask grows by a uniform 0 to this many pixels (annotators' and models' outlines sit
        a few pixels off: the shared photos' COCO outlines, README; the lab frames' circles cover
        background, [ISSUE18]): 4 at 1920x1080, 3 at 1280x720 (judgement).
    mask_amodal_share : float
        Share of partly occluded fruit whose mask is drawn over the occluder (the fruit's whole
        outline, [ISSUE18]: "masks ... that cover an occluding leaf"): 0.5 (judgement).
    clutter_gap : (float, float), metres
        Leaves, branches and a background this far behind and beside the fruit (issue 18: 2-20 cm).
    clutter_leaves : int
        Leaves placed behind and beside each fruit in the camera protocol (judgement: 3).
    """

    name: str
    family: str
    width: int
    height: int
    colour_hfov: float
    colour_vfov: float
    depth_width: int
    depth_hfov: float
    depth_vfov: float
    distance: tuple[float, float]
    sigma_const: float = 0.0
    sigma_linear: float = 0.0
    subpixel: float = 0.0
    baseline: float = 0.0
    noise_corr_px: float = 0.0
    bias_const: float = 0.0
    bias_linear: float = 0.0
    lateral_px: float = 0.3
    edge_step: float = 0.015
    rim_invalid_px: int = 0
    rim_far_px: int = 0
    flying_share: float = 0.0
    fatten_px: int = 0
    grazing: float = 0.2
    grazing_dropout: float = 0.5
    grazing_ramp: float = 0.0
    dropout: float = 0.005
    multipath_bias: float = 0.0
    multipath_range: float = 0.02
    registration_px: float = 0.0
    colour_baseline: float = 0.0
    mask_overshoot_px: float = 0.0
    mask_amodal_share: float = 0.0
    clutter_gap: tuple[float, float] = (0.02, 0.20)
    clutter_leaves: int = 3

    def __post_init__(self) -> None:
        if self.family not in ("tof", "stereo"):
            raise ValueError(f"sensor family must be 'tof' or 'stereo', got {self.family!r}")
        if self.family == "stereo" and (self.subpixel <= 0 or self.baseline <= 0):
            raise ValueError("a stereo sensor needs subpixel > 0 and baseline > 0")
        if not 0 < self.distance[0] < self.distance[1]:
            raise ValueError(f"distance must be (near, far) with 0 < near < far, got {self.distance}")

    def camera(self) -> Camera:
        """The colour camera the depth is registered to: square pixels, the focal length from the
        horizontal field of view (the datasheets round the vertical one), the principal point centred."""
        fx = self.width / 2 / math.tan(math.radians(self.colour_hfov) / 2)
        return Camera(fx=fx, fy=fx, cx=(self.width - 1) / 2, cy=(self.height - 1) / 2, width=self.width,
                      height=self.height)  # fmt: skip

    @property
    def depth_focal(self) -> float:
        """Focal length of the depth camera, its own pixels."""
        return self.depth_width / 2 / math.tan(math.radians(self.depth_hfov) / 2)

    @property
    def footprint(self) -> float:
        """Colour pixels per depth pixel (at least 1: depth is never finer than colour)."""
        return max(1.0, self.camera().fx / self.depth_focal)

    def sigma(self, z: np.ndarray | float) -> np.ndarray:
        """Axial noise standard deviation at depth ``z`` (metres): stereo ``z^2 subpixel / (f B)``,
        time of flight ``sigma_const + sigma_linear z``."""
        z = np.asarray(z, dtype=np.float64)
        if self.family == "stereo":
            return z * z * self.subpixel / (self.depth_focal * self.baseline)
        return self.sigma_const + self.sigma_linear * z

    def bias(self, z: np.ndarray | float) -> np.ndarray:
        """Systematic depth error at depth ``z`` (metres, positive: too far)."""
        return self.bias_const + self.bias_linear * np.asarray(z, dtype=np.float64)

    def at(self, width: int, height: int) -> SensorModel:
        """The same camera streaming colour at ``width x height`` (same fields of view; colour-pixel
        sizes scaled with the height)."""
        scale = height / self.height
        return replace(self, width=int(width), height=int(height), registration_px=self.registration_px * scale,
                       mask_overshoot_px=self.mask_overshoot_px * scale)  # fmt: skip


#: The four cameras of issue 18 (``--sensor NAME``).
SENSOR_MODELS: dict[str, SensorModel] = {
    "azure-kinect": SensorModel(
        "azure-kinect", "tof", 1920, 1080, 90.0, 59.0, 640, 75.0, 65.0, (0.5, 2.0),
        sigma_const=0.0006, sigma_linear=0.0006, noise_corr_px=3.5, bias_const=0.002, bias_linear=0.001,
        rim_invalid_px=1, rim_far_px=0, flying_share=0.005, grazing=0.3, grazing_ramp=0.35, grazing_dropout=1.0,
        multipath_bias=0.005, multipath_range=0.02, registration_px=6.0, colour_baseline=0.032,
        mask_overshoot_px=4.0, mask_amodal_share=0.5,
    ),
    "realsense-l515": SensorModel(
        "realsense-l515", "tof", 1920, 1080, 70.0, 43.0, 1024, 70.0, 55.0, (0.25, 2.0),
        sigma_const=0.001, sigma_linear=0.0015, bias_const=0.002, bias_linear=0.001, rim_invalid_px=1,
        rim_far_px=1, flying_share=0.3, grazing=0.2, grazing_ramp=0.0, grazing_dropout=0.5,
        multipath_bias=0.003, multipath_range=0.02, registration_px=4.0, colour_baseline=0.025,
        mask_overshoot_px=4.0, mask_amodal_share=0.5,
    ),
    "realsense-d435": SensorModel(
        "realsense-d435", "stereo", 1280, 720, 69.0, 42.0, 1280, 87.0, 58.0, (0.28, 2.0),
        subpixel=0.08, baseline=0.050, noise_corr_px=4.0, bias_linear=0.003, fatten_px=3, registration_px=2.0,
        colour_baseline=0.015,
        mask_overshoot_px=3.0, mask_amodal_share=0.5,
    ),
    "realsense-d405": SensorModel(
        "realsense-d405", "stereo", 1280, 720, 87.0, 58.0, 1280, 87.0, 58.0, (0.25, 0.5),
        subpixel=0.08, baseline=0.018, noise_corr_px=4.0, bias_linear=0.003, fatten_px=3, registration_px=0.0,
        colour_baseline=0.0,
        mask_overshoot_px=3.0, mask_amodal_share=0.5,
    ),
}  # fmt: skip


def sensor_model(name: str) -> SensorModel:
    """The model called ``name`` (a key of :data:`SENSOR_MODELS`), or a ValueError naming the known ones."""
    try:
        return SENSOR_MODELS[name]
    except KeyError:
        raise ValueError(f"unknown sensor model {name!r}; known: {', '.join(SENSOR_MODELS)}") from None


#: The artefacts a user may set on a model (``symfruit evaluate --protocol camera --sensor NAME --sensor-set``,
#: ``symfruit scenes --sensor-set``; :func:`varied`) and their bounds (inclusive; a whole number where the field is
#: one): a camera not modelled, or a stress test of how far a model's judgement values matter (docs/stress39.md).
#: ``bias`` is a factor on both bias terms (``bias_const`` and ``bias_linear``), as a camera's bias grows as a whole.
VARIABLE: dict[str, tuple[float, float]] = {
    "rim_invalid_px": (0, 10), "flying_share": (0.0, 1.0), "fatten_px": (0, 20), "edge_step": (0.002, 0.2),
    "lateral_px": (0.0, 5.0), "registration_px": (0.0, 40.0), "colour_baseline": (0.0, 0.2),
    "mask_overshoot_px": (0.0, 30.0), "mask_amodal_share": (0.0, 1.0), "grazing": (0.0, 1.0),
    "grazing_dropout": (0.0, 1.0), "grazing_ramp": (0.0, 1.0), "rim_far_px": (0, 10), "dropout": (0.0, 0.5),
    "multipath_bias": (0.0, 0.05),
    "multipath_range": (0.001, 0.2), "sigma_const": (0.0, 0.05), "sigma_linear": (0.0, 0.05),
    "subpixel": (0.01, 1.0), "noise_corr_px": (0.0, 20.0), "bias_const": (-0.05, 0.05),
    "bias_linear": (-0.05, 0.05), "bias": (0.0, 10.0),
}  # fmt: skip


def parse_sensor_set(text: str) -> tuple[tuple[str, float], ...]:
    """``"rim_invalid_px=3,flying_share=0.3"`` as ``(("rim_invalid_px", 3.0), ("flying_share", 0.3))``, each name one
    of :data:`VARIABLE` and each value within its bounds.

    Raises
    ------
    InputError
        Naming the entry and what is wrong with it (unknown name, not a number, out of bounds, named twice).
    """
    out: list[tuple[str, float]] = []
    for item in str(text).split(","):
        name, eq, value = (part.strip() for part in item.partition("="))
        if not eq or not name or not value:
            raise InputError(f"--sensor-set {item.strip()!r}: expected NAME=VALUE, e.g. rim_invalid_px=3")
        try:
            number = float(value)
        except ValueError:
            raise InputError(f"--sensor-set {name}={value}: {value!r} is not a number") from None
        out.append((name, number))
    return checked_sensor_set(out)


def checked_sensor_set(changes: object) -> tuple[tuple[str, float], ...]:
    """``changes`` (pairs ``(name, value)`` or a mapping) checked against :data:`VARIABLE`, as a tuple of pairs.

    Raises
    ------
    InputError
    """
    items = list(changes.items()) if isinstance(changes, dict) else changes
    if isinstance(items, str | bytes) or not isinstance(items, list | tuple):
        raise InputError(f"sensor_set must be (name, value) pairs or a dict, got {type(changes).__name__}")
    out: list[tuple[str, float]] = []
    for pair in items:
        if not isinstance(pair, list | tuple) or len(pair) != 2:
            raise InputError(f"sensor_set: expected (name, value) pairs, got {pair!r:.60}")
        name, value = pair
        if name not in VARIABLE:  # the names near it, not all of them (a line of 394 characters; stop 47)
            from ..settings import _closest, known_names

            close = _closest(str(name), VARIABLE)
            known = known_names(str(name), VARIABLE, where="symfruit.synthetic.sensors.VARIABLE")
            raise InputError(f"--sensor-set {name!s:.40}: not a setting of a camera model{close}; {known}")
        low, high = VARIABLE[name]
        whole = isinstance(getattr(SENSOR_MODELS["azure-kinect"], name, 0.0), int)
        if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
            raise InputError(f"--sensor-set {name}: the value must be a number, got {value!r:.40}")
        if not (low <= value <= high) or (whole and value != int(value)):
            kind = "a whole number " if whole else ""
            raise InputError(f"--sensor-set {name}={value:g}: must be {kind}{low:g} to {high:g}")
        if any(name == seen for seen, _ in out):
            raise InputError(f"--sensor-set names {name} twice")
        out.append((str(name), float(value)))
    if "bias" in (named := [name for name, _ in out]) and ("bias_const" in named or "bias_linear" in named):
        raise InputError("--sensor-set: bias (a factor on both bias terms) or bias_const/bias_linear, not both")
    return tuple(out)


def varied(model: SensorModel, changes: object) -> SensorModel:
    """``model`` with the artefacts ``changes`` names set (pairs ``(name, value)`` or a mapping, checked by
    :func:`checked_sensor_set`; ``bias`` scales both bias terms); the model's name stays, so its views' random draws
    are the model's own and a varied model's frames differ from the model's by the changed artefacts alone."""
    fields: dict[str, Any] = {}
    for name, value in checked_sensor_set(changes):
        if name == "bias":
            fields["bias_const"] = model.bias_const * value
            fields["bias_linear"] = model.bias_linear * value
        else:
            fields[name] = int(value) if isinstance(getattr(model, name), int) else value
    if model.family == "stereo" and not (fields.get("subpixel", model.subpixel) > 0):
        raise ValueError("a stereo sensor needs subpixel > 0")
    return replace(model, **fields) if fields else model


@dataclass(frozen=True)
class SensorFrame:
    """What :func:`apply_sensor` returns.

    Attributes
    ----------
    depth : (h, w) float32, metres; 0 where the camera returns no depth (registered to colour)
    labels : (h, w) int32; the annotators' masks (0 none, k fruit k), or None without input labels
    jitter : (h, w, 2) float; the lateral jitter (colour pixels, ``(du, dv)``) already applied in ``depth``: each
        pixel holds the depth under ``(u, v) + jitter`` (de-project pixel centres; adding it again doubles it)
    shift : (float, float), colour pixels; the registration offset ``(du, dv)`` of depth against colour
    """

    depth: np.ndarray
    labels: np.ndarray | None
    jitter: np.ndarray
    shift: tuple[float, float]


def apply_sensor(
    model: SensorModel,
    depth: np.ndarray,
    ids: np.ndarray,
    camera: Camera,
    rng: np.random.Generator,
    *,
    facing: np.ndarray | None = None,
    labels: np.ndarray | None = None,
    amodal: np.ndarray | None = None,
) -> SensorFrame:
    """Turn a clean render at the colour camera's resolution into what ``model`` and its annotators give.

    Parameters
    ----------
    model : SensorModel
    depth : (h, w) float, metres
        Ideal depth (``inf``, ``nan`` or 0 where nothing was hit), e.g. :attr:`Rendering.depth`.
    ids : (h, w) int
        Surface seen at each pixel (-1: none): junctions of two surfaces cause multipath.
    camera : Camera
        The colour camera (``h x w``); usually ``model.camera()``.
    rng : numpy.random.Generator
        Every random draw comes from it: the same seed gives the same frame.
    facing : (h, w) float, optional
        ``|cos|`` between ray and surface normal (:attr:`Rendering.facing`); without it no grazing dropout.
    labels : (h, w) int, optional
        The true visible pixels of each fruit (0 none, k fruit k): the masks to degrade.
    amodal : (h, w) int, optional
        Each fruit's whole silhouette, hidden parts included (same ids as ``labels``): an amodal mask
        covers an occluder with probability ``mask_amodal_share``.

    Returns
    -------
    SensorFrame
    """
    depth = np.asarray(depth, dtype=np.float64)
    h, w = depth.shape
    if (h, w) != (camera.height, camera.width) or np.shape(ids) != (h, w):
        raise ValueError(f"depth {depth.shape} and ids {np.shape(ids)} must match the camera ({camera.height}, "
                         f"{camera.width})")  # fmt: skip
    clean = np.where(np.isfinite(depth) & (depth > 0), depth, 0.0)
    ids = np.asarray(ids)
    ratio = model.footprint
    # The depth camera's grid: depth pixel (i, j) covers colour pixels floor(v / ratio) == i, floor(u / ratio) == j.
    hd, wd = math.ceil(h / ratio), math.ceil(w / ratio)
    cell_v = np.minimum((np.arange(h) / ratio).astype(np.int64), hd - 1)
    cell_u = np.minimum((np.arange(w) / ratio).astype(np.int64), wd - 1)
    centre_v = np.minimum(((np.arange(hd) + 0.5) * ratio).astype(np.int64), h - 1)
    centre_u = np.minimum(((np.arange(wd) + 0.5) * ratio).astype(np.int64), w - 1)
    z = clean[np.ix_(centre_v, centre_u)]
    sid = ids[np.ix_(centre_v, centre_u)]
    face = None if facing is None else np.asarray(facing)[np.ix_(centre_v, centre_u)]
    cell = (cell_v[:, None] * wd + cell_u[None, :]).ravel()
    flat = clean.ravel()
    hit = flat > 0
    count = np.bincount(cell, minlength=hd * wd)
    n_hit = np.bincount(cell, weights=hit, minlength=hd * wd)
    z_sum = np.bincount(cell, weights=flat, minlength=hd * wd)
    z_min = np.full(hd * wd, np.inf)
    z_max = np.zeros(hd * wd)
    np.minimum.at(z_min, cell[hit], flat[hit])
    np.maximum.at(z_max, cell[hit], flat[hit])
    some = n_hit > 0
    mixed = some & ((z_max - np.where(some, z_min, 0.0) > model.edge_step) | (n_hit < count))
    mixed = mixed.reshape(hd, wd)
    mean = np.where(some, z_sum / np.maximum(n_hit, 1), 0.0).reshape(hd, wd)
    out = z.copy()
    valid = out > 0
    f_d = model.depth_focal
    if model.family == "tof":
        flying = mixed & (rng.random((hd, wd)) < model.flying_share)
        out[flying] = mean[flying]
        valid = (valid | flying) & ~(mixed & ~flying)
        # A footprint partly on nothing straddles the farthest depth there is: its neighbours are all in front.
        valid &= ~_rim(mixed, np.where(n_hit < count, np.inf, z_max).reshape(hd, wd), z, model)
        if model.multipath_bias > 0:
            out = out + _multipath(z, sid, model, f_d)
    else:
        far = np.where(valid, out, np.inf)
        if model.fatten_px > 0:
            near = ndimage.minimum_filter(far, size=2 * model.fatten_px + 1, mode="nearest")
            with np.errstate(invalid="ignore"):  # inf - inf where neither nor a neighbour has depth: no spread
                spread = np.isfinite(near) & (far - near > model.edge_step)
            out[spread] = near[spread]
            valid |= spread
        valid &= ~_shadow(np.where(valid, out, 0.0), f_d * model.baseline)
    # Noise and bias grow with distance; dropout at grazing angles and at random; nothing outside the field of view.
    noise = correlated_noise(rng.normal(size=(hd, wd)), model.noise_corr_px) * model.sigma(out)
    out = out + model.bias(out) + noise
    if face is not None and model.grazing_dropout > 0:
        limit: np.ndarray | float = model.grazing
        if model.grazing_ramp > 0:  # the threshold varies smoothly along the rim
            # drawn from a stream of its own (a child of the frame's seed): the frame's other draws (registration,
            # jitter, masks) stay what they are without the ramp, so a model with and without it differ at the rim
            side = np.random.default_rng(rng.bit_generator.seed_seq.spawn(1)[0])  # type: ignore[attr-defined]
            wave = correlated_noise(side.normal(size=(hd, wd)), max(model.noise_corr_px, 2.0))
            limit = model.grazing + model.grazing_ramp * special.ndtr(wave)
        valid &= ~((face < limit) & (rng.random((hd, wd)) < model.grazing_dropout))
    valid &= rng.random((hd, wd)) >= model.dropout
    valid &= out > 0
    out = np.where(valid, out, 0.0)
    # Register to colour: each colour pixel takes the depth pixel under it, shifted by the registration offset.
    # Lateral jitter: each colour pixel's depth is that of the point a jittered ray meets, i.e. the depth pixel
    # under its jittered position (drawn here, after the registration's angle, as before it was applied: the
    # other draws, and so the frames at lateral_px = 0, are unchanged).
    angle = rng.uniform(0.0, 2.0 * np.pi)
    du, dv = model.registration_px * math.cos(angle), model.registration_px * math.sin(angle)
    jitter = rng.normal(scale=model.lateral_px, size=(h, w, 2)) if model.lateral_px > 0 else np.zeros((h, w, 2))
    src_v = np.floor((np.arange(h) - dv) / ratio).astype(np.int64)[:, None]
    src_u = np.floor((np.arange(w) - du) / ratio).astype(np.int64)[None, :]
    inside = (src_v >= 0) & (src_v < hd) & (src_u >= 0) & (src_u < wd)  # the jitter opens no holes at the border
    if model.lateral_px > 0:
        src_v = np.floor((np.arange(h)[:, None] - dv + jitter[..., 1]) / ratio).astype(np.int64)
        src_u = np.floor((np.arange(w)[None, :] - du + jitter[..., 0]) / ratio).astype(np.int64)
    registered = out[np.clip(src_v, 0, hd - 1), np.clip(src_u, 0, wd - 1)] * inside
    registered *= _in_view(model, camera)
    if model.colour_baseline > 0:
        registered[_shadow(registered, camera.fx * model.colour_baseline)] = 0.0
    registered = np.round(registered / 0.001) * 0.001  # millimetre depth units (all four cameras)
    masks = None if labels is None else annotate(model, labels, rng, amodal=amodal)
    return SensorFrame(registered.astype(np.float32), masks, jitter, (du, dv))


def correlated_noise(white: np.ndarray, length: float) -> np.ndarray:
    """``white`` (independent unit normal draws) correlated over ``length`` pixels: Gaussian-filtered with
    ``length / 2`` (the autocorrelation ``exp(-(lag / length)^2)``, 1/e at ``length``), wrapping round the image
    (stationary: every pixel's variance the same) and divided by the kernel's norm, so each pixel stays unit normal.
    ``length`` 0 returns ``white`` itself."""
    if length <= 0:
        return white
    s = length / 2.0
    radius = max(1, math.ceil(4.0 * s))
    kernel = np.exp(-0.5 * (np.arange(-radius, radius + 1) / s) ** 2)
    kernel /= kernel.sum()
    smooth = ndimage.gaussian_filter(white, s, mode="wrap", truncate=radius / s)
    return smooth / float(np.sum(kernel**2))  # 2-D variance: (sum k^2)^2, its square root


def _rim(mixed: np.ndarray, z_max: np.ndarray, z: np.ndarray, model: SensorModel) -> np.ndarray:
    """(hd, wd) bool: valid depth pixels the depth engine invalidates beside a mixed one: within ``rim_invalid_px``
    on the nearer surface's side (depth more than ``edge_step`` in front of the farthest depth a mixed pixel within
    that reach straddles) and within ``rim_far_px`` on the farther surface's side. Not the mixed pixels themselves."""
    out = np.zeros(mixed.shape, bool)
    reach = max(model.rim_invalid_px, model.rim_far_px)
    if reach <= 0 or not mixed.any():
        return out
    for r, near_side in ((model.rim_invalid_px, True), (model.rim_far_px, False)):
        if r <= 0:
            continue
        ii, jj = np.mgrid[-r : r + 1, -r : r + 1]
        diamond = np.abs(ii) + np.abs(jj) <= r  # what ``binary_dilation(iterations=r)`` reaches
        far = ndimage.grey_dilation(np.where(mixed, z_max, 0.0), footprint=diamond, mode="constant", cval=0.0)
        with np.errstate(invalid="ignore"):
            front = (z > 0) & (z < far - model.edge_step)
        out |= (far > 0) & ~mixed & (front if near_side else ~front)
    return out


def _multipath(z: np.ndarray, sid: np.ndarray, model: SensorModel, focal: float) -> np.ndarray:
    """Depth added by multipath: largest at junctions of two surfaces close in depth, decaying laterally."""
    junction = np.zeros(z.shape, bool)
    for axis in (0, 1):
        a = [slice(None)] * 2
        b = [slice(None)] * 2
        a[axis], b[axis] = slice(1, None), slice(None, -1)
        meet = (sid[tuple(a)] != sid[tuple(b)]) & (sid[tuple(a)] >= 0) & (sid[tuple(b)] >= 0)
        meet &= np.abs(z[tuple(a)] - z[tuple(b)]) < model.multipath_range
        junction[tuple(a)] |= meet
        junction[tuple(b)] |= meet
    if not junction.any():
        return np.zeros_like(z)
    d_px = distance_transform(~junction)
    lateral = d_px * z / focal
    return np.where(z > 0, model.multipath_bias * np.exp(-lateral / model.multipath_range), 0.0)


def _shadow(depth: np.ndarray, fb: float) -> np.ndarray:
    """Pixels a second camera ``fb / f`` metres to the +x side cannot see (0 depth: none).

    With disparity ``d = fb / z`` (pixels), pixel ``u`` is hidden when some nearer pixel ``q > u`` has
    ``d(q) - d(u) >= q - u``, i.e. when ``max_{q > u} (d(q) - q) >= d(u) - u``: one reversed running
    maximum per row. The band lies on the -x side of nearer objects and is ``fb (1/z_near - 1/z_far)``
    pixels wide.
    """
    valid = depth > 0
    disp = np.where(valid, fb / np.where(valid, depth, 1.0), 0.0)
    g = np.where(valid, disp - np.arange(depth.shape[1])[None, :], -np.inf)
    ahead = np.maximum.accumulate(g[:, ::-1], axis=1)[:, ::-1]
    beyond = np.full(depth.shape, -np.inf)
    beyond[:, :-1] = ahead[:, 1:]
    return valid & (beyond >= g + 1e-9)


def _in_view(model: SensorModel, camera: Camera) -> np.ndarray:
    """(h, w) bool: colour pixels inside the depth camera's field of view."""
    tu = math.tan(math.radians(model.depth_hfov) / 2)
    tv = math.tan(math.radians(model.depth_vfov) / 2)
    u = np.abs((np.arange(camera.width) - camera.cx) / camera.fx) <= tu
    v = np.abs((np.arange(camera.height) - camera.cy) / camera.fy) <= tv
    return v[:, None] & u[None, :]


def annotate(
    model: SensorModel, labels: np.ndarray, rng: np.random.Generator, *, amodal: np.ndarray | None = None
) -> np.ndarray:
    """Masks as annotators draw them: each fruit's visible pixels (or, with probability
    ``mask_amodal_share`` when it is partly hidden, its whole outline from ``amodal``) grown by a uniform
    0 to ``mask_overshoot_px`` colour pixels; a fruit's own visible pixels are never given to another.

    Returns
    -------
    (h, w) int32
    """
    labels = np.asarray(labels)
    out = labels.astype(np.int32).copy()
    for k in np.unique(labels[labels > 0]):
        region = labels == k
        if amodal is not None and model.mask_amodal_share > 0:
            whole = np.asarray(amodal) == k
            if (whole & ~region).any() and rng.random() < model.mask_amodal_share:
                region = region | whole
        grow = rng.uniform(0.0, model.mask_overshoot_px)
        if grow >= 0.5:
            rows, cols = np.nonzero(region)
            pad = math.ceil(grow) + 1
            r0, r1 = max(rows.min() - pad, 0), min(rows.max() + pad + 1, labels.shape[0])
            c0, c1 = max(cols.min() - pad, 0), min(cols.max() + pad + 1, labels.shape[1])
            window = region[r0:r1, c0:c1]
            region = np.zeros_like(region)
            region[r0:r1, c0:c1] = distance_transform(~window) <= grow
        out[region & ((labels == 0) | (labels == k))] = k
    return out
