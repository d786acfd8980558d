"""Segmenters: an RGB-D frame's colour image to instance labels, one label per fruit.

:mod:`.colour` is the built-in one (ripe red fruit by colour, no weights); :mod:`.onnx` and
:mod:`.maskrcnn` run learned models (optional extras ``onnx`` and ``seg``); :mod:`.source` turns a mask spec
(``--masks``) into labels, for ``detect``, ``segment`` and the ROS nodes alike.
"""

from __future__ import annotations

from .colour import SegmentSettings, convex_hull_mask, learned_masks, redness, ripe_seeds, segment
from .source import MaskSource, mask_source

__all__ = [
    "MaskSource",
    "SegmentSettings",
    "convex_hull_mask",
    "learned_masks",
    "mask_source",
    "redness",
    "ripe_seeds",
    "segment",
]
