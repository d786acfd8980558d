"""Points alone from a time-of-flight camera: elongated outlines and the L515 (issue 18, stop 54; docs/rim54.md).

    python docs/rim54.py spheroids SENSOR [--elong E ...] [--seeds N] [--grow PX]
    python docs/rim54.py diagnose SENSOR [--seeds N]

``spheroids`` renders spheroids (``--elong``: half-length along their axis over their radius; 1 a ball, above 1
prolate, a lemon; below 1 oblate, an apple) with their axis in the image plane at a random angle, 0.6-1.2 m before
the sensor model with a wall 0.15 m behind, takes their points as ``detect`` does (:func:`symfruit.extract.extract`),
and completes them alone: without ``rim_grazing`` (``none``); with 0.48 and stop 53's round-section rim
(``round``: :func:`symfruit.methods.evidence.lost_rim`, the outline grown by its equivalent radius times
``1 / sqrt(1 - 0.48^2) - 1``); with 0.48 and the rim of each part of the outline (``local``:
:func:`local_lost_rim`, stop 54's dropped variant, kept here); each of those two with ``prior_tilt: cap``
(``round+cap``, ``local+cap``). ``--grow PX``: also the seen region grown by ``PX`` pixels where the gate stays
shut (``grown``: the L515's edge loss, tried and dropped). It prints each variant's mean side error (x, y, depth;
the box's minus the mesh's box's) and mean centre deviation, mm.

``diagnose`` prints, per ball (``--elong 1``), its points' depth range, how far they reach from its centre on each
side, and ``evidence``'s candidates on the points alone and with the frame's occlusion information: where a shallow
box comes from.
"""

from __future__ import annotations

import argparse
import math
import sys
from typing import Any

import numpy as np
from scipy import ndimage


def say(text: str) -> None:
    sys.stdout.write(text + "\n")


def view(name: str, seed: int, elong: float) -> tuple[np.ndarray, Any, np.ndarray, np.ndarray, Any]:
    """``(points, camera, true centre, true box size, occlusion information)`` of one spheroid's view."""
    from symfruit.core.camera import Camera
    from symfruit.core.occlusion import occlusion
    from symfruit.extract import extract
    from symfruit.synthetic.render import render
    from symfruit.synthetic.sensors import SENSOR_MODELS, apply_sensor
    from symfruit.synthetic.shapes import _revolve

    model, rng = SENSOR_MODELS[name], np.random.default_rng(seed)
    full = model.camera()
    z, a = rng.uniform(0.6, 1.2), rng.uniform(0.03, 0.045)
    b = a / elong
    spin = rng.uniform(0, np.pi)
    t = np.linspace(0, np.pi, 90)
    mesh = _revolve(b * np.sin(t), -a * np.cos(t), name="spheroid", n_phi=96)
    c, s = np.cos(spin), np.sin(spin)
    centre = np.array([rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), z])
    posed = mesh.transformed(np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), centre)
    u, v = full.project(centre[None])[0]
    reach = 2.0 * full.fx * max(a, b) / z + 24
    c0, r0 = int(u - reach), int(v - reach)
    cam = Camera(fx=full.fx, fy=full.fy, cx=full.cx - c0, cy=full.cy - r0, width=int(2 * reach),
                 height=int(2 * reach))  # fmt: skip
    wall = np.array([[-3.0, -3.0, 0.15], [3.0, -3.0, 0.15], [3.0, 3.0, 0.15], [-3.0, 3.0, 0.15]]) + [0.0, 0.0, z]
    shot = render([(posed.vertices, posed.faces), (wall, np.array([[0, 1, 2], [0, 2, 3]]))], cam)
    out = apply_sensor(model, shot.depth, shot.ids, cam, rng, facing=shot.facing,
                       labels=(shot.ids == 0).astype(np.int32))  # fmt: skip
    mask, depth = np.asarray(out.labels) == 1, np.asarray(out.depth, dtype=float)
    points = extract(mask, depth, cam).points
    lo, hi = posed.vertices.min(axis=0), posed.vertices.max(axis=0)
    return points, cam, 0.5 * (lo + hi), hi - lo, occlusion(depth, mask, points, cam)


