import dataclasses
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from matplotlib.path import Path as MplPath

import contourgrasp as cg
from contourgrasp import ContourError, NoFeasibleGrasp, _kernels, efd, synthesis
from contourgrasp.io.plan_file import plan_to_dict
from conftest import disc, rotate

FINE = {"xy_step": 0.02, "yaw_step": math.radians(4)}


@pytest.mark.parametrize("hand", cg.preset_names())
@pytest.mark.parametrize("obj", ["can", "case", "bottle"])
def test_every_preset_grasps_can_case_bottle_with_all_fingers(hand, obj):
    plan = cg.synthesize(cg.example_contour(obj), hand, **FINE)
    assert not any(f.missed for f in plan.fingers)
    assert plan.cost.miss == 0
    for f in plan.fingers:
        assert np.linalg.norm(f.grasp_point - f.start) >= plan.grid.d_min - 1e-12
        assert f.lam <= cg.load_hand(hand).fingers[[g.name for g in plan.fingers].index(f.name)].travel + 1e-12


def test_paper_grid_defaults_match_tables_4_1_and_4_2():
    plan = cg.synthesize(cg.example_contour("can"), "five-finger-linear")
    assert plan.grid_size == 7 * 7 * 180
    assert (plan.grid.xy_step, plan.grid.d_max, plan.grid.d_min) == (0.05, (0.15, 0.15), 0.015)
    assert plan.grid.yaw_step == pytest.approx(math.radians(2))


def test_translation_moves_the_pose_the_same_way():
    stone = cg.example_contour("stone1")
    a = cg.synthesize(stone, "three-finger", yaw_step=math.radians(6))
    b = cg.synthesize(stone + [0.31, -0.17], "three-finger", yaw_step=math.radians(6))
    np.testing.assert_allclose(b.pose, a.pose + [0.31, -0.17, 0], atol=1e-9)
    assert b.cost.total == pytest.approx(a.cost.total, rel=1e-9)


@pytest.mark.parametrize("quarter_turns", [1, 2])
def test_rotation_rotates_the_pose(quarter_turns):
    """A 90-degree turn maps the square position grid and the yaw grid onto themselves."""
    stone = cg.example_contour("stone2")
    angle = quarter_turns * math.pi / 2
    a = cg.synthesize(stone, "three-finger", yaw_step=math.radians(6))
    locus = a.efd.locus
    b = cg.synthesize(rotate(stone, angle, about=locus), "three-finger", yaw_step=math.radians(6))
    assert b.cost.total == pytest.approx(a.cost.total, rel=1e-6)
    expected_xy = rotate(a.pose[None, :2], angle, about=locus)[0]
    assert np.linalg.norm(b.pose[:2] - expected_xy) <= b.grid.xy_step + 1e-9
    dyaw = (b.pose[2] - a.pose[2] - angle + math.pi) % (2 * math.pi) - math.pi
    assert abs(dyaw) <= b.grid.yaw_step + 1e-9


def test_finer_grid_is_never_worse():
    bottle = cg.example_contour("bottle")
    coarse = cg.synthesize(bottle, "five-finger-linear", xy_step=0.05, yaw_step=math.radians(4))
    fine = cg.synthesize(bottle, "five-finger-linear", xy_step=0.025, yaw_step=math.radians(2))
    assert fine.cost.total <= coarse.cost.total + 1e-9


def test_centred_three_finger_grasp_on_a_disc_is_symmetric():
    hand = cg.load_hand("three-finger")
    model = efd.fit(disc(0.03))
    result = synthesis.evaluate_poses(model, hand, [[0.0, 0.0, 0.3]])
    assert result.touching.all() and result.feasible[0]
    np.testing.assert_allclose(result.lam[0], np.linalg.norm(hand.starts, axis=1) - 0.03, atol=1e-4)
    np.testing.assert_allclose(result.curvature[0], result.curvature[0, 0], rtol=1e-3)
    assert np.ptp(result.distance[0]) < 3e-4  # Table A.2 rounds the start radius to 0.0798-0.08
    angles = np.arctan2(result.grasp_point[0, :, 1], result.grasp_point[0, :, 0])
    gaps = np.sort(np.diff(np.sort(angles)))
    np.testing.assert_allclose(gaps, 2 * math.pi / 3, atol=1e-2)


