"""Frames from ROS 1 / ROS 2 bags, through the pure-Python ``rosbags`` package (optional extra ``bag``).

Colour (``sensor_msgs/Image`` rgb8/bgr8/rgba8/bgra8/mono8, packed 4:2:2 YUYV/UYVY (:func:`yuv422_rgb`), or
``CompressedImage``), depth (``Image``
16UC1 in millimetres or 32FC1 in metres) and ``CameraInfo`` topics are found by type and name (a topic
whose name contains "depth" is depth; of several, the aligned depth, the ``color`` topic and the camera
info beside it: :func:`_pick_topics`). Each depth image is one frame, paired with the colour image nearest
in time (within ``max_skew``) and the latest camera info at or before it.

The bag is indexed once (timestamps only; the raw message bytes pass through without being kept or
decoded) and each frame is then decoded on demand, so memory stays flat however long the recording. A
frame's ``stamp`` and ``frame_id`` are its colour image's header's (the detections are in the colour
camera's frame; ROS outputs and detections.json copy them).

:func:`image_array` is the one decoder of ``sensor_msgs/Image`` (:func:`color_image`, :func:`depth_image`
on top of it, and :func:`camera_from_info`, which checks a camera info's distortion as an intrinsics file's is:
non-finite refused, non-zero warned about once per bag): the live ROS node (:mod:`symfruit.ros.core`) uses them too.
"""

from __future__ import annotations

import bisect
import contextlib
import contextvars
import math
import os
import re
import struct
import traceback
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from ..core.camera import Camera
from ..core.frame import MAX_STAMP_NS, Frame
from ..core.limits import (
    MAX_BAG_CHUNK_BYTES,
    MAX_BAG_METADATA_BYTES,
    MAX_DISTORTION_COEFFS,
    MAX_IMAGE_PIXELS,
    check_image_size,
    shown,
)
from ..errors import FileFormatError, InputError, SymfruitError
from .frames import named_frame
from .images import MIN_16BIT_DEPTH_REACH, float_depth
from .intrinsics import (
    FISHEYE_MODELS,
    check_binning_roi,
    check_pinhole_matrix,
    warn_distortion,
    warn_principal_point,
)
from .text import FileState, file_states, unchanged_while

__all__ = [
    "BagSource",
    "camera_from_info",
    "color_image",
    "depth_image",
    "header_frame_id",
    "header_stamp",
    "image_array",
    "info_distortion",
    "yuv422_rgb",
]

_ENCODINGS: dict[str, tuple[type, int]] = {
    "rgb8": (np.uint8, 3), "bgr8": (np.uint8, 3), "rgba8": (np.uint8, 4), "bgra8": (np.uint8, 4),
    "mono8": (np.uint8, 1), "8uc1": (np.uint8, 1), "8uc3": (np.uint8, 3), "16uc1": (np.uint16, 1),
    "mono16": (np.uint16, 1), "32fc1": (np.float32, 1),
}  # fmt: skip
#: Packed 4:2:2 encodings (two bytes a pixel, each U and V shared by two pixels), decoded to RGB: the offsets
#: of Y0, U, Y1, V in each 4-byte pair. librealsense records its YUYV (YUY2) colour as ``YUYV`` and its UYVY as
#: ``yuv422``, which is UYVY in ROS too (``yuv422_yuy2``: YUYV).
_YUV422 = {"yuyv": (0, 1, 2, 3), "yuy2": (0, 1, 2, 3), "yuv422_yuy2": (0, 1, 2, 3), "uyvy": (1, 0, 3, 2),
           "yuv422": (1, 0, 3, 2)}  # fmt: skip
#: Largest image a message may claim (pixels), checked before its data is touched (with the largest side:
#: :func:`symfruit.core.limits.check_image_size`).
MAX_MESSAGE_PIXELS = MAX_IMAGE_PIXELS


def bag_files(path: Path) -> dict[Path, FileState]:
    """The states (:func:`~symfruit.io.text.file_states`) of the files a bag is read from: the file, or a ROS 2
    bag folder's ``metadata.yaml`` and every file beside it. A frame read after one changed is refused naming
    it (robust53): the index taken at the opening is of the bag as it was."""
    if not path.is_dir():
        return file_states([path])
    with contextlib.suppress(OSError):
        return file_states([path / "metadata.yaml", *sorted(p for p in path.iterdir() if p.is_file())])
    return file_states([path / "metadata.yaml"])


def _require_rosbags() -> Any:
    try:
        from rosbags.highlevel import AnyReader
    except ImportError:
        raise SymfruitError(
            "reading bags needs the rosbags package: pip install 'symfruit[bag]' (or pip install rosbags)"
        ) from None
    _bound_decompression()
    return AnyReader


class ChunkExpands(FileFormatError):
    """A bag's compressed chunk (or message) that decompresses to more than it states (an MCAP chunk's
    ``uncompressed_size``) or, where nothing is stated (a ROS 1 chunk, a ROS 2 message), more than
    :data:`~symfruit.core.limits.MAX_BAG_CHUNK_BYTES`: decompression stops at the bound, before the rest is
    allocated. Stop 49 (robust49)."""

    def __init__(self, compression: str, packed: int, stated: int | None, limit: int) -> None:
        self.compression, self.packed, self.stated = compression, packed, stated
        bound = (f"its stated {stated:,} bytes uncompressed" if stated is not None else
                 f"{limit:,} bytes, the most a chunk is read to")  # fmt: skip
        super().__init__(f"{_named(compression)} chunk of {packed:,} compressed bytes expands past {bound} "
                         "(decompression stopped there): the bag is damaged")  # fmt: skip


def _named(compression: str) -> str:
    return "an LZ4" if compression == "lz4" else f"a {compression}"


def bounded_decompress(data: bytes, compression: str, limit: int) -> bytes:
    """``data`` decompressed (``zstd``, ``lz4`` frame or ``bz2``) to at most ``limit`` bytes: a stream of more
    raises :class:`ChunkExpands` once ``limit + 1`` bytes are out, before the rest is decompressed (a
    decompression bomb: a few kB of zstd expand to gigabytes). zstd and bz2 read every concatenated frame
    (stream), as their ``decompress`` does; an lz4 frame is one frame, as ``lz4.frame.decompress``. A stream
    cut short is refused as the libraries refuse it. Stop 49 (robust49)."""
    if compression == "zstd":
        try:
            from compression import zstd  # type: ignore[import-not-found]  # Python 3.14
        except ImportError:
            from backports import zstd
        make: Any = zstd.ZstdDecompressor
    elif compression == "lz4":
        from lz4.frame import LZ4FrameDecompressor  # type: ignore[import-untyped]

        make = LZ4FrameDecompressor
    elif compression == "bz2":
        import bz2

        make = bz2.BZ2Decompressor
    else:  # pragma: no cover - the callers pass these three
        raise ValueError(f"unknown compression {compression!r}")
    rest, out, n = bytes(data), [], 0
    while rest:
        unpacker = make()
        piece = unpacker.decompress(rest, max_length=min(limit + 1 - n, _STEP_BYTES))
        while True:
            n += len(piece)
            if n > limit:
                raise ChunkExpands(compression, len(data), None, limit)
            out.append(piece)
            if unpacker.eof:
                break
            if unpacker.needs_input:
                raise FileFormatError(f"{_named(compression)} chunk of {len(data):,} compressed bytes is cut "
                                      "short (cannot decompress it): the bag is damaged")  # fmt: skip
            piece = unpacker.decompress(b"", max_length=min(limit + 1 - n, _STEP_BYTES))
        rest = b"" if compression == "lz4" else unpacker.unused_data
    return out[0] if len(out) == 1 else b"".join(out)


#: Most bytes one decompression step gives (the LZ4 decompressor allocates its ``max_length`` up front).
_STEP_BYTES = 8 << 20


def _stated(compression: str) -> Any:
    def unpack(data: bytes, size: int) -> bytes:
        limit = min(int(size), MAX_BAG_CHUNK_BYTES)
        try:
            return bounded_decompress(data, compression, limit)
        except ChunkExpands:
            raise ChunkExpands(compression, len(data), int(size) if size == limit else None, limit) from None

    return unpack


def _capped(compression: str) -> Any:
    return lambda data: bounded_decompress(data, compression, MAX_BAG_CHUNK_BYTES)


