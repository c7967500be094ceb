"""The closing sweep against a wall's geometry: on a tall wall the leaning finger's link meets it before the tip;
a finger closing toward a box that is not the target runs into it unless the target stops it first."""

from dataclasses import replace

import numpy as np
import pytest

from contourgrasp import load_hand
from contourgrasp.hand import chain_tip
from contourgrasp.synthesis.descent import descent_clearance, height_base
from contourgrasp.synthesis.sweep import _near_obstacles, closing_hits, link_first, obstacle_map, obstacle_table

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


def box_in_path(hand, along, *, side=0.0, height=0.015, obstacle=True):
    """A yaw-0 pose at the origin and a map with a 20 mm box ``along`` m ahead of the middle finger's open tip on its
    closing path (``side`` m across it), marked an obstacle (or the target's)."""
    i, chain = finger(hand, "middle")
    tip = chain_tip(chain, 0.0)[0, :2]
    direction = np.asarray(hand.fingers[i].trajectory.closing_direction)
    across = np.array([-direction[1], direction[0]])
    near = tip + along * direction + side * across

    def box(x, y):
        u = (x - near[0]) * direction[0] + (y - near[1]) * direction[1]
        v = (x - near[0]) * across[0] + (y - near[1]) * across[1]
        return np.where((u >= 0) & (u < 0.02) & (np.abs(v) < 0.01), height, 0.0)

    heights = scene(box)
    if obstacle:
        heights = replace(heights, obstacles=heights.object, object=np.zeros_like(heights.object))
    pose = np.zeros(3)
    base = height_base(hand, pose[None], TIP, np.asarray(heights.table_normal))[0]
    return i, heights, pose, base


def test_a_finger_closing_on_air_runs_into_a_box_on_its_path(hand):
    i, heights, pose, base = box_in_path(hand, 0.02)
    assert descent_clearance(hand, heights, pose[None], TIP).min() > 0  # the open hand descends clear
    lam, touching = np.full(len(hand.fingers), np.nan), np.zeros(len(hand.fingers), dtype=bool)
    hits = closing_hits(hand, obstacle_map(heights), pose, base, lam, touching)
    assert hits[i] and hits.sum() == 1


def test_a_finger_stopped_by_the_target_before_the_box_does_not_hit_it(hand):
    i, heights, pose, base = box_in_path(hand, 0.02)
    lam, touching = np.full(len(hand.fingers), 0.05), np.zeros(len(hand.fingers), dtype=bool)
    touching[i] = True
    lam[i] = 0.02 - 0.002  # its tip's ball meets the target 11 mm before the box
    assert not closing_hits(hand, obstacle_map(heights), pose, base, lam, touching).any()
    lam[i] = 0.04  # planned beyond the box's near face: the chain passes through the box first
    assert closing_hits(hand, obstacle_map(heights), pose, base, lam, touching)[i]


@pytest.mark.parametrize("change", [{"side": 0.1}, {"height": 0.009}, {"obstacle": False}])
def test_a_box_beside_the_path_below_the_tip_or_of_the_target_is_no_hit(hand, change):
    _, heights, pose, base = box_in_path(hand, 0.02, **change)
    lam, touching = np.full(len(hand.fingers), np.nan), np.zeros(len(hand.fingers), dtype=bool)
    assert not closing_hits(hand, obstacle_map(heights), pose, base, lam, touching).any()


def test_the_obstacle_map_keeps_obstacles_only():
    h = np.array([[0.05, 0.03, np.nan, 0.0]])
    obstacles = np.array([[True, False, False, False]])
    m = scene(lambda x, y: 0.0, shape=(1, 4))
    m = replace(m, heights=h, obstacles=obstacles, object=np.array([[False, True, False, False]]),
                in_view=np.array([[True, True, True, False]]))
    only = obstacle_map(m)
    assert np.array_equal(only.heights, [[0.05, 0.0, 0.0, 0.0]])
    assert only.in_view.all() and not only.object.any() and np.isfinite(only.conservative()).all()


def test_the_obstacle_table_counts_the_raised_cells_of_any_box():
    rng = np.random.default_rng(0)
    m = scene(lambda x, y: 0.0, shape=(9, 13))
    m = replace(m, heights=np.where(rng.random((9, 13)) < 0.3, 0.02, 0.0))
    table = obstacle_table(m)
    raised = m.heights > 0
    for r0, r1, c0, c1 in rng.integers(0, 14, (50, 4)):
        r0, r1, c0, c1 = min(r0, 9), min(r1, 9), min(c0, 13), min(c1, 13)
        if r1 < r0 or c1 < c0:
            continue
        assert table[r1, c1] - table[r0, c1] - table[r1, c0] + table[r0, c0] == raised[r0:r1, c0:c1].sum()


def test_a_box_at_a_distance_is_not_near_and_one_across_the_sweep_is(hand):
    i, heights, pose, base = box_in_path(hand, 0.02)
    only = obstacle_map(heights)
    reaches = np.full(len(hand.fingers), 0.2)
    assert _near_obstacles(hand, only, obstacle_table(only), pose, reaches)[i]
    far = replace(only, heights=np.roll(only.heights, only.heights.shape[1] // 2, axis=1))
    assert not _near_obstacles(hand, far, obstacle_table(far), pose, reaches).any()
