"""The ROS-agnostic core of the symfruit node: camera messages in, located fruit out. No ROS import.

Everything here works on any object with the fields of ``sensor_msgs/Image`` and ``sensor_msgs/CameraInfo``
(rospy, rclpy and rosbags messages alike: ``K`` or ``k``, ``secs``/``nsecs`` or ``sec``/``nanosec``), so the
ROS 1 wrapper (:mod:`symfruit.ros.node`), a ROS 2 (rclpy) wrapper and the bag writer share it:

- :class:`FrameProcessor`: settings resolved once (:func:`symfruit.settings.resolve_settings`, as every
  command does), then ``process(color, depth, info)`` -> :class:`Processed`. The messages are decoded by
  :mod:`symfruit.io.bags` (the one decoder of ``sensor_msgs/Image``, shared with bag recordings) into a
  :class:`~symfruit.core.frame.Frame` stamped with the colour image's header, then :func:`~symfruit.detect.detect`;
- :func:`fruits_of`: the located fruit of a :class:`~symfruit.detect.FrameDetections`, built as
  :func:`~symfruit.writers.detections_record` builds ``detections.json`` (its ``bbox_record``), so every ROS
  message carries exactly ``detections.json``'s centres, sizes and confidences;
- :class:`LatestOnly`: a worker thread with a one-slot buffer, so a slow frame drops the frames that
  arrived meanwhile instead of queueing them.
"""

from __future__ import annotations

import contextlib
import signal
import threading
import time
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..core.frame import Frame
from ..core.limits import shown
from ..detect import DetectStream, FrameDetections, detect
from ..errors import InputError, SymfruitError
from ..fruitpool import MAX_FRUIT_PROCESSES, FruitPool
from ..io.bags import camera_from_info, color_image, depth_image, header_frame_id, header_stamp
from ..io.images import MIN_16BIT_DEPTH_REACH
from ..methods import DEFAULT_METHOD
from ..methods import get as get_method
from ..segment import mask_source
from ..settings import resolve_settings
from ..writers import bbox_record

__all__ = [
    "PARAMETERS",
    "QOS_CHOICES",
    "FrameProcessor",
    "Fruit",
    "LatestOnly",
    "Processed",
    "checked_parameters",
    "fruits_of",
    "message_frame",
    "stop_signals",
]


# ---------------------------------------------------------------------------------------------------
# parameters (both nodes)
# ---------------------------------------------------------------------------------------------------

#: name: (default, description); every parameter is read once, at start.
PARAMETERS: dict[str, tuple[Any, str]] = {
    "method": (DEFAULT_METHOD, "completion method (symfruit methods)"),
    "fruit": ("strawberry", "fruit profile name or profile file; also each detection's class_id"),
    "config": ("", "settings file (YAML/JSON) over the profile; empty for none"),
    "masks": ("auto", "mask source as symfruit detect --masks"),
    "depth_scale": (0.001, "metres per unit of 16UC1 depth images"),
    "slop": (0.05, "largest stamp difference of a synchronised colour, depth and camera info, seconds"),
    "queue_size": (5, "messages kept per input topic for the synchroniser"),
    "qos": ("reliable", "input QoS: reliable (as the RealSense wrapper publishes) or sensor_data (best effort)"),
    "fruit_processes": (
        1,
        "worker processes kept to share each frame's fruit with (0-16; 0: none; none either with fewer than two cores)",
    ),
}
QOS_CHOICES = ("reliable", "sensor_data")


#: Parameters ROS itself gives every node (never refused as unknown): ROS 2's ``use_sim_time``, its QoS overrides.
ROS_OWN_PARAMETERS = ("use_sim_time", "qos_overrides.", "start_type_description_service")


def unknown_parameters(names: Any, *, known: Any = PARAMETERS) -> None:
    """Refuse a parameter given to the node that it does not have (``_metod:=paper``, ``-p slop_s:=0.1``): it was
    ignored in silence, the default used. ``names`` are the node's given parameter names (private, without the
    node's namespace).

    Raises
    ------
    SymfruitError
        One line naming the first unknown parameter, the closest known one and the known ones.
    """
    import difflib

    for name in sorted(str(n) for n in names):
        if name in known or any(name == own or (own.endswith(".") and name.startswith(own))
                                for own in ROS_OWN_PARAMETERS):  # fmt: skip
            continue
        close = difflib.get_close_matches(name.lower(), list(known), n=1, cutoff=0.6)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise SymfruitError(f"parameter {shown(name)}: no such parameter{hint}; the node's are {', '.join(known)}")


