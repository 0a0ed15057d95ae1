"""Exercise: describe a pan-tilt camera mount in URDF and launch robot_state_publisher with it.

Run it as `ros2 launch` runs a launch file (the Run button does).
"""

from launch import LaunchDescription
from launch_ros.actions import Node

ROBOT = """<?xml version="1.0"?>
<robot name="pan_tilt">
  <link name="base_link"/>
  <link name="pan_link"/>
  <joint name="pan" type="continuous">
    <parent link="base_link"/>
    <child link="pan_link"/>
    <origin xyz="0 0 0.1"/>
    <axis xyz="0 0 1"/>
  </joint>
  <!-- TODO 1: the link tilt_link and the revolute joint tilt (see the statement). -->
  <!-- TODO 2: the link camera_link and the fixed joint camera_mount. -->
</robot>
"""


def generate_launch_description():
    return LaunchDescription(
        [
            Node(
                package="robot_state_publisher",
                executable="robot_state_publisher",
                parameters=[{"robot_description": ROBOT}],
                output="screen",
            ),
        ]
    )
