"""Atomic output: a file is either the old one or the whole new one, never half-written."""

import json
import os
import stat
import subprocess
import sys

import pytest

from symfruit import FileFormatError
from symfruit.io import atomic_write, write_json


def test_a_written_file_appears_whole_with_the_usual_permissions(tmp_path):
    target = tmp_path / "sub" / "out.bin"  # the folder is made
    with atomic_write(target, "wb") as handle:
        handle.write(b"hello")
        assert not target.exists()  # nothing under the final name until the block ends
        (temporary,) = target.parent.iterdir()
        assert temporary.name.startswith(".out.bin.") and temporary.name.endswith(".tmp")
    assert target.read_bytes() == b"hello" and [p.name for p in target.parent.iterdir()] == ["out.bin"]
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~mask


def test_a_failure_keeps_the_old_file_and_leaves_no_temporary(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError, match="boom"), atomic_write(target, "w") as handle:
        handle.write("new, half")
        raise RuntimeError("boom")
    assert target.read_text() == "old" and [p.name for p in tmp_path.iterdir()] == ["out.txt"]


def test_text_mode_writes_utf8(tmp_path):
    with atomic_write(tmp_path / "t.txt", "w") as handle:
        handle.write("fr\u00fcit \u2014 \u00e9")
    assert (tmp_path / "t.txt").read_bytes() == "fr\u00fcit \u2014 \u00e9".encode()


def test_a_folder_that_cannot_be_made_is_named(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    with pytest.raises(FileFormatError, match=r"out\.json: cannot write to folder .*file \(.*file is a file, not a f"):
        write_json(blocker / "out.json", {})  # before: "(Not a directory)" or "(File exists)"
    with pytest.raises(FileFormatError, match=r"sub/out\.json: cannot write to folder .*sub \(.*/file is a file, not"):
        write_json(blocker / "sub" / "out.json", {})


def test_json_is_indented_ends_with_a_newline_and_refuses_nan(tmp_path):
    path = tmp_path / "a.json"
    write_json(path, {"b": [1, 2], "a": "\u00fc"})
    text = path.read_text()
    assert text.endswith("}\n") and '\n  "b": [\n' in text and json.loads(text) == {"b": [1, 2], "a": "\u00fc"}
    write_json(path, {"x": 1})
    with pytest.raises(ValueError, match="Out of range float"):
        write_json(path, {"x": float("nan")})
    assert json.loads(path.read_text()) == {"x": 1} and [p.name for p in tmp_path.iterdir()] == ["a.json"]


def test_a_link_inside_an_output_folder_is_refused_never_followed(tmp_path):
    from symfruit import OutputError
    from symfruit.io.outputs import OutputFolder

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "frame").symlink_to(elsewhere, target_is_directory=True)
    with OutputFolder(tmp_path / "out"):
        with pytest.raises(OutputError, match=r"frame: is a symbolic link .*does not write through links"):
            write_json(tmp_path / "out" / "frame" / "detections.json", {})
        with pytest.raises(OutputError, match="is a symbolic link"):
            write_json(tmp_path / "out" / "frame" / "deeper" / "x.json", {})
        write_json(tmp_path / "out" / "real" / "x.json", {"ok": True})  # plain folders are made as needed
    assert list(elsewhere.iterdir()) == [] and (tmp_path / "out" / "real" / "x.json").is_file()
    # outside an output folder, a path the user names is theirs: its links are followed
    write_json(tmp_path / "out" / "frame" / "mine.json", {})
    assert (elsewhere / "mine.json").is_file()


def test_a_file_link_at_the_target_is_replaced_not_written_through(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("keep")
    (tmp_path / "out.json").symlink_to(victim)
    write_json(tmp_path / "out.json", {"new": 1})
    assert victim.read_text() == "keep" and not (tmp_path / "out.json").is_symlink()


def test_a_target_that_is_a_folder_is_one_clear_error(tmp_path):
    from symfruit import OutputError

    (tmp_path / "out.json").mkdir()
    with pytest.raises(OutputError, match=r"out\.json: is a folder"):
        write_json(tmp_path / "out.json", {})
    assert [p.name for p in tmp_path.iterdir()] == ["out.json"]  # no temporary left


def test_only_a_dead_runs_temporaries_are_stale(tmp_path):
    from symfruit.io.atomic import folder_fd, stale_temporaries

    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True,
                          timeout=300)  # fmt: skip
    names = [f".a.json.{os.getpid()}-0001.tmp", f".b.json.{int(dead.stdout)}-0002.tmp", ".c.json.xyz.tmp", "d.tmp"]
    for name in names:
        (tmp_path / name).write_text("")
    with folder_fd(tmp_path) as fd:
        assert sorted(stale_temporaries(fd)) == sorted(names[1:3])  # this live run's one is kept


