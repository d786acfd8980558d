"""Point-cloud files: PLY, PCD (ascii, binary, binary_compressed), XYZ/TXT/CSV and NPY.

Each reader returns an ``(n, 3)`` float64 array of x, y, z and raises
:class:`~symfruit.errors.FileFormatError` naming the file and the problem. Sizes read from headers are
checked against the file's length before anything is allocated.
"""

from __future__ import annotations

import io
import os
import re
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ..core.limits import MAX_CLOUD_POINTS, MAX_TEXT_CLOUD_BYTES, shown
from ..errors import FileFormatError, InputError
from .atomic import atomic_write
from .text import as_path, refuse_pipe, unchanged_while

__all__ = ["CLOUD_READERS", "npy_header", "read_cloud", "read_npy", "read_pcd", "read_ply", "read_text", "write_ply"]

#: Largest header we read before giving up on finding its end.
_MAX_HEADER = 1 << 16
#: Most points any cloud file may hold (a 1280x720 depth frame is 0.9 million; more is refused before it is
#: allocated), and the largest text cloud read (bytes): :mod:`symfruit.core.limits`.
MAX_TEXT_BYTES = MAX_TEXT_CLOUD_BYTES


def read_cloud(path: str | Path) -> np.ndarray:
    """Read x, y, z from a cloud file, choosing the reader by extension (:data:`CLOUD_READERS`).

    Returns
    -------
    (n, 3) float64
    """
    path = as_path(path, "read_cloud: the cloud file")
    reader = CLOUD_READERS.get(path.suffix.lower())
    if reader is None:
        known = ", ".join(sorted(CLOUD_READERS))
        raise FileFormatError(f"{path}: unknown cloud extension {path.suffix!r}; use one of {known}")
    if not path.exists():
        if os.path.lexists(path):  # the link is there: it was 'no such file', as if nothing had that name
            raise FileFormatError(f"{path}: a link that leads to no file (its target is missing, or the links loop)")
        raise FileFormatError(f"{path}: no such file")
    if not path.is_file():
        raise FileFormatError(
            f"{path}: not a regular file ({'a folder' if path.is_dir() else 'a pipe, socket or device'})"
        )
    with unchanged_while([path], "while it was read"):
        points = _read_points(path, reader)
    if points.ndim != 2 or points.shape[1] != 3:
        raise FileFormatError(f"{path}: expected x, y, z columns, got an array of shape {points.shape}")
    with np.errstate(invalid="ignore", over="ignore"):
        return np.ascontiguousarray(points, dtype=np.float64)


def _read_points(path: Path, reader: Any) -> np.ndarray:
    """``reader(path)``, its failures in one line naming the file."""
    try:
        with np.errstate(invalid="ignore", over="ignore"):  # a signalling NaN or a huge float64 stored as float32:
            points = reader(path)  # non-finite points, dropped with the rest (never a warning from the cast)
    except FileFormatError:
        raise
    except UnicodeDecodeError as exc:  # a text cloud of bytes that are no text (stop 48, robust48: the codec's words,
        # "'utf-8' codec can't decode byte 0x89 in position 0: invalid start byte", for a PNG named .xyz)
        raise FileFormatError(f"{path}: cannot read as {path.suffix.lstrip('.').upper()} (not UTF-8 text: "
                              f"{exc.reason} at byte {exc.start})") from None  # fmt: skip
    except (ValueError, OSError, EOFError, IndexError, KeyError) as exc:
        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc  # not "[Errno 13] ...: 'PATH'"
        raise FileFormatError(f"{path}: cannot read as {path.suffix.lstrip('.').upper()} ({why})") from None
    return points


def _header(path: Path, kind: str, magic: bytes, end: re.Pattern[bytes]) -> tuple[bytes, int, int]:
    """Header bytes, offset of the data after it, and the file size."""
    size = path.stat().st_size
    with path.open("rb") as handle:
        head = handle.read(_MAX_HEADER)
    if not head.startswith(magic):
        raise FileFormatError(f"{path}: not a {kind} file (it does not start with {magic!r})")
    match = end.search(head)
    if match is None:
        raise FileFormatError(
            f"{path}: {kind} header has no end within its first {_MAX_HEADER} bytes "
            "(truncated or not a {kind} file)".replace("{kind}", kind)
        )
    return head[: match.end()], match.end(), size


