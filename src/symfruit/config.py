"""Settings: one dataclass per stage, grouped under :class:`Settings`, loaded from YAML or JSON.

Unknown keys, wrong types and out-of-range values raise :class:`~symfruit.errors.ConfigError`
with the dotted path of the offending key, e.g. ``paper.rotations_x: expected int, got 'eleven'``.
"""

from __future__ import annotations

import dataclasses
import json
import types
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from .errors import ConfigError

__all__ = [
    "ExtractSettings",
    "FusedSettings",
    "InputSettings",
    "PaperSettings",
    "SegmentSettings",
    "Settings",
    "SphereSettings",
    "load_settings",
]


@dataclass(frozen=True)
class InputSettings:
    """Checks applied to every cloud before completion.

    Attributes
    ----------
    min_points : int
        Fewest finite points a fruit needs; fewer raise :class:`~symfruit.errors.InputError`.
    max_points : int
        Larger clouds are down-sampled (seeded, reproducible) to this many points.
    max_extent : float, metres
        A cloud wider than this in any axis is refused as "not a single fruit, or in millimetres".
    min_extent : float, metres
        A cloud whose largest extent is smaller than this is refused as "not a fruit, or in the
        wrong units" (e.g. metres read with ``--units mm``).
    """

    min_points: int = 10
    max_points: int = 20000
    max_extent: float = 1.0
    min_extent: float = 0.003

    def __post_init__(self) -> None:
        _check(self.min_points >= 4, "input.min_points must be at least 4")
        _check(self.max_points >= self.min_points, "input.max_points must be >= input.min_points")
        _check(0 < self.min_extent < self.max_extent, "input: need 0 < min_extent < max_extent")


@dataclass(frozen=True)
class PaperSettings:
    """Settings of the ``paper`` method (Ge et al., sections 3.2-3.6, Table 1).

    Hypotheses (section 3.3). Planes are ``m * j * k`` combinations, ordered translation-major
    then rotation about x then rotation about y (ties go to the first, as in the paper).

    Attributes
    ----------
    translations : int
        ``m``, number of depth offsets of the plane point (paper: 4).
    translation_step : float
        ``delta_d`` as a fraction of the depth extent of the visible points (paper: 0.2).
    translation_first : float
        Offset of the first translation, in steps. The paper does not say where the ``m``
        offsets start; 0 puts the first plane through the centroid and the others behind it,
        away from the camera, where the true symmetry plane of a front view lies (the visible
        centroid is always in front of the fruit's centre).
    rotations_x, rotations_y : int
        ``j`` and ``k`` (paper: 11 and 3), centred on zero: angles are
        ``(i - (j - 1) / 2) * step`` for ``i`` in ``0..j-1``.
    rotation_x_step, rotation_y_step : float, degrees
        ``delta_theta_1``, ``delta_theta_2`` (paper: 5 and 5). The paper's Eq. 3 prints a rotation
        about z, which leaves a +z normal unchanged and so cannot generate its Fig. 2; we take it as
        a typo and rotate the normal ``n = R_y(b) @ R_x(a) @ (0, 0, 1)``.
    j1, j2, j3 : float
        Table 1: ``Dist_tol = j1 * Dist_ref``, ``Dist2c_0 = j2 * Dist_ref``,
        ``Dist2c_1 = j3 * Dist_ref`` (0.05, 0.6, 1.2).
    k1, k3 : float
        Table 1 rating constants (10 and 1).
    k2, k4, k5 : float or None
        Table 1 gives ``1/j1``, ``1/j2``, ``1/j3``; None means exactly that. (The text says
        ``k5 = 1``; Table 1 wins because only ``1/j3`` makes Eq. 10 equal -1 at the border of
        location 4-3, the value the text asks of "close to the reasonable region".)
    scoring : {"continuous", "literal"}
        How the equations are read; see :mod:`symfruit.rating`. ``continuous`` (default) makes every
        score continuous at the region borders; ``literal`` uses Eqs. 6-10 as printed.
    centre : {"centroid", "box"}
        The "centre of original points" that ``Dist2c`` is measured from: the mean of the visible
        points (paper) or the centre of their box.
    fill_radius : float or None, pixels
        Radius of the disc that closes the gaps between projected points when the visible mask
        ``Mp`` is rasterised. None estimates it from the density of the projected points.
    precision : {"single", "double"}
        Floating-point precision of the rating (the hot path). Single precision works relative to
        the visible centre, so it keeps well under a micrometre at fruit scale and is about twice as
        fast; the chosen plane and the completed cloud are always computed in double precision.
    rating_points : int or None
        Rate the hypotheses on a fixed random subset of at most this many visible points (the mask
        and the completion use all of them). The paper's fruit had about 600 points; a fruit close
        to a D435 has several thousand, and a 1,500-point subset ranks the planes alike while keeping
        the cost flat. None rates every point.
    """

    translations: int = 4
    translation_step: float = 0.2
    translation_first: float = 0.0
    rotations_x: int = 11
    rotation_x_step: float = 5.0
    rotations_y: int = 3
    rotation_y_step: float = 5.0
    j1: float = 0.05
    j2: float = 0.6
    j3: float = 1.2
    k1: float = 10.0
    k2: float | None = None
    k3: float = 1.0
    k4: float | None = None
    k5: float | None = None
    scoring: Literal["continuous", "literal"] = "continuous"
    centre: Literal["centroid", "box"] = "centroid"
    fill_radius: float | None = None
    precision: Literal["single", "double"] = "single"
    rating_points: int | None = 1500

    def __post_init__(self) -> None:
        _check(
            self.rating_points is None or self.rating_points >= 10,
            "paper.rating_points must be >= 10 or null",
        )
        for name in ("translations", "rotations_x", "rotations_y"):
            _check(getattr(self, name) >= 1, f"paper.{name} must be at least 1")
        _check(
            self.translations * self.rotations_x * self.rotations_y <= 200_000,
            "paper: more than 200000 hypotheses would not fit in memory; lower the counts",
        )
        for name in ("j1", "j2", "j3", "k1", "k3"):
            _check(getattr(self, name) > 0, f"paper.{name} must be positive")
        for name in ("k2", "k4", "k5"):
            value = getattr(self, name)
            _check(value is None or value > 0, f"paper.{name} must be positive or null")
        _check(self.j2 < self.j3, "paper.j2 must be smaller than paper.j3 (Dist2c_0 < Dist2c_1)")
        _check(self.translation_step >= 0, "paper.translation_step must not be negative")
        _check(self.fill_radius is None or self.fill_radius >= 0, "paper.fill_radius must not be negative")

    @property
    def k2_value(self) -> float:
        return 1.0 / self.j1 if self.k2 is None else self.k2

    @property
    def k4_value(self) -> float:
        return 1.0 / self.j2 if self.k4 is None else self.k4

    @property
    def k5_value(self) -> float:
        return 1.0 / self.j3 if self.k5 is None else self.k5

    @property
    def n_hypotheses(self) -> int:
        return self.translations * self.rotations_x * self.rotations_y


