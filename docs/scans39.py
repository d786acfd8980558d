"""Replay `evidence`'s last two steps (the candidates' weighting, ``combine``, and the depth prior's fusion,
``fuse_depth``) on collected views, to measure variants of them without fitting the candidates again
(docs/scans39.md).

    python docs/scans39.py collect OUT.pkl EVALUATE-ARGS...
    python docs/scans39.py summary LABEL=OUT.pkl:KINDS [...] [--variant NAME ...] [--set NAME=key=value,...]
    python docs/scans39.py rob OUT.pkl [...]

``collect`` runs ``symfruit evaluate EVALUATE-ARGS --methods evidence --no-profile --jobs 1`` (the evaluation's own
instances, built and extracted as it does) and keeps, per view, the candidates `evidence` fitted, the inputs of
``combine`` and ``fuse_depth``, the terms of the uncertainty, the seen depths' 2nd, 50th and 98th percentiles and the
true box (a pickle: read it only from a run of your own). ``summary`` recomputes every view's box and confidence
under each variant and prints a row a variant, a column a set: ``KINDS`` is ``p7`` (the seven held-back proxies) or
one kind (``banana``, ``scan/011_banana``, ``scan/016_pear``); cells mean IoU / mean centre error (mm) / views over
10 mm, and for a fruit seen more than 4 times the within-fruit Spearman of confidence against centre error. The
``default`` variant is the method as it is (``summary`` says so when a view's replayed centre error differs from the
one ``evaluate`` scored). ``--set NAME=key=value,...`` adds a variant of `evidence`'s settings; a ``NAME`` of the form
``RULE+anything`` also applies the per-view rule ``RULE`` (below). ``rob`` prints, per kind, how far the seen
surface reaches beyond half the prior's width behind the front, over that width (98th percentile of the depths).

Per-view rules: ``TmisK`` (the weights' temperature times the best closed shape's depth misfit over ``misfit_noise``
times the noise, to the power K: correlated residuals where no shape explains the front; ``TmisKcC``: that factor at
most C), ``DmisK`` (the depth term's
weight alone divided by that ratio to the power K), ``sdroundE`` (the prior's
deviation times ``1 + E max(0, 2 - elongation^2)``: a round outline leaves the long axis's tilt open), ``sdrecC``
(times ``1 + C r``, ``r`` measured from the deepest seen point), ``rsCfF`` (times ``1 + C max(0, r - F)``, ``r`` from
the 98th percentile: a view receding beyond the prior's premise lets the shapes keep their say). Suffix ``+rc``: the
confidence's receding term counted only up to 0.2 widths. Run with ``PYTHONPATH=TREE/src``.
"""

from __future__ import annotations

import argparse
import dataclasses
import pickle
import sys
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.stats import spearmanr

import symfruit.methods.evidence as ev
from symfruit.core.box import Box
from symfruit.evaluate import runner
from symfruit.evaluate.metrics import box_iou, centre_deviation

P7 = ("strawberry", "apple", "citrus", "lemon", "peach", "pear", "plum")
View = dict[str, Any]
Rule = Callable[[View, ev.EvidenceSettings], ev.EvidenceSettings]


def collect(out: str, argv: list[str]) -> int:
    from symfruit.cli import main

    caught: dict[str, Any] = {}
    views: list[View] = []
    combine, fuse_depth, score, complete = ev.combine, ev.fuse_depth, runner.score_completion, runner.complete
    instance = runner._evaluate_instance

    def keep_combine(cands, **kw):
        caught["combine"] = {k: v for k, v in kw.items() if k != "s"}
        return combine(cands, **kw)

    def keep_fusion(combined, cands, region, camera, **kw):
        caught.update(cands=cands, fuse={k: v for k, v in kw.items() if k != "s"})
        return fuse_depth(combined, cands, region, camera, **kw)

    def keep_result(*a, **kw):
        caught["result"] = r = complete(*a, **kw)
        caught["z"] = np.percentile(np.asarray(a[0])[:, 2], [2, 50, 98])
        return r

    def keep_score(box, points, truth_box, truth_surface):
        s = score(box, points, truth_box, truth_surface)
        if "fuse" in caught:
            e = caught["result"].extras
            views.append(dict(cands=caught["cands"], combine=caught["combine"], fuse=caught["fuse"],
                              truth=(truth_box.min, truth_box.max), centre_mm=s.centre_mm, iou=s.iou,
                              recede=e["recede"], elongation=e["elongation"], unexplained=e["unexplained"],
                              confidence=e["confidence"], z=caught["z"]))  # fmt: skip
        caught.clear()
        return s

    def keep_instance(spec, methods, settings):
        rows = instance(spec, methods, settings)
        for r in rows:
            if not r.error and views and "kind" not in views[-1]:
                views[-1].update(kind=r.kind, fruit_id=f"{r.kind}#{r.fruit_index}", pose=r.pose)
        return rows

    ev.combine, ev.fuse_depth, runner.score_completion = keep_combine, keep_fusion, keep_score
    runner.complete, runner._evaluate_instance = keep_result, keep_instance
    code = main(["evaluate", *argv, "--methods", "evidence", "--no-profile", "--jobs", "1"])
    kept = [v for v in views if "kind" in v]
    with open(out, "wb") as f:
        pickle.dump(kept, f)
    sys.stderr.write(f"{len(kept)} views: {out} (evaluate exit {code})\n")
    return int(code or 0)


