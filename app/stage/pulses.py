"""Service calls and action goals, seen live, for the stage to draw as pulses.

What any ROS program can see, nothing the dashboard is told by its own panels:

- a service call: with service introspection (Jazzy), a server publishes an
  event on ``<service>/_service_event`` when a request arrives and when it
  sends the response (the catalog's servers switch it on; metadata only, no
  contents). The event names the caller by the id of its reply reader, which
  the graph maps back to a node (``caller_of``);
- an action: a new goal appears in ``<action>/_action/status``, feedback comes
  on ``<action>/_action/feedback``, and the status says when the goal ended.

Threads: subscription callbacks (executor thread) record events under a lock;
the stage (UI thread) changes what is watched and reads the recent events.
Pulses of one service or action are spaced so that a response follows its
request on screen instead of overlapping it, and a burst is thinned, not queued
for ever.
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from action_msgs.msg import GoalStatus, GoalStatusArray
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.subscription import Subscription
from service_msgs.msg import ServiceEventInfo

from app.ros.convert import ConversionError, import_type
from app.ros.qos import MEASURE_QOS
from app.stage.graph_view import LEG_SEC

log = logging.getLogger(__name__)

TRAVEL_SEC = 2 * LEG_SEC  # a pulse's two legs (see graph_view)
MAX_BEHIND_SEC = 2.5  # a pulse that would wait longer than this is dropped (a burst)
FEEDBACK_GAP_SEC = 0.4  # fast feedback: one pulse per this gap
MAX_WATCHED = 24  # services + actions watched at once
KEEP = 200
RESULT_DELAY_SEC = 0.3  # a result waits this long for late feedback (see _on_status)
CLOCK_SLACK_SEC = 0.5  # between the server's clock stamping a goal and ours
# A goal's end always shows, however far behind its feedback put the queue: it is what
# the learner waits for (seen: a loaded machine's bunched feedback crowded the result out).
NEVER_DROPPED = ("result",)

SERVICE_EVENT = "/_service_event"
ACTION_STATUS = "/_action/status"
ACTION_FEEDBACK = "/_action/feedback"
_ENDED = (GoalStatus.STATUS_SUCCEEDED, GoalStatus.STATUS_CANCELED, GoalStatus.STATUS_ABORTED)
# Action status is latched (transient local): subscribe the same way, so that the
# goals known at subscription time are known, and only later changes pulse.
STATUS_QOS = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)


@dataclass(frozen=True)
class Pulse:
    kind: str  # request, response (services); goal, feedback, result (actions)
    name: str  # the service or action
    shown_at: float  # monotonic time its travel starts on screen
    caller_id: str = ""  # a service caller's reply reader id (hex), '' when unknown


class CallWatch:
    """Events of the watched services and actions; ``watch``/``close`` from one thread."""

    def __init__(self, node: Node, on_event: Callable[[], None] | None = None) -> None:
        self._node = node
        self._on_event = on_event or (lambda: None)
        self._lock = threading.Lock()
        self._subs: dict[str, tuple[str, list[Subscription]]] = {}  # name -> (type, subs)
        self._pulses: deque[Pulse] = deque(maxlen=KEEP)
        self._next_free: dict[str, float] = {}  # per name: when its last pulse has passed
        self._seen: deque[tuple[str, int, bytes, str]] = deque(maxlen=KEEP)
        self._goals: dict[str, dict[bytes, int]] = {}  # action -> goal id -> last status
        self._feedback_at: dict[str, float] = {}
        self._since: dict[str, float] = {}  # action -> wall time its watch began
        self._results: deque[tuple[float, str]] = deque(maxlen=KEEP)  # (due, action)

    # -- what to watch (UI thread) --------------------------------------------

    def watch(self, services: dict[str, str], actions: dict[str, str]) -> None:
        """Watch exactly these services and actions (name -> type); at most MAX_WATCHED."""
        wanted = {name: ("srv", kind) for name, kind in services.items()}
        wanted.update({name: ("action", kind) for name, kind in actions.items()})
        wanted = dict(sorted(wanted.items())[:MAX_WATCHED])
        for name in [
            n for n, (kind, _s) in self._subs.items() if wanted.get(n, ("", ""))[1] != kind
        ]:
            for sub in self._subs.pop(name)[1]:
                self._node.destroy_subscription(sub)
            with self._lock:
                self._goals.pop(name, None)
        for name, (what, kind) in wanted.items():
            if name in self._subs:
                continue
            try:
                subs = (
                    self._subscribe_service(name, kind)
                    if what == "srv"
                    else self._subscribe_action(name, kind)
                )
            except (ConversionError, AttributeError) as exc:  # a type this environment lacks
                log.debug("no pulses for %s: %s", name, exc)
                subs = []
            self._subs[name] = (kind, subs)

    def _subscribe_service(self, name: str, kind: str) -> list[Subscription]:
        event_type = import_type(kind, "srv").Event
        return [
            self._node.create_subscription(
                event_type,
                name + SERVICE_EVENT,
                lambda msg: self._on_service_event(name, msg),
                MEASURE_QOS,
            )
        ]

    def _subscribe_action(self, name: str, kind: str) -> list[Subscription]:
        feedback_type = import_type(kind, "action").Impl.FeedbackMessage
        with self._lock:
            self._goals[name] = {}
            # Goals accepted before this moment come with the latched status: the past.
            self._since[name] = time.time() - CLOCK_SLACK_SEC
        return [
            self._node.create_subscription(
                GoalStatusArray,
                name + ACTION_STATUS,
                lambda msg: self._on_status(name, msg),
                STATUS_QOS,
            ),
            self._node.create_subscription(
                feedback_type,
                name + ACTION_FEEDBACK,
                lambda _msg: self._on_feedback(name),
                MEASURE_QOS,
            ),
        ]

    def close(self) -> None:
        self.watch({}, {})

    # -- events (executor thread) ------------------------------------------------

    def _add(self, kind: str, name: str, caller_id: str = "") -> None:
        """Record a pulse, spaced after the last one of ``name`` (lock held)."""
        now = time.monotonic()
        start = max(now, self._next_free.get(name, 0.0))
        if start - now > MAX_BEHIND_SEC and kind not in NEVER_DROPPED:
            return  # a burst: the screen shows some of it, not a queue minutes long
        self._next_free[name] = start + TRAVEL_SEC
        self._pulses.append(Pulse(kind, name, start, caller_id))
        self._on_event()

    def _on_service_event(self, name: str, msg: Any) -> None:
        info = msg.info
        request = info.event_type in (
            ServiceEventInfo.REQUEST_SENT,
            ServiceEventInfo.REQUEST_RECEIVED,
        )
        kind = "request" if request else "response"
        caller = bytes(info.client_gid)
        key = (name, int(info.sequence_number), caller, kind)
        with self._lock:
            if key in self._seen:  # the client reported it too
                return
            self._seen.append(key)
            self._add(kind, name, caller.hex())

    def _on_status(self, name: str, msg: GoalStatusArray) -> None:
        with self._lock:
            known = self._goals.get(name)
            if known is None:
                return
            since = self._since.get(name, 0.0)
            for status in msg.status_list:
                goal = bytes(status.goal_info.goal_id.uuid)
                before = known.get(goal)
                known[goal] = status.status
                stamp = status.goal_info.stamp
                if before is None and stamp.sec + stamp.nanosec * 1e-9 < since:
                    continue  # a goal from before we looked (the latched status): no pulse
                if before is None:
                    self._add("goal", name)
                if status.status in _ENDED and before not in _ENDED:
                    # Feedback travels best effort, status reliably: the last feedback
                    # may land just after the status says done. Wait for it a moment.
                    self._results.append((time.monotonic() + RESULT_DELAY_SEC, name))
            if len(known) > KEEP:  # forget long-finished goals
                for goal in list(known)[: len(known) - KEEP]:
                    del known[goal]

    def _on_feedback(self, name: str) -> None:
        now = time.monotonic()
        with self._lock:
            if now - self._feedback_at.get(name, 0.0) < FEEDBACK_GAP_SEC:
                return
            self._feedback_at[name] = now
            self._add("feedback", name)

    # -- reading (any thread) --------------------------------------------------------

    def recent(self, now: float | None = None) -> list[Pulse]:
        """Pulses still travelling (or about to) at ``now``."""
        now = time.monotonic() if now is None else now
        with self._lock:
            while self._results and self._results[0][0] <= time.monotonic():
                self._add("result", self._results.popleft()[1])
            return [p for p in self._pulses if p.shown_at + TRAVEL_SEC > now]


def caller_of(node: Node, service: str, caller_id: str) -> str:
    """The node whose reply reader has id ``caller_id``, '' when the graph cannot tell.

    A service client reads its replies on the DDS topic ``rr<service>Reply``; the
    service event names the client by that reader's id.
    """
    if not caller_id:
        return ""
    try:
        readers = node.get_subscriptions_info_by_topic(f"rr{service}Reply", no_mangle=True)
    except Exception:  # the graph may be unreadable for a moment
        return ""
    for reader in readers:
        if bytes(reader.endpoint_gid).hex() == caller_id:
            return reader.node_namespace.rstrip("/") + "/" + reader.node_name
    return ""
