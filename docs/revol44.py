"""Stop 44's measurements for issue 18's elliptic sections (docs/revol44.md): nothing here changes the library.

    python docs/revol44.py synthetic
    python docs/revol44.py run RATIO|cone|three BOXES.csv evaluate ARGS...
    python docs/revol44.py table RESULTS_DIR [RESULTS_DIR ...]

``synthetic`` fits :func:`~symfruit.core.fits.fit_revolution_slices` to the front of ellipsoids of revolution about
x whose sections are ``a`` across and ``b`` deep (0.4 m from the camera, depth noise 0.2 and 1.6 mm, seeded), and
prints the solid's back face against the truth's with circles and with the true section ratio, and the fit's
robust RMS over a grid of ratios (what the view's own fit can tell). ``run`` is docs/eval_boxes.py's ``run`` with
every solid of revolution of ``evidence`` fitted at a fixed section ratio (``RATIO``), or at the ratio of the
``cone`` ellipsoid's depth to its width across the solid's axis (``cone``, clipped to 0.7-1.3; the axis nearer the
image plane than the line of sight), or (``three``) with two more solids of revolution beside the circular one, at
ratios 0.85 and 1.15, left to the evidence's weights. ``table`` prints per kind mean IoU / centre error (mm) /
views over 10 mm of ``evidence`` in each run's ``instances.csv`` and, for two runs or more, of the per-view best (the
oracle: each view the run whose centre is nearest). Run with ``PYTHONPATH=TREE/src`` from the repository's root.
"""

from __future__ import annotations

import collections
import csv
import functools
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def _say(*parts: object) -> None:
    sys.stdout.write(" ".join(map(str, parts)) + "\n")


def _front_of_ellipsoid(
    rng: np.random.Generator, a: float, b: float, length: float, noise: float, n: int = 3000
) -> np.ndarray:
    """Points on the half of the ellipsoid (semi-axes ``length`` along x, ``a`` along y, ``b`` along z, centre 0.4 m
    down z) facing the camera at the origin, depth noise ``noise`` metres."""
    s, phi = rng.uniform(-1, 1, n), rng.uniform(0, 2 * np.pi, n)
    r = np.sqrt(1 - s**2)
    pts = np.stack([s * length, a * r * np.cos(phi), b * r * np.sin(phi) + 0.4], axis=1)
    normal = np.stack([pts[:, 0] / length**2, pts[:, 1] / a**2, (pts[:, 2] - 0.4) / b**2], axis=1)
    pts = pts[(normal * pts).sum(axis=1) < 0]
    pts[:, 2] += rng.normal(0, noise, len(pts))
    return pts


def synthetic() -> None:
    from symfruit.core.fits import fit_revolution_slices, revolution_box

    rng = np.random.default_rng(0)
    grid = (0.7, 0.8, 0.9, 1.0, 1.1, 1.25, 1.4)
    _say(
        "| a x b (mm) | noise (mm) | back: circles | back: true ratio | RMS (mm) at ratio " + " / ".join(map(str, grid))
    )
    _say("|---|---|---|---|---|")
    for a, b in ((0.04, 0.04), (0.042, 0.038), (0.04, 0.032), (0.035, 0.04)):
        for noise in (0.0002, 0.0016):
            pts = _front_of_ellipsoid(rng, a, b, 0.05, noise)[::5]
            backs = [(revolution_box(fit_revolution_slices(pts, ratio=k))[1][2] - 0.4 - b) * 1e3 for k in (1.0, b / a)]
            rms = [np.sqrt(fit_revolution_slices(pts, ratio=k).cost) * 1e3 for k in grid]
            _say(f"| {a * 1e3:.0f} x {b * 1e3:.0f} | {noise * 1e3:.1f} | {backs[0]:+.1f} | {backs[1]:+.1f} | "
                  + " / ".join(f"{x:.2f}" for x in rms) + " |")  # fmt: skip


def _cone_ratio(fit, rev) -> float:  # type: ignore[no-untyped-def]
    """The ``cone`` ellipsoid's depth over its width across the solid's axis (1 where it cannot be had)."""
    shape = getattr(fit, "cone_shape", None)
    if shape is None:
        return 1.0
    sight = fit.sample.mean(axis=0)
    sight = sight / np.linalg.norm(sight)
    across = np.cross(sight, rev.direction)
    if float(across @ across) < 0.5:
        return 1.0
    across /= np.linalg.norm(across)
    deep, wide = float(sight @ shape @ sight), float(across @ shape @ across)
    return min(max(float(np.sqrt(deep / wide)), 0.7), 1.3) if deep > 0 and wide > 0 else 1.0


