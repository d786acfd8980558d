"""One parser for mask specs: ``--masks`` of ``symfruit detect`` and ``symfruit segment``, the ROS nodes'
``masks`` parameter, :func:`symfruit.detect.detect` and :func:`symfruit.batch.segment_images`.

A spec is ``"auto"`` (a frame's own masks file if it has one, else the colour segmenter), ``"color"`` (the
built-in colour segmenter, :func:`symfruit.segment.colour.segment`), ``"maskrcnn:CHECKPOINT"`` (a
torchvision Mask R-CNN, extra ``seg``), ``"onnx:MODEL"`` (an ONNX instance-segmentation export, extra
``onnx``), or files:

* for a frame: a label PNG or COCO JSON holding that frame's masks, or a frame folder with ``masks.png`` /
  ``masks.json`` (:func:`symfruit.io.masks.read_masks`, read for every frame); a COCO JSON of several images
  (one file for a recording's frames) gives each frame the image whose file name, or whose folder, is the
  frame's name (``frame_0007.png`` or ``frame_0007/color.png`` for the frame folder ``frame_0007``), read once
  and refused for a frame it holds no image of, never another frame's masks; a folder without masks files of
  its own holds each frame's as ``<frame>.png`` or ``<frame>/masks.png`` (or ``.json``);
* for a set of image files (``images`` given): a COCO JSON (each image's annotations, by file name), a
  folder of label PNGs (``<stem>.png``), or one label PNG for one image; ``auto`` is a frame's word only.
  Files are checked here, before any image.

A learned model fails here, once, when its extra is missing or the model cannot be read.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import FileFormatError, InputError
from ..io.text import holds_file
from ..settings import Settings

__all__ = ["COLOUR_SEGMENTER", "MaskSource", "mask_source"]

#: The word a :class:`MaskSource` gives for the colour segmenter's labels (``color``, or ``auto`` without a masks
#: file): masks grown from the fruit's own colour, never drawn over what lies in front of it (``detect`` skips
#: extraction's test for an occluder drawn over, stop 47).
COLOUR_SEGMENTER = "colour segmenter"

#: ``(color, depth, camera, name, own, color_file) -> (labels, word)``: see :class:`MaskSource`.
Labeller = Callable[[np.ndarray, Any, Any, str, Any, Any], tuple[np.ndarray, str]]


@dataclass(frozen=True)
class MaskSource:
    """Instance labels for images, from one spec (:func:`mask_source`).

    Attributes
    ----------
    name : str
        A word on where the labels come from, as outputs record it (``colour segmenter``, a path, the spec).
    """

    name: str
    _labeller: Labeller

    def __call__(self, color: np.ndarray, depth: np.ndarray | None = None, camera: Any = None, *, name: str = "",
                 own: np.ndarray | None = None,
                 color_file: tuple[str | Path, int] | None = None) -> tuple[np.ndarray, str]:  # fmt: skip
        """Labels for one image and the word on where they came from (``frame masks file`` for a frame's own).

        Parameters
        ----------
        color : (h, w, 3) uint8, RGB
        depth : (h, w) float, metres, optional
        camera : Camera-like, optional
            Needed with ``depth`` by the colour segmenter's depth rules.
        name : str
            The image's file name or path (a COCO JSON's images are found by it; a folder's label PNGs by its stem).
        own : (h, w) int, optional
            The frame's own masks (``auto``).
        color_file : (path, int), optional
            The colour image's file and the EXIF orientation applied to it on reading; a label PNG read for
            it must carry the same (None: not checked).

        Returns
        -------
        labels : (h, w) int array (not yet checked)
        word : str
        """
        return self._labeller(color, depth, camera, name, own, color_file)


def mask_source(spec: str | Path, *, settings: Settings | None = None,
                images: Sequence[Path] | None = None) -> MaskSource:  # fmt: skip
    """The :class:`MaskSource` a spec names (see the module); ``images``: the image files a set of images is
    segmented from (None: frames)."""
    from .colour import learned_masks, segment

    settings = settings or Settings()
    text = str(spec)
    if not text.strip():  # Path("") is the working folder: never taken for a folder of label PNGs unsaid
        raise InputError("--masks '': expected color, maskrcnn:CHECKPOINT, onnx:MODEL, a COCO .json, a folder of "
                         "label PNGs, or one label .png")  # fmt: skip
    colour = COLOUR_SEGMENTER

    def by_colour(color: np.ndarray, depth: Any, camera: Any, name: str, own: Any, cf: Any) -> tuple[np.ndarray, str]:
        return segment(color, depth, camera, settings.segment), colour

    if images is None and text == "auto":

        def auto(color: np.ndarray, depth: Any, camera: Any, name: str, own: Any, cf: Any) -> tuple[np.ndarray, str]:
            return (own, "frame masks file") if own is not None else by_colour(color, depth, camera, name, own, cf)

        return MaskSource("auto", auto)
    if text == "color":
        return MaskSource(colour, by_colour)
    learned = learned_masks(text)  # a missing extra or a bad model fails once, here
    if learned is not None:
        model = learned
        return MaskSource(text, lambda color, depth, camera, name, own, cf: (model(color), text))
    if images is None:
        from ..io.masks import read_masks

        path = Path(text)  # a file or folder read for every frame: checked once, here, not failed by each frame
        if not os.path.exists(path):  # False for a name too long for the system too (pathlib: OSError)
            raise InputError(f"--masks {text!r}: no such file or folder (expected auto, color, maskrcnn:CHECKPOINT, "
                             "onnx:MODEL, a COCO .json, a folder of frames' masks, or one label .png)")  # fmt: skip
        if not path.is_dir() and path.suffix.lower() not in (".png", ".json"):
            raise FileFormatError(f"{path}: masks must be a label .png or a COCO .json")
        several = _coco_of_several_images(Path(text)) or _frames_folder(Path(text))
        if several is not None:
            return several
        return MaskSource(
            text, lambda color, depth, camera, name, own, cf: (read_masks(spec, color.shape[:2], color=cf), text)
        )
    return _image_files(text, images)


def _coco_of_several_images(path: Path) -> MaskSource | None:
    """For frames: a COCO JSON whose ``images`` list names more than one image, as a source that finds each
    frame's image by the frame's name (None for any other file: one image, or annotations without images)."""
    if path.suffix.lower() != ".json" or not path.is_file():
        return None
    from ..core.limits import MAX_COCO_BYTES
    from ..io.masks import coco_from_data
    from ..io.text import read_structured

    try:
        data = read_structured(path, what="COCO annotation file", max_bytes=MAX_COCO_BYTES)
    except FileFormatError:
        return None  # read_masks says what is wrong with it, for the first frame
    if not (isinstance(data, dict) and isinstance(data.get("images"), list) and len(data["images"]) > 1):
        return None
    coco = coco_from_data(path, data)
    by_frame: dict[str, list[str]] = {}
    for entry in coco.entries():
        file_name = str(entry["file_name"]).replace("\\", "/")
        stem, folder = Path(file_name).stem, Path(file_name).parent.name
        for key in {stem, folder} - {""}:
            by_frame.setdefault(key, []).append(entry["file_name"])

    def from_coco(color: np.ndarray, depth: Any, camera: Any, name: str, own: Any, cf: Any) -> tuple[np.ndarray, str]:
        found = by_frame.get(_frame_key(name), []) if name else []
        if len(found) != 1:
            some = ", ".join(repr(e["file_name"]) for e in coco.entries()[:3])
            why = "no image" if not found else f"{len(found)} images ({', '.join(map(repr, found[:3]))})"
            raise FileFormatError(f"{path}: {why} for frame {name!r} among its {len(coco.entries())} images (an "
                                  "image's file name or folder is matched to the frame's name; they are "
                                  f"{some}, ...)")  # fmt: skip
        return _coco_labels(coco, found[0], color.shape[:2]), str(path)

    return MaskSource(str(path), from_coco)


def _frame_key(name: str) -> str:
    """What a frame's masks are found by: its whole name (a frame folder ``day.1`` is not ``day``: its masks are
    ``day.1.png``, never ``day.png``), an image file's name without its extension (``capture_1.png``)."""
    path = Path(name)
    return path.stem if path.suffix.lower() in (".png", ".jpg", ".jpeg") else path.name


