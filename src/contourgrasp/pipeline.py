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
from .hand import Hand
from .perception import Approach, ApproachView, HeightMap, Intrinsics, MetricContour, Plane, Segmentation, view_along
from .perception.camera import check_intrinsics
from .perception.options import PerceptionOptions
from .perception.view_along import column_points
from .synthesis import Descent, GraspMemory, GraspPlan, SceneMemory, search
from .synthesis.grasp_height import grasp_height as choose_grasp_height
from .synthesis.options import SceneOptions, SearchOptions
from .tolerances import HOMOGENEOUS_ROW, MAX_STANDOFF, ROTATION_TOLERANCE


@dataclass(frozen=True, kw_only=True)
class PlanOptions:
    """Every option of :func:`plan_frame`, by stage: what a planner file, the command line and the ROS node's
    parameters set (:func:`contourgrasp.validation.with_options` puts flat-named values in).

    Attributes
    ----------
    perception : PerceptionOptions
    search : SearchOptions
    scene : SceneOptions
        Planning with the hand's 3-D bodies in the scene.
    standoff : float
        Distance of the pre-grasp pose back along the approach axis, m, in [0, ``MAX_STANDOFF``] (2 m).

    Raises
    ------
    InputError
        Naming the option of the wrong type or value (PerceptionError for ``standoff``).

    Examples
    --------
    >>> from contourgrasp.validation import with_options
    >>> options = with_options(PlanOptions(), {"yaw_step": 0.1, "descent": True}, what="example")
    >>> options.search.grid.yaw_step, options.scene.descent, options.standoff
    (0.1, True, 0.1)
    """

    perception: PerceptionOptions = PerceptionOptions()
    search: SearchOptions = SearchOptions()
    scene: SceneOptions = SceneOptions()
    standoff: float = 0.10

    def __post_init__(self):
        for name, kind in (("perception", PerceptionOptions), ("search", SearchOptions), ("scene", SceneOptions)):
            if not isinstance(getattr(self, name), kind):
                raise PlannerError(f"{name} must be a {kind.__name__}, got {type(getattr(self, name)).__name__}")
        standoff = validation.non_negative("standoff", self.standoff, error=PerceptionError)
        object.__setattr__(self, "standoff", validation.at_most("standoff", standoff, MAX_STANDOFF, " m",
                                                                error=PerceptionError))


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
        executor chooses how deep to go. For a side or tilted approach: the tips' distance in front of
        the reference plane through the object's centroid (:mod:`contourgrasp.perception.view_along`).
    view : ApproachView or None
        Where the plan approaches other than top-down: the scene seen along its approach; ``plan`` and
        ``grasp_height`` are then in its frame. None: top-down, in the planning frame of ``metric``.
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
    view: ApproachView | None = None

    @property
    def quaternion_xyzw(self) -> np.ndarray:
        """(4,) float: rotation of ``T_camera_hand`` as a unit quaternion (x, y, z, w)."""
        return Rotation.from_matrix(self.T_camera_hand[:3, :3]).as_quat()

    @property
    def approach(self) -> Approach:
        """The direction the hand approaches along (top-down unless :attr:`view`)."""
        return TOP_DOWN if self.view is None else self.view.approach

    @property
    def frame(self) -> MetricContour:
        """The frame ``plan`` is in (:func:`plan_metric`): ``metric``'s, or the approach frame of :attr:`view`."""
        return plan_metric(self.metric, self.view)

    @property
    def seen(self) -> np.ndarray:
        """(H, W) bool: the depth image's pixels that see the planned object (the target candidate's; else the
        segmentation's mask), what a :class:`~contourgrasp.synthesis.SceneMemory` finds the object by."""
        return _seen(self.segmentation, self.target)


def _seen(segmentation: Segmentation, target: perception.Candidate | None) -> np.ndarray:
    """(H, W) bool: the pixels that see the planned object (:attr:`ImageGraspPlan.seen`)."""
    return segmentation.mask if target is None else target.mask