#: numpy codes of the PLY scalar types, by every name plyfile takes: PLY's own, the sized ones and numpy's codes
#: (``u1``, ``f4``, ... which plyfile writes and reads too: counted 4 bytes each they made a whole file look cut short)
_PLY_CODES = {
    "char": "i1", "int8": "i1", "i1": "i1", "uchar": "u1", "uint8": "u1", "u1": "u1", "b1": "u1",
    "short": "i2", "int16": "i2", "i2": "i2", "ushort": "u2", "uint16": "u2", "u2": "u2",
    "int": "i4", "int32": "i4", "i4": "i4", "uint": "u4", "uint32": "u4", "u4": "u4",
    "float": "f4", "float32": "f4", "f4": "f4", "double": "f8", "float64": "f8", "f8": "f8",
}  # fmt: skip


def ply_elements(path: Path) -> tuple[str, list[tuple[str, int]]]:
    """``(format, [(element name, count), ...])`` of a PLY header, checked against the file's size.

    Every element's rows need a least number of bytes (binary: the scalar properties' sizes plus each
    list's count field; ascii: two characters per property), so a header promising more rows than the file
    can hold is refused before :mod:`plyfile` allocates them, whichever element it is.
    """
    header, start, size = _header(path, "PLY", b"ply", re.compile(rb"end_header\r?\n"))
    text = header.decode("ascii", errors="replace")
    fmt = re.search(r"^format\s+(\S+)", text, re.M)
    if fmt is None:
        raise FileFormatError(f"{path}: PLY header lacks a format line")
    elements: list[tuple[str, int]] = []
    least = 0
    for block in re.split(r"^element\s+", text, flags=re.M)[1:]:
        head = block.split(None, 2)
        if len(head) < 2 or not head[1].isdigit():
            raise FileFormatError(f"{path}: PLY element line is not 'element NAME COUNT'")
        name, count = head[0], int(head[1])
        props = re.findall(r"^property\s+(list\s+\S+\s+\S+|\S+)\s+(\S+)", block, re.M)
        types = [kind.split()[1:] if kind.split()[0] == "list" else [kind] for kind, _ in props]
        for (_, prop), kinds in zip(props, types, strict=True):  # plyfile's refusal listed its 25 type names
            if unknown := next((t for t in kinds if t not in _PLY_CODES), None):
                raise FileFormatError(f"{path}: PLY property {shown(prop)} of element {shown(name)} is of type "
                                      f"{shown(unknown)}, which is no PLY type (char, uchar, short, ushort, int, "
                                      "uint, float, double; int8 ... float64)")  # fmt: skip
        if fmt.group(1) == "ascii":
            row = 2 * max(len(props), 1)
        else:  # a scalar's size, a list's count field's
            row = sum(int(_PLY_CODES[kinds[0]][1]) for kinds in types if kinds) or 1
        least += count * row
        elements.append((name, count))
    if least > size - start:
        raise FileFormatError(
            f"{path}: header promises {', '.join(_rows(n, c) for n, c in elements)} (at least {least} bytes) but "
            f"the file holds {size - start} bytes of data (truncated or corrupt)"
        )
    return fmt.group(1), elements


def _rows(name: str, count: int) -> str:
    return f"{count} vertices" if name == "vertex" else f"{count} {name} rows"


def read_ply(path: Path) -> np.ndarray:
    """PLY (ascii or binary) through ``plyfile``; every element's row count is checked against the file first."""
    _, elements = ply_elements(path)
    counts = dict(elements)
    if "vertex" not in counts:
        raise FileFormatError(f"{path}: PLY has no vertex element")
    if counts["vertex"] > MAX_CLOUD_POINTS:
        raise FileFormatError(f"{path}: PLY holds {counts['vertex']:,} vertices; at most {MAX_CLOUD_POINTS:,} are read")
    return ply_vertices(path)[1]


