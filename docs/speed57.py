"""Extraction reusing the registration's surface (issue 19, stop 57; docs/speed57.md): how far it moves results.

Neither mode changes ``symfruit``'s source: each patches the running process. ``reuse``: when the frame's
registration shift is (0, 0), extraction's ``fruit_surface`` is not run; its surface is the registration's
(``fruit_surface`` of ``registration_outline``, on the mask's window, found while the shift was searched) cut to
extraction's eroded mask and its pixels with depth, with the registration's front, radius, noise and apex. ``ablate
VARIANT``: extraction's own ``fruit_surface`` with one of its inputs the registration's: ``step0`` (the depth's unit
left out of the tolerance), ``noleaf`` (no leaf pixels), ``nocross`` (no ``crossing``), ``mask`` (the mask as drawn,
not eroded; the pixels then cut to the eroded mask), ``grown`` (as ``mask``, its region the mask grown by 20 px, as
the registration's), ``none`` (unchanged: the check that the patch itself moves nothing).

    python docs/speed57.py boxes reuse BOXES.csv evaluate --protocol camera --sensor realsense-d435 ... --jobs 1
    python docs/speed57.py boxes ablate step0 BOXES.csv evaluate ... --jobs 1
    python docs/speed57.py bench 0 1 2 3 4 5 [--ablate VARIANT]
    python docs/speed57.py time --rounds 5 --repeat 8
    python docs/speed57.py statements 0 1 2

``boxes`` is ``docs/eval_boxes.py run`` with the patch (``--jobs 1``: the patch is in this process alone); compare
with ``python docs/eval_boxes.py compare BEFORE.csv AFTER.csv --list``, BEFORE from ``eval_boxes.py run`` on the same
tree. ``bench`` runs ``detect`` (one process, ``method="evidence"``) on the benchmark frames of the seeds given,
without and then with ``reuse``, and prints each fruit's points before and after and how far its box moved (the
largest of a box face's and the centre's moves). ``time`` alternates ``detect`` on the benchmark frame (seed 0)
without and with ``reuse``, round by round, and prints each one's thread CPU a frame (median and least). ``statements``
captures ``extract``'s calls (and its ``fruit_surface`` calls) of ``detect`` on the benchmark frames of the seeds given,
replays them with a thread-CPU timer around each top-level statement of the two functions, and prints each statement's
ms a frame (a statement holding a ``return`` that is taken loses its time: the sum falls short of the whole).
"""

import argparse
import ast
import inspect
import os
import sys
import textwrap
import time
from typing import Any

import numpy as np

import symfruit.core.surface as surface
import symfruit.detect as detect
import symfruit.evaluate.runner as runner
import symfruit.extract as extract
from symfruit.core.raster import square_filter

#: The registration's surfaces of this frame (window origin, mask, Surface), its shift, extraction's window origin,
#: and how often the reuse ran (``used``), was not asked (``own``: a shift not (0, 0)) or found no mask (``nomatch``).
STATE: dict[str, Any] = {"window": None, "caps": [], "shift": None, "origin": (0, 0), "used": 0, "own": 0, "nomatch": 0}
#: ``ablate``'s variants (the module's docstring).
VARIANTS = ("none", "step0", "noleaf", "nocross", "mask", "grown")
_FRUIT_SURFACE = surface.fruit_surface
_WINDOW = surface.registration_window
_EXTRACT_WINDOW = detect._extract_window


def _window(shape: tuple[int, ...], sl: tuple[slice, slice], max_px: int) -> tuple[int, int, int, int]:
    STATE["window"] = found = _WINDOW(shape, sl, max_px)
    return found


def _registration_surface(depth: np.ndarray, mask: np.ndarray, focal: float, **kw: Any) -> Any:
    found = _FRUIT_SURFACE(depth, mask, focal, **kw)
    if kw.get("step") == 0.0 and kw.get("region") is not None and STATE["window"] is not None:  # _outline's call
        r0, _, c0, _ = STATE["window"]
        STATE["caps"].append((r0, c0, np.asarray(mask, dtype=bool).copy(), found))
    return found