def _coco_labels(coco: Any, name: str, shape: tuple[int, int]) -> np.ndarray:
    """One image's annotations of a :class:`~symfruit.io.masks.CocoSet` (every category) as instance labels, later
    annotations over earlier ones."""
    labels = np.zeros(shape, np.int32)
    for k, m in enumerate(coco.instances(name, shape, category=None), 1):
        labels[m] = k
    return labels


def _frames_folder(folder: Path) -> MaskSource | None:
    """For frames: a folder without ``masks.png`` / ``masks.json`` of its own, holding each frame's masks as
    ``<frame>.png`` or ``<frame>/masks.png`` / ``masks.json`` (None for anything else)."""
    if not folder.is_dir() or (folder / "masks.png").is_file() or (folder / "masks.json").is_file():
        return None
    from ..io.masks import read_masks

    def per_frame(color: np.ndarray, depth: Any, camera: Any, name: str, own: Any, cf: Any) -> tuple[np.ndarray, str]:
        stem = _frame_key(name)
        # a link that loops or leads nowhere, or a folder, under a mask's name is refused by it (holds_file), never
        # read as no masks for the frame (robust53)
        given = [p for p in (folder / f"{stem}.png", folder / stem / "masks.png", folder / stem / "masks.json")
                 if stem and holds_file(p)]  # fmt: skip
        if len(given) > 1:  # two mask files that may disagree: taking one in silence would not be the one meant
            raise FileFormatError(f"{folder}: holds both {given[0]} and {given[1]} for frame {name!r}; which one is "
                                  "meant? Keep one")  # fmt: skip
        if given:
            return read_masks(given[0], color.shape[:2], color=cf), str(given[0])
        raise FileFormatError(f"{folder}: no masks for frame {name!r} ({stem}.png, or {stem}/masks.png or "
                              f"{stem}/masks.json)")  # fmt: skip

    return MaskSource(str(folder), per_frame)