@dataclass(frozen=True)
class SphereSettings:
    """Settings of the ``sphere`` method.

    Attributes
    ----------
    refine : bool
        Refine the algebraic (linear least-squares) fit by geometric Gauss-Newton steps, which
        minimise the distances of the points to the sphere rather than the algebraic residual.
    """

    refine: bool = True


@dataclass(frozen=True)
class FusedSettings:
    """Settings of the default ``fused`` method (:mod:`symfruit.methods.fused`); fruit profiles set these.

    Attributes
    ----------
    clean_ratio : float
        Data count as a clean scan when the local plane-fit residual grows by at least this factor from
        8 to 30 neighbours (curvature, not noise): measured 4.5-6.7 on clean scans of every fruit kind,
        1.5-2.2 on D435-like views, so 3.3 separates them with room on both sides.
    revolution : bool
        On clean data, also fit a solid of revolution and average its box with the ellipsoid's
        (on for strawberries, whose tapered shape an ellipsoid misses).
    depth_prior, depth_ratio : float
        Noisy data: weight of the prior that the depth semi-axis is ``depth_ratio`` times the geometric
        mean of the lateral ones.
    huber : float, metres
        Noisy data: residuals beyond this count linearly (outliers, flying pixels).
    mirror_weight : float in [0, 1]
        Noisy data: share of the mirror completion in the centre (the rest is the aligned fit's).
    mirror_size : float in [0, 1]
        Noisy data: share of the mirror completion in the box size.
    mirror_translations, mirror_translation_step, mirror_j2, mirror_j3 : int, float, float, float
        The mirror completion's grid of depth offsets and its reasonable region (``paper.j2``,
        ``paper.j3``); the paper's 4 x 0.2 stops short of the true plane for shallow views and its
        0.6-1.2 region penalises the true back of elongated fruit (see docs/ablation.md).
    fit_points : int
        Fits and the mirror completion use a fixed random subset of at most this many points (the
        box always covers every visible point).
    mirror_points : int
        Points rated per hypothesis by the mirror completion (``paper.rating_points``).
    shape_points : int
        Points the camera-aligned ellipsoid is fitted to (a spread subset: the fit averages the
        noise of a few hundred points as well as of thousands, at a fraction of the cost).
    spread_scale, min_support, reliable_at : float
        Confidence = coverage * exp(-spread / (spread_scale * size)) * min(1, n / min_support), with
        ``coverage`` the share of the fitted silhouette the camera saw and ``spread`` the largest
        distance between the estimates' centres; ``reliable`` when it is at least ``reliable_at``.
    """

    clean_ratio: float = 3.3
    revolution: bool = False
    depth_prior: float = 1.0
    depth_ratio: float = 1.0
    huber: float = 0.002
    mirror_weight: float = 0.5
    mirror_size: float = 0.0
    mirror_translations: int = 8
    mirror_translation_step: float = 0.1
    mirror_j2: float = 0.4
    mirror_j3: float = 1.0
    fit_points: int = 2000
    mirror_points: int = 600
    shape_points: int = 800
    spread_scale: float = 0.1
    min_support: float = 150.0
    reliable_at: float = 0.4

    def __post_init__(self) -> None:
        _check(self.clean_ratio > 0, "fused.clean_ratio must be positive")
        _check(self.depth_prior >= 0 and self.depth_ratio > 0, "fused: depth_prior >= 0 and depth_ratio > 0")
        _check(self.huber > 0, "fused.huber must be positive")
        _check(0 <= self.mirror_weight <= 1 and 0 <= self.mirror_size <= 1, "fused: mirror shares are in [0, 1]")
        _check(self.mirror_translations >= 1 and self.mirror_translation_step >= 0, "fused: bad mirror grid")
        _check(self.fit_points >= 20 and self.mirror_points >= 10 and self.shape_points >= 10,
               "fused: fit_points >= 20, mirror_points and shape_points >= 10")  # fmt: skip
        _check(self.spread_scale > 0 and self.min_support > 0, "fused: spread_scale and min_support must be > 0")
        _check(0 <= self.reliable_at <= 1, "fused.reliable_at must be in [0, 1]")


