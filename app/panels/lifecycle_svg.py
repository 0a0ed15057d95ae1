"""The managed-node state machine as an SVG: states lit, valid transitions clickable.

The four primary states sit in a row (finalized below them); each transition
is an edge that passes through its transition state (configuring, activating,
...), as in the design article of ROS 2 managed nodes. Forward edges arc over
the row, backward ones under it, and every shutdown edge meets in
shuttingdown on its way to finalized. ``link(label, svg, title)`` wraps an
edge the node offers right now in something clickable; the others stay grey.
"""

from __future__ import annotations

import html
from collections.abc import Callable, Collection
from dataclasses import dataclass

WIDTH, HEIGHT = 460, 410
BOX_W, BOX_H = 110, 40
ROW_Y = 150  # top of the primary-state row
LIT = "#2f9e44"  # the current state
BUSY = "#f08c00"  # the current transition state
LIVE = "#1c7ed6"  # an edge that can be clicked now
DEAD = "#adb5bd"
INK = "#343a40"

Link = Callable[[str, str, str], str]  # (transition label, svg inside, title) -> svg


@dataclass(frozen=True)
class Edge:
    transition: str  # the label `ros2 lifecycle set` takes
    start: str
    via: str  # the transition state passed on the way
    path: str  # SVG path data
    pill: tuple[float, float]  # centre of the transition state's pill
    label: tuple[float, float, str]  # x, y, text-anchor of the clickable label


BOXES = {  # primary state -> (x, y) of its box's top-left corner
    "unconfigured": (10, ROW_Y),
    "inactive": (175, ROW_Y),
    "active": (340, ROW_Y),
    "finalized": (175, 352),
}
_BOTTOM = ROW_Y + BOX_H
EDGES = (
    Edge("configure", "unconfigured", "configuring",
         f"M100,{ROW_Y} Q147,80 195,{ROW_Y}", (147, 115), (147, 92, "middle")),
    Edge("activate", "inactive", "activating",
         f"M265,{ROW_Y} Q312,80 360,{ROW_Y}", (312, 115), (312, 92, "middle")),
    Edge("cleanup", "inactive", "cleaningup",
         f"M195,{_BOTTOM} Q147,260 100,{_BOTTOM}", (147, 225), (147, 258, "middle")),
    Edge("deactivate", "active", "deactivating",
         f"M360,{_BOTTOM} Q312,260 265,{_BOTTOM}", (312, 225), (312, 258, "middle")),
    Edge("shutdown", "unconfigured", "shuttingdown",
         f"M30,{_BOTTOM} L30,320 L188,320", (230, 320), (36, 300, "start")),
    Edge("shutdown", "inactive", "shuttingdown",
         f"M230,{_BOTTOM} L230,309", (230, 320), (236, 290, "start")),
    Edge("shutdown", "active", "shuttingdown",
         f"M430,{_BOTTOM} L430,320 L272,320", (230, 320), (424, 300, "end")),
)  # fmt: skip
GOALS = {"configure": "inactive", "activate": "active", "cleanup": "unconfigured",
         "deactivate": "inactive", "shutdown": "finalized"}  # fmt: skip
PILLS = {edge.via: edge.pill for edge in EDGES} | {"errorprocessing": (70, 378)}


def _text(x: float, y: float, text: str, **style: str) -> str:
    attrs = " ".join(f'{k.replace("_", "-")}="{v}"' for k, v in style.items())
    return f'<text x="{x}" y="{y}" {attrs}>{html.escape(text)}</text>'


def _box(state: str, current: str | None) -> str:
    x, y = BOXES[state]
    lit = state == current
    fill, ink = (LIT, "white") if lit else ("white", INK)
    return (
        f'<rect x="{x}" y="{y}" width="{BOX_W}" height="{BOX_H}" rx="8" fill="{fill}" '
        f'stroke="{LIT if lit else INK}" stroke-width="2"/>'
        + _text(x + BOX_W / 2, y + 25, state, text_anchor="middle", fill=ink,
                font_size="14", font_weight="bold" if lit else "normal")
    )  # fmt: skip