def plan_frame(
    rgb,
    depth,
    intrinsics: Intrinsics,
    hand: Hand,
    options: PlanOptions = PlanOptions(),
    *,
    mask=None,
    target_px=None,
    roi=None,
    T_base_camera=None,
    colour_intrinsics: Intrinsics | None = None,
    memory: GraspMemory | SceneMemory | None = None,
) -> ImageGraspPlan:
    """Plan a grasp on one RGB-D frame with a :class:`~contourgrasp.hand.Hand`.

    :func:`contourgrasp.plan_grasp` is this with a hand preset name or file, a planner's settings and
    flat-named options.

    Parameters
    ----------
    rgb : (H', W', 3) or (H', W') uint8, or None
        Colour image, RGB order, registered to ``depth``; at another resolution it is resampled onto the
        depth image's grid (:func:`contourgrasp.perception.colour_on_depth`).
    depth : (H, W) float
        Depth in meters (0 or NaN where missing).
    intrinsics : Intrinsics
        Of the depth image.
    hand : Hand
    options : PlanOptions
        Perception, search and 3-D options (:class:`PlanOptions`; the defaults are the thesis's).
    mask : (H, W) bool, optional
        The user's own object mask; skips segmentation.
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
    T_base_camera : (4, 4) float, optional
        Camera pose in the robot's base frame, a rigid transform (checked as
        :func:`contourgrasp.io.camera_file.read_extrinsics` checks a file's).
    colour_intrinsics : Intrinsics, optional
        The colour camera's, when ``rgb`` has another resolution than ``depth`` and not the same view
        scaled.
    memory : GraspMemory or SceneMemory, optional
        The grasps of this object that failed (:class:`~contourgrasp.synthesis.memory.GraspMemory`): no
        pose near one, in the object's frame as it is seen now, is planned, nor a side or tilted direction near
        one that failed, and the approach kinds that failed fewer times are tried first (:func:`approach_order`).
        After a failure, keep ``memory.with_failure(result.metric.contour_xy, result.plan.pose,
        approach=result.approach)`` for the next plan. A :class:`~contourgrasp.synthesis.SceneMemory` (a scene of
        several objects, a camera that stays put) gives the memory of the object planned on, found by where it is
        seen; keep ``memory.with_failure(result.seen, result.metric.contour_xy, result.plan.pose,
        approach=result.approach)``.

    Notes
    -----
    The 3-D options (:class:`~contourgrasp.synthesis.options.SceneOptions`) need a 3-D hand and a table
    plane; without them the plan is 2-D and says so in its notes. ``slice_contour`` plans on the object's
    cross-section at the grasp height rather than its outline as seen, where the height map has one;
    ``"unbalanced"`` plans on the outline seen, and on the cross-section only when no pose balances the
    squeeze on the outline seen but one does on the section (the plan's notes say so,
    :data:`NOTE_SECTION`). Our reading: a tall object seen from above off the camera's axis shows its side
    wall, so its outline seen is wider than the object at any height (a standing cracker box's about twice
    its top), and fingers planned on the far side of it close on air; where the outline seen still
    balances, it is kept (planning every object on its section lost on the training objects,
    docs/studies.md). ``"hand"``: the hand's own (:attr:`Hand.slice_contour`), as ``default`` asks: a hand
    that wraps an object with curling links meets it where it is widest, the outline seen.

    Raises
    ------
    PerceptionError
        Bad images, intrinsics or extrinsics; no object found (SegmentationError).
    PlannerError
        ``options`` is not a :class:`PlanOptions`.
    HandError
        ``hand`` is not a :class:`~contourgrasp.hand.Hand`.
    NoFeasibleGrasp
        The object was found but no pose satisfies the constraints.
    """
    if not isinstance(hand, Hand):
        raise HandError(f"hand must be a contourgrasp.Hand, got {type(hand).__name__}")
    if not isinstance(options, PlanOptions):
        raise PlannerError(f"options must be a contourgrasp.pipeline.PlanOptions, got {type(options).__name__}")
    if memory is not None and not isinstance(memory, GraspMemory | SceneMemory):
        raise PlannerError(f"memory must be a contourgrasp.synthesis.GraspMemory or SceneMemory, "
                           f"got {type(memory).__name__}")
    if T_base_camera is not None:
        T_base_camera = validation.rigid_transform("T_base_camera", T_base_camera, error=PerceptionError,
                                                   rotation_tolerance=ROTATION_TOLERANCE,
                                                   row_tolerance=HOMOGENEOUS_ROW)
    scene_options, search_options = options.scene, options.search
    with perception.one_frame():
        seg, metric, filled, d, table, scene = _perceive(
            rgb, depth, intrinsics, options.perception, mask=mask, target_px=target_px, roi=roi,
            max_width=perception.hand_opening(hand), colour_intrinsics=colour_intrinsics)
        heights = scene_heights(d, intrinsics, seg, metric, plane=table)
    if isinstance(memory, SceneMemory):  # the memory of the object planned on
        memory = memory.of(_seen(seg, scene[1]))
    asked = _grasp_height(hand, heights, scene_options)
    spec = (Descent(heights, *asked, sweep=scene_options.closing_sweep, closing=scene_options.closing_obstacles)
            if scene_options.descent and asked is not None else None)
    low = scene_options.low_objects and heights is not None and bool(heights.max_height < tol.LOW_OBJECT_HEIGHT)
    slicing = hand.slice_contour if scene_options.slice_contour == "hand" else scene_options.slice_contour
    section = perception.cross_section(heights, asked[0]) if slicing is True and asked is not None else None
    exclude = None if not memory else partial(memory.excluded, metric.contour_xy)
    avoid = None if not memory else partial(memory.avoids, metric.contour_xy)
    on_section = None
    if slicing == "unbalanced" and asked is not None:
        on_section = partial(_balanced_on_section, heights, hand, spec, asked[0], search_options, low, exclude)
    kinds = approach_order(scene_options.approaches, memory)
    if kinds != ["top"] and spec is None:
        if not approaches_supported(hand, scene_options):
            raise PlannerError(f"approaches {scene_options.approaches!r} need descent=True and a 3-D hand "
                               f"(its file's chains): a side or tilted hand is checked against the scene in 3-D")
        raise NoFeasibleGrasp(f"approaches {scene_options.approaches!r} need a table plane: none was found")
    top_down = partial(search, metric.contour_xy if section is None else section, hand, search_options, descent=spec,
                       balanced_alternative=on_section, low_object=low, exclude=exclude)
    plan, view = _plan_kinds(kinds, top_down, partial(_best_along, heights=heights, hand=hand, avoid=avoid,
                                                      scene_options=scene_options, search_options=search_options))
    tip_height = None if asked is None else asked[0] if plan.descent is None else float(plan.descent.tip_height[0])
    frame = plan_metric(metric, view)
    depth_at = (metric.approach_depth if tip_height is None
                else palm_depth(frame, heights if view is None else view.heights, hand, plan.pose, tip_height))
    T_camera_hand = hand_pose(frame, plan.pose, depth_at)
    T_camera_pregrasp = T_camera_hand.copy()
    T_camera_pregrasp[:3, 3] -= options.standoff * T_camera_hand[:3, 2]
    T_base_hand = None if T_base_camera is None else T_base_camera @ T_camera_hand
    return ImageGraspPlan(plan, seg, metric, intrinsics, T_camera_hand, T_camera_pregrasp, T_base_hand, filled,
                          heights, *scene, grasp_height=tip_height, view=view)


