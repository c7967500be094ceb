"""Grasp execution and trials: scripted good and bad grasps, the causes, determinism."""

import math
from dataclasses import replace

import numpy as np
import pytest

from contourgrasp import InputError, NoFeasibleGrasp, load_hand
from contourgrasp.errors import SimulationError
from contourgrasp.sim import (FAILURE_CAUSES, Camera, ObjectSpec, Part, Workspace, build_scene, execute_grasp, render,
                              pose_matrix, run_trial)
from contourgrasp.sim.planners import make_planner
from contourgrasp.sim.scene import R_WORLD_CAMERA
from contourgrasp.sim.tendon_hand import HandDesign
from contourgrasp.sim.trial import MISSED, NO_PLAN, STRUCK, Execution, scripted_grasp

PAPER = make_planner("paper", load_hand("five-finger-linear"))


def test_scripted_good_grasp_lifts_the_can():
    scene = build_scene("can", seed=4)
    outcome = execute_grasp(scene, *scripted_grasp(scene, "good"))
    assert outcome.success and outcome.cause is None
    assert outcome.lift >= 0.10 and outcome.hold_drift < 0.02
    assert {"thumb", "index"} <= set(outcome.fingers_in_contact)


def test_scripted_bad_grasp_fails():
    scene = build_scene("can", seed=4)
    outcome = execute_grasp(scene, *scripted_grasp(scene, "bad"))
    assert not outcome.success
    assert outcome.cause in FAILURE_CAUSES and outcome.cause != NO_PLAN
    assert "thumb" not in outcome.fingers_in_contact


def test_descending_onto_the_object_is_a_strike():
    scene = build_scene("can", seed=4)
    centre = scene.camera.from_world(scene.object_com())[:2]
    middle_start = np.array([0.0, 0.215])  # the middle finger of five-finger-linear comes down on the can
    outcome = execute_grasp(scene, pose_matrix(*(centre - middle_start), 0.0), scene.camera.height - 0.056)
    assert outcome.cause == STRUCK and not outcome.success


def test_closing_beside_the_object_is_a_miss():
    scene = build_scene("can", seed=4)
    centre = scene.camera.from_world(scene.object_com())[:2]
    beside = centre + [0.0, 0.30]  # the whole open hand 30 cm from the can: every finger closes on air
    outcome = execute_grasp(scene, pose_matrix(*beside, 0.0), scene.camera.height - 0.056)
    assert outcome.cause == MISSED and not outcome.success
    assert outcome.first_contact == () and outcome.push < 0.001


def test_trial_with_the_paper_planner_lifts_the_can():
    record = run_trial("can", seed=1, planner=PAPER, sensor="basic")
    print("\n", record)
    assert record.success, record
    assert len(record.fingers_in_contact) >= 4
    assert record.sim_time > 5.0
    assert record.wall_time < 5.0


def test_too_large_object_is_no_feasible_plan():
    # A 0.8 m disc right under a camera raised to 1 m, so that it is whole in the picture: every pose
    # of the synthesis grid (within 0.15 m of its centre) starts some fingertip inside it. (Smaller
    # discs still let the fingers hook its rim.)
    platter = ObjectSpec("platter", (Part("cylinder", (0.40, 0.01), pos=(0.0, 0.0, 0.01)),), mass=3.0,
                         friction_hand=0.6, friction_table=0.4)
    record = run_trial(platter, seed=0, planner=PAPER, workspace=Workspace(0.0, 0.0),
                       camera=Camera(height=1.0))
    assert not record.success and record.cause == NO_PLAN
    assert record.pose is None and record.fingers_in_contact == ()


@pytest.mark.parametrize("error", [NoFeasibleGrasp("nothing"), InputError("nothing")])
def test_planner_without_a_plan_is_recorded(error):
    def planner(rgb, depth, intrinsics):
        raise error
    ended = []
    record = run_trial("case", seed=1, planner=planner, observe=ended.append)
    assert record.cause == NO_PLAN and record.plan_error == "nothing" and record.plan_time >= 0
    assert len(ended) == 1


def test_same_seed_same_record():
    first = run_trial("bottle", seed=2, planner=PAPER)
    second = run_trial("bottle", seed=2, planner=PAPER)
    assert first == second
    assert first.wall_time != second.wall_time or first.wall_time > 0


def test_pose_must_face_the_table():
    scene = build_scene("can", seed=0)
    flipped = np.diag([1.0, -1.0, -1.0, 1.0])
    with pytest.raises(InputError, match="faces away from the table: its z axis .* points up 90 deg"):
        execute_grasp(scene, flipped, 0.6)


@pytest.mark.parametrize("elevation_deg, azimuth_deg, roll_deg", [(0.0, 30.0, 0.0), (45.0, 200.0, 70.0),
                                                                   (20.0, -100.0, -40.0)])
