"""Let this interpreter (the project's venv) use Debian's ROS 1 packages: ``python -m symfruit.ros.debian``.

Debian bookworm ships ROS 1 Noetic's Python side as ``python3-*`` packages in
``/usr/lib/python3/dist-packages``, for Debian's ``/usr/bin/python3`` (3.11). A venv made from another
Python 3.11 (pyenv's) cannot use ``--system-site-packages`` for them, and putting all of
dist-packages on its path would also expose Debian's pip, setuptools, six, ... to pip and pytest.
So this module

1. checks that Debian's python3 imports the ROS modules the node needs and, with ``--install``, runs
   ``apt-get install --no-install-recommends`` for :data:`APT_PACKAGES` when they are missing and
   apt is usable (root, or password-less sudo), with one ``apt-get update`` if the first try fails;
2. links exactly the dist-packages entries of those packages and their ``python3-*`` dependencies
   (per ``dpkg``) into ``<site-packages>/symfruit-debian-ros/``, leaving out every module and
   distribution the venv already has (its numpy, yaml, ... stay first and alone);
3. appends that folder to ``sys.path`` through ``zz-symfruit-debian-ros.pth`` (after site-packages), and
   checks that this interpreter now imports them.

It prints one line, ``ros-env: ok ...`` or ``ros-env: skipped: <reason>``; the exit status is 0 either way,
unless ``--require`` (CI) makes a skip an error.
"""

from __future__ import annotations

import argparse
import importlib.metadata
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

__all__ = ["APT_PACKAGES", "MODULES", "main"]

#: What the node, its test and the launch file use. python3-rosmaster gives `rosmaster`,
#: python3-roslaunch `roscore` and `roslaunch`.
APT_PACKAGES = (
    "python3-rospy",
    "python3-message-filters",
    "python3-sensor-msgs",
    "python3-visualization-msgs",
    "python3-geometry-msgs",
    "python3-std-msgs",
    "python3-genpy",
    "python3-genmsg",
    "python3-rosmaster",
    "python3-roslib",
    "python3-roslaunch",
)
#: Modules that must import for the node to run.
MODULES = (
    "rospy",
    "message_filters",
    "genpy",
    "genmsg",
    "std_msgs.msg",
    "geometry_msgs.msg",
    "sensor_msgs.msg",
    "visualization_msgs.msg",
    "rosmaster",
    "rosgraph",
)
DEBIAN_PYTHON = "/usr/bin/python3"
DIST = Path("/usr/lib/python3/dist-packages")
LINKS = "symfruit-debian-ros"
PTH = "zz-symfruit-debian-ros.pth"


def _run(cmd: list[str], **kw) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, capture_output=True, text=True, **kw)


def debian_missing() -> list[str]:
    """Modules of :data:`MODULES` that Debian's python3 cannot import (all of them if there is none)."""
    if not Path(DEBIAN_PYTHON).is_file():
        return list(MODULES)
    code = (
        "import importlib, sys\nmissing = []\nfor m in sys.argv[1:]:\n    try:\n        importlib.import_module(m)\n"
        "    except Exception:\n        missing.append(m)\nprint(' '.join(missing))"
    )
    out = _run([DEBIAN_PYTHON, "-c", code, *MODULES], env={"PATH": os.environ.get("PATH", "/usr/bin:/bin")})
    return out.stdout.split() if out.returncode == 0 else list(MODULES)


def _apt_prefix() -> list[str] | None:
    if shutil.which("apt-get") is None:
        return None
    if os.geteuid() == 0:
        return []
    if shutil.which("sudo") and _run(["sudo", "-n", "true"]).returncode == 0:
        return ["sudo", "-n"]
    return None


def apt_install(packages=APT_PACKAGES) -> str:
    """Install with apt-get; '' on success, else why not."""
    prefix = _apt_prefix()
    if prefix is None:
        return "apt-get is not usable here (not root, no password-less sudo)"
    env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
    cmd = [*prefix, "apt-get", "install", "-y", "-qq", "--no-install-recommends", *packages]
    res = _run(cmd, env=env)
    if res.returncode != 0:  # stale or missing package lists: update once and retry
        _run([*prefix, "apt-get", "update", "-qq"], env=env)
        res = _run(cmd, env=env)
    return "" if res.returncode == 0 else f"apt-get install failed: {(res.stderr or res.stdout).strip()[-500:]}"


