"""Shared fixtures and helpers: known-answer solids seen by the default camera, small synthetic RGB-D
frames, point-cloud writers the readers are tested against, the shipped example data, and the hypothesis
profiles.

The test tree mirrors ``src/symfruit``: ``tests/core/test_box.py`` tests ``symfruit/core/box.py`` and so on.
Test modules never import each other; what two of them share lives here, as a fixture or as a helper
imported with ``from ..conftest import NAME`` (``from .conftest import NAME`` at the top level).

Property and fuzz tests run the derandomised ``ci`` profile by default: the same cases on every run,
``SYMFRUIT_FUZZ_EXAMPLES`` of them (default 40), so a failure in CI is a failure on every machine. The
``long`` profile (``make test-long``, or ``SYMFRUIT_HYPOTHESIS=long``) draws fresh random cases, 1,000 per
test unless ``SYMFRUIT_FUZZ_EXAMPLES`` says otherwise.
"""

from __future__ import annotations

import functools
import importlib.util
import os
import signal
import sys
from pathlib import Path

# One BLAS thread per process, set before numpy loads OpenBLAS (numpy's and scipy's both read it): the suite runs
# one pytest-xdist worker per core, and each worker's OpenBLAS would otherwise start a thread per core too and
# spin-wait on it, so on this 2-core machine the workers and their CLI and ROS children (they inherit it) fought
# over the cores: 10-15 % more CPU for the same tests, and more wall time still when other work shares the host.
# A value already set (a run that wants to test threaded BLAS) is kept.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

import symfruit
from symfruit import Camera


def _ram_temp_root(folder: Path = Path("/dev/shm"), needed: int = 2 << 30) -> str | None:
    """``folder`` when it is a writable RAM disk with ``needed`` bytes free, else None."""
    import shutil

    try:
        ok = folder.is_dir() and os.access(folder, os.W_OK) and shutil.disk_usage(folder).free >= needed
    except OSError:
        return None
    return str(folder) if ok else None


# pytest's temporary folders (tmp_path, tmp_path_factory; PYTEST_DEBUG_TEMPROOT is pytest's own setting) on the
# RAM disk where there is one: every output is written atomically, fsync included, and on this host's disk the
# suite's ~700 fsyncs held the workers up for seconds of wall time that nothing here measures (durability across
# a power cut is not something a test can check). Only pytest's folders: the lock files of the ROS 2 domain
# leases stay in the system's temporary folder, shared with every other process on the machine.
if "PYTEST_DEBUG_TEMPROOT" not in os.environ and (_ram := _ram_temp_root()) is not None:
    os.environ["PYTEST_DEBUG_TEMPROOT"] = _ram


_QUIET = [HealthCheck.too_slow, HealthCheck.function_scoped_fixture, HealthCheck.data_too_large]
settings.register_profile(
    "ci", derandomize=True, database=None, deadline=None, suppress_health_check=_QUIET, print_blob=True,
    max_examples=int(os.environ.get("SYMFRUIT_FUZZ_EXAMPLES", "40")),
)  # fmt: skip
settings.register_profile(
    "long", derandomize=False, deadline=None, suppress_health_check=_QUIET, print_blob=True,
    max_examples=int(os.environ.get("SYMFRUIT_FUZZ_EXAMPLES", "1000")),
)  # fmt: skip
settings.load_profile(os.environ.get("SYMFRUIT_HYPOTHESIS", "ci"))

# A shell that starts a job in the background without job control (``make test &`` in a script, ``nohup``) starts
# it with SIGINT ignored, and an ignored signal stays ignored in every process started from it: the nodes, masters
# and children these tests stop with SIGINT would then take their kill timeouts instead (30 s, and the restored
# handler a test compares with is SIG_IGN). Each process of the suite (xdist's workers load this file too) takes
# SIGINT back, so what its children inherit does not depend on how the suite was started.
if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.hookimpl(trylast=True)
def pytest_configure(config) -> None:
    # small_frame() is a crop of the example frame whose principal point lies left of it (cx -80): the cropped
    # image a warning allows for (symfruit.io.intrinsics.warn_principal_point), read by dozens of batch tests.
    # Its warning is tested where it is said (pytest.warns records whatever the filters say).
    config.addinivalue_line("filterwarnings", r"ignore:.*the principal point \(cx -80, cy 140\) lies outside")


