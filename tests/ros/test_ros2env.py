"""symfruit.ros.ros2env (`make ros2-env`): upstream's type hashes, the package it builds, when it rebuilds, and
what the build made (the running node's hash is checked on the ROS graph in test_node2.py)."""

from __future__ import annotations

import json
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
    res = subprocess.run([cmake, "-P", str(script)], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip().endswith("/venv/include/python3.11;/keep/me;/venv/lib/numpy/include")


def test_build_key_follows_the_build_and_the_python(monkeypatch):
    key = ros2env.build_key("3.11")
    assert key == ros2env.build_key("3.11") and key != ros2env.build_key("3.12")
    monkeypatch.setattr(ros2env, "BUILD_VERSION", "something else")
    assert ros2env.build_key("3.11") != key


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
