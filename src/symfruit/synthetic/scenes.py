"""Synthetic RGB-D frames of table-top strawberries, with the truth, for tests, the demo and evaluation.

A scene holds strawberries hanging from a gutter at 0.25-0.6 m (calyx up, tilted, some touching),
ripe ones red and unripe ones white or green (which a segmenter must ignore), a green calyx on each,
stems up to the gutter, leaves in front of some fruit, and a backdrop. It is rendered with the exact
z-buffer of :mod:`symfruit.synthetic.render`, shaded, and given the D435-like depth noise of the evaluation's
``camera`` protocol. ``truth`` lists every fruit's true box (the box of its whole surface).
"""

from __future__ import annotations

import colorsys
import contextlib
import os
import secrets
import shutil
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..core.box import Box
from ..core.camera import DEFAULT_CAMERA, Camera
from ..core.points import perpendicular_basis
from ..errors import OutputError
from ..io.atomic import atomic_write, folder_fd
from ..io.text import as_path
from .render import Photometric, SensorNoise, render
from .sensors import SENSOR_MODELS, SensorModel, apply_sensor
from .shapes import apple, leaf_outline, rotation, strawberry

__all__ = ["Scene", "SceneFruit", "make_photo", "make_scene", "make_tree_scene", "write_scenes"]


@dataclass(frozen=True)
class SceneFruit:
    """One fruit of a scene and its truth; ``visible``: the share of its silhouette the camera sees (its visible
    pixels over those of the fruit rendered alone), for the ripe fruit of scenes through a real camera model."""

    id: int
    ripe: bool
    kind: str
    box: Box
    mesh_index: int
    visible: float | None = None

    def to_dict(self) -> dict:
        seen = {} if self.visible is None else {"visible": round(self.visible, 4)}
        return {"id": self.id, "ripe": self.ripe, "kind": self.kind, "centre": self.box.centre.tolist(),
                **self.box.to_dict(), **seen}  # fmt: skip


@dataclass(frozen=True)
class Scene:
    """A rendered frame: colour (h, w, 3) uint8, depth (h, w) float metres (0 = no depth), the camera,
    the instance labels of the true fruit pixels (0 = none, k = fruit k), and the fruit; through a
    :class:`~symfruit.synthetic.sensors.SensorModel`, also the masks annotators would draw of the ripe fruit
    (overshooting, some over the leaf in front: :func:`symfruit.synthetic.sensors.annotate`)."""

    color: np.ndarray
    depth: np.ndarray
    camera: Camera
    labels: np.ndarray
    fruits: list[SceneFruit] = field(default_factory=list)
    masks: np.ndarray | None = None  # through a real camera model: the annotators' masks of the ripe fruit

    def truth(self) -> dict:
        """The ``truth.json`` layout: ripe and unripe fruit with their boxes, metres, camera frame."""
        return {"fruits": [f.to_dict() for f in self.fruits]}


def _cylinder(a: np.ndarray, b: np.ndarray, radius: float, n: int = 8) -> tuple[np.ndarray, np.ndarray]:
    (u,), (v,) = perpendicular_basis(((b - a) / np.linalg.norm(b - a))[None, :])
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    ring = radius * (np.cos(t)[:, None] * u + np.sin(t)[:, None] * v)
    vertices = np.vstack([a + ring, b + ring])
    j = np.arange(n)
    jn = (j + 1) % n
    faces = np.vstack([np.c_[j, jn, n + j], np.c_[jn, n + jn, n + j]])
    return vertices, faces


def _disc(centre: np.ndarray, normal: np.ndarray, radius: float, lobes: int = 0, n: int = 40) -> tuple:
    (u,), (v,) = perpendicular_basis((normal / np.linalg.norm(normal))[None, :])
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = radius * (1.0 if lobes == 0 else 0.55 + 0.45 * np.abs(np.cos(lobes * t / 2)))
    ring = centre + (r * np.cos(t))[:, None] * u + (r * np.sin(t))[:, None] * v
    vertices = np.vstack([centre, ring])
    faces = np.c_[np.zeros(n, int), 1 + np.arange(n), 1 + (np.arange(n) + 1) % n]
    return vertices, faces


def _leaf(centre: np.ndarray, length: float, spin: float, tilt: np.ndarray) -> tuple:
    outline = leaf_outline(length, 0.5 * length) @ rotation(0, 0, np.degrees(spin)).T @ tilt.T + centre
    vertices = np.vstack([centre, outline])
    faces = np.c_[np.zeros(40, int), 1 + np.arange(40), 1 + (np.arange(40) + 1) % 40]
    return vertices, faces


