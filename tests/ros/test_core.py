"""symfruit.ros.core: messages in (decoded by symfruit.io.bags), fruit out, the latest-only worker. No ROS needed."""

from __future__ import annotations

import threading
from types import SimpleNamespace

import numpy as np
import pytest

from symfruit import SymfruitError
from symfruit.errors import InputError
from symfruit.ros.core import FrameProcessor, LatestOnly, checked_parameters, fruits_of, message_frame


def header(secs: int = 7, nsecs: int = 5, frame_id: str = "cam") -> SimpleNamespace:
    return SimpleNamespace(stamp=SimpleNamespace(secs=secs, nsecs=nsecs), frame_id=frame_id)


def image_msg(array: np.ndarray, encoding: str, *, pad: int = 0, bigendian: bool = False) -> SimpleNamespace:
    """A duck-typed sensor_msgs/Image of ``array`` (h, w[, c]) with ``pad`` bytes at the end of every row."""
    a = np.ascontiguousarray(array)
    if bigendian:
        a = a.astype(a.dtype.newbyteorder(">"))
    h, w = a.shape[:2]
    rows = a.reshape(h, -1).view(np.uint8)
    rows = np.hstack([rows, np.full((h, pad), 7, np.uint8)])
    return SimpleNamespace(height=h, width=w, encoding=encoding, is_bigendian=int(bigendian), step=rows.shape[1],
                           data=rows.tobytes(), header=header())  # fmt: skip


def info_msg(fx=615.0, fy=615.0, cx=320.0, cy=240.0, width=640, height=480, key="K", d=None) -> SimpleNamespace:
    extra = {} if d is None else {"D" if key == "K" else "d": d}
    return SimpleNamespace(width=width, height=height, header=header(),
                           **{key: [fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0]}, **extra)  # fmt: skip


def example_messages(images, color_encoding="rgb8", depth_encoding="16UC1"):
    rgb, raw, cam = images
    color = {"rgb8": rgb, "bgr8": rgb[:, :, ::-1]}[color_encoding]
    depth = raw if depth_encoding == "16UC1" else raw.astype(np.float32) * np.float32(0.001)
    info = info_msg(cam.fx, cam.fy, cam.cx, cam.cy, cam.width, cam.height)
    return image_msg(color, color_encoding), image_msg(depth, depth_encoding), info


def frame_of(color, depth=None, info=None):
    h, w = color.height, color.width
    depth = depth or image_msg(np.full((h, w), 500, np.uint16), "16UC1")
    return message_frame(color, depth, info or info_msg(width=w, height=h, cx=w / 2, cy=h / 2))


@pytest.mark.parametrize("encoding", ["rgb8", "bgr8", "rgba8", "bgra8"])
@pytest.mark.parametrize("pad", [0, 3])
def test_colour_encodings(encoding, pad):
    rng = np.random.default_rng(1)
    rgb = rng.integers(0, 256, (5, 7, 3), dtype=np.uint8)
    order = {"rgb8": [0, 1, 2], "bgr8": [2, 1, 0], "rgba8": [0, 1, 2], "bgra8": [2, 1, 0]}[encoding]
    img = rgb[:, :, order]
    if encoding.endswith("a8"):
        img = np.dstack([img, np.full((5, 7), 255, np.uint8)])
    frame = frame_of(image_msg(img, encoding, pad=pad))
    assert frame.color.dtype == np.uint8 and frame.color.shape == (5, 7, 3) and np.array_equal(frame.color, rgb)


def test_mono8_is_grey_rgb():
    grey = np.arange(12, dtype=np.uint8).reshape(3, 4)
    frame = frame_of(image_msg(grey, "mono8", pad=2))
    assert frame.color.shape == (3, 4, 3) and all(np.array_equal(frame.color[:, :, c], grey) for c in range(3))


@pytest.mark.parametrize("bigendian", [False, True])
def test_depth_16uc1_millimetres(bigendian):
    mm = np.array([[0, 1000], [65535, 250]], np.uint16)
    frame = frame_of(image_msg(np.zeros((2, 2, 3), np.uint8), "rgb8"), image_msg(mm, "16UC1", pad=1,
                     bigendian=bigendian))  # fmt: skip
    assert frame.depth.dtype == np.float32
    assert np.array_equal(frame.depth, mm.astype(np.float32) * np.float32(0.001))


