"""Instance masks from an ONNX instance-segmentation model the user exported (optional extra ``onnx``).

Nothing is downloaded: the user's ``.onnx`` file runs on the CPU through onnxruntime. Two export layouts
are decoded, told apart by the model's outputs:

``maskrcnn``
    A torchvision Mask R-CNN exported with ``torch.onnx.export``: input ``(3, H, W)`` (or ``(1, 3, H, W)``)
    float RGB in [0, 1] at the image's own size; outputs ``boxes (N, 4)``, ``labels (N,)``, ``scores (N,)``
    and ``masks (N, 1, H, W)`` (probabilities). Kept: ``scores >= score`` of class ``fruit_class``
    (default 1: class 0 is the background), mask probability above one half.
``yolo``
    A YOLO-style segmentation head (as Ultralytics' ``-seg`` models export): input ``(1, 3, S, S)`` float
    RGB in [0, 1], the image letterboxed into it (scaled to fit, centred, grey padding); outputs
    ``(1, 4 + nc + nm, A)`` (per anchor: box centre x, y, width, height in input pixels, ``nc`` class
    scores, ``nm`` mask coefficients) and ``(1, nm, mh, mw)`` mask prototypes. Kept: class score
    ``>= score`` (of ``fruit_class``, default any class), non-maximum suppression at box IoU ``iou``;
    each mask is ``sigmoid(coefficients @ prototypes)`` inside its box, taken back to the image.

Later (higher scoring) instances are drawn over earlier ones in the labels, as for Mask R-CNN.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import FileFormatError, InputError, SymfruitError

__all__ = ["OnnxModel", "decode_maskrcnn", "decode_yolo", "letterbox", "load_onnx", "onnx_labels"]

#: Largest model file read (bytes): instance-segmentation models are tens to a few hundred MB.
MAX_MODEL_BYTES = 2 << 30


@dataclass(frozen=True)
class OnnxModel:
    """A loaded model: the onnxruntime session, its layout (``"maskrcnn"`` or ``"yolo"``), its input's
    name and rank, and (``yolo``) the square input side."""

    session: Any
    layout: str
    input_name: str
    input_rank: int
    size: int = 0


@functools.lru_cache(maxsize=2)
def load_onnx(model: str) -> OnnxModel:
    """Open ``model`` with onnxruntime (CPU) and tell its layout from its outputs.

    Raises
    ------
    SymfruitError
        When onnxruntime is not installed (``pip install 'symfruit[onnx]'``).
    FileFormatError
        When the file is missing, too large, not a model, or of neither layout.
    """
    try:
        import onnxruntime
    except ImportError:
        raise SymfruitError("ONNX masks need onnxruntime: pip install 'symfruit[onnx]'") from None
    path = Path(model)
    if not path.is_file():
        raise FileFormatError(f"{path}: no such ONNX model")
    if path.stat().st_size > MAX_MODEL_BYTES:
        raise FileFormatError(f"{path}: larger than {MAX_MODEL_BYTES >> 20} MB; not an instance-segmentation model")
    try:
        session = onnxruntime.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    except Exception as exc:  # onnxruntime raises its own exception types for bad files
        raise FileFormatError(f"{path}: cannot load ONNX model ({exc})") from None
    inputs, outputs = session.get_inputs(), session.get_outputs()
    if len(inputs) != 1:
        raise FileFormatError(f"{path}: expected one image input, the model has {len(inputs)}")
    rank = len(inputs[0].shape)
    ranks = [len(o.shape) for o in outputs]
    if len(outputs) == 4 and sorted(ranks) == [1, 1, 2, 4] and rank in (3, 4):
        return OnnxModel(session, "maskrcnn", inputs[0].name, rank)
    if len(outputs) == 2 and sorted(ranks) == [3, 4] and rank == 4:
        side = inputs[0].shape[2]
        if not isinstance(side, int) or side <= 0 or inputs[0].shape[3] != side:
            raise FileFormatError(f"{path}: a YOLO-style model needs a fixed square input, got {inputs[0].shape}")
        return OnnxModel(session, "yolo", inputs[0].name, rank, side)
    raise FileFormatError(
        f"{path}: outputs of ranks {ranks} are neither a Mask R-CNN export (boxes, labels, scores, masks) "
        "nor a YOLO-style segmentation head (predictions, prototypes)"
    )


def onnx_labels(
    color: np.ndarray,
    model: str,
    *,
    score: float = 0.5,
    fruit_class: int | None = None,
    iou: float = 0.5,
) -> np.ndarray:
    """Instance labels ``(h, w) int32`` (0 background) of the model's fruit detections on one image.

    Parameters
    ----------
    color : (h, w, 3) uint8
    model : path of the ``.onnx`` file
    score : float
        Least detection score kept.
    fruit_class : int, optional
        Class kept: default 1 for a Mask R-CNN export (0 is its background), any class for YOLO.
    iou : float
        YOLO: box IoU above which a lower-scoring detection is suppressed.
    """
    color = np.asarray(color)
    if color.ndim != 3 or color.shape[2] != 3 or color.dtype != np.uint8:
        raise InputError(f"color must be an (h, w, 3) uint8 image, got {color.dtype} {color.shape}")
    m = load_onnx(str(model))
    h, w = color.shape[:2]
    if m.layout == "maskrcnn":
        x = np.ascontiguousarray(color.transpose(2, 0, 1), dtype=np.float32) / 255.0
        names = [o.name.lower() for o in m.session.get_outputs()]
        outs = [np.asarray(v) for v in m.session.run(None, {m.input_name: x[None] if m.input_rank == 4 else x})]
        masks = next(v for v in outs if v.ndim == 4)
        flat = [(n, v) for n, v in zip(names, outs, strict=True) if v.ndim == 1]
        named = {("label" if "label" in n else "score" if "score" in n else ""): v for n, v in flat}
        if set(named) != {"label", "score"}:  # unnamed outputs: the labels are the integer ones
            flat.sort(key=lambda nv: not np.issubdtype(nv[1].dtype, np.integer))
            named = {"label": flat[0][1], "score": flat[1][1]}
        return decode_maskrcnn(named["score"], named["label"], masks, (h, w), score=score,
                               fruit_class=1 if fruit_class is None else fruit_class)  # fmt: skip
    x, box = letterbox(color, m.size)
    preds, protos = sorted((np.asarray(v) for v in m.session.run(None, {m.input_name: x[None]})), key=np.ndim)
    return decode_yolo(preds, protos, box, (h, w), m.size, score=score, fruit_class=fruit_class, iou=iou)


def decode_maskrcnn(
    scores: np.ndarray,
    labels: np.ndarray,
    masks: np.ndarray,
    shape: tuple[int, int],
    *,
    score: float = 0.5,
    fruit_class: int = 1,
) -> np.ndarray:
    """Instance labels from Mask R-CNN outputs: ``scores (N,)``, ``labels (N,)``, ``masks (N, 1, h, w)``."""
    scores, labels, masks = np.asarray(scores, np.float64), np.asarray(labels), np.asarray(masks)
    if masks.ndim != 4 or masks.shape[1] != 1 or masks.shape[2:] != tuple(shape) or len(scores) != len(masks):
        raise InputError(f"Mask R-CNN outputs do not fit the image {shape}: masks {masks.shape}, scores {scores.shape}")
    keep = np.flatnonzero((scores >= score) & (labels == fruit_class))
    out = np.zeros(shape, np.int32)
    for k in keep[np.argsort(scores[keep], kind="stable")]:  # higher scores drawn last, on top
        out[masks[k, 0] > 0.5] = int(k) + 1
    return _compact(out)


def letterbox(color: np.ndarray, size: int) -> tuple[np.ndarray, tuple[int, int, int, int]]:
    """The image scaled to fit a ``size`` square, centred on grey (114): ``(3, size, size)`` float32 in [0, 1],
    and where the image lies in it ``(top, left, height, width)``."""
    from PIL import Image

    h, w = color.shape[:2]
    scale = size / max(h, w)
    nh, nw = max(1, round(h * scale)), max(1, round(w * scale))
    top, left = (size - nh) // 2, (size - nw) // 2
    canvas = np.full((size, size, 3), 114, np.uint8)
    canvas[top : top + nh, left : left + nw] = np.asarray(
        Image.fromarray(color).resize((nw, nh), Image.Resampling.BILINEAR)
    )
    return np.ascontiguousarray(canvas.transpose(2, 0, 1), dtype=np.float32) / 255.0, (top, left, nh, nw)


def decode_yolo(
    preds: np.ndarray,
    protos: np.ndarray,
    box: tuple[int, int, int, int],
    shape: tuple[int, int],
    size: int,
    *,
    score: float = 0.5,
    fruit_class: int | None = None,
    iou: float = 0.5,
) -> np.ndarray:
    """Instance labels from a YOLO-style segmentation head (see the module docstring).

    Parameters
    ----------
    preds : (1, 4 + nc + nm, A) float
    protos : (1, nm, mh, mw) float
    box : (top, left, height, width)
        Where the image lies in the square model input (:func:`letterbox`).
    shape : (h, w)
        The image's size.
    size : int
        The square model input's side (pixels).
    """
    from PIL import Image

    preds, protos = np.asarray(preds, np.float64), np.asarray(protos, np.float32)
    if preds.ndim != 3 or protos.ndim != 4 or preds.shape[0] != 1 or protos.shape[0] != 1:
        raise InputError(f"YOLO outputs must be (1, C, A) and (1, nm, mh, mw), got {preds.shape}, {protos.shape}")
    nm, mh, mw = protos.shape[1:]
    p = preds[0].T  # (A, 4 + nc + nm)
    nc = p.shape[1] - 4 - nm
    if nc < 1:
        raise InputError(f"YOLO predictions have {p.shape[1]} values per anchor, fewer than 4 + 1 + {nm}")
    cls = p[:, 4 : 4 + nc]
    if fruit_class is None:
        best, conf = np.argmax(cls, axis=1), cls.max(axis=1)
    else:
        if not 0 <= fruit_class < nc:
            raise InputError(f"fruit_class {fruit_class} is not one of the model's {nc} classes")
        best, conf = np.full(len(p), fruit_class), cls[:, fruit_class]
    candidates = np.flatnonzero(conf >= score)
    xyxy = np.c_[p[:, 0] - p[:, 2] / 2, p[:, 1] - p[:, 3] / 2, p[:, 0] + p[:, 2] / 2, p[:, 1] + p[:, 3] / 2]
    keep = candidates[_nms(xyxy[candidates], conf[candidates], best[candidates], iou)]
    out = np.zeros(shape, np.int32)
    if len(keep) == 0:
        return out
    keep = keep[np.argsort(conf[keep], kind="stable")]  # higher scores drawn last, on top
    logits = p[keep, 4 + nc :] @ protos[0].reshape(nm, -1)
    masks = (1.0 / (1.0 + np.exp(-np.clip(logits, -50, 50)))).reshape(-1, mh, mw).astype(np.float32)
    top, left, nh, nw = box
    h, w = shape
    region = (left * mw / size, top * mh / size, (left + nw) * mw / size, (top + nh) * mh / size)
    scale = nw / w  # model-input pixels per image pixel (the same both ways, up to rounding)
    for rank, (k, m) in enumerate(zip(keep, masks, strict=True), 1):
        full = np.asarray(Image.fromarray(m, mode="F").resize((w, h), Image.Resampling.BILINEAR, box=region))
        x0, y0, x1, y1 = ((xyxy[k] - [left, top, left, top]) / scale).tolist()
        r0, r1 = int(np.clip(np.floor(y0), 0, h)), int(np.clip(np.ceil(y1), 0, h))
        c0, c1 = int(np.clip(np.floor(x0), 0, w)), int(np.clip(np.ceil(x1), 0, w))
        inside = np.zeros(shape, bool)
        inside[r0:r1, c0:c1] = True
        out[(full > 0.5) & inside] = rank
    return _compact(out)


def _nms(boxes: np.ndarray, conf: np.ndarray, cls: np.ndarray, iou: float) -> np.ndarray:
    """Indices of the boxes kept by class-wise greedy non-maximum suppression."""
    order = np.argsort(-conf, kind="stable")
    kept: list[int] = []
    area = np.clip(boxes[:, 2] - boxes[:, 0], 0, None) * np.clip(boxes[:, 3] - boxes[:, 1], 0, None)
    suppressed = np.zeros(len(boxes), bool)
    for i in order:  # one pass per detection kept (a handful), vectorised over the others
        if suppressed[i]:
            continue
        kept.append(int(i))
        xx0, yy0 = np.maximum(boxes[i, 0], boxes[:, 0]), np.maximum(boxes[i, 1], boxes[:, 1])
        xx1, yy1 = np.minimum(boxes[i, 2], boxes[:, 2]), np.minimum(boxes[i, 3], boxes[:, 3])
        inter = np.clip(xx1 - xx0, 0, None) * np.clip(yy1 - yy0, 0, None)
        overlap = inter / np.maximum(area[i] + area - inter, 1e-12)
        suppressed |= (overlap > iou) & (cls == cls[i])
    return np.array(kept, dtype=np.int64)


def _compact(labels: np.ndarray) -> np.ndarray:
    """Labels renumbered 1..k in order of first appearance of their values (0 stays 0)."""
    values = np.unique(labels[labels > 0])
    lut = np.zeros(int(labels.max()) + 1 if labels.size else 1, np.int32)
    lut[values] = np.arange(1, len(values) + 1)
    return lut[labels]
