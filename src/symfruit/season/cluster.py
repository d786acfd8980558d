"""``detect`` on a Dask cluster: the frames of a recording run as tasks on ``dask.distributed`` workers, with
the batch's guarantees (:func:`symfruit.batch.run_batch`): every frame ends done or recorded in
``errors.json``, ``--resume`` skips finished frames, every file is written atomically, and the fruit tables
(:mod:`symfruit.season.table`) hold each frame's rows exactly once. ``pip install 'symfruit[cluster]'``.

Who does what:

* **The client** (the ``symfruit detect`` process) lists the recording's frames (names only; it decodes
  none), decides which to skip (``--resume``), holds the output folder's lock, and sends tasks of ``chunk``
  frames: each names its frames by index and name, their output folders, and where to read them (a frame
  folder's path; for a bag, the bag's path and the indices, which the worker reads itself). Nothing larger
  than that goes through the scheduler, and no more than a bounded number of frames is ever in flight.
  The client collects each task's small per-frame outcome (done with its table rows, failed with its
  reason, or not reached), writes ``errors.json`` and streams the tables in frame order.
* **A worker** reads its frames, detects, and writes each frame's folder as the serial batch does
  (:func:`symfruit.writers.write_detections`: atomic files, ``detections.json`` last, stale files removed),
  inside the same per-frame error boundary, through the output folder's checks (no links followed, no input
  overwritten) but without its lock, which stays with the client.
* **A worker that dies** (killed, out of memory) has its tasks run again elsewhere by the scheduler. Writing a
  frame is idempotent: a second attempt writes the same files over the first attempt's (atomically; the
  dead attempt's temporary files are removed), and the client takes exactly one outcome per task, so
  nothing is lost or counted twice. A task whose workers die ``distributed.scheduler.allowed-failures`` times
  (default 3: a frame that kills every worker it lands on) is recorded as failed, its frames' folders cleared.

Memory per worker is one frame at a time per worker thread (the worker keeps no frame after its task); a
local cluster (``workers=N``) runs one thread per process under a memory limit its nanny enforces.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import dataclasses
import os
import threading
import time
import uuid
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..batch import (
    BATCH_FILES,
    BatchReport,
    Recording,
    _clear_frame,
    _errors_record,
    _first_part,
    _guarded,
    frame_done,
    frame_folder_name,
    list_recordings,
    once_per_recording,
    plan_recordings,
)
from ..core.limits import shown
from ..detect import detect
from ..errors import InputError, OutputError, SymfruitError
from ..io.frames import is_frame_folder, read_frame
from ..io.outputs import OutputFolder, reserve_record, write_record
from ..io.sources import FolderSource, FrameFolderSource, open_source
from ..io.text import as_path
from ..methods import DEFAULT_METHOD
from ..progress import Progress
from ..settings import Settings
from ..threads import one_blas_thread
from ..writers import detections_record, write_detections
from .table import TABLE_NAME, TableWriter, frame_rows, read_frame_rows

__all__ = [
    "EXTRA",
    "LOCAL_SCHEDULER_HTTP",
    "Job",
    "Outcome",
    "Part",
    "detect_part",
    "local_cluster",
    "require_distributed",
    "run_distributed",
]

#: The optional dependency set that brings dask.distributed.
EXTRA = "symfruit[cluster]"
#: Memory limit of each worker process of a local cluster (its nanny restarts a worker above it).
LOCAL_MEMORY_LIMIT = "2GiB"
#: Dask's statistical profiler off: it keeps a sample of the worker's stacks for every second of the last
#: 1,000 (``distributed.admin.low-level-log-length``), which here grew a worker by about 300 kB a second (300 MB
#: before it levels off); nobody looks at it without the dashboard. For workers you start yourself:
#: ``DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED=False``.
NO_PROFILER = {"distributed.worker.profile.enabled": False}
#: A local scheduler's HTTP server (its health and metrics routes; Dask starts one even without a dashboard) on
#: 127.0.0.1 and a port the system picks: Dask's default is the dashboard's port 8787 (on the scheduler's host,
#: 127.0.0.1 here), taken by the first local cluster of the machine, and every later one warned "Port 8787 is
#: already in use ... Hosting the HTTP server on port N instead" (flake54). ``LocalCluster(...,
#: scheduler_kwargs=LOCAL_SCHEDULER_HTTP)``; the dashboard stays off.
LOCAL_SCHEDULER_HTTP = {"dashboard_address": "127.0.0.1:0"}
#: A local cluster keeps its workers however long one takes to come back: Dask's cluster closes a worker's nanny
#: (and runs on with one worker fewer) when no worker of its name is back within ``lost-worker-timeout`` (15 s) of
#: its death. A worker that dies at once again, or is slow to start (importing symfruit and numba on a loaded
#: machine: 10-20 s), is not back then: a frame that killed every worker it landed on left a cluster of no worker
#: and the run waiting for one for ever (stop 49, robust49). The nanny restarts each worker itself.
KEEP_LOST_WORKERS = {"distributed.deploy.lost-worker-timeout": "3650 days"}
#: How long to try to reach a scheduler before giving up.
CONNECT_TIMEOUT = "10s"
#: How long (s) a run waits while its cluster has no worker at all: for the first worker of a scheduler you
#: started (``--scheduler``; before any task is sent), and at any time during the run, after which the frames not
#: done are recorded ``unprocessed`` and the batch stops (``--resume`` takes them up). A scheduler keeps tasks
#: queued while it has no worker, so the run waited for ever (stop 49, robust50). A local cluster's nannies
#: restart its workers (importing symfruit and numba: 10-20 s on a loaded machine): it gets longer.
NO_WORKER_TIMEOUT = 60.0
LOCAL_NO_WORKER_TIMEOUT = 300.0
#: A worker the scheduler has not heard from (its heartbeat, every 0.5-5 s) for this long (s) counts as none in
#: the watch for workers (:class:`_NoWorkers`), as does one that is paused (its memory above Dask's pause
#: fraction) or closing: registered, such workers kept a run waiting for ever (a paused one) or for the
#: scheduler's ``worker-ttl`` (5 minutes; none if unset) (stop 50 left it; robust51). The default of
#: ``silent_worker_timeout`` (``--silent-worker-timeout``; stop 52, robust52).
SILENT_WORKER_S = 60.0
#: The bounds of ``no_worker_timeout`` (``--no-worker-timeout``, s): a second to a day.
NO_WORKER_TIMEOUT_RANGE = (1.0, 86_400.0)
#: The bounds of ``silent_worker_timeout`` (``--silent-worker-timeout``, s): twice the longest heartbeat Dask
#: gives a worker (5 s, in a large cluster), so that a worker is never taken for silent between two beats, to a day.
SILENT_WORKER_TIMEOUT_RANGE = (10.0, 86_400.0)
#: Frames sent to the cluster and not yet written into the tables, at most: bounds the client's memory and the
#: scheduler's task count however long the recording (with a task that takes long, the others wait at most
#: this far ahead of it).
MAX_AHEAD = 4096
#: Tasks in flight per worker thread (one running, the next ones already there): enough to keep every worker
#: busy, few enough that a worker that dies has little to hand over.
TASKS_PER_THREAD = 3


def check_no_worker_timeout(seconds: Any) -> float:
    """``seconds`` as the wait for a worker (:data:`NO_WORKER_TIMEOUT`), refused outside
    :data:`NO_WORKER_TIMEOUT_RANGE` (NaN, inf, 0, negative, text) before anything is read."""
    return _seconds_within(seconds, "--no-worker-timeout", NO_WORKER_TIMEOUT_RANGE)


def check_silent_worker_timeout(seconds: Any) -> float:
    """``seconds`` as the time after which a worker not heard from counts as none (:data:`SILENT_WORKER_S`),
    refused outside :data:`SILENT_WORKER_TIMEOUT_RANGE` (NaN, inf, below two heartbeats, text) before anything
    is read."""
    return _seconds_within(seconds, "--silent-worker-timeout", SILENT_WORKER_TIMEOUT_RANGE)


def _seconds_within(seconds: Any, option: str, bounds: tuple[float, float]) -> float:
    low, high = bounds
    if isinstance(seconds, bool) or not isinstance(seconds, int | float) or not low <= seconds <= high:
        raise InputError(f"{option} must be between {low:g} and {high:g} s, got {shown(seconds)}")
    return float(seconds)


def require_distributed() -> Any:
    """The ``distributed`` module, or an :class:`~symfruit.errors.InputError` naming the extra to install."""
    try:
        import distributed
    except ImportError:
        raise InputError(f"running on a Dask cluster needs dask.distributed: pip install '{EXTRA}'") from None
    return distributed


@dataclass(frozen=True)
class Job:
    """What every task of a run shares (small: paths, names and the settings)."""

    run: str
    source: str  # absolute path of the recording
    shown: str  # the recording's path as the user gave it (frames' ``source`` field, as a serial run writes it)
    output: str  # absolute path of the output folder
    recording: str
    inputs: tuple[str, ...]  # files a worker must not write over
    input_folders: tuple[str, ...]  # folders a worker must not write into
    exclude: tuple[str, ...]
    masks: str = "auto"
    method: str = DEFAULT_METHOD
    settings: Settings = field(default_factory=Settings)
    client: int = 0  # the client's process id: a worker in that process (an in-process cluster) leaves its BLAS be


@dataclass(frozen=True)
class Part:
    """One task: frames by index and name, each frame's output folder, and (a folder of frames) the frame
    folders to read; else the worker opens the recording and reads the indices. ``base``: where the
    recording's frames start in the run's list of frames (several recordings), for the client."""

    indices: tuple[int, ...]
    names: tuple[str, ...]
    folders: tuple[str, ...]
    frames: tuple[str, ...] | None = None
    base: int = 0


@dataclass(frozen=True)
class Outcome:
    """What became of one frame of a task: ``status`` ``done`` (with its table rows), ``failed`` (``reason``)
    or ``unprocessed`` (its task stopped on a full disk first); ``stop``: why the batch must stop."""

    index: int
    name: str
    status: str
    reason: str = ""
    stop: str = ""
    frame: dict[str, Any] | None = None
    fruits: list[dict[str, Any]] = field(default_factory=list)
    #: symfruit's warnings the frame gave on its worker, given again by the client (:func:`_hold_warnings`)
    warned: tuple[str, ...] = ()


# --- the worker's side ---------------------------------------------------------------------------------------

#: Recordings a worker has open, per (run, recording, thread): a bag is indexed once per worker thread (again
#: when a thread moves on to another recording and back).
_OPEN: dict[tuple[str, str, int], tuple[Any, list[str]]] = {}
_OPEN_LOCK = threading.Lock()


def _opened(job: Job) -> tuple[Any, list[str]]:
    """The recording opened by this worker thread for ``job`` (cached for the run), and its frame names."""
    key = (job.run, job.source, threading.get_ident())
    with _OPEN_LOCK:
        if key in _OPEN:
            return _OPEN[key]
    stale = []
    with _OPEN_LOCK:  # one recording open per worker thread: a run over many bags holds few files open
        for other in [k for k in _OPEN if k != key and k[2] == key[2]]:
            stale.append(_OPEN.pop(other)[0])
    for src in stale:
        with contextlib.suppress(Exception):
            src.close()
    src = open_source(job.source, exclude=[Path(p) for p in job.exclude])
    entry = (src, src.names())
    with _OPEN_LOCK:
        _OPEN[key] = entry
    return entry


def forget(run: str) -> int:
    """Close the recordings this worker opened for ``run``; the number closed (run on every worker at the end)."""
    with _OPEN_LOCK:
        mine = [_OPEN.pop(k)[0] for k in [k for k in _OPEN if k[0] == run]]
    for src in mine:
        with contextlib.suppress(Exception):
            src.close()
    return len(mine)


def _read(job: Job, part: Part, k: int) -> Any:
    """Frame ``k`` of ``part``, its ``source`` spelled as in a serial run."""
    if part.frames is not None:
        frame = read_frame(part.frames[k])
    else:
        src, names = _opened(job)
        index = part.indices[k]
        if index >= len(names) or names[index] != part.names[k]:
            raise InputError(f"{job.source}: frame {index} is not {part.names[k]} on this worker: the recording "
                             "differs from the one the client listed (workers must see the same files)")  # fmt: skip
        frame = src.read(index)
    if frame.source.startswith(job.source) and job.shown != job.source:
        frame = dataclasses.replace(frame, source=job.shown + frame.source[len(job.source) :])
    return frame


#: The process that limited its BLAS to one thread (:func:`_one_blas_thread`): a process forked from it has not.
_BLAS_LIMITED_IN = 0


def _one_blas_thread(job: Job) -> None:
    """A worker process's first task limits its BLAS to one thread (:func:`symfruit.threads.one_blas_thread`): a
    worker started without a nanny (``dask worker --no-nanny``) ran numpy's OpenBLAS on every core, two such
    workers on two cores 1.1-1.6x the CPU of one thread each (robust53; a nanny's workers already run one).
    Not in the client's own process (a Python caller's in-process cluster), nor for a job that names no client
    (one a caller made without :func:`run_distributed`): its BLAS is the caller's."""
    global _BLAS_LIMITED_IN
    if _BLAS_LIMITED_IN == os.getpid() or not job.client or os.getpid() == job.client:
        return
    _BLAS_LIMITED_IN = os.getpid()
    one_blas_thread()


