"""``python -m robot_state_publisher``: the ``robot_state_publisher`` executable."""

from robot_state_publisher.robot_state_publisher import main

main()