def _fruit_labels(
    ids: np.ndarray, meshes: list, fruits: list[SceneFruit], camera: Camera
) -> tuple[np.ndarray, np.ndarray, list[SceneFruit]]:
    """The fruit's visible labels in a rendering (``ids``: the mesh seen at each pixel), the ripe fruit's
    amodal ones (each ripe fruit rendered alone; the first fruit keeps a pixel two would share), and the fruit
    with the ripe ones' visible share (:attr:`SceneFruit.visible`)."""
    labels = np.zeros(ids.shape, np.int32)
    amodal = np.zeros(ids.shape, np.int32)
    out = []
    for f in fruits:
        seen = ids == f.mesh_index
        labels[seen] = f.id
        if f.ripe:
            vertices, faces = meshes[f.mesh_index]
            alone = render([(vertices, faces)], camera).ids == 0
            amodal[alone & (amodal == 0)] = f.id
            f = replace(f, visible=float(np.count_nonzero(seen)) / max(1, int(np.count_nonzero(alone))))
        out.append(f)
    return labels, amodal, out


def _sensor_surfaces(ids: np.ndarray, parts: dict[int, int]) -> np.ndarray:
    """The surface at each pixel for the camera model's multipath (``ids`` of
    :func:`~symfruit.synthetic.sensors.apply_sensor`): the rendered mesh ``ids`` with each fruit's own parts
    (``parts``: part mesh index -> its fruit's mesh index; a strawberry's calyx and stem, an apple's stem) given
    their fruit's index; -1 stays none.

    Time-of-flight multipath is light reaching a pixel's surface by way of a second lit surface that faces it, a
    concave corner of two surfaces (Tolgyessy et al. 2021, ``docs/sensors.md``). What a Lambertian patch ``dA``
    sends to a point is its radiance times the form factor ``cos t1 cos t2 / (pi r^2) dA`` (radiometry; Fuchs,
    Multipath interference compensation in time-of-flight camera images, ICPR 2010, models multipath so). A
    calyx's sepals lie on the skin (the disc here is 2 mm off the fruit's top, nearly tangent to it): between a
    surface and one lying on it the form factor is about zero (each ``cos`` is that of the angle the surface makes
    with the line between them). A stem of 1.2-1.5 mm radius is a few per cent of the half space a corner's second
    surface fills. Neither is the junction of two extended surfaces the model's 5 mm stands for; as separate meshes
    they pushed every berry back by 2-4 mm (``docs/azure48.md``: 549 of the 602 junction pixels beside fruit in
    the Azure Kinect strawberry frames of seeds 0-5)."""
    if not parts:
        return ids
    lut = np.arange(max(max(parts) + 1, int(ids.max(initial=-1)) + 1), dtype=np.int64)
    for part, fruit in parts.items():
        lut[part] = fruit
    return np.where(ids >= 0, lut[np.maximum(ids, 0)], ids)


