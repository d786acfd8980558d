"""Masks moved up or down on the real Azure Kinect sphere frames (docs/realpert55.py): what the colour trim takes, side
by side, and why (docs/shift61.md, issue 18).

    PYTHONPATH=src python docs/shift61.py sides PERTURBATION [--config JSON]
    PYTHONPATH=src python docs/shift61.py separation PERTURBATION [--frame 0|1]

``sides``: for both frames and every sphere, the frame's registration, the pixels of the drawn mask that
``detect``'s colour trim took, by side (the quadrants about the drawn mask's centroid: top, bottom, left, right), the
``evidence`` box's rows (projected at its centre depth, on the colour image's pixels) against the unperturbed mask's
rows, the box's size (mm) and its centre less the unperturbed frame's box centre (mm). ``separation``: for every
sphere, the colour trim's own test at the band ``extract.trim_mask`` uses (:func:`symfruit.core.surface.colour_trim`):
the share of the fruit sample (the pixels 4-13 px inside the mask) and of the ring sample (1-5 px outside it) that
their k-means summaries class right (the trim acts only where both reach 0.85), and the ring's mean brightness and
share read as fruit on its top and bottom.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import sys
from pathlib import Path

import numpy as np

say = sys.stdout.write


def _realpert():  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location("realpert55", Path(__file__).with_name("realpert55.py"))
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


def _quadrants(rows: np.ndarray, cols: np.ndarray, r0: float, c0: float) -> dict[str, np.ndarray]:
    a = np.degrees(np.arctan2(rows - r0, cols - c0))
    top, bottom = (a > -135) & (a < -45), (a > 45) & (a < 135)
    return {"top": top, "bottom": bottom, "left": np.abs(a) >= 135, "right": np.abs(a) <= 45}


def sides(name: str, config: dict) -> None:
    from symfruit.core.frame import Frame
    from symfruit.detect import detect
    from symfruit.io import read_frame
    from symfruit.settings import from_dict

    rp = _realpert()
    settings = from_dict(config) if config else None
    for i, frame_name in enumerate(rp.NAMES):
        frame = read_frame(rp.FRAMES / frame_name)
        color, depth, masks, cam = rp.PERTURBATIONS[name](frame)
        perturbed = Frame(name=frame_name, color=color, depth=depth.astype(np.float32), camera=cam, masks=masks)
        found = detect(perturbed, method="evidence", settings=settings)
        base = {d.id: d.result.box for d in detect(frame, method="evidence", settings=settings).detections if d.result}
        du, dv = found.registration
        moved = cam.shifted(du, dv)
        for d in found.detections:
            drawn = masks == d.id
            rr, cc = np.nonzero(drawn)
            kept = np.roll(d.mask, (-dv, -du), axis=(0, 1))  # the detection's mask back on the colour's pixels
            vv, uu = np.nonzero(drawn & ~kept)
            taken = {k: int(v.sum()) for k, v in _quadrants(vv, uu, rr.mean(), cc.mean()).items()}
            true = np.flatnonzero((frame.masks == d.id).any(axis=1))
            if d.result is None:
                say(f"{name} frame {i} s{d.id}: {d.error}\n")
                continue
            b = d.result.box
            zc = 0.5 * (b.min[2] + b.max[2])
            top, bottom = (moved.fy * y / zc + moved.cy - dv for y in (b.min[1], b.max[1]))
            size = " x ".join(f"{v:.1f}" for v in (b.max - b.min) * 1000)
            off = " ".join(f"{v:+.1f}" for v in (b.centre - base[d.id].centre) * 1000) if d.id in base else "-"
            say(f"{name} frame {i} registration {found.registration} s{d.id}: taken {int(sum(taken.values()))} "
                  f"{taken}; box rows {top:.1f}-{bottom:.1f}, unperturbed mask {true[0]}-{true[-1]}; "
                  f"size {size} mm; centre - unperturbed's {off} mm\n")  # fmt: skip


def separation(name: str, frame_index: int) -> None:
    from symfruit.core import surface
    from symfruit.core.raster import inner_distance
    from symfruit.io import read_frame

    rp = _realpert()
    frame = read_frame(rp.FRAMES / rp.NAMES[frame_index])
    color, _, masks, _ = rp.PERTURBATIONS[name](frame)
    for k in range(1, int(masks.max()) + 1):
        mask = masks == k
        band = min(4.0, 0.2 * float(np.sqrt(mask.sum() / np.pi)))  # trim_mask's band at the default colour_trim_px
        inner = inner_distance(mask)
        fruit = (inner > band) & (inner <= 3.0 * band + 1)
        ring = ~mask & surface.within(mask, band + 1)
        f_fruit, f_ring = surface._colour_features(color, fruit), surface._colour_features(color, ring)
        rng = np.random.default_rng(0)  # the trim's own draws (surface._seeded)
        picks = [rng.choice(len(x), min(len(x), surface._SAMPLE), replace=False) for x in (f_fruit, f_ring)]
        fc, bc = (surface._kmeans(x[p], x[p][np.linspace(0, len(p) - 1, 3).astype(int)], 5)
                  for x, p in zip((f_fruit, f_ring), picks, strict=True))  # fmt: skip
        as_fruit = surface._nearer_fruit(f_ring, fc, bc, 1.0)
        acc_fruit = float(surface._nearer_fruit(f_fruit, fc, bc, 1.0).mean())
        acc_ring = float((~as_fruit).mean())
        rr, cc = np.nonzero(mask)
        vv, uu = np.nonzero(ring)
        q = _quadrants(vv, uu, rr.mean(), cc.mean())
        bright = color[vv, uu].mean(axis=1)
        verdict = "separate" if min(acc_fruit, acc_ring) >= 0.85 else "do not separate"
        say(f"{name} s{k}: accuracy fruit {acc_fruit:.2f} ring {acc_ring:.2f} ({verdict} at {band:.0f} px); "
              f"ring brightness top {bright[q['top']].mean():.0f} bottom {bright[q['bottom']].mean():.0f}, read as "
              f"fruit top {as_fruit[q['top']].mean():.2f} bottom {as_fruit[q['bottom']].mean():.2f}; fruit sample "
              f"brightness {color[fruit].mean():.0f}\n")  # fmt: skip


def mask_edge_shift(color: np.ndarray, labels: np.ndarray, *, max_px: int = 10, cap: float = 6.0,
                    keep: float = 0.7) -> tuple[tuple[int, int], dict[str, int | None], float, float]:  # fmt: skip
    """The frame-wide shift ``(du, dv)`` that lays the masks' outlines on the colour's edges, told per axis by its
    two opposite sides (a what-if, not in the library).

    The oriented, truncated chamfer of :func:`symfruit.core.edges.edge_shift` with the masks' outline pixels (each
    mask's pixels next to one outside it, oriented by the smoothed mask's gradient) in place of the depth's. Each
    side of the outlines (top, bottom, left, right: where the gradient is mostly vertical or horizontal) gives its
    best shift along the axis it constrains, the other axis free. An axis is moved only where its two sides agree
    within two pixels (a mask drawn off moves both sides one way; a generous mask pulls them apart, and a side alone
    cannot tell a shift from an overshoot; the edge's maximum lies between a mask's last pixel and the first outside
    it, so a side of a mask drawn right reads 0 or a pixel outwards: the unperturbed spheres' top -1 and bottom
    +1), by the two sides' mean, rounded towards none. Returns the shift, each
    side's best, and the trimmed costs at the shift and at none (pixels)."""
    from scipy import ndimage

    from symfruit.core import edges
    from symfruit.core.raster import distance_transform

    h, w = labels.shape
    eg, eb = edges.colour_edges(color)
    parts = []
    for k in np.unique(labels[labels > 0]):
        mask = labels == k
        rows, cols = np.nonzero(mask & ~ndimage.binary_erosion(mask))
        smooth = ndimage.gaussian_filter(mask.astype(float), 1.5)
        gx, gy = ndimage.sobel(smooth, axis=1)[rows, cols], ndimage.sobel(smooth, axis=0)[rows, cols]
        parts.append((rows, cols, gx, gy))
    rows, cols, gx, gy = (np.concatenate([p[i] for p in parts]) for i in range(4))
    bins = edges._orientation_bin(gx, gy)
    dist = np.empty((edges.N_BINS, h, w), np.float32)
    for b in range(edges.N_BINS):
        near = eg & np.isin(eb, [(b - 1) % edges.N_BINS, b, (b + 1) % edges.N_BINS])
        dist[b] = np.minimum(distance_transform(~near), cap) if near.any() else cap
    m = int(max_px)
    every = np.full((2 * m + 1, 2 * m + 1, len(rows)), cap, np.float32)  # (dv, du, pixel)
    for i, dv in enumerate(range(-m, m + 1)):
        for j, du in enumerate(range(-m, m + 1)):
            rr, cc = rows + dv, cols + du  # the masks moved by (du, dv)
            ok = (rr >= 0) & (rr < h) & (cc >= 0) & (cc < w)
            every[i, j, ok] = dist[bins[ok], rr[ok], cc[ok]]

    def trimmed(values: np.ndarray) -> np.ndarray:
        k = max(1, round(keep * values.shape[-1]))
        return np.sort(values, axis=-1)[..., :k].mean(axis=-1)

    # the smoothed mask rises into the mask: the top side's gradient points down (+v), the left side's right (+u)
    vertical, horizontal = np.abs(gy) > 2.0 * np.abs(gx), np.abs(gx) > 2.0 * np.abs(gy)
    select = {"top": vertical & (gy > 0), "bottom": vertical & (gy < 0), "left": horizontal & (gx > 0),
              "right": horizontal & (gx < 0)}  # fmt: skip
    best: dict[str, int | None] = {}
    for name, sel in select.items():
        if sel.sum() < 20:
            best[name] = None
            continue
        per = trimmed(every[:, :, sel])
        profile = per.min(axis=1) if name in ("top", "bottom") else per.min(axis=0)
        best[name] = int(np.argmin(profile)) - m
    shift = []
    for a, b in (("left", "right"), ("top", "bottom")):
        x, y = best[a], best[b]
        shift.append(int(np.fix((x + y) / 2)) if x is not None and y is not None and abs(x - y) <= 2 else 0)
    cost = trimmed(every)
    return (shift[0], shift[1]), best, float(cost[shift[1] + m, shift[0] + m]), float(cost[m, m])