def package_closure(roots=APT_PACKAGES) -> list[str]:
    """The installed python3-* packages among ``roots`` and their python3-* dependencies (dpkg)."""
    seen: set[str] = set()
    todo = list(roots)
    while todo:
        pkg = todo.pop()
        if pkg in seen:
            continue
        out = _run(["dpkg-query", "-W", "-f=${Status}\t${Depends}", pkg])
        if out.returncode != 0 or "installed" not in out.stdout.split("\t")[0]:
            continue
        seen.add(pkg)
        for alternative in out.stdout.split("\t", 1)[1].split(","):
            name = alternative.split("|")[0].strip().split(" ")[0].split(":")[0]
            if name.startswith("python3-") and name not in seen:
                todo.append(name)
    return sorted(seen)


def dist_entries(packages) -> list[Path]:
    """Top-level dist-packages entries (module folders, .py, .so, metadata) of the packages."""
    entries: set[Path] = set()
    for pkg in packages:
        for line in _run(["dpkg", "-L", pkg]).stdout.splitlines():
            if re.fullmatch(re.escape(str(DIST)) + r"/[^/]+", line) and Path(line).exists():
                entries.add(Path(line))
    return sorted(entries)


def _norm(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _own(entry: Path, own_dists: set[str], site: Path) -> bool:
    """Whether the venv already provides this entry's module or distribution."""
    name = entry.name
    if name.endswith((".dist-info", ".egg-info")):
        project = name.rsplit(".", 1)[0].split("-")[0]  # "PyYAML-6.0.dist-info" -> "PyYAML"
        return _norm(project) in own_dists
    module = name.split(".")[0]
    spec = importlib.util.find_spec(module) if module.isidentifier() else None
    return spec is not None and not str(spec.origin or "").startswith((str(DIST), str(site / LINKS)))


def link_farm(site: Path, entries: list[Path]) -> Path:
    """(Re)create ``site/LINKS`` with a symlink per entry the venv lacks, and the .pth that appends it."""
    folder = site / LINKS
    if folder.exists():
        shutil.rmtree(folder)
    (site / PTH).unlink(missing_ok=True)
    own = {_norm(d.metadata["Name"] or "") for d in importlib.metadata.distributions(path=[str(site)])}
    folder.mkdir()
    for entry in entries:
        if not _own(entry, own, site):
            (folder / entry.name).symlink_to(entry)
    (site / PTH).write_text(f"{folder}\n", encoding="utf-8")
    return folder


def venv_check(python: str = sys.executable) -> str:
    """'' when ``python`` imports every module of :data:`MODULES`, else the error."""
    res = _run([python, "-c", f"import {', '.join(MODULES)}"])
    return "" if res.returncode == 0 else (res.stderr.strip().splitlines() or ["import failed"])[-1]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m symfruit.ros.debian", description=__doc__.splitlines()[0])
    parser.add_argument("--install", action="store_true", help="apt-get install the packages when missing")
    parser.add_argument("--require", action="store_true", help="exit 1 instead of skipping (CI)")
    args = parser.parse_args(argv)

    def skip(why: str) -> int:
        print(f"ros-env: skipped: {why}; the ROS tests will be skipped")
        return 1 if args.require else 0

    missing = debian_missing()
    if missing and args.install:
        why = apt_install()
        if why:
            return skip(why)
        missing = debian_missing()
    if missing:
        return skip(f"Debian's python3 cannot import {', '.join(missing)} (apt-get install {' '.join(APT_PACKAGES)})")
    if shutil.which("dpkg-query") is None:
        return skip("no dpkg to find the packages' files")
    site = Path(sysconfig.get_path("purelib"))
    folder = link_farm(site, dist_entries(package_closure()))
    error = venv_check()
    if error:
        return skip(f"{sys.executable} still cannot import the ROS modules ({error})")
    debian = _run([DEBIAN_PYTHON, "-c", "import sys; print('%d.%d' % sys.version_info[:2])"]).stdout.strip()
    ours = f"{sys.version_info[0]}.{sys.version_info[1]}"
    note = (
        ""
        if debian == ours
        else f"; warning: Debian's Python is {debian}, this one {ours} (compiled modules may not load)"
    )
    print(f"ros-env: ok: {sys.executable} sees {len(list(folder.iterdir()))} Debian entries via {site / PTH}{note}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
