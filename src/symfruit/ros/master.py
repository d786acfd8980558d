"""A real ROS 1 master on a free local port, for tests and demos: ``with RosMaster() as master: ...``.

It runs Debian's ``rosmaster --core -p PORT`` (package ``python3-rosmaster``; ``roscore`` from
``python3-roslaunch`` would add a C++ ``rosout`` node the tests do not need) in its own process group,
with ``ROS_HOME`` and ``ROS_LOG_DIR`` in a private folder. ``start`` returns once the master answers
XML-RPC (``getPid``); a port taken between choosing and binding makes ``rosmaster`` exit, and the next
free port is tried. ``stop`` sends SIGINT (the master's clean shutdown), then SIGKILL after a timeout.
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import xmlrpc.client
from pathlib import Path
from typing import Any

from ..errors import SymfruitError

__all__ = ["RosMaster", "free_port", "stop_group"]


def free_port() -> int:
    """A TCP port on 127.0.0.1 that was free a moment ago."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _command(port: int) -> list[str]:
    exe = shutil.which("rosmaster")
    if exe is not None:
        return [exe, "--core", "-p", str(port)]
    # no script on PATH: run the module with this interpreter (it must see Debian's dist-packages)
    return [sys.executable, "-c", "import rosmaster; rosmaster.rosmaster_main()", "--core", "-p", str(port)]


def stop_group(process: subprocess.Popen, timeout: float = 10.0) -> None:
    """Stop a process started with ``start_new_session=True`` and everything it started: SIGINT to its
    process group (rospy's and roslaunch's clean shutdown), SIGKILL if it is still there after ``timeout``."""
    if process.poll() is not None:
        return
    try:
        os.killpg(process.pid, signal.SIGINT)
        process.wait(timeout)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait(timeout)
    except ProcessLookupError:  # the group is gone already
        pass


class RosMaster:
    """A ROS master subprocess. Attributes after :meth:`start`: ``port``, ``uri``, ``env`` (the
    environment a node needs to use it: ``ROS_MASTER_URI``, ``ROS_HOSTNAME``, ``ROS_HOME``, ``ROS_LOG_DIR``)."""

    def __init__(self, *, home: str | Path | None = None, timeout: float = 60.0, attempts: int = 5) -> None:
        self._own_home = home is None
        self.home = Path(tempfile.mkdtemp(prefix="symfruit-ros-")) if home is None else Path(home)
        self.timeout, self.attempts = timeout, attempts
        self.process: subprocess.Popen | None = None
        self.port = 0
        self.uri = ""
        self.env: dict[str, str] = {}

    def start(self) -> RosMaster:
        if shutil.which("rosmaster") is None:
            try:
                import rosmaster  # noqa: F401
            except ImportError:
                raise SymfruitError("no ROS master: install Debian's python3-rosmaster") from None
        last = ""
        for _ in range(self.attempts):
            self.port = free_port()
            self.uri = f"http://127.0.0.1:{self.port}/"
            self.env = {
                **os.environ,
                "ROS_MASTER_URI": self.uri,
                "ROS_HOSTNAME": "127.0.0.1",
                "ROS_HOME": str(self.home),
                "ROS_LOG_DIR": str(self.home / "log"),
            }
            self.env.pop("ROS_IP", None)
            log = open(self.home / f"master-{self.port}.log", "wb")
            self.process = subprocess.Popen(
                _command(self.port),
                env=self.env,
                stdout=log,
                stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL,
                start_new_session=True,
            )
            log.close()
            if self._wait_online():
                return self
            last = (self.home / f"master-{self.port}.log").read_text(errors="replace")[-2000:]
            self.stop()
        raise SymfruitError(f"the ROS master did not start in {self.attempts} attempts; its last log: {last}")

    def _wait_online(self) -> bool:
        deadline = time.monotonic() + self.timeout
        process = self.process
        assert process is not None
        with xmlrpc.client.ServerProxy(self.uri) as proxy:  # closes its connection when done
            while time.monotonic() < deadline:
                if process.poll() is not None:
                    return False  # exited: most likely the port was taken meanwhile
                try:
                    answer: Any = proxy.getPid("/symfruit_probe")
                    if answer[0] == 1:
                        return True
                except OSError:
                    pass
                time.sleep(0.05)  # polling: a starting master announces nothing
        return False

    def stop(self, timeout: float = 10.0) -> None:
        """SIGINT the master and wait; SIGKILL its process group if it is still there after ``timeout``."""
        p, self.process = self.process, None
        if p is not None:
            stop_group(p, timeout)

    def close(self) -> None:
        self.stop()
        if self._own_home:
            shutil.rmtree(self.home, ignore_errors=True)

    def __enter__(self) -> RosMaster:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.close()
