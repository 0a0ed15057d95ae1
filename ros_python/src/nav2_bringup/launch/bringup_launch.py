"""nav2_bringup's bringup_launch.py: localization and navigation together.

``ros2 launch nav2_bringup bringup_launch.py map:=MAP.yaml`` starts map_server
and amcl (localization_launch.py) and the navigation servers
(navigation_launch.py), each group with its lifecycle manager. The robot and
its world (the office simulator, robot_state_publisher) come from elsewhere,
as on a real robot. ``use_localization:=false`` leaves localization out.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction, IncludeLaunchDescription
from launch.conditions import IfCondition
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration


def generate_launch_description():
    bringup_dir = get_package_share_directory("nav2_bringup")
    launch_dir = os.path.join(bringup_dir, "launch")

    namespace = LaunchConfiguration("namespace")
    map_yaml_file = LaunchConfiguration("map")
    use_sim_time = LaunchConfiguration("use_sim_time")
    params_file = LaunchConfiguration("params_file")
    autostart = LaunchConfiguration("autostart")
    log_level = LaunchConfiguration("log_level")
    use_localization = LaunchConfiguration("use_localization")

    common = {
        "namespace": namespace,
        "use_sim_time": use_sim_time,
        "autostart": autostart,
        "params_file": params_file,
        "log_level": log_level,
    }

    return LaunchDescription(
        [
            DeclareLaunchArgument("namespace", default_value="", description="Top-level namespace"),
            DeclareLaunchArgument(
                "map", default_value="", description="Full path to map yaml file to load"
            ),
            DeclareLaunchArgument(
                "use_sim_time",
                default_value="false",
                description="Use simulation (Gazebo) clock if true",
            ),
            DeclareLaunchArgument(
                "params_file",
                default_value=os.path.join(bringup_dir, "params", "nav2_params.yaml"),
                description="Full path to the ROS2 parameters file to use for all launched nodes",
            ),
            DeclareLaunchArgument(
                "autostart",
                default_value="true",
                description="Automatically startup the nav2 stack",
            ),
            DeclareLaunchArgument(
                "use_localization",
                default_value="true",
                description="Whether to enable localization or not",
            ),
            DeclareLaunchArgument("log_level", default_value="info", description="log level"),
            # Each included file puts its nodes into the namespace itself.
            GroupAction(
                [
                    IncludeLaunchDescription(
                        PythonLaunchDescriptionSource(
                            os.path.join(launch_dir, "localization_launch.py")
                        ),
                        condition=IfCondition(use_localization),
                        launch_arguments={**common, "map": map_yaml_file}.items(),
                    ),
                    IncludeLaunchDescription(
                        PythonLaunchDescriptionSource(
                            os.path.join(launch_dir, "navigation_launch.py")
                        ),
                        launch_arguments=common.items(),
                    ),
                ]
            ),
        ]
    )
