"""Compiled inner loop of :meth:`contourgrasp.perception.HeightMap.conservative` (numba).

Each unseen cell walks toward the camera's foot in half-cell steps and takes the highest line of
sight over the seen cells on the way. Walking every step of every walk is the cost of a tall
object's long shadow; a loop can stop a walk early. A seen height ``h`` bounds the cell by
``h - (H - h) gap / (r - s + d / 2)``, which grows with ``h`` and falls as the walk goes on (``gap``
grows, ``r - s`` shrinks): once even the map's highest seen height would give less than the bound
found, no later step can raise it. A step's arithmetic is the bound's definition, term for term, so
stopping early changes no bound (tested against every step walked).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def shadow_bounds(heights, start, unit, r, reach, steps, origin, cell, camera_height, diagonal, top):
    """(n,) float: per unseen cell the highest line of sight over the seen cells toward the camera (-inf: none).

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
            if 0 <= col < nx and 0 <= row < ny:
                h = heights[int(row), int(col)]
                b = h - (camera_height - h) * gap / depth
                if math.isfinite(b) and b > best:
                    best = b
            if s >= reach[i]:
                break  # the rest of the walk repeats this step
        out[i] = best
    return out
