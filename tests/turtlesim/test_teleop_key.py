"""turtle_teleop_key without a terminal: key names on /teleop_turtle/_key drive turtlesim.

Both run as catalog nodes under the supervisor; the probe node (our runtime)
sends keys and watches the pose, as the dashboard's buttons will.
"""

from __future__ import annotations

import math
import os
import pty
import select
import subprocess
import sys
import threading
import time

import pytest
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import String
from turtlesim.msg import Pose
from turtlesim.srv import Spawn

from app import PROJECT_ROOT
from tests.conftest import wait_until
from tests.integration.core_helpers import (
    DISCOVERY_TIMEOUT,
    call_service,
    node_names,
    wait_for_output,
)

pytestmark = pytest.mark.ros


class PoseWatcher:
    def __init__(self, node, topic: str) -> None:
        self.lock = threading.Lock()
        self.last: Pose | None = None
        qos = QoSProfile(depth=7, reliability=ReliabilityPolicy.RELIABLE)
        node.create_subscription(Pose, topic, self.on_pose, qos)

    def on_pose(self, msg: Pose) -> None:
        with self.lock:
            self.last = msg

    def pose(self) -> Pose | None:
        with self.lock:
            return self.last


def _press_until(keys, key: str, seen, tries: int = 5):
    """Press ``key`` until ``seen()`` holds. Teleop's /turtle1/cmd_vel publisher may not
    have matched turtlesim yet on a busy machine: that first Twist is lost and the turtle
    has not moved, so pressing again measures the same thing."""
    for _ in range(tries - 1):
        keys.publish(String(data=key))
        deadline = time.monotonic() + 3.0
        while time.monotonic() < deadline:
            if value := seen():
                return value
            time.sleep(0.05)
    keys.publish(String(data=key))
    return wait_until(seen, what=f"the turtle to answer {key!r}")


def test_keys_drive_rotate_and_cancel(supervisor, probe):
    supervisor.start("turtlesim_node")
    supervisor.start("turtle_teleop_key")
    wait_until(
        lambda: {"/turtlesim", "/teleop_turtle"} <= node_names(probe),
        timeout=DISCOVERY_TIMEOUT,
        what="turtlesim and teleop in the graph",
    )
    wait_for_output(supervisor, "turtle_teleop_key", "Use arrow keys to move the turtle.")
    watcher = PoseWatcher(probe.node, "/turtle1/pose")
    keys = probe.node.create_publisher(String, "/teleop_turtle/_key", 10)
    wait_until(lambda: watcher.pose(), timeout=DISCOVERY_TIMEOUT, what="a pose")
    wait_until(lambda: keys.get_subscription_count() > 0, what="teleop's key subscription")

    moving = _press_until(keys, "up", lambda: (p := watcher.pose()) and p.linear_velocity > 0 and p)
    assert moving.linear_velocity == pytest.approx(2.0)  # scale_linear 2.0: 2 m/s for 1 s
    stopped = wait_until(lambda: (p := watcher.pose()) and p.linear_velocity == 0 and p)
    assert stopped.x - 5.544445 == pytest.approx(2.0, abs=0.1)

    keys.publish(String(data="r"))  # rotate to 90 degrees
    wait_until(lambda: (p := watcher.pose()) and p.angular_velocity > 0, what="turning")
    turned = wait_until(
        lambda: (p := watcher.pose()) and p.angular_velocity == 0 and p, what="rotation done"
    )
    assert turned.theta == pytest.approx(math.pi / 2, abs=0.02)
    wait_for_output(supervisor, "turtlesim_node", "Rotation goal completed successfully")

    keys.publish(String(data="v"))  # to -90 degrees: a half turn, 3 s
    wait_until(lambda: (p := watcher.pose()) and p.angular_velocity != 0, what="turning again")
    keys.publish(String(data="F"))  # cancel (upper case works too)
    wait_for_output(supervisor, "turtlesim_node", "Rotation goal canceled")
    halted = wait_until(lambda: (p := watcher.pose()) and p.angular_velocity == 0 and p)
    assert -math.pi / 2 + 0.1 < halted.theta < turned.theta - 0.01  # stopped on the way

    # F right after a goal key: teleop has not had the goal's answer yet (ci102, one core
    # busy: the turtle was already turning when F came, and teleop cancelled the goal before,
    # long done). The goal is cancelled once its answer arrives.
    keys.publish(String(data="g"))  # to 0 degrees, over a radian away
    keys.publish(String(data="f"))
    wait_until(
        lambda: "\n".join(supervisor.output("turtlesim_node")).count("Rotation goal canceled") == 2,
        timeout=30,
        what=lambda: f"a second cancel; turtlesim said {supervisor.output('turtlesim_node')[-4:]}",
    )
    stopped_early = wait_until(lambda: (p := watcher.pose()) and p.angular_velocity == 0 and p)
    assert stopped_early.theta > 0.1, "the rotation ran to its end"


