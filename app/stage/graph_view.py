"""The stage's ROS graph as SVG: stable places, distinct shapes, messages that move.

Pure functions and one small memory of places; no ROS, no browser. The
browser animates the dots itself (CSS keyframes of ``transform``), so the server
sends a new picture only when the graph or a rate changes, never per frame.
"""

from __future__ import annotations

import hashlib
import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from html import escape

from app.panels.graph_svg import (
    BOX_H,
    BOX_W,
    GAP_X,
    MARGIN,
    ROW_GAP,
    STYLE,
    Edge,
    Placed,
    Vertex,
    edge_path,
    fitted_name,
    layout,
    short,
)

PER_ROW = 3  # the stage is about three boxes wide at 1:1
TRAVEL_SEC = 1.0  # a dot takes this long along an edge
MAX_DOTS = 8  # per edge; a faster topic moves batches (its rate is written on the edge)
MAX_REMEMBERED = 500
STARTING = "starting…"  # a node's second line while its process runs but ROS has not listed it
LEG_SEC = 0.6  # a pulse's leg: caller to service/action box, or box to server
STEP_X, STEP_Y = BOX_W + GAP_X, BOX_H + ROW_GAP
EMPTY_NOTE = "Nothing on the graph yet: start a node."
NOTE_ROOM = 30  # px above the boxes for a note line
# A motion follows its curve in this many straight pieces (the eye still sees a curve).
MOTION_STEPS = 16


class StablePlaces:
    """Where each vertex was drawn, kept so that a new vertex never moves the others.

    A vertex seen before goes back to its place when that place is free; a new
    one takes the place the fresh layout suggests, or the nearest free cell.
    """

    def __init__(self, per_row: int = PER_ROW) -> None:
        self.per_row = per_row
        self._at: dict[str, tuple[float, float]] = {}

    def forget(self, key: str) -> None:
        """Let ``key`` take a new place once (a node drawn 'starting…' before its edges were
        known: once they are, it joins its group)."""
        self._at.pop(key, None)

    def place(self, vertices: list[Vertex], edges: list[Edge]) -> list[Placed]:
        fresh = layout(vertices, edges, self.per_row)
        taken: list[tuple[float, float]] = []
        out: list[Placed] = []
        later: list[Placed] = []
        for p in fresh:  # known vertices first: they keep their places
            at = self._at.get(p.vertex.key)
            if at is not None and not _overlaps(at, taken):
                taken.append(at)
                out.append(Placed(p.vertex, *at))
            else:
                later.append(p)
        for p in later:
            at = _free_cell((p.x, p.y), taken, self.per_row)
            taken.append(at)
            self._at[p.vertex.key] = at
            out.append(Placed(p.vertex, *at))
        if len(self._at) > MAX_REMEMBERED:  # forget the long gone, keep the present
            present = {p.vertex.key for p in out}
            self._at = {k: v for k, v in self._at.items() if k in present}
        return out


def _overlaps(at: tuple[float, float], taken: list[tuple[float, float]]) -> bool:
    return any(abs(at[0] - x) < STEP_X - 1 and abs(at[1] - y) < STEP_Y - 1 for x, y in taken)


def _free_cell(
    wish: tuple[float, float], taken: list[tuple[float, float]], per_row: int
) -> tuple[float, float]:
    """``wish`` if free; else the nearest free place in its row (half a box at a time, left
    or right: a second subscriber goes beside the first, not under it); else the first
    free grid cell from the next row down."""
    if not _overlaps(wish, taken):
        return wish
    left, right = float(MARGIN), MARGIN + (per_row - 1) * STEP_X
    for k in range(1, 2 * per_row + 1):
        for sign in (1, -1):
            x = wish[0] + sign * k * STEP_X / 2
            if left - 1 <= x <= right + 1 and not _overlaps((x, wish[1]), taken):
                return (x, wish[1])
    row = max(0, round((wish[1] - MARGIN) / STEP_Y)) + 1
    while True:
        y = MARGIN + row * STEP_Y
        for column in range(per_row):
            cell = (MARGIN + column * STEP_X, y)
            if not _overlaps(cell, taken):
                return cell
        row += 1


def dot_timing(rate_hz: float) -> list[tuple[float, float, float]]:
    """(duration s, begin s, share of the duration spent travelling) for each dot.

    At 2 Hz two dots a second leave the publisher (each dot arrives once per
    ``count / rate`` seconds, about TRAVEL_SEC, so arrivals match the rate);
    below 1/TRAVEL_SEC one dot travels in TRAVEL_SEC and waits for the next
    message; above MAX_DOTS/TRAVEL_SEC the dots stand for batches.
    """
    if rate_hz <= 0:
        return []
    period = 1.0 / rate_hz
    if period >= TRAVEL_SEC:
        return [(period, 0.0, TRAVEL_SEC / period)]
    count = min(MAX_DOTS, max(1, round(TRAVEL_SEC * rate_hz)))
    duration = count * period if count < MAX_DOTS else TRAVEL_SEC
    return [(duration, -i * duration / count, 1.0) for i in range(count)]


