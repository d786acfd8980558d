"""Settings: one frozen dataclass section per stage, declared by that stage, grouped under
:class:`Settings`, and resolved in one place (:func:`resolve_settings`): defaults, then a fruit profile,
then a settings file, then overrides.

A stage declares its section beside its code::

    @dataclass(frozen=True)
    class SphereSettings(Section):
        refine: bool = setting(True, doc="...")

and the built-in sections are listed here, in :data:`BUILT_IN_SECTIONS` (nothing registers by being
imported). A section from outside the package (a method of one's own, :func:`symfruit.methods.register`
with ``settings=``) is added with :func:`register_section` and follows the built-in ones.

Values read from a mapping (a file, a profile, overrides) are validated: unknown keys, wrong types and
non-finite numbers raise :class:`~symfruit.errors.ConfigError` with the dotted path of the key, e.g.
``paper.rotations_x: expected a whole number, got 'eleven'``. Nothing is coerced: YAML 1.1 reads an unquoted
``yes``/``no``/``on``/``off`` as a boolean, so a boolean where text or a number is expected says so and how to
quote it (``evidence.outline_profile: off`` is ``False``, refused, not the choice ``'off'``), and quoted ``"yes"``
for a boolean is refused as text. A number with an exponent (``1e6``) is a number, as in YAML 1.2 and JSON
(:mod:`symfruit.io.text` reads it so; YAML 1.1 would make it text). Every section checks its fields' declared
bounds (``setting(..., ge=1)``) and its cross-field rules (:meth:`Section.check`) when it is made, from a
file or from Python; a failure names the field, and the path is added when it came from a mapping.

Merging has one rule (:func:`merge`): a mapping laid over a mapping replaces only the keys it names, at
every depth; anything else replaces the value.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import os
import types
import typing
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any, Literal, TypeVar

import numpy as np

from .core.limits import MAX_SETTINGS_BYTES  # settings are a few kB; anything larger is not settings
from .errors import ConfigError

__all__ = [
    "Section",
    "SettingError",
    "Settings",
    "from_dict",
    "known_names",
    "load_settings",
    "merge",
    "read_settings_file",
    "register_section",
    "resolve_settings",
    "section_types",
    "setting",
]

T = TypeVar("T")


#: The built-in sections in the order ``Settings``, settings files and ``symfruit settings`` list them:
#: name, the module declaring the section and its class. The stages import this module, so their classes
#: are imported when the sections are first needed, not here.
BUILT_IN_SECTIONS: tuple[tuple[str, str, str], ...] = (
    ("extract", "symfruit.extract", "ExtractSettings"),
    ("occlusion", "symfruit.occlusion", "OcclusionSettings"),
    ("segment", "symfruit.segment.colour", "SegmentSettings"),
    ("paper", "symfruit.methods.paper", "PaperSettings"),
    ("evidence", "symfruit.methods.evidence", "EvidenceSettings"),
    ("fused", "symfruit.methods.fused", "FusedSettings"),
    ("sphere", "symfruit.methods.sphere", "SphereSettings"),
    ("superellipsoid", "symfruit.methods.superellipsoid", "SuperellipsoidSettings"),
    ("input", "symfruit.methods.complete", "InputSettings"),
)

_BUILT_IN: dict[str, type] = {}  # BUILT_IN_SECTIONS' classes, once imported
_SECTIONS: dict[str, type] = {}  # sections registered with register_section, in registration order


def _sections() -> dict[str, type]:
    """Every section by name: the built-in ones, then the registered ones."""
    if not _BUILT_IN:
        import importlib

        _BUILT_IN.update({name: getattr(importlib.import_module(module), cls)
                          for name, module, cls in BUILT_IN_SECTIONS})  # fmt: skip
    return {**_BUILT_IN, **{name: cls for name, cls in _SECTIONS.items() if name not in _BUILT_IN}}


class SettingError(ConfigError):
    """A check inside a section failed; ``key`` is the field it concerns (relative to the section)."""

    def __init__(self, key: str, message: str) -> None:
        super().__init__(f"{key}: {message}" if key else message)
        self.key, self.message = key, message


def setting(default: Any, *, ge: float | None = None, gt: float | None = None, le: float | None = None,
            lt: float | None = None) -> Any:  # fmt: skip
    """A section field with a default and optional inclusive (``ge``, ``le``) or strict (``gt``, ``lt``)
    bounds, checked whenever the section is made. A nested section default is given as an instance."""
    bounds = {k: v for k, v in (("ge", ge), ("gt", gt), ("le", le), ("lt", lt)) if v is not None}
    metadata = {"bounds": bounds}
    if dataclasses.is_dataclass(default) and not isinstance(default, type):
        return dataclasses.field(default_factory=lambda: default, metadata=metadata)
    return dataclasses.field(default=default, metadata=metadata)


class Section:
    """Base of every settings section: checks the declared bounds of its fields, then :meth:`check`."""

    def __post_init__(self) -> None:
        hints = _field_hints(type(self))
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            value = getattr(self, f.name)
            # made in Python as from a file: of its declared type (a numpy number as the Python one), never text
            # for a number (a TypeError in check()) nor np.int64(-5) past the bounds below, which test int and float
            checked = _field_value(value, hints[f.name], f.name)
            if checked is not value:
                object.__setattr__(self, f.name, checked)
                value = checked
            bounds = f.metadata.get("bounds", {})
            if bounds and isinstance(value, (int, float)) and not isinstance(value, bool):
                for op, limit in bounds.items():
                    ok = {"ge": value >= limit, "gt": value > limit, "le": value <= limit, "lt": value < limit}[op]
                    if not ok:
                        sign = {"ge": ">=", "gt": ">", "le": "<=", "lt": "<"}[op]
                        raise SettingError(f.name, f"must be {sign} {limit:g}, got {value!r}")
        self.check()

    def check(self) -> None:
        """Cross-field rules; raise :class:`SettingError` naming the field."""


_HINTS: dict[type, dict[str, Any]] = {}  # each section class's resolved field types, worked out once


def _field_hints(cls: type) -> dict[str, Any]:
    hints = _HINTS.get(cls)
    if hints is None:
        hints = _HINTS[cls] = typing.get_type_hints(cls)
    return hints


def _field_value(value: Any, hint: Any, name: str) -> Any:
    """A section field's value as :func:`_coerce` reads it from a mapping (the same types and finiteness), for a
    section made in Python; a value already of its type is returned as it is, without the general check."""
    kind = type(value)
    if (kind is hint and kind in (int, bool, str)) or (kind is float and hint is float and math.isfinite(value)):
        return value
    if dataclasses.is_dataclass(hint):  # a nested section: its owner's check() names what else it was given
        return value
    return _coerce(value, hint, name)


def register_section(name: str, cls: type[T]) -> type[T]:
    """Make ``cls`` (a frozen dataclass whose every field has a default) the settings section ``name``."""
    if not (dataclasses.is_dataclass(cls) and isinstance(cls, type)):
        raise TypeError(f"settings section {name!r} must be a dataclass type, got {cls!r}")
    built_in = {entry[0]: entry[1:] for entry in BUILT_IN_SECTIONS}
    if name in built_in and built_in[name] != (cls.__module__, cls.__qualname__):
        raise ValueError(f"settings section {name!r} is the built-in {built_in[name][1]}")
    if name in _SECTIONS and _SECTIONS[name] is not cls:
        raise ValueError(f"settings section {name!r} is already registered by {_SECTIONS[name].__qualname__}")
    if name not in built_in:
        _SECTIONS[name] = cls
    return cls


def section_types() -> dict[str, type]:
    """Every section, by name: the built-in ones (:data:`BUILT_IN_SECTIONS`), then the registered ones in
    registration order."""
    return _sections()


class Settings:
    """All settings, one section per stage; every field has a default.

    ``Settings()`` holds the defaults; ``settings.paper`` (or ``settings.section("paper")``) is a section.
    Immutable, comparable, hashable and picklable.

    Examples
    --------
    >>> s = Settings().replace(paper={"rotations_x": 21})
    >>> s.paper.rotations_x, s.paper.translations
    (21, 4)
    """

    __slots__ = ("_sections",)
    _sections: dict[str, Any]

    def __init__(self, **sections: Any) -> None:
        known = _sections()
        unknown = sorted(set(sections) - set(known))
        if unknown:
            raise ConfigError(f"unknown settings section {unknown[0]!r}{_closest(unknown[0], known)}; known: "
                              f"{', '.join(known)}")  # fmt: skip
        values = {}
        for name, cls in known.items():
            value = sections.get(name)
            if value is None:
                value = cls()
            elif not isinstance(value, cls):
                article = "an" if cls.__name__[:1] in "AEIOU" else "a"  # "a EvidenceSettings" before
                raise ConfigError(f"settings section {name!r} must be {article} {cls.__name__}, got "
                                  f"{type(value).__name__}")  # fmt: skip
            values[name] = value
        object.__setattr__(self, "_sections", values)

    def section(self, name: str) -> Any:
        """The section ``name``; raises :class:`ConfigError` listing the known ones."""
        try:
            return self._sections[name]
        except (KeyError, TypeError):  # TypeError: an unhashable name
            if not isinstance(name, str):
                raise ConfigError(f"a settings section is named by text, got {type(name).__name__}") from None
            raise ConfigError(f"unknown settings section {name!r}{_closest(name, self._sections)}; known: "
                              f"{', '.join(self._sections)}") from None  # fmt: skip

    def __getattr__(self, name: str) -> Any:
        try:
            return object.__getattribute__(self, "_sections")[name]
        except KeyError:
            raise AttributeError(f"Settings has no section {name!r}") from None

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("Settings are immutable; use replace()")

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Settings) and self._sections == other._sections

    def __hash__(self) -> int:
        return hash(tuple(self._sections.items()))

    def __repr__(self) -> str:
        return f"Settings({', '.join(f'{k}={v!r}' for k, v in self._sections.items())})"

    def __reduce__(self) -> tuple[Any, ...]:
        return (_rebuild, (self._sections,))

    def to_dict(self) -> dict[str, Any]:
        """Plain nested dict, the layout :func:`from_dict` and settings files read back."""
        return {name: dataclasses.asdict(value) for name, value in self._sections.items()}

    def replace(self, **overrides: Any) -> Settings:
        """A copy with sections overridden by mappings (only the keys they name) or section objects."""
        return from_dict(merge(self.to_dict(), _plain(overrides)))


def _plain(value: Any) -> Any:
    """Section objects, at any depth of a mapping, as plain dicts."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return dataclasses.asdict(value)
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _rebuild(sections: dict[str, Any]) -> Settings:
    return Settings(**sections)


