"""The sensor check: measurements of a sphere's registration, invalid band and noise, on a known case."""

from pathlib import Path

import numpy as np
import pytest

from symfruit import Camera
from symfruit.evaluate.sensorcheck import (
    _best_shift,
    correlation_length,
    flat_patches,
    flat_table,
    measure_sphere,
    model_flat,
    model_frame,
    real_flat,
    real_frames,
    table,
)
from symfruit.synthetic.sensors import correlated_noise

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
    flat = model_flat(seed=0)  # noise_corr_px 3.5 depth px = 8 colour px; the 48 px patches' planes read it lower
    assert flat["patches"] > 20 and 5.5 < flat["corr_px"] < 9.0
    assert model_flat(seed=0, sensor_set={"noise_corr_px": 0})["corr_px"] < 3.0  # the footprint's repeats alone
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
    # Measured on the flat background (docs/sensors.md): about 0.7 mm, correlated over about 8 colour pixels.
    flat = real_flat(EXAMPLES / "real-frames")
    assert [r["frame"] for r in flat] == ["lab-spheres-0", "lab-spheres-1"] and all(r["patches"] > 300 for r in flat)
    assert all(0.5 < r["noise_mm"] < 0.9 and 7.0 < r["corr_px"] < 9.0 for r in flat)
    assert flat_table(flat).count("\n") == len(flat) + 1


def test_correlation_length_and_flat_patches_read_a_known_field():
    """A tilted plane with noise of known size and correlation (2 mm, 1/e at 5 px), a masked disc and its margin
    left out: flat_patches reads 2 mm and about 5 px (the plane fitted to each 48 px patch takes a little of the
    correlation away: within 15 %); independent noise reads below one pixel; too few pairs read NaN."""
    rng = np.random.default_rng(3)
    yy, xx = np.mgrid[:480, :480].astype(float)
    depth = 1.2 + 0.0004 * xx - 0.0002 * yy + 0.002 * correlated_noise(rng.normal(size=(480, 480)), 5.0)
    labels = (np.hypot(xx - 100, yy - 100) < 40).astype(np.int32)  # 16 patches within 20 px less 4 corners
    m = flat_patches(depth, labels)
    assert m["patches"] == 100 - 12 and m["z"] == pytest.approx(1.2 + 0.0004 * 240 - 0.0002 * 240, abs=0.02)
    assert m["noise_mm"] == pytest.approx(2.0, rel=0.1) and m["corr_px"] == pytest.approx(5.0, rel=0.15)
    white = flat_patches(1.0 + 0.002 * rng.normal(size=(96, 96)), np.zeros((96, 96), int))
    assert white["patches"] == 4 and white["corr_px"] < 1.0
    assert np.isnan(correlation_length(np.full((4, 4), np.nan)))
    assert flat_patches(np.zeros((96, 96)), np.zeros((96, 96), int))["patches"] == 0


def test_a_sphere_read_nearer_at_its_slope_is_measured_as_built():
    """A sphere whose depth reads 3 mm too near where its surface turns 45-60 degrees from the ray (|cos| 0.5-0.7):
    the residual at slope reads about -1.5 mm (the free sphere fit, its radius and centre, takes half of such a
    band: a reading is a lower bound of the bias), without it about 0 (1 mm noise)."""
    cam = Camera(fx=900.0, fy=900.0, cx=150.0, cy=150.0, width=300, height=300)
    yy, xx = np.mgrid[:300, :300].astype(float)
    z_c, radius = 1.0, 0.05
    rx, ry = (xx - 150) / cam.fx, (yy - 150) / cam.fy
    a = rx**2 + ry**2 + 1
    disc = z_c**2 - a * (z_c**2 - radius**2)
    on = disc > 0
    t = np.where(on, (z_c - np.sqrt(np.maximum(disc, 0.0))) / a, 0.0)
    cos = np.where(on, np.sqrt(np.maximum(disc, 0.0)) / radius / np.sqrt(a), 0.0)
    mask = on & (cos > 0.05)
    for bump, expect in ((0.0, 0.0), (-0.003, -1.5)):
        noise = 0.001 * np.random.default_rng(4).normal(size=t.shape)
        depth = np.where(on, t + noise + np.where((cos >= 0.5) & (cos < 0.7), bump, 0.0), 1.4)
        m = measure_sphere(depth, mask, cam, search=4)
        assert m["slope_mm"] == pytest.approx(expect, abs=0.5)
