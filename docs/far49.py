"""docs/far49.md's figures: detections whose kept points are not their fruit's own surface (issue 18, stop 49).

    python docs/far49.py survey FRAMES [--config CW1] > X.jsonl   # per fruit with a truth: points, where, report
    python docs/far49.py summary X.jsonl                            # section 1's row and section 2's margins
    python docs/far49.py diff A.jsonl B.jsonl                       # the fruit whose points or report moved
    python docs/far49.py instance --sensor S --fruit F --index I [--pose P] --occlusion O   # one camera-protocol view

Run ``survey`` with ``PYTHONPATH=TREE/src`` for each tree (the margins, ``behind`` / ``level``, are this branch's
:func:`symfruit.extract.backdrop` of the points extraction kept before its own-surface check, where the tree has it).
"""

import argparse
import json
import sys

import numpy as np


def out(*parts) -> None:
    sys.stdout.write(" ".join(str(x) for x in parts) + "\n")


def _backdrop():
    try:
        from symfruit.extract import backdrop
    except ImportError:  # the base tree
        return None
    return backdrop


def survey(folder: str, config: str | None) -> None:
    import symfruit.detect as detect
    from symfruit.evaluate.metrics import centre_deviation
    from symfruit.io import open_source
    from symfruit.settings import Settings, resolve_settings

    settings = resolve_settings(config=config) if config else Settings()
    backdrop, seen = _backdrop(), {}
    if backdrop is not None:  # the margins of the points as extraction kept them, before the check
        check = detect.own_surface

        def keep(ex, mask, depth, cam, s, box=None, **kw):
            if len(ex.points) >= s.min_points:
                seen[box] = backdrop(ex.points, mask, depth, float(np.sqrt(cam.fx * cam.fy)), box)
            return check(ex, mask, depth, cam, s, box=box, **kw)

        detect.own_surface = keep
    src = open_source(folder)
    for i, name in enumerate(src.names()):
        frame = src.read(i)
        seen.clear()
        found = detect.detect(frame, method="evidence", settings=settings)
        truth = dict(frame.truth or [])
        for d in found.detections:
            if (tb := truth.get(d.id)) is None:
                continue
            p = d.extraction.points
            row = {"frame": name, "id": d.id, "area": d.extraction.mask_area, "n": len(p),
                   "visible": frame.visible.get(d.id, float("nan"))}  # fmt: skip
            rows, cols = np.nonzero(d.mask)
            if len(rows) and (b := (rows.min(), rows.max() + 1, cols.min(), cols.max() + 1)) in seen:
                row["behind"], row["level"], _ = seen[b]
            if len(p):
                inside = np.all((p >= tb.min - 0.005) & (p <= tb.max + 0.005), axis=1)
                row.update(own=float(inside.mean()), dz=(float(np.median(p[:, 2])) - float(tb.centre[2])) * 1000)
            if d.result is not None:
                row.update(err=float(centre_deviation(d.result.box, tb)) * 1000, conf=d.result.confidence,
                           reliable=d.result.reliable)  # fmt: skip
            else:
                row["error"] = d.error
            out(json.dumps(row))


def _load(path: str) -> list[dict]:
    with open(path) as f:
        return [json.loads(line) for line in f]


def summary(path: str) -> None:
    rows = _load(path)
    notown = [r for r in rows if r.get("own", 1.0) < 0.5]
    out(f"{len(rows)} fruit with a mask, {sum(r['n'] == 0 for r in rows)} without points, {len(notown)} whose kept "
          f"points are mostly not the fruit's:")  # fmt: skip
    for r in notown:
        where = "behind" if r["dz"] > 0 else "in front"
        said = (f"{r['err']:.1f} mm off, confidence {r['conf']:.4f}, reliable {r['reliable']}" if "err" in r
                else f"failed: {r['error']}")  # fmt: skip
        out(f"  {r['frame']} {r['id']}: {r['n']} points of {r['area']} px, {where} ({r['dz']:+.0f} mm), seen "
              f"{r['visible']:.2f}; {said}")  # fmt: skip
    m = np.array([(r["behind"], r["level"]) for r in rows if "behind" in r])
    if len(m):
        fire = (m[:, 0] <= 0.05) & (m[:, 1] >= 0.5)
        out(f"checked {len(m)}: {int(fire.sum())} fire; behind <= 0.05: {m[m[:, 0] <= 0.05].round(3).tolist()}; "
              f"the others behind >= {m[m[:, 0] > 0.05, 0].min():.3f}, level <= {m[~fire, 1].max():.3f}")  # fmt: skip


def diff(a_path: str, b_path: str) -> None:
    a = {(r["frame"], r["id"]): r for r in _load(a_path)}
    b = {(r["frame"], r["id"]): r for r in _load(b_path)}
    moved = 0
    for k, ra in a.items():
        rb = b.get(k, {})
        if any(ra.get(x) != rb.get(x) for x in ("n", "err", "error")):
            moved += 1
            before, after = ra.get("err", ra.get("error")), rb.get("err", rb.get("error"))
            out(k, "A:", ra.get("n"), before, "| B:", rb.get("n"), after)
    out(f"{len(a)} fruit, {moved} moved")


def instance(sensor: str, fruit: str, index: int, pose: int, occlusion: float) -> None:
    from symfruit.evaluate.protocols import Spec, build
    from symfruit.extract import extract, register
    from symfruit.settings import Settings

    spec = Spec(protocol="camera", fruit=fruit, index=index, pose=pose, occlusion=occlusion, seed=0, sensor=sensor)
    inst, s = build(spec), Settings()
    moved, shift = register(inst.mask.astype(np.int32), inst.depth, inst.camera, s.extract)
    cam, mask = inst.camera.shifted(*shift), moved > 0
    kwargs = {"own": False} if _backdrop() is not None else {}
    ex = extract(mask, inst.depth, cam, s.extract, **kwargs)
    tb = inst.truth_box
    own = np.all((ex.points >= tb.min - 0.005) & (ex.points <= tb.max + 0.005), axis=1).mean() if len(ex.points) else 0
    out(
        f"truth depth {tb.min[2]:.4f}-{tb.max[2]:.4f} m; kept {len(ex.points)} points, median "
        f"{np.median(ex.points[:, 2]) if len(ex.points) else float('nan'):.4f} m, {own:.2f} of them the fruit's"
    )
    if (backdrop := _backdrop()) is not None:
        out("behind, level, count:", backdrop(ex.points, mask, inst.depth, float(np.sqrt(cam.fx * cam.fy))))


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("survey")
    s.add_argument("frames")
    s.add_argument("--config")
    sub.add_parser("summary").add_argument("jsonl")
    d = sub.add_parser("diff")
    d.add_argument("a")
    d.add_argument("b")
    i = sub.add_parser("instance")
    i.add_argument("--sensor", required=True)
    i.add_argument("--fruit", required=True)
    i.add_argument("--index", type=int, required=True)
    i.add_argument("--pose", type=int, help="the view (default: the index, as the generated kinds' views are)")
    i.add_argument("--occlusion", type=float, default=0.0)
    args = p.parse_args()
    if args.cmd == "survey":
        survey(args.frames, args.config)
    elif args.cmd == "summary":
        summary(args.jsonl)
    elif args.cmd == "diff":
        diff(args.a, args.b)
    else:
        instance(args.sensor, args.fruit, args.index, args.index if args.pose is None else args.pose, args.occlusion)
    return 0


if __name__ == "__main__":
    sys.exit(main())
