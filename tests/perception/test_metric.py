"""The contour in meters and the approach depth (contourgrasp.perception.metric)."""

from __future__ import annotations

import math
import warnings

import cv2
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from contourgrasp.errors import InputError
from contourgrasp.perception import (DEPTH_MODES, Intrinsics, PerceptionWarning, Plane, approach_depth, contour_to_metric,
                                     segment, segment_depth)
from contourgrasp.tolerances import APPROACH_OFFSET
from perception_scenes import H, W, CAMERA, render, extents


def test_footprint_contour_without_a_table_is_refused():
    depth, _, _, _ = render(tilt_deg=12.7)
    contour = segment_depth(depth, CAMERA).contour_px
    noise = np.random.default_rng(0).uniform(0.3, 1.4, (H, W))
    with pytest.warns(PerceptionWarning, match="no table plane"), pytest.raises(InputError, match="needs the table plane"):
        contour_to_metric(contour, noise, CAMERA, on_table=True)


@pytest.mark.parametrize("depth_mode", DEPTH_MODES)
def test_cylinder_size_in_meters_top_down(depth_mode):
    radius, height = 0.04, 0.03
    top = 0.7 - height
    depth, rgb, _, _ = render(radius=radius, height=height)
    seg = segment(rgb, depth, CAMERA, depth_options={"footprint": depth_mode == "max"})
    metric = contour_to_metric(seg.contour_px, depth, CAMERA, depth_mode=depth_mode, plane=seg.plane,
                               on_table=seg.on_table)
    assert metric.frame == "camera" and metric.on_table == (depth_mode == "max")
    np.testing.assert_allclose(metric.R_camera_plane, np.eye(3), atol=1e-6)
    # The footprint on the table measures the cylinder itself; "plane" puts the seen top rim at its depth.
    np.testing.assert_allclose(extents(metric.contour_xy), 2 * radius, rtol=0.03)
    assert metric.approach_depth == pytest.approx(top + APPROACH_OFFSET, abs=1e-3)
    assert metric.invalid_depth_px == 0


def test_silhouette_at_the_largest_contour_depth_overstates_a_tall_object():
    # The thesis's eq 3.1-3.2 on the pixels that see the object: the top rim at the table's depth.
    radius, height = 0.04, 0.03
    depth, _, _, _ = render(radius=radius, height=height)
    seg = segment_depth(depth, CAMERA, footprint=False)
    metric = contour_to_metric(seg.contour_px, depth, CAMERA, plane=seg.plane)
    assert metric.z_max == pytest.approx(0.7, abs=2e-3)
    np.testing.assert_allclose(extents(metric.contour_xy), 2 * radius * metric.z_max / (0.7 - height), rtol=0.03)


@pytest.mark.parametrize("tilt_deg", [5.0, 12.7, 19.0])
def test_tilted_camera_plans_the_footprint_on_the_table(tilt_deg):
    radius, height = 0.04, 0.03
    depth, _, _, normal = render(kind="box", tilt_deg=tilt_deg, radius=radius, height=height, centre=(0.02, -0.03))
    seg = segment_depth(depth, CAMERA)
    metric = contour_to_metric(seg.contour_px, depth, CAMERA, plane=seg.plane, on_table=seg.on_table)
    assert metric.frame == "table" and metric.on_table
    np.testing.assert_allclose(metric.R_camera_plane[:, 2], -normal, atol=1e-3)
    np.testing.assert_allclose(extents(metric.contour_xy), 2 * radius, rtol=0.03)
    moments = cv2.moments(metric.contour_xy.astype(np.float32))
    centre = np.array([moments["m10"], moments["m01"]]) / moments["m00"]
    np.testing.assert_allclose(centre, [0.02, -0.03], atol=1e-3)
    assert metric.approach_depth == pytest.approx(0.7 - height + APPROACH_OFFSET, abs=1e-3)


