"""Stop 61 (docs/noise61.md): the depth noise one pixel of registration apart, and a noise read off the quantisation.

``dump`` runs ``detect`` (method ``raw``, CW1) on one frame at the registered shift and at its 8 neighbours (the
registration replaced by the masks moved, as docs/reg59.py does) and keeps every fruit's last ``fruit_surface``
arguments. ``flips`` reads such dumps and prints, per fruit, the noise over the 9 shifts by
``core.surface.depth_noise`` (whatever tree is on ``PYTHONPATH``) and by :func:`grouped_noise` (this file: the
estimator tried at stop 61, not kept), and how many fruit vary by ``--bar`` (1.25: a quarter) or more. ``plane``
prints both on a tilted plane with normal noise rounded to whole millimetres (their bias and spread).

    PYTHONPATH=src python docs/noise61.py dump FRAMES INDEX OUT.pkl
    PYTHONPATH=src python docs/noise61.py flips OUT1.pkl [OUT2.pkl ...] [--bar 1.25]
    PYTHONPATH=src python docs/noise61.py plane
"""

from __future__ import annotations

import argparse
import pickle
import sys
from typing import Any

import numpy as np

#: the differences' test for whole steps (in steps), and the rounding's share of the deviation's square (steps squared)
LATTICE = 0.01
ROUNDING = 0.25 / (1.4826 * 1.4826)


def _say(line: str) -> None:
    sys.stdout.write(line + "\n")


def grouped_deviation(ks: np.ndarray, cs: np.ndarray) -> float:
    """The median absolute deviation about the median (in cells) of counts ``cs`` of whole values ``ks`` (sorted,
    distinct), each count spread evenly over its cell ``[k - 1/2, k + 1/2]``: the median where the piecewise linear
    distribution reaches half the count, then the half-width about it holding half the count."""
    edges = np.concatenate([ks - 0.5, ks + 0.5])
    total = float(cs.sum())
    below = np.concatenate([[0.0], np.cumsum(cs)])
    j = int(np.searchsorted(below[1:], total / 2.0))
    med = ks[j] - 0.5 + (total / 2.0 - below[j]) / cs[j]

    def held(t: float) -> float:
        return float((cs * np.clip(np.minimum(ks + 0.5, med + t) - np.maximum(ks - 0.5, med - t), 0.0, 1.0)).sum())

    ts = np.unique(np.abs(edges - med))
    last_t, last_m = 0.0, 0.0
    for t in ts:
        m = held(float(t))
        if m >= total / 2.0:
            return last_t + (total / 2.0 - last_m) / (m - last_m) * (float(t) - last_t) if m > last_m else float(t)
        last_t, last_m = float(t), m
    return float(ts[-1])


def grouped_noise(depth: np.ndarray, mask: np.ndarray, *, floor: float = 0.0005) -> float:
    """The noise (metres) tried at stop 61: ``depth_noise``'s horizontal neighbour differences, the moved ones where
    at least 20 are; where they are whole steps of the least one, the deviation read off the quantisation's cells (the
    0 cell, a coarser camera's repeated pixels among its equal neighbours, given the mean of its two neighbours'
    counts) less the rounding's share (Sheppard: each neighbour's rounding and the spread over the cells); else the
    base's median absolute deviation. ``1.4826 x deviation / sqrt 2``, at least ``floor``."""
    from symfruit.core.surface import _neighbour_differences, depth_noise

    diff = _neighbour_differences(depth, mask)
    x = diff[diff != 0]
    if len(x) < 20 or not np.isfinite(x).all():
        return depth_noise(depth, mask, floor=floor)
    q = float(np.abs(x).min())
    r = x / q
    k = np.floor(r + 0.5)
    if np.abs(r - k).max() > LATTICE:
        return depth_noise(depth, mask, floor=floor)
    ks, counts = np.unique(k, return_counts=True)
    ones = float(counts[np.abs(ks) == 1.0].sum())
    at = int(np.searchsorted(ks, 0.0))
    g = grouped_deviation(np.insert(ks, at, 0.0), np.insert(counts.astype(float), at, 0.5 * ones))
    square = g * g - ROUNDING
    return max(floor, 1.4826 * q * float(np.sqrt(max(square, 0.0))) / np.sqrt(2.0))


