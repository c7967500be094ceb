"""The outer problem (thesis 3.4.2): the search for the best hand pose, and why none may be feasible.

A grid over x, y within ``d_max`` of the contour's locus (A0, C0) (eq 3.39-3.40,
:class:`~contourgrasp.synthesis.grid.SearchGrid`) and yaw over [0, 2 pi). A pose is feasible when

* no fingertip starts inside the contour (the hand comes down from above),
* every touching finger starts at least ``d_min`` from its grasp point
  (eq 3.41, distance as in eq 3.36 with lambda_virt = 0),
* every ``required`` finger touches, and at least ``hand.min_touching`` do.

Its cost is that of :mod:`contourgrasp.synthesis.cost`. :func:`search` screens every grid pose
(:func:`~contourgrasp.synthesis.grid.screen_reaching`: the first touches of all, the cost of those enough
fingers reach), then solves the cheapest candidates exactly
(:func:`~contourgrasp.synthesis.evaluate_poses`: polygon contacts compiled, then Newton onto the
curve). Optionally (``refine=True``), :func:`~contourgrasp.synthesis.refine_poses` leaves the grid:
a bounded compass search in (x, y, yaw) from the best distinct grid poses, on the exact cost and
under the same constraints.
"""

from __future__ import annotations

import math
import re
import time
from dataclasses import replace
from functools import partial
from typing import Callable, Literal

import numpy as np

from .. import quality
from .. import tolerances as tol
from .. import validation as check
from ..contour import CURVATURE_MODES, EFD, CurvatureMode, choose_harmonics, clean_polygon, efd, grow_polygon
from ..errors import HandError, NoFeasibleGrasp, PlannerError
from ..hand import Hand, to_image
from ._cost_kernels import contact_imbalance
from ._derived import hand_arrays
from .cost import PoseEvaluation, distance
from .descent import (Descent, DescentCheck, blocked_by_obstacles, body_names, check_candidates, descent_feasible,
                      descends_clear)
from .evaluate import concatenate, evaluate_poses
from .grid import SearchGrid, distinct_best, screen_reaching
from .inner import closest_approach
from .plan import Alternative, Cost, FingerContact, GraspPlan, Refinement
from .refine import refine_poses
from .options import SearchOptions
from .safeguards import Safeguards, grasp_epsilon, grasp_imbalance


