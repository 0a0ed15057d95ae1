"""The tf2 tutorials' carrot launch files and their time tutorials, typed in the Console.

"Adding a frame" launches the fixed and the dynamic carrot demos (from
``turtle_tf2_py`` and from ``learning_tf2_py``, the package the tutorials have
the learner write); "Using time" and "Traveling in time" change the
listener's lookup (``nodes/turtle_tf2_listener_time.py``): ``now()`` fails
with tf2's "extrapolation into the future", a 50 ms timeout fixes it, a plain
lookup 5 s in the past starts with "extrapolation into the past", and
``lookup_transform_full`` brings turtle2 to where carrot1 was. Each is judged
by what a learner sees: the listener's log and where turtle2 goes.
"""

from __future__ import annotations

import math
import time

import pytest
from turtlesim.msg import Pose

from tests.conftest import wait_until
from tests.integration.core_helpers import DISCOVERY_TIMEOUT, node_names
from tests.turtlesim.test_ros2_run import console  # noqa: F401  (the Console fixture)

pytestmark = pytest.mark.ros

CENTRE = 5.544445  # turtle1's spawn point, facing +x: carrot1 (2 m to its left) is at y + 2
CARROT = (CENTRE, CENTRE + 2.0)


def ok(console, text: str) -> list[str]:  # noqa: F811
    code, out = console(text)
    assert code == 0, (text, out)
    return out


class Poses:
    """The newest pose of each turtle, from this test's own subscriptions (over DDS)."""

    def __init__(self, probe) -> None:
        self.newest: dict[str, tuple[float, float, float]] = {}  # turtle -> (time, x, y)
        self.since = 0.0
        for turtle in ("turtle1", "turtle2"):
            probe.node.create_subscription(
                Pose, f"/{turtle}/pose", lambda msg, t=turtle: self._on_pose(t, msg), 10
            )

    def _on_pose(self, turtle: str, msg: Pose) -> None:
        self.newest[turtle] = (time.monotonic(), msg.x, msg.y)

    def fresh(self) -> None:
        """From now on, only poses that arrive later count (a new turtlesim)."""
        self.since = time.monotonic()

    def __call__(self, turtle: str) -> tuple[float, float]:
        wait_until(
            lambda: self.newest.get(turtle, (0.0,))[0] > self.since,
            timeout=DISCOVERY_TIMEOUT,
            what=f"a pose of {turtle}",
        )
        _t, x, y = self.newest[turtle]
        return x, y

    def near(self, turtle: str, point: tuple[float, float], within: float) -> bool:
        return math.dist(self(turtle), point) < within


def test_carrot_demo_launch_files(console, probe, supervisor):  # noqa: F811
    pose = Poses(probe)
    ok(console, "ros2 launch learning_tf2_py turtle_tf2_fixed_frame_demo.launch.py")
    wait_until(
        lambda: {"/sim", "/listener", "/fixed_broadcaster"} <= set(node_names(probe)),
        timeout=DISCOVERY_TIMEOUT,
        what="the fixed-frame demo's nodes",
    )
    # turtle1 stands still: turtle2 comes to rest on carrot1, 2 m to its left
    wait_until(
        lambda: pose.near("turtle2", CARROT, 0.5),
        timeout=40,
        what=lambda: f"turtle2 at carrot1 {CARROT}: {pose('turtle2')}",
    )
    ok(console, "ros2 launch --stop learning_tf2_py turtle_tf2_fixed_frame_demo.launch.py")
    wait_until(
        lambda: (
            not supervisor.status(
                "launch:learning_tf2_py/turtle_tf2_fixed_frame_demo.launch.py"
            ).active
        ),
        timeout=DISCOVERY_TIMEOUT,
        what="the fixed-frame demo to end",
    )
    pose.fresh()

    ok(console, "ros2 launch turtle_tf2_py turtle_tf2_dynamic_frame_demo.launch.py")
    wait_until(
        lambda: "/dynamic_broadcaster" in node_names(probe),
        timeout=DISCOVERY_TIMEOUT,
        what="the dynamic-frame demo's broadcaster",
    )
    # carrot1 circles turtle1 at 10 m: turtle2 keeps chasing it, so it keeps moving
    seen = [pose("turtle2")]
    wait_until(
        lambda: seen.append(pose("turtle2")) or math.dist(seen[0], seen[-1]) > 2.0,
        timeout=30,
        what=lambda: f"turtle2 chasing the moving carrot: {seen[-3:]}",
    )
    ok(console, "ros2 launch --stop turtle_tf2_py turtle_tf2_dynamic_frame_demo.launch.py")


def test_using_time_and_traveling_in_time(console, probe, supervisor):  # noqa: F811
    pose = Poses(probe)
    for name in ("tf2_demo_sim", "tf2_demo_broadcaster1", "tf2_demo_broadcaster2"):
        supervisor.start(name)
    try:
        # Using time, 1: the transform at now(), without waiting, is always just out of reach.
        ok(console, "ros2 run learning_tf2_py turtle_tf2_listener_now")
        wait_until(
            lambda: any(
                "[listener]: Could not transform turtle2 to turtle1: Lookup would require "
                "extrapolation into the future.  Requested time "
                in line
                and "when looking up transform from frame [turtle1] to frame [turtle2]" in line
                for line in supervisor.output("turtle_tf2_listener_now")
            ),
            timeout=DISCOVERY_TIMEOUT,
            what=lambda: f"the future error: {supervisor.output('turtle_tf2_listener_now')[-5:]}",
        )
        assert pose.near("turtle2", (4.0, 2.0), 0.01)  # spawned, never driven
        ok(console, "ros2 run --stop /listener")

        # Using time, 2: a 50 ms timeout lets the data arrive; turtle2 follows turtle1.
        ok(console, "ros2 run learning_tf2_py turtle_tf2_listener_wait")
        wait_until(
            lambda: pose.near("turtle2", (CENTRE, CENTRE), 1.0),
            timeout=40,
            what=lambda: f"turtle2 to reach turtle1: {pose('turtle2')}",
        )
        ok(console, "ros2 run --stop /listener")

        # Traveling in time: carrot1; the plain lookup 5 s back first has no such past.
        ok(console, "ros2 run learning_tf2_py fixed_frame_tf2_broadcaster")
        ok(console, "ros2 run learning_tf2_py turtle_tf2_listener_past")
        wait_until(
            lambda: any(
                "Could not transform turtle2 to carrot1: Lookup would require extrapolation "
                "into the past." in line
                for line in supervisor.output("turtle_tf2_listener_past")
            ),
            timeout=DISCOVERY_TIMEOUT,
            what=lambda: f"the past error: {supervisor.output('turtle_tf2_listener_past')[-5:]}",
        )
        ok(console, "ros2 run --stop /listener")
        # lookup_transform_full: carrot1 5 s ago (turtle1 stands still: where it is now)
        ok(console, "ros2 run learning_tf2_py turtle_tf2_listener_full")
        wait_until(
            lambda: pose.near("turtle2", CARROT, 0.5),
            timeout=40,
            what=lambda: f"turtle2 at carrot1's past spot {CARROT}: {pose('turtle2')}",
        )
        ok(console, "ros2 run --stop /listener")
        ok(console, "ros2 run --stop /fixed_frame_tf2_broadcaster")
    finally:
        for name in ("tf2_demo_broadcaster2", "tf2_demo_broadcaster1", "tf2_demo_sim"):
            supervisor.stop(name).result(timeout=10)
