"""The bundled bar-clamp frame (examples/bar_clamp) as rclpy messages, and a bounded spin for the ROS tests.

Importing this module isolates the session's DDS traffic, before any test
creates an rclpy context: a random ROS_DOMAIN_ID for the session and discovery
on localhost only, so every participant (in this process and in the
`contourgrasp ros` processes the tests start) talks only to the others, over
the loopback interface. (Not a conftest.py: tests/ import their conftest by name.)
"""

import os
import random
import time
from pathlib import Path

os.environ["ROS_DOMAIN_ID"] = str(random.SystemRandom().randint(1, 101))
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
for _name in ("ROS_STATIC_PEERS", "ROS_LOCALHOST_ONLY", "ROS_DISCOVERY_SERVER",
              "FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE"):
    os.environ.pop(_name, None)

from contourgrasp.io.camera_file import read_rgbd
from contourgrasp.ros import messages

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "bar_clamp"
FRAME_ID = "camera_color_optical_frame"


def bar_clamp():
    """The bundled frame: rgb (480, 640, 3) uint8, depth (480, 640) float in m, intrinsics."""
    frame = read_rgbd(EXAMPLE / "color_0.png", EXAMPLE / "depth_0.npy", EXAMPLE / "primesense_overhead_color.intr")
    return frame.rgb, frame.depth, frame.intrinsics


def header(stamp: float):
    return messages.header(stamp, FRAME_ID)


def image(pixels, encoding: str, stamp: float):
    return messages.image_message(pixels, encoding, stamp, FRAME_ID)


def camera_info(intrinsics, stamp: float = 0.0):
    return messages.camera_info_message(intrinsics, stamp, FRAME_ID)


def spin_until(executor, done, timeout: float) -> bool:
    """Spin until ``done()`` or ``timeout`` seconds; whether ``done()``."""
    deadline = time.monotonic() + timeout
    while not done() and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.02)
    return bool(done())
