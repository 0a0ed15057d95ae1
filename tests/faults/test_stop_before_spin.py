"""A stop signal that lands between making a node and spinning it ends the program quietly.

rclpy's signal handler shuts the context down; a program that then calls
``rclpy.spin(node)`` finds rclpy's global executor already reset to None
(a CI run: amcl printed two AttributeErrors on SIGTERM and exited 1).
"""

from __future__ import annotations

import subprocess
import sys

import pytest

from app import PROJECT_ROOT

pytestmark = pytest.mark.ros

# The signal lands inside spin(), just after rclpy has made its global executor and before
# it registers that executor's reset: the shutdown then runs the reset at once, and
# get_global_executor() returns None. The patch holds the program in that moment.
PROGRAM = """
import rclpy
import rclpy.executors
from nodes.common.run import run_program

made = rclpy.executors.SingleThreadedExecutor.__init__

def made_then_signalled(self, *args, **kwargs):
    made(self, *args, **kwargs)
    rclpy.get_default_context().shutdown()  # what rclpy's signal handler does

rclpy.executors.SingleThreadedExecutor.__init__ = made_then_signalled

def main():
    rclpy.init()
    node = rclpy.create_node("late_spinner")
    rclpy.spin(node)

run_program(main)
"""


def test_a_shutdown_just_before_spin_ends_quietly(ros_env):
    done = subprocess.run(
        [sys.executable, "-c", PROGRAM],
        env=ros_env,
        cwd=PROJECT_ROOT,
        capture_output=True,
        text=True,
        timeout=60,
    )
    output = done.stdout + done.stderr
    assert "Traceback" not in output, output
    assert done.returncode == 0, output
