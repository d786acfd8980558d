"""Readers and writers: point clouds, intrinsics, JSON. Everything here names the file in its errors."""

from __future__ import annotations

from .atomic import atomic_write, write_json
from .clouds import CLOUD_READERS, read_cloud, write_ply
from .intrinsics import camera_from_dict, load_camera
from .meshes import read_mesh

__all__ = [
    "CLOUD_READERS",
    "atomic_write",
    "camera_from_dict",
    "load_camera",
    "read_cloud",
    "read_mesh",
    "write_json",
    "write_ply",
]
