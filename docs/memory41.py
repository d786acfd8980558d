"""Memory of `symfruit detect` over a long generated recording (docs/robust41.md): the resident set size after
each frame, as `run_batch` (what `symfruit detect` runs) goes through a recording of N copies of the shipped
example frame (640x480, three strawberries), as a folder of frame folders or as a ROS 2 bag (16UC1 depth,
rgb8 colour, CameraInfo).

    python docs/memory41.py folder --frames 200
    python docs/memory41.py bag --frames 200 [--method evidence]
    python docs/memory41.py folder --frames 200 --fruit-processes 1
    python docs/memory41.py table --frames 2000

``table``: the fruit table alone (:class:`symfruit.season.table.TableWriter`, which ``detect`` fills at the end of
a run from every frame's ``detections.json``): the Python heap's peak (``tracemalloc``) while N frames of 8 fruit
each are added, pyarrow imported before. Its buffer holds up to ``ROW_GROUP`` rows before a row group is written, so
the peak grows up to about 2,000 frames of 8 fruit and then stays (stop 63).

``--fruit-processes N``: each frame's fruit shared with N worker processes (:class:`symfruit.fruitpool.FruitPool`,
started and warm before the first frame; stop 53): the workers' RSS is printed too, and the run's seconds.

Prints the largest RSS up to frame 10, 50, 100, 150 and N, and up to the run's end (tables written). A
measurement of minutes, not a test: memory that grows with the frames shows as a rising row.
"""

import argparse
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path


