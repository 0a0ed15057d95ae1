"""Numbers on stage: how often each topic's messages arrive, and the numbers that number
topics carry, over the last minute.

What ``ros2 topic hz`` and ``ros2 topic echo`` print as scrolling lines, drawn as lines
over time: the executors lesson's fast timer at 3 Hz beside 10 Hz, a talker's steady
2 Hz, a QoS talker that stops. The rates are measured once with the live graph's
(``SharedRatesClient``); only while this stage is shown.
"""

from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass, field

import numpy as np
import viser
import viser.uplot as uplot

from app.panels.graph_svg import HEAVY_TYPES
from app.ros.graph import GraphSnapshot
from app.ros.names import CLASSROOM_TOPICS, QUIET_TOPICS, is_internal_topic
from app.ros.rates import MAX_RATE_WINDOW_SEC, SharedRatesClient, rate_text
from app.ui import MarkdownView

WINDOW_SEC = 60.0
SAMPLE_PERIOD_SEC = 1.0
MAX_SERIES = 8  # lines a chart can tell apart by colour
# std_msgs types whose one field, ``data``, is a number: their values are plotted too.
NUMBER_TYPES = tuple(
    f"std_msgs/msg/{name}"
    for name in (
        "Float32", "Float64", "Int8", "Int16", "Int32", "Int64",
        "UInt8", "UInt16", "UInt32", "UInt64",
    )
)  # fmt: skip
COLOURS = ("#1c7ed6", "#e8590c", "#2f9e44", "#ae3ec9", "#f08c00", "#0c8599", "#c2255c", "#495057")
NOTHING = (
    "_No topic has a publisher yet._ Start a node from the step's buttons: each topic it "
    "publishes gets a line here, the number of messages a second (`ros2 topic hz`)."
)
NOTE = (
    "Messages a second on each topic, since it appeared and up to the last minute "
    "(`ros2 topic hz <topic>`), "
    "and the numbers that number topics carry (`ros2 topic echo <topic>`)."
)


@dataclass
class History:
    """Samples of one chart: time, and a value per series."""

    names: tuple[str, ...] = ()
    samples: deque[tuple[float, tuple[float, ...]]] = field(default_factory=deque)

    def add(self, now: float, values: dict[str, float]) -> None:
        names = tuple(sorted(values))
        if names != self.names:  # a topic came or went: the chart starts over
            self.names = names
            self.samples.clear()
        row = tuple(values[n] for n in names)
        self.samples.append((now, row))
        while self.samples and now - self.samples[0][0] > WINDOW_SEC:
            self.samples.popleft()

    def data(self) -> tuple[np.ndarray, ...]:
        if not self.samples:
            return (np.zeros(0), *(np.zeros(0) for _ in self.names))
        end = self.samples[-1][0]
        t = np.array([s[0] - end for s in self.samples])  # seconds before now
        rows = np.array([s[1] for s in self.samples], dtype=np.float64)
        return (t, *(rows[:, i] for i in range(len(self.names))))


def plotted_topics(graph: GraphSnapshot) -> dict[str, str]:
    """Topic -> type of what the plot measures: what another node publishes, or what the
    dashboard publishes to another node, without ROS's plumbing, the classroom's own
    topics, and images and clouds (large to count).

    A bag played or a ``ros2 topic pub`` typed in the Console runs on the dashboard's own
    node: the bags lesson plots /chatter played to the listener, with no talker running. A
    publisher the dashboard keeps with nobody listening (a lesson's earlier button) is not
    plotted: it would be a row of 0 Hz left over from another lesson.
    """
    out: dict[str, str] = {}
    for topic in graph.topics:
        if topic.name in QUIET_TOPICS or is_internal_topic(topic.name) or not topic.types:
            continue
        if topic.types[0] in HEAVY_TYPES or topic.name.startswith(CLASSROOM_TOPICS):
            continue
        others_publish = topic.publishers > topic.own_publishers
        sent_to_others = topic.publishers > 0 and topic.subscribers > topic.own_subscribers
        if others_publish or sent_to_others:
            out[topic.name] = topic.types[0]
    return dict(sorted(out.items())[:MAX_SERIES])


