"""Service calls and action goals.

Blocking-but-bounded calls (``call_service``, ``send_goal``) run on a worker
thread, never a viser callback or the executor thread: the request goes out
with ``call_async`` and this thread waits on the future. ``ServicePoller``
never blocks: it is for checks that are evaluated many times a second.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol, cast
from uuid import uuid4

from action_msgs.msg import GoalStatus
from rclpy.action.client import ClientGoalHandle
from rclpy.action.graph import get_action_names_and_types
from rclpy.client import Client
from rclpy.node import Node
from rclpy.task import Future
from unique_identifier_msgs.msg import UUID

from app.ros.action_client import FeedbackMessage, ThreadSafeActionClient
from app.ros.context import CallContext
from app.ros.convert import import_type, type_name
from app.ros.errors import Cancelled, NoAnswer, Ros2Error

STATUS_NAMES = {
    GoalStatus.STATUS_UNKNOWN: "UNKNOWN",
    GoalStatus.STATUS_ACCEPTED: "ACCEPTED",
    GoalStatus.STATUS_EXECUTING: "EXECUTING",
    GoalStatus.STATUS_CANCELING: "CANCELING",
    GoalStatus.STATUS_SUCCEEDED: "SUCCEEDED",
    GoalStatus.STATUS_CANCELED: "CANCELED",
    GoalStatus.STATUS_ABORTED: "ABORTED",
}


def wait_future(ctx: CallContext, future: Future, timeout: float, what: str) -> object:
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
            raise NoAnswer(f"no answer from {what} within {timeout:g} s")
    exc = future.exception()
    if exc is not None:
        raise Ros2Error(f"{what} failed: {exc}")
    return future.result()


RESEND_SEC = 2.0  # a lost request of a call_again is sent again after this long


def _no_answer(what: str, timeout: float, copies: int, sent: str) -> NoAnswer:
    """'no answer from WHAT within T s', and how often ``sent`` went if more than once."""
    times = "twice" if copies == 2 else f"{copies} times"
    also = f" ({sent} was sent {times})" if copies > 1 else ""
    return NoAnswer(f"no answer from {what} within {timeout:g} s{also}")


def call_again_until_answered(
    ctx: CallContext,
    client: Client,
    request: object,
    timeout: float,
    what: str,
    resend: float = RESEND_SEC,
) -> object:
    """``client``'s answer to ``request``, which is sent again every ``resend`` s until
    any copy is answered, at most ``timeout`` s: only for requests that may arrive twice
    (set or get a parameter, pause, reset).

    A request leaves once: if the client's writer has not matched the server's reader
    yet, it is lost (volatile durability), and the call waits out its whole timeout. That
    happens when a server has just restarted under the same name: the graph still lists
    the old one, so ``service_is_ready`` says yes at once (a learner's second attempt,
    graded while the world from the first one runs on, lost its ``use_sim_time``).
    """
    done = threading.Event()
    sent: list[Future] = []
    started = time.monotonic()
    deadline = started + timeout
    try:
        while True:
            again_at = started + len(sent) * resend
            if time.monotonic() >= again_at and again_at < deadline:
                future = client.call_async(request)
                future.add_done_callback(lambda _f: done.set())
                sent.append(future)
            if done.wait(0.05):
                break
            if ctx.cancel.is_set():
                raise Cancelled()
            if time.monotonic() > deadline:
                raise _no_answer(what, timeout, len(sent), "the request")
        answered = next(f for f in sent if f.done())
    finally:
        for future in sent:
            if not future.done():  # its answer, should it come, goes nowhere
                client.remove_pending_request(future)
                future.cancel()
    exc = answered.exception()
    if exc is not None:
        raise Ros2Error(f"{what} failed: {exc}")
    return answered.result()


def wait_for_server(
    ctx: CallContext, is_ready: Callable[[], bool], timeout: float, what: str
) -> None:
    """Poll ``is_ready`` (service_is_ready / server_is_ready) until true or timeout."""
    deadline = time.monotonic() + timeout
    while not is_ready():
        if time.monotonic() > deadline:
            raise Ros2Error(f"{what} is not available (waited {timeout:g} s)")
        ctx.sleep(0.1)


def service_types(ctx: CallContext, name: str) -> list[str]:
    return next((list(t) for n, t in ctx.node.get_service_names_and_types() if n == name), [])


def check_service_type(ctx: CallContext, name: str, srv_type: type) -> None:
    """When the service is on the graph with another type, say so instead of timing out."""
    types = service_types(ctx, name)
    if types and type_name(srv_type) not in types:
        raise Ros2Error(f"service '{name}' has type {', '.join(types)}, not {type_name(srv_type)}")


def call_service(
    ctx: CallContext,
    name: str,
    srv_type: type,
    request: object,
    timeout: float | None = None,
    *,
    resend_unanswered: bool = False,
) -> object:
    """Send one request and return the response, or raise one clear Ros2Error.

    The response is a ``srv_type.Response``: the caller that reads it names that type.

    ``resend_unanswered``: for a request that is safe to repeat (a pure function, an
    absolute teleport), send it once more when no answer came within ``timeout``, and
    wait as long again. A new client's first answer can be lost: Fast DDS drops a reply
    whose reader the server has not yet matched ("failed to send response (timeout):
    client will not receive response"), which happens on a loaded machine while
    discovery lags. The second request goes out once the reply path is matched; a
    server that never answers still fails.
    """
    timeout = ctx.limits.service_timeout if timeout is None else timeout
    check_service_type(ctx, name, srv_type)
    client = ctx.node.create_client(srv_type, name)
    what = f"service '{name}'"
    try:
        wait_for_server(ctx, client.service_is_ready, timeout, what)
        if resend_unanswered:
            return call_again_until_answered(ctx, client, request, 2 * timeout, what, timeout)
        return wait_future(ctx, client.call_async(request), timeout, what)
    finally:
        ctx.node.destroy_client(client)


def action_type_of(node: Node, name: str) -> str | None:
    for action, types in get_action_names_and_types(node):
        if action == name and types:
            return types[0]
    return None


@dataclass
class GoalRun:
    """A goal in flight: the panel reads it while a worker thread drives it."""

    action: str
    type_text: str
    goal: object  # a Goal of the action's type, as are feedback and result below
    feedback: list[object] = field(default_factory=list)
    status: str = "SENDING"
    result: object = None
    error: str | None = None
    goal_id: str = ""
    command: str = ""  # the equivalent `ros2 action send_goal ...` line
    done: threading.Event = field(default_factory=threading.Event)
    # The server's answer to our cancel: action_msgs' CancelGoal return code (None: none yet).
    cancel_code: int | None = None
    _handle: ClientGoalHandle | None = None

    @property
    def outcome(self) -> str:
        """'running', or the final status in lower case ('succeeded', 'canceled', ...)."""
        return self.status.lower() if self.done.is_set() else "running"

    def cancel(self) -> None:
        """Ask the server to cancel; the final status arrives with the result."""
        handle = self._handle
        if handle is not None and not self.done.is_set():
            self.status = "CANCELING"
            handle.cancel_goal_async().add_done_callback(self._cancel_answered)

    def _cancel_answered(self, future: Future) -> None:
        try:
            response = future.result()
        except Exception:  # the client went away with the goal's end: no answer
            return
        self.cancel_code = int(getattr(response, "return_code", -1))


class _ResultResponse(Protocol):
    """An action's GetResult response: the final status and the result."""

    status: int
    result: object


GOAL_SETTLE_SEC = 0.5  # after a new action client finds its server (see send_goal)


def send_goal(
    ctx: CallContext,
    run: GoalRun,
    on_feedback: Callable[[object], None] | None = None,
    on_accepted: Callable[[GoalRun], None] | None = None,
    *,
    resend_unanswered: bool = False,
) -> GoalRun:
    """Drive ``run`` to its end: accepted or rejected, feedback, final status and result.

    ``resend_unanswered`` (the grader's probes): a goal request unanswered for
    RESEND_SEC is sent again, under the same goal id (see ``_goal_answer``)."""
    action_cls = import_type(run.type_text, "action")
    known = action_type_of(ctx.node, run.action)
    if known and known != type_name(action_cls):
        raise Ros2Error(f"action '{run.action}' has type {known}, not {type_name(action_cls)}")
    # Sent from this job's thread while the runtime spins in its own (see action_client).
    client = ThreadSafeActionClient(ctx.node, action_cls, run.action)

    running_id: list[UUID] = []  # the goal's id, once feedback proves it runs

    def feedback_cb(message: FeedbackMessage) -> None:
        if not running_id:
            running_id.append(message.goal_id)
        run.feedback.append(message.feedback)
        if on_feedback:
            on_feedback(message.feedback)

    try:
        timeout = ctx.limits.service_timeout
        wait_for_server(ctx, client.server_is_ready, timeout, f"action server '{run.action}'")
        # "Ready" is our side's view of discovery. The server may match our fresh
        # client a moment later, and a goal response sent before that is lost: the
        # goal then runs (feedback arrives) while we wait for its acceptance in vain.
        ctx.sleep(GOAL_SETTLE_SEC)
        try:
            if resend_unanswered:
                handle = _goal_answer(ctx, client, run, feedback_cb, running_id, timeout)
            else:
                future = client.send_goal_async(run.goal, feedback_callback=feedback_cb)
                handle = cast(
                    ClientGoalHandle,
                    wait_future(ctx, future, timeout, f"action server '{run.action}'"),
                )
        except Ros2Error:
            if not running_id:
                raise
            # The acceptance was lost on the way (see GOAL_SETTLE_SEC), yet the goal's
            # feedback arrives: it was accepted and runs. Follow it by its id.
            accepted = action_cls.Impl.SendGoalService.Response(accepted=True)
            handle = ClientGoalHandle(client, running_id[0], accepted)
        if not handle.accepted:
            run.status = "REJECTED"
            return run
        run._handle = handle
        run.goal_id = bytes(handle.goal_id.uuid).hex()
        run.status = "EXECUTING"
        if on_accepted:
            on_accepted(run)
        response = cast(
            _ResultResponse,
            wait_future(
                ctx,
                handle.get_result_async(),
                ctx.limits.action_timeout,
                f"action '{run.action}' (result)",
            ),
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


def _goal_answer(
    ctx: CallContext,
    client: ThreadSafeActionClient,
    run: GoalRun,
    feedback_cb: Callable[[FeedbackMessage], None],
    running_id: list[UUID],
    timeout: float,
) -> ClientGoalHandle:
    """The server's answer to ``run``'s goal, sent again every RESEND_SEC until a copy is
    answered or its feedback proves it runs (then NoAnswer: the caller follows it by id).

    A goal request is lost as a service request is (``call_again_until_answered``) when
    the server has just restarted under the same name: a learner's next attempt got "no
    answer from action server within 5 s" (a 2-worker run of test_grading). Every copy
    carries the same goal id, so a server that got the first one rejects the others
    (rclpy: "Failed to accept new goal with ID ..."): a rejection of a later copy is
    believed only once no earlier copy is accepted or gives feedback within RESEND_SEC.
    """
    goal_id = UUID(uuid=list(uuid4().bytes))
    what = f"action server '{run.action}'"
    sent: list[Future] = []
    started = time.monotonic()
    deadline = started + timeout
    rejected_at: float | None = None
    try:
        while True:
            again_at = started + len(sent) * RESEND_SEC
            unanswered = not running_id and rejected_at is None
            if unanswered and time.monotonic() >= again_at and again_at < deadline:
                sent.append(client.send_goal_async(run.goal, feedback_cb, goal_id))
            answers = [cast(ClientGoalHandle, f.result()) for f in sent if f.done()]
            accepted = next((a for a in answers if a.accepted), None)
            if accepted is not None:
                return accepted
            if running_id:
                raise NoAnswer(f"no answer from {what}, yet the goal runs")
            if answers and rejected_at is None:
                rejected_at = time.monotonic()
            if rejected_at is not None and (
                len(answers) == len(sent) or time.monotonic() - rejected_at > RESEND_SEC
            ):
                return answers[0]  # rejected: every copy so answered, or none ran
            if ctx.cancel.is_set():
                raise Cancelled()
            if time.monotonic() > deadline:
                raise _no_answer(what, timeout, len(sent), "the goal")
            ctx.sleep(0.05)
    finally:
        for future in sent:
            if not future.done():
                future.cancel()


STEP_ANSWER_SEC = 5.0  # how long a step action waits for its service's answer
LOST_AFTER_SEC = 3.0  # a request unanswered this long is asked again (a lost answer)


class ServicePoller:
    """The latest answer of a service, re-asked at most once a period; never blocks.

    Lesson checks are evaluated several times a second from the UI thread:
    they read the last answer and, when it is old, send one new request.
    """

    def __init__(self, node: Node, period: float = 1.0) -> None:
        self._node = node
        self._period = period
        self._lock = threading.Lock()
        self._clients: dict[tuple[str, str], Client] = {}
        self._calls: dict[str, tuple[Future | None, object, float]] = {}

    def client(self, service: str, srv_type: type) -> Client:
        """One cached client per (service, type)."""
        with self._lock:
            key = (service, type_name(srv_type))
            if key not in self._clients:
                self._clients[key] = self._node.create_client(srv_type, service)
            return self._clients[key]

    def latest(self, key: str, service: str, srv_type: type, request: object) -> object:
        """The newest response for ``key`` (None before the first); asks again when due.

        The response is a ``srv_type.Response``: the caller that reads it names that type.
        """
        client = self.client(service, srv_type)
        with self._lock:
            future, result, sent_at = self._calls.get(key, (None, None, 0.0))
            if future is not None and future.done():
                result = future.result() if future.exception() is None else None
                future = None
            elif future is not None and time.monotonic() - sent_at > LOST_AFTER_SEC:
                # A server that answers before it has matched our fresh client's reader
                # loses the answer (busy discovery); without this the check waited forever.
                client.remove_pending_request(future)
                future = None
            due = time.monotonic() - sent_at > self._period
            if future is None and due and client.service_is_ready():
                future, sent_at = client.call_async(request), time.monotonic()
            self._calls[key] = (future, result, sent_at)
            return result

    def call(
        self, service: str, srv_type: type, request: object, timeout: float = STEP_ANSWER_SEC
    ) -> object | None:
        """Send one request and wait up to ``timeout`` s for the response (None: none came).

        A step action: the step's next button (a drive after a reset) must find the
        request done, also when the buttons run back to back on a loaded machine.
        None is no error: a fresh client's answer can be lost while discovery lags
        (see ``LOST_AFTER_SEC``), though the server has acted on the request.
        """
        client = self.client(service, srv_type)
        ctx, what = CallContext(self._node), f"service '{service}'"
        wait_for_server(ctx, client.service_is_ready, timeout, what)
        future = client.call_async(request)
        try:
            return wait_future(ctx, future, timeout, what)
        except NoAnswer:
            client.remove_pending_request(future)
            return None

    def forget_answers(self) -> None:
        """Answers from before an action may be stale now."""
        with self._lock:
            self._calls.clear()

    def close(self) -> None:
        with self._lock:
            clients, self._clients = list(self._clients.values()), {}
        for client in clients:
            self._node.destroy_client(client)
