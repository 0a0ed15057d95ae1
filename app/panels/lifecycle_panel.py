"""Lifecycle panel: the managed-node state machine, with only valid transitions clickable.

The state comes from ``<node>/get_state`` and, as soon as anyone changes it
(a launch file, a terminal, this panel), from ``<node>/transition_event``.
Each click runs ``ros2 lifecycle set`` through app.ros2cli on a worker thread.
"""

from __future__ import annotations

import threading
import time

import viser
from lifecycle_msgs.msg import TransitionEvent
from rclpy.node import Node

from app.graph import GraphSnapshot
from app.panels import MarkdownView, code_block
from app.panels.logs_panel import RosoutLog, format_record
from app.panels.ros_tools import run_job
from app.ros2cli import CONSOLE_LIMITS, VerbContext
from app.ros2cli import lifecycle as lc
from app.ros2cli.common import split_node_name
from app.ros2cli.convert import import_type
from app.ros2cli.topic import MEASURE_QOS, TopicMonitor

PRIMARY = ("unconfigured", "inactive", "active", "finalized")
BUTTONS = ("configure", "activate", "deactivate", "cleanup", "shutdown")
EDGES = (
    ("unconfigured", "configure", "inactive"),
    ("inactive", "activate", "active"),
    ("active", "deactivate", "inactive"),
    ("inactive", "cleanup", "unconfigured"),
    ("unconfigured / inactive / active", "shutdown", "finalized"),
)
NONE = "(no lifecycle node)"
POLL_SEC = 2.0
QUIET_TOPICS = ("/rosout", "/parameter_events")
RATE_WINDOW_SEC = 3.0


def draw_state_machine(current: str | None) -> str:
    """The four primary states in a row, the current one highlighted, and the transitions."""
    cells = []
    for state in PRIMARY:
        if state == current:
            cells.append(
                f'<td style="background:#2f9e44;color:white;font-weight:bold;'
                f'padding:6px;border-radius:6px">▶ {state}</td>'
            )
        else:
            cells.append(f'<td style="padding:6px;color:#555">{state}</td>')
    rows = "".join(f"<tr><td>{a}</td><td>—<b>{t}</b>→</td><td>{b}</td></tr>" for a, t, b in EDGES)
    extra = ""
    if current and current not in PRIMARY:
        extra = f'<div style="color:#e67700"><b>in transition: {current}</b></div>'
    return (
        '<div style="font-family:sans-serif;font-size:13px">'
        f'<table style="width:100%;text-align:center"><tr>{"".join(cells)}</tr></table>{extra}'
        f'<table style="font-size:12px;color:#333">{rows}</table></div>'
    )


