"""`ros2 launch turtlesim multisim.launch.py` and turtlesim's `mimic`, through the Console.

The commands are the "Launching nodes" tutorial's, typed verbatim, plus the
mimic line of the launch-file tutorial: turtlesim2's turtle must copy what
turtlesim1's turtle does, on real processes.
"""

from __future__ import annotations

import math
import os
import re

import pytest
import yaml

from app.ros.context import CONSOLE_LIMITS, CallContext
from app.ros2cli import run_text
from tests.conftest import wait_until
from tests.integration.core_helpers import DISCOVERY_TIMEOUT, node_names
from tests.turtlesim.test_ros2_run import console  # noqa: F401  (the Console fixture)

pytestmark = pytest.mark.ros

CENTRE = 5.544445


def ok(console, text: str) -> list[str]:  # noqa: F811
    code, out = console(text)
    assert code == 0, (text, out)
    return out


def pose_of(console, topic: str) -> dict:  # noqa: F811
    out = ok(console, f"ros2 topic echo --once {topic}")
    return yaml.safe_load("\n".join(out[: out.index("---")]))


def test_multisim_runs_two_turtlesims_and_mimic_couples_them(console, probe, supervisor):  # noqa: F811
    out = ok(console, "ros2 launch turtlesim multisim.launch.py")
    assert out[0].startswith("[INFO] [launch]: All log files can be found below "), out
    assert out[1] == "[INFO] [launch]: Default logging verbosity is set to INFO", out
    assert out[2].startswith("[INFO] [turtlesim_node-1]: process started with pid ["), out
    assert out[3].startswith("[INFO] [turtlesim_node-2]: process started with pid ["), out
    # One supervised program: ros2launch, whose children the two turtlesims are.
    assert list(supervisor.statuses()) == ["launch:turtlesim/multisim.launch.py"]
    for label, ns in (("turtlesim_node-1", "turtlesim1"), ("turtlesim_node-2", "turtlesim2")):
        assert any(
            line.startswith(f"[{label}] ")
            and line.endswith(f"Starting turtlesim with node name /{ns}/turtlesim")
            for line in out
        ), out
    wait_until(
        lambda: {"/turtlesim1/turtlesim", "/turtlesim2/turtlesim"} <= set(node_names(probe)),
        timeout=DISCOVERY_TIMEOUT,
        what="both turtlesims",
    )
    # A node is on the graph before its subscriptions and publishers are: as in a
    # terminal, `ros2 topic list` shows them all once discovery has caught up.
    wanted = {"/turtlesim1/turtle1/cmd_vel", "/turtlesim2/turtle1/pose"}
    listed: list[str] = []

    def all_listed() -> bool:
        listed[:] = ok(console, "ros2 topic list")
        return wanted <= set(listed)

    wait_until(
        all_listed,
        timeout=DISCOVERY_TIMEOUT,
        what=lambda: f"{sorted(wanted)} in `ros2 topic list`: {listed}",
    )
    # The same file twice would give the graph two nodes of one name: refused.
    code, out = console("ros2 launch turtlesim multisim.launch.py")
    assert code == 1 and out[-1].startswith("error: turtlesim multisim.launch.py is already"), out

    out = ok(
        console,
        "ros2 run turtlesim mimic --ros-args --remap input/pose:=turtlesim1/turtle1/pose "
        "--remap output/cmd_vel:=turtlesim2/turtle1/cmd_vel",
    )
    assert out[-1].startswith("(/turtle_mimic keeps running"), out
    wait_until(
        lambda: probe.node.count_publishers("/turtlesim2/turtle1/cmd_vel") == 1,
        timeout=DISCOVERY_TIMEOUT,
        what="mimic publishing on turtlesim2's cmd_vel",
    )
    out = ok(console, "ros2 node info /turtle_mimic")
    assert "    /turtlesim1/turtle1/pose: turtlesim/msg/Pose" in out, out
    assert "    /turtlesim2/turtle1/cmd_vel: geometry_msgs/msg/Twist" in out, out

    # Drive turtlesim1 only; turtlesim2's turtle follows the same circle.
    ok(
        console,
        "ros2 topic pub  /turtlesim1/turtle1/cmd_vel geometry_msgs/msg/Twist "
        '"{linear: {x: 2.0, y: 0.0, z: 0.0}, angular: {x: 0.0, y: 0.0, z: 1.8}}"',
    )

    # Compared once both stand still: 1 s after the pub ends turtlesim stops the leader,
    # and mimic passes its zero speed on. Two reads a moment apart while they drive at
    # 2 m/s differed by over half a metre on a loaded machine.
    def both_still() -> tuple[dict, dict] | None:
        poses = (
            pose_of(console, "/turtlesim1/turtle1/pose"),
            pose_of(console, "/turtlesim2/turtle1/pose"),
        )
        return poses if all(pose["linear_velocity"] == 0.0 for pose in poses) else None

    leader, follower = wait_until(both_still, timeout=30, interval=0.5, what="both turtles still")
    for pose in (leader, follower):
        assert math.dist((pose["x"], pose["y"]), (CENTRE, CENTRE)) > 0.5, (leader, follower)
    # Same commands from the same start: the two turtles stay close together.
    assert math.dist((leader["x"], leader["y"]), (follower["x"], follower["y"])) < 0.5

    out = ok(console, "ros2 launch --stop turtlesim multisim.launch.py")  # (ours) Ctrl+C
    assert out[0] == "[WARNING] [launch]: user interrupted with ctrl-c (SIGINT)", out
    assert sorted(re.sub(r"\d+", "N", line) for line in out[1:]) == [
        "[INFO] [turtlesim_node-N]: process has finished cleanly [pid N]",
        "[INFO] [turtlesim_node-N]: process has finished cleanly [pid N]",
    ], out
    ok(console, "ros2 run --stop /turtle_mimic")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("ros2 launch turtlesim nope.launch.py", "'nope.launch.py' was not found"),
        ("ros2 launch no_pkg x.launch.py", "Package 'no_pkg' not found"),
        ("ros2 launch turtlesim multisim.launch.py world", "malformed launch argument 'world'"),
        ("ros2 launch --stop turtlesim multisim.launch.py", "is not running here"),
        ("ros2 launch turtlesim", "the following arguments are required: launch_file"),
    ],
)
def test_bad_launch_commands_give_one_error_line(console, supervisor, text, message):  # noqa: F811
    code, out = console(text)
    assert code != 0
    # Our errors read 'error: ...'; argparse's, as ros2 prints them, 'ros2 launch: error: ...'.
    errors = [line for line in out if line.startswith(("error:", "ros2 launch: error:"))]
    assert len(errors) == 1 and message in errors[0], out
    assert not supervisor.statuses()  # nothing was started