#: The warnings a worker thread's frame gives, held for its :class:`Outcome` while the frame runs (None: not held).
_HELD = threading.local()


def _hold_warnings() -> None:
    """Once a process (again where something put its own in place since): symfruit's warnings given while a frame
    runs on a worker thread are held for the frame's :class:`Outcome` and given again by the client, as a serial
    run gives them (``symfruit: warning: ...``, each once a recording: :func:`symfruit.batch.once_per_recording`). A
    worker process printed them itself in Python's form, its file, line and a line of symfruit's source, one a
    frame (robust55). Other warnings, and any given outside a frame, are shown as before."""
    import warnings

    from ..errors import SymfruitWarning

    show = warnings.showwarning
    if getattr(show, "_symfruit_held", False):
        return

    def held(message: Any, category: type[Warning], filename: str, lineno: int, file: Any = None,
             line: str | None = None) -> None:  # fmt: skip
        into = getattr(_HELD, "into", None)
        if into is not None and issubclass(category, SymfruitWarning):
            into.append(str(message))
        else:
            show(message, category, filename, lineno, file, line)

    held._symfruit_held = True  # type: ignore[attr-defined]
    warnings.showwarning = held


def detect_part(job: Job, part: Part) -> list[Outcome]:
    """The task: detect and write every frame of ``part``, each in its own error boundary; returns one
    :class:`Outcome` per frame. Runs on a worker; never raises for a frame."""
    _one_blas_thread(job)
    _hold_warnings()
    outcomes: list[Outcome] = []
    stop = ""
    with OutputFolder(job.output, inputs=job.inputs, input_folders=job.input_folders, lock=False) as out:
        for k, (index, name, folder) in enumerate(zip(part.indices, part.names, map(Path, part.folders), strict=True)):
            if stop:
                outcomes.append(Outcome(index, name, "unprocessed"))
                continue
            failed: dict[str, str] = {}

            def one_frame(k: int = k, folder: Path = folder) -> Any:
                found = detect(_read(job, part, k), masks=job.masks, method=job.method, settings=job.settings)
                write_detections(folder, found, settings=job.settings)
                return frame_rows(detections_record(found), job.recording)

            def clear(folder: Path = folder) -> None:
                _clear_frame(folder, out)

            warned: list[str] = []
            _HELD.into = warned
            try:
                done, rows, stop = _guarded(one_frame, item=name, failed=failed, target=folder, at=f"frame {name}",
                                            cleanup=clear)  # fmt: skip
            finally:
                _HELD.into = None
            if done and rows is not None:
                outcomes.append(Outcome(index, name, "done", frame=rows[0], fruits=rows[1], warned=tuple(warned)))
            else:
                outcomes.append(Outcome(index, name, "failed", reason=failed.get(name, "failed"), stop=stop,
                                        warned=tuple(warned)))  # fmt: skip
    return outcomes


