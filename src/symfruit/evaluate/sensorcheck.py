"""The time-of-flight model against real Azure Kinect frames: the same measurements on both.

``python -m symfruit.evaluate.sensorcheck ../shared/data/real-frames`` measures, for every masked sphere
of every frame folder there (``color.png``, ``depth.png``, ``camera.json``, ``masks.png``), and for the
same spheres rendered through :data:`~symfruit.synthetic.sensors.SENSOR_MODELS` ``["azure-kinect"]``:

* the registration offset: the shift of the mask that best overlaps the depth silhouette (pixels near
  the sphere's depth), and that overlap (IoU);
* the invalid band: how many pixels of missing depth the silhouette adds across its outline (the excess
  share of zero depth within 8 px of the registered outline, summed over the normal distance);
* flying pixels: the share of pixels within 4 px of the outline whose depth lies between the sphere
  and its background;
* depth noise: the robust standard deviation (1.4826 MAD) of a sphere fitted to the inner part;
* the mask's pixels without depth, and with depth far behind the sphere (the background);
* the noise's correlation length (:func:`correlation_length`: the lag, colour pixels, at which the autocorrelation
  of the axial residuals of a sphere fitted to the pixels more than 0.1 radii inside the mask falls to 1/e; on a
  sphere it includes what the fit leaves, e.g. a bias with slope) and the residual against the surface's slope: the
  median axial residual where the surface turns 45-60 degrees from the ray (``|cos|`` 0.5-0.7) less the median where
  it faces the camera (``|cos|`` >= 0.85), millimetres (positive: too far at the slope);
* :func:`flat_patches`: the same noise statistics on flat background patches (48 x 48 pixels, fully valid, a
  plane fitted to each), away from the spheres: the cleanest measure of the noise's size and correlation.

The rendered spheres copy the lab frames' layout (sizes and distances read off the frames: about 190,
120, 64 and 60 mm across at 1.44, 1.27, 1.02 and 1.27 m, a wall 0.3-0.45 m behind); nothing of the
model is fitted to them.
"""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from ..core.camera import Camera
from ..core.raster import distance_transform

__all__ = [
    "correlation_length",
    "flat_patches",
    "flat_table",
    "measure_sphere",
    "model_flat",
    "model_frame",
    "real_flat",
    "real_frames",
    "table",
]

#: Lags (pixels) of the autocorrelation, and the share 1/e whose crossing is the correlation length.
LAGS = np.arange(1, 33)
_INV_E = math.exp(-1.0)


def correlation_length(residual: np.ndarray) -> float:
    """The lag (pixels, linear between lags) at which the autocorrelation of ``residual`` ((h, w), NaN where none)
    along rows and columns together first falls below 1/e; NaN with too few pairs, the last lag if it never does."""
    prev = 1.0
    for lag in LAGS:
        pairs = [(residual[:, :-lag], residual[:, lag:]), (residual[:-lag, :], residual[lag:, :])]
        a = np.concatenate([x[np.isfinite(x) & np.isfinite(y)] for x, y in pairs])
        b = np.concatenate([y[np.isfinite(x) & np.isfinite(y)] for x, y in pairs])
        if len(a) < 50 or a.std() == 0 or b.std() == 0:
            return float("nan")
        r = float(np.corrcoef(a, b)[0, 1])
        if r < _INV_E:
            return float(lag - 1 + (prev - _INV_E) / (prev - r))
        prev = r
    return float(LAGS[-1])


