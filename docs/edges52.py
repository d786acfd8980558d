"""How often ``core.agreement.observe``'s edge normals vote (issue 18, stop 52; docs/edges52.md).

Runs a ``symfruit`` command in this process (``--jobs 1`` added to the protocols' runs) or one of the cases below
with ``observe`` counted, then prints, over every ``observe`` call with a dense cloud (about a point per pixel of the
region, the views whose edge normals come from the image grid) and over the sparser ones:

- ``calls``: how many, and how many had occlusion information (``detect``'s fruit, the camera protocol's views);
- ``voted``: the calls whose edge test found at least 3 edge points (their normals label the outline);
- ``edges``: the edge points found, summed, and the share of them labelled a cut (a normal facing the camera);
- ``contour share``: the mean of the calls' :attr:`~symfruit.core.agreement.Observation.contour`;
- ``own region``: the same edge test measured from the points' own region (``evidence``'s region before it is grown
  to the fruit's mask, ``core.occlusion.with_own``): the calls it would find edge points in, their edge points and
  cut share; ``1.5 + eroded px``: the same on the grown region with the test's 1.5 px moved inward by extraction's
  default erosion (:data:`ERODED`).

    python docs/edges52.py bench                      # detect on the benchmark frames (seeds 0-2, evidence)
    python docs/edges52.py -- evaluate --protocol paper --fruit examples/scans --n 2 --pose hanging --no-profile \\
        --methods evidence                            # complete() on points alone (no frame around them)
    python docs/edges52.py -- evaluate --spheres examples/real-frames --methods evidence
    python docs/edges52.py -- evaluate --frames FRAMES --methods evidence
    python docs/edges52.py -- evaluate --protocol camera --sensor heldback --fruit examples/scans --n 38 \\
        --pose hanging --no-profile --methods evidence
"""

from __future__ import annotations

import argparse
import contextlib
import io
import sys
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np

from symfruit.core import agreement
from symfruit.core.raster import inner_distance
from symfruit.methods import evidence

#: Per observe call: (dense, occluded, edge points, cut edge points, own-region edge points, own-region cuts, edge
#: points within ``1.5 + ERODED`` px of the grown region, their cuts).
CALLS: list[tuple[bool, bool, int, int, int, int, int, int]] = []
#: Per observe call: the contour share it gave (:attr:`~symfruit.core.agreement.Observation.contour`).
SHARES: list[float] = []
#: Extraction's default ``erode_px``: the tolerance that follows the erosion is ``1.5 + ERODED`` px.
ERODED = 1


