"""The page a browser gets while ``serve`` is still building the dashboard.

Most of a cold start is Python importing (rclpy, the lessons, the exercises,
the tools) and joining ROS; most of a page's first second is the browser
loading viser's client (unpacking and compiling its script, setting up WebGL,
in software where there is no GPU). ``serve`` (app/cli.py) therefore starts
its web server before those imports and says the page's address at once: a
browser opened then does its part while the dashboard is built, on another
core, and is sent the dashboard as it is built. Until the dashboard is whole
the page shows one line saying it is on its way, in the dashboard's theme (no
flash of viser's own title bar). The line that says the dashboard "is ready"
still comes when it is whole: scripts and tests wait for that one.
"""

from __future__ import annotations

import viser

# What the page says meanwhile; clients that wait for the whole dashboard (benchmarks)
# wait until no widget says it.
OPENING_WORDS = "is starting: the lesson appears in a moment"


def configure_theme(gui: viser.GuiApi) -> None:
    """The dashboard's look: no title bar, logo or share button; a wide column."""
    gui.configure_theme(
        titlebar_content=None, control_width="large", show_share_button=False, show_logo=False
    )


class Opening:
    """The one line a page shows until the dashboard is built; ``done()`` takes it away."""

    def __init__(self, server: viser.ViserServer) -> None:
        configure_theme(server.gui)
        self._note = server.gui.add_markdown(f"**ROS 2 Classroom** {OPENING_WORDS}…")

    def done(self) -> None:
        self._note.remove()
