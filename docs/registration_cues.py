"""Is a frame's depth registered off its colour? Three cues per fruit, and the registration on a camera model whose
true shift is known (docs/ablation.md, "Registered depth").

    python docs/registration_cues.py [FRAMES_DIR]      # default examples/real-frames (the Azure Kinect spheres)
    python docs/registration_cues.py --model azure-kinect --n 12

For every fruit of every frame (its label in the frame's masks): the shift ``(du, dv)`` (pixels, depth pixel
``(u + du, v + dv)`` sees colour pixel ``(u, v)``) that ``core.surface.registration_shift`` finds for that fruit
alone; the same with the outline points left out where the depth cap runs on into a surface beside the mask (a
support) or ends at the search border; the image offset from the mask's centroid of the centre of a sphere fitted
to the depth pixels within 0.6 of the mask's equivalent radius of that centroid; and of the nearest depth point
(a paraboloid fitted to the median-filtered depth there); and of its outline's rim points on each side, how many
are free (a silhouette, not a junction with a support) and which axes the fruit tells (``core.surface._outline``).
A sphere's nearest point and centre lie on one ray, so
on a well-registered frame the last two are near (0, 0) for spheres. Per frame, the frame-wide edge cue
(``symfruit.core.edges.edge_shift``: the depth's outlines laid on the colour's edges, independent of the fruit's
outline cue): its best shift over the whole frame and with the fruit's masks (grown by the search radius) left
out, how sharp it is (the cost 2 px off the optimum along u and v, less the optimum's, and the shifts along each
axis within 0.1 px of the optimum's cost), and the shift each side of the outlines says (left/right: du, top/bottom:
dv; their difference is the time-of-flight band). ``--model``: rendered frames through a camera model, the true
shift of each against what ``symfruit.extract.register`` (the fruit-outline cue) and the edge cue find; the edge
cue also on the render's colour given texture and blur (the render's own colour is flat-shaded: its only edges
are the silhouettes, cleaner than a real camera's).
"""

import argparse
import sys

import numpy as np
from scipy import ndimage

from symfruit.core import edges, surface
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


def edge_cue(depth, color, masks, max_px):
    """The edge cue over the whole frame and with the fruit left out; one line each."""
    grown = ndimage.distance_transform_cdt(masks == 0, metric="taxicab") <= max_px
    lines = []
    for label, exclude in (("whole frame", None), ("fruit left out", grown)):
        r = edges.edge_shift(depth, color, max_px=max_px, exclude=exclude)
        m = max_px
        iu, iv = r.shift[0] + m, r.shift[1] + m
        along_u, along_v = r.cost[iv, :], r.cost[:, iu]
        span_u = np.flatnonzero(along_u <= along_u.min() + 0.1) - m
        span_v = np.flatnonzero(along_v <= along_v.min() + 0.1) - m
        sides = ", ".join(
            f"{k} {v[0]} ({v[1]} px, rise {v[2]:.2f})" if v[0] is not None else f"{k} - ({v[1]} px)"
            for k, v in r.sides.items()
        )
        bu, bv = r.balanced
        lines.append(
            f"  edge cue, {label}: (du, dv) = {r.shift} on {r.n_outline} outline px; rise at 2 px u {r.rise[0]:.2f}, "
            f"v {r.rise[1]:.2f} px; within 0.1 px of the optimum du {span_u.min()}..{span_u.max()}, dv "
            f"{span_v.min()}..{span_v.max()}; sides: {sides}; band {r.band}; sides balanced ({bu}, {bv})\n"
        )
    return r, lines


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
        for line in edge_cue(frame.depth, frame.color, frame.masks, max_px)[1]:
            say(line)
        for k, sl in enumerate(ndimage.find_objects(frame.masks), 1):
            if sl is None:
                continue
            r0, c0 = max(sl[0].start - max_px - 8, 0), max(sl[1].start - max_px - 8, 0)
            win = (slice(r0, sl[0].stop + max_px + 8), slice(c0, sl[1].stop + max_px + 8))
            mask = frame.masks[win] == k
            a = fruit_shift(depth[win], mask, focal, max_px, drop_supports=False)
            b = fruit_shift(depth[win], mask, focal, max_px, drop_supports=True)
            centre, apex = sphere_and_apex(depth, frame.masks == k, frame.camera)
            found = surface._outline(depth[win], mask, focal, max_px)
            free, told = "-", "-"
            if found is not None and found.sides is not None:
                names = ("top", "bottom", "left", "right")
                free = " ".join(f"{s} {f}/{n}" for s, (f, n) in zip(names, found.sides.tolist(), strict=True))
                told = "".join(a for a, t in zip("vu", found.axes, strict=True) if t) or "none"
            say(
                f"  fruit {k}: registration alone {a}, without support and border points {b}; sphere centre "
                f"({centre[0]:+.1f}, {centre[1]:+.1f}) px, nearest point ({apex[0]:+.1f}, {apex[1]:+.1f}) px; "
                f"free outline points {free}, axes told {told}\n"
            )


