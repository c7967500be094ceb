"""Grasp synthesis: the inner and outer problems of thesis section 3.4.

Inner problem (eq 3.22-3.31)
    For a pose and a finger, the grasp point is where the fingertip *first*
    touches the EFD contour while it closes, ``0 <= lam <= travel``. The
    thesis's least-squares form (eq 3.24) has a zero wherever the trajectory
    crosses the contour, so for a ray that enters and leaves the object it has
    two; only the first is physical, because the finger stops there. We solve it
    exactly, by intersecting every trajectory chord with the EFD contour sampled
    as a polygon (``tolerances.EFD_SAMPLES`` points). A finger whose trajectory
    never meets the contour *misses*; the plan reports its closest approach.

Outer problem (eq 3.32-3.41)
    A grid over x, y within ``d_max`` of the contour's locus (A0, C0) (eq
    3.39-3.40) and yaw over [0, 2 pi). A pose is feasible when

    * no fingertip starts inside the contour (the hand comes down from above),
    * every touching finger starts at least ``d_min`` from its grasp point
      (eq 3.41, distance as in eq 3.36 with lambda_virt = 0),
    * every ``required`` finger touches, and at least ``hand.min_touching`` do.

    Its cost (eq 3.34) has three parts, summed over touching fingers i:

    * curvature: alpha_i * C(t_i), with C the signed curvature of
      :func:`contourgrasp.efd.curvature` (concave points lower the cost);
    * ratio: beta_i * (dist_i - mean_{j != i} dist_j)^2, with dist the distance
      from the finger's virtual start to its grasp point (eq 3.35-3.36) and the
      mean over the other touching fingers. Eq 3.35 prints the deviation
      without the square; that form sums to zero over the fingers for equal
      gains and cannot steer toward simultaneous contact (see
      :func:`ratio_cost`, ``form="linear"``), and gains of 1e4 against
      distances of centimeters point to a square;
    * miss: ``hand.miss_penalty`` per finger that closes on air.

Search: :func:`screen_grid` evaluates every grid pose with a compiled kernel
(contacts on the EFD polygon, curvature from tables); :func:`evaluate_poses`
then solves the cheapest candidates exactly (polygon contacts compiled, then
Newton onto the curve, numpy). There is no Python loop per pose. Optionally
(``synthesize(refine=True)``), :func:`refine_poses` leaves the grid: a bounded
compass search in (x, y, yaw) from the best distinct grid poses, on the exact
cost and under the same constraints.
"""

from __future__ import annotations

import math
import time
import weakref
from dataclasses import dataclass, fields
from typing import Literal

import numpy as np

from . import efd as efd_model
from . import quality
from . import tolerances as tol
from .efd import EFD, CurvatureMode
from .errors import InputError, NoFeasibleGrasp
from ._kernels import (grid_first_touch, interpolate_curvature, nearest_point_segment, pose_first_touch,
                       ratio_cost_rows, score_poses)
from .hand import Hand, HandSegments, Ray, rotation, to_image


@dataclass(frozen=True)
class SearchGrid:
    """Resolution and extent of the outer problem's pose grid (Tables 4.1-4.2).

    Attributes
    ----------
    xy_step : float
        Position resolution, m.
    yaw_step : float
        Orientation resolution, rad.
    d_max : (2,) float
        (D_max,x, D_max,y): largest offset of the hand from the locus, m.
    d_min : float
        D_min: smallest distance from a fingertip's start to its grasp point, m.
    """

    xy_step: float = 0.05
    yaw_step: float = math.radians(2.0)
    d_max: tuple[float, float] = (0.15, 0.15)
    d_min: float = 0.015

    def __post_init__(self):
        d_max = tuple(float(v) for v in np.broadcast_to(np.asarray(self.d_max, dtype=float), (2,)))
        object.__setattr__(self, "d_max", d_max)
        for name, value, ok in [
            ("xy_step", self.xy_step, self.xy_step > 0),
            ("yaw_step", self.yaw_step, 0 < self.yaw_step <= 2 * math.pi),
            ("d_max", self.d_max, min(d_max) >= 0),
            ("d_min", self.d_min, self.d_min >= 0),
        ]:
            if not (ok and np.all(np.isfinite(value))):
                raise InputError(f"{name} out of range: {value!r}")

    def axes(self, locus) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The grid's x (nx,), y (ny,) and yaw (nyaw,) values around ``locus`` (2,)."""
        xy = []
        for centre, extent in zip(locus, self.d_max):
            n = int(math.floor(extent / self.xy_step + 1e-9))
            xy.append(centre + self.xy_step * np.arange(-n, n + 1))
        n_yaw = int(math.ceil(2 * math.pi / self.yaw_step - 1e-9))
        return xy[0], xy[1], self.yaw_step * np.arange(n_yaw)

    def poses(self, locus) -> np.ndarray:
        """(p, 3) float: every (x, y, yaw) of the grid around ``locus`` (2,), yaw varying fastest."""
        x, y, yaw = self.axes(locus)
        poses = np.empty((len(x), len(y), len(yaw), 3))
        poses[..., 0], poses[..., 1], poses[..., 2] = x[:, None, None], y[:, None], yaw
        return poses.reshape(-1, 3)