def _axial_residuals(pts: np.ndarray, shape: tuple[int, int], vv: np.ndarray, uu: np.ndarray) -> dict[str, float]:
    """A sphere fitted to ``pts`` (trimmed at 3 robust SD, 4 rounds); each point's depth less the fitted front's
    along its ray: their correlation length (:func:`correlation_length`) and the slope residual (module doc)."""
    keep = np.ones(len(pts), bool)
    for _ in range(4):
        p = pts[keep]
        sol, *_ = np.linalg.lstsq(np.c_[2 * p, np.ones(len(p))], (p**2).sum(axis=1), rcond=None)
        centre, radius = sol[:3], float(np.sqrt(max(sol[3] + sol[:3] @ sol[:3], 0.0)))
        res = np.linalg.norm(pts - centre, axis=1) - radius
        spread = 1.4826 * float(np.median(np.abs(res - np.median(res)))) + 1e-9
        keep = np.abs(res - np.median(res)) < 3 * spread
    ray = pts / pts[:, 2:3]
    a, b, c = (ray**2).sum(axis=1), -2 * ray @ centre, centre @ centre - radius * radius
    disc = b * b - 4 * a * c
    t = (-b - np.sqrt(np.maximum(disc, 0.0))) / (2 * a)
    normal = t[:, None] * ray - centre
    cos = np.abs((ray * normal).sum(axis=1)) / np.linalg.norm(ray, axis=1) / np.maximum(radius, 1e-9)
    ok = keep & (disc > 0)
    axial = pts[:, 2] - t
    img = np.full(shape, np.nan)
    img[vv[ok], uu[ok]] = axial[ok] - np.median(axial[ok])
    face, slope = ok & (cos >= 0.85), ok & (cos >= 0.5) & (cos < 0.7)
    at_slope = float(np.median(axial[slope]) - np.median(axial[face])) if slope.sum() >= 20 and face.any() else np.nan
    return {"corr_px": correlation_length(img), "slope_mm": 1000 * at_slope}


def flat_patches(depth: np.ndarray, labels: np.ndarray, *, size: int = 48, clear: int = 20) -> dict[str, float]:
    """Noise on flat background: every ``size``-pixel patch (a grid from the corner) fully valid, ``clear`` pixels
    from any mask, with a plane fitted (least squares on pixel coordinates) leaving a robust SD below 5 mm and no
    residual beyond 6 SD + 3 mm (a step); the medians of the patches' depth, robust SD (mm) and correlation length."""
    h, w = depth.shape
    vv, uu = np.mgrid[0:size, 0:size]
    near = np.zeros(depth.shape, bool) if not (labels > 0).any() else distance_transform(labels == 0) <= clear
    rows = []
    for r in range(0, h - size + 1, size):
        for c in range(0, w - size + 1, size):
            d = np.asarray(depth[r : r + size, c : c + size], dtype=np.float64)
            if (d <= 0).any() or near[r : r + size, c : c + size].any():
                continue
            a = np.c_[uu.ravel(), vv.ravel(), np.ones(size * size)]
            sol, *_ = np.linalg.lstsq(a, d.ravel(), rcond=None)
            e = (d.ravel() - a @ sol).reshape(size, size)
            sd = 1.4826 * float(np.median(np.abs(e)))
            if sd > 0.005 or np.abs(e).max() > 6 * sd + 0.003:
                continue
            rows.append((float(np.median(d)), sd, correlation_length(e)))
    if not rows:
        return {"patches": 0, "z": float("nan"), "noise_mm": float("nan"), "corr_px": float("nan")}
    z, sds, corr = (np.array(col) for col in zip(*rows, strict=True))
    return {"patches": len(rows), "z": float(np.median(z)), "noise_mm": 1000 * float(np.median(sds)),
            "corr_px": float(np.nanmedian(corr))}  # fmt: skip


