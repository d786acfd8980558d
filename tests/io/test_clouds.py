"""Point clouds: each format round-trips, sizes are checked before reading, and no file, however
broken, makes a reader fail other than with a :class:`~symfruit.errors.SymfruitError`."""

import os
import struct

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from symfruit import FileFormatError, InputError, SymfruitError
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


# --- sizes claimed by headers, and files that are not what their name says (issue 13) ------------------


def _pcd_header(points: int, mode: str) -> bytes:
    return (
        f"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {points}\nHEIGHT 1\n"
        f"VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {points}\nDATA {mode}\n"
    ).encode()


def test_a_compressed_pcd_claiming_gigabytes_is_refused_before_allocating(tmp_path):
    import struct

    huge = tmp_path / "huge.pcd"  # 4 GB of points claimed
    huge.write_bytes(_pcd_header(333_333_334, "binary_compressed") + struct.pack("<II", 16, 4_000_000_008) + b"\0" * 16)
    with pytest.raises(FileFormatError, match=r"huge\.pcd: PCD holds 333,333,334 points; at most"):
        read_cloud(huge)
    ratio = tmp_path / "ratio.pcd"  # a legal count whose 1.2 MB could never come out of 16 bytes of LZF
    ratio.write_bytes(_pcd_header(100_000, "binary_compressed") + struct.pack("<II", 16, 1_200_000) + b"\0" * 16)
    with pytest.raises(FileFormatError, match=r"ratio\.pcd: binary_compressed sizes do not match"):
        read_cloud(ratio)


def test_a_ply_face_element_of_billions_of_rows_is_refused_before_plyfile_reads_it(tmp_path):
    path = tmp_path / "faces.ply"
    path.write_bytes(
        b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        b"property float z\nelement face 4000000000\nproperty list uchar int vertex_indices\nend_header\n"
        + np.zeros(9, "<f4").tobytes()
    )
    with pytest.raises(FileFormatError, match=r"faces\.ply: header promises 3 vertices, 4000000000 face rows"):
        read_cloud(path)


def test_a_huge_npy_header_and_an_npz_named_npy_are_refused(tmp_path):
    header = tmp_path / "huge.npy"
    with header.open("wb") as handle:
        np.lib.format.write_array_header_1_0(
            handle, {"descr": "<f8", "fortran_order": False, "shape": (100000, 100000)}
        )
        handle.write(b"\0" * 64)
    with pytest.raises(FileFormatError, match=r"huge\.npy: \.npy header promises \(100000, 100000\)"):
        read_cloud(header)
    npz = tmp_path / "points.npy"
    np.savez(tmp_path / "points.npz", points=POINTS)
    (tmp_path / "points.npz").rename(npz)
    with pytest.raises(FileFormatError, match=r"points\.npy: is an \.npz archive"):
        read_cloud(npz)


def test_a_pipe_named_as_an_npy_array_is_refused_without_waiting_for_a_writer(tmp_path):
    from symfruit.io.clouds import npy_header  # also how depth.npy and segment --depth .npy are read

    os.mkfifo(tmp_path / "depth.npy")
    with pytest.raises(FileFormatError, match=r"depth\.npy: is a pipe or a socket; the \.npy array must be a regular"):
        npy_header(tmp_path / "depth.npy")


def test_text_clouds_are_bounded_in_rows_and_bytes(tmp_path, monkeypatch):
    from symfruit.io import clouds

    path = tmp_path / "rows.xyz"
    path.write_text("\n".join("0.1 0.2 0.3" for _ in range(20)) + "\n")
    monkeypatch.setattr(clouds, "MAX_CLOUD_POINTS", 10)
    with pytest.raises(FileFormatError, match=r"rows\.xyz: more than 10 rows"):
        read_cloud(path)
    monkeypatch.setattr(clouds, "MAX_TEXT_BYTES", 100)
    with pytest.raises(FileFormatError, match=r"rows\.xyz: text cloud is larger than"):
        read_cloud(path)


