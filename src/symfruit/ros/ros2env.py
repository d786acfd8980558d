"""ROS 2 for ``symfruit ros2``: a venv of its own with the ROS 2 wheels and vision_msgs built from the shipped
upstream definitions: ``python -m symfruit.ros.ros2env`` (``make ros2-env``).

The package index has wheels of ROS 2 Kilted (rclpy, Fast DDS, the message packages and the rosidl
generators; the extra ``symfruit[ros2]`` lists them) but none of vision_msgs. So this module

1. makes the venv (default ``.venv-ros2``) and installs the project into it, editable, with the extra
   ``ros2`` (``--here``: use the running interpreter's venv instead, which must have them);
2. makes sure cmake and a C/C++ compiler are there (``apt-get install cmake g++ make`` when missing and
   apt is usable: root or password-less sudo);
3. builds the type support of the detection messages (``msg/ros2/vision_msgs``, vision_msgs 4.x verbatim)
   with ``rosidl_generate_interfaces`` and installs it into the venv, which the wheels lay out like a ROS
   install space (``lib/``, ``share/``, ``lib/pythonX.Y/site-packages``). The wheels were built on a
   manylinux machine and their CMake targets name its Python and numpy include folders
   (``/opt/python/cp3xx-cp3xx/...``); :data:`CMAKELISTS` points them at this venv's own;
4. checks that the venv's rclpy publishes ``vision_msgs/msg/Detection3DArray`` with upstream's type hash
   (:data:`UPSTREAM_TYPE_HASH`, REP-2011), and records the build in ``<venv>/symfruit-ros2-env.json``;
   a second run with the same inputs (:func:`build_key`) only says so.

Why a venv of its own: the ROS 2 wheels add a ``.pth`` start-up hook (``ros_wheels_bootstrapper``) that
re-executes every interpreter start of their venv with ``LD_LIBRARY_PATH`` set to its libraries, and
they install top-level ``std_msgs``, ``sensor_msgs``, ``geometry_msgs`` and ``visualization_msgs``, the
import names of the ROS 1 packages that ``make ros-env`` lets the project's ``.venv`` see: in one venv the
ROS 2 modules would shadow ROS 1's and break ``symfruit ros``. Tests in ``.venv`` start ROS 2 processes
with ``<venv>/bin/python``.

It prints one line, ``ros2-env: ok ...`` or ``ros2-env: skipped: <reason>``; the exit status is 0 either
way, unless ``--require`` (CI) makes a skip an error.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
from importlib import resources
from pathlib import Path

__all__ = [
    "DEFAULT_VENV",
    "MESSAGES",
    "UPSTREAM_TYPE_HASH",
    "build_key",
    "main",
    "ros2_python",
    "status",
    "write_package",
]

DEFAULT_VENV = ".venv-ros2"
STATUS_FILE = "symfruit-ros2-env.json"
#: Built in dependency order (rosidl does not mind the order; the list is also the package's content).
MESSAGES = ("ObjectHypothesis", "ObjectHypothesisWithPose", "BoundingBox3D", "Detection3D", "Detection3DArray")
#: REP-2011 type hashes of upstream vision_msgs 4.x (unchanged since 4.0.0), as upstream's build writes them into
#: ``share/vision_msgs/msg/*.json``; rosbags computes the same from the shipped definitions (tests/ros/test_ros2env.py).
UPSTREAM_TYPE_HASH = {
    f"vision_msgs/msg/{name}": f"RIHS01_{digest}"
    for name, digest in [
        ("Detection3DArray", "793f5eab9595ac1c0da07873cc859db42eae51f0ee76056db8562515d830e018"),
        ("Detection3D", "ddd703be132ab0b69d33121f1bb034132bfbb3b0ac5f9fb1516005ba1c8a265b"),
        ("BoundingBox3D", "bbb73a65c163d7f9bb29009c7bde9f7faa576bd2d23299c4511d19230dab4698"),
        ("ObjectHypothesisWithPose", "41c12344c0396c48b81df12467c192d99b2a0eb1463c5c37194e4223251c80bc"),
        ("ObjectHypothesis", "51da43cec11c01957a64d1e05a24acd18aae7745ec30b74348ad5f6d634f7f90"),
    ]
}
#: Debian packages of the build tools (installed only when one is missing).
APT_BUILD_TOOLS = ("cmake", "g++", "make")
#: Bumped whenever the build below changes, so that an existing venv is rebuilt.
BUILD_VERSION = "1"

PACKAGE_XML = """<?xml version="1.0"?>
<package format="3">
  <name>vision_msgs</name>
  <version>4.1.1</version>
  <description>The detection messages of upstream vision_msgs 4.x (ros-perception/vision_msgs), built by symfruit's
    `make ros2-env` from the verbatim definitions it ships.</description>
  <maintainer email="symfruit@example.com">symfruit</maintainer>
  <license>Apache-2.0</license>
  <buildtool_depend>ament_cmake</buildtool_depend>
  <buildtool_depend>rosidl_default_generators</buildtool_depend>
  <depend>std_msgs</depend>
  <depend>geometry_msgs</depend>
  <exec_depend>rosidl_default_runtime</exec_depend>
  <member_of_group>rosidl_interface_packages</member_of_group>
  <export><build_type>ament_cmake</build_type></export>