def test_first_touch_matches_brute_force_marching():
    hand = cg.load_hand("five-finger-linear")
    model = efd.fit(cg.example_contour("peanut"))
    _, polygon = efd.sample(model, 8192)  # the curve itself, for practical purposes
    inside = MplPath(polygon)
    rng = np.random.default_rng(0)
    poses = np.c_[rng.uniform(-0.15, 0.15, (40, 2)), rng.uniform(0, 2 * math.pi, 40)]
    result = synthesis.evaluate_poses(model, hand, poses)
    lam = np.linspace(0, 1, 4001)
    for p, pose in enumerate(poses):
        for f, finger in enumerate(hand.fingers):
            if result.start_inside[p, f]:
                continue
            path = cg.hand.to_image(finger.points(lam * finger.travel), pose)
            hits = np.flatnonzero(inside.contains_points(path))
            if hits.size == 0:
                assert not result.touching[p, f]
            else:
                assert result.touching[p, f]
                assert result.lam[p, f] == pytest.approx(lam[hits[0]] * finger.travel, abs=finger.travel / 2000)


@pytest.mark.parametrize("hand", cg.preset_names())
@pytest.mark.parametrize("steps", [(0.03, 7), (0.05, 9)])
def test_compiled_grid_screen_matches_the_numpy_inner_problem(hand, steps):
    """Same polygon, same arithmetic: the filtered kernel must find exactly what brute force finds
    (edge groups in buckets on the finer grid, scanned on the coarser one)."""
    hand = cg.load_hand(hand)
    model = efd.fit(cg.example_contour("stone1"))
    grid = synthesis.SearchGrid(xy_step=steps[0], yaw_step=math.radians(steps[1]))
    screen = synthesis.screen_grid(model, hand, grid)
    t, polygon = efd.sample(model)
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


def test_compiled_pose_list_matches_the_numpy_inner_problem():
    """evaluate_poses's polygon stage (every chord against every edge, compiled) is first_touch's answer."""
    for hand in map(cg.load_hand, cg.preset_names()):
        model = efd.fit(cg.example_contour("peanut"))
        t, polygon = efd.sample(model)
        rng = np.random.default_rng(2)
        poses = np.c_[rng.uniform(-0.12, 0.12, (300, 2)), rng.uniform(0, 2 * math.pi, 300)]
        seg = hand.segments()
        lam, t_hit, point, inside = _kernels.pose_first_touch(
            polygon, t, model.T, poses, seg.start, seg.end - seg.start, seg.finger, seg.lam0,
            synthesis._first_chords(seg, len(hand.fingers)), len(hand.fingers), cg.tolerances.PARALLEL)
        ref_lam, ref_t, ref_point, ref_inside = synthesis.first_touch(polygon, t, model.T, seg, len(hand.fingers), poses)
        touching = np.isfinite(ref_lam)
        assert touching.any() and ref_inside.any()
        np.testing.assert_array_equal(inside, ref_inside)
        np.testing.assert_array_equal(np.isfinite(lam), touching)
        np.testing.assert_allclose(lam[touching], ref_lam[touching], atol=1e-12)
        np.testing.assert_allclose(t_hit[touching], ref_t[touching], atol=1e-12)
        np.testing.assert_allclose(point[touching], ref_point[touching], atol=1e-12)


def test_curved_thumb_cells_match_brute_force_on_a_large_and_a_tiny_object():
    """The arc's later chords look edges up in cells: objects much larger and smaller than a cell."""
    hand = cg.load_hand("five-finger-curved-thumb")
    grid = synthesis.SearchGrid(xy_step=0.03, yaw_step=math.radians(9))
    # turned off the grid's axes: a symmetric disc would put rays exactly through polygon vertices
    for outline in (rotate(disc(0.14, n=90) * [1.0, 0.6], 0.3), rotate(disc(0.012, n=40) * [1.0, 0.7], 0.3)):
        model = efd.fit(outline)
        screen = synthesis.screen_grid(model, hand, grid)
        t, polygon = efd.sample(model)
        lam, t_hit, _, inside = synthesis.first_touch(polygon, t, model.T, hand.segments(), 5, screen.poses)
        assert np.isfinite(lam[:, 0]).any()
        np.testing.assert_array_equal(screen.start_inside, inside)
        np.testing.assert_array_equal(screen.touching, np.isfinite(lam))
        np.testing.assert_allclose(screen.lam[screen.touching], lam[np.isfinite(lam)], atol=1e-12)
        np.testing.assert_allclose(screen.t[screen.touching], t_hit[np.isfinite(lam)], atol=1e-12)


