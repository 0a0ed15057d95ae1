"""What every blocking ROS call gets: the node, where to write, how long, when to stop.

Blocking calls run on a worker thread (the CLI's main thread, a console
worker, a panel job) while the node is spun by the runtime's executor thread.
They therefore wait on futures with bounded timeouts and never spin.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field

from rclpy.node import Node

from app.ros.errors import Cancelled

Write = Callable[[str], None]


@dataclass
class Limits:
    """How long calls may take: unbounded streams on the CLI, bounded in the browser."""

    max_messages: int | None = None  # echo: stop after this many messages
    max_seconds: float | None = None  # echo/hz/bw/pub -r: stop after this long
    service_timeout: float = 5.0  # waiting for a server, and for its answer
    action_timeout: float = 60.0  # waiting for an action's result
    discovery_wait: float = 0.0  # CLI: let a fresh node discover the graph first


CONSOLE_LIMITS = Limits(max_messages=10, max_seconds=5.0, action_timeout=30.0)
CLI_LIMITS = Limits(discovery_wait=4.0)


def _discard(_line: str) -> None:
    """Panels show results themselves; a call's progress lines go nowhere."""


@dataclass
class CallContext:
    """The node to work through, where to write, the limits, and a cancel flag."""

    node: Node
    write: Write = _discard
    limits: Limits = field(default_factory=Limits)
    cancel: threading.Event = field(default_factory=threading.Event)
    # What starts programs for `ros2 run` (the dashboard's supervisor, given by
    # the Console); None on the command line. Only ``object`` here: the ROS layer knows no
    # supervisor (app.ros2cli.run.programs_of reads it as one).
    programs: object = None

    def sleep(self, seconds: float) -> None:
        """Sleep that wakes up (and raises) when the call is cancelled."""
        if self.cancel.wait(seconds):
            raise Cancelled()

    def check_cancel(self) -> None:
        if self.cancel.is_set():
            raise Cancelled()


def panel_context(node: Node) -> CallContext:
    """A context for one panel job: browser limits, output discarded."""
    return CallContext(node, _discard, CONSOLE_LIMITS)