def _image_files(text: str, images: Sequence[Path]) -> MaskSource:
    """Masks of a set of image files from files: a COCO JSON, a folder of label PNGs, one label PNG."""
    source = Path(text)
    where = str(source)
    if source.suffix.lower() == ".json":
        from ..io.masks import read_coco

        coco = read_coco(source)

        def from_coco(
            color: np.ndarray, depth: Any, camera: Any, name: str, own: Any, cf: Any
        ) -> tuple[np.ndarray, str]:
            return _coco_labels(coco, name, color.shape[:2]), where

        return MaskSource(where, from_coco)
    if source.is_dir():

        def from_folder(
            color: np.ndarray, depth: Any, camera: Any, name: str, own: Any, cf: Any
        ) -> tuple[np.ndarray, str]:
            label_path = source / f"{Path(name).stem}.png"
            if not label_path.is_file():
                raise FileFormatError(f"{label_path}: no label image for {name}")
            from ..io.masks import read_label_png

            return _sized(read_label_png(label_path, color=cf), color, label_path), where

        return MaskSource(where, from_folder)
    if source.suffix.lower() == ".png" and source.is_file() and len(images) == 1:
        from ..io.masks import read_label_png

        def one_png(color: np.ndarray, depth: Any, camera: Any, name: str, own: Any, cf: Any) -> tuple[np.ndarray, str]:
            return _sized(read_label_png(source, color=cf), color, source), where

        return MaskSource(where, one_png)
    raise InputError(f"--masks {text!r}: expected color, maskrcnn:CHECKPOINT, onnx:MODEL, a COCO .json, "
                     "a folder of label PNGs, or one label .png for one image")  # fmt: skip


def _sized(labels: np.ndarray, color: np.ndarray, path: Path) -> np.ndarray:
    """A label PNG's labels, refused naming the file when they are not the size of the image they are for."""
    if labels.shape != color.shape[:2]:
        raise FileFormatError(f"{path}: labels are {labels.shape[1]}x{labels.shape[0]}, the image "
                              f"{color.shape[1]}x{color.shape[0]}")  # fmt: skip
    return labels
