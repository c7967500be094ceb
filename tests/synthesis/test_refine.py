"""Continuous refinement (synthesis.refine)."""

import math

import numpy as np
import pytest

import contourgrasp as cg
from contourgrasp import contour, synthesis
from contourgrasp.io.plan_file import plan_to_dict
from contourgrasp.synthesis import outer


def _grid_best(outline, hand, top=4, **grid):
    """The model and the exact evaluation of the ``top`` distinct best poses of a grid."""
    model = contour.fit(outline)
    grid = synthesis.SearchGrid(**grid)
    screen = synthesis.screen_grid(model, hand, grid)
    best = outer._reevaluate_best(model, hand, screen, 40, "paper", grid.d_min, synthesis.Safeguards())
    poses = best.poses[synthesis.distinct_best(best, grid, top)]
    return model, grid, synthesis.evaluate_poses(model, hand, poses, d_min=grid.d_min)


@pytest.mark.parametrize("obj, hand", [("stone1", "three-finger"), ("bottle", "five-finger-linear"),
                                       ("can", "five-finger-curved-thumb")])
def test_refinement_is_never_worse_stays_feasible_and_in_its_box(obj, hand):
    hand = cg.load_hand(hand)
    model, grid, start = _grid_best(cg.example_contour(obj), hand, xy_step=0.05, yaw_step=math.radians(6))
    step = (grid.xy_step, grid.yaw_step)
    refined = synthesis.refine_poses(model, hand, start.poses, step=step, d_max=grid.d_max, d_min=grid.d_min)
    assert start.feasible.all() and refined.feasible.all()
    assert (refined.cost <= start.cost).all()
    moved = refined.poses - start.poses
    assert (np.abs(moved) <= np.array([grid.xy_step, grid.xy_step, grid.yaw_step]) + 1e-12).all()
    assert (np.abs(refined.poses[:, :2] - model.locus) <= np.array(grid.d_max) + 1e-12).all()
    # the costs are evaluate_poses's own at the refined poses
    again = synthesis.evaluate_poses(model, hand, refined.poses, d_min=grid.d_min)
    np.testing.assert_allclose(again.cost, refined.cost, rtol=1e-12)


def test_refinement_applies_the_evaluation_keywords():
    """Constraints passed through to evaluate_poses bind the refined poses: here a larger D_min."""
    hand = cg.load_hand("three-finger")
    model, grid, start = _grid_best(cg.example_contour("case"), hand, xy_step=0.05, yaw_step=math.radians(6),
                                    d_min=0.03)
    refined = synthesis.refine_poses(model, hand, start.poses, step=(0.05, math.radians(6)), d_min=0.03)
    assert refined.feasible.all()
    assert np.nanmin(refined.start_distance[refined.touching]) >= 0.03
    loose = synthesis.refine_poses(model, hand, start.poses, step=(0.05, math.radians(6)), d_min=0.0)
    assert loose.cost.min() <= refined.cost.min()


@pytest.mark.parametrize("option, value", [("step", (0.0, 0.1)), ("step", (0.05,)), ("halvings", -1),
                                           ("rounds", 2.5), ("d_max", -0.1)])
def test_refinement_refuses_bad_options(option, value):
    model = contour.fit(cg.example_contour("can"))
    with pytest.raises(cg.InputError):
        synthesis.refine_poses(model, cg.load_hand("three-finger"), [[0.0, 0.0, 0.0]], **{option: value})


def test_refinement_finds_the_off_grid_optimum_of_a_coarse_grid():
    """On a coarse grid the optimum lies between grid poses: refinement gains, and reaches a fine grid's cost."""
    outline = cg.example_contour("can")
    coarse = cg.synthesize(outline, "three-finger", xy_step=0.05, yaw_step=math.radians(10), refine=True)
    fine = cg.synthesize(outline, "three-finger", xy_step=0.01, yaw_step=math.radians(2))
    r = coarse.refinement
    assert r.cost == coarse.cost.total < r.grid_cost
    assert r.gain == pytest.approx(r.grid_cost - r.cost) and r.gain > 0
    assert coarse.cost.total <= fine.cost.total + 1e-9
    on_grid = np.round((np.asarray(coarse.pose[:2]) - coarse.efd.locus) / 0.05, 6)
    assert not np.all(on_grid == np.round(on_grid))


def test_refined_plan_reports_the_grid_best_stages_and_ranked_alternatives():
    plan = cg.synthesize(cg.example_contour("stone1"), "three-finger", yaw_step=math.radians(6), refine=True)
    plain = cg.synthesize(cg.example_contour("stone1"), "three-finger", yaw_step=math.radians(6))
    assert plain.refinement is None and plain.timing_ms["refine"] == 0
    assert set(plan.timing_ms) == {"efd", "search", "exact", "refine", "total"}
    assert plan.refinement.grid_cost == pytest.approx(plain.cost.total, rel=1e-12)
    np.testing.assert_allclose(plan.refinement.grid_pose, plain.pose)
    assert plan.cost.total <= plain.cost.total
    costs = [a.cost.total for a in plan.alternatives]
    assert costs == sorted(costs) and len(costs) == 10
    np.testing.assert_allclose(plan.alternatives[0].pose, plan.pose)
    assert plan_to_dict(plain)["refinement"] is None
    data = plan_to_dict(plan)["refinement"]
    assert (data["grid_cost"], data["cost"], data["gain"]) == (plan.refinement.grid_cost, plan.cost.total,
                                                              plan.refinement.gain)
