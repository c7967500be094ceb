"""Compiled loops of :func:`contourgrasp.perception.view_along` (numba): the scene's column points in the approach
frame, their extent and their least depth per cell.

A view turns every column point of the scene (a hundred thousand for a tall can) into the approach frame
and keeps the least depth per cell of its grid. In numpy that is a product, several masks and copies and a
scatter per view, about 7 ms; one pass per question here, with no copy, about 1 ms. The arithmetic is the
frame's definition: a point's approach-frame coordinates are its offset from the origin dotted with the
frame's axes (the columns of ``R``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def target_extent(points, target, origin, R):
    """(6,) float: the least and greatest approach-frame x, y and z of the target's points: x0, x1, y0, y1, z0, z1.

    Parameters
    ----------
    points : (p, 3) float
        Planning frame.
    target : (p,) bool
    origin : (3,) float
        The approach frame's origin, planning frame.
    R : (3, 3) float
        Columns: the approach frame's axes in planning coordinates.
    """
    extent = np.array([np.inf, -np.inf, np.inf, -np.inf, np.inf, -np.inf])
    for i in range(points.shape[0]):
        if not target[i]:
            continue
        dx, dy, dz = points[i, 0] - origin[0], points[i, 1] - origin[1], points[i, 2] - origin[2]
        for k in range(3):
            v = dx * R[0, k] + dy * R[1, k] + dz * R[2, k]
            extent[2 * k] = min(extent[2 * k], v)
            extent[2 * k + 1] = max(extent[2 * k + 1], v)
    return extent


@njit(cache=True)
def least_depths(points, target, origin, R, low, cell, ny, nx, nearest):
    """The least approach-frame depth per cell of the grid ``cell`` apart from ``low`` (x, y), of all points and of
    the target's: two (ny, nx) float maps, +inf where none falls. A point not the target's counts only where its
    depth is at least ``nearest`` (what stands nearer the hand than its reach is not on its way); points off the
    grid are ignored."""
    least = np.full((ny, nx), np.inf)
    least_target = np.full((ny, nx), np.inf)
    for i in range(points.shape[0]):
        dx, dy, dz = points[i, 0] - origin[0], points[i, 1] - origin[1], points[i, 2] - origin[2]
        z = dx * R[0, 2] + dy * R[1, 2] + dz * R[2, 2]
        if not target[i] and z < nearest:
            continue
        col = math.floor((dx * R[0, 0] + dy * R[1, 0] + dz * R[2, 0] - low[0]) / cell)
        row = math.floor((dx * R[0, 1] + dy * R[1, 1] + dz * R[2, 1] - low[1]) / cell)
        if col < 0 or col >= nx or row < 0 or row >= ny:
            continue
        least[row, col] = min(least[row, col], z)
        if target[i]:
            least_target[row, col] = min(least_target[row, col], z)
    return least, least_target
