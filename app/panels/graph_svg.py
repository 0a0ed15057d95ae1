"""A layered drawing of the ROS graph as SVG, in plain Python (no ROS calls, no browser).

rqt_graph needs Qt and Graphviz and hides services and actions; here the
picture is a small SVG string the Graph panel puts in an HTML widget. Data
flows top to bottom: a publisher sits above its topic, the topic above its
subscribers, a server above its service or action. Layers come from the
longest path (cycles are broken where a depth-first walk finds them), items
in a layer are ordered by the mean position of what feeds them, and a layer
wider than the panel wraps onto extra rows, so 15 nodes stay readable.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, replace
from html import escape
from typing import Literal

from app.ros.graph import NodeEndpoints
from app.ros.names import ACTION_MARKER, QUIET_TOPICS

Kind = Literal["node", "topic", "service", "action"]

BOX_W, BOX_H = 168, 34  # two boxes a row fit the control panel at about 1:1 scale
GAP_X, ROW_GAP = 14, 40
MARGIN = 8
MAX_LABEL = 25
PER_ROW = 2
GROUP_GAP = 18  # extra space between unconnected groups
STYLE: dict[str, tuple[str, str, str]] = {  # fill, stroke, shape rounding
    "node": ("#dbe4ff", "#3b5bdb", "17"),
    "topic": ("#d3f9d8", "#2f9e44", "4"),
    "service": ("#fff4e6", "#e8590c", "4"),
    "action": ("#f3d9fa", "#ae3ec9", "4"),
}


@dataclass(frozen=True)
class Vertex:
    kind: Kind
    name: str
    detail: str = ""  # second line, e.g. the message type or a rate

    @property
    def key(self) -> str:
        return f"{self.kind}:{self.name}"


@dataclass(frozen=True)
class Edge:
    source: str  # Vertex.key
    target: str
    label: str = ""
    dashed: bool = False  # a client (service or action) rather than a server
    blocked: str = ""  # why nothing arrives on it (topic -> subscriber: incompatible QoS)


@dataclass(frozen=True)
class Placed:
    vertex: Vertex
    x: float
    y: float


def layers(keys: list[str], edges: list[Edge]) -> dict[str, int]:
    """Longest-path layer of every vertex; edges closing a cycle are ignored."""
    succ: dict[str, list[str]] = defaultdict(list)
    for edge in edges:
        if edge.source != edge.target:
            succ[edge.source].append(edge.target)
    # Depth-first walk, iterative, to find back edges (the ones that close cycles).
    state: dict[str, int] = {}
    back: set[tuple[str, str]] = set()
    for root in keys:
        if root in state:
            continue
        stack = [(root, iter(succ[root]))]
        state[root] = 1
        while stack:
            here, children = stack[-1]
            child = next(children, None)
            if child is None:
                state[here] = 2
                stack.pop()
            elif state.get(child) == 1:
                back.add((here, child))
            elif child not in state:
                state[child] = 1
                stack.append((child, iter(succ[child])))
    forward = [(a, b) for a in keys for b in succ[a] if (a, b) not in back]
    indegree = {k: 0 for k in keys}
    for _a, b in forward:
        indegree[b] = indegree.get(b, 0) + 1
    layer = {k: 0 for k in keys}
    ready = [k for k in keys if indegree[k] == 0]
    out: dict[str, list[str]] = defaultdict(list)
    for a, b in forward:
        out[a].append(b)
    while ready:
        here = ready.pop()
        for child in out[here]:
            layer[child] = max(layer[child], layer[here] + 1)
            indegree[child] -= 1
            if indegree[child] == 0:
                ready.append(child)
    return layer


def components(keys: list[str], edges: list[Edge]) -> list[list[str]]:
    """Groups of vertices joined by edges, each in ``keys`` order, ordered by first member."""
    parent = {k: k for k in keys}

    def root(k: str) -> str:
        while parent[k] != k:
            parent[k] = parent[parent[k]]
            k = parent[k]
        return k

    for edge in edges:
        a, b = root(edge.source), root(edge.target)
        if a != b:
            parent[max(a, b)] = min(a, b)
    groups: dict[str, list[str]] = defaultdict(list)
    for key in keys:
        groups[root(key)].append(key)
    return list(groups.values())


def _barycentre(sources: list[str], slot: dict[str, float]) -> float:
    """Mean slot of what feeds a vertex: puts it under its publishers, fewer crossings."""
    known = [slot[p] for p in sources if p in slot]
    return sum(known) / len(known) if known else float("inf")


def layout(vertices: list[Vertex], edges: list[Edge], per_row: int = PER_ROW) -> list[Placed]:
    """Top-left corners of every box.

    Each connected group (talker, /chatter, listeners; a server and its service)
    is drawn on its own, one under the other, so edges stay short; inside a
    group layers are rows, wrapped at ``per_row`` boxes. Lone vertices share
    rows at the end.
    """
    order = sorted(vertices, key=lambda v: (list(STYLE).index(v.kind), v.name))
    keys = [v.key for v in order]
    by_key = {v.key: v for v in order}
    edges = [e for e in edges if e.source in by_key and e.target in by_key]
    layer_of = layers(keys, edges)
    preds: dict[str, list[str]] = defaultdict(list)
    for edge in edges:
        preds[edge.target].append(edge.source)
    groups = components(keys, edges)
    rows: list[list[str]] = []
    gaps: set[int] = set()  # row indexes that start a new group
    for group in (g for g in groups if len(g) > 1):
        gaps.add(len(rows))
        grouped: dict[int, list[str]] = defaultdict(list)
        for key in group:
            grouped[layer_of[key]].append(key)
        slot: dict[str, float] = {}
        for level in sorted(grouped):
            members = grouped[level]
            members.sort(key=lambda k: (_barycentre(preds[k], slot), keys.index(k)))
            for start in range(0, len(members), per_row):
                row = members[start : start + per_row]
                rows.append(row)
                for i, key in enumerate(row):
                    slot[key] = i - (len(row) - 1) / 2
    lone = [g[0] for g in groups if len(g) == 1]
    if lone:
        gaps.add(len(rows))
        rows += [lone[i : i + per_row] for i in range(0, len(lone), per_row)]
    placed: list[Placed] = []
    width = per_row * BOX_W + (per_row - 1) * GAP_X
    y = float(MARGIN)
    for index, row in enumerate(rows):
        if index in gaps and index > 0:
            y += GROUP_GAP
        row_width = len(row) * BOX_W + (len(row) - 1) * GAP_X
        x = MARGIN + (width - row_width) / 2
        for key in row:
            placed.append(Placed(by_key[key], x, y))
            x += BOX_W + GAP_X
        y += BOX_H + ROW_GAP
    return placed


def short(text: str, limit: int = MAX_LABEL) -> str:
    return text if len(text) <= limit else text[: limit - 1] + "…"


NAME_FONT, SMALLEST_NAME_FONT = 12.0, 9.0  # px; 9 px still reads at 1:1 scale


def fitted_name(name: str) -> tuple[str, float]:
    """A box's name and its font size: a long name is set smaller so it reads whole.

    Only a name too long even at the smallest size is cut, in its middle: both its
    namespace and its last part (the one a learner typed) stay.
    """
    if len(name) <= MAX_LABEL:
        return name, NAME_FONT
    fits = int(MAX_LABEL * NAME_FONT / SMALLEST_NAME_FONT)
    if len(name) <= fits:
        return name, round(NAME_FONT * MAX_LABEL / len(name), 1)
    head = (fits - 1) // 2
    return name[:head] + "…" + name[-(fits - 1 - head) :], SMALLEST_NAME_FONT


def edge_path(a: Placed, b: Placed) -> tuple[str, float, float]:
    """A cubic curve from a's bottom to b's top (or around the side when b is not below)."""
    x0, y0 = a.x + BOX_W / 2, a.y + BOX_H
    x3, y3 = b.x + BOX_W / 2, b.y
    if y3 > y0:
        dy = (y3 - y0) / 2
        c1, c2 = (x0, y0 + dy), (x3, y3 - dy)
    elif a.y == b.y and a.x != b.x:  # side by side: straight across the gap between them
        y0 = y3 = a.y + BOX_H / 2
        x0, x3 = (a.x + BOX_W, b.x) if b.x > a.x else (a.x, b.x + BOX_W)
        c1, c2 = (x0 + (x3 - x0) / 3, y0), (x0 + 2 * (x3 - x0) / 3, y3)
    else:  # upward: bulge out to the right so the arrow stays visible
        x0, y0 = a.x + BOX_W, a.y + BOX_H / 2
        x3, y3 = b.x + BOX_W, b.y + BOX_H / 2
        reach = 40 + abs(y3 - y0) / 4
        c1, c2 = (x0 + reach, y0), (x3 + reach, y3)
    mid_x = (x0 + 3 * c1[0] + 3 * c2[0] + x3) / 8
    mid_y = (y0 + 3 * c1[1] + 3 * c2[1] + y3) / 8
    if a.y == b.y and a.x != b.x:  # the gap is narrow: the label goes above the two boxes
        mid_y = a.y - 10
    path = f"M{x0:.0f},{y0:.0f} C{c1[0]:.0f},{c1[1]:.0f} {c2[0]:.0f},{c2[1]:.0f} {x3:.0f},{y3:.0f}"
    return path, mid_x, mid_y


def render_svg(vertices: list[Vertex], edges: list[Edge], per_row: int = PER_ROW) -> str:
    """The whole picture as one <svg> element (scales to the panel's width)."""
    placed = layout(vertices, edges, per_row)
    where = {p.vertex.key: p for p in placed}
    width = 2 * MARGIN + per_row * BOX_W + (per_row - 1) * GAP_X
    height = max((p.y for p in placed), default=0) + BOX_H + MARGIN + (0 if placed else 30)
    parts = [
        f'<svg class="ros-graph" xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {width} '
        f'{height:.0f}" width="100%" style="font-family:sans-serif;max-width:{width}px">',
        "<defs>"
        '<marker id="rg-arrow" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="7" '
        'markerHeight="7" orient="auto-start-reverse"><path d="M0,0 L10,5 L0,10 z" '
        'fill="#555"/></marker></defs>',
    ]
    if not placed:
        parts.append('<text x="10" y="24" font-size="13" fill="#666">(nothing on the graph)</text>')
    labels = []
    for edge in edges:
        a, b = where.get(edge.source), where.get(edge.target)
        if a is None or b is None or a is b:
            continue
        path, mx, my = edge_path(a, b)
        dash = ' stroke-dasharray="5,4"' if edge.dashed else ""
        parts.append(
            f'<path class="rg-edge" data-source="{escape(a.vertex.name)}" '
            f'data-target="{escape(b.vertex.name)}" d="{path}" fill="none" stroke="#777" '
            f'stroke-width="1.4"{dash} marker-end="url(#rg-arrow)"/>'
        )
        if edge.label:
            labels.append(
                f'<text class="rg-rate" x="{mx:.0f}" y="{my + 4:.0f}" font-size="11" '
                'text-anchor="middle" fill="#222" stroke="white" stroke-width="3" '
                f'paint-order="stroke">{escape(edge.label)}</text>'
            )
    for p in placed:
        fill, stroke, radius = STYLE[p.vertex.kind]
        v = p.vertex
        cx = p.x + BOX_W / 2
        title = f"{v.kind} {v.name}" + (f" ({v.detail})" if v.detail else "")
        name_y = p.y + (14 if v.detail else 21)
        label, font = fitted_name(v.name)
        parts.append(
            f'<g class="rg-vertex" data-kind="{v.kind}" data-name="{escape(v.name)}">'
            # A tooltip only for cut names: a hidden title would shadow the visible text.
            + (f"<title>{escape(title)}</title>" if label != v.name else "")
            + f'<rect x="{p.x:.0f}" y="{p.y:.0f}" width="{BOX_W}" height="{BOX_H}" rx="{radius}" '
            f'fill="{fill}" stroke="{stroke}" stroke-width="1.5"/>'
            f'<text x="{cx:.0f}" y="{name_y:.0f}" font-size="{font:g}" text-anchor="middle" '
            f'fill="#111">{escape(label)}</text>'
        )
        if v.detail:
            parts.append(
                f'<text x="{cx:.0f}" y="{p.y + 28:.0f}" font-size="10" text-anchor="middle" '
                f'fill="#555">{escape(short(v.detail, 32))}</text>'
            )
        parts.append("</g>")
    parts += labels  # on top of boxes and curves
    parts.append("</svg>")
    return "".join(parts)


def legend_html() -> str:
    """One line explaining colours and dashes, above the picture."""
    # Dark text on the light chips in both colour schemes; the note in the theme's own
    # dimmed colour (a fixed gray was unreadable in dark mode).
    chips = "".join(
        f'<span style="background:{fill};border:1px solid {stroke};border-radius:{radius}px;'
        f'padding:1px 6px;margin-right:6px;color:#111">{kind}</span>'
        for kind, (fill, stroke, radius) in STYLE.items()
    )
    return (
        f'<div style="font-family:sans-serif;font-size:12px;margin-bottom:4px">{chips}'
        '<span style="color:var(--mantine-color-dimmed)">arrows: publisher → topic → '
        "subscriber, server → service/action; dashed: client</span></div>"
    )


# ------------------------------------------------------------ from endpoints

PARAMETER_SERVICES = (
    "/describe_parameters", "/get_parameter_types", "/get_parameters", "/get_type_description",
    "/list_parameters", "/set_parameters", "/set_parameters_atomically",
    # lifecycle plumbing: the Lifecycle tab shows it better than five boxes here
    "/change_state", "/get_state", "/get_available_states", "/get_available_transitions",
    "/get_transition_graph",
)  # fmt: skip
HEAVY_TYPES = (
    "sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage", "sensor_msgs/msg/PointCloud2",
    "sensor_msgs/msg/LaserScan",
)  # fmt: skip


def _short_type(type_text: str) -> str:
    parts = type_text.split("/")
    return f"{parts[0]}/{parts[-1]}" if len(parts) == 3 else type_text


def hidden_name(name: str) -> bool:
    """A name ROS tools hide by default: some part of it starts with '_' (a node
    `/_ros2cli_123`, a topic `/turtlesim/_trails`, `/add_two_ints/_service_event`)."""
    return any(part.startswith("_") for part in name.split("/"))


def graph_picture(
    nodes: list[NodeEndpoints],
    rates: dict[str, str] | None = None,
    *,
    show_quiet: bool = False,
) -> tuple[list[Vertex], list[Edge]]:
    """Vertices and edges to draw; /rosout, /parameter_events, parameter and lifecycle
    services and hidden names (a part starting with '_') are left out unless ``show_quiet``
    (many nodes have them: they hide the rest). ``rates`` maps a topic to its label, e.g.
    '2.0 Hz'."""
    rates = rates or {}
    vertices: dict[str, Vertex] = {}
    edges: list[Edge] = []

    def add(kind: Kind, name: str, detail: str = "") -> str:
        vertex = Vertex(kind, name, detail)
        vertices.setdefault(vertex.key, vertex)
        return vertex.key

    def quiet_topic(name: str) -> bool:
        return ACTION_MARKER in name or (
            not show_quiet and (name in QUIET_TOPICS or hidden_name(name))
        )

    def quiet_service(name: str) -> bool:
        return ACTION_MARKER in name or (
            not show_quiet and (name.endswith(PARAMETER_SERVICES) or hidden_name(name))
        )

    # Hidden nodes (a name part starting with '_', as `ros2 node list` hides them) too.
    nodes = [n for n in nodes if show_quiet or not hidden_name(n.name)]
    for node in nodes:
        me = add("node", node.name)
        for topic, kind in sorted(node.publishes.items()):
            if not quiet_topic(topic):
                edges.append(Edge(me, add("topic", topic, _short_type(kind)), rates.get(topic, "")))
        for service, kind in sorted(node.servers.items()):
            if not quiet_service(service):
                edges.append(Edge(me, add("service", service, _short_type(kind))))
        for action, kind in sorted(node.action_servers.items()):
            edges.append(Edge(me, add("action", action, _short_type(kind))))
    for node in nodes:  # second pass: what nodes use, after what they offer
        me = f"node:{node.name}"
        for topic, kind in sorted(node.subscribes.items()):
            if not quiet_topic(topic):
                source = add("topic", topic, _short_type(kind))
                edges.append(Edge(source, me, rates.get(topic, "")))
        for service, kind in sorted(node.clients.items()):
            if not quiet_service(service):
                edges.append(Edge(me, add("service", service, _short_type(kind)), dashed=True))
        for action, kind in sorted(node.action_clients.items()):
            edges.append(Edge(me, add("action", action, _short_type(kind)), dashed=True))
    # A client waiting for a server that is not there: its box says so (drawn plain, it
    # read as a service that exists).
    served = {edge.target for edge in edges if not edge.dashed}
    for key, vertex in vertices.items():
        if vertex.kind in ("service", "action") and key not in served:
            vertices[key] = replace(vertex, detail=" · ".join(("no server", vertex.detail)))
    return list(vertices.values()), edges


def topics_to_measure(
    picture: tuple[list[Vertex], list[Edge]],
    nodes: list[NodeEndpoints],
    heavy_too: bool = False,
) -> dict[str, str]:
    """Topic -> type for the topics in the picture (large images and clouds only if asked)."""
    shown = {v.name for v in picture[0] if v.kind == "topic"}
    out: dict[str, str] = {}
    for node in nodes:
        for topic, kind in (*node.publishes.items(), *node.subscribes.items()):
            if topic in shown and (heavy_too or kind not in HEAVY_TYPES):
                out.setdefault(topic, kind)
    return out
