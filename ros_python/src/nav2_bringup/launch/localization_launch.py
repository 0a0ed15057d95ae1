"""nav2_bringup's localization_launch.py: map_server and amcl, brought up by their manager.

``map:=`` the map's YAML file, ``params_file:=`` the parameters (the package's
params/nav2_params.yaml by default), ``namespace:=``, ``use_sim_time:=``,
``autostart:=`` (the lifecycle manager configures and activates both at once).
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node, PushRosNamespace
from nav2_common.launch import RewrittenYaml


def generate_launch_description():
    bringup_dir = get_package_share_directory("nav2_bringup")

    namespace = LaunchConfiguration("namespace")
    map_yaml_file = LaunchConfiguration("map")
    use_sim_time = LaunchConfiguration("use_sim_time")
    autostart = LaunchConfiguration("autostart")
    params_file = LaunchConfiguration("params_file")
    log_level = LaunchConfiguration("log_level")

    lifecycle_nodes = ["map_server", "amcl"]

    # Namespaced nodes read their sections under the namespace, and TF stays global.
    configured_params = RewrittenYaml(
        source_file=params_file,
        root_key=namespace,
        param_rewrites={"use_sim_time": use_sim_time, "yaml_filename": map_yaml_file},
        convert_types=True,
    )
    remappings = [("/tf", "tf"), ("/tf_static", "tf_static")]

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
            DeclareLaunchArgument("log_level", default_value="info", description="log level"),
            GroupAction(
                [
                    PushRosNamespace(namespace),
                    Node(
                        package="nav2_map_server",
                        executable="map_server",
                        name="map_server",
                        output="screen",
                        parameters=[configured_params],
                        arguments=["--ros-args", "--log-level", log_level],
                        remappings=remappings,
                    ),
                    Node(
                        package="nav2_amcl",
                        executable="amcl",
                        name="amcl",
                        output="screen",
                        parameters=[configured_params],
                        arguments=["--ros-args", "--log-level", log_level],
                        remappings=remappings,
                    ),
                    Node(
                        package="nav2_lifecycle_manager",
                        executable="lifecycle_manager",
                        name="lifecycle_manager_localization",
                        output="screen",
                        arguments=["--ros-args", "--log-level", log_level],
                        parameters=[
                            configured_params,
                            {"autostart": autostart, "node_names": lifecycle_nodes},
                        ],
                    ),
                ]
            ),
        ]
    )
