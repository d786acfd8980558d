"""Evaluation protocols: how a test instance (visible points + truth) is made from a fruit.

``paper``
    Algorithm 2 and section 4.1 of Ge et al., to the letter: 600 random surface points of a whole
    fruit, rotated about x from -45 to +45 degrees in 5-degree steps (19 poses), the paper's visibility
    rule (keep the points in front of the plane through the lowest- and highest-y points that contains
    the x direction), the fruit's box centre placed :data:`PAPER_DISTANCE` in front of the default
    camera. Truth: the box of the 600 points in the same pose (the paper's "3D position of randomly
    chosen points").
``camera``
    What a depth camera on a harvester sees: the fruit's mesh rendered with a z-buffer at the camera's
    resolution, in a random pose (:data:`POSES`), at a random distance within the sensor's working range,
    anywhere in the image where the whole fruit is in view, through a sensor model (:data:`SENSORS`), and
    optionally a leaf-like occluder in front hiding a set share of the fruit's silhouette. Truth: the box
    of the whole mesh in the same pose.

A fruit is a generated kind (:data:`symfruit.synthetic.shapes.FRUITS`) or a scan of a folder of meshes
(:func:`symfruit.synthetic.shapes.load_scans`, e.g. the YCB scans of ``examples/scans``).

Sensor models (``--sensor``):

``d435`` (default)
    A D435-like camera as the repository has always modelled it (:class:`~symfruit.synthetic.render.SensorNoise`
    defaults): axial noise 1 mm at 0.3 m growing with the square of the depth, 0.3 px lateral jitter, half
    of the silhouette's edge pixels and 60 % of grazing pixels dropped, 1 % random dropout; 0.25-0.60 m.
``heldback``
    The measurement of issue 11 (the held-back real scans): 640x480, ``fx = fy = 615``, axial noise of
    standard deviation ``0.01 z^2`` metres, 0.3 px lateral jitter, one point per fruit pixel, no dropout;
    0.30-0.50 m.
``azure-kinect``, ``realsense-l515``, ``realsense-d435``, ``realsense-d405``
    Real cameras (:data:`symfruit.synthetic.sensors.SENSOR_MODELS`, issue 18): the view is rendered at the camera's
    colour resolution (1920x1080 or 1280x720; a window around the fruit) with leaves and a background
    2-20 cm behind and beside the fruit, through :func:`symfruit.synthetic.sensors.apply_sensor` (rim invalidation
    or edge fattening, flying pixels, registration offset, multipath, noise and bias growing with
    distance), at the camera's working distances within 0.25-2 m. The fruit's points are what
    ``detect`` would take: :func:`symfruit.extract.extract` under the annotators' mask (which may
    overshoot the fruit or cover the leaf), with the occlusion information from the frame's depth.

Pose distributions (``--pose``):

``hanging`` (default)
    About x within +-45 deg, about y any angle, about z within +-45 deg, applied to the fruit in its own
    frame: a generated fruit hangs stem up (its stem end is at -y), a scan keeps the frame of its file
    (the YCB scans stand on a table, z up, so the camera looks at them from below or above).
``upright``
    As ``hanging``, but a scan is first stood up like a generated fruit (its file's +z turned to -y, up
    in the image); generated fruit are unchanged.
``uniform``
    A rotation drawn uniformly over all orientations (camera protocol only).

Instances are described by small :class:`Spec` tuples and built deterministically from them, so
that worker processes build their own and the same seed always gives the same instances.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from ..core.box import Box
from ..core.camera import DEFAULT_CAMERA, Camera
from ..synthetic.render import Rendering, SensorNoise, render
from ..synthetic.sensors import SENSOR_MODELS, SensorFrame, SensorModel, apply_sensor, checked_sensor_set, varied
from ..synthetic.shapes import FRUITS, Fruit, leaf_outline, load_scans, paper_visible, rotation, rotation_x

__all__ = ["PAPER_ANGLES", "PAPER_DISTANCE", "POSES", "SENSORS", "Instance", "Sensor", "Spec", "build", "specs"]

#: Distance of the fruit's centre from the camera in the ``paper`` protocol (metres). The paper does
#: not give one (its rule needs none); 0.3 m is a typical harvester working distance.
PAPER_DISTANCE = 0.30
#: Poses of the ``paper`` protocol, degrees about x.
PAPER_ANGLES = tuple(range(-45, 50, 5))
#: Surface points sampled for the truth surface (Chamfer, F1) in the ``camera`` protocol.
TRUTH_POINTS = 5000
_KIND_IDS = {kind: i for i, kind in enumerate(FRUITS)}


@dataclass(frozen=True)
class Sensor:
    """A camera setup of the ``camera`` protocol: the depth sensor's model and its working distances.

    Attributes
    ----------
    noise : SensorNoise
    distance : (float, float), metres
        The fruit's box centre is drawn uniformly this far from the camera.
    """

    noise: SensorNoise
    distance: tuple[float, float]


#: The sensor models of the ``camera`` protocol (see the module docstring).
SENSORS: dict[str, Sensor] = {
    "d435": Sensor(SensorNoise(), (0.25, 0.60)),
    "heldback": Sensor(
        SensorNoise(axial_at_03=0.0009, edge_dropout=0.0, grazing_dropout=0.0, dropout=0.0), (0.30, 0.50)
    ),
}
#: The pose distributions (see the module docstring).
POSES = ("hanging", "upright", "uniform")
#: A scan stood up: its file's +z (YCB: up) becomes the optical frame's -y (up in the image).
UPRIGHT = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


@dataclass(frozen=True)
class Spec:
    """What identifies one instance: build it with :func:`build`."""

    protocol: str
    fruit: str  # a kind of FRUITS, or a folder of scans
    index: int  # which fruit
    pose: int  # which pose (paper: index into PAPER_ANGLES; camera: the view number)
    occlusion: float = 0.0  # target hidden share of the silhouette (camera protocol)
    seed: int = 0
    sensor: str = "d435"  # a key of SENSORS (camera protocol)
    poses: str = "hanging"  # a pose distribution of POSES
    #: a real camera model's artefacts changed (``(name, value)`` pairs, :func:`symfruit.synthetic.sensors.varied`)
    sensor_set: tuple[tuple[str, float], ...] = ()

    def __post_init__(self) -> None:
        if self.sensor not in SENSORS and self.sensor not in SENSOR_MODELS:
            raise ValueError(f"unknown sensor {self.sensor!r}; known: {', '.join([*SENSORS, *SENSOR_MODELS])}")
        if self.sensor_set:
            if self.sensor not in SENSOR_MODELS:
                raise ValueError(f"sensor_set changes a real camera model ({', '.join(SENSOR_MODELS)}), not "
                                 f"{self.sensor!r}")  # fmt: skip
            object.__setattr__(self, "sensor_set", checked_sensor_set(self.sensor_set))
        if self.poses not in POSES:
            raise ValueError(f"unknown pose distribution {self.poses!r}; known: {', '.join(POSES)}")
        if self.protocol == "paper" and self.poses == "uniform":
            raise ValueError("the paper protocol has its own 19 poses; --pose uniform is for the camera protocol")


@dataclass(frozen=True)
class Instance:
    """A visible view with its truth; a camera view with an occluder keeps its rendered ``depth`` image
    (metres, 0: none) and the fruit's ``mask`` (its visible pixels), from which the evaluation makes the
    occlusion information a robot's ``detect`` would have (:func:`symfruit.occlusion.fruit_occlusion`).
    A view through a real camera model (``extract``) keeps the camera's depth and the annotators' mask
    (in the ``camera`` window around the fruit); ``visible`` is then every mask pixel with depth, and the
    runner extracts the fruit's points from them as ``detect`` does."""

    spec: Spec
    kind: str
    visible: np.ndarray
    truth_box: Box
    truth_surface: np.ndarray
    camera: Camera
    angles: tuple[float, float, float]
    distance: float
    hidden: float = 0.0
    extras: dict = field(default_factory=dict)
    depth: np.ndarray | None = None
    mask: np.ndarray | None = None
    extract: bool = False  # the runner extracts the points from ``mask`` and ``depth`` as ``detect`` does