def _registered(register: Any) -> Any:
    def wrapped(*args: Any, **kwargs: Any) -> Any:
        STATE["caps"] = []
        moved, shift = register(*args, **kwargs)
        STATE["shift"] = tuple(shift)
        return moved, shift

    return wrapped


def _reused(depth: np.ndarray, core: np.ndarray, focal: float, **kw: Any) -> Any:
    """Extraction's surface: the registration's of the mask overlapping ``core`` most, cut to ``core``."""
    if STATE["shift"] != (0, 0) or not STATE["caps"]:
        STATE["own"] += 1
        return _FRUIT_SURFACE(depth, core, focal, **kw)
    o0, p0 = STATE["origin"]
    h, w = core.shape
    best, most = None, 0
    for r0, c0, mask, found in STATE["caps"]:
        a0, a1 = max(r0, o0), min(r0 + mask.shape[0], o0 + h)
        b0, b1 = max(c0, p0), min(c0 + mask.shape[1], p0 + w)
        if a0 < a1 and b0 < b1:
            n = np.count_nonzero(
                mask[a0 - r0 : a1 - r0, b0 - c0 : b1 - c0] & core[a0 - o0 : a1 - o0, b0 - p0 : b1 - p0]
            )
            if n > most:
                best, most = (r0, c0, found, a0, a1, b0, b1), n
    if best is None or best[2] is None:
        STATE["nomatch"] += 1
        return _FRUIT_SURFACE(depth, core, focal, **kw)
    r0, c0, found, a0, a1, b0, b1 = best
    pixels = np.zeros(core.shape, bool)
    pixels[a0 - o0 : a1 - o0, b0 - p0 : b1 - p0] = found.pixels[a0 - r0 : a1 - r0, b0 - c0 : b1 - c0]
    pixels &= core & (depth > 0)
    STATE["used"] += 1
    if not pixels.any():
        return None
    apex = (found.apex[0] + r0 - o0, found.apex[1] + c0 - p0)
    return surface.Surface(pixels, found.front, found.radius, found.noise, apex)


def _extract_window(mask: np.ndarray, sl: tuple[slice, slice], depth: np.ndarray, cam: Any, settings: Any,
                    **kw: Any) -> Any:  # fmt: skip
    pad = settings.extract.erode_px + 2  # as detect._extract_window cuts the window
    STATE["origin"] = (max(sl[0].start - pad, 0), max(sl[1].start - pad, 0))
    try:
        return _EXTRACT_WINDOW(mask, sl, depth, cam, settings, **kw)
    finally:
        STATE["origin"] = (0, 0)


def reuse() -> None:
    """Patch extraction to take the registration's surface when the shift is (0, 0)."""
    surface.registration_window = detect.registration_window = _window
    surface.fruit_surface = _registration_surface
    extract.fruit_surface = _reused
    detect.register = _registered(detect.register)
    runner.register = _registered(runner.register)
    detect._extract_window = _extract_window


def ablate(variant: str) -> None:
    """Patch extraction's ``fruit_surface`` call to take one input the registration's (module docstring)."""
    last: dict[str, np.ndarray] = {}

    def eroded(mask: np.ndarray, *args: Any, **kwargs: Any) -> np.ndarray:
        last["mask"] = np.asarray(mask, dtype=bool)  # extract erodes the mask it was given: the mask as drawn
        return square_filter(mask, *args, **kwargs)

    def own(depth: np.ndarray, core: np.ndarray, focal: float, **kw: Any) -> Any:
        mask = last.get("mask")
        mask = core if mask is None or mask.shape != core.shape else mask
        if variant == "step0":
            kw["step"] = 0.0
        elif variant == "noleaf":
            kw["leafy"] = None
        elif variant == "nocross":
            kw["crossing"] = False
        elif variant in ("mask", "grown"):
            if variant == "grown":
                kw["region"] = surface._taxicab_within(mask, 20)
            found = _FRUIT_SURFACE(depth, mask, focal, **kw)
            if found is None:
                return None
            return surface.Surface(found.pixels & core, found.front, found.radius, found.noise, found.apex)
        return _FRUIT_SURFACE(depth, core, focal, **kw)

    extract.square_filter, extract.fruit_surface = eroded, own


