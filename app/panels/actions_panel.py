"""Actions panel: goal form, feedback as it arrives, cancel, final status and result."""

from __future__ import annotations

import threading

import viser
from rclpy.node import Node

from app.graph import GraphSnapshot
from app.panels import MarkdownView, code_block
from app.panels.ros_tools import FormSlot, run_job, yaml_inline
from app.ros2cli import CONSOLE_LIMITS, Ros2Error, VerbContext
from app.ros2cli.calls import GoalRun, action_type_of, send_goal
from app.ros2cli.convert import ConversionError, import_type, to_yaml

NONE = "(no action)"
SHOWN_FEEDBACK = 8


class ActionsPanel:
    def __init__(self, gui: viser.GuiApi, node: Node) -> None:
        self._gui = gui
        self._node = node
        self._lock = threading.Lock()
        self._actions: tuple[str, ...] = ()
        self._types: dict[str, str] = {}
        self._selector = gui.add_dropdown("Action", [NONE], initial_value=NONE)
        self._info = MarkdownView(gui, "")
        self._form_slot = FormSlot(gui, "Goal")
        self._send = gui.add_button("Send goal", icon=viser.Icon.SEND, disabled=True)
        self._cancel = gui.add_button("Cancel goal", icon=viser.Icon.X, disabled=True)
        self._view = MarkdownView(gui, "")
        self._run: GoalRun | None = None
        self._ctx: VerbContext | None = None
        self._message = ""
        self._send.on_click(lambda _: self._do_send())
        self._cancel.on_click(lambda _: self._do_cancel())
        self._selector.on_update(lambda _: self._rebuild_form())

    def _rebuild_form(self) -> None:
        name = self._selector.value
        type_text = self._types.get(name)
        if type_text is None and name in self._actions:
            type_text = action_type_of(VerbContext(self._node, lambda _l: None), name)
            if type_text:
                self._types[name] = type_text

        def build() -> tuple[type, str]:
            return import_type(type_text, "action").Goal, f"{type_text} goal"

        try:
            form = self._form_slot.show((name, type_text or ""), build if type_text else None)
        except ConversionError as exc:
            self._message = f"⚠️ {exc}"
            form = None
        self._send.disabled = form is None

    def _do_send(self) -> None:
        name, form = self._selector.value, self._form_slot.form
        type_text = self._types.get(name)
        if form is None or type_text is None:
            return
        if self._run is not None and not self._run.done.is_set():
            self._message = "⚠️ a goal is still running: cancel it first"
            return
        try:
            goal = form.message()
        except Ros2Error as exc:
            self._message = f"⚠️ {exc}"
            return
        run = GoalRun(name, type_text, goal)
        ctx = VerbContext(self._node, lambda _l: None, CONSOLE_LIMITS)
        with self._lock:
            self._run, self._ctx = run, ctx
            self._message = ""
        command = f"ros2 action send_goal {name} {type_text} {yaml_inline(goal)} --feedback"
        run.command = command  # type: ignore[attr-defined]
        self._cancel.disabled = False

        def failed(text: str) -> None:
            with self._lock:
                self._message = f"⚠️ {text}"

        run_job(lambda: send_goal(ctx, run), failed)

    def _do_cancel(self) -> None:
        with self._lock:
            run, ctx = self._run, self._ctx
        if run is not None and ctx is not None:
            run.cancel(ctx)

    def refresh(self, graph: GraphSnapshot | None) -> None:
        if graph is not None and graph.actions != self._actions:
            self._actions = graph.actions
            options = list(graph.actions) or [NONE]
            current = self._selector.value
            self._selector.options = options
            if current in options:
                self._selector.value = current
            self._rebuild_form()
        name = self._selector.value
        type_text = self._types.get(name)
        self._info.show(
            f"Type: `{type_text}` · `ros2 action info {name} -t`"
            if type_text
            else "_No action on the graph: start **fibonacci_action_server** in the Nodes tab._"
        )
        with self._lock:
            run, message = self._run, self._message
        if run is None:
            self._view.show(message)
            return
        finished = run.done.is_set()
        if finished and not self._cancel.disabled:
            self._cancel.disabled = True
        feedback = list(run.feedback)[-SHOWN_FEEDBACK:]
        parts = [f"`{getattr(run, 'command', '')}`", "", f"Status: **{run.status}**"]
        if run.goal_id:
            parts.append(f"Goal id: `{run.goal_id}`")
        parts += ["", f"Feedback ({len(run.feedback)} received):"]
        parts.append(code_block([to_yaml(f) for f in feedback], "(none yet)"))
        if run.result is not None:
            parts += ["", "Result:", code_block([to_yaml(run.result)])]
        if message:
            parts += ["", message]
        self._view.show("\n".join(parts))
