"""The ros2-like command grammar: text -> argv -> verb call, with no shell anywhere.

The console hands us whatever a learner typed. It is split with ``shlex``
(quotes as in a terminal, but no globbing, pipes or variables), a leading
``ros2`` is dropped, and argparse picks the verb. argparse is made to raise
instead of printing and exiting, so every mistake becomes one line.
"""

from __future__ import annotations

import argparse
import logging
import shlex
from typing import Any, NoReturn, TypeAlias

from rclpy.exceptions import NameValidationException

from app.ros.context import CallContext, Write
from app.ros.errors import Cancelled, Ros2Error
from app.ros2cli import bag, graph_verbs, interfaces, launch_verb, lifecycle, param, pkg, run, topic
from app.ros2cli.common import (
    Commands,
    Handler,
    Ros2cliMessage,
    SilentFailure,
    TerminalContext,
    settle_discovery,
)
from app.ros2cli.groups import GROUPS
from app.ros2cli.options import NOT_HERE, command_options

log = logging.getLogger(__name__)

EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2
# ros2cli's exit code after Ctrl+C: rclpy's SIGINT handler shuts its context down,
# the verb ends with ExternalShutdownException, and `ros2` returns SIGTERM's number.
EXIT_INTERRUPTED = 15


class UsageError(Ros2Error):
    """The command line itself is wrong (unknown verb, missing argument, bad quoting)."""


