"""Compiled inner loop of the contour checks (numba): the first pair of crossing polygon edges."""

from __future__ import annotations

from numba import njit


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
