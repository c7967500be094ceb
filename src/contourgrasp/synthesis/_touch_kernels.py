"""Compiled first-touch kernels (numba) for a list of poses, and their shared chord-edge arithmetic.

:func:`pose_first_touch` is the inner problem of :func:`contourgrasp.synthesis.inner.first_touch`
compiled, for the few poses of the exact re-evaluation and the refinement; the grid's kernel
(:mod:`contourgrasp.synthesis._grid_kernels`) shares its chord-edge test, :func:`crossing`, and
how contacts are recorded, so both give the same numbers.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def crossing(px, py, dx, dy, q, e, k, parallel_eps):
    """Chord p + u d against edge k, q[k] + v e[k]: (u, v), u = -1 when parallel or v outside [0, 1)."""
    denom = dx * e[k, 1] - dy * e[k, 0]
    if abs(denom) <= parallel_eps:
        return -1.0, 0.0
    wx, wy = q[k, 0] - px, q[k, 1] - py
    v = (wx * dy - wy * dx) / denom
    if v < 0.0 or v >= 1.0:
        return -1.0, 0.0
    return (wx * e[k, 1] - wy * e[k, 0]) / denom, v


@njit(cache=True)
def record(lam, t, point, p, f, hit, k, v, q, e, q_t, period):
    """Keep the contact at ``hit`` (distance travelled) on edge k, fraction v, if it is the first so far."""
    if hit < lam[p, f]:
        m = q.shape[0]
        lam[p, f] = hit
        t_next = q_t[k + 1] if k + 1 < m else period
        t[p, f] = q_t[k] + v * (t_next - q_t[k])
        point[p, f, 0] = q[k, 0] + v * e[k, 0]
        point[p, f, 1] = q[k, 1] + v * e[k, 1]


@njit(cache=True)
def edges(q):
    """(m, 2) float: edge vectors q[k + 1] - q[k] of the closed polygon."""
    m = q.shape[0]
    e = np.empty((m, 2))
    for k in range(m):
        e[k, 0] = q[(k + 1) % m, 0] - q[k, 0]
        e[k, 1] = q[(k + 1) % m, 1] - q[k, 1]
    return e


@njit(cache=True)
def outputs(n_poses, n_fingers):
    """lam (inf), t (NaN), point (NaN), inside (False) for (n_poses, n_fingers): nothing touched yet."""
    return (np.full((n_poses, n_fingers), np.inf), np.full((n_poses, n_fingers), np.nan),
            np.full((n_poses, n_fingers, 2), np.nan), np.zeros((n_poses, n_fingers), np.bool_))




@njit(cache=True)
def apart(a, d, lo, hi, pad):
    """The interval from a to a + d lies outside [lo - pad, hi + pad] (one axis of a chord's box and the contour's)."""
    return min(a, a + d) > hi + pad or max(a, a + d) < lo - pad




@njit(cache=True)
def pose_first_touch(q, q_t, period, poses, seg_start, seg_dir, seg_finger, seg_lam0, seg_first, n_fingers,
                     parallel_eps):
    """First contact of every finger at each of a list of poses: every chord against every edge.

    The arithmetic of :func:`contourgrasp.synthesis._grid_kernels.grid_first_touch` without its buckets, for few poses (exact
    re-evaluation, continuous refinement). A finger's later chords are skipped once it has touched,
    and every chord whose box misses the contour's (as in the grid kernel, a first chord's
    start is then outside).

    Parameters
    ----------
    q, q_t, period, seg_start, seg_dir, seg_finger, seg_lam0, seg_first, n_fingers, parallel_eps
        As for :func:`contourgrasp.synthesis._grid_kernels.grid_first_touch`.
    poses : (p, 3) float
        (x, y, yaw).

    Returns
    -------
    lam, t, point, inside
        As for :func:`contourgrasp.synthesis._grid_kernels.grid_first_touch`.
    """
    m = q.shape[0]
    lam, t, point, inside = outputs(poses.shape[0], n_fingers)
    e = edges(q)
    x0, y0, x1, y1 = q[:, 0].min(), q[:, 1].min(), q[:, 0].max(), q[:, 1].max()
    pad = 1e-9 * max(x1 - x0, y1 - y0)
    for p in range(poses.shape[0]):
        c, s = math.cos(poses[p, 2]), math.sin(poses[p, 2])
        for sg in range(seg_start.shape[0]):
            f = seg_finger[sg]
            if not seg_first[sg] and lam[p, f] <= seg_lam0[sg]:
                continue
            dx = c * seg_dir[sg, 0] - s * seg_dir[sg, 1]
            dy = s * seg_dir[sg, 0] + c * seg_dir[sg, 1]
            px = poses[p, 0] + c * seg_start[sg, 0] - s * seg_start[sg, 1]
            py = poses[p, 1] + s * seg_start[sg, 0] + c * seg_start[sg, 1]
            if apart(px, dx, x0, x1, pad) or apart(py, dy, y0, y1, pad):
                continue
            length = math.hypot(dx, dy)
            parity = False
            for k in range(m):
                u, v = crossing(px, py, dx, dy, q, e, k, parallel_eps)
                if u < 0.0:
                    continue
                parity = not parity
                if u <= 1.0:
                    record(lam, t, point, p, f, seg_lam0[sg] + u * length, k, v, q, e, q_t, period)
            if seg_first[sg]:
                inside[p, f] = parity
    return lam, t, point, inside


@njit(cache=True)
def nearest_point_segment(points, starts, vectors):
    """The point nearest to a segment: of points (n, 2) and segments starts + [0, 1] vectors (s, 2).

    Returns
    -------
    i, k : int
        The point and the segment (the first pair in row-major order on ties).
    s : float
        Fraction along segment k of its point nearest to point i.
    distance : float
    """
    best, best_i, best_k, best_s = np.inf, 0, 0, 0.0
    bound = np.inf  # squared distances above it are farther than best despite rounding: no hypot for them
    for k in range(starts.shape[0]):
        length2 = vectors[k, 0] ** 2 + vectors[k, 1] ** 2
        for i in range(points.shape[0]):
            wx, wy = points[i, 0] - starts[k, 0], points[i, 1] - starts[k, 1]
            s = min(max((wx * vectors[k, 0] + wy * vectors[k, 1]) / length2, 0.0), 1.0) if length2 > 0 else 0.0
            gx, gy = wx - s * vectors[k, 0], wy - s * vectors[k, 1]
            if gx * gx + gy * gy > bound:
                continue
            d = math.hypot(gx, gy)
            if d < best or (d == best and (i < best_i or (i == best_i and k < best_k))):
                best, best_i, best_k, best_s = d, i, k, s
                bound = (best * (1.0 + 1e-12)) ** 2
    return best_i, best_k, best_s, best