class _BoundedZstd:
    """rosbags' ``zstd`` module as its ROS 2 reader sees it: ``decompress`` (a message of a bag compressed per
    message) bounded, ``open`` (a bag compressed as whole files) read through :class:`_BoundedFile`, the rest the
    module's."""

    def __init__(self, module: Any) -> None:
        self._module = module

    def __getattr__(self, name: str) -> Any:
        return getattr(self._module, name)

    def decompress(self, data: bytes) -> bytes:
        return bounded_decompress(data, "zstd", MAX_BAG_CHUNK_BYTES)

    def open(self, file: Any, mode: str = "rb", *args: Any, **kwargs: Any) -> Any:
        opened = self._module.open(file, mode, *args, **kwargs)
        return _BoundedFile(opened, str(getattr(file, "name", file))) if "r" in mode else opened


#: Bytes of the temporary folder's disk left free when a bag compressed as whole files (rosbag2's deprecated
#: ``compression_mode: file``) is decompressed there: rosbags decompresses each file whole before reading it, and
#: nothing in the bag states its size.
BAG_FILE_DISK_RESERVE = 256 << 20


def bag_file_room() -> int:
    """The most bytes one whole-file-compressed bag file may decompress to: the temporary folder's free space
    less :data:`BAG_FILE_DISK_RESERVE`."""
    import shutil
    import tempfile

    return shutil.disk_usage(tempfile.gettempdir()).free - BAG_FILE_DISK_RESERVE


class BagFileRefused(FileFormatError):
    """A bag file compressed whole (zstd) that decompresses past :func:`bag_file_room` (refused once past it,
    before the disk is full), or whose MCAP file, decompressed, :func:`check_mcap` refuses. Stop 50 (robust50)."""


class _BoundedFile:
    """A zstd file opened for reading, as rosbags copies it out whole into its temporary folder: refused
    (:class:`BagFileRefused`) once more bytes come out than :func:`bag_file_room` left on that disk when the first
    came out, or than the room left now less what other runs decompressing there have claimed.

    Each run claims the room before it hands bytes on (:class:`_RoomClaims`: up to :data:`_STEP_BYTES` at a time,
    checked and recorded under a lock shared by the runs on that temporary folder), and counts its claim written
    once it is asked for more (rosbags writes what it read before it reads again). So the reserve holds across
    processes: the room each run checks is the disk's free space less the reserve less the claims of the others
    not yet written (stop 51 asked the disk alone every 8 MB: two runs at once could each pass the reserve by up to
    8 MB; stop 52, robust52)."""

    def __init__(self, opened: Any, name: str) -> None:
        self._opened, self._name, self._out, self._claimed = opened, name, 0, 0
        self._room: int | None = None
        self._claims = _RoomClaims()

    def __enter__(self) -> _BoundedFile:
        return self

    def __exit__(self, *exc: object) -> None:
        self._claims.close()
        self._opened.close()

    def __getattr__(self, name: str) -> Any:
        return getattr(self._opened, name)

    def read(self, size: int | None = -1) -> bytes:
        if size is None or size < 0:  # all of it: in steps, each counted
            return b"".join(iter(lambda: self.read(_STEP_BYTES), b""))
        data = self._opened.read(min(size, _STEP_BYTES))
        written, self._out = self._out, self._out + len(data)  # what came out before is written by now
        if self._out > self._claimed:
            self._claim(written)
        return data

    def _claim(self, written: int) -> None:
        """Claim room for the bytes out beyond the claims so far (at least :data:`_STEP_BYTES` where there is
        room), ``written`` of those out so far being on the disk; refuse when there is not room for them."""
        import tempfile

        with self._claims as others:
            room = bag_file_room()
            if self._room is None:
                self._room = room
            available = room - others - (self._claimed - written)
            need = self._out - self._claimed
            if self._out > max(self._room, 0):
                raise BagFileRefused(
                    f"{self._name}: compressed whole (rosbag2's file compression), it expands past "
                    f"{max(self._room, 0) / 1e6:,.0f} MB, the room in {tempfile.gettempdir()} less "
                    f"{BAG_FILE_DISK_RESERVE >> 20} MB (decompression stopped): damaged, or zstd -d it where there is "
                    "room"
                )
            if need > available:
                held = f", {others / 1e6:,.0f} MB of it held by other runs decompressing there" if others else ""
                raise BagFileRefused(
                    f"{self._name}: compressed whole (rosbag2's file compression), {written / 1e6:,.0f} MB "
                    f"decompressed so far, and the room in {tempfile.gettempdir()} fell below "
                    f"{BAG_FILE_DISK_RESERVE >> 20} MB{held} (another program writes there too; decompression "
                    "stopped): zstd -d it where there is room, or run again when there is"
                )
            self._claimed += min(max(need, _STEP_BYTES), available)
            self._claims.hold(self._claimed - written)

    def readinto(self, buffer: Any) -> int:
        data = self.read(len(buffer))
        buffer[: len(data)] = data
        return len(data)


class _RoomClaims:
    """The temporary disk's room claimed by the runs decompressing a bag there (:class:`_BoundedFile`): a file
    per claimant in ``<tmp>/symfruit-bag-room/`` holding the bytes it claimed and has not yet written, locked
    (``flock``) by its claimant while it lives, so that a claim whose process died is not counted; and a lock
    file taken while a claim is checked and recorded (``with claims as others``: the others' bytes). Where the
    folder cannot be used (another user's, read-only), the claims of the others count as none: the disk alone is
    asked, as before (stop 51)."""

    FOLDER = "symfruit-bag-room"

    def __init__(self) -> None:
        import tempfile
        import uuid

        self._folder = Path(tempfile.gettempdir()) / self.FOLDER
        self._path = self._folder / f"{os.getpid()}-{uuid.uuid4().hex}.claim"
        self._mine: Any = None
        self._lock: Any = None
        try:
            with contextlib.suppress(FileExistsError):  # another run may make it at once
                self._folder.mkdir()
                self._folder.chmod(0o1777)  # every user's runs claim there (sticky: each removes its own alone)
            made = self._path.with_suffix(".new")  # named a claim once locked: never taken for a dead one's
            self._mine = open(made, "w+")  # held, and locked, while this claimant lives
            _flock(self._mine, exclusive=True)
            made.rename(self._path)
        except OSError:
            self.close()

    def __enter__(self) -> int:
        if self._mine is None:
            return 0
        try:
            self._lock = open(self._folder / ".lock", "a")
            _flock(self._lock, exclusive=True, wait=True)
        except OSError:
            self._lock = None
            return 0
        return sum(self._held(path) for path in self._folder.glob("*.claim") if path != self._path)

    def __exit__(self, *exc: object) -> None:
        if self._lock is not None:
            self._lock.close()  # its lock with it
            self._lock = None

    def hold(self, nbytes: int) -> None:
        """Record ``nbytes`` as claimed by this run and not yet written."""
        if self._mine is not None:
            self._mine.seek(0)
            self._mine.truncate()
            self._mine.write(str(nbytes))
            self._mine.flush()

    @staticmethod
    def _held(path: Path) -> int:
        """The bytes another claimant holds: none when its lock is free (its process gone; the file removed)."""
        try:
            with open(path) as file:
                if _flock(file, exclusive=False):
                    path.unlink(missing_ok=True)
                    return 0
                text = file.read(32).strip()
        except OSError:
            return 0
        return int(text) if text.isascii() and text.isdigit() else 0  # '²'.isdigit(), and int() refuses it

    def close(self) -> None:
        if self._mine is not None:
            self._mine.close()
            self._mine = None
        for path in (self._path, self._path.with_suffix(".new")):
            with contextlib.suppress(OSError):
                path.unlink(missing_ok=True)


def _flock(file: Any, *, exclusive: bool, wait: bool = False) -> bool:
    """Lock ``file`` (``flock``); without ``wait``, True when taken, False when another holds it."""
    import fcntl

    flags = (fcntl.LOCK_EX if exclusive else fcntl.LOCK_SH) | (0 if wait else fcntl.LOCK_NB)
    try:
        fcntl.flock(file.fileno(), flags)
    except BlockingIOError:
        return False
    return True


#: The bag folder :class:`BagSource` is opening (rosbags' reader makes its storages then): a storage file outside
#: it is one rosbags decompressed into its temporary folder (a bag compressed as whole files).
_OPENING: contextvars.ContextVar[Path | None] = contextvars.ContextVar("symfruit_bag_opening", default=None)


