"""ONNX instance-segmentation decoding (symfruit.segment.onnx) on tiny models built here: a Mask R-CNN-like
export and a YOLO-like segmentation head, through `symfruit segment` too."""

import importlib.util

import numpy as np
import pytest

from symfruit import FileFormatError, SymfruitError
from symfruit.segment.onnx import decode_yolo, letterbox, load_onnx, onnx_labels

#: onnx is imported by the tests that build a model, not at collection (it takes half a second to import); the
#: module's tests run in one xdist worker, so only that one imports it.
pytestmark = [
    pytest.mark.skipif(not all(importlib.util.find_spec(m) for m in ("onnx", "onnxruntime")),
                       reason="needs onnx and onnxruntime (the extra onnx)"),
    pytest.mark.xdist_group("onnx"),
]  # fmt: skip


def _save(graph, path):
    import onnx
    from onnx import helper

    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 13)])
    model.ir_version = 7
    onnx.checker.check_model(model)
    onnx.save(model, str(path))
    return str(path)


def _const(name, array):
    from onnx import helper, numpy_helper

    return helper.make_node("Constant", [], [name], value=numpy_helper.from_array(np.asarray(array), name + "_v"))


def maskrcnn_model(path):
    """Input (3, H, W); instance 1 = where red > 0.5 (score 0.9, class 1), instance 2 = where green > 0.5
    (score 0.3, class 1), instance 3 = the whole image (score 0.95, class 2: not fruit)."""
    from onnx import TensorProto, helper

    nodes = [
        _const("zero", np.array(0.0, np.float32)), _const("one", np.array(1.0, np.float32)),
        _const("starts", np.array([0], np.int64)), _const("ends", np.array([2], np.int64)),
        _const("axes", np.array([0], np.int64)), _const("ax0", np.array([1], np.int64)),
        helper.make_node("Slice", ["image", "starts", "ends", "axes"], ["rg"]),  # (2, H, W)
        helper.make_node("Unsqueeze", ["rg", "ax0"], ["rg4"]),  # (2, 1, H, W)
        helper.make_node("Slice", ["image", "starts", "ax0", "axes"], ["r"]),  # (1, H, W)
        helper.make_node("Mul", ["r", "zero"], ["r0"]),
        helper.make_node("Add", ["r0", "one"], ["all"]),
        helper.make_node("Unsqueeze", ["all", "ax0"], ["all4"]),
        helper.make_node("Concat", ["rg4", "all4"], ["masks"], axis=0),  # (3, 1, H, W)
        _const("boxes", np.zeros((3, 4), np.float32)),
        _const("labels", np.array([1, 1, 2], np.int64)),
        _const("scores", np.array([0.9, 0.3, 0.95], np.float32)),
    ]  # fmt: skip
    graph = helper.make_graph(
        nodes, "maskrcnn", [helper.make_tensor_value_info("image", TensorProto.FLOAT, [3, "H", "W"])],
        [helper.make_tensor_value_info("boxes", TensorProto.FLOAT, [3, 4]),
         helper.make_tensor_value_info("labels", TensorProto.INT64, [3]),
         helper.make_tensor_value_info("scores", TensorProto.FLOAT, [3]),
         helper.make_tensor_value_info("masks", TensorProto.FLOAT, [3, 1, "H", "W"])],
    )  # fmt: skip
    return _save(graph, path)


S, MH = 64, 16


