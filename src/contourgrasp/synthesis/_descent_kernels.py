"""Compiled descent clearances (numba), for :func:`contourgrasp.synthesis.descent.descent_clearance` and the closing
sweep (:func:`contourgrasp.synthesis.sweep.link_first`), both through :func:`map_clearances`.

Per pose and body the kernel walks the cells of the body's footprint's bounding box and keeps the
least gap between the body's lowest point over a cell's centre line and the cell's height (the
module docstring of :mod:`~contourgrasp.synthesis.descent` has the geometry). A cell is skipped when
even the body's lowest point anywhere (an end ball's bottom: heights are linear along a capsule's
axis) could not lower the least gap found so far, so cells far below the hand cost a comparison.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..tolerances import VERTICAL_AXIS


def map_clearances(heights, hand, poses, base, ends, radii, stop=None, only_below=None) -> np.ndarray:
    """(p, n + 1) float: the least gap over ``heights`` (a HeightMap's conservative layer) of each capsule
    (``ends`` (n, 2, 3), ``radii`` (n,), hand frame) and of ``hand``'s palm, per pose (p, 3) with its height
    offset ``base`` (p,).

    ``stop`` (p,) float, optional: a pose's walk ends at the first gap found below its ``stop`` -- the pose is
    refused whatever the rest -- that body's gap kept (an upper bound of its least) and every body not yet
    walked +inf.

    ``only_below`` (p,) float, optional: a pose's bodies skip every cell that cannot bring their gap below it, so a
    gap is exact where it is below ``only_below`` and only known to be at least ``only_below`` elsewhere -- for a
    yes/no question (the closing sweep's "below the map?"), where the cells under a body far above them cost a
    comparison each instead of a capsule's geometry.
    """
    out = np.empty((len(poses), len(ends) + 1))
    stop = np.full(len(poses), -np.inf) if stop is None else np.ascontiguousarray(stop, dtype=float)
    only_below = np.full(len(poses), np.inf) if only_below is None else np.ascontiguousarray(only_below, dtype=float)
    clearances(np.ascontiguousarray(heights.conservative(), dtype=float), np.asarray(heights.origin, dtype=float),
               float(heights.cell), np.asarray(heights.table_normal, dtype=float), np.ascontiguousarray(poses, dtype=float),
               np.ascontiguousarray(base, dtype=float), np.ascontiguousarray(ends, dtype=float),
               np.ascontiguousarray(radii, dtype=float), np.ascontiguousarray(hand.palm.points, dtype=float),
               np.ascontiguousarray(hand.palm.plane, dtype=float), VERTICAL_AXIS, stop, only_below, out)
    return out


@njit(cache=True)
def capsule_lowest(qx, qy, a, b, r, vertical):
    """Largest z (lowest point, z down) of the capsule a -> b (radius r) on the vertical line at (qx, qy); -inf off it."""
    low = -math.inf
    for end in (a, b):
        d2 = (qx - end[0]) ** 2 + (qy - end[1]) ** 2
        if d2 <= r * r:
            low = max(low, end[2] + math.sqrt(r * r - d2))
    ux, uy, uz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    length = math.sqrt(ux * ux + uy * uy + uz * uz)
    if length > 0.0:
        ux, uy, uz = ux / length, uy / length, uz / length
        k = 1.0 - uz * uz
        if k > vertical:
            wx, wy = qx - a[0], qy - a[1]
            s = wx * ux + wy * uy
            disc = (s * uz) ** 2 - k * (wx * wx + wy * wy - s * s - r * r)
            if disc >= 0.0:
                z = (s * uz + math.sqrt(disc)) / k
                t = s + z * uz
                if 0.0 <= t <= length:
                    low = max(low, a[2] + z)
    return low


@njit(cache=True)
def _inside(qx, qy, polygon):
    inside = False
    n = polygon.shape[0]
    for k in range(n):
        x0, y0 = polygon[k, 0], polygon[k, 1]
        x1, y1 = polygon[(k + 1) % n, 0], polygon[(k + 1) % n, 1]
        if y0 != y1 and ((y0 > qy) != (y1 > qy)) and qx < x0 + (qy - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
    return inside


@njit(cache=True)
def _cell(layer, i, j):
    if i < 0 or j < 0 or i >= layer.shape[0] or j >= layer.shape[1]:
        return math.inf
    return layer[i, j]


@njit(cache=True)
def _gap(layer, origin, cell, normal, i, k, x, y, c, s, ends, r, base, vertical):
    """The gap of a capsule over cell (i, k); +inf when the cell's centre line misses it."""
    cx, cy = origin[0] + (k + 0.5) * cell, origin[1] + (i + 0.5) * cell
    dx, dy = cx - x, cy - y
    low = capsule_lowest(c * dx + s * dy, -s * dx + c * dy, ends[0], ends[1], r, vertical)
    if low == -math.inf:
        return math.inf
    return normal[0] * cx + normal[1] * cy + normal[2] * low + base - _cell(layer, i, k)


@njit(cache=True)
def _palm_gap(layer, origin, cell, normal, i, k, x, y, c, s, outline, plane, base):
    """The gap of the palm's underside (z = plane . (1, x, y), hand frame) over cell (i, k); +inf when the cell's
    centre is outside its outline."""
    cx, cy = origin[0] + (k + 0.5) * cell, origin[1] + (i + 0.5) * cell
    dx, dy = cx - x, cy - y
    hx, hy = c * dx + s * dy, -s * dx + c * dy
    if not _inside(hx, hy, outline):
        return math.inf
    z = plane[0] + plane[1] * hx + plane[2] * hy
    return normal[0] * cx + normal[1] * cy + normal[2] * z + base - _cell(layer, i, k)


@njit(cache=True)
def clearances(layer, origin, cell, normal, poses, base, ends, radii, palm, plane, vertical, stop, only_below, out):
    """Fill out (p, n_capsules + 1): per pose the least gap of each capsule (ends (n, 2, 3), radii (n,)) and the palm
    (its outline (k, 2) and underside plane (3,)); a pose's walk ends at a gap below its ``stop`` (p,), and skips
    the cells that cannot bring a gap below its ``only_below`` (p,).

    A pose's walk starts with the body that refused the last refused pose: neighbouring candidates tend to
    strike with the same body, and a refused pose's other bodies need no walk (they are +inf either way).
    """
    n_bodies = ends.shape[0] + 1
    first = -1
    for p in range(poses.shape[0]):
        refused = False
        for step in range(n_bodies + 1):
            j = first if step == 0 else step - 1
            if j < 0 or (step > 0 and j == first):
                continue
            if refused:
                out[p, j] = math.inf
                continue
            out[p, j] = _body_gap(layer, origin, cell, normal, poses[p], base[p], ends, radii, palm, plane, vertical,
                                  j, stop[p], only_below[p])
            if out[p, j] < stop[p]:
                refused, first = True, j


@njit(cache=True)
def _body_gap(layer, origin, cell, normal, pose, base, ends, radii, palm, plane, vertical, j, stop, only_below):
    """The least gap of body ``j`` (a capsule of ``ends``, or the palm after them) at ``pose`` over the map, its walk
    ended at a gap below ``stop`` and skipping the cells that cannot bring it below ``only_below``."""
    nx_, ny_, nz_ = normal[0], normal[1], normal[2]
    x, y, c, s = pose[0], pose[1], math.cos(pose[2]), math.sin(pose[2])
    capsule = j < ends.shape[0]
    if capsule:
        pts, r = ends[j], radii[j]
    else:
        pts, r = palm, 0.0
    lo_x = lo_y = lowest = math.inf
    hi_x = hi_y = -math.inf
    for v in range(pts.shape[0]):
        px, py = x + c * pts[v, 0] - s * pts[v, 1], y + s * pts[v, 0] + c * pts[v, 1]
        lo_x, hi_x, lo_y, hi_y = min(lo_x, px), max(hi_x, px), min(lo_y, py), max(hi_y, py)
        z = pts[v, 2] if capsule else plane[0] + plane[1] * pts[v, 0] + plane[2] * pts[v, 1]
        lowest = min(lowest, nx_ * px + ny_ * py + nz_ * z + base - r)
    c0 = int(math.floor((lo_x - r - origin[0]) / cell))
    c1 = int(math.floor((hi_x + r - origin[0]) / cell))
    r0 = int(math.floor((lo_y - r - origin[1]) / cell))
    r1 = int(math.floor((hi_y + r - origin[1]) / cell))
    least = math.inf
    if capsule:  # start from the cell under the lower end: over a flat floor, the least gap at once
        e = 0 if nz_ * pts[0, 2] + nx_ * (c * pts[0, 0] - s * pts[0, 1]) + ny_ * (s * pts[0, 0] + c * pts[0, 1]) \
            <= nz_ * pts[1, 2] + nx_ * (c * pts[1, 0] - s * pts[1, 1]) + ny_ * (s * pts[1, 0] + c * pts[1, 1]) else 1
        ex, ey = x + c * pts[e, 0] - s * pts[e, 1], y + s * pts[e, 0] + c * pts[e, 1]
        least = _gap(layer, origin, cell, normal, int(math.floor((ey - origin[1]) / cell)),
                     int(math.floor((ex - origin[0]) / cell)), x, y, c, s, pts, r, base, vertical)
    for i in range(r0, r1 + 1):
        if least < stop:
            break
        for k in range(c0, c1 + 1):
            if lowest - _cell(layer, i, k) >= min(least, only_below):
                continue
            if capsule:
                least = min(least, _gap(layer, origin, cell, normal, i, k, x, y, c, s, pts, r, base, vertical))
            else:
                least = min(least, _palm_gap(layer, origin, cell, normal, i, k, x, y, c, s, pts, plane, base))
            if least < stop:
                break
    return least
