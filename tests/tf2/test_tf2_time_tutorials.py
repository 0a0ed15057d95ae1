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

import pytest
import yaml

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


def pose(console, turtle: str) -> tuple[float, float]:  # noqa: F811
    out = ok(console, f"ros2 topic echo --once /{turtle}/pose")
    data = yaml.safe_load("\n".join(out[: out.index("---")]))
    return data["x"], data["y"]


def near(console, turtle: str, point: tuple[float, float], within: float) -> bool:  # noqa: F811
    return math.dist(pose(console, turtle), point) < within


def test_carrot_demo_launch_files(console, probe, supervisor):  # noqa: F811
    ok(console, "ros2 launch learning_tf2_py turtle_tf2_fixed_frame_demo.launch.py")
    wait_until(
        lambda: {"/sim", "/listener", "/fixed_broadcaster"} <= set(node_names(probe)),
        timeout=DISCOVERY_TIMEOUT,
        what="the fixed-frame demo's nodes",
    )
    wait_until(
        lambda: "/turtle2/pose" in dict(probe.node.get_topic_names_and_types()),
        timeout=DISCOVERY_TIMEOUT,
        what="turtle2",
    )
    # turtle1 stands still: turtle2 comes to rest on carrot1, 2 m to its left
    wait_until(
        lambda: near(console, "turtle2", CARROT, 0.5),
        timeout=40,
        what=lambda: f"turtle2 at carrot1 {CARROT}: {pose(console, 'turtle2')}",
    )
    ok(console, "ros2 launch --stop learning_tf2_py turtle_tf2_fixed_frame_demo.launch.py")

    ok(console, "ros2 launch turtle_tf2_py turtle_tf2_dynamic_frame_demo.launch.py")
    wait_until(
        lambda: "/dynamic_broadcaster" in node_names(probe),
        timeout=DISCOVERY_TIMEOUT,
        what="the dynamic-frame demo's broadcaster",
    )
    wait_until(
        lambda: "/turtle2/pose" in dict(probe.node.get_topic_names_and_types()),
        timeout=DISCOVERY_TIMEOUT,
        what="turtle2",
    )
    # carrot1 circles turtle1 at 10 m: turtle2 keeps chasing it, so it keeps moving
    seen = [pose(console, "turtle2")]
    wait_until(
        lambda: seen.append(pose(console, "turtle2")) or math.dist(seen[0], seen[-1]) > 2.0,
        timeout=30,
        what=lambda: f"turtle2 chasing the moving carrot: {seen[-3:]}",
    )
    ok(console, "ros2 launch --stop turtle_tf2_py turtle_tf2_dynamic_frame_demo.launch.py")


def test_using_time_and_traveling_in_time(console, probe, supervisor):  # noqa: F811
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
        assert near(console, "turtle2", (4.0, 2.0), 0.01)  # spawned, never driven
        ok(console, "ros2 run --stop /listener")

        # Using time, 2: a 50 ms timeout lets the data arrive; turtle2 follows turtle1.
        ok(console, "ros2 run learning_tf2_py turtle_tf2_listener_wait")
        wait_until(
            lambda: near(console, "turtle2", (CENTRE, CENTRE), 1.0),
            timeout=40,
            what=lambda: f"turtle2 to reach turtle1: {pose(console, 'turtle2')}",
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
            lambda: near(console, "turtle2", CARROT, 0.5),
            timeout=40,
            what=lambda: f"turtle2 at carrot1's past spot {CARROT}: {pose(console, 'turtle2')}",
        )
        ok(console, "ros2 run --stop /listener")
        ok(console, "ros2 run --stop /fixed_frame_tf2_broadcaster")
    finally:
        for name in ("tf2_demo_broadcaster2", "tf2_demo_broadcaster1", "tf2_demo_sim"):
            supervisor.stop(name).result(timeout=10)
