"""`ros2 run nav2_waypoint_follower waypoint_follower`: Nav2's waypoint follower.

A lifecycle-managed part of the navigation stack (issue 40): ``follow_waypoints``
sends each pose to ``navigate_to_pose`` in turn; see the module's docstring
for its parameters and results.
"""

from nav2_waypoint_follower.waypoint_follower import main

from nodes.common.run import run_program

if __name__ == "__main__":
    run_program(main)  # Ctrl+C and SIGTERM end it the same quiet way