def cue(names: list[str]) -> None:
    from symfruit.io import read_frame

    rp = _realpert()
    for name in names:
        folders = sorted(p for p in Path(name).iterdir() if p.is_dir()) if Path(name).is_dir() else None
        for i, frame_name in enumerate(rp.NAMES if folders is None else [p.name for p in folders]):
            if folders is None:
                color, _, masks, _ = rp.PERTURBATIONS[name](read_frame(rp.FRAMES / frame_name))
            else:
                frame = read_frame(folders[i])
                color, masks = frame.color, frame.masks
            shift, sides, at, none = mask_edge_shift(color, masks)
            say(f"{name} {frame_name}: shift {shift}, sides {sides}, cost {at:.2f} px (none {none:.2f})\n")


def run(out: Path, names: list[str]) -> None:
    """``OUT/NAME.json`` as ``docs/realpert55.py run`` writes it (``evidence`` alone), each frame's masks moved by
    :func:`mask_edge_shift` before ``detect``: ``python docs/realpert55.py summary OUT`` reads it."""
    from symfruit.evaluate.spheres import evaluate_spheres
    from symfruit.io.frames import read_frame, write_frame

    rp = _realpert()
    out.mkdir(parents=True, exist_ok=True)
    for name in ["none", *[n for n in names if n != "none"]]:
        folder = out / "frames" / name
        for frame_name in rp.NAMES:
            color, depth, masks, camera = rp.PERTURBATIONS[name](read_frame(rp.FRAMES / frame_name))
            (du, dv), _, _, _ = mask_edge_shift(color, masks)
            moved = np.roll(masks, (dv, du), axis=(0, 1))  # the masks lie far from the image's border
            write_frame(folder / frame_name, color, np.asarray(depth, np.float64), camera, masks=moved,
                        depth_scale=0.001)  # fmt: skip
            say(f"{name} {frame_name}: masks moved by {(du, dv)}\n")
        failed: dict[str, str] = {}
        rows = evaluate_spheres(folder, methods=("evidence",), failed=failed)
        (out / f"{name}.json").write_text(json.dumps({"failed": failed, "rows": [r.__dict__ for r in rows]}))


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("sides", help="the colour trim's take by side and the box's rows, per sphere")
    s.add_argument("perturbation")
    s.add_argument("--config", default="", help="settings as JSON text")
    p = sub.add_parser("separation", help="the colour trim's fruit and ring samples, per sphere")
    p.add_argument("perturbation")
    p.add_argument("--frame", type=int, default=0, choices=(0, 1))
    c = sub.add_parser("cue", help="the masks' shift to the colour's edges (perturbation names or frame folders)")
    c.add_argument("names", nargs="+")
    r = sub.add_parser("run", help="realpert55's perturbations scored with the masks moved by the cue")
    r.add_argument("out", type=Path)
    r.add_argument("--only", default="", help="comma-separated perturbations (default: all)")
    a = ap.parse_args(argv)
    if a.cmd == "sides":
        sides(a.perturbation, json.loads(a.config) if a.config else {})
    elif a.cmd == "separation":
        separation(a.perturbation, a.frame)
    elif a.cmd == "cue":
        cue(a.names)
    else:
        run(a.out, [n for n in a.only.split(",") if n] or list(_realpert().PERTURBATIONS))


if __name__ == "__main__":
    main()
