"""Colour with depth: registration and flat parts (contourgrasp.perception.colour)."""

from __future__ import annotations


import numpy as np
import pytest
from scipy import ndimage

from contourgrasp.perception import PerceptionWarning, SegmentationError, colour_offset, register_colour, segment, segment_depth
from contourgrasp.perception import colour as colour_module
from contourgrasp.tolerances import FLAT_WINDOW_PX, HALO_PX
from perception_scenes import H, W, CAMERA, TABLE_RGB, OBJECT_RGB, render, render_footprint, iou, with_flat_part, with_plate, shifted


def test_auto_adds_a_flat_part_that_depth_cannot_see():
    depth, rgb, truth, _ = render(tilt_deg=12.7, height=0.02)
    rgb, whole = with_flat_part(rgb, truth)
    standing = render_footprint(tilt_deg=12.7) | (whole & ~truth)  # the plate lies on the table: its footprint is itself
    assert iou(segment_depth(depth, CAMERA).mask, standing) < 0.7
    seg = segment(rgb, depth, CAMERA)
    assert seg.method == "depth+rgb" and seg.plane is not None and seg.warnings == ()
    assert seg.on_table and seg.colour_offset_px == (0, 0)
    assert iou(seg.mask, standing) > 0.95
    np.testing.assert_array_equal(segment(rgb, depth, CAMERA).mask, seg.mask)


def test_a_flat_part_beyond_the_search_window_is_found_whole():
    # The plate reaches 200 px beyond the object, past the window searched first: the whole image is searched.
    assert 200 > 4 * HALO_PX + FLAT_WINDOW_PX
    depth, rgb, truth, _ = render(height=0.02)
    rgb, whole = with_plate(rgb, truth, 200)
    seg = segment(rgb, depth, CAMERA)
    assert seg.method == "depth+rgb" and iou(seg.mask, whole) > 0.97


@pytest.mark.parametrize("length", [60, 200])
def test_the_search_window_changes_nothing(monkeypatch, length):
    depth, rgb, truth, _ = render(tilt_deg=12.7, height=0.02)
    rgb, _ = with_plate(rgb, truth, length)
    windowed = segment(rgb, depth, CAMERA)
    assert windowed.method == "depth+rgb"
    monkeypatch.setattr(colour_module, "FLAT_WINDOW_PX", 10_000)  # the window is the whole image
    np.testing.assert_array_equal(segment(rgb, depth, CAMERA).mask, windowed.mask)


@pytest.mark.parametrize(("dx", "dy"), [(0, 0), (2, -3), (-4, 1), (1, 5)])
def test_colour_offset_finds_the_misregistration(dx, dy):
    depth, rgb, _, _ = render(tilt_deg=12.7)
    seen = segment_depth(depth, CAMERA, footprint=False).mask
    assert colour_offset(shifted(rgb, dx, dy), depth, seen) == (dx, dy)
    np.testing.assert_array_equal(register_colour(shifted(rgb, dx, dy), (dx, dy))[100:-100, 100:-100],
                                  rgb[100:-100, 100:-100])


def test_colour_offset_survives_a_grainy_table():
    # Pixel noise of +-100 grey levels in colour (a grainy or textured mat) has edges everywhere but none that
    # depth shares: the object's outline still decides the shift.
    depth, rgb, _, _ = render(tilt_deg=12.7)
    seen = segment_depth(depth, CAMERA, footprint=False).mask
    grain = np.random.default_rng(0).integers(-100, 101, (H, W, 1))
    grainy = np.clip(rgb + grain, 0, 255).astype(np.uint8)
    assert colour_offset(shifted(grainy, 2, -3), depth, seen) == (2, -3)


def test_colour_offset_without_edges_is_zero():
    depth = np.full((H, W), 0.7)
    mask = np.zeros((H, W), dtype=bool)
    mask[200:260, 300:360] = True
    assert colour_offset(np.full((H, W, 3), 90, np.uint8), depth, mask) == (0, 0)
    assert colour_offset(render()[1], depth, mask, max_offset_px=0) == (0, 0)