def dump(frames: str, index: int, out: str) -> None:
    """Each fruit's last ``fruit_surface`` arguments at the registered shift and its 8 neighbours, to ``out``."""
    import symfruit.detect as det
    import symfruit.extract as ext
    from symfruit.extract import register, shift_labels
    from symfruit.io.sources import open_source
    from symfruit.settings import from_dict

    settings = from_dict({"evidence": {"cut_width": 1}})
    src = open_source(frames)
    frame = src.read(index)
    src.close()
    current: list[int | None] = [None]
    kept: dict[int, Any] = {}
    call, surface = det._Fruit.__call__, ext.fruit_surface

    def fruit_call(self: Any, k: Any, sl: Any) -> Any:
        current[0] = int(k)
        try:
            return call(self, k, sl)
        finally:
            current[0] = None

    def fruit_surface(*a: Any, **kw: Any) -> Any:
        if current[0] is not None:
            kept[current[0]] = (tuple(np.array(x) if isinstance(x, np.ndarray) else x for x in a), dict(kw))
        return surface(*a, **kw)

    det._Fruit.__call__ = fruit_call  # type: ignore[method-assign]
    ext.fruit_surface = fruit_surface  # type: ignore[assignment]
    used: list[tuple[int, int]] = []

    def run(shift: tuple[int, int] | None) -> dict[int, Any]:
        def forced(labels: np.ndarray, depth: np.ndarray, camera: Any, s: Any, **kw: Any) -> Any:
            if shift is None:
                moved, found = register(labels, depth, camera, s, **kw)
                used.append(found)
                return moved, found
            return shift_labels(labels, *shift), shift

        det.register = forced  # type: ignore[assignment]
        kept.clear()
        det.detect(frame, method="raw", settings=settings)
        return dict(kept)

    try:
        run(None)
        du, dv = used[0]
        res: dict[Any, Any] = {(du + a, dv + b): run((du + a, dv + b)) for a in (-1, 0, 1) for b in (-1, 0, 1)}
    finally:
        det._Fruit.__call__, ext.fruit_surface, det.register = call, surface, register  # type: ignore[method-assign]
    res["registered"] = (du, dv)
    with open(out, "wb") as f:
        pickle.dump(res, f)
    _say(f"{frames} {index}: registered ({du}, {dv})")


def flips(paths: list[str], bar: float) -> None:
    """Per fruit the noise's range over the 9 shifts (mm), the base's and the grouped one; the count over ``bar``."""
    from symfruit.core.surface import depth_noise

    total, over = 0, [0, 0]
    for path in paths:
        with open(path, "rb") as f:
            res = pickle.load(f)
        shifts = [s for s in res if isinstance(s, tuple)]
        for fruit in sorted(res[res["registered"]]):
            total += 1
            line = f"{path} fruit {fruit:3d}:"
            for i, noise in enumerate((depth_noise, grouped_noise)):
                got = [noise(*res[s][fruit][0][:2]) for s in shifts if fruit in res[s]]
                over[i] += max(got) / min(got) >= bar
                line += f"  {min(got) * 1e3:.2f}-{max(got) * 1e3:.2f}"
            _say(line)
    _say(f"fruit whose noise varies by {bar:g} x or more over the 9 shifts: depth_noise {over[0]}, grouped {over[1]} "
         f"of {total}")  # fmt: skip


def plane() -> None:
    """Both estimates on a tilted 40 x 40 plane at 1 m, normal noise rounded to whole millimetres (every other column
    repeated, a coarser camera's pixels, or not), 20 seeds: mean +- SD (mm)."""
    from symfruit.core.surface import depth_noise

    mask = np.ones((40, 40), bool)
    for repeated in (False, True):
        for sigma in (0.0005, 0.0008, 0.001, 0.0015, 0.002, 0.003):
            got: list[list[float]] = [[], []]
            for seed in range(20):
                rng = np.random.default_rng(seed)
                tilt = np.cumsum(np.full((40, 40), rng.uniform(-0.0003, 0.0003)), axis=1)
                z = np.round((1.0 + rng.uniform(0, 0.001) + tilt + rng.normal(0.0, sigma, (40, 40))) * 1000.0) / 1000.0
                if repeated:
                    z[:, 1::2] = z[:, 0:-1:2]
                got[0].append(depth_noise(z, mask) * 1e3)
                got[1].append(grouped_noise(z, mask) * 1e3)
            _say(f"repeated {repeated!s:5} sigma {sigma * 1e3:.1f} mm: depth_noise {np.mean(got[0]):.2f} +- "
                 f"{np.std(got[0]):.2f}, grouped {np.mean(got[1]):.2f} +- {np.std(got[1]):.2f}")  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True)
    d = sub.add_parser("dump", help="fruit_surface's arguments at the 9 shifts of one frame")
    d.add_argument("frames")
    d.add_argument("index", type=int)
    d.add_argument("out")
    f = sub.add_parser("flips", help="the noise over the 9 shifts per fruit")
    f.add_argument("paths", nargs="+")
    f.add_argument("--bar", type=float, default=1.25)
    sub.add_parser("plane", help="both estimates on a tilted plane of whole millimetres")
    args = p.parse_args(argv)
    if args.command == "dump":
        dump(args.frames, args.index, args.out)
    elif args.command == "flips":
        flips(args.paths, args.bar)
    else:
        plane()
    return 0


if __name__ == "__main__":
    sys.exit(main())
