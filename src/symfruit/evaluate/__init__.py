"""Evaluation: protocols that make instances, a parallel runner, and reports.

``evaluate(...)`` is what ``symfruit evaluate`` calls; it drives the same public
:func:`symfruit.complete` a user calls.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..core.limits import shown
from ..errors import InputError
from ..settings import Settings
from ..synthetic.sensors import SENSOR_MODELS, checked_sensor_set
from ..synthetic.shapes import FRUITS
from .protocols import PAPER_ANGLES, POSES, SENSORS, Spec, build, skipped_scans, specs
from .report import markdown_table, write_results
from .runner import Row, run, summarise

__all__ = ["Evaluation", "Row", "Spec", "build", "evaluate", "markdown_table", "run", "specs", "summarise"]

#: ``--quick``: a handful of instances, well under a minute.
QUICK: dict[str, dict[str, Any]] = {"paper": {"n": 4, "angles": (-45, -30, -15, 0, 15, 30, 45)}, "camera": {"n": 8}}


@dataclass(frozen=True)
class Evaluation:
    """What :func:`evaluate` returns."""

    folder: Path | None
    rows: list[Row]
    summary: list[dict[str, Any]]
    table: str
    #: Scans of a scan folder left out as unreadable (path: reason); the others were evaluated.
    skipped: dict[str, str] = field(default_factory=dict)


def evaluate(
    *,
    protocol: str = "paper",
    fruits: Sequence[str] = ("strawberry",),
    methods: Sequence[str] = ("raw", "sphere", "ellipsoid", "superellipsoid", "paper", "fused", "evidence"),
    n: int | None = None,
    seed: int = 0,
    occlusions: Sequence[float] = (0.0,),
    sensor: str = "d435",
    sensor_set: Any = (),
    poses: str = "hanging",
    views: int = 1,
    quick: bool = False,
    settings: Settings | None = None,
    config: Path | None = None,
    output: Path | None = Path("results"),
    jobs: int | None = None,
    progress: bool = True,
) -> Evaluation:
    """Run a protocol for some fruit kinds (or scan folders) and methods; write the results.

    ``n`` is the number of fruits (``paper``: each in 19 poses; default 10, as in the paper) or of
    views per occlusion level (``camera``; default 100). ``sensor`` and ``poses`` choose the camera
    protocol's sensor model and pose distribution (:data:`~symfruit.evaluate.protocols.SENSORS`,
    :data:`~symfruit.evaluate.protocols.POSES`; ``poses="upright"`` also stands scans up in the paper
    protocol); ``sensor_set`` changes artefacts of a real camera model (``(name, value)`` pairs or a dict,
    :func:`symfruit.synthetic.sensors.varied`: a camera not modelled, or how far a model's values matter);
    ``views`` how many of a generated fruit's camera views are of one fruit (default 1: every view a fruit of its
    own). Results go to a new timestamped folder under ``output`` with a ``latest`` link to it;
    ``output=None`` writes nothing. Tables have a row per fruit kind, and per scan of a scan folder; a scan that
    cannot be read is left out, the others evaluated, and named in ``skipped`` (and ``settings.json``).

    Settings: ``settings`` for every fruit if given; otherwise each fruit kind's shipped profile
    (:mod:`symfruit.profiles`), with the settings file ``config`` laid over it.

    Raises
    ------
    InputError
        Before any work, for an argument the evaluation cannot run with (as ``symfruit evaluate`` checks its
        options): an unknown protocol, method, sensor or poses; ``fruits`` or ``methods`` empty, repeating a name
        or given as one string; ``n`` or ``views`` not 1-100000; ``jobs`` not 1-256; ``seed`` not 0 to 2**63 - 1;
        an occlusion level outside [0, 1); a ``sensor_set`` naming an unknown artefact, a value out of its bounds,
        or given without a real camera model.
    """
    from ..profiles import available_profiles
    from ..settings import resolve_settings

    fruits, methods, occlusions = _check_arguments(protocol, fruits, methods, n, seed, occlusions, sensor, poses, views,
                                                   jobs, settings)  # fmt: skip
    changes = checked_sensor_set(sensor_set)
    if changes and (protocol != "camera" or sensor not in SENSOR_MODELS):
        raise InputError(f"evaluate: sensor_set changes a real camera model of the camera protocol "
                         f"({', '.join(SENSOR_MODELS)}), not {protocol} / {sensor}")  # fmt: skip

    def settings_for(fruit: str) -> Settings:
        if settings is not None:
            return settings
        return resolve_settings(fruit=fruit if fruit in available_profiles() else None, config=config)

    angles = tuple(QUICK["paper"]["angles"]) if quick and protocol == "paper" else PAPER_ANGLES
    if n is None:
        n = QUICK[protocol]["n"] if quick else (10 if protocol == "paper" else 100)
    rows, all_specs, used, skipped = [], [], {}, {}
    for fruit in fruits:
        these = specs(protocol, fruit, n=n, seed=seed, angles=angles, occlusions=tuple(occlusions), sensor=sensor,
                      poses=poses, views=views, sensor_set=changes)  # fmt: skip
        skipped.update(skipped_scans(fruit) if fruit not in FRUITS else {})
        used[fruit] = settings_for(fruit)
        rows += run(these, methods, used[fruit], jobs=jobs, progress=progress)
        all_specs += these
    summary = summarise(rows)
    pooled = [s for s in summarise(rows, by=("fruit", "method")) if s.get("spearman") == s.get("spearman")]
    title = f"symfruit evaluation: {protocol} protocol"
    if protocol == "camera":
        title += f", {sensor} sensor, {poses} poses"
        if changes:
            title += " (sensor set: " + ", ".join(f"{k}={v:g}" for k, v in changes) + ")"
    elif poses != "hanging":
        title += f", {poses} scans"
    table = markdown_table(summary, protocol=protocol, title=title)
    if pooled:
        table += "\n## Confidence over all instances of a fruit (every occlusion level)\n\n"
        table += "| fruit | method | Spearman (confidence, centre dev) | centre dev (mm): all "
        table += "| 80 % most confident | reliable | views > 10 mm flagged unreliable |\n"
        table += "|---|---|---|---|---|---|---|\n"
        for s in pooled:
            flagged = "-" if s["bad_flagged"] != s["bad_flagged"] else f"{s['bad_flagged']:.0%} of {s['over_10mm']}"
            table += f"| {Path(str(s['fruit'])).name} | {s['method']} | {s['spearman']:.2f} "
            table += f"| {s['centre_mm_mean']:.1f} | {s['centre_mm_top80']:.1f} | {s['reliable_share']:.0%} "
            table += f"| {flagged} |\n"
    folder = None
    if output is not None:
        from .. import __version__
        from ..writers import new_results_folder

        folder = new_results_folder(output, protocol)

        meta = {
            "title": title, "version": __version__, "protocol": protocol, "fruits": list(fruits),
            "methods": list(methods), "n": n, "seed": seed, "occlusions": list(occlusions), "sensor": sensor,
            "sensor_set": dict(changes),
            "poses": poses, "views": views, "quick": quick,
            "instances": len(all_specs), "settings": {f: s.to_dict() for f, s in used.items()},
            "skipped_scans": skipped,
        }  # fmt: skip
        from ..io import write_json

        write_json(folder / "settings.json", meta)
        write_results(folder, rows, summary, protocol=protocol, meta={**meta, "confidence": pooled}, table=table)
    return Evaluation(folder=folder, rows=rows, summary=summary, table=table, skipped=skipped)


#: Most fruits (views) :func:`evaluate` generates per kind and occlusion level, and most views of a fruit: the
#: bounds ``symfruit evaluate --n`` and ``--views`` check; and most worker processes (``--jobs``).
MAX_N = 100_000
MAX_JOBS = 256


def _names(values: Any, what: str) -> list[str]:
    """``values`` as a non-empty list of distinct texts (a path for a fruit is taken as its text); a bare string
    is refused (it would be read a character at a time), as are an empty list and repeats."""
    if isinstance(values, str | bytes) or not isinstance(values, Sequence):
        raise InputError(f"evaluate: {what} must be a list of names, got {type(values).__name__} "
                         f"{shown(values)}")  # fmt: skip
    out = []
    for value in values:
        if isinstance(value, os.PathLike) and what == "fruits":
            value = os.fspath(value)
        if not isinstance(value, str) or not value.strip():
            raise InputError(f"evaluate: {what} must be names, got {shown(value)}")
        if value in out:
            raise InputError(f"evaluate: {what} lists {value!r} twice")
        out.append(value)
    if not out:
        raise InputError(f"evaluate: {what} is empty; name at least one")
    return out


def _whole(value: Any, what: str, low: int, high: int) -> None:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or not low <= value <= high:
        raise InputError(f"evaluate: {what} must be a whole number {low}-{high}, got {shown(value)}")


def _check_arguments(
    protocol: Any, fruits: Any, methods: Any, n: Any, seed: Any, occlusions: Any, sensor: Any, poses: Any, views: Any,
    jobs: Any, settings: Any,
) -> tuple[list[str], list[str], list[float]]:  # fmt: skip
    """The arguments of :func:`evaluate` checked before any work, as ``symfruit evaluate`` checks its options:
    ``(fruits, methods, occlusions)`` as lists. An empty list of fruits or methods, or ``n`` of 0, would evaluate
    nothing and write an empty table; an unknown method, a row of errors per instance.

    Raises
    ------
    InputError
        Naming the argument and the value.
    """
    from ..methods import get

    if protocol not in ("paper", "camera"):
        raise InputError(f"evaluate: unknown protocol {shown(protocol)}; use paper or camera (the masks protocol: "
                         "symfruit.evaluate.masks)")  # fmt: skip
    fruits = _names(fruits, "fruits")
    methods = _names(methods, "methods")
    for method in methods:
        get(method)  # an unknown one refused by name, with the registered ones
    if n is not None:
        _whole(n, "n", 1, MAX_N)
    _whole(views, "views", 1, MAX_N)
    if jobs is not None:
        _whole(jobs, "jobs", 1, MAX_JOBS)
    if not isinstance(sensor, str) or (sensor not in SENSORS and sensor not in SENSOR_MODELS):
        raise InputError(f"evaluate: unknown sensor {shown(sensor)}; known: {', '.join([*SENSORS, *SENSOR_MODELS])}")
    if poses not in POSES or (protocol == "paper" and poses == "uniform"):
        raise InputError(f"evaluate: poses must be one of {', '.join(POSES)} (uniform: the camera protocol's), got "
                         f"{shown(poses)}")  # fmt: skip
    _whole(seed, "seed", 0, 2**63 - 1)
    if isinstance(occlusions, str | bytes) or not isinstance(occlusions, Sequence | np.ndarray) or not len(occlusions):
        raise InputError(f"evaluate: occlusions must be a non-empty list of levels in [0, 1), got {shown(occlusions)}")
    levels = []
    for level in occlusions:
        if (
            isinstance(level, bool)
            or not isinstance(level, int | float | np.integer | np.floating)
            or not (0.0 <= level < 1.0)
        ):
            raise InputError(f"evaluate: occlusion levels must be numbers in [0, 1), got {shown(level)}")
        levels.append(float(level))
    if settings is not None and not isinstance(settings, Settings):
        raise InputError(f"evaluate: settings must be a Settings (symfruit.resolve_settings) or None, got "
                         f"{type(settings).__name__}")  # fmt: skip
    return fruits, methods, levels
