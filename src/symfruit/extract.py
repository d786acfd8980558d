"""From a fruit's mask to its 3D points: the depth image registered to the masks, invalid depth dropped, the
fruit's own surface kept (:func:`symfruit.core.surface.fruit_surface`: the background, a leaf, the support or a
fruit behind leak in through a mask, flying pixels bridge them), de-projected."""

from __future__ import annotations

import itertools
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy import ndimage

from .core.camera import Camera
from .core.kernels import compiled
from .core.limits import depth_metres
from .core.occlusion import SECTORS, STAR_SHARE
from .core.points import bounds, median
from .core.raster import inner_distance, mask_box, square_filter
from .core.surface import (
    _FREE_PX,
    ALL_ROUND,
    PART_POINTS,
    Reading,
    _free_tol_of,
    across_occluder,
    colour_trim,
    fruit_surface,
    registration_shift,
    within,
)
from .errors import InputError
from .segment.colour import convex_hull_mask
from .settings import Section, SettingError, setting

__all__ = ["ExtractSettings", "Extraction", "backdrop", "cluster", "cluster_gap", "extract", "keep_caps", "one_sided",
           "own_cap", "own_surface", "register", "shift_labels", "trim_labels"]  # fmt: skip

#: Largest border erosion a setting may ask for (pixels).
MAX_RADIUS_PX = 50

#: :func:`cluster_gap`: the least clustering distance in pixel footprints (depth / focal length) at the points'
#: depth. Two points of one surface a pixel apart lie a footprint apart facing the camera and twice that where it
#: turns 60 degrees away (about where a time-of-flight camera stops returning depth on a sphere: the outer 13-20 %
#: of its radius lost); :func:`cluster` keeps points up to half its distance apart together.
CLUSTER_PITCHES = 4.0
#: :func:`extract` clusters again at :func:`cluster_gap` only where the setting's distance broke the points into
#: pieces the largest of which holds less than this share of them (a surface sampled more coarsely than the
#: distance: the real Azure Kinect spheres binned 3 x 3 in pieces of 2-42 % of their points), not where it parted a
#: fruit from a leaf, a branch or the backdrop around it (the fruit the larger part): a wider distance there joins
#: what lies a few millimetres off the fruit to it (the rendered apple trees at 1.2-2 m: a visible apple's depth
#: side 0.9 -> 21.5 mm with the wider distance taken always; docs/realpert55.md, "On merging").
FRAGMENT_SHARE = 0.5

#: :func:`backdrop` reads the depth around a mask on every ``radius / AROUND_STEPS``-th pixel (a near fruit's ring of
#: 100 000 pixels counted on a few thousand: shares, not pixels, are wanted).
AROUND_STEPS = 8


@dataclass(frozen=True)
class ExtractSettings(Section):
    """Turning a mask into the fruit's points (:mod:`symfruit.extract`).

    Attributes
    ----------
    min_depth, max_depth : float, metres
        Depth outside this range is invalid (the D435 reads from about 0.1 m; an orchard robot's camera at 1.2-2 m
        from a canopy sees apples up to 2.4 m away, which a 2 m bound left with the depth of the leaf in front of
        them only; the Azure Kinect's narrow mode reads to 3.86 m).
    erode_px : int
        Pixels dropped along the mask's border, where flying pixels (depth mixed with the background)
        sit.
    registration_px : int
        How far (pixels) the depth image may sit from the masks: a real RGB-D camera's depth registered to
        colour is often a few pixels off. The frame's shift is searched within this radius and the masks moved
        onto the depth before extraction (:func:`~symfruit.core.surface.registration_shift`; 0: never); a least
        cost at the radius itself is no minimum found and moves nothing, so the radius must exceed the largest
        shift expected.
    occluder_edges : bool
        The registration reads a band of lost depth beside something in front of the fruit (a leaf's edge: a
        time-of-flight camera invalidates the mixed pixels along every step in depth) as a junction, not as the
        fruit's silhouette, and pools the sides of every fruit's outline, also those that tell no shift (stop 62,
        docs/leaf62.md; on by default since stop 63, with ``evidence.lost_rim: bound``, which holds the depth at the
        true shift: docs/prior63.md; off, the real frames cut by a leaf are registered 3-11 px off).
    mask_edge_px : int
        With the frame's colour image (``detect``, masks drawn as outlines: a masks file, a label array, a model; not
        the colour segmenter's): how far (pixels) the masks may sit off their fruit in the colour image, all one way
        (an annotator's or a model's masks drawn on an image registered a few pixels off). The shift that lays the
        masks' outlines on the colour's edges (:func:`~symfruit.core.edges.mask_shift`: only along an axis whose two
        opposite sides agree, each from 100 outline pixels or more, by 2 px or more, and only where it beats none)
        moves them before the colour trim; 0: never. The real Azure Kinect spheres with their masks moved 5 px up:
        3 -> 0 of 8 boxes over the 6 mm bar, and every shifted mask's box (5 or 10 px, any way) back where the
        unperturbed mask's is (6-14 mm off on average without). 10 (the default, stop 62, docs/edge62.md): the
        farthest a mask may sit off its fruit and still be that fruit's: the smallest fruit issue 18 names is 40 px
        across, and its mask 10 px off overlaps it at IoU 0.52, about the 0.5 at which a mask is counted as the
        fruit's; a few pixels off (an outline's own pixel or two, colour registered several pixels off the image
        the masks were drawn on) lies well inside it. It reads the colour's edges in a window about each mask:
        0.07-0.10 s of CPU on a 1920 x 1080 frame of 30 tree masks (stop 61's whole window: 0.56-0.85 s); it moves
        nothing on the rendered trees, strawberries and benchmark frames, nor on the real spheres' masks as drawn.
    colour_trim_px : int
        With the frame's colour image (``detect``): a mask's outer band up to this many pixels (and a fifth of
        its equivalent radius) loses the pixels whose colour is the background's
        (:func:`~symfruit.core.surface.colour_trim`: masks overshoot onto what lies around a fruit); where fruit and
        surroundings do not separate in that band, twice and three times it are tried (:func:`trim_labels`: a mask
        overshooting by more than the band); 0: never.
    trim_keeps_surface : bool
        Given the depth (``detect``), a colour cut on one side of a mask (:func:`one_sided`: under two thirds of its
        outline) takes no pixel whose depth lies on the fruit's own convex cap (:func:`own_cap`): a shaded limb
        darkening towards a grey background, or a mask drawn a few pixels off the fruit, where the ring beside it
        that the colour is compared with is the fruit itself, is the fruit (the real 200 mm sphere's lower limb:
        its box 182 mm tall for 198 binned 2 x 2, 196 with it; stop 57, docs/shift57.md). A cut all round is an
        overshoot's, and the colour's alone: where the depth sits a few pixels off the colour (the real frames'
        larger spheres), the cap runs on over an overshoot past the fruit's colour edge (stop 57's rule on every
        cut: the real masks grown 2-10 px 21 -> 28 of 32 boxes over the 6 mm bar; stop 58, docs/trim58.md).
        ``detect`` gives the pixels back after the registration (:func:`keep_caps`), reading the cap on the depth
        the masks are moved onto, so that they cannot move the frame's shift (done before it, they moved a frame
        of rendered apple trees by a pixel and a half-hidden apple's points went to the leaf in front of it:
        docs/trim58.md, "After merging"). On by default since stop 61 (docs/small61.md): the real spheres binned
        2x and 3x, and binned with a wider lost rim, 8 -> 0 boxes over the 6 mm bar; the development trees' mean
        centre the same to 0.01 mm.
    trim_front_ring : bool
        Given the depth (``detect``), after the registration the colour trim is done again on each mask beside which,
        within its convex hull, something lies in front of its fruit (:func:`front_ring`: a leaf or twig crossing it,
        the mask cut along it), with that left out of the ring the band is compared with; it only gives back what the
        colour took, and nothing on the occluder itself, and only where the ring without the occluder takes nothing
        of the mask (finds it tight). Where the occluder shows the fruit's own colour the band and the ring did not
        separate, and a band twice as wide was taken all round (the real spheres under a strip 5 cm in front,
        docs/strip58.md cause 1). Where the ring without it takes some of the mask, the mask overshoots, and the
        colour's wider cut stands: the occluder hid the overshoot from the band (the development trees' masks over
        their apples by up to 4 px, the ring's band taking 2-3 px of it; given back, 36 of 248 apples moved, 22
        farther: strip64). On by default since stripb64 (issue 18, docs/strip64.md section 6): the real frames cut by
        a strip go 2 -> 0 (unpainted) and 1 -> 0 (painted) of 8 boxes over the 6 mm bar, every other perturbation
        the same to the box; the development trees (seeds 0-3, 6-11) and every digest unchanged.
    slab : float
        Depth pixels farther than this many fruit radii (the mask's, at the fruit's depth) behind the
        fruit's front are not its surface (:func:`~symfruit.core.surface.fruit_surface`).
    convex_tolerance : float
        Along every image ray from the fruit's nearest point its depth may fall this many noise deviations
        (at least 3 mm), plus the depth's unit, below its running maximum before the ray has left the fruit (a
        convex front never falls); 0 switches the test off.
    cluster_distance : float, metres
        Points closer than this join one cluster (voxel-grid Euclidean clustering); the fruit is the
        cluster nearest the camera among those with at least ``cluster_share`` of the largest's points. Where
        the camera's pixels are coarser than this at the points' depth, the distance is :data:`CLUSTER_PITCHES`
        pixel footprints there instead (:func:`cluster_gap`), but only where the distance broke the points into
        pieces none of which holds most of them (:data:`FRAGMENT_SHARE`).
    cluster_share : float
    min_points : int
        A fruit with fewer points left is reported as failed.
    """

    min_depth: float = setting(0.1, ge=0.0, le=100.0)
    max_depth: float = setting(3.0, gt=0.0, le=100.0)
    erode_px: int = setting(1, ge=0, le=MAX_RADIUS_PX)
    registration_px: int = setting(20, ge=0, le=MAX_RADIUS_PX)
    occluder_edges: bool = setting(True)
    mask_edge_px: int = setting(10, ge=0, le=MAX_RADIUS_PX)
    colour_trim_px: int = setting(4, ge=0, le=MAX_RADIUS_PX)
    trim_keeps_surface: bool = setting(True)
    trim_front_ring: bool = setting(True)
    slab: float = setting(1.3, gt=0.0, le=100.0)
    convex_tolerance: float = setting(3.0, ge=0.0, le=1000.0)
    cluster_distance: float = setting(0.006, gt=0.0, le=1.0)
    cluster_share: float = setting(0.3, gt=0.0, le=1.0)
    min_points: int = setting(30, ge=4, le=1_000_000)

    def check(self) -> None:
        if self.min_depth >= self.max_depth:
            raise SettingError("min_depth", "must be smaller than max_depth")