# Colours come from the page's theme: light and dark palettes as CSS variables, switched
# by the colour scheme Mantine (viser's UI kit) sets on <html>. Shapes and words carry
# every meaning; colour only helps.
_PALETTE = {
    "light": {
        "text": "#111", "dim": "#444", "edge": "#666", "halo": "#fff", "dot": "#1864ab",
        "node": "#dbe4ff", "node-line": "#3b5bdb", "topic": "#d3f9d8", "topic-line": "#2b8a3e",
        "service": "#fff4e6", "service-line": "#d9480f", "action": "#f3d9fa",
        "action-line": "#9c36b5", "pulse": "#fff", "pulse-line": "#d9480f",
    },
    "dark": {
        "text": "#f1f3f5", "dim": "#ced4da", "edge": "#adb5bd", "halo": "#1a1b1e",
        "dot": "#74c0fc", "node": "#1f2b4d", "node-line": "#91a7ff", "topic": "#183a24",
        "topic-line": "#69db7c", "service": "#47290f", "service-line": "#ffa94d",
        "action": "#3b1f44", "action-line": "#e599f7", "pulse": "#25262b",
        "pulse-line": "#ffa94d",
    },
}  # fmt: skip


def _variables(scheme: str) -> str:
    return ";".join(f"--sg-{name}:{value}" for name, value in _PALETTE[scheme].items())


STAGE_CSS = (
    f".stage-graph,.stage-legend{{{_variables('light')}}}"
    f"[data-mantine-color-scheme=dark] .stage-graph,"
    f"[data-mantine-color-scheme=dark] .stage-legend{{{_variables('dark')}}}"
    ".stage-graph .sg-name{fill:var(--sg-text)}.stage-graph .sg-detail{fill:var(--sg-dim)}"
    ".stage-graph .sg-edge{stroke:var(--sg-edge)}.stage-graph .sg-head{fill:var(--sg-edge)}"
    ".stage-graph .sg-rate,.stage-graph .sg-note{fill:var(--sg-text);stroke:var(--sg-halo)}"
    ".stage-graph .sg-dot{fill:var(--sg-dot);stroke:var(--sg-halo)}"
    ".stage-graph path.sg-blocked{stroke:#e03131}.stage-graph text.sg-blocked{fill:#e03131}"
    ".stage-graph .sg-pulse rect{fill:var(--sg-pulse);stroke:var(--sg-pulse-line)}"
    ".stage-graph .sg-pulse text{fill:var(--sg-text)}"
    + "".join(
        f".stage-graph .sg-{kind}{{fill:var(--sg-{kind});stroke:var(--sg-{kind}-line)}}"
        f".stage-legend .sg-{kind}{{background:var(--sg-{kind});border:1px solid "
        f"var(--sg-{kind}-line);color:var(--sg-text)}}"
        for kind in ("node", "topic", "service", "action")
    )
    + ".stage-graph .sg-action-inner{fill:none;stroke:var(--sg-action-line)}"
    ".stage-legend{color:var(--sg-text)}"
    # A learner who asked their system for less motion reads the rate on the edge instead.
    "@media (prefers-reduced-motion:reduce){.stage-graph .sg-dot{display:none}}"
)


def _shape(p: Placed, dashed: bool = False) -> str:
    """Node: a pill; topic: a box; service: a hexagon; action: a double box."""
    x, y, w, h = p.x, p.y, BOX_W, BOX_H
    kind = p.vertex.kind
    paint = f'class="sg-{kind}" stroke-width="1.5"' + (' stroke-dasharray="6,4"' if dashed else "")
    if kind == "node":
        return f'<rect x="{x:.0f}" y="{y:.0f}" width="{w}" height="{h}" rx="{h / 2:.0f}" {paint}/>'
    if kind == "service":
        c = 10
        points = (
            f"{x + c:.0f},{y:.0f} {x + w - c:.0f},{y:.0f} {x + w:.0f},{y + h / 2:.0f} "
            f"{x + w - c:.0f},{y + h:.0f} {x + c:.0f},{y + h:.0f} {x:.0f},{y + h / 2:.0f}"
        )
        return f'<polygon points="{points}" {paint}/>'
    box = f'<rect x="{x:.0f}" y="{y:.0f}" width="{w}" height="{h}" rx="2" {paint}/>'
    if kind == "action":
        box += (
            f'<rect class="sg-action-inner" x="{x + 3:.0f}" y="{y + 3:.0f}" width="{w - 6}" '
            f'height="{h - 6}" rx="1" stroke-width="1"/>'
        )
    return box