def checked_parameters(values: dict[str, Any]) -> dict[str, Any]:
    """The node's parameters from what ROS handed over (any types): strings as strings, numbers checked; the
    one check of the ROS 2 node's parameters and the ROS 1 node's private ones (which have no ``qos``).

    Raises
    ------
    SymfruitError
        One line naming the parameter, for a number that is not one or is out of range (``depth_scale`` (0, 1] metres
        per unit, ``slop`` 0-10 s, ``queue_size`` 1-100, ``fruit_processes`` 0-16), or an unknown ``qos``.
    """
    out: dict[str, Any] = {}
    for name, (default, _) in PARAMETERS.items():
        value = values.get(name, default)
        if isinstance(default, str):  # text; a number as its text (rosparam types `_fruit:=123`), nothing else
            if value is not None and (isinstance(value, bool) or not isinstance(value, str | int | float)):
                hint = " (quote it: a YAML yes/no/true is a boolean)" if isinstance(value, bool) else ""
                raise SymfruitError(f"parameter {name}: expected text, got {shown(value)}{hint}")
            out[name] = "" if value is None else str(value)
            continue
        kind = int if isinstance(default, int) else float
        try:
            if isinstance(value, bool) or (kind is int and isinstance(value, float) and not value.is_integer()):
                raise ValueError
            out[name] = kind(value)
        except (TypeError, ValueError, OverflowError):  # OverflowError: int() of an infinite float
            what = "whole number" if kind is int else "number"
            raise SymfruitError(f"parameter {name}: expected a {what}, got {shown(value)}") from None
    if not 0 < out["depth_scale"] <= 1:  # as a frame's camera.json: 0, negative or NaN would give no frame depth
        scale = shown(out["depth_scale"])
        raise SymfruitError(f"parameter depth_scale: expected metres per unit in (0, 1], got {scale}")
    if 65535 * out["depth_scale"] < MIN_16BIT_DEPTH_REACH:  # 1e-300: float32 0, every frame without depth, unsaid
        scale = out["depth_scale"]
        raise SymfruitError(f"parameter depth_scale: {scale:g} m per unit; 16-bit depth would reach only "
                            f"{65535 * scale:.3g} m, and no camera measures depth that finely")  # fmt: skip
    if not 0 <= out["slop"] <= 10:
        raise SymfruitError(f"parameter slop: expected seconds in [0, 10], got {shown(out['slop'])}")
    if not 1 <= out["queue_size"] <= 100:
        raise SymfruitError(f"parameter queue_size: expected 1 to 100, got {shown(out['queue_size'])}")
    if not 0 <= out["fruit_processes"] <= MAX_FRUIT_PROCESSES:
        raise SymfruitError(f"parameter fruit_processes: expected 0 to {MAX_FRUIT_PROCESSES}, got "
                            f"{shown(out['fruit_processes'])}")  # fmt: skip
    if out["qos"] not in QOS_CHOICES:
        raise SymfruitError(f"parameter qos: expected one of {', '.join(QOS_CHOICES)}, got {shown(out['qos'])}")
    return out


# ---------------------------------------------------------------------------------------------------
# frames in, fruit out
# ---------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Fruit:
    """One located fruit as a ROS message needs it: an entry of ``detections.json`` plus its cloud.

    Attributes
    ----------
    id : int
        The fruit's id in ``detections.json`` (its mask label).
    centre, size : (3,) float, metres
        Centre and extent of the completed fruit's axis-aligned box (``bbox`` of ``detections.json``),
        camera optical frame.
    score : float
        ``confidence`` of ``detections.json`` in [0, 1] (``fused``); NaN for methods that give none.
    points : (m, 3) float, metres
        Visible then completed points.
    n_visible : int
        How many of ``points`` were seen.
    """

    id: int
    centre: np.ndarray
    size: np.ndarray
    score: float
    points: np.ndarray
    n_visible: int


