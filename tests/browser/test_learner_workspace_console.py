"""The tutorial's workspace sequence typed into the dashboard's Console (issue 22)."""

from __future__ import annotations

import pytest

from tests.browser.helpers import click, open_tab
from tests.browser.test_ros2_panels import expect_shown, field

pytestmark = [pytest.mark.browser, pytest.mark.ros]


def test_pkg_create_colcon_build_source_run_in_the_console(page, progress_dir):
    open_tab(page, "Console")
    steps = (
        (
            "ros2 pkg create --build-type ament_python --license Apache-2.0 "
            "--node-name my_node my_package",
            "creating ./my_package/my_package/my_node.py",
        ),
        ("ros2 run my_package my_node", "Package 'my_package' not found"),
        ("colcon build --packages-select my_package", "Summary: 1 package finished"),
        ("source install/setup.bash", "sourced ~/ros2_ws/install/setup.bash"),
        ("ros2 run my_package my_node", "Hi from my_package."),
    )
    for command, shown in steps:
        field(page, "Command").fill(command)
        click(page, "Run")
        expect_shown(page, shown, timeout=90_000)
    workspace = progress_dir / "default.ros2_ws"
    assert (workspace / "install" / "my_package" / "lib" / "my_package" / "my_node").is_file()
