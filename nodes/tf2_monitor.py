"""`ros2 run tf2_ros tf2_monitor`: tf2_ros's program.

It lives in ros_python/src/tf2_ros/tools/tf2_monitor.py.
"""

from tf2_ros.tools.tf2_monitor import main

from nodes.common.run import run_program

if __name__ == "__main__":
    run_program(main)  # Ctrl+C and SIGTERM end it the same quiet way
