"""Small structured files (settings, intrinsics, truth, COCO): bounded, parsed safely, errors naming the file."""

import json
import os
import re
from pathlib import Path

import numpy as np
import pytest

from symfruit import ConfigError, FileFormatError, InputError, load_settings
from symfruit.io.text import DIGEST_BYTES, as_path, changed, file_states, read_limited, read_structured

from ..conftest import after_its_status_time, set_back


def test_json_and_yaml_by_extension(tmp_path):
    (tmp_path / "a.json").write_text('{"a": [1, 2.5, "x"]}')
    (tmp_path / "a.yaml").write_text("a: [1, 2.5, x]\n")
    (tmp_path / "a.yml").write_text("a: [1, 2.5, x]\n")
    for name in ("a.json", "a.yaml", "a.yml"):
        assert read_structured(tmp_path / name, what="file", max_bytes=100) == {"a": [1, 2.5, "x"]}
    for name in ("empty.yaml", "empty.json", "blank.yml"):  # stop 41: before, None from YAML, "Expecting value"
        (tmp_path / name).write_text("" if name.startswith("empty") else "\n  \n")  # from JSON
        with pytest.raises(FileFormatError, match=rf"^{re.escape(str(tmp_path / name))}: the truth file is empty$"):
            read_structured(tmp_path / name, what="truth file", max_bytes=100)
    (tmp_path / "comment.yaml").write_text("# nothing\n")
    assert read_structured(tmp_path / "comment.yaml", what="file", max_bytes=100) is None


def test_a_file_over_the_bound_is_refused(tmp_path):
    path = tmp_path / "big.json"
    path.write_text(json.dumps({"a": "x" * 2000}))
    with pytest.raises(FileFormatError, match=r"big\.json: settings file is larger than 1 kB"):
        read_structured(path, what="settings file", max_bytes=1024)
    assert len(read_limited(path, what="file", max_bytes=4096)) == path.stat().st_size
    # robust53: "this cannot be a intrinsics file" (a camera.json of a million distortion coefficients)
    with pytest.raises(FileFormatError, match=r"big\.json: intrinsics file is larger than 1 kB; this cannot be an "
                       "intrinsics file$"):  # fmt: skip
        read_limited(path, what="intrinsics file", max_bytes=1024)


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
def test_a_symlink_to_an_endless_file_is_refused_after_the_bound(tmp_path):
    link = tmp_path / "settings.yaml"
    link.symlink_to("/dev/zero")
    # The read stops at the bound (1 MB for settings): it never tries to hold the endless file.
    with pytest.raises(ConfigError, match=r"settings\.yaml: settings file is larger than 1024 kB"):
        load_settings(link)
    with pytest.raises(FileFormatError, match="larger than 0 kB"):
        read_limited(link, what="file", max_bytes=10)


def test_a_pipe_is_refused_without_waiting_for_a_writer(tmp_path):
    pipe = tmp_path / "settings.yaml"
    os.mkfifo(pipe)  # opening it to read would block until something writes to it
    with pytest.raises(
        ConfigError, match=r"settings\.yaml: is a pipe or a socket; the settings file must be a regular file"
    ):
        load_settings(pipe)
    with pytest.raises(FileFormatError, match=r"settings\.yaml: is a pipe or a socket; the file must be"):
        read_structured(pipe, what="file", max_bytes=10)


def test_yaml_aliases_are_refused(tmp_path):
    bomb = tmp_path / "bomb.yaml"
    bomb.write_text('a: &a ["x", "x"]\nb: &b [*a, *a]\nc: &c [*b, *b]\n')
    with pytest.raises(FileFormatError, match=r"bomb\.yaml: not valid YAML: .*aliases \(\*a\) are not allowed"):
        read_structured(bomb, what="file", max_bytes=1 << 20)
    anchor_only = tmp_path / "anchor.yaml"
    anchor_only.write_text("a: &a 1\nb: 2\n")  # an anchor without an alias is harmless
    assert read_structured(anchor_only, what="file", max_bytes=100) == {"a": 1, "b": 2}


def test_yaml_is_loaded_safely(tmp_path):
    evil = tmp_path / "evil.yaml"
    evil.write_text("x: !!python/object/apply:os.system ['echo hacked']\n")
    with pytest.raises(FileFormatError, match="not valid YAML"):
        read_structured(evil, what="file", max_bytes=1000)