def worker_peak_mb() -> float:
    """This process's peak resident memory (MB): its ``VmHWM``, else ``ru_maxrss``."""
    import resource

    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    with contextlib.suppress(OSError, ValueError):
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                peak = int(line.split()[1]) / 1024.0
    return peak


# --- the client's side ---------------------------------------------------------------------------------------


def local_cluster(workers: int, *, memory_limit: str = LOCAL_MEMORY_LIMIT) -> Any:
    """A local Dask cluster of ``workers`` worker processes, one thread each, bound to 127.0.0.1 (no dashboard, the
    scheduler's HTTP server on a free port: :data:`LOCAL_SCHEDULER_HTTP`; no profiler: :data:`NO_PROFILER`), each
    restarted by its nanny if it dies or outgrows ``memory_limit``."""
    import logging

    require_distributed()
    from distributed import LocalCluster

    if not 1 <= workers <= 256:
        raise InputError(f"--workers must be between 1 and 256, got {workers}")
    import dask

    with dask.config.set(NO_PROFILER):  # the nannies keep this config for the workers they restart
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                            dashboard_address=None, scheduler_kwargs=dict(LOCAL_SCHEDULER_HTTP),
                            memory_limit=memory_limit, silence_logs=logging.ERROR)  # fmt: skip


#: The address schemes symfruit can reach a scheduler by (dask.distributed's, less ``ucx``, which needs a package
#: of its own, and ``inproc``, checked apart).
SCHEMES = ("tcp", "tls", "ws", "wss")


