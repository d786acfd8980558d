"""Run methods on instances, in parallel over processes, through the public :func:`symfruit.complete`."""

from __future__ import annotations

import os
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError, SymfruitError
from ..extract import extract, register
from ..methods.complete import complete
from ..occlusion import fruit_occlusion
from ..progress import Progress
from ..settings import Settings
from ..threads import one_blas_thread
from .metrics import score_completion
from .protocols import Spec, build

__all__ = ["Row", "run"]

#: A view is badly off when its centre deviation exceeds this (mm): the worst-case columns count them.
BAD_MM = 10.0

#: Columns of the per-instance CSV, in order.
COLUMNS = (
    "protocol", "fruit", "kind", "fruit_index", "pose", "angle_x", "angle_y", "angle_z", "distance_m",
    "occlusion", "hidden", "n_visible", "method", "iou", "centre_mm", "chamfer_mm", "f1", "precision",
    "recall", "depth_mm", "lateral_mm", "seconds", "confidence", "reliable", "error",
)  # fmt: skip


@dataclass(frozen=True)
class Row:
    """One method on one instance."""

    protocol: str
    fruit: str
    kind: str
    fruit_index: int
    pose: int
    angle_x: float
    angle_y: float
    angle_z: float
    distance_m: float
    occlusion: float
    hidden: float
    n_visible: int
    method: str
    iou: float
    centre_mm: float
    chamfer_mm: float
    f1: float
    precision: float
    recall: float
    seconds: float
    depth_mm: float = float("nan")
    lateral_mm: float = float("nan")
    confidence: float = float("nan")
    reliable: bool = False
    error: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {c: getattr(self, c) for c in COLUMNS}

    @property
    def label(self) -> str:
        """What tables group by: the fruit kind, or the scan (``scan/016_pear``) of a scan folder."""
        return self.kind if self.kind.startswith("scan/") else self.fruit

    @property
    def instance(self) -> tuple[Any, ...]:
        """What identifies the instance (the same for every method run on it)."""
        return (self.protocol, self.fruit, self.fruit_index, self.pose, self.occlusion)


def _evaluate(spec: Spec, methods: Sequence[str], settings: Settings) -> list[Row]:
    """Build one instance and run every method on it (runs in a worker process). An instance that cannot be
    built or prepared, and a method that fails in any way, give rows carrying the error: the run goes on
    (in a worker pool one exception ended the whole evaluation, every finished instance lost)."""
    try:
        return _evaluate_instance(spec, methods, settings)
    except Exception as exc:  # the instance itself: every method's row says why
        return _failed_rows(spec, methods, _reason(exc))


def _failed_rows(spec: Spec, methods: Sequence[str], reason: str) -> list[Row]:
    """The rows of an instance that could not be evaluated, each method's carrying ``the instance: reason``."""
    nan = float("nan")
    return [Row(protocol=spec.protocol, fruit=spec.fruit, kind="", fruit_index=spec.index, pose=spec.pose,
                angle_x=nan, angle_y=nan, angle_z=nan, distance_m=nan, occlusion=spec.occlusion, hidden=nan,
                n_visible=0, method=method, iou=nan, centre_mm=nan, chamfer_mm=nan, f1=nan, precision=nan,
                recall=nan, seconds=nan, error=f"the instance: {reason}") for method in methods]  # fmt: skip


#: A row's reason when the worker process evaluating its instance died (stop 48, robust48).
WORKER_DIED = ("its worker process ended abruptly (killed, e.g. out of memory, or a crash in compiled code); "
               "the others went on")  # fmt: skip


def _isolated(batch: list[Spec], methods: Sequence[str], settings: Settings) -> list[Row]:
    """``batch`` evaluated again after its worker pool broke, each instance in a worker process of its own: the
    instance whose process dies again gets rows saying so (:data:`WORKER_DIED`), the others their results."""
    rows: list[Row] = []
    for spec in batch:
        try:
            with ProcessPoolExecutor(max_workers=1, initializer=one_blas_thread) as one:
                rows += one.submit(_batch, ([spec], methods, settings)).result()
        except BrokenProcessPool:
            rows += _failed_rows(spec, methods, WORKER_DIED)
    return rows


def _reason(exc: BaseException) -> str:
    """An error's message; for anything but a refusal of the input, its type too (a fault, not the data)."""
    return str(exc) if isinstance(exc, SymfruitError) else f"internal error ({type(exc).__name__}: {exc})"


