"""Small structured files (settings, intrinsics, truth, COCO annotations): read with a size bound, parsed
safely, errors naming the file.

* At most ``max_bytes`` are ever read, whatever the file claims to be (a symlink to ``/dev/zero``, a
  device, a huge file): larger input is refused before it is parsed.
* YAML goes through a safe loader that also refuses aliases (``*name``): an alias refers to a shared node,
  and a few lines of nested aliases expand into billions of values as soon as anything walks them.
* Nesting deeper than Python's recursion allows is refused, not a traceback.
* A key repeated in one mapping (JSON object or YAML mapping) is refused naming it: parsers keep the last in
  silence, so ``translations: 3`` above ``translations: 5`` would be dropped unsaid.
* YAML 1.1's octal and base-60 numbers are refused: ``010`` would be read as 8 and ``1:30`` as 90 in silence.
* A number with an exponent is a number, as in YAML 1.2 and JSON: ``1e6`` is 1000000.0, not the text YAML 1.1
  makes of it (1.1 wants a dot and a signed exponent, ``1.0e+6``).
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import stat
import sys
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

from ..errors import FileFormatError, InputError, SymfruitError

__all__ = [
    "as_path",
    "changed",
    "file_states",
    "holds_file",
    "read_limited",
    "read_structured",
    "refuse_pipe",
    "unchanged_while",
]


def as_path(value: Any, what: str) -> Path:
    """``value`` (``str``, ``bytes`` or ``os.PathLike``) as a :class:`~pathlib.Path`; anything else (None, a
    number, an array handed to a reader) is refused naming ``what``, not a ``TypeError`` from pathlib, and so is an
    empty one, which pathlib reads as the working folder."""
    if isinstance(value, (str, bytes)) and not value:  # '' is no file; Path('') would be the folder '.'
        raise InputError(f"{what} is an empty path (an unset variable?)")
    if isinstance(value, (str, bytes, os.PathLike)):
        try:
            return Path(os.fsdecode(value))
        except TypeError:  # an os.PathLike whose __fspath__ returns neither str nor bytes
            pass
    got = "None" if value is None else type(value).__name__  # not Python's "NoneType" (robust50)
    raise InputError(f"{what} must be a path (str or os.PathLike), got {got}")


def holds_file(path: Path) -> bool:
    """Whether ``path`` is a file: False where nothing has that name. An entry of that name that is no file
    (a directory, a link whose target is missing or that links in a loop, a pipe) is refused by name, never
    read as "no such file" (a frame's ``masks.png`` folder would quietly mean no masks).

    Raises
    ------
    FileFormatError
        Naming the path and what it is.
    """
    if path.is_file():
        return True
    if not os.path.lexists(path):
        return False
    if path.is_dir():
        why = "a directory, not a file"
    elif path.is_symlink() and path.exists():  # was "its target is missing": a link to /dev/zero or a pipe
        why = f"a link to {os.path.realpath(path)}, which is not a regular file (a device, pipe or socket)"
    elif path.is_symlink():
        why = "a link that leads to no file (its target is missing, or the links loop)"
    else:
        why = "not a regular file"
    raise FileFormatError(f"{path}: {why}")


def refuse_pipe(path: Path, what: str, *, error: type[SymfruitError] = FileFormatError, devices: bool = False) -> None:
    """Refuse a pipe or a socket named as a file (opening one to read waits for a writer that may never
    come), and with ``devices`` a device too (an image is never one; ``/dev/tty`` would wait for typing);
    anything else, a missing file included, is left to the open that follows to name."""
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return
    if stat.S_ISFIFO(mode) or stat.S_ISSOCK(mode):
        raise error(f"{path}: is a pipe or a socket; the {what} must be a regular file")
    if devices and (stat.S_ISCHR(mode) or stat.S_ISBLK(mode)):
        raise error(f"{path}: is a device; the {what} must be a regular file")


#: A file's state as :func:`file_states` takes it: (device, inode, size in bytes, modification time in ns, status
#: change time in ns, (links, mode, owner, group), a digest of the content of a regular file of at most
#: :data:`DIGEST_BYTES` or None), or None where nothing of that name can be looked at.
FileState = tuple[int, int, int, int, int, tuple[int, int, int, int], bytes | None] | None

#: Files up to this size (bytes) are also compared by content (a 64-bit BLAKE2b digest, read twice: about 10 us a
#: small file): a frame's camera.json and truth.json, an intrinsics file, a COCO masks.json. A change that keeps
#: the size within one time-stamp tick (a kernel without fine-grained time stamps ticks every 1-10 ms; FAT every
#: 2 s) is seen in them. Larger files (images, depth arrays, clouds) are looked at by their status alone.
DIGEST_BYTES = 64 * 1024


def file_states(paths: Iterable[Path]) -> dict[Path, FileState]:
    """Each path's :data:`FileState` now: taken before a read, compared after it by :func:`changed`."""
    states: dict[Path, FileState] = {}
    for path in paths:
        try:
            st = os.stat(path)
        except (OSError, ValueError):
            states[path] = None
        else:
            digest = _digest(path, st) if stat.S_ISREG(st.st_mode) and st.st_size <= DIGEST_BYTES else None
            meta = (st.st_nlink, st.st_mode, st.st_uid, st.st_gid)
            states[path] = (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns, meta, digest)
    return states


def _digest(path: Path, st: os.stat_result) -> bytes | None:
    """The BLAKE2b digest (8 bytes) of a small regular file's content, None where it cannot be read (the read that
    follows says why) or is no longer the file ``st`` describes. Opened without blocking (a pipe put in its place
    meanwhile is not waited on) and read up to one byte more than :data:`DIGEST_BYTES`."""
    import hashlib

    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except (OSError, ValueError):
        return None
    try:
        now = os.fstat(fd)
        if (now.st_dev, now.st_ino) != (st.st_dev, st.st_ino) or not stat.S_ISREG(now.st_mode):
            return None
        return hashlib.blake2b(os.read(fd, DIGEST_BYTES + 1), digest_size=8).digest()
    except OSError:
        return None
    finally:
        os.close(fd)


def changed(states: dict[Path, FileState], during: str) -> str | None:
    """Why the first file whose state changed since ``states`` were taken is refused (``during``: "while the
    frame was read", ...), None where none changed. A file replaced, grown, cut or rewritten while it is read
    was read as it was at that moment, part old and part new (a frame's colour of one moment beside its depth of
    another): robust53. Two looks at each file, its status and a small file's content (:data:`DIGEST_BYTES`):
    refused when its identity, size, content or modification time changed, or its status-change time moved without
    its links, mode or owner changing (a rewrite whose modification time was set back: ``cp -p``, ``touch -r``, an
    archive unpacked over it). Not seen: a same-size change to a large file within one time-stamp tick (none on
    Linux 6.13 and later, whose time stamps are fine-grained once looked at), and a change undone before the
    second look (flake54)."""
    for path, before in states.items():
        (after,) = file_states([path]).values()
        if after == before:
            continue
        if before is None:
            how = "it appeared"
        elif after is None:
            how = "it was removed"
        elif after[:2] != before[:2]:
            how = "it was replaced by another file"
        elif after[2] != before[2]:
            how = f"its size went from {before[2]:,} to {after[2]:,} bytes"
        elif before[6] is not None and after[6] is not None and after[6] != before[6]:
            how = "it was rewritten: its content changed"
        elif after[3] != before[3]:
            how = "it was rewritten: its modification time changed"
        elif after[4] != before[4] and after[5] == before[5]:
            how = "it was rewritten: its modification time was set back"
        else:
            continue  # only its links, mode or owner changed (a chmod, a hard link made to it)
        return f"{path}: changed {during} ({how}); it is being written or replaced: read it again once it is whole"
    return None


@contextlib.contextmanager
def unchanged_while(
    paths: Iterable[Path] | dict[Path, FileState], during: str, *, error: type[SymfruitError] = FileFormatError
) -> Iterator[None]:
    """Look at ``paths`` before and after the block (or compare with ``paths``' states taken earlier, a
    :func:`file_states` dict: a bag's at its opening): one changed in between is refused (:func:`changed`),
    also where the block failed for it (a file cut while read: the change is the reason, not the parser's)."""
    states = paths if isinstance(paths, dict) else file_states(paths)
    try:
        yield
    except SymfruitError:
        why = changed(states, during)
        if why is None:
            raise
        raise error(why) from None
    why = changed(states, during)
    if why is not None:
        raise error(why)


def read_limited(path: Path, *, what: str, max_bytes: int, error: type[SymfruitError] = FileFormatError) -> bytes:
    """The bytes of ``path``, refusing anything over ``max_bytes`` (read is bounded, not trusted to stat), and a
    pipe or socket (opening one waits for a writer that may never come)."""
    refuse_pipe(path, what, error=error)
    try:
        with open(path, "rb") as handle:
            data = handle.read(max_bytes + 1)
    except FileNotFoundError:
        raise error(f"{path}: no such {what}") from None
    except IsADirectoryError:
        raise error(f"{path}: is a folder, not {_a(what)}") from None
    except OSError as exc:
        raise error(f"{path}: cannot read {what} ({exc.strerror or exc})") from None
    if len(data) > max_bytes:
        raise error(f"{path}: {what} is larger than {max_bytes // 1024} kB; this cannot be {_a(what)}")
    return data


def _yaml_loader() -> type:
    import yaml

    class _NoAliasLoader(yaml.SafeLoader):
        def compose_node(self, parent: Any, index: Any) -> Any:
            if self.check_event(yaml.AliasEvent):
                event = self.peek_event()
                raise yaml.composer.ComposerError(
                    None, None, f"YAML aliases (*{event.anchor}) are not allowed here", event.start_mark
                )
            return super().compose_node(parent, index)

        def construct_mapping(self, node: Any, deep: bool = False) -> Any:
            seen: set[Any] = set()
            for key_node, _ in node.value:
                key = self.construct_object(key_node, deep=deep)
                try:
                    duplicate = key in seen
                except TypeError:  # an unhashable key: the SafeLoader says so
                    continue
                if duplicate:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"duplicate key {key!r} (which one is meant?)", key_node.start_mark
                    )
                seen.add(key)
            return super().construct_mapping(node, deep=deep)

    def decimal_only(kind: str) -> Any:
        """YAML 1.1's number of ``kind`` (int or float), refusing its forms a reader takes for another number:
        a leading 0 is octal (``010`` is 8) and colons are base 60 (``1:30`` is 90); hexadecimal and binary
        (``0x``, ``0b``) say what they are and are read."""
        base = getattr(yaml.SafeLoader, f"construct_yaml_{kind}")

        def construct(loader: Any, node: Any) -> Any:
            text = str(loader.construct_scalar(node))
            body = text.replace("_", "").lstrip("+-")
            octal = kind == "int" and len(body) > 1 and body[0] == "0" and body[1].isdigit()
            if ":" in body or octal:
                read = base(loader, node)
                form = "octal (a leading 0)" if octal else "base 60 (colons)"
                raise yaml.constructor.ConstructorError(
                    None, None, f"{text} is a YAML 1.1 {form} number, read as {read!r}: write the number in decimal "
                    "(or quote text)", node.start_mark,
                )  # fmt: skip
            return base(loader, node)

        return construct

    _NoAliasLoader.add_constructor("tag:yaml.org,2002:int", decimal_only("int"))
    _NoAliasLoader.add_constructor("tag:yaml.org,2002:float", decimal_only("float"))
    # YAML 1.2's (and JSON's) exponent forms YAML 1.1 reads as text: 1e6, 2.5E-3, .5e3, 1.0e6 (no dot or no sign)
    _NoAliasLoader.add_implicit_resolver("tag:yaml.org,2002:float", _EXPONENT, list("-+0123456789."))
    return _NoAliasLoader


