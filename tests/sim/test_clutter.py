"""Scenes of several objects: seeded placement, exact per-object truth, the bin in depth, hits and double lifts."""

import mujoco
import numpy as np
import pytest

from contourgrasp import load_hand
from contourgrasp.errors import SimulationError
from contourgrasp.hand import to_image
from contourgrasp.sim import (BIN_LABEL, HIT, Bin, ObjectSpec, Part, arrange, build_clutter, execute_grasp,
                              hand_pose_from_matrix, object_spec, pose_matrix, render, run_trial, scripted_grasp,
                              target_pixel, truth_labels)
from contourgrasp.sim.clutter import MAX_TILT, OBJECT_COUNTS, overlap, plan_hull
from contourgrasp.sim.planners import make_planner
from contourgrasp.sim.scene import R_WORLD_CAMERA

SETTLE = 0.2
#: A light 24 x 24 x 6 mm tile, to rest on top of a target.
TILE = ObjectSpec("tile", (Part("box", (0.012, 0.012, 0.003), pos=(0.0, 0.0, 0.003)),), mass=0.01,
                  friction_hand=0.6, friction_table=0.6)
CANS = ("can", "can-standing")


def _hulls(layout, target):
    placed = [(target, layout.target), *layout.neighbours]
    outlines = []
    for obj, p in placed:
        c, s = np.cos(p.yaw), np.sin(p.yaw)
        outlines.append(plan_hull(obj) @ np.array([[c, s], [-s, c]]) + [p.x, p.y])
    return outlines


@pytest.mark.parametrize("kind", ["clutter", "bin"])
def test_arrangement_is_seeded_and_outlines_are_disjoint(kind):
    target, pool = object_spec("case"), [object_spec(n) for n in ("can", "stone1", "stone2")]
    first = arrange(kind, target, pool, seed=7)
    again = arrange(kind, target, pool, seed=7)
    assert first.target == again.target and first.tilt == again.tilt
    assert [(o.name, p) for o, p in first.neighbours] == [(o.name, p) for o, p in again.neighbours]
    assert arrange(kind, target, pool, seed=8).target != first.target
    low, high = OBJECT_COUNTS[kind]
    for seed in range(6):
        layout = arrange(kind, target, pool, seed=seed)
        assert 0.0 <= layout.tilt <= MAX_TILT and low <= 1 + len(layout.neighbours) <= high
        outlines = _hulls(layout, target)
        assert not any(overlap(a, b) for i, a in enumerate(outlines) for b in outlines[i + 1:])
        if kind == "bin":
            assert all(np.all(np.abs(o) < np.array(layout.bin.inner) / 2) for o in outlines)


def test_overlap_of_convex_polygons():
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    assert overlap(square, square + 0.5)
    assert not overlap(square, square + [1.0, 0.0])  # touching along an edge
    assert not overlap(square, square + [1.2, 1.2])


def test_same_seed_same_settled_scene_and_no_interpenetration():
    a = build_clutter("case", CANS, kind="clutter", seed=3, settle=SETTLE)
    b = build_clutter("case", CANS, kind="clutter", seed=3, settle=SETTLE)
    np.testing.assert_array_equal(a.data.qpos, b.data.qpos)
    np.testing.assert_array_equal(render(a, sensor="basic", seed=3)[1], render(b, sensor="basic", seed=3)[1])
    assert target_pixel(a) == target_pixel(b)
    bodies = {a.model.body("object").id, *(a.model.body(f"neighbour_{k}").id for k in range(len(a.neighbours)))}
    for contact in a.data.contact[: a.data.ncon]:
        owners = {a.model.geom_bodyid[g] for g in contact.geom}
        if owners <= bodies and len(owners) == 2:
            assert contact.dist > -2e-3  # objects touch, never sink into each other


