"""The per-frame job of a harvesting robot: masks -> points -> completion -> boxes -> outputs.

``detect(frame)`` finds the fruit of one RGB-D frame; ``write_detections`` writes what a robot and a
person need: ``detections.json`` (laid out to map one-to-one onto ROS 2 ``vision_msgs/Detection3D``),
each fruit's completed cloud as PLY, and an overlay PNG.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .box import Box
from .complete import Result, complete
from .config import Settings
from .errors import FileFormatError, InputError, SymfruitError
from .extract import Extraction, extract
from .io.frames import Frame
from .segment import segment

__all__ = ["Detection", "FrameDetections", "detect", "frame_masks", "write_detections"]

#: ``frame_id`` written into detections.json: the colour camera's optical frame (REP-103).
OPTICAL_FRAME = "camera_color_optical_frame"


@dataclass(frozen=True)
class Detection:
    """One fruit of a frame."""

    id: int
    mask: np.ndarray
    extraction: Extraction
    result: Result | None = None
    error: str = ""

    @property
    def visible_box(self) -> Box | None:
        pts = self.extraction.points
        return Box.from_points(pts) if len(pts) else None

    def to_dict(self) -> dict[str, Any]:
        """One entry of ``detections.json``; ``bbox`` is a ``vision_msgs/BoundingBox3D``."""
        ex = self.extraction
        out: dict[str, Any] = {
            "id": self.id, "mask_area": ex.mask_area, "n_points": len(ex.points), "truncated": ex.truncated,
            "n_invalid_depth": ex.n_invalid, "n_dropped_clusters": ex.n_other_clusters,
        }  # fmt: skip
        if self.error or self.result is None:
            return {**out, "error": self.error}
        r = self.result
        c, size = r.box.centre, r.box.size
        out.update(
            centre=c.tolist(),
            box=r.box.to_dict(),
            visible_box=self.visible_box.to_dict(),
            bbox={
                "center": {
                    "position": dict(zip("xyz", c.tolist(), strict=True)),
                    "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
                },
                "size": dict(zip("xyz", size.tolist(), strict=True)),
            },
            method=r.method,
            plane=None if r.plane is None else r.plane.to_dict(),
            score=None if not np.isfinite(r.score) else float(r.score),
            seconds=r.seconds,
            confidence=r.confidence,
            reliable=r.reliable,
        )
        return out


@dataclass(frozen=True)
class FrameDetections:
    """All fruit of one frame, with the time each stage took (seconds)."""

    frame: Frame
    detections: list[Detection]
    timings: dict[str, float] = field(default_factory=dict)
    mask_source: str = ""

    def to_dict(self) -> dict[str, Any]:
        """``detections.json``: a ``vision_msgs/Detection3DArray``-like object with symfruit's extras."""
        return {
            "frame": self.frame.name,
            "source": self.frame.source,
            "header": {"frame_id": OPTICAL_FRAME},
            "camera": self.frame.camera.to_dict(),
            "units": "metres",
            "mask_source": self.mask_source,
            "timings": self.timings,
            "fruits": [d.to_dict() for d in self.detections],
        }


Segmenter = Callable[[Frame, Settings], np.ndarray]


def frame_masks(
    frame: Frame, masks: str | Path | Segmenter = "auto", settings: Settings | None = None
) -> tuple[np.ndarray, str]:
    """Instance labels for a frame, and a word on where they came from.

    ``masks`` is ``"auto"`` (the frame's own masks file if it has one, else the colour segmenter),
    ``"color"`` (the built-in segmenter), a label PNG or COCO JSON path, ``"maskrcnn:CHECKPOINT"``
    (a torchvision Mask R-CNN, optional extra ``seg``), or a callable ``(frame, settings) -> labels``.
    """
    settings = settings or Settings()
    shape = frame.depth.shape
    if callable(masks):
        labels, source = np.asarray(masks(frame, settings)), getattr(masks, "__name__", "callable")
    elif masks == "auto" and frame.masks is not None:
        labels, source = frame.masks, "frame masks file"
    elif masks in ("auto", "color"):
        labels, source = segment(frame.color, frame.depth, frame.camera, settings.segment), "colour segmenter"
    elif str(masks).startswith("maskrcnn:"):
        from .segment_maskrcnn import maskrcnn_labels

        labels, source = maskrcnn_labels(frame.color, str(masks).split(":", 1)[1]), str(masks)
    else:
        from .io.masks import read_masks

        labels, source = read_masks(masks, shape), str(masks)
    if labels.shape != shape:
        raise InputError(f"frame {frame.name}: masks are {labels.shape[::-1]}, the image {shape[::-1]}")
    return labels.astype(np.int32, copy=False), source


def detect(
    frame: Frame,
    *,
    masks: str | Path | Segmenter = "auto",
    method: str = "fused",
    settings: Settings | None = None,
) -> FrameDetections:
    """Find, extract, complete and box every fruit of a frame.

    A fruit that cannot be completed (too few points, degenerate) is kept with its ``error``; the
    others are unaffected. A mask covering the whole image is refused (it is not a fruit).
    """
    settings = settings or Settings()
    t0 = time.perf_counter()
    labels, source = frame_masks(frame, masks, settings)
    t1 = time.perf_counter()
    if not (frame.depth > 0).any():
        raise InputError(f"frame {frame.name}: the depth image holds no valid depth")
    detections, t_extract, t_complete = [], 0.0, 0.0
    from scipy import ndimage

    for k, sl in enumerate(ndimage.find_objects(labels), 1):
        if sl is None:
            continue
        mask = np.zeros(labels.shape, bool)
        mask[sl] = labels[sl] == k
        if mask.all():
            raise InputError(f"frame {frame.name}: mask {k} covers the whole image; that is not a fruit")
        a = time.perf_counter()
        ex = _extract_window(mask, sl, frame, settings)
        b = time.perf_counter()
        t_extract += b - a
        if len(ex.points) < settings.extract.min_points:
            why = (f"only {len(ex.points)} points with valid depth (extract.min_points = "
                   f"{settings.extract.min_points}); {ex.n_invalid} of {ex.mask_area} mask pixels "
                   "had no depth")  # fmt: skip
            detections.append(Detection(int(k), mask, ex, error=why))
            continue
        try:
            result = complete(ex.points, camera=frame.camera, method=method, settings=settings)
            detections.append(Detection(int(k), mask, ex, result))
        except SymfruitError as exc:
            detections.append(Detection(int(k), mask, ex, error=str(exc)))
        t_complete += time.perf_counter() - b
    total = time.perf_counter() - t0
    timings = {"segment": t1 - t0, "extract": t_extract, "complete": t_complete, "total": total}
    return FrameDetections(frame, detections, timings, source)