def test_a_side_or_tilted_approach_travels_along_its_axis_to_the_pose(elevation_deg, azimuth_deg, roll_deg):
    """Far from the can, the open hand comes along its approach axis, stops at the pose, closes on air."""
    scene = build_scene("can", seed=0, design=HandDesign(wrist=True))
    e, a, r = (math.radians(v) for v in (elevation_deg, azimuth_deg, roll_deg))
    approach = np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), -math.sin(e)])  # world
    side = np.cross(approach, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    x = math.cos(r) * side + math.sin(r) * np.cross(approach, side)
    R_world_hand = np.column_stack([x, np.cross(approach, x), approach])
    position = np.array([0.25, 0.3, 0.25])  # the can stands near the origin: nothing in the way
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R_WORLD_CAMERA.T @ R_world_hand, scene.camera.from_world(position)
    outcome = execute_grasp(scene, T, 0.0)
    assert outcome.cause == MISSED and outcome.first_contact == ()
    palm, R = scene.palm_pose()
    np.testing.assert_allclose(palm, position + [0.0, 0.0, Execution().lift_height], atol=2e-3)  # closed, lifted
    np.testing.assert_allclose(R, R_world_hand, atol=0.02)


def test_a_hand_without_a_wrist_refuses_a_side_approach_naming_the_wrist():
    scene = build_scene("can", seed=0)
    T = np.eye(4)
    T[:3, :3] = R_WORLD_CAMERA.T @ np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])  # along world x
    T[:3, 3] = scene.camera.from_world([0.3, 0.3, 0.2])
    with pytest.raises(SimulationError, match="no wrist to tilt or roll: build the scene with HandDesign"):
        execute_grasp(scene, T, 0.0)


def test_a_trial_of_a_planner_with_side_approaches_gets_a_wrist_and_a_top_down_one_does_not():
    from contourgrasp.sim.trial import with_wrist

    hand = load_hand("five-finger-linear")
    planner = make_planner("default", hand)
    assert with_wrist(planner, hand, HandDesign()) == (hand, HandDesign())
    sided = replace(planner, options=replace(planner.options, scene=replace(planner.options.scene,
                                                                            approaches="top+tilted")))
    assert with_wrist(sided, hand, HandDesign())[1].wrist
    assert with_wrist(lambda *a: None, hand, HandDesign())[1] == HandDesign()


def test_a_planned_grasp_height_is_executed():
    """The palm closes at the planned height plus the open tips' depth, not at the execution's own rule."""
    from contourgrasp.sim.trial import execute_grasp, scripted_grasp
    from contourgrasp.sim.scene import build_scene

    for height in (0.03, 0.06):
        scene = build_scene("can", seed=0)
        transform, approach = scripted_grasp(scene, "good")
        outcome = execute_grasp(scene, transform, approach, grasp_height=height)
        assert scene.camera.height - outcome.palm_depth == pytest.approx(scene.hand.open_tip_depth + height)


@pytest.mark.parametrize("tilt_deg", [30.0, 45.0])
def test_a_grasp_planned_from_a_tilted_camera_lifts_the_can(tilt_deg):
    # The picture from a camera tilted 30-45 deg (the structured-light sensor's shadows and noise); the pose planned
    # in its frame is executed from the reference camera's.
    hand = load_hand("five-finger-linear")
    record = run_trial("can", seed=1, planner=make_planner("default", hand, seed=1), tilt=math.radians(tilt_deg))
    assert record.success, record


class _FirstMisses:
    """The ``default`` planner, but its first plan (an empty memory) moved 15 cm aside: it closes on air."""

    def __init__(self, seed):
        self.planner = make_planner("default", load_hand("five-finger-linear"), seed=seed)

    def plan(self, rgb, depth, intrinsics, *, memory=None, **target):
        planned = self.planner.plan(rgb, depth, intrinsics, memory=memory, **target)
        if memory:
            return planned
        aside = planned.T_camera_hand.copy()
        aside[0, 3] += 0.15
        return replace(planned, T_camera_hand=aside)

    def __call__(self, rgb, depth, intrinsics, **target):
        planned = self.plan(rgb, depth, intrinsics, **target)
        return planned.T_camera_hand, planned.approach_depth, planned.grasp_height


def test_a_miss_is_told_by_the_hand_and_the_next_attempt_lifts_the_can():
    record = run_trial("can", seed=1, planner=_FirstMisses(1), attempts=3)
    assert record.outcomes == (False, True) and record.detected == (False, True)
    assert record.success and record.cause is None
    once = run_trial("can", seed=1, planner=_FirstMisses(1))
    assert not once.success and once.cause == MISSED and once.outcomes == () == once.detected


def test_several_attempts_need_a_planner_that_takes_a_memory():
    with pytest.raises(SimulationError, match="several attempts need a planner"):
        run_trial("can", seed=1, planner=lambda rgb, depth, intrinsics: None, attempts=2)
    with pytest.raises(SimulationError, match="attempts must be"):
        run_trial("can", seed=1, planner=PAPER, attempts=9)


@pytest.mark.parametrize("approaches, elevation_deg", [("side", 0.0), ("tilted", 45.0)])
def test_a_standing_can_planned_from_the_side_or_tilted_is_lifted(approaches, elevation_deg):
    """The plan approaches along the kind asked for (its angle below the table measured from its pose), and lifts."""
    from contourgrasp.sim.objects import soda_can

    hand = load_hand("five-finger-linear")
    planner = make_planner("default", hand)
    planner = replace(planner, options=replace(planner.options, scene=replace(planner.options.scene,
                                                                              approaches=approaches)))
    scene = build_scene(soda_can(standing=True), seed=2, hand=hand, design=HandDesign(wrist=True))
    rgb, depth = render(scene, sensor="basic", seed=2)
    planned = planner.plan(rgb, depth, scene.camera.intrinsics)
    assert planned.approach.kind == approaches
    approach_world = R_WORLD_CAMERA @ planned.T_camera_hand[:3, 2]
    assert math.degrees(math.asin(-approach_world[2])) == pytest.approx(elevation_deg, abs=1.0)
    outcome = execute_grasp(scene, planned.T_camera_hand, planned.approach_depth, grasp_height=planned.grasp_height)
    assert outcome.success, outcome
