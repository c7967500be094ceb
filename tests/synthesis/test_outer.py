"""The search (synthesis.outer): plans on the examples, invariances, options, infeasibility."""

import gc
import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import contourgrasp as cg
from contourgrasp import ContourError, NoFeasibleGrasp, contour
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
        assert f.concave == (contour.curvature(plan.efd, [f.t], "geometric")[0] < 0)


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


@pytest.mark.parametrize("option, value", [("xy_step", "0.05"), ("d_min", (0.1, -1)), ("d_max", "wide"),
                                           ("d_max", (0.1, 0.1, 0.1)), ("yaw_step", None), ("top_k", 2.5),
                                           ("top_k", True), ("refine", "yes"), ("finger_thickness", 1),
                                           ("require_closure", None), ("clearance", "0"), ("friction", 1e300),
                                           ("quality_gain", float("nan")), ("max_imbalance", 1.01), ("harmonics", "many"),
                                           ("harmonics", 4.0), ("harmonics", 1_000_000), ("curvature", None),
                                           ("d_max", 1e6), ("xy_step", 1e300)])
def test_a_wrong_type_or_value_of_any_option_is_a_planner_error_naming_it(option, value):
    with pytest.raises(cg.PlannerError, match=option):
        cg.synthesize(cg.example_contour("can"), "three-finger", **{option: value})


def test_an_unknown_option_is_a_planner_error_naming_it():
    with pytest.raises(cg.PlannerError, match="'xy_stp'"):
        cg.synthesize(cg.example_contour("can"), "three-finger", xy_stp=0.01)


@pytest.mark.parametrize("options, shape", [({"xy_step": 1e-4, "d_max": 1.0}, "x 20001 × y 20001 × yaw 180"),
                                            ({"yaw_step": 1e-9}, "x 7 × y 7 × yaw 6283185307"),
                                            ({"xy_step": 0.001, "d_max": 5.0}, "x 10001 × y 10001 × yaw 180")])
def test_a_grid_too_large_is_refused_before_any_work_naming_the_limit_and_its_size(options, shape):
    with pytest.raises(cg.PlannerError, match="at most 1,000,000") as err:
        cg.synthesize(cg.example_contour("can"), "three-finger", **options)
    assert shape in str(err.value) and "poses" in str(err.value)


def test_the_dense_bench_grid_is_within_the_limit():
    assert math.prod(cg.synthesis.SearchGrid(xy_step=0.01, yaw_step=math.radians(1)).shape) == 345_960


bounded_floats = st.floats(1e-6, 0.5)
absurd = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.sampled_from([1e-300, 1e300, -1e300, 0, -1]),
                   st.integers(-10**20, 10**20), st.text(max_size=3), st.none(), st.booleans(),
                   st.tuples(st.floats(), st.floats()))
option_values = {
    "harmonics": st.one_of(st.integers(-3, 200), st.just("adaptive"), absurd),
    "curvature": st.one_of(st.sampled_from(["paper", "geometric"]), absurd),
    "xy_step": st.one_of(st.floats(0.02, 0.2), absurd),
    "yaw_step": st.one_of(st.floats(0.05, 7.0), absurd),
    "d_max": st.one_of(st.floats(0.0, 0.3), st.tuples(st.floats(0.0, 0.3), st.floats(0.0, 0.3)), absurd),
    "d_min": st.one_of(bounded_floats, absurd),
    "top_k": st.one_of(st.integers(-2, 20), absurd),
    "refine": st.one_of(st.booleans(), absurd),
    "finger_thickness": st.one_of(st.booleans(), absurd),
    "clearance": st.one_of(st.floats(0, 0.02), absurd),
    "friction": st.one_of(st.floats(0, 12), absurd),
    "require_closure": st.one_of(st.booleans(), absurd),
    "quality_gain": st.one_of(st.floats(0, 100), absurd),
    "max_imbalance": st.one_of(st.floats(0, 1), absurd),
}


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(options=st.fixed_dictionaries({}, optional=option_values), scale=st.sampled_from([1.0, 1.0, 0.3, 3.0]),
       hand=st.sampled_from(cg.preset_names()), planner=st.sampled_from([None, "paper"]))
def test_fuzz_synthesize_returns_a_plan_or_a_clear_error(options, scale, hand, planner):
    """Any options, bounded or absurd: a finite plan, an InputError or NoFeasibleGrasp, nothing else."""
    options.setdefault("yaw_step", math.radians(20))
    try:
        plan = cg.synthesize(cg.example_contour("case") * scale, hand, planner=planner, **options)
    except (cg.InputError, NoFeasibleGrasp):
        return
    assert np.all(np.isfinite(plan.pose)) and np.isfinite(plan.cost.total)
    assert plan.grid_size <= cg.tolerances.MAX_GRID_POSES


