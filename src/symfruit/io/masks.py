"""Fruit masks from files: instance label PNGs and COCO-style JSON (polygons and RLE)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..errors import FileFormatError
from .images import read_labels
from .text import read_structured

#: Largest COCO annotation file read (bytes).
MAX_COCO_BYTES = 256 << 20

__all__ = ["coco_masks", "read_masks", "rle_decode"]


def read_masks(path: str | Path, shape: tuple[int, int]) -> np.ndarray:
    """Instance labels ``(h, w)`` int32 (0 background, k fruit k) from a label PNG or COCO JSON.

    ``path`` may be a frame folder (its ``masks.png`` or ``masks.json``) or the file itself.
    """
    path = Path(path)
    if path.is_dir():
        path = path / "masks.png" if (path / "masks.png").is_file() else path / "masks.json"
    if path.suffix.lower() == ".png":
        labels = read_labels(path)
    elif path.suffix.lower() == ".json":
        labels = coco_masks(path, shape)
    else:
        raise FileFormatError(f"{path}: masks must be a label .png or a COCO .json")
    if labels.shape != tuple(shape):
        raise FileFormatError(f"{path}: masks are {labels.shape[1]}x{labels.shape[0]}, the image {shape[1]}x{shape[0]}")
    return labels


def coco_masks(path: Path, shape: tuple[int, int]) -> np.ndarray:
    """Rasterise COCO annotations (polygons, uncompressed or compressed RLE) into instance labels.

    If the file holds several images, the annotations of the first image are used. Later annotations
    are drawn over earlier ones.
    """
    from PIL import Image, ImageDraw

    data = read_structured(path, what="COCO annotation file", max_bytes=MAX_COCO_BYTES)
    anns = data.get("annotations", data) if isinstance(data, dict) else data
    if not isinstance(anns, list):
        raise FileFormatError(f"{path}: expected a COCO 'annotations' list")
    images = data.get("images") if isinstance(data, dict) else None
    if images:
        first = images[0].get("id")
        anns = [a for a in anns if a.get("image_id", first) == first]
    h, w = shape
    labels = np.zeros((h, w), np.int32)
    for k, ann in enumerate(anns, 1):
        try:
            seg = ann["segmentation"]
            if isinstance(seg, dict):
                mask = rle_decode(seg)
            else:
                img = Image.new("L", (w, h), 0)
                draw = ImageDraw.Draw(img)
                for poly in seg:
                    xy = [(float(poly[i]), float(poly[i + 1])) for i in range(0, len(poly) - 1, 2)]
                    if len(xy) >= 3:
                        draw.polygon(xy, fill=1, outline=1)
                mask = np.asarray(img, dtype=bool)
        except (KeyError, TypeError, ValueError, IndexError) as exc:
            raise FileFormatError(f"{path}: annotation {k} has no valid segmentation ({exc})") from None
        if mask.shape != (h, w):
            raise FileFormatError(f"{path}: annotation {k} is {mask.shape[1]}x{mask.shape[0]}, the image {w}x{h}")
        labels[mask] = int(ann.get("id", k)) if isinstance(ann.get("id"), int) and ann.get("id") > 0 else k
    return labels


def rle_decode(rle: dict[str, Any]) -> np.ndarray:
    """Decode a COCO RLE (``{"size": [h, w], "counts": list or compressed string}``) to a bool mask.

    Uses ``pycocotools`` when installed; the pure-Python decoder below gives the same result.
    """
    h, w = (int(v) for v in rle["size"])
    counts = rle["counts"]
    if isinstance(counts, str):
        counts = _rle_string_counts(counts)
    counts = np.asarray(counts, dtype=np.int64)
    if counts.sum() != h * w or (counts < 0).any():
        raise ValueError(f"RLE counts add up to {counts.sum()}, expected {h * w}")
    values = np.zeros(len(counts), bool)
    values[1::2] = True
    flat = np.repeat(values, counts)
    return flat.reshape(w, h).T  # COCO RLE runs down columns


def _rle_string_counts(s: str) -> list[int]:
    """The LEB128-like string encoding of COCO's ``maskApi.c`` (``rleFrString``)."""
    counts: list[int] = []
    p = 0
    data = s.encode("ascii")
    while p < len(data):
        x, k, more = 0, 0, True
        while more:
            c = data[p] - 48
            x |= (c & 0x1F) << (5 * k)
            more = bool(c & 0x20)
            p += 1
            k += 1
            if not more and (c & 0x10):
                x |= -1 << (5 * k)
        if len(counts) > 2:
            x += counts[-2]
        counts.append(x)
    return counts