def _checked_mcap(plugin: Any) -> Any:
    """rosbags' MCAP storage reader, made only after :func:`check_mcap` passes the file: a bag compressed as
    whole files is decompressed by rosbags into a temporary folder, which :class:`BagSource`'s own check of the
    bag folder's ``*.mcap`` never sees, and a file the metadata calls MCAP storage need not be named ``.mcap``.
    The refusal says "decompressed" only of a file outside the bag folder being opened (stop 56: a sqlite3
    database named MCAP storage by its metadata was "its MCAP file x.db3, decompressed: the record at byte 8
    claims 1,152,977,719,091,359,090 bytes")."""

    def make(path: Any) -> Any:
        try:
            check_mcap(Path(path))
        except FileFormatError as exc:
            folder = _OPENING.get()
            inside = folder is not None and Path(path).resolve().is_relative_to(folder.resolve())
            how = ", decompressed" if folder is not None and not inside else ""
            kind = "MCAP" if Path(path).suffix == ".mcap" else "storage"
            raise BagFileRefused(f"its {kind} file {Path(path).name}{how}: {exc}") from None
        return plugin(path)

    make._symfruit = True  # type: ignore[attr-defined]
    return make


def _bound_decompression() -> None:
    """Put :func:`bounded_decompress` in place of rosbags' whole-buffer decompression (once): an MCAP chunk's
    zstd / lz4 data to its stated ``uncompressed_size`` (rosbags compared the sizes after decompressing it all),
    a ROS 1 chunk's bz2 / lz4 and a per-message zstd ROS 2 message to
    :data:`~symfruit.core.limits.MAX_BAG_CHUNK_BYTES` (they state no size rosbags reads). Where rosbags has not
    the tables (another version), it is left as it is. Stop 49 (robust49)."""
    try:
        from rosbags.rosbag1 import reader as ros1
        from rosbags.rosbag2 import reader as ros2
        from rosbags.rosbag2 import storage_mcap
    except ImportError:  # pragma: no cover - another rosbags layout
        return
    table = getattr(storage_mcap, "DECOMPRESSORS", None)
    if isinstance(table, dict) and not getattr(table.get("zstd"), "_symfruit", False):
        for name in ("zstd", "lz4"):
            table[name] = _stated(name)
            setattr(table[name], "_symfruit", True)  # noqa: B010
    table = getattr(ros1, "decompressors", None)
    if isinstance(table, dict) and not getattr(table.get("bz2"), "_symfruit", False):
        for name in ("bz2", "lz4"):
            table[name] = _capped(name)
            setattr(table[name], "_symfruit", True)  # noqa: B010
    module = getattr(ros2, "zstd", None)
    if module is not None and not isinstance(module, _BoundedZstd):
        setattr(ros2, "zstd", _BoundedZstd(module))  # noqa: B010  # rosbags' module, seen by its reader
    folder_reader = getattr(ros2, "DirectoryReader", None)  # a bag folder's reader (rosbags 0.10 and later)
    plugins = getattr(folder_reader, "STORAGE_PLUGINS", None)
    if isinstance(plugins, dict) and "mcap" in plugins and not getattr(plugins["mcap"], "_symfruit", False):
        folder_reader.STORAGE_PLUGINS = {**plugins, "mcap": _checked_mcap(plugins["mcap"])}  # type: ignore[union-attr]
    chunk_reader = getattr(getattr(ros1, "Reader", None), "read_chunk", None)
    if chunk_reader is not None and not getattr(chunk_reader, "_symfruit", False):
        setattr(ros1.Reader, "read_chunk", _sized_chunks(chunk_reader))  # noqa: B010  # rosbags, for its reader
    opener = getattr(getattr(ros1, "Reader", None), "open", None)
    if opener is not None and not getattr(opener, "_symfruit", False):
        setattr(ros1.Reader, "open", _indexed_within(opener))  # noqa: B010  # rosbags, for its reader
    info_reader = getattr(getattr(ros1, "Reader", None), "read_chunk_info", None)
    if info_reader is not None and not getattr(info_reader, "_symfruit", False):
        setattr(ros1.Reader, "read_chunk_info", _chunk_within(info_reader))  # noqa: B010  # rosbags, for its reader


def _sized_chunks(read_chunk: Any) -> Any:
    """rosbags' ROS 1 ``Reader.read_chunk``, its chunk's decompressor bounded by the ``size`` (uncompressed) the
    chunk's header states (rosbags reads the header and leaves that field; the bound was
    :data:`~symfruit.core.limits.MAX_BAG_CHUNK_BYTES` for every chunk). A header without it keeps that bound."""
    import os

    from rosbags.rosbag1 import reader as ros1

    def sized(self: Any) -> Any:
        start = self.bio.tell()
        chunk = read_chunk(self)
        end = self.bio.tell()
        try:
            self.bio.seek(start)
            header = ros1.Header.read(self.bio, ros1.RecordType.CHUNK)
            compression, size = header.get_string("compression"), header.get_uint32("size")
        except Exception:  # no size stated: the bound stays MAX_BAG_CHUNK_BYTES
            return chunk
        finally:
            self.bio.seek(end, os.SEEK_SET)
        if compression not in ("bz2", "lz4"):
            return chunk
        unpack = _stated(compression)
        return chunk._replace(decompressor=lambda data: unpack(data, size))

    sized._symfruit = True  # type: ignore[attr-defined]
    return sized


def _indexed_within(open_bag: Any) -> Any:
    """rosbags' ROS 1 ``Reader.open``, after a check that the bag header's ``index_pos`` lies within the file:
    rosbags seeks there, and a position past what the file system holds failed in the system's words (``[Errno 22]
    Invalid argument``, ``cannot fit 'int' into an offset-sized integer``; stop 51, robust51). A chunk position
    in the index past it is :func:`_chunk_within`'s."""
    from rosbags.rosbag1 import reader as ros1

    def checked(self: Any) -> Any:
        size = None
        try:
            size = os.stat(self.path).st_size
            with open(self.path, "rb") as bio:
                if bio.readline(64) == b"#ROSBAG V2.0\n":
                    index_pos = ros1.Header.read(bio, ros1.RecordType.BAGHEADER).get_uint64("index_pos")
                else:
                    index_pos = 0
        except Exception:  # anything else is rosbags' to say, as before
            index_pos = 0
        if size is not None and 0 < index_pos and index_pos >= size:  # 0: not indexed, as rosbags says
            raise FileFormatError(f"the bag header puts its index at byte {index_pos:,}, past the end of the file "
                                  f"({size:,} bytes): the bag is damaged")  # fmt: skip
        return open_bag(self)  # its index's chunk positions are checked as read (_chunk_within)

    checked._symfruit = True  # type: ignore[attr-defined]
    return checked


def _chunk_within(read_chunk_info: Any) -> Any:
    """rosbags' ROS 1 ``Reader.read_chunk_info`` (an index entry), refused when the chunk position it gives lies
    past the end of the file: rosbags seeks there, and read an empty record where the file system lets it seek
    (``Header could not be read from file.``, rosbags' words; stop 51 left it) or failed in the system's words where
    it does not. Stop 52 (robust52)."""

    def checked(self: Any) -> Any:
        info = read_chunk_info(self)
        size = os.fstat(self.bio.fileno()).st_size
        if not 0 <= info.pos < size:
            raise FileFormatError(f"the bag's index puts a chunk at byte {info.pos:,}, past the end of the file "
                                  f"({size:,} bytes): the bag is damaged")  # fmt: skip
        return info

    checked._symfruit = True  # type: ignore[attr-defined]
    return checked


#: Longest reason from rosbags quoted in a refusal (its parser quotes a whole message definition, 1-2 kB).
REASON_CHARS = 160


