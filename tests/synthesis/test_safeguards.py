"""Safeguards beyond the thesis: finger thickness, grasp quality and the squeeze's balance in the synthesis."""

import dataclasses
import math

import numpy as np
import pytest

import contourgrasp as cg
from contourgrasp import InputError, NoFeasibleGrasp
from contourgrasp.hand import Finger, Hand, Ray
from contourgrasp.synthesis import Safeguards, fingers_clear, grasp_imbalance
from contourgrasp.synthesis.cost import centring_distance
from contourgrasp.synthesis._cost_kernels import contact_imbalance

FAST = {"yaw_step": math.radians(10), "xy_step": 0.02}


def circle(radius, n=720):
    theta = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return radius * np.stack([np.cos(theta), np.sin(theta)], axis=1)


def one_finger(start, direction, *, radius, travel=0.1):
    finger = Finger("f", start=start, trajectory=Ray(direction), travel=travel, radius=radius)
    return Hand("one", (finger,), min_touching=1)


def test_start_clearance_is_radius_plus_clearance():
    disc = circle(0.03)
    hand = one_finger((-0.05, 0.0), (1.0, 0.0), radius=0.01)  # starts 0.02 m from the disc, closing at its centre
    lam, point = np.array([[0.02]]), np.array([[[-0.03, 0.0]]])
    pose = np.zeros((1, 3))
    assert fingers_clear(disc, hand, pose, lam, point, clearance=0.0)[0]
    assert fingers_clear(disc, hand, pose, lam, point, clearance=0.0099)[0]
    assert not fingers_clear(disc, hand, pose, lam, point, clearance=0.0101)[0]


def test_a_grazing_finger_strikes_the_object_before_its_grasp_point():
    box = np.array([[0.0, 0.0], [0.1, 0.0], [0.1, 0.04], [0.0, 0.04]])
    # closing along x at height y = 0.045: the thin finger passes 5 mm above the box, a 9 mm one hits its top
    hand = one_finger((-0.03, 0.045), (1.0, 0.0), radius=0.009, travel=0.2)
    missed = np.full((1, 1), np.nan), np.full((1, 1, 2), np.nan)
    assert not fingers_clear(box, hand, np.zeros((1, 3)), *missed)[0]
    thin = one_finger((-0.03, 0.045), (1.0, 0.0), radius=0.004, travel=0.2)
    assert fingers_clear(box, thin, np.zeros((1, 3)), *missed)[0]


def test_a_head_on_approach_is_clear_and_the_check_follows_the_pose():
    box = np.array([[0.0, 0.0], [0.1, 0.0], [0.1, 0.04], [0.0, 0.04]])
    hand = one_finger((-0.05, 0.02), (1.0, 0.0), radius=0.009)
    lam, point = np.array([[0.05]]), np.array([[[0.0, 0.02]]])
    assert fingers_clear(box, hand, np.zeros((1, 3)), lam, point)[0]
    # turned by 90 deg about the hand origin it starts at (-0.02, -0.05) and closes along +y, 2 cm beside the box
    turned, missed = np.array([[0.0, 0.0, math.pi / 2]]), (np.full((1, 1), np.nan), np.full((1, 1, 2), np.nan))
    assert fingers_clear(box, hand, turned, *missed)[0]
    wide = one_finger((-0.05, 0.02), (1.0, 0.0), radius=0.025)
    assert not fingers_clear(box, wide, turned, *missed)[0]


def test_zero_radius_and_clearance_change_nothing():
    contour, hand = cg.example_contour("case"), cg.load_hand("three-finger")
    # 2-D fingertips of radius 0 (the 3-D body, whose links have the fingers' radius, dropped)
    thin = dataclasses.replace(hand, fingers=tuple(dataclasses.replace(f, radius=0.0) for f in hand.fingers),
                               chains=None, palm=None)
    plain = cg.synthesize(contour, thin, **FAST)
    checked = cg.synthesize(contour, thin, finger_thickness=True, **FAST)
    np.testing.assert_array_equal(plain.pose, checked.pose)
    assert plain.cost == checked.cost


