"""The sensor check: measurements of a sphere's registration, invalid band and noise, on a known case."""

from pathlib import Path

import numpy as np
import pytest

from symfruit import Camera
from symfruit.evaluate.sensorcheck import _best_shift, measure_sphere, model_frame, real_frames, table

#: The shared real frames: ``../shared`` beside the clone (CI), or beside the folder of worktrees.
_ROOT = Path(__file__).resolve().parents[2]
_CANDIDATES = [p / "shared" / "data" / "real-frames" for p in (_ROOT.parent, _ROOT.parent.parent)]
REAL = next((p for p in _CANDIDATES if p.is_dir()), _CANDIDATES[0])


def test_a_shifted_sphere_with_a_hole_ring_is_measured_as_built():
    cam = Camera(fx=900.0, fy=900.0, cx=100.0, cy=100.0, width=200, height=200)
    yy, xx = np.mgrid[:200, :200].astype(float)
    z_c, radius = 1.0, 0.03
    r_px = cam.fx * radius / z_c
    # The depth silhouette 4 px right and 6 px down of the mask, a 3 px ring of no depth around it, a wall behind.
    rho = np.hypot(xx - 104, yy - 106)
    depth = np.full((200, 200), 1.3)
    on = rho <= r_px
    lateral = rho[on] / cam.fx * z_c
    depth[on] = z_c - np.sqrt(np.maximum(radius**2 - lateral**2, 0.0))
    depth[(rho > r_px) & (rho <= r_px + 3)] = 0.0
    mask = np.hypot(xx - 100, yy - 100) <= r_px
    m = measure_sphere(depth, mask, cam, search=8)
    assert (m["du"], m["dv"]) == (4.0, 6.0) and m["iou"] > 0.95
    assert m["band_px"] == pytest.approx(3.0, abs=1.0)
    assert m["flying"] == 0.0 and m["noise_mm"] < 0.5 and m["mask_no_depth"] < 0.2
    assert "| 1 |" in table([{"frame": "x", "sphere": 1, **m}])


def test_the_best_shift_is_the_one_a_loop_over_every_shift_finds():
    """Every shift's overlap at once (by FFT) against its definition: each shift rolled and counted, the first
    of equal IoUs kept (dv, then du, from -search), on random masks, shifted copies and empty images."""

    def by_loop(mask, silhouette, search):
        best = (-1.0, 0, 0)
        for dv in range(-search, search + 1):
            for du in range(-search, search + 1):
                shifted = np.roll(np.roll(mask, dv, axis=0), du, axis=1)
                iou = float((shifted & silhouette).sum() / max((shifted | silhouette).sum(), 1))
                if iou > best[0]:
                    best = (iou, du, dv)
        return best

    rng = np.random.default_rng(7)
    for k in range(24):
        h, w = rng.integers(3, 30, size=2) if k % 3 else rng.integers(2, 8, size=2)
        mask = rng.random((h, w)) < rng.random()
        silhouette = rng.random((h, w)) < rng.random()
        if k % 2:  # a shifted, thinned copy: one clear best shift
            silhouette = np.roll(mask, (rng.integers(-4, 5), rng.integers(-4, 5)), axis=(0, 1)) & silhouette
        search = int(rng.integers(0, 7)) if k % 3 else int(max(h, w)) + 1  # beyond the image: rolls wrap round
        assert _best_shift(mask, silhouette, search) == by_loop(mask, silhouette, search)
    empty = np.zeros((6, 9), bool)
    assert _best_shift(empty, empty, 3) == by_loop(empty, empty, 3) == (0.0, -3, -3)


@pytest.mark.slow
def test_the_model_and_the_real_frames_side_by_side():
    rows = model_frame(seed=0)
    assert len(rows) == 4 and all(3.0 < r["shift_px"] < 15.0 and 1.0 < r["band_px"] < 10.0 for r in rows)
    if not REAL.is_dir():
        pytest.skip(f"{REAL} not found")
    real = real_frames(REAL)
    assert len(real) == 8 and all(r["mask_no_depth"] > 0.05 for r in real)  # holes under every real mask


def test_the_shipped_real_frames_show_what_renders_lacked():
    """examples/real-frames (a copy of two shared Azure Kinect frames): on every free sphere the depth sits
    below the colour mask, and a ring of several pixels at its rim holds no depth (docs/sensors.md)."""
    from ..conftest import EXAMPLES

    rows = real_frames(EXAMPLES / "real-frames")
    assert sorted((r["frame"], r["sphere"]) for r in rows) == [(f, k) for f in ("lab-spheres-0", "lab-spheres-1")
                                                               for k in (1, 2, 3, 4)]  # fmt: skip
    free = [r for r in rows if r["sphere"] != 3]  # sphere 3 sits on the board (its depth blob runs into it)
    assert all(r["dv"] >= 8 and abs(r["du"]) <= 4 for r in free)
    assert all(3.0 <= r["band_px"] <= 6.0 and r["mask_no_depth"] > 0.05 for r in free)
    assert table(rows).count("\n") == len(rows) + 1
