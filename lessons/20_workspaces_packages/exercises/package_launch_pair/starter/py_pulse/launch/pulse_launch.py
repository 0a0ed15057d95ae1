from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription(
        [
            # TODO: start the heartbeat executable as the node 'pulse'
            # TODO: start the relay executable as the node 'pulse_relay', its topics
            # 'input' and 'output' remapped to 'numbers' and 'plus_one'
        ]
    )
