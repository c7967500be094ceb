"""Conversions between ROS 2 messages and contourgrasp's arrays, intrinsics and plans.

Decoding (:func:`image_to_array`, :func:`colour_image`, :func:`depth_image`,
:func:`camera_info_to_intrinsics`) reads the fields of sensor_msgs/Image and
sensor_msgs/CameraInfo by name, so it takes rclpy's messages and those
``rosbags`` deserialises alike, and imports no ROS package. Building
(:func:`pose_stamped`, :func:`plan_markers`) imports geometry_msgs and
visualization_msgs.

Units follow REP 118: depth ``16UC1`` is millimetres, ``32FC1`` meters. Frames
follow REP 103/105: every pose and marker is in the image's
``header.frame_id``, the camera's optical frame (z forward, x right, y down),
which is the frame of ``T_camera_hand``.
"""

from __future__ import annotations

import math

import numpy as np

from .. import tolerances as tol
from ..errors import InputError
from ..hand import to_image
from ..perception import Intrinsics
from ..pipeline import plan_to_camera

#: Encodings of sensor_msgs/Image read: (numpy dtype, channels).
ENCODINGS = {
    "rgb8": (np.uint8, 3), "bgr8": (np.uint8, 3), "rgba8": (np.uint8, 4), "bgra8": (np.uint8, 4),
    "mono8": (np.uint8, 1), "16UC1": (np.uint16, 1), "mono16": (np.uint16, 1), "32FC1": (np.float32, 1),
}
COLOUR_ENCODINGS = ("rgb8", "bgr8", "rgba8", "bgra8", "mono8")
DEPTH_ENCODINGS = ("16UC1", "32FC1")

#: Meters per unit of a 16UC1 depth image (REP 118: millimetres).
MILLIMETRE = 0.001



def stamp_seconds(header) -> float:
    """Seconds of a std_msgs/Header's stamp (sec + nanosec * 1e-9)."""
    return header.stamp.sec + header.stamp.nanosec * 1e-9


def image_to_array(msg) -> np.ndarray:
    """The pixels of a sensor_msgs/Image, honouring ``step`` and ``is_bigendian``.

    Returns
    -------
    (H, W) or (H, W, C) numpy array
        dtype and channels of ``ENCODINGS[msg.encoding]``, native byte order.

    Raises
    ------
    InputError
        Unknown encoding, a ``step`` shorter than a row, or too few bytes.
    """
    if msg.encoding not in ENCODINGS:
        raise InputError(f"image encoding {msg.encoding!r} is not one of {', '.join(ENCODINGS)}")
    dtype, channels = ENCODINGS[msg.encoding]
    height, width, step = int(msg.height), int(msg.width), int(msg.step)
    row = width * channels * np.dtype(dtype).itemsize
    if height < 1 or width < 1 or step < row:
        raise InputError(f"{msg.encoding} image {width}x{height}: step {step} is shorter than a row ({row} bytes)")
    if width * height > tol.MAX_IMAGE_PIXELS:
        raise InputError(f"{msg.encoding} image {width}x{height}: more than {tol.MAX_IMAGE_PIXELS:,} pixels, the most "
                         "contourgrasp plans on")
    data = np.frombuffer(memoryview(msg.data), dtype=np.uint8)
    if data.size < step * (height - 1) + row:
        raise InputError(f"{msg.encoding} image {width}x{height}, step {step}: {data.size} bytes, too few")
    rows = np.lib.stride_tricks.as_strided(data, (height, row), (step, 1))
    order = ">" if msg.is_bigendian else "<"
    pixels = np.ascontiguousarray(rows).view(np.dtype(dtype).newbyteorder(order)).astype(dtype, copy=False)
    return pixels.reshape((height, width) if channels == 1 else (height, width, channels))


