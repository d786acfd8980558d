"""detect on a Dask cluster: a local cluster of two worker processes on 127.0.0.1, one of them killed while it
works on a frame, gives the serial run's detections frame for frame and tables with each fruit once, also
after --resume; the client refuses what the workers could not do."""

import contextlib
import dataclasses
import importlib.util
import json
import os
import shutil
import signal
import threading
import time
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from symfruit import InputError
from symfruit.batch import run_batch
from symfruit.cli import main
from symfruit.season.cluster import LOCAL_SCHEDULER_HTTP, local_cluster, run_distributed

from ..conftest import small_frame

#: Exec'd on every worker: the first attempt at frame FRAME writes its worker's pid to MARKER (atomically, by a
#: hard link that only one attempt can make) and waits to be killed; any later attempt goes on as usual.
BLOCK_ONE_FRAME = """
import os, time
import symfruit.season.cluster as cluster

real = cluster.detect


def detect(frame, **kwargs):
    if frame.name == FRAME:
        tmp = f"{MARKER}.{os.getpid()}"
        with open(tmp, "w") as handle:
            handle.write(str(os.getpid()))
        try:
            os.link(tmp, MARKER)
        except FileExistsError:
            return real(frame, **kwargs)
        time.sleep(60)  # killed long before
    return real(frame, **kwargs)


cluster.detect = detect
"""


def _fruits(folder: Path) -> dict:
    out = {}
    for path in sorted(folder.glob("*/detections.json")):
        data = json.loads(path.read_text())
        out[path.parent.name] = [{k: v for k, v in f.items() if k != "seconds"} for f in data["fruits"]]
    return out


def _wait_for(check, seconds: float, what: str):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        value = check()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"waited {seconds} s for {what}")


#: one worker of the test run starts the module's local cluster once (pytest-xdist, --dist loadgroup), and only it
#: imports dask.distributed (inside the tests: not at collection)
pytestmark = [
    pytest.mark.skipif(importlib.util.find_spec("distributed") is None, reason="needs dask.distributed"),
    pytest.mark.xdist_group("cluster"),
]


@pytest.fixture(scope="module")
def cluster():
    """A local cluster of two worker processes, shared by the tests that need a running one (starting one
    costs a few seconds); each test leaves it with two workers running symfruit's own code."""
    with local_cluster(2) as running:
        yield running


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """Four copies of the small frame (the shipped frame's right-hand strawberry: conftest.small_frame)."""
    rec = tmp_path_factory.mktemp("cluster") / "rec"
    for k in range(4):
        shutil.copytree(small_frame(), rec / f"scene_{k:05d}")
    return rec


@contextlib.contextmanager
def _one_worker(recording, out: Path, **options):
    """An in-process cluster of one worker on 127.0.0.1 and ``run_distributed`` of ``recording`` into ``out`` on
    it in a thread (chunk 1, method raw, --no-worker-timeout 2 and ``options``): yields the cluster, the thread
    (for the test to start, once what it patches knows the cluster) and the dict its report lands in
    (``report``). The three tests whose one worker leaves, pauses or falls silent share it (robust53)."""
    from distributed import LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp://", host="127.0.0.1",
                      dashboard_address=None, scheduler_kwargs=LOCAL_SCHEDULER_HTTP) as one:  # fmt: skip
        result: dict = {}
        runner = threading.Thread(target=lambda: result.update(report=run_distributed(
            recording, out, scheduler=one.scheduler_address, chunk=1, method="raw", progress=False,
            no_worker_timeout=2, **options)), daemon=True)  # fmt: skip
        yield one, runner, result


def _stopped_with_the_rest_unprocessed(report, address: str, out: Path) -> None:
    """The run stopped for want of a worker after 2 s, nothing failed, the frames not done recorded unprocessed
    (``--resume`` takes them up) in errors.json."""
    assert report.stopped.startswith(f"the Dask cluster ({address}) had no worker for 2 s")
    assert not report.failed
    assert report.unprocessed and len(report.done) + len(report.unprocessed) == 4
    errors = json.loads((out / "errors.json").read_text())
    assert sorted(errors["unprocessed"]) == sorted(report.unprocessed)