def test_depth_32fc1_metres_invalid_to_zero():
    m = np.array([[0.5, np.nan], [np.inf, 0.25]], np.float32)
    frame = frame_of(image_msg(np.zeros((2, 2, 3), np.uint8), "rgb8"), image_msg(m, "32FC1"))
    assert np.array_equal(frame.depth, np.array([[0.5, 0.0], [0.0, 0.25]], np.float32))


def test_frame_carries_the_colour_header():
    color = image_msg(np.zeros((2, 2, 3), np.uint8), "rgb8")
    color.header = header(12, 345, "camera_color_optical_frame")
    frame = frame_of(color)
    assert frame.stamp == 12_000_000_345 and frame.frame_id == "camera_color_optical_frame"


@pytest.mark.parametrize(
    ("change", "match"),
    [({"encoding": "yuv420"}, "encoding"), ({"data": b"\x00" * 10}, "image data holds 10 bytes"),
     ({"step": 2}, "step"), ({"height": 0}, "empty")],
)  # fmt: skip
def test_bad_images_raise_symfruit_errors(change, match):
    msg = image_msg(np.zeros((4, 4, 3), np.uint8), "rgb8")
    for k, v in change.items():
        setattr(msg, k, v)
    with pytest.raises(SymfruitError, match=match):
        frame_of(msg, image_msg(np.ones((4, 4), np.uint16), "16UC1"), info_msg(width=4, height=4, cx=2, cy=2))


def test_an_error_names_the_message_it_is_about():
    color, depth = image_msg(np.zeros((4, 4, 3), np.uint8), "rgb8"), image_msg(np.ones((4, 4), np.uint16), "16UC1")
    info = info_msg(width=4, height=4, cx=2, cy=2)
    for spoilt, what in ((color, "colour image"), (depth, "depth image")):  # one fault, either image
        data, spoilt.data = spoilt.data, b"\x00" * 10
        with pytest.raises(SymfruitError, match=rf"^{what}: image data holds 10 bytes"):  # before: which image?
            frame_of(color, depth, info)
        spoilt.data = data
    with pytest.raises(InputError, match=r"^CameraInfo: camera focal lengths must be positive"):
        frame_of(color, depth, info_msg(fx=0.0, width=4, height=4))


def test_depth_rejects_colour_encodings():
    color = image_msg(np.zeros((2, 2, 3), np.uint8), "rgb8")
    for bad in (image_msg(np.zeros((2, 2, 3), np.uint8), "rgb8"), image_msg(np.zeros((2, 2), np.uint8), "mono8")):
        with pytest.raises(SymfruitError, match="depth image"):
            frame_of(color, bad)


def test_camera_info_ros1_and_ros2_names_and_image_size():
    color = image_msg(np.zeros((48, 64, 3), np.uint8), "rgb8")
    depth = image_msg(np.zeros((48, 64), np.uint16), "16UC1")
    for key in ("K", "k"):
        cam = frame_of(color, depth, info_msg(fx=600, fy=601, cx=30, cy=20, width=64, height=48, key=key)).camera
        assert (cam.fx, cam.fy, cam.cx, cam.cy, cam.width, cam.height) == (600, 601, 30, 20, 64, 48)
    cam = frame_of(color, depth, info_msg(width=0, height=0, cx=32, cy=24)).camera  # an unset size is the image's
    assert (cam.width, cam.height) == (64, 48)
    with pytest.raises(InputError, match="focal"):
        frame_of(color, depth, info_msg(fx=0.0, width=64, height=48))
    with pytest.raises(InputError, match="intrinsics are for 640x480"):  # info of another resolution
        frame_of(color, depth, info_msg())


def test_a_processor_with_a_fruit_worker_gives_the_same_fruit_and_closes_it(example_images):
    from symfruit.fruitpool import one_process_reason

    alone = FrameProcessor(fruit="strawberry")
    assert not alone.pool.active  # the library's default: no process
    assert alone.workers_said() == "no fruit worker process (no worker process asked for (0))"
    shared = FrameProcessor(fruit="strawberry", fruit_processes=1)
    try:
        assert shared.pool.active == (one_process_reason(1) == "")
        assert shared.workers_said() == ("1 fruit worker process (warming up)" if shared.pool.active else
                                         f"no fruit worker process ({one_process_reason(1)})")  # fmt: skip
        assert shared.pool._wait_ready(600) or not shared.pool.active
        shared.pool._caller_shares = False  # the worker does every fruit
        messages = example_messages(example_images)
        a, b = alone.process(*messages), shared.process(*messages)
        assert [(f.id, f.centre.tolist(), f.size.tolist(), f.score) for f in a.fruits] == [
            (f.id, f.centre.tolist(), f.size.tolist(), f.score) for f in b.fruits]  # fmt: skip
        assert shared.pool.fruit_elsewhere == (len(b.fruits) if shared.pool.active else 0)
        processes = [w.process for w in shared.pool._state.workers]
    finally:
        shared.close()
        alone.close()
    assert not shared.pool.active and not any(p.is_alive() for p in processes)


