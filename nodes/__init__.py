"""The tutorial nodes, one module each: ``python -m nodes.<name> --ros-args ...``.

Importing this package makes the node join the project's DDS setup before
rclpy starts: loopback only, unless the dashboard (or the user) opted in to
the network with ``CLASSROOM_DDS_NETWORK=1``. It also makes rclpy's parameter
services refuse a value of unknown type instead of ending the node (an rclpy
7.1.6 bug; see nodes/common/parameter_guard.py).
"""

from app.dds import configure_this_process
from nodes.common.parameter_guard import guard_parameter_services

configure_this_process()
guard_parameter_services()
