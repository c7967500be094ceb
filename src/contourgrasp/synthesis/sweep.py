"""Closing sweep: does each finger's chain first meet the object where the plan says its tip does? (issue 16, item 1.5)

The thesis's fingertip is a point on a ray or an arc: it meets the contour after travelling
``lambda`` (eq 3.22). The 3-D finger is a chain of capsules that sweeps a surface while it closes,
and on a tall object its distal or proximal link may meet the object's side before the tip reaches
its grasp point -- the finger then stops (or pushes) there, and the planned grasp points and the
ratio cost describe a grasp the hand does not make.

:func:`link_first` checks it on the scene's height map, the 2.5-D solid of
:mod:`~contourgrasp.synthesis.descent`: with the open hand at its grasp height, each touching
finger's proximal and distal capsules are placed at ``tolerances.SWEEP_SAMPLES`` closing progresses
whose tips have travelled evenly from 0 to ``lambda - (radius + tolerances.SWEEP_TOLERANCE)`` along
the finger's path (the tip's own ball meets the surface about a radius before its centre reaches the
contour, so that much is not an early contact), and a capsule passing below the map there means the
chain meets the object early. The hand is not moved while it closes (the thesis's grasp: the arm
holds still); the palm and the posts do not move relative to it.

Reading of "the chain meets the object": any capsule of the finger below the height map of any
raised cell, the object's or an obstacle's. A finger that misses is not checked (it closes on air in
the plan as well).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from .. import tolerances as tol
from ..hand import FingerChain, Hand, chain_capsules, chain_tip
from ..perception.height_map import HeightMap
from ._descent_kernels import map_clearances


@lru_cache(maxsize=64)
def _travel(chain: FingerChain) -> tuple[np.ndarray, np.ndarray]:
    """(progress, distance the tip has travelled in the palm plane) on ``tolerances.CHAIN_SAMPLES`` progresses."""
    s = np.linspace(0.0, 1.0, tol.CHAIN_SAMPLES)
    tips = chain_tip(chain, s)[:, :2]
    return s, np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(tips, axis=0), axis=1))]


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
    ends, owner = [], []
    for f, (chain, travelled, touches) in enumerate(zip(hand.chains, lam, touching)):
        reach = float(travelled) - chain.radius - tol.SWEEP_TOLERANCE
        if not touches or not reach > 0:
            continue
        s_grid, distance = _travel(chain)
        s = np.interp(np.linspace(0.0, reach, tol.SWEEP_SAMPLES), distance, s_grid)
        capsules = chain_capsules(chain, s)[:, 1:]  # (m, 2, 2, 3): proximal and distal
        ends.append(capsules.reshape(-1, 2, 3))
        owner += [f] * len(ends[-1])
    early = np.zeros(len(hand.chains), dtype=bool)
    if not ends:
        return early
    ends = np.concatenate(ends)
    radii = np.array([hand.chains[f].radius for f in owner], dtype=float)
    out = map_clearances(heights, hand, np.asarray(pose, dtype=float)[None], np.array([base], dtype=float), ends, radii)
    np.logical_or.at(early, np.asarray(owner), out[0, :-1] < 0.0)
    return early
