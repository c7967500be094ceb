"""Descent check: does the open hand, lowered onto the scene, pass above the height map?

:func:`descent_clearance` and :func:`descent_feasible` are the exact check of candidate poses;
:func:`~contourgrasp.synthesis.search` applies it, given a :class:`Descent`, to its candidates in
increasing cost (:func:`check_candidates`) until it finds feasible ones, and :func:`descent_floor`
tells how low each pose's open hand can go.

The model
---------
A planar pose (x, y, yaw) places the 3-D hand frame as :func:`contourgrasp.pipeline.hand_pose`
does: its x, y axes the planning frame's turned by yaw, its z axis the planning z (the approach
axis, into the table). The open hand (closing progress s = 0) descends along that axis until its
lowest fingertip -- the lowest of the chains' tips (:func:`~contourgrasp.hand.chain_tip`, the
centre of the distal link's end cap, the point the simulation's ``tip_depth`` measures) -- is
``tip_height`` above the table. Heights of hand points are the map's, along the table's normal
(:meth:`HeightMap.height_of`), so a slightly tilted table normal is taken exactly.

Bodies: per finger (in the hand's order) its post and links -- a planar chain's proximal and
distal capsules, a sampled chain's links -- (:func:`~contourgrasp.hand.chain_capsules` at s = 0,
radius ``chain.radius``), then the palm slab (its outline, ``thickness`` above its underside, whose
lowest point over a cell is the underside there: z = 0, or the plane :attr:`~contourgrasp.hand.Palm.plane`
of a tilted palm), named by :func:`body_names`.

Why the final pose decides the whole descent
--------------------------------------------
The height map is a 2.5-D solid: every cell a column filled from the table up to its height. The
hand moves by a pure translation along those columns, so the set of cells under each body does
not change on the way down and every body point only gets lower. A body passes above a cell for
the whole descent exactly when its lowest point over that cell, at the end, is above the cell's
height: the clearance of a body is ``min over the cells under it of (height of the body's lowest
point over the cell, at the grasp pose) - (cell's height)``. Negative: the body strikes that
cell's surface on the way down, by that much.

Cells
-----
A cell is represented by its centre: it is under a body when the vertical line through its centre
meets the body, and the body's lowest point over it is taken on that line (the map's value is
already the highest surface point of the whole cell's column). The discretisation error is that
of moving a body horizontally by up to half a cell's diagonal (1.4 mm at 2 mm cells); a margin
(``descent_feasible(margin=...)``) covers it when needed.

Unseen cells take the map's conservative upper bound (:meth:`HeightMap.conservative`, never free
space); a body over a cell out of the camera's view (+inf) or off the grid gets clearance -inf.

Lowest point of a capsule over a vertical line (exact)
-------------------------------------------------------
A capsule (axis A -> B, length L, unit axis u, radius r) is the union of a finite cylinder and the
balls at its ends, so its lowest point on a vertical line (z down, the largest z) is the largest of
the three parts' lowest points:

* the ball at A: ``z = A_z + sqrt(r^2 - d^2)`` where the line's horizontal distance d from A is
  at most r (the same for B);
* the cylinder's lateral surface: on the line ``P = (q, z)``, with ``w0 = (q - A_xy, 0)``,
  ``a = w0 . u`` and ``b = u_z``, ``|P - A|^2 - ((P - A) . u)^2 = r^2`` reads, for
  ``z' = z - A_z``, ``(1 - b^2) z'^2 - 2 a b z' + |w0|^2 - a^2 - r^2 = 0``; its larger root
  ``z' = (a b + sqrt(a^2 b^2 - (1 - b^2)(|w0|^2 - a^2 - r^2))) / (1 - b^2)`` is the lowest point
  of the infinite cylinder, kept when its axial coordinate ``t = a + z' b`` lies in [0, L]
  (otherwise the finite cylinder's lowest point on the line is on an end disc, inside that end's
  ball, which already counts). A vertical axis (``1 - b^2`` ~ 0, the posts) has only the balls'.

For a finger leaning outward by ``tilt`` and a wall edge of height H crossed by its distal link,
this gives the lean rule: the tip must start ``r / cos(tilt) + tan(tilt) (H - h_tip)``
outside the edge (the vertical half-thickness of an inclined cylinder is ``r / sin(tilt)``
about its axis).

Cost
----
Per pose, each capsule is evaluated on the cells of a square window around its footprint (the
window's half-side its footprint's bounding radius plus a cell), and the palm on the cells of its
outline's window with an even-odd point-in-polygon test: about 10^4 cells a pose for the presets,
in batches of poses. See the README for the measured time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import cached_property, lru_cache, partial

import numpy as np

from .. import validation
from ..errors import HandError, PerceptionError, PlannerError
from ..hand import Hand, chain_capsules, chain_tip, link_names
from ..perception.height_map import HeightMap
from ..tolerances import DESCENT_BATCH, DESCENT_MARGIN, MAX_DESCENT_POSES, MAX_HAND_SIZE
from ._descent_kernels import map_clearances
from .sweep import closing_hits, link_first, obstacle_map, obstacle_table

#: Clearances within this of the margin pass (m): a pose raised to exactly the margin keeps it up to rounding.
_ROUNDING = 1e-9


@dataclass(frozen=True, eq=False)
class DescentCheck:
    """What :func:`descent_feasible` found.

    Attributes
    ----------
    feasible : (p,) bool
        Every body clears the map by at least ``margin`` over the whole descent.
    clearance : (p, n_bodies) float
        :func:`descent_clearance`, m.
    blocking : (p,) int
        Index into ``bodies`` of the body with the least clearance where infeasible, -1 where feasible.
    bodies : tuple of str
        :func:`body_names`.
    margin : float
        The clearance asked for, m.
    tip_height : (p,) float
        The grasp height each pose was checked at, m.
    poses : (p, 3) float
        The poses checked.
    exact : bool
        False when checked with ``refuse_below``: a pose found below it has that body's clearance as an
        upper bound and the bodies not walked +inf; its ``blocking`` and :meth:`reason` say only that it is
        refused.
    """

    feasible: np.ndarray
    clearance: np.ndarray
    blocking: np.ndarray
    bodies: tuple[str, ...]
    margin: float
    tip_height: np.ndarray
    poses: np.ndarray
    exact: bool = True

    def reason(self, i: int) -> str:
        """Why pose ``i`` is refused (or that it is not), e.g. "the index distal strikes the map 3.0 mm deep"."""
        b = int(self.blocking[i])
        if b < 0:
            return f"the open hand clears the height map by {1000 * float(self.clearance[i].min()):.1f} mm"
        c = float(self.clearance[i, b])
        if c == -math.inf:
            return f"the {self.bodies[b]} passes over cells out of the camera's view or off the height map"
        if c < 0:
            return f"the {self.bodies[b]} strikes the height map {1000 * -c:.1f} mm deep while descending"
        return (f"the {self.bodies[b]} clears the height map by only {1000 * c:.1f} mm "
                f"(margin {1000 * self.margin:g} mm)")


@dataclass(frozen=True, eq=False)
class Descent:
    """What :func:`~contourgrasp.synthesis.search` checks the open hand's descent against.

    A candidate pose's hand descends until its lowest fingertip is ``tip_height`` above the table;
    where a body would pass less than ``margin`` above the map on the way, the hand stops higher,
    as high as that body needs (:func:`descent_floor`), but no higher than ``max_tip_height``:
    above it the pose is infeasible.

    Attributes
    ----------
    heights : HeightMap
        The scene, in the planning frame of the contour searched.
    tip_height : float
        The grasp height asked for: the open hand's lowest fingertip (tip centre) above the table
        at the end of the descent, m.
    max_tip_height : float
        The highest grasp height accepted, m (at least ``tip_height``; equal: no raising).
    margin : float
        Clearance every body keeps over the map, m (``tolerances.DESCENT_MARGIN``).
    sweep : bool
        Also refuse a pose where a touching finger's chain meets the scene before its tip reaches
        its grasp point (:func:`~contourgrasp.synthesis.sweep.link_first`).
    closing : bool
        Also refuse a pose where a finger's chain, closing, runs into one of the map's obstacles -- a
        neighbouring object, a bin's wall (:func:`~contourgrasp.synthesis.sweep.closing_hits`).
    """

    heights: HeightMap
    tip_height: float
    max_tip_height: float
    margin: float = DESCENT_MARGIN
    sweep: bool = False
    closing: bool = False

    def __post_init__(self):
        if not isinstance(self.heights, HeightMap):
            raise PerceptionError(f"Descent.heights must be a HeightMap, got {type(self.heights).__name__}")
        validation.finite("tip_height", self.tip_height, error=PlannerError)
        validation.finite("max_tip_height", self.max_tip_height, error=PlannerError)
        if self.max_tip_height < self.tip_height:
            raise PlannerError(f"max_tip_height ({self.max_tip_height:g} m) is below tip_height ({self.tip_height:g} m)")
        validation.bounded("margin", self.margin, MAX_HAND_SIZE, " m", error=PlannerError)
        validation.flag("sweep", self.sweep, error=PlannerError)
        validation.flag("closing", self.closing, error=PlannerError)

    @cached_property
    def closing_map(self) -> tuple[HeightMap, np.ndarray] | None:
        """With ``closing`` and a map that has obstacle cells: their map alone and its summed-area table
        (:func:`~contourgrasp.synthesis.sweep.obstacle_map`, :func:`~contourgrasp.synthesis.sweep.obstacle_table`),
        found once for every batch of candidates; else None."""
        if not self.closing or not self.heights.obstacles.any():
            return None
        only = obstacle_map(self.heights)
        return only, obstacle_table(only)


def body_names(hand: Hand) -> tuple[str, ...]:
    """Names of the bodies of :func:`descent_clearance`'s columns: "<finger> <part>" per finger and capsule of its
    chain (:func:`~contourgrasp.hand.link_names`), then "palm"."""
    _check_hand(hand)
    return _open_hand(hand).names


@dataclass(frozen=True, eq=False)
class _OpenHand:
    """The open hand's bodies (hand frame), found once per hand: the search checks it batch after batch."""

    capsules: np.ndarray  # (bodies - 1, 2, 3)
    radii: np.ndarray  # (bodies - 1,)
    tips: np.ndarray  # (n_fingers, 3)
    names: tuple[str, ...]