@dataclass(frozen=True)
class PulseView:
    """A pulse as drawn: ``age`` seconds since its travel began (negative: not yet)."""

    kind: str  # request, response, goal, feedback, result
    name: str  # the service or action it travels to or from
    caller: str = ""  # the node drawn as the caller; '' when unknown
    age: float = 0.0


_OUTBOUND = ("request", "goal")  # caller -> box -> server; the others come back


def _pulse_legs(
    pulse: PulseView, server_paths: list[str], caller_path: str | None
) -> list[tuple[str, bool, float]]:
    """(path, travel it backwards, begin s) for each leg: a call goes from the caller to the
    box and on to the server; an answer comes back the same way."""
    callers = [caller_path] if caller_path else []
    if pulse.kind in _OUTBOUND:
        first, second = [(c, False) for c in callers], [(s, True) for s in server_paths]
    else:
        first, second = [(s, False) for s in server_paths], [(c, True) for c in callers]
    later = LEG_SEC if first else 0.0  # no caller drawn: the server's leg comes at once
    legs = [(path, back, 0.0) for path, back in first]
    legs += [(path, back, later) for path, back in second]
    return [(path, back, begin - pulse.age) for path, back, begin in legs]


def _pulse_svg(pulse: PulseView, path: str, backwards: bool, begin: float) -> str:
    name = _motion(path, 1.0)[0]
    reverse = " reverse" if backwards else ""
    width = 10 + 7 * len(pulse.kind)
    # Hidden but for its leg's LEG_SEC: the keyframes make it visible, and only while they run.
    return (
        f'<g class="sg-pulse" data-kind="{pulse.kind}" data-name="{escape(pulse.name)}" '
        f'visibility="hidden" style="animation:{name} {LEG_SEC}s linear {begin:.3f}s 1'
        f'{reverse}"><rect x="{-width / 2:.0f}" y="-8" width="{width}" height="16" rx="8" '
        f'stroke-width="1.5"/><text y="4" font-size="11" text-anchor="middle">{pulse.kind}'
        "</text></g>"
    )


def _curve_points(path: str, steps: int = MOTION_STEPS) -> list[tuple[float, float]]:
    """``steps + 1`` points equally spaced along an ``edge_path`` curve ("Mx,y C...")."""
    x0, y0, x1, y1, x2, y2, x3, y3 = (float(v) for v in re.findall(r"-?\d+(?:\.\d+)?", path))

    def at(t: float) -> tuple[float, float]:
        u = 1 - t
        a, b, c, d = u * u * u, 3 * u * u * t, 3 * u * t * t, t * t * t
        return a * x0 + b * x1 + c * x2 + d * x3, a * y0 + b * y1 + c * y2 + d * y3

    dense = [at(i / (8 * steps)) for i in range(8 * steps + 1)]
    run = [0.0]  # length travelled at each dense point
    for (ax, ay), (bx, by) in zip(dense, dense[1:], strict=False):
        run.append(run[-1] + math.hypot(bx - ax, by - ay))
    points, j = [], 0
    for k in range(steps + 1):  # at an even pace, as SVG's own motion along a path moves
        want = run[-1] * k / steps
        while j < len(run) - 2 and run[j + 1] < want:
            j += 1
        piece = run[j + 1] - run[j] or 1.0
        f = min(1.0, max(0.0, (want - run[j]) / piece))
        (ax, ay), (bx, by) = dense[j], dense[j + 1]
        points.append((ax + f * (bx - ax), ay + f * (by - ay)))
    return points


def _motion(path: str, share: float) -> tuple[str, str]:
    """(name, @keyframes) moving an element along ``path`` in the first ``share`` of its
    time, then holding it at the end.

    CSS keyframes of ``transform`` rather than SVG's animateMotion: Chromium repainted the
    whole picture at every frame for animateMotion, and an idle lesson with talker and
    listener cost its page about a fifth of a core (measured: 17-21 % against 10.7 %).
    """
    name = "sg-m" + hashlib.blake2s(f"{path}|{share:.3f}".encode(), digest_size=5).hexdigest()
    at = [(100 * share * k / MOTION_STEPS, xy) for k, xy in enumerate(_curve_points(path))]
    if share < 1.0:  # waits at the end for the rest of its time
        at.append((100.0, at[-1][1]))
    frames = [
        f"{percent:.2f}%{{transform:translate({x:.1f}px,{y:.1f}px);visibility:visible}}"
        for percent, (x, y) in at
    ]
    return name, f"@keyframes {name}{{{''.join(frames)}}}"


