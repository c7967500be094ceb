"""Picking the object's region and its outline (contourgrasp.perception.region)."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from scipy import ndimage

from contourgrasp.perception import SEGMENT_METHODS, PerceptionWarning, SegmentationError, mask_contour, segment, segment_depth
from contourgrasp.tolerances import CONTOUR_EPSILON_PX, MIN_AREA_PX
from perception_scenes import H, W, CAMERA, render, iou


def test_object_on_the_border_is_refused():
    depth, rgb, _, _ = render(centre=(0.38, 0.0), radius=0.05)
    for method in SEGMENT_METHODS:
        with pytest.raises(SegmentationError, match="not completely visible") as err:
            segment(rgb, depth, CAMERA, method=method)
        assert err.value.kind == "not-visible"


def test_tiny_object_is_refused_naming_area_and_threshold():
    depth, _, truth, _ = render(radius=0.008)
    with pytest.raises(SegmentationError, match=rf"has (\d+) px, below min_area_px = {MIN_AREA_PX}") as err:
        segment_depth(depth, CAMERA)
    assert err.value.kind == "tiny"
    assert 0.8 * truth.sum() < int(err.value.args[0].split(" has ")[1].split(" px")[0]) <= truth.sum()


def test_empty_table_has_no_object():
    depth, _, _, _ = render(kind="none")
    with pytest.raises(SegmentationError, match="no object found") as err:
        segment_depth(depth, CAMERA)
    assert err.value.kind == "no-object"


def test_similar_objects_warn_and_the_largest_is_taken():
    big, _, big_mask, _ = render(radius=0.04, centre=(-0.08, 0.0))
    small, _, _, _ = render(radius=0.035, centre=(0.08, 0.0))
    depth = np.minimum(big, small)
    with pytest.warns(PerceptionWarning, match="2 regions .* of similar size"):
        seg = segment_depth(depth, CAMERA)
    assert len(seg.warnings) == 1
    assert iou(seg.mask, big_mask) > 0.95


def test_contour_lies_on_the_mask_outline():
    depth, _, _, _ = render(kind="box", tilt_deg=12.7)
    seg = segment_depth(depth, CAMERA)
    outline = seg.mask & ~ndimage.binary_erosion(seg.mask)
    distance = ndimage.distance_transform_edt(~outline)
    u, v = seg.contour_px.T.astype(int)
    assert np.all(distance[v, u] == 0)
    filled = np.zeros((H, W), np.uint8)
    cv2.fillPoly(filled, [seg.contour_px.astype(np.int32)], 1)
    assert iou(filled > 0, seg.mask) > 0.97
    assert 3 <= len(seg.contour_px) <= 400


def test_long_outlines_are_capped():
    mask = np.zeros((H, W), bool)
    mask[100:380, 100:540] = True
    for left in range(100, 540, 4):
        mask[96:100, left:left + 2] = True
    assert len(mask_contour(mask)) == 400


def test_an_outline_crossing_itself_is_repaired_and_a_simple_one_kept():
    from contourgrasp.contour.polygon import first_self_intersection
    from contourgrasp.io.camera_file import read_rgb
    from contourgrasp.perception import segment_rgb

    # The bundled frame's RGB outline crossed itself on a pixel staircase (edges 76 and 80).
    rgb = read_rgb(Path(__file__).resolve().parents[2] / "examples" / "bar_clamp" / "color_0.png")
    assert first_self_intersection(segment_rgb(rgb).contour_px) is None
    mask = np.zeros((H, W), bool)
    mask[100:200, 150:300] = True
    outline, _ = cv2.findContours(mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    simple = cv2.approxPolyDP(outline[0], CONTOUR_EPSILON_PX, True)[:, 0, :].astype(float)
    np.testing.assert_array_equal(mask_contour(mask), simple)
