"""Python version of ROS 2 Jazzy's robot_state_publisher (see robot_state_publisher.py)."""
