"""Compiled inner loops of the search (numba): first touch of every finger at many poses.

The numpy formulation (:func:`contourgrasp.synthesis.first_touch`) tests every
trajectory chord against every contour edge. A profile of the dense grid
(346 k poses) shows that this (poses x chords x edges) product is the whole
cost. Here the grid's structure removes most of it: at a fixed yaw a chord has
a fixed direction, so an edge can only be crossed by chords whose lateral
offset (perpendicular to the direction) falls within the edge's lateral
extent. A finger's first chord (whose half-line also decides whether the
finger starts inside) looks its edges up in lateral buckets built once per
(yaw, chord), over groups of consecutive edges so that the buckets cost little
on the thesis grid (49 positions per yaw). An arc's later chords are short and
needed only where the finger has not touched yet: they look edges up in square
cells built once per grid, and most find none. The arithmetic of the test is
the same as the numpy version; :func:`pose_first_touch` applies it to a list
of poses (exact re-evaluation, refinement) without buckets.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Lateral buckets per (yaw, first chord).
BUCKETS = 32

#: Consecutive contour edges bucketed as one: the buckets are rebuilt for every (yaw, first chord) and
#: serve only a few grid positions on the thesis grid, so building them must cost little.
GROUP = 4

#: Cells per axis of the grid that short (later) chords look their edges up in, at most.
MAX_CELLS = 128


@njit(cache=True)
def _lateral_buckets(q, nx, ny, lateral, bounds, span, offsets, members):
    """Bucket the groups of GROUP consecutive edges of the polygon ``q`` (m, 2) by lateral offset.

    Fills ``lateral`` (m,) with the vertices' offsets along the unit normal (nx, ny), ``bounds``
    (g, 2) with each group's lateral range and CSR lists (``offsets`` (BUCKETS + 1,), ``members``)
    of the groups overlapping each bucket; ``span`` (g, 2) int is scratch space. Group g holds
    edges g * GROUP ... g * GROUP + GROUP - 1. Returns the lowest lateral offset and the bucket width.
    """
    m, n_groups = q.shape[0], bounds.shape[0]
    for k in range(m):
        lateral[k] = q[k, 0] * nx + q[k, 1] * ny
    for g in range(n_groups):
        lo = hi = lateral[g * GROUP]
        for k in range(g * GROUP + 1, min(g * GROUP + GROUP, m) + 1):
            x = lateral[k] if k < m else lateral[0]
            lo, hi = min(lo, x), max(hi, x)
        bounds[g, 0], bounds[g, 1] = lo, hi
    lo_all, hi_all = bounds[:, 0].min(), bounds[:, 1].max()
    width = (hi_all - lo_all) / BUCKETS + 1e-15
    offsets[:] = 0
    for g in range(n_groups):
        span[g, 0] = min(int((bounds[g, 0] - lo_all) / width), BUCKETS - 1)
        span[g, 1] = min(int((bounds[g, 1] - lo_all) / width), BUCKETS - 1)
        for j in range(span[g, 0], span[g, 1] + 1):
            offsets[j + 1] += 1
    for j in range(BUCKETS):
        offsets[j + 1] += offsets[j]
    fill = offsets[:-1].copy()
    for g in range(n_groups):
        for j in range(span[g, 0], span[g, 1] + 1):
            members[fill[j]] = g
            fill[j] += 1
    return lo_all, width


@njit(cache=True)
def _cells(q, size):
    """Square cells of side ``size`` over the polygon's bounding box and the edges whose box meets each.

    Returns the box's low corner (x0, y0), the cell counts (ncx, ncy) and CSR lists (offsets
    (ncx * ncy + 1,), members) of the edges of each cell, row-major in x.
    """
    m = q.shape[0]
    x0, y0 = q[:, 0].min(), q[:, 1].min()
    ncx = min(int((q[:, 0].max() - x0) / size) + 1, MAX_CELLS)
    ncy = min(int((q[:, 1].max() - y0) / size) + 1, MAX_CELLS)
    size = max(size, (q[:, 0].max() - x0) / ncx * (1 + 1e-12), (q[:, 1].max() - y0) / ncy * (1 + 1e-12))
    box = np.empty((m, 4), np.int64)
    offsets = np.zeros(ncx * ncy + 1, np.int64)
    for k in range(m):
        a, b = q[k], q[(k + 1) % m]
        box[k, 0] = min(int((min(a[0], b[0]) - x0) / size), ncx - 1)
        box[k, 1] = min(int((max(a[0], b[0]) - x0) / size), ncx - 1)
        box[k, 2] = min(int((min(a[1], b[1]) - y0) / size), ncy - 1)
        box[k, 3] = min(int((max(a[1], b[1]) - y0) / size), ncy - 1)
        for i in range(box[k, 0], box[k, 1] + 1):
            for j in range(box[k, 2], box[k, 3] + 1):
                offsets[i * ncy + j + 1] += 1
    for c in range(ncx * ncy):
        offsets[c + 1] += offsets[c]
    members = np.empty(offsets[-1], np.int64)
    fill = offsets[:-1].copy()
    for k in range(m):
        for i in range(box[k, 0], box[k, 1] + 1):
            for j in range(box[k, 2], box[k, 3] + 1):
                members[fill[i * ncy + j]] = k
                fill[i * ncy + j] += 1
    return x0, y0, size, ncx, ncy, offsets, members


@njit(cache=True)
def _crossing(px, py, dx, dy, q, e, k, parallel_eps):
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
def _record(lam, t, point, p, f, hit, k, v, q, e, q_t, period):
    """Keep the contact at ``hit`` (distance travelled) on edge k, fraction v, if it is the first so far."""
    if hit < lam[p, f]:
        m = q.shape[0]
        lam[p, f] = hit
        t_next = q_t[k + 1] if k + 1 < m else period
        t[p, f] = q_t[k] + v * (t_next - q_t[k])
        point[p, f, 0] = q[k, 0] + v * e[k, 0]
        point[p, f, 1] = q[k, 1] + v * e[k, 1]


@njit(cache=True)
def _edges(q):
    """(m, 2) float: edge vectors q[k + 1] - q[k] of the closed polygon."""
    m = q.shape[0]
    e = np.empty((m, 2))
    for k in range(m):
        e[k, 0] = q[(k + 1) % m, 0] - q[k, 0]
        e[k, 1] = q[(k + 1) % m, 1] - q[k, 1]
    return e


@njit(cache=True)
def _outputs(n_poses, n_fingers):
    """lam (inf), t (NaN), point (NaN), inside (False) for (n_poses, n_fingers): nothing touched yet."""
    return (np.full((n_poses, n_fingers), np.inf), np.full((n_poses, n_fingers), np.nan),
            np.full((n_poses, n_fingers, 2), np.nan), np.zeros((n_poses, n_fingers), np.bool_))


@njit(cache=True)
def grid_first_touch(q, q_t, period, xs, ys, yaws, seg_start, seg_dir, seg_finger, seg_lam0,
                     seg_first, n_fingers, parallel_eps):
    """First contact of every finger at every pose of an (x, y, yaw) grid.

    A finger's first chord is tested against the edges bucketed along its own normal (once per
    yaw), which also gives the parity of its half-line (start inside). Its later chords (an arc's)
    are short and matter only where the finger has not touched yet: each tests the edges of the
    square cells (built once, side the longest later chord) its bounding box meets, usually none.

    Parameters
    ----------
    q : (m, 2) float
        Closed contour polygon (EFD samples).
    q_t : (m,) float
        EFD parameter of each polygon vertex, increasing; ``period`` follows the last.
    period : float
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
    inside : (p, f) bool
        The fingertip starts inside the contour.
    """
    m = q.shape[0]
    nx, ny, nyaw = xs.shape[0], ys.shape[0], yaws.shape[0]
    lam, t, point, inside = _outputs(nx * ny * nyaw, n_fingers)
    e = _edges(q)
    n_groups = (m + GROUP - 1) // GROUP
    lateral, bounds, span = np.empty(m), np.empty((n_groups, 2)), np.empty((n_groups, 2), np.int64)
    offsets, members = np.empty(BUCKETS + 1, np.int64), np.empty(n_groups * BUCKETS, np.int64)
    longest = 0.0
    for sg in range(seg_start.shape[0]):
        if not seg_first[sg]:
            longest = max(longest, math.hypot(seg_dir[sg, 0], seg_dir[sg, 1]))
    x0, y0, size, ncx, ncy, cell_offsets, cell_members = _cells(q, max(longest, 1e-9))
    x1, y1, pad = q[:, 0].max(), q[:, 1].max(), 1e-9 * size
    lo, width, nxl, nyl = 0.0, 1.0, 0.0, 0.0
    for iyaw in range(nyaw):
        c, s = math.cos(yaws[iyaw]), math.sin(yaws[iyaw])
        for sg in range(seg_start.shape[0]):
            dx = c * seg_dir[sg, 0] - s * seg_dir[sg, 1]
            dy = s * seg_dir[sg, 0] + c * seg_dir[sg, 1]
            ox = c * seg_start[sg, 0] - s * seg_start[sg, 1]
            oy = s * seg_start[sg, 0] + c * seg_start[sg, 1]
            length = math.hypot(dx, dy)
            f = seg_finger[sg]
            if seg_first[sg]:
                nxl, nyl = -dy / length, dx / length
                lo, width = _lateral_buckets(q, nxl, nyl, lateral, bounds, span, offsets, members)
            for ix in range(nx):
                px = xs[ix] + ox
                for iy in range(ny):
                    py = ys[iy] + oy
                    p = (ix * ny + iy) * nyaw + iyaw
                    if seg_first[sg]:
                        offset = px * nxl + py * nyl
                        b = int(math.floor((offset - lo) / width))
                        if b < 0 or b >= BUCKETS:
                            continue
                        # lateral ranges of the groups, then of their edges, filter before the exact test
                        near = 1e-9 * width
                        parity = False
                        for j in range(offsets[b], offsets[b + 1]):
                            g = members[j]
                            if offset < bounds[g, 0] - near or offset > bounds[g, 1] + near:
                                continue
                            for k in range(g * GROUP, min(g * GROUP + GROUP, m)):
                                a, z = lateral[k], lateral[k + 1] if k + 1 < m else lateral[0]
                                if offset < min(a, z) - near or offset > max(a, z) + near:
                                    continue
                                u, v = _crossing(px, py, dx, dy, q, e, k, parallel_eps)
                                if u < 0.0:
                                    continue
                                parity = not parity
                                if u <= 1.0:
                                    _record(lam, t, point, p, f, seg_lam0[sg] + u * length, k, v, q, e, q_t,
                                            period)
                        inside[p, f] = parity
                        continue
                    if lam[p, f] <= seg_lam0[sg]:
                        continue  # touched on an earlier chord
                    # cells of the chord's bounding box, padded against rounding at their borders
                    if min(px, px + dx) > x1 + pad or max(px, px + dx) < x0 - pad or \
                            min(py, py + dy) > y1 + pad or max(py, py + dy) < y0 - pad:
                        continue
                    i0 = max(int(math.floor((min(px, px + dx) - x0 - pad) / size)), 0)
                    i1 = min(int(math.floor((max(px, px + dx) - x0 + pad) / size)), ncx - 1)
                    j0 = max(int(math.floor((min(py, py + dy) - y0 - pad) / size)), 0)
                    j1 = min(int(math.floor((max(py, py + dy) - y0 + pad) / size)), ncy - 1)
                    for i in range(i0, i1 + 1):
                        for cell in range(i * ncy + j0, i * ncy + j1 + 1):
                            for j in range(cell_offsets[cell], cell_offsets[cell + 1]):
                                k = cell_members[j]
                                u, v = _crossing(px, py, dx, dy, q, e, k, parallel_eps)
                                if 0.0 <= u <= 1.0:
                                    _record(lam, t, point, p, f, seg_lam0[sg] + u * length, k, v, q, e, q_t,
                                            period)
    return lam, t, point, inside


@njit(cache=True)
def interpolate_curvature(magnitude, turn, t, period):
    """Curvature at EFD parameters t (p, f) from tables over [0, period) (NaN stays NaN).

    Parameters
    ----------
    magnitude : (n,) float
        |curvature| at n evenly spaced parameters.
    turn : (n,) float
        A smooth function with the sign of the curvature there (r' x r'').
    t : (p, f) float
    period : float

    Returns
    -------
    (p, f) float
        The interpolated magnitude, negative where the interpolated ``turn`` is.
    """
    n = magnitude.shape[0]
    out = np.full(t.shape, np.nan)
    for p in range(t.shape[0]):
        for f in range(t.shape[1]):
            if not math.isnan(t[p, f]):
                x = t[p, f] / period * n
                i = min(int(x), n - 1)
                j = (i + 1) % n
                w = x - i
                value = (1 - w) * magnitude[i] + w * magnitude[j]
                out[p, f] = -value if (1 - w) * turn[i] + w * turn[j] < 0 else value
    return out


@njit(cache=True)
def pose_first_touch(q, q_t, period, poses, seg_start, seg_dir, seg_finger, seg_lam0, seg_first, n_fingers,
                     parallel_eps):
    """First contact of every finger at each of a list of poses: every chord against every edge.

    The arithmetic of :func:`grid_first_touch` without its buckets, for few poses (exact
    re-evaluation, continuous refinement). A finger's later chords are skipped once it has touched.

    Parameters
    ----------
    q, q_t, period, seg_start, seg_dir, seg_finger, seg_lam0, seg_first, n_fingers, parallel_eps
        As for :func:`grid_first_touch`.
    poses : (p, 3) float
        (x, y, yaw).

    Returns
    -------
    lam, t, point, inside
        As for :func:`grid_first_touch`.
    """
    m = q.shape[0]
    lam, t, point, inside = _outputs(poses.shape[0], n_fingers)
    e = _edges(q)
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
            length = math.hypot(dx, dy)
            parity = False
            for k in range(m):
                u, v = _crossing(px, py, dx, dy, q, e, k, parallel_eps)
                if u < 0.0:
                    continue
                parity = not parity
                if u <= 1.0:
                    _record(lam, t, point, p, f, seg_lam0[sg] + u * length, k, v, q, e, q_t, period)
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
    for k in range(starts.shape[0]):
        length2 = vectors[k, 0] ** 2 + vectors[k, 1] ** 2
        for i in range(points.shape[0]):
            wx, wy = points[i, 0] - starts[k, 0], points[i, 1] - starts[k, 1]
            s = min(max((wx * vectors[k, 0] + wy * vectors[k, 1]) / length2, 0.0), 1.0) if length2 > 0 else 0.0
            d = math.hypot(wx - s * vectors[k, 0], wy - s * vectors[k, 1])
            if d < best or (d == best and (i < best_i or (i == best_i and k < best_k))):
                best, best_i, best_k, best_s = d, i, k, s
    return best_i, best_k, best_s, best


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


@njit(cache=True)
def first_crossing(p, eps):
    """(i, j) of the first pair of non-adjacent edges of a closed polygon p (n, 2) that cross, else (-1, -1).

    Edges i < j cross when each one's end points lie strictly on opposite sides
    of the other (by more than ``eps``); pairs are tried in order of i, then j,
    after a bounding-box reject: O(n^2) pairs but no (n, n) arrays.
    """
    n = len(p)
    for i in range(n):
        ax, ay = p[i, 0], p[i, 1]
        bx, by = p[(i + 1) % n, 0], p[(i + 1) % n, 1]
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue
            cx, cy = p[j, 0], p[j, 1]
            ex, ey = p[(j + 1) % n, 0], p[(j + 1) % n, 1]
            if max(cx, ex) < min(ax, bx) or max(ax, bx) < min(cx, ex) or \
                    max(cy, ey) < min(ay, by) or max(ay, by) < min(cy, ey):
                continue
            if _straddles(ax, ay, bx, by, cx, cy, ex, ey, eps) and _straddles(cx, cy, ex, ey, ax, ay, bx, by, eps):
                return i, j
    return -1, -1


@njit(cache=True)
def _straddles(ax, ay, bx, by, cx, cy, ex, ey, eps):
    """Points c and e lie strictly on opposite sides of the line through a, b (by more than eps)."""
    dx, dy = bx - ax, by - ay
    o1 = dx * (cy - ay) - dy * (cx - ax)
    o2 = dx * (ey - ay) - dy * (ex - ax)
    return (o1 > eps and o2 < -eps) or (o1 < -eps and o2 > eps)
