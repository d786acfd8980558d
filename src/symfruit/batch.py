"""Batches: ``detect`` over a recording (a frame folder, a folder of frames or a bag), and ``segment`` over
images (:func:`segment_images`), without losing anything.

Frames are decoded one at a time (:mod:`symfruit.io.sources`), so memory stays flat however long the
recording. Every frame gets its own output folder; a frame that fails, for whatever reason, is recorded in
``errors.json`` with its reason and the batch goes on. A full disk stops the batch cleanly (what was
written stays whole, the frame is reported). Files are written atomically and ``detections.json`` last,
so with ``resume=True`` a re-run skips exactly the frames already done, deciding before it decodes them.
"""

from __future__ import annotations

import errno
import hashlib
import re
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from .detect import FrameDetections, detect
from .errors import FileFormatError, InputError, SymfruitError
from .io.atomic import write_json
from .io.sources import open_source
from .methods import DEFAULT_METHOD
from .progress import Progress
from .segment import MaskSource, mask_source
from .settings import Settings
from .writers import write_detections

__all__ = [
    "BatchReport",
    "SegmentReport",
    "SegmentedImage",
    "expand_images",
    "frame_folder_name",
    "run_batch",
    "segment_images",
]

#: Errors that mean the output cannot take more data: the batch stops instead of failing every frame.
_NO_SPACE = {errno.ENOSPC, errno.EFBIG, errno.EDQUOT}


def frame_folder_name(name: str) -> str:
    """The output folder name of a frame: ``name`` itself when it is a safe file name (letters, digits,
    ``._-``), else a sanitised name, ``+`` and a short hash of the original. A safe name never holds ``+``,
    so no two names share a folder however the recording grows."""
    clean = re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._")[:100]
    if clean == name and name:
        return name
    digest = hashlib.sha1(name.encode("utf-8", "surrogateescape")).hexdigest()[:8]
    return f"{clean or 'frame'}+{digest}"


@dataclass
class BatchReport:
    """What a batch did: frames done, skipped (resume), failed (with reasons), fruit found; ``stopped`` says
    why the batch ended early (a full disk), empty when it ran to the end."""

    done: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)
    fruits: int = 0
    failed_fruits: int = 0
    stopped: str = ""

    @property
    def ok(self) -> bool:
        return not self.failed and not self.stopped


def run_batch(
    source: str | Path,
    output: str | Path,
    *,
    masks: str = "auto",
    method: str = DEFAULT_METHOD,
    settings: Settings | None = None,
    resume: bool = False,
    progress: bool = True,
    on_frame: Callable[[int, FrameDetections], None] | None = None,
) -> BatchReport:
    """Detect fruit in every frame of ``source`` and write each frame's results under ``output``.

    ``on_frame(index, found)`` is called with each frame's detections (``index``: its place in the source)
    inside the frame's error boundary, just before its files are written, so ``detections.json`` still marks
    a frame whose every step succeeded; e.g. to append it to a ROS 2 bag
    (:meth:`symfruit.ros.bag2.Ros2DetectionBag.write_frame`). Frames skipped by ``resume`` are not passed.

    Raises
    ------
    SymfruitError
        Only when the source itself cannot be opened; per-frame problems go into the report.
    """
    settings = settings or Settings()
    output = Path(output)
    report = BatchReport()
    src = open_source(source, exclude=[output])
    try:
        output.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        src.close()
        raise FileFormatError(f"{output}: cannot write to folder ({exc.strerror or exc})") from None
    for stale in output.glob(".*.tmp"):  # a killed run's half-written errors.json
        stale.unlink(missing_ok=True)
    try:
        names = src.names()
        with Progress(len(names), "detect", enabled=progress and len(names) > 1) as bar:
            for index, name in enumerate(names):
                folder = output / frame_folder_name(name)
                if resume and (folder / "detections.json").is_file():
                    report.skipped.append(name)
                    bar.update()
                    continue

                def one_frame(index: int = index, folder: Path = folder) -> FrameDetections:
                    found = detect(src.read(index), masks=masks, method=method, settings=settings)
                    if on_frame is not None:
                        on_frame(index, found)
                    write_detections(folder, found, settings=settings)
                    return found

                done, found, report.stopped = _guarded(one_frame, item=name, failed=report.failed, target=folder,
                                                       at=f"frame {name}")  # fmt: skip
                if report.stopped:
                    break
                if done and found is not None:
                    report.done.append(name)
                    report.fruits += sum(d.result is not None for d in found.detections)
                    report.failed_fruits += sum(d.result is None for d in found.detections)
                bar.update()
    finally:
        src.close()
    errors = {"failed": [{"frame": k, "reason": v} for k, v in report.failed.items()], "stopped": report.stopped}
    try:
        write_json(output / "errors.json", errors)
    except (SymfruitError, OSError) as exc:
        report.stopped = report.stopped or f"cannot write {output / 'errors.json'} ({exc})"
    return report


