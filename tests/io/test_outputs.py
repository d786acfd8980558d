"""symfruit.io.outputs: one rule for output names, inputs never written, one writer per output folder."""

import errno
import json
import os
import subprocess
import sys

import pytest
from hypothesis import given
from hypothesis import strategies as st

from symfruit import OutputError
from symfruit.io import outputs
from symfruit.io.atomic import write_json
from symfruit.io.outputs import LOCK_NAME, OutputFolder, entry_name, reserve_record, unique_names, write_record


@given(st.lists(st.text(min_size=1, max_size=30), min_size=1, max_size=30, unique=True))
def test_entry_names_never_collide_and_stay_one_file_name(names):
    out = [entry_name(n, reserved=["errors.json"]) for n in names]
    assert len(set(out)) == len(out)
    assert all("/" not in n and n not in ("", ".", "..") and not n.startswith(".") for n in out)


def test_names_the_run_keeps_for_itself_are_hashed():
    assert entry_name("scene_1") == "scene_1" and entry_name("errors.json", reserved=["errors.json"]) != "errors.json"
    assert entry_name("ERRORS.JSON", reserved=["errors.json"]).startswith("ERRORS.JSON+")
    assert entry_name(LOCK_NAME).startswith("symfruit.lock+") and entry_name("..").startswith("frame+")


def test_unique_names_of_images_that_share_a_stem_or_an_overlay_name():
    paths = ["in/a.png", "in/a-2.png", "in/a.jpg", "in/a_overlay.png", "other/b.png", "in/B.png", "in/c.png"]
    stems = [p.rsplit("/", 1)[1].rsplit(".", 1)[0] for p in paths]
    names = unique_names(stems, paths, derived=["_overlay"])
    assert names[1] == "a-2" and names[6] == "c"
    assert all("+" in names[i] for i in (0, 2, 3, 4, 5))  # a/a, a_overlay, b/B (case)
    outputs_ = [f"{n}.png" for n in names] + [f"{n}_overlay.png" for n in names]
    assert len(set(outputs_)) == len(outputs_)


def test_an_input_folder_cannot_be_the_output_and_inputs_are_never_written(tmp_path):
    photos = tmp_path / "photos"
    photos.mkdir()
    (photos / "a.png").write_bytes(b"photo")
    with pytest.raises(OutputError, match="also an input folder"):
        OutputFolder(photos, input_folders=[photos]).open()
    with OutputFolder(tmp_path / "out", inputs=[photos / "a.png"], input_folders=[photos]) as out:
        with pytest.raises(OutputError, match="is an input of this run"):
            write_json(photos / "a.png", {})  # the input outside the output folder: refused by the check
        with pytest.raises(OutputError, match="input folder"):
            out.check(photos / "b.png")
        write_json(out.root / "x.json", {"ok": 1})
    assert (photos / "a.png").read_bytes() == b"photo" and json.loads((tmp_path / "out" / "x.json").read_text())


def test_a_second_writer_is_refused_and_the_lock_is_released(tmp_path):
    first = OutputFolder(tmp_path / "out").open()
    assert (tmp_path / "out" / LOCK_NAME).read_text().strip() == str(os.getpid())
    with pytest.raises(OutputError, match=rf"another symfruit run \(pid {os.getpid()}\) is writing"):
        OutputFolder(tmp_path / "out").open()
    first.close()
    assert not (tmp_path / "out" / LOCK_NAME).exists()
    (tmp_path / "out" / LOCK_NAME).write_text("99999999\n")  # a stale lock file of a killed run: no lock held
    with OutputFolder(tmp_path / "out"):
        pass


HOLDER = """
import sys, time
from symfruit.io.outputs import OutputFolder
OutputFolder(sys.argv[1]).open()
print("locked", flush=True)
sys.stdin.readline()  # hold the lock until told (or killed)
"""


def test_a_killed_writer_never_leaves_the_folder_locked(tmp_path):
    child = subprocess.Popen([sys.executable, "-c", HOLDER, str(tmp_path / "out")], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, text=True)  # fmt: skip
    try:
        assert child.stdout is not None and child.stdout.readline().strip() == "locked"  # event, not a sleep
        with pytest.raises(OutputError, match=rf"\(pid {child.pid}\)"):
            OutputFolder(tmp_path / "out").open()
    finally:
        child.kill()
        child.wait(timeout=60)
    with OutputFolder(tmp_path / "out"):  # the kernel dropped the dead process's lock
        assert (tmp_path / "out" / LOCK_NAME).read_text().strip() == str(os.getpid())


def test_an_unwritable_output_folder_is_one_clear_error(tmp_path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(OutputError, match="cannot write to folder"):
        OutputFolder(tmp_path / "file").open()
    with pytest.raises(OutputError, match="cannot write to folder"):
        OutputFolder(tmp_path / "file" / "out").open()
    if os.geteuid() != 0:  # root writes anywhere
        ro = tmp_path / "ro"
        ro.mkdir(mode=0o555)
        with pytest.raises(OutputError, match="cannot write to folder"):
            OutputFolder(ro).open()


def test_an_output_folder_that_is_a_dangling_or_looping_link_is_named_as_one_not_as_a_file(tmp_path):
    (tmp_path / "gone").symlink_to(tmp_path / "nowhere")
    (tmp_path / "a").symlink_to("b")
    (tmp_path / "b").symlink_to("a")
    for name, target in (("gone", str(tmp_path / "nowhere")), ("a", "b")):
        with pytest.raises(OutputError) as info:
            OutputFolder(tmp_path / name).open()
        assert str(info.value) == (f"{tmp_path / name}: cannot write to folder (the output folder is a dangling or "
                                   f"looping link, to {target}; make that folder or choose another)")  # fmt: skip
    assert not (tmp_path / "nowhere").exists()


def test_an_output_folder_under_a_file_names_the_file(tmp_path):
    (tmp_path / "afile").write_text("x")
    with pytest.raises(OutputError) as info:
        OutputFolder(tmp_path / "afile" / "out" / "deeper").open()
    # before: "(Not a directory)"
    assert str(info.value) == (f"{tmp_path / 'afile' / 'out' / 'deeper'}: cannot write to folder "
                               f"({tmp_path / 'afile'} is a file, not a folder)")  # fmt: skip
    with pytest.raises(OutputError, match=r"afile: cannot write to folder \(the output folder is a file\)"):
        OutputFolder(tmp_path / "afile").open()


def test_the_final_record_is_written_over_its_reserved_space_on_a_full_disk(tmp_path, monkeypatch):
    path = tmp_path / "errors.json"
    reserve_record(path, {"failed": [], "unprocessed": ["f1", "f2"], "stopped": "running"}, entries=2)
    assert json.loads(path.read_text())["unprocessed"] == ["f1", "f2"]
    size = path.stat().st_size

    def full(*args, **kwargs):
        raise OutputError("no space", errno.ENOSPC)

    monkeypatch.setattr(outputs, "write_json", full)
    final = {"failed": [{"frame": "f1", "reason": "x" * 50_000}], "unprocessed": ["f2"], "stopped": "full"}
    assert "in place" in write_record(path, final)
    data = json.loads(path.read_text())
    assert path.stat().st_size == size and data["unprocessed"] == ["f2"] and data["failed"][0]["frame"] == "f1"
    assert data["failed"][0]["reason"].endswith("...")  # shortened to fit the space kept
    (tmp_path / "none.json").write_text("{}")
    with pytest.raises(OutputError, match="no space"):  # no space was kept: the error stands
        write_record(tmp_path / "none.json", final)
