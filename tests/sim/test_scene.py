"""Scene and rendering: geometry of the top-down and tilted cameras, noise, exact masks, plan_grasp on a rendered can."""

import numpy as np
from scipy.spatial import Delaunay
import pytest

import contourgrasp
from contourgrasp import perception
from contourgrasp.sim import (SENSORS, Camera, build_scene, hand_pose_from_matrix, object_truth, render,
                              render_view, tilted_view)
from contourgrasp.sim.objects import flat_tool
from contourgrasp.sim.planners import make_planner
from contourgrasp.sim import ROBOT_ARM
from contourgrasp.sim.objects import ObjectSpec, Part
from contourgrasp.sim.scene import R_WORLD_CAMERA, Workspace

TILT = np.radians(12.7)


@pytest.fixture(scope="module")
def can_scene():
    return build_scene("can", seed=3)


def test_render_types_and_shapes(can_scene):
    rgb, depth = render(can_scene)
    intr = can_scene.camera.intrinsics
    assert rgb.dtype == np.uint8 and rgb.shape == (intr.height, intr.width, 3)
    assert depth.dtype == np.float32 and depth.shape == (intr.height, intr.width)


def test_table_depth_equals_camera_height(can_scene):
    _, depth = render(can_scene)
    # The workspace keeps the object well inside the view, so the image corners see the table.
    corners = np.concatenate([depth[:20, :20].ravel(), depth[-20:, -20:].ravel()])
    assert np.all(np.abs(corners - can_scene.camera.height) < 1e-3)


def test_object_top_depth(can_scene):
    _, depth = render(can_scene)
    # A can lying on its side: its top is 0.066 m above the table.
    assert abs(depth[depth > 0].min() - (can_scene.camera.height - 0.066)) < 1e-3


