"""Closing sweep: what each finger's chain meets while it closes.

The thesis's fingertip is a point on a ray or an arc: it meets the contour after travelling
``lambda`` (eq 3.22). The 3-D finger is a chain of capsules that sweeps a surface while it closes,
and on a tall object its distal or proximal link may meet the object's side before the tip reaches
its grasp point -- the finger then stops (or pushes) there, and the planned grasp points and the
ratio cost describe a grasp the hand does not make.

:func:`link_first` checks it on the scene's height map, the 2.5-D solid of
:mod:`~contourgrasp.synthesis.descent`: with the open hand at its grasp height, each touching
finger's links (a planar chain's proximal and distal capsules) are placed at
``tolerances.SWEEP_SAMPLES`` closing progresses whose tips have travelled evenly from 0 to
``lambda - (radius + tolerances.SWEEP_TOLERANCE)`` along the finger's path (the tip's own ball meets
the surface about a radius before its centre reaches the contour, so that much is not an early
contact), and a capsule passing below the map there means the chain meets the object early. The
hand is not moved while it closes (the thesis's grasp: the arm holds still); the palm and the posts
do not move relative to it.

Reading of "the chain meets the object": any capsule of the finger below the height map of any
raised cell, the object's or an obstacle's. A finger that misses is not checked (it closes on air in
the plan as well).

:func:`closing_hits` asks the other question of the same sweep: does a closing finger run into
something that is *not* the target -- a neighbouring object, a bin's wall -- before it stops? Each
finger closes until it meets the object (its tip's ball then touches the contour, about a radius
before the tip's centre reaches its grasp point) or, if it misses, to its end; its capsules are
sampled along that motion against :func:`obstacle_map`, the height map's obstacle cells alone. The
open hand's descent already kept every body above the whole map, so what this adds is the motion
in the palm plane. Unseen cells count as free here (unlike for the descent): behind the target, in
its occlusion shadow, is where every closing finger goes, and a bound over that shadow would refuse
every grasp.
"""

from __future__ import annotations

from dataclasses import replace
from functools import lru_cache

import numpy as np

from .. import tolerances as tol
from ..hand import FingerChain, Hand, SampledChain, chain_capsules, chain_tip
from ..perception.height_map import HeightMap
from ._descent_kernels import map_clearances


@lru_cache(maxsize=64)
def _travel(chain: FingerChain | SampledChain) -> tuple[np.ndarray, np.ndarray]:
    """(progress, distance the tip has travelled in the palm plane) on ``tolerances.CHAIN_SAMPLES`` progresses."""
    s = np.linspace(0.0, 1.0, tol.CHAIN_SAMPLES)
    tips = chain_tip(chain, s)[:, :2]
    return s, np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(tips, axis=0), axis=1))]


@lru_cache(maxsize=256)
def _swept_capsules(chain: FingerChain | SampledChain, reach: float) -> np.ndarray:
    """(k m, 2, 3) float: the k links' capsules (a planar chain's proximal and distal) at ``SWEEP_SAMPLES`` closing
    progresses whose tips have travelled evenly from 0 to ``reach`` (m) in the palm plane. Cached: a finger that
    closes on air sweeps its whole travel at every pose checked (read-only)."""
    s_grid, distance = _travel(chain)
    s = np.interp(np.linspace(0.0, reach, tol.SWEEP_SAMPLES), distance, s_grid)
    capsules = chain_capsules(chain, s)[:, 1:].reshape(-1, 2, 3)
    capsules.flags.writeable = False
    return capsules


def _below_map(hand: Hand, heights: HeightMap, pose, base: float, reaches) -> np.ndarray:
    """(f,) bool: per finger, whether its swept capsules up to ``reaches[f]`` (NaN: not checked) pass below the map."""
    checked = [f for f, reach in enumerate(reaches) if reach > 0]
    below = np.zeros(len(hand.chains), dtype=bool)
    if not checked:
        return below
    ends = [_swept_capsules(hand.chains[f], float(reaches[f])) for f in checked]
    owner = np.repeat(checked, [len(e) for e in ends])
    radii = np.array([hand.chains[f].radius for f in owner], dtype=float)
    out = map_clearances(heights, hand, np.asarray(pose, dtype=float)[None], np.array([base], dtype=float),
                         np.concatenate(ends), radii, only_below=np.zeros(1))
    np.logical_or.at(below, owner, out[0, :-1] < 0.0)
    return below


def link_first(hand: Hand, heights: HeightMap, pose, base: float, lam, touching) -> np.ndarray:
    """(f,) bool: per finger, whether its chain meets the height map before its tip reaches its grasp point.

    Parameters
    ----------
    hand : Hand
        A 3-D hand.
    heights : HeightMap
    pose : (3,) float
        (x, y, yaw) in the planning frame.
    base : float
        The pose's height offset: a hand point (planning x, y; hand depth z) is
        ``normal . (x, y, z) + base`` above the table (:func:`~contourgrasp.synthesis.descent.height_base`).
    lam : (f,) float
        Each finger's planned travel to its grasp point, m (NaN where it misses).
    touching : (f,) bool

    Returns
    -------
    (f,) bool
        False for fingers that miss or meet the object no earlier than planned.
    """
    reaches = [float(travelled) - chain.radius - tol.SWEEP_TOLERANCE if touches else np.nan
               for chain, travelled, touches in zip(hand.chains, lam, touching)]
    return _below_map(hand, heights, pose, base, reaches)


