"""The inner problem (thesis 3.4.1): where each finger first touches the contour at a pose.

For a pose and a finger, the grasp point is where the fingertip *first* touches
the EFD contour while it closes, ``0 <= lam <= travel``. The thesis's
least-squares form (eq 3.24) has a zero wherever the trajectory crosses the
contour, so for a ray that enters and leaves the object it has two; only the
first is physical, because the finger stops there. It is solved exactly, by
intersecting every trajectory chord with the EFD contour sampled as a polygon
(``tolerances.EFD_SAMPLES`` points, :func:`first_touch`), then moved onto the
curve itself by Newton's method on the residual of eq 3.26-3.27 (:func:`newton`).
A finger whose trajectory never meets the contour *misses*; the plan reports
its closest approach (:func:`closest_approach`).
"""

from __future__ import annotations

import numpy as np

from ..contour import evaluate, evaluate_derivatives
from .. import tolerances as tol
from ..contour import EFD
from ..hand import Hand, HandSegments, rotation, to_image
from ._derived import hand_arrays, polygon
from ._touch_kernels import nearest_point_segment, pose_first_touch


def first_touch(
    contour: np.ndarray, contour_t: np.ndarray, period: float, segments: HandSegments, n_fingers: int, poses: np.ndarray
):
    """Solve the inner problem for every pose and finger: the first contact along the closing motion.

    Implements eq 3.22 and 3.23: xi = (t_i, lam_i) minimising h under the constraints l(xi) <= 0
    (eq 3.28-3.31, see :func:`newton`), taken as the first crossing of each trajectory with the
    contour polygon. This is the numpy formulation, every chord against every edge; the search
    runs its compiled equivalents (:func:`solve`, :func:`contourgrasp.synthesis.grid.screen_grid`).

    Parameters
    ----------
    contour : (m, 2) float
        Closed polygon sampling the EFD curve at parameters ``contour_t`` (m,), increasing.
    contour_t : (m,) float
    period : float
        T of the EFD; the last edge runs from ``contour_t[-1]`` to ``period``.
    segments : HandSegments
        Trajectory chords in the hand frame.
    n_fingers : int
    poses : (p, 3) float

    Returns
    -------
    lam : (p, f) float
        Distance travelled at first contact, ``inf`` where the finger misses.
    t : (p, f) float
        EFD parameter of the contact (NaN where missed).
    point : (p, f, 2) float
        Contact point in the image plane (NaN where missed).
    start_inside : (p, f) bool
        The fingertip starts inside the contour.
    """
    R = rotation(poses[:, 2])
    p = poses[:, None, :2] + np.einsum("pij,sj->psi", R, segments.start)
    d = np.einsum("pij,sj->psi", R, segments.end - segments.start)
    q = contour
    e = np.roll(q, -1, axis=0) - q
    dt = np.diff(np.append(contour_t, period))

    denom = d[..., 0, None] * e[:, 1] - d[..., 1, None] * e[:, 0]
    p_cross_e = p[..., 0, None] * e[:, 1] - p[..., 1, None] * e[:, 0]
    q_cross_e = q[:, 0] * e[:, 1] - q[:, 1] * e[:, 0]
    q_cross_d = q[:, 0] * d[..., 1, None] - q[:, 1] * d[..., 0, None]
    p_cross_d = (p[..., 0] * d[..., 1] - p[..., 1] * d[..., 0])[..., None]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = (q_cross_e - p_cross_e) / denom
        v = (q_cross_d - p_cross_d) / denom
    crosses_edge = (np.abs(denom) > tol.PARALLEL) & (v >= 0) & (v < 1)
    hit = crosses_edge & (u >= 0) & (u <= 1)
    # Parity of the crossings of each finger's first chord, extended to a half-line, tells
    # whether its start lies inside the contour (even-odd rule) at no extra cost.
    first_chord = np.searchsorted(segments.finger, np.arange(n_fingers))
    start_inside = np.count_nonzero(crosses_edge[:, first_chord] & (u[:, first_chord] >= 0), axis=2) % 2 == 1
    lam_seg = np.where(hit, segments.lam0[:, None] + u * segments.length[:, None], np.inf)
    edge = np.argmin(lam_seg, axis=2)
    lam_seg = np.take_along_axis(lam_seg, edge[..., None], 2)[..., 0]
    v_seg = np.take_along_axis(v, edge[..., None], 2)[..., 0]

    n = len(poses)
    rows = np.arange(n)
    lam = np.full((n, n_fingers), np.inf)
    t = np.full((n, n_fingers), np.nan)
    point = np.full((n, n_fingers, 2), np.nan)
    for i in range(n_fingers):
        own = np.flatnonzero(segments.finger == i)
        best = own[np.argmin(lam_seg[:, own], axis=1)]
        lam[:, i] = lam_seg[rows, best]
        k, frac = edge[rows, best], v_seg[rows, best]
        touched = np.isfinite(lam[:, i])
        t[touched, i] = contour_t[k[touched]] + frac[touched] * dt[k[touched]]
        point[touched, i] = q[k[touched]] + frac[touched, None] * e[k[touched]]
    return lam, t, point, start_inside


