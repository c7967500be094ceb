"""Frame-to-pose latency of the warm ``contourgrasp`` ROS 2 node.

A second node publishes the bundled bar-clamp frame (examples/bar_clamp) as
sensor_msgs/Image (rgb8, 32FC1) and CameraInfo, a new stamp per frame, to the
node in continuous mode; each frame waits for its ~/grasp. Reported, median and
p90 over the measured frames (after the warm-up ones):

* node: the message that completed the pair received -> ~/grasp, ~/pregrasp and
  ~/markers published (the node's own clock: decoding, planning, publishing);
* loop: the depth image published -> its ~/grasp received by the publisher
  (adds the DDS transport of 1.2 MB of images and of the pose, and rclpy's
  (de)serialisation);

and the CPU time per measured frame of the whole process (both nodes and the
DDS threads), which a loaded machine inflates less than the wall times.

Run: ``.venv/bin/python benchmarks/ros_latency.py [--frames 20] [--planner default]``.
Traffic stays on this machine: localhost-only discovery and a random domain id
unless ROS_DOMAIN_ID is set.
"""

from __future__ import annotations

import argparse
import os
import random
import sys
import time
from pathlib import Path

os.environ.setdefault("ROS_DOMAIN_ID", str(random.SystemRandom().randint(1, 101)))
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"

import numpy as np  # noqa: E402
import rclpy  # noqa: E402
from geometry_msgs.msg import PoseStamped  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from rclpy.node import Node  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from sensor_msgs.msg import CameraInfo, Image  # noqa: E402

from contourgrasp.io.camera_file import read_rgbd  # noqa: E402
from contourgrasp.ros.messages import camera_info_message, image_message, stamp_seconds  # noqa: E402
from contourgrasp.ros.node import ContourGraspNode  # noqa: E402

TIMEOUT = 60.0
EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "bar_clamp"
FRAME_ID = "camera_color_optical_frame"


def spin_until(executor, done, timeout: float) -> bool:
    """Spin until ``done()`` or ``timeout`` seconds; whether ``done()``."""
    deadline = time.monotonic() + timeout
    while not done() and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.02)
    return bool(done())


def measure(frames: int, warmup: int, planner: str, hand: str) -> tuple[list[float], list[float], float]:
    """(node latencies, loop latencies) of the measured frames and the CPU time per measured frame, ms."""
    context = rclpy.Context()
    rclpy.init(context=context)
    executor = SingleThreadedExecutor(context=context)
    node = ContourGraspNode(context=context, parameter_overrides=[
        Parameter("continuous", value=True), Parameter("planner", value=planner), Parameter("hand", value=hand)])
    camera = Node("camera", context=context)
    grasps = {}
    camera.create_subscription(PoseStamped, "contourgrasp/grasp",
                               lambda m: grasps.setdefault(stamp_seconds(m.header), time.perf_counter()), 10)
    colour_pub, depth_pub = (camera.create_publisher(Image, t, 5) for t in ("color/image_raw", "depth/image_raw"))
    info_pub = camera.create_publisher(CameraInfo, "color/camera_info", 5)
    for n in (node, camera):
        executor.add_node(n)
    frame = read_rgbd(EXAMPLE / "color_0.png", EXAMPLE / "depth_0.npy", EXAMPLE / "primesense_overhead_color.intr")
    rgb, depth32 = frame.rgb, frame.depth.astype(np.float32)
    info = camera_info_message(frame.intrinsics, 0.0, FRAME_ID)
    try:
        while not spin_until(executor, lambda: node.camera_info is not None, 0.25):
            info_pub.publish(info)
        loop = []
        for i in range(warmup + frames):
            if i == warmup:
                cpu = time.process_time()
            stamp = 100.0 + i
            colour, d = image_message(rgb, "rgb8", stamp, FRAME_ID), image_message(depth32, "32FC1", stamp, FRAME_ID)
            colour_pub.publish(colour)
            sent = time.perf_counter()
            depth_pub.publish(d)
            if not spin_until(executor, lambda: stamp in grasps, TIMEOUT):
                raise SystemExit(f"frame {i}: no ~/grasp in {TIMEOUT} s (a frame lost? see the node's log)")
            loop.append(1e3 * (grasps[stamp] - sent))
        return list(node.latencies_ms)[warmup:], loop[warmup:], 1e3 * (time.process_time() - cpu) / frames
    finally:
        executor.shutdown(timeout_sec=5)
        node.destroy_node()
        camera.destroy_node()
        context.try_shutdown()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--warmup", type=int, default=3)
    parser.add_argument("--planner", default="default")
    parser.add_argument("--hand", default="five-finger-linear")
    args = parser.parse_args()
    load = os.getloadavg()
    node, loop, cpu = measure(args.frames, args.warmup, args.planner, args.hand)
    print(f"{args.frames} frames (after {args.warmup} warm-up), planner {args.planner}, hand {args.hand}; "
          f"load average before {load[0]:.1f} / after {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    for name, values in (("node: received -> pose published", node), ("loop: published -> pose received", loop)):
        print(f"{name:34s} median {np.median(values):6.1f} ms, p90 {np.percentile(values, 90):6.1f} ms, "
              f"max {np.max(values):6.1f} ms")
    print(f"{'CPU time per frame (the process)':34s} {cpu:6.1f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
