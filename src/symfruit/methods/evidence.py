"""``evidence``: the default method. The candidate completions that best explain what the camera saw.

Why: a sphere is right for round fruit and wrong for a pear; a solid of revolution is right for a pear
and can take the wrong axis on a near-round fruit; a general ellipsoid fitted to a noisy partial view
comes out too thin; mirror symmetry (the paper) is blind to how deep its plane should be. No single
completion is right for every fruit, and the view itself says which ones fit. This method

1. estimates the front depth from a quadric fitted around the nearest part of the surface
   (:func:`~symfruit.core.front.apex_depth`; the noisy minimum of a D435's depths sits 3-4 mm in front of
   the fruit), shared by every candidate; where a leaf hides the fruit's nearest part, the front of the sphere
   as wide as the outline through the seen points instead (:func:`hidden_front`);
2. fits the candidates of :mod:`symfruit.core.candidates`: a sphere, a general (Li-Griffiths) ellipsoid,
   the ellipsoid whose outline is the silhouette (``cone``: five of its nine degrees of freedom come from
   the silhouette, which a depth camera measures far better than depth), a solid of revolution,
   optionally the mirror completion, and the raw box;
3. measures every closed candidate against the view (:func:`~symfruit.core.agreement.explain`): its
   predicted front depth against the seen depths and its predicted outline against the seen one (rays
   just inside the silhouette must hit it, rays just outside a contour part of the edge must miss it);
4. weighs the candidates by ``exp(-energy)``, with the energy of a closed candidate
   ``depth_weight * log(rms / best rms) + silhouette_weight * (inside + outside)`` (the profile
   log-likelihood of the depths, tempered, and the shares of band rays it gets wrong); candidates whose
   premise the view can contradict pay for it: the ``cone`` ellipsoid and the raw box (both assume the
   seen outline is the fruit's silhouette) ``cut_energy`` times the share of the edge that is a cut rather
   than a contour, the unconstrained ellipsoid ``noise_energy`` times how far the view is a noisy depth
   view rather than a clean scan; the raw box ("nothing hidden") and the mirror completion, which
   reproduce the view by construction, have fixed energies (raw: the fallback when the best closed shape
   gets about half the band rays wrong);
5. takes the weighted median of every box face (robust to one wrong candidate, unlike a mean);
6. moves the back face, the one face no pixel sees, towards a prior on the fruit's depth-to-width ratio by
   the two estimates' uncertainties (:func:`fuse_depth`): a fruit is about as deep as its silhouette is
   wide across the line of sight (solids of revolution seen across their axis exactly), so on a noisy,
   distant or distorted view the shapes' extrapolation of the front's curvature gives way to the
   silhouette, which a camera measures well; on a clean close view the shapes keep most of their say; the
   back face never ends in front of the deepest seen point (the fruit holds every point seen of it);
7. predicts its centre's uncertainty (millimetres, ``extras["uncertainty"]``) from the best-posed fit's
   own noise, the candidates' disagreement, what no candidate explains (of the outline, and of the seen
   depths beyond the sensor's noise), how far the prior moved the back face from the shapes' (half of it,
   as the centre moves), how far the fruit recedes along the line of sight, how much of the outline is a
   cut and how far the silhouette's lateral extent disagrees with the shapes' box, all scaled by the
   outline's elongation, and reports
   ``confidence = exp(-uncertainty / 3 mm)`` and ``reliable = uncertainty <= 3 mm``.

No fruit profile is needed: nothing in it depends on the kind of fruit. The design and the ablation
behind every constant are in ``docs/ablation.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Literal

import numpy as np
from scipy import ndimage

from ..core.agreement import Observation, observe
from ..core.box import Box
from ..core.camera import Camera
from ..core.candidates import SHAPES, Candidate, candidates
from ..core.fits import noise_level, noise_measures
from ..core.front import apex_depth, sphere_front, sphere_front_behind
from ..core.kernels import compiled
from ..core.occlusion import Occlusion, bridged, with_own
from ..core.points import bounds, row_norms, subsample
from ..core.raster import (
    Across,
    Silhouette,
    Tilt,
    across_sight,
    axis_tilt,
    bracket_tilt,
    close_ragged,
    cone_widths,
    free_side_reach,
    inner_distance,
    outline_circle,
    pixel_count,
    point_pixels,
    silhouette,
    silhouette_cone,
    tangent_extent,
    width_across,
)
from ..settings import Section, SettingError, setting
from .paper import PaperSettings
from .registry import Completion, register

__all__ = ["Combined", "EvidenceSettings", "clean_share", "combine", "fuse_depth", "lost_rim", "prior_width"]

#: ``hidden_front``'s sphere (:func:`~symfruit.core.front.sphere_front`) stops its Gauss-Newton once a step moves the
#: centre by less than this, metres (issue 19, stop 55: 10 um instead of its default 0.1 um, about two steps fewer of
#: some six; on the benchmark frames each step moved it at most 0.4 times the last, so less than 10 um is left,
#: docs/fast55.md).
FRONT_TOLERANCE = 1e-5


@dataclass(frozen=True)
class EvidenceSettings(Section):
    """Settings of the default ``evidence`` method.

    Attributes
    ----------
    fit_points : int
        Shapes are fitted to a fixed random subset of at most this many points (the box and the
        silhouette use every point).
    revolution_points : int
        The solid of revolution is fitted to at most this many of them.
    ragged_close_px, ragged_at : int, float
        The seen region's gaps are closed by a square of this half-width when its outline is ragged
        (:func:`~symfruit.core.raster.close_ragged`: a sensor's dropout at the rim shrinks the outline,
        and with it every shape fitted to it).
    rays, band_rays : int
        Depth rays sampled over the seen points, and rays per silhouette band and side.
    march_steps : int
        Ray-march steps per ray through each candidate.
    revolution_coarse : int
        Directions of the solid of revolution's coarse axis search (the ellipsoids' axes are added).
    sections : float in [0, 1]
        On a sparse cloud (not a depth camera's view): how far the solid of revolution's sections go from circles
        towards the depth-over-width ratio the view shows (:func:`~symfruit.core.candidates.section_ratio`; issue 18,
        stop 47, docs/pearview47.md: circles through a section flatter in depth than across over-extend the back).
        Not on a camera's view, whose rim perspective puts in front of the sections' widest. 0 (circles, the default):
        0.5 gains on the generated paper protocol and loses the real pear hanging (the check), docs/pearview47.md.
    covered_contour : float in [0, 1]
        In a depth camera's view (about a point per pixel of the silhouette) whose outline is at least this
        much an occluding contour, the sphere and the unconstrained ellipsoid are not fitted: the ``cone``
        ellipsoid covers both.
    explained_at : float
        There, when the ``cone`` ellipsoid gets at most this share of the silhouette-band rays wrong, the
        solid of revolution is not fitted either (the ablation: the same means, half the views cheaper).
    temperature : float
        Weights are ``exp(-energy / temperature)``: the energies count about ``rays`` correlated ray residuals
        as if they were independent, which makes the plain ``exp(-energy)`` far too sure of the best
        candidate (issue 18's diagnosis; 2 keeps the ranking and lets close candidates share the box).
    back_trim : float in [0, 0.5]
        The candidates' back face is their weighted mean over the weighted quantiles ``back_trim`` to ``1 -
        back_trim`` of their back faces (:func:`midmean`: 0.25, the interquartile mean; 0.5, the default, the
        weighted median, as every other face). The weighted median takes one candidate's back face whole, and
        where two shapes share the weight it jumps between them with noise in the weights; the back face is where
        the centre's error lies (issue 18: 94-96 % of its square, docs/paper46.md).
    depth_ratio, depth_ratio_sd : float, float
        The prior on the depth extent: ``depth_ratio`` times the silhouette's width (the geometric mean of its
        widths across and along its principal axis, measured across the line of sight through its centroid
        at the box centre's distance, :func:`~symfruit.core.raster.across_sight`: a fruit off the optical axis
        projects stretched by ``1 / cos`` of its angle), with standard deviation ``depth_ratio_sd`` times that
        width, divided by the outline's contour share (a cut outline's width says less). Over the generated
        kinds' views the true ratio is 0.85-1.08 by kind (round fruit 1.00-1.08, SD 0.02-0.08 within a kind;
        elongated fruit, whose long axis lies in the image, lower); 1.0 and 0.1 are the round numbers that
        cover them;
        ``depth_ratio_sd = 0`` switches the prior off. Where much of the outline is cut, the width moves from
        that geometric mean towards the larger width (``cut_width``, :func:`prior_width`).
    cut_width : float in [0, 1]
        How far a cut outline's width moves towards its larger width: the prior's log-width is the geometric
        mean's plus ``cut_width`` times the square of the cut share (``1 - contour``) times half the log of the
        larger over the smaller width (:func:`prior_width`). An occluder or the image border only ever shortens
        an outline, and most across the cut: the smaller width of a mostly hidden fruit measures the cut more
        than the fruit, while the larger one, the least shortened, is still at most the fruit's extent, which is
        its depth only for a round fruit: 0, the default, keeps the geometric mean whatever the cut; the apple
        profile sets 1 (mostly hidden apples' boxes were 9 mm too shallow, docs/ablation.md "Hidden apples'
        boxes"). Not the default: on an elongated fruit the larger width is its length, and through the D435
        model the real scans (a banana and a pear) fell from 0.634 / 14.3 mm to 0.607 / 16.9 with it.
    cut_prior : {"sides", "outline", "ellipse"}
        ``ellipse``: with occlusion information, where part of the outline is cut and the ellipse fitted to its
        contour part was taken for the viewing cone (:func:`~symfruit.core.agreement.observe`, ``contour_cone``),
        the prior's width is that ellipse's (the geometric mean of its widths across the line of sight,
        :func:`~symfruit.core.raster.cone_widths`) where that is wider than the cut region's (an occluder only ever
        narrows an outline): the free arcs of the outline are the fruit's own and lie on its whole silhouette. On
        the real spheres with a leaf over a third of each and the mask cut, depth sides 19.7 -> 9.8 mm short; the
        development apple trees' depth sides 4.8 -> 4.5 mm, their centres 3.8 -> 3.9 mm; but through the camera
        models with a leaf in front every kind's boxes grew too deep (Azure Kinect, 25 % hidden: 6.95 -> 7.91 mm,
        depth side +0.2 -> +3.4 mm; stop 56, docs/strip56.md), so not the default. ``sides`` (stop 57,
        docs/cutprior57.md): the ellipse is read only where the outline is cut, along the cut region's two principal
        axes (:func:`~symfruit.core.raster.free_side_stretch`): a side whose outermost outline is the fruit's own
        contour keeps the region's extent, a cut side reaches to the ellipse's, no axis beyond the region's widest
        extent, and nothing moves where the ellipse's centre (a round fruit's nearest point) is hidden (the seen front
        then lies behind the fruit's, and a full-width prior from it runs the back face too far). The real spheres
        with a leaf over a third of each, the mask cut: depth sides 20.4 -> 8.5 mm short; the masks dilated 10 px
        unchanged (the ellipse: +16 -> +25 mm); the development and held-out apple trees' depth sides 4.72 -> 4.54
        and 5.1 -> 4.9 mm; through the Azure Kinect model with a leaf in front the depth side at 50 % hidden 7.6 ->
        6.9 mm, while the centre error grows (25 % hidden 6.95 -> 7.35 mm, 50 % 9.16 -> 9.35: the model's front
        lies 3.9 mm behind the true one, its range bias, which a too-short box had hidden). The default since stop
        57. ``outline``: the cut region's widths, moved by ``cut_width`` (the default before).
    cut_faces : {"sides", "region"}
        With ``cut_prior: sides``, where a side of the outline is cut and the fruit goes on behind it
        (:func:`~symfruit.core.raster.free_side_reach`): ``sides`` (stop 58, docs/cut58.md) moves the silhouette's
        lateral face on that side, which :func:`fuse_depth` pulls the box's towards, to where the fruit ends there
        (the outermost point there of the ellipse through the free arcs, no axis beyond the region's widest
        extent), so that the box's side across a cut is neither stopped at the leaf nor run past the fruit (pulled
        out by the prior's share, in by that times the contour share squared); ``region``: the cut region's face
        (the default before). The real spheres with a leaf over a third of each, the mask cut: the 200 mm sphere's
        x side 183 -> 198 mm; the development apple trees' centres 3.87 -> 3.83 mm.
    cut_reach : {"widest", "contour"}
        On a cut outline (some of it not a contour), how far :func:`fuse_depth` pulls in a lateral face of the box
        that runs past the silhouette's: ``contour`` (the default before) by the prior's share times the contour
        share squared, however far (a cut hides how far the fruit goes on). ``widest`` (stop 59, docs/leafcut59.md):
        the part of those runs by which the box is longer along that axis than the outline's widest extent (along
        its principal axes or the tangent axes) is pulled in by the prior's share alone, as an uncut outline's face
        is. A cut only ever shortens an outline, so its widest extent is the least shortened, and a round fruit is no
        longer any way than that; only an elongated one behind the cut is, which the shapes (not the round prior)
        must then show: the pull is the prior's share of the back face, small where the shapes agree (no threshold).
        The real spheres with a leaf over a third of each, the mask cut: the 66 mm sphere's 106 mm height (a solid of
        revolution 38 mm down behind the leaf) 106 -> 79 mm, not-a-cube 15.2 -> 11.6 mm; the development apple trees
        (seeds 0-3 and 6-11) IoU 0.799 -> 0.800 and 0.766 -> 0.770, the larger lateral side 3.09 -> 2.90 and 4.10 ->
        3.39 mm.
    cut_spread : {"ellipse", "contour"}
        The depth prior's spread on a cut outline: ``contour`` (the default before) divides it by the contour share
        (a cut outline's width says less), also where its width is read from the ellipse through the free arcs
        (``cut_prior``); ``ellipse`` (stop 59, docs/leafcut59.md) divides it by nothing where that ellipse's width
        is taken (wider than the cut outline's): the width is then the whole outline's, not the cut one's. On the
        real spheres cut by a leaf the prior took 0.68-0.70 of the 125 mm sphere's back face, against 0.93 uncut, and
        the shapes' back (24 mm short on a time-of-flight camera's lost rim) kept the rest: depth 115 -> 120-122 mm.
    lost_rim : {"pull", "bound", "least", "cap"}
        How :func:`fuse_depth` reads the shapes' back face where the seen region's rim holds no points
        (:func:`rim_coverage` under 1: a time-of-flight camera's lost rim) and it lies in front of the prior's:
        ``pull`` (the default before stop 63) as an estimate with the lost rim's error (``rim_error``) added to its
        spread, so that it pulls the box's back towards itself; ``bound`` (the default since stop 63,
        docs/prior63.md) as what it is, a lower bound: a shape fitted to a cap without its rim comes out short,
        never deep, by up to that error, so where the prior's back lies within it the prior alone decides, and
        beyond it the shapes' clean error pulls. With the rim seen (``rim`` 1) the two are the same. On the real
        spheres, with ``extract.occluder_edges`` (the true registration), the 60 mm sphere behind a leaf or strip
        53-54 -> 60-61 mm deep (its cap's cone 24-31 mm), the perturbed frames' boxes over the 6 mm bar 33 -> 22 of
        208, the unperturbed boxes' depth sides 2.0 -> 1.1 mm off. What it costs: a mask grown 2 px boxes the 60 mm
        sphere as a 66-67 mm cube (6.1 mm deep over, 2 -> 4 of 8); the development apple trees' depth sides 4.7 ->
        4.3 and 5.0 -> 4.6 mm, but their centres 4.2 -> 4.5 and 5.2 -> 5.3 mm (the Azure Kinect model they are
        rendered through sees 3.4-3.8 mm too far there, its range bias, which the prior's back, ``front + width``,
        keeps and the shapes' short back had offset); on lone generated fruit, whose boxes are already deep, the
        camera models' centres 0.1-0.4 mm farther off (README "Real cameras", stop 63). ``least`` (stop 64, off,
        docs/lone64.md): the lower bound is raised no farther than the least depth the prior allows, the
        outline's smaller width (:func:`prior_width` ``least``; a solid of revolution lying in the image is as deep as
        that if prolate, as its larger width if oblate, and the prior's geometric mean is the middle of that range),
        beyond which the shapes' clean error holds it against the prior; a shapes' back beyond that least depth is read
        as ``pull`` reads it. On a round outline ``least`` is ``bound``, and on a cut one (under ``covered_contour`` of
        it a contour), whose smaller width measures the cut, and on the points' own outline (no mask: a lost rim narrows
        it by a band on every side, more across than along). The lone generated fruit through the camera models: centre
        5.54 / 5.12 / 4.16 / 3.78 mm (``bound``; ``pull`` 5.42 / 4.78 / 3.99 / 3.41) -> 4.57 / 4.55 / 3.86 / 3.24 (Azure
        Kinect, L515, D435, D405), the lemons and pears most; the perturbed real frames 22 of 208 over the bar either
        way; the development apple trees (CW1) seeds 0-3 IoU 0.796 -> 0.794, depth side 4.3 -> 4.5 mm, seeds 6-11 0.771
        -> 0.774, centre 5.3 -> 5.2 mm. Without the whole-outline condition the trees' depth sides were 5.1 and 5.3 mm
        and the real frames' leaf cuts 2 of 8 over (from 0). Not the default: the held-out apple trees (seeds 100-111,
        CW1, by label) read depth side 5.2 (-3.4) -> 5.6 (-3.9) mm, the visible apples' 4.0 -> 4.7 (an apple hangs
        oblate, as deep as its larger width, and the smaller is the least); for elongated fruit seen side on (pears,
        lemons) it is the better reading. ``cap`` (stop 64, off, docs/tilt64.md): ``least``'s reach as far as the
        seen cap says prolate (:meth:`~symfruit.core.raster.Tilt.oblate_share` of the fit
        :func:`~symfruit.core.raster.axis_tilt` makes with ``tilt_outline`` and ``tilt_blocks``, read whatever
        ``prior_tilt`` is): the reach is the smaller width to the power ``1 - 2 share`` times the mean's to the rest,
        the mean's from half-way on and where no tilt is read. The lone generated fruit through the Azure Kinect model
        (``tilt_outline: mask, tilt_blocks: 8``): centre 5.54 (``bound``) / 4.57 (``least``) -> 4.95 mm; the
        development trees' (CW1) visible apples' depth sides 3.6 / 3.9 -> 3.8 mm (seeds 0-3) and 3.6 / 3.9 -> 3.7 mm
        (seeds 6-11): the tree apples' caps read prolate more often than the lone ones'.
    cut_circle : {"free", "off"}
        With ``cut_prior: sides``, where the outline is cut and no ellipse through its free arcs was accepted
        (:func:`~symfruit.core.raster.outline_cone`: on the real spheres 43-59 px across with a leaf over a third of
        each, 51-79 free outline points over a half arc, the five-parameter fit came out too small and missed holding
        the region on 100-130 degrees of arc, docs/cut58.md 1.3; nor is it tried under ``contour_cone``, as the shapes'
        viewing cone): ``free`` (stop 60, docs/cut60.md) reads the sides as ``sides`` does from the circle through the
        free arcs (:func:`~symfruit.core.raster.outline_circle`: three parameters, accepted as the ellipse is and where
        the arcs lie within half a pixel of it, root mean square, as a digitised round outline's do; a round fruit's
        free arcs give its radius, and a cut only shortens an outline). The cut sides reach the circle, no axis
        beyond the outline's widest extent seen, and the prior's spread is then an uncut outline's (``cut_spread``).
        ``off``: the cut region's widths (as before). The real spheres cut by the leaf: the 60 mm sphere 39-41 x 61 x
        41-44 -> 60 x 62 x 59 mm, the 66 mm one 58 x 79 x 62 -> 66 x 69 x 68 mm (frame 1) and 61 x 69 x 59 -> 66 x
        69 x 67 mm (frame 0, contour share 0.30); over the bar 5 / 8 -> 1 / 8. The development trees: one apple of
        248 moves (better); through the D435 model with a leaf in front 7 views of 210 (4 better).
    hidden_front : {"sphere", "off"}
        With occlusion information, where the outline is cut and the front of the sphere as wide as the outline's
        larger width that best fits the seen points lies in front of the seen front at a pixel where the camera
        could not have seen it (hidden, or in the mask without seen points), that sphere's front is the shared
        front (:func:`hidden_front`: a leaf over the fruit's nearest part, stop 46, docs/apex46.md: the dev trees'
        mostly hidden apples 7.78 -> 6.64 mm); ``off``: the seen front (``max(nearest seen depth, apex_depth)``).
    prior_tilt, tilt_floor : {"off", "cap", "prolate"}, float
        In a depth camera's view of a whole outline (at least ``covered_contour`` of it a contour), the prior's width
        from the tilt of the fruit's axis out of the image plane instead of the geometric mean
        (:func:`~symfruit.core.raster.axis_tilt`, stop 45, docs/axis45.md): ``prolate`` the depth of the prolate
        spheroid with the outline and the seen front's midline slope (its minor half-width, deeper as the axis
        tilts towards the camera), ``cap`` between that and the oblate spheroid's by the seen front's sag over the
        outline's half-width, ``off`` (the default: neither helped on every table) the geometric mean.
        ``tilt_floor``: the least ``(major^2 - minor^2) / major^2`` the midline's slope is divided by
        (:meth:`~symfruit.core.raster.Tilt.half_depths`: a near-round outline says little of the tilt; 0.3, the
        measured variant: 0.05 put the D435 model's proxies at 4.30 mm against 4.06).
    prior_axis, gravity_x, gravity_y, gravity_z : {"mean", "gravity"}, float, float, float
        Which width of the outline the prior reads (issue 18, stop 65, docs/hang65.md). ``mean`` (the default): the
        geometric mean of its widths across and along its principal axis. ``gravity``: its width across gravity
        (:func:`~symfruit.core.raster.width_across`, the camera-frame vector ``(gravity_x, gravity_y, gravity_z)``,
        REP-103's optical frame: ``(0, 1, 0)``, the default, is a level camera's down): a fruit hanging from its
        stalk is (near) a solid of revolution about the vertical, as deep along a level line of sight as it is wide
        across gravity, oblate (an apple: its larger width) or prolate (a pear: its smaller) alike. Read on a whole
        outline only (at least ``covered_contour`` of it a contour): a cut takes most off the width across it, and a
        leaf over a fruit's side takes the width across gravity itself (the real spheres' ``leafside5-cut`` boxes 22
        mm too shallow when a cut outline read it); there the mean stands. The width is held within the outline's two
        principal widths, and ``lost_rim: least`` and ``cap`` read it as their least too. Where gravity lies along
        the line of sight (within a degree), or ``prior_tilt`` reads a tilt, that reading stands. Off by default:
        docs/hang65.md.
    tilt_outline, tilt_blocks, tilt_bend : {"points", "mask", "both"}, int, bool
        How the tilt is read (stop 46, docs/tilt46.md; none is on by default, as ``prior_tilt`` is not).
        ``tilt_outline``: the points' own outline (``points``), which a time-of-flight camera's lost rim band erodes
        so that the seen front reads flatter than a round section (the Azure Kinect model's apples too shallow by
        10 mm); that outline scaled to the mask's widths (``mask``), which its annotators draw a few pixels wide;
        or both fits, with the cap as unsure as they disagree (``both``, :func:`~symfruit.core.raster.bracket_tilt`).
        ``tilt_blocks``: the fit's uncertainty from a jackknife over that many sectors of the front (0: off; a
        camera's correlated noise), which shrinks the prolate/oblate share towards the geometric mean.
        ``tilt_bend``: the midline's bow along the outline's axis (a banana hanging), whose sagitta deepens the
        prolate hypothesis as far as the outline is elongated.
    shape_error, rim_error, back_inflation : float, float, float
        The candidates' back face has standard deviation ``hypot(back_inflation * back_std, spread / 2, width *
        (shape_error + rim_error * (1 - rim)))``: the ``cone`` fit's own back-face deviation (from ray residuals
        that are correlated, so too small), half the candidates' weighted spread about the median back face,
        and what a smooth shape's extrapolation of the front misses: a little on a clean view, and up to
        ``rim_error`` widths where the seen region's rim holds no points (:func:`rim_coverage`: a
        time-of-flight camera returns no depth at grazing angles, and the shared Azure Kinect frames' spheres
        show caps tilted and flattened by tens of millimetres that any shape fits well).
    depth_weight, silhouette_weight : float
        Energy per unit of ``log(rms / best rms)`` (the depth misfit against the best closed candidate's)
        and per unit share of silhouette-band rays a closed candidate gets wrong (inside plus outside).
    cut_energy : float
        Energy of the candidates whose premise is that the seen outline is the fruit's silhouette (the
        ``cone`` ellipsoid, and ``raw``: "nothing beyond the outline"), times the share of the outline
        that is not an occluding contour (a cut: the paper's visibility rule, an occluder).
    occluded_px, thin_px, contour_cone : int, int, float
        With the frame's occlusion information (:class:`~symfruit.core.occlusion.Occlusion`): an outline pixel
        with a hidden pixel within ``occluded_px`` is a cut; hidden structures narrower than ``2 thin_px +
        1`` pixels (a stem) do not widen where the fruit can project; with at least ``contour_cone`` of the
        outline a contour (and some of it cut) the ``cone`` ellipsoid is tangent to the ellipse through the
        contour part (:func:`~symfruit.core.agreement.observe`). The seen region then includes the fruit's
        own mask.
    contour_cut_energy : float
        The ``cone`` ellipsoid's energy per unit cut share when it was fitted to the contour part of the
        outline alone (its premise, that this part is the silhouette, then holds).
    lateral_reach, depth_reach : float
        A candidate whose box is implausible for what was seen is left out (it must not win, and the
        weighted median must not follow it): one reaching beyond the seen box by more than
        ``lateral_reach`` seen extents on a side, or whose
        hidden depth beyond the deepest seen point exceeds ``depth_reach`` times the seen box's largest
        lateral side (a fruit is no deeper behind its rim than its silhouette is long;
        :func:`~symfruit.core.candidates.candidates`). In every generated and real view without an occluder
        the truth reaches at most 0.29 seen extents beyond the seen box laterally (the paper protocol's cut
        views; camera views 0.08) and 0.91 deep, except a banana stood on its end (1.5 and 1.3); a fruit
        half hidden by something the method is not told about reaches up to 1.3 seen extents: the lateral
        bound is not checked with occlusion information (which bounds where the fruit can project), so give
        :func:`symfruit.complete` the frame's occlusion information (``detect`` does) for occluded fruit.
    noise_energy, clean_ratio, noise_queries : float, float, int
        Energy of the unconstrained (Li-Griffiths) ellipsoid times how far the view is a depth camera's
        rather than a clean scan (:func:`clean_share` of the roughness ratio of
        :func:`~symfruit.core.fits.surface_noise` on ``noise_queries`` points, ``clean_ratio`` its
        midpoint): an algebraic fit of a noisy partial view comes out too thin; on a clean scan it is the
        best shape there is.
    mirror_energy, raw_energy : float
        Fixed energies of the mirror and raw candidates (raw's grows with the cut share, see above).
    misfit_scale, recede_scale, unexplained_scale, misfit_noise, cut_scale, lateral_scale : float
    uncertainty_scale, reliable_uncertainty : float (metres), float (metres)
        The predicted centre uncertainty ``u = elongation * hypot(hypot(back_std, spread) + misfit_scale * wrong * size,
        moved / 2, recede_scale * recede, unexplained_scale * unexplained, cut_scale * cut, lateral_scale * lateral)``:
        ``back_std`` the ``cone`` ellipsoid's back-face standard deviation from its own fit (the sensor's noise),
        ``spread`` the weighted mean distance of the candidates' centres from the result's (what the shapes disagree
        on), ``wrong`` the best closed candidate's share of silhouette-band rays wrong and ``size`` the result's largest
        side (what no shape explains), ``moved`` how far :func:`fuse_depth` moved the back face (the prior against the
        shapes); ``recede`` how much deeper than half the silhouette's width the points of a depth camera's view reach
        behind the front, times the contour share (a round fruit shows about half its depth in front of its rim; a fruit
        receding along the line of sight, a pear or banana pointing at the camera, has a back that nothing seen
        mirrors); ``unexplained`` the seen depths' misfit that no closed shape explains, ``sqrt(max(0, rms**2 -
        (misfit_noise * noise)**2))``, ``rms`` the best closed candidate's robust RMS depth misfit and ``noise`` the
        points' small-scale plane residual (:func:`~symfruit.core.fits.surface_noise`; a shape that does not explain the
        front it was fitted to does not predict the back it extrapolates; 0 for a sparse cloud; ``unexplained_scale`` 3:
        the back lies about a diameter behind the front the misfit was measured on, docs/conf45.md); ``cut`` the share
        of the outline that is a cut (``1 - contour``) times the shapes' box's largest side (beyond a cut nothing was
        seen of the fruit); ``lateral`` the largest distance between a lateral face of the shapes' box and the
        silhouette's extent across the line of sight at the box's distance (:func:`fuse_depth`'s, before it moves the
        faces: two measures of the fruit's width that disagree); ``elongation`` the square root of the silhouette's
        major over minor width (an elongated outline leaves the tilt of the long axis out of the image unseen, and every
        error above grows with it). ``confidence = exp(-u / uncertainty_scale)``; ``reliable`` when ``u <=
        reliable_uncertainty`` (3 mm: docs/conf45.md). Issue 18's block jackknife of the ``cone`` fit's back face
        (angular sectors of the seen depths, or of the outline, left out) was measured and predicts nothing on the real
        scans (docs/ablation.md).
    mirror_candidate : bool
        Add the mirror completion as a candidate (off by default: ~3 ms per fruit for means that moved
        by less than 0.1 mm in the ablation).
    outline_profile : {"off", "add", "replace"}
        In a depth camera's view of a whole fruit, a second solid of revolution on the same axis whose
        radii are read off the silhouette (:func:`~symfruit.core.fits.outline_radii`: the outline is
        measured to a pixel, the points' radii are blurred by depth noise): ``add`` it as the ``outline``
        candidate, ``replace`` the points' profile with it, or ``off``.
    rim_grazing : float in [0, 0.95]
        Points alone (no occlusion information) from a camera that returns no depth where the surface's normal
        makes ``|cos| < rim_grazing`` with the ray (a time-of-flight camera's lost rim; 0, the default: none, or not
        known). The points cannot tell how wide that rim is (the real Azure Kinect frames' caps are flattened, so
        neither their edge normals nor their sag measure it; docs/tofpts53.md); what they tell is whether it was
        lost: where the edge normals call at least half of a depth camera's outline a cut, the seen region is grown
        by the rim a round section loses, its equivalent radius times ``1 / sqrt(1 - rim_grazing^2) - 1``
        (:func:`lost_rim`), and is then read as a frame's mask is (the normals do not vote on it, its rim holds no
        points). The Azure Kinect model's value is 0.48 (half its grazing pixels lost there, measured on the shared
        lab frames' free sides, docs/realism44.md, docs/sensors.md "dropout"); a structured-light or stereo camera
        has none.
    mirror : PaperSettings
        The mirror candidate's grid and rating: 8 depth offsets of 0.1 ``len_depth`` and the reasonable
        region 0.4-1.0 ``Dist_ref`` (the paper's 4 x 0.2 stops short of the symmetry plane of a shallow
        view), rated on 400 points.
    """

    fit_points: int = setting(1000, ge=20, le=1_000_000)
    ragged_close_px: int = setting(3, ge=0, le=50)
    ragged_at: float = setting(0.3, ge=0.0, le=100.0)
    revolution_points: int = setting(600, ge=20, le=1_000_000)
    rays: int = setting(160, ge=8, le=100_000)
    band_rays: int = setting(64, ge=4, le=100_000)
    march_steps: int = setting(16, ge=4, le=1000)
    revolution_coarse: int = setting(64, ge=0, le=10_000)
    sections: float = setting(0.0, ge=0.0, le=1.0)
    covered_contour: float = setting(0.9, ge=0.0, le=1.0)
    explained_at: float = setting(0.02, ge=0.0, le=2.0)
    hidden_front: Literal["off", "sphere"] = setting("sphere")
    temperature: float = setting(2.0, gt=0.0, le=1e6)
    back_trim: float = setting(0.5, ge=0.0, le=0.5)
    depth_ratio: float = setting(1.0, gt=0.0, le=10.0)
    depth_ratio_sd: float = setting(0.15, ge=0.0, le=10.0)
    cut_width: float = setting(0.0, ge=0.0, le=1.0)
    cut_prior: Literal["outline", "ellipse", "sides"] = setting("sides")
    cut_faces: Literal["region", "sides"] = setting("sides")
    cut_reach: Literal["contour", "widest"] = setting("widest")
    cut_spread: Literal["contour", "ellipse"] = setting("ellipse")
    cut_circle: Literal["off", "free"] = setting("free")
    lost_rim: Literal["pull", "bound", "least", "cap"] = setting("bound")
    prior_tilt: Literal["off", "cap", "prolate"] = setting("off")
    prior_axis: Literal["mean", "gravity"] = setting("mean")
    gravity_x: float = setting(0.0, ge=-1e6, le=1e6)
    gravity_y: float = setting(1.0, ge=-1e6, le=1e6)
    gravity_z: float = setting(0.0, ge=-1e6, le=1e6)
    tilt_floor: float = setting(0.3, gt=0.0, le=1.0)
    tilt_outline: Literal["points", "mask", "both"] = setting("points")
    tilt_blocks: int = setting(0, ge=0, le=64)
    tilt_bend: bool = setting(False)
    shape_error: float = setting(0.02, gt=0.0, le=10.0)
    rim_error: float = setting(1.0, ge=0.0, le=100.0)
    back_inflation: float = setting(1.5, ge=0.0, le=1000.0)
    depth_weight: float = setting(3.0, ge=0.0, le=1e6)
    silhouette_weight: float = setting(10.0, ge=0.0, le=1e6)
    cut_energy: float = setting(10.0, ge=0.0, le=1e6)
    noise_energy: float = setting(3.0, ge=0.0, le=1e6)
    clean_ratio: float = setting(3.3, gt=0.0, le=100.0)
    noise_queries: int = setting(40, ge=3, le=100_000)
    mirror_energy: float = setting(5.0, ge=0.0, le=1e6)
    raw_energy: float = setting(5.0, ge=0.0, le=1e6)
    misfit_scale: float = setting(0.1, ge=0.0, le=100.0)
    recede_scale: float = setting(0.1, ge=0.0, le=100.0)
    unexplained_scale: float = setting(3.0, ge=0.0, le=100.0)
    misfit_noise: float = setting(2.0, ge=0.0, le=100.0)
    cut_scale: float = setting(0.1, ge=0.0, le=100.0)
    lateral_scale: float = setting(0.5, ge=0.0, le=100.0)
    uncertainty_scale: float = setting(0.003, gt=0.0, le=1.0)
    reliable_uncertainty: float = setting(0.003, ge=0.0, le=1.0)
    occluded_px: int = setting(4, ge=0, le=50)
    thin_px: int = setting(3, ge=0, le=50)
    contour_cone: float = setting(0.3, ge=0.0, le=1.0)
    contour_cut_energy: float = setting(0.0, ge=0.0, le=1e6)
    lateral_reach: float = setting(0.5, gt=0.0, le=100.0)
    depth_reach: float = setting(1.0, gt=0.0, le=100.0)
    mirror_candidate: bool = setting(False)
    outline_profile: Literal["off", "add", "replace"] = setting("add")
    rim_grazing: float = setting(0.0, ge=0.0, le=0.95)
    mirror: PaperSettings = setting(
        PaperSettings(translations=8, translation_step=0.1, j2=0.4, j3=1.0, rating_points=400)
    )

    def check(self) -> None:
        if not isinstance(self.mirror, PaperSettings):
            raise SettingError("mirror", f"must be a paper settings section, got {type(self.mirror).__name__}")
        if self.revolution_points > self.fit_points:
            raise SettingError("revolution_points", "must be <= fit_points")
        if self.gravity_x == 0.0 and self.gravity_y == 0.0 and self.gravity_z == 0.0:
            raise SettingError("gravity_y", "gravity (gravity_x, gravity_y, gravity_z) must not be zero")


@dataclass(frozen=True)
class Combined:
    """The weighted completion of one view.

    Attributes
    ----------
    box : Box
    weights, energies : dict of str to float
        Per candidate.
    confidence : float in [0, 1]
        From :attr:`uncertainty` alone (the method's result adds what :func:`fuse_depth` did).
    spread : float, metres
        Weighted mean distance of the candidates' box centres from the result's.
    explained : float in [0, 1]
        Share of silhouette-band rays the best closed candidate gets right.
    contour : float in [0, 1]
        The observation's contour share.
    uncertainty : float, metres
        The candidates' part of the predicted centre uncertainty (see :class:`EvidenceSettings`).
    """

    box: Box
    weights: dict[str, float]
    energies: dict[str, float]
    confidence: float
    spread: float
    explained: float
    contour: float
    uncertainty: float


def _spread(
    rows: list[list[float]], w: np.ndarray, box: Box, centre: tuple[float, float, float] | None = None
) -> float:
    """``float((w * row_norms(centres - box.centre)).sum())`` of the candidates' faces ``rows`` (k lists of six
    floats, ``centres`` their ``0.5 * (lo + hi)``): in Python floats where ``k < 8`` (numpy adds so few values left
    to right; each difference, product and root IEEE's, as numpy's; issue 19, stop 45), else by numpy. ``centre``:
    ``box.centre.tolist()`` when known (stop 65)."""
    if len(rows) >= 8 or len(rows) != len(w):
        faces = np.array(rows)
        centres = 0.5 * (faces[:, :3] + faces[:, 3:])
        return float((w * row_norms(centres - box.centre)).sum())
    b0, b1, b2 = box.centre.tolist() if centre is None else centre
    total = 0.0
    for (l0, l1, l2, h0, h1, h2), wi in zip(rows, w.tolist(), strict=True):
        d0, d1, d2 = 0.5 * (l0 + h0) - b0, 0.5 * (l1 + h1) - b1, 0.5 * (l2 + h2) - b2
        total += wi * math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    return total


def _weighted_median(values: np.ndarray, weights: np.ndarray, *, listed: list[list[float]] | None = None) -> np.ndarray:
    """Weighted (lower) median of each column of ``values`` (k, m) with weights (k,): numpy's order of each column,
    then the first place where the running sum of the weights in that order (added one by one, as ``np.cumsum``
    adds them) reaches half of their sum (``weights.sum()``'s), in Python floats (the same IEEE sums: a few dozen
    additions, where ``np.cumsum`` and two ``np.take_along_axis`` cost some 60 us; issue 19, nineteenth round)."""
    order = values.argsort(axis=0).tolist()  # np.argsort's call
    half = float(0.5 * weights.sum())
    w, v = weights.tolist(), values.tolist() if listed is None else listed  # ``listed``: ``values.tolist()``, known
    out = []
    for j in range(values.shape[1]):
        total = 0.0
        pick = 0  # np.argmax of no place reached: the first
        for i, row in enumerate(order):
            total += w[row[j]]
            if total >= half:
                pick = i
                break
        out.append(v[order[pick][j]][j])
    return np.array(out, dtype=values.dtype)


def midmean(values: np.ndarray, weights: np.ndarray, trim: float) -> float:
    """The weighted mean of ``values`` (k,) over their weighted quantiles ``trim`` to ``1 - trim`` (``weights`` (k,),
    at least one positive): each value counts with the part of its weight inside that range, so ``trim`` 0 is the
    weighted mean and 0.25 the interquartile mean; at ``trim`` 0.5 (no weight inside) the lower weighted median.

    >>> round(midmean(np.array([0.0, 1.0, 2.0, 10.0]), np.ones(4), 0.25), 6)
    1.5
    >>> float(midmean(np.array([3.0, 1.0, 2.0]), np.array([0.2, 0.5, 0.3]), 0.5))
    1.0
    """
    order = np.argsort(values, kind="stable")
    v, w = values[order], weights[order] / weights.sum()
    upper = np.cumsum(w)
    part = np.clip(np.minimum(upper, 1.0 - trim) - np.maximum(upper - w, trim), 0.0, None)
    total = float(part.sum())
    if total <= 0.0:
        return float(v[min(int(np.searchsorted(upper, 0.5)), len(v) - 1)])
    return float((part * v).sum() / total)


def clean_share(ratio: float, threshold: float) -> float:
    """How far a view is a clean scan rather than a depth camera's view, in [0, 1], from the growth of its
    local plane-fit residual with scale (:func:`~symfruit.core.fits.surface_noise`): 0 below
    ``threshold - 0.8``, 1 above ``threshold + 0.8``, linear between (clean scans measure 4.5-6.7,
    depth-camera views 1.5-2.2)."""
    return _clip01(float((ratio - threshold + 0.8) / 1.6))


def _clip01(x: float) -> float:
    """``float(np.clip(x, 0.0, 1.0))`` of a float in Python (issue 19, stop 47: a scalar's ``np.clip`` costs some
    5-10 us): NaN kept, and as numpy's clip an end is taken only where ``x`` is beyond it (``-0.0`` stays ``-0.0``)."""
    if x != x:
        return x
    y = x if x >= 0.0 else 0.0
    return y if y <= 1.0 else 1.0


def combine(cands: list[Candidate], *, contour: float, clean: float, s: EvidenceSettings,
            cone_source: str = "moments") -> Combined:  # fmt: skip
    """Weigh the candidates by their evidence and take the weighted median box (see the module)."""
    closed = [c for c in cands if c.agreement is not None]
    energies: dict[str, float] = {}
    best_rms = max(min((c.agreement.depth for c in closed if c.agreement is not None), default=1.0), 1e-6)
    cut = s.cut_energy * (1.0 - contour)
    # the closed candidates' log depth ratios by one np.log of them all (its float64 values, each the scalar call's;
    # issue 19, stop 65: one ufunc call for one a candidate), in their order
    logs = iter(np.log(np.array([max(c.agreement.depth, 1e-6) / best_rms for c in closed if c.agreement is not None])))
    for c in cands:
        ev = c.agreement
        if ev is None:
            energies[c.name] = s.mirror_energy if c.name == "mirror" else s.raw_energy + cut
            continue
        energy = s.depth_weight * next(logs)
        energy += s.silhouette_weight * (ev.inside + ev.outside)
        if c.name == "cone":
            # its premise: the seen outline is the fruit's silhouette (or, fitted to its contour part, that part)
            energy += cut if cone_source == "moments" else s.contour_cut_energy * (1.0 - contour)
        elif c.name == "ellipsoid":
            energy += s.noise_energy * (1.0 - clean)  # an algebraic fit of a noisy partial view comes out thin
        energies[c.name] = energy
    names = [c.name for c in cands]
    e = np.array([energies[n] for n in names])
    w = np.exp((e - e.min()) / -s.temperature)  # -(x) / t: x / -t to the bit (rounding is symmetric in sign)
    w /= w.sum()
    # each candidate's six faces as Python floats, the array made of them (the same float64 values as joining its
    # float64 lo and hi; one call for one a candidate; issue 19, stop 45)
    rows = [c.lo.tolist() + c.hi.tolist() for c in cands]
    faces = np.array(rows)
    box_faces = _weighted_median(faces, w, listed=rows)
    if s.back_trim < 0.5:  # the back face over the middle of the weight (EvidenceSettings.back_trim)
        box_faces[5] = max(midmean(faces[:, 5], w, s.back_trim), float(box_faces[2]) + 1e-4)
    box = Box(box_faces[:3], box_faces[3:])
    (l0, l1, l2), (h0, h1, h2) = box.min.tolist(), box.max.tolist()
    # box.centre's (lo + hi) / 2 and box.size's differences in Python floats: the same IEEE operations
    spread = _spread(rows, w, box, ((l0 + h0) / 2.0, (l1 + h1) / 2.0, (l2 + h2) / 2.0))
    wrong = min((c.agreement.inside + c.agreement.outside for c in closed if c.agreement is not None),
                default=2.0)  # fmt: skip
    size = max(h0 - l0, h1 - l1, h2 - l2)  # float(box.size.max()): the same differences, finite (a Box's)
    back_std = next((c.back_std for c in cands if c.name == "cone" and math.isfinite(c.back_std)), 0.0)
    uncertainty = float(np.hypot(back_std, spread) + s.misfit_scale * wrong * size)
    confidence = float(np.exp(-uncertainty / s.uncertainty_scale))
    return Combined(box, dict(zip(names, w.tolist(), strict=True)), energies, confidence, spread,
                    1.0 - wrong / 2.0, contour, uncertainty)  # fmt: skip


def _nanmax2(a: float, b: float) -> float:
    """``np.max`` of two numbers: NaN where either is, else the greater."""
    return math.nan if a != a or b != b else a if a >= b else b


def _lateral(dist: float, sized: Across, box: Box) -> float:
    """How far the silhouette's lateral extent at ``dist`` (``sized``: :func:`~symfruit.core.raster.across_sight`'s)
    lies from ``box``'s lateral faces, on its worse side: ``max(np.abs(dist * (axis[:2] + lo) - box.min[:2]).max(),
    np.abs(dist * (axis[:2] + hi) - box.max[:2]).max())`` in Python floats (issue 19, stop 47: the same products,
    sums and absolute values; each ``.max()`` of two NaN where either is; the outer ``max`` Python's, as before)."""
    (a0, a1, _), (s0, s1), (t0, t1) = sized.axis.tolist(), sized.lo.tolist(), sized.hi.tolist()
    (l0, l1, _), (h0, h1, _) = box.min.tolist(), box.max.tolist()
    low = _nanmax2(abs(dist * (a0 + s0) - l0), abs(dist * (a1 + s1) - l1))
    high = _nanmax2(abs(dist * (a0 + t0) - h0), abs(dist * (a1 + t1) - h1))
    return max(low, high)


def prior_width(across: Across, contour: float, cut_width: float = 1.0, tilt: Tilt | None = None,
                prolate: bool = False, floor: float = 0.3, *, least: bool = False,
                level: float | None = None) -> float:  # fmt: skip
    """The silhouette's width the depth prior reads (tangent units: times the distance, metres): the geometric
    mean of its widths across and along its principal axis for a whole outline (a solid of revolution is as deep
    as one of them, whichever way its axis lies in the image), moved in log towards the larger by ``cut_width``
    times the square of the cut share ``1 - contour``.

    A cut (an occluder, the image border) shortens the outline and most across itself, so the smaller width of
    a mostly hidden fruit measures the cut rather than the fruit; the larger one is the least shortened and
    still no more than the fruit's extent. A cut takes off a width about the sagitta of the arc it removes,
    which grows with the square of the cut's length while that is short: a stem or a leaf touching the rim
    shortens no width (the smaller width is then the fruit's own, an elongated fruit's or an oblate one's
    seen from its side), a leaf across half the fruit a whole radius; hence the square. On an outline that is
    all contour nothing changes.

    ``least``: the least depth that reading allows instead (``lost_rim: least``): a solid of revolution is as deep
    as its outline's smaller width (its axis in the image: prolate) or its larger (oblate), and the geometric mean is
    the middle of that range in log; its lower end is the smaller width, moved towards the larger as the mean is
    (by the square of the cut share, twice the mean's exponent). With the seen front's tilt (``tilt``) the depth
    is the tilt's, its own least.

    ``level``: the outline's width across gravity (``prior_axis: gravity``, tangent units,
    :func:`~symfruit.core.raster.width_across`), held within its two widths, instead of the mean (and of
    ``least``'s smaller width: a hanging solid of revolution is that deep), moved towards the larger as the mean is.

    >>> a = Across(np.zeros(3), np.zeros((2, 3)), np.zeros(2), np.zeros(2), 0.04, 0.09)
    >>> round(prior_width(a, 1.0), 4), round(prior_width(a, 0.0), 4), round(prior_width(a, 0.5), 4)
    (0.06, 0.09, 0.0664)
    >>> round(prior_width(a, 1.0, least=True), 4), round(prior_width(a, 0.0, least=True), 4)
    (0.04, 0.09)
    >>> round(prior_width(a, 1.0, level=0.09), 4), round(prior_width(a, 1.0, level=0.04, least=True), 4)
    (0.09, 0.04)
    >>> round(prior_width(a, 0.5, level=0.04), 4), round(prior_width(a, 1.0, level=0.2), 4)
    (0.049, 0.09)
    """
    small, big = sorted((float(across.minor), float(across.major)))
    if small <= 0.0:
        return big
    cut = min(max(1.0 - float(contour), 0.0), 1.0) ** 2 * cut_width
    if tilt is not None and tilt.count > 0 and tilt.major > 0:
        # the spheroid's depth for the outline and the seen front's tilt (core.raster.axis_tilt), in the outline's
        # tangent units, then towards the larger width as the geometric mean is
        half = tilt.half_depths(floor)[0] if prolate else tilt.half_depth(floor)
        depth = min(max(half / tilt.major * big, 0.5 * small), 2.0 * big)
        return depth * (big / depth) ** cut
    if level is not None and level > 0.0:
        depth = min(max(float(level), small), big)
        return depth * (big / depth) ** cut
    return big * (small / big) ** ((1.0 if least else 0.5) * (1.0 - cut))


def _tilt_outer(occlusion: Occlusion | None, which: str) -> Silhouette | None:
    """The whole outline :func:`~symfruit.core.raster.axis_tilt` scales the points' outline to (``tilt_outline``
    ``mask`` or ``both``): the fruit's own mask without what it overshoots the fruit by; None for ``points`` or no
    mask."""
    if which == "points" or occlusion is None or occlusion.own is None:
        return None
    own = occlusion.own if occlusion.overshoot is None else occlusion.own & ~occlusion.overshoot
    return Silhouette(occlusion.u0, occlusion.v0, own, 0.0) if own.any() else None


def hidden_front(sample: np.ndarray, front: float, width: float, occlusion: Occlusion, camera: Camera,
                 points: np.ndarray | None = None) -> float:  # fmt: skip
    """The shared front where a leaf may hide the fruit's nearest part (``hidden_front``, stop 46): metres.

    The nearest seen point of a fruit whose front lies behind a leaf is on the seen part's edge, behind the
    fruit's front (docs/hidden45.md: the mostly hidden apples' boxes' fronts 7 mm behind the truth's, 3 of them
    the hidden front). The sphere as wide as the silhouette (``width``, tangent units: its larger width over the
    distance, read at the sphere's centre) that best fits the seen points (:func:`~symfruit.core.front.sphere_front`)
    places the front instead, when that front lies in front of ``front`` at a pixel where the camera could not
    have seen it: the occlusion map hides the pixel (something nearer was seen there, or the image ends) and
    nothing was seen there behind the sphere's front, or the pixel is the fruit's own (its mask) but holds none of
    its seen points (``points``, default ``sample``) within twice their spacing in the mask (a leaf under the mask,
    its depth dropped by extraction). Otherwise ``front`` stands.
    """
    if width <= 0.0 or len(sample) < 4:
        return front
    diameter = width * front
    diameter = width * (front + 0.5 * diameter)  # at the sphere's centre, half a diameter behind its front
    if sphere_front_behind(sample, 0.5 * diameter, front, tolerance=FRONT_TOLERANCE):
        return front  # the sphere's front surely lies behind: ``front`` stands, as below (issue 19, stop 63)
    z, at = sphere_front(sample, 0.5 * diameter, tolerance=FRONT_TOLERANCE)
    if not (np.isfinite(z) and 0.0 < z < front):
        return front
    ax, ay, az = at.tolist()  # camera.project's (u, v) of ``at`` in Python floats: the same products and sums
    inv_z = 1.0 / az  # (z > 0 here)
    u, v = camera.fx * ax * inv_z + camera.cx, camera.fy * ay * inv_z + camera.cy
    uu, vv = np.array([u]), np.array([v])
    if bool(occlusion.at(uu, vv)[0]):
        return front if float(occlusion.depth_at(uu, vv)[0]) > z else z  # seen behind it there: the fruit would be
    own = occlusion.own
    col, row = int(np.rint(u)) - occlusion.u0, int(np.rint(v)) - occlusion.v0
    if own is None or not (0 <= row < own.shape[0] and 0 <= col < own.shape[1]) or not own[row, col]:
        return front
    seen = sample if points is None else points
    uv = camera.project(seen)
    spacing = float(np.sqrt(np.count_nonzero(own) / len(seen)))  # pixels of the mask per seen point, along a side
    gap = float(np.min((uv[:, 0] - u) ** 2 + (uv[:, 1] - v) ** 2))
    return z if gap > (2.0 * max(spacing, 1.0)) ** 2 else front


def rim_width(mask: np.ndarray | Silhouette, band: float = 0.15) -> float:
    """:func:`rim_coverage`'s rim width, pixels: ``band`` equivalent radii of the region ``mask`` (a bool mask, or a
    region: its pixels counted once, :func:`~symfruit.core.raster.pixel_count`), at least 2."""
    # the count: the sum's, 20x faster; math.sqrt of the (non-negative) quotient: np.sqrt's, both correctly rounded
    n = pixel_count(mask) if isinstance(mask, Silhouette) else np.count_nonzero(mask)
    return max(2.0, band * math.sqrt(n / np.pi))


def rim_coverage(points: np.ndarray, region: Silhouette, camera: Camera, *, band: float = 0.15,
                 inner: np.ndarray | None = None, inner_reach: float = np.inf,
                 pixels: tuple[np.ndarray, np.ndarray] | None = None) -> float:  # fmt: skip
    """How much of the seen region's rim holds seen points, relative to its interior, in [0, 1].

    The rim is the region's pixels within ``band`` equivalent radii (at least 2 px) of its edge; the share of
    rim pixels holding a point is divided by the share of the other pixels holding one (a sparse cloud or a
    depth image coarser than the colour image covers fewer pixels everywhere). Where the surface turns away
    from the camera, at the rim, its depth says how deep the fruit is (a convex fruit's rim lies at about the
    depth of its widest section); a time-of-flight camera returns nothing there (it invalidates grazing
    pixels: the shared Azure Kinect frames lose the outer 13 % of every sphere's radius), and the back face
    must then be extrapolated from the front's curvature alone. ``inner``: the region's distance map when known
    (:attr:`~symfruit.core.agreement.Observation.inner`), exact up to ``inner_reach`` pixels (it is made again
    when that is short of the rim's width). ``pixels``: the points' pixels when known
    (:func:`~symfruit.core.raster.point_pixels`; not projected again).
    """
    mask = region.mask
    width = rim_width(region, band)
    if inner is None or inner.shape != mask.shape or inner_reach < width:
        inner = inner_distance(mask)
    if (jit := compiled()) is not None:  # the compiled twin of what follows (its value to the bit)
        fill = int(np.ceil(region.fill_radius)) if region.fill_radius > 0 else 0
        if pixels is not None and len(pixels[0]) == len(points):
            return float(jit.rim_coverage_pixels(pixels[0], pixels[1], int(region.u0), int(region.v0), mask, inner,
                                                 float(width), fill))  # fmt: skip
        return float(jit.rim_coverage(np.ascontiguousarray(points, dtype=np.float64), camera.fx, camera.fy, camera.cx,
                                      camera.cy, int(region.u0), int(region.v0), mask, inner, float(width),
                                      fill))  # fmt: skip
    rim = mask & (inner <= width)
    rest = mask & ~rim
    if not rim.any() or not rest.any():
        return 1.0
    uv = camera.project(points)
    col = np.rint(uv[:, 0]).astype(np.intp) - region.u0
    row = np.rint(uv[:, 1]).astype(np.intp) - region.v0
    ok = (col >= 0) & (col < mask.shape[1]) & (row >= 0) & (row < mask.shape[0])
    hit = np.zeros(mask.shape, dtype=bool)
    hit.ravel()[row[ok] * mask.shape[1] + col[ok]] = True  # by flat index: twice as fast as two index arrays
    if region.fill_radius > 0:  # a sparse cloud: a point covers its neighbourhood
        hit = ndimage.maximum_filter(hit, size=2 * int(np.ceil(region.fill_radius)) + 1)
    interior = (hit & rest).sum() / rest.sum()
    if interior <= 0:
        return 1.0
    return float(min(1.0, (hit & rim).sum() / rim.sum() / interior))


def lost_rim(region: Silhouette, grazing: float, camera: Camera | None = None, *, least: float = 0.0) -> Silhouette:
    """``region`` grown by the rim a camera that returns no depth where ``|cos| < grazing`` (the surface's normal
    against the ray) loses of a round section: its equivalent radius ``r`` times ``1 / sqrt(1 - grazing^2) - 1``
    pixels (the last seen point of a circle of radius ``R`` lies at ``R sqrt(1 - grazing^2)`` from its centre), or
    ``least`` pixels when more, by a disk, within ``camera``'s image when given. Unchanged when that is under half a
    pixel.

    >>> m = np.zeros((21, 21), dtype=bool); m[5:16, 5:16] = True
    >>> g = lost_rim(Silhouette(100, 50, m, 0.0), 0.6)
    >>> (g.u0, g.v0, int(np.count_nonzero(g.mask)) > int(np.count_nonzero(m)))
    (98, 48, True)
    """
    r = math.sqrt(pixel_count(region) / math.pi)  # the region's count, made once (raster.pixel_count)
    grow = max(r * (1.0 / math.sqrt(1.0 - grazing * grazing) - 1.0), least)
    px = math.ceil(grow)
    if grow < 0.5:
        return region
    d = np.arange(-px, px + 1)
    disk = d[:, None] ** 2 + d[None, :] ** 2 <= grow * grow
    mask = ndimage.binary_dilation(np.pad(region.mask, px), structure=disk)
    u0, v0 = region.u0 - px, region.v0 - px
    if camera is not None:  # within the image: the camera saw nothing beyond it
        c0, r0 = max(0, -u0), max(0, -v0)
        c1 = min(mask.shape[1], camera.width - u0)
        r1 = min(mask.shape[0], camera.height - v0)
        mask, u0, v0 = mask[r0:r1, c0:c1], u0 + c0, v0 + r0
    return Silhouette(u0, v0, np.ascontiguousarray(mask), region.fill_radius)


def _rim_region(sample: np.ndarray, region: Silhouette, camera: Camera, points: np.ndarray,
                pixels: tuple[np.ndarray, np.ndarray] | None, s: EvidenceSettings) -> Silhouette:  # fmt: skip
    """The seen region of points alone (``rim_grazing``): grown by :func:`lost_rim` where the edge normals call at
    least half of the points' own outline a cut (:func:`~symfruit.core.agreement.observe` on it: no occlusion
    information, so its contour share is theirs alone), else ``region``. By at least 2 px: the points then lie as
    far inside it as ``detect``'s inside their mask (extraction's 1 px eroded border), beyond the 1.5 px of
    ``observe``'s edge test, so the normals, which found the rim lost, do not label the grown outline a cut again."""
    own = observe(sample, region, camera, n_rays=s.rays, n_band=0, bands=(), dense=points,
                  inner_reach=rim_width(region), dense_pixels=pixels)  # fmt: skip
    return lost_rim(region, s.rim_grazing, camera, least=2.0) if own.contour < 0.5 else region


def fuse_depth(
    combined: Combined,
    cands: list[Candidate],
    region: Silhouette,
    camera: Camera,
    *,
    s: EvidenceSettings,
    rim: float = 1.0,
    seen_back: float | None = None,
    across: Across | None = None,
    tilt: Tilt | None = None,
    whole: tuple[float, float] | None = None,
    faces: tuple[np.ndarray, np.ndarray] | None = None,
    masked: bool = True,
    prolate: float | None = None,
    level: float | None = None,
) -> tuple[Box, float, float]:
    """The box moved towards what the silhouette says: ``(box, back_sd, width)``, metres.

    ``seen_back``: the deepest seen point, which the back face never ends in front of (a fruit seen deeper
    than it is wide, pointing at the camera, would otherwise be cut by the prior). ``across``: the region's
    :func:`~symfruit.core.raster.across_sight` when known. ``whole``: the widths ``(minor, major)`` (tangent units)
    of the fruit's whole outline where a cut one's are not (``cut_prior``): the prior reads them as an uncut
    outline's where that is wider (a cut only ever narrows an outline). ``faces``: the tangent extents ``(lo, hi)``
    in ``across``' frame of the fruit's whole outline where a cut one's are not (``cut_faces``), the silhouette's box
    for the lateral faces. ``masked``: the outline is the fruit's mask's (occlusion information), not the points' own,
    which a lost rim narrows by a band on every side and so more across than along (``lost_rim: least`` reads its
    smaller width only on a mask's outline). ``prolate``: how far the seen cap says prolate, in [0, 1]
    (``lost_rim: cap``; None: not read, the mean's reach). ``level``: the outline's width across gravity
    (``prior_axis: gravity``, :func:`prior_width`; None: the mean).

    The candidates' back face (the weighted median, :func:`combine`) and the prior ``front + depth_ratio *
    width`` are averaged by their inverse variances (module docstring, step 6); ``back_sd`` is the posterior
    standard deviation of the back face, ``width`` the silhouette's (:class:`EvidenceSettings`). The lateral
    faces move by the prior's share of that average, times the outline's contour share squared, towards the
    silhouette's own box (its extents across the line of sight about the posterior centre's point on the ray
    through its centroid): where the rim holds no depth (a time-of-flight camera) every shape fitted to the
    points is as narrow as the cap it saw, and the silhouette is the better measure of the fruit's width too.
    """
    box = combined.box
    fit_back = float(box.max[2])
    spread = _back_spread(cands, combined.weights, fit_back)
    back_std = next((c.back_std for c in cands if c.name == "cone" and math.isfinite(c.back_std)), 0.0)
    across = across_sight(region, camera) if across is None else across
    width = float(prior_width(across, combined.contour, s.cut_width, tilt, s.prior_tilt == "prolate", s.tilt_floor,
                              level=level))  # fmt: skip
    read = combined.contour  # the contour share of the outline the prior's width is read from
    if whole is not None:  # the ellipse of the outline's free arcs, as an uncut outline's; a cut only narrows
        ellipse = float(np.sqrt(whole[0] * whole[1]))
        if level is not None and tilt is None and across.minor > 0:  # across gravity: the whole outline's stretch
            held = min(max(float(level), across.minor), across.major)  # as prior_width holds it
            ellipse = held * ellipse / math.sqrt(across.minor * across.major)
        if s.cut_spread == "ellipse" and ellipse > width:
            read = 1.0  # the width is the whole outline's (the ellipse's), not the cut one's
        width = max(width, ellipse)
    least = None
    if s.lost_rim in ("least", "cap") and masked and combined.contour >= s.covered_contour:
        # the least depth the prior allows, read as its width is: on a whole outline (a cut one's smaller width
        # measures the cut, not the fruit; there ``least`` is ``bound``)
        least = float(prior_width(across, combined.contour, s.cut_width, tilt, s.prior_tilt == "prolate",
                                  s.tilt_floor, least=True, level=level))  # fmt: skip
        if whole is not None:
            least = max(least, float(min(whole)))
        if s.lost_rim == "cap":  # the least width as far as the seen cap says prolate, the mean's where oblate
            least = least ** (prolate or 0.0) * width ** (1.0 - (prolate or 0.0)) if least > 0 else width
        least = float(least * box.centre[2] / across.axis[2])
    width = float(width * box.centre[2] / across.axis[2])  # in that order: the former bits where no ellipse is
    least = width if least is None else least

    def shapes_sd(model: float) -> float:  # the shapes' back-face deviation with ``model`` widths of model error
        return math.sqrt(float((s.back_inflation * back_std) ** 2 + (0.5 * spread) ** 2 + model**2))

    fit_sd = shapes_sd(width * (s.shape_error + s.rim_error * (1.0 - rim)))
    if s.depth_ratio_sd <= 0 or width <= 0:
        return box, fit_sd, width
    front = float(box.min[2])
    prior_sd = s.depth_ratio_sd * width / max(read, 0.25)
    prior_back = front + s.depth_ratio * width
    shapes_back = fit_back
    # A shape fitted to a cap whose rim the camera lost is short by up to what the rim hides, never deep: its back
    # face then says the fruit reaches at least there (and, within the rim's share of its error, no farther than that
    # beyond), not where. Inside that range the prior decides; beyond it the fit's clean error pulls, as a whole rim's
    # fit does (rim 1: the same as ``pull``). The bound reaches the prior's back (``bound``), or no farther than the
    # least depth the prior allows (``least``, ``cap``: the outline's smaller width for an elongated one, a prolate
    # fruit lying in the image being that deep; ``least`` is ``width`` where it is not read).
    reach = front + s.depth_ratio * min(least, width)
    bounded = s.lost_rim != "pull" and rim < 1.0 and fit_back < reach
    if bounded:
        fit_back = min(reach, fit_back + width * s.rim_error * (1.0 - rim))
        fit_sd = shapes_sd(width * s.shape_error)
    a, b = 1.0 / fit_sd**2, 1.0 / prior_sd**2
    fused = (a * fit_back + b * prior_back) / (a + b)
    # the prior's share of the back face: how far it moved the shapes' towards its own (b / (a + b) where the
    # shapes' back face is read as an estimate)
    pull = b / (a + b) if not bounded else min(max((fused - shapes_back) / (prior_back - shapes_back), 0.0), 1.0)
    back = max(fused, front + 1e-4)
    if seen_back is not None:
        back = max(back, seen_back)  # the fruit holds every point seen of it
    share = pull * combined.contour**2
    # The silhouette's box: its widths across the line of sight (a sphere's diameter wherever it is in the
    # image, where the pixel box times the depth is stretched off the optical axis), about the posterior
    # centre's point on the ray through the silhouette's centroid.
    # Outwards by the prior's share alone: the fruit covers at least what it was seen to cover, cut or not
    # (the contour share only says how far beyond a cut edge it may reach, which pulls inwards).
    sil = across if faces is None else replace(across, lo=faces[0], hi=faces[1])
    widest = math.inf
    if s.cut_reach == "widest" and combined.contour < 1.0:  # the outline's widest extent: along its axes or e1, e2
        widest = max(across.major, across.minor, *(across.hi - across.lo).tolist())
    lo, hi = _lateral_faces(box, sil, front, back, share, pull, widest)
    return Box(np.array(lo), np.array(hi)), 1.0 / math.sqrt(a + b), width


def _back_spread(cands: list[Candidate], weights: dict[str, float], fit_back: float) -> float:
    """``float((w * np.abs(backs - fit_back)).sum())`` of the candidates' weights ``w`` (``weights`` by name) and back
    faces ``backs`` (``c.hi[2]``): in Python floats where there are fewer than 8 (numpy adds so few values left to
    right from the first; each difference, absolute value and product IEEE's, as numpy's; issue 19, stop 65: seven
    numpy calls a fruit), else by numpy."""
    if len(cands) >= 8 or not cands:
        w = np.array([weights[c.name] for c in cands])
        backs = np.array([c.hi[2] for c in cands])
        return float((w * np.abs(backs - fit_back)).sum())
    terms = [weights[c.name] * abs(float(c.hi[2]) - fit_back) for c in cands]
    total = terms[0]
    for term in terms[1:]:
        total += term
    return total


def _lateral_faces(box: Box, across: Across, front: float, back: float, share: float, grow: float,
                   widest: float = math.inf) -> tuple[list[float], list[float]]:  # fmt: skip
    """:func:`fuse_depth`'s box faces: ``box``'s lateral faces moved towards the silhouette's (``across``, about the
    point at depth ``0.5 (front + back)`` on its centroid's ray) by ``grow`` outwards and ``share`` inwards, its
    back face ``back``. Where the box along an axis is longer than ``widest`` (tangent units, times that distance),
    that much of what it runs past the silhouette's faces is pulled in by ``grow`` too (``cut_reach``), shared between
    the two faces in proportion to their runs. In Python floats (issue 19, stop 47): the same products and sums as
    numpy's on the (2,) arrays before, ``np.where``'s test a comparison (False for NaN there too), without a dozen
    numpy calls."""
    (a0, a1, a2), (s0, s1), (t0, t1) = across.axis.tolist(), across.lo.tolist(), across.hi.tolist()
    dist = 0.5 * (front + back) / a2
    lo, hi = box.min.tolist(), box.max.tolist()
    for i, (ax, sil_lo, sil_hi) in enumerate(((a0, s0, t0), (a1, s1, t1))):
        d_lo, d_hi = dist * (ax + sil_lo) - lo[i], dist * (ax + sil_hi) - hi[i]
        past = hi[i] - lo[i] - dist * widest  # -inf where no cap
        lo[i] += (grow if d_lo < 0.0 else share) * d_lo
        hi[i] += (grow if d_hi > 0.0 else share) * d_hi
        run_lo, run_hi = max(d_lo, 0.0), min(d_hi, 0.0)  # how far the box ran past each face
        if past > 0.0 and run_lo - run_hi > 0.0:
            over = min(past / (run_lo - run_hi), 1.0)  # the share of each run beyond the widest extent
            lo[i] += (grow - share) * over * run_lo
            hi[i] += (grow - share) * over * run_hi
    hi[2] = back
    return lo, hi


@register("evidence", settings=EvidenceSettings, occlusion=True)
def evidence(
    points: np.ndarray, camera: Camera, settings: EvidenceSettings, *, occlusion: Occlusion | None = None
) -> Completion:
    """Candidates weighed by how well they explain the view; weighted-median box; confidence."""
    s = settings
    sample = subsample(points, s.fit_points)
    pixels = point_pixels(points, camera)  # the points' pixels, projected once (None without numba)
    region = close_ragged(silhouette(points, camera, pixels=pixels), radius=s.ragged_close_px, ragged=s.ragged_at)
    # about a point per pixel of the points' own region: a depth camera's view (the fruit's mask, joined below,
    # also holds the pixels a time-of-flight camera returns no depth for: its rim, a leaf's mixed edge)
    dense = len(points) >= 0.5 * pixel_count(region)
    seen_region = region
    if occlusion is None and dense and s.rim_grazing > 0:
        region = _rim_region(sample, region, camera, points, pixels, s)
    if occlusion is not None:
        # the fruit's mask reaches beyond its points (an eroded border, a time-of-flight camera's lost rim): its
        # outline is labelled by the occlusion information alone, since no point lies within observe's 1.5 px of it
        # and the edge normals do not vote (measured from the points' own edge they call a lost rim a cut; issue 18,
        # docs/edges52.md)
        region = with_own(region, occlusion)
        # a surface in front crossing the fruit parts its silhouette: the hidden pixels between the parts are the
        # fruit's (issue 18, docs/strip57.md)
        region = bridged(region, occlusion)

    def look(at: Silhouette) -> Observation:
        return observe(sample, at, camera, n_rays=s.rays, n_band=s.band_rays, dense=points, occlusion=occlusion,
                       occluded_px=s.occluded_px, contour_cone=s.contour_cone, thin_px=s.thin_px,
                       inner_reach=rim_width(at), dense_pixels=pixels)  # fmt: skip

    obs = look(region)
    # A whole outline (at least ``covered_contour`` of it a contour) without what the mask overshoots the fruit by
    # (stop 42: an active-stereo camera's spread edge under a mask drawn a few pixels wide,
    # :func:`~symfruit.core.occlusion.overshoot`): the silhouette's cone and the fruit's width (the depth prior's,
    # the lateral faces') are read from it; the observation keeps the whole mask for the rest (its contour share
    # reads the outline's surroundings). Not on a cut outline: the leaf-occluded views lost there (docs/sil42.md).
    trimmed = None
    over = None if occlusion is None else occlusion.overshoot
    if over is not None and (obs.contour >= s.covered_contour or occlusion.seen_past) and over.any():  # type: ignore[union-attr]
        trimmed = with_own(seen_region, occlusion, trimmed=True)  # type: ignore[arg-type]
        observed = False
        if occlusion.seen_past:  # type: ignore[union-attr]
            # Where a time-of-flight camera saw past the fruit, what the mask overshoots it by is the background
            # seen beyond its edge: the fruit's outline is the trimmed one for the shapes too (stop 58,
            # docs/grown58.md: fitted to a mask drawn 10 px wide, the cone's ellipsoid took a 200 mm sphere to 238 x
            # 244 x 290 mm and the box to 207 x 212 x 206). Unless no ellipse fits the trimmed outline's contour
            # part where one fitted the drawn mask's: the trim is cut sector by sector (each at its own edge), and
            # where that leaves a ragged outline the drawn one is the better-posed outline for the viewing cone.
            outline = bridged(trimmed, occlusion)  # type: ignore[arg-type]
            cut_obs = look(outline)
            if cut_obs.cone_source == "contour" or obs.cone_source == "moments":
                region, obs, observed = outline, cut_obs, True
        if not observed and obs.cone_source == "moments":
            cone, axis = silhouette_cone(trimmed, camera)
            obs = replace(obs, cone=cone, axis=axis)
    apex, _ = apex_depth(sample)
    lo, hi = bounds(points)  # one compiled pass where numba is (the columns' least and greatest values)
    front = max(float(lo[2]), apex)
    across = across_sight(region, camera)
    sized = across if trimmed is None else across_sight(trimmed, camera)
    if occlusion is not None and s.hidden_front == "sphere" and obs.contour < 1.0:
        front = hidden_front(sample, front, sized.major / float(sized.axis[2]), occlusion, camera, points)
    shapes: tuple[str, ...] = SHAPES
    explained: float | None = None
    clean = 0.0
    noise: float | None = None
    if not dense:
        # The cone ellipsoid's fit reads each point as the nearest surface along its ray, as a depth camera
        # sees it; a sparse cloud (a scan's points, possibly on both sides of the fruit) is not that.
        shapes = tuple(name for name in SHAPES if name != "cone")
    if dense and obs.contour >= s.covered_contour:
        # A depth camera's view of a whole fruit (a point for about every pixel, the outline a contour): the
        # ellipsoid tangent to the silhouette's cone is the better-posed version of both the sphere and the
        # unconstrained ellipsoid (which noise thins), so they cannot win and are not fitted (the ablation:
        # the same boxes, a millisecond less), and whether the data is noisy need not be measured.
        shapes = tuple(name for name in SHAPES if name not in ("sphere", "ellipsoid"))
        explained = s.explained_at
    else:
        ratio, noise = noise_measures(sample, queries=s.noise_queries)
        clean = clean_share(ratio, s.clean_ratio)
    cands = candidates(
        points, sample=sample, obs=obs, camera=camera, front=front,
        width=across.major * front / float(across.axis[2]) if occlusion is not None else 0.0,
        mirror=s.mirror.options() if s.mirror_candidate else None, revolution_points=s.revolution_points,
        revolution_coarse=s.revolution_coarse, steps=s.march_steps, shapes=shapes, explained=explained,
        region=region, plausible=(s.lateral_reach, s.depth_reach), seen=(lo, hi),
        outline_profile=s.outline_profile if obs.contour >= s.covered_contour else "off",
        sections=0.0 if dense else s.sections,
    )  # fmt: skip
    combined = combine(cands, contour=obs.contour, clean=clean, s=s, cone_source=obs.cone_source)
    rim = rim_coverage(points, region, camera, inner=obs.inner, inner_reach=obs.inner_reach, pixels=pixels)
    seen_back = float(hi[2])
    tilt = None
    capped = s.lost_rim == "cap" and occlusion is not None  # the seen cap says prolate or oblate (``lost_rim: cap``)
    if (s.prior_tilt != "off" or capped) and dense and obs.contour >= s.covered_contour:
        # the points' own outline: the mask's may be shifted from the depth (registration) or reach past it
        outer = _tilt_outer(occlusion, s.tilt_outline)
        tilt = axis_tilt(sample, seen_region, camera, sized, outer=outer if s.tilt_outline == "mask" else None,
                         blocks=s.tilt_blocks, bend=s.tilt_bend)  # fmt: skip
        if s.tilt_outline == "both" and outer is not None:
            wide = axis_tilt(sample, seen_region, camera, sized, outer=outer, blocks=s.tilt_blocks, bend=s.tilt_bend)
            tilt = bracket_tilt(tilt, wide)
    whole = faces = None
    if s.cut_prior == "ellipse" and obs.cone_source == "contour" and obs.cone is not None and obs.axis is not None:
        whole = cone_widths(obs.cone, obs.axis)
    elif s.cut_prior == "sides":
        cracks, free = obs._made.get("outline", (None, None))
        arcs = obs.cone if obs.cone_source == "contour" else None  # the cone of the free arcs' ellipse
        if arcs is None and cracks is not None and s.cut_circle == "free":
            # no ellipse through the free arcs (too short or ragged for five parameters): a round fruit's give its
            # radius (three), read as the ellipse would be, on the cut sides alone and capped at the widest extent
            circle = outline_circle(region, camera, cracks[free])
            arcs = None if circle is None else circle[0]
        if cracks is not None and arcs is not None:
            stretch, reach = free_side_reach(cracks, free, arcs, camera, region)
            whole = (sized.minor * stretch, sized.major * stretch)
            if reach is not None and s.cut_faces == "sides" and trimmed is None:  # the region's own outline
                faces = tangent_extent(reach, sized, camera)
    level = None
    if s.prior_axis == "gravity" and obs.contour >= s.covered_contour:  # across gravity, of ``sized``'s outline
        gravity = np.array([s.gravity_x, s.gravity_y, s.gravity_z])
        level = width_across(region if trimmed is None else trimmed, sized, camera, gravity)
    prolate = None
    if capped and tilt is not None:  # how far the cap says prolate: 1 at the prolate spheroid's cap, 0 from half-way
        share = tilt.oblate_share(s.tilt_floor)
        prolate = 0.0 if share is None else min(max(1.0 - 2.0 * share, 0.0), 1.0)
    box, back_sd, width = fuse_depth(combined, cands, region, camera, s=s, rim=rim, seen_back=seen_back,
                                     across=sized, tilt=tilt if s.prior_tilt != "off" else None, whole=whole,
                                     faces=faces, masked=occlusion is not None, prolate=prolate,
                                     level=level)  # fmt: skip
    moved = 0.5 * abs(float(box.max[2] - combined.box.max[2]))  # the prior against the shapes
    # A fruit receding along the line of sight (a depth camera's view seen deeper than the half-width a round
    # fruit shows in front of its rim, as far as the outline is a contour) has a back that nothing seen
    # mirrors; an elongated outline leaves the tilt of the fruit's long axis out of the image unseen. (A
    # sparse cloud's points need not end at the rim: no receding measure there.)
    recede = obs.contour * max(0.0, seen_back - float(box.min[2]) - 0.5 * width) if dense else 0.0
    stretched = float(across.major / max(across.minor, 1e-12))
    # np.sqrt's value: both square roots correctly rounded (numpy's where the ratio is NaN or negative)
    elongation = math.sqrt(stretched) if stretched >= 0.0 else float(np.sqrt(stretched))
    # What no closed shape explains of the seen depths beyond the sensor's noise: a shape that misses the front
    # it was fitted to does not predict the back it extrapolates (the outline's part is in ``combined``). Not for
    # a sparse cloud, whose points need not be the nearest surface on their rays.
    best_rms = min((c.agreement.depth for c in cands if c.agreement is not None), default=None)
    unexplained = 0.0
    if dense and best_rms is not None and s.unexplained_scale > 0:
        if noise is None:
            noise = noise_level(sample, queries=s.noise_queries)  # the ratio is not read here
        unexplained = math.sqrt(float(max(0.0, best_rms**2 - (s.misfit_noise * noise) ** 2)))
    # What the outline says the shapes miss (docs/conf45.md): the share of it that is a cut, beyond which the fruit
    # was not seen, times the box's largest side; and how far the silhouette's lateral extent (across the line of
    # sight at the box's distance, as fuse_depth reads it) disagrees with the shapes' box, on its worse side.
    cut = (1.0 - combined.contour) * float(combined.box.size.max())
    dist = 0.5 * float(box.min[2] + box.max[2]) / float(sized.axis[2])
    lateral = _lateral(dist, sized, combined.box)
    uncertainty = elongation * math.sqrt(float(combined.uncertainty**2 + moved**2 + (s.recede_scale * recede) ** 2
                                               + (s.unexplained_scale * unexplained) ** 2 + (s.cut_scale * cut) ** 2
                                               + (s.lateral_scale * lateral) ** 2))  # fmt: skip
    confidence = float(np.exp(-uncertainty / s.uncertainty_scale))
    extras: dict[str, Any] = {
        "confidence": confidence,
        "reliable": uncertainty <= s.reliable_uncertainty,
        "uncertainty": uncertainty,
        "recede": recede,
        "unexplained": unexplained,
        "cut": cut,
        "lateral": lateral,
        "elongation": elongation,
        "back_sd": back_sd,
        "rim": rim,
        "width": width,
        "weights": combined.weights,
        "energies": combined.energies,
        "spread": combined.spread,
        "explained": combined.explained,
        "contour": combined.contour,
        "candidates": {
            c.name: {
                "min": c.lo.tolist(), "max": c.hi.tolist(),
                "evidence": None if (a := c.agreement) is None else [a.depth, a.inside, a.outside],
                "back_std": None if not math.isfinite(c.back_std) else c.back_std,
            }
            for c in cands
        },
    }  # fmt: skip
    # the seen points and their mirror images through the box centre, written into one array column by column
    # (the same differences; broadcasting over a last axis of 3 runs numpy's inner loop once per point)
    completed = np.empty((2 * len(points), 3))
    centre2 = 2.0 * box.centre
    # by the compiled twin where numba is (the same copy and differences, in one pass)
    if points.dtype == np.float64 and points.flags.c_contiguous and (jit := compiled()) is not None:
        jit.mirrored(points, centre2, completed)
    else:
        completed[: len(points)] = points
        for c in range(3):  # three components, not a loop over points
            np.subtract(centre2[c], points[:, c], out=completed[len(points) :, c])
    return Completion(points=completed, box=box, extras=extras)
