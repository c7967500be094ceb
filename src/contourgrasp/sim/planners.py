"""Planners for simulated trials: the library's pipeline under named settings, and two baselines.

A planner is what :func:`~contourgrasp.sim.trial.run_trial` calls:
``planner(rgb, depth, intrinsics, *, target_px=None) -> (T_camera_hand, approach_depth, grasp_height)``
(``grasp_height`` None where the planner chose none),
raising :class:`~contourgrasp.errors.NoFeasibleGrasp` or
:class:`~contourgrasp.errors.InputError` when it has no plan; ``target_px``,
given in a scene of several objects, is the pixel (u, v) on the object to
grasp, and every planner here plans on the object under it (the baselines too,
through the same perception). Every planner here also has
``plan(rgb, depth, intrinsics, *, target_px=None) -> PlannedGrasp``, the same
answer with what it saw (for figures).

Synthesis planners (:func:`synthesis_planner`)
    :func:`contourgrasp.pipeline.plan_frame` -- exactly the path a user's camera
    frames take -- with a planner's options: a preset of
    :mod:`contourgrasp.io.planner_file` (``paper``, ``default``), a planner TOML
    file, or a step of the ablation from ``paper`` to ``default``
    (:func:`ablation_planners`).

Baselines (:data:`BASELINES`), to show whether the bench tells good from bad
    Both use the same perception as ``plan_frame`` (:func:`contourgrasp.pipeline.perceive`) and no synthesis.

    ``centroid-principal-axis``
        The hand's grasp centre (:attr:`~contourgrasp.hand.Hand.grasp_centre`,
        the mean closed fingertip) on the contour's centroid, the thumb
        closing along the contour's minor principal axis, i.e. across the
        object's narrow side (the other fingers of the Table 4.3 hand, closing
        at right angles to the thumb, then close along its length). Of the
        minor axis's two directions the one with positive image y is taken.
    ``random``
        A pose drawn uniformly from the ``paper`` planner's whole search region
        (the grid's x and y extent around the EFD locus, any yaw) among the poses
        that satisfy the synthesis constraints
        (:func:`~contourgrasp.synthesis.evaluate_poses`), by rejection
        sampling seeded with the trial seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ..contour import choose_harmonics, clean_polygon, fit
from .. import perception, pipeline, synthesis
from ..errors import HandError, NoFeasibleGrasp, SimulationError
from ..hand import Hand, Ray, to_image
from ..io.planner_file import Planner, load_planner, planner_names
from ..validation import flat_options

#: The ablation from ``paper`` to ``default``: each step takes ``default``'s values of these options. Then come
#: the 3-D hand's steps: finger bodies against the height map (with the executor's old grasp height),
#: the planned grasp height, the closing sweep, the small-object rule; the closing fingers kept clear of
#: obstacles; the squeeze's balance; then the cross-section at the grasp height (in ``default``
#: only where the outline seen has no balanced squeeze); the object between thumb and index; last, the
#: low-object rule.
ABLATION_STEPS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("grid", ("xy_step", "yaw_step", "d_max", "d_min")),
    ("quality", ("friction", "require_closure", "quality_gain")),
    ("thickness", ("finger_thickness", "clearance")),
    ("harmonics", ("harmonics",)),
    ("refine", ("refine",)),
    ("bodies", ("descent",)),
    ("height", ("grasp_height",)),
    ("sweep", ("closing_sweep",)),
    ("small", ("small_objects",)),
    ("closing", ("closing_obstacles",)),
    ("balance", ("max_imbalance",)),
    ("slice", ("slice_contour",)),
    ("centring", ("centring_gain",)),
    ("low", ("low_objects",)),
)
#: Baseline planners without synthesis: name -> what it does (module docstring).
BASELINES = {
    "centroid-principal-axis": "the hand's grasp centre on the contour's centroid, the thumb closing along its "
                               "minor axis; same perception, no synthesis",
    "random": "a pose drawn uniformly among the feasible poses of `paper`'s whole search region; "
              "same perception, no synthesis",
}
#: The planner names :func:`make_planner` knows besides planner files and ablation steps.
PLANNER_NAMES = (*planner_names(), *BASELINES)
#: The settings whose search region and constraints the random baseline uses.
RANDOM_REGION = "paper"
#: Random poses drawn per batch, and batches tried before giving up.
RANDOM_BATCH, RANDOM_BATCHES = 2048, 32


@dataclass(frozen=True, eq=False)
class PlannedGrasp:
    """A planner's answer and what it saw.

    Attributes
    ----------
    pose : (3,) float
        (x, y, yaw) of the hand in the planning frame of ``metric``.
    T_camera_hand : (4, 4) float
    approach_depth : float
    segmentation : Segmentation
    metric : MetricContour
    camera : contourgrasp.perception.Intrinsics
    plan : GraspPlan or None
        The synthesis result (None for a baseline).
    grasp_height : float or None
        The planned height of the open tips above the table (None: the execution's own rule).
    seen : (H, W) bool or None
        The depth image's pixels that see the object (:attr:`contourgrasp.pipeline.ImageGraspPlan.seen`; a tilted
        camera's ``segmentation`` is the object's footprint on the table, not these); None for a baseline.
    view : ApproachView or None
        A side or tilted plan's view (``pose`` is in its frame); None for a top-down plan.
    """

    pose: np.ndarray
    T_camera_hand: np.ndarray
    approach_depth: float
    segmentation: perception.Segmentation
    metric: perception.MetricContour
    camera: perception.Intrinsics
    plan: synthesis.GraspPlan | None
    grasp_height: float | None = None
    seen: np.ndarray | None = None
    view: perception.ApproachView | None = None

    @property
    def approach(self) -> perception.Approach:
        """The plan's approach (top-down: :data:`contourgrasp.pipeline.TOP_DOWN`)."""
        return pipeline.TOP_DOWN if self.view is None else self.view.approach


