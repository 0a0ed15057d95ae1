"""The stage window: one owner for what the centre of the screen shows.

The lesson names a stage for each step; the learner may pick another in the
"On stage" dropdown (the next step's choice replaces it). The live graph is
drawn in a window docked on the left; "code" shows the code window instead;
"scene" hides both so the 3D canvas has the room.
"""

from __future__ import annotations

import time
from typing import Any

import viser
from rclpy.node import Node

from app.panels.graph_panel import SharedRatesClient
from app.panels.graph_svg import graph_picture, topics_to_measure
from app.ros.graph import GraphSnapshot, node_endpoints
from app.ros.rates import RateBoard, rate_text
from app.stage import DEFAULT_STAGE, STAGES
from app.stage.graph_view import StablePlaces, stage_legend, stage_svg
from app.ui import MarkdownView, assign
from app.ui.loop import UiLoop

PICTURE_PERIOD_SEC = 1.0
STAGE_WIDTH = 560
RATE_CHANGE = 0.15  # a rate must move this much (share) before the dots are re-timed
_TURTLESIM_NOTE = (
    "### Turtlesim\nTurtlesim's window is in the **Turtlesim** tab of the panel on the "
    "right: start `turtlesim_node` there and drive with the arrow keys."
)


class Stage:
    def __init__(
        self,
        gui: viser.GuiApi,
        ui: UiLoop,
        node: Node,
        code_window: Any,
        rates: SharedRatesClient | None = None,
    ) -> None:
        self._node = node
        self._code_window = code_window
        self._rates: RateBoard | SharedRatesClient = rates or RateBoard(node)
        self._places = StablePlaces()
        self._shown_rates: dict[str, float] = {}
        self._last_picture = 0.0
        self._svg = ""
        self.current = DEFAULT_STAGE
        by_label = {label: name for name, label in STAGES.items()}
        self._selector = gui.add_dropdown(
            "On stage", list(by_label), initial_value=STAGES[DEFAULT_STAGE]
        )
        self._selector.on_update(
            ui.callback(lambda: self.show(by_label.get(self._selector.value, self.current)))
        )
        self._window = gui.add_panel()
        self._window.dock_left()
        self._window.set_width(STAGE_WIDTH)
        with self._window.add_tab("Stage", viser.Icon.PRESENTATION):
            self._graph_box = gui.add_folder("Live ROS graph", expand_by_default=True)
            with self._graph_box:
                gui.add_html(stage_legend())
                self._picture = gui.add_html(stage_svg([], [], {}))
                self._show_quiet = gui.add_checkbox(
                    # (no word "node" here: tests and learners find the Node dropdown by label)
                    "Show the plumbing: /rosout, /parameter_events, _hidden, parameter services",
                    False,
                )
            self._note = MarkdownView(gui, _TURTLESIM_NOTE, visible=False)
        self.show(DEFAULT_STAGE)

    def show(self, stage: str) -> None:
        """Put ``stage`` on (an unknown name is ignored: lessons are validated at load)."""
        if stage not in STAGES:
            return
        self.current = stage
        assign(self._selector, STAGES[stage])
        self._window.visible = stage in ("graph", "turtlesim")
        self._graph_box.visible = stage == "graph"
        self._note.handle.visible = stage == "turtlesim"
        self._code_window.visible = stage == "code"
        self._last_picture = 0.0  # draw at once
        if stage != "graph":
            self._rates.watch({})  # no subscriptions for a picture nobody sees

    def refresh(self, graph: GraphSnapshot) -> None:
        if self.current != "graph":
            return
        now = time.monotonic()
        if now - self._last_picture < PICTURE_PERIOD_SEC:
            return
        self._last_picture = now
        own = self._node.get_fully_qualified_name()
        endpoints = [
            found
            for fqn in graph.nodes
            if fqn != own and (found := node_endpoints(self._node, fqn)) is not None
        ]
        quiet = self._show_quiet.value
        shape = graph_picture(endpoints, show_quiet=quiet)
        self._rates.watch(topics_to_measure(shape, endpoints))
        rates = {topic: self._steady_rate(topic) for topic in self._rates.watched()}
        labels = {topic: rate_text(rate) for topic, rate in rates.items()}
        vertices, edges = graph_picture(endpoints, labels, show_quiet=quiet)
        svg = stage_svg(self._places.place(vertices, edges), edges, rates)
        if svg != self._svg:
            self._svg = svg
            self._picture.content = svg

    def _steady_rate(self, topic: str) -> float:
        """The measured rate, changed only when it moves by RATE_CHANGE: a new picture
        restarts the dots, so 1.9 / 2.0 / 2.1 Hz jitter must not redraw it."""
        rate = self._rates.rate(topic) or 0.0
        before = self._shown_rates.get(topic)
        if before is None or abs(rate - before) > RATE_CHANGE * max(before, 0.1):
            self._shown_rates[topic] = rate
            return rate
        return before

    def close(self) -> None:
        self._rates.close()