def make_scene(
    seed: int = 0,
    *,
    n_ripe: int = 6,
    n_unripe: int = 2,
    n_leaves: int = 3,
    camera: Camera = DEFAULT_CAMERA,
    noise: SensorNoise | None = None,
    sensor: SensorModel | None = None,
) -> Scene:
    """Render one seeded scene of hanging strawberries.

    Parameters
    ----------
    seed : int
    n_ripe, n_unripe : int
        Red fruit to find, and white or green fruit to ignore.
    n_leaves : int
        Leaves placed in front of (some of) the fruit.
    camera : Camera
    noise : SensorNoise, optional
        Depth sensor model; default :class:`~symfruit.synthetic.render.SensorNoise`.
    sensor : SensorModel, optional
        A real camera instead (``camera`` and ``noise`` are then ignored): the frame at its colour
        resolution, the fruit at its working distances within 0.25-2 m (one cluster per frame, log-uniform
        depth), leaves and the backdrop 2-20 cm behind them, through
        :func:`symfruit.synthetic.sensors.apply_sensor`, with the annotators' masks in :attr:`Scene.masks`.
    """
    if sensor is not None:
        return _sensor_scene(seed, sensor, n_ripe=n_ripe, n_unripe=n_unripe, n_leaves=n_leaves)
    rng = np.random.default_rng(seed)
    noise = noise or SensorNoise()
    meshes: list[tuple[np.ndarray, np.ndarray]] = []
    colours: list[tuple[float, float, float]] = []  # HSV per mesh
    fruits: list[SceneFruit] = []
    placed: list[tuple[float, float, float]] = []  # projected (u, v, radius px)
    gutter_y = -0.12
    for k in range(n_ripe + n_unripe):
        ripe = k < n_ripe
        berry = strawberry(rng, length=rng.uniform(0.030, 0.048) if ripe else rng.uniform(0.022, 0.035))
        rot = rotation(rng.uniform(-30, 30), rng.uniform(-180, 180), rng.uniform(-30, 30))
        touching = placed and ripe and rng.random() < 0.3
        for _ in range(200):
            z = rng.uniform(0.25, 0.6)
            if touching:  # beside the previous fruit, at about its depth
                pu, pv, pr = placed[-1]
                ang = rng.uniform(0, 2 * np.pi)
                zr = fruits[-1].box.centre[2] + rng.uniform(-0.01, 0.01)
                radius_px = camera.fx * 0.5 * np.ptp(berry.vertices[:, 0]) / zr
                u = pu + np.cos(ang) * (pr + radius_px) * 0.95
                v = pv + np.sin(ang) * (pr + radius_px) * 0.95
                z = zr
            else:
                u = rng.uniform(70, camera.width - 70)
                v = rng.uniform(90, camera.height - 60)
            radius_px = camera.fx * 0.5 * np.ptp(berry.vertices, axis=0).max() / z
            if not (
                radius_px + 5 < u < camera.width - radius_px - 5 and radius_px + 5 < v < camera.height - radius_px - 5
            ):
                continue
            clear = all(np.hypot(u - pu, v - pv) > 0.9 * (pr + radius_px) for pu, pv, pr in placed)
            if clear or (touching and all(np.hypot(u - pu, v - pv) > 0.8 * (pr + radius_px) for pu, pv, pr in placed)):
                break
        centre = camera.deproject(np.array([u, v]), np.array(z))
        posed = berry.transformed(rot, centre)
        fruits.append(SceneFruit(k + 1, ripe, berry.kind, Box.from_points(posed.vertices), len(meshes)))
        placed.append((u, v, radius_px))
        meshes.append((posed.vertices, posed.faces))
        if ripe:
            colours.append((rng.uniform(-0.02, 0.015) % 1.0, rng.uniform(0.75, 0.92), rng.uniform(0.55, 0.85)))
        elif rng.random() < 0.5:
            colours.append((rng.uniform(0.12, 0.2), rng.uniform(0.35, 0.6), rng.uniform(0.55, 0.8)))  # green
        else:
            colours.append((rng.uniform(0.08, 0.14), rng.uniform(0.08, 0.2), rng.uniform(0.75, 0.9)))  # white
        # Calyx (green, star-shaped) at the top of the berry, and a stem up to the gutter.
        top = posed.vertices[np.argmin(posed.vertices @ (rot @ [0.0, 1.0, 0.0]))]
        up = rot @ np.array([0.0, -1.0, 0.0])
        width = np.ptp(berry.vertices[:, 0])
        meshes.append(_disc(top + 0.002 * up, up, 0.55 * width, lobes=5))
        colours.append((0.28, 0.7, 0.45))
        stem_top = np.array([top[0] + rng.uniform(-0.01, 0.01), gutter_y * top[2] / 0.4, top[2]])
        meshes.append(_cylinder(top, stem_top, 0.0012))
        colours.append((0.25, 0.55, 0.5))
    # leaves hang in front of ripe fruit; of a scene without any, in front of the unripe; without fruit, none
    ripe_boxes = [f.box for f in fruits if f.ripe] or [f.box for f in fruits]
    for _ in range(n_leaves if ripe_boxes else 0):
        target = ripe_boxes[int(rng.integers(len(ripe_boxes)))]
        centre = target.centre + np.array([rng.uniform(-1, 1) * target.size[0], rng.uniform(-1, 1) * target.size[1],
                                           -target.size[2] / 2 - rng.uniform(0.01, 0.04)])  # fmt: skip
        meshes.append(_leaf(centre, rng.uniform(0.04, 0.07), rng.uniform(0, np.pi),
                            rotation(rng.uniform(-35, 35), rng.uniform(-35, 35), 0)))  # fmt: skip
        colours.append((rng.uniform(0.22, 0.33), rng.uniform(0.55, 0.8), rng.uniform(0.3, 0.55)))
    # Gutter (dark box along the top) and backdrop (grey-green plane far behind).
    gutter = np.array([[-0.6, gutter_y * 1.6, 0.45], [0.6, gutter_y * 1.6, 0.45], [0.6, gutter_y * 0.55, 0.6],
                       [-0.6, gutter_y * 0.55, 0.6]])  # fmt: skip
    meshes.append((gutter, np.array([[0, 1, 2], [0, 2, 3]])))
    colours.append((0.0, 0.0, 0.18))
    back = np.array([[-1.5, -1.2, 1.3], [1.5, -1.2, 1.3], [1.5, 1.2, 1.1], [-1.5, 1.2, 1.1]])
    meshes.append((back, np.array([[0, 1, 2], [0, 2, 3]])))
    colours.append((0.2, 0.18, 0.42))

    shot = render(meshes, camera)
    depth, _ = noise.apply(shot, rng)
    depth[depth > 3.0] = 0.0
    color = _shade(shot, colours, rng)
    labels = np.zeros(shot.ids.shape, np.int32)
    for f in fruits:
        labels[shot.ids == f.mesh_index] = f.id
    return Scene(color=color, depth=depth.astype(np.float32), camera=camera, labels=labels, fruits=fruits)


