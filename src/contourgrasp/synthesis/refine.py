"""Continuous refinement of grid poses: a bounded compass search on the exact cost."""

from __future__ import annotations

import math

import numpy as np

from .. import tolerances as tol
from .. import validation as check
from ..contour import EFD
from ..errors import PlannerError
from ..hand import Hand
from .evaluate import evaluate_poses, replace_rows
from .cost import PoseEvaluation


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

    The grid of the outer problem (see eq 3.39-3.40) only visits multiples of its steps; the optimum
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

    Raises
    ------
    PlannerError
        Naming the option that is malformed.
    """
    poses = np.atleast_2d(np.asarray(poses, dtype=float))
    steps = np.asarray(step, dtype=float)
    if steps.shape != (2,) or not np.all(np.isfinite(steps) & (steps > 0)):
        raise PlannerError(f"step must be two positive numbers (xy, yaw), got {step!r}")
    check.integer("halvings", halvings, 0, error=PlannerError)
    check.integer("rounds", rounds, 0, maximum=tol.REFINE_MAX_ROUNDS, error=PlannerError)
    scale = steps[[0, 0, 1]]
    lower, upper = poses - scale, poses + scale
    if d_max is not None:
        box = np.broadcast_to(np.asarray(d_max, dtype=float), (2,))
        if not np.all(np.isfinite(box) & (box >= 0)):
            raise PlannerError(f"d_max must be non-negative, got {d_max!r}")
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
        current = replace_rows(current, active[moves], tried, (np.arange(len(active)) * len(directions) + pick)[moves])
        s[active] = np.where(moves, np.minimum(2 * s[active], 0.5), s[active] / 2)
    np.mod(current.poses[:, 2], 2 * math.pi, out=current.poses[:, 2])  # the box may reach below yaw 0
    return current