def test_thick_fingers_start_clear_of_the_contour():
    contour = cg.example_contour("can")
    hand = cg.load_hand("five-finger-linear")
    plan = cg.synthesize(contour, hand, finger_thickness=True, clearance=0.005, **FAST)
    samples = cg.contour.sample(plan.efd, 2048)[1]
    for finger, contact in zip(hand.fingers, plan.fingers, strict=True):
        gap = np.linalg.norm(samples - contact.start, axis=1).min()
        assert gap >= finger.radius + 0.005 - 1e-4


def test_every_plan_reports_its_quality():
    plan = cg.synthesize(cg.example_contour("can"), "three-finger", **FAST)
    assert plan.quality.force_closure and plan.quality.epsilon > 0 and plan.quality.mu == 0.5
    frictionless = cg.synthesize(cg.example_contour("can"), "three-finger", friction=0.0, **FAST)
    assert frictionless.quality.epsilon <= plan.quality.epsilon


def test_quality_gain_never_lowers_epsilon():
    # the same candidates ranked with -gain * epsilon added: the chosen epsilon cannot drop
    contour, hand = cg.example_contour("bottle"), cg.load_hand("five-finger-linear")
    plain = cg.synthesize(contour, hand, **FAST)
    graded = cg.synthesize(contour, hand, quality_gain=500.0, **FAST)
    assert graded.quality.epsilon >= plain.quality.epsilon - 1e-12
    assert graded.cost.quality == pytest.approx(-500.0 * graded.quality.epsilon)
    assert graded.cost.total == pytest.approx(graded.cost.curvature + graded.cost.ratio + graded.cost.miss
                                              + graded.cost.quality)


def test_required_closure_holds_or_is_refused():
    plan = cg.synthesize(cg.example_contour("case"), "five-finger-linear", require_closure=True, **FAST)
    assert plan.quality.force_closure
    # one finger alone can never hold an object in force closure
    lone = one_finger((-0.08, 0.0), (1.0, 0.0), radius=0.0)
    with pytest.raises(NoFeasibleGrasp, match="force closure"):
        cg.synthesize(circle(0.03), lone, require_closure=True, **FAST)


def test_a_balanced_squeeze_is_planned_when_one_exists():
    # four fingers along one side of the case outpush the thumb; the thumb against one or two balances
    contour = cg.example_contour("case")
    hand = dataclasses.replace(cg.load_hand("five-finger-linear"), min_touching=2)
    free = cg.synthesize(contour, hand, require_closure=True, **FAST)
    assert free.quality.imbalance > 0.5
    balanced = cg.synthesize(contour, hand, require_closure=True, max_imbalance=0.25, **FAST)
    assert balanced.quality.imbalance <= 0.25 and balanced.safeguards.max_imbalance == 0.25
    assert balanced.cost.total >= free.cost.total  # the cheapest pose passing it costs no less
    assert balanced.notes == ()


def test_the_hands_own_balance_is_the_one_planned_with():
    contour = cg.example_contour("case")
    hand = dataclasses.replace(cg.load_hand("five-finger-linear"), min_touching=2)
    assert hand.max_imbalance == 0.25  # tolerances.HAND_MAX_IMBALANCE: the file states none
    for own in (0.25, 1.0):
        mine = dataclasses.replace(hand, max_imbalance=own)
        plan = cg.synthesize(contour, mine, require_closure=True, max_imbalance="hand", **FAST)
        same = cg.synthesize(contour, mine, require_closure=True, max_imbalance=own, **FAST)
        assert plan.safeguards.max_imbalance == own
        np.testing.assert_array_equal(plan.pose, same.pose)
    with pytest.raises(InputError, match="max_imbalance must be one of 'hand'"):
        cg.synthesize(contour, hand, max_imbalance="hands", **FAST)