@pytest.mark.parametrize("mode", efd.CURVATURE_MODES)
def test_screen_curvature_tables_match_the_curve(mode):
    """Magnitude and turning sign interpolated apart: no smearing across the paper curvature's jumps."""
    model = efd.fit(cg.example_contour("peanut"))
    t = np.random.default_rng(3).uniform(0, model.T, (2000, 1))
    table_t = np.linspace(0.0, model.T, cg.tolerances.CURVATURE_TABLE, endpoint=False)
    d1, d2 = efd.evaluate(model, table_t, 1), efd.evaluate(model, table_t, 2)
    table = _kernels.interpolate_curvature(np.abs(efd.curvature(model, table_t, mode)),
                                           d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0], t, model.T)[:, 0]
    exact = efd.curvature(model, t[:, 0], mode)
    assert (exact < 0).any() and (exact > 0).any()
    assert np.mean(np.sign(table) == np.sign(exact)) > 0.998
    same = np.sign(table) == np.sign(exact)
    np.testing.assert_allclose(table[same], exact[same], rtol=1e-3, atol=2e-3 * np.abs(exact).max())


@pytest.mark.parametrize("seed", [4, 7, 8])
def test_nearest_point_segment_matches_numpy(seed):
    rng = np.random.default_rng(seed)
    points, starts, vectors = rng.normal(size=(30, 2)), rng.normal(size=(20, 2)), rng.normal(size=(20, 2))
    w = points[:, None] - starts[None]
    s = np.clip(np.einsum("nsi,si->ns", w, vectors) / np.sum(vectors**2, axis=1), 0, 1)
    gap = np.linalg.norm(w - s[..., None] * vectors[None], axis=2)
    i, k = np.unravel_index(np.argmin(gap), gap.shape)
    got = _kernels.nearest_point_segment(points, starts, vectors)
    assert got[:2] == (i, k)
    assert got[2:] == pytest.approx((s[i, k], gap[i, k]), abs=1e-14)


def test_start_inside_matches_point_in_polygon():
    hand = cg.load_hand("five-finger-linear")
    model = efd.fit(cg.example_contour("case") * 2.5)
    _, polygon = efd.sample(model)
    rng = np.random.default_rng(1)
    poses = np.c_[rng.uniform(-0.2, 0.2, (300, 2)), rng.uniform(0, 2 * math.pi, 300)]
    result = synthesis.evaluate_poses(model, hand, poses)
    starts = np.stack([cg.hand.to_image(hand.starts, pose) for pose in poses])
    expected = MplPath(polygon).contains_points(starts.reshape(-1, 2)).reshape(len(poses), -1)
    assert expected.any() and (~expected).any()
    np.testing.assert_array_equal(result.start_inside, expected)


def test_printed_linear_ratio_cost_sums_to_zero_for_every_pose():
    hand = cg.load_hand("five-finger-linear")
    model = efd.fit(cg.example_contour("can"))
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


def test_thumb_and_outer_fingers_start_farther_as_section_4_2_3_reports():
    """lambda_virt = +0.03 (thumb), +0.01 (ring, little): those fingers end up farther from the object."""
    plan = cg.synthesize(cg.example_contour("can"), "five-finger-linear", **FINE)
    gap = {f.name: np.linalg.norm(f.grasp_point - f.start) for f in plan.fingers}
    assert gap["thumb"] > max(gap["index"], gap["middle"]) + 0.02
    assert (gap["ring"] + gap["little"]) / 2 > (gap["index"] + gap["middle"]) / 2


def test_missed_fingers_cost_the_penalty_and_report_their_closest_approach():
    hand = cg.load_hand("five-finger-linear")
    pear = np.c_[0.04 * np.cos(np.linspace(0, 2 * math.pi, 200)), 0.03 * np.sin(np.linspace(0, 2 * math.pi, 200))]
    plan = cg.synthesize(pear[:-1], hand, **FINE)
    missed = [f for f in plan.fingers if f.missed]
    assert missed and len(missed) <= len(hand.fingers) - hand.min_touching
    assert not plan.fingers[0].missed  # the thumb is required
    assert plan.cost.miss == pytest.approx(hand.miss_penalty * len(missed))
    for f in missed:
        assert f.gap > 0
        assert (f.grasp_point[0] / 0.04) ** 2 + (f.grasp_point[1] / 0.03) ** 2 == pytest.approx(1, abs=0.05)
    assert plan.cost.total == pytest.approx(plan.cost.curvature + plan.cost.ratio + plan.cost.miss)


def test_object_larger_than_the_hand_is_infeasible():
    with pytest.raises(NoFeasibleGrasp, match="larger than the hand"):
        cg.synthesize(disc(0.5), "five-finger-linear")


def test_object_too_small_is_infeasible():
    with pytest.raises(NoFeasibleGrasp, match="too small"):
        cg.synthesize(disc(0.02), "five-finger-linear", yaw_step=math.radians(10))