def _sensor_scene(seed: int, sensor: SensorModel, *, n_ripe: int, n_unripe: int, n_leaves: int) -> Scene:
    """:func:`make_scene` through a real camera model (see there)."""
    rng = np.random.default_rng([seed, 18])
    camera = sensor.camera()
    near, far = max(0.25, sensor.distance[0]), min(2.0, sensor.distance[1])
    z0 = float(np.exp(rng.uniform(np.log(near), np.log(far))))
    # Where both cameras see: the depth camera may be narrower than the colour camera.
    half_u = min(0.39 * camera.width, 0.97 * np.tan(np.radians(sensor.depth_hfov) / 2) * camera.fx)
    half_v = min(0.34 * camera.height, 0.97 * np.tan(np.radians(sensor.depth_vfov) / 2) * camera.fy)
    meshes: list[tuple[np.ndarray, np.ndarray]] = []
    colours: list[tuple[float, float, float]] = []
    fruits: list[SceneFruit] = []
    placed: list[tuple[float, float, float]] = []
    parts: dict[int, int] = {}  # a fruit's calyx and stem: its own surface for multipath (_sensor_surfaces)
    gutter_y = -0.12 * z0 / 0.4
    for k in range(n_ripe + n_unripe):
        ripe = k < n_ripe
        berry = strawberry(rng, length=rng.uniform(0.030, 0.048) if ripe else rng.uniform(0.022, 0.035))
        rot = rotation(rng.uniform(-30, 30), rng.uniform(-180, 180), rng.uniform(-30, 30))
        for _ in range(200):
            z = float(np.clip(z0 + rng.uniform(-0.04, 0.04), near, far))
            u = camera.cx + rng.uniform(-half_u, half_u)
            v = camera.cy + rng.uniform(-half_v, half_v) * 0.8 + 0.1 * half_v
            radius_px = camera.fx * 0.5 * np.ptp(berry.vertices, axis=0).max() / z
            if all(np.hypot(u - pu, v - pv) > 0.9 * (pr + radius_px) for pu, pv, pr in placed):
                break
        centre = camera.deproject(np.array([u, v]), np.array(z))
        posed = berry.transformed(rot, centre)
        fruits.append(SceneFruit(k + 1, ripe, berry.kind, Box.from_points(posed.vertices), len(meshes)))
        placed.append((u, v, radius_px))
        meshes.append((posed.vertices, posed.faces))
        if ripe:
            colours.append((rng.uniform(-0.02, 0.015) % 1.0, rng.uniform(0.75, 0.92), rng.uniform(0.55, 0.85)))
        else:
            colours.append((rng.uniform(0.12, 0.2), rng.uniform(0.35, 0.6), rng.uniform(0.55, 0.8)))
        top = posed.vertices[np.argmin(posed.vertices @ (rot @ [0.0, 1.0, 0.0]))]
        up = rot @ np.array([0.0, -1.0, 0.0])
        parts[len(meshes)], parts[len(meshes) + 1] = len(meshes) - 1, len(meshes) - 1  # its calyx and stem
        meshes.append(_disc(top + 0.002 * up, up, 0.55 * np.ptp(berry.vertices[:, 0]), lobes=5))
        colours.append((0.28, 0.7, 0.45))
        meshes.append(_cylinder(top, np.array([top[0] + rng.uniform(-0.01, 0.01), gutter_y, top[2]]), 0.0012))
        colours.append((0.25, 0.55, 0.5))
    ripe_boxes = [f.box for f in fruits if f.ripe]
    for _ in range(n_leaves if ripe_boxes else 0):  # in front of some fruit
        target = ripe_boxes[int(rng.integers(len(ripe_boxes)))]
        centre = target.centre + np.array([rng.uniform(-1, 1) * target.size[0], rng.uniform(-1, 1) * target.size[1],
                                           -target.size[2] / 2 - rng.uniform(0.01, 0.04)])  # fmt: skip
        meshes.append(_leaf(centre, rng.uniform(0.04, 0.07), rng.uniform(0, np.pi),
                            rotation(rng.uniform(-35, 35), rng.uniform(-35, 35), 0)))  # fmt: skip
        colours.append((rng.uniform(0.22, 0.33), rng.uniform(0.55, 0.8), rng.uniform(0.3, 0.55)))
    back_z = max(f.box.max[2] for f in fruits)
    for f in fruits if sensor.clutter_leaves else []:  # behind and beside each fruit
        angle = rng.uniform(0, 2 * np.pi)
        offset = rng.uniform(0.3, 1.2) * f.box.size.max() * np.array([np.cos(angle), np.sin(angle), 0.0])
        centre = np.array([*(f.box.centre[:2] + offset[:2]), f.box.max[2] + rng.uniform(*sensor.clutter_gap)])
        meshes.append(_leaf(centre, rng.uniform(0.04, 0.08), rng.uniform(0, np.pi),
                            rotation(rng.uniform(-40, 40), rng.uniform(-40, 40), 0)))  # fmt: skip
        colours.append((rng.uniform(0.22, 0.33), rng.uniform(0.55, 0.8), rng.uniform(0.3, 0.55)))
    span = 3.0 * z0
    gutter = np.array([[-span, gutter_y * 1.4, z0 + 0.05], [span, gutter_y * 1.4, z0 + 0.05],
                       [span, gutter_y * 1.1, z0 + 0.2], [-span, gutter_y * 1.1, z0 + 0.2]])  # fmt: skip
    meshes.append((gutter, np.array([[0, 1, 2], [0, 2, 3]])))
    colours.append((0.0, 0.0, 0.18))
    bz = back_z + rng.uniform(*sensor.clutter_gap)
    back = np.array([[-span, -span, bz], [span, -span, bz], [span, span, bz + 0.1], [-span, span, bz + 0.1]])
    meshes.append((back, np.array([[0, 1, 2], [0, 2, 3]])))
    colours.append((0.2, 0.18, 0.42))

    shot = render(meshes, camera)
    labels, amodal, fruits = _fruit_labels(shot.ids, meshes, fruits, camera)
    ripe_labels = np.where(np.isin(labels, [f.id for f in fruits if f.ripe]), labels, 0)
    out = apply_sensor(sensor, shot.depth, _sensor_surfaces(shot.ids, parts), camera, rng, facing=shot.facing,
                       labels=ripe_labels, amodal=amodal)  # fmt: skip
    color = _shade(shot, colours, rng)
    return Scene(color=color, depth=out.depth, camera=camera, labels=labels, fruits=fruits, masks=out.labels)


