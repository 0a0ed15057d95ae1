"""A cmd_vel that arrives while the update timer is late moves the turtle only from then on.

Under load the 16 ms timer fires late and the node runs the steps it missed
(``Turtlesim.catch_up``). Those steps fell due before the command arrived, so
they must move the turtle with the velocity it had then. Run in this process
without spinning: the test plays the late timer by hand.
"""

from __future__ import annotations

import time

import pytest
import rclpy
from geometry_msgs.msg import Twist

from nodes.common.turtlesim_world import UPDATE_PERIOD
from nodes.turtlesim_node import Turtlesim

pytestmark = pytest.mark.ros

LATE_SEC = 0.2  # how late the timer is: about 12 steps due at once


def test_steps_due_before_a_command_do_not_move_the_turtle_with_it(ros_env, monkeypatch):
    rclpy.init()
    node = Turtlesim()
    try:
        turtle = node.world.turtles["turtle1"]
        start = turtle.x
        node.next_step = time.monotonic() - LATE_SEC  # no step has run for LATE_SEC
        forward = Twist()
        forward.linear.x = 1.0
        node.on_cmd_vel("turtle1", forward)
        node.on_update()  # the late timer fires at last
        moved = turtle.x - start
        # At most the step or two that fell due after the command, not 0.2 m.
        assert 0.0 <= moved <= 2 * UPDATE_PERIOD + 1e-9, f"moved {moved:.3f} m"
        # From here on every due step moves the turtle at 1 m/s. Count the steps the
        # next update runs: a sleep on a busy computer lasts longer than it asks for.
        steps: list[float] = []
        step_world = node.step_world

        def counted(now: float) -> None:
            steps.append(now)
            step_world(now)

        monkeypatch.setattr(node, "step_world", counted)
        time.sleep(10 * UPDATE_PERIOD)
        node.on_update()
        assert len(steps) >= 10, f"{len(steps)} steps ran after a sleep of 10 periods"
        assert turtle.x - start == pytest.approx(moved + len(steps) * UPDATE_PERIOD, abs=1e-6)
    finally:
        node.destroy_node()
        rclpy.shutdown()