def fruits_of(found: FrameDetections) -> list[Fruit]:
    """The completed fruit of ``found`` as ``detections.json`` lists them (failed fruit left out): ``bbox``
    from :func:`~symfruit.writers.bbox_record`, the function that writes it there, ``score`` its
    ``confidence``."""
    out = []
    for d in found.detections:
        r = d.result
        if d.error or r is None:  # an entry with "error" in detections.json
            continue
        bbox = bbox_record(r.box)
        conf = r.confidence
        out.append(
            Fruit(
                id=int(d.id),
                centre=np.array([bbox["center"]["position"][k] for k in "xyz"], dtype=np.float64),
                size=np.array([bbox["size"][k] for k in "xyz"], dtype=np.float64),
                score=float(conf) if conf is not None and np.isfinite(conf) else float("nan"),
                points=r.points,
                n_visible=len(r.visible),
            )
        )
    return out


def message_frame(
    color: Any,
    depth: Any,
    info: Any,
    *,
    depth_scale: float = 0.001,
    name: str = "frame",
    source: str = "ros",
    warn: bool = True,
    warned: set[str] | None = None,
) -> Frame:
    """A :class:`~symfruit.core.frame.Frame` of a colour image, the depth image aligned to it and the colour
    camera's info; stamped with the colour header (``stamp``, ``frame_id``). Non-zero distortion in the camera
    info is not applied: with ``warn``, a :class:`~symfruit.errors.SymfruitWarning` says so, as of a principal
    point outside the image (:func:`~symfruit.io.bags.camera_from_info`; ``warned``: the kinds already said).

    Raises
    ------
    SymfruitError
        (``FileFormatError``, ``InputError``) for an unknown encoding, truncated data, invalid intrinsics,
        or sizes that disagree.
    """
    with _named("colour image"):
        rgb = color_image(color)
    with _named("depth image"):
        metres = depth_image(depth, depth_scale=depth_scale)
    h, w = metres.shape
    with _named("CameraInfo"):
        camera = camera_from_info(info, width=w, height=h, source=f"{source}: CameraInfo" if warn else None,
                                  warned=warned)  # fmt: skip
    return Frame(name, rgb, metres, camera, source=source, stamp=header_stamp(color), frame_id=header_frame_id(color))


@contextlib.contextmanager
def _named(what: str) -> Iterator[None]:
    """Errors of one message said with the message they are about (``colour image: image data holds ...``): the
    node's log line for a skipped frame tells which topic to look at."""
    try:
        yield
    except SymfruitError as exc:
        text = str(exc)
        if text.startswith(what):
            raise
        raise type(exc)(f"{what}: {text}") from None


@dataclass(frozen=True)
class Processed:
    """The outcome of one frame: the fruit, everything detect found, and how long each part took (s)."""

    fruits: list[Fruit]
    found: FrameDetections
    seconds: dict[str, float] = field(default_factory=dict)


