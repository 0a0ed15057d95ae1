from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription(
        [
            # TODO: start the heartbeat executable as the node 'pulse'
            # TODO: start the monitor executable as the node 'pulse_monitor', output on screen
        ]
    )