MAX_ZOOM = 1.6  # a small graph is drawn up to this much larger, to use the stage
MAX_ZOOMED_HEIGHT = 520  # px: a zoomed graph stays about this tall at most (1366x768)
# Room round the boxes in a zoomed view: rate labels above, edges that bulge to the right.
ZOOM_ROOM = (24.0, 28.0, 70.0, 20.0)  # left, top, right, bottom


def _zoomed_view(placed: list[Placed], width: float, height: float, note: str) -> tuple[str, float]:
    """The viewBox and drawn height: a few boxes in one corner of a wide stage left most of
    it white (a teacher read the course on a projector), so a small graph is enlarged, up
    to ``MAX_ZOOM``, and centred; a large one (or one with a note line) stays 1:1."""
    natural = f"0 0 {width:.0f} {height:.0f}"
    if not placed or note:
        return natural, height
    left, top, right, bottom = ZOOM_ROOM
    x0 = min(p.x for p in placed) - left
    y0 = min(p.y for p in placed) - top
    x1 = max(p.x for p in placed) + BOX_W + right
    y1 = max(p.y for p in placed) + BOX_H + bottom
    zoom = min(MAX_ZOOM, width / (x1 - x0), MAX_ZOOMED_HEIGHT / (y1 - y0))
    if zoom <= 1.0:
        return natural, height
    view_w = width / zoom  # the stage's whole width, centred on the boxes
    cx = (x0 + x1) / 2
    return f"{cx - view_w / 2:.0f} {y0:.0f} {view_w:.0f} {y1 - y0:.0f}", (y1 - y0) * zoom