def merge(base: Mapping[str, Any], over: Mapping[str, Any]) -> dict[str, Any]:
    """``base`` with ``over`` laid over it: mappings merge key by key at every depth, other values replace."""
    out = dict(base)
    for key, value in over.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = merge(out[key], value)
        else:
            out[key] = value
    return out


#: Words YAML 1.1 (PyYAML's safe loader) reads as a boolean when unquoted, in any of its three cases.
YAML_BOOLEAN_WORDS = ("y", "yes", "n", "no", "true", "false", "on", "off")


def _as_read(value: Any, choices: tuple[Any, ...] = (), *, number: bool = False) -> str:
    """``value`` as the error shows it: a boolean where text or a ``number`` is expected is said to be what YAML
    makes of an unquoted ``yes``/``no``/``on``/``off`` (the value written, ``'off'``, cannot be told from the
    boolean), naming the choice that is such a word when there is one; anything else as its repr."""
    if not isinstance(value, bool):
        return repr(value)
    words = [c for c in choices if isinstance(c, str) and c.lower() in YAML_BOOLEAN_WORDS]
    fix = "write a number" if number else f"quote text, e.g. {words[0] if words else 'yes'!r}"
    return f"{value!r} (YAML reads an unquoted yes, no, on, off, true or false as a boolean: {fix})"


