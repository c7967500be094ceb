"""Compiled inner loops of the search (numba): first touch of every finger at many poses.

The numpy formulation (:func:`contourgrasp.synthesis.first_touch`) tests every
trajectory chord against every contour edge. A profile of the dense grid
(346 k poses) shows that this (poses x chords x edges) product is the whole
cost. Here the grid's structure removes most of it: at a fixed yaw a chord has
a fixed direction, so an edge can only be crossed by chords whose lateral
offset (perpendicular to the direction) falls within the edge's lateral
extent. A finger's first chord (whose half-line also decides whether the
finger starts inside) is tested only at the grid positions where its box meets
the contour's (a few of the 49 per yaw on the thesis grid), against the groups
of consecutive edges whose lateral range holds its offset. A group is held in a
disc, whose lateral range costs one product per (yaw, chord); the groups are
scanned, or looked up in lateral buckets where many positions share a (yaw,
chord) (the dense grid). An arc's later chords are short and needed only where
the finger has not touched yet: they look edges up in square cells built once
per grid, and most find none. The arithmetic of the test is the same as the
numpy version; :func:`pose_first_touch` applies it to a list of poses (exact
re-evaluation, refinement) with the boxes as the only filter.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Lateral buckets per (yaw, first chord).
BUCKETS = 32

#: Consecutive contour edges held in one disc and bucketed as one: the buckets are rebuilt for every
#: (yaw, first chord), so building them must cost little.
GROUP = 4

#: A (yaw, first chord) with at most this many grid positions near the contour scans every edge group
#: for each rather than building buckets: on the thesis grid (a handful of positions) building would
#: cost more than the scans, on the dense grid (hundreds) less.
SCAN_POSITIONS = 24

#: Cells per axis of the grid that short (later) chords look their edges up in, at most.
MAX_CELLS = 128


@njit(cache=True)
def _group_discs(q):
    """(g, 3) float: centre and radius of a disc holding each group of GROUP consecutive edges of ``q`` (m, 2).

    Group g holds edges g * GROUP ... g * GROUP + GROUP - 1. A disc does not depend on the yaw:
    its lateral range along any normal is its centre's offset +- its radius, one product per
    (yaw, first chord) instead of one per vertex. Radii are padded against rounding.
    """
    m = q.shape[0]
    discs = np.empty(((m + GROUP - 1) // GROUP, 3))
    for g in range(discs.shape[0]):
        stop = min(g * GROUP + GROUP, m)  # the group's last edge ends at vertex stop (mod m)
        x0 = x1 = q[stop % m, 0]
        y0 = y1 = q[stop % m, 1]
        for k in range(g * GROUP, stop):
            x0, x1, y0, y1 = min(x0, q[k, 0]), max(x1, q[k, 0]), min(y0, q[k, 1]), max(y1, q[k, 1])
        cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
        r = 0.0
        for k in range(g * GROUP, stop + 1):
            r = max(r, math.hypot(q[k % m, 0] - cx, q[k % m, 1] - cy))
        discs[g, 0], discs[g, 1], discs[g, 2] = cx, cy, r * (1.0 + 1e-9) + 1e-12
    return discs


@njit(cache=True)
def _lateral_bounds(discs, nx, ny, bounds):
    """Fill ``bounds`` (g, 2) with the lateral range along the unit normal (nx, ny) of each edge group
    (``discs``, :func:`_group_discs`).

    Returns the lowest and highest lateral offset of all.
    """
    lo_all, hi_all = np.inf, -np.inf
    for g in range(discs.shape[0]):
        centre = discs[g, 0] * nx + discs[g, 1] * ny
        bounds[g, 0], bounds[g, 1] = centre - discs[g, 2], centre + discs[g, 2]
        lo_all, hi_all = min(lo_all, bounds[g, 0]), max(hi_all, bounds[g, 1])
    return lo_all, hi_all


@njit(cache=True)
def _lateral_buckets(bounds, lo_all, width, span, offsets, members, fill):
    """Bucket the edge groups by their lateral ``bounds`` (g, 2), from ``lo_all``, ``width`` apart.

    Fills CSR lists (``offsets`` (BUCKETS + 1,), ``members``) of the groups overlapping each
    bucket; ``span`` (g, 2) and ``fill`` (BUCKETS,) int are scratch space (this runs once per yaw
    and first chord: allocating them here would cost more than the rest).
    """
    n_groups = bounds.shape[0]
    for j in range(BUCKETS + 1):
        offsets[j] = 0
    for g in range(n_groups):
        span[g, 0] = min(int((bounds[g, 0] - lo_all) / width), BUCKETS - 1)
        span[g, 1] = min(int((bounds[g, 1] - lo_all) / width), BUCKETS - 1)
        for j in range(span[g, 0], span[g, 1] + 1):
            offsets[j + 1] += 1
    for j in range(BUCKETS):
        offsets[j + 1] += offsets[j]
        fill[j] = offsets[j]
    for g in range(n_groups):
        for j in range(span[g, 0], span[g, 1] + 1):
            members[fill[j]] = g
            fill[j] += 1


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

    A finger's first chord is tested against the edges whose lateral range along its own normal
    holds its offset (:func:`_first_chord`), which also gives the parity of its half-line (start
    inside). Its later chords (an arc's) are short and matter only where the finger has not
    touched yet: each tests the edges of the square cells (built once, side the longest later
    chord) its bounding box meets, usually none.

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
    n_seg = seg_start.shape[0]
    lam, t, point, inside = _outputs(xs.shape[0] * ys.shape[0] * yaws.shape[0], n_fingers)
    e = _edges(q)
    discs = _group_discs(q)
    n_groups = discs.shape[0]
    buckets = (np.empty((n_groups, 2)), np.empty((n_groups, 2), np.int64), np.empty(BUCKETS + 1, np.int64),
               np.empty(n_groups * BUCKETS, np.int64), np.empty(BUCKETS, np.int64),
               np.array([0, n_groups]), np.arange(n_groups))
    longest = 0.0
    for sg in range(n_seg):
        if not seg_first[sg]:
            longest = max(longest, math.hypot(seg_dir[sg, 0], seg_dir[sg, 1]))
    cells = _cells(q, max(longest, 1e-9))
    box = (q[:, 0].min(), q[:, 1].min(), q[:, 0].max(), q[:, 1].max())
    chords = np.empty((n_seg, 5))
    for iyaw in range(yaws.shape[0]):
        c, s = math.cos(yaws[iyaw]), math.sin(yaws[iyaw])
        for sg in range(n_seg):
            chords[sg, 0] = c * seg_dir[sg, 0] - s * seg_dir[sg, 1]
            chords[sg, 1] = s * seg_dir[sg, 0] + c * seg_dir[sg, 1]
            chords[sg, 2] = c * seg_start[sg, 0] - s * seg_start[sg, 1]
            chords[sg, 3] = s * seg_start[sg, 0] + c * seg_start[sg, 1]
            chords[sg, 4] = math.hypot(chords[sg, 0], chords[sg, 1])
        sg = 0
        while sg < n_seg:
            last = sg + 1  # the finger's chords are sg ... last - 1
            while last < n_seg and not seg_first[last]:
                last += 1
            _first_chord(lam, t, point, inside, q, q_t, period, e, xs, ys, iyaw, yaws.shape[0], chords[sg],
                         seg_finger[sg], seg_lam0[sg], discs, buckets, box, parallel_eps)
            if last > sg + 1:
                _later_chords(lam, t, point, q, q_t, period, e, xs, ys, iyaw, yaws.shape[0], chords[sg + 1:last],
                              seg_finger[sg], seg_lam0[sg + 1:last], cells, box[2], box[3], parallel_eps)
            sg = last
    return lam, t, point, inside


@njit(cache=True)
def _first_chord(lam, t, point, inside, q, q_t, period, e, xs, ys, iyaw, nyaw, chord, f, lam0, discs, buckets, box,
                 parallel_eps):
    """A finger's first chord (dx, dy, ox, oy, length at yaw ``iyaw``) at every grid position.

    The chord's half-line meets the edges whose lateral range along its normal holds its own
    offset: their crossings give the contacts and the parity (start inside). Where the chord's box
    misses the contour's, ``box`` (x0, y0, x1, y1), neither can be (a start outside the box is
    outside the contour): that is most positions. The edge groups (``discs``) are bucketed by
    lateral range (``buckets``: scratch of :func:`_lateral_buckets`, then the one bucket of all
    groups) when more than SCAN_POSITIONS positions are near; else each position scans them all.
    """
    dx, dy, ox, oy, length = chord[0], chord[1], chord[2], chord[3], chord[4]
    nxl, nyl = -dy / length, dx / length
    bounds, span, offsets, members, fill, all_offsets, all_members = buckets
    m, ny = q.shape[0], ys.shape[0]
    x0, y0, x1, y1 = box
    pad = 1e-9 * max(x1 - x0, y1 - y0)
    near_x, near_y = 0, 0
    for ix in range(xs.shape[0]):
        near_x += not _apart(xs[ix] + ox, dx, x0, x1, pad)
    for iy in range(ny):
        near_y += not _apart(ys[iy] + oy, dy, y0, y1, pad)
    if near_x * near_y == 0:
        return
    lo, hi = _lateral_bounds(discs, nxl, nyl, bounds)
    width = (hi - lo) / BUCKETS + 1e-15
    near = 1e-9 * width
    n_buckets = BUCKETS
    if near_x * near_y > SCAN_POSITIONS:
        _lateral_buckets(bounds, lo, width, span, offsets, members, fill)
    else:
        offsets, members, n_buckets, width = all_offsets, all_members, 1, BUCKETS * width
    for ix in range(xs.shape[0]):
        px = xs[ix] + ox
        if _apart(px, dx, x0, x1, pad):
            continue
        for iy in range(ny):
            py = ys[iy] + oy
            if _apart(py, dy, y0, y1, pad):
                continue
            offset = px * nxl + py * nyl
            b = int(math.floor((offset - lo) / width))
            if b < 0 or b >= n_buckets:
                continue
            # lateral ranges of the groups, then of their edges, filter before the exact test
            p = (ix * ny + iy) * nyaw + iyaw
            parity = False
            for j in range(offsets[b], offsets[b + 1]):
                g = members[j]
                if offset < bounds[g, 0] or offset > bounds[g, 1]:
                    continue
                for k in range(g * GROUP, min(g * GROUP + GROUP, m)):
                    k1 = k + 1 if k + 1 < m else 0
                    a, z = q[k, 0] * nxl + q[k, 1] * nyl, q[k1, 0] * nxl + q[k1, 1] * nyl
                    if offset < min(a, z) - near or offset > max(a, z) + near:
                        continue
                    u, v = _crossing(px, py, dx, dy, q, e, k, parallel_eps)
                    if u < 0.0:
                        continue
                    parity = not parity
                    if u <= 1.0:
                        _record(lam, t, point, p, f, lam0 + u * length, k, v, q, e, q_t, period)
            inside[p, f] = parity


@njit(cache=True)
def _apart(a, d, lo, hi, pad):
    """The interval from a to a + d lies outside [lo - pad, hi + pad] (one axis of a chord's box and the contour's)."""
    return min(a, a + d) > hi + pad or max(a, a + d) < lo - pad


@njit(cache=True)
def _later_chords(lam, t, point, q, q_t, period, e, xs, ys, iyaw, nyaw, chords, f, lam0, cells, x1, y1,
                  parallel_eps):
    """A finger's later chords (rows dx, dy, ox, oy, length at yaw ``iyaw``) at every grid position.

    Each tests the edges of the ``cells`` (:func:`_cells`) its box meets, only where the finger
    has not touched yet and only where the box of all of them meets the contour's, (x0, y0) to
    (x1, y1): elsewhere, most positions, none would (it is padded twice as much as a chord's,
    against rounding).
    """
    x0, y0, size, ncx, ncy, cell_offsets, cell_members = cells
    pad = 1e-9 * size
    box_x0, box_x1, box_y0, box_y1 = np.inf, -np.inf, np.inf, -np.inf
    for sg in range(chords.shape[0]):
        ox, oy, ex, ey = chords[sg, 2], chords[sg, 3], chords[sg, 2] + chords[sg, 0], chords[sg, 3] + chords[sg, 1]
        box_x0, box_x1 = min(box_x0, ox, ex), max(box_x1, ox, ex)
        box_y0, box_y1 = min(box_y0, oy, ey), max(box_y1, oy, ey)
    box_x0, box_x1, box_y0, box_y1 = box_x0 - 2 * pad, box_x1 + 2 * pad, box_y0 - 2 * pad, box_y1 + 2 * pad
    ny = ys.shape[0]
    for ix in range(xs.shape[0]):
        if xs[ix] + box_x0 > x1 or xs[ix] + box_x1 < x0:
            continue
        for iy in range(ny):
            p = (ix * ny + iy) * nyaw + iyaw
            if lam[p, f] <= lam0[0] or ys[iy] + box_y0 > y1 or ys[iy] + box_y1 < y0:
                continue
            for sg in range(chords.shape[0]):
                dx, dy, length = chords[sg, 0], chords[sg, 1], chords[sg, 4]
                px, py = xs[ix] + chords[sg, 2], ys[iy] + chords[sg, 3]
                if lam[p, f] <= lam0[sg]:
                    break  # touched on an earlier chord
                if _apart(px, dx, x0, x1, pad) or _apart(py, dy, y0, y1, pad):
                    continue
                # cells of the chord's bounding box, padded against rounding at their borders
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
                                _record(lam, t, point, p, f, lam0[sg] + u * length, k, v, q, e, q_t, period)


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
    re-evaluation, continuous refinement). A finger's later chords are skipped once it has touched,
    and every chord whose box misses the contour's (as in :func:`_first_chord`, a first chord's
    start is then outside).

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
            if _apart(px, dx, x0, x1, pad) or _apart(py, dy, y0, y1, pad):
                continue
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


@njit(cache=True)
def ratio_cost_row(distance, touching, beta, p, squared):
    """Eq 3.35 for pose p of (p, f) arrays: sum over touching i of beta_i (d_i - mean_{j != i, touching} d_j)^(2 or 1).

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
    """Constraints 3.39-3.41 and the cost of eq 3.34 for every pose.

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