def damage_reason(exc: BaseException) -> str | None:
    """What a damaged bag made rosbags (or the compression library under it) fail with, in our words, or None for
    another failure: a chunk that cannot be decompressed (the LZ4 library: ``RuntimeError: LZ4F_decompress failed
    with code: ERROR_decompressionFailed``), a record claiming more bytes than memory holds (``MemoryError``:
    rosbags reads a record's length from the file and asks for that many bytes) or a file ending inside a record
    (``ord() expected a character, but string of length 0 found``), or bytes that are no UTF-8 where a bag holds text
    (``'utf-8' codec can't decode byte 0xff in position 0``). Stop 47 (robust47)."""
    if isinstance(exc, SymfruitError):  # ours, from inside rosbags (a chunk that expands past its size)
        return str(exc)
    text = str(exc)
    if "decompress" in text.lower() or text.startswith("Invalid data stream"):  # LZ4, zstd; bz2
        return "a compressed chunk of the bag cannot be decompressed: the bag is damaged"
    if isinstance(exc, MemoryError):
        return "a record in the bag claims more bytes than memory holds: the bag is damaged"
    if isinstance(exc, TypeError) and text.startswith("ord() expected a character"):
        return "the file ends inside a record: the bag is cut short or damaged"
    if isinstance(exc, UnicodeDecodeError):  # rosbags decodes a ROS 1 bag's header fields as UTF-8
        return "bytes that are no text where a bag holds text: not a bag, or a damaged one"
    if type(exc).__module__ == "apsw":  # a ROS 2 bag's SQLite database, read through apsw: "CorruptError: database
        # disk image is malformed" (a database cut short past its first pages), NotADBError, ... (stop 55, robust55)
        said = text.splitlines()[0][:REASON_CHARS] if text.strip() else type(exc).__name__
        return f"its SQLite database is damaged or cut short ({said})"
    if isinstance(exc, AssertionError) and _raised_in_rosbags(exc):  # a bare assert of rosbags' (an index record
        # of another size than its kind has), said as "cannot open bag (AssertionError)" (robust55)
        return "a record of the bag is not of the size its kind has: the bag is damaged"
    if isinstance(exc, TypeError) and _raised_in_rosbags(exc):  # a value of another SQL type than the schema's (a
        # timestamp or message that is text): "unsupported operand type(s) for -: 'int' and 'str'" (robust55)
        return "a record holds a value of the wrong type (text where a number or bytes belong): the bag is damaged"
    return None


def _raised_in_rosbags(exc: BaseException) -> bool:
    """Whether ``exc`` was raised inside rosbags (its innermost frame), not by a bug of ours calling it."""
    frames = traceback.extract_tb(exc.__traceback__)
    return bool(frames) and f"{os.sep}rosbags{os.sep}" in frames[-1].filename


def index_reason(exc: BaseException) -> str:
    """Why indexing a bag failed inside rosbags, one short line: :func:`damage_reason`'s words where it knows
    them, else the exception's type and :func:`reader_reason`."""
    return damage_reason(exc) or f"{type(exc).__name__}: {reader_reason(exc)}"


#: rosbags' words (and numpy's and struct's under them) for a message whose fields run past its bytes.
_RUNS_PAST = re.compile(r"Invalid (string|sequence) length \d+ at offset \d+|buffer is smaller than requested size|"
                        r"unpack_from requires a buffer")  # fmt: skip


def message_reason(exc: BaseException, raw: Any) -> str:
    """Why rosbags could not read a message of ``raw`` bytes, in one short line: a message cut short (its fields
    run past its end: rosbags' ``Invalid string length 27 at offset 8.``, numpy's ``buffer is smaller than
    requested size``, struct's ``unpack_from requires a buffer of at least 4 bytes``) or of no CDR header is
    said so with its size; anything else as :func:`reader_reason` says it. Stop 56 (robust56)."""
    text = str(exc)
    size = len(raw) if isinstance(raw, bytes | bytearray | memoryview) else 0
    if "Invalid or unsupported CDR encapsulation" in text:
        return f"its {size:,} bytes do not begin with a CDR header: the message is damaged"
    if _RUNS_PAST.search(text):
        return f"its fields run past its {size:,} bytes: the message is cut short or damaged"
    return reader_reason(exc)


def _head(path: Path) -> bytes:
    """A file's first 16 bytes; none where it cannot be read."""
    try:
        with open(path, "rb") as f:
            return f.read(16)
    except OSError:
        return b""


def reader_reason(exc: BaseException) -> str:
    """One short line saying why rosbags refused a bag: a message definition it cannot parse is named as that
    (rosbags quotes the whole definition, several lines, in its message), a damaged bag as :func:`damage_reason`
    says, anything else is its first line, cut to :data:`REASON_CHARS` characters."""
    damaged = damage_reason(exc)
    if damaged is not None:
        return damaged
    if isinstance(exc, OSError) and exc.strerror:  # "Permission denied", not "[Errno 13] ...: 'PATH'" (robust52)
        return exc.strerror
    text = str(exc).strip() or type(exc).__name__
    if text.startswith("Could not parse"):
        return "a message definition in the bag cannot be parsed (damaged connection record)"
    if text.startswith("Bag index looks damaged"):  # rosbags' ROS 1 reader: "Bag index looks damaged: ('Header
        # could not be read from file.',)", a tuple's repr, for an index cut short or broken (robust55)
        return "its index, at the end of the file, is cut short or damaged (`rosbag reindex` rebuilds it)"
    if text.startswith("File end magic is invalid"):  # rosbags' MCAP reader on a file cut short
        return "the MCAP file ends before its footer: a recording cut short (`mcap recover` rebuilds one) or damaged"
    newer = re.match(r"Rosbag2 version (\S+) not supported", text)
    if newer:  # rosbags' own words end "please report issue": it is the installed rosbags that is too old
        return (f"its metadata is rosbag2 version {newer.group(1)[:20]}, newer than the installed rosbags reads "
                "(pip install -U rosbags, or `ros2 bag convert` it to an older version)")  # fmt: skip
    first = text.splitlines()[0].strip()
    other = re.fullmatch(r"Cannot open database (.+): file is not a database", first)
    if other:  # a storage file of another kind than the metadata names (stop 56)
        head = _head(Path(other.group(1)))
        if (what := _what_file(head)) is not None and not head.startswith(_SQLITE_MAGIC):
            return (f"{Path(other.group(1)).name} is not an SQLite database ({what}), though the bag reads it as "
                    "one (by its metadata.yaml's storage_identifier)")  # fmt: skip
    if len(first) > REASON_CHARS:
        first = f"{first[:REASON_CHARS]}... ({len(text)} characters)"
    return first


def image_array(msg: Any, typename: str) -> np.ndarray:
    """The pixels of a ``sensor_msgs/Image`` or ``CompressedImage``: ``(h, w)`` or ``(h, w, 3)``.

    Colour comes back RGB (``bgr*`` reordered, alpha dropped, YUYV/UYVY converted, ``mono8`` stays one
    channel); depth keeps its dtype (uint16 units or float32 metres).

    Raises
    ------
    FileFormatError
        For an unknown encoding, a ``compressedDepth`` image, a size that is not positive or too large,
        or data shorter than ``height x step``.
    """
    if typename.endswith("CompressedImage"):
        fmt = str(getattr(msg, "format", ""))
        if "compresseddepth" in fmt.lower():
            raise FileFormatError(f"compressedDepth images ({shown(fmt)}) are not supported; record raw depth")
        from .images import decode_color

        return decode_color(bytes(msg.data), "compressed image")
    enc = str(msg.encoding).lower()
    if enc not in _ENCODINGS and enc not in _YUV422:
        raise FileFormatError(f"unsupported image encoding {shown(msg.encoding)} (use one of "
                              f"{', '.join([*_ENCODINGS, *_YUV422])})")  # fmt: skip
    dtype, channels = _ENCODINGS.get(enc, (np.uint8, 2))
    sizes = [getattr(msg, k, None) for k in ("height", "width", "step")]
    h, w, step = (_whole(v) for v in sizes)
    if h is None or w is None or step is None:  # a fraction is not cut to its whole part, nor text read as a number
        raise FileFormatError(f"image height, width and step must be whole numbers, got "
                              f"{', '.join(shown(v) for v in sizes)}")  # fmt: skip
    if h <= 0 or w <= 0 or h * w > MAX_MESSAGE_PIXELS:
        raise FileFormatError(f"image of {w}x{h} pixels is empty or larger than {MAX_MESSAGE_PIXELS:,} pixels")
    check_image_size(w, h, f"{enc} image message", error=FileFormatError)
    if enc in _YUV422 and w % 2:
        raise FileFormatError(f"{msg.encoding} image of odd width {w}: two pixels share each U and V")
    big = getattr(msg, "is_bigendian", 0)
    if not isinstance(big, bool) and _whole(big) not in (0, 1):  # a uint8 of 0 or 1; 2-255 is no byte order
        raise FileFormatError(f"image is_bigendian is {shown(big)}: 0 (little-endian) or 1 (big-endian) "
                              f"expected; the message is malformed")  # fmt: skip
    dt = np.dtype(dtype).newbyteorder(">" if big else "<")
    row_bytes = w * channels * dt.itemsize
    if step < row_bytes:
        raise FileFormatError(f"image step {step} is shorter than a row of {w} {enc} pixels ({row_bytes} bytes)")
    data = np.frombuffer(_message_bytes(getattr(msg, "data", None)), dtype=np.uint8)
    if len(data) < h * step:
        raise FileFormatError(f"image data holds {len(data)} bytes, {h} rows of {step} need {h * step}")
    rows = data[: h * step].reshape(h, step)
    if enc in _YUV422:
        return yuv422_rgb(rows[:, :row_bytes], _YUV422[enc])
    img = rows[:, :row_bytes].copy().view(dt).reshape(h, w, channels).astype(dtype, copy=False)
    if enc.startswith("bgr"):
        img = img[:, :, [2, 1, 0]]
    return img[:, :, 0] if channels == 1 else img[:, :, :3]


