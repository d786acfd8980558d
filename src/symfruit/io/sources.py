"""Frame sources: recordings read one frame at a time.

A source is anything that follows :class:`FrameSource`: it knows how many frames it has and their names
without decoding any, and decodes one frame when asked (:meth:`FrameSource.read`). A frame that cannot be
read raises a :class:`~symfruit.errors.SymfruitError` for that index only, so a batch records it and goes
on; decisions such as "already done, skip" are taken from the names, before anything is decoded. Memory
therefore does not grow with the length of a recording.

Sources are found through one registry (:func:`register_source`), tried in order:

==========  =====================================================================================
name        recognises
==========  =====================================================================================
bag         a ROS 1 ``.bag`` file or a ROS 2 bag folder (``metadata.yaml``) (:mod:`.bags`); a RealSense
            Viewer / ``rs.recorder`` ``.bag`` (``/device_0/...`` topics) is aligned by :mod:`.realsense`
frame       one frame folder (:mod:`.frames`)
folder      a folder of frame folders, in name order (hidden folders, ROS 2 bags and ``exclude`` skipped)
==========  =====================================================================================
"""

from __future__ import annotations

import errno
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol, runtime_checkable

from ..core.frame import Frame
from ..errors import FileFormatError
from .frames import is_frame_folder, read_frame, unreadable_folder
from .outputs import LOCK_NAME
from .text import as_path

__all__ = ["FolderSource", "FrameFolderSource", "FrameSource", "open_source", "register_source", "source_kinds"]


@runtime_checkable
class FrameSource(Protocol):
    """The contract of a recording."""

    path: Path

    def __len__(self) -> int:
        """Number of frames."""
        ...

    def names(self) -> list[str]:
        """Frame names, in order, known without decoding any frame."""
        ...

    def read(self, index: int) -> Frame:
        """Decode frame ``index``; raises :class:`~symfruit.errors.SymfruitError` for this frame only."""
        ...

    def close(self) -> None:
        """Release open files."""
        ...