@lru_cache(maxsize=16)
def _open_hand(hand: Hand) -> _OpenHand:
    capsules = [chain_capsules(c, 0.0)[0] for c in hand.chains]
    radii = np.repeat([c.radius for c in hand.chains], [len(e) for e in capsules]).astype(float)
    names = tuple(f"{f.name} {part}" for f, c in zip(hand.fingers, hand.chains, strict=True)
                  for part in link_names(c)) + ("palm",)
    arrays = np.concatenate(capsules), radii, np.array([chain_tip(c, 0.0)[0] for c in hand.chains])
    for array in arrays:
        array.flags.writeable = False  # shared by every check of this hand
    return _OpenHand(*arrays, names=names)


def descent_clearance(hand: Hand, heights: HeightMap, poses, tip_height) -> np.ndarray:
    """Smallest vertical clearance of each body of the open hand over the height map during its descent.

    Parameters
    ----------
    hand : Hand
        A 3-D hand (:attr:`Hand.is_3d`).
    heights : HeightMap
        The scene, in the planning frame the poses are in.
    poses : (p, 3) float
        Planar poses (x, y, yaw) in the planning frame, m and rad.
    tip_height : float or (p,) float
        Height above the table of the open hand's lowest fingertip (tip centre) at the end of the descent, m.

    Returns
    -------
    (p, n_bodies) float
        Per pose and body (:func:`body_names`), m: the least over the cells under the body of its
        lowest point's height minus the cell's (module docstring); +inf for a body over no cell,
        -inf over a cell out of view or off the grid. Negative: the body strikes.

    Raises
    ------
    HandError
        ``hand`` is not a Hand, or has no 3-D geometry.
    PerceptionError
        ``heights`` is not a HeightMap, or its table normal is not along the approach axis.
    PlannerError
        ``poses`` or ``tip_height`` not finite or of the wrong shape.
    """
    return _clearance(hand, heights, poses, tip_height)