def rim_scale(seen_major: float, seen_minor: float, grazing: float) -> tuple[float, float]:
    """``(along the major axis, along the minor)``: how much wider than the outline a camera that returns no depth
    where ``|cos| < grazing`` (the surface's normal against the ray) leaves of a spheroid seen from its side is its
    silhouette, from that outline's half-widths (any unit; only their ratio is read).

    An ellipsoid ``x^2/a^2 + y^2/b^2 + z^2/c^2 = 1`` seen along ``z`` is last seen where its normal makes ``|cos| = g``
    with the ray: the ellipse of half-widths ``a sqrt((1 - g^2) / (1 - g^2 + g^2 c^2 / a^2))`` and the same in ``b``.
    With the depth half-width ``c`` the minor's ``b`` (a section across the long axis is round, the section a
    solid of revolution shows from its side; a round outline's, a sphere's), the minor half-width shrinks by
    ``sqrt(1 - g^2)`` and the major by less, the more so the longer it is (at the tips the surface curves with
    radius ``b^2 / a``): ``A^2 (1 - g^2) a^2 + A^2 g^2 b^2 = (1 - g^2) a^4`` gives ``a`` from the seen ``A``.

    >>> [round(v, 4) for v in rim_scale(1.0, 1.0, 0.6)]  # a round outline: both 1 / sqrt(1 - g^2)
    [1.25, 1.25]
    >>> [round(v, 4) for v in rim_scale(2.0, 1.0, 0.6)]  # twice as long: its tips lose less
    [1.0887, 1.25]
    """
    k = 1.0 - grazing * grazing
    minor = 1.0 / math.sqrt(k)
    if seen_major <= 0.0 or seen_minor <= 0.0:
        return minor, minor
    b = seen_minor * minor
    ratio = b * b / (seen_major * seen_major)  # (b / A)^2
    return math.sqrt(0.5 * (1.0 + math.sqrt(1.0 + 4.0 * grazing * grazing * ratio / k))), minor


def local_lost_rim(region: Any, grazing: float, camera: Any = None, *, least: float = 0.0) -> Any:
    """``region`` grown by the rim a camera that returns no depth where ``|cos| < grazing`` (the surface's normal
    against the ray) loses of a spheroid seen from its side: stretched about its centroid along the principal axes of
    its pixels by :func:`rim_scale` of its half-widths there (a round outline by ``1 / sqrt(1 - grazing^2)``: the
    last seen point of a circle of radius ``R`` lies at ``R sqrt(1 - grazing^2)`` from its centre; an elongated one
    by the rim of its minor half-width across, less towards its tips), and by ``least`` pixels (a disk) wherever that
    stretch moves the outline less; within ``camera``'s image when given. Unchanged when it moves the outline under
    half a pixel everywhere.
    """
    from symfruit.core.raster import Silhouette

    mask = region.mask
    rows, cols = np.nonzero(mask)
    if len(rows) == 0:
        return region
    centre = np.array([cols.mean(), rows.mean()])
    offset = np.c_[cols, rows] - centre
    var, vec = np.linalg.eigh(offset.T @ offset / len(rows) + np.eye(2) / 12.0)  # pixel squares, not their centres
    half = 2.0 * np.sqrt(var)  # a filled ellipse's half-widths along its principal axes (minor, major)
    along, across = rim_scale(float(half[1]), float(half[0]), grazing)
    reach = np.abs(offset @ vec).max(axis=0) + 0.5  # the outline's farthest pixel edge along each axis
    moved = reach * (np.array([across, along]) - 1.0)
    if moved.max() < 0.5 and least < 0.5:
        return region
    pad = math.ceil(max(float(moved.max()), least)) + 1
    h, w = mask.shape
    v0, u0 = region.v0 - pad, region.u0 - pad
    grid_v, grid_u = np.mgrid[: h + 2 * pad, : w + 2 * pad]
    # each pixel of the grown window taken back to the outline by the inverse stretch: inside if it lands inside
    back = vec @ np.diag([1.0 / across, 1.0 / along]) @ vec.T
    du, dv = grid_u - pad - centre[0], grid_v - pad - centre[1]
    col = np.rint(centre[0] + back[0, 0] * du + back[0, 1] * dv).astype(np.intp)
    row = np.rint(centre[1] + back[1, 0] * du + back[1, 1] * dv).astype(np.intp)
    ok = (col >= 0) & (col < w) & (row >= 0) & (row < h)
    grown = np.zeros(grid_u.shape, dtype=bool)
    grown[ok] = mask[row[ok], col[ok]]
    if least >= 0.5:
        px = math.ceil(least)
        d = np.arange(-px, px + 1)
        disk = d[:, None] ** 2 + d[None, :] ** 2 <= least * least
        grown |= ndimage.binary_dilation(np.pad(mask, pad), structure=disk)
    if camera is not None:  # within the image: the camera saw nothing beyond it
        c0, r0 = max(0, -u0), max(0, -v0)
        c1 = min(grown.shape[1], camera.width - u0)
        r1 = min(grown.shape[0], camera.height - v0)
        grown, u0, v0 = grown[r0:r1, c0:c1], u0 + c0, v0 + r0
    rows, cols = np.nonzero(grown)  # the window cut to the grown region
    grown = grown[rows.min() : rows.max() + 1, cols.min() : cols.max() + 1]
    return Silhouette(int(u0 + cols.min()), int(v0 + rows.min()), np.ascontiguousarray(grown), region.fill_radius)