def pytest_collection_modifyitems(config, items) -> None:
    """Keep ``--dist loadgroup``'s groups together: pytest-xdist names a test's ``xdist_group`` in its node id on
    the worker, and since pytest 9.2 (structured node ids) its assignment no longer takes, so every group was
    spread over the workers and its expensive fixture computed on each (pytest-xdist issue 1386). Done here
    after xdist's own hook, and only where it did not take."""
    if not getattr(config.option, "loadgroup", False):
        return
    for item in items:
        names = {
            str(m.args[0] if m.args else m.kwargs.get("name", "default")) for m in item.iter_markers("xdist_group")
        }
        suffix = "@" + "_".join(sorted(names))
        if names and not item.nodeid.endswith(suffix):
            try:  # a private attribute: where a pytest lacks it or changes it, the groups spread again, as before
                item._id = type(item._id).parse(item.nodeid + suffix)
            except (AttributeError, TypeError, ValueError):
                return


#: Examples per property test under the loaded profile (tests that are costlier run a share of it).
FUZZ_EXAMPLES = settings.default.max_examples

#: The repository's root, its examples folder (sample cloud, camera) and its package source.
ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
SRC = ROOT / "src" / "symfruit"
#: The demo frame shipped as package data.
EXAMPLE_FRAME = Path(symfruit.__file__).resolve().parent / "data" / "example_frame"


def docs_script(name: str):
    """The module of ``docs/<name>.py`` (a measurement script the README and docs/ cite), loaded from its file: the
    docs folder is no package."""
    spec = importlib.util.spec_from_file_location(f"docs_{name}", ROOT / "docs" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up while it runs
    spec.loader.exec_module(module)
    return module


#: The part of the example frame :func:`small_frame` keeps: (left, top, right, bottom) pixels.
SMALL_CROP = (400, 100, 560, 260)


@functools.cache
def small_frame() -> Path:
    """A frame folder holding :data:`SMALL_CROP` of the example frame: its right-hand ripe strawberry alone
    (160x160 pixels, intrinsics shifted to the crop, the truth of that fruit alone). Tests of how frames are
    batched, resumed, written and refused use it: it detects in a sixth of the example frame's time. Written
    once per test process (a temporary folder removed at exit); copy it, never write into it."""
    import atexit
    import json
    import shutil
    import tempfile

    from PIL import Image

    folder = Path(tempfile.mkdtemp(prefix="symfruit-small-frame-")) / "small_frame"
    folder.mkdir()
    atexit.register(shutil.rmtree, folder.parent, True)
    for name in ("color.png", "depth.png"):
        with Image.open(EXAMPLE_FRAME / name) as image:
            image.crop(SMALL_CROP).save(folder / name)
    left, top, right, bottom = SMALL_CROP
    cam = json.loads((EXAMPLE_FRAME / "camera.json").read_text())
    cam.update(cx=cam["cx"] - left, cy=cam["cy"] - top, width=right - left, height=bottom - top)
    (folder / "camera.json").write_text(json.dumps(cam))
    truth = json.loads((EXAMPLE_FRAME / "truth.json").read_text())
    seen = Camera(**{k: cam[k] for k in ("fx", "fy", "cx", "cy", "width", "height")})
    u, v = seen.project(np.asarray([f["centre"] for f in truth["fruits"]])).T
    keep = (u >= 0) & (u < seen.width) & (v >= 0) & (v < seen.height)
    inside = [f for f, k in zip(truth["fruits"], keep, strict=True) if k]
    (folder / "truth.json").write_text(json.dumps({**truth, "fruits": inside}))
    return folder


CENTRE = np.array([0.01, -0.02, 0.35])


# --- known-answer solids -------------------------------------------------------------------------------


def fibonacci_sphere(n: int) -> np.ndarray:
    """(n, 3) unit vectors spread evenly over the sphere (deterministic)."""
    i = np.arange(n) + 0.5
    phi = np.arccos(1.0 - 2.0 * i / n)
    theta = np.pi * (1.0 + 5**0.5) * i
    return np.c_[np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)]


def sphere_cloud(radius: float = 0.02, n: int = 1200, centre: np.ndarray = CENTRE) -> np.ndarray:
    return radius * fibonacci_sphere(n) + centre


def random_sphere(n: int = 2000, radius: float = 0.03, seed: int = 0) -> np.ndarray:
    """(n, 3) seeded random points on a sphere of ``radius`` about :data:`CENTRE`."""
    d = np.random.default_rng(seed).normal(size=(n, 3))
    return radius * d / np.linalg.norm(d, axis=1, keepdims=True) + CENTRE


