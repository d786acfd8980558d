"""The occlusion information of a frame's fruit, with its settings section ``occlusion``.

:func:`fruit_occlusion` is the one place it is made, from a depth image, the fruit's mask and points and the
other fruit's masks: :func:`symfruit.detect.detect` calls it for every fruit of a frame and the evaluation
for its rendered views with occluders, so the tables measure what a robot gets.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .core.camera import Camera
from .core.occlusion import Occlusion, occlusion
from .settings import Section, setting

__all__ = ["OcclusionSettings", "fruit_occlusion"]


@dataclass(frozen=True)
class OcclusionSettings(Section):
    """The occlusion information ``detect`` and the evaluation compute for every fruit from the frame's depth
    image, masks and border (:func:`symfruit.core.occlusion.occlusion`) and hand to the methods that use it.

    Attributes
    ----------
    enabled : bool
        Compute and pass it (off: every fruit is completed from its points alone).
    tolerance : float, metres
        What the camera saw beside the fruit hides it unless it lies at least this far behind the fruit's
        depth there.
    reach_px : int
        A pixel without depth takes the depth of the nearest pixel with depth (not the fruit's) within this
        many pixels (sensor dropout beside edges).
    trim_own : bool
        Find the pixels a mask not trimmed by colour overshoots the fruit by, where an active-stereo camera spread
        the fruit's own depth beyond its points or a time-of-flight camera saw past the fruit nearly all round it
        (:func:`symfruit.core.occlusion.overshoot`): the completion reads the fruit's width and silhouette cone
        without them (stops 42 and 43, docs/sil42.md, docs/treeover43.md).
    supports : bool
        A surface that runs on from the fruit's outline at the fruit's own depth, without a step towards the camera
        (the board or branch it rests on), is read as hiding it beside the outline only as far as a round fruit could
        still continue behind it (:func:`symfruit.core.occlusion.support_reach`: what lies behind a surface is the
        fruit's part deeper than it; :func:`symfruit.core.occlusion.own_edge`; stop 56, docs/support56.md). Off: the
        whole band is, as a leaf in front is.
    """

    enabled: bool = setting(True)
    tolerance: float = setting(0.005, ge=-1.0, le=1.0)
    reach_px: int = setting(3, ge=0, le=50)
    trim_own: bool = setting(True)
    supports: bool = setting(True)


def fruit_occlusion(
    depth: np.ndarray,
    mask: np.ndarray,
    points: np.ndarray,
    camera: Camera,
    settings: OcclusionSettings,
    others: np.ndarray | None = None,
    *,
    checked: bool = False,
    eroded: int = 1,
    drawn: bool = True,
) -> Occlusion | None:
    """:func:`~symfruit.core.occlusion.occlusion` with the section's values, or None when it is disabled (the one
    place both ``detect`` and the evaluation's rendered views make it). ``checked``: ``depth`` is a
    :class:`~symfruit.core.frame.Frame`'s, its units checked already. ``eroded``: the mask's
    border the points were never taken from (:attr:`symfruit.extract.ExtractSettings.erode_px`); ``drawn``: the
    mask is as drawn (not trimmed by colour, :func:`symfruit.extract.trim_labels`, which takes off what a mask
    overshoots the fruit by where it can: the overshoot is looked for only in a mask as drawn)."""
    if not settings.enabled:
        return None
    return occlusion(depth, mask, points, camera, others=others, tolerance=settings.tolerance,
                     reach=settings.reach_px, checked=checked,
                     trim_own=settings.trim_own and drawn, eroded=eroded, supports=settings.supports)  # fmt: skip