def _coerce(value: Any, hint: Any, where: str) -> Any:
    origin = typing.get_origin(hint)
    if origin is Literal:
        choices = typing.get_args(hint)
        if not isinstance(value, str) or value not in choices:
            raise ConfigError(f"{where}: expected one of {', '.join(repr(a) for a in choices)}, got "
                              f"{_as_read(value, choices)}")  # fmt: skip
        return value
    if origin in (typing.Union, types.UnionType):
        args = typing.get_args(hint)
        if value is None and type(None) in args:
            return None
        (inner,) = [a for a in args if a is not type(None)]
        return _coerce(value, inner, where)
    if dataclasses.is_dataclass(hint):
        if not isinstance(value, Mapping):
            raise ConfigError(f"{where}: expected a mapping of settings, got {type(value).__name__}")
        return _build(typing.cast(type, hint), value, where)
    if hint is bool:
        if isinstance(value, np.bool_):
            value = bool(value)
        if not isinstance(value, bool):
            quoted = isinstance(value, str) and value.strip().lower() in YAML_BOOLEAN_WORDS
            why = " (text, as quoted: write true or false without quotes)" if quoted else ""
            raise ConfigError(f"{where}: expected true or false, got {value!r}{why}")
        return value
    if hint is int:  # a numpy whole number (overrides handed over from arrays) as the Python one
        if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Integral):
            whole = isinstance(value, float) and value.is_integer() and abs(value) < 1e18
            why = f" (a number with a point or an exponent is a fraction: write {int(value)})" if whole else ""
            raise ConfigError(f"{where}: expected a whole number, got {_as_read(value, number=True)}{why}")
        return int(value)
    if hint is float:
        if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Real):
            raise ConfigError(f"{where}: expected a number, got {_as_read(value, number=True)}")
        try:
            finite = math.isfinite(value)
        except OverflowError:  # a whole number of hundreds of digits: beyond any float
            finite = False
        if not finite:
            from .core.limits import shown

            raise ConfigError(f"{where}: expected a finite number, got {shown(value)}")
        return float(value)
    if hint is str:
        if not isinstance(value, str):
            raise ConfigError(f"{where}: expected text, got {_as_read(value)}")
        return value
    raise ConfigError(f"{where}: unsupported setting type {hint!r}")  # pragma: no cover


