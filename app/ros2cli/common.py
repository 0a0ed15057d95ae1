"""Shared pieces of the verbs: errors, output, limits, waiting on futures.

Verbs run on a worker thread (the CLI's main thread or a console worker)
while the node is spun by the runtime's executor thread. They therefore wait
on futures with bounded timeouts through a threading.Event, and never spin.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from rclpy.node import Node
from rclpy.task import Future


class Ros2Error(Exception):
    """A problem the learner can fix; shown as one line, never a traceback."""


class Cancelled(Exception):
    """The learner pressed Stop (or Ctrl+C) while a verb was running."""


Write = Callable[[str], None]


@dataclass
class Limits:
    """How long streaming verbs may run: unbounded on the CLI, bounded in the browser."""

    max_messages: int | None = None  # echo: stop after this many messages
    max_seconds: float | None = None  # echo/hz/bw/pub -r: stop after this long
    service_timeout: float = 5.0  # waiting for a server, and for its answer
    action_timeout: float = 60.0  # waiting for an action's result
    discovery_wait: float = 0.0  # CLI: let a fresh node discover the graph first


CONSOLE_LIMITS = Limits(max_messages=10, max_seconds=5.0, action_timeout=30.0)
CLI_LIMITS = Limits(discovery_wait=4.0)
MIN_DISCOVERY_SEC = 1.5


@dataclass
class VerbContext:
    """What every verb gets: the node to work through, where to write, when to stop."""

    node: Node
    write: Write
    limits: Limits = field(default_factory=Limits)
    cancel: threading.Event = field(default_factory=threading.Event)

    def sleep(self, seconds: float) -> None:
        """Sleep that wakes up (and raises) when the verb is cancelled."""
        if self.cancel.wait(seconds):
            raise Cancelled()

    def check_cancel(self) -> None:
        if self.cancel.is_set():
            raise Cancelled()


def wait_future(ctx: VerbContext, future: Future, timeout: float, what: str) -> Any:
    """Block this (non-executor) thread until ``future`` is done, bounded and cancellable."""
    done = threading.Event()
    future.add_done_callback(lambda _f: done.set())
    deadline = time.monotonic() + timeout
    while not done.wait(0.05):
        if ctx.cancel.is_set():
            future.cancel()
            raise Cancelled()
        if time.monotonic() > deadline:
            future.cancel()
            raise Ros2Error(f"no answer from {what} within {timeout:g} s")
    exc = future.exception()
    if exc is not None:
        raise Ros2Error(f"{what} failed: {exc}")
    return future.result()


def wait_for_server(ctx: VerbContext, is_ready: Callable[[], bool], timeout: float, what: str):
    """Poll ``is_ready`` (service_is_ready / server_is_ready) until true or timeout."""
    deadline = time.monotonic() + timeout
    while not is_ready():
        if time.monotonic() > deadline:
            raise Ros2Error(f"{what} is not available (waited {timeout:g} s)")
        ctx.sleep(0.1)


def split_node_name(fqn: str) -> tuple[str, str]:
    """'/ns/name' -> ('name', '/ns'); 'name' -> ('name', '/')."""
    if not fqn.startswith("/"):
        fqn = "/" + fqn
    namespace, _, name = fqn.rpartition("/")
    return name, namespace or "/"


def node_fqn(name: str, namespace: str) -> str:
    return f"{namespace.rstrip('/')}/{name}"


def all_nodes(node: Node, include_hidden: bool = False) -> list[str]:
    names = sorted(node_fqn(n, ns) for n, ns in node.get_node_names_and_namespaces())
    if include_hidden:
        return names
    return [n for n in names if not n.rsplit("/", 1)[-1].startswith("_")]


def require_node(ctx: VerbContext, fqn: str) -> tuple[str, str]:
    """The (name, namespace) of a node on the graph, or one clear error."""
    if not fqn.startswith("/"):
        fqn = "/" + fqn
    if not wait_for_graph(ctx, lambda: fqn in all_nodes(ctx.node, include_hidden=True)):
        raise Ros2Error(f"node '{fqn}' is not on the graph (see `ros2 node list`)")
    return split_node_name(fqn)


def wait_for_graph(ctx: VerbContext, present: Callable[[], bool]) -> bool:
    """True once ``present()``; a fresh CLI node keeps looking for ``discovery_wait`` s."""
    deadline = time.monotonic() + ctx.limits.discovery_wait
    while not present():
        if time.monotonic() >= deadline:
            return False
        ctx.sleep(0.1)
    return True


def settle_discovery(ctx: VerbContext) -> None:
    """A brand-new node sees the graph piece by piece: wait until it stops changing."""
    if ctx.limits.discovery_wait <= 0:
        return
    # Participants are found before their endpoints: insist on a minimum look
    # (as `ros2 ... --no-daemon` spins a while) and then on a quiet second.
    started = time.monotonic()
    deadline = started + ctx.limits.discovery_wait
    last: tuple[int, int, int] | None = None
    stable_since = started
    while time.monotonic() < deadline:
        node = ctx.node
        now = (
            len(node.get_node_names_and_namespaces()),
            len(node.get_topic_names_and_types()),
            len(node.get_service_names_and_types()),
        )
        if now != last:
            last, stable_since = now, time.monotonic()
        elif (
            now[0] > 1
            and time.monotonic() - started > MIN_DISCOVERY_SEC
            and time.monotonic() - stable_since > 1.0
        ):
            return
        ctx.sleep(0.1)


ACTION_MARKER = "/_action/"