def approaches_supported(hand: Hand, scene_options: SceneOptions) -> bool:
    """Whether ``scene_options.approaches`` can be planned for ``hand``: top-down alone always; a side or tilted kind
    needs ``descent`` and a 3-D hand (its file's chains), which check the hand against the scene along it."""
    return scene_options.approaches == "top" or (scene_options.descent and hand.is_3d)


def _plan_kinds(kinds, top_down, along) -> tuple[GraspPlan, ApproachView | None]:
    """The plan of the first kind in ``kinds`` with a feasible pose, or of the first after it that balances the
    squeeze where it does not (:func:`approach_order`), and its view (None: top-down).

    ``top_down()`` plans top-down (raising NoFeasibleGrasp), ``along(kind, balanced_only)`` a side or tilted kind
    ((None, None): none; ``balanced_only`` once an earlier kind has a plan, which only a balanced one replaces).
    Raises the top-down reason when top-down alone was asked for and failed, else NoFeasibleGrasp."""
    plan, view, top_down_error = None, None, None
    for kind in kinds:
        found, seen_along = None, None
        if kind == "top":
            try:
                found = top_down()
            except NoFeasibleGrasp as err:
                top_down_error = err
        else:
            found, seen_along = along(kind, balanced_only=plan is not None)
        if found is not None and (plan is None or found.balanced):
            plan, view = found, seen_along
        if plan is not None and plan.balanced:
            return plan, view
    if plan is not None:
        return plan, view
    if kinds == ["top"]:
        raise top_down_error
    raise NoFeasibleGrasp(f"no feasible grasp along any approach of {'+'.join(kinds)!r}"
                          + ("" if top_down_error is None else f"; top-down: {top_down_error}"))


