"""The stage: lessons name it (validated), and its graph keeps places and times its dots."""

from __future__ import annotations

import math
import re
import shutil
from pathlib import Path

import pytest

from app.lessons.schema import LESSONS_DIR, LessonError, load_lesson
from app.panels.graph_svg import Edge, Vertex, graph_picture, topics_to_measure
from app.ros.graph import NodeEndpoints
from app.stage import DEFAULT_STAGE, STAGES
from app.stage.graph_view import (
    MAX_DOTS,
    PulseView,
    StablePlaces,
    _curve_points,
    _motion,
    dot_timing,
    stage_svg,
)
from tests.course_data import shared_course


def test_every_lesson_names_a_known_stage():
    course = shared_course()
    assert course.errors == ()
    for lesson in course.lessons:
        text = (lesson.path / "lesson.toml").read_text(encoding="utf-8")
        named = re.search(r'^stage = "(\w+)"', text, re.MULTILINE)
        assert lesson.stage == (named.group(1) if named else DEFAULT_STAGE)
        assert lesson.stage in STAGES


def _copy(tmp_path: Path, stage_line: str, step_stage: str = "") -> Path:
    source = LESSONS_DIR / "05_topics"
    target = tmp_path / source.name
    shutil.copytree(source, target)
    toml = target / "lesson.toml"
    text = re.sub(r'^stage = "\w+"\n', "", toml.read_text(encoding="utf-8"), flags=re.MULTILINE)
    text = stage_line + text
    if step_stage:
        text = text.replace("[[steps]]\n", f"[[steps]]\n{step_stage}", 1)
    toml.write_text(text, encoding="utf-8")
    return target


def test_a_unit_without_stage_gets_the_default_and_a_step_can_override(tmp_path):
    lesson = load_lesson(_copy(tmp_path, "", 'stage = "code"\n'))
    assert lesson.stage == DEFAULT_STAGE
    assert lesson.steps[0].stage == "code"
    assert lesson.steps[1].stage == ""  # the unit's


def test_an_unknown_stage_is_a_clear_error(tmp_path):
    with pytest.raises(LessonError, match=r"unknown stage 'movie' \(stages: graph, plot, image"):
        load_lesson(_copy(tmp_path, 'stage = "movie"\n'))
    with pytest.raises(LessonError, match=r"steps\[0\]: unknown stage 'film'"):
        load_lesson(_copy(tmp_path / "b", 'stage = "graph"\n', 'stage = "film"\n'))
    with pytest.raises(LessonError, match="field 'stage' must be str"):
        load_lesson(_copy(tmp_path / "c", "stage = 3\n"))


def test_the_diagram_stage_needs_a_picture(tmp_path):
    # 05_topics's first step has no image: its diagram cannot be on stage.
    with pytest.raises(LessonError, match=r"steps\[0\]: its stage is the step's diagram"):
        load_lesson(_copy(tmp_path, 'stage = "graph"\n', 'stage = "picture"\n'))
    with pytest.raises(LessonError, match=r"its stage is the step's diagram, but it has no image"):
        load_lesson(_copy(tmp_path / "b", 'stage = "picture"\n'))


def _endpoints(name: str, publishes=(), subscribes=()) -> NodeEndpoints:
    kind = "std_msgs/msg/String"
    return NodeEndpoints(
        name=name,
        publishes={t: kind for t in publishes},
        subscribes={t: kind for t in subscribes},
        servers={},
        clients={},
        action_servers={},
        action_clients={},
    )


def test_a_new_node_moves_no_other():
    places = StablePlaces()
    talker = _endpoints("/talker", publishes=["/chatter"])
    listener = _endpoints("/listener", subscribes=["/chatter"])
    first = {p.vertex.key: (p.x, p.y) for p in places.place(*graph_picture([talker, listener]))}
    more = [
        _endpoints("/a_first", publishes=["/aaa"]),
        talker,
        _endpoints("/aa_listener", subscribes=["/chatter", "/aaa"]),
        listener,
    ]
    second = {p.vertex.key: (p.x, p.y) for p in places.place(*graph_picture(more))}
    for key, at in first.items():
        assert second[key] == at, key
    spots = list(second.values())
    assert len(spots) == len(set(spots)), "no two boxes on one spot"


