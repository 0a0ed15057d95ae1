"""The catalog: the only programs the dashboard may start.

A browser can ask for a catalog *name*, never a command line: the module and
arguments below are fixed here, so no text from the page reaches a process's
argv or a shell. An entry is what ``ros2 run <pkg> <executable> --ros-args ...``
would start; a group is what a Python launch file would describe.
"""

from __future__ import annotations

from dataclasses import dataclass, field

# nav2_bringup's parameters file (issue 40), relative as the office map's path is: the
# catalog's programs run from the project's folder.
NAV2_PARAMS = "ros_python/src/nav2_bringup/params/nav2_params.yaml"


@dataclass(frozen=True)
class CatalogEntry:
    """One runnable node: ``python -m nodes.<module> --ros-args <ros_args>``."""

    name: str
    module: str
    node_name: str  # fully qualified ROS name the process creates, e.g. /talker
    summary: str
    ros_args: tuple[str, ...] = ()
    args: tuple[str, ...] = ()  # program arguments before --ros-args
    package: str = "tutorial_nodes"  # the ROS package a full installation has it in

    def argv_tail(self) -> list[str]:
        """Arguments after ``python -m nodes.<module>``."""
        tail = list(self.args)
        if self.ros_args:
            tail += ["--ros-args", *self.ros_args]
        return tail

    def ros2_run_command(self) -> str:
        """The command a learner would type in a full ROS 2 installation."""
        words = ["ros2", "run", self.package, self.module, *self.argv_tail()]
        return " ".join(words)


@dataclass(frozen=True)
class LaunchGroup:
    """Several catalog entries started together, as one launch file would."""

    name: str
    summary: str
    members: tuple[str, ...] = field(default_factory=tuple)


