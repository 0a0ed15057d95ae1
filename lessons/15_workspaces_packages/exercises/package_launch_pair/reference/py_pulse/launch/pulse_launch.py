from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription(
        [
            Node(package='py_pulse', executable='heartbeat', name='pulse'),
            Node(package='py_pulse', executable='monitor', name='pulse_monitor', output='screen'),
        ]
    )