def noisy_cap(seed: int) -> tuple[np.ndarray, float]:
    """``(points (n, 3), radius)``: a seeded random cap of a sphere facing the camera (radius 15-60 mm, 100-800 points,
    0.5-1.4 rad from its front, at 0.4-1.5 m), with 0-2 mm of Gaussian noise."""
    rng = np.random.default_rng(seed)
    radius, n, cap, noise = (
        rng.uniform(0.015, 0.06),
        int(rng.integers(100, 800)),
        rng.uniform(0.5, 1.4),
        rng.uniform(0, 0.002),
    )
    centre = np.array([rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), rng.uniform(0.4, 1.5)])
    polar, around = np.arccos(rng.uniform(np.cos(cap), 1.0, n)), rng.uniform(0.0, 2.0 * np.pi, n)
    d = np.stack([np.sin(polar) * np.cos(around), np.sin(polar) * np.sin(around), -np.cos(polar)], axis=1)
    return centre + radius * d + rng.normal(0.0, noise, (n, 3)), float(radius)


def ellipsoid_cloud(axes=(0.018, 0.025, 0.015), n: int = 1200, centre: np.ndarray = CENTRE) -> np.ndarray:
    return fibonacci_sphere(n) * np.asarray(axes) + centre


def revolution_cloud(centre: np.ndarray = CENTRE) -> np.ndarray:
    """An egg-like solid of revolution about y: r(y) = R sqrt(1 - (y/L)^2) (1 + 0.3 y/L)."""
    t = np.linspace(-1.0, 1.0, 60)[1:-1]
    phi = np.linspace(0.0, 2.0 * np.pi, 40, endpoint=False)
    tt, pp = np.meshgrid(t, phi)
    r = 0.02 * np.sqrt(1.0 - tt**2) * (1.0 + 0.3 * tt)
    pts = np.c_[(r * np.cos(pp)).ravel(), (0.025 * tt).ravel(), (r * np.sin(pp)).ravel()]
    return pts + centre


def front_half(cloud: np.ndarray, centre: np.ndarray = CENTRE) -> np.ndarray:
    """The half facing the camera (z below the centre's)."""
    return cloud[cloud[:, 2] < centre[2]]


#: The front half of the default sphere: the visible points of most end-to-end tests.
VISIBLE = front_half(sphere_cloud())


def rendered_view(fruit, centre, *, noise: float = 0.0, rotation=None, seed: int = 0) -> tuple[np.ndarray, object]:
    """``(visible (n, 3), posed fruit)``: a fruit mesh posed at ``centre`` (metres) and rendered by the default
    camera, one point per pixel at the pixel centre, axial noise ``noise * z^2`` metres (seeded)."""
    from symfruit.synthetic.render import render

    cam = symfruit.DEFAULT_CAMERA
    posed = fruit.transformed(np.eye(3) if rotation is None else rotation, np.asarray(centre, dtype=float))
    shot = render([(posed.vertices, posed.faces)], cam)
    rows, cols = np.nonzero(shot.ids == 0)
    z = shot.depth[rows, cols]
    z = z + np.random.default_rng(seed).normal(size=z.shape) * noise * z**2
    return cam.deproject(np.c_[cols, rows].astype(float), z), posed


def occluded_view(fruit, centre, *, below: float, occluder_z: float, noise: float = 0.0, seed: int = 0,
                  rotation=None) -> tuple[np.ndarray, np.ndarray, np.ndarray, object]:  # fmt: skip
    """``(visible (n, 3), depth (h, w), mask (h, w), posed fruit)``: as :func:`rendered_view`, with a flat
    occluder at depth ``occluder_z`` (metres) hiding every pixel below image row ``below`` and a backdrop at
    1 m; ``depth`` is the whole rendered depth image (0 where nothing), ``mask`` the fruit's seen pixels."""
    from symfruit.synthetic.render import render

    cam = symfruit.DEFAULT_CAMERA
    posed = fruit.transformed(np.eye(3) if rotation is None else rotation, np.asarray(centre, dtype=float))
    y = (below - cam.cy) / cam.fy
    quad = np.array([[-2.0, y * occluder_z, occluder_z], [2.0, y * occluder_z, occluder_z],
                     [2.0, 2.0, occluder_z], [-2.0, 2.0, occluder_z]])  # fmt: skip
    back = np.array([[-3.0, -3.0, 1.0], [3.0, -3.0, 1.0], [3.0, 3.0, 1.0], [-3.0, 3.0, 1.0]])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    shot = render([(posed.vertices, posed.faces), (quad, faces), (back, faces)], cam)
    depth = np.where(np.isfinite(shot.depth), shot.depth, 0.0)
    depth = depth + np.random.default_rng(seed).normal(size=depth.shape) * noise * depth**2
    mask = shot.ids == 0
    rows, cols = np.nonzero(mask)
    return cam.deproject(np.c_[cols, rows].astype(float), depth[rows, cols]), depth, mask, posed