@dataclass(frozen=True)
class SegmentSettings:
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

    hue_low: float = 340.0
    hue_high: float = 15.0
    sat_min: float = 0.45
    val_min: float = 0.15
    open_px: int = 1
    close_px: int = 2
    min_diameter: float = 0.012
    split: Literal["both", "depth", "watershed", "none"] = "both"
    depth_jump: float = 0.015
    crease_curvature: float = 1500.0
    crease_sigma: float = 2.0
    waist: float = 0.75

    def __post_init__(self) -> None:
        _check(0 <= self.hue_low <= 360 and 0 <= self.hue_high <= 360, "segment: hues are degrees in [0, 360]")
        _check(0 <= self.sat_min <= 1 and 0 <= self.val_min <= 1, "segment: sat_min and val_min are in [0, 1]")
        _check(self.open_px >= 0 and self.close_px >= 0, "segment: morphology radii must not be negative")
        _check(
            self.min_diameter > 0 and self.depth_jump > 0,
            "segment: min_diameter and depth_jump must be positive",
        )
        _check(0 < self.waist <= 1, "segment.waist must be in (0, 1]")


@dataclass(frozen=True)
class ExtractSettings:
    """Turning a mask into the fruit's points (:mod:`symfruit.extract`).

    Attributes
    ----------
    min_depth, max_depth : float, metres
        Depth outside this range is invalid (the D435 reads from about 0.1 m).
    erode_px : int
        Pixels dropped along the mask's border, where flying pixels (depth mixed with the background)
        sit.
    cluster_distance : float, metres
        Points closer than this join one cluster (voxel-grid Euclidean clustering); the fruit is the
        cluster nearest the camera among those with at least ``cluster_share`` of the largest's points.
    cluster_share : float
    min_points : int
        A fruit with fewer points left is reported as failed.
    """

    min_depth: float = 0.1
    max_depth: float = 2.0
    erode_px: int = 1
    cluster_distance: float = 0.006
    cluster_share: float = 0.3
    min_points: int = 30

    def __post_init__(self) -> None:
        _check(0 <= self.min_depth < self.max_depth, "extract: need 0 <= min_depth < max_depth")
        _check(self.erode_px >= 0, "extract.erode_px must not be negative")
        _check(self.cluster_distance > 0, "extract.cluster_distance must be positive")
        _check(0 < self.cluster_share <= 1, "extract.cluster_share must be in (0, 1]")
        _check(self.min_points >= 4, "extract.min_points must be at least 4")


