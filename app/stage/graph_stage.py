"""The live ROS graph on stage: nodes, topics, services and actions as boxes, messages as
moving dots at their measured rate, calls and goals as pulses; a click on a box says what
it offers and uses, with buttons to the tools already set to it.
"""

from __future__ import annotations

import hashlib
import html
import time
from collections.abc import Callable
from dataclasses import replace

import viser
from rclpy.node import Node

from app.panels.graph_svg import Edge, Vertex, graph_picture, topics_to_measure
from app.ros.graph import GraphSnapshot, NodeEndpoints, node_endpoints
from app.ros.qos import undelivered
from app.ros.rates import RateBoard, RateHold, SharedRatesClient, rate_text
from app.stage.graph_view import (
    PER_ROW,
    STARTING,
    STEP_X,
    PulseView,
    StablePlaces,
    stage_legend,
    stage_svg,
)
from app.stage.pulses import CallWatch, Pulse, caller_of
from app.ui import MarkdownView
from app.ui.loop import UiLoop
from app.ui.page_links import SINK, SINK_FRAME, PageLinks

PICTURE_PERIOD_SEC = 1.0
MAX_PICKS = 300  # boxes that answer a click (a larger graph: the first ones)
RATE_CHANGE = 0.15  # a rate must move this much (share) before the dots are re-timed
# A clicked box's tools (set to it already): (tool, button label).
_TOOLS_FOR: dict[str, tuple[tuple[str, str], ...]] = {
    "topic": (("Echo", "Echo {name}"), ("Topics", "Rate, plot and publish {name} in Topics")),
    "node": (("Parameters", "Parameters of {name}"), ("Nodes", "{name} in Run › Nodes")),
    "service": (("Services", "Call {name} in Services"),),
    "action": (("Actions", "Send a goal to {name} in Actions"),),
}
STAGE_PADDING = 40  # the stage window's borders, folder margins and scroll bar
OWN_DETAIL = "this dashboard"
BLOCKED_LABEL = "QoS mismatch: nothing arrives"
ONLY_OWN = "Only this dashboard's own node is on the graph: start a node and watch it join."


