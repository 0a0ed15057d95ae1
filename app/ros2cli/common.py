"""What only the command-line face needs: letting a brand-new node see the graph."""

from __future__ import annotations

import time

from app.ros.context import CallContext

MIN_DISCOVERY_SEC = 1.5


def write_names(ctx: CallContext, lines: list[str], count: bool = False) -> int:
    """A listing as the `ros2 ... list` verbs print it: one per line, or (-c) how many."""
    if count:
        ctx.write(str(len(lines)))
    for line in [] if count else lines:
        ctx.write(line)
    return 0


def settle_discovery(ctx: CallContext) -> None:
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