def hidden_image(occ) -> np.ndarray:
    """An :class:`~symfruit.core.occlusion.Occlusion`'s hidden pixels as a whole image (``height x width`` bool)."""
    full = np.zeros((occ.height, occ.width), bool)
    h, w = occ.hidden.shape
    full[occ.v0 : occ.v0 + h, occ.u0 : occ.u0 + w] = occ.hidden
    return full


def ball_mesh(radius: float = 0.035):
    """A closed triangle-mesh ball (a revolved half circle, 96 x 90)."""
    from symfruit.synthetic.shapes import _revolve

    t = np.linspace(0, np.pi, 90)
    return _revolve(radius * np.sin(t), -radius * np.cos(t), name="ball", n_phi=96)


def _find_real_scans() -> Path | None:
    """The repository's copy of the two shared real scans (``examples/scans``: the same vertices and faces
    as ``../shared/data/real-scans``, binary PLY), so CI runs the real-shape tests wherever it clones."""
    folder = ROOT / "examples" / "scans"
    return folder if (folder / "016_pear.ply").is_file() else None


#: The real scans (YCB object set, Calli et al. 2015, CC BY 4.0; examples/scans/README.md).
REAL_SCANS = _find_real_scans()
#: Skip marker of tests that need them (only a checkout without examples/ lacks them).
needs_real_scans = pytest.mark.skipif(REAL_SCANS is None, reason="examples/scans (the real scans) is absent")


# --- small synthetic RGB-D frames ----------------------------------------------------------------------

#: A 160x120 camera for small synthetic frames.
SMALL_CAM = Camera(fx=600, fy=600, cx=80, cy=60, width=160, height=120)


def disc_frame(centres, radius=20, z=0.3, colour=(200, 20, 30)) -> tuple[np.ndarray, np.ndarray]:
    """``(color (120, 160, 3) uint8, depth (120, 160) float32)`` of spheres seen by :data:`SMALL_CAM`.

    Each ``(u, v)`` of ``centres`` is a sphere whose silhouette is a disc of ``radius`` pixels, its front
    pole ``z`` metres away (``z`` may be one depth per sphere); the background is grey and 1 m away.
    """
    color = np.full((120, 160, 3), 90, np.uint8)
    depth = np.full((120, 160), 1.0, np.float32)
    yy, xx = np.mgrid[:120, :160]
    zs = np.broadcast_to(np.asarray(z, dtype=np.float64), (len(centres),))
    for (cx, cy), zk in zip(centres, zs, strict=True):
        inside = (xx - cx) ** 2 + (yy - cy) ** 2 <= radius**2
        color[inside] = colour
        r_m = radius * zk / 600
        d2 = ((xx - cx) ** 2 + (yy - cy) ** 2) * (zk / 600) ** 2
        depth[inside] = np.minimum(depth[inside], (zk - np.sqrt(np.clip(r_m**2 - d2, 0, None)))[inside])
    return color, depth


