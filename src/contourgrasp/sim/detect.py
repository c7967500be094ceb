"""Telling a failed grasp as a robot tells it: from what the closed hand reports (:func:`hand_holds`).

After an attempt (:func:`contourgrasp.sim.trial.run_trial` with several attempts,
:func:`contourgrasp.sim.clearing.run_clearing`) the hand is read as its encoders and a wrist
force-torque sensor would read it (:meth:`~contourgrasp.sim.scene.Scene.hand_reading`): a finger stopped
short of where it closes on nothing, or a load on the wrist, says it holds something. Not the simulator's
truth; and not a new picture either: among several objects a lifted one uncovers what stood behind it,
and the picture then shows something standing where it stood (docs/studies.md, "Clearing a table").
"""

from __future__ import annotations

import numpy as np

from ..tolerances import HOLD_LOAD, HOLD_READING


def hand_holds(reading, free_closure) -> bool:
    """Whether a closed hand holds something: a finger joint of ``reading``
    (:class:`~contourgrasp.sim.scene.HandReading`) stopped at least ``tolerances.HOLD_READING`` short of where it
    stops closed on nothing (``free_closure``'s) -- a finger on an object --, or the wrist carries at least
    ``tolerances.HOLD_LOAD`` more than the empty hand -- an object caged in the closed hand, its fingers at
    their limits, still weighs."""
    joints, free = np.asarray(reading.joints, dtype=float), np.asarray(free_closure.joints, dtype=float)
    stopped = joints.size and float(np.max(np.abs(joints - free))) >= HOLD_READING
    return bool(stopped or reading.load - free_closure.load >= HOLD_LOAD)
