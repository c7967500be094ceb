"""Conversions between sensor_msgs/geometry_msgs/visualization_msgs messages and contourgrasp's arrays and plans."""

import numpy as np
import pytest

pytest.importorskip("rclpy", reason="rclpy cannot be imported: install contourgrasp[ros] (make test does)")

from sensor_msgs.msg import CameraInfo, Image, RegionOfInterest  # noqa: E402
from visualization_msgs.msg import Marker  # noqa: E402

import contourgrasp  # noqa: E402
from contourgrasp.errors import InputError  # noqa: E402
from contourgrasp.perception import Intrinsics  # noqa: E402
from contourgrasp.ros import messages  # noqa: E402
from frames import FRAME_ID, bar_clamp, camera_info, header, image  # noqa: E402

RNG = np.random.default_rng(18)
PIXELS = RNG.integers(0, 256, (4, 5, 3), dtype=np.uint8)


def raw_image(pixels, encoding, *, bigendian=False, padding=0):
    """An Image built by hand: rows of ``padding`` extra bytes, the byte order asked."""
    a = np.asarray(pixels)
    a = a.astype(a.dtype.newbyteorder(">" if bigendian else "<"))
    rows = a.reshape(a.shape[0], -1).view(np.uint8)
    rows = np.hstack([rows, np.full((a.shape[0], padding), 255, np.uint8)])
    return Image(height=a.shape[0], width=a.shape[1], encoding=encoding, is_bigendian=int(bigendian),
                 step=rows.shape[1], data=rows.tobytes())


ALPHA = np.full(PIXELS.shape[:2], 7, np.uint8)


@pytest.mark.parametrize("pixels, encoding, expected", [
    (PIXELS, "rgb8", PIXELS),
    (PIXELS, "bgr8", PIXELS[..., ::-1]),
    (np.dstack([PIXELS, ALPHA]), "rgba8", PIXELS),
    (np.dstack([PIXELS, ALPHA]), "bgra8", PIXELS[..., ::-1]),
    (PIXELS[..., 0], "mono8", np.repeat(PIXELS[..., :1], 3, axis=2)),
], ids=["rgb8", "bgr8", "rgba8", "bgra8", "mono8"])
def test_colour_images_come_out_rgb(pixels, encoding, expected):
    rgb = messages.colour_image(raw_image(pixels, encoding, padding=3))
    assert rgb.dtype == np.uint8 and rgb.shape == (4, 5, 3)
    np.testing.assert_array_equal(rgb, expected)


@pytest.mark.parametrize("bigendian", [False, True])
@pytest.mark.parametrize("padding", [0, 6])
def test_16uc1_is_millimetres_and_32fc1_meters_in_either_byte_order(bigendian, padding):
    mm = np.array([[0, 650, 651], [1200, 65535, 700]], dtype=np.uint16)
    np.testing.assert_array_equal(messages.depth_image(raw_image(mm, "16UC1", bigendian=bigendian, padding=padding)),
                                  mm * 0.001)
    m = np.array([[np.nan, 0.65, 0.651], [1.2, 0.0, 0.7]], dtype=np.float32)
    np.testing.assert_array_equal(messages.depth_image(raw_image(m, "32FC1", bigendian=bigendian, padding=padding)),
                                  m.astype(float))


def test_image_fields_are_the_inverse_of_image_to_array():
    rgb, depth, _ = bar_clamp()
    np.testing.assert_array_equal(messages.colour_image(image(rgb[..., ::-1], "bgr8", 1.0)), rgb)
    np.testing.assert_array_equal(messages.depth_image(image(np.round(depth * 1000), "16UC1", 1.0)),
                                  np.round(depth * 1000) * 0.001)


@pytest.mark.parametrize("msg, match", [
    (Image(height=4, width=5, encoding="yuv422", step=10, data=bytes(40)),
     "encoding 'yuv422' is not one of"),
    (Image(height=4, width=5, encoding="rgb8", step=10, data=bytes(40)), "step 10 is shorter than a row"),
    (Image(height=4, width=5, encoding="rgb8", step=15, data=bytes(59)), "too few"),
])
def test_unreadable_images_are_refused(msg, match):
    with pytest.raises(InputError, match=match):
        messages.colour_image(msg)


def test_a_depth_encoding_is_not_a_colour_image_nor_the_reverse():
    with pytest.raises(InputError, match="colour image encoding '16UC1'"):
        messages.colour_image(raw_image(np.zeros((2, 2), np.uint16), "16UC1"))
    with pytest.raises(InputError, match="depth image encoding 'rgb8'"):
        messages.depth_image(raw_image(PIXELS, "rgb8"))


@pytest.mark.parametrize("values, encoding, match", [
    (np.full((3, 3), 650.0), "32FC1", "median 650 m.*REP 118 wants meters in 32FC1"),
    (np.ones((3, 3)), "16UC1", "median 0.001 m.*REP 118 wants millimetres in 16UC1"),
    (np.zeros((3, 3)), "16UC1", "no valid reading"),
])
def test_depth_in_the_wrong_unit_is_refused(values, encoding, match):
    dtype = np.float32 if encoding == "32FC1" else np.uint16
    with pytest.raises(InputError, match=match):
        messages.depth_image(raw_image(values.astype(dtype), encoding))


INTRINSICS = Intrinsics(fx=600.0, fy=610.0, cx=319.5, cy=239.5, width=640, height=480)


def test_camera_info_gives_the_intrinsics_and_back():
    assert messages.camera_info_to_intrinsics(camera_info(INTRINSICS)) == INTRINSICS


