# ruff: noqa: E501  (the launch files below are written as the tutorials write them)
"""launch, launch_ros and ros2launch from outside, with real (small, shell-free) Python children.

No ROS graph here: the children are plain Python programs found through an
ament prefix the test builds, as colcon would install them.
"""

from __future__ import annotations

import os
import re
import signal
import sys
import textwrap
from pathlib import Path

import pytest

from tests.launch.helpers import (
    Launch,
    ament_prefix,
    group_members,
    launch_env,
    python_child,
    run,
    started_pids,
)

HEADER = """
import sys
from launch import LaunchDescription
from launch.actions import *
from launch.conditions import IfCondition, UnlessCondition
from launch.event_handlers import *
from launch.events import Shutdown as ShutdownEvent
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import *
from launch_ros.actions import Node, PushRosNamespace, SetParameter, SetRemap
from launch_ros.substitutions import FindPackageShare
PY = sys.executable
"""

# A child that prints its argv (one line) and a line on stderr, then ends with the code asked.
ECHO = python_child(
    """
    import sys
    print("argv", " ".join(sys.argv[1:]), flush=True)
    print("to stderr", file=sys.stderr, flush=True)
    sys.exit(int(sys.argv[1]) if len(sys.argv) > 1 and sys.argv[1].isdigit() else 0)
    """
)
# A child that runs until signalled; "stubborn" ignores SIGINT, "deaf" SIGINT and SIGTERM.
SLEEPER = python_child(
    """
    import signal, sys, time
    mode = sys.argv[1] if len(sys.argv) > 1 else ""
    if mode in ("stubborn", "deaf"):
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    if mode == "deaf":
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
    print("ready", flush=True)
    while True:
        time.sleep(0.05)
    """
)


@pytest.fixture
def prefix(tmp_path: Path) -> Path:
    return ament_prefix(
        tmp_path / "install",
        {
            "demo_pkg": {
                "lib/echo": ECHO,
                "lib/sleeper": SLEEPER,
                "config/params.yaml": "/**:\n  ros__parameters:\n    rate: 5\n",
                "launch/nested/deep/echo.launch.py": HEADER
                + textwrap.dedent(
                    """
                    def generate_launch_description():
                        return LaunchDescription([
                            DeclareLaunchArgument("word", default_value="plain",
                                                  description="what echo says"),
                            Node(package="demo_pkg", executable="echo", name="echoer",
                                 arguments=[LaunchConfiguration("word")], output="screen"),
                        ])
                    """
                ),
            },
            "other_pkg": {"launch/echo.launch.py": HEADER},
        },
    )


def env_for(tmp_path: Path, prefix: Path | None) -> dict[str, str]:
    return launch_env(os.environ, prefix, tmp_path / "log")


def write(tmp_path: Path, body: str, name: str = "test.launch.py") -> Path:
    path = tmp_path / name
    path.write_text(HEADER + textwrap.dedent(body))
    return path


def test_package_file_found_recursively_with_arguments_and_upstream_lines(tmp_path, prefix):
    code, out = run(["demo_pkg", "echo.launch.py", "word:=hello"], env_for(tmp_path, prefix))
    assert code == 0, out
    assert re.fullmatch(
        rf"\[INFO\] \[launch\]: All log files can be found below {tmp_path}/log/"
        r"\d{4}(-\d\d){5}-\d{6}-.+-\d+",
        out[0],
    ), out
    assert out[1] == "[INFO] [launch]: Default logging verbosity is set to INFO"
    pid = started_pids(out)["echo-1"]
    assert out[2] == f"[INFO] [echo-1]: process started with pid [{pid}]"
    # The node's command line: executable from the ament index, then --ros-args.
    assert "[echo-1] argv hello --ros-args -r __node:=echoer" in out, out
    assert "[echo-1] to stderr" in out
    assert out[-1] == f"[INFO] [echo-1]: process has finished cleanly [pid {pid}]"
    assert (next((tmp_path / "log").iterdir()) / "launch.log").is_file()


