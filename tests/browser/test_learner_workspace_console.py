"""The tutorial's workspace sequence typed into the dashboard's Console (issue 22)."""

from __future__ import annotations

import re

import pytest
from playwright.sync_api import expect

from tests.browser.helpers import click, open_folder, open_tab
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


def test_workspace_files_open_edit_save_and_delete(page, progress_dir):
    open_tab(page, "Console")
    field(page, "Command").fill(
        "ros2 pkg create --build-type ament_python --node-name my_node pkg_a"
    )
    click(page, "Run")
    expect_shown(page, "creating ./pkg_a/pkg_a/my_node.py", timeout=60_000)
    open_folder(page, "Workspace files (~/ros2_ws)")
    expect_shown(page, "my_node.py")  # the tree shows what pkg create wrote
    field(page, "Path").fill("src/pkg_a/pkg_a/my_node.py")
    click(page, "Open")
    text = page.locator("textarea").locator("visible=true").first
    expect(text).to_have_value(re.compile("Hi from pkg_a"), timeout=30_000)
    text.fill("def main():\n    print('edited in the page')\n")
    click(page, "Save")
    expect_shown(page, "saved src/pkg_a/pkg_a/my_node.py")
    node = progress_dir / "default.ros2_ws" / "src" / "pkg_a" / "pkg_a" / "my_node.py"
    assert node.read_text() == "def main():\n    print('edited in the page')\n"
    field(page, "Path").fill("../../outside")
    click(page, "New folder")
    expect_shown(page, "outside your workspace")
    assert not (progress_dir / "outside").exists()
