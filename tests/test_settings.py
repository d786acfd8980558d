"""Settings: sections owned by their stages, validated with dotted key paths, resolved in one order
(defaults -> fruit profile -> settings file -> overrides), immutable, comparable, hashable and picklable."""

import json
import pickle
import re
from dataclasses import dataclass, fields

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from symfruit import ConfigError, Settings, load_settings, resolve_settings
from symfruit.methods.evidence import EvidenceSettings
from symfruit.methods.fused import FusedSettings
from symfruit.methods.paper import PaperSettings
from symfruit.settings import Section, SettingError, from_dict, merge, register_section, section_types, setting


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
        ({"paper": {"rotatons_x": 3}}, r"unknown setting paper.rotatons_x \(did you mean 'rotations_x'\?\); known"),
        ({"papr": {}}, r"unknown setting papr \(did you mean 'paper'\?\); known sections"),
        ({"paper": {"Translations": 3}}, r"paper.Translations \(did you mean 'translations'\?\)"),
        ({"paper": {"scoring": "smooth"}}, r"paper.scoring: expected one of"),
        ({"paper": {"j2": 1.5}}, r"paper.j2: must be smaller than j3"),
        ({"paper": {"translations": 0}}, r"paper.translations: must be >= 1, got 0"),
        ({"paper": {"k2": -1}}, r"paper.k2: must be > 0"),
        ({"paper": {"j1": float("nan")}}, r"finite"),
        (
            {"paper": {"j1": 10**400}},
            r"paper\.j1: expected a finite number, got 10{11}\.\.\. \(401 digits\)$",
        ),  # no OverflowError
        ({"sphere": {"refine": "yes"}}, r"true or false"),
        ({"input": {"min_points": 2}}, r"input.min_points: must be >= 4"),
        ({"fused": {"mirror": {"j2": 2.0}}}, r"fused.mirror.j2: must be smaller than j3"),
        ({"fused": {"mirror": {"rating_points": 1}}}, r"fused.mirror.rating_points: must be >= 10"),
        ({"segment": {"close_px": 100000}}, r"segment.close_px: must be <= 50"),
        ({"paper": {"fill_radius": 1e300}}, r"paper.fill_radius: must be <= 100"),
        ({"extract": {"erode_px": 1_000_000_000}}, r"extract.erode_px: must be <= 50"),
        ({"segment": {"crease_sigma": 1e300}}, r"segment.crease_sigma: must be <= 50"),
        ({"input": {"max_points": 10**12}}, r"input.max_points: must be <= 5e\+06"),
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


@pytest.mark.parametrize(
    ("name", "text", "message"),
    [
        ("empty.yaml", "", "the settings file is empty"),
        ("blank.yml", " \n\t\n", "the settings file is empty"),
        ("empty.json", "", "the settings file is empty"),  # before: "not valid JSON: Expecting value"
        ("comments.yaml", "# detect:\n#   method: paper\n", r"the settings file holds no settings \(only comments"),
        ("null.yaml", "null\n", "the settings file holds no settings"),
        ("null.json", "null", "the settings file holds no settings"),
    ],
)
def test_an_empty_settings_file_is_refused_as_empty(tmp_path, name, text, message):
    path = tmp_path / name  # before (stop 40): "expected a mapping of settings, got NoneType"
    path.write_text(text)
    with pytest.raises(ConfigError, match=rf"^{re.escape(str(path))}: {message}"):
        load_settings(path)
    with pytest.raises(ConfigError, match=message):
        resolve_settings(fruit=path)  # a profile file is read the same way


def test_yaml_is_loaded_safely(tmp_path):
    evil = tmp_path / "evil.yaml"
    evil.write_text("paper: !!python/object/apply:os.system ['echo hacked']\n")
    with pytest.raises(ConfigError, match="not valid YAML"):
        load_settings(evil)


def test_section_objects_are_validated():
    with pytest.raises(ConfigError):
        PaperSettings(j1=0)


# --- resolution order ------------------------------------------------------------------------------------