def _build(cls: type, data: Mapping[str, Any], where: str) -> Any:
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    prefix = f"{where}." if where else ""
    bad = [k for k in data if not isinstance(k, str)]
    if bad:
        raise ConfigError(f"{where or 'settings'}: setting names must be text, got {bad[0]!r}")
    unknown = sorted(set(data) - set(fields))
    if unknown:
        raise ConfigError(f"unknown setting {prefix}{unknown[0]}{_closest(unknown[0], fields)}; "
                          f"{_known(unknown[0], fields)}")  # fmt: skip
    kwargs = {name: _coerce(value, hints[name], prefix + name) for name, value in data.items()}
    try:
        return cls(**kwargs)
    except SettingError as exc:
        raise ConfigError(f"{prefix}{exc.key}: {exc.message}" if exc.key else f"{where}: {exc.message}") from None


def from_dict(data: Any) -> Settings:
    """Validated :class:`Settings` from a nested mapping (missing keys keep their defaults)."""
    if not isinstance(data, Mapping):
        raise ConfigError(f"settings must be a mapping of sections, got {type(data).__name__}")
    bad = [k for k in data if not isinstance(k, str)]
    if bad:
        raise ConfigError(f"settings section names must be text, got {bad[0]!r}")
    known = _sections()
    unknown = sorted(set(data) - set(known))
    if unknown:
        raise ConfigError(f"unknown setting {unknown[0]}{_closest(unknown[0], known)}; known sections: "
                          f"{', '.join(known)}")  # fmt: skip
    return Settings(**{name: _build(known[name], value, name) if isinstance(value, Mapping) else
                       _not_a_mapping(name, value) for name, value in data.items()})  # fmt: skip