def search(
    contour_xy,
    hand: Hand,
    options: SearchOptions = SearchOptions(),
    *,
    balance_required: bool = False,
    balanced_alternative: Callable[[], GraspPlan] | None = None,
    low_object: bool = False,
    descent: Descent | None = None,
    exclude: Callable[[np.ndarray], np.ndarray] | None = None,
) -> GraspPlan:
    """Plan a grasp on a contour: fit the EFD model, search the pose grid, return the best pose.

    Implements eq 3.32: min over the grid's poses rho of the cost f (eq 3.34) of the inner
    problem's grasp points (eq 3.22), subject to the constraints g(rho) <= 0 (eq 3.39-3.41).

    Parameters
    ----------
    contour_xy : (n, 2) float
        Closed object contour in the image plane, meters, either orientation.
    hand : Hand
        (:func:`contourgrasp.synthesize` also takes a preset name or a TOML path.)
    options : SearchOptions
        The EFD model, the grid, the safeguards and the rules (their defaults: the thesis's problem).
        With ``refine`` the grid's best ``tol.REFINE_STARTS`` distinct poses are refined continuously
        and the better kept; ``refinement`` reports the gain. ``safeguards.friction`` is also the mu
        of the plan's reported ``quality``. A balanced squeeze (``safeguards.max_imbalance``) is
        preferred, not required: when no pose meets it (with the small-object rule's fewer fingers
        too), the search is repeated without it, and the plan's notes say so.
    balance_required : bool
        Required instead: no pose balanced within ``max_imbalance`` is no feasible grasp (how
        :func:`contourgrasp.pipeline.plan_frame` searches the cross-section, whose plan it takes only
        when balanced).
    balanced_alternative : callable, optional
        Called, once, when no pose balances the squeeze (with the small-object rule's fewer fingers
        too), before the search gives the balance up (or, with ``balance_required``, fails): the
        plan it returns is the search's; if it raises NoFeasibleGrasp, the search goes on. Not
        called while the fingertips cannot reach the object as points: the outline grown by their
        radius is balanced first. How :func:`contourgrasp.pipeline.plan_frame` turns to the
        object's cross-section where its outline seen has no balanced pose.
    low_object : bool
        The low-object rule (the caller judges the object low: :class:`SceneOptions`'s
        ``low_objects``). First plan a pinch: the thumb against one finger (``tolerances.SMALL_OBJECT_TOUCHING``
        touching, or the hand's required fingers), the fingertips as balls (the outline grown by the
        smallest finger ``radius``, as below), and no ``miss_penalty`` for the fingers that close on air,
        which would otherwise prefer poses where they touch too; only where no such pose is feasible,
        the search as without it. Our reading of why: a one-DoF hand lifts a flat object lying on the table
        between thumb and index, the balls' sides meeting its edges, while the other fingers, arriving on
        it first or pressing on its top, push it away (docs/hand3d.md, "The 3-D hand in the plan").
    descent : Descent, optional
        The scene's height map and the grasp height: a pose is feasible only if the open hand,
        lowered along the approach axis until its lowest fingertip is at ``descent.tip_height``,
        keeps every finger's body and the palm ``descent.margin`` above the map
        (:mod:`~contourgrasp.synthesis.descent`; the hand must be 3-D). Checked exactly on the
        candidates in increasing cost, after their inner problem, until one passes. Without it:
        the thesis's 2-D problem.
    exclude : callable, optional
        Poses (n, 3) -> (n,) bool: the poses not to plan, such as those near grasps that failed
        (:meth:`~contourgrasp.synthesis.memory.GraspMemory.excluded`); they are infeasible, on the grid
        and after refinement.

    Notes
    -----
    The small-object rule (``options.small_objects``): when no pose satisfies the constraints with the
    hand's ``min_touching`` fingers, search again with fewer touching fingers, down to
    ``tolerances.SMALL_OBJECT_TOUCHING`` (the thumb, or the hand's required fingers, against one other). A
    one-DoF power grasp of a small object closes the whole hand, but only the thumb and the fingers
    opposite it reach the object. With ``max_imbalance`` the same rule plans the thumb against the one or
    two fingers that balance it on objects of any size (four fingers along one side outpush one thumb).
    The plan's ``hand`` has the ``min_touching`` it was planned with. Last, when even the fewest fingers
    cannot reach the object within their travel, the fingertips are taken as what they are, balls of the
    fingers' ``radius``: a ball touches the object when its centre meets the outline grown by its radius
    (:func:`~contourgrasp.contour.grow_polygon`), so the search is repeated on that outline, grown by the
    smallest radius (a finger of radius 0 is a point: no growth). The thesis's point fingertips cannot
    close on an object smaller than the gap their travels leave (35 mm between the five-finger hand's
    thumb and index); the balls of a real hand do. The plan's ``grown`` says so, and its notes.

    Returns
    -------
    GraspPlan

    Raises
    ------
    InputError
        Bad contour (ContourError), hand (HandError) or option (PlannerError, naming it; a grid
        of more than ``tolerances.MAX_GRID_POSES`` poses is refused before any work).
    NoFeasibleGrasp
        No grid pose satisfies the constraints; the message says which one failed.

    Examples
    --------
    >>> from contourgrasp import example_contour, load_hand
    >>> options = SearchOptions(grid=SearchGrid(yaw_step=np.radians(10)))
    >>> plan = search(example_contour("can"), load_hand("three-finger"), options)
    >>> [f.missed for f in plan.fingers]
    [False, False, False]
    """
    if not isinstance(options, SearchOptions):
        raise PlannerError(f"options must be a contourgrasp.synthesis.SearchOptions, got {type(options).__name__}")
    if not isinstance(hand, Hand):
        raise HandError(f"hand must be a Hand, got {type(hand).__name__} (contourgrasp.synthesize loads names)")
    if descent is not None:
        if not isinstance(descent, Descent):
            raise PlannerError(f"descent must be a contourgrasp.synthesis.Descent, got {type(descent).__name__}")
        body_names(hand)  # refuses a hand without 3-D geometry
    safeguards = options.safeguards.for_hand(hand)

    clock = time.perf_counter()
    preferred = not check.flag("balance_required", balance_required, error=PlannerError)
    contour = clean_polygon(contour_xy)
    if balanced_alternative is not None and not callable(balanced_alternative):
        raise PlannerError(f"balanced_alternative must be callable, got {type(balanced_alternative).__name__}")
    elsewhere = _Elsewhere(balanced_alternative)
    if exclude is not None and not callable(exclude):
        raise PlannerError(f"exclude must be callable, got {type(exclude).__name__}")
    outline = partial(_search_outline, hand=hand, options=replace(options, safeguards=safeguards), descent=descent,
                      clock=clock, fallback=preferred, alternative=elsewhere, exclude=exclude)
    try:
        return _search_rules(contour, hand, options, outline, elsewhere, low_object)
    except NoFeasibleGrasp as err:
        raise NoFeasibleGrasp(_led(err.reason)) from None