def _clearance(hand: Hand, heights: HeightMap, poses, tip_height, refuse_below: float | None = None) -> np.ndarray:
    _check_hand(hand)
    poses, tip, normal = _check_inputs(heights, poses, tip_height)
    bodies = _open_hand(hand)
    base = height_base(hand, poses, tip, normal)
    stop = None if refuse_below is None else np.full(len(poses), refuse_below)
    return map_clearances(heights, hand, poses, base, bodies.capsules, bodies.radii, stop)


def height_base(hand: Hand, poses, tip_height, normal) -> np.ndarray:
    """(p,) float: per pose the offset b with which a hand point at planning (x, y) and hand depth z is
    ``normal . (x, y, z) + b`` above the table, when the open hand's lowest tip is ``tip_height`` up.

    The palm's planning depth cancels out: it is fixed by the lowest tip's height.
    """
    tips = _open_hand(hand).tips
    c, s = np.cos(poses[:, 2])[:, None], np.sin(poses[:, 2])[:, None]
    tip_x = poses[:, :1] + c * tips[None, :, 0] - s * tips[None, :, 1]
    tip_y = poses[:, 1:2] + s * tips[None, :, 0] + c * tips[None, :, 1]
    return tip_height - (normal[0] * tip_x + normal[1] * tip_y + normal[2] * tips[None, :, 2]).min(axis=1)