@dataclass(frozen=True)
class Extraction:
    """The points of one fruit and what was dropped on the way.

    Attributes
    ----------
    points : (n, 3) float, metres
    mask_area : int, pixels
    n_invalid : int
        Mask pixels without valid depth (0, NaN, out of range).
    n_border : int
        Pixels dropped at the mask's border (flying pixels).
    n_other_clusters : int
        Points dropped as not the fruit's own surface: another depth (the background, a leaf in front), a
        support or stem its convex front cannot continue into, another cluster.
    truncated : bool
        The mask touches the image border: the fruit may continue outside the image.
    silhouette : (h, w) bool, optional
        The fruit's outline as the completion sees it (the mask).
    error : str
        Why the mask holds no depth of the fruit's own (:func:`own_surface`: what it held is what lies behind the
        fruit), "" otherwise; the points are then none.
    """

    points: np.ndarray
    mask_area: int
    n_invalid: int
    n_border: int
    n_other_clusters: int
    truncated: bool
    silhouette: np.ndarray | None = None
    error: str = ""


def cluster_gap(points: np.ndarray, camera: Camera, distance: float) -> float:
    """The distance :func:`cluster` joins ``points`` (n, 3, n > 0) of one fruit within: ``distance``, or
    :data:`CLUSTER_PITCHES` pixel footprints at the points' median depth where that is more. A fixed distance
    breaks a far fruit, or one seen by a coarse camera, into single pixels (the Azure Kinect spheres binned
    3 x 3: a 200 mm sphere at 1.5 m, 5 mm a pixel, kept 6 points of 1,033 with depth; docs/realpert55.md)."""
    footprint = float(median(np.ascontiguousarray(points[:, 2]))) / float(np.sqrt(camera.fx * camera.fy))
    return max(float(distance), CLUSTER_PITCHES * footprint)


def _clusters(points: np.ndarray, camera: Camera, distance: float) -> np.ndarray:
    """:func:`cluster`'s labels of ``points`` (n >= 2) at ``distance``; where that broke them into pieces the largest
    of which holds less than :data:`FRAGMENT_SHARE` of them and :func:`cluster_gap` is wider, its labels at that gap."""
    labels = cluster(points, distance)
    if labels.max() > 0 and np.bincount(labels).max() < FRAGMENT_SHARE * len(points):
        if (gap := cluster_gap(points, camera, distance)) > distance:
            return cluster(points, gap)
    return labels


def cluster(points: np.ndarray, distance: float) -> np.ndarray:
    """Euclidean clustering: (n,) int cluster labels, 0 the largest cluster.

    Points are first cut into depth slabs wherever consecutive depths differ by more than
    ``distance`` (such points can never be neighbours); within a slab, points fall into cubes of side
    ``distance / 2`` and occupied cubes that touch (26-neighbourhood) form a cluster. Two points of
    different clusters are at least ``distance / 2`` apart, and points up to ``distance / 2`` apart
    always share one.

    Where numba is, its compiled twin does the same steps (:func:`symfruit.core._jit.clusters`: the same labels; issue
    19, sixteenth round), but for a slab too sparse for a dense grid.
    """
    n = len(points)
    if n == 0:
        return np.zeros(0, np.int64)
    p = np.asarray(points)
    if p.dtype == np.float64 and p.ndim == 2 and p.shape[1] == 3 and (jit := compiled()) is not None:
        labels, done = jit.clusters(np.ascontiguousarray(p), float(distance))
        if done:
            return labels
    order = np.argsort(points[:, 2], kind="stable")
    gaps = np.flatnonzero(np.diff(points[order, 2]) > distance) + 1
    runs = np.concatenate(([0], gaps, [n]))
    labels = np.empty(n, np.int64)
    next_label = 0
    for lo, hi in itertools.pairwise(runs):
        idx = order[lo:hi]
        if hi - lo == 1:
            labels[idx] = next_label
            next_label += 1
            continue
        sub = _grid_clusters(points[idx], distance / 2.0)
        labels[idx] = sub + next_label
        next_label += int(sub.max()) + 1
    counts = np.bincount(labels)
    rank = np.empty(len(counts), np.int64)
    rank[np.argsort(-counts, kind="stable")] = np.arange(len(counts))
    return rank[labels]