def _search_rules(contour, hand: Hand, options: SearchOptions, outline, elsewhere: _Elsewhere,
                  low_object) -> GraspPlan:
    """:func:`search` on the outline seen, after the low-object rule's pinch; the fingertips as balls last."""
    radius = min(f.radius for f in hand.fingers)
    if check.flag("low_object", low_object, error=PlannerError) and radius > 0:
        pinch = replace(hand, min_touching=_fewest_touching(hand), miss_penalty=0.0)
        try:
            plan = outline(_grown(contour, radius), hand=pinch)
            return plan if plan is elsewhere.plan else _as_balls(plan, contour, radius, NOTE_LOW)
        except NoFeasibleGrasp:
            pass
    try:
        return outline(contour)
    except _OutOfReach as points:
        if not options.small_objects or radius <= 0:
            raise NoFeasibleGrasp(points.reason) from None
        try:
            plan = outline(_grown(contour, radius))
        except NoFeasibleGrasp as balls:
            why = balls.fewest if isinstance(balls, _OutOfReach) else balls.reason
            raise NoFeasibleGrasp(f"{points.reason}; with the fingertips as balls (the outline grown by "
                                  f"{1000 * radius:.1f} mm): {why}") from None
    return plan if plan is elsewhere.plan else _as_balls(plan, contour, radius, NOTE_BALLS)


def _led(reason: str) -> str:
    """A failure's reason led by its cause in one sentence: the last attempt's (the most relaxed search, whose failure
    is the plan's), then the attempts, each without that cause repeated."""
    attempts = re.split(r"; (?=with the |without the )", reason)
    last = attempts[-1] if len(attempts) == 1 else attempts[-1].split(": ", 1)[-1]
    cause = (last.split("): ", 1)[1] if "): " in last else last).split(" (the same ")[0].split("; ")[0]
    tried = reason.replace(f"): {cause}", ")")
    return cause if tried == cause else f"{cause}. Tried: {tried}"


def _grown(contour, radius: float) -> np.ndarray:
    """The outline a fingertip ball's centre meets: ``contour`` grown by ``radius``, cleaned (the one gate every
    outline passes before its fit: growth can triple a jagged outline's vertices)."""
    return clean_polygon(grow_polygon(contour, radius), check_units=False)


def _as_balls(plan: GraspPlan, contour, radius: float, note: str) -> GraspPlan:
    """A plan made on the outline grown by ``radius``, reported on the outline seen, with its ``note``."""
    notes = plan.search_notes + (note.format(radius=1000 * radius),)
    return replace(plan, contour=contour, grown=radius, search_notes=notes)


def _fewest_touching(hand: Hand) -> int:
    """The small-object rule's fewest touching fingers: the thumb against one (or the required fingers)."""
    return min(hand.min_touching, max(tol.SMALL_OBJECT_TOUCHING, sum(f.required for f in hand.fingers)))


