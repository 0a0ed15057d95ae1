"""The lifecycle state machine on stage: the node's current state lit, the transitions it
offers now in blue, clickable (the Lifecycle tool's own drawing, without its buttons).

The lifecycle lesson's evidence: each step's button moves the node, and the
stage shows where it went, what it publishes now and its log.
"""

from __future__ import annotations

import viser
from rclpy.node import Node

from app.panels.lifecycle_panel import LifecyclePanel
from app.ros.graph import GraphSnapshot
from app.ros.rosout import RosoutLog
from app.ui.loop import UiLoop
from app.ui.page_links import PageLinks


class LifecycleStage:
    def __init__(
        self, gui: viser.GuiApi, ui: UiLoop, node: Node, rosout: RosoutLog, links: PageLinks
    ) -> None:
        self._active = False
        self._box = gui.add_folder("Lifecycle states", expand_by_default=True, visible=False)
        with self._box:
            self._panel = LifecyclePanel(
                gui, ui, node, rosout, links, link_prefix="stage.lifecycle", buttons=False
            )

    def set_active(self, active: bool) -> None:
        self._active = active
        self._box.visible = active
        if not active:
            self._panel.release()  # no subscription for a drawing nobody sees

    def refresh(self, graph: GraphSnapshot) -> None:
        if self._active:
            self._panel.refresh(graph)

    def close(self) -> None:
        self._panel.close()
