"""Errors raised by symfruit.

Every error a user can cause derives from :class:`SymfruitError`, which is also a
:class:`ValueError`, so callers may catch either.  Messages name the input and say what to do.
"""

from __future__ import annotations

__all__ = ["ConfigError", "FileFormatError", "InputError", "SymfruitError"]


class SymfruitError(ValueError):
    """Base class of every error symfruit raises on purpose."""


class InputError(SymfruitError):
    """An array or value handed to the library cannot be used (empty, non-finite, wrong shape...)."""


class FileFormatError(SymfruitError):
    """A file cannot be read or written: unknown extension, corrupt or truncated content."""


class ConfigError(SymfruitError):
    """A settings file or settings value is invalid."""
