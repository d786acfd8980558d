"""Real RGB-D frames of spheres, whose true size is not known: a sphere's box is a cube, and two frames of
the same spheres give the same boxes.

``symfruit evaluate --spheres DIR`` runs ``detect`` on every frame of ``DIR`` (its masks: one per sphere, the
same ids in every frame) with every method and scores each sphere's completed box by how far it is from a
cube (the largest difference between two of its sides), how far its depth side and its larger lateral side are
from the diameter the colour mask gives (its equivalent radius at the box centre's depth: the 2D thin-lens
estimate issue 18 compares lateral sides with, a reference, not the truth) and how far the frames disagree
(the largest difference of one side between two frames). The shipped Azure Kinect lab frames
(``examples/real-frames``, GRAP-UdL-AT, MIT) are the real-sensor check of issue 18.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..detect import detect
from ..errors import InputError, SymfruitError
from ..io.sources import open_source
from ..settings import Settings
from .frames import _check_run

__all__ = ["SphereBox", "evaluate_spheres", "spheres_table"]

#: Mask specs of segmenters, whose ids are not the same from frame to frame (besides ``color``).
_SEGMENTERS = ("maskrcnn:", "onnx:")


@dataclass(frozen=True)
class SphereBox:
    """One sphere of one frame under one method; sizes and the box's centre (camera frame) in millimetres."""

    frame: str
    sphere: int
    method: str
    size: tuple[float, float, float]
    diameter: float
    error: str = ""
    centre: tuple[float, float, float] = (float("nan"),) * 3

    @property
    def cube_mm(self) -> float:
        """The largest difference between two of the box's sides (0 for a cube)."""
        return float(np.ptp(self.size)) if not self.error else float("nan")

    @property
    def depth_mm(self) -> float:
        """Depth side minus the mask's diameter."""
        return float(self.size[2] - self.diameter) if not self.error else float("nan")

    @property
    def lateral_mm(self) -> float:
        """The larger lateral side (x or y) minus the mask's diameter."""
        return float(max(self.size[0], self.size[1]) - self.diameter) if not self.error else float("nan")


def evaluate_spheres(
    source: str | Path,
    *,
    methods: Sequence[str],
    masks: str = "auto",
    settings: Settings | None = None,
    failed: dict[str, str] | None = None,
) -> list[SphereBox]:
    """Every sphere of every frame of ``source`` under every method (a failed sphere carries its error; a
    frame that cannot be read or detected is left out and, with ``failed``, recorded there with its reason).

    Spheres are matched across frames by their mask ids, so ``masks`` must give the same ids in every frame:
    mask files (``auto``: each frame's own). A segmenter (``color``, ``maskrcnn:``, ``onnx:``) numbers what
    it finds anew in each frame and is refused; under ``auto`` a frame without a masks file is left out and
    recorded, never segmented by colour (its ids would be scored against other spheres' boxes).

    Raises
    ------
    InputError
        ``masks`` names a segmenter.
    """
    spec = str(masks)
    if spec == "color" or spec.startswith(_SEGMENTERS):
        raise InputError(f"--masks {spec}: spheres are matched across frames by their mask ids, which a segmenter "
                         "numbers anew in every frame; give mask files with the same id for a sphere in every "
                         "frame (auto: each frame's masks.png or masks.json)")  # fmt: skip
    settings = settings or Settings()
    _check_run(methods, masks, settings)  # before any frame: not every frame skipped with the same reason
    out: list[SphereBox] = []
    src = open_source(source)
    try:
        for index, name in enumerate(src.names()):
            try:
                frame = src.read(index)
                if spec == "auto" and frame.masks is None:
                    raise InputError(f"{frame.source or name}: no masks file (masks.png or masks.json); spheres are "
                                     "matched across frames by their mask ids, which the colour segmenter does not "
                                     "keep from frame to frame")  # fmt: skip
                found_by = {m: detect(frame, masks=masks, method=m, settings=settings) for m in methods}
            except SymfruitError as exc:
                if failed is not None:
                    failed[name] = str(exc)
                continue
            for method, found in found_by.items():
                for d in found.detections:
                    area = float(d.mask.sum())
                    if d.result is None:
                        out.append(SphereBox(name, d.id, method, (np.nan,) * 3, np.nan, d.error or "failed"))
                        continue
                    box = d.result.box
                    focal = float(np.sqrt(frame.camera.fx * frame.camera.fy))
                    diameter = 2.0 * np.sqrt(area / np.pi) * float(box.centre[2]) / focal
                    size = tuple(float(v) * 1000.0 for v in box.size)
                    centre = tuple(float(v) * 1000.0 for v in box.centre)
                    out.append(SphereBox(name, d.id, method, size, diameter * 1000.0,  # type: ignore[arg-type]
                                         centre=centre))  # type: ignore[arg-type]  # fmt: skip
    finally:
        src.close()
    return out


