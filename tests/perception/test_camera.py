"""Intrinsics and depth images: hole filling, denoising (contourgrasp.perception.camera)."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage

from contourgrasp.perception import Intrinsics, contour_to_metric, denoised_depth, fill_depth_holes, segment, segment_depth
from contourgrasp.perception import camera as camera_module
from perception_scenes import CAMERA, render, iou, BAR_CLAMP, needs_data


def test_depth_holes_are_filled_when_small():
    depth, _, truth, _ = render()
    holed = depth.copy()
    holed[100:105, 100:105] = 0.0
    holed[300:303, 500:504] = np.nan
    holed[20:60, 20:60] = 0.0
    filled, count = fill_depth_holes(holed, max_hole_px=400)
    assert count == 25 + 12
    np.testing.assert_allclose(filled[100:105, 100:105], depth[100:105, 100:105], atol=2e-3)
    assert np.all(filled[20:60, 20:60] == 0)
    holed[240, 320] = 0.0
    assert segment_depth(holed, CAMERA).filled_px == 38
    assert segment_depth(holed, CAMERA, fill_holes=False).filled_px == 0
    assert iou(segment_depth(holed, CAMERA).mask, truth) > 0.95


@pytest.mark.parametrize("call_px", [-10**9, 10**9], ids=["hole-by-hole", "one-box"])
@settings(max_examples=100, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), missing=st.floats(0.05, 0.9), max_hole_px=st.sampled_from([1, 6, 40, 10**6]))
def test_hole_takes_the_nearest_reading_of_the_whole_image(call_px, seed, missing, max_hole_px):
    # The fill looks for readings near the holes only, in one box or hole by hole (forced here by the
    # cost of a call); either must find those of a search over the whole image.
    rng = np.random.default_rng(seed)
    depth = rng.uniform(0.5, 1.0, tuple(rng.integers(2, 40, 2)))
    depth[rng.random(depth.shape) < missing] = 0.0
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(camera_module, "HOLE_CALL_PX", call_px)
        filled, count = fill_depth_holes(depth, max_hole_px=max_hole_px)
    labels, _ = ndimage.label(depth == 0, structure=np.ones((3, 3)))
    small = (np.bincount(labels.ravel()) <= max_hole_px)[labels] & (labels > 0)
    _, (rows, cols) = ndimage.distance_transform_edt(depth == 0, return_indices=True)
    expected = np.where(small & (depth != 0).any(), depth[rows, cols], depth)
    np.testing.assert_array_equal(filled, expected)
    assert count == (small.sum() if (depth != 0).any() else 0)


def test_denoised_depth_keeps_readings_next_to_holes():
    depth = np.full((6, 6), 0.7)
    depth[:2] = 0.0
    depth[2, 2] = 0.6  # a nearer speck: filtered out
    denoised = denoised_depth(depth, depth > 0)
    assert np.all(denoised[:2] == 0.0)  # windows mostly missing keep their own (missing) reading
    np.testing.assert_allclose(denoised[2:], 0.7)


@pytest.mark.parametrize("corner", [(0, 0), (5, 7), (9, 11)])
def test_denoised_depth_on_a_box_equals_the_whole_image(corner):
    rng = np.random.default_rng(1)
    depth = rng.uniform(0.6, 0.8, (10, 12))
    depth[rng.random((10, 12)) < 0.3] = 0.0
    valid = depth > 0
    rows = np.array([corner[0], 4, 5])
    cols = np.array([corner[1], 6, 5])
    np.testing.assert_array_equal(camera_module.denoised_at(depth, valid, rows, cols),
                                  denoised_depth(depth, valid)[rows, cols])


@needs_data
def test_real_raw_depth_with_holes():
    from contourgrasp.io.camera_file import read_depth, read_intrinsics

    depth = read_depth(BAR_CLAMP / "depth_0.npy")
    camera = read_intrinsics(BAR_CLAMP / "primesense_overhead_color.intr")
    seg = segment(None, depth, camera)
    assert seg.filled_px > 0 and seg.warnings == ()
    assert math.degrees(seg.plane.tilt) == pytest.approx(3.7, abs=0.5)
    metric = contour_to_metric(seg.contour_px, depth, camera, plane=seg.plane, depth_mode="plane")
    (_, _), sides, _ = cv2.minAreaRect(metric.contour_xy.astype(np.float32))
    assert 0.07 < min(sides) < 0.09 and 0.10 < max(sides) < 0.13


def test_project_inverts_rays():
    k = Intrinsics(fx=525.0, fy=520.0, cx=319.5, cy=239.5, width=640, height=480)
    pixels = np.array([[0.0, 0.0], [319.5, 239.5], [600.2, 33.7]])
    points = k.rays(pixels) * np.array([[0.5], [0.7], [1.3]])
    np.testing.assert_allclose(k.project(points), pixels, atol=1e-9)


def test_colour_at_twice_the_depths_resolution_is_averaged_back_onto_its_grid():
    from contourgrasp.perception import colour_on_depth

    rng = np.random.default_rng(0)
    rgb = rng.integers(0, 255, (48, 64, 3), dtype=np.uint8)
    doubled = cv2.resize(rgb, (128, 96), interpolation=cv2.INTER_NEAREST)
    np.testing.assert_array_equal(colour_on_depth(doubled, (48, 64)), rgb)
    depth_k = Intrinsics(fx=60.0, fy=60.0, cx=31.5, cy=23.5, width=64, height=48)
    colour_k = Intrinsics(fx=120.0, fy=120.0, cx=63.5, cy=47.5, width=128, height=96)
    np.testing.assert_array_equal(colour_on_depth(doubled, (48, 64), intrinsics=depth_k, colour_intrinsics=colour_k),
                                  rgb)
    assert colour_on_depth(rgb, (48, 64)) is not None and colour_on_depth(rgb, (48, 64)).shape == (48, 64, 3)


def test_colour_of_another_view_maps_through_the_two_intrinsics():
    """A colour camera with a wider view (another focal length and principal point): depth pixel (u, v) takes the
    colour at cx_c + (u - cx) fx_c / fx, analytically."""
    from contourgrasp.perception import colour_on_depth

    u, v = np.meshgrid(np.arange(120), np.arange(90))
    colour = np.dstack([u % 256, v % 256, np.zeros_like(u)]).astype(np.uint8)  # each pixel holds its own (u, v)
    colour_k = Intrinsics(fx=50.0, fy=50.0, cx=62.0, cy=44.0, width=120, height=90)
    depth_k = Intrinsics(fx=100.0, fy=100.0, cx=40.0, cy=30.0, width=80, height=60)
    on_depth = colour_on_depth(colour, (60, 80), intrinsics=depth_k, colour_intrinsics=colour_k)
    for du, dv in ((0, 0), (10, 20), (79, 59), (40, 30)):
        expected = (62.0 + (du - 40.0) * 0.5, 44.0 + (dv - 30.0) * 0.5)
        np.testing.assert_allclose(on_depth[dv, du, :2], expected, atol=1.0)


def test_colour_of_another_aspect_without_its_intrinsics_is_refused():
    from contourgrasp.perception import PerceptionError, colour_on_depth

    with pytest.raises(PerceptionError, match="not the same view at another resolution"):
        colour_on_depth(np.zeros((90, 200, 3), np.uint8), (60, 80))
    with pytest.raises(PerceptionError, match="together, or neither"):
        colour_on_depth(np.zeros((120, 160, 3), np.uint8), (60, 80), intrinsics=CAMERA)
