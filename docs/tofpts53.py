"""``complete()`` on a time-of-flight camera's points alone (issue 18, stop 53; docs/tofpts53.md).

    python docs/tofpts53.py spheres [--grazing G ...]     # the real sphere frames, each sphere's points alone
    python docs/tofpts53.py pool RUN ... [--kinds]        # camera-protocol runs pooled over their seeds

``spheres`` takes each sphere's points as ``detect`` takes them (``examples/real-frames``, occlusion information
off: what ``symfruit evaluate --spheres examples/real-frames --config NOOCCL.yaml`` completes) and prints, per sphere:
the box ``evidence`` gives on them (``rim_grazing`` 0, then each ``--grazing``), its candidates' boxes, weights and
outline errors, the contour share and rim coverage, what the points' own edge says of the lost rim (the edge points'
``|cos|`` between their local plane's normal and the ray, quartiles: 7 x 7 pixel neighbourhoods as
``core.agreement``'s edge test takes them) and the diameter of the sphere through the seen front and the points'
edge ring (from the cap's sag), against the colour mask's diameter (``evaluate --spheres``' reference).

``pool`` reads each ``RUN`` (a glob of ``symfruit evaluate --output`` folders, one per seed, quoted) and prints
``evidence``'s IoU, centre deviation and side errors over all their views.
"""

from __future__ import annotations

import argparse
import csv
import glob
import sys
from pathlib import Path

import numpy as np

FRAMES = Path(__file__).resolve().parents[1] / "examples" / "real-frames"


def say(text: str) -> None:
    sys.stdout.write(text + "\n")


def _edge_cos(points: np.ndarray, camera, half: int = 3) -> np.ndarray:
    """``|cos|`` between each edge point's local plane normal (PCA of the points of the ``(2 half + 1)^2`` pixels
    around its own) and its ray, for the points within 1.5 px of their own region's edge."""
    from symfruit.core.agreement import _inside_px
    from symfruit.core.raster import close_ragged, inner_distance, silhouette

    region = close_ragged(silhouette(points, camera), radius=3, ragged=0.3)
    depth_px = _inside_px(points, region, camera, inner_distance(region.mask))
    uv = camera.project(points)
    h, w = region.mask.shape
    col = np.rint(uv[:, 0]).astype(int) - region.u0 + half
    row = np.rint(uv[:, 1]).astype(int) - region.v0 + half
    grid = np.full((h + 2 * half, w + 2 * half, 3), np.nan)
    grid[row, col] = points
    out = []
    for i in np.flatnonzero(depth_px <= 1.5):
        patch = grid[row[i] - half : row[i] + half + 1, col[i] - half : col[i] + half + 1].reshape(-1, 3)
        patch = patch[np.isfinite(patch[:, 0])]
        if len(patch) >= 6:
            normal = np.linalg.eigh(np.cov((patch - patch.mean(axis=0)).T))[1][:, 0]
            out.append(abs(float(normal @ points[i])) / float(np.linalg.norm(points[i])))
    return np.array(out)


def _sag_diameter(points: np.ndarray, camera) -> float:
    """The diameter of the sphere through the seen front and the points' edge ring: ``(r^2 + s^2) / s``, ``r`` the
    outline's equivalent half-width at the points' median depth, ``s`` the edge points' median depth behind the
    front (:func:`~symfruit.core.front.apex_depth`)."""
    from symfruit.core.agreement import _inside_px
    from symfruit.core.front import apex_depth
    from symfruit.core.raster import across_sight, close_ragged, inner_distance, silhouette

    region = close_ragged(silhouette(points, camera), radius=3, ragged=0.3)
    edge = points[_inside_px(points, region, camera, inner_distance(region.mask)) <= 1.5]
    sag = float(np.median(edge[:, 2])) - max(float(points[:, 2].min()), apex_depth(points)[0])
    a = across_sight(region, camera)
    r = 0.5 * np.sqrt(a.major * a.minor) * float(np.median(points[:, 2])) / float(a.axis[2])
    return float((r * r + sag * sag) / sag)


