"""Lifecycle panel: the managed-node state machine, with only valid transitions clickable.

The state comes from ``<node>/get_state`` and, as soon as anyone changes it
(a launch file, a terminal, this panel), from ``<node>/transition_event``.
Each click runs the same code as ``ros2 lifecycle set`` on a worker thread.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import viser
from lifecycle_msgs.msg import TransitionEvent
from rclpy.node import Node
from rclpy.subscription import Subscription

from app.panels.lifecycle_svg import draw_state_machine
from app.ros import lifecycle as lc
from app.ros.context import panel_context
from app.ros.graph import GraphSnapshot, published_topics
from app.ros.rates import RateBoard, rate_text
from app.ros.rosout import RosoutLog, format_record
from app.ui import MarkdownView, code_block, set_options
from app.ui.loop import UiLoop
from app.ui.page_links import SINK_FRAME, PageLinks

NONE = "(no lifecycle node)"
POLL_SEC = 2.0
LOG_LINES = 5  # the node's newest /rosout lines under the diagram


class LifecyclePanel:
    calm = True  # once a second while idle (app.ui.Panel): it polls every POLL_SEC anyway

    def __init__(
        self,
        gui: viser.GuiApi,
        ui: UiLoop,
        node: Node,
        rosout: RosoutLog,
        links: PageLinks,
        *,
        link_prefix: str = "lifecycle",
        buttons: bool = True,
    ) -> None:
        """``link_prefix``: the page links its drawing's edges use (one per drawing);
        ``buttons``: a button per transition under the drawing (the stage has only the
        drawing's edges, the tool both)."""
        self._ui = ui
        self._link_prefix = link_prefix
        self._links = links
        self._node = node
        self._rosout = rosout
        self._target: str | None = None
        self._state: str | None = None
        self._available: set[str] = set()
        self._message = ""
        self._polling = False  # a get_state job is out: never two at once
        self._stale = False  # the state changed while that job was out: ask again
        self._changing = False  # a transition job is out: buttons stay disabled
        self._last_poll = 0.0
        self._event_sub: Subscription | None = None
        self._nodes: list[str] = []
        self._rates = RateBoard(node, limit=8)
        self._selector = gui.add_dropdown("Lifecycle node", [NONE], initial_value=NONE)
        self._diagram = gui.add_html("")
        self._diagram_html = ""
        self._buttons = {}
        for label in lc.TRANSITION_LABELS:
            if buttons:
                button = gui.add_button(label, disabled=True)
                button.on_click(ui.callback(self._transition, label))
                self._buttons[label] = button
            # The drawing's edges act as these buttons do (see app/ui/page_links.py).
            links.register(f"{link_prefix}.{label}", self._poster(label))
        self._result = MarkdownView(gui, "")
        self._log = MarkdownView(gui, "")
        self._selector.on_update(ui.callback(lambda: self._select(self._selector.value)))

    def _poster(self, label: str) -> Callable[[], None]:
        return lambda: self._ui.post(lambda: self._transition(label))

    def _edge_link(self, label: str, svg: str, title: str) -> str:
        return self._links.anchor(f"{self._link_prefix}.{label}", svg, title)

    # --- selection and state (UI thread) -------------------------------------------

    def _select(self, choice: str) -> None:
        target = None if choice == NONE else choice
        if target == self._target:
            return
        self._target = target
        self._state, self._available, self._message = None, set(), ""
        self._rates.watch({})
        if self._event_sub is not None:
            self._node.destroy_subscription(self._event_sub)
            self._event_sub = None
        if target:
            # The executor thread hands each event to the UI thread.
            self._event_sub = self._node.create_subscription(
                TransitionEvent,
                f"{target}/transition_event",
                lambda event: self._ui.post(lambda: self._on_event(target, event)),
                10,
            )
            self._poll()

    def _on_event(self, target: str, event: TransitionEvent) -> None:
        if target == self._target:
            self._state = event.goal_state.label
            self._poll()

    def _poll(self) -> None:
        target = self._target
        if target is None:
            return
        if self._polling:
            # The job out may have read the state before this change: its answer would show
            # the old state's transitions (clickable, wrong) until the next poll, 2 s on.
            self._stale = True
            return
        self._polling, self._stale = True, False
        self._last_poll = time.monotonic()
        ctx = panel_context(self._node)

        def work() -> tuple[str, set[str]]:
            _id, state = lc.get_state(ctx, target)
            return state, {t.label for t in lc.available_transitions(ctx, target)}

        def done(answer: tuple[str, set[str]]) -> None:
            self._polling = False
            if self._stale:
                self._poll()
            elif self._target == target:
                self._state, self._available = answer

        def failed(text: str) -> None:
            self._polling = False
            self._message = f"⚠️ {text}"
            if self._stale:
                self._poll()

        self._ui.run_job(work, done, failed)

    def _transition(self, label: str) -> None:
        target = self._target
        if target is None or self._changing or label not in self._available:
            return
        command = f"ros2 lifecycle set {target} {label}"
        self._message = f"`{command}` …"
        self._changing = True
        ctx = panel_context(self._node)

        def done(answer: tuple[bool, lc.TransitionInfo]) -> None:
            ok, chosen = answer
            self._changing = False
            verdict = "Transitioning successful" if ok else "Transitioning failed"
            self._message = f"`{command}` → **{verdict}** ({chosen.start} → {chosen.goal})"
            self._poll()

        def failed(text: str) -> None:
            self._changing = False
            self._message = f"⚠️ {text}"
            self._poll()

        self._ui.run_job(lambda: lc.change_state(ctx, target, label), done, failed)

    # --- refresh ---------------------------------------------------------------

    def refresh(self, graph: GraphSnapshot) -> None:
        nodes = graph.nodes_serving("/get_state", lc.GET_STATE_TYPE)
        if nodes != self._nodes:
            self._nodes = nodes
            set_options(self._selector, nodes or [NONE], keep_current=False)
            self._select(self._selector.value)
        target = self._target
        if target and time.monotonic() - self._last_poll > POLL_SEC:
            self._poll()
        available = set() if self._changing else self._available
        html = SINK_FRAME + draw_state_machine(self._state, available, self._edge_link)
        if html != self._diagram_html:
            self._diagram_html = html
            self._diagram.content = html
        for label, button in self._buttons.items():
            disabled = self._changing or label not in self._available
            if button.disabled != disabled:
                button.disabled = disabled
        if target is None:
            self._result.show("_Start **lifecycle_talker** in the Nodes tab._")
            self._log.show("")
            return
        # Publishers appear on configure and go on cleanup: measure what exists now.
        self._rates.watch(published_topics(self._node, target))
        self._result.show(
            f"Current state of `{target}`: **{self._state or '…'}** · "
            f"`ros2 lifecycle get {target}`\n\n"
            + self._rates_text()
            + (f"\n\n{self._message}" if self._message else "")
        )
        # Few lines: on a laptop's screen the log sits under the diagram, and the newest
        # (what the last transition said) must be in view without scrolling.
        lines = [format_record(r) for r in self._rosout.records(target, last=LOG_LINES)]
        self._log.show(f"Log of `{target}` (/rosout), newest last:\n\n" + code_block(lines))

    def _rates_text(self) -> str:
        parts = [
            f"`{topic}`: **{rate_text(self._rates.rate(topic)) or 'silent'}** "
            f"(`ros2 topic hz {topic}`)"
            for topic in self._rates.watched()
        ]
        return "Publishing: " + (" · ".join(parts) if parts else "no topics yet")

    def release(self) -> None:
        """Follow no node until the next refresh (the stage while it is not shown)."""
        self._nodes = []
        self._select(NONE)

    def close(self) -> None:
        self._rates.close()
        if self._event_sub is not None:
            self._node.destroy_subscription(self._event_sub)
            self._event_sub = None
