"""ROS 2 at the edge of contourgrasp: message conversions, frame pairing and the ``contourgrasp`` node.

:mod:`contourgrasp.ros.messages` and :mod:`contourgrasp.ros.pairing` import no
ROS package at module level: they decode any object with the fields of
sensor_msgs/Image and sensor_msgs/CameraInfo (rclpy's messages or those
``rosbags`` deserialises). :mod:`contourgrasp.ros.node` needs rclpy, the
optional extra ``contourgrasp[ros]``.
"""
