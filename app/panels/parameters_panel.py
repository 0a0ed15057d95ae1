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
import time
from dataclasses import dataclass
from typing import cast

import viser
from rcl_interfaces.msg import ParameterDescriptor, ParameterType, ParameterValue
from rclpy.node import Node

from app.ros import params as rp
from app.ros.context import CallContext, panel_context
from app.ros.graph import GraphSnapshot, published_topics
from app.ros.rates import RateBoard, rate_text
from app.ros.rosout import RosoutLog, format_record
from app.ui import Input, MarkdownView, assign, code_block, set_options
from app.ui.loop import UiLoop

NONE = "(pick a node)"
SYNC_PERIOD_SEC = 3.0
LOG_LINES = 6

# What an editor holds: a checkbox's bool, a number's or slider's number, or text.
EditorValue = bool | int | float | str


@dataclass(frozen=True)
class ParamSpec:
    """What an editor needs to know about one parameter."""

    name: str
    type: int
    value: object  # as rp.python_value gives it
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


def value_for(spec: ParamSpec, widget_value: EditorValue) -> object:
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


def command_value(value: object) -> str:
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
    calm = True  # once a second while idle (app.ui.Panel): values change when set, with a wake

    def __init__(
        self, gui: viser.GuiApi, ui: UiLoop, node: Node, rosout: RosoutLog | None = None
    ) -> None:
        self._gui = gui
        self._ui = ui
        self._node = node
        self._rosout = rosout
        self._nodes: list[str] = []
        self._target: str | None = None
        self._loading = False
        self._syncing = False
        self._synced_at = 0.0
        self._built_for: str | None = None
        self._specs: dict[str, ParamSpec] = {}
        self._widgets: dict[str, Input[EditorValue]] = {}
        # What each editor showed when it last matched the node: an editor whose
        # value differs from it is being edited, and a sync leaves it alone.
        self._known: dict[str, object] = {}
        self._message = ""
        self._rates = RateBoard(node, limit=8)
        gui.add_markdown(
            "A node's parameters are settings it reads while it runs. Pick a node, "
            "change a value, press its **Set** button: the node may accept or refuse."
        )
        self._selector = gui.add_dropdown("Node", [NONE], initial_value=NONE)
        self._info = MarkdownView(gui, "")
        self._result = MarkdownView(gui, "")  # above the editors: seen right after a click
        self._editors = gui.add_folder("Parameters", expand_by_default=True)
        self._editor_folder: viser.GuiFolderHandle | None = None
        self._activity = MarkdownView(gui, "")
        self._selector.on_update(ui.callback(lambda: self._select(self._selector.value)))

    def _ctx(self) -> CallContext:
        return panel_context(self._node)

    def _show_error(self, text: str) -> None:
        self._message = f"⚠️ {text}"

    # --- loading ---------------------------------------------------------------

    def inspect(self, kind: str, node: str, type_text: str) -> None:
        """A node clicked on the stage graph (UI thread): show its parameters."""
        if kind == "node" and node in self._nodes and node != self._selector.value:
            assign(self._selector, node)
            self._select(node)

    def _select(self, choice: str) -> None:
        target = None if choice == NONE else choice
        if target == self._target:
            return
        self._target, self._message = target, ""
        self._rates.watch({})
        self._remove_editors()
        if target:
            self._load(target)

    def _load(self, target: str) -> None:
        """Fetch names, values and descriptors on a worker; build the editors after."""
        self._loading = True
        self._synced_at = time.monotonic()
        ctx = self._ctx()

        def work() -> list[ParamSpec]:
            names = rp.list_names(ctx, target)
            values = rp.get_values(ctx, target, names) if names else []
            descriptors = rp.describe(ctx, target, names) if names else []
            return [spec_from(n, v, d) for n, v, d in zip(names, values, descriptors, strict=False)]

        def done(specs: list[ParamSpec]) -> None:
            self._loading = False
            if self._target == target:
                self._build(target, specs)

        def failed(text: str) -> None:
            self._loading = False
            self._show_error(text)

        self._ui.run_job(work, done, failed)

    # --- editors -------------------------------------------------------------------

    def _remove_editors(self) -> None:
        if self._editor_folder is not None:
            self._editor_folder.remove()
            self._editor_folder = None
        self._built_for = None
        self._widgets, self._known, self._specs = {}, {}, {}

    def _build(self, target: str, specs: list[ParamSpec]) -> None:
        self._remove_editors()
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
                button.on_click(self._ui.callback(self._set, spec.name))
        self._built_for = target

    def _editor(self, spec: ParamSpec) -> Input[EditorValue]:
        gui, label, value = self._gui, spec.name, spec.value
        disabled = spec.read_only
        if spec.type == ParameterType.PARAMETER_BOOL:
            return gui.add_checkbox(label, bool(value), disabled=disabled)
        if spec.type in (ParameterType.PARAMETER_INTEGER, ParameterType.PARAMETER_DOUBLE):
            whole = spec.type == ParameterType.PARAMETER_INTEGER
            amount = cast(float, value or 0)  # an integer or a double parameter's number
            number = int(amount) if whole else float(amount)
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
            self._show_error(str(exc))
            return
        command = f"ros2 param set {target} {name} {command_value(value)}"
        self._message = f"`{command}` …"
        ctx = self._ctx()

        def work() -> tuple[bool, str, object]:
            ok, reason = rp.set_value(ctx, target, name, value)
            kept = None if ok else rp.python_value(rp.get_values(ctx, target, [name])[0])
            return ok, reason, kept

        def done(answer: tuple[bool, str, object]) -> None:
            ok, reason, kept = answer
            if ok:
                verdict = "✅ Set parameter successful"
                # The node now holds what was *sent*; the editor may hold a newer edit.
                if self._built_for == target and name in self._known:
                    self._known[name] = shown_value(spec, value)
            else:
                verdict = (
                    "❌ Set parameter failed"
                    + (f": **{reason}**" if reason else "")
                    + f"\n\nThe node keeps `{name}` = `{command_value(kept)}`."
                )
            self._message = f"`{command}`\n\n{verdict}"
            self._sync(target)

        self._ui.run_job(work, done, lambda text: self._show_error(f"`{command}`: {text}"))

    def _sync(self, target: str) -> None:
        """Re-read values: another tool may have changed them (e.g. the Console)."""
        names = list(self._specs)
        if not names or self._syncing:
            return
        self._syncing = True
        self._synced_at = time.monotonic()
        ctx = self._ctx()

        def work() -> dict[str, object]:
            values = rp.get_values(ctx, target, names)
            return {n: rp.python_value(v) for n, v in zip(names, values, strict=False)}

        def done(fresh: dict[str, object]) -> None:
            self._syncing = False
            if self._built_for == target:
                self._apply_synced(fresh)

        def failed(text: str) -> None:
            self._syncing = False
            self._show_error(text)

        self._ui.run_job(work, done, failed)

    def _apply_synced(self, fresh: dict[str, object]) -> None:
        for name, value in fresh.items():
            widget, spec = self._widgets.get(name), self._specs.get(name)
            if widget is None or spec is None or value is None:
                continue
            shown = shown_value(spec, value)
            # Only overwrite what the learner has not started editing.
            if widget.value == self._known.get(name) and widget.value != shown:
                assign(widget, shown)
            if widget.value == shown:
                self._known[name] = shown

    # --- refresh ---------------------------------------------------------------

    def refresh(self, graph: GraphSnapshot) -> None:
        nodes = graph.nodes_serving("/list_parameters")
        if nodes != self._nodes:
            self._nodes = nodes
            set_options(self._selector, [NONE, *nodes])  # the value stays: it is in options
        target = self._target
        if target and self._built_for == target and not self._loading:
            if time.monotonic() - self._synced_at > SYNC_PERIOD_SEC:
                self._sync(target)
        self._show_status(target, graph)

    def _show_status(self, target: str | None, graph: GraphSnapshot) -> None:
        if target is None:
            self._info.show("_Start **parameters_node** in the Nodes tab, then pick it here._")
            self._activity.show("")
            self._result.show(self._message)
            return
        gone = not graph.has_node(target)
        self._info.show(
            (f"⚠️ `{target}` is not on the graph now.\n\n" if gone else "")
            + f"`ros2 param list {target}` · `ros2 param dump {target}`"
            + ("" if self._built_for == target else "\n\nreading parameters…")
        )
        self._result.show(self._message)
        if not gone:
            self._rates.watch(published_topics(self._node, target))
        rates = [
            f"`{topic}`: **{rate_text(self._rates.rate(topic)) or '…'}** (`ros2 topic hz {topic}`)"
            for topic in self._rates.watched()
        ]
        parts = ["Publishing: " + (" · ".join(rates) if rates else "nothing")]
        if self._rosout is not None:
            lines = [format_record(r) for r in self._rosout.records(target, last=LOG_LINES)]
            parts += ["", f"Latest log lines of `{target}`:", "", code_block(lines)]
        self._activity.show("\n".join(parts))

    def close(self) -> None:
        self._rates.close()


def shown_value(spec: ParamSpec, value: object) -> object:
    """A parameter value as its editor holds it: plain types as they are, others as text."""
    return value if spec.type in _PLAIN_TYPES else str(value)


_PLAIN_TYPES = (
    ParameterType.PARAMETER_BOOL,
    ParameterType.PARAMETER_INTEGER,
    ParameterType.PARAMETER_DOUBLE,
    ParameterType.PARAMETER_STRING,
)


def _nice_step(span: float) -> float:
    """A power of ten giving 100 to 1000 positions, so round values like 5.0 are reachable."""
    return 10.0 ** math.floor(math.log10(span / 100))
