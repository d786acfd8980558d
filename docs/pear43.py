"""Stop 43's measurements for issue 18's stood-up real pear (docs/pear43.md): nothing here changes the library.

    python docs/pear43.py methods --tilt 90 [--fruit pear,banana,lemon,lopsided,strawberry] [--methods M,...]
    python docs/pear43.py variants LABEL=OUT.pkl[:KIND] ... -- NAME ...
    python docs/pear43.py closure --tilt 90 [--fruit ...] [--n 2]

``methods`` completes docs/evid40.py's end-on set (the paper protocol's 19 poses of generated fruit turned ``--tilt``
degrees about the camera's x axis first, ``--n 3 --seed 7``) with each of ``--methods`` and prints, per kind, mean
IoU / mean centre error (mm) / views over 10 mm. ``variants`` replays ``combine`` and ``fuse_depth`` on views
collected by ``docs/evid40.py collect`` or ``endon`` (``KIND``: views whose fruit id holds it) under rules: ``default``,
``noraw`` (the raw box left out of the back face's weighted median), ``spreadK`` (the candidates' back-face spread
counted ``K`` times in the shapes' deviation instead of 0.5), ``dwcK`` and other docs/scans39.py rules, and
``x=key:value,...`` (settings). ``closure`` fits the solid of revolution
(:func:`~symfruit.core.fits.fit_revolution_slices`) to every end-on view (axis within 45 deg of the line of sight)
whose far end :func:`~symfruit.core.fits.closed_profile` closes, and prints per kind the closed length along the line
of sight against the truth's depth for the mirror closure and for a profile closed at the apex of the conic
``r^2 = a + b t + c t^2`` fitted to its seen slices (the quadric of revolution through them).
Run with ``PYTHONPATH=TREE/src`` from the repository's root.
"""

from __future__ import annotations

import argparse
import dataclasses
import inspect
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import evid40
import scans39

import symfruit.methods.evidence as ev
from symfruit.core.box import Box
from symfruit.core.fits import closed_profile, fit_revolution_slices
from symfruit.evaluate import protocols as proto

KINDS = "pear,banana,lemon,lopsided,strawberry"


def say(line: str) -> None:
    sys.stdout.write(line + "\n")


def endon_views(kind: str, tilt: float, n: int, seed: int = 7) -> Iterator[tuple[str, np.ndarray, np.ndarray, Box]]:
    """docs/evid40.py ``endon``'s views: ``(name, seen points, every point, truth box)``; a folder of scans: the
    paper protocol's views of its scans stood up (``--pose upright``; ``tilt`` not used)."""
    if "/" in kind:
        for i in range(n):
            for pose in range(len(proto.PAPER_ANGLES)):
                inst = proto.build(proto.Spec("paper", kind, i, pose, 0.0, 0, poses="upright"))
                yield f"{inst.kind}{i} p{pose}", inst.visible, inst.truth_surface, inst.truth_box
        return
    for i in range(n):
        fruit = proto._fruit(proto.Spec("paper", kind, i, 0, 0.0, seed))
        rng = np.random.default_rng([seed, 1000 + proto._KIND_IDS.get(kind, 99), i])  # as the paper protocol
        points = fruit.sample(600, rng) @ proto.rotation_x(tilt).T
        for pose, angle in enumerate(proto.PAPER_ANGLES):
            posed = points @ proto.rotation_x(float(angle)).T
            posed = posed - Box.from_points(posed).centre + [0.0, 0.0, proto.PAPER_DISTANCE]
            yield f"{kind}{i} p{pose}", posed[proto.paper_visible(posed)], posed, Box.from_points(posed)


def methods(tilt: float, kinds: list[str], names: list[str], n: int) -> None:
    from symfruit.evaluate.metrics import score_completion
    from symfruit.methods.complete import complete
    from symfruit.settings import Settings

    settings = Settings()
    say("| kind | tilt | " + " | ".join(names) + " |")
    for kind in kinds:
        scores: dict[str, list[tuple[float, float]]] = {m: [] for m in names}
        for _, seen, posed, truth in endon_views(kind, tilt, n):
            for m in names:
                try:
                    r = complete(seen, camera=proto.DEFAULT_CAMERA, method=m, settings=settings)
                    s = score_completion(r.box, r.points, truth, posed)
                    scores[m].append((s.iou, s.centre_mm))
                except Exception:  # a method's failure is counted, the others go on
                    scores[m].append((float("nan"), float("nan")))
        cells = []
        for m in names:
            a = np.array(scores[m])
            fails = int(np.isnan(a[:, 0]).sum())
            cells.append(f"{np.nanmean(a[:, 0]):.3f} / {np.nanmean(a[:, 1]):.2f} / {int((a[:, 1] > 10).sum())}"
                         + (f" ({fails} failed)" if fails else ""))  # fmt: skip
        say(f"| {kind} | {tilt:+.0f} | " + " | ".join(cells) + " |")


_COMBINE, _FUSE, _MEDIAN = ev.combine, ev.fuse_depth, ev._weighted_median
_FUSE_SOURCE = inspect.getsource(_FUSE)