class FrameProcessor:
    """Settings resolved once (defaults, ``fruit`` profile, ``config`` file, ``overrides``); then one call per
    frame.

    Parameters
    ----------
    method : str
        Completion method (``symfruit methods``).
    fruit : str or None
        Fruit profile name or profile file.
    config : path or None
        Settings file over the profile.
    masks : str
        Mask source as ``symfruit detect --masks``: ``auto``/``color`` (the colour segmenter on a
        live stream), a label PNG / COCO JSON, or ``maskrcnn:CHECKPOINT``.
    depth_scale : float
        Metres per unit of 16-bit depth images (0.001: millimetres).
    overrides : mapping, optional
        Nested ``{section: {key: value}}`` over the file.
    fruit_processes : int
        Worker processes kept to share each frame's fruit with (a :class:`~symfruit.fruitpool.FruitPool`, 0-16;
        0, the default here: none; the nodes' parameter defaults to 1). They warm up while the first frames run in
        this process alone; :meth:`close` ends them.

    Raises
    ------
    SymfruitError
        At construction, for an unknown method, profile, mask source or an invalid settings file, so that a node
        fails at start-up rather than on every frame.
    """

    def __init__(
        self,
        *,
        method: str = DEFAULT_METHOD,
        fruit: str | None = "strawberry",
        config: str | Path | None = None,
        masks: str = "auto",
        depth_scale: float = 0.001,
        overrides: Mapping[str, Any] | None = None,
        fruit_processes: int = 0,
    ) -> None:
        get_method(method)
        try:  # the nodes' own check: (0, 1] metres per unit, as documented and as a frame's camera.json
            depth_scale = checked_parameters({"depth_scale": depth_scale})["depth_scale"]
        except SymfruitError as exc:
            raise InputError(str(exc).replace("parameter depth_scale: ", "depth_scale: ", 1)) from None
        self.method, self.masks, self.depth_scale = method, masks, float(depth_scale)
        self.settings = resolve_settings(fruit=fruit or None, config=config or None, overrides=overrides)
        self.mask_source = mask_source(masks, settings=self.settings)  # a bad model fails here, once
        self._warned: set[str] = set()  # what was said of the camera infos ("distortion", "principal point")
        # last: a bad parameter above starts no process; no frame waits for the workers' warm-up (wait=False)
        self.pool = FruitPool(fruit_processes, method=method, wait=False)
        self._stream = DetectStream(self.pool, masks=self.mask_source, method=method, settings=self.settings)

    def close(self) -> None:
        """End the fruit workers (:meth:`symfruit.fruitpool.FruitPool.close`; a frame in flight dropped); frames
        after it run in this process."""
        self._stream.abandon()
        self.pool.close()

    def workers_said(self) -> str:
        """The fruit workers in a line for the node's start-up log."""
        pool = self.pool
        if pool.active:
            return f"{pool.processes} fruit worker process{'es' if pool.processes > 1 else ''} (warming up)"
        return f"no fruit worker process ({pool.reason})"

    def frame(self, color: Any, depth: Any, info: Any, *, name: str = "frame", source: str = "ros") -> Frame:
        """The :class:`~symfruit.core.frame.Frame` of the three messages (:func:`message_frame`); the first camera
        info with non-zero distortion is warned about, once per processor (not on every frame), and so is the
        first with its principal point outside the image."""
        return message_frame(color, depth, info, depth_scale=self.depth_scale, name=name, source=source,
                             warned=self._warned)  # fmt: skip

    def process(self, color: Any, depth: Any, info: Any, *, name: str = "frame", source: str = "ros") -> Processed:
        """Decode, detect, and list the located fruit. Raises ``SymfruitError`` for a bad frame."""
        t0 = time.perf_counter()
        frame = self.frame(color, depth, info, name=name, source=source)
        t1 = time.perf_counter()
        found = detect(frame, masks=self.mask_source, method=self.method, settings=self.settings, pool=self.pool)
        t2 = time.perf_counter()
        fruits = fruits_of(found)
        t3 = time.perf_counter()
        return Processed(fruits, found, {"decode": t1 - t0, "detect": t2 - t1, "collect": t3 - t2})

    # ---- frames in a stream (issue 19, stop 55, docs/pipe55.md): :class:`Overlapped` -----------------------------

    def begin(self, color: Any, depth: Any, info: Any, *, name: str = "frame", source: str = "ros") -> Begun:
        """A frame's first part: decoded, its masks found (:meth:`symfruit.detect.DetectStream.prepare`). Raises
        ``SymfruitError`` for a bad frame; the frame in flight (:meth:`launch`) is left running."""
        t0 = time.perf_counter()
        frame = self.frame(color, depth, info, name=name, source=source)
        t1 = time.perf_counter()
        return Begun(self._stream.prepare(frame), t1 - t0)

    def launch(self, begun: Begun) -> None:
        """Start a begun frame (:meth:`symfruit.detect.DetectStream.start`): the frame in flight must be finished
        first (:meth:`finish`)."""
        self._stream.start(begun.ready)

    def finish(self, begun: Begun) -> Processed | None:
        """The frame in flight's fruit (None if none is; ``begun``: what :meth:`begin` gave for it), once the
        workers' last ones came. Raises ``SymfruitError`` for the frame's error."""
        found = self._stream.finish()
        if found is None:
            return None
        t = time.perf_counter()
        fruits = fruits_of(found)
        seconds = {"decode": begun.decode, "detect": found.timings["total"], "collect": time.perf_counter() - t}
        return Processed(fruits, found, seconds)


