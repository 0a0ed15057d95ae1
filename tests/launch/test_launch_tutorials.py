# ruff: noqa: E501  (the launch files below are written as the tutorials write them)
"""The Jazzy launch tutorials' files, run by ``ros2 launch`` on real turtlesims over DDS.

"Creating a launch file" (two turtlesims and mimic), "Using substitutions"
(arguments, an include with arguments, a substitution in a parameter) and
"Using event handlers" (OnProcessStart/IO/Exit, OnExecutionComplete,
OnShutdown). The tutorials call ``ros2 service call``; ros2cli is not
installed here, so that step is a small rclpy client in the same place.
The turtlesim executables are the classroom's, installed into an ament
prefix the test builds; this process observes with plain rclpy.
"""

from __future__ import annotations

import os
import re
import signal
import time
from pathlib import Path

import pytest

from tests.launch.helpers import (
    Launch,
    ament_prefix,
    group_members,
    launch_env,
    python_child,
    started_pids,
)

pytestmark = pytest.mark.ros

DISCOVERY_SEC = 30.0  # generous: a loaded 2-core machine starts rclpy nodes slowly


def node_exec(module: str) -> str:
    """An installed executable that is the classroom's program ``nodes.<module>``."""
    return python_child(
        f"""
        import os, sys
        os.execv(sys.executable, [sys.executable, "-m", "nodes.{module}", *sys.argv[1:]])
        """
    )


SPAWN_CLIENT = python_child(
    """
    # What `ros2 service call /turtlesim2/spawn turtlesim/srv/Spawn "{x: 2, y: 2, theta: 0.2}"` does.
    import sys
    import rclpy
    from turtlesim.srv import Spawn

    rclpy.init()
    node = rclpy.create_node("spawn_client")
    client = node.create_client(Spawn, sys.argv[1])
    if not client.wait_for_service(timeout_sec=15.0):
        sys.exit("no spawn service")
    future = client.call_async(Spawn.Request(x=2.0, y=2.0, theta=0.2))
    rclpy.spin_until_future_complete(node, future, timeout_sec=15.0)
    print(f"response: name={future.result().name!r}", flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    """
)

MIMIC_LAUNCH = """
from launch import LaunchDescription
from launch_ros.actions import Node

def generate_launch_description():
    return LaunchDescription([
        Node(
            package='turtlesim',
            namespace='turtlesim1',
            executable='turtlesim_node',
            name='sim'
        ),
        Node(
            package='turtlesim',
            namespace='turtlesim2',
            executable='turtlesim_node',
            name='sim'
        ),
        Node(
            package='turtlesim',
            executable='mimic',
            name='mimic',
            remappings=[
                ('/input/pose', '/turtlesim1/turtle1/pose'),
                ('/output/cmd_vel', '/turtlesim2/turtle1/cmd_vel'),
            ]
        )
    ])
"""

SUBSTITUTIONS_LAUNCH = """
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration, PythonExpression
from launch.actions import LogInfo
from launch_ros.actions import Node


def generate_launch_description():
    turtlesim_ns = LaunchConfiguration('turtlesim_ns')
    use_provided_red = LaunchConfiguration('use_provided_red')
    new_background_r = LaunchConfiguration('new_background_r')

    turtlesim_ns_launch_arg = DeclareLaunchArgument('turtlesim_ns', default_value='turtlesim1')
    use_provided_red_launch_arg = DeclareLaunchArgument('use_provided_red', default_value='False')
    new_background_r_launch_arg = DeclareLaunchArgument('new_background_r', default_value='200')

    turtlesim_node = Node(
        package='turtlesim',
        namespace=turtlesim_ns,
        executable='turtlesim_node',
        name='sim',
        parameters=[{'background_r': new_background_r}],
    )
    red_note = LogInfo(
        msg=['background_r of ', turtlesim_ns, ' is ', new_background_r],
        condition=IfCondition(
            PythonExpression([new_background_r, ' == 200', ' and ', use_provided_red])
        ),
    )
    return LaunchDescription([
        turtlesim_ns_launch_arg,
        use_provided_red_launch_arg,
        new_background_r_launch_arg,
        turtlesim_node,
        red_note,
    ])
"""