class LifecyclePanel:
    def __init__(self, gui: viser.GuiApi, node: Node, rosout: RosoutLog) -> None:
        self._node = node
        self._rosout = rosout
        self._lock = threading.Lock()
        self._target: str | None = None
        self._state: str | None = None
        self._available: set[str] = set()
        self._message = ""
        self._busy = False
        self._last_poll = 0.0
        self._event_sub = None
        self._nodes: list[str] = []
        self._monitors: dict[str, TopicMonitor] = {}
        self._selector = gui.add_dropdown("Lifecycle node", [NONE], initial_value=NONE)
        self._diagram = gui.add_html(draw_state_machine(None))
        self._diagram_html = ""
        self._buttons = {}
        for label in BUTTONS:
            button = gui.add_button(label, disabled=True)
            button.on_click(lambda _e, label=label: self._transition(label))
            self._buttons[label] = button
        self._result = MarkdownView(gui, "")
        self._log = MarkdownView(gui, "")
        self._selector.on_update(lambda _: self._select(self._selector.value))

    # --- selection and state -------------------------------------------------

    def _ctx(self) -> VerbContext:
        return VerbContext(self._node, lambda _line: None, CONSOLE_LIMITS)

    def _select(self, target: str) -> None:
        with self._lock:
            if target == self._target:
                return
            self._target = None if target == NONE else target
            self._state, self._available, self._message = None, set(), ""
            old, self._event_sub = self._event_sub, None
        if old is not None:
            self._node.destroy_subscription(old)
        with self._lock:
            monitors, self._monitors = list(self._monitors.values()), {}
        for monitor in monitors:
            monitor.close()
        if self._target:
            self._event_sub = self._node.create_subscription(
                TransitionEvent, f"{self._target}/transition_event", self._on_event, 10
            )
            self._poll()

    def _on_event(self, event: TransitionEvent) -> None:
        # Runs on the executor thread: record the new state, fetch transitions elsewhere.
        with self._lock:
            self._state = event.goal_state.label
        self._poll()

    def _poll(self) -> None:
        target = self._target
        if target is None or self._busy:
            return
        self._busy = True
        self._last_poll = time.monotonic()

        def work() -> None:
            try:
                ctx = self._ctx()
                _id, state = lc.get_state(ctx, target)
                available = {t.label for t in lc.available_transitions(ctx, target)}
                self._watch_topics(target)
                with self._lock:
                    if self._target == target:
                        self._state, self._available = state, available
            finally:
                self._busy = False

        run_job(work, self._show_error)

    def _watch_topics(self, target: str) -> None:
        """Measure the rate of every topic the node publishes (they appear on configure)."""
        name, namespace = split_node_name(target)
        for topic, types in self._node.get_publisher_names_and_types_by_node(name, namespace):
            if topic in self._monitors or topic in QUIET_TOPICS or "/_" in topic:
                continue
            if topic.endswith("/transition_event"):
                continue
            monitor = TopicMonitor(
                self._node, topic, import_type(types[0]), qos=MEASURE_QOS, keep=1
            )
            with self._lock:
                self._monitors[topic] = monitor

    def _rates_text(self) -> str:
        parts = []
        with self._lock:
            monitors = sorted(self._monitors.items())
        for topic, monitor in monitors:
            stats = monitor.rate(window_sec=RATE_WINDOW_SEC)
            rate = f"**{stats.rate:.1f} Hz**" if stats else "**silent**"
            parts.append(f"`{topic}`: {rate} (`ros2 topic hz {topic}`)")
        return "Publishing: " + (" · ".join(parts) if parts else "no topics yet")

    def _show_error(self, text: str) -> None:
        with self._lock:
            self._message = f"⚠️ {text}"

    def _transition(self, label: str) -> None:
        target = self._target
        if target is None:
            return
        command = f"ros2 lifecycle set {target} {label}"
        with self._lock:
            self._message = f"`{command}` …"
            self._available = set()  # no double clicks while it runs

        def work() -> None:
            ok, chosen = lc.change_state(self._ctx(), target, label)
            verdict = "Transitioning successful" if ok else "Transitioning failed"
            with self._lock:
                self._message = f"`{command}` → **{verdict}** ({chosen.start} → {chosen.goal})"
            self._busy = False
            self._poll()

        run_job(work, self._show_error)

    # --- refresh ---------------------------------------------------------------

    def refresh(self, graph: GraphSnapshot | None) -> None:
        if graph is not None:
            nodes = sorted(
                name[: -len("/get_state")]
                for name, types in graph.services
                if name.endswith("/get_state") and lc.GET_STATE_TYPE in types
            )
            if nodes != self._nodes:
                self._nodes = nodes
                options = nodes or [NONE]
                self._selector.options = options
                if self._selector.value not in options:
                    self._selector.value = options[0]
                self._select(self._selector.value)
        if self._target and time.monotonic() - self._last_poll > POLL_SEC:
            self._poll()
        with self._lock:
            state, available, message = self._state, set(self._available), self._message
        html = draw_state_machine(state)
        if html != self._diagram_html:
            self._diagram_html = html
            self._diagram.content = html
        for label, button in self._buttons.items():
            disabled = label not in available
            if button.disabled != disabled:
                button.disabled = disabled
        target = self._target
        header = (
            f"Current state of `{target}`: **{state or '…'}** · `ros2 lifecycle get {target}`"
            if target
            else "_Start **lifecycle_talker** in the Nodes tab._"
        )
        rates = "\n\n" + self._rates_text() if target else ""
        self._result.show(header + rates + ("\n\n" + message if message else ""))
        if target:
            lines = [format_record(r) for r in self._rosout.records(target, last=12)]
            self._log.show(f"Log of `{target}` (/rosout):\n\n" + code_block(lines))
        else:
            self._log.show("")