def test_a_worker_killed_mid_frame_loses_nothing_and_writes_nothing_twice(cluster, recording, tmp_path, capsys):
    import distributed

    from symfruit.settings import resolve_settings

    settings = resolve_settings(fruit="strawberry")  # what the command line's default --fruit gives
    serial = run_batch(recording, tmp_path / "serial", method="sphere", settings=settings, progress=False)
    assert serial.ok and serial.fruits > 0
    marker, out = tmp_path / "started", tmp_path / "out"
    result: dict = {}
    with distributed.Client(cluster) as client:
        client.run(exec, BLOCK_ONE_FRAME, {"FRAME": "scene_00003", "MARKER": str(marker)})
        pids = set(client.run(os.getpid).values())

        def run() -> None:
            try:
                result["report"] = run_distributed(recording, out, scheduler=cluster.scheduler_address, chunk=2,
                                                   method="sphere", settings=settings, progress=False)  # fmt: skip
            except BaseException as exc:  # surfaced by the assertions below
                result["error"] = exc

        thread = threading.Thread(target=run)
        thread.start()
        pid = int(_wait_for(lambda: marker.is_file() and marker.read_text(), 600, "a worker to start scene_00003"))
        assert pid in pids
        os.kill(pid, signal.SIGKILL)  # mid-task: scene_00002, the task's first frame, is written already
        thread.join(timeout=600)
        assert not thread.is_alive() and "error" not in result, result.get("error")
        workers = _wait_for(lambda: len(client.scheduler_info()["workers"]) == 2 and client.run(os.getpid), 300,
                            "the nanny to start another worker")  # fmt: skip
        assert pid not in workers.values()
        report = result["report"]
        assert report.ok and report.done == serial.done and report.fruits == serial.fruits
        assert _fruits(out) == _fruits(tmp_path / "serial")  # frame for frame
        assert not list(out.rglob("*.tmp"))
        table = pq.read_table(out / "detections.parquet").to_pylist()
        assert len(table) == serial.fruits and len({(r["frame"], r["id"]) for r in table}) == len(table)
        assert table == pq.read_table(tmp_path / "serial" / "detections.parquet").to_pylist()
        frames = pq.read_table(out / "frames.parquet").column("frame").to_pylist()
        assert frames == serial.done

        # --resume (the command line, on the same cluster) after losing two frames, one folder and one record:
        # only those two are detected again, and the tables are whole again with each fruit once
        shutil.rmtree(out / "scene_00000")
        (out / "scene_00002" / "detections.json").unlink()
        capsys.readouterr()
        args = ["detect", str(recording), "--output", str(out), "--method", "sphere"]
        assert main([*args, "--resume", "--scheduler", cluster.scheduler_address, "--chunk", "1"]) == 0
        assert "frames: 2 done, 2 skipped (resume), 0 failed" in capsys.readouterr().out
        client.run(exec, "import symfruit.detect, symfruit.season.cluster as c\nc.detect = symfruit.detect.detect")
    assert pq.read_table(out / "detections.parquet").to_pylist() == table
    assert _fruits(out) == _fruits(tmp_path / "serial")


def test_a_frame_that_fails_on_a_worker_is_recorded_and_the_task_goes_on(recording, tmp_path):
    """The worker's side in this process: each frame of a task in its own error boundary."""
    from symfruit.season.cluster import Job, Part, detect_part

    rec = tmp_path / "rec"
    for name in ("scene_00000", "scene_00001"):
        shutil.copytree(recording / name, rec / name)
    (rec / "scene_00000" / "depth.png").write_bytes(b"not a png")
    out = tmp_path / "out"
    out.mkdir()
    job = Job(run="r", source=str(rec), shown="rec", output=str(out), recording="rec", inputs=(),
              input_folders=(str(rec),), exclude=(), method="raw")  # fmt: skip
    part = Part((0, 1), ("scene_00000", "scene_00001"), (str(out / "scene_00000"), str(out / "scene_00001")),
                (str(rec / "scene_00000"), str(rec / "scene_00001")))  # fmt: skip
    failed, done = detect_part(job, part)
    assert failed.status == "failed" and "depth.png" in failed.reason and not failed.stop
    assert done.status == "done" and done.frame is not None and len(done.fruits) == done.frame["fruit"] > 0
    assert json.loads((out / "scene_00001" / "detections.json").read_text())["source"] == "rec/scene_00001"
    assert not (out / "scene_00000").exists() or not list((out / "scene_00000").iterdir())


