"""Open in Foxglove: the dashboard's live graph served to Foxglove or Lichtblick.

A folder of the Bags tool. The server (``app.foxglove.bridge``) starts on the
learner's click, never before (an idle dashboard pays nothing for it), on
127.0.0.1 only: Foxglove's desktop app on the same computer connects; the
dashboard never opens a port to other machines by itself. A recorded bag or a
graded attempt needs no server: its ``.mcap`` file opens in Foxglove as is.

Threads: starting and stopping are jobs (binding a port, ending the bridge's
thread); the UI thread owns ``_bridge`` and reads the bridge's counts.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import viser
from rclpy.node import Node

from app.ros.graph import GraphSnapshot
from app.ui import MarkdownView
from app.ui.loop import UiLoop

if TYPE_CHECKING:  # imported on the first click: the SDK's start-up is not the dashboard's
    from app.foxglove.bridge import FoxgloveBridge

PORTS = (8765, 0)  # Foxglove's usual port; when it is taken, any free one
OFF = (
    "See this session in **Foxglove** (or Lichtblick), the tools many robotics teams use: "
    "**Open in Foxglove** starts a Foxglove WebSocket server for the live graph. A recorded "
    "bag or a graded attempt (`attempts/` in your bags folder) is an `.mcap` file: open it "
    "in Foxglove as a file, no server needed."
)


def _start(node: Node) -> FoxgloveBridge:
    """A bridge on the first port of ``PORTS`` it can have."""
    from app.foxglove.bridge import FoxgloveBridge

    failure: Exception | None = None
    for port in PORTS:
        bridge = FoxgloveBridge(node, host="127.0.0.1", port=port)
        try:
            bridge.start()
            return bridge
        except Exception as exc:  # the port is taken: the next one
            failure = exc
    raise RuntimeError(f"no port for the Foxglove server: {failure}")


class FoxgloveSection:
    def __init__(self, gui: viser.GuiApi, ui: UiLoop, node: Node) -> None:
        self._ui, self._node = ui, node
        self._bridge: FoxgloveBridge | None = None
        self._busy = False
        with gui.add_folder("Open in Foxglove", expand_by_default=False):
            self._text = MarkdownView(gui, OFF)
            self._open = gui.add_button("Open in Foxglove", icon=viser.Icon.EXTERNAL_LINK)
            self._close = gui.add_button(
                "Stop the Foxglove server", icon=viser.Icon.PLAYER_STOP, visible=False
            )
            self._status = MarkdownView(gui, "")
        self._open.on_click(ui.callback(self._on_open))
        self._close.on_click(ui.callback(self._on_close))

    def _on_open(self) -> None:
        if self._bridge is not None or self._busy:
            return
        self._busy = True
        self._status.show("Starting the Foxglove server…")

        def started(bridge: FoxgloveBridge) -> None:
            self._busy = False
            self._bridge = bridge
            self._text.show(
                f"Serving this dashboard's ROS graph at **`{bridge.url}`**. In Foxglove: "
                "**Open connection › Foxglove WebSocket**, paste that address, **Open**. "
                "Topics arrive as ROS 2 messages with their definitions; a Teleop panel "
                "publishing on `/cmd_vel` drives the simulated robot."
            )
            self._open.visible, self._close.visible = False, True

        def failed(text: str) -> None:
            self._busy = False
            self._status.show(f"✗ The Foxglove server did not start: {text}")

        self._ui.run_job(lambda: _start(self._node), started, failed)

    def _on_close(self) -> None:
        bridge = self._bridge
        if bridge is None or self._busy:
            return
        self._busy = True

        def stopped(_none: None) -> None:
            self._busy = False
            self._bridge = None
            self._text.show(OFF)
            self._status.show("The Foxglove server is stopped.")
            self._open.visible, self._close.visible = True, False

        def failed(text: str) -> None:
            self._busy = False
            self._status.show(f"⚠ {text}")

        self._ui.run_job(bridge.close, stopped, failed)

    def refresh(self, graph: GraphSnapshot) -> None:
        bridge = self._bridge
        if bridge is None or self._busy:
            return
        counts = bridge.counts()
        self._status.show(
            f"{counts.channels} topics offered · {counts.subscriptions} watched by Foxglove · "
            f"{counts.forwarded} messages sent, {counts.published} received from it"
            + (f" · {counts.refused} refused" if counts.refused else "")
        )

    def close(self) -> None:
        if self._bridge is not None:
            self._bridge.close()
            self._bridge = None