def test_alternatives_are_ranked_distinct_and_start_with_the_best():
    plan = cg.synthesize(cg.example_contour("stone1"), "three-finger", top_k=5)
    assert len(plan.alternatives) == 5
    costs = [a.cost.total for a in plan.alternatives]
    assert costs == sorted(costs)
    np.testing.assert_allclose(plan.alternatives[0].pose, plan.pose)
    poses = np.array([a.pose for a in plan.alternatives])
    for i in range(5):
        for j in range(i):
            d = np.abs(poses[i] - poses[j])
            d[2] = min(d[2], 2 * math.pi - d[2])
            assert (d[:2] > plan.grid.xy_step * 1.000001).any() or d[2] > plan.grid.yaw_step * 1.000001


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
    assert synthesis._distinct_best(result, grid, 8, block=block) == expected[:8]
    assert synthesis._distinct_best(result, grid, 100, block=block) == expected


def test_derived_arrays_are_computed_once_and_go_with_their_model():
    model = efd.fit(cg.example_contour("can"))
    polygon = synthesis._polygon(model)
    assert synthesis._polygon(model) is polygon
    np.testing.assert_array_equal(polygon[1], efd.sample(model)[1])
    twin = efd.fit(cg.example_contour("can"))
    assert synthesis._polygon(twin) is not polygon
    key = id(model)
    del model
    assert key not in synthesis._DERIVED


def test_deterministic():
    a = cg.synthesize(cg.example_contour("stone2"), "five-finger-linear")
    b = cg.synthesize(cg.example_contour("stone2"), "five-finger-linear")
    np.testing.assert_array_equal(a.pose, b.pose)
    assert a.cost == b.cost


def test_paper_grid_takes_well_under_seconds():
    plan = cg.synthesize(cg.example_contour("can"), "five-finger-linear")
    assert plan.timing_ms["total"] < 5000  # order of magnitude; speed is measured in benchmarks/


def test_geometric_curvature_mode_runs_and_reports_it():
    plan = cg.synthesize(cg.example_contour("case"), "three-finger", curvature="geometric", yaw_step=math.radians(6))
    assert plan.curvature_mode == "geometric"
    for f in plan.fingers:
        assert f.concave == (efd.curvature(plan.efd, [f.t], "geometric")[0] < 0)


@pytest.mark.parametrize("option, value", [("xy_step", 0.0), ("yaw_step", -1.0), ("d_min", -0.1), ("top_k", 0),
                                           ("curvature", "gauss"), ("harmonics", 0)])
def test_bad_options_are_refused(option, value):
    with pytest.raises(cg.InputError):
        cg.synthesize(cg.example_contour("can"), "three-finger", **{option: value})


@st.composite
def star_polygons(draw):
    n = draw(st.integers(5, 40))
    radii = draw(st.lists(st.floats(0.01, 0.09), min_size=n, max_size=n))
    jitter = draw(st.lists(st.floats(-0.4, 0.4), min_size=n, max_size=n))
    theta = (np.arange(n) + np.array(jitter)) * 2 * math.pi / n
    centre = draw(st.tuples(st.floats(-0.3, 0.3), st.floats(-0.3, 0.3)))
    return np.c_[np.cos(theta), np.sin(theta)] * np.array(radii)[:, None] + centre


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(polygon=star_polygons(), hand=st.sampled_from(cg.preset_names()), harmonics=st.integers(1, 8))
def test_random_star_polygons_give_finite_plans_or_documented_errors(polygon, hand, harmonics):
    try:
        plan = cg.synthesize(polygon, hand, harmonics=harmonics, yaw_step=math.radians(15), top_k=3)
    except (NoFeasibleGrasp, ContourError):
        return
    assert np.all(np.isfinite(plan.pose))
    assert all(np.isfinite([plan.cost.total, plan.cost.curvature, plan.cost.ratio, plan.cost.miss]))
    for f in plan.fingers:
        assert np.all(np.isfinite(f.grasp_point)) and np.isfinite(f.curvature) and np.isfinite(f.distance)


def _grid_best(outline, hand, top=4, **grid):
    """The model and the exact evaluation of the ``top`` distinct best poses of a grid."""
    model = efd.fit(outline)
    grid = synthesis.SearchGrid(**grid)
    screen = synthesis.screen_grid(model, hand, grid)
    best = synthesis._reevaluate_best(model, hand, screen, 40, "paper", grid.d_min, synthesis.Safeguards())
    poses = best.poses[synthesis._distinct_best(best, grid, top)]
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
    model = efd.fit(cg.example_contour("can"))
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