def test_what_the_cluster_cannot_do_is_refused_before_anything_runs(recording, tmp_path, capsys, monkeypatch):
    from symfruit.season import cluster

    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT", "0.5s")
    with pytest.raises(InputError, match="either a scheduler address or a number of local workers"):
        run_distributed(recording, tmp_path / "out")
    with pytest.raises(InputError, match="--workers must be between 1 and 256"):
        local_cluster(0)
    with pytest.raises(InputError, match="frames per task"):
        run_distributed(recording, tmp_path / "out", workers=1, chunk=0)
    with pytest.raises(InputError, match="--workers must be between 1 and 256, got 0"):  # not taken as one
        run_distributed(recording, tmp_path / "out", workers=0)
    assert main(["detect", str(recording), "--output", str(tmp_path / "o"), "--workers", "2", "--ros2-bag",
                 str(tmp_path / "bag")]) == 2  # fmt: skip
    assert "cannot be combined with --scheduler or --workers" in capsys.readouterr().err
    assert main(["detect", str(recording), "--output", str(tmp_path / "o"), "--scheduler", "tcp://127.0.0.1:1"]) == 2
    assert "cannot reach the Dask scheduler" in capsys.readouterr().err
    assert not (tmp_path / "o" / "errors.json").exists()
    for address, message in (
        ("", "an empty address"),
        ("tcp://127.0.0.1:99999", "the port 1-65535"),
        ("127.0.0.1", "not a scheduler address"),
        ("tcp://127.0.0.1:\uff11\uff12", "not a scheduler address"),  # full-width digits: int() reads them
        ("8786", "not a scheduler address"),  # a port without a host
        # stop 41: before, Dask's words ("not enough values to unpack (expected 3, got 1)") or a TypeError traceback
        ("inproc://x", "reachable only from the Python process that started that scheduler"),
        ("inproc://127.0.0.1/1/1", "reachable only from the Python process"),  # another process's
        ("tls://127.0.0.1:1", "tls:// needs Dask's TLS settings"),
        ("ucx://127.0.0.1:1", "not an address scheme symfruit can use ('ucx')"),
        ("TCP://127.0.0.1:1", "not an address scheme symfruit can use ('TCP')"),
    ):  # before: tried for 10 s, or ": cannot reach"
        assert main(["detect", str(recording), "--output", str(tmp_path / "o"), "--scheduler", address]) == 2
        assert message in capsys.readouterr().err
    assert main(["detect", str(recording), "--output", str(tmp_path / "o"), "--chunk", "8"]) == 2  # before: ignored
    assert "--chunk (frames per Dask task) is for --scheduler or --workers" in capsys.readouterr().err
    assert not (tmp_path / "o" / "errors.json").exists()


#: The cluster's two time-outs: option, least seconds, what it sets (as its refusals say), values out of bounds.
TIMEOUTS = [
    ("--no-worker-timeout", 1, "the wait for a Dask worker", ["0", "-5", "0.5", "nan", "inf", "1e9", "86401"]),
    ("--silent-worker-timeout", 10, "when a Dask worker not heard from counts as none",
     ["0", "-5", "9.9", "nan", "inf", "86401"]),
]  # fmt: skip


@pytest.mark.parametrize(
    ("option", "least", "seconds"), [(option, least, seconds) for option, least, _, out in TIMEOUTS for seconds in out]
)
def test_a_worker_timeout_out_of_its_bounds_is_refused_before_anything_runs(recording, tmp_path, capsys, option,
                                                                           least, seconds):  # fmt: skip
    """Stop 51 (robust51): the wait for a worker was a module constant (60 s, a local cluster 300 s); now
    --no-worker-timeout sets it, 1 s to a day. Stop 52 (robust52): so does --silent-worker-timeout the time after
    which a worker not heard from counts as none (SILENT_WORKER_S, 60 s), 10 s (twice Dask's longest heartbeat) to
    a day. Each refused before the inputs are read or a cluster started."""
    argv = ["detect", str(recording), "--output", str(tmp_path / "o"), "--workers", "1", option]
    assert main([*argv, seconds]) == 2
    assert f"{option} must be between {least} and 86400 s, got {float(seconds)!r}" in capsys.readouterr().err
    keyword = option.lstrip("-").replace("-", "_")
    with pytest.raises(InputError, match=rf"{option} must be between {least} and 86400 s"):
        run_distributed(recording, tmp_path / "o", workers=1, **{keyword: float(seconds)})
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(("option", "what"), [(option, what) for option, _, what, _ in TIMEOUTS])
def test_a_worker_timeout_without_a_cluster_is_refused_not_ignored(recording, tmp_path, capsys, option, what):
    assert main(["detect", str(recording), "--output", str(tmp_path / "o"), option, "30"]) == 2
    assert f"{option} ({what}) is for --scheduler or --workers" in capsys.readouterr().err
    keyword = option.lstrip("-").replace("-", "_")
    with pytest.raises(InputError, match=rf"{keyword} \({option}\) is for a Dask cluster"):
        run_batch(recording, tmp_path / "o", **{keyword: 30})
    assert not (tmp_path / "o").exists()
    with pytest.raises(SystemExit):
        main(["detect", "--help"])
    assert f"{option} S" in " ".join(capsys.readouterr().out.split())


