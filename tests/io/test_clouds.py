"""Point clouds: each format round-trips, sizes are checked before reading, and no file, however
broken, makes a reader fail other than with a :class:`~symfruit.errors.SymfruitError`."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from symfruit import FileFormatError, SymfruitError
from symfruit.io import read_cloud, write_ply

from ..conftest import POINTS, lzf_compress, write_pcd


@pytest.mark.parametrize("text", [False, True])
def test_ply_round_trip(tmp_path, text):
    from plyfile import PlyData, PlyElement

    path = tmp_path / "c.ply"
    if text:
        v = np.array([tuple(p) for p in POINTS], dtype=[("x", "f8"), ("y", "f8"), ("z", "f8")])
        PlyData([PlyElement.describe(v, "vertex")], text=True).write(str(path))
    else:
        write_ply(path, POINTS, labels=np.arange(len(POINTS)) % 2)
    assert np.allclose(read_cloud(path), POINTS, atol=1e-7)


@pytest.mark.parametrize("mode", ["ascii", "binary", "binary_compressed"])
@pytest.mark.parametrize("extra", [False, True])
def test_pcd_round_trip(tmp_path, mode, extra):
    path = tmp_path / "c.pcd"
    write_pcd(path, POINTS, mode, extra)
    assert np.allclose(read_cloud(path), POINTS, atol=1e-7)


def test_lzf_back_references_are_exercised():
    data = bytes(range(10)) * 50
    packed = lzf_compress(data)
    assert len(packed) < len(data) / 5
    from pathlib import Path

    from symfruit.io.clouds import _lzf_decompress

    assert _lzf_decompress(packed, len(data), Path("x")) == data


@pytest.mark.parametrize(
    "name, text",
    [
        ("c.xyz", "\n".join(" ".join(f"{v:.17g}" for v in p) for p in POINTS)),
        ("c.txt", "# comment\n" + "\n".join("\t".join(f"{v:.17g}" for v in p) + "\t1.0" for p in POINTS)),
        ("c.csv", "x,y,z,r\n" + "\n".join(",".join(f"{v:.17g}" for v in p) + ",7" for p in POINTS)),
    ],
)
def test_text_round_trip(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    assert np.allclose(read_cloud(path), POINTS)


def test_npy_round_trip(tmp_path):
    np.save(tmp_path / "a.npy", POINTS)
    assert np.allclose(read_cloud(tmp_path / "a.npy"), POINTS)
    structured = np.zeros(len(POINTS), dtype=[("x", "f4"), ("y", "f4"), ("z", "f4"), ("rgb", "u4")])
    for i, c in enumerate("xyz"):
        structured[c] = POINTS[:, i]
    np.save(tmp_path / "s.npy", structured)
    assert np.allclose(read_cloud(tmp_path / "s.npy"), POINTS, atol=1e-7)


def test_npy_never_unpickles(tmp_path):
    np.save(tmp_path / "o.npy", np.array([{"a": 1}], dtype=object), allow_pickle=True)
    with pytest.raises(FileFormatError, match=r"o\.npy"):
        read_cloud(tmp_path / "o.npy")


def test_unknown_extension_and_missing_file(tmp_path):
    with pytest.raises(FileFormatError, match=r"unknown cloud extension '.obj'"):
        read_cloud(tmp_path / "a.obj")
    with pytest.raises(FileFormatError, match="no such file"):
        read_cloud(tmp_path / "a.ply")


def test_ply_header_promising_too_much_is_refused_before_reading(tmp_path):
    path = tmp_path / "huge.ply"
    path.write_bytes(
        b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n"
        b"property float x\nproperty float y\nproperty float z\nend_header\n" + b"\0" * 24
    )
    with pytest.raises(FileFormatError, match="promises 1000000000000 vertices"):
        read_cloud(path)


def test_truncated_binary_pcd(tmp_path):
    path = tmp_path / "t.pcd"
    write_pcd(path, POINTS, "binary")
    path.write_bytes(path.read_bytes()[:-10])
    with pytest.raises(FileFormatError, match="promises 40 points"):
        read_cloud(path)


def test_written_ply_is_atomic_and_labelled(tmp_path):
    from plyfile import PlyData

    path = tmp_path / "out" / "c.ply"
    write_ply(path, POINTS, labels=np.r_[np.zeros(20), np.ones(20)].astype(int))
    assert [p.name for p in path.parent.iterdir()] == ["c.ply"]
    assert PlyData.read(str(path))["vertex"]["label"].sum() == 20


# --- fuzz ----------------------------------------------------------------------------------------------


@settings()
@given(st.binary(max_size=2048), st.sampled_from([".ply", ".pcd", ".xyz", ".csv", ".npy"]))
def test_readers_survive_random_bytes(tmp_path, data, suffix):
    path = tmp_path / f"fuzz{suffix}"
    path.write_bytes(data)
    try:
        read_cloud(path)
    except SymfruitError:
        pass


@settings()
@given(st.sampled_from(["ply", "pcd", "npy"]), st.integers(1, 400), st.integers(0, 255), st.integers(0, 10_000))
def test_readers_survive_corrupted_valid_files(tmp_path, kind, cut, byte, where):
    path = tmp_path / f"c.{kind}"
    if kind == "ply":
        write_ply(path, POINTS)
    elif kind == "pcd":
        write_pcd(path, POINTS, "binary_compressed")
    else:
        np.save(path, POINTS)
    data = bytearray(path.read_bytes())
    data[where % len(data)] = byte
    path.write_bytes(bytes(data[: max(1, len(data) - cut)]))
    try:
        read_cloud(path)
    except SymfruitError:
        pass