def test_side_view_sees_the_object_over_the_table(can_scene):
    target = can_scene.object_com()
    rgb, hit = render_view(can_scene, target + [0.0, -0.5, 0.2], target, show_hand=False)
    assert rgb.shape == (*hit.shape, 3) and hit[-1].all() and not hit[0].any()  # table below, nothing above
    red = (rgb[..., 0] > 100) & (rgb[..., 1] < 60)
    assert red[rgb.shape[0] // 2 - 10: rgb.shape[0] // 2 + 10, rgb.shape[1] // 2].any()  # the can, in the middle


def test_depth_outside_the_sensor_range_is_missing():
    scene = build_scene("can", seed=0, camera=Camera(height=2.0))
    _, depth = render(scene)
    assert not depth.any()


def test_noise_is_seeded_and_drops_edge_pixels(can_scene):
    _, exact = render(can_scene)
    _, a = render(can_scene, sensor="basic", seed=5)
    _, b = render(can_scene, sensor="basic", seed=5)
    _, c = render(can_scene, sensor=SENSORS["basic"], seed=6)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    table = (exact > can_scene.camera.height - 1e-3) & (a > 0)
    residual = a[table] - exact[table]
    assert 0.5e-3 < residual.std() < 3e-3  # a few mm at 0.65 m, like the SR300
    assert 0 < np.count_nonzero((a == 0) & (exact > 0)) < 0.01 * a.size  # holes only along edges


def test_placement_is_seeded_and_inside_the_workspace():
    first = build_scene("can", seed=11).placement
    assert build_scene("can", seed=11).placement == first
    assert build_scene("can", seed=12).placement != first
    workspace = Workspace()
    assert abs(first.x) <= workspace.half_x and abs(first.y) <= workspace.half_y


def test_planner_finds_the_can(can_scene):
    rgb, depth = render(can_scene, sensor="basic", seed=1)
    hand = contourgrasp.load_hand("five-finger-linear")
    transform, approach, height = make_planner("paper", hand)(rgb, depth, can_scene.camera.intrinsics)
    x, y, yaw = hand_pose_from_matrix(transform)
    grasp_centre = contourgrasp.hand.to_image(hand.grasp_centre[None], (x, y, yaw))[0]
    can_centre = can_scene.camera.from_world(can_scene.object_com())[:2]
    assert np.linalg.norm(grasp_centre - can_centre) < 0.04
    assert abs(approach - (can_scene.camera.height - 0.066 + 0.01)) < 0.005


def test_tilted_view_geometry():
    eye, R = tilted_view(0.0, 0.65)
    np.testing.assert_allclose(eye, [0.0, 0.0, 0.65])
    np.testing.assert_allclose(R, R_WORLD_CAMERA)
    eye, R = tilted_view(TILT, 0.7, target=(0.1, 0.0, 0.0))
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    assert np.isclose(np.linalg.det(R), 1.0)
    np.testing.assert_allclose(eye + 0.7 * R[:, 2], [0.1, 0.0, 0.0], atol=1e-12)  # looks at the target
    assert np.isclose(np.arccos(-R[2, 2]), TILT)  # optical axis 12.7 deg from straight down
    np.testing.assert_allclose(R.T @ [0.0, 0.0, 1.0], [0.0, -0.220, -0.976], atol=1e-3)  # the PrimeSense frames' normal


def test_object_truth_from_above(can_scene):
    _, depth = render(can_scene)
    seen, footprint = object_truth(can_scene)
    np.testing.assert_array_equal(seen, (depth > 0) & (depth < can_scene.camera.height - 1e-4))
    # Straight down, a lying can's footprint is its 0.066 x 0.120 m rectangle at the table's depth.
    intr = can_scene.camera.intrinsics
    expected = 0.066 * 0.120 * intr.fx * intr.fy / can_scene.camera.height**2
    assert abs(footprint.sum() / expected - 1) < 0.02
    centre = can_scene.camera.from_world(can_scene.object_com() * [1.0, 1.0, 0.0])  # on the table, below the axis
    centre_px = intr.K @ (centre / centre[2])
    rows, cols = np.nonzero(footprint)
    assert np.hypot(cols.mean() - centre_px[0], rows.mean() - centre_px[1]) < 1.0


def test_footprint_segmentation_matches_the_exact_footprint_of_a_tilted_view():
    scene = build_scene("can", seed=0, camera=Camera(height=0.7))
    view = tilted_view(TILT, 0.7)
    rgb, depth = render(scene, sensor="basic", seed=0, view=view)
    seen, footprint = object_truth(scene, view)
    result = perception.segment(rgb, depth, scene.camera.intrinsics)
    assert np.isclose(result.plane.tilt, TILT, atol=np.radians(0.5)) and result.on_table

    def iou(truth):
        return (result.mask & truth).sum() / (result.mask | truth).sum()

    assert iou(footprint) > 0.9
    assert iou(seen) < iou(footprint) - 0.1  # the footprint, not the region seen


def test_flat_parts_and_registration_against_exact_truth():
    # A dark grey tool whose plate depth cannot see, on the light table, colour misregistered by (1, -3) px.
    scene = build_scene(flat_tool(), seed=1, camera=Camera(height=0.7))
    view = tilted_view(TILT, 0.7)
    rgb, depth = render(scene, sensor="basic", seed=1, view=view)
    _, footprint = object_truth(scene, view)
    misregistered = perception.register_colour(rgb, (-1, 3))
    result = perception.segment(misregistered, depth, scene.camera.intrinsics)
    assert result.method == "depth+rgb" and result.colour_offset_px == (1, -3)
    assert (result.mask & footprint).sum() / (result.mask | footprint).sum() > 0.9


@pytest.mark.parametrize("name", ["can", "case"])
def test_a_plan_from_a_tilted_camera_lands_on_the_object(name):
    # End to end from a camera tilted 12.7 deg, with the sensor's noise: the hand approaches along the table's
    # normal, its grasp centre over the object (within its outline seen from above) and its fingertip plane 1 cm below the object's top (the nearest
    # raw reading would put it 4-7 mm higher: benchmarks/approach_depth.py).
    scene = build_scene(name, seed=0, camera=Camera(height=0.7))
    eye, R_world_camera = view = tilted_view(TILT, 0.7)
    rgb, depth = render(scene, sensor="basic", seed=0, view=view)
    hand = contourgrasp.load_hand("five-finger-linear")
    plan = contourgrasp.plan_grasp(rgb, depth, scene.camera.intrinsics, hand=hand)
    T_world_camera = np.eye(4)
    T_world_camera[:3, :3], T_world_camera[:3, 3] = R_world_camera, eye
    T_world_hand = T_world_camera @ plan.T_camera_hand
    assert np.degrees(np.arccos(-T_world_hand[2, 2])) < 1.0  # approach axis straight down
    centre = T_world_hand @ [*hand.grasp_centre, 0.0, 1.0]
    assert Delaunay(scene.object_points()[:, :2]).find_simplex(centre[:2]) >= 0  # over the object's outline
    assert abs(T_world_hand[2, 3] - (scene.object_points()[:, 2].max() - 0.01)) < 0.003


@pytest.mark.parametrize("tilt", [0.0, 30.0, 60.0])
def test_a_robot_arm_in_view_enters_from_the_border_touches_nothing_and_is_not_planned_on(tilt):
    # The arm of ROBOT_ARM beside the workspace: in every view it crosses the image's top border, the object's
    # pixels are those of the scene without it, nothing touches it, and the plan is the plan without it.
    view = tilted_view(np.radians(tilt), 0.65)
    scene, bare = build_scene("can", seed=3, robot=True), build_scene("can", seed=3)
    _, with_arm = render(scene, view=view)
    _, without = render(bare, view=view)
    arm = np.abs(with_arm - without) > 1e-6
    assert arm.sum() > 500 and arm[0].any()
    np.testing.assert_array_equal(object_truth(scene, view)[0], object_truth(bare, view)[0])
    robot = [scene.model.geom(f"robot_{k}").id for k in range(len(ROBOT_ARM))]
    assert not np.isin(scene.data.contact.geom[: scene.data.ncon], robot).any()
    hand = contourgrasp.load_hand("five-finger-linear")
    plans = [contourgrasp.plan_grasp(*render(s, sensor="structured-light", seed=3, view=view), s.camera.intrinsics,
                                     hand=hand) for s in (scene, bare)]
    masks = [p.segmentation.mask for p in plans]
    assert (masks[0] & masks[1]).sum() > 0.99 * (masks[0] | masks[1]).sum()  # the support's fit sees the arm's edge
    np.testing.assert_allclose(plans[0].T_camera_hand[:3, 3], plans[1].T_camera_hand[:3, 3], atol=0.002)
    np.testing.assert_allclose(plans[0].T_camera_hand[:3, :3], plans[1].T_camera_hand[:3, :3], atol=0.03)


def test_the_base_angles_turn_the_hand_to_any_rotation():
    from scipy.spatial.transform import Rotation

    from contourgrasp.sim.scene import base_angles

    def turned(yaw, tilt, roll):
        return (Rotation.from_euler("z", -yaw) * Rotation.from_euler("y", tilt) * Rotation.from_euler("z", -roll)
                * Rotation.from_euler("x", np.pi)).as_matrix()

    for R in Rotation.random(50, random_state=3).as_matrix():
        np.testing.assert_allclose(turned(*base_angles(R)), R, atol=1e-9)
    yaw, tilt, roll = base_angles(turned(0.7, 0.0, 0.0))  # facing down: all the turn is yaw
    assert (yaw, tilt, roll) == (pytest.approx(0.7), 0.0, 0.0)


def test_the_scene_is_photographed_at_rest():
    """An object whose resting face is an unstable stand falls before the picture: a moment later it lies still."""
    plank = Part("box", (0.004, 0.04, 0.06), pos=(0.0, 0.0, 0.06))  # 8 mm x 8 cm x 12 cm, on end
    arm = Part("box", (0.03, 0.01, 0.01), pos=(0.03, 0.0, 0.11))  # its top heavy to one side: it falls
    standing = ObjectSpec("plank", (plank, arm), mass=0.1, friction_hand=0.6, friction_table=0.5)
    scene = build_scene(standing, seed=1)
    before = scene.object_com()
    scene.step(0.5)
    assert np.linalg.norm(scene.object_com() - before) < 0.003
    assert before[2] < 0.045  # fallen: its centre of mass stood 6.5 cm up