def bench(seeds: list[int], variant: str | None = None) -> None:
    from symfruit.evaluate.bench import _bench_scene

    def run() -> dict[tuple[int, int], tuple[np.ndarray | None, int]]:
        out = {}
        for seed in seeds:
            for d in detect.detect(_bench_scene(None, seed)[0], method="evidence").detections:
                box = None if d.result is None else np.r_[d.result.box.min, d.result.box.max]
                out[(seed, d.id)] = (box, len(d.extraction.points))
        return out

    before = run()
    if variant is None:
        reuse()
    else:
        ablate(variant)
    after = run()
    moves = []
    for key in sorted(before):
        (a, na), (b, nb) = before[key], after.get(key, (None, 0))
        if a is None or b is None:
            sys.stdout.write(f"seed {key[0]} fruit {key[1]}: no box before {a is None}, after {b is None}\n")
            continue
        moved = 1000.0 * max(np.abs(b - a).max(), np.linalg.norm((b[:3] - a[:3] + b[3:] - a[3:]) / 2.0))
        moves.append(moved)
        sys.stdout.write(f"seed {key[0]} fruit {key[1]}: points {na} -> {nb}, box moved {moved:.3f} mm\n")
    m = np.array(moves)
    sys.stdout.write(f"{len(m)} fruit; {int((m > 0.1).sum())} moved by more than 0.1 mm; median {np.median(m):.3f} "
                     f"mm, largest {m.max():.3f} mm; reused {STATE['used']}, own {STATE['own']}\n")  # fmt: skip


_PATCHED = (
    (surface, "registration_window"),
    (detect, "registration_window"),
    (surface, "fruit_surface"),
    (extract, "fruit_surface"),
    (detect, "register"),
    (runner, "register"),
    (detect, "_extract_window"),
)


def timed(rounds: int, repeat: int) -> None:
    from symfruit.evaluate.bench import _bench_scene

    before = [getattr(m, n) for m, n in _PATCHED]
    reuse()
    after = [getattr(m, n) for m, n in _PATCHED]
    frame = _bench_scene(None, 0)[0]
    ms: dict[str, list[float]] = {"base": [], "reuse": []}
    for _ in range(rounds):
        for name, values in (("base", before), ("reuse", after)):
            for (module, attr), value in zip(_PATCHED, values, strict=True):
                setattr(module, attr, value)
            detect.detect(frame, method="evidence")  # a warm-up
            for _ in range(repeat):
                a = time.thread_time()
                detect.detect(frame, method="evidence")
                ms[name].append(1000.0 * (time.thread_time() - a))
    for name, values in ms.items():
        sys.stdout.write(f"{name}: {np.median(values):.2f} / {min(values):.2f} ms a frame (median / least of "
                         f"{len(values)}), thread CPU\n")  # fmt: skip


