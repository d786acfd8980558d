"""Output folders: the one rule for what a run may write, and under which names.

A command that writes a folder of results (``detect``, ``segment``, ``demo``, ``scenes``) opens it as an
:class:`OutputFolder`, and every file goes through :func:`symfruit.io.atomic.atomic_write` with it:

* **Names.** An entry (a frame's folder, an image's label file) is named by :func:`entry_name`: a name made
  of letters, digits and ``._-`` is kept, anything else (and a name the run keeps for its own files, such
  as ``errors.json``) becomes a cleaned name, ``+`` and a hash of the original. A kept name never holds
  ``+``, so no two entries share a name however the input grows. :func:`unique_names` does the same for
  names that are not unique among the inputs (``a.png`` and ``a.jpg`` share the stem ``a``) or that take
  another entry's derived name (``a_overlay.png`` is ``a.png``'s overlay): each of those gets the hash of
  its full path instead.
* **Containment.** Nothing is written outside the output folder: folders below it are opened without
  following links, and a link is refused by name (:mod:`symfruit.io.atomic`).
* **Inputs.** Nothing is written over a run's input file or straight into an input folder; an output
  folder that *is* an input folder is refused before anything is written.
* **One writer.** The folder is locked (``flock`` on ``.symfruit.lock``) while the run writes; a second run
  on the same folder is refused at once with the first one's process id. The kernel drops the lock of a
  run that dies, so a killed run never leaves the folder locked.

Every refusal is an :class:`~symfruit.errors.OutputError` that says what was refused and why.
"""

from __future__ import annotations

import contextlib
import contextvars
import errno
import hashlib
import os
import re
from collections import Counter
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from ..errors import OutputError
from .atomic import _ACTIVE, atomic_write, folder_fd, write_json

__all__ = ["LOCK_NAME", "OutputFolder", "entry_name", "reserve_record", "unique_names", "write_record"]

#: The lock file of an output folder (removed when the run ends).
LOCK_NAME = ".symfruit.lock"
_SAFE = re.compile(r"[^A-Za-z0-9._-]+")


def _digest(text: str) -> str:
    return hashlib.sha1(text.encode("utf-8", "surrogateescape")).hexdigest()[:8]


def _clean(name: str) -> str:
    return _SAFE.sub("_", name).strip("._")[:100]


def entry_name(name: str, *, reserved: Iterable[str] = (), default: str = "frame") -> str:
    """The file or folder name of an entry called ``name``: ``name`` itself when it is a safe name (letters,
    digits, ``._-``; not hidden) that is not ``reserved`` (compared without case), else the cleaned name,
    ``+`` and a short hash of ``name``. A safe name never holds ``+``, so no two names share an entry."""
    clean = _clean(name)
    taken = {r.casefold() for r in reserved}
    if clean == name and name and name.casefold() not in taken:
        return name
    return f"{clean or default}+{_digest(name)}"


def unique_names(
    keys: Sequence[str], ids: Sequence[str], *, derived: Sequence[str] = (), reserved: Iterable[str] = ()
) -> list[str]:
    """Distinct names for entries whose natural names are ``keys`` (e.g. image stems).

    Parameters
    ----------
    keys : sequence of str
        The natural name of each entry.
    ids : sequence of str
        What tells the entries apart (e.g. each image's full path).
    derived : sequence of str
        Suffixes the run appends to a name for further outputs (``_overlay``): a key ending in one takes
        another entry's derived name, so it is hashed.
    reserved : iterable of str
        Names the run keeps for its own files.

    Returns
    -------
    list of str
        ``keys[i]`` where it is safe, unique (without case) and takes no derived name; else the cleaned key,
        ``+`` and a hash of ``ids[i]``. Kept names never hold ``+`` and hashed ones always do.
    """
    if len(keys) != len(ids):
        raise ValueError("keys and ids must be the same length")
    counts = Counter(k.casefold() for k in keys)
    out = []
    for key, ident in zip(keys, ids, strict=True):
        shared = counts[key.casefold()] > 1 or any(key.casefold().endswith(d.casefold()) for d in derived)
        out.append(f"{_clean(key) or 'image'}+{_digest(ident)}" if shared else
                   entry_name(key, reserved=reserved, default="image"))  # fmt: skip
    return out