def test_a_worker_counts_while_it_runs_and_is_heard_from():
    """Paused (memory above Dask's pause fraction), closing, or silent for SILENT_WORKER_S: no worker for the
    watch (:class:`_NoWorkers`); a worker heard from again, or a new one, counts again."""
    from symfruit.season.cluster import SILENT_WORKER_S, working_workers

    heard: dict = {}
    info = {"a": {"status": "running", "last_seen": 1.0}, "b": {"status": "paused", "last_seen": 1.0},
            "c": {"status": "closing_gracefully", "last_seen": 1.0}}  # fmt: skip
    assert working_workers(info, heard, 0.0) == 1
    assert working_workers(info, heard, SILENT_WORKER_S) == 1  # a's last_seen unchanged, but not for long enough
    assert working_workers(info, heard, SILENT_WORKER_S + 0.5) == 0  # silent since 0.0
    info["a"]["last_seen"] = 2.0
    assert working_workers(info, heard, SILENT_WORKER_S + 1) == 1  # heard from again
    info["b"].update(status="running", last_seen=2.0)  # resumed, heard from
    assert working_workers(info, heard, SILENT_WORKER_S + 1) == 2
    assert working_workers({}, heard, SILENT_WORKER_S + 2) == 0 and heard == {}  # the workers gone are forgotten
    assert working_workers({"d": {}}, heard, 0.0) == 1 == working_workers({"d": {}}, heard, 10 * SILENT_WORKER_S)
    one: dict = {"e": {"status": "running", "last_seen": 1.0}}  # silent_s (--silent-worker-timeout): sooner, later
    assert working_workers(one, heard, 0.0, 20.0) == 1
    assert working_workers(one, heard, 20.5, 20.0) == 0 < working_workers(one, heard, 20.5)
    assert working_workers(one, heard, SILENT_WORKER_S + 0.5, 2 * SILENT_WORKER_S) == 1


def test_an_in_process_address_of_this_process_passes_the_check():
    from symfruit.season.cluster import check_address

    check_address(f"inproc://127.0.0.1/{os.getpid()}/3")  # a Python caller's LocalCluster(processes=False)
    with pytest.raises(InputError, match="reachable only from the Python process"):
        check_address(f"inproc://127.0.0.1/{os.getpid() + 1}/3")


def test_a_local_clusters_scheduler_serves_http_on_127_0_0_1_and_a_port_of_its_own():
    """Dask's scheduler starts an HTTP server (health and metrics routes) even without a dashboard, on the
    dashboard's port 8787 unless told: every local cluster after the machine's first warned "Port 8787 is already in
    use" (seven warnings in this module a run; flake54). Now on a port the system picks, on 127.0.0.1 alone. 8787 is
    held here while the cluster starts (or is held already by another process: the same for this test)."""
    import socket
    import warnings

    hold = socket.socket()
    try:
        hold.bind(("127.0.0.1", 8787))
        hold.listen()
    except OSError:  # another process has it
        pass
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            with local_cluster(1) as running:
                http = running.scheduler.http_server
                assert http.address == "127.0.0.1" and http.port != 8787
    finally:
        hold.close()
    assert [str(w.message) for w in caught if "already in use" in str(w.message)] == []


def test_without_dask_the_message_names_the_extra(monkeypatch, tmp_path):
    import builtins

    from symfruit.season import cluster

    real = builtins.__import__

    def no_distributed(name, *args, **kwargs):
        if name == "distributed" or name.startswith("distributed."):
            raise ImportError(name)
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_distributed)
    with pytest.raises(InputError, match=r"pip install 'symfruit\[cluster\]'"):
        cluster.require_distributed()


def test_a_bag_is_read_by_the_worker_from_its_path_and_indices(tmp_path):
    """A bag travels as its path and frame indices: the worker opens it (once per run and thread), checks that
    it lists the frame the client named, and writes what a serial run writes."""
    from symfruit.season.cluster import Job, Part, detect_part, forget

    from ..conftest import EXAMPLES

    pytest.importorskip("rosbags")
    bag = EXAMPLES / "realsense" / "fruit.bag"
    serial = run_batch(bag, tmp_path / "serial", method="raw", progress=False)
    name = serial.done[0]
    out = tmp_path / "out"
    out.mkdir()
    job = Job(run="bag", source=str(bag), shown=str(bag), output=str(out), recording="fruit.bag", inputs=(str(bag),),
              input_folders=(), exclude=(), method="raw")  # fmt: skip
    (done,) = detect_part(job, Part((0,), (name,), (str(out / name),)))
    assert done.status == "done" and _fruits(out) == {name: _fruits(tmp_path / "serial")[name]}
    written = json.loads((out / name / "detections.json").read_text())
    assert written["source"] == json.loads((tmp_path / "serial" / name / "detections.json").read_text())["source"]
    (moved,) = detect_part(job, Part((0,), ("another_00000_1",), (str(out / "x"),)))
    assert moved.status == "failed" and "differs from the one the client listed" in moved.reason
    assert forget("bag") == 1 and forget("bag") == 0  # the bag was opened once and is closed at the end


