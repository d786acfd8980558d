"""The colour segmenter with depth on rendered apple trees through a real colour camera's photometry (issue 18,
stop 45, docs/apples45.md): recall at mask IoU 0.5 and false regions with each effect of
:class:`symfruit.synthetic.render.Photometric` alone and all together, and the misses classed as
``docs/tree_misses.py`` classes them.

Each seed is rendered twice (the old apple palette and the new one); every look is then the same rendered colour
through :meth:`Photometric.apply` with that effect alone (the frame's photometric RNG the same for each), so the
looks differ by the effect only. ``old``: the colours of stops 30-44 bit for bit (``make_tree_scene(...,
photometric=None)``); ``palette``: the new apple colours, no camera effect; ``all``: ``make_tree_scene``'s default.

    python docs/apples45.py [--seed 0] [--n 12] [--looks old,all] [--cache DIR] [--rules old]

``--rules old``: the segmenter's colour rules of stops 1-44 (``dark_chroma: 0``: dim pixels never red).

``--cache DIR`` keeps the renders (pickles, about 130 MB a seed) to run the segmenter again without rendering.
"""

import argparse
import pickle
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from tree_masks import false_kind, match  # docs/tree_masks.py, beside this script
from tree_misses import CLASSES, classify  # docs/tree_misses.py

from symfruit.segment.colour import segment
from symfruit.settings import resolve_settings
from symfruit.synthetic.render import Photometric
from symfruit.synthetic.scenes import make_tree_scene

EFFECTS = {  # look -> the Photometric fields it keeps on (the rest off)
    "exposure": ("exposure_ev",),
    "cast": ("cast_deg",),
    "shadow": ("shadow_share",),
    "specular": ("specular",),
    "noise": ("full_well",),
    "blur": ("blur_px",),
    "jpeg": ("jpeg_quality",),
}
OFF = {"exposure_ev": 0.0, "cast_deg": 0.0, "shadow_share": 0.0, "specular": 0.0, "full_well": 0.0, "blur_px": 0.0,
       "jpeg_quality": 0}  # fmt: skip
LOOKS = ("old", "palette", *EFFECTS, "all")


class _Capture(Photometric):
    """Photometric that keeps what it was given (the rendered colour, the specular term, the scale, the RNG)."""

    def apply(self, color, spec, px_per_metre, rng):  # type: ignore[override]
        old = (np.clip(color, 0, 1) * 255).astype(np.uint8)  # make_tree_scene(..., photometric=None)'s colour
        object.__setattr__(self, "got", (color.copy(), spec.copy(), px_per_metre, rng.bit_generator.state, old))
        return super().apply(color, spec, px_per_metre, rng)


def renders(seed: int, cache: Path | None) -> dict:
    path = cache / f"tree{seed}.pkl" if cache else None
    if path and path.exists():
        return pickle.loads(path.read_bytes())
    out = {}
    for palette in (False, True):
        cap = _Capture(apple_palette=palette)
        scene = make_tree_scene(seed, photometric=cap)
        out[palette] = (replace(scene, color=None), *cap.got)  # type: ignore[attr-defined]
    if path:
        path.write_bytes(pickle.dumps(out))
    return out


def look_colour(look: str, parts: dict) -> np.ndarray:
    if look == "old":
        return parts[False][5]
    palette = look in ("palette", "all")
    _, color, spec, pxm, state, _ = parts[palette]
    if look == "all":
        p = Photometric()
    else:
        keep = EFFECTS.get(look, ())
        p = Photometric(**{k: v for k, v in OFF.items() if k not in keep})
    rng = np.random.default_rng()
    rng.bit_generator.state = state
    return p.apply(color.copy(), spec, pxm, rng)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--n", type=int, default=12)
    parser.add_argument("--looks", default=",".join(LOOKS))
    parser.add_argument("--cache", type=Path, default=None)
    parser.add_argument("--rules", choices=("new", "old"), default="new")
    args = parser.parse_args()
    looks = args.looks.split(",")
    settings = resolve_settings(fruit="apple").segment
    if args.rules == "old":
        settings = replace(settings, dark_chroma=0)
    stats = {k: {"found": 0, "total": 0, "regions": 0, "false": dict.fromkeys(("on_apple", "on_unripe", "other"), 0),
                 "miss": dict.fromkeys(CLASSES, 0), "ms": []} for k in looks}  # fmt: skip
    for seed in range(args.seed, args.seed + args.n):
        parts = renders(seed, args.cache)
        scene = parts[False][0]
        for look in looks:
            color = look_colour(look, parts)
            ripe = [f for f in scene.fruits if f.ripe and (scene.labels == f.id).any()]
            unripe = np.array([f.id for f in scene.fruits if not f.ripe])
            ids = np.array([f.id for f in ripe])
            truth = scene.labels[None] == ids[:, None, None]
            start = time.process_time()
            labels = segment(color, scene.depth, scene.camera, settings)
            st = stats[look]
            st["ms"].append(1000 * (time.process_time() - start))
            _, rids, found, matched = match(truth, labels)
            st["found"] += int(found.sum())
            st["total"] += len(ripe)
            st["regions"] += len(rids)
            sizes = np.array([(labels == k).sum() for k in rids])
            on_fruit = np.array([((labels == k) & (scene.labels > 0)).sum() for k in rids])
            for i in np.flatnonzero(~found):
                mask = truth[i]
                area = int(mask.sum())
                cover = np.array([(labels[mask] == k).sum() for k in rids])
                f = ripe[i]
                st["miss"][classify(area, f.visible or 1.0, cover, sizes, on_fruit - cover)] += 1
            for k in rids[~matched]:
                st["false"][false_kind(scene.labels[labels == k], ids, unripe)] += 1
        sys.stderr.write(f"seed {seed} done\n")
    out = sys.stdout
    out.write(f"seeds {args.seed}-{args.seed + args.n - 1}\n")
    out.write("| look | found | recall | false (partial / unripe / other) of regions | misses " +
              " ".join(CLASSES) + " | ms median |\n|---|---|---|---|---|---|\n")  # fmt: skip
    for look in looks:
        st = stats[look]
        fa = st["false"]
        out.write(f"| {look} | {st['found']} / {st['total']} | {st['found'] / max(1, st['total']):.1%} | "
                  f"{sum(fa.values())} ({fa['on_apple']} / {fa['on_unripe']} / {fa['other']}) of {st['regions']} | "
                  + " ".join(str(st["miss"][c]) for c in CLASSES) + f" | {np.median(st['ms']):.0f} |\n")  # fmt: skip


if __name__ == "__main__":
    main()
