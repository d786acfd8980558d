"""Make ``fruit.bag``: a RealSense recording in librealsense's own ROS 1 format, of fruit the project renders.

Three strawberries on stems in front of a backdrop, rendered by ``symfruit.synthetic.render`` twice per frame: depth
by a D435-like depth camera (wider field of view, Brown-Conrady lens with zero coefficients, depth units of
0.1 mm) and colour by a colour camera 25 mm to its right, turned by 1 degree (Inverse Brown-Conrady, zero
coefficients, as D400 colour streams report). The frames go through pyrealsense2's software device into
``rs.recorder``, so the file is what the SDK itself writes (topics, message types, extrinsics, options,
metadata), LZ4-compressed like the Viewer's recordings. SDK 2.58 and later record ``.db3`` instead, so this
needs pyrealsense2 2.57 or older (``pip install 'pyrealsense2<2.58'``, in a venv of its own).

Beside the bag it writes ``aligned_00000/``: frame 0 as a frame folder whose depth was rendered by the colour
camera itself (what perfect alignment would give) with ``truth.json``, for the tests.

    python examples/realsense/make_bag.py examples/realsense
"""

from __future__ import annotations

import colorsys
import sys
from pathlib import Path

import numpy as np

from symfruit.core.box import Box
from symfruit.core.camera import Camera
from symfruit.io.frames import write_frame
from symfruit.synthetic.render import render
from symfruit.synthetic.shapes import rotation, strawberry

DEPTH_CAMERA = Camera(fx=212.0, fy=212.0, cx=211.5, cy=119.5, width=424, height=240)
COLOR_CAMERA = Camera(fx=308.0, fy=308.0, cx=160.5, cy=119.0, width=320, height=240)
DEPTH_UNITS = 0.0001  # metres per unit (the Viewer's "Depth Units" option; D400 default is 0.001)
#: Depth -> colour extrinsics: p_color = ROTATION @ p_depth + TRANSLATION.
ROTATION = rotation(0.5, 1.0, 0.0)
TRANSLATION = np.array([0.025, 0.001, 0.0005])
FRAMES = 2


def scene(seed: int) -> tuple[list[tuple[np.ndarray, np.ndarray]], list[tuple[float, float, float]], list[Box]]:
    """Meshes in the colour camera's frame, their HSV colours, and the ripe fruit's boxes."""
    rng = np.random.default_rng(seed)
    meshes, colours, boxes = [], [], []
    for k, (x, y, z) in enumerate([(-0.07, 0.0, 0.36), (0.0, 0.02, 0.32), (0.075, -0.01, 0.40)]):
        berry = strawberry(rng, length=float(rng.uniform(0.034, 0.046)))
        posed = berry.transformed(rotation(rng.uniform(-20, 20), rng.uniform(-90, 90), rng.uniform(-15, 15)),
                                  np.array([x + rng.uniform(-0.005, 0.005), y, z]))  # fmt: skip
        meshes.append((posed.vertices, posed.faces))
        colours.append((0.99 - 0.01 * k, 0.85, 0.75))
        boxes.append(Box.from_points(posed.vertices))
    back = np.array([[-1.0, -0.8, 0.7], [1.0, -0.8, 0.7], [1.0, 0.8, 0.7], [-1.0, 0.8, 0.7]])  # in the depth frame
    back = back @ ROTATION.T + TRANSLATION
    meshes.append((back, np.array([[0, 1, 2], [0, 2, 3]])))
    colours.append((0.3, 0.35, 0.45))
    return meshes, colours, boxes


def shade(shot, colours) -> np.ndarray:
    """Flat colour per mesh, times a Lambert-like term on the fruit; no noise (the bag stays small)."""
    rgb = np.array([colorsys.hsv_to_rgb(*c) for c in colours])
    image = np.zeros((*shot.ids.shape, 3))
    seen = shot.ids >= 0
    light = np.where(shot.ids[seen] < len(colours) - 1, 0.4 + 0.6 * shot.facing[seen], 1.0)
    image[seen] = rgb[shot.ids[seen]] * light[:, None]
    return (np.clip(image, 0, 1) * 255).astype(np.uint8)


