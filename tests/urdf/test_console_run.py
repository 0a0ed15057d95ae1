"""`ros2 run robot_state_publisher robot_state_publisher ...` typed in the Console."""

from __future__ import annotations

import pytest

from app.ros.context import CONSOLE_LIMITS, CallContext
from app.ros2cli import run_text

pytestmark = pytest.mark.ros

FLEXIBLE = "ros_python/src/urdf_tutorial/urdf/06-flexible.urdf"


@pytest.fixture
def console(probe, supervisor):
    def run(text: str) -> tuple[int, list[str]]:
        lines: list[str] = []
        ctx = CallContext(probe.node, lines.append, CONSOLE_LIMITS, programs=supervisor)
        code = run_text(ctx, text)
        return code, "\n".join(lines).splitlines()

    return run


def test_urdf_file_argument_and_inline_description(console) -> None:
    code, out = console(f"ros2 run robot_state_publisher robot_state_publisher {FLEXIBLE}")
    assert code == 0, out
    assert any("Assuming argument is name of URDF file" in line for line in out), out
    assert any(line.endswith("Robot initialized") for line in out), out

    code, out = console(
        "ros2 run robot_state_publisher robot_state_publisher --ros-args -r __node:=rsp_inline "
        """-p robot_description:='<robot name="tiny"><link name="only"/></robot>'"""
    )
    assert code == 0, out
    assert any("[rsp_inline]: Robot initialized" in line for line in out), out

    code, out = console(
        "ros2 run robot_state_publisher robot_state_publisher /etc/passwd --ros-args -r __node:=x"
    )
    assert code == 1 and "takes no arguments" in out[-1], out

    code, out = console(
        "ros2 run robot_state_publisher robot_state_publisher --ros-args -r __node:=rsp_empty"
    )
    assert any("robot_description parameter must not be empty" in line for line in out), out


@pytest.mark.parametrize("form", ["file", "xacro"])
def test_terminal_forms_of_the_tutorials(ros_env, form) -> None:
    """`ros2-classroom run robot_state_publisher robot_state_publisher ...` in a terminal."""
    import os
    import signal
    import subprocess
    import sys
    import time
    from pathlib import Path

    from app import PROJECT_ROOT

    if form == "file":
        words = [FLEXIBLE]
    else:
        xacro = Path(sys.executable).with_name("xacro")
        model = "ros_python/src/urdf_tutorial/urdf/08-macroed.urdf.xacro"
        described = subprocess.run(
            [str(xacro), model], cwd=PROJECT_ROOT, capture_output=True, text=True, check=True
        )  # what "$(xacro model.urdf.xacro)" gives the shell
        words = ["--ros-args", "-p", f"robot_description:={described.stdout}"]
    proc = subprocess.Popen(
        [sys.executable, "-m", "app", "run", "robot_state_publisher", "robot_state_publisher"]
        + words,
        cwd=PROJECT_ROOT, env=ros_env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
        text=True, start_new_session=True,
    )  # fmt: skip
    lines: list[str] = []
    try:
        deadline = time.monotonic() + 30
        assert proc.stdout is not None
        while time.monotonic() < deadline:
            line = proc.stdout.readline()
            if not line:
                break
            lines.append(line)
            if "Robot initialized" in line:
                break
        assert any("Robot initialized" in line for line in lines), lines
    finally:
        os.killpg(proc.pid, signal.SIGINT)
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=5)