def ply_vertices(path: Path) -> tuple[Any, np.ndarray]:
    """``(PlyData, vertices (n, 3) float64)`` of a PLY file whose element counts were checked against its size
    (:func:`ply_elements`); a vertex element without ``x``, ``y`` and ``z`` is refused naming what it lacks and what
    it has."""
    from plyfile import PlyData, PlyListProperty, PlyParseError

    _check_ply_byte_order(path)
    try:
        with path.open("rb") as handle:
            data = PlyData.read(handle)
            end = None if data.text else handle.tell()
        element = data["vertex"]
    except PlyParseError as exc:
        raise FileFormatError(f"{path}: corrupt PLY ({exc})") from None
    except (KeyError, ValueError) as exc:
        raise FileFormatError(f"{path}: unreadable PLY ({exc})") from None
    _check_ply_rest(path, data, end)
    names = [p.name for p in element.properties]
    missing = [c for c in ("x", "y", "z") if c not in names]
    if missing:
        raise FileFormatError(
            f"{path}: PLY vertices lack the {', '.join(missing)} propert"
            f"{'y' if len(missing) == 1 else 'ies'} (they have {', '.join(names) or 'none'})"
        )
    if lists := [p.name for p in element.properties if p.name in ("x", "y", "z") and isinstance(p, PlyListProperty)]:
        one = len(lists) == 1  # numpy's words were "setting an array element with a sequence."
        raise FileFormatError(f"{path}: PLY vertex {'property' if one else 'properties'} {', '.join(lists)} "
                              f"{'is a list' if one else 'are lists'}; x, y and z are one number a vertex")  # fmt: skip
    try:
        with np.errstate(invalid="ignore", over="ignore"):  # a signalling NaN cast: a missing point, no warning
            return data, np.column_stack([np.asarray(element[c], dtype=np.float64) for c in ("x", "y", "z")])
    except PlyParseError as exc:
        raise FileFormatError(f"{path}: corrupt PLY ({exc})") from None
    except (KeyError, ValueError) as exc:
        raise FileFormatError(f"{path}: unreadable PLY vertices ({exc})") from None


#: Vertices a binary PLY's byte order is judged on (the first rows).
_BYTE_ORDER_ROWS = 1000


def _plausible(values: np.ndarray) -> float:
    """Share of coordinates that look like a measurement in any unit: 0, or finite with magnitude 1e-6 to 1e6
    (bytes read in the wrong order give exponents all over the range: ~13 % of float32 fall there by chance)."""
    with np.errstate(invalid="ignore", over="ignore"):
        a = np.abs(values.astype(np.float64))
        ok = (a == 0) | ((a >= 1e-6) & (a <= 1e6))
    return float(ok.mean()) if len(a) else 1.0


