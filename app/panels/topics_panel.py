"""Topics panel: every topic with its counts; echo, hz, bw, a plot and a publish form for one.

One ``TopicMonitor`` (app.ros.monitor, the same one behind `ros2 topic echo/hz/bw`)
watches the selected topic as raw bytes; messages are deserialized here only
when new ones arrived, at most ``KEEP`` per refresh, so a fast or large topic
costs little. Publishing reuses the generated ``MessageForm``: once (after
waiting briefly for subscribers to match, as `ros2 topic pub --once` does) or
at a rate from a timer on the dashboard's node, never blocking a callback.
"""

from __future__ import annotations

import math
import time
from collections import deque

import numpy as np
import viser
import viser.uplot as uplot
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.timer import Timer

from app.ros.convert import (
    ConversionError,
    field_value,
    import_type,
    leaf_fields,
    to_yaml,
    type_name,
    yaml_inline,
)
from app.ros.errors import Ros2Error
from app.ros.graph import GraphSnapshot
from app.ros.monitor import TopicMonitor
from app.ros.qos import matching_qos
from app.ui import MarkdownView, assign, code_block, set_options, topic_item
from app.ui.forms import FormSlot
from app.ui.loop import UiLoop

NONE = "(pick a topic)"
NO_FIELD = "(no field)"
KEEP = 10  # raw messages the monitor keeps; also the most deserialized per refresh
SHOWN_MESSAGES = 3
ECHO_LINES = 36  # fewer messages are shown when each is long
PLOT_WINDOW_SEC = 30.0
PLOT_SAMPLES = 600
STATS_WINDOW_SEC = 5.0
MATCH_WAIT_SEC = 3.0
MAX_RATE_HZ = 100.0


def numeric_fields(cls: type) -> list[str]:
    """Paths of the number fields of a message type, nested ones too ('linear.x')."""
    return [path for path, _ros, kind in leaf_fields(cls) if kind in ("int", "float")]


def preferred_field(cls: type) -> str:
    """The field a learner most likely wants to see first: a float, else any number."""
    fields = leaf_fields(cls)
    for kind in ("float", "int"):
        found = next((path for path, _ros, k in fields if k == kind), None)
        if found:
            return found
    return NO_FIELD


def plot_value(msg: object, path: str) -> float | None:
    """The number at ``path`` as a float, or None when it is not a finite number."""
    try:
        value = field_value(msg, path)
    except ConversionError:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    value = float(value)
    return value if math.isfinite(value) else None