def make_tree_scene(
    seed: int = 0,
    *,
    sensor: SensorModel | None = None,
    n_apples: int = 30,
    n_green: int = 4,
    n_leaves: int = 2500,
    distance: tuple[float, float] = (1.2, 2.0),
    photometric: Photometric | None = Photometric(),  # noqa: B008 (frozen)
) -> Scene:
    """Render one seeded frame of an apple tree's canopy, the way an orchard robot sees it (issue 18).

    Apples of 60-90 mm (:func:`~symfruit.synthetic.shapes.apple`) hang in a canopy slab whose front is
    ``distance`` (log-uniform) from the camera, among ``n_leaves`` leaves of 5-9 cm (some in front of the
    fruit), branches and a distant background; at 1.2-2 m a 1920x1080 camera sees them 40-70 px across.
    Most apples are red all over, the rest yellow-green with a red blush over 40-80 % of the skin (the
    blush faces a random side, so some show mostly green); ``n_green`` apples are green (unripe, not to be
    found). Shading follows the surface normal with a brighter sunlit side, plus pixel noise. The frame goes
    through ``sensor`` (default the Azure Kinect model: rim invalidation, flying pixels, registration,
    noise, multipath; :func:`~symfruit.synthetic.sensors.apply_sensor`). The colour image then goes through what a
    colour camera outdoors does (``photometric``, :class:`~symfruit.synthetic.render.Photometric`: exposure and
    white balance off per frame, leaves' hard shadows, highlights on the apples' waxy skin, apples' red from
    crimson to orange-red, shot noise, softness, MJPEG), drawn from an RNG of its own: depth, labels and truth are
    the same with it or without; ``photometric=None`` gives the colours of stops 30-44 bit for bit.

    Returns
    -------
    Scene
        ``labels`` holds every apple's visible pixels (the ripe ones are the truth), ``fruits`` the apples
        (``kind`` ``"apple"``), ``masks`` the annotators' masks of the ripe ones.
    """
    sensor = sensor or SENSOR_MODELS["azure-kinect"]
    rng = np.random.default_rng([seed, 19])
    photo_rng = np.random.default_rng([seed, 19, 45])  # the colour camera's own draws: the scene's stay as they were
    palette = photometric is not None and photometric.apple_palette
    camera = sensor.camera()
    z0 = float(np.exp(rng.uniform(np.log(distance[0]), np.log(distance[1]))))
    half_x = 0.5 * camera.width / camera.fx * z0
    half_y = 0.5 * camera.height / camera.fy * z0
    meshes: list[tuple[np.ndarray, np.ndarray]] = []
    colours: list[tuple[float, float, float]] = []
    fruits: list[SceneFruit] = []
    skins: list[
        tuple[int, np.ndarray, float, np.ndarray, np.ndarray, float]
    ] = []  # mesh, centre, r, base, blush, share
    spheres: list[tuple[np.ndarray, float]] = []
    parts: dict[int, int] = {}  # an apple's stem: its own surface for multipath (_sensor_surfaces)
    for k in range(n_apples + n_green):
        ripe = k < n_apples
        fruit = apple(rng)
        radius = 0.5 * float(np.ptp(fruit.vertices, axis=0).max())
        for _ in range(200):
            z = z0 + rng.uniform(-0.05, 0.35)
            centre = np.array(
                [rng.uniform(-0.95, 0.95) * half_x * z / z0, rng.uniform(-0.95, 0.95) * half_y * z / z0, z]
            )
            if all(np.linalg.norm(centre - c) > 1.05 * (radius + r) for c, r in spheres):
                break
        spheres.append((centre, radius))
        rot = rotation(rng.uniform(-40, 40), rng.uniform(-180, 180), rng.uniform(-40, 40))
        posed = fruit.transformed(rot, centre)
        fruits.append(SceneFruit(k + 1, ripe, "apple", Box.from_points(posed.vertices), len(meshes)))
        red = colorsys.hsv_to_rgb(rng.uniform(-0.03, 0.02) % 1.0, rng.uniform(0.65, 0.9), rng.uniform(0.45, 0.8))
        yellow = colorsys.hsv_to_rgb(rng.uniform(0.12, 0.2), rng.uniform(0.45, 0.7), rng.uniform(0.55, 0.8))
        if palette:  # dark crimson to orange-red (Photometric.apple_palette)
            hue = photo_rng.uniform(-13, 16) / 360 % 1.0
            red = colorsys.hsv_to_rgb(hue, photo_rng.uniform(0.6, 0.92), photo_rng.uniform(0.3, 0.8))
        if not ripe:
            skins.append((len(meshes), centre, radius, np.array(yellow), np.array(yellow), 0.0))
        elif rng.random() < 0.6:  # red all over, a paler streak side
            skins.append((len(meshes), centre, radius, np.array(red) * 0.8 + 0.2 * np.array(yellow), np.array(red),
                          rng.uniform(0.75, 0.95)))  # fmt: skip
        else:  # bicolour: a red blush over part of a yellow-green skin
            skins.append((len(meshes), centre, radius, np.array(yellow), np.array(red), rng.uniform(0.4, 0.8)))
        meshes.append((posed.vertices, posed.faces))
        colours.append((0.0, 0.0, 0.0))  # coloured per pixel below
        top = centre + rot @ np.array([0.0, -radius * 0.8, 0.0])
        parts[len(meshes)] = len(meshes) - 1  # its stem: the apple's own surface for multipath (_sensor_surfaces)
        meshes.append(_cylinder(top, top + np.array([rng.uniform(-0.01, 0.01), -0.025, 0.0]), 0.0015))
        colours.append((0.08, 0.5, 0.3))
    for _ in range(n_leaves):  # the canopy, from in front of the fruit to behind them
        z = z0 + rng.uniform(-0.2, 0.6)
        centre = np.array([rng.uniform(-1.1, 1.1) * half_x * z / z0, rng.uniform(-1.1, 1.1) * half_y * z / z0, z])
        meshes.append(_leaf(centre, rng.uniform(0.06, 0.10), rng.uniform(0, 2 * np.pi),
                            rotation(rng.uniform(-70, 70), rng.uniform(-70, 70), 0)))  # fmt: skip
        colours.append((rng.uniform(0.2, 0.36), rng.uniform(0.4, 0.85), rng.uniform(0.15, 0.6)))
    for _ in range(8):  # branches
        a = np.array([rng.uniform(-1, 1) * half_x, rng.uniform(-1, 1) * half_y, z0 + rng.uniform(0.0, 0.4)])
        b = a + rng.normal(size=3) * np.array([0.5, 0.5, 0.1]) * z0
        meshes.append(_cylinder(a, b, rng.uniform(0.008, 0.03)))
        colours.append((rng.uniform(0.05, 0.1), rng.uniform(0.3, 0.5), rng.uniform(0.2, 0.4)))
    span, bz = 4.0 * z0, z0 + rng.uniform(2.0, 4.0)  # the next row, grass and sky far behind
    back = np.array([[-span, -span, bz], [span, -span, bz], [span, span, bz], [-span, span, bz]])
    meshes.append((back, np.array([[0, 1, 2], [0, 2, 3]])))
    colours.append((rng.uniform(0.2, 0.3), rng.uniform(0.2, 0.4), rng.uniform(0.35, 0.55)))

    shot = render(meshes, camera)
    labels, amodal, fruits = _fruit_labels(shot.ids, meshes, fruits, camera)
    color = _shade(shot, colours, rng).astype(np.float64) / 255.0
    # apple skins: blush and base colour by the direction from the apple's centre, sunlit from the upper left
    sun = np.array([-0.5, -0.7, -0.5]) / np.linalg.norm([-0.5, -0.7, -0.5])
    yy, xx = np.mgrid[: camera.height, : camera.width]
    spec = np.zeros(shot.ids.shape)
    for index, centre, _radius, base, blush, share in skins:
        on = shot.ids == index
        if not on.any():
            continue
        z = shot.depth[on]
        p = np.c_[(xx[on] - camera.cx) * z / camera.fx, (yy[on] - camera.cy) * z / camera.fy, z]
        d = (p - centre) / np.linalg.norm(p - centre, axis=1, keepdims=True)
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        cut = 1.0 - 2.0 * share  # the cap d . axis > cut covers ``share`` of the sphere
        streak = 0.12 * np.sin(40.0 * np.arctan2(d[:, 1], d[:, 0]) + rng.uniform(0, 6.3))  # striped blush
        w = np.clip((d @ axis - cut) / 0.25 + 0.5 + streak, 0.0, 1.0) if share > 0 else np.zeros(len(d))
        skin = base[None] * (1 - w[:, None]) + blush[None] * w[:, None]
        light = 0.3 + 0.45 * shot.facing[on] + 0.35 * np.clip(-(d @ sun), 0, 1)
        color[on] = skin * light[:, None] + rng.normal(scale=0.015, size=(len(d), 3))
        if photometric is not None:  # Blinn-Phong: the half vector of the sun's direction and the camera's
            half = -sun[None] - p / np.linalg.norm(p, axis=1, keepdims=True)
            half /= np.linalg.norm(half, axis=1, keepdims=True)
            spec[on] = np.clip(np.einsum("ij,ij->i", d, half), 0, 1) ** photometric.shininess
    if photometric is None:
        color = (np.clip(color, 0, 1) * 255).astype(np.uint8)
    else:
        color = photometric.apply(color, spec, camera.fx / z0, photo_rng)
    ripe_labels = np.where(np.isin(labels, [f.id for f in fruits if f.ripe]), labels, 0)
    out = apply_sensor(sensor, shot.depth, _sensor_surfaces(shot.ids, parts), camera, rng, facing=shot.facing,
                       labels=ripe_labels, amodal=amodal)  # fmt: skip
    return Scene(color=color, depth=out.depth, camera=camera, labels=labels, fruits=fruits, masks=out.labels)


