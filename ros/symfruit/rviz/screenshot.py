"""Headless RViz screenshot of the node's markers on the example frame (docs/ros-rviz.png).

Needs Debian's rviz, xvfb and imagemagick (`apt-get install --no-install-recommends rviz xvfb xauth
libgl1-mesa-dri imagemagick`; RViz renders with Mesa's llvmpipe) besides `make ros-env`. Run from the
repository: `.venv/bin/python ros/symfruit/rviz/screenshot.py [OUT.png]`. It starts a master, Xvfb,
`symfruit ros` and RViz (this folder's symfruit.rviz), plays the example frame once a second together
with its coloured depth cloud on /scene_points, and after ~25 s grabs the screen.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
DISPLAY = ":77"


def scene_cloud(rgb: np.ndarray, raw: np.ndarray, cam) -> np.ndarray:
    """(n, 4) float32 x, y, z, packed rgb of every pixel with depth."""
    z = raw.astype(np.float32) * np.float32(0.001)
    v, u = np.mgrid[0 : raw.shape[0], 0 : raw.shape[1]]
    ok = z > 0
    col = rgb[ok].astype(np.uint32)
    packed = ((col[:, 0] << 16) | (col[:, 1] << 8) | col[:, 2]).view(np.float32)
    x, y = (u[ok] - cam.cx) / cam.fx * z[ok], (v[ok] - cam.cy) / cam.fy * z[ok]
    return np.column_stack([x, y, z[ok], packed]).astype(np.float32)


def main(out: Path, seconds: float = 25.0) -> None:
    from symfruit.ros.master import RosMaster, stop_group

    procs: list[subprocess.Popen] = []

    def start(cmd, env, name):
        with open(master.home / f"{name}.log", "wb") as log:
            procs.append(subprocess.Popen(cmd, env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True))

    with RosMaster() as master:
        os.environ.update({k: master.env[k] for k in ("ROS_MASTER_URI", "ROS_HOSTNAME", "ROS_HOME", "ROS_LOG_DIR")})
        env = {**master.env, "DISPLAY": DISPLAY, "PYTHONUNBUFFERED": "1"}
        try:
            start(["Xvfb", DISPLAY, "-screen", "0", "1100x720x24", "-nolisten", "tcp"], master.env, "xvfb")
            start([sys.executable, "-m", "symfruit", "ros"], env, "node")
            start(["rviz", "-d", str(HERE / "symfruit.rviz")], env, "rviz")
            import rospy
            from sensor_msgs.msg import CameraInfo, Image, PointCloud2, PointField
            from std_msgs.msg import Header

            rospy.init_node("symfruit_screenshot", anonymous=True, disable_signals=True)
            from symfruit.ros.bench import example_images

            rgb, raw, cam = example_images()
            h, w = raw.shape
            k = [cam.fx, 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0]
            cloud = scene_cloud(rgb, raw, cam)
            fields = [PointField(n, 4 * k, PointField.FLOAT32, 1) for k, n in enumerate(("x", "y", "z", "rgb"))]
            pubs = [rospy.Publisher("/camera/color/image_raw", Image, queue_size=2),
                    rospy.Publisher("/camera/aligned_depth_to_color/image_raw", Image, queue_size=2),
                    rospy.Publisher("/camera/color/camera_info", CameraInfo, queue_size=2),
                    rospy.Publisher("/scene_points", PointCloud2, queue_size=1)]  # fmt: skip
            t_end = time.monotonic() + seconds
            i = 0
            while time.monotonic() < t_end:  # a demo, not a test: RViz and the node catch up on their own
                head = Header(stamp=rospy.Time(1000 + i), frame_id="camera_color_optical_frame")
                i += 1
                pubs[0].publish(Image(header=head, height=h, width=w, encoding="rgb8", step=w * 3, data=rgb.tobytes()))
                pubs[1].publish(Image(header=head, height=h, width=w, encoding="16UC1", step=w * 2, data=raw.tobytes()))
                pubs[2].publish(CameraInfo(header=head, height=h, width=w, K=k))
                pubs[3].publish(PointCloud2(header=head, height=1, width=len(cloud), fields=fields, point_step=16,
                                            row_step=16 * len(cloud), data=cloud.tobytes(), is_dense=True))  # fmt: skip
                time.sleep(1.0)
            grab = master.home / "screen.png"
            subprocess.run(["import", "-window", "root", "-display", DISPLAY, str(grab)], check=True)
            subprocess.run(["convert", str(grab), "-crop", "1068x628+16+62", "+repage", "-resize", "80%",
                            "-colors", "96", f"PNG8:{out}"], check=True)  # fmt: skip
            rospy.signal_shutdown("done")
        finally:
            for p in reversed(procs):
                stop_group(p, 15)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else REPO / "docs" / "ros-rviz.png")
