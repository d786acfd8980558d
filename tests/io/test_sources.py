"""Frame sources: recordings read one frame at a time, found through one registry."""

import shutil
from pathlib import Path

import pytest

from symfruit import FileFormatError
from symfruit.io.frames import write_frame
from symfruit.io.sources import (
    FolderSource,
    FrameFolderSource,
    FrameSource,
    open_source,
    register_source,
    source_kinds,
)

from ..conftest import EXAMPLE_FRAME, SMALL_CAM, disc_frame

CAM = SMALL_CAM


def make_frames(root: Path, *names: str) -> None:
    color, depth = disc_frame([(80, 60)])
    for name in names:
        write_frame(root / name, color, depth, CAM)


def test_iter_frames_reports_bad_frames_and_goes_on(tmp_path):
    color, depth = disc_frame([(80, 60)])
    for name in ("a", "b", "c"):
        write_frame(tmp_path / name, color, depth, CAM)
    (tmp_path / "b" / "depth.png").unlink()
    src = open_source(tmp_path)
    assert src.names() == ["a", "b", "c"]
    assert src.read(0).name == "a" and src.read(2).name == "c"
    with pytest.raises(FileFormatError, match="depth"):
        src.read(1)


def test_folder_order_is_by_name_hidden_folders_and_exclusions_skipped(tmp_path):
    make_frames(tmp_path, "b", "a", "c10", "c9", ".hidden", "out")
    (tmp_path / "notes.txt").write_text("not a frame")
    src = open_source(tmp_path, exclude=[tmp_path / "out"])
    assert isinstance(src, FolderSource) and isinstance(src, FrameSource)
    assert src.names() == ["a", "b", "c10", "c9"] and len(src) == 4  # name order, not natural order
    assert [src.read(i).name for i in range(len(src))] == ["a", "b", "c10", "c9"]
    assert open_source(tmp_path).names() == ["a", "b", "c10", "c9", "out"]
    # An exclusion given by another spelling of the same folder is still excluded.
    assert "out" not in open_source(tmp_path, exclude=[tmp_path / "a" / ".." / "out"]).names()


def test_a_link_back_to_the_recording_is_refused_as_such_and_the_frames_go_on(tmp_path):
    rec = tmp_path / "rec"
    make_frames(rec, "a", "c")
    (rec / "b").symlink_to(rec)  # before (stop 41): "rec/b: no color.png or color.jpg"
    (rec / "up").symlink_to(tmp_path)
    (rec / "loop1").symlink_to(rec / "loop2")  # links in a loop, and one to nothing, are no folders: left out
    (rec / "loop2").symlink_to(rec / "loop1")
    src = open_source(rec)
    assert src.names() == ["a", "b", "c", "up"]
    with pytest.raises(FileFormatError, match=rf"^{rec}/b: a link back to the recording folder, not a frame folder$"):
        src.read(1)
    with pytest.raises(FileFormatError, match=rf"rec/up: a link back to {tmp_path}, which holds the recording"):
        src.read(3)
    assert src.read(0).name == "a" and src.read(2).name == "c"


@pytest.mark.parametrize("left", ["errors.json", "detections.parquet", "frames.parquet", ".symfruit.lock",
                                  "summary.json"])  # fmt: skip
def test_an_earlier_runs_output_inside_the_recording_is_no_frame(tmp_path, left):
    make_frames(tmp_path, "a", "b")
    (tmp_path / "out" / "a").mkdir(parents=True)  # detect rec --output rec/out, then --output rec/out2
    (tmp_path / "out" / left).write_text("{}")
    assert open_source(tmp_path).names() == ["a", "b"]
    (tmp_path / "b" / left).write_text("{}")  # a frame folder holding such a file is still a frame
    (tmp_path / "odd").mkdir()  # and a folder with neither is still a frame that fails, by name
    assert open_source(tmp_path).names() == ["a", "b", "odd"]


def test_a_frame_folder_is_a_one_frame_recording(tmp_path):
    src = open_source(EXAMPLE_FRAME)
    assert isinstance(src, FrameFolderSource) and isinstance(src, FrameSource)
    assert len(src) == 1 and src.names() == ["example_frame"] and src.read(0).name == "example_frame"
    with pytest.raises(IndexError, match="frame index 1 out of range for 1 frames"):
        src.read(1)
    with src as same:
        assert same is src


def test_names_come_without_decoding_any_frame(tmp_path, monkeypatch):
    from symfruit.io import sources

    make_frames(tmp_path, "a", "b")
    decoded = []
    monkeypatch.setattr(sources, "read_frame", lambda folder: decoded.append(Path(folder).name))
    src = open_source(tmp_path)
    assert src.names() == ["a", "b"] and len(src) == 2 and decoded == []
    src.read(1)
    assert decoded == ["b"]
    with pytest.raises(IndexError, match="frame index -1 out of range for 2 frames"):
        src.read(-1)


