"""The Graph panel's picture: which vertices and edges, their layers, and the SVG text."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

from app.panels.graph_svg import (
    BOX_H,
    Edge,
    NodeEndpoints,
    Vertex,
    fitted_name,
    graph_picture,
    layers,
    layout,
    render_svg,
    topics_to_measure,
)

STRING = "std_msgs/msg/String"


def endpoints(name: str, **kwargs: dict[str, str]) -> NodeEndpoints:
    fields = ("publishes", "subscribes", "servers", "clients", "action_servers", "action_clients")
    return NodeEndpoints(name, **{f: kwargs.get(f, {}) for f in fields})


TALKER = endpoints(
    "/talker",
    publishes={"/chatter": STRING, "/rosout": "rcl_interfaces/msg/Log"},
    servers={"/talker/list_parameters": "rcl_interfaces/srv/ListParameters"},
)
LISTENER = endpoints("/listener", subscribes={"/chatter": STRING})
SERVER = endpoints(
    "/add_two_ints_server", servers={"/add_two_ints": "tutorial_interfaces/srv/AddTwoInts"}
)
CLIENT = endpoints(
    "/add_two_ints_client", clients={"/add_two_ints": "tutorial_interfaces/srv/AddTwoInts"}
)
ACTION = endpoints(
    "/fibonacci_action_server",
    action_servers={"/fibonacci": "tutorial_interfaces/action/Fibonacci"},
    publishes={"/fibonacci/_action/status": "action_msgs/msg/GoalStatusArray"},
)


def test_picture_has_services_actions_and_flow_edges():
    vertices, edges = graph_picture(
        [TALKER, LISTENER, SERVER, CLIENT, ACTION], {"/chatter": "2.0 Hz"}
    )
    keys = {v.key for v in vertices}
    assert keys == {
        "node:/talker",
        "node:/listener",
        "node:/add_two_ints_server",
        "node:/add_two_ints_client",
        "node:/fibonacci_action_server",
        "topic:/chatter",
        "service:/add_two_ints",
        "action:/fibonacci",
    }  # /rosout, parameter services and action internals are left out by default
    flows = {(e.source, e.target, e.label, e.dashed) for e in edges}
    assert ("node:/talker", "topic:/chatter", "2.0 Hz", False) in flows
    assert ("topic:/chatter", "node:/listener", "2.0 Hz", False) in flows
    assert ("node:/add_two_ints_server", "service:/add_two_ints", "", False) in flows
    assert ("node:/add_two_ints_client", "service:/add_two_ints", "", True) in flows
    assert ("node:/fibonacci_action_server", "action:/fibonacci", "", False) in flows
    chatter = next(v for v in vertices if v.key == "topic:/chatter")
    assert chatter.detail == "std_msgs/String"


def test_quiet_topics_and_parameter_services_on_request():
    vertices, _edges = graph_picture([TALKER], show_quiet=True)
    names = {v.name for v in vertices}
    assert {"/rosout", "/talker/list_parameters"} <= names


def test_layers_follow_the_data_and_survive_cycles():
    chain = [Edge("a", "b"), Edge("b", "c"), Edge("c", "d")]
    assert layers(["a", "b", "c", "d"], chain) == {"a": 0, "b": 1, "c": 2, "d": 3}
    cyclic = [Edge("a", "b"), Edge("b", "a"), Edge("b", "c")]
    got = layers(["a", "b", "c"], cyclic)
    assert got["a"] < got["b"] < got["c"]
    assert layers(["x"], []) == {"x": 0}


def test_layout_puts_publishers_above_subscribers_and_wraps_wide_layers():
    vertices, edges = graph_picture([TALKER, LISTENER])
    y = {p.vertex.name: p.y for p in layout(vertices, edges)}
    assert y["/talker"] < y["/chatter"] < y["/listener"]
    many = [Vertex("node", f"/n{i}") for i in range(5)]
    placed = layout(many, [], per_row=2)
    rows = sorted({p.y for p in placed})
    assert len(rows) == 3 and rows[1] - rows[0] > BOX_H
    assert len({(p.x, p.y) for p in placed}) == 5  # nothing on top of anything


def test_svg_is_well_formed_escaped_and_labelled():
    nodes = [endpoints(f"/node_{i}", publishes={f"/topic_{i}": STRING}) for i in range(15)]
    nodes.append(endpoints("/odd<&>", subscribes={"/topic_0": STRING}))
    vertices, edges = graph_picture(nodes, {"/topic_0": "9.5 Hz"})
    svg = render_svg(vertices, edges)
    root = ET.fromstring(svg)  # raises on malformed markup or bad escaping
    groups = [g for g in root.iter("{http://www.w3.org/2000/svg}g")]
    assert len(groups) == 31
    assert 'data-name="/odd&lt;&amp;&gt;"' in svg
    assert len(re.findall(r'class="rg-rate"[^>]*>9\.5 Hz<', svg)) == 2
    assert "(nothing on the graph)" in render_svg([], [])


def test_rates_measured_only_for_drawn_topics_and_not_heavy_ones():
    camera = endpoints(
        "/camera", publishes={"/image": "sensor_msgs/msg/Image", "/rosout": "x/msg/Log"}
    )
    picture = graph_picture([TALKER, camera])
    assert topics_to_measure(picture, [TALKER, camera]) == {"/chatter": STRING}
    heavy = topics_to_measure(picture, [TALKER, camera], heavy_too=True)
    assert heavy == {"/chatter": STRING, "/image": "sensor_msgs/msg/Image"}


def test_a_long_name_is_set_smaller_and_only_a_very_long_one_is_cut_in_its_middle():
    assert fitted_name("/talker") == ("/talker", 12.0)
    name, font = fitted_name("/fibonacci_action_server")  # 24 characters: as it is
    assert (name, font) == ("/fibonacci_action_server", 12.0)
    name, font = fitted_name("/turtlesim/describe_parameters")  # 30: whole, smaller
    assert name == "/turtlesim/describe_parameters" and 9.0 <= font < 12.0
    assert len(name) * font <= 25 * 12.0  # no wider than 25 characters at 12 px
    very_long = "/classroom_dashboard/get_parameter_types_and_more"
    name, font = fitted_name(very_long)
    assert font == 9.0 and "…" in name and len(name) * font <= 25 * 12.0
    head, tail = name.split("…")
    assert very_long.startswith(head) and very_long.endswith(tail) and tail.endswith("_more")
    svg = render_svg([Vertex("node", very_long)], [])
    assert f"<title>node {very_long}</title>" in svg  # the whole name on hover
