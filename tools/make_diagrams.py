"""Draw the course's diagrams as SVG files in ``static/``.

Each picture is plain SVG text built here, with no dependency beyond the
standard library, so the output is the same on every machine: running the
script again changes no byte (``tests/unit/test_static_images.py`` checks
that). Lessons name a picture in a step (``image = "..."``) and the Lessons
tab shows it under the step's text.

The pictures are drawn for the side panel, about 370 to 480 px wide: the
view box is 400 units wide and no text is smaller than 12 units.

Usage: ``python tools/make_diagrams.py [output folder]`` (default ``static/``).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from pathlib import Path
from xml.sax.saxutils import escape, quoteattr

ROOT = Path(__file__).resolve().parent.parent
STATIC = ROOT / "static"

W = 400
FONT = "DejaVu Sans, Verdana, Arial, sans-serif"
MONO = "DejaVu Sans Mono, Menlo, Consolas, monospace"
INK = "#212529"
SOFT = "#495057"  # secondary text, still 7:1 on white
LINE = "#343a40"
# The Graph tab's colours: a node is a blue pill, a topic a green box.
NODE = ("#dbe4ff", "#3b5bdb")
TOPIC = ("#d3f9d8", "#2f9e44")
SERVICE = ("#fff4e6", "#e8590c")
STATE = ("#d0ebff", "#1864ab")
TRANSITION = ("#fff3bf", "#e67700")
GOOD = ("#d3f9d8", "#2b8a3e")
BAD = ("#ffe3e3", "#c92a2a")
RED, GREEN, BLUE = "#c92a2a", "#2b8a3e", "#1864ab"  # x, y, z axes (rviz colours)


def _n(value: float) -> str:
    """A coordinate, the same text on every platform."""
    return f"{round(value, 2):g}"


class Svg:
    """A picture under construction: shapes appended in drawing order."""

    def __init__(self, height: float, title: str, desc: str) -> None:
        self.height = height
        self.title = title
        self.desc = desc
        self.parts: list[str] = []
        self.markers: dict[str, str] = {}

    def _marker(self, color: str) -> str:
        marker_id = "arrow-" + color.lstrip("#")
        self.markers[marker_id] = color
        return marker_id

    def rect(
        self,
        x: float,
        y: float,
        w: float,
        h: float,
        fill: str,
        stroke: str,
        rx: float = 6,
        dashed: bool = False,
        width: float = 1.5,
    ) -> None:
        dash = ' stroke-dasharray="6 4"' if dashed else ""
        self.parts.append(
            f'<rect x="{_n(x)}" y="{_n(y)}" width="{_n(w)}" height="{_n(h)}" rx="{_n(rx)}" '
            f'fill="{fill}" stroke="{stroke}" stroke-width="{_n(width)}"{dash}/>'
        )

    def text(
        self,
        x: float,
        y: float,
        content: str,
        size: float = 14,
        bold: bool = False,
        italic: bool = False,
        anchor: str = "middle",
        fill: str = INK,
        mono: bool = False,
        rotate: float = 0,
    ) -> None:
        style = ""
        if bold:
            style += ' font-weight="bold"'
        if italic:
            style += ' font-style="italic"'
        if mono:
            style += f" font-family={quoteattr(MONO)}"
        if rotate:
            style += f' transform="rotate({_n(rotate)} {_n(x)} {_n(y)})"'
        self.parts.append(
            f'<text x="{_n(x)}" y="{_n(y)}" font-size="{_n(size)}" text-anchor="{anchor}" '
            f'fill="{fill}"{style}>{escape(content)}</text>'
        )

    def lines(self, x: float, y: float, rows: list[str], size: float = 13, **kwargs) -> float:
        """Several lines of text from baseline ``y``; returns the baseline after the last."""
        for row in rows:
            self.text(x, y, row, size=size, **kwargs)
            y += size * 1.35
        return y

    def path(
        self,
        points: list[tuple[float, float]],
        color: str = LINE,
        width: float = 2,
        arrow: bool = True,
        dashed: bool = False,
    ) -> None:
        d = "M" + " L".join(f"{_n(x)} {_n(y)}" for x, y in points)
        end = f' marker-end="url(#{self._marker(color)})"' if arrow else ""
        dash = ' stroke-dasharray="7 5"' if dashed else ""
        self.parts.append(
            f'<path d="{d}" fill="none" stroke="{color}" stroke-width="{_n(width)}" '
            f'stroke-linejoin="round"{dash}{end}/>'
        )

    def arrow(self, x1: float, y1: float, x2: float, y2: float, **kwargs) -> None:
        self.path([(x1, y1), (x2, y2)], **kwargs)

    def box(
        self,
        cx: float,
        y: float,
        w: float,
        h: float,
        colors: tuple[str, str],
        name: str,
        detail: str = "",
        rx: float = 6,
        dashed: bool = False,
        size: float = 15,
        detail_size: float = 13,
        mono_name: bool = False,
    ) -> None:
        """A box centred on ``cx``: a bold name and an optional second line."""
        self.rect(cx - w / 2, y, w, h, colors[0], colors[1], rx=rx, dashed=dashed)
        if detail:
            middle = y + h / 2
            self.text(cx, middle - 3, name, size=size, bold=True, mono=mono_name)
            self.text(cx, middle + detail_size + 1, detail, size=detail_size, fill=SOFT)
        else:
            self.text(cx, y + h / 2 + size * 0.36, name, size=size, bold=True, mono=mono_name)

    def axis_into_page(self, x: float, y: float, color: str) -> None:
        """An axis pointing away from the viewer: a circle with a cross."""
        self.parts.append(
            f'<circle cx="{_n(x)}" cy="{_n(y)}" r="7" fill="white" stroke="{color}" '
            f'stroke-width="2"/><path d="M{_n(x - 4.5)} {_n(y - 4.5)} L{_n(x + 4.5)} '
            f'{_n(y + 4.5)} M{_n(x - 4.5)} {_n(y + 4.5)} L{_n(x + 4.5)} {_n(y - 4.5)}" '
            f'stroke="{color}" stroke-width="2"/>'
        )

    def axis_out_of_page(self, x: float, y: float, color: str) -> None:
        """An axis pointing at the viewer: a circle with a dot."""
        self.parts.append(
            f'<circle cx="{_n(x)}" cy="{_n(y)}" r="7" fill="white" stroke="{color}" '
            f'stroke-width="2"/><circle cx="{_n(x)}" cy="{_n(y)}" r="2.5" fill="{color}"/>'
        )

    def raw(self, element: str) -> None:
        self.parts.append(element)

    def render(self) -> str:
        markers = "".join(
            f'<marker id="{marker_id}" viewBox="0 0 10 10" refX="9" refY="5" '
            f'markerUnits="userSpaceOnUse" markerWidth="11" markerHeight="11" '
            f'orient="auto-start-reverse">'
            f'<path d="M0 0 L10 5 L0 10 z" fill="{color}"/></marker>'
            for marker_id, color in sorted(self.markers.items())
        )
        head = (
            f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {W} {_n(self.height)}" '
            f'width="{W}" height="{_n(self.height)}" role="img" '
            f'aria-labelledby="title desc" font-family={quoteattr(FONT)}>\n'
            f'<title id="title">{escape(self.title)}</title>\n'
            f'<desc id="desc">{escape(self.desc)}</desc>\n'
            f"<defs>{markers}</defs>\n"
            f'<rect width="{W}" height="{_n(self.height)}" fill="white"/>\n'
        )
        return head + "\n".join(self.parts) + "\n</svg>\n"


# -- the pictures ------------------------------------------------------------


def dds_layers() -> Svg:
    svg = Svg(
        400,
        "The layers a ROS 2 message passes through",
        "A Python talker and a C++ listener, each drawn as a stack of layers: "
        "your code, the client library (rclpy or rclcpp), rcl, rmw and DDS. "
        "A message goes down the talker's stack, across the network as UDP "
        "packets or shared memory, and up the listener's stack.",
    )
    left, right, col_w = 110, 290, 160
    svg.text(left, 22, "talker process", size=14, bold=True, fill=SOFT)
    svg.text(right, 22, "listener process", size=14, bold=True, fill=SOFT)
    layers = [
        (("talker.py", "your code, Python"), ("listener.cpp", "your code, C++"), NODE),
        (("rclpy", "Python client library"), ("rclcpp", "C++ client library"), NODE),
        (("rcl", "shared C core"), ("rcl", "shared C core"), ("#e7f5ff", "#1971c2")),
        (("rmw", "one API, any vendor"), ("rmw", "one API, any vendor"), SERVICE),
        (("DDS", "Fast DDS (default)"), ("DDS", "Fast DDS (default)"), ("#f3d9fa", "#ae3ec9")),
    ]
    y, h, gap = 34, 42, 8
    for (l_name, l_detail), (r_name, r_detail), colors in layers:
        svg.box(left, y, col_w, h, colors, l_name, l_detail)
        svg.box(right, y, col_w, h, colors, r_name, r_detail)
        y += h + gap
    net_y = y + 6
    svg.rect(8, net_y, W - 16, 44, "#e9ecef", "#495057")
    svg.text(W / 2, net_y + 19, "operating system and network", size=14, bold=True)
    svg.text(W / 2, net_y + 36, "UDP packets or shared memory", size=13, fill=SOFT)
    orange = "#d9480f"
    svg.arrow(18, 40, 18, net_y - 2, color=orange, width=3)
    svg.arrow(W - 18, net_y - 2, W - 18, 40, color=orange, width=3)
    svg.text(14, 210, "publish: down", size=13, bold=True, fill=orange, rotate=-90)
    svg.text(W - 14, 150, "receive: up", size=13, bold=True, fill=orange, rotate=90)
    svg.lines(
        W / 2,
        net_y + 68,
        [
            "Python and C++ nodes share rcl, so they understand",
            "each other. RMW_IMPLEMENTATION picks the DDS vendor",
            "and your code does not change.",
        ],
        size=13,
    )
    return svg


def topic_graph() -> Svg:
    svg = Svg(
        300,
        "A talker and two listeners on one topic",
        "The node /talker publishes on the topic /chatter. Two nodes, /listener "
        "and /listener2, subscribe to /chatter, so each message reaches both.",
    )
    svg.box(62, 96, 104, 40, NODE, "/talker", rx=20)
    svg.box(200, 92, 112, 48, TOPIC, "/chatter", "String", rx=4)
    svg.box(333, 30, 118, 40, NODE, "/listener", rx=20)
    svg.box(333, 162, 118, 40, NODE, "/listener2", rx=20)
    svg.arrow(114, 116, 142, 116, width=2.5)
    svg.path([(256, 106), (280, 106), (280, 50), (272, 50)], width=2.5)
    svg.path([(256, 126), (280, 126), (280, 182), (272, 182)], width=2.5)
    svg.text(62, 160, "1 publisher", size=13, bold=True, fill=SOFT)
    svg.text(200, 160, "the topic", size=13, bold=True, fill=SOFT)
    svg.text(333, 124, "2 subscribers", size=13, bold=True, fill=SOFT)
    svg.text(200, 72, '"Hello World: 7"', size=13, italic=True, fill=SOFT, mono=True)
    svg.rect(20, 226, 30, 22, *NODE, rx=11)
    svg.text(60, 242, "node: a process doing one job", size=13, anchor="start")
    svg.rect(20, 258, 30, 22, *TOPIC, rx=3)
    svg.text(60, 274, "topic: a named stream of messages", size=13, anchor="start")
    return svg


def service_call() -> Svg:
    svg = Svg(
        420,
        "A service call: one request, one response",
        "Sequence over time. The client node sends a request with a=2 and b=3 "
        "to /add_two_ints; call_async returns a future at once. The server's "
        "callback fills response.sum and returns it; the response sum=5 "
        "completes the client's future. Below, the AddTwoInts file: request "
        "fields above the three dashes, response fields below.",
    )
    client, server = 80, 320
    svg.box(client, 12, 150, 46, NODE, "client", "/add_two_ints_client", rx=12, detail_size=12)
    svg.box(server, 12, 150, 46, NODE, "server", "/add_two_ints_server", rx=12, detail_size=12)
    for x in (client, server):
        svg.arrow(x, 58, x, 268, color="#adb5bd", width=2, arrow=False, dashed=True)
    svg.rect(server - 7, 104, 14, 84, "#ffe8cc", SERVICE[1], rx=2)
    svg.rect(client - 7, 84, 14, 160, "#e7f5ff", NODE[1], rx=2)
    svg.arrow(client + 7, 104, server - 9, 104, color=SERVICE[1], width=2.5)
    svg.text(200, 97, "request  a=2, b=3", size=14, bold=True)
    svg.text(200, 122, "call_async returns a future;", size=13, fill=SOFT)
    svg.text(200, 139, "the client keeps spinning", size=13, fill=SOFT)
    svg.text(200, 162, "the server callback fills", size=13, fill=SOFT)
    svg.text(200, 179, "response.sum and returns it", size=13, fill=SOFT)
    svg.arrow(server - 7, 200, client + 9, 200, color=SERVICE[1], width=2.5)
    svg.text(200, 219, "response  sum=5", size=14, bold=True)
    svg.text(200, 250, "future done: the client reads 5", size=13, fill=SOFT)
    svg.arrow(14, 70, 14, 262, color=SOFT, width=1.5)
    svg.text(10, 166, "time", size=13, fill=SOFT, rotate=-90)
    svg.text(W / 2, 296, "tutorial_interfaces/srv/AddTwoInts", size=13, bold=True)
    svg.rect(100, 306, 200, 100, "#f8f9fa", "#868e96", rx=4)
    svg.lines(
        116, 328, ["int64 a", "int64 b", "---", "int64 sum"], size=15, mono=True, anchor="start"
    )
    svg.text(206, 339, "request", size=13, bold=True, anchor="start", fill=SERVICE[1])
    svg.text(206, 393, "response", size=13, bold=True, anchor="start", fill=SERVICE[1])
    return svg


def action_timeline() -> Svg:
    svg = Svg(
        540,
        "An action over time: goal, feedback, result, cancel",
        "Sequence over time between an action client and the /fibonacci server. "
        "The client sends a goal (order 10) and the server accepts it. The client "
        "asks for the result, which is answered only at the end. Meanwhile the "
        "server publishes feedback messages with the partial sequence. Finally the "
        "result arrives with status SUCCEEDED. Alternatively the client sends a "
        "cancel request, the server accepts it, stops at its next step and the "
        "result arrives with status CANCELED and the numbers so far.",
    )
    client, server = 62, 338
    svg.box(client, 12, 112, 46, NODE, "client", "Actions tab", rx=12)
    svg.box(server, 12, 112, 46, NODE, "server", "/fibonacci", rx=12)
    for x in (client, server):
        svg.arrow(x, 58, x, 464, color="#adb5bd", width=2, arrow=False, dashed=True)
    blue, green, red = NODE[1], TOPIC[1], "#c92a2a"

    def send(y: float, label: str, color: str, to_server: bool, dashed: bool = False) -> None:
        a, b = (client, server) if to_server else (server, client)
        svg.arrow(a, y, b + (-9 if to_server else 9), y, color=color, width=2.5, dashed=dashed)
        svg.text(W / 2, y - 7, label, size=13, bold=True)

    svg.rect(server - 6, 118, 12, 178, "#ffe8cc", SERVICE[1], rx=2)
    send(92, "goal: order 10", blue, True)
    send(126, "accepted", blue, False)
    send(160, "get result (answered at the end)", blue, True)
    send(194, "feedback  [0, 1]", green, False, dashed=True)
    send(228, "feedback  [0, 1, 1]", green, False, dashed=True)
    send(262, "feedback  ...", green, False, dashed=True)
    send(296, "result: SUCCEEDED, 11 numbers", blue, False)
    svg.arrow(20, 318, W - 20, 318, color="#868e96", width=1, arrow=False, dashed=True)
    svg.text(W / 2, 340, "or: the client cancels part-way", size=13, italic=True, fill=SOFT)
    send(374, "cancel", red, True)
    send(408, "cancel accepted", red, False)
    send(448, "result: CANCELED, numbers so far", red, False)
    svg.arrow(14, 70, 14, 450, color=SOFT, width=1.5)
    svg.text(10, 260, "time", size=13, fill=SOFT, rotate=-90)
    svg.arrow(24, 490, 64, 490, color=blue, width=2.5)
    svg.text(74, 495, "service: request and its answer", size=13, anchor="start")
    svg.arrow(24, 518, 64, 518, color=green, width=2.5, dashed=True)
    svg.text(74, 523, "topic: feedback, as often as it comes", size=13, anchor="start")
    return svg


def lifecycle_states() -> Svg:
    svg = Svg(
        560,
        "The lifecycle state machine",
        "Four primary states: unconfigured, inactive, active and finalized. Between "
        "them are transition states, each running one callback: configure leads from "
        "unconfigured to inactive through configuring, activate from inactive to "
        "active through activating, deactivate back through deactivating, cleanup "
        "from inactive back to unconfigured through cleaningup. Shutdown from any "
        "of the three first states goes through shuttingdown to finalized. An error "
        "raised in a callback leads to errorprocessing, which returns to "
        "unconfigured.",
    )
    col, right = 130, 330
    rows = {"A": 46, "B": 128, "C": 212, "D": 294, "E": 378}
    ph, th = 44, 46

    def primary(cx: float, y: float, name: str) -> None:
        svg.box(cx, y, 150 if cx == col else 120, ph, STATE, name, rx=10, size=16)

    def transition(cx: float, y: float, name: str, state: str) -> None:
        svg.box(cx, y, 104, th, TRANSITION, name, state, rx=4, dashed=True, size=14)

    primary(col, rows["A"], "unconfigured")
    primary(col, rows["C"], "inactive")
    primary(col, rows["E"], "active")
    primary(right, rows["E"], "finalized")
    transition(75, rows["B"], "configure", "configuring")
    transition(185, rows["B"], "cleanup", "cleaningup")
    transition(75, rows["D"], "activate", "activating")
    transition(185, rows["D"], "deactivate", "deactivating")
    transition(right, rows["C"], "shutdown", "shuttingdown")
    svg.box(right, rows["A"], 120, th, BAD, "on error", "errorprocessing", rx=4, dashed=True)
    down, up = 75, 185
    for top, mid, bottom in (("A", "B", "C"), ("C", "D", "E")):
        svg.arrow(down, rows[top] + ph, down, rows[mid] - 2)
        svg.arrow(down, rows[mid] + th, down, rows[bottom] - 2)
        svg.arrow(up, rows[bottom], up, rows[mid] + th + 2)
        svg.arrow(up, rows[mid], up, rows[top] + ph + 2)
    bus = 240
    for row in ("A", "C", "E"):
        svg.arrow(205, rows[row] + ph / 2 + 6, bus, rows[row] + ph / 2 + 6, arrow=False)
    svg.arrow(bus, rows["A"] + ph / 2 + 6, bus, rows["E"] + ph / 2 + 6, arrow=False)
    svg.arrow(bus, rows["C"] + th / 2, right - 62, rows["C"] + th / 2)
    svg.arrow(right, rows["C"] + th, right, rows["E"] - 2)
    svg.path([(right, rows["A"]), (right, 24), (col, 24), (col, rows["A"] - 2)], color=BAD[1])
    svg.text(240, 18, "recovered", size=12, fill=BAD[1], bold=True)
    ly = 446
    svg.rect(14, ly, 34, 22, *STATE, rx=8)
    svg.text(58, ly + 16, "primary state: the node rests here", size=13, anchor="start")
    svg.rect(14, ly + 30, 34, 22, *TRANSITION, rx=3, dashed=True)
    svg.text(58, ly + 46, "transition: runs your on_... callback", size=13, anchor="start")
    svg.lines(
        14,
        ly + 80,
        ["A callback that returns FAILURE leaves the node", "in the state it started from."],
        size=13,
        anchor="start",
        fill=SOFT,
    )
    return svg


def qos_compatibility() -> Svg:
    svg = Svg(
        430,
        "QoS compatibility: what the publisher offers against what the subscriber requests",
        "Two tables. Reliability: a best-effort publisher and a best-effort "
        "subscriber connect; a best-effort publisher and a reliable subscriber do "
        "not connect; a reliable publisher connects with either subscriber. "
        "Durability: a volatile publisher and a transient-local subscriber do not "
        "connect; every other pair connects. The rule: the offer must be at least "
        "the request.",
    )
    svg.text(W / 2, 22, "They connect only if the publisher offers", size=14, bold=True)
    svg.text(W / 2, 40, "at least what the subscriber requests.", size=14, bold=True)

    def table(top: float, policy: str, weak: str, strong: str, mark_lesson: bool) -> None:
        head_w, cell_w, row_h = 134, 124, 40
        x0 = (W - head_w - 2 * cell_w) / 2
        svg.text(x0, top, policy, size=15, bold=True, anchor="start")
        svg.text(x0 + head_w + cell_w, top + 22, "subscriber requests", size=13, fill=SOFT)
        svg.text(x0 + 6, top + 50, "publisher offers", size=13, fill=SOFT, anchor="start")
        for i, name in enumerate((weak, strong)):
            svg.text(x0 + head_w + cell_w * (i + 0.5), top + 50, name, size=14, bold=True)
        for row, offer in enumerate((weak, strong)):
            y = top + 60 + row * row_h
            svg.rect(x0, y, head_w, row_h, "#f1f3f5", "#adb5bd", rx=0)
            svg.text(x0 + 8, y + 25, offer, size=14, bold=True, anchor="start")
            for col, _request in enumerate((weak, strong)):
                ok = not (row == 0 and col == 1)
                colors = GOOD if ok else BAD
                x = x0 + head_w + col * cell_w
                svg.rect(x, y, cell_w, row_h, colors[0], "#adb5bd", rx=0)
                label = "✓ connects" if ok else "✗ no match"
                svg.text(x + cell_w / 2, y + 25, label, size=13, bold=True, fill=colors[1])
                if not ok and mark_lesson:
                    svg.rect(x + 2, y + 2, cell_w - 4, row_h - 4, "none", "#d9480f", 2, width=3)

    table(76, "Reliability", "best effort", "reliable", mark_lesson=True)
    table(246, "Durability", "volatile", "transient local", mark_lesson=False)
    svg.lines(
        W / 2,
        408,
        ["Orange frame: this lesson's best-effort talker and reliable", "listener."],
        size=13,
        fill=SOFT,
    )
    return svg


def camera_base_frames() -> Svg:
    svg = Svg(
        400,
        "The camera frame and the robot's base frame",
        "Side view of the pick-and-place cell. The arm stands on the table with "
        "base_link at its foot: x forward, z up, y into the picture. The camera "
        "hangs 0.25 m in front of the base and 0.70 m above it, looking down: its "
        "optical z axis points down to the table, x forward, y out of the picture. "
        "The camera measures the object about 0.62 m away along its z axis; in the "
        "base frame the same point is about 0.08 m high.",
    )
    ox, oy, scale = 90, 300, 330  # base_link in pixels; pixels per metre
    cam_x, cam_y = ox + 0.25 * scale, oy - 0.70 * scale
    obj_x, obj_y = ox + 0.34 * scale, oy - 0.08 * scale
    svg.rect(6, oy, W - 12, 12, "#e9ecef", "#868e96", rx=2)
    svg.text(W - 14, oy + 30, "table", size=13, fill=SOFT, anchor="end")
    # The arm, pale, behind everything else.
    arm = "#ced4da"
    svg.rect(ox - 18, oy - 16, 36, 16, arm, "#adb5bd", rx=3)
    svg.raw(
        f'<path d="M{_n(ox)} {_n(oy - 16)} L{_n(ox + 22)} {_n(oy - 120)} '
        f'L{_n(obj_x - 6)} {_n(obj_y - 44)}" fill="none" stroke="{arm}" stroke-width="12" '
        'stroke-linecap="round" stroke-linejoin="round"/>'
    )
    svg.text(ox + 32, oy - 124, "arm", size=13, fill=SOFT, anchor="start")
    # The object on the table.
    svg.rect(obj_x - 14, oy - 30, 28, 30, "#ffd8a8", "#d9480f", rx=2)
    svg.raw(f'<circle cx="{_n(obj_x)}" cy="{_n(obj_y)}" r="4" fill="#d9480f"/>')
    svg.text(obj_x + 20, obj_y + 4, "object", size=13, bold=True, anchor="start")
    # The camera, looking down.
    svg.rect(cam_x - 20, cam_y - 26, 40, 20, "#495057", "#212529", rx=3)
    svg.raw(
        f'<path d="M{_n(cam_x - 9)} {_n(cam_y - 6)} L{_n(cam_x + 9)} {_n(cam_y - 6)} '
        f'L{_n(cam_x + 6)} {_n(cam_y)} L{_n(cam_x - 6)} {_n(cam_y)} z" fill="#212529"/>'
    )
    svg.text(cam_x - 26, cam_y - 12, "camera", size=14, bold=True, anchor="end")
    # What the camera measures: the depth along its z axis.
    svg.arrow(cam_x + 3, cam_y + 58, obj_x - 2, obj_y - 6, color="#d9480f", width=1.5, dashed=True)
    svg.text(obj_x + 10, cam_y + 110, "z ≈ 0.62 m:", size=13, bold=True, anchor="start")
    svg.text(obj_x + 10, cam_y + 127, "the camera's view", size=13, anchor="start")
    # Camera axes (optical convention).
    svg.arrow(cam_x, cam_y, cam_x, cam_y + 56, color=BLUE, width=3)
    svg.text(cam_x - 8, cam_y + 52, "z", size=15, bold=True, fill=BLUE, anchor="end")
    svg.arrow(cam_x, cam_y, cam_x + 56, cam_y, color=RED, width=3)
    svg.text(cam_x + 60, cam_y + 5, "x", size=15, bold=True, fill=RED, anchor="start")
    svg.axis_out_of_page(cam_x, cam_y, GREEN)
    svg.text(cam_x - 12, cam_y + 22, "y ⊙", size=15, bold=True, fill=GREEN, anchor="end")
    # base_link axes (x forward, y left, z up).
    svg.arrow(ox, oy, ox + 60, oy, color=RED, width=3)
    svg.text(ox + 64, oy - 6, "x", size=15, bold=True, fill=RED, anchor="start")
    svg.arrow(ox, oy, ox, oy - 62, color=BLUE, width=3)
    svg.text(ox - 8, oy - 52, "z", size=15, bold=True, fill=BLUE, anchor="end")
    svg.axis_into_page(ox, oy, GREEN)
    svg.text(ox - 12, oy - 12, "y ⊗", size=15, bold=True, fill=GREEN, anchor="end")
    svg.text(ox - 12, oy + 30, "base_link", size=14, bold=True, anchor="middle")
    # Where the camera is mounted, in the base frame.
    svg.arrow(ox, 34, cam_x, 34, color=SOFT, width=1.5)
    svg.arrow(ox, 26, ox, 42, color=SOFT, width=1.5, arrow=False)
    svg.text((ox + cam_x) / 2, 26, "0.25 m", size=13, bold=True)
    svg.arrow(30, oy, 30, cam_y, color=SOFT, width=1.5)
    svg.text(24, (oy + cam_y) / 2, "0.70 m", size=13, bold=True, rotate=-90)
    svg.lines(
        14,
        oy + 56,
        [
            "⊙ points at you, ⊗ away from you.",
            "Camera (optical): z out of the lens, x right, y down",
            "in the image. base_link: x forward, y left, z up.",
        ],
        size=13,
        anchor="start",
    )
    return svg


def slam_pipeline() -> Svg:
    svg = Svg(
        650,
        "The monocular SLAM pipeline",
        "video_publisher publishes frames on /cam/image_raw. slam_node runs four "
        "stages: features tracked with optical flow; a two-view start that "
        "estimates the essential matrix with RANSAC; triangulation of the first "
        "3D points; then tracking each new frame with PnP and adding new points. "
        "It publishes /cam/map_points (PointCloud2), /cam/camera_pose "
        "(MarkerArray) and /cam/feature_ext_viz (Image), all shown in the 3D "
        "view tab.",
    )
    cx = 178
    svg.box(cx, 10, 180, 38, NODE, "video_publisher", rx=19)
    svg.arrow(cx, 48, cx, 64)
    svg.box(cx, 66, 220, 42, TOPIC, "/cam/image_raw", "Image, about 10 a second", rx=4)
    svg.arrow(cx, 108, cx, 128)
    top, box_w, step = 130, 240, 64
    svg.rect(cx - 135, top, 270, 292, "#f8f9ff", NODE[1], rx=14, dashed=True)
    svg.text(cx, top + 22, "slam_node", size=15, bold=True, fill=NODE[1])
    stages = [
        ("1  features", "corners, tracked frame to frame"),
        ("2  two-view start", "essential matrix + RANSAC"),
        ("3  triangulation", "two rays meet: first 3D points"),
        ("4  track and map", "PnP per frame, add new points"),
    ]
    y = top + 34
    for i, (name, detail) in enumerate(stages):
        colors = TRANSITION if i in (1, 2) else ("#ffffff", LINE)
        svg.box(cx, y, box_w, 48, colors, name, detail, size=14)
        if i < 3:
            svg.arrow(cx, y + 48, cx, y + 62)
        y += step
    once_middle = top + 34 + step * 1.5 + 24
    svg.lines(cx + 142, once_middle - 6, ["once,", "at start"], size=13, bold=True,
              fill=TRANSITION[1], anchor="start")  # fmt: skip
    left = cx - box_w / 2
    loop_y1, loop_y2 = top + 34 + step * 3 + 24, top + 34 + 24
    svg.path(
        [(left, loop_y1), (24, loop_y1), (24, loop_y2), (left - 2, loop_y2)],
        color=NODE[1],
    )
    svg.text(18, (loop_y1 + loop_y2) / 2, "every new frame", size=13, bold=True,
             fill=NODE[1], rotate=-90)  # fmt: skip
    outputs = [
        ("/cam/map_points", "PointCloud2: the 3D map"),
        ("/cam/camera_pose", "MarkerArray: the path"),
        ("/cam/feature_ext_viz", "Image: tracked corners"),
    ]
    y = top + 292 + 22
    svg.arrow(cx, top + 292, cx, y - 2)
    rail = W - 30
    for name, detail in outputs:
        svg.box(cx, y, box_w, 46, TOPIC, name, detail, rx=4, size=14, mono_name=True)
        svg.arrow(cx + box_w / 2, y + 23, rail, y + 23, arrow=False)
        y += 54
    svg.arrow(rail, top + 314 + 23, rail, y + 4)
    svg.text(W - 10, y + 26, "all three: the 3D view tab", size=14, bold=True, anchor="end")
    return svg


def log_odds_cell() -> Svg:
    """One map cell's evidence over seven scans, with the thresholds that name it."""
    steps = [("start", 0.0), ("miss", -0.4), ("miss", -0.4), ("miss", -0.4),
             ("hit", 0.85), ("hit", 0.85), ("hit", 0.85)]  # fmt: skip
    free_at, occupied_at = math.log(0.25 / 0.75), math.log(0.65 / 0.35)  # -1.10, +0.62
    svg = Svg(
        400,
        "One map cell's log-odds, scan by scan",
        "The cell starts at log-odds 0 (probability 0.5, unknown). Beams of three scans "
        "cross it, minus 0.4 each: -0.4, -0.8, -1.2, below the free line (probability "
        "0.25, log-odds -1.10), so the map calls it free. Then beams of three scans end "
        "in it, plus 0.85 each: -0.35 and +0.5 (unknown again), then +1.35, above the "
        "occupied line (probability 0.65, log-odds +0.62): occupied. Evidence adds up, "
        "and the cell can change its mind.",
    )
    left, right, top, bottom = 58.0, W - 16.0, 40.0, 300.0
    low, high = -1.6, 1.6

    def y_of(value: float) -> float:
        return bottom - (value - low) / (high - low) * (bottom - top)

    svg.text(W / 2, 22, "One cell, scan by scan", size=15, bold=True)
    bands = ((high, occupied_at, BAD, "occupied"), (occupied_at, free_at, ("#f1f3f5", SOFT),
             "unknown"), (free_at, low, GOOD, "free"))  # fmt: skip
    for upper, lower, colors, name in bands:
        svg.rect(left, y_of(upper), right - left, y_of(lower) - y_of(upper), colors[0], "none", 0)
        svg.text(left + 6, y_of(upper) + 17, name, size=13, bold=True, fill=colors[1],
                 anchor="start")  # fmt: skip
    for value, label, x, dy, anchor in (
        (occupied_at, "+0.62 (p 0.65)", (left + right) / 2, 15, "middle"),  # clear of the line
        (free_at, "-1.10 (p 0.25)", right - 6, -6, "end"),
    ):
        svg.path([(left, y_of(value)), (right, y_of(value))], SOFT, 1.5, arrow=False, dashed=True)
        svg.text(x, y_of(value) + dy, label, size=12, fill=SOFT, anchor=anchor)
    svg.text(left - 8, y_of(0.0) + 4, "0", size=12, fill=SOFT, anchor="end")
    svg.text(16, (top + bottom) / 2, "log-odds", size=13, fill=SOFT, rotate=-90)
    gap = (right - left) / len(steps)
    total, points = 0.0, []
    for i, (_event, change) in enumerate(steps):
        total += change
        points.append((left + gap * (i + 0.5), y_of(total)))
    svg.path(points, LINE, 2, arrow=False)
    total = 0.0
    for (x, y), (event, change) in zip(points, steps, strict=True):
        total += change
        svg.raw(f'<circle cx="{_n(x)}" cy="{_n(y)}" r="5" fill="{LINE}"/>')
        svg.text(x, y - 10 if total <= 0.2 else y + 20, f"{total:+.2f}".replace("+0.00", "0"),
                 size=12, bold=True)  # fmt: skip
        svg.text(x, bottom + 18, event, size=12, fill=SOFT)
    svg.lines(W / 2, bottom + 48, ["miss: a beam crossed it, -0.4",
              "hit: a beam ended in it, +0.85"], size=13, fill=SOFT)  # fmt: skip
    return svg


DIAGRAMS: dict[str, Callable[[], Svg]] = {
    "dds_layers.svg": dds_layers,
    "topic_graph.svg": topic_graph,
    "service_call.svg": service_call,
    "action_timeline.svg": action_timeline,
    "lifecycle_states.svg": lifecycle_states,
    "qos_compatibility.svg": qos_compatibility,
    "camera_base_frames.svg": camera_base_frames,
    "slam_pipeline.svg": slam_pipeline,
    "log_odds.svg": log_odds_cell,
}


def render_all() -> dict[str, str]:
    """Every diagram's file name and SVG text."""
    return {name: draw().render() for name, draw in DIAGRAMS.items()}


def main(argv: list[str]) -> int:
    target = Path(argv[0]) if argv else STATIC
    target.mkdir(parents=True, exist_ok=True)
    for name, text in render_all().items():
        path = target / name
        data = text.encode("utf-8")
        if not path.exists() or path.read_bytes() != data:
            path.write_bytes(data)
            print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