def descent_feasible(hand: Hand, heights: HeightMap, poses, tip_height, *, margin: float = 0.0,
                     refuse_below: float | None = None) -> DescentCheck:
    """Which poses the open hand can descend to without any body passing below the map (plus ``margin``).

    Parameters are :func:`descent_clearance`'s, ``margin`` (m, in [0, ``MAX_HAND_SIZE``]) the
    clearance every body must keep, and ``refuse_below`` (m, optional) a clearance below which a pose
    is refused whatever its other bodies: its walk over the map stops there (``DescentCheck.exact``
    False). The search passes what no raising of the grasp height can make up for; the feasible
    poses' clearances are exact either way.

    Returns
    -------
    DescentCheck
        Feasibility per pose, the clearances, and the body that blocks first (the least clearance).

    Raises
    ------
    HandError, PerceptionError, PlannerError
        As :func:`descent_clearance`; PlannerError for a bad ``margin``.
    """
    margin = validation.bounded("margin", margin, MAX_HAND_SIZE, " m", error=PlannerError)
    if refuse_below is not None:
        refuse_below = validation.finite("refuse_below", refuse_below, error=PlannerError)
    clearance = _clearance(hand, heights, poses, tip_height, refuse_below)
    worst = clearance.argmin(axis=1) if clearance.size else np.zeros(0, dtype=int)
    feasible = clearance.min(axis=1) >= margin - _ROUNDING if len(clearance) else np.zeros(0, dtype=bool)
    tip = np.broadcast_to(np.asarray(tip_height, dtype=float), (len(clearance),)).copy()
    return DescentCheck(feasible=feasible, clearance=clearance, blocking=np.where(feasible, -1, worst),
                        bodies=body_names(hand), margin=margin, tip_height=tip,
                        poses=np.asarray(poses, dtype=float).reshape(-1, 3), exact=refuse_below is None)


def descent_floor(hand: Hand, heights: HeightMap, poses) -> np.ndarray:
    """(p,) float: the lowest height above the table each pose's open hand can bring its lowest tip to.

    The hand moves by a translation along the approach axis, so every clearance of
    :func:`descent_clearance` grows one for one with ``tip_height``: the floor is the tip height at
    which the least clearance is zero (+inf where a body passes out of view, -inf over no cell).
    """
    clearance = descent_clearance(hand, heights, poses, 0.0)
    return -clearance.min(axis=1) if clearance.size else np.zeros(len(clearance))


