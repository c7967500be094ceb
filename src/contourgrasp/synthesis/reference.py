"""A faithful reference of the thesis's nested optimisation (section 3.4, 4.1.1) — the yardstick.

For every pose of the grid and every finger, the inner problem (eq 3.22-3.31)

    min_{t, lam} 1/2 |r(t) - p(lam)|^2   s.t.  0 <= lam <= F,  t in a period

is solved by a local bounded solver (scipy's L-BFGS-B with the analytic
gradient), started from the first-touch guess: the first of 201 points along
the finger's path that lies inside the EFD curve (drawn with 1024 samples),
or, when none does, the closest approach. A finger touches when the solver
drives the distance below ``TOUCH`` (it converges onto the crossing); the
outer cost (eq 3.34, squared ratio as in the library) and constraints
(3.39-3.41, starts outside, required fingers, min_touching) are then
evaluated pose by pose in plain Python. Slow on purpose: it is what the
library must agree with.

Not imported by :mod:`contourgrasp.synthesis`: ``benchmarks/search_speed.py`` measures the search's
speed against it, and ``tests/synthesis/test_reference.py`` checks the search's answers against it.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.path import Path as MplPath
from scipy.optimize import minimize

from ..contour import clean_polygon, efd
from ..hand import Hand, to_image
from .grid import SearchGrid

TOUCH = 1e-7  # m: the solver's residual distance below which a finger touches
MARCH = 201
CURVE_SAMPLES = 1024


def solve_inner(model: efd.EFD, finger, pose, outline: MplPath, curve: np.ndarray, curve_t: np.ndarray):
    """One finger at one pose: (touching, t, lam, grasp_point)."""
    lam_grid = np.linspace(0.0, finger.travel, MARCH)
    path = to_image(finger.points(lam_grid), pose)
    inside = np.flatnonzero(outline.contains_points(path))
    if inside.size:
        i = inside[0]
        j = int(np.argmin(np.linalg.norm(curve - path[i], axis=1)))
    else:
        gaps = np.linalg.norm(path[:, None] - curve[None], axis=2)
        i, j = np.unravel_index(np.argmin(gaps), gaps.shape)
    x0 = np.array([curve_t[j], lam_grid[i]])
    R = np.array([[math.cos(pose[2]), -math.sin(pose[2])], [math.sin(pose[2]), math.cos(pose[2])]])

    def h(x):
        t, lam = x
        d = efd.evaluate(model, [t])[0] - to_image(finger.points(lam), pose)[0]
        dr = efd.evaluate(model, [t], 1)[0]
        dp = R @ finger.tangent(lam)[0]
        return 0.5 * d @ d, np.array([d @ dr, -(d @ dp)])

    bounds = [(x0[0] - model.T / 2, x0[0] + model.T / 2), (0.0, finger.travel)]
    res = minimize(h, x0, jac=True, method="L-BFGS-B", bounds=bounds, options={"ftol": 1e-20, "gtol": 1e-14})
    t, lam = res.x
    touching = math.sqrt(2 * res.fun) < TOUCH
    return touching, t % model.T, lam, efd.evaluate(model, [t])[0]


def reference_search(contour_xy, hand: Hand, *, harmonics=4, curvature="paper", xy_step=0.05,
                     yaw_step=math.radians(2), d_max=(0.15, 0.15), d_min=0.015):
    """Best pose and cost of the nested optimisation on the grid: (pose (3,), cost, n_feasible)."""
    model = efd.fit(clean_polygon(contour_xy), harmonics)
    curve_t, curve = efd.sample(model, CURVE_SAMPLES)
    outline = MplPath(curve)
    grid = SearchGrid(xy_step=xy_step, yaw_step=yaw_step, d_max=d_max, d_min=d_min)
    best_pose, best_cost, feasible = None, math.inf, 0
    for pose in grid.poses(model.locus):
        cost = pose_cost(model, hand, pose, outline, curve, curve_t, curvature, d_min)
        if cost is None:
            continue
        feasible += 1
        if cost < best_cost:
            best_pose, best_cost = pose, cost
    return best_pose, best_cost, feasible


def pose_cost(model, hand, pose, outline, curve, curve_t, curvature, d_min):
    """Outer cost of eq 3.34 at one pose, or None when a constraint fails."""
    starts = to_image(hand.starts, pose)
    if outline.contains_points(starts).any():
        return None
    virtual = to_image(hand.virtual_starts, pose)
    contacts = [solve_inner(model, f, pose, outline, curve, curve_t) for f in hand.fingers]
    touching = [c[0] for c in contacts]
    if sum(touching) < hand.min_touching or any(f.required and not ok for f, ok in zip(hand.fingers, touching)):
        return None
    cost, dist = 0.0, {}
    for i, (finger, (ok, t, _lam, point)) in enumerate(zip(hand.fingers, contacts)):
        if not ok:
            cost += hand.miss_penalty
            continue
        if np.linalg.norm(starts[i] - point) < d_min:
            return None
        cost += finger.alpha * efd.curvature(model, [t], curvature)[0]
        dist[i] = np.linalg.norm(virtual[i] - point)
    for i, d in dist.items():
        others = [dist[j] for j in dist if j != i]
        if others:
            cost += hand.fingers[i].beta * (d - sum(others) / len(others)) ** 2
    return cost