def test_remapped_teleop_drives_a_spawned_turtle(supervisor, probe):
    """``--ros-args -r turtle1/cmd_vel:=turtle2/cmd_vel`` as the tutorials do, really applied."""
    supervisor.start("turtlesim_node")
    supervisor.start(
        "turtle_teleop_key",
        ["-r", "__node:=teleop2", "-r", "turtle1/cmd_vel:=turtle2/cmd_vel"],
    )
    wait_until(
        lambda: {"/turtlesim", "/teleop2"} <= node_names(probe),
        timeout=DISCOVERY_TIMEOUT,
        what="turtlesim and the renamed teleop",
    )
    reply = call_service(probe, Spawn, "/spawn", Spawn.Request(x=2.0, y=2.0, name=""))
    assert reply.name == "turtle2"
    turtle1 = PoseWatcher(probe.node, "/turtle1/pose")
    turtle2 = PoseWatcher(probe.node, "/turtle2/pose")
    keys = probe.node.create_publisher(String, "/teleop2/_key", 10)
    wait_until(lambda: turtle2.pose() and turtle1.pose(), timeout=DISCOVERY_TIMEOUT)
    wait_until(lambda: keys.get_subscription_count() > 0, what="teleop2's key subscription")
    keys.publish(String(data="up"))
    wait_until(lambda: (p := turtle2.pose()) and p.linear_velocity > 0, what="turtle2 moving")
    assert turtle1.pose().linear_velocity == 0.0 and turtle1.pose().x == pytest.approx(5.544445)


def test_in_a_terminal_arrow_keys_drive_and_q_quits(supervisor, probe, ros_env):
    """Run in a terminal (a pseudo-terminal here), it reads raw keys as upstream does."""
    supervisor.start("turtlesim_node")
    watcher = PoseWatcher(probe.node, "/turtle1/pose")
    wait_until(lambda: watcher.pose(), timeout=DISCOVERY_TIMEOUT, what="a pose")
    master, terminal = pty.openpty()
    teleop = subprocess.Popen(
        [sys.executable, "-m", "nodes.turtle_teleop_key"],
        cwd=PROJECT_ROOT,
        env=ros_env,
        stdin=terminal,
        stdout=terminal,
        stderr=terminal,
        start_new_session=True,
    )
    os.close(terminal)
    try:
        wait_until(
            lambda: "/teleop_turtle" in node_names(probe),
            timeout=DISCOVERY_TIMEOUT,
            what="the teleop node",
        )

        def press_up() -> Pose | None:
            """The up arrow's escape sequence, again until turtlesim has matched teleop."""
            os.write(master, b"\x1b[A")
            time.sleep(0.3)
            pose = watcher.pose()
            return pose if pose and pose.linear_velocity > 0 else None

        moving = wait_until(press_up, timeout=DISCOVERY_TIMEOUT, what="the turtle to move")
        assert moving.linear_velocity == pytest.approx(2.0)
        os.write(master, b"q")
        assert teleop.wait(timeout=10) == 0
        shown = b""
        while select.select([master], [], [], 0.2)[0]:
            try:
                shown += os.read(master, 4096)
            except OSError:  # the terminal closed with the process
                break
        assert b"Use arrow keys to move the turtle." in shown
    finally:
        if teleop.poll() is None:
            teleop.kill()
            teleop.wait()
        os.close(master)