@pytest.mark.parametrize(
    "text",
    [
        "x;y;z\n0,031;-0,002;0,305\n0,032;-0,001;0,306\n",  # European CSV: ';' columns, decimal commas
        "\ufeff0.031 -0.002 0.305\n0.032 -0.001 0.306\n",  # a UTF-8 byte-order mark before the first row
        "0.031,-0.002,0.305\n0.032,-0.001,0.306\n",
        "# comment\n0.031\t-0.002\t0.305\t7\n0.032 -0.001 0.306 8\n",
        # blank and comment lines among or after the rows: were refused with numpy's note on max_rows
        "0.031 -0.002 0.305\n0.032 -0.001 0.306\n\n",
        "0.031 -0.002 0.305\r\n\r\n0.032 -0.001 0.306\r\n",
        "0.031,-0.002,0.305\n# second scan\n   \n0.032,-0.001,0.306\n% end\n",
    ],
)
def test_text_clouds_keep_every_row_and_every_digit(tmp_path, text):
    path = tmp_path / "cloud.csv"
    path.write_text(text, encoding="utf-8")
    assert np.array_equal(read_cloud(path), [[0.031, -0.002, 0.305], [0.032, -0.001, 0.306]])


def test_a_device_or_a_folder_is_not_a_cloud(tmp_path):
    link = tmp_path / "zero.xyz"
    link.symlink_to("/dev/zero")
    with pytest.raises(FileFormatError, match=r"zero\.xyz: not a regular file"):
        read_cloud(link)
    (tmp_path / "dir.ply").mkdir()
    with pytest.raises(FileFormatError, match=r"dir\.ply: not a regular file"):
        read_cloud(tmp_path / "dir.ply")


def test_complex_npy_is_refused(tmp_path):
    np.save(tmp_path / "c.npy", POINTS.astype(np.complex128))
    with pytest.raises(FileFormatError, match="complex numbers cannot be coordinates"):
        read_cloud(tmp_path / "c.npy")


def _pcd(fields: str, data: bytes, *, points: int = 1, mode: str = "ascii", size: str = "4 4 4", kind: str = "F F F",
         count: str = "1 1 1") -> bytes:  # fmt: skip
    return (f"VERSION 0.7\nFIELDS {fields}\nSIZE {size}\nTYPE {kind}\nCOUNT {count}\nWIDTH {points}\nHEIGHT 1\n"
            f"POINTS {points}\nDATA {mode}\n").encode() + data  # fmt: skip