@pytest.mark.parametrize("suffix", [".json", ".yaml"])
def test_deep_nesting_is_refused_with_a_clear_error(tmp_path, suffix):
    path = tmp_path / f"deep{suffix}"
    path.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(FileFormatError, match=rf"deep\{suffix}: .*(nested too deeply|not valid)"):
        read_structured(path, what="truth file", max_bytes=1 << 20)


def test_deep_json_names_the_nesting(tmp_path):
    path = tmp_path / "deep.json"
    path.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(FileFormatError, match=r"deep\.json: truth file is nested too deeply to be a truth file"):
        read_structured(path, what="truth file", max_bytes=1 << 20)


def test_a_utf8_byte_order_mark_is_accepted(tmp_path):
    (tmp_path / "bom.json").write_bytes(b"\xef\xbb\xbf" + b'{"a": 1}')
    (tmp_path / "bom.yaml").write_bytes(b"\xef\xbb\xbf" + b"a: 1\n")
    assert read_structured(tmp_path / "bom.json", what="file", max_bytes=100) == {"a": 1}
    assert read_structured(tmp_path / "bom.yaml", what="file", max_bytes=100) == {"a": 1}


def test_other_problems_name_the_file(tmp_path):
    (tmp_path / "latin1.json").write_bytes(b'{"a": "\xfc"}')
    with pytest.raises(FileFormatError, match=r"latin1\.json: file is not UTF-8 text \(invalid start byte at byte 7\)"):
        read_structured(tmp_path / "latin1.json", what="file", max_bytes=100)
    (tmp_path / "bad.json").write_text('{"a": }')
    with pytest.raises(FileFormatError, match=r"bad\.json: not valid JSON: .*line 1 column 7"):
        read_structured(tmp_path / "bad.json", what="file", max_bytes=100)
    with pytest.raises(FileFormatError, match="no such camera file"):
        read_structured(tmp_path / "missing.json", what="camera file", max_bytes=100)
    (tmp_path / "folder.json").mkdir()
    with pytest.raises(FileFormatError, match="is a folder, not a camera file"):
        read_structured(tmp_path / "folder.json", what="camera file", max_bytes=100)
    with pytest.raises(ConfigError, match="no such thing"):
        read_structured(tmp_path / "missing.yaml", what="thing", max_bytes=100, error=ConfigError)


def test_as_path_takes_paths_and_refuses_anything_else_by_name(tmp_path):
    assert as_path("a/b.png", "x") == as_path(b"a/b.png", "x") == as_path(Path("a/b.png"), "x") == Path("a/b.png")
    for value, kind in ((None, "None"), (3, "int"), (["a"], "list"), (np.zeros(3), "ndarray")):
        with pytest.raises(InputError, match=rf"^the image must be a path \(str or os\.PathLike\), got {kind}$"):
            as_path(value, "the image")


@pytest.mark.parametrize(
    "reader", ["load_camera", "open_source", "read_cloud", "read_color", "read_depth_units", "read_frame",
               "read_labels", "read_mesh"],
)  # fmt: skip
def test_every_reader_refuses_what_is_not_a_path_by_name(reader):
    import symfruit.io

    with pytest.raises(InputError, match=rf"^{reader}: the .* must be a path \(str or os\.PathLike\), got None$"):
        getattr(symfruit.io, reader)(None)
    for empty in ("", b""):  # before: the working folder '.' (open_source opened it as a recording)
        with pytest.raises(InputError, match=rf"^{reader}: the .* is an empty path \(an unset variable\?\)$"):
            getattr(symfruit.io, reader)(empty)


def test_holds_file_says_what_an_entry_that_is_no_file_is(tmp_path):
    from symfruit.io.text import holds_file

    (tmp_path / "f.png").write_bytes(b"x")
    (tmp_path / "d.png").mkdir()
    (tmp_path / "loop.png").symlink_to("loop.png")
    (tmp_path / "gone.png").symlink_to("nowhere.png")
    os.mkfifo(tmp_path / "pipe.png")
    (tmp_path / "to-pipe.png").symlink_to("pipe.png")
    (tmp_path / "zero.png").symlink_to("/dev/zero")
    assert holds_file(tmp_path / "f.png") and not holds_file(tmp_path / "missing.png")
    pipe = re.escape(os.path.realpath(tmp_path / "pipe.png"))
    for name, why in [("d.png", "a directory, not a file"), ("loop.png", "a link that leads to no file"),
                      ("gone.png", "a link that leads to no file"), ("pipe.png", "not a regular file"),
                      # before: "its target is missing, or the links loop", of a target that is there
                      ("to-pipe.png", rf"a link to {pipe}, which is not a regular file"),
                      ("zero.png", "a link to /dev/zero, which is not a regular file")]:  # fmt: skip
        with pytest.raises(FileFormatError, match=rf"{name}: {why}"):
            holds_file(tmp_path / name)


