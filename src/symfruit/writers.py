"""Every file symfruit writes, in one place, each written atomically (a temporary file renamed over the
target, so an interrupted run never leaves a half-written file; :mod:`symfruit.io.atomic`). Inside a run's
output folder (:class:`symfruit.io.outputs.OutputFolder`: names, inputs, links, one writer) every file
written here goes through that folder's checks.

==================  ===================================================================================
what                files
==================  ===================================================================================
one completion      ``OUT.ply`` (visible + completed points, ``label`` 0/1) and ``OUT.json`` (the result,
                    the input, the camera and the effective settings): :func:`write_result`
one frame           ``detections.json`` (maps one-to-one onto ROS 2 ``vision_msgs/Detection3DArray``),
                    ``fruit_NNN.ply`` per completed fruit, ``overlay.png``: :func:`write_detections`;
                    the folder holds exactly the current run's files
a results folder    ``ROOT/<timestamp>-<tag>[-k]`` with a ``latest`` link: :func:`new_results_folder`
instance masks      ``<stem>.png`` (16-bit instance labels, 0 background) and ``<stem>_overlay.png`` (the
                    image with each fruit tinted and outlined): :func:`write_labels`,
                    :func:`draw_label_overlay`
a masks evaluation  ``masks.csv`` (one row per image), ``summary.json``, ``worst.png`` (contact sheet of the
                    worst images, truth green and prediction magenta): :func:`write_mask_report`
==================  ===================================================================================
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import fnmatch
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from .core.box import Box
from .core.limits import instance_labels, shown
from .detect import Detection, FrameDetections
from .errors import FileFormatError, OutputError
from .extract import shift_labels
from .io.atomic import atomic_write, folder_fd, stale_temporaries, write_json
from .io.clouds import write_ply
from .io.images import BAND_PIXELS
from .io.text import as_path
from .methods.complete import Result
from .settings import Settings

__all__ = [
    "OPTICAL_FRAME",
    "bbox_record",
    "check_result_paths",
    "detection_record",
    "detections_record",
    "draw_contact_sheet",
    "draw_label_overlay",
    "draw_overlay",
    "new_results_folder",
    "write_detections",
    "write_label_overlay",
    "write_labels",
    "write_mask_report",
    "write_result",
]

#: ``frame_id`` written into detections.json: the colour camera's optical frame (REP-103).
OPTICAL_FRAME = "camera_color_optical_frame"
#: Files a frame's output folder may hold; anything else matching these patterns is a previous run's.
_FRAME_OUTPUTS = ("fruit_*.ply", "overlay.png", "detections.json")
#: zlib level of the overlays: level 1 writes a 640x480 overlay in about 60 % of the default level's time
#: (a sixth of a frame's wall time at level 6) for files about 13 % larger.
FAST_PNG = 1


def _labels(result: Result) -> np.ndarray:
    """0 for the visible points, 1 for the completed ones (the order of ``result.points``)."""
    n_vis = len(result.visible)
    return np.r_[np.zeros(n_vis, np.uint8), np.ones(len(result.points) - n_vis, np.uint8)]


def check_result_paths(path: str | Path, inputs: Iterable[str | Path | None] = ()) -> tuple[Path, Path]:
    """``(ply, json)``: the two files :func:`write_result` writes for ``path``, checked before any work is
    done: ``path`` ends in ``.ply``, neither is a folder nor one of the run's ``inputs`` (the cloud, the
    intrinsics, the settings file: ``complete a.ply --output a.ply`` would write over the cloud it read).
    A symbolic link at either name is followed: the file returned is its target, written over atomically.

    Raises
    ------
    FileFormatError
        When ``path`` does not end in ``.ply``.
    OutputError
        When either file is a folder, an input, a pipe, socket or device (or a link to one), or a link into a
        folder that does not exist.
    """
    path = as_path(path, "write_result: the output file")  # '' was the working folder
    if path.suffix.lower() != ".ply":
        raise FileFormatError(f"{path}: the output must end in .ply")
    json_path = path.with_suffix(".json")
    read = {os.path.realpath(p): Path(p) for p in inputs if p is not None}
    out = []
    for target in (path, json_path):  # both checked before either is written
        if target.is_dir():
            raise OutputError(f"{target}: is a folder; give a file name ending in .ply (the result goes to "
                              f"{path.name} and {json_path.name})")  # fmt: skip
        if (given := read.get(os.path.realpath(target))) is not None:
            raise OutputError(f"{target}: is an input of this run ({given}); the result ({path.name} and "
                              f"{json_path.name}) would write over it: choose another output name")  # fmt: skip
        out.append(_named_target(target))
    return out[0], out[1]


def _named_target(target: Path) -> Path:
    """Where a file the user names is written: a link there is followed to its target (written atomically
    beside the target, as the user set the link up), never replaced by a file; a pipe, socket or device (its
    own or the link's target) is refused, never replaced either."""
    import stat

    where = Path(os.path.realpath(target)) if target.is_symlink() else target
    try:
        mode = os.stat(where).st_mode
    except FileNotFoundError:
        if where is not target and not where.parent.is_dir():
            raise OutputError(f"{target}: is a link to {where}, whose folder {where.parent} does not exist; "
                              "not written") from None  # fmt: skip
        return where
    except OSError:  # a file where a folder is, a loop of links: the write names it as for any path
        return where
    if not stat.S_ISREG(mode):
        what = "a pipe" if stat.S_ISFIFO(mode) else "a socket" if stat.S_ISSOCK(mode) else "a device"
        via = f" (through the link to {where})" if where is not target else ""
        raise OutputError(f"{target}: is {what}{via}, not a file; the result is written to regular files only: "
                          "choose another output name")  # fmt: skip
    return where


def write_result(
    path: str | Path, result: Result, *, meta: dict[str, Any] | None = None, inputs: Iterable[str | Path | None] = ()
) -> tuple[Path, Path]:
    """Write ``path`` (``.ply``: the completed cloud) and the same name ``.json`` (record, extras, settings);
    ``inputs``: the files the result was made from, never written over (:func:`check_result_paths`).

    Raises
    ------
    FileFormatError
        When ``path`` does not end in ``.ply``.
    OutputError
        When ``path`` or its ``.json`` is a folder or one of ``inputs``.
    """
    path, json_path = check_result_paths(path, inputs)
    record = {**result.to_dict(), **(meta or {}), "extras": result.extras,
              "settings": result.settings.to_dict()}  # fmt: skip
    write_ply(path, result.points, labels=_labels(result))
    write_json(json_path, record)
    return path, json_path


def bbox_record(box: Box) -> dict[str, Any]:
    """``bbox`` of a ``detections.json`` entry: a ``vision_msgs/BoundingBox3D`` (centre pose, size; metres)."""
    return {
        "center": {
            "position": dict(zip("xyz", box.centre.tolist(), strict=True)),
            "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
        },
        "size": dict(zip("xyz", box.size.tolist(), strict=True)),
    }


def detection_record(d: Detection) -> dict[str, Any]:
    """One entry of ``detections.json``; ``bbox`` is a ``vision_msgs/BoundingBox3D``."""
    ex = d.extraction
    # Python's ints and bools: a count computed by numpy (an np.int64) made json.dumps fail the frame ("Object of
    # type int64 is not JSON serializable", stop 50: robust49's masks cases on 35f8d31)
    out: dict[str, Any] = {
        "id": int(d.id), "mask_area": int(ex.mask_area), "n_points": len(ex.points), "truncated": bool(ex.truncated),
        "n_invalid_depth": int(ex.n_invalid), "n_dropped_clusters": int(ex.n_other_clusters),
    }  # fmt: skip
    if d.error or d.result is None:
        return {**out, "error": d.error}
    r = d.result
    visible = d.visible_box
    out.update(
        centre=r.box.centre.tolist(),
        box=r.box.to_dict(),
        visible_box=None if visible is None else visible.to_dict(),
        bbox=bbox_record(r.box),
        method=r.method,
        plane=None if r.plane is None else r.plane.to_dict(),
        score=None if not np.isfinite(r.score) else float(r.score),
        seconds=r.seconds,
        confidence=r.confidence,
        reliable=r.reliable,
    )
    return out


def detections_record(found: FrameDetections, *, settings: Settings | None = None) -> dict[str, Any]:
    """``detections.json``: a ``vision_msgs/Detection3DArray``-like object with symfruit's extras."""
    frame = found.frame
    header: dict[str, Any] = {"frame_id": frame.frame_id or OPTICAL_FRAME}
    if frame.stamp is not None:
        header["stamp"] = {"sec": frame.stamp // 1_000_000_000, "nanosec": frame.stamp % 1_000_000_000}
    data: dict[str, Any] = {
        "frame": frame.name,
        "source": frame.source,
        "header": header,
        "camera": frame.camera.to_dict(),
        "units": "metres",
        "mask_source": found.mask_source,
        "registration_px": list(found.registration),
        "timings": found.timings,
        "fruits": [detection_record(d) for d in found.detections],
    }
    if settings is not None:
        data["settings"] = settings.to_dict()
    return data


def write_detections(folder: str | Path, found: FrameDetections, *, settings: Settings | None = None) -> list[Path]:
    """Write a frame's ``fruit_<id>.ply`` files, ``overlay.png`` and, last, ``detections.json``.

    ``detections.json`` is written last: its presence marks the frame as done. Files a previous run left
    in the folder that this run does not write (``fruit_004.ply`` when there are now three fruit, stale
    temporary files of a killed run) are removed, so the folder holds exactly this run's results. Inside an
    open :class:`~symfruit.io.outputs.OutputFolder` (a batch's), a link in the way is refused, never followed.

    Raises
    ------
    OutputError
        When a file cannot be written (``errno`` set for a full disk); the frame is then not done.
    """
    folder = as_path(folder, "write_detections: the frame folder")  # '' was the working folder
    with folder_fd(folder) as fd, contextlib.suppress(FileNotFoundError, IsADirectoryError):
        os.unlink("detections.json", dir_fd=fd)  # the frame is not done until its new record is written
    written = []
    for d in found.detections:
        if d.result is not None:
            path = folder / f"fruit_{d.id:03d}.ply"
            write_ply(path, d.result.points, labels=_labels(d.result))
            written.append(path)
    with atomic_write(folder / "overlay.png", "wb") as handle:
        draw_overlay(found).save(handle, format="PNG", compress_level=FAST_PNG)
    written.append(folder / "overlay.png")
    remove_stale(folder, keep=[*written, folder / "detections.json"])
    write_json(folder / "detections.json", detections_record(found, settings=settings))
    written.append(folder / "detections.json")
    return written


def frame_outputs(name: str) -> bool:
    """Whether ``name`` is one of the files :func:`write_detections` writes into a frame's folder."""
    return any(fnmatch.fnmatchcase(name, pattern) for pattern in _FRAME_OUTPUTS)


def remove_stale(folder: Path, *, keep: list[Path]) -> None:
    """Delete a previous run's frame outputs and a killed run's temporary files in ``folder`` that are not
    in ``keep`` (a live run's temporary files are left alone; inside an output folder links are not followed)."""
    keep_names = {p.name for p in keep}
    with folder_fd(folder, create=False) as fd:
        stale = [n for n in os.listdir(fd) if frame_outputs(n) and n not in keep_names] + stale_temporaries(fd)
        for name in stale:
            with contextlib.suppress(FileNotFoundError, IsADirectoryError):
                os.unlink(name, dir_fd=fd)


def check_results_root(root: str | Path) -> None:
    """Refuse, before any work is done, a results root :func:`new_results_folder` could not write into: a
    file, a path below a file, or a folder (or the nearest existing one above a root still to be made) that
    is not writable. Nothing is created.

    Raises
    ------
    FileFormatError
        Naming ``root`` and the problem.
    """
    root = as_path(root, "the results root")  # '' was the working folder
    probe = root
    while not probe.exists() and probe != probe.parent:  # the nearest existing folder, where mkdir would start
        probe = probe.parent
    if not probe.is_dir():
        where = "is a file" if probe == root else f"lies below {probe}, which is a file"
        raise FileFormatError(f"{root}: cannot create a results folder (the results root {where})")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise FileFormatError(f"{root}: cannot create a results folder ({probe} is not writable)")


def new_results_folder(root: str | Path, tag: str) -> Path:
    """A new folder ``root/<YYYYmmdd-HHMMSS>-<tag>`` (``-2``, ``-3``... if taken) and a ``latest`` link to it.

    Raises
    ------
    FileFormatError
        When ``root`` cannot be written.
    """
    root = as_path(root, "new_results_folder: the results root")  # '' was the working folder
    stamp = _dt.datetime.now().strftime("%Y%m%d-%H%M%S")
    k = 1
    while True:
        folder = root / (f"{stamp}-{tag}" if k == 1 else f"{stamp}-{tag}-{k}")
        try:
            folder.mkdir(parents=True)
            break
        except FileExistsError:
            k += 1
        except OSError as exc:
            raise FileFormatError(f"{root}: cannot create a results folder ({exc.strerror or exc})") from None
    _link_latest(folder)
    return folder


def _link_latest(folder: Path) -> None:
    link = folder.parent / "latest"
    tmp = folder.parent / f".latest-{os.getpid()}"
    try:
        if tmp.is_symlink() or tmp.exists():
            tmp.unlink()
        tmp.symlink_to(folder.name)
        os.replace(tmp, link)
    except OSError:  # file systems without symlinks: the timestamped folder is still there
        pass


_EDGES = [(a, b) for a in range(8) for b in range(a + 1, 8) if bin(a ^ b).count("1") == 1]
VISIBLE_COLOUR = (255, 170, 0)
COMPLETED_COLOUR = (0, 220, 255)
_PALETTE = np.array([[230, 25, 75], [60, 180, 75], [255, 225, 25], [67, 99, 216], [245, 130, 49],
                     [145, 30, 180], [70, 240, 240], [240, 50, 230], [188, 246, 12], [250, 190, 190]])  # fmt: skip


def draw_overlay(found: FrameDetections) -> Any:
    """The colour image (a PIL image) with each fruit's mask, the box of its visible points (orange) and
    of the completed fruit (cyan) as projected wireframe cuboids, and the completed centre marked."""
    from PIL import Image, ImageDraw

    frame = found.frame
    du, dv = found.registration
    image = frame.color.copy()  # tinted fruit by fruit (their masks are disjoint): no full-size float copy
    for i, d in enumerate(found.detections):
        # the masks lie on the depth image: moved back by the registration shift onto the colour image's pixels
        mask = shift_labels(d.mask, -du, -dv) if (du, dv) != (0, 0) else d.mask
        tinted = 0.55 * image[mask].astype(np.float32) + 0.45 * _PALETTE[i % len(_PALETTE)].astype(np.float32)
        image[mask] = np.clip(tinted, 0, 255).astype(np.uint8)
    img = Image.fromarray(image)
    del image
    draw = ImageDraw.Draw(img)
    cam = frame.camera
    for d in found.detections:
        visible = d.visible_box
        boxes = [(visible, VISIBLE_COLOUR)] if visible is not None else []
        if d.result is not None:
            boxes.append((d.result.box, COMPLETED_COLOUR))
        for box, colour in boxes:
            uv = cam.project(box.corners())
            for a, b in _EDGES:
                draw.line([tuple(uv[a]), tuple(uv[b])], fill=colour, width=1)
        rows, cols = np.nonzero(d.mask)
        label_at = (min(max(int(cols.min()) - du, 0), frame.camera.width - 1), max(int(rows.min()) - dv - 12, 0))
        if d.result is not None:
            u, v = cam.project(d.result.centre[None])[0]
            draw.line([(u - 4, v), (u + 4, v)], fill=COMPLETED_COLOUR, width=2)
            draw.line([(u, v - 4), (u, v + 4)], fill=COMPLETED_COLOUR, width=2)
            z = d.result.centre[2] * 1000
            draw.text(label_at, f"{d.id}: {z:.0f} mm" + (" (cut)" if d.extraction.truncated else ""),
                      fill=(255, 255, 255))  # fmt: skip
        else:
            draw.text(label_at, f"{d.id}: failed", fill=(255, 80, 80))
    draw.text((5, cam.height - 14), "orange: visible points   cyan: completed fruit", fill=(255, 255, 255))
    return img


def _outline(labels: np.ndarray) -> np.ndarray:
    """(h, w) bool: the pixels of each labelled region that touch another label or the background."""
    from scipy import ndimage

    fg = labels > 0
    return fg & ((ndimage.grey_erosion(labels, size=3) != labels) | (ndimage.grey_dilation(labels, size=3) != labels))


def draw_label_overlay(color: np.ndarray, labels: np.ndarray, *, alpha: float = 0.45) -> Any:
    """The colour image (a PIL image) with each labelled fruit tinted in its own colour and outlined.

    Parameters
    ----------
    color : (h, w, 3) uint8
    labels : (h, w) int, 0 background
    alpha : float in [0, 1]
        Tint strength.
    """
    from PIL import Image

    color = np.asarray(color)
    labels = instance_labels(labels, "labels", error=FileFormatError)  # before: -1 and 2.5 drawn as what they cast to
    if color.ndim != 3 or color.shape[:2] != labels.shape:
        raise FileFormatError(f"labels are {labels.shape[::-1]}, the image {color.shape[1::-1]}")
    if color.shape[2] not in (3, 4):  # two channels were numpy's broadcast error
        raise FileFormatError(f"the image must be RGB (h, w, 3), got {color.shape[2]} channels")
    if color.dtype != np.uint8 and color.size:  # a float image in [0, 1] was drawn black, 0-1000 clipped, unsaid
        values = color[:, :, :3]
        if color.dtype.kind not in "iuf" or values.min() < 0 or values.max() > 255 or (values % 1).any():
            raise FileFormatError(f"the image must be 8-bit colour (whole numbers 0-255), got {color.dtype}")
    if isinstance(alpha, bool) or not isinstance(alpha, int | float | np.integer | np.floating) or not 0 <= alpha <= 1:
        raise FileFormatError(f"alpha must be a tint strength in [0, 1], got {shown(alpha)}")
    h, w = labels.shape
    out = Image.new("RGB", (w, h))
    rows = max(1, BAND_PIXELS // max(w, 1))
    palette = _PALETTE.astype(np.float32)
    for r0 in range(0, h, rows):  # in bands of rows (one row more each side for the outline): memory stays small
        r1 = min(r0 + rows, h)
        a0, a1 = max(r0 - 1, 0), min(r1 + 1, h)
        lab = labels[r0:r1]
        edge = _outline(labels[a0:a1])[r0 - a0 : r0 - a0 + (r1 - r0)]
        img = color[r0:r1, :, :3].astype(np.float32)
        fg = lab > 0
        tint = palette[(lab[fg].astype(np.int64) - 1) % len(palette)]
        img[fg] = (1 - alpha) * img[fg] + alpha * tint
        img[edge] = palette[(lab[edge].astype(np.int64) - 1) % len(palette)]
        out.paste(Image.fromarray(np.clip(img, 0, 255).astype(np.uint8)), (0, r0))
    return out


#: Largest label id a 16-bit label PNG holds.
MAX_LABEL_PNG_ID = 65535


def write_labels(path: str | Path, labels: np.ndarray) -> Path:
    """Write instance labels as a 16-bit greyscale PNG (0 background, 1..k fruit).

    Raises
    ------
    FileFormatError
        When the labels are not a 2-D image of integers in 0-65535, or ``path`` is not a ``.png``.
    """
    from PIL import Image

    path = Path(path)
    labels = np.asarray(labels)
    if path.suffix.lower() != ".png":
        raise FileFormatError(f"{path}: instance labels are written as .png")
    if labels.ndim != 2 or not np.issubdtype(labels.dtype, np.integer):
        raise FileFormatError(f"{path}: labels must be an (h, w) integer image, got {labels.dtype} {labels.shape}")
    if labels.size == 0:  # Pillow's 'cannot write empty image'
        raise FileFormatError(f"{path}: labels are a {labels.shape[1]}x{labels.shape[0]} image; no PNG is empty")
    if labels.min() < 0 or labels.max() > MAX_LABEL_PNG_ID:
        raise FileFormatError(f"{path}: labels must be 0-{MAX_LABEL_PNG_ID} to fit a 16-bit PNG")
    with atomic_write(path, "wb") as handle:
        Image.fromarray(labels.astype(np.uint16)).save(handle, format="PNG")
    return path


def write_label_overlay(path: str | Path, color: np.ndarray, labels: np.ndarray) -> Path:
    """Write :func:`draw_label_overlay` as a PNG."""
    path = Path(path)
    image = draw_label_overlay(color, labels)
    with atomic_write(path, "wb") as handle:
        image.save(handle, format="PNG", compress_level=FAST_PNG)
    return path


def draw_contact_sheet(entries: Any, *, tile: int = 256, columns: int = 4, threshold: float = 0.5) -> Any:
    """A PIL image of ``(name, color, truth masks, labels)`` tiles: truth outlines green, predicted
    outlines magenta, the name and the image's scores written on each tile."""
    from PIL import Image, ImageDraw
    from scipy import ndimage

    from .evaluate.masks import score_masks, truth_stack

    entries = list(entries)
    if not entries:
        return Image.new("RGB", (tile, tile // 4), (40, 40, 40))
    rows = (len(entries) + columns - 1) // columns
    sheet = Image.new("RGB", (columns * tile, rows * tile), (40, 40, 40))
    for k, (name, color, truth, labels) in enumerate(entries):
        img = np.asarray(color, dtype=np.uint8)[:, :, :3].copy()
        truth = truth_stack(truth, labels.shape)
        edge_t = np.zeros(labels.shape, bool)
        for m in truth:
            edge_t |= m & ~ndimage.binary_erosion(m)
        scale = tile / max(img.shape[:2])
        grow = max(1, int(np.ceil(1.0 / scale)))  # outlines stay visible once the tile is scaled down
        img[ndimage.binary_dilation(edge_t, iterations=grow)] = (0, 230, 0)
        img[ndimage.binary_dilation(_outline(labels), iterations=grow)] = (255, 0, 255)
        s = score_masks(truth, labels, threshold=threshold)
        pic = Image.fromarray(img)
        size = (max(1, round(pic.width * scale)), max(1, round(pic.height * scale)))
        pic = pic.resize(size, Image.Resampling.BILINEAR)
        draw = ImageDraw.Draw(pic)
        iou = f"{s.best_iou.mean():.2f}" if s.n_true else "-"
        text = f"{Path(str(name)).name[:36]}\niou {iou} true {s.n_true} pred {s.n_pred} false {s.false}"
        draw.rectangle([0, 0, pic.width, 24], fill=(0, 0, 0))
        draw.text((2, 1), text, fill=(255, 255, 255))
        sheet.paste(pic, ((k % columns) * tile, (k // columns) * tile))
    return sheet


def write_mask_report(folder: str | Path, evaluation: Any, *, meta: dict[str, Any] | None = None) -> list[Path]:
    """Write a masks evaluation (:class:`symfruit.evaluate.masks.MaskEvaluation`) into ``folder``:
    ``masks.csv`` (one row per image scored), ``summary.json`` (``meta``, the summary and ``failed``: the images
    skipped, name -> reason) and ``worst.png``."""
    import csv
    import io
    import math

    from .evaluate.masks import CSV_COLUMNS

    folder = as_path(folder, "write_mask_report: the output folder")  # '' was the working folder
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise FileFormatError(f"{folder}: cannot create output folder ({exc.strerror or exc})") from None
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(CSV_COLUMNS))
    writer.writeheader()
    for score in evaluation.scores:
        writer.writerow({k: (f"{v:.4f}" if isinstance(v, float) else v) for k, v in score.to_dict().items()})
    with atomic_write(folder / "masks.csv", "w") as handle:
        handle.write(buf.getvalue())
    clean = {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in evaluation.summary.items()}
    failed = dict(getattr(evaluation, "failed", {}))
    write_json(folder / "summary.json", {**(meta or {}), "protocol": "masks", "summary": clean, "failed": failed})
    with atomic_write(folder / "worst.png", "wb") as handle:
        draw_contact_sheet(evaluation.worst).save(handle, format="PNG")
    return [folder / "masks.csv", folder / "summary.json", folder / "worst.png"]