def _search_outline(contour, *, hand: Hand, options: SearchOptions, descent: Descent | None, clock: float,
                    fallback: bool = True, alternative: _Elsewhere, exclude=None) -> GraspPlan:
    """:func:`search` on one cleaned outline: fit, screen (less the poses ``exclude`` names), then each attempt of
    the small-object rule and the squeeze's balance in turn, then the ``alternative``'s plan, then (``fallback``)
    without the balance. Raises :class:`_OutOfReach` when, with the fewest touching fingers tried, no pose brings
    them onto the object within their travel."""
    harmonics, grid, safeguards = options.harmonics, options.grid, options.safeguards
    if harmonics == "adaptive":
        harmonics = choose_harmonics(contour, validate=False)
    model = efd.fit(contour, harmonics, validate=False)
    fitted = time.perf_counter()
    fewest = _fewest_touching(hand) if options.small_objects else hand.min_touching
    counts = range(hand.min_touching, fewest - 1, -1)
    screen, touch_counts, any_outside = screen_reaching(model, replace(hand, min_touching=fewest), grid,
                                                        curvature=options.curvature,
                                                        centring_gain=safeguards.centring_gain)
    screen = _without(screen, exclude)
    share = np.full(len(screen.poses), np.nan)  # the squeeze's balance per screened pose, filled as attempts need it
    searched = time.perf_counter()
    errors = []

    def attempt(guards: Safeguards) -> GraspPlan | None:
        """The plan of the first of the small-object rule's counts that has one under ``guards``; None when none
        has (each failure kept in ``errors``, its reason worked out only if every attempt fails: _Unexplained)."""
        for touching in counts:
            try:
                return _search_fitted(model, contour, replace(hand, min_touching=touching),
                                      _needing(screen, touch_counts, touching), grid, guards, descent,
                                      curvature=options.curvature, top_k=options.top_k, refine=options.refine,
                                      times=(clock, fitted, searched), share=share, any_outside=any_outside,
                                      exclude=exclude)
            except NoFeasibleGrasp as err:  # kept without its traceback: through this frame that would make a
                errors.append(err.with_traceback(None))  # cycle holding every screen until the gc runs
        return None

    if (plan := attempt(safeguards)) is not None:
        return plan
    if safeguards.balances:  # a balanced squeeze is preferred: elsewhere's, else (fallback) the thesis's best pose
        if (plan := alternative.after(errors[-1])) is not None:
            return plan
        if fallback and (plan := attempt(replace(safeguards, max_imbalance=1.0))) is not None:
            note = NOTE_UNBALANCED.format(limit=safeguards.max_imbalance, share=plan.quality.imbalance)
            return replace(plan, safeguards=safeguards, search_notes=(note,))
    reason = _no_grasp(errors, len(counts), fewest)
    if isinstance(errors[len(counts) - 1], _OutOfReach):
        raise _OutOfReach(reason, fewest=str(errors[len(counts) - 1]))
    raise NoFeasibleGrasp(reason)


class _Elsewhere:
    """A :func:`search`'s ``balanced_alternative``, called at most once; ``plan`` is what it returned, if any."""

    def __init__(self, plan_elsewhere: Callable[[], GraspPlan] | None):
        self._plan_elsewhere, self._called, self.plan = plan_elsewhere, plan_elsewhere is None, None

    def after(self, fewest: NoFeasibleGrasp) -> GraspPlan | None:
        """Its plan once no pose balances, ``fewest`` being why the fewest fingers tried found none; None
        when it has none (or raised NoFeasibleGrasp), and when they are out of reach: the outline grown
        by the fingertips' radius is then searched, and balanced first, as its points' cannot be."""
        if not self._called and not isinstance(fewest, _OutOfReach):
            self._called = True
            try:
                self.plan = self._plan_elsewhere()
            except NoFeasibleGrasp:
                pass
        return self.plan


class _OutOfReach(NoFeasibleGrasp):
    """No pose brings the fingers asked for onto the object within their travel (the object is too small);
    ``fewest`` is the reason with the fewest fingers tried."""

    def __init__(self, reason: str, *, fewest: str | None = None):
        super().__init__(reason)
        self.fewest = reason if fewest is None else fewest


