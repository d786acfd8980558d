"""symfruit.ros.ros1_msgs: vision_msgs classes generated from the shipped upstream noetic definitions."""

from __future__ import annotations

import io
import sys
import types

import pytest

from symfruit import SymfruitError
from symfruit.ros import ros1_msgs


def test_md5sums_and_definitions_are_upstream_noetic(ros1):
    vm = ros1_msgs.load_vision_msgs()
    for full, md5 in ros1_msgs.UPSTREAM_MD5.items():
        cls = getattr(vm, full.split("/")[1])
        assert (cls._type, cls._md5sum) == (full, md5)
    assert ros1_msgs.load_vision_msgs() is vm  # generated once per process
    text = vm.Detection3DArray._full_text
    assert text.startswith("# A list of 3D detections") and "MSG: vision_msgs/ObjectHypothesisWithPose" in text
    assert ros1_msgs.definition("Detection3DArray").startswith("# A list of 3D detections")


def test_generated_classes_round_trip(ros1):
    from geometry_msgs.msg import Point
    from std_msgs.msg import Header

    vm = ros1_msgs.load_vision_msgs()
    det = vm.Detection3D(header=Header(stamp=ros1.Time(12, 345), frame_id="cam"),
                         results=[vm.ObjectHypothesisWithPose(id=3, score=0.8)])  # fmt: skip
    det.bbox.center.position = Point(0.01, -0.02, 0.3)
    msg = vm.Detection3DArray(header=det.header, detections=[det])
    buf = io.BytesIO()
    msg.serialize(buf)
    back = vm.Detection3DArray().deserialize(buf.getvalue())
    assert back.header.stamp == ros1.Time(12, 345) and back.detections[0].results[0].id == 3
    assert back.detections[0].bbox.center.position.y == -0.02 and back.detections[0].results[0].score == 0.8


def test_missing_genpy_names_the_packages(monkeypatch):
    monkeypatch.setattr(ros1_msgs, "_cache", None)
    for name in ("vision_msgs", "vision_msgs.msg", "genpy", "genpy.generator", "genmsg", "genmsg.msg_loader"):
        monkeypatch.setitem(sys.modules, name, None)
    with pytest.raises(SymfruitError, match="python3-genpy"):
        ros1_msgs.load_vision_msgs()


def test_an_installed_vision_msgs_with_other_md5sums_is_refused(monkeypatch):
    fake = types.ModuleType("vision_msgs.msg")
    fake.__file__ = "/opt/ros/other/vision_msgs/msg/__init__.py"
    for name in ("ObjectHypothesisWithPose", "BoundingBox3D", "Detection3D", "Detection3DArray"):
        setattr(fake, name, type(name, (), {"_md5sum": "0" * 32}))
    package = types.ModuleType("vision_msgs")
    package.msg = fake  # type: ignore[attr-defined]
    monkeypatch.setattr(ros1_msgs, "_cache", None)
    monkeypatch.setitem(sys.modules, "vision_msgs", package)
    monkeypatch.setitem(sys.modules, "vision_msgs.msg", fake)
    with pytest.raises(SymfruitError, match="upstream noetic has"):
        ros1_msgs.load_vision_msgs()
