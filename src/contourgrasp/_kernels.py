"""Compiled inner loop of the grid search (numba): first touch of every finger at every grid pose.

The numpy formulation (:func:`contourgrasp.synthesis.first_touch`) tests every
trajectory chord against every contour edge. A profile of the dense grid
(346 k poses) shows that this (poses x chords x edges) product is the whole
cost. Here the grid's structure removes most of it: at a fixed yaw a chord has
a fixed direction, so an edge can only be crossed by chords whose lateral
offset (perpendicular to the direction) falls within the edge's lateral
extent. Edges are bucketed by lateral offset once per (yaw, chord), and each
grid position tests only the few edges in its bucket. The arithmetic of the
test is the same as the numpy version.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

BUCKETS = 64


@njit(cache=True)
def _buckets(lateral, span, offsets, members):
    """Fill CSR lists (offsets (BUCKETS + 1,), members) of the edges overlapping each lateral bucket.

    ``span`` (m, 2) int is scratch space. Returns the lowest lateral offset and the bucket width.
    """
    m = lateral.shape[0]
    lo_all, hi_all = lateral.min(), lateral.max()
    width = (hi_all - lo_all) / BUCKETS + 1e-15
    offsets[:] = 0
    for k in range(m):
        a, b = lateral[k], lateral[(k + 1) % m]
        span[k, 0] = min(int((min(a, b) - lo_all) / width), BUCKETS - 1)
        span[k, 1] = min(int((max(a, b) - lo_all) / width), BUCKETS - 1)
        for j in range(span[k, 0], span[k, 1] + 1):
            offsets[j + 1] += 1
    for j in range(BUCKETS):
        offsets[j + 1] += offsets[j]
    fill = offsets[:-1].copy()
    for k in range(m):
        for j in range(span[k, 0], span[k, 1] + 1):
            members[fill[j]] = k
            fill[j] += 1
    return lo_all, width


@njit(cache=True)
def grid_first_touch(q, q_t, period, curvature_table, xs, ys, yaws, seg_start, seg_dir, seg_finger, seg_lam0,
                     seg_first, n_fingers, parallel_eps):
    """First contact of every finger at every pose of an (x, y, yaw) grid.

    Parameters
    ----------
    q : (m, 2) float
        Closed contour polygon (EFD samples).
    q_t : (m,) float
        EFD parameter of each polygon vertex, increasing; ``period`` follows the last.
    period : float
    curvature_table : (n,) float
        Curvature at n evenly spaced parameters over [0, period), interpolated at the contacts.
    xs, ys, yaws : (nx,), (ny,), (nyaw,) float
        Grid axes; pose index p = (ix * ny + iy) * nyaw + iyaw.
    seg_start, seg_dir : (s, 2) float
        Trajectory chords in the hand frame: start and end - start.
    seg_finger : (s,) int
    seg_lam0 : (s,) float
        Distance travelled at each chord's start.
    seg_first : (s,) bool
        The chord is its finger's first (its half-line decides start-inside).
    n_fingers : int
    parallel_eps : float

    Returns
    -------
    lam : (p, f) float
        Distance travelled at first contact, inf where missed.
    t : (p, f) float
        EFD parameter of the contact, NaN where missed.
    point : (p, f, 2) float
        Contact point, NaN where missed.
    curvature : (p, f) float
        Curvature at the contact, NaN where missed.
    inside : (p, f) bool
        The fingertip starts inside the contour.
    """
    m = q.shape[0]
    nx, ny, nyaw = xs.shape[0], ys.shape[0], yaws.shape[0]
    n_poses = nx * ny * nyaw
    lam = np.full((n_poses, n_fingers), np.inf)
    t = np.full((n_poses, n_fingers), np.nan)
    point = np.full((n_poses, n_fingers, 2), np.nan)
    curvature = np.full((n_poses, n_fingers), np.nan)
    inside = np.zeros((n_poses, n_fingers), np.bool_)
    n_table = curvature_table.shape[0]
    e = np.empty((m, 2))
    for k in range(m):
        e[k, 0] = q[(k + 1) % m, 0] - q[k, 0]
        e[k, 1] = q[(k + 1) % m, 1] - q[k, 1]
    lateral = np.empty(m)
    span = np.empty((m, 2), np.int64)
    offsets = np.empty(BUCKETS + 1, np.int64)
    members = np.empty(m * BUCKETS, np.int64)
    for iyaw in range(nyaw):
        c, s = math.cos(yaws[iyaw]), math.sin(yaws[iyaw])
        for sg in range(seg_start.shape[0]):
            dx = c * seg_dir[sg, 0] - s * seg_dir[sg, 1]
            dy = s * seg_dir[sg, 0] + c * seg_dir[sg, 1]
            ox = c * seg_start[sg, 0] - s * seg_start[sg, 1]
            oy = s * seg_start[sg, 0] + c * seg_start[sg, 1]
            length = math.hypot(dx, dy)
            nxl, nyl = -dy / length, dx / length
            for k in range(m):
                lateral[k] = q[k, 0] * nxl + q[k, 1] * nyl
            lo, width = _buckets(lateral, span, offsets, members)
            f = seg_finger[sg]
            for ix in range(nx):
                px = xs[ix] + ox
                for iy in range(ny):
                    py = ys[iy] + oy
                    b = int(math.floor((px * nxl + py * nyl - lo) / width))
                    if b < 0 or b >= BUCKETS:
                        continue
                    p = (ix * ny + iy) * nyaw + iyaw
                    parity = False
                    for j in range(offsets[b], offsets[b + 1]):
                        k = members[j]
                        denom = dx * e[k, 1] - dy * e[k, 0]
                        if abs(denom) <= parallel_eps:
                            continue
                        wx, wy = q[k, 0] - px, q[k, 1] - py
                        v = (wx * dy - wy * dx) / denom
                        if v < 0.0 or v >= 1.0:
                            continue
                        u = (wx * e[k, 1] - wy * e[k, 0]) / denom
                        if u < 0.0:
                            continue
                        parity = not parity
                        if u <= 1.0:
                            hit = seg_lam0[sg] + u * length
                            if hit < lam[p, f]:
                                lam[p, f] = hit
                                t_next = q_t[k + 1] if k + 1 < m else period
                                t[p, f] = q_t[k] + v * (t_next - q_t[k])
                                point[p, f, 0] = q[k, 0] + v * e[k, 0]
                                point[p, f, 1] = q[k, 1] + v * e[k, 1]
                                x = t[p, f] / period * n_table
                                i = min(int(x), n_table - 1)
                                w = x - i
                                curvature[p, f] = (1 - w) * curvature_table[i] + w * curvature_table[(i + 1) % n_table]
                    if seg_first[sg]:
                        inside[p, f] = parity
    return lam, t, point, curvature, inside


@njit(cache=True)
def ratio_cost_row(distance, touching, beta, squared):
    """Eq 3.35 for one pose: sum over touching i of beta_i (d_i - mean_{j != i, touching} d_j)^(2 or 1)."""
    n = distance.shape[0]
    count, total = 0, 0.0
    for i in range(n):
        if touching[i]:
            count += 1
            total += distance[i]
    cost = 0.0
    if count < 2:
        return cost
    for i in range(n):
        if touching[i]:
            deviation = distance[i] - (total - distance[i]) / (count - 1)
            cost += beta[i] * (deviation * deviation if squared else deviation)
    return cost


@njit(cache=True)
def ratio_cost_rows(distance, touching, beta, squared):
    """(p,) float: :func:`ratio_cost_row` for every row of (p, f) arrays."""
    out = np.empty(distance.shape[0])
    for p in range(distance.shape[0]):
        out[p] = ratio_cost_row(distance[p], touching[p], beta, squared)
    return out


@njit(cache=True)
def score_poses(poses, touching, point, curvature, inside, starts, virtual, alpha, beta, required,
                min_touching, miss_penalty, d_min):
    """Constraints 3.39-3.41 and the cost of eq 3.34 for every pose.

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
    for p in range(n_poses):
        c, s = math.cos(poses[p, 2]), math.sin(poses[p, 2])
        n_touching = 0
        for f in range(n_f):
            outside[p] &= not inside[p, f]
            if not touching[p, f]:
                reaches[p] &= not required[f]
                cost_miss[p] += miss_penalty
                continue
            n_touching += 1
            gx, gy = point[p, f, 0] - poses[p, 0], point[p, f, 1] - poses[p, 1]
            sx, sy = c * starts[f, 0] - s * starts[f, 1], s * starts[f, 0] + c * starts[f, 1]
            vx, vy = c * virtual[f, 0] - s * virtual[f, 1], s * virtual[f, 0] + c * virtual[f, 1]
            start_distance[p, f] = math.hypot(gx - sx, gy - sy)
            distance[p, f] = math.hypot(gx - vx, gy - vy)
            far_enough[p] &= start_distance[p, f] >= d_min
            cost_curvature[p] += alpha[f] * curvature[p, f]
        reaches[p] &= n_touching >= min_touching
        cost_ratio[p] = ratio_cost_row(distance[p], touching[p], beta, True)
    return distance, start_distance, outside, reaches, far_enough, cost_curvature, cost_ratio, cost_miss
