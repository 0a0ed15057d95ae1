"""Parameters panel: pick a node, edit its parameters with typed editors, Set, see the answer.

Names, values and descriptors come from the node's own parameter services
(list/get/describe, through app.ros2cli.param, the same code as `ros2 param`),
fetched on worker threads; the editors are built on the UI thread once the
answers are in. A descriptor's range becomes a slider; a refused set shows
the reason the node gave. The node's publishing rate and latest log lines sit
below, so a learner sees a change take effect.
"""

from __future__ import annotations

import math
import shlex
import threading
import time
from dataclasses import dataclass
from typing import Any

import viser
from rcl_interfaces.msg import ParameterDescriptor, ParameterType, ParameterValue
from rclpy.node import Node

from app.graph import GraphSnapshot
from app.panels import MarkdownView, code_block
from app.panels.graph_svg import QUIET_TOPICS
from app.panels.logs_panel import RosoutLog, format_record
from app.panels.rates import RateBoard, rate_text
from app.panels.ros_tools import run_job
from app.ros2cli import CONSOLE_LIMITS, VerbContext
from app.ros2cli import param as rp
from app.ros2cli.common import split_node_name

NONE = "(pick a node)"
SYNC_PERIOD_SEC = 3.0
LOG_LINES = 6


@dataclass(frozen=True)
class ParamSpec:
    """What an editor needs to know about one parameter."""

    name: str
    type: int
    value: Any
    description: str = ""
    read_only: bool = False
    low: float | None = None
    high: float | None = None
    step: float | None = None

    @property
    def type_word(self) -> str:
        return rp.TYPE_NAMES.get(self.type, "?")


def spec_from(name: str, value: ParameterValue, descriptor: ParameterDescriptor) -> ParamSpec:
    """A ParamSpec from get_parameters + describe_parameters answers."""
    low = high = step = None
    if descriptor.floating_point_range:
        r = descriptor.floating_point_range[0]
        low, high, step = r.from_value, r.to_value, r.step or None
    elif descriptor.integer_range:
        r = descriptor.integer_range[0]
        low, high, step = float(r.from_value), float(r.to_value), float(r.step or 1)
    kind = value.type if value.type != ParameterType.PARAMETER_NOT_SET else descriptor.type
    return ParamSpec(
        name,
        kind,
        rp.python_value(value),
        descriptor.description,
        descriptor.read_only,
        low,
        high,
        step,
    )


def value_for(spec: ParamSpec, widget_value: Any) -> Any:
    """What the editor holds, as the Python value of the parameter's own type."""
    if spec.type == ParameterType.PARAMETER_BOOL:
        return bool(widget_value)
    if spec.type == ParameterType.PARAMETER_INTEGER:
        number = float(widget_value)
        if not number.is_integer():
            raise ValueError(f"{spec.name} needs a whole number, got {widget_value}")
        return int(number)
    if spec.type == ParameterType.PARAMETER_DOUBLE:
        return float(widget_value)
    if spec.type == ParameterType.PARAMETER_STRING:
        return str(widget_value)
    return rp.parse_value(str(widget_value))  # arrays and untyped: YAML, as ros2 param set