def spheroids(name: str, elongs: list[float], seeds: int, grow: float) -> None:
    import symfruit.methods.evidence as ev
    from symfruit import complete

    tree, gated = ev.lost_rim, ev._rim_region

    def shut_grown(sample, region, camera, points, pixels, s):
        out = gated(sample, region, camera, points, pixels, s)
        return tree(region, 0.0, camera, least=grow) if out is region else out

    told = {"rim_grazing": 0.48}
    variants: dict[str, tuple[Any, Any, dict[str, Any]]] = {
        "none": (tree, gated, {}),
        "round": (tree, gated, told),
        "local": (local_lost_rim, gated, told),
        "round+cap": (tree, gated, {**told, "prior_tilt": "cap"}),
        "local+cap": (local_lost_rim, gated, {**told, "prior_tilt": "cap"}),
    }
    if grow > 0:
        variants[f"grown {grow:g} px"] = (tree, shut_grown, told)
    for elong in elongs:
        errors: dict[str, list[np.ndarray]] = {key: [] for key in variants}
        for seed in range(seeds):
            points, cam, centre, size, _ = view(name, seed, elong)
            for key, (rim, region, settings) in variants.items():
                ev.lost_rim, ev._rim_region = rim, region
                try:
                    r = complete(points, camera=cam, settings={"evidence": settings})
                finally:
                    ev.lost_rim, ev._rim_region = tree, gated
                off = 1e3 * np.linalg.norm(r.box.centre - centre)
                errors[key].append(np.r_[1e3 * (r.box.size - size), off])
        for key, rows in errors.items():
            e = np.array(rows)
            sides = " / ".join(f"{v:+.1f}" for v in e[:, :3].mean(axis=0))
            say(f"{name} elong {elong:g}, {key:>12}: side error x / y / depth {sides} mm (depth mean abs "
                f"{np.abs(e[:, 2]).mean():.1f}), centre {e[:, 3].mean():.2f} mm")  # fmt: skip


def diagnose(name: str, seeds: int) -> None:
    from symfruit import complete

    for seed in range(seeds):
        points, cam, centre, size, occ = view(name, seed, 1.0)
        z, half = float(centre[2]), 0.5 * float(size[2])
        say(f"seed {seed}: ball {1e3 * size[2]:.1f} mm at {z:.2f} m, {len(points)} points; the ball's front / centre "
            f"{1e3 * (z - half):.1f} / {1e3 * z:.1f} mm, the points' nearest / 99th percentile / farthest "
            f"{1e3 * points[:, 2].min():.1f} / {1e3 * np.quantile(points[:, 2], 0.99):.1f} / "
            f"{1e3 * points[:, 2].max():.1f} mm")  # fmt: skip
        lateral = points[:, :2] / points[:, 2:3] * z - centre[:2]  # each point's pixel, at the centre's depth
        reach = [-lateral[:, 0].min(), lateral[:, 0].max(), -lateral[:, 1].min(), lateral[:, 1].max()]
        say(f"  the points reach -x / +x / -y / +y {' / '.join(f'{1e3 * r:.1f}' for r in reach)} mm from the centre "
            f"against the ball's {1e3 * half:.1f} ({1e3 * z / cam.fx:.2f} mm a pixel)")  # fmt: skip
        for label, kw in (("alone", {}), ("frame", {"occlusion": occ})):
            r = complete(points, camera=cam, **kw)
            e = r.extras
            box = " x ".join(f"{v:.1f}" for v in 1e3 * r.box.size)
            say(f"  {label}: box {box} mm, contour {e['contour']:.2f}, rim {e['rim']:.2f}, prior width "
                f"{1e3 * e['width']:.1f} mm, back sd {1e3 * e['back_sd']:.1f} mm")  # fmt: skip
            for cand, c in e["candidates"].items():
                side = " x ".join(f"{v:.1f}" for v in 1e3 * (np.array(c["max"]) - c["min"]))
                say(f"    {cand:<10} weight {e['weights'][cand]:.3f} energy {e['energies'][cand]:6.2f} {side} mm")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    sp = sub.add_parser("spheroids", help="spheroids' points alone through a sensor model")
    sp.add_argument("sensor")
    sp.add_argument("--elong", type=float, nargs="*", default=[1.0, 1.4, 0.7])
    sp.add_argument("--seeds", type=int, default=6)
    sp.add_argument("--grow", type=float, default=0.0, help="also grow a shut gate's region by this many pixels")
    dg = sub.add_parser("diagnose", help="balls' candidates, points alone and with the frame")
    dg.add_argument("sensor")
    dg.add_argument("--seeds", type=int, default=6)
    args = parser.parse_args()
    if args.command == "spheroids":
        spheroids(args.sensor, args.elong, args.seeds, args.grow)
    else:
        diagnose(args.sensor, args.seeds)


if __name__ == "__main__":
    main()
