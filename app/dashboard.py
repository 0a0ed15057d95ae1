"""Wires the web server, the ROS runtime, the supervisor and the panels. Nothing else.

The dashboard owns the UI thread (see the threading model in app.ui): it
applies posted intents, takes a graph snapshot, and refreshes every panel.
"""

from __future__ import annotations

import json
import logging
import os
import threading
import time
from collections.abc import Callable
from functools import partial
from typing import TYPE_CHECKING, cast

import viser

from app.catalog import UnknownNodeError, lookup
from app.exercises.attempts import AttemptStore, attempts_root
from app.exercises.editor_server import EditorHub
from app.exercises.grader import Grader
from app.exercises.model import load_exercises
from app.exercises.panel import ExercisePanel, ExerciseSettings
from app.exercises.workspace import Workspace
from app.lessons.panel import LessonsPanel
from app.lessons.progress import ProgressStore
from app.lessons.runtime import LessonRuntime
from app.lessons.schema import load_course
from app.panels.scene_panel import ScenePanel
from app.ros.graph import GraphSnapshot, snapshot
from app.ros.rates import SharedRates
from app.ros.rosout import RosoutLog
from app.ros.runtime import RosRuntime
from app.scene.grid import add_floor_grid
from app.scene.point_shader import keep_point_shader
from app.stage.window import Stage
from app.supervisor import NodeState, Supervisor
from app.ui import GROUP_OF, TAB_NAMES, TOOL_GROUPS, TOOLS, Inspector, MarkdownView, Panel
from app.ui.loop import FullPasses, HiddenPasses, UiLoop
from app.ui.opening import configure_theme
from app.ui.page_fixes import page_fixes_html
from app.ui.page_links import PageLinks, link_sender_html
from app.ui.page_script import page_script
from app.ui.shown_tools import ShownTools
from app.ui.starting import StartRequests
from app.ui.tab_opener import TabOpener

if TYPE_CHECKING:
    from app.ros2cli.console_panel import ConsolePanel

log = logging.getLogger(__name__)

# Tools built as the dashboard starts: the one a page opens on, the exercise (its code
# sits beside the lesson's) and the 3D view, which draws into the scene every page
# shows. The others are built when a page first shows them (app.ui.shown_tools) or the
# dashboard opens them: a first page then carries 123 fewer widgets (204 of 327).
EAGER_TOOLS = frozenset({"Lessons", "Exercise", "3D view"})

UI_PERIOD_SEC = 0.2  # panels refresh at 5 Hz
# ...and within 20 ms of a node joining or leaving when this dashboard started or
# stopped it: the supervisor tells the loop, which then looks at the node list every
# GRAPH_CHECK_SEC for GRAPH_BURST_SEC (a node joins once its Python has imported rclpy).
# Otherwise (a node started elsewhere) a look at each refresh. Looking every 20 ms all
# the time cost an idle dashboard with a browser about 0.9 % of a core (measured).
# (rclpy has no graph-change event to wait on, and ROS's own discovery topic,
# "ros_discovery_info", has a name rcl cannot subscribe to: rcl makes it "/ros_...".)
GRAPH_CHECK_SEC = 0.02
GRAPH_BURST_SEC = 3.0
# With no browser connected nobody sees a frame: checks and progress still move on, once
# a second, at a tenth of the idle cost (a class's dashboards idle while learners are away).
UNWATCHED_PERIOD_SEC = 1.0
UNWATCHED_CHECK_SEC = 0.5
# While nothing happens, the graph is asked for and the calm panels refreshed once a
# second (app.ui.loop.FullPasses): at every pass, those two were three quarters of the
# UI thread's work on an idle lesson with a talker and listener (measured: 0.25 s and
# 0.33 s of CPU each 30 s, of 0.68 s).
CALM_PERIOD_SEC = 1.0
# A tool no page shows (app.ui.shown_tools) is refreshed this often while nothing happens,
# and at every pass after something did: it keeps up, but nobody waits for it. Refreshing
# the hidden tools as the shown ones were most of the UI thread's idle work (measured,
# bench/results/findings.md).
HIDDEN_PERIOD_SEC = 5.0
# Runs in the page (app.ui.page_script): what the address asks to open, reported once per
# page load to the page link of its kind (values the links take: a-z, 0-9, '_', '.', '-').
_OPEN_FROM_ADDRESS = """
const links = %s;
const asked = new URLSearchParams(parent.location.search);
for (const [key, link] of Object.entries(links)) {
  const value = asked.get(key);
  if (value && /^[a-z0-9_.-]{1,80}$/.test(value)) {
    fetch(new URL(link + '/' + value, parent.location.href).href, {cache: 'no-store'})
      .catch(() => {});
  }
}
"""