ENTRIES: tuple[CatalogEntry, ...] = (
    CatalogEntry("talker", "talker", "/talker", 'Publishes "Hello World: N" on /chatter at 2 Hz.'),
    CatalogEntry("listener", "listener", "/listener", "Prints every message on /chatter."),
    CatalogEntry(
        "listener2",
        "listener",
        "/listener2",
        "The same listener program, renamed with a remap: a second subscriber.",
        ros_args=("-r", "__node:=listener2"),
    ),
    CatalogEntry(
        "crashing_node",
        "crashing_node",
        "/crashing_node",
        "Crashes on purpose after 3 s, to show how failures are reported.",
    ),
    # --- core tutorial nodes (issue 3): add entries below this line ---
    CatalogEntry(
        "flood_node",
        "flood_node",
        "/flood_node",
        "Misbehaves on purpose: 2000 messages/s on /chatter, each one logged.",
    ),
    CatalogEntry(
        "minimal_node",
        "minimal_node",
        "/minimal_node",
        'The smallest OOP node: logs "Hello ROS2" from a 5 Hz timer.',
    ),
    CatalogEntry(
        "minimal_node_procedural",
        "minimal_node_procedural",
        "/minimal_node_procedural",
        "The same minimal node written without a class, for comparison.",
    ),
    CatalogEntry(
        "add_two_ints_server",
        "add_two_ints_server",
        "/add_two_ints_server",
        "Offers the /add_two_ints service (AddTwoInts: a + b -> sum).",
    ),
    CatalogEntry(
        "add_two_ints_client",
        "add_two_ints_client",
        "/add_two_ints_client",
        "Waits for /add_two_ints, asks for 2 + 3, prints the sum and exits.",
        args=("2", "3"),
    ),
    CatalogEntry(
        "fibonacci_action_server",
        "fibonacci_action_server",
        "/fibonacci_action_server",
        "Offers the /fibonacci action: feedback per step, cancel, range 0..46, newest goal wins.",
    ),
    CatalogEntry(
        "fibonacci_action_client",
        "fibonacci_action_client",
        "/fibonacci_action_client",
        "Sends a /fibonacci goal of order 10, prints feedback and the result, exits.",
        args=("10",),
    ),
    CatalogEntry(
        "lifecycle_talker",
        "lifecycle_talker",
        "/lifecycle_talker",
        "A lifecycle node: publishes on /lifecycle_chatter only while active.",
    ),
    CatalogEntry(
        "lifecycle_talker_failing",
        "lifecycle_talker",
        "/lifecycle_talker",
        "The lifecycle talker with fail_on:=activate: activation fails on purpose.",
        ros_args=("-p", "fail_on:=activate"),
    ),
    CatalogEntry(
        "parameters_node",
        "parameters_node",
        "/parameters_node",
        "Publishes a greeting on /greeting; rate, text and case are live parameters.",
    ),
    CatalogEntry(
        "qos_talker",
        "qos_talker",
        "/qos_talker",
        "Publishes on /qos_chatter, reliable + volatile (QoS set by parameters).",
    ),
    CatalogEntry(
        "qos_talker_best_effort",
        "qos_talker",
        "/qos_talker_best_effort",
        "The QoS talker as a best-effort publisher: reliable listeners reject it.",
        ros_args=("-r", "__node:=qos_talker_best_effort", "-p", "reliability:=best_effort"),
    ),
    CatalogEntry(
        "qos_talker_transient_local",
        "qos_talker",
        "/qos_talker_transient_local",
        "The QoS talker keeping its last 10 messages for late-joining subscribers.",
        ros_args=("-r", "__node:=qos_talker_transient_local", "-p", "durability:=transient_local"),
    ),
    CatalogEntry(
        "qos_listener",
        "qos_listener",
        "/qos_listener",
        "Subscribes to /qos_chatter as reliable; logs incompatible-QoS events.",
    ),
    CatalogEntry(
        "qos_listener_best_effort",
        "qos_listener",
        "/qos_listener_best_effort",
        "The QoS listener as best-effort: compatible with every talker.",
        ros_args=("-r", "__node:=qos_listener_best_effort", "-p", "reliability:=best_effort"),
    ),
    CatalogEntry(
        "qos_listener_transient_local",
        "qos_listener",
        "/qos_listener_transient_local",
        "The QoS listener asking for transient-local history (late joiner).",
        ros_args=(
            "-r",
            "__node:=qos_listener_transient_local",
            "-p",
            "durability:=transient_local",
        ),
    ),
    CatalogEntry(
        "executor_demo",
        "executor_demo",
        "/executor_demo",
        "A slow callback starves a fast one under the single-threaded executor.",
    ),
    CatalogEntry(
        "executor_demo_multi",
        "executor_demo",
        "/executor_demo_multi",
        "The executor demo on a multi-threaded executor with callback groups: no starvation.",
        ros_args=("-r", "__node:=executor_demo_multi", "-p", "executor:=multi"),
    ),
    # --- perception and manipulation nodes (issue 5): add entries below this line ---
    CatalogEntry(
        "camera_publisher",
        "camera_publisher",
        "/camera_publisher",
        "A pretend camera: an object's position on /pos_in_cam_frame (camera frame).",
    ),
    CatalogEntry(
        "coordinate_transform",
        "coordinate_transform",
        "/coordinate_transform",
        "Camera frame to robot base frame with a configurable camera pose.",
    ),
    CatalogEntry(
        "robotic_arm",
        "robotic_arm",
        "/robotic_arm",
        "A 4-joint arm: inverse kinematics, /joint_states, /end_effector_pose, /arm_status.",
    ),
    CatalogEntry(
        "image_publisher",
        "image_publisher",
        "/image_publisher",
        "Camera images (bgr8) on /camera/image_raw: a synthetic scene with a moving red ball.",
    ),
    CatalogEntry(
        "object_detector",
        "object_detector",
        "/object_detector",
        "Finds the red ball with OpenCV; annotated image and its position in the camera frame.",
    ),
    CatalogEntry(
        "video_publisher",
        "video_publisher",
        "/video_publisher",
        "Frames on /cam/image_raw from a camera looping through a textured room.",
    ),
    CatalogEntry(
        "slam_node",
        "slam_node",
        "/slam_node",
        "Monocular SLAM: map points, camera trajectory and tracked features.",
    ),
    # --- turtlesim (issue 15): `ros2 run turtlesim <name>` maps onto these names ---
    CatalogEntry(
        "turtlesim_node",
        "turtlesim_node",
        "/turtlesim",
        "The turtlesim of the ROS 2 tutorials: turtle1 in an 11 m world, pose at 62.5 Hz.",
        package="turtlesim",
    ),
    CatalogEntry(
        "turtle_teleop_key",
        "turtle_teleop_key",
        "/teleop_turtle",
        "Drives turtle1 with arrow keys; G B V C D E R T rotate, F cancels.",
        package="turtlesim",
    ),
    CatalogEntry(
        "turtle_mimic",
        "turtlesim_mimic",
        "/turtle_mimic",
        "Copies a turtle's velocities from input/pose onto output/cmd_vel (turtlesim's mimic).",
        package="turtlesim",
    ),
    # multisim.launch.py: turtlesim twice, in the namespaces /turtlesim1 and /turtlesim2.
    CatalogEntry(
        "multisim_turtlesim1",
        "turtlesim_node",
        "/turtlesim1/turtlesim",
        "The first turtlesim of multisim.launch.py, in the namespace /turtlesim1.",
        ros_args=("-r", "__ns:=/turtlesim1"),
        package="turtlesim",
    ),
    CatalogEntry(
        "multisim_turtlesim2",
        "turtlesim_node",
        "/turtlesim2/turtlesim",
        "The second turtlesim of multisim.launch.py, in the namespace /turtlesim2.",
        ros_args=("-r", "__ns:=/turtlesim2"),
        package="turtlesim",
    ),
    CatalogEntry(
        "turtle_mimic_multisim",
        "turtlesim_mimic",
        "/turtle_mimic",
        "mimic wired between the multisim turtlesims: turtlesim2's turtle copies turtlesim1's.",
        ros_args=(
            "-r",
            "input/pose:=turtlesim1/turtle1/pose",
            "-r",
            "output/cmd_vel:=turtlesim2/turtle1/cmd_vel",
        ),
        package="turtlesim",
    ),
    # --- the MuJoCo world (issue 26): `ros2 run sim_world sim_world` ---
    CatalogEntry(
        "sim_world",
        "sim_world",
        "/sim_world",
        "A MuJoCo room: a diff-drive robot (/cmd_vel, /odom, /scan, camera, IMU) and an arm.",
        package="sim_world",
    ),
    CatalogEntry(
        "sim_robot_state_publisher",
        "model_state_publisher",
        "/robot_state_publisher",
        "robot_state_publisher with the sim robot's URDF: /robot_description, its frames on /tf.",
        args=("nodes/robots/diffbot/robot.urdf",),
        package="sim_world",
    ),
    # Two robots, two descriptions: the arm's robot_state_publisher lives in the /arm
    # namespace (/arm/robot_description), as multi-robot launch files do; both read the
    # one /joint_states the simulator publishes and ignore the other robot's joints.
    CatalogEntry(
        "sim_arm_state_publisher",
        "model_state_publisher",
        "/arm/robot_state_publisher",
        "robot_state_publisher for the sim's arm, in /arm: /arm/robot_description, links on /tf.",
        args=("nodes/robots/arm/robot.urdf",),
        ros_args=("-r", "__ns:=/arm", "-r", "joint_states:=/joint_states"),
        package="sim_world",
    ),
    CatalogEntry(
        "sim_teleop_key",
        "turtle_teleop_key",
        "/sim_teleop_key",
        "The arrow-key teleop, remapped to drive the sim_world robot on /cmd_vel.",
        ros_args=(
            "-r",
            "__node:=sim_teleop_key",
            "-r",
            "turtle1/cmd_vel:=/cmd_vel",
            "-p",
            "scale_linear:=0.3",
            "-p",
            "scale_angular:=1.5",
        ),
        package="turtlesim",  # upstream's teleop drives any robot: remap its topic
    ),
    # --- tf2 (issue 23): tf2_ros/tf2_tools programs and the turtle_tf2_py tutorial nodes ---
    CatalogEntry(
        "tf2_echo",
        "tf2_echo",
        "/tf2_echo",
        "Prints the transform between two frames once a second (tf2_echo SOURCE TARGET).",
        package="tf2_ros",
    ),
    CatalogEntry(
        "static_transform_publisher",
        "static_transform_publisher",
        "/static_transform_publisher",  # upstream adds 16 random characters to the name
        "Publishes one static transform on /tf_static from its command line.",
        package="tf2_ros",
    ),
    CatalogEntry(
        "tf2_monitor",
        "tf2_monitor",
        "/tf2_monitor_main",
        "Every 10 s: the delay of /tf data per frame and per broadcaster (optional: two frames).",
        package="tf2_ros",
    ),
    CatalogEntry(
        "view_frames",
        "view_frames",
        "/view_frames",
        "Listens to /tf for 5 s, then writes the frame tree as frames_<date>.gv and a picture.",
        package="tf2_tools",
    ),
    CatalogEntry(
        "static_turtle_tf2_broadcaster",
        "static_turtle_tf2_broadcaster",
        "/static_turtle_tf2_broadcaster",
        "world -> CHILD once on /tf_static (args: child x y z roll pitch yaw).",
        package="turtle_tf2_py",
    ),
    CatalogEntry(
        "turtle_tf2_broadcaster",
        "turtle_tf2_broadcaster",
        "/turtle_tf2_frame_publisher",
        "Broadcasts world -> <turtlename> on /tf from /<turtlename>/pose.",
        package="turtle_tf2_py",
    ),
    CatalogEntry(
        "turtle_tf2_listener",
        "turtle_tf2_listener",
        "/turtle_tf2_frame_listener",
        "Spawns turtle2 and drives it towards target_frame (turtle1) with tf2 lookups.",
        package="turtle_tf2_py",
    ),
    CatalogEntry(
        "fixed_frame_tf2_broadcaster",
        "fixed_frame_tf2_broadcaster",
        "/fixed_frame_tf2_broadcaster",
        "Broadcasts carrot1, 2 m to turtle1's left, at 10 Hz.",
        package="turtle_tf2_py",
    ),
    CatalogEntry(
        "dynamic_frame_tf2_broadcaster",
        "dynamic_frame_tf2_broadcaster",
        "/dynamic_frame_tf2_broadcaster",
        "Broadcasts carrot1 circling turtle1 at 10 m, at 10 Hz.",
        package="turtle_tf2_py",
    ),
    # The tf2 time tutorials' listeners (nodes/turtle_tf2_listener_time.py), named /listener
    # as the demo's, so they stand in for it.
    CatalogEntry(
        "turtle_tf2_listener_now",
        "turtle_tf2_listener_time",
        "/listener",
        "Using time: looks up turtle1 at now() without waiting; tf2 says the data is too old.",
        args=("now",),
        ros_args=("-r", "__node:=listener"),
        package="learning_tf2_py",
    ),
    CatalogEntry(
        "turtle_tf2_listener_wait",
        "turtle_tf2_listener_time",
        "/listener",
        "Using time: looks up turtle1 at now() and waits up to 50 ms: turtle2 follows.",
        args=("wait",),
        ros_args=("-r", "__node:=listener"),
        package="learning_tf2_py",
    ),
    CatalogEntry(
        "turtle_tf2_listener_past",
        "turtle_tf2_listener_time",
        "/listener",
        "Traveling in time: lookup_transform 5 s ago, both frames in the past: turtle2 wanders.",
        args=("past",),
        ros_args=("-r", "__node:=listener", "-p", "target_frame:=carrot1"),
        package="learning_tf2_py",
    ),
    CatalogEntry(
        "turtle_tf2_listener_full",
        "turtle_tf2_listener_time",
        "/listener",
        "Traveling in time: lookup_transform_full, carrot1 5 s ago seen from turtle2 now.",
        args=("full",),
        ros_args=("-r", "__node:=listener", "-p", "target_frame:=carrot1"),
        package="learning_tf2_py",
    ),
    # turtle_tf2_demo.launch.py: turtlesim as /sim, a broadcaster per turtle, the listener.
    CatalogEntry(
        "tf2_demo_sim",
        "turtlesim_node",
        "/sim",
        "turtlesim of the tf2 demo launch, named sim.",
        ros_args=("-r", "__node:=sim"),
        package="turtle_tf2_py",
    ),
    CatalogEntry(
        "tf2_demo_broadcaster1",
        "turtle_tf2_broadcaster",
        "/broadcaster1",
        "The tf2 demo's broadcaster for turtle1.",
        ros_args=("-r", "__node:=broadcaster1", "-p", "turtlename:=turtle1"),
        package="turtle_tf2_py",
    ),
    CatalogEntry(
        "tf2_demo_broadcaster2",
        "turtle_tf2_broadcaster",
        "/broadcaster2",
        "The tf2 demo's broadcaster for turtle2.",
        ros_args=("-r", "__node:=broadcaster2", "-p", "turtlename:=turtle2"),
        package="turtle_tf2_py",
    ),
    CatalogEntry(
        "tf2_demo_listener",
        "turtle_tf2_listener",
        "/listener",
        "The tf2 demo's listener: turtle2 follows turtle1.",
        ros_args=("-r", "__node:=listener", "-p", "target_frame:=turtle1"),
        package="turtle_tf2_py",
    ),
    CatalogEntry(
        "tf2_demo_listener_carrot",
        "turtle_tf2_listener",
        "/listener",
        "The tf2 demo's listener with target_frame carrot1: turtle2 follows the carrot.",
        ros_args=("-r", "__node:=listener", "-p", "target_frame:=carrot1"),
        package="turtle_tf2_py",
    ),
    CatalogEntry(
        "tf2_demo_fixed_broadcaster",
        "fixed_frame_tf2_broadcaster",
        "/fixed_broadcaster",
        "The fixed-frame demo's carrot1 broadcaster.",
        ros_args=("-r", "__node:=fixed_broadcaster"),
        package="turtle_tf2_py",
    ),
    CatalogEntry(
        "tf2_demo_dynamic_broadcaster",
        "dynamic_frame_tf2_broadcaster",
        "/dynamic_broadcaster",
        "The dynamic-frame demo's carrot1 broadcaster.",
        ros_args=("-r", "__node:=dynamic_broadcaster"),
        package="turtle_tf2_py",
    ),
    # --- URDF (issue 23): robot_state_publisher, joint_state_publisher, the arm's TF ---
    CatalogEntry(
        "robot_state_publisher",
        "robot_state_publisher",
        "/robot_state_publisher",
        "URDF + /joint_states -> /tf, /tf_static, /robot_description (needs robot_description).",
        package="robot_state_publisher",
    ),
    CatalogEntry(
        "joint_state_publisher",
        "joint_state_publisher",
        "/joint_state_publisher",
        "Publishes /joint_states for every movable joint of /robot_description.",
        package="joint_state_publisher",
    ),
    CatalogEntry(
        "joint_state_publisher_gui",
        "joint_state_publisher",
        "/joint_state_publisher",
        "joint_state_publisher driven by the sliders in the 3D view (/joint_state_sliders).",
        ros_args=("-p", "source_list:=['/joint_state_sliders']"),
        package="joint_state_publisher_gui",
    ),
    CatalogEntry(
        "arm_state_publisher",
        "model_state_publisher",
        "/robot_state_publisher",
        "robot_state_publisher with robotic_arm's URDF: the arm's joints become /tf.",
    ),
    CatalogEntry(
        "urdf_tutorial_rsp",
        "model_state_publisher",
        "/robot_state_publisher",
        "robot_state_publisher with the URDF tutorial's movable robot (06-flexible.urdf).",
        args=("ros_python/src/urdf_tutorial/urdf/06-flexible.urdf",),
        package="urdf_tutorial",
    ),
    CatalogEntry(
        "r2d2_state_publisher",
        "r2d2_state_publisher",
        "/state_publisher",
        "The URDF tutorial's R2-D2 on a circle: its joints on /joint_states, odom -> axis on /tf.",
        package="urdf_tutorial_r2d2",
    ),
    # The unit-13 cell the ROS 2 way: the camera's pose on /tf_static, the point through tf2.
    CatalogEntry(
        "camera_static_tf",
        "static_transform_publisher",
        "/camera_static_tf",
        "The camera's pose on /tf_static: base_link -> camera, 0.25 m ahead, 0.7 m up, lens down.",
        args=(
            "--x",
            "0.25",
            "--y",
            "0",
            "--z",
            "0.7",
            "--yaw",
            "0",
            "--pitch",
            "0",
            "--roll",
            "3.1415927",
            "--frame-id",
            "base_link",
            "--child-frame-id",
            "camera",
        ),
        ros_args=("-r", "__node:=camera_static_tf"),
        package="tf2_ros",
    ),
    CatalogEntry(
        "coordinate_transform_tf2",
        "coordinate_transform_tf2",
        "/coordinate_transform_tf2",
        "coordinate_transform done with tf2: the camera point into base_link by a tf2 lookup.",
    ),
    CatalogEntry(
        "coordinate_transform_tf2_side",
        "coordinate_transform_tf2",
        "/coordinate_transform_tf2",
        "The tf2 coordinate transform beside the matrix one, on /pos_in_robot_base_frame_tf2.",
        ros_args=("-r", "pos_in_robot_base_frame:=pos_in_robot_base_frame_tf2"),
    ),
    CatalogEntry(
        "r2d2_rsp",
        "model_state_publisher",
        "/robot_state_publisher",
        "robot_state_publisher with the tutorial's r2d2.urdf.xml.",
        args=("ros_python/src/urdf_tutorial_r2d2/urdf/r2d2.urdf.xml",),
        package="urdf_tutorial_r2d2",
    ),
    # --- maps and navigation (issue 40): the office world, mapping, Nav2's map files ---
    CatalogEntry(
        "sim_office",
        "sim_world",
        "/sim_world",
        "The MuJoCo office (10 m x 8 m: a corridor, four rooms, furniture) with the diffbot.",
        ros_args=("-p", "world:=office"),
        package="sim_world",
    ),
    CatalogEntry(
        "sim_office_mapping",
        "sim_world",
        "/sim_world",
        "The office world for mapping: no world -> odom on /tf (the mapper's map -> odom).",
        ros_args=("-p", "world:=office", "-p", "publish_world_tf:=false"),
        package="sim_world",
    ),
    CatalogEntry(
        "office_tour",
        "office_tour",
        "/office_tour",
        "Drives the diffbot through every room of the office (19 waypoints) on ground truth.",
        package="sim_world",
    ),
    CatalogEntry(
        "grid_mapper",
        "grid_mapper",
        "/grid_mapper",
        "Log-odds occupancy grid from /scan: /map (5 cm cells, latched), map -> odom on /tf.",
    ),
    CatalogEntry(
        "map_server",
        "map_server",
        "/map_server",
        "Nav2's map_server (lifecycle): loads yaml_filename, /map on activate, load_map service.",
        package="nav2_map_server",
    ),
    CatalogEntry(
        "map_server_office",
        "map_server",
        "/map_server",
        "Nav2's map_server with the office's map (nodes/worlds/office/map.yaml), for navigation.",
        ros_args=("-p", "yaml_filename:=nodes/worlds/office/map.yaml"),
        package="nav2_map_server",
    ),
    # --- localization and navigation (issue 40): Nav2's servers, our Python versions ---
    CatalogEntry(
        "office_map_world",
        "static_transform_publisher",
        "/office_map_world",
        "map -> world, the identity, on /tf_static: the office's map was drawn in the "
        "simulator's world frame, so its walls and the robot on the map line up.",
        args=("--frame-id", "map", "--child-frame-id", "world"),
        ros_args=("-r", "__node:=office_map_world"),
        package="tf2_ros",
    ),
    CatalogEntry(
        "amcl",
        "amcl",
        "/amcl",
        "Nav2's amcl (lifecycle): particle filter on /map from /scan and odom; /amcl_pose, "
        "/particle_cloud, map -> odom; /initialpose or reinitialize_global_localization.",
        package="nav2_amcl",
    ),
    CatalogEntry(
        "amcl_office",
        "amcl",
        "/amcl",
        "Nav2's amcl with nav2_bringup's params file: told where the office robot starts "
        "(set_initial_pose at 0, 0, facing east).",
        ros_args=("--params-file", NAV2_PARAMS),
        package="nav2_amcl",
    ),
    CatalogEntry(
        "planner_server",
        "planner_server",
        "/planner_server",
        "Nav2's planner server (lifecycle): /global_costmap/costmap from /map, "
        "compute_path_to_pose (GridBased), /plan.",
        package="nav2_planner",
    ),
    CatalogEntry(
        "controller_server",
        "controller_server",
        "/controller_server",
        "Nav2's controller server (lifecycle): follow_path, regulated pure pursuit on /cmd_vel.",
        package="nav2_controller",
    ),
    CatalogEntry(
        "bt_navigator",
        "bt_navigator",
        "/bt_navigator",
        "Nav2's navigator (lifecycle): navigate_to_pose and navigate_through_poses "
        "(plan, follow, replan once a second).",
        package="nav2_bt_navigator",
    ),
    CatalogEntry(
        "waypoint_follower",
        "waypoint_follower",
        "/waypoint_follower",
        "Nav2's waypoint follower (lifecycle): follow_waypoints sends each pose to "
        "navigate_to_pose in turn (stop_on_failure, wait_at_waypoint).",
        package="nav2_waypoint_follower",
    ),
    CatalogEntry(
        "lifecycle_manager",
        "lifecycle_manager",
        "/lifecycle_manager",
        "Nav2's lifecycle manager as `ros2 run` starts it: give it node_names (and autostart) "
        "to configure and activate those servers in order.",
        package="nav2_lifecycle_manager",
    ),
    CatalogEntry(
        "lifecycle_manager_navigation",
        "lifecycle_manager",
        "/lifecycle_manager_navigation",
        "Nav2's lifecycle manager: configures and activates the map server, amcl and the "
        "navigation servers in order (autostart).",
        ros_args=(
            "-r",
            "__node:=lifecycle_manager_navigation",
            "-p",
            "autostart:=true",
            "-p",
            "node_names:=[map_server,amcl,planner_server,controller_server,bt_navigator,"
            "waypoint_follower]",
        ),
        package="nav2_lifecycle_manager",
    ),
    CatalogEntry(
        "go_to_pose",
        "go_to_pose",
        "/basic_navigator",
        "Nav2's Python API (nav2_simple_commander's BasicNavigator): go to X Y on the map.",
        args=("0", "0"),
    ),
    CatalogEntry(
        "map_saver_cli",
        "map_saver_cli",
        "/map_saver",
        "Nav2's map_saver_cli: saves /map as PATH.pgm + PATH.yaml (-f PATH) and exits.",
        package="nav2_map_server",
    ),
)

