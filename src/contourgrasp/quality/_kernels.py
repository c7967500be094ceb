"""Compiled inner loop of :func:`contourgrasp.quality.epsilon_many` for the L1 metric (numba).

The ball radius of a grasp's wrench hull is the least distance of the origin to a supporting
plane through three of its wrenches (see :func:`contourgrasp.quality.wrench_space._ball_radius_batch`). Testing
every triple's plane against every wrench is what numpy does in one broadcast; a loop can skip a
plane whose distance could not lower the least found so far, and stop testing a plane at the first
wrench on each side. Neither changes the result: a skipped plane would only have given a larger
distance, and a plane with wrenches on both sides is no supporting plane (tested against Qhull).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def ball_radii(w, ok, i, j, k, plane_tol, zero_tol):
    """(g,) float: per grasp the least distance of the origin to a supporting plane (inf: none).

    Parameters
    ----------
    w : (g, m, 3) float
        Edge wrenches of g grasps.
    ok : (g, m) bool
        Which wrenches exist.
    i, j, k : (t,) int
        The triples of wrench indices whose planes are tried.
    plane_tol : float
        A triple whose normal is no longer than this spans no plane and is skipped.
    zero_tol : float
        How far on the wrong side of a plane a wrench may lie and the plane still support.
    """
    g, m, _ = w.shape
    out = np.full(g, np.inf)
    for s in range(g):
        best = np.inf
        for t in range(i.shape[0]):
            a, b, c = i[t], j[t], k[t]
            if not (ok[s, a] and ok[s, b] and ok[s, c]):
                continue
            u0, u1, u2 = w[s, b, 0] - w[s, a, 0], w[s, b, 1] - w[s, a, 1], w[s, b, 2] - w[s, a, 2]
            v0, v1, v2 = w[s, c, 0] - w[s, a, 0], w[s, c, 1] - w[s, a, 1], w[s, c, 2] - w[s, a, 2]
            n0, n1, n2 = u1 * v2 - u2 * v1, u2 * v0 - u0 * v2, u0 * v1 - u1 * v0
            length = math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
            if length <= plane_tol:
                continue
            n0, n1, n2 = n0 / length, n1 / length, n2 / length
            h = n0 * w[s, a, 0] + n1 * w[s, a, 1] + n2 * w[s, a, 2]
            below, above = h < best, -h < best  # only a plane nearer than the best can matter
            for q in range(m):
                if not (below or above):
                    break
                if not ok[s, q]:
                    continue
                side = n0 * w[s, q, 0] + n1 * w[s, q, 1] + n2 * w[s, q, 2] - h
                below = below and side <= zero_tol
                above = above and side >= -zero_tol
            if below:
                best = h
            if above and -h < best:
                best = -h
        out[s] = best
    return out
