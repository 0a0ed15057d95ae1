"""What lesson checks subscribe to ends when no check reads it any more.

A simulation step's checks listen to /clock (100-200 messages a second at 1-2x);
once the learner has moved on to a step without them, the dashboard must stop
listening, not keep the subscription for as long as it runs.
"""

from __future__ import annotations

import time

import pytest

from app.lessons.runtime import IDLE_SEC, PASS
from app.lessons.schema import Spec
from tests.conftest import wait_until
from tests.sim.test_sim_speed_under_load import lessons  # noqa: F401 (fixture)

pytestmark = pytest.mark.ros

SIM_STEP = [
    Spec("sim_time_factor", {"requested": 1.0}),
    Spec("topic_messages", {"topic": "/odom", "type": "nav_msgs/msg/Odometry", "at_least": 1}),
]
OTHER_STEP = Spec("quiz", {"question": "2+2?", "options": ["3", "4"], "answer": "4"})


def test_a_step_s_subscriptions_end_once_the_learner_moved_on(lessons, supervisor):  # noqa: F811
    node = lessons.node
    supervisor.start("sim_world", ["-p", "camera_rate:=0.0"])
    wait_until(lambda: lessons.graph.has_node("/sim_world"), timeout=30, what="/sim_world")
    ours = {"/clock": 1, "/odom": 1}  # the world subscribes to neither
    wait_until(
        lambda: all(lessons.evaluate(c).state == PASS for c in SIM_STEP),
        timeout=30,
        interval=0.2,
        what=lambda: str([lessons.evaluate(c).reason for c in SIM_STEP]),
    )
    for topic, count in ours.items():
        assert node.count_subscribers(topic) == count, topic
    # The learner reads the next step: its checks are looked at, these are not.
    moved_on = time.monotonic()
    while time.monotonic() - moved_on < IDLE_SEC - 2:
        lessons.evaluate(OTHER_STEP)
        time.sleep(0.2)
    assert node.count_subscribers("/clock") == 1, "released before IDLE_SEC"
    # Each ends a sweep after its own last read: the /odom tap was read after /clock's
    # watch (ci76: still there the moment /clock's ended, at load 12), so wait for all.
    released = ("/clock", "/odom", "/real_time_factor")
    wait_until(
        lambda: (
            lessons.evaluate(OTHER_STEP)
            and all(node.count_subscribers(topic) == 0 for topic in released)
        ),
        timeout=8,
        interval=0.2,
        what=lambda: (
            f"every subscription to end: {[(t, node.count_subscribers(t)) for t in released]}"
        ),
    )
    # Back to the step: its checks listen again.
    lessons.evaluate(SIM_STEP[0])
    assert node.count_subscribers("/clock") == 1
