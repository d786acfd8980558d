"""Errors raised by symfruit.

Every error a user can cause derives from :class:`SymfruitError`, which is also a
:class:`ValueError`, so callers may catch either.  Messages name the input and say what to do.
"""

from __future__ import annotations

__all__ = ["ConfigError", "FileFormatError", "InputError", "OutputError", "SymfruitError", "SymfruitWarning"]


class SymfruitError(ValueError):
    """Base class of every error symfruit raises on purpose."""


class InputError(SymfruitError):
    """An array or value handed to the library cannot be used (empty, non-finite, wrong shape...)."""


class FileFormatError(SymfruitError):
    """A file cannot be read or written: unknown extension, corrupt or truncated content."""


class ConfigError(SymfruitError):
    """A settings file or settings value is invalid."""


class OutputError(FileFormatError):
    """A file cannot be written: the folder is not writable, the disk is full, the target is a folder, an
    input, or lies behind a link out of the output folder, or another run holds the output folder.

    ``errno`` is the operating system's error number when there was one (``errno.ENOSPC``: the disk is
    full), else None.
    """

    def __init__(self, message: str, errno: int | None = None) -> None:
        super().__init__(message)
        self.errno = errno


class SymfruitWarning(UserWarning):
    """Input symfruit uses but cannot honour in full (intrinsics with lens distortion it does not apply); the
    command line prints it as ``symfruit: warning: ...``."""