def _closest(key: str, known: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` for the known name closest to a misspelt ``key`` (difflib), else ``""``."""
    import difflib

    close = difflib.get_close_matches(key.lower(), list(known), n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


#: Characters of known names an unknown name's error lists whole; a longer list (evidence has 49 settings, 700
#: characters) is cut to the names near the unknown one, so that the error stays one short line.
KNOWN_LISTED = 160


def known_names(key: str, known: Iterable[str], *, where: str) -> str:
    """``known: ...`` for the error of an unknown name ``key``: every name of ``known`` where they are few
    (:data:`KNOWN_LISTED` characters), else the ones near it (close in spelling, or sharing a word: ``tilt`` ->
    ``tilt_bend, tilt_blocks, ...``; the first ones where none is), at most six, how many more there are and
    ``where`` the rest are listed."""
    import difflib

    names = list(known)
    listed = ", ".join(names)
    if len(listed) <= KNOWN_LISTED:
        return f"known: {listed}"
    near = difflib.get_close_matches(str(key).lower(), names, n=3, cutoff=0.5)
    words = {w for w in str(key).lower().replace(".", "_").split("_") if len(w) > 1}
    near = (near + [n for n in names if n not in near and words & set(n.split("_"))])[:6] or names[:6]
    return f"known: {', '.join(near)} and {len(names) - len(near)} more ({where})"


def _known(key: str, known: Iterable[str]) -> str:
    return known_names(key, sorted(known), where="`symfruit settings` lists them with their values")


def _not_a_mapping(name: str, value: Any) -> Any:
    if value is None:  # `evidence:` with nothing under it (a file cut after its first line): not Python's "NoneType"
        raise ConfigError(f"{name}: holds no settings (nothing under it); give its settings indented below it, or "
                          "remove the line")  # fmt: skip
    raise ConfigError(f"{name}: expected a mapping of settings, got {type(value).__name__}")


def read_settings_file(path: str | Path) -> dict[str, Any]:
    """Parse a ``.yaml``/``.yml`` or ``.json`` settings file into a mapping (not yet validated).

    Raises
    ------
    ConfigError
        Naming the file and the problem: unreadable, too large, not YAML/JSON, not a mapping.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".yaml", ".yml", ".json"):
        raise ConfigError(f"{path}: settings file must end in .yaml, .yml or .json")
    from .io.text import read_structured

    data = read_structured(path, what="settings file", max_bytes=MAX_SETTINGS_BYTES, error=ConfigError)
    if data is None:  # YAML reads a file of comments or ``null`` alone as None: "got NoneType"
        raise ConfigError(f"{path}: the settings file holds no settings (only comments or null); give at least one "
                          "section, e.g. 'detect: {method: evidence}', or no settings file")  # fmt: skip
    return data


def load_settings(path: str | Path, base: Settings | None = None) -> Settings:
    """Settings from a file laid over ``base`` (default: the defaults); errors name the file."""
    if path is None:  # resolve_settings' "no file": here it would be the defaults, with no file read, unsaid
        raise ConfigError("load_settings needs a settings file path, got None (the defaults are Settings())")
    return resolve_settings(config=path, base=base)


def resolve_settings(
    *,
    fruit: str | Path | None = None,
    config: str | Path | None = None,
    overrides: Mapping[str, Any] | None = None,
    base: Settings | None = None,
) -> Settings:
    """The effective settings: ``base`` (default: the defaults), then the fruit profile, then the settings
    file, then ``overrides``; each names only what it changes.

    Every command and the API resolve settings here, so they mean the same everywhere.

    Parameters
    ----------
    fruit : str or path, optional
        A shipped profile name (:func:`symfruit.profiles.available_profiles`) or a profile file.
    config : path, optional
        A settings file (YAML or JSON).
    overrides : mapping, optional
        Nested ``{section: {key: value}}``.

    Raises
    ------
    ConfigError
        Naming the profile or file and the key.
    """
    for name, value in (("fruit", fruit), ("config", config)):  # a number or list is no name or path (TypeError)
        if value is not None and not isinstance(value, str | bytes | os.PathLike):
            raise ConfigError(f"{name} must be a profile name or a path, got {type(value).__name__}")
    if isinstance(config, bytes):
        config = os.fsdecode(config)
    if isinstance(fruit, bytes):
        fruit = os.fsdecode(fruit)
    if config is not None and not str(config).strip():  # '' was read as the folder '.': ".: must end in .yaml"
        raise ConfigError("config is an empty path (an unset variable?); give a settings file, or None for none")
    if base is not None and not isinstance(base, Settings):
        raise ConfigError(f"base must be a Settings, got {type(base).__name__}")
    data = (base or Settings()).to_dict()
    if fruit is not None:
        from .profiles import profile_data

        label, layer = profile_data(fruit)
        data = _lay(data, layer, label)
    if config is not None:
        data = _lay(data, read_settings_file(config), str(config))
    if overrides:
        data = _lay(data, overrides, "")
    return from_dict(data)


def _lay(data: dict[str, Any], layer: Any, label: str) -> dict[str, Any]:
    """``layer`` over ``data``, validated, with errors prefixed by ``label``."""
    try:
        if not isinstance(layer, Mapping):
            raise ConfigError(f"settings must be a mapping of sections, got {type(layer).__name__}")
        merged = merge(data, layer)
        from_dict(merged)
    except ConfigError as exc:
        raise ConfigError(f"{label}: {exc}" if label else str(exc)) from None
    return merged