def check_address(scheduler: Any) -> None:
    """Refuse a scheduler address that cannot be one before trying it for :data:`CONNECT_TIMEOUT`: empty (an
    unset shell variable), a port that is not 1-65535 (``tcp://HOST:PORT``), a scheme Dask has no connector for
    here (``udp://``, ``ucx://``), ``tls://`` or ``wss://`` without Dask's TLS settings, or an in-process address
    (``inproc://``) of another process or not of the form Dask writes (``inproc://HOST/PID/N``)."""
    text = str(scheduler).strip()
    if not text:
        raise InputError("--scheduler '': an empty address (an unset shell variable?); give tcp://HOST:PORT")
    scheme, sep, rest = text.partition("://")
    scheme = scheme if sep else "tcp"  # distributed's schemes are lower case: ``TCP://`` is none
    rest = rest if sep else text
    if scheme == "inproc":
        # distributed splits the rest in three and says "not enough values to unpack" if it cannot; an in-process
        # scheduler is one of this process (a Python caller's LocalCluster(processes=False)), never the CLI's
        pid = rest.rpartition("/")[0].rpartition("/")[2]
        if not (pid.isascii() and pid.isdigit() and int(pid) == os.getpid()):
            raise InputError(f"--scheduler {shown(text)}: an in-process (inproc://) address is reachable only from "
                             "the Python process that started that scheduler; give tcp://HOST:PORT")  # fmt: skip
        return
    if scheme not in SCHEMES:
        raise InputError(f"--scheduler {shown(text)}: not an address scheme symfruit can use ({shown(scheme, 12)}); "
                         "give tcp://HOST:PORT (or tls://, ws://, wss://)")  # fmt: skip
    _, colon, port = rest.rpartition(":")
    # ASCII digits only: str.isdigit() takes full-width and other scripts' digits and int() reads them, so a
    # mistyped port passed as another; ``8786`` alone has no port (distributed: "missing port number")
    if not colon or not (port.isascii() and port.isdigit()) or not 1 <= int(port) <= 65535:
        raise InputError(f"--scheduler {shown(text)}: not a scheduler address; give tcp://HOST:PORT, the port 1-65535")
    # a host no name or address can be (robust55): distributed said "invalid address '[::1'; maybe: ipv6 needs
    # brackets like [::1]" of one with a bracket, Python's "encoding with 'idna' codec failed (UnicodeError: label
    # too long)" of a part over DNS's 63 characters
    host = rest.rpartition(":")[0]  # "" (tcp://:8786) is this machine's, as the system takes it
    named = host.removesuffix(".")  # a fully qualified name may end in a dot
    bracketed = host.startswith("[")
    if (
        bracketed != host.endswith("]")
        or host == "[]"
        or (host and not bracketed and (len(named) > 253 or any(not 0 < len(p) <= 63 for p in named.split("."))))
    ):
        raise InputError(f"--scheduler {shown(text)}: not a scheduler address; its host {shown(host)} is no host "
                         "name (at most 253 characters, 1-63 between dots) nor address (IPv6 in brackets, "
                         "[::1])")  # fmt: skip
    if scheme in ("tls", "wss"):
        distributed = require_distributed()
        if distributed.Security().get_connection_args("client").get("ssl_context") is None:
            # distributed: "TLS expects a `ssl_context` argument of type ssl.SSLContext ..." as a traceback
            raise InputError(f"--scheduler {shown(text)}: {scheme}:// needs Dask's TLS settings (distributed.comm."
                             "tls.ca-file, .client.cert, .client.key), and none are set; set them or give "
                             "tcp://HOST:PORT")  # fmt: skip