def colour_image(msg) -> np.ndarray:
    """(H, W, 3) uint8, RGB order: a colour sensor_msgs/Image (rgb8, bgr8, rgba8, bgra8 or mono8)."""
    if msg.encoding not in COLOUR_ENCODINGS:
        raise InputError(f"colour image encoding {msg.encoding!r} is not one of {', '.join(COLOUR_ENCODINGS)}")
    pixels = image_to_array(msg)
    if msg.encoding == "mono8":
        return np.repeat(pixels[..., None], 3, axis=2)
    rgb = pixels[..., :3]
    return np.ascontiguousarray(rgb[..., ::-1] if msg.encoding.startswith("bgr") else rgb)


def depth_image(msg) -> np.ndarray:
    """(H, W) float, meters: a depth sensor_msgs/Image (16UC1 millimetres or 32FC1 meters, REP 118).

    0 and NaN stay "no reading".

    Raises
    ------
    InputError
        Another encoding, no valid reading, or a median valid depth outside
        ``tolerances.MIN_PLAUSIBLE_DEPTH`` to ``MAX_PLAUSIBLE_DEPTH`` (millimetres in a 32FC1 image, meters in a 16UC1 one).
    """
    if msg.encoding not in DEPTH_ENCODINGS:
        raise InputError(f"depth image encoding {msg.encoding!r} is not one of {', '.join(DEPTH_ENCODINGS)}")
    raw = image_to_array(msg)
    depth = raw.astype(float) * (MILLIMETRE if msg.encoding == "16UC1" else 1.0)
    present = depth[np.isfinite(depth) & (depth > 0)]
    if present.size == 0:
        raise InputError(f"{msg.encoding} depth image has no valid reading (all 0 or NaN)")
    median = float(np.median(present))
    lo, hi = tol.MIN_PLAUSIBLE_DEPTH, tol.MAX_PLAUSIBLE_DEPTH
    if not lo <= median <= hi:
        unit = "millimetres" if msg.encoding == "16UC1" else "meters"
        raise InputError(f"{msg.encoding} depth has median {median:.4g} m, outside {lo:g}-{hi:g} m: "
                         f"REP 118 wants {unit} in {msg.encoding}")
    return depth