def yolo_model(path):
    """Input (1, 3, 64, 64); prototypes: 0 = left half of the input, 1 = right half; anchors: a box over the
    left half (score 0.9, class 0), a near duplicate of it (0.8: suppressed), a box over the right half
    (0.7, class 1), one below the threshold (0.2)."""
    from onnx import TensorProto, helper

    protos = np.full((1, 2, MH, MH), -10.0, np.float32)
    protos[0, 0, :, : MH // 2] = 10.0
    protos[0, 1, :, MH // 2 :] = 10.0
    anchors = [  # cx, cy, w, h, class 0, class 1, coefficient 0, coefficient 1
        [16, 32, 32, 64, 0.9, 0.0, 1, 0], [17, 32, 32, 62, 0.8, 0.0, 1, 0],
        [48, 32, 32, 64, 0.0, 0.7, 0, 1], [48, 32, 10, 10, 0.2, 0.0, 0, 1],
    ]  # fmt: skip
    preds = np.asarray(anchors, np.float32).T[None]  # (1, 8, 4)
    nodes = [
        _const("p", preds), _const("q", protos), _const("zero", np.array(0.0, np.float32)),
        helper.make_node("ReduceSum", ["images"], ["total"], keepdims=0),
        helper.make_node("Mul", ["total", "zero"], ["nothing"]),
        helper.make_node("Add", ["p", "nothing"], ["output0"]),
        helper.make_node("Add", ["q", "nothing"], ["output1"]),
    ]  # fmt: skip
    graph = helper.make_graph(
        nodes, "yolo", [helper.make_tensor_value_info("images", TensorProto.FLOAT, [1, 3, S, S])],
        [helper.make_tensor_value_info("output0", TensorProto.FLOAT, [1, 8, 4]),
         helper.make_tensor_value_info("output1", TensorProto.FLOAT, [1, 2, MH, MH])],
    )  # fmt: skip
    return _save(graph, path)


def test_maskrcnn_export_decoding(tmp_path):
    model = maskrcnn_model(tmp_path / "m.onnx")
    assert load_onnx(model).layout == "maskrcnn"
    color = np.zeros((30, 40, 3), np.uint8)
    color[5:15, 5:20, 0] = 255  # instance 1
    color[20:28, 25:35, 1] = 255  # instance 2, scored 0.3
    labels = onnx_labels(color, model)
    assert labels.dtype == np.int32 and labels.max() == 1  # below the score and other classes left out
    assert np.array_equal(labels > 0, color[:, :, 0] > 127)
    both = onnx_labels(color, model, score=0.2)
    assert both.max() == 2 and both[24, 30] > 0 and both[10, 10] != both[24, 30]
    assert onnx_labels(color, model, fruit_class=2).min() == 1  # the whole-image instance of class 2


def test_yolo_head_decoding_with_letterbox_and_nms(tmp_path):
    model = yolo_model(tmp_path / "y.onnx")
    m = load_onnx(model)
    assert (m.layout, m.size) == ("yolo", S)
    color = np.zeros((64, 64, 3), np.uint8)
    labels = onnx_labels(color, model)
    assert labels.max() == 2  # the duplicate suppressed, the weak anchor dropped
    assert (labels[:, :30] == labels[0, 0]).all() and (labels[:, 34:] == labels[0, 63]).all()
    assert labels[0, 0] != labels[0, 63] and labels[0, 63] == 1  # the higher score is drawn last: number 2
    assert onnx_labels(color, model, fruit_class=1).max() == 1
    wide = np.zeros((32, 64, 3), np.uint8)  # letterboxed into rows 16-48 of the input
    x, box = letterbox(wide, S)
    assert x.shape == (3, S, S) and box == (16, 0, 32, 64) and np.isclose(x[0, 0, 0], 114 / 255)
    labels = onnx_labels(wide, model)
    assert labels.shape == (32, 64) and labels.max() == 2 and labels[:, :30].min() > 0


def test_yolo_decoder_known_answer_without_a_model():
    protos = np.zeros((1, 1, 4, 4), np.float32)
    protos[0, 0, 1:3, 1:3] = 20.0
    preds = np.array([[8.0], [8.0], [16.0], [16.0], [0.9], [1.0]])[None]  # one anchor, whole 16-px input
    labels = decode_yolo(preds, protos, (0, 0, 16, 16), (16, 16), 16)
    assert labels[4:12, 4:12].all() and not labels[:2].any()


def test_bad_models_and_the_missing_extra(tmp_path, monkeypatch):
    with pytest.raises(FileFormatError, match="no such ONNX model"):
        load_onnx(str(tmp_path / "none.onnx"))
    (tmp_path / "junk.onnx").write_bytes(b"not a model")
    with pytest.raises(FileFormatError, match="cannot load"):
        load_onnx(str(tmp_path / "junk.onnx"))
    import builtins

    real_import = builtins.__import__

    def no_onnxruntime(name, *args, **kwargs):
        if name == "onnxruntime":
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    load_onnx.cache_clear()
    monkeypatch.setattr(builtins, "__import__", no_onnxruntime)
    with pytest.raises(SymfruitError, match=r"symfruit\[onnx\]"):
        load_onnx(str(tmp_path / "other.onnx"))


def test_onnx_masks_through_segment(tmp_path, capsys):
    from PIL import Image

    from symfruit.cli import main

    model = maskrcnn_model(tmp_path / "m.onnx")
    color = np.zeros((30, 40, 3), np.uint8)
    color[5:15, 5:20, 0] = 255
    (tmp_path / "in").mkdir()
    Image.fromarray(color).save(tmp_path / "in" / "a.png")
    assert main(["segment", str(tmp_path / "in"), "--output", str(tmp_path / "out"), "--masks", f"onnx:{model}"]) == 0
    assert "a.png: 1 fruit" in capsys.readouterr().out
    with Image.open(tmp_path / "out" / "a.png") as img:
        assert np.array_equal(np.asarray(img) > 0, color[:, :, 0] > 0)
