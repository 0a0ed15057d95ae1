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
from collections.abc import Callable
from typing import Any, NoReturn

from app.ros.context import CallContext, Write
from app.ros.errors import Cancelled, Ros2Error
from app.ros2cli import bag, graph_verbs, interfaces, launch_verb, lifecycle, param, run, topic
from app.ros2cli.common import settle_discovery

log = logging.getLogger(__name__)

GROUPS = ("node", "topic", "service", "action", "param", "lifecycle", "interface", "bag", "pkg")
EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2


class UsageError(Ros2Error):
    """The command line itself is wrong (unknown verb, missing argument, bad quoting)."""


class _HelpShown(Exception):
    """argparse printed help (-h); stop without an error."""


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser that writes to our output and raises instead of exiting."""

    def __init__(self, *args: Any, write: Write, **kwargs: Any) -> None:
        kwargs.setdefault("exit_on_error", False)
        super().__init__(*args, **kwargs)
        self._write = write

    def _print_message(self, message: str, file: Any = None) -> None:
        if message:
            for line in message.rstrip("\n").splitlines():
                self._write(line)

    def exit(self, status: int = 0, message: str | None = None) -> NoReturn:
        if message:
            raise UsageError(message.strip())
        raise _HelpShown()

    def error(self, message: str) -> NoReturn:
        raise UsageError(f"{self.prog}: {message}")


def split_command(text: str) -> list[str]:
    """Split like a shell would quote, never run one; drop a leading 'ros2'."""
    try:
        words = shlex.split(text, comments=False, posix=True)
    except ValueError as exc:  # unbalanced quotes
        raise UsageError(f"cannot read the command: {exc}") from None
    if words[:1] == ["ros2"]:
        words = words[1:]
    return words


Handler = Callable[[CallContext, argparse.Namespace], int]


def topic_and_type(p: argparse.ArgumentParser) -> None:
    """The two positional arguments of echo, hz and bw: a topic, and optionally its type."""
    p.add_argument("topic_name")
    p.add_argument("message_type", nargs="?")


def _measure_handler(measure: Callable[..., int]) -> Handler:
    return lambda c, a: measure(c, a.topic_name, a.message_type, a.window)


def build_parser(write: Write, prog: str = "ros2") -> argparse.ArgumentParser:
    parser = _Parser(prog=prog, write=write, description="ros2-like verbs")
    groups = parser.add_subparsers(dest="group", metavar="COMMAND", parser_class=_Parser)
    groups.required = True

    def group(name: str, help_text: str):
        g = groups.add_parser(name, help=help_text, write=write)
        verbs = g.add_subparsers(dest="verb", metavar="VERB", parser_class=_Parser)
        verbs.required = True
        return verbs

    def verb(verbs, name: str, help_text: str, handler: Handler) -> argparse.ArgumentParser:
        p = verbs.add_parser(name, help=help_text, write=write)
        p.set_defaults(handler=handler)
        return p

    def typed_list(verbs, noun: str, listing: Callable[..., int]) -> None:
        """`ros2 service list` and `ros2 action list`, with -t (types) and -c (count)."""
        p = verb(
            verbs,
            "list",
            f"list {noun}s",
            lambda c, a: listing(c, a.show_types, getattr(a, f"count_{noun}s")),
        )
        p.add_argument("-t", "--show-types", action="store_true")
        p.add_argument("-c", f"--count-{noun}s", action="store_true")

    # node
    v = group("node", "nodes on the graph")
    p = verb(v, "list", "list nodes", lambda c, a: graph_verbs.node_list(c, a.all, a.count_nodes))
    p.add_argument("-a", "--all", action="store_true", help="include hidden nodes")
    p.add_argument("-c", "--count-nodes", action="store_true", help="only print the count")
    p = verb(v, "info", "a node's endpoints", lambda c, a: graph_verbs.node_info(c, a.node_name))
    p.add_argument("node_name")

    # topic
    v = group("topic", "topics")
    p = verb(
        v,
        "list",
        "list topics",
        lambda c, a: topic.list_topics(c, a.show_types, a.verbose),
    )
    p.add_argument("-t", "--show-types", action="store_true")
    p.add_argument("-v", "--verbose", action="store_true", help="with publisher/subscriber counts")
    p = verb(
        v, "info", "type, counts and QoS", lambda c, a: topic.topic_info(c, a.topic_name, a.verbose)
    )
    p.add_argument("topic_name")
    p.add_argument("-v", "--verbose", action="store_true", help="endpoints with their QoS")
    p = verb(v, "type", "a topic's type", lambda c, a: topic.topic_type(c, a.topic_name))
    p.add_argument("topic_name")
    p = verb(v, "find", "topics of a type", lambda c, a: topic.find(c, a.topic_type))
    p.add_argument("topic_type")
    p = verb(
        v,
        "echo",
        "print messages",
        lambda c, a: topic.echo(c, a.topic_name, a.message_type, once=a.once, field=a.field),
    )
    topic_and_type(p)
    p.add_argument("--once", action="store_true", help="print one message and exit")
    p.add_argument("--field", help="print only this field, e.g. linear.x")
    for name, help_text, measure, window in (
        ("hz", "publishing rate", topic.hz, 10_000),
        ("bw", "bandwidth", topic.bw, 100),
    ):
        p = verb(v, name, help_text, _measure_handler(measure))
        topic_and_type(p)
        p.add_argument("-w", "--window", type=int, default=window, help="messages in the window")
    p = verb(
        v,
        "pub",
        "publish",
        lambda c, a: topic.pub(
            c,
            a.topic_name,
            a.message_type,
            a.values,
            once=a.once,
            rate=a.rate,
            times=a.times,
            wait_matching=a.wait_matching_subscriptions,
        ),
    )
    p.add_argument("topic_name")
    p.add_argument("message_type")
    p.add_argument("values", nargs="?", default="", help="YAML, e.g. \"{data: 'hi'}\"")
    p.add_argument("-1", "--once", action="store_true", help="publish one message and exit")
    p.add_argument("-r", "--rate", type=float, default=1.0, help="Hz (default 1)")
    p.add_argument("-t", "--times", type=int, default=None, help="publish this many times")
    p.add_argument("-w", "--wait-matching-subscriptions", type=int, default=None)

    # service
    v = group("service", "services")
    typed_list(v, "service", graph_verbs.service_list)
    p = verb(
        v, "type", "a service's type", lambda c, a: graph_verbs.service_type(c, a.service_name)
    )
    p.add_argument("service_name")
    p = verb(v, "find", "services of a type", lambda c, a: graph_verbs.service_find(c, a.type_name))
    p.add_argument("type_name")
    p = verb(v, "info", "type and counts", lambda c, a: graph_verbs.service_info(c, a.service_name))
    p.add_argument("service_name")
    p = verb(
        v,
        "call",
        "call a service",
        lambda c, a: graph_verbs.service_call(c, a.service_name, a.service_type, a.values),
    )
    p.add_argument("service_name")
    p.add_argument("service_type")
    p.add_argument("values", nargs="?", default="")

    # action
    v = group("action", "actions")
    typed_list(v, "action", graph_verbs.action_list)
    p = verb(v, "type", "an action's type", lambda c, a: graph_verbs.action_type(c, a.action_name))
    p.add_argument("action_name")
    p = verb(
        v,
        "info",
        "clients and servers",
        lambda c, a: graph_verbs.action_info(c, a.action_name, a.show_types),
    )
    p.add_argument("action_name")
    p.add_argument("-t", "--show-types", action="store_true")
    p = verb(
        v,
        "send_goal",
        "send a goal",
        lambda c, a: graph_verbs.action_send_goal(
            c, a.action_name, a.action_type, a.goal, a.feedback
        ),
    )
    p.add_argument("action_name")
    p.add_argument("action_type")
    p.add_argument("goal", nargs="?", default="")
    p.add_argument("-f", "--feedback", action="store_true", help="print feedback as it arrives")

    # param
    v = group("param", "parameters")
    p = verb(
        v, "list", "parameter names", lambda c, a: param.param_list(c, a.node_name, a.param_type)
    )
    p.add_argument("node_name", nargs="?")
    p.add_argument("--param-type", action="store_true")
    p = verb(v, "get", "one value", lambda c, a: param.param_get(c, a.node_name, a.parameter_name))
    p.add_argument("node_name")
    p.add_argument("parameter_name")
    p = verb(
        v,
        "set",
        "set one value",
        lambda c, a: param.param_set(c, a.node_name, a.parameter_name, a.value),
    )
    p.add_argument("node_name")
    p.add_argument("parameter_name")
    p.add_argument("value")
    p = verb(v, "dump", "all values as YAML", lambda c, a: param.param_dump(c, a.node_name))
    p.add_argument("node_name")
    p = verb(
        v,
        "load",
        "set values from a YAML file",
        lambda c, a: param.param_load(c, a.node_name, a.parameter_file),
    )
    p.add_argument("node_name")
    p.add_argument("parameter_file")

    # lifecycle
    v = group("lifecycle", "managed (lifecycle) nodes")
    p = verb(v, "nodes", "lifecycle nodes", lambda c, a: lifecycle.verb_nodes(c, a.count_nodes))
    p.add_argument("-c", "--count-nodes", action="store_true")
    p = verb(v, "get", "current state", lambda c, a: lifecycle.verb_get(c, a.node_name))
    p.add_argument("node_name", nargs="?")
    p = verb(v, "list", "available transitions", lambda c, a: lifecycle.verb_list(c, a.node_name))
    p.add_argument("node_name")
    p = verb(
        v,
        "set",
        "trigger a transition",
        lambda c, a: lifecycle.verb_set(c, a.node_name, a.transition),
    )
    p.add_argument("node_name")
    p.add_argument("transition", help="label (configure, activate, ...) or id")

    # interface
    v = group("interface", "message, service and action definitions")
    p = verb(v, "list", "installed interfaces", _interface_list)
    p.add_argument("-m", "--only-msgs", action="store_true")
    p.add_argument("-s", "--only-srvs", action="store_true")
    p.add_argument("-a", "--only-actions", action="store_true")
    p = verb(v, "packages", "interface packages", _interface_packages)
    p = verb(v, "package", "one package's interfaces", _interface_package)
    p.add_argument("package_name")
    p = verb(v, "show", "a definition", _interface_show)
    p.add_argument("type")
    p.add_argument("--no-expand", action="store_true", help="do not expand nested types")

    bag.add_verbs(group("bag", "record, inspect and replay topics"), verb)
    v = group("pkg", "packages")
    p = verb(v, "executables", "what `ros2 run` can start", _pkg_executables)
    p.add_argument("package_name", nargs="?")
    run.add_command(groups, write)  # `ros2 run PKG EXE`: a command, not a group of verbs
    launch_verb.add_command(groups, write)  # `ros2 launch PKG FILE`: the same
    return parser


_NO_DDS = (
    {("interface", v) for v in ("list", "packages", "package", "show")}
    | {("pkg", "executables")}
    | {("bag", v) for v in bag.NO_DDS_VERBS}
)


def needs_ros(argv: list[str]) -> bool:
    """False for verbs that only read files (interface ...): the CLI skips DDS for them."""
    words = [w for w in argv if not w.startswith("-")]
    return tuple(words[:2]) not in _NO_DDS


def _pkg_executables(ctx: CallContext, args: argparse.Namespace) -> int:
    return run.pkg_executables(ctx, args.package_name)


def _interface_list(ctx: CallContext, args: argparse.Namespace) -> int:
    found = interfaces.all_interfaces()
    chosen = [
        k
        for k, flag in (
            ("msg", args.only_msgs),
            ("srv", args.only_srvs),
            ("action", args.only_actions),
        )
        if flag
    ] or ["msg", "srv", "action"]
    titles = {"msg": "Messages", "srv": "Services", "action": "Actions"}
    for kind in chosen:
        ctx.write(f"{titles[kind]}:")
        for name in found[kind]:
            ctx.write(f"    {name}")
    return 0


def _interface_packages(ctx: CallContext, args: argparse.Namespace) -> int:
    for package in interfaces.interface_packages():
        ctx.write(package)
    return 0


def _interface_package(ctx: CallContext, args: argparse.Namespace) -> int:
    packages = interfaces.interface_packages()
    if args.package_name not in packages:
        raise Ros2Error(f"unknown interface package '{args.package_name}'")
    for name in packages[args.package_name]:
        ctx.write(f"{args.package_name}/{name}")
    return 0


def _interface_show(ctx: CallContext, args: argparse.Namespace) -> int:
    for line in interfaces.show(args.type, expand=not args.no_expand).splitlines():
        ctx.write(line)
    return 0


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


def run_argv(ctx: CallContext, argv: list[str], prog: str = "ros2") -> int:
    """Run one verb; every failure becomes one 'error: ...' line and an exit code."""
    try:
        args = parse(argv, ctx.write, prog)
        if args is None:
            return EXIT_OK
        if needs_ros(argv):
            settle_discovery(ctx)
        return args.handler(ctx, args)
    except UsageError as exc:
        ctx.write(f"error: {exc}")
        return EXIT_USAGE
    except Cancelled:
        ctx.write("(stopped)")
        return EXIT_FAILED
    except Ros2Error as exc:
        ctx.write(f"error: {exc}")
        return EXIT_FAILED
    except (ValueError, TypeError, RuntimeError, LookupError) as exc:
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