PLY_XYZ = b"property float x\nproperty float y\nproperty float z\n"
#: Files each reader refuses, and what its message says: every header field it checks, each in its own file.
# fmt: off
REFUSED = {
    "ply-no-format": ("a.ply", b"ply\nelement vertex 1\n" + PLY_XYZ + b"end_header\n" + bytes(12),
                      "PLY header lacks a format line"),
    "ply-element-line": ("a.ply", b"ply\nformat ascii 1.0\nelement vertex many\nend_header\n1 2 3\n",
                         "PLY element line is not 'element NAME COUNT'"),
    "ply-no-vertex": ("a.ply", b"ply\nformat ascii 1.0\nelement point 1\n" + PLY_XYZ + b"end_header\n1 2 3\n",
                      "PLY has no vertex element"),
    "ply-too-many": ("a.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 6000000\nproperty uchar x\n"
                     b"end_header\n" + bytes(6_000_000), "PLY holds 6,000,000 vertices; at most 5,000,000 are read"),
    "ply-no-z": ("a.ply", b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                 b"end_header\n1 2\n", "PLY vertices lack the z property (they have x, y)"),
    "ply-corrupt": ("a.ply", b"ply\nformat ascii 2.0\nelement vertex 1\n" + PLY_XYZ + b"end_header\n1 2 3\n",
                    "corrupt PLY (line 2: expected version '1.0')"),
    "ply-type": ("a.ply", b"ply\nformat ascii 1.0\nelement vertex 1\nproperty nonsense x\nend_header\n1 2 3\n",
                 "PLY property 'x' of element 'vertex' is of type 'nonsense', which is no PLY type"),  # robust55
    "ply-more-rows": ("a.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 1\n" + PLY_XYZ + b"end_header\n"
                      + np.ones((3, 3), "<f4").tobytes(), "24 bytes of data after the header's 1 vertices"),
    "ply-more-lines": ("a.ply", b"ply\nformat ascii 1.0\nelement vertex 1\n" + PLY_XYZ + b"end_header\n1 2 3\n4 5 6\n",
                       "2 data lines after the header but it declares 1 vertices"),
    "pcd-points-wh": ("a.pcd", _pcd("x y z", b"1 2 3\n4 5 6\n", points=2).replace(b"WIDTH 2", b"WIDTH 1"),
                      "PCD header's POINTS 2 disagrees with WIDTH x HEIGHT 1 x 1 = 1"),
    "pcd-ascii-more": ("a.pcd", _pcd("x y z", b"1 2 3\n4 5 6\n"), "header promises 1 points but more rows follow"),
    "pcd-binary-more": ("a.pcd", _pcd("x y z", np.ones((3, 3), "<f4").tobytes(), mode="binary"),
                        "header promises 1 points (12 bytes) but the file holds 36: 2 more whole points"),
    "pcd-no-fields": ("a.pcd", b"VERSION 0.7\nSIZE 4\nPOINTS 1\nDATA ascii\n1 2 3\n",
                      "PCD header lacks or garbles FIELDS/SIZE/TYPE/POINTS/DATA"),
    "pcd-type": ("a.pcd", _pcd("x y z", b"1 2 3\n", kind="F F X"), "PCD has an unsupported TYPE/SIZE pair"),
    "pcd-ascii-short": ("a.pcd", _pcd("x y z", b"1 2 3\n", points=40), "header promises 40 points but the file is "
                        "too short"),
    "pcd-ascii-rows": ("a.pcd", _pcd("x y z", b"1 2 3" + b" " * 80 + b"\n", points=3),
                       "header promises 3 points, the file holds 1"),
    "pcd-no-size-words": ("a.pcd", _pcd("x y z", b"\x01\x00", mode="binary_compressed"),
                          "truncated binary_compressed PCD (no size words)"),
    "pcd-lzf-literal": ("a.pcd", _pcd("x y z", struct.pack("<II", 4, 12) + b"\x1f\x00\x00\x00",
                                      mode="binary_compressed"), "corrupt LZF data in binary_compressed PCD"),
    "pcd-lzf-reference": ("a.pcd", _pcd("x y z", struct.pack("<II", 4, 12) + b"\x00\x01\x40\x05",
                                        mode="binary_compressed"), "corrupt LZF data in binary_compressed PCD"),
    "pcd-lzf-short": ("a.pcd", _pcd("x y z", struct.pack("<II", 4, 12) + b"\x02abc", mode="binary_compressed"),
                      "binary_compressed PCD decompressed to 3 bytes, expected 12"),
    "text-two-columns": ("a.xyz", b"# x y\n1 2\n", "line 2 has 2 columns, need x y z"),
    "text-ragged": ("a.xyz", b"1 2 3\n4 5\n", "rows after line 1 are not all x y z numbers"),
    "npy-bad-header": ("a.npy", b"\x93NUMPY\x01\x00\x10\x00{'descr': <f8'}   \n", "not a valid .npy file"),
    "npy-v2-shape": ("a.npy", None, "expected a numeric (n, 3) array, got float64 (4,)"),
    "npy-no-z": ("a.npy", np.zeros(2, dtype=[("x", "f4"), ("y", "f4")]), "structured array lacks field 'z'"),
    "npy-2-columns": ("a.npy", np.zeros((3, 2)), "expected a numeric (n, 3) array, got float64 (3, 2)"),
}
# fmt: on


@pytest.mark.parametrize("case", REFUSED)
def test_each_header_check_refuses_with_its_own_message(tmp_path, case):
    name, content, message = REFUSED[case]
    path = tmp_path / name
    if content is None:  # a version 2.0 header
        with path.open("wb") as handle:
            np.lib.format.write_array_header_2_0(handle, {"descr": "<f8", "fortran_order": False, "shape": (4,)})
            handle.write(bytes(32))
    elif isinstance(content, np.ndarray):
        np.save(path, content)
    else:
        path.write_bytes(content)
    with pytest.raises(FileFormatError) as info:
        read_cloud(path)
    assert str(info.value).startswith(f"{path}: ") and message in str(info.value)


