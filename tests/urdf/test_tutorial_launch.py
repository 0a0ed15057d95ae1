"""The URDF tutorials' launch commands, typed verbatim in the Console.

``ros2 launch urdf_tutorial display.launch.py model:=urdf/<model>`` for every
model of the tutorials (xacro included, and ``gui:=false``), and ``ros2 launch
urdf_tutorial_r2d2 demo.launch.py``: each must put its robot on the latched
``/robot_description`` and its frames on TF.
"""

from __future__ import annotations

import pytest

from tests.conftest import wait_until
from tests.integration.core_helpers import DISCOVERY_TIMEOUT, node_names
from tests.turtlesim.test_ros2_run import console  # noqa: F401  (the Console fixture)

pytestmark = pytest.mark.ros

MODELS = [
    ("01-myfirst.urdf", "myfirst", ""),
    ("02-multipleshapes.urdf", "multipleshapes", ""),
    ("03-origins.urdf", "origins", ""),
    ("04-materials.urdf", "materials", ""),
    ("05-visual.urdf", "visual", ""),
    ("06-flexible.urdf", "flexible", ""),
    ("08-macroed.urdf.xacro", "macroed", " gui:=false"),
]


def ok(console, text: str) -> list[str]:  # noqa: F811
    code, out = console(text)
    assert code == 0, (text, out)
    return out


DESCRIPTION = "--full-length /robot_description"
LAUNCH = "launch:urdf_tutorial/display.launch.py"  # the Console's name for the launch program


def names_robot(text: str, robot: str) -> bool:
    """The echoed description names the robot (YAML escapes the quotes of some texts)."""
    return f'robot name="{robot}"' in text or f'robot name=\\"{robot}\\"' in text


def echo_once(console, topic: str) -> str:  # noqa: F811
    code, out = console(f"ros2 topic echo --once {topic}")
    return "\n".join(out) if code == 0 else ""


def test_display_launch_for_every_model(console, probe, supervisor):  # noqa: F811
    for model, robot, extra in MODELS:
        command = f"ros2 launch urdf_tutorial display.launch.py model:=urdf/{model}{extra}"
        ok(console, command)
        jsp = "/joint_state_publisher"
        wait_until(
            lambda j=jsp: {"/robot_state_publisher", j} <= set(node_names(probe)),
            timeout=DISCOVERY_TIMEOUT,
            what=f"robot_state_publisher and joint_state_publisher for {model}",
        )
        wait_until(
            lambda r=robot: names_robot(echo_once(console, DESCRIPTION), r),
            timeout=DISCOVERY_TIMEOUT,
            what=lambda r=robot: f"{r} on /robot_description: {echo_once(console, DESCRIPTION)}",
        )
        if robot in ("flexible", "macroed"):  # movable joints: on /tf from the joint states
            wait_until(
                lambda: "child_frame_id: gripper_pole" in echo_once(console, "/tf"),
                timeout=DISCOVERY_TIMEOUT,
                what=lambda: (
                    f"gripper_pole on /tf: {echo_once(console, '/tf')[:300]}; launch output: "
                    f"{supervisor.output(LAUNCH)}; "
                    f"/joint_states: {echo_once(console, '/joint_states')[:300]}"
                ),
            )
        ok(console, "ros2 launch --stop urdf_tutorial display.launch.py")
        wait_until(
            lambda: not supervisor.status(LAUNCH).active,
            timeout=DISCOVERY_TIMEOUT,
            what=f"the {model} launch to stop",
        )


def test_r2d2_demo_launch(console, probe):  # noqa: F811
    ok(console, "ros2 launch urdf_tutorial_r2d2 demo.launch.py")
    wait_until(
        lambda: {"/robot_state_publisher", "/state_publisher"} <= set(node_names(probe)),
        timeout=DISCOVERY_TIMEOUT,
        what="the r2d2 demo's nodes",
    )
    wait_until(
        lambda: "child_frame_id: axis" in echo_once(console, "/tf"),
        timeout=DISCOVERY_TIMEOUT,
        what="odom -> axis on /tf",
    )
    assert names_robot(echo_once(console, DESCRIPTION), "r2d2")
    ok(console, "ros2 launch --stop urdf_tutorial_r2d2 demo.launch.py")
