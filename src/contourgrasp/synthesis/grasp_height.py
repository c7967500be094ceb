"""Grasp height: how far above the table the open hand's fingertips stop.

The thesis's hand descends to a depth its operator chose (3.1.1, 4.1.4). With a 3-D hand and the
scene's height map the planner chooses it, as the height above the table of the open hand's lowest
fingertip (its tip centre) at the end of the descent, the ``tip_height`` of
:class:`~contourgrasp.synthesis.Descent`. Rules (:data:`GRASP_HEIGHT_RULES`):

Each rule gives the height asked for and the highest accepted (:class:`~contourgrasp.synthesis.Descent`):
a pose whose open hand cannot descend that low stops as high as its bodies need, up to the highest.

``"clearance"``
    The rule the simulated execution applied before the planner chose a height: the tips just
    above the table while they close (the lowest tip of the closing hand, :attr:`Hand.closing_tip_depth`,
    its radius plus ``tolerances.GRASP_TIP_CLEARANCE`` up), unless that brings the palm plane (z = 0)
    closer than ``tolerances.GRASP_PALM_CLEARANCE`` to the object's top; then that high. Never raised.
    A tilted palm (a hand model's, :attr:`~contourgrasp.hand.Palm.plane`) reaches below that plane
    at one end; the rule still counts from the plane, and the descent check keeps the tilted
    underside itself above the object, pose by pose (chosen on the training objects with the Inspire
    model: docs/hand-models.md, "The bench on the models").
``"auto"``
    The same height asked for, at least the hand's :attr:`Hand.grasp_height_fraction` of the
    object's height (``tolerances.GRASP_HEIGHT_FRACTION``, 0.4, unless its file says), raised where
    the bodies need it up to ``tolerances.MAX_GRASP_HEIGHT_FRACTION`` of it: the tips still close on
    its lower part, below its widest part for most objects lying or standing on a table. Chosen on
    the ``ycb-train`` objects (docs/hand3d.md); the Inspire model's fingers, curling, lift their
    tips toward the palm as they close, and its fraction is 0 (the tips as low as the rest of this
    rule lets them), chosen on its training trials (docs/hand-models.md, "The bench on the models"). A hand whose
    fingertips brush the table (:attr:`Hand.tips_brush_table`) is asked for its open tips just
    above the table, its radius plus ``tolerances.GRASP_TIP_CLEARANCE``, without the swing of a
    leaning finger that dips lower as it closes; it may still be raised to the height where no
    closing tip reaches the table. That lowers the grasp only on objects lower than the clearance
    height divided by ``GRASP_HEIGHT_FRACTION`` (2.5 times it), where the fraction does not decide.
"""

from __future__ import annotations

import math

from .. import tolerances as tol
from .. import validation
from ..errors import NoFeasibleGrasp, PlannerError
from ..hand import Hand
from ..perception.height_map import HeightMap

#: The rules of :func:`grasp_height`.
GRASP_HEIGHT_RULES = ("clearance", "auto")


def check_rule(rule):
    """``rule`` if it names a rule of :data:`GRASP_HEIGHT_RULES` or is a height in [0, ``MAX_HAND_SIZE``] m (as a float).

    Raises
    ------
    PlannerError
        Anything else, naming ``grasp_height``.
    """
    if isinstance(rule, str):
        return validation.choice("grasp_height", rule, GRASP_HEIGHT_RULES, error=PlannerError)
    return validation.bounded("grasp_height", rule, tol.MAX_HAND_SIZE, " m", error=PlannerError)


def open_floor(hand: Hand) -> float:
    """The lowest the open hand's lowest fingertip (its centre) may be above the table, m.

    Its radius plus ``tolerances.GRASP_TIP_CLEARANCE``; ``hand`` is a 3-D hand.
    """
    return max(c.radius for c in hand.chains) + tol.GRASP_TIP_CLEARANCE


def grasp_height(hand: Hand, heights: HeightMap, rule: str | float = "auto") -> tuple[float, float]:
    """The grasp height asked for and the highest accepted: the open hand's lowest fingertip above the table, m.

    Parameters
    ----------
    hand : Hand
        A 3-D hand (its chains give the tips' radius and depth below the palm).
    heights : HeightMap
        The scene; its ``max_height`` is the object's top.
    rule : {"clearance", "auto"} or float
        A rule of the module's docstring, or the height itself (m, at most ``MAX_HAND_SIZE``, never raised).

    Returns
    -------
    (float, float)

    Raises
    ------
    PlannerError
        Unknown rule, or a height that is not a finite number in [0, ``MAX_HAND_SIZE``].
    NoFeasibleGrasp
        A height given as a number that is not below the object's top.
    """
    rule = check_rule(rule)
    top = float(heights.max_height) if math.isfinite(heights.max_height) else 0.0
    if not isinstance(rule, str):
        if math.isfinite(heights.max_height) and rule >= top:
            raise NoFeasibleGrasp(f"a grasp height of {1000 * rule:.0f} mm is not below the object's top "
                                  f"({1000 * top:.0f} mm): the fingertips would close over it")
        return rule, rule
    floor = open_floor(hand)
    palm_floor = top + tol.GRASP_PALM_CLEARANCE - hand.open_tip_depth
    height = max(floor + hand.closing_tip_depth - hand.open_tip_depth, palm_floor)
    if rule == "clearance":
        return height, height
    lowest = max(floor, palm_floor) if hand.tips_brush_table else height
    asked = max(lowest, hand.grasp_height_fraction * top)
    return asked, max(height, asked, tol.MAX_GRASP_HEIGHT_FRACTION * top)