class Dashboard:
    def __init__(
        self,
        server: viser.ViserServer,
        runtime: RosRuntime,
        supervisor: Supervisor,
        progress: ProgressStore,
        editor_hub: EditorHub,
        workspace: Workspace,
        exercise_settings: ExerciseSettings | None = None,
        page_links: PageLinks | None = None,
    ):
        self.server = server
        self.runtime = runtime
        self.supervisor = supervisor
        self.progress = progress
        self.editor_hub = editor_hub
        self.workspace = workspace
        self.exercise_settings = exercise_settings or ExerciseSettings()
        # Clickable drawings; unless the server was built with these links, they answer 404.
        self.page_links = page_links or PageLinks()
        self.exercises = load_exercises()
        self.ui = UiLoop()
        self.lessons = LessonRuntime(runtime.node, supervisor)
        self.rosout = RosoutLog(runtime.node)
        self._look_until = 0.0  # time.monotonic() until which the node list is looked at often
        supervisor.on_change(self._graph_may_change)
        self._stop = threading.Event()
        self.start_requests = StartRequests()  # Start clicks the stage shows at once
        self._lesson_since = time.time()  # when the current lesson was opened (UI thread)
        self._lesson_programs: frozenset[str] = frozenset()  # what its buttons start
        self.graph = GraphSnapshot()
        self._tools: dict[str, Panel] = {}  # the tools built so far, by tab name
        self._tool_tabs: dict[str, viser.GuiTabHandle] = {}
        self._placeholders: dict[str, viser.GuiMarkdownHandle] = {}  # until a tool is built
        self._tools_failed: set[str] = set()
        self._inspected: tuple[str, str, str] | None = None  # the box last clicked on stage
        self._panels: list[Panel] = []  # what the UI thread refreshes: the stage, built tools
        # What the pages show: the first group's first tool until a page says.
        first = next(iter(TOOL_GROUPS.values()))[0]
        self._shown = ShownTools([*TOOL_GROUPS, *TAB_NAMES], frozenset({first}), self.ui.wake)
        self._build_gui()
        self._ui_thread = threading.Thread(target=self._ui_loop, name="ui-refresh", daemon=True)

    def _build_gui(self) -> None:
        gui, ui, node = self.server.gui, self.ui, self.runtime.node
        configure_theme(gui)  # as the page serve shows while this is built (app.ui.opening)
        gui.add_html(page_fixes_html())  # contrast and button names viser leaves out
        gui.add_html(link_sender_html())  # clicks on links in drawings (graph, lifecycle)
        gui.add_html(  # which tools the page shows: the others are refreshed less often
            self._shown.script_html(self.page_links.register_value("shown", self._shown.report))
        )
        # Both cost a lot where WebGL runs in software (no GPU: headless
        # browsers, many classroom VMs). The shadow pass of the arm on the grid
        # alone stalled the page ~100 ms on every redraw (measured; findings.md).
        self.server.scene.configure_environment_map(None)
        self.server.scene.configure_default_lights(cast_shadow=False)
        add_floor_grid(self.server.scene)  # 4 m, half-metre cells: see app/scene/grid.py
        keep_point_shader(self.server.scene)  # no recompile per scan: app/scene/point_shader.py
        # One line: where am I (the domain learners compare when two dashboards share a room).
        gui.add_markdown(
            f"**ROS 2 Classroom** · Domain id **{os.environ.get('ROS_DOMAIN_ID', '0')}** · "
            "node `/classroom_dashboard`"
        )
        self.notice = MarkdownView(gui)  # in a classroom: the teacher's latest message
        # One window docked on the left: the lesson's code and the learner's own.
        side_window = gui.add_panel()
        side_window.dock_left()
        side_window.set_width(560)
        opener = TabOpener(gui, {name: [GROUP_OF[name], name] for name in TAB_NAMES})
        # The stage: what the current step is about (the live graph, ...), chosen by the lesson.
        self._rates = SharedRates(node)  # the stage and the Graph tab measure a topic once
        stage = Stage(
            gui,
            ui,
            node,
            side_window,
            self._rates,
            self.page_links,
            self.rosout,
            starting=self._starting_nodes,
            program_output=self._program_output,
            inspect=self._inspect,
            open_tool=self._open_tool,
        )
        stage.follow_window(self.server)
        self._stage = stage
        self._panels.append(stage)
        # The current step, read top to bottom: its text, buttons, checks, Back and Next;
        # above the tools, so it stays where it is whichever tool is open.
        position = MarkdownView(gui)  # "Lesson 4 of 22 · Step 1 of 6", above the card
        step_card = gui.add_folder("This step")
        builders: dict[str, Callable[[], Panel]] = {
            "Lessons": lambda: LessonsPanel(
                gui,
                ui,
                load_course(),
                self.lessons,
                self.progress,
                side_window,
                self._exercise_marks,
                stage.show_step,
                step_card=step_card,
                open_tool=self._open_tool,
                start_requests=self.start_requests,
                new_lesson=self._new_lesson,
                position=position,
                # The column's top: any tab always in it finds the column (the first group).
                to_top=lambda: opener.scroll_to_top(next(iter(TOOL_GROUPS))),
                atomic=self.server.atomic,
            ),
            "Exercise": lambda: ExercisePanel(
                gui,
                ui,
                self.exercises,
                self.workspace,
                self.supervisor,
                Grader(node, self.supervisor, AttemptStore(attempts_root())),
                self.editor_hub,
                side_window,
                self.exercise_settings,
                open_code=lambda: stage.show("code"),
                watch=stage.watch,
            ),
            "3D view": lambda: ScenePanel(self.server, ui, node),
            **self._lazy_builders(),
        }
        assert set(builders) == set(TAB_NAMES), "every tool lessons may name has a panel"
        self._builders = builders
        # Tools grouped as a learner thinks of them: a tab per group, a tab per tool inside.
        # The tools of EAGER_TOOLS are built now; the others when first shown or used.
        groups = gui.add_tab_group()
        for group, declared in TOOLS.items():
            with groups.add_tab(group, declared.icon):
                tools = gui.add_tab_group()
                for name, icon in declared.tools.items():
                    tab = tools.add_tab(name, icon)
                    self._tool_tabs[name] = tab
                    if name not in EAGER_TOOLS:
                        with tab:
                            self._placeholders[name] = gui.add_markdown(f"*Opening {name}…*")
        self._opener = opener
        for name in TAB_NAMES:
            if name in EAGER_TOOLS:
                self._tool(name)
        # A lesson's `console` buttons type their command into the Console tab.
        self.lessons.console = lambda command: self._console().run_for_lesson(command)
        self._open_from_address(opener)

    def _lazy_builders(self) -> dict[str, Callable[[], Panel]]:
        """How to build each tool that waits until a page shows it. Each imports its module
        only then (the warm parent of app.warm_start imports them all ahead)."""
        gui, ui, node = self.server.gui, self.ui, self.runtime.node

        def nodes() -> Panel:
            from app.panels.nodes_panel import NodesPanel

            return NodesPanel(gui, ui, self.supervisor, self.start_requests)

        def console() -> Panel:
            from app.ros2cli.console_panel import ConsolePanel

            return ConsolePanel(gui, ui, node, self.supervisor)

        def turtlesim() -> Panel:
            from app.panels.turtlesim_panel import TurtlesimPanel

            return TurtlesimPanel(gui, ui, node, self.supervisor, self.page_links)

        def graph() -> Panel:
            from app.panels.graph_panel import GraphPanel

            return GraphPanel(gui, node, self._rates.client())

        def tf() -> Panel:
            from app.panels.tf_panel import TfPanel

            return TfPanel(gui, ui, node, self.supervisor)

        def topics() -> Panel:
            from app.panels.topics_panel import TopicsPanel

            return TopicsPanel(gui, ui, node)

        def echo() -> Panel:
            from app.panels.echo_panel import EchoPanel

            return EchoPanel(gui, node)

        def logs() -> Panel:
            from app.panels.logs_panel import LogsPanel

            return LogsPanel(gui, self.rosout)

        def services() -> Panel:
            from app.panels.services_panel import ServicesPanel

            return ServicesPanel(gui, ui, node)

        def actions() -> Panel:
            from app.panels.actions_panel import ActionsPanel

            return ActionsPanel(gui, ui, node)

        def parameters() -> Panel:
            from app.panels.parameters_panel import ParametersPanel

            return ParametersPanel(gui, ui, node, self.rosout)

        def lifecycle() -> Panel:
            from app.panels.lifecycle_panel import LifecyclePanel

            return LifecyclePanel(gui, ui, node, self.rosout, self.page_links)

        def bags() -> Panel:
            from app.panels.bags_panel import BagsPanel

            return BagsPanel(gui, ui, node)

        return {
            "Nodes": nodes,
            "Console": console,
            "Turtlesim": turtlesim,
            "Graph": graph,
            "TF": tf,
            "Topics": topics,
            "Echo": echo,
            "Logs": logs,
            "Services": services,
            "Actions": actions,
            "Parameters": parameters,
            "Lifecycle": lifecycle,
            "Bags": bags,
        }

    def _tool(self, name: str) -> Panel:
        """The tool ``name``, built in its tab now if it was not yet (UI thread only)."""
        built = self._tools.get(name)
        if built is not None:
            return built
        started = time.monotonic()
        # In one piece: a page sees none of its widgets before all have their callbacks
        # (a click on a Start sent the moment it arrived was lost, under load).
        with self.server.atomic():
            with self._tool_tabs[name]:
                panel = self._builders[name]()
            placeholder = self._placeholders.pop(name, None)
            if placeholder is not None:
                placeholder.remove()
        self._tools[name] = panel
        self._panels.append(panel)
        if isinstance(panel, Inspector) and self._inspected is not None:
            # What the learner last clicked on the stage, once the tool knows the graph.
            panel.refresh(self.graph)
            panel.inspect(*self._inspected)
        log.debug("built the %s tool in %.3f s", name, time.monotonic() - started)
        return panel

    def _console(self) -> ConsolePanel:
        return cast("ConsolePanel", self._tool("Console"))

    def _open_tool(self, name: str) -> None:
        """Open a tool's tab on the pages (UI thread): built here, before the page asks."""
        if name in self._builders:
            self._tool(name)
        self._opener.open(name)

    def _build_asked_tools(self) -> None:
        """Build every tool a page has shown and that is not built yet (UI thread)."""
        asked = self._shown.asked()
        for name in TAB_NAMES:
            if name in self._tools or name in self._tools_failed:
                continue
            if name in asked:
                try:
                    self._tool(name)
                except Exception:  # one tool's bug leaves the others (and its tab) working
                    log.exception("building the %s tool failed", name)
                    self._tools_failed.add(name)

    def _open_from_address(self, opener: TabOpener) -> None:
        """A link into the course opens where it points: ``?lesson=ID`` the lesson (Learn ›
        Lessons), ``?exercise=SLUG`` the exercise (an LMS's launch lands there)."""
        lessons = cast(LessonsPanel, self._tools["Lessons"])
        exercises = cast(ExercisePanel, self._tools["Exercise"])
        openers = {"lesson": lessons.open_lesson, "exercise": exercises.open_exercise}
        tabs = {"lesson": "Lessons", "exercise": "Exercise"}

        def opened(key: str, value: str) -> None:  # viser's asyncio thread: check and post
            def open_it() -> None:
                if openers[key](value):
                    opener.open(tabs[key])
                else:
                    log.warning("the address asks for %s %r, which the course has not", key, value)

            self.ui.post(open_it)

        hrefs = {
            key: self.page_links.register_value(f"open.{key}", partial(opened, key))
            for key in openers
        }
        script = _OPEN_FROM_ADDRESS % json.dumps(hrefs)
        self.server.gui.add_html(page_script(script, "open what the address names"))

    def _new_lesson(self, programs: frozenset[str]) -> None:
        """Another lesson was opened (UI thread): the views forget what the last one left,
        and the Exercise tool opens the new lesson's exercise."""
        cast(ScenePanel, self._tools["3D view"]).forget_unpublished(self.graph)
        cast(ExercisePanel, self._tools["Exercise"]).follow_the_lesson()
        self._stage.forget()
        self._lesson_since = time.time()
        self._lesson_programs = programs

    def _starting_nodes(self) -> list[str]:
        """Catalog nodes that are starting: clicked (until the supervisor has the process),
        or whose process runs but has not joined the ROS graph yet."""
        statuses = self.supervisor.statuses()
        names = {name for name, status in statuses.items() if status.state is NodeState.STARTING}
        for name, asked_at in self.start_requests.pending().items():
            status = statuses.get(name)
            taken = status is not None and (status.started_at or 0.0) >= asked_at - 0.5
            if taken or (status is not None and status.state is NodeState.RUNNING):
                self.start_requests.done(name)  # the supervisor's state says the rest
            else:
                names.add(name)
        found = []
        for name in sorted(names):
            try:
                found.append(lookup(name).node_name)
            except UnknownNodeError:  # a learner's own program: drawn once it joins
                pass
        return found

    def _inspect(self, kind: str, name: str, type_text: str) -> None:
        """A box clicked on the stage: every tool that shows more of such a thing picks
        it (UI thread); each tool says which kinds it shows."""
        self._inspected = (kind, name, type_text)  # a tool built later picks it too
        for tool in self._tools.values():
            if isinstance(tool, Inspector):
                tool.inspect(kind, name, type_text)

    def _program_output(self) -> tuple[str, list[str]]:
        """The program started last in this lesson, the learner's own or a lesson's (one
        still running first): its name and state, and its last lines of output, for under
        the code. What an earlier lesson ran is not this lesson's output, unless it is one
        of this lesson's own programs still running (the learner came back to the lesson)."""
        # A program this lesson started was spawned after the click that opened it.
        statuses = [
            status
            for status in self.supervisor.statuses().values()
            if (status.started_at or 0.0) >= self._lesson_since
            or (status.active and status.name in self._lesson_programs)
        ]
        if not statuses:
            return "", []
        running = [status for status in statuses if status.active]
        latest = max(running or statuses, key=lambda status: status.started_at or 0.0)
        return f"{latest.name} · {latest.describe()}", self.supervisor.output(latest.name, 40)

    def _exercise_marks(self, lesson_id: str) -> str:
        """The outline's exercise column: ✓ for each exercise passed, ○ for each open."""
        exercises = self.exercises.for_lesson(lesson_id)
        return " ".join("✓" if self.workspace.passed(e) else "○" for e in exercises)

    def start(self) -> None:
        self._ui_thread.start()

    def _graph_may_change(self, _status: object) -> None:
        """A program of ours started or is ending: its node joins or leaves the graph soon."""
        self._look_until = time.monotonic() + GRAPH_BURST_SEC
        self.ui.wake()

    def _ui_loop(self) -> None:
        # Any posted intent, or a node list that changed, refreshes at once; otherwise
        # panels refresh at UI_PERIOD_SEC. The node list is looked at with each refresh,
        # and every GRAPH_CHECK_SEC while a program of ours starts or stops: its node
        # shows up within a frame, a click's effect within one pass.
        last_nodes: list[tuple[str, str]] | None = None
        due = 0.0
        full = FullPasses(CALM_PERIOD_SEC, GRAPH_BURST_SEC)
        hidden_passes = HiddenPasses(HIDDEN_PERIOD_SEC)
        while not self._stop.is_set():
            watched = bool(self.server.get_clients())
            if not watched:
                check = UNWATCHED_CHECK_SEC
            elif time.monotonic() < self._look_until:
                check = GRAPH_CHECK_SEC
            else:
                check = max(0.0, min(UI_PERIOD_SEC, due - time.monotonic()))
            woken = self.ui.wait(check)
            applied = self.ui.apply_pending()
            self._build_asked_tools()
            try:
                nodes = self.runtime.node.get_node_names_and_namespaces()
            except Exception:  # the graph may be unreadable for a moment
                nodes = last_nodes or []
            now = time.monotonic()
            if nodes == last_nodes and now < due and not (woken or applied):
                continue
            happened = bool(woken or applied) or now < self._look_until
            full_pass = full.due(now, happened=happened, nodes_changed=nodes != last_nodes)
            last_nodes, due = nodes, now + (UI_PERIOD_SEC if watched else UNWATCHED_PERIOD_SEC)
            if full_pass:
                try:
                    self.graph = snapshot(self.runtime.node)
                    self.supervisor.note_visible_nodes(self.graph.nodes)
                    self.lessons.graph = self.graph
                except Exception:  # the graph may be unreadable a moment: keep the panels going
                    log.exception("graph snapshot failed")
            eventful = happened or full.settling(now)
            refresh_hidden = hidden_passes.due(now, eventful=eventful, full=full_pass)
            hidden = set() if refresh_hidden else self._hidden_tools()
            for panel in self._panels:
                if not full_pass and getattr(panel, "calm", False):
                    continue
                if id(panel) in hidden:
                    continue
                try:
                    panel.refresh(self.graph)
                except Exception:  # one panel's bug (or a forged widget value) freezes no other
                    log.exception("refresh of %s failed", type(panel).__name__)
            # Send now: viser otherwise holds a lone update up to one 60 Hz window.
            self.server.flush()

    def _hidden_tools(self) -> set[int]:
        """The tools (by id) that no page shows and that have no work to do unseen."""
        shown = self._shown.shown()
        return {
            id(tool)
            for name, tool in self._tools.items()
            if name not in shown and not getattr(tool, "hidden_work", False)
        }

    def stop(self) -> None:
        """Stop the UI thread, then close every panel (their subscriptions, timers)."""
        self._stop.set()
        self.ui.post(lambda: None)  # wake the loop now
        self._ui_thread.join(timeout=2.0)
        self.ui.close()
        for panel in self._panels:
            try:
                panel.close()
            except Exception:  # shutting down: close the others anyway
                log.exception("close of %s failed", type(panel).__name__)
        self._rates.close()
        self.lessons.close()
        self.rosout.close()