class OutputFolder:
    """The output folder of one run: locked while open, the one place its paths are checked.

    Parameters
    ----------
    root : path
        The folder (created when missing).
    inputs : iterable of path
        The run's input files: never written over.
    input_folders : iterable of path
        The run's input folders: nothing is written straight into them, and ``root`` may not be one.
    lock : bool
        Take the folder's lock (refuse a second writer).
    what : str
        How the folder is named in messages (e.g. ``--output``).

    Examples
    --------
    >>> with OutputFolder("out", inputs=["photos/a.png"]) as out:  # doctest: +SKIP
    ...     write_json(out.root / "errors.json", {}, root=out)
    """

    def __init__(
        self,
        root: str | Path,
        *,
        inputs: Iterable[str | Path] = (),
        input_folders: Iterable[str | Path] = (),
        lock: bool = True,
        what: str = "output folder",
    ) -> None:
        self.root = Path(root)
        self.what = what
        self._inputs = {os.path.realpath(p) for p in inputs}
        self._input_folders = {os.path.realpath(p) for p in input_folders}
        self._lock = lock
        self._fd: int | None = None
        self._lock_fd: int | None = None
        self._token: contextvars.Token[tuple[Any, ...]] | None = None

    # -- life cycle ---------------------------------------------------------------------------------------
    def open(self) -> OutputFolder:
        """Create the folder, refuse it if it is an input folder, take its lock.

        Raises
        ------
        OutputError
            When the folder cannot be made or written, is an input folder, or another run holds it.
        """
        real = os.path.realpath(self.root)
        if real in self._input_folders:
            raise OutputError(f"{self.root}: the {self.what} is also an input folder; its outputs would overwrite or "
                              "mix with the inputs: choose another output folder")  # fmt: skip
        try:
            self.root.mkdir(parents=True, exist_ok=True)
            self._fd = os.open(self.root, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
        except FileExistsError:
            if os.path.islink(self.root) and not os.path.exists(self.root):
                target = os.readlink(self.root)
                raise OutputError(
                    f"{self.root}: cannot write to folder (the {self.what} is a dangling or looping link, to {target}; "
                    "make that folder or choose another)"
                ) from None
            raise OutputError(f"{self.root}: cannot write to folder (the {self.what} is a file)") from None
        except OSError as exc:
            file = next((p for p in self.root.parents if p.exists() and not p.is_dir()), None)
            why = f"{file} is a file, not a folder" if file is not None else exc.strerror or exc  # not "Not a dir..."
            raise OutputError(f"{self.root}: cannot write to folder ({why})", exc.errno) from None
        if self._lock:
            try:
                self._take_lock()
            except BaseException:
                self.close()
                raise
        self._token = _ACTIVE.set((*_ACTIVE.get(), self))  # every write under root now goes through self
        return self

    def _take_lock(self) -> None:
        try:
            import fcntl
        except ImportError:  # pragma: no cover - no flock on this platform: one writer is the user's care
            return
        assert self._fd is not None
        flags = os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
        for _ in range(100):  # the file may be replaced between open and lock when its holder ends: try again
            try:
                fd = os.open(LOCK_NAME, flags, 0o666, dir_fd=self._fd)
            except OSError as exc:
                raise OutputError(f"{self.root}: cannot write to folder ({exc.strerror or exc})", exc.errno) from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                holder = _read_pid(fd)
                os.close(fd)
                if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                    who = f" (pid {holder})" if holder else ""
                    msg = (f"{self.root}: another symfruit run{who} is writing into this {self.what}; wait for it "
                           "to end or choose another output folder")  # fmt: skip
                    raise OutputError(msg, exc.errno) from None
                raise OutputError(
                    f"{self.root}: cannot lock the {self.what} ({exc.strerror or exc})", exc.errno
                ) from None
            try:
                now = os.stat(LOCK_NAME, dir_fd=self._fd, follow_symlinks=False)
            except FileNotFoundError:
                os.close(fd)
                continue
            mine = os.fstat(fd)
            if (now.st_ino, now.st_dev) != (mine.st_ino, mine.st_dev):
                os.close(fd)
                continue
            with contextlib.suppress(OSError):
                os.ftruncate(fd, 0)
                os.write(fd, f"{os.getpid()}\n".encode())
            self._lock_fd = fd
            return
        raise OutputError(f"{self.root}: cannot lock the {self.what} (its lock file keeps changing)")

    def close(self) -> None:
        """Release the lock (the lock file is removed while still held, so no other run can be cut off)."""
        if self._token is not None:
            try:
                _ACTIVE.reset(self._token)
            except ValueError:  # closed in another context than it was opened in
                _ACTIVE.set(tuple(f for f in _ACTIVE.get() if f is not self))
            self._token = None
        if self._lock_fd is not None:
            if self._fd is not None:
                with contextlib.suppress(OSError):
                    os.unlink(LOCK_NAME, dir_fd=self._fd)
            os.close(self._lock_fd)
            self._lock_fd = None
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def __enter__(self) -> OutputFolder:
        return self.open()

    def __exit__(self, *exc: Any) -> None:
        self.close()

    # -- checks -------------------------------------------------------------------------------------------
    def check(self, path: str | Path) -> Path:
        """``path``, if the run may write it: not one of its input files, not straight inside an input
        folder (containment and links are checked as the file is written, :mod:`symfruit.io.atomic`).

        Raises
        ------
        OutputError
            Saying what was refused.
        """
        path = Path(path)
        parent = os.path.realpath(path.parent)
        if os.path.join(parent, path.name) in self._inputs:
            raise OutputError(f"{path}: is an input of this run; it is not overwritten")
        if parent in self._input_folders:
            raise OutputError(f"{path}: would be written into the input folder {path.parent}; not written")
        return path


def _read_pid(fd: int) -> str:
    with contextlib.suppress(OSError):
        text = os.pread(fd, 32, 0).decode("ascii", "replace").strip()
        return text if text.isdigit() else ""
    return ""


#: Space kept in a run's record file (``errors.json``, ``segment.json``) from its start, per entry and in all:
#: on a full disk the final record is written over that space in place.
RECORD_BYTES_PER_ENTRY = 256
RECORD_BYTES = 32 << 10
MAX_RECORD_RESERVE = 8 << 20


def reserve_record(path: Path, data: Any, *, entries: int, root: OutputFolder | Path | None = None) -> None:
    """Write a run's record file at its start (``data``: what it says if the run never ends, e.g. every
    entry still to do), padded with spaces so that the final record can later be written over it in place
    when the disk is full (:func:`write_record`)."""
    import json

    text = json.dumps(data, indent=2, allow_nan=False) + "\n"
    pad = min(RECORD_BYTES + RECORD_BYTES_PER_ENTRY * max(entries, 0), MAX_RECORD_RESERVE)
    with atomic_write(path, "w", root=root) as handle:
        handle.write(text)
        handle.write(" " * pad + "\n")  # JSON allows trailing white space


def write_record(path: Path, data: Any, *, root: OutputFolder | Path | None = None) -> str:
    """Write a run's final record file: atomically, or, when that fails for want of space, over the
    space :func:`reserve_record` kept (long texts shortened if it must). Returns ``""``, or how it was written.

    Raises
    ------
    OutputError
        When neither way works.
    """
    import json

    try:
        write_json(path, data, root=root)
        return ""
    except OutputError as exc:
        first = exc
    text = json.dumps(data, indent=2, allow_nan=False) + "\n"
    try:
        with folder_fd(path.parent, root=root, create=False) as dfd:
            fd = os.open(path.name, os.O_WRONLY | getattr(os, "O_NOFOLLOW", 0), dir_fd=dfd)
            try:
                size = os.fstat(fd).st_size
                if len(text.encode()) > size:
                    text = json.dumps(_shorten(data), allow_nan=False) + "\n"
                raw = text.encode()
                if len(raw) > size:
                    raise first
                os.pwrite(fd, raw + b" " * (size - len(raw)), 0)  # over blocks already allocated: no new space
                os.fsync(fd)
            finally:
                os.close(fd)
    except OSError:
        raise first from None
    return "written in place over its reserved space (the disk is full)"


def _shorten(data: Any, limit: int = 120) -> Any:
    if isinstance(data, str):
        return data if len(data) <= limit else data[: limit - 3] + "..."
    if isinstance(data, dict):
        return {k: _shorten(v, limit) for k, v in data.items()}
    if isinstance(data, list):
        return [_shorten(v, limit) for v in data]
    return data
