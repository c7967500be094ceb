"""Clearing a table: the clutter-removal protocol grasping papers report (VGN's ``clutter_removal.py``).

:func:`run_clearing` takes a ``clutter`` or ``bin`` scene (:mod:`contourgrasp.sim.clutter`) and picks
until the table is empty, nothing can be planned, or :data:`FAILURES_IN_A_ROW` attempts in a row
failed, at most :data:`ATTEMPTS_PER_OBJECT` attempts per object in the scene. Each attempt:

1. a new picture (the seeded sensor noise of :func:`~contourgrasp.sim.trial.run_trial`'s attempts);
2. the planner chooses the object itself, as a user's camera frame with no click does (the
   perception's ``"hand"`` rule). After a grasp failed, and whenever the planner's own choice has no
   plan, it is asked about every object standing wholly in view that the hand spans (its minimum-area
   rectangle no wider than the hand opens: :func:`~contourgrasp.picking.objects_to_try`, at most
   ``tolerances.MAX_OBJECTS_TRIED``, each at the pixel deepest inside it), those no grasp failed on first,
   then those with the fewest failures, until one has a plan (the order :func:`~contourgrasp.picking.plan_any`
   tries them in); each object is planned with the memory of the grasps that failed on it
   (:class:`~contourgrasp.synthesis.SceneMemory`: an object is the one a failure was on when it stands within
   ``tolerances.MEMORY_SAME_OBJECT_PX`` of where that failure's object stood).
   Nothing planned ends the run;
3. the grasp is executed on the object the plan is on (the one most of the plan's pixels see), the
   others its neighbours; the closed hand carries what it holds out of view;
4. the closed hand's readings tell whether it holds something
   (:func:`~contourgrasp.sim.detect.hand_holds`: a finger stopped short of where it closes on nothing, or
   a load on the wrist),
   as a robot's encoders and wrist sensor tell it. Told it holds: whatever it holds is put away
   (:meth:`~contourgrasp.sim.scene.Scene.remove`). Told empty: the hand leaves, and the grasp that failed is
   remembered on its object;
5. an object knocked off the table (or out of the bin) is lost: removed, not cleared.

What counts, as in VGN: an attempt succeeds when the hand has taken an object off the table -- after
the lift, the hold and the carry away, an object is in the hand (above the table's top, no longer over
it). Touching a neighbour while closing is not a failure here (a trial's ``hit`` is); a descent stopped
by a touch is, as always. An object is cleared when the hand told the attempt that held it a success
and it was put away; one the hand held but did not tell falls where the hand opened, off the table,
and is lost. The run succeeds when every object was cleared; when it does not, its cause is the last
failed attempt's, "no feasible plan" when nothing could be planned, and otherwise (every attempt held
something, yet an object was lost off the table) the hit of a neighbour.

Why the hand and not a new picture: among several objects, a lifted one uncovers what stood behind it
(a neighbour, a bin wall), and the picture then shows something standing where it stood -- a success
told a failure (docs/studies.md, "Clearing a table", has the counts). Whatever the hand holds after the
carry away is off the table, which is all clearing asks.
"""

from __future__ import annotations

import time
import warnings

import numpy as np

from .. import pipeline
from ..picking import objects_to_try
from ..perception import deepest_pixel
from ..errors import ContourGraspWarning, InputError, NoFeasibleGrasp, SimulationError
from ..hand import Hand
from ..synthesis import SceneMemory
from ..validation import choice
from .detect import hand_holds
from .render import DEFAULT_SENSOR, Sensor, render, truth_labels
from .scene import Camera, Workspace
from .tendon_hand import HandDesign
from .trial import (HIT, NO_PLAN, NO_PLAN_FIELDS, PARKED, SETTLE_AFTER_FAILURE, Execution, TrialRecord, carry_away,
                    execute_planned, noise_seed, trial_scene)

#: A run stops after this many attempts in a row told failed (VGN's ``consecutive_failures``).
FAILURES_IN_A_ROW = 2
#: At most this many attempts per object in the scene.
ATTEMPTS_PER_OBJECT = 3
#: How a clearing run ended (:attr:`TrialRecord.ended`).
CLEARED, NOTHING_PLANNED, FAILED_IN_A_ROW, ATTEMPT_LIMIT = ("table cleared", "nothing to plan on",
                                                            "failed twice in a row", "attempt limit")
ENDINGS = (CLEARED, NOTHING_PLANNED, FAILED_IN_A_ROW, ATTEMPT_LIMIT)


