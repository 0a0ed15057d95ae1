"""The catalog: the only programs the dashboard may start.

A browser can ask for a catalog *name*, never a command line: the module and
arguments below are fixed here, so no text from the page reaches a process's
argv or a shell. An entry is what ``ros2 run <pkg> <executable> --ros-args ...``
would start; a group is what a Python launch file would describe.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class CatalogEntry:
    """One runnable node: ``python -m nodes.<module> --ros-args <ros_args>``."""

    name: str
    module: str
    node_name: str  # fully qualified ROS name the process creates, e.g. /talker
    summary: str
    ros_args: tuple[str, ...] = ()
    args: tuple[str, ...] = ()  # program arguments before --ros-args

    def argv_tail(self) -> list[str]:
        """Arguments after ``python -m nodes.<module>``."""
        tail = list(self.args)
        if self.ros_args:
            tail += ["--ros-args", *self.ros_args]
        return tail

    def ros2_run_command(self) -> str:
        """The command a learner would type in a full ROS 2 installation."""
        words = ["ros2", "run", "tutorial_nodes", self.module, *self.argv_tail()]
        return " ".join(words)


@dataclass(frozen=True)
class LaunchGroup:
    """Several catalog entries started together, as one launch file would."""

    name: str
    summary: str
    members: tuple[str, ...] = field(default_factory=tuple)


ENTRIES: tuple[CatalogEntry, ...] = (
    CatalogEntry("talker", "talker", "/talker", 'Publishes "Hello World: N" on /chatter at 2 Hz.'),
    CatalogEntry("listener", "listener", "/listener", "Prints every message on /chatter."),
    CatalogEntry(
        "listener2",
        "listener",
        "/listener2",
        "The same listener program, renamed with a remap: a second subscriber.",
        ros_args=("-r", "__node:=listener2"),
    ),
    CatalogEntry(
        "crashing_node",
        "crashing_node",
        "/crashing_node",
        "Crashes on purpose after 3 s, to show how failures are reported.",
    ),
    # --- core tutorial nodes (issue 3): add entries below this line ---
    # --- perception and manipulation nodes (issue 5): add entries below this line ---
)

GROUPS: tuple[LaunchGroup, ...] = (
    LaunchGroup(
        "chatter_demo",
        "talker + listener + listener2 on /chatter",
        ("talker", "listener", "listener2"),
    ),
    # --- core tutorial groups (issue 3): add groups below this line ---
    # --- perception groups (issue 5): add groups below this line ---
)

_BY_NAME = {entry.name: entry for entry in ENTRIES}
_GROUPS_BY_NAME = {group.name: group for group in GROUPS}


class UnknownNodeError(LookupError):
    """Raised for a name that is not in the catalog."""


def lookup(name: str) -> CatalogEntry:
    try:
        return _BY_NAME[name]
    except (KeyError, TypeError):
        known = ", ".join(sorted(_BY_NAME))
        raise UnknownNodeError(f"no catalog node named {name!r}; known nodes: {known}") from None


def lookup_group(name: str) -> LaunchGroup:
    try:
        return _GROUPS_BY_NAME[name]
    except (KeyError, TypeError):
        known = ", ".join(sorted(_GROUPS_BY_NAME))
        raise UnknownNodeError(f"no launch group named {name!r}; known groups: {known}") from None


def names() -> list[str]:
    return [entry.name for entry in ENTRIES]