def solve(model: EFD, hand: Hand, poses: np.ndarray, samples: int = tol.EFD_SAMPLES):
    """The inner problem at each of a list of poses, exactly: polygon contacts compiled, then :func:`newton`.

    Parameters
    ----------
    model : EFD
    hand : Hand
    poses : (p, 3) float
    samples : int
        Points of the EFD polygon the fingers are intersected with first.

    Returns
    -------
    lam, t, point, start_inside
        As for :func:`first_touch`, with contacts on the curve (``lam`` inf where missed).
    """
    contour_t, contour = polygon(model, samples)
    arrays = hand_arrays(hand)
    segments, n_f = arrays.segments, len(hand.fingers)
    lam, t, point, start_inside = pose_first_touch(
        contour, contour_t, model.T, poses, segments.start, segments.end - segments.start, segments.finger,
        segments.lam0, arrays.first, n_f, tol.PARALLEL,
    )
    t, lam, point = newton(model, hand, poses, t, lam, point, np.isfinite(lam), model.T / samples)
    return lam, t, point, start_inside


def residual(r: np.ndarray, xy: np.ndarray, R: np.ndarray, local: np.ndarray) -> np.ndarray:
    """(n, 2) float: (d_x, d_y), contour point minus trajectory point, of each (pose, finger) pair.

    Implements eq 3.26 and 3.27, with the trajectory point (eq 3.18 or 3.20) placed at its pose:
    ``r`` (n, 2) are contour points, ``xy`` (n, 2) and ``R`` (n, 2, 2) the poses' positions and
    rotations, ``local`` (n, 2) the fingertips in the hand frame.
    """
    return r - xy - np.einsum("pij,pj->pi", R, local)


