"""Clearing a table (sim.clearing): what ends a run, what counts, objects taken out of a scene, a failure's object."""

from dataclasses import replace

import numpy as np
import pytest

from contourgrasp import load_hand
from contourgrasp.tolerances import MAX_OBJECTS_TRIED
from contourgrasp.errors import NoFeasibleGrasp, SimulationError
from contourgrasp.sim import HIT, MISSED, NO_PLAN, build_clutter, render, run_clearing, truth_labels
from contourgrasp.sim.clearing import CLEARED, FAILED_IN_A_ROW, FAILURES_IN_A_ROW, NOTHING_PLANNED
from contourgrasp.perception import hand_opening
from contourgrasp.pipeline import find_objects
from contourgrasp.sim.planners import make_planner

POOL = ("can-standing", "case")
HAND = load_hand("five-finger-linear")


def test_a_clutter_of_cans_and_a_case_is_cleared_every_attempt_told_right():
    record = run_clearing("can", seed=1, planner=make_planner("default", HAND), pool=POOL)
    assert record.ended == CLEARED and record.success and record.cause is None
    assert record.cleared == record.scene_objects == 4
    assert record.outcomes == record.detected == (True,) * 4


def test_same_seed_same_run_in_a_bin():
    first, again = (run_clearing("can", seed=2, planner=make_planner("default", HAND), pool=POOL, scene_kind="bin")
                    for _ in range(2))
    assert first == again and first.ended == CLEARED and first.cleared == first.scene_objects == 1


class _Aside:
    """The ``default`` planner with every plan moved 30 cm aside, over bare table: it closes on air."""

    hand = HAND

    def __init__(self):
        self.planner, self.memories = make_planner("default", HAND), []

    def plan(self, rgb, depth, intrinsics, *, memory=None, **target):
        planned = self.planner.plan(rgb, depth, intrinsics, memory=memory, **target)
        self.memories.append((len(memory), target.get("target_px"), planned.seen))
        aside = planned.T_camera_hand.copy()
        aside[1, 3] += 0.3
        return replace(planned, T_camera_hand=aside)


def test_two_grasps_on_air_told_by_the_joints_end_the_run_the_second_on_another_object():
    planner = _Aside()
    record = run_clearing("can", seed=1, planner=planner, pool=POOL)
    assert record.ended == FAILED_IN_A_ROW and not record.success and record.cleared == 0
    assert record.outcomes == record.detected == (False,) * FAILURES_IN_A_ROW and record.cause in (MISSED, HIT)
    (first_memory, first_pixel, first_seen), (second_memory, second_pixel, _) = planner.memories
    assert first_memory == second_memory == 0 and first_pixel is None  # the planner's own choice, then ...
    assert not first_seen[second_pixel[1], second_pixel[0]]  # ... an object no grasp failed on


class _NoPlan:
    """Never has a plan; keeps the target pixel of every call."""

    hand = HAND

    def __init__(self):
        self.asked = []

    def plan(self, rgb, depth, intrinsics, *, memory=None, target_px=None):
        self.asked.append((target_px, rgb, depth, intrinsics))
        raise NoFeasibleGrasp("no plan here")


@pytest.mark.parametrize("kind", ["clutter", "bin"])
def test_with_no_plan_every_object_the_hand_spans_is_asked_about_then_the_run_ends(kind):
    """In a bin, the walls (and what touches them) make a region wider than the hand opens: never asked about."""
    planner = _NoPlan()
    record = run_clearing("can", seed=1, planner=planner, pool=POOL, scene_kind=kind)
    assert record.ended == NOTHING_PLANNED and record.outcomes == () and record.cleared == 0
    assert record.plan_error == "no plan here" and record.pose is None and record.cause == NO_PLAN
    first, *others = [pixel for pixel, *_ in planner.asked]
    assert first is None and 1 <= len(others) <= MAX_OBJECTS_TRIED and len(set(others)) == len(others)
    _, rgb, depth, intrinsics = planner.asked[0]
    candidates = find_objects(depth, intrinsics, rgb=rgb).candidates
    assert kind == "clutter" or any(c.in_view and c.extent[1] > hand_opening(HAND) for c in candidates)  # the walls
    assert len(others) == sum(c.in_view and c.extent[1] <= hand_opening(HAND) for c in candidates)
    scene = build_clutter("can", POOL, kind=kind, seed=1)
    labels = truth_labels(scene)
    assert all(labels[v, u] > 0 for u, v in others)  # each pixel on an object


def test_an_object_taken_out_leaves_the_scene_stays_out_and_is_never_a_neighbour():
    scene = build_clutter("can", POOL, kind="clutter", seed=1, settle=0.2)
    assert len(scene.objects) == 4 and scene.present == (0, 1, 2, 3) and scene.on_support().all()
    scene.remove(1)
    assert scene.present == (0, 2, 3) and len(scene.neighbour_coms()) == 2 and scene.on_support().all()
    assert not (truth_labels(scene) == 2).any()
    parked = scene.data.xipos[scene.model.body("neighbour_0").id].copy()
    scene.step(1.0)
    assert np.linalg.norm(scene.data.xipos[scene.model.body("neighbour_0").id] - parked) < 1e-3
    with pytest.raises(SimulationError, match="not in the scene"):
        scene.retarget(1)
    scene.retarget(2)
    assert scene.object is scene.objects[2] and scene.object.name == "case"
    assert (truth_labels(scene) == 3).any() and len(scene.neighbour_coms()) == 2


def test_clearing_needs_several_objects_and_a_planner_that_remembers():
    with pytest.raises(SimulationError, match="scene"):
        run_clearing("can", seed=0, planner=make_planner("default", HAND), pool=POOL, scene_kind="single")
    with pytest.raises(SimulationError, match="plan method"):
        run_clearing("can", seed=0, planner=lambda rgb, depth, intrinsics: None, pool=POOL)
