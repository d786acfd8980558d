"""A frame's fruit on worker processes kept between frames: :class:`FruitPool` (issue 19, stop 53; docs/proc53.md).

The fruit of a frame are independent of each other, but two threads of one process gain nothing on them (the GIL;
stop 52, docs/threads52.md). A :class:`FruitPool` keeps worker processes, started once (``forkserver``: never a fork
of a process that may run threads, as the ROS nodes' executors) and warmed up (their compiled kernels loaded), and
:func:`symfruit.detect.detect` with ``pool=`` shares each frame's fruit between the calling process and them::

    with FruitPool(1) as pool:  # seconds, once
        for frame in frames:
            found = detect(frame, pool=pool)  # the same detections as without the pool, bit for bit

How a frame goes: its arrays (depth, colour, labels, fruit pixels) are copied into one shared-memory segment, made
as large as the frame needs and made anew when a larger frame comes; each worker is sent the small rest of the
per-fruit task (camera, settings, method: a few kB pickled) and the fruit's boxes, sorted longest first (by mask
pixels); the calling process and the workers then take the next fruit from one shared counter until none is left,
so neither waits while fruit are left; each detection a worker made comes back pickled (its whole-image mask cut to
its box), and the detections are returned in the frame's order. An error a fruit raises (not a fruit's ``error``,
which is a detection: an exception) is the first failing fruit's in the frame's order, as one process raises it.
A warning a fruit gives in a worker (a ``warnings.warn``, numpy's ``RuntimeWarning`` of a division by zero) is
recorded there and given again in the calling process once the frame is done, in the frame's order, through the
caller's warning filters (``warnings.catch_warnings``, ``-W error``, pytest's ``filterwarnings``): the same warning
(category, text, file and line) as one process gives, shown once where one process shows it once; one the filters
make an error is raised as that fruit's error, as in one process. The workers run with the caller's numpy error
handling (``np.errstate``) of the frame. The warnings of the fruit the calling process did itself were given as it
did them: the pool's warnings keep the frame's order among themselves, not among those (recording them too would
change this process's warning filters, which are shared by its threads, for the frame's length; flake54).

``detect`` gives the pool two tasks a frame (stop 54, docs/pool54.md): first each mask's colour trimming and
registration outline (``detect._Masks``; the search for the frame's shift over the outlines runs in the calling
process), then the fruit (``detect._Fruit``). The fruit are sent moved by :attr:`FruitPool.registration_guess` (the
last shift found) while the search runs (:meth:`FruitPool.run_guessed`); a wrong guess calls that run off (the
workers' fruit dropped) and the fruit go again with the shift found. The frame's depth and colour are copied into the
shared segment once for both tasks.

A worker that dies (killed, a crash) or stays silent for :data:`STALL_TIMEOUT` seconds within a frame is ended: the
fruit it had not returned are done in the calling process, and new workers are started at once for the next
frames (a frame that comes before they are warm runs in the calling process: no frame waits for a start-up). The
pool gives up after :data:`MAX_RESTARTS` starts in a row whose workers never finished a frame (it then stays
inactive, :attr:`FruitPool.reason` says why). Every wait is bounded (the constants below give each bound's reason).

The pool runs everything in the calling process (it is *inactive*, :attr:`FruitPool.reason` says why) where a second
process does not belong: in a process ``multiprocessing`` started (an evaluation's or a multiprocessing pool's
worker, a Dask worker under its nanny: they are one of several already, and daemonic ones cannot start children),
in a Dask worker, with fewer than two usable cores (``os.sched_getaffinity``), with ``processes=0``, in a child
forked from the pool's owner, and off POSIX. The shared-memory segment is unlinked when the pool is closed (the
``with`` block's end, :meth:`FruitPool.close`, the pool collected, or the interpreter's exit), also after a worker
died or the caller was interrupted.
"""

from __future__ import annotations

import contextlib
import mmap
import multiprocessing
import os
import queue
import secrets
import signal
import sys
import threading
import time
import traceback
import warnings
import weakref
from collections.abc import Callable, Iterator
from multiprocessing import shared_memory
from typing import Any

import numpy as np

from .errors import InputError
from .threads import one_blas_thread

__all__ = ["MAX_FRUIT_PROCESSES", "FruitPool", "Running", "check_fruit_processes", "one_process_reason", "usable_cores"]

#: Most worker processes a :class:`FruitPool` starts (more than the cores less one gain nothing).
MAX_FRUIT_PROCESSES = 16

#: Seconds a worker's start and warm-up may take: imports and a small frame's detection, about 3-5 s with numba's
#: cache warm, but a cold cache compiles every kernel (3-4 minutes on two loaded cores).
START_TIMEOUT = 900.0

#: Seconds a worker may stay silent within a frame before it is taken for stuck, ended, and its fruit done in the
#: calling process: a fruit takes milliseconds (the slowest of the benchmark frames' about 10 ms, a 1080p frame's
#: fruit tens of ms), so this only ends a worker that will not answer.
STALL_TIMEOUT = 120.0

#: Seconds a worker is given to stop when the pool closes before it is terminated (then killed).
STOP_TIMEOUT = 10.0

#: Starts in a row whose workers die before they finish a frame after which the pool stays inactive.
MAX_RESTARTS = 3

#: Seconds between two looks at a worker while waiting for it (its answer ends the wait at once).
_POLL = 0.05