@dataclass(frozen=True)
class _Planner:
    """Base of the planners: ``__call__`` is the trial's planner interface over the subclass's ``plan``."""

    hand: Hand

    def __call__(self, rgb, depth, intrinsics, *, target_px=None):
        planned = self.plan(rgb, depth, intrinsics, target_px=target_px)
        return planned.T_camera_hand, planned.approach_depth, planned.grasp_height


@dataclass(frozen=True)
class SynthesisPlanner(_Planner):
    """:func:`contourgrasp.pipeline.plan_frame` with fixed options."""

    options: pipeline.PlanOptions = pipeline.PlanOptions()

    def plan(self, rgb, depth, intrinsics, *, target_px=None, memory=None) -> PlannedGrasp:
        result = pipeline.plan_frame(rgb, depth, intrinsics, self.hand, self.options, target_px=target_px,
                                     memory=memory)
        return PlannedGrasp(result.plan.pose, result.T_camera_hand, result.metric.approach_depth,
                            result.segmentation, result.metric, result.camera, result.plan, result.grasp_height,
                            result.seen, result.view)


@dataclass(frozen=True)
class CentroidPlanner(_Planner):
    """The ``centroid-principal-axis`` baseline (module docstring)."""

    def plan(self, rgb, depth, intrinsics, *, target_px=None, memory=None) -> PlannedGrasp:
        """The centroid's pose; ``memory`` is not used: the rule has one pose per outline."""
        segmentation, metric, _ = pipeline.perceive(rgb, depth, intrinsics, target_px=target_px)
        return _planned(centroid_pose(metric.contour_xy, self.hand), segmentation, metric, intrinsics)


@dataclass(frozen=True)
class RandomPlanner(_Planner):
    """The ``random`` baseline (module docstring), seeded by the trial seed."""

    seed: int = 0

    def plan(self, rgb, depth, intrinsics, *, target_px=None, memory=None) -> PlannedGrasp:
        """A random feasible pose; with a ``memory``, another draw per failure it holds (it is not avoided)."""
        segmentation, metric, _ = pipeline.perceive(rgb, depth, intrinsics, target_px=target_px)
        draws = [self.seed, 2] if not memory else [self.seed, 2, len(memory)]
        rng = np.random.default_rng(draws)  # streams 0 and 1 place the object and add noise
        pose = random_feasible_pose(metric.contour_xy, self.hand, rng, load_planner(RANDOM_REGION).options.search)
        return _planned(pose, segmentation, metric, intrinsics)


def ablation_planners() -> tuple[Planner, ...]:
    """``paper``, then per :data:`ABLATION_STEPS` step ``default``'s values of its options on top of the last.

    Steps are named ``paper+grid``, ``paper+grid+quality``, ...; a step that
    changes nothing is left out (an option a file leaves unset has the library's default), and the
    last step has ``default``'s effective options.
    """
    paper, default = load_planner("paper"), load_planner("default")
    options, target = dict(paper.settings), dict(default.settings)
    defaults = flat_options(pipeline.PlanOptions())
    steps, name = [paper], paper.name
    for step, keys in ABLATION_STEPS:
        changed = {k: target[k] for k in keys if k in target and options.get(k, defaults.get(k)) != target[k]}
        if changed:
            options |= changed
            name += f"+{step}"
            steps.append(Planner.from_settings(name, f"paper with default's {', '.join(changed)}", options.items()))
    if defaults | options != defaults | target:  # options outside every step (e.g. curvature) make a last step
        steps.append(Planner.from_settings(name + "+other", "paper with all of default's options", default.settings))
    return tuple(steps)


