"""symfruit.ros.master: free ports, stopping a process group (cleanly, or by force), a real master."""

from __future__ import annotations

import socket
import subprocess
import sys
import time
import xmlrpc.client
from pathlib import Path

import pytest

from symfruit import SymfruitError
from symfruit.ros.master import RosMaster, free_port, stop_group


def _running(pid: int) -> bool:
    """Whether process ``pid`` exists and has not ended (a zombie waiting to be reaped has ended)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return False
    return state not in ("Z", "X")


def test_free_port_can_be_bound():
    """A port that was free a moment ago: another process on the machine (a test on another xdist worker making a
    connection, whose local port comes from the same range) may take it before this test binds it, so each of three
    fresh ports is tried; a port that is never bindable fails (flake54)."""
    taken = []
    for _ in range(3):
        port = free_port()
        assert 1024 <= port <= 65535
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
            try:
                s.bind(("127.0.0.1", port))
            except OSError as exc:
                taken.append((port, exc))
                continue
        break
    assert len(taken) < 3, taken


def test_stop_group_ends_a_process_and_what_it_started():
    # A parent that has started a child of its own and waits for it: SIGINT to the group ends both.
    code = ("import subprocess, sys; p = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(60)']); "
            "print(p.pid, flush=True); p.wait()")  # fmt: skip
    proc = subprocess.Popen([sys.executable, "-c", code], start_new_session=True, stdout=subprocess.PIPE, text=True,
                            stderr=subprocess.DEVNULL)  # fmt: skip
    assert proc.stdout is not None
    child = int(proc.stdout.readline())  # the child runs
    assert _running(child)
    stop_group(proc, timeout=30)
    assert proc.returncode is not None
    deadline = time.monotonic() + 30  # the child is not ours to wait for: it ends on its own SIGINT
    while _running(child) and time.monotonic() < deadline:
        time.sleep(0.01)
    assert not _running(child)


def test_stop_group_kills_what_ignores_sigint():
    code = (
        "import signal, time; signal.signal(signal.SIGINT, signal.SIG_IGN); print('ready', flush=True); time.sleep(60)"
    )
    proc = subprocess.Popen([sys.executable, "-c", code], start_new_session=True, stdout=subprocess.PIPE, text=True)
    assert proc.stdout is not None and proc.stdout.readline().strip() == "ready"  # SIGINT is ignored from here
    stop_group(proc, timeout=0.5)
    assert proc.returncode == -9
    assert not _running(proc.pid)
    stop_group(proc)  # a finished process: nothing to do


def test_a_real_master_answers_and_stops(ros1):
    with RosMaster(timeout=60) as master:
        assert master.env["ROS_MASTER_URI"] == master.uri == f"http://127.0.0.1:{master.port}/"
        with xmlrpc.client.ServerProxy(master.uri) as proxy:
            code, _, pid = proxy.getPid("/symfruit_test")
        assert code == 1 and pid == master.process.pid
        process = master.process
    assert master.process is None and process.returncode is not None
    assert not master.home.exists()  # its private ROS_HOME is removed


def test_a_missing_master_is_named(monkeypatch, tmp_path):
    import builtins
    import shutil

    real_import = builtins.__import__

    def no_rosmaster(name, *args, **kwargs):
        if name == "rosmaster":
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(shutil, "which", lambda name: None)
    monkeypatch.setattr(builtins, "__import__", no_rosmaster)
    with pytest.raises(SymfruitError, match="python3-rosmaster"):
        RosMaster(home=tmp_path).start()