def newton(model: EFD, hand: Hand, poses, t, lam, point, touching, t_step, iterations: int = 4):
    """Newton on r(t) - p(lam) = 0 from the polygon's contacts; keeps the polygon's answer where it fails.

    Implements eq 3.24, 3.25, 3.28, 3.29, 3.30 and 3.31: h = 1/2 sum d_i^2, d_i = |(d_x, d_y)| of
    :func:`residual`, is driven to zero by Newton's method on the residual itself, and a
    step is kept only where it lands with ``0 <= lam <= F`` (eq 3.28-3.29), within two polygon
    steps of its start (the first touch, not another zero of h) and with t reduced to [0, T)
    (eq 3.30-3.31).

    Every touching (pose, finger) pair iterates at once: the curve is evaluated for all of them
    together, which is most of the work. From the polygon's contacts (within ~1e-5 m) Newton
    converges in two or three steps; it stops once no step exceeds 1e-12 m.

    Parameters
    ----------
    model : EFD
    hand : Hand
    poses : (p, 3) float
    t, lam : (p, f) float
        The polygon's contacts.
    point : (p, f, 2) float
    touching : (p, f) bool
    t_step : float
        The polygon's parameter step, T / samples.
    iterations : int

    Returns
    -------
    t, lam : (p, f) float
    point : (p, f, 2) float
        Copies, moved onto the curve where Newton converged.
    """
    t, lam, point = t.copy(), lam.copy(), point.copy()
    rows, fingers = np.nonzero(touching)
    R = rotation(poses[rows, 2])
    xy = poses[rows, :2]
    t_i, lam_i = t[rows, fingers], lam[rows, fingers]
    paths = _Paths(hand, fingers)
    for _ in range(iterations):
        local, direction = paths.at(lam_i)
        r, dr = evaluate_derivatives(model, t_i, (0, 1))
        F = residual(r, xy, R, local)
        dp = np.einsum("pij,pj->pi", R, direction)
        det = -dr[:, 0] * dp[:, 1] + dp[:, 0] * dr[:, 1]
        det = np.where(np.abs(det) > 1e-12, det, np.inf)
        step_t = (F[:, 0] * dp[:, 1] - F[:, 1] * dp[:, 0]) / det
        step_lam = (dr[:, 1] * F[:, 0] - dr[:, 0] * F[:, 1]) / det
        t_i, lam_i = t_i + step_t, lam_i + step_lam
        if not (np.abs(step_t) > 1e-12).any() and not (np.abs(step_lam) > 1e-12).any():
            break
    local, _ = paths.at(lam_i, tangents=False)
    r = evaluate(model, t_i)
    gap = np.linalg.norm(residual(r, xy, R, local), axis=1)
    travel = hand_arrays(hand).travel[fingers]
    ok = (gap < 1e-9) & (lam_i >= 0) & (lam_i <= travel) & (np.abs(t_i - t[rows, fingers]) < 2 * t_step)
    rows, fingers = rows[ok], fingers[ok]
    t[rows, fingers] = t_i[ok] % model.T
    lam[rows, fingers] = lam_i[ok]
    point[rows, fingers] = r[ok]
    return t, lam, point


class _Paths:
    """The trajectories of fingers ``fingers`` (n,) int of a hand, evaluated together at every Newton step.

    Rays in one expression, arcs finger by finger; what does not change between steps is indexed once.
    """

    def __init__(self, hand: Hand, fingers: np.ndarray):
        arrays = hand_arrays(hand)
        self.starts, self.rays = arrays.starts[fingers], arrays.rays[fingers]
        on_arcs = np.unique(fingers[np.isnan(self.rays[:, 0])])
        self.arcs = [(hand.fingers[f], fingers == f) for f in on_arcs]

    def at(self, lam, tangents: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Hand-frame points and unit tangents (both (n, 2)) after travelling ``lam`` (n,); tangents of arcs
        only if ``tangents``."""
        direction = self.rays.copy()
        points = self.starts + lam[:, None] * direction
        for finger, rows in self.arcs:
            points[rows] = finger.points(lam[rows])
            if tangents:
                direction[rows] = finger.tangent(lam[rows])
        return points, direction


def closest_approach(model: EFD, finger, pose, samples: int = tol.EFD_SAMPLES, chords: int = 64):
    """Closest approach of a finger's trajectory to the EFD contour at a pose.

    The contour is its ``samples``-point polygon and the trajectory a
    ``chords``-chord polyline; the distance between the two polylines is exact
    (vertex-to-segment both ways).

    Parameters
    ----------
    model : EFD
    finger : Finger
    pose : (3,) float
    samples, chords : int

    Returns
    -------
    t : float
        EFD parameter of the nearest contour point.
    lam : float
        Distance travelled to the nearest trajectory point, m.
    point : (2,) float
        The nearest contour point.
    gap : float
        Their distance, m.
    """
    lam = np.linspace(0.0, finger.travel, chords + 1)
    path = to_image(finger.points(lam), pose)
    t, contour = polygon(model, samples)
    edges = np.roll(contour, -1, axis=0) - contour
    steps = np.diff(path, axis=0)
    # path vertices against contour edges, then contour vertices against path chords
    i, k, s1, gap1 = nearest_point_segment(path, contour, edges)
    k2, j, s2, gap2 = nearest_point_segment(contour, path[:-1], steps)
    if gap1 <= gap2:
        return float(t[k] + s1 * model.T / samples), float(lam[i]), contour[k] + s1 * edges[k], gap1
    return float(t[k2]), float(lam[j] + s2 * (lam[j + 1] - lam[j])), contour[k2].copy(), gap2  # not a view of the shared polygon
