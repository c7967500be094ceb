"""The outer problem's cost (thesis 3.4.2, eq 3.34-3.38) and its constraint on the fingers' starts (eq 3.41).

The cost of a pose has three parts, summed over touching fingers i:

* curvature: alpha_i * C(t_i), with C the signed curvature of
  :func:`contourgrasp.contour.curvature` (concave points lower the cost);
* ratio: beta_i * (dist_i - mean_{j != i} dist_j)^2, with dist the distance
  from the finger's virtual start to its grasp point (eq 3.35-3.36) and the
  mean over the other touching fingers. Eq 3.35 prints the deviation
  without the square; that form sums to zero over the fingers for equal
  gains and cannot steer toward simultaneous contact (see
  :func:`ratio_cost`, ``form="linear"``), and gains of 1e4 against
  distances of centimeters point to a square;
* miss: ``hand.miss_penalty`` per finger that closes on air;
* beyond the thesis, with :class:`Safeguards`: ``-quality_gain * epsilon`` and
  ``centring_gain * (d / CENTRING_SCALE)^2`` (:func:`centring_distance`).

The per-pose loops are compiled (:mod:`contourgrasp.synthesis._cost_kernels`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from .. import tolerances as tol
from ..errors import PlannerError
from ..hand import Hand
from ._cost_kernels import centring_distances, ratio_cost_rows, score_poses
from ._derived import hand_arrays
from .safeguards import Safeguards


@dataclass(frozen=True, eq=False)
class PoseEvaluation:
    """Inner-problem solutions and costs for many poses; arrays are (p,) or (p, n_fingers).

    Attributes
    ----------
    poses : (p, 3) float
    touching : (p, f) bool
        The finger meets the contour within its travel.
    lam : (p, f) float
        Distance travelled to the grasp point, m (NaN where missed).
    t : (p, f) float
        EFD parameter of the grasp point (NaN where missed).
    grasp_point : (p, f, 2) float
        Image-plane grasp point, m (NaN where missed).
    distance : (p, f) float
        dist(t, lambda_virt) of eq 3.36: virtual start to grasp point, m.
    start_distance : (p, f) float
        dist(t, 0): actual start to grasp point, m (eq 3.41).
    curvature : (p, f) float
        Signed curvature at the grasp point (NaN where missed).
    start_inside : (p, f) bool
        The fingertip starts inside the contour.
    starts_outside : (p,) bool
        No fingertip starts inside the contour.
    reaches : (p,) bool
        Every required finger and at least ``min_touching`` fingers touch.
    clear : (p,) bool
        The fingers pass :class:`Safeguards` ``finger_thickness`` (all True when it is off).
    epsilon : (p,) float
        Ferrari-Canny epsilon of the grasp points (NaN where not computed).
    imbalance : (p,) float
        The squeeze's imbalance at the grasp points (:func:`contourgrasp.quality.imbalance`; NaN
        where not computed).
    feasible : (p,) bool
    cost_curvature, cost_ratio, cost_miss, cost_quality, cost_centring, cost : (p,) float
    """

    poses: np.ndarray
    touching: np.ndarray
    lam: np.ndarray
    t: np.ndarray
    grasp_point: np.ndarray
    distance: np.ndarray
    start_distance: np.ndarray
    curvature: np.ndarray
    start_inside: np.ndarray
    starts_outside: np.ndarray
    reaches: np.ndarray
    clear: np.ndarray
    epsilon: np.ndarray
    imbalance: np.ndarray
    feasible: np.ndarray
    cost_curvature: np.ndarray
    cost_ratio: np.ndarray
    cost_miss: np.ndarray
    cost_quality: np.ndarray
    cost_centring: np.ndarray
    cost: np.ndarray


def ratio_cost(
    distance: np.ndarray, touching: np.ndarray, beta: np.ndarray, *, form: Literal["squared", "linear"] = "squared"
) -> np.ndarray:
    """Cost of ratio, summed over touching fingers.

    Implements eq 3.35: ``beta_i * (dist_i - mean_{j != i} dist_j)`` squared (our reading, the
    default) or as printed (``form="linear"``); the mean runs over the other
    *touching* fingers, and a finger with no touching partner costs nothing.

    Parameters
    ----------
    distance : (p, f) float
        dist(t_i, lambda_virt,i) of eq 3.36.
    touching : (p, f) bool
    beta : (f,) float

    Returns
    -------
    (p,) float

    Examples
    --------
    With equal gains the printed form sums to zero whatever the distances:

    >>> d = np.array([[0.01, 0.05, 0.02]])
    >>> abs(float(ratio_cost(d, np.ones((1, 3), bool), np.ones(3), form="linear")[0])) < 1e-15
    True
    """
    if form not in ("squared", "linear"):
        raise PlannerError(f"form must be 'squared' or 'linear', got {form!r}")
    distance = np.where(touching, distance, 0.0).astype(float)
    return ratio_cost_rows(distance, np.asarray(touching, bool), np.asarray(beta, dtype=float), form == "squared")


def distance(p_virt, p_grasp):
    """dist(t, lambda_virt) = |p_virt - p_grasp|: from a (virtual) start point to the grasp point, m.

    Implements eq 3.36 and 3.38: ``p_grasp`` (..., 2) is the contour at the grasp point's t (the
    inner problem's contact), ``p_virt`` (..., 2) the trajectory at lambda_virt (eq 3.37,
    :attr:`contourgrasp.hand.Finger.virtual_start_point`) or, for eq 3.41, at 0. A float for
    one pair of points, a (...) float array for many.

    Examples
    --------
    >>> float(distance([0.0, 0.0], [0.03, 0.04]))
    0.05
    """
    gap = np.asarray(p_virt, dtype=float) - np.asarray(p_grasp, dtype=float)
    return float(np.linalg.norm(gap)) if gap.ndim == 1 else np.linalg.norm(gap, axis=-1)


def centring_distance(hand: Hand, poses, locus, *, n_yaw: int | None = None) -> np.ndarray:
    """(p,) float: distance from ``hand.pinch_centre`` to the object's centre ``locus``, in the hand frame, m.

    It is the distance in the image plane from ``locus`` to the pinch centre placed by the pose, so
    for a grid, whose yaws repeat, the placed centre's offset is computed once per yaw.

    Parameters
    ----------
    hand : Hand
    poses : (p, 3) float
        (x, y, yaw) of the hand in the image plane.
    locus : (2,) float
        The object's centre in the image plane, m.
    n_yaw : int, optional
        The period of the poses' yaws, as for :func:`score` (p a multiple of it); None for any list of poses.

    Examples
    --------
    >>> from contourgrasp import load_hand
    >>> hand = load_hand("five-finger-linear")
    >>> x, y = -hand.pinch_centre  # the hand's origin where the pinch centre falls on the image's origin
    >>> float(centring_distance(hand, np.array([[x, y, 0.0]]), np.zeros(2))[0])
    0.0
    """
    poses = np.asarray(poses, dtype=float)
    period = n_yaw if n_yaw and len(poses) >= n_yaw and len(poses) % n_yaw == 0 else max(len(poses), 1)
    return centring_distances(poses, period, np.asarray(hand.pinch_centre, dtype=float), np.asarray(locus, dtype=float))


def score(hand: Hand, poses, touching, lam, t, point, curv, start_inside, d_min, clear, epsilon,
          safeguards: Safeguards, n_yaw: int | None = None, *, imbalance=None, locus=None) -> PoseEvaluation:
    """Constraints and cost of each pose from the inner problem's solutions.

    Implements eq 3.34 and 3.41: the cost f = sum_i alpha_i C_curvature(t_i) + C_ratio
    (:func:`ratio_cost`, squared) + ``hand.miss_penalty`` per missed finger, and the feasibility of
    each pose: no fingertip starts inside the contour, every required finger and at least
    ``hand.min_touching`` touch, every touching finger starts at least D_min from its grasp point
    (eq 3.41, dist(t_i, 0) of :func:`distance`), plus the :class:`Safeguards`' constraints
    (``clear``, force closure, the squeeze's balance) and cost (``-quality_gain * epsilon``).

    Parameters
    ----------
    hand : Hand
    poses : (p, 3) float
    touching : (p, f) bool
    lam, t, curv : (p, f) float
        The inner problem's solution and the signed curvature there (NaN where missed).
    point : (p, f, 2) float
    start_inside : (p, f) bool
    d_min : float
        D_min, m.
    clear : (p,) bool
        The finger-thickness check (all True when it is off).
    epsilon : (p,) float
        Ferrari-Canny epsilon (NaN where not computed).
    safeguards : Safeguards
    n_yaw : int, optional
        The period of the poses' yaws, for a grid (yaw fastest); None for any list of poses.
    imbalance : (p,) float, optional
        :func:`contourgrasp.quality.imbalance` of the grasp points (NaN or None: not computed).
    locus : (2,) float, optional
        The object's centre in the image plane (the EFD locus), for ``safeguards.centring_gain``
        (None: no centring cost).

    Returns
    -------
    PoseEvaluation
    """
    arrays = hand_arrays(hand)
    (distances, start_distance, outside, reaches, far_enough, cost_curvature, cost_ratio, cost_miss) = score_poses(
        poses, len(poses) if n_yaw is None else n_yaw, touching, point, curv, start_inside, arrays.starts,
        arrays.virtual_starts, arrays.alpha, arrays.beta, arrays.required, hand.min_touching, float(hand.miss_penalty),
        float(d_min),
    )
    feasible = outside & reaches & far_enough & clear
    if safeguards.require_closure:
        feasible &= epsilon > 0
    imbalance = np.full(len(poses), np.nan) if imbalance is None else np.asarray(imbalance, dtype=float)
    if safeguards.balances:
        feasible &= imbalance <= safeguards.max_imbalance
    cost_quality = -safeguards.quality_gain * np.nan_to_num(epsilon) if safeguards.quality_gain else np.zeros(len(poses))
    cost_centring = np.zeros(len(poses))
    if safeguards.centring_gain and locus is not None:
        cost_centring = (safeguards.centring_gain * centring_distance(hand, poses, locus, n_yaw=n_yaw) ** 2
                         / tol.CENTRING_SCALE ** 2)
    return PoseEvaluation(
        poses=poses,
        touching=touching,
        lam=lam,
        t=t,
        grasp_point=point,
        distance=distances,
        start_distance=start_distance,
        curvature=curv,
        start_inside=start_inside,
        starts_outside=outside,
        reaches=reaches,
        clear=clear,
        epsilon=epsilon,
        imbalance=imbalance,
        feasible=feasible,
        cost_curvature=cost_curvature,
        cost_ratio=cost_ratio,
        cost_miss=cost_miss,
        cost_quality=cost_quality,
        cost_centring=cost_centring,
        cost=cost_curvature + cost_ratio + cost_miss + cost_quality + cost_centring,
    )