def test_several_recordings_on_the_cluster_equal_a_serial_run_also_after_resume(cluster, recording, tmp_path,
                                                                                 monkeypatch):  # fmt: skip
    """Two recordings that share a name and one that cannot be opened: the cluster's folders, tables and
    errors.json are the serial run's; a task never mixes recordings (three frames of one, chunk 2); --resume
    (with ``workers=1``: a local cluster of that many workers, here the module's running one standing in for it,
    as starting another costs a scheduler and a worker process; ``local_cluster`` itself starts the module's)
    redoes what is missing and keeps each fruit once."""
    import contextlib

    from symfruit.season import cluster as cluster_module

    a, b = tmp_path / "a" / "rec", tmp_path / "b" / "rec"
    for k in range(3):
        shutil.copytree(recording / f"scene_{k:05d}", a / f"scene_{k:05d}")
    shutil.copytree(recording / "scene_00003", b / "scene_00003")
    bad = tmp_path / "bad.txt"
    bad.write_text("no recording")
    inputs = [a, bad, b]
    serial = run_batch(inputs, tmp_path / "serial", method="raw", progress=False)
    out = tmp_path / "out"
    report = run_distributed(inputs, out, scheduler=cluster.scheduler_address, chunk=2, method="raw", progress=False)
    assert report.recordings == serial.recordings and report.done == serial.done and len(report.done) == 4
    assert report.failed_recordings == serial.failed_recordings and list(report.failed_recordings) == [str(bad)]
    for name in (report.recordings[str(a)], report.recordings[str(b)]):
        assert name.startswith("rec+") and _fruits(out / name) == _fruits(tmp_path / "serial" / name)
    rows = pq.read_table(out / "detections.parquet").to_pylist()
    assert rows == pq.read_table(tmp_path / "serial" / "detections.parquet").to_pylist() and len(rows) == 4
    errors = json.loads((out / "errors.json").read_text())
    assert errors == json.loads((tmp_path / "serial" / "errors.json").read_text()) and errors["recordings"]
    shutil.rmtree(out / report.recordings[str(a)] / "scene_00001")
    asked: list[int] = []
    monkeypatch.setattr(cluster_module, "local_cluster", lambda n: asked.append(n) or contextlib.nullcontext(cluster))
    again = run_distributed(inputs, out, workers=1, chunk=2, method="raw", resume=True, progress=False)
    assert asked == [1]
    assert again.done == [f"{report.recordings[str(a)]}/scene_00001"] and len(again.skipped) == 3
    assert pq.read_table(out / "detections.parquet").to_pylist() == rows


def test_run_distributed_refuses_an_empty_output_path_before_any_cluster(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match="run_distributed: the output folder is an empty path"):
        run_distributed(str(small_frame()), "", workers=1)  # before: the results written into the working folder
    assert not list(tmp_path.iterdir())


def test_a_tls_scheduler_runs_the_recording_as_a_serial_run_does(recording, tmp_path):
    """``--scheduler tls://`` against a real scheduler that speaks only TLS (a self-signed certificate made here by
    openssl, Dask's TLS settings pointing at it, scheduler and worker on 127.0.0.1): the detections are the
    serial run's. Without the settings the address is refused before any connection (check_address)."""
    import subprocess

    import dask
    from distributed import LocalCluster
    from distributed.security import Security

    if shutil.which("openssl") is None:
        pytest.skip("needs the openssl command to make a certificate")
    key, cert = tmp_path / "key.pem", tmp_path / "cert.pem"
    subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", str(key), "-out", str(cert),
                    "-days", "2", "-subj", "/CN=127.0.0.1", "-addext", "subjectAltName=IP:127.0.0.1"], check=True,
                   capture_output=True, timeout=60)  # fmt: skip
    tls = {"distributed.comm.tls.ca-file": str(cert)}
    for who in ("scheduler", "worker", "client"):
        tls |= {f"distributed.comm.tls.{who}.cert": str(cert), f"distributed.comm.tls.{who}.key": str(key)}
    rec = tmp_path / "rec"
    for k in range(2):
        shutil.copytree(recording / f"scene_{k:05d}", rec / f"scene_{k:05d}")
    serial = run_batch(rec, tmp_path / "serial", method="raw", progress=False)
    with dask.config.set(tls):
        with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tls://", host="127.0.0.1",
                          dashboard_address=None, scheduler_kwargs=LOCAL_SCHEDULER_HTTP,
                          security=Security()) as tls_cluster:  # fmt: skip
            address = tls_cluster.scheduler_address
            assert address.startswith("tls://127.0.0.1:")
            report = run_distributed(rec, tmp_path / "out", scheduler=address, chunk=1, method="raw", progress=False)
    assert report.done == serial.done and len(report.done) == 2
    assert _fruits(tmp_path / "out") == _fruits(tmp_path / "serial") != {}
    with pytest.raises(InputError, match=r"tls:// needs Dask's TLS settings"):
        run_distributed(rec, tmp_path / "none", scheduler=address, method="raw", progress=False)


