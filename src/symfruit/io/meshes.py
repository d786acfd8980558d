"""Triangle meshes: OBJ and PLY (a PLY without faces reads as a point cloud)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import FileFormatError
from .clouds import read_cloud

__all__ = ["read_mesh"]


def read_mesh(path: str | Path) -> tuple[np.ndarray, np.ndarray | None]:
    """Read ``(vertices (v, 3) float, faces (f, 3) int or None)``; polygons are split into fans."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".obj":
        return _read_obj(path)
    if suffix == ".ply":
        vertices = read_cloud(path)  # checks the header against the file size first
        from plyfile import PlyData

        data = PlyData.read(str(path))
        if "face" not in data:
            return vertices, None
        face = data["face"]
        name = next((n for n in ("vertex_indices", "vertex_index") if n in face.data.dtype.names), None)
        if name is None:
            return vertices, None
        return vertices, _fans(list(face.data[name]), len(vertices), path)
    raise FileFormatError(f"{path}: meshes must be .obj or .ply")


def _read_obj(path: Path) -> tuple[np.ndarray, np.ndarray | None]:
    vertices, polygons = [], []
    try:
        text = path.read_text(encoding="utf-8", errors="strict")
    except (OSError, UnicodeDecodeError) as exc:
        raise FileFormatError(f"{path}: cannot read OBJ ({exc})") from None
    for number, line in enumerate(text.splitlines(), 1):
        parts = line.split()
        if not parts:
            continue
        try:
            if parts[0] == "v":
                vertices.append([float(p) for p in parts[1:4]])
            elif parts[0] == "f":
                polygons.append([int(p.split("/")[0]) for p in parts[1:]])
        except ValueError:
            raise FileFormatError(f"{path}: line {number} is not a valid OBJ vertex or face") from None
    if not vertices:
        raise FileFormatError(f"{path}: OBJ has no vertices")
    v = np.asarray(vertices, dtype=np.float64)
    if v.shape[1] != 3:
        raise FileFormatError(f"{path}: OBJ vertices need x y z")
    # OBJ indices are 1-based; negative ones count back from the last vertex read.
    polygons = [[i - 1 if i > 0 else len(v) + i for i in poly] for poly in polygons]
    return v, (_fans(polygons, len(v), path) if polygons else None)


def _fans(polygons: list, n_vertices: int, path: Path) -> np.ndarray:
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