def _dense(v: View) -> bool:
    """A depth camera's view: the ``cone`` ellipsoid is fitted only there (and may be left out as implausible),
    and only there does ``evidence`` measure how far the view recedes."""
    return v["recede"] > 0 or any(c.name == "cone" for c in v["cands"])


def _width(v: View, s: ev.EvidenceSettings) -> tuple[float, float]:
    """(front, the prior's width) of a view, metres."""
    comb = ev.combine(v["cands"], s=s, **v["combine"])
    _, _, width = ev.fuse_depth(comb, v["cands"], None, None, s=dataclasses.replace(s, depth_ratio_sd=0.0),
                                **v["fuse"])  # fmt: skip
    return float(comb.box.min[2]), width


def recede_over_width(v: View, s: ev.EvidenceSettings, deepest: float | None = None) -> float:
    """How much deeper than half the prior's width the seen surface reaches behind the front, over that width
    (the seen depths' 98th percentile unless ``deepest``); 0 for a sparse cloud."""
    front, width = _width(v, s)
    if not _dense(v) or width <= 0:
        return 0.0
    deep = float(v["z"][2]) if deepest is None else deepest
    return max(0.0, deep - front - 0.5 * width) / width


def _misfit_ratio(v: View) -> float:
    """The best closed shape's depth RMS over ``misfit_noise`` times the noise (1 where it is within it)."""
    rms = min((c.agreement.depth for c in v["cands"] if c.agreement is not None), default=None)
    if rms is None or v["unexplained"] <= 0:
        return 1.0
    return float(rms / np.sqrt(max(rms**2 - v["unexplained"] ** 2, 1e-18)))


RULES: dict[str, Rule] = {}
for _k in (0.5, 1.0, 2.0):
    RULES[f"Tmis{_k:g}"] = (lambda k: lambda v, s: dataclasses.replace(
        s, temperature=s.temperature * _misfit_ratio(v) ** k))(_k)  # fmt: skip
for _k, _cap in ((2.0, 2.0), (2.0, 3.0), (2.0, 4.0), (1.0, 2.0)):  # the temperature's factor at most _cap
    RULES[f"Tmis{_k:g}c{_cap:g}"] = (lambda k, cap: lambda v, s: dataclasses.replace(
        s, temperature=s.temperature * min(cap, _misfit_ratio(v) ** k)))(_k, _cap)  # fmt: skip
for _k in (1.0, 2.0):
    RULES[f"Dmis{_k:g}"] = (lambda k: lambda v, s: dataclasses.replace(
        s, depth_weight=s.depth_weight / _misfit_ratio(v) ** k))(_k)  # fmt: skip
for _e in (1.0, 2.0):
    RULES[f"sdround{_e:g}"] = (lambda e: lambda v, s: dataclasses.replace(
        s, depth_ratio_sd=s.depth_ratio_sd * (1.0 + e * max(0.0, 2.0 - v["elongation"] ** 2))))(_e)  # fmt: skip
for _c in (1.0, 2.0, 4.0):
    RULES[f"sdrec{_c:g}"] = (lambda c: lambda v, s: dataclasses.replace(
        s, depth_ratio_sd=s.depth_ratio_sd * (1.0 + c * recede_over_width(v, s, v["fuse"]["seen_back"])))
    )(_c)  # fmt: skip
for _c, _free in ((2.0, 0.0), (2.0, 0.2), (4.0, 0.2)):  # measured from the 98th percentile, a free zone
    RULES[f"rs{_c:g}f{_free:g}"] = (lambda c, free: lambda v, s: dataclasses.replace(
        s, depth_ratio_sd=s.depth_ratio_sd * (1.0 + c * max(0.0, recede_over_width(v, s) - free)))
    )(_c, _free)  # fmt: skip
VARIANTS: dict[str, dict[str, float]] = {"default": {}, **{name: {} for name in RULES}}
VARIANTS.update({f"T{t:g}": {"temperature": t} for t in (1.5, 3.0)})