def _whole(value: Any) -> int | None:
    """A message's size field as an int: whole numbers only (uint32 in every ROS message; a hand-made message's
    48.5, "48" or None is no size). None for anything else."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer | float | np.floating):
        return None
    if isinstance(value, float | np.floating) and not float(value).is_integer():
        return None
    return int(value)


def _message_bytes(data: Any) -> bytes:
    """A message's ``data`` as bytes (``bytes`` in rospy and rosbags, ``array('B')`` or a list of 0-255 in
    rclpy); anything else refused, not a ``TypeError`` from ``bytes`` (None, text, values beyond a byte), nor a
    whole number taken as a count of zero bytes to allocate (``bytes(10**12)``)."""
    if isinstance(data, bytes):
        return data
    if not isinstance(data, int | np.integer | str):
        try:
            return bytes(data)
        except (TypeError, ValueError):
            pass
    got = "nothing (None)" if data is None else type(data).__name__  # not Python's "NoneType" (robust48)
    raise FileFormatError(f"image data must be bytes (uint8[]), got {got}")


def yuv422_rgb(rows: np.ndarray, order: tuple[int, int, int, int]) -> np.ndarray:
    """``(h, w, 3) uint8`` RGB of packed 4:2:2 rows (``(h, 2 w)`` bytes), BT.601 limited range in integers
    exactly as librealsense's ``unpack_yuy2`` (its portable code): ``c = Y - 16, d = U - 128, e = V - 128``,
    ``R = (298 c + 409 e + 128) >> 8``, ``G = (298 c - 100 d - 208 e + 128) >> 8``, ``B = (298 c + 516 d + 128)
    >> 8``, clipped to 0-255. ``order`` gives the offsets of Y0, U, Y1 and V in each 4 bytes."""
    h = rows.shape[0]
    quads = rows.reshape(h, -1, 4).astype(np.int32)
    y0, u, y1, v = (quads[:, :, k] for k in order)
    c = np.stack([y0, y1], axis=2).reshape(h, -1) - 16  # pixel by pixel: Y0 Y1 of each pair
    d = np.repeat(u - 128, 2, axis=1)
    e = np.repeat(v - 128, 2, axis=1)
    out = np.empty((*c.shape, 3), np.uint8)
    out[:, :, 0] = np.clip((298 * c + 409 * e + 128) >> 8, 0, 255)
    out[:, :, 1] = np.clip((298 * c - 100 * d - 208 * e + 128) >> 8, 0, 255)
    out[:, :, 2] = np.clip((298 * c + 516 * d + 128) >> 8, 0, 255)
    return out


def color_image(msg: Any, typename: str = "sensor_msgs/msg/Image") -> np.ndarray:
    """(h, w, 3) uint8 RGB of a colour image message (:func:`image_array`; ``mono8`` repeated to grey RGB).

    Raises
    ------
    FileFormatError
        For anything :func:`image_array` refuses, or a 16-bit or float encoding (depth, not colour: it is
        refused, never cut to 8 bits).
    """
    img = image_array(msg, typename)
    if img.dtype != np.uint8:
        eight = [e for e, (t, _) in _ENCODINGS.items() if t is np.uint8]
        raise FileFormatError(f"colour image encoding {shown(msg.encoding)} is not 8-bit colour (use one of "
                              f"{', '.join([*eight, *_YUV422])})")  # fmt: skip
    if img.ndim == 2:
        img = np.repeat(img[:, :, None], 3, axis=2)
    return np.ascontiguousarray(img, dtype=np.uint8)


def depth_image(msg: Any, typename: str = "sensor_msgs/msg/Image", *, depth_scale: float = 0.001) -> np.ndarray:
    """(h, w) float32 metres of a depth image message (:func:`image_array`): 16-bit units times
    ``depth_scale`` (millimetres by default, as RealSense cameras record) or 32FC1 metres; 0 where invalid.

    Raises
    ------
    FileFormatError
        For anything :func:`image_array` refuses, or an image that is not one-channel depth.
    InputError
        For a ``depth_scale`` that is not metres per unit in (0, 1], or by which 16-bit units reach less than
        :data:`~symfruit.io.images.MIN_16BIT_DEPTH_REACH`.
    """
    if (
        isinstance(depth_scale, bool)
        or not isinstance(depth_scale, int | float | np.integer | np.floating)
        or not (0 < depth_scale <= 1)
    ):  # a frame's camera.json's rule: 0, a negative or NaN scale would read every pixel as no depth
        raise InputError(f"depth_scale must be metres per unit in (0, 1], got {shown(depth_scale)}")
    raw = image_array(msg, typename)
    if raw.ndim != 2:
        raise FileFormatError(f"depth image has {raw.shape[2]} channels, expected 1")
    if raw.dtype not in (np.uint16, np.float32):
        raise FileFormatError(f"depth image encoding {shown(msg.encoding)}: expected 16UC1/mono16 units or 32FC1 "
                              "metres")  # fmt: skip
    if raw.dtype == np.uint16 and 65535 * depth_scale < MIN_16BIT_DEPTH_REACH:  # 1e-300 was 0 in float32: no depth
        raise InputError(f"depth_scale {depth_scale:g}: 16-bit depth would reach only {65535 * depth_scale:.3g} m; no "
                         "camera measures depth that finely (metres per unit, 0.001 for millimetres)")  # fmt: skip
    if raw.dtype == np.uint16:  # one pass, float32 as everywhere (units x scale)
        return np.multiply(raw, np.float32(depth_scale), dtype=np.float32)
    return float_depth(raw)  # image_array's own copy; NaN, inf, FLT_MAX (beyond NO_DEPTH_BEYOND): no depth


def camera_from_info(
    msg: Any,
    *,
    width: int | None = None,
    height: int | None = None,
    source: str | None = None,
    warned: set[str] | None = None,
) -> Camera:
    """Pinhole intrinsics of a ``sensor_msgs/CameraInfo`` (``K`` in ROS 1, ``k`` in ROS 2).

    A camera info whose width or height is 0 takes ``width`` / ``height`` (the image's) when given.
    Distortion (``D``/``d``) is not applied: symfruit works on rectified or near-distortion-free colour images.
    It is checked as an intrinsics file's is (:func:`info_distortion`: non-finite refused) and, with ``source``
    (what names the camera in the warning), non-zero coefficients raise a
    :class:`~symfruit.errors.SymfruitWarning` (:func:`symfruit.io.intrinsics.warn_distortion`), as does a
    principal point outside the image (:func:`symfruit.io.intrinsics.warn_principal_point`). ``warned``: the
    kinds (``"distortion"``, ``"principal point"``) already said, not said again; those said are added.

    Raises
    ------
    InputError
        When there is no 3x3 ``K``, the intrinsics are invalid or the distortion is not finite numbers.
    """
    k = getattr(msg, "k", None)
    if k is None:
        k = getattr(msg, "K", [])
    try:
        k = [float(v) for v in k]
    except (TypeError, ValueError):
        raise InputError("CameraInfo K holds something that is not a number") from None
    if len(k) != 9:
        raise InputError("CameraInfo has no 3x3 K matrix")
    key, coeffs = info_distortion(msg)
    sizes = (getattr(msg, "width", None), getattr(msg, "height", None))
    w, h = (_whole(v) for v in sizes)
    if w is None or h is None:  # uint32 in the message; a hand-made one's None or "640" is no size, 2.5 not 2
        raise InputError(f"CameraInfo width and height must be whole numbers, got {', '.join(shown(v) for v in sizes)}")
    w, h = w or (width or 0), h or (height or 0)
    camera = Camera(fx=k[0], fy=k[4], cx=k[2], cy=k[5], width=w, height=h)
    check_pinhole_matrix(k, "CameraInfo K")  # row-major; a transposed one would read cx = cy = 0
    check_binning_roi(getattr(msg, "binning_x", None), getattr(msg, "binning_y", None), getattr(msg, "roi", None),
                      camera, "CameraInfo")  # fmt: skip
    if source is not None:
        said = warned if warned is not None else set()
        model = getattr(msg, "distortion_model", None)
        if "distortion" not in said and warn_distortion(source, key, coeffs, stacklevel=3, model=model):
            said.add("distortion")
        if "principal point" not in said and warn_principal_point(source, camera, stacklevel=3):
            said.add("principal point")
    return camera


def fisheye(msg: Any) -> bool:
    """Whether a ``CameraInfo``'s ``distortion_model`` is a fisheye one (:data:`~.intrinsics.FISHEYE_MODELS`)."""
    model = getattr(msg, "distortion_model", None)
    return isinstance(model, str) and model.lower() in FISHEYE_MODELS


def info_distortion(msg: Any) -> tuple[str, list[float]]:
    """``(field, coefficients)`` of a ``CameraInfo``'s distortion (``D`` in ROS 1, ``d`` in ROS 2; none: empty),
    checked as an intrinsics file's: at most :data:`~symfruit.core.limits.MAX_DISTORTION_COEFFS` finite numbers.

    Raises
    ------
    InputError
        Naming the field, for values that are not finite numbers or too many of them.
    """
    key = "d" if getattr(msg, "d", None) is not None else "D"
    values = getattr(msg, key, None)
    if values is None:
        return key, []
    try:
        count = len(values)  # counted before any is converted: a field of millions is refused as it stands
    except TypeError:
        raise InputError(f"CameraInfo {key} is not a list of numbers") from None
    if count > MAX_DISTORTION_COEFFS:
        raise InputError(f"CameraInfo {key} must hold at most {MAX_DISTORTION_COEFFS} finite numbers, got {count} "
                         "values")  # fmt: skip
    try:
        coeffs = [float(v) for v in values]
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"CameraInfo {key} holds something that is not a number") from None
    if not all(math.isfinite(c) for c in coeffs):
        raise InputError(f"CameraInfo {key} must hold at most {MAX_DISTORTION_COEFFS} finite numbers, got {coeffs}")
    return key, coeffs


