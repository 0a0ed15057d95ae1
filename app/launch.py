"""Launch groups: run one in the foreground, or show it as a Python launch file.

A :class:`~app.catalog.LaunchGroup` is what a ROS 2 Python launch file
describes: several nodes, each with its name, arguments, parameters and
remappings. ``launch_ros`` is not on PyPI, so ``ros2-classroom launch <group>``
does its job with the supervisor: it starts every member, streams each
node's output prefixed with its name (as ``ros2 launch`` does) and stops them
all on Ctrl+C or SIGTERM. :func:`launch_file_text` writes the launch file a
learner would write for the same group, for the lessons to display.
"""

from __future__ import annotations

import json
import sys
import threading
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TextIO

import yaml

from app.catalog import CatalogEntry, LaunchGroup, lookup, lookup_group
from app.stop_signals import set_on_signals
from app.supervisor import ACTIVE_STATES, NodeState, Supervisor

PACKAGE = "tutorial_nodes"  # the package name our `ros2 run` commands use


# -- launch file text --------------------------------------------------------


@dataclass
class NodeSpec:
    """The keyword arguments of one ``launch_ros.actions.Node``."""

    executable: str
    name: str
    namespace: str | None = None
    arguments: list[str] = field(default_factory=list)
    parameters: dict[str, object] = field(default_factory=dict)
    remappings: list[tuple[str, str]] = field(default_factory=list)
    ros_arguments: list[str] = field(default_factory=list)


def node_spec(entry: CatalogEntry) -> NodeSpec:
    """Translate a catalog entry's command line into launch ``Node`` fields."""
    namespace, _, name = entry.node_name.rpartition("/")
    spec = NodeSpec(
        executable=entry.module,
        name=name,
        namespace=namespace or None,
        arguments=list(entry.args),
    )
    words = list(entry.ros_args)
    i = 0
    while i < len(words):
        flag = words[i]
        value = words[i + 1] if i + 1 < len(words) else None
        if flag in ("-r", "--remap") and value and ":=" in value:
            source, target = value.split(":=", 1)
            if source not in ("__node", "__name", "__ns"):  # name/namespace come from node_name
                spec.remappings.append((source, target))
            i += 2
        elif flag in ("-p", "--param") and value and ":=" in value:
            key, text = value.split(":=", 1)
            # rcl reads a -p value as YAML, so "5" is an int and "true" a bool.
            spec.parameters[key] = yaml.safe_load(text) if text else ""
            i += 2
        else:
            spec.ros_arguments.append(flag)
            i += 1
    return spec


def _py(value: object) -> str:
    """A Python literal in the double-quoted style of our code."""
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, tuple):
        return "(" + ", ".join(_py(v) for v in value) + ")"
    if isinstance(value, list):
        return "[" + ", ".join(_py(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{_py(k)}: {_py(v)}" for k, v in value.items()) + "}"
    return repr(value)  # bool, int, float, None


def launch_file_text(group: LaunchGroup | str) -> str:
    """The Python launch file equivalent to a launch group."""
    if isinstance(group, str):
        group = lookup_group(group)
    nodes = []
    for member in group.members:
        spec = node_spec(lookup(member))
        lines = [
            f"package={_py(PACKAGE)}",
            f"executable={_py(spec.executable)}",
            f"name={_py(spec.name)}",
        ]
        if spec.namespace:
            lines.append(f"namespace={_py(spec.namespace)}")
        if spec.arguments:
            lines.append(f"arguments={_py(spec.arguments)}")
        if spec.parameters:
            lines.append(f"parameters=[{_py(spec.parameters)}]")
        if spec.remappings:
            lines.append(f"remappings={_py(spec.remappings)}")
        if spec.ros_arguments:
            lines.append(f"ros_arguments={_py(spec.ros_arguments)}")
        lines.append('output="screen"')
        body = "".join(f"                {line},\n" for line in lines)
        nodes.append(f"            Node(\n{body}            ),\n")
    return (
        f'"""Launch group {group.name!r}.\n\n{group.summary[:1].upper()}{group.summary[1:]}.\n"""\n'
        "\n"
        "from launch import LaunchDescription\n"
        "from launch_ros.actions import Node\n"
        "\n"
        "\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription(\n"
        "        [\n"
        f"{''.join(nodes)}"
        "        ]\n"
        "    )\n"
    )


# -- running a group ---------------------------------------------------------


class _OutputPump:
    """Prints the lines a node wrote since the last call, prefixed with its name.

    The supervisor keeps a bounded buffer per node; lines that fell out of it
    between two calls are counted as skipped rather than printed twice.
    """

    def __init__(self, supervisor: Supervisor, name: str, out: TextIO) -> None:
        self._supervisor = supervisor
        self._name = name
        self._out = out
        self._printed = 0  # lines seen so far, including dropped ones

    def pump(self) -> None:
        dropped = self._supervisor.status(self._name).dropped_lines
        lines = self._supervisor.output(self._name)
        total = dropped + len(lines)
        new = total - self._printed
        if new <= 0:
            return
        if new > len(lines):
            self._out.write(f"[{self._name}] ... {new - len(lines)} line(s) skipped\n")
            new = len(lines)
        for line in lines[len(lines) - new :]:
            self._out.write(f"[{self._name}] {line}\n")
        self._printed = total
        self._out.flush()


def run_group(
    name: str,
    env: Mapping[str, str],
    *,
    stop: threading.Event,
    out: TextIO | None = None,
    poll_sec: float = 0.1,
) -> int:
    """Run a group until ``stop`` is set or every member has ended.

    Returns 0 when stopped on request or when every member ended with exit
    code 0, else 1.
    """
    group = lookup_group(name)
    out = out or sys.stdout
    supervisor = Supervisor(env, max_log_lines=5000)
    pumps = [_OutputPump(supervisor, member, out) for member in group.members]
    reported: set[str] = set()
    failed = False

    def report_endings() -> None:
        nonlocal failed
        for member in group.members:
            status = supervisor.status(member)
            if member not in reported and status.state not in ACTIVE_STATES:
                reported.add(member)
                failed |= status.state is NodeState.CRASHED
                out.write(f"[launch] {member} {status.describe()}\n")
                out.flush()

    try:
        for member in group.members:
            status = supervisor.start(member)
            out.write(f"[launch] started {member} (pid {status.pid})\n")
        out.flush()
        while not stop.wait(poll_sec):
            for pump in pumps:
                pump.pump()
            report_endings()
            if len(reported) == len(group.members):
                break  # everything ended on its own
    finally:
        if stop.is_set():
            out.write(f"[launch] stopping {len(group.members)} node(s)...\n")
            out.flush()
        supervisor.shutdown()
        for pump in pumps:
            pump.pump()
        report_endings()
    return 1 if failed else 0


def launch_in_foreground(name: str, env: Mapping[str, str]) -> int:
    """``ros2-classroom launch``: run a group until Ctrl+C (SIGINT) or SIGTERM."""
    lookup_group(name)  # an unknown name fails before anything starts
    stop = threading.Event()
    set_on_signals(stop)
    return run_group(name, env, stop=stop)