def test_each_layer_overrides_the_one_before_and_keeps_the_rest(tmp_path):
    profile = tmp_path / "pear.yaml"
    profile.write_text("paper:\n  translations: 5\n  rotations_x: 7\n  j1: 0.06\nfused:\n  depth_ratio: 1.3\n")
    config = tmp_path / "run.json"
    config.write_text(json.dumps({"paper": {"rotations_x": 9, "j1": 0.07}, "sphere": {"refine": False}}))
    overrides = {"paper": {"j1": 0.08}}
    defaults = Settings()
    assert resolve_settings() == defaults
    p = resolve_settings(fruit=profile)
    assert (p.paper.translations, p.paper.rotations_x, p.paper.j1, p.fused.depth_ratio) == (5, 7, 0.06, 1.3)
    assert p.paper.rotations_y == defaults.paper.rotations_y and p.sphere == defaults.sphere
    c = resolve_settings(fruit=profile, config=config)
    assert (c.paper.translations, c.paper.rotations_x, c.paper.j1, c.fused.depth_ratio) == (5, 9, 0.07, 1.3)
    assert c.sphere.refine is False
    o = resolve_settings(fruit=profile, config=config, overrides=overrides)
    assert (o.paper.translations, o.paper.rotations_x, o.paper.j1, o.fused.depth_ratio) == (5, 9, 0.08, 1.3)
    assert o.sphere.refine is False and o.input == defaults.input
    base = Settings().replace(paper={"rotations_y": 1, "rotations_x": 3})
    b = resolve_settings(base=base, config=config)
    assert (b.paper.rotations_y, b.paper.rotations_x) == (1, 9)  # the base is under everything


def test_a_shipped_profile_sits_under_the_settings_file(tmp_path):
    assert resolve_settings(fruit="strawberry").fused.revolution is True
    config = tmp_path / "s.yaml"
    config.write_text("fused:\n  revolution: false\n  mirror:\n    j2: 0.5\n")
    s = resolve_settings(fruit="strawberry", config=config)
    assert s.fused.revolution is False and s.fused.mirror.j2 == 0.5
    assert s.fused.mirror.translations == 8 and s.fused.mirror_weight == 1.0  # the profile's, kept


def test_errors_name_the_layer_and_the_dotted_key(tmp_path):
    profile = tmp_path / "bad_profile.yaml"
    profile.write_text("fused:\n  mirror:\n    rotations_x: many\n")
    with pytest.raises(ConfigError, match=r"bad_profile\.yaml: fused\.mirror\.rotations_x: expected a whole number"):
        resolve_settings(fruit=profile)
    config = tmp_path / "run.yaml"
    config.write_text("fused:\n  mirror:\n    nope: 1\n")
    with pytest.raises(ConfigError, match=r"run\.yaml: unknown setting fused\.mirror\.nope; known: "):  # none close
        resolve_settings(config=config)
    with pytest.raises(ConfigError, match=r"^fused\.mirror\.j3: must be <= 10, got 11"):
        resolve_settings(overrides={"fused": {"mirror": {"j3": 11}}})
    with pytest.raises(ConfigError, match=r"^fused\.mirror_weight: must be <= 1, got 2"):
        resolve_settings(fruit="strawberry", overrides={"fused": {"mirror_weight": 2}})
    not_mapping = tmp_path / "list.yaml"
    not_mapping.write_text("- 1\n- 2\n")
    with pytest.raises(ConfigError, match=r"list\.yaml: settings must be a mapping of sections, got list"):
        load_settings(not_mapping)


@pytest.mark.parametrize(
    "data, message",
    [
        ({"fused": {"mirror": {"j2": 2.0}}}, r"^fused\.mirror\.j2: must be smaller than j3"),
        ({"fused": {"mirror": {"k2": -1}}}, r"^fused\.mirror\.k2: must be > 0"),
        ({"fused": {"mirror": {"scoring": "smooth"}}}, r"^fused\.mirror\.scoring: expected one of 'continuous'"),
        ({"fused": {"mirror": {"translations": 1000, "rotations_x": 3600}}}, r"^fused\.mirror: .* hypotheses"),
        ({"fused": {"mirror": 3}}, r"^fused\.mirror: expected a mapping of settings, got int"),
        ({"fused": {"mirror": {"fill_radius": "auto"}}}, r"^fused\.mirror\.fill_radius: expected a number"),
    ],
)
def test_nested_sections_carry_the_dotted_path(data, message):
    with pytest.raises(ConfigError, match=message):
        from_dict(data)


def test_optional_values_take_none():
    s = from_dict({"paper": {"k2": None, "fill_radius": 2.5, "rating_points": None}})
    assert s.paper.k2 is None and s.paper.fill_radius == 2.5 and s.paper.rating_points is None
    assert from_dict({"paper": {"k2": 4}}).paper.k2 == 4.0 and isinstance(
        from_dict({"paper": {"k2": 4}}).paper.k2, float
    )


# --- sections a stage registers ------------------------------------------------------------------------


@dataclass(frozen=True)
class GripperSettings(Section):
    """A section a test stage registers."""

    width: float = setting(0.08, gt=0.0, le=0.2)
    fingers: int = setting(2, ge=2, le=5)
    mode: str = setting("soft")

    def check(self) -> None:
        if self.mode not in ("soft", "hard"):
            raise SettingError("mode", "must be soft or hard")