class _HelpShown(Exception):
    """argparse printed help (-h); stop without an error."""


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser that writes to our output and raises instead of exiting."""

    def __init__(self, *args: Any, write: Write, **kwargs: Any) -> None:
        # argparse then reports every mistake through error() below, as ros2 does.
        kwargs.setdefault("exit_on_error", True)
        super().__init__(*args, **kwargs)
        self._write = write

    def _print_message(self, message: str, file: object = None) -> None:
        if message:
            for line in message.rstrip("\n").splitlines():
                self._write(line)

    def exit(self, status: int = 0, message: str | None = None) -> NoReturn:
        if message:
            raise UsageError(message.strip())
        raise _HelpShown()

    def error(self, message: str) -> NoReturn:
        raise ArgumentUsageError(self.prog, message, self.format_usage())


class ArgumentUsageError(UsageError):
    """argparse's own complaint (exit code 2, as ros2's)."""

    def __init__(self, prog: str, message: str, usage: str) -> None:
        super().__init__(f"{prog}: {message}")
        self.usage = usage
        # As argparse (and so ros2) prints it: the usage, then "PROG: error: MESSAGE".
        self.as_ros2 = f"{prog}: error: {message}"


def split_command(text: str) -> list[str]:
    """Split like a shell would quote, never run one; drop a leading 'ros2'."""
    try:
        words = shlex.split(text, comments=False, posix=True)
    except ValueError as exc:  # unbalanced quotes
        raise UsageError(f"cannot read the command: {exc}") from None
    if words[:1] == ["ros2"]:
        words = words[1:]
    return words


COMMANDS_HINT = "Call `{prog} <command> -h` for more detailed usage."
RAW = argparse.RawDescriptionHelpFormatter

# Verbs Jazzy's ros2 has in a group we offer, and we do not (listed in the group's -h).
NOT_HERE_VERBS = {
    "topic": {"delay": "Display delay of topic from timestamp in header"},
    "service": {"echo": "Echo a service"},
}


# The "Commands:" table of ``ros2`` or of one group (a ``Commands`` to the verbs' modules).
_Commands: TypeAlias = "argparse._SubParsersAction[_Parser]"  # not generic at run time


def commands(parser: argparse.ArgumentParser, dest: str) -> _Commands:
    """A "Commands:" section as ros2cli makes one: its lines are filled in by finish_commands."""
    sub = parser.add_subparsers(
        title="Commands",
        description="",
        dest=dest,
        metavar=COMMANDS_HINT.format(prog=parser.prog),
        parser_class=_Parser,
    )
    sub.required = False  # no verb: the group prints its help (ros2cli does)
    return sub


def finish_commands(parser: argparse.ArgumentParser, sub: _Commands) -> None:
    """One line per command (its description), sorted, as ros2cli's -h lists them.

    The choices are sorted too (argparse's "invalid choice" error names them in
    that order), and the per-command help lines argparse would add are dropped.
    """
    described = {a.dest: a.help for a in sub._choices_actions}
    shown = {name: p.description or described.get(name) or "" for name, p in sub.choices.items()}
    width = max(map(len, shown))
    section = next(g for g in parser._action_groups if sub in g._group_actions)
    section.description = "".join(f"{n.ljust(width)}  {shown[n]}\n" for n in sorted(shown))
    ordered = sorted(sub.choices.items())
    sub.choices.clear()
    sub.choices.update(ordered)
    sub._choices_actions.clear()


def build_parser(write: Write, prog: str = "ros2") -> argparse.ArgumentParser:
    parser = _Parser(
        prog=prog,
        write=write,
        description=f"{prog} is an extensible command-line tool for ROS 2.",
        formatter_class=RAW,
    )
    parser.add_argument(
        "--use-python-default-buffering",
        action="store_true",
        help="Do not force line buffering in stdout and instead use the python default "
        "buffering, which might be affected by PYTHONUNBUFFERED/-u and depends on whatever "
        "stdout is interactive or not",
    )
    parser.set_defaults(handler=lambda ctx, _args: _print_help(ctx, parser))
    groups = commands(parser, "group")
    groups_done: list[tuple[argparse.ArgumentParser, _Commands, str]] = []

    def group(name: str, description: str) -> _Commands:
        g = groups.add_parser(name, description=description, formatter_class=RAW, write=write)
        command_options(name, g)  # `ros2 topic --include-hidden-topics ...`
        g.set_defaults(handler=lambda ctx, _args: _print_help(ctx, g))
        verbs = commands(g, "verb")
        groups_done.append((g, verbs, name))
        return verbs

    def verb(
        verbs: Commands, name: str, help_text: str, handler: Handler
    ) -> argparse.ArgumentParser:
        p = verbs.add_parser(name, description=help_text, formatter_class=RAW, write=write)
        p.set_defaults(handler=handler)
        return p

    # node, topic, service, action, param, lifecycle: arguments as Jazzy's ros2cli has them
    graph_verbs.add_node_verbs(group("node", "Various node related sub-commands"), verb)
    topic.add_verbs(group("topic", "Various topic related sub-commands"), verb)
    graph_verbs.add_service_verbs(group("service", "Various service related sub-commands"), verb)
    graph_verbs.add_action_verbs(group("action", "Various action related sub-commands"), verb)
    param.add_verbs(group("param", "Various param related sub-commands"), verb)
    lifecycle.add_verbs(group("lifecycle", "Various lifecycle related sub-commands"), verb)

    interfaces.add_verbs(group("interface", "Show information about ROS interfaces"), verb)

    bag.add_verbs(group("bag", "Various rosbag related sub-commands"), verb)
    pkg.add_verbs(group("pkg", "Various package related sub-commands"), verb)  # issue 22
    pkg.add_commands(groups, write)  # `colcon ...` and `source install/setup.bash`
    # `ros2 run PKG EXE`: a command, not a group of verbs; sourced workspaces come first.
    run.add_command(groups, write, pkg.run_own)
    launch_verb.add_command(groups, write)  # `ros2 launch PKG FILE`: the same
    for g, verbs, name in groups_done:
        for missing, description in NOT_HERE_VERBS.get(name, {}).items():
            p = verbs.add_parser(
                missing,
                description=f"{description} ({NOT_HERE})",
                formatter_class=RAW,
                write=write,
            )
            p.add_argument("words", nargs=argparse.REMAINDER, help=argparse.SUPPRESS)
            p.set_defaults(handler=_not_here_verb(f"{name} {missing}"))
        finish_commands(g, verbs)
    finish_commands(parser, groups)
    return parser


def _not_here_verb(words: str) -> Handler:
    """A verb of Jazzy's ros2 we do not offer: listed, and a clear refusal (exit code 2)."""

    def refuse(_ctx: CallContext, _args: argparse.Namespace) -> int:
        raise UsageError(f"`ros2 {words}` is {NOT_HERE}")

    return refuse


def _print_help(ctx: CallContext, parser: argparse.ArgumentParser) -> int:
    """`ros2 topic` alone: the group's help on stdout, exit code 0 (as ros2cli)."""
    for line in parser.format_help().rstrip("\n").split("\n"):
        ctx.write(line)
    return EXIT_OK