def command_value(value: Any) -> str:
    """A value as it would be typed after `ros2 param set <node> <name>`."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return shlex.quote(value) if value else "''"
    return str(value)


def describe_spec(spec: ParamSpec) -> str:
    parts = [spec.type_word]
    if spec.low is not None and spec.high is not None:
        parts.append(f"{spec.low:g} to {spec.high:g}")
    if spec.read_only:
        parts.append("read-only")
    text = f"**{spec.name}** ({', '.join(parts)})"
    return text + (f": {spec.description}" if spec.description else "")


class ParametersPanel:
    def __init__(self, gui: viser.GuiApi, node: Node, rosout: RosoutLog | None = None) -> None:
        self._gui = gui
        self._node = node
        self._rosout = rosout
        self._lock = threading.Lock()
        self._nodes: list[str] = []
        self._target: str | None = None
        self._loaded: tuple[str, list[ParamSpec]] | None = None  # from a worker
        self._built_for: str | None = None
        self._specs: dict[str, ParamSpec] = {}
        self._widgets: dict[str, Any] = {}
        self._known: dict[str, Any] = {}
        self._busy = False
        self._synced_at = 0.0
        self._message = ""
        self._pending_values: dict[str, Any] | None = None
        self._rates = RateBoard(node, limit=8)
        gui.add_markdown(
            "A node's parameters are settings it reads while it runs. Pick a node, "
            "change a value, press its **Set** button: the node may accept or refuse."
        )
        self._selector = gui.add_dropdown("Node", [NONE], initial_value=NONE)
        self._info = MarkdownView(gui, "")
        self._result = MarkdownView(gui, "")  # above the editors: seen right after a click
        self._editors = gui.add_folder("Parameters", expand_by_default=True)
        self._editor_folder: Any = None
        self._activity = MarkdownView(gui, "")
        self._selector.on_update(lambda _: self._select(self._selector.value))

    def _ctx(self) -> VerbContext:
        return VerbContext(self._node, lambda _line: None, CONSOLE_LIMITS)

    def _show_error(self, text: str) -> None:
        with self._lock:
            self._message = f"⚠️ {text}"
            self._busy = False

    # --- loading ---------------------------------------------------------------

    def _select(self, choice: str) -> None:
        target = None if choice == NONE else choice
        with self._lock:
            if target == self._target:
                return
            self._target, self._loaded, self._message = target, None, ""
            self._busy = False
        self._rates.watch({})
        if target:
            self._load(target)

    def _load(self, target: str) -> None:
        """Fetch names, values and descriptors off the callback thread."""
        with self._lock:
            if self._busy:
                return
            self._busy = True
            self._synced_at = time.monotonic()

        def work() -> None:
            ctx = self._ctx()
            names = rp.list_names(ctx, target)
            values = rp.get_values(ctx, target, names) if names else []
            descriptors = rp.describe(ctx, target, names) if names else []
            specs = [
                spec_from(n, v, d) for n, v, d in zip(names, values, descriptors, strict=False)
            ]
            with self._lock:
                if self._target == target:
                    self._loaded = (target, specs)
                self._busy = False

        run_job(work, self._show_error)

    # --- editors (UI thread) ------------------------------------------------------

    def _build(self, target: str, specs: list[ParamSpec]) -> None:
        if self._editor_folder is not None:
            self._editor_folder.remove()
        self._widgets, self._known = {}, {}
        self._specs = {s.name: s for s in specs}
        gui = self._gui
        with self._editors:
            self._editor_folder = gui.add_folder(target, expand_by_default=True)
        with self._editor_folder:
            if not specs:
                gui.add_markdown("_(this node has no parameters)_")
            for spec in specs:
                gui.add_markdown(describe_spec(spec) + f"  \n`ros2 param get {target} {spec.name}`")
                self._widgets[spec.name] = self._editor(spec)
                self._known[spec.name] = self._widgets[spec.name].value
                button = gui.add_button(
                    f"Set {spec.name}", icon=viser.Icon.DEVICE_FLOPPY, disabled=spec.read_only
                )
                button.on_click(lambda _e, name=spec.name: self._set(name))
        self._built_for = target

    def _editor(self, spec: ParamSpec) -> Any:
        gui, label, value = self._gui, spec.name, spec.value
        disabled = spec.read_only
        if spec.type == ParameterType.PARAMETER_BOOL:
            return gui.add_checkbox(label, bool(value), disabled=disabled)
        if spec.type in (ParameterType.PARAMETER_INTEGER, ParameterType.PARAMETER_DOUBLE):
            whole = spec.type == ParameterType.PARAMETER_INTEGER
            number = int(value or 0) if whole else float(value or 0.0)
            if spec.low is not None and spec.high is not None and spec.high > spec.low:
                step = spec.step or (1 if whole else _nice_step(spec.high - spec.low))
                return gui.add_slider(label, spec.low, spec.high, step, number, disabled=disabled)
            return gui.add_number(label, number, step=1 if whole else 0.01, disabled=disabled)
        if spec.type == ParameterType.PARAMETER_STRING:
            return gui.add_text(label, str(value or ""), disabled=disabled)
        text = "" if value is None else str(value)
        return gui.add_text(label, text, hint="YAML, e.g. [1, 2, 3]", disabled=disabled)

    def _set(self, name: str) -> None:
        target, spec, widget = self._target, self._specs.get(name), self._widgets.get(name)
        if target is None or spec is None or widget is None:
            return
        try:
            value = value_for(spec, widget.value)
        except ValueError as exc:
            self._message = f"⚠️ {exc}"
            return
        command = f"ros2 param set {target} {name} {command_value(value)}"
        with self._lock:
            self._message = f"`{command}` …"

        def work() -> None:
            ctx = self._ctx()
            ok, reason = rp.set_value(ctx, target, name, value)
            if ok:
                verdict = "✅ Set parameter successful"
            else:
                kept = rp.python_value(rp.get_values(ctx, target, [name])[0])
                verdict = (
                    "❌ Set parameter failed"
                    + (f": **{reason}**" if reason else "")
                    + f"\n\nThe node keeps `{name}` = `{command_value(kept)}`."
                )
            with self._lock:
                self._message = f"`{command}`\n\n{verdict}"
                if ok:
                    self._known[name] = widget.value
            self._sync(target)

        run_job(work, self._show_error)

    def _sync(self, target: str) -> None:
        """Re-read values: another tool may have changed them (e.g. the Console)."""
        names = list(self._specs)
        if not names:
            return
        values = rp.get_values(self._ctx(), target, names)
        fresh = {n: rp.python_value(v) for n, v in zip(names, values, strict=False)}
        with self._lock:
            if self._target == target:
                self._pending_values = fresh

    def _apply_synced(self) -> None:
        with self._lock:
            fresh = self._pending_values
            self._pending_values = None
        for name, value in (fresh or {}).items():
            widget, spec = self._widgets.get(name), self._specs.get(name)
            if widget is None or spec is None or value is None:
                continue
            shown = value if spec.type in _PLAIN_TYPES else str(value)
            # Only overwrite what the learner has not started editing.
            if widget.value == self._known.get(name) and widget.value != shown:
                widget.value = shown
            self._known[name] = widget.value if widget.value == shown else shown

    # --- refresh ---------------------------------------------------------------

    def refresh(self, graph: GraphSnapshot | None) -> None:
        if graph is not None:
            nodes = sorted(
                name[: -len("/list_parameters")]
                for name, _types in graph.services
                if name.endswith("/list_parameters")
            )
            if nodes != self._nodes:
                self._nodes = nodes
                current = self._selector.value
                options = [NONE, *nodes]
                if current not in options:
                    options.append(current)
                self._selector.options = options  # the value stays: it is in options
        with self._lock:
            target, loaded, message = self._target, self._loaded, self._message
        if loaded is not None and loaded[0] == target and self._built_for != target:
            self._build(*loaded)
        elif target is None and self._built_for is not None:
            if self._editor_folder is not None:
                self._editor_folder.remove()
                self._editor_folder = None
            self._built_for = None
        self._apply_synced()
        if target and self._built_for == target and not self._busy:
            if time.monotonic() - self._synced_at > SYNC_PERIOD_SEC:
                self._synced_at = time.monotonic()
                run_job(lambda: self._sync(target), self._show_error)
        self._show_status(target, graph, message)

    def _show_status(self, target: str | None, graph: GraphSnapshot | None, message: str) -> None:
        if target is None:
            self._info.show("_Start **parameters_node** in the Nodes tab, then pick it here._")
            self._activity.show("")
            self._result.show(message)
            return
        gone = graph is not None and not graph.has_node(target)
        self._info.show(
            (f"⚠️ `{target}` is not on the graph now.\n\n" if gone else "")
            + f"`ros2 param list {target}` · `ros2 param dump {target}`"
            + ("" if self._built_for == target else "\n\nreading parameters…")
        )
        self._result.show(message)
        name, namespace = split_node_name(target)
        if graph is not None and not gone:
            try:
                published = self._node.get_publisher_names_and_types_by_node(name, namespace)
            except Exception:  # noqa: BLE001 - the node left between two looks
                published = []
            self._rates.watch(
                {
                    topic: types[0]
                    for topic, types in published
                    if types and topic not in QUIET_TOPICS and "/_" not in topic
                }
            )
        rates = [
            f"`{topic}`: **{rate_text(self._rates.rate(topic)) or '…'}** (`ros2 topic hz {topic}`)"
            for topic in self._rates.watched()
        ]
        parts = ["Publishing: " + (" · ".join(rates) if rates else "nothing")]
        if self._rosout is not None:
            lines = [format_record(r) for r in self._rosout.records(target, last=LOG_LINES)]
            parts += ["", f"Latest log lines of `{target}`:", "", code_block(lines)]
        self._activity.show("\n".join(parts))


_PLAIN_TYPES = (
    ParameterType.PARAMETER_BOOL,
    ParameterType.PARAMETER_INTEGER,
    ParameterType.PARAMETER_DOUBLE,
    ParameterType.PARAMETER_STRING,
)


def _nice_step(span: float) -> float:
    """A power of ten giving 100 to 1000 positions, so round values like 5.0 are reachable."""
    return 10.0 ** math.floor(math.log10(span / 100))