def test_folder_fd_refuses_what_lies_outside_or_cannot_be_opened(tmp_path):
    from symfruit import OutputError
    from symfruit.io.atomic import folder_fd

    base = tmp_path / "out"
    base.mkdir()
    with pytest.raises(OutputError, match=r"elsewhere: outside the output folder .*out; not written"):
        with folder_fd(tmp_path / "elsewhere", root=base):
            pass
    with pytest.raises(OutputError, match=r"missing: cannot write to folder"):
        with folder_fd(tmp_path / "missing" / "x", root=tmp_path / "missing"):  # the root itself is not there
            pass
    (base / "f").write_text("a file")
    with pytest.raises(OutputError, match=r"out/f: is a file, not a folder; not overwritten"):
        with folder_fd(base / "f" / "sub", root=base):
            pass
    with pytest.raises(OutputError, match=r"cannot write to folder"):
        with folder_fd(base / ("x" * 300), root=base):  # a name longer than the file system allows
            pass
    with pytest.raises(OutputError, match=r"nothing: cannot write to folder"):
        with folder_fd(tmp_path / "nothing", create=False):  # no root: a plain folder that is not there
            pass
    assert not (tmp_path / "nothing").exists() and sorted(p.name for p in base.iterdir()) == ["f"]


def test_an_activated_folder_checks_every_write_under_it(tmp_path):
    from symfruit import OutputError
    from symfruit.io.atomic import activate, active_root

    class Folder:  # what activate needs of an output folder: its root and its check of a path
        def __init__(self):
            self.root, self.checked = tmp_path / "out", []

        def check(self, path):
            self.checked.append(path.name)
            if path.name == "input.png":
                raise OutputError(f"{path}: is an input of this run; not overwritten")
            return path

    folder = Folder()
    folder.root.mkdir()
    with activate(folder):
        assert active_root(folder.root / "a" / "b.json") is folder and active_root(tmp_path / "x") is None
        write_json(folder.root / "a" / "b.json", {"k": 1})
        with pytest.raises(OutputError, match="is an input of this run"):
            write_json(folder.root / "input.png", {})
        (folder.root / "link").symlink_to(tmp_path, target_is_directory=True)
        with pytest.raises(OutputError, match="is a symbolic link"):  # under the root: no link followed
            write_json(folder.root / "link" / "c.json", {})
    assert active_root(folder.root / "a" / "b.json") is None
    assert "b.json" in folder.checked and json.loads((folder.root / "a" / "b.json").read_text()) == {"k": 1}
    assert not (tmp_path / "c.json").exists() and not (folder.root / "input.png").exists()


def test_a_pid_no_process_can_have_is_not_alive():
    from symfruit.io.atomic import _alive

    assert _alive(os.getpid()) and _alive(1)  # this process, and the first one (init) that outlives every other
    assert not _alive(2**70)  # os.kill overflows: no such process


def test_a_path_without_a_file_name_is_refused(tmp_path):
    from symfruit import OutputError

    with pytest.raises(OutputError, match=r"\.\.: not a file name"):
        write_json(tmp_path / "a" / "..", {})


def test_a_temporary_named_with_other_digits_than_ascii_is_stale_not_a_traceback(tmp_path):
    """Stop 56 (robust56): a file '.a.json.\u00b2-1.tmp' in an output folder (its pid part '\u00b2', which
    str.isdigit() takes and int() refuses) made every later write there a ValueError traceback
    (``invalid literal for int() with base 10: '\u00b2'``); now it is no run's, stale like '.c.json.xyz.tmp'."""
    from symfruit.io.atomic import folder_fd, stale_temporaries

    names = [".a.json.\u00b2-0001.tmp", ".b.json.\u0663-0002.tmp"]
    for name in names:
        (tmp_path / name).write_text("")
    with folder_fd(tmp_path) as fd:
        assert sorted(stale_temporaries(fd)) == sorted(names)