def test_without_a_balanced_pose_the_plan_is_the_unbalanced_best_and_says_so():
    contour, hand = cg.example_contour("case"), cg.load_hand("five-finger-linear")  # four fingers must touch
    free = cg.synthesize(contour, hand, require_closure=True, **FAST)
    plan = cg.synthesize(contour, hand, require_closure=True, max_imbalance=0.25, **FAST)
    np.testing.assert_array_equal(plan.pose, free.pose)
    assert plan.safeguards.max_imbalance == 0.25 and plan.quality.imbalance == free.quality.imbalance > 0.25
    assert plan.notes == (f"no pose balances the squeeze within max_imbalance = 0.25: planned without it; with every "
                          f"finger pushing equally hard, {free.quality.imbalance:.2f} of their force is left to "
                          "friction",)


def test_a_required_balance_is_no_grasp_where_no_pose_balances_and_the_same_plan_where_one_does():
    contour, hand = cg.example_contour("case"), cg.load_hand("five-finger-linear")
    with pytest.raises(NoFeasibleGrasp, match="balances the squeeze") as refused:
        cg.synthesize(contour, hand, require_closure=True, max_imbalance=0.25, balance_required=True, **FAST)
    assert "without the squeeze's balance" not in str(refused.value)  # no fallback was searched
    two = dataclasses.replace(hand, min_touching=2)
    preferred = cg.synthesize(contour, two, require_closure=True, max_imbalance=0.25, **FAST)
    required = cg.synthesize(contour, two, require_closure=True, max_imbalance=0.25, balance_required=True, **FAST)
    np.testing.assert_array_equal(required.pose, preferred.pose)
    with pytest.raises(InputError, match="balance_required"):
        cg.synthesize(contour, two, balance_required="yes", **FAST)


def test_a_balanced_alternative_is_planned_before_the_balance_is_given_up():
    contour, hand = cg.example_contour("case"), cg.load_hand("five-finger-linear")  # no balanced pose (above)
    two = dataclasses.replace(hand, min_touching=2)
    options = {"require_closure": True, "max_imbalance": 0.25, **FAST}
    elsewhere = cg.synthesize(contour, two, **options)  # stands for another outline's plan
    calls = []

    def alternative(plan=elsewhere):
        calls.append(plan)
        if plan is None:
            raise NoFeasibleGrasp("none there either")
        return plan

    assert cg.synthesize(contour, hand, balanced_alternative=alternative, **options) is elsewhere
    assert cg.synthesize(contour, hand, balanced_alternative=alternative, balance_required=True, **options) is elsewhere
    assert len(calls) == 2  # once per search
    calls.clear()
    unbalanced = cg.synthesize(contour, hand, balanced_alternative=lambda: alternative(None), **options)
    assert len(calls) == 1 and "planned without it" in unbalanced.notes[0]  # it failed: the search went on
    np.testing.assert_array_equal(unbalanced.pose, cg.synthesize(contour, hand, **options).pose)
    calls.clear()
    balanced = cg.synthesize(contour, two, balanced_alternative=alternative, **options)
    assert calls == [] and balanced.balanced  # a pose balances on the outline itself: never asked
    with pytest.raises(InputError, match="balanced_alternative must be callable"):
        cg.synthesize(contour, hand, balanced_alternative=elsewhere, **options)


def test_a_plan_made_elsewhere_is_not_labelled_as_the_grown_outline_s():
    theta = np.linspace(0.0, 2 * np.pi, 200, endpoint=False)
    disc = 0.013 * np.c_[np.cos(theta), np.sin(theta)]  # no two fingertips, as points, close on 26 mm
    hand, options = cg.load_hand("five-finger-linear"), {"yaw_step": math.radians(10), "xy_step": 0.01}
    grown = cg.synthesize(disc, hand, small_objects=True, max_imbalance=0.01, **options)
    assert grown.grown == 0.009 and not grown.balanced  # the balls' outline, no pose balanced there
    elsewhere = cg.synthesize(cg.example_contour("can"), hand, **options)
    plan = cg.synthesize(disc, hand, small_objects=True, max_imbalance=0.01, balanced_alternative=lambda: elsewhere,
                         **options)
    assert plan is elsewhere and plan.grown == 0.0  # asked for on the grown outline, returned as it came
    pinch = cg.synthesize(disc * 4, hand, low_object=True, max_imbalance=0.01, balanced_alternative=lambda: elsewhere,
                          **options)
    assert pinch is elsewhere  # the low-object rule's pinch, unbalanced, turned to it: not labelled a pinch