@contextlib.contextmanager
def _client(scheduler: str | None, workers: int | None) -> Iterator[Any]:
    distributed = require_distributed()
    if scheduler is not None:
        try:
            client = distributed.Client(scheduler, timeout=CONNECT_TIMEOUT)
        except (OSError, TimeoutError, ValueError, TypeError) as exc:
            reason = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
            reason = reason if len(reason) <= 160 else reason[:157] + "..."
            raise InputError(f"{scheduler}: cannot reach the Dask scheduler ({reason})") from None
        with client:
            yield client
        return
    import dask

    with (
        dask.config.set(KEEP_LOST_WORKERS),
        local_cluster(int(workers or 1)) as cluster,
        distributed.Client(cluster) as client,
    ):
        yield client


def run_distributed(
    source: str | Path | Sequence[str | Path],
    output: str | Path,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    chunk: int = 4,
    masks: str = "auto",
    method: str = DEFAULT_METHOD,
    settings: Settings | None = None,
    resume: bool = False,
    progress: bool = True,
    exclude: Sequence[str | Path] = (),
    max_ahead: int = MAX_AHEAD,
    no_worker_timeout: float | None = None,
    silent_worker_timeout: float | None = None,
) -> BatchReport:
    """:func:`symfruit.batch.run_batch` on a Dask cluster: an existing one (``scheduler``, its address) or a
    local one of ``workers`` processes; ``chunk`` frames per task (see the module docstring). ``source``: one
    recording or several, laid out as :func:`symfruit.batch.run_batch` does (a task holds frames of one
    recording). ``no_worker_timeout`` (s; default :data:`NO_WORKER_TIMEOUT` for a scheduler,
    :data:`LOCAL_NO_WORKER_TIMEOUT` for a local cluster): how long the run waits while the cluster has no worker.
    ``silent_worker_timeout`` (s; default :data:`SILENT_WORKER_S`): a worker the scheduler has not heard from for
    that long counts as none (:func:`working_workers`).

    Raises
    ------
    SymfruitError
        When the recording cannot be opened (one; several: as :func:`symfruit.batch.plan_recordings` says),
        the output folder cannot be used, dask.distributed is missing or the scheduler cannot be reached;
        per-frame problems go into the report.
    """
    if (scheduler is None) == (workers is None):
        raise InputError("give either a scheduler address or a number of local workers")
    if scheduler is not None:
        check_address(scheduler)
    if not 1 <= chunk <= 10_000:
        raise InputError(f"--chunk must be between 1 and 10000 frames per task, got {chunk}")
    if workers is not None and not 1 <= workers <= 256:  # refused before the inputs are read, not taken as 1
        raise InputError(f"--workers must be between 1 and 256, got {workers}")
    if no_worker_timeout is None:
        no_worker_timeout = NO_WORKER_TIMEOUT if scheduler is not None else LOCAL_NO_WORKER_TIMEOUT
    no_worker_timeout = check_no_worker_timeout(no_worker_timeout)
    silent_s = check_silent_worker_timeout(SILENT_WORKER_S if silent_worker_timeout is None else silent_worker_timeout)
    if not isinstance(masks, str):
        raise InputError("on a Dask cluster the mask source must be a spec (auto, color, a file, maskrcnn:, onnx:)")
    require_distributed()
    settings = settings or Settings()
    output = as_path(output, "run_distributed: the output folder")  # '' was the working folder
    report = BatchReport()
    reserved = [*BATCH_FILES, *(_first_part(Path(p), output) for p in exclude)]
    recordings = plan_recordings(source, output, reserved=reserved)
    if len(recordings) > 1:
        report.recordings = {str(r.source): r.name for r in recordings}
    skip = [output, *map(Path, exclude)]
    seen: dict[str, tuple[list[str] | None, list[Path], list[Path]]] = {}

    def inspect(rec: Recording, src: Any, files: list[Path], folders: list[Path]) -> None:
        """What the workers need of a recording: its frame folders to read directly (none for a bag), and the
        files and folders they must not write into."""
        direct = [str(Path(p).absolute()) for p in src.folders()] if isinstance(src, FolderSource) else None
        if isinstance(src, FrameFolderSource):
            direct = [str(Path(src.path).absolute())]
        seen[rec.name] = (direct, files, folders)

    listed, files, folders, _ = list_recordings(recordings, skip, report, inspect=inspect)  # the client decodes none
    if is_frame_folder(output):
        folders.append(output)
    out = OutputFolder(output, inputs=files, input_folders=folders).open()
    run = uuid.uuid4().hex
    tops = [os.path.realpath(r.source) for r in recordings]
    jobs: list[Job] = []
    keys: list[str] = []
    raw: list[str] = []
    owner: list[int] = []
    target: list[Path] = []
    direct: list[str | None] = []
    bases: list[int] = []
    for rec, names in listed:
        rec_direct, rec_files, rec_folders = seen[rec.name]
        if is_frame_folder(output):
            rec_folders = [*rec_folders, output]
        jobs.append(Job(run=run, source=str(rec.source.absolute()), shown=str(rec.source),
                        output=str(output.absolute()), recording=rec.name,
                        inputs=tuple(dict.fromkeys([*(os.path.realpath(p) for p in rec_files), *tops])),
                        input_folders=tuple(dict.fromkeys([*(os.path.realpath(p) for p in rec_folders), *tops])),
                        exclude=tuple(str(Path(p).absolute()) for p in skip), masks=masks, method=method,
                        settings=settings, client=os.getpid()))  # fmt: skip
        bases.append(len(keys))
        keys += [rec.key + n for n in names]
        raw += names
        owner += [len(jobs) - 1] * len(names)
        target += [rec.folder / frame_folder_name(n, reserved) for n in names]
        direct += rec_direct if rec_direct is not None else [None] * len(names)
    try:
        done_before = {i for i in range(len(keys)) if resume and frame_done(target[i], raw[i])}
        todo = [i for i in range(len(keys)) if i not in done_before]
        with contextlib.ExitStack() as stack:
            client = stack.enter_context(_client(scheduler, workers)) if todo else None
            if client is not None:
                _preflight(client, jobs, scheduler, no_worker_timeout)
            reserve_record(output / "errors.json", _errors_record({}, keys, "the batch is running (or was killed)",
                           report.failed_recordings, recordings), entries=len(keys), root=out)  # fmt: skip
            with Progress(len(keys), "detect", enabled=progress and len(keys) > 1) as bar:
                if done_before:
                    bar.update(len(done_before))
                frames = _Frames(jobs, bases, keys, raw, owner, target, direct)
                try:
                    named = {v: k for k, v in report.recordings.items()}
                    # the workers' warnings given here, each once (robust55), as run_batch gives a recording's
                    said = str(recordings[0].source) if len(recordings) == 1 else f"{len(recordings)} recordings"
                    with TableWriter(output, root=out, inputs=named) as table, once_per_recording(said) as current:
                        _run(frames, client, todo, done_before, chunk, max_ahead, report, table, bar, out,
                             no_worker_timeout, silent_s, current)  # fmt: skip
                except OutputError as exc:
                    report.stopped = report.stopped or f"cannot write {output / TABLE_NAME} ({exc})"
            if client is not None:
                with contextlib.suppress(Exception):
                    client.run(forget, run)
        try:
            how = write_record(output / "errors.json", _errors_record(report.failed, report.unprocessed,
                               report.stopped, report.failed_recordings, recordings), root=out)  # fmt: skip
            if how and report.stopped:
                report.stopped += f"; errors.json {how}"
        except SymfruitError as exc:
            report.stopped = report.stopped or f"cannot write {output / 'errors.json'} ({exc})"
    finally:
        out.close()
    return report


