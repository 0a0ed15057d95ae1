"""Services panel: pick a service, fill the form generated from its request type, call it."""

from __future__ import annotations

import threading

import viser
from rclpy.node import Node

from app.graph import GraphSnapshot
from app.panels import MarkdownView
from app.panels.ros_tools import FormSlot, run_job, yaml_inline
from app.ros2cli import CONSOLE_LIMITS, Ros2Error, VerbContext
from app.ros2cli.calls import call_service
from app.ros2cli.convert import ConversionError, import_type, message_repr

NONE = "(no service)"
HIDDEN_SUFFIXES = (
    "/describe_parameters", "/get_parameter_types", "/get_parameters", "/get_type_description",
    "/list_parameters", "/set_parameters", "/set_parameters_atomically",
)  # fmt: skip


class ServicesPanel:
    def __init__(self, gui: viser.GuiApi, node: Node) -> None:
        self._gui = gui
        self._node = node
        self._lock = threading.Lock()
        self._services: dict[str, str] = {}
        self._show_all = gui.add_checkbox("Show parameter services", False)
        self._selector = gui.add_dropdown("Service", [NONE], initial_value=NONE)
        self._info = MarkdownView(gui, "")
        self._form_slot = FormSlot(gui, "Request")
        self._call = gui.add_button("Call", icon=viser.Icon.SEND, disabled=True)
        self._result = MarkdownView(gui, "")
        self._message = ""
        self._call.on_click(lambda _: self._do_call())
        self._selector.on_update(lambda _: self._rebuild_form())

    def _rebuild_form(self) -> None:
        name = self._selector.value
        type_text = self._services.get(name)

        def build() -> tuple[type, str]:
            return import_type(type_text, "srv").Request, f"{type_text} request"

        try:
            form = self._form_slot.show((name, type_text), build if type_text else None)
        except ConversionError as exc:
            self._set_message(f"⚠️ {exc}")
            form = None
        self._call.disabled = form is None

    def _set_message(self, text: str) -> None:
        with self._lock:
            self._message = text

    def _do_call(self) -> None:
        name, form = self._selector.value, self._form_slot.form
        type_text = self._services.get(name)
        if form is None or type_text is None:
            return
        try:
            request = form.message()
        except Ros2Error as exc:
            self._set_message(f"⚠️ {exc}")
            return
        command = f"ros2 service call {name} {type_text} {yaml_inline(request)}"
        self._set_message(f"`{command}`\n\nwaiting for the response…")

        def work() -> None:
            ctx = VerbContext(self._node, lambda _l: None, CONSOLE_LIMITS)
            response = call_service(ctx, name, import_type(type_text, "srv"), request)
            self._set_message(f"`{command}`\n\n**response:** `{message_repr(response)}`")

        run_job(work, lambda text: self._set_message(f"`{command}`\n\n⚠️ {text}"))

    def refresh(self, graph: GraphSnapshot | None) -> None:
        if graph is not None:
            services = {
                name: types[0]
                for name, types in graph.services
                if types and (self._show_all.value or not name.endswith(HIDDEN_SUFFIXES))
            }
            if services != self._services:
                self._services = services
                options = sorted(services) or [NONE]
                current = self._selector.value
                self._selector.options = options
                if current in options:
                    self._selector.value = current
                self._rebuild_form()
        name = self._selector.value
        type_text = self._services.get(name)
        info = (
            f"Type: `{type_text}` · `ros2 service type {name}`"
            if type_text
            else ("_No service on the graph: start **add_two_ints_server** in the Nodes tab._")
        )
        self._info.show(info)
        with self._lock:
            self._result.show(self._message)
