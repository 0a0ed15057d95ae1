"""`ros2 run tf2_ros tf2_monitor`: tf2_ros's program.

It lives in ros_python/src/tf2_ros/tools/tf2_monitor.py.
"""

import sys

from tf2_ros.tools.tf2_monitor import main

if __name__ == "__main__":
    sys.exit(main())