#: The top-down approach: along the table's normal, into it.
TOP_DOWN = Approach(math.pi / 2)

#: Elevations (rad) of the approach kinds other than top-down.
APPROACH_ELEVATIONS = {"side": 0.0, "tilted": math.pi / 4}


def approach_set(approaches: str, heights: HeightMap) -> tuple[Approach, ...]:
    """The approaches other than top-down that :attr:`SceneOptions.approaches` names (e.g. ``"top+side"``).

    Per kind's elevation (:data:`APPROACH_ELEVATIONS`), four azimuths: along the target footprint's
    principal axis, across it, and their opposites (the footprint: the map's object cells; a round one's
    axis is any). Our reading of the thesis's "check different viewpoints": a person takes a can, a
    bottle or a standing box from the side across or along it, not at an angle the object gives no
    reason for.
    """
    elevations = [APPROACH_ELEVATIONS[k] for k in approaches.split("+") if k in APPROACH_ELEVATIONS]
    if not elevations or not heights.object.any():
        return ()
    rows, cols = np.nonzero(heights.object)
    xs, ys = heights.centres()
    cells = np.c_[xs[cols], ys[rows]]
    cells = cells - cells.mean(axis=0)
    _, vectors = np.linalg.eigh(cells.T @ cells)
    axis = math.atan2(vectors[1, 1], vectors[0, 1])
    return tuple(Approach(e, axis + k * math.pi / 2) for e in elevations for k in range(4))


def approach_order(approaches: str, memory: GraspMemory | None = None) -> list[str]:
    """The approach kinds of :attr:`SceneOptions.approaches` in the order a plan tries them: as named, the kinds
    that failed fewer times on this object (``memory``) first.

    :func:`plan_frame` plans the first kind in this order with a feasible pose, unless its plan does not
    balance the squeeze (:attr:`GraspPlan.balanced`) and a later kind's does: then that one.

    >>> approach_order("top+tilted+side")
    ['top', 'tilted', 'side']
    """
    kinds = approaches.split("+")
    failed = {} if memory is None else memory.failures_by_kind()
    return sorted(kinds, key=lambda kind: failed.get(kind, 0))


