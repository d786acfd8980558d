"""Fruit profiles: per fruit kind, the settings that work best, as data files (YAML).

A profile is a partial settings file; ``symfruit ... --fruit NAME`` loads ``NAME.yaml`` from this
package, ``--fruit PATH.yaml`` loads a user's own. Settings apply in the order defaults, profile,
``--config``.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from ..config import Settings, load_settings, overlay
from ..errors import ConfigError

__all__ = ["available_profiles", "load_profile"]


def available_profiles() -> list[str]:
    """Names of the shipped profiles."""
    return sorted(p.name[:-5] for p in resources.files(__package__).iterdir() if p.name.endswith(".yaml"))


def load_profile(name_or_path: str | Path, base: Settings | None = None) -> Settings:
    """Settings of a shipped profile (by name) or of a profile file, laid over ``base`` (default settings).

    Raises
    ------
    ConfigError
        For an unknown name, an unreadable file or an invalid setting (naming the key).
    """
    path = Path(name_or_path)
    if path.suffix.lower() in (".yaml", ".yml", ".json"):
        return load_settings(path, base=base)
    resource = resources.files(__package__) / f"{name_or_path}.yaml"
    if not resource.is_file():
        raise ConfigError(
            f"no fruit profile {str(name_or_path)!r}; shipped: {', '.join(available_profiles())}, "
            "or give a profile file (.yaml)"
        )
    import yaml

    try:
        return overlay(base or Settings(), yaml.safe_load(resource.read_text(encoding="utf-8")) or {})
    except ConfigError as exc:
        raise ConfigError(f"profile {name_or_path}: {exc}") from None
