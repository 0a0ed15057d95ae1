"""What every browser front end shares: the UI thread, its widgets and the tools' names.

Threading model (every panel follows it; see ``UiLoop``):

- One thread, the dashboard's UI thread, owns every panel's state. It applies
  intents in the order they were posted, then calls ``refresh(graph)`` on each
  panel. Only it reads or writes a panel's attributes.
- viser runs browser callbacks on its own thread pool. A callback never
  touches panel state and never waits: it posts an intent (``ui.post``).
- The rclpy executor thread runs ROS callbacks. They either record into an
  object that has its own lock and is read through copies (``TopicMonitor``,
  ``RosoutLog``), or post an intent.
- Anything that waits on ROS (a service call, a goal, a parameter read) runs
  as a job (``ui.run_job``) on a worker thread. A job receives its inputs as
  arguments and returns a result; the UI thread applies it (``on_done``) or
  shows the one-line error (``on_error``). Jobs of one lane run one after
  another, in click order.
- Each panel has ``close()``; the dashboard calls it once, on shutdown.

viser (1.1.1) from each thread:

- Setting a handle's properties, ``add_*``, ``remove()``, ``flush()`` and
  ``atomic()`` are safe from any thread (UI, job, executor, viser's pool or
  its event loop) on a server made by ``app.access.make_server``: it installs
  ``app.viser_threads``. Bare viser woke its event loop from the calling
  thread and could crash there (``deque mutated during iteration``, issue 38);
  servers built without ``make_server`` (bench/ baselines, a few tests) still do.
- Setting an input's ``value`` runs its update callbacks at once, on the
  setter's thread (``event.client`` is None; ``UiLoop.callback`` ignores them).
- viser takes any string a browser sends as a dropdown's value; ``UiLoop.callback``
  puts back one the dropdown does not offer, on the pool thread, and posts nothing.
- Browser events run plain callbacks on viser's pool (32 threads) and
  ``async def`` callbacks on the event loop thread. Blocking in the first
  holds a pool thread, in the second freezes every browser: post an intent.
- Calls that wait for a browser's answer (``client.get_render``,
  ``client.local_storage.get_item``, ``request_share_url``) run as jobs:
  never on the event loop thread (the answer needs that loop: they hang, up
  to their timeout if any) nor on the UI thread (every panel would stall).
  ``server.stop()`` joins the loop thread: never call it from that thread.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol, TypeVar, runtime_checkable

import viser

if TYPE_CHECKING:  # at run time only a name in an annotation: serve's page comes up
    from app.ros.graph import GraphSnapshot  # before rclpy is imported (app/cli.py)


# The dashboard's tools, grouped as a learner thinks of them: what I learn with, what I
# run, what I watch flowing through the running system, how I ask its nodes to do or
# change something, what I see in 3D, what I record. Each group is a tab holding its
# tools' tabs, one row each. A new tool joins the group it belongs to, here, with its
# icon; the dashboard says how to build it (``app/dashboard.py``, keyed by its name).
@dataclass(frozen=True)
class ToolGroup:
    icon: viser.IconName
    tools: dict[str, viser.IconName]  # each tool's tab name -> its icon, in tab order


Icon = viser.Icon
TOOLS: dict[str, ToolGroup] = {
    "Learn": ToolGroup(Icon.SCHOOL, {"Lessons": Icon.SCHOOL, "Exercise": Icon.PENCIL}),
    "Run": ToolGroup(
        Icon.PLAYER_PLAY, {"Nodes": Icon.CPU, "Console": Icon.TERMINAL, "Turtlesim": Icon.PAW}
    ),
    "Inspect": ToolGroup(
        Icon.ZOOM_IN,
        {
            "Graph": Icon.SITEMAP,
            "TF": Icon.BINARY_TREE,
            "Topics": Icon.LIST_DETAILS,
            "Echo": Icon.MESSAGE,
            "Logs": Icon.FILE_TEXT,
        },
    ),
    "Interact": ToolGroup(
        Icon.HAND_CLICK,
        {
            "Services": Icon.ARROWS_EXCHANGE,
            "Actions": Icon.ROCKET,
            "Parameters": Icon.ADJUSTMENTS,
            "Lifecycle": Icon.PROGRESS,
        },
    ),
    "See": ToolGroup(Icon.EYE, {"3D view": Icon.CUBE}),
    "Record": ToolGroup(Icon.PLAYER_RECORD, {"Bags": Icon.DATABASE}),
}
TOOL_GROUPS: dict[str, tuple[str, ...]] = {
    group: tuple(declared.tools) for group, declared in TOOLS.items()
}
# Every tool tab, in order. Lessons name them ("Open the Lifecycle tool") and are
# checked against this list when they load.
TAB_NAMES = tuple(name for names in TOOL_GROUPS.values() for name in names)
GROUP_OF = {name: group for group, names in TOOL_GROUPS.items() for name in names}


class Panel(Protocol):
    """A tool's widgets, refreshed by the UI thread.

    A panel whose content never moves on its own faster than about once a second
    (a table of states, a log, checks) says so with a class attribute
    ``calm = True``: while nothing happens it is refreshed once a second, not at
    every pass (what an idle dashboard costs); a click, a job's end or a node that
    joins still refreshes it at once.

    A tool no page shows (``app.ui.shown_tools``) is refreshed every few seconds
    and whenever something happens, unless it says ``hidden_work = True``: its
    refresh does work that matters unseen (the 3D view draws into the scene every
    page shows, the lesson's checks mark progress, a recording is watched).
    """

    def refresh(self, graph: GraphSnapshot) -> None: ...

    def close(self) -> None: ...


@runtime_checkable
class Inspector(Protocol):
    """A tool that shows more of a box clicked on the stage's graph: ``kind`` is node,
    topic, service or action; a tool ignores the kinds it does not show."""

    def inspect(self, kind: str, name: str, type_text: str) -> None: ...


class MarkdownView:
    """A markdown handle that is re-sent only when its text changes."""

    def __init__(
        self,
        gui: viser.GuiApi,
        content: str = "",
        *,
        order: float | None = None,
        visible: bool = True,
    ) -> None:
        self._content = content
        self.handle = gui.add_markdown(content, order=order, visible=visible)

    def show(self, content: str) -> None:
        if content != self._content:
            self._content = content
            self.handle.content = content

    @property
    def content(self) -> str:
        return self._content


V = TypeVar("V")
V_co = TypeVar("V_co", covariant=True)


class Input(Protocol[V_co]):
    """A viser input (text, number, slider, dropdown, checkbox, progress bar...)."""

    @property
    def value(self) -> V_co: ...


def assign(handle: Input[V], value: V) -> None:
    """Set a viser input's value (viser 1.1 types ``value`` read-only; its setter is there)."""
    setattr(handle, "value", value)  # noqa: B010 (mypy sees no setter)


def topic_item(name: str, type_text: str, publishers: int, subscribers: int) -> str:
    """One topic as a Markdown list item, shaped like a line of `ros2 topic list -t`.

    A list, not a table: long type names wrap instead of pushing columns past
    the panel's right edge.
    """
    return f"- `{name}` [{type_text}] · {publishers} pub, {subscribers} sub"


def code_block(lines: list[str], empty: str = "(nothing yet)") -> str:
    body = "\n".join(lines) if lines else empty
    return f"```\n{body}\n```"


def set_options(
    dropdown: viser.GuiDropdownHandle[str], options: list[str], keep_current: bool = True
) -> None:
    """New dropdown options without stealing the learner's choice.

    With ``keep_current`` the current value stays selectable even when it has
    left the list (a topic that went away may come back); otherwise a value
    not in the list falls back to the first option (a browser cannot set a value the
    dropdown does not offer: ``app.viser_input``).
    """
    current = dropdown.value
    if keep_current and current not in options:
        options = [*options, current]
    if tuple(dropdown.options) != tuple(options):
        dropdown.options = options
    if current not in options and options:
        assign(dropdown, options[0])
