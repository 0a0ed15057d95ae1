"""Python version of ROS 2 Jazzy's joint_state_publisher (see joint_state_publisher.py)."""
