"""Browser panels, one concept each. A panel owns its viser handles and callbacks.

The dashboard calls ``refresh(graph)`` on every panel a few times a second
from one UI thread; a panel updates a handle only when its content changed.
"""

from __future__ import annotations

from typing import Protocol

from app.graph import GraphSnapshot


class Panel(Protocol):
    def refresh(self, graph: GraphSnapshot) -> None: ...


class MarkdownView:
    """A markdown handle that is re-sent only when its text changes."""

    def __init__(self, gui, content: str = "", **kwargs) -> None:
        self._content = content
        self.handle = gui.add_markdown(content, **kwargs)

    def show(self, content: str) -> None:
        if content != self._content:
            self._content = content
            self.handle.content = content


def code_block(lines: list[str], empty: str = "(nothing yet)") -> str:
    body = "\n".join(lines) if lines else empty
    return f"```\n{body}\n```"