#: A worker preload (every worker, restarted ones too): frame FRAME makes its worker exit at once, every time (as a
#: crash in compiled code or the OOM killer would).
KILL_ON_FRAME = """
import os
import symfruit.season.cluster as cluster

real = getattr(cluster, "_real_detect", cluster.detect)
cluster._real_detect = real


def detect(frame, **kwargs):
    if frame.name == FRAME:
        os._exit(1)
    return real(frame, **kwargs)


cluster.detect = detect
"""


def test_a_frame_that_kills_every_worker_is_lost_alone_and_the_batch_goes_on(recording, tmp_path, capsys):
    """Stop 49 (robust49): `detect --workers 2` with a frame that killed every worker it landed on hung for ever:
    Dask's local cluster closed a nanny whose worker was not back within 15 s (lost-worker-timeout), until no worker
    was left; and every frame of the frame's task (and of the tasks queued on the same worker) was lost with it."""
    import dask

    rec = tmp_path / "rec"
    for name in ("scene_00000", "scene_00001", "scene_00002"):
        shutil.copytree(recording / name, rec / name)
    preload = tmp_path / "kill_on_frame.py"
    preload.write_text(f"FRAME = 'scene_00001'\n{KILL_ON_FRAME}")
    out = tmp_path / "out"
    args = ["detect", str(rec), "--output", str(out), "--method", "sphere", "--workers", "1", "--chunk", "2"]
    with dask.config.set({"distributed.worker.preload": [str(preload)], "distributed.scheduler.allowed-failures": 1}):
        assert main(args) == 1
    said = capsys.readouterr().out
    assert "frames: 2 done, 0 skipped (resume), 1 failed" in said
    reason = "the workers running this frame died 2 times, the last 2 running it alone (killed or out of memory)"
    assert f"failed scene_00001: {reason}" in said
    errors = json.loads((out / "errors.json").read_text())
    assert errors == {"failed": [{"frame": "scene_00001", "reason": reason}], "stopped": ""}
    assert sorted(p.parent.name for p in out.glob("*/detections.json")) == ["scene_00000", "scene_00002"]
    assert not (out / "scene_00001").exists() or not list((out / "scene_00001").iterdir())
    assert not list(out.rglob("*.tmp"))
    frames = pq.read_table(out / "frames.parquet").column("frame").to_pylist()
    assert frames == ["scene_00000", "scene_00002"]


def test_a_scheduler_without_workers_is_refused_after_the_time_out_not_waited_on_for_ever(recording, tmp_path):
    """A scheduler that has no worker (none started, or all gone) keeps the tasks queued: the run waited for ever
    (stop 49 left it). Now it waits ``no_worker_timeout`` seconds for the first worker and says so by address."""
    from distributed import LocalCluster

    with LocalCluster(n_workers=0, processes=False, protocol="tcp://", host="127.0.0.1",
                      dashboard_address=None, scheduler_kwargs=LOCAL_SCHEDULER_HTTP) as empty:  # fmt: skip
        address = empty.scheduler_address
        start = time.monotonic()
        with pytest.raises(
            InputError,
            match=rf"{address}: the Dask scheduler has no worker \(waited 2 s for one, "
            r"--no-worker-timeout\); start workers",
        ):
            run_distributed(recording, tmp_path / "o", scheduler=address, method="raw", progress=False,
                            no_worker_timeout=2)  # fmt: skip
        assert time.monotonic() - start < 60
    assert not (tmp_path / "o" / "errors.json").exists()


def test_a_result_lost_with_the_last_worker_before_it_was_gathered_is_unprocessed(recording, tmp_path, monkeypatch):
    """The one worker leaves after the first task finished but before the client gathered its result (a race that
    a worker leaving at any moment can hit): the client reschedules that task on no worker, and the run, which
    waits on its result, stops after the time-out with it unprocessed, not waited on for ever."""
    import symfruit.season.cluster as cluster

    real = cluster._outcomes
    left = threading.Event()
    running: dict = {}  # the cluster, once started

    def late(future, part, distributed):  # the first finished task's result is asked for once the worker left
        if not left.is_set():
            left.set()
            running["cluster"].scale(0)
            _wait_for(lambda: not running["cluster"].scheduler.workers, 60, "the worker to leave")
        return real(future, part, distributed)

    monkeypatch.setattr(cluster, "_outcomes", late)
    out = tmp_path / "o"
    with _one_worker(recording, out) as (one, runner, result):
        running["cluster"] = one
        runner.start()
        runner.join(600)
        assert not runner.is_alive(), "the run waited for a result lost with the last worker"
    assert left.is_set()
    _stopped_with_the_rest_unprocessed(result["report"], one.scheduler_address, out)


