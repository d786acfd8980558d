"""The occlusion map's ring about a camera-protocol view's fruit (docs/occl40.md): the share of a 4 px ring outside
the fruit's mask that :func:`symfruit.core.occlusion.occlusion` marks hidden, without its post-step
(``band=0``, as a8dfd56) and with it (the default ``band``).

    python docs/occl40.py SENSOR OCCLUSION N     # e.g. realsense-d435 0 3; azure-kinect 0.25 2

The view is rebuilt as ``symfruit evaluate --protocol camera --sensor SENSOR --seed 0`` makes fruit index 0..N-1
(hanging), registered and extracted with the default settings.
"""

import argparse
import sys

import numpy as np
from scipy import ndimage

from symfruit.core.occlusion import occlusion
from symfruit.evaluate import protocols as proto
from symfruit.extract import extract, register
from symfruit.settings import Settings

FRUIT = "strawberry,apple,citrus,tomato,lemon,peach,plum".split(",")


def main(sensor: str, occluded: float, n: int) -> None:
    st = Settings()
    for fruit in FRUIT:
        shares = []
        for index in range(n):
            inst = proto.build(proto.Spec("camera", fruit, index, index, occluded, 0, sensor, "hanging"))
            assert inst.mask is not None and inst.depth is not None
            moved, shift = register(inst.mask.astype(np.int32), inst.depth, inst.camera, st.extract)
            camera = inst.camera.shifted(*shift)
            ex = extract(moved > 0, inst.depth, camera, st.extract)
            mask = ex.silhouette if ex.silhouette is not None else moved > 0
            row = []
            for band in (0, None):
                kw = {} if band is None else {"band": band}
                occ = occlusion(inst.depth, mask, ex.points, camera, tolerance=st.occlusion.tolerance,
                                reach=st.occlusion.reach_px, **kw)  # fmt: skip
                assert occ.own is not None
                ring = ndimage.binary_dilation(occ.own, iterations=4) & ~occ.own
                row.append((occ.hidden & ring).sum() / max(ring.sum(), 1))
            shares.append(row)
        a = np.array(shares)
        sys.stdout.write(f"{sensor} {fruit} occlusion {occluded:g}: ring hidden share, a8dfd56 "
                         f"{np.round(a[:, 0], 2)} -> own_edge {np.round(a[:, 1], 2)}\n")  # fmt: skip


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sensor", help="a camera model, e.g. realsense-d435")
    parser.add_argument("occlusion", type=float, help="the leaf's share, e.g. 0 or 0.25")
    parser.add_argument("n", type=int, help="fruit indices 0..N-1 of each kind")
    args = parser.parse_args()
    main(args.sensor, args.occlusion, args.n)