def test_hidden_nodes_and_quiet_topics_are_folded_unless_asked():
    nodes = [
        _endpoints("/talker", publishes=["/chatter", "/rosout"]),
        _endpoints("/_ros2cli_daemon", subscribes=["/chatter"]),
    ]
    names = {v.name for v in graph_picture(nodes)[0]}
    assert names == {"/talker", "/chatter"}
    names = {v.name for v in graph_picture(nodes, show_quiet=True)[0]}
    assert names == {"/talker", "/chatter", "/rosout", "/_ros2cli_daemon"}


def test_hidden_topics_and_services_are_folded_and_not_measured_unless_asked():
    """turtlesim's pen trails and teleop's key topic are plumbing: no box, no rate counted."""
    sim = _endpoints("/turtlesim", publishes=["/turtle1/pose", "/turtlesim/_trails"])
    sim = NodeEndpoints(
        **{
            **sim.__dict__,
            "servers": {"/spawn": "turtlesim/srv/Spawn", "/turtlesim/_snap": "x/srv/S"},
        }
    )
    teleop = _endpoints("/teleop_turtle", publishes=["/turtle1/cmd_vel", "/teleop_turtle/_key"])
    follower = _endpoints("/follower", subscribes=["/turtlesim/_trails"])
    nodes = [sim, teleop, follower]
    picture = graph_picture(nodes)
    names = {v.name for v in picture[0]}
    assert "/turtlesim/_trails" not in names and "/teleop_turtle/_key" not in names
    assert "/turtlesim/_snap" not in names and "/spawn" in names
    assert {"/turtle1/pose", "/turtle1/cmd_vel", "/follower"} <= names
    assert set(topics_to_measure(picture, nodes)) == {"/turtle1/pose", "/turtle1/cmd_vel"}
    shown = graph_picture(nodes, show_quiet=True)
    assert {"/turtlesim/_trails", "/teleop_turtle/_key", "/turtlesim/_snap"} <= {
        v.name for v in shown[0]
    }
    assert "/turtlesim/_trails" in topics_to_measure(shown, nodes)


def test_dots_follow_the_rate_and_are_capped():
    assert dot_timing(0.0) == []
    (slow,) = dot_timing(0.5)  # one dot, travels 1 s, waits 1 s
    assert slow == (2.0, 0.0, 0.5)
    two = dot_timing(2.0)
    assert [begin for _d, begin, _s in two] == [0.0, -0.5]
    for rate in (1.3, 2.0, 2.4, 5.0, 7.0):  # arrivals per second (dots / duration) = the rate
        timing = dot_timing(rate)
        assert len(timing) / timing[0][0] == pytest.approx(rate)
    assert len(dot_timing(1000.0)) == MAX_DOTS


def test_an_edge_no_publisher_can_deliver_on_is_red_dashed_and_carries_no_dots():
    """The QoS lesson's mismatch: the topic has its rate, the listener hears nothing."""
    vertices = [Vertex("node", "/talker"), Vertex("topic", "/chatter"), Vertex("node", "/l")]
    why = "Best effort publisher and reliable subscription"
    edges = [
        Edge("node:/talker", "topic:/chatter", "2.0 Hz"),
        Edge("topic:/chatter", "node:/l", "QoS mismatch: nothing arrives", blocked=why),
    ]
    svg = stage_svg(StablePlaces().place(vertices, edges), edges, {"/chatter": 2.0})
    assert svg.count('data-edge="/talker>/chatter"') == 2  # the publisher's side moves
    assert 'data-edge="/chatter>/l"' not in svg  # nothing travels to the listener
    assert 'class="sg-edge sg-blocked"' in svg and f"<title>{why}</title>" in svg
    assert re.search(r'class="sg-rate sg-blocked"[^>]*>QoS mismatch: nothing arrives<', svg)


def test_the_svg_animates_dots_on_both_edges_of_a_topic():
    vertices = [Vertex("node", "/talker"), Vertex("topic", "/chatter"), Vertex("node", "/l")]
    edges = [Edge("node:/talker", "topic:/chatter", "2.0 Hz"), Edge("topic:/chatter", "node:/l")]
    svg = stage_svg(StablePlaces().place(vertices, edges), edges, {"/chatter": 2.0})
    assert svg.count('class="sg-dot" data-topic="/chatter"') == 4
    assert svg.count('infinite"/>') == 4  # each dot loops on its keyframes
    (name,) = set(re.findall(r'data-edge="/talker>/chatter"[^>]*animation:(sg-m\w+) ', svg))
    assert f"@keyframes {name}{{" in svg
    assert "2.0 Hz" in svg
    quiet = stage_svg(StablePlaces().place(vertices, edges), edges, {})
    assert '<circle class="sg-dot"' not in quiet