#: The note of a plan the small-object rule made with the fingertips as balls.
NOTE_BALLS = ("no pose brings the fingertips, as points, onto the object within their travel: planned on its "
              "outline grown by {radius:.1f} mm, the fingers' smallest radius (grasp points are the tips' centres "
              "when their balls first touch it)")


#: The note of a plan made by the low-object rule.
NOTE_LOW = ("a low object: planned as a pinch, the thumb against one finger, with the fingertips as balls (the "
            "outline grown by {radius:.1f} mm, the fingers' smallest radius)")


#: The note of a plan whose squeeze no pose could balance within ``max_imbalance``.
NOTE_UNBALANCED = ("no pose balances the squeeze within max_imbalance = {limit:g}: planned without it; with every "
                   "finger pushing equally hard, {share:.2f} of their force is left to friction")


def _no_grasp(errors: list[NoFeasibleGrasp], counts: int, fewest: int) -> str:
    """The first attempt's reason, the small-object rule's last, and the search without the squeeze's balance.

    A later attempt that failed for the first one's reason is named, not its reason repeated.
    """
    errors = [str(error) for error in errors]
    later = []
    if counts > 1:
        later.append((f"with the small-object rule, down to {fewest} touching fingers", errors[counts - 1]))
    if len(errors) > counts:
        later.append(("without the squeeze's balance", errors[-1]))
    same = [attempt for attempt, reason in later if reason == errors[0]]
    message = errors[0] + (f" (the same {', and '.join(same)})" if same else "")
    return "; ".join([message] + [f"{attempt}: {reason}" for attempt, reason in later if reason != errors[0]])


#: Why a search found nothing when the poses it was asked to leave out were all it had.
EXCLUDED = "every pose that would satisfy the constraints lies near a grasp that failed (the memory's exclusion)"


def _without(poses: PoseEvaluation, exclude, *, only: bool = True) -> PoseEvaluation:
    """``poses`` with those ``exclude`` names infeasible (and not reaching); unchanged without ``exclude``.

    Raises NoFeasibleGrasp (:data:`EXCLUDED`) when that leaves none of the feasible ones and they are the
    ``only`` poses searched (the grid's screen; not a refinement's, added to it)."""
    if exclude is None or not len(poses.poses):
        return poses
    keep = ~np.asarray(exclude(poses.poses), dtype=bool)
    if only and poses.feasible.any() and not (poses.feasible & keep).any():
        raise NoFeasibleGrasp(EXCLUDED)
    return replace(poses, reaches=poses.reaches & keep, feasible=poses.feasible & keep)


def _needing(screen: PoseEvaluation, counts: np.ndarray, touching: int) -> PoseEvaluation:
    """The screen of the fewest touching fingers, feasible only where at least ``touching`` fingers touch.

    Nothing else in the screen depends on ``min_touching``: one screen serves every count the
    small-object rule tries. ``counts``: the touching fingers per pose, counted once per screen.
    """
    enough = counts >= touching
    return replace(screen, reaches=screen.reaches & enough, feasible=screen.feasible & enough)