@dataclass(frozen=True)
class _Frames:
    """Every frame of a run, over its recordings in order: its key in the report (``rec/frame`` with several
    recordings), its name in its recording, its recording's :class:`Job` (``owner``, an index into ``jobs``),
    its output folder, and its frame folder when a worker reads it directly (else ``None``: a bag);
    ``bases``: where each recording's frames start."""

    jobs: list[Job]
    bases: list[int]
    keys: list[str]
    raw: list[str]
    owner: list[int]
    target: list[Path]
    direct: list[str | None]


def _parts(todo: Sequence[int], chunk: int, owner: Sequence[int] | None = None) -> Iterator[list[int]]:
    """Runs of up to ``chunk`` frame indices, in order, each of one recording (``owner``)."""
    run: list[int] = []
    for i in todo:
        if run and (len(run) == chunk or (owner is not None and owner[i] != owner[run[0]])):
            yield run
            run = []
        run.append(i)
    if run:
        yield run


def _run(
    frames: _Frames, client: Any, todo: list[int], done_before: set[int], chunk: int, max_ahead: int,
    report: BatchReport, table: TableWriter, bar: Progress, out: OutputFolder,
    no_worker_timeout: float = NO_WORKER_TIMEOUT, silent_s: float = SILENT_WORKER_S, current: list[str] | None = None,
) -> None:  # fmt: skip
    """Send the parts (at most ``max_ahead`` frames beyond the last one in the tables), collect their outcomes,
    and write the tables in frame order; stop, the frames not done unprocessed, once the cluster has had no worker
    (none heard from within ``silent_s`` seconds) for ``no_worker_timeout`` seconds (:class:`_NoWorkers`)."""
    keys, target = frames.keys, frames.target
    results: dict[int, Outcome] = {}  # outcomes not yet in the tables, by frame index (in the run)
    state = {"flushed": 0, "sent": 0, "stopped": False}  # frames below "flushed" are in the report and tables

    def flush() -> None:
        while state["flushed"] < len(keys):
            i = state["flushed"]
            if i in done_before:
                try:
                    table.add(*read_frame_rows(target[i] / "detections.json", frames.jobs[frames.owner[i]].recording))
                    report.skipped.append(keys[i])
                except SymfruitError as exc:
                    report.failed[keys[i]] = f"{exc} (left out of {TABLE_NAME})"
            elif i in results:
                _record(results.pop(i), keys[i], report, table, current)
            elif i >= state["sent"] and state["stopped"]:
                report.unprocessed.append(keys[i])
            else:
                return  # still running
            state["flushed"] += 1

    if client is not None:
        distributed = require_distributed()
        parts = _parts(todo, chunk, frames.owner)
        pending = distributed.as_completed()
        part_of: dict[Any, Part] = {}
        window = {"tasks": 0, "at": -1.0}
        watch = _NoWorkers(client, no_worker_timeout, silent_s)

        def room() -> bool:
            """Whether another task may go: within the frames ahead, and within the tasks the workers can
            take (their thread count, asked again every second as workers come and go)."""
            if time.monotonic() - window["at"] > 1.0:
                threads = sum(client.nthreads().values())
                window["tasks"], window["at"] = max(TASKS_PER_THREAD * threads, 2), time.monotonic()
            return state["sent"] - state["flushed"] < max_ahead and len(part_of) < window["tasks"]

        def send() -> None:
            while not state["stopped"] and not watch.gone.is_set() and room():
                indices = next(parts, None)
                if indices is None:
                    state["sent"] = len(keys)
                    return
                j = frames.owner[indices[0]]
                base = frames.bases[j]
                direct = frames.direct[indices[0]]
                part = Part(tuple(i - base for i in indices), tuple(frames.raw[i] for i in indices),
                            tuple(str(target[i].absolute()) for i in indices),
                            None if direct is None else tuple(str(frames.direct[i]) for i in indices),
                            base)  # fmt: skip
                future = client.submit(detect_part, frames.jobs[j], part,
                                       key=f"symfruit-detect-{frames.jobs[j].run}-{indices[0]}")  # fmt: skip
                part_of[future.key] = part
                watch.track(future)
                pending.add(future)
                state["sent"] = indices[-1] + 1

        # frames of a task whose workers died (KilledWorker): each is run again alone once nothing else of the run
        # is in flight, so that only a frame that kills its worker by itself is lost, not its task's other frames
        # nor the tasks that were queued on the same worker (the scheduler counts a death against all of them)
        suspects: list[int] = []
        alone: set[str] = set()
        with watch:
            send()
            while True:
                for future in pending:
                    part = part_of.pop(future.key)
                    # tracked until its outcome is in: a result lost with the last worker before it was gathered
                    # is rescheduled by the client, and only the watch's cancel ends the wait for it
                    got = None if future.cancelled() else _outcomes(future, part, distributed)
                    watch.untrack(future)
                    if got is None:  # cancelled by the watch (no worker): not run, not failed
                        _unprocessed(part, watch.reason, state, report, results)
                        flush()
                        continue
                    outcomes, whole = got
                    killed = whole and future.key not in alone and outcomes[0].reason.startswith(_DIED)
                    future.release()
                    for o in outcomes:
                        i = part.base + o.index
                        if whole:  # the task died as a whole: what its attempts left is no result
                            _clear_frame(target[i], out)
                        if killed:
                            suspects.append(i)
                            continue
                        results[i] = o
                        if o.stop and not state["stopped"]:
                            state["stopped"] = True
                            report.stopped = o.stop
                    if not killed:
                        bar.update(len(part.indices))
                    flush()
                    if not suspects:
                        send()
                if not suspects:
                    break
                i = suspects.pop(0)
                j = frames.owner[i]
                base = frames.bases[j]
                direct = frames.direct[i]
                part = Part((i - base,), (frames.raw[i],), (str(target[i].absolute()),),
                            None if direct is None else (str(direct),), base)  # fmt: skip
                if watch.gone.is_set():
                    _unprocessed(part, watch.reason, state, report, results)
                    continue
                future = client.submit(
                    detect_part, frames.jobs[j], part, key=f"symfruit-detect-{frames.jobs[j].run}-{i}-alone"
                )
                alone.add(future.key)
                part_of[future.key] = part
                watch.track(future)
                pending.add(future)
    state["stopped"] = True
    flush()