def test_the_small_object_rule_plans_fewer_touching_fingers_and_says_why_when_it_cannot():
    theta = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    disc = 0.02 * np.stack([np.cos(theta), np.sin(theta)], axis=1)  # 4 cm: too small for four fingers
    grid = {"yaw_step": math.radians(10), "xy_step": 0.01}
    with pytest.raises(cg.NoFeasibleGrasp, match="no pose brings 4 fingers"):
        cg.synthesize(disc, "five-finger-linear", **grid)
    plan = cg.synthesize(disc, "five-finger-linear", small_objects=True, **grid)
    assert plan.hand.min_touching == 2 and sum(not f.missed for f in plan.fingers) == 2
    with pytest.raises(cg.NoFeasibleGrasp, match="with the small-object rule, down to 2 touching fingers: no pose"):
        cg.synthesize(disc / 7, "five-finger-linear", small_objects=True, **grid)


def test_a_reason_every_attempt_shares_is_given_once():
    theta = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    table_top = 0.5 * np.stack([np.cos(theta), np.sin(theta)], axis=1)  # 1 m across: larger than the hand
    grid = {"yaw_step": math.radians(30), "xy_step": 0.05}
    with pytest.raises(cg.NoFeasibleGrasp) as refused:
        cg.synthesize(table_top, "five-finger-linear", small_objects=True, **grid)
    message = str(refused.value)
    assert message.count("larger than the hand") == 1
    assert message.endswith("(the same with the small-object rule, down to 2 touching fingers)")


def test_the_low_object_rule_pinches_with_the_thumb_and_the_fingertips_balls_on_the_grown_outline():
    circle = disc(0.04)  # 8 cm across: the fingers reach it as points
    hand = cg.load_hand("five-finger-linear")
    grid = {"yaw_step": math.radians(10), "xy_step": 0.01}
    points = cg.synthesize(circle, hand, **grid)
    assert points.grown == 0.0 and points.hand.min_touching == 4
    pinch = cg.synthesize(circle, hand, low_object=True, **grid)
    radius = min(f.radius for f in hand.fingers)
    assert pinch.grown == radius and "a low object" in pinch.notes[-1]
    assert pinch.hand.min_touching == 2 and pinch.hand.miss_penalty == 0.0
    touching = [f for f in pinch.fingers if not f.missed]
    assert "thumb" in [f.name for f in touching] and len(touching) >= 2
    # a ball touches the disc where its centre meets the disc grown by its radius: 49 mm from the centre
    np.testing.assert_allclose([np.linalg.norm(f.grasp_point) for f in touching], 0.04 + radius, atol=2e-4)
    np.testing.assert_array_equal(pinch.contour, points.contour)  # the plan keeps the outline seen


def test_the_low_object_rule_needs_fingertips_with_a_radius_and_a_flag():
    circle = disc(0.04)
    hand = cg.load_hand("five-finger-linear")
    points = replace(hand, fingers=tuple(replace(f, radius=0.0) for f in hand.fingers), chains=None, palm=None)
    plan = cg.synthesize(circle, points, low_object=True, yaw_step=math.radians(10), xy_step=0.01)
    assert plan.grown == 0.0 and plan.hand.min_touching == 4
    with pytest.raises(cg.PlannerError, match="low_object"):
        cg.synthesize(circle, hand, low_object="yes")


def test_an_attempts_reason_is_worked_out_once_and_only_when_asked():
    from contourgrasp.synthesis.outer import _Unexplained

    calls = []
    failure = _Unexplained(lambda: calls.append(1) or "blocked")
    assert calls == [] and isinstance(failure, NoFeasibleGrasp)
    assert str(failure) == failure.reason == "blocked" and calls == [1]


def test_a_search_whose_first_attempts_fail_leaves_nothing_for_the_garbage_collector():
    """The failed attempts are kept for the no-plan message. Kept with their tracebacks, they held the
    search's frames, and so every screen of the grid, in reference cycles that only the cyclic garbage
    collector frees, late and in bulk: a slow plan in every few."""
    plan = cg.synthesize(cg.example_contour("can"), "five-finger-linear", planner="default")
    assert plan.hand.min_touching < cg.load_hand("five-finger-linear").min_touching  # attempts failed before it
    gc.collect()
    gc.disable()
    try:
        cg.synthesize(cg.example_contour("can"), "five-finger-linear", planner="default")
        assert gc.collect() == 0
    finally:
        gc.enable()


