"""Triangle meshes: OBJ and PLY (a PLY without faces reads as a point cloud)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core.limits import MAX_FACES, MAX_OBJ_BYTES, shown  # most faces a mesh holds, largest OBJ file (bytes)
from ..errors import FileFormatError
from .clouds import MAX_CLOUD_POINTS, ply_elements, ply_vertices
from .text import as_path, holds_file, read_limited

__all__ = ["read_mesh"]


def read_mesh(path: str | Path) -> tuple[np.ndarray, np.ndarray | None]:
    """Read ``(vertices (v, 3) float, faces (f, 3) int or None)``; polygons are split into fans."""
    path = as_path(path, "read_mesh: the mesh file")
    suffix = path.suffix.lower()
    if suffix not in (".obj", ".ply"):
        raise FileFormatError(f"{path}: meshes must be .obj or .ply")
    try:
        return _read_obj(path) if suffix == ".obj" else _read_ply_mesh(path)
    except PermissionError as exc:  # one not this user's to read: pathlib's "[Errno 13] Permission denied: 'PATH'"
        raise FileFormatError(f"{path}: cannot read mesh ({exc.strerror})") from None


def _read_ply_mesh(path: Path) -> tuple[np.ndarray, np.ndarray | None]:
    if not holds_file(path):  # a folder or a looping link was 'no such file'; now named for what it is
        raise FileFormatError(f"{path}: no such file")
    _, elements = ply_elements(path)  # every element's count checked against the file size first
    counts = dict(elements)
    if "vertex" not in counts:
        raise FileFormatError(f"{path}: PLY has no vertex element")
    if counts.get("vertex", 0) > MAX_CLOUD_POINTS or counts.get("face", 0) > MAX_FACES:
        raise FileFormatError(f"{path}: mesh of {counts.get('vertex', 0):,} vertices and {counts.get('face', 0):,} "
                              f"faces; at most {MAX_CLOUD_POINTS:,} and {MAX_FACES:,} are read")  # fmt: skip
    data, vertices = ply_vertices(path)
    if not np.isfinite(vertices).all():
        raise FileFormatError(f"{path}: PLY mesh vertices must be finite numbers")
    if "face" not in data:
        return vertices, None
    face = data["face"]
    name = next((n for n in ("vertex_indices", "vertex_index") if n in face.data.dtype.names), None)
    if name is None:
        return vertices, None
    kind = next(p for p in face.properties if p.name == name).val_dtype
    if np.dtype(kind).kind not in "iu":  # float indices were cut to whole numbers in silence (1.7 -> vertex 1)
        raise FileFormatError(f"{path}: PLY face {name} are {np.dtype(kind).name}; vertex indices are whole numbers")
    return vertices, _fans(list(face.data[name]), len(vertices), path)


def _read_obj(path: Path) -> tuple[np.ndarray, np.ndarray | None]:
    vertices, polygons = [], []
    try:
        text = read_limited(path, what="OBJ mesh", max_bytes=MAX_OBJ_BYTES).decode("utf-8-sig")
    except UnicodeDecodeError as exc:  # the codec's words were "'utf-8' codec can't decode byte 0xe9 in position 2"
        raise FileFormatError(f"{path}: cannot read OBJ (not UTF-8 text: {exc.reason} at byte {exc.start})") from None
    triangles = 0  # the faces the polygons make as fans: bounded as a PLY's faces are, while they are read
    for number, line in enumerate(text.splitlines(), 1):
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v" and len(parts) < 4:
            raise FileFormatError(f"{path}: line {number}: OBJ vertices need x y z")
        try:
            if parts[0] == "v":
                vertices.append([float(p) for p in parts[1:4]])
            elif parts[0] == "f":
                polygons.append([int(p.split("/")[0]) for p in parts[1:]])
                triangles += max(len(parts) - 3, 0)
        except ValueError:
            raise FileFormatError(f"{path}: line {number} is not a valid OBJ vertex or face") from None
        if parts[0] == "f" and any(not 0 < abs(i) <= MAX_CLOUD_POINTS for i in polygons[-1]):
            raise FileFormatError(f"{path}: line {number}: OBJ face {shown(polygons[-1])} holds an index that is 0 or "
                                  f"beyond the {MAX_CLOUD_POINTS:,} vertices a mesh may hold")  # fmt: skip
        if len(vertices) > MAX_CLOUD_POINTS or triangles > MAX_FACES:
            raise FileFormatError(f"{path}: line {number}: OBJ mesh of more than {MAX_CLOUD_POINTS:,} vertices or "
                                  f"{MAX_FACES:,} faces (polygons counted as the triangles they make); no more "
                                  "are read")  # fmt: skip
    if not vertices:
        raise FileFormatError(f"{path}: OBJ has no vertices")
    v = np.asarray(vertices, dtype=np.float64)
    if not np.isfinite(v).all():
        raise FileFormatError(f"{path}: OBJ vertices must be finite numbers")
    # OBJ indices are 1-based; negative ones count back from the last vertex read.
    polygons = [[i - 1 if i > 0 else len(v) + i for i in poly] for poly in polygons]
    return v, (_fans(polygons, len(v), path) if polygons else None)


def _fans(polygons: list, n_vertices: int, path: Path) -> np.ndarray:
    lengths = np.fromiter(map(len, polygons), dtype=np.int64, count=len(polygons))
    if (made := int(np.maximum(lengths - 2, 0).sum())) > MAX_FACES:  # a PLY face of a million corners: 999,998
        raise FileFormatError(f"{path}: its polygons make {made:,} triangles; at most {MAX_FACES:,} faces are read")
    if len(polygons) and (lengths == 3).all():  # a triangle mesh: no fans to make
        arr = np.asarray(np.stack([np.asarray(p, dtype=np.int64) for p in polygons]), dtype=np.int64)
        if arr.min() < 0 or arr.max() >= n_vertices:
            raise FileFormatError(f"{path}: a face refers to a vertex that does not exist")
        return arr
    faces: list[list[int]] = []
    for poly in polygons:
        poly = [int(i) for i in poly]
        if len(poly) < 3:
            continue
        faces.extend([poly[0], poly[k], poly[k + 1]] for k in range(1, len(poly) - 1))
    arr = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if len(arr) and (arr.min() < 0 or arr.max() >= n_vertices):
        raise FileFormatError(f"{path}: a face refers to a vertex that does not exist")
    return arr