class _NoWorkers:
    """Watches a run's cluster from a thread of its own (every second, while the run lives): once it has had no
    worker that can run a task (:func:`working_workers`: none, or all paused or silent) for ``timeout`` seconds,
    :attr:`gone` is set and the run's tasks (:meth:`track`) are cancelled, so that the client, which waits on
    them, goes on; it records their frames unprocessed (:func:`_unprocessed`). A scheduler keeps tasks queued
    while it has no worker: without this the run waited for ever."""

    def __init__(self, client: Any, timeout: float, silent_s: float = SILENT_WORKER_S) -> None:
        self.client, self.timeout, self.silent_s = client, timeout, silent_s
        self.gone, self._done = threading.Event(), threading.Event()
        self._futures: dict[Any, Any] = {}
        self._lock = threading.Lock()
        self._thread = threading.Thread(target=self._watch, name="symfruit-no-workers", daemon=True)
        address = getattr(getattr(client, "scheduler", None), "address", None) or "the scheduler"
        self.reason = (f"the Dask cluster ({address}) had no worker for {timeout:g} s: the frames not done are "
                       "unprocessed; start workers and run again with --resume")  # fmt: skip

    def __enter__(self) -> _NoWorkers:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._done.set()
        self._thread.join()

    def track(self, future: Any) -> None:
        with self._lock:
            self._futures[future.key] = future

    def untrack(self, future: Any) -> None:
        with self._lock:
            self._futures.pop(future.key, None)

    def _watch(self) -> None:
        since: float | None = None
        heard: dict[str, tuple[Any, float]] = {}
        while not self._done.wait(1.0):
            if not self.gone.is_set():
                try:
                    info = self.client.scheduler_info(n_workers=-1).get("workers", {})
                except Exception:  # the scheduler itself gone: the client's own errors reach the run
                    continue
                workers = working_workers(info, heard, time.monotonic(), self.silent_s)
                since = None if workers else since if since is not None else time.monotonic()
                if since is None or time.monotonic() - since < self.timeout:
                    continue
                self.gone.set()
            with self._lock:  # every tick once gone: a task sent just before the run saw it is cancelled too
                futures = list(self._futures.values())
            if futures:
                with contextlib.suppress(Exception):
                    self.client.cancel(futures)


