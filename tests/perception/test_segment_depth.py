"""Depth segmentation and the footprint (contourgrasp.perception.segment_depth)."""

from __future__ import annotations


import numpy as np
import pytest
from scipy import ndimage

from contourgrasp.errors import SegmentationError
from contourgrasp.perception import Plane, hidden_side, object_footprint, segment_depth
from contourgrasp.perception.segment_depth import hidden_side_weight
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


@pytest.mark.parametrize("tilt_deg", [45.0, 60.0])
def test_an_oblique_view_gets_the_hidden_side_of_the_footprint(tilt_deg):
    # A 10 cm tall can seen from 45-60 deg: its top and near side are seen, its far half is not. The rays over it
    # bound the hidden side, the hull of what is seen closes it: the whole base, where the region seen covers
    # less than half of it. The table beyond the can lies past the sensor's range (1.5 m): the can is still
    # wholly in view (a reading beyond the range is behind what it borders).
    depth, _, seen, _ = render(kind="cylinder", tilt_deg=tilt_deg, radius=0.04, height=0.10)
    truth = render_footprint(kind="cylinder", tilt_deg=tilt_deg, radius=0.04)
    assert (depth > 1.5).any()
    seg = segment_depth(depth, CAMERA)
    assert seg.on_table and iou(seg.mask, truth) > 0.9
    assert iou(seen, truth) < 0.4
    rows = np.nonzero(truth.any(axis=1))[0]
    far_half = truth & (np.arange(truth.shape[0])[:, None] < rows.mean())  # the image's top: away from the camera
    assert (seg.mask & far_half).sum() > 0.9 * far_half.sum()


@pytest.mark.parametrize("footprint", [False, True])
def test_a_hole_that_sees_the_table_is_object_free_and_a_hole_of_missing_readings_is_filled(footprint):
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


def _tall_box_over_a_flat_one():
    """A 15 cm box whose side, seen 25 deg tilted, covers a flat box 6 cm behind it: one region, two footprints."""
    tall, _, tall_seen, _ = render(kind="box", tilt_deg=25.0, radius=0.02, height=0.15)
    flat, _, flat_seen, _ = render(kind="box", tilt_deg=25.0, radius=0.03, height=0.02, centre=(0.0, -0.11))
    depth = np.minimum(tall, flat)
    feet = (render_footprint(kind="box", tilt_deg=25.0, radius=0.02),
            render_footprint(kind="box", tilt_deg=25.0, radius=0.03, centre=(0.0, -0.11)))
    return depth, (tall_seen & (tall <= flat), flat_seen & (flat < tall)), feet


def _innermost(mask):
    v, u = np.unravel_index(np.argmax(ndimage.distance_transform_edt(mask)), mask.shape)
    return int(u), int(v)


def test_the_clicked_object_is_taken_where_touching_neighbours_share_a_region():
    depth, seen, (tall, flat) = _tall_box_over_a_flat_one()
    assert ndimage.label(seen[0] | seen[1])[1] == 1  # the view joins them
    with pytest.warns(UserWarning, match="2 regions in the object's footprint"):
        largest = segment_depth(depth, CAMERA, footprint=True).mask
    assert iou(largest, flat) > 0.6 and iou(largest, tall) == 0  # without a click: the largest footprint
    clicked_tall = segment_depth(depth, CAMERA, footprint=True, target_px=_innermost(seen[0])).mask
    assert iou(clicked_tall, tall) > 0.9
    clicked_flat = segment_depth(depth, CAMERA, footprint=True, target_px=_innermost(seen[1])).mask
    assert iou(clicked_flat, flat) > 0.6 and iou(clicked_flat, tall) == 0


def test_a_click_outside_the_image_is_refused():
    depth, _, _ = _tall_box_over_a_flat_one()
    with pytest.raises(SegmentationError, match=r"pixel \(9999, 5\) is outside"):
        segment_depth(depth, CAMERA, footprint=True, target_px=(9999, 5))


@pytest.mark.parametrize("kind", ["box", "cylinder"])
def test_the_hidden_side_is_the_visual_hull_as_tall_as_the_object(kind):
    # Seen from 45 deg, a 6 cm box's or can's far side is hidden. The table points hidden behind it whose point
    # 6 cm up still projects into its silhouette are where it may stand: within its base (a pixel's slack), and
    # for the can the base's far part its top does not show.
    depth, _, seen, normal = render(kind=kind, tilt_deg=45.0, radius=0.03, height=0.06)
    plane = Plane(normal=normal, offset=0.7)
    added = hidden_side(seen, CAMERA, plane, top=0.06)
    base = render_footprint(kind=kind, tilt_deg=45.0, radius=0.03)
    assert added.sum() > 50
    assert (added & ~ndimage.binary_dilation(base, iterations=2)).sum() < 0.02 * added.sum()
    hidden = base & seen  # the base's pixels that see the object, not the table
    assert (added & hidden).sum() > 0.8 * hidden.sum()


def test_the_hidden_side_grows_with_the_tilt_and_no_tilt_switches_it_on():
    # A 6 cm can seen from 24 to 36 deg whose far half returned no readings (as a RealSense's far wall does):
    # its footprint grows from the near half to the whole base smoothly; across 30 deg (where a threshold stood)
    # it changes by a few pixels, not by the hidden band.
    match = {}
    for tilt in (24.0, 29.9, 30.1, 33.0, 36.0):
        depth, _, seen, normal = render(kind="cylinder", tilt_deg=tilt, radius=0.03, height=0.06)
        rows = np.nonzero(seen)[0]
        depth[seen & (np.arange(seen.shape[0])[:, None] < np.median(rows))] = np.nan
        footprint = object_footprint(seen, depth, CAMERA, Plane(normal=normal, offset=0.7))
        match[tilt] = iou(footprint, render_footprint(kind="cylinder", tilt_deg=tilt, radius=0.03))
    assert match[24.0] < 0.3 and match[36.0] > 0.9
    assert match[30.1] < match[33.0] < match[36.0]
    assert abs(match[30.1] - match[29.9]) < 0.1
    assert hidden_side_weight(np.radians(30.0)) == pytest.approx(0.5)
