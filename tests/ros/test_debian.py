"""symfruit.ros.debian (`make ros-env`): the venv sees Debian's ROS packages, never instead of its own."""

from __future__ import annotations

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