def rss_mb(pid: int | str = "self") -> float:
    with open(f"/proc/{pid}/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def folder_recording(root: Path, n: int, frame: Path) -> Path:
    rec = root / "rec"
    for k in range(n):
        shutil.copytree(frame, rec / f"f{k:05d}", ignore=shutil.ignore_patterns("truth.json"))
    return rec


def bag_recording(root: Path, n: int, frame: Path) -> Path:
    import numpy as np
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    from symfruit.io.frames import read_frame

    f = read_frame(frame)
    cam = json.loads((frame / "camera.json").read_text())
    mm = np.round(f.depth * 1000).astype(np.uint16)
    ts = get_typestore(Stores.ROS2_HUMBLE)
    Image, Info = ts.types["sensor_msgs/msg/Image"], ts.types["sensor_msgs/msg/CameraInfo"]
    Header, Time = ts.types["std_msgs/msg/Header"], ts.types["builtin_interfaces/msg/Time"]
    RoI = ts.types["sensor_msgs/msg/RegionOfInterest"]
    h, w = mm.shape
    k = np.array([cam["fx"], 0, cam["cx"], 0, cam["fy"], cam["cy"], 0, 0, 1.0])
    with Writer(root / "rec", version=9) as writer:
        c_col = writer.add_connection("/camera/color/image_raw", "sensor_msgs/msg/Image", typestore=ts)
        c_dep = writer.add_connection("/camera/aligned_depth_to_color/image_raw", "sensor_msgs/msg/Image", typestore=ts)
        c_inf = writer.add_connection("/camera/color/camera_info", "sensor_msgs/msg/CameraInfo", typestore=ts)
        for i in range(n):
            t = 1_000_000_000 + i * 33_333_333
            head = Header(stamp=Time(sec=t // 10**9, nanosec=t % 10**9), frame_id="camera_color_optical_frame")
            info = Info(header=head, height=h, width=w, distortion_model="plumb_bob", d=np.zeros(5), k=k,
                        r=np.eye(3).ravel(), p=np.array([*k[:3], 0, *k[3:6], 0, *k[6:], 0]), binning_x=0,
                        binning_y=0, roi=RoI(x_offset=0, y_offset=0, height=0, width=0, do_rectify=False))  # fmt: skip
            writer.write(c_inf, t, ts.serialize_cdr(info, "sensor_msgs/msg/CameraInfo"))
            img = Image(header=head, height=h, width=w, encoding="rgb8", is_bigendian=0, step=3 * w,
                        data=f.color.ravel())  # fmt: skip
            writer.write(c_col, t, ts.serialize_cdr(img, "sensor_msgs/msg/Image"))
            dep = Image(header=head, height=h, width=w, encoding="16UC1", is_bigendian=0, step=2 * w,
                        data=mm.view(np.uint8).ravel())  # fmt: skip
            writer.write(c_dep, t + 1000, ts.serialize_cdr(dep, "sensor_msgs/msg/Image"))
    return root / "rec"


def table_peak(frames: int) -> float:
    """The Python heap's peak in MB while ``frames`` records of 8 fruit go through a :class:`TableWriter`."""
    import tracemalloc

    import pyarrow.parquet  # noqa: F401  (imported before the measurement, as detect has it by then)

    from symfruit.season.table import TableWriter, frame_rows

    fruit = {"centre": [0.1, 0.2, 0.3], "box": {"size": [0.03, 0.03, 0.03]}, "confidence": 0.5, "reliable": True}
    fruit |= {"method": "evidence", "mask_area": 500, "n_points": 300}
    record = {"header": {"stamp": {"sec": 1, "nanosec": 0}}, "timings": {"total": 0.1}}
    record["fruits"] = [{"id": k, **fruit} for k in range(8)]
    tracemalloc.start()
    with tempfile.TemporaryDirectory(prefix="symfruit-memory41-") as tmp, TableWriter(tmp) as table:
        for i in range(frames):
            table.add(*frame_rows({**record, "frame": f"frame_{i:06d}"}, "rec"))
    peak = tracemalloc.get_traced_memory()[1] / 1e6
    tracemalloc.stop()
    return peak


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("kind", choices=("folder", "bag", "table"))
    parser.add_argument("--frames", type=int, default=200)
    parser.add_argument("--method", default=None, help="completion method (default: detect's)")
    parser.add_argument("--fruit-processes", type=int, default=0, help="fruit worker processes (default 0: none)")
    args = parser.parse_args()
    if args.kind == "table":
        rows = 8 * args.frames
        peak = table_peak(args.frames)
        sys.stdout.write(f"table, {args.frames} frames ({rows} rows): Python heap peak {peak:.1f} MB\n")
        return

    from symfruit.batch import run_batch
    from symfruit.demo import example_frame
    from symfruit.fruitpool import FruitPool
    from symfruit.methods import DEFAULT_METHOD

    with tempfile.TemporaryDirectory(prefix="symfruit-memory41-") as tmp, example_frame() as frame:
        root = Path(tmp)
        make = folder_recording if args.kind == "folder" else bag_recording
        rec = make(root, args.frames, frame)
        after: list[float] = []
        theirs: list[list[float]] = []
        extra = {} if args.method is None else {"method": args.method}
        with FruitPool(args.fruit_processes, method=args.method or DEFAULT_METHOD) as pool:
            if args.fruit_processes and not pool.active:
                raise SystemExit(f"--fruit-processes: no worker here ({pool.reason})")
            pids = [w.process.pid for w in pool._state.workers]

            def note(i, found):
                after.append(rss_mb())
                theirs.append([rss_mb(pid) for pid in pids])

            t0 = time.perf_counter()
            report = run_batch(rec, root / "out", progress=False, on_frame=note, pool=pool, **extra)
            seconds = time.perf_counter() - t0
            end, end_theirs = rss_mb(), [rss_mb(pid) for pid in pids]
            elsewhere = pool.fruit_elsewhere
    out = sys.stdout
    out.write(f"{args.kind}, {args.frames} frames: {len(report.done)} done, {len(report.failed)} failed, "
              f"{seconds:.1f} s ({args.frames / seconds:.1f} frames/s)")  # fmt: skip
    out.write(f"; {elsewhere} of {report.fruits + report.failed_fruits} fruit in the workers\n" if pids else "\n")
    for upto in (10, 50, 100, 150, args.frames):
        if upto <= len(after):
            workers = "".join(f", worker {max(t[j] for t in theirs[:upto]):7.1f} MB" for j in range(len(pids)))
            out.write(f"  largest RSS up to frame {upto:5d}: {max(after[:upto]):7.1f} MB{workers}\n")
    workers = "".join(f", worker {v:7.1f} MB" for v in end_theirs)
    out.write(f"  after the run (tables written):  {end:7.1f} MB{workers}\n")


if __name__ == "__main__":
    main()
