"""A stop signal ends a spinning node even when rclpy's own signal thread leaves it waiting.

rclpy's signal thread wakes the executors first and shuts the context down
second: an executor that wakes in between sees ROS still up and waits again,
for good. Beside a busy loop three nodes of the catalog were still spinning
20 s after SIGTERM (``test_sigterm_stops``, with every thread's stack dumped:
the main thread in ``rclpy.spin``'s wait). The program here is left with no
rclpy handler at all (uninstalled once it spins), the worst case of that
race: only ``spin_node``'s own stop watch can end it.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from typing import Any

import pytest

from app import PROJECT_ROOT

pytestmark = pytest.mark.ros

PROGRAM = """
import rclpy
from rclpy.node import Node
from rclpy.signals import uninstall_signal_handlers
from nodes.common.run import spin_node

class Ticker(Node):
    def __init__(self):
        super().__init__("lonely_ticker")
        self.ready = False
        self.create_timer(0.05, self.tick)

    def tick(self):
        if not self.ready:  # spinning: rclpy's handlers and its signal thread go away
            uninstall_signal_handlers()
            self.ready = True
            print("spinning", flush=True)

spin_node(Ticker)
"""


def _python(program: str, env: dict[str, str]) -> dict[str, Any]:
    """How each test starts its program: this project's Python, output and errors as text."""
    return {
        "args": [sys.executable, "-c", program],
        "env": env,
        "cwd": PROJECT_ROOT,
        "stdout": subprocess.PIPE,
        "stderr": subprocess.STDOUT,
        "text": True,
    }


def test_sigterm_ends_a_spin_that_rclpys_signal_thread_did_not_end(ros_env):
    proc = subprocess.Popen(**_python(PROGRAM, ros_env))
    try:
        assert proc.stdout is not None
        assert proc.stdout.readline().strip() == "spinning"
        proc.send_signal(signal.SIGTERM)
        sent = time.monotonic()
        code = proc.wait(15)
        took = time.monotonic() - sent
        output = proc.stdout.read()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert "Traceback" not in output, output
    assert code == 0, output
    assert took < 5, f"ended {took:.1f} s after SIGTERM"


# A stop just after start-up, before spinning: rclpy's signal thread shuts the context
# down while the executor would be made (ci33: turtlesim printed the __del__ tracebacks
# of a half-made SingleThreadedExecutor). The hook sends it at exactly that moment.
STOPPED_BEFORE_SPIN = """
import os, signal, time
import rclpy
from rclpy.node import Node
from nodes.common import run

started = run.ros_started

def started_then_stopped(*args):
    started(*args)
    os.kill(os.getpid(), signal.SIGTERM)
    deadline = time.monotonic() + 5
    while rclpy.ok() and time.monotonic() < deadline:
        time.sleep(0.01)
    print("context down" if not rclpy.ok() else "context still up", flush=True)

run.ros_started = started_then_stopped
run.spin_node(lambda: Node("stopped_before_spin"){executor})
"""


@pytest.mark.parametrize("executor", ["", ", executor=MultiThreadedExecutor"])
def test_a_stop_between_start_up_and_spinning_ends_quietly(ros_env, executor):
    program = STOPPED_BEFORE_SPIN.format(executor=executor)
    if executor:
        program = "from rclpy.executors import MultiThreadedExecutor\n" + program
    done = subprocess.run(**_python(program, ros_env), timeout=30)
    assert "context down" in done.stdout, done.stdout
    assert "Traceback" not in done.stdout, done.stdout
    assert done.returncode == 0, done.stdout
