"""Constraints and a cost term beyond the thesis's, against the failures of its chapter 5.

Finger thickness (:func:`fingers_clear`, failure 5: a finger striking the object on its way) and
grasp quality (:func:`grasp_epsilon`, failure 2: "all grasping points on the same surface";
6.1 item 2) and the squeeze's balance (:func:`grasp_imbalance`, failure 1: the object pushed
away before every finger touches). All off, :class:`Safeguards` is the thesis's problem.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from .. import quality
from .. import tolerances as tol
from .. import validation as check
from ..contour import EFD
from ..errors import PlannerError
from ..hand import Hand, rotation
from ._derived import cached, polygon


@dataclass(frozen=True)
class Safeguards:
    """Constraints and a cost term beyond the thesis's, against the failures of its chapter 5.

    All off (the default) is the thesis's problem. They act where contacts are
    exact (:func:`~contourgrasp.synthesis.evaluate_poses`): :func:`~contourgrasp.synthesis.search`
    screens the grid without them, then applies them to the cheapest candidates, widening the
    candidate set until one passes.

    Attributes
    ----------
    finger_thickness : bool
        Fingers are discs of their hand file's ``radius`` (failure 5, a finger
        striking the object on the way). A pose is rejected when a fingertip
        starts closer than ``radius + clearance`` to the contour, or when the
        disc swept along its trajectory up to the grasp point meets the contour
        farther than ``2 radius`` from the grasp point (the disc of a finger
        meeting a flat side at up to ~60 deg from its normal touches within
        that distance; beyond, it hits another part of the object first). A
        finger that misses must clear the contour by ``radius`` all along.
    clearance : float
        Extra free distance around every open fingertip, m (at most ``tolerances.MAX_SEARCH_LENGTH``):
        the margin for the open finger leaning over its path and for segmentation error.
    friction : float
        mu of the grasp quality (:mod:`contourgrasp.quality`), at most ``tolerances.MAX_FRICTION``.
    require_closure : bool
        Reject poses whose grasp points are not in 2-D force closure (failure 2,
        "all grasping points on the same surface"; 6.1 item 2).
    quality_gain : float
        Cost term ``-quality_gain * epsilon`` (Ferrari-Canny L1, wrenches about
        the EFD locus, torque over the contour's largest radius about it).
    centring_gain : float
        Cost term ``centring_gain * (d / CENTRING_SCALE)^2`` (at most ``tolerances.MAX_CENTRING_GAIN``), d the distance in the hand frame from the
        object's centre (the EFD locus) to the hand's pinch centre (:attr:`Hand.pinch_centre
        <contourgrasp.hand.Hand.pinch_centre>`): prefer poses that put the object between the thumb
        and the finger nearest it (beyond the thesis; README, "The object between thumb and index").
    max_imbalance : float
        Reject poses whose equal pushes along the grasp points' normals leave a net force of
        more than this share of their sum (:func:`contourgrasp.quality.imbalance`; in [0, 1],
        1 = off). Force closure says the contacts *could* hold the object; an underactuated
        hand does not choose its forces, and an unbalanced squeeze pushes the object away
        before the last finger arrives or slides it out as the fingers close. A constraint of
        each evaluation; :func:`~contourgrasp.synthesis.search` prefers it, and plans without it
        (with a note) when no pose meets it. ``"hand"``: the hand's own (:meth:`for_hand`).

    Raises
    ------
    PlannerError
        Naming the attribute that is not a bool or not a number in range.
    """

    finger_thickness: bool = False
    clearance: float = 0.0
    friction: float = 0.5
    require_closure: bool = False
    quality_gain: float = 0.0
    max_imbalance: float | Literal["hand"] = 1.0
    centring_gain: float = 0.0

    def __post_init__(self):
        check.flag("finger_thickness", self.finger_thickness, error=PlannerError)
        check.bounded("clearance", self.clearance, tol.MAX_SEARCH_LENGTH, " m", error=PlannerError)
        check.friction("friction", self.friction, tol.MAX_FRICTION, error=PlannerError)
        check.flag("require_closure", self.require_closure, error=PlannerError)
        check.non_negative("quality_gain", self.quality_gain, error=PlannerError)
        if isinstance(self.max_imbalance, str):
            check.choice("max_imbalance", self.max_imbalance, ("hand",), error=PlannerError)
        else:
            check.bounded("max_imbalance", self.max_imbalance, 1.0, "", error=PlannerError)
        check.bounded("centring_gain", self.centring_gain, tol.MAX_CENTRING_GAIN, "", error=PlannerError)

    def for_hand(self, hand: Hand) -> Safeguards:
        """These safeguards with ``max_imbalance = "hand"`` read as ``hand``'s own (:attr:`Hand.max_imbalance`)."""
        return replace(self, max_imbalance=hand.max_imbalance) if self.max_imbalance == "hand" else self

    @property
    def balances(self) -> bool:
        """The squeeze's imbalance is a constraint."""
        if self.max_imbalance == "hand":
            raise PlannerError('max_imbalance "hand" is read for a hand first (Safeguards.for_hand)')
        return self.max_imbalance < 1.0

    @property
    def grades_quality(self) -> bool:
        """Epsilon is needed for every candidate (not only the plan)."""
        return self.require_closure or self.quality_gain > 0


def fingers_clear(contour, hand: Hand, poses, lam, grasp_point, *, clearance: float = 0.0,
                  samples: int = 9) -> np.ndarray:
    """Finger-thickness check of :class:`Safeguards` for each pose.

    Parameters
    ----------
    contour : (m, 2) float
        The object's polygon (e.g. the EFD curve sampled).
    hand : Hand
        Finger radii from ``Finger.radius``.
    poses : (p, 3) float
    lam : (p, f) float
        Travel to the grasp point; NaN for a finger that misses (it sweeps its whole travel).
    grasp_point : (p, f, 2) float
    clearance : float
        Extra free distance required around every open fingertip, m.
    samples : int
        Points of each swept path (its chords bound arcs to a fraction of a mm).

    Returns
    -------
    (p,) bool
        Every fingertip starts ``radius + clearance`` clear of the contour and
        its swept disc first meets the contour within ``2 radius`` of its grasp point.
    """
    poses = np.atleast_2d(np.asarray(poses, dtype=float))
    p = len(poses)
    edges = np.roll(contour, -1, axis=0) - contour
    rotations = rotation(poses[:, 2])
    u = np.linspace(0.0, 1.0, samples)
    ok = np.ones(p, bool)
    for f, finger in enumerate(hand.fingers):
        reach = np.where(np.isfinite(lam[:, f]), lam[:, f], finger.travel)
        path = finger.points(np.outer(reach, u).ravel()).reshape(p, samples, 2)
        path = np.einsum("pij,pkj->pki", rotations, path) + poses[:, None, :2]
        ok &= _distance_to_segments(path[:, :1], contour[None], edges[None]).min(axis=2)[:, 0] >= (
            finger.radius + clearance)
        if finger.radius == 0:
            continue
        swept = _distance_to_segments(contour[None], path[:, :-1], np.diff(path, axis=1)).min(axis=2) < finger.radius
        with np.errstate(invalid="ignore"):
            elsewhere = ~(np.linalg.norm(contour[None] - grasp_point[:, f, None], axis=2) <= 2 * finger.radius)
        ok &= ~(swept & elsewhere).any(axis=1)
    return ok


def _distance_to_segments(points, starts, vectors) -> np.ndarray:
    """(p, n, k): distance of points (p | 1, n, 2) to segments starts + [0, 1] vectors (p | 1, k, 2)."""
    w = points[:, :, None, :] - starts[:, None, :, :]
    length2 = np.maximum(np.sum(vectors * vectors, axis=-1), np.finfo(float).tiny)[:, None, :]
    s = np.clip(np.einsum("pnki,pki->pnk", w, np.broadcast_to(vectors, (len(w), *vectors.shape[1:]))) / length2,
                0.0, 1.0)
    return np.linalg.norm(w - s[..., None] * vectors[:, None, :, :], axis=-1)


def grasp_epsilon(model: EFD, grasp_point, t, touching, *, friction: float = 0.5) -> np.ndarray:
    """(p,) float: Ferrari-Canny L1 epsilon of each pose's grasp points on the EFD contour.

    Wrenches are taken about the EFD locus (A0, C0) with torques divided by the
    contour's largest radius about it, so that poses of one plan compare
    (:func:`contourgrasp.quality.epsilon_many`); normals are the curve's inward normals.

    Parameters
    ----------
    model : EFD
    grasp_point : (p, f, 2) float
    t : (p, f) float
    touching : (p, f) bool
    friction : float
    """
    return _epsilon(model, grasp_point, *_normals(model, t, touching), friction)


def grade(model: EFD, grasp_point, t, touching, safeguards: Safeguards) -> tuple[np.ndarray, np.ndarray]:
    """(p,) float twice: :func:`grasp_epsilon` and :func:`grasp_imbalance` where ``safeguards`` need them, else NaN.

    The grasp points' normals are found once for both.
    """
    epsilon, imbalance = np.full(len(t), np.nan), np.full(len(t), np.nan)
    if not (safeguards.grades_quality or safeguards.balances):
        return epsilon, imbalance
    normals, valid = _normals(model, t, touching)
    if safeguards.grades_quality:
        epsilon = _epsilon(model, grasp_point, normals, valid, safeguards.friction)
    if safeguards.balances:
        imbalance = quality.imbalance(normals, valid)
    return epsilon, imbalance


def _epsilon(model: EFD, grasp_point, normals, valid, friction: float) -> np.ndarray:
    rho = cached(model, "rho", lambda: float(np.linalg.norm(polygon(model)[1] - model.locus, axis=1).max()))
    return quality.epsilon_many(grasp_point, normals, valid, mu=friction, centre=model.locus, rho=rho)


def grasp_imbalance(model: EFD, t, touching) -> np.ndarray:
    """(p,) float: :func:`contourgrasp.quality.imbalance` of each pose's grasp points on the EFD contour.

    Parameters
    ----------
    model : EFD
    t : (p, f) float
    touching : (p, f) bool
    """
    return quality.imbalance(*_normals(model, t, touching))


def _normals(model: EFD, t, touching) -> tuple[np.ndarray, np.ndarray]:
    """Inward normals (p, f, 2) at the touching fingers' grasp points, and where they exist (p, f)."""
    normals = quality.contour_normals(model, np.where(touching, t, 0.0))
    return normals, touching & np.isfinite(normals).all(axis=-1)