def test_auto_puts_misregistered_colour_where_depth_sees_it():
    # The flat plate's colour arrives 3 px low and 2 px right: found in colour, it is moved back before it is added.
    depth, rgb, truth, _ = render(height=0.02)
    rgb, whole = with_flat_part(rgb, truth)
    seg = segment(shifted(rgb, -2, -3), depth, CAMERA)
    assert seg.method == "depth+rgb" and seg.colour_offset_px == (-2, -3)
    np.testing.assert_array_equal(seg.mask, segment(rgb, depth, CAMERA).mask)
    unregistered = segment(shifted(rgb, -2, -3), depth, CAMERA, colour_offset_px=(0, 0))
    assert iou(unregistered.mask, whole) < iou(seg.mask, whole) - 0.02


def test_auto_ignores_a_shadow_band_along_the_depth_outline():
    depth, rgb, truth, _ = render()
    band = ndimage.binary_dilation(truth, iterations=4) & ~truth
    rgb[band] = (40, 80, 20)
    seg = segment(rgb, depth, CAMERA)
    assert seg.method == "depth"
    np.testing.assert_array_equal(seg.mask, segment_depth(depth, CAMERA).mask)


def test_a_wide_shadow_is_not_a_flat_part_because_lightness_counts_little():
    # A shadow 40 px wide beside the object: the table's colour at 60 % brightness, CIELAB distance 84,
    # 35 with lightness weighted 0.25.
    depth, rgb, truth, _ = render()
    rows, cols = np.nonzero(truth)
    shadow = np.zeros_like(truth)
    shadow[rows.min(): rows.max(), cols.max(): cols.max() + 40] = True
    rgb[shadow & ~truth] = (TABLE_RGB * 0.6).astype(np.uint8)
    assert segment(rgb, depth, CAMERA).method == "depth"
    assert segment(rgb, depth, CAMERA, colour_options={"lightness_weight": 1.0}).method == "depth+rgb"


def test_a_dark_grey_flat_part_on_a_light_grey_table_is_found_by_its_lightness():
    # Grey on grey differs in lightness only (CIELAB distance 33 with lightness weighted 0.25): the part, at
    # 0.37 of the table's lightness, is darker than a shadow; the shadow on the other side, at 0.63, is not.
    depth, rgb, truth, _ = render(tilt_deg=12.7, height=0.02)
    rgb[~truth] = 200
    rgb, whole = with_flat_part(rgb, truth, colour=(70, 70, 70))
    rows, cols = np.nonzero(truth)
    shadow = np.zeros_like(truth)
    shadow[rows.min(): rows.max(), cols.min() - 40: cols.min()] = True
    rgb[shadow & ~truth] = 120
    standing = render_footprint(tilt_deg=12.7) | (whole & ~truth)
    seg = segment(rgb, depth, CAMERA)
    assert seg.method == "depth+rgb" and iou(seg.mask, standing) > 0.95
    assert segment(rgb, depth, CAMERA, colour_options={"shadow_lightness": 0.0}).method == "depth"


def test_auto_finds_a_flat_object_of_another_colour():
    depth, rgb, _, _ = render(kind="none")
    flat = np.zeros((H, W), dtype=bool)
    flat[200:260, 280:380] = True
    rgb[flat] = OBJECT_RGB
    with pytest.warns(PerceptionWarning, match="nothing|no region"):
        seg = segment(rgb, depth, CAMERA)
    assert seg.method == "rgb" and iou(seg.mask, flat) > 0.9


def test_flat_part_reaching_the_border_is_refused():
    depth, rgb, truth, _ = render(centre=(0.2, 0.0), height=0.02)
    rows, cols = np.nonzero(truth)
    rgb[rows.min() + 5: rows.max() - 5, cols.max():] = (230, 230, 230)
    with pytest.raises(SegmentationError, match="not completely visible") as err:
        segment(rgb, depth, CAMERA)
    assert err.value.kind == "not-visible"
