"""``paper``: the symmetry completion of Ge et al. (sections 3.2-3.6), faithfully and vectorised.

All hypotheses and all points are mirrored and rated at once (:func:`symfruit.core.rating.rate_planes`);
the algorithm itself is :func:`symfruit.core.symmetry.complete_by_symmetry`. How the paper's gaps and
slips are read is documented in :mod:`symfruit.core.rating` and on :class:`PaperSettings`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from ..core.camera import Camera
from ..core.planes import PlaneGrid
from ..core.rating import Table1
from ..core.symmetry import complete_by_symmetry
from ..settings import Section, SettingError, setting
from .registry import Completion, register

__all__ = ["PaperSettings"]

#: Most hypotheses one rating may hold (memory grows with hypotheses x rated points).
MAX_HYPOTHESES = 200_000


@dataclass(frozen=True)
class PaperSettings(Section):
    """Settings of the ``paper`` method (Ge et al., sections 3.2-3.6, Table 1).

    Hypotheses (section 3.3). Planes are ``m * j * k`` combinations, ordered translation-major
    then rotation about x then rotation about y (ties go to the first, as in the paper).

    Attributes
    ----------
    translations : int
        ``m``, number of depth offsets of the plane point (paper: 4).
    translation_step : float
        ``delta_d`` as a fraction of the depth extent of the visible points (paper: 0.2).
    translation_first : float
        Offset of the first translation, in steps. The paper does not say where the ``m``
        offsets start; 0 puts the first plane through the centroid and the others behind it,
        away from the camera, where the true symmetry plane of a front view lies (the visible
        centroid is always in front of the fruit's centre).
    rotations_x, rotations_y : int
        ``j`` and ``k`` (paper: 11 and 3), centred on zero: angles are
        ``(i - (j - 1) / 2) * step`` for ``i`` in ``0..j-1``.
    rotation_x_step, rotation_y_step : float, degrees
        ``delta_theta_1``, ``delta_theta_2`` (paper: 5 and 5). The paper's Eq. 3 prints a rotation
        about z, which leaves a +z normal unchanged and so cannot generate its Fig. 2; we take it as
        a typo and rotate the normal ``n = R_y(b) @ R_x(a) @ (0, 0, 1)``.
    j1, j2, j3 : float
        Table 1: ``Dist_tol = j1 * Dist_ref``, ``Dist2c_0 = j2 * Dist_ref``,
        ``Dist2c_1 = j3 * Dist_ref`` (0.05, 0.6, 1.2).
    k1, k3 : float
        Table 1 rating constants (10 and 1).
    k2, k4, k5 : float or None
        Table 1 gives ``1/j1``, ``1/j2``, ``1/j3``; None means exactly that. (The text says
        ``k5 = 1``; Table 1 wins because only ``1/j3`` makes Eq. 10 equal -1 at the border of
        location 4-3, the value the text asks of "close to the reasonable region".)
    scoring : {"continuous", "literal"}
        How the equations are read; see :mod:`symfruit.core.rating`. ``continuous`` (default) makes
        every score continuous at the region borders; ``literal`` uses Eqs. 6-10 as printed.
    centre : {"centroid", "box"}
        The "centre of original points" that ``Dist2c`` is measured from: the mean of the visible
        points (paper) or the centre of their box.
    fill_radius : float or None, pixels
        Radius of the square that closes the gaps between projected points when the visible mask
        ``Mp`` is rasterised. None estimates it from the density of the projected points.
    precision : {"single", "double"}
        Floating-point precision of the rating (the hot path). Single precision works relative to
        the visible centre, so it keeps well under a micrometre at fruit scale and is about twice as
        fast; the chosen plane and the completed cloud are always computed in double precision.
    rating_points : int or None
        Rate the hypotheses on a fixed random subset of at most this many visible points (the mask
        and the completion use all of them). The paper's fruit had about 600 points; a fruit close
        to a D435 has several thousand, and a 1,500-point subset ranks the planes alike while keeping
        the cost flat. None rates every point.
    """

    translations: int = setting(4, ge=1, le=1000)
    translation_step: float = setting(0.2, ge=0.0, le=10.0)
    translation_first: float = setting(0.0, ge=-1000.0, le=1000.0)
    rotations_x: int = setting(11, ge=1, le=3600)
    rotation_x_step: float = setting(5.0, ge=-90.0, le=90.0)
    rotations_y: int = setting(3, ge=1, le=3600)
    rotation_y_step: float = setting(5.0, ge=-90.0, le=90.0)
    j1: float = setting(0.05, gt=0.0, le=10.0)
    j2: float = setting(0.6, gt=0.0, le=10.0)
    j3: float = setting(1.2, gt=0.0, le=10.0)
    k1: float = setting(10.0, gt=0.0, le=1e6)
    k2: float | None = setting(None, gt=0.0, le=1e6)
    k3: float = setting(1.0, gt=0.0, le=1e6)
    k4: float | None = setting(None, gt=0.0, le=1e6)
    k5: float | None = setting(None, gt=0.0, le=1e6)
    scoring: Literal["continuous", "literal"] = setting("continuous")
    centre: Literal["centroid", "box"] = setting("centroid")
    fill_radius: float | None = setting(None, ge=0.0, le=100.0)
    precision: Literal["single", "double"] = setting("single")
    rating_points: int | None = setting(1500, ge=10, le=1_000_000)

    def check(self) -> None:
        if self.n_hypotheses > MAX_HYPOTHESES:
            raise SettingError("", f"{self.n_hypotheses} hypotheses (translations x rotations_x x rotations_y) "
                                   f"exceed {MAX_HYPOTHESES}; lower the counts")  # fmt: skip
        if self.j2 >= self.j3:
            raise SettingError("j2", "must be smaller than j3 (Dist2c_0 < Dist2c_1)")

    @property
    def table(self) -> Table1:
        """The rating constants as :class:`~symfruit.core.rating.Table1`."""
        return Table1(j1=self.j1, j2=self.j2, j3=self.j3, k1=self.k1, k2=self.k2, k3=self.k3, k4=self.k4,
                      k5=self.k5)  # fmt: skip

    @property
    def k2_value(self) -> float:
        return self.table.k2_value

    @property
    def k4_value(self) -> float:
        return self.table.k4_value

    @property
    def k5_value(self) -> float:
        return self.table.k5_value

    @property
    def grid(self) -> PlaneGrid:
        """The hypothesis grid these settings describe."""
        return PlaneGrid(self.translations, self.translation_step, self.translation_first, self.rotations_x,
                         self.rotation_x_step, self.rotations_y, self.rotation_y_step)  # fmt: skip

    @property
    def n_hypotheses(self) -> int:
        return len(self.grid)

    def options(self) -> dict[str, Any]:
        """Keyword arguments of :func:`~symfruit.core.symmetry.complete_by_symmetry`."""
        return {
            "grid": self.grid, "table": self.table, "scoring": self.scoring,
            "centre": self.centre, "fill_radius": self.fill_radius, "precision": self.precision,
            "rating_points": self.rating_points,
        }  # fmt: skip


@register("paper", settings=PaperSettings)
def paper(points: np.ndarray, camera: Camera, settings: PaperSettings) -> Completion:
    """Ge et al.: hypothesise mirror planes, rate every mirrored point, keep the best; box the merge."""
    done = complete_by_symmetry(points, camera, **settings.options())
    return Completion(points=done.points, box=done.box, plane=done.plane, score=done.score, scores=done.scores,
                      planes=done.planes, extras=done.extras())  # fmt: skip