#: Bytes a shared-memory segment is rounded up to (a slightly larger frame reuses it).
_SEGMENT_STEP = 1 << 20
SEGMENT_PREFIX = "symfruit_"  # a segment's name: the prefix, the caller's process id and a random part

#: Set in a pool's worker process: a worker never starts workers of its own.
_IN_WORKER = False


def check_fruit_processes(processes: Any, what: str = "processes") -> int:
    """``processes`` as :class:`FruitPool` takes it: a whole number 0..:data:`MAX_FRUIT_PROCESSES`, else
    :class:`~symfruit.errors.InputError` naming ``what`` (``--fruit-processes`` on the command line)."""
    if (
        isinstance(processes, bool)
        or not isinstance(processes, int | np.integer)
        or not (0 <= processes <= MAX_FRUIT_PROCESSES)
    ):
        raise InputError(f"{what} must be a whole number from 0 to {MAX_FRUIT_PROCESSES}, got {processes!r}")
    return int(processes)


def usable_cores() -> int:
    """The CPU cores this process may run on (``os.sched_getaffinity`` where the system has it, else
    ``os.cpu_count()``)."""
    getaffinity = getattr(os, "sched_getaffinity", None)
    return max(1, len(getaffinity(0)) if getaffinity is not None else (os.cpu_count() or 1))


def one_process_reason(processes: int = 1) -> str:
    """Why a :class:`FruitPool` of ``processes`` workers would run everything in this process ("" if it would
    not): see the module's docstring."""
    if processes == 0:
        return "no worker process asked for (0)"
    if os.name != "posix":
        return "worker processes need POSIX shared memory"
    if _IN_WORKER:
        return "this process is a FruitPool worker"
    if multiprocessing.current_process().daemon or multiprocessing.parent_process() is not None:
        return ("this process was started by multiprocessing (an evaluation's, a multiprocessing pool's or a Dask "
                "worker): it is one of several already")  # fmt: skip
    if _in_dask_worker():
        return "this process is a Dask worker: it is one of several already"
    cores = usable_cores()
    if cores < 2:
        return f"this process may use {cores} core: a second process would only take turns with it"
    return ""


def _in_dask_worker() -> bool:
    distributed = sys.modules.get("distributed")  # never imported for the question
    if distributed is None:
        return False
    try:
        distributed.get_worker()
    except (ValueError, AttributeError):
        return False
    return True


class _Lost(Exception):
    """A worker was lost within a frame (dead, silent, or its pipe broken)."""


class _Worker:
    """One worker process and the calling side of its pipe."""

    def __init__(self, process: Any, conn: Any) -> None:
        self.process, self.conn, self.ready = process, conn, False


class _State:
    """What closing a pool ends: its workers and its shared-memory segment (apart from the pool, for
    ``weakref.finalize``)."""

    def __init__(self) -> None:
        self.owner = os.getpid()
        self.workers: list[_Worker] = []
        self.segment: shared_memory.SharedMemory | None = None

    def stop_workers(self, gently: bool) -> None:
        workers, self.workers = self.workers, []
        if os.getpid() != self.owner:  # a forked child's copy: the workers and the segment are the owner's
            return
        asks = [gently and w.ready for w in workers]  # one still warming up would hear it only when warm
        for w, ask in zip(workers, asks, strict=True):
            if ask and w.process.is_alive():
                with contextlib.suppress(OSError, ValueError):
                    w.conn.send(("stop",))
        for w, ask in zip(workers, asks, strict=True):
            w.process.join(STOP_TIMEOUT if ask else 0.0)
            if w.process.is_alive():
                w.process.terminate()
                w.process.join(STOP_TIMEOUT)
            if w.process.is_alive():
                w.process.kill()
                w.process.join(STOP_TIMEOUT)
            w.conn.close()

    def drop_segment(self) -> None:
        segment, self.segment = self.segment, None
        if segment is None or os.getpid() != self.owner:
            return
        segment.close()
        with contextlib.suppress(FileNotFoundError):
            segment.unlink()

    def close(self) -> None:
        try:
            self.stop_workers(gently=True)
        finally:
            self.drop_segment()


