"""``_jit.depth_mode`` alone on the benchmark frame's own calls (docs/register52.md): the valid depths, equivalent
radius, noise and leaf pixels of ``fruit_surface``'s 18 calls in one ``detect`` on ``symfruit bench --frame``'s frame
(seed 0: the registration's 9 and extraction's 9), each worked out as ``fruit_surface`` works it out
(``_jit.mask_values`` on the mask's box), then ``depth_mode`` replayed on them ``--rounds`` times three ways: with
the calls' own arguments; with ``docs/surface51.py --depth-mode``'s fixed ones (radius 20 px, focal 600 px, noise
1 mm, no leaf pixels); and with the calls' own arguments after 32 MB written before each call (the caches holding
other data, as in a frame). Prints the thread CPU per frame, median and least.

    PYTHONPATH=TREE/src python docs/register52.py [--rounds 60]

Run it once per tree, alternating, on one host (thread CPU; the host's load still shows).
"""

import argparse
import sys
import time

import numpy as np


def _arguments() -> list[tuple]:
    from surface51 import _calls  # docs/surface51.py: fruit_surface's calls of one detect on the benchmark frame

    import symfruit.core.surface as surface
    from symfruit.core.kernels import compiled
    from symfruit.core.raster import mask_box

    jit = compiled()
    assert jit is not None, "numba's kernels are needed"
    shares = (float(surface.LEAFY[0]), float(surface.LEAFY[1]))
    out = []
    for (depth, mask, focal), k in _calls():
        leafy = k.get("leafy")
        r0, r1, c0, c1 = mask_box(mask)
        box = (slice(r0, r1), slice(c0, c1))
        d = np.ascontiguousarray(np.asarray(depth, dtype=np.float64)[box])
        d = np.where(np.isfinite(d) & (d > 0), d, 0.0)
        leaf = np.zeros((0, 0), bool) if leafy is None else np.ascontiguousarray(leafy[box])
        noise, kept, kept_leaf, _ = jit.mask_values(d, np.ascontiguousarray(mask[box]), leaf, leafy is not None,
                                                    surface._NOISE_FLOOR)  # fmt: skip
        radius_px = float(np.sqrt(np.count_nonzero(mask[box]) / np.pi))
        out.append((kept, radius_px, float(focal), float(noise), kept_leaf, leafy is not None, shares))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=60)
    args = parser.parse_args()
    from symfruit.core.kernels import compiled

    jit = compiled()
    calls = _arguments()
    none = np.zeros(0, bool)
    fixed = [(a[0], 20.0, 600.0, 0.001, none, False, a[6]) for a in calls]
    junk = np.ones(4_000_000)
    for name, use, flush in (("own arguments", calls, False), ("surface51's fixed arguments", fixed, False),
                             ("own arguments, caches flushed", calls, True)):  # fmt: skip
        for a in use:
            jit.depth_mode(*a)
        spent = []
        for _ in range(args.rounds if not flush else max(args.rounds // 3, 1)):
            total = 0.0
            for a in use:
                if flush:
                    junk += 1.0
                start = time.thread_time()
                jit.depth_mode(*a)
                total += time.thread_time() - start
            spent.append(total)
        sys.stdout.write(f"depth_mode, {len(use)} calls, {name}: {np.median(spent) * 1e3:.3f} / "
                         f"{np.min(spent) * 1e3:.3f} ms a frame\n")  # fmt: skip


if __name__ == "__main__":
    main()
