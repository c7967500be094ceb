"""`contourgrasp plan --bag`: a small rosbag2 (SQLite3 and MCAP) written with rosbags from the bundled frame."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rosbags", reason="rosbags cannot be imported: install contourgrasp[ros] (make test does)")

from rosbags.rosbag2 import StoragePlugin, Writer  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

import contourgrasp  # noqa: E402
from contourgrasp.cli import main  # noqa: E402
from contourgrasp.io.camera_file import read_rgbd  # noqa: E402
from contourgrasp.ros.messages import camera_info_fields, image_fields  # noqa: E402

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "bar_clamp"
TOPICS = {"color": "/camera/camera/color/image_raw", "depth": "/camera/camera/aligned_depth_to_color/image_raw",
          "info": "/camera/camera/color/camera_info"}
STORE = get_typestore(Stores.ROS2_JAZZY)
T = STORE.types


@pytest.fixture(scope="module")
def frame():
    return read_rgbd(EXAMPLE / "color_0.png", EXAMPLE / "depth_0.npy", EXAMPLE / "primesense_overhead_color.intr")


def _header(stamp: float):
    sec = math.floor(stamp)
    return T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](sec=sec, nanosec=round((stamp - sec) * 1e9)),
                                    frame_id="camera_color_optical_frame")


def _image(pixels, encoding, stamp):
    fields = image_fields(pixels, encoding)
    fields["data"] = np.frombuffer(fields["data"], np.uint8)
    return T["sensor_msgs/msg/Image"](header=_header(stamp), **fields)


def _camera_info(intrinsics, stamp):
    roi = T["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)
    return T["sensor_msgs/msg/CameraInfo"](header=_header(stamp), binning_x=0, binning_y=0, roi=roi,
                                           **camera_info_fields(intrinsics))


def write_bag(path, frame, depth_encoding, storage, *, frames=2):
    """Frame i at stamp 10 + i s: colour, depth (the depth of frame 1 is the bundled one, frame 0's is 2 cm nearer)."""
    depth = np.round(frame.depth * 1000) if depth_encoding == "16UC1" else frame.depth.astype(np.float32)
    with Writer(path, version=9, storage_plugin=storage) as writer:
        connections = {name: writer.add_connection(TOPICS[name], msgtype, typestore=STORE) for name, msgtype in
                       (("color", "sensor_msgs/msg/Image"), ("depth", "sensor_msgs/msg/Image"),
                        ("info", "sensor_msgs/msg/CameraInfo"))}
        for i in range(frames):
            stamp = 10.0 + i
            near = depth - (20 if depth_encoding == "16UC1" else 0.02) * (i == 0) * (depth > 0)
            for name, msg in (("info", _camera_info(frame.intrinsics, stamp)),
                              ("color", _image(frame.rgb, "rgb8", stamp)),
                              ("depth", _image(near, depth_encoding, stamp + 0.004))):
                writer.write(connections[name], int(stamp * 1e9), STORE.serialize_cdr(msg, msg.__msgtype__))
    return path


def _bag_args(bag, **changes):
    topics = {"--color-topic": TOPICS["color"], "--depth-topic": TOPICS["depth"], "--info-topic": TOPICS["info"]}
    args = ["plan", "--bag", str(bag)]
    for option, topic in (topics | changes).items():
        args += [option, topic]
    return args


@pytest.mark.parametrize("storage, encoding", [(StoragePlugin.SQLITE3, "32FC1"), (StoragePlugin.MCAP, "16UC1")],
                         ids=["sqlite3-32FC1", "mcap-16UC1"])
def test_plan_on_a_bag_gives_plan_grasps_pose_on_the_same_frame(tmp_path, frame, storage, encoding):
    bag = write_bag(tmp_path / "bag", frame, encoding, storage)
    depth = np.round(frame.depth * 1000) * 0.001 if encoding == "16UC1" else frame.depth
    expected = contourgrasp.plan_grasp(frame.rgb, depth, frame.intrinsics, "five-finger-linear", planner="default",
                                       top_k=10)
    assert main([*_bag_args(bag), "--bag-index", "1", "--out", str(tmp_path / "plan.json")]) == 0
    plan = json.loads((tmp_path / "plan.json").read_text())
    np.testing.assert_array_equal(plan["T_camera_hand"], expected.T_camera_hand)
    assert main([*_bag_args(bag), "--out", str(tmp_path / "first.json")]) == 0
    first = json.loads((tmp_path / "first.json").read_text())
    assert first["approach_depth"] < plan["approach_depth"] - 0.015


def test_a_bag_file_of_one_storage_file_is_read_too(tmp_path, frame):
    bag = write_bag(tmp_path / "bag", frame, "32FC1", StoragePlugin.MCAP, frames=1)
    (storage_file,) = bag.glob("*.mcap")
    assert main([*_bag_args(storage_file), "--out", str(tmp_path / "plan.json")]) == 0


@pytest.fixture(scope="module")
def bag(tmp_path_factory, frame):
    return write_bag(tmp_path_factory.mktemp("bag") / "bag", frame, "32FC1", StoragePlugin.SQLITE3, frames=1)


@pytest.mark.parametrize("args, message", [
    (lambda bag, tmp: _bag_args(tmp / "missing"), "missing: no such bag"),
    (lambda bag, tmp: _bag_args(_garbage(tmp)), "cannot read the bag"),
    (lambda bag, tmp: _bag_args(bag, **{"--depth-topic": "/depth"}), "no topic /depth; the bag has /camera/camera/"),
    (lambda bag, tmp: _bag_args(bag, **{"--info-topic": TOPICS["color"]}),
     "topic /camera/camera/color/image_raw is sensor_msgs/msg/Image, need sensor_msgs/msg/CameraInfo"),
    (lambda bag, tmp: [*_bag_args(bag), "--bag-index", "3"], "has 1 message(s), no index 3"),
    (lambda bag, tmp: ["plan", "--bag", str(bag), "--color-topic", "/c"], "--bag needs --depth-topic, --info-topic"),
    (lambda bag, tmp: [*_bag_args(bag), "--rgb", "x.png"], "--bag replaces --rgb, --depth and --intrinsics"),
    (lambda bag, tmp: ["plan"], "plan needs --depth and --intrinsics, or --bag"),
    (lambda bag, tmp: _bag_args(_corrupt_metadata(tmp)), "cannot read the bag: Could not load YAML"),
], ids=["no-bag", "not-a-bag", "missing-topic", "wrong-type", "index", "topics-missing", "bag-and-files", "no-input",
        "corrupt-metadata"])
def test_a_bad_bag_or_option_is_one_line_and_exit_2(bag, tmp_path, capsys, args, message):
    assert main(args(bag, tmp_path)) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err, err


def _corrupt_metadata(tmp) -> Path:
    """A bag folder whose metadata.yaml breaks off inside a list (rosbags' message spans seven lines)."""
    folder = tmp / "corrupt"
    folder.mkdir()
    (folder / "metadata.yaml").write_text("rosbag2_bagfile_information:\n  version: [\n")
    return folder


def _garbage(tmp) -> Path:
    path = tmp / "garbage.mcap"
    path.write_bytes(b"not an mcap file" * 10)
    return path


def test_a_depth_image_too_far_in_time_is_no_pair(tmp_path, frame):
    bag = tmp_path / "bag"
    with Writer(bag, version=9) as writer:
        c = {n: writer.add_connection(TOPICS[n], t, typestore=STORE) for n, t in (
            ("color", "sensor_msgs/msg/Image"), ("depth", "sensor_msgs/msg/Image"), ("info", "sensor_msgs/msg/CameraInfo"))}
        for name, msg in (("info", _camera_info(frame.intrinsics, 10.0)), ("color", _image(frame.rgb, "rgb8", 10.0)),
                          ("depth", _image(frame.depth.astype(np.float32), "32FC1", 10.5))):
            writer.write(c[name], 10**10, STORE.serialize_cdr(msg, msg.__msgtype__))
    assert main(_bag_args(bag)) == 2
