"""The paper's section 5.3 / Table 3 evaluation on any folder of annotated RGB-D frames.

Each frame's fruit are found once (masks, points); every method then completes the same points.
Found fruit are matched to the true boxes of ``truth.json`` (Hungarian assignment on centre distance,
within ``gate`` metres); matched fruit are scored by box IoU and centre deviation, as in Table 3.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import linear_sum_assignment

from ..core.box import Box, box_iou, centre_deviation
from ..core.camera import Camera
from ..core.frame import Frame
from ..core.raster import mask_box
from ..detect import FrameDetections, detect
from ..errors import SymfruitError
from ..io.sources import open_source
from ..methods.complete import complete
from ..settings import Settings

__all__ = ["VISIBILITY_GROUPS", "FrameScore", "evaluate_frames", "match", "thin_lens"]


@dataclass(frozen=True)
class FrameScore:
    """One matched fruit under one method: box IoU, centre deviation and the signed size errors of the box's
    depth side and larger lateral side (positive: too large; :class:`~symfruit.evaluate.metrics.Scores`).

    ``visible``: the share of the fruit's silhouette the camera sees, where ``truth.json`` records it (NaN
    otherwise). ``thin_depth_mm``, ``thin_lateral_mm``: the same two errors of the 2-D thin-lens estimate, a
    reference that knows no 3-D shape (:func:`thin_lens`; the same for every method of one fruit)."""

    frame: str
    fruit: int
    truth: int
    method: str
    iou: float
    centre_mm: float
    n_points: int
    truncated: bool
    depth_mm: float = float("nan")
    lateral_mm: float = float("nan")
    visible: float = float("nan")
    thin_depth_mm: float = float("nan")
    thin_lateral_mm: float = float("nan")


def thin_lens(mask: np.ndarray, points: np.ndarray, camera: Camera) -> float:
    """The 2-D thin-lens estimate of a fruit's diameter (metres): the mask's larger extent in pixels times the
    median depth of its points over the focal length (issue 18's reference for a box's lateral sides)."""
    box = mask_box(mask)
    if box is None or not len(points):
        return float("nan")
    r0, r1, c0, c1 = box
    return max((c1 - c0) / camera.fx, (r1 - r0) / camera.fy) * float(np.median(points[:, 2]))


def match(found: Sequence[Box | None], truth: Sequence[Box], gate: float = 0.03) -> list[tuple[int, int]]:
    """Pairs ``(found index, truth index)`` minimising total centre distance, each within ``gate`` metres
    (a ``None`` among ``found`` matches nothing)."""
    if not found or not truth:
        return []
    far = np.inf
    cost = np.array([[far if f is None else np.linalg.norm(f.centre - t.centre) for t in truth] for f in found])
    rows, cols = linear_sum_assignment(np.where(cost <= gate, cost, 1e6))
    return [(int(r), int(c)) for r, c in zip(rows, cols, strict=True) if cost[r, c] <= gate]


def score_frame(
    frame: Frame, found: FrameDetections, methods: Sequence[str], settings: Settings, gate: float = 0.03,
    *, by_id: bool = False,
) -> tuple[list[FrameScore], dict[str, int]]:  # fmt: skip
    """Scores of every matched fruit under every method, and detection counts.

    Found fruit are matched to the truth by the centre of the box of their visible points, within ``gate``
    metres (independent of the method being scored; the paper's protocol), or with ``by_id`` by their mask's
    label, which must then be the truth's id (masks drawn for the truth, as the scenes' annotators' masks are):
    every fruit with a completion is scored however far its seen points' box lies from the truth."""
    truth = frame.truth or []
    ok = [d for d in found.detections if d.result is not None]
    if by_id:
        index = {tid: j for j, (tid, _) in enumerate(truth)}
        pairs = [(i, index[d.id]) for i, d in enumerate(ok) if d.id in index]
    else:
        pairs = match([d.visible_box for d in ok], [b for _, b in truth], gate)
    scores = []
    for i, j in pairs:
        d = ok[i]
        tid, tbox = truth[j]
        thin = thin_lens(d.mask, d.extraction.points, found.camera)
        reference = {"visible": frame.visible.get(tid, float("nan")),
                     "thin_depth_mm": (thin - float(tbox.size[2])) * 1000,
                     "thin_lateral_mm": (thin - float(tbox.size[:2].max())) * 1000}  # fmt: skip
        for method in methods:
            try:
                box = complete(d.extraction.points, camera=found.camera, method=method, settings=settings,
                               occlusion=d.occlusion).box  # fmt: skip
            except SymfruitError:
                continue
            scores.append(FrameScore(frame.name, d.id, tid, method, box_iou(box, tbox),
                                     centre_deviation(box, tbox) * 1000, len(d.extraction.points),
                                     d.extraction.truncated, float(box.size[2] - tbox.size[2]) * 1000,
                                     float(box.size[:2].max() - tbox.size[:2].max()) * 1000,
                                     **reference))  # fmt: skip
    counts = {"truth": len(truth), "found": len(found.detections), "matched": len(pairs),
              "missed": len(truth) - len(pairs), "false": len(found.detections) - len(pairs)}  # fmt: skip
    return scores, counts


def evaluate_frames(
    source: str | Path,
    *,
    methods: Sequence[str] = ("raw", "sphere", "ellipsoid", "paper"),
    masks: str = "auto",
    settings: Settings | None = None,
    gate: float = 0.03,
    by_id: bool = False,
) -> tuple[list[FrameScore], dict[str, int], dict[str, str]]:
    """Table 3 on a recording: scores, summed detection counts, and frames that failed (with reasons); ``gate``
    and ``by_id``: how found fruit are matched to the truth (:func:`score_frame`)."""
    settings = settings or Settings()
    _check_run(methods, masks, settings)
    scores: list[FrameScore] = []
    totals = {"frames": 0, "truth": 0, "found": 0, "matched": 0, "missed": 0, "false": 0}
    failed: dict[str, str] = {}
    src = open_source(source)
    try:
        for index, name in enumerate(src.names()):
            try:
                frame = src.read(index)
                if frame.truth is None:
                    failed[name] = "no truth.json"
                    continue
                found = detect(frame, masks=masks, method="raw", settings=settings)
            except SymfruitError as exc:
                failed[name] = str(exc)
                continue
            if by_id and found.mask_source != "frame masks file":  # a segmenter's labels are not the truth's ids
                failed[name] = f"no masks file to match the truth by label (the masks: {found.mask_source})"
                continue
            s, counts = score_frame(frame, found, methods, settings, gate, by_id=by_id)
            scores += s
            totals["frames"] += 1
            for k, v in counts.items():
                totals[k] += v
    finally:
        src.close()
    return scores, totals, failed


def table3(scores: Sequence[FrameScore], totals: dict[str, int], methods: Sequence[str]) -> str:
    """Markdown laid out like the paper's Table 3."""
    from .report import PAPER_TABLE3

    lines = [
        "# symfruit evaluation: annotated frames (cf. Ge et al. Table 3)", "",
        f"{totals['frames']} frames, {totals['truth']} true fruit, {totals['found']} found, "
        f"{totals['matched']} matched, {totals['missed']} missed, {totals['false']} false.", "",
        "| method | IoU mean | IoU median | centre dev mean (mm) | centre dev median (mm) | depth side (mm) "
        "| larger lateral side (mm) | fruit |",
        "|---|---|---|---|---|---|---|---|",
    ]  # fmt: skip
    for m in methods:
        mine = [s for s in scores if s.method == m]
        if not mine:
            continue
        iou = np.array([s.iou for s in mine])
        dev = np.array([s.centre_mm for s in mine])
        dz = np.array([s.depth_mm for s in mine])
        dl = np.array([s.lateral_mm for s in mine])
        lines.append(f"| {m} | {iou.mean():.3f} | {np.median(iou):.3f} | {dev.mean():.1f} | {np.median(dev):.1f} "
                     f"| {np.abs(dz).mean():.1f} ({dz.mean():+.1f}) | {np.abs(dl).mean():.1f} ({dl.mean():+.1f}) "
                     f"| {len(mine)} |")  # fmt: skip
    (ri, rc), (pi, pc) = PAPER_TABLE3["raw"], PAPER_TABLE3["paper"]
    lines += [
        "",
        f"Ge et al. 2020, Table 3 (D435, mean): input points {ri} / {rc} mm, completed {pi} / {pc} mm.",
        "",
    ]
    lines += sizes_by_visibility(scores, methods)
    return "\n".join(lines)


#: Groups of truth fruit by the share of their silhouette the camera sees: (label, least share, below share).
VISIBILITY_GROUPS = (("visible (>= 90 % seen)", 0.9, 2.0), ("partly hidden (60-90 %)", 0.6, 0.9),
                     ("mostly hidden (< 60 %)", -1.0, 0.6))  # fmt: skip


def sizes_by_visibility(scores: Sequence[FrameScore], methods: Sequence[str]) -> list[str]:
    """Markdown lines: the box's depth side and larger lateral side against the truth per visibility group
    (``truth.json``'s ``visible``; none when no fruit records one), the thin-lens estimate as a reference row."""
    if not any(np.isfinite(s.visible) for s in scores):
        return []
    head = [label for label, _, _ in VISIBILITY_GROUPS]
    lines = ["Box sides by how much of each fruit the camera sees (mean absolute error in mm, the mean signed error "
             "in brackets: depth side / larger lateral side; the thin-lens row is the mask's larger extent times "
             "the median depth over f, for both):", "",
             "| method | " + " | ".join(head) + " |", "|---|" + "---|" * len(head)]  # fmt: skip

    def cell(dz: np.ndarray, dl: np.ndarray) -> str:
        if not len(dz):
            return "-"
        return (f"{np.abs(dz).mean():.1f} ({dz.mean():+.1f}) / {np.abs(dl).mean():.1f} ({dl.mean():+.1f}) "
                f"(n {len(dz)})")  # fmt: skip

    def groups(mine: Sequence[FrameScore], depth: str, lateral: str) -> list[str]:
        out = []
        for _, lo, hi in VISIBILITY_GROUPS:
            got = [s for s in mine if lo <= s.visible < hi]
            out.append(cell(np.array([getattr(s, depth) for s in got]), np.array([getattr(s, lateral) for s in got])))
        return out

    first = [s for s in scores if s.method == next((m for m in methods if any(x.method == m for x in scores)), "")]
    lines.append("| thin-lens (reference) | " + " | ".join(groups(first, "thin_depth_mm", "thin_lateral_mm")) + " |")
    for m in methods:
        mine = [s for s in scores if s.method == m]
        if mine:
            lines.append(f"| {m} | " + " | ".join(groups(mine, "depth_mm", "lateral_mm")) + " |")
    return [*lines, ""]


def summary_dict(scores: Sequence[FrameScore], totals: dict[str, int], failed: dict[str, str]) -> dict[str, Any]:
    """What ``summary.json`` holds (a value not measured, NaN, is ``null``: JSON has no NaN)."""

    def plain(value: Any) -> Any:
        return None if isinstance(value, float) and not np.isfinite(value) else value

    return {"totals": totals, "failed": failed,
            "scores": [{k: plain(v) for k, v in s.__dict__.items()} for s in scores]}  # fmt: skip


def _check_run(methods: Sequence[str], masks: Any, settings: Settings) -> None:
    """Refuse, before any frame, an unknown method or a masks spec no frame can use (an empty one, a file or folder
    that does not exist, a model or its extra missing): otherwise every frame is skipped with the same reason."""
    from ..methods.registry import get
    from ..segment import mask_source

    for method in methods:
        get(method)
    if isinstance(masks, str | Path):
        mask_source(masks, settings=settings)
