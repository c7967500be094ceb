"""The library's grid search finds the same optimum as the thesis's nested optimisation.

``contourgrasp.synthesis.reference`` solves the inner problem of every pose and finger with scipy's
L-BFGS-B, as the thesis does; the library screens the grid with a compiled kernel on the EFD polygon
and re-evaluates the best candidates exactly. On a small grid (xy 0.05 m, yaw 30 deg, D_max 0.10 m:
5 x 5 x 12 = 300 poses, a few seconds of reference per case) both must find the same best cost within
1e-6 relative and the same number of feasible poses; refining that optimum continuously never makes it
worse. Correctness only: speed is measured by ``benchmarks/search_speed.py``.

peanut / five-finger-curved-thumb has no feasible pose on any grid this small (its 14 feasible poses
on the thesis grid need the 2-degree yaw step), so stone1 stands in for it with the curved-thumb hand.
"""

import math

import numpy as np
import pytest

import contourgrasp as cg
from contourgrasp import contour, synthesis

from contourgrasp.synthesis.reference import reference_search

GRID = {"xy_step": 0.05, "yaw_step": math.radians(30), "d_max": (0.10, 0.10), "d_min": 0.015}
REL = 1e-6


@pytest.mark.parametrize(
    "name, hand",
    [("can", "three-finger"), ("stone1", "five-finger-linear"), ("stone1", "five-finger-curved-thumb")],
)
def test_best_cost_and_feasible_count_match_the_nested_reference(name, hand):
    outline = cg.example_contour(name)
    plan = cg.synthesize(outline, hand, **GRID)
    ref_pose, ref_cost, ref_feasible = reference_search(outline, cg.load_hand(hand), **GRID)
    assert ref_pose is not None, "the reference finds no feasible pose: pick a case feasible on this grid"

    assert plan.cost.total == pytest.approx(ref_cost, rel=REL, abs=0), (
        f"library {plan.cost.total!r} at {plan.pose}, reference {ref_cost!r} at {ref_pose}"
    )

    # The library counts feasible poses on its screen, where contacts lie on the 256-point EFD polygon;
    # the reference solves them on the curve. The two can only disagree for a pose within the polygon's
    # error (~1e-5 m here) of a constraint: a finger grazing a concave stretch (polygon chords lie
    # outside the curve there), a contact at the very end of a finger's travel, or a start distance
    # within that error of D_min. None occurs on this grid; the exact evaluation of every grid pose
    # (contacts moved onto the curve by Newton) must agree with the reference as well.
    assert plan.feasible_poses == ref_feasible
    model = contour.fit(contour.clean_polygon(outline), 4)
    grid = synthesis.SearchGrid(**GRID)
    exact = synthesis.evaluate_poses(model, cg.load_hand(hand), grid.poses(model.locus), d_min=grid.d_min)
    assert int(exact.feasible.sum()) == ref_feasible
    assert exact.cost[exact.feasible].min() == pytest.approx(ref_cost, rel=REL, abs=0)

    # Continuous refinement starts from that optimum and never ends above it.
    refined = cg.synthesize(outline, hand, refine=True, **GRID)
    assert refined.refinement.grid_cost == pytest.approx(ref_cost, rel=REL, abs=0)
    assert refined.cost.total <= refined.refinement.grid_cost


def test_both_agree_when_no_pose_is_feasible():
    """The curved-thumb hand cannot bring four fingers onto the small ellipse (README, make demo)."""
    outline = cg.example_contour("ellipse")
    grid = dict(GRID, yaw_step=math.radians(60))
    with pytest.raises(cg.NoFeasibleGrasp):
        cg.synthesize(outline, "five-finger-curved-thumb", **grid)
    ref_pose, ref_cost, ref_feasible = reference_search(outline, cg.load_hand("five-finger-curved-thumb"), **grid)
    assert (ref_pose, ref_feasible) == (None, 0) and np.isinf(ref_cost)