def _best_along(kind: str, *, balanced_only: bool = False, heights: HeightMap, hand: Hand,
                scene_options: SceneOptions, search_options: SearchOptions,
                avoid=None) -> tuple[GraspPlan | None, ApproachView | None]:
    """The lowest-cost plan along the approaches of ``kind`` (:func:`approach_set`) that ``avoid`` (Approach -> bool:
    a grasp failed along it) does not refuse, of those that balance the squeeze where one does (``balanced_only``: of
    those alone, so no approach's search goes on without the balance), and its view; (None, None) when none has a
    feasible pose. Each is planned on the target's cross-section at the grasp height asked for in its view: the
    fingertips close there, and what stands in front of them is what they meet."""
    best, best_view = None, None
    points = column_points(heights)
    for approach in approach_set(kind, heights):
        if avoid is not None and avoid(approach):
            continue
        try:
            view = view_along(heights, approach, points=points)
        except PerceptionError:  # the target hidden along it
            continue
        asked = choose_grasp_height(hand, view.heights, scene_options.grasp_height or "clearance")
        section = perception.cross_section(view.heights, asked[0])
        if section is None:
            continue
        spec = Descent(view.heights, *asked, sweep=scene_options.closing_sweep, closing=scene_options.closing_obstacles)
        try:
            plan = search(section, hand, search_options, descent=spec, balance_required=balanced_only)
        except NoFeasibleGrasp:
            continue
        if best is None or (not plan.balanced, plan.cost.total) < (not best.balanced, best.cost.total):
            best, best_view = plan, view
    return best, best_view


def plan_to_camera(metric: MetricContour, view: ApproachView | None, grasp_height: float | None, xy) -> np.ndarray:
    """(n, 3) float: camera-frame points of a plan's frame's points (n, 2): in the contour's plane for a top-down
    plan (``view`` None), at ``grasp_height`` in front of the reference plane (where the fingertips close) for a side
    or tilted one (:attr:`ImageGraspPlan.view`)."""
    frame = plan_metric(metric, view)
    points = frame.to_camera(xy)
    return points if view is None else points - grasp_height * frame.R_camera_plane[:, 2]


def plan_metric(metric: MetricContour, view: ApproachView | None) -> MetricContour:
    """The planning frame of a plan: ``metric`` for a top-down one (``view`` None); else ``metric`` with the approach
    frame of ``view`` as its planning frame (its contour the outline seen along it, its origin the view's)."""
    if view is None:
        return metric
    return replace(metric, contour_xy=view.contour_xy, R_camera_plane=metric.R_camera_plane @ view.R_plane_view,
                   origin=metric.origin + metric.R_camera_plane @ view.origin)


#: The note of a plan made on the cross-section because no pose balanced the squeeze on the outline seen.
NOTE_SECTION = ("no pose balances the squeeze on the outline seen: planned on the object's cross-section "
                "{height:.0f} mm above the table, the height where the fingertips close")


def _balanced_on_section(heights: HeightMap, hand: Hand, descent, height: float, options: SearchOptions,
                         low_object: bool, exclude=None) -> GraspPlan:
    """The plan on the object's cross-section at ``height`` with a balanced squeeze (the search requires
    it): the outline seen's ``balanced_alternative``. Raises NoFeasibleGrasp without one, or without a section."""
    section = perception.cross_section(heights, height)
    if section is None:
        raise NoFeasibleGrasp("the height map has no cross-section of the object")
    sliced = search(section, hand, options, descent=descent, balance_required=True, low_object=low_object,
                    exclude=exclude)
    return replace(sliced, search_notes=sliced.search_notes + (NOTE_SECTION.format(height=1000 * height),))


def _grasp_height(hand: Hand, heights: HeightMap | None, options: SceneOptions) -> tuple[float, float] | None:
    """The grasp height asked for and the highest accepted, for :func:`plan_frame`'s options; None: not
    planned (a 2-D hand, no table)."""
    if options.grasp_height is None and not options.descent:
        return None
    if not hand.is_3d or heights is None:
        return None
    return choose_grasp_height(hand, heights, "clearance" if options.grasp_height is None else options.grasp_height)


