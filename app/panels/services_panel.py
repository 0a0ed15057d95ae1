"""Services panel: pick a service, fill the form generated from its request type, call it."""

from __future__ import annotations

import viser
from rclpy.node import Node

from app.ros.calls import call_service
from app.ros.context import panel_context
from app.ros.convert import ConversionError, import_type, message_repr, yaml_inline
from app.ros.errors import Ros2Error
from app.ros.graph import GraphSnapshot
from app.ui import MarkdownView, assign, set_options
from app.ui.forms import FormSlot
from app.ui.loop import UiLoop

NONE = "(no service)"
HIDDEN_SUFFIXES = (
    "/describe_parameters", "/get_parameter_types", "/get_parameters", "/get_type_description",
    "/list_parameters", "/set_parameters", "/set_parameters_atomically",
)  # fmt: skip


class ServicesPanel:
    calm = True  # once a second while idle (app.ui.Panel): an answer wakes the loop

    def __init__(self, gui: viser.GuiApi, ui: UiLoop, node: Node) -> None:
        self._ui = ui
        self._node = node
        self._services: dict[str, str] = {}
        self._message = ""
        self._show_all = gui.add_checkbox("Show parameter services", False)
        self._selector = gui.add_dropdown("Service", [NONE], initial_value=NONE)
        self._info = MarkdownView(gui, "")
        self._form_slot = FormSlot(gui, "Request")
        self._call = gui.add_button("Call", icon=viser.Icon.SEND, disabled=True)
        self._result = MarkdownView(gui, "")
        self._call.on_click(ui.callback(self._do_call))
        self._selector.on_update(ui.callback(self._rebuild_form))

    def inspect(self, kind: str, name: str, type_text: str) -> None:
        """A service clicked on the stage graph (UI thread): pick it; one not listed is left."""
        if kind == "service" and name in self._selector.options and name != self._selector.value:
            assign(self._selector, name)
            self._rebuild_form()

    def _rebuild_form(self) -> None:
        name = self._selector.value
        type_text = self._services.get(name)

        def build() -> tuple[type, str]:
            return import_type(type_text or "", "srv").Request, f"{type_text} request"

        try:
            form = self._form_slot.show((name, type_text), build if type_text else None)
        except ConversionError as exc:
            self._message = f"⚠️ {exc}"
            form = None
        self._call.disabled = form is None

    def _do_call(self) -> None:
        name, form = self._selector.value, self._form_slot.form
        type_text = self._services.get(name)
        if form is None or type_text is None:
            return
        try:
            request = form.message()
        except Ros2Error as exc:
            self._message = f"⚠️ {exc}"
            return
        command = f"ros2 service call {name} {type_text} {yaml_inline(request)}"
        self._message = f"`{command}`\n\nwaiting for the response…"
        ctx = panel_context(self._node)

        def work() -> object:
            return call_service(ctx, name, import_type(type_text, "srv"), request)

        def done(response: object) -> None:
            self._message = f"`{command}`\n\n**response:** `{message_repr(response)}`"

        def failed(text: str) -> None:
            self._message = f"`{command}`\n\n⚠️ {text}"

        self._ui.run_job(work, done, failed)

    def refresh(self, graph: GraphSnapshot) -> None:
        services = {
            name: types[0]
            for name, types in graph.services
            if types and (self._show_all.value or not name.endswith(HIDDEN_SUFFIXES))
        }
        if services != self._services:
            self._services = services
            set_options(self._selector, sorted(services) or [NONE], keep_current=False)
            self._rebuild_form()
        name = self._selector.value
        type_text = self._services.get(name)
        self._info.show(
            f"Type: `{type_text}` · `ros2 service type {name}`"
            if type_text
            else "_No service on the graph: start **add_two_ints_server** in the Nodes tab._"
        )
        self._result.show(self._message)

    def close(self) -> None:
        """Calls in flight end by their own timeout; nothing is held here."""
