"""The tutorial nodes, one module each: ``python -m nodes.<name> --ros-args ...``.

Importing this package makes the node join the project's DDS setup before
rclpy starts: loopback only, unless the dashboard (or the user) opted in to
the network with ``CLASSROOM_DDS_NETWORK=1``.
"""

from app.dds import configure_this_process

configure_this_process()