def palm_depth(metric: MetricContour, heights: HeightMap, hand: Hand, pose, tip_height: float) -> float:
    """Depth along the approach axis of the palm's underside at ``pose`` when the open tips are ``tip_height`` up."""
    x, y = pose[:2]
    n, offset = heights.table_normal, heights.table_offset
    z = (tip_height + hand.open_tip_depth - offset - n[0] * x - n[1] * y) / n[2]
    return float(z + metric.R_camera_plane[:, 2] @ metric.origin)


def _on_depth_grid(rgb, shape, intrinsics: Intrinsics, colour_intrinsics: Intrinsics | None):
    """``rgb`` on the depth image's grid of ``shape`` (:func:`contourgrasp.perception.colour_on_depth`); None
    stays None."""
    if rgb is None:
        return None
    return perception.colour_on_depth(rgb, shape, intrinsics=None if colour_intrinsics is None else intrinsics,
                                      colour_intrinsics=colour_intrinsics)


def find_objects(depth, intrinsics: Intrinsics, *, rgb=None, fill_holes: bool = True,
                 colour_offset_px=None, colour_intrinsics: Intrinsics | None = None) -> perception.Support:
    """The support surface and every candidate on it, as :func:`plan_frame` finds them (``plan --all``).

    The depth is checked and its small holes filled as in :func:`plan_frame`, and with ``rgb`` (put on
    the depth's grid as there: the same view scaled, or through ``colour_intrinsics``) a candidate
    holding touching objects is split as there
    (:func:`contourgrasp.perception.split_touching`, ``colour_offset_px`` as
    :class:`~contourgrasp.perception.PerceptionOptions`'), so a candidate's pixels here are its
    pixels there: ``plan_frame(target_px=...)`` at one of them plans on it.

    Raises
    ------
    PerceptionError
        Bad depth, colour or intrinsics; no support plane (SegmentationError ``"no-plane"``).
    """
    check_intrinsics(intrinsics)
    validation.flag("fill_holes", fill_holes, error=PerceptionError)
    d = perception.as_depth(depth)
    intrinsics.check_shape(d.shape, "depth image")
    rgb = _on_depth_grid(rgb, d.shape, intrinsics, colour_intrinsics)
    if fill_holes:
        d, _ = perception.fill_depth_holes(d)
    with perception.one_frame():
        support = perception.find_support(d, intrinsics)
        return replace(support, candidates=_split_touching(support.candidates, rgb, d, intrinsics, support.plane,
                                                           colour_offset_px))


def _split_touching(candidates, rgb, depth, intrinsics, plane, colour_offset_px):
    """:func:`contourgrasp.perception.split_touching` where there is colour and a candidate."""
    if rgb is None or not candidates:
        return candidates
    return perception.split_touching(candidates, rgb, depth, intrinsics, plane, colour_offset_px=colour_offset_px)


def perceive(rgb, depth, intrinsics: Intrinsics, options: PerceptionOptions = PerceptionOptions(), *, mask=None,
             target_px=None, colour_intrinsics: Intrinsics | None = None) -> tuple[Segmentation, MetricContour, int]:
    """The perception half of :func:`plan_frame`: (segmentation, metric contour, filled depth pixels).

    Checks the depth, fills small holes, segments (or takes ``mask``) and puts
    the contour in meters; the arguments are :func:`plan_frame`'s.
    """
    with perception.one_frame():
        return _perceive(rgb, depth, intrinsics, options, mask=mask, target_px=target_px,
                         colour_intrinsics=colour_intrinsics)[:3]


