"""nav2_bringup's navigation_launch.py: planner, controller, navigator, waypoint follower.

They are brought up by ``lifecycle_manager_navigation``; localization (a map
and map -> odom) comes from elsewhere: localization_launch.py, or SLAM.
Arguments: ``params_file:=``, ``namespace:=``, ``use_sim_time:=``, ``autostart:=``.
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
    use_sim_time = LaunchConfiguration("use_sim_time")
    autostart = LaunchConfiguration("autostart")
    params_file = LaunchConfiguration("params_file")
    log_level = LaunchConfiguration("log_level")

    lifecycle_nodes = ["controller_server", "planner_server", "bt_navigator", "waypoint_follower"]

    configured_params = RewrittenYaml(
        source_file=params_file,
        root_key=namespace,
        param_rewrites={"use_sim_time": use_sim_time},
        convert_types=True,
    )
    remappings = [("/tf", "tf"), ("/tf_static", "tf_static")]

    def server(package, executable):
        return Node(
            package=package,
            executable=executable,
            name=executable,
            output="screen",
            parameters=[configured_params],
            arguments=["--ros-args", "--log-level", log_level],
            remappings=remappings,
        )

    return LaunchDescription(
        [
            DeclareLaunchArgument("namespace", default_value="", description="Top-level namespace"),
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
                    server("nav2_controller", "controller_server"),
                    server("nav2_planner", "planner_server"),
                    server("nav2_bt_navigator", "bt_navigator"),
                    server("nav2_waypoint_follower", "waypoint_follower"),
                    Node(
                        package="nav2_lifecycle_manager",
                        executable="lifecycle_manager",
                        name="lifecycle_manager_navigation",
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
