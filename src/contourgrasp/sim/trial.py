"""Grasp execution (thesis 4.1.4, automated end to end) and grasping trials (4.2.4, Table 4.4).

Execution, given the hand pose ``T_camera_hand`` and the approach depth:

1. the hand appears above the pose at a safe height, yaw aligned (the arm's
   transit is not simulated: nothing touches anything on the way), its
   fingertips :attr:`Execution.approach_height` above the object's top;
2. it descends at :attr:`Execution.descend_speed` to the planner's grasp height
   when the planner gave one (the open hand's lowest fingertip that high above
   the table); otherwise until the fingertips are just above the table, but
   never bringing the palm closer than :attr:`Execution.palm_clearance` to
   ``approach_depth`` (so tall objects are grasped lower down the fingers, not
   crushed by the palm) -- the part the thesis's operator did by hand. The
   palm's lowest point counts: a mounted model's palm may reach ``palm_depth``
   below the hand frame's z = 0 (the Inspire's, along its fingers);
3. the tendon force ramps to its maximum over :attr:`Execution.close_time`,
   then squeezes for :attr:`Execution.squeeze_time`;
4. the hand lifts :attr:`Execution.lift_height` and holds for
   :attr:`Execution.hold_time`.

A pose approached from the side or tilted (its z axis not the camera's) is executed as it stands
(:func:`execute_along`): the hand, on a wrist that tilts and rolls (:attr:`HandDesign.wrist`, which
:func:`run_trial` gives a planner of such approaches), travels along its approach to the pose in
step 2 instead, then closes, lifts straight up and holds the same way.

Reading of ``approach_depth``: the thesis's z (3.1.1), the depth of the
object's top as the camera saw it plus the planner's offset; it bounds the
palm, not the fingertips.

Success (4.1.3, "pick it up without slippage"): the object rose at least
:attr:`Execution.success_lift` from the start of the lift (closing itself
raises a lying object a few millimetres) and moved less than
:attr:`Execution.hold_tolerance` relative to the palm during the hold.

Failure causes (chapter 5), first that applies:

* ``"no feasible plan"`` -- the planner raised :class:`~contourgrasp.errors.NoFeasibleGrasp`
  or :class:`~contourgrasp.errors.InputError` (e.g. perception found no object
  wholly in view); the record keeps its message;
* ``"a finger struck the object while descending"`` -- any hand-object contact
  before closing; the execution stops there, as a robot with a force sensor would;
* ``"closed without touching the object"`` -- no finger touched the object while
  closing (the plan's grasp points are not where the object is); it was not lifted;
* ``"object pushed away before all fingers touched"`` -- the object had moved
  more than :attr:`Execution.push_tolerance` in the plane when the last finger
  touched it (or closing ended with fingers still on air), and it was not lifted;
* ``"slipped during lift"`` -- the object did not rise ``success_lift``;
* ``"dropped"`` -- it rose, then fell or slid in the hand during the hold;
* ``"hit a neighbour or the bin"`` -- in a scene of several objects
  (:mod:`contourgrasp.sim.clutter`): a hand geom touched a neighbour or a bin
  wall while descending (the descent stops there, as for a strike, unless the
  target was touched too: then it is a strike) or closing, or at the end of the
  hold a neighbour had risen more than :data:`~contourgrasp.tolerances.NEIGHBOUR_LIFT`
  or left the table (the bin's floor). It fails the trial whatever became of the
  target, and comes before missed, pushed, slipped and dropped: a collision is a failure
  of the plan even when the target is held. Touching the bin's floor is not a hit
  (the fingertips close just above it, as above the table).

In a scene of several objects success is the target's success (above) with
no hit: no neighbour or wall touched while descending or closing, none lifted
or knocked off. A single object has no neighbour, so its trials are unchanged.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from ..errors import ContourGraspWarning, InputError, NoFeasibleGrasp, SimulationError
from ..hand import Hand
from ..synthesis import GraspMemory
from ..tolerances import MAX_ATTEMPTS
from ..validation import integer
from .clutter import build_clutter, target_pixel
from .detect import hand_holds
from .tendon_hand import HandDesign
from .render import DEFAULT_SENSOR, Sensor, render, tilted_view
from .scene import R_WORLD_CAMERA, Camera, Scene, Workspace, base_angles, build_scene

NO_PLAN = "no feasible plan"
STRUCK = "a finger struck the object while descending"
MISSED = "closed without touching the object"
PUSHED = "object pushed away before all fingers touched"
SLIPPED = "slipped during lift"
DROPPED = "dropped"
HIT = "hit a neighbour or the bin"
#: Every failure cause a trial can report (HIT only in a scene of several objects).
FAILURE_CAUSES = (NO_PLAN, STRUCK, MISSED, PUSHED, SLIPPED, DROPPED, HIT)
#: Where the hand waits between attempts (world x, y, z of the palm, yaw), far above the table, open.
PARKED = (0.0, 0.0, 0.6)
#: How much farther back (m) than its fingertips' reach and the approach height a hand approaching along a
#: tilted or horizontal axis starts (:func:`execute_along`).
APPROACH_RUN = 0.05
#: The most a hand's approach may point up, as the sine of its angle above the horizontal.
UPWARD_APPROACH = 1e-3
#: A pose planned in a tilted view whose approach is within this angle of the world's vertical (rad) is a
#: top-down grasp, executed from the reference camera's frame.
VERTICAL_APPROACH = math.radians(5.0)
#: Seconds the scene settles after a failed attempt, the hand parked, before the next picture.
SETTLE_AFTER_FAILURE = 0.5
#: After an attempt the closed hand is carried this far (m) along the world's y in this many seconds, off the table and
#: out of the camera's view with what it holds.
CARRY_AWAY, CARRY_TIME = 0.7, 1.0
#: Angle of the hand's x axis from the object's x axis in :func:`scripted_grasp`, rad.
SCRIPTED_TILT = math.radians(20.0)


@dataclass(frozen=True)
class Execution:
    """Motion and success parameters of a grasp execution (SI units)."""

    approach_height: float = 0.05
    descend_speed: float = 0.10
    tip_clearance: float = 0.003
    palm_clearance: float = 0.02
    settle_time: float = 0.2
    close_time: float = 1.0
    squeeze_time: float = 0.3
    lift_height: float = 0.15
    lift_speed: float = 0.10
    hold_time: float = 2.0
    success_lift: float = 0.10
    hold_tolerance: float = 0.02
    push_tolerance: float = 0.01


@dataclass(frozen=True)
class GraspOutcome:
    """What happened when a grasp was executed.

    Attributes
    ----------
    success : bool
    cause : str or None
        One of :data:`FAILURE_CAUSES`; None on success.
    fingers_in_contact : tuple of str
        Fingers touching the object when the lift starts (empty if aborted before).
    first_contact : tuple of (str, float)
        Per finger that touched the object while closing, seconds from the start of closing, in time order.
    push : float
        Object's displacement in the table plane when the last finger touched, m.
    lift : float
        Object's rise from the start of the lift to the end of the hold, m.
    hold_drift : float
        Largest displacement of the object relative to the palm during the hold, m.
    pose : (3,) float
        Executed hand pose (x, y, yaw) in the image plane.
    palm_depth : float
        Depth of the palm (hand-frame origin) when closing, m.
    """

    success: bool
    cause: str | None
    fingers_in_contact: tuple[str, ...]
    first_contact: tuple[tuple[str, float], ...]
    push: float
    lift: float
    hold_drift: float
    pose: tuple[float, float, float]
    palm_depth: float


@dataclass(frozen=True)
class TrialRecord:
    """One grasping trial: the scene's seed, the plan, and its outcome.

    Equal records mean the same trial; ``plan_time`` and ``wall_time`` are left out of the comparison.

    Attributes
    ----------
    object : str
    seed : int
    success : bool
    cause : str or None
        One of :data:`FAILURE_CAUSES`; None on success.
    fingers_in_contact : tuple of str
    first_contact : tuple of (str, float)
    push, lift, hold_drift : float
        See :class:`GraspOutcome` (0 when no grasp was executed).
    pose : (3,) float or None
        Planned hand pose (x, y, yaw), image plane; None without a plan.
    approach_depth : float or None
    grasp_height : float or None
        The planned height of the open fingertips above the table (None: the execution's rule, or no plan).
    plan_error : str or None
        Why the planner gave no plan (its exception's message); None with a plan.
    sim_time : float
        Simulated seconds, settling included.
    plan_time : float
        Seconds of wall time the planner took (left out of the comparison).
    wall_time : float
        Seconds of wall time for the whole trial (scene, picture, plan, simulation).
    outcomes, detected : tuple of bool
        With several attempts (:func:`run_trial`'s ``attempts``), per attempt made: whether it truly
        succeeded, and whether the hand told it a success (:func:`~contourgrasp.sim.detect.hand_holds`); empty
        with one.
        The other fields are the last attempt's, ``plan_time`` the attempts' sum.
    scene_objects, cleared : int or None
        Of a run clearing a table (:func:`~contourgrasp.sim.clearing.run_clearing`): the objects in the
        scene, and those it cleared; None otherwise.
    ended : str or None
        How a clearing run ended (:data:`~contourgrasp.sim.clearing.ENDINGS`); None otherwise.
    """

    object: str
    seed: int
    success: bool
    cause: str | None
    fingers_in_contact: tuple[str, ...]
    first_contact: tuple[tuple[str, float], ...]
    push: float
    lift: float
    hold_drift: float
    pose: tuple[float, float, float] | None
    approach_depth: float | None
    grasp_height: float | None
    plan_error: str | None
    sim_time: float
    plan_time: float = field(compare=False)
    wall_time: float = field(compare=False)
    outcomes: tuple[bool, ...] = ()
    detected: tuple[bool, ...] = ()
    scene_objects: int | None = None
    cleared: int | None = None
    ended: str | None = None


def run_trial(object_spec, *, seed: int, planner, hand: Hand | str = "five-finger-linear",
              sensor: Sensor | str = DEFAULT_SENSOR, tilt: float | None = None, timing: str = "thesis",
              design: HandDesign = HandDesign(), camera: Camera = Camera(),
              workspace: Workspace = Workspace(), execution: Execution = Execution(), observe=None,
              scene_kind: str = "single", pool=(), robot: bool = False, attempts: int = 1) -> TrialRecord:
    """Place the object (seeded), take an RGB-D picture, plan, execute, and record the outcome.

    With ``attempts`` above 1, a failure is told as a real robot would tell it -- at the end of the hold
    the closed hand reports nothing held: its joints where they stop on nothing and no load on its wrist
    (:func:`~contourgrasp.sim.detect.hand_holds`), or it never closed (the descent stopped on a touch); not
    the simulator's truth -- and then the hand carries what it holds away, opens and leaves, the scene
    settles as it is, a new picture is taken and the planner tries again, remembering the grasps that
    failed (its ``plan`` takes ``memory``: :class:`~contourgrasp.synthesis.GraspMemory`), until an
    attempt is told a success or ``attempts`` were made. The record is the last attempt's, with every attempt's
    true and told outcome (``outcomes``, ``detected``).

    Parameters
    ----------
    object_spec : ObjectSpec or str
        An object, a name of :data:`~contourgrasp.sim.objects.THESIS_OBJECTS` or a mesh path.
    seed : int
        Chooses the placement and the sensor noise; same seed, same record.
    planner : callable
        ``planner(rgb, depth, intrinsics) -> (T_camera_hand, approach_depth[, grasp_height])``:
        ``rgb`` (H, W, 3) uint8, ``depth`` (H, W) float32 m (0 = missing),
        ``intrinsics`` :class:`~contourgrasp.perception.Intrinsics`; returns the
        (4, 4) hand pose in the camera frame (see :func:`hand_pose_from_matrix`)
        and the approach depth (m), and optionally the planned grasp height (m, see
        :func:`execute_grasp`; None or left out: the execution's own rule). It may raise ``NoFeasibleGrasp`` or
        ``InputError`` when it has no plan. In a scene of several objects it is
        called with the keyword ``target_px``, the target's pixel (u, v)
        (:func:`~contourgrasp.sim.clutter.target_pixel`), and its pose, planned
        in the tilted camera's frame, is executed from the reference camera's
        (:meth:`~contourgrasp.sim.scene.Scene.to_reference`).
    hand : Hand or str
        The hand preset the simulated hand is built from.
    sensor : Sensor or str
        The depth sensor of the picture: a :class:`~contourgrasp.sim.render.Sensor` or a preset's name
        (:func:`~contourgrasp.sim.render.render`).
    tilt : float, optional
        The picture is taken from a camera tilted this far (rad) from looking straight down, at the reference
        camera's distance from the table's centre (:func:`~contourgrasp.sim.render.tilted_view`); the pose
        planned in its frame is executed from the reference camera's. None: a ``single`` scene's top-down
        camera, a ``clutter`` or ``bin`` scene's seeded tilt.
    timing, design
        Finger closing schedule and hand parameters (:mod:`contourgrasp.sim.tendon_hand`).
    camera, workspace, execution
        Scene and execution parameters.
    observe : callable, optional
        ``observe(scene)`` is called when the trial ends (after the hold, an
        aborted descent, or the picture when there is no plan), e.g. to render it.
    scene_kind : {"single", "clutter", "bin"}
        The scene (:mod:`contourgrasp.sim.clutter`); ``object_spec`` is its target.
    pool : sequence of ObjectSpec
        The neighbours of a ``clutter`` or ``bin`` scene are drawn from it.
    robot : bool
        A robot arm in the picture (:data:`~contourgrasp.sim.mjcf.ROBOT_ARM`), seen and never touched.
    attempts : int
        At most this many attempts (above).
    """
    started = time.perf_counter()
    attempts = integer("attempts", attempts, 1, maximum=MAX_ATTEMPTS, error=SimulationError)
    if attempts > 1 and not hasattr(planner, "plan"):
        raise SimulationError("several attempts need a planner with a plan method that takes memory= "
                              "(contourgrasp.sim.planners)")
    scene = trial_scene(object_spec, seed=seed, scene_kind=scene_kind, pool=pool, planner=planner, tilt=tilt,
                        hand=hand, design=design, timing=timing, camera=camera, workspace=workspace, robot=robot)
    memory, outcomes, detected, plan_time = GraspMemory(), [], [], 0.0
    for attempt in range(attempts):
        rgb, depth = render(scene, sensor=sensor, seed=seed if attempt == 0 else noise_seed(seed, attempt))
        fields, plan_error, planned, spent = _attempt(scene, planner, rgb, depth, camera, execution,
                                                      memory if attempts > 1 else None)
        plan_time += spent
        if attempts == 1:
            break
        outcomes.append(bool(fields["success"]))
        if planned is None:  # no plan: nothing more to try
            detected.append(False)
            break
        # read when the outcome is judged, the hold's end; a descent stopped on a touch never closed
        detected.append(scene.closed and hand_holds(scene.hand_reading(), scene.free_closure()))
        carry_away(scene)
        if detected[-1]:
            break
        memory = memory.with_failure(planned.metric.contour_xy, planned.pose, approach=planned.approach)
        scene.set_hand(*PARKED, 0.0)  # the hand opens and leaves; what it held falls where it is
        scene.step(SETTLE_AFTER_FAILURE)
    if observe is not None:
        observe(scene)
    return TrialRecord(object=scene.object.name, seed=seed, **fields, plan_error=plan_error, sim_time=scene.time,
                       plan_time=plan_time, wall_time=time.perf_counter() - started, outcomes=tuple(outcomes),
                       detected=tuple(detected))


def carry_away(scene) -> None:
    """The closed hand, at its height, carried ``CARRY_AWAY`` (m) along the world's y in ``CARRY_TIME`` s, off the table
    and out of the camera's view, with what it holds: where a robot puts down what it took."""
    _move_closed(scene, scene.hand_base(), 1, CARRY_AWAY, CARRY_TIME)


def _move_closed(scene, start, joint: int, distance: float, duration: float) -> None:
    """Move the closed hand's base from ``start`` by ``distance`` (m) along its ``joint`` (0-2: world x, y, z) in
    ``duration`` s, smoothly (smoothstep)."""
    offset = np.zeros(len(start))
    offset[joint] = distance
    steps = max(1, round(duration / scene.model.opt.timestep))
    for k in range(steps):
        u = (k + 1) / steps
        scene.command(start + offset * (u * u * (3 - 2 * u)), 1.0)
        scene.step()


def noise_seed(seed: int, attempt: int) -> int:
    """The sensor noise's seed of the picture before a later attempt of a trial."""
    return int(np.random.SeedSequence([seed, attempt, 0]).generate_state(1)[0])


def _attempt(scene, planner, rgb, depth, camera: Camera, execution: Execution, memory):
    """Plan on a picture and execute: (the record's fields, the plan's error or None, the planner's
    PlannedGrasp or None, seconds planning). ``memory``: None for the planner's call, else its ``plan``'s."""
    target = {} if scene.view is None else {"target_px": target_pixel(scene)}
    planning, planned = time.perf_counter(), None
    try:
        with warnings.catch_warnings():  # a trial's record is its outcome: its perception's notes are not printed
            warnings.simplefilter("ignore", ContourGraspWarning)
            if memory is None:
                transform, approach_depth, *planned_height = planner(rgb, depth, camera.intrinsics, **target)
            else:
                planned = planner.plan(rgb, depth, camera.intrinsics, memory=memory, **target)
                transform, approach_depth, planned_height = (planned.T_camera_hand, planned.approach_depth,
                                                             [planned.grasp_height])
    except (NoFeasibleGrasp, InputError) as err:
        return NO_PLAN_FIELDS, str(err), None, time.perf_counter() - planning
    spent = time.perf_counter() - planning
    grasp_height = planned_height[0] if planned_height else None
    return execute_planned(scene, transform, approach_depth, grasp_height, execution), None, planned, spent


#: The outcome's fields of a trial without a plan.
NO_PLAN_FIELDS = {"success": False, "cause": NO_PLAN, "fingers_in_contact": (), "first_contact": (), "push": 0.0,
                  "lift": 0.0, "hold_drift": 0.0, "pose": None, "approach_depth": None, "grasp_height": None}


def execute_planned(scene, transform, approach_depth: float, grasp_height: float | None, execution: Execution) -> dict:
    """Execute a planner's answer on ``scene`` (a top-down pose planned in a tilted view from the reference
    camera's frame, :meth:`~contourgrasp.sim.scene.Scene.to_reference`); the record's fields of its outcome."""
    if scene.view is not None and _vertical(scene, transform):
        *pose, approach_depth = scene.to_reference(transform)
        transform = pose_matrix(*pose, approach_depth)
    outcome = asdict(execute_grasp(scene, transform, approach_depth, execution, grasp_height=grasp_height))
    return {k: v for k, v in outcome.items() if k != "palm_depth"} | {
        "approach_depth": float(approach_depth), "grasp_height": None if grasp_height is None else float(grasp_height)}


def with_wrist(planner, hand, design: HandDesign):
    """(hand, design) with the simulated hand's wrist (:attr:`HandDesign.wrist`) where ``planner``'s options plan
    side or tilted approaches; else as given: a top-down planner's trials keep the thesis's x, y, z, yaw base."""
    options = getattr(planner, "options", None)
    if options is None or options.scene.approaches == "top":
        return hand, design
    if hasattr(hand, "mount"):  # a mounted hand model carries its own design
        return replace(hand, design=replace(hand.design, wrist=True)), design
    return hand, replace(design, wrist=True)


def trial_scene(object_spec, *, seed: int, scene_kind: str = "single", pool=(), planner=None,
                tilt: float | None = None, hand: Hand | str = "five-finger-linear", design: HandDesign = HandDesign(),
                **options) -> Scene:
    """The settled scene of a trial: :func:`~contourgrasp.sim.scene.build_scene` for ``"single"``, else
    :func:`~contourgrasp.sim.clutter.build_clutter` (``pool``: its neighbours); ``options`` go to either. The
    hand has the wrist ``planner`` needs (:func:`with_wrist`); ``tilt``: the picture's camera, as
    :func:`run_trial`'s."""
    hand, design = with_wrist(planner, hand, design)
    if scene_kind == "single":
        scene = build_scene(object_spec, seed=seed, hand=hand, design=design, **options)
    else:
        scene = build_clutter(object_spec, pool, kind=scene_kind, seed=seed, hand=hand, design=design, **options)
    if tilt is not None:
        scene.view = tilted_view(tilt, scene.camera.height)
    return scene


def hand_pose_from_matrix(transform) -> tuple[float, float, float]:
    """The image-plane pose (x, y, yaw) of a (4, 4) ``T_camera_hand``.

    The hand frame's z axis must be the camera's z axis (palm facing the
    table); its x, y axes are the preset's hand frame turned by yaw, i.e. the
    upper-left block is ``R(yaw) = [[cos, -sin], [sin, cos]]``. The translation's
    z is not used: the depth comes from the approach depth (4.1.4).

    Raises
    ------
    SimulationError
        Not a (4, 4) rigid transform with its z axis along the camera's.
    """
    t = np.asarray(transform, dtype=float)
    if t.shape != (4, 4) or not np.all(np.isfinite(t)):
        raise SimulationError(f"T_camera_hand must be a finite (4, 4) matrix, got shape {t.shape}")
    rotation = t[:3, :3]
    if not np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-6) or t[2, 2] < 1 - 1e-6:
        raise SimulationError("T_camera_hand must be a rotation about the camera's z axis (palm facing the table)")
    return float(t[0, 3]), float(t[1, 3]), math.atan2(t[1, 0], t[0, 0])


def pose_matrix(x: float, y: float, yaw: float, depth: float = 0.0) -> np.ndarray:
    """(4, 4) float: ``T_camera_hand`` of an image-plane pose (x, y, yaw) at ``depth``."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0, x], [s, c, 0.0, y], [0.0, 0.0, 1.0, depth], [0.0, 0.0, 0.0, 1.0]])


def execute_grasp(scene: Scene, transform, approach_depth: float, execution: Execution = Execution(), *,
                  grasp_height: float | None = None) -> GraspOutcome:
    """Execute a grasp on a settled scene (module docstring: phases, success, causes).

    ``grasp_height`` (m), when the planner chose one: the height above the table of the open hand's
    lowest fingertip (its tip centre) at the end of the descent, executed as planned instead of
    the palm-clearance rule of step 2. A ``transform`` whose approach is not the camera's axis (a side
    or tilted approach) is executed as it stands (:func:`execute_along`); ``approach_depth`` and
    ``grasp_height`` are then not used.
    """
    if not _top_down(transform):
        return execute_along(scene, transform, execution)
    x, y, yaw = hand_pose_from_matrix(transform)
    world_xy = scene.camera.to_world([x, y, 0.0])[:2]
    top = scene.camera.height - float(approach_depth)  # the planner's idea of the object's top, world z
    if grasp_height is None:
        lowest = max(f.radius for f in scene.hand.fingers) + execution.tip_clearance
        palm_final = max(scene.hand.tip_depth + lowest, top + execution.palm_clearance + scene.hand.palm_depth)
    else:
        depth = scene.hand.open_tip_depth
        if depth is None:
            raise SimulationError(f"the simulated hand {scene.hand.hand.name!r} has no open fingertip depth: "
                                  "it cannot execute a planned grasp height")
        palm_final = depth + float(grasp_height)
    palm_start = max(palm_final, top + execution.approach_height + scene.hand.tip_depth)
    end = np.array([*world_xy, palm_final, yaw, 0.0, 0.0])
    start = end + [0.0, 0.0, palm_start - palm_final, 0.0, 0.0, 0.0]
    return _grasp(scene, start, end, (x, y, yaw), execution)


def execute_along(scene: Scene, transform, execution: Execution = Execution()) -> GraspOutcome:
    """Execute a grasp approached along its hand frame's z axis: the open hand starts
    ``hand.tip_depth + execution.approach_height + APPROACH_RUN`` back along it, travels to the pose
    ``transform`` (``T_camera_hand``, or the tilted view's ``T_view_hand``), closes and lifts straight up.
    """
    t = np.asarray(transform, dtype=float)
    if t.shape != (4, 4) or not np.all(np.isfinite(t)):
        raise SimulationError(f"T_camera_hand must be a finite (4, 4) matrix, got shape {t.shape}")
    if scene.view is None:
        position, R_world_hand = scene.camera.to_world(t[:3, 3]), R_WORLD_CAMERA @ t[:3, :3]
    else:
        eye, R_world_view = scene.view
        position, R_world_hand = R_world_view @ t[:3, 3] + eye, R_world_view @ t[:3, :3]
    if R_world_hand[2, 2] > UPWARD_APPROACH:
        raise SimulationError("T_camera_hand faces away from the table: its z axis (the approach) points up "
                              f"{math.degrees(math.asin(min(1.0, R_world_hand[2, 2]))):.0f} deg")
    end = np.array([*position, *base_angles(R_world_hand)])
    back = scene.hand.tip_depth + execution.approach_height + APPROACH_RUN
    start = end - np.r_[back * R_world_hand[:, 2], 0.0, 0.0, 0.0]
    camera_xy = scene.camera.from_world(position)[:2]
    yaw = math.atan2(t[1, 0], t[0, 0])
    return _grasp(scene, start, end, (float(camera_xy[0]), float(camera_xy[1]), yaw), execution)


def _vertical(scene: Scene, T_view_hand) -> bool:
    """Whether a pose planned in the tilted view's frame approaches along the world's vertical, within
    ``VERTICAL_APPROACH`` (the planner's table normal is a fraction of a degree off it)."""
    _, R_world_view = scene.view
    return float((R_world_view @ np.asarray(T_view_hand, dtype=float)[:3, 2])[2]) < -math.cos(VERTICAL_APPROACH)


def _top_down(transform) -> bool:
    """Whether ``transform``'s approach (its z axis) is the camera's within a millionth (not checked further)."""
    t = np.asarray(transform, dtype=float)
    return t.shape != (4, 4) or not np.isfinite(t[2, 2]) or t[2, 2] >= 1 - 1e-6


def _grasp(scene: Scene, start, end, pose, execution: Execution) -> GraspOutcome:
    """Travel from the base pose ``start`` to ``end`` (x, y, z, yaw, tilt, roll), close, lift and hold; the outcome."""
    probe = _Probe(scene)
    rest = scene.neighbour_coms()
    palm_depth = scene.camera.height - float(end[2])
    scene.set_hand(*start[:4], tilt=start[4], roll=start[5])
    if _descend(scene, probe, start, end, execution):
        cause = HIT if probe.hit and not probe.touching() else STRUCK
        return GraspOutcome(False, cause, (), (), 0.0, 0.0, 0.0, pose, palm_depth)
    first_contact, push = _close(scene, probe, end, execution)
    touching = probe.fingers_touching()
    lift, lifted, drift = _lift_and_hold(scene, end, execution)
    success = lift >= execution.success_lift and drift < execution.hold_tolerance
    if success:
        cause = None
    elif lifted >= execution.success_lift:
        cause = DROPPED
    elif not first_contact:
        cause = MISSED
    else:
        cause = PUSHED if push > execution.push_tolerance else SLIPPED
    if probe.hit or scene.displaced_neighbours(rest):
        success, cause = False, HIT
    return GraspOutcome(success, cause, touching, first_contact, push, lift, drift, pose, palm_depth)


class _Probe:
    """Which hand geoms touch the object, by finger; :attr:`hit` once any touched an obstacle (neighbour, bin wall)."""

    def __init__(self, scene: Scene):
        model = scene.model
        self.scene = scene
        self.hit = False
        self.obstacle_geoms = scene.obstacle_geoms()
        self.object_geoms = np.flatnonzero(model.geom_bodyid == scene.object_body)
        self.finger_of = {}  # hand geom id -> finger index (-1: palm and posts)
        for name in scene.hand.geom_names():
            finger = next((i for i, f in enumerate(scene.hand.fingers) if name.startswith(f"{f.name}_")
                           and not name.endswith("_post")), -1)
            self.finger_of[model.geom(name).id] = finger
        self.hand_geoms = np.fromiter(self.finger_of, dtype=int)

    def touching(self) -> set[int]:
        """Finger indices (-1 for palm or post) in contact with the object now (and :attr:`hit` updated)."""
        data = self.scene.data
        if data.ncon == 0:
            return set()
        pairs = data.contact.geom[: data.ncon]
        if len(self.obstacle_geoms) and not self.hit:
            hand = np.isin(pairs, self.hand_geoms)
            obstacle = np.isin(pairs, self.obstacle_geoms)
            self.hit = bool(np.any((hand[:, 0] & obstacle[:, 1]) | (hand[:, 1] & obstacle[:, 0])))
        found = set()
        for g1, g2 in pairs:
            if g1 in self.object_geoms and g2 in self.finger_of:
                found.add(self.finger_of[g2])
            elif g2 in self.object_geoms and g1 in self.finger_of:
                found.add(self.finger_of[g1])
        return found

    def fingers_touching(self) -> tuple[str, ...]:
        names = self.scene.hand.finger_names
        return tuple(names[i] for i in sorted(self.touching()) if i >= 0)


def _descend(scene, probe, start, end, execution) -> bool:
    """Move the open hand's base from ``start`` to ``end`` (6,) at the descent speed; True when the hand touched the
    object (or an obstacle) on the way."""
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    run = float(np.linalg.norm(end[:3] - start[:3]))
    steps = max(1, round(run / execution.descend_speed / scene.model.opt.timestep))
    for u in np.linspace(0.0, 1.0, steps):
        scene.command(start + u * (end - start), 0.0)
        scene.step()
        if probe.touching() or probe.hit:
            return True
    for _ in range(round(execution.settle_time / scene.model.opt.timestep)):
        scene.step()
        if probe.touching() or probe.hit:
            return True
    return False


def _close(scene, probe, base, execution):
    """Ramp the tendon force up, then squeeze; per finger first-contact times and the push before the last."""
    dt = scene.model.opt.timestep
    start_xy = scene.object_position()[:2]
    n_fingers = len(scene.hand.fingers)
    first: dict[int, float] = {}
    push_at_last = None
    max_push = 0.0
    ramp = round(execution.close_time / dt)
    for k in range(ramp + round(execution.squeeze_time / dt)):
        scene.command(base, min(1.0, (k + 1) / ramp))
        scene.step()
        max_push = max(max_push, float(np.linalg.norm(scene.object_position()[:2] - start_xy)))
        for i in probe.touching() - first.keys() - {-1}:
            first[i] = (k + 1) * dt
            if len(first) == n_fingers:
                push_at_last = max_push
    names = scene.hand.finger_names
    order = tuple((names[i], round(t, 6)) for i, t in sorted(first.items(), key=lambda item: item[1]))
    return order, max_push if push_at_last is None else push_at_last


def _lift_and_hold(scene, base, execution):
    """Lift smoothly, hold; the object's rise (end of hold, end of lift) and its largest drift in the hand."""
    dt = scene.model.opt.timestep
    z0 = scene.object_com()[2]
    _move_closed(scene, base, 2, execution.lift_height, execution.lift_height / execution.lift_speed)
    lifted = scene.object_com()[2] - z0
    reference = _in_palm(scene)
    drift = 0.0
    for _ in range(round(execution.hold_time / dt)):
        scene.step()
        drift = max(drift, float(np.linalg.norm(_in_palm(scene) - reference)))
    return float(scene.object_com()[2] - z0), float(lifted), drift


def _in_palm(scene) -> np.ndarray:
    position, rotation = scene.palm_pose()
    return rotation.T @ (scene.object_com() - position)


def scripted_grasp(scene: Scene, kind: str = "good") -> tuple[np.ndarray, float]:
    """A hand-made grasp from the object's true pose, for tests: ``(T_camera_hand, approach_depth)``.

    ``"good"``: the centre of opposition -- midway between the thumb's
    closed tip and the mean closed tip of the other fingers -- over the
    object's centre of mass, the object's x axis (a lying can's or bottle's
    axis, the case's length) :data:`SCRIPTED_TILT` off the hand's x axis, so
    the four fingers close on its long side and the thumb on its end at an
    angle -- the kind of pose the synthesis picks for the can (its axis 15-35
    degrees off). With the end square to the thumb, the thumb, closing first,
    slides the can along its axis before the fingers arrive.
    ``"bad"``: the object's axis along the hand's x, shifted along it until
    the object lies beyond the thumb's closed tip: every finger that touches pushes from the
    same side (chapter 5's failure 2). The approach depth is the object's true
    top plus 1 cm, as the test planner does.
    """
    if kind not in ("good", "bad"):
        raise SimulationError(f"scripted grasp kind must be 'good' or 'bad', got {kind!r}")
    hand = scene.hand.hand
    rotation_world = scene.data.xmat[scene.object_body].reshape(3, 3)
    axis = scene.camera.from_world(scene.camera.position + rotation_world[:, 0])[:2]
    yaw = math.atan2(axis[1], axis[0]) + (SCRIPTED_TILT if kind == "good" else 0.0)
    thumbs = np.array([f.required for f in hand.fingers])
    target = (hand.ends[thumbs].mean(axis=0) + hand.ends[~thumbs].mean(axis=0)) / 2
    if kind == "bad":
        thumb_end = hand.ends[thumbs, 0].min()
        half_length = float(np.ptp(scene.object.points()[:, 0])) / 2
        target[0] = thumb_end + half_length + 0.01
    centre = scene.camera.from_world(scene.object_com())[:2]
    x, y = centre - _rotate(target, yaw)
    top = float(scene.camera.from_world(_world_points(scene))[:, 2].min())
    return pose_matrix(x, y, yaw, top + 0.01), top + 0.01


def _rotate(point, yaw) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([c * point[0] - s * point[1], s * point[0] + c * point[1]])


def _world_points(scene: Scene) -> np.ndarray:
    body = scene.object_body
    rotation = scene.data.xmat[body].reshape(3, 3)
    return scene.object.points() @ rotation.T + scene.data.xpos[body]
