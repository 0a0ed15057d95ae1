"""`ros2 run PKG EXE [--ros-args ...]` as the Console runs it: real processes, real remaps."""

from __future__ import annotations

import threading
from dataclasses import replace

import pytest

from app.ros.context import CONSOLE_LIMITS, CallContext
from app.ros2cli import run_text
from tests.conftest import wait_until
from tests.integration.core_helpers import DISCOVERY_TIMEOUT, node_names, wait_node_gone

pytestmark = pytest.mark.ros


@pytest.fixture
def console(probe, supervisor):
    """Runs console text like the Console tab, with the supervisor as ``ctx.programs``."""

    def run(text: str, until: threading.Event | None = None) -> tuple[int, list[str]]:
        """``until``: the command runs until it is set (a terminal's Ctrl+C), not the
        Console's 5 s, and ends as a stopped Console command does."""
        lines: list[str] = []
        limits = CONSOLE_LIMITS if until is None else replace(CONSOLE_LIMITS, max_seconds=None)
        ctx = CallContext(
            probe.node, lines.append, limits, until or threading.Event(), programs=supervisor
        )
        code = run_text(ctx, text)
        return code, "\n".join(lines).splitlines()

    return run


def publishers_of(probe, topic: str) -> set[str]:
    infos = probe.node.get_publishers_info_by_topic(topic)
    return {f"{i.node_namespace.rstrip('/')}/{i.node_name}" for i in infos}


def test_turtlesim_runs_renamed_remapped_and_with_parameters(console, probe, supervisor):
    code, out = console("ros2 run turtlesim turtlesim_node")
    assert code == 0, out
    assert any(line.endswith("Starting turtlesim with node name /turtlesim") for line in out), out
    assert any(
        line.endswith("Spawning turtle [turtle1] at x=[5.544445], y=[5.544445], theta=[0.000000]")
        for line in out
    ), out
    assert supervisor.status("turtlesim_node").active

    code, out = console("ros2 run turtlesim turtlesim_node")  # the same name twice
    assert code == 1 and out[-1].startswith("error: a node named /turtlesim is already running")

    code, out = console(
        "ros2 run turtlesim turtlesim_node --ros-args --remap __node:=my_turtle "
        "-p background_r:=150"
    )
    assert code == 0, out
    assert any("Starting turtlesim with node name /my_turtle" in line for line in out), out
    code, out = console("ros2 param get /my_turtle background_r")
    assert (code, out) == (0, ["Integer value is: 150"])

    code, out = console(
        "ros2 run turtlesim turtle_teleop_key --ros-args --remap turtle1/cmd_vel:=turtle2/cmd_vel"
    )
    assert code == 0, out
    assert "Use arrow keys to move the turtle." in out
    wait_until(
        lambda: "/teleop_turtle" in publishers_of(probe, "/turtle2/cmd_vel"),
        timeout=DISCOVERY_TIMEOUT,
        what="teleop publishing on the remapped /turtle2/cmd_vel",
    )
    assert "/teleop_turtle" not in publishers_of(probe, "/turtle1/cmd_vel")

    code, out = console("ros2 run --stop /my_turtle")
    assert code == 0 and out == ["/my_turtle: stopped (exit code 0)"], out
    wait_node_gone(probe, "/my_turtle")
    assert "/turtlesim" in node_names(probe)


