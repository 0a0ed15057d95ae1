"""turtle_tf2_py's launch files, for the catalog's ament prefix (app.launch_prefix).

The tf2 tutorials start their demo with ``ros2 launch turtle_tf2_py
turtle_tf2_demo.launch.py``: turtlesim named ``sim``, a broadcaster per
turtle and the listener that spawns turtle2 and makes it follow
``target_frame``. The carrot demos include it with ``target_frame:=carrot1``
and add the frame's broadcaster. Written here in the tutorials' own form.

``learning_tf2_py`` is the package the tutorials have the learner write:
the same launch files, naming its own executables, under both spellings the
tutorials have used (``turtle_tf2_demo_launch.py``, ``turtle_tf2_demo.launch.py``).
The URDF tutorials' ``display.launch.py`` (urdf_tutorial: a model given as
``model:=urdf/<file>``, relative to the package, run through xacro, with
robot_state_publisher and the joint sliders; the dashboard's 3D view is the
rviz) and ``demo.launch.py`` (urdf_tutorial_r2d2: robot_state_publisher
with r2d2.urdf.xml and the tutorial's state_publisher) come with their
models.
"""

from __future__ import annotations

from pathlib import Path

_DEMO = '''"""PACKAGE's turtle_tf2_demo launch file: turtle2 follows target_frame (turtle1)."""

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
            package='PACKAGE',
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
            package='PACKAGE',
            executable='turtle_tf2_broadcaster',
            name='broadcaster2',
            parameters=[
                {'turtlename': 'turtle2'}
            ]
        ),
        Node(
            package='PACKAGE',
            executable='turtle_tf2_listener',
            name='listener',
            parameters=[
                {'target_frame': LaunchConfiguration('target_frame')}
            ]
        ),
    ])
'''


def _demo(package: str) -> str:
    return _DEMO.replace("PACKAGE", package)


def _carrot_demo(package: str, executable: str, name: str, demo_file: str) -> str:
    return f'''"""{package}'s demo with carrot1 ({executable}): turtle2 follows the carrot."""

from launch import LaunchDescription
from launch.actions import IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    demo_nodes = IncludeLaunchDescription(
        PythonLaunchDescriptionSource([
            PathJoinSubstitution([
                FindPackageShare('{package}'),
                'launch',
                '{demo_file}'
            ]),
        ]),
        launch_arguments={{'target_frame': 'carrot1'}}.items(),
    )

    return LaunchDescription([
        demo_nodes,
        Node(
            package='{package}',
            executable='{executable}',
            name='{name}',
        ),
    ])
'''


def _tf2_package(package: str, suffix: str) -> dict[str, str]:
    """The three demo launch files of a tf2 tutorial package, named ``<demo><suffix>``."""
    demo = f"turtle_tf2_demo{suffix}"
    return {
        f"share/{package}/launch/{demo}": _demo(package),
        f"share/{package}/launch/turtle_tf2_fixed_frame_demo{suffix}": _carrot_demo(
            package, "fixed_frame_tf2_broadcaster", "fixed_broadcaster", demo
        ),
        f"share/{package}/launch/turtle_tf2_dynamic_frame_demo{suffix}": _carrot_demo(
            package, "dynamic_frame_tf2_broadcaster", "dynamic_broadcaster", demo
        ),
    }


URDF_DISPLAY = '''"""urdf_tutorial's display.launch.py: a model, robot_state_publisher, sliders.

``model`` is a path relative to the urdf_tutorial package (urdf/01-myfirst.urdf
... urdf/08-macroed.urdf.xacro); it goes through xacro, as urdf_launch does.
With gui:=true (the default) joint_state_publisher_gui publishes the joints
from the sliders in the dashboard's 3D view; gui:=false starts
joint_state_publisher. The 3D view is this classroom's rviz.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.conditions import IfCondition, UnlessCondition
from launch.substitutions import Command, FindExecutable, LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    ld = LaunchDescription()
    ld.add_action(DeclareLaunchArgument(
        name='gui', default_value='true', choices=['true', 'false'],
        description='Flag to enable joint_state_publisher_gui'))
    ld.add_action(DeclareLaunchArgument(
        name='model', default_value=PathJoinSubstitution(['urdf', '01-myfirst.urdf']),
        description='Path to robot urdf file relative to urdf_tutorial package'))
    model_path = PathJoinSubstitution(
        [FindPackageShare('urdf_tutorial'), LaunchConfiguration('model')])
    robot_description = ParameterValue(
        Command([FindExecutable(name='xacro'), ' ', model_path]), value_type=str)
    ld.add_action(Node(
        package='robot_state_publisher',
        executable='robot_state_publisher',
        parameters=[{'robot_description': robot_description}]))
    ld.add_action(Node(
        package='joint_state_publisher_gui',
        executable='joint_state_publisher_gui',
        condition=IfCondition(LaunchConfiguration('gui'))))
    ld.add_action(Node(
        package='joint_state_publisher',
        executable='joint_state_publisher',
        condition=UnlessCondition(LaunchConfiguration('gui'))))
    return ld
'''

R2D2_DEMO = '''"""urdf_tutorial_r2d2's demo.launch.py: robot_state_publisher and state_publisher."""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    use_sim_time = LaunchConfiguration('use_sim_time', default='false')

    urdf_file_name = 'r2d2.urdf.xml'
    urdf = os.path.join(
        get_package_share_directory('urdf_tutorial_r2d2'),
        urdf_file_name)
    with open(urdf, 'r') as infp:
        robot_desc = infp.read()

    return LaunchDescription([
        DeclareLaunchArgument(
            'use_sim_time',
            default_value='false',
            description='Use simulation (Gazebo) clock if true'),
        Node(
            package='robot_state_publisher',
            executable='robot_state_publisher',
            name='robot_state_publisher',
            output='screen',
            parameters=[{'use_sim_time': use_sim_time, 'robot_description': robot_desc}],
            arguments=[urdf]),
        Node(
            package='urdf_tutorial_r2d2',
            executable='state_publisher',
            name='state_publisher',
            output='screen'),
    ])
'''

_SRC = Path(__file__).resolve().parent.parent / "ros_python" / "src"


def _models() -> dict[str, str]:
    """The URDF tutorials' models, where the launch files above look for them."""
    files = {
        f"share/urdf_tutorial/urdf/{path.name}": path.read_text(encoding="utf-8")
        for path in sorted((_SRC / "urdf_tutorial" / "urdf").iterdir())
        if path.is_file()
    }
    r2d2 = _SRC / "urdf_tutorial_r2d2" / "urdf" / "r2d2.urdf.xml"
    files["share/urdf_tutorial_r2d2/r2d2.urdf.xml"] = r2d2.read_text(encoding="utf-8")
    return files


LAUNCH_FILES: dict[str, str] = {
    **_tf2_package("turtle_tf2_py", ".launch.py"),
    **_tf2_package("learning_tf2_py", "_launch.py"),
    **_tf2_package("learning_tf2_py", ".launch.py"),
    "share/urdf_tutorial/launch/display.launch.py": URDF_DISPLAY,
    "share/urdf_tutorial_r2d2/launch/demo.launch.py": R2D2_DEMO,
    "share/urdf_tutorial_r2d2/launch/demo_launch.py": R2D2_DEMO,
    **_models(),
}
