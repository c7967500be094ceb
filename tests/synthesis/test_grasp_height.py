"""The grasp height rules against the hand's geometry."""

from dataclasses import replace

import numpy as np
import pytest

from contourgrasp import load_hand
from contourgrasp import tolerances as tol
from contourgrasp.errors import NoFeasibleGrasp, PlannerError
from contourgrasp.perception import HeightMap
from contourgrasp.synthesis.grasp_height import grasp_height


@pytest.fixture(scope="module")
def hand():
    return load_hand("five-finger-linear")


def with_top(top):
    grid = np.zeros((10, 10))
    grid[4:6, 4:6] = top
    return HeightMap(grid, 0.002, np.zeros(2), grid > 0, np.zeros((10, 10), bool), top, np.ones((10, 10), bool),
                     np.array([0.0, 0.0, -1.0]), 0.7, np.zeros(2), 0.7)


def test_clearance_keeps_the_closing_tips_just_above_the_table_for_a_low_object(hand):
    low, high = grasp_height(hand, with_top(0.03), "clearance")
    swing = hand.closing_tip_depth - hand.open_tip_depth
    assert low == high == pytest.approx(max(c.radius for c in hand.chains) + tol.GRASP_TIP_CLEARANCE + swing)


def test_clearance_keeps_the_palm_above_a_tall_objects_top(hand):
    low, high = grasp_height(hand, with_top(0.2), "clearance")
    assert low == high == pytest.approx(0.2 + tol.GRASP_PALM_CLEARANCE - hand.open_tip_depth)


def test_auto_asks_a_fraction_of_the_height_and_accepts_up_to_a_larger_one(hand):
    stiff = replace(hand, tips_brush_table=False)
    floor, _ = grasp_height(stiff, with_top(0.02), "clearance")
    assert grasp_height(stiff, with_top(0.02), "auto") == pytest.approx((floor, floor))
    for h in (hand, stiff):
        low, high = grasp_height(h, with_top(0.10), "auto")
        assert low == pytest.approx(tol.GRASP_HEIGHT_FRACTION * 0.10)
        assert high == pytest.approx(tol.MAX_GRASP_HEIGHT_FRACTION * 0.10)


def test_the_hands_own_fraction_is_the_one_asked_for(hand):
    top = 0.10
    for fraction in (0.2, 0.6):
        low, high = grasp_height(replace(hand, grasp_height_fraction=fraction), with_top(top), "auto")
        assert (low, high) == pytest.approx((fraction * top, tol.MAX_GRASP_HEIGHT_FRACTION * top))
    # none: the open tips' floor, as low as the table lets a brushing hand go
    floor = max(c.radius for c in hand.chains) + tol.GRASP_TIP_CLEARANCE
    assert grasp_height(replace(hand, grasp_height_fraction=0.0), with_top(top), "auto")[0] == pytest.approx(floor)


def test_tips_brushing_the_table_are_asked_just_above_it_and_may_rise_to_clear_it(hand):
    assert hand.tips_brush_table
    swing = hand.closing_tip_depth - hand.open_tip_depth
    open_floor = max(c.radius for c in hand.chains) + tol.GRASP_TIP_CLEARANCE
    low, high = grasp_height(hand, with_top(0.02), "auto")
    assert low == pytest.approx(open_floor)  # 20 mm: 0.4 of it is below the open tips' floor
    assert high == pytest.approx(open_floor + swing) == grasp_height(hand, with_top(0.02), "clearance")[0]
    # between the floors the fraction decides, as without brushing
    top = (open_floor + 0.5 * swing) / tol.GRASP_HEIGHT_FRACTION
    assert grasp_height(hand, with_top(top), "auto")[0] == pytest.approx(open_floor + 0.5 * swing)


def test_a_number_is_the_height_itself_and_bad_rules_are_refused(hand):
    assert grasp_height(hand, with_top(0.1), 0.05) == (0.05, 0.05)
    with pytest.raises(NoFeasibleGrasp, match="a grasp height of 100 mm is not below the object's top"):
        grasp_height(hand, with_top(0.1), 0.1)
    for bad in ("high", -0.01, np.nan, 1e9):
        with pytest.raises(PlannerError, match="grasp_height"):
            grasp_height(hand, with_top(0.1), bad)
