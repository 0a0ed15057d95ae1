"""The stage's ROS graph as SVG: stable places, distinct shapes, messages that move.

Pure functions and one small memory of places; no ROS, no browser. The
browser animates the dots itself (SVG ``animateMotion``), so the server sends
a new picture only when the graph or a rate changes, never per frame.
"""

from __future__ import annotations

from collections.abc import Callable
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
    layout,
    short,
)

PER_ROW = 3  # the stage is about three boxes wide at 1:1
TRAVEL_SEC = 1.0  # a dot takes this long along an edge
MAX_DOTS = 8  # per edge; a faster topic moves batches (its rate is written on the edge)
MAX_REMEMBERED = 500
STEP_X, STEP_Y = BOX_W + GAP_X, BOX_H + ROW_GAP


class StablePlaces:
    """Where each vertex was drawn, kept so that a new vertex never moves the others.

    A vertex seen before goes back to its place when that place is free; a new
    one takes the place the fresh layout suggests, or the nearest free cell.
    """

    def __init__(self, per_row: int = PER_ROW) -> None:
        self.per_row = per_row
        self._at: dict[str, tuple[float, float]] = {}

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
    """``wish`` if free, else the first free grid cell from its row down."""
    if not _overlaps(wish, taken):
        return wish
    row = max(0, round((wish[1] - MARGIN) / STEP_Y))
    while True:
        y = MARGIN + row * STEP_Y
        for column in range(per_row):
            cell = (MARGIN + column * STEP_X, y)
            if not _overlaps(cell, taken):
                return cell
        row += 1


def dot_timing(rate_hz: float) -> list[tuple[float, float, float]]:
    """(duration s, begin s, share of the duration spent travelling) for each dot.

    At 2 Hz two dots a second leave the publisher; below 1/TRAVEL_SEC one dot
    travels in TRAVEL_SEC and waits for the next message; above
    MAX_DOTS/TRAVEL_SEC the dots stand for batches.
    """
    if rate_hz <= 0:
        return []
    period = 1.0 / rate_hz
    if period >= TRAVEL_SEC:
        return [(period, 0.0, TRAVEL_SEC / period)]
    count = min(MAX_DOTS, max(1, round(TRAVEL_SEC * rate_hz)))
    return [(TRAVEL_SEC, -i * TRAVEL_SEC / count, 1.0) for i in range(count)]


def _shape(p: Placed) -> str:
    """Node: a pill; topic: a box; service: a hexagon; action: a double box."""
    fill, stroke, _radius = STYLE[p.vertex.kind]
    x, y, w, h = p.x, p.y, BOX_W, BOX_H
    paint = f'fill="{fill}" stroke="{stroke}" stroke-width="1.5"'
    kind = p.vertex.kind
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
            f'<rect x="{x + 3:.0f}" y="{y + 3:.0f}" width="{w - 6}" height="{h - 6}" rx="1" '
            f'fill="none" stroke="{stroke}" stroke-width="1"/>'
        )
    return box