@dataclass(frozen=True)
class Begun:
    """A frame :meth:`FrameProcessor.begin` decoded and prepared, and its decoding's seconds."""

    ready: Any
    decode: float


class Overlapped:
    """A node's frames through :class:`FrameProcessor`'s stream (issue 19, stop 55, docs/pipe55.md): the next frame
    decoded and segmented here while the fruit workers end the fruit of the frame before, then that frame finished
    and given to ``done``, then the next started. Made for :class:`LatestOnly`: :meth:`handle` is its ``handle``,
    :meth:`drain` its ``drain`` (the frame in flight finished as soon as no newer frame waits: a frame is never
    kept waiting for one that may not come). At most one frame is in
    flight beside the one being begun; a frame still waiting is replaced by a newer one as before.

    ``done(item, processed)`` publishes a frame, ``skipped(item, exc)`` tells of a bad one (a ``SymfruitError``),
    ``failed(item, exc)`` of a bug (any other exception of the frame in flight: that of the frame being handled
    goes up to :class:`LatestOnly`'s ``on_error``)."""

    def __init__(
        self, core: FrameProcessor, *, done: Callable[[Any, Processed], None],
        skipped: Callable[[Any, SymfruitError], None], failed: Callable[[Any, BaseException], None],
    ) -> None:  # fmt: skip
        self.core, self._done, self._skipped, self._failed = core, done, skipped, failed
        self._flight: tuple[Any, Begun] | None = None

    def handle(self, item: tuple, *, name: str, source: str) -> None:
        """Begin the frame of ``item`` (a node's: when it came, the colour, depth and camera info messages), finish
        the frame in flight, then start this one. ``done`` and the others are given ``item`` with the time its
        handling began added (``(came, color, depth, info, began)``)."""
        _, color, depth, info = item
        item = (*item, time.perf_counter())
        try:
            begun: Begun | None = self.core.begin(color, depth, info, name=name, source=source)
        except SymfruitError as exc:
            begun = None
            self._skipped(item, exc)
        self.drain()
        if begun is None:
            return
        try:
            self.core.launch(begun)
        except SymfruitError as exc:
            self._skipped(item, exc)
            return
        self._flight = (item, begun)

    def drain(self) -> None:
        """Finish the frame in flight, if any, and give it to ``done``."""
        if self._flight is None:
            return
        (item, begun), self._flight = self._flight, None
        try:
            processed = self.core.finish(begun)
        except SymfruitError as exc:
            self._skipped(item, exc)
            return
        except Exception as exc:  # a bug: told, and the next frame goes on
            self._failed(item, exc)
            return
        if processed is not None:
            self._done(item, processed)


# ---------------------------------------------------------------------------------------------------
# ending on SIGINT and SIGTERM
# ---------------------------------------------------------------------------------------------------