class FruitPool:
    """Worker processes that take a share of each frame's fruit in :func:`symfruit.detect.detect` (``pool=``),
    kept from frame to frame; a context manager (closed at the ``with`` block's end). See the module's docstring.

    Parameters
    ----------
    processes : int
        Worker processes, 0 to :data:`MAX_FRUIT_PROCESSES` (0: none, the pool is inactive). On two cores one is
        what pays (the calling process works too).
    method : str or None
        The completion method the workers' warm-up runs (a small synthetic frame's detection: loads the compiled
        kernels, seconds); None: no warm-up (the workers' first frame loads them).
    wait : bool
        Wait for the workers to be warm (bounded by :data:`START_TIMEOUT`) before returning; else the frames that
        come before they are run in the calling process.
    start_method : str
        ``forkserver`` (default) or ``spawn``: never ``fork``, which copies a process that may be running threads.

    Attributes
    ----------
    reason : str
        Why the pool runs everything in the calling process ("" while it has workers).
    started_s : float
        Seconds the first workers took to start and warm up (with ``wait``; NaN otherwise).
    fruit_elsewhere : int
        Fruit the workers have done so far.
    registration_guess : tuple of int
        The registration shift ``(du, dv)`` :func:`symfruit.detect.detect` sends a frame's fruit to the workers
        with while it searches for the frame's own (the last shift found that differed from its guess: a camera's
        shift stays the same from frame to frame); a wrong guess costs the fruit the workers were on.
    masks_elsewhere : int
        Masks the workers have colour trimmed and found registration outlines of so far (``detect``'s first task
        a frame).
    starts : int
        Sets of workers started (1 and one more after each loss).
    last_loss : str
        Why the last set of workers was ended ("" while none was).

    Raises
    ------
    InputError
        ``processes`` out of bounds, an unknown ``start_method``.
    SymfruitError
        An unknown ``method``.
    """

    #: Whether the calling process takes fruit too (tests set it False on a pool: the workers then do every fruit).
    _caller_shares = True

    def __init__(
        self, processes: int = 1, *, method: str | None = "evidence", wait: bool = True,
        start_method: str = "forkserver",
    ) -> None:  # fmt: skip
        self.processes = check_fruit_processes(processes)
        if start_method not in ("forkserver", "spawn"):
            raise InputError(f"start_method must be forkserver or spawn (never fork), got {start_method!r}")
        if method is not None:  # an unknown method is refused here, not by every worker's warm-up
            from .methods.registry import get as get_method

            get_method(method)
        self.method, self.start_method = method, start_method
        self.reason = one_process_reason(self.processes)
        self.started_s, self.fruit_elsewhere, self.starts, self.last_loss = float("nan"), 0, 0, ""
        self.masks_elsewhere = 0
        self.registration_guess = (0, 0)
        #: what :meth:`_share` last copied: each array (the object) and its place, for the frame ``_shared_for``
        self._shared: dict[str, tuple[np.ndarray, Any]] = {}
        self._shared_for: object = None
        self._state = _State()
        self._close = weakref.finalize(self, self._state.close)
        self._busy = threading.Lock()  # one frame at a time; another thread's frame meanwhile runs here alone
        self._blas: Any = None  # threadpoolctl's controller of this process's BLAS, made at the first shared frame
        self._failed_starts, self._seq = 0, 0
        self._lock: Any = None
        self._counter: Any = None
        self._started_at = 0.0  # time.monotonic() when the current set of workers was started
        if not self.reason:
            try:
                self._start()
                if wait and self._wait_ready(START_TIMEOUT):
                    self.started_s = time.monotonic() - self._started_at
            except BaseException:  # interrupted while waiting: no worker outlives the failed constructor
                self.close()
                raise

    @property
    def active(self) -> bool:
        """Whether frames may use workers (in the process that made the pool)."""
        return not self.reason and os.getpid() == self._state.owner

    def __enter__(self) -> FruitPool:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """End the workers (asked to stop, then terminated after :data:`STOP_TIMEOUT` s) and unlink the shared
        memory; the pool is inactive afterwards. Closing twice is harmless."""
        if not self.reason:
            self.reason = "the pool is closed"
        self._close()
        self._lock = self._counter = None  # their semaphore is unlinked when collected

    def __repr__(self) -> str:
        how = f"{len(self._state.workers)} workers" if self.active else f"inactive: {self.reason}"
        return f"FruitPool({self.processes}, {how})"

    # ---- workers ------------------------------------------------------------------------------------------------

    def _start(self) -> None:
        ctx: Any = multiprocessing.get_context(self.start_method)
        self._lock, self._counter = ctx.Lock(), ctx.RawValue("q", 0)
        self._started_at = time.monotonic()
        for _ in range(self.processes):
            here, there = ctx.Pipe(duplex=True)
            process = ctx.Process(target=_worker_main, args=(there, self._lock, self._counter, self.method),
                                  name="symfruit-fruit", daemon=True)  # fmt: skip
            with _main_hidden():
                process.start()
            there.close()  # the worker's end lives in the worker alone: its death closes the pipe
            self._state.workers.append(_Worker(process, here))
        self.starts += 1

    def _wait_ready(self, timeout: float) -> bool:
        """Wait up to ``timeout`` seconds for every worker's word that it is warm; False if one is not yet. A worker
        that died or failed its warm-up ends the set (:meth:`_lost`)."""
        deadline = time.monotonic() + timeout
        for w in self._state.workers:
            while not w.ready:
                left = deadline - time.monotonic()
                if not w.conn.poll(max(0.0, min(left, _POLL))):
                    if not w.process.is_alive():
                        self._lost(f"a worker process ended during its start (exit code {w.process.exitcode})")
                        return False
                    if time.monotonic() - self._started_at > START_TIMEOUT:
                        self._lost(f"a worker process was not ready after {START_TIMEOUT:.0f} s")
                        return False
                    if left <= 0:
                        return False
                    continue
                try:
                    word = w.conn.recv()
                except (EOFError, OSError):
                    self._lost("a worker process ended during its start")
                    return False
                if word[0] != "ready":
                    self._lost(f"a worker process failed its warm-up: {word[1]}", give_up=True)
                    return False
                w.ready = True
        return True

    def _lost(self, why: str, *, give_up: bool = False) -> None:
        """End the workers after a loss and start new ones (up to :data:`MAX_RESTARTS` sets in a row that never
        finished a frame; then the pool stays inactive with ``why``)."""
        self.last_loss = why
        self._state.stop_workers(gently=False)
        self._failed_starts += 1
        if give_up or self._failed_starts >= MAX_RESTARTS:
            self.reason = f"{why}; no more workers are started"
            return
        self._start()

    # ---- a frame ------------------------------------------------------------------------------------------------

    def run(
        self, fruit: Any, jobs: list[tuple[int, tuple[slice, slice]]], same: object = None
    ) -> tuple[list[Any], float]:
        """``[fruit(k, sl) for k, sl in jobs]`` shared with the workers: the same list, in the same order, and the
        CPU seconds the workers spent on their fruit. An exception a fruit raises is raised after the others are
        done, the first failing fruit's in ``jobs``' order. Called by :func:`symfruit.detect.detect`.

        ``fruit``: a per-fruit task (``detect``'s ``_Fruit``, or its masks' trimming and registration outlines,
        ``_Masks``) whose class names its whole-image arrays (``ARRAYS``: sent through shared memory, the rest of its
        attributes pickled), may pack its answers to send (``packed``, ``unpacked``), and whose answer ends with the
        CPU seconds it took. ``same``: an object that stands for one frame (``detect`` makes one per call): an array
        of a later task given the same ``same`` that is the very object the last one shared under its name is not
        copied again (the frame's depth and colour, shared once for both of ``detect``'s tasks)."""
        got = self.run_guessed(fruit, jobs, same, None)
        assert got is not None  # nothing to check: never called off
        return got

    def run_guessed(
        self, fruit: Any, jobs: list[tuple[int, tuple[slice, slice]]], same: object, check: Callable[[], bool] | None
    ) -> tuple[list[Any], float] | None:
        """:meth:`run` of a task made from a guess, started on the workers while this process runs ``check`` (once,
        before it takes a fruit itself, whether or not the pool has workers), which tells whether the guess was
        right: if it returns False no more fruit are taken, the workers end the fruit they are on, their answers are
        dropped, and None is returned (``detect`` sends its fruit with the last frame's registration shift while its
        search for this frame's runs, then again with the right one when they differ). An exception ``check``
        raises goes up as one a fruit raises here would (the workers ended, new ones started)."""
        return self.start(fruit, jobs, same, check).result()

    def start(
        self, fruit: Any, jobs: list[tuple[int, tuple[slice, slice]]], same: object = None,
        check: Callable[[], bool] | None = None, *, leave: float | None = None,
    ) -> Running:  # fmt: skip
        """:meth:`run_guessed` in two halves (issue 19, stop 55: frames in a stream, docs/pipe55.md): the task sent
        to the workers and this process's share of its fruit done here; what :meth:`run_guessed` returns (or raises)
        is had from the :class:`Running` returned, :meth:`Running.result`, which waits for the workers' last fruit.

        ``leave``: None, every fruit this process can take it takes (as :meth:`run`); else the seconds this
        process will spend elsewhere before it asks for the result (the next frame's segmentation): it stops taking
        fruit once those left untaken would take the workers about that long (each fruit's time guessed from its
        mask's pixels and this process's own seconds per pixel on the frame's fruit so far), so that the workers
        are busy meanwhile. Which process does a fruit never changes its answer.

        Until the result is had (or :meth:`Running.abandon` called) the pool is busy: another frame run meanwhile
        (another thread's) runs in its calling process alone."""
        number = isinstance(leave, int | float | np.integer | np.floating) and not isinstance(leave, bool)
        if leave is not None and not (number and leave >= 0):  # "x" was a TypeError after the task was sent (stop 56)
            raise InputError(f"FruitPool.start: leave must be None or seconds >= 0, got {leave!r:.40}")
        if not self.active or not self._busy.acquire(blocking=False):
            return Running.here(fruit, jobs, check)
        try:
            if not self._workers_ready():
                self._busy.release()
                return Running.here(fruit, jobs, check)
            with self._one_blas_thread():
                collect = self._run(fruit, jobs, same, check, leave)
        except BaseException:  # interrupted (or a bug here): the workers may be mid-frame; new ones next time
            self._interrupted()
            raise
        return Running(self, collect)

    def _interrupted(self, why: str = "the calling process was interrupted within a frame") -> None:
        """The calling process was interrupted (or failed) within a frame, or dropped it: its workers ended (new ones
        next time) and the pool free."""
        try:
            if self.active:
                self._lost(why)
        finally:
            self._busy.release()

    def _given(
        self, got: tuple[list[tuple[str, Any]], list[list[_Warned]], float] | None
    ) -> tuple[list[Any], float] | None:
        """A run's answers as :meth:`run_guessed` gives them: the workers' warnings given again here, the first
        failing fruit's error raised."""
        if got is None:
            return None
        out, warned, cpu = got
        for j, given in enumerate(warned):  # the workers' warnings, through this process's filters
            if given:
                try:
                    _warn_again(given)
                except Warning as exc:  # a filter made it an error: the fruit's error, as in one process (it came
                    out[j] = ("raised", exc)  # before anything the fruit raised, which ended it)
        for kind, value in out:  # the first failing fruit's error, in the frame's order
            if kind == "raised":
                raise value
        return [value for _, value in out], cpu

    def _one_blas_thread(self) -> contextlib.AbstractContextManager[Any]:
        """This process's BLAS on one thread while a frame is shared (threadpoolctl, the ``fast`` extra; without it,
        nothing): each worker runs its own on one thread beside it, and two-thread BLAS on both sides of two cores
        made the benchmark frame slower than no pool with `paper` (66-68 against 45-48 ms; 38.6 with one thread
        each; docs/proc53.md). About 0.03 ms a frame; the limit is lifted when the frame is done."""
        if self._blas is None:
            try:
                from threadpoolctl import ThreadpoolController
            except ImportError:
                self._blas = False
            else:
                self._blas = ThreadpoolController()
        return contextlib.nullcontext() if self._blas is False else self._blas.limit(limits=1, user_api="blas")

    def _workers_ready(self) -> bool:
        for w in self._state.workers:
            if not w.process.is_alive():  # killed between frames: new workers for the next frames
                self._lost(f"a worker process ended between frames (exit code {w.process.exitcode})")
                return False
        return self._wait_ready(0.0) if self.active else False

    def _run(
        self, fruit: Any, jobs: list[tuple[int, tuple[slice, slice]]], same: object, check: Callable[[], bool] | None,
        leave: float | None,
    ) -> Callable[[], tuple[list[tuple[str, Any]], list[list[_Warned]], float] | None]:  # fmt: skip
        """:meth:`start`'s work: the task sent and this process's share done; returns what gives, once the workers'
        last fruit came, each fruit's :func:`_attempt` and the warnings a worker recorded for it (none for those done
        here), in ``jobs``' order, and the workers' CPU seconds (None: the run was called off)."""
        # longest first (mask pixels; ties in the frame's order): the last fruit taken are the short ones
        pixels = [int(np.count_nonzero(fruit.labels[sl] == k)) for k, sl in jobs]
        order = sorted(range(len(jobs)), key=lambda i: -pixels[i])
        todo = [jobs[i] for i in order]
        kind = type(fruit)
        arrays = {name: getattr(fruit, name) for name in kind.ARRAYS}
        name, size, layout = self._share(arrays, same)
        rest = {k: v for k, v in fruit.__dict__.items() if k not in arrays}
        self._seq += 1
        seq, workers = self._seq, list(self._state.workers)
        self._counter.value = 0  # no worker takes a fruit between frames: each said "done" to the last one
        # numpy's error handling as here ("call" and "log" need this process's callable: a warning there instead)
        numpy_errors = {k: v if v in ("ignore", "warn", "raise", "print") else "warn" for k, v in np.geterr().items()}
        message = ("frame", seq, name, size, layout, kind, rest, todo, os.environ.get("SYMFRUIT_KERNELS"),
                   numpy_errors)  # fmt: skip
        found: list[Any] = [None] * len(todo)  # ("ok", _Done) or ("raised", exception), in ``todo``'s order
        warned: list[list[_Warned]] = [[] for _ in todo]  # what a worker recorded for each
        theirs, done, cpu, lost = [False] * len(todo), [False] * len(workers), 0.0, ""
        for w in workers:
            try:
                w.conn.send(message)
            except OSError:
                lost = "a worker process's pipe broke"
        called_off = check is not None and not check()
        if called_off and not _take_all(self._lock, self._counter, len(todo)):
            lost = f"the fruit counter's lock was held for {STALL_TIMEOUT:.0f} s"
        # pixels left from each place in ``todo`` on, and this process's seconds per pixel on its fruit (``leave``)
        after = np.cumsum([0, *(pixels[i] for i in reversed(order))])[::-1] if leave is not None else None
        own_s = own_px = 0.0
        while not lost and self._caller_shares and (i := _claim(self._lock, self._counter, len(todo))) is not None:
            t = time.perf_counter()
            found[i] = _attempt(fruit, *todo[i])
            for j, w in enumerate(workers):  # what came meanwhile, so that no worker waits on a full pipe
                lost = lost or self._take(w, seq, kind, found, warned, theirs, done, j, wait=0.0)[0]
            if after is not None and leave is not None:
                own_s, own_px = own_s + time.perf_counter() - t, own_px + pixels[order[i]]
                untaken = after[min(int(self._counter.value), len(todo))]  # a read: at worst one fruit off
                if own_px and own_s / own_px * untaken <= leave * len(workers):
                    break
        return lambda: self._collect(fruit, jobs, todo, order, kind, seq, workers, found, warned, theirs, done, cpu,
                                     lost, called_off)  # fmt: skip

    def _collect(
        self, fruit: Any, jobs: list[Any], todo: list[Any], order: list[int], kind: type, seq: int,
        workers: list[_Worker], found: list[Any], warned: list[list[_Warned]], theirs: list[bool], done: list[bool],
        cpu: float, lost: str, called_off: bool,
    ) -> tuple[list[tuple[str, Any]], list[list[_Warned]], float] | None:  # fmt: skip
        """:meth:`_run`'s second half: the workers' last fruit waited for (a lost worker's done here)."""
        from .detect import _Fruit

        if not lost and self._caller_shares:  # fruit left untaken (``leave``): this process takes them with the rest
            while (i := _claim(self._lock, self._counter, len(todo))) is not None:
                found[i] = _attempt(fruit, *todo[i])
                for j, w in enumerate(workers):
                    lost = lost or self._take(w, seq, kind, found, warned, theirs, done, j, wait=0.0)[0]
                if lost:
                    break
        for j, w in enumerate(workers):
            silent_since = time.monotonic()
            while not lost and not done[j]:
                lost, heard = self._take(w, seq, kind, found, warned, theirs, done, j, wait=_POLL)
                if heard:
                    silent_since = time.monotonic()
                elif not w.process.is_alive():
                    lost = f"a worker process ended within a frame (exit code {w.process.exitcode})"
                elif time.monotonic() - silent_since > STALL_TIMEOUT:
                    lost = f"a worker process was silent for {STALL_TIMEOUT:.0f} s within a frame"
        if called_off:  # the workers' answers dropped
            if lost:
                self._lost(lost)
            else:
                self._failed_starts = 0
            return None
        if lost:  # the fruit not returned are done here; new workers for the next frames
            self._lost(lost)
            for i, got in enumerate(found):
                if got is None:
                    found[i] = _attempt(fruit, *todo[i])
                    theirs[i], warned[i] = False, []
        else:
            self._failed_starts = 0
        out: list[Any] = [None] * len(jobs)
        out_warned: list[list[_Warned]] = [[] for _ in jobs]
        for i, got in enumerate(found):
            out[order[i]], out_warned[order[i]] = got, warned[i]
            if theirs[i] and got[0] == "ok":
                cpu += got[1][-1]
                if issubclass(kind, _Fruit):
                    self.fruit_elsewhere += 1
                else:
                    self.masks_elsewhere += 1
        return out, out_warned, cpu

    def _take(self, w: _Worker, seq: int, kind: type, found: list[Any], warned: list[list[_Warned]],
              theirs: list[bool], done: list[bool], j: int, wait: float) -> tuple[str, bool]:  # fmt: skip
        """Read what worker ``w`` (the ``j``-th) sent for a task of class ``kind``, waiting up to ``wait`` seconds
        for a first message: its fruit into ``found`` and their warnings into ``warned`` (``theirs`` marked), the end
        of its share into ``done``.
        Returns why it is lost ("" if it is not) and whether anything came."""
        heard = False
        while w.conn.poll(0.0 if heard else wait):
            try:
                word = w.conn.recv()  # from this pool's own worker, over a pipe no one else holds
            except (EOFError, OSError):
                return f"a worker process ended within a frame (exit code {w.process.exitcode})", heard
            heard = True
            if word[1] != seq:  # cannot happen: each worker said "done" to the frame before
                return "a worker process answered another frame", heard
            if word[0] == "done":
                done[j] = True
                break
            found[word[2]], warned[word[2]], theirs[word[2]] = _unpacked(kind, word[3]), word[4], True
        return "", heard

    def _share(self, arrays: dict[str, np.ndarray | None], same: object = None) -> tuple[str, int, dict[str, Any]]:
        """Copy ``arrays`` into the shared segment (a larger one made first when they do not fit); its name, size
        and each array's place ``(offset, dtype, shape)`` (None for a None). An array that is the very object the
        last call shared under its name, with the same ``same`` (not None), in the same segment, is where it was
        and is not copied again (:meth:`run`)."""
        layout: dict[str, Any] = {}
        at = 0
        for key, a in arrays.items():
            if a is None:
                layout[key] = None
                continue
            layout[key] = (at, a.dtype.str, a.shape)
            at += -(-a.nbytes // 64) * 64
        segment, kept = self._state.segment, self._shared
        if segment is None or segment.size < at:
            self._state.drop_segment()  # a worker keeps its mapping of the old one until the next frame's
            size = max(_SEGMENT_STEP, -(-at // _SEGMENT_STEP) * _SEGMENT_STEP)
            segment = self._state.segment = _new_segment(size)
            kept = {}
        if same is None or same is not self._shared_for:
            kept = {}
        self._shared, self._shared_for = {}, same
        for key, a in arrays.items():
            if a is not None:
                offset, dtype, shape = layout[key]
                if key not in kept or kept[key][0] is not a or kept[key][1] != layout[key]:
                    np.copyto(np.ndarray(shape, dtype, buffer=segment.buf, offset=offset), a)
                self._shared[key] = (a, layout[key])
        return segment.name, segment.size, layout


class Running:
    """A task started on a :class:`FruitPool` (:meth:`FruitPool.start`): this process's share of its fruit done,
    the workers' maybe not yet. :meth:`result` once (or :meth:`abandon`); the pool is busy until then."""

    def __init__(self, pool: FruitPool | None, collect: Callable[[], Any], value: Any = None) -> None:
        self._pool, self._collect, self._value = pool, collect, value

    @classmethod
    def here(cls, fruit: Any, jobs: list[tuple[int, tuple[slice, slice]]], check: Callable[[], bool] | None) -> Running:
        """The task run in this process alone, now (no workers, or the pool busy): its answer kept."""
        return cls.ready(None if check is not None and not check() else ([fruit(k, sl) for k, sl in jobs], 0.0))

    @classmethod
    def ready(cls, value: tuple[list[Any], float] | None) -> Running:
        """A run whose answer ``value`` is had already."""
        return cls(None, lambda: None, value)

    @property
    def pending(self) -> bool:
        """Whether the workers' answers are still to be had (:meth:`result`) or dropped (:meth:`abandon`)."""
        return self._pool is not None

    def result(self) -> tuple[list[Any], float] | None:
        """What :meth:`FruitPool.run_guessed` returns: the answers in the jobs' order and the workers' CPU seconds
        (None: called off), once the workers' last fruit came; the first failing fruit's error is raised, the
        workers' warnings given here. An interrupt while waiting ends the workers (new ones for the next frame)."""
        pool, self._pool = self._pool, None
        if pool is None:
            return self._value
        try:
            got = self._collect()
        except BaseException:
            pool._interrupted()
            raise
        pool._busy.release()
        return pool._given(got)

    def abandon(self) -> None:
        """Drop the workers' answers (a stream stopped between frames): the workers are ended, new ones started for
        the next frames, as after an interrupt within a frame. Nothing if the answers were had."""
        pool, self._pool = self._pool, None
        if pool is not None:
            pool._interrupted("a frame was dropped before its workers' fruit came")


def _new_segment(size: int) -> shared_memory.SharedMemory:
    """A new shared segment named ``symfruit_<pid>_<random>``: a segment left by a process killed outright is
    told by its name (and its process id) in ``/dev/shm``."""
    while True:
        try:
            name = f"{SEGMENT_PREFIX}{os.getpid()}_{secrets.token_hex(4)}"
            return shared_memory.SharedMemory(name=name, create=True, size=size)
        except FileExistsError:  # 2**-32 a try
            continue


# ---- both sides ---------------------------------------------------------------------------------------------------


@contextlib.contextmanager
def _main_hidden() -> Iterator[None]:
    """While a worker starts: this process's ``__main__`` without its file and spec, so that the worker does not
    import it again (as ``spawn`` and ``forkserver`` do, running a script without an ``if __name__ == "__main__"``
    guard once more): the worker needs nothing of it."""
    main = sys.modules.get("__main__")
    if main is None:
        yield
        return
    saved: dict[str, Any] = {key: main.__dict__[key] for key in ("__file__", "__spec__") if key in main.__dict__}
    main.__dict__.pop("__file__", None)
    main.__dict__["__spec__"] = None
    try:
        yield
    finally:
        main.__dict__.pop("__spec__", None)
        main.__dict__.update(saved)


def _claim(lock: Any, counter: Any, count: int) -> int | None:
    """The next fruit's place in the frame's list (the shared counter taken and moved on under the shared lock),
    None when none is left. A lock not had within :data:`STALL_TIMEOUT` s (its holder died holding it) ends the
    taking: None."""
    if not lock.acquire(timeout=STALL_TIMEOUT):
        return None
    try:
        i = counter.value
        if i >= count:
            return None
        counter.value = i + 1
        return int(i)
    finally:
        lock.release()


def _take_all(lock: Any, counter: Any, count: int) -> bool:
    """No fruit left to take: the shared counter moved to ``count`` under the shared lock (False: the lock was not
    had within :data:`STALL_TIMEOUT` s)."""
    if not lock.acquire(timeout=STALL_TIMEOUT):
        return False
    try:
        counter.value = max(int(counter.value), count)
        return True
    finally:
        lock.release()


def _attempt(fruit: Callable[..., Any], k: int, sl: tuple[slice, slice]) -> tuple[str, Any]:
    """``("ok", fruit(k, sl))``, or ``("raised", the exception)`` (an ``Exception``; anything else goes up)."""
    try:
        return "ok", fruit(k, sl)
    except Exception as exc:
        return "raised", exc


#: A warning a worker recorded: (category, text, file, line).
_Warned = tuple[type[Warning], str, str, int]


def _recorded(fruit: Callable[..., Any], k: int, sl: tuple[slice, slice]) -> tuple[tuple[str, Any], list[_Warned]]:
    """In a worker: :func:`_attempt` and every warning it gave, recorded whatever the filters (the caller's decide
    when they are given again, :func:`_warn_again`). A category the caller could not import by its name (a class
    made inside a function: it would not pickle) goes as a ``UserWarning`` whose text starts with its name."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        got = _attempt(fruit, k, sl)
    given: list[_Warned] = []
    for w in caught:
        category, text = w.category, str(w.message)
        if not _by_name(category):
            category, text = UserWarning, f"{category.__name__}: {text}"
        given.append((category, text, w.filename, w.lineno))
    return got, given


def _by_name(cls: type) -> bool:
    """Whether ``cls`` is found by its module and qualified name (what pickling a class by reference needs)."""
    found: Any = sys.modules.get(cls.__module__)
    for part in cls.__qualname__.split("."):
        found = getattr(found, part, None)
    return found is cls


def _warn_again(given: list[_Warned]) -> None:
    """Give the warnings a worker recorded in this process, in their order, through this process's filters, as
    ``warnings.warn`` gave them there: the module a filter's ``module`` matches is the one of their file, and the
    once-per-place record (``__warningregistry__``) is that module's. Raises the first one a filter makes an error."""
    for category, text, filename, lineno in given:
        module = _module_of(filename)
        registry = None if module is None else vars(module).setdefault("__warningregistry__", {})
        name = None if module is None else module.__name__
        warnings.warn_explicit(text, category, filename, lineno, module=name, registry=registry)


def _module_of(filename: str) -> Any:
    """The loaded module whose file ``filename`` is, or None (``warn_explicit`` then names it by its file)."""
    for module in list(sys.modules.values()):
        if getattr(module, "__file__", None) == filename:
            return module
    return None


def _packed(kind: type, got: tuple[str, Any]) -> tuple[Any, ...]:
    """A worker's answer for one job of a task of class ``kind``, small to pickle: its value as ``kind.packed``
    gives it (``detect``'s ``_Fruit``: a detection's whole-image mask cut to its box), or the value itself; an
    exception pickled or told as text."""
    what, value = got
    if what == "raised":
        value.add_note(f"(in FruitPool worker {os.getpid()}:\n{''.join(traceback.format_exception(value))})")
        return ("raised", value)  # the sender tells it as text if it does not pickle (_send_all)
    pack = getattr(kind, "packed", None)
    return ("ok", value if pack is None else pack(value))


def _unpacked(kind: type, packed: tuple[Any, ...]) -> tuple[str, Any]:
    """:func:`_packed`'s answer as :func:`_attempt` gives it."""
    what, value = packed
    unpack = getattr(kind, "unpacked", None)
    return (what, value) if what == "raised" or unpack is None else ("ok", unpack(value))


# ---- the worker ---------------------------------------------------------------------------------------------------


def _worker_main(conn: Any, lock: Any, counter: Any, method: str | None) -> None:
    """A worker process: warm up, say so, then take fruit of each frame it is sent until told to stop or its pipe
    closes (the calling process ended)."""
    global _IN_WORKER
    _IN_WORKER = True
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C in a terminal reaches the whole group: the caller decides
    one_blas_thread()  # beside the caller on its own core: two-thread BLAS in each made `paper` slower than no pool
    outbox: queue.SimpleQueue[tuple[Any, ...] | None] = queue.SimpleQueue()
    sender = threading.Thread(target=_send_all, args=(conn, outbox), daemon=True)
    sender.start()  # sent from there: a full pipe never holds the next fruit up
    try:
        try:
            if method is not None:
                _warm_up(method)
        except Exception as exc:
            conn.send(("failed", f"{type(exc).__name__}: {exc}"))
            return
        conn.send(("ready", os.getpid()))
        mapped: tuple[str, mmap.mmap] | None = None
        while True:
            message = conn.recv()
            if message[0] != "frame":
                return
            _, seq, name, size, layout, kind, rest, todo, kernels, numpy_errors = message
            if kernels is None:
                os.environ.pop("SYMFRUIT_KERNELS", None)
            else:
                os.environ["SYMFRUIT_KERNELS"] = kernels
            if mapped is None or mapped[0] != name:
                if mapped is not None:
                    with contextlib.suppress(BufferError):
                        mapped[1].close()
                mapped = (name, _map(name, size))
            with np.errstate(**numpy_errors):  # the caller's: a division by zero warns, raises or is ignored as there
                _frame(mapped[1], seq, layout, kind, rest, todo, lock, counter, outbox)
    except (EOFError, OSError, KeyboardInterrupt):
        return
    finally:
        outbox.put(None)
        sender.join(STOP_TIMEOUT)


def _frame(buf: mmap.mmap, seq: int, layout: dict[str, Any], kind: type, rest: dict[str, Any], todo: list[Any],
           lock: Any, counter: Any, outbox: queue.SimpleQueue[tuple[Any, ...] | None]) -> None:  # fmt: skip
    """One frame's share: fruit taken from the shared counter until none is left, each answer queued for the
    sender, then the frame's end. ``kind``: the per-fruit task's class (``detect``'s ``_Fruit``)."""
    fruit: Any = object.__new__(kind)
    arrays = {key: None if at is None else np.ndarray(at[2], at[1], buffer=buf, offset=at[0])
              for key, at in layout.items()}  # fmt: skip
    fruit.__dict__.update(rest, **arrays)
    while (i := _claim(lock, counter, len(todo))) is not None:
        got, given = _recorded(fruit, *todo[i])
        outbox.put(("fruit", seq, i, _packed(kind, got), given))
    outbox.put(("done", seq))


def _send_all(conn: Any, outbox: queue.SimpleQueue[tuple[Any, ...] | None]) -> None:
    """The worker's sender thread: each answer sent (pickled by the pipe) until ``None``; an exception that does not
    pickle goes as a ``RuntimeError`` with its type and text."""
    while (word := outbox.get()) is not None:
        try:
            try:
                conn.send(word)
            except OSError:
                raise
            except Exception:  # only a fruit's exception can fail to pickle: sent nothing, told as text
                exc = word[3][1]
                conn.send((*word[:3], ("raised", RuntimeError(f"{type(exc).__name__}: {exc}")), word[4]))
        except OSError:
            return


def _map(name: str, size: int) -> mmap.mmap:
    """The caller's segment ``name`` mapped here without registering it with the resource tracker (the caller
    unlinks it; a worker's registration would unlink it when the worker ends, or warn)."""
    import _posixshmem  # type: ignore[import-not-found]  # POSIX shared memory, as multiprocessing's own

    fd = _posixshmem.shm_open("/" + name, os.O_RDWR, mode=0o600)
    try:
        return mmap.mmap(fd, size)
    finally:
        os.close(fd)


def _warm_up(method: str) -> None:
    """A small synthetic frame's detection with ``method``: the compiled kernels loaded before the first frame."""
    from .detect import detect
    from .evaluate.bench import _bench_scene

    frame, _ = _bench_scene(None, 0)
    detect(frame, method=method)
