"""symfruit.ros.debian (`make ros-env`): the venv sees Debian's ROS packages, never instead of its own."""

from __future__ import annotations

import pytest

from symfruit.ros import debian


def test_link_farm_links_only_what_the_venv_lacks(tmp_path):
    dist = tmp_path / "dist-packages"
    for name in ("zz_fake_rospy", "numpy", "PyYAML-6.0.dist-info", "zz_fake_rospy-1.0.egg-info"):
        (dist / name).mkdir(parents=True)
    (dist / "zz_fake_em.py").write_text("")
    site = tmp_path / "site-packages"
    (site / "PyYAML-6.0.dist-info").mkdir(parents=True)
    (site / "PyYAML-6.0.dist-info" / "METADATA").write_text("Metadata-Version: 2.1\nName: PyYAML\nVersion: 6.0\n")
    folder = debian.link_farm(site, sorted(dist.iterdir()))
    linked = sorted(p.name for p in folder.iterdir())
    assert linked == ["zz_fake_em.py", "zz_fake_rospy", "zz_fake_rospy-1.0.egg-info"]  # not numpy, not PyYAML
    assert all((folder / n).resolve() == (dist / n).resolve() for n in linked)
    assert (site / debian.PTH).read_text().strip() == str(folder)
    again = debian.link_farm(site, [dist / "zz_fake_rospy"])  # re-running replaces the farm
    assert sorted(p.name for p in again.iterdir()) == ["zz_fake_rospy"]


def test_skip_is_visible_and_only_an_error_when_required(monkeypatch, capsys):
    monkeypatch.setattr(debian, "debian_missing", lambda: ["rospy"])
    monkeypatch.setattr(debian, "apt_install", lambda: "apt-get is not usable here (not root, no password-less sudo)")
    assert debian.main(["--install"]) == 0
    assert "ros-env: skipped: apt-get is not usable" in capsys.readouterr().out
    assert debian.main(["--install", "--require"]) == 1


# --- the installer's steps against stand-in commands (a folder of shell scripts first on PATH) ---------------


def _script(folder, name: str, body: str):
    """An executable shell script ``folder/name`` that logs its arguments to ``folder/calls`` then runs ``body``."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(f'#!/bin/sh\necho "{name} $*" >> "{folder}/calls"\n{body}\n')
    path.chmod(0o755)
    return path


def _calls(folder) -> list[str]:
    log = folder / "calls"
    return log.read_text().splitlines() if log.exists() else []


@pytest.fixture
def fake_bin(tmp_path, monkeypatch):
    """An empty folder of stand-in commands, alone on PATH (a test adds the commands it needs; they use shell
    built-ins only)."""
    folder = tmp_path / "bin"
    folder.mkdir()
    monkeypatch.setenv("PATH", str(folder))
    return folder


def test_what_debians_python_cannot_import_is_listed(fake_bin, monkeypatch):
    monkeypatch.setattr(debian, "DEBIAN_PYTHON", str(fake_bin / "no-such-python"))
    assert debian.debian_missing() == list(debian.MODULES)  # no Debian python at all
    python = _script(fake_bin, "python3", 'echo "rospy genpy"')
    monkeypatch.setattr(debian, "DEBIAN_PYTHON", str(python))
    assert debian.debian_missing() == ["rospy", "genpy"]
    assert (fake_bin / "calls").read_text().endswith(" ".join(debian.MODULES) + "\n")  # asked about each module
    _script(fake_bin, "python3", "exit 1")
    assert debian.debian_missing() == list(debian.MODULES)  # a python that fails imports nothing


def test_apt_is_used_as_root_through_password_less_sudo_or_not_at_all(fake_bin, monkeypatch):
    assert debian._apt_prefix() is None  # no apt-get
    _script(fake_bin, "apt-get", "exit 0")
    monkeypatch.setattr(debian.os, "geteuid", lambda: 0)
    assert debian._apt_prefix() == []
    monkeypatch.setattr(debian.os, "geteuid", lambda: 1000)
    assert debian._apt_prefix() is None  # no sudo
    _script(fake_bin, "sudo", "exit 1")  # sudo asks for a password
    assert debian._apt_prefix() is None
    _script(fake_bin, "sudo", "exit 0")
    assert debian._apt_prefix() == ["sudo", "-n"]
    assert debian.apt_install(("python3-x",)) == ""
    assert _calls(fake_bin)[-1] == "sudo -n apt-get install -y -qq --no-install-recommends python3-x"


def test_apt_install_updates_once_when_the_first_try_fails_and_reports_the_error(fake_bin, monkeypatch):
    monkeypatch.setattr(debian.os, "geteuid", lambda: 0)
    assert debian.apt_install() == "apt-get is not usable here (not root, no password-less sudo)"
    # fails until `apt-get update` has run (stale package lists)
    _script(fake_bin, "apt-get", f'[ "$1" = update ] && : > "{fake_bin}/updated"; [ -e "{fake_bin}/updated" ]')
    assert debian.apt_install(("python3-x",)) == ""
    assert [c.split()[1] for c in _calls(fake_bin)] == ["install", "update", "install"]
    _script(fake_bin, "apt-get", 'echo "E: Unable to locate package python3-x" >&2; exit 100')
    assert debian.apt_install(("python3-x",)) == "apt-get install failed: E: Unable to locate package python3-x"


DPKG_QUERY = """case "$3" in
  python3-rospy) printf 'install ok installed\\tpython3-genpy (>= 0.6), python3-yaml | python3-ruamel, libc6:any' ;;
  python3-genpy) printf 'install ok installed\\tpython3-genmsg:any, python3-rospy' ;;
  python3-genmsg) printf 'install ok installed\\t' ;;
  python3-ruamel) printf 'install ok installed\\t' ;;
  python3-yaml) printf 'deinstall ok config-files\\t' ;;
  *) exit 1 ;;
