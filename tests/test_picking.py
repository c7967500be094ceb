"""picking: a plan on some object of a scene of several -- its own choice first, the objects a grasp failed on
last, the next object where the one chosen has no grasp (a real bin frame)."""

import os
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import contourgrasp as cg
from contourgrasp import picking, pipeline
from contourgrasp.io.camera_file import read_rgbd

REPO = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("CONTOURGRASP_SHARED_DATA", REPO.parent / "shared" / "data"))
needs_shared = pytest.mark.skipif(not (SHARED / "rgbd").is_dir(), reason=f"the shared real frames are not at {SHARED}")

@pytest.fixture(scope="module")
def clutter_frame():
    from contourgrasp.sim import build_clutter, render

    scene = build_clutter("can", ("can-standing", "case"), kind="clutter", seed=1)
    rgb, depth = render(scene, sensor="structured-light", seed=1)
    return rgb, depth, scene.camera.intrinsics


def test_plan_any_plans_the_object_it_chooses_itself_first(clutter_frame):
    hand, options = cg.load_hand("five-finger-linear"), cg.load_planner("default").options
    chosen = pipeline.plan_frame(*clutter_frame, hand, options)
    anyone = picking.plan_any(*clutter_frame, hand, options)
    assert anyone.target.label == chosen.target.label and np.array_equal(anyone.plan.pose, chosen.plan.pose)


def test_plan_any_tries_the_objects_a_grasp_failed_on_last(clutter_frame):
    from contourgrasp.errors import PlannerError
    from contourgrasp.perception import hand_opening
    from contourgrasp.synthesis import SceneMemory

    hand, options = cg.load_hand("five-finger-linear"), cg.load_planner("default").options
    first = pipeline.plan_frame(*clutter_frame, hand, options)
    memory = SceneMemory().with_failure(first.seen, first.metric.contour_xy, first.plan.pose)
    support = pipeline.find_objects(clutter_frame[1], clutter_frame[2], rgb=clutter_frame[0])
    order = picking.objects_to_try(support.candidates, hand, memory)
    assert len(order) >= 2 and (order[-1].mask & first.seen).any() and not (order[0].mask & first.seen).any()
    assert all(c.in_view and c.extent[1] <= hand_opening(hand) for c in order)
    again = picking.plan_any(*clutter_frame, hand, options, memory=memory)
    assert again.target.label != first.target.label and not (again.seen & first.seen).any()
    with pytest.raises(PlannerError, match="plan_any's memory must be a SceneMemory, got GraspMemory"):
        picking.plan_any(*clutter_frame, hand, options, memory=memory.of(first.seen))


@needs_shared
def test_plan_any_plans_the_phoxi_bin_whose_chosen_object_has_no_grasp():
    """The real PhoXi bin (colour at twice its depth, with its own intrinsics): every pose on the object the hand rule
    chooses strikes the wall or a neighbour; another object has a plan."""
    folder = SHARED / "rgbd" / "real_gqcnn_phoxi_fcgqcnn_2"
    frame = read_rgbd(folder / "color.png", folder / "depth.npy", folder / "camera.yaml")
    hand, options = cg.load_hand("five-finger-linear"), cg.load_planner("default").options
    rgbd = (frame.rgb, frame.depth, frame.intrinsics)
    with pytest.raises(cg.NoFeasibleGrasp, match="bin wall"):
        pipeline.plan_frame(*rgbd, hand, options, colour_intrinsics=frame.colour_intrinsics)
    result = picking.plan_any(*rgbd, hand, options, colour_intrinsics=frame.colour_intrinsics)
    assert result.target is not None and result.target.in_view
    on_depth = cg.perception.colour_on_depth(frame.rgb, frame.depth.shape, intrinsics=frame.intrinsics,
                                             colour_intrinsics=frame.colour_intrinsics)
    given = pipeline.find_objects(frame.depth, frame.intrinsics, rgb=frame.rgb, colour_intrinsics=frame.colour_intrinsics)
    resampled = pipeline.find_objects(frame.depth, frame.intrinsics, rgb=on_depth)
    assert [c.label for c in given.candidates] == [c.label for c in resampled.candidates]
    assert all(np.array_equal(a.mask, b.mask) for a, b in zip(given.candidates, resampled.candidates))


def test_plan_any_refuses_what_it_cannot_choose_among(clutter_frame):
    hand = cg.load_hand("five-finger-linear")
    rgb_only = cg.load_planner("default").options
    rgb_only = replace(rgb_only, perception=replace(rgb_only.perception, segment="rgb"))
    with pytest.raises(cg.InputError, match="plan_any chooses among the depth candidates: not with segment='rgb'"):
        picking.plan_any(*clutter_frame, hand, rgb_only)
