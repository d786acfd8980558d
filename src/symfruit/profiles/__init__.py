"""Fruit profiles: per fruit kind, the settings that work best, as data files (YAML).

A profile is a partial settings file; ``symfruit ... --fruit NAME`` loads ``NAME.yaml`` from this
package, ``--fruit PATH.yaml`` loads a user's own. Settings apply in the order defaults, profile,
``--config``.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from ..config import Settings, from_dict, load_settings
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
    import yaml

    path = Path(name_or_path)
    if path.suffix.lower() in (".yaml", ".yml", ".json"):
        load_settings(path)  # validates the file on its own, with the file named in any error
        text = path.read_text(encoding="utf-8")
    else:
        resource = resources.files(__package__) / f"{name_or_path}.yaml"
        if not resource.is_file():
            raise ConfigError(
                f"no fruit profile {str(name_or_path)!r}; shipped: {', '.join(available_profiles())}, "
                "or give a profile file (.yaml)"
            )
        text = resource.read_text(encoding="utf-8")
    data = yaml.safe_load(text) or {}  # JSON is YAML too
    merged = (base or Settings()).to_dict()
    for section, values in data.items():
        if not isinstance(values, dict):
            raise ConfigError(f"profile {name_or_path}: section {section!r} must be a mapping")
        merged[section] = {**merged.get(section, {}), **values}
    try:
        return from_dict(merged)
    except ConfigError as exc:
        raise ConfigError(f"profile {name_or_path}: {exc}") from None