def test_trailing_padding_and_blank_lines_after_the_declared_rows_are_not_more_rows(tmp_path):
    ply = tmp_path / "pad.ply"
    ply.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 1\n" + PLY_XYZ + b"end_header\n"
                    + np.ones(3, "<f4").tobytes() + b"\n\0\0")  # fmt: skip
    text = tmp_path / "blank.ply"
    text.write_bytes(b"ply\nformat ascii 1.0\nelement vertex 1\n" + PLY_XYZ + b"end_header\n1 2 3\n\n  \n")
    pcd = tmp_path / "pad.pcd"
    pcd.write_bytes(_pcd("x y z", np.ones(3, "<f4").tobytes() + b"\n", mode="binary"))
    for path in (ply, text, pcd):
        assert read_cloud(path).shape == (1, 3)


def test_a_signalling_nan_in_a_binary_cloud_is_a_missing_point_not_a_warning(tmp_path):
    import warnings

    points = POINTS.astype(np.float32)
    raw = points.view(np.uint32).copy()
    raw[3, 0] = 0x7F800001  # float32 signalling NaN: casting it to float64 raises numpy's "invalid value" flag
    write_pcd(tmp_path / "snan.pcd", raw.view(np.float32), "binary")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = read_cloud(tmp_path / "snan.pcd")
    assert np.isnan(out[3, 0]) and np.isfinite(np.delete(out, 3, axis=0)).all()


@pytest.mark.parametrize(("written", "said"), [("<f4", "binary_big_endian"), (">f8", "binary_little_endian")])
def test_a_ply_header_naming_the_other_byte_order_than_its_data_is_refused_saying_so(tmp_path, written, said):
    rng = np.random.default_rng(5)
    pts = rng.normal(size=(300, 3)) * 0.02 + [0.0, 0.0, 0.5]
    kind = "float" if written.endswith("4") else "double"
    head = f"ply\nformat {said} 1.0\nelement vertex 300\n" + "".join(f"property {kind} {c}\n" for c in "xyz")
    (tmp_path / "a.ply").write_bytes((head + "end_header\n").encode() + pts.astype(written).tobytes())
    other = "binary_little_endian" if said == "binary_big_endian" else "binary_big_endian"
    with pytest.raises(FileFormatError, match=rf"a\.ply: the header says {said} but the data look {other}: read as "
                       rf"declared, \d+% of the first 300 vertices' coordinates are implausible .* write 'format "
                       rf"{other} 1\.0' in the header"):  # fmt: skip
        read_cloud(tmp_path / "a.ply")
    right = head.replace(said, other) + "end_header\n"  # the same bytes under the right header read as written
    (tmp_path / "b.ply").write_bytes(right.encode() + pts.astype(written).tobytes())
    assert np.allclose(read_cloud(tmp_path / "b.ply"), pts, atol=1e-6)
    zeros = head + "end_header\n"  # nothing to tell the orders apart by: read as declared
    (tmp_path / "c.ply").write_bytes(zeros.encode() + np.zeros((300, 3), written).tobytes())
    assert not read_cloud(tmp_path / "c.ply").any()


def test_a_ragged_ascii_pcd_is_refused_in_its_own_words(tmp_path):
    head = "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n"
    (tmp_path / "a.pcd").write_text(head + "0 0\n1 0 0.5\n0 0 0.5\n")
    with pytest.raises(FileFormatError, match=r"a\.pcd: ascii PCD rows are not all 3 numbers \(the number of columns "
                       r"changed from 2 to 3 at row 2\)$"):  # fmt: skip
        read_cloud(tmp_path / "a.pcd")  # before: numpy's "; use `usecols` to select a subset and avoid this error"


