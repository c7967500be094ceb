"""What to pick in a scene of several objects: a plan on some object of it (a bin, a table to clear).

:func:`plan_any` plans on the object :func:`~contourgrasp.pipeline.plan_frame` chooses itself, or where that one
has no feasible grasp on the next of :func:`objects_to_try`; a clearing run (:mod:`contourgrasp.sim.clearing`) asks
its planner in the same order. It composes :mod:`contourgrasp.pipeline`, as the CLI and the ROS node do.
"""

from __future__ import annotations

from . import perception
from .errors import NoFeasibleGrasp, PerceptionError, PlannerError, SegmentationError
from .hand import Hand
from .perception import Intrinsics
from .pipeline import ImageGraspPlan, PlanOptions, find_objects, plan_frame
from .synthesis import SceneMemory
from .tolerances import MAX_OBJECTS_TRIED


def plan_any(rgb, depth, intrinsics: Intrinsics, hand: Hand, options: PlanOptions = PlanOptions(), *,
             memory: SceneMemory | None = None, T_base_camera=None, colour_intrinsics: Intrinsics | None = None
             ) -> ImageGraspPlan:
    """A plan on some object of a scene of several: the one ``plan_frame`` chooses, or when it has none, the next.

    Our reading of "grasp something" (a bin, a table to clear): first the object :func:`~contourgrasp.pipeline.plan_frame`
    chooses itself, unless a grasp already failed in this scene (``memory`` has an object); then, or when that
    object has no feasible grasp, each other of :func:`objects_to_try` in turn -- those with the fewest failed
    grasps first, at most ``tolerances.MAX_OBJECTS_TRIED`` -- planned at the pixel deepest inside it, until one
    has a plan. The result's ``target`` and ``seen`` say which object it is on. The parameters are
    :func:`~contourgrasp.pipeline.plan_frame`'s; ``memory`` a :class:`~contourgrasp.synthesis.SceneMemory` (each object planned with its
    own failures).

    Raises
    ------
    NoFeasibleGrasp
        No object tried has a plan; the reason names how many were tried, and the last one's reason.
    InputError
        As :func:`~contourgrasp.pipeline.plan_frame`, for the frame and the options.
    """
    if memory is not None and not isinstance(memory, SceneMemory):
        raise PlannerError(f"plan_any's memory must be a SceneMemory, got {type(memory).__name__}")
    if options.perception.segment == "rgb":
        raise PerceptionError("plan_any chooses among the depth candidates: not with segment='rgb'")
    frame = dict(T_base_camera=T_base_camera, colour_intrinsics=colour_intrinsics, memory=memory)
    reason, tried = None, 0
    if memory is None or not memory.objects:
        try:
            return plan_frame(rgb, depth, intrinsics, hand, options, **frame)
        except NoFeasibleGrasp as err:
            reason, tried = err.reason, 1
    perceive = options.perception
    found = find_objects(depth, intrinsics, rgb=rgb, fill_holes=perceive.fill_holes,
                         colour_offset_px=perceive.colour_offset_px, colour_intrinsics=colour_intrinsics)
    own = _own_choice(found.candidates, hand) if tried else None
    others = [c for c in found.candidates if own is None or c.label != own.label]  # not the one planned on already
    for candidate in objects_to_try(others, hand, memory):
        tried += 1
        try:
            return plan_frame(rgb, depth, intrinsics, hand, options, target_px=perception.deepest_pixel(candidate.mask),
                              **frame)
        except (NoFeasibleGrasp, SegmentationError) as err:
            reason = getattr(err, "reason", str(err))
    if reason is None:
        raise NoFeasibleGrasp("no object standing wholly in view is narrow enough for the hand to span")
    if tried == 1:
        raise NoFeasibleGrasp(reason)
    raise NoFeasibleGrasp(f"none of the {tried} objects tried has a feasible grasp; the last: {reason}")


def _own_choice(candidates, hand: Hand) -> perception.Candidate | None:
    """The candidate :func:`~contourgrasp.pipeline.plan_frame` chooses by itself (the ``"hand"`` rule); None where it chose none of them."""
    try:
        return perception.choose_target(candidates, max_width=perception.hand_opening(hand))[0]
    except SegmentationError:
        return None


def objects_to_try(candidates, hand: Hand, memory: SceneMemory | None = None) -> list[perception.Candidate]:
    """The objects :func:`plan_any` tries after its own choice: the candidates standing wholly in view whose
    minimum-area rectangle is no wider than the hand opens (:func:`~contourgrasp.perception.hand_opening`), the
    first ``tolerances.MAX_OBJECTS_TRIED`` of them in :func:`~contourgrasp.pipeline.find_objects`' order, those with the fewest failed
    grasps in ``memory`` first."""
    width = perception.hand_opening(hand)
    spanned = [c for c in candidates if c.in_view and c.extent[1] <= width][:MAX_OBJECTS_TRIED]
    if memory is None:
        return spanned
    return sorted(spanned, key=lambda c: len(memory.of(c.mask)))
