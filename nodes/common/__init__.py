"""Plain, ROS-free helpers shared by the perception and manipulation nodes.

Everything here is numpy (and OpenCV for the vision parts): it can be imported,
tested and reused without starting a ROS node.
"""