def _search_fitted(model: EFD, contour, hand: Hand, screen: PoseEvaluation, grid: SearchGrid,
                   safeguards: Safeguards, descent: Descent | None, *, curvature, top_k, refine,
                   times, share, any_outside: bool, exclude=None) -> GraspPlan:
    """:func:`search` for one ``hand.min_touching`` on a fitted model and its screened grid.

    ``screen``: :func:`~contourgrasp.synthesis.grid.screen_reaching`'s poses (with ``any_outside``, its
    answer for the whole grid).

    ``times``: the clock at the search's start, after the fit and after the screen (``timing_ms``'s
    ``exact`` includes earlier counts' exact evaluations). ``share``: see :func:`_screened_share`.
    """
    clock, fitted, searched = times
    if not screen.feasible.any():
        raise _no_pose(screen, hand, grid, any_outside)
    result = _reevaluate_best(model, hand, screen, max(tol.REFINE_CANDIDATES, 4 * top_k), curvature, grid.d_min,
                              safeguards, descent, share)
    ranked = distinct_best(result, grid, top_k)
    exact = time.perf_counter()
    refinement, refined_at = None, exact
    if refine:
        grid_best = ranked[0]
        refined = refine_poses(model, hand, result.poses[ranked[:tol.REFINE_STARTS]],
                               step=(grid.xy_step, grid.yaw_step), d_max=grid.d_max,
                               curvature=curvature, d_min=grid.d_min, safeguards=safeguards)
        refined = _without(refined, exclude, only=False)
        if descent is not None:
            passed, _, _ = check_candidates(hand, descent, refined.poses, _by_cost(refined), refined.lam,
                                            refined.touching)
            refined = replace(refined, feasible=refined.feasible & passed)
        result = concatenate(refined, result)
        ranked = distinct_best(result, grid, top_k)
        refinement = Refinement(tuple(map(float, result.poses[len(refined.poses) + grid_best])),
                                float(result.cost[len(refined.poses) + grid_best]), float(result.cost[ranked[0]]))
        refined_at = time.perf_counter()
    best = ranked[0]
    descended = None if descent is None else _descended(hand, descent, result.poses[best:best + 1])
    fingers = _contacts(model, hand, result, best, curvature)
    grasp_quality = _quality(model, result, best, safeguards.friction)
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
        grid_size=math.prod(grid.shape),
        feasible_poses=int(screen.feasible.sum()),
        timing_ms=timing,
        refinement=refinement,
        safeguards=safeguards,
        quality=grasp_quality,
        descent=descended,
    )


def _reevaluate_best(model, hand, screen: PoseEvaluation, n: int, curvature, d_min,
                     safeguards: Safeguards, descent: Descent | None = None, share=None) -> PoseEvaluation:
    """Exact evaluation of the n cheapest screened poses, then 4n, 16n, ... until one is feasible.

    With ``descent``, feasible also means the open hand descends clear (checked in increasing cost,
    each pose once, at most ``tolerances.MAX_DESCENT_POSES`` in all). With the squeeze's balance, only
    poses whose screened contacts balance within ``tolerances.IMBALANCE_SCREEN`` of it are evaluated
    (``share``: see :func:`_screened_share`; default none known).
    """
    feasible = np.flatnonzero(screen.feasible)
    if safeguards.balances:  # screened on the polygon's contacts: the exact check below decides
        known = np.full(len(screen.poses), np.nan) if share is None else share
        share = _screened_share(model, screen, known, feasible)
        near = share <= safeguards.max_imbalance + tol.IMBALANCE_SCREEN
        if not near.any():
            raise NoFeasibleGrasp(_unbalanced(len(feasible), float(share.min(initial=1.0)), safeguards))
        feasible = feasible[near]
    order = feasible[np.argsort(screen.cost[feasible], kind="stable")]
    checked, descended, last, result = 0, 0, None, None
    while True:
        done = 0 if result is None else len(result.poses)  # each pose evaluated once: the new ones appended
        more = evaluate_poses(model, hand, screen.poses[order[done:n]], curvature=curvature, d_min=d_min,
                              safeguards=safeguards)
        result = more if result is None else concatenate(result, more)
        if descent is not None and result.feasible.any():
            candidates = _by_cost(result)
            candidates = candidates[candidates >= checked]  # poses [0, checked) were checked before
            passed, _, check = check_candidates(hand, descent, result.poses, candidates, result.lam, result.touching)
            passed[:checked] = False
            last = check if check is not None and not descends_clear(descent, last) else last
            checked, descended = min(n, len(order)), descended + min(len(candidates), tol.MAX_DESCENT_POSES)
            result = replace(result, feasible=result.feasible & passed)
        if result.feasible.any():
            return result
        if n >= len(order) or descended >= tol.MAX_DESCENT_POSES:
            if last is not None:
                raise _Unexplained(partial(_diagnose_descent, hand, last, descended, descent))
            raise NoFeasibleGrasp(_diagnose_exact(result, safeguards))
        n *= 4


