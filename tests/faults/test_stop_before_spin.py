"""A stop signal that lands at an awkward moment ends the program quietly.

- Between making a node and spinning it: rclpy's signal handler shuts the
  context down; a program that then calls ``rclpy.spin(node)`` finds rclpy's
  global executor already reset to None (a CI run: amcl printed two
  AttributeErrors on SIGTERM and exited 1).
- While a program makes a second node (planner_server's costmap makes one for
  its tf listener; a rehearsal, ci70): the shutdown makes rclpy refuse it with
  NotInitializedException.
- After tf2_monitor has made its spinning thread and before it has started
  it (a rehearsal, ci44): its clean-up joined a thread never started and
  printed "cannot join thread before it is started".
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


# The shutdown lands as the second node is made; a program that never called rclpy.init()
# still gets its error (NEVER_INITIALIZED, below).
SECOND_NODE = """
import rclpy
from nodes.common.run import run_program

def main():
    rclpy.init()
    first = rclpy.create_node("first_node")
    rclpy.get_default_context().shutdown()  # what rclpy's signal handler does
    rclpy.create_node("costmap_listener")

run_program(main)
"""
NEVER_INITIALIZED = """
import rclpy
from nodes.common.run import run_program

run_program(lambda: rclpy.create_node("too_early"))
"""


# The signal, landing exactly there: the spinner's start raises what SIGTERM raises.
TF2_MONITOR_STOPPED_BEFORE_ITS_SPINNER_STARTS = """
import sys, threading
from tf2_ros.tools import tf2_monitor

start = threading.Thread.start

def start_or_stop(thread):
    if getattr(getattr(thread, "_target", None), "__name__", "") == "spin":
        raise KeyboardInterrupt
    start(thread)

threading.Thread.start = start_or_stop
sys.exit(tf2_monitor.main(["tf2_monitor"]))
"""


def _run(program: str, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    """``program`` run to its end by a fresh Python, its output kept."""
    return subprocess.run(
        [sys.executable, "-c", program],
        env=env,
        cwd=PROJECT_ROOT,
        capture_output=True,
        text=True,
        timeout=60,
    )


@pytest.mark.parametrize(
    "program",
    [PROGRAM, SECOND_NODE, TF2_MONITOR_STOPPED_BEFORE_ITS_SPINNER_STARTS],
    ids=[
        "shutdown_just_before_spin",
        "shutdown_as_a_second_node_is_made",
        "tf2_monitor_before_its_spinner_starts",
    ],
)
def test_a_stop_at_an_awkward_moment_ends_quietly(ros_env, program):
    done = _run(program, ros_env)
    output = done.stdout + done.stderr
    assert "Traceback" not in output, output
    assert done.returncode == 0, output


def test_a_program_that_never_started_ros_still_gets_its_error(ros_env):
    done = _run(NEVER_INITIALIZED, ros_env)
    assert done.returncode != 0
    assert "NotInitializedException" in done.stderr, done.stderr