MAIN_LAUNCH = """
from launch_ros.substitutions import FindPackageShare

from launch import LaunchDescription
from launch.actions import IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import PathJoinSubstitution, TextSubstitution


def generate_launch_description():
    colors = {
        'background_r': '200'
    }

    return LaunchDescription([
        IncludeLaunchDescription(
            PythonLaunchDescriptionSource([
                PathJoinSubstitution([
                    FindPackageShare('launch_tutorial'),
                    'launch',
                    'example_substitutions.launch.py'
                ])
            ]),
            launch_arguments={
                'turtlesim_ns': 'turtlesim2',
                'use_provided_red': 'True',
                'new_background_r': TextSubstitution(text=str(colors['background_r']))
            }.items()
        )
    ])
"""

EVENT_HANDLERS_LAUNCH = """
from launch import LaunchDescription
from launch.actions import (DeclareLaunchArgument, EmitEvent, ExecuteProcess,
                            LogInfo, RegisterEventHandler)
from launch.event_handlers import (OnExecutionComplete, OnProcessExit,
                                OnProcessIO, OnProcessStart, OnShutdown)
from launch.events import Shutdown
from launch.substitutions import (EnvironmentVariable, FindExecutable,
                                LaunchConfiguration, LocalSubstitution)
from launch_ros.actions import Node
from launch_ros.substitutions import ExecutableInPackage


def generate_launch_description():
    turtlesim_ns = LaunchConfiguration('turtlesim_ns')

    turtlesim_ns_launch_arg = DeclareLaunchArgument('turtlesim_ns', default_value='turtlesim1')

    turtlesim_node = Node(
        package='turtlesim',
        namespace=turtlesim_ns,
        executable='turtlesim_node',
        name='sim'
    )
    spawn_turtle = ExecuteProcess(
        cmd=[ExecutableInPackage('spawn_client', 'launch_tutorial'), [turtlesim_ns, '/spawn']],
        name='spawn_client',
    )

    return LaunchDescription([
        turtlesim_ns_launch_arg,
        turtlesim_node,
        RegisterEventHandler(
            OnProcessStart(
                target_action=turtlesim_node,
                on_start=[
                    LogInfo(msg='Turtlesim started, spawning turtle'),
                    spawn_turtle
                ]
            )
        ),
        RegisterEventHandler(
            OnProcessIO(
                target_action=spawn_turtle,
                on_stdout=lambda event: LogInfo(
                    msg='Spawn request says "{}"'.format(
                        event.text.decode().strip())
                )
            )
        ),
        RegisterEventHandler(
            OnExecutionComplete(
                target_action=spawn_turtle,
                on_completion=[
                    LogInfo(msg='Spawn finished'),
                ]
            )
        ),
        RegisterEventHandler(
            OnProcessExit(
                target_action=turtlesim_node,
                on_exit=[
                    LogInfo(msg=(EnvironmentVariable(name='USER'),
                            ' closed the turtlesim window')),
                    EmitEvent(event=Shutdown(
                        reason='Window closed'))
                ]
            )
        ),
        RegisterEventHandler(
            OnShutdown(
                on_shutdown=[LogInfo(
                    msg=['Launch was asked to shutdown: ',
                        LocalSubstitution('event.reason')]
                )]
            )
        ),
    ])
"""


@pytest.fixture
def tutorial(tmp_path: Path, ros_env):
    prefix = ament_prefix(
        tmp_path / "install",
        {
            "turtlesim": {"lib/turtlesim_node": node_exec("turtlesim_node"),
                          "lib/mimic": node_exec("turtlesim_mimic")},
            "launch_tutorial": {
                "lib/spawn_client": SPAWN_CLIENT,
                "launch/example_substitutions.launch.py": SUBSTITUTIONS_LAUNCH,
                "launch/example_main.launch.py": MAIN_LAUNCH,
                "launch/example_event_handlers.launch.py": EVENT_HANDLERS_LAUNCH,
            },
        },
    )  # fmt: skip
    env = launch_env(ros_env, prefix, tmp_path / "log")
    env["USER"] = "learner"
    launches: list[Launch] = []

    def start(args: list[str]) -> Launch:
        launch = Launch(args, env)
        launches.append(launch)
        return launch

    yield start, tmp_path
    for launch in launches:
        launch.kill()


@pytest.fixture
def graph(ros_env):
    """A plain rclpy node in this process, to look at the graph."""
    import rclpy

    context = rclpy.Context()
    rclpy.init(context=context)
    node = rclpy.create_node("launch_test_observer", context=context)
    yield node
    node.destroy_node()
    rclpy.try_shutdown(context=context)


def wait_for(predicate, what: str, timeout: float = DISCOVERY_SEC) -> None:  # type: ignore[no-untyped-def]
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.1)