def stage_svg(
    placed: list[Placed],
    edges: list[Edge],
    rates: dict[str, float],
    link: Callable[[int, str, str], str] | None = None,
) -> str:
    """The picture; ``rates`` (topic -> Hz) sets how many dots move on its edges.

    ``link(i, content, title)`` wraps the i-th box (``placed`` order) in a link.
    """
    where = {p.vertex.key: p for p in placed}
    right = max((p.x for p in placed), default=0) + BOX_W + MARGIN
    width = max(right, 2 * MARGIN + PER_ROW * BOX_W + (PER_ROW - 1) * GAP_X)
    height = max((p.y for p in placed), default=0) + BOX_H + MARGIN + (0 if placed else 30)
    parts = [
        f'<svg class="stage-graph" xmlns="http://www.w3.org/2000/svg" role="img" '
        f'aria-label="Live ROS graph: {len(placed)} items" viewBox="0 0 {width:.0f} '
        f'{height:.0f}" width="100%" style="font-family:sans-serif;max-width:{width:.0f}px">',
        '<defs><marker id="sg-arrow" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="7" '
        'markerHeight="7" orient="auto-start-reverse"><path d="M0,0 L10,5 L0,10 z" '
        'fill="#555"/></marker></defs>',
    ]
    if not placed:
        parts.append(
            '<text x="10" y="24" font-size="13" fill="#555">Nothing on the graph yet: '
            "start a node.</text>"
        )
    labels, dots = [], []
    for edge in edges:
        a, b = where.get(edge.source), where.get(edge.target)
        if a is None or b is None or a is b:
            continue
        path, mx, my = edge_path(a, b)
        topic = next((v.name for v in (a.vertex, b.vertex) if v.kind == "topic"), "")
        dash = ' stroke-dasharray="5,4"' if edge.dashed else ""
        parts.append(
            f'<path class="sg-edge" data-source="{escape(a.vertex.name)}" '
            f'data-target="{escape(b.vertex.name)}" d="{path}" fill="none" stroke="#777" '
            f'stroke-width="1.4"{dash} marker-end="url(#sg-arrow)"/>'
        )
        for duration, begin, share in dot_timing(rates.get(topic, 0.0)):
            timing = (
                f'keyPoints="0;1;1" keyTimes="0;{share:.3f};1" calcMode="linear" '
                if share < 1.0
                else ""
            )
            dots.append(
                f'<circle class="sg-dot" data-topic="{escape(topic)}" r="4" fill="#1971c2" '
                'stroke="white" stroke-width="1" cx="0" cy="0">'
                f'<animateMotion dur="{duration:.3f}s" begin="{begin:.3f}s" '
                f'repeatCount="indefinite" {timing}path="{path}"/></circle>'
            )
        if edge.label:
            labels.append(
                f'<text class="sg-rate" x="{mx:.0f}" y="{my + 4:.0f}" font-size="11" '
                'text-anchor="middle" fill="#222" stroke="white" stroke-width="3" '
                f'paint-order="stroke">{escape(edge.label)}</text>'
            )
    for i, p in enumerate(placed):
        v = p.vertex
        cx = p.x + BOX_W / 2
        name_y = p.y + (14 if v.detail else 21)
        body = (
            f'{_shape(p)}<text x="{cx:.0f}" y="{name_y:.0f}" font-size="12" '
            f'text-anchor="middle" fill="#111">{escape(short(v.name))}</text>'
        )
        if v.detail:
            body += (
                f'<text x="{cx:.0f}" y="{p.y + 28:.0f}" font-size="10" text-anchor="middle" '
                f'fill="#444">{escape(short(v.detail, 30))}</text>'
            )
        title = f"{v.kind} {v.name}"
        body = (
            link(i, body, f"Inspect {title}") if link else f"<title>{escape(title)}</title>{body}"
        )
        parts.append(
            f'<g class="sg-vertex" data-kind="{v.kind}" data-name="{escape(v.name)}">{body}</g>'
        )
    parts += dots + labels  # dots above the curves, labels on top of all
    parts.append("</svg>")
    return "".join(parts)


def stage_legend() -> str:
    """Shapes and words, so colour is never the only key."""
    shapes = {"node": "pill", "topic": "box", "service": "hexagon", "action": "double box"}
    chips = "".join(
        f'<span style="background:{fill};border:1px solid {stroke};'
        f"border-radius:{'10' if kind == 'node' else '2'}px;padding:1px 6px;margin-right:6px;"
        f'color:#111">{kind} ({shapes[kind]})</span>'
        for kind, (fill, stroke, _r) in STYLE.items()
    )
    return (
        f'<div style="font-family:sans-serif;font-size:12px;line-height:1.9">{chips}<br>'
        "publisher → topic → subscriber; server → service/action; dashed: client. "
        "Blue dots are messages, at the rate written on the edge.</div>"
    )
