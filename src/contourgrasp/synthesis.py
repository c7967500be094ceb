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
(contacts on the EFD polygon, curvature from a table); :func:`evaluate_poses`
then solves the cheapest candidates exactly (numpy, Newton onto the curve).
There is no Python loop per pose.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Literal

import numpy as np

from . import efd as efd_model
from . import tolerances as tol
from .efd import EFD, CurvatureMode
from .errors import InputError, NoFeasibleGrasp
from ._kernels import grid_first_touch, ratio_cost_rows, score_poses
from .hand import Hand, HandSegments, rotation, to_image


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
        x, y, yaw = np.meshgrid(*self.axes(locus), indexing="ij")
        return np.stack([x.ravel(), y.ravel(), yaw.ravel()], axis=1)


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
    feasible : (p,) bool
    cost_curvature, cost_ratio, cost_miss, cost : (p,) float
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
    feasible: np.ndarray
    cost_curvature: np.ndarray
    cost_ratio: np.ndarray
    cost_miss: np.ndarray
    cost: np.ndarray


@dataclass(frozen=True)
class Cost:
    """The cost of a pose (eq 3.34) and its parts."""

    total: float
    curvature: float
    ratio: float
    miss: float


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
        Wall time per stage, milliseconds.
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
    >>> float(ratio_cost(d, np.ones((1, 3), bool), np.ones(3), form="linear"))
    0.0
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

    Returns
    -------
    PoseEvaluation
    """
    poses = np.atleast_2d(np.asarray(poses, dtype=float))
    contour_t, contour = efd_model.sample(model, samples)
    segments = hand.segments()
    n_f = len(hand.fingers)
    chunks = np.array_split(poses, max(1, math.ceil(len(poses) / tol.POSE_CHUNK)))
    parts = [first_touch(contour, contour_t, model.T, segments, n_f, chunk) for chunk in chunks]
    lam, t, point, start_inside = (np.concatenate(arrays) for arrays in zip(*parts))
    touching = np.isfinite(lam)
    t, lam, point = _refine(model, hand, poses, t, lam, point, touching, model.T / samples)
    curv = np.full(lam.shape, np.nan)
    curv[touching] = efd_model.curvature(model, t[touching], curvature)
    return _assemble(hand, poses, touching, lam, t, point, curv, start_inside, d_min)


def screen_grid(
    model: EFD, hand: Hand, grid: SearchGrid, *, curvature: CurvatureMode = "paper", samples: int = tol.EFD_SAMPLES
) -> PoseEvaluation:
    """Evaluate every pose of a grid fast, to within the EFD polygon's accuracy.

    Contacts stay on the sampled polygon (``samples`` points) and curvature is
    interpolated from a table, so costs differ from :func:`evaluate_poses` by
    about 1e-4 relative; :func:`synthesize` re-evaluates the best candidates
    exactly. The inner loop is the compiled :func:`contourgrasp._kernels.grid_first_touch`.
    """
    xs, ys, yaws = grid.axes(model.locus)
    contour_t, contour = efd_model.sample(model, samples)
    seg = hand.segments()
    n_f = len(hand.fingers)
    first = np.zeros(len(seg.finger), bool)
    first[np.searchsorted(seg.finger, np.arange(n_f))] = True
    table_t = np.linspace(0.0, model.T, tol.CURVATURE_TABLE, endpoint=False)
    lam, t, point, curv, start_inside = grid_first_touch(
        contour, contour_t, model.T, efd_model.curvature(model, table_t, curvature), xs, ys, yaws,
        seg.start, seg.end - seg.start, seg.finger, seg.lam0, first, n_f, tol.PARALLEL,
    )
    touching = np.isfinite(lam)
    poses = grid.poses(model.locus)
    return _assemble(hand, poses, touching, np.where(touching, lam, np.nan), t, point, curv, start_inside, d_min=grid.d_min)


def _refine(model: EFD, hand: Hand, poses, t, lam, point, touching, t_step, iterations: int = 4):
    """Newton on r(t) - p(lam) = 0 from the polygon's contacts; keeps the polygon's answer where it fails."""
    t, lam, point = t.copy(), lam.copy(), point.copy()
    for f, finger in enumerate(hand.fingers):
        rows = np.flatnonzero(touching[:, f])
        if rows.size == 0:
            continue
        R = rotation(poses[rows, 2])
        xy = poses[rows, :2]
        t_f, lam_f = t[rows, f], lam[rows, f]
        for _ in range(iterations):
            r, dr = efd_model.evaluate(model, t_f), efd_model.evaluate(model, t_f, 1)
            p = xy + np.einsum("pij,pj->pi", R, finger.points(lam_f))
            dp = np.einsum("pij,pj->pi", R, finger.tangent(lam_f))
            F = r - p
            det = -dr[:, 0] * dp[:, 1] + dp[:, 0] * dr[:, 1]
            det = np.where(np.abs(det) > 1e-12, det, np.inf)
            t_f = t_f + (F[:, 0] * dp[:, 1] - F[:, 1] * dp[:, 0]) / det
            lam_f = lam_f + (dr[:, 1] * F[:, 0] - dr[:, 0] * F[:, 1]) / det
        residual = np.linalg.norm(
            efd_model.evaluate(model, t_f) - xy - np.einsum("pij,pj->pi", R, finger.points(lam_f)), axis=1
        )
        ok = (residual < 1e-9) & (lam_f >= 0) & (lam_f <= finger.travel) & (np.abs(t_f - t[rows, f]) < 2 * t_step)
        rows = rows[ok]
        t[rows, f] = t_f[ok] % model.T
        lam[rows, f] = lam_f[ok]
        point[rows, f] = efd_model.evaluate(model, t_f[ok])
    return t, lam, point


def _assemble(hand: Hand, poses, touching, lam, t, point, curv, start_inside, d_min) -> PoseEvaluation:
    """Constraints 3.39-3.41 and the cost of eq 3.34 from the inner problem's solutions."""
    (distance, start_distance, outside, reaches, far_enough, cost_curvature, cost_ratio, cost_miss) = score_poses(
        poses, touching, point, curv, start_inside, hand.starts, hand.virtual_starts,
        np.array([f.alpha for f in hand.fingers], dtype=float), np.array([f.beta for f in hand.fingers], dtype=float),
        np.array([f.required for f in hand.fingers]), hand.min_touching, float(hand.miss_penalty), float(d_min),
    )
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
        feasible=outside & reaches & far_enough,
        cost_curvature=cost_curvature,
        cost_ratio=cost_ratio,
        cost_miss=cost_miss,
        cost=cost_curvature + cost_ratio + cost_miss,
    )