@pytest.mark.parametrize("tilt_deg", [5.0, 12.7, 19.0])
def test_tilted_camera_plans_in_the_table_plane(tilt_deg):
    radius, height = 0.04, 0.03
    depth, _, _, normal = render(kind="disc", tilt_deg=tilt_deg, radius=radius, height=height, centre=(0.02, -0.03))
    seg = segment_depth(depth, CAMERA, footprint=False)
    metric = contour_to_metric(seg.contour_px, depth, CAMERA, plane=seg.plane, depth_mode="plane")
    assert metric.frame == "table"
    assert math.degrees(metric.tilt) == pytest.approx(tilt_deg, abs=0.5)
    np.testing.assert_allclose(metric.R_camera_plane[:, 2], -normal, atol=1e-3)
    np.testing.assert_allclose(metric.R_camera_plane.T @ metric.R_camera_plane, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(extents(metric.contour_xy), 2 * radius, rtol=0.03)
    # The origin is where the optical axis meets the disc's plane, height * tan(tilt) from where it meets the table.
    moments = cv2.moments(metric.contour_xy.astype(np.float32))
    centre = np.array([moments["m10"], moments["m01"]]) / moments["m00"]
    np.testing.assert_allclose(centre, [0.02, -0.03 - height * math.tan(math.radians(tilt_deg))], atol=5e-4)
    assert metric.approach_depth == pytest.approx(0.7 - height + APPROACH_OFFSET, abs=1e-3)


def test_without_tilt_correction_a_tilted_disc_is_squashed():
    radius = 0.04
    depth, _, _, _ = render(kind="disc", tilt_deg=19.0, radius=radius)
    seg = segment_depth(depth, CAMERA)
    level = Plane(normal=np.array([0.0, 0.0, -1.0]), offset=0.7)
    width, length = extents(contour_to_metric(seg.contour_px, depth, CAMERA, plane=level).contour_xy)
    assert length / width < math.cos(math.radians(19.0)) + 0.02


def test_to_camera_reprojects_onto_the_contour_pixels():
    depth, _, _, _ = render(kind="disc", tilt_deg=12.7)
    seg = segment_depth(depth, CAMERA)
    metric = contour_to_metric(seg.contour_px, depth, CAMERA, plane=seg.plane)
    points = metric.to_camera(metric.contour_xy)
    pixels = (points @ CAMERA.K.T)[:, :2] / points[:, 2:]
    np.testing.assert_allclose(pixels, seg.contour_px, atol=1e-6)
    stop = metric.to_camera(metric.contour_xy, depth=metric.approach_depth)
    np.testing.assert_allclose(stop @ metric.R_camera_plane[:, 2], metric.approach_depth)


def test_steep_camera_warns():
    depth, _, _, _ = render(kind="disc", tilt_deg=25.0)
    seg = segment_depth(depth, CAMERA)
    with pytest.warns(PerceptionWarning, match="tilted 25"):
        contour_to_metric(seg.contour_px, depth, CAMERA, plane=seg.plane)


def test_invalid_contour_depth_is_ignored_and_counted():
    depth, _, _, _ = render(radius=0.05, height=0.02)
    seg = segment_depth(depth, CAMERA, footprint=False)
    spoiled = depth.copy()
    u, v = np.round(seg.contour_px[:3]).astype(int).T
    spoiled[v, u] = [0.0, np.nan, 3.0]
    metric = contour_to_metric(seg.contour_px, spoiled, CAMERA, plane=seg.plane)
    assert metric.invalid_depth_px == 3
    assert metric.z_max == pytest.approx(0.7, abs=2e-3)


def test_contour_without_valid_depth_is_refused():
    depth, _, _, _ = render()
    seg = segment_depth(depth, CAMERA)
    with pytest.raises(InputError, match=r"no valid depth on the contour: all \d+ contour pixels"):
        contour_to_metric(seg.contour_px, np.full((H, W), 2.0), CAMERA)


def test_unknown_table_assumes_the_thesis_planes():
    depth, _, _, _ = render()
    seg = segment_depth(depth, CAMERA)
    noisy = np.where(seg.mask, depth, np.random.default_rng(0).uniform(0.3, 1.4, (H, W)))
    with pytest.warns(PerceptionWarning, match="assuming the image plane is parallel"):
        metric = contour_to_metric(seg.contour_px, noisy, CAMERA)
    assert metric.tilt is None and metric.frame == "camera"


def test_approach_depth_is_the_nearest_reading_plus_offset():
    depth = np.full((12, 12), 0.8)
    depth[3:6, 3:6] = 0.5  # the object's top, 3 x 3 pixels
    depth[7, 7], depth[8, 8] = 0.1, 0.0  # a flying pixel and a missing reading
    mask = np.zeros((12, 12), bool)
    mask[2:10, 2:10] = True
    assert approach_depth(depth, mask, offset=0.02) == pytest.approx(0.52)
    with pytest.raises(InputError, match="no valid depth inside the object"):
        approach_depth(depth, np.zeros((12, 12), bool))


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_random_contours_and_cameras_give_a_metric_contour_or_input_error(data):
    from hypothesis.extra.numpy import arrays

    h, w = data.draw(st.integers(2, 24), label="h"), data.draw(st.integers(2, 24), label="w")
    absurd = st.sampled_from([1e-300, 1e-3, 1.0, 525.0, 1e300])
    try:
        camera = Intrinsics(fx=data.draw(absurd), fy=data.draw(absurd),
                            cx=data.draw(st.sampled_from([w / 2, -1e300, 1e300])), cy=h / 2, width=w, height=h)
    except InputError:
        return  # an absurd camera is refused where it is made
    depth = data.draw(arrays(np.float64, (h, w), elements=st.sampled_from([0.0, np.nan, np.inf, 0.7, 0.65, 1e300])))
    n = data.draw(st.integers(0, 6), label="n")
    contour = data.draw(st.one_of(
        arrays(np.float64, (n, 2), elements=st.floats(-1, max(h, w)) | st.sampled_from([np.nan, np.inf, 1e300])),
        st.sampled_from([None, "contour", [[1, 2, 3]], np.zeros((3, 2), complex)])), label="contour")
    options = data.draw(st.fixed_dictionaries({}, optional={
        "depth_mode": st.sampled_from(["max", "plane", "min", 1]), "on_table": st.booleans(),
        "offset": st.sampled_from([0.01, -1e300, np.nan, "1"]),
        "depth_range": st.sampled_from([(0.2, 1.5), (0, 1e300), (1.0, 0.5), "far", (np.nan, 1)])}), label="options")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            contour_to_metric(contour, depth, camera, **options)
        except InputError:
            pass
