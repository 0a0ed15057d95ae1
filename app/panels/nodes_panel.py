"""Nodes panel: the catalog with Start / Stop / Restart, state and a live log tail."""

from __future__ import annotations

import viser

from app.catalog import ENTRIES, GROUPS, lookup, lookup_group
from app.launch import launch_file_text
from app.ros.graph import GraphSnapshot
from app.supervisor import ACTIVE_STATES, NodeState, NodeStatus, Supervisor
from app.ui import MarkdownView, assign, code_block
from app.ui.loop import UiLoop
from app.ui.starting import StartRequests

_STATE_ICONS = {
    NodeState.STARTING: "◐",
    NodeState.RUNNING: "●",
    NodeState.STOPPING: "◑",
    NodeState.STOPPED: "○",
    NodeState.EXITED: "✓",
    NodeState.CRASHED: "✗",
}
LOG_TAIL_LINES = 14
_ENTRY_NAMES = frozenset(entry.name for entry in ENTRIES)
_GROUP_NAMES = frozenset(group.name for group in GROUPS)
STALE_NOTE = " · ⚠ still listed in the ROS graph until its DDS lease expires (about 20 s)"


def _notes(status: NodeStatus, stale: bool, elsewhere: str = "") -> str:
    """What the state alone hides: a dead node the graph still lists, the same node started
    by another process (``elsewhere``: its name), lost log lines."""
    notes = STALE_NOTE if stale else ""
    if elsewhere:
        notes += f" · {elsewhere} is on the graph: started elsewhere (a terminal, a launch file)"
    if status.dropped_lines:
        notes += f" · dropping log lines ({status.dropped_lines} so far)"
    return notes


