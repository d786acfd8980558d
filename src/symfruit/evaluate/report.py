"""Write an evaluation's results: per-instance CSV, summary JSON, a Markdown table laid out like the
paper's Table 2, and box plots like its Figs. 9-10 (PNG, with the optional ``plot`` extra)."""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..io import atomic_write, write_json
from .runner import COLUMNS, Row

__all__ = ["PAPER_TABLE2", "markdown_table", "write_plots", "write_results"]

#: Ge et al. 2020, Table 2 (reconstructed strawberries) and Table 3 (D435), mean values.
PAPER_TABLE2 = {"raw": (0.56, 14.1), "paper": (0.77, 6.9)}
PAPER_TABLE3 = {"raw": (0.47, 8.9), "paper": (0.61, 5.7)}


def _count(value: Any) -> str:
    return "-" if value is None or isinstance(value, float) else str(value)


def _f(value: float | None, digits: int) -> str:
    return "-" if value is None or (isinstance(value, float) and math.isnan(value)) else f"{value:.{digits}f}"


def _size(stats: dict[str, Any], metric: str) -> str:
    """A signed size error's cell: mean absolute (mean signed, the bias)."""
    mean_abs, bias = stats.get(f"{metric}_abs"), stats.get(f"{metric}_bias")
    if mean_abs is None or bias is None or math.isnan(mean_abs):
        return "-"
    return f"{mean_abs:.1f} ({bias:+.1f})"