def evaluate_view(v: View, s: ev.EvidenceSettings, name: str = "default") -> tuple[float, float, float]:
    """(IoU, centre error mm, confidence) of one view under settings ``s`` and the variant ``name``'s rule."""
    rule = RULES.get(name.split("+")[0])
    if rule is not None:
        s = rule(v, s)
    fuse = v["fuse"]
    cands = v["cands"]
    combined = ev.combine(cands, s=s, **v["combine"])
    box, _, width = ev.fuse_depth(combined, cands, None, None, s=s, **fuse)
    moved = 0.5 * abs(float(box.max[2] - combined.box.max[2]))
    recede = combined.contour * max(0.0, fuse["seen_back"] - float(box.min[2]) - 0.5 * width) if _dense(v) else 0.0
    if name.endswith("+rc"):
        recede = min(recede, 0.2 * width)
    u = v["elongation"] * float(np.sqrt(combined.uncertainty**2 + moved**2 + (s.recede_scale * recede) ** 2
                                        + (s.unexplained_scale * v["unexplained"]) ** 2))  # fmt: skip
    truth = Box(*v["truth"])
    return box_iou(box, truth), centre_deviation(box, truth) * 1000.0, float(np.exp(-u / s.uncertainty_scale))


def within(ids: np.ndarray, conf: np.ndarray, err: np.ndarray) -> float:
    """Mean over fruits of at least 5 views of the Spearman of confidence against centre error."""
    found = []
    for fruit in dict.fromkeys(ids):
        ix = ids == fruit
        if ix.sum() >= 5 and np.ptp(conf[ix]) > 0:
            r = spearmanr(conf[ix], err[ix])[0]
            if np.isfinite(r):
                found.append(r)
    return float(np.mean(found)) if found else float("nan")


def load(spec: str) -> tuple[str, list[View]]:
    label, _, rest = spec.partition("=")
    path, _, kinds = rest.partition(":")
    with open(path, "rb") as f:
        views = pickle.load(f)
    for v in views:  # collected while fuse_depth took the seen depths' percentile (a trial, off: the default)
        v["fuse"].pop("seen_deep", None)
    if kinds == "p7":
        return label, [v for v in views if v["kind"].split("/")[0] in P7]
    return label, [v for v in views if not kinds or v["kind"] == kinds]


def say(line: str) -> None:
    sys.stdout.write(line + "\n")


def summary(sets: list[str], names: list[str]) -> None:
    loaded = [load(spec) for spec in sets]
    say("| variant | " + " | ".join(f"{label} ({len(views)})" for label, views in loaded) + " |")
    say("|---" * (len(loaded) + 1) + "|")
    for name in names:
        overrides = VARIANTS.get(name, {} if name.split("+")[0] in RULES else None)
        if overrides is None:
            raise SystemExit(f"unknown variant {name!r}: default, {', '.join(VARIANTS)} or a --set name")
        s = dataclasses.replace(ev.EvidenceSettings(), **overrides)
        cells = []
        for _, views in loaded:
            r = np.array([evaluate_view(v, s, name) for v in views])
            if name == "default" and (
                np.abs(r[:, 1] - [v["centre_mm"] for v in views]).max() > 1e-6
                or np.abs(r[:, 2] - [v["confidence"] for v in views]).max() > 1e-9
            ):
                say(f"(the default's replay differs from evaluate's scores or confidences on {_})")
            w = within(np.array([v["fruit_id"] for v in views]), r[:, 2], r[:, 1])
            cells.append(f"{r[:, 0].mean():.3f} / {r[:, 1].mean():.2f} / {(r[:, 1] > 10).sum()}"
                         + (f" / {w:+.2f}" if np.isfinite(w) else ""))  # fmt: skip
        say(f"| {name} | " + " | ".join(cells) + " |")


def rob(paths: list[str]) -> None:
    s = ev.EvidenceSettings()
    for path in paths:
        _, views = load(f"x={path}:")
        kinds: dict[str, list[float]] = {}
        for v in views:
            kinds.setdefault(v["kind"].split("/")[0], []).append(recede_over_width(v, s))
        for kind, r in kinds.items():
            a = np.array(r)
            say(f"{path} {kind}: n {len(a)}, median {np.median(a):.2f}, "
                f"90th percentile {np.percentile(a, 90):.2f}, max {a.max():.2f}")  # fmt: skip


def main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawTextHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("collect", help="run evaluate and keep every view's candidates")
    c.add_argument("out")
    c.add_argument("evaluate", nargs=argparse.REMAINDER)
    m = sub.add_parser("summary", help="a row a variant, a column a set")
    m.add_argument("sets", nargs="+", help="LABEL=PATH:KINDS (KINDS p7, a kind, or empty for all)")
    m.add_argument("--variant", action="append", help="default, T1.5, T3, " + ", ".join(RULES) + " or a --set name")
    m.add_argument("--set", action="append", default=[], help="NAME=key=value,...: a variant of the settings")
    r = sub.add_parser("rob", help="how far each kind's views recede beyond half the prior's width")
    r.add_argument("paths", nargs="+")
    a = p.parse_args(argv)
    if a.cmd == "collect":
        return collect(a.out, a.evaluate)
    if a.cmd == "rob":
        rob(a.paths)
        return 0
    for spec in a.set:
        name, _, kv = spec.partition("=")
        VARIANTS[name] = {k: float(x) for k, x in (item.split("=") for item in kv.split(","))}
    summary(a.sets, a.variant or ["default"])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
