"""joint_state_publisher: ``ros2 run joint_state_publisher joint_state_publisher``.

Our Python version of ROS 2's joint_state_publisher
(``ros_python/src/joint_state_publisher``) as a catalog node: it reads
``/robot_description`` and publishes ``/joint_states`` for every movable joint.
"""

from joint_state_publisher.joint_state_publisher import main

from nodes.common.run import run_program

if __name__ == "__main__":
    run_program(main)  # Ctrl+C and SIGTERM end it the same quiet way
