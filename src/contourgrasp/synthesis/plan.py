"""What the search returns: the plan, its cost, each finger's contact, and the evaluations of many poses."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..contour import EFD
from ..hand import Hand
from ..quality import GraspQuality

if TYPE_CHECKING:
    from .grid import SearchGrid
    from .safeguards import Safeguards
    from .descent import DescentCheck


@dataclass(frozen=True)
class Cost:
    """The cost of a pose (see eq 3.34) and its parts (``quality``, ``centring``: :class:`Safeguards`' gains)."""

    total: float
    curvature: float
    ratio: float
    miss: float
    quality: float = 0.0
    centring: float = 0.0


@dataclass(frozen=True, eq=False)
class FingerContact:
    """Where one finger meets the object at the chosen pose (image plane, meters).

    For a missed finger, ``grasp_point``, ``t``, ``lam`` are the closest approach
    between its trajectory and the contour, and ``gap`` is their distance.
    """

    name: str
    grasp_point: np.ndarray
    t: float
    lam: float
    curvature: float
    concave: bool
    distance: float
    start: np.ndarray
    virtual_start: np.ndarray
    missed: bool
    gap: float


@dataclass(frozen=True)
class Alternative:
    """A ranked candidate pose (x, y, yaw) and its cost."""

    pose: tuple[float, float, float]
    cost: Cost


@dataclass(frozen=True)
class Refinement:
    """What the continuous refinement of :func:`~contourgrasp.synthesis.search` (``refine=True``) gained over the grid.

    Attributes
    ----------
    grid_pose : (3,) float
        The best grid pose (exactly evaluated), before refinement.
    grid_cost : float
        Its cost (see eq 3.34).
    cost : float
        The plan's cost after refinement, never above ``grid_cost``.
    """

    grid_pose: tuple[float, float, float]
    grid_cost: float
    cost: float

    @property
    def gain(self) -> float:
        """grid_cost - cost, >= 0."""
        return self.grid_cost - self.cost


@dataclass(frozen=True, eq=False)
class GraspPlan:
    """The result of :func:`~contourgrasp.synthesis.search`.

    Attributes
    ----------
    pose : (3,) float
        Best hand pose (x, y, yaw) in the image plane: m, m, rad.
    cost : Cost
    fingers : tuple of FingerContact
    efd : EFD
    hand : Hand
    contour : (n, 2) float
        The input polygon, cleaned, in its input orientation.
    grown : float
        How far the outline ``efd`` models was grown from ``contour``, m: 0, or the fingers' smallest
        radius when the small-object rule planned the fingertips as balls
        (:func:`~contourgrasp.contour.grow_polygon`); the grasp points are then the tips' centres.
    curvature_mode : str
    grid : SearchGrid
    alternatives : tuple of Alternative
        The best distinct poses in increasing cost; the first is ``pose``.
        Distinct: no two are neighbours on the grid in x, y and yaw at once.
    grid_size : int
        Poses evaluated.
    feasible_poses : int
    timing_ms : dict
        Wall time per stage, milliseconds: ``efd`` (contour check and fit), ``search`` (grid
        screen), ``exact`` (exact re-evaluation of the best screened poses), ``refine``
        (continuous refinement, 0 without it) and ``total``.
    refinement : Refinement or None
        The grid's best and the gain of the continuous refinement; None without it.
    safeguards : Safeguards
    quality : contourgrasp.quality.GraspQuality
        Force closure and Ferrari-Canny L1 epsilon of the grasp points (missed fingers excluded).
    descent : DescentCheck or None
        The descent check of ``pose`` (one row: each finger's body's and the palm's clearance over
        the height map); None when the search had no :class:`~contourgrasp.synthesis.Descent`.
    search_notes : tuple of str
        What the search had to give up (e.g. :data:`~contourgrasp.synthesis.outer.NOTE_UNBALANCED`).
    notes : tuple of str
        What the plan could not take into account (a property: :func:`plan_notes`, then ``search_notes``).
    """

    pose: np.ndarray
    cost: Cost
    fingers: tuple[FingerContact, ...]
    efd: EFD
    hand: Hand
    contour: np.ndarray
    curvature_mode: str
    grid: SearchGrid
    alternatives: tuple[Alternative, ...]
    grid_size: int
    feasible_poses: int
    timing_ms: dict
    refinement: Refinement | None
    safeguards: Safeguards
    quality: GraspQuality
    descent: DescentCheck | None = None
    search_notes: tuple[str, ...] = ()
    grown: float = 0.0

    @property
    def notes(self) -> tuple[str, ...]:
        """Notes on what the plan could not take into account (:func:`plan_notes`, then ``search_notes``)."""
        return plan_notes(self.hand) + self.search_notes

    @property
    def balanced(self) -> bool:
        """The squeeze is within the safeguards' ``max_imbalance`` (always, when the balance is off)."""
        return not self.safeguards.balances or self.quality.imbalance <= self.safeguards.max_imbalance


#: The note of a plan made with a hand that has no 3-D geometry.
NOTE_2D_HAND = ("hand {name!r} has no 3-D geometry ([fingers.chain], [palm]): planned in 2-D, "
                "fingertips as points (discs with finger_thickness); finger bodies and palm not considered")


def plan_notes(hand) -> tuple[str, ...]:
    """Notes a plan with ``hand`` carries: :data:`NOTE_2D_HAND` for a hand without chains."""
    return () if hand.is_3d else (NOTE_2D_HAND.format(name=hand.name),)
