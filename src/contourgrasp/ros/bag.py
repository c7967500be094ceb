"""One RGB-D frame from a rosbag2 recording (MCAP or SQLite3), read with the pure-Python ``rosbags``.

The bag is a rosbag2 directory (with ``metadata.yaml``) or one ``.mcap`` or
``.db3`` file. The frame is the ``index``-th message of the colour topic
(sensor_msgs/Image), the depth image (sensor_msgs/Image, 16UC1 millimetres or
32FC1 meters) whose header stamp is nearest its stamp within ``tolerance``,
and the camera info (sensor_msgs/CameraInfo) recorded nearest it; decoded as
the node decodes them (:mod:`contourgrasp.ros.messages`). Bags without
embedded message definitions are read with ROS 2 Jazzy's.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import InputError
from . import messages
from .pairing import PAIR_TOLERANCE, nearest
from ..io.camera_file import RGBDFrame

IMAGE, CAMERA_INFO = "sensor_msgs/msg/Image", "sensor_msgs/msg/CameraInfo"

#: Depth images searched for a partner: those recorded within this time of the colour image, s.
SEARCH_WINDOW = 2.0


def read_bag_frame(path, color_topic: str, depth_topic: str, info_topic: str, *, index: int = 0,
                   tolerance: float = PAIR_TOLERANCE) -> RGBDFrame:
    """Read one frame of a bag: rgb (H, W, 3) uint8, depth (H, W) float in m, and its intrinsics.

    Raises
    ------
    InputError
        No such bag or not one ``rosbags`` reads; a topic missing or of another
        type; no colour image ``index``; no depth image within ``tolerance``
        seconds of it; a message that cannot be decoded. The message names the bag.
    """
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: no such bag (a rosbag2 directory, .mcap or .db3 file)")
    try:
        from rosbags.highlevel import AnyReader, AnyReaderError
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise InputError("plan --bag needs rosbags, which is not installed: pip install 'contourgrasp[ros]'") from None
    try:
        with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
            colour, depth, info = _frame_messages(reader, path, color_topic, depth_topic, info_topic, index, tolerance)
    except (AnyReaderError, OSError, ValueError, KeyError, AssertionError) as err:
        if isinstance(err, InputError):
            raise
        raise InputError(f"{path}: cannot read the bag: {' '.join(str(err).split())[:300]}") from None
    try:
        rgb, d, intrinsics = messages.rgbd_arrays(colour, depth, info)
    except InputError as err:
        raise InputError(f"{path}: {err}") from None
    return RGBDFrame(rgb=rgb, depth=d, intrinsics=intrinsics)


def _frame_messages(reader, path, color_topic, depth_topic, info_topic, index, tolerance):
    connections = {t: _connections(reader, path, t, kind)
                   for t, kind in ((color_topic, IMAGE), (depth_topic, IMAGE), (info_topic, CAMERA_INFO))}
    colour, recorded = _indexed(reader, path, connections[color_topic], color_topic, index)
    stamp = messages.stamp_seconds(colour.header)
    window = int(SEARCH_WINDOW * 1e9)
    depths = [reader.deserialize(raw, c.msgtype) for c, _, raw in
              reader.messages(connections=connections[depth_topic], start=recorded - window, stop=recorded + window)]
    i = nearest([messages.stamp_seconds(d.header) for d in depths], stamp, tolerance)
    if i is None:
        raise InputError(f"{path}: no {depth_topic} image within {tolerance} s of {color_topic} image {index} "
                         f"(stamp {stamp:.3f} s)")
    infos = [(abs(t - recorded), c, raw) for c, t, raw in reader.messages(connections=connections[info_topic])]
    if not infos:
        raise InputError(f"{path}: topic {info_topic} has no message")
    _, c, raw = min(infos, key=lambda item: item[0])
    return colour, depths[i], reader.deserialize(raw, c.msgtype)


def _connections(reader, path, topic: str, kind: str) -> list:
    found = [c for c in reader.connections if c.topic == topic]
    if not found:
        topics = sorted({c.topic for c in reader.connections})
        raise InputError(f"{path}: no topic {topic}; the bag has {', '.join(topics) or 'no topic'}")
    if any(c.msgtype != kind for c in found):
        raise InputError(f"{path}: topic {topic} is {found[0].msgtype}, need {kind}")
    return found


def _indexed(reader, path, connections, topic: str, index: int):
    count = 0
    for c, recorded, raw in reader.messages(connections=connections):
        if count == index:
            return reader.deserialize(raw, c.msgtype), recorded
        count += 1
    raise InputError(f"{path}: topic {topic} has {count} message(s), no index {index}")