def _shade(shot, colours: list[tuple[float, float, float]], rng: np.random.Generator) -> np.ndarray:
    rgb = np.array([colorsys.hsv_to_rgb(*c) for c in colours])
    h, w = shot.ids.shape
    image = np.full((h, w, 3), 0.08)
    seen = shot.ids >= 0
    light = 0.35 + 0.65 * shot.facing[seen]
    image[seen] = rgb[shot.ids[seen]] * light[:, None]
    # Achenes: small pale specks on ripe fruit, and mild sensor noise everywhere.
    image += rng.normal(scale=0.015, size=image.shape)
    return (np.clip(image, 0, 1) * 255).astype(np.uint8)


def write_scenes(
    folder: str | Path, n: int, *, seed: int = 0, distinct: int | None = None, n_ripe: int = 6, n_unripe: int = 2,
    n_leaves: int = 3, sensor: SensorModel | None = None, tree: bool = False,
    photometric: Photometric | None = Photometric(),  # noqa: B008 (frozen)
) -> list[Path]:  # fmt: skip
    """Write ``n`` frame folders ``scene_00000`` ... (colour, depth, camera, truth) of seeds ``seed``,
    ``seed + 1``, ...; with ``distinct``, only that many are rendered and the rest repeat them as hard links
    (copies where links are impossible; either put in place atomically), so a long recording costs little time
    and disk. Through a real camera model (``sensor``) each folder also gets the annotators' ``masks.png``
    (which ``detect`` and ``evaluate --frames`` then use instead of the colour segmenter). ``tree``: apple-tree frames
    (:func:`make_tree_scene`, ``n_ripe`` apples and ``n_unripe`` green ones a frame, through ``sensor`` or the
    Azure Kinect model; ``n_leaves`` is not used; ``photometric`` their colour camera, None: the colours of stops
    30-44).

    Returns
    -------
    list of Path
        The frame folders, in order.
    """
    from ..io.outputs import OutputFolder

    folder = as_path(folder, "write_scenes: the output folder")  # '' was the working folder
    with OutputFolder(folder):  # locked while written; no link inside it followed
        return _write_scenes(folder, n, seed, distinct, n_ripe, n_unripe, n_leaves, sensor, tree, photometric)