def _extract_window(mask: np.ndarray, sl: tuple[slice, slice], frame: Frame, settings: Settings) -> Extraction:
    """:func:`extract` on the mask's bounding window (with a margin), keeping the truncation test."""
    h, w = mask.shape
    pad = settings.extract.erode_px + 1
    r0, r1 = max(sl[0].start - pad, 0), min(sl[0].stop + pad, h)
    c0, c1 = max(sl[1].start - pad, 0), min(sl[1].stop + pad, w)
    from .camera import Camera

    cam = frame.camera
    local = Camera(fx=cam.fx, fy=cam.fy, cx=cam.cx - c0, cy=cam.cy - r0, width=c1 - c0, height=r1 - r0)
    ex = extract(mask[r0:r1, c0:c1], frame.depth[r0:r1, c0:c1], local, settings.extract)
    truncated = bool(sl[0].start == 0 or sl[1].start == 0 or sl[0].stop == h or sl[1].stop == w)
    return Extraction(ex.points, ex.mask_area, ex.n_invalid, ex.n_border, ex.n_other_clusters, truncated)


def write_detections(folder: str | Path, found: FrameDetections, *, settings: Settings | None = None) -> list[Path]:
    """Write ``detections.json``, ``fruit_<id>.ply`` per completed fruit and ``overlay.png``, atomically."""
    from .io import write_json, write_ply
    from .io.atomic import atomic_write

    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise FileFormatError(f"{folder}: cannot create output folder ({exc.strerror or exc})") from None
    written = []
    for d in found.detections:
        if d.result is not None:
            path = folder / f"fruit_{d.id:03d}.ply"
            n_vis = len(d.result.visible)
            labels = np.r_[np.zeros(n_vis, np.uint8), np.ones(len(d.result.points) - n_vis, np.uint8)]
            write_ply(path, d.result.points, labels=labels)
            written.append(path)
    overlay = draw_overlay(found)
    with atomic_write(folder / "overlay.png", "wb") as handle:
        overlay.save(handle, format="PNG")
    written.append(folder / "overlay.png")
    data = found.to_dict()
    if settings is not None:
        data["settings"] = settings.to_dict()
    write_json(folder / "detections.json", data)  # last: its presence marks the frame as done
    written.append(folder / "detections.json")
    return written


_EDGES = [(a, b) for a in range(8) for b in range(a + 1, 8) if bin(a ^ b).count("1") == 1]
VISIBLE_COLOUR = (255, 170, 0)
COMPLETED_COLOUR = (0, 220, 255)


def draw_overlay(found: FrameDetections):
    """The colour image with each fruit's mask, the box of its visible points (orange) and of the
    completed fruit (cyan) as projected wireframe cuboids, and the completed centre marked."""
    from PIL import Image, ImageDraw

    frame = found.frame
    image = frame.color.astype(np.float32)
    palette = np.array([[230, 25, 75], [60, 180, 75], [255, 225, 25], [67, 99, 216], [245, 130, 49],
                        [145, 30, 180], [70, 240, 240], [240, 50, 230], [188, 246, 12], [250, 190, 190]])  # fmt: skip
    for i, d in enumerate(found.detections):
        image[d.mask] = 0.55 * image[d.mask] + 0.45 * palette[i % len(palette)]
    img = Image.fromarray(np.clip(image, 0, 255).astype(np.uint8))
    draw = ImageDraw.Draw(img)
    cam = frame.camera
    for d in found.detections:
        boxes = [(d.visible_box, VISIBLE_COLOUR)] if d.visible_box is not None else []
        if d.result is not None:
            boxes.append((d.result.box, COMPLETED_COLOUR))
        for box, colour in boxes:
            uv = cam.project(box.corners())
            for a, b in _EDGES:
                draw.line([tuple(uv[a]), tuple(uv[b])], fill=colour, width=1)
        rows, cols = np.nonzero(d.mask)
        label_at = (int(cols.min()), max(int(rows.min()) - 12, 0))
        if d.result is not None:
            u, v = cam.project(d.result.centre[None])[0]
            draw.line([(u - 4, v), (u + 4, v)], fill=COMPLETED_COLOUR, width=2)
            draw.line([(u, v - 4), (u, v + 4)], fill=COMPLETED_COLOUR, width=2)
            z = d.result.centre[2] * 1000
            draw.text(
                label_at,
                f"{d.id}: {z:.0f} mm" + (" (cut)" if d.extraction.truncated else ""),
                fill=(255, 255, 255),
            )
        else:
            draw.text(label_at, f"{d.id}: failed", fill=(255, 80, 80))
    draw.text((5, cam.height - 14), "orange: visible points   cyan: completed fruit", fill=(255, 255, 255))
    return img
