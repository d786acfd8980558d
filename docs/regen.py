"""Regenerate README's and docs/ablation.md's tables by the commands written next to them, and compare runs.

    python docs/regen.py run OUT [PART ...] [--jobs N] [--resume]   # run from the tree to measure (PYTHONPATH=src)
    python docs/regen.py compare OLD NEW [--tolerance T] [--all]    # every printed cell of the parts in both
    python docs/regen.py readme OUT [--root TREE] [--write]         # which README figures the printed rows confirm
    python docs/regen.py list                                       # the parts and the commands each runs

``run`` runs, from the working folder (the tree measured: its ``src`` on ``PYTHONPATH``, its ``docs/`` scripts,
its ``examples/``), each part's commands as README gives them, ``symfruit evaluate`` with ``--output`` added so its
results land in ``OUT/_runs/<command>/``; frames that several commands read (``symfruit scenes``) are rendered once
into ``OUT/_scenes/``. Each part then writes ``OUT/PART/rows.md``: per table a section (``## title``), the
commands, and the rows printed by ``docs/readme_rows.py`` (or the script README names, or ``symfruit evaluate``'s
own table). ``OUT/PART/status.json`` holds each command's exit status, CPU seconds (its own and its worker
processes', from ``wait4``) and wall seconds, and the frames it rendered. ``--resume`` keeps every command already
finished in OUT (a part cut short goes on where it stopped; a command that failed runs again) and prints every
``rows.md`` anew; without it every command of the named parts is run afresh. ``--jobs N`` runs N commands at once
(each ``symfruit evaluate`` keeps its own default worker count, as README's commands do).

``compare`` reads two OUT folders' ``rows.md``: every cell (a section, a row by its label, a column) moved beyond
``--tolerance`` (each number in the cell, absolute; default 0: any change of the printed text) is listed with both
values; ``--all`` lists the unchanged cells too. Rows printed in one run only are named.

``readme`` matches each printed row to README's row of the same label in the table the section names (the first
table after a line holding its anchor text, README.md or docs/ablation.md) and says which rows README confirms
cell for cell and which cells differ (best effort: where the printed table has README's columns, by position;
otherwise each README cell is looked for among the printed row's cells). With ``--write`` it rewrites each
differing row where the printed table has README's columns (a cell README agrees with kept as README writes it, the
timing and earlier-stop columns kept) and names the rest to be done by hand.

Parts: spheres, heldback, paper, frames, straw, trees, photos, cams, occl, leaf, scans, conf, seg (``list`` prints
each one's commands). The held-out seed sets README reports (100 and up) are among them: that is the lead's
regeneration, never a development loop.
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

METHODS = "raw,sphere,ellipsoid,superellipsoid,paper,fused,evidence"
PROXIES = "strawberry,apple,citrus,lemon,peach,pear,plum"
LEAF_KINDS = "strawberry,apple,citrus,tomato,lemon,peach,plum"
SENSORS = (("azure-kinect", "Azure Kinect"), ("realsense-l515", "L515"), ("realsense-d435", "D435"),
           ("realsense-d405", "D405"))  # fmt: skip
#: README's labels of the camera models' rows ("Annotated frames through each camera", "Through real depth cameras").
SENSOR_FRAMES = {"azure-kinect": "Azure Kinect (1920x1080)", "realsense-l515": "L515 (1920x1080)",
                 "realsense-d435": "D435 (1280x720)", "realsense-d405": "D405 (1280x720)"}  # fmt: skip
SENSOR_ROW = {"azure-kinect": "Azure Kinect (ToF, 1920x1080, 0.5-2 m)",
              "realsense-l515": "L515 (ToF, 1920x1080, 0.25-2 m)",
              "realsense-d435": "D435 (stereo, 1280x720, 0.28-2 m)",
              "realsense-d405": "D405 (stereo, 1280x720, 0.25-0.5 m)"}  # fmt: skip
#: Settings files README's commands name (``--config CW1``, the annotated frames without occlusion information).
CONFIGS = {"CW1": "evidence: {cut_width: 1}\n", "NOOCCL": "occlusion: {enabled: false}\n"}
#: README columns ``readme`` does not check: timings (ms per image), which no other machine or run repeats, and
#: earlier stops' figures kept beside the current ones ("25 % at stop 39").
SKIPPED_COLUMNS = re.compile(r"\bms\b|\bstop \d+")
#: Largest file read as a part's rows or a command's output (a run's printed output is a few kB).
MAX_TEXT = 50_000_000


def say(text: str) -> None:
    sys.stdout.write(text + "\n")
    sys.stdout.flush()


@dataclass(frozen=True)
class Cmd:
    """One command as README gives it: ``symfruit ...`` or ``python docs/....py ...``. ``{scenes:KEY}``,
    ``{config:NAME}`` and ``{shared}`` (the shared data folder) are filled in when it runs."""

    argv: tuple[str, ...]

    def text(self) -> str:
        """The command as written in ``rows.md``: frames rendered once are ``_scenes/KEY``."""
        shown = [
            re.sub(r"^\{scenes:(.*)\}$", lambda m: "_scenes/" + scenes_key(m.group(1).split()), a) for a in self.argv
        ]
        shown = [re.sub(r"^\{config:(.*)\}$", r"_config/\1.yaml", a).replace("{shared}", "SHARED") for a in shown]
        return shlex.join(shown)

    def scenes(self) -> list[list[str]]:
        """The ``symfruit scenes`` arguments of the frames it reads."""
        return [m.group(1).split() for a in self.argv if (m := re.fullmatch(r"\{scenes:(.*)\}", a))]

    def key(self) -> str:
        slug = re.sub(r"[^A-Za-z0-9]+", "-", " ".join(self.argv[1:4])).strip("-")[:48]
        return f"{slug}-{hashlib.sha1(self.text().encode()).hexdigest()[:10]}"


@dataclass
class Section:
    """One table: its commands and how its rows are printed from their results.

    ``rows(results)`` gets each command's :class:`Result` in order and returns the printed lines; ``anchor`` is
    ``(file, text)``: README's table is the first one after the first line of ``file`` holding ``text``; a list of
    texts names one per printed table (None: a table README does not hold)."""

    title: str
    cmds: list[Cmd]
    rows: Callable[[list[Result]], list[str]]
    anchor: tuple[str, str | list[str | None]] | None = None
    #: README's label of a printed row where the printing script labels it otherwise (by the label without a
    #: trailing parenthesis, e.g. ``half 0 (503 images)`` -> README's ``photos, half 0 (503 images, development)``).
    aliases: dict[str, str] = field(default_factory=dict)


@dataclass
class Result:
    cmd: Cmd
    folder: Path  # OUT/_runs/KEY
    stdout: str
    results: Path | None  # symfruit evaluate's results folder, from its "results: FOLDER" line
    rc: int
    cpu_s: float
    wall_s: float = 0.0


@dataclass
class Ctx:
    out: Path
    shared: Path
    resume: bool
    done: dict[str, Result] = field(default_factory=dict)  # commands run or kept by this invocation
    rendered: set[str] = field(default_factory=set)  # frame folders rendered or kept by this invocation


def sym(*args: str) -> Cmd:
    return Cmd(("symfruit", *args))


def py(script: str, *args: str) -> Cmd:
    return Cmd(("python", f"docs/{script}", *args))


def scenes_key(args: Sequence[str]) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "-", " ".join(args)).strip("-") or "default"


def scenes(*args: str) -> str:
    """The placeholder of a folder of frames ``symfruit scenes F ARGS`` renders (once per OUT)."""
    return "{scenes:" + " ".join(args) + "}"


# ---------------------------------------------------------------- printing rows from results


def read_text(path: Path) -> str:
    if path.stat().st_size > MAX_TEXT:
        raise SystemExit(f"{path}: over {MAX_TEXT} bytes, not a run's printed output")
    return path.read_text(errors="replace")


def rows_script(*args: str) -> list[str]:
    """``python docs/readme_rows.py ARGS`` from the working folder (the measured tree's own script)."""
    done = subprocess.run([sys.executable, "docs/readme_rows.py", *args], capture_output=True, text=True)
    if done.returncode:
        return [f"(docs/readme_rows.py {shlex.join(args)} failed: {done.stderr.strip().splitlines()[-1:]})"]
    return done.stdout.splitlines()


def folder(r: Result) -> str:
    return str(r.results) if r.results is not None else str(r.folder / "missing")


def readme_rows(*options: str, labels: Sequence[str] | None = None) -> Callable[[list[Result]], list[str]]:
    """Rows of ``docs/readme_rows.py OPTIONS`` on the commands' results (``LABEL=FOLDER`` each when labels)."""

    def rows(results: list[Result]) -> list[str]:
        if labels is None:
            return [line for r in results for line in rows_script(*options, folder(r))]
        return rows_script(*options, *(f"{n}={folder(r)}" for n, r in zip(labels, results, strict=True)))

    return rows


def printed(results: list[Result]) -> list[str]:
    """The commands' own printed output (a table of ``evaluate --frames/--spheres``, a script's rows)."""
    return [line for r in results for line in r.stdout.splitlines() if not line.startswith("results: ")]


def scan_label(kind: str) -> str:
    """``scan/016_pear`` -> ``real pear`` (README's label of a real scan)."""
    stem = kind.removeprefix("scan/")
    return "real " + (stem.split("_", 1)[1] if re.match(r"\d+_", stem) else stem)


def relabel_scans(suffix: str) -> Callable[[list[str]], list[str]]:
    def fix(lines: list[str]) -> list[str]:
        return [re.sub(r"^\| scan/([^|]+?) \|", lambda m: f"| {scan_label(m.group(1))}, {suffix} |", x) for x in lines]

    return fix


def by_fruit_scans(suffixes: Sequence[str]) -> Callable[[list[Result]], list[str]]:
    def rows(results: list[Result]) -> list[str]:
        out = []
        for suffix, r in zip(suffixes, results, strict=True):
            out += relabel_scans(suffix)(rows_script("--by", "fruit", folder(r)))
        return out

    return rows


def leaf_cells(sensor_labels: Sequence[str]) -> Callable[[list[Result]], list[str]]:
    """README's leaf table through the camera models: per sensor, mean IoU / mean centre (views over 10 mm) at
    each level, from ``readme_rows.py --by occlusion --methods evidence`` (cells IoU / mean / worst / over 10 / ...)."""

    def rows(results: list[Result]) -> list[str]:
        out = []
        for name, r in zip(sensor_labels, results, strict=True):
            lines = rows_script("--by", "occlusion", "--methods", "evidence", folder(r))
            out += [*lines, ""]
            cells = []
            for line in lines:
                parts = [c.strip() for c in line.strip().strip("|").split("|")]
                if len(parts) >= 3:
                    v = parts[2].split(" / ")
                    cells.append(f"{v[0]} / {float(v[1]):.1f} ({v[3]})" if len(v) >= 4 else parts[2])
            out += [f"| {name} | " + " | ".join(cells) + " |", ""]
        return out

    return rows


def scan_confidence(pose: str) -> Callable[[list[Result]], list[str]]:
    """README's confidence rows of the real scans: each scan's views alone, then all (``readme_rows.py
    --confidence`` on an ``instances.csv`` holding one scan's rows)."""

    def rows(results: list[Result]) -> list[str]:
        (r,) = results
        if r.results is None:
            return ["(no results)"]
        with open(r.results / "instances.csv") as handle:
            data = list(csv.DictReader(handle))
        kinds = sorted({d["kind"] for d in data})
        args = []
        for kind in kinds:
            sub = r.folder / "by-scan" / kind.replace("/", "_")
            sub.mkdir(parents=True, exist_ok=True)
            with open(sub / "instances.csv", "w", newline="") as handle:
                writer = csv.DictWriter(handle, fieldnames=list(data[0]))
                writer.writeheader()
                writer.writerows(d for d in data if d["kind"] == kind)
            args.append(f"real, {pose}: {scan_label(kind)}={sub}")
        return rows_script("--confidence", *args, f"real, {pose}: ALL={r.results}")

    return rows


def masks_row(label: str) -> Callable[[list[Result]], list[str]]:
    """A row of README's segmentation tables from ``evaluate --protocol masks``'s ``summary.json`` (its timings
    left out: machine-dependent)."""

    def rows(results: list[Result]) -> list[str]:
        (r,) = results
        if r.results is None:
            return [f"| {label} | (no results) |"]
        s = json.loads(read_text(r.results / "summary.json"))["summary"]
        iou = "-" if s["mean_best_iou"] is None else f"{s['mean_best_iou']:.3f}"
        share = "-" if s["matched_share"] is None else f"{100 * s['matched_share']:.1f} %"
        return [f"| {label} | {iou} | {s['matched']:,} / {s['true_fruit']:,} ({share}) | {s['false']:,} / "
                f"{s['detections']:,} ({100 * s['false_share']:.1f} %) |"]  # fmt: skip

    return rows


def frames_row(label: str) -> Callable[[list[Result]], list[str]]:
    """README's row of "Annotated frames through each camera" from ``evaluate --frames``'s ``summary.json``: true /
    matched fruit, then per method mean IoU / mean centre error (mm) of the matched fruit; then its own table."""

    def rows(results: list[Result]) -> list[str]:
        (r,) = results
        if r.results is None:
            return [f"| {label} | (no results) |"]
        summary = json.loads(read_text(r.results / "summary.json"))
        scores, totals = summary["scores"], summary["totals"]
        cells = []
        for method in METHODS.split(","):
            mine = [s for s in scores if s["method"] == method]
            if mine:
                iou = sum(s["iou"] for s in mine) / len(mine)
                cells.append(f"{iou:.3f} / {sum(s['centre_mm'] for s in mine) / len(mine):.1f}")
        head = f"| {label} | {totals['truth']} / {totals['matched']} | " + " | ".join(cells) + " |"
        return [head, "", *printed(results)]

    return rows


def by_label_counts(results: list[Result]) -> list[str]:
    """``evaluate --frames F --match id``: its table, then per method the mean / median centre error and the fruit
    over 30 mm, from the ``scores`` of its ``summary.json`` (README's "Scoring every annotated apple")."""
    out = printed(results)
    for r in results:
        if r.results is None:
            continue
        scores = json.loads(read_text(r.results / "summary.json"))["scores"]
        out += ["", "| method | n | centre mean / median (mm) | over 30 mm | worst (mm) |", "|---|---|---|---|---|"]
        for method in dict.fromkeys(s["method"] for s in scores):
            dev = sorted(s["centre_mm"] for s in scores if s["method"] == method and s["centre_mm"] is not None)
            if not dev:
                continue
            mid = len(dev) // 2
            median = dev[mid] if len(dev) % 2 else (dev[mid - 1] + dev[mid]) / 2
            out.append(f"| {method} | {len(dev)} | {sum(dev) / len(dev):.1f} / {median:.1f} | "
                       f"{sum(d > 30 for d in dev)} | {dev[-1]:.0f} |")  # fmt: skip
    return out


# ---------------------------------------------------------------- the parts


def camera(*args: str) -> Cmd:
    return sym("evaluate", "--protocol", "camera", *args)


def heldback(seed: int) -> Cmd:
    extra = ("--seed", str(seed)) if seed else ()
    return camera("--sensor", "heldback", "--fruit", "all", "--n", "30", "--no-profile", *extra)


def paper(seed: int) -> Cmd:
    extra = ("--seed", str(seed)) if seed else ()
    return sym("evaluate", "--protocol", "paper", "--fruit", "all", "--n", "3", "--no-profile", *extra)


def scans_camera(pose: str) -> Cmd:
    return camera("--sensor", "heldback", "--fruit", "examples/scans", "--n", "38", "--pose", pose, "--no-profile")


def scans_paper(pose: str) -> Cmd:
    return sym("evaluate", "--protocol", "paper", "--fruit", "examples/scans", "--n", "2", "--pose", pose,
               "--no-profile")  # fmt: skip


def views10(seed: int) -> Cmd:
    extra = ("--seed", str(seed)) if seed else ()
    return camera("--sensor", "heldback", "--fruit", PROXIES, "--n", "100", "--views", "10", "--no-profile", *extra)


LEAF_HELDBACK = camera("--sensor", "heldback", "--occlusion", "0.25,0.5", "--fruit", PROXIES + ",banana", "--n", "30",
                       "--no-profile")  # fmt: skip
STRAW0 = scenes("--seed", "0")
STRAW100 = scenes("--seed", "100")
TREES100 = scenes("--scene", "apple-tree", "--n", "12", "--seed", "100")
README = "README.md"
ABLATION = "docs/ablation.md"


def leaf_camera(sensor: str) -> Cmd:
    return camera("--sensor", sensor, "--fruit", LEAF_KINDS, "--occlusion", "0,0.25,0.5", "--n", "10", "--seed", "0",
                  "--methods", "evidence")  # fmt: skip


def masks_scene(*args: str) -> Cmd:
    return sym("evaluate", "--protocol", "masks", *args)


def parts() -> dict[str, list[Section]]:
    p: dict[str, list[Section]] = {}
    p["spheres"] = [
        Section("Real time-of-flight frames of spheres",
                [sym("evaluate", "--spheres", "examples/real-frames", "--methods", METHODS)], printed,
                (README, "**Real time-of-flight frames of spheres**")),
    ]  # fmt: skip
    p["heldback"] = [
        Section("camera protocol, heldback sensor, seed 0", [heldback(0)], readme_rows("--by", "fruit"),
                (README, "**`camera` protocol, the held-back measurement**")),
        Section("camera protocol, heldback sensor, seed 1", [heldback(1)], readme_rows("--by", "fruit"),
                (README, "Seed 1 (other fruit, poses")),
    ]  # fmt: skip
    p["paper"] = [
        Section("paper protocol, seed 0", [paper(0)], readme_rows("--by", "fruit"), (README, "**`paper` protocol**")),
        Section("paper protocol, seed 1", [paper(1)], readme_rows("--by", "fruit"),
                (README, "Seed 1:\n")),
    ]  # fmt: skip
    p["scans"] = [
        Section("real scans, camera protocol (heldback sensor, 19 views a scan)",
                [scans_camera(pose) for pose in ("hanging", "upright", "uniform")],
                by_fruit_scans(("hanging", "upright", "uniform")),
                (README, "**Real scans** (`--fruit examples/scans`)")),
        Section("real scans, paper protocol", [scans_paper(pose) for pose in ("hanging", "upright")],
                by_fruit_scans(("file frame", "stood up")), (README, "Paper protocol (19 poses per scan)")),
    ]  # fmt: skip
    p["conf"] = [
        Section("confidence: generated", [heldback(0), heldback(1), views10(0), views10(1)],
                readme_rows("--confidence", labels=("generated, seed 0: ALL", "generated, seed 1: ALL",
                                                    "generated, 10 views a fruit, seed 0: ALL",
                                                    "generated, 10 views a fruit, seed 1: ALL")),
                (README, "**Confidence** (`evidence`")),
        *(Section(f"confidence: real scans, {pose}", [scans_camera(pose)], scan_confidence(pose),
                  (README, "**Confidence** (`evidence`")) for pose in ("hanging", "upright", "uniform")),
        Section("confidence: paper protocol and leaf", [paper(0), LEAF_HELDBACK],
                readme_rows("--confidence", labels=("paper protocol, seed 0: ALL",
                                                    "generated, 25 % and 50 % hidden by a leaf, seed 0: ALL")),
                (README, "**Confidence** (`evidence`")),
    ]  # fmt: skip
    p["straw"] = [
        Section("annotated frames, seed 0", [sym("evaluate", "--frames", STRAW0)], printed,
                (README, ["**Annotated frames** (the paper's Table 3"])),
        Section("annotated frames, seed 100 (held out)", [sym("evaluate", "--frames", STRAW100)], printed),
    ]  # fmt: skip
    p["occl"] = [
        Section("annotated frames, seed 0, without occlusion information",
                [sym("evaluate", "--frames", STRAW0, "--config", "{config:NOOCCL}")], printed),
    ]  # fmt: skip
    p["leaf"] = [
        Section("camera views with a leaf in front (heldback)", [LEAF_HELDBACK], readme_rows("--by", "level"),
                (README, "**Camera views with a leaf in front**")),
        Section("a leaf in front, through the camera models",
                [leaf_camera(s) for s in ("azure-kinect", "realsense-d435")],
                leaf_cells(("Azure Kinect", "D435")),
                (README, [None, "**A leaf in front, through the camera models**"] * 2)),
    ]  # fmt: skip
    cams = [c for s, _ in SENSORS for c in (
        camera("--sensor", s, "--fruit", PROXIES, "--n", "10", "--no-profile"),
        camera("--sensor", s, "--fruit", "examples/scans", "--n", "20", "--no-profile"))]  # fmt: skip
    p["cams"] = [
        Section("through real depth cameras", cams,
                readme_rows(labels=[x for s, name in SENSORS for x in (
                    f"{SENSOR_ROW[s]}, 7 proxies", f"{name}, real scans")]),
                (README, "**Through real depth cameras**")),
        Section("box sizes through each camera", cams,
                readme_rows("--cells", "sizes", labels=[x for _, name in SENSORS for x in (
                    f"{name}, 7 proxies", f"{name}, real scans")]),
                (README, "Box sizes through each camera")),
    ]  # fmt: skip
    p["frames"] = [
        *(Section(f"annotated frames through {name}", [sym("evaluate", "--frames", scenes("--n", "6", "--sensor", s))],
                  frames_row(SENSOR_FRAMES[s]), (README, ["**Annotated frames through each camera**"]))
          for s, name in SENSORS),
        *(Section(f"16 frames of seed 100 through {name} (held out)",
                  [sym("evaluate", "--frames", scenes("--n", "16", "--seed", "100", "--sensor", s), "--methods",
                       "evidence"),
                   sym("evaluate", "--frames", scenes("--n", "16", "--seed", "100", "--sensor", s), "--methods",
                       "evidence", "--match", "id")], printed) for s, name in SENSORS[:3]),
    ]  # fmt: skip
    p["trees"] = [
        Section("apples on a tree, seeds 100-111 (held out)",
                [sym("evaluate", "--frames", TREES100, "--methods", METHODS, "--config", "{config:CW1}")], printed,
                (README, ["**Apples on a tree, as the held-back real frames measure them**",
                          "By how much of each apple the camera sees"])),
        Section("apples on a tree, seeds 100-111, every annotated apple by label",
                [sym("evaluate", "--frames", TREES100, "--match", "id", "--config", "{config:CW1}", "--methods",
                     "raw,sphere,superellipsoid,paper,evidence")], by_label_counts),
        Section("apples on a tree, seeds 100-111, default settings",
                [sym("evaluate", "--frames", TREES100, "--methods", "evidence")], printed),
        Section("apples on a tree, seeds 100-111, depth side taken apart",
                [py("depth_side.py", "--frames", TREES100)], printed),
        *(Section(f"development trees by label, seeds {a}-{a + 5}",
                  [sym("evaluate", "--frames", scenes("--scene", "apple-tree", "--n", "6", "--seed", str(a)),
                       "--config", "{config:CW1}", "--match", "id", "--methods", "evidence")], by_label_counts)
          for a in (0, 6)),
    ]  # fmt: skip
    p["photos"] = [
        Section("strawberry photographs, halves", [py("photo_halves.py", "{shared}/strawberry-photos/train")],
                printed, (README, "On the shared strawberry photos (971 Roboflow images"),
                {"half 0": "photos, half 0 (503 images, development)",
                 "half 1": "photos, half 1 (468 images, held out)", "all": "all 971 photos"}),
        *(Section(f"rendered strawberry scenes {a}-{a + 19}, {what}",
                  [masks_scene(*(("--seed", str(a)) if a else ()), "--n", "20", *flag)],
                  masks_row(f"rendered scenes {a}-{a + 19}, {what}"),
                  (README, "On the shared strawberry photos (971 Roboflow images"))
          for a in (0, 20) for what, flag in (("with depth", ()), ("colour alone", ("--no-depth",)))),
        Section("examples/photos", [masks_scene("--images", "examples/photos", "--truth",
                                                "examples/photos/_annotations.coco.json")],
                masks_row("examples/photos")),
    ]  # fmt: skip
    p["seg"] = [
        *(Section(f"tree segmenter, seeds {a}-{a + n - 1}",
                  [masks_scene("--scene", "apple-tree", "--fruit", "apple", *(("--seed", str(a)) if a else ()),
                               "--n", str(n))],
                  masks_row(f"apple trees, seeds {a}-{a + n - 1}")) for a, n in ((0, 12), (6, 6), (12, 12), (100, 12))),
        *(Section(f"tree segmenter by skin, seeds {a}-{a + 11}",
                  [py("tree_masks.py", *(("--seed", str(a)) if a else ()), "--n", "12")], printed)
          for a in (0, 12, 100)),
    ]  # fmt: skip
    return p


PART_ORDER = ("spheres", "heldback", "paper", "frames", "straw", "trees", "photos", "cams", "occl", "leaf", "scans",
              "conf", "seg")  # fmt: skip


# ---------------------------------------------------------------- running


def fill(cmd: Cmd, ctx: Ctx) -> list[str]:
    """The argv to run: placeholders filled, ``symfruit`` and ``python`` this interpreter."""
    argv = []
    for a in cmd.argv:
        m = re.fullmatch(r"\{scenes:(.*)\}", a)
        if m:
            argv.append(str(render(m.group(1).split(), ctx)))
            continue
        m = re.fullmatch(r"\{config:(.*)\}", a)
        if m:
            argv.append(str(ctx.out / "_config" / f"{m.group(1)}.yaml"))
            continue
        argv.append(a.replace("{shared}", str(ctx.shared)))
    if argv[0] == "symfruit":
        argv[:1] = [sys.executable, "-m", "symfruit"]
        if argv[3] == "evaluate":
            argv += ["--output", "{results}"]
    elif argv[0] == "python":
        argv[0] = sys.executable
    return argv


def execute(argv: list[str], log: Path) -> tuple[int, float, str]:
    """Run one command, its output to ``log``; exit status, CPU seconds (its own and its children's), stdout."""
    log.mkdir(parents=True, exist_ok=True)
    with open(log / "stdout.txt", "w") as out, open(log / "stderr.txt", "w") as err:
        proc = subprocess.Popen(argv, stdout=out, stderr=err)
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
    return proc.returncode, usage.ru_utime + usage.ru_stime, read_text(log / "stdout.txt")


def render(args: list[str], ctx: Ctx) -> Path:
    key = scenes_key(args)
    target = ctx.out / "_scenes" / key
    marker = target / ".regen-done"
    if key in ctx.rendered or (ctx.resume and marker.exists()):
        return target
    if target.exists():
        shutil.rmtree(target)
    t0 = time.time()
    rc, cpu, _ = execute(
        [sys.executable, "-m", "symfruit", "scenes", str(target), *args], ctx.out / "_scenes" / f"{key}.log"
    )
    if rc:
        raise SystemExit(f"symfruit scenes {shlex.join(args)} failed (exit {rc}): see {ctx.out}/_scenes/{key}.log")
    write_atomic(marker, json.dumps({"args": args, "cpu_s": cpu, "wall_s": time.time() - t0}))
    ctx.rendered.add(key)
    return target


def run_cmd(cmd: Cmd, ctx: Ctx) -> Result:
    key = cmd.key()
    if key in ctx.done:
        return ctx.done[key]
    folder = ctx.out / "_runs" / key
    status = folder / "status.json"
    info = json.loads(read_text(status)) if ctx.resume and status.exists() else None
    if info is None or info["rc"] not in (0, 1):  # 1: went on past a bad item and said so; else run it (again)
        if folder.exists():
            shutil.rmtree(folder)
        folder.mkdir(parents=True)
        argv = [a.replace("{results}", str(folder / "results")) for a in fill(cmd, ctx)]
        t0 = time.time()
        rc, cpu, _ = execute(argv, folder)
        info = {"command": cmd.text(), "argv": argv, "rc": rc, "cpu_s": round(cpu, 1),
                "wall_s": round(time.time() - t0, 1)}  # fmt: skip
        write_atomic(folder / "status.json", json.dumps(info, indent=1))
    stdout = read_text(folder / "stdout.txt")
    m = re.search(r"^results: (\S+)", stdout, re.M)
    result = Result(cmd, folder, stdout, Path(m.group(1)) if m else None, info["rc"], info["cpu_s"], info["wall_s"])
    ctx.done[key] = result
    return result


def run_part(name: str, sections: list[Section], ctx: Ctx, jobs: int) -> None:
    out = ctx.out / name
    out.mkdir(parents=True, exist_ok=True)
    cmds = list(dict.fromkeys(c for s in sections for c in s.cmds))
    # frames first, one at a time: two commands of one part may read the same frames
    for c in cmds:
        for args in c.scenes():
            render(args, ctx)
    with ThreadPoolExecutor(max(1, jobs)) as pool:
        list(pool.map(lambda c: run_cmd(c, ctx), cmds))
    lines = [f"# {name}", ""]
    for s in sections:
        results = [run_cmd(c, ctx) for c in s.cmds]
        lines += [f"## {s.title}", ""]
        if s.anchor:
            lines += [f"README table: {s.anchor[0]}, after {json.dumps(s.anchor[1])}", ""]
        if s.aliases:
            lines += [f"README labels: {json.dumps(s.aliases)}", ""]
        renders = list(dict.fromkeys(shlex.join(["symfruit", "scenes", "_scenes/" + scenes_key(a), *a])
                                     for c in s.cmds for a in c.scenes()))  # fmt: skip
        lines += [f"    {x}" for x in renders + [c.text() for c in s.cmds]] + [""]
        failed = [r for r in results if r.rc not in (0, 1) or (r.results is None and r.cmd.argv[1] == "evaluate")]
        for r in failed:
            lines.append(f"(failed, exit {r.rc}: {r.folder}/stderr.txt)")
        try:
            lines += s.rows(results) + [""]
        except (OSError, ValueError, KeyError, IndexError) as exc:  # one table's rows, not the whole run
            lines += [f"(rows failed: {type(exc).__name__}: {exc})", ""]
    write_atomic(out / "rows.md", "\n".join(lines))
    status = {c.text(): {k: getattr(ctx.done[c.key()], k) for k in ("rc", "cpu_s", "wall_s")} for c in cmds}
    frames = {}
    for c in cmds:
        for args in c.scenes():
            marker = ctx.out / "_scenes" / scenes_key(args) / ".regen-done"
            info = json.loads(read_text(marker))
            frames["symfruit scenes " + shlex.join(args)] = {k: round(info[k], 1) for k in ("cpu_s", "wall_s")}
    cpu = sum(v["cpu_s"] for v in [*status.values(), *frames.values()])
    wall = sum(v["wall_s"] for v in [*status.values(), *frames.values()])
    write_atomic(out / "status.json", json.dumps({"part": name, "cpu_s": round(cpu, 1), "wall_s": round(wall, 1),
                                                  "commands": status, "scenes": frames}, indent=1))  # fmt: skip
    say(f"{name}: {out}/rows.md ({cpu:.0f} s CPU, {wall:.0f} s, rendered frames included)")


def write_atomic(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


# ---------------------------------------------------------------- reading rows.md


def split_row(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")]


def norm(label: str) -> str:
    """A label or cell as compared with README's: no markup, one space, ``99.5%`` as ``99.5 %``, lower case."""
    text = re.sub(r"(\d)%", r"\1 %", label.replace("*", "").replace("`", ""))
    return re.sub(r"\s+", " ", text).strip().lower()


def read_rows(text: str) -> dict[tuple[str, int, str], tuple[list[str], list[str]]]:
    """``(section, table, row label) -> (header, cells)`` of a ``rows.md``; a printed line outside a table is a row
    of its own, labelled by its text up to the first colon, its cells the numbers in it."""
    rows: dict[tuple[str, int, str], tuple[list[str], list[str]]] = {}
    section, table, header, in_table = "", 0, [], False
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if line.startswith("## "):
            section, table, in_table = line[3:].strip(), 0, False
            continue
        if line.startswith("|"):
            cells = split_row(line)
            if all(re.fullmatch(r":?-+:?", c) for c in cells):
                continue
            nxt = lines[i + 1] if i + 1 < len(lines) else ""
            if re.match(r"\|\s*:?-", nxt):  # a header row
                table, header, in_table = table + 1, cells, True
                continue
            if not in_table:
                table, header, in_table = table + 1, [], True
            label = cells[0]
            key = (section, table, label)
            k = 2
            while key in rows:
                key, k = (section, table, f"{label} #{k}"), k + 1
            rows[key] = (header, cells[1:])
            continue
        in_table = False
        if not section or line.startswith(("    ", "README table:", "#", "(")) or not re.search(r"\d", line):
            continue
        label = line.split(":", 1)[0].strip() if ":" in line else re.sub(r"[\d.,%+-]+", "#", line)[:60]
        rows[(section, 0, label)] = ([], re.findall(r"[-+]?\d[\d,]*(?:\.\d+)?", line.split(":", 1)[-1]))
    return rows


def numbers(cell: str) -> list[float]:
    return [float(x.replace(",", "")) for x in re.findall(r"[-+]?\d[\d,]*(?:\.\d+)?", cell)]


def same(a: str, b: str, tolerance: float) -> bool:
    if a == b:
        return True
    if tolerance <= 0:
        return False
    na, nb = numbers(a), numbers(b)
    if len(na) != len(nb) or re.sub(r"[-+]?\d[\d,]*(?:\.\d+)?", "#", a) != re.sub(r"[-+]?\d[\d,]*(?:\.\d+)?", "#", b):
        return False
    return all(abs(x - y) <= tolerance + 1e-12 for x, y in zip(na, nb, strict=True))


def part_rows(out: Path) -> dict[str, dict]:
    found = {}
    for path in sorted(out.glob("*/rows.md")):
        found[path.parent.name] = read_rows(read_text(path))
    return found


def compare(old: Path, new: Path, tolerance: float, show_all: bool, say: Callable[[str], object] = say) -> int:
    """Every cell of every part in both OUT folders; returns how many moved (or appear in one only)."""
    a, b = part_rows(old), part_rows(new)
    moved = 0
    for part in sorted(set(a) & set(b)):
        ra, rb = a[part], b[part]
        count = same_cells = 0
        for key in list(ra) + [k for k in rb if k not in ra]:
            section, _, label = key
            where = f"{part} | {section} | {label}"
            if key not in rb or key not in ra:
                say(f"{where}: only in {'OLD' if key in ra else 'NEW'}")
                moved += 1
                continue
            (head, ca), (_, cb) = ra[key], rb[key]
            for j in range(max(len(ca), len(cb))):
                x = ca[j] if j < len(ca) else "(none)"
                y = cb[j] if j < len(cb) else "(none)"
                column = head[j + 1] if j + 1 < len(head) else f"cell {j + 1}"
                count += 1
                if same(x, y, tolerance):
                    same_cells += 1
                    if show_all:
                        say(f"{where} | {column}: {x}")
                    continue
                moved += 1
                say(f"{where} | {column}: {x} -> {y}")
        say(f"{part}: {same_cells} of {count} cells the same" + (f" (within {tolerance:g})" if tolerance else ""))
    for part in sorted(set(a) ^ set(b)):
        say(f"{part}: only in {'OLD' if part in a else 'NEW'}")
    return moved


def readme_tables(text: str, anchor: str) -> tuple[list[str], dict[str, list[str]]] | None:
    """README's table after the first line holding ``anchor``: header and rows by normalised label."""
    at = text.find(anchor)
    if at < 0:
        return None
    lines = text[at:].splitlines()
    start = next((i for i, x in enumerate(lines) if x.startswith("|")), None)
    if start is None:
        return None
    header = split_row(lines[start])
    rows: dict[str, list[str]] = {}
    for line in lines[start + 2 :]:
        if not line.startswith("|"):
            break
        cells = split_row(line)
        rows.setdefault(norm(cells[0]), cells[1:])
    return header, rows


def agrees(readme: str, printed: str) -> bool:
    """README's cell says what the printed one does: the same text, but for a count ``(n N)`` README leaves out."""
    return norm(readme) == norm(printed) or norm(readme) == norm(re.sub(r" \(n \d+\)$", "", printed))


def rewrite_row(text: str, anchor: str, label: str, cells: list[str], keep: Callable[[int], bool]) -> str:
    """``text`` with the row of ``label`` (normalised) in the first table after ``anchor`` given ``cells`` (all but
    its label), its own cell kept where ``keep(j)`` (column ``j + 1``); ``text`` itself when there is no such row."""
    at = text.find(anchor)
    if at < 0:
        return text
    lines = text[at:].splitlines(keepends=True)
    start = next((i for i, x in enumerate(lines) if x.startswith("|")), None)
    if start is None:
        return text
    offset = at + sum(len(x) for x in lines[:start])
    for line in lines[start:]:
        if not line.startswith("|"):
            break
        mine = split_row(line)
        if norm(mine[0]) == norm(label) and len(mine) == len(cells) + 1:
            new = [mine[0]] + [mine[j + 1] if keep(j) else c for j, c in enumerate(cells)]
            end = "\n" if line.endswith("\n") else ""
            return text[:offset] + "| " + " | ".join(new) + " |" + end + text[offset + len(line) :]
        offset += len(line)
    return text


def check_readme(
    out: Path, root: Path, say: Callable[[str], object] = say, *, write: bool = False
) -> tuple[int, int, int]:
    """(rows confirmed, rows that differ, printed rows without a README row) over the parts of OUT; with ``write``
    each differing row whose printed table has README's columns is rewritten in place (the cells README agrees
    with, and the skipped columns, kept as README has them) and the file written atomically; the others are named
    "by hand"."""
    texts: dict[str, str] = {}
    changed: set[str] = set()
    confirmed = differ = unmatched = 0
    prose: list[str] = []  # sections whose figures README gives in its text: read by hand
    for path in sorted(out.glob("*/rows.md")):
        text = read_text(path)
        anchors = dict(re.findall(r"^## (.+)\n\nREADME table: .+?, after ([\"\[].*)$", text, re.M))
        files = dict(re.findall(r"^## (.+)\n\nREADME table: (.+?), after ", text, re.M))
        aliases = {
            k: json.loads(v) for k, v in re.findall(r"^## (.+)\n\nREADME table: .+\n\nREADME labels: (.+)$", text, re.M)
        }
        prose += [f"{path.parent.name} | {x}" for x in re.findall(r"^## (.+)$", text, re.M) if x not in anchors]
        for (section, table, label), (header, cells) in read_rows(text).items():
            if section not in anchors or table == 0:
                continue
            anchor = json.loads(anchors[section])
            if isinstance(anchor, list):
                anchor = anchor[table - 1] if table <= len(anchor) else None
            if anchor is None:
                continue
            name = files[section]
            if name not in texts:
                texts[name] = read_text(root / name) if (root / name).is_file() else ""
            found = readme_tables(texts[name], anchor)
            where = f"{path.parent.name} | {section} | {label}"
            alias = aliases.get(section, {})
            label = alias.get(label, alias.get(re.sub(r"\s*\([^()]*\)$", "", label), label))
            if found is None or norm(label) not in found[1]:
                unmatched += 1
                say(f"{where}: no README row of that label")
                continue
            head, mine = found[0], found[1][norm(label)]
            # a printed table without a header (rows printed by docs/readme_rows.py) whose rows hold README's
            # number of cells is read in README's columns
            aligned = len(mine) == len(cells) and (len(head) == len(header) or not header)
            if aligned:
                bad = [
                    (head[j + 1], x, y) for j, (x, y) in enumerate(zip(mine, cells, strict=True)) if not agrees(x, y)
                ]
            else:
                bad = [(head[j + 1] if j + 1 < len(head) else f"cell {j + 1}", x, "(not printed)")
                       for j, x in enumerate(mine) if not any(agrees(x, y) for y in cells)]  # fmt: skip
            bad = [b for b in bad if not SKIPPED_COLUMNS.search(b[0])]
            if bad:
                differ += 1
                say(f"{where}: differs: " + "; ".join(f"{c}: README {x}, printed {y}" for c, x, y in bad))
                if write and aligned:
                    keep = [SKIPPED_COLUMNS.search(head[j + 1]) is not None or agrees(x, y)
                            for j, (x, y) in enumerate(zip(mine, cells, strict=True))]  # fmt: skip
                    # a count "(n N)" README leaves out of a cell stays out
                    new = [y if re.search(r"\(n \d+\)$", x) else re.sub(r" \(n \d+\)$", "", y)
                           for x, y in zip(mine, cells, strict=True)]  # fmt: skip
                    texts[name] = rewrite_row(texts[name], anchor, label, new, keep.__getitem__)
                    changed.add(name)
                    say(f"{where}: rewritten")
                elif write:
                    say(f"{where}: BY HAND (the printed row has other columns than README's)")
            else:
                confirmed += 1
                say(f"{where}: confirmed")
    for x in prose:
        say(f"{x}: no README table (its figures are in README's text: compare by hand)")
    for name in sorted(changed):
        write_atomic(root / name, texts[name])
        say(f"{name}: written")
    say(f"README rows confirmed {confirmed}, differing {differ}, printed rows without a README row {unmatched}")
    return confirmed, differ, unmatched


def shared_data() -> Path:
    """The shared data folder: ``../shared/data`` from the working folder (README's paths), else /work/shared/data."""
    here = Path("../shared/data")
    return here.resolve() if here.is_dir() else Path("/work/shared/data")


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="what", required=True)
    r = sub.add_parser("run", help="run the parts' commands into OUT")
    r.add_argument("out")
    r.add_argument("parts", nargs="*", help=f"default all: {' '.join(PART_ORDER)}")
    r.add_argument("--jobs", type=int, default=1, help="commands run at once (default 1)")
    r.add_argument("--resume", action="store_true", help="keep the commands already finished in OUT")
    r.add_argument("--shared", help="the shared data folder (default ../shared/data, else /work/shared/data)")
    c = sub.add_parser("compare", help="every printed cell of the parts in both OUT folders")
    c.add_argument("old")
    c.add_argument("new")
    c.add_argument("--tolerance", type=float, default=0.0, help="largest change of a number taken as none")
    c.add_argument("--all", action="store_true", help="list the unchanged cells too")
    m = sub.add_parser("readme", help="which README figures the printed rows confirm")
    m.add_argument("out")
    m.add_argument("--root", default=".", help="the tree whose README.md and docs/ablation.md are read (default .)")
    m.add_argument("--write", action="store_true", help="rewrite the differing rows (where the columns are README's)")
    sub.add_parser("list", help="each part's commands")
    args, extra = parser.parse_known_args(argv)  # run OUT --jobs 1 PART ...: parts after the options too
    if extra and (args.what != "run" or any(e.startswith("-") for e in extra)):
        parser.error(f"unrecognized arguments: {' '.join(extra)}")
    if args.what == "run":
        args.parts += extra
    table = parts()
    if args.what == "list":
        for name in PART_ORDER:
            say(f"{name}:")
            for cmd in dict.fromkeys(c for s in table[name] for c in s.cmds):
                say(f"    {cmd.text()}")
        return 0
    if args.what == "compare":
        compare(Path(args.old), Path(args.new), args.tolerance, args.all)
        return 0
    if args.what == "readme":
        check_readme(Path(args.out), Path(args.root), write=args.write)
        return 0
    unknown = [p for p in args.parts if p not in table]
    if unknown:
        parser.error(f"unknown part {unknown[0]!r} (parts: {', '.join(PART_ORDER)})")
    if not 1 <= args.jobs <= 64:
        parser.error("--jobs must be 1-64")
    if not Path("src/symfruit").is_dir() or not Path("docs/readme_rows.py").is_file():
        parser.error("run from the tree to measure (its src/ and docs/), with PYTHONPATH=src")
    ctx = Ctx(Path(args.out).resolve(), Path(args.shared) if args.shared else shared_data(), args.resume)
    (ctx.out / "_config").mkdir(parents=True, exist_ok=True)
    for name, text in CONFIGS.items():  # README's --config files
        (ctx.out / "_config" / f"{name}.yaml").write_text(text)
    for name in args.parts or PART_ORDER:
        run_part(name, table[name], ctx, args.jobs)
    return 0


if __name__ == "__main__":
    sys.exit(main())