def frame(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[Box]]:
    """Colour (h, w, 3) uint8, depth units (h_d, w_d) uint16 from the depth camera, and the depth the colour
    camera itself sees (metres), with the boxes."""
    meshes, colours, boxes = scene(seed)
    color_shot = render(meshes, COLOR_CAMERA)
    in_depth = [((v - TRANSLATION) @ ROTATION, f) for v, f in meshes]  # R^T (p - t), row vectors
    depth_shot = render(in_depth, DEPTH_CAMERA)
    depth = np.where(np.isfinite(depth_shot.depth), depth_shot.depth, 0.0)
    depth[150:170, 250:280] = 0.0  # a patch the sensor returned nothing for (holes must stay holes)
    units = np.clip(np.rint(depth / DEPTH_UNITS), 0, 65535).astype(np.uint16)
    truth_depth = np.where(np.isfinite(color_shot.depth), color_shot.depth, 0.0)
    return shade(color_shot, colours), units, truth_depth.astype(np.float32), boxes


def record(path: Path, frames: list[tuple[np.ndarray, np.ndarray]]) -> None:
    """Write ``frames`` (colour, depth units) through pyrealsense2's software device and recorder."""
    import pyrealsense2 as rs

    def intrinsics(cam: Camera, model) -> rs.intrinsics:
        i = rs.intrinsics()
        i.width, i.height, i.fx, i.fy, i.ppx, i.ppy = cam.width, cam.height, cam.fx, cam.fy, cam.cx, cam.cy
        i.model, i.coeffs = model, [0.0] * 5
        return i

    device = rs.software_device()
    depth_sensor, color_sensor = device.add_sensor("Stereo Module"), device.add_sensor("RGB Camera")
    depth_sensor.add_read_only_option(rs.option.depth_units, DEPTH_UNITS)
    streams = []
    for sensor, kind, cam, fmt, bpp, uid, model in (
        (depth_sensor, rs.stream.depth, DEPTH_CAMERA, rs.format.z16, 2, 0, rs.distortion.brown_conrady),
        (color_sensor, rs.stream.color, COLOR_CAMERA, rs.format.rgb8, 3, 1, rs.distortion.inverse_brown_conrady),
    ):
        vs = rs.video_stream()
        vs.type, vs.index, vs.uid, vs.width, vs.height = kind, 0, uid, cam.width, cam.height
        vs.fps, vs.bpp, vs.fmt, vs.intrinsics = 30, bpp, fmt, intrinsics(cam, model)
        streams.append(sensor.add_video_stream(vs).as_video_stream_profile())
    ext = rs.extrinsics()
    ext.rotation = ROTATION.T.ravel().tolist()  # librealsense stores the rotation column-major
    ext.translation = TRANSLATION.tolist()
    streams[0].register_extrinsics_to(streams[1], ext)
    recorder = rs.recorder(str(path), device, True)  # LZ4, as the Viewer records
    queues = [rs.frame_queue(8), rs.frame_queue(8)]
    for sensor, profile, queue in zip((depth_sensor, color_sensor), streams, queues, strict=True):
        sensor.open(profile)
        sensor.start(queue)
    keep = []
    for k, (color, units) in enumerate(frames):
        for sensor, profile, pixels, bpp, offset in ((depth_sensor, streams[0], units, 2, 0.0),
                                                     (color_sensor, streams[1], color, 3, 1.5)):  # fmt: skip
            keep.append(np.ascontiguousarray(pixels))
            f = rs.software_video_frame()
            f.pixels, f.bpp, f.stride = keep[-1], bpp, pixels.shape[1] * bpp
            f.timestamp = 1000.0 + 1000.0 / 30 * k + offset  # ms: colour 1.5 ms after its depth
            f.domain, f.frame_number, f.profile = rs.timestamp_domain.global_time, k, profile
            if bpp == 2:
                f.depth_units = DEPTH_UNITS
            sensor.on_video_frame(f)
    for sensor in (depth_sensor, color_sensor):
        sensor.stop()
        sensor.close()
    recorder.pause()
    del recorder


def main(folder: str) -> None:
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    rendered = [frame(seed) for seed in range(FRAMES)]
    record(out / "fruit.bag", [(c, u) for c, u, _, _ in rendered])
    color, _, truth_depth, boxes = rendered[0]
    truth = {"fruits": [{"id": i + 1, **b.to_dict()} for i, b in enumerate(boxes)]}
    write_frame(out / "aligned_00000", color, truth_depth, COLOR_CAMERA, truth=truth, depth_scale=DEPTH_UNITS)
    sys.stdout.write(
        f"wrote {out / 'fruit.bag'} ({(out / 'fruit.bag').stat().st_size} bytes) and {out / 'aligned_00000'}\n"
    )


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else str(Path(__file__).parent))