#: A decimal number with an exponent in YAML 1.2's core schema that YAML 1.1 does not read as a number.
_EXPONENT = re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9][0-9_]*)[eE][-+]?[0-9]+$")


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """A JSON object, refused where a key repeats (the last would win in silence)."""
    out = dict(pairs)
    if len(out) != len(pairs):
        seen: set[str] = set()
        for key, _ in pairs:
            if key in seen:
                raise ValueError(f"duplicate key {key!r} (which one is meant?)")
            seen.add(key)
    return out


def read_structured(
    path: str | Path, *, what: str, max_bytes: int, error: type[SymfruitError] = FileFormatError
) -> Any:
    """Parse a ``.json`` or ``.yaml``/``.yml`` file (by extension) into Python data.

    Raises
    ------
    error
        Naming the file: unreadable, too large, not UTF-8, not valid JSON/YAML, aliases, nesting too deep, a
        key repeated in one mapping.
    """
    path = Path(path)
    raw = read_limited(path, what=what, max_bytes=max_bytes, error=error)
    try:
        text = raw.decode("utf-8-sig")  # a UTF-8 byte-order mark is allowed and dropped
    except UnicodeDecodeError as exc:
        raise error(f"{path}: {what} is not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    suffix = path.suffix.lower()
    kind = "JSON" if suffix == ".json" else "YAML"
    if not text.strip():  # JSON: "Expecting value: line 1 column 1"; YAML: None, "got NoneType" further on
        raise error(f"{path}: the {what} is empty")
    try:
        if kind == "JSON":
            return json.loads(text, object_pairs_hook=_unique_keys)
        loader = _yaml_loader()(text)  # a SafeLoader that also refuses aliases
        try:
            return loader.get_single_data()
        finally:
            loader.dispose()
    except RecursionError:
        raise error(f"{path}: {what} is nested too deeply to be {_a(what)}") from None
    except ValueError as exc:
        digits = _DIGITS.search(str(exc))
        if digits is None:  # json.JSONDecodeError is a ValueError: its position, below
            raise error(f"{path}: not valid {kind}: {_parse_reason(exc)}") from None
        raise error(f"{path}: not valid {kind}: a number of {int(digits.group(1)):,} digits (at most "
                    f"{sys.get_int_max_str_digits():,} are read)") from None  # fmt: skip
    except Exception as exc:  # json.JSONDecodeError / yaml.YAMLError carry the position
        raise error(f"{path}: not valid {kind}: {_parse_reason(exc)}") from None


#: Python's refusal of a whole number of more digits than ``sys.get_int_max_str_digits()`` (4,300): its words
#: tell the user to call ``sys.set_int_max_str_digits()`` (stop 49, robust49).
_DIGITS = re.compile(r"Exceeds the limit \(\d+ digits\) for integer string conversion: value has (\d+) digits")


def _a(what: str) -> str:
    """``what`` with its article: an intrinsics file, a settings file."""
    return f"{'an' if what[:1] in 'aeiou' else 'a'} {what}"


#: Longest parser reason quoted in a refusal.
PARSE_REASON_CHARS = 160


def _parse_reason(exc: BaseException) -> str:
    """One short line saying why a JSON or YAML parser refused a file: a YAML error's problem, context and
    position (PyYAML's own message quotes the line and a caret under it over several lines: 300-400 characters
    for a quote left open), anything else its first line, cut to :data:`PARSE_REASON_CHARS` characters."""
    problem = getattr(exc, "problem", None)
    mark = getattr(exc, "problem_mark", None)
    if isinstance(problem, str) and mark is not None:  # yaml.MarkedYAMLError
        context = getattr(exc, "context", None)
        text = f"{context}: {problem}" if isinstance(context, str) and context else problem
        text = f"{text} (at line {mark.line + 1}, column {mark.column + 1})"
    else:
        lines = str(exc).strip().splitlines()
        text = lines[0].strip() if lines else type(exc).__name__
    return text if len(text) <= PARSE_REASON_CHARS else f"{text[:PARSE_REASON_CHARS]}..."
