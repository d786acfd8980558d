"""Stop 65, helper flat65: why the tree apples' seen caps read flatter than a round section (docs/flat65.md).

``run FRAMES OUT.jsonl``: ``symfruit evaluate --frames FRAMES --match id --methods evidence`` in this process, with
the settings of a shared evaluation's ``summary.json`` (``--settings``, default the CW1 run of seeds 0-3) and
``--set`` changes (e.g. ``evidence.lost_rim=cap``), recording for every scored fruit the seen cap that
``core.raster.axis_tilt`` read (where it was read: a whole outline) next to its scores and the 2-D thin-lens
reference. ``summary OUT.jsonl ...``: per run, the caps and the visible apples' box sides against the thin-lens
estimate from the same masks. ``thin --eval SUMMARY.json ... --frames DIR ...``: the visible apples' box sides
against that estimate, and how much of its error is the camera's obliquity. ``truth SEED N OUT.jsonl``: every
apple's true shape and pose (re-drawn from the scenes' seeds) and the cap a spheroid of that shape and pose shows.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

SHARED = Path("/tmp/lead65/shared/eval-trees0/latest/summary.json")


def _say(text: str) -> None:
    sys.stdout.write(text + "\n")


def _value(text: str) -> Any:
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return text


def _mask_moved(
    e: np.ndarray, outer: Any, camera: Any, across: Any, centre: np.ndarray, frame: np.ndarray, reach: float
) -> np.ndarray:
    """``core.raster._outline_to``'s variant for ``run --outline moved``: the mask's own outline (what it overshoots
    the fruit by taken off, as ``evidence._tilt_outer`` gives it) moved to the points' outline's middle, instead of
    the points' outline scaled to the mask's widths (a registration shift moves the mask; the lost rim band's wavy
    edge makes the points' extremes wider than its typical outline, so the scaled outline is too small)."""
    from symfruit.core.raster import outline_cracks

    cracks = outline_cracks(outer)
    if len(cracks) < 8:
        return e
    rays = camera.rays(cracks[:, 0], cracks[:, 1]).reshape(-1, 3)
    o = ((rays @ across.basis.T) / (rays @ across.axis)[:, None] - centre) @ frame
    return o - 0.5 * (o.min(axis=0) + o.max(axis=0)) + 0.5 * (e.min(axis=0) + e.max(axis=0))


def run(frames: str, out: str, settings_from: str, changes: list[str], outline: str = "scaled") -> None:
    from symfruit.core import raster
    from symfruit.evaluate import frames as fr
    from symfruit.methods import evidence
    from symfruit.settings import from_dict

    data = json.loads(Path(settings_from).read_text())["settings"]
    for change in changes:
        key, _, value = change.partition("=")
        section, _, name = key.partition(".")
        data[section][name] = _value(value)
    settings = from_dict(data)
    seen: list[Any] = []
    records: list[Any] = []
    tilt_of = evidence.axis_tilt
    complete_of = fr.complete

    def tilt(*args: Any, **kwargs: Any) -> Any:
        t = tilt_of(*args, **kwargs)
        if not seen:
            seen.append(t)  # the first fit (with ``both`` the bracket's inner)
        return t

    def complete(*args: Any, **kwargs: Any) -> Any:
        seen.clear()
        result = complete_of(*args, **kwargs)  # raises: no score, no record
        records.append(seen[0] if seen else None)
        return result

    evidence.axis_tilt = tilt
    fr.complete = complete
    outline_of = raster._outline_to
    if outline == "moved":
        raster._outline_to = _mask_moved
    try:
        scores, totals, _failed = fr.evaluate_frames(frames, methods=["evidence"], settings=settings, by_id=True)
    finally:
        evidence.axis_tilt = tilt_of
        fr.complete = complete_of
        raster._outline_to = outline_of
    if len(scores) != len(records):
        raise SystemExit(f"{len(scores)} scores, {len(records)} fits: cannot pair them")
    floor = settings.evidence.tilt_floor
    with open(out, "w") as fh:
        for s, t in zip(scores, records, strict=True):
            row = dict(vars(s))
            if t is not None and t.count > 0:
                row.update(cap=t.cap, cap_sd=t.cap_sd, share=t.oblate_share(floor), slope_major=t.slope_major,
                           slope_minor=t.slope_minor, slope_sd=t.slope_sd, major=t.major, minor=t.minor,
                           count=t.count)  # fmt: skip
            fh.write(json.dumps(row) + "\n")
    _say(f"{out}: {len(scores)} fruit, {sum(r is not None and r.count > 0 for r in records)} caps; {totals}")


def _rows(path: str) -> list[dict[str, Any]]:
    return [json.loads(line) for line in Path(path).read_text().splitlines() if line.strip()]


def _ma(x: np.ndarray) -> str:
    return f"{np.mean(np.abs(x)):.1f} ({np.mean(x):+.1f})" if len(x) else "-"


def summary(paths: list[str], visible: float) -> None:
    _say("| run | caps | median cap | under 0.95 | share < 0.5 | visible n | depth side | lateral | thin-lens lat. |")
    _say("|---|---|---|---|---|---|---|---|---|")
    for path in paths:
        rows = _rows(path)
        caps = np.array([r["cap"] for r in rows if "cap" in r])
        shares = [r["share"] for r in rows if r.get("share") is not None]
        vis = [r for r in rows if r["visible"] >= visible]
        d = np.array([r["depth_mm"] for r in vis])
        lat = np.array([r["lateral_mm"] for r in vis])
        thin = np.array([r["thin_lateral_mm"] for r in vis])
        med = f"{np.median(caps):.2f}" if len(caps) else "-"
        under = int((caps < 0.95).sum())
        _say(f"| {Path(path).stem} | {len(caps)} | {med} | {under} | {sum(s < 0.5 for s in shares)} of {len(shares)} | "
             f"{len(vis)} | {_ma(d)} | {_ma(lat)} | {_ma(thin)} |")  # fmt: skip


def thin(evaluations: list[str], frames: list[str], visible: float) -> None:
    """The visible apples' box sides against the 2-D thin-lens estimate from the same masks (``thin_lateral_mm``, as
    ``symfruit evaluate`` scores it), and the part of the thin-lens error a pinhole camera's obliquity makes: a
    round fruit ``theta`` off the optical axis images ``1 / cos(theta)`` wider radially than on it, so the mask's
    extent times its depth over ``f`` reads ``D / cos(theta)`` (truth.json's centre gives ``theta``)."""
    _say("| evaluation | visible n | off-axis median / max (deg) | box depth side | box lateral | thin-lens lateral | "
          "thin-lens less the obliquity | corr(off-axis, thin-lens error) |")  # fmt: skip
    _say("|---|---|---|---|---|---|---|---|")
    for ev, folder in zip(evaluations, frames, strict=True):
        scores = json.loads(Path(ev).read_text())["scores"]
        out = []
        for r in scores:
            if not r["visible"] >= visible:
                continue
            fruits = json.loads((Path(folder) / r["frame"] / "truth.json").read_text())["fruits"]
            f = next(x for x in fruits if x["id"] == r["truth"])
            c = np.array(f["centre"])
            theta = math.acos(c[2] / np.linalg.norm(c))
            big = 1000.0 * max(f["size"][:2])
            out.append((math.degrees(theta), r["thin_lateral_mm"], r["lateral_mm"], r["depth_mm"],
                        r["thin_lateral_mm"] - big * (1.0 / math.cos(theta) - 1.0)))  # fmt: skip
        o = np.array(out)
        angle = f"{np.median(o[:, 0]):.0f} / {o[:, 0].max():.0f}"
        _say(f"| {ev} | {len(o)} | {angle} | {_ma(o[:, 3])} | {_ma(o[:, 2])} | {_ma(o[:, 1])} | {_ma(o[:, 4])} | "
             f"{np.corrcoef(o[:, 0], o[:, 1])[0, 1]:.2f} |")  # fmt: skip


def spheroid_cap(a: float, c: float, rot: np.ndarray) -> dict[str, float]:
    """The seen cap of a spheroid (equatorial radius ``a``, half-length ``c``, its axis the rotated y axis) seen along
    z, in :func:`~symfruit.core.raster.axis_tilt`'s terms: its outline's half-widths and the sag of its front's
    section across the outline's major axis through the middle over the outline's half-width there."""
    u = rot @ np.array([0.0, 1.0, 0.0])
    dual = a * a * np.eye(3) + (c * c - a * a) * np.outer(u, u)  # the dual quadric of the centred spheroid
    img = dual[:2, :2]
    w, v = np.linalg.eigh(img)
    minor, major = float(np.sqrt(w[0])), float(np.sqrt(w[1]))
    q = np.r_[v[:, 0], 0.0]  # the outline's minor direction; sections across the major axis hold q and z
    # the section through the middle in the (q, z) plane: the spheroid's quadric restricted to it
    quad = np.linalg.inv(dual)
    basis = np.c_[q, [0.0, 0.0, 1.0]]
    m = basis.T @ quad @ basis  # x^T m x = 1
    area = math.pi / math.sqrt(float(np.linalg.det(m)))
    h = minor  # the outline's half-width across the major axis through the middle: the section's own q extent
    # (the major axis is a principal axis of the outline and the q-z plane is conjugate to it for a spheroid whose
    # axis lies in it or across it; in general the section's q extent: sqrt of the inverse's (0, 0))
    h_sec = math.sqrt(float(np.linalg.inv(m)[0, 0]))
    chord = area / (math.pi * h_sec)  # half the chord along z through the section's middle (an affine image's area)
    return {"major": major, "minor": minor, "cap": chord / h, "cap_section": chord / h_sec,
            "tilt_deg": math.degrees(math.asin(min(abs(float(u[2])), 1.0)))}  # fmt: skip


def truth(seed: int, n: int, out: str) -> None:
    """Every apple's drawn shape (diameter, height ratio) and rotation, re-drawn by running the tree scene's own
    draws with the render and the sensor stubbed out (``make_tree_scene`` draws the geometry first)."""
    from symfruit.synthetic import scenes, shapes

    rows: list[dict[str, Any]] = []
    for s in range(seed, seed + n):
        drawn: list[dict[str, Any]] = []
        rotation_of, pome_of = scenes.rotation, shapes._pome

        def pome(rng: Any, drawn: list[dict[str, Any]] = drawn, pome_of: Any = pome_of, **kw: Any) -> Any:
            drawn.append({"diameter": kw["diameter"], "height_ratio": kw["height_ratio"]})
            return pome_of(rng, **kw)

        def rotation(*angles: float, drawn: list[dict[str, Any]] = drawn, rotation_of: Any = rotation_of) -> Any:
            r = rotation_of(*angles)
            if len(drawn) and "rot" not in drawn[-1]:
                drawn[-1]["rot"] = np.asarray(r).tolist()
                drawn[-1]["angles"] = list(angles)
            return r

        class Stop(Exception):
            pass

        def render(*_a: Any, **_k: Any) -> Any:
            raise Stop

        render_of = scenes.render
        setattr(shapes, "_pome", pome)  # noqa: B010 (replaced for the call, put back below)
        setattr(scenes, "rotation", rotation)  # noqa: B010
        setattr(scenes, "render", render)  # noqa: B010
        try:
            scenes.make_tree_scene(s)
        except Stop:
            pass
        finally:
            setattr(shapes, "_pome", pome_of)  # noqa: B010
            setattr(scenes, "rotation", rotation_of)  # noqa: B010
            setattr(scenes, "render", render_of)  # noqa: B010
        for k, d in enumerate(drawn):
            a = 0.5 * d["diameter"]
            c = a * d["height_ratio"]
            row = {"seed": s, "fruit": k + 1, **d, **spheroid_cap(a, c, np.array(d["rot"]))}
            rows.append(row)
    with open(out, "w") as fh:
        for row in rows:
            fh.write(json.dumps(row) + "\n")
    _say(f"{out}: {len(rows)} apples")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="evaluate FRAMES with evidence, recording each whole outline's seen cap")
    r.add_argument("frames")
    r.add_argument("out")
    r.add_argument("--settings", default=str(SHARED), help="a shared evaluation's summary.json (its settings)")
    r.add_argument("--set", action="append", default=[], help="SECTION.NAME=VALUE (JSON value), e.g. "
                   "evidence.lost_rim=cap")  # fmt: skip
    r.add_argument("--outline", choices=("scaled", "moved"), default="scaled",
                   help="tilt_outline mask's outline: the points' scaled to the mask's widths (the library's) or "
                   "the mask's own moved to the points' middle (an experiment, docs/flat65.md)")  # fmt: skip
    s = sub.add_parser("summary", help="caps and the visible apples' sides against the thin-lens estimate")
    s.add_argument("runs", nargs="+")
    s.add_argument("--visible", type=float, default=0.9)
    h = sub.add_parser("thin", help="visible apples' box sides against the thin-lens estimate, and its obliquity")
    h.add_argument("--eval", nargs="+", required=True, help="summary.json of symfruit evaluate --match id runs")
    h.add_argument("--frames", nargs="+", required=True, help="their frame folders (truth.json), in the same order")
    h.add_argument("--visible", type=float, default=0.9)
    t = sub.add_parser("truth", help="every apple's drawn shape and pose, and its spheroid's cap")
    t.add_argument("seed", type=int)
    t.add_argument("n", type=int)
    t.add_argument("out")
    a = p.parse_args()
    if a.cmd == "run":
        run(a.frames, a.out, a.settings, a.set, a.outline)
    elif a.cmd == "summary":
        summary(a.runs, a.visible)
    elif a.cmd == "thin":
        thin(a.eval, a.frames, a.visible)
    else:
        truth(a.seed, a.n, a.out)


if __name__ == "__main__":
    main()
