import json

import pytest

from symfruit import ConfigError, Settings, load_settings
from symfruit.methods.paper import PaperSettings
from symfruit.settings import from_dict


def test_defaults_are_the_papers():
    p = Settings().paper
    assert (p.translations, p.rotations_x, p.rotations_y) == (4, 11, 3)
    assert (p.translation_step, p.rotation_x_step, p.rotation_y_step) == (0.2, 5.0, 5.0)
    assert (p.j1, p.j2, p.j3, p.k1, p.k3) == (0.05, 0.6, 1.2, 10.0, 1.0)
    assert p.k2_value == pytest.approx(20.0) and p.k4_value == pytest.approx(1 / 0.6)
    assert p.k5_value == pytest.approx(1 / 1.2)
    assert p.n_hypotheses == 132


@pytest.mark.parametrize("suffix, dump", [(".json", json.dumps), (".yaml", None)])
def test_load_overrides_only_what_it_names(tmp_path, suffix, dump):
    path = tmp_path / f"s{suffix}"
    if dump:
        path.write_text(dump({"paper": {"rotations_x": 21, "k5": 1.0, "scoring": "literal"}}))
    else:
        path.write_text("paper:\n  rotations_x: 21\n  k5: 1.0\n  scoring: literal\n")
    s = load_settings(path)
    assert s.paper.rotations_x == 21 and s.paper.k5_value == 1.0 and s.paper.scoring == "literal"
    assert s.paper.translations == 4 and s.input == Settings().input


def test_round_trip():
    s = Settings().replace(paper={"translations": 7}, sphere={"refine": False})
    assert from_dict(s.to_dict()) == s


@pytest.mark.parametrize(
    "data, message",
    [
        ({"paper": {"rotations_x": "eleven"}}, r"paper.rotations_x: expected a whole number"),
        ({"paper": {"rotatons_x": 3}}, r"unknown setting paper.rotatons_x"),
        ({"papr": {}}, r"unknown setting papr"),
        ({"paper": {"scoring": "smooth"}}, r"paper.scoring: expected one of"),
        ({"paper": {"j2": 1.5}}, r"paper.j2: must be smaller than j3"),
        ({"paper": {"translations": 0}}, r"paper.translations: must be >= 1, got 0"),
        ({"paper": {"k2": -1}}, r"paper.k2: must be > 0"),
        ({"paper": {"j1": float("nan")}}, r"finite"),
        ({"sphere": {"refine": "yes"}}, r"true or false"),
        ({"input": {"min_points": 2}}, r"input.min_points: must be >= 4"),
        ({"fused": {"mirror": {"j2": 2.0}}}, r"fused.mirror.j2: must be smaller than j3"),
        ({"fused": {"mirror": {"rating_points": 1}}}, r"fused.mirror.rating_points: must be >= 10"),
        ({"segment": {"close_px": 100000}}, r"segment.close_px: must be <= 50"),
        ({"paper": {"fill_radius": 1e300}}, r"paper.fill_radius: must be <= 100"),
        ({"paper": {1: 2}}, r"setting names must be text"),
        ({1: {}}, r"section names must be text"),
        ({"paper": 3}, r"expected a mapping"),
        ([1, 2], r"mapping of sections"),
    ],
)
def test_invalid_settings_name_the_key(data, message):
    with pytest.raises(ConfigError, match=message):
        from_dict(data)


def test_bad_files_name_the_file(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("paper: [unclosed\n")
    with pytest.raises(ConfigError, match=r"bad\.yaml: not valid YAML"):
        load_settings(bad)
    wrong = tmp_path / "wrong.json"
    wrong.write_text('{"paper": {"rotations_x": true}}')
    with pytest.raises(ConfigError, match=r"wrong.json: paper.rotations_x"):
        load_settings(wrong)
    with pytest.raises(ConfigError, match="no such settings file"):
        load_settings(tmp_path / "missing.yaml")
    other = tmp_path / "s.toml"
    other.write_text("")
    with pytest.raises(ConfigError, match="must end in"):
        load_settings(other)


def test_yaml_is_loaded_safely(tmp_path):
    evil = tmp_path / "evil.yaml"
    evil.write_text("paper: !!python/object/apply:os.system ['echo hacked']\n")
    with pytest.raises(ConfigError, match="not valid YAML"):
        load_settings(evil)


def test_section_objects_are_validated():
    with pytest.raises(ConfigError):
        PaperSettings(j1=0)
