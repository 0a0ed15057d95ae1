"""The command-line face: ``ros2-classroom topic list -t`` and friends.

A short-lived rclpy participant (a hidden node, as ros2cli's daemon is) is
created only for verbs that need the graph; Ctrl+C stops a streaming verb
(echo, hz, pub -r) cleanly.
"""

from __future__ import annotations

import os
import sys
import threading
from typing import cast

from rclpy.node import Node

from app.ros.context import CLI_LIMITS
from app.ros2cli.common import TerminalContext
from app.ros2cli.parser import needs_ros, run_argv
from app.stop_signals import set_on_signals

ROS2CLI_GROUPS = ("node", "topic", "service", "action", "param", "lifecycle", "interface")
EXIT_INTERRUPTED_OTHER = 130  # our other commands (bag, run, ...): the shell's convention


def _print(line: str) -> None:
    print(line, flush=True)


def _note(line: str) -> None:
    """What ros2 would not print on stdout (its stdout stays the same as ours)."""
    print(line, file=sys.stderr, flush=True)


def main(argv: list[str], prog: str = "ros2-classroom") -> int:
    """Run one verb; the caller has already configured DDS for this process.

    ``prog`` names the command in usage lines (``ros2`` for the terminal's ``ros2``).
    """
    cancel = threading.Event()
    if not needs_ros(argv):
        # Verbs that need no ROS (interface ...) never touch the node: none is made.
        no_node = cast(Node, None)
        return run_argv(
            TerminalContext(node=no_node, write=_print, limits=CLI_LIMITS, note=_note),
            argv,
            prog,
        )
    from app.ros.runtime import RosRuntime

    # Ctrl+C (or SIGTERM) asks the running verb to stop at its next wait, so it
    # always cleans up (subscriptions, publishers) instead of dying mid-call.
    restore_handlers = set_on_signals(cancel)
    # Hidden, and without parameter services, as ros2cli's own node is.
    runtime = RosRuntime(f"_ros2_classroom_cli_{os.getpid()}", quiet=True)
    ctx = TerminalContext(
        node=runtime.node, write=_print, limits=CLI_LIMITS, cancel=cancel, note=_note
    )
    try:
        code = run_argv(ctx, argv, prog)
        if cancel.is_set() and not (argv[:1] and argv[0] in ROS2CLI_GROUPS):
            return EXIT_INTERRUPTED_OTHER
        return code  # ros2cli's verbs: as `ros2` ends after Ctrl+C (parser.EXIT_INTERRUPTED)
    finally:
        runtime.shutdown()
        restore_handlers()
        sys.stdout.flush()