def spheres_table(rows: Sequence[SphereBox], methods: Sequence[str]) -> tuple[str, list[dict[str, Any]]]:
    """A Markdown table (per method: mean cube error, depth side and larger lateral side against the mask's
    diameter, the frames' largest disagreement, and every sphere's box) and its rows as dictionaries."""
    frames = sorted({r.frame for r in rows})
    spheres = sorted({r.sphere for r in rows})
    head = ["method", "not a cube (mm), mean / worst", "depth side - mask diameter (mm), mean abs (mean)",
            "larger lateral side - mask diameter (mm), mean abs (mean)", "frames differ (mm), worst",
            *(f"sphere {k} (mm)" for k in spheres)]  # fmt: skip
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]  # no sphere: no empty column (stop 56)
    summary = []
    for m in methods:
        mine = [r for r in rows if r.method == m]
        ok = [r for r in mine if not r.error]
        cube = np.array([r.cube_mm for r in ok])
        depth = np.array([r.depth_mm for r in ok])
        lateral = np.array([r.lateral_mm for r in ok])
        by_sphere: dict[int, list[SphereBox]] = {k: [] for k in spheres}
        for r in ok:
            by_sphere[r.sphere].append(r)
        # the largest difference of one side between two frames: of each side, its largest less its least (the
        # same as over every pair of frames, without the pairs: a recording of n frames has n^2 / 2)
        differ = [float(np.ptp([r.size for r in boxes], axis=0).max()) for boxes in by_sphere.values()
                  if len(boxes) > 1]  # fmt: skip
        cells = []
        for k in spheres:
            boxes = by_sphere[k]
            cells.append(" / ".join("x".join(f"{v:.0f}" for v in r.size) for r in boxes) or "failed")
        worst = max(differ) if differ else float("nan")
        lines.append(
            f"| `{m}` | {cube.mean():.1f} / {cube.max():.1f} | {np.abs(depth).mean():.1f} ({depth.mean():+.1f}) "
            f"| {np.abs(lateral).mean():.1f} ({lateral.mean():+.1f}) "
            f"| {f'{worst:.1f}' if differ else '-'} | " + " | ".join(cells) + " |"
            if len(ok)
            else "| " + " | ".join([f"`{m}`", "-", "-", "-", "-", *("failed" for _ in spheres)]) + " |"
        )
        summary.append({"method": m, "frames": frames, "failed": len(mine) - len(ok),
                        "cube_mm_mean": float(cube.mean()) if len(ok) else None,
                        "cube_mm_max": float(cube.max()) if len(ok) else None,
                        "depth_mm_mean_abs": float(np.abs(depth).mean()) if len(ok) else None,
                        "lateral_mm_mean_abs": float(np.abs(lateral).mean()) if len(ok) else None,
                        "frames_differ_mm": worst if differ else None,
                        "boxes": [_box_record(r) for r in mine]})  # fmt: skip
    return "\n".join(lines) + "\n", summary


def _box_record(r: SphereBox) -> dict[str, Any]:
    """One sphere box for summary.json: a failed one has no size, no diameter and no centre (null, never NaN,
    which is not JSON)."""
    if r.error:
        return {**r.__dict__, "size": None, "diameter": None, "centre": None}
    centre = list(r.centre) if np.isfinite(r.centre).all() else None
    return {**r.__dict__, "size": list(r.size), "centre": centre}