def test_a_key_repeated_in_one_mapping_is_refused_naming_it(tmp_path):
    # the parsers keep the last in silence: 'translations: 3' above 'translations: 5' was dropped unsaid
    config = tmp_path / "run.yaml"
    config.write_text("paper:\n  translations: 3\n  j1: 1\n  translations: 5\n")
    with pytest.raises(ConfigError, match=r"run\.yaml: not valid YAML: duplicate key 'translations' .* line 4"):
        load_settings(config)
    (tmp_path / "cam.json").write_text('{"color": {"fx": 600}, "depth": {}, "color": {"fx": 615}}')
    with pytest.raises(FileFormatError, match=r"cam\.json: not valid JSON: duplicate key 'color'"):
        read_structured(tmp_path / "cam.json", what="intrinsics file", max_bytes=1000)
    # the same key in different mappings, and distinct keys, are fine
    (tmp_path / "ok.yaml").write_text("a: {x: 1}\nb: {x: 2}\n1: one\n'1': text\n")
    assert read_structured(tmp_path / "ok.yaml", what="file", max_bytes=1000) == {
        "a": {"x": 1}, "b": {"x": 2}, 1: "one", "1": "text"}  # fmt: skip
    (tmp_path / "ok.json").write_text('[{"x": 1}, {"x": 2}]')
    assert read_structured(tmp_path / "ok.json", what="file", max_bytes=1000) == [{"x": 1}, {"x": 2}]


@pytest.mark.parametrize(
    ("value", "form", "read"),
    [("010", "octal (a leading 0)", "8"), ("1:30", "base 60 (colons)", "90"), ("-1:30.5", "base 60", "-90.5")],
)
def test_yaml_octal_and_base_60_numbers_are_refused_not_read_as_another_number(tmp_path, value, form, read):
    path = tmp_path / "settings.yaml"
    path.write_text(f"input:\n  min_points: {value}\n")
    with pytest.raises(FileFormatError, match=re.escape(f"{value} is a YAML 1.1 {form}") + ".*" + f"read as {read}"):
        read_structured(path, what="settings file", max_bytes=1 << 20)  # before: 8, 90 or -90.5 in silence
    path.write_text("a: 10\nb: 0\nc: 0x10\nd: 1_000\ne: 0.5\nf: '010'\ng: -7\n")
    assert read_structured(path, what="settings file", max_bytes=1 << 20) == {
        "a": 10, "b": 0, "c": 16, "d": 1000, "e": 0.5, "f": "010", "g": -7
    }  # fmt: skip


def test_yaml_numbers_with_an_exponent_are_numbers_as_in_yaml_1_2(tmp_path):
    path = tmp_path / "settings.yaml"
    path.write_text("a: 1e6\nb: -2.5E-3\nc: .5e3\nd: 1.0e6\ne: 1.0e+6\nf: '1e6'\ng: 1e\nh: e6\ni: [1E2, +1e-2]\n")
    # before: 'a', 'b', 'c', 'd' and 'i' were text (YAML 1.1 wants a dot and a signed exponent)
    assert read_structured(path, what="settings file", max_bytes=1 << 20) == {
        "a": 1e6, "b": -2.5e-3, "c": 500.0, "d": 1e6, "e": 1e6, "f": "1e6", "g": "1e", "h": "e6", "i": [100.0, 0.01]
    }  # fmt: skip
    import yaml

    assert yaml.safe_load("1e6") == "1e6"  # PyYAML's own loader is left as it is


