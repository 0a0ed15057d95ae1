"""rclpy's Node without a participant, for judging a learner's node offline over many seeds.

The ``stand_in`` fixture (tests/exercises/conftest.py) puts it in place.

The offline exercise tests (``test_*_offline.py``) load a solution file, build its node on
this stand-in (its subscriptions are called by hand, what it publishes is kept by topic)
and judge what it publishes as the live probe does. Nothing here starts DDS; the live
grading of one seed is test_grading's.
"""

from __future__ import annotations

import importlib.util
import types
from pathlib import Path


class KeptPublisher:
    """A publisher that keeps what it was given, with the QoS it was made with."""

    def __init__(self, qos) -> None:
        self.qos = qos
        self.sent: list = []

    def publish(self, msg) -> None:
        self.sent.append(msg)


def load_solution(path: Path, prefix: str) -> types.ModuleType:
    """A solution file as a module of its own (named ``prefix_<file stem>``)."""
    spec = importlib.util.spec_from_file_location(f"{prefix}_{path.stem}", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def node_of(module: types.ModuleType):
    """An instance of the module's one Node subclass, built on the stand-in."""
    from rclpy.node import Node

    [cls] = [
        v
        for v in vars(module).values()
        if isinstance(v, type) and issubclass(v, Node) and v is not Node
    ]
    return cls()
