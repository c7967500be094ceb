"""Colour with depth: registration and flat parts (contourgrasp.perception.colour)."""

from __future__ import annotations


import numpy as np
import pytest
from scipy import ndimage

from contourgrasp.perception import PerceptionWarning, SegmentationError, colour_offset, register_colour, segment, segment_depth
from contourgrasp.perception import colour as colour_module
from contourgrasp.tolerances import FLAT_GAP_PX, FLAT_WINDOW_PX, HALO_PX
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


def _grey_scene(*, centre=(0.0, 0.0), noise_m=0.0, seed=0):
    """Top-down: a dark cylinder 2 cm high on a light grey table, in grey; depth with Gaussian noise."""
    depth, rgb, truth, _ = render(height=0.02, centre=centre)
    rgb[:] = 200
    rgb[truth] = 60
    depth = depth + np.random.default_rng(seed).normal(0.0, noise_m, depth.shape)
    return depth, rgb, truth


def _beside(truth, first_col, last_col):
    """(H, W) bool: a strip 30 px tall from column ``first_col`` to ``last_col`` past the object's right edge."""
    rows, cols = np.nonzero(truth)
    strip = np.zeros_like(truth)
    middle = (rows.min() + rows.max()) // 2
    strip[middle - 15: middle + 15, cols.max() + first_col: cols.max() + last_col] = True
    return strip & ~truth


def test_a_grey_image_finds_a_part_as_light_as_the_table_by_its_height():
    # A plate 4 mm high, grey as the table: no lightness test sees it, and depth's 10 mm threshold does not.
    # Each depth pixel has 1 mm of noise (5 sigma: 5 mm, more than the plate); the 5 x 5 median cuts it to about
    # a quarter, and the plate stands out.
    depth, rgb, truth = _grey_scene(noise_m=0.001)
    plate = _beside(truth, -2, 70)
    depth[plate] -= 0.004
    seg = segment(rgb, depth, CAMERA)
    assert seg.method == "depth+rgb" and iou(seg.mask, truth | plate) > 0.9
    assert segment(rgb, depth, CAMERA, colour_options={"height_sigmas": 100.0}).method == "depth"
    tinted = rgb.copy()
    tinted[..., 2] -= 10  # a hue: colour bounds parts better, and the height test is not used
    assert segment(tinted, depth, CAMERA).method == "depth"


def test_a_grey_flat_part_across_a_narrow_gap_is_joined():
    # A dark plate 5 px from the object, beyond a gap as light as the table (a hinge): joined in grey, by the
    # shortest segment across the gap; not 12 px away; and not in colour, where a gap would join neighbours.
    depth, rgb, truth = _grey_scene()
    near = _beside(truth, 6, 70)
    rgb[near] = 70
    seg = segment(rgb, depth, CAMERA)
    assert seg.method == "depth+rgb" and iou(seg.mask, truth | near) > 0.9
    assert (seg.mask & ~(truth | near)).sum() < 5 * FLAT_GAP_PX  # the bridge only
    assert segment(rgb, depth, CAMERA, colour_options={"gap_px": 0}).method == "depth"
    tinted = rgb.copy()
    tinted[..., 2] -= 10
    assert segment(tinted, depth, CAMERA).method == "depth"
    depth, rgb, truth = _grey_scene()
    rgb[_beside(truth, FLAT_GAP_PX + 5, 70)] = 70
    assert segment(rgb, depth, CAMERA).method == "depth"


def test_grey_evidence_stops_at_a_neighbour_standing_on_the_table():
    # A plate 4 mm high (grey as the table) runs from the target to a smaller cylinder 75 px away. The height test
    # sees the neighbour too, but a region standing above 10 mm that the target does not touch is another
    # object: the plate is added, the neighbour is not.
    depth, rgb, truth = _grey_scene()
    other_depth, _, other, _ = render(height=0.02, radius=0.03, centre=(0.1, 0.0))
    depth = np.minimum(depth, other_depth)
    rgb[other] = 60
    plate = _beside(truth, -2, 30) & ~other
    depth[plate] -= 0.004
    seg = segment(rgb, depth, CAMERA)
    assert seg.method == "depth+rgb"
    assert (seg.mask & other).sum() < 0.05 * other.sum()
    assert iou(seg.mask, truth | plate) > 0.85


def test_grey_height_evidence_is_measured_from_the_surface_around_the_object():
    # The object stands on a floor 4 mm above the fitted table (a bin's floor, the table being the plane with most
    # pixels): the floor is the surface there, not a flat part, though it stands above the table's noise.
    depth, rgb, truth = _grey_scene(noise_m=0.001)
    rows, cols = np.nonzero(truth)
    floor = np.zeros_like(truth)
    floor[rows.min() - 80: rows.max() + 80, cols.min() - 100: cols.max() + 100] = True
    depth[floor & ~truth] -= 0.004
    seg = segment(rgb, depth, CAMERA)
    assert seg.method == "depth" and iou(seg.mask, truth) > 0.95