class NodesPanel:
    calm = True  # once a second while idle (app.ui.Panel): states change with a wake; output lines

    def __init__(
        self,
        gui: viser.GuiApi,
        ui: UiLoop,
        supervisor: Supervisor,
        start_requests: StartRequests | None = None,
    ) -> None:
        self._ui = ui
        self._supervisor = supervisor
        self._requests = start_requests or StartRequests()  # the stage shows them at once
        self._graph = GraphSnapshot()
        self._selector = gui.add_dropdown(
            "Catalog node",
            [entry.name for entry in ENTRIES],
            initial_value=ENTRIES[0].name,
            hint="Pick a tutorial node to start, stop or inspect",
        )
        self._details = MarkdownView(gui)
        self._start = gui.add_button("Start", icon=viser.Icon.PLAYER_PLAY, color="green")
        self._stop = gui.add_button("Stop", icon=viser.Icon.PLAYER_STOP, color="red")
        self._restart = gui.add_button("Restart", icon=viser.Icon.REFRESH)
        self._message = MarkdownView(gui)
        self._log = MarkdownView(gui)
        with gui.add_folder("Launch groups"):
            gui.add_markdown("Several nodes at once, as a Python launch file would start them.")
            self._group_selector = gui.add_dropdown(
                "Launch group", [group.name for group in GROUPS], initial_value=GROUPS[0].name
            )
            self._start_group = gui.add_button("Start group", icon=viser.Icon.PLAYER_PLAY)
            self._stop_group = gui.add_button("Stop group", icon=viser.Icon.PLAYER_STOP)
            self._group_details = MarkdownView(gui)
        with gui.add_folder("All catalog nodes"):
            self._overview = MarkdownView(gui)
        self._start.on_click(ui.callback(self._act, "start"))
        self._stop.on_click(ui.callback(self._act, "stop"))
        self._restart.on_click(ui.callback(self._act, "restart"))
        self._start_group.on_click(ui.callback(self._act_on_group, "start"))
        self._stop_group.on_click(ui.callback(self._act_on_group, "stop"))
        # A new choice only needs a refresh, which follows every applied intent.
        self._selector.on_update(ui.callback(self._valid_selection))
        self._group_selector.on_update(ui.callback(self._valid_selection))

    # -- clicks (UI thread) ------------------------------------------------------
    # Every click becomes a job in one lane: clicks run one at a time, in the
    # order they were made, so a Stop never overtakes a half-done group Start.

    def _act(self, verb: str) -> None:
        name = self._selector.value
        work = {"start": self._do_start, "stop": self._do_stop, "restart": self._do_restart}[verb]
        if verb == "restart":
            self._message.show(f"Restarting **{name}**…")
        if verb == "start" and name in _ENTRY_NAMES:
            self._requests.asked(name)
        self._ui.run_job(
            lambda: work(name),
            self._message.show,
            lambda text: self._start_failed(text, [name]),
            lane="nodes",
        )

    def _act_on_group(self, verb: str) -> None:
        name = self._group_selector.value

        def work() -> str:
            group = lookup_group(name)
            for member in group.members:
                if verb == "start":
                    self._supervisor.start(member)
                else:
                    self._supervisor.stop(member)
            done = "Started" if verb == "start" else "Stopping"
            return f"{done} group **{group.name}**: {', '.join(group.members)}."

        members = list(lookup_group(name).members) if name in _GROUP_NAMES else []
        if verb == "start":
            for member in members:
                self._requests.asked(member)
        self._ui.run_job(
            work,
            self._message.show,
            lambda text: self._start_failed(text, members),
            lane="nodes",
        )

    def _start_failed(self, text: str, names: list[str]) -> None:
        for name in names:
            self._requests.done(name)
        self._show_error(text)

    def _show_error(self, text: str) -> None:
        self._message.show(f"⚠ {text}")

    # -- jobs (lane "nodes") -------------------------------------------------------

    def _do_start(self, name: str) -> str:
        status = self._supervisor.start(name)
        program = self._supervisor.program(name)
        node = f": node `{program.node_name}`" if program is not None else ""
        return f"Started **{name}**{node} (pid {status.pid})."

    def _do_stop(self, name: str) -> str:
        self._supervisor.stop(name)  # escalates in the supervisor's own thread
        return f"Stopping **{name}** (Ctrl+C, as in a terminal)…"

    def _do_restart(self, name: str) -> str:
        self._supervisor.restart(name)
        return f"Restarted **{name}**."

    # -- UI thread -------------------------------------------------------------

    def inspect(self, kind: str, node_name: str, type_text: str) -> None:
        """A node clicked on the stage graph: pick the catalog entry that makes it."""
        if kind != "node":
            return
        entry = next((e for e in ENTRIES if e.node_name == node_name), None)
        if entry is not None:
            assign(self._selector, entry.name)

    def _valid_selection(self) -> None:
        """Dropdown values come from the browser: anything outside the catalog is reset."""
        if self._selector.value not in _ENTRY_NAMES:
            assign(self._selector, ENTRIES[0].name)
        if self._group_selector.value not in _GROUP_NAMES:
            assign(self._group_selector, GROUPS[0].name)

    def refresh(self, graph: GraphSnapshot) -> None:
        self._valid_selection()
        statuses = self._supervisor.statuses()
        stale = self._supervisor.stale_in_graph(graph.nodes)
        rows = ["| node | state |", "|---|---|"]

        def elsewhere(name: str, status: NodeStatus) -> str:
            """A catalog node this dashboard does not run, yet on the graph: the learner
            started it from a terminal (the lessons teach `ros2 run`), so 'stopped' alone
            would contradict the stage."""
            node = lookup(name).node_name
            quiet = status.state not in ACTIVE_STATES and name not in stale
            return node if quiet and graph.has_node(node) else ""

        for entry in ENTRIES:
            status = statuses.get(entry.name, NodeStatus(entry.name, NodeState.STOPPED))
            rows.append(
                f"| {entry.name} | {_STATE_ICONS[status.state]} {status.describe()}"
                f"{_notes(status, entry.name in stale, elsewhere(entry.name, status))} |"
            )
        self._overview.show("\n".join(rows))

        name = self._selector.value
        entry = lookup(name)
        status = statuses.get(name, NodeStatus(name, NodeState.STOPPED))
        self._details.show(
            f"**{name}**: {entry.summary}\n\n"
            f"State: {_STATE_ICONS[status.state]} **{status.describe()}**"
            f"{_notes(status, name in stale, elsewhere(name, status))}\n\n"
            f"In a terminal: `{entry.ros2_run_command()}`"
        )
        active = status.state in ACTIVE_STATES
        self._start.disabled = active
        self._stop.disabled = not active
        group = lookup_group(self._group_selector.value)
        self._group_details.show(
            f"{group.summary}.\n\nIn a terminal: `ros2 launch tutorial_nodes "
            f"{group.name}.launch.py`, where the launch file says:\n\n"
            f"```python\n{launch_file_text(group)}\n```"
        )
        lines = self._supervisor.output(name, last=LOG_TAIL_LINES)
        dropped = (
            f"\n\n_⚠ output is faster than the buffer keeps: {status.dropped_lines} older "
            f"lines dropped, the last {self._supervisor.max_log_lines} kept_"
            if status.dropped_lines
            else ""
        )
        self._log.show(f"Log of **{name}**:\n\n" + code_block(lines) + dropped)

    def close(self) -> None:
        """The supervisor, not this panel, owns the processes: nothing to release."""