class PlotStage:
    def __init__(self, gui: viser.GuiApi, rates: SharedRatesClient) -> None:
        self._gui = gui
        self._rates = rates
        self._active = False
        self._next_sample = 0.0
        self._rate_history = History()
        self._value_history = History()
        self._box = gui.add_folder("Live plot", expand_by_default=True, visible=False)
        self._first_seen: dict[str, float] = {}
        # The table first (one line a topic), then what a number topic says, then rates:
        # at 1366x768 the numbers a lesson is about (3 Hz against 10) are in view.
        with self._box:
            self._note = MarkdownView(gui, NOTHING)
            self._table = MarkdownView(gui, "")
            self._value_chart = self._chart("Values (the numbers these topics carry)")
            self._rate_chart = self._chart("Messages a second (Hz)")

    def _chart(self, title: str) -> viser.GuiUplotHandle:
        return self._gui.add_uplot(
            (np.zeros(0), np.zeros(0)),
            (uplot.Series(label="seconds ago"), uplot.Series(label="")),
            title=title,
            scales={"x": uplot.Scale(time=False)},
            height=230,
            visible=False,
        )

    def set_active(self, active: bool) -> None:
        self._active = active
        self._box.visible = active
        self._next_sample = 0.0
        if not active:
            self._rates.watch({})  # no subscriptions for a chart nobody sees

    def refresh(self, graph: GraphSnapshot) -> None:
        now = time.monotonic()
        if not self._active or now < self._next_sample:
            return
        self._next_sample = now + SAMPLE_PERIOD_SEC
        topics = plotted_topics(graph)
        self._rates.watch(topics)
        # Over 10 s, not the graph's 3: a 0.5 Hz topic has a message in every window.
        rates = {t: self._rates.rate(t, MAX_RATE_WINDOW_SEC) or 0.0 for t in topics}
        numbers = {
            t: number
            for t, kind in topics.items()
            if kind in NUMBER_TYPES and (number := self._number(t)) is not None
        }
        self._rate_history.add(now, rates)
        self._value_history.add(now, numbers)
        self._first_seen = {t: self._first_seen.get(t, now) for t in topics}
        measuring = {t for t in topics if now - self._first_seen[t] < MAX_RATE_WINDOW_SEC}
        self._note.show(NOTE if topics else NOTHING)
        self._table.show(_table(topics, rates, numbers, measuring))
        _draw(self._value_chart, self._value_history)
        _draw(self._rate_chart, self._rate_history)

    def _number(self, topic: str) -> float | None:
        latest = self._rates.latest(topic)
        if latest is None:
            return None
        value = getattr(latest[1], "data", None)
        return float(value) if isinstance(value, (int, float)) else None

    def close(self) -> None:
        self._rates.watch({})


def _draw(chart: viser.GuiUplotHandle, history: History) -> None:
    if not history.names:
        chart.visible = False
        return
    series = (
        uplot.Series(label="seconds ago"),
        *(
            uplot.Series(label=name, stroke=COLOURS[i % len(COLOURS)], width=2)
            for i, name in enumerate(history.names)
        ),
    )
    data = history.data()
    if len(chart.series) != len(series) or any(
        a.get("label") != b.get("label") for a, b in zip(chart.series, series, strict=True)
    ):
        # Never more lines than data arrays, not even for one frame. viser sends the two
        # as separate messages, which a loaded page may draw apart; new lines drawn with
        # the old data throw inside uPlot's first draw, and that chart then ignores every
        # resize and update for good (ci34: the rate chart stuck at 157 px wide). uPlot
        # ignores data arrays beyond its lines, so a line added gets its data first.
        if len(series) > len(chart.series):
            chart.data = data
            chart.series = series
        else:
            chart.series = series
            chart.data = data
    else:
        chart.data = data
    chart.visible = True


def _table(
    topics: dict[str, str], rates: dict[str, float], numbers: dict[str, float], measuring: set[str]
) -> str:
    if not topics:
        return ""
    rows = ["| topic | type | now |", "|---|---|---|"]
    for topic, kind in topics.items():
        rate = rates.get(topic, 0.0)
        now = "measuring…" if topic in measuring and not rate else rate_text(rate)
        if topic in numbers:
            now += f" · last value {numbers[topic]:.4g}"
        rows.append(f"| `{topic}` | `{kind.split('/')[-1]}` | {now} |")
    return "\n".join(rows)
