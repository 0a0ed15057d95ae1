"""Graph panel: nodes, topics, services and actions in one picture, edges with live rates.

rqt_graph shows no services or actions; this picture does. Who publishes,
subscribes, serves or calls what is asked per node (as `ros2 node info`
does) once a second; rates come from a ``RateBoard`` of best-effort raw
subscriptions on the topics in the picture only. The text lists below
(`ros2 node list`, `ros2 topic list -t`) stay for copying names.
"""

from __future__ import annotations

import time

import viser
from rclpy.node import Node

from app.panels.graph_svg import graph_picture, legend_html, render_svg, topics_to_measure
from app.ros.graph import GraphSnapshot, node_endpoints
from app.ros.rates import RateBoard, SharedRatesClient, rate_text
from app.ui import MarkdownView, topic_item

PICTURE_PERIOD_SEC = 1.0


class GraphPanel:
    def __init__(
        self, gui: viser.GuiApi, node: Node, rates: SharedRatesClient | None = None
    ) -> None:
        self._node = node
        self._rates: RateBoard | SharedRatesClient = rates or RateBoard(node)
        self._last_picture = 0.0
        self._svg = ""
        with gui.add_folder("Options", expand_by_default=False):
            self._show_quiet = gui.add_checkbox(
                "Show /rosout, /parameter_events, parameter and lifecycle services", False
            )
            self._show_self = gui.add_checkbox("Show this dashboard's own node", False)
            self._live = gui.add_checkbox("Live rates", True)
            self._heavy = gui.add_checkbox(
                "Rates of images and clouds too",
                False,
                hint="Large messages cost bandwidth even when only counted",
            )
        gui.add_html(legend_html())
        self._picture = gui.add_html(render_svg([], []))
        self._view = MarkdownView(gui, "Waiting for the first look at the graph…")

    def refresh(self, graph: GraphSnapshot) -> None:
        self._refresh_picture(graph)
        parts = [f"**Nodes ({len(graph.nodes)})** · `ros2 node list`", ""]
        parts += [f"- `{name}`" for name in graph.nodes] or ["- (none)"]
        if graph.ghosts:
            parts += [
                "",
                "Stale names (their process is gone, DDS still lists them): "
                + ", ".join(f"`{name}`" for name in graph.ghosts),
            ]
        parts += ["", f"**Topics ({len(graph.topics)})** · `ros2 topic list -t`", ""]
        hide_own = not self._show_self.value  # the dashboard's taps: left out, as in the picture
        parts += [
            topic_item(
                topic.name,
                ", ".join(topic.types),
                topic.publishers - (topic.own_publishers if hide_own else 0),
                topic.subscribers - (topic.own_subscribers if hide_own else 0),
            )
            for topic in graph.topics
        ] or ["- (none)"]
        if graph.services or graph.actions:
            parts += ["", f"**Actions ({len(graph.actions)})** · `ros2 action list`", ""]
            parts += [f"- `{name}`" for name in graph.actions] or ["- (none)"]
        self._view.show("\n".join(parts))

    def _refresh_picture(self, graph: GraphSnapshot) -> None:
        node, rates = self._node, self._rates
        now = time.monotonic()
        if now - self._last_picture < PICTURE_PERIOD_SEC:
            return
        self._last_picture = now
        own = node.get_fully_qualified_name()
        endpoints = [
            found
            for fqn in graph.nodes
            if (self._show_self.value or fqn != own)
            and (found := node_endpoints(node, fqn)) is not None
        ]
        quiet = self._show_quiet.value
        if self._live.value:
            shape = graph_picture(endpoints, show_quiet=quiet)
            rates.watch(topics_to_measure(shape, endpoints, heavy_too=self._heavy.value))
        else:
            rates.watch({})
        labels = {}
        for topic in rates.watched():
            rate = rates.rate(topic)
            labels[topic] = rate_text(rate, rate == 0 and rates.heard(topic))
        vertices, edges = graph_picture(endpoints, labels, show_quiet=quiet)
        svg = render_svg(vertices, edges)
        if svg != self._svg:
            self._svg = svg
            self._picture.content = svg

    def close(self) -> None:
        self._rates.close()  # a shared board's owner (the dashboard) closes the board itself