def check_candidates(hand: Hand, descent: Descent, poses, order, lam=None,
                     touching=None) -> tuple[np.ndarray, np.ndarray, DescentCheck | None]:
    """The descent check of candidate poses in the given order, a batch at a time, until a batch has a feasible one.

    Parameters
    ----------
    hand : Hand
    descent : Descent
    poses : (p, 3) float
    order : (m,) int
        Indices into ``poses`` to check, best first.
    lam, touching : (p, f) float and bool, optional
        The poses' inner problem (:class:`~contourgrasp.synthesis.PoseEvaluation`), for ``descent.sweep``
        and ``descent.closing``.

    Returns
    -------
    passed : (p,) bool
        True for the checked poses whose hand descends clear to a grasp height at most
        ``descent.max_tip_height`` (and closes clear, with ``descent.sweep`` or ``descent.closing``);
        every pose not checked is False.
    tip_height : (p,) float
        The grasp height of each checked pose: ``descent.tip_height``, or higher where a body needs it
        (NaN where not checked).
    last : DescentCheck or None
        The check at ``descent.tip_height`` of the last batch in which some pose descended clear
        (:func:`descends_clear`: a closing check refused it), else of the last batch -- for the
        reason none passed; None when ``order`` is empty.

    At most ``tolerances.MAX_DESCENT_POSES`` poses are checked.
    """
    passed = np.zeros(len(poses), dtype=bool)
    tip = np.full(len(poses), np.nan)
    last = cleared = None
    order = np.asarray(order, dtype=np.intp)[:MAX_DESCENT_POSES]
    for a in range(0, len(order), DESCENT_BATCH):
        rows = order[a:a + DESCENT_BATCH]
        last = descent_feasible(hand, descent.heights, poses[rows], descent.tip_height, margin=descent.margin,
                                refuse_below=descent.margin - (descent.max_tip_height - descent.tip_height) - _ROUNDING)
        raised = _raised(last)
        tip[rows] = raised
        passed[rows] = raised <= descent.max_tip_height
        cleared = last if passed[rows].any() else cleared
        if descent.sweep and lam is not None:  # the sweeps of the poses still passing only: the costly part
            keep = passed[rows]
            passed[rows[keep]] = ~_swept(link_first, hand, descent.heights, poses[rows[keep]], raised[keep],
                                         lam[rows[keep]], touching[rows[keep]])
        if descent.closing_map is not None and lam is not None:
            obstacles, table = descent.closing_map
            keep = passed[rows]
            passed[rows[keep]] = ~_swept(partial(closing_hits, table=table), hand, obstacles, poses[rows[keep]],
                                         raised[keep], lam[rows[keep]], touching[rows[keep]])
        if passed[rows].any():
            break
    return passed, tip, cleared or last


def descends_clear(descent: Descent, check: DescentCheck | None) -> bool:
    """Whether some pose of ``check`` descends clear within ``descent.max_tip_height`` (raised where it must be)."""
    return check is not None and bool((_raised(check) <= descent.max_tip_height).any())


def _raised(check: DescentCheck) -> np.ndarray:
    """(p,) float: each checked pose's grasp height raised by what its least clearance lacks of the margin."""
    return check.tip_height + np.maximum(check.margin - check.clearance.min(axis=1), 0.0)


def blocked_by_obstacles(hand: Hand, descent: Descent, check: DescentCheck) -> bool:
    """Whether some pose ``check`` refused would descend clear but for the map's obstacle cells (neighbours, bin walls)."""
    heights = descent.heights
    if not heights.obstacles.any():
        return False
    bare = replace(heights, heights=np.where(heights.obstacles, 0.0, heights.heights),
                   obstacles=np.zeros_like(heights.obstacles))
    tip = np.full(len(check.poses), descent.max_tip_height)
    return bool(descent_feasible(hand, bare, check.poses, tip, margin=descent.margin).feasible.any())


def _swept(check, hand, heights, poses, tip, lam, touching) -> np.ndarray:
    """(p,) bool: some finger fails a closing-sweep ``check`` (:func:`link_first`, :func:`closing_hits`) per pose."""
    base = height_base(hand, poses, tip, np.asarray(heights.table_normal, dtype=float))
    return np.array([check(hand, heights, pose, b, l, t).any()
                     for pose, b, l, t in zip(poses, base, lam, touching)], dtype=bool)


def _check_hand(hand) -> None:
    if not isinstance(hand, Hand):
        raise HandError(f"hand must be a contourgrasp.Hand, got {type(hand).__name__}")
    if not hand.is_3d:
        raise HandError(f"hand {hand.name!r} has no 3-D geometry (finger chains and a palm): "
                        "the descent check needs the hand's bodies")


def _check_inputs(heights, poses, tip_height):
    if not isinstance(heights, HeightMap):
        raise PerceptionError(f"heights must be a contourgrasp.perception.HeightMap, got {type(heights).__name__}")
    normal = np.asarray(heights.table_normal, dtype=float)
    if normal.shape != (3,) or not np.isfinite(normal).all() or normal[2] > -0.5:
        raise PerceptionError(f"heights.table_normal must point up the approach axis (z component < -0.5), "
                              f"got {heights.table_normal!r}")
    poses = validation.finite_array("poses", poses, (None, 3), error=PlannerError)
    tip = validation.float_array("tip_height", tip_height, error=PlannerError)
    if tip.ndim == 0:
        tip = np.full(len(poses), float(tip))
    if tip.shape != (len(poses),):
        raise PlannerError(f"tip_height must be a number or one per pose ({len(poses)}), got shape {tip.shape}")
    validation.finite_array("tip_height", tip, error=PlannerError)
    return poses, tip, normal