def header_stamp(msg: Any) -> int | None:
    """A message's header stamp in nanoseconds (``sec``/``nanosec`` or ``secs``/``nsecs``); None without one,
    or for one that is not a time (before 1970 or from 2242 on: :data:`~symfruit.core.frame.MAX_STAMP_NS`)."""
    stamp = getattr(getattr(msg, "header", None), "stamp", None)
    if stamp is None:
        return None
    sec = _whole(getattr(stamp, "sec", getattr(stamp, "secs", 0)))
    nsec = _whole(getattr(stamp, "nanosec", getattr(stamp, "nsecs", 0)))
    if sec is None or nsec is None:  # a hand-made message's text, None, NaN, inf or 2.5: no time (stop 48,
        return None  # robust48: int() raised TypeError / ValueError / OverflowError, or cut 2.5 s to 2)
    value = sec * 1_000_000_000 + nsec
    return value if 0 <= value < MAX_STAMP_NS else None


def header_frame_id(msg: Any) -> str:
    """A message's header ``frame_id`` ("" without one)."""
    return str(getattr(getattr(msg, "header", None), "frame_id", "") or "")


def _stamp(msg: Any, fallback: int) -> int:
    """The header stamp in nanoseconds, else ``fallback`` (also for a zero stamp or one that is not a time)."""
    value = header_stamp(msg)
    return value if value else fallback


def listed(topics: Sequence[str], most: int = 6) -> str:
    """Topics for an error message: at most ``most`` of them, each cut to 60 characters, and how many more (a
    recording's topics are its own text and may be hundreds: tf, imu, diagnostics...)."""
    named = [t if len(t) <= 60 else t[:57] + "..." for t in topics[:most]]
    if len(topics) > most:
        named.append(f"and {len(topics) - most} more")
    return ", ".join(named) or "none"


def _check_metadata(path: Path) -> None:
    """Refuse a ROS 2 bag's ``metadata.yaml`` that rosbags would read without end or bound: not a regular
    file (a link to ``/dev/zero``, a pipe) or larger than :data:`~symfruit.core.limits.MAX_BAG_METADATA_BYTES`;
    and one that is empty or holds no ``rosbag2_bagfile_information`` mapping (rosbags: "'NoneType' object is
    not subscriptable")."""
    try:
        size = path.stat().st_size if path.is_file() else None
    except OSError as exc:
        raise FileFormatError(f"{path}: cannot read bag metadata ({exc.strerror or exc})") from None
    if size is None:
        raise FileFormatError(f"{path}: bag metadata is missing or not a regular file")
    if size > MAX_BAG_METADATA_BYTES:
        raise FileFormatError(f"{path}: bag metadata is {size:,} bytes; at most {MAX_BAG_METADATA_BYTES >> 20} MB "
                              "are read (a rosbag2 metadata.yaml takes a few kB)")  # fmt: skip
    from .text import read_structured

    data = read_structured(path, what="bag metadata", max_bytes=MAX_BAG_METADATA_BYTES)
    if not isinstance(data, dict) or not isinstance(data.get("rosbag2_bagfile_information"), dict):
        raise FileFormatError(f"{path}: not a ROS 2 bag's metadata (no rosbag2_bagfile_information mapping)")


_MCAP_MAGIC = b"\x89MCAP0\r\n"
_SQLITE_MAGIC = b"SQLite format 3\0"
#: Largest MCAP record read whole by the walk (a chunk index: a few dozen bytes and 10 a channel).
_MCAP_INDEX_BYTES = 1 << 20


#: What a bag's storage file is, by its first bytes (stop 56: a file of the other storage than its metadata names).
_FILE_KINDS = (
    (_SQLITE_MAGIC, "it is an SQLite database: rosbag2's sqlite3 storage"),
    (_MCAP_MAGIC, "it is an MCAP file: rosbag2's mcap storage"),
    (b"\x28\xb5\x2f\xfd", "it is zstd-compressed"),
    (b"#ROSBAG", "it is a ROS 1 bag"),
)


def _what_file(head: bytes) -> str | None:
    """What a file beginning ``head`` is, in a few words, where its first bytes say (a bag's storages)."""
    return next((said for magic, said in _FILE_KINDS if head.startswith(magic)), None)