def synthesis_planner(name: str) -> Planner | None:
    """The planner a bench name means: a preset, an ablation step or a ``.toml`` file; None for a baseline.

    Raises
    ------
    SimulationError
        A name that is none of these (or a planner file that does not load).
    """
    if name in BASELINES:
        return None
    if name in planner_names():
        return load_planner(name)
    steps = {p.name: p for p in ablation_planners()}
    if name in steps:
        return steps[name]
    if Path(name).suffix == ".toml":
        return load_planner(name)
    raise SimulationError(f"unknown planner {name!r}: choose from {', '.join(PLANNER_NAMES)}, an ablation step "
                     f"({', '.join(steps)}) or a planner .toml file")


def make_planner(name: str, hand: Hand, *, seed: int = 0) -> _Planner:
    """The planner called ``name`` (see :func:`synthesis_planner`, or a baseline) for ``hand``; ``seed`` seeds ``random``.

    Raises
    ------
    SimulationError
        Unknown name.
    """
    planner = synthesis_planner(name)
    if planner is not None:
        return SynthesisPlanner(hand, planner.options)
    if name == "centroid-principal-axis":
        return CentroidPlanner(hand)
    if name == "random":
        return RandomPlanner(hand, seed)
    raise AssertionError(f"baseline {name!r} has no planner")  # BASELINES and this function disagree


def centroid_pose(contour_xy, hand: Hand) -> np.ndarray:
    """(3,) float: the pose putting ``hand.grasp_centre`` on the polygon's centroid, thumb along its minor axis."""
    moments = cv2.moments(np.asarray(contour_xy, dtype=np.float32))
    if moments["m00"] == 0:
        raise SimulationError("the contour encloses no area")
    centroid = np.array([moments["m10"], moments["m01"]]) / moments["m00"]
    covariance = np.array([[moments["mu20"], moments["mu11"]], [moments["mu11"], moments["mu02"]]])
    minor = np.linalg.eigh(covariance)[1][:, 0]  # eigenvalues ascending
    minor = minor if minor[1] >= 0 else -minor
    thumb = _thumb_direction(hand)
    yaw = (math.atan2(minor[1], minor[0]) - math.atan2(thumb[1], thumb[0])) % (2 * math.pi)
    x, y = centroid - to_image(hand.grasp_centre[None], (0.0, 0.0, yaw))[0]
    return np.array([x, y, yaw])


def _thumb_direction(hand: Hand) -> tuple[float, float]:
    """Closing direction of the first required finger (the thumb), else of the first finger."""
    finger = hand.fingers[hand.thumb_index]
    if not isinstance(finger.trajectory, Ray):
        raise HandError(f"hand {hand.name!r}: the centroid baseline needs a thumb that closes on a ray")
    return finger.trajectory.closing_direction


def random_feasible_pose(contour_xy, hand: Hand, rng: np.random.Generator,
                         options: synthesis.SearchOptions) -> np.ndarray:
    """(3,) float: a pose uniform over the search region's feasible poses (rejection sampling).

    The region is the ``options.grid``'s x and y extent around the EFD locus (as
    :func:`~contourgrasp.synthesis.search` would search it) and any yaw; feasibility is
    :func:`~contourgrasp.synthesis.evaluate_poses`'s with the grid's D_min, and the EFD model has the
    options' harmonics and curvature.

    Raises
    ------
    NoFeasibleGrasp
        None of ``RANDOM_BATCH * RANDOM_BATCHES`` poses drawn is feasible.
    """
    contour = clean_polygon(contour_xy)
    harmonics = choose_harmonics(contour, validate=False) if options.harmonics == "adaptive" else options.harmonics
    model = fit(contour, harmonics, validate=False)
    grid = options.grid
    xs, ys, _ = grid.axes(model.locus)
    low, high = np.array([xs[0], ys[0], 0.0]), np.array([xs[-1], ys[-1], 2 * math.pi])
    for _ in range(RANDOM_BATCHES):
        poses = rng.uniform(low, high, size=(RANDOM_BATCH, 3))
        feasible = synthesis.evaluate_poses(model, hand, poses, curvature=options.curvature,
                                            d_min=grid.d_min).feasible
        if feasible.any():
            return poses[np.argmax(feasible)]
    raise NoFeasibleGrasp(f"none of {RANDOM_BATCH * RANDOM_BATCHES} random poses in the search region is feasible")


def _planned(pose, segmentation, metric, camera) -> PlannedGrasp:
    pose = np.asarray(pose, dtype=float)
    return PlannedGrasp(pose, pipeline.hand_pose(metric, pose, metric.approach_depth), metric.approach_depth,
                        segmentation, metric, camera, None)