class _Closing:
    path: Path

    def close(self) -> None:
        """Nothing to release."""

    def __enter__(self) -> _Closing:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class FrameFolderSource(_Closing):
    """One frame folder as a one-frame recording."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def __len__(self) -> int:
        return 1

    def names(self) -> list[str]:
        return [self.path.name]

    def read(self, index: int) -> Frame:
        _check_index(index, 1)
        return read_frame(self.path)


class FolderSource(_Closing):
    """A folder of frame folders (sub-folders in name order; hidden ones and ``exclude`` skipped)."""

    def __init__(self, path: Path, *, exclude: Sequence[Path] = ()) -> None:
        self.path = path
        skip = {p.resolve() for p in exclude}
        self._folders = sorted(
            p
            for p in path.iterdir()
            if p.is_dir()
            and not p.name.startswith(".")
            and p.resolve() not in skip
            and (unreadable_folder(p) or not (_is_bag_output(p) or _is_run_output(p)))
        )  # one this user may not open is a frame folder, refused by name when read (not pathlib's PermissionError)

    def __len__(self) -> int:
        return len(self._folders)

    def names(self) -> list[str]:
        return [p.name for p in self._folders]

    def folders(self) -> list[Path]:
        """The frame folders, in order (a batch writes nothing into them)."""
        return list(self._folders)

    def read(self, index: int) -> Frame:
        _check_index(index, len(self._folders))
        folder = self._folders[index]
        if folder.is_symlink():
            here, there = self.path.resolve(), folder.resolve()
            if there == here or there in here.parents:  # read as a frame: "no color.png or color.jpg"
                which = "the recording folder" if there == here else f"{there}, which holds the recording"
                raise FileFormatError(f"{folder}: a link back to {which}, not a frame folder")
        return read_frame(folder)


def _check_index(index: int, n: int) -> None:
    if not 0 <= index < n:
        raise IndexError(f"frame index {index} out of range for {n} frames")


@dataclass(frozen=True)
class _Kind:
    name: str
    probe: Callable[[Path], bool]
    open: Callable[[Path, Sequence[Path]], FrameSource]


_KINDS: list[_Kind] = []


def register_source(
    name: str, probe: Callable[[Path], bool], opener: Callable[[Path, Sequence[Path]], FrameSource]
) -> None:
    """Add a kind of recording: ``probe(path)`` says whether it is one, ``opener(path, exclude)`` opens it.

    Kinds are tried in registration order; the built-in ones are ``bag``, ``frame`` and ``folder``.
    """
    if any(k.name == name for k in _KINDS):
        raise ValueError(f"frame source {name!r} is already registered")
    _KINDS.append(_Kind(name, probe, opener))


def source_kinds() -> list[str]:
    """Names of the registered kinds, in the order they are tried."""
    return [k.name for k in _KINDS]


def open_source(path: str | Path, *, exclude: Sequence[Path] = ()) -> FrameSource:
    """Open a recording: a bag, a frame folder or a folder of frame folders.

    ``exclude`` lists folders that are not frames even if they sit inside (e.g. the output folder).

    Raises
    ------
    FileFormatError
        When ``path`` is none of the registered kinds.
    """
    path = as_path(path, "open_source: the recording")
    if unreadable_folder(path):  # probing what it holds was pathlib's PermissionError (stop 52, robust52)
        raise FileFormatError(f"{path}: cannot read folder ({os.strerror(errno.EACCES)}: this user may not list it "
                              "or open what it holds)")  # fmt: skip
    for kind in _KINDS:
        if kind.probe(path):
            return kind.open(path, exclude)
    if not path.exists():
        raise FileFormatError(f"{path}: no such frame folder, folder of frames or bag")
    raise FileFormatError(f"{path}: neither a frame folder (color.png, depth.png, camera.json), a folder of them, "
                          "nor a bag")  # fmt: skip


def _is_bag(path: Path) -> bool:
    return (path.suffix.lower() == ".bag" and path.is_file()) or (path.is_dir() and (path / "metadata.yaml").is_file())


def _open_bag(path: Path, exclude: Sequence[Path]) -> FrameSource:
    from .bags import BagSource
    from .realsense import RealSenseBagSource, is_realsense

    if path.is_file() and path.suffix != ".bag":  # was "neither a frame folder ..., nor a bag"
        raise FileFormatError(f"{path}: a bag named {path.suffix!r}: the bag reader (rosbags) opens only names "
                              f"ending in '.bag'; rename it {path.stem}.bag")  # fmt: skip
    if path.suffix == ".bag" and is_realsense(path):
        return RealSenseBagSource(path)
    return BagSource(path)


def _is_folder(path: Path) -> bool:
    return path.is_dir() and any(p.is_dir() and not p.name.startswith(".") for p in path.iterdir())


def _is_bag_output(folder: Path) -> bool:
    """A ROS 2 bag folder (``metadata.yaml``, no colour image) inside a recording of frame folders, e.g. the
    ``--ros2-bag`` an earlier run wrote there: not a frame (a frame folder missing its files still is one)."""
    return (folder / "metadata.yaml").is_file() and not is_frame_folder(folder)


#: Files a ``detect`` run writes at the top of its output folder (:mod:`symfruit.batch`), and the summary every
#: ``evaluate`` results folder holds (:func:`symfruit.writers.new_results_folder`), never in a frame folder.
RUN_FILES = ("errors.json", "detections.parquet", "frames.parquet", LOCK_NAME, "summary.json")


def _is_run_output(folder: Path) -> bool:
    """An earlier ``detect`` run's output folder inside a recording of frame folders (``--output rec/out``, then
    ``--output rec/out2``), or an ``evaluate`` results folder there (``evaluate --frames rec --output rec``, and
    its ``latest`` link): not a frame (it was counted as one that failed, 'no color.png or color.jpg')."""
    return any((folder / name).is_file() for name in RUN_FILES) and not is_frame_folder(folder)


register_source("bag", _is_bag, _open_bag)
register_source("frame", is_frame_folder, lambda path, exclude: FrameFolderSource(path))
register_source("folder", _is_folder, lambda path, exclude: FolderSource(path, exclude=exclude))