def test_what_is_no_recording_is_refused(tmp_path):
    with pytest.raises(FileFormatError, match=r"nothing: no such frame folder, folder of frames or bag"):
        open_source(tmp_path / "nothing")
    (tmp_path / "empty").mkdir()
    with pytest.raises(FileFormatError, match=r"empty: neither a frame folder .*, a folder of them, nor a bag"):
        open_source(tmp_path / "empty")
    (tmp_path / "file.png").write_bytes(b"x")
    with pytest.raises(FileFormatError, match="neither a frame folder"):
        open_source(tmp_path / "file.png")
    (tmp_path / "only_hidden" / ".git").mkdir(parents=True)
    with pytest.raises(FileFormatError, match="neither a frame folder"):
        open_source(tmp_path / "only_hidden")


def test_a_bag_named_in_capitals_is_named_as_a_bag(tmp_path):
    from ..conftest import EXAMPLES

    shutil.copy(EXAMPLES / "realsense" / "fruit.bag", tmp_path / "ROW3.BAG")  # as a Windows tool may name it
    # before: "neither a frame folder (color.png, depth.png, camera.json), a folder of them, nor a bag"
    with pytest.raises(FileFormatError, match=r"ROW3\.BAG: a bag named '\.BAG': the bag reader \(rosbags\) opens only "
                       r"names ending in '\.bag'; rename it ROW3\.bag"):  # fmt: skip
        open_source(tmp_path / "ROW3.BAG")


def test_the_registry_of_kinds(tmp_path, isolated_registry):
    assert source_kinds() == ["bag", "frame", "folder"]
    with pytest.raises(ValueError, match="frame source 'frame' is already registered"):
        register_source("frame", lambda path: False, lambda path, exclude: None)

    class ListSource:
        """A made-up recording: a text file listing frame folders."""

        def __init__(self, path, exclude):
            self.path = path
            self.folders = [Path(line) for line in path.read_text().split()]

        def __len__(self):
            return len(self.folders)

        def names(self):
            return [f.name for f in self.folders]

        def read(self, index):
            from symfruit.io import read_frame

            return read_frame(self.folders[index])

        def close(self):
            pass

    register_source("list", lambda path: path.suffix == ".list", ListSource)
    assert source_kinds() == ["bag", "frame", "folder", "list"]
    shutil.copytree(EXAMPLE_FRAME, tmp_path / "x")
    (tmp_path / "rec.list").write_text(f"{tmp_path / 'x'}\n")
    src = open_source(tmp_path / "rec.list")
    assert isinstance(src, FrameSource) and src.names() == ["x"] and src.read(0).color.shape == (480, 640, 3)


def test_evaluate_results_written_into_the_frames_folder_are_no_frames_of_it(tmp_path):
    from symfruit.writers import new_results_folder

    make_frames(tmp_path, "a", "b")
    for tag in ("frames", "spheres"):  # evaluate --frames rec --output rec: rec/<stamp>-frames and rec/latest
        (new_results_folder(tmp_path, tag) / "summary.json").write_text("{}")
    # before: each results folder and the latest link counted as a frame, and failed ('no color.png')
    assert open_source(tmp_path).names() == ["a", "b"]


def test_a_folder_this_user_may_not_open_is_refused_and_a_batch_goes_on_past_one(unreadable_place):
    """Stop 52 (robust52): a recording, or one of its frame folders, of mode 000 read as a user who may not open
    it: pathlib's PermissionError from the probes (is it a bag? a run's output?) ended the whole batch."""
    import shutil

    from ..conftest import refusal_unprivileged, small_frame

    rec = unreadable_place / "rec"
    for k in range(3):
        shutil.copytree(small_frame(), rec / f"f_{k}")
    out = unreadable_place / "out"
    out.mkdir(mode=0o777)
    out.chmod(0o777)
    said = refusal_unprivileged(
        "from symfruit.batch import run_batch; r = run_batch(" + repr(str(rec)) + ", " + repr(str(out / "o")) + ", "
        "method='raw', progress=False); print(sorted(r.done), r.failed)",
        rec / "f_1",
    )
    assert said.splitlines()[-2:] == [
        "['f_0', 'f_2'] {'f_1': '" + str(rec / "f_1") + ": cannot read frame folder (Permission denied: this user may "
        "not list it or open what it holds)'}", "taken"]  # fmt: skip
    said = refusal_unprivileged("from symfruit.io.sources import open_source; open_source(P0)", rec)
    assert said == (f"refused: {rec}: cannot read folder (Permission denied: this user may not list it or open what "
                    "it holds)")  # fmt: skip
