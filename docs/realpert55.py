"""The real Azure Kinect sphere frames (examples/real-frames), perturbed as issue 18's held-back frames differ from
them: farther (binned), annotators' masks (dilated, shifted), a leaf in front (drawn over, cut), a wider lost rim.

Every perturbation keeps the sensor's own depth noise and its own rim: it only bins, moves, erodes or puts in front
what the camera returned. Each perturbed frame is written as a frame folder and scored by the scorer of
``symfruit evaluate --spheres`` (:func:`symfruit.evaluate.spheres.evaluate_spheres`), with one change: the reference
diameter of every sphere is the one its *unperturbed* mask gives (the same method's box depth, the same frame), so a
dilated or cut mask is judged against the sphere, not against itself.

    PYTHONPATH=src python docs/realpert55.py run OUT [--only NAME,...] [--methods raw,sphere,...] [--config JSON]
    PYTHONPATH=src python docs/realpert55.py summary OUT [--methods evidence,...] [--compact]

``run`` writes ``OUT/frames/NAME/lab-spheres-{0,1}/`` and ``OUT/NAME.json`` (every box); ``summary`` prints one
Markdown table: per perturbation and method, the not-a-cube mean / worst, the depth side and larger lateral side
against the reference diameter (mean abs, signed mean), the frames' worst disagreement and the boxes over the
issue's 6 mm bar (not a cube or depth side; a failed box counts), the boxes that failed (no box: too few
points), and how far the boxes' centres lie from the unperturbed frame's boxes' (mean / worst). ``--compact``: one
row per perturbation, a column per method, the boxes over the bar (and the mean not-a-cube).
"""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy import ndimage

from symfruit.core.camera import Camera
from symfruit.core.frame import Frame
from symfruit.evaluate.spheres import SphereBox, evaluate_spheres
from symfruit.io.frames import read_frame, write_frame
from symfruit.settings import from_dict

FRAMES = Path(__file__).resolve().parent.parent / "examples" / "real-frames"
NAMES = ("lab-spheres-0", "lab-spheres-1")
METHODS = ("raw", "sphere", "ellipsoid", "superellipsoid", "paper", "evidence")
BAR_MM = 6.0  # issue 18's bar for balls
LEAF_GREEN = (60, 100, 40)  # a leaf's RGB (the `-green` perturbations: the leaf painted; docs/strip58.md)

Perturb = Callable[[Frame], tuple[np.ndarray, np.ndarray, np.ndarray, Camera]]  # colour, depth (m), masks, camera


def disk(r: int) -> np.ndarray:
    """A disk of radius ``r`` pixels (a structuring element)."""
    y, x = np.mgrid[-r : r + 1, -r : r + 1]
    return x * x + y * y <= r * r + r  # the +r: radius 1 the 3x3 square, 2 the 5x5 less its corners