def _patch(mode: str) -> None:
    import symfruit.core.candidates as cands

    if mode == "three":
        plain = cands._revolution

        def three(fit) -> Iterator:  # type: ignore[no-untyped-def]
            yield from plain(fit)
            for ratio in (0.85, 1.15):
                rev = cands.fit_revolution_slices(fit.sample[:: max(1, len(fit.sample) // fit.revolution_points)],
                                                  extra_directions=np.vstack(fit.axes) if fit.axes else None,
                                                  coarse=fit.revolution_coarse, ratio=ratio)  # fmt: skip
                lo, hi, t, r = cands.box_and_profile(rev)
                yield cands._Shape("revolution", lo, hi, cands.RevolutionInside(rev, profile=(t, r)), 0.5 * (lo + hi))

        cands._FITTERS["revolution"] = (three, cands._FITTERS["revolution"][1])
        return
    if mode != "cone":
        cands.fit_revolution_slices = functools.partial(cands.fit_revolution_slices, ratio=float(mode))  # type: ignore[assignment]
        return
    plain_cone, plain_fit = cands._cone, cands.fit_revolution_slices

    def cone(fit) -> Iterator:  # type: ignore[no-untyped-def]
        for shape in plain_cone(fit):
            fit.cone_shape = np.linalg.inv(shape.inside.shape)  # Quadric(centre, inverse of the fit's S)
            yield shape

    def fitted(points, **kwargs):  # type: ignore[no-untyped-def]
        rev = plain_fit(points, **kwargs)
        ratio = _cone_ratio(_current[0], rev) if _current else 1.0
        return plain_fit(points, **kwargs, ratio=ratio) if abs(ratio - 1.0) > 0.02 else rev

    _current: list = []
    plain_revolution = cands._revolution

    def revolution(fit) -> Iterator:  # type: ignore[no-untyped-def]
        _current[:] = [fit]
        yield from plain_revolution(fit)

    cands._cone, cands._revolution, cands.fit_revolution_slices = cone, revolution, fitted  # type: ignore[assignment]
    cands._FITTERS["cone"] = (cone, cands._FITTERS["cone"][1])
    cands._FITTERS["revolution"] = (revolution, cands._FITTERS["revolution"][1])


def table(folders: list[str]) -> None:
    runs = []
    for folder in folders:
        rows = {}
        with open(Path(folder) / "instances.csv") as f:
            for r in csv.DictReader(f):
                if r["method"] == "evidence":
                    key = (r["kind"], r["fruit_index"], r["pose"], r["occlusion"])
                    rows[key] = (float(r["iou"] or 0.0), float(r["centre_mm"] or 1e3))
        runs.append((folder, rows))
    if len(runs) > 1:
        keys = set.intersection(*(set(rows) for _, rows in runs))
        runs.append(("oracle", {k: min((rows[k] for _, rows in runs), key=lambda x: x[1]) for k in keys}))
    for label, rows in runs:
        by = collections.defaultdict(list)
        for key, value in rows.items():
            by[key[0].split("/")[-1]].append(value)
            by["all"].append(value)
        cells = [f"{kind} {np.mean([v[0] for v in vs]):.3f} / {np.mean([v[1] for v in vs]):.2f} / "
                 f"{sum(v[1] > 10 for v in vs)}" for kind, vs in sorted(by.items())]  # fmt: skip
        _say(label, "|", " | ".join(cells))


def main(argv: list[str]) -> int:
    if argv[:1] == ["synthetic"]:
        synthetic()
        return 0
    if argv[:1] == ["table"]:
        table(argv[1:])
        return 0
    if argv[:1] == ["run"] and len(argv) > 3:
        import eval_boxes

        _patch(argv[1])
        return eval_boxes.run(argv[2], argv[3:])
    usage = "usage: revol44.py synthetic | run RATIO|cone|three BOXES.csv evaluate ARGS... | table RESULTS_DIR...\n"
    if argv[:1] in (["-h"], ["--help"]):
        sys.stdout.write(usage + (__doc__ or ""))
        return 0
    sys.stderr.write(usage)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
