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
