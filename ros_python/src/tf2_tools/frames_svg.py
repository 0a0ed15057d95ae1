"""Draw view_frames' tree as SVG, without graphviz.

Upstream renders its ``.gv`` file with graphviz's ``dot -Tpdf``. Graphviz is
a system package we do not require, and a browser shows SVG natively, so the
picture is laid out here: one row per depth, leaves spread evenly, each
parent centred over its children, each edge labelled as upstream labels it.
"""

from __future__ import annotations

from html import escape
from typing import Any

NODE_W, ROW_H, LABEL_LINES = 250, 170, 5


def _label(data: dict[str, Any]) -> list[str]:
    return [
        f"Broadcaster: {data.get('broadcaster', '')}",
        f"Average rate: {data.get('rate', '')}",
        f"Buffer length: {data.get('buffer_length', '')}",
        f"Most recent transform: {data.get('most_recent_transform', '')}",
        f"Oldest transform: {data.get('oldest_transform', '')}",
    ]


def layout(frames: dict[str, dict[str, Any]]) -> dict[str, tuple[float, float]]:
    """(x, y) centre of every frame: roots on top, children below their parent."""
    children: dict[str, list[str]] = {}
    for child, data in frames.items():
        children.setdefault(str(data["parent"]), []).append(str(child))
    names = set(children) | {str(c) for c in frames}
    roots = sorted(n for n in names if n not in frames) or sorted(names)[:1]
    pos: dict[str, tuple[float, float]] = {}
    next_leaf = [0]

    def place(name: str, depth: int, seen: set[str]) -> float:
        kids = [k for k in sorted(children.get(name, [])) if k not in seen]
        seen.add(name)
        if not kids:
            x = next_leaf[0] * NODE_W + NODE_W / 2
            next_leaf[0] += 1
        else:
            xs = [place(k, depth + 1, seen) for k in kids]
            x = (min(xs) + max(xs)) / 2
        pos[name] = (x, depth * ROW_H + 40)
        return x

    seen: set[str] = set()
    for root in roots:
        place(root, 0, seen)
    for name in sorted(names - set(pos)):  # frames caught in a loop: a row of their own
        place(name, 0, seen)
    return pos


def render(frames: dict[str, dict[str, Any]], recorded_time: float) -> str:
    """The whole picture as an SVG document."""
    if not frames:
        return (
            '<svg xmlns="http://www.w3.org/2000/svg" width="300" height="60">'
            '<text x="150" y="35" text-anchor="middle" font-family="sans-serif">'
            "No tf data received</text></svg>\n"
        )
    pos = layout(frames)
    width = max(x for x, _ in pos.values()) + NODE_W / 2 + 20
    width = max(width, 420)
    height = max(y for _, y in pos.values()) + 70
    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0f}" height="{height:.0f}" '
        'font-family="sans-serif" font-size="11">',
        f'<text x="10" y="{height - 12:.0f}" font-weight="bold">view_frames Result - '
        f"Recorded at time: {recorded_time}</text>",
    ]
    for child, data in frames.items():
        (x1, y1), (x2, y2) = pos[str(data["parent"])], pos[str(child)]
        out.append(
            f'<line x1="{x1:.1f}" y1="{y1 + 16:.1f}" x2="{x2:.1f}" y2="{y2 - 16:.1f}" '
            'stroke="black" marker-end="url(#arrow)"/>'
        )
        for k, line in enumerate(_label(data)):
            out.append(  # in the child's own column: sibling labels never overlap
                f'<text x="{x2 - NODE_W / 2 + 12:.1f}" y="{(y1 + y2) / 2 - 30 + 13 * k:.1f}" '
                f'font-size="9" fill="#333">{escape(line)}</text>'
            )
    for name, (x, y) in pos.items():
        out.append(
            f'<ellipse cx="{x:.1f}" cy="{y:.1f}" rx="{NODE_W / 2 - 15}" ry="16" '
            'fill="white" stroke="black"/>'
        )
        out.append(f'<text x="{x:.1f}" y="{y + 4:.1f}" text-anchor="middle">{escape(name)}</text>')
    out.insert(
        1,
        '<defs><marker id="arrow" markerWidth="10" markerHeight="7" refX="9" refY="3.5" '
        'orient="auto"><polygon points="0 0, 10 3.5, 0 7"/></marker></defs>',
    )
    out.append("</svg>\n")
    return "\n".join(out)