def test_show_args_lists_declared_arguments(tmp_path, prefix):
    code, out = run(["demo_pkg", "echo.launch.py", "-s"], env_for(tmp_path, prefix))
    assert code == 0, out
    assert out == [
        "Arguments (pass arguments as '<name>:=<value>'):",
        "",
        "    'word':",
        "        what echo says",
        "        (default: 'plain')",
    ]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["nope_pkg", "x.launch.py"], "Package 'nope_pkg' not found: \"package 'nope_pkg' not "
                                      "found, searching: ["),
        (["demo_pkg", "missing.launch.py"], "file 'missing.launch.py' was not found in the "
                                            "share directory of package 'demo_pkg' which is at"),
        (["demo_pkg", "echo.launch.py", "word"], "malformed launch argument 'word', expected "
                                                 "format '<name>:=<value>'"),
    ],
)  # fmt: skip
def test_bad_command_lines_give_ros2s_error(tmp_path, prefix, args, message):
    code, out = run(args, env_for(tmp_path, prefix))
    assert code == 1 and len(out) == 1 and out[0].startswith(message), out


def test_missing_executable_and_package_are_launch_errors(tmp_path, prefix):
    path = write(
        tmp_path,
        """
        def generate_launch_description():
            return LaunchDescription([Node(package="demo_pkg", executable="nope")])
        """,
    )
    code, out = run([str(path)], env_for(tmp_path, prefix))
    assert code == 1
    assert out[-1] == (
        "[ERROR] [launch]: Caught exception in launch (see debug for traceback): executable "
        f"'nope' not found on the libexec directory '{prefix}/lib/demo_pkg' "
    ), out


def test_substitutions(tmp_path, prefix):
    path = write(
        tmp_path,
        """
        def generate_launch_description():
            return LaunchDescription([
                DeclareLaunchArgument("n", default_value="2"),
                SetEnvironmentVariable("GREETING", "hi"),
                SetLaunchConfiguration("computed", PythonExpression([LaunchConfiguration("n"), " * pi"])),
                LogInfo(msg=["n=", LaunchConfiguration("n")]),
                LogInfo(msg=["expr=", LaunchConfiguration("computed")]),
                LogInfo(msg=["default=", LaunchConfiguration("unset", default="fallback")]),
                LogInfo(msg=["env=", EnvironmentVariable("GREETING"), " ",
                             EnvironmentVariable("NOT_SET_ANYWHERE", default_value="none")]),
                LogInfo(msg=["join=", PathJoinSubstitution([FindPackageShare("demo_pkg"), "config", "params.yaml"])]),
                LogInfo(msg=["dir=", ThisLaunchFileDir()]),
                LogInfo(msg=["exe=", FindExecutable(name="sh")]),
                LogInfo(msg=["cmd=", Command([PY, " -c \\"print(6 * 7)\\""])]),
            ])
        """,
    )
    code, out = run([str(path), "n:=3"], env_for(tmp_path, prefix))
    assert code == 0, out
    logged = [line.split("]: ", 1)[1] for line in out if line.startswith("[INFO] [launch.user]")]
    assert logged == [
        "n=3",
        "expr=9.42477796076938",
        "default=fallback",
        "env=hi none",
        f"join={prefix}/share/demo_pkg/config/params.yaml",
        f"dir={tmp_path}",
        f"exe={__import__('shutil').which('sh')}",
        "cmd=42\n",
    ][:7] + [logged[7]], out
    assert logged[7].startswith("cmd=42"), out


@pytest.mark.parametrize(
    ("flag", "expected"), [("true", ["if ran"]), ("False", ["unless ran"]), ("1", ["if ran"])]
)
def test_conditions(tmp_path, prefix, flag, expected):
    path = write(
        tmp_path,
        """
        def generate_launch_description():
            flag = LaunchConfiguration("flag")
            return LaunchDescription([
                DeclareLaunchArgument("flag"),
                LogInfo(msg="if ran", condition=IfCondition(flag)),
                LogInfo(msg="unless ran", condition=UnlessCondition(flag)),
            ])
        """,
    )
    code, out = run([str(path), f"flag:={flag}"], env_for(tmp_path, prefix))
    assert code == 0, out
    assert [line.split("]: ", 1)[1] for line in out if "[launch.user]" in line] == expected


