"""Adversarial masks for the time-of-flight overshoot cut (stop 44, docs/guard44.md): curved, end-on and touching
fruit whose own surface recedes beyond extraction's slab, and round fruit the cut must still trim. Each view: the
fruit's silhouette and depth, the mixed pixels about its edge without depth (``--ring`` px on either side) or given
an intermediate depth (flying pixels), the background behind, a mask drawn ``--grow`` px wider, the points the
fruit's pixels one px inside its silhouette within a slab of 1.3 mask radii behind its front (as extraction).

    PYTHONPATH=TREE/src python docs/guard44.py [--ring 2] [--grow 5]

Prints per view: the fruit's pixels, the mask's pixels beyond the fruit, the fruit's pixels cut (wrongly) and the
mask's pixels beyond the fruit cut (rightly).
"""

import argparse
import sys

import numpy as np
from scipy import ndimage

from symfruit.core.camera import Camera
from symfruit.core.occlusion import occlusion

CAM = Camera(fx=300.0, fy=300.0, cx=80.0, cy=60.0, width=160, height=120)  # 1 mm a pixel at 0.3 m


def grid():
    vv, uu = np.mgrid[: CAM.height, : CAM.width]
    return vv.astype(float), uu.astype(float)


def views():
    """name -> (fruit silhouette, depth on the fruit (image), depth of what is not the fruit (image))."""
    vv, uu = grid()
    out = {}
    far = np.full(vv.shape, 0.9)
    # an 8 px wide arch on a 14-22 px radius, receding along its length (a banana's far end beyond the slab)
    r, a = np.hypot(uu - 80, vv - 70), np.degrees(np.arctan2(uu - 80, 70 - vv))
    arch = (r >= 14) & (r <= 22) & (np.abs(a) <= 80)
    out["arch 8px r14-22"] = (arch, 0.30 + 0.10 * (a + 80) / 160, far)
    arch2 = (r >= 22) & (r <= 30) & (np.abs(a) <= 60)
    out["arch 8px r22-30"] = (arch2, 0.30 + 0.15 * (a + 60) / 120, far)
    # a crescent: a disc less an offset disc, its horns receding
    cres = (np.hypot(uu - 80, vv - 60) <= 24) & (np.hypot(uu - 88, vv - 52) > 20)
    out["crescent"] = (cres, 0.30 + 0.002 * np.hypot(uu - 62, vv - 78), far)
    # a banana from its side: a tube 12 px thick curved on a 45 px radius, round in section, far end receding
    r2, a2 = np.hypot(uu - 80, vv - 100), np.degrees(np.arctan2(uu - 80, 100 - vv))
    t = r2 - 51
    ban = (np.abs(t) <= 12) & (np.abs(a2) <= 55)
    zb = 0.32 + 0.12 * (a2 + 55) / 110 - 0.001 * np.sqrt(np.clip(144 - t**2, 0, None))
    out["banana side, far end receding"] = (ban, zb, far)
    # a pear end-on, its neck towards the camera: radius rho(t) = 35 mm (t / 70 mm)^0.6 along the view axis
    rho = np.hypot(uu - 80, vv - 60) * 0.001 * 0.40 / 0.3  # mm a px at 0.40 m: 1.33
    pear = rho <= 0.035
    out["pear end-on"] = (pear, 0.40 + 0.070 * (np.clip(rho, 0, 0.035) / 0.035) ** (1 / 0.6), far)
    # two touching fruit in one mask, the second 6 cm behind (the points are the first's)
    d1, d2 = np.hypot(uu - 65, vv - 60), np.hypot(uu - 94, vv - 60)
    one, two = d1 <= 15, (d2 <= 15) & (d1 > 15)
    ztwo = np.where(one, 0.30 + 0.001 * (15 - np.sqrt(np.clip(225 - d1**2, 0, None))), 0.36)
    out["two touching, 6 cm apart (fruit = the first)"] = (one, ztwo, np.where(two, 0.36, 0.9))
    # controls: a ball before a wall, a 3:1 ellipse, a ball 4 cm before leaves
    db = np.hypot(uu - 80, vv - 60)
    ball = db <= 16
    zball = 0.30 + 0.001 * (16 - np.sqrt(np.clip(256 - db**2, 0, None)))
    out["ball before a wall (control)"] = (ball, zball, far)
    ell = ((uu - 80) / 30.0) ** 2 + ((vv - 60) / 10.0) ** 2 <= 1
    out["3:1 ellipse before a wall (control)"] = (ell, np.full(vv.shape, 0.30), far)
    out["ball 4 cm before leaves (control)"] = (ball, zball, np.full(vv.shape, 0.30 + 0.016 + 0.04))
    # a ball a third hidden by a leaf in front, its mask drawn round what is seen (over the leaf's edge)
    leaf = uu < 74
    out["ball a third behind a leaf"] = (ball & ~leaf, zball, np.where(leaf, 0.25, 0.9))
    return out


def render(fruit, zf, zbg, ring, grow, flying, rng):
    inner = fruit & ~ndimage.binary_erosion(fruit, iterations=ring)
    outer = ndimage.binary_dilation(fruit, iterations=ring) & ~fruit
    depth = np.where(fruit, zf, zbg)
    mixed = inner | outer
    depth[mixed] = 0.0
    if flying:  # the mixed pixels' depth between the fruit's and what lies behind, a share of them
        edge = outer & (rng.random(fruit.shape) < flying)
        near = ndimage.grey_dilation(np.where(fruit, -zf, -np.inf), size=2 * ring + 3)
        depth[edge] = 0.5 * (zbg[edge] - near[edge])
    mask = ndimage.binary_dilation(fruit, iterations=grow)
    core = ndimage.binary_erosion(fruit & (depth > 0), iterations=1)
    front = zf[core].min()
    radius = np.sqrt(mask.sum() / np.pi) * front / CAM.fx
    core &= zf <= front + 1.3 * radius
    rows, cols = np.nonzero(core)
    points = CAM.deproject(np.c_[cols, rows].astype(float), depth[rows, cols])
    return depth, mask, points


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ring", type=int, default=2, help="mixed pixels without depth each side of the edge")
    ap.add_argument("--grow", type=int, default=5, help="the mask drawn this many px wider")
    ap.add_argument("--flying", type=float, default=0.0, help="share of the outer mixed pixels kept as flying")
    ap.add_argument("--star", type=float, default=None, help="core.occlusion.STAR_SHARE set to this")
    args = ap.parse_args()
    if args.star is not None:
        import symfruit.core.occlusion as core_occlusion

        core_occlusion.STAR_SHARE = args.star
    rng = np.random.default_rng(0)
    w = sys.stdout.write
    w(f"ring {args.ring} grow {args.grow} flying {args.flying} star {args.star}\n")
    w("| view | fruit px | mask beyond | fruit cut | beyond cut | cut |\n|---|---|---|---|---|---|\n")
    for name, (fruit, zf, zbg) in views().items():
        depth, mask, points = render(fruit, zf, zbg, args.ring, args.grow, args.flying, rng)
        occ = occlusion(depth, mask, points, CAM, eroded=1)
        cut = np.zeros(mask.shape, bool)
        if occ.overshoot is not None:
            cut[occ.v0 : occ.v0 + occ.overshoot.shape[0], occ.u0 : occ.u0 + occ.overshoot.shape[1]] = occ.overshoot
        beyond = mask & ~fruit
        w(f"| {name} | {fruit.sum()} | {beyond.sum()} | {(cut & fruit).sum()} | {(cut & beyond).sum()} | "
          f"{occ.seen_past} |\n")  # fmt: skip


if __name__ == "__main__":
    main()
