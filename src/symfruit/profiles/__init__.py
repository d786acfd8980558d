"""Fruit profiles: per fruit kind, the settings that work best, as data files (YAML).

A profile is a partial settings file; ``symfruit ... --fruit NAME`` loads ``NAME.yaml`` from this package,
``--fruit PATH.yaml`` loads a user's own. :func:`symfruit.settings.resolve_settings` lays it over the
defaults and under ``--config``.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import Any

from ..errors import ConfigError

__all__ = ["available_profiles", "load_profile", "profile_data"]


def available_profiles() -> list[str]:
    """Names of the shipped profiles."""
    return sorted(p.name[:-5] for p in resources.files(__package__).iterdir() if p.name.endswith(".yaml"))


def profile_data(name_or_path: str | Path) -> tuple[str, Any]:
    """``(label for messages, parsed mapping)`` of a shipped profile (by name) or of a profile file.

    Raises
    ------
    ConfigError
        For an unknown name or an unreadable file.
    """
    from ..settings import read_settings_file

    path = Path(name_or_path)
    if path.suffix.lower() in (".yaml", ".yml", ".json"):
        return str(path), read_settings_file(path)
    resource = resources.files(__package__) / f"{name_or_path}.yaml"
    if len(str(name_or_path)) > 200 or not resource.is_file():  # a longer name no file system holds (OSError)
        raise ConfigError(
            f"no fruit profile {str(name_or_path)!r}; shipped: {', '.join(available_profiles())}, "
            "or give a profile file (.yaml)"
        )
    import yaml

    return f"profile {name_or_path}", yaml.safe_load(resource.read_text(encoding="utf-8")) or {}


def load_profile(name_or_path: str | Path, base: Any = None) -> Any:
    """The settings of a profile laid over ``base`` (default: the defaults); see :func:`resolve_settings`."""
    from ..settings import resolve_settings

    return resolve_settings(fruit=name_or_path, base=base)
