"""The stage window: one owner for what the centre of the screen shows.

The lesson names a stage for each step; the learner may pick another in the
"On stage" dropdown (the next step's choice replaces it). Each stage is one part
(its own module), picked by name from ``Stage.parts``: the live graph, turtlesim and
the TF tree are drawn in a window docked on the left; "code" shows the code window
and its output instead; "scene" hides them all so the 3D canvas has the room.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Protocol

import viser
from rclpy.node import Node

from app.ros.graph import GraphSnapshot
from app.ros.rates import SharedRates
from app.ros.rosout import RosoutLog
from app.stage import DEFAULT_STAGE, STAGES
from app.stage.bag_stage import BagStage
from app.stage.code_stage import CodeStage
from app.stage.graph_stage import GraphStage
from app.stage.image_stage import ImageStage
from app.stage.lifecycle_stage import LifecycleStage
from app.stage.picture_stage import PictureStage
from app.stage.plot_stage import PlotStage
from app.stage.replay_stage import ReplayStage
from app.stage.tf_stage import TfStage
from app.stage.turtlesim_stage import TurtlesimStage
from app.ui import assign
from app.ui.loop import UiLoop
from app.ui.page_links import PageLinks
from app.ui.page_script import listen_on_page, page_script

STAGE_WIDTH = 560  # until the browser says how wide its window is
# The control panel (lesson text, tools) floats on the right: ~65 characters a line of
# lesson text at viser's 14 px font, the 60-80 a reading column wants.
CONTROL_WIDTH = 480
PANEL_MARGIN = 14  # the floating control panel's gap to the window's edges
CONTROL_PANEL_ROOM = CONTROL_WIDTH + 28  # and its margins
MIN_WIDTH, MAX_WIDTH = 400, 3000  # up to the panel: no 3D scene peeks out between
REFIT_PX = 24  # a smaller change of the window is not worth moving the stage
WIDTH_RESENDS = (0.05, 0.5, 1.5)  # s after a stage change: its width again
# Runs in the page (app.ui.page_script): report the window's width now and after resizes.
_REPORT_WIDTH = (
    """
const url = new URL(%s, parent.location.href).href;
const report = () => fetch(url + '/' + Math.round(parent.innerWidth), {cache: 'no-store'})
  .catch(() => {});
