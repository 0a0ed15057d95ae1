"""The architecture picture of the docs, drawn from the code itself.

Reads the imports of ``app`` (grimp, the library import-linter is built on),
folds them to one box per package or top-level module, ranks the boxes so
that every import points down, and draws them as SVG. Imports that close a
circle cannot point down: they are drawn red and listed, so the picture
shows what is wrong with the house as well as its shape. The docs build
calls ``architecture_svg()`` through ``docs/hooks.py``; nothing is drawn by
hand, so the picture cannot go stale.

``python tools/architecture.py`` prints the boxes, their ranks and the
circles.
"""

from __future__ import annotations

import html
import sys
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

import grimp

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = "app"
BOX_W, BOX_H, GAP_X, GAP_Y, MARGIN = 128, 30, 14, 56, 16
# What each home is for, shown as the box's tooltip.
ROLES = {
    "ros": "the ROS layer: runtime, graph, monitor, rates, TF, calls, parameters, QoS",
    "bags": "rosbag2 files: record, info, play, repair",
    "ui": "what the browser front ends share: the UI thread, widgets, page links",
    "panels": "the tools: rqt- and rviz-like tabs",
    "scene": "the 3D view's drawing",
    "stage": "the left of the screen: graph, turtlesim, TF, code",
    "lessons": "lesson loading, checks, actions, the Lessons tab",
    "exercises": "exercises: files, runner, grader, probes, editor",
    "ros2cli": "the ros2 verbs (command line and Console)",
    "learner_ws": "the learner's colcon workspace",
    "containment": "learner code's rule (RunPolicy) and its sandbox",
    "teacher": "the teacher's view",
    "hub": "JupyterHub spawner and proxy",
    "dashboard": "wires server, runtime, supervisor, lessons",
    "cli": "the ros2-classroom command",
    "supervisor": "owns every node process",
}


@dataclass(frozen=True)
class House:
    boxes: list[str]  # short names, e.g. "ros", "dashboard"
    imports: set[tuple[str, str]]  # (importer, imported)
    rank: dict[str, int]  # 0 = bottom
    circles: list[list[str]]  # boxes that import each other, round and round


def _box(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[0] == PACKAGE else None


def read_house() -> House:
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    graph = grimp.build_graph(PACKAGE)
    imports: set[tuple[str, str]] = set()
    boxes: set[str] = set()
    for module in graph.modules:
        source = _box(module)
        if source is None:
            continue
        boxes.add(source)
        for imported in graph.find_modules_directly_imported_by(module):
            target = _box(imported)
            if target is not None and target != source:
                imports.add((source, target))
    circles = _circles(sorted(boxes), imports)
    return House(sorted(boxes), imports, _ranks(sorted(boxes), imports, circles), circles)


def _circles(boxes: list[str], imports: set[tuple[str, str]]) -> list[list[str]]:
    """Strongly connected groups of two or more boxes (Tarjan's algorithm)."""
    out = defaultdict(list)
    for a, b in imports:
        out[a].append(b)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in out[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                found.append(sorted(group))

    for v in boxes:
        if v not in index:
            visit(v)
    return found


def _ranks(
    boxes: list[str], imports: set[tuple[str, str]], circles: list[list[str]]
) -> dict[str, int]:
    """Longest path down to a box that imports nothing of ours; a circle shares one rank."""
    group_of = {box: box for box in boxes}
    for circle in circles:
        for box in circle:
            group_of[box] = circle[0]
    below: dict[str, set[str]] = defaultdict(set)
    for a, b in imports:
        if group_of[a] != group_of[b]:
            below[group_of[a]].add(group_of[b])
    rank: dict[str, int] = {}

    def height(group: str) -> int:
        if group not in rank:
            rank[group] = 1 + max((height(g) for g in below[group]), default=-1)
        return rank[group]

    return {box: height(group_of[box]) for box in boxes}


def architecture_svg(house: House | None = None) -> str:
    house = house or read_house()
    rows: dict[int, list[str]] = defaultdict(list)
    for box in house.boxes:
        rows[house.rank[box]].append(box)
    top = max(rows)
    widest = max(len(r) for r in rows.values())
    width = 2 * MARGIN + widest * BOX_W + (widest - 1) * GAP_X
    height = 2 * MARGIN + (top + 1) * BOX_H + top * GAP_Y
    where: dict[str, tuple[float, float]] = {}  # box -> its top-left corner
    for level, names in rows.items():
        row_w = len(names) * BOX_W + (len(names) - 1) * GAP_X
        x0 = (width - row_w) / 2
        y = MARGIN + (top - level) * (BOX_H + GAP_Y)
        for i, name in enumerate(sorted(names)):
            where[name] = (x0 + i * (BOX_W + GAP_X), y)
    in_circle = {box for circle in house.circles for box in circle}
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {width} {height}" '
        f'width="{width}" role="img" aria-label="The packages of app and their imports">',
        '<defs><marker id="arch-head" viewBox="0 0 8 8" refX="8" refY="4" markerWidth="7" '
        'markerHeight="7" orient="auto"><path d="M0,0 L8,4 L0,8 z" fill="#8a8a8a"/></marker>'
        '<marker id="arch-up" viewBox="0 0 8 8" refX="8" refY="4" markerWidth="7" '
        'markerHeight="7" orient="auto"><path d="M0,0 L8,4 L0,8 z" fill="#d32f2f"/></marker>'
        "</defs>",
    ]
    for a, b in sorted(house.imports):
        (ax, ay), (bx, by) = where[a], where[b]
        up = house.rank[b] >= house.rank[a]  # only a circle makes an import point sideways
        x1, y1 = ax + BOX_W / 2, ay + (BOX_H if not up else BOX_H / 2)
        x2, y2 = bx + BOX_W / 2, by + (0 if not up else BOX_H / 2)
        colour, head = ("#d32f2f", "arch-up") if up else ("#b0b0b0", "arch-head")
        parts.append(
            f'<line x1="{x1:.0f}" y1="{y1:.0f}" x2="{x2:.0f}" y2="{y2:.0f}" stroke="{colour}" '
            f'stroke-width="1" marker-end="url(#{head})"><title>{a} imports {b}</title></line>'
        )
    for name, (x, y) in where.items():
        fill = "#fdecea" if name in in_circle else "#e8f0fe"
        role = html.escape(ROLES.get(name, f"app.{name}"))
        parts.append(
            f'<g><title>app.{name}: {role}</title><rect x="{x:.0f}" y="{y:.0f}" width="{BOX_W}" '
            f'height="{BOX_H}" rx="6" fill="{fill}" stroke="#5f6368"/>'
            f'<text x="{x + BOX_W / 2:.0f}" y="{y + BOX_H / 2 + 5:.0f}" text-anchor="middle" '
            f'font-family="sans-serif" font-size="13">{name}</text></g>'
        )
    parts.append("</svg>")
    return "".join(parts)


def circles_markdown(house: House | None = None) -> str:
    house = house or read_house()
    if not house.circles:
        return "No two homes of `app` import each other."
    lines = ["Homes that import each other (drawn red), to be untangled:", ""]
    lines += [f"- {' ↔ '.join(f'`app.{box}`' for box in circle)}" for circle in house.circles]
    return "\n".join(lines)


def main() -> None:
    house = read_house()
    for box in sorted(house.boxes, key=lambda b: (-house.rank[b], b)):
        print(f"{house.rank[box]:2d}  app.{box}")
    print(circles_markdown(house))


if __name__ == "__main__":
    main()
