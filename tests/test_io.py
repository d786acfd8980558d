"""Readers and writers: each cloud format round-trips, intrinsics load in each layout."""

import json

import numpy as np
import pytest

from symfruit import Camera, FileFormatError
from symfruit.io import load_camera, read_cloud, write_ply

POINTS = np.random.default_rng(0).normal(size=(40, 3)) * 0.01 + [0.0, 0.0, 0.3]


def lzf_compress(data: bytes) -> bytes:
    """A small greedy LZF compressor, to test the reader's back references."""
    out, i, lit = bytearray(), 0, bytearray()

    def flush():
        while lit:
            chunk = lit[:32]
            out.append(len(chunk) - 1)
            out.extend(chunk)
            del lit[:32]

    while i < len(data):
        best_len, best_off = 0, 0
        for off in range(1, min(i, 8192) + 1):
            n = 0
            while i + n < len(data) and n < 264 and data[i - off + n] == data[i + n]:
                n += 1
            if n > best_len:
                best_len, best_off = n, off
        if best_len >= 3:
            flush()
            length, ref = best_len - 2, best_off - 1
            if length < 7:
                out.append((length << 5) | (ref >> 8))
            else:
                out.append((7 << 5) | (ref >> 8))
                out.append(length - 7)
            out.append(ref & 0xFF)
            i += best_len
        else:
            lit.append(data[i])
            i += 1
    flush()
    return bytes(out)


def write_pcd(path, points, mode, extra_field=False):
    names = ["x", "y", "z"] + (["intensity"] if extra_field else [])
    cols = np.c_[points, np.arange(len(points))] if extra_field else points
    head = (
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n"
        f"FIELDS {' '.join(names)}\nSIZE {' '.join(['4'] * len(names))}\n"
        f"TYPE {' '.join(['F'] * len(names))}\nCOUNT {' '.join(['1'] * len(names))}\n"
        f"WIDTH {len(points)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {len(points)}\nDATA {mode}\n"
    )
    arr = cols.astype("<f4")
    if mode == "ascii":
        body = "\n".join(" ".join(f"{v:.9g}" for v in row) for row in arr).encode() + b"\n"
    elif mode == "binary":
        body = arr.tobytes()
    else:
        raw = arr.T.copy().tobytes()  # field after field
        packed = lzf_compress(raw)
        body = np.array([len(packed), len(raw)], "<u4").tobytes() + packed
    path.write_bytes(head.encode() + body)


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


LAYOUTS = {
    "plain.json": json.dumps({"fx": 615.0, "fy": 616.0, "cx": 321.0, "cy": 239.0, "width": 640, "height": 480}),
    "realsense.json": json.dumps(
        {
            "color": {
                "fx": 615.0,
                "fy": 616.0,
                "ppx": 321.0,
                "ppy": 239.0,
                "width": 640,
                "height": 480,
                "model": "Brown Conrady",
                "coeffs": [0, 0, 0, 0, 0],
            }
        }
    ),
    "open3d.json": json.dumps(
        {"width": 640, "height": 480, "intrinsic_matrix": [615.0, 0, 0, 0, 616.0, 0, 321.0, 239.0, 1.0]}
    ),
    "ros1.yaml": "header: {frame_id: camera_color_optical_frame}\nheight: 480\nwidth: 640\n"
    "distortion_model: plumb_bob\nD: [0, 0, 0, 0, 0]\n"
    "K: [615.0, 0.0, 321.0, 0.0, 616.0, 239.0, 0.0, 0.0, 1.0]\n",
    "ros2.yaml": "height: 480\nwidth: 640\nk: [615.0, 0.0, 321.0, 0.0, 616.0, 239.0, 0.0, 0.0, 1.0]\n",
    "calibration.yml": "image_width: 640\nimage_height: 480\ncamera_name: d435\ncamera_matrix:\n"
    "  rows: 3\n  cols: 3\n  data: [615.0, 0.0, 321.0, 0.0, 616.0, 239.0, 0.0, 0.0, 1.0]\n",
}


@pytest.mark.parametrize("name", LAYOUTS)
def test_intrinsics_layouts(tmp_path, name):
    path = tmp_path / name
    path.write_text(LAYOUTS[name])
    assert load_camera(path) == Camera(fx=615.0, fy=616.0, cx=321.0, cy=239.0, width=640, height=480)


@pytest.mark.parametrize(
    "text, message",
    [
        ('{"fx": 615, "fy": 615, "cx": 320, "width": 640, "height": 480}', "lack field 'cy' \\(or 'ppy'\\)"),
        ('{"fx": 0, "fy": 615, "cx": 320, "cy": 240, "width": 640, "height": 480}', "positive"),
        ('{"fx": 615, "fy": 615, "cx": 320, "cy": 240}', "width and height"),
        ('{"K": [1, 2, 3], "width": 640, "height": 480}', "9 numbers"),
        ('{"foo": 1}', "not recognised"),
        ("[1, 2]", "mapping"),
        ("{not json", "not valid JSON"),
    ],
)
def test_bad_intrinsics_name_the_file_and_field(tmp_path, text, message):
    path = tmp_path / "cam.json"
    path.write_text(text)
    with pytest.raises(FileFormatError, match=rf"cam.json: .*{message}"):
        load_camera(path)