#: Image file suffixes taken from a folder by :func:`segment_images`.
IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png", ".bmp", ".tif", ".tiff", ".webp")

#: A mask source as :func:`segment_images` calls it: ``(color, depth=, camera=) -> (h, w) int labels``.
Masker = Callable[..., np.ndarray]


@dataclass(frozen=True)
class SegmentedImage:
    """One image :func:`segment_images` segmented: fruit found, whether depth rules ran (False: colour
    alone), the segmentation time (milliseconds) and the files written."""

    path: Path
    fruit: int
    used_depth: bool
    ms: float
    written: tuple[Path, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        return {"image": str(self.path), "fruit": self.fruit, "depth": self.used_depth, "ms": round(self.ms, 3),
                "written": [str(p) for p in self.written]}  # fmt: skip


@dataclass
class SegmentReport:
    """What :func:`segment_images` did: the images done, the ones that failed (with reasons), and why it
    stopped early (a full disk), empty when it ran to the end."""

    done: list[SegmentedImage] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)
    stopped: str = ""
    mask_source: str = ""

    @property
    def ok(self) -> bool:
        return not self.failed and not self.stopped

    @property
    def fruit(self) -> int:
        return sum(d.fruit for d in self.done)


def expand_images(paths: Sequence[str | Path]) -> list[Path]:
    """Image files from files and folders (a folder's images in name order, not recursive).

    Raises
    ------
    FileFormatError
        For a path that does not exist, or when no image is found.
    """
    out: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            out += sorted(q for q in p.iterdir() if q.is_file() and q.suffix.lower() in IMAGE_SUFFIXES)
        elif p.is_file():
            out.append(p)
        else:
            raise FileFormatError(f"{p}: no such image or folder")
    if not out:
        raise FileFormatError("no images found in " + ", ".join(str(p) for p in paths))
    return out


def _read_depth(path: Path, scale: float, shape: tuple[int, int]) -> np.ndarray:
    """Depth in metres from ``.npy`` (metres) or a 16-bit PNG (``scale`` metres per unit), of ``shape``."""
    from .io.frames import read_depth_npy
    from .io.images import read_depth_units

    if path.suffix.lower() == ".npy":
        depth = read_depth_npy(path).astype(np.float64)  # sizes checked from the header; never unpickled
    else:
        depth = read_depth_units(path).astype(np.float64) * scale
    if depth.shape != shape:
        raise FileFormatError(f"{path}: depth is {depth.shape[1]}x{depth.shape[0]}, the image {shape[1]}x{shape[0]}")
    return depth


def _depth_file(image: Path, depth: Path | None, n_images: int) -> Path | None:
    if depth is None:
        return None
    if depth.is_dir():
        for name in (image.stem, image.stem + "_depth"):
            for suffix in (".png", ".npy"):
                if (depth / (name + suffix)).is_file():
                    return depth / (name + suffix)
        return None
    if n_images != 1:
        raise InputError(f"--depth {depth} is one file but there are {n_images} images: give a folder of depth images")
    return depth


def _labeller(
    masks: str | Path | MaskSource | Masker, settings: Settings | None, images: Sequence[Path]
) -> tuple[Callable[[Path, np.ndarray, np.ndarray | None, Any], np.ndarray], str]:
    """What :func:`segment_images` runs on each image ``(path, color, depth, camera) -> labels``, and a word on
    it: a callable ``(color, depth=, camera=) -> labels`` as it is, anything else through
    :func:`symfruit.segment.mask_source` (checked here, before any image)."""
    if callable(masks) and not isinstance(masks, MaskSource):
        fn = masks
        return (lambda path, color, depth, camera: np.asarray(fn(color, depth=depth, camera=camera))), getattr(
            masks, "__name__", "callable"
        )
    source = masks if isinstance(masks, MaskSource) else mask_source(masks, settings=settings, images=images)
    return (lambda path, color, depth, camera: source(color, depth, camera, name=path.name)[0]), source.name


T = TypeVar("T")


def _guarded(
    work: Callable[[], T], *, item: str, failed: dict[str, str], target: Path, at: str
) -> tuple[bool, T | None, str]:
    """One item of a batch inside its error boundary: ``(done, result, stop)``.

    A :class:`~symfruit.errors.SymfruitError`, an ``OSError`` or any other exception is recorded in
    ``failed[item]`` and the batch goes on; a full disk (``ENOSPC``, ``EFBIG``, ``EDQUOT``) while writing
    ``target`` also returns ``stop``, the reason to stop the batch (``at``: where, e.g. ``frame 0007``).
    """
    try:
        return True, work(), ""
    except SymfruitError as exc:
        failed[item] = str(exc)
    except OSError as exc:
        if exc.errno in _NO_SPACE:
            failed[item] = f"cannot write {target}: {exc.strerror}"
            return False, None, f"stopped at {at}: the output is full ({exc.strerror})"
        failed[item] = f"{type(exc).__name__}: {exc}"
    except Exception as exc:  # the per-item error boundary: record anything and go on
        failed[item] = f"{type(exc).__name__}: {exc}"
    return False, None, ""