def test_tutorial_package_names_map_onto_the_catalog(console, probe, supervisor):
    code, out = console("ros2 run demo_nodes_py add_two_ints_server")
    assert code == 0, out
    code, out = console("ros2 run py_srvcli client 20 22")  # a client: runs to its end
    wait_until(
        lambda: not supervisor.status("add_two_ints_client").active,
        timeout=DISCOVERY_TIMEOUT,
        what="the client to finish",
    )
    log = "\n".join(supervisor.output("add_two_ints_client"))
    assert "20 + 22 = 42" in log, log
    assert supervisor.status("add_two_ints_client").exit_code == 0


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("ros2 run turtlesim nope", "'nope' is not in package 'turtlesim' here"),
        ("ros2 run no_such_pkg talker", "Package 'no_such_pkg' not found"),
        ("ros2 run turtlesim turtlesim_node --ros-args --enclave /x", "unsupported ROS argument"),
        ("ros2 run turtlesim turtlesim_node --ros-args -r 'a b'", "not a remapping rule"),
        ("ros2 run turtlesim turtlesim_node --ros-args -p", "-p needs a value"),
        ("ros2 run turtlesim turtlesim_node --ros-args --params-file /etc/passwd", "no YAML"),
        ("ros2 run turtlesim turtlesim_node extra", "takes no arguments"),
        ("ros2 run py_srvcli client 2 '$(reboot)'", "takes 2 whole numbers"),
        ("ros2 run --stop /nobody", "no running node named /nobody"),
        ("ros2 run turtlesim", "usage: ros2 run PACKAGE EXECUTABLE"),
    ],
)
def test_bad_run_commands_give_one_error_line(console, supervisor, text, message):
    code, out = console(text)
    assert code != 0
    errors = [line for line in out if line.startswith("error:")]
    assert len(errors) == 1 and message in errors[0], out
    assert not supervisor.statuses()  # nothing was started


def test_without_the_supervisor_the_verb_says_where_it_works(probe):
    lines: list[str] = []
    code = run_text(CallContext(probe.node, lines.append, CONSOLE_LIMITS), "ros2 run turtlesim x")
    assert code == 1 and lines[0].startswith(
        "error: `ros2 run` starts nodes through the dashboard's"
    )


def test_a_params_file_and_a_namespace(console, probe, tmp_path):
    """The parameters tutorial: values saved in a file, loaded at start-up."""
    saved = tmp_path / "turtlesim.yaml"
    saved.write_text("/**:\n  ros__parameters:\n    background_g: 200\n    holonomic: true\n")
    code, out = console(
        f"ros2 run turtlesim turtlesim_node --ros-args -r __ns:=/turtlesim1 --params-file {saved}"
    )
    assert code == 0, out
    assert any("Starting turtlesim with node name /turtlesim1/turtlesim" in x for x in out), out
    assert console("ros2 param get /turtlesim1/turtlesim background_g") == (
        0,
        ["Integer value is: 200"],
    )
    assert console("ros2 param get /turtlesim1/turtlesim holonomic") == (
        0,
        ["Boolean value is: True"],
    )
    wait_until(
        lambda: "/turtlesim1/turtle1/pose" in dict(probe.node.get_topic_names_and_types()),
        timeout=DISCOVERY_TIMEOUT,
        what="the namespaced pose topic",
    )


def test_the_command_line_runs_package_and_executable_like_ros2_run(ros_env, probe):
    """`ros2-classroom run turtlesim turtlesim_node --ros-args ...` in a terminal."""
    import signal
    import subprocess
    import sys
    import threading

    from app import PROJECT_ROOT

    argv = [sys.executable, "-m", "app", "run", "turtlesim", "turtlesim_node"]
    argv += ["--ros-args", "-r", "__node:=cli_turtle"]
    proc = subprocess.Popen(
        argv,
        cwd=PROJECT_ROOT,
        env=ros_env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    assert proc.stdout is not None
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(proc.stdout), daemon=True)
    reader.start()
    started = "Starting turtlesim with node name /cli_turtle"
    try:
        wait_until(
            lambda: "/cli_turtle" in node_names(probe),
            timeout=DISCOVERY_TIMEOUT,
            what="the renamed turtlesim",
        )
        # The node joins the graph in Node.__init__, before it logs its greeting.
        wait_until(
            lambda: any(started in line for line in lines),
            timeout=DISCOVERY_TIMEOUT,
            what=lambda: f"{started!r} in the output: {lines}",
        )
    finally:
        proc.send_signal(signal.SIGINT)  # Ctrl+C, as in the terminal
        proc.wait(timeout=15)
        reader.join(timeout=5)
