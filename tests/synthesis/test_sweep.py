"""The closing sweep against a wall's geometry: on a tall wall the leaning finger's link meets it before the tip."""

import numpy as np
import pytest

from contourgrasp import load_hand
from contourgrasp.hand import chain_tip
from contourgrasp.synthesis.descent import descent_clearance, height_base
from contourgrasp.synthesis.sweep import link_first

from .test_descent import CELL, finger, middle_pose, scene

TIP = 0.02


@pytest.fixture(scope="module")
def hand():
    return load_hand("five-finger-linear")


def wall(height, edge):
    """A block 12 mm wide under the middle finger only, of the given height, for y below ``edge`` (its last row of
    cell centres)."""
    return scene(lambda x, y: np.where((np.abs(x) < 0.006) & (y < edge + 1e-9) & (y > edge - 0.05), height, 0.0))


def planned(hand, heights, pose, edge):
    """The middle finger's travel to the wall's face (the thesis's point fingertip), and the pose's height base."""
    i, chain = finger(hand, "middle")
    tip = chain_tip(chain, 0.0)[0]
    start_y = pose[1] + tip[1]
    lam = np.full(len(hand.fingers), np.nan)
    lam[i] = start_y - (edge + 0.5 * CELL)
    touching = np.zeros(len(hand.fingers), dtype=bool)
    touching[i] = True
    base = height_base(hand, pose[None], TIP, np.asarray(heights.table_normal))[0]
    return i, lam, touching, base


@pytest.mark.parametrize("height, early", [(0.10, True), (0.015, False)])
def test_a_tall_wall_meets_the_link_first_a_low_one_the_tip(hand, height, early):
    edge = 0.1 + 0.5 * CELL
    heights = wall(height, edge)
    pose = middle_pose(hand, edge, height, TIP, 0.004)  # the open hand clears the wall by 4 mm
    assert descent_clearance(hand, heights, pose[None], TIP).min() > 0
    i, lam, touching, base = planned(hand, heights, pose, edge)
    found = link_first(hand, heights, pose, base, lam, touching)
    assert found[i] == early and found.sum() == early


def test_fingers_that_miss_are_not_checked(hand):
    edge = 0.1 + 0.5 * CELL
    heights = wall(0.10, edge)
    pose = middle_pose(hand, edge, 0.10, TIP, 0.004)
    i, lam, touching, base = planned(hand, heights, pose, edge)
    assert not link_first(hand, heights, pose, base, lam, np.zeros_like(touching)).any()
