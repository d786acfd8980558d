"""Fixtures of the ROS tests: Debian's ROS 1 (skipped with the reason, or failed under CI), the example frame
as a camera driver publishes it, and what ``symfruit detect`` finds in it."""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest


def _require_or_skip(why: str) -> None:
    if os.environ.get("SYMFRUIT_REQUIRE_ROS") == "1":
        pytest.fail(why + " (SYMFRUIT_REQUIRE_ROS=1: not skipping)")
    pytest.skip(why)


@pytest.fixture(scope="session")
def ros1() -> Any:
    """Debian's ROS 1 Python packages (rospy, genpy, message types): ``rospy``. Skipped with the reason when
    they are missing, failed instead when SYMFRUIT_REQUIRE_ROS=1 (CI, where `make ros-env` installed them)."""
    try:
        import genpy  # noqa: F401
        import message_filters  # noqa: F401
        import rospy
        import sensor_msgs.msg  # noqa: F401
        import visualization_msgs.msg  # noqa: F401
    except ImportError as exc:
        _require_or_skip(f"ROS 1 is not installed for this interpreter ({exc}); `make ros-env` installs Debian's "
                         "packages and lets the venv see them")  # fmt: skip
    return rospy


@pytest.fixture(scope="session")
def require_ros() -> Callable[[str], None]:
    """``require_ros(why)``: skip, or fail under SYMFRUIT_REQUIRE_ROS=1, for a missing ROS tool."""
    return _require_or_skip


@pytest.fixture(scope="session")
def example_images() -> tuple[np.ndarray, np.ndarray, Any]:
    """The shipped example frame as a camera driver publishes it: RGB uint8, depth uint16 mm, Camera."""
    from symfruit.ros.bench import example_images

    return example_images()


@pytest.fixture(scope="session")
def example_fruits() -> list:
    """``fruits_of(detect(...))`` on the example frame with the CLI's defaults (the default method, the
    strawberry profile)."""
    from symfruit.demo import example_frame
    from symfruit.detect import detect
    from symfruit.io.frames import read_frame
    from symfruit.ros.core import fruits_of
    from symfruit.settings import resolve_settings

    with example_frame() as folder:
        frame = read_frame(folder)
    return fruits_of(detect(frame, settings=resolve_settings(fruit="strawberry")))


@pytest.fixture(scope="session")
def detect_json(tmp_path_factory) -> dict:
    """``detections.json`` of ``symfruit detect`` on the example frame (defaults: the default method, the
    strawberry profile)."""
    from symfruit.cli import main
    from symfruit.demo import example_frame

    out = tmp_path_factory.mktemp("detect")
    with example_frame() as folder:
        assert main(["detect", str(folder), "--output", str(out)]) == 0
    (path,) = out.glob("*/detections.json")
    return json.loads(path.read_text())


@pytest.fixture(scope="session")
def ros2_python() -> str:
    """The interpreter of the ROS 2 venv (`make ros2-env`: rclpy, Fast DDS and vision_msgs built with upstream's
    type hash; SYMFRUIT_ROS2_VENV, default .venv-ros2 beside the sources). Skipped with the reason when it is not
    there, failed instead when SYMFRUIT_REQUIRE_ROS=1 (CI, where `make ros2-env` built it)."""
    from pathlib import Path

    from symfruit.ros.ros2env import DEFAULT_VENV, UPSTREAM_TYPE_HASH, ros2_python, status

    venv = Path(os.environ.get("SYMFRUIT_ROS2_VENV") or Path(__file__).resolve().parents[2] / DEFAULT_VENV)
    built = status(venv).get("hash")
    if not ros2_python(venv).exists() or built != UPSTREAM_TYPE_HASH["vision_msgs/msg/Detection3DArray"]:
        _require_or_skip(f"no ROS 2 venv with vision_msgs at {venv} (built: {built}); `make ros2-env` makes it")
    return str(ros2_python(venv))