@pytest.mark.parametrize("how", ["paused", "silent"])
def test_a_cluster_whose_workers_are_all_paused_or_silent_stops_the_run(recording, tmp_path, monkeypatch, how):
    """Stop 51 (robust51): a worker paused (its memory above Dask's pause fraction) or no longer heard from (its
    heartbeat stopped: a frozen process, a lost network) stays registered, and the watch counted it: the run
    waited for ever (paused) or for the scheduler's worker-ttl. Now neither counts: after the time-out the run
    stops, the frames not done unprocessed. The silence is --silent-worker-timeout's (its least, 10 s; stop 52)."""
    from distributed.core import Status

    import symfruit.season.cluster as cluster

    real = cluster.detect
    release, calls = threading.Event(), []

    def held(frame, **kwargs):  # the first frame goes through; the others wait until the test ends
        calls.append(frame.name)
        if len(calls) > 1:
            release.wait(300)
        return real(frame, **kwargs)

    monkeypatch.setattr(cluster, "detect", held)  # the in-process worker runs this module
    out = tmp_path / "o"
    with _one_worker(recording, out, silent_worker_timeout=10) as (one, runner, result):
        worker = next(iter(one.workers.values()))
        runner.start()
        _wait_for(lambda: list(out.glob("*/detections.json")), 600, "the first frame")

        def stop() -> None:  # on the worker's event loop, as Dask's memory monitor pauses it
            if how == "paused":  # and kept so: its memory monitor would resume it, memory being low here
                worker.periodic_callbacks["memory_monitor"].stop()
                worker.status = Status.paused
            else:
                worker.periodic_callbacks["heartbeat"].stop()

        one.loop.add_callback(stop)
        runner.join(180)  # 10 s of silence, 2 without a worker: generous for a loaded host (flake54: was 50)
        alive = runner.is_alive()
        release.set()
        assert not alive, f"the run waited on a {how} worker"
        assert len(one.scheduler.workers) == 1  # still registered
    _stopped_with_the_rest_unprocessed(result["report"], one.scheduler_address, out)
    assert len(result["report"].done) == 1 and len(result["report"].unprocessed) == 3


def test_a_cluster_whose_workers_all_leave_stops_the_run_with_the_rest_unprocessed(recording, tmp_path, monkeypatch):
    """The one worker leaves once the first frame is written (each later frame takes 5 s here: the worker cannot
    finish the other three before it leaves, whatever the load; it was 1 s each, the first too, a 3 s window for the
    test to see the first frame and scale the cluster down; flake54): after the time-out the run stops, the frames
    not done recorded unprocessed (``--resume`` takes them up), not waited on for ever."""
    import symfruit.season.cluster as cluster

    real, calls = cluster.detect, []

    def slow(frame, **kwargs):
        calls.append(frame.name)
        if len(calls) > 1:
            time.sleep(5.0)
        return real(frame, **kwargs)

    monkeypatch.setattr(cluster, "detect", slow)  # the in-process worker runs this module
    out = tmp_path / "o"
    with _one_worker(recording, out) as (one, runner, result):
        runner.start()
        _wait_for(lambda: list(out.glob("*/detections.json")), 600, "the first frame")
        one.scale(0)
        runner.join(600)
        assert not runner.is_alive()
    # the first frame is written, but its result may be lost with the worker before the client gathers it (then
    # it is unprocessed too: the test above): done may be none
    _stopped_with_the_rest_unprocessed(result["report"], one.scheduler_address, out)


def _blas_threads() -> list[int]:
    from threadpoolctl import threadpool_info

    return sorted({info["num_threads"] for info in threadpool_info() if info["user_api"] == "blas"})


def _first_task(job, part) -> list[int]:
    from symfruit.season.cluster import detect_part

    detect_part(job, part)
    return _blas_threads()


def test_a_worker_process_runs_numpys_blas_on_one_thread_from_its_first_task(tmp_path):
    """Robust53: a worker started without a nanny (``dask worker --no-nanny``) kept numpy's OpenBLAS on every core:
    two on two cores took 1.3-1.6x the CPU (docs/robust53.md). Its first task limits it to one thread, in a
    worker process of its own; in the client's own process (an in-process cluster) the caller's BLAS is left be.
    The worker is a forked process whose parent runs two BLAS threads (a process that kept them would say 2)."""
    threadpoolctl = pytest.importorskip("threadpoolctl")
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from symfruit.season.cluster import Job, Part

    part = Part(indices=(), names=(), folders=())  # no frame: the task's set-up alone
    job = Job(run="r", source=str(tmp_path), shown=str(tmp_path), output=str(tmp_path / "o"), recording="r",
              inputs=(), input_folders=(), exclude=(), client=os.getpid())  # fmt: skip
    fork = multiprocessing.get_context("fork")
    with threadpoolctl.threadpool_limits(limits=2, user_api="blas"):
        if _blas_threads() != [2]:
            pytest.skip(f"numpy's BLAS here cannot run two threads ({_blas_threads()})")
        with ProcessPoolExecutor(max_workers=1, mp_context=fork) as pool:
            assert pool.submit(_blas_threads).result(timeout=600) == [2]  # what a worker inherits
            assert pool.submit(_first_task, job, part).result(timeout=600) == [1]
        assert _first_task(job, part) == [2]  # the client's own process: its BLAS left be
        with ProcessPoolExecutor(max_workers=1, mp_context=fork) as pool:  # a job that names no client: left be
            assert pool.submit(_first_task, dataclasses.replace(job, client=0), part).result(timeout=600) == [2]


