"""contourgrasp.sim.planners: the baselines and the ablation from paper to default."""

import math

import numpy as np
import pytest

import contourgrasp
from contourgrasp.hand import to_image
from contourgrasp.io.planner_file import load_planner
from contourgrasp.pipeline import plan_frame
from contourgrasp.sim import build_scene, render
from contourgrasp.sim.planners import ABLATION_STEPS, ablation_planners, centroid_pose, make_planner, random_feasible_pose
from contourgrasp.synthesis import evaluate_poses
from contourgrasp.validation import flat_options

HAND = contourgrasp.load_hand("five-finger-linear")


@pytest.mark.parametrize("baseline", ["centroid-principal-axis", "random"])
def test_baselines_share_plan_grasps_perception(baseline):
    scene = build_scene("case", seed=3)
    rgb, depth = render(scene, sensor="basic", seed=3)
    camera = scene.camera.intrinsics
    planned = make_planner(baseline, HAND, seed=3).plan(rgb, depth, camera)
    reference = plan_frame(rgb, depth, camera, HAND)
    np.testing.assert_array_equal(planned.segmentation.mask, reference.segmentation.mask)
    np.testing.assert_array_equal(planned.metric.contour_xy, reference.metric.contour_xy)
    assert planned.approach_depth == reference.metric.approach_depth and planned.camera is camera


def test_centroid_pose_centres_the_hand_with_the_thumb_on_the_minor_axis():
    angle = math.radians(30)
    t = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    ellipse = np.c_[0.06 * np.cos(t), 0.03 * np.sin(t)] @ np.array([[math.cos(angle), math.sin(angle)],
                                                                   [-math.sin(angle), math.cos(angle)]])
    ellipse += [0.1, -0.05]
    pose = centroid_pose(ellipse, HAND)
    np.testing.assert_allclose(to_image(HAND.grasp_centre[None], pose)[0], [0.1, -0.05], atol=1e-6)
    thumb = to_image(np.array([HAND.fingers[0].trajectory.closing_direction]), (0.0, 0.0, pose[2]))[0]
    minor = [-math.sin(angle), math.cos(angle)]
    assert abs(thumb @ minor) == pytest.approx(1.0, abs=1e-6)


def test_random_pose_is_feasible_and_seeded():
    contour = contourgrasp.example_contour("case")
    options = load_planner("paper").options.search
    poses = [random_feasible_pose(contour, HAND, np.random.default_rng(seed), options) for seed in (0, 0, 1)]
    np.testing.assert_array_equal(poses[0], poses[1])
    assert not np.array_equal(poses[0], poses[2])
    model = contourgrasp.contour.fit(contourgrasp.contour.clean_polygon(contour), options.harmonics)
    assert evaluate_poses(model, HAND, np.array(poses), d_min=options.grid.d_min).feasible.all()


def test_ablation_walks_from_paper_to_default_one_group_at_a_time():
    steps = ablation_planners()
    assert steps[0].name == "paper" and steps[-1].options == load_planner("default").options
    groups = dict(ABLATION_STEPS)
    for before, after in zip(steps, steps[1:]):
        ahead, behind = flat_options(after.options), flat_options(before.options)
        changed = {k for k in ahead if ahead[k] != behind[k]}
        step = after.name.rsplit("+", 1)[1]
        assert changed and (step == "other" or changed <= set(groups[step]))
