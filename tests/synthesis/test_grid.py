"""The pose grid (synthesis.grid): the compiled screen against numpy, curvature tables, distinct poses."""

import dataclasses
import math

import numpy as np
import pytest

import contourgrasp as cg
from contourgrasp import contour, synthesis
from contourgrasp.synthesis import _grid_kernels
from conftest import disc, rotate


@pytest.mark.parametrize("hand", cg.preset_names())
@pytest.mark.parametrize("steps", [(0.03, 7), (0.05, 9)])
def test_compiled_grid_screen_matches_the_numpy_inner_problem(hand, steps):
    """Same polygon, same arithmetic: the filtered kernel must find exactly what brute force finds
    (edge groups in buckets on the finer grid, scanned on the coarser one)."""
    hand = cg.load_hand(hand)
    model = contour.fit(cg.example_contour("stone1"))
    grid = synthesis.SearchGrid(xy_step=steps[0], yaw_step=math.radians(steps[1]))
    screen = synthesis.screen_grid(model, hand, grid)
    t, polygon = contour.sample(model)
    lam, t_hit, _, inside = synthesis.first_touch(polygon, t, model.T, hand.segments(), len(hand.fingers), screen.poses)
    np.testing.assert_array_equal(screen.start_inside, inside)
    np.testing.assert_array_equal(screen.touching, np.isfinite(lam))
    np.testing.assert_allclose(screen.lam[screen.touching], lam[np.isfinite(lam)], atol=1e-12)
    np.testing.assert_allclose(screen.t[screen.touching], t_hit[np.isfinite(lam)], atol=1e-12)
    exact = synthesis.evaluate_poses(model, hand, screen.poses)
    np.testing.assert_array_equal(exact.touching, screen.touching)
    both = screen.feasible & exact.feasible
    assert both.sum() > 0.95 * screen.feasible.sum() > 0
    # The screen keeps contacts on the 256-gon and on the arc's chords; the exact path moves them onto
    # the curves, which the curved thumb's gain of 100 on curvature amplifies.
    has_arc = any(isinstance(f.trajectory, cg.Arc) for f in hand.fingers)
    np.testing.assert_allclose(screen.cost[both], exact.cost[both], rtol=1e-2 if has_arc else 2e-3, atol=0.05)


@pytest.mark.parametrize("touching", [1, 3])
def test_the_reaching_screen_is_the_full_screen_where_enough_fingers_touch(touching):
    hand = dataclasses.replace(cg.load_hand("five-finger-linear"), min_touching=touching)
    model = contour.fit(cg.example_contour("stone1"))
    grid = synthesis.SearchGrid(xy_step=0.03, yaw_step=math.radians(7))
    full = synthesis.screen_grid(model, hand, grid)
    reaching, counts, any_outside = synthesis.screen_reaching(model, hand, grid)
    kept = full.touching.sum(axis=1) >= touching
    np.testing.assert_array_equal(counts, full.touching.sum(axis=1)[kept])
    assert 0 < kept.sum() < len(full.poses)
    for field in dataclasses.fields(full):
        np.testing.assert_array_equal(getattr(reaching, field.name), getattr(full, field.name)[kept], err_msg=field.name)
    np.testing.assert_array_equal(np.flatnonzero(full.feasible), np.flatnonzero(kept)[reaching.feasible])
    assert any_outside == bool(full.starts_outside.any())


def test_curved_thumb_cells_match_brute_force_on_a_large_and_a_tiny_object():
    """The arc's later chords look edges up in cells: objects much larger and smaller than a cell."""
    hand = cg.load_hand("five-finger-curved-thumb")
    grid = synthesis.SearchGrid(xy_step=0.03, yaw_step=math.radians(9))
    # turned off the grid's axes: a symmetric disc would put rays exactly through polygon vertices
    for outline in (rotate(disc(0.14, n=90) * [1.0, 0.6], 0.3), rotate(disc(0.012, n=40) * [1.0, 0.7], 0.3)):
        model = contour.fit(outline)
        screen = synthesis.screen_grid(model, hand, grid)
        t, polygon = contour.sample(model)
        lam, t_hit, _, inside = synthesis.first_touch(polygon, t, model.T, hand.segments(), 5, screen.poses)
        assert np.isfinite(lam[:, 0]).any()
        np.testing.assert_array_equal(screen.start_inside, inside)
        np.testing.assert_array_equal(screen.touching, np.isfinite(lam))
        np.testing.assert_allclose(screen.lam[screen.touching], lam[np.isfinite(lam)], atol=1e-12)
        np.testing.assert_allclose(screen.t[screen.touching], t_hit[np.isfinite(lam)], atol=1e-12)


@pytest.mark.parametrize("mode", contour.CURVATURE_MODES)
def test_screen_curvature_tables_match_the_curve(mode):
    """Magnitude and turning sign interpolated apart: no smearing across the paper curvature's jumps."""
    model = contour.fit(cg.example_contour("peanut"))
    t = np.random.default_rng(3).uniform(0, model.T, (2000, 1))
    table_t = np.linspace(0.0, model.T, cg.tolerances.CURVATURE_TABLE, endpoint=False)
    d1, d2 = contour.evaluate(model, table_t, 1), contour.evaluate(model, table_t, 2)
    table = _grid_kernels.interpolate_curvature(np.abs(contour.curvature(model, table_t, mode)),
                                           d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0], t, model.T)[:, 0]
    exact = contour.curvature(model, t[:, 0], mode)
    assert (exact < 0).any() and (exact > 0).any()
    assert np.mean(np.sign(table) == np.sign(exact)) > 0.998
    same = np.sign(table) == np.sign(exact)
    np.testing.assert_allclose(table[same], exact[same], rtol=1e-3, atol=2e-3 * np.abs(exact).max())


@pytest.mark.parametrize("block", [3, 512])
def test_distinct_best_is_the_greedy_choice(block):
    """Cheapest first, skipping neighbours of those taken, whatever the blocks compared at once."""
    grid = synthesis.SearchGrid(xy_step=0.05, yaw_step=math.radians(10))
    rng = np.random.default_rng(6)
    poses = np.c_[rng.integers(0, 4, (60, 2)) * grid.xy_step, rng.integers(0, 36, 60) * grid.yaw_step]
    cost = rng.integers(0, 20, 60).astype(float)  # ties: the first pose wins
    feasible = rng.random(60) < 0.8
    result = synthesis.PoseEvaluation(**{f.name: None for f in dataclasses.fields(synthesis.PoseEvaluation)}
                                      | {"poses": poses, "cost": cost, "feasible": feasible})
    expected = []
    for i in sorted(np.flatnonzero(feasible), key=lambda i: (cost[i], i)):
        near = [np.all(np.abs(poses[i, :2] - poses[j, :2]) <= grid.xy_step * 1.000001)
                and min(abs(poses[i, 2] - poses[j, 2]), 2 * math.pi - abs(poses[i, 2] - poses[j, 2]))
                <= grid.yaw_step * 1.000001 for j in expected]
        if not any(near):
            expected.append(int(i))
    assert len(expected) > 8
    assert synthesis.distinct_best(result, grid, 8, block=block) == expected[:8]
    assert synthesis.distinct_best(result, grid, 100, block=block) == expected