def names(node) -> set[str]:  # type: ignore[no-untyped-def]
    return {f"{ns.rstrip('/')}/{name}" for name, ns in node.get_node_names_and_namespaces()}


def test_two_turtlesims_and_mimic_then_ctrl_c_ends_all(tutorial, graph):
    start, tmp_path = tutorial
    path = tmp_path / "turtlesim_mimic_launch.py"
    path.write_text(MIMIC_LAUNCH)
    launch = start([str(path)])
    launch.read_until(lambda lines: len(started_pids(lines)) == 3, DISCOVERY_SEC)
    wait_for(lambda: {"/turtlesim1/sim", "/turtlesim2/sim", "/mimic"} <= names(graph), "nodes")
    wait_for(lambda: graph.count_publishers("/turtlesim2/turtle1/cmd_vel") == 1, "mimic's pub")
    wait_for(lambda: graph.count_subscribers("/turtlesim1/turtle1/pose") == 1, "mimic's sub")
    pids = started_pids(launch.lines)
    assert set(pids) == {"turtlesim_node-1", "turtlesim_node-2", "mimic-3"}
    assert sorted(group_members(launch.pgid)) == sorted([launch.pgid, *pids.values()])
    lines = launch.read_until(
        lambda lines: sum("Spawning turtle [turtle1]" in line for line in lines) == 2, DISCOVERY_SEC
    )
    assert any(
        re.fullmatch(r"\[turtlesim_node-1\] \[INFO\] \[[\d.]+\] \[turtlesim1\.sim\]: Starting "
                     r"turtlesim with node name /turtlesim1/sim", line) for line in lines
    ), lines  # fmt: skip

    launch.ctrl_c()
    out = launch.finish(timeout=20)
    assert launch.proc.returncode == 0, out
    assert "[WARNING] [launch]: user interrupted with ctrl-c (SIGINT)" in out
    for label, pid in pids.items():
        assert f"[INFO] [{label}]: process has finished cleanly [pid {pid}]" in out, out
    assert group_members(launch.pgid) == []


def test_substitutions_include_with_arguments_and_a_parameter(tutorial, graph):
    import rclpy
    from rcl_interfaces.srv import GetParameters
    from rclpy.executors import SingleThreadedExecutor

    start, _ = tutorial
    launch = start(["launch_tutorial", "example_main.launch.py"])
    launch.read_until(
        lambda lines: any("background_r of " in line for line in lines), DISCOVERY_SEC
    )
    assert "[INFO] [launch.user]: background_r of turtlesim2 is 200" in launch.lines
    wait_for(lambda: "/turtlesim2/sim" in names(graph), "/turtlesim2/sim")
    client = graph.create_client(GetParameters, "/turtlesim2/sim/get_parameters")
    assert client.wait_for_service(timeout_sec=DISCOVERY_SEC)
    future = client.call_async(GetParameters.Request(names=["background_r"]))
    executor = SingleThreadedExecutor(context=graph.context)
    rclpy.spin_until_future_complete(graph, future, timeout_sec=10.0, executor=executor)
    executor.shutdown()
    assert future.result() is not None and future.result().values[0].integer_value == 200
    launch.ctrl_c()
    launch.finish()
    assert group_members(launch.pgid) == []


def test_event_handlers(tutorial, graph):
    start, _ = tutorial
    launch = start(
        ["launch_tutorial", "example_event_handlers.launch.py", "turtlesim_ns:=turtlesim3"]
    )
    lines = launch.read_until(
        lambda lines: any("Spawn finished" in line for line in lines), DISCOVERY_SEC
    )
    user = [line.split("]: ", 1)[1] for line in lines if line.startswith("[INFO] [launch.user]")]
    assert user == [
        "Turtlesim started, spawning turtle",
        "Spawn request says \"response: name='turtle2'\"",
        "Spawn finished",
    ], lines
    assert "[spawn_client-2] response: name='turtle2'" not in lines  # output='log': not shown
    # Closing the window (the turtlesim ends): the exit handler shuts the launch down.
    os.kill(started_pids(lines)["turtlesim_node-1"], signal.SIGINT)
    out = launch.finish(timeout=20)
    assert launch.proc.returncode == 0, out
    tail = [line.split("]: ", 1)[1] for line in out if line.startswith("[INFO] [launch.user]")]
    assert tail[-2:] == [
        "learner closed the turtlesim window",
        "Launch was asked to shutdown: Window closed",
    ], out
    assert group_members(launch.pgid) == []
