"""symfruit.ros.ros2env (`make ros2-env`): upstream's type hashes, the package it builds, when it rebuilds, and
what the build made (the running node's hash is checked on the ROS graph in test_node2.py)."""

from __future__ import annotations

import importlib.metadata
import json
import os
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from symfruit.ros import ros2env
from symfruit.ros.ros2env import MESSAGES, UPSTREAM_TYPE_HASH


def test_rosbags_computes_upstreams_hashes_from_the_shipped_definitions():
    """REP-2011 computed by rosbags from the shipped .msg files (and the ROS 2 Humble+ std_msgs and geometry_msgs
    it knows) equals the hashes upstream's build writes: the definitions are upstream's, to the hash."""
    pytest.importorskip("rosbags")
    from symfruit.ros.bag2 import ros2_typestore

    store = ros2_typestore()
    assert {f"vision_msgs/msg/{m}" for m in MESSAGES} == set(UPSTREAM_TYPE_HASH)
    for name, expected in UPSTREAM_TYPE_HASH.items():
        assert store.hash_rihs01(name) == expected, name


def test_the_package_holds_the_definitions_verbatim(tmp_path):
    folder = ros2env.write_package(tmp_path / "vision_msgs")
    shipped = ros2env.definition_files()
    assert sorted(p.name for p in (folder / "msg").iterdir()) == sorted(f"{m}.msg" for m in MESSAGES)
    for path in shipped:
        assert (folder / "msg" / path.name).read_bytes() == path.read_bytes()
    xml = ET.parse(folder / "package.xml").getroot()
    assert xml.findtext("name") == "vision_msgs" and xml.findtext("member_of_group") == "rosidl_interface_packages"
    cmake = (folder / "CMakeLists.txt").read_text()
    listed = re.findall(r"msg/(\w+)\.msg", cmake)
    assert listed == list(MESSAGES) and "DEPENDENCIES std_msgs geometry_msgs" in cmake