def _pincer(radius: float) -> cg.Hand:
    """Two fingers closing on a line toward each other; their travels end 20 mm apart."""
    return cg.Hand("pincer", (cg.Finger("left", start=(-0.06, 0.0), trajectory=cg.Ray((1.0, 0.0)), travel=0.05,
                                        radius=radius),
                              cg.Finger("right", start=(0.06, 0.0), trajectory=cg.Ray((-1.0, 0.0)), travel=0.05,
                                        radius=radius)), min_touching=2)


def test_the_small_object_rule_closes_fingertip_balls_on_an_object_the_points_cannot_reach():
    grid = {"xy_step": 0.002, "yaw_step": math.radians(15), "d_max": 0.01}
    small = disc(0.005)  # 10 mm across: the points' travels end 20 mm apart
    with pytest.raises(NoFeasibleGrasp, match="onto the object within their travel"):
        cg.synthesize(small, _pincer(0.006), small_objects=False, **grid)
    plan = cg.synthesize(small, _pincer(0.006), small_objects=True, **grid)
    assert plan.grown == 0.006 and "grown by 6.0 mm" in plan.notes[-1]
    assert np.array_equal(plan.contour, contour.clean_polygon(small))
    for finger in plan.fingers:  # each tip's centre stops one radius off the object: 5 + 6 mm from its centre
        assert not finger.missed and np.linalg.norm(finger.grasp_point) == pytest.approx(0.011, abs=2e-4)
    with pytest.raises(NoFeasibleGrasp, match=r"as balls \(the outline grown by 6.0 mm\): no pose brings 2"):
        cg.synthesize(disc(0.003), _pincer(0.006), small_objects=True, **grid)  # 3 + 6 mm < 10 mm
    with pytest.raises(NoFeasibleGrasp) as points:  # fingers of radius 0 are points: nothing to grow
        cg.synthesize(small, _pincer(0.0), small_objects=True, **grid)
    assert "balls" not in str(points.value)


def test_widening_the_exact_evaluation_evaluates_each_pose_once_and_keeps_the_full_evaluations_answer(monkeypatch):
    from contourgrasp.synthesis import outer
    from contourgrasp.synthesis.grid import SearchGrid, screen_grid
    from contourgrasp.synthesis.safeguards import Safeguards

    hand, grid = cg.load_hand("five-finger-linear"), SearchGrid(**FINE)
    model = contour.fit(cg.example_contour("can"), 4)
    screen = screen_grid(model, hand, grid)
    cheapest = np.flatnonzero(screen.feasible)[np.argsort(screen.cost[screen.feasible], kind="stable")]
    refused = {tuple(p) for p in screen.poses[cheapest[:10]]}  # the 10 cheapest fail exactly: the set must widen twice
    sizes, evaluate = [], outer.evaluate_poses

    def failing_the_first_ten(model, hand, poses, **options):
        sizes.append(len(poses))
        result = evaluate(model, hand, poses, **options)
        return replace(result, feasible=result.feasible & [tuple(p) not in refused for p in poses])

    monkeypatch.setattr(outer, "evaluate_poses", failing_the_first_ten)
    widened = outer._reevaluate_best(model, hand, screen, 2, "paper", grid.d_min, Safeguards())
    assert sizes == [2, 6, 24]  # 2, then 8 and 32 in all: each pose once
    whole = failing_the_first_ten(model, hand, screen.poses[cheapest[:32]], d_min=grid.d_min)
    np.testing.assert_array_equal(widened.poses, whole.poses)
    np.testing.assert_array_equal(widened.feasible, whole.feasible)
    np.testing.assert_allclose(widened.cost, whole.cost, rtol=0, atol=1e-12)


def test_a_failure_leads_with_its_cause_in_one_sentence_then_the_attempts():
    """The small-object rule, the balance and the fingertips as balls each add an attempt; the message leads with the
    cause the last of them failed for, and does not repeat it attempt by attempt."""
    tiny = np.c_[0.005 * np.cos(np.linspace(0, 2 * np.pi, 60, endpoint=False)),
                 0.0025 * np.sin(np.linspace(0, 2 * np.pi, 60, endpoint=False))]
    with pytest.raises(NoFeasibleGrasp) as failure:
        cg.synthesize(tiny, "five-finger-linear", planner="default", yaw_step=0.2)
    reason = failure.value.reason
    cause, tried = reason.split(". Tried: ")
    assert cause == "the object is too small or too far from the hand's grasp region"
    assert cause not in tried and tried.count("; ") == 3 and "with the fingertips as balls" in tried