_NO_DDS = (
    {(group, verb) for group, verbs in NOT_HERE_VERBS.items() for verb in verbs}
    | {("interface", v) for v in ("list", "packages", "package", "show")}
    | {("interface", "proto")}
    | pkg.NO_DDS
    | {("bag", v) for v in bag.NO_DDS_VERBS}
)


def needs_ros(argv: list[str]) -> bool:
    """False for verbs that only read files (interface ...): the CLI skips DDS for them."""
    words = [w for w in argv if not w.startswith("-")]
    if len(words) < 2:
        return False  # a group without its verb: help or a usage error, no graph needed
    if words[0] in _HELP_WITHOUT_DDS and ("-h" in argv or "--help" in argv):
        return False  # help only: no need to discover the graph first
    return tuple(words[:2]) not in _NO_DDS and not pkg.no_dds(words)


# ros2cli's `service call` makes its client right away, in a brand-new node, and prints
# "waiting for service to become available..." while it has not matched the server yet:
# no look at the graph first, so a terminal shows that line when ros2 would.
_FRESH_CLIENT = {("service", "call")}

_HELP_WITHOUT_DDS = {"node", "topic", "service", "action", "param", "lifecycle", "interface"}


def parse(argv: list[str], write: Write, prog: str = "ros2") -> argparse.Namespace | None:
    """argv -> Namespace with ``handler``; None when help was printed. Raises UsageError."""
    if not argv:
        raise UsageError(f"type a command, e.g. `ros2 topic list` (groups: {', '.join(GROUPS)})")
    try:
        return build_parser(write, prog).parse_args(argv)
    except _HelpShown:
        return None
    except argparse.ArgumentError as exc:
        raise UsageError(str(exc)) from None


def run_argv(
    ctx: CallContext, argv: list[str], prog: str = "ros2", note: Write | None = None
) -> int:
    """Run one verb; every failure becomes one 'error: ...' line and an exit code.

    ``note`` (a terminal's stderr) takes what ros2 prints on stderr: argparse's
    complaints, ros2cli's failure messages, and the reason of a silent failure.
    """
    if note is None and isinstance(ctx, TerminalContext):
        note = ctx.note
    try:
        args = parse(argv, ctx.write, prog)
        if args is None:
            return EXIT_OK
        if needs_ros(argv) and tuple(argv[:2]) not in _FRESH_CLIENT:
            settle_discovery(ctx, getattr(args, "spin_time", None))
        return args.handler(ctx, args)
    except ArgumentUsageError as exc:
        # Every verb as ros2's argparse says it: the usage, then 'ros2 VERB: error: ...'.
        for line in [*exc.usage.rstrip("\n").split("\n"), exc.as_ros2]:
            (note or ctx.write)(line)
        return EXIT_USAGE
    except UsageError as exc:
        ctx.write(f"error: {exc}")
        return EXIT_USAGE
    except Cancelled:
        if isinstance(ctx, TerminalContext):
            return EXIT_INTERRUPTED  # as ros2 ends on Ctrl+C: nothing printed
        ctx.write("(stopped)")  # the Console says why the output ends
        return EXIT_FAILED
    except SilentFailure as exc:  # ros2 prints nothing; say why where it does not disturb
        (note or ctx.write)(f"({exc})" if note is None else str(exc))
        return EXIT_FAILED
    except Ros2cliMessage as exc:  # ros2cli's own words, as `ros2` prints them (stderr)
        (note or ctx.write)(str(exc))
        return EXIT_FAILED
    except Ros2Error as exc:
        ctx.write(f"error: {exc}")
        return EXIT_FAILED
    except (ValueError, TypeError, RuntimeError, LookupError, NameValidationException) as exc:
        # rclpy's own complaints (an invalid topic name, a node that just left):
        # still one line for the learner, never a traceback.
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        ctx.write(f"error: {first}")
        # The traceback goes to the dashboard's log (INFO: a terminal user sees one line).
        log.info("ros2 %s failed", " ".join(argv), exc_info=True)
        return EXIT_FAILED


def run_text(ctx: CallContext, text: str) -> int:
    """What the console does with a line of text."""
    try:
        argv = split_command(text)
    except UsageError as exc:
        ctx.write(f"error: {exc}")
        return EXIT_USAGE
    return run_argv(ctx, argv)