def _warning_frames(recording, rec: Path, count: int) -> Path:
    """``count`` copies of the small frame whose camera.json puts the principal point outside the image (cx -81: the
    small frame's own -80 is filtered out of every test, conftest): each gives a warning when read."""
    for k in range(count):
        shutil.copytree(recording / f"scene_{k:05d}", rec / f"scene_{k:05d}")
        cam = json.loads((rec / f"scene_{k:05d}" / "camera.json").read_text())
        (rec / f"scene_{k:05d}" / "camera.json").write_text(json.dumps({**cam, "cx": -81.0}))
    return rec


def test_a_frames_warnings_on_a_worker_are_held_for_the_client_not_shown_there(recording, tmp_path):
    """The worker's side in this process: a frame's SymfruitWarning goes into its Outcome, not to the worker's
    stderr in Python's form (its file, line and a line of symfruit's source; robust55)."""
    import warnings

    from symfruit import SymfruitWarning
    from symfruit.season.cluster import Job, Part, detect_part

    rec = _warning_frames(recording, tmp_path / "rec", 1)
    out = tmp_path / "out"
    out.mkdir()
    job = Job(run="r", source=str(rec), shown="rec", output=str(out), recording="rec", inputs=(),
              input_folders=(str(rec),), exclude=(), method="raw")  # fmt: skip
    part = Part((0,), ("scene_00000",), (str(out / "scene_00000"),), (str(rec / "scene_00000"),))
    with warnings.catch_warnings(record=True) as shown:
        warnings.simplefilter("always")
        (done,) = detect_part(job, part)
        warnings.warn("given outside a frame", SymfruitWarning, stacklevel=1)  # shown as before
    assert done.status == "done" and len(done.warned) == 1
    assert done.warned[0].startswith(f"{rec}/scene_00000/camera.json: the principal point (cx -81")
    assert [str(w.message) for w in shown if issubclass(w.category, SymfruitWarning)] == ["given outside a frame"]


def test_the_workers_warnings_are_given_by_the_client_once_a_recording(cluster, recording, tmp_path, capsys):
    """As a serial run gives them. Before (robust55): each worker process printed each frame's warning itself in
    Python's form (``.../io/frames.py:156: SymfruitWarning: ...`` and the source line), the client none."""
    rec = _warning_frames(recording, tmp_path / "rec", 3)
    out = tmp_path / "out"
    assert main(["detect", str(rec), "--output", str(out), "--method", "raw", "--scheduler",
                 cluster.scheduler_address, "--chunk", "1"]) == 0  # fmt: skip
    err = capsys.readouterr().err
    assert err.count("principal point") == 1 and "SymfruitWarning" not in err
    assert f"symfruit: warning: {rec}/scene_00000/camera.json: the principal point (cx -81" in err
    assert f"symfruit: warning: {rec}: 2 more frames gave a warning above (each is shown for its first frame" in err


@pytest.mark.parametrize(
    "address",
    ["tcp://[::1", "tcp://[::1:8786", "tcp://::1]:8786", f"tcp://{'a' * 64}:8786", f"tcp://{'ab.' * 90}c:8786",
     "tcp://a..b:8786", "tcp://[]:8786"],
)  # fmt: skip
def test_a_scheduler_address_whose_host_can_be_no_name_nor_address_is_refused_in_our_words(address):
    """Before (robust55): distributed's "invalid address '[::1'; maybe: ipv6 needs brackets like [::1]" of an address
    with its bracket, Python's "encoding with 'idna' codec failed (UnicodeError: label too long)" of a part of a name
    over 63 characters, each after ``cannot reach the Dask scheduler``; now refused before any connection."""
    from symfruit.season.cluster import check_address

    with pytest.raises(InputError, match=r"not a scheduler address; its host .* is no host name \(at most 253 "):
        check_address(address)


@pytest.mark.parametrize(
    "address",
    ["tcp://[::1]:8786", "tcp://scheduler.example.org.:8786", f"tcp://{'a' * 63}.b:8786", "host:8786", "tcp://:8786"],
)
def test_a_scheduler_address_of_a_host_name_or_an_ipv6_address_in_brackets_passes_the_check(address):
    from symfruit.season.cluster import check_address

    check_address(address)
