"""Reference solution: a launch file for a greeter and a listener that hears it.

Run it as `ros2 launch` runs a launch file (the Run button does): each
node's output appears prefixed with its label, and Stop (Ctrl+C) ends both.
"""

from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription(
        [
            Node(
                package="tutorial_nodes",
                executable="parameters_node",
                name="launch_greeter",
                parameters=[{"greeting": "Ahoy"}],
                output="screen",
            ),
            Node(
                package="tutorial_nodes",
                executable="listener",
                name="launch_listener",
                remappings=[("chatter", "greeting")],  # (from, to)
                output="screen",
            ),
        ]
    )
