"""The support surface: a bin's floor under the objects, not the conveyor with most pixels."""

from __future__ import annotations

import numpy as np
import pytest

from contourgrasp.errors import SegmentationError
from contourgrasp.perception import Support, find_support, fit_table_plane
from contourgrasp.perception.camera import backproject

from perception_scenes import CAMERA, H, W

CONVEYOR, FLOOR, RIM = 0.80, 0.78, 0.70  # depths (m) of a top-down view: a bin 2 cm deep floor, 10 cm walls


def bin_scene(*, objects=((250, 200, 60, 40, 0.05),), floor=(160, 120, 320, 240), wall_px=12):
    """Depth of a bin on a conveyor: the conveyor fills the view, the bin's floor (x, y, w, h) is 2 cm above it,
    its walls ``wall_px`` wide 10 cm; objects (x, y, w, h, height above the floor) stand on the floor."""
    depth = np.full((H, W), CONVEYOR)
    x, y, w, h = floor
    depth[y - wall_px:y + h + wall_px, x - wall_px:x + w + wall_px] = RIM
    depth[y:y + h, x:x + w] = FLOOR
    for ox, oy, ow, oh, height in objects:
        depth[oy:oy + oh, ox:ox + ow] = FLOOR - height
    return depth


def test_a_bins_floor_is_the_support_though_the_conveyor_has_more_pixels():
    depth = bin_scene()
    dominant = fit_table_plane(depth, CAMERA)
    assert dominant.offset == pytest.approx(CONVEYOR, abs=1e-6)  # the plane with most pixels
    support = find_support(depth, CAMERA)
    assert isinstance(support, Support)
    assert support.plane.offset == pytest.approx(FLOOR, abs=1e-6)
    assert support.plane is not support.planes[0] and "parallel" in support.reason
    inner = [c for c in support.candidates if c.in_view]
    # on the floor: the object (2400 px) and the walls' ring, which the conveyor, below, does not join
    assert sorted(c.area_px for c in inner) == [60 * 40, 344 * 264 - 320 * 240]
    obj = next(c for c in inner if c.area_px == 2400)
    assert obj.height == pytest.approx(0.05, abs=1e-6)


def test_on_an_empty_table_the_dominant_plane_is_the_support():
    depth = np.full((H, W), 0.7)
    depth[200:260, 300:380] = 0.65
    support = find_support(depth, CAMERA)
    assert support.planes == (support.plane,) and support.plane.offset == pytest.approx(0.7, abs=1e-6)
    assert [c.area_px for c in support.candidates] == [60 * 80]
    empty = find_support(np.full((H, W), 0.7), CAMERA)
    assert empty.candidates == () and "no plane holds" in empty.reason


def test_a_higher_plane_that_holds_nothing_is_not_the_support():
    depth = np.full((H, W), 0.7)
    depth[:, :200] = 0.6  # a broad shelf at the left, 10 cm up: more than 5 % of the pixels, nothing on it
    depth[200:260, 300:380] = 0.65
    support = find_support(depth, CAMERA)
    assert len(support.planes) == 2 and support.plane.offset == pytest.approx(0.7, abs=1e-6)


def test_no_plane_is_one_line():
    rng = np.random.default_rng(0)
    with pytest.raises(SegmentationError) as err:
        find_support(rng.uniform(0.3, 1.4, (H, W)), CAMERA)
    assert err.value.kind == "no-plane" and "\n" not in str(err.value)


def test_backproject_is_consistent_with_the_planes_offsets():
    # the floor plane passes through the floor's points
    depth = bin_scene()
    support = find_support(depth, CAMERA)
    points = backproject(depth, CAMERA)[200:210, 200:210].reshape(-1, 3)
    np.testing.assert_allclose(support.plane.height(points), 0.0, atol=1e-6)


def test_plan_frame_in_a_bin_plans_on_the_object_not_on_the_walls():
    import math

    import contourgrasp as cg
    from contourgrasp.io.plan_file import image_plan_to_dict
    result = cg.plan_grasp(None, bin_scene(), CAMERA, cg.load_hand("three-finger"), xy_step=0.03, yaw_step=math.radians(6))
    assert result.target.area_px == 2400 and result.segmentation.area_px == 2400
    assert result.support.plane.offset == pytest.approx(FLOOR, abs=1e-6)
    data = image_plan_to_dict(result)["support_surface"]
    assert data["offset"] == pytest.approx(FLOOR, abs=1e-6) and data["planes_considered"] == 2
    assert data["normal"] == pytest.approx([0, 0, -1], abs=1e-6) and data["inliers"] == 320 * 240 - 2400


def tilted_bin(tilt_deg=8.8, distance=0.8, noise=0.001, missing=0.1, seed=0):
    """Depth of a bin on a conveyor seen by a camera tilted ``tilt_deg`` about its x axis, with Gaussian noise
    and a share of missing readings: heights above the conveyor of 0 (conveyor), 0.02 (the floor, 0.40 x 0.30 m),
    0.12 (the walls, 2 cm thick) and 0.07 (a 8 x 5 cm object on the floor), as flat tops seen along each ray."""
    t = np.radians(tilt_deg)
    normal = np.array([0.0, np.sin(t), -np.cos(t)])  # toward the camera
    u, v = np.meshgrid(np.arange(W), np.arange(H))
    rays = np.stack([(u - CAMERA.cx) / CAMERA.fx, (v - CAMERA.cy) / CAMERA.fy, np.ones((H, W))], axis=-1)
    x_axis = np.array([1.0, 0.0, 0.0])
    y_axis = np.cross(normal, x_axis)
    depth = np.full((H, W), np.inf)
    centre = distance * np.array([0.0, 0.0, 1.0])  # where the optical axis meets the conveyor (height 0)

    def top(height, half_x, half_y, inner=None):
        # z of each ray where it meets the plane `height` above the conveyor, inside the box (minus `inner`)
        z = (height + normal @ centre) / (rays @ normal)  # z (normal . ray) + offset = height
        p = z[..., None] * rays - centre
        x, y = p @ x_axis, p @ y_axis
        inside = (np.abs(x) <= half_x) & (np.abs(y) <= half_y)
        if inner is not None:
            inside &= ~((np.abs(x) < inner[0]) & (np.abs(y) < inner[1]))
        return np.where(inside, z, np.inf)

    for layer in (top(0.0, 1e3, 1e3), top(0.02, 0.22, 0.17), top(0.12, 0.22, 0.17, inner=(0.20, 0.15)),
                  top(0.07, 0.04, 0.025)):
        depth = np.minimum(depth, layer)
    rng = np.random.default_rng(seed)
    depth = depth + rng.normal(0.0, noise, depth.shape)
    depth[rng.random(depth.shape) < missing] = 0.0
    return depth


def test_a_tilted_noisy_bin_with_missing_readings_plans_on_the_object():
    import math

    import contourgrasp as cg
    depth = tilted_bin()
    result = cg.plan_grasp(None, depth, CAMERA, cg.load_hand("three-finger"), xy_step=0.03, yaw_step=math.radians(6))
    assert math.degrees(result.support.plane.tilt) == pytest.approx(8.8, abs=0.5)
    assert "mm above the dominant one" in result.support.reason
    conveyor = result.support.planes[0]
    assert conveyor.offset - result.support.plane.offset == pytest.approx(0.02, abs=0.003)
    assert result.target.height == pytest.approx(0.05, abs=0.005)  # the object's top above the floor
    assert result.target.extent == pytest.approx((0.08, 0.05), abs=0.01)
