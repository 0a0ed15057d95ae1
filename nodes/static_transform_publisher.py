"""`ros2 run tf2_ros static_transform_publisher`: tf2_ros's program.

It lives in ros_python/src/tf2_ros/tools/static_transform_publisher.py.
"""

from tf2_ros.tools.static_transform_publisher import main

from nodes.common.run import run_program

if __name__ == "__main__":
    run_program(main)  # Ctrl+C and SIGTERM end it the same quiet way
