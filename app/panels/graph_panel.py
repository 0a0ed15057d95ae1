"""Graph panel: the nodes and topics on the live ROS graph (`ros2 node list`, `ros2 topic list`)."""

from __future__ import annotations

import viser

from app.graph import GraphSnapshot
from app.panels import MarkdownView


class GraphPanel:
    def __init__(self, gui: viser.GuiApi) -> None:
        self._view = MarkdownView(gui, "Waiting for the first look at the graph…")

    def refresh(self, graph: GraphSnapshot | None) -> None:
        if graph is None:
            return
        parts = [f"**Nodes ({len(graph.nodes)})** · `ros2 node list`", ""]
        parts += [f"- `{name}`" for name in graph.nodes] or ["- (none)"]
        parts += ["", f"**Topics ({len(graph.topics)})** · `ros2 topic list -t`", ""]
        parts += ["| topic | type | pub | sub |", "|---|---|---|---|"]
        for topic in graph.topics:
            parts.append(
                f"| `{topic.name}` | {', '.join(topic.types)} "
                f"| {topic.publishers} | {topic.subscribers} |"
            )
        self._view.show("\n".join(parts))