let timer = 0;
const onResize = () => { clearTimeout(timer); timer = setTimeout(report, 150); };
"""
    + listen_on_page("__stageWidthOff", "resize", "onResize")
    + "report();\n"
)
# Drawn in the stage window: all but the code (its own windows) and the 3D scene (the canvas).
_IN_WINDOW = tuple(name for name in STAGES if name not in ("code", "scene"))

_TOAST_STYLE = (
    "<style>.mantine-Notifications-root{top:auto!important;bottom:12px!important;"
    "left:12px!important;right:auto!important;transform:none!important}</style>"
)
# Any stage but the 3D scene covers the canvas (but for a sliver beside the control
# panel), yet viser's canvas still drew every change of the scene: with the camera and
# arm running, 29 % of a core in the page for nothing seen (software WebGL, measured).
# Out of view, viser's in-view watch (an IntersectionObserver) stops its drawing; back,
# it draws at once. The wrapper is moved out of the window, shrunk and made invisible,
# not taken out of the layout: with display:none the watch missed the change on one or
# two pages of five in about half of issue 38's soaks (the MuJoCo world starting while
# they were open): they drew the hidden scene 400-700 times a second, Chromium's software
# GPU process went to 130 % of a core and every page waited seconds for a frame
# (tests/browser/test_stage.py). The element moved is viser's
# wrapper of three.js's canvas (data-engine="three.js ..."); a browser without CSS :has()
# (Firefox before 121) keeps drawing it, as before.
_CANVAS_OFF_STYLE = (
    "<style>div:has(> div > div > canvas[data-engine]){position:fixed!important;"
    "left:-300vw!important;top:0!important;width:8px!important;height:8px!important;"
    "visibility:hidden!important}</style>"
)


class StagePart(Protocol):
    """One thing the stage can show (the 3D scene needs none: it is the canvas)."""

    def set_active(self, active: bool) -> None: ...

    def refresh(self, graph: GraphSnapshot) -> None: ...

    def close(self) -> None: ...


class Stage:
    def __init__(
        self,
        gui: viser.GuiApi,
        ui: UiLoop,
        node: Node,
        code_window: viser.PanelHandle,
        rates: SharedRates | None,
        links: PageLinks,
        rosout: RosoutLog,
        starting: Callable[[], list[str]] = lambda: [],
        program_output: Callable[[], tuple[str, list[str]]] = lambda: ("", []),
        inspect: Callable[[str, str, str], None] = lambda _kind, _name, _type: None,
        open_tool: Callable[[str], None] = lambda _tool: None,
    ) -> None:
        """``rates``: measured once for the graph, the plot and the Graph tool (None: the
        stage measures its own); ``rosout``: the lifecycle drawing's log;
        ``starting``, ``inspect`` and ``open_tool``: see ``GraphStage``;
        ``program_output``: see ``CodeStage``."""
        self._ui = ui
        self._links = links
        self._code_window = code_window
        self._own_rates = rates is None  # a stage alone (no Graph tool): it measures itself
        rates = rates or SharedRates(node)
        self._rates = rates
        self.width = STAGE_WIDTH
        self._fitted = False
        self._widths_due: list[float] = []  # when to say the stage's width again
        self._main_panel: viser.MainPanelHandle | None = None  # placed by follow_window
        self.current = DEFAULT_STAGE
        by_label = {label: name for name, label in STAGES.items()}
        self._selector = gui.add_dropdown(
            "On stage", list(by_label), initial_value=STAGES[DEFAULT_STAGE]
        )
        self._selector.on_update(
            ui.callback(lambda: self.show(by_label.get(self._selector.value, self.current)))
        )
        # viser's toasts (e.g. "software WebGL") open at the canvas's top-left, which is
        # the control panel's edge once the stage fills the room: they would cover the
        # tabs. Bottom-left, over the stage's free space, they hide nothing one clicks.
        self._page_style = gui.add_html(_TOAST_STYLE)
        self._window = gui.add_panel()
        self._window.dock_left()
        self._window.set_width(STAGE_WIDTH)
        with self._window.add_tab("Stage", viser.Icon.PRESENTATION):
            self.graph = GraphStage(
                gui, ui, node, STAGE_WIDTH, rates.client(), links, starting, inspect, open_tool
            )
            self.plot = PlotStage(gui, rates.client())
            self.image = ImageStage(gui, node)
            self.lifecycle = LifecycleStage(gui, ui, node, rosout, links)
            self.bag = BagStage(gui, ui)
            self.replay = ReplayStage(gui, ui)
            self.turtlesim = TurtlesimStage(gui, ui, node, links)
            self.tf = TfStage(gui, node)
            self.picture = PictureStage(gui)
        # Under the code: what the learner's program printed (the exercise's output).
        self.code = CodeStage(gui, code_window, program_output)
        self.parts: dict[str, StagePart] = {
            "graph": self.graph,
            "plot": self.plot,
            "image": self.image,
            "lifecycle": self.lifecycle,
            "bag": self.bag,
            "replay": self.replay,
            "turtlesim": self.turtlesim,
            "tf": self.tf,
            "code": self.code,
            "picture": self.picture,
        }
        self.show(DEFAULT_STAGE)

    def follow_window(self, server: viser.ViserServer) -> None:
        """Size the stage to the browser's window: all the room the control panel leaves.

        The page reports its window's width through a page link when it loads
        and after each resize (the camera messages' canvas width cannot tell:
        it is the window minus whatever the docks were at that moment).
        """
        self._main_panel = server.gui.main_panel
        self._place_control_panel()
        href = self._links.register_value("stage.window", self._on_window_width)
        server.gui.add_html(page_script(_REPORT_WIDTH % json.dumps(href), "window width"))

    def _on_window_width(self, value: str) -> None:
        """The link's action (viser's asyncio thread): only checks and posts."""
        if value.isdigit() and len(value) <= 5:
            width = int(value)
            self._ui.post(lambda: self._fit(width))

    def _fit(self, window: int) -> None:
        wanted = max(MIN_WIDTH, min(MAX_WIDTH, window - CONTROL_PANEL_ROOM))
        if abs(wanted - self.width) >= REFIT_PX or not self._fitted:
            self._fitted = True
            self.width = wanted
            self._set_widths()
            self.graph.set_width(wanted)

    def _set_widths(self) -> None:
        for window in (self._window, self._code_window, self.code.output_window):
            window.set_width(self.width)

    def _place_control_panel(self) -> None:
        """The 3D scene on stage: the control panel docks on the right, so viser insets
        the canvas to the stage's area and centres the scene there (floating, the panel
        covered the canvas's right third). Any other stage: it floats beside the stage
        window, which takes all the room left of it."""
        if self._main_panel is None:
            return
        if self.current == "scene":
            self._main_panel.dock_right()
        else:
            self._main_panel.float(x=-PANEL_MARGIN, y=PANEL_MARGIN)
        self._main_panel.set_width(CONTROL_WIDTH)

    def show(self, stage: str) -> None:
        """Put ``stage`` on (an unknown name is ignored: lessons are validated at load)."""
        if stage not in STAGES:
            return
        self.current = stage
        assign(self._selector, STAGES[stage])
        style = _TOAST_STYLE + ("" if stage == "scene" else _CANVAS_OFF_STYLE)
        if self._page_style.content != style:
            self._page_style.content = style
        windows = [
            (self._window, stage in _IN_WINDOW),
            (self._code_window, stage == "code"),
            (self.code.output_window, stage == "code"),
        ]
        # Off first, then on: for a moment both docked on the left, the client squeezed
        # the newcomer to its 300 px default and kept it there (the graph in lessons 3-10
        # was a 300 px strip after the code stage of lesson 2).
        for window, on in sorted(windows, key=lambda pair: pair[1]):
            window.visible = on
        for name, part in self.parts.items():
            part.set_active(name == stage)
        # A window docked again takes the client's default width: give it the stage's,
        # and again a little later. The client applies a width only to a panel it has
        # placed, and a window just re-shown is placed a few frames on (seen once at
        # 2560 px: the graph left at the client's 300 px default after the code stage).
        self._set_widths()
        now = time.monotonic()
        self._widths_due = [now + delay for delay in WIDTH_RESENDS]
        self._place_control_panel()

    def show_step(self, stage: str, picture: str) -> None:
        """A lesson step: its stage on, and its picture (HTML, '' for none) for the
        diagram stage, the learner's to pick too."""
        self.picture.set_picture(picture)
        self.show(stage)

    def watch(self, bag: Path, heading: str = "") -> None:
        """Play the recording ``bag`` on stage (a graded attempt: its verdict as ``heading``)."""
        self.replay.open(bag, heading)
        self.show("replay")

    def forget(self) -> None:
        """A new lesson: its graph is laid out afresh, nothing inspected."""
        self.graph.forget()

    def refresh(self, graph: GraphSnapshot) -> None:
        if self._widths_due and time.monotonic() > self._widths_due[0]:
            self._widths_due.pop(0)
            self._set_widths()
        part = self.parts.get(self.current)
        if part is not None:
            part.refresh(graph)

    def close(self) -> None:
        for part in self.parts.values():
            part.close()
        if self._own_rates:
            self._rates.close()
