"""`ros2 run tf2_ros static_transform_publisher`: tf2_ros's program.

It lives in ros_python/src/tf2_ros/tools/static_transform_publisher.py.
"""

import sys

from tf2_ros.tools.static_transform_publisher import main

if __name__ == "__main__":
    sys.exit(main())