</package>
"""

CMAKELISTS = """cmake_minimum_required(VERSION 3.16)
project(vision_msgs)
find_package(ament_cmake REQUIRED)
find_package(rosidl_default_generators REQUIRED)
find_package(std_msgs REQUIRED)
find_package(geometry_msgs REQUIRED)
rosidl_generate_interfaces(${PROJECT_NAME}
  @MESSAGES@
  DEPENDENCIES std_msgs geometry_msgs)
ament_export_dependencies(rosidl_default_runtime)
ament_package()

# The wheels' exported targets name the include folders of the machine they were built on; use this venv's.
get_property(_imported DIRECTORY PROPERTY IMPORTED_TARGETS)
foreach(_target IN LISTS _imported)
  get_target_property(_dirs ${_target} INTERFACE_INCLUDE_DIRECTORIES)
  if(_dirs)
    list(TRANSFORM _dirs REPLACE "^/opt/python/[^/]+/include/python[0-9.]+$" "${SYMFRUIT_PYTHON_INCLUDE}")
    list(TRANSFORM _dirs REPLACE "^/opt/python/[^/]+/lib/python[0-9.]+/site-packages/numpy/_core/include$"
         "${SYMFRUIT_NUMPY_INCLUDE}")
    set_target_properties(${_target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_dirs}")
  endif()
endforeach()
"""

#: Run by the venv's interpreter: the runtime type hash of Detection3DArray (a publisher's graph entry).
_CHECK = """
import json, sys, rclpy
from vision_msgs.msg import Detection3DArray
context = rclpy.Context()
rclpy.init(context=context, domain_id=int(sys.argv[1]))
try:
    node = rclpy.create_node("symfruit_ros2env_check", context=context)
    node.create_publisher(Detection3DArray, "/symfruit_ros2env_check", 1)
    (info,) = node.get_publishers_info_by_topic("/symfruit_ros2env_check")
    print(json.dumps({"type": info.topic_type, "hash": str(info.topic_type_hash)}))
    node.destroy_node()
finally:
    rclpy.try_shutdown(context=context)
"""


def definition_files() -> list[Path]:
    """The shipped upstream ``.msg`` files, in :data:`MESSAGES` order."""
    folder = resources.files(__package__) / "msg" / "ros2" / "vision_msgs"
    return [Path(str(folder / f"{name}.msg")) for name in MESSAGES]


#: The project's extras the venv gets: the ROS 2 wheels, and the compiled kernels with their BLAS limits (without
#: numba the node runs the kernels' numpy twins: 151 against 38 ms a frame, stop 53).
EXTRAS = ("ros2", "fast")


def build_key(python_version: str = f"{sys.version_info[0]}.{sys.version_info[1]}") -> str:
    """What a build depends on: the definitions, this build, the extras' requirements and the Python version."""
    from importlib.metadata import PackageNotFoundError, requires

    marks = [f'extra == "{name}"' for name in EXTRAS]
    try:
        extra = sorted(r for r in (requires("symfruit") or []) if any(m in r.replace("'", '"') for m in marks))
    except PackageNotFoundError:
        extra = []
    h = hashlib.sha256(f"{BUILD_VERSION}\n{python_version}\n{extra}\n{PACKAGE_XML}\n{CMAKELISTS}".encode())
    for path in definition_files():
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def write_package(folder: Path) -> Path:
    """Write the ament package of the definitions (``package.xml``, ``CMakeLists.txt``, ``msg/``) into
    ``folder`` (created); returns it."""
    (folder / "msg").mkdir(parents=True, exist_ok=True)
    for path in definition_files():
        shutil.copyfile(path, folder / "msg" / path.name)
    (folder / "package.xml").write_text(PACKAGE_XML, encoding="utf-8")
    listed = "\n  ".join(f"msg/{name}.msg" for name in MESSAGES)
    (folder / "CMakeLists.txt").write_text(CMAKELISTS.replace("@MESSAGES@", listed), encoding="utf-8")
    return folder


def ros2_python(venv: Path) -> Path:
    return venv / "bin" / "python"


def status(venv: Path) -> dict:
    """The record of the last successful build in ``venv`` ({} without one)."""
    try:
        return json.loads((venv / STATUS_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}


def _run(cmd: list[str], *, env: dict | None = None, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=cwd)


def _tail(res: subprocess.CompletedProcess) -> str:
    text = (res.stderr or "") + (res.stdout or "")
    lines = [ln for ln in text.splitlines() if ln.strip() and "WARNING: Location" not in ln]
    return " | ".join(lines[-6:])[-1500:]


class Skip(Exception):
    """The environment cannot be made here; the message says why."""


def _build_tools() -> None:
    missing = [tool for tool in ("cmake", "cc", "c++", "make") if shutil.which(tool) is None]
    if not missing:
        return
    from .debian import apt_install

    why = apt_install(APT_BUILD_TOOLS)
    if why or any(shutil.which(tool) is None for tool in missing):
        raise Skip(f"no {', '.join(missing)} to build vision_msgs ({why or 'still missing after apt-get'})")


def make_venv(venv: Path, project: Path) -> None:
    """Create ``venv`` (when missing) and install ``project[ros2,fast]`` (:data:`EXTRAS`) into it, editable."""
    if not ros2_python(venv).exists():
        res = _run([sys.executable, "-m", "venv", str(venv)])
        if res.returncode != 0:
            raise Skip(f"cannot create {venv}: {_tail(res)}")
    pip = [str(ros2_python(venv)), "-m", "pip", "install", "--quiet", "--disable-pip-version-check"]
    res = _run([*pip, "--upgrade", "pip"])
    res = _run([*pip, "-e", f"{project}[{','.join(EXTRAS)}]"])
    if res.returncode != 0:
        raise Skip(f"pip could not install the ROS 2 wheels into {venv}: {_tail(res)}")
    # `pytest --cov` in the project's venv measures the subprocesses it starts only where coverage is importable:
    # the ROS 2 node and stand-in camera run here, so the same coverage goes here too (the project's tests only)
    try:
        import coverage
    except ImportError:
        return
    _run([*pip, f"coverage=={coverage.__version__}"])  # not fatal: without it only the measurement is lost


def build_vision_msgs(venv: Path) -> None:
    """Configure, build and install vision_msgs into ``venv`` (its interpreter, CMake packages and libraries)."""
    python = str(ros2_python(venv))
    probe = _run([python, "-c", "import sysconfig, numpy; print(sysconfig.get_paths()['include']); "
                  "print(numpy.get_include())"])  # fmt: skip
    if probe.returncode != 0:
        raise Skip(f"{python} cannot report its include folders: {_tail(probe)}")
    py_include, np_include = probe.stdout.split()[-2:]
    work = venv / "build" / "vision_msgs"
    if work.exists():
        shutil.rmtree(work)
    source = write_package(work / "src")
    env = {**os.environ, "PATH": f"{venv / 'bin'}{os.pathsep}{os.environ.get('PATH', '/usr/bin:/bin')}",
           "AMENT_PREFIX_PATH": str(venv), "CMAKE_PREFIX_PATH": str(venv)}  # fmt: skip
    for key in ("PYTHONPATH", "PYTHONHOME", "COLCON_PREFIX_PATH"):
        env.pop(key, None)
    steps = [
        ["cmake", "-S", str(source), "-B", str(work / "build"), f"-DCMAKE_INSTALL_PREFIX={venv}",
         "-DCMAKE_BUILD_TYPE=Release", "-DBUILD_TESTING=OFF", f"-DPython3_EXECUTABLE={python}",
         f"-DSYMFRUIT_PYTHON_INCLUDE={py_include}", f"-DSYMFRUIT_NUMPY_INCLUDE={np_include}"],
        ["cmake", "--build", str(work / "build"), "--parallel", str(os.cpu_count() or 1)],
        ["cmake", "--install", str(work / "build")],
    ]  # fmt: skip
    for cmd in steps:
        res = _run(cmd, env=env)
        if res.returncode != 0:
            (work / "build.log").write_text(res.stdout + res.stderr, encoding="utf-8")
            raise Skip(f"`{' '.join(cmd[:2])}` failed building vision_msgs (log: {work / 'build.log'}): {_tail(res)}")


def check(venv: Path) -> str:
    """Detection3DArray's type hash as the venv's rclpy publishes it; raises :class:`Skip` unless upstream's."""
    env = {**os.environ, "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST", "ROS_LOG_DIR": str(venv / "log")}
    res = _run([str(ros2_python(venv)), "-c", _CHECK, "101"], env=env)  # only its own publisher: any domain
    if res.returncode != 0:
        raise Skip(f"{ros2_python(venv)} cannot publish vision_msgs: {_tail(res)}")
    got = json.loads(res.stdout.strip().splitlines()[-1])
    want = UPSTREAM_TYPE_HASH["vision_msgs/msg/Detection3DArray"]
    if got != {"type": "vision_msgs/msg/Detection3DArray", "hash": want}:
        raise Skip(f"the built Detection3DArray is {got}, not upstream's {want}")
    return got["hash"]


def ensure(venv: Path, project: Path | None, *, here: bool = False) -> str:
    """Make (or find up to date) the ROS 2 venv; returns the line to print. Raises :class:`Skip`."""
    key = build_key()
    if status(venv).get("key") == key and ros2_python(venv).exists():
        return f"ros2-env: ok: {venv} up to date (vision_msgs {status(venv)['hash']})"
    if not here:
        if project is None:
            raise Skip("no project folder to install into the venv (--project)")
        make_venv(venv, project)
    _build_tools()
    build_vision_msgs(venv)
    type_hash = check(venv)
    (venv / STATUS_FILE).write_text(json.dumps({"key": key, "hash": type_hash}) + "\n", encoding="utf-8")
    return f"ros2-env: ok: {ros2_python(venv)} runs rclpy with vision_msgs ({type_hash}, upstream's)"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m symfruit.ros.ros2env", description=__doc__.splitlines()[0])
    parser.add_argument("--venv", type=Path, default=Path(DEFAULT_VENV), help=f"venv to make (default {DEFAULT_VENV})")
    parser.add_argument("--project", type=Path, default=Path("."), help="project folder to install (default .)")
    parser.add_argument("--here", action="store_true",
                        help="build into this interpreter's venv (which has symfruit[ros2]) instead")  # fmt: skip
    parser.add_argument("--require", action="store_true", help="exit 1 instead of skipping (CI)")
    args = parser.parse_args(argv)
    venv = Path(sys.prefix) if args.here else args.venv.absolute()
    try:
        print(ensure(venv, args.project.absolute(), here=args.here))
    except Skip as why:
        print(f"ros2-env: skipped: {why}; the ROS 2 tests will be skipped")
        return 1 if args.require else 0
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