def _world_points(scene, depth):
    """(H, W, 3) world points of an exact depth image from the scene's view."""
    intr = scene.camera.intrinsics
    u, v = np.meshgrid(np.arange(intr.width), np.arange(intr.height))
    rays = intr.rays(np.stack([u, v], axis=-1).reshape(-1, 2).astype(float)).reshape(*depth.shape, 3)
    eye, R_world_camera = scene.view
    return (rays * depth[..., None]) @ R_world_camera.T + eye


def test_truth_masks_are_exact():
    scene = build_clutter("can-standing", CANS, kind="clutter", seed=2, settle=SETTLE)
    _, depth = render(scene)
    labels = truth_labels(scene)
    points = _world_points(scene, depth.astype(float))
    objects = [scene.object, *scene.neighbours]
    assert set(np.unique(labels)) == {0, *range(1, len(objects) + 1)}
    for k, obj in enumerate(objects):
        body = scene.model.body("object" if k == 0 else f"neighbour_{k - 1}").id
        local = (points[labels == k + 1] - scene.data.xpos[body]) @ scene.data.xmat[body].reshape(3, 3)
        part = obj.collision[0]
        radius, half = part.size
        if obj.name == "can-standing":  # axis along z, from z = 0 to 0.12
            radial, along = np.hypot(local[:, 0], local[:, 1]), local[:, 2] - half
        else:  # lying: axis along x, at height radius
            radial, along = np.hypot(local[:, 1], local[:, 2] - radius), local[:, 0]
        on_side, on_end = np.abs(radial - radius) < 2e-4, np.abs(np.abs(along) - half) < 2e-4
        assert np.all(on_side | on_end) and np.all(radial < radius + 2e-4) and np.all(np.abs(along) < half + 2e-4)


def test_bin_walls_stand_in_the_depth_image():
    scene = build_clutter("stone2", ["stone1"], kind="bin", seed=4, settle=SETTLE)
    _, depth = render(scene)
    labels = truth_labels(scene)
    z = _world_points(scene, depth.astype(float))[..., 2]
    walls = labels == BIN_LABEL
    assert walls.sum() > 2000 and np.isclose(z[walls].max(), Bin().height, atol=1e-4)
    bin_xy = _world_points(scene, depth.astype(float))[..., :2]
    floor = (labels == 0) & scene.bin.contains(bin_xy) & (depth > 0)
    table = (labels == 0) & ~scene.bin.contains(bin_xy) & (np.abs(bin_xy) > np.array(Bin().inner) / 2 + 0.01).any(-1)
    assert np.allclose(z[floor], 0.0, atol=1e-5) and np.allclose(z[table & (depth > 0)], -Bin().floor, atol=1e-5)
    assert target_pixel(scene) and labels[target_pixel(scene)[::-1]] == 1


def _clutter_with_neighbour_at(xy_world, z=0.0):
    scene = build_clutter("can", ["can-standing"], kind="clutter", seed=4, settle=SETTLE)
    address = scene.model.joint("neighbour_0").qposadr[0]
    scene.data.qpos[address:address + 7] = [*xy_world, z, 1.0, 0.0, 0.0, 0.0]
    scene.data.qvel[:] = 0.0
    mujoco.mj_forward(scene.model, scene.data)
    return scene


def test_a_finger_coming_down_on_a_neighbour_is_a_hit():
    scene = _clutter_with_neighbour_at((0.5, 0.4))
    transform, depth = scripted_grasp(scene, "good")
    middle = next(f for f in load_hand("five-finger-linear").fingers if f.name == "middle")
    start = to_image(np.asarray(middle.start)[None], hand_pose_from_matrix(transform))[0]
    scene = _clutter_with_neighbour_at(scene.camera.to_world([*start, 0.0])[:2])
    outcome = execute_grasp(scene, transform, depth)
    assert not outcome.success and outcome.cause == HIT and outcome.lift == 0.0


def test_a_good_grasp_beside_a_far_neighbour_succeeds():
    scene = _clutter_with_neighbour_at((0.5, 0.4))
    outcome = execute_grasp(scene, *scripted_grasp(scene, "good"))
    assert outcome.success and outcome.cause is None


