"""symfruit.ros.camera2 without ROS: domain leases, the isolated environment, and the JSON-line client (against a
stand-in of the stand-in). Its rclpy side (frames as the RealSense wrapper publishes them, spoilt frames, the
listener) is exercised against the real node in test_node2.py and by test_bench2.py."""

from __future__ import annotations

import json
import stat
import sys
import textwrap
from pathlib import Path

import pytest

from symfruit.ros.camera2 import DOMAINS, CameraClient, domain_lease, isolated_env


def test_domain_leases_are_exclusive_and_released(tmp_path):
    with domain_lease(tmp_path) as a, domain_lease(tmp_path) as b:
        assert a != b and a in DOMAINS and b in DOMAINS
    with domain_lease(tmp_path) as again:
        assert again == a  # the same start (this pid), free again


def test_every_domain_leased_is_an_error(tmp_path, monkeypatch):
    import symfruit.ros.camera2 as camera2

    monkeypatch.setattr(camera2, "DOMAINS", range(5, 7))
    with domain_lease(tmp_path), domain_lease(tmp_path), pytest.raises(RuntimeError, match="every ROS domain id 5-6"):
        with domain_lease(tmp_path):
            pass


def test_isolated_env_stays_on_this_machine(tmp_path):
    base = {"PATH": "/usr/bin", "ROS_DOMAIN_ID": "0", "ROS_LOCALHOST_ONLY": "0", "ROS_STATIC_PEERS": "10.0.0.2",
            "ROS_DISCOVERY_SERVER": "10.0.0.3:11811", "FASTDDS_DEFAULT_PROFILES_FILE": "/etc/wan.xml"}  # fmt: skip
    env = isolated_env(42, tmp_path, base)
    assert env["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "LOCALHOST" and env["ROS_DOMAIN_ID"] == "42"
    assert env["RMW_IMPLEMENTATION"] == "rmw_fastrtps_cpp" and env["ROS_LOG_DIR"] == str(tmp_path)
    assert env["PATH"] == "/usr/bin"
    for gone in ("ROS_LOCALHOST_ONLY", "ROS_STATIC_PEERS", "ROS_DISCOVERY_SERVER", "FASTDDS_DEFAULT_PROFILES_FILE"):
        assert gone not in env


def fake_server(tmp_path: Path, body: str) -> Path:
    """An executable that stands in for the ROS 2 venv's python: it ignores its arguments and runs ``body`` with
    ``req`` (each request) and ``answer(**reply)``."""
    script = tmp_path / "python"
    script.write_text(
        f"#!{sys.executable}\nimport json, sys\n"
        "def answer(**reply):\n    print(json.dumps(reply), flush=True)\n"
        "for line in sys.stdin:\n    req = json.loads(line)\n" + textwrap.indent(body, "    ")
    )
    script.chmod(script.stat().st_mode | stat.S_IEXEC)
    return script


def test_client_requests_and_replies_in_order(tmp_path):
    server = fake_server(tmp_path, 'answer(ok=True, echo=req)\nif req["op"] == "quit":\n    break\n')
    client = CameraClient(server, {"PATH": "/usr/bin"}, tmp_path / "camera.log")
    assert client.call("frame", sec=3, spoil="zero_k") == {"ok": True, "echo": {"op": "frame", "sec": 3,
                                                                                  "spoil": "zero_k"}}  # fmt: skip
    assert client.call("wait", kind="detections", sec=3)["echo"]["kind"] == "detections"
    assert client.close() == 0


def test_client_reports_a_dead_or_silent_server_with_its_log(tmp_path):
    dies = fake_server(tmp_path, 'sys.stderr.write("it broke\\n")\nsys.exit(3)\n')
    client = CameraClient(dies, {"PATH": "/usr/bin"}, tmp_path / "camera.log")
    with pytest.raises(RuntimeError, match=r"(?s)ended during frame.*it broke"):
        client.call("frame", sec=1)
    assert client.close() == 3

    (tmp_path / "silent").mkdir()
    silent = fake_server(tmp_path / "silent", "pass\n")
    client = CameraClient(silent, {"PATH": "/usr/bin"}, tmp_path / "silent.log")
    with pytest.raises(RuntimeError, match=r"no answer to ready in 0 s"):
        client.call("ready", deadline=0.2)
    assert client.close(timeout=0.5) is not None  # no answer to quit either: stopped


def test_replies_are_json_lines(tmp_path):
    server = fake_server(tmp_path, "answer(ok=False, error=f\"unknown op {req['op']!r}\")\nbreak\n")
    client = CameraClient(server, {"PATH": "/usr/bin"}, tmp_path / "camera.log")
    reply = client.call("nonsense")
    assert reply == {"ok": False, "error": "unknown op 'nonsense'"} and json.dumps(reply)
    client.close()


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (["--count", "-1"], "--count must be 0 (until Ctrl-C) or more frames, got -1"),
        (["--count", "٣"], "ASCII digits"),
        (["--rate", "٥"], "ASCII digits"),
        (["--rate", "0"], "--rate must be a positive number"),
    ],
)
def test_play_refuses_bad_counts_and_rates_before_anything_starts(args, said, capsys, monkeypatch):
    """Stop 56: a negative ``--count`` was taken (``play`` publishes until its count is reached), and ``int()`` /
    ``float()`` read another script's digits; both are refused by name before ROS is touched."""
    import symfruit.ros.camera2 as camera2

    monkeypatch.setattr(camera2, "play", lambda *a, **k: pytest.fail("play started"))
    with pytest.raises(SystemExit) as stop:
        camera2.main(["play", *args])
    assert stop.value.code == 2
    assert said in capsys.readouterr().err
