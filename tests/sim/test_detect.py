"""Telling a failed grasp from the closed hand (contourgrasp.sim.detect, Scene.hand_reading): stopped fingers,
a load on the wrist, a hand read once still, a grasp that never closed."""

import numpy as np
import pytest

from contourgrasp import load_hand
from contourgrasp.sim import STRUCK, HandReading, build_scene, execute_grasp, pose_matrix, scripted_grasp
from contourgrasp.sim.detect import hand_holds
from contourgrasp.sim.scene import FREE_CLOSURE_TIME, PARK_HEIGHT
from contourgrasp.sim.trial import carry_away
from contourgrasp.tolerances import HOLD_LOAD, HOLD_READING

GRAVITY = 9.81
HAND = load_hand("five-finger-linear")


def test_the_hand_holds_when_a_joint_stops_short_or_the_wrist_carries_a_load():
    free = HandReading(np.array([0.5, 1.0, 1.2]), 0.0)
    assert not hand_holds(HandReading(free.joints + 0.5 * HOLD_READING, 0.5 * HOLD_LOAD), free)
    assert hand_holds(HandReading(free.joints - [0.0, HOLD_READING, 0.0], 0.0), free)
    assert hand_holds(HandReading(free.joints, HOLD_LOAD), free)  # caged: every finger at its limit
    assert not hand_holds(HandReading(np.array([]), 0.0), HandReading(np.array([]), 0.0))


def test_a_hand_carrying_a_can_reads_its_weight_and_stopped_fingers_and_an_empty_one_its_free_closure():
    scene = build_scene("can", seed=0)
    transform, depth = scripted_grasp(scene, "good")
    assert execute_grasp(scene, transform, depth).success
    carry_away(scene)
    reading, free = scene.hand_reading(), scene.free_closure()
    assert reading.load - free.load == pytest.approx(scene.object.mass * GRAVITY, rel=0.05)  # analytic: m g
    assert np.max(np.abs(reading.joints - free.joints)) > HOLD_READING and hand_holds(reading, free)
    empty = build_scene("can", seed=0)
    empty.set_hand(0.0, 0.0, PARK_HEIGHT, 0.0, closing=1.0)
    empty.step(FREE_CLOSURE_TIME)
    reading, free = empty.hand_reading(), empty.free_closure()
    assert len(free.joints) == 2 * len(HAND.fingers)  # two flexion joints per finger
    assert np.max(np.abs(reading.joints - free.joints)) < 0.1 * HOLD_READING and abs(free.load) < 0.1 * HOLD_LOAD
    assert not hand_holds(reading, free)



def test_a_hand_told_to_close_is_read_once_its_fingers_are_still_and_a_grasp_struck_on_the_way_never_closed():
    scene = build_scene("can", seed=0)
    scene.set_hand(0.0, 0.0, PARK_HEIGHT, 0.0, closing=1.0)
    scene.step(0.05)  # the fingers are closing
    started = scene.time
    reading = scene.hand_reading()
    assert scene.time > started and np.max(np.abs(reading.joints - scene.free_closure().joints)) < HOLD_READING
    assert scene.closed
    struck = build_scene("can", seed=4)
    centre = struck.camera.from_world(struck.object_com())[:2]
    middle_start = np.array([0.0, 0.215])  # the middle finger of five-finger-linear comes down on the can
    outcome = execute_grasp(struck, pose_matrix(*(centre - middle_start), 0.0), struck.camera.height - 0.056)
    assert outcome.cause == STRUCK and not struck.closed