def test_without_the_supervisor_the_verb_names_the_terminal_command(probe):
    lines: list[str] = []
    ctx = CallContext(probe.node, lines.append, CONSOLE_LIMITS)
    assert run_text(ctx, "ros2 launch turtlesim multisim.launch.py") == 1
    assert lines == [
        "error: `ros2 launch` starts nodes through the dashboard's supervisor, which this "
        "console was not given; in a terminal use "
        "`ros2-classroom launch turtlesim multisim.launch.py`"
    ]


def test_every_launch_group_is_a_tutorial_nodes_launch_file(console, supervisor):  # noqa: F811
    out = ok(console, "ros2 launch tutorial_nodes minimal_nodes.launch.py")
    assert out[2].startswith("[INFO] [minimal_node-1]: process started with pid ["), out
    assert out[3].startswith("[INFO] [minimal_node_procedural-2]: process started"), out
    pid = supervisor.status("launch:tutorial_nodes/minimal_nodes.launch.py").pid
    children = {int(line.rsplit("[", 1)[1].rstrip("]")) for line in out[2:4]}
    assert {os.getpgid(child) for child in children} == {pid}  # the launcher's group
    out = ok(console, "ros2 launch --stop tutorial_nodes minimal_nodes.launch.py")
    # The nodes' own lines ("[minimal_node-1] [INFO] ...") that came after the start
    # command stopped showing output are shown here: on busy cores some do. Launch's own:
    own = [line for line in out if not re.match(r"\[[\w.]+-\d+\] ", line)]
    assert len(own) == 3 and all("process has finished cleanly" in line for line in own[1:]), out
    for child in children:  # reaped: no orphan left
        with pytest.raises(ProcessLookupError):
            os.kill(child, 0)


def test_a_lesson_log_check_reads_a_node_inside_a_console_launch(console, supervisor):  # noqa: F811
    """The lesson's `ros2 launch tutorial_nodes chatter_demo.launch.py`, typed in the Console:
    one program for three nodes, yet the step's check on listener2's log still sees it."""
    from types import SimpleNamespace

    from app.lessons.checks.log_contains import evaluate
    from app.lessons.registry import FAIL, PASS
    from app.lessons.schema import Spec

    rt = SimpleNamespace(supervisor=supervisor)
    check = Spec("log_contains", {"catalog_node": "listener2", "text": "I heard", "at_least": 3})
    assert evaluate(rt, check).state == FAIL  # nothing runs yet
    ok(console, "ros2 launch tutorial_nodes chatter_demo.launch.py")
    wait_until(lambda: evaluate(rt, check).state == PASS, timeout=20, what="listener2 hearing")
    lines = supervisor.output("launch:tutorial_nodes/chatter_demo.launch.py")
    assert any(
        line.startswith("[listener-3] ") and "[listener2]: I heard" in line for line in lines
    )
    ok(console, "ros2 launch --stop tutorial_nodes chatter_demo.launch.py")
