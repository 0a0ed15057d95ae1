"""What one Foxglove client may cost the dashboard: sizes, rates and counts, all bounded.

The WebSocket server accepts anyone who reaches its port, and a client is a
program: it may send garbage, subscribe to every topic or publish as fast as
its socket goes. Everything it can make us hold or do has a ceiling here, so
a bad client is refused or slowed down and the dashboard goes on. Plain
values and checks; no ROS, no server.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable
from dataclasses import dataclass

# 'pkg/msg/Name' (ROS 2, as Foxglove names ROS 2 schemas) or 'pkg/Name' (as ROS 1 and
# the nested types of a ros2msg definition name them).
_TYPE_NAME = re.compile(r"^([A-Za-z][A-Za-z0-9_]*)/(?:msg/)?([A-Za-z][A-Za-z0-9_]*)$")


@dataclass(frozen=True)
class BridgeLimits:
    """Ceilings for one bridge; the defaults suit one learner with a few Foxglove windows."""

    # Topics advertised as channels at once (a graph bigger than this is cut, and said).
    max_channels: int = 256
    # ROS subscriptions at once, for all clients together: "subscribe to everything"
    # gets this many topics, the rest refused and said.
    max_subscriptions: int = 64
    # A ROS message bigger than this is not forwarded (a 4k point cloud is about 2 MB).
    max_forward_bytes: int = 16 * 1024 * 1024
    # Messages queued for one client that reads too slowly; the oldest go first.
    client_backlog: int = 64
    # Channels one client may advertise for publishing, and ROS publishers in all.
    max_client_channels: int = 16
    max_publishers: int = 32
    # One message a client publishes (a Twist is 52 bytes of CDR).
    max_client_message_bytes: int = 64 * 1024
    # Messages per second one client channel may publish, and the burst allowed at once.
    publish_rate_hz: float = 50.0
    publish_burst: int = 25
    # Client messages waiting for the bridge's thread; when full, the oldest are dropped.
    pending_messages: int = 256
    # How often the graph is read, and how long a topic may be gone before its channel goes.
    refresh_sec: float = 0.5
    gone_after_sec: float = 2.0
    # The same refusal is said to clients at most this often.
    repeat_note_sec: float = 2.0
    # ROS services advertised at once (the rest are left out, and said).
    max_services: int = 128
    # Service calls waiting for their answer: per client, and for all clients together.
    # Each one holds a thread of the server's blocking pool until it ends.
    calls_per_client: int = 4
    max_calls: int = 16
    # One request's bytes (an AddTwoInts request is 20), and how long a call may take.
    max_request_bytes: int = 64 * 1024
    call_timeout_sec: float = 5.0
    # Nodes whose parameters are cached (three ROS clients each), the parameters read per
    # node, how often they are read again, and parameter sets waiting to be applied.
    max_parameter_nodes: int = 32
    max_parameters_per_node: int = 256
    parameter_refresh_sec: float = 5.0
    pending_parameter_sets: int = 64


def ros_message_type(schema_name: str) -> str | None:
    """'geometry_msgs/msg/Twist' for 'geometry_msgs/msg/Twist' or 'geometry_msgs/Twist'.

    None for anything else (a service or action type, a path, garbage).
    """
    found = _TYPE_NAME.match(schema_name.strip()) if isinstance(schema_name, str) else None
    return f"{found[1]}/msg/{found[2]}" if found else None


class RateLimit:
    """A token bucket: ``rate`` events a second on average, ``burst`` at once."""

    def __init__(
        self, rate: float, burst: int, clock: Callable[[], float] = time.monotonic
    ) -> None:
        self._rate = rate
        self._burst = float(burst)
        self._clock = clock
        self._tokens = float(burst)
        self._last = clock()

    def allow(self) -> bool:
        """Take one token if there is one."""
        now = self._clock()
        self._tokens = min(self._burst, self._tokens + (now - self._last) * self._rate)
        self._last = now
        if self._tokens >= 1.0:
            self._tokens -= 1.0
            return True
        return False


class NoteThrottle:
    """Says each distinct note at most once per ``every`` seconds (remembers a bounded set)."""

    def __init__(
        self, every: float, remember: int = 256, clock: Callable[[], float] = time.monotonic
    ) -> None:
        self._every = every
        self._remember = remember
        self._clock = clock
        self._said: dict[str, float] = {}

    def due(self, note: str) -> bool:
        now = self._clock()
        last = self._said.get(note)
        if last is not None and now - last < self._every:
            return False
        if len(self._said) >= self._remember:
            self._said = {k: t for k, t in self._said.items() if now - t < self._every}
            if len(self._said) >= self._remember:
                return False  # a flood of distinct notes: the rest wait
        self._said[note] = now
        return True