def specs(
    protocol: str, fruit: str, *, n: int, seed: int = 0, angles: tuple[int, ...] = PAPER_ANGLES,
    occlusions: tuple[float, ...] = (0.0,), sensor: str = "d435", poses: str = "hanging", views: int = 1,
    sensor_set: tuple[tuple[str, float], ...] = (),
) -> list[Spec]:  # fmt: skip
    """All instance specs of a protocol: ``n`` fruits x the 19 poses (paper) or ``n`` views per
    occlusion level (camera; the views of a scan folder go round its scans, and a generated kind's go
    ``views`` to a fruit: ``n // views`` fruits, each seen from ``views`` poses and distances, so that
    confidence can be ranked among one fruit's views as on the scans); for a scan folder, the paper
    protocol's ``n`` is capped by the number of scans. ``sensor_set``: the camera protocol's real camera model with
    these artefacts changed (:func:`symfruit.synthetic.sensors.varied`)."""
    if not 1 <= views <= 100_000:
        raise ValueError(f"views must be 1-100000 views a fruit, got {views}")
    if protocol == "paper":
        if fruit not in FRUITS:
            n = min(n, len(_scans(fruit)))
        return [Spec("paper", fruit, i, PAPER_ANGLES.index(a), 0.0, seed, sensor, poses) for i in range(n)
                for a in angles]  # fmt: skip
    if protocol == "camera":
        count = len(_scans(fruit)) if fruit not in FRUITS else None
        return [Spec("camera", fruit, i % count if count else i // views, i, occ, seed, sensor, poses, sensor_set)
                for occ in occlusions for i in range(n)]  # fmt: skip
    raise ValueError(f"unknown protocol {protocol!r}; use paper or camera")


def _scans(folder: str) -> tuple[Fruit, ...]:
    return _read_scans(folder)[0]


def skipped_scans(folder: str) -> dict[str, str]:
    """The scans of the scan folder ``folder`` left out of its evaluation as unreadable (path: reason); the
    others are evaluated, so one broken file does not stop a folder's evaluation (as a bad frame does not stop
    ``detect``)."""
    return dict(_read_scans(folder)[1])


@functools.lru_cache(maxsize=4)
def _read_scans(folder: str) -> tuple[tuple[Fruit, ...], tuple[tuple[str, str], ...]]:
    failed: dict[str, str] = {}
    return tuple(load_scans(folder, failed=failed)), tuple(failed.items())


def _fruit(spec: Spec) -> Fruit:
    if spec.fruit in FRUITS:
        rng = np.random.default_rng([spec.seed, _KIND_IDS[spec.fruit], spec.index])
        return FRUITS[spec.fruit](rng)
    scan = _scans(spec.fruit)[spec.index]
    return scan.transformed(UPRIGHT, np.zeros(3)) if spec.poses == "upright" else scan


def _uniform_rotation(rng: np.random.Generator) -> np.ndarray:
    """(3, 3) rotation drawn uniformly from SO(3): a normalised Gaussian quaternion."""
    q = rng.normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip


def build(spec: Spec, camera: Camera = DEFAULT_CAMERA) -> Instance:
    """Make the instance a spec describes."""
    if spec.protocol == "paper":
        return _paper(spec)
    return _camera(spec, camera)


def _paper(spec: Spec) -> Instance:
    fruit = _fruit(spec)
    rng = np.random.default_rng([spec.seed, 1000 + _KIND_IDS.get(spec.fruit, 99), spec.index])
    points = fruit.sample(600, rng)  # the same 600 points in every pose of this fruit
    angle = float(PAPER_ANGLES[spec.pose])
    posed = points @ rotation_x(angle).T
    truth = Box.from_points(posed)
    posed = posed - truth.centre + [0.0, 0.0, PAPER_DISTANCE]
    visible = posed[paper_visible(posed)]
    return Instance(
        spec=spec, kind=fruit.kind, visible=visible, truth_box=Box.from_points(posed), truth_surface=posed,
        camera=DEFAULT_CAMERA, angles=(angle, 0.0, 0.0), distance=PAPER_DISTANCE,
    )  # fmt: skip


def _camera(spec: Spec, camera: Camera) -> Instance:
    if spec.sensor in SENSOR_MODELS:
        return _real_camera(spec, varied(SENSOR_MODELS[spec.sensor], spec.sensor_set))
    fruit = _fruit(spec)
    sensor = SENSORS[spec.sensor]
    noise = sensor.noise
    rng = np.random.default_rng([spec.seed, 2000 + _KIND_IDS.get(spec.fruit, 99), spec.index, spec.pose,
                                 round(spec.occlusion * 1000)])  # fmt: skip
    rot, angles = _pose(spec, rng)
    distance = float(rng.uniform(*sensor.distance))
    radius = float(np.linalg.norm(fruit.vertices, axis=1).max())
    # Anywhere in the image where the whole fruit stays in view (a 10-pixel margin).
    half_u = (camera.width / 2 - 10) * distance / camera.fx - radius
    half_v = (camera.height / 2 - 10) * distance / camera.fy - radius
    centre = np.array([
        (camera.width / 2 - camera.cx) * distance / camera.fx + rng.uniform(-1, 1) * max(half_u, 0.0),
        (camera.height / 2 - camera.cy) * distance / camera.fy + rng.uniform(-1, 1) * max(half_v, 0.0),
        distance,
    ])  # fmt: skip
    posed = fruit.transformed(rot, centre)
    meshes = [(posed.vertices, posed.faces)]
    leaf = None
    if spec.occlusion > 0:
        leaf = _leaf(posed, camera, spec.occlusion, rng)
        meshes.append(leaf)
    shot = render(meshes, camera)
    depth, jitter = noise.apply(shot, rng)
    fruit_px = (shot.ids == 0) & (depth > 0)
    rows, cols = np.nonzero(fruit_px)
    uv = np.c_[cols, rows] + jitter[rows, cols]
    visible = camera.deproject(uv, depth[rows, cols])
    silhouette = render([(posed.vertices, posed.faces)], camera).ids == 0 if leaf is not None else shot.ids == 0
    hidden = 1.0 - (shot.ids == 0).sum() / max(silhouette.sum(), 1)
    surface = posed.sample(TRUTH_POINTS, np.random.default_rng([spec.seed, 3000, spec.index]))
    truth = Box.from_points(posed.vertices if posed.points is None else posed.points)
    return Instance(
        spec=spec, kind=fruit.kind, visible=visible, truth_box=truth, truth_surface=surface, camera=camera,
        angles=angles, distance=distance, hidden=float(hidden), depth=depth if leaf is not None else None,
        mask=shot.ids == 0 if leaf is not None else None,
    )  # fmt: skip


def _pose(spec: Spec, rng: np.random.Generator) -> tuple[np.ndarray, tuple[float, float, float]]:
    """A view's rotation and its hanging-pose angles (degrees; NaN for ``poses == "uniform"``), drawn from ``rng``."""
    if spec.poses == "uniform":
        return _uniform_rotation(rng), (float("nan"),) * 3
    angles = (float(rng.uniform(-45, 45)), float(rng.uniform(-180, 180)), float(rng.uniform(-45, 45)))
    return rotation(*angles), angles


@dataclass(frozen=True)
class RealView:
    """What :func:`_real_camera` renders for one view, before it is made an :class:`Instance`: the posed fruit, the
    window's camera, the fruit's pixels alone (``alone``) and as seen among the leaf and clutter (``seen``), the
    render itself (``shot``: its ``depth`` is the scene's clean depth, ``ids`` which mesh each pixel shows) and what
    the camera model made of it (``out``: depth, labels and the registration ``shift`` it drew). The evaluation's
    diagnostics (docs/occl42.py) rebuild a view from it with the render's truth."""

    fruit: Fruit
    posed: Fruit
    camera: Camera
    angles: tuple[float, float, float]
    distance: float
    shot: Rendering
    alone: Rendering
    out: SensorFrame


def real_view(spec: Spec, model: SensorModel) -> RealView:
    """A view through a real camera model: the fruit, an optional occluding leaf, clutter behind and beside,
    rendered in a window of the camera's colour image around the fruit (:class:`RealView`)."""
    fruit = _fruit(spec)
    full = model.camera()
    rng = np.random.default_rng([spec.seed, 4000 + _KIND_IDS.get(spec.fruit, 99), spec.index, spec.pose,
                                 round(spec.occlusion * 1000), list(SENSOR_MODELS).index(model.name)])  # fmt: skip
    rot, angles = _pose(spec, rng)
    distance = float(rng.uniform(*model.distance))
    radius = float(np.linalg.norm(fruit.vertices, axis=1).max())
    # Anywhere the whole fruit is in both cameras' view (the Azure Kinect's depth is narrower than its colour).
    tan_u = min((full.width / 2 - 10) / full.fx, np.tan(np.radians(model.depth_hfov) / 2) * 0.97)
    tan_v = min((full.height / 2 - 10) / full.fy, np.tan(np.radians(model.depth_vfov) / 2) * 0.97)
    half_u, half_v = max(tan_u * distance - radius, 0.0), max(tan_v * distance - radius, 0.0)
    centre = np.array([rng.uniform(-1, 1) * half_u, rng.uniform(-1, 1) * half_v, distance])
    posed = fruit.transformed(rot, centre)
    # The window: the fruit and what lies around it within about its own size (the rest of the frame does not
    # reach its mask, extraction or occlusion information).
    u, v = full.project(centre[None])[0]
    reach = 1.8 * full.fx * radius / distance + 24
    c0, c1 = max(int(u - reach), 0), min(int(u + reach) + 1, full.width)
    r0, r1 = max(int(v - reach), 0), min(int(v + reach) + 1, full.height)
    cam = Camera(fx=full.fx, fy=full.fy, cx=full.cx - c0, cy=full.cy - r0, width=c1 - c0, height=r1 - r0)
    meshes = [(posed.vertices, posed.faces)]
    if spec.occlusion > 0:
        meshes.append(_leaf(posed, cam, spec.occlusion, rng))
    meshes += _clutter(posed, model, rng)
    shot = render(meshes, cam)
    alone = render([(posed.vertices, posed.faces)], cam)
    out = apply_sensor(model, shot.depth, shot.ids, cam, rng, facing=shot.facing,
                       labels=(shot.ids == 0).astype(np.int32), amodal=(alone.ids == 0).astype(np.int32))  # fmt: skip
    return RealView(fruit, posed, cam, angles, distance, shot, alone, out)


def _real_camera(spec: Spec, model: SensorModel) -> Instance:
    """:func:`real_view`'s view as the evaluation's instance: the fruit's points extracted from the camera model's
    depth under its annotators' mask (``extract``), the truth from the posed fruit."""
    view = real_view(spec, model)
    fruit, posed, cam, out = view.fruit, view.posed, view.camera, view.out
    seen, alone = view.shot.ids == 0, view.alone.ids == 0
    mask = np.asarray(out.labels) == 1
    rows, cols = np.nonzero(mask & (out.depth > 0))
    # Pixel centres: the lateral jitter is in ``out.depth`` already (as in a camera's image; the runner extracts
    # from it as ``detect`` does), unlike the heldback branch's noise, which leaves it to the de-projection.
    visible = cam.deproject(np.c_[cols, rows].astype(np.float64), out.depth[rows, cols].astype(np.float64))
    surface = posed.sample(TRUTH_POINTS, np.random.default_rng([spec.seed, 3000, spec.index]))
    truth = Box.from_points(posed.vertices if posed.points is None else posed.points)
    return Instance(
        spec=spec, kind=fruit.kind, visible=visible, truth_box=truth, truth_surface=surface, camera=cam,
        angles=view.angles, distance=view.distance, hidden=float(1.0 - seen.sum() / max(alone.sum(), 1)),
        depth=out.depth, mask=mask, extract=True,
    )  # fmt: skip


def _clutter(fruit: Fruit, model: SensorModel, rng: np.random.Generator) -> list[tuple[np.ndarray, np.ndarray]]:
    """Leaves behind and beside the fruit and a background plane, ``model.clutter_gap`` behind its back
    (issue 18: leaves, branches and background 2-20 cm behind and beside the fruit)."""
    lo, hi = fruit.vertices.min(axis=0), fruit.vertices.max(axis=0)
    centre, extent = (lo + hi) / 2, float((hi - lo).max())
    meshes = []
    for _ in range(model.clutter_leaves):
        angle = rng.uniform(0, 2 * np.pi)
        offset = rng.uniform(0.3, 1.2) * extent * np.array([np.cos(angle), np.sin(angle), 0.0])
        z = hi[2] + rng.uniform(*model.clutter_gap) * rng.uniform(0.1, 1.0)
        length = extent * rng.uniform(1.0, 2.0)
        tilt = rotation(rng.uniform(-40, 40), rng.uniform(-40, 40), 0.0)
        ring = leaf_outline(length, length * rng.uniform(0.4, 0.6), 40) @ rotation(0, 0, rng.uniform(0, 180)).T
        ring = ring @ tilt.T + np.array([centre[0] + offset[0], centre[1] + offset[1], z])
        vertices = np.vstack([ring.mean(axis=0, keepdims=True), ring])
        n = len(ring)
        meshes.append((vertices, np.c_[np.zeros(n, int), 1 + np.arange(n), 1 + (np.arange(n) + 1) % n]))
    z_back = hi[2] + rng.uniform(*model.clutter_gap)
    side = 2.0 * z_back  # far wider than any window
    back = np.array([[-side, -side, 0.0], [side, -side, 0.0], [side, side, 0.0], [-side, side, 0.0]])
    back = back @ rotation(rng.uniform(-20, 20), rng.uniform(-20, 20), 0.0).T + [centre[0], centre[1], z_back]
    meshes.append((back, np.array([[0, 1, 2], [0, 2, 3]])))
    return meshes


def _leaf(fruit: Fruit, camera: Camera, share: float, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A flat, pointed-oval leaf between the camera and the fruit hiding about ``share`` of its silhouette.

    The leaf lies 5-30 mm in front of the fruit's nearest point, tilted up to 30 degrees; its size is
    drawn relative to the fruit and its offset across the fruit is solved so that the hidden share of
    the fruit's silhouette (the projected leaf polygon over the fruit's pixels) matches ``share``.
    """
    rows, cols = np.nonzero(render([(fruit.vertices, fruit.faces)], camera).ids == 0)
    extent = float(np.ptp(fruit.vertices, axis=0).max())
    length = extent * rng.uniform(1.2, 2.0)
    width = length * rng.uniform(0.4, 0.6)
    z = float(fruit.vertices[:, 2].min()) - rng.uniform(0.005, 0.03)
    spin = rng.uniform(0, np.pi)
    direction = rng.uniform(0, 2 * np.pi)
    tilt = rotation(rng.uniform(-30, 30), rng.uniform(-30, 30), 0.0)
    outline = leaf_outline(length, width, 48) @ rotation(0, 0, np.degrees(spin)).T @ tilt.T
    centre_fruit = np.array([np.mean(cols), np.mean(rows)])

    def place(offset: float) -> np.ndarray:
        shift_px = centre_fruit + offset * np.array([np.cos(direction), np.sin(direction)])
        centre = camera.deproject(shift_px, np.array(z))
        return outline + centre

    def hidden(offset: float) -> float:
        poly = camera.project(place(offset))
        return float(_inside(poly, np.c_[cols, rows]).mean())

    lo, hi = 0.0, 3.0 * max(np.ptp(cols), np.ptp(rows)) + 1.0
    if hidden(lo) < share:  # even centred the leaf hides too little: scale it up
        scale = 1.0
        while hidden(lo) < share and scale < 8:
            outline = outline * 1.25
            scale *= 1.25
    for _ in range(30):
        mid = (lo + hi) / 2.0
        if hidden(mid) > share:
            lo = mid
        else:
            hi = mid
    ring = place((lo + hi) / 2.0)
    vertices = np.vstack([ring.mean(axis=0, keepdims=True), ring])
    n = len(ring)
    faces = np.c_[np.zeros(n, int), 1 + np.arange(n), 1 + (np.arange(n) + 1) % n]
    return vertices, faces


def _inside(poly: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Even-odd point-in-polygon test, vectorised over points; (n,) bool."""
    x, y = pts[:, 0][:, None], pts[:, 1][:, None]
    x0, y0 = poly[:, 0][None, :], poly[:, 1][None, :]
    x1, y1 = np.roll(poly[:, 0], -1)[None, :], np.roll(poly[:, 1], -1)[None, :]
    crosses = ((y0 > y) != (y1 > y)) & (x < (x1 - x0) * (y - y0) / np.where(y1 == y0, 1e-12, y1 - y0) + x0)
    return crosses.sum(axis=1) % 2 == 1