@pytest.mark.parametrize(("color_encoding", "depth_encoding"), [("rgb8", "16UC1"), ("bgr8", "32FC1")])
def test_processor_equals_detect_on_the_example_frame(example_images, example_fruits, color_encoding,
                                                      depth_encoding):  # fmt: skip
    core = FrameProcessor(fruit="strawberry")
    got = core.process(*example_messages(example_images, color_encoding, depth_encoding))
    assert len(got.fruits) == len(example_fruits) > 0
    for a, b in zip(got.fruits, example_fruits, strict=True):
        assert a.id == b.id and a.n_visible == b.n_visible
        np.testing.assert_allclose(a.centre, b.centre, rtol=0, atol=1e-9)
        np.testing.assert_allclose(a.size, b.size, rtol=0, atol=1e-9)
        assert a.score == pytest.approx(b.score, abs=1e-12)
    assert set(got.seconds) == {"decode", "detect", "collect"}


def test_fruits_are_the_detections_json_entries(example_fruits, detect_json):
    located = [e for e in detect_json["fruits"] if "error" not in e]
    assert [f.id for f in example_fruits] == [e["id"] for e in located]
    for f, e in zip(example_fruits, located, strict=True):
        assert f.centre.tolist() == [e["bbox"]["center"]["position"][k] for k in "xyz"] == e["centre"]
        assert f.size.tolist() == [e["bbox"]["size"][k] for k in "xyz"]
        assert f.score == e["confidence"] and len(f.points) > f.n_visible == e["n_points"]


def test_fruits_of_leaves_failed_fruit_out(example_images):
    from symfruit.detect import Detection, FrameDetections

    found = FrameProcessor().process(*example_messages(example_images)).found
    first = found.detections[0]
    failed = Detection(99, first.mask, first.extraction, None, "too few points")
    with_failure = FrameDetections(found.frame, [*found.detections, failed], found.timings, found.mask_source)
    assert [f.id for f in fruits_of(with_failure)] == [f.id for f in fruits_of(found)]


def test_settings_resolve_like_the_cli(tmp_path):
    from symfruit.settings import resolve_settings

    config = tmp_path / "s.yaml"
    config.write_text("extract:\n  min_points: 77\n")
    core = FrameProcessor(fruit="apple", config=str(config))
    assert core.settings == resolve_settings(fruit="apple", config=config)
    assert core.settings.extract.min_points == 77
    assert FrameProcessor(fruit="", config="").settings == resolve_settings()  # empty ROS parameters: unset


def test_processor_refuses_bad_settings_at_start(tmp_path):
    for kwargs in ({"method": "no-such-method"}, {"fruit": "no-such-fruit"}, {"config": tmp_path / "none.yaml"},
                   {"depth_scale": 1.5}, {"depth_scale": 0.0}, {"depth_scale": float("nan")}, {"depth_scale": True},
                   {"depth_scale": 1e-300}):  # fmt: skip
        with pytest.raises(SymfruitError):
            FrameProcessor(**kwargs)


def test_processor_takes_the_depth_scales_the_nodes_document():
    """(0, 1] metres per unit, as ``checked_parameters`` and a frame's camera.json (1.0 was refused)."""
    for scale in (1.0, 0.001, 1e-4):
        assert checked_parameters({"depth_scale": scale})["depth_scale"] == scale
        assert FrameProcessor(depth_scale=scale).depth_scale == scale
    with pytest.raises(InputError, match=r"^depth_scale: expected metres per unit in \(0, 1\], got 2.5$"):
        FrameProcessor(depth_scale=2.5)


def test_latest_only_drops_waiting_items_and_survives_errors():
    entered, release = threading.Event(), threading.Event()
    handled, errors = [], []

    def handle(item):
        handled.append(item)
        if item == 1:
            entered.set()
            assert release.wait(60)
        if item == "boom":
            raise ValueError("bad frame")

    worker = LatestOnly(handle, on_error=lambda item, exc: errors.append((item, type(exc)))).start()
    try:
        assert worker.put(1) is False
        assert entered.wait(60)  # 1 is being handled: 2 waits, 3 replaces it
        assert worker.put(2) is False
        assert worker.put(3) is True
        release.set()
        assert worker.wait_idle(60)  # 1, then 3
        worker.put("boom")
        assert worker.wait_idle(60)
        worker.put(4)
        assert worker.wait_idle(60)
    finally:
        worker.stop()
    assert handled == [1, 3, "boom", 4] and worker.handled == 4
    assert worker.dropped == 1 and errors == [("boom", ValueError)]


