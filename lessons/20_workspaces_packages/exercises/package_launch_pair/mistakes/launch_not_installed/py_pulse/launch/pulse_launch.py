from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription(
        [
            Node(package='py_pulse', executable='heartbeat', name='pulse'),
            Node(
                package='py_pulse',
                executable='relay',
                name='pulse_relay',
                remappings=[('input', 'numbers'), ('output', 'plus_one')],
            ),
        ]
    )