def test_binning_and_roi_are_applied_at_pixel_centres():
    info = camera_info(INTRINSICS)
    info.binning_x, info.binning_y = 2, 4
    info.roi = RegionOfInterest(x_offset=100, y_offset=40, width=320, height=240)
    got = messages.camera_info_to_intrinsics(info)
    assert (got.width, got.height) == (160, 60)
    assert (got.fx, got.fy) == (300.0, 152.5)
    assert (got.cx, got.cy) == ((319.5 - 100 - 0.5) / 2, (239.5 - 40 - 1.5) / 4)
    # a full-resolution pixel centre lands on the binned pixel centre covering it
    u, v = 100 + 2 * 7 + 0.5, 40 + 4 * 3 + 1.5
    ray = INTRINSICS.rays([[u, v]])[0]
    np.testing.assert_allclose(got.project([ray])[0], [7, 3])


def test_camera_info_with_k_all_zero_is_refused():
    info = camera_info(INTRINSICS)
    info.k = np.zeros(9)
    with pytest.raises(InputError, match="K is all zero"):
        messages.camera_info_to_intrinsics(info)
    with pytest.raises(InputError, match="camera_info: intrinsics: fx must be a focal length in pixels"):
        messages.camera_info_to_intrinsics(CameraInfo(k=[-1.0, 0, 1, 0, 1, 1, 0, 0, 1], width=2, height=2))


def test_colour_and_depth_of_different_sizes_are_refused():
    rgb, depth, intrinsics = bar_clamp()
    with pytest.raises(InputError, match="colour image is 640x480 but depth is 320x240"):
        messages.rgbd_arrays(image(rgb, "rgb8", 1.0), image(depth[::2, ::2].astype(np.float32), "32FC1", 1.0),
                             camera_info(intrinsics))
    with pytest.raises(InputError, match="intrinsics are for 640x480"):
        messages.rgbd_arrays(image(rgb[::2, ::2], "rgb8", 1.0), image(depth[::2, ::2].astype(np.float32), "32FC1", 1.0),
                             camera_info(intrinsics))


@pytest.fixture(scope="module")
def result():
    rgb, depth, intrinsics = bar_clamp()
    return contourgrasp.plan_grasp(rgb, depth, intrinsics, "five-finger-linear", planner="default")


def test_poses_keep_the_image_frame_and_stamp(result):
    h = header(12.5)
    pose = messages.pose_stamped(result.T_camera_hand, h)
    assert pose.header.frame_id == FRAME_ID and (pose.header.stamp.sec, pose.header.stamp.nanosec) == (12, 5 * 10**8)
    np.testing.assert_allclose(messages.pose_matrix(pose.pose), result.T_camera_hand, atol=1e-12)
    q = pose.pose.orientation
    np.testing.assert_allclose([q.x, q.y, q.z, q.w], result.quaternion_xyzw)


def test_markers_lie_on_the_contour_and_in_the_fingertips_plane(result):
    array = messages.plan_markers(result, header(3.0)).markers
    fingers = len(result.plan.fingers)
    assert array[0].action == Marker.DELETEALL
    assert [m.ns for m in array[1:]] == ["outline"] + ["path", "start", "grasp"] * fingers
    assert all(m.header.frame_id == FRAME_ID and m.header.stamp.sec == 3 for m in array)
    outline = np.array([[p.x, p.y, p.z] for p in array[1].points])
    pixels = result.camera.project(outline)
    np.testing.assert_allclose(pixels[:-1], result.segmentation.contour_px, atol=1e-6)
    approach = result.metric.R_camera_plane[:, 2]
    np.testing.assert_allclose(outline @ approach, approach @ result.metric.origin, atol=1e-9)
    np.testing.assert_allclose(result.T_camera_hand[:3, 2], approach)
    tips = [m for m in array if m.ns in ("start", "grasp")]
    depths = [approach @ [m.pose.position.x, m.pose.position.y, m.pose.position.z] for m in tips]
    np.testing.assert_allclose(depths, result.metric.approach_depth, atol=1e-9)
    paths = [m for m in array if m.ns == "path"]
    for path, start, contact in zip(paths, array[3::3], result.plan.fingers):
        first = path.points[0]
        np.testing.assert_allclose([first.x, first.y, first.z],
                                   [start.pose.position.x, start.pose.position.y, start.pose.position.z], atol=1e-9)
    missed = [m.color.r > 0.5 and m.color.g < 0.5 for m in array if m.ns == "grasp"]
    assert missed == [f.missed for f in result.plan.fingers]


def test_markers_of_a_tilted_plan_lie_in_its_approach_frame_at_the_grasp_height():
    rgb, depth, intrinsics = bar_clamp()
    tilted = contourgrasp.plan_grasp(rgb, depth, intrinsics, "five-finger-linear", planner="default",
                                     approaches="tilted")
    array = messages.plan_markers(tilted, header(3.0)).markers
    view, metric = tilted.view, tilted.metric
    R_camera_view = metric.R_camera_plane @ view.R_plane_view
    origin = metric.origin + metric.R_camera_plane @ view.origin
    np.testing.assert_allclose(R_camera_view[:, 2], tilted.T_camera_hand[:3, 2], atol=1e-12)
    outline = np.array([[p.x, p.y, p.z] for p in array[1].points])
    np.testing.assert_allclose((outline - origin) @ R_camera_view[:, :2], np.vstack([view.contour_xy,
                                                                                      view.contour_xy[:1]]), atol=1e-9)
    tips = np.array([[m.pose.position.x, m.pose.position.y, m.pose.position.z] for m in array
                     if m.ns in ("start", "grasp")])
    np.testing.assert_allclose((tips - origin) @ R_camera_view[:, 2], -tilted.grasp_height, atol=1e-9)