def segment_images(
    paths: Sequence[str | Path],
    *,
    output: str | Path,
    masks: str | Path | MaskSource | Masker = "color",
    depth: str | Path | None = None,
    camera: Any = None,
    depth_scale: float = 0.001,
    settings: Settings | None = None,
    progress: bool = False,
) -> SegmentReport:
    """Instance masks for images (files or folders): ``<stem>.png`` (16-bit labels, 0 background, 1..k
    fruit) and ``<stem>_overlay.png`` per image under ``output``, and ``segment.json`` (every image's
    result and every failure).

    Parameters
    ----------
    paths : image files or folders
    output : folder
    masks : a spec of :func:`symfruit.segment.mask_source`, a :class:`~symfruit.segment.MaskSource`, or a callable
        ``(color, depth=, camera=) -> labels``
    depth : file or folder, optional
        Depth for the images (a folder: ``<stem>.png`` / ``<stem>.npy`` / ``<stem>_depth.*``); 16-bit PNG
        depth is ``depth_scale`` metres per unit, ``.npy`` is metres. Images without depth are segmented
        on colour alone (``used_depth`` False: no depth split, the size rule a share of the image).
    camera : Camera-like (``fx``, ``fy``; ``cx``, ``cy``), needed with ``depth``
    settings : Settings, optional
    progress : bool

    Each image has its own error boundary, as in :func:`run_batch`: an image that cannot be read or
    segmented is reported in ``failed`` and the batch goes on; a full disk stops it cleanly.

    Raises
    ------
    SymfruitError
        Only for the batch as a whole: no images, depth without a camera, an unusable mask source or
        output folder.
    """
    from .io.images import read_color
    from .writers import write_label_overlay, write_labels

    images = expand_images(paths)
    depth_path = Path(depth) if depth is not None else None
    if depth_path is not None:
        if camera is None:
            raise InputError("segment: depth needs a camera (--camera: fx, fy) to turn metres into pixels")
        if not depth_path.exists():
            raise FileFormatError(f"{depth_path}: no such depth image or folder")
    if not (np.isfinite(depth_scale) and 0 < depth_scale <= 1.0):
        raise InputError(f"depth_scale must be in (0, 1] metres per unit, got {depth_scale}")
    labeller, source = _labeller(masks, settings, images)
    output = Path(output)
    try:
        output.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise FileFormatError(f"{output}: cannot write to folder ({exc.strerror or exc})") from None
    report = SegmentReport(mask_source=source)
    stems: dict[str, int] = {}
    with Progress(len(images), "segment", enabled=progress and len(images) > 1) as bar:
        for path in images:
            stem = frame_folder_name(path.stem)
            if stem in stems:  # two images of one name in different folders: both are kept
                stems[stem] += 1
                stem = f"{stem}-{stems[stem]}"
            stems.setdefault(stem, 1)

            def one_image(path: Path = path, stem: str = stem) -> SegmentedImage:
                color = read_color(path)
                dfile = _depth_file(path, depth_path, len(images))
                z = _read_depth(dfile, depth_scale, color.shape[:2]) if dfile is not None else None
                t0 = time.perf_counter()
                labels = np.asarray(labeller(path, color, z, camera if z is not None else None))
                ms = (time.perf_counter() - t0) * 1000.0
                if labels.shape != color.shape[:2] or not np.issubdtype(labels.dtype, np.integer):
                    raise InputError(f"{path.name}: the mask source gave labels {labels.dtype} {labels.shape}, "
                                     f"the image is {color.shape[1]}x{color.shape[0]}")  # fmt: skip
                written = (write_labels(output / f"{stem}.png", labels),
                           write_label_overlay(output / f"{stem}_overlay.png", color, labels))  # fmt: skip
                used = z is not None and bool((z > 0).any())
                return SegmentedImage(path, len(np.unique(labels[labels > 0])), used, ms, written)

            done, image, report.stopped = _guarded(one_image, item=str(path), failed=report.failed, target=output,
                                                   at=path.name)  # fmt: skip
            if report.stopped:
                break
            if done and image is not None:
                report.done.append(image)
            bar.update()
    record = {
        "mask_source": source,
        "images": [d.to_dict() for d in report.done],
        "failed": [{"image": k, "reason": v} for k, v in report.failed.items()],
        "stopped": report.stopped,
    }
    try:
        write_json(output / "segment.json", record)
    except (SymfruitError, OSError) as exc:
        report.stopped = report.stopped or f"cannot write {output / 'segment.json'} ({exc})"
    return report
