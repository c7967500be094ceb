"""Without the optional extra ``contourgrasp[ros]`` the doctest collection skips the modules that import rclpy."""

import importlib.util

collect_ignore = [] if importlib.util.find_spec("rclpy") else ["src/contourgrasp/ros/node.py", "tests/ros/frames.py"]
