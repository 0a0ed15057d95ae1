"""``python -m joint_state_publisher``: the ``joint_state_publisher`` executable."""

from joint_state_publisher.joint_state_publisher import main

main()
