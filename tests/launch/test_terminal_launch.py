"""`ros2-classroom launch PACKAGE FILE` in a terminal: ros2launch with the catalog's prefix.

The terminal command replaces itself with ros2launch (as ``ros2 launch``
holds its terminal), so Ctrl+C reaches the launcher and its nodes, which
share the terminal's foreground process group.
"""

from __future__ import annotations

import sys

import pytest

from tests.launch.helpers import Launch, group_members, launch_env, started_pids

pytestmark = pytest.mark.ros


def test_terminal_launch_of_multisim_and_ctrl_c(tmp_path, ros_env):
    env = launch_env(ros_env, None, tmp_path / "log")
    domain = env["ROS_DOMAIN_ID"]
    command = [sys.executable, "-m", "app", "launch", "turtlesim", "multisim.launch.py",
               "--domain-id", domain]  # fmt: skip
    launch = Launch([], env, command=command)
    try:
        lines = launch.read_until(
            lambda lines: sum("Spawning turtle [turtle1]" in line for line in lines) == 2, 30
        )
        assert lines[1] == "[INFO] [launch]: Default logging verbosity is set to INFO", lines
        pids = started_pids(lines)
        assert set(pids) == {"turtlesim_node-1", "turtlesim_node-2"}
        assert sorted(group_members(launch.pgid)) == sorted([launch.pgid, *pids.values()])
        launch.ctrl_c()
        out = launch.finish(timeout=20)
    finally:
        launch.kill()
    assert launch.proc.returncode == 0, out
    for label, pid in pids.items():
        assert f"[INFO] [{label}]: process has finished cleanly [pid {pid}]" in out, out
    assert group_members(launch.pgid) == []