def check_mcap(path: Path) -> dict[int, tuple[int, int, int]]:
    """Refuse an MCAP file (a ROS 2 bag's) whose records claim sizes it cannot hold, before rosbags reads it:
    rosbags reads each record's length from the file and asks for that many bytes (the header record's, a
    chunk's, a chunk index's compressed size), and decompresses a chunk whole. Walks the top-level records
    (9 bytes read a record, a seek past it): every record's length within the bytes left before the end magic;
    a chunk's uncompressed size at most :data:`~symfruit.core.limits.MAX_BAG_CHUNK_BYTES`, its compressed
    data within its record; the footer's summary offset and every chunk index's chunk offset a record's start
    (a chunk's), its sizes the chunk's. Of a file without the end magic (cut short) only the header record is
    checked (rosbags reads it, then refuses the file as cut short). Stop 48 (robust48).

    Returns the chunks found (start -> uncompressed size, compressed size, record length): a chunk that
    expands past its size when rosbags decompresses it is named by them (:class:`ChunkExpands`)."""
    try:
        with open(path, "rb") as f:
            size = f.seek(0, 2)
            if size < 16:
                return {}  # rosbags: empty, or its magic alone ("the file ends inside a record")
            f.seek(0)
            magic = f.read(16)
            if magic[:8] != _MCAP_MAGIC:
                what = _what_file(magic) or "it does not begin with MCAP's magic bytes"
                raise FileFormatError(f"not an MCAP file ({what}), though the bag reads it as one (by its "
                                      "metadata.yaml's storage_identifier, or its name)")  # fmt: skip
            f.seek(size - 8)
            whole = f.read(8) == _MCAP_MAGIC
            end = size - 8 if whole else size
            pos = 8
            starts: dict[int, int] = {}  # record start -> opcode
            chunks: dict[int, tuple[int, int, int]] = {}  # chunk start -> uncompressed, compressed, record size
            indexes: list[tuple[int, bytes]] = []
            footer: bytes | None = None
            while pos < end:
                f.seek(pos)
                head = f.read(9)
                if len(head) < 9:
                    raise FileFormatError(f"the record at byte {pos:,} is cut short: the MCAP file is damaged")
                op, length = head[0], int.from_bytes(head[1:], "little")
                left = max(end - pos - 9, 0)
                if length > left:
                    raise FileFormatError(f"the record at byte {pos:,} claims {length:,} bytes, more than the "
                                          f"{left:,} left in the file: the MCAP file is damaged")  # fmt: skip
                if not whole:  # rosbags reads the header record, then refuses the missing end magic itself
                    return {}
                starts[pos] = op
                if op == 0x06:  # chunk: start, end, uncompressed size (u64 each), crc (u32), compression, records
                    body = f.read(min(length, 32))
                    if len(body) < 32:
                        raise FileFormatError(f"the chunk at byte {pos:,} is too short to be one: the MCAP file is "
                                              "damaged")  # fmt: skip
                    unpacked = int.from_bytes(body[16:24], "little")
                    name_len = int.from_bytes(body[28:32], "little")
                    if unpacked > MAX_BAG_CHUNK_BYTES:
                        raise FileFormatError(f"the chunk at byte {pos:,} claims {unpacked:,} bytes uncompressed; "
                                              f"at most {MAX_BAG_CHUNK_BYTES >> 20} MB are read (rosbag2 writes "
                                              "chunks of 768 kB)")  # fmt: skip
                    if 32 + name_len + 8 > length:
                        raise FileFormatError(f"the chunk at byte {pos:,} names a compression longer than itself: "
                                              "the MCAP file is damaged")  # fmt: skip
                    f.seek(pos + 9 + 32 + name_len)
                    packed = int.from_bytes(f.read(8), "little")
                    if 32 + name_len + 8 + packed > length:
                        raise FileFormatError(f"the chunk at byte {pos:,} claims {packed:,} compressed bytes, more "
                                              "than its record holds: the MCAP file is damaged")  # fmt: skip
                    chunks[pos] = (unpacked, packed, length)
                elif op == 0x08:  # chunk index: read whole (small), checked once every chunk is known
                    if length > _MCAP_INDEX_BYTES:
                        raise FileFormatError(f"the chunk index at byte {pos:,} claims {length:,} bytes; a chunk "
                                              f"index takes a few dozen: the MCAP file is damaged")  # fmt: skip
                    indexes.append((pos, f.read(length)))
                elif op == 0x02:  # footer: summary start, summary offset start (u64), crc
                    footer = f.read(length)
                    break
                pos += 9 + length
    except OSError as exc:
        raise FileFormatError(f"cannot read {path.name} ({exc.strerror or exc})") from None
    if footer is not None and len(footer) >= 8:
        summary = int.from_bytes(footer[:8], "little")
        if summary and summary not in starts:
            raise FileFormatError(f"its footer's summary offset {summary:,} is no record's start: the MCAP file is "
                                  "damaged")  # fmt: skip
    for at, rec in indexes:
        try:
            start = struct.unpack_from("<QQQQ", rec, 0)[2:]
            (map_len,) = struct.unpack_from("<I", rec, 32)
            k = 36 + map_len + 8
            (name_len,) = struct.unpack_from("<I", rec, k)
            packed, unpacked = struct.unpack_from("<QQ", rec, k + 4 + name_len)
        except struct.error:
            raise FileFormatError(f"the chunk index at byte {at:,} is cut short: the MCAP file is damaged") from None
        offset, length = start
        chunk = chunks.get(offset)
        if chunk is None or length != chunk[2] + 9 or (unpacked, packed) != chunk[:2]:
            raise FileFormatError(f"the chunk index at byte {at:,} points at no chunk of its sizes (offset "
                                  f"{shown(offset)}, {shown(packed)} bytes compressed, {shown(unpacked)} "
                                  "uncompressed): the MCAP file is damaged")  # fmt: skip
    return chunks


def _namespace(topic: str) -> str:
    return topic.rsplit("/", 1)[0]


def _pick_topics(depth: list[Any], color: list[Any], info: list[Any]) -> tuple[Any, Any, Any]:
    """The depth, colour and CameraInfo connections a frame is read from, when a bag holds several (a
    realsense-ros recording has ``depth/image_rect_raw`` beside ``aligned_depth_to_color/image_raw``,
    ``infra1`` beside ``color``, and a camera info for each).

    Depth aligned to colour (``aligned`` or ``registered`` in its name) comes first; colour is a topic named
    ``color``/``colour``/``rgb`` before any other, and never an infrared one while there is another; the camera
    info is the one beside the colour topic (same namespace), else beside the aligned depth (whose intrinsics
    are the colour camera's), else the only one. Several camera infos and none of those is refused: taking
    one at random could give the colour image the depth camera's intrinsics.
    """

    def has(conn: Any, *words: str) -> bool:
        return any(w in conn.topic.lower() for w in words)

    d = sorted(depth, key=lambda c: not has(c, "aligned", "registered"))[0]
    named = [c for c in color if has(c, "color", "colour", "rgb")]
    plain = [c for c in color if not has(c, "infra", "/ir/", "/ir_")]
    c = (named or plain or color)[0]
    beside = [i for i in info if _namespace(i.topic) == _namespace(c.topic)]
    if not beside and has(d, "aligned", "registered"):
        beside = [i for i in info if _namespace(i.topic) == _namespace(d.topic)]
    if not beside and len(info) == 1:
        beside = info
    if not beside:
        topics = listed([i.topic for i in info])
        raise FileFormatError(f"bag has several CameraInfo topics ({topics}) and none beside the colour topic "
                              f"{c.topic}: which are the colour camera's intrinsics?")  # fmt: skip
    return d, c, beside[0]


def _on_topic(topic: str, stamp: int, read: Any, *args: Any) -> np.ndarray:
    """``read(*args)`` (an image of a message), its refusal naming the topic and stamp of the message (a colour
    and a depth image may be refused alike: ``image data holds ...`` would not say which)."""
    try:
        return read(*args)
    except FileFormatError as exc:
        raise FileFormatError(f"{topic} at {stamp}: {exc}") from None