def test_a_motion_runs_the_whole_curve_at_an_even_pace_then_waits_at_its_end():
    """The keyframes start on the publisher's side, end at the arrow, take equal steps,
    and a slow topic's dot (share 0.5) travels in the first half and waits at the end."""
    path = "M100,60 C100,90 300,90 300,120"
    points = _curve_points(path)
    assert points[0] == pytest.approx((100, 60)) and points[-1] == pytest.approx((300, 120))
    steps = [math.dist(a, b) for a, b in zip(points, points[1:], strict=False)]
    assert max(steps) - min(steps) < 0.05 * max(steps)
    name, frames = _motion(path, 0.5)
    percents = [float(p) for p in re.findall(r"([\d.]+)%\{", frames)]
    assert percents[0] == 0.0 and percents[-2] == 50.0 and percents[-1] == 100.0
    assert frames.startswith(f"@keyframes {name}{{")
    assert frames.count("translate(300.0px,120.0px)") == 2  # arrives, then waits there


def _pulse_legs_in(svg: str) -> list[tuple[str, str, float, bool]]:
    """(kind, name, begin s, travels backwards) of each pulse leg drawn in ``svg``."""
    legs = re.findall(
        r'<g class="sg-pulse" data-kind="(\w+)" data-name="([^"]+)" visibility="hidden" '
        r'style="animation:sg-m\w+ 0.6s linear (-?[\d.]+)s 1( reverse)?">',
        svg,
    )
    return [(kind, name, float(b), rest == " reverse") for kind, name, b, rest in legs]


def test_a_call_travels_from_its_caller_to_the_server_and_back():
    vertices = [
        Vertex("node", "/server"), Vertex("service", "/add"), Vertex("node", "/client"),
        Vertex("node", "/other_client"),
    ]  # fmt: skip
    edges = [
        Edge("node:/server", "service:/add"),
        Edge("node:/client", "service:/add", dashed=True),
        Edge("node:/other_client", "service:/add", dashed=True),
    ]
    placed = StablePlaces().place(vertices, edges)
    request = PulseView("request", "/add", caller="/client", age=0.0)
    response = PulseView("response", "/add", caller="/client", age=-1.2)  # after the request
    svg = stage_svg(placed, edges, {}, pulses=[request, response])
    assert _pulse_legs_in(svg) == [
        ("request", "/add", 0.0, False),  # /client -> /add
        ("request", "/add", 0.6, True),  # /add -> /server, against the server's arrow
        ("response", "/add", 1.2, False),  # /server -> /add
        ("response", "/add", 1.8, True),  # /add -> /client
    ]
    # Unknown caller (this dashboard, not drawn): only the server's leg, at once.
    svg = stage_svg(placed, edges, {}, pulses=[PulseView("goal", "/add")])
    assert _pulse_legs_in(svg) == [("goal", "/add", 0.0, True)]
    # Half way through: the first leg is over and left out, the second under way.
    svg = stage_svg(placed, edges, {}, pulses=[PulseView("request", "/add", "/client", 0.9)])
    assert _pulse_legs_in(svg) == [("request", "/add", -0.3, True)]
    assert (
        stage_svg(placed, edges, {}, pulses=[PulseView("result", "/add", "", 5.0)]).count(
            'class="sg-pulse"'
        )
        == 0
    )
    assert ">request</text>" in stage_svg(placed, edges, {}, pulses=[request])  # said in words


def test_a_started_node_is_drawn_dashed_until_the_graph_lists_it():
    vertices = [Vertex("node", "/talker", "starting…")]
    placed = StablePlaces().place(vertices, [])
    svg = stage_svg(placed, [], {}, starting=frozenset({"/talker"}))
    assert 'data-name="/talker" data-state="starting"' in svg and "stroke-dasharray" in svg
    svg = stage_svg(StablePlaces().place([Vertex("node", "/talker")], []), [], {})
    assert 'data-state="on-graph"' in svg and "stroke-dasharray" not in svg


