"""A small z-buffer renderer and an RGB-D sensor model, for synthetic views and scenes.

``render`` rasterises triangle meshes exactly (the depth of each pixel is where its ray meets the
triangle's plane); ``SensorNoise`` turns the ideal depth into what a D435-like camera returns.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.camera import Camera

__all__ = ["Photometric", "Rendering", "SensorNoise", "render"]


@dataclass(frozen=True)
class Rendering:
    """An ideal depth image of some meshes.

    Attributes
    ----------
    depth : (h, w) float, metres; ``inf`` where nothing was hit
    ids : (h, w) int; index of the mesh seen at each pixel, -1 for background
    facing : (h, w) float; ``|cos|`` of the angle between the pixel's ray and the surface normal
        (small at grazing angles, as near a fruit's silhouette)
    """

    depth: np.ndarray
    ids: np.ndarray
    facing: np.ndarray


def render(meshes: list[tuple[np.ndarray, np.ndarray]], camera: Camera, *, max_candidates: int = 1 << 21) -> Rendering:
    """Render triangle meshes with a z-buffer.

    Parameters
    ----------
    meshes : list of (vertices (v, 3) float, faces (f, 3) int)
        In the camera optical frame, metres; triangles with a vertex at ``z <= 1 mm`` are skipped.
    camera : Camera
    max_candidates : int
        Pixel candidates tested per batch of triangles (bounds memory).

    Returns
    -------
    Rendering
    """
    h, w = camera.height, camera.width
    tris: list[np.ndarray] = []
    owners: list[np.ndarray] = []
    for k, (vertices, faces) in enumerate(meshes):
        if len(faces):
            tris.append(np.asarray(vertices, dtype=np.float64)[np.asarray(faces)])
            owners.append(np.full(len(faces), k))
    zbuf = np.full(h * w, np.inf)
    ids = np.full(h * w, -1)
    facing = np.zeros(h * w)
    if not tris:
        return Rendering(zbuf.reshape(h, w), ids.reshape(h, w), facing.reshape(h, w))
    tri = np.concatenate(tris)
    owner = np.concatenate(owners)
    keep = (tri[:, :, 2] > 1e-3).all(axis=1)
    tri, owner = tri[keep], owner[keep]
    uv = camera.project(tri)  # (t, 3, 2)
    lo = np.ceil(uv.min(axis=1) - 1e-9).astype(np.int64)
    hi = np.floor(uv.max(axis=1) + 1e-9).astype(np.int64)
    lo = np.maximum(lo, 0)
    hi = np.minimum(hi, [w - 1, h - 1])
    size = hi - lo + 1
    ok = (size > 0).all(axis=1)
    tri, owner, uv, lo, size = tri[ok], owner[ok], uv[ok], lo[ok], size[ok]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(normal, axis=1)
    good = norm > 0
    tri, owner, uv, lo, size, normal = tri[good], owner[good], uv[good], lo[good], size[good], normal[good]
    normal = normal / np.linalg.norm(normal, axis=1, keepdims=True)
    offset = np.einsum("ti,ti->t", normal, tri[:, 0])

    # Batch triangles by the side of their pixel box so the candidate grids stay small.
    sides = size.max(axis=1)
    cand_pix: list[np.ndarray] = []
    cand_z: list[np.ndarray] = []
    cand_t: list[np.ndarray] = []
    for side in np.unique(sides):
        group = np.flatnonzero(sides == side)
        per_batch = max(1, max_candidates // int(side * side))
        for first in range(0, len(group), per_batch):
            idx = group[first : first + per_batch]
            _candidates(idx, int(side), lo, size, uv, normal, offset, camera, w, cand_pix, cand_z, cand_t)
    if not cand_pix:
        return Rendering(zbuf.reshape(h, w), ids.reshape(h, w), facing.reshape(h, w))
    pix, z, t = np.concatenate(cand_pix), np.concatenate(cand_z), np.concatenate(cand_t)
    np.minimum.at(zbuf, pix, z)
    win = z <= zbuf[pix]
    pix, t = pix[win], t[win]
    ids[pix] = owner[t]
    u, v = pix % w, pix // w
    ray = camera.rays(u, v)
    ray /= np.linalg.norm(ray, axis=1, keepdims=True)
    facing[pix] = np.abs(np.einsum("ti,ti->t", normal[t], ray))
    return Rendering(zbuf.reshape(h, w), ids.reshape(h, w), facing.reshape(h, w))


def _candidates(idx, side, lo, size, uv, normal, offset, camera, w, cand_pix, cand_z, cand_t) -> None:
    """Pixels covered by triangles ``idx`` (boxes up to ``side`` pixels) and their exact depths.

    Each triangle's candidates are the ``side x side`` pixels from its box's corner, ``(t, dv, du)``. An edge
    function ``(q - p) x (pixel - p)`` is a product depending on the row alone minus one depending on the column
    alone: each is computed once per row or column and the two broadcast, the same floating-point operations on
    the same numbers as per pixel."""
    n, step = len(idx), np.arange(side)
    pu = lo[idx, 0, None] + step  # (n, side): the columns of each box
    pv = lo[idx, 1, None] + step  # (n, side): the rows
    a, b, c = uv[idx, 0], uv[idx, 1], uv[idx, 2]

    def edge(p: np.ndarray, q: np.ndarray) -> np.ndarray:
        rows = (q[:, 0, None] - p[:, 0, None]) * (pv - p[:, 1, None])
        cols = (q[:, 1, None] - p[:, 1, None]) * (pu - p[:, 0, None])
        return (rows[:, :, None] - cols[:, None, :]).reshape(n, side * side)

    e0, e1, e2 = edge(a, b), edge(b, c), edge(c, a)
    inside = ((step < size[idx, 1, None])[:, :, None] & (step < size[idx, 0, None])[:, None, :]).reshape(n, -1)
    # Inside: all three edge functions >= 0 or all <= 0, with a small tolerance so that pixels exactly on an edge
    # shared by two triangles are not lost (the least >= -eps or the largest <= eps; NaN is neither, as before).
    eps = 1e-6
    inside &= (np.minimum(np.minimum(e0, e1), e2) >= -eps) | (np.maximum(np.maximum(e0, e1), e2) <= eps)
    t_i, k = np.nonzero(inside)
    if len(t_i) == 0:
        return
    u, v = pu[t_i, k % side], pv[t_i, k // side]
    tt = idx[t_i]
    ray = camera.rays(u, v)
    denom = np.einsum("ti,ti->t", normal[tt], ray)
    with np.errstate(divide="ignore", invalid="ignore"):
        z = offset[tt] / denom
    valid = np.isfinite(z) & (z > 0)
    cand_pix.append((v * w + u)[valid])
    cand_z.append(z[valid])
    cand_t.append(tt[valid])


@dataclass(frozen=True)
class SensorNoise:
    """A D435-like depth sensor.

    Attributes
    ----------
    axial_at_03 : float, metres
        Standard deviation of the depth noise at 0.3 m; it grows with the square of the distance
        (1 mm at 0.3 m gives 4 mm at 0.6 m, in line with the D435's published RMS error).
    lateral_px : float, pixels
        Standard deviation of the lateral jitter of each de-projected pixel.
    edge_dropout : float
        Probability that a pixel on an object's silhouette returns no depth.
    grazing_dropout : float
        Probability that a pixel seen at a grazing angle (``facing < grazing``) returns no depth.
    grazing : float
    dropout : float
        Probability that any pixel returns no depth.
    """

    axial_at_03: float = 0.001
    lateral_px: float = 0.3
    edge_dropout: float = 0.5
    grazing_dropout: float = 0.6
    grazing: float = 0.25
    dropout: float = 0.01

    def sigma(self, z: np.ndarray) -> np.ndarray:
        """Axial noise standard deviation at depth ``z`` (metres)."""
        return self.axial_at_03 * (np.asarray(z) / 0.3) ** 2

    def apply(self, rendering: Rendering, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """Noisy depth (0 where no depth returned) and the sub-pixel jitter ``(h, w, 2)`` of each pixel."""
        depth = rendering.depth.copy()
        seen = np.isfinite(depth)
        ids = rendering.ids
        edge = np.zeros_like(seen)
        for axis in (0, 1):
            for step in (1, -1):
                edge |= seen & (np.roll(ids, step, axis=axis) != ids)
        drop = rng.random(depth.shape) < self.dropout
        drop |= edge & (rng.random(depth.shape) < self.edge_dropout)
        drop |= seen & (rendering.facing < self.grazing) & (rng.random(depth.shape) < self.grazing_dropout)
        noisy = np.where(seen, depth + rng.normal(size=depth.shape) * self.sigma(np.where(seen, depth, 0.0)), 0.0)
        noisy[drop | ~seen] = 0.0
        jitter = rng.normal(scale=self.lateral_px, size=depth.shape + (2,))
        return noisy, jitter


@dataclass(frozen=True)
class Photometric:
    """What a colour camera outdoors does to a frame's colours (issue 18, stop 45), for rendered apple trees.

    The renderer's colours are clean: one white light, no shadow from leaves, no highlight, the same exposure
    and white balance in every frame. A real orchard frame differs by what the sun and the camera do; each
    effect is one attribute (0 or ``False``: off), its value and its source next to it. :meth:`apply` takes the
    rendered colour (display-coded, 0-1), the apples' specular term and the frame's own RNG.

    Attributes
    ----------
    exposure_ev : float, stops
        Auto exposure keeps the frame's mean brightness (linear light) where it was without shadows and
        highlights, off by a uniform ``+-exposure_ev``: the metering sees sky, sunlit and shaded canopy in shares
        that differ from frame to frame (stated: half a stop). With shadows the sunlit parts come out brighter.
    cast_deg : float, degrees
        Each frame's white balance is off by an angular error uniform in ``0-cast_deg`` (median half of it) in a
        random direction of chromaticity: a cast from the sky or the canopy. Stated: median 4 degrees, as the
        median angular errors of grey-world and camera-style white balance on the Gehler-Shi set (about 3-6
        degrees; Gijsenij, Gevers & van de Weijer 2011, "Computational color constancy: survey and
        experiments", IEEE TIP 20(9)).
    shadow_share : float
        Share of the frame in hard shadow of leaves between the sun and the scene (stated: a third; inside a
        canopy much of what is seen lies in some leaf's shadow).
    shadow_size : float, metres
        Size of the shadow patches at the canopy (a leaf's, 5-9 cm: the scene's own leaves); the sun's half
        degree gives a penumbra of 1-3 mm at 10-30 cm behind a leaf, under a pixel at 1.2-2 m: hard edges.
    shadow_gain : float
        Light in shadow over light in sun: skylight alone. The diffuse share of a clear day's light is 0.1-0.2
        (Erbs, Klein & Duffie 1982, Solar Energy 28(4)); the canopy's interreflections lift it (stated: 0.35).
    shadow_tint : (3,) float
        Skylight's colour relative to sunlight, R G B (skylight is bluer: a correlated colour temperature
        of about 10,000 K against the sun's 5,500 K; Wyszecki & Stiles, "Color Science", 1982; stated gains).
    specular, shininess : float
        An apple's waxy cuticle reflects the sun as a near-white highlight: Blinn-Phong ``specular (n.h) **
        shininess`` in linear light, white, where the skin is sunlit (stated: 0.6 and 40, a small bright spot).
    full_well, read_noise : float, electrons
        Shot and read noise in linear light. The Azure Kinect's colour sensor (OV12A10, 1.25 um pixels) holds
        about 4,000-5,000 electrons per pixel (typical of 1.1-1.4 um pixels); its 1920x1080 stream is scaled
        from 3840x2160, four pixels a pixel: 16,000 electrons and a read noise of 2 x 2.5 (stated).
    blur_px : float, pixels
        Gaussian softness of optics, demosaicing and the scaling to 1920x1080 (stated: 0.6 px).
    jpeg_quality : int
        The 1920x1080 colour stream of the Azure Kinect is MJPEG (Azure Kinect DK hardware specification, colour
        camera operating modes): JPEG with 4:2:0 chroma (colour at half resolution each way, blocking). 0: none;
        stated 90 (the camera's own quality is not published).
    apple_palette : bool
        Apples' red from dark crimson (hue -13 degrees, value 0.3) to orange-red (hue +16 degrees) instead of the
        old -11 to +7 degrees, value 0.45-0.8 (red cultivars from 'Red Delicious' to 'Gala'; stated).
    gamma : float
        The display coding of the rendered colours (sRGB's 2.2); the effects act in linear light.
    """

    exposure_ev: float = 0.5
    cast_deg: float = 8.0
    shadow_share: float = 0.33
    shadow_size: float = 0.07
    shadow_gain: float = 0.35
    shadow_tint: tuple[float, float, float] = (0.88, 1.0, 1.18)
    specular: float = 0.6
    shininess: float = 40.0
    full_well: float = 16000.0
    read_noise: float = 5.0
    blur_px: float = 0.6
    jpeg_quality: int = 90
    apple_palette: bool = True
    gamma: float = 2.2

    def apply(self, color: np.ndarray, spec: np.ndarray, px_per_metre: float, rng: np.random.Generator) -> np.ndarray:
        """The camera's frame: ``color`` (h, w, 3) float display-coded 0-1, ``spec`` (h, w) the apples' specular
        term (0 elsewhere), ``px_per_metre`` the image scale at the canopy; (h, w, 3) uint8."""
        h, w = color.shape[:2]
        lin = np.clip(color, 0.0, 1.0) ** self.gamma
        metered = float(lin.mean())
        sun = np.ones((h, w))
        if self.shadow_share > 0:
            shade = _shadow_mask(h, w, self.shadow_size * px_per_metre, self.shadow_share, rng)
            sun[shade] = 0.0
            lin[shade] *= self.shadow_gain * np.asarray(self.shadow_tint)
        if self.specular > 0:
            lin += (self.specular * spec * sun)[:, :, None]
        gain = metered / max(float(lin.mean()), 1e-9)  # auto exposure
        gain *= 2.0 ** rng.uniform(-self.exposure_ev, self.exposure_ev) if self.exposure_ev > 0 else 1.0
        lin *= gain * _cast(self.cast_deg, rng)
        if self.full_well > 0:
            e = np.clip(lin, 0.0, None) * self.full_well
            lin = (e + rng.normal(size=e.shape) * np.sqrt(e + self.read_noise**2)) / self.full_well
        out = np.clip(lin, 0.0, 1.0) ** (1.0 / self.gamma)  # saturation: a clipped channel
        if self.blur_px > 0:
            from scipy import ndimage

            out = ndimage.gaussian_filter(out, (self.blur_px, self.blur_px, 0), mode="nearest")
        img = (np.clip(out, 0, 1) * 255 + 0.5).astype(np.uint8)
        if self.jpeg_quality > 0:
            img = _jpeg(img, self.jpeg_quality)
        return img


def _cast(cast_deg: float, rng: np.random.Generator) -> np.ndarray:
    """Channel gains (3,) of a white-balance error: an angle uniform in ``0-cast_deg`` between white and the gains,
    in a uniform direction orthogonal to grey; mean gain 1."""
    if cast_deg <= 0:
        return np.ones(3)
    angle = np.radians(rng.uniform(0.0, cast_deg))
    phi = rng.uniform(0.0, 2 * np.pi)
    u = np.array([1.0, -1.0, 0.0]) / np.sqrt(2.0)
    v = np.array([1.0, 1.0, -2.0]) / np.sqrt(6.0)
    direction = np.cos(phi) * u + np.sin(phi) * v
    gains = np.ones(3) + np.tan(angle) * np.sqrt(3.0) * direction
    return gains / gains.mean()


def _shadow_mask(h: int, w: int, size_px: float, share: float, rng: np.random.Generator) -> np.ndarray:
    """(h, w) bool: ``share`` of the frame in hard-edged patches about ``size_px`` across (smoothed noise on a grid
    of a quarter patch, cut at its ``share`` quantile, brought to full resolution bilinearly and cut again)."""
    from scipy import ndimage

    step = max(1, int(size_px / 4))
    gh, gw = h // step + 2, w // step + 2
    field = ndimage.gaussian_filter(rng.normal(size=(gh, gw)), 1.0, mode="wrap")
    yy = (np.arange(h) + 0.5) / step
    xx = (np.arange(w) + 0.5) / step
    full = ndimage.map_coordinates(field, np.meshgrid(yy, xx, indexing="ij"), order=1, mode="nearest")
    return full < np.quantile(field, share)


def _jpeg(img: np.ndarray, quality: int) -> np.ndarray:
    """``img`` through JPEG at ``quality`` with 4:2:0 chroma (Pillow), as an MJPEG colour stream delivers it."""
    import io

    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(img).save(buf, format="JPEG", quality=int(quality), subsampling=2)
    buf.seek(0)
    return np.asarray(Image.open(buf).convert("RGB")).copy()