def test_the_wheels_include_folders_are_pointed_at_this_venv(tmp_path):
    """The CMake lines that rewrite the include folders the wheels were built with, run on such a list."""
    cmake = shutil.which("cmake")
    if cmake is None:
        pytest.skip("no cmake here (`make ros2-env` installs it where it builds)")
    script = tmp_path / "fix.cmake"
    script.write_text(
        'set(SYMFRUIT_PYTHON_INCLUDE "/venv/include/python3.11")\n'
        'set(SYMFRUIT_NUMPY_INCLUDE "/venv/lib/numpy/include")\n'
        'set(_dirs "/opt/python/cp311-cp311/include/python3.11;/keep/me;'
        '/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include")\n'
        + ros2env.CMAKELISTS.split("  if(_dirs)\n")[1].split("    set_target_properties")[0]
        + 'message(STATUS "${_dirs}")\n'
    )
    res = subprocess.run([cmake, "-P", str(script)], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip().endswith("/venv/include/python3.11;/keep/me;/venv/lib/numpy/include")


def test_build_key_follows_the_build_and_the_python(monkeypatch):
    key = ros2env.build_key("3.11")
    assert key == ros2env.build_key("3.11") and key != ros2env.build_key("3.12")
    monkeypatch.setattr(ros2env, "BUILD_VERSION", "something else")
    assert ros2env.build_key("3.11") != key

    def not_installed(name):
        raise importlib.metadata.PackageNotFoundError(name)

    other = ros2env.build_key("3.11")
    monkeypatch.setattr(importlib.metadata, "requires", not_installed)  # symfruit run from a source tree
    assert ros2env.build_key("3.11") != other  # the extra's requirements are part of the key


def test_build_key_follows_the_fast_extras_requirements_too(monkeypatch):
    """A venv made when it had the ROS 2 extra alone is made again with the compiled kernels (stop 53)."""
    ros2 = ['ros-rclpy[fastrtps]>=9.1; extra == "ros2"']
    monkeypatch.setattr(importlib.metadata, "requires", lambda name: ros2)
    before = ros2env.build_key("3.11")
    monkeypatch.setattr(importlib.metadata, "requires", lambda name: [*ros2, 'numba>=0.60; extra == "fast"'])
    with_fast = ros2env.build_key("3.11")
    assert with_fast != before
    monkeypatch.setattr(importlib.metadata, "requires", lambda name: [*ros2, 'numba>=0.60; extra == "fast"',
                                                                      'matplotlib>=3.6; extra == "plot"'])  # fmt: skip
    assert ros2env.build_key("3.11") == with_fast  # an extra the venv does not get is no part of it


def test_an_up_to_date_venv_is_left_alone(tmp_path, monkeypatch):
    venv = tmp_path / "venv"
    (venv / "bin").mkdir(parents=True)
    (venv / "bin" / "python").write_text("")
    (venv / ros2env.STATUS_FILE).write_text(json.dumps({"key": ros2env.build_key(), "hash": "RIHS01_x"}))

    def no(*a, **k):
        raise AssertionError("rebuilt an up-to-date venv")

    monkeypatch.setattr(ros2env, "make_venv", no)
    monkeypatch.setattr(ros2env, "build_vision_msgs", no)
    assert ros2env.ensure(venv, tmp_path) == f"ros2-env: ok: {venv} up to date (vision_msgs RIHS01_x)"
    (venv / ros2env.STATUS_FILE).write_text(json.dumps({"key": "stale", "hash": "RIHS01_x"}))
    with pytest.raises(AssertionError, match="rebuilt"):
        ros2env.ensure(venv, tmp_path)


def test_skip_is_visible_and_only_an_error_when_required(monkeypatch, capsys, tmp_path):
    def skip(*a, **k):
        raise ros2env.Skip("pip could not install the ROS 2 wheels")

    monkeypatch.setattr(ros2env, "ensure", skip)
    assert ros2env.main(["--venv", str(tmp_path / "v")]) == 0
    assert "ros2-env: skipped: pip could not install the ROS 2 wheels" in capsys.readouterr().out
    assert ros2env.main(["--venv", str(tmp_path / "v"), "--require"]) == 1


def test_the_built_venv_holds_upstreams_type(ros2_python):
    """What `make ros2-env` built: upstream's hashes in the type description it installed, the build recorded."""
    venv = Path(ros2_python).parents[1]
    description = json.loads((venv / "share" / "vision_msgs" / "msg" / "Detection3DArray.json").read_text())
    hashes = {h["type_name"]: h["hash_string"] for h in description["type_hashes"]}
    for name, expected in UPSTREAM_TYPE_HASH.items():
        assert hashes[name] == expected
    assert ros2env.status(venv)["hash"] == UPSTREAM_TYPE_HASH["vision_msgs/msg/Detection3DArray"]


def test_a_missing_or_unreadable_status_is_no_build(tmp_path):
    assert ros2env.status(tmp_path) == {}
    (tmp_path / ros2env.STATUS_FILE).write_text("{not json")
    assert ros2env.status(tmp_path) == {}


# --- the build's steps against stand-in commands: a venv whose python, and a cmake, are shell scripts --------

#: The venv's stand-in python: `-m venv DIR` makes DIR a venv of itself; `-m pip` exits $PIP_STATUS; `-c` with
#: the include probe prints two folders, with the publisher check prints $CHECK_OUT (exit $CHECK_STATUS).
FAKE_PYTHON = """case "$1 $2" in
  "-m venv") mkdir -p "$3/bin" && cp "$0" "$3/bin/python" ;;
  "-m pip") echo "WARNING: Location something" >&2; echo "pip said no" >&2; exit "${PIP_STATUS:-0}" ;;
  -c*numpy*) echo /venv/include/python3.11; echo /venv/numpy/include; exit "${PROBE_STATUS:-0}" ;;
  -c*rclpy*) echo "$CHECK_OUT"; exit "${CHECK_STATUS:-0}" ;;
esac"""


def _script(path: Path, body: str, log: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f'#!/bin/sh\necho "{path.name} $*" >> "{log}"\n{body}\n')
    path.chmod(0o755)
    return path


def _hash_line(type_hash: str = UPSTREAM_TYPE_HASH["vision_msgs/msg/Detection3DArray"]) -> str:
    return json.dumps({"type": "vision_msgs/msg/Detection3DArray", "hash": type_hash})


@pytest.fixture
def fake_venv(tmp_path, monkeypatch):
    """``(venv, log)``: a venv folder with the stand-in python and cmake, and the file they log their calls to."""
    venv, log = tmp_path / "venv", tmp_path / "calls"
    _script(venv / "bin" / "python", FAKE_PYTHON, log)
    _script(venv / "bin" / "cmake", 'case "$1" in "$FAIL_STEP") echo "CMake Error: boom" >&2; exit 1 ;; esac', log)
    monkeypatch.setenv("CHECK_OUT", _hash_line())
    return venv, log


def test_make_venv_installs_the_project_with_the_extra_and_says_why_not(fake_venv, tmp_path, monkeypatch):
    venv, log = fake_venv
    new = tmp_path / "new"
    monkeypatch.setattr(ros2env.sys, "executable", str(venv / "bin" / "python"))  # the interpreter making venvs
    ros2env.make_venv(new, tmp_path / "project")
    assert ros2env.ros2_python(new).is_file()
    calls = log.read_text().splitlines()
    pip = "python -m pip install --quiet --disable-pip-version-check"
    assert calls[:3] == [f"python -m venv {new}", f"{pip} --upgrade pip", f"{pip} -e {tmp_path / 'project'}[ros2,fast]"]
    monkeypatch.setenv("PIP_STATUS", "1")
    with pytest.raises(ros2env.Skip, match=r"pip could not install the ROS 2 wheels into .*: pip said no$"):
        ros2env.make_venv(new, tmp_path / "project")  # the venv exists: not made again, pip fails
    assert sum(c.startswith("python -m venv") for c in log.read_text().splitlines()) == 1


def test_make_venv_fails_cleanly_when_venv_cannot_run(tmp_path, monkeypatch):
    broken = _script(tmp_path / "python3", 'echo "Error: ensurepip is not available" >&2; exit 1', tmp_path / "l")
    monkeypatch.setattr(ros2env.sys, "executable", str(broken))
    with pytest.raises(ros2env.Skip, match=r"cannot create .*other: Error: ensurepip is not available"):
        ros2env.make_venv(tmp_path / "other", tmp_path)


def test_the_build_runs_cmake_configure_build_install_with_the_venvs_folders(fake_venv, monkeypatch):
    venv, log = fake_venv
    monkeypatch.setenv("PYTHONPATH", "/somewhere/else")  # not passed on to the build
    ros2env.build_vision_msgs(venv)
    calls = [c for c in log.read_text().splitlines() if c.startswith("cmake")]
    work = venv / "build" / "vision_msgs"
    assert calls[0].startswith(f"cmake -S {work / 'src'} -B {work / 'build'} -DCMAKE_INSTALL_PREFIX={venv} ")
    assert calls[0].endswith(
        " -DSYMFRUIT_PYTHON_INCLUDE=/venv/include/python3.11 -DSYMFRUIT_NUMPY_INCLUDE=/venv/numpy/include"
    )  # what the probe printed
    build = work / "build"
    assert calls[1:] == [f"cmake --build {build} --parallel {os.cpu_count() or 1}", f"cmake --install {build}"]
    assert (work / "src" / "CMakeLists.txt").is_file()  # the package written, then built
    monkeypatch.setenv("FAIL_STEP", "--build")
    with pytest.raises(ros2env.Skip, match=r"`cmake --build` failed building vision_msgs \(log: .*build.log\): "
                                           r"CMake Error: boom"):  # fmt: skip
        ros2env.build_vision_msgs(venv)
    assert "CMake Error: boom" in (work / "build.log").read_text()
    monkeypatch.setenv("PROBE_STATUS", "1")
    with pytest.raises(ros2env.Skip, match="cannot report its include folders"):
        ros2env.build_vision_msgs(venv)


def test_the_check_accepts_only_upstreams_type_hash(fake_venv, monkeypatch):
    venv, _ = fake_venv
    assert ros2env.check(venv) == UPSTREAM_TYPE_HASH["vision_msgs/msg/Detection3DArray"]
    monkeypatch.setenv("CHECK_OUT", _hash_line("RIHS01_other"))
    with pytest.raises(ros2env.Skip, match=r"the built Detection3DArray is .*RIHS01_other.*, not upstream's RIHS01_7"):
        ros2env.check(venv)
    monkeypatch.setenv("CHECK_STATUS", "1")
    monkeypatch.setenv("CHECK_OUT", "ImportError: vision_msgs")
    with pytest.raises(ros2env.Skip, match="cannot publish vision_msgs: ImportError: vision_msgs"):
        ros2env.check(venv)


def test_missing_build_tools_are_installed_or_named(tmp_path, monkeypatch):
    from symfruit.ros import debian

    tools = tmp_path / "tools"
    for tool in ("cmake", "cc", "c++", "make"):
        _script(tools / tool, "exit 0", tmp_path / "l")
    monkeypatch.setenv("PATH", str(tools))
    asked = []
    monkeypatch.setattr(debian, "apt_install", lambda packages: asked.append(packages) or "")
    ros2env._build_tools()  # all there: apt is not asked
    assert asked == []
    (tools / "c++").unlink()
    with pytest.raises(ros2env.Skip, match=r"no c\+\+ to build vision_msgs \(still missing after apt-get\)"):
        ros2env._build_tools()
    assert asked == [ros2env.APT_BUILD_TOOLS]
    monkeypatch.setattr(debian, "apt_install", lambda packages: "apt-get is not usable here")
    with pytest.raises(ros2env.Skip, match=r"no c\+\+ to build vision_msgs \(apt-get is not usable here\)"):
        ros2env._build_tools()


def test_ensure_builds_checks_and_records_then_finds_it_up_to_date(fake_venv, tmp_path, monkeypatch, capsys):
    venv, _ = fake_venv
    monkeypatch.setattr(ros2env, "_build_tools", lambda: None)
    with pytest.raises(ros2env.Skip, match="no project folder"):
        ros2env.ensure(venv, None)
    want = UPSTREAM_TYPE_HASH["vision_msgs/msg/Detection3DArray"]
    assert ros2env.main(["--venv", str(venv), "--project", str(tmp_path)]) == 0
    python = venv / "bin" / "python"
    assert capsys.readouterr().out == f"ros2-env: ok: {python} runs rclpy with vision_msgs ({want}, upstream's)\n"
    assert ros2env.status(venv) == {"key": ros2env.build_key(), "hash": want}
    assert ros2env.ensure(venv, tmp_path) == f"ros2-env: ok: {venv} up to date (vision_msgs {want})"
    (venv / ros2env.STATUS_FILE).unlink()
    monkeypatch.setattr(ros2env.sys, "prefix", str(venv))  # --here: this interpreter's venv, no pip install
    monkeypatch.setenv("PIP_STATUS", "1")
    assert ros2env.ensure(venv, None, here=True).startswith("ros2-env: ok:")
    monkeypatch.setenv("CHECK_STATUS", "1")
    (venv / ros2env.STATUS_FILE).unlink()
    assert ros2env.main(["--here", "--require"]) == 1
    assert capsys.readouterr().out.startswith(f"ros2-env: skipped: {venv / 'bin' / 'python'} cannot publish")
