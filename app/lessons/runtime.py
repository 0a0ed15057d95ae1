"""What lessons do to and read from the live system: step actions and checks.

``LessonRuntime`` is used by the lesson panel's buttons and by the test that
walks every lesson, so both exercise the same code. It holds what the kinds
share (graph snapshot, topic taps, service poller, goals, supervisor) and
dispatches to them; each kind lives in its own module (``app.lessons.checks``,
``app.lessons.actions``; ``app.lessons.registry`` says how to add one). Checks never block: a
check that needs a service answer issues ``call_async`` and reports
*waiting* until the answer is in.

What checks subscribe to (topic taps, and shared watches such as the TF
listener or the world's /clock) lives only while checks read it: once no
check has read one for ``IDLE_SEC`` of looking (the learner moved on to
another step or lesson), it is closed. A dashboard that once showed a
simulation step no longer takes /clock at 100-200 messages a second for good.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any, Protocol, TypeVar

from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from app import catalog
from app.lessons.registry import ACTIONS, CHECKS, FAIL, PASS, WAITING, CheckResult
from app.lessons.schema import Spec
from app.ros.calls import GoalRun, ServicePoller
from app.ros.convert import import_type
from app.ros.errors import Ros2Error
from app.ros.graph import GraphSnapshot
from app.ros.monitor import TopicMonitor
from app.supervisor import Supervisor

__all__ = ["FAIL", "PASS", "WAITING", "CheckResult", "LessonRuntime"]

RECALL_PERIOD_SEC = 1.0
# Best effort hears reliable and best-effort publishers alike (camera images
# are usually best effort); a reliable tap would hear only the former.
TAP_QOS = QoSProfile(depth=50, reliability=ReliabilityPolicy.BEST_EFFORT)
TAP_KEEP = 50  # messages a check can look back on
# /rosout keeps each node's recent log for late joiners (transient local, 10 s
# lifespan): a reliable, transient-local tap also reads what was logged just
# before the check first looked, e.g. right after the step's button.
ROSOUT_QOS = QoSProfile(
    depth=1000, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
ROSOUT_KEEP = 500
# A tap or watch no check has read for this long, while checks were looked at, is
# closed; a stalled UI loop does not count (idle time runs between looks only).
IDLE_SEC = 10.0
SWEEP_SEC = 1.0  # how often idle ones are looked for


class Closable(Protocol):
    def close(self) -> None: ...


W = TypeVar("W", bound=Closable)


class LessonRuntime:
    """Performs step actions and evaluates checks on the live graph.

    ``perform`` may block briefly (it starts processes): call it from a job,
    never a viser callback. ``evaluate`` never blocks: service answers come
    from a ``ServicePoller``, goals run on their own threads. The UI thread
    sets ``graph`` and calls both; the topic taps and the poller have their
    own locks, and ``quiz_answers`` is written only by the UI thread.
    """

    def __init__(self, node: Node, supervisor: Supervisor) -> None:
        self.node = node
        self.supervisor = supervisor
        self.lock = threading.Lock()
        self._graph = GraphSnapshot()
        self._taps: dict[tuple[str, str], TopicMonitor[object]] = {}
        self._watches: dict[str, Closable] = {}  # shared by several checks (TF, sim speed)
        self._read: dict[Any, float] = {}  # when a check last read each tap or watch
        self._last_look = self._next_sweep = time.monotonic()
        self.tap_born: dict[tuple[str, str], float] = {}  # when each tap began to listen
        # When a step's set_param action last changed a parameter (its node answered):
        # a rate judged after it hears only the new setting (topic_rate).
        self.changed_at: float | None = None
        self.services = ServicePoller(node, RECALL_PERIOD_SEC)
        self.goals: dict[str, GoalRun] = {}
        self.senders: dict[tuple[str, str], Publisher] = {}  # kept: a fresh one misses subscribers
        self.quiz_answers: dict[str, str] = {}
        # Runs a `ros2 ...` line in the Console tab (the dashboard wires it; UI thread).
        self.console: Callable[[str], None] | None = None

    def tap(self, topic: str, type_name: str, history: bool = False) -> TopicMonitor[Any]:
        """A kept subscription; ``history``: the reliable, transient-local /rosout kind.

        Its messages are untyped: their class is named by text (``type_name``).
        """
        with self.lock:
            key = (topic, type_name + (" (history)" if history else ""))
            if key not in self._taps:
                self.tap_born[key] = time.monotonic()
                self._taps[key] = TopicMonitor(
                    self.node,
                    topic,
                    import_type(type_name),
                    keep=ROSOUT_KEEP if history else TAP_KEEP,
                    qos=ROSOUT_QOS if history else TAP_QOS,
                )
            self._read[key] = time.monotonic()
            return self._taps[key]

    def watch(self, name: str, make: Callable[[Node], W]) -> W:
        """The watch ``name`` several checks share, made on this node at the first use;
        closed as a tap is, once no check reads it."""
        with self.lock:
            found = self._watches.get(name)
            if found is None:
                found = self._watches[name] = make(self.node)
            self._read[name] = time.monotonic()
            return found  # type: ignore[return-value]

    @property
    def graph(self) -> GraphSnapshot:
        return self._graph

    @graph.setter
    def graph(self, graph: GraphSnapshot) -> None:
        """Every user sets the graph once a pass (the UI loop, the grader): a look."""
        self._graph = graph
        self._look()

    def _look(self) -> None:
        """Close the taps and watches no check has read for IDLE_SEC of looking."""
        now = time.monotonic()
        with self.lock:
            last, self._last_look = self._last_look, now
            if now < self._next_sweep:
                return
            self._next_sweep = now + SWEEP_SEC
            # Against the previous look, not now: after a stall of the UI loop, what the
            # current step read just before it is not idle.
            idle = [key for key, read in self._read.items() if last - read > IDLE_SEC]
            closing: list[Closable] = []
            for key in idle:
                del self._read[key]
                self.tap_born.pop(key, None)
                tap = self._taps.pop(key, None)
                watch = self._watches.pop(key, None)
                closing += [each for each in (tap, watch) if each is not None]
        for each in closing:
            each.close()

    def close(self) -> None:
        with self.lock:
            taps, self._taps = list(self._taps.values()), {}
            watches, self._watches = list(self._watches.values()), {}
            goals = list(self.goals.values())
        for tap in [*taps, *watches]:
            tap.close()
        for run in goals:
            run.cancel()
        self.services.close()

    def perform(self, action: Spec) -> str:
        """Do one step action; returns a one-line message for the page."""
        self.services.forget_answers()  # answers from before this action may be stale now
        return ACTIONS[action.kind].perform(self, action)

    def evaluate(self, check: Spec) -> CheckResult:
        self._look()
        try:
            return CHECKS[check.kind].evaluate(self, check)
        except (Ros2Error, ValueError, RuntimeError, catalog.UnknownNodeError) as exc:
            return CheckResult(FAIL, str(exc))

    def publishers(self, topic: str) -> int:
        """How many publishers the graph snapshot shows on ``topic``."""
        return self.graph.publishers(topic)


# Each kind's code, by name (the registry's; kept for the schema test and callers).
_ACTIONS: dict[str, Callable[[LessonRuntime, Spec], str]] = {
    name: kind.perform for name, kind in ACTIONS.items()
}
_CHECKS: dict[str, Callable[[LessonRuntime, Spec], CheckResult]] = {
    name: kind.evaluate for name, kind in CHECKS.items()
}