def test_a_yaml_error_is_one_short_line_with_its_position(tmp_path):
    # stop 47 (robust47): PyYAML's message quotes the line and a caret under it: a quote left open in a settings
    # file or a cut metadata.yaml gave 307-361 characters over several lines
    path = tmp_path / "run.yaml"
    path.write_text("evidence:\n  hidden_front: 'sph")
    with pytest.raises(ConfigError) as info:
        load_settings(path)
    assert str(info.value) == (f"{path}: not valid YAML: while scanning a quoted scalar: found unexpected end of "
                               "stream (at line 2, column 21)")  # fmt: skip
    path.write_text("a:\n  b: [1, 2\n")
    with pytest.raises(FileFormatError, match=r"run\.yaml: not valid YAML: while parsing a flow sequence: expected "
                       r"',' or '\]', but got '<stream end>' \(at line 3, column 1\)$"):  # fmt: skip
        read_structured(path, what="file", max_bytes=1000)


def test_a_folder_named_as_a_file_says_an_before_a_vowel(tmp_path):
    """Stop 48 (robust48): "is a folder, not a intrinsics file"."""
    from symfruit.io.text import read_limited

    with pytest.raises(FileFormatError) as info:
        read_limited(tmp_path, what="intrinsics file", max_bytes=10)
    assert str(info.value) == f"{tmp_path}: is a folder, not an intrinsics file"
    with pytest.raises(FileFormatError, match="is a folder, not a settings file"):
        read_limited(tmp_path, what="settings file", max_bytes=10)


def test_a_number_of_thousands_of_digits_and_deep_nesting_are_said_in_our_words(tmp_path):
    """Stop 49 (robust49): a camera.json or settings file holding a number of 5,001 digits quoted Python ("Exceeds
    the limit (4300 digits) for integer string conversion: ...; use sys.set_int_max_str_digits() to increase the
    limit"); an intrinsics file nested 100,000 deep was "nested too deeply to be a intrinsics file"."""
    for suffix, kind in ((".json", "JSON"), (".yaml", "YAML")):
        path = tmp_path / f"camera{suffix}"
        path.write_text('{"fx": 1' + "0" * 5000 + "}")
        with pytest.raises(FileFormatError) as info:
            read_structured(path, what="intrinsics file", max_bytes=1 << 20)
        assert str(info.value) == f"{path}: not valid {kind}: a number of 5,001 digits (at most 4,300 are read)"
        path.write_text("[" * 100_000 + "]" * 100_000)
        with pytest.raises(FileFormatError) as info:
            read_structured(path, what="intrinsics file", max_bytes=1 << 20)
        assert str(info.value) == f"{path}: intrinsics file is nested too deeply to be an intrinsics file"
    path = tmp_path / "bad.json"
    path.write_text('{"fx": 1,}')
    with pytest.raises(FileFormatError, match=r"not valid JSON: Expecting property name enclosed in double quotes"):
        read_structured(path, what="intrinsics file", max_bytes=1 << 20)  # other ValueErrors: the parser's reason


@pytest.mark.parametrize("size", [120, 300_000], ids=["small", "large"])
def test_a_same_size_rewrite_whose_times_are_set_back_is_seen(tmp_path, size):
    """Stop 53's look at a file (size and modification time) missed a rewrite that kept the size and whose
    modification time was set back (``cp -p``, ``touch -r``) or fell in the same time-stamp tick. Now a small file's
    content is compared too (its digest), and a larger one's status-change time, which no program sets back."""
    path = tmp_path / f"file_{size}"
    path.write_bytes(bytes(range(256)) * (size // 256) + b"x" * (size % 256))
    after_its_status_time(path)
    states = file_states([path])
    set_back(path, flip=True)
    said = "its content changed" if size <= DIGEST_BYTES else "its modification time was set back"
    assert os.stat(path).st_mtime_ns == states[path][3]  # the times a look at the status alone compared
    assert changed(states, "while it was read") == (
        f"{path}: changed while it was read (it was rewritten: {said}); it is being written or replaced: read it "
        "again once it is whole"
    )


def test_a_mode_changed_or_a_link_made_while_a_file_is_read_is_no_change(tmp_path):
    """The status-change time also moves when a file's mode, owner or links change (a chmod, a hard link made to it
    by a backup): that is no change to what was read."""
    path = tmp_path / "large.bin"
    path.write_bytes(b"\1" * (DIGEST_BYTES + 1))
    small = tmp_path / "small.json"
    small.write_text("{}")
    after_its_status_time(path)
    states = file_states([path, small])
    path.chmod(0o600)
    os.link(path, tmp_path / "linked.bin")
    small.chmod(0o600)
    assert changed(states, "while it was read") is None