@pytest.mark.parametrize("shape", ["WIDTH -2\nHEIGHT -1\nPOINTS 2\n", "WIDTH -2\nHEIGHT -1\n", "WIDTH 2\nHEIGHT 1\n"])
def test_a_pcd_of_negative_width_and_height_is_refused(tmp_path, shape):
    head = f"VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n{shape}DATA ascii\n"
    (tmp_path / "a.pcd").write_text(head + "0 0 0.5\n0.01 0 0.5\n")
    if "-" not in shape:  # no POINTS: the shape's product
        assert read_cloud(tmp_path / "a.pcd").shape == (2, 3)
        return
    with pytest.raises(FileFormatError, match=r"a\.pcd: PCD header garbles WIDTH/HEIGHT \(-2 x -1; counts are >= 0\)"):
        read_cloud(tmp_path / "a.pcd")  # before: -2 x -1 = 2 points read


def test_a_pcd_header_that_repeats_a_field_or_a_line_says_so_not_that_a_field_is_missing(tmp_path):
    rows = "0 0 0.5 1\n0.01 0 0.5 1\n"
    head = "VERSION .7\nFIELDS x x z _\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 2\nHEIGHT 1\nDATA ascii\n"
    (tmp_path / "a.pcd").write_text(head + rows)
    with pytest.raises(FileFormatError, match=r"a\.pcd: PCD header names field 'x' 2 times \(fields: x x z _\)"):
        read_cloud(tmp_path / "a.pcd")  # before: "PCD has no field 'y'"
    (tmp_path / "b.pcd").write_text(head.replace("FIELDS x x z _", "FIELDS x y z\nFIELDS x z y _") + rows)
    with pytest.raises(FileFormatError, match=r"b\.pcd: PCD header has two FIELDS lines$"):
        read_cloud(tmp_path / "b.pcd")  # before: the last one read, y and z swapped in silence
    padded = head.replace("x x z _", "x y z _ _").replace("F F F F", "F F F F F").replace("4 4 4 4", "4 4 4 4 4")
    (tmp_path / "c.pcd").write_text(padded.replace("1 1 1 1", "1 1 1 1 1") + rows.replace(" 1\n", " 1 1\n"))
    assert read_cloud(tmp_path / "c.pcd").shape == (2, 3)  # PCL's padding field '_' may repeat: it is not read


def test_a_npy_of_times_or_a_structured_npy_of_other_fields_than_numbers_is_refused(tmp_path):
    np.save(tmp_path / "times.npy", np.ones((20, 3)).astype("timedelta64[ms]"))  # numpy counts it an integer
    with pytest.raises(FileFormatError, match=r"expected a numeric \(n, 3\) array, got timedelta64\[ms\]"):
        read_cloud(tmp_path / "times.npy")  # before: read as counts of milliseconds, 'the cloud is 28 m across'
    fields = np.zeros(20, dtype=[("x", "f4"), ("y", "f4"), ("z", "?")])
    np.save(tmp_path / "flags.npy", fields)
    with pytest.raises(FileFormatError, match="structured array field 'z' is bool, not a number"):
        read_cloud(tmp_path / "flags.npy")  # before: True/False read as 1 m / 0 m
    fields = np.zeros(20, dtype=[("x", "f4"), ("y", "f4"), ("z", "i2")])
    fields["z"] = 3
    np.save(tmp_path / "ints.npy", fields)
    assert read_cloud(tmp_path / "ints.npy")[:, 2].tolist() == [3.0] * 20


@pytest.mark.parametrize(
    ("points", "labels", "message"),
    [
        (np.zeros((4, 3)), np.array([0, 1, 255, 256]), r"labels must be 0-255 to fit the PLY's uchar, got 0 to 256"),
        (np.zeros((4, 3)), np.array([-1, 0, 0, 0]), r"labels must be 0-255"),  # before: -1 written as 255
        (np.zeros((4, 3)), np.zeros(3, np.uint8), r"labels must be 4 whole numbers, one a point"),  # ValueError
        (np.zeros((4, 2)), None, r"points must have shape \(n, 3\), got \(4, 2\)"),  # before: IndexError
        (np.full((4, 3), 1e300), None, r"beyond a 32-bit float's range"),  # before: written as infinity
    ],
)
def test_write_ply_refuses_points_or_labels_it_would_write_as_something_else(tmp_path, points, labels, message):
    with pytest.raises(InputError, match=message):
        write_ply(tmp_path / "c.ply", points, labels=labels)
    assert not (tmp_path / "c.ply").exists()
    write_ply(tmp_path / "ok.ply", [[0.0, 0.0, 0.3]] * 4, labels=[0, 1, 1, 255])  # lists are read as arrays
    assert read_cloud(tmp_path / "ok.ply").tolist() == [[0.0, 0.0, 0.30000001192092896]] * 4


