"""Stop 63 (docs/support63.md): a grown mask on the support a real sphere stands on, read by depth and by an oracle.

Two probes on the real Azure Kinect sphere frames (``examples/real-frames``) and their perturbed copies by
``docs/realpert55.py`` (``OUT/frames/NAME/lab-spheres-K``; written here when missing):

- ``profiles``: for every sphere of a frame, along rays from its drawn mask's centroid in each of
  ``core.occlusion.SECTORS`` sectors, where the depth ends or turns against the drawn mask's outline: in the sectors
  where the depth runs on across the outline (a support or a neighbour at the sphere's depth, continuous as
  ``core.occlusion._joined`` reads it), the depth's slope inside and outside the outline and where the depth turns
  (its greatest value along the ray: the crease between the sphere's receding cap and the support coming nearer);
  in the sectors where the camera saw past the sphere, how far inside the outline its last depth lies.
- ``oracle``: ``detect``'s boxes (method ``evidence``) when extraction is told which of a grown mask's pixels lie on
  the support: the pixels beyond the drawn mask in the sectors where the depth runs on across the grown mask's
  outline. They are taken from the points and the silhouette extraction hands on (``Extraction.silhouette``), and
  with ``--not-hidden`` also from the occlusion map's hidden pixels (a support the fruit does not continue behind).
  Each box against the unperturbed frame's (its centre's offset, its sizes and the 6 mm bar of realpert55).

    PYTHONPATH=src python docs/support63.py profiles examples/real-frames/lab-spheres-0
    PYTHONPATH=src python docs/support63.py oracle OUT dilate10 [--not-hidden]
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import realpert55 as RP

from symfruit import detect as D
from symfruit.core.occlusion import SECTORS, SLOPE
from symfruit.io.frames import read_frame

#: The depth step across an outline still read as one surface: extraction's least convexity tolerance (3 mm) plus the
#: frames' 1 mm unit, plus :data:`~symfruit.core.occlusion.SLOPE` pixel footprints (``_joined``'s reading).
LEAST_TOL = 0.004


def _continuous(z_in: float, z_out: float, focal: float) -> bool:
    return z_in > 0 and z_out > 0 and abs(z_in - z_out) <= LEAST_TOL + SLOPE * min(z_in, z_out) / focal


def _deepest(depth: np.ndarray, mask: np.ndarray, focal: float) -> float:
    """The farthest depth of the fruit under ``mask``: beyond it the camera saw past the fruit (its front, the 2nd
    percentile of the mask's depth, plus half the mask's width, as ``core.occlusion._seen_past`` reads it)."""
    z = depth[mask & (depth > 0)]
    front = float(np.percentile(z, 2)) if len(z) else np.inf
    return front + float(np.sqrt(mask.sum() / np.pi)) * front / focal + LEAST_TOL


def _ray(mask: np.ndarray, r0: float, c0: float, angle: float, reach: int) -> tuple[np.ndarray, np.ndarray, int]:
    t = np.arange(reach)
    rr = np.clip(np.rint(r0 + t * np.sin(angle)).astype(int), 0, mask.shape[0] - 1)
    cc = np.clip(np.rint(c0 + t * np.cos(angle)).astype(int), 0, mask.shape[1] - 1)
    inside = np.flatnonzero(mask[rr, cc])
    return rr, cc, int(inside[-1]) if len(inside) else -1


def supported_sectors(depth: np.ndarray, mask: np.ndarray, focal: float, centre: tuple[float, float]) -> np.ndarray:
    """(SECTORS,) bool: the sectors about ``centre`` where the depth runs on across ``mask``'s outline at the fruit's
    depth (the ray through the sector's middle: its last mask pixel, not seen past the fruit, and the next pixel out
    both hold depth, one surface)."""
    r0, c0 = centre
    reach = int(np.sqrt(mask.sum() / np.pi) * 2) + 40
    deepest = _deepest(depth, mask, focal)
    out = np.zeros(SECTORS, bool)
    for s in range(SECTORS):
        a = (s + 0.5) * 2 * np.pi / SECTORS - np.pi
        rr, cc, e = _ray(mask, r0, c0, a, reach)
        if 0 <= e < reach - 1:
            z_in = float(depth[rr[e], cc[e]])
            out[s] = z_in <= deepest and _continuous(z_in, float(depth[rr[e + 1], cc[e + 1]]), focal)
    return out


def profiles(path: Path) -> str:
    """Per sphere: the supported sectors' slopes and crease against the drawn outline, the free sectors' rim."""
    frame = read_frame(path)
    depth = np.asarray(frame.depth, dtype=np.float64)
    focal = float(np.sqrt(frame.camera.fx * frame.camera.fy))
    labels = np.asarray(frame.masks)
    lines = []
    for k in range(1, int(labels.max()) + 1):
        m = labels == k
        rs, cs = np.nonzero(m)
        r0, c0 = rs.mean(), cs.mean()
        radius = float(np.sqrt(m.sum() / np.pi))
        reach = int(2 * radius) + 40
        sup = supported_sectors(depth, m, focal, (r0, c0))
        deepest = _deepest(depth, m, focal)
        crease, inside, outside, rim = [], [], [], []
        for s in range(SECTORS):
            a = (s + 0.5) * 2 * np.pi / SECTORS - np.pi
            rr, cc, e = _ray(m, r0, c0, a, reach)
            z = depth[rr, cc]
            if sup[s]:
                lo, hi = e, e
                while lo > 0 and _continuous(z[lo - 1], z[lo], focal):
                    lo -= 1
                while hi < len(z) - 1 and _continuous(z[hi], z[hi + 1], focal):
                    hi += 1
                seg = np.arange(max(lo, e - 15), min(hi, e + 15) + 1)
                crease.append(int(seg[np.argmax(z[seg])]) - e)
                if e - 4 >= lo:
                    inside.append((z[e] - z[e - 4]) / 4 * 1000)
                if e + 4 <= hi:
                    outside.append((z[e + 4] - z[e]) / 4 * 1000)
            else:
                valid = np.flatnonzero((z[: e + 1] > 0) & (z[: e + 1] <= deepest))
                if len(valid):
                    rim.append(e - int(valid[-1]))

        def med(v: list[Any]) -> str:
            return f"{np.median(v):+.1f}" if v else "-"

        lines.append(f"sphere {k} ({2 * radius:.0f} px across): {int(sup.sum())} of {SECTORS} sectors run on "
                     f"across the outline; there, slope 4 px inside {med(inside)} mm/px, 4 px outside "
                     f"{med(outside)} mm/px, the depth turns {med(crease)} px from the outline (range "
                     f"{min(crease, default=0):+d} to {max(crease, default=0):+d}); elsewhere the last depth lies "
                     f"{med(rim)} px inside the outline")  # fmt: skip
    return "\n".join(lines) + "\n"


def _oracle_support(drawn: np.ndarray, grown: np.ndarray, depth: np.ndarray, focal: float) -> np.ndarray:
    """The pixels of ``grown`` beyond ``drawn`` in the sectors (about ``drawn``'s centroid) where the depth runs on
    across ``grown``'s outline."""
    rs, cs = np.nonzero(drawn)
    r0, c0 = rs.mean(), cs.mean()
    sup = supported_sectors(depth, grown, focal, (r0, c0))
    vv, uu = np.nonzero(grown & ~drawn)
    sec = np.minimum(((np.arctan2(vv - r0, uu - c0) + np.pi) / (2 * np.pi) * SECTORS).astype(int), SECTORS - 1)
    out = np.zeros(grown.shape, bool)
    out[vv[sup[sec]], uu[sup[sec]]] = True
    return out


def boxes(path: Path, drawn: np.ndarray | None, not_hidden: bool,
          coupled: bool = False) -> dict[int, tuple[np.ndarray, np.ndarray]]:  # fmt: skip
    """``detect``'s boxes (centre, size; mm) on the frame folder ``path``; with ``drawn`` (the unperturbed labels),
    the oracle's support pixels of every mask taken from extraction's points and silhouette (``not_hidden``: and
    from the hidden pixels); ``coupled``: from the points, and from the occlusion's own mask and hidden pixels after
    its overshoot rules read the whole mask."""
    frame = read_frame(path)
    depth = np.asarray(frame.depth, dtype=np.float64)
    focal = float(np.sqrt(frame.camera.fx * frame.camera.fy))
    extract_window, fruit_occlusion = D._extract_window, D.fruit_occlusion
    support: list[np.ndarray | None] = [None]

    def patched_extract(mask: np.ndarray, sl: Any, depth_: Any, cam: Any, settings: Any, **kw: Any) -> Any:
        ex = extract_window(mask, sl, depth_, cam, settings, **kw)
        assert drawn is not None
        ids = np.bincount(drawn[mask], minlength=2)
        ids[0] = 0
        sup = _oracle_support(drawn == int(np.argmax(ids)), mask, depth, focal)
        support[0] = sup
        uv = cam.project(ex.points)
        keep = ~sup[np.rint(uv[:, 1]).astype(int), np.rint(uv[:, 0]).astype(int)]
        if coupled:  # the occlusion's overshoot rules read the whole mask; the support is taken off after them
            return replace(ex, points=ex.points[keep])
        silhouette = (ex.silhouette if ex.silhouette is not None else mask) & ~sup
        return replace(ex, points=ex.points[keep], silhouette=silhouette)

    def patched_occlusion(depth_: Any, mask: Any, *a: Any, **kw: Any) -> Any:
        occ = fruit_occlusion(depth_, mask, *a, **kw)
        if (not_hidden or coupled) and occ is not None and support[0] is not None:
            h, w = occ.hidden.shape
            here = support[0][occ.v0 : occ.v0 + h, occ.u0 : occ.u0 + w]
            occ.hidden[here] = False
            if coupled and occ.own is not None:
                occ.own[here] = False
        return occ

    try:
        if drawn is not None:
            D._extract_window, D.fruit_occlusion = patched_extract, patched_occlusion  # type: ignore[assignment]
        found = D.detect(frame, method="evidence")
    finally:
        D._extract_window, D.fruit_occlusion = extract_window, fruit_occlusion
    return {
        d.id: (np.asarray(d.result.box.centre) * 1000, np.asarray(d.result.box.size) * 1000)
        for d in found.detections
        if d.result is not None
    }


def oracle(out: Path, name: str, not_hidden: bool, coupled: bool = False) -> str:
    """The boxes of perturbation ``name`` as ``detect`` makes them and with the oracle's support taken off."""
    if not (out / "frames" / name).exists():
        RP.write_perturbed(out, name)
    if not (out / "frames" / "none").exists():
        RP.write_perturbed(out, "none")
    lines = ["| frame | sphere | unperturbed size | as detect (size; centre off) | oracle (size; centre off) |",
             "|---|---|---|---|---|"]  # fmt: skip
    over = [0, 0]
    for fn in RP.NAMES:
        unperturbed = read_frame(RP.FRAMES / fn)
        drawn = unperturbed.masks
        focal = float(np.sqrt(unperturbed.camera.fx * unperturbed.camera.fy))
        ref = boxes(out / "frames" / "none" / fn, None, False)
        rows = [
            boxes(out / "frames" / name / fn, None, False),
            boxes(out / "frames" / name / fn, drawn, not_hidden, coupled),
        ]
        for k, (c0, s0) in sorted(ref.items()):
            cells = []
            for i, got in enumerate(rows):
                if k not in got:
                    cells.append("failed")
                    over[i] += 1
                    continue
                c, s = got[k]
                # realpert55's bar: not a cube, or the depth side off the unperturbed mask's diameter (at the
                # unperturbed box's depth), by more than 6 mm
                diameter = 2.0 * np.sqrt(np.count_nonzero(drawn == k) / np.pi) * c0[2] / focal
                if max(float(np.ptp(s)), abs(s[2] - diameter)) > RP.BAR_MM:
                    over[i] += 1
                cells.append(f"{s[0]:.0f} x {s[1]:.0f} x {s[2]:.0f}; {np.linalg.norm(c - c0):.1f}")
            lines.append(f"| {fn[-1]} | {k} | {s0[0]:.0f} x {s0[1]:.0f} x {s0[2]:.0f} | " + " | ".join(cells) + " |")
    lines.append(f"\nover realpert55's 6 mm bar: as detect "
                 f"{over[0]} of {len(lines) - 2}, oracle {over[1]}")  # fmt: skip
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    p = sub.add_parser("profiles", help="where each sphere's depth ends or turns against its drawn outline")
    p.add_argument("frames", type=Path, nargs="+", help="frame folders")
    o = sub.add_parser("oracle", help="the boxes with a grown mask's support pixels taken off by an oracle")
    o.add_argument("out", type=Path, help="realpert55's OUT (frames written there when missing)")
    o.add_argument("name", help="a realpert55 perturbation (dilate5, dilate10, ...)")
    o.add_argument("--not-hidden", action="store_true", help="the support's pixels hide nothing of the fruit")
    coupled = "the occlusion's overshoot rules read the whole mask, the support taken off after them"
    o.add_argument("--coupled", action="store_true", help=coupled)
    a = ap.parse_args(argv)
    if a.cmd == "profiles":
        for path in a.frames:
            sys.stdout.write(f"== {path}\n" + profiles(path))
    else:
        sys.stdout.write(oracle(a.out, a.name, a.not_hidden, a.coupled))


if __name__ == "__main__":
    main()
