"""docs/grown64.py (stop 64, docs/grown64.md): the lost rim and the first pixel seen past read against a mask."""

import numpy as np

from ..conftest import docs_script


def _disc(lost: int, grown: int, gap: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """A flat disc 30 px in radius at 1 m, its outer ``lost`` px without depth, a wall at 2 m from ``gap`` px beyond
    its edge; the mask the disc grown by ``grown`` px."""
    yy, xx = np.mgrid[:200, :200]
    r = np.hypot(yy - 100, xx - 100)
    depth = np.where(r < 30 - lost, 1.0, np.where(r >= 30 + gap, 2.0, 0.0))
    return depth, r < 30 + grown


def test_a_grown_mask_moves_both_reads_a_wider_lost_rim_only_the_rim():
    """Known answers: the outline's distance beyond the last depth is the lost rim plus the growth; beyond the first
    pixel seen past, the growth less the gap outside the edge (plus half a pixel); a rim lost 3 px wider moves the
    first read by 3 and the second not at all. The colour camera's shadow is ``B f (1 / z_f - 1 / z_b)``."""
    g = docs_script("grown64")
    reads = {}
    for name, (lost, grown) in {"drawn": (4, 0), "grown": (4, 3), "rim": (7, 0)}.items():
        depth, mask = _disc(lost, grown)
        r = g.sector_reads(depth, mask, 1000.0, 0.05)
        reads[name] = (np.nanmedian(r["rim"]), np.nanmedian(r["past"]), np.nanmedian(r["shadow"]))
    rim, past, shadow = reads["drawn"]
    # along a ray: the last mask pixel at 29 px, the last depth at 25, the first pixel seen past at 31
    assert abs(rim - 4) <= 0.5 and abs(past - (29 - 31 + 0.5)) <= 0.5 and abs(shadow - 25.0) < 0.5
    assert abs(reads["grown"][0] - rim - 3) <= 0.5 and abs(reads["grown"][1] - past - 3) <= 0.5
    assert abs(reads["rim"][0] - rim - 3) <= 0.5 and abs(reads["rim"][1] - past) <= 0.5
