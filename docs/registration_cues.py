"""Is a frame's depth registered off its colour? Three cues per fruit, and the registration on a camera model whose
true shift is known (docs/ablation.md, "Registered depth").

    python docs/registration_cues.py [FRAMES_DIR]      # default examples/real-frames (the Azure Kinect spheres)
    python docs/registration_cues.py --model azure-kinect --n 12

For every fruit of every frame (its label in the frame's masks): the shift ``(du, dv)`` (pixels, depth pixel
``(u + du, v + dv)`` sees colour pixel ``(u, v)``) that ``core.surface.registration_shift`` finds for that fruit
alone; the same with the outline points left out where the depth cap runs on into a surface beside the mask (a
support) or ends at the search border; the image offset from the mask's centroid of the centre of a sphere fitted
to the depth pixels within 0.6 of the mask's equivalent radius of that centroid; and of the nearest depth point
(a paraboloid fitted to the median-filtered depth there). A sphere's nearest point and centre lie on one ray, so
on a well-registered frame the last two are near (0, 0) for spheres. ``--model``: rendered frames through a camera
model, the true shift of each against what ``symfruit.extract.register`` finds.
"""

import argparse
import sys

import numpy as np
from scipy import ndimage

from symfruit.core import surface
from symfruit.core.raster import inner_distance
from symfruit.extract import ExtractSettings, register

say = sys.stdout.write


def fruit_shift(depth, mask, focal, max_px, *, drop_supports):
    """The registration cost's best shift for one fruit's window, optionally without the support's outline points."""
    grown = ndimage.distance_transform_cdt(~mask, metric="taxicab") <= max_px
    inner = inner_distance(mask)
    found = surface.fruit_surface(depth, mask, focal, region=grown, inner=inner)
    if found is None:
        return None
    labels, _ = ndimage.label(found.pixels)
    cap = labels == labels[found.apex]
    edge = cap & ~ndimage.binary_erosion(cap)
    if drop_supports:
        near_cap = ndimage.grey_dilation(np.where(cap, depth, 0.0), size=5)
        runs_on = ~cap & (depth > 0) & (depth < near_cap + 0.01) & grown
        border = grown & ~ndimage.binary_erosion(grown)
        edge &= ~ndimage.binary_dilation(runs_on, iterations=2) & ~ndimage.binary_dilation(border)
    rows, cols = np.nonzero(edge)
    if len(rows) < 12:
        return None
    step = max(1, len(rows) // 160)
    inside = inner - ndimage.distance_transform_edt(~mask)
    outline = surface._Outline(rows[::step], cols[::step], inside, 0.3 * float(np.sqrt(mask.sum() / np.pi)))
    grid = np.stack(np.meshgrid(np.arange(-max_px, max_px + 1), np.arange(-max_px, max_px + 1), indexing="ij"), -1)
    grid = grid.reshape(-1, 2)
    dv, du = grid[int(np.argmin(outline.cost(grid, max_px, 0.7)))]
    return int(du), int(dv)


def sphere_and_apex(depth, mask, camera):
    """Image offsets (pixels) from the mask's centroid of a fitted sphere's centre and of the nearest depth point."""
    rows, cols = np.nonzero(mask)
    cy, cx, r = rows.mean(), cols.mean(), np.sqrt(mask.sum() / np.pi)
    vv, uu = np.mgrid[: depth.shape[0], : depth.shape[1]]
    near = (np.hypot(uu - cx, vv - cy) < 0.6 * r) & (depth > 0)
    z, u, v = depth[near], uu[near], vv[near]
    p = np.c_[(u - camera.cx) / camera.fx * z, (v - camera.cy) / camera.fy * z, z]
    sol = np.linalg.lstsq(np.c_[2 * p, np.ones(len(p))], (p**2).sum(axis=1), rcond=None)[0]
    centre = camera.project(sol[:3][None])[0]
    smooth = ndimage.median_filter(depth, 5)
    ok = near & (smooth > 0)
    yy, xx = np.nonzero(ok)
    a = np.linalg.lstsq(np.c_[xx**2, yy**2, xx, yy, np.ones(len(xx))].astype(float), smooth[ok], rcond=None)[0]
    apex = np.array([-a[2] / (2 * a[0]), -a[3] / (2 * a[1])])
    return centre - (cx, cy), apex - (cx, cy)


def real(folder):
    from symfruit.io.sources import open_source

    src = open_source(folder)
    max_px = ExtractSettings().registration_px
    for index, name in enumerate(src.names()):
        frame = src.read(index)
        depth = np.where(np.isfinite(frame.depth) & (frame.depth > 0), frame.depth, 0.0).astype(np.float64)
        focal = float(np.sqrt(frame.camera.fx * frame.camera.fy))
        _, whole = register(frame.masks, frame.depth, frame.camera)
        say(f"{name}: registration of the frame (du, dv) = {whole}\n")
        for k, sl in enumerate(ndimage.find_objects(frame.masks), 1):
            if sl is None:
                continue
            r0, c0 = max(sl[0].start - max_px - 8, 0), max(sl[1].start - max_px - 8, 0)
            win = (slice(r0, sl[0].stop + max_px + 8), slice(c0, sl[1].stop + max_px + 8))
            mask = frame.masks[win] == k
            a = fruit_shift(depth[win], mask, focal, max_px, drop_supports=False)
            b = fruit_shift(depth[win], mask, focal, max_px, drop_supports=True)
            centre, apex = sphere_and_apex(depth, frame.masks == k, frame.camera)
            say(
                f"  fruit {k}: registration alone {a}, without support and border points {b}; sphere centre "
                f"({centre[0]:+.1f}, {centre[1]:+.1f}) px, nearest point ({apex[0]:+.1f}, {apex[1]:+.1f}) px\n"
            )


def model(name, n):
    from symfruit.synthetic import scenes, sensors

    shifts = []
    apply = scenes.apply_sensor

    def keep(*args, **kwargs):
        out = apply(*args, **kwargs)
        shifts.append(out.shift)
        return out

    scenes.apply_sensor = keep
    errors = []
    for seed in range(n):
        scene = scenes._sensor_scene(seed, sensors.sensor_model(name), n_ripe=6, n_unripe=2, n_leaves=2)
        _, (du, dv) = register(scene.masks, scene.depth, scene.camera)
        tu, tv = shifts[-1]
        errors.append(np.hypot(du - tu, dv - tv))
        say(f"seed {seed}: true ({tu:+.1f}, {tv:+.1f}), found ({du:+d}, {dv:+d})\n")
    say(f"mean distance of the found shift from the true one: {np.mean(errors):.2f} px\n")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("frames", nargs="?", default="examples/real-frames")
    ap.add_argument("--model", help="a camera model of symfruit.synthetic.sensors instead of real frames")
    ap.add_argument("--n", type=int, default=12)
    args = ap.parse_args(argv)
    if args.model:
        model(args.model, args.n)
    else:
        real(args.frames)


if __name__ == "__main__":
    sys.exit(main())
