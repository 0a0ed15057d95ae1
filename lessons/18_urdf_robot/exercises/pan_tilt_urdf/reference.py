"""Reference: the pan-tilt mount in URDF, loaded by robot_state_publisher.

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
  <link name="tilt_link"/>
  <joint name="tilt" type="revolute">
    <parent link="pan_link"/>
    <child link="tilt_link"/>
    <origin xyz="0 0 0.05"/>
    <axis xyz="0 1 0"/>
    <limit lower="-1.0" upper="1.0" effort="1.0" velocity="1.0"/>
  </joint>
  <link name="camera_link"/>
  <joint name="camera_mount" type="fixed">
    <parent link="tilt_link"/>
    <child link="camera_link"/>
    <origin xyz="0.03 0 0.02"/>
  </joint>
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
