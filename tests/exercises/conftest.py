"""Fixtures of the exercise tests."""

from __future__ import annotations

import types

import pytest

from tests.exercises.stand_in_node import KeptPublisher


@pytest.fixture
def stand_in(monkeypatch):
    """rclpy's Node without a participant: subscriptions and publishers kept by topic."""
    from rclpy.node import Node

    def init(self, name, *args, **kwargs):
        self.handlers, self.publishers_by_topic = {}, {}

    def create_publisher(self, _type, topic, qos, *args, **kwargs):
        self.publishers_by_topic[topic] = KeptPublisher(qos)
        return self.publishers_by_topic[topic]

    def create_subscription(self, _type, topic, callback, _qos, *args, **kwargs):
        self.handlers[topic] = callback

    logger = types.SimpleNamespace(info=lambda *_a: None, warn=lambda *_a: None)
    monkeypatch.setattr(Node, "__init__", init)
    monkeypatch.setattr(Node, "create_publisher", create_publisher)
    monkeypatch.setattr(Node, "create_subscription", create_subscription)
    monkeypatch.setattr(Node, "get_logger", lambda self: logger)