def leaf_across_frame(seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(color, depth (float32), mask)`` seen by :data:`SMALL_CAM`: a red ball of 30 px at (80, 60), its front 0.5 m,
    the outer tenth of its radius without depth (a time-of-flight camera's grazing pixels), under a grey flat leaf
    at 0.40 m, a disc of 42 px at (60, 60) that hides all of it but a crescent on its right and runs on beyond it
    on the left; ``mask`` the ball's outline grown by 2 px, drawn over the leaf as an annotator draws it (the scene
    of tests/core/test_surface.py's ``leaf_across``, stop 46)."""
    yy, xx = np.mgrid[:120, :160].astype(np.float64)
    d2 = ((xx - 80) ** 2 + (yy - 60) ** 2) / 30**2
    disc = d2 <= 1.0
    depth = np.where(disc, 0.5 + 0.025 * (1.0 - np.sqrt(np.clip(1.0 - d2, 0.0, None))), 0.8)
    leaf = (xx - 60) ** 2 + (yy - 60) ** 2 <= 42**2
    depth = np.where(leaf, 0.40 / (1.0 - 0.1 * (xx - 60) / 600 + 0.05 * (yy - 60) / 600), depth)
    depth = depth + np.random.default_rng(seed).normal(scale=0.0005, size=depth.shape)
    depth[disc & ~leaf & (d2 > 0.81)] = 0.0
    color = np.full((120, 160, 3), 90, np.uint8)
    color[disc] = (200, 20, 30)
    color[leaf] = (90, 90, 90)
    yy, xx = np.mgrid[:120, :160]
    mask = (xx - 80) ** 2 + (yy - 60) ** 2 <= 32**2
    return color, depth.astype(np.float32), mask


# --- cloud files -----------------------------------------------------------------------------------------

#: A small seeded cloud the readers and writers round-trip.
POINTS = np.random.default_rng(0).normal(size=(40, 3)) * 0.01 + [0.0, 0.0, 0.3]


def lzf_compress(data: bytes) -> bytes:
    """A small greedy LZF compressor, to test the reader's back references."""
    out, i, lit = bytearray(), 0, bytearray()

    def flush():
        while lit:
            chunk = lit[:32]
            out.append(len(chunk) - 1)
            out.extend(chunk)
            del lit[:32]

    while i < len(data):
        best_len, best_off = 0, 0
        for off in range(1, min(i, 8192) + 1):
            n = 0
            while i + n < len(data) and n < 264 and data[i - off + n] == data[i + n]:
                n += 1
            if n > best_len:
                best_len, best_off = n, off
        if best_len >= 3:
            flush()
            length, ref = best_len - 2, best_off - 1
            if length < 7:
                out.append((length << 5) | (ref >> 8))
            else:
                out.append((7 << 5) | (ref >> 8))
                out.append(length - 7)
            out.append(ref & 0xFF)
            i += best_len
        else:
            lit.append(data[i])
            i += 1
    flush()
    return bytes(out)


def write_pcd(path, points, mode, extra_field=False):
    """Write a PCD v0.7 file in ``mode`` ``ascii``, ``binary`` or ``binary_compressed``."""
    names = ["x", "y", "z"] + (["intensity"] if extra_field else [])
    cols = np.c_[points, np.arange(len(points))] if extra_field else points
    head = (
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n"
        f"FIELDS {' '.join(names)}\nSIZE {' '.join(['4'] * len(names))}\n"
        f"TYPE {' '.join(['F'] * len(names))}\nCOUNT {' '.join(['1'] * len(names))}\n"
        f"WIDTH {len(points)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {len(points)}\nDATA {mode}\n"
    )
    arr = cols.astype("<f4")
    if mode == "ascii":
        body = "\n".join(" ".join(f"{v:.9g}" for v in row) for row in arr).encode() + b"\n"
    elif mode == "binary":
        body = arr.tobytes()
    else:
        raw = arr.T.copy().tobytes()  # field after field
        packed = lzf_compress(raw)
        body = np.array([len(packed), len(raw)], "<u4").tobytes() + packed
    path.write_bytes(head.encode() + body)


def after_its_status_time(path: Path) -> None:
    """Return once the clock is past ``path``'s status-change time by more than a file-time tick (10 ms at most:
    a kernel without fine-grained time stamps takes them from a clock that ticks every 1-10 ms), so that a change
    made next gives it a later one on any kernel. The wait is for the clock to pass, bounded (a minute)."""
    import time

    until = os.stat(path).st_ctime_ns + 20_000_000
    deadline = time.monotonic() + 60
    while time.time_ns() <= until and time.monotonic() < deadline:
        time.sleep(0.002)


def set_back(path: Path, *, flip: bool = False) -> None:
    """Write the middle byte of ``path`` again (``flip``: its bits flipped; its size kept) and set its access and
    modification times back to what they were (``os.utime``), as ``cp -p`` or an archive unpacked over it would."""
    st = os.stat(path)
    with open(path, "r+b") as handle:
        handle.seek(st.st_size // 2)
        byte = handle.read(1)[0]
        handle.seek(st.st_size // 2)
        handle.write(bytes([byte ^ 0xFF if flip else byte]))
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns))


# --- fixtures --------------------------------------------------------------------------------------------


@pytest.fixture
def numpy_twins(monkeypatch):
    """The numpy twins of the compiled kernels (:mod:`symfruit.core.kernels`) for the test: for tests that pin the
    numpy formulation's values bit for bit (the kernels agree with them to rounding)."""
    monkeypatch.setenv("SYMFRUIT_KERNELS", "numpy")


@pytest.fixture
def camera() -> symfruit.Camera:
    return symfruit.DEFAULT_CAMERA


@pytest.fixture
def sphere_view() -> np.ndarray:
    return front_half(sphere_cloud())


def _read_only(frame):
    """The frame with its arrays made read-only: a test or a stage that writes into a shared frame fails."""
    for arr in (frame.color, frame.depth, frame.masks):
        if arr is not None:
            arr.flags.writeable = False
    return frame


@pytest.fixture(scope="session")
def example():
    """The shipped example frame (read once; its arrays are read-only)."""
    from symfruit.io.frames import read_frame

    return _read_only(read_frame(EXAMPLE_FRAME))


@pytest.fixture(scope="session")
def example_found(example):
    """``detect(example, method="paper")``, computed once."""
    from symfruit.detect import detect

    return detect(example, method="paper")


@pytest.fixture
def isolated_registry(monkeypatch):
    """Lets a test register completion methods, settings sections and frame sources without leaking
    them into other tests: the registries are copies, restored afterwards."""
    from symfruit import settings as settings_module
    from symfruit.io import sources
    from symfruit.methods import registry

    monkeypatch.setattr(settings_module, "_SECTIONS", dict(settings_module._SECTIONS))
    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))
    monkeypatch.setattr(sources, "_KINDS", list(sources._KINDS))