def binned(frame: Frame, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, Camera]:
    """The frame seen by a camera with ``k`` x ``k`` pixels merged: depth the median of a block's valid pixels
    (none when fewer than half are valid: a block straddling the lost rim keeps the camera's invalidation), the
    masks the block's most common label (an annotator at the coarser resolution), the colour averaged, the
    intrinsics scaled (pixel centres: ``c' = (c + 0.5) / k - 0.5``)."""
    h, w = frame.depth.shape[0] // k * k, frame.depth.shape[1] // k * k
    d = (
        frame.depth[:h, :w]
        .astype(np.float64)
        .reshape(h // k, k, w // k, k)
        .transpose(0, 2, 1, 3)
        .reshape(h // k, w // k, -1)
    )
    valid = d > 0
    with warnings.catch_warnings():  # a block without depth: NaN, then none
        warnings.simplefilter("ignore", RuntimeWarning)
        med = np.nanmedian(np.where(valid, d, np.nan), axis=2)
    depth = np.where(valid.sum(axis=2) * 2 >= k * k, med, 0.0)
    m = frame.masks[:h, :w].reshape(h // k, k, w // k, k).transpose(0, 2, 1, 3).reshape(h // k, w // k, -1)
    ids = np.arange(int(frame.masks.max()) + 1)
    votes = (m[..., None] == ids).sum(axis=2)
    masks = ids[np.argmax(votes, axis=2)]  # ties to the lower id: the background first
    c = frame.color[:h, :w].astype(np.float64).reshape(h // k, k, w // k, k, 3).mean(axis=(1, 3))
    cam = frame.camera
    camera = Camera(fx=cam.fx / k, fy=cam.fy / k, cx=(cam.cx + 0.5) / k - 0.5, cy=(cam.cy + 0.5) / k - 0.5,
                    width=w // k, height=h // k)  # fmt: skip
    return np.rint(c).astype(np.uint8), depth, masks, camera


def dilated(frame: Frame, r: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, Camera]:
    """Every sphere's mask grown by ``r`` pixels onto the background (an annotator's generous outline; never onto
    another sphere)."""
    masks = frame.masks.copy()
    for k in np.unique(frame.masks[frame.masks > 0]):
        grown = ndimage.binary_dilation(frame.masks == k, disk(r))
        masks[grown & (masks == 0)] = k
    return frame.color, frame.depth, masks, frame.camera


def shifted(frame: Frame, du: int, dv: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, Camera]:
    """The masks moved by ``(du, dv)`` pixels against the depth and colour (an annotator's outline drawn on an
    image registered a few pixels off the depth)."""
    masks = np.zeros_like(frame.masks)
    h, w = masks.shape
    masks[max(dv, 0) : h + min(dv, 0), max(du, 0) : w + min(du, 0)] = frame.masks[
        max(-dv, 0) : h + min(-dv, 0), max(-du, 0) : w + min(-du, 0)
    ]
    return frame.color, frame.depth, masks, frame.camera


def noise_level(depth: np.ndarray) -> float:
    """The frame's own depth noise (metres): the spread of a valid pixel less the median of its 5 x 5
    neighbourhood, over pixels whose whole neighbourhood is valid and within 10 mm of that median (no edge, no
    rim); the mean absolute residual times sqrt(pi / 2), a normal law's standard deviation (a median absolute one
    is 0 on depth in whole millimetres)."""
    d = depth.astype(np.float64)
    full = ndimage.minimum_filter(d, size=5) > 0
    resid = (d - ndimage.median_filter(d, size=5))[full]
    resid = resid[np.abs(resid) < 0.01]
    return float(np.sqrt(np.pi / 2.0) * np.abs(resid).mean())


def rim_eroded(frame: Frame, r: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, Camera]:
    """The camera's lost rim ``r`` pixels wider: near every sphere (its mask grown by 20 px), a pixel within
    ``r`` of one without depth loses its own (a stricter mixed-pixel filter; where the sphere meets the board
    at its own depth nothing is lost, as on the camera)."""
    depth = frame.depth.copy()
    near = ndimage.binary_dilation(frame.masks > 0, disk(20))
    lost = ndimage.binary_dilation(depth <= 0, disk(r)) & near
    depth[lost] = 0.0
    return frame.color, depth, frame.masks, frame.camera


def leafed(
    frame: Frame, shape: str, gap: float, cut: bool, seed: int = 0, paint: tuple[int, int, int] | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, Camera]:
    """A leaf ``gap`` metres in front of every sphere's nearest seen point: ``shape`` ``side`` covers the left 35 %
    of the sphere's width (a half-plane), ``strip`` a horizontal band over the middle 20 % of its height, each
    reaching a quarter of the diameter past the mask (not over another sphere). The leaf's depth is flat plus
    the frame's own noise (:func:`noise_level`), and its edge loses depth as the camera's silhouettes do: a
    pixel of the leaf or behind it within 2 px of the leaf's edge has none (the mixed pixels the camera
    invalidates). ``cut``: the mask loses what the leaf hides (an annotator outlining the visible part); else the
    mask is drawn over the leaf (an annotator outlining the whole fruit). ``paint``: the leaf's pixels (its edge
    included) take this RGB colour plus a noise of 8 levels a channel (a leaf has a colour of its own; without, the
    colour image shows the fruit through it, and the colour trim compares a cut mask's band with the fruit itself:
    docs/strip58.md)."""
    rng = np.random.default_rng(seed)
    sigma = noise_level(frame.depth)
    depth, masks = frame.depth.astype(np.float64).copy(), frame.masks.copy()
    color = frame.color.copy() if paint is not None else frame.color
    tint = np.random.default_rng([seed, 1])  # its own stream: the depth is the unpainted leaf's to the bit
    ids = np.unique(frame.masks[frame.masks > 0])
    for k in ids:
        mine = frame.masks == k
        others = ndimage.binary_dilation((frame.masks > 0) & ~mine, disk(5))
        rows, cols = np.flatnonzero(mine.any(axis=1)), np.flatnonzero(mine.any(axis=0))
        r0, r1, c0, c1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
        pad = (c1 - c0) // 4
        yy, xx = np.mgrid[: masks.shape[0], : masks.shape[1]]
        inside = (yy >= r0 - pad) & (yy < r1 + pad) & (xx >= c0 - pad) & (xx < c1 + pad)
        if shape == "side":
            leaf = inside & (xx < c0 + 0.35 * (c1 - c0))
        else:
            mid, half = (r0 + r1) / 2.0, 0.1 * (r1 - r0)
            leaf = inside & (np.abs(yy - mid) <= half)
        leaf &= ~others
        seen = depth[mine & (depth > 0)]
        z = float(np.percentile(seen, 1)) - gap
        edge = ndimage.binary_dilation(leaf, disk(2)) & ~ndimage.binary_erosion(leaf, disk(2))
        depth[leaf] = z + sigma * rng.standard_normal(int(leaf.sum()))
        depth[edge & ~others] = 0.0
        if paint is not None:
            at = (leaf | edge) & ~others
            noise = 8.0 * tint.standard_normal((int(at.sum()), 3))
            color[at] = np.clip(np.asarray(paint, np.float64) + noise, 0, 255).astype(np.uint8)
        if cut:
            masks[leaf & mine] = 0
    return color, depth.astype(np.float32), masks, frame.camera


PERTURBATIONS: dict[str, Perturb] = {
    "none": lambda f: (f.color, f.depth, f.masks, f.camera),
    "bin2": lambda f: binned(f, 2),
    "bin3": lambda f: binned(f, 3),
    "dilate2": lambda f: dilated(f, 2),
    "dilate5": lambda f: dilated(f, 5),
    "dilate10": lambda f: dilated(f, 10),
    "shift+5x": lambda f: shifted(f, 5, 0),
    "shift-5x": lambda f: shifted(f, -5, 0),
    "shift+5y": lambda f: shifted(f, 0, 5),
    "shift-5y": lambda f: shifted(f, 0, -5),
    "shift+10x": lambda f: shifted(f, 10, 0),
    "shift+10y": lambda f: shifted(f, 0, 10),
    "leafside5-over": lambda f: leafed(f, "side", 0.05, cut=False),
    "leafside5-cut": lambda f: leafed(f, "side", 0.05, cut=True),
    "leafside15-over": lambda f: leafed(f, "side", 0.15, cut=False),
    "leafside15-cut": lambda f: leafed(f, "side", 0.15, cut=True),
    "leafstrip5-over": lambda f: leafed(f, "strip", 0.05, cut=False),
    "leafstrip5-cut": lambda f: leafed(f, "strip", 0.05, cut=True),
    "leafstrip5-over-green": lambda f: leafed(f, "strip", 0.05, cut=False, paint=LEAF_GREEN),
    "leafstrip5-cut-green": lambda f: leafed(f, "strip", 0.05, cut=True, paint=LEAF_GREEN),
    "leafside5-cut-green": lambda f: leafed(f, "side", 0.05, cut=True, paint=LEAF_GREEN),
    "rim1": lambda f: rim_eroded(f, 1),
    "rim2": lambda f: rim_eroded(f, 2),
    "rim3": lambda f: rim_eroded(f, 3),
    "bin2-dilate2": lambda f: dilated(_as_frame(f, binned(f, 2)), 2),
    "bin2-rim1": lambda f: rim_eroded(_as_frame(f, binned(f, 2)), 1),
}


def _as_frame(frame: Frame, parts: tuple[np.ndarray, np.ndarray, np.ndarray, Camera]) -> Frame:
    color, depth, masks, camera = parts
    return Frame(name=frame.name, color=color, depth=depth.astype(np.float32), camera=camera, masks=masks)


def write_perturbed(out: Path, name: str) -> Path:
    """``OUT/frames/NAME/``: both frames under perturbation ``name``."""
    folder = out / "frames" / name
    for frame_name in NAMES:
        frame = read_frame(FRAMES / frame_name)
        color, depth, masks, camera = PERTURBATIONS[name](frame)
        write_frame(folder / frame_name, color, np.asarray(depth, np.float64), camera, masks=masks, depth_scale=0.001)
    return folder


def run(out: Path, names: list[str], methods: tuple[str, ...], config: dict | None = None) -> None:
    out.mkdir(parents=True, exist_ok=True)
    settings = from_dict(config or {})
    for name in names:
        folder = write_perturbed(out, name)
        failed: dict[str, str] = {}
        rows = evaluate_spheres(folder, methods=methods, failed=failed, settings=settings)
        (out / f"{name}.json").write_text(json.dumps({"failed": failed, "rows": [r.__dict__ for r in rows]}))
        sys.stderr.write(f"{name}: {len(rows)} boxes {failed or ''}\n")


def load(out: Path, name: str) -> list[SphereBox]:
    path = out / f"{name}.json"
    if not path.is_file():  # a folder that is not a `run` output, or a run that has not reached this perturbation
        raise SystemExit(f"realpert55: {path}: no such file (`python docs/realpert55.py run {out}` writes it)")
    data = json.loads(path.read_text())
    return [SphereBox(**{**r, "size": tuple(r["size"]), **({"centre": tuple(r["centre"])} if "centre" in r else {})})
            for r in data["rows"]]  # fmt: skip


def compact(out: Path, methods: tuple[str, ...] | None) -> str:
    """One row per perturbation, one column per method: the boxes over the 6 mm bar (not a cube or depth side;
    failed boxes count) of all, and the mean not-a-cube (mm)."""
    table = summary(out, methods).splitlines()[2:]
    cells: dict[str, dict[str, str]] = {}
    for line in table:
        c = [x.strip() for x in line.strip("|").split("|")]
        cells.setdefault(c[0], {})[c[1].strip("`")] = f"{c[7]} ({c[2].split(' / ')[0]})"
    names = list(methods or dict.fromkeys(m for row in cells.values() for m in row))
    lines = ["| perturbation | " + " | ".join(f"`{m}`" for m in names) + " |", "|---|" + "---|" * len(names)]
    lines += [f"| {p} | " + " | ".join(row.get(m, "-") for m in names) + " |" for p, row in cells.items()]
    return "\n".join(lines) + "\n"


def centre_offsets(rows: list[SphereBox], unperturbed: dict[tuple[str, int, str], SphereBox]) -> np.ndarray:
    """How far (mm) each box's centre lies from the same method's box of the same sphere in the unperturbed frame:
    where the box is, which its sizes do not say (a mask drawn a few pixels off moves the whole box with it; stop
    61, docs/shift61.md). Boxes without a centre (results written before stop 61) or without an unperturbed box are
    left out."""
    found = []
    for r in rows:
        ref = unperturbed.get((r.frame, r.sphere, r.method))
        if ref is not None and not ref.error:
            found.append(float(np.linalg.norm(np.subtract(r.centre, ref.centre))))
    off = np.array(found)
    return off[np.isfinite(off)]


def _mean_worst(values: np.ndarray) -> str:
    return f"{values.mean():.1f} / {values.max():.1f}" if len(values) else "-"


def summary(out: Path, methods: tuple[str, ...] | None) -> str:
    unperturbed = {(r.frame, r.sphere, r.method): r for r in load(out, "none")}
    reference = {key: r.diameter for key, r in unperturbed.items()}
    lines = ["| perturbation | method | not a cube (mm), mean / worst | depth - diameter (mm), mean abs (mean) "
             "| lateral - diameter (mm), mean abs (mean) | frames differ (mm), worst | failed | over 6 mm "
             "| worst box | centre off the unperturbed box's (mm), mean / worst |",
             "|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for path in sorted(
        out.glob("*.json"), key=lambda p: list(PERTURBATIONS).index(p.stem) if p.stem in PERTURBATIONS else 99
    ):
        rows = [replace(r, diameter=reference[(r.frame, r.sphere, r.method)]) for r in load(out, path.stem)]
        for m in methods or tuple(dict.fromkeys(r.method for r in rows)):
            mine = [r for r in rows if r.method == m]
            ok = [r for r in mine if not r.error]
            if not ok:
                lines.append(f"| {path.stem} | `{m}` | - | - | - | - | {len(mine)} | {len(mine)} / {len(mine)} | | - |")
                continue
            cube = np.array([r.cube_mm for r in ok])
            depth = np.array([r.depth_mm for r in ok])
            lateral = np.array([r.lateral_mm for r in ok])
            differ = [float(np.ptp([r.size for r in ok if r.sphere == k], axis=0).max())
                      for k in {r.sphere for r in ok} if sum(r.sphere == k for r in ok) > 1]  # fmt: skip
            over = sum(r.cube_mm > BAR_MM or abs(r.depth_mm) > BAR_MM for r in ok) + len(mine) - len(ok)
            worst = max(ok, key=lambda r: max(r.cube_mm, abs(r.depth_mm)))
            off = centre_offsets(ok, unperturbed)
            lines.append(f"| {path.stem} | `{m}` | {cube.mean():.1f} / {cube.max():.1f} "
                         f"| {np.abs(depth).mean():.1f} ({depth.mean():+.1f}) "
                         f"| {np.abs(lateral).mean():.1f} ({lateral.mean():+.1f}) "
                         f"| {max(differ) if differ else float('nan'):.1f} | {len(mine) - len(ok)} "
                         f"| {over} / {len(mine)} | s{worst.sphere} {'x'.join(f'{v:.0f}' for v in worst.size)} "
                         f"(d {worst.diameter:.0f}) | {_mean_worst(off)} |")  # fmt: skip
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("out", type=Path)
    r.add_argument("--only", default="", help="comma-separated perturbations (default: all)")
    r.add_argument("--methods", default=",".join(METHODS))
    r.add_argument("--config", default="", help='settings as JSON text, e.g. \'{"extract": {"registration_px": 0}}\'')
    s = sub.add_parser("summary")
    s.add_argument("out", type=Path)
    s.add_argument("--methods", default="")
    s.add_argument("--compact", action="store_true", help="over 6 mm (mean not a cube) per perturbation and method")
    a = ap.parse_args(argv)
    if a.cmd == "run":
        names = [n for n in a.only.split(",") if n] or list(PERTURBATIONS)
        unknown = [n for n in names if n not in PERTURBATIONS]
        if unknown:
            ap.error(f"unknown perturbations {unknown}; known: {', '.join(PERTURBATIONS)}")
        if "none" not in names and not (a.out / "none.json").is_file():
            names = ["none", *names]  # the reference diameters
        run(a.out, names, tuple(a.methods.split(",")), json.loads(a.config) if a.config else None)
    else:
        show = compact if a.compact else summary
        sys.stdout.write(show(a.out, tuple(m for m in a.methods.split(",") if m) or None))


if __name__ == "__main__":
    main()