def stage_svg(
    placed: list[Placed],
    edges: list[Edge],
    rates: dict[str, float],
    link: Callable[[int, str, str], str] | None = None,
    pulses: list[PulseView] | tuple[PulseView, ...] = (),
    starting: frozenset[str] = frozenset(),
    min_width: float = 0.0,
    note: str | None = None,
) -> str:
    """The picture; ``rates`` (topic -> Hz) sets how many dots move on its edges,
    ``pulses`` are calls and goals on their way, ``starting`` the nodes drawn dashed
    because their process runs but the ROS graph does not list them yet.

    Drawn at its natural size or larger, never scaled down (the stage scrolls instead):
    at least ``min_width`` px wide, so it fills the stage; a small graph is enlarged
    (``_zoomed_view``). ``note``: a line written
    above the boxes (default: none, or that the graph is empty).

    ``link(i, content, title)`` wraps the i-th box (``placed`` order) in a link.
    """
    if note is None:
        note = "" if placed else EMPTY_NOTE
    top = NOTE_ROOM if note else 0.0
    placed = [Placed(p.vertex, p.x, p.y + top) for p in placed]
    where = {p.vertex.key: p for p in placed}
    right = max((p.x for p in placed), default=0) + BOX_W + MARGIN
    width = max(right, 2 * MARGIN + PER_ROW * BOX_W + (PER_ROW - 1) * GAP_X, min_width)
    height = max((p.y for p in placed), default=top) + (BOX_H + MARGIN if placed else 0) + 8
    view, shown_height = _zoomed_view(placed, width, height, note)
    parts = [
        f'<svg class="stage-graph" xmlns="http://www.w3.org/2000/svg" role="group" '
        f'aria-label="Live ROS graph: {len(placed)} items" viewBox="{view}" '
        f'width="{width:.0f}" height="{shown_height:.0f}" '
        'style="font-family:sans-serif;display:block">',
        f"<style>{STAGE_CSS}</style>",
        '<defs><marker id="sg-arrow" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="7" '
        'markerHeight="7" orient="auto-start-reverse"><path class="sg-head" '
        'd="M0,0 L10,5 L0,10 z"/></marker></defs>',
    ]
    if note:
        parts.append(
            f'<text class="sg-note" x="{MARGIN}" y="20" font-size="13" stroke-width="0">'
            f"{escape(note)}</text>"
        )
    labels, dots = [], []
    motions: dict[str, str] = {}  # keyframes by name: a path's dots share theirs
    servers: dict[str, list[str]] = {}  # service/action -> paths from its servers
    clients: dict[tuple[str, str], str] = {}  # (service/action, client node) -> path
    for edge in edges:
        a, b = where.get(edge.source), where.get(edge.target)
        if a is None or b is None or a is b:
            continue
        path, mx, my = edge_path(a, b)
        if a.vertex.kind == "node" and b.vertex.kind in ("service", "action"):
            if edge.dashed:
                clients[(b.vertex.name, a.vertex.name)] = path
            else:
                servers.setdefault(b.vertex.name, []).append(path)
        topic = next((v.name for v in (a.vertex, b.vertex) if v.kind == "topic"), "")
        dash = ' stroke-dasharray="5,4"' if edge.dashed or edge.blocked else ""
        blocked = (
            f' data-blocked="{escape(edge.blocked)}"><title>{escape(edge.blocked)}</title></path>'
            if edge.blocked
            else "/>"
        )
        parts.append(
            f'<path class="sg-edge{" sg-blocked" if edge.blocked else ""}" '
            f'data-source="{escape(a.vertex.name)}" '
            f'data-target="{escape(b.vertex.name)}" d="{path}" fill="none" '
            f'stroke-width="1.4"{dash} marker-end="url(#sg-arrow)"{blocked}'
        )
        # Nothing travels an edge no publisher can deliver on: no dots on it.
        for duration, begin, share in dot_timing(0.0 if edge.blocked else rates.get(topic, 0.0)):
            name, frames = _motion(path, share)
            motions[name] = frames
            dots.append(
                f'<circle class="sg-dot" data-topic="{escape(topic)}" '
                f'data-edge="{escape(a.vertex.name)}>{escape(b.vertex.name)}" r="4" '
                f'stroke-width="1" cx="0" cy="0" style="animation:{name} {duration:.3f}s '
                f'linear {begin:.3f}s infinite"/>'
            )
        if edge.label:
            labels.append(
                f'<text class="sg-rate{" sg-blocked" if edge.blocked else ""}" '
                f'x="{mx:.0f}" y="{my + 4:.0f}" font-size="11" '
                'text-anchor="middle" stroke-width="3" '
                f'paint-order="stroke">{escape(edge.label)}</text>'
            )
    for i, p in enumerate(placed):
        v = p.vertex
        cx = p.x + BOX_W / 2
        name_y = p.y + (14 if v.detail else 21)
        waiting = v.kind == "node" and v.name in starting
        label, font = fitted_name(v.name)
        body = (
            f'{_shape(p, waiting)}<text class="sg-name" x="{cx:.0f}" y="{name_y:.0f}" '
            f'font-size="{font:g}" text-anchor="middle">{escape(label)}</text>'
        )
        if v.detail:
            body += (
                f'<text class="sg-detail" x="{cx:.0f}" y="{p.y + 28:.0f}" font-size="11" '
                f'text-anchor="middle">{escape(short(v.detail, 30))}</text>'
            )
        title = f"{v.kind} {v.name}"
        body = (
            link(i, body, f"Inspect {title}") if link else f"<title>{escape(title)}</title>{body}"
        )
        state = "starting" if waiting else "on-graph"
        parts.append(
            f'<g class="sg-vertex" data-kind="{v.kind}" data-name="{escape(v.name)}" '
            f'data-state="{state}">{body}</g>'
        )
    moving = []
    for pulse in pulses:
        caller_path = clients.get((pulse.name, pulse.caller)) if pulse.caller else None
        for path, backwards, begin in _pulse_legs(pulse, servers.get(pulse.name, []), caller_path):
            if begin + LEG_SEC > 0:  # this leg is still to come or under way
                motions.setdefault(*_motion(path, 1.0))
                moving.append(_pulse_svg(pulse, path, backwards, begin))
    if motions:
        parts.append(f"<style>{''.join(motions.values())}</style>")
    parts += dots + moving + labels  # dots and pulses above the curves, labels on top of all
    parts.append("</svg>")
    return "".join(parts)


def stage_legend() -> str:
    """Shapes and words, so colour is never the only key."""
    shapes = {"node": "pill", "topic": "box", "service": "hexagon", "action": "double box"}
    chips = "".join(
        f'<span class="sg-{kind}" style="border-radius:{"10" if kind == "node" else "2"}px;'
        f'padding:1px 6px;margin-right:6px">{kind} ({shapes[kind]})</span>'
        for kind in STYLE
    )
    return (
        f'<style>{STAGE_CSS}</style><div class="stage-legend" style="font-family:sans-serif;'
        f'font-size:12px;line-height:1.9">{chips}<br>'
        "publisher → topic → subscriber; server → service/action; dashed: client. "
        "Dots are messages, at the rate written on the edge; a labelled pulse is a service "
        "call (request, response) or an action's goal, feedback and result. A red dashed "
        "edge is a subscription no publisher's QoS can deliver to.</div>"
    )