def _statements(function: Any, calls: list[tuple[tuple, dict]], frames: int, repeat: int = 50) -> None:
    """Each top-level statement of ``function`` timed (thread CPU) over ``calls`` replayed ``repeat`` times."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(function)))
    fn = tree.body[0]
    assert isinstance(fn, ast.FunctionDef)
    body: list[ast.stmt] = []
    labels = []
    for st in fn.body:
        if isinstance(st, ast.Expr) and isinstance(st.value, ast.Constant):
            continue  # the docstring
        labels.append(ast.unparse(st).splitlines()[0][:100])
        k = len(labels) - 1
        post = ast.parse(f"_T[{k}] += _now() - _s").body
        if isinstance(st, ast.Return) and st.value is not None:
            body += [*ast.parse("_s = _now()").body, *ast.parse(f"_r = {ast.unparse(st.value)}").body, *post,
                     *ast.parse("return _r").body]  # fmt: skip
        else:
            body += [*ast.parse("_s = _now()").body, st, *post]
    fn.body = body
    ast.fix_missing_locations(tree)
    spent = np.zeros(len(labels))
    scope = dict(sys.modules[function.__module__].__dict__, _T=spent, _now=time.thread_time)
    exec(compile(tree, f"<{function.__name__} timed>", "exec"), scope)
    again = scope[function.__name__]
    for args, kwargs in calls:  # a warm-up
        again(*args, **kwargs)
    spent[:] = 0.0
    a = time.thread_time()
    for _ in range(repeat):
        for args, kwargs in calls:
            again(*args, **kwargs)
    whole = 1000.0 * (time.thread_time() - a) / repeat / frames
    each = 1000.0 * spent / repeat / frames
    sys.stdout.write(f"{function.__module__}.{function.__name__}: {len(calls) / frames:.1f} calls, {whole:.3f} ms a "
                     f"frame (the statements {each.sum():.3f})\n")  # fmt: skip
    for k in np.argsort(-each)[:12]:
        sys.stdout.write(f"  {each[k]:7.3f} ms  {labels[k]}\n")


def statements(seeds: list[int]) -> None:
    from symfruit.evaluate.bench import _bench_scene

    calls: dict[str, list[tuple[tuple, dict]]] = {"extract": [], "fruit_surface": []}
    run_extract, run_surface = detect.extract, extract.fruit_surface

    def copied(values: Any) -> Any:
        return np.array(values) if isinstance(values, np.ndarray) else values

    def extract_kept(*args: Any, **kwargs: Any) -> Any:
        calls["extract"].append((tuple(copied(v) for v in args), {k: copied(v) for k, v in kwargs.items()}))
        return run_extract(*args, **kwargs)

    def surface_kept(*args: Any, **kwargs: Any) -> Any:
        calls["fruit_surface"].append((tuple(copied(v) for v in args), {k: copied(v) for k, v in kwargs.items()}))
        return run_surface(*args, **kwargs)

    detect.extract, extract.fruit_surface = extract_kept, surface_kept
    for seed in seeds:
        detect.detect(_bench_scene(None, seed)[0], method="evidence")
    detect.extract, extract.fruit_surface = run_extract, run_surface
    _statements(run_extract, calls["extract"], len(seeds))
    _statements(run_surface, calls["fruit_surface"], len(seeds))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="cmd", required=True)
    b = sub.add_parser("boxes", help="eval_boxes.py run with a patch")
    b.add_argument("patch", choices=("reuse", "ablate"))
    b.add_argument("rest", nargs=argparse.REMAINDER, help="[VARIANT] BOXES.csv evaluate ARGS...")
    s = sub.add_parser("bench", help="detect on the benchmark frames, without and with reuse")
    s.add_argument("seeds", type=int, nargs="+")
    s.add_argument("--ablate", choices=VARIANTS, help="with this variant of extraction's own surface, not reuse")
    t = sub.add_parser("time", help="detect's thread CPU on the benchmark frame, without and with reuse, alternated")
    t.add_argument("--rounds", type=int, default=5)
    t.add_argument("--repeat", type=int, default=8)
    st = sub.add_parser("statements", help="extract's and fruit_surface's statements timed on the benchmark frames")
    st.add_argument("seeds", type=int, nargs="+")
    args = parser.parse_args()
    if args.cmd == "bench":
        bench(args.seeds, args.ablate)
        return 0
    if args.cmd == "time":
        timed(args.rounds, args.repeat)
        return 0
    if args.cmd == "statements":
        statements(args.seeds)
        return 0
    rest = list(args.rest)
    if args.patch == "ablate":
        variant = rest.pop(0)
        if variant not in VARIANTS:
            parser.error(f"unknown variant {variant!r}")
        ablate(variant)
    else:
        reuse()
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import eval_boxes

    code = eval_boxes.run(rest[0], rest[1:])
    sys.stderr.write(f"reused {STATE['used']}, own {STATE['own']}, no mask {STATE['nomatch']}\n")
    return int(code)


if __name__ == "__main__":
    sys.exit(main())