#: What root gives up to read files as any other user would (root reads a file whatever its mode by these two
#: capabilities): ``setpriv`` drops them from the bounding set, so the command run keeps root's user id (the
#: repository, its environment and numba's cache stay readable wherever the clone lies, a folder of mode 0700 under
#: /root too, where the nobody user could not even start the interpreter) but a file of mode 000 is unreadable to it.
DROP_READ_ALL = ["setpriv", "--bounding-set=-dac_override,-dac_read_search", "--"]


@pytest.fixture
def unreadable_place():
    """A folder for files a test makes unreadable (mode 000) and reads through :func:`as_unprivileged`; removed after.
    Skips, saying why, where nothing can be run to which a file of mode 000 is unreadable: root without ``setpriv``
    to give up its reading capabilities."""
    import shutil
    import tempfile

    if os.geteuid() == 0 and shutil.which("setpriv") is None:
        pytest.skip("running as root, who reads files of mode 000, and no setpriv to give that up")
    place = Path(tempfile.mkdtemp(prefix="symfruit-unreadable-"))
    place.chmod(0o755)
    yield place
    for path in [place, *place.rglob("*")]:
        if not path.is_symlink():
            path.chmod(0o755)
    shutil.rmtree(place, ignore_errors=True)


def as_unprivileged(code: str) -> str:
    """Run ``code`` (Python) as a user to whom a file of mode 000 is unreadable, and return what it printed: root
    without its reading capabilities (:data:`DROP_READ_ALL`) when the tests run as root, else this user; HOME
    /nonexistent (as nobody's is), and the kernels' numpy twins (compiling them in a fresh process takes minutes)."""
    import subprocess
    import sys

    drop = DROP_READ_ALL if os.geteuid() == 0 else []
    env = {**os.environ, "HOME": "/nonexistent", "SYMFRUIT_KERNELS": "numpy",
           "PYTHONPATH": os.pathsep.join([str(Path(symfruit.__file__).resolve().parents[1]), str(ROOT)])}  # fmt: skip
    done = subprocess.run([*drop, sys.executable, "-W", "ignore", "-c", code], capture_output=True, text=True,
                          env=env, timeout=300, cwd="/")  # fmt: skip
    assert done.returncode == 0, done.stderr[-600:]
    return done.stdout.strip()


def refusal_unprivileged(call: str, *paths: Path) -> str:
    """The one-line refusal (a :class:`~symfruit.errors.SymfruitError`) of ``call`` (a Python expression, its
    imports before it: ``"from m import f; f(P0)"``, ``P0``... the ``paths`` made unreadable), read through
    :func:`as_unprivileged`; any other exception fails the test with its traceback."""
    for path in paths:
        path.chmod(0o000)
    setup = "".join(f"P{k} = {str(p)!r}; " for k, p in enumerate(paths))
    *imports, expr = call.split("; ")
    code = (f"{'; '.join(imports)}\nfrom symfruit.errors import SymfruitError\n{setup}\ntry:\n    {expr}\n"
            "except SymfruitError as exc:\n    print('refused:', exc)\nelse:\n    print('taken')")  # fmt: skip
    # e.g. "from m import f; r = f(P0); print(r)": the last part is tried, the ones before it run first
    return as_unprivileged(code)
