"""Readers and writers: point clouds, meshes, images, intrinsics, masks, frames, recordings, JSON.

Everything here names the file in its errors and bounds every size it reads before allocating it.
"""

from __future__ import annotations

from .atomic import atomic_write, write_json
from .clouds import CLOUD_READERS, read_cloud, write_ply
from .frames import is_frame_folder, read_frame, write_frame
from .images import read_color, read_depth_units, read_labels
from .intrinsics import camera_from_dict, load_camera
from .meshes import read_mesh
from .outputs import OutputFolder
from .sources import FrameSource, open_source, register_source

__all__ = [
    "CLOUD_READERS",
    "FrameSource",
    "OutputFolder",
    "atomic_write",
    "camera_from_dict",
    "is_frame_folder",
    "load_camera",
    "open_source",
    "read_cloud",
    "read_color",
    "read_depth_units",
    "read_frame",
    "read_labels",
    "read_mesh",
    "register_source",
    "write_frame",
    "write_json",
    "write_ply",
]
