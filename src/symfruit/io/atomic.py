"""Atomic file output: write to a temporary file in the same folder, then rename over the target.

Every file symfruit writes goes through :func:`atomic_write`. Inside an output folder of a run (``root``,
or any :class:`symfruit.io.outputs.OutputFolder` that is open and holds the path: :func:`active_root`), the
folders from the output folder down to the file are opened one at a time without following links
(``O_NOFOLLOW``) and created where missing, and the file is created and renamed relative to its folder's
descriptor: a sub-folder that is a symbolic link (to a folder elsewhere) is refused by name, never followed,
so nothing is written outside the output folder, even when a link is swapped in while the run goes on; and
the output folder refuses a path that is one of the run's inputs. A path the user names directly
(``--output`` of ``complete``) is theirs: links in its folders are followed as the user set them up, and
:func:`symfruit.writers.write_result` follows a link at the file itself to its target (this module replaces a
link at the file name, never writes through it); only the temporary file is created without following one.
"""

from __future__ import annotations

import contextlib
import contextvars
import json
import os
import secrets
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

from ..errors import OutputError

if TYPE_CHECKING:
    from .outputs import OutputFolder

__all__ = ["activate", "active_root", "atomic_write", "folder_fd", "stale_temporaries", "write_json"]

#: The output folders open in this thread of control, innermost last (:func:`activate`).
_ACTIVE: contextvars.ContextVar[tuple[Any, ...]] = contextvars.ContextVar("symfruit_outputs", default=())

_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_DIRECTORY = getattr(os, "O_DIRECTORY", 0)
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)
#: Temporary files are ``.<name>.<pid>-<token>.tmp``: the pid tells a live run's file from a killed run's.
_TMP_SUFFIX = ".tmp"


def _error(path: Path | str, exc: OSError, doing: str = "cannot write") -> OutputError:
    """The error of a plain operating-system failure (not a refusal of ours)."""
    err = OutputError(f"{path}: {doing} ({exc.strerror or exc})", exc.errno)
    err.plain = True  # type: ignore[attr-defined]
    return err


def _root_of(root: Path | OutputFolder | None) -> Path | None:
    if root is None or isinstance(root, Path):
        return root
    return root.root


def _inside(path: Path, base: Path) -> bool:
    here, top = os.path.abspath(path), os.path.abspath(base)
    return here == top or here.startswith(top.rstrip(os.sep) + os.sep)


@contextlib.contextmanager
def activate(folder: OutputFolder) -> Iterator[None]:
    """Make ``folder`` the output folder of every write under its root until the block ends."""
    token = _ACTIVE.set((*_ACTIVE.get(), folder))
    try:
        yield
    finally:
        _ACTIVE.reset(token)


def active_root(path: str | Path) -> OutputFolder | None:
    """The innermost open output folder that holds ``path`` (by its path), or None."""
    for folder in reversed(_ACTIVE.get()):
        if _inside(Path(path), folder.root):
            return folder
    return None


@contextlib.contextmanager
def folder_fd(folder: str | Path, *, root: Path | OutputFolder | None = None, create: bool = True) -> Iterator[int]:
    """An open descriptor of ``folder`` (created if missing), closed on exit.

    With ``root``, ``folder`` must be ``root`` or lie under it (by its path), and every folder below ``root``
    is opened without following links: a link is refused (:class:`~symfruit.errors.OutputError`).

    Raises
    ------
    OutputError
        When the folder cannot be made or opened, lies outside ``root``, or a part of it is a link.
    """
    folder = Path(folder) if str(folder) else Path(".")
    base = _root_of(root if root is not None else active_root(folder))
    if base is None:
        try:
            if create:
                folder.mkdir(parents=True, exist_ok=True)
            fd = os.open(folder, os.O_RDONLY | _DIRECTORY | _CLOEXEC)
        except OSError as exc:
            err = _error(folder, exc, "cannot create output folder" if create else "cannot write to folder")
            file = next((p for p in (folder, *folder.parents) if p.exists() and not p.is_dir()), None)
            if file is not None:  # said as it is, not as the system's "File exists" / "Not a directory"
                err = OutputError(f"{folder}: {file} is a file, not a folder; not overwritten", exc.errno)
                err.plain, err.reason = True, f"{file} is a file, not a folder"  # type: ignore[attr-defined]
            raise err from None
    else:
        if not _inside(folder, base):
            raise OutputError(f"{folder}: outside the output folder {base}; not written")
        parts = Path(os.path.relpath(os.path.abspath(folder), os.path.abspath(base))).parts
        parts = () if parts == (".",) else parts
        if any(p in ("..", "") for p in parts):
            raise OutputError(f"{folder}: leaves the output folder {base}; not written")
        try:
            fd = os.open(base, os.O_RDONLY | _DIRECTORY | _CLOEXEC)
        except OSError as exc:
            raise _error(base, exc, "cannot write to folder") from None
        here = base
        for part in parts:
            here = here / part
            try:
                if create:
                    with contextlib.suppress(FileExistsError):
                        os.mkdir(part, dir_fd=fd)
                nfd = os.open(part, os.O_RDONLY | _DIRECTORY | _NOFOLLOW | _CLOEXEC, dir_fd=fd)
            except OSError as exc:
                os.close(fd)
                if os.path.islink(here):
                    msg = (f"{here}: is a symbolic link (to {os.readlink(here)}); symfruit does not write through "
                           f"links inside its output folder {base}")  # fmt: skip
                    raise OutputError(msg, exc.errno) from None
                if os.path.exists(here) and not os.path.isdir(here):
                    raise OutputError(f"{here}: is a file, not a folder; not overwritten", exc.errno) from None
                raise _error(here, exc, "cannot write to folder") from None
            os.close(fd)
            fd = nfd
    try:
        yield fd
    finally:
        os.close(fd)