def _check_ply_byte_order(path: Path) -> None:
    """Refuse a binary PLY whose header names the other byte order than its data's (a ``binary_big_endian``
    header written over little-endian floats, or the reverse): read as declared, the first vertices' float x, y, z
    are mostly no coordinates (1e25, 1e-39, NaN), read swapped they are. Judged only where it can be told: the
    vertex element first, of fixed-size properties, with float or double x, y, z."""
    header, start, size = _header(path, "PLY", b"ply", re.compile(rb"end_header\r?\n"))
    text = header.decode("ascii", errors="replace")
    fmt = re.search(r"^format\s+(\S+)", text, re.M)
    orders = {"binary_little_endian": "<", "binary_big_endian": ">"}
    if fmt is None or fmt.group(1) not in orders:
        return
    blocks = re.split(r"^element\s+", text, flags=re.M)[1:]
    head = blocks[0].split(None, 2) if blocks else []
    if len(head) < 2 or head[0] != "vertex" or not head[1].isdigit():
        return
    props = re.findall(r"^property\s+(\S+)\s+(\S+)", blocks[0], re.M)
    if not props or any(kind not in _PLY_CODES for kind, _ in props):  # a list property: rows of varying size
        return
    coords = [name for kind, name in props if name in ("x", "y", "z") and _PLY_CODES[kind].startswith("f")]
    if len(coords) != 3 or len({name for _, name in props}) != len(props):
        return
    declared = orders[fmt.group(1)]
    other = "<" if declared == ">" else ">"
    fields = [(name, _PLY_CODES[kind]) for kind, name in props]
    row = np.dtype([(name, declared + code) for name, code in fields])
    n = min(int(head[1]), _BYTE_ORDER_ROWS, (size - start) // row.itemsize)
    if n <= 0:
        return
    with path.open("rb") as handle:
        handle.seek(start)
        raw = handle.read(n * row.itemsize)
    as_declared = np.frombuffer(raw, row, count=n)
    swapped = np.frombuffer(raw, np.dtype([(name, other + code) for name, code in fields]), count=n)
    ours = _plausible(np.concatenate([as_declared[c] for c in coords]))
    theirs = _plausible(np.concatenate([swapped[c] for c in coords]))
    if ours < 0.5 and theirs > 0.9:
        named = {v: k for k, v in orders.items()}
        example = ", ".join(f"{float(as_declared[c][0]):.3g}" for c in coords)
        raise FileFormatError(
            f"{path}: the header says {fmt.group(1)} but the data look {named[other]}: read as declared, "
            f"{1 - ours:.0%} of the first {n} vertices' coordinates are implausible (the first: {example}), read "
            f"in the other byte order {theirs:.0%} are plausible; write 'format {named[other]} 1.0' in the header"
        )


def _check_ply_rest(path: Path, data: Any, end: int | None) -> None:
    """Refuse data left after the header's last element: a vertex count smaller than the rows written (a file
    appended to, or a header edited by hand) read the first rows in silence. Trailing whitespace or NUL padding
    is allowed; in ASCII every row is one line, so the lines after the header are counted."""
    counts = ", ".join(_rows(e.name, e.count) for e in data.elements)
    if end is not None:  # binary: plyfile stops right after the last element
        with path.open("rb") as handle:
            handle.seek(end)
            rest = handle.read(1 << 16)
            extra = path.stat().st_size - end
        if rest.strip(b" \t\r\n\0"):
            raise FileFormatError(
                f"{path}: {extra} bytes of data after the header's {counts} (the header's counts disagree with the "
                "data: truncated header count or a file appended to)"
            )
        return
    _, start, _ = _header(path, "PLY", b"ply", re.compile(rb"end_header\r?\n"))
    lines = 0
    with path.open("rb") as handle:
        handle.seek(start)
        for line in handle:
            lines += bool(line.strip())
    rows = sum(e.count for e in data.elements)
    if lines > rows:
        raise FileFormatError(
            f"{path}: {lines} data lines after the header but it declares {counts} ({rows} rows): the header's "
            "counts disagree with the data"
        )


_PCD_TYPES = {("F", 4): "f4", ("F", 8): "f8", ("I", 1): "i1", ("I", 2): "i2", ("I", 4): "i4",
              ("I", 8): "i8", ("U", 1): "u1", ("U", 2): "u2", ("U", 4): "u4", ("U", 8): "u8"}  # fmt: skip


def read_pcd(path: Path) -> np.ndarray:
    """PCD v0.7 (``DATA ascii``, ``binary`` or ``binary_compressed``), fields x, y, z."""
    header, start, size = _header(path, "PCD", b"", re.compile(rb"^DATA[^\n]*\n", re.M))
    fields: dict[str, list[str]] = {}
    for line in header.decode("ascii", errors="replace").splitlines():
        parts = line.split()
        if parts and not parts[0].startswith("#"):
            if parts[0].upper() in fields:  # the last would win in silence: which one is meant?
                raise FileFormatError(f"{path}: PCD header has two {parts[0].upper()} lines")
            fields[parts[0].upper()] = parts[1:]
    try:
        names = fields["FIELDS"]
        sizes = [int(s) for s in fields["SIZE"]]
        types = fields["TYPE"]
        counts = [int(c) for c in fields.get("COUNT", ["1"] * len(names))]
        if "POINTS" not in fields:  # the shape's product, of counts that are no counts below 0
            fields["POINTS"] = [str(int(fields["WIDTH"][0]) * int(fields["HEIGHT"][0]))]
        n = int(fields["POINTS"][0])
        mode = fields["DATA"][0].lower()
    except (KeyError, ValueError, IndexError):
        raise FileFormatError(f"{path}: PCD header lacks or garbles FIELDS/SIZE/TYPE/POINTS/DATA") from None
    if not (len(names) == len(sizes) == len(types) == len(counts)) or n < 0 or min(counts, default=1) < 1:
        raise FileFormatError(f"{path}: PCD header's FIELDS, SIZE, TYPE and COUNT disagree")
    if "POINTS" in fields and "WIDTH" in fields and "HEIGHT" in fields:
        try:
            width, height = int(fields["WIDTH"][0]), int(fields["HEIGHT"][0])
        except (ValueError, IndexError):
            raise FileFormatError(f"{path}: PCD header garbles WIDTH/HEIGHT") from None
        if width < 0 or height < 0:  # -2 x -1 is 2, but no cloud's shape
            raise FileFormatError(f"{path}: PCD header garbles WIDTH/HEIGHT ({width} x {height}; counts are >= 0)")
        if width * height != n:
            raise FileFormatError(
                f"{path}: PCD header's POINTS {n} disagrees with WIDTH x HEIGHT {width} x {height} = {width * height}"
            )
    if n > MAX_CLOUD_POINTS:
        raise FileFormatError(f"{path}: PCD holds {n:,} points; at most {MAX_CLOUD_POINTS:,} are read")
    twice = [c for c in ("x", "y", "z") if names.count(c) > 1]  # PCL's padding fields '_' may repeat
    if twice:
        raise FileFormatError(f"{path}: PCD header names field {twice[0]!r} {names.count(twice[0])} times "
                              f"(fields: {' '.join(names)}); which one is meant?")  # fmt: skip
    missing = [c for c in ("x", "y", "z") if c not in names]
    if missing:
        raise FileFormatError(f"{path}: PCD has no field {missing[0]!r} (fields: {' '.join(names)})")
    try:
        dtypes = [np.dtype(_PCD_TYPES[(t.upper(), s)]) for t, s in zip(types, sizes, strict=True)]
    except KeyError:
        raise FileFormatError(f"{path}: PCD has an unsupported TYPE/SIZE pair") from None
    row = sum(s * c for s, c in zip(sizes, counts, strict=True))
    body_size = size - start
    with path.open("rb") as handle:
        handle.seek(start)
        if mode == "ascii":
            if n * 2 * len(names) > body_size + 1:
                raise FileFormatError(f"{path}: header promises {n} points but the file is too short")
            text = io.TextIOWrapper(handle, encoding="ascii", errors="replace")
            try:
                values = np.loadtxt(text, ndmin=2, dtype=np.float64, max_rows=n)
            except ValueError as exc:  # numpy's own words on a ragged or wordy row, without its API advice
                why = str(exc).split("; use `usecols`")[0].replace("\n", " ")
                raise FileFormatError(
                    f"{path}: ascii PCD rows are not all {int(sum(counts))} numbers ({why})"
                ) from None
            if len(values) < n:
                raise FileFormatError(f"{path}: header promises {n} points, the file holds {len(values)}")
            if any(line.strip() for line in text):
                raise FileFormatError(
                    f"{path}: header promises {n} points but more rows follow them (the header's POINTS disagrees "
                    "with the data)"
                )
            columns = np.cumsum([0, *counts])
            return np.column_stack([values[:n, columns[names.index(c)]] for c in ("x", "y", "z")])
        if mode == "binary":
            if n * row > body_size:
                raise FileFormatError(
                    f"{path}: header promises {n} points ({n * row} bytes) but the file holds {body_size}"
                )
            if body_size - n * row >= max(row, 1):
                raise FileFormatError(
                    f"{path}: header promises {n} points ({n * row} bytes) but the file holds {body_size}: "
                    f"{(body_size - n * row) // max(row, 1)} more whole points (the header's POINTS disagrees with "
                    "the data)"
                )
            dtype = np.dtype([(f"f{i}", d, (c,)) for i, (d, c) in enumerate(zip(dtypes, counts, strict=True))])
            rec = np.frombuffer(handle.read(n * row), dtype=dtype, count=n)
            return np.column_stack([rec[f"f{names.index(c)}"][:, 0].astype(np.float64) for c in ("x", "y", "z")])
        if mode == "binary_compressed":
            raw = handle.read(8)
            if len(raw) < 8:
                raise FileFormatError(f"{path}: truncated binary_compressed PCD (no size words)")
            packed, unpacked = (int(v) for v in np.frombuffer(raw, dtype="<u4"))
            # LZF expands at most ~132-fold (a 3-byte back reference copies up to 264 bytes).
            if unpacked != n * row or packed > body_size - 8 or unpacked > 132 * packed + 64:
                raise FileFormatError(f"{path}: binary_compressed sizes do not match the header or the file")
            data = _lzf_decompress(handle.read(packed), unpacked, path)
            out, offset = [], 0
            for d, c in zip(dtypes, counts, strict=True):  # column-major: field after field
                out.append(np.frombuffer(data, dtype=d, count=n * c, offset=offset).reshape(n, c))
                offset += n * c * d.itemsize
            return np.column_stack([out[names.index(c)][:, 0].astype(np.float64) for c in ("x", "y", "z")])
    raise FileFormatError(f"{path}: unknown PCD DATA mode {mode!r} (ascii, binary, binary_compressed)")


def _lzf_decompress(data: bytes, size: int, path: Path) -> bytes:
    """Decompress LZF (as PCL writes ``binary_compressed``); ``size`` is bounded by the caller.

    Our own decoder (the format is 30 lines; PyPI's python-lzf ships no wheels, only a C source to build):
    literal runs and non-overlapping back references are slice copies, so it runs at tens of MB/s.
    """
    out = bytearray(size)
    i = o = 0
    n = len(data)
    try:
        while i < n:
            ctrl = data[i]
            i += 1
            if ctrl < 32:  # literal run of ctrl + 1 bytes
                length = ctrl + 1
                out[o : o + length] = data[i : i + length]
                if i + length > n or o + length > size:
                    raise IndexError
                i += length
                o += length
            else:  # back reference
                length = ctrl >> 5
                ref = o - ((ctrl & 0x1F) << 8) - 1
                if length == 7:
                    length += data[i]
                    i += 1
                ref -= data[i]
                i += 1
                length += 2
                if ref < 0 or o + length > size:
                    raise IndexError
                if ref + length <= o:  # no overlap: one slice copy
                    out[o : o + length] = out[ref : ref + length]
                else:  # overlapping (a repeated run): byte by byte
                    for k in range(length):
                        out[o + k] = out[ref + k]
                o += length
    except IndexError:
        raise FileFormatError(f"{path}: corrupt LZF data in binary_compressed PCD") from None
    if o != size:
        raise FileFormatError(f"{path}: binary_compressed PCD decompressed to {o} bytes, expected {size}")
    return bytes(out)


def read_text(path: Path) -> np.ndarray:
    """Text columns x y z [...]: one separator per file, read from its first data row.

    ``;`` separates columns in European CSV, whose numbers may then use a decimal comma (``0,31;0,02;...``);
    otherwise ``,``, tabs or spaces separate. Lines starting with ``#``, ``//`` or ``%`` are comments;
    non-numeric lines before the data (a header) are skipped; a UTF-8 byte-order mark is dropped. At most
    :data:`MAX_TEXT_BYTES` are read and :data:`MAX_CLOUD_POINTS` rows parsed.
    """
    from .text import read_limited

    raw = read_limited(path, what="text cloud", max_bytes=MAX_TEXT_BYTES)
    text = raw.decode("utf-8-sig")
    lines = text.splitlines()
    first, sep = None, None
    for number, line in enumerate(lines):
        line = line.strip()
        if not line or line.startswith(_COMMENTS):
            continue
        sep = ";" if ";" in line else "," if "," in line else None
        parts = _split(line, sep)
        try:
            [float(p) for p in parts[:3]]
        except ValueError:
            continue  # a header line before the data
        if len(parts) < 3:
            raise FileFormatError(f"{path}: line {number + 1} has {len(parts)} columns, need x y z")
        first = number
        break
    if first is None:
        raise FileFormatError(f"{path}: no numeric x y z rows found")
    # blank and comment lines out: numpy warns of each under max_rows (a last empty line, a comment between rows),
    # and that warning, an error here, refused the file with numpy's note on its 1.23 release
    body = "\n".join(line for line in lines[first:] if line.strip() and not line.strip().startswith(_COMMENTS))
    if sep == ";":
        body = body.replace(",", ".")  # decimal commas
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # an empty or ragged body must be an error, not a warning
            values = np.loadtxt(io.StringIO(body), delimiter=sep, comments=list(_COMMENTS), usecols=(0, 1, 2),
                                ndmin=2, max_rows=MAX_CLOUD_POINTS + 1, dtype=np.float64)  # fmt: skip
    except (ValueError, UserWarning) as exc:
        message = str(exc).replace("\n", " ")
        raise FileFormatError(f"{path}: rows after line {first + 1} are not all x y z numbers ({message})") from None
    if len(values) > MAX_CLOUD_POINTS:
        raise FileFormatError(f"{path}: more than {MAX_CLOUD_POINTS:,} rows; at most that many points are read")
    return values


_COMMENTS = ("#", "//", "%")


def _split(line: str, sep: str | None) -> list[str]:
    parts = [p.strip() for p in (line.split(sep) if sep else line.split())]
    if sep == ";":
        parts = [p.replace(",", ".") for p in parts]
    return [p for p in parts if p] if sep is None else parts


def npy_header(path: Path) -> tuple[tuple[int, ...], np.dtype]:
    """``(shape, dtype)`` from a ``.npy`` header, without reading the data; checks that the file holds it.

    Raises
    ------
    FileFormatError
        For a file that is not ``.npy`` (an ``.npz`` archive is named as such), a header numpy cannot
        parse, an object (pickled) dtype, or data shorter than the header promises.
    """
    refuse_pipe(path, ".npy array")
    try:
        with open(path, "rb") as handle:
            magic = handle.read(6)
            if magic.startswith(b"PK"):
                raise FileFormatError(f"{path}: is an .npz archive (zip), not a single .npy array")
            if magic != b"\x93NUMPY":
                raise FileFormatError(f"{path}: not a .npy file (no NumPy magic)")
            handle.seek(0)
            version = np.lib.format.read_magic(handle)
            if version == (1, 0):
                shape, _, dtype = np.lib.format.read_array_header_1_0(handle)
            else:
                shape, _, dtype = np.lib.format.read_array_header_2_0(handle)
            start = handle.tell()
        size = path.stat().st_size
    except FileFormatError:
        raise
    except Exception as exc:  # numpy parses the header with ast/tokenize: SyntaxError, TokenError, ...
        raise FileFormatError(f"{path}: not a valid .npy file ({_npy_reason(exc)})") from None
    if dtype.hasobject:
        raise FileFormatError(f"{path}: .npy holds Python objects; symfruit never unpickles files")
    need = int(np.prod(shape, dtype=np.float64) * dtype.itemsize)
    if need > size - start:
        raise FileFormatError(f"{path}: .npy header promises {shape} {dtype} ({need} bytes) but the file holds "
                              f"{size - start} bytes of data")  # fmt: skip
    return tuple(int(v) for v in shape), dtype


def _npy_reason(exc: BaseException) -> str:
    """Why numpy could not read a ``.npy`` header, in a few words: a header cut short says so (numpy: ``EOF: reading
    array header, expected 49912 bytes got 498``), anything else is numpy's first line, cut to 120 characters."""
    if isinstance(exc, OSError) and exc.strerror:  # the file cannot be opened: "Permission denied", not its path again
        return f"cannot read it: {exc.strerror}"
    text = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
    cut = re.match(r"EOF: reading (.+?), expected (\d+) bytes got (\d+)", text)
    if cut:
        return (f"its {cut.group(1)} claims {int(cut.group(2)):,} bytes but only {int(cut.group(3)):,} follow: cut "
                "short or damaged")  # fmt: skip
    return f"its header cannot be parsed: {text[:120]}"


def read_npy(path: Path) -> np.ndarray:
    """NumPy ``.npy``: an (n, >=3) numeric array or a structured array with x, y, z; never pickles."""
    shape, _ = npy_header(path)
    if shape and shape[0] > MAX_CLOUD_POINTS:
        raise FileFormatError(f"{path}: .npy holds {shape[0]:,} rows; at most {MAX_CLOUD_POINTS:,} points are read")
    try:
        arr = np.load(path, allow_pickle=False, mmap_mode="r")
    except Exception as exc:  # numpy parses the header with ast/tokenize: SyntaxError, TokenError, ...
        raise FileFormatError(f"{path}: not a valid .npy file ({_npy_reason(exc)})") from None
    if arr.dtype.names:
        missing = [c for c in ("x", "y", "z") if c not in arr.dtype.names]
        if missing:
            raise FileFormatError(f"{path}: structured array lacks field {missing[0]!r}")
        for c in ("x", "y", "z"):  # numbers only: a bool, a time or text would be read as metres by the cast
            if arr.dtype[c].kind not in "iuf":
                raise FileFormatError(f"{path}: structured array field {c!r} is {arr.dtype[c]}, not a number")
        return np.column_stack([np.asarray(arr[c], dtype=np.float64) for c in ("x", "y", "z")])
    # numpy counts timedelta64 among its integers: a time is no coordinate (read as a count of its units)
    if arr.ndim != 2 or arr.shape[1] < 3 or arr.dtype.kind not in "iufc":
        raise FileFormatError(f"{path}: expected a numeric (n, 3) array, got {arr.dtype} {arr.shape}")
    if np.iscomplexobj(arr):
        raise FileFormatError(f"{path}: complex numbers cannot be coordinates")
    return np.asarray(arr[:, :3], dtype=np.float64)


#: Cloud readers by lower-case extension; add an entry to support another format.
CLOUD_READERS: dict[str, Callable[[Path], np.ndarray]] = {
    ".ply": read_ply,
    ".pcd": read_pcd,
    ".xyz": read_text,
    ".txt": read_text,
    ".csv": read_text,
    ".pts": read_text,
    ".npy": read_npy,
}


def write_ply(path: str | Path, points: np.ndarray, *, labels: np.ndarray | None = None) -> None:
    """Write a binary little-endian PLY of ``points`` : (n, 3) float, metres, atomically.

    ``labels`` : (n,) int, optional, is stored as a ``uchar`` property ``label`` (symfruit writes 0 for
    visible and 1 for completed points) and is ignored by viewers that do not know it.

    Raises
    ------
    InputError
        Before anything is written: ``points`` not ``(n, 3)`` numbers, or beyond a 32-bit float's range (written as
        infinity); ``labels`` not ``n`` whole numbers in 0-255 (a ``uchar`` would wrap 256 to 0 and -1 to 255).
    """
    from plyfile import PlyData, PlyElement

    from ..core.points import as_points

    path = as_path(path, "write_ply: the PLY file")  # None was pathlib's TypeError
    points = as_points(points, min_count=0, name=f"{path}: points")
    with np.errstate(invalid="ignore"):
        if (np.abs(points) > np.finfo(np.float32).max).any():
            raise InputError(f"{path}: points beyond a 32-bit float's range ({np.abs(points).max():g}) cannot be "
                             "written to a float PLY")  # fmt: skip
    if labels is not None:
        labels = np.asarray(labels)
        if labels.shape != (len(points),) or labels.dtype.kind not in "biu":
            raise InputError(f"{path}: labels must be {len(points)} whole numbers, one a point, got {labels.dtype} "
                             f"{labels.shape}")  # fmt: skip
        if labels.size and (int(labels.min()) < 0 or int(labels.max()) > 255):
            raise InputError(f"{path}: labels must be 0-255 to fit the PLY's uchar, got {int(labels.min())} to "
                             f"{int(labels.max())}")  # fmt: skip

    fields = [("x", "f4"), ("y", "f4"), ("z", "f4")]
    if labels is not None:
        fields.append(("label", "u1"))
    vertex = np.empty(len(points), dtype=fields)
    vertex["x"], vertex["y"], vertex["z"] = points[:, 0], points[:, 1], points[:, 2]
    if labels is not None:
        vertex["label"] = labels
    with atomic_write(path, "wb") as handle:
        PlyData([PlyElement.describe(vertex, "vertex")], text=False).write(handle)
