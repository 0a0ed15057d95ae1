"""`ros2 launch my_package my_launch.py` in the Console for a learner's own (installed) package.

The package is an install space as colcon leaves it (index marker, the
launch file under share/, the node's executable under lib/); the learner
"sourced" it, so its prefix comes first on AMENT_PREFIX_PATH. Its launch
file is learner code: it runs only under the dashboard's rule for learner
code (supervisor.learner_policy), here the loopback rule (runs as the user).
"""

from __future__ import annotations

import os
import re
import textwrap

import pytest

from app.containment.policy import RunPolicy
from tests.launch.helpers import ament_prefix, group_members, python_child
from tests.turtlesim.test_ros2_run import console  # noqa: F401  (the Console fixture)

pytestmark = pytest.mark.ros

LAUNCH = textwrap.dedent(
    """
    from launch import LaunchDescription
    from launch.actions import DeclareLaunchArgument
    from launch.substitutions import LaunchConfiguration
    from launch_ros.actions import Node


    def generate_launch_description():
        return LaunchDescription([
            DeclareLaunchArgument('greeting', default_value='hello'),
            Node(package='my_package', executable='my_node', name='my_node',
                 arguments=[LaunchConfiguration('greeting')], output='screen'),
            Node(package='demo_nodes_py', executable='talker', output='screen'),
        ])
    """
)
MY_NODE = python_child(
    """
    import sys, time
    print("my_node says", sys.argv[1], flush=True)
    while True:
        time.sleep(0.1)
    """
)


@pytest.fixture
def sourced(tmp_path, monkeypatch):
    install = ament_prefix(
        tmp_path / "ros2_ws/install/my_package",
        {"my_package": {"lib/my_node": MY_NODE, "launch/my_launch.py": LAUNCH}},
    )
    from app.ros2cli.tutorial_prefix import tutorial_prefix  # demo_nodes_py's talker

    monkeypatch.setenv("AMENT_PREFIX_PATH", f"{install}{os.pathsep}{tutorial_prefix()}")
    return install


def test_a_learners_launch_file_runs_under_the_learner_code_rule(console, supervisor, sourced):  # noqa: F811
    code, out = console("ros2 launch my_package my_launch.py")
    assert code == 1 and "no rule for learner code was given here" in out[-1], out
    supervisor.learner_policy = RunPolicy(allowed=False, contained=True)
    code, out = console("ros2 launch my_package my_launch.py")
    assert code == 1 and "--allow-learner-code" in out[-1], out
    assert not supervisor.statuses()

    supervisor.learner_policy = RunPolicy()  # the dashboard on loopback: the learner's own machine
    code, out = console("ros2 launch my_package my_launch.py greeting:=ahoy")
    assert code == 0, out
    assert "[my_node-1] my_node says ahoy" in out, out
    assert out[-1] == (
        "(the launch keeps running: stop it with `ros2 launch --stop my_package my_launch.py`)"
    )
    pids = [
        int(m[1]) for line in out if (m := re.search(r"process started with pid \[(\d+)\]", line))
    ]
    key = "launch:my_package/my_launch.py"
    launcher = supervisor.status(key).pid
    assert len(pids) == 2 and {os.getpgid(pid) for pid in pids} == {launcher}
    code, out = console("ros2 launch --stop my_package my_launch.py")
    assert code == 0 and out[0] == "[WARNING] [launch]: user interrupted with ctrl-c (SIGINT)", out
    assert group_members(launcher) == []