@dataclass(frozen=True)
class Safeguards:
    """Constraints and a cost term beyond the thesis's, against the failures of its chapter 5.

    All off (the default) is the thesis's problem. They act where contacts are
    exact (:func:`evaluate_poses`): :func:`synthesize` screens the grid
    without them, then applies them to the cheapest candidates, widening the
    candidate set until one passes.

    Attributes
    ----------
    finger_thickness : bool
        Fingers are discs of their hand file's ``radius`` (failure 5, a finger
        striking the object on the way). A pose is rejected when a fingertip
        starts closer than ``radius + clearance`` to the contour, or when the
        disc swept along its trajectory up to the grasp point meets the contour
        farther than ``2 radius`` from the grasp point (the disc of a finger
        meeting a flat side at up to ~60 deg from its normal touches within
        that distance; beyond, it hits another part of the object first). A
        finger that misses must clear the contour by ``radius`` all along.
    clearance : float
        Extra free distance around every open fingertip, m: the margin for the
        open finger leaning over its path and for segmentation error.
    friction : float
        mu of the grasp quality (:mod:`contourgrasp.quality`).
    require_closure : bool
        Reject poses whose grasp points are not in 2-D force closure (failure 2,
        "all grasping points on the same surface"; 6.1 item 2).
    quality_gain : float
        Cost term ``-quality_gain * epsilon`` (Ferrari-Canny L1, wrenches about
        the EFD locus, torque over the contour's largest radius about it).
    """

    finger_thickness: bool = False
    clearance: float = 0.0
    friction: float = 0.5
    require_closure: bool = False
    quality_gain: float = 0.0

    def __post_init__(self):
        for name in ("clearance", "friction", "quality_gain"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise InputError(f"{name} must be a number >= 0, got {value!r}")

    @property
    def grades_quality(self) -> bool:
        """Epsilon is needed for every candidate (not only the plan)."""
        return self.require_closure or self.quality_gain > 0


@dataclass(frozen=True, eq=False)
class PoseEvaluation:
    """Inner-problem solutions and costs for many poses; arrays are (p,) or (p, n_fingers).

    Attributes
    ----------
    poses : (p, 3) float
    touching : (p, f) bool
        The finger meets the contour within its travel.
    lam : (p, f) float
        Distance travelled to the grasp point, m (NaN where missed).
    t : (p, f) float
        EFD parameter of the grasp point (NaN where missed).
    grasp_point : (p, f, 2) float
        Image-plane grasp point, m (NaN where missed).
    distance : (p, f) float
        dist(t, lambda_virt) of eq 3.36: virtual start to grasp point, m.
    start_distance : (p, f) float
        dist(t, 0): actual start to grasp point, m (eq 3.41).
    curvature : (p, f) float
        Signed curvature at the grasp point (NaN where missed).
    start_inside : (p, f) bool
        The fingertip starts inside the contour.
    starts_outside : (p,) bool
        No fingertip starts inside the contour.
    reaches : (p,) bool
        Every required finger and at least ``min_touching`` fingers touch.
    clear : (p,) bool
        The fingers pass :class:`Safeguards` ``finger_thickness`` (all True when it is off).
    epsilon : (p,) float
        Ferrari-Canny epsilon of the grasp points (NaN where not computed).
    feasible : (p,) bool
    cost_curvature, cost_ratio, cost_miss, cost_quality, cost : (p,) float
    """

    poses: np.ndarray
    touching: np.ndarray
    lam: np.ndarray
    t: np.ndarray
    grasp_point: np.ndarray
    distance: np.ndarray
    start_distance: np.ndarray
    curvature: np.ndarray
    start_inside: np.ndarray
    starts_outside: np.ndarray
    reaches: np.ndarray
    clear: np.ndarray
    epsilon: np.ndarray
    feasible: np.ndarray
    cost_curvature: np.ndarray
    cost_ratio: np.ndarray
    cost_miss: np.ndarray
    cost_quality: np.ndarray
    cost: np.ndarray


@dataclass(frozen=True)
class Cost:
    """The cost of a pose (eq 3.34) and its parts (``quality``: :class:`Safeguards` ``quality_gain``)."""

    total: float
    curvature: float
    ratio: float
    miss: float
    quality: float = 0.0


@dataclass(frozen=True, eq=False)
class FingerContact:
    """Where one finger meets the object at the chosen pose (image plane, meters).

    For a missed finger, ``grasp_point``, ``t``, ``lam`` are the closest approach
    between its trajectory and the contour, and ``gap`` is their distance.
    """

    name: str
    grasp_point: np.ndarray
    t: float
    lam: float
    curvature: float
    concave: bool
    distance: float
    start: np.ndarray
    virtual_start: np.ndarray
    missed: bool
    gap: float


@dataclass(frozen=True)
class Alternative:
    """A ranked candidate pose (x, y, yaw) and its cost."""

    pose: tuple[float, float, float]
    cost: Cost


@dataclass(frozen=True)
class Refinement:
    """What the continuous refinement of :func:`synthesize` (``refine=True``) gained over the grid.

    Attributes
    ----------
    grid_pose : (3,) float
        The best grid pose (exactly evaluated), before refinement.
    grid_cost : float
        Its cost (eq 3.34).
    cost : float
        The plan's cost after refinement, never above ``grid_cost``.
    """

    grid_pose: tuple[float, float, float]
    grid_cost: float
    cost: float

    @property
    def gain(self) -> float:
        """grid_cost - cost, >= 0."""
        return self.grid_cost - self.cost


@dataclass(frozen=True, eq=False)
class GraspPlan:
    """The result of :func:`synthesize`.

    Attributes
    ----------
    pose : (3,) float
        Best hand pose (x, y, yaw) in the image plane: m, m, rad.
    cost : Cost
    fingers : tuple of FingerContact
    efd : EFD
    hand : Hand
    contour : (n, 2) float
        The input polygon, cleaned, in its input orientation.
    curvature_mode : str
    grid : SearchGrid
    alternatives : tuple of Alternative
        The best distinct poses in increasing cost; the first is ``pose``.
        Distinct: no two are neighbours on the grid in x, y and yaw at once.
    grid_size : int
        Poses evaluated.
    feasible_poses : int
    timing_ms : dict
        Wall time per stage, milliseconds: ``efd`` (contour check and fit), ``search`` (grid
        screen), ``exact`` (exact re-evaluation of the best screened poses), ``refine``
        (continuous refinement, 0 without it) and ``total``.
    refinement : Refinement or None
        The grid's best and the gain of the continuous refinement; None without it.
    safeguards : Safeguards
    quality : contourgrasp.quality.GraspQuality
        Force closure and Ferrari-Canny L1 epsilon of the grasp points (missed fingers excluded).
    """

    pose: np.ndarray
    cost: Cost
    fingers: tuple[FingerContact, ...]
    efd: EFD
    hand: Hand
    contour: np.ndarray
    curvature_mode: str
    grid: SearchGrid
    alternatives: tuple[Alternative, ...]
    grid_size: int
    feasible_poses: int
    timing_ms: dict
    refinement: Refinement | None
    safeguards: Safeguards
    quality: quality.GraspQuality


#: Values derived from an object (a model, a hand) by :func:`_cached`: id -> (weak reference, {kind: value}).
_DERIVED: dict = {}


def _cached(owner, kind, build):
    """``build()``, computed once per ``owner`` (by identity) and ``kind``; the entry goes with its owner.

    Every stage of a plan (and every round of the refinement) needs the same polygon of its model
    and the same arrays of its hand; they are shared between them, so callers must not modify them.
    """
    key = id(owner)
    entry = _DERIVED.get(key)
    if entry is None or entry[0]() is not owner:
        entry = _DERIVED[key] = (weakref.ref(owner, lambda _, key=key: _DERIVED.pop(key, None)), {})
    values = entry[1]
    if kind not in values:
        values[kind] = build()
    return values[kind]


def _polygon(model: EFD, samples: int = tol.EFD_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
    """:func:`contourgrasp.efd.sample` of ``model``, computed once per model and count (:func:`_cached`)."""
    return _cached(model, ("polygon", samples), lambda: _read_only(*efd_model.sample(model, samples)))


def _read_only(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """The arrays, made read-only: cached values are shared, and a write to one would leak into later plans."""
    for a in arrays:
        a.setflags(write=False)
    return arrays


@dataclass(frozen=True, eq=False)
class _HandArrays:
    """A hand's fingers as the arrays the search needs (:func:`_hand_arrays`); rows are fingers.

    ``rays``: closing directions, NaN for fingers on arcs; ``first``: (s,) bool, the chord is its finger's first.
    """

    segments: HandSegments
    first: np.ndarray
    starts: np.ndarray
    virtual_starts: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    required: np.ndarray
    travel: np.ndarray
    rays: np.ndarray


def _hand_arrays(hand: Hand) -> _HandArrays:
    """The :class:`_HandArrays` of ``hand``, built once (:func:`_cached`)."""
    return _cached(hand, "arrays", lambda: _build_hand_arrays(hand))


def _build_hand_arrays(hand: Hand) -> _HandArrays:
    """The :class:`_HandArrays` of ``hand``, from its fingers."""
    segments = hand.segments()
    fingers = hand.fingers
    return _HandArrays(segments, *_read_only(
        _first_chords(segments, len(fingers)),
        np.array(hand.starts, dtype=float),
        np.array(hand.virtual_starts, dtype=float),
        np.array([f.alpha for f in fingers], dtype=float),
        np.array([f.beta for f in fingers], dtype=float),
        np.array([f.required for f in fingers]),
        np.array([f.travel for f in fingers], dtype=float),
        np.array([f.trajectory.closing_direction if isinstance(f.trajectory, Ray) else (np.nan, np.nan)
                  for f in fingers]),
    ))


def first_touch(
    contour: np.ndarray, contour_t: np.ndarray, period: float, segments: HandSegments, n_fingers: int, poses: np.ndarray
):
    """Solve the inner problem for every pose and finger: the first contact along the closing motion.

    Parameters
    ----------
    contour : (m, 2) float
        Closed polygon sampling the EFD curve at parameters ``contour_t`` (m,), increasing.
    period : float
        T of the EFD; the last edge runs from ``contour_t[-1]`` to ``period``.
    segments : HandSegments
        Trajectory chords in the hand frame.
    n_fingers : int
    poses : (p, 3) float

    Returns
    -------
    lam : (p, f) float
        Distance travelled at first contact, ``inf`` where the finger misses.
    t : (p, f) float
        EFD parameter of the contact (NaN where missed).
    point : (p, f, 2) float
        Contact point in the image plane (NaN where missed).
    start_inside : (p, f) bool
        The fingertip starts inside the contour.
    """
    R = rotation(poses[:, 2])
    p = poses[:, None, :2] + np.einsum("pij,sj->psi", R, segments.start)
    d = np.einsum("pij,sj->psi", R, segments.end - segments.start)
    q = contour
    e = np.roll(q, -1, axis=0) - q
    dt = np.diff(np.append(contour_t, period))

    denom = d[..., 0, None] * e[:, 1] - d[..., 1, None] * e[:, 0]
    p_cross_e = p[..., 0, None] * e[:, 1] - p[..., 1, None] * e[:, 0]
    q_cross_e = q[:, 0] * e[:, 1] - q[:, 1] * e[:, 0]
    q_cross_d = q[:, 0] * d[..., 1, None] - q[:, 1] * d[..., 0, None]
    p_cross_d = (p[..., 0] * d[..., 1] - p[..., 1] * d[..., 0])[..., None]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = (q_cross_e - p_cross_e) / denom
        v = (q_cross_d - p_cross_d) / denom
    crosses_edge = (np.abs(denom) > tol.PARALLEL) & (v >= 0) & (v < 1)
    hit = crosses_edge & (u >= 0) & (u <= 1)
    # Parity of the crossings of each finger's first chord, extended to a half-line, tells
    # whether its start lies inside the contour (even-odd rule) at no extra cost.
    first_chord = np.searchsorted(segments.finger, np.arange(n_fingers))
    start_inside = np.count_nonzero(crosses_edge[:, first_chord] & (u[:, first_chord] >= 0), axis=2) % 2 == 1
    lam_seg = np.where(hit, segments.lam0[:, None] + u * segments.length[:, None], np.inf)
    edge = np.argmin(lam_seg, axis=2)
    lam_seg = np.take_along_axis(lam_seg, edge[..., None], 2)[..., 0]
    v_seg = np.take_along_axis(v, edge[..., None], 2)[..., 0]

    n = len(poses)
    rows = np.arange(n)
    lam = np.full((n, n_fingers), np.inf)
    t = np.full((n, n_fingers), np.nan)
    point = np.full((n, n_fingers, 2), np.nan)
    for i in range(n_fingers):
        own = np.flatnonzero(segments.finger == i)
        best = own[np.argmin(lam_seg[:, own], axis=1)]
        lam[:, i] = lam_seg[rows, best]
        k, frac = edge[rows, best], v_seg[rows, best]
        touched = np.isfinite(lam[:, i])
        t[touched, i] = contour_t[k[touched]] + frac[touched] * dt[k[touched]]
        point[touched, i] = q[k[touched]] + frac[touched, None] * e[k[touched]]
    return lam, t, point, start_inside


def ratio_cost(
    distance: np.ndarray, touching: np.ndarray, beta: np.ndarray, *, form: Literal["squared", "linear"] = "squared"
) -> np.ndarray:
    """Cost of ratio (eq 3.35), summed over touching fingers.

    ``beta_i * (dist_i - mean_{j != i} dist_j)`` squared (our reading, the
    default) or as printed (``form="linear"``); the mean runs over the other
    *touching* fingers, and a finger with no touching partner costs nothing.

    Parameters
    ----------
    distance : (p, f) float
        dist(t_i, lambda_virt,i) of eq 3.36.
    touching : (p, f) bool
    beta : (f,) float

    Returns
    -------
    (p,) float

    Examples
    --------
    With equal gains the printed form sums to zero whatever the distances:

    >>> d = np.array([[0.01, 0.05, 0.02]])
    >>> abs(float(ratio_cost(d, np.ones((1, 3), bool), np.ones(3), form="linear")[0])) < 1e-15
    True
    """
    if form not in ("squared", "linear"):
        raise ValueError(f"form must be 'squared' or 'linear', got {form!r}")
    distance = np.where(touching, distance, 0.0).astype(float)
    return ratio_cost_rows(distance, np.asarray(touching, bool), np.asarray(beta, dtype=float), form == "squared")


def evaluate_poses(
    model: EFD,
    hand: Hand,
    poses: np.ndarray,
    *,
    curvature: CurvatureMode = "paper",
    d_min: float = 0.015,
    samples: int = tol.EFD_SAMPLES,
    safeguards: Safeguards = Safeguards(),
) -> PoseEvaluation:
    """Solve the inner problem exactly and the outer cost for each pose (eq 3.22-3.41).

    The first touch is found on the EFD curve sampled as a polygon, then moved
    onto the curve itself by Newton's method on r(t) = p(lam) (the zero of
    eq 3.24 nearest the polygon's answer).

    Parameters
    ----------
    model : EFD
    hand : Hand
    poses : (p, 3) float
        (x, y, yaw) of the hand in the image plane.
    curvature : {"paper", "geometric"}
    d_min : float
        D_min of eq 3.41, m.
    samples : int
        Points of the EFD polygon the fingers are intersected with first.
    safeguards : Safeguards
        Constraints and cost beyond the thesis's (default: none).

    Returns
    -------
    PoseEvaluation
    """
    poses = np.atleast_2d(np.asarray(poses, dtype=float))
    contour_t, contour = _polygon(model, samples)
    arrays = _hand_arrays(hand)
    segments, n_f = arrays.segments, len(hand.fingers)
    lam, t, point, start_inside = pose_first_touch(
        contour, contour_t, model.T, poses, segments.start, segments.end - segments.start, segments.finger,
        segments.lam0, arrays.first, n_f, tol.PARALLEL,
    )
    touching = np.isfinite(lam)
    t, lam, point = _newton(model, hand, poses, t, lam, point, touching, model.T / samples)
    curv = np.full(lam.shape, np.nan)
    curv[touching] = efd_model.curvature(model, t[touching], curvature)
    clear = np.ones(len(poses), bool)
    if safeguards.finger_thickness:
        # chunks bound the (poses, contour points, chords) arrays when the candidate set widens
        clear = np.concatenate([fingers_clear(contour, hand, poses[rows], lam[rows], point[rows],
                                              clearance=safeguards.clearance)
                                for rows in np.array_split(np.arange(len(poses)), -(-len(poses) // tol.POSE_BATCH))])
    epsilon = np.full(len(poses), np.nan)
    if safeguards.grades_quality:
        epsilon = grasp_epsilon(model, point, t, touching, friction=safeguards.friction)
    return _assemble(hand, poses, touching, lam, t, point, curv, start_inside, d_min, clear, epsilon, safeguards)


def screen_grid(
    model: EFD, hand: Hand, grid: SearchGrid, *, curvature: CurvatureMode = "paper", samples: int = tol.EFD_SAMPLES
) -> PoseEvaluation:
    """Evaluate every pose of a grid fast, to within the EFD polygon's accuracy.

    Contacts stay on the sampled polygon (``samples`` points) and curvature is
    interpolated from tables (``tol.CURVATURE_TABLE`` samples), so costs differ
    from :func:`evaluate_poses` by about 1e-4 relative (up to ~1 where a contact
    grazes the contour); :func:`synthesize` re-evaluates the best candidates
    exactly. The inner loop is the compiled :func:`contourgrasp._kernels.grid_first_touch`.
    """
    xs, ys, yaws = grid.axes(model.locus)
    contour_t, contour = _polygon(model, samples)
    arrays = _hand_arrays(hand)
    seg, n_f = arrays.segments, len(hand.fingers)
    lam, t, point, start_inside = grid_first_touch(
        contour, contour_t, model.T, xs, ys, yaws, seg.start, seg.end - seg.start, seg.finger, seg.lam0, arrays.first,
        n_f, tol.PARALLEL,
    )
    # The paper's curvature jumps where the contour turns from convex to concave; its magnitude and
    # the turning direction r' x r'' do not, so they are tabulated and interpolated apart.
    table_t = np.linspace(0.0, model.T, tol.CURVATURE_TABLE, endpoint=False)
    d1, d2 = efd_model.evaluate_derivatives(model, table_t, (1, 2))
    turn = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    magnitude = np.abs(efd_model.curvature_from_derivatives(d1, d2, model.T, curvature))
    curv = interpolate_curvature(magnitude, turn, t, model.T)
    touching = np.isfinite(lam)
    poses = grid.poses(model.locus)
    n = len(poses)
    return _assemble(hand, poses, touching, np.where(touching, lam, np.nan), t, point, curv, start_inside,
                     grid.d_min, np.ones(n, bool), np.full(n, np.nan), Safeguards(), n_yaw=len(yaws))


def refine_poses(
    model: EFD,
    hand: Hand,
    poses,
    *,
    step=(0.05, math.radians(2.0)),
    d_max=None,
    halvings: int = tol.REFINE_HALVINGS,
    rounds: int = tol.REFINE_ROUNDS,
    **evaluation,
) -> PoseEvaluation:
    """Improve poses continuously: a bounded compass search on the exact cost of :func:`evaluate_poses`.

    The grid of the outer problem (eq 3.39-3.40) only visits multiples of its steps; the optimum
    of eq 3.34 lies between them. From each pose the search tries +-s along x, y and yaw (every
    pose and direction in one call of :func:`evaluate_poses`), moves to the cheapest feasible trial
    cheaper than where it stands and doubles s (up to half a grid step, where it starts), or halves
    s where there is none. A pose stops when s falls below half a grid step / 2**``halvings``, and
    every pose after ``rounds`` rounds. The cost is piecewise smooth (a finger's contact jumps where
    it grazes the contour), which a compass search, unlike a gradient method, takes in its stride.

    A pose stays within one grid step of its start and, with ``d_max``, within D_max of the
    locus. A feasible pose stays feasible and its cost never rises; an infeasible one moves to a
    feasible trial when it finds one.

    Parameters
    ----------
    model : EFD
    hand : Hand
    poses : (p, 3) float
        Start poses (x, y, yaw), e.g. the grid's best.
    step : (2,) float
        The grid's (xy, yaw) steps, m and rad.
    d_max : float or (2,) float, optional
        D_max,x and D_max,y of eq 3.39-3.40, m; None: no bound but the step box.
    halvings : int
        Halvings of s before a pose stops (resolution: step / 2**(halvings + 1)).
    rounds : int
        Calls of :func:`evaluate_poses` at most, after the one for the start poses.
    **evaluation
        Passed to every :func:`evaluate_poses` call (``curvature``, ``d_min``, ``samples``, its
        constraints...): the refined poses satisfy what the grid's did.

    Returns
    -------
    PoseEvaluation
        Of the refined poses, in the order given.
    """
    poses = np.atleast_2d(np.asarray(poses, dtype=float))
    steps = np.asarray(step, dtype=float)
    if steps.shape != (2,) or not np.all(np.isfinite(steps) & (steps > 0)):
        raise InputError(f"step must be two positive numbers (xy, yaw), got {step!r}")
    for name, value in (("halvings", halvings), ("rounds", rounds)):
        if not isinstance(value, (int, np.integer)) or value < 0:
            raise InputError(f"{name} must be a non-negative integer, got {value!r}")
    scale = steps[[0, 0, 1]]
    lower, upper = poses - scale, poses + scale
    if d_max is not None:
        box = np.broadcast_to(np.asarray(d_max, dtype=float), (2,))
        if not np.all(np.isfinite(box) & (box >= 0)):
            raise InputError(f"d_max must be non-negative, got {d_max!r}")
        lower[:, :2] = np.maximum(lower[:, :2], model.locus - box)
        upper[:, :2] = np.minimum(upper[:, :2], model.locus + box)
    directions = np.vstack([np.eye(3), -np.eye(3)]) * scale
    current = evaluate_poses(model, hand, poses, **evaluation)
    s = np.full(len(poses), 0.5)
    for _ in range(rounds):
        active = np.flatnonzero(s >= 0.5**(halvings + 1))
        if active.size == 0:
            break
        trials = np.clip(current.poses[active, None] + s[active, None, None] * directions,
                         lower[active, None], upper[active, None])
        tried = evaluate_poses(model, hand, trials.reshape(-1, 3), **evaluation)
        cost = np.where(tried.feasible, tried.cost, np.inf).reshape(len(active), len(directions))
        pick = np.argmin(cost, axis=1)
        best = cost[np.arange(len(active)), pick]
        moves = np.isfinite(best) & (~current.feasible[active] | (best < current.cost[active]))
        current = _replace_rows(current, active[moves], tried, (np.arange(len(active)) * len(directions) + pick)[moves])
        s[active] = np.where(moves, np.minimum(2 * s[active], 0.5), s[active] / 2)
    np.mod(current.poses[:, 2], 2 * math.pi, out=current.poses[:, 2])  # the box may reach below yaw 0
    return current


def _replace_rows(evaluation: PoseEvaluation, rows, source: PoseEvaluation, source_rows) -> PoseEvaluation:
    """``evaluation`` with its ``rows`` replaced by ``source_rows`` of ``source``."""
    def replaced(name):
        values = getattr(evaluation, name).copy()
        values[rows] = getattr(source, name)[source_rows]
        return values

    return PoseEvaluation(**{f.name: replaced(f.name) for f in fields(PoseEvaluation)})


def _concatenate(*evaluations: PoseEvaluation) -> PoseEvaluation:
    """The poses of several evaluations, in order, as one."""
    return PoseEvaluation(**{f.name: np.concatenate([getattr(e, f.name) for e in evaluations])
                             for f in fields(PoseEvaluation)})


def _first_chords(segments: HandSegments, n_fingers: int) -> np.ndarray:
    """(s,) bool: the chord is its finger's first (its half-line decides whether the finger starts inside)."""
    first = np.zeros(len(segments.finger), bool)
    first[np.searchsorted(segments.finger, np.arange(n_fingers))] = True
    return first


def _newton(model: EFD, hand: Hand, poses, t, lam, point, touching, t_step, iterations: int = 4):
    """Newton on r(t) - p(lam) = 0 from the polygon's contacts; keeps the polygon's answer where it fails.

    Every touching (pose, finger) pair iterates at once: the curve is evaluated for all of them
    together, which is most of the work. From the polygon's contacts (within ~1e-5 m) Newton
    converges in two or three steps; it stops once no step exceeds 1e-12 m.
    """
    t, lam, point = t.copy(), lam.copy(), point.copy()
    rows, fingers = np.nonzero(touching)
    R = rotation(poses[rows, 2])
    xy = poses[rows, :2]
    t_i, lam_i = t[rows, fingers], lam[rows, fingers]
    paths = _Paths(hand, fingers)
    for _ in range(iterations):
        local, direction = paths.at(lam_i)
        r, dr = efd_model.evaluate_derivatives(model, t_i, (0, 1))
        F = r - xy - np.einsum("pij,pj->pi", R, local)
        dp = np.einsum("pij,pj->pi", R, direction)
        det = -dr[:, 0] * dp[:, 1] + dp[:, 0] * dr[:, 1]
        det = np.where(np.abs(det) > 1e-12, det, np.inf)
        step_t = (F[:, 0] * dp[:, 1] - F[:, 1] * dp[:, 0]) / det
        step_lam = (dr[:, 1] * F[:, 0] - dr[:, 0] * F[:, 1]) / det
        t_i, lam_i = t_i + step_t, lam_i + step_lam
        if not (np.abs(step_t) > 1e-12).any() and not (np.abs(step_lam) > 1e-12).any():
            break
    local, _ = paths.at(lam_i, tangents=False)
    r = efd_model.evaluate(model, t_i)
    residual = np.linalg.norm(r - xy - np.einsum("pij,pj->pi", R, local), axis=1)
    travel = _hand_arrays(hand).travel[fingers]
    ok = (residual < 1e-9) & (lam_i >= 0) & (lam_i <= travel) & (np.abs(t_i - t[rows, fingers]) < 2 * t_step)
    rows, fingers = rows[ok], fingers[ok]
    t[rows, fingers] = t_i[ok] % model.T
    lam[rows, fingers] = lam_i[ok]
    point[rows, fingers] = r[ok]
    return t, lam, point


class _Paths:
    """The trajectories of fingers ``fingers`` (n,) int of a hand, evaluated together at every Newton step.

    Rays in one expression, arcs finger by finger; what does not change between steps is indexed once.
    """

    def __init__(self, hand: Hand, fingers: np.ndarray):
        arrays = _hand_arrays(hand)
        self.starts, self.rays = arrays.starts[fingers], arrays.rays[fingers]
        on_arcs = np.unique(fingers[np.isnan(self.rays[:, 0])])
        self.arcs = [(hand.fingers[f], fingers == f) for f in on_arcs]

    def at(self, lam, tangents: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Hand-frame points and unit tangents (both (n, 2)) after travelling ``lam`` (n,); tangents of arcs
        only if ``tangents``."""
        direction = self.rays.copy()
        points = self.starts + lam[:, None] * direction
        for finger, rows in self.arcs:
            points[rows] = finger.points(lam[rows])
            if tangents:
                direction[rows] = finger.tangent(lam[rows])
        return points, direction


def _assemble(hand: Hand, poses, touching, lam, t, point, curv, start_inside, d_min, clear, epsilon,
              safeguards: Safeguards, n_yaw: int | None = None) -> PoseEvaluation:
    """Constraints 3.39-3.41 and the cost of eq 3.34 (plus the safeguards') from the inner problem's solutions.

    ``n_yaw``: the period of the poses' yaws, for a grid (yaw fastest); None for any list of poses.
    """
    arrays = _hand_arrays(hand)
    (distance, start_distance, outside, reaches, far_enough, cost_curvature, cost_ratio, cost_miss) = score_poses(
        poses, len(poses) if n_yaw is None else n_yaw, touching, point, curv, start_inside, arrays.starts,
        arrays.virtual_starts, arrays.alpha, arrays.beta, arrays.required, hand.min_touching, float(hand.miss_penalty),
        float(d_min),
    )
    feasible = outside & reaches & far_enough & clear
    if safeguards.require_closure:
        feasible &= epsilon > 0
    cost_quality = -safeguards.quality_gain * np.nan_to_num(epsilon) if safeguards.quality_gain else np.zeros(len(poses))
    return PoseEvaluation(
        poses=poses,
        touching=touching,
        lam=lam,
        t=t,
        grasp_point=point,
        distance=distance,
        start_distance=start_distance,
        curvature=curv,
        start_inside=start_inside,
        starts_outside=outside,
        reaches=reaches,
        clear=clear,
        epsilon=epsilon,
        feasible=feasible,
        cost_curvature=cost_curvature,
        cost_ratio=cost_ratio,
        cost_miss=cost_miss,
        cost_quality=cost_quality,
        cost=cost_curvature + cost_ratio + cost_miss + cost_quality,
    )


def fingers_clear(contour, hand: Hand, poses, lam, grasp_point, *, clearance: float = 0.0,
                  samples: int = 9) -> np.ndarray:
    """Finger-thickness check of :class:`Safeguards` for each pose.

    Parameters
    ----------
    contour : (m, 2) float
        The object's polygon (e.g. the EFD curve sampled).
    hand : Hand
        Finger radii from ``Finger.radius``.
    poses : (p, 3) float
    lam : (p, f) float
        Travel to the grasp point; NaN for a finger that misses (it sweeps its whole travel).
    grasp_point : (p, f, 2) float
    clearance : float
        Extra free distance required around every open fingertip, m.
    samples : int
        Points of each swept path (its chords bound arcs to a fraction of a mm).

    Returns
    -------
    (p,) bool
        Every fingertip starts ``radius + clearance`` clear of the contour and
        its swept disc first meets the contour within ``2 radius`` of its grasp point.
    """
    poses = np.atleast_2d(np.asarray(poses, dtype=float))
    p = len(poses)
    edges = np.roll(contour, -1, axis=0) - contour
    rotations = rotation(poses[:, 2])
    u = np.linspace(0.0, 1.0, samples)
    ok = np.ones(p, bool)
    for f, finger in enumerate(hand.fingers):
        reach = np.where(np.isfinite(lam[:, f]), lam[:, f], finger.travel)
        path = finger.points(np.outer(reach, u).ravel()).reshape(p, samples, 2)
        path = np.einsum("pij,pkj->pki", rotations, path) + poses[:, None, :2]
        ok &= _distance_to_segments(path[:, :1], contour[None], edges[None]).min(axis=2)[:, 0] >= (
            finger.radius + clearance)
        if finger.radius == 0:
            continue
        swept = _distance_to_segments(contour[None], path[:, :-1], np.diff(path, axis=1)).min(axis=2) < finger.radius
        with np.errstate(invalid="ignore"):
            elsewhere = ~(np.linalg.norm(contour[None] - grasp_point[:, f, None], axis=2) <= 2 * finger.radius)
        ok &= ~(swept & elsewhere).any(axis=1)
    return ok


def _distance_to_segments(points, starts, vectors) -> np.ndarray:
    """(p, n, k): distance of points (p | 1, n, 2) to segments starts + [0, 1] vectors (p | 1, k, 2)."""
    w = points[:, :, None, :] - starts[:, None, :, :]
    length2 = np.maximum(np.sum(vectors * vectors, axis=-1), np.finfo(float).tiny)[:, None, :]
    s = np.clip(np.einsum("pnki,pki->pnk", w, np.broadcast_to(vectors, (len(w), *vectors.shape[1:]))) / length2,
                0.0, 1.0)
    return np.linalg.norm(w - s[..., None] * vectors[:, None, :, :], axis=-1)


def grasp_epsilon(model: EFD, grasp_point, t, touching, *, friction: float = 0.5) -> np.ndarray:
    """(p,) float: Ferrari-Canny L1 epsilon of each pose's grasp points on the EFD contour.

    Wrenches are taken about the EFD locus (A0, C0) with torques divided by the
    contour's largest radius about it, so that poses of one plan compare
    (:func:`contourgrasp.quality.epsilon_many`); normals are the curve's inward normals.
    """
    normals = quality.contour_normals(model, np.where(touching, t, 0.0))
    valid = touching & np.isfinite(normals).all(axis=-1)
    rho = _cached(model, "rho", lambda: float(np.linalg.norm(_polygon(model)[1] - model.locus, axis=1).max()))
    return quality.epsilon_many(grasp_point, normals, valid, mu=friction, centre=model.locus, rho=rho)


def synthesize(
    contour_xy,
    hand: Hand,
    *,
    harmonics: int | Literal["adaptive"] = 4,
    curvature: CurvatureMode = "paper",
    xy_step: float = 0.05,
    yaw_step: float = math.radians(2.0),
    d_max=(0.15, 0.15),
    d_min: float = 0.015,
    top_k: int = 10,
    refine: bool = False,
    finger_thickness: bool = False,
    clearance: float = 0.0,
    friction: float = 0.5,
    require_closure: bool = False,
    quality_gain: float = 0.0,
) -> GraspPlan:
    """Plan a grasp on a contour: fit the EFD model, search the pose grid, return the best pose.

    Parameters
    ----------
    contour_xy : (n, 2) float
        Closed object contour in the image plane, meters, either orientation.
    hand : Hand
        (:func:`contourgrasp.synthesize` also takes a preset name or a TOML path.)
    harmonics : int or "adaptive"
        EFD harmonics (thesis: 4); ``"adaptive"`` chooses them per object
        (:func:`contourgrasp.efd.choose_harmonics` with its defaults).
    curvature : {"paper", "geometric"}
        Curvature flavour of the cost, see :mod:`contourgrasp.efd`.
    xy_step, yaw_step : float
        Grid resolution, m and rad (Table 4.1: 0.05 m, 2 deg).
    d_max : float or (2,) float
        D_max,x and D_max,y, m (Table 4.2: 0.15).
    d_min : float
        D_min, m (Table 4.2: 0.015).
    top_k : int
        Number of distinct ranked poses to keep in ``alternatives``.
    refine : bool
        After the grid, refine its best ``tol.REFINE_STARTS`` distinct poses continuously
        (:func:`refine_poses`, under the same constraints) and keep the better; ``refinement``
        reports the gain.
    finger_thickness, clearance, friction, require_closure, quality_gain
        The :class:`Safeguards` (all off: the thesis's problem). ``friction`` is
        also the mu of the plan's reported ``quality``.

    Returns
    -------
    GraspPlan

    Raises
    ------
    InputError
        Bad contour, hand or option (ContourError, HandFileError are subclasses).
    NoFeasibleGrasp
        No grid pose satisfies the constraints; the message says which one failed.

    Examples
    --------
    >>> from contourgrasp import example_contour, load_hand
    >>> plan = synthesize(example_contour("can"), load_hand("three-finger"), yaw_step=np.radians(10))
    >>> [f.missed for f in plan.fingers]
    [False, False, False]
    """
    if curvature not in efd_model.CURVATURE_MODES:
        raise InputError(f"curvature must be one of {efd_model.CURVATURE_MODES}, got {curvature!r}")
    if not isinstance(top_k, (int, np.integer)) or top_k < 1:
        raise InputError(f"top_k must be a positive integer, got {top_k!r}")
    if not isinstance(hand, Hand):
        raise InputError(f"hand must be a Hand, got {type(hand).__name__} (contourgrasp.synthesize loads names)")
    grid = SearchGrid(xy_step=xy_step, yaw_step=yaw_step, d_max=d_max, d_min=d_min)
    safeguards = Safeguards(finger_thickness=bool(finger_thickness), clearance=clearance, friction=friction,
                            require_closure=bool(require_closure), quality_gain=quality_gain)

    clock = time.perf_counter()
    contour = efd_model.clean_polygon(contour_xy)
    if harmonics == "adaptive":
        harmonics = efd_model.choose_harmonics(contour, validate=False)
    model = efd_model.fit(contour, harmonics, validate=False)
    fitted = time.perf_counter()
    screen = screen_grid(model, hand, grid, curvature=curvature)
    searched = time.perf_counter()
    if not screen.feasible.any():
        raise NoFeasibleGrasp(_diagnose(screen, hand, grid))
    result = _reevaluate_best(model, hand, screen, max(tol.REFINE_CANDIDATES, 4 * top_k), curvature, grid.d_min,
                              safeguards)
    ranked = _distinct_best(result, grid, top_k)
    exact = time.perf_counter()
    refinement, refined_at = None, exact
    if refine:
        grid_best = ranked[0]
        refined = refine_poses(model, hand, result.poses[ranked[:tol.REFINE_STARTS]],
                               step=(grid.xy_step, grid.yaw_step), d_max=grid.d_max,
                               curvature=curvature, d_min=grid.d_min, safeguards=safeguards)
        result = _concatenate(refined, result)
        ranked = _distinct_best(result, grid, top_k)
        refinement = Refinement(tuple(map(float, result.poses[len(refined.poses) + grid_best])),
                                float(result.cost[len(refined.poses) + grid_best]), float(result.cost[ranked[0]]))
        refined_at = time.perf_counter()
    best = ranked[0]
    fingers = _contacts(model, hand, result, best, curvature)
    grasp_quality = _quality(model, result, best, friction)
    timing = {
        "efd": 1e3 * (fitted - clock),
        "search": 1e3 * (searched - fitted),
        "exact": 1e3 * (exact - searched),
        "refine": 1e3 * (refined_at - exact),
        "total": 1e3 * (time.perf_counter() - clock),
    }
    return GraspPlan(
        pose=result.poses[best].copy(),
        cost=_cost(result, best),
        fingers=fingers,
        efd=model,
        hand=hand,
        contour=contour,
        curvature_mode=curvature,
        grid=grid,
        alternatives=tuple(Alternative(tuple(map(float, result.poses[i])), _cost(result, i)) for i in ranked),
        grid_size=len(screen.poses),
        feasible_poses=int(screen.feasible.sum()),
        timing_ms=timing,
        refinement=refinement,
        safeguards=safeguards,
        quality=grasp_quality,
    )


def _reevaluate_best(model, hand, screen: PoseEvaluation, n: int, curvature, d_min,
                     safeguards: Safeguards) -> PoseEvaluation:
    """Exact evaluation of the n cheapest screened poses, then 4n, 16n, ... until one is feasible."""
    feasible = np.flatnonzero(screen.feasible)
    order = feasible[np.argsort(screen.cost[feasible], kind="stable")]
    while True:
        result = evaluate_poses(model, hand, screen.poses[order[:n]], curvature=curvature, d_min=d_min,
                                safeguards=safeguards)
        if result.feasible.any():
            return result
        if n >= len(order):
            raise NoFeasibleGrasp(_diagnose_exact(result, safeguards))
        n *= 4


def _diagnose_exact(result: PoseEvaluation, safeguards: Safeguards) -> str:
    """Why no screened pose survives exact evaluation."""
    n = len(result.poses)
    if safeguards.finger_thickness and not result.clear.any():
        return (f"every one of the {n} poses that reach the object has a finger starting closer than its radius + "
                f"{safeguards.clearance} m to the object or striking it before its grasp point")
    if safeguards.require_closure and not (result.epsilon > 0).any():
        return f"none of the {n} poses that reach the object puts its grasp points in force closure"
    return ("every pose that reaches the object fails a constraint once its contacts are "
            "computed on the EFD curve itself rather than its polygon")


def _quality(model: EFD, result: PoseEvaluation, i: int, friction: float) -> quality.GraspQuality:
    """Force closure and L1 epsilon of pose i's grasp points (as :func:`grasp_epsilon` grades them).

    The evaluation's own epsilon when the safeguards needed it (same friction and convention), else computed.
    """
    eps = float(result.epsilon[i])
    if np.isnan(eps):
        eps = float(grasp_epsilon(model, result.grasp_point[i:i + 1], result.t[i:i + 1], result.touching[i:i + 1],
                                  friction=friction)[0])
    return quality.GraspQuality(force_closure=eps > 0, epsilon=eps, metric="L1", mu=float(friction))


def _cost(result: PoseEvaluation, i: int) -> Cost:
    return Cost(
        total=float(result.cost[i]),
        curvature=float(result.cost_curvature[i]),
        ratio=float(result.cost_ratio[i]),
        miss=float(result.cost_miss[i]),
        quality=float(result.cost_quality[i]),
    )


def _distinct_best(result: PoseEvaluation, grid: SearchGrid, k: int, block: int = 512) -> list[int]:
    """Indices of the k cheapest feasible poses, skipping grid neighbours of those already taken.

    Candidates are compared with each other ``block`` at a time, in increasing cost.
    """
    candidates = np.flatnonzero(result.feasible)
    order = candidates[np.argsort(result.cost[candidates], kind="stable")]
    taken: list[int] = []
    for start in range(0, len(order), block):
        rows = order[start:start + block]
        blocked = _neighbours(result.poses[rows], result.poses[taken], grid).any(axis=1)
        near = _neighbours(result.poses[rows], result.poses[rows], grid)
        for j, i in enumerate(rows.tolist()):
            if blocked[j]:
                continue
            taken.append(i)
            if len(taken) == k:
                return taken
            blocked |= near[j]
    return taken


def _neighbours(a: np.ndarray, b: np.ndarray, grid: SearchGrid) -> np.ndarray:
    """(len(a), len(b)) bool: poses a (n, 3) and b (m, 3) are grid neighbours in x, y and yaw at once."""
    delta = np.abs(a[:, None, :] - b[None, :, :])
    delta[..., 2] = np.minimum(delta[..., 2], 2 * math.pi - delta[..., 2])
    slack = 1.0 + 1e-6
    return (delta[..., :2] <= grid.xy_step * slack).all(axis=-1) & (delta[..., 2] <= grid.yaw_step * slack)


def _diagnose(result: PoseEvaluation, hand: Hand, grid: SearchGrid) -> str:
    """Name the first constraint that leaves no pose standing."""
    n = len(result.poses)
    if not result.starts_outside.any():
        return (f"no pose keeps every fingertip outside the object ({n} poses tried): "
                "the object is larger than the hand")
    reach = result.starts_outside & result.reaches
    if not reach.any():
        names = [f.name for f in hand.fingers if f.required]
        extra = f" including {', '.join(names)}" if names else ""
        return (f"no pose brings {hand.min_touching} fingers{extra} onto the object within their travel "
                f"({n} poses tried): the object is too small or too far from the hand's grasp region")
    return (f"every pose that reaches the object starts a fingertip closer than D_min = {grid.d_min} m "
            f"to its grasp point ({int(reach.sum())} poses reach it)")


def _contacts(model: EFD, hand: Hand, result: PoseEvaluation, i: int, mode: CurvatureMode):
    pose = result.poses[i]
    arrays = _hand_arrays(hand)
    starts = to_image(arrays.starts, pose)
    virtual = to_image(arrays.virtual_starts, pose)
    found = []
    for f, finger in enumerate(hand.fingers):
        if result.touching[i, f]:
            found.append((result.t[i, f], result.lam[i, f], result.grasp_point[i, f], 0.0))
        else:
            found.append(closest_approach(model, finger, pose))
    curvatures = efd_model.curvature(model, [t for t, *_ in found], mode)
    contacts = []
    for f, (finger, (t, lam, point, gap), kappa) in enumerate(zip(hand.fingers, found, curvatures.tolist())):
        missed = not result.touching[i, f]
        contacts.append(FingerContact(
            name=finger.name,
            grasp_point=np.asarray(point, dtype=float),
            t=float(t),
            lam=float(lam),
            curvature=kappa,
            concave=kappa < 0,
            distance=float(np.linalg.norm(virtual[f] - point)),
            start=starts[f],
            virtual_start=virtual[f],
            missed=missed,
            gap=float(gap),
        ))
    return tuple(contacts)


def closest_approach(model: EFD, finger, pose, samples: int = tol.EFD_SAMPLES, chords: int = 64):
    """Closest approach of a finger's trajectory to the EFD contour at a pose.

    The contour is its ``samples``-point polygon and the trajectory a
    ``chords``-chord polyline; the distance between the two polylines is exact
    (vertex-to-segment both ways).

    Returns
    -------
    t : float
        EFD parameter of the nearest contour point.
    lam : float
        Distance travelled to the nearest trajectory point, m.
    point : (2,) float
        The nearest contour point.
    gap : float
        Their distance, m.
    """
    lam = np.linspace(0.0, finger.travel, chords + 1)
    path = to_image(finger.points(lam), pose)
    t, contour = _polygon(model, samples)
    edges = np.roll(contour, -1, axis=0) - contour
    steps = np.diff(path, axis=0)
    # path vertices against contour edges, then contour vertices against path chords
    i, k, s1, gap1 = nearest_point_segment(path, contour, edges)
    k2, j, s2, gap2 = nearest_point_segment(contour, path[:-1], steps)
    if gap1 <= gap2:
        return float(t[k] + s1 * model.T / samples), float(lam[i]), contour[k] + s1 * edges[k], gap1
    return float(t[k2]), float(lam[j] + s2 * (lam[j + 1] - lam[j])), contour[k2], gap2
