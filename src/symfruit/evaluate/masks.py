"""Mask quality: how well a segmenter finds every fruit, whole (``symfruit evaluate --protocol masks``).

Per image, each true fruit is scored by its *best-match IoU* (the highest mask IoU of any predicted
region, 0 when none overlaps), and true and predicted regions are matched one to one at IoU >= 0.5
(the assignment that maximises the summed IoU of the matched pairs): a matched true fruit is *found*,
an unmatched one *missed*, an unmatched prediction *false*. The summary gives the mean best-match IoU
over all true fruit, the matched share of true fruit and the false share of the predictions.

Truth comes from a COCO file (polygons or RLE, one category kept; :func:`evaluate_masks`) or from the
instance labels of rendered scenes (:func:`evaluate_scene_masks`). :func:`symfruit.writers.write_mask_report`
writes the per-image CSV, the summary JSON and a contact sheet of the worst images.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..core.limits import MAX_INSTANCES, instance_labels, shown, unmasked
from ..errors import FileFormatError, InputError, OutputError, SymfruitError

__all__ = [
    "CSV_COLUMNS",
    "ImageScore",
    "MaskEvaluation",
    "Skipped",
    "coco_items",
    "evaluate_mask_items",
    "evaluate_masks",
    "evaluate_scene_masks",
    "mask_ious",
    "match_masks",
    "score_masks",
    "summarise_masks",
]

#: Columns of the per-image CSV.
CSV_COLUMNS = ("image", "n_true", "n_pred", "matched", "missed", "false", "mean_best_iou", "min_best_iou", "ms")

#: A segmenter as the protocol calls it: ``segment(color, **extra) -> (h, w) int labels``.
Segmenter = Callable[..., np.ndarray]
#: One evaluation item: ``(name, color, truth)`` or ``(name, color, truth, extra keyword arguments)``.
#: A fifth element ``(crowd mask, crowd count)`` gives the image's crowd regions (:func:`score_masks` ``ignore``).
Item = (
    tuple[str, np.ndarray, np.ndarray]
    | tuple[str, np.ndarray, np.ndarray, dict[str, Any]]
    | tuple[str, np.ndarray, np.ndarray, dict[str, Any], tuple[np.ndarray, int]]
)


@dataclass(frozen=True)
class Skipped:
    """An item that could not be made (its photograph unreadable or missing, its COCO entry failing): it is
    reported by name with the reason, and the evaluation goes on with the others."""

    name: str
    reason: str


def truth_stack(truth: np.ndarray, shape: tuple[int, int] | None = None) -> np.ndarray:
    """``(n, h, w)`` bool true masks from masks or from ``(h, w)`` instance labels (0 = none).

    Integer masks hold 0 and one other value each (1 or 255: a mask image); a mask of several values (a label
    image put in the stack) or of negative ones is refused, as are labels that :func:`instance_labels` refuses
    (negative, beyond 32 bits, more than :data:`MAX_INSTANCES` fruit). A masked entry of a
    :class:`numpy.ma.MaskedArray` is background.
    """
    t = unmasked(truth, 0)
    if t.dtype != bool and not np.issubdtype(t.dtype, np.integer):  # 0.5 or NaN would count as fruit in silence
        raise InputError(f"truth must be bool masks or integer labels, got {t.dtype}")
    if t.ndim == 2:  # -1 was background in silence; 10^6 ids made an (ids, h, w) stack of terabytes
        t = instance_labels(t, "truth")
        ids = np.unique(t[t > 0])
        t = t[None] == ids[:, None, None]
    if t.ndim != 3:
        raise InputError(f"truth must be (n, h, w) masks or (h, w) labels, got shape {t.shape}")
    if len(t) > MAX_INSTANCES:
        raise InputError(f"truth holds {len(t)} masks; at most {MAX_INSTANCES} fruit per image are read")
    if t.dtype != bool and t.size:  # before: any non-zero was fruit (-1, or label 2 of a label image in the stack)
        top = t.reshape(len(t), -1).max(axis=1)
        bad = (t.reshape(len(t), -1).min(axis=1) < 0) | ((t != 0) & (t != top[:, None, None])).any(axis=(1, 2))
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            held = np.unique(t[k])
            raise InputError(f"truth mask {k} holds the values {shown(held.tolist())}: an integer mask is 0 and one "
                             "value (1 or 255); labels are one (h, w) image, not a stack")  # fmt: skip
    if shape is not None and t.shape[1:] != tuple(shape):
        raise InputError(f"truth masks are {t.shape[2]}x{t.shape[1]}, the labels {shape[1]}x{shape[0]}")
    return t.astype(bool, copy=False)


def mask_ious(truth: np.ndarray, labels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """IoU of every true mask with every predicted region.

    Parameters
    ----------
    truth : (n, h, w) bool, or (h, w) int instance labels (0 = none)
        True fruit masks; they may overlap.
    labels : (h, w) int
        Predicted instance labels, 0 background.

    Returns
    -------
    ious : (n, k) float
        IoU of true mask ``i`` with predicted region ``ids[j]``.
    ids : (k,) int
        The predicted labels present, ascending.

    Examples
    --------
    >>> truth = np.zeros((1, 4, 4), bool); truth[0, :2] = True
    >>> labels = np.zeros((4, 4), np.int32); labels[:1] = 3
    >>> mask_ious(truth, labels)
    (array([[0.5]]), array([3]))
    """
    labels = np.asarray(labels)
    if labels.ndim != 2 or not np.issubdtype(labels.dtype, np.integer):
        raise InputError(f"labels must be an (h, w) integer image, got {labels.dtype} {labels.shape}")
    if labels.size and labels.min() < 0:
        raise InputError("labels must not be negative")
    instance_labels(labels, "labels")  # at most MAX_INSTANCES regions: the (n, k) IoU table stays small
    truth = truth_stack(truth, labels.shape)
    ids, inverse = np.unique(labels, return_inverse=True)
    inverse = inverse.reshape(labels.shape)
    keep = ids > 0
    k_all = len(ids)
    pred_area = np.bincount(inverse.ravel(), minlength=k_all)
    n = len(truth)
    inter = np.zeros((n, k_all), np.int64)
    for i in range(n):  # one bincount per true fruit (a handful per image)
        inter[i] = np.bincount(inverse[truth[i]], minlength=k_all)
    true_area = truth.reshape(n, labels.size).sum(axis=1)
    union = true_area[:, None] + pred_area[None, :] - inter
    ious = np.where(union > 0, inter / np.maximum(union, 1), 0.0)
    return ious[:, keep], ids[keep].astype(np.int64)


def match_masks(ious: np.ndarray, *, threshold: float = 0.5) -> np.ndarray:
    """One-to-one matching of true and predicted regions at IoU >= ``threshold``.

    The assignment maximises the summed IoU over pairs that reach the threshold (Hungarian).

    Parameters
    ----------
    ious : (n, k) float
    threshold : float in (0, 1]

    Returns
    -------
    (m, 2) int: rows ``(true index, predicted index)``.
    """
    from scipy.optimize import linear_sum_assignment

    try:
        ious = np.asarray(ious, dtype=np.float64)
    except (TypeError, ValueError):  # numpy's 'could not convert string to float'
        raise InputError(f"ious must be an (n, k) array of IoUs in [0, 1], got {shown(ious)}") from None
    if ious.ndim != 2:
        raise InputError(f"ious must be (n, k), got shape {ious.shape}")
    if ious.size and not (ious.min() >= 0.0 and ious.max() <= 1.0):  # NaN never matched, 1.5 matched, unsaid
        raise InputError(f"ious must be IoUs in [0, 1], got values from {ious.min()} to {ious.max()}")
    if isinstance(threshold, bool) or not isinstance(threshold, (int, float, np.integer, np.floating)):
        raise InputError(f"threshold must be a number in (0, 1], got {shown(threshold)}")
    if not 0 < threshold <= 1:  # NaN fails this too
        raise InputError(f"threshold must be in (0, 1], got {threshold}")
    if ious.size == 0:
        return np.zeros((0, 2), np.int64)
    gain = np.where(ious >= threshold, ious, 0.0)
    rows, cols = linear_sum_assignment(gain, maximize=True)
    good = gain[rows, cols] > 0
    return np.stack([rows[good], cols[good]], axis=1).astype(np.int64)


@dataclass(frozen=True)
class ImageScore:
    """The mask scores of one image.

    Attributes
    ----------
    image : str
    best_iou : (n,) float
        Best-match IoU of each true fruit.
    n_pred, matched : int
        Predicted regions, and true fruit matched one to one at the threshold.
    ms : float
        Segmentation time, milliseconds (NaN when not timed).
    """

    image: str
    best_iou: np.ndarray
    n_pred: int
    matched: int
    ms: float = float("nan")
    #: Crowd regions of the image (COCO ``iscrowd``: no fruit to find), and predictions lying in them, which
    #: count neither as matched nor as false (left out of ``n_pred``), as COCO's evaluation does.
    crowd: int = 0
    ignored: int = 0

    @property
    def n_true(self) -> int:
        return len(self.best_iou)

    @property
    def missed(self) -> int:
        return self.n_true - self.matched

    @property
    def false(self) -> int:
        return self.n_pred - self.matched

    def badness(self) -> float:
        """How bad the image is, for picking the worst: lost IoU plus one per false region."""
        return float(np.sum(1.0 - self.best_iou) + self.false)

    def to_dict(self) -> dict[str, Any]:
        b = self.best_iou
        return {
            "image": self.image, "n_true": self.n_true, "n_pred": self.n_pred, "matched": self.matched,
            "missed": self.missed, "false": self.false,
            "mean_best_iou": float(b.mean()) if len(b) else float("nan"),
            "min_best_iou": float(b.min()) if len(b) else float("nan"), "ms": self.ms,
        }  # fmt: skip


def score_masks(
    truth: np.ndarray,
    labels: np.ndarray,
    *,
    threshold: float = 0.5,
    image: str = "",
    ms: float = float("nan"),
    ignore: np.ndarray | None = None,
    crowd: int = 0,
) -> ImageScore:
    """Score one image's predicted labels against its true masks.

    Parameters
    ----------
    truth : (n, h, w) bool or (h, w) int labels
    labels : (h, w) int, 0 background
    threshold : float
        IoU a match needs.
    ignore : (h, w) bool, optional
        Crowd regions (``crowd`` of them): an unmatched prediction with at least ``threshold`` of its area
        in them is ignored, neither matched nor false (COCO's rule for ``iscrowd`` annotations).
    """
    if not isinstance(image, str):  # an image's name, written into the report's tables as text
        raise InputError(f"image must be the image's name (text), got {shown(image)}")
    if isinstance(ms, bool) or not isinstance(ms, int | float | np.integer | np.floating) or ms < 0:
        raise InputError(f"ms must be milliseconds >= 0 (or NaN: not timed), got {shown(ms)}")  # 'x' a ValueError
    if isinstance(crowd, bool) or not isinstance(crowd, int | np.integer) or crowd < 0:
        raise InputError(f"crowd must be a count of crowd regions >= 0, got {shown(crowd)}")  # -1 summed as is
    if ignore is not None:
        ignore = np.asarray(ignore)
        if ignore.dtype != bool and not (np.issubdtype(ignore.dtype, np.integer) and np.isin(ignore, (0, 1)).all()):
            raise InputError(f"ignore must be a bool (h, w) mask of crowd regions, got {ignore.dtype}")  # 0.5: crowd
    ious, ids = mask_ious(truth, labels)
    best = ious.max(axis=1) if ious.shape[1] else np.zeros(ious.shape[0])
    pairs = match_masks(ious, threshold=threshold)
    ignored = 0
    if ignore is not None and len(ids):
        ignore = np.asarray(ignore, dtype=bool)
        if ignore.shape != np.shape(labels):
            raise InputError(f"crowd regions are {ignore.shape[::-1]}, the labels {np.shape(labels)[::-1]}")
        values, inverse = np.unique(np.asarray(labels), return_inverse=True)
        area = np.bincount(inverse.ravel(), minlength=len(values))
        inside = np.bincount(inverse.ravel()[ignore.ravel()], minlength=len(values))
        share = inside[values > 0] / np.maximum(area[values > 0], 1)
        unmatched = np.ones(len(ids), bool)
        unmatched[pairs[:, 1]] = False
        ignored = int(np.count_nonzero(unmatched & (share >= threshold)))
    return ImageScore(image, best, int(ious.shape[1]) - ignored, len(pairs), float(ms), int(crowd), ignored)


def summarise_masks(scores: Sequence[ImageScore], skipped: int = 0) -> dict[str, Any]:
    """Totals over images: mean best-match IoU over true fruit, matched / missed / false, shares, time;
    ``skipped``: how many images could not be scored (not in the totals)."""
    best = np.concatenate([s.best_iou for s in scores]) if scores else np.zeros(0)
    n_true = int(sum(s.n_true for s in scores))
    n_pred = int(sum(s.n_pred for s in scores))
    matched = int(sum(s.matched for s in scores))
    ms = np.array([s.ms for s in scores], dtype=np.float64)
    ms = ms[np.isfinite(ms)]
    return {
        "images": len(scores),
        "skipped_images": int(skipped),
        "true_fruit": n_true,
        "detections": n_pred,
        "matched": matched,
        "missed": n_true - matched,
        "false": n_pred - matched,
        "mean_best_iou": float(best.mean()) if len(best) else None,
        "median_best_iou": float(np.median(best)) if len(best) else None,
        "matched_share": matched / n_true if n_true else None,
        "false_share": (n_pred - matched) / n_pred if n_pred else 0.0,
        "images_with_false": int(sum(s.false > 0 for s in scores)),
        "crowd_regions": int(sum(s.crowd for s in scores)),
        "ignored_in_crowd": int(sum(s.ignored for s in scores)),
        "ms_median": float(np.median(ms)) if len(ms) else None,
        "ms_p90": float(np.percentile(ms, 90)) if len(ms) else None,
    }


@dataclass(frozen=True)
class MaskEvaluation:
    """What the masks protocol returns: per-image scores, the summary, the worst images kept for
    the contact sheet as ``(name, color, truth masks, labels)``, and the images skipped (name -> reason)."""

    scores: list[ImageScore]
    summary: dict[str, Any]
    worst: list[tuple[str, np.ndarray, np.ndarray, np.ndarray]] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)


def evaluate_mask_items(
    items: Iterable[Item | Skipped], segment: Segmenter, *, threshold: float = 0.5, keep_worst: int = 12
) -> MaskEvaluation:
    """Run ``segment(color, **extra) -> labels`` on each ``(name, color, truth[, extra])`` and score it.

    An image that cannot be scored (a :class:`Skipped` item, or ``segment`` or the scoring raising a
    :class:`~symfruit.errors.SymfruitError`, e.g. a label file that is not the photograph's) is recorded in
    ``failed`` with the reason and left out of the totals; the others are scored.

    Parameters
    ----------
    items : iterable of (str, (h, w, 3) uint8, (n, h, w) bool or (h, w) int[, dict]) or Skipped
        The optional dict holds keyword arguments for ``segment`` (e.g. ``depth`` and ``camera``).
    segment : callable
        Colour image to instance labels; timed per image (the segmentation alone, no file reading).
    threshold : float
    keep_worst : int
        How many of the worst images to keep (with their pixels) for the contact sheet.
    """
    scores: list[ImageScore] = []
    failed: dict[str, str] = {}
    worst: list[tuple[float, int, tuple[str, np.ndarray, np.ndarray, np.ndarray]]] = []
    for k, item in enumerate(items):
        if isinstance(item, Skipped):
            failed[item.name] = item.reason
            continue
        name, color, truth = item[0], item[1], item[2]
        extra: dict[str, Any] = item[3] if len(item) > 3 else {}
        ignore, crowd = item[4] if len(item) > 4 else (None, 0)
        try:
            t0 = time.perf_counter()
            labels = np.asarray(segment(color, **extra))
            ms = (time.perf_counter() - t0) * 1000.0
            truth = truth_stack(truth, labels.shape)
            score = score_masks(truth, labels, threshold=threshold, image=name, ms=ms, ignore=ignore, crowd=crowd)
        except OutputError:
            raise
        except SymfruitError as exc:
            failed[name] = str(exc)
            continue
        scores.append(score)
        if keep_worst > 0:
            worst.append((score.badness(), k, (name, color, truth, labels)))
            worst.sort(key=lambda w: (-w[0], w[1]))
            del worst[keep_worst:]
    kept = [w[2] for w in worst if w[0] > 0]
    return MaskEvaluation(scores, summarise_masks(scores, len(failed)), kept, failed)


def coco_items(
    images: str | Path,
    truth: str | Path,
    *,
    category: int | None = 1,
    names: Sequence[str] | None = None,
    files: bool = False,
) -> Iterator[Item | Skipped]:
    """``(file name, colour, true masks, {}, (crowd mask, crowd count))`` for every image of a COCO file found
    in ``images``, by name; a :class:`Skipped` (name and reason) for one that cannot be read, is missing from
    the folder, or whose COCO entry or annotations fail (the file as a whole is checked first). Crowd regions
    (``iscrowd: 1``) are no true fruit; predictions in them are ignored.
    With ``files``, the keyword arguments are ``name`` (the file name) and ``color_file`` (the image's path and
    the EXIF orientation applied to it on reading), which a :class:`~symfruit.segment.MaskSource` reading label
    files needs: to find an image's labels, and to refuse a label PNG that turns otherwise than the photograph.

    Raises
    ------
    FileFormatError
        When ``images`` is not a folder, the COCO file cannot be read, or no image is left to evaluate.
    InputError
        When no annotation has ``category``.
    """
    from ..io.masks import read_coco

    folder = Path(images)
    if not folder.is_dir():
        raise FileFormatError(f"{folder}: not a folder of images")
    coco = read_coco(truth)
    coco.check_category(category)  # a category no annotation has would score every image as fruitless
    entries = coco.entries()
    if names is not None:
        wanted = {Path(n).name for n in names}
        entries = [e for e in entries if Path(str(e["file_name"])).name in wanted]
    if not entries:
        raise FileFormatError(f"{coco.path}: no images to evaluate")
    for entry in entries:
        name = str(entry["file_name"])
        try:
            item = _coco_item(folder, coco, name, category, files)
        except OutputError:
            raise
        except SymfruitError as exc:  # this photograph alone: reported by name, the others scored
            yield Skipped(name, str(exc))
            continue
        yield item


def _coco_item(folder: Path, coco: Any, name: str, category: int | None, files: bool) -> Item:
    """One photograph of :func:`coco_items`: read, its truth and crowd regions drawn."""
    from ..io.images import read_color_oriented

    # inside the folder only: an absolute name or one climbing out ("../../x.png") is looked up by its base name
    inside = not Path(name).is_absolute() and ".." not in Path(name).parts
    path = folder / name if inside else folder / Path(name).name
    if not path.is_file():
        path = folder / Path(name).name
    if not path.is_file():
        said = "" if name == path.name else f" as {name!r}"  # the name once (it was three times: 350 characters)
        raise FileFormatError(f"{folder / Path(name).name if not inside else folder / name}: listed in "
                              f"{coco.path.name}{said}, but there is no such file")  # fmt: skip
    color, orientation = read_color_oriented(path)
    crowd = coco.crowd(name, color.shape[:2], category=category)
    extra = {"name": name, "color_file": (path, orientation)} if files else {}
    return name, color, coco.instances(name, color.shape[:2], category=category), extra, crowd


def evaluate_masks(
    images: str | Path,
    truth: str | Path,
    segment: Segmenter,
    *,
    category: int | None = 1,
    threshold: float = 0.5,
    keep_worst: int = 12,
    names: Sequence[str] | None = None,
    files: bool = False,
) -> MaskEvaluation:
    """The masks protocol on a folder of photographs with COCO truth.

    Parameters
    ----------
    images : folder
        The photographs; every image of the COCO file is evaluated (images in the folder without an
        entry are left out). An image listed but missing from the folder or unreadable, one whose COCO entry
        or annotations fail, or one ``segment`` refuses (a label file not the photograph's) is skipped and
        named in ``failed`` with the reason; when none can be scored, that is an error.
    truth : COCO JSON path
    segment : callable ``(h, w, 3) uint8 -> (h, w) int labels``
    category : int or None
        The COCO category of the fruit (annotations of other categories are ignored: a region predicted
        on them is false); ``None`` takes every annotation as fruit.
    names : sequence of str, optional
        Evaluate only these file names (e.g. one half of a split).
    files : bool
        Call ``segment(color, name=..., color_file=...)`` (:func:`coco_items`): for a mask source of label files.
    """
    items = coco_items(images, truth, category=category, names=names, files=files)
    ev = evaluate_mask_items(items, segment, threshold=threshold, keep_worst=keep_worst)
    if not ev.scores and ev.failed:
        first, reason = next(iter(ev.failed.items()))
        n = len(ev.failed)
        which = f"none of the {n} images" if n > 1 else "the one image"
        more = f" (and {n - 1} more)" if n > 1 else ""
        raise FileFormatError(f"{images}: {which} of {Path(truth).name} could be scored; {first}: {reason}{more}")
    return ev


def evaluate_scene_masks(
    seeds: Sequence[int],
    segment: Segmenter,
    *,
    threshold: float = 0.5,
    keep_worst: int = 12,
    depth: bool = True,
    scene: str = "strawberry",
    **scene_options: Any,
) -> MaskEvaluation:
    """The masks protocol on rendered scenes: truth is the ripe fruit's visible pixels; a region on an
    unripe fruit counts as false.

    ``scene`` is ``"strawberry"`` (:func:`symfruit.synthetic.scenes.make_scene`, table-top strawberries) or
    ``"apple-tree"`` (:func:`symfruit.synthetic.scenes.make_tree_scene`: an apple tree's canopy at 1.2-2 m
    through the Azure Kinect model, 1920x1080, apples 40-70 px across). With ``depth`` (default),
    ``segment(color, depth=..., camera=...)`` is given the scene's depth and camera; without,
    ``segment(color)`` sees the colour alone.
    """
    from ..synthetic.scenes import make_scene, make_tree_scene

    if scene not in ("strawberry", "apple-tree"):
        raise InputError(f"scene must be 'strawberry' or 'apple-tree', got {scene!r}")
    make = make_scene if scene == "strawberry" else make_tree_scene

    def items() -> Iterator[Item]:
        for seed in seeds:
            frame = make(int(seed), **scene_options)
            ripe = np.array([f.id for f in frame.fruits if f.ripe], dtype=np.int32)
            truth = frame.labels[None] == ripe[:, None, None]
            truth = truth[truth.reshape(len(ripe), -1).any(axis=1)]  # fruit hidden entirely are not truth
            extra = {"depth": frame.depth, "camera": frame.camera} if depth else {}
            yield f"scene-{seed}", frame.color, truth, extra

    return evaluate_mask_items(items(), segment, threshold=threshold, keep_worst=keep_worst)
