"""``core.agreement.observe`` replayed alone on the benchmark frame's inputs (``symfruit bench --frame``, default
method): its fused compiled calls against the steps called one by one, interleaved in one process, thread CPU per
frame (``observe`` and ``_bands`` of each of the frame's fruit), median and least over the rounds.

    python docs/observe_replay.py [--rounds 9] [--repeat 20]

The one-by-one path is ``observe`` with ``_observed_edges``, ``_outline_bands`` and ``_observed_bands`` (issue 19,
stop 51) declining, so that it takes the steps they fuse (each still by its own kernel where numba is installed):
what ``observe`` was before them. Both paths' observations are checked to be the same to the bit first. A replay
reads the frame's inputs warm, from caches the frame itself fills as it goes (a region's moments and outline cracks),
so its figures are below ``observe``'s share of a frame (``docs/speed_ab.py --wrap
symfruit.methods.evidence:observe``); compare figures within one run.
"""

import argparse
import sys
import time
from typing import Any

import numpy as np


def _fields(obs: Any) -> list[Any]:
    from symfruit.core.agreement import _bands

    b = _bands(obs)
    return [obs.rays, obs.depth, obs.inner, obs.interior, *obs.rays_in, *obs.rays_out, *(obs.out_weights or ()),
            *(obs.out_depth or ()), obs.contour, obs.cone, obs.axis, obs.extent, *vars(b).values()]  # fmt: skip


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return (isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape
                and bool(np.array_equal(a, b, equal_nan=a.dtype.kind == "f")))  # fmt: skip
    return bool(a == b)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=9)
    parser.add_argument("--repeat", type=int, default=20, help="frames per round and path")
    args = parser.parse_args(argv)
    import symfruit.core.agreement as ag
    import symfruit.detect as detect
    import symfruit.methods.evidence as ev
    from symfruit.evaluate.bench import _bench_scene

    frame, _ = _bench_scene(None, 0)
    calls: list[tuple[tuple[Any, ...], dict[str, Any]]] = []
    real = ev.observe

    def kept(*a: Any, **k: Any) -> Any:
        calls.append((a, k))
        return real(*a, **k)

    ev.observe = kept
    detect.detect(frame)
    ev.observe = real
    fused = {name: getattr(ag, name) for name in ("_observed_edges", "_outline_bands", "_observed_bands")}

    def declined(*a: Any) -> None:
        return None

    def use(path: str) -> None:
        for name, fn in fused.items():
            setattr(ag, name, fn if path == "fused" else declined)

    for a, k in calls:  # the same observations either way
        use("fused")
        one = _fields(ag.observe(*a, **k))
        use("one by one")
        other = _fields(ag.observe(*a, **k))
        if len(one) != len(other) or not all(_same(x, y) for x, y in zip(one, other, strict=False)):
            sys.stderr.write("the two paths' observations differ\n")
            return 1
    spent: dict[str, list[float]] = {"fused": [], "one by one": []}
    for _ in range(args.rounds):
        for path, times in spent.items():
            use(path)
            start = time.thread_time()
            for _ in range(args.repeat):
                for a, k in calls:
                    ag._bands(ag.observe(*a, **k))
            times.append((time.thread_time() - start) / args.repeat * 1e3)
    use("fused")
    lines = [f"observe replayed on the benchmark frame's {len(calls)} fruit: thread CPU ms per frame, median / least"]
    for path, times in spent.items():
        lines.append(f"{path:>11}  {np.median(times):6.2f} / {min(times):6.2f}")
    sys.stdout.write("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
