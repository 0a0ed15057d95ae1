"""robot_state_publisher: ``ros2 run robot_state_publisher robot_state_publisher``.

The node is our Python version of ROS 2's robot_state_publisher
(``ros_python/src/robot_state_publisher``); this module only makes it a
catalog node. Give it the URDF as upstream takes it: ``--ros-args -p
robot_description:=...`` or, the old way, a URDF file name as the first
argument.
"""

from robot_state_publisher.robot_state_publisher import main

from nodes.common.run import run_program

if __name__ == "__main__":
    run_program(main)  # Ctrl+C and SIGTERM end it the same quiet way
