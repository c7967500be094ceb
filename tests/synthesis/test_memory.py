"""A memory of failed grasps (synthesis.memory): the object's frame, failures mapped through its motion, the plans
that avoid them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import contourgrasp as cg
from contourgrasp import tolerances as tol
from contourgrasp.errors import NoFeasibleGrasp, PlannerError
from contourgrasp.io.camera_file import read_rgbd
from contourgrasp.synthesis import GraspMemory, SearchGrid, SearchOptions, object_frame, search
from contourgrasp.synthesis.outer import EXCLUDED

FRAME = Path(__file__).resolve().parents[2] / "examples" / "bar_clamp"
#: A 6 x 2 cm box's outline, counter-clockwise, centred at (0.03, 0.01).
BOX = np.array([[0.0, 0.0], [0.06, 0.0], [0.06, 0.02], [0.0, 0.02]])


def moved(points, turn, shift):
    """``points`` (n, 2) turned by ``turn`` about the origin, then shifted."""
    c, s = np.cos(turn), np.sin(turn)
    return np.asarray(points) @ np.array([[c, -s], [s, c]]).T + shift


@pytest.mark.parametrize("turn", [0.0, 0.4, -1.2, 2.5])
def test_the_frame_is_the_centroid_and_the_long_axis_either_way_round(turn):
    centre, angle = object_frame(moved(BOX, turn, [0.2, -0.1]))
    np.testing.assert_allclose(centre, moved([[0.03, 0.01]], turn, [0.2, -0.1])[0], atol=1e-6)
    assert np.sin(angle - turn) == pytest.approx(0.0, abs=1e-5)  # the long axis, mod pi
    centre_cw, angle_cw = object_frame(moved(BOX, turn, [0.2, -0.1])[::-1])  # clockwise: the same frame
    np.testing.assert_allclose(centre_cw, centre, atol=1e-9)
    assert np.sin(angle_cw - angle) == pytest.approx(0.0, abs=1e-9)


def test_a_round_outline_keeps_the_planning_frames_orientation():
    circle = 0.03 * np.c_[np.cos(np.linspace(0, 2 * np.pi, 64, endpoint=False)),
                          np.sin(np.linspace(0, 2 * np.pi, 64, endpoint=False))]
    assert object_frame(circle + [0.1, 0.2])[1] == 0.0


@pytest.mark.parametrize("turn", [0.0, 0.5, np.pi / 2])
def test_a_failure_follows_the_object_as_it_moves_and_turns(turn):
    failed = (0.03, 0.05, 0.3)  # beside the box's long side
    memory = GraspMemory().with_failure(BOX, failed)
    now = moved(BOX, turn, [0.1, 0.05])
    there = np.r_[moved([failed[:2]], turn, [0.1, 0.05])[0], failed[2] + turn]
    mirrored = np.r_[moved([[0.03, -0.03]], turn, [0.1, 0.05])[0], failed[2] + turn + np.pi]  # the axis's other way
    near = there + [0.01, 0.0, 0.2]
    far = there + [0.03, 0.0, 0.0]
    turned = there + [0.0, 0.0, 0.5]
    assert memory.excluded(now, [there, mirrored, near, far, turned]).tolist() == [True, True, True, False, False]
    assert not GraspMemory().excluded(now, [there]).any() and len(memory) == 1


def test_the_memory_keeps_the_newest_failures():
    memory = GraspMemory()
    for i in range(tol.MAX_MEMORY_FAILURES + 3):
        memory = memory.with_failure(BOX, (0.001 * i, 0.0, 0.0))
    assert len(memory) == tol.MAX_MEMORY_FAILURES
    assert memory.failures[-1][0] == pytest.approx(0.001 * (tol.MAX_MEMORY_FAILURES + 2) - 0.03, abs=1e-9)


@pytest.mark.parametrize("call, message", [
    (lambda: GraspMemory().with_failure(BOX, (0.0, 0.0)), "pose"),
    (lambda: GraspMemory().with_failure(BOX[:2], (0.0, 0.0, 0.0)), "at least 3 points"),
    (lambda: GraspMemory().with_failure(np.zeros((4, 2)), (0.0, 0.0, 0.0)), "no area"),
    (lambda: GraspMemory().excluded(BOX, [[0.0, np.nan, 0.0]]), "poses"),
])
def test_bad_input_is_a_planner_error_naming_it(call, message):
    with pytest.raises(PlannerError, match=message):
        call()


def test_a_search_with_every_pose_excluded_says_so():
    options = SearchOptions(grid=SearchGrid(yaw_step=np.radians(10)))
    hand = cg.load_hand("three-finger")
    with pytest.raises(NoFeasibleGrasp, match=EXCLUDED.split(" (")[0]):
        search(cg.example_contour("can"), hand, options, exclude=lambda poses: np.ones(len(poses), bool))
    with pytest.raises(PlannerError, match="exclude must be callable"):
        search(cg.example_contour("can"), hand, options, exclude=3)


def test_the_next_plan_of_the_bundled_frame_avoids_the_failed_one():
    frame = read_rgbd(FRAME / "color_0.png", FRAME / "depth_0.npy", FRAME / "primesense_overhead_color.intr")
    first = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, yaw_step=0.1)
    memory = GraspMemory().with_failure(first.metric.contour_xy, first.plan.pose)
    second = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, yaw_step=0.1, memory=memory)
    assert not memory.excluded(second.metric.contour_xy, second.plan.pose[None])[0]
    step = second.plan.pose - first.plan.pose
    turn = abs((step[2] + np.pi) % (2 * np.pi) - np.pi)
    assert np.hypot(*step[:2]) > tol.MEMORY_REACH or turn > tol.MEMORY_TURN
    with pytest.raises(PlannerError, match="memory must be"):
        cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, yaw_step=0.1, memory=[first.plan.pose])


def test_a_scene_memory_gives_the_plan_its_objects_failures_and_not_another_objects():
    from contourgrasp.synthesis import SceneMemory

    frame = read_rgbd(FRAME / "color_0.png", FRAME / "depth_0.npy", FRAME / "primesense_overhead_color.intr")
    first = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, yaw_step=0.1)
    failed = dict(approach=first.approach)
    on_it = SceneMemory().with_failure(first.seen, first.metric.contour_xy, first.plan.pose, **failed)
    elsewhere = np.zeros_like(first.seen)
    elsewhere[:20, :20] = True  # an object in the image's corner, away from the planned one
    on_another = SceneMemory().with_failure(elsewhere, first.metric.contour_xy, first.plan.pose, **failed)
    avoided = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, yaw_step=0.1, memory=on_it)
    assert not np.allclose(avoided.plan.pose, first.plan.pose)
    same = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, yaw_step=0.1, memory=on_another)
    np.testing.assert_array_equal(same.plan.pose, first.plan.pose)


def test_a_failed_direction_is_avoided_of_its_kind_both_ways_round_the_axis_and_turns_with_the_object():
    from contourgrasp.perception import Approach

    bar = np.array([[0.0, 0.0], [0.08, 0.0], [0.08, 0.02], [0.0, 0.02]])  # its axis along x
    failed = Approach(np.pi / 4, 0.3)
    memory = GraspMemory().with_failure(bar, (0.0, 0.0, 0.0), approach=failed)
    assert memory.kinds == ("tilted",) and not memory.failures
    avoided = [memory.avoids(bar, Approach(np.pi / 4, a)) for a in (0.3, 0.5, 0.3 + np.pi, 0.3 + np.pi / 2, 0.7)]
    assert avoided == [True, True, True, False, False]  # MEMORY_TURN is 20 deg
    assert not memory.avoids(bar, Approach(0.0, 0.3))  # a side approach along the same azimuth: another kind
    turned = bar @ np.array([[0.0, 1.0], [-1.0, 0.0]])  # the bar turned a quarter round: its axis along y
    assert memory.avoids(turned, Approach(np.pi / 4, 0.3 + np.pi / 2))
    assert not memory.avoids(turned, Approach(np.pi / 4, 0.3))


def test_a_failure_from_the_side_is_kept_as_its_kind_only():
    square = np.array([[0.0, 0.0], [0.04, 0.0], [0.04, 0.02], [0.0, 0.02]])
    memory = GraspMemory().with_failure(square, (0.02, 0.05, 0.0)).with_failure(square, (0.0, 0.0, 1.0),
                                                                                approach="tilted")
    assert len(memory) == 2 and len(memory.failures) == 1
    assert memory.failures_by_kind() == {"top": 1, "tilted": 1}
    assert memory.excluded(square, [[0.02, 0.05, 0.0], [0.0, 0.0, 1.0]]).tolist() == [True, False]


def test_the_memory_keeps_the_last_failures_of_every_kind_in_order():
    from contourgrasp.tolerances import MAX_MEMORY_FAILURES

    square = np.array([[0.0, 0.0], [0.04, 0.0], [0.04, 0.02], [0.0, 0.02]])
    memory = GraspMemory()
    for k in range(MAX_MEMORY_FAILURES + 3):
        memory = memory.with_failure(square, (0.01 * k, 0.0, 0.0), approach="side" if k % 3 == 0 else "top")
    assert len(memory) == MAX_MEMORY_FAILURES
    assert len(memory.failures) == memory.kinds.count("top")
    assert memory.failures[-1][0] == pytest.approx(0.01 * (MAX_MEMORY_FAILURES + 2) - 0.02, abs=1e-6)  # the last one kept


@pytest.mark.parametrize("approach", ["from above", "", None, "TOP"])
def test_an_unknown_approach_kind_is_refused(approach):
    square = np.array([[0.0, 0.0], [0.04, 0.0], [0.04, 0.02], [0.0, 0.02]])
    with pytest.raises(PlannerError, match="approach"):
        GraspMemory().with_failure(square, (0.0, 0.0, 0.0), approach=approach)


def test_the_kinds_that_failed_fewer_times_are_tried_first():
    from contourgrasp.pipeline import approach_order

    square = np.array([[0.0, 0.0], [0.04, 0.0], [0.04, 0.02], [0.0, 0.02]])
    assert approach_order("top+tilted+side") == ["top", "tilted", "side"]
    once = GraspMemory().with_failure(square, (0.0, 0.0, 0.0))
    assert approach_order("top+tilted+side", once) == ["tilted", "side", "top"]
    twice = once.with_failure(square, (0.0, 0.0, 0.0), approach="tilted")
    assert approach_order("top+tilted+side", twice) == ["side", "top", "tilted"]
    assert approach_order("top", twice) == ["top"]


def _blob(u, v, shape=(120, 160), half=10):
    mask = np.zeros(shape, dtype=bool)
    mask[max(v - half, 0):v + half, max(u - half, 0):u + half] = True
    return mask


def test_a_scene_memory_keeps_each_objects_failures_and_finds_an_object_moved_a_little():
    from contourgrasp.synthesis import SceneMemory

    square = np.array([[0.0, 0.0], [0.04, 0.0], [0.04, 0.02], [0.0, 0.02]])
    left, right = _blob(40, 60), _blob(120, 60)
    memory = SceneMemory()
    for seen in (left, right, left):
        memory = memory.with_failure(seen, square, (0.0, 0.0, 0.0))
    assert len(memory) == 3 and len(memory.objects) == 2
    assert len(memory.of(left)) == 2 and len(memory.of(right)) == 1
    assert len(memory.of(_blob(40 + 25, 60))) == 2  # pushed 25 px: its edge 15 px from where its middle was
    assert len(memory.of(_blob(40 + 35, 60))) == 0  # 35 px: another object (MEMORY_SAME_OBJECT_PX is 20)
    assert len(memory.without(left)) == 1 and len(memory.without(left).of(left)) == 0


def test_a_scene_memory_keeps_its_latest_objects():
    from contourgrasp.synthesis import SceneMemory
    from contourgrasp.tolerances import MAX_MEMORY_OBJECTS

    square = np.array([[0.0, 0.0], [0.04, 0.0], [0.04, 0.02], [0.0, 0.02]])
    blobs = [_blob(5 + 50 * (k % 30), 5 + 50 * (k // 30), shape=(200, 1600), half=3) for k in range(MAX_MEMORY_OBJECTS + 2)]
    memory = SceneMemory()
    for blob in blobs:
        memory = memory.with_failure(blob, square, (0.0, 0.0, 0.0))
    assert len(memory.objects) == MAX_MEMORY_OBJECTS
    assert [len(memory.of(blob)) for blob in (blobs[0], blobs[1], blobs[2], blobs[-1])] == [0, 0, 1, 1]


@pytest.mark.parametrize("seen, message", [
    (np.zeros((4, 4), bool), "empty"), (np.full((4, 4), 2.0), "0 and 1"), (np.ones(4, bool), "(H, W)"),
    (np.ones(4), "(n, n)"),
    ("mask", "numbers"),
])
def test_a_bad_mask_is_refused_by_name(seen, message):
    from contourgrasp.synthesis import SceneMemory

    square = np.array([[0.0, 0.0], [0.04, 0.0], [0.04, 0.02], [0.0, 0.02]])
    with pytest.raises(PlannerError, match=message) as raised:
        SceneMemory().with_failure(seen, square, (0.0, 0.0, 0.0))
    assert "seen" in str(raised.value)