@pytest.mark.parametrize("target", ["loop.ply", "missing.ply"])
def test_a_link_that_leads_to_no_file_is_named_as_such_not_no_such_file(tmp_path, target):
    (tmp_path / "loop.ply").symlink_to(tmp_path / "loop.ply")  # a link to itself: the links loop
    link = tmp_path / "cloud.ply"
    link.symlink_to(tmp_path / target)
    with pytest.raises(FileFormatError, match=r"cloud\.ply: a link that leads to no file \(its target is missing"):
        read_cloud(link)  # before: 'no such file', though cloud.ply is there
    with pytest.raises(FileFormatError, match=r"nothing\.ply: no such file"):
        read_cloud(tmp_path / "nothing.ply")


def test_an_npy_header_cut_short_says_so_in_its_own_words(tmp_path):
    # stop 47 (robust47): numpy's words and type were quoted, "(ValueError: EOF: reading array header, expected
    # 49912 bytes got 498)"
    path = tmp_path / "cut.npy"
    path.write_bytes(b"\x93NUMPY\x01\x00" + b"\xf8\xc2" + b"x" * 498)
    with pytest.raises(FileFormatError) as info:
        read_cloud(path)
    assert str(info.value) == (f"{path}: not a valid .npy file (its array header claims 49,912 bytes but only 498 "
                               "follow: cut short or damaged)")  # fmt: skip


def test_a_text_cloud_of_bytes_that_are_no_text_is_said_in_our_words(tmp_path):
    """Stop 48 (robust48): a PNG named .xyz was "cannot read as XYZ ('utf-8' codec can't decode byte 0x89 in
    position 0: invalid start byte)", Python's codec's words."""
    path = tmp_path / "photo.xyz"
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)))
    with pytest.raises(FileFormatError) as info:
        read_cloud(path)
    assert str(info.value) == f"{path}: cannot read as XYZ (not UTF-8 text: invalid start byte at byte 0)"


def test_a_cloud_that_is_a_pipe_is_not_called_a_folder(tmp_path):
    """Stop 49 (robust49): a FIFO named cloud.ply was "not a regular file (a folder or a device)"."""
    fifo = tmp_path / "cloud.ply"
    os.mkfifo(fifo)
    with pytest.raises(FileFormatError) as info:
        read_cloud(fifo)  # refused before it is opened: a reader would wait for a writer
    assert str(info.value) == f"{fifo}: not a regular file (a pipe, socket or device)"
    folder = tmp_path / "folder.ply"
    folder.mkdir()
    with pytest.raises(FileFormatError, match=r"folder\.ply: not a regular file \(a folder\)"):
        read_cloud(folder)


def test_write_ply_of_no_path_is_refused_in_our_words(tmp_path):
    """Stop 50 (robust50): ``write_ply(None, points)`` was pathlib's ``TypeError: expected str, bytes or
    os.PathLike object, not NoneType``."""
    with pytest.raises(InputError, match=r"^write_ply: the PLY file must be a path \(str or os.PathLike\), got None$"):
        write_ply(None, POINTS)
    with pytest.raises(InputError, match=r"^write_ply: the PLY file is an empty path"):
        write_ply("", POINTS)


def test_a_cloud_this_user_may_not_read_is_refused_in_its_words_not_errnos(unreadable_place):
    """Stop 52 (robust52): "cannot read as PLY ([Errno 13] Permission denied: 'PATH')" read as a user who may not."""
    from ..conftest import refusal_unprivileged

    ply, npy = unreadable_place / "c.ply", unreadable_place / "c.npy"
    write_ply(ply, np.random.default_rng(0).normal(size=(50, 3)))
    np.save(npy, np.zeros((50, 3)))
    said = refusal_unprivileged("from symfruit.io.clouds import read_cloud; read_cloud(P0)", ply)
    assert said == f"refused: {ply}: cannot read as PLY (Permission denied)"
    npy_said = refusal_unprivileged("from symfruit.io.clouds import read_cloud; read_cloud(P0)", npy)
    assert npy_said == f"refused: {npy}: not a valid .npy file (cannot read it: Permission denied)"


