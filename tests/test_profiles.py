"""Fruit profiles: shipped settings per fruit kind, and a user's own profile files."""

import pytest

from symfruit import ConfigError, Settings
from symfruit.profiles import available_profiles, load_profile, profile_data


def test_profiles_ship_and_load(tmp_path):
    assert {"strawberry", "apple", "citrus", "tomato"} <= set(available_profiles())
    assert load_profile("strawberry").fused.revolution is True
    assert load_profile("apple").fused.mirror_weight == 0.25
    assert load_profile("apple").evidence.cut_width == 1.0  # a round fruit: a cut outline's larger width
    assert Settings().evidence.cut_width == 0.0 and load_profile("strawberry").evidence.cut_width == 0.0
    mine = tmp_path / "pear.yaml"
    mine.write_text("fused:\n  depth_ratio: 1.3\n")
    assert load_profile(mine).fused.depth_ratio == 1.3
    with pytest.raises(ConfigError, match="no fruit profile 'banana'"):
        load_profile("banana")
    bad = tmp_path / "bad.yaml"
    bad.write_text("fused:\n  mirror_weight: 2\n")
    with pytest.raises(ConfigError, match=r"fused\.mirror_weight: must be <= 1"):
        load_profile(bad)


def test_every_shipped_profile_is_valid_and_changes_something():
    names = available_profiles()
    assert names == sorted(names) and len(names) == len(set(names))
    for name in names:
        label, data = profile_data(name)
        assert label == f"profile {name}" and isinstance(data, dict) and data
        assert load_profile(name) != Settings()


def test_profiles_lay_over_a_base_and_files_are_read_by_extension(tmp_path):
    base = Settings().replace(paper={"translations": 2})
    s = load_profile("citrus", base=base)
    assert s.paper.translations == 2 and s.fused.depth_ratio == 1.1
    mine = tmp_path / "kiwi.json"
    mine.write_text('{"fused": {"huber": 0.004}}')
    label, data = profile_data(mine)
    assert label == str(mine) and data == {"fused": {"huber": 0.004}}
    assert load_profile(mine).fused.huber == 0.004
    with pytest.raises(ConfigError, match=r"no fruit profile 'kiwi'; shipped: apple, citrus, strawberry, tomato"):
        load_profile("kiwi")  # a name, not a file: only the shipped ones
    with pytest.raises(ConfigError, match="no such settings file"):
        load_profile(tmp_path / "missing.yaml")