GROUPS: tuple[LaunchGroup, ...] = (
    LaunchGroup(
        "chatter_demo",
        "talker + listener + listener2 on /chatter",
        ("talker", "listener", "listener2"),
    ),
    # --- core tutorial groups (issue 3): add groups below this line ---
    LaunchGroup(
        "minimal_nodes",
        "the OOP and the procedural minimal node side by side",
        ("minimal_node", "minimal_node_procedural"),
    ),
    LaunchGroup(
        "add_two_ints",
        "the /add_two_ints server and a client that asks for 2 + 3",
        ("add_two_ints_server", "add_two_ints_client"),
    ),
    LaunchGroup(
        "fibonacci",
        "the /fibonacci action server and a client sending order 10",
        ("fibonacci_action_server", "fibonacci_action_client"),
    ),
    LaunchGroup(
        "qos_mismatch",
        "a best-effort talker and a reliable listener: incompatible QoS, reported",
        ("qos_talker_best_effort", "qos_listener"),
    ),
    LaunchGroup(
        "qos_compatible",
        "a reliable talker and a best-effort listener: compatible, messages flow",
        ("qos_talker", "qos_listener_best_effort"),
    ),
    LaunchGroup(
        "executor_comparison",
        "the executor demo on a single- and a multi-threaded executor, side by side",
        ("executor_demo", "executor_demo_multi"),
    ),
    # --- perception groups (issue 5): add groups below this line ---
    LaunchGroup(
        "camera_to_arm",
        "camera_publisher + coordinate_transform + robotic_arm: pick and place",
        ("camera_publisher", "coordinate_transform", "robotic_arm"),
    ),
    LaunchGroup(
        "image_pipeline",
        "image_publisher + object_detector: find a ball in camera images",
        ("image_publisher", "object_detector"),
    ),
    LaunchGroup(
        "slam",
        "video_publisher + slam_node: monocular SLAM on a synthetic room",
        ("video_publisher", "slam_node"),
    ),
    # --- turtlesim groups (issue 15) ---
    LaunchGroup(
        "multisim",
        "two turtlesims in the namespaces /turtlesim1 and /turtlesim2 (multisim.launch.py)",
        ("multisim_turtlesim1", "multisim_turtlesim2"),
    ),
    # --- the MuJoCo world (issue 26) ---
    LaunchGroup(
        "sim_drive",
        "the MuJoCo room, its robots' state publishers and the arrow-key teleop: drive the robot",
        ("sim_world", "sim_robot_state_publisher", "sim_arm_state_publisher", "sim_teleop_key"),
    ),
    # --- tf2 (issue 23): the turtle_tf2_py demo launch files ---
    LaunchGroup(
        "turtle_tf2_demo",
        "turtlesim, a tf2 broadcaster per turtle, and a listener: turtle2 follows turtle1",
        ("tf2_demo_sim", "tf2_demo_broadcaster1", "tf2_demo_broadcaster2", "tf2_demo_listener"),
    ),
    LaunchGroup(
        "turtle_tf2_fixed_frame_demo",
        "the tf2 demo with a fixed carrot1 frame beside turtle1: turtle2 follows the carrot",
        (
            "tf2_demo_sim",
            "tf2_demo_broadcaster1",
            "tf2_demo_broadcaster2",
            "tf2_demo_listener_carrot",
            "tf2_demo_fixed_broadcaster",
        ),
    ),
    LaunchGroup(
        "turtle_tf2_dynamic_frame_demo",
        "the tf2 demo with carrot1 circling turtle1: turtle2 chases the moving carrot",
        (
            "tf2_demo_sim",
            "tf2_demo_broadcaster1",
            "tf2_demo_broadcaster2",
            "tf2_demo_listener_carrot",
            "tf2_demo_dynamic_broadcaster",
        ),
    ),
    # --- URDF (issue 23) ---
    LaunchGroup(
        "arm_tf",
        "robotic_arm + robot_state_publisher with its URDF: the arm on /tf",
        ("robotic_arm", "arm_state_publisher"),
    ),
    LaunchGroup(
        "camera_to_arm_tf2",
        "the camera -> arm cell the ROS 2 way: static camera pose, tf2 lookup, URDF arm on /tf",
        (
            "camera_publisher",
            "camera_static_tf",
            "coordinate_transform_tf2",
            "robotic_arm",
            "arm_state_publisher",
        ),
    ),
    LaunchGroup(
        "urdf_tutorial_display",
        "the URDF tutorial's display.launch.py: its robot, robot_state_publisher, joint sliders",
        ("urdf_tutorial_rsp", "joint_state_publisher_gui"),
    ),
    LaunchGroup(
        "urdf_tutorial_r2d2_demo",
        "demo.launch.py of urdf_tutorial_r2d2: robot_state_publisher + state_publisher",
        ("r2d2_rsp", "r2d2_state_publisher"),
    ),
    # --- maps and navigation (issue 40) ---
    LaunchGroup(
        "office_mapping",
        "the office world, the robot's state publisher, the grid mapper and the teleop: map it",
        ("sim_office_mapping", "sim_robot_state_publisher", "grid_mapper", "sim_teleop_key"),
    ),
    LaunchGroup(
        "office_navigation",
        "the office world, its map, amcl and Nav2's planner, controller and navigator, "
        "brought up by the lifecycle manager: send a navigation goal",
        (
            "sim_office_mapping",
            "sim_robot_state_publisher",
            "office_map_world",
            "map_server_office",
            "amcl_office",
            "planner_server",
            "controller_server",
            "bt_navigator",
            "waypoint_follower",
            "lifecycle_manager_navigation",
        ),
    ),
)

_BY_NAME = {entry.name: entry for entry in ENTRIES}
_GROUPS_BY_NAME = {group.name: group for group in GROUPS}


class UnknownNodeError(LookupError):
    """Raised for a name that is not in the catalog."""


def lookup(name: str) -> CatalogEntry:
    try:
        return _BY_NAME[name]
    except (KeyError, TypeError):
        known = ", ".join(sorted(_BY_NAME))
        raise UnknownNodeError(f"no catalog node named {name!r}; known nodes: {known}") from None


def lookup_group(name: str) -> LaunchGroup:
    try:
        return _GROUPS_BY_NAME[name]
    except (KeyError, TypeError):
        known = ", ".join(sorted(_GROUPS_BY_NAME))
        raise UnknownNodeError(f"no launch group named {name!r}; known groups: {known}") from None


def names() -> list[str]:
    return [entry.name for entry in ENTRIES]