def test_bad_condition_and_missing_required_argument_are_errors(tmp_path, prefix):
    path = write(
        tmp_path,
        """
        def generate_launch_description():
            return LaunchDescription([
                DeclareLaunchArgument("flag", description="needed"),
                LogInfo(msg="ran", condition=IfCondition(LaunchConfiguration("flag"))),
            ])
        """,
    )
    code, out = run([str(path)], env_for(tmp_path, prefix))
    assert code == 1 and out[-1].endswith(
        "Required launch argument 'flag' (description: 'needed') was not provided"
    ), out
    code, out = run([str(path), "flag:=maybe"], env_for(tmp_path, prefix))
    assert code == 1 and "invalid condition expression 'maybe'" in out[-1], out


def test_event_handlers_include_group_and_timer(tmp_path, prefix):
    write(
        tmp_path,
        """
        def generate_launch_description():
            return LaunchDescription([
                DeclareLaunchArgument("who"),
                LogInfo(msg=["included for ", LaunchConfiguration("who"), " in ",
                             ThisLaunchFileDir()]),
            ])
        """,
        name="inner.launch.py",
    )
    path = write(
        tmp_path,
        """
        def generate_launch_description():
            first = ExecuteProcess(cmd=[PY, "-c", "print('out one')"], output="screen", name="first")
            failing = Node(package="demo_pkg", executable="echo", arguments=["3"], name="f")
            def on_exit(event, context):
                return LogInfo(msg=f"{event.action.process_details['name']} returned {event.returncode}")
            return LaunchDescription([
                IncludeLaunchDescription(
                    PythonLaunchDescriptionSource([ThisLaunchFileDir(), "/inner.launch.py"]),
                    launch_arguments={"who": "outer"}.items()),
                GroupAction([SetLaunchConfiguration("scoped", "inside"),
                             LogInfo(msg=LaunchConfiguration("scoped"))]),
                LogInfo(msg=LaunchConfiguration("scoped", default="outside")),
                RegisterEventHandler(OnProcessStart(target_action=first,
                                                    on_start=[LogInfo(msg="first started")])),
                RegisterEventHandler(OnProcessIO(target_action=first,
                    on_stdout=lambda event: LogInfo(msg="heard " + event.text.decode().strip()))),
                RegisterEventHandler(OnExecutionComplete(target_action=first,
                                                         on_completion=[LogInfo(msg="first complete")])),
                RegisterEventHandler(OnProcessExit(target_action=failing, on_exit=on_exit)),
                # 3 s after `first` ends: `failing` (a node's Python start) has ended by then
                # on a loaded machine too (at 0.3 s the shutdown once came first, on CI).
                RegisterEventHandler(OnProcessExit(target_action=first, on_exit=[
                    TimerAction(period=3.0, actions=[
                        OpaqueFunction(function=lambda context: [LogInfo(msg="timer fired")]),
                        EmitEvent(event=ShutdownEvent(reason="all done")),
                    ]),
                ])),
                RegisterEventHandler(OnShutdown(on_shutdown=[
                    LogInfo(msg=["shutdown because: ", LocalSubstitution("event.reason")])])),
                first,
                failing,
            ])
        """,
    )
    code, out = run([str(path)], env_for(tmp_path, prefix))
    assert code == 0, out
    logged = [line.split("]: ", 1)[1] for line in out if "[launch.user]" in line]
    assert logged[:3] == [f"included for outer in {tmp_path}", "inside", "outside"], out
    for wanted in ("first started", "heard out one", "first complete", "echo-2 returned 3"):
        assert wanted in logged, out
    assert logged[-2:] == ["timer fired", "shutdown because: all done"], out
    assert logged.index("heard out one") < logged.index("first complete")
    pids = started_pids(out)
    cmd = f"{prefix}/lib/demo_pkg/echo 3 --ros-args -r __node:=f"
    assert (
        f"[ERROR] [echo-2]: process has died [pid {pids['echo-2']}, exit code 3, cmd '{cmd}']."
        in out
    )


