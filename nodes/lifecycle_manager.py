"""`ros2 run nav2_lifecycle_manager lifecycle_manager`: Nav2's lifecycle_manager.

Part of the navigation stack (issue 40): it brings the others up; see the
module's docstring for its actions, services and parameters.
"""

from nav2_lifecycle_manager.lifecycle_manager import main

from nodes.common.run import run_program

if __name__ == "__main__":
    run_program(main)  # Ctrl+C and SIGTERM end it the same quiet way
