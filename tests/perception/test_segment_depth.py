"""Depth segmentation and the footprint (contourgrasp.perception.segment_depth)."""

from __future__ import annotations


import pytest

from contourgrasp.perception import segment_depth
from perception_scenes import CAMERA, render, render_footprint, iou


@pytest.mark.parametrize("tilt_deg", [0.0, 12.7])
def test_depth_segmentation_finds_the_cylinder(tilt_deg):
    depth, _, seen, _ = render(tilt_deg=tilt_deg)
    footprint = render_footprint(tilt_deg=tilt_deg)
    seg = segment_depth(depth, CAMERA)
    assert seg.method == "depth" and seg.warnings == ()
    assert seg.on_table == (tilt_deg > 2.0)  # the footprint by default only when the camera is tilted
    assert iou(seg.mask, footprint if seg.on_table else seen) > 0.95
    assert seg.area_px == seg.mask.sum()
    assert iou(segment_depth(depth, CAMERA, footprint=False).mask, seen) > 0.95
    assert iou(segment_depth(depth, CAMERA, footprint=True).mask, footprint) > 0.95


@pytest.mark.parametrize("tilt_deg", [0.0, 12.7, 25.0])
def test_footprint_is_where_the_object_stands(tilt_deg):
    # A 6 cm tall box: seen from a tilted camera its top is displaced from its base and its side shows.
    depth, _, seen, _ = render(kind="box", tilt_deg=tilt_deg, radius=0.03, height=0.06, centre=(0.03, 0.02))
    seg = segment_depth(depth, CAMERA, footprint=True)
    truth = render_footprint(kind="box", tilt_deg=tilt_deg, radius=0.03, centre=(0.03, 0.02))
    assert iou(seg.mask, truth) > 0.95
    assert iou(seen, truth) < 0.9


@pytest.mark.parametrize("footprint", [False, True])
def test_a_hole_that_sees_the_table_is_object_free_and_a_hole_of_missing_readings_is_filled(footprint):
    import numpy as np

    table = np.full((CAMERA.height, CAMERA.width), 0.7)
    ring, block = table.copy(), table.copy()
    ring[200:280, 280:360] = 0.68  # a 2 cm thick ring whose 40 x 40 px eye sees the table
    ring[220:260, 300:340] = 0.7
    block[200:280, 280:360] = 0.68  # a block with a hole of missing readings (fill_holes=False keeps it)
    block[230:250, 310:330] = 0.0
    eye = segment_depth(ring, CAMERA, fill_holes=False, footprint=footprint)
    unseen = segment_depth(block, CAMERA, fill_holes=False, footprint=footprint)
    assert not eye.mask[225:255, 305:335].any() and eye.mask[205:275, 285:292].all()
    assert unseen.mask[230:250, 310:330].all()  # the unseen hole is object
    assert eye.area_px == eye.mask.sum()
    if not footprint:
        assert eye.area_px == 6400 - 1600 and unseen.area_px == 6400
