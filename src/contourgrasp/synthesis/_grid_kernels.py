"""Compiled inner loops of the grid screen (numba): first touch of every finger at every grid pose.

The numpy formulation (:func:`contourgrasp.synthesis.inner.first_touch`) tests every
trajectory chord against every contour edge, a (poses x chords x edges) product that
is the whole cost of a dense grid. Here the grid's structure removes most of it: at a fixed yaw a chord has
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
per grid, and most find none. The arithmetic of the test is that of
:mod:`contourgrasp.synthesis._touch_kernels`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._touch_kernels import apart, crossing, edges, outputs, record

#: Lateral buckets per (yaw, first chord).
BUCKETS = 64

#: Consecutive contour edges held in one disc and bucketed as one: the buckets are rebuilt for every
#: (yaw, first chord), so building them must cost little. With 64 buckets, 2 edges a group screens the
#: dense grid 12 % faster than 4 in 32 buckets, and the thesis grid's (1.3 ms) 0.3 ms slower
#: (`benchmarks/search_speed.py`).
GROUP = 2

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
    lam, t, point, inside = outputs(xs.shape[0] * ys.shape[0] * yaws.shape[0], n_fingers)
    e = edges(q)
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
        near_x += not apart(xs[ix] + ox, dx, x0, x1, pad)
    for iy in range(ny):
        near_y += not apart(ys[iy] + oy, dy, y0, y1, pad)
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
        if apart(px, dx, x0, x1, pad):
            continue
        for iy in range(ny):
            py = ys[iy] + oy
            if apart(py, dy, y0, y1, pad):
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
                    u, v = crossing(px, py, dx, dy, q, e, k, parallel_eps)
                    if u < 0.0:
                        continue
                    parity = not parity
                    if u <= 1.0:
                        record(lam, t, point, p, f, lam0 + u * length, k, v, q, e, q_t, period)
            inside[p, f] = parity


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
                if apart(px, dx, x0, x1, pad) or apart(py, dy, y0, y1, pad):
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
                            u, v = crossing(px, py, dx, dy, q, e, k, parallel_eps)
                            if 0.0 <= u <= 1.0:
                                record(lam, t, point, p, f, lam0[sg] + u * length, k, v, q, e, q_t, period)


@njit(cache=True)
def touch_counts(lam, inside):
    """Per pose the fingers that touch (``lam`` (p, f) finite), and whether some pose starts with no fingertip
    ``inside`` (p, f): one pass where numpy's row reductions of a (p, 5) array walk it five times."""
    counts = np.zeros(lam.shape[0], np.int64)
    any_outside = False
    for p in range(lam.shape[0]):
        starts_inside = False
        for f in range(lam.shape[1]):
            counts[p] += math.isfinite(lam[p, f])
            starts_inside |= inside[p, f]
        any_outside |= not starts_inside
    return counts, any_outside


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