def working_workers(info: dict[str, Any], heard: dict[str, tuple[Any, float]], now: float,
                    silent_s: float | None = None) -> int:  # fmt: skip
    """How many of the scheduler's workers (``info``: its identity's ``workers``) can run a task: status
    ``running`` (not paused, closing, ...), and heard from (their ``last_seen`` changed) within ``silent_s``
    (default :data:`SILENT_WORKER_S`) of ``now`` (the caller's monotonic clock: the scheduler's may be another
    host's).
    ``heard`` (address: (last_seen, when it last changed)) is kept between calls."""
    for gone in heard.keys() - info.keys():
        del heard[gone]
    count = 0
    for address, worker in info.items():
        seen = worker.get("last_seen")
        if address not in heard or heard[address][0] != seen:
            heard[address] = (seen, now)
        silent = seen is not None and now - heard[address][1] > (SILENT_WORKER_S if silent_s is None else silent_s)
        # a Dask that states no status or last_seen (an older one) is taken as running and heard from
        if worker.get("status", "running") == "running" and not silent:
            count += 1
    return count


def _unprocessed(part: Part, reason: str, state: dict[str, Any], report: BatchReport,
                 results: dict[int, Outcome]) -> None:  # fmt: skip
    """Record a part's frames unprocessed and stop the run (no worker to run them)."""
    for index, name in zip(part.indices, part.names, strict=True):
        results[part.base + index] = Outcome(index, name, "unprocessed")
    if not state["stopped"]:
        state["stopped"] = True
        report.stopped = reason


def _record(o: Outcome, key: str, report: BatchReport, table: TableWriter, current: list[str] | None = None) -> None:
    """Put one frame's outcome into the report (as ``key``) and its rows into the tables; the warnings it gave on
    its worker are given here (``current``: :func:`symfruit.batch.once_per_recording`'s frame name, set to the
    frame's)."""
    if o.warned:
        import warnings

        from ..errors import SymfruitWarning

        if current is not None:
            current[0] = o.name
        for text in o.warned:
            warnings.warn(text, SymfruitWarning, stacklevel=2)
    if o.status == "done" and o.frame is not None:
        table.add(o.frame, o.fruits)
        report.done.append(key)
        report.fruits += sum(f["error"] is None for f in o.fruits)
        report.failed_fruits += sum(f["error"] is not None for f in o.fruits)
    elif o.status == "failed":
        report.failed[key] = o.reason
    else:
        report.unprocessed.append(key)


def _worker_check(sources: Sequence[str], output: str) -> dict[str, Any]:
    """Run on every worker before the first task: its symfruit version and the run's paths it does not see."""
    from .. import __version__

    return {"version": __version__, "missing": [p for p in [*sources, output] if not os.path.exists(p)]}


def _preflight(client: Any, jobs: Sequence[Job], scheduler: str | None = None,
               timeout: float = NO_WORKER_TIMEOUT) -> None:  # fmt: skip
    """Refuse a cluster whose workers cannot run these jobs: no worker within ``timeout`` seconds (a scheduler
    you started), symfruit missing or of another version, or a recording or the output folder not at the same path
    on a worker."""
    from .. import __version__

    if not client.nthreads():
        try:
            client.wait_for_workers(1, timeout=timeout)
        except TimeoutError:  # distributed's WorkerStartTimeoutError: "Only 0/1 workers arrived after 60"
            where = f"{scheduler}: the Dask scheduler" if scheduler else "the local Dask cluster"
            raise InputError(f"{where} has no worker (waited {timeout:g} s for one, --no-worker-timeout); start "
                             f"workers, dask worker {scheduler or 'ADDRESS'}, or give --workers N for a local "
                             "cluster") from None  # fmt: skip

    try:
        checks = client.run(_worker_check, [job.source for job in jobs], jobs[0].output)
    except Exception as exc:  # unpickling symfruit's function fails on a worker without symfruit
        raise InputError(f"the Dask workers cannot run symfruit ({type(exc).__name__}: {exc}); install "
                         f"'{EXTRA}' where the workers run") from None  # fmt: skip
    for worker, check in sorted(checks.items()):
        if check["version"] != __version__:
            raise InputError(f"Dask worker {worker} runs symfruit {check['version']}, this client {__version__}: "
                             "install the same version on both")  # fmt: skip
        for path in check["missing"][:1]:
            raise InputError(
                f"{path}: Dask worker {worker} does not see it; workers must see the recording "
                "and the output folder at the same paths as this client (a shared file system)"
            )


#: How the reason of a frame whose workers died begins.
_DIED = "the workers running this frame died"


def _outcomes(future: Any, part: Part, distributed: Any) -> tuple[list[Outcome], bool] | None:
    """The outcomes of a finished task, and whether it failed as a whole (each of its frames failed then); None
    when it was cancelled (only :class:`_NoWorkers` cancels a run's tasks), also while its result was awaited."""
    try:
        return list(future.result()), False
    except (concurrent.futures.CancelledError, asyncio.CancelledError):
        return None
    except distributed.scheduler.KilledWorker as exc:
        times = getattr(exc, "allowed_failures", 3) + 1
        reason = f"{_DIED} {times} times, the last {times} running it alone (killed or out of memory)"
    except Exception as exc:  # the task as a whole: e.g. a worker that cannot unpickle it
        reason = f"the task failed on its worker ({type(exc).__name__}: {exc})"
    return [Outcome(i, n, "failed", reason=reason) for i, n in zip(part.indices, part.names, strict=True)], True