def spheres(grazings: list[float]) -> None:
    from symfruit import complete
    from symfruit.detect import detect
    from symfruit.io.sources import open_source
    from symfruit.settings import from_dict

    alone = from_dict({"occlusion": {"enabled": False}})
    src = open_source(FRAMES)
    try:
        for index, name in enumerate(src.names()):
            frame = src.read(index)
            for d in detect(frame, masks="auto", method="evidence", settings=alone).detections:
                points, cam = d.result.visible, frame.camera
                focal = float(np.sqrt(cam.fx * cam.fy))
                cos = _edge_cos(points, cam)
                quartiles = " / ".join(f"{q:.2f}" for q in np.quantile(cos, [0.25, 0.5, 0.75]))
                say(f"{name} sphere {d.id}: {len(points)} points, edge |cos| quartiles {quartiles} ({len(cos)} edge "
                    f"points), sphere through the cap's sag {1e3 * _sag_diameter(points, cam):.1f} mm")  # fmt: skip
                for grazing in [0.0, *grazings]:
                    r = complete(points, camera=cam, settings={"evidence": {"rim_grazing": grazing}})
                    e = r.extras
                    mask_mm = 2e3 * np.sqrt(d.mask.sum() / np.pi) * float(r.box.centre[2]) / focal
                    size = " x ".join(f"{v:.1f}" for v in 1e3 * r.box.size)
                    say(f"  rim_grazing {grazing}: box {size} mm (not a cube {1e3 * np.ptp(r.box.size):.1f}; mask "
                          f"diameter {mask_mm:.1f}), contour {e['contour']:.2f}, rim {e['rim']:.2f}, prior width "
                          f"{1e3 * e['width']:.1f} mm, back sd {1e3 * e['back_sd']:.1f} mm")  # fmt: skip
                    for cand, c in e["candidates"].items():
                        side = " x ".join(f"{v:.1f}" for v in 1e3 * (np.array(c["max"]) - c["min"]))
                        ev = (
                            ""
                            if c["evidence"] is None
                            else f" inside {c['evidence'][1]:.3f} outside {c['evidence'][2]:.3f}"
                        )
                        say(f"    {cand:<10} weight {e['weights'][cand]:.3f} energy {e['energies'][cand]:6.2f} "
                              f"{side} mm{ev}")  # fmt: skip
    finally:
        src.close()


def pool(runs: list[str], kinds: bool = False) -> None:
    for pattern in runs:
        rows: list[dict[str, str]] = []
        for path in sorted(glob.glob(pattern + "/latest/instances.csv")):
            with open(path, newline="") as f:
                rows += [r for r in csv.DictReader(f) if r["method"] == "evidence"]
        if not rows:
            say(f"{pattern}: no instances.csv")
            continue
        groups = sorted({r["fruit"] for r in rows}) if kinds else []
        for label, part in [(pattern, rows)] + [(f"  {g}", [r for r in rows if r["fruit"] == g]) for g in groups]:
            _pooled(label, part)


def _pooled(pattern: str, rows: list[dict[str, str]]) -> None:
    """One line: ``evidence``'s IoU, centre deviation and side errors over ``rows``."""

    def col(key: str) -> np.ndarray:
        return np.array([float(r[key]) if r[key] not in ("", "nan") else np.nan for r in rows])

    iou, centre, depth, lateral = col("iou"), col("centre_mm"), col("depth_mm"), col("lateral_mm")
    failed = sum(1 for r in rows if r["error"])
    say(f"{pattern}: {len(rows)} views ({failed} failed); IoU {np.nanmean(iou):.3f} / {np.nanmedian(iou):.3f} "
          f"(mean / median); centre {np.nanmean(centre):.2f} / {np.nanmedian(centre):.2f} mm, worst "
          f"{np.nanmax(centre):.1f}, over 10 mm {int((centre > 10).sum())}; depth side "
          f"{np.nanmean(abs(depth)):.1f} ({np.nanmean(depth):+.1f}) mm; larger lateral side "
          f"{np.nanmean(abs(lateral)):.1f} ({np.nanmean(lateral):+.1f}) mm")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    sph = sub.add_parser("spheres", help="the real sphere frames, each sphere's points alone")
    sph.add_argument("--grazing", type=float, nargs="*", default=[0.48], help="rim_grazing values besides 0")
    pl = sub.add_parser("pool", help="camera-protocol runs pooled over their seeds")
    pl.add_argument("runs", nargs="+", help="globs of --output folders, quoted")
    pl.add_argument("--kinds", action="store_true", help="and a line per fruit (kind, or scan) of each")
    args = parser.parse_args()
    if args.command == "spheres":
        spheres(args.grazing)
    else:
        pool(args.runs, args.kinds)


if __name__ == "__main__":
    main()