def _no_raw_back(cands: list[Any], **kw: Any) -> Any:
    """``combine`` with the raw box left out of the back face's weighted median."""
    c = _COMBINE(cands, **kw)
    keep = np.array([x.name != "raw" for x in cands])
    if keep.all() or not keep.any():
        return c
    w = np.array([c.weights[x.name] for x in cands])
    back = float(_MEDIAN(np.array([[x.hi[2]] for x in cands])[keep], w[keep])[0])
    hi = c.box.max.copy()
    hi[2] = back
    return dataclasses.replace(c, box=Box(c.box.min, hi))


def _fuse_spread(k: float) -> Any:
    """``fuse_depth`` with the candidates' back-face spread counted ``k`` times (0.5 in the library)."""
    space = dict(vars(ev))
    exec(compile(_FUSE_SOURCE.replace("(0.5 * spread) ** 2", f"({k} * spread) ** 2"), "fuse_depth", "exec"), space)
    return space["fuse_depth"]


def variants(sets: list[str], names: list[str]) -> None:
    loaded = []
    for spec in sets:
        label, _, rest = spec.partition("=")
        path, _, kind = rest.partition(":")
        views = [v for v in evid40._load(path) if not kind or kind in v["fruit_id"]]
        loaded.append((label, views))
    say("| variant | " + " | ".join(f"{label} ({len(views)})" for label, views in loaded) + " |")
    say("|---" * (len(loaded) + 1) + "|")
    for name in names:
        key, _, kv = name.partition("=")
        over = {k: float(x) for k, x in (item.split(":") for item in kv.split(","))} if kv else {}
        s = dataclasses.replace(ev.EvidenceSettings(), **over)
        ev.combine = _no_raw_back if key == "noraw" else _COMBINE  # type: ignore[assignment]
        ev.fuse_depth = _fuse_spread(float(key[6:])) if key.startswith("spread") else _FUSE  # type: ignore[assignment]
        rule = key if key in scans39.RULES else "default"
        cells = []
        for _, views in loaded:
            r = np.array([scans39.evaluate_view(v, s, rule) for v in views])
            cells.append(f"{r[:, 0].mean():.3f} / {r[:, 1].mean():.2f} / {int((r[:, 1] > 10).sum())}")
        say(f"| {name} | " + " | ".join(cells) + " |")
    ev.combine, ev.fuse_depth = _COMBINE, _FUSE  # type: ignore[assignment]


def _apex(t: np.ndarray, r: np.ndarray) -> float:
    """Where the conic ``r^2 = a + b t + c t^2`` fitted to a profile is widest (inf unless it closes, ``c < 0``)."""
    a = np.stack([np.ones_like(t), t, t * t], axis=1)
    _, b, c = np.linalg.lstsq(a, r * r, rcond=None)[0]
    return float(-b / (2 * c)) if c < 0 else float("inf")


def closure(tilt: float, kinds: list[str], n: int) -> None:
    say("| kind | tilt | closed views | mirror: mean / mean abs (mm) | conic apex: mean / mean abs (mm) |")
    say("|---|---|---|---|---|")
    for kind in kinds:
        mirror, conic = [], []
        for name, seen, _, truth in endon_views(kind, tilt, n):
            if "/" in kind and "pear" not in name:
                continue  # the scans' pear only (the banana is bent)
            rev = fit_revolution_slices(seen, coarse=64)
            d = rev.direction
            if d[2] ** 2 < 0.5:
                continue
            t, _ = closed_profile(rev)
            mid = 0.5 * (rev.edges[:-1] + rev.edges[1:])
            ok = np.isfinite(rev.radii)
            tm, rm = mid[ok], rev.radii[ok]
            if len(t) == len(tm):  # not closed
                continue
            if d[2] < 0:  # the far end first
                tm, rm = -tm[::-1], rm[::-1]
            tm = tm - tm[0]
            depth = float(truth.size[2])
            mirror.append(1000 * (2 * tm[-1] * abs(d[2]) - depth))
            apex = max(_apex(tm, rm), float(tm[-1]))
            conic.append(1000 * (2 * apex * abs(d[2]) - depth) if np.isfinite(apex) else np.nan)
        m, c = np.array(mirror), np.array(conic)
        say(f"| {kind} | {tilt:+.0f} | {len(m)} | {m.mean():+.1f} / {np.abs(m).mean():.1f} | "
            f"{np.nanmean(c):+.1f} / {np.nanmean(np.abs(c)):.1f} ({int(np.isnan(c).sum())} open) |")  # fmt: skip


def main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    for cmd in ("methods", "closure"):
        c = sub.add_parser(cmd)
        c.add_argument("--tilt", type=float, default=90.0)
        c.add_argument("--fruit", default=KINDS)
        c.add_argument("--n", type=int, default=3 if cmd == "methods" else 2)
        if cmd == "methods":
            c.add_argument("--methods", default="evidence,ellipsoid,sphere")
    v = sub.add_parser("variants")
    v.add_argument("rest", nargs=argparse.REMAINDER)
    a = p.parse_args(argv)
    if a.cmd == "methods":
        methods(a.tilt, a.fruit.split(","), a.methods.split(","), a.n)
    elif a.cmd == "closure":
        closure(a.tilt, a.fruit.split(","), a.n)
    else:
        if "--" not in a.rest:
            p.error("variants SETS... -- NAMES...")
        i = a.rest.index("--")
        variants(a.rest[:i], a.rest[i + 1 :])
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