class TopicsPanel:
    def __init__(self, gui: viser.GuiApi, ui: UiLoop, node: Node) -> None:
        self._gui = gui
        self._ui = ui
        self._node = node
        self._types: dict[str, str] = {}
        self._counts: dict[str, tuple[int, int]] = {}
        self._topic: str | None = None
        self._monitor: TopicMonitor[object] | None = None
        self._seen = 0
        self._latest: deque[tuple[float, object]] = deque(maxlen=SHOWN_MESSAGES)
        self._samples: deque[tuple[float, float]] = deque(maxlen=PLOT_SAMPLES)
        self._plot_dirty = False
        self._plot_path = ""
        self._publisher: Publisher | None = None
        self._timer: Timer | None = None
        self._sent = 0  # written only by the timer's callback (executor thread)
        self._pub_message = ""
        self._echo_rows = 1  # the lines Echo keeps for the topic's messages (UI thread)

        gui.add_markdown(
            "Every topic on the graph. Counts leave out this dashboard's own "
            "subscriptions (`ros2 topic list -t`, `ros2 topic info <topic>`)."
        )
        self._table = MarkdownView(gui, "")
        self._selector = gui.add_dropdown("Topic", [NONE], initial_value=NONE)
        self._info = MarkdownView(gui, "")
        with gui.add_folder("Echo", expand_by_default=True):
            self._stats = MarkdownView(gui, "")
            self._echo = MarkdownView(gui, "")
        with gui.add_folder("Plot", expand_by_default=True):
            self._field = gui.add_dropdown("Field to plot", [NO_FIELD], initial_value=NO_FIELD)
            self._plot_note = MarkdownView(gui, "")
            self._plot = gui.add_uplot(
                (np.zeros(0), np.zeros(0)),
                (uplot.Series(label="t (s)"), uplot.Series(label="value", stroke="#1c7ed6")),
                scales={"x": uplot.Scale(time=False)},
                height=200,
                visible=False,
            )
        with gui.add_folder("Publish", expand_by_default=True):
            self._form_slot = FormSlot(gui, "Message")
            self._rate = gui.add_number("Rate (Hz)", 1.0, min=0.1, max=MAX_RATE_HZ, step=0.1)
            self._once = gui.add_button("Publish once", icon=viser.Icon.SEND, disabled=True)
            self._start = gui.add_button(
                "Publish at rate", icon=viser.Icon.PLAYER_PLAY, disabled=True
            )
            self._stop = gui.add_button(
                "Stop publishing", icon=viser.Icon.PLAYER_STOP, disabled=True
            )
            self._pub_view = MarkdownView(gui, "")
        self._selector.on_update(ui.callback(lambda: self._select(self._selector.value)))
        self._field.on_update(ui.callback(self._clear_plot))
        self._once.on_click(ui.callback(self._publish_once))
        self._start.on_click(ui.callback(self._publish_at_rate))
        self._stop.on_click(ui.callback(self._stop_publishing))

    # --- selection -------------------------------------------------------------

    def inspect(self, kind: str, topic: str, type_text: str) -> None:
        """A topic clicked on the stage graph (UI thread): follow it."""
        if kind != "topic" or topic not in self._types:
            return  # not on the graph (yet): the list would not keep it
        if topic != self._selector.value:
            set_options(self._selector, [NONE, *sorted(self._types)])
            assign(self._selector, topic)
        self._select(topic)

    def _select(self, topic: str) -> None:
        """Follow another topic: a new monitor, form and plot (UI thread)."""
        chosen = None if topic == NONE else topic
        type_text = self._types.get(chosen or "")
        current = self._monitor.msg_type if self._monitor else None
        if chosen == self._topic and (
            type_text is None or (current and type_name(current) == type_text)
        ):
            return
        self._stop_publishing()
        self._drop_publisher()
        if self._monitor is not None:
            self._monitor.close()
            self._monitor = None
        self._topic, self._seen = chosen, 0
        self._latest.clear()
        self._echo_rows = 1
        self._pub_message = ""
        fields: list[str] = []
        cls = None
        if chosen and type_text:
            try:
                cls = import_type(type_text, "msg")
            except ConversionError as exc:
                self._pub_message = f"⚠️ {exc}"
        if chosen and cls is not None:
            qos = matching_qos(self._node, chosen, depth=KEEP)
            self._monitor = TopicMonitor(self._node, chosen, cls, keep=KEEP, qos=qos)
            self._echo_rows = echo_rows(cls)
            fields = numeric_fields(cls)
        form = self._form_slot.show(
            (chosen, type_text), (lambda: (cls, type_text or "")) if cls is not None else None
        )
        self._field.options = [NO_FIELD, *fields]
        assign(self._field, preferred_field(cls) if cls is not None else NO_FIELD)
        self._clear_plot()
        for button in (self._once, self._start):
            button.disabled = form is None
        # Echo's room and the plot's note at once, not at the next refresh: the Publish buttons
        # below are where they will stay when the learner first sees them.
        self._show_topic(self._topic, self._monitor, [])
        self._show_plot()

    def _clear_plot(self) -> None:
        self._samples.clear()
        self._plot_dirty = True

    # --- publishing ------------------------------------------------------------

    def _message(self) -> object | None:
        form = self._form_slot.form
        if form is None:
            return None
        try:
            return form.message()
        except Ros2Error as exc:
            self._pub_message = f"⚠️ {exc}"
            return None

    def _ensure_publisher(self) -> Publisher | None:
        if self._publisher is None and self._monitor is not None:
            self._publisher = self._node.create_publisher(
                self._monitor.msg_type, self._monitor.topic, 10
            )
        return self._publisher

    def _drop_publisher(self) -> None:
        publisher, self._publisher = self._publisher, None
        if publisher is not None:
            self._node.destroy_publisher(publisher)

    def _publish_once(self) -> None:
        msg, topic, type_text = self._message(), self._topic, self._types.get(self._topic or "")
        if msg is None or topic is None:
            return
        command = f"ros2 topic pub --once {topic} {type_text} {yaml_inline(msg)}"
        publisher = self._ensure_publisher()
        if publisher is None:
            return
        self._pub_message = f"`{command}`\n\nwaiting for subscribers to match…"
        node = self._node

        def work() -> None:
            # A fresh publisher is matched to subscribers after discovery: wait for
            # them (bounded) so a reliable listener does not miss the one message.
            deadline = time.monotonic() + MATCH_WAIT_SEC
            while time.monotonic() < deadline and publisher.get_subscription_count() < (
                node.count_subscribers(topic)
            ):
                time.sleep(0.05)
            publisher.publish(msg)

        def done(_: None) -> None:
            self._pub_message = f"`{command}`\n\npublished 1 message"

        def failed(text: str) -> None:
            self._pub_message = f"`{command}`\n\n⚠️ {text}"

        self._ui.run_job(work, done, failed)

    def _publish_at_rate(self) -> None:
        msg, topic, type_text = self._message(), self._topic, self._types.get(self._topic or "")
        rate = float(self._rate.value)
        if msg is None or topic is None:
            return
        if not 0 < rate <= MAX_RATE_HZ:
            self._pub_message = f"⚠️ the rate must be between 0.1 and {MAX_RATE_HZ:g} Hz"
            return
        self._stop_publishing()
        publisher = self._ensure_publisher()
        if publisher is None:
            return
        command = f"ros2 topic pub -r {rate:g} {topic} {type_text} {yaml_inline(msg)}"
        self._sent = 0

        def on_timer() -> None:
            publisher.publish(msg)
            self._sent += 1

        self._timer = self._node.create_timer(1.0 / rate, on_timer)
        self._pub_message = f"`{command}`"
        self._stop.disabled = False

    def _stop_publishing(self) -> None:
        timer, self._timer = self._timer, None
        if timer is not None:
            self._node.destroy_timer(timer)
            self._pub_message += f"\n\nstopped after {self._sent} messages"
        self._stop.disabled = True

    # --- refresh ---------------------------------------------------------------

    def refresh(self, graph: GraphSnapshot) -> None:
        self._refresh_list(graph)
        monitor, topic = self._monitor, self._topic
        fresh = self._take_fresh(monitor)
        self._show_topic(topic, monitor, fresh)
        self._show_plot()
        text, timer = self._pub_message, self._timer
        if timer is not None:
            text += f"\n\npublishing: {self._sent} sent so far"
        self._pub_view.show(text)

    def _refresh_list(self, graph: GraphSnapshot) -> None:
        types = {t.name: t.types[0] for t in graph.topics if t.types}
        # Counted without this dashboard's own taps, which would confuse a learner.
        self._counts = {
            t.name: (t.publishers - t.own_publishers, t.subscribers - t.own_subscribers)
            for t in graph.topics
        }
        rows = [
            topic_item(topic, type_text, *self._counts.get(topic, (0, 0)))
            for topic, type_text in sorted(types.items())
        ]
        self._table.show("\n".join(rows) or "No topics yet.")
        if types != self._types:
            self._types = types
            # A vanished topic stays selected: it may come back.
            set_options(self._selector, [NONE, *sorted(types)])
            self._select(self._selector.value)

    def _take_fresh(self, monitor: TopicMonitor[object] | None) -> list[tuple[float, object]]:
        """New messages since the last refresh (at most KEEP), fed to echo and the plot."""
        if monitor is None or monitor.count == self._seen:
            return []
        fresh = monitor.messages_since(self._seen)
        self._seen = monitor.count
        self._latest.extend(fresh)
        path = self._field.value
        if path != NO_FIELD:
            for stamp, msg in fresh:
                value = plot_value(msg, path)
                if value is not None:
                    self._samples.append((stamp, value))
                    self._plot_dirty = True
        return fresh

    def _show_topic(
        self,
        topic: str | None,
        monitor: TopicMonitor[object] | None,
        fresh: list[tuple[float, object]],
    ) -> None:
        if topic is None:
            self._info.show("_Pick a topic to echo, measure, plot or publish on it._")
            self._stats.show("")
            self._echo.show("")
            return
        type_text = self._types.get(topic)
        pubs, subs = self._counts.get(topic, (0, 0))
        if type_text is None:
            self._info.show(f"`{topic}` is not on the graph right now.")
        else:
            self._info.show(
                f"`{topic}` · type `{type_text}` · {pubs} publisher{'s' * (pubs != 1)}, "
                f"{subs} subscriber{'s' * (subs != 1)} · `ros2 topic info {topic} -v`"
            )
        if monitor is None:
            return
        # No figure yet: nothing came, a message came a moment ago (a rate needs two), or the
        # topic went quiet.
        heard = self._latest[-1][0] if self._latest else None
        if heard is None:
            idle = "waiting…"
        elif time.time() - heard < STATS_WINDOW_SEC:
            idle = "measuring…"
        else:
            idle = "silent"
        published = monitor.published_rate(window_sec=STATS_WINDOW_SEC)
        band = monitor.bandwidth(window_sec=STATS_WINDOW_SEC)
        if published is None:
            hz = idle
        elif published.fallback:
            unknown = f"publisher's rate unknown: {published.fallback}"
            hz = f"**{published.rate:.2f} Hz** arrived ({unknown})"
        else:
            # The publisher's clock and sequence numbers: a sample this view
            # missed does not lower the rate, it is counted as missed.
            hz = f"**{published.rate:.2f} Hz** published"
            if published.restarts:
                hz += " (the publisher restarted)"
            arrived = monitor.rate(window_sec=STATS_WINDOW_SEC)
            if published.missed and arrived:
                hz += (
                    f"; {arrived.rate:.2f} Hz arrived here: this view missed "
                    f"{published.missed:,} of {published.published:,} "
                    f"({monitor.why_missed()})"
                )
            else:
                hz += f", none missed in {STATS_WINDOW_SEC:g} s"
        bw = f"**{band.ros2_text().splitlines()[0]}**" if band else idle
        # Short lines, the commands on their own: the block keeps its height while the first
        # figures arrive (a wrapped line would move the Publish buttons under the pointer).
        self._stats.show(
            f"Rate: {hz}\n\n"
            f"Bandwidth: {bw}\n\n"
            f"Messages received: {monitor.count}\n\n"
            f"`ros2 topic hz {topic}` · `ros2 topic bw {topic}`"
        )
        if fresh or not self._latest:
            latest = list(self._latest)
            shown: list[str] = []
            for _stamp, msg in reversed(latest):
                text = to_yaml(msg) + "\n---"
                if shown and sum(t.count("\n") + 1 for t in shown) + text.count("\n") > ECHO_LINES:
                    break
                shown.insert(0, text)
            body = "\n".join(shown) or f"(no message on {topic} yet)"
            blank = max(0, self._echo_rows - body.count("\n") - 1)
            self._echo.show(
                f"Latest messages · `ros2 topic echo {topic}`\n\n"
                + code_block([body + "\n" * blank])
            )

    def _show_plot(self) -> None:
        path = self._field.value
        topic = self._topic
        if topic is None or path == NO_FIELD:
            cls = self._monitor.msg_type if self._monitor else None
            self._plot_note.show(
                f"`{type_name(cls)}` has no number field to plot."
                if cls and not numeric_fields(cls)
                else ""
            )
            if self._plot.visible:
                self._plot.visible = False
            return
        if not self._plot_dirty:
            return
        self._plot_dirty = False
        samples = list(self._samples)
        if samples:
            end = samples[-1][0]
            samples = [s for s in samples if end - s[0] <= PLOT_WINDOW_SEC]
        note = f"{len(samples)} samples of `{path}`"
        if samples:
            note += f", latest {samples[-1][1]:.4g}"
        self._plot_note.show(f"{note} · `ros2 topic echo {topic} --field {path}`")
        if len(samples) < 2:
            return
        start = samples[0][0]
        t = np.array([s[0] - start for s in samples])
        y = np.array([s[1] for s in samples])
        if path != self._plot_path:
            self._plot_path = path
            self._plot.series = (
                uplot.Series(label="t (s)"),
                uplot.Series(label=path, stroke="#1c7ed6", width=2),
            )
        self._plot.data = (t, y)
        if not self._plot.visible:
            self._plot.visible = True

    def close(self) -> None:
        self._stop_publishing()
        self._drop_publisher()
        if self._monitor is not None:
            self._monitor.close()
            self._monitor = None


def echo_rows(msg_type: type) -> int:
    """The lines Echo keeps for a topic from the moment it is picked.

    As many as ``SHOWN_MESSAGES`` messages of the type take (``ECHO_LINES`` at most). Echo's
    block then stands still while the first messages arrive, and so do the Publish buttons
    below it: on a slow computer a click on a button that moved between the press and the
    release was lost.
    """
    try:
        per_message = to_yaml(msg_type()).count("\n") + 2  # and its '---' line
    except Exception:  # a type that cannot be built empty: no room kept
        return 1
    return min(ECHO_LINES, per_message * SHOWN_MESSAGES)
