"""Without the optional extra ``contourgrasp[ros]`` the doctest collection skips the modules that import rclpy.

Hypothesis draws the same examples on every run (``derandomize``), so a run of ``make test`` on a fresh clone
is repeatable: a property that fails, fails every time, not once in a while.
"""

import importlib.util

from hypothesis import settings

settings.register_profile("repeatable", derandomize=True)
settings.load_profile("repeatable")

collect_ignore = [] if importlib.util.find_spec("rclpy") else ["src/contourgrasp/ros/node.py", "tests/ros/frames.py"]