class GraphStage:
    def __init__(
        self,
        gui: viser.GuiApi,
        ui: UiLoop,
        node: Node,
        width: int,
        rates: SharedRatesClient | None = None,
        links: PageLinks | None = None,
        starting: Callable[[], list[str]] = lambda: [],
        inspect: Callable[[str, str, str], None] = lambda _kind, _name, _type: None,
        open_tool: Callable[[str], None] = lambda _tool: None,
    ) -> None:
        """``starting()``: nodes whose process was just started and that the ROS graph does
        not list yet (drawn at once, marked 'starting…', so a click on Start shows).
        ``inspect(kind, name, type)``: a box was clicked (the tools preselect it);
        ``open_tool(name)`` brings a tool's tab into view."""
        self._ui = ui
        self._node = node
        self._links = links
        self._starting = starting
        self._inspect = inspect
        self._open_tool = open_tool
        self._width = width
        self._active = False
        # The boxes a click may name: this picture's and the one before (the learner may
        # click the picture on screen just as a newer one is drawn), by their link's id.
        self._pickable: dict[str, Vertex] = {}
        self._drawn_picks: dict[str, Vertex] = {}
        self._placed: list[Vertex] = []  # the boxes in the picture, in link order
        self._inspected = ""  # Vertex.key the learner clicked
        self._endpoints: list[NodeEndpoints] = []
        if links is not None:  # a click on a box runs stage.pick/<its id>
            links.register_value("stage.pick", self._picker)
        self._rates: RateBoard | SharedRatesClient = rates or RateBoard(node)
        self._places = StablePlaces()
        # Calls and goals as pulses: an event wakes the UI loop, which draws it at once.
        self._calls = CallWatch(node, on_event=lambda: ui.post(lambda: None))
        self._drawn_pulses: set[tuple[str, str, float]] = set()
        self._alone: set[str] = set()  # node boxes drawn without an edge
        self._callers: dict[tuple[str, str], str] = {}
        self._shown_rates = RateHold(RATE_CHANGE)
        self._last_picture = 0.0
        self._drawn_nodes: tuple[str, ...] = ()
        self._svg = ""
        self._box = gui.add_folder("Live ROS graph", expand_by_default=True)
        with self._box:
            gui.add_html(stage_legend())
            self._picture = gui.add_html(stage_svg([], [], {}))
            self._show_quiet = gui.add_checkbox(
                # (no word "node" here: tests and learners find the Node dropdown by label)
                "Show ROS plumbing",
                False,
                hint="/rosout, /parameter_events, hidden _names and parameter services",
            )
            self._inspector = MarkdownView(
                gui, "_Click a box in the graph to see what it offers and uses._"
            )
            # The tools that show more of the clicked box (already set to it).
            self._tool_buttons = [
                gui.add_button("", icon=viser.Icon.EXTERNAL_LINK, visible=False) for _ in range(2)
            ]
            for i, button in enumerate(self._tool_buttons):
                button.on_click(ui.callback(self._open_inspected_tool, i))

    def set_active(self, active: bool) -> None:
        self._active = active
        self._box.visible = active
        self._last_picture = 0.0  # draw at once
        if not active:
            self._rates.watch({})  # no subscriptions for a picture nobody sees
            self._calls.watch({}, {})

    def set_width(self, width: int) -> None:
        """Wider stage, more boxes a row (boxes already placed stay where they are)."""
        self._width = width
        self._places.per_row = max(PER_ROW, (width - 40) // STEP_X)
        self._last_picture = 0.0

    def forget(self) -> None:
        """A new lesson: its graph is laid out afresh, nothing inspected."""
        self._places = StablePlaces(self._places.per_row)
        self._alone.clear()
        self._inspected = ""
        for button in self._tool_buttons:
            button.visible = False
        self._last_picture = 0.0

    def refresh(self, graph: GraphSnapshot) -> None:
        now = time.monotonic()
        starting = tuple(n for n in self._starting() if n not in graph.nodes)
        # A node that joined, left or was just started is drawn at once, not on the next tick.
        joined_or_left = (*graph.nodes, *starting) != self._drawn_nodes
        pulses = self._calls.recent(now)
        fresh = {(p.kind, p.name, p.shown_at) for p in pulses} - self._drawn_pulses
        if now - self._last_picture < PICTURE_PERIOD_SEC and not (joined_or_left or fresh):
            return
        self._last_picture = now
        self._drawn_nodes = (*graph.nodes, *starting)
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
        labels = {
            t: rate_text(rate, rate <= 0 and self._rates.heard(t)) for t, rate in rates.items()
        }
        vertices, edges = graph_picture(endpoints, labels, show_quiet=quiet)
        edges = self._mark_undelivered(edges)
        vertices += [Vertex("node", name, STARTING) for name in starting]
        note = ""
        if not vertices:  # the dashboard is a node too: say so rather than 'nothing'
            vertices = [Vertex("node", own, OWN_DETAIL)]
            note = ONLY_OWN
            if (mine := node_endpoints(self._node, own)) is not None:
                endpoints = [*endpoints, mine]  # inspected like any other node
        # A node drawn alone (starting, or its endpoints not discovered yet) joins its
        # group's place once its first edge is known; every other box stays put.
        linked = {key for e in edges for key in (e.source, e.target)}
        for key in self._alone & linked:
            self._places.forget(key)
        self._alone = {f"node:{v.name}" for v in vertices if v.kind == "node"} - linked
        placed = self._places.place(vertices, edges)
        self._placed = [p.vertex for p in placed]
        picture = {_pick_id(v.key): v for v in self._placed[:MAX_PICKS]}
        self._pickable = {**self._drawn_picks, **picture}
        self._drawn_picks = picture
        self._endpoints = endpoints
        self._calls.watch(*_calls_to_watch(vertices, endpoints))
        self._drawn_pulses = {(p.kind, p.name, p.shown_at) for p in pulses}
        views = [
            PulseView(p.kind, p.name, self._caller(p, edges), now - p.shown_at) for p in pulses
        ]
        link = self._link if self._links is not None else None
        svg = stage_svg(
            placed,
            edges,
            rates,
            link,
            views,
            frozenset(starting),
            self._width - STAGE_PADDING,
            note,
        )
        # Natural size, never shrunk to fit (its text stays readable): a wider graph scrolls.
        svg = f'<div style="overflow:auto">{svg}</div>'
        if self._links is not None:
            svg = SINK_FRAME + svg
        if svg != self._svg:
            self._svg = svg
            self._picture.content = svg
        self._inspector.show(self._inspection(labels))

    def _mark_undelivered(self, edges: list[Edge]) -> list[Edge]:
        """A subscription no publisher can deliver to (incompatible QoS) is drawn as such:
        drawn plainly, with the topic's rate on it, it said the opposite of the QoS lesson."""
        checked: dict[str, dict[str, str]] = {}
        marked = []
        for edge in edges:
            kind, _, topic = edge.source.partition(":")
            if kind == "topic" and edge.target.startswith("node:"):
                if topic not in checked:
                    checked[topic] = undelivered(self._node, topic)
                why = checked[topic].get(edge.target.partition(":")[2], "")
                if why:
                    edge = replace(edge, label=BLOCKED_LABEL, blocked=why)
            marked.append(edge)
        return marked

    def _caller(self, pulse: Pulse, edges: list[Edge]) -> str:
        """The node drawn as the one who called or sent the goal; '' when unknown."""
        if pulse.caller_id:  # a service event names its caller
            key = (pulse.name, pulse.caller_id)
            if key not in self._callers:
                if len(self._callers) > MAX_PICKS:
                    self._callers.clear()
                self._callers[key] = caller_of(self._node, pulse.name, pulse.caller_id)
            return self._callers[key]
        # An action's goal does not: the one client on the graph, unless this dashboard
        # (not drawn) may have sent it from its Actions tool.
        users = {e.source for e in edges if e.dashed and e.target == f"action:{pulse.name}"}
        own = node_endpoints(self._node, self._node.get_fully_qualified_name())
        if len(users) != 1 or (own is not None and pulse.name in own.action_clients):
            return ""
        return next(iter(users)).partition(":")[2]

    def _picker(self, pick_id: str) -> None:
        """The link's action: runs in viser's asyncio thread, so it only posts."""
        self._ui.post(lambda: self._pick(pick_id))

    def _link(self, index: int, content: str, title: str) -> str:
        if self._links is None or index >= MAX_PICKS:
            return content
        # Named by its <title> and text, not aria-label: tests and screen readers find the
        # control panel's fields by label ("Topic", "Node"), which box names often contain.
        pick_id = _pick_id(self._placed[index].key)
        href = html.escape(f"{self._links.href('stage.pick')}/{pick_id}")
        return f'<a href="{href}" target="{SINK}"><title>{html.escape(title)}</title>{content}</a>'

    def _pick(self, pick_id: str) -> None:
        vertex = self._pickable.get(pick_id)
        if vertex is None:  # a box from a picture two redraws ago: gone or moved on
            return
        self._inspected = vertex.key
        self._last_picture = 0.0  # answer at once
        self._inspect(vertex.kind, vertex.name, self._full_type(vertex))
        tools = _TOOLS_FOR.get(vertex.kind, ())
        for i, button in enumerate(self._tool_buttons):
            if i < len(tools):
                button.label = tools[i][1].format(name=vertex.name)
            button.visible = i < len(tools)

    def _full_type(self, vertex: Vertex) -> str:
        """A topic's, service's or action's full type name ('' for a node)."""
        for e in self._endpoints:
            for table in (
                e.publishes, e.subscribes, e.servers, e.clients, e.action_servers,
                e.action_clients,
            ):  # fmt: skip
                if vertex.name in table and vertex.kind != "node":
                    return table[vertex.name]
        return ""

    def _open_inspected_tool(self, index: int) -> None:
        kind = self._inspected.partition(":")[0]
        tools = _TOOLS_FOR.get(kind, ())
        if index < len(tools):
            self._open_tool(tools[index][0])

    def _inspection(self, labels: dict[str, str]) -> str:
        """What the clicked box offers and uses, as `ros2 node info` / `topic info` say."""
        kind, _, name = self._inspected.partition(":")
        if not name:
            return "_Click a box in the graph to see what it offers and uses._"
        if kind == "node":
            found = next((e for e in self._endpoints if e.name == name), None)
            if found is None and name in self._drawn_nodes:
                return (
                    f"**Node `{name}`** is starting: its process runs, and the ROS graph "
                    "lists it once discovery has found it (usually within a second or two)."
                )
            if found is None:
                return f"**{name}** has left the graph."
            parts = [f"**Node `{name}`** · `ros2 node info {name}`"]
            for title, table in (
                ("Publishers", found.publishes), ("Subscribers", found.subscribes),
                ("Service servers", found.servers), ("Service clients", found.clients),
                ("Action servers", found.action_servers),
                ("Action clients", found.action_clients),
            ):  # fmt: skip
                if table:
                    items = ", ".join(f"`{t}` [{kind}]" for t, kind in sorted(table.items()))
                    parts.append(f"- {title}: {items}")
            return "\n".join(parts)
        users: dict[str, list[str]] = {"pub": [], "sub": [], "serve": [], "use": []}
        for e in self._endpoints:
            if name in e.publishes or name in e.servers or name in e.action_servers:
                users["pub" if kind == "topic" else "serve"].append(e.name)
            if name in e.subscribes or name in e.clients or name in e.action_clients:
                users["sub" if kind == "topic" else "use"].append(e.name)
        rate = labels.get(name, "")
        if kind == "topic":
            return (
                f"**Topic `{name}`** · `ros2 topic info {name}`"
                + (f" · {rate}" if rate else "")
                + f"\n- publishers: {', '.join(users['pub']) or 'none'}"
                + f"\n- subscribers: {', '.join(users['sub']) or 'none'}"
            )
        return (
            f"**{kind.capitalize()} `{name}`**"
            + f"\n- served by: {', '.join(users['serve']) or 'none'}"
            + f"\n- used by: {', '.join(users['use']) or 'none'}"
        )

    def _steady_rate(self, topic: str) -> float:
        """The measured rate, held against jitter: a new picture restarts the dots, so
        1.9 / 2.0 / 2.1 Hz wobbles must not redraw it (``RateHold``)."""
        return self._shown_rates.shown(topic, self._rates.rate(topic) or 0.0)

    def close(self) -> None:
        self._rates.close()
        self._calls.close()


def _pick_id(key: str) -> str:
    """A box's id in its link: the same box keeps it in every picture (an index did not:
    a redraw between a click and its arrival could turn it into another box's)."""
    return hashlib.blake2s(key.encode(), digest_size=8).hexdigest()


def _calls_to_watch(
    vertices: list[Vertex], endpoints: list[NodeEndpoints]
) -> tuple[dict[str, str], dict[str, str]]:
    """The services and actions in the picture, with their full types."""
    shown = {v.name for v in vertices if v.kind in ("service", "action")}
    services: dict[str, str] = {}
    actions: dict[str, str] = {}
    for e in endpoints:
        for table, out in (
            (e.servers, services), (e.clients, services),
            (e.action_servers, actions), (e.action_clients, actions),
        ):  # fmt: skip
            for name, kind in table.items():
                if name in shown:
                    out.setdefault(name, kind)
    return services, actions
