"""Which subscribers no publisher can deliver to, asked of the real DDS graph.

The QoS lesson's point: a reliable subscription to a best-effort publisher
matches nothing, although both are on the same topic. The stage draws that
edge as a mismatch (app/stage/graph_stage.py) from ``undelivered``.
"""

from __future__ import annotations

import pytest
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

from app.ros.qos import undelivered
from app.ros.runtime import RosRuntime
from tests.conftest import wait_until

pytestmark = [pytest.mark.ros, pytest.mark.timeout(60)]

BEST_EFFORT = QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT)
RELIABLE = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
LATCHED = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)


def test_a_reliable_subscriber_of_a_best_effort_publisher_is_undelivered(probe):
    listener = RosRuntime("qos_listener_test")
    try:
        topic = "/qos_undelivered/chatter"
        assert undelivered(probe.node, topic) == {}  # nobody yet
        listener.node.create_subscription(String, topic, lambda _m: None, RELIABLE)
        wait_until(lambda: probe.node.count_subscribers(topic) == 1, what="the subscriber")
        assert undelivered(probe.node, topic) == {}  # no publisher: nothing to deliver
        probe.node.create_publisher(String, topic, BEST_EFFORT)
        wait_until(lambda: probe.node.count_publishers(topic) == 1, what="the publisher")
        wait_until(lambda: bool(undelivered(probe.node, topic)), what="the mismatch")
        found = undelivered(probe.node, topic)
        assert list(found) == ["/qos_listener_test"], found
        assert "Best effort publisher and reliable subscription" in found["/qos_listener_test"]
        # One publisher that can deliver is enough: a reliable one joins.
        probe.node.create_publisher(String, topic, RELIABLE)
        wait_until(lambda: probe.node.count_publishers(topic) == 2, what="the second publisher")
        assert undelivered(probe.node, topic) == {}

        # Durability: a transient-local subscription and a volatile publisher.
        latched_topic = "/qos_undelivered/map"
        listener.node.create_subscription(String, latched_topic, lambda _m: None, LATCHED)
        probe.node.create_publisher(String, latched_topic, RELIABLE)
        wait_until(lambda: bool(undelivered(probe.node, latched_topic)), what="the mismatch")
        why = undelivered(probe.node, latched_topic)["/qos_listener_test"]
        assert why == "Volatile publisher and transient local subscription", why
    finally:
        listener.shutdown()