def test_the_alternative_waits_while_the_fingers_cannot_reach_the_object_as_points():
    from contourgrasp.synthesis.outer import _Elsewhere, _OutOfReach

    calls = []
    elsewhere = _Elsewhere(lambda: calls.append(1) or "plan")
    assert elsewhere.after(_OutOfReach("too small")) is None and calls == []  # the grown outline goes first
    assert elsewhere.after(NoFeasibleGrasp("unbalanced")) == "plan" == elsewhere.after(NoFeasibleGrasp("again"))
    assert calls == [1]
    assert _Elsewhere(None).after(NoFeasibleGrasp("unbalanced")) is None


def test_the_no_grasp_reason_names_the_squeeze():
    from contourgrasp.synthesis.evaluate import evaluate_poses
    from contourgrasp.synthesis.outer import _diagnose_exact

    lone = one_finger((-0.08, 0.0), (1.0, 0.0), radius=0.0)  # one finger pushes alone: all its force is left over
    guards = Safeguards(max_imbalance=0.5)
    result = evaluate_poses(cg.contour.fit(circle(0.03), 4), lone, np.zeros((1, 3)), safeguards=guards)
    assert result.touching.all() and not result.feasible.any()
    assert _diagnose_exact(result, guards) == (
        "none of the 1 poses that reach the object balances the squeeze: with every finger pushing equally hard, "
        "the least net force left is 1.00 of their sum (max_imbalance = 0.5)")


def test_two_opposed_fingers_balance_a_disc():
    pair = Hand("pair", (Finger("a", start=(-0.06, 0.0), trajectory=Ray((1.0, 0.0)), travel=0.1),
                         Finger("b", start=(0.06, 0.0), trajectory=Ray((-1.0, 0.0)), travel=0.1)), min_touching=2)
    plan = cg.synthesize(circle(0.03), pair, max_imbalance=1e-6, **FAST)
    assert plan.quality.imbalance == pytest.approx(0.0, abs=1e-6)


def test_the_screens_compiled_balance_is_the_squeezes_on_a_disc_and_equals_it_on_any_contour():
    radius = 0.04
    disc = cg.contour.fit(circle(radius), harmonics=1)
    at = np.radians([[180, -60, -20, 20, 60], [0, 180, 0, 0, 0], [90, 0, 0, 0, 0], [0, 0, 0, 0, 0]])
    t = np.mod(at, 2 * np.pi) * disc.T / (2 * np.pi) + 0.0  # the fit starts at angle 0, counter-clockwise
    touching = np.array([[1, 1, 1, 1, 1], [1, 1, 0, 0, 0], [1, 0, 0, 0, 0], [0, 0, 0, 0, 0]], bool)
    share = contact_imbalance(disc.coefficients, disc.T, t, touching, 1e-12)
    # the thumb against four fingers over 120 deg (quality.imbalance's example), an opposed pair, one finger, none
    assert share == pytest.approx([0.376, 0.0, 1.0, 1.0], abs=1e-3)
    theta = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    blob = cg.contour.fit(np.c_[(0.05 + 0.01 * np.cos(3 * theta)) * np.cos(theta), 0.03 * np.sin(theta)], harmonics=12)
    rng = np.random.default_rng(0)
    t, touching = rng.uniform(0, blob.T, (500, 5)), rng.random((500, 5)) < 0.7
    assert contact_imbalance(blob.coefficients, blob.T, t, touching, 1e-12) == pytest.approx(
        grasp_imbalance(blob, t, touching), abs=1e-12)


def test_the_pinch_centre_is_midway_between_thumb_and_the_nearest_closed_tip():
    hand = cg.load_hand("five-finger-linear")  # thumb closes to (-25.5, 109.5) mm, the index to (-26.3, 145.1)
    np.testing.assert_allclose(hand.pinch_centre, (hand.ends[0] + hand.ends[1]) / 2)
    assert np.linalg.norm(hand.ends[1] - hand.ends[0]) < min(np.linalg.norm(hand.ends[2:] - hand.ends[0], axis=1))