def _perceive(rgb, depth, intrinsics, options: PerceptionOptions, *, mask, target_px=None, roi=None, max_width=None,
              colour_intrinsics=None):
    """:func:`perceive`, the depth image it worked on (holes filled), the support plane (None if there is
    none: found once here, :func:`contourgrasp.perception.find_support`, and shared by segmentation, the
    metric contour and the height map), and (candidates, target, reason, support).

    Without ``target_px`` and ``roi`` the target is chosen by the ``"hand"`` rule of
    :func:`contourgrasp.perception.choose_target` (``max_width``: the hand's opening); when that is
    the largest wholly visible candidate, segmentation picks it itself (the same region, and its
    warnings), else it is handed to segmentation as the target."""
    check_intrinsics(intrinsics)
    if not isinstance(options, PerceptionOptions):
        raise PerceptionError(f"options must be a contourgrasp.perception.PerceptionOptions, "
                              f"got {type(options).__name__}")
    segment, depth_mode, fill_holes = options.segment, options.depth_mode, options.fill_holes
    chosen = target_px is not None or roi is not None
    if target_px is not None and roi is not None:
        raise PerceptionError("give target_px or roi, not both")
    shape = (intrinsics.height, intrinsics.width)
    if options.colour_offset_px is not None and any(abs(o) >= n for o, n in zip(options.colour_offset_px, shape[::-1])):
        raise PerceptionError(f"colour_offset_px {options.colour_offset_px} moves the colour image out of the "
                              f"{intrinsics.width}x{intrinsics.height} frame")
    if target_px is not None:
        target_px = perception.candidates.check_pixel(target_px, shape)
    if roi is not None:
        roi = perception.candidates.check_roi(roi, shape)
    if chosen and (mask is not None or segment == "rgb"):
        raise PerceptionError("target_px and roi choose among the depth candidates: not with a mask or segment='rgb'")
    d = perception.as_depth(depth)
    intrinsics.check_shape(d.shape, "depth image")
    rgb = _on_depth_grid(rgb, d.shape, intrinsics, colour_intrinsics)
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
    if mask is None and segment != "rgb":
        candidates = _split_touching(candidates, rgb, d, intrinsics, plane, options.colour_offset_px)
    target, reason = None, ""
    if chosen:
        pixel_heights = None if target_px is None or plane is None else perception.table.heights(d, intrinsics, plane)
        target, reason = perception.choose_target(candidates, target_px=target_px, roi=roi, pixel_heights=pixel_heights)
    elif mask is None and segment != "rgb" and any(c.in_view for c in candidates):
        target, reason = perception.choose_target(candidates, max_width=max_width)
    if mask is not None:
        seg = perception.segment_from_mask(mask)
    else:
        depth_options = {"footprint": False if depth_mode == "plane" else options.footprint}
        if fill_holes:
            depth_options["fill_holes"] = False  # d is filled already: a second pass finds the same larger holes only
        if plane is not None and segment != "rgb":
            depth_options["plane"] = plane  # the same fit segmentation would make
        if target is not None and (chosen or target.touching or target is not next(c for c in candidates if c.in_view)):
            depth_options["target"] = target.mask  # else segmentation's own pick, the largest wholly visible region
        if target_px is not None:
            depth_options["target_px"] = target_px  # which of the target's footprints, where neighbours share it
        seg = perception.segment(rgb, d, intrinsics, method=segment, colour_offset_px=options.colour_offset_px,
                                 depth_options=depth_options)
    if mask is not None or seg.method == "rgb":
        target, reason = _found_target(candidates, seg, mask is not None)
    metric = perception.contour_to_metric(
        seg.contour_px, d, intrinsics, depth_mode=depth_mode, plane=plane if seg.plane is None else seg.plane,
        on_table=seg.on_table, offset=options.approach_offset,
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


def hand_pose(metric: MetricContour, pose, depth: float) -> np.ndarray:
    """(4, 4) float: T_camera_hand of a planar pose (x, y, yaw) at ``depth`` along the approach axis."""
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    T = np.eye(4)
    T[:3, :3] = metric.R_camera_plane @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    T[:3, 3] = metric.to_camera([[x, y]], depth=depth)[0]
    return T

