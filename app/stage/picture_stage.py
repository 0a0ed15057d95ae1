"""A step's diagram on stage, as large as the stage: for a step about an idea, not a
live thing (lesson 1's layers under a node). The lesson gives the picture of each
step; a learner who picks "This step's diagram" on a step without one is told so.
"""

from __future__ import annotations

import viser

from app.ros.graph import GraphSnapshot

NO_PICTURE = (
    '<p style="padding:8px 12px">This step has no diagram. Pick another view in '
    "<b>On stage</b>.</p>"
)


class PictureStage:
    def __init__(self, gui: viser.GuiApi) -> None:
        self._box = gui.add_folder("This step's diagram", expand_by_default=True, visible=False)
        with self._box:
            self._picture = gui.add_html(NO_PICTURE)

    def set_picture(self, html: str) -> None:
        """The current step's picture as HTML (app.lessons.panel.picture_html); '' for none."""
        wanted = html or NO_PICTURE
        if self._picture.content != wanted:
            self._picture.content = wanted

    def set_active(self, active: bool) -> None:
        self._box.visible = active

    def refresh(self, graph: GraphSnapshot) -> None:
        """A still picture: nothing to update."""

    def close(self) -> None:
        pass