def test_centring_distance_is_measured_in_the_hand_frame():
    hand = cg.load_hand("five-finger-linear")
    c = hand.pinch_centre
    # the hand turned 90 deg: its pinch centre (cx, cy) lies at (-cy, cx) from its origin in the image
    poses = np.array([[0.0, 0.0, math.pi / 2], [0.0, 0.0, math.pi / 2], [0.01, 0.0, 0.0]])
    locus = np.array([-c[1], c[0]])
    d = centring_distance(hand, poses[:2], locus)
    assert d[0] == pytest.approx(0.0, abs=1e-12)
    assert centring_distance(hand, poses[2:], c + [0.01 + 0.03, 0.04])[0] == pytest.approx(0.05)


def test_centring_distance_on_a_grid_takes_each_yaw_once_and_gives_the_same():
    hand = cg.load_hand("five-finger-linear")
    grid = cg.synthesis.SearchGrid(xy_step=0.02, yaw_step=math.radians(30))
    poses = grid.poses(np.zeros(2))
    locus = np.array([0.01, -0.02])
    n_yaw = grid.shape[2]
    np.testing.assert_allclose(centring_distance(hand, poses, locus, n_yaw=n_yaw),
                               centring_distance(hand, poses, locus), rtol=0, atol=1e-15)
    assert centring_distance(hand, poses[:0], locus, n_yaw=n_yaw).shape == (0,)
    # the hand turned 90 deg puts its pinch centre (cx, cy) at (-cy, cx) from its origin, on the grid too
    turned = (poses[:, 2] == poses[3, 2]) & np.all(poses[:, :2] == 0, axis=1)
    assert poses[3, 2] == pytest.approx(math.pi / 2) and turned.sum() == 1
    c = hand.pinch_centre
    assert centring_distance(hand, poses, [-c[1], c[0]], n_yaw=n_yaw)[turned] == pytest.approx(0.0, abs=1e-12)


def test_the_centring_gain_adds_its_cost_and_brings_the_object_to_the_pinch_centre():
    contour, hand = cg.example_contour("bottle"), cg.load_hand("five-finger-linear")
    plain = cg.synthesize(contour, hand, **FAST)
    centred = cg.synthesize(contour, hand, centring_gain=1000.0, **FAST)
    locus = cg.contour.fit(contour, 4).locus
    def distance(plan):
        return float(centring_distance(hand, np.array([plan.pose]), locus)[0])
    assert distance(centred) <= distance(plain) and distance(centred) < 0.02  # within a grid step of it
    assert plain.cost.centring == 0.0
    assert centred.cost.centring == pytest.approx(1000.0 * (distance(centred) / 0.01) ** 2)
    assert centred.cost.total == pytest.approx(centred.cost.curvature + centred.cost.ratio + centred.cost.miss
                                               + centred.cost.quality + centred.cost.centring)


@pytest.mark.parametrize("option", [{"clearance": -0.01}, {"friction": float("nan")}, {"quality_gain": -1.0},
                                    {"centring_gain": -1.0}, {"centring_gain": float("inf")}, {"centring_gain": 1e7},
                                    {"max_imbalance": 1.5}, {"max_imbalance": -0.1}])
def test_bad_safeguards_are_refused_by_name(option):
    with pytest.raises(InputError, match=next(iter(option))):
        Safeguards(**option)


def test_a_squeeze_no_screened_pose_balances_is_refused_before_exact_evaluation_then_planned_without():
    lone = one_finger((-0.08, 0.0), (1.0, 0.0), radius=0.0)
    with pytest.raises(NoFeasibleGrasp, match=r"^none of the \d+ poses that reach the object puts its grasp points in "
                                              r"force closure\. Tried: none of the \d+ poses that reach the object "
                                              r"balances the squeeze.*least net force left is 1.00.*; without the "
                                              "squeeze's balance: .*force closure"):
        cg.synthesize(circle(0.03), lone, max_imbalance=0.5, require_closure=True, **FAST)
    plan = cg.synthesize(circle(0.03), lone, max_imbalance=0.5, **FAST)
    assert plan.quality.imbalance == 1.0 and "no pose balances the squeeze" in plan.notes[-1]