@dataclass(frozen=True)
class Settings:
    """All settings, grouped per stage. Every field has a default; files override only what they name."""

    input: InputSettings = field(default_factory=InputSettings)
    segment: SegmentSettings = field(default_factory=SegmentSettings)
    extract: ExtractSettings = field(default_factory=ExtractSettings)
    paper: PaperSettings = field(default_factory=PaperSettings)
    sphere: SphereSettings = field(default_factory=SphereSettings)
    fused: FusedSettings = field(default_factory=FusedSettings)

    def to_dict(self) -> dict[str, Any]:
        """Plain nested dict, the layout :func:`load_settings` reads back."""
        return dataclasses.asdict(self)

    def replace(self, **sections: Any) -> Settings:
        """A copy with some sections overridden by dicts or section objects."""
        data = self.to_dict()
        for name, value in sections.items():
            if name not in data:
                raise ConfigError(f"unknown settings section {name!r}; known: {', '.join(data)}")
            if dataclasses.is_dataclass(value):
                value = dataclasses.asdict(value)
            data[name] = {**data[name], **value}
        return from_dict(data)


def _check(condition: bool, message: str) -> None:
    if not condition:
        raise ConfigError(message)


def _coerce(value: Any, hint: Any, where: str) -> Any:
    origin = typing.get_origin(hint)
    if origin is Literal:
        if value not in typing.get_args(hint):
            choices = ", ".join(repr(a) for a in typing.get_args(hint))
            raise ConfigError(f"{where}: expected one of {choices}, got {value!r}")
        return value
    if origin in (typing.Union, types.UnionType):
        args = typing.get_args(hint)
        if value is None and type(None) in args:
            return None
        (inner,) = [a for a in args if a is not type(None)]
        return _coerce(value, inner, where)
    if dataclasses.is_dataclass(hint):
        if not isinstance(value, dict):
            raise ConfigError(f"{where}: expected a mapping of settings, got {type(value).__name__}")
        return _build(hint, value, where)
    if hint is bool:
        if not isinstance(value, bool):
            raise ConfigError(f"{where}: expected true or false, got {value!r}")
        return value
    if hint is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"{where}: expected a whole number, got {value!r}")
        return value
    if hint is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"{where}: expected a number, got {value!r}")
        if value != value or value in (float("inf"), float("-inf")):
            raise ConfigError(f"{where}: expected a finite number, got {value!r}")
        return float(value)
    if hint is str:
        if not isinstance(value, str):
            raise ConfigError(f"{where}: expected text, got {value!r}")
        return value
    raise ConfigError(f"{where}: unsupported setting type {hint!r}")  # pragma: no cover


def _build(cls: type, data: dict[str, Any], where: str) -> Any:
    hints = typing.get_type_hints(cls)
    names = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - names)
    if unknown:
        prefix = f"{where}." if where else ""
        raise ConfigError(f"unknown setting {prefix}{unknown[0]}; known: {', '.join(sorted(names))}")
    kwargs = {}
    for name, value in data.items():
        kwargs[name] = _coerce(value, hints[name], f"{where}.{name}" if where else name)
    try:
        return cls(**kwargs)
    except ConfigError as exc:
        raise ConfigError(str(exc)) from None


def from_dict(data: dict[str, Any]) -> Settings:
    """Build validated :class:`Settings` from a nested dict (missing keys keep their defaults)."""
    if not isinstance(data, dict):
        raise ConfigError(f"settings must be a mapping of sections, got {type(data).__name__}")
    return _build(Settings, data, "")


def load_settings(path: str | Path, base: Settings | None = None) -> Settings:
    """Read settings from a ``.yaml``/``.yml`` or ``.json`` file, laid over ``base`` (default: defaults).

    Raises
    ------
    ConfigError
        Naming the file and the problem: unreadable, not YAML/JSON, unknown key, bad value.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read settings file ({exc})") from None
    try:
        if path.suffix.lower() in (".yaml", ".yml"):
            import yaml

            data = yaml.safe_load(text)
        elif path.suffix.lower() == ".json":
            data = json.loads(text)
        else:
            raise ConfigError(f"{path}: settings file must end in .yaml, .yml or .json")
    except ConfigError:
        raise
    except Exception as exc:  # yaml.YAMLError or json.JSONDecodeError: both carry the position
        raise ConfigError(f"{path}: not valid {path.suffix.lstrip('.').upper()}: {exc}") from None
    if data is None:
        data = {}
    try:
        return overlay(base or Settings(), data)
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None


def overlay(base: Settings, data: Any) -> Settings:
    """``base`` with the sections of a parsed settings mapping laid over it (only the keys it names)."""
    if not isinstance(data, dict):
        raise ConfigError(f"settings must be a mapping of sections, got {type(data).__name__}")
    merged = base.to_dict()
    for section, values in data.items():
        merged[section] = {**merged[section], **values} if isinstance(values, dict) and section in merged else values
    return from_dict(merged)
