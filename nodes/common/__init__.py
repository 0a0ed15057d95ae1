"""Helpers shared by the nodes.

Most are plain numpy (and OpenCV for the vision parts): frames, kinematics,
point clouds, images, SLAM geometry; they can be imported, tested and reused
without starting a ROS node. A few small rclpy pieces sit next to them:
``run.spin_node`` (the main() every node shares), ``lifecycle_guard`` and
``parameter_guard`` (work-arounds for rclpy 7.1.6 bugs that end a node).
"""