def test_node_command_line_namespaces_parameters_and_remaps(tmp_path, prefix):
    params = prefix / "share/demo_pkg/config/params.yaml"
    path = write(
        tmp_path,
        f"""
        def generate_launch_description():
            return LaunchDescription([
                DeclareLaunchArgument("rate", default_value="7.5"),
                GroupAction([
                    PushRosNamespace("robot1"),
                    SetParameter(name="use_sim_time", value=True),
                    SetRemap(src="/clock", dst="/sim_clock"),
                    Node(package="demo_pkg", executable="echo", name="talker", namespace="arm",
                         parameters=[{{"rate": LaunchConfiguration("rate"), "frame": "base",
                                      "limits": {{"max": 2}}}}, "{params}"],
                         remappings=[("chatter", "greeting")], ros_arguments=["--log-level", "warn"],
                         output="screen"),
                ]),
                Node(package="demo_pkg", executable="echo", exec_name="plain", output="screen"),
            ])
        """,
    )
    code, out = run([str(path)], env_for(tmp_path, prefix))
    assert code == 0, out
    argv = [line for line in out if line.startswith("[echo-1] argv")]
    assert argv == [
        "[echo-1] argv --ros-args --log-level warn -r __node:=talker -r __ns:=/robot1/arm "
        '-p use_sim_time:=true -p rate:=7.5 -p frame:="base" -p limits.max:=2 '
        f"--params-file {params} -r /clock:=/sim_clock -r chatter:=greeting"
    ], out
    assert "[plain-2] argv --ros-args" in out, out


def test_ctrl_c_ends_every_child_with_escalation_and_leaves_no_orphan(tmp_path, prefix):
    path = write(
        tmp_path,
        """
        def generate_launch_description():
            return LaunchDescription([
                Node(package="demo_pkg", executable="sleeper", output="screen"),
                Node(package="demo_pkg", executable="sleeper", arguments=["stubborn"], output="screen"),
                Node(package="demo_pkg", executable="sleeper", arguments=["deaf"], output="screen"),
            ])
        """,
    )
    launch = Launch([str(path), "sigterm_timeout:=1", "sigkill_timeout:=1"],
                    env_for(tmp_path, prefix))  # fmt: skip
    try:
        launch.read_until(lambda lines: sum(line.endswith("] ready") for line in lines) == 3, 15)
        pids = started_pids(launch.lines)
        assert sorted(group_members(launch.pgid)) == sorted([launch.pgid, *pids.values()])
        launch.ctrl_c()
        out = launch.finish(timeout=15)
    finally:
        launch.kill()
    assert launch.proc.returncode == 0
    assert "[WARNING] [launch]: user interrupted with ctrl-c (SIGINT)" in out
    p1, p2, p3 = pids["sleeper-1"], pids["sleeper-2"], pids["sleeper-3"]
    assert f"[ERROR] [sleeper-1]: process has died [pid {p1}, exit code -2, cmd '" in "\n".join(out)
    for label in ("sleeper-2", "sleeper-3"):
        assert (f"[ERROR] [{label}]: process[{label}] failed to terminate '1' seconds after "
                "receiving 'SIGINT', escalating to 'SIGTERM'") in out, out  # fmt: skip
    assert f"[ERROR] [sleeper-2]: process has died [pid {p2}, exit code -15, cmd '" in "\n".join(
        out
    )
    assert ("[ERROR] [sleeper-3]: process[sleeper-3] failed to terminate '2.0' seconds after "
            "receiving 'SIGTERM', escalating to 'SIGKILL'") in out, out  # fmt: skip
    assert f"[ERROR] [sleeper-3]: process has died [pid {p3}, exit code -9, cmd '" in "\n".join(out)
    assert group_members(launch.pgid) == []


def test_sigint_to_the_launcher_alone_still_ends_its_children(tmp_path, prefix):
    """kill -INT <launcher>: the children got no SIGINT of their own, the escalation ends them."""
    path = write(
        tmp_path,
        """
        def generate_launch_description():
            return LaunchDescription([Node(package="demo_pkg", executable="sleeper", output="screen")])
        """,
    )
    launch = Launch([str(path), "sigterm_timeout:=0.5"], env_for(tmp_path, prefix))
    try:
        launch.read_until(lambda lines: any(line.endswith("] ready") for line in lines), 15)
        os.kill(launch.proc.pid, signal.SIGINT)
        out = launch.finish(timeout=15)
    finally:
        launch.kill()
    assert "[WARNING] [launch]: user interrupted with ctrl-c (SIGINT)" in out
    assert any(": process has died [pid" in line and "exit code -15" in line for line in out), out
    assert group_members(launch.pgid) == []