def _evaluate_instance(spec: Spec, methods: Sequence[str], settings: Settings) -> list[Row]:
    inst = build(spec)
    visible, mask = inst.visible, inst.mask
    failed = ""
    camera = inst.camera
    if inst.extract and mask is not None and inst.depth is not None:  # as ``detect`` takes a fruit's points
        moved, shift = register(mask.astype(np.int32), inst.depth, inst.camera, settings.extract)
        mask = moved > 0
        camera = inst.camera.shifted(*shift)
        ex = extract(mask, inst.depth, camera, settings.extract)
        visible = ex.points
        mask = ex.silhouette if ex.silhouette is not None else mask
        if len(visible) < settings.extract.min_points:
            failed = f"only {len(visible)} points extracted (extract.min_points = {settings.extract.min_points})"
    base: dict[str, Any] = dict(
        protocol=spec.protocol, fruit=spec.fruit, kind=inst.kind, fruit_index=spec.index, pose=spec.pose,
        angle_x=inst.angles[0], angle_y=inst.angles[1], angle_z=inst.angles[2], distance_m=inst.distance,
        occlusion=spec.occlusion, hidden=inst.hidden, n_visible=len(visible),
    )  # fmt: skip
    rows = []
    occlusion = None
    if inst.depth is not None and mask is not None and len(visible) and not failed:
        occlusion = fruit_occlusion(inst.depth, mask, visible, camera, settings.occlusion,
                                    eroded=settings.extract.erode_px if inst.extract else 0)  # fmt: skip
    for method in methods:
        try:
            if failed:
                raise InputError(failed)
            result = complete(visible, camera=camera, method=method, settings=settings, occlusion=occlusion)
            s = score_completion(result.box, result.points, inst.truth_box, inst.truth_surface)
        except Exception as exc:  # one method's failure, whatever it is, is its row's; the others go on
            nan = float("nan")
            rows.append(Row(**base, method=method, iou=nan, centre_mm=nan, chamfer_mm=nan, f1=nan,
                            precision=nan, recall=nan, seconds=nan, error=_reason(exc)))  # fmt: skip
            continue
        conf = float("nan") if result.confidence is None else result.confidence
        rows.append(Row(**base, method=method, iou=s.iou, centre_mm=s.centre_mm, chamfer_mm=s.chamfer_mm,
                        f1=s.f1, precision=s.precision, recall=s.recall, seconds=result.seconds,
                        depth_mm=s.depth_mm, lateral_mm=s.lateral_mm,
                        confidence=conf, reliable=bool(result.reliable)))  # fmt: skip
    return rows


def _batch(args: tuple[list[Spec], Sequence[str], Settings]) -> list[Row]:
    specs, methods, settings = args
    return [row for spec in specs for row in _evaluate(spec, methods, settings)]


