"""One picked topic at a time: the subscription behind a scene layer's dropdown.

Threads (see ``app.ui``): only the UI thread switches topics (the panel posts
an intent), so a follower's subscription needs no lock. The executor thread
only hands messages to ``deliver`` (by default the layer's
:class:`LatestWorker`), and the worker thread may read ``topic``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Generic, TypeVar

from rclpy.node import Node
from rclpy.qos import QoSProfile
from rclpy.subscription import Subscription

from app.scene.latest import LatestWorker
from app.scene.qos import SCENE_CALLBACK_GROUP, newest_only_qos
from app.scene.topic_picker import NONE

M = TypeVar("M")  # the topic's messages (their generated classes are untyped)


class TopicFollower(Generic[M]):
    """A scene layer's one subscription: which topic it follows, its messages into a worker.

    ``qos`` defaults to :func:`newest_only_qos`, asked afresh for each topic.
    ``on_switch(topic)`` runs once the old subscription is gone and before the
    new one exists: there the layer forgets what it drew of the old topic.
    """

    def __init__(
        self,
        node: Node,
        worker: LatestWorker,  # draws the messages (with ``deliver``: what the layer offers it)
        msg_type: type[M],
        *,
        qos: QoSProfile | int | None = None,
        deliver: Callable[[M], None] | None = None,
        on_switch: Callable[[str], None] | None = None,
    ) -> None:
        self.worker = worker
        self.topic = NONE
        self._subscription: Subscription | None = None
        self._node = node
        self._msg_type = msg_type
        self._qos = qos
        self._deliver = deliver if deliver is not None else worker.offer
        self._on_switch = on_switch

    def select(self, topic: str, msg_type: type[M] | None = None) -> bool:
        """Follow ``topic`` ("(none)": nothing), dropping the old backlog; False if unchanged.

        ``msg_type`` overrides the type given at construction, for this topic.
        """
        if topic == self.topic:
            return False
        self.topic = topic
        if self._subscription is not None:
            self._node.destroy_subscription(self._subscription)
            self._subscription = None
        self.worker.reset()
        if self._on_switch is not None:
            self._on_switch(topic)
        if topic != NONE:
            qos = self._qos if self._qos is not None else newest_only_qos(self._node, topic)
            self._subscription = self._node.create_subscription(
                msg_type or self._msg_type,
                topic,
                self._deliver,
                qos,
                callback_group=SCENE_CALLBACK_GROUP,
            )
        return True

    def close(self) -> None:
        """Unsubscribe and stop the worker (on shutdown)."""
        self.select(NONE)
        self.worker.stop()


class OneTopicLayer:
    """What the layers that draw the one topic picked in a dropdown share."""

    def __init__(self, follower: TopicFollower) -> None:
        self._follower = follower
        self.worker = follower.worker  # the panel reads its stats for the liveness note

    @property
    def topic(self) -> str:
        return self._follower.topic

    def select(self, topic: str) -> None:
        """Draw ``topic`` from now on ("(none)": nothing). UI thread only."""
        self._follower.select(topic)

    def close(self) -> None:
        self.select(NONE)
        self._follower.close()