def test_a_service_with_only_a_client_says_no_server():
    """Lesson 7's client waiting for its server: the service box must not read as served."""
    types = {"/add_two_ints": "example_interfaces/srv/AddTwoInts"}
    client = NodeEndpoints("/add_two_ints_client", {}, {}, {}, types, {}, {})
    details = {v.name: v.detail for v in graph_picture([client])[0]}
    assert details["/add_two_ints"] == "no server · example_interfaces/AddTwoInts"
    server = NodeEndpoints("/add_two_ints_server", {}, {}, types, {}, {}, {})
    details = {v.name: v.detail for v in graph_picture([client, server])[0]}
    assert details["/add_two_ints"] == "example_interfaces/AddTwoInts"


def test_a_goals_result_pulse_is_never_crowded_out_by_its_feedback():
    """Feedback that came bunched (a loaded machine) fills the action's queue beyond what a
    burst may wait; further feedback is thinned, but the result still travels, after it."""
    from app.stage.pulses import MAX_BEHIND_SEC, TRAVEL_SEC, CallWatch

    watch = CallWatch(node=None)  # type: ignore[arg-type]  # only the event side is used
    with watch._lock:
        for _ in range(int(MAX_BEHIND_SEC / TRAVEL_SEC) + 3):
            watch._add("feedback", "/fibonacci")
        watch._add("result", "/fibonacci")
    kinds = [p.kind for p in watch._pulses]
    assert kinds[-1] == "result" and kinds.count("feedback") < int(MAX_BEHIND_SEC / TRAVEL_SEC) + 3
    shown = [p.shown_at for p in watch._pulses]
    assert shown == sorted(shown)  # the result follows the feedback on screen


def test_an_edge_between_boxes_side_by_side_runs_across_the_gap_with_its_rate_above():
    """The bags lesson's replay: /chatter (no publisher drawn) beside /listener. The edge
    bulged round the listener's far side and its rate sat on the listener's name."""
    from app.panels.graph_svg import BOX_H, BOX_W, Placed, edge_path

    topic = Placed(Vertex("topic", "/chatter"), 100.0, 50.0)
    node = Placed(Vertex("node", "/listener"), 100.0 + BOX_W + 14, 50.0)
    path, mx, my = edge_path(topic, node)
    start, end = path.split()[0], path.split()[-1]
    assert start == f"M{100 + BOX_W:.0f},{50 + BOX_H / 2:.0f}"  # the topic's right side
    assert end == f"{100 + BOX_W + 14:.0f},{50 + BOX_H / 2:.0f}"  # the listener's left side
    assert 100 + BOX_W <= mx <= 100 + BOX_W + 14 and my < 50  # in the gap, above the boxes
    back, _mx, _my = edge_path(node, topic)  # right to left: the facing sides again
    assert back.split()[0] == f"M{100 + BOX_W + 14:.0f},{50 + BOX_H / 2:.0f}"


def test_a_small_graph_is_enlarged_to_use_the_stage_and_a_large_one_stays_1_to_1():
    """Three boxes in a column on an 800 px stage: drawn 1.6x, centred, not taller than
    the stage; twelve rows of boxes: natural size (the stage scrolls)."""
    small = [Vertex("node", "/talker"), Vertex("topic", "/chatter"), Vertex("node", "/l")]
    edges = [Edge("node:/talker", "topic:/chatter"), Edge("topic:/chatter", "node:/l")]
    svg = stage_svg(StablePlaces().place(small, edges), edges, {}, min_width=800)
    view = [float(v) for v in re.search(r'viewBox="([^"]+)"', svg).group(1).split()]
    drawn_w = float(re.search(r' width="([\d.]+)"', svg).group(1))
    drawn_h = float(re.search(r' height="([\d.]+)"', svg).group(1))
    assert drawn_w == 800 and drawn_w / view[2] == pytest.approx(1.6, abs=0.01)
    assert drawn_h / view[3] == pytest.approx(1.6, abs=0.01) and drawn_h <= 520
    chain = [Vertex("node", f"/n{i}") for i in range(12)]
    links = [Edge(f"node:/n{i}", f"node:/n{i + 1}") for i in range(11)]
    tall = stage_svg(StablePlaces().place(chain, links), links, {}, min_width=800)
    assert re.search(r'viewBox="0 0 (\d+) (\d+)" width="\1" height="\2"', tall), tall[:300]
