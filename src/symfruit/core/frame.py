"""One RGB-D frame: the unit of work of the pipeline (segment -> extract -> complete -> boxes)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError
from .box import Box
from .camera import Camera
from .limits import depth_metres, instance_labels

__all__ = ["MAX_STAMP_NS", "Frame"]

#: Stamps are nanoseconds since the epoch in [0, MAX_STAMP_NS): 2**33 s, the year 2242 (the range a run's
#: fruit table reads back, :mod:`symfruit.season.table`).
MAX_STAMP_NS = 2**33 * 1_000_000_000


@dataclass(frozen=True)
class Frame:
    """One RGB-D frame, depth aligned to colour.

    Attributes
    ----------
    name : str
    color : (h, w, 3) uint8, RGB
    depth : (h, w) float32, metres; 0 where the sensor returned nothing
    camera : Camera
        Intrinsics of the colour image (``width x height`` must match the images).
    masks : (h, w) int, optional
        Instance labels from the frame's own ``masks.*`` (0 background).
    truth : list of (id, Box), optional
        True boxes of the ripe fruit.
    source : str
        Where it came from (folder, or bag and timestamp).
    stamp : int, optional
        Acquisition time of the colour image, nanoseconds since the epoch (bags and ROS messages carry
        one; detections are stamped with it).
    frame_id : str, optional
        The colour image's coordinate frame (a ROS header's ``frame_id``); detections are in it.
        None: ``camera_color_optical_frame``.
    extras : dict
    visible : dict of int to float
        For truth fruit whose ``truth.json`` records it: the share of the fruit's silhouette the camera sees.
    """

    name: str
    color: np.ndarray
    depth: np.ndarray
    camera: Camera
    masks: np.ndarray | None = None
    truth: list[tuple[int, Box]] | None = None
    source: str = ""
    stamp: int | None = None
    frame_id: str | None = None
    extras: dict[str, Any] = field(default_factory=dict)
    visible: dict[int, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):  # written into detections.json and the run's tables as text
            raise InputError(f"a frame's name must be text, got {type(self.name).__name__} {self.name!r:.40}")
        if not isinstance(self.camera, Camera):
            raise InputError(f"frame {self.name}: camera must be a symfruit Camera (symfruit.Camera or "
                             f"symfruit.io.camera_from_dict), got {type(self.camera).__name__}")  # fmt: skip
        object.__setattr__(self, "color", np.asarray(self.color))
        # float metres, within the image bounds: uint16 millimetres handed over as metres are refused here
        object.__setattr__(self, "depth", depth_metres(self.depth, f"frame {self.name}"))
        if self.masks is not None:
            object.__setattr__(self, "masks", instance_labels(self.masks, f"frame {self.name}: masks"))
        if self.color.ndim != 3 or self.color.shape[2] != 3 or self.color.dtype != np.uint8:
            raise InputError(f"frame {self.name}: colour must be (h, w, 3) uint8 RGB, got {self.color.dtype} "
                             f"{self.color.shape}")  # fmt: skip
        if self.depth.ndim != 2:
            raise InputError(f"frame {self.name}: depth must be a 2-D image, got shape {self.depth.shape}")
        h, w = self.depth.shape
        if self.color.shape[:2] != (h, w):
            raise InputError(
                f"frame {self.name}: colour is {self.color.shape[1]}x{self.color.shape[0]} but depth is {w}x{h}; "
                "depth must be aligned to the colour image"
            )
        if (self.camera.width, self.camera.height) != (w, h):
            raise InputError(
                f"frame {self.name}: intrinsics are for {self.camera.width}x{self.camera.height} "
                f"but the images are {w}x{h}"
            )
        if self.masks is not None and self.masks.shape != (h, w):
            raise InputError(f"frame {self.name}: masks are {self.masks.shape[1]}x{self.masks.shape[0]}, "
                             f"the image {w}x{h}")  # fmt: skip
        if self.stamp is not None:
            if isinstance(self.stamp, bool) or not isinstance(self.stamp, (int, np.integer)):
                raise InputError(f"frame {self.name}: stamp must be whole nanoseconds since the epoch, got "
                                 f"{type(self.stamp).__name__}")  # fmt: skip
            if not 0 <= self.stamp < MAX_STAMP_NS:
                raise InputError(f"frame {self.name}: stamp {self.stamp} ns is not a time (0 to 2**33 s after 1970)")
            object.__setattr__(self, "stamp", int(self.stamp))
        # the rest is written into detections.json and ROS headers, or scored: before, frame_id 5, truth
        # [(1, "box")] or visible {1: 5.0} were taken and failed (or were written) far from here
        if self.frame_id is not None and not isinstance(self.frame_id, str):
            raise InputError(f"frame {self.name}: frame_id must be text (a coordinate frame's name), got "
                             f"{type(self.frame_id).__name__}")  # fmt: skip
        if self.truth is not None and (
            not isinstance(self.truth, list | tuple) or not all(_truth_pair(t) for t in self.truth)
        ):
            raise InputError(f"frame {self.name}: truth must be a list of (id, Box) pairs, ids whole numbers, got "
                             f"{self.truth!r:.60}")  # fmt: skip
        if not isinstance(self.visible, dict) or not all(_share(k, v) for k, v in self.visible.items()):
            raise InputError(f"frame {self.name}: visible must map fruit ids to shares in [0, 1], got "
                             f"{self.visible!r:.60}")  # fmt: skip
        if not isinstance(self.extras, dict):
            raise InputError(f"frame {self.name}: extras must be a dict, got {type(self.extras).__name__}")


def _whole(value: Any) -> bool:
    return isinstance(value, int | np.integer) and not isinstance(value, bool)


def _truth_pair(item: Any) -> bool:
    """Whether ``item`` is one ``(id, Box)`` of a frame's truth."""
    return isinstance(item, tuple | list) and len(item) == 2 and _whole(item[0]) and isinstance(item[1], Box)


def _share(key: Any, value: Any) -> bool:
    """Whether ``key: value`` is a fruit id and a share of its silhouette seen, in [0, 1]."""
    number = isinstance(value, int | float | np.integer | np.floating) and not isinstance(value, bool)
    return _whole(key) and number and 0.0 <= value <= 1.0