def textured(color, seed):
    """``color`` with a random blotch texture (+-20 % brightness, edges of its own) and a 1 px blur: edges that
    are not silhouettes, and soft ones, as a real camera's."""
    rng = np.random.default_rng(seed)
    h, w = color.shape[:2]
    blotch = ndimage.gaussian_filter(rng.normal(size=(h, w)), 6.0) > 0
    out = color.astype(np.float64) * np.where(blotch, 1.2, 0.8)[..., None]
    out = ndimage.gaussian_filter(out, (1.0, 1.0, 0))
    return np.clip(out, 0, 255).astype(np.uint8)


def model(name, n):
    from symfruit.synthetic import scenes, sensors

    shifts = []
    apply = scenes.apply_sensor

    def keep(*args, **kwargs):
        out = apply(*args, **kwargs)
        shifts.append(out.shift)
        return out

    scenes.apply_sensor = keep
    max_px = ExtractSettings().registration_px
    cues = ("fruit outline", "edge, 2D optimum", "edge, sides balanced", "edge, fruit left out, sides balanced",
            "edge, textured colour, sides balanced")  # fmt: skip
    errors = {c: ([], []) for c in cues}
    for seed in range(n):
        scene = scenes._sensor_scene(seed, sensors.sensor_model(name), n_ripe=6, n_unripe=2, n_leaves=2)
        _, found = register(scene.masks, scene.depth, scene.camera)
        grown = ndimage.distance_transform_cdt(scene.masks == 0, metric="taxicab") <= max_px
        whole = edges.edge_shift(scene.depth, scene.color, max_px=max_px)
        alone = edges.edge_shift(scene.depth, scene.color, max_px=max_px, exclude=grown)
        tex = edges.edge_shift(scene.depth, textured(scene.color, seed), max_px=max_px)
        tu, tv = shifts[-1]
        row = []
        answers = (found, whole.shift, whole.balanced, alone.balanced, tex.balanced)
        for cue, (du, dv) in zip(cues, answers, strict=True):
            for axis, (got, true) in enumerate(((du, tu), (dv, tv))):
                if got is not None:
                    errors[cue][axis].append(abs(got - true))
            row.append(f"{cue} ({_px(du)}, {_px(dv)})")
        sides = ", ".join(f"{k} {_px(v[0])}" for k, v in whole.sides.items())
        say(f"seed {seed}: true ({tu:+.1f}, {tv:+.1f}); " + "; ".join(row) + f"; edge sides: {sides}\n")
    for cue in cues:
        eu, ev = (np.array(e) for e in errors[cue])
        say(
            f"{cue}: mean absolute error u {eu.mean():.2f} px ({len(eu)} of {n} frames answer), v {ev.mean():.2f} px "
            f"({len(ev)} of {n}); answers off by more than 2 px: u {int((eu > 2).sum())}, v {int((ev > 2).sum())}\n"
        )


def _px(value):
    return "-" if value is None else f"{value:+g}"


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