def _grid_clusters(points: np.ndarray, voxel: float) -> np.ndarray:
    cells = np.floor((points - bounds(points)[0]) / voxel).astype(np.int64)
    shape = bounds(cells)[1] + 1  # column by column: the first-axis reduction of (n, 3) is slow
    if np.prod(shape) > 2e7:  # too sparse for a dense grid: link the occupied cells through a tree
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components
        from scipy.spatial import cKDTree

        uniq, inverse = np.unique(cells, axis=0, return_inverse=True)
        pairs = cKDTree(uniq).query_pairs(np.sqrt(3) + 1e-9, output_type="ndarray")
        graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(uniq),) * 2)
        _, cell_labels = connected_components(graph, directed=False)
        return cell_labels[inverse.ravel()]
    grid = np.zeros(shape, bool)
    # each point's cell by flat index (twice as fast as three index arrays, the same cells)
    flat = (cells[:, 0] * shape[1] + cells[:, 1]) * shape[2] + cells[:, 2]
    grid.ravel()[flat] = True
    lab, _ = ndimage.label(grid, structure=np.ones((3, 3, 3), bool))
    return np.take(lab.ravel(), flat) - 1


def _checked(image: Any, beside: Any, camera: Any, settings: Any, what: str, name: str) -> np.ndarray:
    """A mask (``name`` "mask": bool, an integer mask read as non-zero) or instance labels (integers) checked at an
    entry point in O(1): a 2-D image of ``beside``'s shape (the depth: float metres; or the colour), ``camera`` a
    :class:`Camera` of that size, ``settings`` an :class:`ExtractSettings`. Before: numpy's broadcast errors, an
    int64 mask viewed as 8 bytes a pixel, 16-bit depth read as metres (no point within range), AttributeErrors."""
    arr = np.asarray(image)
    size = np.shape(beside)
    if arr.ndim != 2 or arr.shape != size:
        raise InputError(f"{what}: {name} must be an (h, w) image of the {'colour' if camera is None else 'depth'}"
                         f"'s shape {size}, got {arr.shape}")  # fmt: skip
    if arr.dtype != bool and arr.dtype.kind not in "iu":
        raise InputError(f"{what}: {name} must be {'bool' if name == 'mask' else 'whole numbers'}, got {arr.dtype}")
    if camera is not None:
        depth = np.asarray(beside)
        if depth.dtype.kind != "f":
            raise InputError(f"{what}: depth must be float metres, got {depth.dtype} (raw units: multiply by the "
                             "depth scale first)")  # fmt: skip
        if not isinstance(camera, Camera):
            raise InputError(f"{what}: camera must be a symfruit Camera, got {type(camera).__name__}")
        if (camera.width, camera.height) != (size[1], size[0]):
            raise InputError(f"{what}: the camera is for {camera.width}x{camera.height} images, the depth is "
                             f"{size[1]}x{size[0]}")  # fmt: skip
    if settings is not None and not isinstance(settings, ExtractSettings):
        raise InputError(f"{what}: settings must be an ExtractSettings (Settings().extract), got "
                         f"{type(settings).__name__}")  # fmt: skip
    return (arr != 0) if name == "mask" and arr.dtype != bool else arr