def _write_scenes(
    folder: Path, n: int, seed: int, distinct: int | None, n_ripe: int, n_unripe: int, n_leaves: int,
    sensor: SensorModel | None, tree: bool, photometric: Photometric | None = Photometric(),  # noqa: B008 (frozen)
) -> list[Path]:  # fmt: skip
    from ..io.frames import write_frame

    unique = n if distinct is None else max(1, min(distinct, n))
    written: list[Path] = []
    for i in range(n):
        target = folder / f"scene_{i:05d}"
        if i < unique:
            if tree:
                scene = make_tree_scene(seed + i, sensor=sensor, n_apples=n_ripe, n_green=n_unripe,
                                        photometric=photometric)  # fmt: skip
            else:
                scene = make_scene(seed + i, n_ripe=n_ripe, n_unripe=n_unripe, n_leaves=n_leaves, sensor=sensor)
            written.append(write_frame(target, scene.color, scene.depth, scene.camera, truth=scene.truth(),
                                       masks=scene.masks))  # fmt: skip
            continue
        if target.is_symlink():
            raise OutputError(f"{target}: is a symbolic link; symfruit does not write through links inside {folder}")
        with folder_fd(target) as fd:  # made where missing; inside the output folder no link is followed
            for path in written[i % unique].iterdir():
                _repeat(path, target / path.name, fd)
        written.append(target)
    return written