esac"""


def test_the_package_closure_follows_installed_python3_dependencies(fake_bin):
    _script(fake_bin, "dpkg-query", DPKG_QUERY)
    # versions and architectures stripped, the first of alternatives taken, removed and unknown packages left out
    assert debian.package_closure(("python3-rospy", "python3-unknown")) == [
        "python3-genmsg", "python3-genpy", "python3-rospy"]  # fmt: skip


def test_only_top_level_dist_packages_entries_that_exist_are_taken(fake_bin, tmp_path, monkeypatch):
    dist = tmp_path / "dist-packages"
    for name in ("rospy", "genpy", "rospy-1.0.egg-info"):
        (dist / name).mkdir(parents=True)
    monkeypatch.setattr(debian, "DIST", dist)
    listing = [f"{dist}/rospy", f"{dist}/rospy/__init__.py", f"{dist}/rospy-1.0.egg-info", f"{dist}/gone",
               "/usr/share/doc/python3-rospy", f"{dist}/genpy"]  # fmt: skip
    _script(fake_bin, "dpkg", 'case "$2" in python3-rospy) printf "%s\\n" ' + " ".join(listing[:5]) + " ;; "
            f'python3-genpy) echo {listing[5]} ;; esac')  # fmt: skip
    assert debian.dist_entries(["python3-rospy", "python3-genpy"]) == sorted(
        [dist / "genpy", dist / "rospy", dist / "rospy-1.0.egg-info"])  # fmt: skip


def test_the_venv_check_reports_the_import_error(fake_bin):
    good = _script(fake_bin, "good-python", "exit 0")
    bad = _script(fake_bin, "bad-python", 'echo "Traceback ..." >&2; echo "ModuleNotFoundError: rospy" >&2; exit 1')
    silent = _script(fake_bin, "silent-python", "exit 1")
    assert debian.venv_check(str(good)) == ""
    assert _calls(fake_bin)[0] == f"good-python -c import {', '.join(debian.MODULES)}"
    assert debian.venv_check(str(bad)) == "ModuleNotFoundError: rospy"
    assert debian.venv_check(str(silent)) == "import failed"


def test_main_links_the_packages_and_says_what_it_did(fake_bin, tmp_path, monkeypatch, capsys):
    """The whole run: Debian's python imports the modules after apt-get, the farm is made in site-packages,
    the venv imports them, and a Python version that differs from Debian's is named."""
    dist = tmp_path / "dist-packages"
    (dist / "zz_fake_rospy").mkdir(parents=True)
    monkeypatch.setattr(debian, "DIST", dist)
    site = tmp_path / "site-packages"
    site.mkdir()
    monkeypatch.setattr(debian.sysconfig, "get_path", lambda name: str(site))
    monkeypatch.setattr(debian.os, "geteuid", lambda: 0)
    _script(fake_bin, "apt-get", f': > "{fake_bin}/installed"')
    python = _script(fake_bin, "python3", f'case "$2" in *version_info*) echo 3.9 ;; *) [ -e "{fake_bin}/installed" ] '
                     f'|| echo rospy ;; esac')  # fmt: skip
    monkeypatch.setattr(debian, "DEBIAN_PYTHON", str(python))
    _script(fake_bin, "dpkg-query", DPKG_QUERY)
    _script(fake_bin, "dpkg", f'echo "{dist}/zz_fake_rospy"')
    monkeypatch.setattr(debian, "venv_check", lambda: "")
    assert debian.main([]) == 0  # without --install nothing is installed: a skip
    assert "skipped: Debian's python3 cannot import rospy (apt-get install python3-rospy" in capsys.readouterr().out
    assert debian.main(["--install", "--require"]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"ros-env: ok: {debian.sys.executable} sees 1 Debian entries via {site / debian.PTH}")
    assert "warning: Debian's Python is 3.9, this one 3." in out
    assert (site / debian.LINKS / "zz_fake_rospy").resolve() == dist / "zz_fake_rospy"
    monkeypatch.setattr(debian, "venv_check", lambda: "ModuleNotFoundError: rospy")
    assert debian.main(["--require"]) == 1
    assert "still cannot import the ROS modules (ModuleNotFoundError: rospy)" in capsys.readouterr().out
    (fake_bin / "dpkg-query").unlink()
    assert debian.main([]) == 0
    assert "skipped: no dpkg to find the packages' files" in capsys.readouterr().out


def test_a_failed_install_is_the_reason_given(fake_bin, monkeypatch, capsys):
    monkeypatch.setattr(debian, "DEBIAN_PYTHON", str(fake_bin / "none"))
    monkeypatch.setattr(debian.os, "geteuid", lambda: 0)
    _script(fake_bin, "apt-get", "echo 'E: no space left' >&2; exit 100")
    assert debian.main(["--install", "--require"]) == 1
    assert "ros-env: skipped: apt-get install failed: E: no space left" in capsys.readouterr().out
