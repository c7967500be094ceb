"""Isolation of the ROS tests: a random ROS_DOMAIN_ID per session and discovery on localhost only.

Set before any test creates an rclpy context, so every participant of the
session (in this process and in the `contourgrasp ros` processes it starts)
talks only to the others, over the loopback interface.
"""

import os
import random

os.environ["ROS_DOMAIN_ID"] = str(random.SystemRandom().randint(1, 101))
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
for name in ("ROS_STATIC_PEERS", "ROS_LOCALHOST_ONLY", "ROS_DISCOVERY_SERVER",
             "FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE"):
    os.environ.pop(name, None)