def camera_info_to_intrinsics(msg) -> Intrinsics:
    """The intrinsics of the images a sensor_msgs/CameraInfo describes, binning and ROI applied.

    K is for the full sensor; an image taken with a region of interest
    (``roi``: x_offset, y_offset, width, height; all 0 for the full image) and
    then binned by ``binning_x``, ``binning_y`` (0 or 1: none) has
    f' = f / b, c' = (c - offset - (b - 1) / 2) / b (pixel centres) and
    size = ROI size (or full size) // b.

    Raises
    ------
    InputError
        K all zero (an uncalibrated camera), or intrinsics that cannot be used.
    """
    k = np.asarray(msg.k if hasattr(msg, "k") else msg.K, dtype=float).reshape(-1)
    if k.size != 9 or not np.any(k):
        raise InputError("camera_info: K is all zero (an uncalibrated camera)" if k.size == 9 else
                         f"camera_info: K has {k.size} numbers, need 9")
    bx, by = max(int(msg.binning_x), 1), max(int(msg.binning_y), 1)
    roi = msg.roi
    full = not (roi.x_offset or roi.y_offset or roi.width or roi.height)
    width = int(msg.width) if full else int(roi.width)
    height = int(msg.height) if full else int(roi.height)
    x0, y0 = (0, 0) if full else (int(roi.x_offset), int(roi.y_offset))
    try:
        return Intrinsics(fx=k[0] / bx, fy=k[4] / by, cx=(k[2] - x0 - (bx - 1) / 2) / bx,
                          cy=(k[5] - y0 - (by - 1) / 2) / by, width=width // bx, height=height // by)
    except InputError as err:
        raise InputError(f"camera_info: {err}") from None


def rgbd_arrays(colour_msg, depth_msg, info_msg) -> tuple[np.ndarray, np.ndarray, Intrinsics]:
    """(rgb, depth in m, intrinsics) of a paired colour, depth and camera-info message, sizes checked.

    Raises
    ------
    InputError
        From the decoders, or colour, depth and intrinsics of different sizes.
    """
    rgb, depth, intrinsics = colour_image(colour_msg), depth_image(depth_msg), camera_info_to_intrinsics(info_msg)
    if rgb.shape[:2] != depth.shape:
        raise InputError(f"colour image is {rgb.shape[1]}x{rgb.shape[0]} but depth is "
                         f"{depth.shape[1]}x{depth.shape[0]} (width x height): register depth to colour")
    intrinsics.check_shape(depth.shape, "the depth image")
    return rgb, depth, intrinsics


def image_fields(pixels, encoding: str) -> dict:
    """The fields (height, width, encoding, is_bigendian, step, data as bytes) of an Image holding ``pixels``.

    The inverse of :func:`image_to_array`, for publishers, bag writers and tests.
    """
    dtype, channels = ENCODINGS[encoding]
    array = np.ascontiguousarray(pixels, dtype=np.dtype(dtype).newbyteorder("<"))
    height, width = array.shape[:2]
    return {"height": height, "width": width, "encoding": encoding, "is_bigendian": 0,
            "step": width * channels * array.itemsize, "data": array.tobytes()}


def camera_info_fields(intrinsics: Intrinsics) -> dict:
    """The fields (width, height, k, p, r, d, distortion_model) of a CameraInfo of rectified ``intrinsics``."""
    k = intrinsics.K
    p = np.c_[k, np.zeros(3)]
    return {"width": intrinsics.width, "height": intrinsics.height, "distortion_model": "plumb_bob",
            "d": np.zeros(5), "k": k.reshape(-1), "r": np.eye(3).reshape(-1), "p": p.reshape(-1)}


def header(stamp: float, frame_id: str):
    """std_msgs/Header at ``stamp`` (s) in ``frame_id`` (the inverse of :func:`stamp_seconds`)."""
    from builtin_interfaces.msg import Time
    from std_msgs.msg import Header

    sec = math.floor(stamp)
    return Header(frame_id=frame_id, stamp=Time(sec=sec, nanosec=round((stamp - sec) * 1e9)))


def image_message(pixels, encoding: str, stamp: float, frame_id: str):
    """sensor_msgs/Image of ``pixels`` (:func:`image_fields`), e.g. to replay a frame to the node."""
    import array

    from sensor_msgs.msg import Image

    fields = image_fields(pixels, encoding)
    return Image(header=header(stamp, frame_id), **(fields | {"data": array.array("B", fields["data"])}))


def camera_info_message(intrinsics: Intrinsics, stamp: float, frame_id: str):
    """sensor_msgs/CameraInfo of rectified ``intrinsics`` (:func:`camera_info_fields`)."""
    from sensor_msgs.msg import CameraInfo

    return CameraInfo(header=header(stamp, frame_id), **camera_info_fields(intrinsics))


def pose_stamped(T_camera_hand, header):
    """geometry_msgs/PoseStamped of a (4, 4) pose in the image's frame, with the image's header."""
    from geometry_msgs.msg import PoseStamped
    from scipy.spatial.transform import Rotation

    T = np.asarray(T_camera_hand, dtype=float)
    msg = PoseStamped()
    msg.header.frame_id, msg.header.stamp = header.frame_id, header.stamp
    msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = (float(v) for v in T[:3, 3])
    q = msg.pose.orientation
    q.x, q.y, q.z, q.w = (float(v) for v in Rotation.from_matrix(T[:3, :3]).as_quat())
    return msg


def pose_matrix(pose) -> np.ndarray:
    """(4, 4) float: the transform of a geometry_msgs/Pose (the inverse of :func:`pose_stamped`'s)."""
    from scipy.spatial.transform import Rotation

    T = np.eye(4)
    q = pose.orientation
    T[:3, :3] = Rotation.from_quat([q.x, q.y, q.z, q.w]).as_matrix()
    T[:3, 3] = pose.position.x, pose.position.y, pose.position.z
    return T


#: RGBA of the markers: outline, finger paths, starts, grasp points, a finger that misses.
MARKER_COLOURS = {"outline": (1.0, 0.85, 0.0, 1.0), "path": (0.1, 0.6, 1.0, 1.0), "start": (1.0, 1.0, 1.0, 1.0),
                  "grasp": (0.1, 0.9, 0.2, 1.0), "missed": (0.9, 0.1, 0.1, 1.0)}
LINE_WIDTH = 0.002
POINT_DIAMETER = 0.008


def plan_markers(result, header):
    """visualization_msgs/MarkerArray of an ImageGraspPlan, in the image's frame (RViz).

    Namespaces: ``outline`` (the contour, a closed line in the contour's plane,
    at depth z_max or on the table), ``path`` (one line per finger, open to
    closed), ``start`` and ``grasp`` (a sphere per finger; grasp points of
    fingers that miss are red). Paths, starts and grasp points lie in the
    fingertips' plane, at the approach depth; a side or tilted plan's in its
    approach frame, at its grasp height (:func:`contourgrasp.pipeline.plan_to_camera`).
    A DELETEALL marker comes first, so markers of an earlier plan do not linger.
    """
    from visualization_msgs.msg import Marker, MarkerArray

    metric, plan = result.metric, result.plan
    clear = Marker(action=Marker.DELETEALL)
    clear.header.frame_id, clear.header.stamp = header.frame_id, header.stamp
    if result.view is None:
        contour, tips = metric.contour_xy, metric.approach_depth
        outline_at, tips_at = metric.to_camera, lambda xy: metric.to_camera(xy, depth=tips)
    else:  # a side or tilted plan: its outline and fingers in its approach frame, at the grasp height
        contour = result.view.contour_xy
        outline_at = tips_at = lambda xy: plan_to_camera(metric, result.view, result.grasp_height, xy)
    outline = np.vstack([contour, contour[:1]])
    markers = [clear, _marker(Marker.LINE_STRIP, "outline", 0, outline_at(outline), header, "outline")]
    for i, (finger, contact) in enumerate(zip(plan.hand.fingers, plan.fingers)):
        path = to_image(finger.points(np.linspace(0.0, finger.travel, 30)), plan.pose)
        markers.append(_marker(Marker.LINE_STRIP, "path", i, tips_at(path), header, "path"))
        for ns, point in (("start", contact.start), ("grasp", contact.grasp_point)):
            colour = "missed" if ns == "grasp" and contact.missed else ns
            markers.append(_marker(Marker.SPHERE, ns, i, tips_at([point]), header, colour))
    return MarkerArray(markers=markers)


def _marker(kind, ns: str, marker_id: int, points, header, colour: str):
    from geometry_msgs.msg import Point
    from visualization_msgs.msg import Marker

    m = Marker(type=kind, ns=ns, id=marker_id, action=Marker.ADD)
    m.header.frame_id, m.header.stamp = header.frame_id, header.stamp
    m.pose.orientation.w = 1.0
    m.color.r, m.color.g, m.color.b, m.color.a = MARKER_COLOURS[colour]
    if kind == Marker.SPHERE:
        m.pose.position = Point(x=float(points[0][0]), y=float(points[0][1]), z=float(points[0][2]))
        m.scale.x = m.scale.y = m.scale.z = POINT_DIAMETER
    else:
        m.points = [Point(x=float(x), y=float(y), z=float(z)) for x, y, z in points]
        m.scale.x = LINE_WIDTH
    return m


def plan_summary(result) -> str:
    """One line: the grasp's position in the camera frame, yaw, cost and fingers touching."""
    x, y, z = result.T_camera_hand[:3, 3]
    touching = sum(not f.missed for f in result.plan.fingers)
    return (f"grasp at ({x:.4f}, {y:.4f}, {z:.4f}) m, yaw {math.degrees(result.plan.pose[2]):.1f} deg, "
            f"cost {result.plan.cost.total:.2f}, {touching}/{len(result.plan.fingers)} fingers touch")
