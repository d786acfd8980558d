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

__all__ = ["InputSettings", "PaperSettings", "Settings", "SphereSettings", "load_settings"]


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
        ``Mp`` is rasterised. None estimates it from the median spacing of the projected points.
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

    def __post_init__(self) -> None:
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
class Settings:
    """All settings, grouped per stage. Every field has a default; files override only what they name."""

    input: InputSettings = field(default_factory=InputSettings)
    paper: PaperSettings = field(default_factory=PaperSettings)
    sphere: SphereSettings = field(default_factory=SphereSettings)

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


def load_settings(path: str | Path) -> Settings:
    """Read settings from a ``.yaml``/``.yml`` or ``.json`` file.

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
        return from_dict(data)
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None