def run_clearing(object_spec, *, seed: int, planner, pool, scene_kind: str = "clutter",
                 hand: Hand | str = "five-finger-linear", sensor: Sensor | str = DEFAULT_SENSOR,
                 tilt: float | None = None, timing: str = "thesis", design: HandDesign = HandDesign(),
                 camera: Camera = Camera(), workspace: Workspace = Workspace(), execution: Execution = Execution(),
                 observe=None, robot: bool = False) -> TrialRecord:
    """Clear a ``clutter`` or ``bin`` scene (module docstring); the record of the whole run.

    The scene and every parameter are :func:`~contourgrasp.sim.trial.run_trial`'s (``object_spec`` is the
    scene's first object); ``planner`` must have the ``plan`` method of :mod:`contourgrasp.sim.planners`.
    The record's ``outcomes`` and ``detected`` are every attempt's true and told outcome,
    ``scene_objects`` and ``cleared`` count the objects, ``ended`` is one of :data:`ENDINGS`, and
    ``success`` says whether every object was cleared; its other fields are the last attempt's,
    ``plan_time`` the attempts' sum.
    """
    started = time.perf_counter()
    choice("scene", scene_kind, ("clutter", "bin"), error=SimulationError)
    if not hasattr(planner, "plan"):
        raise SimulationError("clearing a table needs a planner with a plan method that takes memory= "
                              "(contourgrasp.sim.planners)")
    scene = trial_scene(object_spec, seed=seed, scene_kind=scene_kind, pool=pool, planner=planner, tilt=tilt,
                        hand=hand, design=design, timing=timing, camera=camera, workspace=workspace, robot=robot)
    memory, outcomes, detected, cleared, in_a_row, plan_time = SceneMemory(), [], [], 0, 0, 0.0
    fields, plan_error, ended, failure = dict(NO_PLAN_FIELDS), None, ATTEMPT_LIMIT, HIT
    for attempt in range(ATTEMPTS_PER_OBJECT * len(scene.objects)):
        _remove_lost(scene)
        if not scene.present:
            ended = CLEARED
            break
        rgb, depth = render(scene, sensor=sensor, seed=seed if attempt == 0 else noise_seed(seed, attempt))
        planned, plan_error, spent = _plan_next(planner, rgb, depth, scene.camera.intrinsics, memory)
        plan_time += spent
        if planned is None:
            fields, ended, failure = dict(NO_PLAN_FIELDS), NOTHING_PLANNED, NO_PLAN
            break
        fields, held, told = _pick(scene, planned, execution)
        outcomes.append(bool(held))
        detected.append(told)
        failure = failure if held else fields["cause"]
        if told:
            cleared, in_a_row = cleared + len(held), 0
        else:
            memory = memory.with_failure(_planned_pixels(planned), planned.metric.contour_xy, planned.pose,
                                         approach=planned.approach)
            in_a_row += 1
        if in_a_row == FAILURES_IN_A_ROW:
            ended = FAILED_IN_A_ROW
            break
    else:
        _remove_lost(scene)
        ended = CLEARED if not scene.present else ATTEMPT_LIMIT
    if observe is not None:
        observe(scene)
    success = cleared == len(scene.objects)
    fields |= {"success": success, "cause": None if success else failure}
    return TrialRecord(object=scene.objects[0].name, seed=seed, **fields, plan_error=plan_error, sim_time=scene.time,
                       plan_time=plan_time, wall_time=time.perf_counter() - started, outcomes=tuple(outcomes),
                       detected=tuple(detected), scene_objects=len(scene.objects), cleared=cleared, ended=ended)


def _pick(scene, planned, execution) -> tuple[dict, list[int], bool]:
    """Execute a plan on the object it is on, carry away what the hand holds, tell it from the hand, put it away
    when told held, and park the hand (what it still holds falls where it is): (the record's fields of the
    execution, the objects truly held, whether the hand told something held)."""
    scene.retarget(planned_object(scene, planned))
    fields = execute_planned(scene, planned.T_camera_hand, planned.approach_depth, planned.grasp_height, execution)
    carry_away(scene)
    held = _held(scene)
    told = hand_holds(scene.hand_reading(), scene.free_closure())
    for index in held if told else ():
        scene.remove(index)
    scene.set_hand(*PARKED, 0.0)
    scene.step(SETTLE_AFTER_FAILURE)
    return fields, held, told


def _plan_next(planner, rgb, depth, intrinsics, memory: SceneMemory):
    """(PlannedGrasp or None, the last planning error or None, seconds): before any failure the planner's own
    choice of object; then, or when it has no plan, every object standing wholly in view that the hand spans
    (a bin's walls and what touches them do not), those no grasp failed on first (fewest failures first, then
    largest), each with its own memory."""
    started, error = time.perf_counter(), None
    with warnings.catch_warnings():  # a run's record is its outcome: its perception's notes are not printed
        warnings.simplefilter("ignore", ContourGraspWarning)
        if not memory.objects:
            try:
                return planner.plan(rgb, depth, intrinsics, memory=memory), None, time.perf_counter() - started
            except (NoFeasibleGrasp, InputError) as err:
                error = str(err)
        try:
            candidates = pipeline.find_objects(depth, intrinsics, rgb=rgb).candidates
        except InputError as err:
            return None, str(err), time.perf_counter() - started
        for candidate in objects_to_try(candidates, planner.hand, memory):
            try:
                planned = planner.plan(rgb, depth, intrinsics, memory=memory.of(candidate.mask),
                                       target_px=deepest_pixel(candidate.mask))
                return planned, None, time.perf_counter() - started
            except (NoFeasibleGrasp, InputError) as err:
                error = str(err)
    return None, error, time.perf_counter() - started


def _planned_pixels(planned) -> np.ndarray:
    """(H, W) bool: the pixels that saw the object a plan is on (a baseline's: its segmentation's mask)."""
    return np.asarray(planned.seen if planned.seen is not None else planned.segmentation.mask, dtype=bool)


def planned_object(scene, planned) -> int:
    """The object (index into the scene's objects) a plan is on: the one most of the pixels that saw its target
    see (:func:`~contourgrasp.sim.render.truth_labels`); the first present when none does."""
    labels = truth_labels(scene)[_planned_pixels(planned)] - 1
    counts = np.bincount(labels[(labels >= 0) & (labels < len(scene.objects))], minlength=len(scene.objects))
    counts[[k for k in range(len(scene.objects)) if k not in scene.present]] = 0
    return int(np.argmax(counts)) if counts.any() else scene.present[0]


def _held(scene) -> list[int]:
    """The objects present that the hand holds after carrying them away: above the table's top and no longer
    over it (or its bin)."""
    coms = scene.coms()
    return [k for k, on, com in zip(scene.present, scene.on_support(), coms, strict=True) if not on and com[2] > 0.0]


def _remove_lost(scene) -> None:
    """Remove the objects knocked off the table (or out of the bin): lost, not cleared."""
    for k, on in zip(scene.present, scene.on_support(), strict=True):
        if not on:
            scene.remove(k)