def _pill(state: str, current: str | None) -> str:
    cx, cy = PILLS[state]
    lit = state == current
    dashed = ' stroke-dasharray="4 3"' if state == "errorprocessing" else ""
    fill, ink = (BUSY, "white") if lit else ("#f8f9fa", "#495057")
    return (  # clicks pass through a pill to the edge it sits on
        f'<g pointer-events="none"><rect x="{cx - 44}" y="{cy - 10}" width="88" height="20" '
        f'rx="10" fill="{fill}" stroke="{BUSY if lit else DEAD}"{dashed}/>'
        + _text(cx, cy + 4, state, text_anchor="middle", fill=ink, font_size="11",
                font_style="italic")
        + "</g>"
    )  # fmt: skip


def _edge(edge: Edge, live: bool, link: Link) -> str:
    colour = LIVE if live else DEAD
    x, y, anchor = edge.label
    drawn = (
        f'<path d="{edge.path}" fill="none" stroke="{colour}" '
        f'stroke-width="{3 if live else 1.5}" marker-end="url(#{"live" if live else "dead"})"/>'
        + _text(x, y, edge.transition, text_anchor=anchor, fill=colour, font_size="13",
                font_weight="bold" if live else "normal",
                text_decoration="underline" if live else "none")
    )  # fmt: skip
    if not live:
        return drawn
    # A wide invisible stroke makes the whole edge easy to hit, not just its hairline.
    target = f'<path d="{edge.path}" fill="none" stroke="transparent" stroke-width="16"/>'
    title = f"{edge.transition}: {edge.start} → {edge.via} → {GOALS[edge.transition]}"
    clickable = link(edge.transition, target + drawn, title)
    return f'<g class="live-edge" style="cursor:pointer">{clickable}</g>'


def draw_state_machine(current: str | None, available: Collection[str], link: Link) -> str:
    """The whole machine; ``available`` are the transition labels the node offers now.

    A shutdown edge is live only from the state the node is in: all three
    carry the same label, and the node picks the one matching its state.
    """
    primary = current if current in BOXES else None
    edges = [
        _edge(e, e.transition in available and (e.transition != "shutdown" or e.start == primary),
              link)
        for e in EDGES
    ]  # fmt: skip
    arrowheads = "".join(
        f'<marker id="{name}" viewBox="0 0 10 10" refX="9" refY="5" markerUnits="userSpaceOnUse" '
        f'markerWidth="9" markerHeight="9" orient="auto-start-reverse">'
        f'<path d="M0,0 L10,5 L0,10 z" '
        f'fill="{colour}"/></marker>'
        for name, colour in (("live", LIVE), ("dead", DEAD))
    )
    finalize = f'<path d="M230,330 L230,{BOXES["finalized"][1]}" stroke="{DEAD}" fill="none" '
    finalize += 'stroke-width="1.5" marker-end="url(#dead)"/>'
    # With no node (or none in a state), nothing is blue: say what makes edges clickable.
    said = (
        ("Click a blue edge to take that transition; italic names are the transition",
         "states a node passes through on the way.")
        if primary
        else ("No node's state yet: once it has one, its transitions turn blue; italic names",
              "are the transition states.")
    )  # fmt: skip
    note = "".join(
        _text(10, y, line, fill="#495057", font_size="12")
        for y, line in zip((30, 46), said, strict=True)
    )
    return (
        f'<svg viewBox="0 0 {WIDTH} {HEIGHT}" width="100%" role="img" '
        f'aria-label="Lifecycle state machine, current state {html.escape(current or "unknown")}" '
        'style="font-family:sans-serif;max-width:520px">'
        f"<defs>{arrowheads}</defs>{note}"
        + "".join(edges)
        + finalize
        + "".join(_pill(state, current) for state in PILLS)
        + "".join(_box(state, primary) for state in BOXES)
        + _text(70, 398, "(a failing callback)", text_anchor="middle", fill="#868e96",
                font_size="10")
        + "</svg>"
    )  # fmt: skip