def run(
    specs: Sequence[Spec],
    methods: Sequence[str],
    settings: Settings | None = None,
    *,
    jobs: int | None = None,
    progress: bool = True,
) -> list[Row]:
    """Evaluate every method on every instance; rows come back in spec order.

    Parameters
    ----------
    jobs : int, optional
        Worker processes (default: the number of CPUs); 1 runs in this process. Each worker runs
        single-threaded BLAS so workers do not fight over cores.
    """
    settings = settings or Settings()
    if jobs is not None and (isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1):
        raise InputError(f"jobs must be a whole number >= 1, got {jobs!r}")
    jobs = jobs or os.cpu_count() or 1
    chunk = max(1, min(8, len(specs) // (4 * jobs) or 1))
    batches = [list(specs[i : i + chunk]) for i in range(0, len(specs), chunk)]
    out: list[list[Row]] = []
    with Progress(len(specs), "evaluate", enabled=progress) as bar:
        if jobs == 1:
            for b in batches:
                out.append(_batch((b, methods, settings)))
                bar.update(len(b))
        else:
            with ProcessPoolExecutor(max_workers=jobs, initializer=one_blas_thread) as pool:
                futures = [pool.submit(_batch, (b, methods, settings)) for b in batches]
                for b, future in zip(batches, futures, strict=True):
                    try:
                        rows = future.result()
                    except BrokenProcessPool:  # a worker died (killed, out of memory): the pool is lost, every
                        # batch not yet back is evaluated again alone (stop 48, robust48: a BrokenProcessPool
                        # traceback ended the evaluation, every finished batch lost)
                        rows = _isolated(b, methods, settings)
                    out.append(rows)
                    bar.update(len(b))
    return [row for rows in out for row in rows]


def average_ranks(x: np.ndarray) -> np.ndarray:
    """Ranks 1..n of the values of ``x`` (n,), ties given the mean of the ranks they share (``scipy.stats.rankdata``'s
    ``average``, which its ``spearmanr`` uses)."""
    order = np.argsort(x, kind="stable")
    ordered = x[order]
    edges = np.flatnonzero(np.r_[True, ordered[1:] != ordered[:-1], True])  # where each run of equal values starts
    ranks = np.empty(len(x))
    ranks[order] = np.repeat((edges[:-1] + edges[1:] + 1) / 2.0, np.diff(edges))
    return ranks


def spearman(x: np.ndarray, y: np.ndarray) -> float:
    """Spearman's rank correlation of ``x`` and ``y`` (n,): the Pearson correlation of their average ranks, as
    ``scipy.stats.spearmanr(x, y).statistic`` computes it (``np.corrcoef`` of the ranks); NaN when either holds a
    NaN or does not vary. (scipy.stats itself is not imported: it alone took 0.6 s of CPU to import.)"""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if np.isnan(x).any() or np.isnan(y).any() or not np.ptp(x) > 0 or not np.ptp(y) > 0:
        return float("nan")
    return float(np.corrcoef(np.column_stack([average_ranks(x), average_ranks(y)]), rowvar=False)[1, 0])


def _confidence_stats(rows: Sequence[Row]) -> dict[str, Any]:
    """How well confidence predicts the centre error: Spearman rank correlation (negative is good), the
    mean centre error of the 80 % most confident fruit (what a robot skipping the rest would get), the
    share flagged reliable, and the share of badly-off views (> :data:`BAD_MM`) flagged unreliable."""
    conf = np.array([r.confidence for r in rows], dtype=float)
    err = np.array([r.centre_mm for r in rows], dtype=float)
    nan = float("nan")
    if not len(conf) or not np.isfinite(conf).all():
        return {"spearman": nan, "centre_mm_top80": nan, "reliable_share": nan, "bad_flagged": nan}
    bad = err > BAD_MM
    flagged = float(np.mean([not r.reliable for r, b in zip(rows, bad, strict=True) if b])) if bad.any() else nan
    stats = {"reliable_share": float(np.mean([r.reliable for r in rows])), "bad_flagged": flagged}
    if len(conf) < 3:
        return {**stats, "spearman": nan, "centre_mm_top80": nan}
    rho = spearman(conf, err)
    keep = conf >= np.quantile(conf, 0.2)
    return {**stats, "spearman": float(rho), "centre_mm_top80": float(err[keep].mean())}


def summarise(rows: Sequence[Row], *, by: Sequence[str] = ("fruit", "occlusion", "method")) -> list[dict[str, Any]]:
    """Mean and median metrics per group (failed runs counted, left out of the statistics).

    ``fruit`` groups by :attr:`Row.label` (a scan folder's rows by scan). Worst cases: ``centre_mm_max``,
    ``over_10mm`` (views off by more than :data:`BAD_MM`) and ``below_raw`` (views whose IoU is below the
    ``raw`` box's on the same instance; NaN when ``raw`` was not run).
    """
    raw = {r.instance: r.iou for r in rows if r.method == "raw" and not r.error}
    groups: dict[tuple, list[Row]] = {}
    for row in rows:
        groups.setdefault(tuple(row.label if k == "fruit" else getattr(row, k) for k in by), []).append(row)
    summary = []
    for key, members in groups.items():
        ok = [r for r in members if not r.error]
        stats: dict[str, Any] = dict(zip(by, key, strict=True))
        stats.update(n=len(members), failed=len(members) - len(ok))
        for metric in ("iou", "centre_mm", "chamfer_mm", "f1"):
            values = np.array([getattr(r, metric) for r in ok], dtype=float)
            stats[f"{metric}_mean"] = float(values.mean()) if len(values) else float("nan")
            stats[f"{metric}_median"] = float(np.median(values)) if len(values) else float("nan")
        for metric in ("depth_mm", "lateral_mm"):  # signed size errors: mean absolute and mean (the bias)
            values = np.array([getattr(r, metric) for r in ok], dtype=float)
            stats[f"{metric}_abs"] = float(np.abs(values).mean()) if len(values) else float("nan")
            stats[f"{metric}_bias"] = float(values.mean()) if len(values) else float("nan")
        centre = np.array([r.centre_mm for r in ok], dtype=float)
        stats["centre_mm_max"] = float(centre.max()) if len(centre) else float("nan")
        stats["over_10mm"] = int((centre > BAD_MM).sum()) if ok else float("nan")
        below = [r.method != "raw" and r.iou < raw[r.instance] - 1e-9 for r in ok if r.instance in raw]
        stats["below_raw"] = int(sum(below)) if len(below) == len(ok) and ok else float("nan")
        secs = np.array([r.seconds for r in ok], dtype=float)
        stats["ms_median"] = float(np.median(secs) * 1000) if len(secs) else float("nan")
        stats["hidden_mean"] = float(np.mean([r.hidden for r in members]))
        stats.update(_confidence_stats(ok))
        summary.append(stats)
    return summary