def test_a_child_dies_with_a_killed_launcher(tmp_path, prefix):
    path = write(
        tmp_path,
        """
        def generate_launch_description():
            return LaunchDescription([Node(package="demo_pkg", executable="sleeper", output="screen")])
        """,
    )
    launch = Launch([str(path)], env_for(tmp_path, prefix))
    try:
        launch.read_until(lambda lines: any(line.endswith("] ready") for line in lines), 15)
        child = started_pids(launch.lines)["sleeper-1"]
        os.kill(launch.proc.pid, signal.SIGKILL)
        launch.proc.wait(5)
        deadline = __import__("time").monotonic() + 5
        while child in group_members(launch.pgid) and __import__("time").monotonic() < deadline:
            __import__("time").sleep(0.05)
        assert child not in group_members(launch.pgid)  # the parent-death signal ended it
    finally:
        launch.kill()


def test_the_test_process_imports_nothing_of_the_classroom():
    code = (
        "import sys, launch, launch_ros.actions, ros2launch.api; "
        "print(sorted({m.split('.')[0] for m in sys.modules} & {'app', 'nodes'}))"
    )
    out = __import__("subprocess").run([sys.executable, "-c", code], capture_output=True,
                                       text=True, check=True).stdout  # fmt: skip
    assert out.strip() == "[]"


def test_respawn_environment_and_scoped_environment(tmp_path, prefix):
    path = write(
        tmp_path,
        """
        def generate_launch_description():
            show = [PY, "-c", "import os; print('color', os.environ.get('COLOR', 'unset'))"]
            return LaunchDescription([
                GroupAction([
                    SetEnvironmentVariable("COLOR", "red"),
                    ExecuteProcess(cmd=show, name="inside", output="screen"),
                ]),
                ExecuteProcess(cmd=show, name="outside", output="screen"),
                ExecuteProcess(cmd=show, name="extra", additional_env={"COLOR": "blue"},
                               output="screen"),
                Node(package="demo_pkg", executable="echo", arguments=["4"], respawn=True,
                     respawn_delay=0.1, respawn_max_retries=2, output="log"),
            ])
        """,
    )
    code, out = run([str(path)], env_for(tmp_path, prefix))
    assert code == 0, out
    assert "[inside-1] color red" in out and "[outside-2] color unset" in out, out
    assert "[extra-3] color blue" in out, out
    starts = [line for line in out if line.startswith("[INFO] [echo-4]: process started")]
    deaths = [line for line in out if line.startswith("[ERROR] [echo-4]: process has died")]
    assert len(starts) == 3 and len(deaths) == 3, out  # the first run and two respawns
    # output="log": stdout only in launch.log, stderr also on the screen (upstream's default).
    assert "[echo-4] to stderr" in out and not any("[echo-4] argv" in line for line in out)
    log = (next((tmp_path / "log").iterdir()) / "launch.log").read_text()
    assert "[echo-4] argv 4 --ros-args" in log


def test_an_error_in_the_launch_file_names_its_line(tmp_path, prefix):
    path = write(
        tmp_path,
        """
        def generate_launch_description():
            return LaunchDescription([
                Nod(package="demo_pkg", executable="echo"),
            ])
        """,
    )
    code, out = run([str(path)], env_for(tmp_path, prefix))
    assert code == 1
    assert (
        "[ERROR] [launch]: Caught exception in launch (see debug for traceback): Caught "
        "exception when trying to load file of format [py]: name 'Nod' is not defined"
    ) in out, out
    lines = path.read_text().splitlines()
    line = next(i for i, text in enumerate(lines, start=1) if text.strip().startswith("Nod("))
    assert f'  File "{path}", line {line}, in generate_launch_description' in out, out
    assert out[-1] == "NameError: name 'Nod' is not defined"