def test_a_registered_section_appears_everywhere_and_validates(isolated_registry, tmp_path):
    register_section("gripper", GripperSettings)
    assert list(section_types())[-1] == "gripper"
    s = Settings()
    assert s.gripper == GripperSettings() and s.section("gripper").fingers == 2
    assert s.to_dict()["gripper"] == {"width": 0.08, "fingers": 2, "mode": "soft"}
    assert from_dict(s.to_dict()) == s
    config = tmp_path / "g.yaml"
    config.write_text("gripper:\n  fingers: 3\n")
    assert load_settings(config).gripper.fingers == 3 and load_settings(config).paper == PaperSettings()
    for data, message in [
        ({"gripper": {"fingers": 1}}, r"gripper\.fingers: must be >= 2, got 1"),
        ({"gripper": {"width": "wide"}}, r"gripper\.width: expected a number, got 'wide'"),
        ({"gripper": {"mode": "firm"}}, r"gripper\.mode: must be soft or hard"),
        ({"gripper": {"colour": "red"}}, r"unknown setting gripper\.colour; known: fingers, mode, width"),
    ]:
        with pytest.raises(ConfigError, match=message):
            from_dict(data)
    with pytest.raises(ConfigError, match="mode: must be soft or hard"):
        GripperSettings(mode="firm")
    register_section("gripper", GripperSettings)  # the same class again: harmless
    with pytest.raises(ValueError, match="'gripper' is already registered by GripperSettings"):
        register_section("gripper", PaperSettings)
    with pytest.raises(TypeError, match="must be a dataclass type"):
        register_section("loose", dict)


def test_the_built_in_sections_belong_to_their_stages():
    from symfruit.extract import ExtractSettings
    from symfruit.methods.complete import InputSettings
    from symfruit.methods.fused import FusedSettings
    from symfruit.methods.sphere import SphereSettings
    from symfruit.occlusion import OcclusionSettings
    from symfruit.segment.colour import SegmentSettings

    types = section_types()
    assert types["input"] is InputSettings and types["extract"] is ExtractSettings
    assert types["segment"] is SegmentSettings and types["paper"] is PaperSettings
    assert types["fused"] is FusedSettings and types["sphere"] is SphereSettings
    assert types["occlusion"] is OcclusionSettings
    assert set(Settings().to_dict()) == set(types)


# --- the Settings object ---------------------------------------------------------------------------------


def test_settings_pickle_hash_and_compare():
    a = Settings().replace(paper={"rotations_x": 21}, fused={"mirror": {"j2": 0.5}})
    b = Settings().replace(paper={"rotations_x": 21}).replace(fused={"mirror": {"j2": 0.5}})
    assert a == b and hash(a) == hash(b) and a is not b
    assert pickle.loads(pickle.dumps(a)) == a and hash(pickle.loads(pickle.dumps(a))) == hash(a)
    c = a.replace(paper={"rotations_x": 23})
    assert c != a and len({a: 1, b: 2, c: 3}) == 2
    assert a != a.to_dict() and Settings() != "defaults"
    assert "paper=PaperSettings(" in repr(a) and "rotations_x=21" in repr(a)


def test_settings_are_immutable_and_name_unknown_sections():
    s = Settings()
    with pytest.raises(AttributeError, match="immutable; use replace"):
        s.paper = PaperSettings()
    with pytest.raises(AttributeError, match="Settings has no section 'papr'"):
        _ = s.papr
    with pytest.raises(
        ConfigError, match=r"unknown settings section 'papr' \(did you mean 'paper'\?\); known: .*paper"
    ):
        s.section("papr")
    with pytest.raises(ConfigError, match="unknown settings section 'papr'"):
        Settings(papr=PaperSettings())
    with pytest.raises(ConfigError, match="settings section 'paper' must be a PaperSettings, got dict"):
        Settings(paper={"translations": 2})
    assert Settings(paper=PaperSettings(translations=2)).paper.translations == 2


def test_replace_takes_mappings_or_section_objects():
    s = Settings().replace(paper=PaperSettings(translations=3), sphere={"refine": False})
    assert s.paper.translations == 3 and s.sphere.refine is False
    merged = s.replace(fused={"mirror": {"translations": 2}})  # a mapping names keys, at every depth
    assert merged.fused.mirror.translations == 2 and merged.fused.mirror.j2 == 0.4 and merged.paper.translations == 3
    whole = s.replace(fused=FusedSettings(mirror=PaperSettings(translations=2)))  # an object replaces the section
    assert whole.fused.mirror.translations == 2 and whole.fused.mirror.j2 == 0.6