def measure_sphere(depth: np.ndarray, mask: np.ndarray, camera: Camera, *, search: int = 25) -> dict[str, float]:
    """The measurements of the module docstring for one sphere (``mask``: its annotated pixels)."""
    rows, cols = np.nonzero(mask)
    r_px = float(np.sqrt(mask.sum() / np.pi))
    pad = int(r_px + search + 24)
    r0, r1 = max(rows.min() - pad, 0), min(rows.max() + pad + 1, depth.shape[0])
    c0, c1 = max(cols.min() - pad, 0), min(cols.max() + pad + 1, depth.shape[1])
    d = np.asarray(depth[r0:r1, c0:c1], dtype=np.float64)
    m = mask[r0:r1, c0:c1]
    inside = d[m & (d > 0)]
    z_front = float(np.percentile(inside, 5)) if len(inside) else 0.0
    r_m = r_px * z_front / camera.fx
    silhouette = (d > 0) & (d > z_front - 0.02) & (d < z_front + 1.2 * r_m)
    iou, du, dv = _best_shift(m, silhouette, search)
    reg = np.roll(np.roll(m, dv, axis=0), du, axis=1)
    sd = np.where(reg, distance_transform(reg), -distance_transform(~reg))
    zero = d == 0
    base_in = float(zero[(sd > 8) & (sd < 8 + r_px)].mean()) if ((sd > 8) & (sd < 8 + r_px)).any() else 0.0
    base_out = float(zero[(sd < -10) & (sd > -24)].mean())
    band = 0.0
    for s in range(-8, 9):
        ring = np.abs(sd - s) < 0.5
        if ring.any():
            band += max(0.0, float(zero[ring].mean()) - (base_in if s > 0 else base_out))
    background = d[(sd < -10) & (sd > -24) & (d > z_front + 1.2 * r_m)]
    z_back = float(np.median(background)) if len(background) else np.inf
    near = (np.abs(sd) <= 4) & (d > 0)
    flying = near & (d > z_front + 1.2 * r_m + 0.01) & (d < z_back - 0.02)
    vv, uu = np.nonzero((sd > 0.3 * r_px) & (d > 0))
    pts = Camera(fx=camera.fx, fy=camera.fy, cx=camera.cx - c0, cy=camera.cy - r0, width=c1 - c0,
                 height=r1 - r0).deproject(np.c_[uu, vv].astype(np.float64), d[vv, uu])  # fmt: skip
    noise = float("nan")
    if len(pts) >= 10:
        a = np.c_[2 * pts, np.ones(len(pts))]
        sol, *_ = np.linalg.lstsq(a, (pts**2).sum(axis=1), rcond=None)
        radius = float(np.sqrt(max(sol[3] + sol[:3] @ sol[:3], 0.0)))
        res = np.linalg.norm(pts - sol[:3], axis=1) - radius
        noise = float(1.4826 * np.median(np.abs(res - np.median(res))))
    vv, uu = np.nonzero((sd > 0.1 * r_px) & (d > 0) & (d < z_front + 1.2 * r_m))
    surface = {"corr_px": float("nan"), "slope_mm": float("nan")}
    if len(vv) >= 50:
        pts = Camera(fx=camera.fx, fy=camera.fy, cx=camera.cx - c0, cy=camera.cy - r0, width=c1 - c0,
                     height=r1 - r0).deproject(np.c_[uu, vv].astype(np.float64), d[vv, uu])  # fmt: skip
        surface = _axial_residuals(pts, d.shape, vv, uu)
    in_mask = d[m]
    return {**surface,
        "r_px": r_px, "z": z_front + r_m, "du": float(du), "dv": float(dv), "shift_px": float(np.hypot(du, dv)),
        "iou": iou, "band_px": band, "flying": float(flying.sum() / max(near.sum(), 1)), "noise_mm": noise * 1000,
        "mask_no_depth": float((in_mask == 0).mean()),
        "mask_background": float((in_mask > z_front + 2 * r_m + 0.02).mean()),
    }  # fmt: skip