@pytest.mark.parametrize(
    ("change", "match"),
    [({"width": 30000, "height": 20}, "at most 16384 pixels a side"),
     ({"width": 100_000, "height": 100_000}, "larger than 40,000,000 pixels"),
     ({"height": -3}, "empty"), ({"height": "many"}, "must be whole numbers"),
     ({"step": -1}, "step"), ({"is_bigendian": 1, "encoding": "rgb8"}, None)],
)  # fmt: skip
def test_malformed_colour_messages_are_refused_before_their_data_is_touched(change, match):
    msg = image_msg(np.zeros((4, 4, 3), np.uint8), "rgb8")
    for k, v in change.items():
        setattr(msg, k, v)
    args = (image_msg(np.ones((4, 4), np.uint16), "16UC1"), info_msg(width=4, height=4, cx=2, cy=2))
    if match is None:  # byte order means nothing for 8-bit data: the frame is read as it is
        assert frame_of(msg, *args).color.shape == (4, 4, 3)
        return
    with pytest.raises((SymfruitError, ValueError), match=match) as err:
        frame_of(msg, *args)
    assert isinstance(err.value, SymfruitError)


def test_depth_in_millimetres_as_float_metres_and_non_finite_depth():
    color = image_msg(np.zeros((8, 8, 3), np.uint8), "rgb8")
    info = info_msg(width=8, height=8, cx=4, cy=4)
    with pytest.raises(InputError, match="look like millimetres"):
        frame_of(color, image_msg(np.full((8, 8), 450.0, np.float32), "32FC1"), info)
    odd = np.full((8, 8), 0.5, np.float32)
    odd[0, :3] = [np.nan, np.inf, -np.inf]
    assert frame_of(color, image_msg(odd, "32FC1"), info).depth[0, :3].tolist() == [0.0, 0.0, 0.0]


def test_stamps_out_of_order_and_odd_headers_are_carried_as_given():
    color = image_msg(np.zeros((4, 4, 3), np.uint8), "rgb8")
    depth = image_msg(np.ones((4, 4), np.uint16), "16UC1")
    info = info_msg(width=4, height=4, cx=2, cy=2)
    stamps = []
    for secs in (9, 3, 7):  # a replayed or reordered stream: each frame keeps its own stamp
        color.header = header(secs=secs, nsecs=0)
        stamps.append(message_frame(color, depth, info).stamp)
    assert stamps == [9_000_000_000, 3_000_000_000, 7_000_000_000]


STOP_CHILD = """
import os, signal, sys, threading, time
from symfruit.ros.core import stop_signals
before = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
started = threading.Event()
def early():  # started before the mask, as numpy's BLAS threads are: SIGINT and SIGTERM are not blocked in it
    started.set()
    time.sleep(30)
early_thread = threading.Thread(target=early, daemon=True)
early_thread.start()
started.wait()
with stop_signals() as wait:
    signal.pthread_kill(early_thread.ident, signal.SIGTERM)  # lands on the thread that does not block it
    print(signal.Signals(wait()).name, flush=True)
with stop_signals() as wait:
    os.kill(os.getpid(), signal.SIGINT)  # process-wide, while the main thread is not waiting
    print(signal.Signals(wait()).name, flush=True)
    os.kill(os.getpid(), signal.SIGTERM)  # a second signal before leaving: taken, not fatal
print("handlers", before == (signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)),
      before == (signal.default_int_handler, signal.SIG_DFL), flush=True)
"""


def test_stop_signals_are_never_fatal_whichever_thread_they_land_on():
    """A node ends on SIGINT or SIGTERM by returning from ``wait()``, also when the kernel hands the signal to a
    thread started before the mask (with the default action that killed the process with exit -15); a signal
    arriving before ``wait()`` or while leaving is taken too, and the handlers are restored afterwards."""
    import subprocess
    import sys

    res = subprocess.run([sys.executable, "-c", STOP_CHILD], capture_output=True, text=True, timeout=60)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split("\n")[:3] == ["SIGTERM", "SIGINT", "handlers True True"], res.stdout + res.stderr