def test_merge_replaces_only_what_it_names_at_every_depth():
    base = {"a": {"b": 1, "c": {"d": 2, "e": 3}}, "f": [1, 2]}
    assert merge(base, {"a": {"c": {"d": 5}}, "f": [3]}) == {"a": {"b": 1, "c": {"d": 5, "e": 3}}, "f": [3]}
    assert merge(base, {"a": 7}) == {"a": 7, "f": [1, 2]} and base["a"]["c"]["d"] == 2  # the base is untouched
    assert merge({"a": 1}, {"a": {"b": 2}}) == {"a": {"b": 2}}


# --- fuzz: every registered section takes only valid values, whatever a file holds ---------------------

_VALUES = st.one_of(
    st.none(), st.booleans(), st.integers(-(10**12), 10**12), st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12), st.lists(st.integers(), max_size=3),
    st.dictionaries(st.text(max_size=5), st.integers(), max_size=2),
)  # fmt: skip


@pytest.mark.parametrize("name", sorted(section_types()))
@settings()
@given(data=st.data())
def test_every_section_survives_random_values(name, data):
    import dataclasses

    fields = [f.name for f in dataclasses.fields(section_types()[name])]
    keys = st.one_of(st.sampled_from(fields), st.text(max_size=8), st.integers(-3, 3))
    layer = data.draw(st.dictionaries(keys, _VALUES, max_size=4))
    try:
        result = from_dict({name: layer})
    except ConfigError:
        return
    section = result.section(name)
    for key, value in layer.items():  # what was accepted is what is there (numbers as floats where floats)
        got = getattr(section, key)
        assert got == value or (isinstance(got, float) and got == float(value)) or dataclasses.is_dataclass(got)


@pytest.mark.parametrize(
    "text, message",
    [
        # YAML 1.1 reads an unquoted off as False: refused (never coerced back), saying why and how to write it
        ("evidence:\n  outline_profile: off\n", r"x\.yaml: evidence\.outline_profile: expected one of 'off', 'add', "
         r"'replace', got False \(YAML reads an unquoted yes, no, on, off, true or false as a boolean: quote text, "
         r"e\.g\. 'off'\)$"),
        ("paper:\n  rotations_x: on\n", r"paper\.rotations_x: expected a whole number, got True \(YAML reads an "
         r"unquoted yes, .* as a boolean: write a number\)$"),
        ("sphere:\n  refine: \"yes\"\n", r"sphere\.refine: expected true or false, got 'yes' \(text, as quoted: write "
         r"true or false without quotes\)$"),
        ("sphere:\n  refine: \"maybe\"\n", r"sphere\.refine: expected true or false, got 'maybe'$"),
    ],
)  # fmt: skip
def test_yaml_booleans_where_text_or_numbers_are_expected_are_refused_saying_why(tmp_path, text, message):
    (tmp_path / "x.yaml").write_text(text)
    with pytest.raises(ConfigError, match=message):
        load_settings(tmp_path / "x.yaml")
    assert load_settings_text(tmp_path, "sphere:\n  refine: yes\n").sphere.refine is True  # a boolean: YAML's own


def test_a_yaml_number_with_an_exponent_is_a_number_where_one_is_expected(tmp_path):
    s = load_settings_text(tmp_path, "paper:\n  k1: 1e3\ninput:\n  max_extent: 5e-1\n")
    assert s.paper.k1 == 1000.0 and s.input.max_extent == 0.5  # before: "expected a number, got '1e3'"
    with pytest.raises(ConfigError, match=r"paper\.k1: must be <= 1e\+06, got 10000000\.0"):
        load_settings_text(tmp_path, "paper:\n  k1: 1e7\n")  # read as a number, so its bounds apply
    with pytest.raises(ConfigError, match=r"input\.max_points: expected a whole number, got 20000\.0 \(a number "
                       r"with a point or an exponent is a fraction: write 20000\)$"):  # fmt: skip
        load_settings_text(tmp_path, "input:\n  max_points: 2e4\n")


