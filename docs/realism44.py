"""The rim of a sphere through a time-of-flight camera: where depth stops against the colour outline (stop 44).

``python docs/realism44.py [--sensor-set NAME=V,...] [--seeds 0,1] [--real examples/real-frames]``

For every sphere of the shared real Azure Kinect frames (``examples/real-frames``: circles fitted to the spheres'
colour outlines) and of the same lab layout rendered through the ``azure-kinect`` model
(``symfruit.evaluate.sensorcheck``'s layout; the mask is the render's true silhouette, not the annotators' grown
one), in the outline's *silhouette sectors* (10-degree sectors about the circle's centre whose ring 10-20 px outside
holds depth 5 cm or more behind the sphere's centre: the sphere against its background, not against the board it
stands on), each pixel within 25 px of the outline is classed by its depth: ``sphere`` (within 2 cm in front of the
sphere's front and its centre's depth + 2 cm), ``background`` (within 3 cm of the sector's background or beyond),
``flying`` (between), ``none`` (no depth). Printed:

* the profile: the share of each class against the signed distance from the outline ``s`` (colour px, positive
  inside), pooled over the silhouette sectors;
* ``stop``: where the sphere's share falls to one half, coming out from inside (colour px inside the outline), and
  ``bg``: where the background's share reaches one half, going out (px outside; negative: inside);
* the same stop as the surface's facing ``|cos|`` (``sqrt(1 - (sin t / sin a)^2)``, ``t`` the ray's angle from the
  circle's centre ray, ``a`` the circle's angular radius: exact for a sphere whose silhouette is the circle);
* the sphere's share against ``|cos|`` inside the outline;
* the flying share: flying pixels among the pixels with depth within 4 px of the outline (sensorcheck's measure,
  here in silhouette sectors only);
* the registration: ``stop(theta) = s0 + a cos(theta) + b sin(theta)`` fitted over the silhouette sectors (each
  sector's own half-share crossing); ``(a, b)`` colour px is where depth sits against colour (positive ``a``: depth
  right of colour), ``s0`` the mean stop with the offset taken out.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from symfruit.core.camera import Camera

S_BINS = np.arange(-15, 26)  # signed distance from the outline, colour px (positive inside)
COS_EDGES = np.array([0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.85, 1.0])
SECTORS = 36


def _crossing(values: np.ndarray, share: np.ndarray, *, rising: bool) -> float:
    """First value (walking ``values`` in order) where ``share`` crosses 0.5, linear between bins; NaN if never."""
    ok = np.isfinite(share)
    v, s = values[ok], share[ok]
    for i in range(1, len(s)):
        a, b = s[i - 1], s[i]
        if (rising and a < 0.5 <= b) or (not rising and a >= 0.5 > b):
            return float(v[i - 1] + (0.5 - a) / (b - a) * (v[i] - v[i - 1]))
    return float("nan")


def profile(depth: np.ndarray, mask: np.ndarray, camera: Camera) -> dict:
    """The rim profile of one sphere (``mask``: its outline as a filled disc) in ``depth`` (metres, 0 none)."""
    rows, cols = np.nonzero(mask)
    cv, cu = rows.mean(), cols.mean()
    r_px = math.sqrt(mask.sum() / math.pi)
    pad = int(r_px + 30)
    r0, r1 = max(int(cv) - pad, 0), min(int(cv) + pad + 1, depth.shape[0])
    c0, c1 = max(int(cu) - pad, 0), min(int(cu) + pad + 1, depth.shape[1])
    d = np.asarray(depth[r0:r1, c0:c1], dtype=np.float64)
    vv, uu = np.mgrid[r0:r1, c0:c1]
    rad = np.hypot(uu - cu, vv - cv)
    s = r_px - rad
    theta = np.arctan2(vv - cv, uu - cu)
    sector = ((theta + np.pi) / (2 * np.pi) * SECTORS).astype(int) % SECTORS
    inner = d[(s > 0.3 * r_px) & (d > 0)]
    z_front = float(np.percentile(inner, 5))

    # The circle's angular radius and each pixel's angle from its centre ray: |cos| of a sphere with that silhouette.
    def ray(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        x = np.stack([(u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, np.ones_like(u, dtype=float)], -1)
        return x / np.linalg.norm(x, axis=-1, keepdims=True)

    c_ray = ray(np.array(cu), np.array(cv))
    edge_ray = ray(np.array(cu + r_px), np.array(cv))
    sin_a = math.sqrt(max(0.0, 1 - float(c_ray @ edge_ray) ** 2))
    cos_t = np.clip(ray(uu.astype(float), vv.astype(float)) @ c_ray, -1, 1)
    sin_t = np.sqrt(1 - cos_t**2)
    facing = np.sqrt(np.clip(1 - (sin_t / sin_a) ** 2, 0, 1))
    r_m = z_front * sin_a / max(1e-9, 1 - sin_a)  # sphere radius from its front depth and angular size
    z_c = z_front + r_m
    sphere = (d > z_front - 0.02) & (d < z_c + 0.02)
    out_ring = (s < -10) & (s > -20)
    silhouette = np.zeros(SECTORS, bool)
    z_bg = np.full(SECTORS, np.inf)
    for k in range(SECTORS):
        ring = d[out_ring & (sector == k)]
        if len(ring) and (ring > z_c + 0.05).mean() > 0.5:
            silhouette[k] = True
            z_bg[k] = float(np.median(ring[ring > z_c + 0.05]))
    sil = silhouette[sector]
    bg_z = z_bg[sector]
    background = (d > 0) & (d > bg_z - 0.03)
    none = d == 0
    flying = (d > 0) & ~sphere & ~background
    bins = np.rint(s).astype(int)
    share = {name: np.full(len(S_BINS), np.nan) for name in ("sphere", "background", "flying", "none")}
    for i, b in enumerate(S_BINS):
        sel = sil & (bins == b)
        if sel.sum() >= 10:
            for name, cls in (("sphere", sphere), ("background", background), ("flying", flying), ("none", none)):
                share[name][i] = cls[sel].mean()
    order = np.argsort(-S_BINS)  # from inside outwards
    stop = _crossing(S_BINS[order].astype(float), share["sphere"][order], rising=False)
    bg = _crossing(S_BINS[order].astype(float), share["background"][order], rising=True)
    by_cos = np.full(len(COS_EDGES) - 1, np.nan)
    for i in range(len(COS_EDGES) - 1):
        sel = sil & (s > 0) & (facing >= COS_EDGES[i]) & (facing < COS_EDGES[i + 1])
        if sel.sum() >= 10:
            by_cos[i] = sphere[sel].mean()
    stop_cos = math.sqrt(max(0.0, 1 - ((r_px - stop) / r_px) ** 2)) if np.isfinite(stop) else float("nan")
    near = sil & (np.abs(s) <= 4) & (d > 0)
    fly_share = float(flying[near].mean()) if near.any() else float("nan")
    # Registration: each silhouette sector's own stop.
    ks, stops = [], []
    for k in np.nonzero(silhouette)[0]:
        col = np.full(len(S_BINS), np.nan)
        for i, b in enumerate(S_BINS):
            sel = (sector == k) & (bins == b)
            if sel.sum() >= 3:
                col[i] = sphere[sel].mean()
        st = _crossing(S_BINS[order].astype(float), col[order], rising=False)
        if np.isfinite(st):
            ks.append(k)
            stops.append(st)
    reg = (float("nan"),) * 3
    if len(ks) >= 6:
        ang = (np.array(ks) + 0.5) / SECTORS * 2 * np.pi - np.pi
        a = np.c_[np.ones(len(ang)), np.cos(ang), np.sin(ang)]
        sol, *_ = np.linalg.lstsq(a, np.array(stops), rcond=None)
        # stop = r_px - r_depth: the depth's outline r_depth(theta) = r_px - s0 - a cos - b sin, centre moved -(a, b)
        reg = (float(sol[0]), float(-sol[1]), float(-sol[2]))
    return {
        "r_px": r_px,
        "z": z_c,
        "r_m": r_m,
        "sectors": int(silhouette.sum()),
        "stop": stop,
        "bg": bg,
        "stop_cos": stop_cos,
        "by_cos": by_cos,
        "fly_share": fly_share,
        "s0": reg[0],
        "reg": reg[1:],
        **share,
    }


def sides(depth: np.ndarray, mask: np.ndarray, camera: Camera) -> dict:
    """Left, right and top of one sphere (90-degree sectors about the outline's centre): where the sphere's depth
    stops (first bin, coming out from 16 px inside, below half), where the background's starts (first bin at half or
    more; None: not a silhouette there) and the flying pixels within 4 px; and the share of pixels with the sphere's
    depth against ``|cos|`` over the left and right sectors together (a registration across cancels to first order)."""
    rows, cols = np.nonzero(mask)
    cv, cu = rows.mean(), cols.mean()
    r_px = math.sqrt(mask.sum() / math.pi)
    vv, uu = np.mgrid[0 : depth.shape[0], 0 : depth.shape[1]]
    rad = np.hypot(uu - cu, vv - cv)
    s = r_px - rad
    th = np.arctan2(vv - cv, uu - cu)
    z_front = np.percentile(depth[(s > 0.3 * r_px) & (depth > 0)], 5)
    z_c = z_front * (1 + r_px / camera.fx)
    sphere = (depth > z_front - 0.02) & (depth < z_c + 0.02)
    bg = depth > z_c + 0.1
    out: dict = {}
    for name, sel in (
        ("left", np.abs(np.abs(th) - np.pi) < np.pi / 4),
        ("right", np.abs(th) < np.pi / 4),
        ("top", np.abs(th + np.pi / 2) < np.pi / 4),
    ):
        stop = start = None
        flying = near = 0
        for b in range(16, -9, -1):
            x = sel & (np.rint(s) == b)
            if stop is None and sphere[x].mean() < 0.5:
                stop = b
            if start is None and bg[x].mean() >= 0.5:
                start = b
            if abs(b) <= 4:
                flying += int(((depth[x] > 0) & ~sphere[x] & ~bg[x]).sum())
                near += int(x.sum())
        out[name] = (stop, start, flying, near)
    facing = np.sqrt(1 - np.clip(rad / r_px, 0, 1) ** 2)
    lr = (np.abs(np.sin(th)) < math.sin(math.pi / 4)) & (s > 0)
    out["by_cos"] = [
        float(sphere[lr & (facing >= a) & (facing < b)].mean())
        for a, b in zip(COS_EDGES[:-1], COS_EDGES[1:] + (COS_EDGES[1:] == 1.0) * 0.01, strict=True)
    ]
    return out


def real(folder: str) -> list[tuple[str, int, dict]]:
    from symfruit.evaluate.sensorcheck import frame_spheres

    return [(name, k, {**profile(depth, mask, cam), **sides(depth, mask, cam)})
            for name, k, depth, mask, cam in frame_spheres(folder)]  # fmt: skip


def model(name: str, seed: int, sensor_set: object) -> list[tuple[str, int, dict]]:
    """The lab layout of ``symfruit.evaluate.sensorcheck`` through ``name``; masks the true silhouettes."""
    from symfruit.evaluate.sensorcheck import LAB_SPHERES, lab_meshes
    from symfruit.synthetic.render import render
    from symfruit.synthetic.sensors import SENSOR_MODELS, apply_sensor, varied

    m = varied(SENSOR_MODELS[name], sensor_set)
    cam = m.camera()
    shot = render(lab_meshes(cam), cam)
    fr = apply_sensor(m, shot.depth, shot.ids, cam, np.random.default_rng(seed), facing=shot.facing)
    depth = np.asarray(fr.depth, dtype=np.float64)
    tag = f"{name} seed {seed} (shift {fr.shift[0]:+.1f}, {fr.shift[1]:+.1f})"
    return [
        (tag, k + 1, {**profile(depth, shot.ids == k, cam), **sides(depth, shot.ids == k, cam)})
        for k in range(len(LAB_SPHERES))
    ]


def report(rows: list[tuple[str, int, dict]]) -> None:
    def print(*parts: str) -> None:
        sys.stdout.write(" ".join(parts) + "\n")

    print(
        "| frame | sphere | r (px) | z (m) | silhouette sectors | depth stops (px inside) | at |cos| | background "
        "from (px outside) | no-depth band (px) | flying share | registration fit (a, b) px, s0 |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for frame, k, p in rows:
        print(
            f"| {frame} | {k} | {p['r_px']:.0f} | {p['z']:.2f} | {p['sectors']} | {p['stop']:.1f} | "
            f"{p['stop_cos']:.2f} | {-p['bg']:.1f} | {p['stop'] - p['bg']:.1f} | {p['fly_share']:.3f} | "
            f"({p['reg'][0]:+.1f}, {p['reg'][1]:+.1f}), {p['s0']:.1f} |"
        )
    print()
    print("sphere share against |cos| (bins " + ", ".join(f"{a:.2f}" for a in COS_EDGES[:-1]) + "):")
    for frame, k, p in rows:
        print(f"  {frame} {k}: " + " ".join("  -  " if not np.isfinite(x) else f"{x:.2f}" for x in p["by_cos"]))
    print()
    print("left / right / top: depth stops at (px inside), background from (px inside; None: none within 8 px out),")
    print("flying pixels within 4 px; then the left and right sectors' share with the sphere's depth against |cos|:")
    for frame, k, p in rows:
        cells = [f"{n} {p[n][0]}, {p[n][1]}, {p[n][2]}/{p[n][3]}" for n in ("left", "right", "top")]
        cos = " ".join(f"{x:.2f}" for x in p["by_cos"])
        print(f"  {frame} {k}: " + "; ".join(cells) + " | " + cos)
    print()
    print("profile (s px: sphere / flying / none / background), pooled per sphere:")
    for frame, k, p in rows:
        cells = []
        for i, b in enumerate(S_BINS):
            if b % 2 == 0 and -12 <= b <= 16:
                cells.append(
                    f"{b:+d}:{p['sphere'][i]:.2f}/{p['flying'][i]:.2f}/{p['none'][i]:.2f}/{p['background'][i]:.2f}"
                )
        print(f"  {frame} {k}: " + " ".join(cells))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--real", default="examples/real-frames")
    ap.add_argument("--sensor", default="azure-kinect")
    ap.add_argument("--sensor-set", default="")
    ap.add_argument("--seeds", default="0,1")
    ap.add_argument("--no-real", action="store_true")
    args = ap.parse_args()
    from symfruit.synthetic.sensors import parse_sensor_set

    changes = parse_sensor_set(args.sensor_set) if args.sensor_set else ()
    rows = [] if args.no_real else real(args.real)
    for seed in (int(x) for x in args.seeds.split(",") if x):
        rows += model(args.sensor, seed, changes)
    report(rows)


if __name__ == "__main__":
    main()
