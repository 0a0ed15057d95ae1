"""`ros2 run nav2_amcl amcl`: Nav2's AMCL localization (ros_python/src/nav2_amcl).

A lifecycle node: configure and activate it (``ros2 lifecycle set /amcl
configure``, ``... activate``, or the dashboard's lifecycle tool), give it a
map on /map and an initial pose on /initialpose (rviz's "2D Pose Estimate",
or the dashboard's), and it publishes /amcl_pose, /particle_cloud and
map -> odom.
"""

from nav2_amcl.amcl_node import main

from nodes.common.run import run_program

if __name__ == "__main__":
    run_program(main)  # Ctrl+C and SIGTERM end it the same quiet way
