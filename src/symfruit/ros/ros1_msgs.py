"""ROS 1 ``vision_msgs`` message classes, generated at run time with genpy from the shipped definitions.

Debian packages ROS 1 (``python3-genpy``, ``python3-sensor-msgs``, ...) but not ``vision_msgs``. The
project ships the upstream noetic definitions (``vision_msgs`` 0.0.2, ``msg/ros1/vision_msgs/*.msg``,
verbatim) and this module turns them into genpy classes, exactly as ``catkin_make`` would: the
dependencies (``std_msgs/Header``, ``geometry_msgs/...``, ``sensor_msgs/PointCloud2``) come from the
installed packages' own definitions, the md5sums are computed by genmsg, and the result is checked
against the md5sums the upstream package publishes (:data:`UPSTREAM_MD5`). A node publishing these
classes is received by any subscriber built against the real ``ros-noetic-vision-msgs``.

If a real ``vision_msgs`` package is importable (a ROS installation that has it), it is used instead,
after the same md5 check.
"""

from __future__ import annotations

import atexit
import importlib.util
import shutil
import sys
import tempfile
import types
from importlib import resources
from pathlib import Path

from ..errors import SymfruitError

__all__ = ["UPSTREAM_MD5", "load_vision_msgs"]

#: md5sums of ros-noetic-vision-msgs 0.0.2 as published in the upstream package's generated code
#: (gencpp/gennodejs/rosserial output of the released package). genmsg's md5 ignores comments and
#: whitespace: it hashes the field declarations with every nested type replaced by its own md5.
UPSTREAM_MD5 = {
    "vision_msgs/ObjectHypothesisWithPose": "fa1ab3bc7146f53921fa142d631d02db",
    "vision_msgs/BoundingBox3D": "727c83f2b037373b8e968433d9c84ecb",
    "vision_msgs/Detection3D": "7f3d8e29f3ab9853108801543aec1a5d",
    "vision_msgs/Detection3DArray": "05c51d9aea1fb4cfdc8effb94f197b6f",
}

#: Generation order: every type after the types it contains.
_TYPES = ("ObjectHypothesisWithPose", "BoundingBox3D", "Detection3D", "Detection3DArray")
#: Installed message classes whose definitions (with their own dependencies) the vision types need.
_DEPENDENCIES = (
    "std_msgs/Header",
    "geometry_msgs/PoseWithCovariance",
    "geometry_msgs/Vector3",
    "sensor_msgs/PointCloud2",
)
_SEPARATOR = "\n" + "=" * 80 + "\n"

_cache: types.ModuleType | None = None


def _missing(what: str) -> SymfruitError:
    return SymfruitError(
        f"the ROS node needs {what}; on Debian/Ubuntu: sudo apt-get install python3-rospy "
        "python3-message-filters python3-sensor-msgs python3-visualization-msgs python3-geometry-msgs "
        "python3-genpy python3-rosmaster, then `make ros-env` so the project's venv sees them"
    )


def definition(name: str) -> str:
    """The shipped upstream ROS 1 definition (``.msg`` text) of ``vision_msgs/NAME``."""
    return (resources.files(__package__) / "msg" / "ros1" / "vision_msgs" / f"{name}.msg").read_text(encoding="utf-8")


def _installed_class(full_name: str):
    pkg, name = full_name.split("/")
    try:
        module = __import__(f"{pkg}.msg", fromlist=[name])
        return getattr(module, name)
    except (ImportError, AttributeError):
        raise _missing(f"the ROS 1 message package {pkg} (python3-{pkg.replace('_', '-')})") from None


def _check(module: types.ModuleType, where: str) -> types.ModuleType:
    for name in _TYPES:
        cls = getattr(module, name, None)
        full = f"vision_msgs/{name}"
        if cls is None or getattr(cls, "_md5sum", None) != UPSTREAM_MD5[full]:
            got = getattr(cls, "_md5sum", "missing")
            raise SymfruitError(f"{where}: {full} has md5sum {got}, upstream noetic has {UPSTREAM_MD5[full]}")
    return module


def _import_package(name: str, folder: Path) -> types.ModuleType:
    spec = importlib.util.spec_from_file_location(
        name, folder / "__init__.py", submodule_search_locations=[str(folder)]
    )
    if spec is None or spec.loader is None:  # pragma: no cover - a folder we just wrote
        raise SymfruitError(f"cannot import the generated {name} from {folder}")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    return module


def _generate() -> types.ModuleType:
    try:
        import genmsg
        import genmsg.msg_loader
        from genpy.generator import msg_generator
    except ImportError:
        raise _missing("genpy and genmsg (python3-genpy)") from None

    context = genmsg.MsgContext.create_default()
    for dep in _DEPENDENCIES:  # register the installed definitions: `_full_text` is the type then its deps
        sections = _installed_class(dep)._full_text.split(_SEPARATOR)
        genmsg.msg_loader.load_msg_from_string(context, sections[0], dep)
        for section in sections[1:]:
            header, _, text = section.partition("\n")
            genmsg.msg_loader.load_msg_from_string(context, text, header[len("MSG: ") :].strip())
    specs = {
        name: genmsg.msg_loader.load_msg_from_string(context, definition(name), f"vision_msgs/{name}")
        for name in _TYPES
    }

    # Write the package catkin would have built (vision_msgs/msg/_Type.py per type) to a private temporary
    # folder, removed at exit, and import it from there under its real name.
    root = Path(tempfile.mkdtemp(prefix="symfruit-vision-msgs-"))
    atexit.register(shutil.rmtree, root, ignore_errors=True)
    msg_dir = root / "vision_msgs" / "msg"
    msg_dir.mkdir(parents=True)
    (root / "vision_msgs" / "__init__.py").write_text('"""vision_msgs generated by symfruit.ros.ros1_msgs."""\n')
    (msg_dir / "__init__.py").write_text("".join(f"from ._{n} import *\n" for n in _TYPES))
    for name in _TYPES:
        (msg_dir / f"_{name}.py").write_text("\n".join(msg_generator(context, specs[name], {})) + "\n")
    package = _import_package("vision_msgs", root / "vision_msgs")
    msg = _import_package("vision_msgs.msg", msg_dir)
    setattr(package, "msg", msg)  # noqa: B010 - a module attribute mypy does not know
    setattr(msg, "_symfruit_generated", True)  # noqa: B010
    return _check(msg, "generated vision_msgs")


def load_vision_msgs() -> types.ModuleType:
    """The ``vision_msgs.msg`` module (classes ``Detection3DArray``, ``Detection3D``, ``BoundingBox3D``,
    ``ObjectHypothesisWithPose``): the installed package if there is one, else generated once per process.

    Raises
    ------
    SymfruitError
        When genpy or the ROS 1 message packages are missing (naming what to install), or when an
        installed ``vision_msgs`` is not the noetic one (its md5sums differ).
    """
    global _cache
    if _cache is not None:
        return _cache
    try:
        import vision_msgs.msg as found
    except ImportError:
        found = None
    if found is None:
        _cache = _generate()
    elif getattr(found, "_symfruit_generated", False):
        _cache = _check(found, "vision_msgs generated earlier")
    else:
        _cache = _check(found, f"the installed vision_msgs ({getattr(found, '__file__', '?')})")
    return _cache
