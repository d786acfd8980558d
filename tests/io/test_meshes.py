"""Triangle meshes: OBJ (polygons split into fans, negative indices, ``v/vt/vn`` faces) and PLY."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from plyfile import PlyData, PlyElement

from symfruit import FileFormatError, SymfruitError
from symfruit.io import read_mesh, write_ply

CUBE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)


def test_obj_quads_become_fans_and_indices_count_from_one(tmp_path):
    path = tmp_path / "cube.obj"
    lines = ["# a unit cube", "o cube", *(f"v {x} {y} {z}" for x, y, z in CUBE), "vt 0 0", ""]
    lines += ["f 1 2 3 4", "f 5/1 6/1 7/1 8/1", "f 1//1 2//1 6//1", "f -8 -7 -3"]  # negative: from the end
    path.write_text("\n".join(lines))
    vertices, faces = read_mesh(path)
    assert np.array_equal(vertices, CUBE)
    assert faces.tolist() == [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 1, 5]]


def test_obj_without_faces_and_broken_objs(tmp_path):
    (tmp_path / "pts.obj").write_text("v 0 0 0\nv 1 0 0\n")
    vertices, faces = read_mesh(tmp_path / "pts.obj")
    assert vertices.shape == (2, 3) and faces is None
    for name, text, message in [
        ("none.obj", "# nothing\n", "OBJ has no vertices"),
        ("bad.obj", "v 0 0 0\nv 0 x 0\n", "line 2 is not a valid OBJ vertex or face"),
        ("far.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "a face refers to a vertex that does not exist"),
        ("short.obj", "v 0 0\n", "line 1: OBJ vertices need x y z"),
        ("mixed.obj", "v 0 0 0\nv 1 0\n", "line 2: OBJ vertices need x y z"),  # was numpy's ragged-array error
        ("nan.obj", "v 0 0 0\nv nan 0 inf\n", "OBJ vertices must be finite numbers"),
    ]:
        (tmp_path / name).write_text(text)
        with pytest.raises(FileFormatError, match=rf"{name.replace('.', '[.]')}: {message}"):
            read_mesh(tmp_path / name)
    (tmp_path / "latin.obj").write_bytes(b"v 0 0 0 # \xfc\n")
    with pytest.raises(FileFormatError, match="cannot read OBJ"):
        read_mesh(tmp_path / "latin.obj")


def test_ply_with_and_without_faces(tmp_path):
    vertex = np.array([tuple(v) for v in CUBE], dtype=[("x", "f4"), ("y", "f4"), ("z", "f4")])
    face = np.empty(2, dtype=[("vertex_indices", object)])
    face["vertex_indices"] = [np.array([0, 1, 2, 3]), np.array([4, 5, 6])]
    PlyData([PlyElement.describe(vertex, "vertex"), PlyElement.describe(face, "face")]).write(str(tmp_path / "m.ply"))
    vertices, faces = read_mesh(tmp_path / "m.ply")
    assert np.allclose(vertices, CUBE) and faces.tolist() == [[0, 1, 2], [0, 2, 3], [4, 5, 6]]
    write_ply(tmp_path / "cloud.ply", CUBE)
    vertices, faces = read_mesh(tmp_path / "cloud.ply")
    assert np.allclose(vertices, CUBE) and faces is None
    import warnings

    raw = vertex.view(np.uint32).reshape(len(CUBE), 3).copy()
    raw[2, 1] = 0x7F800001  # a float32 signalling NaN: refused as not finite, without numpy's cast warning
    bad = raw.view(vertex.dtype).ravel()
    PlyData([PlyElement.describe(bad, "vertex"), PlyElement.describe(face, "face")]).write(str(tmp_path / "nan.ply"))
    with warnings.catch_warnings(), pytest.raises(FileFormatError, match=r"nan\.ply: PLY mesh vertices must be finite"):
        warnings.simplefilter("error")
        read_mesh(tmp_path / "nan.ply")


def test_other_extensions_are_refused(tmp_path):
    (tmp_path / "m.stl").write_text("solid")
    with pytest.raises(FileFormatError, match=r"m\.stl: meshes must be \.obj or \.ply"):
        read_mesh(tmp_path / "m.stl")


def test_a_mesh_claiming_more_faces_than_the_file_holds_is_refused(tmp_path):
    path = tmp_path / "m.ply"
    path.write_bytes(
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        b"element face 4000000000\nproperty list uchar int vertex_indices\nend_header\n0 0 1\n1 0 1\n0 1 1\n3 0 1 2\n"
    )
    with pytest.raises(FileFormatError, match=r"m\.ply: header promises 3 vertices, 4000000000 face rows"):
        read_mesh(path)


def test_a_mesh_within_the_file_but_over_the_face_bound_is_refused(tmp_path, monkeypatch):
    from symfruit.io import meshes

    path = tmp_path / "m.ply"
    path.write_bytes(
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        b"element face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 1\n1 0 1\n0 1 1\n3 0 1 2\n3 0 2 1\n"
    )
    assert read_mesh(path)[1].shape == (2, 3)
    monkeypatch.setattr(meshes, "MAX_FACES", 1)
    with pytest.raises(FileFormatError, match=r"m\.ply: mesh of 3 vertices and 2 faces; at most"):
        read_mesh(path)


@settings()
@given(st.binary(max_size=2048), st.sampled_from([".ply", ".obj"]))
def test_mesh_readers_survive_random_bytes(tmp_path, data, suffix):
    path = tmp_path / f"fuzz{suffix}"
    path.write_bytes(data)
    try:
        read_mesh(path)
    except SymfruitError:
        pass


@pytest.mark.parametrize(
    "body, message",
    [
        (b"element point 1\nproperty float x\nend_header\n1\n", "PLY has no vertex element"),
        (b"element vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n",
         r"PLY vertices lack the z property \(they have x, y\)"),
        (b"element vertex 1\nproperty float a\nend_header\n1\n",
         r"PLY vertices lack the x, y, z properties \(they have a\)"),
    ],
)  # fmt: skip
def test_a_ply_mesh_without_xyz_vertices_is_refused_naming_what_it_lacks(tmp_path, body, message):
    path = tmp_path / "m.ply"
    path.write_bytes(b"ply\nformat ascii 1.0\n" + body)
    with pytest.raises(FileFormatError, match=rf"m\.ply: {message}"):
        read_mesh(path)


@pytest.mark.parametrize(
    "body, line",
    [("v 0 0 0\n" * 11, 11),  # one vertex over the bound
     ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf " + "1 2 3 " * 3 + "\n", 4)],  # one polygon of 9 corners: 7 triangles
)  # fmt: skip
def test_an_obj_over_the_vertex_or_face_bound_is_refused_while_read(tmp_path, monkeypatch, body, line):
    from symfruit.io import meshes

    monkeypatch.setattr(meshes, "MAX_CLOUD_POINTS", 10)  # bounds as a PLY mesh's (before: an OBJ had none)
    monkeypatch.setattr(meshes, "MAX_FACES", 5)
    (tmp_path / "m.obj").write_text(body)
    with pytest.raises(FileFormatError, match=rf"m\.obj: line {line}: OBJ mesh of more than 10 vertices or 5 faces"):
        read_mesh(tmp_path / "m.obj")


def test_a_ply_polygon_of_many_corners_is_bounded_by_the_triangles_it_makes(tmp_path, monkeypatch):
    from symfruit.io import meshes

    path = tmp_path / "m.ply"
    path.write_bytes(
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        b"element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 1\n1 0 1\n0 1 1\n"
        b"9 0 1 2 0 1 2 0 1 2\n"
    )
    assert read_mesh(path)[1].shape == (7, 3)
    monkeypatch.setattr(meshes, "MAX_FACES", 5)  # one face within the bound, its fan of 7 triangles over it
    with pytest.raises(FileFormatError, match=r"m\.ply: its polygons make 7 triangles; at most 5 faces are read"):
        read_mesh(path)


@pytest.mark.parametrize("index", ["99999999999999999999", "-99999999999999999999", "0"])
def test_an_obj_face_index_zero_or_beyond_any_mesh_is_refused_naming_its_line(tmp_path, index):
    path = tmp_path / "m.obj"
    path.write_text(f"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 {index}\n")  # before: OverflowError from numpy
    with pytest.raises(FileFormatError, match=r"line 5: OBJ face \[1, 2, 3, .*\] holds an index that is 0 or beyond"):
        read_mesh(path)


def test_a_ply_face_of_float_indices_is_refused_not_cut_to_whole_numbers(tmp_path):
    path = tmp_path / "m.ply"
    xyz = "".join(f"property float {c}\n" for c in "xyz")
    head = f"ply\nformat ascii 1.0\nelement vertex 3\n{xyz}element face 1\n"
    body = "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1.7 2.9\n"
    path.write_text(head + "property list uchar float vertex_indices\n" + body)  # before: face [0, 1, 2]
    with pytest.raises(FileFormatError, match="PLY face vertex_indices are float32; vertex indices are whole"):
        read_mesh(path)
    path.write_text(head + "property list uchar uint vertex_indices\n" + body.replace("1.7 2.9", "1 2"))
    assert read_mesh(path)[1].tolist() == [[0, 1, 2]]


def test_a_ply_mesh_that_is_a_folder_or_a_looping_link_is_named_as_such(tmp_path):
    (tmp_path / "m.ply").mkdir()
    with pytest.raises(FileFormatError, match=r"m\.ply: a directory, not a file"):  # before: 'no such file'
        read_mesh(tmp_path / "m.ply")
    (tmp_path / "loop.ply").symlink_to(tmp_path / "loop.ply")
    with pytest.raises(FileFormatError, match=r"loop\.ply: a link that leads to no file"):  # before: 'no such file'
        read_mesh(tmp_path / "loop.ply")
    with pytest.raises(FileFormatError, match=r"none\.ply: no such file"):
        read_mesh(tmp_path / "none.ply")


def test_a_mesh_this_user_may_not_read_is_refused_by_name(unreadable_place):
    """Stop 52 (robust52): pathlib's PermissionError from the PLY and OBJ readers, read as a user who may not."""
    from ..conftest import refusal_unprivileged

    obj = unreadable_place / "m.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    ply = unreadable_place / "m.ply"
    ply.write_bytes(b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nend_header\n")
    for path in (obj, ply):
        said = refusal_unprivileged("from symfruit.io.meshes import read_mesh; read_mesh(P0)", path)
        assert said == f"refused: {path}: cannot read {'OBJ ' if path.suffix == '.obj' else ''}mesh (Permission denied)"


def test_an_obj_that_is_no_utf8_text_is_said_in_our_words_not_the_codecs(tmp_path):
    # the codec's words were "'utf-8' codec can't decode byte 0xfc in position 10: invalid start byte"
    (tmp_path / "latin.obj").write_bytes(b"v 0 0 0 # \xfc\n")
    with pytest.raises(FileFormatError, match=r"latin\.obj: cannot read OBJ \(not UTF-8 text: invalid start byte at "
                                              r"byte 10\)$") as e:  # fmt: skip
        read_mesh(tmp_path / "latin.obj")
    assert "codec" not in str(e.value)


def test_a_ply_mesh_face_of_a_type_ply_lacks_is_named_in_one_short_line(tmp_path):
    path = tmp_path / "m.ply"
    path.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 1\nproperty list uchar int64 vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
                    "3 0 1 2\n")  # fmt: skip
    with pytest.raises(FileFormatError, match="property 'vertex_indices' of element 'face' is of type 'int64', which "
                                              r"is no PLY type \(char, uchar"):  # fmt: skip
        read_mesh(path)