def markdown_table(summary: Sequence[dict[str, Any]], *, protocol: str, title: str = "") -> str:
    """Tables per fruit (and occlusion level): mean and median IoU and centre deviation per method."""
    lines = [f"# {title or 'symfruit evaluation'}", ""]
    keys = sorted({(s["fruit"], s["occlusion"]) for s in summary}, key=lambda k: (str(k[0]), k[1]))
    for fruit, occlusion in keys:
        rows = [s for s in summary if s["fruit"] == fruit and s["occlusion"] == occlusion]
        n = max(s["n"] for s in rows)
        heading = f"## {protocol} protocol: {Path(str(fruit)).name}"
        if protocol == "camera":
            hidden = np.mean([s["hidden_mean"] for s in rows])
            heading += f", occluder target {occlusion:.0%} (hidden {hidden:.0%} on average)"
        lines += [heading, "", f"{n} instances.", ""]
        lines += [
            "| method | IoU mean | IoU median | centre dev mean (mm) | centre dev median (mm) | worst (mm) "
            "| views > 10 mm | below raw | depth side (mm) | larger lateral side (mm) | Chamfer (mm) | F1 @ 5 mm "
            "| ms / fruit | failed |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        for s in rows:
            lines.append(
                f"| {s['method']} | {_f(s['iou_mean'], 3)} | {_f(s['iou_median'], 3)} "
                f"| {_f(s['centre_mm_mean'], 1)} | {_f(s['centre_mm_median'], 1)} | {_f(s.get('centre_mm_max'), 1)} "
                f"| {_count(s.get('over_10mm'))} | {_count(s.get('below_raw'))} "
                f"| {_size(s, 'depth_mm')} | {_size(s, 'lateral_mm')} "
                f"| {_f(s['chamfer_mm_mean'], 2)} | {_f(s['f1_mean'], 3)} "
                f"| {_f(s['ms_median'], 2)} | {s['failed']} |"
            )
        for s in rows:
            if s.get("spearman") is not None and not math.isnan(s.get("spearman", float("nan"))):
                lines += ["", f"Confidence of `{s['method']}`: Spearman {s['spearman']:.2f} against the centre "
                          f"deviation; the 80 % most confident fruit deviate {s['centre_mm_top80']:.1f} mm on average "
                          f"(all: {s['centre_mm_mean']:.1f} mm)."]  # fmt: skip
        if protocol == "paper" and str(fruit) == "strawberry":
            (ri, rc), (pi, pc) = PAPER_TABLE2["raw"], PAPER_TABLE2["paper"]
            lines += [
                "",
                f"Ge et al. 2020, Table 2 (mean): input points {ri} / {rc} mm, completed {pi} / {pc} mm.",
            ]
        lines.append("")
    return "\n".join(lines)


def write_results(
    folder: Path,
    rows: Sequence[Row],
    summary: Sequence[dict[str, Any]],
    *,
    protocol: str,
    meta: dict[str, Any],
    table: str | None = None,
) -> list[Path]:
    """Write ``instances.csv``, ``summary.json``, ``table.md`` (``table``, or the per-group tables) and
    the plots into ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(COLUMNS))
    writer.writeheader()
    for row in rows:
        writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.to_dict().items()})
    with atomic_write(folder / "instances.csv", "w") as handle:
        handle.write(buf.getvalue())

    def clean(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
        return [{k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in s.items()} for s in rows]

    meta = {**meta, "confidence": clean(meta["confidence"])} if "confidence" in meta else meta
    write_json(folder / "summary.json", {**meta, "summary": clean(summary)})
    if table is None:
        table = markdown_table(summary, protocol=protocol, title=meta.get("title", ""))
    with atomic_write(folder / "table.md", "w") as handle:
        handle.write(table)
    written = [folder / "instances.csv", folder / "summary.json", folder / "table.md"]
    written += write_plots(folder, rows, protocol=protocol)
    return written


def write_plots(folder: Path, rows: Sequence[Row], *, protocol: str) -> list[Path]:
    """Box plots of IoU and centre deviation per method (and per pose angle, or per occlusion level).

    Needs matplotlib (``pip install 'symfruit[plot]'``); without it, returns no files.
    """
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return []
    written = []
    ok = [r for r in rows if not r.error]
    methods = list(dict.fromkeys(r.method for r in ok))
    for fruit in dict.fromkeys(r.fruit for r in ok):
        name = Path(str(fruit)).name
        mine = [r for r in ok if r.fruit == fruit]
        fig, axes = plt.subplots(1, 2, figsize=(10, 4))
        for ax, metric, label in (
            (axes[0], "iou", "3D box IoU"),
            (axes[1], "centre_mm", "centre deviation (mm)"),
        ):
            data = [[getattr(r, metric) for r in mine if r.method == m] for m in methods]
            ax.boxplot(data, tick_labels=methods, showmeans=True, meanprops={"marker": "x", "markeredgecolor": "k"})
            ax.set_ylabel(label)
            ax.grid(axis="y", alpha=0.3)
        fig.suptitle(f"{protocol} protocol, {name}: {len(mine) // max(len(methods), 1)} instances")
        fig.tight_layout()
        written.append(_save(fig, folder / f"{name}-methods.png"))
        plt.close(fig)
        if protocol == "paper":
            written.append(_by_angle(plt, folder, name, mine, methods))
        elif len({r.occlusion for r in mine}) > 1:
            written.append(_by_occlusion(plt, folder, name, mine, methods))
    return written


def _by_angle(plt: Any, folder: Path, name: str, rows: Sequence[Row], methods: list[str]) -> Path:
    """Figs. 9-10 of the paper: per pose angle, the input (raw) beside each completion."""
    angles = sorted({r.angle_x for r in rows})
    fig, axes = plt.subplots(2, 1, figsize=(12, 7), sharex=True)
    width = 0.8 / len(methods)
    for ax, metric, label in (
        (axes[0], "iou", "3D box IoU"),
        (axes[1], "centre_mm", "centre deviation (mm)"),
    ):
        for k, m in enumerate(methods):
            data = [[getattr(r, metric) for r in rows if r.method == m and r.angle_x == a] for a in angles]
            pos = np.arange(len(angles)) + (k - (len(methods) - 1) / 2) * width
            bp = ax.boxplot(data, positions=pos, widths=width * 0.9, patch_artist=True, showmeans=True,
                            meanprops={"marker": "x", "markeredgecolor": "k", "markersize": 4})  # fmt: skip
            for box in bp["boxes"]:
                box.set_facecolor(plt.cm.tab10(k))
            ax.plot([], [], color=plt.cm.tab10(k), lw=6, label=m)
        ax.set_ylabel(label)
        ax.grid(axis="y", alpha=0.3)
    axes[0].legend(ncol=len(methods), fontsize=8)
    axes[1].set_xticks(np.arange(len(angles)), [f"{a:g}" for a in angles])
    axes[1].set_xlabel("rotation about x (degrees)")
    fig.suptitle(f"paper protocol, {name}: per pose (cf. Ge et al. Figs. 9-10)")
    fig.tight_layout()
    path = _save(fig, folder / f"{name}-by-angle.png")
    plt.close(fig)
    return path


def _by_occlusion(plt: Any, folder: Path, name: str, rows: Sequence[Row], methods: list[str]) -> Path:
    """Mean centre deviation and IoU against the hidden share of the silhouette."""
    levels = sorted({r.occlusion for r in rows})
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for m in methods:
        hidden = [np.mean([r.hidden for r in rows if r.method == m and r.occlusion == lv]) for lv in levels]
        for ax, metric in ((axes[0], "iou"), (axes[1], "centre_mm")):
            means = [
                np.mean([getattr(r, metric) for r in rows if r.method == m and r.occlusion == lv]) for lv in levels
            ]
            ax.plot(hidden, means, marker="o", label=m)
    axes[0].set_ylabel("mean 3D box IoU")
    axes[1].set_ylabel("mean centre deviation (mm)")
    for ax in axes:
        ax.set_xlabel("hidden share of the silhouette")
        ax.grid(alpha=0.3)
    axes[0].legend()
    fig.suptitle(f"camera protocol, {name}: error against occlusion")
    fig.tight_layout()
    path = _save(fig, folder / f"{name}-by-occlusion.png")
    plt.close(fig)
    return path


def _save(fig: Any, path: Path) -> Path:
    with atomic_write(path, "wb") as handle:
        fig.savefig(handle, format="png", dpi=100)
    return path
