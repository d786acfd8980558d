"""Parametric fruit surfaces and scans: closed, centred, sized, seeded."""

import numpy as np
import pytest

from symfruit.synthetic.shapes import FRUITS, STRAWBERRY_CLASSES, load_scans, paper_visible, rotation, strawberry

from ..conftest import fibonacci_sphere

#: Per kind: 1 = the length (y extent) is checked, 0 = the width (the larger of the x and z extents).
SIZES = {"strawberry": (1, (0.025, 0.050)), "apple": (0, (0.058, 0.095)), "citrus": (0, (0.058, 0.095)),
         "tomato": (0, (0.038, 0.085)), "pear": (1, (0.055, 0.125)), "lemon": (1, (0.055, 0.100)),
         "peach": (0, (0.050, 0.090)), "plum": (1, (0.030, 0.070)), "banana": (1, (0.100, 0.200)),
         "lopsided": (0, (0.035, 0.130))}  # fmt: skip


def closed(faces: np.ndarray) -> bool:
    """Every undirected edge shared by exactly two triangles."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return bool(np.all(counts == 2))


@pytest.mark.parametrize("kind", FRUITS)
def test_fruits_are_closed_centred_sized_and_seeded(kind):
    for seed in range(5):
        fruit = FRUITS[kind](np.random.default_rng(seed))
        assert closed(fruit.faces)
        lo, hi = fruit.vertices.min(axis=0), fruit.vertices.max(axis=0)
        assert np.allclose((lo + hi) / 2, 0, atol=1e-12)
        axis, (small, large) = SIZES[kind]
        size = (hi - lo)[axis] if axis == 1 else max((hi - lo)[0], (hi - lo)[2])
        assert small <= size <= large, (kind, seed, size)
        again = FRUITS[kind](np.random.default_rng(seed))
        assert np.array_equal(fruit.vertices, again.vertices)


def test_strawberry_classes_and_shape_features():
    for shape in STRAWBERRY_CLASSES:
        berry = strawberry(np.random.default_rng(1), shape=shape, length=0.04)
        assert berry.kind == f"strawberry/{shape}"
        lo, hi = berry.vertices.min(axis=0), berry.vertices.max(axis=0)
        assert hi[1] - lo[1] == pytest.approx(0.04, rel=0.08)
    long = strawberry(np.random.default_rng(1), shape="long-conic", length=0.04)
    globose = strawberry(np.random.default_rng(1), shape="globose", length=0.04)
    assert np.ptp(long.vertices[:, 0]) < np.ptp(globose.vertices[:, 0])
    # Shoulder near the calyx (top, -y), tip at the bottom: the widest ring sits in the top half.
    v = long.vertices
    widest = v[np.argmax(np.hypot(v[:, 0], v[:, 2])), 1]
    assert widest < 0
    with pytest.raises(ValueError, match="unknown strawberry class"):
        strawberry(np.random.default_rng(0), shape="banana")


def test_sampling_is_uniform_on_a_sphere():
    from scipy.spatial import ConvexHull

    hull = ConvexHull(fibonacci_sphere(800))
    from symfruit.synthetic.shapes import sample_surface

    pts = sample_surface(hull.points, hull.simplices, 20000, np.random.default_rng(0))
    assert np.abs(pts.mean(axis=0)).max() < 0.02
    assert np.allclose(np.linalg.norm(pts, axis=1), 1.0, atol=0.01)


def test_paper_visibility_rule_keeps_the_front_half_of_a_sphere():
    pts = fibonacci_sphere(2000) * 0.02 + [0, 0, 0.3]
    keep = paper_visible(pts)
    assert np.all(pts[keep, 2] < 0.3 + 1e-3) and keep.mean() == pytest.approx(0.5, abs=0.02)


def test_rotation_composes_about_fixed_axes():
    assert np.allclose(rotation(90, 0, 0) @ [0, 1, 0], [0, 0, 1])
    assert np.allclose(rotation(0, 90, 0) @ [1, 0, 0], [0, 0, -1])
    r = rotation(20, 30, 40)
    assert np.allclose(r @ r.T, np.eye(3))


def test_load_scans_from_a_folder(tmp_path):
    from symfruit.io import write_ply

    fruit = FRUITS["apple"](np.random.default_rng(0))
    write_ply(tmp_path / "a_cloud.ply", fruit.sample(2000, np.random.default_rng(1)) + [0.1, 0.2, 0.3])
    with (tmp_path / "b_mesh.obj").open("w") as f:
        for v in fruit.vertices:
            f.write(f"v {v[0]} {v[1]} {v[2]}\n")
        for t in fruit.faces + 1:
            f.write(f"f {t[0]}/1/1 {t[1]}/1/1 {t[2]}/1/1\n")
    (tmp_path / "notes.md").write_text("ignored")
    scans = load_scans(tmp_path)
    assert [s.kind for s in scans] == ["scan/a_cloud", "scan/b_mesh"]
    assert scans[0].points is not None and len(scans[0].faces) > 0  # rendered through its hull
    assert scans[1].points is None and len(scans[1].faces) == len(fruit.faces)
    assert np.allclose((scans[0].vertices.min(0) + scans[0].vertices.max(0)) / 2, 0, atol=1e-9)


def test_load_scans_errors(tmp_path):
    from symfruit import FileFormatError

    with pytest.raises(FileFormatError, match="no such folder"):
        load_scans(tmp_path / "nope")
    with pytest.raises(FileFormatError, match="no fruit scans found"):
        load_scans(tmp_path)
    np.save(tmp_path / "tiny.npy", np.random.default_rng(0).random((20, 3)))
    with pytest.raises(FileFormatError, match=r"tiny\.npy: a complete scan needs at least 100 points"):
        load_scans(tmp_path)
    failed = {}  # asked to go on: the bad scan is recorded, the folder refused only for holding none readable
    with pytest.raises(FileFormatError, match=r"no fruit scans found .*1 not readable, the first: .*tiny\.npy: a comp"):
        load_scans(tmp_path, failed=failed)
    assert list(failed) == [str(tmp_path / "tiny.npy")]
    np.save(tmp_path / "whole.npy", FRUITS["apple"](np.random.default_rng(0)).sample(500, np.random.default_rng(1)))
    failed = {}
    assert [s.kind for s in load_scans(tmp_path, failed=failed)] == ["scan/whole"]
    assert "at least 100 points, got 20" in failed[str(tmp_path / "tiny.npy")]


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda v, f: (v * 1000, f), r"the scan is 80\.6 m across; fruit scans are in metres, 0\.001-2 m across "
         r"\(millimetres, or no fruit\?\)$"),
        (lambda v, f: (v * 1e30, f), r"the scan is 8\.06e\+28 m across"),
        (lambda v, f: (v * 1e-6, f), r"the scan is 8\.06e-08 m across"),
        (lambda v, f: (v, np.repeat(f[:, :1], 3, axis=1)), r"the mesh's 9,984 faces have no area \(each a point or "
         r"a line\)$"),
        (lambda v, f: (v, f[:, [0, 1, 1]]), r"the mesh's 9,984 faces have no area"),
    ],
)  # fmt: skip
def test_a_scan_of_no_area_or_of_a_size_no_fruit_has_is_refused_by_name(tmp_path, change, message):
    """Stop 51 (robust51): a mesh whose every face is a point or a line failed in numpy when sampled
    ("Probabilities contain NaN"); a scan of 1e30 m, or in millimetres (an apple of 80 m), was taken."""
    from symfruit import FileFormatError

    fruit = FRUITS["apple"](np.random.default_rng(0))
    vertices, faces = change(fruit.vertices, fruit.faces)
    with (tmp_path / "s.obj").open("w") as f:
        f.writelines(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in vertices)
        f.writelines(f"f {a} {b} {c}\n" for a, b, c in faces + 1)
    with pytest.raises(FileFormatError, match=rf"s\.obj: {message}"):
        load_scans(tmp_path)
