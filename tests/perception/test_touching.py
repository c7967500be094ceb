"""Touching objects split where colour and surface both change (perception.touching), on synthetic frames."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import contourgrasp as cg
from contourgrasp.errors import PerceptionError
from contourgrasp.io.camera_file import read_rgbd
from contourgrasp.io.plan_file import image_plan_to_dict
from contourgrasp.perception import find_candidates, fit_table_plane, split_touching
from contourgrasp.pipeline import find_objects

from perception_scenes import CAMERA, H, W

TABLE = 0.7
FRAME = Path(__file__).resolve().parents[2] / "examples" / "bar_clamp"
TABLE_RGB = (200, 190, 170)
#: Two boxes side by side, touching along x = 300: (x, y, w, h px, height m, colour).
LOW = (220, 200, 80, 80, 0.03, (235, 235, 235))
TALL = (300, 190, 70, 100, 0.07, (30, 30, 30))


def frame(*boxes):
    """Top-down depth and colour of a table with boxes standing on it."""
    depth = np.full((H, W), TABLE)
    rgb = np.empty((H, W, 3), np.uint8)
    rgb[:] = TABLE_RGB
    for x, y, w, h, height, colour in boxes:
        depth[y:y + h, x:x + w] = TABLE - height
        rgb[y:y + h, x:x + w] = colour
    return rgb, depth


def split(rgb, depth, **options):
    plane = fit_table_plane(depth, CAMERA)
    found = find_candidates(depth, CAMERA, plane)
    return found, split_touching(found, rgb, depth, CAMERA, plane, **options)


def box_mask(box):
    x, y, w, h = box[:4]
    mask = np.zeros((H, W), bool)
    mask[y:y + h, x:x + w] = True
    return mask


def iou(a, b):
    return (a & b).sum() / (a | b).sum()


def test_a_white_box_against_a_taller_black_one_is_two_objects():
    found, pieces = split(*frame(LOW, TALL))
    assert len(found) == 1 and len(pieces) == 2
    tall, low = pieces  # largest first: 70 x 100 px, then 80 x 80
    assert [p.label for p in pieces] == [1, 2] and all(p.touching and p.in_view for p in pieces)
    assert iou(tall.mask, box_mask(TALL)) > 0.97 and iou(low.mask, box_mask(LOW)) > 0.97
    assert tall.height == pytest.approx(0.07, abs=1e-6) and low.height == pytest.approx(0.03, abs=1e-6)
    assert not (tall.mask & low.mask).any() and (tall.mask | low.mask).sum() == found[0].mask.sum()
    # the extent of each, in meters at its depth: the tall box is 70 px wide at 0.63 m
    assert tall.extent[1] == pytest.approx(70 * 0.63 / CAMERA.fx, rel=0.05)


@pytest.mark.parametrize("why, low, tall", [
    ("one colour: a step on one object", LOW, (*TALL[:5], LOW[5])),
    ("two colours on one surface: no step", LOW, (*TALL[:4], LOW[4], TALL[5])),
    ("white, lit and in shade", (*LOW[:5], (220, 220, 220)), (*TALL[:5], (130, 130, 130))),
    ("red, lit and in shade", (*LOW[:5], (200, 60, 60)), (*TALL[:5], (150, 45, 45))),
])
def test_one_object_stays_whole(why, low, tall):
    found, pieces = split(*frame(low, tall))
    assert pieces == found, why


def test_the_colour_offset_given_is_used_and_a_shifted_colour_still_splits():
    rgb, depth = frame(LOW, TALL)
    shifted = np.roll(rgb, (4, -3), axis=(0, 1))  # the colour lies (-3, +4) px from the depth: offset (3, -4)
    assert len(split(shifted, depth, colour_offset_px=(3, -4))[1]) == 2
    assert len(split(shifted, depth)[1]) == 2  # estimated


def test_candidates_at_the_border_and_small_ones_are_left_alone():
    rgb, depth = frame((0, 200, 80, 80, 0.03, (235, 235, 235)), (80, 190, 70, 100, 0.07, (30, 30, 30)))
    found, pieces = split(rgb, depth)
    assert not found[0].in_view and pieces == found
    found, pieces = split(*frame((288, 200, 12, 14, 0.03, (235, 235, 235)), TALL))  # 168 px: no object
    assert pieces == found


def test_plan_frame_plans_on_one_of_the_touching_objects():
    rgb, depth = frame(LOW, TALL)
    result = cg.plan_grasp(rgb, depth, CAMERA, cg.load_hand("five-finger-linear"), target_px=(250, 240), yaw_step=0.1)
    assert iou(result.segmentation.mask, box_mask(LOW)) > 0.95
    assert [o["touching"] for o in image_plan_to_dict(result)["objects"]] == [True, True]  # the plan file says so


def test_bad_input_is_refused_by_name():
    rgb, depth = frame(LOW, TALL)
    plane = fit_table_plane(depth, CAMERA)
    found = find_candidates(depth, CAMERA, plane)
    with pytest.raises(PerceptionError, match="candidates must be"):
        split_touching([object()], rgb, depth, CAMERA, plane)
    with pytest.raises(PerceptionError, match="rgb image"):
        split_touching(found, rgb[:10], depth, CAMERA, plane)
    with pytest.raises(PerceptionError, match="min_area_px"):
        split_touching(found, rgb, depth, CAMERA, plane, min_area_px=0)


def test_the_bundled_bar_clamp_is_one_object():
    # orange and red parts, a block on the clamp's body: one surface where the colours meet
    frame = read_rgbd(FRAME / "color_0.png", FRAME / "depth_0.npy", FRAME / "primesense_overhead_color.intr")
    found = find_objects(frame.depth, frame.intrinsics, rgb=frame.rgb).candidates
    assert found and not any(c.touching for c in found)


@pytest.mark.parametrize("seed", [3, 4, 5])
def test_a_cans_lit_top_and_dark_side_wall_meet_at_a_convex_edge_and_stay_one(seed):
    # Seen from above off the image's centre the side wall shows, dark red against the top's red, 12 cm below it
    # at the table: colour and a step, but the surface folds outward there.
    from contourgrasp.sim import build_scene, render
    from contourgrasp.sim.objects import soda_can

    scene = build_scene(soda_can(standing=True), seed=seed)
    rgb, depth = render(scene, sensor="ideal")
    found = find_objects(depth, scene.camera.intrinsics, rgb=rgb).candidates
    assert len(found) == 1 and not found[0].touching
