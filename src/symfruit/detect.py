"""The per-frame job of a harvesting robot: masks -> points -> completion -> boxes.

``detect(frame)`` finds, extracts, completes and boxes the fruit of one RGB-D frame and returns them as
:class:`FrameDetections`; :mod:`symfruit.writers` turns that into files (``detections.json``, PLYs, an
overlay) and the ROS node into messages.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy import ndimage

from .core.box import Box
from .core.camera import Camera
from .core.edges import mask_shift
from .core.frame import Frame
from .core.kernels import compiled
from .core.limits import MAX_FOCAL_PX, MAX_INSTANCES, instance_labels
from .core.occlusion import Occlusion
from .core.raster import mask_box
from .core.surface import Reading, _Outline, registration_outline, registration_search, registration_window
from .errors import InputError, SymfruitError
from .extract import (
    Extraction,
    ExtractSettings,
    _checked,
    _trim_checked,
    extract,
    front_ring,
    keep_caps,
    own_surface,
    register,
    shift_labels,
    trim_labels,
    trim_mask,
    trim_window,
)
from .fruitpool import FruitPool, Running
from .io.frames import COLOR_FILE
from .methods import DEFAULT_METHOD
from .methods.complete import Result, complete
from .methods.registry import get as get_method
from .occlusion import fruit_occlusion
from .segment import MaskSource, mask_source
from .segment.colour import _leaf as leaf_green
from .segment.source import COLOUR_SEGMENTER
from .settings import Settings, section_types

__all__ = ["MAX_FRUIT_PER_FRAME", "DetectStream", "Detection", "FrameDetections", "FruitPool", "detect", "frame_masks"]

#: Most instances one frame's masks may hold (a label image with more is not a fruit mask).
MAX_FRUIT_PER_FRAME = MAX_INSTANCES


@dataclass(frozen=True)
class Detection:
    """One fruit of a frame."""

    id: int
    mask: np.ndarray
    extraction: Extraction
    result: Result | None = None
    error: str = ""
    occlusion: Occlusion | None = None

    @property
    def visible_box(self) -> Box | None:
        pts = self.extraction.points
        return Box.from_points(pts) if len(pts) else None


@dataclass(frozen=True)
class FrameDetections:
    """All fruit of one frame, with the time each stage took (seconds) and the shift ``(du, dv)`` (pixels) the
    masks were moved by onto the depth image (:func:`symfruit.extract.register`; each detection's mask is the
    moved one).

    ``timings``: wall seconds of ``segment``, ``extract`` (of which ``trim`` and ``register``, the colour trimming
    and registration of the whole frame's masks), ``complete`` (of which ``occlusion``, the occlusion maps) and
    ``total``, and ``cpu``, the CPU seconds of this thread over the whole frame (and of a
    :class:`~symfruit.fruitpool.FruitPool`'s workers on its fruit)."""

    frame: Frame
    detections: list[Detection]
    timings: dict[str, float] = field(default_factory=dict)
    mask_source: str = ""
    registration: tuple[int, int] = (0, 0)

    @property
    def camera(self) -> Camera:
        """The camera of the detections' masks, points and occlusion maps: the frame's, its principal point moved
        by :attr:`registration` (:meth:`~symfruit.core.camera.Camera.shifted`; the points are in the frame
        camera's frame). Complete a detection's points again with this one."""
        return self.frame.camera.shifted(*self.registration)


Segmenter = Callable[[Frame, Settings], np.ndarray]


def frame_masks(
    frame: Frame, masks: str | Path | MaskSource | Segmenter | np.ndarray = "auto", settings: Settings | None = None
) -> tuple[np.ndarray, str]:
    """Instance labels for a frame, and a word on where they came from.

    ``masks`` is a spec of :func:`symfruit.segment.mask_source` (``"auto"``: the frame's own masks file if it
    has one, else the colour segmenter; ``"color"``; a label PNG or COCO JSON path; ``"maskrcnn:CHECKPOINT"``;
    ``"onnx:MODEL"``), a :class:`~symfruit.segment.MaskSource` made from one, a callable
    ``(frame, settings) -> labels``, or the labels themselves: an ``(h, w)`` integer array of the frame's size
    (0 = background, k = fruit k).
    """
    settings = settings or Settings()
    shape = frame.depth.shape
    if isinstance(masks, np.ndarray):  # checked below: its size, whole numbers, how many fruit
        labels, source = masks, "label array"
    elif not isinstance(masks, str | Path | MaskSource) and not callable(masks):
        raise InputError(f"frame {frame.name}: masks must be a spec (str or path), a MaskSource, a callable or a "
                         f"label array, got {type(masks).__name__}")  # fmt: skip
    elif callable(masks) and not isinstance(masks, MaskSource):
        labels, source = np.asarray(masks(frame, settings)), getattr(masks, "__name__", "callable")
    else:
        source_of = masks if isinstance(masks, MaskSource) else mask_source(masks, settings=settings)
        # a label file must turn on reading as the frame's colour did (pixels as stored where it was no file)
        color_file = frame.extras.get(COLOR_FILE) or (f"frame {frame.name}'s colour image", 1)
        labels, source = source_of(frame.color, frame.depth, frame.camera, name=frame.name, own=frame.masks,
                                   color_file=color_file)  # fmt: skip
    if labels.ndim != 2:
        raise InputError(f"frame {frame.name}: masks must be an (h, w) label image, got shape {labels.shape}")
    if labels.shape != shape:
        raise InputError(f"frame {frame.name}: masks are {labels.shape[1]}x{labels.shape[0]}, the image "
                         f"{shape[1]}x{shape[0]}")  # fmt: skip
    # whole numbers, at most MAX_INSTANCES fruit; ids beyond 32 bits refused, never truncated into others
    return instance_labels(labels, f"frame {frame.name}: masks ({source})"), source


def _check_depth_range(frame: Frame, near: float, far: float) -> None:
    """Refuse a frame whose depth holds nothing extraction could use: no depth at all, or none within its range
    (a wrong ``depth_scale`` puts a whole frame 10 or 1000 times too far or too near)."""
    depth = frame.depth
    low = max(near, 1e-9)
    # every 97th pixel first (a usable frame has depth in range among them; stop 45: 0.07 ms a frame for the pass
    # over the whole image), the whole image when none is: the same answer either way
    sample = depth.reshape(-1)[::97] if depth.flags.c_contiguous else depth[::8, ::8]
    if ((sample >= low) & (sample <= far)).any() or ((depth >= low) & (depth <= far)).any():
        return
    if not (depth > 0).any():
        raise InputError(f"frame {frame.name}: the depth image holds no valid depth")
    median = float(np.median(depth[depth > 0]))
    raise InputError(f"frame {frame.name}: no depth within extraction's range {near:g}-{far:g} m "
                     f"(extract.min_depth, extract.max_depth; the image's median depth is {median:.3g} m): is the "
                     "frame's depth_scale right (metres per unit: 0.001 for millimetres)?")  # fmt: skip


def detect(
    frame: Frame,
    *,
    masks: str | Path | MaskSource | Segmenter | np.ndarray = "auto",
    method: str = DEFAULT_METHOD,
    settings: Settings | None = None,
    pool: FruitPool | None = None,
) -> FrameDetections:
    """Find, extract, complete and box every fruit of a frame.

    A fruit that cannot be completed (too few points, degenerate) is kept with its ``error``; the
    others are unaffected. A mask covering the whole image is refused (it is not a fruit).

    Masks from the colour segmenter (``masks`` ``"color"``, or ``"auto"`` for a frame without a masks file) are
    extracted with ``outlined=False`` (:func:`~symfruit.extract.extract`: the visible surface alone, no test for an
    occluder the mask is drawn over); every other source (a masks file or folder, a label array, a learned model,
    a callable) with ``outlined=True``.

    ``pool``: a :class:`~symfruit.fruitpool.FruitPool` the caller keeps open across frames (``with FruitPool(1) as
    pool: ...``): the frame's fruit are shared between this process and the pool's workers (issue 19, stop 53,
    docs/proc53.md). The detections are the same, bit for bit, in the same order; an error a fruit raises is the
    first failing fruit's; ``timings``' ``extract``, ``occlusion`` and ``complete`` are then the sums of each fruit's
    own wall times (more than the frame's wall time they took) and ``cpu`` counts the workers' CPU on the fruit too.
    None (the default), an inactive pool or a frame of fewer than two fruit: everything in this process. Frames
    that come one after another overlap with a pool in a :class:`DetectStream` (stop 55).
    """
    return _start(_prepare(frame, masks, method, settings, pool), pool).result()


def _prepare(
    frame: Frame, masks: str | Path | MaskSource | Segmenter | np.ndarray, method: str, settings: Settings | None,
    pool: FruitPool | None,
) -> _Prepared:  # fmt: skip
    """:func:`detect`'s first part, which needs no pool: the checks, the frame's masks and their boxes."""
    if not isinstance(frame, Frame):
        raise InputError(f"detect needs a Frame (symfruit.io.read_frame or a frame source), got {type(frame).__name__}")
    if settings is not None and not isinstance(settings, Settings):
        raise InputError(f"settings must be a Settings (symfruit.resolve_settings), got {type(settings).__name__}")
    settings = settings or _default_settings()
    get_method(method)  # an unknown method is refused before any work, not reported once per fruit
    if pool is not None and not isinstance(pool, FruitPool):
        raise InputError(f"pool must be a FruitPool (symfruit.fruitpool) or None, got {type(pool).__name__}")
    t0, cpu0 = time.perf_counter(), time.thread_time()
    _check_depth_range(frame, settings.extract.min_depth, settings.extract.max_depth)
    labels, source = frame_masks(frame, masks, settings)
    t1 = time.perf_counter()
    lo, hi = (int(labels.min()), int(labels.max())) if labels.size else (0, 0)
    if lo < 0:
        raise InputError(f"frame {frame.name}: masks hold negative labels")
    if hi > MAX_FRUIT_PER_FRAME:  # sparse ids: number them 1..k first
        values, inverse = np.unique(labels, return_inverse=True)
        count = len(values) - int(values[0] == 0)
        if count > MAX_FRUIT_PER_FRAME:
            raise InputError(f"frame {frame.name}: masks hold {count} instances; at most {MAX_FRUIT_PER_FRAME} "
                             "fruit per frame are read")  # fmt: skip
        labels = (inverse.reshape(labels.shape) + int(values[0] != 0)).astype(np.int32)
        lo, hi = int(labels.min()), int(labels.max())
    # one mask covers the whole image when every pixel holds the same label above 0: the least and greatest labels
    # tell it (a bincount of the image cost 0.3 ms a frame; issue 19, stop 41)
    if labels.size and lo == hi and lo > 0:
        raise InputError(f"frame {frame.name}: mask {lo} covers the whole image; that is not a fruit")
    # the masks' boxes, found once and carried along while the labels stay the same (a pass over the whole image
    # each); trimming only takes pixels away, so a mask's new box is looked for within its old one
    boxes = _label_boxes(labels, hi)
    if settings.extract.mask_edge_px > 0 and frame.color is not None and source != COLOUR_SEGMENTER and hi > 0:
        # masks drawn a few pixels off their fruit, all one way, moved back onto the colour's edges (stops 61 and
        # 62, docs/shift61.md, docs/edge62.md); the segmenter's masks are the colour's own
        du, dv = mask_shift(frame.color, labels, max_px=settings.extract.mask_edge_px, boxes=boxes)
        if (du, dv) != (0, 0):
            labels = shift_labels(labels, du, dv)
            boxes = _label_boxes(labels, hi)
    return _Prepared(frame, labels, hi, boxes, source, settings, method, t0, cpu0, t1, time.thread_time() - cpu0,
                     time.perf_counter())  # fmt: skip


@dataclass(frozen=True)
class _Prepared:
    """A frame :func:`_prepare` made ready: its labels (greatest ``hi``) and their boxes, where they came from, and
    when it started (``t0``, ``cpu0``), its masks were had (``t1``) and it was ready (``cpu``: its CPU seconds so
    far, ``t2``)."""

    frame: Frame
    labels: np.ndarray
    hi: int
    boxes: list[tuple[slice, slice] | None]
    source: str
    settings: Settings
    method: str
    t0: float
    cpu0: float
    t1: float
    cpu: float
    t2: float


def _start(prep: _Prepared, pool: FruitPool | None, leave: float | None = None) -> _Started:
    """:func:`detect`'s second part: trimming, registration and the fruit; with an active ``pool`` the workers'
    last fruit may still be running when it returns (:meth:`_Started.result` waits for them), and ``leave`` is
    :meth:`~symfruit.fruitpool.FruitPool.start`'s (the seconds this process will spend elsewhere before it asks)."""
    frame, labels, boxes, settings, method = prep.frame, prep.labels, prep.boxes, prep.settings, prep.method
    t2, cpu2 = time.perf_counter(), time.thread_time()  # trimming, registration and extraction start
    # a fruit's outline as drawn (a masks file, a label array, a model) may cover a leaf or branch in front that runs
    # on across it; the colour segmenter's masks are the visible surface alone, grown from the fruit's colour with
    # what lies off its depth dropped: extraction's test for such an occluder is skipped on them (0.4 ms a fruit;
    # stop 47, docs/mask47.md)
    outlined = prep.source != COLOUR_SEGMENTER
    if pool is not None and pool.active and sum(sl is not None for sl in boxes) >= 2:
        # each mask's trimming and registration outline shared with the workers too, and the fruit sent to them
        # while the search for the shift runs here (stop 54, docs/pool54.md): the same detections
        running, shift, t_trim, t_register, cpu_elsewhere = _detect_shared(
            pool, frame, labels, prep.hi, boxes, settings, method, outlined, leave
        )
        t_extract = t_trim + t_register
    else:
        # the masks colour trimmed (stop 43: one the colour could not trim is still as drawn, and its overshoot is
        # looked for in the depth, docs/treeover43.md): those the trim took pixels from, each a new box looked for
        # within its old one (another mask's trim takes none of its pixels; stop 45: not every mask compared again)
        colour_trimmed: set[int] = set()
        drawn, drawn_boxes = labels, boxes
        if frame.color is not None:  # in the colour camera's pixels, before the masks move onto the depth image
            # by the colour alone: the fruit's own cap keeps what it may after the registration (_kept_caps)
            labels, colour_trimmed = _trim_labels(frame.color, labels, settings.extract, boxes)
            boxes = [_box_within(labels, k, sl) if k in colour_trimmed else sl for k, sl in enumerate(boxes, 1)]
        t_trim = time.perf_counter() - t2
        moved, shift = register(labels, frame.depth, frame.camera, settings.extract, boxes=boxes)
        readings: dict[int, Reading] = {}  # the drawn masks' surfaces read once for both (surf65)
        front = _front_trimmed(frame, drawn, labels, colour_trimmed, drawn_boxes, boxes, shift, settings.extract,
                               readings)  # fmt: skip
        if front[0] is not labels:  # a trim done again beside something in front: the new masks moved
            labels, colour_trimmed, boxes = front
            moved = shift_labels(labels, *shift) if shift != (0, 0) else labels
        moved = _kept_caps(frame, drawn, labels, moved, colour_trimmed, drawn_boxes, shift, settings.extract, readings)
        fruit, jobs, ended = _fruit_task(frame, labels, moved, shift, prep.hi, boxes, settings, method, outlined,
                                         colour_trimmed, drawn_boxes)  # fmt: skip
        t_extract = ended - t2
        t_register, cpu_elsewhere = t_extract - t_trim, 0.0
        running = Running.ready(([fruit(k, sl) for k, sl in jobs], 0.0))
    return _Started(prep, running, shift, t_trim, t_register, t_extract, cpu_elsewhere, t2, cpu2)


class _Started:
    """A frame :func:`_start` started: :meth:`result` gives its detections (once)."""

    def __init__(self, prep: _Prepared, running: Running, shift: tuple[int, int], t_trim: float, t_register: float,
                 t_extract: float, cpu_elsewhere: float, t2: float, cpu2: float) -> None:  # fmt: skip
        self.prep, self.running, self.shift = prep, running, shift
        self.t_trim, self.t_register, self.t_extract, self.cpu_elsewhere = t_trim, t_register, t_extract, cpu_elsewhere
        # this frame's own wall and CPU seconds so far (:func:`_prepare`'s and :func:`_start`'s: a stream does
        # another frame's work between them and after)
        self.wall = time.perf_counter() - t2 + prep.t2 - prep.t0
        self.cpu = time.thread_time() - cpu2 + prep.cpu

    def result(self) -> FrameDetections:
        """The frame's detections, once the workers' last fruit came (:meth:`~symfruit.fruitpool.Running.result`:
        the first failing fruit's error raised, the workers' warnings given here)."""
        t, cpu = time.perf_counter(), time.thread_time()
        got = self.running.result()
        assert got is not None  # never called off: _detect_shared ran again what was
        done, cpu_elsewhere = got[0], self.cpu_elsewhere + got[1]
        prep = self.prep
        t_extract, t_complete, t_occlusion = self.t_extract, 0.0, 0.0
        detections = [d[0] for d in done]
        for _, ext, occl, comp, _ in done:
            t_extract, t_occlusion, t_complete = t_extract + ext, t_occlusion + occl, t_complete + comp
        total = self.wall + time.perf_counter() - t
        timings = {"segment": prep.t1 - prep.t0, "trim": self.t_trim, "register": self.t_register,
                   "extract": t_extract, "occlusion": t_occlusion, "complete": t_complete, "total": total,
                   "cpu": self.cpu + time.thread_time() - cpu + cpu_elsewhere}  # fmt: skip
        return FrameDetections(prep.frame, detections, timings, prep.source, self.shift)

    def abandon(self) -> None:
        """The frame dropped (:meth:`~symfruit.fruitpool.Running.abandon`)."""
        self.running.abandon()


def _fruit_task(
    frame: Frame, labels: np.ndarray, moved: np.ndarray, shift: tuple[int, int], hi: int,
    boxes: list[tuple[slice, slice] | None], settings: Settings, method: str, outlined: bool, colour_trimmed: set[int],
    drawn_boxes: list[tuple[slice, slice] | None] | None = None,
) -> tuple[_Fruit, list[tuple[int, tuple[slice, slice]]], float]:  # fmt: skip
    """The frame's per-fruit task and its jobs, from the trimmed ``labels`` (greatest label ``hi``, boxes ``boxes``)
    moved by ``shift`` onto the depth image (``moved``: ``labels`` itself when they did not move), and when the
    registration's part of it ended (``time.perf_counter()``: the boxes and the camera moved). ``drawn_boxes``: the
    boxes of the masks before their trimming when ``moved`` holds each mask's pixels within its drawn box moved by
    ``shift`` alone (:func:`_kept_caps`' masks: their trimmed pixels moved, and what it gives back from the drawn
    mask moved): the moved masks' boxes are looked for there (:func:`_moved_boxes`)."""
    if moved is not labels:
        boxes = _label_boxes(moved, hi) if drawn_boxes is None else _moved_boxes(moved, drawn_boxes, shift)
    # Every fruit is extracted, occluded and completed on the depth image's pixels, with the camera whose principal
    # point follows the shift: its points deproject to where the colour camera, whose frame the intrinsics are,
    # sees them (deprojected with the colour camera's own, a fruit 6 px off sat 8 mm off at 1.25 m).
    camera = frame.camera.shifted(*shift)
    ended = time.perf_counter()
    fruit = _Fruit(moved, frame.depth, frame.color, camera, settings, method, shift, outlined, moved > 0,
                   colour_trimmed)  # fmt: skip
    return fruit, [(k, sl) for k, sl in enumerate(boxes, 1) if sl is not None], ended


def _detect_shared(
    pool: FruitPool, frame: Frame, labels: np.ndarray, hi: int, boxes: list[tuple[slice, slice] | None],
    settings: Settings, method: str, outlined: bool, leave: float | None = None,
) -> tuple[Running, tuple[int, int], float, float, float]:  # fmt: skip
    """``detect``'s trimming, registration and fruit with ``pool`` (active, two masks or more): each mask's
    trimming and registration outline shared with its workers (:func:`_shared_masks`); then the fruit, moved by
    the pool's guess of the shift (the last frame's), sent to the workers while the search for this frame's shift
    runs here (:meth:`~symfruit.fruitpool.FruitPool.run_guessed`), and sent again moved by the shift found when the
    guess was wrong. The fruit's run (:meth:`~symfruit.fruitpool.FruitPool.start`, with ``leave``), the shift,
    the masks' trimming seconds and the registration's (each mask's own summed, and the search's and the move's
    here), and the workers' CPU seconds on the masks. The same answers as
    without the pool; the first failing mask's or fruit's error is raised."""
    same = object()  # this frame's depth and colour go to the workers once
    drawn_boxes = boxes
    masks = _shared_masks(pool, frame, labels, boxes, settings.extract, same)
    colour_only, colour_ids, colour_boxes, outlines, t_trim, t_outlines, cpu = masks
    a, t_search = time.perf_counter(), 0.0
    guess = found = pool.registration_guess

    def search() -> bool:
        nonlocal found, t_search
        b = time.perf_counter()
        found = registration_search(outlines, max_px=settings.extract.registration_px)
        t_search = time.perf_counter() - b
        return found == guess

    readings: dict[int, Reading] = {}  # the drawn masks' surfaces read once for both (surf65)
    trimmed, colour_trimmed, boxes = _front_trimmed(frame, labels, colour_only, colour_ids, drawn_boxes, colour_boxes,
                                                    guess, settings.extract, readings)  # fmt: skip
    moved = shift_labels(trimmed, *guess) if guess != (0, 0) else trimmed
    moved = _kept_caps(frame, labels, trimmed, moved, colour_trimmed, drawn_boxes, guess, settings.extract, readings)
    fruit, jobs, ended = _fruit_task(frame, trimmed, moved, guess, hi, boxes, settings, method, outlined,
                                     colour_trimmed, drawn_boxes)  # fmt: skip
    t_register = t_outlines + ended - a  # the move's and the search's seconds with them
    if len(jobs) >= 2:
        running = pool.start(fruit, jobs, same, search, leave=leave)  # the first failing fruit's error is raised
    else:
        running = Running.ready(([fruit(k, sl) for k, sl in jobs], 0.0) if search() else None)
    t_register += t_search
    if found != guess:  # the wrong guess (the run called off): the fruit moved by the shift found
        running.result()  # None: the workers' fruit dropped
        pool.registration_guess = found
        b = time.perf_counter()
        readings = {}
        trimmed, colour_trimmed, boxes = _front_trimmed(frame, labels, colour_only, colour_ids, drawn_boxes,
                                                        colour_boxes, found, settings.extract, readings)  # fmt: skip
        moved = shift_labels(trimmed, *found) if found != (0, 0) else trimmed
        moved = _kept_caps(frame, labels, trimmed, moved, colour_trimmed, drawn_boxes, found, settings.extract,
                           readings)  # fmt: skip
        fruit, jobs, ended = _fruit_task(frame, trimmed, moved, found, hi, boxes, settings, method, outlined,
                                         colour_trimmed, drawn_boxes)  # fmt: skip
        t_register += ended - b
        if len(jobs) >= 2:
            running = pool.start(fruit, jobs, same, leave=leave)
        else:
            running = Running.ready(([fruit(k, sl) for k, sl in jobs], 0.0))
    return running, found, t_trim, t_register, cpu


#: What one fruit's task gives back: its detection, the wall seconds of its extraction, occlusion maps and completion
#: (occlusion included), and the CPU seconds of the thread it ran on while it ran.
_Done = tuple[Detection, float, float, float, float]


class _Fruit:
    """One fruit's extraction, occlusion maps and completion, given the frame's labels and what every fruit shares
    (read, never written: a :class:`~symfruit.fruitpool.FruitPool`'s worker runs it on views of shared memory).
    ``labels``, ``depth``, ``color`` and ``fruit_px`` are the frame's arrays (:data:`ARRAYS`); the rest is small."""

    #: The attributes that are whole-image arrays (a pool sends them through shared memory, the rest pickled).
    ARRAYS = ("labels", "depth", "color", "fruit_px")

    def __init__(
        self, labels: np.ndarray, depth: np.ndarray, color: np.ndarray | None, camera: Camera, settings: Settings,
        method: str, shift: tuple[int, int], outlined: bool, fruit_px: np.ndarray, colour_trimmed: set[int],
    ) -> None:  # fmt: skip
        self.labels, self.depth, self.color, self.camera, self.settings = labels, depth, color, camera, settings
        self.method, self.shift, self.outlined, self.fruit_px = method, shift, outlined, fruit_px
        self.colour_trimmed = colour_trimmed

    def __call__(self, k: int, sl: tuple[slice, slice]) -> _Done:
        cpu0, a = time.thread_time(), time.perf_counter()
        depth, settings, camera = self.depth, self.settings, self.camera
        mask = np.zeros(self.labels.shape, bool)
        mask[sl] = self.labels[sl] == k
        ex = _extract_window(mask, sl, depth, camera, settings, color=self.color, shift=self.shift,
                             outlined=self.outlined)  # fmt: skip
        mask = ex.silhouette if ex.silhouette is not None else mask
        b = time.perf_counter()
        if ex.error:  # the mask's depth is what lies behind the fruit: reported, never completed (a box metres off)
            return Detection(int(k), mask, ex, error=ex.error), b - a, 0.0, 0.0, time.thread_time() - cpu0
        if len(ex.points) < settings.extract.min_points:
            why = (f"only {len(ex.points)} points with valid depth (extract.min_points = "
                   f"{settings.extract.min_points}); {ex.n_invalid} of {ex.mask_area} mask pixels "
                   "had no depth")  # fmt: skip
            return Detection(int(k), mask, ex, error=why), b - a, 0.0, 0.0, time.thread_time() - cpu0
        occ, t_occlusion = None, 0.0
        try:
            # the frame checked its depth's units when it was made; every fruit's pixels are the others' (this
            # fruit's own are never hidden: the same occlusion without two whole-image operations per fruit); a
            # mask trimmed by colour already lost what it overshot the fruit by (stop 42, docs/sil42.md)
            occ = fruit_occlusion(depth, mask, ex.points, camera, settings.occlusion,
                                  others=self.fruit_px, checked=True, eroded=settings.extract.erode_px,
                                  drawn=k not in self.colour_trimmed)  # fmt: skip
            t_occlusion = time.perf_counter() - b
            result = complete(ex.points, camera=camera, method=self.method, settings=settings, occlusion=occ)
            found = Detection(int(k), mask, ex, result, occlusion=occ)
        except SymfruitError as exc:
            found = Detection(int(k), mask, ex, error=str(exc), occlusion=occ)
        return found, b - a, t_occlusion, time.perf_counter() - b, time.thread_time() - cpu0

    @staticmethod
    def packed(done: _Done) -> tuple[Any, ...]:
        """A fruit's answer small to pickle (a pool's worker sends it): the detection's whole-image mask cut to its
        box (its extraction's outline is the same array or none)."""
        d, *times = done
        mask, ex = d.mask, d.extraction
        rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
        box = (int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1) if len(rows) else (0, 0, 0, 0)
        same = ex.silhouette is mask
        fields = {k: v for k, v in d.__dict__.items() if k not in ("mask", "extraction")}
        ex_fields = ex.__dict__ | ({"silhouette": None} if same else {})
        window = np.ascontiguousarray(mask[box[0] : box[1], box[2] : box[3]])
        return fields, ex_fields, mask.shape, box, window, same, tuple(times)

    @staticmethod
    def unpacked(packed: tuple[Any, ...]) -> _Done:
        """:meth:`packed`'s answer as the task gives it."""
        fields, ex_fields, shape, box, window, same, times = packed
        mask = np.zeros(shape, bool)
        mask[box[0] : box[1], box[2] : box[3]] = window
        ex = object.__new__(Extraction)
        ex.__dict__.update(ex_fields)
        if same:
            ex.__dict__["silhouette"] = mask
        d = object.__new__(Detection)
        d.__dict__.update(fields, mask=mask, extraction=ex)
        return (d, *times)


#: The pixels a mask's colour trimming drops: a window ``(r0, r1, c0, c1)`` of the image and its pixels
#: (:func:`~symfruit.extract.trim_mask`).
_Dropped = tuple[tuple[int, int, int, int], np.ndarray]

#: What one mask's task gives back (:class:`_Masks`): the window and pixels its colour trimming drops (None: none),
#: its box after it (None: no pixel left), its registration outline (None: none; an exception it raised), the wall
#: seconds of its trimming and of its outline, and the CPU seconds of the thread it ran on while it ran.
_MaskDone = tuple[_Dropped | None, tuple[slice, slice] | None,
                  "_Outline | Exception | None", float, float, float]  # fmt: skip


class _Masks:
    """One mask's colour trimming (:func:`~symfruit.extract.trim_mask`) and registration outline
    (:func:`~symfruit.core.surface.registration_outline`, on the trimmed mask), with a pool (:func:`_shared_masks`).
    Each reads its own mask, the colour and the depth alone: the masks' answers, put together in the frame's order,
    are :func:`_trim_labels`' and :func:`~symfruit.extract.register`'s, bit for bit. ``labels``, ``depth`` and
    ``color`` are the frame's (:data:`ARRAYS`), the masks as found (before any trimming)."""

    ARRAYS = ("labels", "depth", "color")

    def __init__(self, labels: np.ndarray, depth: np.ndarray, color: np.ndarray | None, settings: ExtractSettings,
                 focal: float) -> None:  # fmt: skip
        self.labels, self.depth, self.color, self.settings, self.focal = labels, depth, color, settings, focal

    def __call__(self, k: int, sl: tuple[slice, slice]) -> _MaskDone:
        cpu0, a = time.thread_time(), time.perf_counter()
        dropped, box = self._trim(k, sl)  # an error here is raised as trim_labels raises it
        b = time.perf_counter()
        outline: _Outline | Exception | None = None
        if box is not None and self.settings.registration_px > 0:
            try:  # raised after every mask's trimming, as register raises it after trim_labels
                outline = self._outline(k, box, dropped)
            except Exception as exc:
                outline = exc
        return dropped, box, outline, b - a, time.perf_counter() - b, time.thread_time() - cpu0

    def _trim(self, k: int, sl: tuple[slice, slice]) -> tuple[_Dropped | None, tuple[slice, slice] | None]:
        """Mask ``k``'s pixels its colour trimming drops (None: none) and its box after it (None: none left)."""
        if self.color is None or self.settings.colour_trim_px <= 0:
            return None, sl
        # by the colour alone, as _trim_labels: the fruit's own cap keeps what it may after the registration
        if (dropped := trim_mask(self.color, self.labels, k, sl, self.settings)) is None:
            return None, sl
        return dropped, _box_of(_without(self.labels[sl] == k, sl[0].start, sl[1].start, dropped), sl)

    def _outline(self, k: int, box: tuple[slice, slice], dropped: _Dropped | None) -> _Outline | None:
        """Mask ``k``'s registration outline (its box ``box`` and the pixels ``dropped`` after trimming)."""
        s = self.settings
        r0, r1, c0, c1 = registration_window(self.labels.shape, box, s.registration_px)
        mask = self.labels[r0:r1, c0:c1] == k
        if dropped is not None:
            _without(mask, r0, c0, dropped)
        return registration_outline(self.depth[r0:r1, c0:c1], mask, self.focal, max_px=s.registration_px,
                                    depth_range=(s.min_depth, s.max_depth), occluders=s.occluder_edges)  # fmt: skip


def _without(mask: np.ndarray, r0: int, c0: int, dropped: _Dropped) -> np.ndarray:
    """``mask`` (a window whose first pixel is the image's ``(r0, c0)``), the pixels ``dropped`` (a window of the
    image and its pixels, :func:`~symfruit.extract.trim_mask`'s) taken off where the two overlap; in place."""
    (d0, d1, e0, e1), gone = dropped
    a0, a1 = max(r0, d0), min(r0 + mask.shape[0], d1)
    b0, b1 = max(c0, e0), min(c0 + mask.shape[1], e1)
    if a0 < a1 and b0 < b1:
        mask[a0 - r0 : a1 - r0, b0 - c0 : b1 - c0] &= ~gone[a0 - d0 : a1 - d0, b0 - e0 : b1 - e0]
    return mask


def _shared_masks(
    pool: FruitPool, frame: Frame, labels: np.ndarray, boxes: list[tuple[slice, slice] | None], s: ExtractSettings,
    same: object,
) -> tuple[np.ndarray, set[int], list[tuple[slice, slice] | None], list[_Outline], float, float, float]:  # fmt: skip
    """``detect``'s trimming and the registration's outlines with each mask's part (:class:`_Masks`) shared with
    ``pool``'s workers: the trimmed labels, the colour-trimmed masks and their boxes, as :func:`_trim_labels` and
    :func:`_box_within` give them, and the masks' registration outlines in the frame's order (those
    :func:`~symfruit.extract.register` searches the shift with: :func:`~symfruit.core.surface.registration_search`);
    then the masks' trimming seconds summed, their outlines' seconds summed (with the putting together here), and
    the workers' CPU seconds. The first failing mask's error is raised (its trimming's, then its outline's), as one
    process raises it."""
    color = frame.color
    if color is not None:  # the checks trim_labels, then register make, before any mask
        color, labels, _ = _trim_checked(color, labels, s)
    _checked(labels, frame.depth, frame.camera, s, "register", "labels")
    task = _Masks(labels, frame.depth, color, s, float(np.sqrt(frame.camera.fx * frame.camera.fy)))
    jobs = [(k, sl) for k, sl in enumerate(boxes, 1) if sl is not None]
    done, cpu = pool.run(task, jobs, same)
    after = time.perf_counter()
    trimmed, colour_trimmed, boxes = labels, set(), list(boxes)
    outlines: list[_Outline] = []
    t_trim = t_outlines = 0.0
    for (k, _), (dropped, box, _, a, b, _) in zip(jobs, done, strict=True):
        if dropped is not None:
            (r0, r1, c0, c1), gone = dropped
            trimmed = trimmed.copy() if trimmed is labels else trimmed
            trimmed[r0:r1, c0:c1][gone] = 0
            colour_trimmed.add(k)
        boxes[k - 1] = box
        t_trim, t_outlines = t_trim + a, t_outlines + b
    for _, _, outline, *_ in done:
        if isinstance(outline, Exception):
            raise outline
        if outline is not None:
            outlines.append(outline)
    return trimmed, colour_trimmed, boxes, outlines, t_trim, t_outlines + time.perf_counter() - after, cpu


def _default_settings() -> Settings:
    """``Settings()``, made once while the known sections stay the same (a section registered later makes it anew):
    settings are immutable, and making them checks every section's fields (0.15 ms a frame; issue 19, stop 45)."""
    known = tuple(section_types().items())
    made = _DEFAULT.get(known)
    if made is None:
        _DEFAULT.clear()
        made = _DEFAULT[known] = Settings()
    return made


_DEFAULT: dict[tuple[tuple[str, type], ...], Settings] = {}


def _label_boxes(labels: np.ndarray, count: int) -> list[tuple[slice, slice] | None]:
    """``ndimage.find_objects(labels)`` of a label image whose greatest label is ``count`` (0 for none): each label
    1..count's box, None for one without pixels, by one compiled pass where numba is
    (:func:`symfruit.core._jit.label_boxes`: the same boxes; 0.6 against 0.17 ms on a 640x480 frame; issue 19,
    stop 45)."""
    jit = compiled()
    if jit is None or count <= 0 or labels.ndim != 2 or labels.dtype != np.int32:
        return list(ndimage.find_objects(labels))
    found = jit.label_boxes(labels, int(count)).tolist()
    return [None if r1 == 0 else (slice(r0, r1, None), slice(c0, c1, None)) for r0, r1, c0, c1 in found]


def _moved_boxes(moved: np.ndarray, drawn: list[tuple[slice, slice] | None],
                 shift: tuple[int, int]) -> list[tuple[slice, slice] | None]:  # fmt: skip
    """``ndimage.find_objects(moved)`` of labels ``moved`` (greatest label ``len(drawn)`` at most) whose every mask
    ``k`` lies within its box ``drawn[k - 1]`` (None: it has no pixels) moved by ``shift`` ``(du, dv)``: each mask's
    box looked for within that window alone (issue 19, stop 62: the moved masks' boxes without a pass over the whole
    image; the same boxes), by :func:`symfruit.core._jit.boxes_within` where numba is."""
    du, dv = shift
    h, w = moved.shape
    windows = np.zeros((len(drawn), 4), np.int64)  # (0, 0, 0, 0): no window, no pixels
    for i, sl in enumerate(drawn):
        if sl is not None:
            r0, r1 = max(sl[0].start + dv, 0), min(sl[0].stop + dv, h)
            c0, c1 = max(sl[1].start + du, 0), min(sl[1].stop + du, w)
            if r0 < r1 and c0 < c1:
                windows[i] = (r0, r1, c0, c1)
    jit = compiled()
    if jit is None or moved.ndim != 2 or moved.dtype != np.int32:
        return [None if r1 == 0 else _box_within(moved, k, (slice(r0, r1), slice(c0, c1)))
                for k, (r0, r1, c0, c1) in enumerate(windows.tolist(), 1)]  # fmt: skip
    found = jit.boxes_within(moved, windows).tolist()
    return [None if r1 == 0 else (slice(r0, r1, None), slice(c0, c1, None)) for r0, r1, c0, c1 in found]


def _trim_labels(
    color: np.ndarray, labels: np.ndarray, settings: ExtractSettings, boxes: list[tuple[slice, slice] | None]
) -> tuple[np.ndarray, set[int]]:
    """:func:`~symfruit.extract.trim_labels` by the colour alone (the same labels), and the masks it took pixels
    from."""
    trimmed: set[int] = set()
    return trim_labels(color, labels, settings, boxes=boxes, trimmed=trimmed), trimmed


def _front_trimmed(frame: Frame, drawn: np.ndarray, trimmed: np.ndarray, ids: set[int],
                   drawn_boxes: list[tuple[slice, slice] | None], boxes: list[tuple[slice, slice] | None],
                   shift: tuple[int, int], s: ExtractSettings, readings: dict[int, Reading] | None = None,
                   ) -> tuple[np.ndarray, set[int], list[tuple[slice, slice] | None]]:  # fmt: skip
    """The colour trim done again (``extract.trim_front_ring``) on each mask as drawn (``drawn``, boxes
    ``drawn_boxes``) beside which something lies in front of its fruit (:func:`~symfruit.extract.front_ring`,
    read on the depth moved back by the registration's ``shift`` onto the colour's pixels: after the registration,
    so that the depth beside a mask is the depth there, and the shift is the colour's trim's alone), its ring
    leaving that out: ``trimmed`` (the colour-trimmed labels), ``ids`` (the masks the trim took pixels from) and
    ``boxes`` (their boxes) with those masks' new trims; the same objects where none has anything in front beside
    it (issue 18, strip64). Only the masks of ``ids`` are looked at: the trim done again gives back only what the
    colour took (stripb64: on by default, a mask the colour left whole costs nothing). ``readings``: given each mask's
    surface reading (:func:`~symfruit.extract.front_ring`'s ``read``) by label, for :func:`_kept_caps` (surf65)."""
    if frame.color is None or not s.trim_front_ring or s.colour_trim_px <= 0 or not ids:
        return trimmed, ids, boxes
    du, dv = shift
    depth = shift_labels(frame.depth, -du, -dv) if (du, dv) != (0, 0) else frame.depth
    focal = float(np.sqrt(frame.camera.fx * frame.camera.fy))
    out, new_ids, new_boxes = trimmed, ids, boxes
    for k in sorted(ids):
        if (sl := drawn_boxes[k - 1]) is None:
            continue
        r0, r1, c0, c1 = trim_window(drawn.shape, sl, s)
        mask = drawn[r0:r1, c0:c1] == k
        read: list[Reading] = []
        front = front_ring(depth[r0:r1, c0:c1], mask, focal, s, read=read)
        if readings is not None and read:
            readings[k] = read[0]
        if not front.any():
            continue
        # the colour's own trim of the mask: what it kept of it (another mask's trim takes none of its pixels)
        before = out[r0:r1, c0:c1] == k
        dropped = trim_mask(frame.color, drawn, k, sl, s, focal=focal, front_depth=depth, front=front, kept=before)
        gone = np.zeros_like(mask) if dropped is None else dropped[1]
        if np.array_equal(before, mask & ~gone):
            continue
        if out is trimmed:
            out, new_ids, new_boxes = trimmed.copy(), set(ids), list(boxes)
        out[r0:r1, c0:c1][mask] = k
        out[r0:r1, c0:c1][gone] = 0
        if dropped is None:
            new_ids.discard(k)
        else:
            new_ids.add(k)
        new_boxes[k - 1] = _box_within(out, k, sl)
    return out, new_ids, new_boxes


def _kept_caps(frame: Frame, drawn: np.ndarray, trimmed: np.ndarray, moved: np.ndarray, ids: set[int],
               boxes: list[tuple[slice, slice] | None], shift: tuple[int, int],
               settings: ExtractSettings, readings: dict[int, Reading] | None = None) -> np.ndarray:  # fmt: skip
    """:func:`~symfruit.extract.keep_caps` of the frame: what a one-sided colour cut took of a fruit's own convex cap
    given back to the masks ``moved`` by ``shift`` onto the depth image (``extract.trim_keeps_surface``);
    ``readings``: :func:`_front_trimmed`'s with the same ``shift`` (surf65)."""
    if not settings.trim_keeps_surface or not ids:
        return moved
    focal = float(np.sqrt(frame.camera.fx * frame.camera.fy))
    return keep_caps(drawn, trimmed, moved, ids, boxes, shift, frame.depth, focal, settings, readings=readings)


def _box_within(labels: np.ndarray, k: int, sl: tuple[slice, slice] | None) -> tuple[slice, slice] | None:
    """``ndimage.find_objects(labels)[k - 1]`` when label ``k`` lies within ``sl`` (its box before pixels were taken
    away; None: it had none): the box of its pixels there, None when none is left."""
    return None if sl is None else _box_of(labels[sl] == k, sl)


def _box_of(mask: np.ndarray, sl: tuple[slice, slice]) -> tuple[slice, slice] | None:
    """The box (in the image) of the pixels of ``mask``, the window ``sl`` of the image; None when it has none."""
    if (box := mask_box(mask)) is None:
        return None
    r0, c0 = sl[0].start, sl[1].start
    return slice(r0 + box[0], r0 + box[1], None), slice(c0 + box[2], c0 + box[3], None)


def _leafy(color: np.ndarray, shift: tuple[int, int], window: tuple[int, int, int, int]) -> np.ndarray:
    """(r1 - r0, c1 - c0) bool: the leaf-green pixels of the colour image where the depth image's ``window`` sees
    them (depth pixel ``(u + du, v + dv)`` sees colour pixel ``(u, v)``; none beyond the colour image), worked out
    on that window alone (the leaf test is per pixel: the same as the whole image's, moved and cut)."""
    du, dv = shift
    r0, r1, c0, c1 = window
    h, w = color.shape[:2]
    out = np.zeros((r1 - r0, c1 - c0), dtype=bool)
    a0, a1 = max(r0 - dv, 0), min(r1 - dv, h)
    b0, b1 = max(c0 - du, 0), min(c1 - du, w)
    if a0 < a1 and b0 < b1:
        out[a0 + dv - r0 : a1 + dv - r0, b0 + du - c0 : b1 + du - c0] = leaf_green(color[a0:a1, b0:b1])
    return out


def _window_camera(cam: Camera, r0: int, r1: int, c0: int, c1: int) -> Camera:
    """``Camera(fx=cam.fx, fy=cam.fy, cx=cam.cx - c0, cy=cam.cy - r0, width=c1 - c0, height=r1 - r0)``, the camera of
    rows ``r0:r1`` and columns ``c0:c1`` (a window within the image) of ``cam``'s image, made without the checks a
    window of a valid camera passes but for its principal point's bound (which it may fail: the constructor then
    raises as it would): its focal lengths are the camera's, its size whole numbers within the image's. The checks
    cost 16 us a fruit (issue 19, eighteenth round)."""
    cx, cy = cam.cx - c0, cam.cy - r0
    if abs(cx) > MAX_FOCAL_PX or abs(cy) > MAX_FOCAL_PX:
        return Camera(fx=cam.fx, fy=cam.fy, cx=cx, cy=cy, width=c1 - c0, height=r1 - r0)
    local = object.__new__(Camera)
    local.__dict__.update(fx=cam.fx, fy=cam.fy, cx=cx, cy=cy, width=int(c1 - c0), height=int(r1 - r0))
    return local


def _extract_window(
    mask: np.ndarray, sl: tuple[slice, slice], depth: np.ndarray, cam: Camera, settings: Settings,
    *, color: np.ndarray | None = None, shift: tuple[int, int] = (0, 0), outlined: bool = True,
) -> Extraction:  # fmt: skip
    """:func:`extract` on the mask's bounding window (with a margin), keeping the truncation test; ``outlined`` as
    :func:`extract`'s."""
    h, w = mask.shape
    pad = settings.extract.erode_px + 2
    r0, r1 = max(sl[0].start - pad, 0), min(sl[0].stop + pad, h)
    c0, c1 = max(sl[1].start - pad, 0), min(sl[1].stop + pad, w)
    window = mask[r0:r1, c0:c1]
    local = _window_camera(cam, r0, r1, c0, c1)
    leafy = None if color is None else _leafy(color, shift, (r0, r1, c0, c1))
    ex = extract(window, depth[r0:r1, c0:c1], local, settings.extract, leafy=leafy, checked=True, outlined=outlined,
                 own=False)  # fmt: skip
    # are the points what lies behind the fruit (docs/far49.md)? Told by the depth around the mask, beyond the window
    ex = own_surface(ex, mask, depth, cam, settings.extract, box=(sl[0].start, sl[0].stop, sl[1].start, sl[1].stop),
                     window=(r0, r1, c0, c1), leafy=leafy, outlined=outlined)  # fmt: skip
    truncated = bool(sl[0].start == 0 or sl[1].start == 0 or sl[0].stop == h or sl[1].stop == w)
    # the mask's pixels all lie in the window (its box): the rest of the image is none of the outline's. Where the
    # outline is the window itself (extract keeps its mask's view), it is the mask: no image is copied (a whole
    # image per fruit; issue 19, twentieth round)
    if ex.silhouette is None or ex.silhouette is window:
        outline = mask
    else:
        outline = np.zeros_like(mask)
        outline[r0:r1, c0:c1] = ex.silhouette
    return Extraction(ex.points, ex.mask_area, ex.n_invalid, ex.n_border, ex.n_other_clusters, truncated, outline,
                      ex.error)  # fmt: skip


class DetectStream:
    """:func:`detect` on frames that come one after another (a recording, a camera's stream), with ``pool``'s
    workers kept busy across frames (issue 19, stop 55, docs/pipe55.md): a frame's first part (its checks and
    segmentation, :meth:`prepare`) runs in this process while the workers still do the fruit of the frame before.
    Each frame's detections are :func:`detect`'s, bit for bit; at most one frame is in flight::

        stream = DetectStream(pool, method="evidence")
        for frame in frames:
            ready = stream.prepare(frame)  # this frame's own errors are raised here
            found = stream.finish()  # the frame before's detections (None for the first): its errors raised here
            stream.start(ready)  # its fruit shared; the workers' last ones left running
        found = stream.finish()  # the last frame's

    The frame in flight keeps the pool busy: :meth:`finish` it (or :meth:`abandon` it, on an interrupt) before
    anything else uses the pool. Each :meth:`start` leaves the workers fruit for about as many seconds as this
    process spent last time between a :meth:`start` and the next :meth:`finish` (``symfruit detect``: writing the
    frame before's files, reading and segmenting the next; :meth:`~symfruit.fruitpool.FruitPool.start`'s
    ``leave``), and does the rest itself.
    Without a pool, or an inactive one, :meth:`start` does the whole frame (as :func:`detect`)."""

    def __init__(
        self, pool: FruitPool | None, *, masks: str | Path | MaskSource | Segmenter | np.ndarray = "auto",
        method: str = DEFAULT_METHOD, settings: Settings | None = None,
    ) -> None:  # fmt: skip
        if pool is not None and not isinstance(pool, FruitPool):
            raise InputError(f"pool must be a FruitPool (symfruit.fruitpool) or None, got {type(pool).__name__}")
        get_method(method)
        self.pool, self.masks, self.method, self.settings = pool, masks, method, settings
        self._running: _Started | None = None
        self._leave: float | None = None  # the seconds between the last start and the finish after it
        self._started_at = 0.0

    @property
    def in_flight(self) -> bool:
        """Whether a frame was started and not finished (nor abandoned)."""
        return self._running is not None

    def prepare(self, frame: Frame) -> _Prepared:
        """``frame``'s first part (checks, masks and their boxes; no pool): raises the errors :func:`detect` raises
        there. The frame in flight, if any, is left as it is."""
        return _prepare(frame, self.masks, self.method, self.settings, self.pool)

    def finish(self) -> FrameDetections | None:
        """The detections of the frame in flight (None if none is), once the workers' last fruit came: that frame's
        errors are raised here (a fruit's, a worker's warning made an error) and its workers' warnings given."""
        running, self._running = self._running, None
        if running is None:
            return None
        self._leave = time.perf_counter() - self._started_at
        return running.result()

    def start(self, ready: _Prepared) -> None:
        """Start a prepared frame: trimming, registration and this process's share of its fruit (their errors
        raised here: then nothing is in flight). The frame before must be finished (or abandoned) first."""
        if not isinstance(ready, _Prepared):  # a Frame given as it is (stop 56: an AttributeError from _start)
            given = "None" if ready is None else type(ready).__name__
            raise InputError(f"DetectStream.start takes what DetectStream.prepare returned (a prepared frame), got "
                             f"{given}")  # fmt: skip
        if self._running is not None:
            raise RuntimeError("DetectStream.start: the frame before is still in flight (finish it first)")
        self._running = _start(ready, self.pool, self._leave)
        self._started_at = time.perf_counter()

    def abandon(self) -> None:
        """Drop the frame in flight (the workers ended, new ones started, as after an interrupt within a frame)."""
        running, self._running = self._running, None
        if running is not None:
            running.abandon()