class BagSource:
    """A bag as a recording: one frame per depth image (see the module docstring)."""

    def __init__(self, path: Path, *, max_skew: float = 0.05) -> None:
        self.path = Path(path)
        self.max_skew = max_skew
        self._files = bag_files(self.path)  # each frame read checks that none changed since (robust53)
        reader_cls = _require_rosbags()
        self._chunks: dict[Path, dict[int, tuple[int, int, int]]] = {}  # each MCAP file's chunks (ChunkExpands)
        if self.path.is_dir():
            _check_metadata(self.path / "metadata.yaml")
            for mcap in sorted(self.path.glob("*.mcap")):
                try:
                    self._chunks[mcap] = check_mcap(mcap)
                except FileFormatError as exc:
                    raise FileFormatError(f"{mcap}: cannot open bag ({exc})") from None
        try:
            self._reader = reader_cls([self.path])
            opening = _OPENING.set(self.path)
            try:
                self._reader.open()
            finally:
                _OPENING.reset(opening)
        except ChunkExpands as exc:  # an MCAP without a summary: rosbags decompresses every chunk to index it
            raise FileFormatError(self._expands(exc)) from None
        except BagFileRefused as exc:  # a bag compressed as whole files
            message = str(exc)
            raise FileFormatError(
                message if message.startswith(str(self.path)) else f"{self.path}: {message}"
            ) from None
        except Exception as exc:  # rosbags raises its own ReaderError / AnyReaderError types
            raise FileFormatError(f"{self.path}: cannot open bag ({reader_reason(exc)})") from None
        try:
            self._index()
        except ChunkExpands as exc:
            self.close()
            raise FileFormatError(self._expands(exc)) from None
        except SymfruitError as exc:
            self.close()
            raise FileFormatError(f"{self.path}: {exc}") from None
        except Exception as exc:  # a corrupt bag fails inside rosbags while indexing
            self.close()
            raise FileFormatError(f"{self.path}: cannot index bag ({index_reason(exc)})") from None

    def _expands(self, exc: ChunkExpands) -> str:
        """``exc`` naming the MCAP file and the chunk (its byte) whose sizes it has, where one chunk has them."""
        at = [(mcap, pos) for mcap, chunks in self._chunks.items() for pos, (unpacked, packed, _) in chunks.items()
              if packed == exc.packed and unpacked == exc.stated]  # fmt: skip
        if len(at) != 1:
            return f"{self.path}: {exc}"
        mcap, pos = at[0]
        return (f"{mcap}: the {exc.compression} chunk at byte {pos:,} ({exc.packed:,} bytes compressed) expands "
                f"past its stated {exc.stated:,} bytes uncompressed (decompression stopped there): the bag is "
                "damaged")  # fmt: skip

    def _index(self) -> None:
        conns = self._reader.connections
        info = [c for c in conns if c.msgtype.endswith("CameraInfo")]
        images = [c for c in conns if c.msgtype.endswith(("/Image", "/CompressedImage"))]
        depth = [c for c in images if "depth" in c.topic.lower()]
        color = [c for c in images if "depth" not in c.topic.lower()]
        if not depth or not color:
            topics = sorted({c.topic for c in conns})
            raise FileFormatError(f"bag needs a colour and a depth image topic (its image topics: "
                                  f"{listed([c.topic for c in images])}; {len(topics)} topics in all)")  # fmt: skip
        if not info:
            raise FileFormatError("bag has no CameraInfo topic")
        self._depth, self._color, self._info = _pick_topics(depth, color, info)
        self._depth_stamps: list[int] = []
        self._color_stamps: list[int] = []
        # (stamp, camera or why it is invalid, whether its width/height were 0: the image's then), on change
        self._cameras: list[tuple[int, Camera | str, tuple[bool, bool]]] = []
        last: Any = None
        distorted: tuple[str, list[float]] | None = None  # the first non-zero distortion: warned about once
        model: Any = None  # its lens model (a fisheye one is warned about with coefficients 0)
        for conn, stamp, raw in self._reader.messages(connections=[self._info, self._depth, self._color]):
            if not isinstance(raw, bytes | bytearray | memoryview):  # a SQLite row whose data is text (robust55)
                raise FileFormatError(f"the message on {conn.topic} at {stamp} holds {type(raw).__name__}, not bytes: "
                                      "the bag's database is damaged")  # fmt: skip
            if conn == self._depth:
                self._depth_stamps.append(stamp)
            elif conn == self._color:
                self._color_stamps.append(stamp)
            elif bytes(raw) != last:
                last = bytes(raw)
                sizeless = (False, False)
                try:
                    try:
                        msg = self._reader.deserialize(raw, conn.msgtype)
                    except Exception as exc:
                        raise FileFormatError(message_reason(exc, raw)) from None
                    sizeless = (not int(msg.width), not int(msg.height))  # as the live node: the image's size
                    camera: Camera | str = camera_from_info(msg, width=1, height=1)
                    coeffs = info_distortion(msg)
                    if distorted is None and (any(coeffs[1]) or fisheye(msg)):
                        distorted, model = coeffs, getattr(msg, "distortion_model", None)
                except Exception as exc:  # a corrupt or invalid CameraInfo: frames after it fail, not the bag
                    camera = f"invalid CameraInfo on {conn.topic} ({exc})"
                if not self._cameras or self._cameras[-1][1:] != (camera, sizeless):  # kept on change: each
                    self._cameras.append((stamp, camera, sizeless))  # is stamped anew, the intrinsics seldom change
        if not self._depth_stamps:  # a frame per depth image: a recording of none would be "0 frames", unsaid
            raise FileFormatError(f"depth topic {self._depth.topic} holds no messages")
        if not self._color_stamps:
            raise FileFormatError(f"colour topic {self._color.topic} holds no messages")
        if not self._cameras:
            raise FileFormatError(f"CameraInfo topic {self._info.topic} holds no messages")
        self._camera_stamps = [s for s, _, _ in self._cameras]
        self._off_centre_said = False  # a principal point outside the image: warned about at the first frame
        if distorted is not None:
            warn_distortion(f"{self.path}: CameraInfo on {self._info.topic}", *distorted, stacklevel=4, model=model)

    def __len__(self) -> int:
        return len(self._depth_stamps)

    def names(self) -> list[str]:
        return [f"{self.path.stem}_{i:05d}_{s}" for i, s in enumerate(self._depth_stamps)]

    def _message(self, conn: Any, stamp: int, nth: int = 0) -> Any:
        """The ``nth`` message of ``conn`` at bag time ``stamp`` (two may share one: a bag rewritten with header
        stamps as its times; each is its own frame, never the first read twice)."""
        for k, (_, _, raw) in enumerate(self._reader.messages(connections=[conn], start=stamp, stop=stamp + 1)):
            if k < nth:
                continue
            try:
                return self._reader.deserialize(raw, conn.msgtype)
            except Exception as exc:
                reason = message_reason(exc, raw)
                raise FileFormatError(f"{self.path}: corrupt message on {conn.topic} at {stamp} ({reason})") from None
        raise FileFormatError(f"{self.path}: no message on {conn.topic} at {stamp}")  # pragma: no cover

    def read(self, index: int) -> Frame:
        with unchanged_while(self._files, "since the bag was opened"):
            return self._read(index)

    def _read(self, index: int) -> Frame:
        if not 0 <= index < len(self._depth_stamps):
            raise IndexError(f"frame index {index} out of range for {len(self._depth_stamps)} frames")
        stamp = self._depth_stamps[index]
        name = f"{self.path.stem}_{index:05d}_{stamp}"
        j = bisect.bisect_left(self._color_stamps, stamp)
        near = min((k for k in (j - 1, j) if 0 <= k < len(self._color_stamps)),
                   key=lambda k: abs(self._color_stamps[k] - stamp))  # fmt: skip
        if abs(self._color_stamps[near] - stamp) > self.max_skew * 1e9:
            raise FileFormatError(f"{self.path}: no colour image within {self.max_skew} s of depth at {stamp}")
        c = max(bisect.bisect_right(self._camera_stamps, stamp) - 1, 0)
        _, camera, sizeless = self._cameras[c]
        if isinstance(camera, str):
            raise FileFormatError(f"{self.path}: {camera}")
        try:
            dmsg = self._message(self._depth, stamp, index - bisect.bisect_left(self._depth_stamps, stamp))
            cstamp = self._color_stamps[near]
            cmsg = self._message(self._color, cstamp, near - bisect.bisect_left(self._color_stamps, cstamp))
            color = _on_topic(self._color.topic, cstamp, color_image, cmsg, self._color.msgtype)
            depth = _on_topic(self._depth.topic, stamp, depth_image, dmsg, self._depth.msgtype)
            if any(sizeless):  # a camera info of width or height 0 is for the images' size (the live node's rule)
                camera = replace(camera, width=depth.shape[1] if sizeless[0] else camera.width,
                                 height=depth.shape[0] if sizeless[1] else camera.height)  # fmt: skip
        except ChunkExpands as exc:
            raise FileFormatError(self._expands(exc)) from None
        except FileFormatError as exc:
            message = str(exc)
            named = message if message.startswith(str(self.path)) else f"{self.path}: {message}"
            raise FileFormatError(named) from None
        if not self._off_centre_said:  # once per bag, as its distortion: the camera is whole only here
            self._off_centre_said = warn_principal_point(f"{self.path}: CameraInfo on {self._info.topic}", camera,
                                                         stacklevel=3)  # fmt: skip
        # stamped like the colour image: the detections are in its frame (ROS outputs copy its header)
        return named_frame(f"{self.path}@{stamp}", name, color, depth, camera, source=f"{self.path}@{stamp}",
                           stamp=_stamp(cmsg, cstamp), frame_id=header_frame_id(cmsg))  # fmt: skip

    def close(self) -> None:
        """Close the bag."""
        reader = getattr(self, "_reader", None)
        if reader is not None:
            try:
                reader.close()
            except Exception:
                pass
            self._reader = None

    def __enter__(self) -> BagSource:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