@pytest.mark.parametrize("suffix", [".npy", ".ply", ".xyz"])
def test_a_cloud_grown_while_it_is_read_is_refused_naming_it(tmp_path, monkeypatch, suffix):
    """Robust53: a cloud file written on while it was read was taken as it was at that moment (part old, part
    new); now it is refused by name, saying how it changed (the change made by the reader itself: no race)."""
    import symfruit.io.clouds as clouds

    path = tmp_path / f"c{suffix}"
    if suffix == ".npy":
        np.save(path, POINTS)
    elif suffix == ".ply":
        write_ply(path, POINTS)
    else:
        np.savetxt(path, POINTS)
    size = path.stat().st_size
    real = clouds.CLOUD_READERS[suffix]

    def read_then_grow(p):
        points = real(p)
        with open(p, "ab") as f:
            f.write(b"\n")
        return points

    monkeypatch.setitem(clouds.CLOUD_READERS, suffix, read_then_grow)
    with pytest.raises(FileFormatError, match=rf"c\{suffix}: changed while it was read \(its size went from "
                       rf"{size:,} to {size + 1:,} bytes\); it is being written or replaced"):  # fmt: skip
        read_cloud(path)


def test_a_binary_ply_of_plyfiles_short_type_names_is_read_whole_not_called_cut_short(tmp_path):
    # plyfile reads 'u1', 'f4', ... as PLY's own type names; the size check counted them 4 bytes each, and a
    # whole file of float x, y, z and u1 colours (15 bytes a vertex) looked cut short (stop 55, robust55)
    rows = np.zeros(len(POINTS), dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("r", "u1"), ("g", "i1"),
                                        ("b", "u1")])  # fmt: skip
    rows["x"], rows["y"], rows["z"] = POINTS.T
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty f4 x\nproperty f4 y\n"
              "property f4 z\nproperty u1 red\nproperty i1 green\nproperty b1 blue\nend_header\n")  # fmt: skip
    path = tmp_path / "c.ply"
    path.write_bytes(header.format(len(POINTS)).encode() + rows.tobytes())
    assert np.allclose(read_cloud(path), POINTS, atol=1e-6)
    path.write_bytes(header.format(len(POINTS)).encode() + rows.tobytes()[:-1])  # one byte short: still refused
    with pytest.raises(FileFormatError, match="truncated or corrupt"):
        read_cloud(path)


@pytest.mark.parametrize("line", ["property int64 x", "property list uchar int64 q", "property listy q"])
def test_a_ply_property_of_a_type_ply_lacks_is_named_in_one_short_line(tmp_path, line):
    # plyfile's refusal listed its 25 type names: a line of 300 characters (stop 55, robust55)
    path = tmp_path / "c.ply"
    path.write_text(f"ply\nformat ascii 1.0\nelement vertex 1\n{line}\nproperty float y\nproperty float z\n"
                    "end_header\n1 2 3\n")  # fmt: skip
    with pytest.raises(FileFormatError, match=r"of element 'vertex' is of type '(int64|listy)', which is no PLY") as e:
        read_cloud(path)
    assert "'i1'" not in str(e.value) and len(str(e.value)) < 200 + len(str(path))


def test_a_ply_whose_coordinates_are_lists_is_refused_in_our_words(tmp_path):
    path = tmp_path / "c.ply"
    path.write_text("ply\nformat ascii 1.0\nelement vertex 2\nproperty list uchar float x\nproperty float y\n"
                    "property float z\nend_header\n1 1 2 3\n2 4 4 5 6\n")  # fmt: skip
    with pytest.raises(FileFormatError, match=r"c\.ply: PLY vertex property x is a list; x, y and z are one number"):
        read_cloud(path)