def synthesize(
    contour_xy,
    hand: Hand,
    *,
    harmonics: int = 4,
    curvature: CurvatureMode = "paper",
    xy_step: float = 0.05,
    yaw_step: float = math.radians(2.0),
    d_max=(0.15, 0.15),
    d_min: float = 0.015,
    top_k: int = 10,
) -> GraspPlan:
    """Plan a grasp on a contour: fit the EFD model, search the pose grid, return the best pose.

    Parameters
    ----------
    contour_xy : (n, 2) float
        Closed object contour in the image plane, meters, either orientation.
    hand : Hand
        (:func:`contourgrasp.synthesize` also takes a preset name or a TOML path.)
    harmonics : int
        EFD harmonics (thesis: 4).
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

    clock = time.perf_counter()
    contour = efd_model.clean_polygon(contour_xy)
    model = efd_model.fit(contour, harmonics, validate=False)
    fitted = time.perf_counter()
    screen = screen_grid(model, hand, grid, curvature=curvature)
    searched = time.perf_counter()
    if not screen.feasible.any():
        raise NoFeasibleGrasp(_diagnose(screen, hand, grid))
    result = _reevaluate_best(model, hand, screen, max(tol.REFINE_CANDIDATES, 4 * top_k), curvature, grid.d_min)
    ranked = _distinct_best(result, grid, top_k)
    best = ranked[0]
    fingers = _contacts(model, hand, result, best, curvature)
    timing = {
        "efd": 1e3 * (fitted - clock),
        "search": 1e3 * (searched - fitted),
        "refine": 1e3 * (time.perf_counter() - searched),
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
    )


def _reevaluate_best(model, hand, screen: PoseEvaluation, n: int, curvature, d_min) -> PoseEvaluation:
    """Exact evaluation of the n cheapest screened poses (all feasible ones if none of those stays feasible)."""
    feasible = np.flatnonzero(screen.feasible)
    order = feasible[np.argsort(screen.cost[feasible], kind="stable")]
    for candidates in (order[:n], order):
        result = evaluate_poses(model, hand, screen.poses[candidates], curvature=curvature, d_min=d_min)
        if result.feasible.any():
            return result
    raise NoFeasibleGrasp("every pose that reaches the object fails a constraint once its contacts are "
                          "computed on the EFD curve itself rather than its polygon")


def _cost(result: PoseEvaluation, i: int) -> Cost:
    return Cost(
        total=float(result.cost[i]),
        curvature=float(result.cost_curvature[i]),
        ratio=float(result.cost_ratio[i]),
        miss=float(result.cost_miss[i]),
    )


def _distinct_best(result: PoseEvaluation, grid: SearchGrid, k: int) -> list[int]:
    """Indices of the k cheapest feasible poses, skipping grid neighbours of those already taken."""
    candidates = np.flatnonzero(result.feasible)
    order = candidates[np.argsort(result.cost[candidates], kind="stable")]
    taken: list[int] = []
    slack = 1.0 + 1e-6
    for i in order:
        if taken:
            delta = np.abs(result.poses[taken] - result.poses[i])
            delta[:, 2] = np.minimum(delta[:, 2], 2 * math.pi - delta[:, 2])
            near = (delta[:, :2] <= grid.xy_step * slack).all(axis=1) & (delta[:, 2] <= grid.yaw_step * slack)
            if near.any():
                continue
        taken.append(int(i))
        if len(taken) == k:
            break
    return taken


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
    starts = to_image(hand.starts, pose)
    virtual = to_image(hand.virtual_starts, pose)
    contacts = []
    for f, finger in enumerate(hand.fingers):
        missed = not result.touching[i, f]
        if missed:
            t, lam, point, gap = closest_approach(model, finger, pose)
        else:
            t, lam, point, gap = result.t[i, f], result.lam[i, f], result.grasp_point[i, f], 0.0
        kappa = float(efd_model.curvature(model, [t], mode)[0])
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
    t, contour = efd_model.sample(model, samples)
    edges = np.roll(contour, -1, axis=0) - contour
    steps = np.diff(path, axis=0)
    # path vertices against contour edges, then contour vertices against path chords
    s1, gap1 = _point_segment(path, contour, edges)
    s2, gap2 = _point_segment(contour, path[:-1], steps)
    if gap1.min() <= gap2.min():
        i, k = np.unravel_index(np.argmin(gap1), gap1.shape)
        point = contour[k] + s1[i, k] * edges[k]
        return float(t[k] + s1[i, k] * model.T / samples), float(lam[i]), point, float(gap1[i, k])
    k, j = np.unravel_index(np.argmin(gap2), gap2.shape)
    return float(t[k]), float(lam[j] + s2[k, j] * (lam[j + 1] - lam[j])), contour[k], float(gap2[k, j])


def _point_segment(points, starts, vectors):
    """Fraction along each segment of the nearest point, and the distance: both (n_points, n_segments)."""
    w = points[:, None, :] - starts[None, :, :]
    s = np.clip(np.einsum("nsi,si->ns", w, vectors) / np.sum(vectors * vectors, axis=1), 0.0, 1.0)
    return s, np.linalg.norm(w - s[..., None] * vectors[None], axis=2)