def obstacle_map(heights: HeightMap) -> HeightMap:
    """The map of ``heights``'s obstacle cells alone: every other cell (the target, the table, unseen, out of view) 0.

    Examples
    --------
    A map without obstacles has nothing to hit:

    >>> import numpy as np
    >>> from contourgrasp.perception import HeightMap
    >>> m = HeightMap(np.array([[0.05, np.nan]]), 0.01, np.zeros(2), np.array([[True, False]]),
    ...               np.zeros((1, 2), bool), 0.05, np.ones((1, 2), bool), np.array([0.0, 0.0, -1.0]), 0.7,
    ...               np.zeros(2), 0.7)
    >>> obstacle_map(m).heights
    array([[0., 0.]])
    """
    only = np.where(heights.obstacles, np.nan_to_num(heights.heights, nan=0.0), 0.0)
    return replace(heights, heights=only, object=np.zeros_like(heights.object),
                   in_view=np.ones_like(heights.in_view))


def obstacle_table(obstacles: HeightMap) -> np.ndarray:
    """(rows + 1, cols + 1) int: the summed-area table of ``obstacles``'s raised cells (an :func:`obstacle_map`):
    entry (i, j) counts those in rows below i and columns below j, so a box's count is four look-ups."""
    raised = (np.asarray(obstacles.heights) > 0.0).astype(np.int64)
    return np.pad(raised.cumsum(axis=0).cumsum(axis=1), ((1, 0), (1, 0)))


def closing_hits(hand: Hand, obstacles: HeightMap, pose, base: float, lam, touching, *,
                 table=None) -> np.ndarray:
    """(f,) bool: per finger, whether its chain runs into an obstacle while it closes (module docstring).

    Parameters
    ----------
    hand : Hand
        A 3-D hand.
    obstacles : HeightMap
        :func:`obstacle_map` of the scene's height map.
    pose, base
        As for :func:`link_first`.
    lam : (f,) float
        Each finger's planned travel to its grasp point, m (ignored where it misses).
    touching : (f,) bool
        A touching finger stops a radius before its grasp point; the others close to their end.
    table : (rows + 1, cols + 1) int, optional
        :func:`obstacle_table` of ``obstacles``, when it is checked for many poses.
    """
    reaches = [float(travelled) - chain.radius if touches else float(_travel(chain)[1][-1])
               for chain, travelled, touches in zip(hand.chains, lam, touching)]
    table = obstacle_table(obstacles) if table is None else table
    near = _near_obstacles(hand, obstacles, table, pose, reaches)
    return _below_map(hand, obstacles, pose, base, np.where(near, reaches, np.nan))


def _near_obstacles(hand: Hand, obstacles: HeightMap, table, pose, reaches) -> np.ndarray:
    """(f,) bool: fingers whose whole closing sweep's box (grown by their radius and a cell) holds the centre of an
    obstacle cell (``table``: :func:`obstacle_table`).

    Most poses of a scene with a distant neighbour sweep nowhere near it; the exact check is for those that do.
    The box is the whole sweep's (:func:`_sweep_points`), computed once per finger: a finger that stops
    earlier sweeps inside it, so no finger that could hit is left out.
    """
    near = np.zeros(len(hand.chains), dtype=bool)
    c, s = np.cos(pose[2]), np.sin(pose[2])
    turn = np.array([[c, s], [-s, c]])
    last = np.array(table.shape[::-1]) - 2  # the last column and row
    for f, (chain, reach) in enumerate(zip(hand.chains, reaches)):
        if not reach > 0:
            continue
        placed = np.asarray(pose[:2], dtype=float) + _sweep_points(chain) @ turn
        grow = chain.radius + obstacles.cell
        # the cells whose centres origin + (index + 1/2) cell lie in the box, clipped to the map
        first = np.maximum(np.ceil((placed.min(axis=0) - grow - obstacles.origin) / obstacles.cell - 0.5), 0)
        final = np.minimum(np.floor((placed.max(axis=0) + grow - obstacles.origin) / obstacles.cell - 0.5), last)
        if (final < first).any():
            continue
        (c0, r0), (c1, r1) = first.astype(int), final.astype(int) + 1
        near[f] = table[r1, c1] - table[r0, c1] - table[r1, c0] + table[r0, c0] > 0
    return near


@lru_cache(maxsize=64)
def _sweep_points(chain: FingerChain | SampledChain) -> np.ndarray:
    """(k, 2) float: the (x, y) of the capsules' ends over the finger's whole closing, hand frame."""
    return _swept_capsules(chain, float(_travel(chain)[1][-1]))[..., :2].reshape(-1, 2)