def test_live_camera_info_distortion_is_warned_about_once_and_a_non_finite_one_refused(example_images):
    import warnings

    from symfruit import SymfruitWarning

    color, depth = image_msg(np.zeros((48, 64, 3), np.uint8), "rgb8"), image_msg(np.zeros((48, 64), np.uint16), "16UC1")
    for key in ("K", "k"):
        with pytest.warns(
            SymfruitWarning,
            match=r"^ros: CameraInfo: non-zero distortion coefficients "
            rf"'{key.replace('K', 'D').replace('k', 'd')}' \(largest -0\.2\) are not applied",
        ):
            frame_of(color, depth, info_msg(width=64, height=48, cx=32, cy=24, key=key, d=[-0.2, 0.05, 0, 0, 0]))
    with pytest.raises(InputError, match=r"CameraInfo D must hold at most 16 finite numbers, got \[inf"):
        frame_of(color, depth, info_msg(width=64, height=48, cx=32, cy=24, d=[float("inf"), 0, 0, 0, 0]))
    with pytest.raises(InputError, match=r"CameraInfo D holds something that is not a number"):
        frame_of(color, depth, info_msg(width=64, height=48, cx=32, cy=24, d=["x"]))
    with warnings.catch_warnings():
        warnings.simplefilter("error", SymfruitWarning)
        frame_of(color, depth, info_msg(width=64, height=48, cx=32, cy=24, d=[0.0] * 5))  # zeros or none: silent
        frame_of(color, depth, info_msg(width=64, height=48, cx=32, cy=24))
    core = FrameProcessor(fruit="strawberry")
    color, depth, info = example_messages(example_images)
    info.D = [0.1, 0, 0, 0, 0]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for k in range(2):
            core.frame(color, depth, info, source=f"ros:/c@{k}")
    said = [str(w.message) for w in caught if issubclass(w.category, SymfruitWarning)]
    assert len(said) == 1 and said[0].startswith("ros:/c@0: CameraInfo: non-zero distortion coefficients 'D'")


def test_live_camera_info_principal_point_off_the_image_is_warned_about_once(example_images):
    import warnings

    from symfruit import SymfruitWarning

    color, depth = image_msg(np.zeros((48, 64, 3), np.uint8), "rgb8"), image_msg(np.zeros((48, 64), np.uint16), "16UC1")
    with pytest.warns(SymfruitWarning, match=r"^ros: CameraInfo: the principal point \(cx 320, cy 240\) lies outside "
                      r"the 64x48 image"):  # fmt: skip
        frame_of(color, depth, info_msg(width=0, height=0))  # the intrinsics of 640x480 on 64x48 images
    core = FrameProcessor(fruit="strawberry")
    color, depth, info = example_messages(example_images)
    info.D, info.K[2] = [0.1, 0, 0, 0, 0], -40.0
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for k in range(3):
            core.frame(color, depth, info, source=f"ros:/c@{k}")
    said = [str(w.message) for w in caught if issubclass(w.category, SymfruitWarning)]
    assert len(said) == 2 and said[0].startswith("ros:/c@0: CameraInfo: non-zero distortion coefficients 'D'")
    assert said[1].startswith("ros:/c@0: CameraInfo: the principal point (cx -40, cy")


def test_live_camera_info_with_a_transposed_k_is_refused():
    color = image_msg(np.zeros((48, 64, 3), np.uint8), "rgb8")
    depth = image_msg(np.zeros((48, 64), np.uint16), "16UC1")
    info = SimpleNamespace(width=64, height=48, header=header(), K=[600.0, 0, 0, 0, 600, 0, 32, 24, 1])
    with pytest.raises(InputError, match=r"CameraInfo K \[600, 0, 0, 0, 600, 0, 32, 24, 1\] is not a pinhole"):
        frame_of(color, depth, info)  # before: a frame of cx = cy = 0


@pytest.mark.parametrize("scale", [0, -0.001, float("nan"), float("inf"), 10])
def test_a_depth_scale_parameter_that_is_no_metres_per_unit_is_refused_at_start(scale):
    from symfruit.ros.core import checked_parameters

    # before: taken, and every frame's depth read as none (0, negative, NaN) or thousands of metres, each logged
    with pytest.raises(SymfruitError, match=r"parameter depth_scale: expected metres per unit in \(0, 1\]"):
        checked_parameters({"depth_scale": scale})
    assert checked_parameters({"depth_scale": 0.0001})["depth_scale"] == 0.0001


