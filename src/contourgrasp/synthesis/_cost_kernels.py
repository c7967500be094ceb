"""Compiled loops of the outer problem's cost and constraints (numba), per pose and finger.

:func:`contourgrasp.synthesis.cost.score` is their entry point and owns the equations.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def ratio_cost_row(distance, touching, beta, p, squared):
    """See eq 3.35: for pose p of (p, f) arrays, sum over touching i of beta_i (d_i - mean_{j != i, touching} d_j)^(2 or 1).

    Row p is indexed in place rather than sliced: a row view per pose costs more than the sum.
    """
    n = distance.shape[1]
    count, total = 0, 0.0
    for i in range(n):
        if touching[p, i]:
            count += 1
            total += distance[p, i]
    cost = 0.0
    if count < 2:
        return cost
    for i in range(n):
        if touching[p, i]:
            deviation = distance[p, i] - (total - distance[p, i]) / (count - 1)
            cost += beta[i] * (deviation * deviation if squared else deviation)
    return cost


@njit(cache=True)
def ratio_cost_rows(distance, touching, beta, squared):
    """(p,) float: :func:`ratio_cost_row` for every row of (p, f) arrays."""
    out = np.empty(distance.shape[0])
    for p in range(distance.shape[0]):
        out[p] = ratio_cost_row(distance, touching, beta, p, squared)
    return out


@njit(cache=True)
def score_poses(poses, n_yaw, touching, point, curvature, inside, starts, virtual, alpha, beta, required,
                min_touching, miss_penalty, d_min):
    """The loops of :func:`contourgrasp.synthesis.cost.score` (see eq 3.34, 3.41) for every pose.

    ``n_yaw``: the poses' yaws repeat with this period (pose p has the yaw of pose p % n_yaw, as on
    the grid, yaw fastest; ``len(poses)`` for any list), so the hand is rotated once per yaw.

    Returns
    -------
    distance, start_distance : (p, f) float
        Virtual start and start to grasp point, m (NaN where missed).
    outside, reaches, far_enough : (p,) bool
        No fingertip starts inside; enough and every required finger touch;
        every touching finger starts at least ``d_min`` from its grasp point.
    cost_curvature, cost_ratio, cost_miss : (p,) float
    """
    n_poses, n_f = touching.shape
    distance = np.full((n_poses, n_f), np.nan)
    start_distance = np.full((n_poses, n_f), np.nan)
    outside = np.ones(n_poses, np.bool_)
    reaches = np.ones(n_poses, np.bool_)
    far_enough = np.ones(n_poses, np.bool_)
    cost_curvature = np.zeros(n_poses)
    cost_ratio = np.zeros(n_poses)
    cost_miss = np.zeros(n_poses)
    rotated = np.empty((min(n_yaw, n_poses), n_f, 4))  # start and virtual start, per yaw and finger
    for p in range(rotated.shape[0]):
        c, s = math.cos(poses[p, 2]), math.sin(poses[p, 2])
        for f in range(n_f):
            rotated[p, f, 0] = c * starts[f, 0] - s * starts[f, 1]
            rotated[p, f, 1] = s * starts[f, 0] + c * starts[f, 1]
            rotated[p, f, 2] = c * virtual[f, 0] - s * virtual[f, 1]
            rotated[p, f, 3] = s * virtual[f, 0] + c * virtual[f, 1]
    for p in range(n_poses):
        r = p % n_yaw
        n_touching = 0
        for f in range(n_f):
            outside[p] &= not inside[p, f]
            if not touching[p, f]:
                reaches[p] &= not required[f]
                cost_miss[p] += miss_penalty
                continue
            n_touching += 1
            gx, gy = point[p, f, 0] - poses[p, 0], point[p, f, 1] - poses[p, 1]
            start_distance[p, f] = math.hypot(gx - rotated[r, f, 0], gy - rotated[r, f, 1])
            distance[p, f] = math.hypot(gx - rotated[r, f, 2], gy - rotated[r, f, 3])
            far_enough[p] &= start_distance[p, f] >= d_min
            cost_curvature[p] += alpha[f] * curvature[p, f]
        reaches[p] &= n_touching >= min_touching
        if n_touching > 1:
            cost_ratio[p] = ratio_cost_row(distance, touching, beta, p, True)
    return distance, start_distance, outside, reaches, far_enough, cost_curvature, cost_ratio, cost_miss


@njit(cache=True)
def contact_imbalance(coefficients, period, t, touching, min_normal):
    """(p,) float: :func:`contourgrasp.quality.imbalance` of each pose's contacts on the EFD contour, fused.

    Per pose p and touching finger f: the contour's inward unit normal at ``t[p, f]`` (its tangent by eq
    3.6, turned by +90 deg, as :func:`contourgrasp.quality.contour_normals`), skipped where the tangent
    is shorter than ``min_normal``; then ``|sum of normals| / count`` (1 without a contact). The numpy path
    builds (p, f, harmonics) arrays and checks them; this is the search's screen, on thousands of poses
    per attempt, and equals it to rounding (tested).

    Parameters
    ----------
    coefficients : (harmonics, 4) float
        The EFD's (a, b, c, d) per harmonic.
    period : float
        The EFD's T.
    t : (p, f) float
    touching : (p, f) bool
    min_normal : float
    """
    n_poses, n_f = t.shape
    out = np.ones(n_poses)
    w0 = 2.0 * np.pi / period
    for p in range(n_poses):
        count, sx, sy = 0, 0.0, 0.0
        for f in range(n_f):
            if not touching[p, f]:
                continue
            dx, dy = 0.0, 0.0
            c1, s1 = math.cos(w0 * t[p, f]), math.sin(w0 * t[p, f])
            c, s = c1, s1  # cos and sin of (h + 1) w0 t, by angle addition: two calls per contact, not 2 per harmonic
            for h in range(coefficients.shape[0]):
                w = w0 * (h + 1)  # d/dt (a cos wt + b sin wt) = w (b cos wt - a sin wt)
                dx += w * (coefficients[h, 1] * c - coefficients[h, 0] * s)
                dy += w * (coefficients[h, 3] * c - coefficients[h, 2] * s)
                c, s = c * c1 - s * s1, s * c1 + c * s1
            length = math.hypot(dx, dy)
            if not length > min_normal:
                continue
            count += 1
            sx, sy = sx - dy / length, sy + dx / length
        if count:
            out[p] = math.hypot(sx, sy) / count
    return out


@njit(cache=True)
def centring_distances(poses, n_yaw, centre, locus):
    """(p,) float: :func:`contourgrasp.synthesis.cost.centring_distance`'s loop, the pinch centre rotated once per yaw.

    ``n_yaw``: the poses' yaws repeat with this period (as :func:`score_poses`'s); ``centre`` (2,) the
    hand's pinch centre in the hand frame, ``locus`` (2,) the object's centre in the image plane.
    """
    n_poses = poses.shape[0]
    out = np.empty(n_poses)
    placed = np.empty((min(n_yaw, n_poses), 2))  # R(yaw) pinch centre, per yaw
    for r in range(placed.shape[0]):
        c, s = math.cos(poses[r, 2]), math.sin(poses[r, 2])
        placed[r, 0], placed[r, 1] = c * centre[0] - s * centre[1], s * centre[0] + c * centre[1]
    for p in range(n_poses):
        r = p % n_yaw
        out[p] = math.hypot(locus[0] - poses[p, 0] - placed[r, 0], locus[1] - poses[p, 1] - placed[r, 1])
    return out
