"""Compare symfruit's depth-to-colour alignment with the RealSense SDK's ``rs.align`` on the same recording.

    pip install 'symfruit[bag,realsense]'
    python examples/realsense/compare_sdk.py examples/realsense/fruit.bag
    python examples/realsense/compare_sdk.py examples/realsense/fruit.bag --distort 0.06,-0.1,0.001,-0.0008,0.02

Per depth frame the SDK plays (it may skip the first): the share of colour pixels with depth in both, in
symfruit's only and in the SDK's only; with ``z=depth`` (the SDK's convention: the depth camera's reading)
the share of pixels with depth in both whose values are bit-identical; with symfruit's default ``z=color``
(depth along the colour camera's axis) the median difference and the share of pixels more than 10 mm
apart (footprint edges that moved at a silhouette). ``--distort`` first writes a
copy of the bag (uncompressed, beside it in a temporary folder) whose colour lens has those Inverse
Brown-Conrady coefficients, to compare the distortion path too.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

from symfruit.core.align import align_depth
from symfruit.io.realsense import RealSenseBagSource, sdk_aligned


def distorted_copy(bag: Path, coeffs: list[float], folder: Path) -> Path:
    """``bag`` with the colour stream's distortion coefficients replaced (every other message as it was)."""
    from rosbags.highlevel import AnyReader
    from rosbags.rosbag1 import Writer

    out = folder / f"{bag.stem}-distorted.bag"
    with AnyReader([bag]) as reader, Writer(out) as writer:
        conns = {c.id: writer.add_connection(c.topic, c.msgtype, msgdef=c.msgdef.data, md5sum=c.digest)
                 for c in reader.connections}  # fmt: skip
        for c, t, raw in reader.messages():
            if c.topic.endswith("Color_0/info/camera_info"):
                msg = reader.deserialize(raw, c.msgtype)
                msg.D = np.array(coeffs, dtype=np.float64)
                raw = reader.typestore.serialize_ros1(msg, c.msgtype)
            writer.write(conns[c.id], t, raw)
    return out


def compare(bag: Path) -> list[str]:
    rows = []
    with RealSenseBagSource(bag) as src:
        index = {stamp: i for i, stamp in enumerate(int(n.rsplit("_", 1)[1]) for n in src.names())}
        geometry = (src.depth_stream.lens, src.color_stream.lens, src.rotation, src.translation)
        for stamp, sdk in sdk_aligned(bag):
            _, units, scale, _ = src.read_raw(index[stamp])
            depth = units * np.float32(scale)
            same = align_depth(depth, *geometry, z="depth")
            ours = align_depth(depth, *geometry)
            both = (same > 0) & (sdk > 0)
            diff = np.abs(ours - sdk)[(ours > 0) & (sdk > 0)] * 1000
            rows.append(
                f"| {index[stamp]} | {both.mean():.2%} | {((same > 0) & (sdk == 0)).mean():.3%} "
                f"| {((sdk > 0) & (same == 0)).mean():.3%} | {(same[both] == sdk[both]).mean():.3%} "
                f"| {np.median(diff):.2f} / {(diff > 10).mean():.3%} |"
            )
    return rows


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("bag", type=Path)
    parser.add_argument("--distort", help="k1,k2,p1,p2,k3 for the colour lens of a copy")
    args = parser.parse_args(argv)
    sys.stdout.write("| frame | depth in both | symfruit only | SDK only | z=depth bit-identical "
                     "| z=color vs SDK: median (mm) / share > 10 mm |\n|---|---|---|---|---|---|\n")  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        bag = args.bag
        if args.distort:
            bag = distorted_copy(bag, [float(v) for v in args.distort.split(",")], Path(tmp))
        for row in compare(bag):
            sys.stdout.write(row + "\n")


if __name__ == "__main__":
    main()
