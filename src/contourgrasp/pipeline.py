"""End to end: one top-down RGB-D frame -> a 6-DoF grasp pose (thesis 3.1, 3.1.1, 4.1.4).

Perception finds the object and its contour in meters in a *planning frame*
(the camera frame for a top-down camera, a frame on the table's plane for a
tilted one); synthesis plans (x, y, yaw) in that frame; this module turns the
result into poses a robot can execute.

Hand frame (``T_camera_hand``)
    Origin at the hand's reference point of the preset (the origin of its
    hand file's coordinates) placed at the planned (x, y) and at the approach
    depth along the approach axis; x and y axes the hand file's axes turned by
    yaw; z axis the approach direction: the camera's z (palm facing along it,
    toward the table) or, for a tilted camera, the table's normal pointing
    into the table. ``approach_depth`` = nearest valid depth inside the contour
    (after a 3 x 3 median filter against sensor noise, see
    :func:`contourgrasp.perception.approach_depth`) plus ``approach_offset``
    (section 3.1.1): the fingertips' plane reaches
    that far, ``approach_offset`` below the object's top.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import partial

import numpy as np
from scipy.spatial.transform import Rotation

from . import perception, validation
from . import tolerances as tol
from .errors import HandError, NoFeasibleGrasp, PerceptionError, PlannerError, SegmentationError
from .hand import SLICE_CONTOUR as HAND_SLICE_CONTOUR
from .hand import Hand
from .perception import HeightMap, Intrinsics, MetricContour, Plane, Segmentation
from .perception.camera import check_intrinsics
from .synthesis import Descent, GraspPlan, search
from .synthesis.grasp_height import check_rule as check_grasp_height
from .synthesis.grasp_height import grasp_height as choose_grasp_height
from .tolerances import APPROACH_OFFSET, HOMOGENEOUS_ROW, MAX_APPROACH_OFFSET, MAX_STANDOFF, ROTATION_TOLERANCE

SEGMENT_CHOICES = perception.SEGMENT_METHODS


@dataclass(frozen=True, eq=False)
class ImageGraspPlan:
    """A grasp planned on an RGB-D frame.

    Attributes
    ----------
    plan : GraspPlan
        The planar plan, in the planning frame of ``metric``.
    segmentation : Segmentation
        Mask and pixel contour of the object.
    metric : MetricContour
        The contour in meters, its planning frame and the approach depth.
    camera : Intrinsics
    T_camera_hand, T_camera_pregrasp : (4, 4) float
        The grasp pose and the pose ``standoff`` m back along the approach axis.
    T_base_hand : (4, 4) float or None
        The grasp pose in the robot's base frame, when extrinsics were given.
    filled_depth_px : int
        Depth holes filled before use.
    height_map : HeightMap or None
        Heights above the table around the object, in the planning frame of ``metric``
        (:func:`contourgrasp.perception.height_map`); None when no table plane was found.
    candidates : tuple of Candidate
        Every region standing on the table (:func:`contourgrasp.perception.find_candidates`),
        largest first; empty when depth found no table plane.
    target : Candidate or None
        The candidate planned on (:func:`contourgrasp.perception.choose_target`); None when the
        object did not come from the depth candidates (the RGB method found it) and overlaps none.
    target_reason : str
        Why that object was planned on, one line.
    support : Support or None
        The support surface and how it was chosen (:func:`contourgrasp.perception.find_support`);
        None when depth found no plane.
    grasp_height : float or None
        Height above the table of the open hand's lowest fingertip at ``T_camera_hand``, m, when
        the planner chose it (``plan_frame(descent=...)`` or ``grasp_height=...``); None when the
        executor chooses how deep to go.
    """

    plan: GraspPlan
    segmentation: Segmentation
    metric: MetricContour
    camera: Intrinsics
    T_camera_hand: np.ndarray
    T_camera_pregrasp: np.ndarray
    T_base_hand: np.ndarray | None
    filled_depth_px: int
    height_map: HeightMap | None = None
    candidates: tuple = ()
    target: perception.Candidate | None = None
    target_reason: str = ""
    support: perception.Support | None = None
    grasp_height: float | None = None

    @property
    def quaternion_xyzw(self) -> np.ndarray:
        """(4,) float: rotation of ``T_camera_hand`` as a unit quaternion (x, y, z, w)."""
        return Rotation.from_matrix(self.T_camera_hand[:3, :3]).as_quat()


def plan_frame(
    rgb,
    depth,
    intrinsics: Intrinsics,
    hand: Hand,
    *,
    segment: str = "auto",
    mask=None,
    depth_mode: str = "max",
    footprint: bool | None = None,
    fill_holes: bool = True,
    colour_offset_px=None,
    approach_offset: float = APPROACH_OFFSET,
    standoff: float = 0.10,
    T_base_camera=None,
    target_px=None,
    roi=None,
    descent: bool = False,
    grasp_height: str | float | None = None,
    slice_contour: bool | str = False,
    closing_sweep: bool = False,
    closing_obstacles: bool = False,
    low_objects: bool = False,
    **synthesis_options,
) -> ImageGraspPlan:
    """Plan a grasp on one RGB-D frame with a :class:`~contourgrasp.hand.Hand`.

    :func:`contourgrasp.plan_grasp` is this with a hand preset name or file and
    a planner's settings.

    Parameters
    ----------
    rgb : (H, W, 3) uint8 or None
        Colour image, RGB order, registered to ``depth``.
    depth : (H, W) float
        Depth in meters (0 or NaN where missing).
    intrinsics : Intrinsics
    hand : Hand
    segment : {"auto", "rgb", "depth"}
        Segmentation method (:func:`contourgrasp.perception.segment`); ignored with ``mask``.
    mask : (H, W) bool, optional
        The user's own object mask; skips segmentation.
    depth_mode : {"max", "plane"}
        Height of the contour's plane (:func:`contourgrasp.perception.contour_to_metric`). With ``"max"``
        depth segmentation returns the object's footprint when the camera is tilted, planned on the table
        itself; with ``"plane"`` always the pixels that see the object, planned at the object's top.
    footprint : bool, optional
        With ``depth_mode="max"``: plan the object's footprint on the table
        (:func:`contourgrasp.perception.object_footprint`) even from a top-down camera (True), or
        never (False); by default only when the camera is tilted more than 2 deg.
    fill_holes : bool
        Fill small depth holes (nearest valid reading) before use.
    colour_offset_px : (int, int), optional
        The colour-depth misregistration (dx, dy) if known, ``(0, 0)`` for a pair registered to the
        pixel; by default ``"auto"`` segmentation estimates it
        (:func:`contourgrasp.perception.colour_offset`).
    approach_offset : float
        Added to the nearest depth inside the contour, m; at most ``MAX_APPROACH_OFFSET`` (0.5 m)
        either way (:mod:`contourgrasp.tolerances`).
    standoff : float
        Distance of the pre-grasp pose back along the approach axis, m, in [0, ``MAX_STANDOFF``] (2 m).
    T_base_camera : (4, 4) float, optional
        Camera pose in the robot's base frame, a rigid transform (checked as
        :func:`contourgrasp.io.camera_file.read_extrinsics` checks a file's).
    target_px : (int, int), optional
        Plan on the object under this pixel (u, v) of the depth image.
    roi : (int, int, int, int), optional
        Plan on the wholly visible object with most pixels in this box (x, y, w, h).
        Without ``target_px`` and ``roi`` the object is chosen by the default ``"hand"`` rule of
        :func:`contourgrasp.perception.choose_target`: of the wholly visible candidates narrower than
        the hand's opening and at least half as large as the largest of them, the one nearest the
        image centre (with one object in view: the largest wholly visible region, as always);
        regions touching the image border are listed in ``candidates`` but never chosen.
        Both need depth segmentation (not ``mask`` or ``segment="rgb"``).
    descent : bool
        Plan with the hand's 3-D bodies: a pose is feasible only if the open hand descends to the
        grasp height without any finger's body or the palm passing below the scene's height map
        (:class:`~contourgrasp.synthesis.Descent`). Needs a 3-D hand and a table plane; without
        them the plan is 2-D and says so in its notes.
    grasp_height : {"clearance", "auto"} or float, optional
        The height above the table of the open hand's lowest fingertip at the grasp
        (:func:`~contourgrasp.synthesis.grasp_height.grasp_height`); with ``descent`` and None,
        ``"clearance"``. Planned, it is the plan's ``grasp_height`` and ``T_camera_hand`` is the
        hand at that height; None without ``descent``: ``T_camera_hand`` is at the approach
        depth and the executor chooses how deep to go, as in the thesis.
    slice_contour : bool or "unbalanced" or "hand"
        With a planned grasp height: plan on the object's cross-section at that height
        (:func:`contourgrasp.perception.cross_section`) rather than its outline as seen, where the
        height map has one. ``"unbalanced"``: plan on the outline seen, and on the cross-section only
        when no pose balances the squeeze on the outline seen but one does on the section (the plan's
        notes say so, :data:`NOTE_SECTION`). Our reading: a tall object seen from above off the
        camera's axis shows its side wall, so its outline seen is wider than the object at any height
        (a standing cracker box's about twice its top), and fingers planned on the far side of it close
        on air; where the outline seen still balances, it is kept (planning every object on its section
        lost on the training objects, ``benchmarks/hand3d_sweep.md``). ``"hand"``: the hand's own
        (:attr:`Hand.slice_contour`), as ``default`` asks: a hand that wraps an object with curling
        links meets it where it is widest, the outline seen.
    closing_sweep : bool
        With ``descent``: also refuse a pose where a touching finger's chain would meet the scene
        before its tip reaches its grasp point (:mod:`contourgrasp.synthesis.sweep`).
    closing_obstacles : bool
        With ``descent``: also refuse a pose where a finger, closing until it meets the target (or to
        its end, if it misses), would run into a neighbouring object or a bin's wall -- the height
        map's obstacle cells (:func:`contourgrasp.synthesis.sweep.closing_hits`).
    low_objects : bool
        Plan an object lower than ``tolerances.LOW_OBJECT_HEIGHT`` (its height map's ``max_height``) first as a
        pinch of the thumb against one finger with the fingertips as balls (:func:`~contourgrasp.synthesis.search`'s
        ``low_object``); needs a table (the height map).
    **synthesis_options
        Keyword options of :func:`contourgrasp.synthesis.search`.

    Raises
    ------
    PerceptionError
        Bad images, intrinsics, extrinsics or options; no object found (SegmentationError).
    PlannerError
        An unknown or bad planning option.
    HandError
        ``hand`` is not a :class:`~contourgrasp.hand.Hand`.
    NoFeasibleGrasp
        The object was found but no pose satisfies the constraints.
    """
    if not isinstance(hand, Hand):
        raise HandError(f"hand must be a contourgrasp.Hand, got {type(hand).__name__}")
    standoff = validation.non_negative("standoff", standoff, error=PerceptionError)
    validation.at_most("standoff", standoff, MAX_STANDOFF, " m", error=PerceptionError)
    validation.options("synthesis options", synthesis_options, search, error=PlannerError)
    if T_base_camera is not None:
        T_base_camera = validation.rigid_transform("T_base_camera", T_base_camera, error=PerceptionError,
                                                   rotation_tolerance=ROTATION_TOLERANCE,
                                                   row_tolerance=HOMOGENEOUS_ROW)
    with perception.one_frame():
        seg, metric, filled, d, table, scene = _perceive(
            rgb, depth, intrinsics, segment=segment, mask=mask, depth_mode=depth_mode, footprint=footprint,
            fill_holes=fill_holes, colour_offset_px=colour_offset_px, approach_offset=approach_offset,
            target_px=target_px, roi=roi, max_width=perception.hand_opening(hand))
        heights = scene_heights(d, intrinsics, seg, metric, plane=table)
    asked = _grasp_height(hand, heights, descent, grasp_height)
    sweep = validation.flag("closing_sweep", closing_sweep, error=PlannerError)
    closing = validation.flag("closing_obstacles", closing_obstacles, error=PlannerError)
    spec = Descent(heights, *asked, sweep=sweep, closing=closing) if descent and asked is not None else None
    if validation.flag("low_objects", low_objects, error=PlannerError) and heights is not None:
        synthesis_options = {**synthesis_options, "low_object": bool(heights.max_height < tol.LOW_OBJECT_HEIGHT)}
    slicing = validation.choice("slice_contour", slice_contour, SLICE_CONTOUR, error=PlannerError)
    slicing = hand.slice_contour if slicing == "hand" else slicing
    section = perception.cross_section(heights, asked[0]) if slicing is True and asked is not None else None
    on_section = None
    if slicing == "unbalanced" and asked is not None:
        on_section = partial(_balanced_on_section, heights, hand, spec, asked[0], synthesis_options)
    plan = search(metric.contour_xy if section is None else section, hand, descent=spec,
                  balanced_alternative=on_section, **synthesis_options)
    tip_height = None if asked is None else asked[0] if plan.descent is None else float(plan.descent.tip_height[0])
    depth_at = (metric.approach_depth if tip_height is None
                else _palm_depth(metric, heights, hand, plan.pose, tip_height))
    T_camera_hand = hand_pose(metric, plan.pose, depth_at)
    T_camera_pregrasp = T_camera_hand.copy()
    T_camera_pregrasp[:3, 3] -= standoff * T_camera_hand[:3, 2]
    T_base_hand = None if T_base_camera is None else T_base_camera @ T_camera_hand
    return ImageGraspPlan(plan, seg, metric, intrinsics, T_camera_hand, T_camera_pregrasp, T_base_hand, filled,
                          heights, *scene, grasp_height=tip_height)


#: The values of :func:`plan_frame`'s ``slice_contour``: a hand's, or the hand's own.
SLICE_CONTOUR = (*HAND_SLICE_CONTOUR, "hand")
#: The note of a plan made on the cross-section because no pose balanced the squeeze on the outline seen.
NOTE_SECTION = ("no pose balances the squeeze on the outline seen: planned on the object's cross-section "
                "{height:.0f} mm above the table, the height where the fingertips close")


def _balanced_on_section(heights: HeightMap, hand: Hand, descent, height: float, options) -> GraspPlan:
    """The plan on the object's cross-section at ``height`` with a balanced squeeze (the search requires
    it): the outline seen's ``balanced_alternative``. Raises NoFeasibleGrasp without one, or without a section."""
    section = perception.cross_section(heights, height)
    if section is None:
        raise NoFeasibleGrasp("the height map has no cross-section of the object")
    sliced = search(section, hand, descent=descent, balance_required=True, **options)
    return replace(sliced, search_notes=sliced.search_notes + (NOTE_SECTION.format(height=1000 * height),))


def _grasp_height(hand: Hand, heights: HeightMap | None, descent, grasp_height) -> tuple[float, float] | None:
    """The grasp height asked for and the highest accepted, for :func:`plan_frame`'s options; None: not
    planned (a 2-D hand, no table). A bad ``grasp_height`` is refused whether or not it could be used."""
    descent = validation.flag("descent", descent, error=PlannerError)
    if grasp_height is not None:
        check_grasp_height(grasp_height)
    if grasp_height is None and not descent:
        return None
    if not hand.is_3d or heights is None:
        return None
    return choose_grasp_height(hand, heights, "clearance" if grasp_height is None else grasp_height)


def _palm_depth(metric: MetricContour, heights: HeightMap, hand: Hand, pose, tip_height: float) -> float:
    """Depth along the approach axis of the palm's underside at ``pose`` when the open tips are ``tip_height`` up."""
    x, y = pose[:2]
    n, offset = heights.table_normal, heights.table_offset
    z = (tip_height + hand.open_tip_depth - offset - n[0] * x - n[1] * y) / n[2]
    return float(z + metric.R_camera_plane[:, 2] @ metric.origin)


def find_objects(depth, intrinsics: Intrinsics, *, fill_holes: bool = True) -> perception.Support:
    """The support surface and every candidate on it, as :func:`plan_frame` finds them (``plan --all``).

    The depth is checked and its small holes filled as in :func:`plan_frame`, so a candidate's
    pixels here are its pixels there: ``plan_frame(target_px=...)`` at one of them plans on it.

    Raises
    ------
    PerceptionError
        Bad depth or intrinsics; no support plane (SegmentationError ``"no-plane"``).
    """
    check_intrinsics(intrinsics)
    validation.flag("fill_holes", fill_holes, error=PerceptionError)
    d = perception.as_depth(depth)
    intrinsics.check_shape(d.shape, "depth image")
    if fill_holes:
        d, _ = perception.fill_depth_holes(d)
    with perception.one_frame():
        return perception.find_support(d, intrinsics)


def perceive(
    rgb,
    depth,
    intrinsics: Intrinsics,
    *,
    segment: str = "auto",
    mask=None,
    depth_mode: str = "max",
    footprint: bool | None = None,
    fill_holes: bool = True,
    colour_offset_px=None,
    approach_offset: float = APPROACH_OFFSET,
    target_px=None,
) -> tuple[Segmentation, MetricContour, int]:
    """The perception half of :func:`plan_frame`: (segmentation, metric contour, filled depth pixels).

    Checks the depth, fills small holes, segments (or takes ``mask``) and puts
    the contour in meters; the options are :func:`plan_frame`'s.
    """
    with perception.one_frame():
        return _perceive(rgb, depth, intrinsics, segment=segment, mask=mask, depth_mode=depth_mode,
                         footprint=footprint, fill_holes=fill_holes, colour_offset_px=colour_offset_px,
                         approach_offset=approach_offset, target_px=target_px)[:3]


def _perceive(rgb, depth, intrinsics, *, segment, mask, depth_mode, footprint, fill_holes, colour_offset_px,
              approach_offset, target_px=None, roi=None, max_width=None):
    """:func:`perceive`, the depth image it worked on (holes filled), the support plane (None if there is
    none: found once here, :func:`contourgrasp.perception.find_support`, and shared by segmentation, the
    metric contour and the height map), and (candidates, target, reason, support).

    Without ``target_px`` and ``roi`` the target is chosen by the ``"hand"`` rule of
    :func:`contourgrasp.perception.choose_target` (``max_width``: the hand's opening); when that is
    the largest wholly visible candidate, segmentation picks it itself (the same region, and its
    warnings), else it is handed to segmentation as the target."""
    _check_options(intrinsics, segment, depth_mode, footprint, fill_holes, colour_offset_px, approach_offset)
    chosen = target_px is not None or roi is not None
    if target_px is not None and roi is not None:
        raise PerceptionError("give target_px or roi, not both")
    shape = (intrinsics.height, intrinsics.width)
    if target_px is not None:
        target_px = perception.candidates.check_pixel(target_px, shape)
    if roi is not None:
        roi = perception.candidates.check_roi(roi, shape)
    if chosen and (mask is not None or segment == "rgb"):
        raise PerceptionError("target_px and roi choose among the depth candidates: not with a mask or segment='rgb'")
    d = perception.as_depth(depth)
    intrinsics.check_shape(d.shape, "depth image")
    if not perception.valid_depth(d).any():
        raise PerceptionError("the depth image has no valid reading (all 0, NaN or outside the sensor range)")
    filled = 0
    if fill_holes:
        d, filled = perception.fill_depth_holes(d)
    if mask is not None:
        intrinsics.check_shape(np.shape(mask), "mask")
    try:
        support = perception.find_support(d, intrinsics)
    except SegmentationError:
        if chosen:
            raise
        support = None
    plane = None if support is None else support.plane
    candidates = () if support is None else support.candidates
    target, reason = None, ""
    if chosen:
        pixel_heights = None if target_px is None or plane is None else perception.table.heights(d, intrinsics, plane)
        target, reason = perception.choose_target(candidates, target_px=target_px, roi=roi, pixel_heights=pixel_heights)
    elif mask is None and segment != "rgb" and any(c.in_view for c in candidates):
        target, reason = perception.choose_target(candidates, max_width=max_width)
    if mask is not None:
        seg = perception.segment_from_mask(mask)
    else:
        options = {"footprint": False if depth_mode == "plane" else footprint}
        if fill_holes:
            options["fill_holes"] = False  # d is filled already: a second pass finds the same larger holes only
        if plane is not None and segment != "rgb":
            options["plane"] = plane  # the same fit segmentation would make
        if target is not None and (chosen or target is not next(c for c in candidates if c.in_view)):
            options["target"] = target.mask  # else segmentation's own pick, the largest wholly visible region
        if target_px is not None:
            options["target_px"] = target_px  # which of the target's footprints, where touching neighbours share it
        seg = perception.segment(rgb, d, intrinsics, method=segment, colour_offset_px=colour_offset_px,
                                 depth_options=options)
    if mask is not None or seg.method == "rgb":
        target, reason = _found_target(candidates, seg, mask is not None)
    metric = perception.contour_to_metric(
        seg.contour_px, d, intrinsics, depth_mode=depth_mode, plane=plane if seg.plane is None else seg.plane,
        on_table=seg.on_table, offset=approach_offset,
    )
    return seg, metric, filled, d, plane, (candidates, target, reason, support)


def _found_target(candidates, seg: Segmentation, user_mask: bool):
    """The candidate a user's mask or the RGB method's region overlaps most, and why (None when it overlaps none)."""
    overlap = [(int((c.mask & seg.mask).sum()), c) for c in candidates]
    n, best = max(overlap, key=lambda item: item[0], default=(0, None))
    what = "the user's mask" if user_mask else f"the region found by the {seg.method} method"
    if best is None or n == 0:
        return None, f"{what} (no depth candidate under it)"
    return best, f"{what}, over candidate {best.label}"


def scene_heights(depth, intrinsics: Intrinsics, segmentation: Segmentation, metric: MetricContour, *,
                  plane: Plane | None = None) -> HeightMap | None:
    """The height map of :func:`plan_frame` (:func:`contourgrasp.perception.height_map`, default cell and margin).

    The table is ``plane`` when given (:func:`plan_frame` fits it once), else the segmentation's
    plane; a user's mask or the RGB method brings none, and it is fitted then (the same fit
    :func:`contourgrasp.perception.contour_to_metric` makes). None when there is no table plane in
    the depth image.

    Parameters
    ----------
    depth : (H, W) float
        The depth image perception worked on (holes filled).
    intrinsics : Intrinsics
    segmentation : Segmentation
    metric : MetricContour

    Returns
    -------
    HeightMap or None
    """
    plane = segmentation.plane if plane is None else plane
    if plane is None:
        if metric.tilt is None:  # contour_to_metric found no table either
            return None
        try:
            plane = perception.fit_table_plane(depth, intrinsics)
        except SegmentationError:
            return None
    return perception.height_map(depth, intrinsics, plane, metric, segmentation.mask)


def _check_options(intrinsics, segment, depth_mode, footprint, fill_holes, colour_offset_px, approach_offset):
    """Refuse, by name, a perception option of :func:`perceive` of the wrong type or value."""
    check_intrinsics(intrinsics)
    validation.choice("segment", segment, SEGMENT_CHOICES, error=PerceptionError)
    validation.choice("depth_mode", depth_mode, perception.DEPTH_MODES, error=PerceptionError)
    if footprint is not None and not isinstance(footprint, (bool, np.bool_)):
        raise PerceptionError(f"footprint must be True, False or None, got {footprint!r}")
    if footprint and depth_mode == "plane":
        raise PerceptionError("footprint=True needs depth_mode 'max': a footprint lies on the table, not at the object's top")
    validation.flag("fill_holes", fill_holes, error=PerceptionError)
    if colour_offset_px is not None:
        validation.pixel_offset("colour_offset_px", colour_offset_px, error=PerceptionError)
    offset = validation.finite("approach_offset", approach_offset, error=PerceptionError)
    if abs(offset) > MAX_APPROACH_OFFSET:
        raise PerceptionError(f"approach_offset must be within +-{MAX_APPROACH_OFFSET:g} m of the object's top, "
                              f"got {offset:g} m")


def hand_pose(metric: MetricContour, pose, depth: float) -> np.ndarray:
    """(4, 4) float: T_camera_hand of a planar pose (x, y, yaw) at ``depth`` along the approach axis."""
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    T = np.eye(4)
    T[:3, :3] = metric.R_camera_plane @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    T[:3, 3] = metric.to_camera([[x, y]], depth=depth)[0]
    return T

