"""Actions panel: goal form, feedback as it arrives, cancel, final status and result."""

from __future__ import annotations

import viser
from rclpy.node import Node

from app.ros.calls import GoalRun, action_type_of, send_goal
from app.ros.context import panel_context
from app.ros.convert import ConversionError, import_type, to_yaml, yaml_inline
from app.ros.errors import Ros2Error
from app.ros.graph import GraphSnapshot
from app.ui import MarkdownView, assign, code_block, set_options
from app.ui.forms import FormSlot
from app.ui.loop import UiLoop

NONE = "(no action)"
SHOWN_FEEDBACK = 8


class ActionsPanel:
    def __init__(self, gui: viser.GuiApi, ui: UiLoop, node: Node) -> None:
        self._ui = ui
        self._node = node
        self._actions: tuple[str, ...] = ()
        self._types: dict[str, str] = {}
        self._run: GoalRun | None = None  # its fields are written by the goal's job thread
        self._message = ""
        self._selector = gui.add_dropdown("Action", [NONE], initial_value=NONE)
        self._info = MarkdownView(gui, "")
        self._form_slot = FormSlot(gui, "Goal")
        self._send = gui.add_button("Send goal", icon=viser.Icon.SEND, disabled=True)
        self._cancel = gui.add_button("Cancel goal", icon=viser.Icon.X, disabled=True)
        self._view = MarkdownView(gui, "")
        self._send.on_click(ui.callback(self._do_send))
        self._cancel.on_click(ui.callback(self._do_cancel))
        self._selector.on_update(ui.callback(self._rebuild_form))

    def inspect(self, kind: str, name: str, type_text: str) -> None:
        """An action clicked on the stage graph (UI thread): pick it; one not listed is left."""
        if kind == "action" and name in self._selector.options and name != self._selector.value:
            assign(self._selector, name)
            self._rebuild_form()

    def _rebuild_form(self) -> None:
        name = self._selector.value
        type_text = self._types.get(name)
        if type_text is None and name in self._actions:
            type_text = action_type_of(self._node, name)
            if type_text:
                self._types[name] = type_text

        def build() -> tuple[type, str]:
            return import_type(type_text or "", "action").Goal, f"{type_text} goal"

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
        command = f"ros2 action send_goal {name} {type_text} {yaml_inline(goal)} --feedback"
        run = GoalRun(name, type_text, goal, command=command)
        self._run, self._message = run, ""
        self._cancel.disabled = False
        ctx = panel_context(self._node)
        self._ui.run_job(lambda: send_goal(ctx, run), None, self._show_error)

    def _show_error(self, text: str) -> None:
        self._message = f"⚠️ {text}"

    def _do_cancel(self) -> None:
        if self._run is not None:
            self._run.cancel()

    def refresh(self, graph: GraphSnapshot) -> None:
        if graph.actions != self._actions:
            self._actions = graph.actions
            set_options(self._selector, list(graph.actions) or [NONE], keep_current=False)
            self._rebuild_form()
        elif self._selector.value in self._actions and self._selector.value not in self._types:
            # An action is listed from its services, but its type is read from its
            # topics, which discovery may bring later: ask again until they come.
            self._rebuild_form()
        name = self._selector.value
        type_text = self._types.get(name)
        if type_text:
            info = f"Type: `{type_text}` · `ros2 action info {name} -t`"
        elif name in self._actions:
            info = f"_`{name}` is on the graph; waiting for its topics to learn its type…_"
        else:
            info = "_No action on the graph: start **fibonacci_action_server** in the Nodes tab._"
        self._info.show(info)
        run = self._run
        if run is None:
            self._view.show(self._message)
            return
        if run.done.is_set() and not self._cancel.disabled:
            self._cancel.disabled = True
        feedback = list(run.feedback)[-SHOWN_FEEDBACK:]
        parts = [f"`{run.command}`", "", f"Status: **{run.status}**"]
        if run.goal_id:
            parts.append(f"Goal id: `{run.goal_id}`")
        parts += ["", f"Feedback ({len(run.feedback)} received):"]
        parts.append(code_block([to_yaml(f) for f in feedback], "(none yet)"))
        if run.result is not None:
            parts += ["", "Result:", code_block([to_yaml(run.result)])]
        if self._message:
            parts += ["", self._message]
        self._view.show("\n".join(parts))

    def close(self) -> None:
        if self._run is not None:
            self._run.cancel()
