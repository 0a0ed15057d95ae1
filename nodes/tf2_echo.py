"""`ros2 run tf2_ros tf2_echo`: tf2_ros's program (ros_python/src/tf2_ros/tools/tf2_echo.py)."""

from tf2_ros.tools.tf2_echo import main

from nodes.common.run import run_program

if __name__ == "__main__":
    run_program(main)  # Ctrl+C and SIGTERM end it the same quiet way