def _best_shift(mask: np.ndarray, silhouette: np.ndarray, search: int) -> tuple[float, int, int]:
    """``(IoU, du, dv)``: the shift of ``mask`` (``np.roll`` by ``dv`` rows, then ``du`` columns; each within
    ``search`` pixels) that overlaps ``silhouette`` best, the first of equals in the order dv, then du, from
    ``-search``. Every shift's overlap at once: a circular cross-correlation of the two (h, w) bool images by FFT,
    its counts rounded back to the integers they are (below 2**31, far within float64's exact range)."""
    h, w = mask.shape
    spectrum = np.fft.rfft2(silhouette.astype(np.float64)) * np.conj(np.fft.rfft2(mask.astype(np.float64)))
    overlap = np.rint(np.fft.irfft2(spectrum, s=(h, w))).astype(np.int64)  # [dv % h, du % w]
    shifts = np.arange(-search, search + 1)
    inter = overlap[np.ix_(shifts % h, shifts % w)]  # (dv, du)
    union = int(mask.sum()) + int(silhouette.sum()) - inter  # a shift moves the mask's pixels, never drops one
    iou = inter / np.maximum(union, 1)
    k = int(np.argmax(iou))  # the first of equals, as a loop over dv, then du, keeping only a larger IoU would
    return float(iou.flat[k]), int(shifts[k % len(shifts)]), int(shifts[k // len(shifts)])


def frame_spheres(folder: str | Path) -> Iterator[tuple[str, int, np.ndarray, np.ndarray, Camera]]:
    """Every sphere of every frame folder under ``folder`` (the lab frames' layout: ``depth.png``, ``masks.png``,
    ``camera.json``): its frame's name, its label, the frame's depth (metres), its mask and the camera."""
    from PIL import Image

    for frame in sorted(p for p in Path(folder).iterdir() if (p / "depth.png").is_file()):
        meta = json.loads((frame / "camera.json").read_text())
        cam = Camera(meta["fx"], meta["fy"], meta["cx"], meta["cy"], meta["width"], meta["height"])
        depth = np.asarray(Image.open(frame / "depth.png"), dtype=np.float64) * float(meta.get("depth_scale", 0.001))
        labels = np.asarray(Image.open(frame / "masks.png"))
        for k in np.unique(labels[labels > 0]):
            yield frame.name, int(k), depth, labels == k, cam


def real_frames(folder: str | Path) -> list[dict[str, Any]]:
    """Measure every sphere of every frame folder under ``folder``."""
    return [{"frame": name, "sphere": k, **measure_sphere(depth, mask, cam)}
            for name, k, depth, mask, cam in frame_spheres(folder)]  # fmt: skip


#: The lab frames' layout: (diameter m, centre depth m, u, v at 1920x1080), read off the frames.
LAB_SPHERES = ((0.19, 1.44, 1148, 420), (0.12, 1.27, 905, 483), (0.064, 1.02, 1052, 588), (0.06, 1.27, 1290, 531))


def lab_meshes(cam: Camera) -> list[tuple[np.ndarray, np.ndarray]]:
    """The lab frames' layout as meshes (vertices, faces) for ``cam``: the four spheres of :data:`LAB_SPHERES`
    (mesh ids 0-3) and the flat background 1.73 m away (id 4)."""
    from ..synthetic.shapes import _revolve

    meshes = []
    for diameter, z, u, v in LAB_SPHERES:
        t = np.linspace(0, np.pi, 90)
        ball = _revolve(diameter / 2 * np.sin(t), -diameter / 2 * np.cos(t), name="ball", n_phi=96)
        centre = cam.deproject(np.array([u, v], float), np.array(z))
        meshes.append((ball.vertices + centre, ball.faces))
    wall = np.array([[-3.0, -3.0, 1.73], [3.0, -3.0, 1.73], [3.0, 3.0, 1.73], [-3.0, 3.0, 1.73]])
    meshes.append((wall, np.array([[0, 1, 2], [0, 2, 3]])))
    return meshes


def _model_shot(name: str, seed: int, sensor_set: object = ()) -> tuple[np.ndarray, np.ndarray, Camera]:
    """The lab layout rendered through the sensor model ``name`` (``sensor_set`` varied, seeded): (depth, masks,
    camera)."""
    from ..synthetic.render import render
    from ..synthetic.sensors import SENSOR_MODELS, apply_sensor, varied

    model = varied(SENSOR_MODELS[name], sensor_set)
    cam = model.camera()
    shot = render(lab_meshes(cam), cam)
    labels = np.where((shot.ids >= 0) & (shot.ids < len(LAB_SPHERES)), shot.ids + 1, 0)
    out = apply_sensor(model, shot.depth, shot.ids, cam, np.random.default_rng(seed), facing=shot.facing,
                       labels=labels)  # fmt: skip
    return np.asarray(out.depth, dtype=np.float64), np.asarray(out.labels), cam


def model_frame(name: str = "azure-kinect", seed: int = 0, sensor_set: object = ()) -> list[dict[str, Any]]:
    """The lab spheres rendered through a sensor model and measured as the real ones."""
    depth, masks, cam = _model_shot(name, seed, sensor_set)
    return [{"frame": f"{name} model, seed {seed}", "sphere": k, **measure_sphere(depth, masks == k, cam)}
            for k in range(1, len(LAB_SPHERES) + 1)]  # fmt: skip


def real_flat(folder: str | Path) -> list[dict[str, Any]]:
    """:func:`flat_patches` of every frame folder under ``folder``."""
    from PIL import Image

    out = []
    for frame in sorted(p for p in Path(folder).iterdir() if (p / "depth.png").is_file()):
        meta = json.loads((frame / "camera.json").read_text())
        depth = np.asarray(Image.open(frame / "depth.png"), dtype=np.float64) * float(meta.get("depth_scale", 0.001))
        out.append({"frame": frame.name, **flat_patches(depth, np.asarray(Image.open(frame / "masks.png")))})
    return out


def model_flat(name: str = "azure-kinect", seed: int = 0, sensor_set: object = ()) -> dict[str, Any]:
    """:func:`flat_patches` of the lab layout rendered through a sensor model (its wall, 1.73 m)."""
    depth, masks, _ = _model_shot(name, seed, sensor_set)
    return {"frame": f"{name} model, seed {seed}", **flat_patches(depth, masks)}


def table(rows: list[dict[str, Any]]) -> str:
    """Markdown: one row per sphere."""
    head = ("| frame | sphere | across (px) | depth (m) | registration (du, dv) px | IoU | invalid band (px) "
            "| flying share | noise (mm) | mask without depth | mask on background | correlation length (px) "
            "| residual at slope (mm) |")  # fmt: skip
    lines = [head, "|" + "---|" * 13]
    for r in rows:
        lines.append(f"| {r['frame']} | {r['sphere']} | {2 * r['r_px']:.0f} | {r['z']:.2f} | ({r['du']:+.0f}, "
                     f"{r['dv']:+.0f}) | {r['iou']:.2f} | {r['band_px']:.1f} | {r['flying']:.3f} | "
                     f"{r['noise_mm']:.1f} | {r['mask_no_depth']:.0%} | {r['mask_background']:.0%} | "
                     f"{r['corr_px']:.1f} | {r['slope_mm']:+.1f} |")  # fmt: skip
    return "\n".join(lines)


def flat_table(rows: list[dict[str, Any]]) -> str:
    """Markdown: one row per frame's flat background patches."""
    lines = ["| frame | flat patches | depth (m) | noise (mm) | correlation length (px) |", "|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['frame']} | {r['patches']} | {r['z']:.2f} | {r['noise_mm']:.2f} | {r['corr_px']:.1f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    folder = args[0] if args else "../shared/data/real-frames"
    rows = real_frames(folder) + model_frame(seed=0) + model_frame(seed=1)
    flats = real_flat(folder) + [model_flat(seed=0), model_flat(seed=1)]
    sys.stdout.write(table(rows) + "\n\n" + flat_table(flats) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
