"""Stop 47's measurements for issue 18's pears in the paper protocol (docs/pearview47.md): nothing here changes the
library.

    python docs/pearview47.py synthetic
    python docs/pearview47.py views KIND
    python docs/pearview47.py run VARIANT BOXES.csv evaluate ARGS...

The cue: the section ratio (depth over width) of the solid of revolution read off the view itself. The seen points
are sliced across the image direction of the circular fit's axis; in each slice the points' lateral extremes give
the half-width (a quadratic ``a(s)`` and middle ``t_c(s)`` along the axis, so the profile's change within a slice
does not read as depth), and the depth is fitted as ``z = z_c - B sqrt(1 - u^2)`` (``u`` the lateral offset over
``a``, the outer 15 % left out: a sparse sample's extremes fall short of the rim); the slices' centres ``z_c`` along
the axis give its tilt, and the ratio is ``B cos(tilt) / a``, the weighted median over the slices.

``synthetic`` prints the estimate on ellipsoids of known ratio under the paper's visibility rule (600 points);
``views KIND`` the estimate per fruit of the paper protocol (seeds 0 and 1, ``--n 3``) and the solid's back face
against the truth, circular and at the estimated ratio; ``run`` is docs/eval_boxes.py's ``run`` with the solid of
revolution of every view refitted at the estimated ratio (VARIANT: ``los`` squashed along the line of sight as
``fit_revolution_slices(ratio=)`` does; ``full`` squashed across the axis only; ``half`` half way to the estimate,
clipped to 0.85-1.15, slices seen less than 0.6 of their half-width deep left out; ``side`` only where the circular
axis is within 17 deg of the image plane). Run with ``PYTHONPATH=TREE/src`` from the repository's root.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

#: the share of the seen points along the axis that is sliced
SPAN = float(__import__("os").environ.get("PV47_SPAN", "0.9"))
#: name: (squash across the axis only, shrink towards 1, clip low, clip high, least seen depth over half-width,
#: largest |axis z|)
VARIANTS = {
    "los": (False, 1.0, 0.8, 1.25, 0.0, 2.0),
    "full": (True, 1.0, 0.8, 1.25, 0.0, 2.0),
    "half": (True, 0.5, 0.85, 1.15, 0.6, 2.0),
    "side": (True, 1.0, 0.8, 1.25, 0.6, 0.3),
}


def _say(line: str) -> None:
    sys.stdout.write(line + "\n")


def section_ratio(points: np.ndarray, direction: np.ndarray, *, bins: int = 8, inner: float = 0.85,
    span: float = SPAN,
                  min_sag: float = 0.0) -> tuple[float, np.ndarray | None]:  # fmt: skip
    """``(ratio, per-slice ratios)``; ``(1, None)`` where the axis is within 60 deg of the line of sight or fewer
    than three slices hold."""
    d = np.asarray(direction, dtype=np.float64)
    n = float(np.hypot(d[0], d[1]))
    if n < 0.5:
        return 1.0, None
    e = d[:2] / n
    q = points - points.mean(axis=0)
    s, t, z = q[:, :2] @ e, q[:, :2] @ np.array([-e[1], e[0]]), points[:, 2]
    lo, hi = np.quantile(s, [0.5 - span / 2, 0.5 + span / 2])
    idx = np.floor((s - lo) / (hi - lo) * bins).astype(int)
    ok = (idx >= 0) & (idx < bins)
    idx, s, t, z = idx[ok], s[ok], t[ok], z[ok]
    cnt = np.bincount(idx, minlength=bins)
    tmin, tmax = np.full(bins, np.inf), np.full(bins, -np.inf)
    np.minimum.at(tmin, idx, t)
    np.maximum.at(tmax, idx, t)
    a, tc = 0.5 * (tmax - tmin), 0.5 * (tmax + tmin)
    good = (cnt >= 8) & (a > 0)
    order = np.lexsort((t, idx))
    first = np.searchsorted(idx[order], np.arange(bins))
    last = np.searchsorted(idx[order], np.arange(bins), side="right") - 1
    good &= last > first
    fi, la = order[np.clip(first, 0, len(t) - 1)], order[np.clip(last, 0, len(t) - 1)]
    sa = 0.5 * (s[fi] + s[la])
    wq = good.astype(float)
    design = np.c_[np.ones(bins), sa, sa * sa] * wq[:, None]
    ca = np.linalg.lstsq(design, np.where(good, a, 0.0) * wq, rcond=None)[0]
    cc = np.linalg.lstsq(design, np.where(good, tc, 0.0) * wq, rcond=None)[0]
    u = (t - (cc[0] + cc[1] * s + cc[2] * s * s)) / np.maximum(ca[0] + ca[1] * s + ca[2] * s * s, 1e-6)
    w = np.sqrt(np.clip(1.0 - u * u, 0.0, 1.0))
    m = (np.abs(u) < inner).astype(float)
    s1, sw, sww = np.bincount(idx, m, bins), np.bincount(idx, w * m, bins), np.bincount(idx, w * w * m, bins)
    sz, swz = np.bincount(idx, z * m, bins), np.bincount(idx, w * z * m, bins)
    det = s1 * sww - sw * sw
    good &= det > 1e-12 * np.maximum(s1, 1) ** 2
    det = np.where(good, det, 1.0)
    zc, depth = (sww * sz - sw * swz) / det, -(s1 * swz - sw * sz) / det
    sm = np.bincount(idx, s, bins) / np.maximum(cnt, 1)
    aa = np.maximum(ca[0] + ca[1] * sm + ca[2] * sm * sm, 1e-6)
    good &= aa > 0.3 * np.where(np.isfinite(a), a, 0.0).max()
    zmin, zmax = np.full(bins, np.inf), np.full(bins, -np.inf)
    np.minimum.at(zmin, idx, z)
    np.maximum.at(zmax, idx, z)
    good &= (zmax - zmin) > min_sag * aa
    if good.sum() < 3:
        return 1.0, None
    weight = cnt * good
    x = np.c_[np.ones(bins), sm] * np.sqrt(weight)[:, None]
    slope = np.linalg.lstsq(x, zc * np.sqrt(weight), rcond=None)[0][1]
    k = depth / aa / np.sqrt(1.0 + slope**2)
    ranked = np.argsort(np.where(good, k, np.inf))
    cum = np.cumsum((weight * aa)[ranked])
    return float(k[ranked][np.searchsorted(cum, 0.5 * cum[-1])]), k[good]


def across_fit(pts: np.ndarray, rev: Any, k: float, **kwargs: Any) -> Any:
    """The solid refitted with sections ``k`` deep over wide, squashed across its axis only (``deep`` the line of
    sight's part perpendicular to the circular fit's axis), not along the line of sight."""
    from symfruit.core.fits import Revolution, fit_revolution_slices

    centre = pts.mean(axis=0)
    los = centre / np.linalg.norm(centre)
    deep = los - (los @ rev.direction) * rev.direction
    if np.linalg.norm(deep) < 0.3:
        return rev
    deep = deep / np.linalg.norm(deep)
    q = pts - centre
    found = fit_revolution_slices(centre + q + (1.0 / k - 1.0) * (q @ deep)[:, None] * deep, **kwargs)
    p = found.point - centre
    return Revolution(centre + p + (k - 1.0) * (p @ deep) * deep, found.direction, found.edges, found.radii,
                      found.cost, k, deep)  # fmt: skip


def _patch(variant: str) -> None:
    import symfruit.core.candidates as cands
    from symfruit.core.fits import RevolutionInside, box_and_profile, fit_revolution_slices, outline_radii

    across, shrink, k_lo, k_hi, min_sag, max_z = VARIANTS[variant]

    def revolution(fit: Any) -> Iterator[Any]:
        pts = fit.sample[:: max(1, len(fit.sample) // fit.revolution_points)]
        kw = {"extra_directions": np.concatenate(fit.axes) if fit.axes else None, "coarse": fit.revolution_coarse}
        rev = fit_revolution_slices(pts, **kw)
        k, _ = section_ratio(pts, rev.direction, min_sag=min_sag)
        k = min(max(1.0 + shrink * (k - 1.0), k_lo), k_hi) if abs(rev.direction[2]) <= max_z else 1.0
        if abs(k - 1.0) > 0.02:
            rev = across_fit(pts, rev, k, **kw) if across else fit_revolution_slices(pts, **kw, ratio=k)
        if fit.region is not None and fit.outline_profile != "off":  # as the library's _revolution
            region = fit.region
            r_out = outline_radii(rev, region.mask, (region.u0, region.v0), fit.camera, hidden=fit.obs.hidden_map())
            shaped = replace(rev, radii=np.where(np.isfinite(r_out) & np.isfinite(rev.radii), r_out, rev.radii))
            if fit.outline_profile == "replace":
                rev = shaped
            else:
                olo, ohi, *profile = box_and_profile(shaped)
                yield cands._Shape("outline", olo, ohi, RevolutionInside(shaped, profile=(profile[0], profile[1])),
                                   0.5 * (olo + ohi))  # fmt: skip
        lo, hi, t, r = box_and_profile(rev)
        yield cands._Shape("revolution", lo, hi, RevolutionInside(rev, profile=(t, r)), 0.5 * (lo + hi))

    cands._FITTERS["revolution"] = (revolution, cands._FITTERS["revolution"][1])


def synthetic() -> None:
    from symfruit.core.fits import fit_revolution_slices
    from symfruit.synthetic.shapes import paper_visible, rotation_x

    rng = np.random.default_rng(0)
    _say("| true ratio | pose (deg) | estimate mean +- sd (6 ellipsoids) |")
    for k in (0.85, 1.0, 1.15):
        for angle in (0, 20, 40):
            found = []
            for _ in range(6):
                u = rng.normal(size=(20000, 3))
                u /= np.linalg.norm(u, axis=1)[:, None]
                p = u * [0.035, 0.045, 0.035 * k]
                g = np.linalg.norm(u / [0.035, 0.045, 0.035 * k], axis=1)
                p = p[rng.random(len(p)) < (1 / g) / (1 / g).max()][:600] @ rotation_x(angle).T + [0, 0, 0.3]
                seen = p[paper_visible(p)]
                found.append(section_ratio(seen, fit_revolution_slices(seen).direction)[0])
            _say(f"| {k} | {angle} | {np.mean(found):.3f} +- {np.std(found):.3f} |")


def views(kind: str) -> None:
    from symfruit.core.fits import box_and_profile, fit_revolution_slices
    from symfruit.evaluate.protocols import build, specs

    _say(
        "| seed | fruit | ratio at pose 0 (truth) | estimate median / sd, 19 poses | back: circular | at the estimate |"
    )
    for seed in (0, 1):
        rows: dict[int, list[tuple[float, float, float]]] = {}
        truth: dict[int, float] = {}
        for sp in specs("paper", kind, n=3, seed=seed):
            inst = build(sp)
            seen, box = inst.visible, inst.truth_box
            rev = fit_revolution_slices(seen)
            k, _ = section_ratio(seen, rev.direction)
            fitted = across_fit(seen, rev, min(max(k, 0.8), 1.25), extra_directions=None, coarse=64)
            back = [(box_and_profile(x)[1][2] - box.max[2]) * 1e3 for x in (rev, fitted)]
            rows.setdefault(sp.index, []).append((k, back[0], back[1]))
            if sp.pose == 9:  # 0 deg: the fruit's own axis across the view; the middle band's depth over width
                full = inst.truth_surface
                band = np.abs(full[:, 1] - np.median(full[:, 1])) < 0.2 * np.ptp(full[:, 1])
                truth[sp.index] = float(np.ptp(full[band, 2]) / np.ptp(full[band, 0]))
        for i, r in rows.items():
            a = np.array(r)
            _say(f"| {seed} | {i} | {truth[i]:.3f} | {np.median(a[:, 0]):.3f} / {a[:, 0].std():.3f} | "
                  f"{a[:, 1].mean():+.1f} ({np.abs(a[:, 1]).mean():.1f}) | {a[:, 2].mean():+.1f} "
                  f"({np.abs(a[:, 2]).mean():.1f}) |")  # fmt: skip


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="pearview47.py", description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)  # fmt: skip
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("synthetic", help="the estimate on ellipsoids of known ratio")
    sub.add_parser("views", help="the estimate per fruit of the paper protocol").add_argument("kind")
    run = sub.add_parser("run", help="docs/eval_boxes.py run with the sections refitted")
    run.add_argument("variant", choices=sorted(VARIANTS))
    run.add_argument("boxes", help="the per-instance CSV to write")
    run.add_argument("command_line", nargs=argparse.REMAINDER, help="evaluate ARGS...")
    args = parser.parse_args(argv)
    if args.command == "synthetic":
        synthetic()
        return 0
    if args.command == "views":
        views(args.kind)
        return 0
    import eval_boxes

    _patch(args.variant)
    return eval_boxes.run(args.boxes, args.command_line)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
