"""LAPACK's own cost in the benchmark frame's completions, and closed forms' rounding against numpy's (issue 19, stop
64, docs/comp64.md).

    PYTHONPATH=src python docs/comp62.py record calls.pkl
    PYTHONPATH=src python docs/comp64.py lapack-cost calls.pkl [--pairs 1000]
    PYTHONPATH=src python docs/comp64.py pow-scan [--n 100000] [--seed 1]

``lapack-cost``: the recorded completions replayed with every ``core.lapack`` call made, and with its results
replayed instead (copies of the arrays of the first pass, in the order they were made), the two alternated pass by
pass in one process; prints both passes' thread CPU and their paired difference: LAPACK's own cost inside the
completions, without a timer around each call (``time.thread_time_ns`` is a system call of about 1.7 us on the
stop-64 host, whose return leaves the caches cold). ``pow-scan``: standard normal symmetric 2x2 matrices whose
:func:`symfruit.core.fits.eigenvalues2` differs from ``np.linalg.eigvalsh``, with dlae2's root squared by a product
(as now) and by Python's ``**`` (``pow``, as before stop 64).
"""

import argparse
import math
import pickle
import sys
import time
from typing import Any


def lapack_cost(path: str, pairs: int) -> None:
    import numpy as np

    from symfruit.core import lapack
    from symfruit.methods.complete import complete

    with open(path, "rb") as f:
        calls = pickle.load(f)
    for args, kwargs in calls:
        complete(*args, **kwargs)
    original = lapack._call
    made: list[Any] = []

    def recorded(errors: Any, ufunc: Any, signature: str, *args: Any) -> Any:
        out = original(errors, ufunc, signature, *args)
        made.append(out)
        return out

    at = [0]

    def replayed(errors: Any, ufunc: Any, signature: str, *args: Any) -> Any:
        out = made[at[0]]
        at[0] += 1
        return tuple(x.copy() for x in out) if isinstance(out, tuple) else out.copy()

    lapack._call = recorded
    try:
        for args, kwargs in calls:
            complete(*args, **kwargs)
        spent: dict[str, list[float]] = {"lapack": [], "replayed": []}
        for i in range(pairs):
            for mode in ("lapack", "replayed") if i % 2 else ("replayed", "lapack"):
                lapack._call = original if mode == "lapack" else replayed
                at[0] = 0
                start = time.thread_time()
                for args, kwargs in calls:
                    complete(*args, **kwargs)
                spent[mode].append(1e3 * (time.thread_time() - start))
    finally:
        lapack._call = original
    with_lapack, without = np.array(spent["lapack"]), np.array(spent["replayed"])
    diff = with_lapack - without
    sys.stdout.write(
        f"{len(made)} LAPACK calls a frame; completions with LAPACK {np.median(with_lapack):.3f} / "
        f"{with_lapack.min():.3f} ms (median / least), its results replayed {np.median(without):.3f} / "
        f"{without.min():.3f}; LAPACK's own cost: mean {diff.mean():.3f} +- {diff.std() / math.sqrt(len(diff)):.3f}, "
        f"median {np.median(diff):.3f} ms a frame\n"
    )


def _eigenvalues2_pow(a: float, b: float, c: float) -> tuple[float, float]:
    """:func:`symfruit.core.fits.eigenvalues2` before stop 64 (``** 2``), for plain values off the split."""
    b = math.sqrt(b * b)
    sm, adf, ab = a + c, abs(a - c), abs(b + b)
    big, small = (a, c) if abs(a) > abs(c) else (c, a)
    if adf > ab:
        rt = adf * math.sqrt(1.0 + (ab / adf) ** 2)
    elif adf < ab:
        rt = ab * math.sqrt(1.0 + (adf / ab) ** 2)
    else:
        rt = ab * math.sqrt(2.0)
    if sm != 0.0:
        rt1 = 0.5 * (sm - rt) if sm < 0.0 else 0.5 * (sm + rt)
        rt2 = (big / rt1) * small - (b / rt1) * b
    else:
        rt1, rt2 = 0.5 * rt, -0.5 * rt
    return (rt1, rt2) if rt1 <= rt2 else (rt2, rt1)


def pow_scan(n: int, seed: int) -> None:
    import numpy as np

    from symfruit.core.fits import eigenvalues2

    m = np.random.default_rng(seed).normal(size=(n, 2, 2))
    m[:, 0, 1] = m[:, 1, 0]
    want = np.linalg.eigvalsh(m).tolist()
    now = before = 0
    for ((a, _), (b, c)), values in zip(m.tolist(), want, strict=True):
        w = tuple(values)
        if eigenvalues2(a, b, c) != w:
            now += 1
        split = b == 0.0 or b * b <= 2.0**-106 * abs(a * c)
        if not split and _eigenvalues2_pow(a, b, c) != w:
            before += 1
            sys.stdout.write(f"  pow differs: (a, b, c) = {(a, b, c)!r}\n")
    sys.stdout.write(f"{n} matrices: eigenvalues2 differs from eigvalsh in {now}; with ** 2 (pow) in {before}\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    cost = sub.add_parser("lapack-cost", help="LAPACK's own cost in the replayed completions")
    cost.add_argument("calls", help="docs/comp62.py record's file")
    cost.add_argument("--pairs", type=int, default=1000)
    scan = sub.add_parser("pow-scan", help="eigenvalues2 against numpy's eigvalsh, with a product and with pow")
    scan.add_argument("--n", type=int, default=100_000)
    scan.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    if args.command == "lapack-cost":
        lapack_cost(args.calls, args.pairs)
    else:
        pow_scan(args.n, args.seed)


if __name__ == "__main__":
    main()