def _repeat(source: Path, target: Path, fd: int) -> None:
    """Put ``target`` (in the folder open as ``fd``) in place as a hard link to ``source``, or where links are
    impossible as a copy, either one atomically: made under a temporary name and renamed over ``target``, so a
    file that is there (an earlier run's, maybe a link to a file elsewhere) is replaced, never written into."""
    tmp = f".{target.name[:200]}.{os.getpid()}-{secrets.token_hex(4)}.tmp"  # the name io.atomic gives its own
    try:
        os.link(source, tmp, dst_dir_fd=fd)
    except OSError:  # another file system, or none that links: a copy, written atomically
        with atomic_write(target, "wb") as out, open(source, "rb") as src:
            shutil.copyfileobj(src, out)
        return
    try:
        os.replace(tmp, target.name, src_dir_fd=fd, dst_dir_fd=fd)
    except OSError as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp, dir_fd=fd)
        raise OutputError(f"{target}: cannot write ({exc.strerror or exc})", exc.errno) from None


def make_photo(
    fruit: Sequence[tuple[float, float, float, tuple[int, int, int]]],
    *,
    shape: tuple[int, int] = (240, 320),
    seed: int = 0,
    background: tuple[int, int, int] = (225, 225, 222),
    calyx: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """A photo-like test image (no depth): shaded fruit discs on a light background, each with pale
    seeds, a white specular highlight and (``calyx``) a green calyx over its top, and mild noise.

    Parameters
    ----------
    fruit : sequence of (cx, cy, r, (R, G, B))
        Disc centres and radii (pixels) and colours; later discs lie in front of earlier ones.
    shape : (h, w)
    seed : int
        Seeds, highlights and noise are drawn from this seed.
    background : (R, G, B)
    calyx : bool

    Returns
    -------
    color : (h, w, 3) uint8
    truth : (n, h, w) bool
        Each fruit's outline as an annotator draws it: its disc, less the fruit in front of it.
    """
    rng = np.random.default_rng(seed)
    h, w = shape
    yy, xx = np.mgrid[:h, :w]
    img = np.empty((h, w, 3), np.float64)
    img[:] = background
    discs = []
    for cx, cy, r, colour in fruit:
        d2 = (xx - cx) ** 2 + (yy - cy) ** 2
        inside = d2 <= r * r
        shade = 0.6 + 0.4 * np.sqrt(np.clip(1 - d2 / (r * r), 0, 1))
        img[inside] = np.asarray(colour, float) * shade[inside, None]
        for _ in range(int(r * r / 40)):  # achenes: small pale dots
            a, rho = rng.uniform(0, 2 * np.pi), r * np.sqrt(rng.uniform(0, 0.8))
            x, y = int(cx + rho * np.cos(a)), int(cy + rho * np.sin(a))
            if 1 <= x < w and 1 <= y < h:
                img[y - 1 : y + 1, x - 1 : x + 1] = (230, 200, 90)
        hx, hy = cx - r / 3, cy - r / 3
        img[(xx - hx) ** 2 + (yy - hy) ** 2 <= (r / 5) ** 2] = (250, 250, 250)
        if calyx:  # a five-lobed green star over the top of the fruit
            ang = np.arctan2(yy - (cy - 0.8 * r), xx - cx)
            star = np.hypot(xx - cx, yy - (cy - 0.8 * r)) <= 0.35 * r * (0.6 + 0.4 * np.cos(5 * ang))
            img[star] = (70, 120, 40)
        discs.append(inside)
    img += rng.normal(scale=3, size=img.shape)
    truth = np.zeros((len(discs), h, w), bool)
    for k, disc in enumerate(discs):
        truth[k] = disc & ~np.any(discs[k + 1 :], axis=0) if k + 1 < len(discs) else disc
    return np.clip(img, 0, 255).astype(np.uint8), truth