def test_lifting_two_objects_is_not_a_success():
    scene = build_clutter("can", [TILE], kind="clutter", seed=0, settle=SETTLE)
    com = scene.object_com()
    address = scene.model.joint("neighbour_0").qposadr[0]
    scene.data.qpos[address:address + 7] = [com[0], com[1], 0.0663, 1.0, 0.0, 0.0, 0.0]  # on top of the lying can
    scene.data.qvel[:] = 0.0
    mujoco.mj_forward(scene.model, scene.data)
    scene.step(0.1)
    rest = scene.neighbour_coms()
    transform, _ = scripted_grasp(scene, "good")
    outcome = execute_grasp(scene, transform, scene.camera.height - 0.072 - 0.01)
    assert outcome.lift > 0.10  # the can was lifted ...
    assert scene.neighbour_coms()[0, 2] - rest[0, 2] > 0.10 and scene.displaced_neighbours(rest) == [0]
    assert not outcome.success and outcome.cause == HIT  # ... with the tile on it


def test_knocked_off_neighbours_are_displaced():
    scene = _clutter_with_neighbour_at((0.2, 0.1))
    rest = scene.neighbour_coms()
    assert scene.displaced_neighbours(rest) == []
    scene = _clutter_with_neighbour_at((0.7, 0.1), z=-0.2)  # off the table's edge, below its top
    assert scene.displaced_neighbours(rest) == [0]


def test_trial_in_a_bin_is_seeded_and_gets_the_target_pixel():
    seen = []

    def planner(rgb, depth, intrinsics, *, target_px=None):
        seen.append(target_px)
        return make_planner("default", load_hand("five-finger-linear"))(rgb, depth, intrinsics, target_px=target_px)

    first = run_trial("can", seed=1, planner=planner, scene_kind="bin", pool=["stone2"])
    again = run_trial("can", seed=1, planner=planner, scene_kind="bin", pool=["stone2"])
    assert first == again and seen[0] == seen[1] and seen[0] is not None


def test_a_scene_of_several_objects_needs_neighbours():
    with pytest.raises(SimulationError, match="pool"):
        arrange("clutter", object_spec("can"), [], seed=0)
    with pytest.raises(SimulationError, match="scene kind"):
        arrange("heap", object_spec("can"), ["can"], seed=0)


def test_a_pose_planned_in_the_tilted_view_is_executed_where_it_was_planned():
    scene = build_clutter("can", ["stone2"], kind="clutter", seed=0, settle=0.01)
    eye, R_world_view = scene.view
    assert np.degrees(np.arccos(-R_world_view[2, 2])) > 5  # this seed tilts the camera
    x, y, yaw, depth = 0.03, -0.02, 0.7, 0.55
    T_world_reference = np.eye(4)
    T_world_reference[:3, :3], T_world_reference[:3, 3] = R_WORLD_CAMERA, scene.camera.position
    T_world_view = np.eye(4)
    T_world_view[:3, :3], T_world_view[:3, 3] = R_world_view, eye
    T_view_hand = np.linalg.inv(T_world_view) @ T_world_reference @ pose_matrix(x, y, yaw, depth)
    np.testing.assert_allclose(scene.to_reference(T_view_hand), (x, y, yaw, depth), atol=1e-12)


@pytest.mark.parametrize("kind", ["clutter", "bin"])
def test_the_target_is_wholly_in_view_and_its_pixel_on_it(kind):
    for seed in range(3):
        scene = build_clutter("bottle", ["case", "stone1"], kind=kind, seed=seed, settle=0.01)
        target = truth_labels(scene) == 1
        assert target.sum() > 1000 and not (target[0].any() or target[-1].any() or target[:, 0].any()
                                            or target[:, -1].any())
        u, v = target_pixel(scene)
        assert target[v, u]
