"""Shared by the verbs: ros2cli's failure kinds, hidden names, print()-like output, and
letting a brand-new node see the graph."""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

from rclpy.topic_or_service_is_hidden import topic_or_service_is_hidden

from app.ros.context import CallContext, Write
from app.ros.convert import ConversionError, RosType, import_type
from app.ros.errors import Ros2Error

MIN_DISCOVERY_SEC = 1.5

# What a verb does with its parsed arguments: its exit code.
Handler = Callable[[CallContext, argparse.Namespace], int]


class Commands(Protocol):
    """A "Commands:" table (argparse's sub-parsers, made by ``parser.commands``).

    Its parsers raise instead of exiting and print through ``write``.
    """

    def add_parser(
        self,
        name: str,
        *,
        help: str | None = ...,
        description: str | None = ...,
        formatter_class: type[argparse.HelpFormatter] = ...,
        write: Write,
    ) -> argparse.ArgumentParser: ...


# The parser's helper that adds one verb to a group: (group, name, description, handler).
Verb = Callable[[Commands, str, str, Handler], argparse.ArgumentParser]


class Ros2cliMessage(Ros2Error):
    """A failure ros2cli reports with these exact words (no 'error:' prefix), exit code 1.

    ros2cli's verbs return a string (or raise RuntimeError) and the `ros2`
    entry point prints it and exits with 1: "Unable to find node '/x'",
    "Unknown topic '/x'", "Node not found".
    """


class SilentFailure(Ros2Error):
    """ros2cli ends with exit code 1 and prints nothing (`ros2 service type /unknown`).

    A terminal keeps stdout as ros2's (the reason goes to stderr); the Console,
    which has one output, shows the reason in parentheses.
    """


_INVALID_TYPE = {
    "msg": "The passed message type is invalid",
    "srv": "The passed service type is invalid",
    "action": "The passed action type is invalid",
}


def ros2_type(type_text: str, kind: str) -> RosType:
    """A message, service or action class, or ros2cli's words for a type it cannot import."""
    try:
        return import_type(type_text, kind)
    except ConversionError:
        raise Ros2cliMessage(_INVALID_TYPE[kind]) from None


@dataclass
class TerminalContext(CallContext):
    """A terminal's context: ``note`` takes what ros2 prints on stderr, not stdout."""

    note: Write | None = None


def write_note(ctx: CallContext, line: str) -> None:
    """A line ros2 prints on stderr (a warning, a refusal): a terminal's stderr, else the output."""
    note = ctx.note if isinstance(ctx, TerminalContext) else None
    (note or ctx.write)(line)


def write_outcome(ctx: CallContext, ok: bool, line: str) -> None:
    """ros2cli prints a success on stdout and a refusal on stderr."""
    if ok:
        ctx.write(line)
    else:
        write_note(ctx, line)


def is_hidden_name(name: str) -> bool:
    """A topic, service or action name with any component starting with '_'."""
    return topic_or_service_is_hidden(name)


def visible(
    pairs: list[tuple[str, list[str]]], include_hidden: bool = False
) -> list[tuple[str, list[str]]]:
    """(name, types) pairs as ros2cli lists them: hidden names left out unless asked for."""
    return [(n, list(t)) for n, t in pairs if include_hidden or not is_hidden_name(n)]


def write_text(ctx: CallContext, text: str) -> None:
    """What Python's print(text) shows, one line per write (a trailing newline: an empty line)."""
    for line in text.split("\n"):
        ctx.write(line)


def write_names(ctx: CallContext, lines: list[str], count: bool = False) -> int:
    """A listing as the `ros2 ... list` verbs print it: one per line, or (-c) how many."""
    if count:
        ctx.write(str(len(lines)))
    for line in [] if count else lines:
        ctx.write(line)
    return 0


def settle_discovery(ctx: CallContext, spin_time: float | None = None) -> None:
    """A brand-new node sees the graph piece by piece: wait until it stops changing.

    ``--spin-time S`` asks for exactly S seconds instead, as ros2cli's own node spins.
    """
    if ctx.limits.discovery_wait <= 0:
        return
    if spin_time is not None:
        ctx.sleep(max(0.0, spin_time))
        return
    # Participants are found before their endpoints: insist on a minimum look
    # (as `ros2 ... --no-daemon` spins a while) and then on a quiet second.
    started = time.monotonic()
    deadline = started + ctx.limits.discovery_wait
    last: tuple[int, int, int] | None = None
    stable_since = started
    while time.monotonic() < deadline:
        node = ctx.node
        now = (
            len(node.get_node_names_and_namespaces()),
            len(node.get_topic_names_and_types()),
            len(node.get_service_names_and_types()),
        )
        if now != last:
            last, stable_since = now, time.monotonic()
        elif (
            now[0] > 1
            and time.monotonic() - started > MIN_DISCOVERY_SEC
            and time.monotonic() - stable_since > 1.0
        ):
            return
        ctx.sleep(0.1)
