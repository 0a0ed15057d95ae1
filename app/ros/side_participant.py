"""A second ROS participant on another domain: one context, one node, one executor thread.

A learner's dashboard lives in the learner's own ROS domain, so that nobody's
nodes show up in anybody else's graph. The classroom's shared traffic (each
learner's progress, the teacher's notices) needs a domain that every learner
and the teacher share. Rather than open that domain to the learner's nodes,
the dashboard joins it with a separate, small participant: its node serves
no parameters and writes no /rosout, so the shared domain carries only the
classroom's own topics.
"""

from __future__ import annotations

import threading

import rclpy
from rclpy.context import Context
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from app.dds import validate_domain_id


class SideParticipant:
    """``node`` on ``domain_id``, spun by its own executor thread until ``shutdown``."""

    def __init__(self, node_name: str, domain_id: int) -> None:
        self.domain_id = validate_domain_id(domain_id)
        self.context = Context()
        rclpy.init(
            context=self.context,
            domain_id=domain_id,
            signal_handler_options=SignalHandlerOptions.NO,
        )
        self.node = Node(
            node_name,
            context=self.context,
            start_parameter_services=False,
            enable_rosout=False,
        )
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin, name=f"ros-{node_name}", daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        try:
            self.executor.spin()
        except (ExternalShutdownException, KeyboardInterrupt):
            pass

    def shutdown(self, timeout: float = 2.0) -> None:
        """Executor first, then the node, then the context (as the main runtime does)."""
        self.executor.shutdown(timeout_sec=timeout)
        self._thread.join(timeout)
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