@contextlib.contextmanager
def counted() -> Iterator[None]:
    """``observe`` counted into :data:`CALLS` while inside."""
    saved = {name: getattr(agreement, name) for name in ("observe", "_observed_edges", "_contour_pixels",
                                                         "_contour_points")}  # fmt: skip
    with_own = evidence.with_own
    state: dict[str, Any] = {}

    def edges_of(found: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        state["edges"] = found
        return found

    def observed_edges(*args: Any, **kw: Any) -> Any:
        made = saved["_observed_edges"](*args, **kw)
        if made is not None and made[4] is not None:
            edges_of(made[4])
        return made

    def wrap(name: str) -> Callable[..., Any]:
        return lambda *a, **k: edges_of(saved[name](*a, **k))

    def own(region: Any, occlusion: Any, *, trimmed: bool = False) -> Any:
        if not trimmed:
            state["own"] = region
        return with_own(region, occlusion, trimmed=trimmed)

    def labelled(edge_points: np.ndarray, px: np.ndarray, region: Any, camera: Any, count: int,
                 grid: bool) -> tuple[int, int]:  # fmt: skip
        """The edge points the test finds at ``px`` (each point's depth inside the edge) and how many are cuts."""
        if grid:
            _, found = saved["_contour_pixels"](edge_points, px, region, camera, count)
        else:
            _, found = saved["_contour_points"](edge_points, px, camera, count)
        return len(found), int(np.count_nonzero(~found))

    def observe(points: np.ndarray, region: Any, camera: Any, **kw: Any) -> Any:
        state.pop("edges", None)
        seen = state.pop("own", None)
        obs = saved["observe"](points, region, camera, **kw)
        dense = kw.get("dense")
        edge_points = points if dense is None else dense
        grid = len(edge_points) >= 0.5 * np.count_nonzero(region.mask)
        _, label = state.pop("edges", (np.zeros((0, 2)), np.zeros(0, dtype=bool)))
        n_own = cut_own = n_tol = cut_tol = -1  # no grown region: the test already measures from the points' own
        if seen is not None:
            count = kw.get("contour_points", 150)
            # the edge test with its 1.5 px moved ERODED px inward
            px = np.maximum(agreement._inside_px(edge_points, region, camera, inner_distance(region.mask)) - ERODED, 0)
            n_tol, cut_tol = labelled(edge_points, px, region, camera, count, grid)
            px = agreement._inside_px(edge_points, seen, camera, inner_distance(seen.mask))
            n_own, cut_own = labelled(edge_points, px, seen, camera, count, grid)
        CALLS.append((grid, kw.get("occlusion") is not None, len(label), int(np.count_nonzero(~label)), n_own,
                      cut_own, n_tol, cut_tol))  # fmt: skip
        SHARES.append(obs.contour)
        return obs

    agreement.observe = observe  # type: ignore[assignment]
    evidence.observe = observe  # type: ignore[attr-defined]
    evidence.with_own = own  # type: ignore[assignment]
    agreement._observed_edges = observed_edges  # type: ignore[assignment]
    agreement._contour_pixels = wrap("_contour_pixels")  # type: ignore[assignment]
    agreement._contour_points = wrap("_contour_points")  # type: ignore[assignment]
    try:
        yield
    finally:
        for name, f in saved.items():
            setattr(agreement, name, f)
        evidence.observe = saved["observe"]  # type: ignore[attr-defined]
        evidence.with_own = with_own  # type: ignore[assignment]


def say(text: str = "") -> None:
    sys.stdout.write(text + "\n")


def report(title: str) -> None:
    say(f"## {title}")
    say("| clouds | calls | with occlusion | contour share (mean) | voted (>= 3 edge points) | edge points | cut share "
        "| own region: would vote | own: edge points | own: cut share | 1.5 + eroded px: would vote | edge points "
        "| cut share |")  # fmt: skip
    say("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    a = np.array(CALLS, dtype=np.int64).reshape(-1, 8)
    shares = np.array(SHARES)
    for name, which in (("dense", a[:, 0] == 1), ("sparser", a[:, 0] == 0)):
        rows = a[which]
        if not len(rows):
            continue
        grown = rows[:, 4] >= 0
        cells = [name, str(len(rows)), str(int(rows[:, 1].sum())), f"{shares[which].mean():.3f}"]
        for n, cut, kept in ((2, 3, np.ones(len(rows), bool)), (4, 5, grown), (6, 7, grown)):
            voted = int((kept & (rows[:, n] >= 3)).sum())
            edges, cuts = int(rows[kept, n].sum()), int(rows[kept, cut].sum())
            cells += [str(voted) if n == 2 else f"{voted} of {int(grown.sum())} grown", str(edges),
                      f"{cuts / edges:.3f}" if edges else "-"]  # fmt: skip
        say("| " + " | ".join(cells) + " |")
    say()


def bench() -> None:
    from symfruit.detect import detect
    from symfruit.evaluate.bench import _bench_scene

    for seed in (0, 1, 2):
        frame, _ = _bench_scene(None, seed)
        detect(frame, method="evidence")


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("what", nargs=argparse.REMAINDER, help="bench, or -- and a symfruit command")
    what = parser.parse_args(argv).what
    what = what[1:] if what[:1] == ["--"] else what
    if not what:
        parser.error("name a case (bench) or a symfruit command after --")
    with counted():
        if what == ["bench"]:
            bench()
            title = "detect on the benchmark frames (seeds 0-2, evidence)"
        else:
            from symfruit.cli import main as cli

            command = list(what)
            if "--protocol" in command and "--jobs" not in command:
                command += ["--jobs", "1"]
            with contextlib.redirect_stdout(io.StringIO()):
                cli(command)
            title = "symfruit " + " ".join(command)
    report(title)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