@pytest.mark.parametrize("scale", [1e-300, 1e-9])
def test_a_depth_scale_parameter_no_camera_has_is_refused_at_start(scale):
    from symfruit.ros.core import checked_parameters

    # before: taken, 1e-300 being 0 in float32: every frame read as one without depth, unsaid
    with pytest.raises(SymfruitError, match=rf"parameter depth_scale: {scale:g} m per unit; 16-bit depth would reach"):
        checked_parameters({"depth_scale": scale})


def test_unknown_parameters_name_the_first_and_leave_ross_own():
    from symfruit.ros.core import unknown_parameters

    unknown_parameters(["method", "use_sim_time", "qos_overrides./x.subscription.depth", "slop"])
    with pytest.raises(SymfruitError, match=r"^parameter 'slop_s': no such parameter \(did you mean 'slop'\?\); "
                       r"the node's are method, fruit"):  # fmt: skip
        unknown_parameters(["slop_s", "zzz_unrelated"])
    with pytest.raises(SymfruitError, match=r"^parameter 'zzz': no such parameter; the node's"):
        unknown_parameters(["zzz"])


def test_latest_only_drains_when_no_item_waits_and_at_stop():
    """Stop 55: ``drain`` runs after items were handled as soon as none waits (not between a handled item and one
    that waits), once, and at ``stop`` for the last item; wait_idle waits for it; its exceptions go to on_error."""
    entered, release = threading.Event(), threading.Event()
    seen, errors = [], []

    def handle(item):
        seen.append(item)
        if item in (1, 4):
            entered.set()
            assert release.wait(60)

    def drain():
        seen.append("drained")
        if seen[-2] == 3:
            raise ValueError("drain failed")

    worker = LatestOnly(handle, on_error=lambda item, exc: errors.append((item, type(exc))), drain=drain).start()
    try:
        worker.put(1)
        assert entered.wait(60)
        worker.put(2)  # waits: 1 is not drained before it
        release.set()
        assert worker.wait_idle(60)
        assert seen == [1, 2, "drained"]
        worker.put(3)
        assert worker.wait_idle(60)
        assert seen == [1, 2, "drained", 3, "drained"] and errors == [(None, ValueError)]
        entered.clear()
        release.clear()
        worker.put(4)
        assert entered.wait(60)
        stopping = threading.Thread(target=worker.stop, args=(60,))
        stopping.start()
        release.set()
        stopping.join(60)
    finally:
        release.set()
        worker.stop()
    assert seen == [1, 2, "drained", 3, "drained", 4, "drained"] and worker.handled == 4


def test_overlapped_frames_are_the_processors_in_order_and_a_bad_one_is_skipped(example_images):
    """Stop 55: through :class:`Overlapped` (a frame begun before the one in flight is finished, the workers
    ending its last fruit meanwhile) each frame's fruit are :meth:`FrameProcessor.process`'s, given in their
    order; a bad frame is skipped when begun, the one in flight finished after it."""
    from symfruit.fruitpool import one_process_reason
    from symfruit.ros.core import Overlapped

    alone = FrameProcessor(fruit="strawberry")
    shared = FrameProcessor(fruit="strawberry", fruit_processes=1)
    try:
        assert shared.pool._wait_ready(600) or not shared.pool.active
        messages = example_messages(example_images)
        bad = (image_msg(np.zeros((4, 4, 3), np.uint8), "rgb8"), messages[1], messages[2])  # not the depth's size
        expected = [(f.id, f.centre.tolist(), f.size.tolist(), f.score) for f in alone.process(*messages).fruits]
        events = []
        overlapped = Overlapped(shared, done=lambda item, p: events.append((item[0], [(f.id, f.centre.tolist(),
                                f.size.tolist(), f.score) for f in p.fruits])),
                                skipped=lambda item, exc: events.append((item[0], type(exc))),
                                failed=lambda item, exc: events.append((item[0], exc)))  # fmt: skip
        for name, msgs in (("a", messages), ("bad", bad), ("b", messages), ("c", messages)):
            overlapped.handle((name, *msgs), name=name, source="test")
        # the bad one told when begun, before a (in flight) is finished; b finished when c came; c in flight
        assert events == [("bad", InputError), ("a", expected), ("b", expected)] and shared._stream.in_flight
        overlapped.drain()
        overlapped.drain()  # nothing in flight: nothing
        assert events[3:] == [("c", expected)] and not shared._stream.in_flight
        assert shared.pool.starts == (1 if one_process_reason(1) == "" else 0), shared.pool.last_loss
    finally:
        shared.close()
        alone.close()
