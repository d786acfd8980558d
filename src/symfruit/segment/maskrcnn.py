"""Instance masks from a torchvision Mask R-CNN the user trained (optional extra ``seg``).

No weights are ever downloaded: the model is built with no pretrained weights and the user's
checkpoint is loaded with ``torch.load(..., weights_only=True)`` (no pickled code runs).
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from ..errors import FileFormatError, SymfruitError

__all__ = ["load_maskrcnn", "maskrcnn_labels"]


@functools.lru_cache(maxsize=2)
def load_maskrcnn(checkpoint: str, num_classes: int = 2):
    """Build ``maskrcnn_resnet50_fpn`` without downloads and load ``checkpoint`` (a state dict, or a
    dict holding one under ``"model"`` or ``"state_dict"``)."""
    try:
        import torch
        import torchvision
    except ImportError:
        raise SymfruitError("Mask R-CNN masks need torch and torchvision: pip install 'symfruit[seg]'") from None
    path = Path(checkpoint)
    if not path.is_file():
        raise FileFormatError(f"{path}: no such Mask R-CNN checkpoint")
    model = torchvision.models.detection.maskrcnn_resnet50_fpn(
        weights=None, weights_backbone=None, num_classes=num_classes
    )
    try:
        state = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:  # torch raises several unpickling/format errors
        raise FileFormatError(f"{path}: cannot load checkpoint ({exc})") from None
    for key in ("model", "state_dict"):
        if isinstance(state, dict) and key in state and isinstance(state[key], dict):
            state = state[key]
    try:
        model.load_state_dict(state)
    except (RuntimeError, TypeError) as exc:
        raise FileFormatError(f"{path}: checkpoint does not fit maskrcnn_resnet50_fpn ({exc})") from None
    return model.eval()


def maskrcnn_labels(color: np.ndarray, checkpoint: str, *, score: float = 0.5, fruit_class: int = 1) -> np.ndarray:
    """Instance labels (0 background) of the detections of ``fruit_class`` scoring at least ``score``."""
    model = load_maskrcnn(checkpoint)  # first: it says which extra to install when torch is missing
    import torch

    with torch.no_grad():
        out = model([torch.from_numpy(np.ascontiguousarray(color)).permute(2, 0, 1).float() / 255.0])[0]
    keep = (out["scores"] >= score) & (out["labels"] == fruit_class)
    masks = (out["masks"][keep, 0] > 0.5).numpy()
    labels = np.zeros(color.shape[:2], np.int32)
    for k in np.argsort(out["scores"][keep].numpy()):  # higher scores drawn last, on top
        labels[masks[k]] = k + 1
    return labels
