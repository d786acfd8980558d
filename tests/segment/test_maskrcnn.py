"""Mask R-CNN masks (optional extra ``seg``): without torch, a clear message naming the extra; never a download."""

import importlib.util

import numpy as np
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


# --- the glue around torchvision, with stand-ins for torch and torchvision (runs with or without them) ---------


class _Tensor(np.ndarray):
    """The few tensor methods the module uses, on a numpy array."""

    def numpy(self):
        return np.asarray(self)

    def permute(self, *axes):
        return self.transpose(axes)

    def float(self):
        return self.astype(np.float32)


class _Model:
    """A Mask R-CNN stand-in: the state it was given, the images it saw, four detections on a 6x4 image."""

    def __init__(self, **kwargs):
        self.kwargs, self.state, self.seen = kwargs, None, []

    def load_state_dict(self, state):
        if state != {"w": 1}:
            raise RuntimeError("Missing key(s) in state_dict: 'w'")
        self.state = state

    def eval(self):
        return self

    def __call__(self, images):
        self.seen.extend(np.asarray(im) for im in images)
        masks = np.zeros((4, 1, 6, 4), np.float32)
        masks[0, 0, 0:4] = 0.9  # score 0.9, the fruit class
        masks[1, 0, :] = 0.9  # score 0.4: below the threshold
        masks[2, 0, :] = 0.9  # another class
        masks[3, 0, 2:6] = 0.8  # score 0.6, the fruit class, under the first where they overlap
        masks[3, 0, 5] = 0.3  # below the mask threshold 0.5
        out = {"scores": [0.9, 0.4, 0.7, 0.6], "labels": [1, 1, 2, 1], "masks": masks}
        return [{k: np.asarray(v).view(_Tensor) for k, v in out.items()}]


@pytest.fixture
def stand_in_torch(monkeypatch):
    """``torch`` and ``torchvision`` stand-ins in sys.modules; returns the list of models built."""
    import json
    import sys
    import types
    from contextlib import nullcontext

    from symfruit.segment.maskrcnn import load_maskrcnn

    built: list[_Model] = []

    def load(path, *, map_location, weights_only):
        assert weights_only is True and map_location == "cpu"  # no pickled code runs
        return json.loads(path.read_text())

    torch = types.ModuleType("torch")
    torch.load, torch.no_grad = load, nullcontext
    torch.from_numpy = lambda a: a.view(_Tensor)
    vision = types.ModuleType("torchvision")
    vision.models = types.SimpleNamespace(detection=types.SimpleNamespace(
        maskrcnn_resnet50_fpn=lambda **kw: built.append(_Model(**kw)) or built[-1]))  # fmt: skip
    monkeypatch.setitem(sys.modules, "torch", torch)
    monkeypatch.setitem(sys.modules, "torchvision", vision)
    load_maskrcnn.cache_clear()
    yield built
    load_maskrcnn.cache_clear()


@pytest.mark.parametrize("saved", [{"w": 1}, {"model": {"w": 1}}, {"state_dict": {"w": 1}}])
def test_a_checkpoint_is_loaded_into_a_model_built_without_downloads(stand_in_torch, tmp_path, saved):
    import json

    from symfruit.segment.maskrcnn import load_maskrcnn

    path = tmp_path / "model.pth"
    path.write_text(json.dumps(saved))
    model = load_maskrcnn(str(path), num_classes=3)
    assert model.state == {"w": 1}
    assert model.kwargs == {"weights": None, "weights_backbone": None, "num_classes": 3}  # nothing downloaded
    assert load_maskrcnn(str(path), num_classes=3) is model and len(stand_in_torch) == 1  # loaded once


def test_a_checkpoint_that_does_not_load_or_fit_is_named(stand_in_torch, tmp_path):
    from symfruit.segment.maskrcnn import load_maskrcnn

    with pytest.raises(FileFormatError, match=r"nothing\.pth: no such Mask R-CNN checkpoint"):
        load_maskrcnn(str(tmp_path / "nothing.pth"))
    (tmp_path / "bad.pth").write_text("not a checkpoint")
    with pytest.raises(FileFormatError, match=r"bad\.pth: cannot load checkpoint \(Expecting value"):
        load_maskrcnn(str(tmp_path / "bad.pth"))
    (tmp_path / "other.pth").write_text('{"model": {"v": 2}}')
    with pytest.raises(FileFormatError, match=r"other\.pth: checkpoint does not fit maskrcnn_resnet50_fpn \(Missing"):
        load_maskrcnn(str(tmp_path / "other.pth"))


def test_labels_keep_the_fruit_class_above_the_score_higher_scores_on_top(stand_in_torch, tmp_path):
    from symfruit.segment.maskrcnn import maskrcnn_labels

    (tmp_path / "m.pth").write_text('{"w": 1}')
    color = np.full((6, 4, 3), 255, np.uint8)
    color[0, 0] = (0, 51, 102)
    labels = maskrcnn_labels(color, str(tmp_path / "m.pth"))
    (seen,) = stand_in_torch[0].seen
    assert seen.shape == (3, 6, 4) and seen.dtype == np.float32  # channels first, scaled to [0, 1]
    np.testing.assert_allclose(seen[:, 0, 0], [0.0, 0.2, 0.4])
    assert seen.max() == 1.0
    # the kept detections 0 (score 0.9, label 1) and 3 (0.6, label 2), the better drawn over the other where they
    # overlap (rows 2-3); 1 is below the score, 2 of another class, row 5 below the mask threshold
    np.testing.assert_array_equal(labels[:, 0], [1, 1, 1, 1, 2, 0])
    assert labels.dtype == np.int32 and labels.shape == (6, 4)
    only_best = maskrcnn_labels(color, str(tmp_path / "m.pth"), score=0.8)
    np.testing.assert_array_equal(only_best[:, 0], [1, 1, 1, 1, 0, 0])
