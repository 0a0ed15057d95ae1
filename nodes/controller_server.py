"""`ros2 run nav2_controller controller_server`: Nav2's controller_server.

A lifecycle-managed part of the navigation stack (issue 40); see the
module's docstring for its actions, services and parameters.
"""

from nav2_controller.controller_server import main

from nodes.common.run import run_program

if __name__ == "__main__":
    run_program(main)  # Ctrl+C and SIGTERM end it the same quiet way