def load_settings_text(tmp_path, text):
    (tmp_path / "y.yaml").write_text(text)
    return load_settings(tmp_path / "y.yaml")


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("min_points", np.int64(-5), "min_points: must be >= 4, got -5"),  # before: numpy's int skipped the bounds
        ("max_extent", np.float32("nan"), "max_extent: expected a finite number, got nan"),  # before: taken
        ("min_points", "5", "min_points: expected a whole number, got '5'"),  # before: TypeError from check()
        ("max_extent", "1", "max_extent: expected a number, got '1'"),
        ("min_points", 5.0, "min_points: expected a whole number, got 5.0"),
    ],
)
def test_a_section_made_in_python_is_checked_as_one_read_from_a_file(field, value, message):
    from symfruit.methods.complete import InputSettings

    with pytest.raises(ConfigError, match=re.escape(message)):
        InputSettings(**{field: value})


def test_numpy_numbers_are_read_as_the_python_ones_from_python_and_from_overrides():
    from symfruit.methods.complete import InputSettings

    made = InputSettings(min_points=np.int64(12), max_extent=np.float32(0.5))
    assert (made.min_points, made.max_extent) == (12, 0.5) and type(made.min_points) is int
    assert type(made.max_extent) is float and made == InputSettings(min_points=12, max_extent=0.5)
    # before: 'input.min_points: expected a whole number, got np.int64(12)'
    over = Settings().replace(input={"min_points": np.int64(12), "max_points": np.uint16(900)})
    assert (over.input.min_points, over.input.max_points) == (12, 900)
    with pytest.raises(ConfigError, match=r"expected a whole number, got np\.True_"):
        Settings().replace(input={"min_points": np.bool_(True)})


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: resolve_settings(fruit=5), "fruit must be a profile name or a path, got int"),  # before: TypeError
        (lambda: resolve_settings(config=["a.yaml"]), "config must be a profile name or a path, got list"),
        (lambda: resolve_settings(base="apple"), "base must be a Settings, got str"),  # before: AttributeError
        (lambda: load_settings(None), "load_settings needs a settings file path, got None"),  # before: the defaults
        (lambda: Settings().section(5), "a settings section is named by text, got int"),  # before: AttributeError
    ],
)
def test_resolve_settings_refuses_arguments_of_another_type_by_name(call, message):
    with pytest.raises(ConfigError, match=message):
        call()


@pytest.mark.parametrize("config", ["", "  ", b""])
def test_an_empty_config_path_is_refused_as_such(config):
    with pytest.raises(ConfigError, match=r"config is an empty path \(an unset variable\?\)"):
        resolve_settings(fruit="apple", config=config)  # before: '.: settings file must end in .yaml, .yml or .json'
    with pytest.raises(ConfigError, match="config is an empty path"):
        load_settings(config)


def test_an_unknown_setting_of_a_large_section_names_the_near_ones_in_one_short_line(tmp_path):
    # stop 47 (robust47): evidence.tilt_bends listed all 49 evidence settings, a line of 780 characters
    config = tmp_path / "run.yaml"
    config.write_text("evidence:\n  tilt_bends: true\n")
    with pytest.raises(ConfigError) as info:
        resolve_settings(config=config)
    message = str(info.value)
    more = len(fields(EvidenceSettings)) - 5  # the five named, the rest counted
    assert message.endswith(
        "run.yaml: unknown setting evidence.tilt_bends (did you mean 'tilt_bend'?); known: tilt_bend, tilt_blocks, "
        f"tilt_outline, prior_tilt, tilt_floor and {more} more (`symfruit settings` lists them with their values)"
    )
    assert len(message) - len(str(config)) < 220
    with pytest.raises(ConfigError, match=r"unknown setting evidence\.zzz; known: back_inflation, back_trim, "
                       rf"band_rays, clean_ratio, contour_cone, contour_cut_energy and {more - 1} more"):  # fmt: skip
        resolve_settings(overrides={"evidence": {"zzz": 1}})
    # a small section is still listed whole
    with pytest.raises(ConfigError, match=r"unknown setting input\.max_pts.*; known: max_extent, max_points, "):
        resolve_settings(overrides={"input": {"max_pts": 1}})


def test_a_section_with_nothing_under_it_says_so_not_nonetype(tmp_path):
    """Stop 48 (robust48): a settings file cut after ``evidence:`` was "evidence: expected a mapping of settings,
    got NoneType", Python's name of null."""
    path = tmp_path / "cut.yaml"
    path.write_text("evidence:\n")
    with pytest.raises(ConfigError) as info:
        load_settings(path)
    assert str(info.value) == (f"{path}: evidence: holds no settings (nothing under it); give its settings indented "
                               "below it, or remove the line")  # fmt: skip


def test_a_section_of_another_type_is_named_with_its_article():
    """Stop 50 (robust50): ``settings section 'evidence' must be a EvidenceSettings``."""
    with pytest.raises(ConfigError, match=r"section 'evidence' must be an EvidenceSettings, got int$"):
        Settings(evidence=5)