def _screened_share(model, screen: PoseEvaluation, share: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """The squeeze's imbalance of the screened poses ``poses`` (indices) on their polygon contacts.

    ``share`` (one per screened pose, NaN where not yet known) is filled in where missing: one
    screen serves every attempt of a search, each on a subset of its poses, so each pose's share
    is computed once, by the compiled :func:`~contourgrasp.synthesis._cost_kernels.contact_imbalance`
    (:func:`~contourgrasp.synthesis.grasp_imbalance` to rounding).
    """
    missing = poses[np.isnan(share[poses])]
    share[missing] = contact_imbalance(model.coefficients, model.T, screen.t[missing], screen.touching[missing],
                                       tol.MIN_NORMAL)
    return share[poses]


class _Unexplained(NoFeasibleGrasp):
    """An attempt of :func:`search` that failed, its reason worked out when first asked for.

    The descent's diagnosis checks the poses again without the scene's obstacles (a new map, a few
    milliseconds); a search whose later attempt plans never needs it.
    """

    def __init__(self, explain):
        RuntimeError.__init__(self)
        self._explain, self._reason = explain, None

    @property
    def reason(self) -> str:
        if self._reason is None:
            self._reason = self._explain()
        return self._reason

    def __str__(self) -> str:
        return self.reason


def _descended(hand: Hand, descent: Descent, pose) -> DescentCheck:
    """The descent check of one pose at its grasp height (raised from ``descent.tip_height`` where it must be)."""
    _, tip, _ = check_candidates(hand, descent, pose, [0])
    return descent_feasible(hand, descent.heights, pose, tip, margin=descent.margin)


def _by_cost(result: PoseEvaluation) -> np.ndarray:
    """Indices of the feasible poses of an evaluation, in increasing cost."""
    feasible = np.flatnonzero(result.feasible)
    return feasible[np.argsort(result.cost[feasible], kind="stable")]


def _diagnose_descent(hand: Hand, check: DescentCheck, n: int, descent: Descent) -> str:
    """Why every pose that reaches the object fails the descent check, with the best one's reason."""
    if not check.exact:  # the search stopped walking a refused pose at its first strike: walk it all now
        check = descent_feasible(hand, descent.heights, check.poses, check.tip_height, margin=check.margin)
    best = int(np.argmax(check.clearance.min(axis=1)))
    limit = (f"at a grasp height of {1000 * descent.tip_height:.0f} mm" if descent.max_tip_height == descent.tip_height
             else f"at any grasp height from {1000 * descent.tip_height:.0f} to {1000 * descent.max_tip_height:.0f} mm")
    if descends_clear(descent, check):  # a closing check refused it
        return _diagnose_closing(descent, n)
    if blocked_by_obstacles(hand, descent, check):
        return (f"blocked by a neighbouring object or the bin wall: every one of the {n} poses checked that reach "
                f"the object would strike another raised region of the scene while the open hand descends {limit}; "
                f"at the clearest, {check.reason(best)}")
    return (f"every one of the {n} poses checked that reach the object would strike the scene while the open "
            f"hand descends {limit}; at the clearest, {check.reason(best)}")


def _diagnose_closing(descent: Descent, n: int) -> str:
    """Why poses whose open hand descends clear were refused: a closing finger's chain (:mod:`.sweep`)."""
    closing = descent.closing_map is not None
    hits = "run a finger into a neighbouring object or the bin wall" if closing else ""
    early = "meet the object with a finger's link before its tip" if descent.sweep else ""
    what = " or ".join(w for w in (hits, early) if w)
    prefix = "blocked by a neighbouring object or the bin wall: " if closing and not descent.sweep else ""
    return (f"{prefix}every one of the {n} poses checked that reach the object and descend clear would {what} "
            "while the hand closes")


def _diagnose_exact(result: PoseEvaluation, safeguards: Safeguards) -> str:
    """Why no screened pose survives exact evaluation."""
    n = len(result.poses)
    if safeguards.finger_thickness and not result.clear.any():
        return (f"every one of the {n} poses that reach the object has a finger starting closer than its radius + "
                f"{safeguards.clearance} m to the object or striking it before its grasp point")
    if safeguards.require_closure and not (result.epsilon > 0).any():
        return f"none of the {n} poses that reach the object puts its grasp points in force closure"
    balanced = (result.epsilon > 0) if safeguards.require_closure else np.ones(n, bool)
    if safeguards.balances and not (balanced & (result.imbalance <= safeguards.max_imbalance)).any():
        return _unbalanced(n, float(np.nanmin(np.where(balanced, result.imbalance, np.nan), initial=1.0)), safeguards)
    return ("every pose that reaches the object fails a constraint once its contacts are "
            "computed on the EFD curve itself rather than its polygon")


def _unbalanced(n: int, best: float, safeguards: Safeguards) -> str:
    return (f"none of the {n} poses that reach the object balances the squeeze: with every finger pushing "
            f"equally hard, the least net force left is {best:.2f} of their sum (max_imbalance = "
            f"{safeguards.max_imbalance:g})")


def _quality(model: EFD, result: PoseEvaluation, i: int, friction: float) -> quality.GraspQuality:
    """Force closure, L1 epsilon and imbalance of pose i's grasp points (as the safeguards grade them).

    The evaluation's own values when the safeguards needed them (same friction and convention), else computed.
    """
    rows = slice(i, i + 1)
    eps, share = float(result.epsilon[i]), float(result.imbalance[i])
    if np.isnan(eps):
        eps = float(grasp_epsilon(model, result.grasp_point[rows], result.t[rows], result.touching[rows],
                                  friction=friction)[0])
    if np.isnan(share):
        share = float(grasp_imbalance(model, result.t[rows], result.touching[rows])[0])
    return quality.GraspQuality(force_closure=eps > 0, epsilon=eps, metric="L1", mu=float(friction), imbalance=share)


def _cost(result: PoseEvaluation, i: int) -> Cost:
    return Cost(
        total=float(result.cost[i]),
        curvature=float(result.cost_curvature[i]),
        ratio=float(result.cost_ratio[i]),
        miss=float(result.cost_miss[i]),
        quality=float(result.cost_quality[i]),
        centring=float(result.cost_centring[i]),
    )


def _no_pose(result: PoseEvaluation, hand: Hand, grid: SearchGrid, any_outside: bool) -> NoFeasibleGrasp:
    """The failure naming the first constraint that leaves no pose of the ``grid`` standing (:class:`_OutOfReach`
    for reach); ``result``: its poses where enough fingers touch, ``any_outside``: some pose of it starts outside."""
    n = math.prod(grid.shape)
    if not any_outside:
        return NoFeasibleGrasp(f"no pose keeps every fingertip outside the object ({n} poses tried): "
                               "the object is larger than the hand")
    reach = result.starts_outside & result.reaches
    if not reach.any():
        names = [f.name for f in hand.fingers if f.required]
        extra = f" including {', '.join(names)}" if names else ""
        return _OutOfReach(f"no pose brings {hand.min_touching} fingers{extra} onto the object within their "
                           f"travel ({n} poses tried): the object is too small or too far from the hand's grasp region")
    return NoFeasibleGrasp(f"every pose that reaches the object starts a fingertip closer than D_min = {grid.d_min} m "
                           f"to its grasp point ({int(reach.sum())} poses reach it)")


def _contacts(model: EFD, hand: Hand, result: PoseEvaluation, i: int, mode: CurvatureMode):
    """The :class:`FingerContact` of every finger at pose i; a missed finger's closest approach."""
    pose = result.poses[i]
    arrays = hand_arrays(hand)
    starts = to_image(arrays.starts, pose)
    virtual = to_image(arrays.virtual_starts, pose)
    found = []
    for f, finger in enumerate(hand.fingers):
        if result.touching[i, f]:
            found.append((result.t[i, f], result.lam[i, f], result.grasp_point[i, f], 0.0))
        else:
            found.append(closest_approach(model, finger, pose))
    curvatures = efd.curvature(model, [t for t, *_ in found], mode)
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
            distance=distance(virtual[f], point),
            start=starts[f],
            virtual_start=virtual[f],
            missed=missed,
            gap=float(gap),
        ))
    return tuple(contacts)
