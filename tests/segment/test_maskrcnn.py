"""Mask R-CNN masks (optional extra ``seg``): without torch, a clear message naming the extra; never a download."""

import importlib.util

import pytest

from symfruit import FileFormatError, SymfruitError
from symfruit.detect import detect, frame_masks

HAS_TORCH = importlib.util.find_spec("torch") is not None and importlib.util.find_spec("torchvision") is not None


def test_maskrcnn_without_torch_says_which_extra():
    import importlib.util

    if importlib.util.find_spec("torch") is not None:
        pytest.skip("torch is installed")
    from symfruit import SymfruitError
    from symfruit.segment.maskrcnn import load_maskrcnn

    with pytest.raises(SymfruitError, match=r"symfruit\[seg\]"):
        load_maskrcnn("model.pth")


@pytest.mark.skipif(HAS_TORCH, reason="torch is installed")
def test_detect_with_maskrcnn_masks_without_torch_says_which_extra(example):
    with pytest.raises(SymfruitError, match=r"pip install 'symfruit\[seg\]'"):
        frame_masks(example, "maskrcnn:weights.pth")
    with pytest.raises(SymfruitError, match="torch and torchvision"):
        detect(example, masks="maskrcnn:weights.pth")


@pytest.mark.skipif(not HAS_TORCH, reason="needs torch and torchvision")
def test_a_missing_checkpoint_is_named(tmp_path):
    from symfruit.segment.maskrcnn import load_maskrcnn

    with pytest.raises(FileFormatError, match=r"nothing\.pth: no such Mask R-CNN checkpoint"):
        load_maskrcnn(str(tmp_path / "nothing.pth"))
