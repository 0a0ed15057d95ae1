"""turtle_tf2_py's launch files, for the catalog's ament prefix (app.launch_prefix).

The tf2 tutorials start their demo with ``ros2 launch turtle_tf2_py
turtle_tf2_demo.launch.py``: turtlesim named ``sim``, a broadcaster per
turtle and the listener that spawns turtle2 and makes it follow
``target_frame``. The carrot demos include it with ``target_frame:=carrot1``
and add the frame's broadcaster. Written here in the tutorials' own form.
"""

from __future__ import annotations

DEMO = '''"""turtle_tf2_py's turtle_tf2_demo.launch.py: turtle2 follows target_frame (turtle1)."""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([
        Node(
            package='turtlesim',
            executable='turtlesim_node',
            name='sim'
        ),
        Node(
            package='turtle_tf2_py',
            executable='turtle_tf2_broadcaster',
            name='broadcaster1',
            parameters=[
                {'turtlename': 'turtle1'}
            ]
        ),
        DeclareLaunchArgument(
            'target_frame', default_value='turtle1',
            description='Target frame name.'
        ),
        Node(
            package='turtle_tf2_py',
            executable='turtle_tf2_broadcaster',
            name='broadcaster2',
            parameters=[
                {'turtlename': 'turtle2'}
            ]
        ),
        Node(
            package='turtle_tf2_py',
            executable='turtle_tf2_listener',
            name='listener',
            parameters=[
                {'target_frame': LaunchConfiguration('target_frame')}
            ]
        ),
    ])
'''


def _carrot_demo(executable: str, name: str) -> str:
    return f'''"""turtle_tf2_py's demo with carrot1 ({executable}): turtle2 follows the carrot."""

from launch import LaunchDescription
from launch.actions import IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import ThisLaunchFileDir
from launch_ros.actions import Node


def generate_launch_description():
    demo_nodes = IncludeLaunchDescription(
        PythonLaunchDescriptionSource([ThisLaunchFileDir(), '/turtle_tf2_demo.launch.py']),
        launch_arguments={{'target_frame': 'carrot1'}}.items(),
    )

    return LaunchDescription([
        demo_nodes,
        Node(
            package='turtle_tf2_py',
            executable='{executable}',
            name='{name}',
        ),
    ])
'''


LAUNCH_FILES: dict[str, str] = {
    "share/turtle_tf2_py/launch/turtle_tf2_demo.launch.py": DEMO,
    "share/turtle_tf2_py/launch/turtle_tf2_fixed_frame_demo.launch.py": _carrot_demo(
        "fixed_frame_tf2_broadcaster", "fixed_broadcaster"
    ),
    "share/turtle_tf2_py/launch/turtle_tf2_dynamic_frame_demo.launch.py": _carrot_demo(
        "dynamic_frame_tf2_broadcaster", "dynamic_broadcaster"
    ),
}
