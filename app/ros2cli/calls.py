"""One service call, one action goal: the blocking-but-bounded building blocks.

Run from a worker thread (never a viser callback, never the executor thread):
the request goes out with ``call_async`` and this thread waits on the future.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from action_msgs.msg import GoalStatus
from rclpy.action import ActionClient

from app.ros2cli.common import Cancelled, Ros2Error, VerbContext, wait_for_server, wait_future
from app.ros2cli.convert import import_type, type_name

STATUS_NAMES = {
    GoalStatus.STATUS_UNKNOWN: "UNKNOWN",
    GoalStatus.STATUS_ACCEPTED: "ACCEPTED",
    GoalStatus.STATUS_EXECUTING: "EXECUTING",
    GoalStatus.STATUS_CANCELING: "CANCELING",
    GoalStatus.STATUS_SUCCEEDED: "SUCCEEDED",
    GoalStatus.STATUS_CANCELED: "CANCELED",
    GoalStatus.STATUS_ABORTED: "ABORTED",
}


def service_types(ctx: VerbContext, name: str) -> list[str]:
    return next((list(t) for n, t in ctx.node.get_service_names_and_types() if n == name), [])


def check_service_type(ctx: VerbContext, name: str, srv_type: type) -> None:
    """When the service is on the graph with another type, say so instead of timing out."""
    types = service_types(ctx, name)
    if types and type_name(srv_type) not in types:
        raise Ros2Error(f"service '{name}' has type {', '.join(types)}, not {type_name(srv_type)}")


def call_service(
    ctx: VerbContext, name: str, srv_type: type, request: Any, timeout: float | None = None
) -> Any:
    """Send one request and return the response, or raise one clear Ros2Error."""
    timeout = ctx.limits.service_timeout if timeout is None else timeout
    check_service_type(ctx, name, srv_type)
    client = ctx.node.create_client(srv_type, name)
    try:
        wait_for_server(ctx, client.service_is_ready, timeout, f"service '{name}'")
        return wait_future(ctx, client.call_async(request), timeout, f"service '{name}'")
    finally:
        ctx.node.destroy_client(client)


def action_type_of(ctx: VerbContext, name: str) -> str | None:
    from rclpy.action import get_action_names_and_types

    for action, types in get_action_names_and_types(ctx.node):
        if action == name and types:
            return types[0]
    return None


@dataclass
class GoalRun:
    """A goal in flight: the panel reads it while a worker thread drives it."""

    action: str
    type_text: str
    goal: Any
    feedback: list[Any] = field(default_factory=list)
    status: str = "SENDING"
    result: Any = None
    error: str | None = None
    goal_id: str = ""
    done: threading.Event = field(default_factory=threading.Event)
    _handle: Any = None

    def cancel(self, ctx: VerbContext) -> None:
        """Ask the server to cancel; the final status arrives with the result."""
        handle = self._handle
        if handle is not None and not self.done.is_set():
            self.status = "CANCELING"
            handle.cancel_goal_async()


def send_goal(
    ctx: VerbContext,
    run: GoalRun,
    on_feedback: Callable[[Any], None] | None = None,
    on_accepted: Callable[[GoalRun], None] | None = None,
) -> GoalRun:
    """Drive ``run`` to its end: accepted or rejected, feedback, final status and result."""
    action_cls = import_type(run.type_text, "action")
    known = action_type_of(ctx, run.action)
    if known and known != type_name(action_cls):
        raise Ros2Error(f"action '{run.action}' has type {known}, not {type_name(action_cls)}")
    client = ActionClient(ctx.node, action_cls, run.action)

    def feedback_cb(message: Any) -> None:
        run.feedback.append(message.feedback)
        if on_feedback:
            on_feedback(message.feedback)

    try:
        timeout = ctx.limits.service_timeout
        wait_for_server(ctx, client.server_is_ready, timeout, f"action server '{run.action}'")
        future = client.send_goal_async(run.goal, feedback_callback=feedback_cb)
        handle = wait_future(ctx, future, timeout, f"action server '{run.action}'")
        if not handle.accepted:
            run.status = "REJECTED"
            return run
        run._handle = handle
        run.goal_id = bytes(handle.goal_id.uuid).hex()
        run.status = "EXECUTING"
        if on_accepted:
            on_accepted(run)
        response = wait_future(
            ctx,
            handle.get_result_async(),
            ctx.limits.action_timeout,
            f"action '{run.action}' (result)",
        )
        run.status = STATUS_NAMES.get(response.status, str(response.status))
        run.result = response.result
        return run
    except Cancelled:
        if run._handle is not None:
            run._handle.cancel_goal_async()  # Stop/Ctrl+C also stops the server's work
        run.status = "CANCELED (stopped here)"
        raise
    except Ros2Error as exc:
        run.error = str(exc)
        run.status = "ERROR"
        raise
    finally:
        run.done.set()
        client.destroy()