def extract(mask: np.ndarray, depth: np.ndarray, camera: Camera, settings: ExtractSettings | None = None, *,
            leafy: np.ndarray | None = None, checked: bool = False, outlined: bool = True,
            own: bool = True) -> Extraction:  # fmt: skip
    """The 3D points of the fruit under ``mask``.

    Parameters
    ----------
    mask : (h, w) bool
    depth : (h, w) float, metres (0 or NaN = no depth), registered to the mask (:func:`register`)
    camera : Camera
    settings : ExtractSettings
    checked : bool
        ``depth`` is (a window of) a :class:`~symfruit.core.frame.Frame`'s, its units checked already. Else, when the
        mask holds no depth within ``min_depth``-``max_depth``, the depth image's units are checked
        (:func:`~symfruit.core.limits.depth_metres`): a depth in millimetres is refused, not 0 points.
    outlined : bool
        The mask is the fruit's whole outline as a person draws it (a masks file, a label array, a learned model
        trained on such masks): it may be drawn over a leaf or branch in front, which is passed over for the fruit
        behind it where it runs on across the outline (:func:`~symfruit.core.surface.fruit_surface`'s
        ``crossing``). False for a mask of the visible surface alone, occluders left out: the colour segmenter's
        given depth (:func:`symfruit.segment.colour.segment`: leaf, calyx and stem pixels and pixels off the
        fruit's depth dropped), on which the test is skipped (0.4 ms a fruit; stop 47, docs/mask47.md).
    own : bool
        Check that the points kept are the fruit's own surface, not what lies behind it (:func:`own_surface`, on the
        depth around the mask: ``depth`` must hold the fruit's radius beyond the mask; ``detect`` extracts on a
        window and checks on the image). False: not checked.

    Returns
    -------
    Extraction
        Its points are the mask's pixels (the border eroded) on the fruit's own surface
        (:func:`~symfruit.core.surface.fruit_surface`: its depth mode, a slab of ``slab`` radii behind its
        front, the convex cap from its nearest point), then the cluster nearest the camera among the clusters
        holding at least ``cluster_share`` of the largest one's points, with the clusters a nearer surface crossing
        the fruit parted from it on one convex surface (:func:`~symfruit.core.surface.across_occluder`); with
        ``own``, none where those are what lies behind the fruit and the mask holds no other surface
        (:func:`own_surface`; the reason in its ``error``).
    """
    mask = _checked(mask, depth, camera, settings, "extract", "mask")
    if leafy is not None and (np.shape(leafy) != mask.shape or np.asarray(leafy).dtype != bool):
        raise InputError(f"extract: leafy must be an (h, w) bool image of the mask's shape {mask.shape}, got "
                         f"{np.asarray(leafy).dtype} {np.shape(leafy)}")  # fmt: skip
    s = settings or ExtractSettings()
    # bool masks' counts by np.count_nonzero: the same whole numbers, without sum's cast of every pixel to an integer
    # (some 10-50 us a window; stop 47)
    area = int(np.count_nonzero(mask))
    truncated = bool(mask[0].any() or mask[-1].any() or mask[:, 0].any() or mask[:, -1].any())
    core = mask
    if s.erode_px:
        eroded = square_filter(mask, s.erode_px, every=True)
        if np.count_nonzero(eroded) >= max(s.min_points, area // 4):  # small masks keep their border
            core = eroded
    z_all = np.asarray(depth, dtype=np.float64)
    # the depth tests and the points' deprojection by compiled twins where numba is (issue 19, seventeenth round:
    # the same maps, counts and points, bit for bit)
    jit = compiled() if z_all.ndim == 2 and core.dtype == bool else None
    if jit is not None:
        z_valid, usable = np.empty(z_all.shape), np.empty(z_all.shape, bool)
        n_invalid, n_usable = jit.valid_depth(z_all, core, float(s.min_depth), float(s.max_depth), z_valid, usable)
    else:
        valid = np.isfinite(z_all) & (z_all >= s.min_depth) & (z_all <= s.max_depth)
        n_invalid = int((core & ~valid).sum())
        usable = core & valid
        n_usable = int(usable.sum())
        z_valid = np.where(valid, z_all, 0.0) if n_usable >= 10 else z_all
    if n_usable == 0 and not checked:  # nothing in range: the units are looked at then alone (no cost otherwise)
        depth_metres(z_all, "extract")  # stop 43: millimetres handed over as metres gave 0 points, unsaid
    outline = np.asarray(mask, dtype=bool)
    surface = None
    if n_usable >= 10:
        focal = float(np.sqrt(camera.fx * camera.fy))
        # with a least depth above 0 the depth kept is finite and above 0, or 0: fruit_surface reads it as it is, as
        # the registration's (stop 52, register52: the same values; its cleaning a copy of the window a fruit)
        surface = fruit_surface(z_valid, core, focal, slab=s.slab,
                                tolerance=s.convex_tolerance if s.convex_tolerance > 0 else np.inf,
                                leafy=leafy, thin=True, crossing=outlined, clean=s.min_depth > 0)  # fmt: skip
    if jit is not None:
        points = jit.pixel_points(usable, usable if surface is None else surface.pixels, z_all, float(camera.cx),
                                  float(camera.cy), float(camera.fx), float(camera.fy))  # fmt: skip
    else:
        rows, cols = np.nonzero(usable if surface is None else usable & surface.pixels)
        points = camera.deproject(np.stack((cols, rows), axis=1).astype(np.float64), z_all[rows, cols])
    dropped = int(n_usable - len(points))
    # one cluster (every label 0): every point kept, nothing dropped, no cluster picked (stop 46)
    if len(points) >= 2 and int((labels := _clusters(points, camera, s.cluster_distance)).max()) > 0:
        counts = np.bincount(labels)
        big = np.flatnonzero(counts >= s.cluster_share * counts.max())
        # the nearest of the big clusters (one alone needs no medians)
        near = big[0] if len(big) == 1 else big[np.argmin([median(points[labels == k, 2]) for k in big])]
        keep_cluster = labels == near
        if surface is not None and len(points) >= 2 * PART_POINTS:
            # parts of the fruit a nearer surface crossing it parted from the nearest (a twig, a leaf's midrib or
            # strip across it: issue 18, stop 56)
            rows, cols = np.nonzero(usable & surface.pixels)
            tol = max(s.convex_tolerance * surface.noise, 0.003)  # ``focal``: the surface's, above
            keep_cluster = across_occluder(z_all, rows, cols, labels, int(near), tol, focal, surface.radius,
                                            s.erode_px + s.colour_trim_px + 2)[labels]  # fmt: skip
        dropped += int((~keep_cluster).sum())
        points = points[keep_cluster]
    ex = Extraction(points, area, n_invalid, area - np.count_nonzero(core), dropped, truncated, outline)
    return own_surface(ex, mask, z_all, camera, s, leafy=leafy, outlined=outlined) if own else ex


#: :func:`own_surface`: points extraction kept are what lies behind the fruit when no more than this share of the
#: valid depth around the mask lies behind them by more than the fruit's radius ...
BEHIND_SHARE = 0.05
#: ... while at least this share of the pixels around it (with depth or without) lies at their depth, within that
#: radius (the surface runs on past the outline).
LEVEL_SHARE = 0.5


def backdrop(points: np.ndarray, mask: np.ndarray, depth: np.ndarray, focal: float,
             box: tuple[int, int, int, int] | None = None) -> tuple[float, float, int]:  # fmt: skip
    """How the depth around a mask lies against the points kept of it: ``(behind, level, count)``. Around the mask:
    its pixels within the fruit's radius beyond it (at least 4 pixels; from 2 pixels beyond it, or the sampling step
    where the ring is read on every ``step``-th pixel, :data:`AROUND_STEPS`). ``behind``: the share of those with
    valid depth lying behind the points' median depth ``z`` by more than the fruit's radius ``r`` (the mask's larger
    extent in pixels at ``z``, halved: the 2-D thin-lens size); ``level``: the share of all of them (with depth or
    without: where the camera has none, nothing is known to run on) lying within ``r`` of ``z``; ``count``: those
    with depth (NaN, NaN, 0 without points or depth around). A stereo camera's depth runs on a few pixels past a
    near fruit's edge (the matching window) and leaves a band without depth beside it: a ring of the fruit's own
    width reaches past both.

    ``mask`` and ``depth`` (metres, 0 or NaN: none) are the same (h, w) image or window, ``box`` the mask's rows and
    columns ``(r0, r1, c0, c1)`` when known (:func:`~symfruit.core.raster.mask_box`); pixels beyond it are none.
    """
    found = box if box is not None else mask_box(np.asarray(mask, dtype=bool))
    if found is None or not len(points):
        return float("nan"), float("nan"), 0
    r0, r1, c0, c1 = found
    h, w = mask.shape
    radius_px = float(np.sqrt(np.count_nonzero(mask[r0:r1, c0:c1]) / np.pi))
    grow = int(max(np.ceil(radius_px), 4))
    step = max(1, grow // AROUND_STEPS)
    a0, a1, b0, b1 = max(r0 - grow - 1, 0), min(r1 + grow + 1, h), max(c0 - grow - 1, 0), min(c1 + grow + 1, w)
    z = float(median(points[:, 2]))  # np.median's value, bit for bit, without its general-axis machinery
    r = 0.5 * max(r1 - r0, c1 - c0) * z / focal
    jit = compiled()
    if jit is not None and mask.dtype == bool and depth.shape == mask.shape and depth.dtype in (np.float32, np.float64):
        # the ring's sampling, its two square filters and the counts below in one call (stop 50, docs/speed50.md:
        # the same pixels and counts; the kernel reads both images at the same places, so only where they match)
        around, count, n_behind, n_level = jit.backdrop_counts(mask, depth, a0, a1, b0, b1, step, max(grow // step, 2),
                                                               z, r)  # fmt: skip
        if not count:
            return float("nan"), float("nan"), 0
        return n_behind / count, n_level / around, count
    m = np.ascontiguousarray(np.asarray(mask[a0:a1:step, b0:b1:step], dtype=bool))
    ring = square_filter(m, max(grow // step, 2)) & ~square_filter(m, 1)
    d = np.asarray(depth[a0:a1:step, b0:b1:step], dtype=np.float64)[ring]
    around = len(d)
    d = d[np.isfinite(d) & (d > 0)]
    if not len(d):
        return float("nan"), float("nan"), 0
    return np.count_nonzero(d > z + r) / len(d), np.count_nonzero(np.abs(d - z) <= r) / around, len(d)


def own_surface(ex: Extraction, mask: np.ndarray, depth: np.ndarray, camera: Camera,
                settings: ExtractSettings | None = None, *, box: tuple[int, int, int, int] | None = None,
                window: tuple[int, int, int, int] | None = None, leafy: np.ndarray | None = None,
                outlined: bool = True) -> Extraction:  # fmt: skip
    """``ex`` (:func:`extract`'s of ``mask``) when its points can be the fruit's own surface; else the points of the
    fruit in front of them, or none with the reason in ``error`` (issue 18, stop 49: docs/far49.md).

    A fruit is a body in front of what lies behind it: where no occluder covers its outline the camera sees past its
    edge to something farther. Points that run on past the mask's outline at their depth (at least
    :data:`LEVEL_SHARE` of the pixels around the mask, :func:`backdrop`) with nothing around lying behind them
    (at most :data:`BEHIND_SHARE`) are what lies behind the fruit: the background seen through a mask that is off
    the fruit, or around a small fruit whose own pixels a time-of-flight camera left without depth (mixed and
    grazing pixels). The mask's pixels nearer than them by the fruit's radius are then extracted alone; their points
    are the fruit's when they pass the same test, else the fruit has none (``detect`` reports it with the reason as
    its ``error``: a box on the background lies metres off, a fruit reported without one is looked at again). Fewer
    points than ``min_points`` are not looked at (the fruit is reported for too few points either way).

    ``mask``, ``depth`` (metres): the (h, w) image, ``camera`` its camera; ``box``: the mask's rows and columns
    ``(r0, r1, c0, c1)`` when known; ``window``: those the points are extracted again on (default the whole image),
    ``leafy`` that window's leaf-green pixels, ``outlined`` as :func:`extract`'s.
    """
    s = settings or ExtractSettings()
    if len(ex.points) < s.min_points:  # too few to complete: reported so whatever they are
        return ex
    focal = float(np.sqrt(camera.fx * camera.fy))
    box = box if box is not None else mask_box(np.asarray(mask, dtype=bool))
    behind, level, count = backdrop(ex.points, mask, depth, focal, box)
    if box is None or count < 10 or not (behind <= BEHIND_SHARE and level >= LEVEL_SHARE):
        return ex
    z = float(median(ex.points[:, 2]))
    r = 0.5 * max(box[1] - box[0], box[3] - box[2]) * z / focal
    r0, r1, c0, c1 = window or (0, mask.shape[0], 0, mask.shape[1])
    d = np.asarray(depth[r0:r1, c0:c1], dtype=np.float64)
    nearer = np.where(np.isfinite(d) & (d > 0) & (d < z - r), d, 0.0)
    m = np.asarray(mask[r0:r1, c0:c1], dtype=bool)
    n_nearer = int(np.count_nonzero(m & (nearer > 0)))
    n = len(ex.points)
    why = (f"no depth of the fruit's own: the {n} point{'s' * (n != 1)} its mask holds (at {z:.3f} m) run on past "
           f"its outline at their depth ({level:.0%} of the pixels around it) with nothing around behind them "
           "(the background seen through the mask, not the fruit)")  # fmt: skip
    again = None
    if n_nearer >= 10:
        local = Camera(fx=camera.fx, fy=camera.fy, cx=camera.cx - c0, cy=camera.cy - r0, width=c1 - c0,
                       height=r1 - r0)  # fmt: skip
        again = extract(m, nearer, local, s, leafy=leafy, checked=True, outlined=outlined, own=False)
    if again is None or not len(again.points):
        why += f"; {n_nearer} mask pixels nearer" if again is None else f"; no surface in the {n_nearer} pixels nearer"
    else:
        behind, level, count = backdrop(again.points, mask, depth, focal, box)
        if count < 10 or not (behind <= BEHIND_SHARE and level >= LEVEL_SHARE):
            kept = len(again.points)  # the fruit's own, in front: what the mask held behind it is dropped
            return replace(ex, points=again.points,
                           n_other_clusters=max(ex.mask_area - ex.n_border - ex.n_invalid - kept, 0))  # fmt: skip
        why += f"; the {len(again.points)} points nearer run on past it too"
    return replace(ex, points=np.zeros((0, 3)), n_other_clusters=ex.mask_area - ex.n_border - ex.n_invalid,
                   error=why)  # fmt: skip


def shift_labels(labels: np.ndarray, du: int, dv: int) -> np.ndarray:
    """``labels`` moved by ``(du, dv)`` pixels (what lay at ``(u, v)`` lies at ``(u + du, v + dv)``; 0 enters)."""
    out = np.zeros_like(labels)
    h, w = labels.shape
    if abs(du) >= w or abs(dv) >= h:
        return out
    out[max(dv, 0) : h + min(dv, 0), max(du, 0) : w + min(du, 0)] = labels[
        max(-dv, 0) : h - max(dv, 0), max(-du, 0) : w - max(du, 0)
    ]
    return out


#: Where fruit and surroundings do not separate in a mask's band (a mask overshooting by more than the band puts
#: background into the fruit's sample), :func:`trim_labels` tries bands these times wider, up to ``WIDEST`` of the
#: mask's equivalent radius (docs/stress39.md).
WIDER = (2, 3)
WIDEST = 0.4


def trim_labels(color: np.ndarray, labels: np.ndarray, settings: ExtractSettings | None = None,
                *, boxes: list[tuple[slice, slice] | None] | None = None,
                trimmed: set[int] | None = None, depth: np.ndarray | None = None,
                focal: float = 0.0, front_depth: np.ndarray | None = None) -> np.ndarray:  # fmt: skip
    """``labels`` with each mask's outer band trimmed where its colour is the background's
    (:func:`~symfruit.core.surface.colour_trim`, a band of ``colour_trim_px``, at most a fifth of the mask's
    equivalent radius; where fruit and surroundings do not separate there, twice and three times that band, at
    most ``WIDEST`` of the radius: a mask overshooting by more than the band).

    Masks and colour share the colour camera's pixels, so this comes before :func:`register` moves the masks
    onto the depth image: trimmed after the move, a mask would be compared with colours several pixels off.
    ``boxes``: ``ndimage.find_objects(labels)`` when the caller has it. ``labels`` itself is returned when nothing
    is trimmed. ``trimmed``: a set given the labels of the masks that lost pixels. ``depth`` (metres, the colour's
    size) and ``focal`` (pixels): with ``trim_keeps_surface``, no pixel of a fruit's own convex cap is taken
    (:func:`trim_mask`). ``front_depth`` (the same, and ``focal``): with ``trim_front_ring``, what lies in front of a
    fruit outside its mask is not sampled as its surroundings (:func:`front_ring`).
    """
    color, labels, s = _trim_checked(color, labels, settings)
    if s.colour_trim_px <= 0:
        return labels
    if depth is not None and s.trim_keeps_surface:  # checked where read (a whole frame is not copied)
        depth, focal = _depth_checked(depth, focal, labels.shape, "trim_labels")
    if front_depth is not None and s.trim_front_ring:
        front_depth, focal = _depth_checked(front_depth, focal, labels.shape, "trim_labels")
    out = labels
    for k, sl in enumerate(ndimage.find_objects(labels) if boxes is None else boxes, 1):
        if sl is None or (dropped := trim_mask(color, labels, k, sl, s, depth=depth, focal=focal,
                                               front_depth=front_depth)) is None:  # fmt: skip
            continue
        (r0, r1, c0, c1), gone = dropped
        out = out.copy() if out is labels else out
        out[r0:r1, c0:c1][gone] = 0
        if trimmed is not None:
            trimmed.add(k)
    return out


def _trim_checked(color: Any, labels: Any, settings: ExtractSettings | None) -> tuple[np.ndarray, np.ndarray,
                                                                                       ExtractSettings]:  # fmt: skip
    """:func:`trim_labels`' arguments checked: the colour (h, w, 3) uint8, the labels an integer image of its size,
    the settings (the defaults for None)."""
    color = np.asarray(color)
    if color.ndim != 3 or color.shape[2] != 3 or color.dtype != np.uint8:
        raise InputError(f"trim_labels: colour must be (h, w, 3) uint8 RGB, got {color.dtype} {color.shape}")
    labels = _checked(labels, color[:, :, 0], None, settings, "trim_labels", "labels")
    return color, labels, settings or ExtractSettings()


def trim_mask(color: np.ndarray, labels: np.ndarray, k: int, sl: tuple[slice, slice], s: ExtractSettings, *,
              depth: np.ndarray | None = None, focal: float = 0.0, front_depth: np.ndarray | None = None,
              front: np.ndarray | None = None,
              kept: np.ndarray | None = None) -> tuple[tuple[int, int, int, int], np.ndarray] | None:  # fmt: skip
    """One mask's part of :func:`trim_labels` (checked arguments, ``s.colour_trim_px`` above 0): mask ``k`` of
    ``labels`` (its box ``sl``) trimmed by colour, as the window ``(r0, r1, c0, c1)`` and the (r1 - r0, c1 - c0)
    bool pixels of the mask it drops there; None when it drops none. A mask's trimming reads its own pixels, the
    colour and the depth alone: the masks are trimmed in any order, or on several processes
    (:class:`~symfruit.fruitpool.FruitPool`), with the same pixels dropped.

    Given ``depth`` (the frame's, metres, read at the mask's own pixels as drawn: before :func:`register` moves it)
    and ``focal`` (pixels), with ``s.trim_keeps_surface``, the pixels the colour would drop whose depth lies on the
    fruit's own convex cap (:func:`own_cap`) are kept: the colour trim compares a band pixel with the ring just
    outside the mask, and where the fruit runs on past the mask (a mask drawn or registered a few pixels off, its
    shaded limb darkening towards a background of about its colour) that ring is the fruit itself (stop 57,
    docs/shift57.md: the real 200 mm sphere's lower limb taken, its box 175-190 mm tall for 198). Given
    ``front_depth`` (the frame's, as ``depth``) with ``s.trim_front_ring``, the colour's ring outside the mask leaves
    out what lies in front of the fruit (:func:`front_ring`), where that ring finds the mask tight; ``front``: that
    ring already read on the window :func:`trim_window` gives (the same pixels, not read again); ``kept``: the colour
    trim's own answer on that window (:func:`~symfruit.core.surface.colour_trim`'s pixels kept, read where the mask
    is alone: the mask less what :func:`trim_mask` without ``front_depth`` drops), not worked out again (front64)."""
    r0, r1, c0, c1 = trim_window(labels.shape, sl, s)
    mask = labels[r0:r1, c0:c1] == k
    radius = float(np.sqrt(np.count_nonzero(mask) / np.pi))
    band = min(float(s.colour_trim_px), 0.2 * radius)
    wider = tuple(f * band for f in WIDER if f * band <= WIDEST * radius)
    exclude = None
    if front_depth is not None and focal > 0.0 and s.trim_front_ring:
        exclude = front_ring(front_depth[r0:r1, c0:c1], mask, focal, s) if front is None else front
    if kept is None:
        kept = colour_trim(color[r0:r1, c0:c1], mask, band_px=band, wider=wider)
    if exclude is not None and (exclude & ~mask).any() and not kept.all(where=mask):
        # the ring without what lies in front gives back what the colour took only because the occluder was sampled
        # as the surroundings; it takes nothing the colour alone left, and gives back nothing on the occluder itself;
        # and only where it finds the mask tight: where it takes some of it, the mask overshoots, and the occluder in
        # the ring hid that overshoot from the band, which the colour's wider cut then took (stripb64)
        ring = colour_trim(color[r0:r1, c0:c1], mask, band_px=band, wider=wider, exclude=exclude & ~mask)
        if ring.all(where=mask):
            kept = kept | (ring & ~exclude)
    dropped = mask & ~kept
    if depth is not None and focal > 0.0 and s.trim_keeps_surface and dropped.any() and one_sided(mask, dropped):
        dropped &= ~own_cap(depth[r0:r1, c0:c1], mask, focal, s)
    return ((r0, r1, c0, c1), dropped) if dropped.any() else None


def trim_window(shape: tuple[int, ...], sl: tuple[slice, slice], s: ExtractSettings) -> tuple[int, int, int, int]:
    """The window ``(r0, r1, c0, c1)`` of an image of ``shape`` that :func:`trim_mask` reads about a mask's box
    ``sl``: the box grown by the widest band tried and 2 px."""
    h, w = shape[0], shape[1]
    pad = WIDER[-1] * s.colour_trim_px + 2
    return max(sl[0].start - pad, 0), min(sl[0].stop + pad, h), max(sl[1].start - pad, 0), min(sl[1].stop + pad, w)


def one_sided(mask: np.ndarray, dropped: np.ndarray) -> bool:
    """Whether the colour's cut ``dropped`` (pixels of ``mask``) takes less than
    :data:`~symfruit.core.surface.ALL_ROUND` of the mask's outline pixels (the mask's pixels next to one outside it).

    A mask that overshoots its fruit lies on the surroundings nearly all round, and the colour cuts it all round (the
    real spheres' masks grown 2-10 px: 88-100 % of their outline but for one, 57 %). A shaded limb darkening
    towards a background of about the fruit's colour is one side of it (the real spheres binned: 29-46 %). Only on
    such a cut may the fruit's own convex cap keep pixels (``trim_keeps_surface``): the depth near a fruit's outline
    may sit a few pixels off its colour edge (the real Azure Kinect frames: 5-11 px past the bottom of their larger
    spheres), and then the cap runs on over an overshoot there, which the colour is right to take (stop 58,
    docs/trim58.md)."""
    mask, dropped = np.asarray(mask, dtype=bool), np.asarray(dropped, dtype=bool)
    if mask.ndim != 2 or dropped.shape != mask.shape:
        raise InputError(f"one_sided: mask and cut must be 2-D images of one shape, got {mask.shape} and "
                         f"{dropped.shape}")  # fmt: skip
    edge = _outline(mask)
    return bool(np.count_nonzero(edge & dropped) < ALL_ROUND * np.count_nonzero(edge))


def _outline(mask: np.ndarray) -> np.ndarray:
    """(h, w) bool: ``mask & (inner_distance(mask, 2.0) <= 1.0)``, the pixels of ``mask`` (h, w) bool within a pixel
    of one outside it in the array (beyond the array is not outside: scipy's transform's), by the four shifted views
    of the mask padded with true (stop 62, cap62: the same pixels at a tenth of the distance map's cost). A mask true
    everywhere (no pixel outside it: scipy's transform then measures from a pixel beyond the array) is left to
    :func:`~symfruit.core.raster.inner_distance`."""
    if mask.all():
        return mask & (inner_distance(mask, 2.0) <= 1.0)
    h, w = mask.shape
    p = np.ones((h + 2, w + 2), dtype=bool)  # padded by hand: np.pad is slow
    p[1:-1, 1:-1] = mask
    return mask & ~(p[:-2, 1:-1] & p[2:, 1:-1] & p[1:-1, :-2] & p[1:-1, 2:])


def beyond_even_cut(mask: np.ndarray, dropped: np.ndarray) -> np.ndarray:
    """(h, w) bool: the pixels of the colour's cut ``dropped`` (pixels of ``mask``) that lie farther inside the mask
    than the cut reaches along most of its outline: deeper than the median, over the outline of what the cut leaves,
    of the distance from the mask's own outline.

    An overshoot all round (a generous pen, a model's dilation) is about as wide all round, the one assumption such
    a mask allows (as :func:`~symfruit.core.occlusion.overshoot` takes it where a support hides it); where the
    colour cuts deeper than that on part of the outline (a shaded limb darkening towards the ring outside, a contact
    shadow), it cuts the fruit: :func:`keep_caps` gives those pixels back where they lie on the fruit's own convex
    cap, and never the overshoot's, which lie within the even cut (the real 200 mm sphere's mask grown 5 px: cut
    5 px deep on three sides, 12 px at its shaded bottom; docs/grown62.md)."""
    mask, dropped = np.asarray(mask, dtype=bool), np.asarray(dropped, dtype=bool)
    if mask.ndim != 2 or dropped.shape != mask.shape:
        raise InputError(f"beyond_even_cut: mask and cut must be 2-D images of one shape, got {mask.shape} and "
                         f"{dropped.shape}")  # fmt: skip
    dropped = dropped & mask
    kept = mask & ~dropped
    if not kept.any() or not dropped.any() or not star_shaped(mask):
        return np.zeros(mask.shape, bool)
    dist = ndimage.distance_transform_edt(np.pad(mask, 1))[1:-1, 1:-1]
    edge = kept & ~ndimage.binary_erosion(np.pad(kept, 1))[1:-1, 1:-1]
    return dropped & (dist > float(np.median(dist[edge])))


def star_shaped(mask: np.ndarray) -> bool:
    """Whether ``mask`` fills :data:`~symfruit.core.occlusion.STAR_SHARE` of its star polygon about its centroid
    (its farthest pixel in each of :data:`~symfruit.core.occlusion.SECTORS` sectors): a silhouette every ray from
    the centroid leaves once, a round fruit's whole outline, as :func:`~symfruit.core.occlusion.overshoot` asks
    before it reads an outline by sectors. A mask cut along a leaf in front is not: part of its outline lies inside
    the fruit, and a cut's depth from it there is no overshoot's (:func:`beyond_even_cut`)."""
    vv, uu = np.nonzero(mask)
    if len(vv) == 0:
        return False
    dv, du = vv - vv.mean(), uu - uu.mean()
    sec = np.minimum(((np.arctan2(dv, du) + np.pi) / (2 * np.pi) * SECTORS).astype(np.intp), SECTORS - 1)
    reach = np.zeros(SECTORS)
    np.maximum.at(reach, sec, np.hypot(dv, du) + 0.5)
    return bool(len(vv) >= STAR_SHARE * 0.5 * float(reach @ reach) * (2 * np.pi / SECTORS))


def _depth_checked(depth: Any, focal: Any, shape: tuple[int, ...], what: str) -> tuple[np.ndarray, float]:
    """``depth`` (as it is, no copy) of ``shape`` and float, ``focal`` a float above 0, or an :class:`InputError`
    naming ``what``."""
    z = np.asarray(depth)
    if z.shape != tuple(shape) or z.dtype.kind != "f":
        raise InputError(f"{what}: depth must be float metres of the masks' shape {tuple(shape)}, got {z.dtype} "
                         f"{z.shape}")  # fmt: skip
    f = float(focal)
    if not (np.isfinite(f) and f > 0.0):
        raise InputError(f"{what}: focal must be a positive number of pixels, got {focal!r}")
    return z, f


def front_ring(depth: np.ndarray, mask: np.ndarray, focal: float, settings: ExtractSettings | None = None, *,
               read: list[Reading] | None = None) -> np.ndarray:  # fmt: skip
    """(h, w) bool: the pixels outside ``mask`` but within its convex hull that lie in front of its fruit: depth
    (metres, the same (h, w) window; 0 or NaN: none) nearer than the fruit's front
    (:func:`~symfruit.core.surface.fruit_surface`'s, the nearest depth of the mask's depth mode) by more than the
    registration's free-side tolerance (three noise deviations, at least 3 mm); and the pixels without depth within
    ``_FREE_PX`` of one (the mixed pixels a time-of-flight camera invalidates along the occluder's edge, as the
    registration reads them: stop 62, docs/leaf62.md). All false where there is none.

    A mask cut in two, or notched, by a leaf or twig crossing its fruit ends at the occluder's edge, not at the
    fruit's: the ring just outside it that :func:`~symfruit.core.surface.colour_trim` compares the mask's band with
    lies on the occluder there, and no overshoot lies on something in front. Where the occluder shows the fruit's own
    colour (a red twig, a stalk, the fruit between two leaves) the two summaries did not separate at the band, and a
    band twice as wide was taken all round (the real spheres cut by a strip 5 cm in front: 1,066 of the 125 mm
    sphere's 4,509 px; docs/strip58.md, cause 1). Only within the hull: a support beside the fruit comes nearer than
    its front away from it (a board below the fruit seen obliquely, 6 mm nearer a row: the real spheres' masks grown
    10 px), and does not cross it (issue 18, strip64, docs/strip64.md).

    ``read``: a list given the fruit's surface's :class:`~symfruit.core.surface.Reading` where one is made (its front
    and noise read on the mask's box alone), for :func:`own_cap` of the same mask on the same depth (surf65)."""
    s = settings or ExtractSettings()
    z, focal = _depth_checked(depth, focal, np.shape(mask), "front_ring")
    z, mask = np.asarray(z, dtype=np.float64), np.asarray(mask, dtype=bool)
    zv = _usable_depth(z, mask, s)
    valid = zv > 0.0
    with np.errstate(invalid="ignore"):
        lost = ~(z > 0)
    out = np.zeros(mask.shape, bool)
    seen = z[mask & valid]
    if not seen.size:
        return out
    # the fruit's front lies at or before its mask's farthest depth, and the tolerance is 3 mm or more: nothing can
    # be in front where nothing outside is nearer than that (the hull and the fruit's surface are then not looked for)
    ahead = ~mask & valid & (z < float(seen.max()) - 0.003)
    if not ahead.any():
        return out
    ahead &= convex_hull_mask(mask)
    if not ahead.any():
        return out
    found: list[np.ndarray] = []

    def wanted(front: float, noise: float) -> bool:
        """Whether anything ahead lies nearer than the fruit's front by the free side's tolerance (``_free_tol``'s):
        else the ring is empty whatever the fruit's surface, whose slab and cap are then not worked out (front64)."""
        found.append(valid & (zv < front - _free_tol_of(noise)))
        return bool((ahead & found[0]).any())

    surface = fruit_surface(zv, mask, focal, slab=s.slab,
                            tolerance=s.convex_tolerance if s.convex_tolerance > 0 else np.inf, thin=True,
                            clean=True, wanted=wanted, read=read)  # fmt: skip
    if surface is None:
        return out
    nearer = found[0]
    ahead &= nearer
    # and the mask's own pixels whose depth lies in front of the fruit too, with those without depth beside them (an
    # overshoot onto the occluder and its mixed pixels), which the ring without the occluder does not give back
    out = ahead | (lost & ~mask & within(ahead, _FREE_PX))
    if (on := nearer & mask).any():
        out |= on | (lost & mask & within(on, _FREE_PX))
    return out


def _usable_depth(z: np.ndarray, mask: np.ndarray, s: ExtractSettings) -> np.ndarray:
    """(h, w) float: the depth ``z`` (metres, float64) where it is finite, above 0 and within the settings' range,
    0 elsewhere, as :func:`fruit_surface` reads it (:func:`own_cap`, :func:`front_ring`); by the extraction's kernel
    where numba is (the same map: stop 62, cap62)."""
    if (jit := compiled()) is not None and z.ndim == 2:
        valid = np.empty(z.shape)  # z > 0 and z >= the least depth is z >= the larger of it and the least double
        jit.valid_depth(z, mask, max(float(s.min_depth), 5e-324), float(s.max_depth), valid, np.empty(z.shape, bool))
        return valid
    with np.errstate(invalid="ignore"):
        return np.where(np.isfinite(z) & (z >= s.min_depth) & (z <= s.max_depth) & (z > 0), z, 0.0)


def own_cap(depth: np.ndarray, mask: np.ndarray, focal: float, settings: ExtractSettings | None = None, *,
            known: Reading | None = None) -> np.ndarray:  # fmt: skip
    """(h, w) bool: the pixels of ``mask`` whose depth (metres, the same (h, w) window; 0 or NaN: none) lies on the
    fruit's own surface: the convex cap from its nearest point (:func:`~symfruit.core.surface.fruit_surface`, with
    the settings' slab and convexity tolerance), no deeper than its front plus its radius (and the convexity test's
    tolerance, 3 noise deviations and at least 3 mm: the registration's free-side depth).

    A round fruit's seen surface runs from its front to its rim, at most a radius behind it, and recedes smoothly
    the whole way; what meets it at its outline at about that depth meets it at a crease (a board or a branch
    turning back towards the camera, a neighbour's front), where the convex cap stops, and what lies behind it lies
    deeper than the rim. So a pixel of the cap is the fruit's, whatever its colour: :func:`trim_mask` does not take
    it (``trim_keeps_surface``). ``known``: :func:`front_ring`'s reading of the mask's surface, taken where it was
    read from the same box, depth and mask (:func:`~symfruit.core.surface.fruit_surface`'s ``known``; surf65)."""
    s = settings or ExtractSettings()
    z, focal = _depth_checked(depth, focal, np.shape(mask), "own_cap")
    mask = np.asarray(mask, dtype=bool)
    z = _usable_depth(np.asarray(z, dtype=np.float64), mask, s)
    surface = fruit_surface(z, mask, focal, slab=s.slab,
                            tolerance=s.convex_tolerance if s.convex_tolerance > 0 else np.inf, thin=True,
                            clean=True, known=known)  # fmt: skip
    if surface is None:
        return np.zeros(np.shape(mask), bool)
    # the rim's depth: the front plus the radius, plus the convexity test's tolerance (the registration's free test's)
    rim = surface.front + surface.radius + max(3.0 * surface.noise, 0.003)
    return surface.pixels & (z > 0.0) & (z <= rim)


def keep_caps(drawn: np.ndarray, trimmed: np.ndarray, moved: np.ndarray, ids: set[int],
              boxes: list[tuple[slice, slice] | None], shift: tuple[int, int], depth: np.ndarray, focal: float,
              settings: ExtractSettings | None = None, *,
              readings: dict[int, Reading] | None = None) -> np.ndarray:  # fmt: skip
    """``moved`` (the colour-trimmed masks ``trimmed`` moved by ``shift`` onto the depth image, :func:`register`)
    with what each mask of ``ids`` lost to a one-sided colour cut (:func:`one_sided`) given back where its depth, read
    where the registration puts it, lies on the fruit's own convex cap (:func:`own_cap`); of a cut all round (an
    overshoot), only what the colour took deeper inside the mask than the cut reaches along most of its outline
    (:func:`beyond_even_cut`: an overshoot is about as wide all round, the rest a shaded limb; stop 62,
    docs/grown62.md); ``moved`` itself when nothing is given back (``trim_keeps_surface`` off, or no such pixel).

    :func:`trim_mask`'s veto done after the registration (issue 18, stop 61, docs/small61.md): the registration reads
    the masks as the colour alone trimmed them, so what the cap keeps cannot move the frame's shift (done before it,
    the pixels kept moved the shift of a frame of rendered apple trees by a pixel, and a half-hidden apple's points
    went to the leaf in front of it: docs/trim58.md), and the cap is read on the depth the mask is moved onto, not
    on the depth a few pixels off. ``drawn``: the masks as found (their boxes ``boxes``), ``depth`` metres,
    ``focal`` pixels. ``readings``: :func:`front_ring`'s readings of the drawn masks by label, on the depth moved back
    by ``shift`` (``detect._front_trimmed``'s), each taken by :func:`own_cap` where it holds (surf65)."""
    s = settings or ExtractSettings()
    if not s.trim_keeps_surface or not ids:
        return moved
    du, dv = shift
    h, w = moved.shape
    out = moved
    for k in sorted(ids):
        sl = boxes[k - 1]
        if sl is None:
            continue
        r0, r1, c0, c1 = sl[0].start, sl[0].stop, sl[1].start, sl[1].stop
        mask = drawn[r0:r1, c0:c1] == k
        dropped = mask & (trimmed[r0:r1, c0:c1] != k)
        if not dropped.any():
            continue
        if not one_sided(mask, dropped):
            dropped = beyond_even_cut(mask, dropped)
            if not dropped.any():
                continue
        # the window moved onto the depth image; what falls off the image has no depth
        a0, a1, b0, b1 = max(r0 + dv, 0), min(r1 + dv, h), max(c0 + du, 0), min(c1 + du, w)
        if a0 >= a1 or b0 >= b1:
            continue
        inside = (slice(a0 - r0 - dv, a1 - r0 - dv), slice(b0 - c0 - du, b1 - c0 - du))
        seen, free = depth[a0:a1, b0:b1], out[a0:a1, b0:b1] == 0
        with np.errstate(invalid="ignore"):
            if not (dropped[inside] & free & (seen > 0.0) & (seen >= s.min_depth) & (seen <= s.max_depth)).any():
                # the cap holds depth in range alone (own_cap's), and gives back no pixel another mask holds: nothing
                # to give back (a time-of-flight camera's lost rim; stop 62: a cut under a neighbour's mask)
                continue
        z = np.zeros(mask.shape)
        z[inside] = seen
        known = None if readings is None else readings.get(k)
        keep = dropped[inside] & own_cap(z, mask, focal, s, known=known)[inside] & free
        if keep.any():
            out = out.copy() if out is moved else out
            out[a0:a1, b0:b1][keep] = k
    return out


def register(
    labels: np.ndarray, depth: np.ndarray, camera: Camera, settings: ExtractSettings | None = None,
    *, boxes: list[tuple[slice, slice] | None] | None = None,
) -> tuple[np.ndarray, tuple[int, int]]:  # fmt: skip
    """The masks moved onto the depth image, and the shift ``(du, dv)`` (pixels) they were moved by.

    :func:`~symfruit.core.surface.registration_shift` within ``registration_px``; ``(0, 0)`` and the masks as they
    are when the frame is registered well enough or the masks do not say. ``boxes``: ``ndimage.find_objects(labels)``
    when the caller has it.
    """
    labels = _checked(labels, depth, camera, settings, "register", "labels")
    s = settings or ExtractSettings()
    z = np.asarray(depth)  # float64 window by window (registration_shift): no float64 copy of the whole frame
    du, dv = registration_shift(z, labels, float(np.sqrt(camera.fx * camera.fy)), max_px=s.registration_px,
                                depth_range=(s.min_depth, s.max_depth), boxes=boxes,
                                occluders=s.occluder_edges)  # fmt: skip
    return (shift_labels(labels, du, dv) if (du, dv) != (0, 0) else labels), (du, dv)