@contextlib.contextmanager
def atomic_write(path: str | Path, mode: str = "wb", *, root: Path | OutputFolder | None = None) -> Iterator[IO[Any]]:
    """Open a temporary file beside ``path``; on success rename it to ``path``, else delete it.

    An interrupted run never leaves a half-written ``path``.

    Parameters
    ----------
    path : path
    mode : ``"wb"`` or ``"w"`` (UTF-8)
    root : Path or OutputFolder, optional
        The output folder ``path`` must stay in (see the module docstring); an :class:`OutputFolder` also
        refuses a ``path`` that is one of the run's inputs.

    Raises
    ------
    OutputError
        Naming the file: the folder cannot be written, the disk is full (``errno``), ``path`` is a folder, an
        input, or lies behind a link.
    """
    path = Path(path)
    root = root if root is not None else active_root(path)
    if root is not None and not isinstance(root, Path):
        root.check(path)
    for folder in _ACTIVE.get():  # a run's inputs are never written, wherever the path points
        folder.check(path)
    name = path.name
    if name in ("", ".", ".."):
        raise OutputError(f"{path}: not a file name")
    stack = contextlib.ExitStack()
    try:
        dfd = stack.enter_context(folder_fd(path.parent, root=root))
    except OutputError as exc:
        if not getattr(exc, "plain", False) or exc.errno is None:
            raise
        reason = getattr(exc, "reason", None) or os.strerror(exc.errno)
        raise OutputError(f"{path}: cannot write to folder {path.parent} ({reason})", exc.errno) from None
    with stack:
        with contextlib.suppress(FileNotFoundError):
            st = os.stat(name, dir_fd=dfd, follow_symlinks=False)
            if stat.S_ISDIR(st.st_mode):
                raise OutputError(f"{path}: is a folder; the file cannot be written there")
        tmp = f".{name[:200]}.{os.getpid()}-{secrets.token_hex(4)}{_TMP_SUFFIX}"
        try:
            # 0o666 less the umask: the usual permissions, created new (never through a link)
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW | _CLOEXEC, 0o666, dir_fd=dfd)
        except OSError as exc:
            raise _error(path, exc) from None
        try:
            encoding = None if "b" in mode else "utf-8"
            with os.fdopen(fd, mode, encoding=encoding) as handle:
                yield handle
                handle.flush()
                os.fsync(handle.fileno())
            os.replace(tmp, name, src_dir_fd=dfd, dst_dir_fd=dfd)
        except BaseException as exc:
            with contextlib.suppress(OSError):
                os.unlink(tmp, dir_fd=dfd)
            if isinstance(exc, OSError):
                raise _error(path, exc) from None
            raise


def stale_temporaries(fd: int) -> list[str]:
    """Names of temporary files in the folder ``fd`` that a run no longer alive left behind (a killed run);
    a live run's (another process writing now, or this one) are not listed."""
    out = []
    for name in os.listdir(fd):
        if not (name.startswith(".") and name.endswith(_TMP_SUFFIX)):
            continue
        pid_part = name[: -len(_TMP_SUFFIX)].rsplit(".", 1)[-1].split("-", 1)[0]
        if pid_part.isascii() and pid_part.isdigit() and _alive(int(pid_part)):  # '²'.isdigit(): int() refuses it
            continue
        out.append(name)
    return out


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's live process
        return True
    except (OverflowError, OSError):
        return False
    return True


def write_json(path: str | Path, data: Any, *, root: Path | OutputFolder | None = None) -> None:
    """Write ``data`` as indented JSON, atomically (``root``: see :func:`atomic_write`)."""
    with atomic_write(path, "w", root=root) as handle:
        json.dump(data, handle, indent=2, allow_nan=False)
        handle.write("\n")
