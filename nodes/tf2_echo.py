"""`ros2 run tf2_ros tf2_echo`: tf2_ros's program (ros_python/src/tf2_ros/tools/tf2_echo.py)."""

import sys

from tf2_ros.tools.tf2_echo import main

if __name__ == "__main__":
    sys.exit(main())
