"""The cost (synthesis.cost): the ratio cost, printed and squared."""

import math

import numpy as np
import pytest

import contourgrasp as cg
from contourgrasp import contour, synthesis


def test_printed_linear_ratio_cost_sums_to_zero_for_every_pose():
    hand = cg.load_hand("five-finger-linear")
    model = contour.fit(cg.example_contour("can"))
    grid = synthesis.SearchGrid(xy_step=0.05, yaw_step=math.radians(10))
    result = synthesis.evaluate_poses(model, hand, grid.poses(model.locus))
    beta = np.full(len(hand.fingers), 1e4)
    assert result.touching.sum(axis=1).max() >= 4
    linear = synthesis.ratio_cost(result.distance, result.touching, beta, form="linear")
    np.testing.assert_allclose(linear, 0.0, atol=1e-9)
    squared = synthesis.ratio_cost(result.distance, result.touching, beta)
    assert (squared[result.touching.sum(axis=1) >= 2] > 0).any()


def test_squared_ratio_cost_by_hand():
    d = np.array([[0.02, 0.02, 0.05]])
    cost = synthesis.ratio_cost(d, np.ones((1, 3), bool), np.array([1.0, 1.0, 2.0]))
    expected = (0.02 - 0.035) ** 2 * 2 + 2 * (0.05 - 0.02) ** 2
    assert cost[0] == pytest.approx(expected)
    missed_one = synthesis.ratio_cost(d, np.array([[True, True, False]]), np.ones(3))
    assert missed_one[0] == pytest.approx(0.0)