@contextlib.contextmanager
def stop_signals(signals: tuple[signal.Signals, ...] = (signal.SIGINT, signal.SIGTERM)) -> Iterator[Callable[[], int]]:
    """Hold ``signals`` for the main thread while a node runs; yields ``wait()``, which returns the first one's number.

    Inside, the signals are blocked in the calling (main) thread, and so in every thread it starts (rclpy's
    executor and the DDS threads inherit the mask): none of them is interrupted, and ``wait()`` takes the signal by
    ``sigtimedwait``. Threads started before (the BLAS pool numpy starts on import) do not block them, and the kernel
    hands a process-wide signal to such a thread whenever the main thread is not waiting for it at that instant; with
    the default action that killed the whole process (exit -15, the DDS segments left in /dev/shm). So a Python handler
    is installed as well: whichever thread the signal lands on, the interpreter notes it for the main thread, and
    ``wait()`` sees it within a fifth of a second. On leaving, signals still pending are taken (a second Ctrl-C
    meanwhile does not kill the process as it returns) and the mask and the handlers are restored
    (``signal.signal`` runs the handlers still due first).
    """
    caught: list[int] = []

    def note(signum: int, frame: object) -> None:
        caught.append(signum)

    handlers = {sig: signal.signal(sig, note) for sig in signals}
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, signals)

    def wait() -> int:
        me = threading.get_ident()
        while not caught:
            info = signal.sigtimedwait(signals, 0.2)
            if info is not None:
                return info.si_signo
            # A signal another thread took is marked for the main thread, but the interpreter may not get round to
            # ``note`` by itself (since Python 3.12 a thread that cannot run handlers does not flag the main one):
            # signal 0 to this thread sends nothing, and pthread_kill then runs the handlers due.
            signal.pthread_kill(me, 0)
        return caught[0]

    try:
        yield wait
    finally:
        # Taken without waiting: a signal sigpending() still lists may be handed to another thread a moment
        # later (then ``note`` has it), and a blocking sigwait would wait for ever.
        while signal.sigtimedwait(signals, 0) is not None:
            pass
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)
        for sig, handler in handlers.items():
            signal.signal(sig, handler)


# ---------------------------------------------------------------------------------------------------
# the newest frame only
# ---------------------------------------------------------------------------------------------------


class LatestOnly:
    """Run ``handle(item)`` on one worker thread for the newest item only.

    ``put`` never blocks: an item still waiting when a newer one arrives is dropped (and counted),
    so a node that falls behind skips frames instead of queueing them. ``handle`` exceptions go to
    ``on_error(item, exc)``; the worker keeps running. ``drain``: called on the worker thread after items were
    handled, as soon as none waits (and at :meth:`stop`): a handler that leaves work of an item running while it
    may take the next (:class:`Overlapped`) ends it there; its exceptions go to ``on_error(None, exc)``.
    """

    def __init__(
        self,
        handle: Callable[[Any], None],
        *,
        on_error: Callable[[Any, BaseException], None],
        name: str = "symfruit-worker",
        drain: Callable[[], None] | None = None,
    ) -> None:
        self._handle, self._on_error, self._drain = handle, on_error, drain
        self._cond = threading.Condition()
        self._item: Any = None
        self._has_item = False
        self._busy = False
        self._owed = False  # a drain owed: an item handled since the last one
        self._stop = False
        self.dropped = 0
        self.handled = 0
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)

    def start(self) -> LatestOnly:
        self._thread.start()
        return self

    def put(self, item: Any) -> bool:
        """Offer an item; True when it replaced one that was never handled."""
        with self._cond:
            replaced = self._has_item
            if replaced:
                self.dropped += 1
            self._item, self._has_item = item, True
            self._cond.notify_all()
        return replaced

    def wait_idle(self, timeout: float | None = None) -> bool:
        """Block until no item waits, none is being handled and no drain is owed; False on timeout."""
        with self._cond:
            return self._cond.wait_for(lambda: not self._has_item and not self._busy and not self._owed, timeout)

    def stop(self, timeout: float | None = 10.0) -> None:
        """Let the current item finish (and the drain it owes), drop a waiting one, and end the thread."""
        with self._cond:
            self._stop = True
            self._cond.notify_all()
        if self._thread.is_alive():
            self._thread.join(timeout)

    def _run(self) -> None:
        while True:
            with self._cond:
                while not self._has_item and not self._stop and not self._owed:
                    self._cond.wait()
                if self._has_item and not self._stop:
                    item, self._item, self._has_item = self._item, None, False
                    draining = False
                elif self._owed:  # none waits (or stopping): the drain owed
                    item, draining, self._owed = None, True, False
                else:
                    return
                self._busy = True
            try:
                if draining:
                    self._drain()  # type: ignore[misc]  # owed only with a drain
                else:
                    self._handle(item)
            except Exception as exc:  # never let a frame end the worker
                self._on_error(item, exc)
            finally:
                with self._cond:
                    if not draining:
                        self.handled += 1
                        self._owed = self._drain is not None
                    self._busy = False
                    self._cond.notify_all()
