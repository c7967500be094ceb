"""The descent check against MuJoCo's own collision test of the open hand (the simulation as oracle).

A standing can is rendered and planned on as a user's frame would be; on 240 sampled poses and grasp
heights the height-map check (what the planner sees, through the noiseless camera) is compared with
MuJoCo's contacts of the simulated open hand, placed at that pose over the true can. The check must
never call a pose clear that MuJoCo finds touching; it may call a clear pose blocked where the
camera could not see (the can's occlusion shadow is bounded conservatively), but rarely, and it
refuses a hand over cells outside the camera's view.

The same for the hand models, whose bodies the planner knows from ``hand-from-model``:
measured chains of capsules of the fingertip's radius and the palm box's tilted underside, against
the model's own mesh geoms. The Jaco's agree as closely as our hand's; the Inspire's links are
wider than its fingertips and its palm is a box, so its band is wider (:data:`BANDS`).
"""

import numpy as np
import pytest

from contourgrasp import load_hand, pipeline, plan_grasp
from contourgrasp.hand import to_image
from contourgrasp.handmodels.mount import mount_model
from contourgrasp.sim.objects import soda_can
from contourgrasp.sim.render import render
from contourgrasp.sim.scene import build_scene
from contourgrasp.sim.trial import _Probe, hand_pose_from_matrix
from contourgrasp.synthesis import descent_clearance

#: Clearances within this of zero (m) are not compared, per hand: the map's 2 mm cells and MuJoCo's mesh-free
#: cylinder differ by up to a cell's half diagonal there; the Inspire's capsules (its fingertips' 6-7 mm radius)
#: miss the bulge of its thumb's links and its palm box's rounded edge (measured on these poses, the thumb
#: levelled with the deepest finger: 1 of 63 poses called clear by more than 4 mm touched, at 12.7 mm, its
#: thumb's second collision geom (thumb_1) 2.3 mm into the can where its capsules are 22 mm clear or more;
#: levelled with the fingers' mean, 3 of 69, none beyond 12 mm).
BANDS = {"five-finger-linear": 0.004, "jaco-three-finger": 0.004, "inspire": 0.013}


@pytest.fixture(scope="module", params=list(BANDS))
def sampled(request):
    name = request.param
    hand, simulated = (load_hand(name),) * 2 if name == "five-finger-linear" else _mounted(name)
    scene = build_scene(soda_can(standing=True), seed=3, hand=simulated)
    rgb, depth = render(scene, sensor="ideal")
    planned = plan_grasp(rgb, depth, scene.camera.intrinsics, hand, xy_step=0.02, yaw_step=0.2)
    centre = planned.metric.contour_xy.mean(axis=0)
    rng = np.random.default_rng(7)
    n = 240
    yaw = rng.uniform(0.0, 2 * np.pi, n)
    grasp_centre = np.stack([to_image(hand.grasp_centre[None], (0.0, 0.0, a))[0] for a in yaw])
    poses = np.c_[centre - grasp_centre + rng.uniform(-0.07, 0.07, (n, 2)), yaw]  # the hand's grasp region near the can
    tips = rng.choice([0.02, 0.06, 0.10], n)
    predicted = descent_clearance(hand, planned.height_map, poses, tips).min(axis=1)
    scene.set_hand(0.0, 0.0, 0.6, 0.0)
    scene.step(2.0)  # a model's fingers settle open (the Inspire's thumb turns to oppose); set_hand keeps them so
    probe = _Probe(scene)
    touched = np.zeros(n, dtype=bool)
    for i, (pose, tip) in enumerate(zip(poses, tips)):
        x, y, yaw = hand_pose_from_matrix(pipeline.hand_pose(planned.metric, pose, 0.5))
        world = scene.camera.to_world([x, y, 0.0])[:2]
        scene.set_hand(*world, scene.hand.open_tip_depth + tip, yaw)
        touched[i] = bool(probe.touching())
    return predicted, touched, BANDS[name]


def _mounted(name):
    mounted = mount_model(name)
    return mounted.hand, mounted


def test_no_pose_the_check_calls_clear_touches_the_can_in_mujoco(sampled):
    predicted, touched, band = sampled
    clear = predicted > band
    assert clear.sum() > 20 and not touched[clear].any()


def test_poses_the_check_calls_blocked_touch_the_can_in_mujoco_but_for_the_unseen_shadow(sampled):
    """Blocked by a seen or bounded cell, that is: a hand over cells outside the camera's view (-inf) is refused
    because nothing is known there, not because MuJoCo would find it touching."""
    predicted, touched, band = sampled
    blocked = (predicted < -band) & np.isfinite(predicted)
    assert blocked.sum() > 40 and touched[blocked].mean() >= 0.85
