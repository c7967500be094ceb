"""Compiled inner loops of :meth:`contourgrasp.perception.HeightMap.conservative` (numba).

Each unseen cell walks in half-cell steps over the seen cells along the line through the camera's
foot, toward it (:func:`shadow_bounds`: the highest line of sight over an occluder) and away from it
(:func:`ray_bounds`: the lowest ray that passed over the cell to a seen point beyond). Walking every
step of every walk is the cost of a tall object's long shadow or a wide hole; a loop can stop a walk
early. Toward the camera a seen height ``h`` bounds the cell by ``h - (H - h) gap / (r - s + d / 2)``,
which grows with ``h`` and falls as the walk goes on: once even the map's highest seen height would
give less than the bound found, no later step can raise it. Away from it the bound is
``h + (H - h) gap / far``, which grows with ``h`` and as the walk goes on: once even the map's lowest
seen height would give more than the bound found, no later step can lower it. A step's arithmetic is
the bound's definition, term for term, so stopping early changes no bound (tested against every
step walked). The cell takes the smaller of the two, so a walk toward the camera also stops once its
bound reaches the one away from it (``cap``): it can only grow, and the smaller is then known.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def ray_bounds(heights, start, unit, r, steps, origin, cell, camera_height, diagonal, bottom):
    """(n,) float: per unseen cell the lowest line of sight to a seen cell beyond it, away from the camera (+inf: none).

    A ray that reached a seen point farther from the camera's foot passed over the cell, so the
    cell's surface lies below it: with the seen point at height ``h`` and radial distance ``far``
    from the foot, the ray is ``h + (H - h) gap / far`` high over the cell, ``gap`` apart. The
    point and the cell's surface may lie anywhere in their cells: the bound takes them a cell's
    diagonal farther apart and the point half a diagonal farther out (both only raise it).

    Parameters
    ----------
    heights : (ny, nx) float
        The map's heights, NaN where unseen.
    start, unit : (n, 2) float
        The cells' centres and the unit directions away from the camera's foot.
    r : (n,) float
        The cells' distances from the camera's foot.
    steps : (k,) float
        The walk's distances, increasing (half cells).
    origin : (2,) float
    cell, camera_height, diagonal, bottom : float
        Cell size, the camera's height above the table, a cell's diagonal, the lowest seen height.
    """
    ny, nx = heights.shape
    out = np.empty(start.shape[0])
    for i in range(start.shape[0]):
        best = np.inf
        for k in range(steps.shape[0]):
            s = steps[k]
            gap = s + diagonal
            far = r[i] + s + 0.5 * diagonal
            if bottom + (camera_height - bottom) * gap / far >= best:
                break  # no later step can lower the bound
            col = math.floor((start[i, 0] + s * unit[i, 0] - origin[0]) / cell)
            row = math.floor((start[i, 1] + s * unit[i, 1] - origin[1]) / cell)
            if not (0 <= col < nx and 0 <= row < ny):
                break  # off the map
            h = heights[int(row), int(col)]
            if math.isfinite(h):
                b = h + (camera_height - h) * gap / far
                if b < best:
                    best = b
        out[i] = best
    return out


@njit(cache=True)
def shadow_bounds(heights, start, unit, r, reach, steps, origin, cell, camera_height, diagonal, top, cap):
    """(n,) float: per unseen cell the highest line of sight over the seen cells toward the camera (-inf: none),
    or a height at least ``cap`` when the walk reaches it.

    Parameters
    ----------
    heights : (ny, nx) float
        The map's heights, NaN where unseen.
    start, unit : (n, 2) float
        The cells' centres and the unit directions toward the camera's foot.
    r, reach : (n,) float
        The cells' distances from the camera's foot and how far their walks go.
    steps : (k,) float
        The walk's distances, increasing (half cells).
    origin : (2,) float
    cell, camera_height, diagonal, top : float
        Cell size, the camera's height above the table, a cell's diagonal, the highest seen height.
    cap : (n,) float
        The walk stops once its bound reaches this (+inf: never); the bound then returned is at least it.
    """
    ny, nx = heights.shape
    out = np.empty(start.shape[0])
    for i in range(start.shape[0]):
        best = -np.inf
        for k in range(steps.shape[0]):
            s = min(steps[k], reach[i])
            if s >= r[i]:
                break
            gap = max(s - diagonal, 0.0)
            depth = r[i] - s + 0.5 * diagonal
            if camera_height > top and top - (camera_height - top) * gap / depth < best:
                break  # no later step can raise the bound
            col = math.floor((start[i, 0] + s * unit[i, 0] - origin[0]) / cell)
            row = math.floor((start[i, 1] + s * unit[i, 1] - origin[1]) / cell)
            if not (0 <= col < nx and 0 <= row < ny):
                break  # off the map, which a straight walk from inside it does not enter again
            h = heights[int(row), int(col)]
            b = h - (camera_height - h) * gap / depth
            if math.isfinite(b) and b > best:
                best = b
                if best >= cap[i]:
                    break  # the cell takes the smaller bound: the cap
            if s >= reach[i]:
                break  # the rest of the walk repeats this step
        out[i] = best
    return out
