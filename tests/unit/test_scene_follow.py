"""TopicFollower: the one subscription behind each 3D-view dropdown (a fake node, no ROS graph)."""

from __future__ import annotations

import threading
from types import SimpleNamespace

import pytest
from rclpy.qos import QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import Image, JointState

from app.scene.follow import TopicFollower
from app.scene.latest import LatestWorker
from app.scene.qos import SCENE_CALLBACK_GROUP
from app.scene.topic_picker import NONE


class FakeNode:
    """Records subscriptions made and destroyed, in order."""

    def __init__(self, *reliabilities: ReliabilityPolicy) -> None:
        self.events: list[tuple[str, str]] = []
        self.live: list[SimpleNamespace] = []
        self._publishers = [
            SimpleNamespace(qos_profile=SimpleNamespace(reliability=r)) for r in reliabilities
        ]

    def get_publishers_info_by_topic(self, topic: str) -> list[SimpleNamespace]:
        return self._publishers

    def create_subscription(self, msg_type, topic, callback, qos, *, callback_group=None):
        sub = SimpleNamespace(
            msg_type=msg_type, topic=topic, callback=callback, qos=qos, group=callback_group
        )
        self.events.append(("create", topic))
        self.live.append(sub)
        return sub

    def destroy_subscription(self, sub: SimpleNamespace) -> None:
        self.events.append(("destroy", sub.topic))
        self.live.remove(sub)


@pytest.fixture
def worker():
    w = LatestWorker("test-follow", lambda _msg: None, 1000.0)
    yield w
    w.stop()


def test_follows_one_topic_at_a_time_and_only_switches_on_a_change(worker):
    node = FakeNode()
    follower = TopicFollower(node, worker, JointState, qos=10)
    assert follower.topic == NONE and not node.live

    assert follower.select("/a") is True
    (sub,) = node.live
    assert (sub.topic, sub.msg_type, sub.qos) == ("/a", JointState, 10)
    assert sub.group is SCENE_CALLBACK_GROUP
    assert sub.callback == worker.offer

    assert follower.select("/a") is False
    assert node.events == [("create", "/a")]

    assert follower.select("/b") is True
    assert node.events == [("create", "/a"), ("destroy", "/a"), ("create", "/b")]
    assert [s.topic for s in node.live] == ["/b"] and follower.topic == "/b"

    assert follower.select(NONE) is True
    assert not node.live and follower.topic == NONE


def test_switching_forgets_the_old_topic_before_the_new_one_is_heard(worker):
    node = FakeNode()
    switches: list[tuple[str, list[tuple[str, str]], int]] = []

    def on_switch(topic: str) -> None:
        switches.append((topic, list(node.events), worker.stats()[0]))

    follower = TopicFollower(node, worker, JointState, qos=10, on_switch=on_switch)
    follower.select("/a")
    node.live[0].callback(JointState())
    assert worker.stats()[0] == 1
    follower.select("/b")
    # the old subscription is gone and the worker's count is reset; the new one does not exist yet
    assert switches[-1] == ("/b", [("create", "/a"), ("destroy", "/a")], 0)
    assert node.events[-1] == ("create", "/b")


def test_default_qos_is_reliable_only_when_every_publisher_is(worker):
    mixed = FakeNode(ReliabilityPolicy.RELIABLE, ReliabilityPolicy.BEST_EFFORT)
    TopicFollower(mixed, worker, Image).select("/img")
    qos = mixed.live[0].qos
    assert isinstance(qos, QoSProfile) and qos.depth == 1
    assert qos.reliability == ReliabilityPolicy.BEST_EFFORT

    reliable = FakeNode(ReliabilityPolicy.RELIABLE)
    TopicFollower(reliable, worker, Image).select("/img")
    assert reliable.live[0].qos.reliability == ReliabilityPolicy.RELIABLE


def test_a_per_topic_type_and_delivery_callback(worker):
    node = FakeNode()
    got: list[object] = []
    follower = TopicFollower(node, worker, Image, qos=10, deliver=got.append)
    follower.select("/joints", JointState)
    assert node.live[0].msg_type is JointState
    node.live[0].callback("msg")
    assert got == ["msg"] and worker.stats()[0] == 0


def test_close_unsubscribes_and_stops_the_worker():
    node = FakeNode()
    worker = LatestWorker("test-follow-close", lambda _msg: None, 1000.0)
    follower = TopicFollower(node, worker, JointState, qos=10)
    follower.select("/a")
    follower.close()
    assert not node.live and follower.topic == NONE
    assert "scene-test-follow-close" not in [t.name for t in threading.enumerate()]


def test_a_poke_is_drawn_but_is_not_a_message_received():
    """A layer's own "look again" (the marker layer takes an old topic's markers away on a
    switch) is drawn, but it must not read as a message: the 3D view's empty-scene hint
    goes once any layer has received one."""
    drawn = threading.Event()
    worker = LatestWorker("test-poke", lambda _token: drawn.set(), 1000.0)
    try:
        worker.poke(True)
        assert drawn.wait(5.0), "the poke was never drawn"
        received, _drawn, rate, since = worker.stats()
        assert (received, rate, since) == (0, None, None)
        worker.offer(True)
        assert worker.stats()[0] == 1
    finally:
        worker.stop()
